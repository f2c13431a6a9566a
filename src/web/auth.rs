//! Sign-in, sessions and CSRF tokens for `ncplan serve`.
//!
//! Every visitor has a session cookie (`ncplan_session`, HttpOnly, SameSite=Strict): a random
//! token. Where users are configured, the token is known to the server only after a password
//! check (argon2); without users, any token is an anonymous session. A form's CSRF token is
//! the SHA-256 of the process's secret and the session token, so a page of another site can
//! neither read nor forge it.

use axum::http::{HeaderMap, header};
use sha2::Digest as _;

use super::{Ctx, Server};
use crate::config::WebUser;

const COOKIE: &str = "ncplan_session";

/// 32 random bytes from the kernel.
pub(super) fn random() -> anyhow::Result<[u8; 32]> {
    use std::io::Read as _;
    let mut b = [0u8; 32];
    std::fs::File::open("/dev/urandom")
        .and_then(|mut f| f.read_exact(&mut b))
        .map_err(|e| anyhow::anyhow!("cannot read /dev/urandom: {e}"))?;
    Ok(b)
}

fn hex(b: &[u8]) -> String {
    b.iter().map(|x| format!("{x:02x}")).collect()
}

fn cookie_value(headers: &HeaderMap) -> Option<String> {
    for value in headers.get_all(header::COOKIE) {
        let Ok(text) = value.to_str() else { continue };
        for part in text.split(';') {
            if let Some(v) = part.trim().strip_prefix(COOKIE).and_then(|r| r.strip_prefix('='))
                && v.len() == 64
                && v.bytes().all(|c| c.is_ascii_hexdigit())
            {
                return Some(v.to_owned());
            }
        }
    }
    None
}

fn set_cookie(token: &str) -> String {
    format!("{COOKIE}={token}; Path=/; HttpOnly; SameSite=Strict")
}

fn csrf_of(s: &Server, token: &str) -> String {
    let mut h = sha2::Sha256::new();
    h.update(s.secret);
    h.update(token.as_bytes());
    format!("{:x}", h.finalize())
}

/// The visitor's context and, for a new visitor, the cookie to set; `None` when users are
/// configured and the visitor has not signed in.
pub(super) fn context(s: &Server, headers: &HeaderMap) -> Option<(Ctx, Option<String>)> {
    let token = cookie_value(headers);
    if s.auth_required() {
        let token = token?;
        let user = s.sessions.lock().ok()?.get(&token).cloned()?;
        return Some((Ctx { user: Some(user), csrf: csrf_of(s, &token), auth: true }, None));
    }
    match token {
        Some(t) => Some((Ctx { user: None, csrf: csrf_of(s, &t), auth: false }, None)),
        None => {
            let t = hex(&random().ok()?);
            Some((Ctx { user: None, csrf: csrf_of(s, &t), auth: false }, Some(set_cookie(&t))))
        }
    }
}

/// Whether a POST may act: its CSRF token matches the session's, and a browser's `Origin`,
/// when sent, is this server.
pub(super) fn post_allowed(s: &Server, headers: &HeaderMap, ctx: &Ctx, csrf: Option<&str>) -> bool {
    if let (Some(origin), Some(host)) = (headers.get(header::ORIGIN), headers.get(header::HOST)) {
        let (Ok(origin), Ok(host)) = (origin.to_str(), host.to_str()) else { return false };
        let bare = origin.strip_prefix("http://").or_else(|| origin.strip_prefix("https://")).unwrap_or(origin);
        if bare != host {
            return false;
        }
    }
    let _ = s;
    csrf.is_some_and(|c| constant_time_eq(c.as_bytes(), ctx.csrf.as_bytes()))
}

fn constant_time_eq(a: &[u8], b: &[u8]) -> bool {
    a.len() == b.len() && a.iter().zip(b).fold(0u8, |acc, (x, y)| acc | (x ^ y)) == 0
}

/// Whether `password` is the password of the configured user `name`.
pub(super) fn check_password(users: &[WebUser], name: &str, password: &str) -> bool {
    use argon2::PasswordVerifier as _;
    let Some(user) = users.iter().find(|u| u.name == name) else { return false };
    let Ok(hash) = argon2::PasswordHash::new(&user.password_hash) else { return false };
    argon2::Argon2::default().verify_password(password.as_bytes(), &hash).is_ok()
}

/// A new session for `name`: its cookie.
pub(super) fn start_session(s: &Server, name: &str) -> anyhow::Result<String> {
    let token = hex(&random()?);
    s.sessions.lock().map_err(|_| anyhow::anyhow!("the session table is poisoned"))?.insert(token.clone(), name.to_owned());
    Ok(set_cookie(&token))
}

/// Ends the visitor's session.
pub(super) fn end_session(s: &Server, headers: &HeaderMap) {
    if let (Some(t), Ok(mut sessions)) = (cookie_value(headers), s.sessions.lock()) {
        sessions.remove(&t);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn passwords_are_checked_against_argon2_hashes() {
        use argon2::PasswordHasher as _;
        let salt = argon2::password_hash::SaltString::encode_b64(b"ncplan-test-salt").unwrap();
        let hash = argon2::Argon2::default().hash_password(b"s3cret", &salt).unwrap().to_string();
        let users = vec![WebUser { name: "ada".into(), password_hash: hash }];
        assert!(check_password(&users, "ada", "s3cret"));
        assert!(!check_password(&users, "ada", "wrong"));
        assert!(!check_password(&users, "bob", "s3cret"));
    }

    #[test]
    fn the_session_cookie_is_read_only_when_well_formed() {
        let mut h = HeaderMap::new();
        h.insert(header::COOKIE, format!("a=b; {COOKIE}={}", "ab".repeat(32)).parse().unwrap());
        assert_eq!(cookie_value(&h), Some("ab".repeat(32)));
        h.insert(header::COOKIE, format!("{COOKIE}=\"><script>").parse().unwrap());
        assert_eq!(cookie_value(&h), None);
        assert!(set_cookie("x").contains("HttpOnly; SameSite=Strict"));
    }
}

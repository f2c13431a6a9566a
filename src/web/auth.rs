//! Sign-in, sessions and CSRF tokens for `ncplan serve`.
//!
//! Every visitor has a session cookie (`ncplan_session`, HttpOnly, SameSite=Strict): a random
//! token. Where users are configured, the token is a session only once a password check
//! (argon2) has recorded it in the store (`web_sessions`, by the token's SHA-256: the
//! database holds no cookie that works), for [`SESSION_HOURS`] or until its planner signs
//! out, and only while its planner is still configured; a restart of the server signs no one
//! out. (Through a database role that only reads, the server keeps its sessions itself, until
//! it stops.) Without users, any token is an anonymous session. A form's CSRF token is the SHA-256
//! of the session token and, without users, a per-process secret (a client-chosen token is
//! not enough to make it); a page of another site can neither read nor forge it.

use axum::http::{HeaderMap, header};
use sha2::Digest as _;

use super::{Ctx, Server};
use crate::config::WebUser;

const COOKIE: &str = "ncplan_session";

/// How long a sign-in lasts: a working day and then some.
pub(super) const SESSION_HOURS: i64 = 12;

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
    if s.auth_required() {
        // A session the store knows: its token, unguessable and never stored, is enough, and
        // the forms of a page stay good across a restart of the server.
        h.update(b"ncplan csrf\0");
    } else {
        h.update(s.secret);
    }
    h.update(token.as_bytes());
    format!("{:x}", h.finalize())
}

/// The name of a session in the store: its token's SHA-256.
fn token_hash(token: &str) -> String {
    format!("{:x}", sha2::Sha256::digest(token.as_bytes()))
}

/// The visitor's context and, for a new visitor, the cookie to set; `None` when users are
/// configured and the visitor has no session (never signed in, signed out, expired, or no
/// longer a configured user). A session is looked up in the store on the blocking pool.
pub(super) async fn context(s: &std::sync::Arc<Server>, headers: &HeaderMap) -> Option<(Ctx, Option<String>)> {
    let token = cookie_value(headers);
    if s.auth_required() {
        let token = token?;
        let (server, hash) = (s.clone(), token_hash(&token));
        let user = match tokio::task::spawn_blocking(move || server.session_user(&hash)).await {
            Ok(Ok(user)) => user?,
            Ok(Err(e)) => {
                tracing::warn!(error = format!("{e:#}"), "cannot read the session");
                return None;
            }
            Err(_) => return None,
        };
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

/// A new session for `name`, recorded in the store until [`SESSION_HOURS`] from now: its
/// cookie. Where the store does not take it (a database role that only reads), the session is
/// kept by this process alone, and said. Blocks (the store's write).
pub(super) fn start_session(s: &Server, name: &str) -> anyhow::Result<String> {
    let token = hex(&random()?);
    let now = s.clock.now();
    let until = later(&now, SESSION_HOURS * 3600).ok_or_else(|| anyhow::anyhow!("the clock says `{now}`, not an RFC 3339 time"))?;
    let hash = token_hash(&token);
    if let Err(e) = s.writer().and_then(|w| Ok(w.start_session(&hash, name, &now, &until)?)) {
        tracing::warn!(error = format!("{e:#}"), "the database does not keep the session; it lasts while this server runs");
        s.unstored.lock().map_err(|_| anyhow::anyhow!("the session table is poisoned"))?.insert(hash, (name.to_owned(), until));
    }
    Ok(set_cookie(&token))
}

/// Ends the visitor's session. Blocks (the store's write).
pub(super) fn end_session(s: &Server, headers: &HeaderMap) -> anyhow::Result<()> {
    if let Some(t) = cookie_value(headers) {
        let hash = token_hash(&t);
        let unstored = s.unstored.lock().ok().and_then(|mut m| m.remove(&hash));
        if unstored.is_none() {
            s.writer()?.end_session(&hash)?;
        }
    }
    Ok(())
}

/// `now` (`YYYY-MM-DDTHH:MM:SS.mmmZ`, as the clock gives it) `secs` seconds later, in the
/// same form: such times compare as text.
fn later(now: &str, secs: i64) -> Option<String> {
    let b = now.as_bytes();
    if b.len() < 20 || b[4] != b'-' || b[7] != b'-' || b[10] != b'T' || b[13] != b':' || b[16] != b':' || !now.ends_with('Z') {
        return None;
    }
    let num = |r: std::ops::Range<usize>| now.get(r)?.parse::<i64>().ok();
    let (y, m, d) = (num(0..4)?, num(5..7)?, num(8..10)?);
    let millis = if b[19] == b'.' { num(20..23)? } else { 0 };
    // Days since 1970-01-01 of a civil date (Howard Hinnant's algorithm).
    let y = if m <= 2 { y - 1 } else { y };
    let era = y.div_euclid(400);
    let yoe = y - era * 400;
    let doy = (153 * (if m > 2 { m - 3 } else { m + 9 }) + 2) / 5 + d - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    let days = era * 146_097 + doe - 719_468;
    let t = days * 86_400 + num(11..13)? * 3600 + num(14..16)? * 60 + num(17..19)? + secs;
    Some(crate::daemon::rfc3339(t, millis as u32))
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

    #[test]
    fn a_session_ends_hours_after_it_starts_in_the_clocks_own_form() {
        assert_eq!(later("2026-03-01T00:00:00.000Z", 12 * 3600).as_deref(), Some("2026-03-01T12:00:00.000Z"));
        assert_eq!(later("2024-02-28T20:30:15.250Z", 12 * 3600).as_deref(), Some("2024-02-29T08:30:15.250Z"));
        assert_eq!(later("2025-12-31T23:59:59.999Z", 1).as_deref(), Some("2026-01-01T00:00:00.999Z"));
        assert_eq!(later("1970-01-01T00:00:00Z", 0).as_deref(), Some("1970-01-01T00:00:00.000Z"));
        assert_eq!(later("yesterday", 1), None);
        // The store's session is the token's hash, never the token.
        let token = "ab".repeat(32);
        assert_eq!(token_hash(&token).len(), 64);
        assert_ne!(token_hash(&token), token);
    }
}

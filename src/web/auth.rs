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

use std::collections::BTreeMap;
use std::net::IpAddr;
use std::time::{Duration, Instant};

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

/// The session cookie (`Secure` is added by `guard::layer` when the request came over TLS).
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

/// The hash a sign-in as `name` is checked against, and whether `name` is a configured user:
/// an unknown name is checked against `dummy`, so that its reply takes as long as a known
/// user's with a wrong password (no list of users by timing).
fn hash_to_check<'a>(users: &'a [WebUser], name: &str, dummy: &'a str) -> (&'a str, bool) {
    match users.iter().find(|u| u.name == name) {
        Some(u) => (&u.password_hash, true),
        None => (dummy, false),
    }
}

/// Whether `password` is the password of the configured user `name`; `dummy` (see
/// [`dummy_hash`]) stands in for an unknown name. Blocks (argon2).
pub(super) fn check_password(users: &[WebUser], name: &str, password: &str, dummy: &str) -> bool {
    let (phc, known) = hash_to_check(users, name, dummy);
    let matches = verify(password.as_bytes(), phc).unwrap_or(false);
    matches && known
}

thread_local! {
    /// argon2's working memory, kept by the thread for its next check: allocated anew for
    /// each check (as `PasswordVerifier` does), glibc left 19 MiB more resident per check.
    static BLOCKS: std::cell::RefCell<Vec<argon2::Block>> = const { std::cell::RefCell::new(Vec::new()) };
}

/// Whether `password` hashes to the PHC string `phc` (its algorithm, version, parameters and
/// salt), in this thread's working memory; `None` when `phc` is not an argon2 hash.
fn verify(password: &[u8], phc: &str) -> Option<bool> {
    let hash = argon2::PasswordHash::new(phc).ok()?;
    let algorithm = argon2::Algorithm::try_from(hash.algorithm).ok()?;
    let version = match hash.version {
        Some(v) => argon2::Version::try_from(v).ok()?,
        None => argon2::Version::default(),
    };
    let params = argon2::Params::try_from(&hash).ok()?;
    let expected = hash.hash?;
    let mut salt = [0u8; 64];
    let salt = hash.salt?.decode_b64(&mut salt).ok()?;
    let mut out = vec![0u8; expected.len()];
    let blocks = params.block_count();
    let hashed = BLOCKS.with_borrow_mut(|memory| {
        memory.resize(blocks, argon2::Block::default());
        argon2::Argon2::new(algorithm, version, params).hash_password_into_with_memory(password, salt, &mut out, &mut memory[..blocks])
    });
    hashed.ok()?;
    Some(constant_time_eq(&out, expected.as_bytes()))
}

/// A hash of a random password with the parameters of the first configured user's (argon2's
/// defaults without users): what an unknown name is checked against. Blocks (one argon2 hash).
pub(super) fn dummy_hash(users: &[WebUser]) -> String {
    use argon2::PasswordHasher as _;
    let bytes = random().unwrap_or([7; 32]);
    let Ok(salt) = argon2::password_hash::SaltString::encode_b64(&bytes[..16]) else { return String::new() };
    let like = users.first().and_then(|u| argon2::PasswordHash::new(&u.password_hash).ok());
    let hasher = like
        .as_ref()
        .and_then(|h| {
            let algorithm = argon2::Algorithm::try_from(h.algorithm).ok()?;
            let version = h.version.and_then(|v| argon2::Version::try_from(v).ok()).unwrap_or_default();
            let params = argon2::Params::try_from(h).ok()?;
            Some(argon2::Argon2::new(algorithm, version, params))
        })
        .unwrap_or_default();
    hasher.hash_password(&bytes[16..], &salt).map(|h| h.to_string()).unwrap_or_default()
}

/// The threads that check passwords, as many as may run at once: argon2 takes its memory (19
/// MiB by default) per check, and a check on any thread of the blocking pool would leave that
/// thread's allocator holding it; here it is held by these threads only.
pub(super) struct Checkers {
    jobs: std::sync::mpsc::Sender<Box<dyn FnOnce() + Send>>,
}

impl Checkers {
    pub(super) fn new(threads: usize) -> Checkers {
        let (jobs, queue) = std::sync::mpsc::channel::<Box<dyn FnOnce() + Send>>();
        let queue = std::sync::Arc::new(std::sync::Mutex::new(queue));
        for i in 0..threads {
            let queue = queue.clone();
            let spawned = std::thread::Builder::new().name(format!("ncplan-password-{i}")).spawn(move || {
                loop {
                    let job = match queue.lock() {
                        Ok(q) => q.recv(),
                        Err(_) => return,
                    };
                    match job {
                        Ok(job) => job(),
                        Err(_) => return,
                    }
                }
            });
            if let Err(e) = spawned {
                tracing::warn!(error = %e, "cannot start a password-checking thread");
            }
        }
        Checkers { jobs }
    }

    /// Runs `f` on a checking thread; `None` if none runs.
    pub(super) async fn run<T: Send + 'static>(&self, f: impl FnOnce() -> T + Send + 'static) -> Option<T> {
        let (tx, rx) = tokio::sync::oneshot::channel();
        self.jobs
            .send(Box::new(move || {
                let _ = tx.send(f());
            }))
            .ok()?;
        rx.await.ok()
    }
}

/// Sign-in attempts per client: a token bucket each (a burst of `per_minute`, then one every
/// `60 / per_minute` s), at most [`CLIENTS_KEPT`] clients remembered (full buckets forgotten
/// first, then the longest unused).
pub(super) struct Attempts {
    per_minute: u32,
    buckets: BTreeMap<IpAddr, (f64, Instant)>,
}

/// Clients whose sign-in attempts are remembered.
const CLIENTS_KEPT: usize = 4096;

impl Attempts {
    pub(super) fn new(per_minute: u32) -> Attempts {
        Attempts { per_minute: per_minute.max(1), buckets: BTreeMap::new() }
    }

    /// Takes one attempt for `client` at `now`, or says how long until the next is allowed.
    pub(super) fn take(&mut self, client: IpAddr, now: Instant) -> Result<(), Duration> {
        let cap = f64::from(self.per_minute);
        let rate = cap / 60.0;
        let level = |(tokens, at): (f64, Instant)| (tokens + now.saturating_duration_since(at).as_secs_f64() * rate).min(cap);
        if !self.buckets.contains_key(&client) && self.buckets.len() >= CLIENTS_KEPT {
            self.buckets.retain(|_, b| level(*b) < cap);
            if self.buckets.len() >= CLIENTS_KEPT
                && let Some(oldest) = self.buckets.iter().min_by_key(|(_, b)| b.1).map(|(ip, _)| *ip)
            {
                self.buckets.remove(&oldest);
            }
        }
        let tokens = self.buckets.get(&client).map_or(cap, |b| level(*b));
        if tokens < 1.0 {
            self.buckets.insert(client, (tokens, now));
            return Err(Duration::from_secs_f64((1.0 - tokens) / rate));
        }
        self.buckets.insert(client, (tokens - 1.0, now));
        Ok(())
    }
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
        let dummy = dummy_hash(&users);
        assert!(check_password(&users, "ada", "s3cret", &dummy));
        assert!(!check_password(&users, "ada", "wrong", &dummy));
        assert!(!check_password(&users, "bob", "s3cret", &dummy));
    }

    /// An unknown name costs the same argon2 work as a known one: it is checked against a
    /// dummy hash with the configured users' parameters (memory, passes, lanes).
    #[test]
    fn an_unknown_name_is_checked_against_a_hash_like_the_users() {
        use argon2::PasswordHasher as _;
        let salt = argon2::password_hash::SaltString::encode_b64(b"ncplan-test-salt").unwrap();
        let params = argon2::Params::new(8 * 1024, 3, 1, None).unwrap();
        let hasher = argon2::Argon2::new(argon2::Algorithm::Argon2id, argon2::Version::V0x13, params);
        let hash = hasher.hash_password(b"s3cret", &salt).unwrap().to_string();
        let users = vec![WebUser { name: "ada".into(), password_hash: hash.clone() }];
        let dummy = dummy_hash(&users);
        assert_eq!(hash_to_check(&users, "ada", &dummy), (hash.as_str(), true));
        assert_eq!(hash_to_check(&users, "mallory", &dummy), (dummy.as_str(), false));
        let (d, h) = (argon2::PasswordHash::new(&dummy).unwrap(), argon2::PasswordHash::new(&hash).unwrap());
        assert_eq!(argon2::Params::try_from(&d).unwrap(), argon2::Params::try_from(&h).unwrap());
        assert_eq!((d.algorithm, d.version), (h.algorithm, h.version));
        assert_ne!(d.salt, h.salt);
        // The dummy's password is random: no password signs an unknown name in.
        assert!(!check_password(&users, "mallory", "", &dummy));
    }

    #[test]
    fn sign_in_attempts_are_rate_limited_per_client() {
        let mut a = Attempts::new(6);
        let t0 = Instant::now();
        let (one, two): (IpAddr, IpAddr) = ("192.0.2.1".parse().unwrap(), "192.0.2.2".parse().unwrap());
        for _ in 0..6 {
            assert!(a.take(one, t0).is_ok());
        }
        let wait = a.take(one, t0).unwrap_err();
        assert!(wait > Duration::from_secs(9) && wait <= Duration::from_secs(10), "{wait:?}");
        // Another client is not held back; the first gets one attempt back in 10 s.
        assert!(a.take(two, t0).is_ok());
        assert!(a.take(one, t0 + Duration::from_secs(10)).is_ok());
        assert!(a.take(one, t0 + Duration::from_secs(10)).is_err());
        // The memory of clients is bounded.
        for i in 0..(CLIENTS_KEPT as u32 + 10) {
            let _ = a.take(IpAddr::from(i.to_be_bytes()), t0 + Duration::from_secs(11));
        }
        assert!(a.buckets.len() <= CLIENTS_KEPT);
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

//! What the tests that run the real binaries share (`daemon`, `faults`, `pg`, `web`): a child
//! process ended when dropped, `ncplan watch` and `ncplan serve` started on a configuration,
//! one HTTP exchange, waiting for rows or a condition, and the small face-milling program
//! their edits change.

use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// A child process, killed and reaped when dropped (or by [`Proc::kill`]).
pub(crate) struct Proc(pub(crate) Child);

impl Proc {
    /// Kills the process now (SIGKILL) and reaps it.
    pub(crate) fn kill(mut self) {
        self.0.kill().unwrap();
        self.0.wait().unwrap();
    }
}

impl Drop for Proc {
    fn drop(&mut self) {
        let _ = self.0.kill();
        let _ = self.0.wait();
    }
}

/// The folder a command given `--config config` runs in: the configuration's own, since
/// relative paths are resolved against the working directory.
pub(crate) fn config_dir(config: &Path) -> &Path {
    config.parent().filter(|p| !p.as_os_str().is_empty()).unwrap_or(Path::new("."))
}

/// Starts `ncplan watch --config config` in the configuration's folder, logging at `level`
/// (`NCPLAN_LOG`) to `stderr`. It does not wait: the callers wait for what they need (the
/// catch-up scan, a row).
pub(crate) fn watch(config: &Path, level: &str, stderr: impl Into<Stdio>) -> Proc {
    let child = Command::new(crate::bin())
        .current_dir(config_dir(config))
        .args(["watch", "--config"])
        .arg(config)
        .env("NCPLAN_LOG", level)
        .stdout(Stdio::null())
        .stderr(stderr)
        .spawn()
        .expect("start ncplan watch");
    Proc(child)
}

/// Starts `ncplan serve --config config` with `args`, on a free loopback port unless they
/// give `--listen`; returns it and its base URL (`http://127.0.0.1:PORT`), once it listens.
pub(crate) fn serve(config: &Path, args: &[&str]) -> (Proc, String) {
    use std::io::BufRead as _;
    let listen: &[&str] = if args.contains(&"--listen") { &[] } else { &["--listen", "127.0.0.1:0"] };
    let mut child = Command::new(crate::bin())
        .current_dir(config_dir(config))
        .args(["serve", "--config"])
        .arg(config)
        .args(listen)
        .args(args)
        .stdout(Stdio::piped())
        .stderr(Stdio::inherit())
        .spawn()
        .expect("start ncplan serve");
    let mut line = String::new();
    std::io::BufReader::new(child.stdout.take().unwrap()).read_line(&mut line).unwrap();
    let url = line.split_whitespace().find(|w| w.starts_with("http://")).unwrap_or_else(|| panic!("serve said: {line}"));
    (Proc(child), url.trim_end_matches('/').to_owned())
}

/// One HTTP/1.1 exchange on a new connection (`{host}` in `request` is the server's address):
/// the status line and headers, and the body.
pub(crate) fn http(base: &str, request: &str) -> (String, String) {
    use std::io::{Read as _, Write as _};
    let addr = base.trim_start_matches("http://");
    let mut s = std::net::TcpStream::connect(addr).unwrap();
    s.write_all(request.replace("{host}", addr).as_bytes()).unwrap();
    let mut out = String::new();
    s.read_to_string(&mut out).unwrap();
    let (head, body) = out.split_once("\r\n\r\n").unwrap_or((&out, ""));
    (head.to_owned(), body.to_owned())
}

/// `s` percent-encoded, every byte but letters and digits (a query value, a form field).
pub(crate) fn urlencode(s: &str) -> String {
    s.bytes().map(|b| if b.is_ascii_alphanumeric() { (b as char).to_string() } else { format!("%{b:02X}") }).collect()
}

/// A free local port.
pub(crate) fn free_port() -> u16 {
    std::net::TcpListener::bind("127.0.0.1:0").unwrap().local_addr().unwrap().port()
}

/// The rows `sql` gives on the SQLite file `db` once there are at least `want`, or those
/// there are after `timeout`.
pub(crate) fn wait_rows(db: &Path, sql: &str, want: usize, timeout: Duration) -> Vec<Vec<String>> {
    let deadline = Instant::now() + timeout;
    loop {
        let r = crate::db_rows(db, sql);
        if r.len() >= want || Instant::now() > deadline {
            return r;
        }
        std::thread::sleep(Duration::from_millis(25));
    }
}

/// Waits until `done`, failing the test after `timeout` with `what`.
pub(crate) fn wait_until(what: &str, timeout: Duration, mut done: impl FnMut() -> bool) {
    let deadline = Instant::now() + timeout;
    while !done() {
        assert!(Instant::now() < deadline, "timed out waiting until {what}");
        std::thread::sleep(Duration::from_millis(25));
    }
}

/// A configuration's `[web]` section with the users `(name, password)` (argon2 hashes).
pub(crate) fn web_users(users: &[(&str, &str)]) -> String {
    use argon2::PasswordHasher as _;
    let salt = argon2::password_hash::SaltString::encode_b64(b"web-test-salt-16").unwrap();
    let mut cfg = String::from("[web]\n");
    for (name, password) in users {
        let hash = argon2::Argon2::default().hash_password(password.as_bytes(), &salt).unwrap().to_string();
        cfg.push_str(&format!("[[web.user]]\nname = '{name}'\npassword_hash = '{hash}'\n"));
    }
    cfg
}

/// Signs in at `base` with a raw `POST /login`; the session cookie (`ncplan_session=…`).
pub(crate) fn sign_in(base: &str, name: &str, password: &str) -> String {
    let body = format!("name={name}&password={password}");
    let (head, _) = http(
        base,
        &format!(
            "POST /login HTTP/1.1\r\nHost: {{host}}\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
            body.len()
        ),
    );
    assert!(head.starts_with("HTTP/1.1 303") && head.lines().any(|l| l.trim().eq_ignore_ascii_case("location: /")), "{head}");
    head.lines()
        .find_map(|l| l.strip_prefix("set-cookie: ").or_else(|| l.strip_prefix("Set-Cookie: ")))
        .and_then(|c| c.split(';').next())
        .expect("a session cookie")
        .to_owned()
}

/// A small Fanuc program: face with T1 at `feed` and spindle `speed`, numbered `number`.
pub(crate) fn program(number: u32, feed: u32, speed: u32) -> String {
    format!("%\nO{number} (FACE)\nG21 G90 G17\nT1 M6\nS{speed} M3\nG0 X-10 Y0 Z5\nG1 Z-1 F{feed}\nX110\nY20\nX-10\nG0 Z50\nM30\n%\n")
}

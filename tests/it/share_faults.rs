//! The daemon against what a share holds besides programs, and against its own workers:
//! FIFOs, hard links, names that are not UTF-8 or hold control characters, and a worker that
//! never finishes. Real binary, real folders, real SQLite.

use std::ffi::OsStr;
use std::io::Write as _;
use std::os::unix::ffi::OsStrExt as _;
use std::path::Path;
use std::process::{Command, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use crate::faults::Site;
use crate::support::Proc;

fn program(number: u32) -> String {
    crate::support::program(number, 300, 2000)
}

fn mkfifo(path: &Path) {
    assert!(Command::new("mkfifo").arg(path).status().unwrap().success());
}

/// Sends SIGTERM; whether the process ended within `bound`.
fn terminate(p: &mut Proc, bound: Duration) -> bool {
    assert!(Command::new("kill").args(["-TERM", &p.0.id().to_string()]).status().unwrap().success());
    let deadline = Instant::now() + bound;
    while Instant::now() < deadline {
        if p.0.try_wait().unwrap().is_some() {
            return true;
        }
        std::thread::sleep(Duration::from_millis(25));
    }
    false
}

#[test]
fn files_replaced_by_fifos_are_refused_and_ingest_goes_on() {
    let site = Site::new("");
    let mut daemon = site.start();
    // Files written, then replaced by FIFOs within their settle window: more than there are
    // workers. An open of a FIFO without a writer would block its worker for good.
    for i in 1..=4 {
        let p = site.path(&format!("share/O{i}.nc"));
        std::fs::write(&p, program(i)).unwrap();
        std::thread::sleep(Duration::from_millis(60));
        std::fs::remove_file(&p).unwrap();
        mkfifo(&p);
    }
    std::fs::write(site.path("share/O9.nc"), program(9)).unwrap();
    let stored = site.wait_for("SELECT p.path FROM revisions r JOIN programs p ON p.id = r.program_id", 1);
    assert_eq!(stored.len(), 1, "ingest stopped:\n{}", site.log());
    assert!(stored[0][0].ends_with("/share/O9.nc"), "{stored:?}");
    for i in 1..=4 {
        let name = format!("O{i}.nc");
        site.wait_log(&format!("{name} reason=\"it is a FIFO"), 1);
        let said = site.log().lines().filter(|l| l.contains("Refused a file") && l.contains(&name) && l.contains("a FIFO")).count();
        assert_eq!(said, 1, "{name}:\n{}", site.log());
    }
    assert!(terminate(&mut daemon, Duration::from_secs(20)), "SIGTERM did not end the daemon:\n{}", site.log());
}

#[test]
fn a_hard_link_to_a_file_outside_the_share_is_refused_once() {
    let site = Site::new("");
    std::fs::create_dir_all(site.path("outside")).unwrap();
    std::fs::write(site.path("outside/secret.nc"), "SECRET CONTENT\n").unwrap();
    std::fs::hard_link(site.path("outside/secret.nc"), site.path("share/O5.nc")).unwrap();
    let daemon = site.start();
    std::fs::write(site.path("share/O1.nc"), program(1)).unwrap();
    site.wait_for("SELECT id FROM revisions", 1);
    // Written again through the share: still refused, not said again.
    for _ in 0..3 {
        std::fs::OpenOptions::new().append(true).open(site.path("share/O5.nc")).unwrap().write_all(b"MORE\n").unwrap();
        std::thread::sleep(Duration::from_millis(400));
    }
    let stored = site.rows(
        "SELECT p.path, CAST(b.content AS TEXT) FROM revisions r JOIN programs p ON p.id = r.program_id JOIN blobs b ON b.hash = r.hash",
    );
    assert_eq!(stored.len(), 1, "{stored:?}");
    assert!(!stored[0][1].contains("SECRET"), "{stored:?}");
    let log = site.log();
    let said = log.lines().filter(|l| l.contains("Refused a file") && l.contains("O5.nc") && l.contains("2 hard links")).count();
    assert_eq!(said, 1, "{log}");
    daemon.kill();
}

#[test]
fn names_that_are_not_utf8_or_hold_control_characters_are_stored_and_logged_escaped() {
    let site = Site::new("");
    let daemon = site.start();
    let latin1 = site.path("share").join(OsStr::from_bytes(b"PI\xc8CE.nc"));
    let forged = site.path("share").join("O2\nERROR ncplan: forged line.nc");
    std::fs::write(&latin1, program(3)).unwrap();
    std::fs::write(&forged, program(2)).unwrap();
    let rows = site.wait_for("SELECT p.path, r.status FROM revisions r JOIN programs p ON p.id = r.program_id ORDER BY p.path", 2);
    let paths: Vec<&str> = rows.iter().map(|r| r[0].rsplit('/').next().unwrap()).collect();
    assert_eq!(paths, ["O2\\x0aERROR ncplan: forged line.nc", "PI\\xc8CE.nc"], "{}", site.log());
    assert!(rows.iter().all(|r| r[1] == "analysed"), "{rows:?}");
    // The stored text names the file again.
    for (row, file) in rows.iter().zip([&forged, &latin1]) {
        assert_eq!(&ncplan::sharefile::text_path(&row[0]), file);
    }
    let log = site.log();
    assert!(log.lines().all(|l| !l.starts_with("ERROR ncplan: forged")), "a forged log line:\n{log}");
    assert!(log.lines().filter(|l| l.contains("forged line")).all(|l| l.contains("O2\\x0aERROR")), "{log}");
    daemon.kill();
}

/// Starts the daemon of `site` with a systemd notification socket; the messages it sends.
fn start_notified(site: &Site) -> (Proc, Arc<Mutex<Vec<String>>>) {
    let sock_path = site.path("notify.sock");
    let sock = std::os::unix::net::UnixDatagram::bind(&sock_path).unwrap();
    sock.set_read_timeout(Some(Duration::from_millis(200))).unwrap();
    let said = Arc::new(Mutex::new(Vec::new()));
    let heard = Arc::clone(&said);
    std::thread::spawn(move || {
        let mut buf = [0u8; 512];
        loop {
            if let Ok(n) = sock.recv(&mut buf) {
                heard.lock().unwrap().push(String::from_utf8_lossy(&buf[..n]).into_owned());
            }
            if Arc::strong_count(&heard) == 1 {
                return;
            }
        }
    });
    let log = std::fs::File::create(site.path("daemon.log")).unwrap();
    let child = Command::new(crate::bin())
        .current_dir(site.dir.path())
        .args(["watch", "--config"])
        .arg(site.path("ncplan.toml"))
        .env("NCPLAN_LOG", "debug")
        .env("NOTIFY_SOCKET", &sock_path)
        .env("WATCHDOG_USEC", "400000")
        .stdout(Stdio::null())
        .stderr(log)
        .spawn()
        .unwrap();
    site.wait_log("Catch-up scan queued", 1);
    (Proc(child), said)
}

#[test]
fn a_stuck_worker_is_replaced_its_file_quarantined_and_a_stop_still_ends() {
    // A program whose analysis runs for minutes (nested loops of a million passes each), and a
    // worker bound of three seconds (a small program takes milliseconds, even on a busy host).
    let site = Site::new("[analysis]\nmax_repeated_blocks = 1000000000\n");
    let text = std::fs::read_to_string(site.path("ncplan.toml")).unwrap();
    std::fs::write(site.path("ncplan.toml"), text.replace("settle_ms = 200\n", "settle_ms = 200\nworker_timeout_s = 3\n")).unwrap();
    let (mut daemon, said) = start_notified(&site);
    let spin = "%\nO9 (SPIN)\n#1=0\nWHILE[#1LT1000000]DO1\n#2=0\nWHILE[#2LT1000000]DO2\n#2=#2+1\nEND2\n#1=#1+1\nEND1\nM30\n%\n";
    std::fs::write(site.path("share/O9.nc"), spin).unwrap();
    let quarantined = site.wait_for(
        "SELECT r.status, d.message FROM revisions r JOIN programs p ON p.id = r.program_id JOIN diagnostics d ON d.revision_id = r.id
         WHERE p.path LIKE '%O9.nc'",
        1,
    );
    assert_eq!(quarantined.len(), 1, "{}", site.log());
    assert_eq!(quarantined[0][0], "failed");
    assert!(quarantined[0][1].contains("worker bound of 3 s"), "{quarantined:?}");
    assert_eq!(site.wait_log("did not finish a file within the worker bound", 1), 1, "{}", site.log());
    // The replaced worker's place works: a new file is analysed and stored.
    let pings_before = said.lock().unwrap().iter().filter(|m| *m == "WATCHDOG=1").count();
    std::fs::write(site.path("share/O1.nc"), program(1)).unwrap();
    let ok = site.wait_for("SELECT r.status FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.path LIKE '%O1.nc'", 1);
    assert_eq!(ok, [["analysed"]], "{}", site.log());
    // Work advances again, so the watchdog is pinged.
    crate::support::wait_until("a watchdog ping after the replacement", Duration::from_secs(10), || {
        said.lock().unwrap().iter().filter(|m| *m == "WATCHDOG=1").count() > pings_before
    });
    assert!(said.lock().unwrap().iter().any(|m| m == "READY=1"));
    // The stuck thread still runs; a stop does not wait for it.
    assert!(terminate(&mut daemon, Duration::from_secs(30)), "SIGTERM did not end the daemon:\n{}", site.log());
    // The quarantined content is not tried again at the next start.
    let daemon = site.start();
    assert_eq!(site.wait_log("Caught up with the folders", 1), 1, "{}", site.log());
    assert!(!site.log().contains("worker bound"), "{}", site.log());
    assert_eq!(site.rows("SELECT id FROM revisions").len(), 2);
    daemon.kill();
}

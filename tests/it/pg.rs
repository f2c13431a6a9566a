//! The store on a real PostgreSQL server, which each test starts for itself (`initdb` in a
//! temporary folder, as a non-root user, on a free local port) and stops at its end: the
//! daemon and the read commands give what they give on SQLite; four daemons of four sites
//! write to one database through bursts of edits and kills, and every revision is stored
//! once and compared. Without PostgreSQL the tests say so and skip, unless
//! `NCPLAN_REQUIRE_POSTGRES` is set (CI sets it).

use std::path::PathBuf;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use ncplan::store::{Location, Store};

use crate::support::{Proc, free_port, http, program, urlencode, wait_until, watch};

/// A PostgreSQL cluster of one test.
pub(crate) struct Cluster {
    dir: tempfile::TempDir,
    bin: PathBuf,
    port: u16,
    /// The user the server runs as when the tests run as root.
    user: Option<&'static str>,
}

/// The folder holding `initdb` and `pg_ctl`: on the `PATH`, or Debian's `/usr/lib/postgresql/*/bin`.
fn pg_bin() -> Option<PathBuf> {
    let on_path = std::env::var_os("PATH")
        .map(|p| std::env::split_paths(&p).collect::<Vec<_>>())
        .unwrap_or_default()
        .into_iter()
        .find(|d| d.join("initdb").is_file() && d.join("pg_ctl").is_file());
    if on_path.is_some() {
        return on_path;
    }
    let mut debian: Vec<PathBuf> = std::fs::read_dir("/usr/lib/postgresql")
        .ok()?
        .flatten()
        .map(|e| e.path().join("bin"))
        .filter(|d| d.join("initdb").is_file() && d.join("pg_ctl").is_file())
        .collect();
    debian.sort();
    debian.pop()
}

fn is_root() -> bool {
    Command::new("id").arg("-u").output().is_ok_and(|o| String::from_utf8_lossy(&o.stdout).trim() == "0")
}

impl Cluster {
    /// Starts a cluster, or says why `test` is skipped and returns `None`.
    pub(crate) fn start(test: &str) -> Option<Cluster> {
        Cluster::start_with(test, "", |_| {})
    }

    /// Starts a cluster with the server options `extra`, after `prepare` has put what they
    /// name into the cluster's folder.
    fn start_with(test: &str, extra: &str, prepare: impl FnOnce(&std::path::Path)) -> Option<Cluster> {
        let Some(bin) = pg_bin() else {
            assert!(
                std::env::var_os("NCPLAN_REQUIRE_POSTGRES").is_none(),
                "NCPLAN_REQUIRE_POSTGRES is set but initdb and pg_ctl are neither on the PATH nor in /usr/lib/postgresql/*/bin"
            );
            crate::skip(test, "PostgreSQL is not installed (initdb, pg_ctl; Debian: apt-get install postgresql)");
            return None;
        };
        let dir = tempfile::Builder::new().prefix("ncplan-pg").tempdir().unwrap();
        // PostgreSQL refuses to run as root: the server runs as `nobody` then.
        let user = is_root().then_some("nobody");
        if let Some(u) = user {
            let ok = Command::new("chown").args(["-R", u]).arg(dir.path()).status().unwrap().success();
            assert!(ok, "cannot hand {} to {u}", dir.path().display());
        }
        let c = Cluster { dir, bin, port: free_port(), user };
        let data = c.dir.path().join("data");
        c.run("initdb", &["-D", data.to_str().unwrap(), "-U", "ncplan", "--auth=trust", "-E", "UTF8", "--locale=C", "--no-sync"]);
        prepare(c.dir.path());
        if let Some(u) = user {
            let ok = Command::new("chown").args(["-R", u]).arg(c.dir.path()).status().unwrap().success();
            assert!(ok, "cannot hand {} to {u}", c.dir.path().display());
        }
        let opts = format!(
            "-p {} -k {} -c listen_addresses=127.0.0.1 -c fsync=off -c synchronous_commit=off -c max_connections=200 {extra}",
            c.port,
            c.dir.path().display()
        );
        let log = c.dir.path().join("server.log");
        c.run("pg_ctl", &["-D", data.to_str().unwrap(), "-l", log.to_str().unwrap(), "-o", &opts, "-w", "-t", "60", "start"]);
        Some(c)
    }

    fn run(&self, tool: &str, args: &[&str]) {
        let exe = self.bin.join(tool);
        let mut cmd = match self.user {
            Some(u) => {
                let mut c = Command::new("runuser");
                c.args(["-u", u, "--"]).arg(&exe);
                c
            }
            None => Command::new(&exe),
        };
        let out = cmd.args(args).current_dir(self.dir.path()).stdin(Stdio::null()).output().unwrap();
        assert!(out.status.success(), "{tool} failed: {}{}", String::from_utf8_lossy(&out.stdout), String::from_utf8_lossy(&out.stderr));
    }

    /// The database URL (trust authentication on the loopback: no password).
    pub(crate) fn url(&self) -> String {
        format!("postgresql://ncplan@127.0.0.1:{}/postgres?sslmode=disable", self.port)
    }

    /// Rows of `sql`, read-only.
    fn rows(&self, sql: &str) -> Vec<Vec<String>> {
        Store::open_read_only(&Location::parse(&self.url())).unwrap().query(sql).unwrap().1
    }

    /// The one number `sql` gives.
    fn count(&self, sql: &str) -> i64 {
        self.rows(sql)[0][0].parse().unwrap()
    }
}

impl Drop for Cluster {
    fn drop(&mut self) {
        let data = self.dir.path().join("data");
        self.run("pg_ctl", &["-D", data.to_str().unwrap(), "-m", "immediate", "-w", "stop"]);
    }
}

/// One DNC server: a CAM folder and a share `DMU50`, a config naming `site` and `database`.
struct Server {
    dir: tempfile::TempDir,
}

impl Server {
    fn new(site: Option<&str>, database: &str) -> Server {
        let dir = tempfile::tempdir().unwrap();
        for d in ["cam", "share", "var"] {
            std::fs::create_dir_all(dir.path().join(d)).unwrap();
        }
        let site = site.map(|s| format!("site = '{s}'\n")).unwrap_or_default();
        std::fs::write(
            dir.path().join("ncplan.toml"),
            format!(
                "{site}[database]\n{database}\n[daemon]\nsettle_ms = 150\nworkers = 2\n\
                 [[cam]]\npath = 'cam'\ndialect = 'fanuc'\n\
                 [[machine]]\nname = 'DMU50'\npath = 'share'\ndialect = 'fanuc'\n"
            ),
        )
        .unwrap();
        Server { dir }
    }

    fn path(&self, rel: &str) -> PathBuf {
        self.dir.path().join(rel)
    }

    fn start(&self) -> Proc {
        let log = std::fs::OpenOptions::new().create(true).append(true).open(self.path("daemon.log")).unwrap();
        let before = self.log().matches("Catch-up scan queued").count();
        let daemon = watch(&self.path("ncplan.toml"), "info", log);
        let deadline = Instant::now() + Duration::from_secs(30);
        while self.log().matches("Catch-up scan queued").count() <= before {
            assert!(Instant::now() < deadline, "the daemon did not start:\n{}", self.log());
            std::thread::sleep(Duration::from_millis(20));
        }
        daemon
    }

    fn log(&self) -> String {
        std::fs::read_to_string(self.path("daemon.log")).unwrap_or_default()
    }

    /// Writes a program whole (a temporary name, then a rename), as a DNC transfer ends.
    fn put(&self, rel: &str, text: &str) {
        let tmp = self.path(&format!("{rel}.part"));
        std::fs::write(&tmp, text).unwrap();
        std::fs::rename(&tmp, self.path(rel)).unwrap();
    }

    fn ncplan(&self, args: &[&str]) -> (i32, String, String) {
        let out = Command::new(crate::bin()).args(args).current_dir(self.dir.path()).output().unwrap();
        (
            out.status.code().unwrap_or(-1),
            String::from_utf8_lossy(&out.stdout).into_owned(),
            String::from_utf8_lossy(&out.stderr).into_owned(),
        )
    }
}

fn sha256(text: &str) -> String {
    ncplan::daemon::ingest::sha256_hex(text.as_bytes())
}

/// The rows the read commands give for the demo edit, on either engine.
fn one_edit(server: &Server, db: &str, rows: impl Fn(&str) -> Vec<Vec<String>>) -> Vec<String> {
    let daemon = server.start();
    server.put("share/O1234.nc", &program(1234, 300, 2000));
    server.put("cam/O1234.nc", &program(1234, 250, 1800));
    wait_until("the edit is compared", Duration::from_secs(30), || {
        rows("SELECT COUNT(*) FROM comparisons").first().is_some_and(|r| r[0] == "1")
    });
    daemon.kill();
    let mut out = Vec::new();
    for sql in [
        "SELECT machine, program, kind, field, before, after, workingstep, operation, line, deviation, site FROM shopfloor_changes ORDER BY change_id",
        "SELECT p.role, r.status, r.size, r.encoding, r.name, pl.workingsteps, pl.tools, pl.complete FROM revisions r JOIN programs p ON p.id = r.program_id LEFT JOIN plans pl ON pl.revision_id = r.id ORDER BY p.role, r.id",
        "SELECT idx, operation, tool, feature, strategy, feed, spindle_speed, spindle, coolant, depth, first_line, last_line FROM workingsteps ORDER BY revision_id, idx",
        "SELECT kind, x, y, z, depth, width, length, positions, top_inferred, workingsteps FROM features ORDER BY revision_id, id",
        "SELECT code, severity, line, col, message FROM diagnostics ORDER BY revision_id, id",
        "SELECT rule, changes FROM comparisons",
        "SELECT m.name, m.dialect, m.site, p.site, k.rule, k.key FROM programs p LEFT JOIN machines m ON m.id = p.machine_id JOIN program_keys k ON k.program_id = p.id ORDER BY p.role, k.rule",
    ] {
        // Which of the two files was stored first is the watcher's timing, not the engine's.
        let mut lines: Vec<String> = rows(sql).iter().map(|r| r.join("|")).collect();
        lines.sort();
        out.push(format!("{sql}\n{}", lines.join("\n")));
    }
    let (code, report, err) = server.ncplan(&["report", "--db", db]);
    assert_eq!(code, 0, "{err}");
    // The report names revisions and times; what it says of them is compared.
    out.push(report.lines().filter(|l| l.starts_with("- ")).collect::<Vec<_>>().join("\n"));
    // The CSV report (the workspace's change rows) without its ids and times.
    let (code, csv, err) = server.ncplan(&["report", "--db", db, "--format", "csv", "--since", "2000-01-01"]);
    assert_eq!(code, 0, "{err}");
    assert!(csv.lines().count() > 1, "{csv}");
    out.push(
        csv.lines()
            .map(|l| {
                let f: Vec<&str> = l.split(',').collect();
                [0, 1, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13].iter().filter_map(|&i| f.get(i).copied()).collect::<Vec<_>>().join(",")
            })
            .collect::<Vec<_>>()
            .join("\n"),
    );
    let (code, show, err) = server.ncplan(&["show", "--db", db, "share/O1234.nc"]);
    assert_eq!(code, 0, "{err}");
    out.push(
        show.lines()
            .filter(|l| l.contains("change") || l.contains("finding") || l.starts_with("  "))
            .map(redact_times)
            .collect::<Vec<_>>()
            .join("\n"),
    );
    out
}

/// A line of `show` without its paths, ids and times.
fn redact_times(line: &str) -> String {
    line.split_whitespace()
        .filter(|w| !w.contains('/') && !w.contains(':') && !w.chars().all(|c| c.is_ascii_digit() || c == ','))
        .collect::<Vec<_>>()
        .join(" ")
}

#[test]
fn the_daemon_and_the_read_commands_give_the_same_on_both_engines() {
    let Some(pg) = Cluster::start("pg::the_daemon_and_the_read_commands_give_the_same_on_both_engines") else { return };
    let lite = Server::new(Some("HALL1"), "path = 'var/ncplan.db'");
    let lite_db = lite.path("var/ncplan.db");
    let on_lite = one_edit(&lite, lite_db.to_str().unwrap(), |sql| crate::db_rows(&lite_db, sql));
    let server = Server::new(Some("HALL1"), &format!("url = '{}'", pg.url()));
    let on_pg = one_edit(&server, &pg.url(), |sql| pg.rows(sql));
    assert!(on_lite[0].lines().count() > 1, "the edit made changes: {}", on_lite[0]);
    for (a, b) in on_lite.iter().zip(&on_pg) {
        assert_eq!(a, b);
    }
    // The same schema version and view columns.
    let store = Store::open_read_only(&Location::parse(&pg.url())).unwrap();
    let lite_store = Store::open_read_only(&Location::Sqlite(lite_db.clone())).unwrap();
    assert_eq!(store.version().unwrap(), lite_store.version().unwrap());
    assert_eq!(store.query("SELECT * FROM shopfloor_changes").unwrap().0, lite_store.query("SELECT * FROM shopfloor_changes").unwrap().0);
}

#[test]
fn query_on_postgres_reads_only_and_refuses_in_plain_words() {
    let Some(pg) = Cluster::start("pg::query_on_postgres_reads_only_and_refuses_in_plain_words") else { return };
    let server = Server::new(Some("HALL1"), &format!("url = '{}'", pg.url()));
    drop(Store::open(&Location::parse(&pg.url()), "HALL1").unwrap());
    let url = pg.url();
    let (code, out, err) = server.ncplan(&["query", "--db", &url, "SELECT COUNT(*) AS n, 1 = 1 AS yes FROM revisions"]);
    assert_eq!((code, out.as_str()), (0, "n\tyes\n0\t1\n"), "{err}");
    let (code, _, err) = server.ncplan(&["query", "--db", &url, "DROP TABLE changes"]);
    assert_eq!(code, 2);
    assert!(err.contains("`DROP` is refused: queries only read"), "{err}");
    let (code, _, err) =
        server.ncplan(&["query", "--db", &url, "WITH gone AS (DELETE FROM changes RETURNING id) SELECT COUNT(*) FROM gone"]);
    assert_eq!(code, 2);
    assert!(err.contains("the query would write; queries only read"), "{err}");
    let (code, _, err) = server.ncplan(&["query", "--db", &url, "SELECT 1; DELETE FROM blobs"]);
    assert_eq!(code, 2);
    assert!(err.contains("one statement at a time"), "{err}");
    // Revisions and blobs are immutable on this engine too.
    let (code, _, err) = server.ncplan(&["query", "--db", &url, "SELECT nosuchcolumn FROM revisions"]);
    assert_eq!(code, 2);
    assert!(err.contains("nosuchcolumn") && err.contains("does not exist"), "{err}");
}

#[test]
fn credentials_come_from_a_private_file_and_are_never_shown() {
    use std::os::unix::fs::PermissionsExt as _;
    let Some(pg) = Cluster::start("pg::credentials_come_from_a_private_file_and_are_never_shown") else { return };
    let server = Server::new(Some("HALL1"), "url = 'x'");
    let secret = server.path("db.password");
    std::fs::write(&secret, "s3cret-pass\n").unwrap();
    std::fs::set_permissions(&secret, std::fs::Permissions::from_mode(0o644)).unwrap();
    let config = format!(
        "site = 'HALL1'\n[database]\nurl = '{}'\npassword_file = '{}'\n[[machine]]\nname = 'DMU50'\npath = 'share'\ndialect = 'fanuc'\n",
        pg.url(),
        secret.display()
    );
    std::fs::write(server.path("ncplan.toml"), &config).unwrap();
    let (code, _, err) = server.ncplan(&["report", "--config", server.path("ncplan.toml").to_str().unwrap()]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("may be read by others (mode 644)") && !err.contains("s3cret"), "{err}");
    std::fs::set_permissions(&secret, std::fs::Permissions::from_mode(0o600)).unwrap();
    // Trust authentication takes any password: the file is read and the report runs.
    drop(Store::open(&Location::parse(&pg.url()), "HALL1").unwrap());
    let (code, _, err) = server.ncplan(&["report", "--config", server.path("ncplan.toml").to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    // A password in a URL is never shown, not even when the server cannot be reached.
    let dead = format!("postgresql://ncplan:hunter2@127.0.0.1:{}/x?sslmode=disable", free_port());
    let (code, _, err) = server.ncplan(&["query", "--db", &dead, "SELECT 1"]);
    assert_eq!(code, 2);
    assert!(!err.contains("hunter2") && err.contains("PostgreSQL"), "{err}");
    // sslmode is honoured: this test server offers no TLS, which `require` refuses and `prefer` accepts.
    let with_mode = |mode: &str| pg.url().replace("sslmode=disable", &format!("sslmode={mode}"));
    let (code, _, err) = server.ncplan(&["query", "--db", &with_mode("require"), "SELECT 1"]);
    assert_eq!(code, 2);
    assert!(err.contains("server does not support TLS"), "{err}");
    let (code, out, err) = server.ncplan(&["query", "--db", &with_mode("prefer"), "SELECT 1 AS one"]);
    assert_eq!((code, out.as_str()), (0, "one\n1\n"), "{err}");
    let (code, _, err) = server.ncplan(&["query", "--db", &with_mode("bogus"), "SELECT 1"]);
    assert_eq!(code, 2);
    assert!(err.contains("sslmode `bogus` is not one of"), "{err}");
    // A PostgreSQL database needs the site named.
    std::fs::write(server.path("ncplan.toml"), config.replace("site = 'HALL1'\n", "")).unwrap();
    let (code, _, err) = server.ncplan(&["watch", "--config", server.path("ncplan.toml").to_str().unwrap()]);
    assert_ne!(code, 0);
    assert!(err.contains("name this one's site"), "{err}");
}

#[test]
fn four_daemons_of_four_sites_store_every_revision_once_through_bursts_and_kills() {
    let Some(pg) = Cluster::start("pg::four_daemons_of_four_sites_store_every_revision_once_through_bursts_and_kills") else { return };
    let servers: Vec<Server> = (1..=4).map(|i| Server::new(Some(&format!("HALL{i}")), &format!("url = '{}'", pg.url()))).collect();
    // Started one after the other would hide a migration race: all four at once.
    let mut daemons: Vec<Option<Proc>> = std::thread::scope(|s| {
        let started: Vec<_> = servers.iter().map(|srv| s.spawn(move || srv.start())).collect();
        started.into_iter().map(|h| Some(h.join().unwrap())).collect()
    });
    const PROGRAMS: u32 = 4;
    const ROUNDS: u32 = 8;
    // Half the originals come before their edits, half after the first edits.
    for srv in &servers {
        for n in 0..PROGRAMS / 2 {
            srv.put(&format!("cam/O{}.nc", 100 + n), &program(100 + n, 250, 1800));
        }
    }
    for round in 0..ROUNDS {
        std::thread::scope(|s| {
            for (i, srv) in servers.iter().enumerate() {
                s.spawn(move || {
                    for n in 0..PROGRAMS {
                        // Each site's edit differs from every other, so equal contents never meet.
                        srv.put(&format!("share/O{}.nc", 100 + n), &program(100 + n, 300 + round * 10 + i as u32, 2000));
                    }
                });
            }
        });
        if round == 1 {
            for srv in &servers {
                for n in PROGRAMS / 2..PROGRAMS {
                    srv.put(&format!("cam/O{}.nc", 100 + n), &program(100 + n, 250, 1800));
                }
            }
        }
        if round == 3 {
            // Mid-burst: two daemons die.
            daemons[1].take().unwrap().kill();
            daemons[2].take().unwrap().kill();
        }
        if round == 5 {
            daemons[1] = Some(servers[1].start());
            daemons[2] = Some(servers[2].start());
        }
        std::thread::sleep(Duration::from_millis(if round % 2 == 0 { 60 } else { 400 }));
    }
    // Every file's final content ends up the newest revision of its path.
    let finals: Vec<(String, String, String)> = servers
        .iter()
        .enumerate()
        .flat_map(|(i, srv)| {
            (0..PROGRAMS).flat_map(move |n| {
                let share = srv.path(&format!("share/O{}.nc", 100 + n));
                let cam = srv.path(&format!("cam/O{}.nc", 100 + n));
                let site = format!("HALL{}", i + 1);
                [share, cam].map(|p| (site.clone(), p.display().to_string(), sha256(&std::fs::read_to_string(&p).unwrap())))
            })
        })
        .collect();
    wait_until("every final content is stored and compared", Duration::from_secs(60), || {
        let latest = pg.rows(
            "SELECT p.site, p.path, r.hash FROM revisions r JOIN programs p ON p.id = r.program_id
             WHERE r.id = (SELECT MAX(id) FROM revisions WHERE program_id = p.id)",
        );
        let stored = finals.iter().all(|(site, path, hash)| latest.iter().any(|r| &r[0] == site && &r[1] == path && &r[2] == hash));
        stored && pg.count(UNCOMPARED) == 0
    });
    drop(daemons);
    let revisions = pg.count("SELECT COUNT(*) FROM revisions");
    // No content of a program is stored twice (no edit here returns to an earlier content).
    assert_eq!(pg.count("SELECT COUNT(*) FROM (SELECT program_id, hash FROM revisions GROUP BY 1, 2 HAVING COUNT(*) > 1) d"), 0);
    // Each site has its own DMU50 and its own programs; the same program numbers do not collide.
    assert_eq!(
        pg.rows("SELECT site, name FROM machines ORDER BY site"),
        (1..=4).map(|i| vec![format!("HALL{i}"), "DMU50".into()]).collect::<Vec<_>>()
    );
    assert_eq!(pg.count("SELECT COUNT(*) FROM programs"), i64::from(4 * 2 * PROGRAMS));
    // Every analysed edit is compared, with its own site's original and that original's newest content.
    assert_eq!(pg.count(UNCOMPARED), 0);
    assert_eq!(
        pg.count(
            "SELECT COUNT(*) FROM comparisons c JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id
             JOIN revisions o ON o.id = c.original_revision_id JOIN programs op ON op.id = o.program_id
             WHERE op.site <> p.site OR op.role <> 'cam' OR op.stem <> p.stem"
        ),
        0
    );
    // Every edit's changes name its own feed against the original's 250.
    let wrong = pg.count(
        "SELECT COUNT(*) FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.role = 'machine' AND r.status = 'analysed'
         AND NOT EXISTS (SELECT 1 FROM changes c WHERE c.revision_id = r.id AND c.kind = 'feed_changed' AND c.before LIKE '%250%')",
    );
    assert_eq!(wrong, 0);
    // A kill mid-analysis is a revision stored as failed, never a revision lost or doubled.
    let failed = pg.count("SELECT COUNT(*) FROM revisions WHERE status <> 'analysed'");
    assert!(failed <= 2, "{failed} revisions not analysed");
    assert!(revisions >= i64::from(4 * PROGRAMS * 2), "{revisions} revisions");
    let blobs = pg.count("SELECT COUNT(*) FROM blobs");
    let distinct = pg.count("SELECT COUNT(DISTINCT hash) FROM revisions");
    assert_eq!(blobs, distinct, "blobs are shared across the plant by hash");
    // The CAM originals are the same bytes on every site: one blob each.
    assert_eq!(
        pg.count("SELECT COUNT(DISTINCT r.hash) FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.role = 'cam'"),
        i64::from(PROGRAMS)
    );
    use std::io::Write as _;
    let _ = writeln!(
        std::io::stderr(),
        "four daemons: {revisions} revisions of {} programs on 4 sites, {blobs} blobs, {failed} stored unanalysed after the kills",
        4 * 2 * PROGRAMS
    );
}

/// Usable edits without a comparison.
const UNCOMPARED: &str = "SELECT COUNT(*) FROM revisions r JOIN programs p ON p.id = r.program_id
     WHERE p.role = 'machine' AND r.status = 'analysed'
       AND NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = r.id)
       AND NOT EXISTS (SELECT 1 FROM comparisons c WHERE c.revision_id = r.id)";

#[test]
fn migrate_copies_a_servers_history_into_the_plant_database_and_resumes() {
    let Some(pg) = Cluster::start("pg::migrate_copies_a_servers_history_into_the_plant_database_and_resumes") else { return };
    let lite = Server::new(Some("HALL7"), "path = 'var/ncplan.db'");
    let db = lite.path("var/ncplan.db");
    let daemon = lite.start();
    lite.put("cam/O1234.nc", &program(1234, 250, 1800));
    lite.put("share/O1234.nc", &program(1234, 300, 2000));
    wait_until("the edit is compared", Duration::from_secs(30), || crate::db_rows(&db, "SELECT COUNT(*) FROM comparisons") == [["1"]]);
    daemon.kill();
    // A planner's review mark on the speed change goes along with it.
    let speed: i64 = crate::db_rows(&db, "SELECT id FROM changes WHERE kind = 'spindle_speed_changed'")[0][0].parse().unwrap();
    Store::open(&Location::Sqlite(db.clone()), "HALL7")
        .unwrap()
        .add_mark(speed, "adopt", "kept", "ada", "2026-03-01T00:00:00.000Z")
        .unwrap();
    let url = pg.url();
    let (code, out, err) = lite.ncplan(&["migrate", "--from", db.to_str().unwrap(), "--to", &url, "--site", "HALL7"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("2 revisions, 2 copied now, 0 already there; 1 comparisons copied; 1 review marks"), "{out}");
    const MARKS: &str = "SELECT c.kind, c.before, c.after, v.kind, v.mark, v.note, v.marked_by, v.marked_at
                         FROM review_marks v JOIN changes c ON c.id = v.change_id AND c.revision_id = v.revision_id";
    assert_eq!(pg.rows(MARKS), crate::db_rows(&db, MARKS));
    assert_eq!(pg.rows(MARKS).len(), 1);
    const SHOWN: &str = "SELECT machine, program, kind, before, after, line FROM shopfloor_changes ORDER BY change_id";
    let copied = pg.rows(SHOWN);
    assert!(!copied.is_empty());
    assert_eq!(copied, crate::db_rows(&db, SHOWN));
    assert_eq!(pg.rows("SELECT DISTINCT site FROM programs"), [["HALL7"]]);
    // More history on the server, and migrate again: only what is new is copied.
    let daemon = lite.start();
    lite.put("share/O1234.nc", &program(1234, 320, 2000));
    wait_until("the second edit is compared", Duration::from_secs(30), || {
        crate::db_rows(&db, "SELECT COUNT(*) FROM comparisons") == [["2"]]
    });
    daemon.kill();
    let (code, out, err) = lite.ncplan(&["migrate", "--from", db.to_str().unwrap(), "--to", &url, "--site", "HALL7"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("3 revisions, 1 copied now, 2 already there; 1 comparisons copied"), "{out}");
    assert_eq!(pg.rows(MARKS), crate::db_rows(&db, MARKS), "a mark is copied once");
    assert_eq!(pg.rows(SHOWN), crate::db_rows(&db, SHOWN));
    for table in ["revisions", "blobs", "plans", "diagnostics", "comparisons", "changes", "workingsteps", "features", "program_keys"] {
        let sql = format!("SELECT COUNT(*) FROM {table}");
        assert_eq!(pg.rows(&sql), crate::db_rows(&db, &sql), "{table}");
    }
    // History is copied as some site's: without one named, nothing is.
    let (code, _, err) = lite.ncplan(&["migrate", "--from", db.to_str().unwrap(), "--to", &url]);
    assert_eq!(code, 2);
    assert!(err.contains("name the site"), "{err}");
}

/// A store on each engine for a store test: SQLite in memory, and PostgreSQL on a cluster of
/// its own when one can be started (the cluster stops when the engine is dropped).
pub(crate) struct Engine {
    pub(crate) store: Store,
    _cluster: Option<Cluster>,
}

/// The engines `test` runs on.
pub(crate) fn engines(test: &str) -> Vec<Engine> {
    let mut out = vec![Engine { store: Store::open_in_memory().unwrap(), _cluster: None }];
    if let Some(c) = Cluster::start(&format!("{test} on PostgreSQL")) {
        out.push(Engine { store: Store::open(&Location::parse(&c.url()), "").unwrap(), _cluster: Some(c) });
    }
    out
}

/// A longer program, so that reading it again takes a moment: `rows` passes at `feed`.
fn long_program(number: u32, feed: u32, rows: u32) -> String {
    let mut p = format!("%\nO{number} (SURFACE)\nG21 G90 G17\nT1 M6\nS2000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F{feed}\n");
    for r in 0..rows {
        p.push_str(&format!("X100 Y{}\nX0 Y{}\n", r * 2, r * 2 + 1));
    }
    p.push_str("G0 Z50\nM30\n%\n");
    p
}

#[test]
fn three_workers_one_killed_mid_batch_read_every_revision_again_exactly_once() {
    let Some(pg) = Cluster::start("pg::three_workers_one_killed_mid_batch_read_every_revision_again_exactly_once") else { return };
    let server = Server::new(Some("HALL1"), &format!("url = '{}'", pg.url()));
    const PROGRAMS: u32 = 24;
    let daemon = server.start();
    for n in 0..PROGRAMS {
        server.put(&format!("cam/O{}.nc", 200 + n), &long_program(200 + n, 250, 400));
        server.put(&format!("share/O{}.nc", 200 + n), &long_program(200 + n, 300, 400));
    }
    wait_until("every edit is compared", Duration::from_secs(120), || pg.count("SELECT COUNT(*) FROM comparisons") == i64::from(PROGRAMS));
    daemon.kill();
    let config = server.path("ncplan.toml");
    let args = |cmd: &str| -> Vec<String> {
        [cmd, "--config", config.to_str().unwrap(), "--jobs", "1", "--lease", "3"].iter().map(|s| (*s).to_owned()).collect()
    };
    let spawn = |a: Vec<String>| {
        Command::new(crate::bin()).current_dir(server.dir.path()).args(a).stdout(Stdio::piped()).stderr(Stdio::piped()).spawn().unwrap()
    };
    // The first queues everything and starts; two workers join; the first dies holding a batch.
    let mut first = spawn(args("reanalyze"));
    wait_until("the archive is queued", Duration::from_secs(30), || pg.count("SELECT COUNT(*) FROM reanalysis_queue") > 0);
    let second = spawn(args("worker"));
    let third = spawn(args("worker"));
    let holder = format!("%:{}/%", first.id());
    wait_until("the first worker holds a batch", Duration::from_secs(30), || {
        pg.count(&format!("SELECT COUNT(*) FROM reanalysis_queue WHERE worker LIKE '{holder}'")) > 0
    });
    first.kill().unwrap();
    first.wait().unwrap();
    let held = pg.count(&format!("SELECT COUNT(*) FROM reanalysis_queue WHERE worker LIKE '{holder}'"));
    assert!(held > 0, "the killed worker held a batch");
    let (a, b) = (second.wait_with_output().unwrap(), third.wait_with_output().unwrap());
    for o in [&a, &b] {
        assert!(o.status.success(), "{}{}", String::from_utf8_lossy(&o.stdout), String::from_utf8_lossy(&o.stderr));
    }
    let revisions = i64::from(2 * PROGRAMS);
    // Every revision once for this version, the killed worker's batch taken over after its lease.
    assert_eq!(pg.count("SELECT COUNT(*) FROM reanalysis_queue"), 0);
    assert_eq!(pg.count("SELECT COUNT(*) FROM analyses"), revisions);
    assert_eq!(pg.count("SELECT COUNT(DISTINCT version) FROM analyses"), 1);
    assert_eq!(pg.count("SELECT COUNT(*) FROM plans WHERE analysis <> ''"), revisions);
    let by_others = pg.count(&format!("SELECT COUNT(*) FROM analyses WHERE worker NOT LIKE '{holder}'"));
    assert!(by_others >= held, "{by_others} read by the survivors, {held} held by the killed one");
    let read: usize = [&a, &b]
        .iter()
        .map(|o| {
            let out = String::from_utf8_lossy(&o.stdout).into_owned();
            out.split(": ")
                .nth(1)
                .and_then(|t| t.split_whitespace().next())
                .and_then(|n| n.parse::<usize>().ok())
                .unwrap_or_else(|| panic!("{out}"))
        })
        .sum();
    assert_eq!(read as i64, by_others);
    // The old results are kept, with the version that made them (the ingest's: ''); the
    // comparisons were made again and still find the feed change.
    assert_eq!(pg.count("SELECT COUNT(*) FROM analyses WHERE previous = '' AND previous_plan IS NOT NULL"), revisions);
    assert_eq!(pg.count("SELECT COUNT(*) FROM changes WHERE kind = 'feed_changed'"), i64::from(PROGRAMS));
    // Nothing changed in the dictionary: same plans, no new or vanished findings.
    assert_eq!(pg.count("SELECT COUNT(*) FROM analyses WHERE plan_changed = 1 OR new_findings > 0 OR vanished_findings > 0"), 0);
    // Again: nothing is left to read for this version.
    let (code, out, err) = server.ncplan(&args("reanalyze").iter().map(String::as_str).collect::<Vec<_>>());
    assert_eq!(code, 0, "{err}");
    assert!(out.contains(": 0 revisions read again"), "{out}");
}

#[test]
fn reanalyze_on_sqlite_reads_every_revision_again_once_and_keeps_the_old_results() {
    let server = Server::new(None, "path = 'var/ncplan.db'");
    let db = server.path("var/ncplan.db");
    let daemon = server.start();
    server.put("cam/O1.nc", &program(1, 250, 1800));
    server.put("share/O1.nc", &program(1, 300, 2000));
    wait_until("the edit is compared", Duration::from_secs(30), || crate::db_rows(&db, "SELECT COUNT(*) FROM comparisons") == [["1"]]);
    daemon.kill();
    let config = server.path("ncplan.toml");
    let (code, out, err) = server.ncplan(&["reanalyze", "--config", config.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains(": 2 revisions read again, 0 plans changed, 0 new findings, 0 vanished; 1 comparisons made again"), "{out}");
    assert_eq!(crate::db_rows(&db, "SELECT COUNT(*), COUNT(previous_plan) FROM analyses"), [["2", "2"]]);
    assert_eq!(crate::db_rows(&db, "SELECT kind FROM shopfloor_changes ORDER BY change_id"), [["feed_changed"], ["spindle_speed_changed"]]);
    let (code, out, _) = server.ncplan(&["reanalyze", "--config", config.to_str().unwrap(), "--since", "2000-01-01"]);
    assert_eq!(code, 0);
    assert!(out.contains(": 0 revisions read again"), "{out}");
}

/// `ncplan serve` with `args`, until dropped; its base URL.
fn serve(server: &Server, args: &[&str]) -> (Proc, String) {
    crate::support::serve(&server.path("ncplan.toml"), args)
}

const SESSION: &str = "ncplan_session=0123456789abcdef0123456789abcdef0123456789abcdef0123456789abcdef";

fn get(base: &str, path: &str) -> (String, String) {
    http(base, &format!("GET {path} HTTP/1.1\r\nHost: {{host}}\r\nCookie: {SESSION}\r\nConnection: close\r\n\r\n"))
}

/// `text` with every `value="…"` after `name="csrf"` (the token is the session's and the
/// server's secret's), the console's list of the knowledge pages' queries, and, with `sql`, every `/sql?q=…` link and `<pre class="sql">`
/// (a knowledge page's SQL is in its engine's words) replaced by a mark.
fn masked(text: &str, sql: bool) -> String {
    let mut out = text.to_owned();
    let mut cut = |from: &str, to: &str| {
        let mut done = String::new();
        let mut rest = out.as_str();
        while let Some(i) = rest.find(from) {
            let start = i + from.len();
            let end = rest[start..].find(to).map_or(rest.len(), |j| start + j);
            done.push_str(&rest[..start]);
            done.push('…');
            rest = &rest[end..];
        }
        done.push_str(rest);
        out = done;
    };
    cut("name=\"csrf\" value=\"", "\"");
    // The console lists the knowledge pages' queries, each in its engine's words.
    cut("<h3>The knowledge pages' queries</h3>", "<h3>");
    if sql {
        cut("href=\"/sql?q=", "\"");
        cut("<pre class=\"sql\">", "</pre>");
    }
    out
}

#[test]
fn serve_on_postgres_renders_every_page_as_on_sqlite_and_records_review_marks() {
    let Some(pg) = Cluster::start("pg::serve_on_postgres_renders_every_page_as_on_sqlite_and_records_review_marks") else { return };
    // A real daemon on real folders builds the SQLite file: two originals, then their edits.
    let lite = Server::new(Some("HALL1"), "path = 'var/ncplan.db'");
    let db = lite.path("var/ncplan.db");
    let root = crate::root();
    let daemon = lite.start();
    lite.put("cam/O1234.nc", &std::fs::read_to_string(root.join("demo/cam/O1234.nc")).unwrap());
    lite.put("cam/O4321.nc", &long_program(4321, 400, 30));
    wait_until("the originals are stored", Duration::from_secs(30), || crate::db_rows(&db, "SELECT COUNT(*) FROM revisions") == [["2"]]);
    lite.put("share/O1234.nc", &std::fs::read_to_string(root.join("demo/examples/O1234_edited.nc")).unwrap());
    wait_until("the first edit is compared", Duration::from_secs(30), || {
        crate::db_rows(&db, "SELECT COUNT(*) FROM comparisons") == [["1"]]
    });
    lite.put("share/O4321.nc", &long_program(4321, 300, 30).replace("S2000", "S2400"));
    wait_until("the second edit is compared", Duration::from_secs(30), || {
        crate::db_rows(&db, "SELECT COUNT(*) FROM comparisons") == [["2"]]
    });
    daemon.kill();
    // The same database on PostgreSQL, copied by `migrate`, keeps the ids the pages link by.
    let url = pg.url();
    let (code, _, err) = lite.ncplan(&["migrate", "--from", db.to_str().unwrap(), "--to", &url, "--site", "HALL1"]);
    assert_eq!(code, 0, "{err}");
    for ids in [
        "SELECT id, path FROM programs ORDER BY id",
        "SELECT id, hash, seen_at FROM revisions ORDER BY id",
        "SELECT id, revision_id, kind, before, after FROM changes ORDER BY id",
    ] {
        assert_eq!(pg.rows(ids), crate::db_rows(&db, ids), "{ids}");
    }
    let changes = crate::db_rows(&db, "SELECT id, revision_id FROM changes ORDER BY id");
    assert!(changes.len() >= 3, "{changes:?}");
    // The workspace reads PostgreSQL through the README's role for it (the console refuses a
    // superuser, which the cluster's owner is).
    let mut owner = postgres::Client::connect(&url, postgres::NoTls).unwrap();
    owner.batch_execute(WEB_ROLE).unwrap();
    let web_url = url.replacen("ncplan@", "ncplan_web@", 1);
    let (_lite_serve, on_lite) = serve(&lite, &[]);
    let (_pg_serve, on_pg) = serve(&lite, &["--db", &web_url]);
    // Every page: the overview, the machine, each program and comparison, the knowledge
    // pages with and without their SQL, the console with each saved query, searches.
    let mut paths: Vec<String> =
        ["/", "/machine/DMU50", "/knowledge", "/sql", "/search", "/search?program=o1234", "/search?to_review=1&machine=DMU50"]
            .iter()
            .map(|p| (*p).to_owned())
            .collect();
    paths.push("/search?kind=feed_changed&since=2000-01-01&until=2999-12-31".into());
    paths.push("/search?until=2000-01-01".into());
    for p in crate::db_rows(&db, "SELECT id FROM programs ORDER BY id") {
        paths.push(format!("/program/{}", p[0]));
    }
    for r in crate::db_rows(&db, "SELECT revision_id FROM comparisons ORDER BY revision_id") {
        paths.push(format!("/compare/{}", r[0]));
    }
    for k in ncplan::store::KNOWLEDGE {
        paths.push(format!("/knowledge/{}", k.name));
        paths.push(format!("/knowledge/{}?sql", k.name));
    }
    for (_, sql) in ncplan::store::SAVED_QUERIES {
        paths.push(format!("/sql?q={}", urlencode(sql)));
    }
    paths.push(format!("/sql?q={}", urlencode("SELECT kind, COUNT(*) AS n FROM changes GROUP BY kind ORDER BY n DESC, kind")));
    paths.push(format!("/sql?q={}", urlencode("DELETE FROM changes")));
    paths.push(format!("/sql?q={}", urlencode("SELECT 1; DROP TABLE changes")));
    let mut compared = 0;
    for path in &paths {
        let (head_l, page_l) = get(&on_lite, path);
        let (head_p, page_p) = get(&on_pg, path);
        assert!(head_l.starts_with("HTTP/1.1 200"), "{path} on SQLite: {head_l}\n{page_l}");
        assert!(head_p.starts_with("HTTP/1.1 200"), "{path} on PostgreSQL: {head_p}\n{page_p}");
        let sql = path.starts_with("/knowledge/");
        let (a, b) = (masked(&page_l, sql), masked(&page_p, sql));
        if a != b {
            let line = a.lines().zip(b.lines()).position(|(x, y)| x != y).unwrap_or(0);
            panic!(
                "{path} differs from line {line}:\nSQLite:     {}\nPostgreSQL: {}",
                a.lines().nth(line).unwrap_or(""),
                b.lines().nth(line).unwrap_or("")
            );
        }
        compared += 1;
    }
    assert_eq!(compared, paths.len());
    let (_, overview) = get(&on_pg, "/");
    assert!(overview.contains("O1234") && overview.contains("DMU50"), "{overview}");
    let (_, feeds) = get(&on_pg, "/knowledge/feeds");
    assert!(feeds.contains(">feed_changed<"), "the feeds page has rows: {feeds}");

    // The console on PostgreSQL: a row cap, a time limit, writes refused in plain words.
    let (_, page) = run_sql(&on_pg, "SELECT generate_series(1, 5000) AS n");
    assert!(page.contains("1000 rows (more left off at the row limit)"), "{page}");
    let (_, page) = run_sql(&on_pg, "SELECT pg_sleep(10)");
    assert!(page.contains("the query ran past its time limit of 2000 ms and was stopped"), "{page}");
    let (_, page) = run_sql(&on_pg, "WITH gone AS (DELETE FROM changes RETURNING id) SELECT COUNT(*) FROM gone");
    assert!(page.contains("the query would write; queries only read"), "{page}");
    // The server's files are not the console's to read, through this role or through a superuser.
    let (_, page) = run_sql(&on_pg, "SELECT pg_read_file('/etc/passwd')");
    assert!(page.contains("permission denied for function pg_read_file") && !page.contains("root:"), "{page}");
    let (_super_serve, as_super) = serve(&lite, &["--db", &url]);
    let (head, page) = run_sql(&as_super, "SELECT pg_read_file('/etc/passwd')");
    assert!(head.starts_with("HTTP/1.1 200") && !page.contains("root:"), "{head}\n{page}");
    assert!(
        page.contains("the SQL console does not run as the database role `ncplan`: it is a superuser"),
        "{}",
        page.split("<p class=\"error\">").nth(1).unwrap_or(&page)
    );
    drop(_super_serve);
    assert_eq!(pg.count("SELECT COUNT(*) FROM changes") as usize, changes.len());

    // A review mark posted with the session's CSRF token lands in PostgreSQL.
    let (change, revision) = (&changes[0][0], &changes[0][1]);
    let (_, page) = get(&on_pg, &format!("/compare/{revision}"));
    let token = page.split("name=\"csrf\" value=\"").nth(1).and_then(|t| t.split('"').next()).expect("a CSRF token").to_owned();
    let post = |token: &str| {
        let body = format!("mark=note&note={}&by=ada&csrf={token}", urlencode("<b>feed</b> kept"));
        http(
            &on_pg,
            &format!(
                "POST /review/{change} HTTP/1.1\r\nHost: {{host}}\r\nCookie: {SESSION}\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
                body.len()
            ),
        )
        .0
    };
    let head = post("forged");
    assert!(head.starts_with("HTTP/1.1 403"), "{head}");
    assert_eq!(pg.count("SELECT COUNT(*) FROM review_marks"), 0);
    let head = post(&token);
    assert!(head.starts_with("HTTP/1.1 303"), "{head}");
    assert_eq!(
        pg.rows("SELECT change_id, mark, note, marked_by FROM review_marks"),
        [[change.clone(), "note".into(), "<b>feed</b> kept".into(), "ada".into()]]
    );
    assert!(crate::db_rows(&db, "SELECT id FROM review_marks").is_empty(), "the SQLite file is not written");
    let (_, page) = get(&on_pg, &format!("/compare/{revision}"));
    assert!(page.contains("&lt;b&gt;feed&lt;/b&gt; kept") && !page.contains("<b>feed</b>"), "the note shows as text");

    // Saved queries: the console offers the knowledge pages' queries in its engine's words,
    // and a planner's own, saved by a CSRF-protected POST, listed with who and when, runnable;
    // a hostile name shows as text; a write is not saved.
    let lite_rows = |sql: &str| crate::db_rows(&db, sql);
    let pg_rows = |sql: &str| pg.rows(sql);
    let engines: [(&String, &Rows<'_>); 2] = [(&on_lite, &lite_rows), (&on_pg, &pg_rows)];
    for (base, rows) in engines {
        let (_, console) = get(base, "/sql");
        let engine_sql = if base == &on_pg { ncplan::store::KNOWLEDGE[1].pg_sql } else { ncplan::store::KNOWLEDGE[1].sql };
        assert!(console.contains(&format!("href=\"/sql?q={}\"", pages_urlencode(engine_sql))), "{console}");
        const SQL: &str = "SELECT kind, COUNT(*) AS n FROM changes GROUP BY kind ORDER BY n DESC, kind";
        let (_, ran) = get(base, &format!("/sql?q={}", urlencode(SQL)));
        assert!(ran.contains("Save this query"), "a query shown can be saved: {ran}");
        let token = ran.split("name=\"csrf\" value=\"").nth(1).and_then(|t| t.split('"').next()).unwrap().to_owned();
        let save = |name: &str, sql: &str, token: &str| {
            let body = format!("name={}&q={}&by=ada&csrf={token}", urlencode(name), urlencode(sql));
            http(
                base,
                &format!(
                    "POST /sql/save HTTP/1.1\r\nHost: {{host}}\r\nCookie: {SESSION}\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
                    body.len()
                ),
            )
            .0
        };
        let hostile = "<script>alert(1)</script> feeds";
        assert!(save(hostile, SQL, "forged").starts_with("HTTP/1.1 403"));
        assert_eq!(rows("SELECT COUNT(*) FROM saved_queries"), [["0"]]);
        let head = save(hostile, SQL, &token);
        assert!(head.starts_with("HTTP/1.1 303"), "{head}");
        let head = save("wipe", "DELETE FROM changes", &token);
        assert!(head.starts_with("HTTP/1.1 303") && head.contains("refused="), "{head}");
        assert_eq!(rows("SELECT name, sql, saved_by FROM saved_queries"), [[hostile.to_owned(), SQL.to_owned(), "ada".to_owned()]]);
        let (_, console) = get(base, "/sql");
        assert!(console.contains("&lt;script&gt;alert(1)&lt;/script&gt; feeds") && !console.contains("<script>alert"), "{console}");
        let link =
            console.split("<ul id=\"saved\">").nth(1).and_then(|t| t.split("href=\"").nth(1)).and_then(|t| t.split('"').next()).unwrap();
        // The link fills the console's form; its Run button runs it.
        let (_, shown) = get(base, &link.replace("&amp;", "&"));
        assert!(shown.contains(&format!(">{}</textarea>", SQL)) && !shown.contains(">feed_changed<"), "{shown}");
        let (_, ran) = run_sql(base, SQL);
        assert!(ran.contains(" rows") && ran.contains(">feed_changed<"), "{ran}");
    }
}

/// Runs `sql` in the console at `base` as its Run button does: a POST with the session's
/// CSRF token.
fn run_sql(base: &str, sql: &str) -> (String, String) {
    let (_, console) = get(base, "/sql");
    let token = console.split("name=\"csrf\" value=\"").nth(1).and_then(|t| t.split('"').next()).expect("a CSRF token").to_owned();
    let body = format!("csrf={token}&q={}", urlencode(sql));
    http(
        base,
        &format!(
            "POST /sql HTTP/1.1\r\nHost: {{host}}\r\nCookie: {SESSION}\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
            body.len()
        ),
    )
}

/// The workspace's role of README's PostgreSQL section, as its SQL creates it (the database
/// here is `postgres`, the schema's owner `ncplan`).
const WEB_ROLE: &str = "CREATE ROLE ncplan_web LOGIN NOSUPERUSER;
GRANT CONNECT ON DATABASE postgres TO ncplan_web;
GRANT USAGE ON SCHEMA public TO ncplan_web;
GRANT SELECT ON ALL TABLES IN SCHEMA public TO ncplan_web;
GRANT INSERT ON review_marks, saved_queries TO ncplan_web;
GRANT INSERT, DELETE ON web_sessions TO ncplan_web;
GRANT USAGE ON ALL SEQUENCES IN SCHEMA public TO ncplan_web;
ALTER DEFAULT PRIVILEGES FOR ROLE ncplan IN SCHEMA public GRANT SELECT ON TABLES TO ncplan_web;";

/// Rows of a query on one engine's database.
type Rows<'a> = dyn Fn(&str) -> Vec<Vec<String>> + 'a;

/// The workspace's URL encoding (`web::pages::urlencode`): unreserved characters kept.
fn pages_urlencode(s: &str) -> String {
    s.bytes()
        .map(|b| if b.is_ascii_alphanumeric() || b"-_.~".contains(&b) { (b as char).to_string() } else { format!("%{b:02X}") })
        .collect()
}

/// A change an older analysis found in the first compared edit and today's does not (its
/// tool renamed T1 → T9), as a re-analysis meets it; the edit's revision id.
fn add_older_rename(store: &Store) -> String {
    let (_, edit) = store.query("SELECT revision_id, original_revision_id FROM comparisons ORDER BY revision_id LIMIT 1").unwrap();
    let (edit, original) = (&edit[0][0], &edit[0][1]);
    store
        .query(&format!(
            "INSERT INTO changes(revision_id, original_revision_id, workingstep, operation, kind, field, before, after, detected_at)
             VALUES ({edit}, {original}, 1, 'plane finish milling', 'tool_renamed', 'tool', 'T1', 'T9', '2026-01-01T00:00:00.000Z')"
        ))
        .unwrap();
    edit.clone()
}

/// A re-analysis on `server`'s database `db`: the old changes are kept with the version that
/// made them, a change found again keeps its id and its review marks, one the new analysis
/// does not find leaves the pages with its marks, and the summary says what changed.
fn reanalysis_keeps_old_changes_and_marks(server: &Server, db: &Location, rows: impl Fn(&str) -> Vec<Vec<String>>) {
    let daemon = server.start();
    server.put("cam/O1.nc", &program(1, 250, 1800));
    server.put("share/O1.nc", &program(1, 300, 2000));
    wait_until("the edit is compared", Duration::from_secs(30), || rows("SELECT COUNT(*) FROM comparisons") == [["1"]]);
    daemon.kill();
    let store = Store::open(db, "HALL1").unwrap();
    // An older analysis also found a tool renamed, which today's does not find.
    let edit = add_older_rename(&store);
    let id_of = |kind: &str| rows(&format!("SELECT id FROM changes WHERE kind = '{kind}'"))[0][0].parse::<i64>().unwrap();
    let (feed, speed, renamed) = (id_of("feed_changed"), id_of("spindle_speed_changed"), id_of("tool_renamed"));
    let detected = rows(&format!("SELECT detected_at FROM changes WHERE id = {feed}"));
    store.add_mark(feed, "adopt", "", "ada", "2026-02-01T00:00:00.000Z").unwrap().unwrap();
    store.add_mark(renamed, "reject", "", "ada", "2026-02-01T00:00:00.000Z").unwrap().unwrap();
    drop(store);
    let config = server.path("ncplan.toml");
    let (code, out, err) = server.ncplan(&["reanalyze", "--config", config.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains(": 2 revisions read again, 0 plans changed, 0 new findings, 0 vanished; 1 comparisons made again"), "{out}");
    let version = rows("SELECT DISTINCT version FROM analyses");
    assert_eq!(version.len(), 1);
    let version = &version[0][0];
    // The newest analysis: the same two changes under their old ids, the rename gone.
    assert_eq!(
        rows("SELECT id, kind, analysis FROM changes ORDER BY id"),
        [[feed.to_string(), "feed_changed".into(), version.clone()], [speed.to_string(), "spindle_speed_changed".into(), version.clone()]]
    );
    assert_eq!(rows(&format!("SELECT detected_at FROM changes WHERE id = {feed}")), detected, "a change found again keeps its time");
    // The old rows are kept, with the version that made them and the one that replaced them.
    assert_eq!(
        rows("SELECT change_id, kind, analysis, replaced_by FROM old_changes ORDER BY change_id"),
        [
            [feed.to_string(), "feed_changed".into(), String::new(), version.clone()],
            [speed.to_string(), "spindle_speed_changed".into(), String::new(), version.clone()],
            [renamed.to_string(), "tool_renamed".into(), String::new(), version.clone()],
        ]
    );
    // The marks stay on their changes: the adopted one is reviewed still, the rejected rename
    // names a kept old row; only the speed change waits for review.
    let store = Store::open_read_only(db).unwrap();
    let queue = store.search_changes(&ncplan::store::ChangeFilter { to_review: true, ..Default::default() }, 10).unwrap();
    assert_eq!(queue.iter().map(|c| c.id).collect::<Vec<_>>(), [speed]);
    assert_eq!(store.marks(feed).unwrap()[0].mark, "adopt");
    assert_eq!(store.change_rows(edit.parse().unwrap()).unwrap().len(), 2);
    assert_eq!(
        rows(&format!("SELECT COUNT(*) FROM old_changes o JOIN review_marks v ON v.change_id = o.change_id WHERE o.change_id = {renamed}")),
        [["1"]]
    );
    let (code, show, err) = server.ncplan(&["show", "--db", &db.to_string(), "share/O1.nc"]);
    assert_eq!(code, 0, "{err}");
    assert!(show.contains("feed") && !show.contains("T9"), "show tells the newest analysis: {show}");
    // A new change after all that gets an id no change ever had.
    let daemon = server.start();
    server.put("share/O1.nc", &program(1, 320, 2000));
    wait_until("the second edit is compared", Duration::from_secs(30), || rows("SELECT COUNT(*) FROM comparisons") == [["2"]]);
    daemon.kill();
    let newest =
        rows("SELECT MIN(id) FROM changes WHERE revision_id <> (SELECT MIN(revision_id) FROM comparisons)")[0][0].parse::<i64>().unwrap();
    assert!(newest > renamed.max(speed), "{newest}");
}

#[test]
fn reanalysis_keeps_old_changes_and_marks_on_both_engines() {
    let lite = Server::new(Some("HALL1"), "path = 'var/ncplan.db'");
    let db = lite.path("var/ncplan.db");
    reanalysis_keeps_old_changes_and_marks(&lite, &Location::Sqlite(db.clone()), |sql| crate::db_rows(&db, sql));
    let Some(pg) = Cluster::start("pg::reanalysis_keeps_old_changes_and_marks_on_both_engines on PostgreSQL") else { return };
    let server = Server::new(Some("HALL1"), &format!("url = '{}'", pg.url()));
    reanalysis_keeps_old_changes_and_marks(&server, &Location::parse(&pg.url()), |sql| pg.rows(sql));
}

/// The read-only role of README's deployment section, as its SQL creates it.
pub(crate) const READER_ROLE: &str = "CREATE ROLE ncplan_reader LOGIN;
GRANT CONNECT ON DATABASE postgres TO ncplan_reader;
GRANT USAGE ON SCHEMA public TO ncplan_reader;
GRANT SELECT ON ALL TABLES IN SCHEMA public TO ncplan_reader;
ALTER DEFAULT PRIVILEGES IN SCHEMA public GRANT SELECT ON TABLES TO ncplan_reader;
ALTER ROLE ncplan_reader SET default_transaction_read_only = on;";

#[test]
fn a_read_only_role_queries_and_is_refused_writes_in_plain_words() {
    let Some(pg) = Cluster::start("pg::a_read_only_role_queries_and_is_refused_writes_in_plain_words") else { return };
    let server = Server::new(Some("HALL1"), &format!("url = '{}'", pg.url()));
    let daemon = server.start();
    server.put("cam/O1.nc", &program(1, 250, 1800));
    server.put("share/O1.nc", &program(1, 300, 2000));
    wait_until("the edit is compared", Duration::from_secs(30), || pg.count("SELECT COUNT(*) FROM comparisons") == 1);
    daemon.kill();
    let mut owner = postgres::Client::connect(&pg.url(), postgres::NoTls).unwrap();
    owner.batch_execute(READER_ROLE).unwrap();
    let reader = pg.url().replacen("ncplan@", "ncplan_reader@", 1);
    // Reading works.
    let (code, out, err) = server.ncplan(&["query", "--db", &reader, "SELECT kind FROM shopfloor_changes ORDER BY change_id"]);
    assert_eq!((code, out.as_str()), (0, "kind\nfeed_changed\nspindle_speed_changed\n"), "{err}");
    let (code, out, err) = server.ncplan(&["report", "--db", &reader, "--format", "csv", "--since", "2000-01-01"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(out.lines().count(), 3, "{out}");
    // Writes are refused, by ncplan and by the database, in plain words.
    let (code, _, err) = server.ncplan(&["query", "--db", &reader, "DELETE FROM changes"]);
    assert_eq!(code, 2);
    assert!(err.contains("`DELETE` is refused: queries only read"), "{err}");
    let (code, _, err) = server.ncplan(&["query", "--db", &reader, "WITH g AS (DELETE FROM changes RETURNING id) SELECT COUNT(*) FROM g"]);
    assert_eq!(code, 2);
    assert!(err.contains("the query would write; queries only read"), "{err}");
    let store = Store::open(&Location::parse(&reader), "HALL1").expect("a current database opens with a role that only reads");
    let change: i64 = pg.rows("SELECT MIN(id) FROM changes")[0][0].parse().unwrap();
    let err = format!("{:#}", anyhow::Error::from(store.add_mark(change, "adopt", "", "ada", "2026-01-01T00:00:00.000Z").unwrap_err()));
    assert!(err.contains("read-only transaction") || err.contains("permission denied"), "{err}");
    // Past its default: a session that asks to write is still refused by the grants.
    let mut direct = postgres::Client::connect(&reader, postgres::NoTls).unwrap();
    direct.batch_execute("SET default_transaction_read_only = off").unwrap();
    let e = direct.batch_execute("DELETE FROM changes").unwrap_err();
    assert!(e.as_db_error().is_some_and(|d| d.message().contains("permission denied for table changes")), "{e:?}");
    // The workspace reads through it; a review mark is refused and nothing is written.
    let (_serve, base) = serve(&server, &["--db", &reader]);
    let (head, page) = get(&base, "/");
    assert!(head.starts_with("HTTP/1.1 200") && page.contains("DMU50"), "{head}\n{page}");
    let (_, page) = get(&base, &format!("/compare/{}", pg.rows("SELECT revision_id FROM comparisons")[0][0]));
    let token = page.split("name=\"csrf\" value=\"").nth(1).and_then(|t| t.split('"').next()).expect("a CSRF token").to_owned();
    let body = format!("mark=adopt&by=ada&csrf={token}");
    let (head, body) = http(
        &base,
        &format!(
            "POST /review/{change} HTTP/1.1\r\nHost: {{host}}\r\nCookie: {SESSION}\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
            body.len()
        ),
    );
    assert!(head.starts_with("HTTP/1.1 500") && body.contains("cannot record the mark"), "{head}\n{body}");
    assert_eq!(pg.count("SELECT COUNT(*) FROM review_marks"), 0);
    assert_eq!(pg.count("SELECT COUNT(*) FROM changes"), 2);
    // Planners still sign in through it: the server keeps their sessions itself.
    drop(_serve);
    let mut cfg = std::fs::read_to_string(server.path("ncplan.toml")).unwrap();
    cfg.push_str(&crate::support::web_users(&[("ada", "planner-pw")]));
    std::fs::write(server.path("ncplan.toml"), cfg).unwrap();
    let (_serve, base) = serve(&server, &["--db", &reader]);
    let cookie = crate::support::sign_in(&base, "ada", "planner-pw");
    let (head, page) = http(&base, &format!("GET / HTTP/1.1\r\nHost: {{host}}\r\nCookie: {cookie}\r\nConnection: close\r\n\r\n"));
    assert!(head.starts_with("HTTP/1.1 200") && page.contains("Sign out") && page.contains("DMU50"), "{head}\n{page}");
    assert_eq!(pg.count("SELECT COUNT(*) FROM web_sessions"), 0);
}

#[test]
fn sslmode_require_against_a_server_with_a_self_signed_certificate() {
    const TEST: &str = "pg::sslmode_require_against_a_server_with_a_self_signed_certificate";
    if Command::new("openssl").arg("version").stdout(Stdio::null()).status().is_err() {
        crate::skip(TEST, "openssl is not installed: it makes the server's self-signed certificate");
        return;
    }
    let certs = tempfile::tempdir().unwrap();
    let (crt, key) = (certs.path().join("server.crt"), certs.path().join("server.key"));
    let out = Command::new("openssl")
        .args([
            "req",
            "-x509",
            "-newkey",
            "rsa:2048",
            "-nodes",
            "-days",
            "2",
            "-subj",
            "/CN=127.0.0.1",
            "-addext",
            "subjectAltName=IP:127.0.0.1",
            "-addext",
            "basicConstraints=critical,CA:FALSE",
        ])
        .arg("-keyout")
        .arg(&key)
        .arg("-out")
        .arg(&crt)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let prepare = |dir: &std::path::Path| {
        use std::os::unix::fs::PermissionsExt as _;
        // Relative names in the server's options are of its data folder.
        let data = dir.join("data");
        std::fs::copy(&crt, data.join("server.crt")).unwrap();
        std::fs::copy(&key, data.join("server.key")).unwrap();
        std::fs::set_permissions(data.join("server.key"), std::fs::Permissions::from_mode(0o600)).unwrap();
    };
    let Some(pg) = Cluster::start_with(TEST, "-c ssl=on -c ssl_cert_file=server.crt -c ssl_key_file=server.key", prepare) else { return };
    let server = Server::new(Some("HALL1"), "path = 'var/ncplan.db'");
    let url = |mode: &str| pg.url().replace("sslmode=disable", mode);
    const SSL: &str = "SELECT ssl FROM pg_stat_ssl WHERE pid = pg_backend_pid()";
    // Required, with the server's certificate trusted: the session is encrypted.
    let trusted = url(&format!("sslmode=require&sslrootcert={}", crt.display()));
    let (code, out, err) = server.ncplan(&["query", "--db", &trusted, SSL]);
    assert_eq!((code, out.as_str()), (0, "ssl\n1\n"), "{err}");
    // Required, without trusting it: refused, never sent in the clear.
    let (code, _, err) = server.ncplan(&["query", "--db", &url("sslmode=require"), SSL]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("connecting to PostgreSQL"), "{err}");
    // Disabled: in the clear, as asked.
    let (code, out, err) = server.ncplan(&["query", "--db", &url("sslmode=disable"), SSL]);
    assert_eq!((code, out.as_str()), (0, "ssl\n0\n"), "{err}");
    // A root file that holds no certificate is named.
    let (code, _, err) = server.ncplan(&["query", "--db", &url(&format!("sslmode=require&sslrootcert={}", key.display())), SSL]);
    assert_eq!(code, 2);
    assert!(err.contains("sslrootcert"), "{err}");
}

/// The web's sign-in sessions on both engines: kept by their token's hash until their
/// expiry (the server restarts in between: they are in the store), forgotten by a later
/// sign-in once ended, gone at sign-out.
#[test]
fn sign_in_sessions_are_kept_until_they_expire_on_both_engines() {
    for engine in engines("pg::sign_in_sessions_are_kept_until_they_expire_on_both_engines") {
        let s = &engine.store;
        let name = s.engine_name();
        s.start_session("h1", "ada", "2026-03-01T08:00:00.000Z", "2026-03-01T20:00:00.000Z").unwrap();
        assert_eq!(s.session_user("h1", "2026-03-01T19:59:59.999Z").unwrap().as_deref(), Some("ada"), "{name}");
        assert_eq!(s.session_user("h1", "2026-03-01T20:00:00.000Z").unwrap(), None, "{name}: ended at its expiry");
        assert_eq!(s.session_user("ada", "2026-03-01T09:00:00.000Z").unwrap(), None, "{name}: no such session");
        s.start_session("h2", "bob", "2026-03-02T08:00:00.000Z", "2026-03-02T20:00:00.000Z").unwrap();
        assert_eq!(s.query("SELECT token_hash, user_name FROM web_sessions").unwrap().1, [["h2", "bob"]], "{name}: h1 forgotten");
        s.end_session("h2").unwrap();
        assert_eq!(s.session_user("h2", "2026-03-02T09:00:00.000Z").unwrap(), None, "{name}: signed out");
        assert!(s.query("SELECT * FROM web_sessions").unwrap().1.is_empty(), "{name}");
    }
}

/// Every row of every table of `db` (a SQLite file), each cell with its type (a blob as hex),
/// by table, in a fixed order.
fn every_row(db: &std::path::Path) -> Vec<(String, Vec<Vec<String>>)> {
    let tables = crate::db_rows(db, "SELECT name FROM sqlite_master WHERE type = 'table' AND name NOT LIKE 'sqlite_%' ORDER BY name");
    tables
        .iter()
        .map(|t| {
            let cols = crate::db_rows(db, &format!("SELECT name FROM pragma_table_info('{}') ORDER BY cid", t[0]));
            let cells: Vec<String> =
                cols.iter().map(|c| format!("typeof({0}), CASE WHEN typeof({0}) = 'blob' THEN hex({0}) ELSE {0} END", c[0])).collect();
            let order: Vec<String> = (1..=2 * cols.len()).map(|i| i.to_string()).collect();
            let sql = format!("SELECT {} FROM {} ORDER BY {}", cells.join(", "), t[0], order.join(", "));
            (t[0].clone(), crate::db_rows(db, &sql))
        })
        .collect()
}

/// A server's whole history, every table of it filled (edits compared, an old analysis's
/// changes kept by a re-analysis, review marks on kept and vanished changes, a partial write,
/// a queue left for the next analysis, an attempt in progress, a saved query, a session, a
/// suggestion's review step),
/// migrated into PostgreSQL and back into a new SQLite file: every row of every table comes
/// back the same, ids included; PostgreSQL has them under the same ids; a second run of
/// each copies nothing.
#[test]
fn migrate_round_trips_every_table_from_sqlite_to_postgres_and_back() {
    let Some(pg) = Cluster::start("pg::migrate_round_trips_every_table_from_sqlite_to_postgres_and_back") else { return };
    let lite = Server::new(Some("HALL7"), "path = 'var/ncplan.db'");
    let db = lite.path("var/ncplan.db");
    let at = Location::Sqlite(db.clone());
    let daemon = lite.start();
    lite.put("cam/O1.nc", &program(1, 250, 1800));
    lite.put("share/O1.nc", &program(1, 300, 2000));
    // O2 cuts before any tool change: findings to copy.
    lite.put("cam/O2.nc", &program(2, 250, 1800).replace("T1 M6\n", ""));
    lite.put("share/O2.nc", &program(2, 300, 2000).replace("T1 M6\n", ""));
    wait_until("both edits are compared", Duration::from_secs(30), || crate::db_rows(&db, "SELECT COUNT(*) FROM comparisons") == [["2"]]);
    daemon.kill();
    // An older analysis found a rename today's does not; marks on it and on a kept change.
    let store = Store::open(&at, "HALL7").unwrap();
    add_older_rename(&store);
    let id_of =
        |kind: &str| crate::db_rows(&db, &format!("SELECT MIN(id) FROM changes WHERE kind = '{kind}'"))[0][0].parse::<i64>().unwrap();
    store.add_mark(id_of("feed_changed"), "adopt", "", "ada", "2026-02-01T00:00:00.000Z").unwrap().unwrap();
    store.add_mark(id_of("tool_renamed"), "reject", "", "ada", "2026-02-01T00:00:00.000Z").unwrap().unwrap();
    store.add_mark(id_of("spindle_speed_changed"), "note", "check the chatter", "bob", "2026-02-02T00:00:00.000Z").unwrap().unwrap();
    drop(store);
    let config = lite.path("ncplan.toml");
    let (code, _, err) = lite.ncplan(&["reanalyze", "--config", config.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    // A later edit of O1: its changes get ids after every id a change had.
    let daemon = lite.start();
    lite.put("share/O1.nc", &program(1, 320, 2000));
    wait_until("the later edit is compared", Duration::from_secs(30), || {
        crate::db_rows(&db, "SELECT COUNT(*) FROM comparisons") == [["3"]]
    });
    daemon.kill();
    // The rest of the schema: a partial write, a call, a queue, an attempt, a saved query, a session.
    let mut store = Store::open(&at, "HALL7").unwrap();
    let edits = crate::db_rows(&db, "SELECT revision_id FROM comparisons ORDER BY revision_id");
    let tx = store.begin().unwrap();
    tx.mark_partial(edits[0][0].parse().unwrap(), edits[2][0].parse().unwrap(), "2026-02-03T00:00:00.000Z").unwrap();
    // A subprogram the edit calls, which is not there.
    tx.add_calls(edits[0][0].parse().unwrap(), &["o9000".to_owned(), "9000".to_owned()]).unwrap();
    tx.commit().unwrap();
    assert!(store.queue_reanalysis("next-version", None, None).unwrap() > 0);
    store.begin_attempt(&sha256("in progress"), "/share/O3.nc", "2026-02-04T00:00:00.000Z").unwrap();
    store
        .save_query(
            "feeds by machine",
            "SELECT machine, COUNT(*) FROM shopfloor_changes GROUP BY machine",
            "ada",
            "2026-02-05T00:00:00.000Z",
        )
        .unwrap();
    store.start_session(&sha256("a token"), "ada", "2026-02-06T08:00:00.000Z", "2026-02-06T20:00:00.000Z").unwrap();
    // A suggestion's review step (knowledge back to CAM).
    let step = ncplan::store::SuggestionStep {
        suggestion: "0123456789ab".into(),
        step: 1,
        group_key: "T1|||||unknown|DMU50|finishing|cutting_feed".into(),
        state: "proposed".into(),
        reason: "the rules' gates passed".into(),
        value: 270.0,
        evidence: 6,
        by: "ncplan".into(),
        at: "2026-02-07T00:00:00.000Z".into(),
    };
    assert_eq!(store.add_suggestion_step(&step).unwrap(), Some(1));
    drop(store);
    let before = every_row(&db);
    let empty: Vec<&str> = before.iter().filter(|(_, rows)| rows.is_empty()).map(|(t, _)| t.as_str()).collect();
    assert!(empty.is_empty(), "every table has rows to copy; empty: {empty:?}");
    assert_eq!(crate::db_rows(&db, "SELECT COUNT(*) FROM old_changes WHERE change_id NOT IN (SELECT id FROM changes)"), [["1"]]);

    // Into PostgreSQL: every table, under the same ids.
    let url = pg.url();
    let migrate = |from: &str, to: &str, site: &str| {
        let (code, out, err) = lite.ncplan(&["migrate", "--from", from, "--to", to, "--site", site]);
        assert_eq!(code, 0, "{err}");
        out
    };
    let out = migrate(db.to_str().unwrap(), &url, "HALL7");
    assert!(out.contains("5 revisions, 5 copied now, 0 already there; 3 comparisons copied; 3 review marks"), "{out}");
    for (table, rows) in &before {
        assert_eq!(pg.count(&format!("SELECT COUNT(*) FROM {table}")), rows.len() as i64, "{table} on PostgreSQL");
    }
    for ids in [
        "SELECT id, name FROM machines ORDER BY id",
        "SELECT id, path FROM programs ORDER BY id",
        "SELECT id, hash, seen_at FROM revisions ORDER BY id",
        "SELECT id, revision_id, code FROM diagnostics ORDER BY id",
        "SELECT id, revision_id, kind, before, after FROM changes ORDER BY id",
        "SELECT change_id, revision_id, kind, replaced_by FROM old_changes ORDER BY change_id, replaced_at",
        "SELECT id, change_id, revision_id, mark, marked_by FROM review_marks ORDER BY id",
        "SELECT revision_id, superseded_by FROM revision_marks",
        "SELECT id, name FROM saved_queries ORDER BY id",
    ] {
        assert_eq!(pg.rows(ids), crate::db_rows(&db, ids), "{ids}");
    }
    assert_eq!(pg.rows("SELECT DISTINCT site FROM programs UNION SELECT DISTINCT site FROM attempts"), [["HALL7"]]);
    // Again: everything is there already.
    let out = migrate(db.to_str().unwrap(), &url, "HALL7");
    assert!(
        out.contains("5 revisions, 0 copied now, 5 already there; 0 comparisons copied; 3 review marks; rows copied now: none"),
        "{out}"
    );

    // And back into a new SQLite file: every row of every table as it was.
    let back = lite.path("var/back.db");
    let out = migrate(&url, back.to_str().unwrap(), "HALL7");
    assert!(out.contains("5 revisions, 5 copied now"), "{out}");
    let after = every_row(&back);
    assert_eq!(after.iter().map(|(t, _)| t).collect::<Vec<_>>(), before.iter().map(|(t, _)| t).collect::<Vec<_>>());
    for ((table, a), (_, b)) in before.iter().zip(&after) {
        assert_eq!(a, b, "{table}");
    }
    let out = migrate(&url, back.to_str().unwrap(), "HALL7");
    assert!(out.contains("rows copied now: none"), "{out}");
    assert_eq!(every_row(&back), before, "a second run copies nothing twice");
    // Another site's history is not this one's.
    let out = migrate(&url, lite.path("var/other.db").to_str().unwrap(), "HALL8");
    assert!(out.contains(": 0 revisions, 0 copied now"), "{out}");

    // The same history as a second site of the plant: every id is taken, so every row gets a
    // new one and every reference follows; back in SQLite it says all it said.
    let out = migrate(db.to_str().unwrap(), &url, "HALL9");
    assert!(out.contains("5 revisions, 5 copied now"), "{out}");
    assert_eq!(
        pg.count("SELECT COUNT(*) FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.site = 'HALL9' AND r.id <= 5"),
        0,
        "new ids"
    );
    let renumbered = lite.path("var/hall9.db");
    migrate(&url, renumbered.to_str().unwrap(), "HALL9");
    for sql in SAID {
        let mut a = crate::db_rows(&db, sql);
        let mut b = crate::db_rows(&renumbered, sql);
        a.sort();
        b.sort();
        assert!(!a.is_empty(), "{sql}");
        assert_eq!(a, b, "{sql}");
    }
}

/// What a history says, every reference followed to what it names (a program's path, a
/// revision's program and time, a change's words): the same whatever the ids.
const SAID: &[&str] = &[
    "SELECT m.name, m.dialect, m.folder, p.path, p.role, p.name, p.program_key, p.stem, p.dialect
     FROM programs p LEFT JOIN machines m ON m.id = p.machine_id",
    "SELECT p.path, k.rule, k.key FROM program_keys k JOIN programs p ON p.id = k.program_id",
    "SELECT p.path, r.hash, r.size, r.mtime_ns, r.seen_at, r.encoding, r.status, r.name, hex(b.content)
     FROM revisions r JOIN programs p ON p.id = r.program_id JOIN blobs b ON b.hash = r.hash",
    "SELECT p.path, r.seen_at, l.plan_json, l.workingsteps, l.tools, l.complete, l.analysis FROM plans l
     JOIN revisions r ON r.id = l.revision_id JOIN programs p ON p.id = r.program_id",
    "SELECT p.path, r.seen_at, d.code, d.severity, d.line, d.col, d.byte_start, d.byte_end, d.message FROM diagnostics d
     JOIN revisions r ON r.id = d.revision_id JOIN programs p ON p.id = r.program_id",
    "SELECT p.path, r.seen_at, w.idx, w.operation, w.tool, w.feed, w.spindle_speed, w.depth, w.first_line FROM workingsteps w
     JOIN revisions r ON r.id = w.revision_id JOIN programs p ON p.id = r.program_id",
    "SELECT p.path, r.seen_at, f.id, f.kind, f.x, f.y, f.z, f.depth, f.workingsteps FROM features f
     JOIN revisions r ON r.id = f.revision_id JOIN programs p ON p.id = r.program_id",
    "SELECT p.path, r.seen_at, a.version, a.worker, a.previous, a.previous_plan, a.previous_findings, a.plan_changed FROM analyses a
     JOIN revisions r ON r.id = a.revision_id JOIN programs p ON p.id = r.program_id",
    "SELECT p.path, r.seen_at, q.version, q.worker, q.lease_until FROM reanalysis_queue q
     JOIN revisions r ON r.id = q.revision_id JOIN programs p ON p.id = r.program_id",
    "SELECT p.path, r.seen_at, k.mark, sp.path, s.seen_at, k.noted_at FROM revision_marks k
     JOIN revisions r ON r.id = k.revision_id JOIN programs p ON p.id = r.program_id
     JOIN revisions s ON s.id = k.superseded_by JOIN programs sp ON sp.id = s.program_id",
    "SELECT p.path, r.seen_at, op.path, o.seen_at, c.compared_at, c.changes, c.rule FROM comparisons c
     JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id
     JOIN revisions o ON o.id = c.original_revision_id JOIN programs op ON op.id = o.program_id",
    "SELECT p.path, r.seen_at, op.path, c.workingstep, c.kind, c.field, c.before, c.after, c.line, c.detected_at, c.deviation, c.analysis
     FROM changes c JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id
     JOIN revisions o ON o.id = c.original_revision_id JOIN programs op ON op.id = o.program_id",
    // An old change keeps the id of the change it was, where that change is still current.
    "SELECT p.path, r.seen_at, x.kind, x.before, x.after, x.analysis, x.replaced_by,
            (SELECT k.kind || ' ' || k.after FROM changes k WHERE k.id = x.change_id)
     FROM old_changes x JOIN revisions r ON r.id = x.revision_id JOIN programs p ON p.id = r.program_id",
    // A mark names its change (current or old) and its revision.
    "SELECT p.path, r.seen_at, v.kind, v.before, v.after, v.mark, v.note, v.marked_by, v.marked_at,
            COALESCE((SELECT k.kind || ' ' || k.after FROM changes k WHERE k.id = v.change_id),
                     (SELECT 'old ' || k.kind || ' ' || k.after FROM old_changes k WHERE k.change_id = v.change_id LIMIT 1))
     FROM review_marks v JOIN revisions r ON r.id = v.revision_id JOIN programs p ON p.id = r.program_id",
    "SELECT name, sql, saved_by, saved_at FROM saved_queries",
    "SELECT token_hash, user_name, created_at, expires_at FROM web_sessions",
    "SELECT hash, path, started_at, tries FROM attempts",
];

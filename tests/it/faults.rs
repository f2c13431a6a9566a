//! The daemon under the faults a DNC server sees: its own reads, a kill after a late
//! original, Siemens names, writers that pause or rewrite, a remounted share, links out of a
//! share, empty files. Real binary, real folders, real SQLite; the ingest-level cases drive
//! `daemon::ingest` with an injected clock.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use ncplan::config::Config;
use ncplan::daemon::{Outcome, Snapshot, ingest};
use ncplan::dialect::Registry;
use ncplan::store::Store;

use crate::support::{Proc, wait_rows, watch};

/// A temporary DNC server: a CAM folder, one machine share, a config and a database.
pub(crate) struct Site {
    pub(crate) dir: tempfile::TempDir,
}

impl Site {
    pub(crate) fn new(extra: &str) -> Site {
        Site::with("fanuc", extra)
    }

    fn with(dialect: &str, extra: &str) -> Site {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir_all(dir.path().join("cam")).unwrap();
        std::fs::create_dir_all(dir.path().join("share")).unwrap();
        std::fs::write(
            dir.path().join("ncplan.toml"),
            format!(
                "[database]\npath = 'var/ncplan.db'\n[daemon]\nsettle_ms = 200\n\
                 [[cam]]\npath = 'cam'\ndialect = '{dialect}'\n\
                 [[machine]]\nname = 'M1'\npath = 'share'\ndialect = '{dialect}'\n{extra}"
            ),
        )
        .unwrap();
        Site { dir }
    }

    pub(crate) fn path(&self, rel: &str) -> PathBuf {
        self.dir.path().join(rel)
    }

    pub(crate) fn db(&self) -> PathBuf {
        self.path("var/ncplan.db")
    }

    pub(crate) fn config(&self) -> Config {
        let text = std::fs::read_to_string(self.path("ncplan.toml")).unwrap();
        Config::parse(&text, self.dir.path()).unwrap()
    }

    pub(crate) fn start(&self) -> Proc {
        let log = std::fs::File::create(self.path("daemon.log")).unwrap();
        let d = watch(&self.path("ncplan.toml"), "debug", log);
        // Ready once the catch-up scan has been queued.
        self.wait_log("Catch-up scan queued", 1);
        d
    }

    pub(crate) fn log(&self) -> String {
        std::fs::read_to_string(self.path("daemon.log")).unwrap_or_default()
    }

    pub(crate) fn wait_log(&self, needle: &str, want: usize) -> usize {
        let deadline = Instant::now() + Duration::from_secs(20);
        loop {
            let n = self.log().matches(needle).count();
            if n >= want || Instant::now() > deadline {
                return n;
            }
            std::thread::sleep(Duration::from_millis(25));
        }
    }

    pub(crate) fn rows(&self, sql: &str) -> Vec<Vec<String>> {
        rows(&self.db(), sql)
    }

    pub(crate) fn wait_for(&self, sql: &str, want: usize) -> Vec<Vec<String>> {
        wait_rows(&self.db(), sql, want, Duration::from_secs(30))
    }
}

fn rows(db: &Path, sql: &str) -> Vec<Vec<String>> {
    crate::db_rows(db, sql)
}

/// A small Fanuc program: face with T1 at `feed`, numbered `number`.
fn program(number: u32, feed: u32) -> String {
    crate::support::program(number, feed, 2000)
}

fn siemens(name: &str, drill_feed: u32, depth: &str) -> String {
    format!(
        "%_N_{name}_MPF\n;$PATH=/_N_WKS_DIR/_N_PLATE_WPD\nG17 G90 G71\nT=\"DRILL8\"\nM6\nS1800 M3\nG0 X20 Y20 Z50\n\
         MCALL CYCLE81(10,0,2,{depth},)\nX20 Y20\nX60 Y20\nMCALL\nG0 Z100\nG1 X80 F{drill_feed}\nM30\n"
    )
}

#[test]
fn reading_a_stored_file_does_not_queue_it_again() {
    let site = Site::new("");
    let daemon = site.start();
    std::fs::write(site.path("share/O1.nc"), program(1, 300)).unwrap();
    assert_eq!(site.wait_for("SELECT id FROM revisions", 1).len(), 1);
    // Readers of a stored file (the daemon itself, a DNC tool, a backup) open and close it.
    for _ in 0..30 {
        let _ = std::fs::read(site.path("share/O1.nc")).unwrap();
        std::thread::sleep(Duration::from_millis(20));
    }
    std::thread::sleep(Duration::from_millis(800));
    let log = site.log();
    let queued = log.lines().filter(|l| l.contains("Queued a settled file") && l.contains("O1.nc")).count();
    assert_eq!(queued, 1, "the file was queued again after reads:\n{log}");
    assert!(!log.contains("Content unchanged"), "{log}");
    daemon.kill();
}

#[test]
fn a_late_original_and_its_waiting_edits_commit_together_across_a_kill() {
    // Every edit is paired with the one original by a file-name pattern.
    let site = Site::new("[matching]\npattern = '^(?P<key>O1)[0-9]*'\n");
    let daemon = site.start();
    let n = 120;
    for i in 0..n {
        std::fs::write(site.path(&format!("share/O{}.nc", 1000 + i)), program(1000 + i, 250)).unwrap();
    }
    assert_eq!(site.wait_for("SELECT id FROM revisions", n as usize).len(), n as usize);
    assert!(site.rows("SELECT * FROM comparisons").is_empty());
    std::fs::write(site.path("cam/O1.nc"), program(1, 300)).unwrap();
    // Kill the moment the original is visible: its comparisons are visible with it.
    let deadline = Instant::now() + Duration::from_secs(20);
    while site.rows("SELECT r.id FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.role = 'cam'").is_empty() {
        assert!(Instant::now() < deadline, "the original was never stored");
    }
    daemon.kill();
    let compared = site.rows("SELECT revision_id, rule FROM comparisons");
    assert_eq!(compared.len(), n as usize, "comparisons lost by a kill");
    assert!(compared.iter().all(|r| r[1] == "pattern"), "{compared:?}");
    let feeds = site.rows("SELECT DISTINCT before, after FROM shopfloor_changes WHERE kind = 'feed_changed'");
    assert_eq!(feeds, [["F300", "F250"]]);
    // A restart neither loses nor repeats any of it.
    let daemon = site.start();
    std::thread::sleep(Duration::from_millis(1000));
    assert_eq!(site.rows("SELECT * FROM comparisons").len(), n as usize);
    assert_eq!(site.rows("SELECT * FROM revisions").len(), n as usize + 1);
    daemon.kill();
}

#[test]
fn start_up_compares_what_an_older_run_left_waiting() {
    // An older ncplan, killed between storing an original and comparing the edits that were
    // waiting for it, left them uncompared: the next start compares them.
    let site = Site::new("");
    let config = site.config();
    let registry = Registry::shipped();
    let dialect = registry.get("fanuc").unwrap();
    std::fs::create_dir_all(site.path("var")).unwrap();
    {
        let mut store = Store::open(&ncplan::store::Location::Sqlite(site.db()), "").unwrap();
        for (path, folder, text, machine) in
            [("share/O7.nc", 1, program(7, 250), Some(("M1", "fanuc", "share"))), ("cam/O7.nc", 0, program(7, 300), None)]
        {
            std::fs::write(site.path(path), &text).unwrap();
            let a = ncplan::pipeline::analyze(text.as_bytes(), &dialect, &config.profile);
            let keys = ncplan::pairing::keys(None, "O7.nc", Some("O7"));
            let full = site.path(path).to_string_lossy().into_owned();
            let plan = serde_json::to_string(&a.plan).unwrap();
            let tx = store.begin().unwrap();
            tx.insert_revision(&ncplan::store::NewRevision {
                path: &full,
                role: config.folders[folder].role.as_str(),
                machine,
                name: "O7",
                keys: &keys,
                stem: "O7",
                dialect: "fanuc",
                content: ncplan::store::Content::Bytes(text.as_bytes()),
                hash: &ncplan::daemon::ingest::sha256_hex(text.as_bytes()),
                mtime_ns: None,
                seen_at: "2026-12-01T10:00:00.000Z",
                encoding: "utf-8",
                status: "analysed",
                plan_json: Some(&plan),
                plan_complete: true,
                counts: (a.plan.workingsteps.len(), a.plan.tools.len()),
                diagnostics: &[],
            })
            .unwrap();
            tx.commit().unwrap();
        }
    }
    assert!(site.rows("SELECT * FROM comparisons").is_empty());
    let daemon = site.start();
    let feeds = site.wait_for("SELECT before, after FROM shopfloor_changes WHERE kind = 'feed_changed'", 1);
    assert_eq!(feeds, [["F300", "F250"]]);
    assert_eq!(site.wait_log("waiting for their original", 1), 1);
    daemon.kill();
}

#[test]
fn siemens_programs_pair_by_whole_names_and_an_ambiguous_pairing_is_a_finding() {
    let site = Site::with("siemens", "");
    std::fs::write(site.path("cam/DRILL_REAM.MPF"), siemens("DRILL_REAM", 300, "-12")).unwrap();
    std::fs::write(site.path("cam/DRILL_PLATE.MPF"), siemens("DRILL_PLATE", 300, "-20")).unwrap();
    // Two originals that state the same name under different file names.
    std::fs::write(site.path("cam/HOLES_A.MPF"), siemens("HOLES", 300, "-12")).unwrap();
    std::fs::write(site.path("cam/HOLES_B.MPF"), siemens("HOLES", 300, "-14")).unwrap();
    let daemon = site.start();
    assert_eq!(site.wait_for("SELECT id FROM revisions", 4).len(), 4);
    // The machine's DRILL_REAM, with the operator's slower feed.
    std::fs::write(site.path("share/DRILL_REAM.MPF"), siemens("DRILL_REAM", 200, "-12")).unwrap();
    std::fs::write(site.path("share/PLATE7.MPF"), siemens("HOLES", 200, "-12")).unwrap();
    let compared = site.wait_for(
        "SELECT p.path, c.rule, c.changes FROM comparisons c JOIN revisions r ON r.id = c.original_revision_id
         JOIN programs p ON p.id = r.program_id",
        1,
    );
    assert_eq!(compared.len(), 1, "{compared:?}");
    assert!(compared[0][0].ends_with("cam/DRILL_REAM.MPF"), "{compared:?}");
    assert_eq!(compared[0][1], "program-name");
    let changes = site.rows("SELECT program, kind, before, after FROM shopfloor_changes");
    assert_eq!(changes, [["DRILL_REAM", "feed_changed", "F300", "F200"]]);
    let ambiguous = site.wait_for(
        "SELECT d.message FROM diagnostics d JOIN revisions r ON r.id = d.revision_id JOIN programs p ON p.id = r.program_id
         WHERE d.code = 'pairing::ambiguous' AND p.path LIKE '%PLATE7.MPF'",
        1,
    );
    assert_eq!(ambiguous.len(), 1);
    assert!(ambiguous[0][0].contains("2 CAM originals have the program-name `HOLES`"), "{ambiguous:?}");
    assert!(ambiguous[0][0].contains("HOLES_A.MPF") && ambiguous[0][0].contains("HOLES_B.MPF"), "{ambiguous:?}");
    daemon.kill();
}

#[test]
fn a_writer_that_pauses_with_the_file_open_is_not_stored_half_written() {
    let site = Site::new("");
    let daemon = site.start();
    let full = program(42, 300);
    let (head, tail) = full.split_at(full.len() / 2);
    let mut f = std::fs::File::create(site.path("share/O42.nc")).unwrap();
    f.write_all(head.as_bytes()).unwrap();
    f.sync_all().unwrap();
    // Longer than the settle window, with the file still open.
    std::thread::sleep(Duration::from_millis(1200));
    assert!(site.rows("SELECT id FROM revisions").is_empty(), "a half-written file was stored");
    f.write_all(tail.as_bytes()).unwrap();
    drop(f);
    let stored = site.wait_for("SELECT CAST(b.content AS TEXT) FROM revisions r JOIN blobs b ON b.hash = r.hash", 1);
    std::thread::sleep(Duration::from_millis(600));
    assert_eq!(site.rows("SELECT id FROM revisions").len(), 1);
    assert_eq!(stored[0][0], full);
    daemon.kill();
}

/// Ingests `rel` of `site` with the clock reading `now`, as the worker does.
pub(crate) fn ingest_at(site: &Site, store: &mut Store, rel: &str, now: &str, expected: Option<Snapshot>) -> Outcome {
    let mut config = site.config();
    config.probe_exe = Some(crate::bin().to_path_buf());
    ingest_with(site, store, rel, now, expected, config)
}

fn ingest_with(site: &Site, store: &mut Store, rel: &str, now: &str, expected: Option<Snapshot>, config: Config) -> Outcome {
    let path = site.path(rel);
    let folder = if rel.starts_with("cam/") { 0 } else { 1 };
    let root = std::fs::canonicalize(&config.folders[folder].path).unwrap();
    ingest(&path, &config.folders[folder], &root, &config, &Registry::shipped(), store, now, expected).unwrap()
}

#[test]
fn a_file_that_changed_since_it_settled_is_not_stored() {
    for mut engine in crate::pg::engines("faults::a_file_that_changed_since_it_settled_is_not_stored") {
        let store = &mut engine.store;
        let site = Site::new("");
        let path = site.path("share/O5.nc");
        std::fs::write(&path, program(5, 300)).unwrap();
        let meta = std::fs::metadata(&path).unwrap();
        // The settle logic saw a shorter file: it was rewritten after it settled.
        let seen = Snapshot { size: meta.len() - 10, mtime: meta.modified().ok() };
        assert_eq!(ingest_at(&site, store, "share/O5.nc", "2026-12-01T10:00:00.000Z", Some(seen)), Outcome::Changing);
        assert_eq!(store.query("SELECT id FROM revisions").unwrap().1.len(), 0);
        let now = Snapshot { size: meta.len(), mtime: meta.modified().ok() };
        assert!(matches!(ingest_at(&site, store, "share/O5.nc", "2026-12-01T10:00:01.000Z", Some(now)), Outcome::Stored { .. }));
    }
}

#[test]
fn a_strict_prefix_seconds_before_the_next_revision_is_a_partial_write() {
    for mut engine in crate::pg::engines("faults::a_strict_prefix_seconds_before_the_next_revision_is_a_partial_write") {
        let store = &mut engine.store;
        let site = Site::new("");
        std::fs::write(site.path("cam/O9.nc"), program(9, 300)).unwrap();
        ingest_at(&site, store, "cam/O9.nc", "2026-12-01T10:00:00.000Z", None);
        let edited = program(9, 250);
        std::fs::write(site.path("share/O9.nc"), &edited[..edited.len() * 2 / 3]).unwrap();
        ingest_at(&site, store, "share/O9.nc", "2026-12-01T10:05:00.000Z", None);
        std::fs::write(site.path("share/O9.nc"), &edited).unwrap();
        ingest_at(&site, store, "share/O9.nc", "2026-12-01T10:05:03.500Z", None);
        let marks = store.query("SELECT revision_id, mark, superseded_by FROM revision_marks").unwrap().1;
        assert_eq!(marks, [["2", "partial", "3"]]);
        let finding = store.query("SELECT message FROM diagnostics WHERE code = 'text::partial-write' AND revision_id = 2").unwrap().1;
        assert!(finding[0][0].contains("3.5 s later"), "{finding:?}");
        // Only the complete revision's changes are reported.
        let reported = store.query("SELECT revision_id, kind, before, after FROM shopfloor_changes").unwrap().1;
        assert_eq!(reported, [["3", "feed_changed", "F300", "F250"]]);

        // The same growth a day apart is an edit, not a partial write.
        let grown = format!("{edited}(SETUP NOTE)\n");
        std::fs::write(site.path("share/O9.nc"), &grown).unwrap();
        ingest_at(&site, store, "share/O9.nc", "2026-12-02T10:00:00.000Z", None);
        assert_eq!(store.query("SELECT * FROM revision_marks").unwrap().1.len(), 1);
    }
}

#[test]
fn a_partial_original_is_replaced_in_the_comparisons_made_with_it() {
    for mut engine in crate::pg::engines("faults::a_partial_original_is_replaced_in_the_comparisons_made_with_it") {
        let store = &mut engine.store;
        let site = Site::new("");
        let original = program(3, 300);
        std::fs::write(site.path("share/O3.nc"), program(3, 250)).unwrap();
        ingest_at(&site, store, "share/O3.nc", "2026-12-01T10:00:00.000Z", None);
        std::fs::write(site.path("cam/O3.nc"), &original[..original.len() / 2]).unwrap();
        ingest_at(&site, store, "cam/O3.nc", "2026-12-01T11:00:00.000Z", None);
        std::fs::write(site.path("cam/O3.nc"), &original).unwrap();
        ingest_at(&site, store, "cam/O3.nc", "2026-12-01T11:00:02.000Z", None);
        let compared = store.query("SELECT revision_id, original_revision_id FROM comparisons").unwrap().1;
        assert_eq!(compared, [["1", "3"]]);
        let reported = store.query("SELECT kind, before, after FROM shopfloor_changes").unwrap().1;
        assert_eq!(reported, [["feed_changed", "F300", "F250"]]);
    }
}

#[test]
fn an_empty_file_is_stored_and_never_compared() {
    for mut engine in crate::pg::engines("faults::an_empty_file_is_stored_and_never_compared") {
        let store = &mut engine.store;
        let site = Site::new("");
        std::fs::write(site.path("cam/O4.nc"), program(4, 300)).unwrap();
        ingest_at(&site, store, "cam/O4.nc", "2026-12-01T10:00:00.000Z", None);
        for (i, content) in [&b""[..], b"\0\0\0\0\0\0\0\0", b"\r\n \r\n"].into_iter().enumerate() {
            std::fs::write(site.path("share/O4.nc"), content).unwrap();
            let out = ingest_at(&site, store, "share/O4.nc", &format!("2026-12-01T1{}:00:00.000Z", i + 1), None);
            assert!(matches!(out, Outcome::Stored { changes: None, .. }), "{out:?}");
        }
        let revs =
            store.query("SELECT r.status, d.code FROM revisions r JOIN diagnostics d ON d.revision_id = r.id WHERE r.id > 1").unwrap().1;
        assert_eq!(revs, [["empty", "text::empty"], ["empty", "text::empty"], ["empty", "text::empty"]]);
        assert!(store.query("SELECT * FROM comparisons").unwrap().1.is_empty());
        // An empty CAM revision is no original either: the edit is compared with the last real one.
        std::fs::write(site.path("cam/O4.nc"), b"").unwrap();
        ingest_at(&site, store, "cam/O4.nc", "2026-12-01T15:00:00.000Z", None);
        std::fs::write(site.path("share/O4.nc"), program(4, 250)).unwrap();
        let out = ingest_at(&site, store, "share/O4.nc", "2026-12-01T16:00:00.000Z", None);
        assert!(matches!(out, Outcome::Stored { changes: Some(1), .. }), "{out:?}");
        assert_eq!(store.query("SELECT original_revision_id FROM comparisons").unwrap().1, [["1"]]);
    }
}

#[test]
fn old_revisions_keep_the_name_they_had() {
    for mut engine in crate::pg::engines("faults::old_revisions_keep_the_name_they_had") {
        let store = &mut engine.store;
        let site = Site::new("[matching]\npattern = '^(?P<key>PART)'\n");
        std::fs::write(site.path("cam/PART.nc"), program(100, 300)).unwrap();
        ingest_at(&site, store, "cam/PART.nc", "2026-12-01T10:00:00.000Z", None);
        std::fs::write(site.path("share/PART.nc"), program(100, 250)).unwrap();
        ingest_at(&site, store, "share/PART.nc", "2026-12-01T11:00:00.000Z", None);
        // The operator saves another program over the same file.
        std::fs::write(site.path("share/PART.nc"), program(200, 280)).unwrap();
        ingest_at(&site, store, "share/PART.nc", "2026-12-01T12:00:00.000Z", None);
        let reported = store.query("SELECT revision_id, program, after FROM shopfloor_changes ORDER BY change_id").unwrap().1;
        assert_eq!(reported, [["2", "O100", "F250"], ["3", "O200", "F280"]]);
    }
}

#[test]
fn a_link_out_of_the_share_is_never_followed() {
    let site = Site::new("");
    let outside = site.path("outside");
    std::fs::create_dir_all(outside.join("dir")).unwrap();
    std::fs::write(outside.join("secret.nc"), "SECRET CONTENT\n").unwrap();
    std::fs::write(outside.join("dir/O77.nc"), "SECRET FOLDER CONTENT\n").unwrap();
    std::os::unix::fs::symlink(outside.join("secret.nc"), site.path("share/O66.nc")).unwrap();
    std::os::unix::fs::symlink("/etc/passwd", site.path("share/passwd.nc")).unwrap();
    std::os::unix::fs::symlink(outside.join("dir"), site.path("share/linked")).unwrap();
    // A link that stays inside the share is content the share holds.
    std::fs::write(site.path("share/O1.nc"), program(1, 300)).unwrap();
    std::os::unix::fs::symlink(site.path("share/O1.nc"), site.path("share/O1_LINK.nc")).unwrap();
    let daemon = site.start();
    site.wait_for("SELECT id FROM revisions", 2);
    // New links appear while it runs too.
    std::os::unix::fs::symlink(outside.join("secret.nc"), site.path("share/O67.nc")).unwrap();
    std::thread::sleep(Duration::from_millis(1200));
    let stored = site.rows(
        "SELECT p.path, CAST(b.content AS TEXT) FROM revisions r JOIN programs p ON p.id = r.program_id JOIN blobs b ON b.hash = r.hash",
    );
    assert!(stored.iter().all(|r| !r[1].contains("SECRET") && !r[1].contains("root:")), "{stored:?}");
    let mut paths: Vec<String> = stored.iter().map(|r| r[0].rsplit('/').next().unwrap().to_owned()).collect();
    paths.sort();
    assert_eq!(paths, ["O1.nc", "O1_LINK.nc"]);
    let log = site.log();
    for name in ["O66.nc", "passwd.nc", "O67.nc"] {
        let said =
            log.lines().filter(|l| l.contains("Refused a file") && l.contains("outside the watched folder") && l.contains(name)).count();
        assert_eq!(said, 1, "{name}:\n{log}");
    }
    daemon.kill();
}

#[test]
fn a_replaced_share_is_watched_again_at_once() {
    let site = Site::new("");
    // A long rescan interval: only the share check can find the new files in time.
    let text = std::fs::read_to_string(site.path("ncplan.toml")).unwrap();
    std::fs::write(site.path("ncplan.toml"), text.replace("settle_ms = 200\n", "settle_ms = 200\nrescan_s = 3600\n")).unwrap();
    let daemon = site.start();
    std::fs::write(site.path("share/O1.nc"), program(1, 300)).unwrap();
    site.wait_for("SELECT id FROM revisions", 1);
    // The share is unmounted and another one mounted at the same place: here, the folder
    // is moved away and a new one made, which gives the same dead watch.
    std::fs::rename(site.path("share"), site.path("share.old")).unwrap();
    std::fs::create_dir(site.path("share")).unwrap();
    std::thread::sleep(Duration::from_millis(1500));
    let landed = Instant::now();
    std::fs::write(site.path("share/O2.nc"), program(2, 300)).unwrap();
    let revs = site.wait_for("SELECT id FROM revisions", 2);
    assert_eq!(revs.len(), 2, "a file in the new share was not seen");
    assert!(landed.elapsed() < Duration::from_secs(10));
    assert_eq!(site.wait_log("remounted or replaced", 1), 1, "{}", site.log());
    // A file written into the old folder is not the share's.
    std::fs::write(site.path("share.old/O3.nc"), program(3, 300)).unwrap();
    std::thread::sleep(Duration::from_millis(800));
    assert_eq!(site.rows("SELECT id FROM revisions").len(), 2);
    daemon.kill();
}

#[test]
fn a_share_that_goes_down_is_said_once_and_watched_again_when_it_is_back() {
    let site = Site::new("");
    let text = std::fs::read_to_string(site.path("ncplan.toml")).unwrap();
    std::fs::write(site.path("ncplan.toml"), text.replace("dialect = 'fanuc'\n", "dialect = 'fanuc'\npoll = true\npoll_ms = 100\n"))
        .unwrap();
    let daemon = site.start();
    std::fs::rename(site.path("share"), site.path("gone")).unwrap();
    std::thread::sleep(Duration::from_millis(3500));
    std::fs::rename(site.path("gone"), site.path("share")).unwrap();
    std::fs::write(site.path("share/O8.nc"), program(8, 300)).unwrap();
    assert_eq!(site.wait_for("SELECT id FROM revisions", 1).len(), 1);
    let log = site.log();
    let down = log.lines().filter(|l| l.contains("WARN") && l.contains("share")).count();
    // Down once (for each watched share that went), back once: never once per poll.
    assert!((2..=4).contains(&down), "{down} warnings:\n{log}");
    daemon.kill();
}

#[test]
fn a_tmpfs_mounted_over_the_share_is_watched() {
    let site = Site::new("");
    let probe = site.path("probe");
    std::fs::create_dir_all(&probe).unwrap();
    let can_mount =
        Command::new("mount").args(["-t", "tmpfs", "tmpfs"]).arg(&probe).stderr(Stdio::null()).status().is_ok_and(|s| s.success());
    if !can_mount {
        crate::skip(
            "faults::a_tmpfs_mounted_over_the_share_is_watched",
            "mounting a tmpfs is not permitted here (it needs root with CAP_SYS_ADMIN); faults::a_replaced_share_is_watched_again_at_once covers the dead watch",
        );
        return;
    }
    let _ = Command::new("umount").arg(&probe).status();
    let daemon = site.start();
    std::fs::write(site.path("share/O1.nc"), program(1, 300)).unwrap();
    site.wait_for("SELECT id FROM revisions", 1);
    assert!(Command::new("mount").args(["-t", "tmpfs", "tmpfs"]).arg(site.path("share")).status().unwrap().success());
    std::thread::sleep(Duration::from_millis(1500));
    std::fs::write(site.path("share/O2.nc"), program(2, 300)).unwrap();
    let revs = site.wait_for("SELECT id FROM revisions", 2);
    let _ = Command::new("umount").arg(site.path("share")).status();
    assert_eq!(revs.len(), 2, "{}", site.log());
    daemon.kill();
}

#[test]
fn a_file_over_the_size_limit_is_stored_as_its_hash_and_size_and_analysed_by_no_one() {
    for mut engine in crate::pg::engines("faults::a_file_over_the_size_limit_is_stored_as_its_hash_and_size_and_analysed_by_no_one") {
        let store = &mut engine.store;
        let site = Site::new("");
        let text = std::fs::read_to_string(site.path("ncplan.toml")).unwrap();
        std::fs::write(site.path("ncplan.toml"), text.replace("settle_ms = 200\n", "settle_ms = 200\nmax_file_mb = 1\n")).unwrap();
        let mut big = String::from("%\nO8 (SURFACE)\nT1 M6\nS9000 M3\nG0 X0 Y0 Z5\nG1 Z0 F900\n");
        for i in 0..60_000 {
            big.push_str(&format!("X{}.{:03} Y{}.500 Z-0.{:04}\n", i % 100, i % 1000, i / 500, i % 9999));
        }
        big.push_str("M30\n%\n");
        assert!(big.len() > 1 << 20);
        std::fs::write(site.path("share/O8.nc"), &big).unwrap();
        let out = ingest_at(&site, store, "share/O8.nc", "2026-12-01T10:00:00.000Z", None);
        assert!(matches!(out, Outcome::Stored { changes: None, .. }), "{out:?}");
        let rows = store
        .query("SELECT r.status, r.size, b.size, length(b.content), r.hash, d.code FROM revisions r JOIN blobs b ON b.hash = r.hash JOIN diagnostics d ON d.revision_id = r.id ORDER BY d.id")
        .unwrap()
        .1;
        // The limit bounds what is stored: a revision row with the size and hash, not the bytes.
        let size = big.len().to_string();
        assert_eq!(rows[0][..4], ["too_large", size.as_str(), size.as_str(), "0"]);
        assert_eq!(rows[0][4], ncplan::daemon::ingest::sha256_hex(big.as_bytes()));
        assert_eq!(rows[0][5], "text::too-large");
        assert!(store.query("SELECT * FROM plans").unwrap().1.is_empty());
        // Seen again unchanged, it is not stored again.
        let again = ingest_at(&site, store, "share/O8.nc", "2026-12-01T10:05:00.000Z", None);
        assert_eq!(again, Outcome::Unchanged);
        // Two sparse files of 64 MB: two rows, not 128 MB of zeros.
        for name in ["share/SPARSE1.nc", "share/SPARSE2.nc"] {
            let f = std::fs::File::create(site.path(name)).unwrap();
            f.set_len(64 << 20).unwrap();
            (&f).write_all(format!("{name}\n").as_bytes()).unwrap();
            let out = ingest_at(&site, store, name, "2026-12-01T10:10:00.000Z", None);
            assert!(matches!(out, Outcome::Stored { changes: None, .. }), "{out:?}");
        }
        let kept = store.query("SELECT SUM(length(content)), COUNT(*) FROM blobs").unwrap().1;
        assert_eq!(kept, [["0", "3"]]);
    }
}

#[test]
fn content_whose_analysis_killed_the_process_is_stored_once_without_analysis() {
    for mut engine in crate::pg::engines("faults::content_whose_analysis_killed_the_process_is_stored_once_without_analysis") {
        let store = &mut engine.store;
        let site = Site::new("");
        // One analysis that never finished is no evidence against the content: a kill from
        // outside lands on whatever is being analysed. It is analysed again, and stored so.
        let once = program(11, 300);
        std::fs::write(site.path("share/O11.nc"), &once).unwrap();
        let at = site.path("share/O11.nc").to_string_lossy().into_owned();
        let hash = ncplan::daemon::ingest::sha256_hex(once.as_bytes());
        assert_eq!(store.begin_attempt(&hash, &at, "2026-12-01T09:00:00.000Z").unwrap(), 0);
        ingest_at(&site, store, "share/O11.nc", "2026-12-01T09:30:00.000Z", None);
        let rows = store.query("SELECT r.status FROM revisions r").unwrap().1;
        assert_eq!(rows, [["analysed"]]);
        assert!(store.query("SELECT * FROM attempts").unwrap().1.is_empty(), "the journal is closed once the analysis returns");

        let text = program(12, 300);
        std::fs::write(site.path("share/O12.nc"), &text).unwrap();
        // Earlier runs began analysing this content twice and never finished (killed by a memory
        // limit), and a trial in a process of its own dies too (a stand-in that kills itself).
        let hash = ncplan::daemon::ingest::sha256_hex(text.as_bytes());
        let at = site.path("share/O12.nc").to_string_lossy().into_owned();
        assert_eq!(store.begin_attempt(&hash, &at, "2026-12-01T09:00:00.000Z").unwrap(), 0);
        assert_eq!(store.begin_attempt(&hash, &at, "2026-12-01T09:10:00.000Z").unwrap(), 1);
        let dies = site.path("dies.sh");
        std::fs::write(&dies, "#!/bin/sh\nkill -9 $$\n").unwrap();
        std::fs::set_permissions(&dies, std::os::unix::fs::PermissionsExt::from_mode(0o755)).unwrap();
        let mut config = site.config();
        config.probe_exe = Some(dies);
        let out = ingest_with(&site, store, "share/O12.nc", "2026-12-01T10:00:00.000Z", None, config);
        assert!(matches!(out, Outcome::Stored { changes: None, .. }), "{out:?}");
        let rows = store
            .query(
                "SELECT r.status, d.code, d.message FROM revisions r JOIN programs p ON p.id = r.program_id
                 JOIN diagnostics d ON d.revision_id = r.id WHERE p.path LIKE '%O12.nc'",
            )
            .unwrap()
            .1;
        assert_eq!(rows[0][..2], ["failed", "text::analysis-failed"]);
        assert!(rows[0][2].contains("ended the process 2 time(s) before"), "{rows:?}");
        assert!(store.query("SELECT * FROM attempts").unwrap().1.is_empty(), "the journal is closed with the revision");
        // It is not retried: the same content again is unchanged.
        assert_eq!(ingest_at(&site, store, "share/O12.nc", "2026-12-01T10:01:00.000Z", None), Outcome::Unchanged);
        // The same content in another file is analysed: the journal is per file.
        std::fs::write(site.path("share/O12_COPY.nc"), &text).unwrap();
        ingest_at(&site, store, "share/O12_COPY.nc", "2026-12-01T10:02:00.000Z", None);
        let copy = store
            .query("SELECT r.status FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.path LIKE '%O12_COPY.nc'")
            .unwrap()
            .1;
        assert_eq!(copy, [["analysed"]]);

        // Two analyses cut short by kills from outside, and the trial reads it through: the
        // content is analysed (a kill loop never loses an original this way).
        let text = program(13, 300);
        std::fs::write(site.path("share/O13.nc"), &text).unwrap();
        let hash = ncplan::daemon::ingest::sha256_hex(text.as_bytes());
        let at = site.path("share/O13.nc").to_string_lossy().into_owned();
        store.begin_attempt(&hash, &at, "2026-12-01T11:00:00.000Z").unwrap();
        store.begin_attempt(&hash, &at, "2026-12-01T11:01:00.000Z").unwrap();
        ingest_at(&site, store, "share/O13.nc", "2026-12-01T11:02:00.000Z", None);
        let rows =
            store.query("SELECT r.status FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.path LIKE '%O13.nc'").unwrap().1;
        assert_eq!(rows, [["analysed"]]);
    }
}

#[test]
fn plans_are_stored_without_toolpaths_and_rebuilt_from_the_program_for_the_diff() {
    for mut engine in crate::pg::engines("faults::plans_are_stored_without_toolpaths_and_rebuilt_from_the_program_for_the_diff") {
        let store = &mut engine.store;
        let site = Site::new("");
        std::fs::write(site.path("cam/O21.nc"), program(21, 300)).unwrap();
        ingest_at(&site, store, "cam/O21.nc", "2026-12-01T10:00:00.000Z", None);
        // The operator shortens one pass: only the toolpath tells.
        std::fs::write(site.path("share/O21.nc"), program(21, 300).replace("X110\n", "X104\n")).unwrap();
        let out = ingest_at(&site, store, "share/O21.nc", "2026-12-01T11:00:00.000Z", None);
        assert!(matches!(out, Outcome::Stored { changes: Some(n), .. } if n >= 1), "{out:?}");
        let plans = store.query("SELECT plan_json, complete FROM plans").unwrap().1;
        for p in &plans {
            let v: serde_json::Value = serde_json::from_str(&p[0]).unwrap();
            assert!(v["workingsteps"].as_array().unwrap().iter().all(|w| w["toolpath"].as_array().is_some_and(Vec::is_empty)), "{}", p[0]);
            assert_eq!(p[1], "0");
        }
        assert!(!store.query("SELECT kind FROM changes").unwrap().1.is_empty());
        // The queryable tables are filled from the summary.
        assert_eq!(store.query("SELECT operation FROM workingsteps WHERE revision_id = 1").unwrap().1.len(), 1);
    }
}

#[test]
fn a_site_named_later_still_pairs_with_the_originals_stored_before() {
    // A server's SQLite file from before sites (or before `site` was configured): its rows
    // have a blank site, and the server, now named, still pairs with them.
    let site = Site::new("");
    std::fs::create_dir_all(site.path("var")).unwrap();
    let db = ncplan::store::Location::Sqlite(site.db());
    {
        let mut store = Store::open(&db, "").unwrap();
        std::fs::write(site.path("cam/O4.nc"), program(4, 300)).unwrap();
        ingest_at(&site, &mut store, "cam/O4.nc", "2026-12-01T10:00:00.000Z", None);
    }
    let mut store = Store::open(&db, "HALL2").unwrap();
    std::fs::write(site.path("share/O4.nc"), program(4, 250)).unwrap();
    ingest_at(&site, &mut store, "share/O4.nc", "2026-12-01T10:05:00.000Z", None);
    let rows = store.query("SELECT kind, before, after, site FROM shopfloor_changes").unwrap().1;
    assert_eq!(rows, [["feed_changed", "F300", "F250", "HALL2"]]);
}

#[test]
fn a_huge_revision_leaves_no_log_of_its_size_beside_the_database() {
    // The revision is one transaction, so its bytes pass through the write-ahead log; the
    // log must give that space back while the daemon keeps the database open.
    let site = Site::new("");
    std::fs::create_dir_all(site.path("var")).unwrap();
    let db = ncplan::store::Location::Sqlite(site.db());
    let mut store = Store::open(&db, "").unwrap();
    let mut text = String::from("%\nO30 (SURFACE)\nG21 G90 G17\nT1 M6\nS2000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F300\n");
    for i in 0..600_000 {
        text.push_str(&format!("X{}.{:03} Y{}\n", i % 100, i % 1000, i % 7));
    }
    text.push_str("G0 Z50\nM30\n%\n");
    assert!(text.len() > 6 << 20, "{} bytes", text.len());
    std::fs::write(site.path("cam/O30.nc"), &text).unwrap();
    let out = ingest_at(&site, &mut store, "cam/O30.nc", "2026-12-01T10:00:00.000Z", None);
    assert!(matches!(out, Outcome::Stored { .. }), "{out:?}");
    let wal = std::fs::metadata(site.path("var/ncplan.db-wal")).map_or(0, |m| m.len());
    assert!(wal < 1 << 20, "the write-ahead log kept {wal} bytes");
    let db_len = std::fs::metadata(site.db()).unwrap().len();
    assert!(db_len >= text.len() as u64, "the database holds the program: {db_len} bytes");
}

/// The daemon compares revisions as `ncplan diff` does, on one machine: the CAM original's
/// arcs show X read as radii, the operator's edit turns one of them into a chamfer so that the
/// edited program alone no longer shows it. The stored comparison names the edited line
/// only; no size elsewhere changes and the unedited arc is no error the edit "breaks".
#[test]
fn a_revision_is_compared_on_the_machine_its_original_shows() {
    for mut engine in crate::pg::engines("faults::a_revision_is_compared_on_the_machine_its_original_shows") {
        let store = &mut engine.store;
        let site = Site::with("fanuc_lathe", "");
        let a = "O1000\nG18 G21 G99\nT0101\nG97 S1000 M3\nG0 X20. Z2.\nG1 X10. Z0. F0.2\nG2 X15. Z-5. I5. K0.\nG1 Z-20.\n\
                 G2 X20. Z-25. I5. K0.\nG1 Z-40.\nG0 X30.\nG0 Z2.\nM30\n";
        std::fs::write(site.path("cam/O1000.nc"), a).unwrap();
        std::fs::write(site.path("share/O1000.nc"), a.replace("G2 X20. Z-25. I5. K0.", "G1 X20. Z-25.")).unwrap();
        assert!(matches!(ingest_at(&site, store, "cam/O1000.nc", "2026-12-01T10:00:00.000Z", None), Outcome::Stored { .. }));
        assert!(matches!(ingest_at(&site, store, "share/O1000.nc", "2026-12-01T10:00:01.000Z", None), Outcome::Stored { .. }));
        let changes = store.query("SELECT kind, line FROM changes ORDER BY id").unwrap().1;
        assert!(!changes.is_empty(), "the edit is a change");
        for row in &changes {
            assert_ne!(row[0], "program_broken", "{changes:?}");
            assert_eq!(row[1], "9", "{changes:?}");
        }
    }
}

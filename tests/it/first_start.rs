//! A newcomer's first start: the README's demo as written, `show`, `query`'s refusals, and
//! configuration mistakes told in plain words that name the file.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::Duration;

fn ncplan_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(crate::bin()).args(args).current_dir(dir).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// A copy of the checkout's demo, so that the demo's own folders are left alone.
fn demo_checkout() -> tempfile::TempDir {
    let tmp = tempfile::tempdir().unwrap();
    for rel in ["demo/cam/O1234.nc", "demo/examples/O1234_edited.nc"] {
        let to = tmp.path().join(rel);
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(crate::root().join(rel), to).unwrap();
    }
    for share in ["demo/shares/DMU50", "demo/shares/HAAS1"] {
        std::fs::create_dir_all(tmp.path().join(share)).unwrap();
    }
    tmp
}

#[test]
fn the_readme_demo_works_as_written() {
    let checkout = demo_checkout();
    let dir = checkout.path();
    let mut daemon = Command::new(crate::bin()).arg("watch").current_dir(dir).stdout(Stdio::piped()).stderr(Stdio::null()).spawn().unwrap();
    // A newcomer copies the edit from a second terminal, by which time the daemon has stored
    // the CAM original (on a loaded machine that can take longer than a fixed pause).
    let deadline = std::time::Instant::now() + Duration::from_secs(30);
    while crate::db_rows(&dir.join("var/ncplan.db"), "SELECT COUNT(*) FROM revisions").first().and_then(|r| r.first()).map(String::as_str)
        != Some("1")
    {
        assert!(std::time::Instant::now() < deadline, "the demo's CAM original was never stored");
        std::thread::sleep(Duration::from_millis(20));
    }
    std::fs::copy(dir.join("demo/examples/O1234_edited.nc"), dir.join("demo/shares/DMU50/O1234.nc")).unwrap();
    let (code, out, err) = ncplan_in(dir, &["report", "--wait"]);
    let _ = daemon.kill();
    let output = daemon.wait_with_output().unwrap();
    assert_eq!(code, 0, "{err}");
    assert!(
        out.contains(
            "workingstep 1 (plane finish milling): tool T1 renamed T8 at line 5; start point moved from X90 Y20 to X83 Y20 at line 6"
        ),
        "{out}\n{err}"
    );
    let banner = String::from_utf8_lossy(&output.stdout);
    assert!(banner.contains("report --wait") && banner.contains("cp demo/examples/O1234_edited.nc"), "{banner}");
    assert!(!dir.join("demo/shares/DMU50/var").exists());

    // `show` by the path's end, by id, its source and its plan.
    let (code, out, err) = ncplan_in(dir, &["show", "DMU50/O1234.nc"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("revision 2: machine DMU50, program O1234"), "{out}");
    assert!(out.contains("paired by program-name: 3 changes"), "{out}");
    let (_, source, _) = ncplan_in(dir, &["show", "2", "--source"]);
    assert_eq!(source, std::fs::read_to_string(dir.join("demo/examples/O1234_edited.nc")).unwrap());
    let (_, plan, _) = ncplan_in(dir, &["show", "1", "--plan"]);
    assert!(serde_json::from_str::<serde_json::Value>(&plan).unwrap()["workingsteps"].is_array());
    let (code, _, err) = ncplan_in(dir, &["show", "O1234.nc"]);
    assert_eq!(code, 2);
    assert!(err.contains("names several programs") && err.contains("demo/cam/O1234.nc"), "{err}");
    let (code, _, err) = ncplan_in(dir, &["show", "DMU50/O1234.nc", "--at", "2020-01-01"]);
    assert_eq!(code, 2);
    assert!(err.contains("no stored revision"), "{err}");
}

#[test]
fn the_demo_refuses_to_run_outside_the_checkout_root() {
    let checkout = demo_checkout();
    let sub = checkout.path().join("demo/cam");
    let (code, out, err) = ncplan_in(&sub, &["watch"]);
    assert_eq!(code, 2);
    assert!(err.contains("run it from the checkout's root, or give --config FILE"), "{err}");
    assert!(out.is_empty(), "no banner before the refusal: {out}");
    assert!(!sub.join("var").exists(), "a stray var/");
}

#[test]
fn query_refuses_in_plain_words() {
    let checkout = demo_checkout();
    let dir = checkout.path();
    let db = dir.join("x.db");
    ncplan::store::Store::open(&ncplan::store::Location::Sqlite(db.clone()), "").unwrap();
    let db = db.to_str().unwrap();
    for (sql, said) in [
        ("SELECT 1; DROP TABLE changes", "one statement at a time: `DROP TABLE changes` was not run"),
        ("VACUUM INTO '/tmp/ncplan-stolen.db'", "`VACUUM` is refused"),
        ("DELETE FROM changes", "`DELETE` is refused"),
        ("ATTACH '/tmp/x.db' AS x", "`ATTACH` is refused"),
        ("SELECT * FROM nowhere", "no such table: nowhere"),
    ] {
        let (code, _, err) = ncplan_in(dir, &["query", "--db", db, sql]);
        assert_eq!(code, 2, "{sql}");
        assert!(err.contains(said), "{sql}: {err}");
        assert!(!err.contains("disk I/O") && !err.contains("while"), "{sql}: {err}");
    }
    assert!(!Path::new("/tmp/ncplan-stolen.db").exists());
    // A trailing semicolon or comment is one statement.
    let (code, out, err) = ncplan_in(dir, &["query", "--db", db, "SELECT 'a;b' AS s; -- done"]);
    assert_eq!((code, out.as_str()), (0, "s\na;b\n"), "{err}");
}

#[test]
fn configuration_mistakes_name_the_file_and_say_what_is_wrong() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(tmp.path().join("m")).unwrap();
    let cases = [
        ("[database]\npath = 'x.db'\n", "no folders to watch"),
        (
            "[database]\npath = 'x.db'\n[daemon]\nsettle_ms = 10\n[[machine]]\nname = 'M'\npath = 'm'\ndialect = 'fanuc'\n",
            "settle_ms = 10 is below",
        ),
        (
            "[database]\npath = 'x.db'\n[daemon]\nrescan_s = 1\n[[machine]]\nname = 'M'\npath = 'm'\ndialect = 'fanuc'\n",
            "rescan_s = 1 is below",
        ),
        ("[database]\npath = 'x.db'\n[[machine]]\nname = 'M'\npath = 'm'\ndialect = 'fanucc'\n", "unknown dialect `fanucc`"),
    ];
    for (i, (text, said)) in cases.iter().enumerate() {
        let file = tmp.path().join(format!("c{i}.toml"));
        std::fs::write(&file, text).unwrap();
        let (code, out, err) = ncplan_in(tmp.path(), &["watch", "--config", file.to_str().unwrap()]);
        assert_eq!(code, 2, "{text}");
        assert!(err.contains(said), "{text}: {err}");
        if i > 0 {
            assert!(err.contains(&format!("c{i}.toml")) || i == 3, "the file is named: {err}");
        }
        assert!(out.is_empty(), "no banner before a refusal: {out}");
    }
}

#[test]
fn logs_to_a_file_carry_no_colour_codes() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(tmp.path().join("m")).unwrap();
    let config = tmp.path().join("c.toml");
    std::fs::write(&config, "[database]\npath = 'db/x.db'\n[[machine]]\nname = 'M'\npath = 'm'\ndialect = 'linuxcnc'\n").unwrap();
    let log = std::fs::File::create(tmp.path().join("log")).unwrap();
    let mut d = Command::new(crate::bin())
        .current_dir(tmp.path())
        .args(["watch", "--config"])
        .arg(&config)
        .stdout(Stdio::null())
        .stderr(log)
        .spawn()
        .unwrap();
    std::thread::sleep(Duration::from_millis(700));
    let _ = d.kill();
    let _ = d.wait();
    let text = std::fs::read_to_string(tmp.path().join("log")).unwrap();
    assert!(text.contains("Watching a folder"), "{text}");
    assert!(!text.contains('\u{1b}'), "{text:?}");
}

#[test]
fn import_stores_dated_backups_with_their_file_times_and_resumes() {
    let tmp = tempfile::tempdir().unwrap();
    let dir = tmp.path();
    for sub in ["cam", "share", "backups/2024-01-10", "backups/2024-02-20", "backups/2024-03-05"] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
    }
    let config = dir.join("c.toml");
    std::fs::write(
        &config,
        "[database]\npath = 'var/x.db'\n[[cam]]\npath = 'cam'\ndialect = 'fanuc'\n[[machine]]\nname = 'DMU50'\npath = 'share'\ndialect = 'fanuc'\n",
    )
    .unwrap();
    let original = std::fs::read_to_string(crate::root().join("demo/cam/O1234.nc")).unwrap();
    std::fs::copy(crate::root().join("demo/cam/O1234.nc"), dir.join("cam/O1234.nc")).unwrap();
    let (c, _, err) = ncplan_in(dir, &["import", "--cam", "cam", "--config", "c.toml"]);
    assert_eq!(c, 2, "the watched folder itself is refused");
    assert!(err.contains("the watched folder itself"), "{err}");
    let edited = std::fs::read_to_string(crate::root().join("demo/examples/O1234_edited.nc")).unwrap();
    for (day, text) in [("2024-01-10", &original), ("2024-02-20", &edited), ("2024-03-05", &edited)] {
        let f = dir.join(format!("backups/{day}/O1234.nc"));
        std::fs::write(&f, text).unwrap();
        assert!(Command::new("touch").args(["-d", &format!("{day} 12:00:00 UTC")]).arg(&f).status().unwrap().success());
    }
    std::fs::write(dir.join("backups/2024-03-05/O2000.nc"), "%\nO2000\nT2 M6\nS900 M3\nG0 X0 Y0 Z5\nG1 Z-1 F80\nX20\nM30\n%\n").unwrap();
    // The originals first, then the machine's backups.
    std::fs::create_dir_all(dir.join("cam_archive")).unwrap();
    std::fs::copy(dir.join("cam/O1234.nc"), dir.join("cam_archive/O1234.nc")).unwrap();
    let (code, out, err) = ncplan_in(dir, &["import", "cam_archive", "--cam", "--config", "c.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    let (code, out, err) = ncplan_in(dir, &["import", "backups", "--machine", "DMU50", "--config", "c.toml"]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("4 files of 2 programs; 3 revisions stored, 1 already stored, 2 compared with their original, 0 errors"), "{out}");
    let store = ncplan::store::Store::open_read_only(&ncplan::store::Location::Sqlite(dir.join("var/x.db"))).unwrap();
    let (_, revs) = store
        .query(
            "SELECT substr(r.seen_at, 1, 10), p.path FROM revisions r JOIN programs p ON p.id = r.program_id
             WHERE p.role = 'machine' ORDER BY r.id",
        )
        .unwrap();
    let got: Vec<(String, bool)> =
        revs.iter().map(|r| (r[0].clone(), r[1].ends_with("share/O1234.nc") || r[1].ends_with("share/O2000.nc"))).collect();
    assert_eq!(got.iter().filter(|g| g.1).count(), 3);
    let o1234: Vec<&str> = revs.iter().filter(|r| r[1].ends_with("O1234.nc")).map(|r| r[0].as_str()).collect();
    assert_eq!(o1234, ["2024-01-10", "2024-02-20"], "in file-time order, the repeat skipped");
    let (_, changes) = store.query("SELECT kind FROM shopfloor_changes ORDER BY change_id").unwrap();
    assert_eq!(changes, [["tool_renamed"], ["start_point_moved"], ["risky_edit"]]);
    // Run again (as after a kill): nothing new.
    let (code, out, _) = ncplan_in(dir, &["import", "backups", "--machine", "DMU50", "--config", "c.toml"]);
    assert_eq!(code, 0);
    assert!(out.contains("0 revisions stored, 4 already stored"), "{out}");
    let (code, _, err) = ncplan_in(dir, &["import", "backups", "--machine", "NOPE", "--config", "c.toml"]);
    assert_eq!(code, 2);
    assert!(err.contains("no machine `NOPE`") && err.contains("DMU50"), "{err}");
}

#[test]
fn check_takes_many_files_and_ends_with_a_summary() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::write(tmp.path().join("good.nc"), "%\nO1\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nX10\nM30\n%\n").unwrap();
    std::fs::write(tmp.path().join("bad.nc"), "%\nO2\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG2 X10 Y0 I1 J1\nM30\n%\n").unwrap();
    let (code, out, err) = ncplan_in(tmp.path(), &["check", "-d", "fanuc", "good.nc", "bad.nc", "missing.nc"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(out.contains("good.nc: 0 errors") && out.contains("bad.nc: 1 errors"), "{out}");
    assert!(out.trim_end().ends_with("checked 3 files: 1 with errors (1 errors, 0 other findings); 1 could not be read"), "{out}");
    assert!(err.contains("cannot read missing.nc"), "{err}");
    let (code, out, _) = ncplan_in(tmp.path(), &["check", "-d", "fanuc", "--format", "json", "good.nc", "bad.nc"]);
    assert_eq!(code, 1);
    let v: serde_json::Value = serde_json::from_str(&out).unwrap();
    assert_eq!(v.as_array().map(Vec::len), Some(2));
}

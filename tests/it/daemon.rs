//! The real binary watching real folders: a CAM original, an operator's edit, SIGKILL and
//! a restart.

use std::path::Path;
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::support::{Proc, wait_rows, watch};

fn start(config: &Path) -> Proc {
    watch(config, "debug", Stdio::null())
}

fn rows(db: &Path, sql: &str) -> Vec<Vec<String>> {
    crate::db_rows(db, sql)
}

fn wait_for(db: &Path, sql: &str, want: usize) -> Vec<Vec<String>> {
    wait_rows(db, sql, want, Duration::from_secs(20))
}

#[test]
fn edited_program_yields_exactly_the_two_changes_and_survives_sigkill() {
    let tmp = tempfile::tempdir().unwrap();
    let (cam, share, var) = (tmp.path().join("cam"), tmp.path().join("share"), tmp.path().join("var"));
    std::fs::create_dir_all(&cam).unwrap();
    std::fs::create_dir_all(&share).unwrap();
    let config = tmp.path().join("ncplan.toml");
    std::fs::write(
        &config,
        "[database]\npath = 'var/ncplan.db'\n[daemon]\nsettle_ms = 200\n\
         [[cam]]\npath = 'cam'\ndialect = 'fanuc'\n\
         [[machine]]\nname = 'DMU50'\npath = 'share'\ndialect = 'fanuc'\n",
    )
    .unwrap();
    let db = var.join("ncplan.db");
    let demo = crate::root().join("demo");

    let daemon = start(&config);
    std::fs::copy(demo.join("cam/O1234.nc"), cam.join("O1234.nc")).unwrap();
    assert_eq!(wait_for(&db, "SELECT id FROM revisions", 1).len(), 1);

    // The operator's edit lands the way DNC tools write: a temp file, then a rename.
    let landed = Instant::now();
    std::fs::copy(demo.join("examples/O1234_edited.nc"), share.join("O1234.tmp")).unwrap();
    std::fs::rename(share.join("O1234.tmp"), share.join("O1234.nc")).unwrap();
    let changes =
        wait_for(&db, "SELECT machine, program, workingstep, kind, field, before, after FROM shopfloor_changes ORDER BY change_id", 3);
    let latency = landed.elapsed();
    assert_eq!(
        changes,
        vec![
            vec!["DMU50", "O1234", "1", "tool_renamed", "tool", "T1", "T8"],
            vec!["DMU50", "O1234", "1", "start_point_moved", "start_point", "X90 Y20", "X83 Y20"],
            // The sister tool kept T1's length offset: a risky edit.
            vec!["DMU50", "O1234", "1", "risky_edit", "foreign-length-offset", "", "T8 cuts with the length offset H1, not its own H8"],
        ],
        "latency {latency:?}"
    );
    // Give it time to (wrongly) add anything else, then check nothing else arrived.
    std::thread::sleep(Duration::from_millis(600));
    assert_eq!(rows(&db, "SELECT * FROM shopfloor_changes").len(), 3);
    assert_eq!(rows(&db, "SELECT id FROM revisions").len(), 2);
    assert!(rows(&db, "SELECT * FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.path LIKE '%.tmp'").is_empty());
    // Plans are queryable as workingsteps and features.
    assert_eq!(
        rows(
            &db,
            "SELECT DISTINCT w.operation, w.strategy, f.kind FROM workingsteps w JOIN features f ON f.revision_id = w.revision_id AND f.id = w.feature"
        ),
        [["plane_finish_milling", "bidirectional", "planar_face"]]
    );

    // SIGKILL mid-run, with more files arriving while it is down.
    daemon.kill();
    let edited = std::fs::read_to_string(demo.join("examples/O1234_edited.nc")).unwrap();
    std::fs::write(share.join("O1234.nc"), edited.replace("F240.", "F200.")).unwrap();
    std::fs::write(share.join("O5555.nc"), "%\nO5555\nT2 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nX10\nM30\n%\n").unwrap();
    let restarted = start(&config);
    let revs = wait_for(&db, "SELECT id FROM revisions", 4);
    assert_eq!(revs.len(), 4, "the two files written while the daemon was down are stored once each");
    let feed = wait_for(&db, "SELECT before, after FROM shopfloor_changes WHERE kind = 'feed_changed'", 1);
    assert_eq!(feed, vec![vec!["F240", "F200"]]);
    std::thread::sleep(Duration::from_millis(800));
    // No duplicates: every (program, hash) pair appears once, and the raw bytes are kept.
    assert_eq!(rows(&db, "SELECT id FROM revisions").len(), 4);
    assert!(rows(&db, "SELECT program_id, hash FROM revisions GROUP BY program_id, hash HAVING COUNT(*) > 1").is_empty());
    let stored = rows(&db, "SELECT CAST(b.content AS TEXT) FROM revisions r JOIN blobs b ON b.hash = r.hash ORDER BY r.id LIMIT 1");
    assert_eq!(stored[0][0], std::fs::read_to_string(demo.join("cam/O1234.nc")).unwrap());
    // The daemon never wrote into a watched folder.
    let mut names: Vec<_> = std::fs::read_dir(&share).unwrap().map(|e| e.unwrap().file_name().into_string().unwrap()).collect();
    names.sort();
    assert_eq!(names, ["O1234.nc", "O5555.nc"]);
    drop(restarted);
}

#[test]
fn sigterm_stops_gracefully() {
    let tmp = tempfile::tempdir().unwrap();
    std::fs::create_dir_all(tmp.path().join("m")).unwrap();
    let config = tmp.path().join("c.toml");
    std::fs::write(&config, "[database]\npath = 'db/x.db'\n[[machine]]\nname = 'M'\npath = 'm'\ndialect = 'linuxcnc'\n").unwrap();
    let mut d = start(&config);
    let db = tmp.path().join("db/x.db");
    let deadline = Instant::now() + Duration::from_secs(10);
    while !db.exists() && Instant::now() < deadline {
        std::thread::sleep(Duration::from_millis(50));
    }
    std::thread::sleep(Duration::from_millis(300));
    let pid = d.0.id().to_string();
    assert!(Command::new("kill").args(["-TERM", &pid]).status().unwrap().success());
    let deadline = Instant::now() + Duration::from_secs(10);
    let status = loop {
        if let Some(s) = d.0.try_wait().unwrap() {
            break s;
        }
        assert!(Instant::now() < deadline, "daemon did not stop on SIGTERM");
        std::thread::sleep(Duration::from_millis(50));
    };
    assert!(status.success(), "{status:?}");
}

//! The real binary watching real folders: a CAM original, an operator's edit, SIGKILL and
//! a restart.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::support::{Proc, program, wait_rows, watch};

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

/// Issue 32 §6: edited programs that wait for their CAM originals are all compared, however
/// many SIGKILLs land while many late originals arrive at once, whatever the moment. A kill
/// lands on whatever is being analysed or stored; none of it may leave an original stored
/// unanalysed (it would never serve its edits) or an edit uncompared.
#[test]
fn waiting_edits_are_all_compared_across_kills_while_late_originals_arrive() {
    const MACHINES: u32 = 4;
    const ORIGINALS: u32 = 60;
    let tmp = tempfile::tempdir().unwrap();
    let (cam, stage) = (tmp.path().join("cam"), tmp.path().join("stage"));
    std::fs::create_dir_all(&cam).unwrap();
    std::fs::create_dir_all(&stage).unwrap();
    let mut text =
        String::from("[database]\npath = 'var/ncplan.db'\n[daemon]\nsettle_ms = 100\n[[cam]]\npath = 'cam'\ndialect = 'fanuc'\n");
    let numbers: Vec<u32> = (1001..1001 + ORIGINALS).collect();
    for m in 0..MACHINES {
        let share = tmp.path().join(format!("m{m}"));
        std::fs::create_dir_all(&share).unwrap();
        text.push_str(&format!("[[machine]]\nname = 'M{m}'\npath = 'm{m}'\ndialect = 'fanuc'\n"));
        // Each machine's operator changed the feed of every program.
        for &n in &numbers {
            std::fs::write(share.join(format!("O{n}.nc")), program(n, 205 + 10 * m, 1000 + n % 7)).unwrap();
        }
    }
    let config = tmp.path().join("ncplan.toml");
    std::fs::write(&config, text).unwrap();
    let db = tmp.path().join("var/ncplan.db");
    let edits = (MACHINES * ORIGINALS) as usize;

    // The edits are stored first, each waiting for its original.
    let mut daemon = start(&config);
    assert_eq!(wait_rows(&db, "SELECT id FROM revisions", edits, Duration::from_secs(60)).len(), edits);
    assert!(rows(&db, "SELECT revision_id FROM comparisons").is_empty());

    // The originals arrive at once (posted elsewhere, moved into the CAM folder), each the
    // original of one program on every machine; the daemon is killed at varied moments of the
    // first second, as they arrive and after each restart.
    for &n in &numbers {
        std::fs::write(stage.join(format!("O{n}.nc")), program(n, 250, 1000 + n % 7)).unwrap();
    }
    for &n in &numbers {
        std::fs::rename(stage.join(format!("O{n}.nc")), cam.join(format!("O{n}.nc"))).unwrap();
    }
    let moments = [130, 240, 350, 460, 570, 680, 790, 900, 60, 300, 520, 740, 180, 410, 630, 850];
    for ms in moments {
        std::thread::sleep(Duration::from_millis(ms));
        daemon.kill();
        daemon = start(&config);
    }

    // The last start runs undisturbed: every edit is compared with its original.
    let uncompared = "SELECT p.path, r.status FROM revisions r JOIN programs p ON p.id = r.program_id
                      WHERE p.role = 'machine' AND NOT EXISTS (SELECT 1 FROM comparisons c WHERE c.revision_id = r.id) ORDER BY r.id";
    let deadline = Instant::now() + Duration::from_secs(30);
    while Instant::now() < deadline
        && (rows(&db, "SELECT id FROM revisions").len() < edits + numbers.len() || !rows(&db, uncompared).is_empty())
    {
        std::thread::sleep(Duration::from_millis(100));
    }
    drop(daemon);
    let originals = rows(
        &db,
        "SELECT p.path, r.status FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.role = 'cam' AND r.status <> 'analysed'",
    );
    assert!(originals.is_empty(), "originals stored unanalysed after {} kills: {originals:?}", moments.len());
    let left = rows(&db, uncompared);
    assert!(left.is_empty(), "{} of {edits} edits uncompared after {} kills: {left:?}", left.len(), moments.len());
    // Every revision once, nothing left in the attempt journal, nothing written into a watched folder.
    assert_eq!(rows(&db, "SELECT id FROM revisions").len(), edits + numbers.len());
    assert_eq!(rows(&db, "SELECT revision_id FROM comparisons").len(), edits);
    assert!(rows(&db, "SELECT * FROM attempts").is_empty());
    assert_eq!(std::fs::read_dir(&cam).unwrap().count(), numbers.len());
}

/// A shop in `dir`: Fanuc CAM originals in `cam`, one Fanuc machine VF2 on `share`; its
/// folders, configuration file and database path.
fn fanuc_shop(dir: &Path) -> (PathBuf, PathBuf, PathBuf, PathBuf) {
    let (cam, share) = (dir.join("cam"), dir.join("share"));
    std::fs::create_dir_all(&cam).unwrap();
    std::fs::create_dir_all(&share).unwrap();
    let config = dir.join("ncplan.toml");
    std::fs::write(
        &config,
        "[database]\npath = 'var/ncplan.db'\n[daemon]\nsettle_ms = 200\n\
         [[cam]]\npath = 'cam'\ndialect = 'fanuc'\n\
         [[machine]]\nname = 'VF2'\npath = 'share'\ndialect = 'fanuc'\n",
    )
    .unwrap();
    (cam, share, config, dir.join("var").join("ncplan.db"))
}

/// A program that calls a subprogram kept beside it is read with it; when the subprogram is
/// edited on its own, the caller's comparison is made again and names it as the cause.
#[test]
fn an_edited_subprogram_recompares_the_programs_that_call_it() {
    let tmp = tempfile::tempdir().unwrap();
    let (cam, share, config, db) = fanuc_shop(tmp.path());
    let main = "%\nO1000 (CONTOUR)\nG21 G90 G17\nT1 M6\nS3000 M3\nG54 G0 X0. Y0.\nG43 H1 Z5.\nM98 P2000\nG0 Z50.\nM30\n%\n";
    let sub = |feed: &str| format!("%\nO2000 (PASS)\nG1 Z-2. F100.\nX50. F{feed}\nY30.\nX0.\nY0.\nG0 Z5.\nM99\n%\n");
    let _daemon = start(&config);
    std::fs::write(cam.join("O2000.nc"), sub("300.")).unwrap();
    std::fs::write(cam.join("O1000.nc"), main).unwrap();
    wait_for(&db, "SELECT id FROM revisions", 2);
    std::fs::write(share.join("O2000.nc"), sub("300.")).unwrap();
    std::fs::write(share.join("O1000.nc"), main).unwrap();
    wait_for(&db, "SELECT revision_id FROM comparisons", 2);
    assert!(rows(&db, "SELECT * FROM shopfloor_changes").is_empty(), "the same programs");
    // The operator slows the subprogram's contour down.
    std::fs::write(share.join("O2000.nc"), sub("200.")).unwrap();
    let got = wait_for(
        &db,
        "SELECT p.name, c.kind, c.before, c.after FROM changes c JOIN revisions r ON r.id = c.revision_id
         JOIN programs p ON p.id = r.program_id WHERE p.path LIKE '%O1000.nc' AND c.kind = 'feed_changed'",
        1,
    );
    assert_eq!(got, vec![vec!["O1000", "feed_changed", "F100, F300", "F100, F200"]]);
    let rule = rows(
        &db,
        "SELECT c.rule FROM comparisons c JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id
         WHERE p.path LIKE '%share%O1000.nc'",
    );
    assert!(rule[0][0].contains("recomputed: the called program O2000 changed"), "{rule:?}");
}

/// The daemon's comparison tells what an edit breaks from the same errors `ncplan check`
/// finds (a jump to a label that is gone is found by the run, not by reading the blocks), and
/// stores it as a row of its own, first.
#[test]
fn a_stored_comparison_says_the_edit_breaks_the_program_as_check_does() {
    let tmp = tempfile::tempdir().unwrap();
    let (cam, share, config, db) = fanuc_shop(tmp.path());
    let original = "%\nO2000\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\n#1=0\nN10 G1 Z-1 F100\nX10\n#1=#1+1\nIF [#1 LT 2] GOTO10\nG0 Z5\nM30\n%\n";
    let daemon = start(&config);
    std::fs::write(cam.join("O2000.nc"), original).unwrap();
    assert_eq!(wait_for(&db, "SELECT id FROM revisions", 1).len(), 1);
    // The jump now names a block the program has not.
    std::fs::write(share.join("O2000.nc"), original.replace("GOTO10", "GOTO20")).unwrap();
    let changes = wait_for(&db, "SELECT kind, field, after, line FROM shopfloor_changes ORDER BY change_id", 2);
    assert_eq!(changes[0][..2], ["program_broken", "flow::missing-label"], "{changes:?}");
    assert!(changes[0][2].contains("no block N20"), "{changes:?}");
    assert_eq!(changes[0][3], "10");
    // The same error is among the edit's stored findings, as `ncplan check` reports it.
    let found = rows(&db, "SELECT d.code FROM diagnostics d JOIN revisions r ON r.id = d.revision_id WHERE d.severity = 'error'");
    assert_eq!(found, [["flow::missing-label"]]);
    drop(daemon);
}

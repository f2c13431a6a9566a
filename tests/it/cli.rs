//! The binary's commands, exit codes and output formats.

use std::process::Command;

fn ncplan(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(crate::bin()).args(args).current_dir(crate::root()).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

#[test]
fn diff_ignores_renumbering_comments_case_and_number_spelling() {
    let tmp = tempfile::tempdir().unwrap();
    let a = tmp.path().join("a.nc");
    let b = tmp.path().join("b.nc");
    std::fs::write(&a, "O1 (ROUGH)\nN10 T1 M6\nN20 S1000 M3\nN30 G0 X10. Y0 Z5.\nN40 G1 Z-1. F100.\nN50 X20.\nN60 M30\n").unwrap();
    std::fs::write(
        &b,
        "o1 (rough, checked by Ann)\nn1 t1 m06\nn2 s1000 m03\nn3 g00 x10.000 y0.0 z5.0\nn4 g01 z-1.0 f100.00\nn5   x20.00\nn6 m30\n",
    )
    .unwrap();
    let (code, out, _) = ncplan(&["diff", "-d", "fanuc", a.to_str().unwrap(), b.to_str().unwrap(), "--format", "json", "--exit-code"]);
    assert_eq!((code, out.trim()), (0, "[]"));
    // On a Fanuc a whole number without its point counts least increments: `z5` is 0.005 mm,
    // not the `Z5.` of the original.
    let text = std::fs::read_to_string(&b).unwrap().replace("z5.0", "z5");
    std::fs::write(&b, text).unwrap();
    let (code, out, _) = ncplan(&["diff", "-d", "fanuc", a.to_str().unwrap(), b.to_str().unwrap(), "--exit-code"]);
    assert_eq!((code, out.trim()), (1, "workingstep 1 (freeform milling): approach height changed from Z5 to Z0.005 at line 4"));
}

#[test]
fn diff_reports_typed_changes_as_json_and_sentences() {
    let (code, out, _) = ncplan(&["diff", "-d", "fanuc", "demo/cam/O1234.nc", "demo/examples/O1234_edited.nc", "--exit-code"]);
    assert_eq!(code, 1);
    assert_eq!(
        out.trim(),
        "workingstep 1 (plane finish milling): tool T1 renamed T8 at line 5; start point moved from X90 Y20 to X83 Y20 at line 6; \
         warning: T8 cuts with the length offset H1, not its own H8"
    );
    let (_, json, _) = ncplan(&["diff", "-d", "fanuc", "demo/cam/O1234.nc", "demo/examples/O1234_edited.nc", "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let kinds: Vec<&str> = v.as_array().unwrap().iter().map(|c| c["kind"].as_str().unwrap()).collect();
    assert_eq!(kinds, ["tool_renamed", "start_point_moved", "risky_edit"]);
    for key in ["kind", "workingstep", "field", "before", "after"] {
        assert!(v[0].get(key).is_some(), "{key}");
    }
}

#[test]
fn diff_reports_feed_speed_depth_and_added_steps() {
    let tmp = tempfile::tempdir().unwrap();
    let a = tmp.path().join("a.ngc");
    let b = tmp.path().join("b.ngc");
    std::fs::write(&a, "T1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nX50\nY10\nX0\nG0 Z5\nM30\n").unwrap();
    std::fs::write(
        &b,
        "T1 M6\nS1200 M3\nG0 X0 Y0 Z5\nG1 Z-2 F80\nX50\nY10\nX0\nG0 Z5\nT2 M6\nS3000 M3\nG0 X5 Y5\nG81 X5 Y5 Z-10 R2 F50\nG80\nM30\n",
    )
    .unwrap();
    let (_, json, _) = ncplan(&["diff", a.to_str().unwrap(), b.to_str().unwrap(), "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    let got: Vec<(String, String, String)> = v
        .as_array()
        .unwrap()
        .iter()
        .map(|c| (c["kind"].as_str().unwrap().into(), c["before"].as_str().unwrap().into(), c["after"].as_str().unwrap().into()))
        .collect();
    let want = [
        ("feed_changed", "F100", "F80"),
        ("spindle_speed_changed", "S1000", "S1200"),
        ("depth_changed", "Z-1", "Z-2"),
        ("workingstep_added", "", "drilling with T2, 12 mm of cut"),
    ];
    assert_eq!(got, want.map(|(a, b, c)| (a.to_owned(), b.to_owned(), c.to_owned())));
}

#[test]
fn check_reports_all_findings_with_carets_and_exit_codes() {
    let tmp = tempfile::tempdir().unwrap();
    let f = tmp.path().join("bad.ngc");
    std::fs::write(&f, "G0 X1 Y2\nG1 X1.2.3 F100\nG0 G1 X5\n(open comment\nG83 X1 Y1 Z-5 R2\nM30\n").unwrap();
    let (code, out, _) = ncplan(&["check", f.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}");
    for code in ["syntax::malformed-number", "syntax::modal-group-conflict", "syntax::unterminated-comment", "syntax::missing-parameter"] {
        assert!(out.contains(code), "{code} missing in\n{out}");
    }
    assert!(out.contains("bad.ngc:2:5"), "{out}");
    assert!(out.contains("^"), "{out}");
    let (_, json, _) = ncplan(&["check", f.to_str().unwrap(), "--format", "json"]);
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert!(v["diagnostics"].as_array().unwrap().len() >= 4);
    let good = tmp.path().join("good.ngc");
    std::fs::write(&good, "G21 G90\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG2 X10 Y0 R5\nM30\n").unwrap();
    assert_eq!(ncplan(&["check", good.to_str().unwrap()]).0, 0);
}

#[test]
fn query_is_read_only() {
    let tmp = tempfile::tempdir().unwrap();
    let db = tmp.path().join("x.db");
    drop(ncplan::store::Store::open(&ncplan::store::Location::Sqlite(db.clone()), "").unwrap());
    let (code, out, _) = ncplan(&["query", "--db", db.to_str().unwrap(), "SELECT COUNT(*) AS n FROM revisions"]);
    assert_eq!((code, out.as_str()), (0, "n\n0\n"));
    let (code, _, err) = ncplan(&["query", "--db", db.to_str().unwrap(), "DROP TABLE changes"]);
    assert_eq!(code, 2);
    assert!(err.contains("`DROP` is refused: queries only read"), "{err}");
    let (code, out, _) = ncplan(&["report", "--db", db.to_str().unwrap()]);
    assert_eq!((code, out.contains("No changes recorded.")), (0, true));
}

#[test]
fn canon_prints_rs274_calls() {
    let tmp = tempfile::tempdir().unwrap();
    let f = tmp.path().join("a.ngc");
    std::fs::write(&f, "G21 F100\nG0 X1 Y2 Z3\nG1 X[1+2*3-4/5] Z[SIN[30]]\n#1=2.0 F#1\nM2\n").unwrap();
    let (code, out, _) = ncplan(&["canon", f.to_str().unwrap()]);
    assert_eq!(code, 0);
    expect_test::expect![[r#"
        SET_FEED_RATE(100.0000)
        USE_LENGTH_UNITS(CANON_UNITS_MM)
        STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(6.2000, 2.0000, 0.5000, 0.0000, 0.0000, 0.0000)
        SET_FEED_RATE(0.0000)
        SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        SET_FEED_RATE(0.0000)
        STOP_SPINDLE_TURNING(0)
        PROGRAM_END()
    "#]]
    .assert_eq(&out);
}

#[test]
fn canon_reads_a_file_piece_by_piece_as_it_reads_a_pipe_whole() {
    let tmp = tempfile::tempdir().unwrap();
    let f = tmp.path().join("a.ngc");
    // A byte-order mark, Windows-1252 text, CRLF and LF line ends and a stray CR (a blank in a
    // file with LF), an error on line 3.
    std::fs::write(&f, b"\xEF\xBB\xBFG21 F100\r\n(caf\xe9)\rG0 X1\nG1 X2 E5\nM2\n").unwrap();
    let (code, out, err) = ncplan(&["canon", "-d", "linuxcnc", f.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("STRAIGHT_TRAVERSE(1.0000") && out.contains("PROGRAM_END()"), "{out}");
    assert!(err.contains("a.ngc:3:7: error"), "{err}");
    let piped = Command::new(crate::bin())
        .args(["canon", "-d", "linuxcnc", "/dev/stdin"])
        .stdin(std::fs::File::open(&f).unwrap())
        .output()
        .unwrap();
    assert_eq!(String::from_utf8_lossy(&piped.stdout), out);
    assert_eq!(String::from_utf8_lossy(&piped.stderr).replace("/dev/stdin", "a.ngc"), err.replace(f.to_str().unwrap(), "a.ngc"));
}

#[test]
fn translate_to_a_file_leaves_no_partial_file() {
    let tmp = tempfile::tempdir().unwrap();
    let o = tmp.path().join("out.nc");
    let (code, _, err) =
        ncplan(&["translate", "tests/programs/equivalence/drill_ream.nc", "-d", "fanuc", "--to", "siemens", "-o", o.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let names: Vec<String> =
        std::fs::read_dir(tmp.path()).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    assert_eq!(names, ["out.nc"]);
    assert!(std::fs::read_to_string(&o).unwrap().contains("M30"));
}

#[test]
fn stepnc_writes_part21_to_stdout_and_needs_a_class() {
    let (code, out, err) = ncplan(&["stepnc", "-d", "fanuc", "demo/cam/O1234.nc", "--cc2", "--timestamp", "2026-01-01T00:00:00"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("ISO-10303-21;\nHEADER;\n"), "{out}");
    assert!(out.contains("=PLANAR_FACE('F1 top=inferred size_from=tool_comment top_from=assumption',"), "{out}");
    assert!(out.trim_end().ends_with("ENDSEC;\nEND-ISO-10303-21;"), "{out}");
    assert!(err.contains("warning[stepnc::stock-unknown]"), "{err}");
    let (code, _, _) = ncplan(&["stepnc", "-d", "fanuc", "demo/cam/O1234.nc"]);
    assert_eq!(code, 2, "a conformance class is required");
    let (code, _, _) = ncplan(&["stepnc", "-d", "fanuc", "demo/cam/O1234.nc", "--cc1", "--cc2"]);
    assert_eq!(code, 2, "one class at a time");
}

#[test]
fn check_finds_a_called_program_beside_the_file_by_its_name_on_the_control() {
    let tmp = tempfile::tempdir().unwrap();
    let main = tmp.path().join("MAIN.H");
    std::fs::write(
        &main,
        "0 BEGIN PGM MAIN MM\n1 TOOL CALL 1 Z S1000\n2 CALL PGM TNC:\\PARTS\\sub.h\n3 L X+0 Y+0 Z+50 R0 FMAX M30\n4 END PGM MAIN MM\n",
    )
    .unwrap();
    // Not there: the control may hold it, so a warning that the analysis lacks its moves.
    let (code, out, _) = ncplan(&["check", "--dialect", "heidenhain", main.to_str().unwrap()]);
    assert_eq!(code, 0, "{out}");
    assert!(out.contains("warning[flow::missing-program]") && out.contains("lacks its moves"), "{out}");
    // The control's path means the file `sub.h` in the program's folder (any case).
    std::fs::write(tmp.path().join("SUB.H"), "0 BEGIN PGM SUB MM\n1 L X+10 Y+0 R0 F500 M3\n2 END PGM SUB MM\n").unwrap();
    let (code, out, _) = ncplan(&["check", "--dialect", "heidenhain", main.to_str().unwrap()]);
    assert_eq!((code, out.lines().last()), (0, Some(format!("{}: 0 errors, 0 other findings", main.display()).as_str())), "{out}");
}

#[test]
fn translate_writes_for_another_control_and_never_into_a_watched_folder() {
    let (code, out, err) = ncplan(&["translate", "tests/programs/equivalence/drill_ream.nc", "-d", "fanuc", "--to", "heidenhain"]);
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("0 BEGIN PGM O1002 MM\n") && out.contains("CYCL DEF 200 DRILLING") && out.contains("M99"), "{out}");
    assert!(out.trim_end().ends_with("END PGM O1002 MM"), "{out}");
    let dir = tempfile::tempdir().unwrap();
    for sub in ["cam", "share"] {
        std::fs::create_dir(dir.path().join(sub)).unwrap();
    }
    let config = dir.path().join("ncplan.toml");
    // Relative paths are the working directory's (the checkout's here): the folders are given whole.
    let d = dir.path().display();
    std::fs::write(
        &config,
        format!(
            "[database]\npath = '{d}/db.sqlite'\n[[cam]]\npath = '{d}/cam'\ndialect = 'fanuc'\n[[machine]]\nname = 'M1'\npath = '{d}/share'\n\
             dialect = 'fanuc'\nunits = 'mm'\nmax_spindle_speed = 8100\n"
        ),
    )
    .unwrap();
    let config = config.to_str().unwrap();
    // An -o inside a watched folder is refused.
    let inside = dir.path().join("share/x.nc");
    let (code, _, err) = ncplan(&[
        "translate",
        "tests/programs/equivalence/drill_ream.nc",
        "--to",
        "siemens",
        "--config",
        config,
        "-o",
        inside.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("never writes into a watched folder"), "{err}");
    assert!(!inside.exists());
    // A machine's dialect, units and limits.
    let fast = dir.path().join("fast.h");
    std::fs::write(
        &fast,
        std::fs::read_to_string(crate::root().join("tests/programs/equivalence/face.h")).unwrap().replace("S1200", "S9000"),
    )
    .unwrap();
    let (code, out, err) = ncplan(&["translate", fast.to_str().unwrap(), "-d", "heidenhain", "--machine", "M1", "--config", config]);
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("%\n") && out.contains("T1 M6") && out.contains("G21"), "{out}");
    assert!(err.contains("post::machine-limit") && err.contains("highest spindle speed"), "{err}");
}

#[test]
fn translate_writes_a_stored_revision() {
    let dir = tempfile::tempdir().unwrap();
    for sub in ["cam", "share", "copy"] {
        std::fs::create_dir(dir.path().join(sub)).unwrap();
    }
    std::fs::copy(crate::root().join("tests/programs/equivalence/drill_ream.nc"), dir.path().join("copy/O1002.nc")).unwrap();
    let config = dir.path().join("ncplan.toml");
    let d = dir.path().display();
    std::fs::write(
        &config,
        format!("[database]\npath = '{d}/db.sqlite'\n[[cam]]\npath = '{d}/cam'\ndialect = 'fanuc'\n[[machine]]\nname = 'M1'\npath = '{d}/share'\ndialect = 'fanuc'\n"),
    )
    .unwrap();
    let config = config.to_str().unwrap();
    let copy = dir.path().join("copy");
    let (code, _, err) = ncplan(&["import", copy.to_str().unwrap(), "--cam", "--config", config]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = ncplan(&["translate", "--revision", "1", "--to", "siemens", "--config", config]);
    assert_eq!(code, 0, "{err}");
    assert!(out.starts_with("%_N_O1002_MPF\n") && out.contains("MCALL CYCLE81(50,0,2,-15)"), "{out}");
}

/// A Klartext pocket 50 x 30 r8 cut by T1 (D12) in computer compensation, its radius only in
/// the shop's TOOL.T: without the table its size is unknown and the tool-centre path is said;
/// with `--tool-table` it is the pocket's, said to come from the table.
#[test]
fn plan_takes_tool_sizes_from_a_tool_table_and_says_so() {
    let dir = tempfile::tempdir().unwrap();
    let program = dir.path().join("PK.h");
    std::fs::write(
        &program,
        "0 BEGIN PGM PK MM\n1 BLK FORM 0.1 Z X+0 Y+0 Z-20\n2 BLK FORM 0.2 X+100 Y+80 Z+0\n3 TOOL CALL 1 Z S6000\n\
         4 L Z+50 R0 FMAX M3\n5 L X+50 Y+40 R0 FMAX\n6 L Z+2 R0 FMAX\n7 L Z-5 R0 F200\n8 L X+50 Y+31 R0 F800\n\
         9 L X+67\n10 CC X+67 Y+33\n11 C X+69 Y+33 DR+\n12 L Y+47\n13 CC X+67 Y+47\n14 C X+67 Y+49 DR+\n15 L X+33\n\
         16 CC X+33 Y+47\n17 C X+31 Y+47 DR+\n18 L Y+33\n19 CC X+33 Y+33\n20 C X+33 Y+31 DR+\n21 L X+50\n\
         22 L Z+50 R0 FMAX\n23 M30\n24 END PGM PK MM\n",
    )
    .unwrap();
    let table = dir.path().join("TOOL.T");
    std::fs::write(&table, "BEGIN TOOL.T MM\nT    NAME   L    R   R2  T-ANGLE\n1    EM12   50   6   0   0\n[END]\n").unwrap();
    let program = program.to_str().unwrap();
    let (code, out, err) = ncplan(&["plan", "-d", "heidenhain", program]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("feature 1 closed pocket at X50 Y40 Z0 depth 5"), "{out}");
    assert!(out.contains("size unknown (the tool's diameter is not known; the tool-centre path spans 38 x 18)"), "{out}");
    let (code, out, err) = ncplan(&["plan", "-d", "heidenhain", "--tool-table", table.to_str().unwrap(), program]);
    assert_eq!(code, 0, "{err}");
    assert!(out.contains("feature 1 closed pocket 50 x 30 r8 at X50 Y40 Z0 depth 5"), "{out}");
    assert!(out.contains("size from the tool table, top from the stock"), "{out}");
    let (code, json, err) = ncplan(&["plan", "-d", "heidenhain", "--tool-table", table.to_str().unwrap(), "--format", "json", program]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(&json).unwrap();
    assert_eq!(v["features"][0]["sources"]["size"], "tool_table");
    assert_eq!(v["workpiece"]["line"], 3, "the line of `BLK FORM 0.2`, which completes the blank");
    let (code, _, err) = ncplan(&["plan", "-d", "heidenhain", "--tool-table", "tests/programs/posts/README.md", program]);
    assert_eq!(code, 2);
    assert!(err.contains("in the tool table tests/programs/posts/README.md"), "{err}");
}

#[test]
fn translate_check_proves_the_motion_and_refuses_what_runs_otherwise() {
    let tmp = tempfile::tempdir().unwrap();
    // Fanuc to LinuxCNC: the home return is a home return, the work offset is stated; the
    // proof holds and the file is written.
    let o = tmp.path().join("O1234.ngc");
    let (code, _, err) =
        ncplan(&["translate", "demo/cam/O1234.nc", "-d", "fanuc", "--to", "linuxcnc", "--check", "-o", o.to_str().unwrap()]);
    assert_eq!(code, 0, "{err}");
    let text = std::fs::read_to_string(&o).unwrap();
    assert!(text.contains("G54") && text.contains("G91 G28 Z0\nG90"), "{text}");
    // To standard output, the same text.
    let (code, out, err) = ncplan(&["translate", "demo/cam/O1234.nc", "-d", "fanuc", "--to", "linuxcnc", "--check"]);
    assert_eq!((code, out.as_str()), (0, text.as_str()), "{err}");
    // Heidenhain has no return through a point: refused, naming the block, and nothing written.
    let h = tmp.path().join("O1234.h");
    let (code, out, err) =
        ncplan(&["translate", "demo/cam/O1234.nc", "-d", "fanuc", "--to", "heidenhain", "--check", "-o", h.to_str().unwrap()]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("O1234.nc:17:1: error[post::unwritable]: the return to reference position 1 in Z is not written"), "{err}");
    assert!(err.contains("the translation is refused: nothing was written"), "{err}");
    // The refusal alone: no proof of what is not given out (it said `post::motion-differs`,
    // the translation ending before the return, which says nothing new).
    assert!(!err.contains("post::motion-differs"), "{err}");
    assert!(!h.exists());
    let names: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().map(|e| e.unwrap().file_name()).collect();
    assert_eq!(names.len(), 1, "no partial file is left: {names:?}");
    // On standard output, with --check, nothing of the refused program either.
    let (code, out, _) = ncplan(&["translate", "demo/cam/O1234.nc", "-d", "fanuc", "--to", "siemens", "--check"]);
    assert_eq!((code, out.as_str()), (1, ""));
}

/// A program whose dialect is guessed (no code of its maker's own) reads the same in every
/// command: `check` keeps the Fanuc-only dwell-point alarm a warning, `diff` says no stop,
/// and `translate` refuses the translation there (the source maker's control stops at it).
#[test]
fn a_guessed_dialect_reads_alike_in_check_diff_and_translate() {
    let tmp = tempfile::tempdir().unwrap();
    let p = tmp.path().join("part.ptp");
    let text = "%\nO0001\nT1M6\nG90G54G0X1.Y1.S1000M3\nG43Z1.H1\nG82X1.Y1.Z-.2R.1P500F10.\nX2.P.5\nG80\nM30\n%\n";
    std::fs::write(&p, text).unwrap();
    let file = p.to_str().unwrap();
    let (code, out, err) = ncplan(&["check", file]);
    assert_eq!(code, 0, "{out}{err}");
    assert!(out.contains("warning[interp::dwell-point-alarm]") && out.contains("guessed"), "{out}");
    let (code, _, err) = ncplan(&["diff", file, file]);
    assert_eq!(code, 0, "{err}");
    assert!(!err.contains("error"), "{err}");
    let (code, out, err) = ncplan(&["translate", file, "--to", "siemens"]);
    assert_eq!(code, 1, "{out}{err}");
    assert!(err.contains("post::source-error") && err.contains("dwell-point-alarm") && out.is_empty(), "{out}{err}");
}

//! The analysis bound (issue 44): a macro program rs274 runs to its end in a second is
//! analysed to its end with the default bound, move for move as rs274 makes them; a run that
//! reaches the bound, in time or in memory, stops with a warning that every command says on
//! stderr.

use ncplan::diag::Severity;
use ncplan::interp::Profile;

/// The program: 200 calls of a subroutine with arguments and named parameters, each a
/// row of 500 moves from a loop and a condition: 100,000 moves, some 700,000 blocks run again.
fn rows_by_calls() -> String {
    "G21 G90 G17\nT1 M6\nS10000 M3\nF1200\nG0 X0 Y0 Z5\n\
     o<row> sub\n\
     \x20 #<y> = #1\n\
     \x20 #<forward> = #2\n\
     \x20 #<col> = 0\n\
     \x20 o10 while [#<col> LT 500]\n\
     \x20   o11 if [#<forward> GT 0]\n\
     \x20     #<x> = [#<col> * 0.2]\n\
     \x20   o11 else\n\
     \x20     #<x> = [[499 - #<col>] * 0.2]\n\
     \x20   o11 endif\n\
     \x20   G1 X#<x> Y#<y> Z[-1 + 0.5 * SIN[#<x> * 3.6] * COS[#<y> * 3.6]]\n\
     \x20   #<col> = [#<col> + 1]\n\
     \x20 o10 endwhile\n\
     o<row> endsub\n\
     #<r> = 0\n\
     o20 while [#<r> LT 200]\n\
     \x20 o<row> call [#<r> * 0.5] [1 - [#<r> MOD 2] * 2]\n\
     \x20 #<r> = [#<r> + 1]\n\
     o20 endwhile\n\
     G0 Z5\nM30\n"
        .to_owned()
}

/// The moves rs274 makes of `program` (LinuxCNC), as it prints them; `None` without rs274.
fn rs274_moves(name: &str, program: &str) -> Option<Vec<String>> {
    if std::process::Command::new("rs274").arg("--help").output().is_err() {
        assert!(std::env::var_os("NCPLAN_REQUIRE_RS274").is_none(), "NCPLAN_REQUIRE_RS274 is set but rs274 is not installed");
        crate::skip(name, "rs274 (linuxcnc-uspace) is not installed");
        return None;
    }
    let dir = std::env::temp_dir().join(format!("ncplan-bound-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let (file, table) = (dir.join("rows.ngc"), dir.join("zero.tbl"));
    std::fs::write(&file, program).unwrap();
    std::fs::write(&table, (1..100).map(|t| format!("T{t} P{t} Z0 D0\n")).collect::<String>()).unwrap();
    let out = std::process::Command::new("rs274").arg("-g").arg("-t").arg(&table).arg(&file).output().unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    let text = String::from_utf8_lossy(&out.stdout);
    // rs274 writes `   12 N..... STRAIGHT_FEED(...)`: the call from its name on.
    let moves = text
        .lines()
        .filter_map(|l| {
            ["STRAIGHT_FEED(", "STRAIGHT_TRAVERSE(", "ARC_FEED("].iter().find_map(|m| l.find(m).map(|i| l[i..].trim().to_owned()))
        })
        .collect();
    Some(moves)
}

#[test]
fn a_macro_program_of_100000_moves_is_analysed_to_its_end_as_rs274_runs_it() {
    let program = rows_by_calls();
    let (moves, diags) = crate::moves_and_findings("linuxcnc", &program, &Profile::default());
    assert!(!diags.iter().any(|d| d.stops_analysis()), "{:#?}", diags.iter().filter(|d| d.stops_analysis()).collect::<Vec<_>>());
    assert!(!diags.iter().any(|d| d.is_error()), "{:#?}", diags.iter().filter(|d| d.is_error()).collect::<Vec<_>>());
    // Two rapids and 200 rows of 500 feeds.
    assert_eq!(moves.len(), 100_002);
    assert_eq!(moves[100_000], "STRAIGHT_FEED(0.0000, 99.5000, -1.0000, 0.0000, 0.0000, 0.0000)", "the last row ends at X0");
    let Some(theirs) = rs274_moves("bound::rs274", &program) else { return };
    assert_eq!(theirs.len(), moves.len(), "rs274 makes as many moves");
    let differ: Vec<_> = moves.iter().zip(&theirs).enumerate().filter(|(_, (a, b))| a != b).take(3).collect();
    assert!(differ.is_empty(), "moves that differ from rs274's: {differ:#?}");
}

/// The same program under a small bound: in time (blocks run again) and in memory (moves
/// made by blocks run again), a warning that names which, and the analysis stops there.
#[test]
fn a_run_that_reaches_the_bound_stops_and_says_which() {
    let program = rows_by_calls();
    let time = Profile { max_repeated_blocks: 20_000, ..Profile::default() };
    let (moves, diags) = crate::moves_and_findings("linuxcnc", &program, &time);
    let stops: Vec<_> = diags.iter().filter(|d| d.stops_analysis()).collect();
    assert_eq!(stops.len(), 1, "{diags:#?}");
    assert_eq!((stops[0].code.as_str(), stops[0].severity), ("flow::repeat-budget", Severity::Warning));
    assert!(stops[0].message.contains("bound in time (20000 blocks run again"), "{}", stops[0].message);
    assert!(moves.len() < 10_000, "{} moves", moves.len());
    // Ops kept whole (a vector: what `check` keeps) count as the vector's capacity: it grows
    // by doubling, so the bound of 1,000 ops is passed when it grows to 1,024 and more.
    let op = std::mem::size_of::<ncplan::canon::Canon>() as u64;
    let memory = Profile { max_repeated_bytes: 1_000 * op, ..Profile::default() };
    let (moves, diags) = crate::moves_and_findings("linuxcnc", &program, &memory);
    let stops: Vec<_> = diags.iter().filter(|d| d.stops_analysis()).collect();
    assert_eq!(stops.len(), 1, "{diags:#?}");
    assert!(stops[0].message.contains("its bound in memory ("), "{}", stops[0].message);
    assert!((500..=1_100).contains(&moves.len()), "{} moves", moves.len());
}

/// The bound in memory counts what the result keeps, as its sink says: ops kept whole (a
/// vector) by the vector's capacity, which grows by doubling; a plan by the most a kept move
/// costs (`BYTES_PER_MOVE`).
/// The finding names the moves made.
#[test]
fn the_bound_in_memory_counts_what_the_result_keeps() {
    let program = rows_by_calls();
    let d = ncplan::dialect::Registry::shipped().get("linuxcnc").unwrap();
    let mut profile = Profile::default();
    profile.bound_memory(1);
    let moves_made = |diags: &[ncplan::diag::Diagnostic]| -> u64 {
        let stop = diags.iter().find(|d| d.stops_analysis()).expect("the run stops at the bound");
        let m = stop.message.split("its bound in memory (").nth(1).expect("a bound in memory");
        m.split(' ').next().unwrap().parse().unwrap()
    };
    let plan = ncplan::pipeline::analyze_plan(program.as_bytes(), &d, &profile);
    let per_move = 1_000_000 / ncplan::interp::BYTES_PER_MOVE;
    assert!((per_move..=per_move + 10).contains(&moves_made(&plan.diagnostics)), "{:?}", plan.diagnostics);
    let whole = ncplan::pipeline::analyze(program.as_bytes(), &d, &profile);
    let op = std::mem::size_of::<ncplan::canon::Canon>() as u64;
    let kept = moves_made(&whole.diagnostics);
    assert!((1_000_000 / op / 2 - 20..=1_000_000 / op + 20).contains(&kept), "{kept} moves, {op} bytes an op");
}

/// Every command that stops early says so on stderr, whatever findings it shows otherwise:
/// `canon`, `plan`, `stepnc` and `diff` (which show none but errors), `check` among its
/// findings. The bound comes from the configuration or the command line.
#[test]
fn every_command_that_stops_early_says_so() {
    let dir = std::env::temp_dir().join(format!("ncplan-bound-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("rows.ngc");
    std::fs::write(&file, rows_by_calls()).unwrap();
    let config = dir.join("small.toml");
    std::fs::write(&config, "[database]\npath = 'unused.db'\n[analysis]\nmax_repeated_blocks = 5000\n").unwrap();
    let f = file.to_string_lossy().into_owned();
    let c = config.to_string_lossy().into_owned();
    let stepnc = ["stepnc", "-d", "linuxcnc", "--config", &c, "--cc2", "--timestamp", "2026-01-01T00:00:00", &f];
    for args in [
        &["canon", "-d", "linuxcnc", "--config", &c, &f][..],
        &["plan", "-d", "linuxcnc", "--config", &c, &f],
        &stepnc,
        &["diff", "-d", "linuxcnc", "--config", &c, &f, &f],
        &["check", "-d", "linuxcnc", "--config", &c, &f],
    ] {
        let out = std::process::Command::new(crate::bin()).args(args).output().unwrap();
        let said = format!(
            "{}{}",
            String::from_utf8_lossy(&out.stderr),
            if args[0] == "check" { String::from_utf8_lossy(&out.stdout) } else { "".into() }
        );
        assert!(said.contains("flow::repeat-budget") && said.contains("bound in time (5000 blocks"), "{} said:\n{said}", args[0]);
    }
    // The command line's bound over the configuration's: a second of analysis is a million
    // blocks run again, past this program's end.
    let out = std::process::Command::new(crate::bin())
        .args(["canon", "-d", "linuxcnc", "--config", &c, "--max-seconds", "1", &f])
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(!String::from_utf8_lossy(&out.stderr).contains("repeat-budget"), "{}", String::from_utf8_lossy(&out.stderr));
    let _ = std::fs::remove_dir_all(&dir);
}

/// A bore milled in a helix (Heidenhain `CYCL DEF 208`) with an infeed per turn of a micron down
/// a bore 100 deep would be 200 000 arcs, and a modal call repeats it at each position: the half
/// turns of one call are bounded (10 000) as the pocket and slot passes are, and past the
/// bound the call is kept as intent with one warning at its call. A bore within the bound is
/// milled as its helix; one past the bound after it is not.
#[test]
fn helical_bores_have_a_bound_per_call() {
    let dialect = ncplan::dialect::Registry::shipped().get("heidenhain").unwrap();
    let bore = |depth: &str, pitch: &str| {
        format!(
            "CYCL DEF 208 BORE MILLING ~\n  Q200=2 ;SET-UP CLEARANCE ~\n  Q201=-{depth} ;DEPTH ~\n  Q206=150 ;FEED RATE FOR PLNGNG ~\n  \
             Q334={pitch} ;PLUNGING DEPTH ~\n  Q203=+0 ;SURFACE COORDINATE ~\n  Q204=50 ;2ND SET-UP CLEARANCE ~\n  \
             Q335=10 ;NOMINAL DIAMETER ~\n  Q342=0 ;ROUGHING DIAMETER\nCYCL CALL\n"
        )
    };
    let text = format!(
        "BEGIN PGM T MM\nTOOL CALL 1 Z S3000\nL X+0 Y+0 Z+50 R0 FMAX\n{}L X+40 Y+0 R0 FMAX\n{}END PGM T MM\n",
        bore("10", "2"),
        bore("100", "0.001")
    );
    let a = ncplan::pipeline::analyze(text.as_bytes(), &dialect, &Profile::default());
    let line_of = |d: &ncplan::diag::Diagnostic| text[..d.range.start as usize].matches('\n').count() + 1;
    let bound: Vec<_> = a.diagnostics.iter().filter(|d| d.message.contains("half turns in one bore milled in a helix")).collect();
    assert_eq!(bound.len(), 1, "{:?}", a.diagnostics);
    assert_eq!(bound[0].code.as_str(), "interp::unsupported");
    assert_eq!(bound[0].severity, Severity::Warning);
    assert!(matches!(line_of(bound[0]), 15..=24), "{:?} at line {}", bound[0], line_of(bound[0]));
    // The first bore is milled: its arcs are in the plan; the second writes none.
    let arcs: usize = a.plan.workingsteps.iter().map(|w| w.toolpath.iter().filter(|m| m.arc.is_some()).count()).sum();
    assert!((6..1000).contains(&arcs), "{arcs} arcs");
}

/// 84 bores milled in a helix of 120 half turns each (Heidenhain `CYCL DEF 208`, 58 deep at
/// 1 per turn from 2 above): 10 080 half turns in all, an ordinary program, each bore within the
/// bound of one call and the run far within its million. Every bore is milled; no warning.
#[test]
fn many_helical_bores_are_all_milled() {
    let dialect = ncplan::dialect::Registry::shipped().get("heidenhain").unwrap();
    let mut text = String::from("BEGIN PGM T MM\nTOOL CALL 1 Z S3000\nL X+0 Y+0 Z+50 R0 FMAX\n");
    text.push_str(
        "CYCL DEF 208 BORE MILLING ~\n  Q200=2 ;SET-UP CLEARANCE ~\n  Q201=-58 ;DEPTH ~\n  Q206=150 ;FEED RATE FOR PLNGNG ~\n  \
         Q334=1 ;PLUNGING DEPTH ~\n  Q203=+0 ;SURFACE COORDINATE ~\n  Q204=50 ;2ND SET-UP CLEARANCE ~\n  \
         Q335=10 ;NOMINAL DIAMETER ~\n  Q342=0 ;ROUGHING DIAMETER\n",
    );
    for i in 0..84 {
        text.push_str(&format!("L X+{} Y+{} R0 FMAX\nCYCL CALL\n", 20 * (i % 12), 20 * (i / 12)));
    }
    text.push_str("END PGM T MM\n");
    let a = ncplan::pipeline::analyze(text.as_bytes(), &dialect, &Profile::default());
    assert!(a.diagnostics.iter().all(|d| !d.message.contains("milled in a helix")), "{:?}", a.diagnostics);
    let arcs: usize = a.plan.workingsteps.iter().map(|w| w.toolpath.iter().filter(|m| m.arc.is_some()).count()).sum();
    assert!(arcs >= 84 * 120, "{arcs} arcs");
}

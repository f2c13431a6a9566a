//! Programs analysed on their own whose caller or machine supplies state (issue 17 §1), and
//! runs that must end quickly (§5): small programs in `tests/programs/called/`.

use ncplan::canon::{CanonOp, write_call};
use ncplan::diag::{Diagnostic, Severity};
use ncplan::dialect::Registry;
use ncplan::interp::{Profile, ProgramRole, interpret, role_from_file_name};

fn program(name: &str) -> String {
    std::fs::read_to_string(crate::root().join("tests/programs/called").join(name)).unwrap()
}

/// The moves (and feed settings) of `name` in `dialect`, and its findings.
fn run(dialect: &str, name: &str, role: ProgramRole) -> (Vec<String>, Vec<Diagnostic>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut out = Vec::new();
    let diags = interpret(&program(name), &d, &Profile { role, ..Profile::default() }, &mut out);
    let moves = out
        .iter()
        .filter(|c| matches!(c.op, CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_) | CanonOp::SetFeedRate(_)))
        .map(|c| {
            let mut s = String::new();
            write_call(&mut s, &c.op);
            s.trim_end().to_owned()
        })
        .collect();
    (moves, diags)
}

fn codes(diags: &[Diagnostic]) -> Vec<(&'static str, Severity)> {
    diags.iter().map(|d| (d.code.as_str(), d.severity)).collect()
}

fn errors(diags: &[Diagnostic]) -> Vec<&Diagnostic> {
    diags.iter().filter(|d| d.is_error()).collect()
}

/// A Fanuc macro (O9xxx) checks its arguments with `#3000` alarms; analysed alone, its
/// arguments and the common variables it reads are unknown: the checks take the way without
/// alarm, each with a note, the moves keep their known axes, the unknown feed is not zero,
/// and arithmetic on unknown values stays unknown (no division by zero).
#[test]
fn a_macro_on_its_own_reads_its_arguments_as_unknown_and_raises_no_alarm() {
    let (moves, diags) = run("fanuc", "O9010.nc", ProgramRole::Auto);
    assert!(errors(&diags).is_empty(), "{diags:#?}");
    let conditions: Vec<_> = diags.iter().filter(|d| d.code.as_str() == "flow::unknown-condition").collect();
    assert_eq!(conditions.len(), 2, "{diags:#?}");
    assert!(conditions[0].message.contains("`IF [#24 NE #0] GOTO 10` reads argument #24"), "{}", conditions[0].message);
    assert!(conditions[0].message.contains("taken as true"), "{}", conditions[0].message);
    assert!(conditions[1].message.contains("taken as false"), "{}", conditions[1].message);
    assert!(conditions.iter().all(|d| d.severity == Severity::Note));
    assert!(diags.iter().any(|d| d.code.as_str() == "interp::called-program" && d.message.contains("O9010")), "{diags:#?}");
    // X#24 is left out: the rapid keeps Y; Z#26 is left out: no move at all; the feed is the caller's.
    assert_eq!(
        moves,
        [
            "STRAIGHT_TRAVERSE(0.0000, 5.0000, 0.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(0.0000, 5.0000, -0.5000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_TRAVERSE(0.0000, 5.0000, 10.0000, 0.0000, 0.0000, 0.0000)",
            "SET_FEED_RATE(0.0000)",
        ]
    );
    let unknown: Vec<_> = diags.iter().filter(|d| d.code.as_str() == "interp::unknown-value").collect();
    assert!(unknown.iter().any(|d| d.message.contains("`X#24` reads argument #24")), "{unknown:#?}");
    assert!(unknown.iter().all(|d| d.severity == Severity::Note), "{unknown:#?}");
    // `F#650` is unknown, not zero: a note that the feed is the caller's, no no-feed error.
    assert!(!diags.iter().any(|d| d.code.as_str() == "interp::no-feed"), "{diags:#?}");
}

/// A subprogram that ends with M99 and sets no feed cuts at its caller's feed: a note that
/// says so. The same moves in a main program are an error.
#[test]
fn the_feed_of_a_called_program_comes_from_its_caller() {
    let (_, diags) = run("fanuc", "sub_no_feed.nc", ProgramRole::Auto);
    assert!(errors(&diags).is_empty(), "{diags:#?}");
    let note = diags.iter().find(|d| d.code.as_str() == "interp::caller-state").expect("a caller-state note");
    assert!(note.message.contains("the feed comes from the caller"), "{}", note.message);
    assert_eq!(note.severity, Severity::Note);
    // No warning that M99 restarts a main program: it is the subprogram's return.
    assert!(!diags.iter().any(|d| d.code.as_str() == "interp::unsupported"), "{diags:#?}");

    let (_, diags) = run("fanuc", "main_no_feed.nc", ProgramRole::Auto);
    assert_eq!(errors(&diags).iter().map(|d| d.code.as_str()).collect::<Vec<_>>(), ["interp::no-feed"], "{diags:#?}");
    assert!(!diags.iter().any(|d| d.code.as_str() == "interp::caller-state"), "{diags:#?}");

    // The role given (config, `check --as`) wins over the form.
    let (_, diags) = run("fanuc", "sub_no_feed.nc", ProgramRole::Main);
    assert!(codes(&diags).contains(&("interp::no-feed", Severity::Error)), "{diags:#?}");
    let (_, diags) = run("fanuc", "main_no_feed.nc", ProgramRole::Called);
    assert!(errors(&diags).is_empty(), "{diags:#?}");
    assert!(diags.iter().any(|d| d.code.as_str() == "interp::called-program" && d.message.contains("role is given")), "{diags:#?}");
}

/// A Siemens `PROC` analysed alone: its arguments, R parameters and global user data are
/// unknown; a jump on them takes the dictionary's way, and the moves keep their known axes.
#[test]
fn a_siemens_procedure_reads_its_arguments_r_parameters_and_gud_as_unknown() {
    let (moves, diags) = run("siemens", "POCKET.SPF", ProgramRole::Auto);
    assert!(errors(&diags).is_empty(), "{diags:#?}");
    assert!(diags.iter().any(|d| d.code.as_str() == "interp::called-program" && d.message.contains("PROC")), "{diags:#?}");
    let cond = diags.iter().find(|d| d.code.as_str() == "flow::unknown-condition").expect("a note on the condition");
    assert!(cond.message.contains("`IF DEPTH>0 GOTOF CUT` reads `depth`"), "{}", cond.message);
    assert!(diags.iter().any(|d| d.message.contains("`_x_home` is neither declared nor set")), "{diags:#?}");
    assert!(diags.iter().any(|d| d.message.contains("R10, which is set outside this file")), "{diags:#?}");
    // `Z=-DEPTH F=FEED` and `X=R10 Y=_X_HOME` keep no axis; `G1 X50` moves.
    assert_eq!(
        moves.iter().rev().find(|m| m.starts_with("STRAIGHT")).unwrap(),
        "STRAIGHT_FEED(50.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)"
    );
    assert_eq!(role_from_file_name("POCKET.SPF", &Registry::shipped().get("siemens").unwrap()), Some(ProgramRole::Called));
    assert_eq!(role_from_file_name("POCKET.MPF", &Registry::shipped().get("siemens").unwrap()), None);
}

/// A loop whose counter changes every round but whose exit reads an R parameter the caller
/// sets: the way out is taken (a run that ends leaves its loops) at once, not after a million
/// rounds.
#[test]
fn a_loop_on_an_unknown_value_ends_at_once() {
    let (moves, diags) = run("siemens", "COUNTER.SPF", ProgramRole::Auto);
    assert!(errors(&diags).is_empty(), "{diags:#?}");
    assert_eq!(
        moves,
        ["SET_FEED_RATE(100.0000)", "STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)", "SET_FEED_RATE(0.0000)"]
    );
    assert!(diags.iter().any(|d| d.code.as_str() == "flow::unknown-condition" && d.message.contains("leaves its loops")), "{diags:#?}");
}

/// A condition the lexer cannot read (`<=` is no Fanuc operator) does not jump on what was
/// left of it (a bare `GOTO 30`): the statement is skipped, and its own findings stay.
#[test]
fn a_broken_condition_takes_no_jump_and_keeps_its_findings() {
    let (moves, diags) = run("fanuc", "broken_if.nc", ProgramRole::Auto);
    assert!(moves.contains(&"STRAIGHT_FEED(5.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{moves:?}");
    let on_if: Vec<_> = diags.iter().filter(|d| d.is_error() && (17..42).contains(&d.range.start)).collect();
    assert!(on_if.len() >= 2, "{diags:#?}");
    assert!(diags.iter().any(|d| d.code.as_str() == "flow::broken-statement"), "{diags:#?}");
}

/// A loop whose counter changes every round, so that no round repeats the one before, and
/// whose exit never comes: the run stops at the repeat budget with a warning, and what it
/// keeps (calls, findings) does not grow with the loop budget.
#[test]
fn a_runaway_loop_stops_at_the_repeat_budget_whatever_the_loop_budget() {
    let d = Registry::shipped().get("fanuc").unwrap();
    let text = "O0001\n#1=0\nN10 #1=#1+1\nG1 X[#1/1000] Y1. F100\nIF [#1 GT 0] GOTO 10\nM30\n";
    let run = |max_loop_iterations: u64| {
        let profile = Profile { max_loop_iterations, max_repeated_blocks: 20_000, ..Profile::default() };
        let mut out = Vec::new();
        let diags = interpret(text, &d, &profile, &mut out);
        (out.len(), diags)
    };
    let (small, diags) = run(1_000_000);
    let (large, _) = run(u64::MAX);
    assert_eq!(small, large);
    assert!(small < 30_000, "{small} calls");
    assert_eq!(codes(&diags).iter().filter(|(_, s)| *s == Severity::Error).count(), 0, "{diags:#?}");
    assert!(codes(&diags).contains(&("flow::repeat-budget", Severity::Warning)), "{diags:#?}");
    // The spindle finding of the loop's G1 is listed once, not once a pass.
    assert!(diags.len() < 10, "{diags:#?}");
}

/// `check --as main|called|auto`, and the file name in auto: a `.SPF` is a called program.
#[test]
fn check_takes_the_role_from_as_or_the_file_name() {
    let dir = crate::root().join("tests/programs/called");
    let check = |file: &str, args: &[&str]| {
        let out = std::process::Command::new(crate::bin()).arg("check").arg(dir.join(file)).args(args).output().unwrap();
        (out.status.code(), String::from_utf8_lossy(&out.stdout).into_owned())
    };
    assert_eq!(check("sub_no_feed.nc", &["-d", "fanuc"]).0, Some(0));
    let (code, text) = check("sub_no_feed.nc", &["-d", "fanuc", "--as", "main"]);
    assert_eq!(code, Some(1), "{text}");
    assert!(text.contains("interp::no-feed"), "{text}");
    let (code, text) = check("main_no_feed.nc", &["-d", "fanuc", "--as", "called"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("the feed comes from the caller"), "{text}");
    // A Siemens subprogram file without any return or PROC: the extension says it is called.
    let (code, text) = check("COUNTER.SPF", &["-d", "siemens"]);
    assert_eq!(code, Some(0), "{text}");
    assert!(text.contains("role is given"), "{text}");
}

/// Every run ends quickly in bounded memory: `check` on runaway loops and on every corpus
/// file under 64 KB runs with its data segment limited to 100 MB (an allocation past it
/// aborts the process) and ends: the runaway loops stop at the analysis bound, which counts
/// blocks (how fast is `ncplan bench --corpus`'s to report, not a test's).
#[test]
fn check_stays_within_100_mb_on_runaway_loops_and_every_small_corpus_file() {
    let mut files: Vec<std::path::PathBuf> =
        ["runaway_while.nc", "runaway_goto.nc"].iter().map(|f| crate::root().join("tests/programs/called").join(f)).collect();
    let corpus = crate::shared().join("corpus");
    if let Ok(dirs) = std::fs::read_dir(&corpus) {
        let mut small: Vec<(u64, std::path::PathBuf)> = dirs
            .flatten()
            .filter(|d| d.path().is_dir())
            .flat_map(|d| std::fs::read_dir(d.path()).into_iter().flatten().flatten())
            .filter_map(|e| Some((e.metadata().ok()?.len(), e.path())))
            .filter(|(len, _)| *len < 64 * 1024)
            .collect();
        small.sort();
        files.extend(small.into_iter().rev().map(|(_, p)| p));
    }
    for f in files {
        let started = std::time::Instant::now();
        let status = std::process::Command::new("sh")
            .arg("-c")
            .arg("ulimit -d 102400; exec \"$0\" check \"$1\" >/dev/null 2>&1")
            .arg(crate::bin())
            .arg(&f)
            .status()
            .unwrap();
        let took = started.elapsed();
        assert!(matches!(status.code(), Some(0 | 1)), "{}: {status:?} (over 100 MB?)", f.display());
        // A hang guard, not a timing: the bound that stops a runaway loop counts blocks, so it ends
        // in about 3 s of CPU; minutes would mean the bound does not hold. Speed is `ncplan bench`'s.
        assert!(took < std::time::Duration::from_secs(180), "{}: no end after {took:?}", f.display());
    }
}

//! Two reading gaps of real programs (issue 17): the legacy Heidenhain cycles, one
//! sub-block per argument with the value after the name (`CYCL DEF 1.1 SET UP .1181`), and
//! the Okuma definition block (`DEF WORK` ... `END`, data for the control's drawing).
//! Small programs of our own in the styles of the posts and operators that write them.

use ncplan::diag::Diagnostic;
use ncplan::dialect::Registry;
use ncplan::interp::Profile;

/// The moves of `program` in `dialect`, one per line, and its findings.
fn run(dialect: &str, program: &str) -> (Vec<String>, Vec<Diagnostic>) {
    crate::moves_and_findings(dialect, program, &Profile::default())
}

fn errors(diags: &[Diagnostic]) -> Vec<String> {
    diags.iter().filter(|d| d.is_error()).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect()
}

fn warnings(diags: &[Diagnostic]) -> Vec<String> {
    diags.iter().filter(|d| !d.is_error() && d.severity == ncplan::diag::Severity::Warning).map(|d| d.message.clone()).collect()
}

/// Cycle 1 PECKING written as an old TNC (and the NX post) writes it: the value after the
/// sub-block's name, with a blank, a sign or none, and a leading dot.
#[test]
fn legacy_pecking_reads_the_value_after_each_sub_block_name() {
    let program = "\
0 BEGIN PGM PECK MM
1 TOOL CALL 1 Z S1000
2 L X+10 Y+10 R0 FMAX M3
3 L Z+20 R0 FMAX
4 CYCL DEF 1.0 PECKING
5 CYCL DEF 1.1 SET UP 2
6 CYCL DEF 1.2 DEPTH -12
7 CYCL DEF 1.3 PECKG 5
8 CYCL DEF 1.4 DWELL 0
9 CYCL DEF 1.5 F80
10 CYCL CALL
11 END PGM PECK MM
";
    let (moves, diags) = run("heidenhain", program);
    assert_eq!(errors(&diags), Vec::<String>::new());
    let feeds: Vec<&String> = moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).collect();
    // Pecks of 5, 5 and 2 down to 12 below the surface, which is the set-up clearance (2)
    // below the start (Z20): Z13, Z8, then the bottom Z6, each peck back up to the start.
    let depths: Vec<&str> = feeds.iter().map(|m| m.split(", ").nth(2).unwrap()).collect();
    assert_eq!(depths, ["13.0000", "8.0000", "6.0000"], "{moves:#?}");
    assert_eq!(moves.last().unwrap(), "STRAIGHT_TRAVERSE(10.0000, 10.0000, 20.0000, 0.0000, 0.0000, 0.0000)");
}

/// Inch values with a leading dot and no digit before it (`.1181`, `-.4921`), a blank
/// before the value, and a sub-block with no value (`1.4 DWELL`): the same as the values
/// written without a blank.
#[test]
fn leading_dot_values_after_a_blank_equal_the_values_written_tight() {
    let spaced = "\
0 BEGIN PGM P INCH
1 TOOL CALL 1 Z S1000
2 L X+1 Y+1 R0 FMAX M3
3 L Z+1 R0 FMAX
4 CYCL DEF 1.0 PECKING
5 CYCL DEF 1.1 SET UP .1181
6 CYCL DEF 1.2 DEPTH -.4921
7 CYCL DEF 1.3 PECKG  .2
8 CYCL DEF 1.4 DWELL
9 CYCL DEF 1.5 F9.8
10 CYCL CALL
11 END PGM P INCH
";
    let tight = spaced.replace("SET UP .1181", "DIST.1181").replace("DEPTH -.4921", "DEPTH-.4921").replace("PECKG  .2", "PLNGNG.2");
    let (a, da) = run("heidenhain", spaced);
    let (b, db) = run("heidenhain", &tight);
    assert_eq!(errors(&da), Vec::<String>::new());
    assert_eq!(errors(&db), Vec::<String>::new());
    assert!(a.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).count() >= 2, "{a:#?}");
    assert_eq!(a, b);
}

/// Cycle 2 TAPPING (floating holder): `2.1 SET UP` / `2.2 DEPTH` / `2.3 DWELL` / `2.4 F`,
/// called by M99 at each position: one tap per call, down to its depth and back.
#[test]
fn legacy_tapping_runs_at_each_call() {
    let program = "\
0 BEGIN PGM TAP MM
1 TOOL CALL 4 Z S300
2 L X+10 Y+10 R0 FMAX M3
3 L Z+10 R0 FMAX
4 CYCL DEF 2.0 TAPPING
5 CYCL DEF 2.1 SET UP 3
6 CYCL DEF 2.2 DEPTH -15
7 CYCL DEF 2.3 DWELL 0
8 CYCL DEF 2.4 F150
9 L R0 FMAX M99
10 L X+30 R0 FMAX M99
11 END PGM TAP MM
";
    let (moves, diags) = run("heidenhain", program);
    assert_eq!(errors(&diags), Vec::<String>::new());
    assert_eq!(warnings(&diags), Vec::<String>::new());
    let feeds: Vec<&String> = moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).collect();
    // In and out at each of the two positions, at the feed; the bottom is 3 + 15 below Z10.
    let zs: Vec<&str> = feeds.iter().map(|m| m.split(", ").nth(2).unwrap()).collect();
    assert_eq!(zs, ["-8.0000", "10.0000", "-8.0000", "10.0000"], "{moves:#?}");
    assert!(feeds[2].starts_with("STRAIGHT_FEED(30.0000, 10.0000"), "{moves:#?}");
}

/// A number after a display name that is not a legacy cycle's sub-block (`CYCL DEF 200
/// DRILLING`, the Q parameters on the next lines) is unchanged: the modern cycle still runs.
#[test]
fn a_modern_cycle_is_unchanged() {
    let program = "\
0 BEGIN PGM D MM
1 TOOL CALL 1 Z S1000
2 L X+10 Y+10 R0 FMAX M3
3 CYCL DEF 200 DRILLING ~
  Q200=2 ;SET-UP CLEARANCE ~
  Q201=-10 ;DEPTH ~
  Q206=150 ;FEED RATE FOR PLNGNG ~
  Q202=10 ;PLUNGING DEPTH ~
  Q210=0 ;DWELL TIME AT TOP ~
  Q203=+0 ;SURFACE COORDINATE ~
  Q204=50 ;2ND SET-UP CLEARANCE ~
  Q211=0 ;DWELL TIME AT DEPTH
4 L Z+100 R0 FMAX M99
5 END PGM D MM
";
    let (moves, diags) = run("heidenhain", program);
    assert_eq!(errors(&diags), Vec::<String>::new());
    assert!(moves.iter().any(|m| m.starts_with("STRAIGHT_FEED") && m.contains("-10")), "{moves:#?}");
}

/// The blank an Okuma lathe program defines for the control's drawing: `DEF WORK`, its
/// points, `END`. Skipped for motion with one note; its `END` is not a loop's end, and a
/// WHILE loop after it still closes with its own END.
#[test]
fn an_okuma_definition_block_is_skipped_with_one_note() {
    let program = "\
$BLANK.MIN%
DEF WORK
PT LF,LC,[0,0],[80,80],[602,0]
END
CLEAR
DRAW
N0001 G50 S3000
N0002 G00 X100 Z50
VC1=0
N0010 IF [VC1 GE 2] N0020
N0011 G01 X90 Z40 F0.2
N0012 VC1=VC1+1
N0013 GOTO N0010
N0020 G00 X100 Z50
N0030 M02
";
    let (moves, diags) = run("okuma_lathe", program);
    assert_eq!(errors(&diags), Vec::<String>::new());
    let notes: Vec<&Diagnostic> = diags.iter().filter(|d| d.code.as_str() == "flow::definition-skipped").collect();
    assert_eq!(notes.len(), 1, "{diags:#?}");
    assert!(notes[0].message.contains("DEF WORK"));
    assert!(moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).count() == 2, "{moves:#?}");
}

/// A definition that never ends is an error at its start, not a silent skip of the program.
#[test]
fn an_unclosed_definition_block_is_an_error() {
    let program = "\
DEF WORK
PT LF,LC,[0,0],[80,80],[602,0]
N0002 G00 X100 Z50
N0030 M02
";
    let (moves, diags) = run("okuma_lathe", program);
    assert!(moves.is_empty(), "{moves:#?}");
    assert!(errors(&diags).iter().any(|e| e.starts_with("flow::unmatched") && e.contains("not closed")), "{diags:#?}");
}

/// A milling Okuma reads `END` as before: the definition block is a lathe dictionary's.
#[test]
fn the_mill_dictionary_has_no_definition_block() {
    let d = Registry::shipped().get("okuma").unwrap();
    assert!(d.macros.definition_block.is_none());
    let l = Registry::shipped().get("okuma_lathe").unwrap();
    assert_eq!(l.macros.definition_block, Some(("DEF".to_owned(), "END".to_owned())));
}

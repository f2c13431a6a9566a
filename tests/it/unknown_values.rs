//! Values from outside the file (issue 17): probe results, pallet numbers, the tool
//! radius of the machine's tool table, a caller's Q parameters. A condition on such a value
//! takes the way a successful run goes, with a note naming it; the same program with the
//! value set in it still raises its alarm, as an error. Small programs in shop styles.

use std::collections::BTreeMap;
use std::sync::Arc;

use ncplan::diag::{Diagnostic, Severity};
use ncplan::interp::{Profile, ProgramSource, ToolData};

/// The moves of `program` in `dialect` under `profile`, one per line, and its findings.
fn run_with(dialect: &str, program: &str, profile: &Profile) -> (Vec<String>, Vec<Diagnostic>) {
    crate::moves_and_findings(dialect, program, profile)
}

fn run(dialect: &str, program: &str) -> (Vec<String>, Vec<Diagnostic>) {
    run_with(dialect, program, &Profile::default())
}

fn errors(diags: &[Diagnostic]) -> Vec<String> {
    diags.iter().filter(|d| d.is_error()).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect()
}

/// The messages of the findings with `code`.
fn said(diags: &[Diagnostic], code: &str) -> Vec<String> {
    diags.iter().filter(|d| d.code.as_str() == code).map(|d| d.message.clone()).collect()
}

/// Programs by name, as a program directory would give them.
struct Programs(BTreeMap<String, String>);

impl ProgramSource for Programs {
    fn load(&self, name: &str) -> Option<String> {
        let stem = name.rsplit(['\\', '/', ':']).next().unwrap_or(name);
        self.0.get(stem).cloned()
    }
}

/// A Haas/Fanuc probing macro in the style of a CAM probing post: probe down, and if the
/// skip position #5063 shows nothing was found, try again further left; when the tries run
/// out, `#3000` alarms. The skip position is machine data.
const PROBE_SEARCH: &str = "\
O1000 (EDGE SEARCH)
G90 G54 G0 X0 Y0 Z10.
#103 = 3
N10
IF [#103 LE 0] GOTO 30
G91 G1 X-1. F600.
G90 G31 Z-2. F60.
IF [#5063 LT -0.08] GOTO 40
G90 G1 Z1. F600.
#103 = #103 - 1
GOTO 10
N30
#3000 = 101 (EDGE NOT FOUND)
N40
G90 G1 Z5. F600.
G0 X20.
M30
";

#[test]
fn a_probe_search_that_finds_its_edge_is_the_run_taken() {
    let (moves, diags) = run("haas", PROBE_SEARCH);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let notes = said(&diags, "flow::unknown-condition");
    assert!(
        notes.iter().any(|m| m.contains("IF [#5063 LT -0.08] GOTO 40")
            && m.contains("#5063")
            && m.contains("taken as true")
            && m.contains("leaves the loop")),
        "{notes:?}"
    );
    // One try (left 1, probe down), then the found branch: up and away.
    assert_eq!(moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED(-1.0000, 0.0000, 10.0000")).count(), 1, "{moves:?}");
    assert!(!moves.iter().any(|m| m.contains("(-2.0000, 0.0000")), "no second try: {moves:?}");
    assert!(moves.iter().any(|m| m.starts_with("STRAIGHT_FEED(-1.0000, 0.0000, 5.0000")), "{moves:?}");
    assert!(moves.last().is_some_and(|m| m.starts_with("STRAIGHT_TRAVERSE(20.0000")), "{moves:?}");
}

/// The same macro with the skip position set in the program to a miss: the search runs
/// out and the alarm is an error.
#[test]
fn a_probe_search_with_a_known_miss_still_alarms() {
    let program = PROBE_SEARCH.replace("IF [#5063 LT -0.08]", "#5063 = 0\nIF [#5063 LT -0.08]");
    let (_, diags) = run("haas", &program);
    let errors = errors(&diags);
    assert!(errors.iter().any(|e| e.starts_with("interp::alarm") && e.contains("EDGE NOT FOUND")), "{errors:?}");
    assert!(said(&diags, "flow::unknown-condition").is_empty());
}

/// A Fanuc probing macro in the Renishaw style: out of tolerance goes to the alarm, within
/// it the macro goes on.
#[test]
fn an_out_of_range_probe_result_alarm_is_not_taken() {
    let program = "\
%
O9810 (PROTECTED MOVE)
G90 G31 Z-10. F500.
IF [#5063 LT -5.] GOTO 99
G0 Z20.
GOTO 100
N99 #3000 = 1 (PROBE TRIGGERED EARLY)
N100 M99
%
";
    let (moves, diags) = run("fanuc", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let notes = said(&diags, "flow::unknown-condition");
    assert!(notes.iter().any(|m| m.contains("#5063") && m.contains("taken as false") && m.contains("alarm")), "{notes:?}");
    assert!(moves.iter().any(|m| m.contains("20.0000, 0.0000, 0.0000, 0.0000)")), "{moves:?}");
    let known = program.replace("G90 G31", "#5063 = -7.\nG90 G31");
    let (_, diags) = run("fanuc", &known);
    assert!(errors(&diags).iter().any(|e| e.starts_with("interp::alarm")), "{:?}", errors(&diags));
}

/// A Heidenhain cycle library: its parameter check jumps to an `FN 14` error label when a
/// caller's Q parameter is missing. Run on its own, the caller's Q1 is unknown and the
/// check passes.
const CYCLE_LIBRARY: &str = "\
0 BEGIN PGM POCKET MM
1 FN 9: IF +Q1 EQU +0 GOTO LBL 99
2 FN 12: IF +Q2 LT +0 GOTO LBL 98
3 L X+10 Y+10 R0 FMAX
4 L Z-Q2 R0 F200
5 L X+40 R0 F500
6 L Z+50 R0 FMAX
7 FN 9: IF +0 EQU +0 GOTO LBL 100
8 LBL 98
9 FN 14: ERROR= 1001
10 LBL 99
11 FN 14: ERROR= 1000
12 LBL 100
13 END PGM POCKET MM
";

#[test]
fn a_cycle_librarys_parameter_check_passes_without_its_caller() {
    let (moves, diags) = run("heidenhain", CYCLE_LIBRARY);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let notes = said(&diags, "flow::unknown-condition");
    assert!(notes.iter().any(|m| m.contains("IF +Q1 EQU +0 GOTO LBL 99") && m.contains("Q1") && m.contains("taken as false")), "{notes:?}");
    assert!(notes.iter().any(|m| m.contains("IF +Q2 LT +0 GOTO LBL 98") && m.contains("raises the program's alarm")), "{notes:?}");
    // The depth is the caller's: the plunge keeps its known axes and says so.
    assert!(said(&diags, "interp::unknown-value").iter().any(|m| m.contains("Q2")), "{diags:?}");
    assert!(moves.iter().any(|m| m.starts_with("STRAIGHT_FEED(40.0000, 10.0000")), "{moves:?}");
    assert!(moves.last().is_some_and(|m| m.contains("40.0000, 10.0000, 50.0000")), "{moves:?}");
}

#[test]
fn a_cycle_library_given_a_bad_parameter_raises_its_error() {
    let program = CYCLE_LIBRARY.replace("1 FN 9:", "1 Q1 = 0\n1 FN 9:");
    let (_, diags) = run("heidenhain", &program);
    let errors = errors(&diags);
    assert!(errors.iter().any(|e| e.starts_with("interp::alarm") && e.contains("1000")), "{errors:?}");
}

/// A loop over the tool radius, Q108: the machine's tool table holds it. Without a tool
/// table entry it is unknown, the loop ends after one pass with a note, and no division by
/// zero is reported; with the tool in the table the loop runs its passes.
const RADIUS_LOOP: &str = "\
0 BEGIN PGM STEPS MM
1 TOOL CALL 5 Z S3000
2 Q3 = 0
3 Q4 = 20 / Q108
4 L X+0 Y+0 Z+5 R0 FMAX M3
5 LBL 1
6 Q3 = Q3 + 1
7 L X+Q3 R0 F300
8 FN 12: IF +Q3 LT +Q108 GOTO LBL 1
9 L Z+50 R0 FMAX
10 END PGM STEPS MM
";

#[test]
fn a_loop_over_an_unknown_tool_radius_ends_with_a_note() {
    let (moves, diags) = run("heidenhain", RADIUS_LOOP);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(said(&diags, "interp::arithmetic").is_empty(), "division by an unknown radius is unknown, not by zero");
    let notes = said(&diags, "flow::unknown-condition");
    assert!(notes.iter().any(|m| m.contains("Q108") && m.contains("tool table") && m.contains("jump back is not taken")), "{notes:?}");
    let feeds: Vec<_> = moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).collect();
    assert_eq!(feeds.len(), 1, "{moves:?}");

    let mut tools = BTreeMap::new();
    tools.insert(5, ToolData { diameter: Some(6.0), ..ToolData::default() });
    let profile = Profile { tools, ..Profile::default() };
    let (moves, diags) = run_with("heidenhain", RADIUS_LOOP, &profile);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(said(&diags, "flow::unknown-condition").is_empty());
    assert_eq!(moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).count(), 3, "{moves:?}");
}

/// A main program that sets the library's Q parameters and calls it: the check reads known
/// values, and a bad one raises the library's error.
#[test]
fn a_caller_that_sets_the_parameters_gets_the_librarys_check() {
    let mut programs = BTreeMap::new();
    programs.insert("POCKET.H".to_owned(), CYCLE_LIBRARY.to_owned());
    let profile = Profile { programs: Some(Arc::new(Programs(programs))), ..Profile::default() };
    let main = "0 BEGIN PGM MAIN MM\n1 Q1 = 1\n2 Q2 = 4\n3 CALL PGM TNC:\\POCKET.H\n4 END PGM MAIN MM\n";
    let (moves, diags) = run_with("heidenhain", main, &profile);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(said(&diags, "flow::unknown-condition").is_empty(), "{diags:?}");
    assert!(moves.iter().any(|m| m.starts_with("STRAIGHT_FEED(10.0000, 10.0000, -4.0000")), "{moves:?}");
    let bad = main.replace("Q2 = 4", "Q2 = -4");
    let (_, diags) = run_with("heidenhain", &bad, &profile);
    assert!(errors(&diags).iter().any(|e| e.contains("1001")), "{:?}", errors(&diags));
}

/// A Mazak pallet-changer macro reads the machine's pallet variable (#51998, beyond Fanuc's
/// #9999): unknown, never an out-of-range parameter; a Fanuc-style `#1000`-range input reads
/// the same way.
#[test]
fn pallet_macros_read_machine_variables_as_unknown() {
    let program = "\
O9100 (PALLET SWAP)
IF [#51998 EQ 1.] GOTO 10
M911
GOTO 20
N10 M912
N20 IF [#1004 EQ 0] GOTO 30
#3000 = 12 (PALLET NOT CLAMPED)
N30 M99
";
    let (_, diags) = run("mazak", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let notes = said(&diags, "flow::unknown-condition");
    assert!(notes.iter().any(|m| m.contains("#51998") && m.contains("outside this file")), "{notes:?}");
    assert!(notes.iter().any(|m| m.contains("#1004") && m.contains("taken as true") && m.contains("alarm")), "{notes:?}");
    let known = program.replace("(PALLET SWAP)", "(PALLET SWAP)\n#1004 = 1");
    let (_, diags) = run("mazak", &known);
    assert!(errors(&diags).iter().any(|e| e.starts_with("interp::alarm") && e.contains("PALLET NOT CLAMPED")), "{:?}", errors(&diags));
}

/// The notes of an unknown condition are notes, not warnings or errors.
#[test]
fn unknown_conditions_are_notes() {
    let (_, diags) = run("heidenhain", CYCLE_LIBRARY);
    assert!(diags.iter().filter(|d| d.code.as_str() == "flow::unknown-condition").all(|d| d.severity == Severity::Note));
}

/// A Siemens tool check in the style of a machine builder's cycle: the active tool number
/// `$P_TOOLNO` and the tool's length `$TC_DP3[…]` are the control's data. A run that
/// succeeds has the right tool, so `SETAL` is not taken; the values are unknown, never 0.
const SIEMENS_TOOL_CHECK: &str = "\
G90 G54 G17
T=\"DRILL8\" M6
IF $P_TOOLNO==0 GOTOF NO_TOOL
R1=$TC_DP3[$P_TOOLNO,1]
IF R1<=0 GOTOF NO_TOOL
G0 X10 Y20 Z5 S2000 M3
G1 Z-5 F150
G0 Z50
M30
NO_TOOL:
SETAL(61001)
M0
";

#[test]
fn siemens_system_variables_are_unknown_and_the_check_passes() {
    let (moves, diags) = run("siemens", SIEMENS_TOOL_CHECK);
    assert_eq!(errors(&diags), Vec::<String>::new(), "{diags:?}");
    let unknown = said(&diags, "interp::unknown-value");
    assert!(unknown.iter().any(|m| m.to_ascii_uppercase().contains("$P_TOOLNO")), "{diags:?}");
    assert!(
        said(&diags, "interp::unset-variable").iter().all(|m| !m.to_ascii_uppercase().contains("$P_TOOLNO")),
        "not taken as 0: {diags:?}"
    );
    assert!(moves.iter().any(|m| m.contains("STRAIGHT_FEED") && m.contains("-5.0000")), "the drilling move is made: {moves:?}");
}

/// What a `THEN` sets on a condition the caller decides depends on the caller's value, and
/// its note names that value, not "set outside this file"; a work offset numbered by an
/// argument (`G10 L20 P#1`, `G54.1 P#1`) is not known, said once by the note on the word,
/// without a warning that offsets are numbered 1 to 300 and without choosing offset 1.
#[test]
fn values_that_depend_on_the_caller_name_the_caller() {
    let program = "O9001\nIF [#1 GT 5] THEN #33=1\nG0 X#33\nG10 L20 P#1 X0 Y0 Z0\nG54.1 P#1\nG0 Y5.\nM99\n";
    let (_, diags) = run("fanuc", program);
    assert!(errors(&diags).is_empty(), "{diags:?}");
    let notes = said(&diags, "interp::unknown-value");
    assert!(notes.iter().any(|m| m.starts_with("`X#33` reads argument #1, which the caller gives")), "{notes:?}");
    assert_eq!(notes.iter().filter(|m| m.starts_with("`P#1`")).count(), 2, "{notes:?}");
    assert!(said(&diags, "interp::unsupported").is_empty(), "{diags:?}");
    let mut canon = Vec::new();
    let d = ncplan::dialect::Registry::shipped().get("fanuc").unwrap();
    ncplan::interp::interpret(program, &d, &Profile::default(), &mut canon);
    assert!(!canon.iter().any(|c| matches!(c.op, ncplan::canon::CanonOp::SetG5xOffset(i, ..) if i > 9)), "{canon:?}");
    // A known number out of range still warns.
    let (_, diags) = run("fanuc", "G21\nG10 L20 P400 X0 Y0 Z0\nM30\n");
    assert!(said(&diags, "interp::unsupported").iter().any(|m| m.contains("numbered 1 to 300")), "{diags:?}");
}

/// A handshake: the program sets a common variable and waits, polling it with a dwell,
/// for the PLC, a robot or a remote client to change it. The loop changes nothing itself;
/// it is a wait, with a warning, not an endless loop, and the run goes on past it. A loop
/// on the program's own local that changes nothing is still an endless loop.
#[test]
fn a_loop_waiting_for_an_outside_variable_is_a_wait_not_an_endless_loop() {
    let handshake = "O0001\nG21 G90\n#890=1 (REQUEST)\nN1 IF[#890EQ3]GOTO2\nG04 P1000\nGOTO1\nN2 G0 X10.\nM30\n";
    for dialect in ["fanuc", "haas", "mitsubishi", "mazak"] {
        let (moves, diags) = run(dialect, handshake);
        assert!(errors(&diags).is_empty(), "{dialect}: {diags:?}");
        let waits = said(&diags, "flow::wait-loop");
        assert_eq!(waits.len(), 1, "{dialect}: {diags:?}");
        assert!(waits[0].starts_with("the loop waits for #890 to change"), "{waits:?}");
        assert!(moves.iter().any(|m| m.starts_with("STRAIGHT_TRAVERSE(10.0000,")), "{dialect}: {moves:?}");
    }
    // The same wait written as a WHILE loop on a common variable.
    let (_, diags) = run("fanuc", "O0002\n#500=0\nWHILE [#500 EQ 0] DO1\nG04 P500\nEND1\nM30\n");
    assert!(errors(&diags).is_empty(), "{diags:?}");
    assert_eq!(said(&diags, "flow::wait-loop").len(), 1, "{diags:?}");
    // A local the program owns: nothing outside changes it, so the loop never ends.
    let (_, diags) = run("fanuc", "O0003\n#1=0\nWHILE [#1 LT 5] DO1\nG04 P100\nEND1\nM30\n");
    assert!(errors(&diags).iter().any(|e| e.starts_with("flow::loop-limit")), "{diags:?}");
    assert!(said(&diags, "flow::wait-loop").is_empty(), "{diags:?}");
}

/// A feed the shop keeps in a common variable (`F#650`) is the machine's, not zero: the
/// moves after it are not "cutting at feed zero", in a main program too.
#[test]
fn a_feed_from_a_common_variable_is_not_a_zero_feed() {
    let (_, diags) = run("fanuc", "O1000\nG21 G90 G54 G00 X0 Y0\nM3 S1000\nG01 Z-1. F#650\nX10.\nY10.\nM30\n");
    assert!(errors(&diags).is_empty(), "{diags:?}");
    assert!(said(&diags, "interp::no-feed").is_empty(), "{diags:?}");
    // A feed the program never sets is still an error.
    let (_, diags) = run("fanuc", "O1000\nG21 G90 G54 G00 X0 Y0\nM3 S1000\nG01 Z-1.\nM30\n");
    assert!(errors(&diags).iter().any(|e| e.starts_with("interp::no-feed")), "{diags:?}");
}

/// An arc whose end, centre or radius the caller gives (`CR=RAD` in a Siemens procedure,
/// `R#18` in a Fanuc macro) cannot be drawn or checked: no "needs I or K" or "cannot be a
/// full circle" error, only the notes on the words; the next moves go on from its known end.
#[test]
fn an_arc_shaped_by_the_callers_values_is_not_an_error() {
    let (_, diags) = run("siemens", "PROC SHAPE(REAL RAD, REAL DX)\nG18 G91 G02 X=DX Z=0 CR=RAD F500\nG90 G1 X10 Z0\nRET\n");
    assert!(errors(&diags).is_empty(), "{diags:?}");
    assert_eq!(said(&diags, "interp::unknown-value").len(), 2, "{diags:?}");
    let (moves, diags) = run("fanuc", "O9001\nG17 G90 G0 X0 Y0\nG2 X#24 Y0 R#18 F100\nG3 X10. Y0 I#4 J0\nG1 X20.\nM99\n");
    assert!(errors(&diags).is_empty(), "{diags:?}");
    assert!(!moves.iter().any(|m| m.starts_with("ARC_FEED")), "{moves:?}");
    assert!(moves.iter().any(|m| m.starts_with("STRAIGHT_FEED(20.0000,")), "{moves:?}");
    // With every value known, a bad arc is still an error.
    let (_, diags) = run("fanuc", "O1\nG17 G21 G90 G0 X0 Y0\nG2 X10. Y0 R2. F100.\nM30\n");
    assert!(errors(&diags).iter().any(|e| e.starts_with("interp::bad-arc")), "{diags:?}");
}

/// Argument guards that all jump to one alarm block (`IF [#18 EQ #0] GOTO 800` … `GOTO 800`
/// after the accepted cases) and a retry loop on an input (`IF [#1004 EQ 0] GOTO 9`
/// `#33=#33+1` `IF [#33 LT 4] GOTO 1` `#3000=146`): analysed alone, the way a successful call
/// goes is taken at each condition; called with a missing argument, the alarm is raised.
#[test]
fn guards_that_jump_to_a_shared_alarm_block_take_the_successful_way() {
    let library = std::fs::read_to_string(crate::root().join("tests/programs/shops/fanuc/guarded_measure_macro.nc")).unwrap();
    let (_, diags) = run("fanuc", &library);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let notes = said(&diags, "flow::unknown-condition");
    assert!(notes.iter().any(|m| m.contains("`IF[#33EQ100.]GOTO3`") && m.contains("taken as true")), "{notes:?}");
    assert!(notes.iter().any(|m| m.contains("`IF[#1004EQ0]GOTO9`") && m.contains("taken as true")), "{notes:?}");
    // Called without R, the guard raises the alarm.
    let main = format!("O1000\nG21 G90 G54\nG65 P7301 X10. Z-5.\nM30\n{}", library.trim_start_matches("%\n"));
    let (_, diags) = run("fanuc", &main);
    assert!(errors(&diags).iter().any(|e| e.starts_with("interp::alarm") && e.contains("ARGUMENTS")), "{diags:?}");
}

/// An Okuma OSP subprogram read alone: its arguments (`PA`, `PH`) come from the `CALL`, so
/// they are unknown here, and a check that jumps to an alarm (`VDOUT[992]`, the alarm output,
/// after its message in `VUACM[1]`) when one is missing is passed as a successful run passes
/// it. The same check on a value the program sets raises the alarm, as an error.
#[test]
fn an_okuma_subprogram_s_arguments_are_the_caller_s() {
    let sub = "OROTA\n IF[PA EQ EMPTY]NER04\n GOTO N0001\nNER04\n  VUACM[1]='NO DATA \"PA\"'\n  VDOUT[992]=1004\n  GOTO NER04\nN0001\nG0 X10. Y5.\nRTS\n";
    let (moves, diags) = run("okuma", sub);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(moves.iter().any(|m| m.contains("10.0000") && m.contains("5.0000")), "{moves:?}");
    let notes = said(&diags, "flow::unknown-condition");
    assert!(notes.iter().any(|n| n.contains("the other way raises the program's alarm")), "{notes:?}");

    let set = sub.replace("OROTA\n", "OROTA\n PA=0\n EMPTY=0\n");
    let (_, diags) = run("okuma", &set);
    let errors = errors(&diags);
    assert!(errors.iter().any(|e| e.starts_with("interp::alarm") && e.contains("1004")), "{errors:?}");
}

/// A Renishaw-style protected move read alone: its argument checks (`IF[#26NE#0]GOTO3`) read
/// the caller's arguments; the way taken sets `#8=210` and calls the error macro, whose
/// `GOTO#149` lands on an alarm. The control raises it only if the caller left Z out, which is
/// not known here: a warning, not an error. With Z known to be vacant, the alarm is an error.
#[test]
fn an_alarm_on_the_way_chosen_at_an_unknown_argument_is_a_warning() {
    let program = "\
%
O9810 (PROTECTED MOVE)
IF[#26NE#0]GOTO3
#8=210
M98P9700
N3
G90 G1 Z#26 F100.
M99
O9700 (ERROR MESSAGE)
#149=#8
GOTO#149
N210
#3000=91(XYZ INPUT MISSING)
M99
%
";
    let (_, diags) = run("fanuc", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let alarms: Vec<&Diagnostic> = diags.iter().filter(|d| d.code.as_str() == "interp::alarm").collect();
    assert!(alarms.iter().any(|d| d.severity == Severity::Warning && d.message.contains("IF[#26NE#0]GOTO3")), "{diags:?}");
    let known = program.replace("IF[#26NE#0]GOTO3", "#26=#0\nIF[#26NE#0]GOTO3");
    let (_, diags) = run("fanuc", &known);
    assert!(errors(&diags).iter().any(|e| e.starts_with("interp::alarm") && e.contains("XYZ INPUT MISSING")), "{diags:?}");
}

/// A Siemens grinding loop that waits (the work head turning) until the operator's retract key sets a
/// PLC byte (`IF $A_DBB[2]==1` `GOTOF RING_END` `ENDIF` `GOTOB C_CYCLE`): the round comes
/// alike, but its condition reads the control's data, which changes; a warning, and the run
/// is followed no further, never an endless-loop error.
#[test]
fn a_loop_waiting_on_the_controls_data_is_no_endless_loop() {
    let program = "\
N10 G0 X10 Z0
C_CYCLE:
G4 F1
IF $A_DBB[2]==1
GOTOF RING_END
ENDIF
GOTOB C_CYCLE
RING_END:
G90 G0 X50
M30
";
    let (_, diags) = run("siemens", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert_eq!(said(&diags, "flow::wait-loop").len(), 1, "{diags:?}");
    // The same loop on a value the program sets never ends: still an error.
    let known = format!(
        "DEF INT KEY\n{}",
        program.replace("N10 G0 X10 Z0\n", "N10 G0 X10 Z0\nSTART:\nG0 X20\n").replace("IF $A_DBB[2]==1", "KEY=0\nIF KEY==1")
    );
    let (_, diags) = run("siemens", &known);
    assert!(errors(&diags).iter().any(|e| e.starts_with("flow::loop-limit")), "{diags:?}");
}

/// A grinder's infeed loop in the style of a Sinumerik shop cycle (`DOSKOK:` … `GOTOB
/// DOSKOK`): each pass feeds in deeper, and the exit past the loop's `GOTOB` reads a global
/// the machine's data sets (`IF (PASS>=MAXPASS) GOTOF KRAJ`), with a check between it and the
/// jump back. No round repeats the one before, so the loop would run to the analysis bound;
/// a run that ends leaves it: its whole body runs one pass (the check after the exit too), the
/// loop comes round, and the exit is taken at its next test, with a warning that the pass count
/// is assumed.
#[test]
fn a_jump_loops_exit_on_unknown_data_leaves_after_one_pass() {
    let program = "\
PROC GRIND
DEF REAL DEPTH=0
DEF INT PASS=0
G0 X20 Z5
DOSKOK:
DEPTH=DEPTH-0.1
PASS=PASS+1
G1 X=10+DEPTH F100
G0 X20
IF (PASS>=MAXPASS) GOTOF KRAJ
IF (PASS>=2)
  PASS=PASS+0
ENDIF
GOTOB DOSKOK
KRAJ:
G0 X50
M17
";
    let (moves, diags) = run("siemens", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let feeds: Vec<&String> = moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).collect();
    assert_eq!(
        feeds,
        ["STRAIGHT_FEED(9.9000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)", "STRAIGHT_FEED(9.8000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)"],
        "{moves:?}"
    );
    assert_eq!(moves.last().map(String::as_str), Some("STRAIGHT_TRAVERSE(50.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)"));
    let exit: Vec<&Diagnostic> = diags.iter().filter(|d| d.code.as_str() == "flow::unknown-condition").collect();
    assert!(
        exit.iter().any(|d| d.severity == Severity::Warning && d.message.contains("leaves the loop") && d.message.contains("one pass")),
        "{exit:?}"
    );
    assert!(said(&diags, "flow::repeat-budget").is_empty(), "{diags:?}");
    // The same loop with the pass count set in the program runs its passes and leaves.
    let known = program.replace("DEF INT PASS=0\n", "DEF INT PASS=0\nDEF INT MAXPASS=3\n");
    let (moves, diags) = run("siemens", &known);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert_eq!(moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).count(), 3, "{moves:?}");
    assert!(said(&diags, "flow::unknown-condition").is_empty(), "{diags:?}");
}

/// The same exit out of a Sinumerik `LOOP` … `ENDLOOP`, and out of a Fanuc `N10` … `GOTO 10`
/// loop whose exit reads a common variable the machine keeps (`#500`) with another check
/// between it and the jump back: one whole pass each (the moves before the exit come round
/// once more before it is taken), a warning, no bound reached.
#[test]
fn an_endless_loops_exit_on_unknown_data_leaves_after_one_pass() {
    let siemens = "\
PROC LOOPER
DEF REAL DEPTH=0
G0 X20 Z5
LOOP
DEPTH=DEPTH-0.1
G1 X=10+DEPTH F100
G0 X20
IF (DEPTH<=ZIEL) GOTOF KRAJ
ENDLOOP
KRAJ:
G0 X50
M17
";
    let fanuc = "\
O1000
G90 G54 G0 X0 Y0 Z5
#1=0
N10 #1=#1-0.5
G1 Z#1 F100
G1 X10
G0 Z5
X0
IF [#1 LE #500] GOTO 99
IF [#1 LT -100] GOTO 99
GOTO 10
N99 G0 Z50
M30
";
    for (dialect, program, cuts) in [("siemens", siemens, 2), ("fanuc", fanuc, 4)] {
        let (moves, diags) = run(dialect, program);
        assert!(errors(&diags).is_empty(), "{dialect}: {:?}", errors(&diags));
        assert_eq!(moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).count(), cuts, "{dialect}: {moves:?}");
        assert!(said(&diags, "flow::repeat-budget").is_empty(), "{dialect}: {diags:?}");
        assert!(
            diags
                .iter()
                .any(|d| d.code.as_str() == "flow::unknown-condition" && d.severity == Severity::Warning && d.message.contains("one pass")),
            "{dialect}: {diags:?}"
        );
    }
}

/// The pass an exit on unknown data waits for is counted per entry into its loop: a Fanuc
/// subprogram whose `N10 IF [#1000 EQ 1] GOTO 90` … `GOTO 10` loop reads an input, called
/// twice, runs its pass at each call (the second call used to leave at once, its moves lost).
#[test]
fn a_loop_exit_on_unknown_data_runs_its_pass_at_each_call() {
    let program = "\
O1000
G0 X0 Y0 Z0
M98 P2000
G0 Z1
M98 P2000
M30
O2000
N10 IF [#1000 EQ 1] GOTO 90
N15 IF [#1 GT 5] THEN #2=1
N20 G1 X10 F100
N30 G1 X0
N40 GOTO 10
N90 M99
%
";
    let (moves, diags) = run("fanuc", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let feeds: Vec<&String> = moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).collect();
    assert_eq!(feeds.len(), 4, "{moves:?}");
    // The second call's pass runs after the `G0 Z1` (Z1 without a decimal point: one increment).
    let after =
        moves.iter().position(|m| m.starts_with("STRAIGHT_TRAVERSE") && !m.contains("(0.0000, 0.0000, 0.0000")).expect("the Z1 move");
    assert_eq!(moves[after..].iter().filter(|m| m.starts_with("STRAIGHT_FEED")).count(), 2, "{moves:?}");
}

/// The same for a Sinumerik `GOTOB` loop inside an outer loop: each round of the outer loop
/// runs the inner loop's pass (X10 and back) before its exit on the PLC input is taken.
#[test]
fn an_inner_loops_exit_on_unknown_data_runs_its_pass_each_outer_round() {
    let program = "\
N10 G0 X0 Y0 Z0
N20 R1=0
OUTER:
INNER:
N40 IF $A_IN[1]==1 GOTOF OUT
N45 IF R1>5
N46 G1 Y5
N47 ENDIF
N50 G1 X10 F100
N60 G1 X0
N70 GOTOB INNER
OUT:
N80 R1=R1+1
N85 G0 Z=R1
N90 IF R1<3 GOTOB OUTER
N100 M30
";
    let (moves, diags) = run("siemens", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let feeds: Vec<&str> = moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).map(|m| &m[..24]).collect();
    assert_eq!(
        feeds,
        [
            "STRAIGHT_FEED(10.0000, 0",
            "STRAIGHT_FEED(0.0000, 0.",
            "STRAIGHT_FEED(10.0000, 0",
            "STRAIGHT_FEED(0.0000, 0.",
            "STRAIGHT_FEED(10.0000, 0",
            "STRAIGHT_FEED(0.0000, 0."
        ],
        "{moves:?}"
    );
}

/// An exit after the loop's first moves (a grinder's infeed `G1 X=R1`, then `IF $AA_IM[X]<R5
/// GOTOF ENDE`, then the strokes `Z-100` and back): the rest of the body runs its pass before
/// the exit is taken, so the strokes are in the run.
#[test]
fn a_loop_exit_after_the_infeed_still_runs_the_strokes() {
    let program = "\
N10 G0 X50 Z0
N20 R1=40
LBL:
N30 G1 X=R1 F100
N40 IF $AA_IM[X]<R5 GOTOF ENDE
N45 IF R1>100
N46 M0
N47 ENDIF
N50 G1 Z-100
N60 G1 Z0
N70 R1=R1-0.01
N80 GOTOB LBL
ENDE:
N90 M30
";
    let (moves, diags) = run("siemens", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let feeds: Vec<&String> = moves.iter().filter(|m| m.starts_with("STRAIGHT_FEED")).collect();
    assert_eq!(
        feeds,
        [
            "STRAIGHT_FEED(40.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(40.0000, 0.0000, -100.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(40.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(39.9900, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)",
        ],
        "{moves:?}"
    );
    assert!(said(&diags, "flow::repeat-budget").is_empty(), "{diags:?}");
}

/// A Siemens array element numbered by a value from outside the file (`WERT[R1]` with R1 the
/// tool number `$P_TOOLNO`): which element is written is not known, so the write is not
/// followed (a note, as for `#[#111+5]`), and a later read through an unknown index is itself
/// unknown, not the value of the element "NaN" the first write would have made. An element
/// numbered by a known value is written and read as before.
#[test]
fn an_array_element_at_an_unknown_index_is_neither_written_nor_read_back() {
    let program = "DEF REAL WERT[4]\nR1=$P_TOOLNO\nWERT[R1]=7\nWERT[2]=3\nR2=WERT[R1]\nG1 X=WERT[2] F100\nG1 Y=R2\nM30\n";
    let (moves, diags) = run("siemens", program);
    assert_eq!(errors(&diags), Vec::<String>::new(), "{diags:?}");
    let notes = said(&diags, "interp::unknown-value");
    assert!(
        notes
            .iter()
            .any(|m| m.to_ascii_uppercase().starts_with("THE ELEMENT OF `WERT` THIS ASSIGNS IS NUMBERED BY A VALUE SET OUTSIDE THIS FILE")),
        "{notes:?}"
    );
    let feeds: Vec<&String> = moves.iter().filter(|m| m.contains("STRAIGHT_FEED")).collect();
    assert!(feeds.first().is_some_and(|m| m.contains("(3.0000,")), "{moves:?}");
    // `Y=R2`: R2 read WERT[R1] through the unknown index, so it is unknown (the move keeps Y, a
    // note), not 7.
    assert!(feeds.iter().all(|m| !m.contains("7.0000")), "{moves:?}");
}

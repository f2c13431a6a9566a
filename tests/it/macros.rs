//! Macro programming and control flow, by what they make the machine do: Fanuc Macro B
//! (`IF`/`GOTO`/`WHILE`/`DO`/`END`, `G65`, `M98`/`M99`, vacant variables, alarms) and the
//! expression rules of the issue. Each test runs a small program written for it and checks the
//! moves (canonical calls) and the findings.

use expect_test::expect;
use ncplan::canon::{CanonOp, write_call};
use ncplan::dialect::Registry;
use ncplan::interp::{Profile, ProgramSource, interpret, run};

/// Canonical moves (other calls left out) and the diagnostic codes.
fn moves(dialect: &str, program: &str) -> (String, Vec<&'static str>) {
    moves_with(dialect, program, &Profile::default())
}

fn moves_with(dialect: &str, program: &str, profile: &Profile) -> (String, Vec<&'static str>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut canon = Vec::new();
    let diags = interpret(program, &d, profile, &mut canon);
    (render(&canon), diags.iter().map(|d| d.code.as_str()).collect())
}

fn render(canon: &[ncplan::canon::Canon]) -> String {
    let mut out = String::new();
    for c in canon {
        if matches!(c.op, CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. }) {
            write_call(&mut out, &c.op);
        }
    }
    out
}

#[test]
fn expressions_follow_precedence_and_degree_functions() {
    let (out, codes) =
        moves("fanuc", "G0 X[1+2*3-4/5] Z[SIN[30]] Y[ATAN[1]/[1]]\nG0 X[SQRT[16]+ABS[-1]+ROUND[1.5]+FIX[1.7]+FUP[1.2]]\nM30\n");
    expect![[r#"
        STRAIGHT_TRAVERSE(6.2000, 45.0000, 0.5000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.0000, 45.0000, 0.5000, 0.0000, 0.0000, 0.0000)
    "#]]
    .assert_eq(&out);
    assert!(codes.is_empty(), "{codes:?}");
}

#[test]
fn two_argument_functions_in_one_bracket() {
    let (out, codes) = moves("fanuc", "G0 X[ATAN[1,1]] Y[POW[2,3]] Z[ATAN[1]/[-1]]\nM30\n");
    assert!(out.starts_with("STRAIGHT_TRAVERSE(45.0000, 8.0000, 135.0000,"), "{out}");
    assert!(codes.is_empty(), "{codes:?}");
    let (_, codes) = moves("fanuc", "G0 X[POW[2]]\nM30\n");
    assert_eq!(codes.first(), Some(&"syntax::malformed-expression"), "{codes:?}");
}

#[test]
fn an_operator_run_into_a_function_name_reads_as_both() {
    // Renishaw's O9029 on a Robodrill: `IF[#20NEFIX[#20]]GOTO700`, no blank between NE and FIX.
    let (out, codes) = moves("fanuc", "#20=2.5\nIF[#20NEFIX[#20]]GOTO7\nG0 X1.\nN7 G0 X[1EQABS[-1]]\nM30\n");
    assert_eq!(out.trim(), "STRAIGHT_TRAVERSE(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)", "{out}");
    assert!(codes.is_empty(), "{codes:?}");
    // A word that is no operator and function stays an error.
    let (_, codes) = moves("fanuc", "#1=1\nIF[#1NEFOO[#1]]GOTO7\nN7 M30\n");
    assert!(!codes.is_empty(), "{codes:?}");
}
#[test]
fn fix_and_fup_round_by_dialect() {
    let program = "G0 X[FIX[-1.2]] Y[FUP[-1.2]] Z[FIX[1.7]+FUP[1.2]]\nM30\n";
    let (fanuc, _) = moves("fanuc", program);
    assert!(fanuc.starts_with("STRAIGHT_TRAVERSE(-1.0000, -2.0000, 3.0000,"), "{fanuc}");
    let (lcnc, _) = moves("linuxcnc", program);
    assert!(lcnc.starts_with("STRAIGHT_TRAVERSE(-2.0000, -1.0000, 3.0000,"), "{lcnc}");
}

#[test]
fn fanuc_assigns_before_the_block_reads_and_linuxcnc_after() {
    let program = "#1=1.0\n#1=2.0 G0 X#1\nM30\n";
    let (fanuc, _) = moves("fanuc", program);
    assert!(fanuc.starts_with("STRAIGHT_TRAVERSE(2.0000,"), "{fanuc}");
    let (lcnc, _) = moves("linuxcnc", program);
    assert!(lcnc.starts_with("STRAIGHT_TRAVERSE(1.0000,"), "{lcnc}");
}

#[test]
fn vacant_variables_omit_words_and_compare_apart_from_zero() {
    let program = "\
G0 X1. Y1.
#1=#0
G0 X#1 Y5.
#2=#1+3.
G0 X#2
IF [#1 EQ #0] GOTO 20
G0 X99.
N20 IF [#1 EQ 0] GOTO 30
G0 Y7.
N30 #3=#[#2-1]
G0 Z#3
M30
";
    let (out, codes) = moves("fanuc", program);
    // X#1 with #1 vacant leaves X as it was; #1+3 reads vacant as zero; `EQ #0` is true and
    // `EQ 0` false; #[#2-1] is #2, which holds 3.
    expect![[r#"
        STRAIGHT_TRAVERSE(1.0000, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(1.0000, 5.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(3.0000, 5.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(3.0000, 7.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(3.0000, 7.0000, 3.0000, 0.0000, 0.0000, 0.0000)
    "#]]
    .assert_eq(&out);
    assert!(codes.is_empty(), "{codes:?}");
}

#[test]
fn while_do_end_loops_and_then_statements() {
    let program = "\
#1=0
WHILE [#1 LT 3] DO 1
  #2=0
  WHILE [#2 LT 2] DO 2
    G0 X#1 Y#2
    #2=#2+1
  END 2
  #1=#1+1
END 1
IF [#1 EQ 3] THEN #5=42.
G0 Z#5
M30
";
    let (out, codes) = moves("fanuc", program);
    assert_eq!(out.lines().count(), 7, "{out}");
    assert!(out.lines().nth(5).unwrap().starts_with("STRAIGHT_TRAVERSE(2.0000, 1.0000"), "{out}");
    assert!(out.ends_with("STRAIGHT_TRAVERSE(2.0000, 1.0000, 42.0000, 0.0000, 0.0000, 0.0000)\n"), "{out}");
    assert!(codes.is_empty(), "{codes:?}");
}

#[test]
fn g65_maps_argument_letters_to_locals_and_restores_the_caller() {
    let program = "\
O0001
#1=7.
G65 P9010 A1.5 B2. X3. L2
G0 Z#1
M30
O9010
G0 X[#1+#24] Y#2
#1=100.
M99
";
    let (out, codes) = moves("fanuc", program);
    // A→#1, B→#2, X→#24; the call runs twice; the caller's #1 is 7 again afterwards.
    expect![[r#"
        STRAIGHT_TRAVERSE(4.5000, 2.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(4.5000, 2.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(4.5000, 2.0000, 7.0000, 0.0000, 0.0000, 0.0000)
    "#]]
    .assert_eq(&out);
    assert!(codes.is_empty(), "{codes:?}");
}

#[test]
fn m98_repeats_a_subprogram_and_shares_variables() {
    let program = "\
#100=0
M98 P31000
G0 Z#100
M30
O1000
#100=#100+1
G91 G0 X10.
G90
M99
";
    // P31000: program 1000, three times (the digits above the fourth are the repeat count).
    let (out, codes) = moves("fanuc", program);
    expect![[r#"
        STRAIGHT_TRAVERSE(10.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(20.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(30.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(30.0000, 0.0000, 3.0000, 0.0000, 0.0000, 0.0000)
    "#]]
    .assert_eq(&out);
    assert!(codes.is_empty(), "{codes:?}");
}

struct OneProgram(&'static str, &'static str);

impl ProgramSource for OneProgram {
    fn load(&self, name: &str) -> Option<String> {
        (name == self.0).then(|| self.1.to_owned())
    }
}

#[test]
fn subprograms_come_from_the_program_source_and_report_in_their_own_file() {
    let d = Registry::shipped().get("fanuc").unwrap();
    let programs = OneProgram("O2000", "%\nO2000\nG0 X5.\nG0 Q1\nM99\n%\n");
    let mut canon = Vec::new();
    let main = "M98 P2000\nG0 Y1.\nM30\n";
    let diags = run(main, &d, &Profile::default(), &programs, &mut canon);
    expect![[r#"
        STRAIGHT_TRAVERSE(5.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(5.0000, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    "#]]
    .assert_eq(&render(&canon));
    // The finding inside O2000 points at the call and names the file, line and column.
    let unused = diags.iter().find(|d| d.code.as_str() == "syntax::unused-word").expect("unused Q");
    assert_eq!(unused.range.start, 0);
    assert!(unused.message.starts_with("in O2000:4:4:"), "{}", unused.message);
    // Ops from the subprogram carry the call block's range.
    assert_eq!(canon.iter().find(|c| matches!(c.op, CanonOp::StraightTraverse(_))).unwrap().line, 1);
}

#[test]
fn alarms_missing_labels_and_runaway_loops_stop_with_a_finding() {
    let (out, codes) = moves("fanuc", "G0 X1.\n#3000=12 (TOOL BROKEN)\nG0 X2.\nM30\n");
    assert_eq!(out.lines().count(), 1);
    assert_eq!(codes, ["interp::alarm"]);

    let (_, codes) = moves("fanuc", "GOTO 77\nM30\n");
    assert_eq!(codes, ["flow::missing-label"]);

    // A called program that is not here stops LinuxCNC, whose subroutines are files; a Fanuc
    // control may hold it in its memory: a warning, and the run goes on past the call.
    let (_, codes) = moves("linuxcnc", "M98 P4321\nG0 X1\nM30\n");
    assert_eq!(codes, ["flow::missing-label"]);
    let d = Registry::shipped().get("fanuc").unwrap();
    let mut canon = Vec::new();
    let diags = interpret("M98 P4321\nG0 X1.\nM30\n", &d, &Profile::default(), &mut canon);
    assert_eq!(render(&canon).lines().count(), 1, "the move after the call runs");
    assert_eq!(diags.iter().map(|d| (d.code.as_str(), d.is_error())).collect::<Vec<_>>(), [("flow::missing-program", false)]);
    assert!(diags[0].message.contains("the control may hold it in its memory"), "{}", diags[0].message);

    let profile = Profile { max_loop_iterations: 1000, ..Profile::default() };
    let (_, codes) = moves_with("fanuc", "WHILE [1 EQ 1] DO 1\nG0 X1.\nEND 1\nM30\n", &profile);
    assert_eq!(codes, ["flow::loop-limit"]);
    let (_, codes) = moves_with("fanuc", "N10 G0 X1.\nGOTO 10\n", &profile);
    assert_eq!(codes, ["flow::loop-limit"]);
    let (_, codes) = moves_with("linuxcnc", "o1 do\nG0 X1\no1 while [1]\nM2\n", &profile);
    assert_eq!(codes, ["flow::loop-limit"]);
    // Endless recursion stops at the call depth.
    let (_, codes) = moves("linuxcnc", "o<r> sub\no<r> call\no<r> endsub\no<r> call\nM2\n");
    assert_eq!(codes, ["flow::call-depth"]);
}

#[test]
fn unknown_statements_and_unmatched_ends_are_named() {
    let (_, codes) = moves("fanuc", "PRINTF\nEND 3\nM30\n");
    assert_eq!(codes, ["flow::unknown-statement", "flow::unmatched"]);
    let (_, codes) = moves("linuxcnc", "o5 endwhile\nM2\n");
    assert_eq!(codes, ["flow::unmatched"]);
}

#[test]
fn a_loop_reports_its_findings_once() {
    // `Q5` is 5 µm beside `X1.`, and no command here takes Q: each is said once, not fifty
    // times, and not counted fifty times towards the limit of a kind.
    let program = "#1=0\nWHILE [#1 LT 50] DO 1\nG0 X1. Q5\n#1=#1+1\nEND 1\nM30\n";
    let (_, codes) = moves("fanuc", program);
    assert_eq!(codes, ["interp::no-decimal-point", "syntax::unused-word"]);
}

#[test]
fn fanuc_rotation_and_scaling_move_the_toolpath() {
    let program = "\
G17 G90 G0 X10. Y0
G68 X0 Y0 R90.
G0 X10. Y0
G2 X0 Y-10. R10. F100.
G69
G51 X0 Y0 P2000
G0 X5. Y5.
G50
G0 X5. Y5.
M30
";
    let (out, codes) = moves("fanuc", program);
    // G68 turns X10 Y0 into X0 Y10 (and the arc with it); G51 P2000 doubles about the origin.
    expect![[r#"
        STRAIGHT_TRAVERSE(10.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(0.0000, 10.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        ARC_FEED(10.0000, 0.0000, 0.0000, 0.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.0000, 10.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(5.0000, 5.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    "#]]
    .assert_eq(&out.replace("-0.0000", "0.0000"));
    assert_eq!(codes, ["interp::cutting-without-technology"]);
}

#[test]
fn bin_and_bcd_convert_between_binary_and_packed_decimal() {
    // BCD[12] is 0x12 = 18; BIN[18] is 12; BIN of a non-BCD nibble is an error.
    let (out, codes) = moves("fanuc", "G0 X[BCD[12]] Y[BIN[18]] Z[BIN[BCD[9876]]]\nM30\n");
    assert!(out.starts_with("STRAIGHT_TRAVERSE(18.0000, 12.0000, 9876.0000,"), "{out}");
    assert!(codes.is_empty(), "{codes:?}");
    let (_, codes) = moves("fanuc", "G0 X[BIN[10]]\nM30\n");
    assert!(!codes.is_empty(), "0x0A is not BCD");
}

#[test]
fn g66_calls_the_macro_after_every_move_until_g67() {
    let program = "O1000\nS1000 M3\nG90 G00 X0 Y0 Z50.\nG66 P9100 Z-10. R2. F100.\nX10. Y10.\nX20.\nG67\nX30.\nM30\nO9100\nG01 Z#26 F#9\nG00 Z#18\nM99\n";
    let (out, codes) = moves("fanuc", program);
    expect![[r#"
        STRAIGHT_TRAVERSE(0.0000, 0.0000, 50.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.0000, 10.0000, 50.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(10.0000, 10.0000, -10.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.0000, 10.0000, 2.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(20.0000, 10.0000, 2.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(20.0000, 10.0000, -10.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(20.0000, 10.0000, 2.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(30.0000, 10.0000, 2.0000, 0.0000, 0.0000, 0.0000)
    "#]]
    .assert_eq(&out);
    assert!(codes.is_empty(), "{codes:?}");
}

#[test]
fn dprnt_prints_a_message_and_output_statements_are_accepted() {
    let d = Registry::shipped().get("fanuc").unwrap();
    let mut canon = Vec::new();
    let program = "#100=1.5\n#101=-12.25\nPOPEN\nDPRNT[X#100[53]*Y#101[44]*Z#102[2]]\nPCLOS\nSETVN 500[TOOL]\nM30\n";
    let diags = interpret(program, &d, &Profile::default(), &mut canon);
    assert!(diags.is_empty(), "{diags:?}");
    let messages: Vec<&str> = canon.iter().filter_map(|c| if let CanonOp::Message(m) = &c.op { Some(m.as_str()) } else { None }).collect();
    // #102 is vacant: blanks in its field.
    assert_eq!(messages, ["X     1.500 Y  -12.2500 Z   "]);
}

/// LinuxCNC's O-word return value: `#<_value>` is 0 before any call, each call resets it,
/// and `return [e]` or `endsub [e]` sets it with `#<_value_returned>`.
#[test]
fn a_subroutine_return_value_reaches_the_caller() {
    let program = "G0 X#<_value>\n\
                   o1 sub\no2 if [#1 GT 0]\no1 return [123*#1]\no2 endif\no1 endsub [4712]\n\
                   o1 call [2]\nG0 X#<_value> Y#<_value_returned>\n\
                   o1 call [0]\nG0 X#<_value>\nM2\n";
    let (moves, codes) = moves("linuxcnc", program);
    assert_eq!(codes, Vec::<&str>::new());
    expect![[r#"
        STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(246.0000, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(4712.0000, 1.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    "#]]
    .assert_eq(&moves);
}

/// `EXISTS[#1]` asks whether an index names a parameter; `EXISTS[##2]` reads the index first.
#[test]
fn exists_takes_numbered_parameters_too() {
    let (moves, codes) = moves("linuxcnc", "#<a>=1\n#2=99999\nG0 X EXISTS[#1] Y EXISTS[##2] Z EXISTS[#<a>] A EXISTS[#<b>]\nM2\n");
    assert_eq!(codes, Vec::<&str>::new());
    expect![[r#"
        STRAIGHT_TRAVERSE(1.0000, 0.0000, 1.0000, 0.0000, 0.0000, 0.0000)
    "#]]
    .assert_eq(&moves);
}

/// Centre-format arcs: LinuxCNC accepts a radius difference of 0.028 mm, and a larger one
/// below 0.1% of the radius (a spiral); the Fanuc dictionary keeps its 0.002 mm.
#[test]
fn arc_radius_tolerance_follows_the_dialect() {
    let spiral = "G21 G17 G90 F100\nG1 X0 Y0\nG2 X6000 I3001.4\nM2\n";
    let near = "G21 G17 G90 F100\nG1 X0 Y0\nG2 X20.02 I10\nM2\n";
    let (_, codes) = moves("linuxcnc", spiral);
    assert!(!codes.contains(&"interp::bad-arc"), "{codes:?}");
    let (_, codes) = moves("linuxcnc", near);
    assert!(!codes.contains(&"interp::bad-arc"), "{codes:?}");
    let (_, codes) = moves("linuxcnc", "G21 G17 G90 F100\nG1 X0 Y0\nG2 X20.1 I10\nM2\n");
    assert!(codes.contains(&"interp::bad-arc"), "0.1 mm on a 10 mm radius: {codes:?}");
    // Fanuc: 0.002 mm, or 2.83 of the steps the block is written in (0.01 here).
    let (_, codes) = moves("fanuc", "G21 G17 G90 F100 S1000 M3\nG1 X0 Y0\nG2 X20.05 I10.\nM30\n");
    assert!(codes.contains(&"interp::bad-arc"), "{codes:?}");
    let (_, codes) = moves("fanuc", "G21 G17 G90 F100 S1000 M3\nG1 X0 Y0\nG2 X20.02 I10.\nM30\n");
    assert!(!codes.contains(&"interp::bad-arc"), "{codes:?}");
}

/// LinuxCNC forms the canonical output has to follow: polar `@`/`^` words (in G91 they add
/// to the distance and angle about the origin), `G80` giving way to a motion code of its
/// group, a G0 without axis words moving in place, and `o#<n> call`.
#[test]
fn linuxcnc_polar_words_g80_with_motion_and_indirect_calls() {
    let program = "G20 G0 X1 Y0\nG91 G1 @-.0025 ^4.5 F10\nG90 G80 G0\nG0 @2 ^90\n\
                   o2 sub\nG0 X3\no2 endsub\n#<n>=2\no#<n> call\nM2\n";
    let (moves, codes) = moves("linuxcnc", program);
    assert_eq!(codes, ["interp::cutting-without-technology"]);
    expect![[r#"
        STRAIGHT_TRAVERSE(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(0.9944, 0.0783, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(0.9944, 0.0783, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(0.0000, 2.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(3.0000, 2.0000, 0.0000, 0.0000, 0.0000, 0.0000)
    "#]]
    .assert_eq(&moves);
    // Fanuc keeps G80 and G0 apart (its own group) and a bare G0 only sets the mode.
    let (fanuc, _) = self::moves("fanuc", "G0 X1.\nG80 G0\nM30\n");
    assert_eq!(fanuc.lines().count(), 1, "{fanuc}");
}

/// All calls except LinuxCNC's bookkeeping ones, and the diagnostic codes.
fn calls(program: &str) -> (String, Vec<&'static str>) {
    let d = Registry::shipped().get("linuxcnc").unwrap();
    let mut canon = Vec::new();
    let diags = interpret(program, &d, &Profile::default(), &mut canon);
    let mut out = String::new();
    for c in &canon {
        let mut line = String::new();
        write_call(&mut line, &c.op);
        if !ncplan::canon::LINUXCNC_INTERNAL.iter().any(|k| line.starts_with(&format!("{k}("))) && !line.is_empty() {
            out.push_str(&line);
        }
    }
    (out, diags.iter().map(|d| d.code.as_str()).collect())
}

/// Each case checked against LinuxCNC 2.9's `rs274`: R orients, P picks the way, Q waits;
/// a bare M19 does nothing there.
#[test]
fn m19_orients_the_spindle_as_rs274_does() {
    let (out, codes) = calls("S500 M3\nM19\nM19 R45 Q2\nM19 P1\nM19 R30 P2 Q3\nM19 Q1\nM2\n");
    assert!(codes.is_empty(), "{codes:?}");
    expect![[r#"
        SET_SPINDLE_SPEED(0, 500.0000)
        START_SPINDLE_CLOCKWISE(0)
        ORIENT_SPINDLE(0, 45.0000, 0)
        SPINDLE.0.WAIT_ORIENT_COMPLETE(2.0000)
        ORIENT_SPINDLE(0, 0.0000, 1)
        ORIENT_SPINDLE(0, 30.0000, 2)
        SPINDLE.0.WAIT_ORIENT_COMPLETE(3.0000)
        SPINDLE.0.WAIT_ORIENT_COMPLETE(1.0000)
        SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        SET_FEED_RATE(0.0000)
        STOP_SPINDLE_TURNING(0)
        PROGRAM_END()
    "#]]
    .assert_eq(&out);
    // rs274: "P value must be 0,1,or 2 with M19", "Q word with M19 requires a value > 0".
    assert_eq!(calls("M19 R10 P3\nM2\n").1, ["interp::bad-value"]);
    assert_eq!(calls("M19 R10 Q-1\nM2\n").1, ["interp::bad-value"]);
}

/// M70 saves, M72 restores only what changed, in rs274's order (units, feed, speed,
/// spindle, plane, system, distance, coolant); M73 in a subroutine restores at its return;
/// M71 forgets, after which M72 has nothing to restore. Checked against `rs274`.
#[test]
fn m70_to_m73_save_and_restore_the_modal_state() {
    let (out, codes) = calls(
        "G21 G17 G90 F100 S1000 M3 G54\nM70\nF5 S200 M7\nM8\nG91 G18 G55\nM72\nG1 X1\n\
         o10 sub\nM73\nG91 M9 M4\nG0 X1\no10 endsub\no10 call\nG0 X2\nM71\nM72\nM2\n",
    );
    assert_eq!(codes, ["flow::unmatched"]);
    expect![[r#"
        SET_FEED_RATE(100.0000)
        SET_SPINDLE_SPEED(0, 1000.0000)
        START_SPINDLE_CLOCKWISE(0)
        SELECT_PLANE(CANON_PLANE_XY)
        USE_LENGTH_UNITS(CANON_UNITS_MM)
        SET_FEED_RATE(5.0000)
        SET_SPINDLE_SPEED(0, 200.0000)
        MIST_ON()
        FLOOD_ON()
        SELECT_PLANE(CANON_PLANE_XZ)
        SET_G5X_OFFSET(2, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        SET_G92_OFFSET(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        SET_FEED_RATE(100.0000)
        SET_SPINDLE_SPEED(0, 1000.0000)
        MIST_OFF()
        FLOOD_OFF()
        SELECT_PLANE(CANON_PLANE_XY)
        SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        SET_G92_OFFSET(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        START_SPINDLE_COUNTERCLOCKWISE(0)
        MIST_OFF()
        FLOOD_OFF()
        STRAIGHT_TRAVERSE(2.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        START_SPINDLE_CLOCKWISE(0)
        STRAIGHT_TRAVERSE(2.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        SET_FEED_RATE(0.0000)
        STOP_SPINDLE_TURNING(0)
        PROGRAM_END()
    "#]]
    .assert_eq(&out);
}

/// LinuxCNC's G76 lathe threading cycle: an inside thread (I > 0) cut towards +Z with a
/// compound angle, tapers at both ends and one spring pass; then an outside thread with
/// the defaults. The expected calls are rs274's, byte for byte (its bookkeeping calls left
/// out); so are the three rejections.
#[test]
fn g76_threads_pass_by_pass_as_rs274_does() {
    let (out, codes) = calls("G21 G18\nS300 M4\nG0 X10 Z-20\nG76 P1.5 Z5 I1 J0.3 K0.9 Q30 H1 E2 L3\nG76 P1.5 Z-20 X12 I-1 J0.5 K1\nM2\n");
    assert!(codes.is_empty(), "{codes:?}");
    expect![[r#"
        SELECT_PLANE(CANON_PLANE_XZ)
        USE_LENGTH_UNITS(CANON_UNITS_MM)
        SET_SPINDLE_SPEED(0, 300.0000)
        START_SPINDLE_COUNTERCLOCKWISE(0)
        STRAIGHT_TRAVERSE(10.0000, 0.0000, -20.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(9.4000, 0.0000, -19.8268, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.644878,0)
        STRAIGHT_FEED(10.4000, 0.0000, -19.8268, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(11.3000, 0.0000, -17.8268, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.500000,0)
        STRAIGHT_FEED(11.3000, 0.0000, 2.6536, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.644878,0)
        STRAIGHT_FEED(10.4000, 0.0000, 4.6536, 0.0000, 0.0000, 0.0000)
        STOP_SPEED_FEED_SYNCH()
        STRAIGHT_TRAVERSE(9.4000, 0.0000, 4.6536, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(9.7000, 0.0000, -19.6536, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.644878,0)
        STRAIGHT_FEED(10.7000, 0.0000, -19.6536, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(11.6000, 0.0000, -17.6536, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.500000,0)
        STRAIGHT_FEED(11.6000, 0.0000, 2.8268, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.644878,0)
        STRAIGHT_FEED(10.7000, 0.0000, 4.8268, 0.0000, 0.0000, 0.0000)
        STOP_SPEED_FEED_SYNCH()
        STRAIGHT_TRAVERSE(9.7000, 0.0000, 4.8268, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.0000, 0.0000, -19.4804, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.644878,0)
        STRAIGHT_FEED(11.0000, 0.0000, -19.4804, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(11.9000, 0.0000, -17.4804, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.500000,0)
        STRAIGHT_FEED(11.9000, 0.0000, 3.0000, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.644878,0)
        STRAIGHT_FEED(11.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)
        STOP_SPEED_FEED_SYNCH()
        STRAIGHT_TRAVERSE(10.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.0000, 0.0000, -19.4804, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.644878,0)
        STRAIGHT_FEED(11.0000, 0.0000, -19.4804, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(11.9000, 0.0000, -17.4804, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.500000,0)
        STRAIGHT_FEED(11.9000, 0.0000, 3.0000, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.644878,0)
        STRAIGHT_FEED(11.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)
        STOP_SPEED_FEED_SYNCH()
        STRAIGHT_TRAVERSE(10.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.5000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(8.5000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.500000,0)
        STRAIGHT_FEED(8.5000, 0.0000, -20.0000, 0.0000, 0.0000, 0.0000)
        STOP_SPEED_FEED_SYNCH()
        STRAIGHT_TRAVERSE(10.5000, 0.0000, -20.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(8.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)
        START_SPEED_FEED_SYNC(1.500000,0)
        STRAIGHT_FEED(8.0000, 0.0000, -20.0000, 0.0000, 0.0000, 0.0000)
        STOP_SPEED_FEED_SYNCH()
        STRAIGHT_TRAVERSE(10.0000, 0.0000, -20.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(12.0000, 0.0000, -20.0000, 0.0000, 0.0000, 0.0000)
        SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        SELECT_PLANE(CANON_PLANE_XY)
        SET_FEED_RATE(0.0000)
        STOP_SPINDLE_TURNING(0)
        PROGRAM_END()
    "#]]
    .assert_eq(&out);
    for (block, message) in [("I0 J.1 K.5", "I, the offset"), ("I-1 J0 K.5", "J, the first"), ("I-1 J.5 K.5", "K, the full")] {
        let d = Registry::shipped().get("linuxcnc").unwrap();
        let mut canon = Vec::new();
        let diags = interpret(&format!("G18 S100 M3\nG0 X5 Z0\nG76 P1 Z-5 {block}\nM2\n"), &d, &Profile::default(), &mut canon);
        assert!(diags.iter().any(|d| d.code.as_str() == "interp::bad-value" && d.message.contains(message)), "{block}: {diags:?}");
    }
    // rs274: "Spindle not turning in G33", "Chosen spindle (0) not turning in G76".
    for program in ["G33 Z-1 K1\nM2\n", "G33.1 Z-1 K1\nM2\n", "G18 G76 P1 Z-5 I-1 J.2 K.5\nM2\n"] {
        let (out, codes) = calls(program);
        assert_eq!(codes, ["interp::cutting-without-technology"], "{program}");
        assert!(!out.contains("SYNC"), "{program}: {out}");
        let d = Registry::shipped().get("linuxcnc").unwrap();
        let diags = interpret(program, &d, &Profile::default(), &mut Vec::new());
        assert_eq!(diags[0].severity, ncplan::diag::Severity::Error, "{program}: the control stops");
    }
}

/// G38.2 to G38.5 probe towards a point with the probe on; the analysis goes on from the
/// programmed end point (where the probe touches only the machine knows), which the probe
/// result parameters then hold. rs274's rejections: no feed, compensation on, no length.
#[test]
fn probing_moves_and_their_results() {
    let (out, codes) = calls("G21 F100 S1000 M3\nG0 X1 Y2 Z3\nG38.2 Z-5\nG1 X#5061 Y#5063\nG38.5 X0\nM2\n");
    assert_eq!(codes, ["interp::unsupported", "interp::unsupported"]);
    expect![[r#"
        SET_FEED_RATE(100.0000)
        SET_SPINDLE_SPEED(0, 1000.0000)
        START_SPINDLE_CLOCKWISE(0)
        USE_LENGTH_UNITS(CANON_UNITS_MM)
        STRAIGHT_TRAVERSE(1.0000, 2.0000, 3.0000, 0.0000, 0.0000, 0.0000)
        TURN_PROBE_ON()
        STRAIGHT_PROBE(1.0000, 2.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        TURN_PROBE_OFF()
        STRAIGHT_FEED(1.0000, -5.0000, -4.7460, 0.0000, 0.0000, 0.0000)
        TURN_PROBE_ON()
        STRAIGHT_PROBE(0.0000, -5.0000, -4.7460, 0.0000, 0.0000, 0.0000)
        TURN_PROBE_OFF()
        SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        SET_FEED_RATE(0.0000)
        STOP_SPINDLE_TURNING(0)
        PROGRAM_END()
    "#]]
    .assert_eq(&out);
    for (program, code) in [
        ("G38.2 Z-1\nM2\n", "interp::no-feed"),
        ("F100 G0 Z1\nG38.2 Z1\nM2\n", "interp::bad-value"),
        ("F100 G41.1 D1 G1 X1\nG38.2 Z-1\nM2\n", "interp::bad-value"),
    ] {
        assert!(calls(program).1.contains(&code), "{program}: {:?}", calls(program).1);
    }
    // Whether the probe touched only the machine knows: a probing macro's check that aborts
    // when it did not takes the way a successful probe goes (a note, no error), and a loop
    // that probes until it touches ends, as under rs274's simulator.
    let (out, codes) = calls(
        "F100 G0 Z1\nG38.2 Z-1\no1 if [#5070 EQ 0]\n(abort, no contact)\no1 endif\n#1=0\n#5070=1\no2 while [#5070 NE 0]\n#1=[#1+1]\nG38.3 Z-2\no2 endwhile\nG0 X#1\nM2\n",
    );
    assert!(codes.iter().all(|c| *c == "interp::unsupported" || *c == "flow::unknown-condition"), "{codes:?}");
    assert!(out.contains("STRAIGHT_TRAVERSE(1.0000,"), "the loop ran once: {out}");
    // A quiet probe may have no length, as in rs274 (the tool stays where it is).
    let (out, codes) = calls("F100 G0 Z1\nG38.3 Z1\nG0 X1\nM2\n");
    assert!(codes.iter().all(|c| *c == "interp::unsupported"), "{codes:?}");
    assert!(out.contains("STRAIGHT_PROBE(0.0000, 0.0000, 1.0000") && out.contains("STRAIGHT_TRAVERSE(1.0000, 0.0000, 1.0000"), "{out}");
}

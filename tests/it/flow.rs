//! Control flow in the Siemens and Heidenhain dialects, by what it makes the machine do:
//! labels and jumps, structured statements without labels (nested by depth), counting and
//! repeat-until loops, calls by name with arguments and passes, Heidenhain label sections
//! and FN 9–12 jumps. The statements come from the dialect files; the engine is the one that
//! runs Fanuc Macro B and LinuxCNC O-words.

use std::collections::BTreeMap;

use ncplan::canon::{CanonOp, write_call};
use ncplan::dialect::Registry;
use ncplan::interp::{Profile, ProgramSource, run};

/// Programs by name, for calls that leave the file.
struct Programs(BTreeMap<&'static str, &'static str>);

impl ProgramSource for Programs {
    fn load(&self, name: &str) -> Option<String> {
        self.0.get(name).map(|s| (*s).to_owned())
    }
}

/// The X, Y and Z of every move, one `x y z` per line, and the diagnostic codes.
fn path(dialect: &str, program: &str, programs: &[(&'static str, &'static str)]) -> (String, Vec<&'static str>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut canon = Vec::new();
    let diags = run(program, &d, &Profile::default(), &Programs(programs.iter().copied().collect()), &mut canon);
    let mut out = String::new();
    for c in &canon {
        if let CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) = &c.op {
            out.push_str(&format!("{} {} {}\n", p[0], p[1], p[2]));
        } else if matches!(c.op, CanonOp::ArcFeed { .. }) {
            write_call(&mut out, &c.op);
        }
    }
    (out, diags.iter().filter(|d| d.severity == ncplan::diag::Severity::Error).map(|d| d.code.as_str()).collect())
}

#[test]
fn siemens_labels_jumps_and_nested_conditionals() {
    let program = "\
DEF INT CNT
R1=0
MARK1:
R1=R1+1
G1 X=R1 F100
IF R1<3 GOTOB MARK1
IF R1==3
  IF R1>5
    G1 Y99
  ELSE
    G1 Y1
  ENDIF
  G1 Y2
ELSE
  G1 Y98
ENDIF
GOTOF N90
G1 Z99
N90 G1 Z-1
GOTOC NOWHERE
GOTO ENDE
G1 Z98
ENDE:
M30
";
    let (out, errors) = path("siemens", program, &[]);
    assert_eq!(out, "1 0 0\n2 0 0\n3 0 0\n3 1 0\n3 2 0\n3 2 -1\n");
    assert!(errors.is_empty(), "{errors:?}");
}

#[test]
fn siemens_loops_count_and_test_at_either_end() {
    let program = "\
DEF INT CNT=0
WHILE CNT<2
  CNT=CNT+1
  G1 X=CNT F100
ENDWHILE
FOR R2=1 TO 3
  G1 Y=R2
ENDFOR
FOR R3=5 TO 4
  G1 Y99
ENDFOR
R4=0
REPEAT
  R4=R4+1
  G1 Z=-R4
UNTIL R4>=2
R5=0
LOOP
  R5=R5+1
  IF R5>1 GOTOF OUT
ENDLOOP
OUT:
G1 X=R5*10
M30
";
    let (out, errors) = path("siemens", program, &[]);
    assert_eq!(out, "1 0 0\n2 0 0\n2 1 0\n2 2 0\n2 3 0\n2 3 -1\n2 3 -2\n20 3 -2\n");
    assert!(errors.is_empty(), "{errors:?}");
}

#[test]
fn siemens_calls_by_name_with_arguments_and_passes() {
    let programs = [
        ("POCKET_A", "PROC POCKET_A(REAL DEPTH, INT N=2)\nG1 Z=-DEPTH X=N F100\nRET\n"),
        ("L123", "G91 G1 X1\nG90\nM17\n"),
        ("BARE", "G1 Y7 F100\n"),
    ];
    let program = "G0 X0 Y0 Z0\nPOCKET_A(1.5)\nPOCKET_A(2, 5)\nL123 P3\nCALL \"BARE\"\nM30\n";
    let (out, errors) = path("siemens", program, &programs);
    assert_eq!(out, "0 0 0\n2 0 -1.5\n5 0 -2\n6 0 -2\n7 0 -2\n8 0 -2\n8 7 -2\n");
    // BARE ends without M17 or RET: a finding, and the call still returns.
    assert_eq!(errors, ["flow::unmatched"]);
}

#[test]
fn siemens_unknown_names_and_labels_are_named() {
    // A name that is no program here may be one the control holds (a warning, issue 17 §2).
    let (_, errors) = path("siemens", "G0 X0\nFACE_MILL\nGOTOF NOWHERE\nG0 X1\nM30\n", &[]);
    assert_eq!(errors, ["flow::missing-label"]);
    // A subprogram checked on its own ends at its return.
    let (out, errors) = path("siemens", "G0 X1\nRET\nG0 X2\n", &[]);
    assert_eq!(out, "1 0 0\n");
    assert!(errors.is_empty(), "{errors:?}");
}

#[test]
fn heidenhain_labels_sections_and_fn_jumps() {
    let program = "\
0 BEGIN PGM FLOW MM
1 Q1 = 0
2 L X+0 Y+0 Z+0 R0 FMAX
3 LBL 1
4 Q1 = Q1 + 1
5 L X+Q1 F100
6 FN 12: IF +Q1 LT +3 GOTO LBL 1
7 CALL LBL \"SUB\" REP 1
8 LBL 3
9 L IY+1
10 CALL LBL 3 REP 2/2
11 FN 9: IF +0 EQU +0 GOTO LBL 4
12 L Z+99
13 LBL 4
14 CALL PGM TNC:\\PARTS\\OTHER.H
15 M30
16 LBL \"SUB\"
17 L IZ-1
18 LBL 0
19 END PGM FLOW MM
";
    let programs = [("OTHER.H", "0 BEGIN PGM OTHER MM\n1 L X+50\n2 END PGM OTHER MM\n")];
    let (out, errors) = path("heidenhain", program, &programs);
    assert_eq!(out, "0 0 0\n1 0 0\n2 0 0\n3 0 0\n3 0 -1\n3 0 -2\n3 1 -2\n3 2 -2\n3 3 -2\n50 3 -2\n");
    assert!(errors.is_empty(), "{errors:?}");
}

#[test]
fn heidenhain_missing_labels_stop_the_run() {
    let (out, errors) = path("heidenhain", "0 BEGIN PGM X MM\n1 L X+1 FMAX\n2 CALL LBL 7\n3 L X+2 FMAX\n4 END PGM X MM\n", &[]);
    assert_eq!(out, "1 0 0\n");
    assert_eq!(errors, ["flow::missing-label"]);
}

/// The error codes of `program` in `dialect`.
fn errors(dialect: &str, program: &str) -> Vec<&'static str> {
    path(dialect, program, &[]).1
}

#[test]
fn linuxcnc_requires_a_program_end_and_pairs_percent_lines_as_rs274_does() {
    // Each case as rs274 -g (LinuxCNC 2.9) judges it.
    let cases: &[(&str, &[&str])] = &[
        ("G0 X1\nM2\n", &[]),
        ("%\nG0 X1\n%\nG0 X2\n", &[]),
        ("\n%\nG0 X1\n%\n", &[]),
        // A file of subroutine definitions is a library, not a program run off its end.
        ("o<a> sub\nG0 X1\no<a> endsub\n", &[]),
        ("G0 X1\n", &["flow::no-program-end"]),
        ("%\nG0 X1\n", &["flow::no-program-end"]),
        ("G0 X1\n%\n", &["flow::unmatched"]),
        ("(first)\n%\nG0 X1\n%\n", &["flow::unmatched"]),
    ];
    for (program, want) in cases {
        assert_eq!(errors("linuxcnc", program), *want, "{program:?}");
    }
    // Tape format: `%` delimits wherever it stands, and no end code is required.
    assert_eq!(errors("fanuc", "G0 X1\n"), Vec::<&str>::new());
    assert_eq!(errors("fanuc", "G0 X1\n%\n"), Vec::<&str>::new());
}

#[test]
fn linuxcnc_rejects_unused_words_nested_definitions_and_aborts_on_a_comment() {
    assert_eq!(errors("linuxcnc", "G0 X1 R2\nM2\n"), ["syntax::unused-word"]);
    // Fanuc ignores the word, with a warning.
    assert_eq!(errors("fanuc", "G0 X1 R2\nM30\n"), Vec::<&str>::new());
    let nested = "o1 sub\no2 sub\nG0 X1\no2 endsub\no1 endsub\no1 call\nM2\n";
    assert!(errors("linuxcnc", nested).contains(&"flow::nested-definition"));
    let (moves, codes) = path("linuxcnc", "G0 X1\n( abort, no tool #1)\nG0 X2\nM2\n", &[]);
    assert_eq!((moves.as_str(), codes), ("1 0 0\n", vec!["interp::alarm"]));
    // `(ABORT ,` is an ordinary comment, as in rs274.
    assert_eq!(errors("linuxcnc", "(ABORT ,x)\nG0 X1\nM2\n"), Vec::<&str>::new());
}

#[test]
fn cutting_at_zero_feed_is_an_error_everywhere_but_a_stopped_spindle_only_a_warning() {
    for (dialect, end) in [("linuxcnc", "M2"), ("fanuc", "M30"), ("siemens", "M30")] {
        assert_eq!(errors(dialect, &format!("G1 X1\n{end}\n")), ["interp::no-feed"], "{dialect}");
        assert_eq!(errors(dialect, &format!("G1 X1 F100\n{end}\n")), Vec::<&str>::new(), "{dialect}");
    }
    // Inverse time: each move's own F.
    assert_eq!(errors("linuxcnc", "G93 G1 X1 F30\nM2\n"), Vec::<&str>::new());
}

#[test]
fn siemens_synchronized_actions_and_interrupts_are_named_and_kept_out_of_the_toolpath() {
    let d = Registry::shipped().get("siemens").unwrap();
    let program = "N10 WHENEVER $A_IN[1] DO OVR=0\nN20 SETINT(1) PRIO=4 ALARM\nN30 STOPRE\nN40 G0 X10\n\
                   N42 DEFINE RAPID AS G0 ; a macro\nN44 ISOCALL \"L320\"\nN50 M30\n";
    let mut canon = Vec::new();
    let diags = run(program, &d, &Profile::default(), &Programs(BTreeMap::new()), &mut canon);
    let found: Vec<(&str, &str)> = diags.iter().map(|d| (d.code.as_str(), d.message.as_str())).collect();
    assert_eq!(
        found,
        [
            ("interp::unsupported", "`WHENEVER $A_IN[1] DO OVR=0` is not simulated; it was skipped"),
            ("interp::unsupported", "`SETINT(1) PRIO=4 ALARM` is not simulated; it was skipped"),
            ("interp::unsupported", "`DEFINE RAPID AS G0` is not simulated; it was skipped"),
            ("interp::unsupported", "`ISOCALL \"L320\"` is not simulated; it was skipped"),
        ]
    );
    assert_eq!(path("siemens", program, &[]).0, "10 0 0\n");
}

/// 840D section repeats: `REPEAT A B P=n` runs the blocks from label A through label B n
/// more times, `REPEAT A P=n` the blocks from A up to the statement, `REPEATB A P=n` the
/// block with A alone; then the run goes on after the statement. A bare `REPEAT` still
/// opens a REPEAT ... UNTIL loop.
#[test]
fn siemens_section_repeats() {
    let program = "\
G0 X0 Y0 Z0
ANF: G1 X1 F100
G1 Y1
ENDE: G1 Z1
G1 Z9
REPEAT ANF ENDE P=2
BOHR: G0 X5
G0 X6
REPEAT BOHR P = 1
REPEATB BOHR
R1=0
REPEAT
R1=R1+1
G1 Y=R1
UNTIL R1>=2
REPEAT NOWHERE
M30
";
    let (path, errors) = path("siemens", program, &[]);
    assert_eq!(
        path,
        "0 0 0\n1 0 0\n1 1 0\n1 1 1\n1 1 9\n\
         1 1 9\n1 1 9\n1 1 1\n1 1 1\n1 1 1\n1 1 1\n\
         5 1 1\n6 1 1\n5 1 1\n6 1 1\n5 1 1\n\
         5 1 1\n5 2 1\n"
    );
    assert_eq!(errors, ["flow::missing-label"]);
}

/// `CASE` jumps by value, to `DEFAULT` without a match, and on past the block when there
/// is neither.
#[test]
fn siemens_case_jumps_by_value() {
    let case = |r1: u32, default: bool| {
        let program = format!(
            "R1={r1}\nCASE R1 OF 1 GOTOF ONE 2 GOTOF TWO{}\nG1 X9 F100\nONE: G1 X1 F100\nTWO: G1 Y2 F100\nOTHER: G1 Z3 F100\nM30\n",
            if default { " DEFAULT GOTOF OTHER ; note" } else { "" }
        );
        let (path, errors) = path("siemens", &program, &[]);
        assert!(errors.is_empty(), "{errors:?}");
        path
    };
    assert_eq!(case(1, true), "1 0 0\n1 2 0\n1 2 3\n");
    assert_eq!(case(2, true), "0 2 0\n0 2 3\n");
    assert_eq!(case(7, true), "0 0 3\n");
    assert_eq!(case(7, false), "9 0 0\n1 0 0\n1 2 0\n1 2 3\n");
}

#[test]
fn blanks_inside_an_o_word_keyword_do_not_count_as_in_rs274() {
    // rs274 -g (LinuxCNC 2.9) runs this program to X1 then X1 Y2.
    let program = "o1 sub\nG0 X1\no1 end sub\no1 call\n#1=2\no2 if [#1 EQ 1]\nG0 Y1\n\
                   o2 else if [#1 EQ 2]\nG0 Y2\no2 end if\nM2\n";
    let (moves, codes) = path("linuxcnc", program, &[]);
    assert_eq!((moves.as_str(), codes), ("1 0 0\n1 2 0\n", vec![]));
}

#[test]
fn a_loop_that_changes_nothing_stops_at_once_and_one_that_moves_on_runs_out() {
    // Nothing changes from round to round: the control would run for ever.
    let (moves, codes) = path("fanuc", "#1=0\nWHILE [#1 LT 5] DO 1\nG0 X#1\nEND 1\nM30\n", &[]);
    assert_eq!((moves.as_str(), codes), ("0 0 0\n0 0 0\n0 0 0\n", vec!["flow::loop-limit"]));
    // A parameter changes and changes back within each round, as Q1940 does in a spiral
    // that cannot grow: the rounds still end alike.
    let spiral = "#2=0\nN10 #1=5\n#1=[#1-#2]\nG0 X#1\nIF [#1 LT 0] GOTO 20\nGOTO 10\nN20 M30\n";
    let (_, codes) = path("fanuc", spiral, &[]);
    assert_eq!(codes, ["flow::loop-limit"]);
    // The same loops with progress run to their end.
    let (moves, codes) = path("fanuc", "#1=0\nWHILE [#1 LT 3] DO 1\nG0 X#1\n#1=#1+1\nEND 1\nM30\n", &[]);
    assert_eq!((moves.as_str(), codes), ("0 0 0\n1 0 0\n2 0 0\n", vec![]));
    // Only the position moves on, read back through #5420 in the condition (rs274 -g: X1,
    // X2, X3): no parameter of the program's own changes from round to round, yet it ends.
    let program = "o1 while [1]\nG91 G0 X1\no2 if [#5420 GE 3]\no1 break\no2 endif\no1 endwhile\nM2\n";
    let (moves, codes) = path("linuxcnc", program, &[]);
    assert_eq!((moves.as_str(), codes), ("1 0 0\n2 0 0\n3 0 0\n", vec![]));
}

/// Sinumerik checks the nesting of its control structures (alarm 12640): an `ENDIF` with no
/// `IF`, an end of another structure than the one open, or a structure never closed is an
/// error where the run meets it (a warning where the run never comes); one-line `IF … GOTOF` and `REPEAT` of a section open
/// nothing, and a well-nested program has no such finding. Dialects whose dictionary does
/// not say so (`checks-nesting`) are not read this way.
#[test]
fn siemens_control_structure_nesting_is_checked() {
    let nesting = |dialect: &str, program: &str| -> Vec<String> {
        let (_, diags) = crate::moves_and_findings(dialect, program, &ncplan::interp::Profile::default());
        diags.iter().filter(|d| d.code.as_str() == "flow::unmatched" && d.message.contains("nesting")).map(|d| d.message.clone()).collect()
    };
    let good = "\
DEF INT CNT=0
IF R1>0 GOTOF SKIP
WHILE CNT<2
  IF CNT==1
    G1 X1 F100
  ELSE
    G1 X2 F100
  ENDIF
  FOR R2=1 TO 2
    REPEAT
      R3=R3+1
    UNTIL R3>2
  ENDFOR
  LOOP
    GOTOF OUT
  ENDLOOP
  OUT:
  CNT=CNT+1
ENDWHILE
SKIP:
M30
";
    assert!(nesting("siemens", good).is_empty(), "{:?}", nesting("siemens", good));
    let stray = good.replace("  OUT:\n", "  OUT:\n  ENDIF\n");
    let found = nesting("siemens", &stray);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].starts_with("`ENDIF` where the open structure ends with `ENDWHILE`"), "{found:?}");
    let unclosed = good.replace("  ENDIF\n", "");
    let found = nesting("siemens", &unclosed);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].contains("ENDIF") || found[0].contains("ENDWHILE"), "{found:?}");
    let never = "IF R1>0\nG1 X1 F100\nM30\n";
    assert_eq!(nesting("siemens", never).len(), 1);
    // Not in the branch the run takes: still the control's alarm.
    let untaken = "R1=0\nIF R1>0 GOTOF SKIP\nG0 X0\nSKIP:\nENDIF\nM30\n";
    assert_eq!(nesting("siemens", untaken).len(), 1);
    // A dictionary that does not check nesting reads no such error.
    assert!(nesting("linuxcnc", "G0 X0\nM2\n").is_empty());
}

/// In interpreter mode the 840D sl checks the block structure only as far as it runs
/// (job planning, Arbeitsvorbereitung 02/2011, p.107): a stray `ENDIF` a `GOTOF` jumps over is
/// a warning, not an error, and the moves after it run; one fault the run meets
/// (`WHILE` … `ENDFOR`) is one error, not two.
#[test]
fn siemens_nesting_faults_are_errors_where_the_run_meets_them_once() {
    let findings = |program: &str| {
        let (moves, diags) = crate::moves_and_findings("siemens", program, &ncplan::interp::Profile::default());
        let unmatched: Vec<(bool, String)> =
            diags.iter().filter(|d| d.code.as_str() == "flow::unmatched").map(|d| (d.is_error(), d.message.clone())).collect();
        (moves, unmatched)
    };
    let jumped = "N10 G0 X0 Y0 Z0\nN20 GOTOF WEITER\nN30 ENDIF\nWEITER:\nN40 G1 X10 F100 S1000 M3\nN50 M30\n";
    let (moves, found) = findings(jumped);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(!found[0].0 && found[0].1.contains("no run reaches"), "{found:?}");
    assert!(moves.iter().any(|m| m.starts_with("STRAIGHT_FEED(10.0000")), "{moves:?}");
    let mistyped = "N10 G0 X0 Y0 Z0\nN20 R1=1\nN30 WHILE R1<3\nN40 R1=R1+1\nN50 ENDFOR\nN70 M30\n";
    let (_, found) = findings(mistyped);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].0, "{found:?}");
}

/// Nesting deeper than the check records (256) still pairs each end with its structure:
/// 300 `IF`s closed by 300 `ENDIF`s are well nested, and one `ENDIF` more is the fault.
#[test]
fn siemens_nesting_past_the_recorded_depth_stays_paired() {
    let nesting = |program: &str| -> usize {
        let (_, diags) = crate::moves_and_findings("siemens", program, &ncplan::interp::Profile::default());
        diags.iter().filter(|d| d.code.as_str() == "flow::unmatched" && d.message.contains("nesting")).count()
    };
    let deep = format!("R1=1\n{}G1 X1 F100\n{}M30\n", "IF R1>0\n".repeat(300), "ENDIF\n".repeat(300));
    assert_eq!(nesting(&deep), 0);
    let extra = format!("R1=1\n{}G1 X1 F100\n{}M30\n", "IF R1>0\n".repeat(300), "ENDIF\n".repeat(301));
    assert_eq!(nesting(&extra), 1);
}

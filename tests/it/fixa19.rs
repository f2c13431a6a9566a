//! Translation safety where the reading of source and output could agree on a wrong motion
//! (task fixa19): Fanuc back boring (`G87`) goes down to R only with the bar shifted and the
//! spindle oriented, and fine and back boring, whose shift direction the control's parameters
//! set, are never written as moves; a called program not found, an error in the reading, a
//! LinuxCNC stored parameter (the G54 offset `#5221`) and a return to a reference position the
//! program taught (`G28.1`) refuse the translation; a return with no axis words names no
//! rotary axis the program never used.

use ncplan::canon::{Canon, CanonOp, MachineTarget};
use ncplan::diag::Diagnostic;
use ncplan::interp::Profile;

use crate::translate::{dialect, translate};

fn canon(d: &str, program: &str) -> (Vec<Canon>, Vec<Diagnostic>) {
    let mut out: Vec<Canon> = Vec::new();
    let diags = ncplan::interp::interpret(program, &dialect(d), &Profile::default(), &mut out);
    (out, diags)
}

/// The codes of the errors of a translation, each with the text it stands at.
fn refusals(program: &str, diags: &[Diagnostic]) -> Vec<(String, String)> {
    diags
        .iter()
        .filter(|d| d.is_error())
        .map(|d| (d.code.as_str().to_owned(), program.get(d.range.start as usize..d.range.end as usize).unwrap_or("").to_owned()))
        .collect()
}

const G87: &str = "%\nO1000\nG21 G17 G40 G49 G80 G90\nT1 M6\nG54 G0 X0. Y0. S1000 M3\nG43 H1 Z10.\nG98 G87 X10. Y10. Z-10. R-15. Q1. F100.\nG80\nG0 Z50.\nM30\n%\n";

#[test]
fn fanuc_back_boring_goes_down_to_r_only_shifted_with_the_spindle_oriented() {
    let (c, _) = canon("fanuc", G87);
    let at = c.iter().position(|c| matches!(c.op, CanonOp::CycleBegin(_))).unwrap();
    let end = c.iter().position(|c| matches!(c.op, CanonOp::CycleEnd)).unwrap();
    let ops: Vec<&CanonOp> = c[at + 1..end].iter().map(|c| &c.op).filter(|o| !matches!(o, CanonOp::Known(_))).collect();
    // Every move below the initial level (Z10) before the spindle turns again is off the hole's
    // centre by the shift (X11), made with the spindle oriented, never turning.
    let mut oriented = false;
    let mut turning = true;
    let mut z = 10.0;
    for op in &ops {
        match op {
            CanonOp::OrientSpindle { .. } => (oriented, turning) = (true, false),
            CanonOp::StopSpindleTurning => panic!("back boring stops the spindle oriented, not anyhow: {ops:?}"),
            CanonOp::StartSpindleClockwise => turning = true,
            CanonOp::StraightTraverse(p) if p[2] < z => {
                // Down through the bore: shifted, the spindle oriented.
                assert!(!turning && (p[0] - 11.0).abs() < 1e-9, "down to R unshifted or turning: {p:?} in {ops:?}");
                z = p[2];
            }
            _ => {}
        }
        if let CanonOp::StraightFeed(p) = op {
            // The cut: up from R (-15) to Z (-10) on the hole's centre, the spindle turning.
            assert!(turning && (p[0] - 10.0).abs() < 1e-9 && p[2] == -10.0, "{p:?} in {ops:?}");
            break;
        }
    }
    assert!(oriented, "{ops:?}");
}

#[test]
fn fine_and_back_boring_are_never_written_as_moves_with_an_unstated_shift() {
    let g76 = "%\nO1000\nG21 G17 G40 G49 G80 G90\nT1 M6\nG54 G0 X0. Y0. S1000 M3\nG43 H1 Z10.\nG99 G76 X10. Y10. Z-10. R2. Q0.5 F100.\nG80\nG0 Z50.\nM30\n%\n";
    for (program, code) in [(G87, "G98 G87"), (g76, "G99 G76")] {
        for to in ["haas", "linuxcnc", "siemens", "heidenhain"] {
            let (text, diags) = translate(program, &dialect("fanuc"), &dialect(to), "O1000");
            let r = refusals(program, &diags);
            assert!(r.iter().any(|(c, at)| c == "post::motion-unknown" && at.starts_with(code)), "fanuc → {to}: {r:?}\n{text}");
        }
    }
    // The reading orients the spindle in fine boring too.
    let (c, _) = canon("fanuc", g76);
    let at = c.iter().position(|c| matches!(c.op, CanonOp::CycleBegin(_))).unwrap();
    let end = c.iter().position(|c| matches!(c.op, CanonOp::CycleEnd)).unwrap();
    assert!(c[at..end].iter().any(|c| matches!(c.op, CanonOp::OrientSpindle { .. })));
    assert!(!c[at..end].iter().any(|c| matches!(c.op, CanonOp::StopSpindleTurning)));
}

#[test]
fn a_called_program_not_found_refuses_the_translation_at_the_call() {
    let cases = [
        (
            "fanuc",
            "%\nO1000\nG21 G17 G90\nT1 M6\nG54 G0 X0. Y0. S1000 M3\nG43 H1 Z10.\nM98 P9001\nG1 X20. F100.\nM30\n%\n",
            "M98 P9001",
            "haas",
        ),
        (
            "haas",
            "%\nO1000\nG20 G17 G90\nT1 M6\nG54 G0 X0. Y0. S1000 M3\nG43 H1 Z1.\nG65 P9010 A1.\nG0 Z2.\nM30\n%\n",
            "G65 P9010",
            "fanuc",
        ),
        ("siemens", "G17 G90 G71\nT1 D1\nM6\nG54 G0 X0 Y0 S1000 M3\nZ10\nL100 P3\nG1 X20 F100\nM30\n", "L100 P3", "fanuc"),
        (
            "heidenhain",
            "0 BEGIN PGM MAIN MM\n1 TOOL CALL 1 Z S1000\n2 L Z+10 R0 FMAX M3\n3 CALL PGM SUB1\n4 L X+20 R0 F100\n5 END PGM MAIN MM\n",
            "CALL PGM SUB1",
            "fanuc",
        ),
    ];
    for (from, program, call, to) in cases {
        let (text, diags) = translate(program, &dialect(from), &dialect(to), "O1000");
        let r = refusals(program, &diags);
        assert!(r.iter().any(|(c, at)| c == "post::motion-unknown" && at.contains(call)), "{from} → {to}: {r:?}\n{text}");
    }
}

#[test]
fn an_error_in_the_reading_refuses_the_translation() {
    // The arc's radii differ (3 from its start, 7 at its end): LinuxCNC stops there.
    let program =
        "G21 G17 G40 G49 G80 G90 G94\nT1 M6\nG54 G0 X0 Y0 S1000 M3\nG43 H1 Z10\nG1 Z-1 F100\nG2 X10 Y0 I3 J0\nG1 X20 Y5\nG0 Z50\nM2\n";
    let (text, diags) = translate(program, &dialect("linuxcnc"), &dialect("fanuc"), "O1000");
    let r = refusals(program, &diags);
    assert!(r.iter().any(|(c, at)| c == "post::source-error" && at.contains("G2")), "{r:?}\n{text}");
}

#[test]
fn a_linuxcnc_stored_parameter_is_unknown_unless_the_program_sets_it() {
    let unset = "G21 G17 G90\nT1 M6\nG54 G0 X0 Y0 S1000 M3\nG43 H1 Z10\nG0 X[#5221+1]\nG0 Z50\nM2\n";
    let (text, diags) = translate(unset, &dialect("linuxcnc"), &dialect("fanuc"), "O1000");
    let r = refusals(unset, &diags);
    assert!(r.iter().any(|(c, at)| c == "post::motion-unknown" && at.contains("#5221")), "{r:?}\n{text}");
    // Set by the program, it is known: the move is written.
    let set = "G21 G17 G90\nT1 M6\nG54 G0 X0 Y0 S1000 M3\nG43 H1 Z10\n#5221=2\nG0 X[#5221+1]\nG0 Z50\nM2\n";
    let (text, diags) = translate(set, &dialect("linuxcnc"), &dialect("fanuc"), "O1000");
    assert!(refusals(set, &diags).is_empty(), "{diags:?}");
    assert!(text.lines().any(|l| l.contains("X3.")), "{text}");
    // A user parameter (#31-#5000) is the program's own: vacant, read as 0.
    let user = "G21 G17 G90\nT1 M6\nG54 G0 X0 Y0 S1000 M3\nG43 H1 Z10\nG0 X[#100+1]\nG0 Z50\nM2\n";
    let (_, diags) = translate(user, &dialect("linuxcnc"), &dialect("fanuc"), "O1000");
    assert!(refusals(user, &diags).is_empty(), "{diags:?}");
}

#[test]
fn a_return_to_a_taught_reference_position_is_refused_and_a_bare_return_names_no_unused_axis() {
    let taught =
        "G21 G17 G40 G49 G80 G90 G94\nT1 M6\nG54 G0 X0 Y0 S1000 M3\nG43 H1 Z10\nG0 X5 Y5\nG28.1\nG0 X20 Y20\nG28\nG0 X1 Y1\nG0 Z50\nM2\n";
    let (text, diags) = translate(taught, &dialect("linuxcnc"), &dialect("fanuc"), "O1000");
    let r = refusals(taught, &diags);
    assert!(r.iter().any(|(c, at)| c == "post::motion-unknown" && at == "G28"), "{r:?}\n{text}");
    // Without G28.1 the return is the machine's own, written with the axes the program has.
    let bare = "G21 G17 G40 G49 G80 G90 G94\nT1 M6\nG54 G0 X0 Y0 S1000 M3\nG43 H1 Z10\nG0 X20 Y20\nG28\nG0 X1 Y1\nG0 Z50\nM2\n";
    let (c, _) = canon("linuxcnc", bare);
    let axes = c.iter().find_map(|c| match &c.op {
        CanonOp::MachineMove(m) if m.target == MachineTarget::Reference(1) => Some(m.axes),
        _ => None,
    });
    assert_eq!(axes, Some([Some(0.0), Some(0.0), Some(0.0), None, None, None]));
    let (text, diags) = translate(bare, &dialect("linuxcnc"), &dialect("fanuc"), "O1000");
    assert!(refusals(bare, &diags).is_empty(), "{diags:?}\n{text}");
    let home = text.lines().find(|l| l.contains("G28")).unwrap_or_default();
    assert!(home.contains("X0. Y0. Z0.") && !home.contains('A') && !home.contains('B') && !home.contains('C'), "{text}");
    // A program that turns A: its bare return homes A too.
    let rotary = "G21 G17 G90\nT1 M6\nG54 G0 X0 Y0 A30 S1000 M3\nG43 H1 Z10\nG28\nM2\n";
    let (c, _) = canon("linuxcnc", rotary);
    let axes = c.iter().find_map(|c| match &c.op {
        CanonOp::MachineMove(m) => Some(m.axes),
        _ => None,
    });
    assert_eq!(axes, Some([Some(0.0), Some(0.0), Some(0.0), Some(0.0), None, None]));
}

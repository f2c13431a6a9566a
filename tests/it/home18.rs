//! Moves read as what the control does with them, not as a look-alike (task home18): SINUMERIK
//! `G74`/`G75` go straight to the reference or fixed point (no intermediate point), Heidenhain
//! `M92` is a position from the machine builder's datum (no `G53` reaches it), Centroid `M25`
//! is Z straight home, Fanuc `G16` makes X and Y a radius and an angle, a move whose value is
//! unknown (`FN 18: SYSREAD`) is never written, and a target whose output rules would be
//! another dialect's refuses.

use ncplan::canon::{Canon, CanonOp, MachineTarget};
use ncplan::diag::Diagnostic;
use ncplan::interp::Profile;
use ncplan::proof::{self, Trace};

use crate::translate::{dialect, translate};

fn canon(d: &str, program: &str) -> (Vec<Canon>, Vec<Diagnostic>) {
    let mut out: Vec<Canon> = Vec::new();
    let diags = ncplan::interp::interpret(program, &dialect(d), &Profile::default(), &mut out);
    (out, diags)
}

/// The machine-frame markers of a stream, each with the number of traverses up to the next
/// marker or move of another kind.
fn markers(c: &[Canon]) -> Vec<(MachineTarget, [Option<f64>; 6])> {
    c.iter()
        .filter_map(|c| match &c.op {
            CanonOp::MachineMove(m) => Some((m.target, m.axes)),
            _ => None,
        })
        .collect()
}

fn errors(diags: &[Diagnostic]) -> Vec<String> {
    diags.iter().filter(|d| d.is_error()).map(|d| format!("{}:{} {} {}", d.range.start, d.range.end, d.code.as_str(), d.message)).collect()
}

/// The translation, read back in `to`, runs as the source does.
fn runs_the_same(from: &str, source: &str, to: &str, translated: &str) {
    let (a, _) = canon(from, source);
    let (b, diags) = canon(to, translated);
    assert!(errors(&diags).is_empty(), "{diags:?}\n{translated}");
    let (ta, tb) = (Trace::of(&a, 0.001), Trace::of(&b, 0.001));
    assert!(proof::difference(&ta, &tb, 0.001).is_none(), "{:?}\n{translated}", proof::difference(&ta, &tb, 0.001).map(|d| d.to_string()));
}

const G74: &str = "N10 G90 G0 X50 Z20\nN20 G74 X1=0 Z1=0\nN30 G0 X40 Z10\nN40 G1 X30 F100\nN50 G74 Z1=0\nN60 M30\n";

#[test]
fn siemens_g74_goes_straight_to_the_reference_point_in_the_axes_it_names() {
    let (c, diags) = canon("siemens", G74);
    assert!(errors(&diags).is_empty(), "{diags:?}");
    let m = markers(&c);
    // X1=0 Z1=0 name X and Z (machine axis names): those two, not every axis.
    assert_eq!(m[0], (MachineTarget::Direct(1), [Some(0.0), None, Some(0.0), None, None, None]));
    assert_eq!(m[1], (MachineTarget::Direct(1), [None, None, Some(0.0), None, None, None]));
    // One traverse after the marker: no intermediate point at X0 Z0 (the values are ignored).
    let at = c.iter().position(|c| matches!(c.op, CanonOp::MachineMove(_))).unwrap();
    assert!(matches!(c[at + 1].op, CanonOp::StraightTraverse(_)), "{:?}", c[at + 1]);
    // The next move (past the markers of the axes known again) is the program's own.
    let next = c[at + 2..].iter().find(|c| !matches!(c.op, CanonOp::Known(_))).unwrap();
    assert!(matches!(next.op, CanonOp::StraightTraverse(p) if p[0] == 40.0 && p[2] == 10.0), "{next:?}");
}

/// Outside G74/G75 a machine axis name (`X1=10`) is read as its axis, said and refused:
/// whether the value is the machine's frame is the machine's configuration.
#[test]
fn a_machine_axis_name_outside_g74_is_said() {
    let (_, diags) = canon("siemens", "N10 G0 X1=10 Z1=5\nN20 M30\n");
    assert!(diags.iter().any(|d| d.code.as_str() == "interp::motion-unknown" && d.message.contains("X1=10")), "{diags:?}");
    let (_, diags) = canon("siemens", G74);
    assert!(diags.iter().all(|d| d.code.as_str() != "interp::motion-unknown"), "{diags:?}");
    let (_, diags) = canon("siemens", "N10 G0 C4=120\nN20 M30\n");
    assert!(diags.iter().all(|d| d.code.as_str() != "interp::motion-unknown"), "{diags:?}");
}

#[test]
fn siemens_g74_translates_to_a_return_through_the_current_position() {
    let (fanuc, diags) = translate(G74, &dialect("siemens"), &dialect("fanuc"), "P1");
    assert!(errors(&diags).is_empty(), "{diags:?}");
    let lines: Vec<&str> = fanuc.lines().collect();
    assert!(lines.contains(&"G91 G28 X0. Z0."), "{fanuc}");
    assert!(lines.contains(&"G91 G28 Z0."), "{fanuc}");
    assert!(!fanuc.contains("Y0.") && !fanuc.contains("A0."), "only the axes named return: {fanuc}");
    runs_the_same("siemens", G74, "fanuc", &fanuc);
}

#[test]
fn siemens_g75_goes_to_fixed_point_n_and_is_refused_where_no_target_says_it() {
    let src = "N10 G90 G0 X50 Z20\nN20 G75 FP=2 X1=0 Z1=0\nN30 G75 Z1=0\nN40 M30\n";
    let (c, diags) = canon("siemens", src);
    assert!(errors(&diags).is_empty(), "{diags:?}");
    let m = markers(&c);
    assert_eq!(m[0].0, MachineTarget::Fixed(2));
    assert_eq!(m[1], (MachineTarget::Fixed(1), [None, None, Some(0.0), None, None, None]));
    // A fixed point is not Fanuc's second reference position: no G30, refused.
    let (fanuc, diags) = translate(src, &dialect("siemens"), &dialect("fanuc"), "P1");
    let e = errors(&diags);
    assert!(e.iter().any(|e| e.contains("post::unwritable") && e.contains("fixed point 2")), "{e:?}");
    assert!(!fanuc.contains("G30"), "{fanuc}");
}

#[test]
fn fanuc_g30_p3_is_the_third_reference_position_not_the_second() {
    let src = "G90 G0 X10 Y10 Z10\nG91 G30 P3 Z0\nG90\nM30\n";
    let (c, _) = canon("fanuc", src);
    assert_eq!(markers(&c)[0].0, MachineTarget::Reference(3));
    let (_, diags) = translate(src, &dialect("fanuc"), &dialect("linuxcnc"), "P1");
    assert!(errors(&diags).iter().any(|e| e.contains("reference position 3")), "{diags:?}");
    // G30 alone stays the second.
    let (c, _) = canon("fanuc", "G90 G0 X10 Y10 Z10\nG91 G30 Z0\nG90\nM30\n");
    assert_eq!(markers(&c)[0].0, MachineTarget::Reference(2));
}

const M92: &str =
    "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000\n2 L X+10 Y+10 Z+5 R0 FMAX M3\n3 L Z+50 R0 FMAX M92\n4 L X+0 Y+0 FMAX\n5 END PGM T MM\n";

#[test]
fn heidenhain_m92_is_the_machine_builders_datum_not_g53() {
    let (c, diags) = canon("heidenhain", M92);
    assert!(errors(&diags).is_empty(), "{diags:?}");
    assert_eq!(markers(&c), vec![(MachineTarget::Builder, [None, None, Some(50.0), None, None, None])]);
    for to in ["fanuc", "linuxcnc", "siemens", "haas"] {
        let (text, diags) = translate(M92, &dialect("heidenhain"), &dialect(to), "P1");
        let e = errors(&diags);
        assert!(e.iter().any(|e| e.contains("machine builder's datum")), "{to}: {e:?}");
        assert!(!text.contains("G53") && !text.contains("SUPA"), "{to}: {text}");
    }
    let (tnc, diags) = translate(M92, &dialect("heidenhain"), &dialect("heidenhain"), "T");
    assert!(errors(&diags).is_empty(), "{diags:?}");
    assert!(tnc.lines().any(|l| l.contains("Z+50") && l.ends_with("M92")), "{tnc}");
    assert!(!tnc.contains("M91"), "{tnc}");
}

#[test]
fn centroid_m25_is_z_straight_home() {
    let src = "G90 G17 G0 X10 Y10 Z5\nM25\nG0 X20 Y20\nM30\n";
    let (c, diags) = canon("centroid", src);
    assert!(diags.iter().all(|d| d.code.as_str() != "interp::motion-unknown"), "{diags:?}");
    assert_eq!(markers(&c), vec![(MachineTarget::Direct(1), [None, None, Some(0.0), None, None, None])]);
    let (fanuc, diags) = translate(src, &dialect("centroid"), &dialect("fanuc"), "P1");
    assert!(errors(&diags).is_empty(), "{diags:?}");
    assert!(fanuc.lines().any(|l| l == "G91 G28 Z0."), "{fanuc}");
    runs_the_same("centroid", src, "fanuc", &fanuc);
}

#[test]
fn fanuc_g16_reads_x_as_radius_and_y_as_angle_about_the_work_origin() {
    let src = "G90 G17 G54 G0 X0 Y0 Z10.\nG16\nG0 X50. Y30.\nG1 Z-1. F100.\nY90.\nG3 Y180. R50.\nG15\nG0 X0 Y0\nG16\nG81 X40. Y45. Z-5. R2. F100.\nY135.\nG80 G15\nM30\n";
    let (moves, diags) = crate::moves_and_findings("fanuc", src, &Profile::default());
    assert!(diags.iter().all(|d| d.code.as_str() != "interp::motion-unknown" && !d.is_error()), "{diags:?}");
    let has = |s: &str| moves.iter().any(|m| m.starts_with(s));
    assert!(has("STRAIGHT_TRAVERSE(43.3013, 25.0000, 10.0000"), "{moves:#?}");
    assert!(has("STRAIGHT_FEED(0.0000, 50.0000, -1.0000"), "{moves:#?}");
    assert!(has("ARC_FEED(-50.0000, 0.0000, 0.0000, 0.0000, 1, -1.0000"), "{moves:#?}");
    assert!(has("STRAIGHT_FEED(28.2843, 28.2843, -5.0000"), "{moves:#?}");
    assert!(has("STRAIGHT_FEED(-28.2843, 28.2843, -5.0000"), "{moves:#?}");
    // After G15, X and Y are X and Y again.
    assert!(has("STRAIGHT_TRAVERSE(0.0000, 0.0000, -1.0000"), "{moves:#?}");
    let (text, diags) = translate(src, &dialect("fanuc"), &dialect("linuxcnc"), "P1");
    assert!(errors(&diags).is_empty(), "{diags:?}");
    runs_the_same("fanuc", src, "linuxcnc", &text);
}

#[test]
fn fanuc_g16_with_incremental_words_is_said_and_refused() {
    let src = "G90 G17 G0 X0 Y0 Z10.\nG91 G16\nG0 X10. Y10.\nG90 G15\nM30\n";
    let (_, diags) = translate(src, &dialect("fanuc"), &dialect("linuxcnc"), "P1");
    assert!(errors(&diags).iter().any(|e| e.contains("post::motion-unknown") && e.contains("incremental polar")), "{diags:?}");
}

#[test]
fn a_move_by_a_value_read_with_sysread_is_refused_at_its_word() {
    let src = "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000\n2 FN 18: SYSREAD Q1 = ID20 NR1\n3 L X+10 Y+10 Z+5 R0 FMAX M3\n4 L Z+Q1 F100\n5 L X+20\n6 END PGM T MM\n";
    let (_, diags) = translate(src, &dialect("heidenhain"), &dialect("fanuc"), "P1");
    let refused: Vec<&Diagnostic> = diags.iter().filter(|d| d.code.as_str() == "post::motion-unknown").collect();
    assert_eq!(refused.len(), 1, "{diags:?}");
    let at = &src[refused[0].range.start as usize..refused[0].range.end as usize];
    assert_eq!(at, "Z+Q1", "{refused:?}");
    assert!(refused[0].message.contains("Q1"), "{refused:?}");
}

#[test]
fn targets_whose_output_would_be_another_dialects_refuse() {
    let src = "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X0. Y0. Z5.\nG1 Z-1. F100.\nX10.\nM30\n";
    for (to, says) in [("heidenhain_iso", "Klartext"), ("siemens_810", "840D")] {
        let (text, diags) = translate(src, &dialect("fanuc"), &dialect(to), "P1");
        assert!(text.is_empty(), "{to}: {text}");
        let e = errors(&diags);
        assert!(e.iter().any(|e| e.contains("post::unwritable") && e.contains(says)), "{to}: {e:?}");
    }
}

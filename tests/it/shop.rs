//! Real shop programs read without false alarms (issue 17, §2-§4): the dialect told from
//! the program, controller built-ins and resident cycles, and the dialect gaps real
//! programs showed. Small programs of our own, each showing one reading.

use ncplan::canon::{CanonOp, write_call};
use ncplan::diag::{Diagnostic, Severity};
use ncplan::dialect::Registry;
use ncplan::dialect::sniff::Confidence;
use ncplan::interp::{Profile, interpret};

/// Every canonical call of `program` in `dialect`, one per line, and its findings.
fn run(dialect: &str, program: &str) -> (String, Vec<Diagnostic>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut out = Vec::new();
    let diags = interpret(program, &d, &Profile::default(), &mut out);
    let mut text = String::new();
    for c in &out {
        write_call(&mut text, &c.op);
    }
    (text, diags)
}

/// The moves of `program`, one per line.
fn moves(dialect: &str, program: &str) -> Vec<String> {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut out = Vec::new();
    interpret(program, &d, &Profile::default(), &mut out);
    let mut lines = Vec::new();
    for c in &out {
        if matches!(c.op, CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. }) {
            let mut t = String::new();
            write_call(&mut t, &c.op);
            lines.push(t.trim().to_owned());
        }
    }
    lines
}

fn errors(diags: &[Diagnostic]) -> Vec<String> {
    diags.iter().filter(|d| d.is_error()).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect()
}

fn has(diags: &[Diagnostic], code: &str, severity: Severity) -> bool {
    diags.iter().any(|d| d.code.as_str() == code && d.severity == severity)
}

// ---- §3: telling the dialect ----

/// A derived dialect counts its base's evidence and its own; with evidence of its own it
/// beats its base, without it the base wins. Markers ignore case.
#[test]
fn a_derived_dialect_wins_over_its_base_by_evidence_of_its_own() {
    let r = Registry::shipped();
    let fanuc = "%\nO1234\nG90 G54 G0 X10. Y5.\nG43 H1 Z5.\nG81 Z-5. R2. F100.\nM30\n%\n";
    let s = r.sniff(fanuc, Some("p.nc"), "linuxcnc");
    assert_eq!(s.dialect, "fanuc", "{s:?}");
    for (marker, want) in [
        ("( HAAS VF2 )", "haas"),
        ("(haas vf2)", "haas"),
        ("(NX POSTPROCESSOR: HAAS_UMC750_5AXIS_MILL_IN)", "haas"),
        ("G103 P1", "haas"),
        ("G187 P2", "haas"),
        ("G255", "haas"),
        ("(Mitsubishi M80)", "mitsubishi"),
        ("#900001=5.", "mitsubishi"),
        ("(OKUMA MB-46)", "okuma"),
    ] {
        let text = fanuc.replacen("O1234\n", &format!("O1234\n{marker}\n"), 1);
        let s = r.sniff(&text, Some("p.nc"), "linuxcnc");
        assert_eq!(s.dialect, want, "{marker}: {s:?}");
        assert!(s.evidence.iter().any(|e| e == "O1234"), "the base's evidence counts: {s:?}");
        assert!(s.confidence >= Confidence::Medium, "{marker}: {s:?}");
    }
}

/// Lathe programs get the lathe dialect of their family.
#[test]
fn lathe_programs_get_a_lathe_dialect_of_their_family() {
    let r = Registry::shipped();
    let lathe = "%\nO0001\nG50 S3000\nG96 S200 M3\nT0101\nG0 X52. Z2.\nG99 G1 Z-20. F0.2\nU2. W1.\nM30\n%\n";
    assert_eq!(r.sniff(lathe, Some("p.nc"), "linuxcnc").dialect, "fanuc_lathe");
    for (marker, want) in [("(HAAS ST-20)", "haas_lathe"), ("(MITSUBISHI M80 L)", "mitsubishi_lathe"), ("(MAZAK QTN 200)", "mazak_lathe")] {
        let text = lathe.replacen("O0001\n", &format!("O0001\n{marker}\n"), 1);
        assert_eq!(r.sniff(&text, Some("p.nc"), "linuxcnc").dialect, want, "{marker}");
    }
    let fagor = "%\nN10 G90 G71\nN20 T1.1\nN30 G92 S2000\nN40 G96 S200 M3\nN50 G95 G1 X20 Z-5 F0.2\nM30\n";
    assert_eq!(r.sniff(fagor, Some("p.ptp"), "linuxcnc").dialect, "fagor_lathe");
}

/// A program that only shows what a base and its derived dialects share is read in the
/// base, but not said to be sure: a Haas or a Mitsubishi control would read it too.
#[test]
fn a_program_any_of_a_family_would_read_is_not_sure_of_the_maker() {
    let r = Registry::shipped();
    let s = r.sniff("%\nO0001\nT1 M6\nG0 G90 G54 X1. Y2.\nG43 H1 Z1.\nG1 Z-1. F10.\nM30\n%\n", Some("p.nc"), "linuxcnc");
    assert_eq!(s.dialect, "fanuc");
    assert_eq!(s.confidence, Confidence::Medium, "{s:?}");
}

// ---- §4: dialect gaps ----

/// Haas lathes write G71 in one block, `G71 P Q U W D F`, D the depth of each pass: the
/// same roughing as Fanuc's two-block form with that depth.
#[test]
fn haas_lathe_one_block_roughing_is_fanucs_two_block_form() {
    let contour = "N10 G0 X30.\nG1 Z-20.\nX40. Z-30.\nN20 X52.\nG70 P10 Q20\nG0 X100. Z100.\nM30\n";
    let start = "T0101\nG97 S1000 M3\nG0 X52. Z2.\n";
    let fanuc = format!("{start}G71 U2. R0.\nG71 P10 Q20 U0.4 W0.1 F0.25\n{contour}");
    let haas = format!("{start}G71 P10 Q20 U0.4 W0.1 D2. F0.25\n{contour}");
    let (_, diags) = run("haas_lathe", &haas);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let (h, f) = (moves("haas_lathe", &haas), moves("fanuc_lathe", &fanuc));
    assert!(h.len() > 20, "{h:?}");
    assert_eq!(h, f);
}

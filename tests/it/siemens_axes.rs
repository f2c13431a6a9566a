//! Siemens spindle positioning and axis variables (issue 17): `SPOS=90` orients the spindle
//! to that angle; `AX[_X]=10` moves the axis an `AXIS` variable holds, and says so when the
//! axis comes from outside the file.

use std::collections::BTreeMap;
use std::sync::Arc;

use ncplan::canon::{CanonOp, write_call};
use ncplan::diag::Diagnostic;
use ncplan::dialect::Registry;
use ncplan::interp::{Profile, ProgramSource, interpret};

fn run_with(dialect: &str, program: &str, profile: &Profile) -> (Vec<CanonOp>, Vec<Diagnostic>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut out = Vec::new();
    let diags = interpret(program, &d, profile, &mut out);
    (out.into_iter().map(|c| c.op).collect(), diags)
}

fn run(dialect: &str, program: &str) -> (Vec<CanonOp>, Vec<Diagnostic>) {
    run_with(dialect, program, &Profile::default())
}

fn moves(ops: &[CanonOp]) -> Vec<String> {
    ops.iter()
        .filter(|op| matches!(op, CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_)))
        .map(|op| {
            let mut t = String::new();
            write_call(&mut t, op);
            t.trim().to_owned()
        })
        .collect()
}

fn orients(ops: &[CanonOp]) -> Vec<f64> {
    ops.iter().filter_map(|op| if let CanonOp::OrientSpindle { angle, .. } = op { Some(*angle) } else { None }).collect()
}

fn findings(diags: &[Diagnostic]) -> Vec<String> {
    diags.iter().map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect()
}

#[test]
fn spos_orients_the_spindle_to_its_angle() {
    let program = "N10 G90 G0 X0 Y0 Z50\nN20 SPOS=90\nN30 SPOS[1]=45\nN40 SPOSA=DC(180)\nN50 M5 SPOS = R1\nN60 M30\n";
    let program = program.replace("N10", "R1=270\nN10");
    let (ops, diags) = run("siemens", &program);
    assert_eq!(orients(&ops), [90.0, 45.0, 180.0, 270.0], "{ops:?}");
    assert!(findings(&diags).is_empty(), "{:?}", findings(&diags));
}

#[test]
fn fanuc_m19_stays_as_it_was() {
    let (ops, diags) = run("fanuc", "%\nO1\nM19\nM30\n%\n");
    assert_eq!(orients(&ops), [0.0]);
    assert!(diags.iter().all(|d| !d.is_error()), "{:?}", findings(&diags));
}

#[test]
fn an_axis_variable_names_the_axis_it_holds() {
    let program = "\
DEF AXIS _X=X
DEF AXIS _AX1
DEF AXIS _AX2=Y
G90 G0 X0 Y0 Z10
_AX1=Z
AX[_X]=10
POS[_AX1]=5
G1 AX[_AX2]=20 F300
_AX1=X
G1 AX[_AX1]=30
M30
";
    let (ops, diags) = run("siemens", program);
    assert_eq!(
        moves(&ops),
        [
            "STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_TRAVERSE(10.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_TRAVERSE(10.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(10.0000, 20.0000, 5.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(30.0000, 20.0000, 5.0000, 0.0000, 0.0000, 0.0000)",
        ]
    );
    assert!(!diags.iter().any(|d| d.code.as_str() == "interp::unknown-value"), "{:?}", findings(&diags));
}

/// A `PROC`'s `AXIS` argument comes from its caller: alone, the move along it is left out
/// with a note; called with `MOVEAX(Y, 12)`, it moves Y.
#[test]
fn an_axis_argument_is_the_callers() {
    let sub = "PROC MOVEAX(AXIS _A, REAL _V)\nG1 AX[_A]=_V Z-1 F100\nM17\n";
    let (ops, diags) = run("siemens", sub);
    let notes: Vec<_> = diags.iter().filter(|d| d.code.as_str() == "interp::unknown-value").map(|d| d.message.clone()).collect();
    assert!(notes.iter().any(|m| m.contains("AX[_A]") && m.contains("names its axis by") && m.contains("caller")), "{notes:?}");
    assert!(diags.iter().all(|d| !d.is_error()), "{:?}", findings(&diags));
    assert_eq!(moves(&ops), ["STRAIGHT_FEED(0.0000, 0.0000, -1.0000, 0.0000, 0.0000, 0.0000)"]);

    struct Subs(BTreeMap<String, String>);
    impl ProgramSource for Subs {
        fn load(&self, name: &str) -> Option<String> {
            self.0.get(&name.to_ascii_uppercase()).cloned()
        }
    }
    let subs = Subs(BTreeMap::from([("MOVEAX".to_owned(), sub.to_owned())]));
    let profile = Profile { programs: Some(Arc::new(subs)), ..Profile::default() };
    let (ops, diags) = run_with("siemens", "G90 G0 X0 Y0 Z5\nMOVEAX(Y, 12)\nM30\n", &profile);
    assert!(diags.iter().all(|d| !d.is_error()), "{:?}", findings(&diags));
    assert!(moves(&ops).contains(&"STRAIGHT_FEED(0.0000, 12.0000, -1.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{:?}", moves(&ops));
}

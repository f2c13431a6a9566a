//! LinuxCNC parity (issue 17 §6): constructs where ncplan follows rs274.

use ncplan::canon::{CanonOp, write_call};
use ncplan::dialect::Registry;
use ncplan::interp::{Profile, interpret};

fn traverses(dialect: &str, text: &str) -> Vec<String> {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut out = Vec::new();
    let diags = interpret(text, &d, &Profile::default(), &mut out);
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:#?}");
    out.iter()
        .filter(|c| matches!(c.op, CanonOp::StraightTraverse(_)))
        .map(|c| {
            let mut s = String::new();
            write_call(&mut s, &c.op);
            s.trim_end().to_owned()
        })
        .collect()
}

/// Without G98 or G99 in the program, RS274NGC's cycles retract to the R plane (the EMC
/// handbook: "If G98 is not specified, then the canned cycle will return to the R value");
/// Fanuc's power-on mode is G98, the initial level. The dictionaries say so
/// (`initial-retract`).
#[test]
fn the_retract_mode_at_start_up_is_the_dictionarys() {
    let text = std::fs::read_to_string(crate::root().join("tests/programs/linuxcnc/cycle_startup_retract.ngc")).unwrap();
    let lcnc = traverses("linuxcnc", &text);
    // Over the first hole at Z10, down to R, back to R after it; over the second hole at R.
    assert_eq!(
        lcnc[1..6],
        [
            "STRAIGHT_TRAVERSE(1.0000, 1.0000, 10.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_TRAVERSE(1.0000, 1.0000, 2.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_TRAVERSE(1.0000, 1.0000, 2.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_TRAVERSE(2.0000, 1.0000, 2.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_TRAVERSE(2.0000, 1.0000, 2.0000, 0.0000, 0.0000, 0.0000)",
        ],
        "{lcnc:#?}"
    );
    let fanuc = traverses("fanuc", "G21 G90 G17\nG0 X0. Y0. Z10.\nM3 S1000\nG81 X1. Y1. Z-1. R2. F100.\nX2.\nG80\nG0 Z10.\nM30\n");
    // Fanuc: back to the initial level Z10 after the first hole.
    assert_eq!(fanuc[3], "STRAIGHT_TRAVERSE(1.0000, 1.0000, 10.0000, 0.0000, 0.0000, 0.0000)", "{fanuc:#?}");
}

//! Fanuc canned cycles beyond drilling, by the moves they make: tapping reverses the spindle
//! at the bottom, fine boring stops oriented, shifts by Q and rapids out, and manual-retract boring
//! stops the program.

use expect_test::expect;
use ncplan::canon::{CanonOp, write_call};
use ncplan::dialect::Registry;
use ncplan::interp::{Profile, interpret};

fn canon(program: &str) -> (String, Vec<&'static str>) {
    let d = Registry::shipped().get("fanuc").unwrap();
    let mut out = Vec::new();
    let diags = interpret(program, &d, &Profile::default(), &mut out);
    let mut text = String::new();
    for c in &out {
        if !matches!(c.op, CanonOp::Comment(_) | CanonOp::CycleBegin(_) | CanonOp::CycleEnd) {
            write_call(&mut text, &c.op);
        }
    }
    (text, diags.iter().map(|d| d.code.as_str()).collect())
}

#[test]
fn tapping_fine_boring_and_manual_boring() {
    let (out, codes) = canon(
        "G90 G17 G21 S500 M3 F100.\nG0 X0 Y0 Z10.\nG98 G84 X10. Y10. Z-5. R2. P500\nG80\nG76 X30. Y0 Z-5. R2. Q0.5 P0\nG88 X40. Z-3. R2.\nG80 M30\n",
    );
    expect![[r#"
        SET_FEED_RATE(100.0000)
        SET_SPINDLE_SPEED(0, 500.0000)
        START_SPINDLE_CLOCKWISE(0)
        SELECT_PLANE(CANON_PLANE_XY)
        USE_LENGTH_UNITS(CANON_UNITS_MM)
        STRAIGHT_TRAVERSE(0.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.0000, 10.0000, 10.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(10.0000, 10.0000, 2.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(10.0000, 10.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        DWELL(0.5000)
        START_SPINDLE_COUNTERCLOCKWISE(0)
        STRAIGHT_FEED(10.0000, 10.0000, 2.0000, 0.0000, 0.0000, 0.0000)
        START_SPINDLE_CLOCKWISE(0)
        STRAIGHT_TRAVERSE(10.0000, 10.0000, 10.0000, 0.0000, 0.0000, 0.0000)
        COMMENT("interpreter: motion mode set to none")
        STRAIGHT_TRAVERSE(30.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(30.0000, 0.0000, 2.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(30.0000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        ORIENT_SPINDLE(0, 0.0000, 0)
        STRAIGHT_TRAVERSE(30.5000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(30.5000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(30.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)
        START_SPINDLE_CLOCKWISE(0)
        STRAIGHT_TRAVERSE(40.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(40.0000, 0.0000, 2.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(40.0000, 0.0000, -3.0000, 0.0000, 0.0000, 0.0000)
        DWELL(0.0000)
        STOP_SPINDLE_TURNING(0)
        PROGRAM_STOP()
        STRAIGHT_TRAVERSE(40.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)
        START_SPINDLE_CLOCKWISE(0)
        COMMENT("interpreter: motion mode set to none")
        SET_G5X_OFFSET(1, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)
        SET_FEED_RATE(0.0000)
        STOP_SPINDLE_TURNING(0)
        PROGRAM_END()
    "#]]
    .assert_eq(&out);
    // Fine boring's shift goes the way the control's parameters say (Fanuc 5101), not the
    // program: read along +X, said as a motion a translation cannot write.
    assert_eq!(codes, ["interp::motion-unknown"]);
}

#[test]
fn a_zero_offset_keeps_the_path_and_a_negative_one_changes_sides() {
    let run = |comp: &str| {
        let program = format!("G20 F10 S1000 M3\nG0 X0 Y0\n{comp}\nG1 X1 Y0.3\nG1 X2 Y0\nG1 X2 Y1\nG40\nG0 X0 Y0\nM2\n");
        let mut out = Vec::new();
        let diags = interpret(&program, &Registry::shipped().get("linuxcnc").unwrap(), &Profile::default(), &mut out);
        assert!(diags.is_empty(), "{comp}: {diags:?}");
        let mut text = String::new();
        for c in out.iter().filter(|c| matches!(c.op, CanonOp::StraightFeed(_))) {
            write_call(&mut text, &c.op);
        }
        text
    };
    // As rs274 -g runs LinuxCNC's inside-corners and inverse-time-with-comp tests.
    assert_eq!(run("G41.1 D0"), run(""));
    assert_eq!(run("G41.1 D-0.2"), run("G42.1 D0.2"));
    assert_ne!(run("G41.1 D-0.2"), run("G41.1 D0.2"));
    assert_ne!(run("G41.1 D0.2"), run(""));
}

/// G80 clears the drilling data with R and Z (Fanuc 0i/30i manuals: "other drilling data
/// are also cleared"): a tapping cycle after `G82 … P1000` and G80 does not dwell at the
/// bottom, while within one cycle mode the P stays.
#[test]
fn g80_clears_the_dwell_of_the_cycle_before() {
    let (out, codes) = canon(
        "G90 G17 G21 S500 M3 F100.\nG0 X0 Y0 Z10.\nG99 G82 X10. Y10. Z-1. R3. P1000\nY20.\nG80\nG99 G84 X30. Y10. Z-5. R3.\nG80 M30\n",
    );
    assert_eq!(codes, Vec::<&str>::new());
    assert_eq!(out.matches("DWELL(1.0000)").count(), 2, "both counterbores dwell:\n{out}");
    assert_eq!(out.matches("DWELL").count(), 2, "the tap after G80 does not:\n{out}");
}

//! Shopfloor edits: one CAM original (`tests/programs/cam/edits_original.nc`), one edit at a
//! time, and the exact change rows the diff must give. A cosmetic rewrite gives none.
//!
//! Each row is `kind | field | before | after | edited line | original line`, and the
//! planner's sentence follows on the next line.

use expect_test::{Expect, expect};
use ncplan::dialect::Registry;
use ncplan::diff::{self, Change, ChangeKind};
use ncplan::interp::Profile;
use ncplan::pipeline;

fn original() -> String {
    std::fs::read_to_string(crate::root().join("tests/programs/cam/edits_original.nc")).unwrap()
}

fn changes(a: &str, b: &str, dialect: &str) -> Vec<Change> {
    let registry = Registry::shipped();
    let d = registry.get(dialect).unwrap();
    let profile = Profile::default();
    let pa = pipeline::analyze(a.as_bytes(), &d, &profile);
    let pb = pipeline::analyze(b.as_bytes(), &d, &profile);
    let got = diff::compare(
        diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d },
        diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d },
    );
    let missing = diff::unaccounted(
        diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d },
        diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d },
        &got,
    );
    assert!(missing.is_empty(), "differing statements no change names: {missing:?}");
    got
}

fn rows(changes: &[Change]) -> String {
    let opt = |l: Option<u32>| l.map_or("-".to_owned(), |l| l.to_string());
    let mut s = String::new();
    for c in changes {
        s.push_str(&format!(
            "{} | {} | {} | {} | {} | {}\n  {}\n",
            c.kind.as_str(),
            c.field,
            c.before,
            c.after,
            opt(c.line),
            opt(c.original_line),
            c.phrase()
        ));
    }
    s
}

/// Replaces `from` (which must occur once) by `to` in the original and diffs.
fn edit(from: &str, to: &str, want: Expect) {
    let a = original();
    assert_eq!(a.matches(from).count(), 1, "{from:?} occurs once in the original");
    let b = a.replace(from, to);
    let got = changes(&a, &b, "fanuc");
    for c in &got {
        for word in ["Cw", "Ccw", "Flood", "Mist", "Some(", "None", "Rapid", "Line"] {
            assert!(!c.phrase().contains(word), "a Rust name in {:?}", c.phrase());
        }
        assert_ne!(c.before, c.after, "{}", c.phrase());
    }
    want.assert_eq(&rows(&got));
}

#[test]
fn cosmetic_rewrite_gives_no_change() {
    let a = original();
    let mut b = String::new();
    for line in a.lines() {
        let mut l = line.to_owned();
        // Block numbers, comments, spacing, case, G0/G00, X10./X10.000.
        if let Some(rest) = l.strip_prefix('N')
            && let Some((n, tail)) = rest.split_once(' ')
        {
            l = format!("N{} {tail}", n.parse::<u32>().unwrap() * 2 + 1);
        }
        if l.starts_with("(FACE1") {
            l = "(FACING THE TOP, CHECKED BY ANN)".into();
        }
        l = l.replace("G00", "G0").replace("G01 ", "G1 ").replace("M06", "M6").replace(' ', "  ");
        for axis in ["X", "Y", "Z", "R", "Q", "F"] {
            for n in ["130.", "50.", "15.", "20.", "4.", "3.", "1000."] {
                l = l.replace(&format!("{axis}{n} "), &format!("{axis}{n}000 "));
            }
        }
        if l.contains("G83") {
            l = l.to_lowercase();
        }
        b.push_str(&l);
        b.push('\n');
    }
    assert_ne!(a, b);
    assert_eq!(rows(&changes(&a, &b, "fanuc")), "");
}

#[test]
fn work_offset() {
    edit(
        "N195 G54",
        "N195 G55",
        expect![[r#"
            work_offset_changed | work_offset | G54 | G55 | 47 | 47
              work offset changed from G54 to G55 at line 47
            risky_edit | lone-work-offset |  | workingstep 3 cuts in G55, which the rest of the program never uses (it cuts in G54) | 48 | 48
              warning: workingstep 3 cuts in G55, which the rest of the program never uses (it cuts in G54)
        "#]],
    );
}

/// An additional work offset (Fanuc `G54.1 P`, Haas `G154 P`) is a system of its own: the
/// operator who moves a fixture from P20 to P21 is seen.
#[test]
fn additional_work_offset() {
    let program =
        |p: u32| format!("%\nO1\nG21 G90 G17\nT1 M6\nS2000 M3\nG154 P{p} G0 X0 Y0\nG43 H1 Z5.\nG1 Z-1. F300.\nX50.\nG0 Z50.\nM30\n%\n");
    let got = changes(&program(20), &program(21), "haas");
    expect![[r#"
        work_offset_changed | work_offset | additional work offset 20 | additional work offset 21 | 6 | 6
          work offset changed from additional work offset 20 to additional work offset 21 at line 6
    "#]]
    .assert_eq(&rows(&got));
    let fanuc = |w: &str| format!("%\nO1\nG21 G90 G17\nT1 M6\nS2000 M3\n{w} G0 X0 Y0\nG43 H1 Z5.\nG1 Z-1. F300.\nX50.\nG0 Z50.\nM30\n%\n");
    assert!(changes(&fanuc("G54"), &fanuc("G54.1 P1"), "fanuc").iter().any(|c| c.after == "additional work offset 1"));
}

#[test]
fn length_offset_of_another_tool() {
    edit(
        "G43 Z15. H03",
        "G43 Z15. H02",
        expect![[r#"
            length_offset_changed | length_offset | the tool's own (H3) | H2 | 49 | 49
              length offset changed from the tool's own (H3) to H2 at line 49
            risky_edit | foreign-length-offset |  | T3 cuts with the length offset of tool T2 (H2) | 48 | 48
              warning: T3 cuts with the length offset of tool T2 (H2)
        "#]],
    );
}

#[test]
fn no_length_offset_while_cutting() {
    edit(
        "G43 Z15. H02",
        "G43 Z15. H00",
        expect![[r#"
            length_offset_changed | length_offset | the tool's own (H2) | none (H0) | 35 | 35
              length offset changed from the tool's own (H2) to none (H0) at line 35
            risky_edit | no-length-offset |  | T2 cuts with no length offset (H0), while the rest of the program uses them | 34 | 34
              warning: T2 cuts with no length offset (H0), while the rest of the program uses them
        "#]],
    );
}

#[test]
fn cutter_compensation_side() {
    edit(
        "G41 D03",
        "G42 D03",
        expect![[r#"
            cutter_comp_changed | cutter_compensation | left (G41) with the tool's own D3 | right (G42) with the tool's own D3 | 53 | 53
              cutter compensation changed from left (G41) with the tool's own D3 to right (G42) with the tool's own D3 at line 53
        "#]],
    );
}

#[test]
fn compensation_number() {
    edit(
        "G41 D03",
        "G41 D13",
        expect![[r#"
            cutter_comp_changed | cutter_compensation | left (G41) with the tool's own D3 | left (G41) with D13 | 53 | 53
              cutter compensation changed from left (G41) with the tool's own D3 to left (G41) with D13 at line 53
        "#]],
    );
}

#[test]
fn program_stop_added() {
    edit(
        "N215 G00 Z3.\n",
        "N215 G00 Z3.\nN216 M00\n",
        expect![[r#"
        stop_added | stop |  | program stop (M00) | 52 | -
          program stop (M00) added at line 52
    "#]],
    );
}

#[test]
fn optional_stop_removed() {
    edit(
        "N115 M01\n",
        "",
        expect![[r#"
            stop_removed | stop | optional stop (M01) |  | - | 29
              optional stop (M01) removed at original line 29
        "#]],
    );
}

#[test]
fn dwell_added() {
    edit(
        "N220 G01 Z-5. F300.\n",
        "N220 G01 Z-5. F300.\nN221 G04 X0.5\n",
        expect![[r#"
        dwell_changed | dwell |  | 0.5 s | 53 | -
          dwell 0.5 s added at line 53
    "#]],
    );
}

#[test]
fn block_delete_on_a_hole() {
    edit(
        "N160 Y40.",
        "/N160 Y40.",
        expect![[r#"
            optional_block_changed | optional_block | the hole at X80 Y40 | now depends on the block-delete switch | 39 | 39
              the hole at X80 Y40 now depends on the block-delete switch at line 39
        "#]],
    );
}

#[test]
fn block_delete_on_a_pass() {
    edit(
        "N85 Y50.\nN90 X130.",
        "/N85 Y50.\n/N90 X130.",
        expect![[r#"
            optional_block_changed | optional_block | the moves at lines 23–24 | now depend on the block-delete switch | 23 | -
              the moves at lines 23–24 now depend on the block-delete switch at lines 23 and 24
        "#]],
    );
}

#[test]
fn peck_depth() {
    edit(
        "Q4.",
        "Q2.",
        expect![[r#"
            cycle_parameter_changed | peck | Q4 | Q2 | 37 | 37
              peck changed from Q4 to Q2 at line 37
        "#]],
    );
}

#[test]
fn r_level() {
    edit(
        "R3.",
        "R5.",
        expect![[r#"
            cycle_parameter_changed | r_level | Z3 | Z5 | 37 | 37
              r level changed from Z3 to Z5 at line 37
        "#]],
    );
}

#[test]
fn retract_plane() {
    edit(
        "G98 G83",
        "G99 G83",
        expect![[r#"
            cycle_parameter_changed | retract_plane | Z15 | Z3 | 37 | 37
              retract plane changed from Z15 to Z3 at line 37
        "#]],
    );
}

#[test]
fn hole_added() {
    edit(
        "N160 Y40.\n",
        "N160 Y40.\nN161 X50.\n",
        expect![[r#"
            hole_added | hole |  | X50 Y40 | 40 | -
              hole added at X50 Y40 at line 40
        "#]],
    );
}

/// A hole drilled elsewhere by the same cycle is that hole moved, not one removed and another
/// added (`diff::moved`).
#[test]
fn hole_moved() {
    edit(
        "N160 Y40.\n",
        "N160 Y45.\n",
        expect![[r#"
            hole_moved | hole | X80 Y40 | X80 Y45 | 39 | 39
              hole at X80 Y40 moved to X80 Y45 at line 39
        "#]],
    );
}

#[test]
fn hole_removed() {
    edit(
        "N155 X80.\n",
        "",
        expect![[r#"
            hole_removed | hole | X80 Y20 |  | - | 38
              hole at X80 Y20 removed at original line 38
            hole_removed | hole | X80 Y40 |  | - | 38
              hole at X80 Y40 removed at original line 38
            hole_added | hole |  | X20 Y40 | - | 38
              hole added at X20 Y40 at original line 38
        "#]],
    );
}

#[test]
fn hole_depth() {
    edit(
        "Z-20. R3.",
        "Z-18. R3.",
        expect![[r#"
            depth_changed | depth | Z-20 | Z-18 | 37 | 37
              depth changed from Z-20 to Z-18 at line 37
        "#]],
    );
}

#[test]
fn pass_shortened() {
    edit(
        "N80 X-30.",
        "N80 X-24.",
        expect![[r#"
        toolpath_changed | toolpath | the 2 cuts at lines 22–23, ending at X-30 Y50 | the 2 cuts at lines 22–23, ending at X-24 Y50 (6 mm shorter), in X-30…130 Y30…50, at most 6 mm from the original path | 22 | 22
          toolpath changed at line 22: the 2 cuts at lines 22–23, ending at X-30 Y50 became the 2 cuts at lines 22–23, ending at X-24 Y50 (6 mm shorter), in X-30…130 Y30…50, at most 6 mm from the original path
    "#]],
    );
}

#[test]
fn last_pass_shortened() {
    edit(
        "N90 X130.",
        "N90 X120.",
        expect![[r#"
        toolpath_changed | toolpath | the cut at line 24 to X130 Y50 | the cut at line 24 to X120 Y50 (10 mm shorter), in X-30…130 Y50…50, at most 10 mm from the original path | 24 | 24
          toolpath changed at line 24: the cut at line 24 to X130 Y50 became the cut at line 24 to X120 Y50 (10 mm shorter), in X-30…130 Y50…50, at most 10 mm from the original path
    "#]],
    );
}

#[test]
fn constant_surface_speed() {
    edit(
        "S8000 M03",
        "G96 S200 M03",
        expect![[r#"
            spindle_mode_changed | spindle_mode | S8000 1/min (G97) | constant surface speed 200 m/min (G96) | 46 | 46
              spindle mode changed from S8000 1/min (G97) to constant surface speed 200 m/min (G96) at line 46
        "#]],
    );
}

#[test]
fn feed_and_speed() {
    edit(
        "X60. F1200.",
        "X60. F1000.",
        expect![[r#"
            feed_changed | feed | F300, F1200 | F300, F1000 | 53 | 53
              feed changed from F300, F1200 to F300, F1000 at line 53
        "#]],
    );
}

#[test]
fn spindle_and_coolant() {
    edit(
        "N190 S8000 M03",
        "N190 S8000 M04",
        expect![[r#"
            spindle_direction_changed | spindle_direction | clockwise (M3) | counter-clockwise (M4) | 46 | 46
              spindle direction changed from clockwise (M3) to counter-clockwise (M4) at line 46
        "#]],
    );
}

#[test]
fn pocket_wall_moved() {
    edit(
        "N235 X40.",
        "N235 X44.",
        expect![[r#"
            feature_changed | pocket_width | 20 mm | 16 mm | 55 | 55
              pocket width changed from 20 mm to 16 mm at line 55
        "#]],
    );
}

/// An inch program's changes are written in inches.
#[test]
fn inch_program_in_inches() {
    let a = "%\nO2 (INCH)\n(T1 D=0.5 FLAT END MILL)\nG20 G17 G40 G49 G80 G90\nT1 M06\nS6000 M03\nG54 G00 X-0.3 Y0.\nG43 Z1. H01\nZ0.1\nG01 Z-0.05 F20.\nX4.3 F40.\nY0.4\nX-0.3\nY0.8\nX4.3\nG00 Z1.\nM30\n%\n";
    let b = a.replace("Y0.8\nX4.3\n", "Y0.8\nX3.8 F30.\n");
    expect![[r#"
        feed_changed | feed | F20, F40 | F20, F40, F30 | 15 | 15
          feed changed from F20, F40 to F20, F40, F30 at line 15
        toolpath_changed | toolpath | the cut at line 15 to X4.3 Y0.8 | the cut at line 15 to X3.8 Y0.8 (0.5 in shorter), in X-0.3…4.3 Y0.8…0.8, at most 0.5 in from the original path | 15 | 15
          toolpath changed at line 15: the cut at line 15 to X4.3 Y0.8 became the cut at line 15 to X3.8 Y0.8 (0.5 in shorter), in X-0.3…4.3 Y0.8…0.8, at most 0.5 in from the original path
    "#]].assert_eq(&rows(&changes(a, &b, "fanuc")));
}

/// A surfacing raster of `passes` passes of `steps` short moves over 200 × 200 mm.
fn raster(passes: usize, steps: usize, shift: f64, edit: Option<usize>) -> ncplan::plan::ProcessPlan {
    use ncplan::plan::*;
    let (dx, dy) = (200.0 / steps as f64, 200.0 / passes as f64);
    let mut moves = Vec::with_capacity(passes * steps);
    let mut at = [0.0, shift, -1.0];
    for p in 0..passes {
        for s in 0..steps {
            let x = if p % 2 == 0 { (s + 1) as f64 * dx } else { 200.0 - (s + 1) as f64 * dx };
            let z = -1.0 - 0.5 * ((x / 20.0).sin() * (at[1] / 20.0).cos());
            let mut to = [x, at[1], z];
            if edit == Some(moves.len()) {
                to[2] -= 0.3;
            }
            moves.push(Move {
                kind: MoveKind::Line,
                phase: Phase::Cut,
                from: at,
                to,
                arc: None,
                feed: 2000.0,
                line: moves.len() as u32 + 10,
            });
            at = to;
        }
        let to = [at[0], (p + 1) as f64 * dy + shift, at[2]];
        moves.push(Move { kind: MoveKind::Line, phase: Phase::Cut, from: at, to, arc: None, feed: 2000.0, line: moves.len() as u32 + 10 });
        at = to;
    }
    let tech = Technology {
        feed: 2000.0,
        feeds: vec![2000.0],
        spindle_speed: 12000.0,
        surface_speed: None,
        spindle: SpindleDir::Cw,
        coolant: Coolant::Flood,
        spindle_id: ncplan::plan::SpindleId::Main,
    };
    let mut ws =
        Workingstep::unmeasured(1, Operation::FreeformMilling, 1, tech, 10.0, moves.into(), ncplan::text::TextRange::new(0, 1), (10, 10));
    measure(&mut ws, None, None, &[]);
    ProcessPlan { workingsteps: vec![ws], tools: vec![Tool::unknown(1)], ..ProcessPlan::default() }
}

/// One move of a quarter million changed: the change names its line and its deviation.
/// (Near-linear time: a quadratic comparison would not finish; timings live in `bench`.)
#[test]
fn localisation_on_a_large_program() {
    let a = raster(500, 499, 0.0, None);
    let b = raster(500, 499, 0.0, Some(154_321));
    let got = diff::diff(&a, &b);
    assert_eq!(got.len(), 1, "{}", rows(&got));
    let c = &got[0];
    assert_eq!((c.kind.as_str(), c.line, c.original_line), ("toolpath_changed", Some(154_331), Some(154_331)));
    assert!((c.deviation.unwrap() - 0.3).abs() < 0.01, "{c:?}");
    let r = c.region.unwrap();
    assert!(r.max[0] - r.min[0] < 1.0 && r.max[1] - r.min[1] < 1.0, "{r:?}");
}

/// Every move changed (the whole raster shifted by 0.05 mm): still measured.
#[test]
fn localisation_of_a_shift_over_a_large_program() {
    let a = raster(500, 499, 0.0, None);
    let b = raster(500, 499, 0.05, None);
    let got = diff::diff(&a, &b);
    let c = got.iter().find(|c| c.kind.as_str() == "toolpath_changed").expect("a toolpath change");
    assert!(c.deviation.unwrap() < 0.1 && c.deviation.unwrap() > 0.0, "{c:?}");
}

/// A roughing re-posted with other parameters: `tests/programs/cam/edits/pocket_*.nc`.
fn pocket_edit(variant: &str, want: Expect) {
    let read = |name: &str| std::fs::read_to_string(crate::root().join(format!("tests/programs/cam/edits/pocket_{name}.nc"))).unwrap();
    want.assert_eq(&rows(&changes(&read("original"), &read(variant), "fanuc")));
}

#[test]
fn stepover() {
    pocket_edit(
        "stepover",
        expect![[r#"
            stepover_changed | stepover | 5 mm | 4 mm | 17 | 17
              stepover changed from 5 mm to 4 mm at lines 17, 18, 19 and 19 more
        "#]],
    );
}

#[test]
fn allowance() {
    pocket_edit(
        "allowance",
        expect![[r#"
            allowance_changed | wall_allowance | 0.3 mm | 0.5 mm | 17 | 17
              wall allowance changed from 0.3 mm to 0.5 mm at lines 17, 18, 19 and 17 more
        "#]],
    );
}

#[test]
fn axial_depth() {
    pocket_edit(
        "axial_depth",
        expect![[r#"
            approach_changed | approach_height | Z2 | Z3 | 15 | 15
              approach height changed from Z2 to Z3 at lines 15, 16, 29 and 16 more
            axial_depth_changed | axial_depth | 3 mm | 2 mm | 15 | 15
              axial depth changed from 3 mm to 2 mm at lines 15, 16, 29 and 16 more
        "#]],
    );
}

#[test]
fn the_feed_override_turned_off_is_a_change() {
    // LinuxCNC: M49 disables the feed and speed overrides, M50 P0 the feed override alone.
    let a = "G21 G90 G17\nT1 M6\nS3000 M3\nG0 X0 Y0 Z5\nG1 Z-2 F400\nX50\nY30\nX0\nY0\nG0 Z5\nM30\n";
    for off in ["M49", "M50 P0"] {
        let b = a.replace("G1 Z-2 F400\n", &format!("{off}\nG1 Z-2 F400\n"));
        expect![[r#"
            feed_override_changed | feed_override | on | off (the programmed feed, whatever the dial) | 5 | -
              feed override changed from on to off (the programmed feed, whatever the dial) at line 5
        "#]]
        .assert_eq(&rows(&changes(a, &b, "linuxcnc")));
    }
    // Turned on again before the cut: no plan change; the two statements are still named.
    let b = a.replace("G1 Z-2 F400\n", "M49\nM48\nG1 Z-2 F400\n");
    expect![[r#"
        feed_override_changed | feed override |  | M49 | 5 | -
          feed override M49 added at line 5
        feed_override_changed | feed override |  | M48 | 6 | -
          feed override M48 added at line 6
    "#]]
    .assert_eq(&rows(&changes(a, &b, "linuxcnc")));
}

#[test]
fn return_and_rotary_moves_are_their_own_kinds() {
    let a = "%\nO1\nG21 G90 G17\nT1 M6\nS2000 M3\nG54 G0 X0. Y0.\nG43 H1 Z5.\nG1 Z-1. F300.\nX50.\nG0 Z50.\nM30\n%\n";
    let b = a.replace("G54 G0 X0. Y0.\n", "G91 G28 Z0.\nG90\nG54 G0 X0. Y0.\nG0 A90.\n");
    expect![[r#"
        return_move_changed | statement |  | G91 G28 Z0 | 6 | -
          return move: `G91 G28 Z0` added at line 6
        machine_function_changed | machine function G90: distance absolute |  | G90 | 7 | -
          machine function `G90` added (G90: distance absolute) at line 7
        rotary_move_changed | statement |  | G0 A90. | 9 | -
          rotary axis move: `G0 A90.` added at line 9
    "#]]
    .assert_eq(&rows(&changes(a, &b, "fanuc")));
}

#[test]
fn control_flow_edits_are_told_as_what_runs() {
    // A loop's bound and the repeat count of a call code (`M98 … L`).
    let a = "%\nO1\nG21 G90 G17\nT1 M6\nS2000 M3\nG54 G0 X0. Y0. Z5.\n#1=0\nWHILE[#1LT3]DO1\nG1 Z-1. F300.\nX50.\n#1=#1+1\nEND1\nM98 P2 L2\nG0 Z50.\nM30\n%\nO2\nG0 Z5.\nM99\n%\n";
    let b = a.replace("WHILE[#1LT3]", "WHILE[#1LE3]").replace("P2 L2", "P2 L3");
    expect![[r#"
        flow_changed | loop condition | #1 LT 3 | #1 LE 3 | 8 | 8
          loop condition changed from #1 LT 3 to #1 LE 3 at line 8
        flow_changed | passes | 2 | 3 | 13 | 13
          call runs 2 → 3 times at line 13
    "#]]
    .assert_eq(&rows(&changes(a, &b, "fanuc")));
}

#[test]
fn machine_functions_are_named_by_the_dictionary() {
    // LinuxCNC: a digital output and a wait on an input the plan has no kind for; a builder's
    // M-code the dictionary does not know.
    let a = "G21 G90 G17\nT1 M6\nS3000 M3\nM64 P1\nM66 P0 L3 Q5\nG0 X0 Y0 Z5\nG1 Z-2 F400\nX50\nG0 Z5\nM30\n";
    let b = a.replace("M64 P1", "M64 P2").replace("M66 P0 L3 Q5\n", "M66 P0 L4 Q5\nM188\n");
    expect![[r#"
        machine_function_changed | machine function M64: digital output on | P1 | P2 | 4 | 4
          machine function M64 (digital output on) changed from P1 to P2 at line 4
        machine_function_changed | machine function M66: wait on input | L3 | L4 | 5 | 5
          machine function M66 (wait on input) changed from L3 to L4 at line 5
        machine_function_changed | machine function M188: user-defined M codes: a program M1nn on the control's USER_M_PATH, with P and Q |  | M188 | 6 | -
          machine function `M188` added (M188: user-defined M codes: a program M1nn on the control's USER_M_PATH, with P and Q) at line 6
    "#]]
    .assert_eq(&rows(&changes(a, &b, "linuxcnc")));
}

/// The changes of an edit with the analyses' errors given, as the daemon and `ncplan diff`
/// compare them.
fn changes_with_findings(a: &str, b: &str, dialect: &str) -> Vec<Change> {
    let registry = Registry::shipped();
    let d = registry.get(dialect).unwrap();
    let profile = Profile::default();
    let (pa, pb) = (pipeline::analyze(a.as_bytes(), &d, &profile), pipeline::analyze(b.as_bytes(), &d, &profile));
    let faults = |x: &pipeline::Analysis| diff::verdict::faults(&x.source.text, &x.diagnostics);
    diff::compare_with_findings(
        diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d },
        diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d },
        (&faults(&pa), &faults(&pb)),
    )
}

#[test]
fn an_edit_that_fixes_a_block_the_file_does_not_run_says_so() {
    // A LinuxCNC subroutine file (no line of it calls the subroutine, and it has no M2: an
    // error in both versions): the stray `O1` before an assignment (rs274: "unknown control
    // command in o word") and the text after an `if`'s condition ("unexpected character
    // after O-word") stop the control when the subroutine runs; the edit removes both.
    let a = "o<probe> sub\nO1 if [#1 GE 0]\n  O1 #<dir> = 1\nO1 else\n  #<dir> = -1\nO1 endif\no2 if [#2 EQ 1]abort\n  G0 Z1\no2 endif\no<probe> endsub\n";
    let b = a.replace("  O1 #<dir> = 1", "  #<dir> = 1").replace("]abort", "]");
    let got = changes_with_findings(a, &b, "linuxcnc");
    let fixed: Vec<(Option<u32>, String)> = got
        .iter()
        .filter(|c| c.kind == diff::ChangeKind::ProgramFixed)
        .flat_map(|c| c.detail.at.iter().map(|&(o, _)| (o, c.field.clone())))
        .collect();
    assert_eq!(fixed, [(Some(3), "syntax::unknown-address".to_owned()), (Some(7), "syntax::unknown-address".to_owned())], "{}", rows(&got));
    // The reverse edit breaks it at the same places; an unchanged file is no change.
    let back = changes_with_findings(&b, a, "linuxcnc");
    assert!(
        back.iter().any(|c| c.kind == diff::ChangeKind::ProgramBroken && c.detail.at == [(None, Some(3)), (None, Some(7))]),
        "{}",
        rows(&back)
    );
    assert!(changes_with_findings(a, a, "linuxcnc").is_empty());
}

#[test]
fn siemens_machine_moves_calls_by_name_and_loop_bounds_are_told_as_what_runs() {
    // A subprogram whose pass count is a parameter: the analysis cannot run its loop, so the
    // statements tell the edit. `SUPA` moves in machine coordinates, as `G53` does.
    let sub = "PROC WARM(REAL _S, REAL _T)\nDEF INT PASSES\nDEF INT K\nM3 S=_S\nPASSES = _T / 10\nFOR K = 1 TO PASSES\n  G1 SUPA Z-4 F300\n  G1 SUPA X5\nENDFOR\nRET\n";
    let moved = sub.replace("SUPA X5", "SUPA X-5");
    let fewer = sub.replace("_T / 10", "_T / 15");
    let main = "G90 G17 G710\nG0 SUPA Z0\nWARM(3600, 20)\nWARM(7200, 20)\nM5\nM30\n";
    let one_stage = main.replace("WARM(7200, 20)\n", "");
    expect![[r#"
        return_move_changed | statement | X5 | X-5 | 8 | 8
          return move: `X-5` instead of `X5` at line 8
    "#]]
    .assert_eq(&rows(&changes(sub, &moved, "siemens")));
    expect![[r#"
        flow_changed | loop bound (via PASSES) | _T/10 | _T/15 | 5 | 5
          loop bound (via PASSES) changed from _T/10 to _T/15 at line 5
    "#]]
    .assert_eq(&rows(&changes(sub, &fewer, "siemens")));
    expect![[r#"
        flow_changed | call | WARM(7200,20) |  | - | 4
          call WARM(7200,20) removed at original line 4
    "#]]
    .assert_eq(&rows(&changes(main, &one_stage, "siemens")));
}

#[test]
fn features_known_from_unlike_stocks_are_not_compared() {
    // The same face milled with and without its BLK FORM: with the stock the cut is clipped to
    // it (an open pocket, one layer 1 mm deep), without it the face is what the tool swept (a
    // planar face, its depth unknown). The kinds and sizes differ by knowledge: only the
    // removed statements are told.
    let a = "0 BEGIN PGM FACE MM\n1 BLK FORM 0.1 Z X+0 Y+0 Z-20\n2 BLK FORM 0.2 X+100 Y+50 Z+0\n3 TOOL CALL 1 Z S2000\n4 L Z+50 R0 FMAX M3\n5 L X-30 Y+10 R0 FMAX\n6 L Z-1 R0 FMAX\n7 L X+130 F800\n8 L Y+40\n9 L X-30\n10 L Z+50 FMAX\n11 END PGM FACE MM\n";
    let b: String = a.lines().filter(|l| !l.contains("BLK FORM")).map(|l| format!("{l}\n")).collect();
    let got = changes(a, &b, "heidenhain");
    assert!(
        !got.iter().any(|c| matches!(c.kind, diff::ChangeKind::FeatureChanged | diff::ChangeKind::AxialDepthChanged)),
        "{}",
        rows(&got)
    );
    assert!(got.iter().any(|c| c.original_line == Some(2)) && got.iter().any(|c| c.original_line == Some(3)), "{}", rows(&got));
}

#[test]
fn a_global_the_file_does_not_read_is_told_for_what_runs_after() {
    // LinuxCNC: a named parameter whose name starts with `_` is global; set and not read here,
    // it is for the subroutines and programs that run after (a flag other probing subroutines
    // read). A local one read by nothing stays the statement.
    let a = "#<_paranoid> = 0\n#<note> = 1\nG21 G90\nG0 X0 Y0 Z5\nM2\n";
    let b = a.replace("#<_paranoid> = 0", "#<_paranoid> = 1").replace("#<note> = 1", "#<note> = 2");
    expect![[r#"
        global_variable_changed | variable #<_PARANOID> | 0 | 1 | 1 | 1
          global variable `#<_PARANOID>` 0 → 1, for the subroutines and programs that run after (this file does not read it) at line 1
        statement_changed | variable #<NOTE> | 1 | 2 | 2 | 2
          variable `#<NOTE>` set to 2 instead of 1 at line 2
    "#]]
    .assert_eq(&rows(&changes(a, &b, "linuxcnc")));
}

#[test]
fn a_numbered_global_the_file_does_not_read_is_told_for_what_runs_after() {
    // LinuxCNC's #31-#5000 are global (a probing subroutine's result for the next one);
    // #1-#30 are a subroutine's own.
    let a = "#1000 = 0\n#5 = 1\nG21 G90\nG0 X0 Y0 Z5\nM2\n";
    let b = a.replace("#1000 = 0", "#1000 = 1").replace("#5 = 1", "#5 = 2");
    expect![[r#"
        global_variable_changed | variable #1000 | 0 | 1 | 1 | 1
          global variable `#1000` 0 → 1, for the subroutines and programs that run after (this file does not read it) at line 1
        statement_changed | variable #5 | 1 | 2 | 2 | 2
          variable `#5` set to 2 instead of 1 at line 2
    "#]]
    .assert_eq(&rows(&changes(a, &b, "linuxcnc")));
    // Fanuc's common variables, #100-#999, shared by the main program and every macro.
    let a = "O1000\n#500 = 1\n#1 = 1\nG21 G90\nG0 X0 Y0 Z5\nM30\n";
    let b = a.replace("#500 = 1", "#500 = 2").replace("#1 = 1", "#1 = 2");
    expect![[r#"
        global_variable_changed | variable #500 | 1 | 2 | 2 | 2
          global variable `#500` 1 → 2, for the subroutines and programs that run after (this file does not read it) at line 2
        statement_changed | variable #1 | 1 | 2 | 3 | 3
          variable `#1` set to 2 instead of 1 at line 3
    "#]]
    .assert_eq(&rows(&changes(a, &b, "fanuc")));
    // Siemens R parameters are the channel's, read by the programs and cycles run after.
    let a = "R10=5\nG17 G90 G71\nG0 X0 Y0 Z5\nM30\n";
    let b = a.replace("R10=5", "R10=6");
    expect![[r#"
        global_variable_changed | variable R10 | 5 | 6 | 1 | 1
          global variable `R10` 5 → 6, for the subroutines and programs that run after (this file does not read it) at line 1
    "#]]
    .assert_eq(&rows(&changes(a, &b, "siemens")));
}

#[test]
fn lnc_comments_global_variables_and_block_statements_are_read_as_the_control_reads_them() {
    // LNC-M: `//` comments (the text after them is no program), `@` global variables apart
    // from the local `#` ones, C-style operators in a block IF … END_IF, and a call's repeat
    // count told as how often the subprogram runs.
    let a = "%\nO1 // warm up\n#1 = @100 // pass count\nIF[#1 == 0 && @5 != 1]\n  #1 = 2\nEND_IF\nG21 G90 G17\nT1 M6\nS2000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F300 // plunge\nM98 P2 L2\nG0 Z50\nM30\n%\nO2\nG0 Z5\nM99\n%\n";
    let comments = a.replace("// warm up", "// warm-up, slowly").replace("// plunge", "// plunge to depth");
    assert!(changes(a, &comments, "lnc").is_empty(), "{}", rows(&changes(a, &comments, "lnc")));
    let b = a.replace("F300 // plunge", "F250 // plunge").replace("P2 L2", "P2 L3");
    expect![[r#"
        feed_changed | feed | F300 | F250 | 11 | 11
          feed changed from F300 to F250 at line 11
        flow_changed | passes | 2 | 3 | 12 | 12
          call runs 2 → 3 times at line 12
    "#]]
    .assert_eq(&rows(&changes(a, &b, "lnc")));
}

/// LNC's `/* ... */` (MACRO manual): the comment ends at `*/` and the block's code goes on
/// after it on the same line; one not closed on its line is a diagnostic.
#[test]
fn lnc_block_comments_end_at_their_two_character_close() {
    let registry = Registry::shipped();
    let d = registry.get("lnc").unwrap();
    let profile = Profile::default();
    let a = "O1\nG21 G90 G17\nT1 M6\nS2000 M3\nG0 X0 Y0 Z5\nG1 /* plunge */ Z-1 F300\nG0 Z50\nM30\n";
    let errors = |t: &str| {
        pipeline::analyze(t.as_bytes(), &d, &profile)
            .diagnostics
            .iter()
            .filter(|x| x.is_error())
            .map(|x| x.code.as_str().to_owned())
            .collect::<Vec<_>>()
    };
    assert!(errors(a).is_empty(), "{:?}", errors(a));
    // Comment text edited: silent; the code after `*/` edited: told as what it does.
    let comment = a.replace("/* plunge */", "/* plunge to depth (slowly) */");
    assert!(changes(a, &comment, "lnc").is_empty(), "{}", rows(&changes(a, &comment, "lnc")));
    let b = a.replace("*/ Z-1 F300", "*/ Z-1 F250");
    expect![[r#"
        feed_changed | feed | F300 | F250 | 6 | 6
          feed changed from F300 to F250 at line 6
    "#]]
    .assert_eq(&rows(&changes(a, &b, "lnc")));
    // Not closed on its line: the rest of the line is comment, and the control's reader says so.
    let open = a.replace("/* plunge */", "/* plunge");
    assert_eq!(errors(&open), ["syntax::unterminated-comment"]);
}

/// A subroutine beside the program, for [`diff::follow_calls`].
struct Beside(&'static str, &'static str);

impl ncplan::interp::ProgramSource for Beside {
    fn load(&self, name: &str) -> Option<String> {
        (name == self.0).then(|| self.1.to_owned())
    }
}

/// The changes from `a` to `b`, read in `dialect`, with the calls followed into `sub`.
fn diff_following(dialect: &str, sub: &Beside, a: &str, b: &str) -> Vec<Change> {
    let d = Registry::shipped().get(dialect).unwrap();
    let profile = Profile::default();
    let (pa, pb) = (pipeline::analyze(a.as_bytes(), &d, &profile), pipeline::analyze(b.as_bytes(), &d, &profile));
    let edited = diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d };
    let mut got = diff::compare(diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d }, edited);
    diff::follow_calls(&mut got, edited, sub);
    got
}

/// A call's argument changed in place is told as what the parameter it binds does in the
/// subroutine in another file; a call whose argument count changed is left as statements,
/// since every later argument binds another parameter.
#[test]
fn call_arguments_followed_into_a_subroutine_beside_the_program() {
    let sub = Beside("probe", "o<probe> sub\n#<fast> = #2\nG91 G38.2 X[#1] F[#<fast>]\no<probe> endsub\nM2\n");
    let run = |a: &str, b: &str| diff_following("linuxcnc", &sub, a, b);
    let got = run("G21\no<probe> call [10] [300]\nM2\n", "G21\no<probe> call [10] [150]\nM2\n");
    // The subroutine's `G38.2 … F[#<fast>]`: the probing feed.
    let feed = got.iter().find(|c| c.kind == ChangeKind::ProbingChanged).unwrap_or_else(|| panic!("{got:#?}"));
    assert!(feed.field.contains("argument 2, #2 in probe"), "{}", feed.field);
    assert_eq!((feed.before.as_str(), feed.after.as_str(), feed.line), ("300", "150", Some(2)));
    // An argument inserted before it: the binding shifts, nothing is claimed about it.
    let got = run("G21\no<probe> call [10] [300]\nM2\n", "G21\no<probe> call [5] [10] [300]\nM2\n");
    assert!(got.iter().all(|c| c.kind != ChangeKind::ProbingChanged), "{got:#?}");
    assert!(!got.is_empty());
    // An argument appended at the end shifts nothing: it binds #2, which sets the feed.
    let got = run("G21\no<probe> call [10]\nM2\n", "G21\no<probe> call [10] [150]\nM2\n");
    let feed = got.iter().find(|c| c.kind == ChangeKind::ProbingChanged).unwrap_or_else(|| panic!("{got:#?}"));
    assert!(feed.field.contains("argument 2, #2 in probe"), "{}", feed.field);
    assert_eq!((feed.before.as_str(), feed.after.as_str()), ("none", "150"));
    // Appended with the first changed in place: both followed, each to its own parameter.
    let got = run("G21\no<probe> call [10]\nM2\n", "G21\no<probe> call [12] [150]\nM2\n");
    assert!(got.iter().any(|c| c.kind == ChangeKind::ProbingChanged), "{got:#?}");
    // The last argument taken off: #2 no longer passed, told as the feed it set.
    let got = run("G21\no<probe> call [10] [300]\nM2\n", "G21\no<probe> call [10]\nM2\n");
    let feed = got.iter().find(|c| c.kind == ChangeKind::ProbingChanged).unwrap_or_else(|| panic!("{got:#?}"));
    assert_eq!((feed.before.as_str(), feed.after.as_str()), ("300", "none"));
}

/// A subroutine in a subfolder of the program's folder (ngcgui's `utilitysubs/`) is found,
/// after one beside the program; the configured program directory's own files only.
#[test]
fn subroutines_are_found_in_the_program_folders_subfolders() {
    use ncplan::interp::ProgramSource;
    let root = std::env::temp_dir().join(format!("ncplan-subfolders-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    std::fs::create_dir_all(root.join("utilitysubs")).unwrap();
    std::fs::create_dir_all(root.join("b")).unwrap();
    std::fs::write(root.join("utilitysubs/loadtool.ngc"), "o<loadtool> sub\no<loadtool> endsub\n").unwrap();
    std::fs::write(root.join("b/probe.ngc"), "(deeper)\n").unwrap();
    std::fs::write(root.join("probe.ngc"), "(beside)\n").unwrap();
    let tree = ncplan::config::DirPrograms { dir: root.clone(), max_bytes: 1 << 20, subfolders: true };
    assert!(tree.load("loadtool").is_some_and(|t| t.starts_with("o<loadtool> sub")));
    assert_eq!(tree.load("probe").as_deref(), Some("(beside)\n"));
    assert_eq!(tree.load("missing"), None);
    let flat = ncplan::config::DirPrograms { dir: root.clone(), max_bytes: 1 << 20, subfolders: false };
    assert_eq!(flat.load("loadtool"), None);
    let _ = std::fs::remove_dir_all(&root);
}

/// A Fanuc macro call's argument letter changed: followed to the local it sets (`B` is `#2`)
/// in the program it calls, found beside the program.
#[test]
fn macro_call_argument_followed_into_the_program_it_calls() {
    let sub = Beside("O9810", "O9810\nG0 Z5.\nG1 Z-#2 F100.\nG0 Z5.\nM99\n");
    let got = diff_following("fanuc", &sub, "O1\nG21 G90\nG65 P9810 B2.\nM30\n", "O1\nG21 G90\nG65 P9810 B3.\nM30\n");
    let depth = got.iter().find(|c| c.kind == ChangeKind::DepthChanged).unwrap_or_else(|| panic!("{got:#?}"));
    assert!(depth.field.contains("G65 argument B, #2 in O9810"), "{}", depth.field);
    assert_eq!((depth.before.as_str(), depth.after.as_str(), depth.line), ("2.", "3.", Some(3)));
}

/// A variable newly set (or set to another value) that this program only passes to a
/// subroutine beside it is followed there, through the variables the parameter feeds, to the
/// words it sets (`#4` → `#<len>` → `#<tip>` → `#<angle>` → `M68 … Q`).
#[test]
fn a_variable_passed_to_a_subroutine_is_told_as_what_it_feeds_there() {
    let sub = Beside(
        "nozzle",
        "o<nozzle> sub\n#<len> = #1\n#<tip> = [#<len> + 10]\n#<raw> = [#<tip> * 2]\n#<angle> = [#<raw> + 5]\nM68 E20 Q[#<angle>]\no<nozzle> endsub\nM2\n",
    );
    let run = |a: &str, b: &str| diff_following("linuxcnc", &sub, a, b);
    let got = run("G21\n#<l> = 0\no<nozzle> call [#<l>]\nM2\n", "G21\n#<l> = #5403\no<nozzle> call [#<l>]\nM2\n");
    expect![[r#"
        machine_function_changed | machine function M68: analog output (via #<L>, O<NOZZLE> argument 1, #1 in nozzle) | 0 | #5403 | 2 | 2
          machine function M68 (analog output) (via #<L>, O<NOZZLE> argument 1, #1 in nozzle) changed from 0 to #5403 at line 2
    "#]]
    .assert_eq(&rows(&got));
    // A variable the call does not pass stays the statement that names it.
    let got = run("G21\n#<l> = 0\n#<m> = 1\no<nozzle> call [#<l>]\nM2\n", "G21\n#<l> = 0\n#<m> = 2\no<nozzle> call [#<l>]\nM2\n");
    assert!(got.iter().all(|c| c.kind == ChangeKind::StatementChanged), "{}", rows(&got));
}

/// A subroutine's return value (LinuxCNC `endsub [value]` sets `#<_value>` for the caller)
/// given, changed or taken away is told as that value, not as a statement.
#[test]
fn a_return_value_is_told_as_the_value_the_caller_reads() {
    let a = "o<edge> sub\n#<e> = [#5061 + 1]\no<edge> endsub\nM2\n";
    let b = "o<edge> sub\n#<e> = [#5061 + 1]\no<edge> endsub [#<e>]\nM2\n";
    expect![[r#"
        global_variable_changed | return value #<_VALUE> |  | #<E> | 3 | 3
          the subroutine now returns #<E> at line 3: `#<_VALUE>` for the program that called it
    "#]]
    .assert_eq(&rows(&changes(a, b, "linuxcnc")));
    let c = b.replace("endsub [#<e>]", "endsub [#<e> * 2]");
    let got = changes(b, &c, "linuxcnc");
    assert_eq!(got.len(), 1, "{}", rows(&got));
    assert_eq!((got[0].kind, got[0].before.as_str(), got[0].after.as_str()), (ChangeKind::GlobalVariableChanged, "#<E>", "#<E>*2"));
}

/// An assignment added or removed is followed to the statements after it that both programs
/// have (they now read another value); a variable renamed with its uses, or read only before
/// the assignment, is no such change.
#[test]
fn an_assignment_added_is_told_through_the_unchanged_uses_after_it() {
    let a = "G21 G90\nT1 M6\nS1000 M3\n#<f> = 200\nG0 X0 Y0 Z5\nG1 Z-1 F[#<f>]\nG1 X10\nG0 Z5\nM2\n";
    let b = a.replace("G1 X10\n", "#<f> = 150\nG1 X10 F[#<f>]\n");
    // The feed word itself changed at the move: told there, the assignment before it too.
    let got = changes(a, &b, "linuxcnc");
    assert!(got.iter().any(|c| c.kind == ChangeKind::FeedChanged), "{}", rows(&got));
    // Added before an unchanged move that reads it: the feed it gives there.
    let a = "G21 G90\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F[#<f>]\nG0 Z5\nM2\n";
    let b = a.replace("G0 X0 Y0 Z5\n", "G0 X0 Y0 Z5\n#<f> = 150\n");
    let got = changes(a, &b, "linuxcnc");
    let feed = got.iter().find(|c| c.field.contains("(via #<F>)")).unwrap_or_else(|| panic!("{}", rows(&got)));
    assert_eq!((feed.before.as_str(), feed.after.as_str(), feed.line), ("not set", "150", Some(5)));
    // Renamed with every use: no use both programs have reads either name.
    let a = "G21 G90\nT1 M6\nS1000 M3\n#<f> = 200\nG0 X0 Y0 Z5\nG1 Z-1 F[#<f>]\nG0 Z5\nM2\n";
    let b = a.replace("#<f>", "#<feed>");
    let got = changes(a, &b, "linuxcnc");
    assert!(got.iter().all(|c| !c.field.contains("(via")), "{}", rows(&got));
}

/// A macro call's letters are the macro's arguments (locals), never the modal feed, spindle
/// speed or tool, whether the macro is found or not (issue 41, r277: `G65 P110002 … F200.`
/// removed is a skip feed passed to a probing macro, not "feed removed").
#[test]
fn a_macro_call_letter_is_an_argument_not_a_feed() {
    let a = "O1\nG21 G90 G54\nT1 M6\nS1000 M3\nG0 X0 Y0 Z10.\nG65 P9001 Y183. Z49. F200. S300.\nG1 X10. F100.\nM30\n";
    let b = a.replace(" F200. S300.", "");
    let got = changes(a, &b, "fanuc");
    assert!(!got.iter().any(|c| matches!(c.kind, ChangeKind::FeedChanged | ChangeKind::SpindleSpeedChanged)), "{}", rows(&got));
    assert!(got.iter().any(|c| c.line == Some(6) && c.before.contains("F200.")), "{}", rows(&got));
}

/// A Siemens frame's words (`TRANS … B= C=`) shift the origin: no rotary axis moves (issue 41,
/// r286).
#[test]
fn a_frame_with_rotary_words_is_no_rotary_move() {
    let a = "G54 G90 G17\nT1 D1\nM6\nS1000 M3\nG0 X0 Y0 Z10\nG1 X10 F100\nM30\n";
    let b = a.replace("G0 X0 Y0 Z10\n", "G0 X0 Y0 Z10\nTRANS X=1 Z=2 B=3 C=4\n");
    let got = changes(a, &b, "siemens");
    assert!(!got.iter().any(|c| c.kind == ChangeKind::RotaryMoveChanged), "{}", rows(&got));
    // The plan sees what the shift does to the moves after it; the statement is no rotary move.
    assert!(got.iter().any(|c| c.line == Some(6)), "{}", rows(&got));
}

/// A LinuxCNC global read before the file sets it (`#<_td>`) may come from another program on
/// the machine (globals persist between programs): the edit that reads it breaks nothing
/// (issue 41, r279). A local read before it is set still does.
#[test]
fn a_global_read_before_it_is_set_breaks_nothing() {
    let a = "G21 G90\n#<tr> = 3\nG0 X#<tr> Y0 Z5\nM2\n";
    let broken = |b: &str| changes_with_findings(a, b, "linuxcnc").into_iter().any(|c| c.kind == ChangeKind::ProgramBroken);
    assert!(!broken(&a.replace("#<tr> = 3", "#<tr> = [#<_td>/2]")));
    assert!(broken(&a.replace("#<tr> = 3", "#<tr> = [#<td>/2]")));
}

/// A Siemens `TRANS` added whose axis words are assignments (`X=gX-cyR*fR B=gB`): an origin
/// shift, where the plan cannot see it (issue 41, r286).
#[test]
fn a_frame_of_variables_is_an_origin_shift() {
    let a = "DEF REAL GX=1\nG54 G90 G17\nT1 D1\nM6\nS1000 M3\nG0 X0 Y0 Z10\nM30\n";
    let b = a.replace("M30\n", "TRANS X=GX Z=GX B=GX C=GX\nM30\n");
    let got = changes(a, &b, "siemens");
    assert!(!got.iter().any(|c| c.kind == ChangeKind::RotaryMoveChanged), "{}", rows(&got));
    assert!(got.iter().any(|c| c.kind == ChangeKind::WorkOffsetChanged && c.line == Some(7)), "{}", rows(&got));
    // The keyword is told with its shift, not as a statement of its own.
    assert!(!got.iter().any(|c| c.kind == ChangeKind::StatementChanged), "{}", rows(&got));
}

/// A value passed to a program called by name that the analysis cannot follow (the
/// grinder's `F_TP_GRINDING_PARAMETERS`, not beside the program) is that parameter's change,
/// named by its position, whether the argument itself or a variable it reads changed; a
/// two-letter variable the dictionary names no address (`WR`, not `CR`) is a variable
/// (issue 41, r283–r285). An argument inserted before others binds nothing claimable.
#[test]
fn a_value_passed_to_a_called_program_is_that_parameter_s_change() {
    let none = Beside("other", "PROC OTHER\nM17\n");
    let changes = |a: &str, b: &str, d: &str| diff_following(d, &none, a, b);
    let a = "DEF REAL WR, AL1\nWR = 572.86 / 2\nAL1 = 75.1238\nG54 G90\nGRIND_SETUP(WR, 2, AL1)\nM30\n";
    let got = changes(a, &a.replace("572.86", "572.50"), "siemens");
    let want = "cycle_parameter_changed | parameter 1 of GRIND_SETUP (via WR) | 572.86/2 | 572.5/2 | 2 | 2";
    assert!(rows(&got).lines().any(|l| l == want), "{}", rows(&got));
    let got = changes(a, &a.replace("AL1 = 75.1238", "AL1 = 75.1328"), "siemens");
    assert!(got.iter().any(|c| c.field == "parameter 3 of GRIND_SETUP (via AL1)"), "{}", rows(&got));
    let got = changes(a, &a.replace("(WR, 2, AL1)", "(WR, 3, AL1)"), "siemens");
    assert!(got.iter().any(|c| c.kind == ChangeKind::CycleParameterChanged && c.field == "parameter 2 of GRIND_SETUP"), "{}", rows(&got));
    assert!(got.iter().all(|c| c.phrase().contains("GRIND_SETUP")), "the name as written: {}", rows(&got));
    let got = changes(a, &a.replace("(WR, 2, AL1)", "(WR, 7, 2, AL1)"), "siemens");
    assert!(!got.iter().any(|c| c.kind == ChangeKind::CycleParameterChanged), "{}", rows(&got));
}

/// A count loop's count (LinuxCNC `o100 repeat [5]`) changed is told as its passes, written
/// or through the variable it reads; a count the analysis cannot read as a number stays the
/// loop's condition (issue 41: "loop runs 5 → 6 times").
#[test]
fn a_count_loop_s_passes() {
    let a = "G21 G90\nT1 M6\nS1000 M3\n#<n> = 5\no100 repeat [5]\nG91 G1 Z-1 F100\nG90 G1 X10\no100 endrepeat\nM2\n";
    let got = changes(a, &a.replace("repeat [5]", "repeat [6]"), "linuxcnc");
    let row = got.iter().find(|c| c.field == "loop passes").unwrap_or_else(|| panic!("{}", rows(&got)));
    assert_eq!((row.kind, row.before.as_str(), row.after.as_str(), row.line), (ChangeKind::FlowChanged, "5", "6", Some(5)));
    let by_var = a.replace("repeat [5]", "repeat [#<n>]");
    let got = changes(&by_var, &by_var.replace("#<n> = 5", "#<n> = 6"), "linuxcnc");
    assert!(got.iter().any(|c| c.kind == ChangeKind::FlowChanged && c.field == "loop passes (via #<N>)"), "{}", rows(&got));
    let got = changes(&by_var, &by_var.replace("repeat [#<n>]", "repeat [#<n>+1]"), "linuxcnc");
    assert!(got.iter().any(|c| c.field == "loop condition"), "{}", rows(&got));
}

/// A zero written with a sign (`J-0.000`, a CAM re-post's rounding) is the same number as
/// `J0.000`: no change (issue 41, held-back pair r297).
#[test]
fn a_signed_zero_is_zero() {
    let a = "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG2 X10 Y0 I5 J-0.000 F200\nG0 Z5\nM2\n";
    let got = changes(a, &a.replace("J-0.000", "J0.000"), "linuxcnc");
    assert!(got.is_empty(), "{}", rows(&got));
    let got = changes(a, &a.replace("J-0.000", "J-0.5"), "linuxcnc");
    assert!(!got.is_empty());
}

/// A height added to or removed from a rapid before the first cut (`G0 G54 X0 Y0` → `G0 G54
/// X0 Y0 Z0`: the tool now goes down to the part's top first) is a clearance change, told as
/// the rapid height at its line, where the plan has no cut that changed (held7 r309, r313,
/// r314). A rapid height through a variable is left to the variable's rule.
#[test]
fn a_rapid_height_added_or_removed_is_a_clearance_change() {
    let a = "%\nO1000\nG20 G90 G17 G40 G80\nT1 M6\nG0 G54 X0 Y0\nG43 H1 Z0.1 S1200 M3\nG81 X1 Y1 Z-0.2 R0.1 F5\nG80\nG0 Z1\nM30\n%\n";
    let b = a.replace("G0 G54 X0 Y0\n", "G0 G54 X0 Y0 Z0\n");
    let got = changes(a, &b, "fanuc");
    assert_eq!(got.len(), 1, "{}", rows(&got));
    assert_eq!((got[0].kind.as_str(), got[0].field.as_str(), got[0].after.as_str()), ("clearance_changed", "rapid height", "Z0"));
    assert_eq!(got[0].phrase(), "rapid height (clearance, approach) `Z0` added at line 5");
    let got = changes(&b, a, "fanuc");
    assert_eq!(got.len(), 1, "{}", rows(&got));
    assert!(got[0].phrase().starts_with("rapid height (clearance, approach) `Z0` removed"), "{}", rows(&got));
}

/// A label renamed one to one over the whole program is no change: an O-word subroutine with
/// its calls (`o<a>` → `o<b>`, `o100` → `o200`), a jump target with its block number (`GOTO 10`
/// → `GOTO 20` with `N10` → `N20`). A call renamed alone (its subroutine in another file), or
/// a jump sent to another block that was there already, is a change (held7 r306).
#[test]
fn a_label_renamed_with_every_use_is_no_change() {
    let a =
        "o<a> sub\n  G0 Z[#1]\no<a> endsub\no100 sub\n  G1 X1 F100\no100 endsub\nG0 X0 Y0\no<a> call [5]\no100 call\no<a> call [6]\nM2\n";
    let b = a.replace("o<a>", "o<b>").replace("o100", "o200");
    let got = changes(a, &b, "linuxcnc");
    assert!(got.is_empty(), "{}", rows(&got));
    // Only the calls renamed: they call subroutines this file does not have.
    let calls_only = "G0 X0 Y0\no<a> call [5]\nM2\n";
    let got = changes(calls_only, &calls_only.replace("o<a>", "o<b>"), "linuxcnc");
    assert!(!got.is_empty());
    // A jump with the block it names, and one sent to another block that both programs have.
    let f = "%\nO1000\n#1=0\nN10 G0 X#1\n#1=#1+1\nIF[#1LT3]GOTO10\nN30 G0 Z5\nM30\n%\n";
    let got = changes(f, &f.replace("N10", "N20").replace("GOTO10", "GOTO20"), "fanuc");
    assert!(got.is_empty(), "{}", rows(&got));
    let got = changes(f, &f.replace("GOTO10", "GOTO30"), "fanuc");
    assert!(!got.is_empty());
    // A subprogram renumbered with its M98-less reference (`P1` alone on its block).
    let m = "G0 X0 Y0\nN70 P0001 (call)\nM2\n;\nO0001 (init)\nG90\nM99\n";
    let got = changes(m, &m.replace("P0001", "P1000").replace("O0001", "O1000"), "linuxcnc");
    assert!(got.is_empty(), "{}", rows(&got));
}

/// A comment after an empty assignment (`#4= (FEED)`) is a comment, never the value: both
/// controls stop at the empty value, and an edit of the comment is no change; an edit that
/// empties the value breaks the program and says so first (held7 r300).
#[test]
fn a_comment_after_an_empty_assignment_is_no_value() {
    let a = "#2=20 (SPEED)\n#4= (FEED)\nG0 X0 Y0\nG1 X1 F[#2]\nM2\n";
    let got = changes_with_findings(a, &a.replace("(FEED)", "(REVOLUTIONS PER MINUTE)"), "linuxcnc");
    assert!(got.is_empty(), "{}", rows(&got));
    // A comment nested in it now: the control stopped at that statement before too.
    let got = changes_with_findings(a, &a.replace("(FEED)", "(RPM (SPEED))"), "linuxcnc");
    assert!(!got.iter().any(|c| matches!(c.kind, diff::ChangeKind::ProgramBroken | diff::ChangeKind::ProgramFixed)), "{}", rows(&got));
    let got = changes_with_findings(a, &a.replace("#2=20 (SPEED)", "#2= (SPEED)"), "linuxcnc");
    let first = got.iter().position(|c| c.kind == diff::ChangeKind::ProgramBroken && c.field == "syntax::malformed-expression");
    assert_eq!(first.map(|k| got[k].line), Some(Some(1)), "{}", rows(&got));
    // Listed first, with the other stops the edit brings in (the feed now unset).
    assert!(got[..first.unwrap_or(0)].iter().all(|c| c.kind == diff::ChangeKind::ProgramBroken), "{}", rows(&got));
}

/// An error the edit brings in at an edited line is told there, not at an unchanged line with
/// an error of the same kind further on (held7 r300).
#[test]
fn an_error_brought_in_is_told_at_its_own_line() {
    let a = "(A (nested) comment)\nG0 X0 Y0\nG1 X1 F100\n(B (nested) comment)\nM2\n";
    let b = a.replace("G1 X1 F100", "G1 X1 F100 (C (nested) comment)");
    let got = changes_with_findings(a, &b, "linuxcnc");
    let broken: Vec<Option<u32>> = got.iter().filter(|c| c.kind == diff::ChangeKind::ProgramBroken).map(|c| c.line).collect();
    assert_eq!(broken, [Some(3)], "{}", rows(&got));
}

/// Moves that read a value the file never sets (a global another program sets): the toolpath
/// change is told without the sizes the analysis would make up for it (held6 r279).
#[test]
fn a_toolpath_from_values_the_file_never_sets_has_no_size() {
    let a = "G20 G90\nT1 M6\nS1000 M3\n#<tr> = [#5410/2]\nG0 X[2+#<tr>] Y0\nG0 Z0\nG1 X[3+#<tr>] Z-0.25 F10\nG1 Y1\nG1 X[2+#<tr>]\nM2\n";
    let b = a.replace("#5410/2", "#<_td>/2");
    let got = changes_with_findings(a, &b, "linuxcnc");
    let paths: Vec<&Change> = got.iter().filter(|c| c.kind == diff::ChangeKind::ToolpathChanged && !c.field.starts_with("moves")).collect();
    assert_eq!(paths.len(), 1, "{}", rows(&got));
    assert!(paths[0].deviation.is_none() && paths[0].region.is_none(), "{}", rows(&got));
    assert!(paths[0].phrase().contains("no size is told"), "{}", rows(&got));
    assert!(!got.iter().any(|c| c.kind == diff::ChangeKind::StartPointMoved), "{}", rows(&got));
}

/// The changes from `a` to `b` with each call whose argument count changed compared with its
/// subroutine as each version has it (`old`, `new`).
fn diff_rebinding(old: &Beside, new: &Beside, a: &str, b: &str) -> Vec<Change> {
    let d = Registry::shipped().get("linuxcnc").unwrap();
    let profile = Profile::default();
    let (pa, pb) = (pipeline::analyze(a.as_bytes(), &d, &profile), pipeline::analyze(b.as_bytes(), &d, &profile));
    let (oa, eb) = (
        diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d },
        diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d },
    );
    let mut got = diff::compare(oa, eb);
    diff::follow_rebound_calls(&mut got, (oa, old), (eb, new));
    diff::follow_calls(&mut got, eb, new);
    let missing = diff::unaccounted(oa, eb, &got);
    assert!(missing.is_empty(), "differing statements no change names: {missing:?}\n{}", rows(&got));
    got
}

/// A call whose argument list shrinks together with its subroutine's parameters (r159): the
/// same values reach the same parameters, one statement change says so; the same call against
/// a subroutine that did not change (r265) binds other values, each told once as what it feeds.
#[test]
fn a_call_rebound_with_its_subroutine_is_compared_by_what_reaches_it() {
    let old_sub = "o<probe> sub\n#<fast> = #2\n#<z_clear> = #3\n#<slow> = #4\nG0 Z[#<z_clear>]\nG1 Z-1 F[#<fast>]\nG1 Z-2 F[#<slow>]\no<probe> endsub\nM2\n";
    let new_sub = "o<probe> sub\n#<z_clear> = #2\n#<slow> = #3\nG0 Z[#<z_clear>]\nG1 Z-2 F[#<slow>]\no<probe> endsub\nM2\n";
    let a = "G0 X0 Y0\no<probe> call [#1][#2][#3][#4]\nM2\n";
    let b = "G0 X0 Y0\no<probe> call [#1][#3][#4]\nM2\n";
    let got = diff_rebinding(&Beside("probe", old_sub), &Beside("probe", new_sub), a, b);
    assert_eq!(got.len(), 1, "{}", rows(&got));
    assert_eq!(got[0].field, "call O<PROBE> rebound", "{}", rows(&got));
    // The subroutine unchanged: its second and third parameters now get #3 and #4.
    let got = diff_rebinding(&Beside("probe", new_sub), &Beside("probe", new_sub), a, b);
    let told: Vec<(&str, &str, &str)> = got.iter().map(|c| (c.kind.as_str(), c.before.as_str(), c.after.as_str())).collect();
    assert_eq!(told, [("feed_changed", "#3", "#4"), ("clearance_changed", "#2", "#3")], "{}", rows(&got));
}

/// Issue 41's wording: an argument inserted is told as such (not as a shift of every later
/// one), an expression rewritten to the same value is silent, and a long run of changed
/// statements keeps its line range.
#[test]
fn arguments_inserted_same_values_and_long_hunks_are_told_plainly() {
    let a = "G0 X0 Y0\no<sub> call [1][2][3][4]\nM2\n";
    let got = changes(a, &a.replace("[1][2][3][4]", "[1][9][2][3][4]"), "linuxcnc");
    assert_eq!(got.len(), 1, "{}", rows(&got));
    assert!(got[0].phrase().contains("argument 2 (9) inserted"), "{}", rows(&got));
    let s = "G0 X0 Y0\nG1 X286.43 F100\nM2\n";
    let got = changes(s, &s.replace("X286.43", "X[572.86/2]"), "linuxcnc");
    assert!(got.is_empty(), "{}", rows(&got));
    let long_a: String = (0..40).map(|i| format!("G1 X{i} Y0 F100\n")).collect::<String>() + "M2\n";
    let long_b: String = (0..40).map(|i| format!("G1 X{i} Y1 F100\n")).collect::<String>() + "M2\n";
    let got = changes(&format!("G0 X0 Y0\n{long_a}"), &format!("G0 X0 Y0\n{long_b}"), "linuxcnc");
    let ranged = got.iter().any(|c| c.phrase().contains("lines 2–41"));
    assert!(ranged, "{}", rows(&got));
}

/// The machine is one across revisions. The original's two arcs have centres that fit only
/// with X read as a radius; the edit makes the second a chamfer, so the edited program alone
/// no longer shows it. Read apart, the edited program's X words would be diameters, its first
/// (unedited) arc an error the edit "breaks", and every size would change. Read as
/// `ncplan diff` reads them, on one machine, the only change is at the edited line.
#[test]
fn what_one_revision_shows_of_the_machine_holds_for_both() {
    let a = "O1000\nG18 G21 G99\nT0101\nG97 S1000 M3\nG0 X20. Z2.\nG1 X10. Z0. F0.2\nG2 X15. Z-5. I5. K0.\nG1 Z-20.\n\
             G2 X20. Z-25. I5. K0.\nG1 Z-40.\nG0 X30.\nG0 Z2.\nM30\n";
    let b = a.replace("G2 X20. Z-25. I5. K0.", "G1 X20. Z-25.");
    let registry = Registry::shipped();
    let d = registry.get("fanuc_lathe").unwrap();
    let profile = Profile::default();
    let apart = pipeline::analyze_plan(b.as_bytes(), &d, &profile);
    assert!(apart.has_errors(), "alone, the edited program reads X as diameters and its first arc fails");
    let (pa, pb) = pipeline::analyze_pair((a.as_bytes().to_vec(), &d, &profile), (b.into_bytes(), &d, &profile));
    assert!(!pb.has_errors(), "{:?}", pb.diagnostics);
    let why = pb.diagnostics.iter().find(|x| x.code == pipeline::Code::XWordsRadius).expect("the edited program says why");
    assert!(why.message.starts_with("read as the other revision shows the machine"), "{}", why.message);
    let got = pipeline::diff(&pa, &d, &pb, &d);
    assert!(!got.is_empty());
    for c in &got {
        assert_ne!(c.kind, ChangeKind::ProgramBroken, "{}", rows(&got));
        assert_eq!(c.line, Some(9), "{}", rows(&got));
    }
}

/// An operator who puts the decimal point on some of a program's whole numbers (`X50` →
/// `X50.`) changes no length: the original, written for calculator-type input, shows the
/// machine reads `X50` as 50 mm, and so both revisions are read. Read apart, the edited
/// program would no longer show it and every length without a point would become µm.
#[test]
fn points_added_to_whole_numbers_change_nothing_on_a_calculator_input_machine() {
    let a = "O1\nG21 G99\nT0101\nG50 S2000\nG96 S200 M3\nG0 X55 Z2\nG1 Z0 F0.2\nX-1.6\nG0 Z2\nX50\n\
             G1 Z-30 F0.25\nX55\nG0 X100 Z50\nM30\n";
    let b = a.replace("G0 X55 Z2", "G0 X55. Z2.").replace("X50\n", "X50.\n").replace("Z-30 ", "Z-30. ").replace("X55\nG0", "X55.\nG0");
    let registry = Registry::shipped();
    let d = registry.get("fanuc_lathe").unwrap();
    let profile = Profile::default();
    let apart = pipeline::analyze_plan(b.as_bytes(), &d, &profile);
    assert!(!apart.diagnostics.iter().any(|x| x.code == pipeline::Code::DecimalInputInferred), "alone, the edit reads in increments");
    let (pa, pb) = pipeline::analyze_pair((a.as_bytes().to_vec(), &d, &profile), (b.into_bytes(), &d, &profile));
    let got = pipeline::diff(&pa, &d, &pb, &d);
    assert!(got.is_empty(), "{}", rows(&got));
}

/// A tilted working plane added where no cut follows it (a program that only positions, as
/// a test of a plane finder does): the statement is still the work plane's change, not a raw
/// statement row, on every control's tilt statement.
#[test]
fn a_tilted_plane_added_without_cuts_is_a_work_plane_change() {
    let a = "0 BEGIN PGM T MM\n1 PLANE RESET TURN FMAX\n2 L Z+0 R0 FMAX M92\n3 END PGM T MM\n";
    let b =
        "0 BEGIN PGM T MM\n1 PLANE RESET TURN FMAX\n2 L Z+0 R0 FMAX M92\n3 PLANE SPATIAL SPA-45 SPB+0 SPC+0 TURN FMAX\n4 END PGM T MM\n";
    let got = changes(a, b, "heidenhain");
    assert_eq!(got.len(), 1, "{}", rows(&got));
    assert_eq!(got[0].kind, ChangeKind::WorkPlaneChanged, "{}", rows(&got));
    assert_eq!(got[0].line, Some(4), "{}", rows(&got));
    assert_eq!(got[0].phrase(), "work plane: `PLANE SPATIAL SPA-45 SPB0 SPC0 TURN FMAX` added at line 4");
    let a = "G17 G90 G54\nG0 X0 Y0 Z50\nM30\n";
    let b = "G17 G90 G54\nG0 X0 Y0 Z50\nG68.2 X0 Y0 Z0 I0 J30 K0\nG53.1\nG69\nM30\n";
    let got = changes(a, b, "fanuc");
    assert!(got.iter().any(|c| c.kind == ChangeKind::WorkPlaneChanged && c.line == Some(3)), "{}", rows(&got));
}

/// The rows naming a variable (`… (via R1)`), as `kind | field | before | after | line`.
fn via_rows(got: &[Change]) -> Vec<String> {
    got.iter()
        .filter(|c| c.field.contains("(via "))
        .map(|c| format!("{} | {} | {} | {} | {:?}", c.kind.as_str(), c.field, c.before, c.after, c.line))
        .collect()
}

#[test]
fn siemens_r_parameters_and_def_variables_are_followed_to_the_depth_they_feed() {
    // Sinumerik: an R parameter in a feed move's Z (`Z=-R1`), and an R parameter and a DEF
    // variable in a drilling cycle's depth argument (CYCLE81 RTP, RFP, SDIS, DP: the
    // Programming Manual's positions). Each is told as the depth, through the variable.
    let moves = "R1=5\nT1 D1\nM6\nS2000 M3\nG0 X0 Y0 Z2\nG1 Z=-R1 F200\nG1 X50\nG0 Z2\nM30\n";
    let got = changes(moves, &moves.replace("R1=5", "R1=8"), "siemens");
    assert_eq!(via_rows(&got), ["depth_changed | cut depth (via R1) | 5 | 8 | Some(1)"], "{}", rows(&got));
    let cycle = "R1=5\nT1 D1\nM6\nS2000 M3\nG0 X0 Y0 Z2\nMCALL CYCLE81(10,0,1,-R1)\nX20\nMCALL\nM30\n";
    let got = changes(cycle, &cycle.replace("R1=5", "R1=8"), "siemens");
    assert_eq!(via_rows(&got), ["depth_changed | CYCLE81 DP (depth) (via R1) | 5 | 8 | Some(1)"], "{}", rows(&got));
    let def = "DEF REAL DEPTH=5\nT1 D1\nM6\nS2000 M3\nG0 X0 Y0 Z2\nMCALL CYCLE81(10,0,1,-DEPTH)\nX20\nMCALL\nM30\n";
    let got = changes(def, &def.replace("DEPTH=5", "DEPTH=8"), "siemens");
    assert_eq!(via_rows(&got), ["depth_changed | CYCLE81 DP (depth) (via DEPTH) | 5 | 8 | Some(1)"], "{}", rows(&got));
    // A variable the cycle does not read (the X of a later hole) is no cycle parameter.
    let x = "R2=20\nT1 D1\nM6\nS2000 M3\nG0 X0 Y0 Z2\nMCALL CYCLE81(10,0,1,-5)\nX=R2\nMCALL\nM30\n";
    let got = changes(x, &x.replace("R2=20", "R2=30"), "siemens");
    assert!(!got.iter().any(|c| c.kind == ChangeKind::CycleParameterChanged), "{}", rows(&got));
}

#[test]
fn heidenhain_q_parameters_are_followed_into_the_cycle_parameter_they_set() {
    // TNC 640 Klartext: Q1 set once and given to cycle 200's Q201 (depth): the depth through Q1.
    let a = "0 BEGIN PGM T MM\n1 Q1 = -15\n2 TOOL CALL 1 Z S2000\n3 L Z+50 R0 FMAX M3\n4 CYCL DEF 200 DRILLING ~\n  Q200=2 ;SET-UP CLEARANCE ~\n  Q201=Q1 ;DEPTH ~\n  Q206=150 ;FEED RATE FOR PLNGNG ~\n  Q202=5 ;PLUNGING DEPTH ~\n  Q210=0 ;DWELL TIME AT TOP ~\n  Q203=+0 ;SURFACE COORDINATE ~\n  Q204=50 ;2ND SET-UP CLEARANCE ~\n  Q211=0 ;DWELL TIME AT DEPTH\n5 L X+10 Y+10 R0 FMAX M99\n6 L Z+50 R0 FMAX M30\n7 END PGM T MM\n";
    let got = changes(a, &a.replace("Q1 = -15", "Q1 = -20"), "heidenhain");
    assert_eq!(via_rows(&got), ["depth_changed | cycle parameter Q201 (depth relative) (via Q1) | -15 | -20 | Some(2)"], "{}", rows(&got));
    // The set-up clearance through QL (a local Q parameter) the same way.
    let b = a.replace("1 Q1 = -15", "1 QL5 = 2").replace("Q200=2 ;", "Q200=QL5 ;").replace("Q201=Q1 ;", "Q201=-15 ;");
    let got = changes(&b, &b.replace("QL5 = 2", "QL5 = 4"), "heidenhain");
    assert_eq!(
        via_rows(&got),
        ["cycle_parameter_changed | cycle parameter Q200 (safety distance) (via QL5) | 2 | 4 | Some(2)"],
        "{}",
        rows(&got)
    );
}

#[test]
fn breaks_and_fixes_are_only_where_the_control_stops_whatever_the_values() {
    // A Fanuc dispatcher: the program's own alarm (`#3000`) reached on a way chosen at a
    // condition on a value the file does not set (#891, set by the caller) stops the control
    // only on that way: no verdict when an edit moves the run towards or away from it.
    let a = "O9000\nIF[#890 NE 1] GOTO3\nM98 P[#891]\nGOTO 9\nN3\n#3000=15(NOT REQUESTED)\nN9\nM99\n";
    let b = a.replace("GOTO 9\n", "");
    let got = changes_with_findings(a, &b, "fanuc");
    assert!(!got.iter().any(|c| matches!(c.kind, ChangeKind::ProgramBroken | ChangeKind::ProgramFixed)), "{}", rows(&got));
    // A jump to a block number the program lacks stops the control when taken, whatever the
    // analysis chose at its condition: an edit that adds the block fixes the program ...
    let a = "O1000\nIF[#101 EQ 1] GOTO 1\nIF[#101 EQ 2] GOTO 2\n#3000=5(STATE)\nN1\nG0 X1\nM99\nN3\nG0 X2\nM99\n";
    let b = a.replace("N3\n", "N2\n");
    let fixed: Vec<(String, Option<u32>)> = changes_with_findings(a, &b, "fanuc")
        .into_iter()
        .filter(|c| c.kind == ChangeKind::ProgramFixed)
        .map(|c| (c.field, c.original_line))
        .collect();
    assert_eq!(fixed, [("flow::missing-label".to_owned(), Some(3))]);
    // ... and one never taken (the same condition just before it jumps first) is none.
    let dead = a.replace("N3\n", "N2\n").replace("IF[#101 EQ 2] GOTO 2\n", "IF[#101 EQ 2] GOTO 2\nIF[#101 EQ 2] GOTO 7\n");
    let got = changes_with_findings(&b, &dead, "fanuc");
    assert!(!got.iter().any(|c| c.kind == ChangeKind::ProgramBroken), "{}", rows(&got));
    // Nor is that jump made reachable by its own condition corrected (state 2 stopped at the
    // alarm before, at the missing block now): the same statement jumped nowhere in both.
    let live = dead.replace("IF[#101 EQ 2] GOTO 7", "IF[#101 EQ 3] GOTO 7");
    let got = changes_with_findings(&dead, &live, "fanuc");
    assert!(!got.iter().any(|c| matches!(c.kind, ChangeKind::ProgramBroken | ChangeKind::ProgramFixed)), "{}", rows(&got));
    // A LinuxCNC subroutine reading a local nobody sets (rs274: "Named parameter
    // #<spindle_on> not defined") is fixed by reading the predefined `#<_spindle_on>`; a
    // conditional `endsub` does not end its body, a one-letter local is a remap's word.
    let a = "o<change> sub\no10 if [#<p> EQ 1]\n  o<change> endsub [1]\no10 endif\no11 if [#<spindle_on> EQ 1]\n  M5\no11 endif\no<change> endsub [1]\nM2\n";
    let b = a.replace("#<spindle_on>", "#<_spindle_on>");
    let got = changes_with_findings(a, &b, "linuxcnc");
    let fixed: Vec<(String, Option<u32>)> =
        got.iter().filter(|c| c.kind == ChangeKind::ProgramFixed).map(|c| (c.before.clone(), c.original_line)).collect();
    assert_eq!(fixed, [("parameter `#<spindle_on>` is used before it is set".to_owned(), Some(5))], "{}", rows(&got));
    // Read only inside a branch (a value decides whether it runs): no verdict.
    let a2 = a.replace("o11 if [#<spindle_on> EQ 1]\n  M5\n", "o11 if [#5400 EQ 1]\n  G0 Z#<spindle_on>\n");
    let b2 = a2.replace("#<spindle_on>", "#<_spindle_on>");
    let got = changes_with_findings(&a2, &b2, "linuxcnc");
    assert!(!got.iter().any(|c| c.kind == ChangeKind::ProgramFixed), "{}", rows(&got));
}

#[test]
fn a_straight_line_written_in_two_pieces_at_its_feed_is_no_change() {
    // Pravar20/Gcode-history's solder strokes, regenerated: in G91 two `G1 Y5 F75` joined into
    // one `G1 Y10 F75` trace the same path at the same feed.
    let a = "G21\nG91\nM3 S9000\nG1 Y10 F2000\nG1 Y-10 F2000\nG1 Y5 F75\nG1 Y5 F75\nG1 Z5 F2000\nG1 X3 Y-10 F2000\nM5\nM2\n";
    let b = a.replace("G1 Y5 F75\nG1 Y5 F75\n", "G1 Y10 F75\n");
    assert_eq!(rows(&changes(a, &b, "linuxcnc")), "");
    // At another feed, or bent, it is a change.
    let slower = a.replace("G1 Y5 F75\nG1 Y5 F75\n", "G1 Y10 F60\n");
    assert!(!changes(a, &slower, "linuxcnc").is_empty());
    let bent = a.replace("G1 Y5 F75\nG1 Y5 F75\n", "G1 X1 Y5 F75\nG1 X-1 Y5 F75\n");
    assert!(!changes(a, &bent, "linuxcnc").is_empty());
}

#[test]
fn a_call_written_into_a_statement_is_the_call_added() {
    // An older Sinumerik main program (ph-lk/tempGCodeCNC): the block that only set the cycle's
    // R parameters now also calls the cycle, `L100 P1` (the subprogram is not there).
    let a = "N10 G90 G0 X100 Z100\nN20 R910=25 R911=17 R941=-0.5\nN30 M30\n";
    let b = a.replace("R941=-0.5", "R941=-0.5 L100 P1");
    expect![[r#"
        flow_changed | call |  | L100 P1 (1 pass) | 2 | 2
          call L100 P1 (1 pass) added at line 2
    "#]]
    .assert_eq(&rows(&changes(a, &b, "siemens")));
}

#[test]
fn an_absolute_height_the_incremental_moves_start_from_is_told_as_that_height() {
    // ozturkf/AluFDM: the first layer's start height, the layers after it reached by G91 steps.
    let a = "G90 X-20 Y-20 Z0.85 F285\nY-10 M10\nG90 X-7.5 Y-7.5\nG91 X15 M10\nG91 Z0.8\nX-15 M10\nM30\n";
    let b = a.replace("Z0.85", "Z0.8");
    let got = changes(a, &b, "siemens");
    let typed: Vec<(&str, &str, &str)> = got.iter().map(|c| (c.kind.as_str(), c.before.as_str(), c.after.as_str())).collect();
    assert_eq!(typed, [("depth_changed", "Z0.85", "Z0.8")], "{}", rows(&got));
    // A later absolute height starts the later moves anew: the word stays a statement change.
    let again = "G90 X-20 Y-20 Z0.85 F285\nY-10 M10\nG90 Z1.6\nG91 Z0.8\nM30\n";
    let got = changes(again, &again.replace("Z0.85", "Z0.8"), "siemens");
    assert!(!got.iter().any(|c| c.kind == ChangeKind::DepthChanged), "{}", rows(&got));
}

#[test]
fn moves_of_other_axes_are_not_paired() {
    // probe_basic's go_to_zero: `G0 Z0` gone, `G0 A0` new: one removed, one added.
    let a = "G0 X0 Y0\nG0 Z0\nM2\n";
    let b = "G0 X0 Y0\nG0 A0\nM2\n";
    expect![[r#"
        statement_changed | statement | G0 Z0 |  | - | 2
          `G0 Z0` removed at original line 2
        rotary_move_changed | statement |  | G0 A0 | 2 | -
          rotary axis move: `G0 A0` added at line 2
    "#]]
    .assert_eq(&rows(&changes(a, b, "linuxcnc")));
}

#[test]
fn another_error_in_a_program_that_machines_nothing_breaks_nothing() {
    // KL-Mithunvel/G-M_CODE EX4: no feed anywhere (the control refuses the first cut), and a
    // program number typed with a zero added at the top: both versions stop, neither machines.
    let a = "G21 G98\nM06 T01\nM03 S1000\nG0 X5 Z2\nG1 X0 Z0\nG1 Z-15 X10\nG0 Z2\nM30\n";
    let b = format!("01000\n{a}");
    let got = changes_with_findings(a, &b, "fanuc_lathe");
    assert!(!got.iter().any(|c| c.kind == ChangeKind::ProgramBroken), "{}", rows(&got));
    // With a feed the original runs its cuts: the same line breaks it.
    let fed = a.replace("G1 X0 Z0", "G1 X0 Z0 F0.2");
    let got = changes_with_findings(&fed, &format!("01000\n{fed}"), "fanuc_lathe");
    assert!(got.iter().any(|c| c.kind == ChangeKind::ProgramBroken), "{}", rows(&got));
}

/// A motion word that restates the motion in force (`X0.5 Y0.5` written `G0 X0.5 Y0.5` after
/// a rapid, `G1 X1 Y0.5` in the cuts) makes the same moves: no change, also where a hunk is too
/// large to tell statement by statement (held10's r400). A motion word that changes the mode
/// (`G0` where `G1` is in force) turns cuts into rapids: told.
#[test]
fn a_motion_word_that_restates_the_mode_in_force_is_no_change() {
    let a = "G20 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z0.25\nX0.5 Y0.5\nG1 Z-0.005 F50\nX1 Y0.5\nX1 Y1\nX0.5 Y1\nX0.5 Y0.5\nG0 Z0.25\nM2\n";
    let b =
        a.replace("\nX0.5 Y0.5\nG1", "\nG0 X0.5 Y0.5\nG1").replace("\nX1 Y0.5\n", "\nG1 X1 Y0.5\n").replace("\nX1 Y1\n", "\nG1 X1 Y1\n");
    assert_eq!(rows(&changes(a, &b, "linuxcnc")), "");
    let mut long = String::from("G20 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z0.25\nG1 Z-0.005 F50\n");
    for k in 1..=40 {
        long.push_str(&format!("X{} Y{}\n", k as f64 * 0.1, (k % 2) as f64 * 0.2));
    }
    long.push_str("G0 Z0.25\nM2\n");
    let explicit = long.lines().map(|l| if l.starts_with('X') { format!("G1 {l}\n") } else { format!("{l}\n") }).collect::<String>();
    assert_eq!(rows(&changes(&long, &explicit, "linuxcnc")), "");
    let rapid = a.replace("\nX1 Y1\n", "\nG0 X1 Y1\n");
    assert_ne!(rows(&changes(a, &rapid, "linuxcnc")), "");
}

#[test]
fn a_remark_edit_that_only_takes_out_a_nested_parenthesis_is_that_fix() {
    // Fanuc closes a remark at its first `)`: `(STOCK IS (NOMINALLY) 3/8)` leaves ` 3/8)` as
    // words, where the control stops. Taking the inner parenthesis out fixes the program and
    // does nothing else: one row, not the statements of the remark's rest.
    let a = "%\nO1000\n(STOCK IS (NOMINALLY) 10 MM)\nG21 G90 G17\nT1 M6\nS3000 M3\nG0 X0 Y0 Z5.\nG1 Z-1. F100.\nX50.\nG0 Z5.\nM30\n%\n";
    let b = a.replace("(STOCK IS (NOMINALLY) 10 MM)", "(STOCK IS NOMINALLY 10 MM)");
    let got = changes(a, &b, "fanuc");
    assert_eq!(got.len(), 1, "{}", rows(&got));
    assert_eq!(got[0].kind, ChangeKind::ProgramFixed, "{}", rows(&got));
    assert!(got[0].phrase().contains("remark closed early by a parenthesis nested in it"), "{}", rows(&got));
    // Put back, it breaks the program, told the same way.
    let back = changes(&b, a, "fanuc");
    assert_eq!(back.iter().map(|c| c.kind).collect::<Vec<_>>(), [ChangeKind::ProgramBroken], "{}", rows(&back));
    // A block number renumbered beside such a remark is no remark edit.
    let renumbered = b.replace("G21 G90 G17", "N5 G21 G90 G17");
    assert!(changes(a, &renumbered, "fanuc").iter().all(|c| !c.phrase().contains("remark closed early")));
}

#[test]
fn a_probes_feed_moves_are_no_cut_and_make_no_hole() {
    // A probing job (Fusion's probe tool `T99 ... probe`): the protected moves down at a feed
    // and the probing moves measure; moving the start is no hole removed and another added.
    let a = "G20 G90 G17\n(T99 D=0.1181 CR=0.0591 - ZMIN=0. - probe)\nT99 G43 H99 M6\nG54\nG0 X-0.25 Y0\nG1 Z1 F50\nG1 Z-0.25 F20\nG38.2 X0.5 F10\nG0 Z1\nM30\n";
    let b = a.replace("G0 X-0.25 Y0", "G0 X1.25 Y-1").replace("G38.2 X0.5", "G38.2 X2");
    let got = changes(a, &b, "linuxcnc");
    let kinds: Vec<ChangeKind> = got.iter().map(|c| c.kind).collect();
    assert!(!kinds.iter().any(|k| matches!(k, ChangeKind::HoleAdded | ChangeKind::HoleRemoved | ChangeKind::HoleMoved)), "{}", rows(&got));
    assert!(!got.is_empty(), "the edit is told");
    let registry = Registry::shipped();
    let plan = pipeline::analyze(a.as_bytes(), &registry.get("linuxcnc").unwrap(), &Profile::default()).plan;
    assert!(plan.workingsteps.is_empty(), "a probe cuts nothing: {:?}", plan.workingsteps.len());
}

/// Every line in `lines` of one side is named by a row: in its run of lines or its `at`.
fn all_named(got: &[Change], lines: std::ops::RangeInclusive<u32>, original: bool) -> bool {
    let names = |c: &Change, l: u32| {
        let (first, end) = if original { (c.original_line, c.detail.original_line_end) } else { (c.line, c.detail.line_end) };
        first.is_some_and(|f| (f..=end.unwrap_or(f)).contains(&l))
            || c.detail.at.iter().any(|&(o, e)| if original { o == Some(l) } else { e == Some(l) })
    };
    lines.into_iter().all(|l| got.iter().any(|c| names(c, l)))
}

#[test]
fn long_runs_under_a_changed_condition_or_commented_out_are_named_in_time() {
    // Thousands of lines in one run of differing lines (place.rs once scanned the whole run
    // for each line: 20 s at 8000 lines re-spelled under a changed condition, 3.6 s at 32000
    // lines commented out, in a debug build).
    let n = 3000u32;
    let registry = Registry::shipped();
    let d = registry.get("linuxcnc").unwrap();
    let compare = |a: &str, b: &str| {
        let profile = Profile::default();
        let (pa, pb) = (pipeline::analyze(a.as_bytes(), &d, &profile), pipeline::analyze(b.as_bytes(), &d, &profile));
        diff::compare(
            diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d },
            diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d },
        )
    };
    let body = |indent: &str| (0..n).map(|i| format!("{indent}g1 x{i} y{} f100\n", i % 7)).collect::<String>();
    let a = format!("o1 if [#1 GT 0]\n{}o1 endif\nm2\n", body("  "));
    // The body re-indented under the changed condition: each of its lines is the condition's.
    let b = format!("o1 if [#1 GT 1]\n{}o1 endif\nm2\n", body(""));
    let got = compare(&a, &b);
    let flow: Vec<&Change> = got.iter().filter(|c| c.kind == ChangeKind::FlowChanged).collect();
    assert_eq!(flow.len(), 1, "{}", rows(&got));
    let want: Vec<(Option<u32>, Option<u32>)> = (1..=n + 1).map(|l| (Some(l), Some(l))).collect();
    assert_eq!(flow[0].detail.at, want);
    // The whole file re-spelled in upper case: no body line is the same text, so the
    // condition names only its own line.
    let upper = a.to_ascii_uppercase().replace("GT 0", "GT 1");
    let got = compare(&a, &upper);
    assert_eq!(got.len(), 1, "{}", rows(&got));
    assert_eq!((got[0].kind, got[0].detail.at.as_slice()), (ChangeKind::FlowChanged, &[(Some(1), Some(1))][..]));
    // A long section commented out after its plunge: each comment is named beside the
    // statement it took the place of.
    let moves = (0..n).map(|i| format!("G1 X{} Y{}\n", i % 50, i % 7)).collect::<String>();
    let a = format!("G1 Z-1 F100\n{moves}M2\n");
    let commented: String = moves.lines().map(|l| format!("({l})\n")).collect();
    let b = format!("G1 Z-1 F100\n{commented}M2\n");
    let got = compare(&a, &b);
    assert!(all_named(&got, 2..=n + 1, true) && all_named(&got, 2..=n + 1, false), "{}", rows(&got));
}

/// The rows `kind | field | before | after` of the comparison of two programs.
fn kind_rows(a: &str, b: &str, dialect: &str) -> Vec<String> {
    changes(a, b, dialect).iter().map(|c| format!("{} | {} | {} | {}", c.kind.as_str(), c.field, c.before, c.after)).collect()
}

const SIEMENS_PLAIN: &str = "N10 G17 G90 G71\nN20 T1 D1\nN30 M3 S1000\nN40 G0 X0 Y0 Z5\nN50 G1 Z-2 F200\nN60 G1 X50\nN70 G0 Z5\nN80 M30\n";

#[test]
fn an_extended_address_added_is_no_global_variable() {
    let b = SIEMENS_PLAIN.replace("N40 ", "N35 M1=3 S1=2000\nN40 ");
    let got = kind_rows(SIEMENS_PLAIN, &b, "siemens");
    assert!(!got.iter().any(|r| r.starts_with("global_variable_changed")), "{got:#?}");
    assert!(got.iter().any(|r| r.contains("S1") && r.ends_with("| 2000")), "{got:#?}");
    // Keyword codes and axis-indexed settings written with `=`, numbered axes.
    for edit in ["SPOS=0", "SPOSA=90", "FA[X]=100", "OVRA[X]=50", "X1=10 Y2=5"] {
        let b = SIEMENS_PLAIN.replace("N70 ", &format!("N65 {edit}\nN70 "));
        let got = kind_rows(SIEMENS_PLAIN, &b, "siemens");
        assert!(!got.iter().any(|r| r.starts_with("global_variable_changed")), "{edit}: {got:#?}");
    }
    // A name the program neither defines nor takes is still global user data.
    let b = SIEMENS_PLAIN.replace("N70 ", "N65 PROCESS[50]=3\nN70 ");
    let got = kind_rows(SIEMENS_PLAIN, &b, "siemens");
    assert!(got.iter().any(|r| r.starts_with("global_variable_changed | variable PROCESS[50]")), "{got:#?}");
}

#[test]
fn a_move_to_an_incremental_number_is_no_move_by_variables() {
    let a = "N10 G17 G90 G71\nN20 T1 D1\nN30 M3 S1000\nN40 G0 X0 Y0 Z5\nN50 G1 Z-2 F200 X10\nN60 G1 X=IC(10)\nN70 G0 Z5\nN80 M30\n";
    let b = a.replace("X=IC(10)", "X20");
    let rows = kind_rows(a, &b, "siemens");
    // The block told as it is written, removed and added: no moves by variables.
    assert_eq!(rows, ["statement_changed | statement | G1 X=IC(10) | ", "statement_changed | statement |  | G1 X20"], "{rows:#?}");
    // Where the increment reads a parameter the program does not set, the plan does not
    // see where the move goes: the moves.
    let (a, b) = (a.replace("X=IC(10)", "X=IC(R1)"), a.replace("X=IC(10)", "X=IC(R2)"));
    let rows = kind_rows(&a, &b, "siemens");
    assert!(rows.iter().any(|r| r.starts_with("toolpath_changed | moves")), "{rows:#?}");
}

#[test]
fn a_conditional_jump_s_condition_is_told_as_its_condition() {
    // Heidenhain FN 9 (IF equal, GOTO): the comparison's value or its function edited is the
    // condition; the label it jumps to, the target.
    let a = "0 BEGIN PGM FN9 MM\n1 TOOL CALL 1 Z S3000 F500\n2 Q1 = 0\n3 L Z+50 R0 FMAX M3\n4 FN 9: IF +Q1 EQU +0 GOTO LBL 5\n5 L X+10 Y+10 R0 FMAX\n6 LBL 5\n7 L X+50 Y+50 R0 FMAX\n8 LBL 6\n9 L Z+50 R0 FMAX M30\n10 END PGM FN9 MM\n";
    for edit in ["FN 9: IF +Q1 EQU +1 GOTO LBL 5", "FN 10: IF +Q1 NE +0 GOTO LBL 5"] {
        let b = a.replace("FN 9: IF +Q1 EQU +0 GOTO LBL 5", edit);
        let rows = kind_rows(a, &b, "heidenhain");
        assert!(rows.iter().any(|r| r.starts_with("flow_changed | condition")), "{edit}: {rows:#?}");
        assert!(!rows.iter().any(|r| r.contains("jump target")), "{edit}: {rows:#?}");
    }
    let b = a.replace("GOTO LBL 5", "GOTO LBL 6");
    let rows = kind_rows(a, &b, "heidenhain");
    assert!(rows.iter().any(|r| r.starts_with("flow_changed | jump target")), "{rows:#?}");
    // The condition is told whole, left, relation, right and label, once: not the one word
    // that differs.
    let b = a.replace("FN 9: IF +Q1 EQU +0 GOTO LBL 5", "FN 9: IF +Q2 EQU +1 GOTO LBL 5");
    let rows = kind_rows(a, &b, "heidenhain");
    let condition: Vec<&String> = rows.iter().filter(|r| r.starts_with("flow_changed | condition")).collect();
    assert_eq!(condition.len(), 1, "{rows:#?}");
    assert!(condition[0].ends_with("| FN 9: IF +Q1 EQU 0 GOTO LBL5 | FN 9: IF +Q2 EQU 1 GOTO LBL5"), "{rows:#?}");
}

#[test]
fn a_tool_table_write_is_the_tool_s_data_changed() {
    // Heidenhain FN 17: SYSWRITE ID50 writes the tool table (the TNC technical manuals' system
    // data group 50: NR the column, IDX the tool): a length or radius is the tool's offset,
    // another column the tool data, with the column's name, the tool and the values.
    let a = "0 BEGIN PGM T MM\n1 FN 0: Q1 = +5\n2 FN 17: SYSWRITE ID50 NR1 IDXQ1 = +0 ; L\n3 FN 17: SYSWRITE ID50 NR9 IDX5 = +30\n4 END PGM T MM\n";
    let b = a.replace("NR1 IDXQ1 = +0", "NR1 IDXQ1 = +12.5").replace("NR9 IDX5 = +30", "NR9 IDX5 = +45");
    let rows = kind_rows(a, &b, "heidenhain");
    assert!(rows.contains(&"length_offset_changed | tool table L (tool length, ID50 NR1) of tool Q1 | 0 | 12.5".to_owned()), "{rows:#?}");
    assert!(
        rows.contains(&"tool_data_changed | tool table TIME1 (maximum tool age, ID50 NR9) of tool 5 | 30 | 45".to_owned()),
        "{rows:#?}"
    );
    // Radius, added whole; a column the dictionary does not name is still the tool table's.
    let b = a.replace("4 END", "4 FN 17: SYSWRITE ID50 NR2 IDX5 = +3\n5 FN 17: SYSWRITE ID50 NR36 IDX5 = +0\n6 END");
    let rows = kind_rows(a, &b, "heidenhain");
    assert!(rows.contains(&"cutter_comp_changed | tool table R (tool radius, ID50 NR2) of tool 5 |  | 3".to_owned()), "{rows:#?}");
    assert!(rows.contains(&"tool_data_changed | tool table column NR36 (ID50) of tool 5 |  | 0".to_owned()), "{rows:#?}");
    // A read of the table is no change of it: the parameter it sets, named by what it reads.
    let b = a.replace("4 END", "4 FN 18: SYSREAD Q1600 = ID50 NR1 IDX5\n5 END");
    let rows = kind_rows(a, &b, "heidenhain");
    assert_eq!(rows, ["statement_changed | Q1600 read from tool table L (tool length, ID50 NR1) of tool 5 |  | read"], "{rows:#?}");
    // Other system data stays the machine function it is.
    let b = a.replace("4 END", "4 FN 17: SYSWRITE ID990 NR6 IDX0 = +1\n5 END");
    let rows = kind_rows(a, &b, "heidenhain");
    assert!(rows.iter().all(|r| r.starts_with("machine_function_changed")), "{rows:#?}");
}

#[test]
fn a_plane_changed_under_cutter_compensation_breaks_the_program_where_the_control_stops() {
    // LinuxCNC: "Cannot change planes with cutter radius compensation on" (`rs274 -g`; the
    // same plane again runs); the dictionary's `modes-under-comp="locked"`.
    let a = "G21 G17 G90\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG41 D1 G1 X10 Y0\nG17\nG1 X20\nG40 G0 Z5\nM30\n";
    let b = a.replace("G17\nG1 X20", "G18\nG1 X20");
    let rows = |dialect: &str| -> Vec<String> {
        changes_with_findings(a, &b, dialect).iter().map(|c| format!("{} | {} | {}", c.kind.as_str(), c.field, c.after)).collect()
    };
    let got = rows("linuxcnc");
    assert!(got.iter().any(|r| r.starts_with("program_broken | interp::plane-under-comp")), "{got:#?}");
    // Fanuc stops too: alarm PS0037 "CAN NOT CHANGE PLANE IN G41/G42" (`plane-under-comp="stops"`),
    // and so does Mitsubishi, which extends it (P112).
    for dialect in ["fanuc", "mitsubishi"] {
        let got = rows(dialect);
        assert!(got.iter().any(|r| r.starts_with("program_broken | interp::plane-under-comp")), "{dialect}: {got:#?}");
    }
    // A control whose dictionary does not say it stops: a warning, no verdict.
    let got = rows("haas");
    assert!(!got.iter().any(|r| r.starts_with("program_broken")), "{got:#?}");
}

#[test]
fn a_keyword_spelled_as_the_control_does_not_take_it_breaks_the_program_first() {
    // A post's `CYCLE DEF 9.0` dwell (Klartext is `CYCL DEF`): the control stops at it. The edit
    // that brings it in is told first as breaking the program, at every block it wrote; the
    // dwell is still read as meant.
    let a = "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000\n2 L Z+50 R0 FMAX M3\n3 L X+0 Y+0 FMAX\n4 L Z-1 F100\n5 L X+10\n6 END PGM T MM\n";
    let b = a.replace("3 L X+0", "21 CYCLE DEF 9.0 DWELL TIME\n22 CYCLE DEF 9.1 10\n3 L X+0");
    let changes = changes_with_findings(a, &b, "heidenhain");
    let first = &changes[0];
    assert_eq!(
        (first.kind.as_str(), first.field.as_str(), first.line),
        ("program_broken", "syntax::rejected-spelling", Some(4)),
        "{changes:#?}"
    );
    assert_eq!(first.detail.at, [(None, Some(4)), (None, Some(5))], "{changes:#?}");
    assert!(changes.iter().any(|c| c.kind.as_str() == "dwell_changed"), "{changes:#?}");
    // The fix: written `CYCL DEF`, the edit fixes the program.
    let c = b.replace("CYCLE DEF", "CYCL DEF");
    let changes = changes_with_findings(&b, &c, "heidenhain");
    assert_eq!(changes[0].kind.as_str(), "program_fixed", "{changes:#?}");
    // Both versions stop at it alike: no verdict.
    let d = b.replace("DWELL TIME\n22 CYCLE DEF 9.1 10", "DWELL TIME\n22 CYCLE DEF 9.1 5");
    let changes = changes_with_findings(&b, &d, "heidenhain");
    assert!(!changes.iter().any(|c| c.kind.as_str().starts_with("program_")), "{changes:#?}");
}

#[test]
fn a_table_write_is_told_by_the_table_it_writes() {
    // Heidenhain FN 26: TABOPEN opens a table, FN 27: TABWRITE writes a row's columns by name:
    // in the tool table (TOOL.T) row n is tool n, L its length, R its radius.
    let a = "0 BEGIN PGM T MM\n1 FN 26: TABOPEN TNC:\\table\\TOOL.T\n2 FN 27: TABWRITE 5/\"L\" = Q2\n3 FN 27: TABWRITE 5/\"TIME1\" = Q3\n4 FN 26: TABOPEN TNC:\\MEAS.TAB\n5 FN 27: TABWRITE 2/\"X\" = Q2\n6 END PGM T MM\n";
    let b =
        a.replace("5/\"L\" = Q2", "5/\"L\" = Q4").replace("5/\"TIME1\" = Q3", "5/\"TIME1\" = Q5").replace("2/\"X\" = Q2", "2/\"X\" = Q6");
    let rows = kind_rows(a, &b, "heidenhain");
    assert!(rows.contains(&"length_offset_changed | tool table L (tool length) of tool 5 | Q2 | Q4".to_owned()), "{rows:#?}");
    assert!(rows.contains(&"tool_data_changed | tool table TIME1 (maximum tool age) of tool 5 | Q3 | Q5".to_owned()), "{rows:#?}");
    assert!(
        rows.contains(
            &"machine_function_changed | machine function TABWRITE: write to table MEAS.TAB, row 2, column X | Q2 | Q6".to_owned()
        ),
        "{rows:#?}"
    );
}

#[test]
fn a_table_named_in_a_comment_is_no_table_opened_or_written() {
    // A comment that names TABOPEN or TABWRITE opens and writes nothing: the write is told by the
    // table the program last opened (MEAS.TAB), and a comment's edit is no tool data.
    let a = "0 BEGIN PGM T MM\n1 FN 26: TABOPEN TNC:\\MEAS.TAB\n2 ; FN 26: TABOPEN TNC:\\table\\TOOL.T\n3 FN 27: TABWRITE 5/\"L\" = Q2\n4 ; FN 27: TABWRITE 7/\"R\" = Q3\n5 END PGM T MM\n";
    let b = a.replace("5/\"L\" = Q2", "5/\"L\" = Q4").replace("7/\"R\" = Q3", "7/\"R\" = Q5");
    let rows = kind_rows(a, &b, "heidenhain");
    assert!(
        rows.contains(
            &"machine_function_changed | machine function TABWRITE: write to table MEAS.TAB, row 5, column L | Q2 | Q4".to_owned()
        ),
        "{rows:#?}"
    );
    assert!(!rows.iter().any(|r| r.contains("tool table") || r.contains("row 7")), "{rows:#?}");
}

/// A LinuxCNC program that turns compensation off, then changes the plane or the units.
const COMP_THEN_MODE: &str =
    "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG41 D1 G1 X10 Y0\nG1 X20\nG40\nG18 G90\nG0 Z20\nM30\n";

#[test]
fn a_plane_or_units_code_moved_before_g40_is_no_reblocking_where_the_control_stops() {
    // rs274ngc: "Cannot change planes with cutter radius compensation on", "Cannot change units
    // with cutter radius compensation on" (the dictionary's `modes-under-comp`): `G40` then
    // `G18` runs, `G18` then `G40` stops. The edit must be told, not passed as re-blocked.
    for (mode, moved) in [("G18", "G18\nG40 G90\n"), ("G20", "G20\nG40 G90\n")] {
        let a = COMP_THEN_MODE.replace("G18 G90\n", &format!("{mode} G90\n"));
        let b = a.replace(&format!("G40\n{mode} G90\n"), moved);
        let rows = kind_rows(&a, &b, "linuxcnc");
        assert!(!rows.is_empty(), "{mode}: {rows:#?}");
    }
    // The same codes only re-blocked with `G40` still first: no change.
    let b = COMP_THEN_MODE.replace("G40\nG18 G90\n", "G40\nG18\nG90\n");
    assert!(kind_rows(COMP_THEN_MODE, &b, "linuxcnc").is_empty());
    let b = COMP_THEN_MODE.replace("G40\nG18 G90\n", "G40 G90\nG18\n");
    assert!(kind_rows(COMP_THEN_MODE, &b, "linuxcnc").is_empty());
}

#[test]
fn a_jump_s_target_is_the_word_after_its_keyword() {
    // SINUMERIK jumps name a label (`MARKE1:`) or a block number after GOTOF/GOTOB/GOTO/GOTOC;
    // a label holds no keyword, so its place tells it is the target, and a condition is only
    // what stands in `IF …` before the keyword.
    let program =
        |jump: &str| format!("N10 R1=0\nN20 G0 X0 Y0 Z5\nN30 {jump}\nN40 G0 X10\nMARKE1:\nN50 G0 X20\nMARKE2:\nN60 G0 X30\nM30\n");
    for kw in ["GOTOF", "GOTO", "GOTOC"] {
        let rows = kind_rows(&program(&format!("{kw} MARKE1")), &program(&format!("{kw} MARKE2")), "siemens");
        assert!(rows.iter().any(|r| r.starts_with("flow_changed | jump target")), "{kw}: {rows:#?}");
        assert!(!rows.iter().any(|r| r.contains("condition")), "{kw}: {rows:#?}");
        let (a, b) = (program(&format!("IF R1<3 {kw} MARKE1")), program(&format!("IF R1<3 {kw} MARKE2")));
        let rows = kind_rows(&a, &b, "siemens");
        assert!(rows.iter().any(|r| r.starts_with("flow_changed | jump target")), "IF {kw}: {rows:#?}");
        assert!(!rows.iter().any(|r| r.contains("condition")), "IF {kw}: {rows:#?}");
        let rows = kind_rows(&a, &program(&format!("IF R1<4 {kw} MARKE1")), "siemens");
        assert!(rows.iter().any(|r| r.starts_with("flow_changed | condition")), "IF {kw} condition: {rows:#?}");
        assert!(!rows.iter().any(|r| r.contains("jump target")), "IF {kw} condition: {rows:#?}");
    }
    // A jump back to a block number.
    let back = |n: &str| format!("N10 R1=0\nN20 G0 X0 Y0 Z5\nN30 G0 X10\nN40 R1=R1+1\nN50 IF R1<3 GOTOB {n}\nN60 M30\n");
    let rows = kind_rows(&back("N30"), &back("N20"), "siemens");
    assert!(rows.iter().any(|r| r.starts_with("flow_changed | jump target")), "{rows:#?}");
    assert!(!rows.iter().any(|r| r.contains("condition")), "{rows:#?}");
    // Fanuc `IF [..] GOTO n`: the block number after GOTO is the target, the bracket the condition.
    let fanuc = |jump: &str| format!("O1000\n#1=0\nG0 X0 Y0 Z5\n{jump}\nG0 X10\nN100 G0 X20\nN200 G0 X30\nM30\n");
    let a = fanuc("IF [#1 EQ 0] GOTO 100");
    let rows = kind_rows(&a, &fanuc("IF [#1 EQ 0] GOTO 200"), "fanuc");
    assert!(rows.iter().any(|r| r.starts_with("flow_changed | jump target")), "{rows:#?}");
    assert!(!rows.iter().any(|r| r.contains("condition")), "{rows:#?}");
    let rows = kind_rows(&a, &fanuc("IF [#1 EQ 1] GOTO 100"), "fanuc");
    assert!(rows.iter().any(|r| r.starts_with("flow_changed | condition")), "{rows:#?}");
    assert!(!rows.iter().any(|r| r.contains("jump target")), "{rows:#?}");
    // LinuxCNC O-word branches have no jump: a condition stays a condition.
    let o = |c: &str| format!("#1 = 0\nG0 X0 Y0 Z5\no100 if [#1 {c} 0]\nG0 X10\no100 endif\nM2\n");
    let rows = kind_rows(&o("EQ"), &o("NE"), "linuxcnc");
    assert!(rows.iter().any(|r| r.starts_with("flow_changed | condition")), "{rows:#?}");
    assert!(!rows.iter().any(|r| r.contains("jump target")), "{rows:#?}");
}

#[test]
fn an_expression_after_an_address_without_equals_is_the_sinumerik_syntax_error() {
    // 840D Fundamentals p.59: an address whose value is more than one constant takes `=`
    // (`J=(R109*(-1))`); `J(R109*(-1))` stops the control. Writing the `=` fixes the program.
    let ok = "N10 G17 G90 G71\nN20 T1 D1\nN30 M3 S1000\nN40 R109=5\nN50 G0 X0 Y0 Z5\nN60 G1 Z-2 F200\nN70 G2 X10 Y0 I=5 J=(R109*(-1))\nN80 G0 Z5\nN90 M30\n";
    let bad = ok.replace("J=(", "J(");
    let registry = Registry::shipped();
    let d = registry.get("siemens").unwrap();
    let errors = |t: &str| {
        pipeline::analyze(t.as_bytes(), &d, &Profile::default())
            .diagnostics
            .iter()
            .filter(|x| x.is_error())
            .map(|x| x.message.clone())
            .collect::<Vec<_>>()
    };
    assert!(errors(ok).is_empty(), "{:#?}", errors(ok));
    assert!(errors(&bad).iter().any(|m| m.contains("only after `=`")), "{:#?}", errors(&bad));
    let rows = kind_rows(&bad, ok, "siemens");
    assert!(rows.iter().any(|r| r.starts_with("program_fixed")), "{rows:#?}");
    // Brackets without `=` after a one-letter address are an expression on a Fanuc (`X[#1*2]`).
    let fanuc = "O1000\nG90 G17\n#1=5\nG0 X[#1*2] Y0\nM30\n";
    let d = registry.get("fanuc").unwrap();
    assert!(!pipeline::analyze(fanuc.as_bytes(), &d, &Profile::default()).diagnostics.iter().any(|x| x.is_error()));
}

#[test]
fn workingsteps_are_compared_in_xz_only_when_both_turn() {
    // A lathe's turning lies at Y = 0: its workingsteps are compared over X and Z (a finish
    // that gains a rough before it stays the same finish). A milling workingstep that happens
    // to stay at Y = 0 is compared in XY as any other: a short cut and a raster over the same
    // X and Z (as LinuxCNC threading.ngc's thread pass and its spring passes) are two
    // workingsteps, one removed and one added, not one changed.
    let mut raster = String::from("G20 G90 G17\nT1 M6\nS100 M3\nG0 X-2 Y0 Z1\n");
    for k in 0..10 {
        raster.push_str(&format!("G1 Z{:.2} F5\nX2\nG0 Z1\nX-2\n", 0.9 - 0.04 * f64::from(k)));
    }
    raster.push_str("M30\n");
    let pass = "G20 G90 G17\nT1 M6\nS100 M3\nG0 X-2 Y0 Z1\nG1 Z0.9 F5\nX2 Z0.5\nG0 Z1\nM30\n";
    let rows = kind_rows(pass, &raster, "linuxcnc");
    assert!(rows.iter().any(|r| r.starts_with("workingstep_removed")), "{rows:#?}");
    assert!(rows.iter().any(|r| r.starts_with("workingstep_added")), "{rows:#?}");
    let finish = "G21 G99\nT0101\nG97 S500 M3\nG0 X40. Z1.\nG1 Z0 F0.2\nX20. Z-20.\nG0 X50. Z5.\nM30\n";
    let mut roughed = String::from("G21 G99\nT0101\nG97 S500 M3\nG0 X40. Z1.\n");
    for k in 0..5 {
        roughed.push_str(&format!("G1 X{:.1} F0.2\nZ-20.\nG0 X42.\nZ1.\n", 36.0 - 4.0 * f64::from(k)));
    }
    roughed.push_str("G0 X50. Z5.\nM30\n");
    let rows = kind_rows(finish, &roughed, "fanuc_lathe");
    assert_eq!(rows.iter().filter(|r| r.starts_with("workingstep_added")).count(), 1, "{rows:#?}");
    assert!(!rows.iter().any(|r| r.starts_with("workingstep_removed")), "{rows:#?}");
}

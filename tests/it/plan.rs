//! Plan recovery: features, operations and strategies from small programs written the way
//! CAM posts write them (Fanuc dialect).

use ncplan::dialect::Registry;
use ncplan::interp::Profile;
use ncplan::pipeline;
use ncplan::plan::{CutMode, FeatureKind, HoleBottom, Operation, ProcessPlan, Rotation, StrategyKind, ToolKind, ToolSource};

/// Named test programs, shared with the STEP-NC tests.
pub(crate) const PROGRAMS: &[(&str, &str)] = &[
    ("face", FACE),
    ("drill_ream", DRILL_REAM),
    ("peck", PECK),
    ("pocket", POCKET),
    ("profile", PROFILE),
    ("slot", SLOT),
    ("step", STEP),
    ("surface", SURFACE),
    ("open_pocket", OPEN_POCKET),
];

const FACE: &str = "%
O1234 (FACE MILL TOP)
(T1 D=18 ENDMILL)
G21 G17 G40 G49 G80 G90
T1 M06
G54 G00 X90. Y20. S720 M03
G43 Z50. H01 M08
Z5.
G01 Z0. F240.
X-10.
Y34.
X90.
Y48.
X-10.
G00 Z50.
M30
%
";

const DRILL_REAM: &str = "%
O2000 (HOLES)
(T2 DRILL D7.8)
T2 M06
G90 G54 G00 X20. Y20. S1500 M03
G43 Z50. H02 M08
G99 G81 Z-15. R2. F120.
X60.
Y40.
G98 X20.
G80
(T3 REAMER D8)
T3 M06
G00 X20. Y20. S400 M03
G43 Z50. H03
G99 G85 Z-12. R2. F60.
X60.
Y40.
G98 X20.
G80 M09
M30
%
";

const PECK: &str = "%
O2100 (PECK)
(T5 6MM DRILL)
T5 M06
G90 G54 G00 X10. Y10. S2000 M03
G43 Z30. H05 M08
G98 G83 Z-30. R3. Q5. F100.
X30.
G80
M30
%
";

const POCKET: &str = "%
O3000 (RECT POCKET)
(T4 D10 ENDMILL)
T4 M06
G90 G54 G00 X50. Y30. S3000 M03
G43 Z20. H04 M08
Z2.
G01 Z-3. F150.
X45. Y25. F400.
X55.
Y35.
X45.
Y25.
X40. Y20.
X60.
Y40.
X40.
Y20.
G00 Z2.
X50. Y30.
G01 Z-6. F150.
X45. Y25. F400.
X55.
Y35.
X45.
Y25.
X40. Y20.
X60.
Y40.
X40.
Y20.
G00 Z20.
M30
%
";

const PROFILE: &str = "%
O4000 (OUTSIDE PROFILE ROUGH AND FINISH)
(T6 D12 ENDMILL)
T6 M06
G90 G54 G00 X-10. Y0. S2500 M03
G43 Z20. H06 M08
Z2.
G01 Z-5. F200.
Y40. F600.
G02 X0. Y50. R10.
G01 X60.
G02 X70. Y40. R10.
G01 Y0.
G02 X60. Y-10. R10.
G01 X0.
G02 X-10. Y0. R10.
G00 Z20.
X-9.5 Y0.
Z2.
G01 Z-5. F200.
Y40. F300.
G02 X0. Y49.5 R9.5
G01 X60.
G02 X69.5 Y40. R9.5
G01 Y0.
G02 X60. Y-9.5 R9.5
G01 X0.
G02 X-9.5 Y0. R9.5
G00 Z20.
M30
%
";

const SLOT: &str = "%
O5000 (SLOT)
(T7 8MM SLOT MILL)
T7 M06
G90 G54 G00 X10. Y20. S4000 M03
G43 Z20. H07
Z2.
G01 Z-3. F100.
X80. F300.
G00 Z20.
M30
%
";

const STEP: &str = "%
O6000 (STEP)
(STOCK X0 Y0 Z-20 X100 Y50 Z0)
(T8 D16 ENDMILL)
T8 M06
G90 G54 G00 X-10. Y50. S2500 M03
G43 Z20. H08
Z2.
G01 Z-5. F150.
X110. F500.
Y44.
X-10.
G00 Z20.
M30
%
";

const SURFACE: &str = "%
O7000 (3D)
(T9 6MM BALL END MILL)
T9 M06
G90 G54 G00 X0. Y0. S8000 M03
G43 Z20. H09
Z2.
G01 Z0. F500.
X1. Z-0.1
X2. Z-0.3
X3. Z-0.6
X4. Z-1.0
X5. Z-1.5
Y1. Z-1.4
X4. Z-0.9
X3. Z-0.5
X2. Z-0.2
X1. Z0.
G00 Z20.
M30
%
";

const OPEN_POCKET: &str = "%
O8000 (POCKET OPEN TO +X)
(STOCK X0 Y0 Z-20 X100 Y50 Z0)
(T4 D10 ENDMILL)
T4 M06
G90 G54 G00 X95. Y25. S3000 M03
G43 Z20. H04
Z2.
G01 Z-4. F150.
X85. Y20. F400.
X105.
Y30.
X85.
Y20.
X80. Y15.
X110.
Y35.
X80.
Y15.
G00 Z20.
M30
%
";

fn analyze(program: &str) -> ProcessPlan {
    let reg = Registry::shipped();
    pipeline::analyze(program.as_bytes(), &reg.get("fanuc").unwrap(), &Profile::default()).plan
}

#[test]
fn face_milling_is_a_bidirectional_planar_face() {
    let p = analyze(FACE);
    assert_eq!(p.features.len(), 1);
    let FeatureKind::PlanarFace { direction, length, width } = p.features[0].kind else { panic!("{:?}", p.features) };
    assert_eq!((direction, length, width), ([1.0, 0.0, 0.0], 118.0, 46.0));
    let ws = &p.workingsteps[0];
    assert_eq!(ws.operation, Operation::PlaneFinishMilling);
    let s = ws.strategy.as_ref().unwrap();
    assert_eq!((s.kind, s.feed_direction), (StrategyKind::Bidirectional, Some([-1.0, 0.0, 0.0])));
    assert_eq!((ws.radial_depth, s.overlap), (Some(14.0), Some(0.222222)));
    assert_eq!(ws.security_plane, 50.0);
    assert_eq!((p.tools[0].kind, p.tools[0].kind_source, p.tools[0].diameter), (ToolKind::EndMill, ToolSource::Comment, Some(18.0)));
}

#[test]
fn drilling_then_reaming_one_pattern_is_one_hole_feature() {
    let p = analyze(DRILL_REAM);
    assert_eq!(p.workingsteps.len(), 2);
    assert_eq!([p.workingsteps[0].operation, p.workingsteps[1].operation], [Operation::Drilling, Operation::Reaming]);
    assert_eq!(p.features.len(), 1, "{:#?}", p.features);
    let f = &p.features[0];
    let FeatureKind::RoundHole { diameter, bottom, positions, .. } = &f.kind else { panic!() };
    assert_eq!(*diameter, Some(8.0));
    // The D7.8 drill's point (assumed 118°) lies below the reamer's flat end at 12: the hole
    // ends in the drill's cone, and is as deep as the drill's full diameter goes,
    // 15 - 3.9 / tan 59° (below the reamed 12).
    assert_eq!(*bottom, HoleBottom::Conical(118.0));
    assert_eq!(f.sources.point_angle, Some(ncplan::plan::Source::Assumption));
    assert_eq!(positions, &[[0.0, 0.0], [40.0, 0.0], [40.0, 20.0], [0.0, 20.0]]);
    assert_eq!(f.workingsteps, [1, 2]);
    // Without stock or a faced level the top is the program zero, not the R level.
    assert_eq!(f.placement, [20.0, 20.0, 0.0]);
    assert!(f.top_inferred);
    assert_eq!(f.depth, 12.656644);
    assert_eq!(p.tools.iter().map(|t| t.kind).collect::<Vec<_>>(), [ToolKind::TwistDrill, ToolKind::Reamer]);
}

#[test]
fn peck_drilling_is_multistep_with_its_peck() {
    let p = analyze(PECK);
    let ws = &p.workingsteps[0];
    assert_eq!(ws.operation, Operation::MultistepDrilling);
    assert_eq!(ws.axial_depth, Some(5.0));
    let FeatureKind::RoundHole { positions, bottom, diameter, .. } = &p.features[0].kind else { panic!() };
    assert_eq!((positions.len(), *bottom, *diameter), (2, HoleBottom::Conical(118.0), Some(6.0)));
}

#[test]
fn nested_loops_are_a_rectangular_closed_pocket() {
    let p = analyze(POCKET);
    assert_eq!(p.workingsteps.len(), 1);
    let ws = &p.workingsteps[0];
    assert_eq!(ws.operation, Operation::BottomAndSideFinishMilling);
    let s = ws.strategy.as_ref().unwrap();
    assert_eq!((s.kind, s.rotation, s.cutmode), (StrategyKind::ContourParallel, Some(Rotation::Ccw), Some(CutMode::Climb)));
    assert_eq!((ws.axial_depth, ws.radial_depth), (Some(3.0), Some(5.0)));
    let f = &p.features[0];
    let FeatureKind::ClosedPocket { rectangle, corner_radius, .. } = &f.kind else { panic!("{:?}", f.kind) };
    assert_eq!((*rectangle, *corner_radius), (Some((30.0, 30.0)), Some(5.0)));
    assert_eq!((f.placement, f.depth), ([50.0, 30.0, 0.0], 6.0));
}

#[test]
fn rough_and_finish_passes_around_the_part_are_one_outside_profile() {
    let p = analyze(PROFILE);
    assert_eq!(p.workingsteps.len(), 2);
    assert_eq!(p.features.len(), 1);
    assert!(matches!(p.features[0].kind, FeatureKind::OutsideProfile { .. }), "{:?}", p.features[0].kind);
    assert_eq!(p.features[0].workingsteps, [1, 2]);
    let (rough, finish) = (&p.workingsteps[0], &p.workingsteps[1]);
    assert_eq!((rough.operation, finish.operation), (Operation::SideRoughMilling, Operation::SideFinishMilling));
    assert_eq!((rough.allowance_side, rough.allowance_bottom), (Some(0.5), None), "side milling has no floor allowance");
    let s = finish.strategy.as_ref().unwrap();
    // The tool enters on the contour and without compensation: nothing says where the
    // material is, so the cut mode is not stated (the side comes from the cut direction).
    assert_eq!((s.kind, s.rotation, s.cutmode), (StrategyKind::ContourParallel, Some(Rotation::Cw), None));
}

#[test]
fn one_open_pass_is_a_slot_as_wide_as_the_tool() {
    let p = analyze(SLOT);
    let FeatureKind::Slot { width, path } = &p.features[0].kind else { panic!("{:?}", p.features[0].kind) };
    assert_eq!(*width, 8.0);
    assert_eq!(path.segments.len(), 1);
    assert_eq!(p.workingsteps[0].strategy.as_ref().unwrap().kind, StrategyKind::CenterMilling);
    assert_eq!(p.features[0].depth, 3.0, "top inferred at the program zero, not the plunge start at Z2");
}

#[test]
fn passes_along_one_stock_edge_are_a_step() {
    let p = analyze(STEP);
    let stock = p.workpiece.as_ref().expect("the stock comment is read");
    assert_eq!((stock.origin, stock.size), ([0.0, 0.0, -20.0], [100.0, 50.0, 20.0]));
    let FeatureKind::Step { width, length, direction } = p.features[0].kind else { panic!("{:?}", p.features[0].kind) };
    assert_eq!((direction, length, width), ([1.0, 0.0, 0.0], 100.0, 14.0));
    assert_eq!(p.features[0].placement, [0.0, 36.0, 0.0]);
    assert_eq!(p.features[0].depth, 5.0);
    assert!(!p.features[0].top_inferred);
}

#[test]
fn three_d_cutting_stays_a_toolpath_feature() {
    let p = analyze(SURFACE);
    assert_eq!(p.features[0].kind, FeatureKind::Toolpath);
    assert_eq!(p.workingsteps[0].operation, Operation::FreeformMilling);
    assert_eq!(p.tools[0].kind, ToolKind::BallEndMill);
}

#[test]
fn a_pocket_through_a_stock_side_is_open() {
    let p = analyze(OPEN_POCKET);
    let FeatureKind::OpenPocket { boundary } = &p.features[0].kind else { panic!("{:?}", p.features[0].kind) };
    assert!(boundary.is_closed());
    assert_eq!(p.features[0].placement, [75.0, 10.0, 0.0]);
    assert_eq!(p.features[0].depth, 4.0);
    assert_eq!(p.workingsteps[0].operation, Operation::BottomAndSideFinishMilling);
}

#[test]
fn rigid_tapping_and_feed_per_revolution_become_a_tapping_step_and_feeds_per_minute() {
    // LinuxCNC: G33.1 taps synchronised to the spindle; G95 gives the feed per revolution.
    let program = "G21 G90 G17
T1 M6
S500 M3
G0 X10 Y10 Z5
G33.1 Z-12 K1.25
G0 X30
G95 G1 Z-2 F0.1
G94 G1 Z-4 F100
M2
";
    let reg = Registry::shipped();
    let a = pipeline::analyze(program.as_bytes(), &reg.get("linuxcnc").unwrap(), &Profile::default());
    assert!(!a.has_errors(), "{:?}", a.diagnostics);
    let steps: Vec<(Operation, Vec<f64>)> = a.plan.workingsteps.iter().map(|w| (w.operation, w.technology.feeds.clone())).collect();
    // The tap advances 1.25 mm per turn at 500 rpm: 625 mm/min; 0.1 mm/rev at 500 rpm is 50.
    // The feeds straight down with the same tool are a hole made by explicit moves.
    assert_eq!(steps, [(Operation::Tapping, vec![625.0]), (Operation::Drilling, vec![50.0, 100.0])]);
}

#[test]
fn constant_surface_speed_is_kept_and_feeds_per_revolution_follow_the_diameter() {
    // G96 S is metres per minute, with D (LinuxCNC) or `G50 S` (lathes) as the speed limit.
    let program = "G18 G21 G95\nT1 M6\nG96 S200 D2000 M3\nG0 X20 Z1\nG1 Z-10 F0.2\nG1 X5\nM2\n";
    let reg = Registry::shipped();
    let lathe = reg.get("linuxcnc").unwrap();
    let a = pipeline::analyze(program.as_bytes(), &lathe, &Profile::default());
    assert!(!a.has_errors(), "{:?}", a.diagnostics);
    let t = &a.plan.workingsteps[0].technology;
    assert_eq!((t.surface_speed, t.spindle_speed), (Some(200.0), 2000.0));
    // 200 m/min at 20 mm from the axis is 1591.55 1/min: 0.2 mm/rev is 318.31 mm/min. At
    // 5 mm it would be 6366 1/min, held to the 2000 limit: 400 mm/min.
    assert_eq!(t.feeds, [318.309886184, 400.0]);
    // The change of surface speed is a change report of its own: on this program, which
    // turns (G18, G96), in a turner's words, the cutting speed.
    let b = pipeline::analyze(program.replace("S200", "S180").as_bytes(), &lathe, &Profile::default());
    let rows = ncplan::diff::diff(&a.plan, &b.plan);
    assert!(rows.iter().any(|r| r.field == "cutting_speed" && r.before == "200 m/min" && r.after == "180 m/min"), "{rows:?}");
    // Siemens writes the limit as LIMS=, in the block or on its own later.
    // (On a Sinumerik lathe X is a diameter from reset: DIAMOF reads it as the radius it is here.)
    let siemens = "G18 G71 G95 DIAMOF\nT1 D1 M6\nG96 S200 LIMS=1500 M3\nLIMS=2000\nG0 X20 Z1\nG1 Z-10 F0.2\nG1 X5\nM30\n";
    let s = pipeline::analyze(siemens.as_bytes(), &reg.get("siemens").unwrap(), &Profile::default());
    assert!(!s.has_errors(), "{:?}", s.diagnostics);
    assert_eq!(s.plan.workingsteps[0].technology, *t);
}

/// A plan read in `dialect`.
fn analyze_in(dialect: &str, program: &str) -> ProcessPlan {
    let d = ncplan::dialect::Registry::shipped().get(dialect).unwrap();
    ncplan::pipeline::analyze(program.as_bytes(), &d, &ncplan::interp::Profile::default()).plan
}

#[test]
fn a_hole_s_top_is_the_surface_its_cycle_states() {
    // A boss 3 mm above the work zero: Siemens RFP=3, Heidenhain Q203=+3. The R level (the
    // safety distance above it) is not the top, nor is the work zero.
    let siemens = "%_N_BOSS_MPF\nG17 G90 G71\nT=\"DRILL8\"\nM6\nS1800 M3 F150\nG0 X20 Y20 Z50\n\
                   MCALL CYCLE81(20,3,2,-12,)\nX20 Y20\nX60 Y20\nMCALL\nG0 Z100\nM30\n";
    let heidenhain = "0 BEGIN PGM BOSS MM\n1 TOOL CALL 5 Z S1800\n2 L Z+50 R0 FMAX M3\n\
                      3 CYCL DEF 200 DRILLING ~\n  Q200=2 ;SET-UP CLEARANCE ~\n  Q201=-15 ;DEPTH ~\n  Q206=150 ;FEED RATE FOR PLNGNG ~\n\
                      \x20 Q202=15 ;PLUNGING DEPTH ~\n  Q210=0 ;DWELL TIME AT TOP ~\n  Q203=+3 ;SURFACE COORDINATE ~\n\
                      \x20 Q204=20 ;2ND SET-UP CLEARANCE ~\n  Q211=0 ;DWELL TIME AT DEPTH\n\
                      4 L X+20 Y+20 R0 FMAX M99\n5 L X+60 Y+20 R0 FMAX M99\n6 L Z+100 R0 FMAX\n7 END PGM BOSS MM\n";
    for (dialect, program) in [("siemens", siemens), ("heidenhain", heidenhain)] {
        let p = analyze_in(dialect, program);
        let holes: Vec<&ncplan::plan::Feature> = p.features.iter().filter(|f| matches!(f.kind, FeatureKind::RoundHole { .. })).collect();
        assert_eq!(holes.len(), 1, "{dialect}: {:#?}", p.features);
        let f = holes[0];
        assert_eq!((f.placement[2], f.depth, f.top_inferred), (3.0, 15.0, false), "{dialect}");
    }
}

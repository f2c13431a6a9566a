//! A path with no tool, spindle or feed in its file (a contour subprogram read alone, a routine
//! whose caller sets tool and feed) keeps its workingstep and toolpath, is told as a contour path,
//! and machines no feature (review19b F1, F2).

use ncplan::dialect::Registry;
use ncplan::diff::{self, ChangeKind};
use ncplan::interp::Profile;
use ncplan::pipeline;

const CONT_A: &str = "N10 G1 X0 Z0\nN20 G1 X34 Z0\nN30 G1 X42 Z-20\nN40 G1 X70 Z-32\nN50 G1 Z-40\nN60 M17\n";
const CONT_B: &str = "N10 G1 X0 Z0\nN20 G1 X34 Z0\nN30 G1 X44 Z-20\nN40 G1 X70 Z-32\nN50 G1 Z-40\nN60 M17\n";

#[test]
fn a_contour_subprogram_edit_is_a_toolpath_change() {
    let registry = Registry::shipped();
    let d = registry.get("siemens").unwrap();
    let profile = Profile::default();
    let pa = pipeline::analyze(CONT_A.as_bytes(), &d, &profile);
    let pb = pipeline::analyze(CONT_B.as_bytes(), &d, &profile);
    let got = diff::compare(
        diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d },
        diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d },
    );
    let row = got.iter().find(|c| c.kind == ChangeKind::ToolpathChanged).unwrap_or_else(|| panic!("no toolpath row: {got:?}"));
    assert!(row.operation.starts_with("contour path"), "{}", row.operation);
}

#[test]
fn a_routine_without_tool_or_feed_keeps_its_path_and_makes_no_feature() {
    // As CIRCLE.NC: the cut's feed and tool come from the caller.
    let program = "%\nO1000\nG90 G0 X0. Y0.\nG1 X20.\nY20.\nX0.\nY0.\nM99\n%\n";
    let registry = Registry::shipped();
    let plan = pipeline::analyze(program.as_bytes(), &registry.get("fanuc").unwrap(), &Profile::default()).plan;
    assert_eq!(plan.workingsteps.len(), 1, "{plan:?}");
    let ws = &plan.workingsteps[0];
    assert!(ws.path_only());
    assert!((ws.cutting_length - 80.0).abs() < 1e-6, "{}", ws.cutting_length);
    assert!(ws.feature.is_none() && plan.features.is_empty(), "{:?}", plan.features);
    assert_eq!(ws.label(), "contour path (no tool, spindle or feed in this file)");
    let text = ncplan::plan::describe(&plan);
    assert!(text.contains("workingstep 1 (contour path (no tool, spindle or feed in this file)) T0 F0"), "{text}");
}

#[test]
fn a_tool_and_feed_make_it_machining_again() {
    let program = "%\nO1000\nT1 M6\nS1000 M3\nG90 G0 X0. Y0.\nG1 X20. F100.\nY20.\nX0.\nY0.\nM30\n%\n";
    let registry = Registry::shipped();
    let plan = pipeline::analyze(program.as_bytes(), &registry.get("fanuc").unwrap(), &Profile::default()).plan;
    assert!(!plan.workingsteps[0].path_only());
    assert!(plan.workingsteps[0].feature.is_some());
}

//! Tool comments further from the change: a comment that names the tool being changed to
//! (`T1 ...`, `TOOL 1 ...`), or names no tool, anywhere before the change since the previous
//! operation (or in the program's header) gives that tool's facts; the nearest one wins,
//! and a comment naming another tool is never this one's.

use ncplan::diag::Severity;
use ncplan::dialect::Registry;
use ncplan::interp::Profile;
use ncplan::pipeline::{self, Analysis};
use ncplan::plan::ToolKind;

fn analyze(dialect: &str, program: &str) -> Analysis {
    pipeline::analyze(program.as_bytes(), &Registry::shipped().get(dialect).unwrap(), &Profile::default())
}

/// (tool number, diameter, kind) of every tool the plan uses.
fn tools(a: &Analysis) -> Vec<(u32, Option<f64>, ToolKind)> {
    let errors: Vec<String> = a.diagnostics.iter().filter(|d| d.severity == Severity::Error).map(|d| d.message.clone()).collect();
    assert!(errors.is_empty(), "{errors:#?}");
    a.plan.tools.iter().map(|t| (t.number, t.diameter, t.kind)).collect()
}

#[test]
fn a_mastercam_header_lists_every_tool_for_haas() {
    // The `D1` of the list is the radius offset, not the diameter.
    let program = "%
O0100 (BRACKET)
(DATE=DD-MM-YY - 02-12-26 TIME=HH:MM - 07:00)
(MCX FILE - BRACKET.MCAM)
(NC FILE - O0100.NC)
(MATERIAL - ALUMINUM MM - 2024)
( T1 | 10. FLAT ENDMILL | H1 | D1 )
( T2 | 6.8 DRILL | H2 )
G21
G0 G17 G40 G49 G80 G90
T1 M6
G0 G90 G54 X0. Y0. S3000 M3
G43 H1 Z50.
G1 Z-2. F100.
X50.
G0 Z50.
M5
T2 M6
G0 G90 G54 X10. Y10. S2000 M3
G43 H2 Z50.
G98 G81 X10. Y10. Z-10. R2. F80.
G80
M5
M30
%
";
    let a = analyze("haas", program);
    assert_eq!(tools(&a), [(1, Some(10.0), ToolKind::EndMill), (2, Some(6.8), ToolKind::TwistDrill)]);
}

#[test]
fn a_fusion_header_and_an_operation_comment_further_up_for_fanuc() {
    // Tool 1 from the header's list; tool 2 from the operation's comment five lines
    // above its change; a comment in the middle of the first operation is not tool 2's.
    let program = "%
O0200
(T1 D=12. CR=0. - ZMIN=-10. - FLAT END MILL)
(T3 D=20. CR=0. - ZMIN=-2. - FACE MILL)
G90 G94 G17
G21
(ADAPTIVE1)
T1 M6
S5000 M3
G54
G0 X0. Y0.
G43 Z15. H1
G1 Z-2. F300.
(ROUGH 16MM FINISH PASS)
X40.
Y20.
G0 Z15.
M5
(DRILL2 - TOOL 2 - D8.5 DRILL)
G28 G91 Z0.
G90
(COMMENT WITHOUT FACTS)
(SECOND LINE)
(THIRD LINE)
T2 M6
S2000 M3
G0 X10. Y10.
G43 Z15. H2
G98 G81 X10. Y10. Z-10. R2. F80.
G80
M30
%
";
    let a = analyze("fanuc", program);
    assert_eq!(tools(&a), [(1, Some(12.0), ToolKind::EndMill), (2, Some(8.5), ToolKind::TwistDrill)]);
}

#[test]
fn a_siemens_operation_header_names_its_tool_further_up() {
    let program = "; TOOL 3 - 16MM END MILL
; OPERATION 1: ROUGH POCKET
; MACHINE: DMU 50
; CLEARANCE 50
; STOCK TO LEAVE 0.2
G17 G90 G71
T3 M6
S4000 M3
G0 X0 Y0 Z50
G1 Z-3 F200
X30
G0 Z50
; TOOL 4 - 6MM BALL END MILL
; OPERATION 2: FINISH
G0 Z100
G0 X0 Y0
T4 M6
S8000 M3
G0 X0 Y0 Z50
G1 Z-1 F500
X30
M30
";
    let a = analyze("siemens", program);
    assert_eq!(tools(&a), [(3, Some(16.0), ToolKind::EndMill), (4, Some(6.0), ToolKind::BallEndMill)]);
}

#[test]
fn an_nx_operation_header_names_its_tool_further_up() {
    // No TLDATA: the operation's header `TOOL PATH/...,TOOL,ENDMILL_D10` seven lines up
    // names the tool; the second operation's header after the first one's cuts is tool 2's.
    let program = "TOOL PATH/POCKET_4,TOOL,ENDMILL_D10
MSYS/0.0000,0.0000,0.0000,1.0000000,0.0000000,0.0000000,0.0000000,1.0000000,0.0000000
$$ centerline data
PAINT/PATH
PAINT/SPEED,10
PAINT/COLOR,186
LOAD/TOOL,4,ADJUST,4
SPINDL/RPM,3000.0000,CLW
RAPID
GOTO/0.0000,0.0000,50.0000
FEDRAT/MMPM,200.0000
GOTO/0.0000,0.0000,-2.0000
GOTO/40.0000,0.0000,-2.0000
RAPID
GOTO/40.0000,0.0000,50.0000
END-OF-PATH
TOOL PATH/DRILLING,TOOL,DRILL_D6.8
PAINT/PATH
PAINT/SPEED,10
PAINT/COLOR,186
PAINT/COLOR,211
LOAD/TOOL,2,ADJUST,2
SPINDL/RPM,2000.0000,CLW
RAPID
GOTO/10.0000,10.0000,50.0000
FEDRAT/MMPM,80.0000
GOTO/10.0000,10.0000,-10.0000
RAPID
GOTO/10.0000,10.0000,50.0000
END-OF-PATH
FINI
";
    let a = analyze("cldata", program);
    assert_eq!(tools(&a), [(2, Some(6.8), ToolKind::TwistDrill), (4, Some(10.0), ToolKind::EndMill)]);
}

/// A router's post writes the one tool in its header and no tool change (`(T1 D=3.175 ...)`,
/// no `T1 M6`): the cuts are that tool's, with a note, and its plunges with an end mill are
/// holes each, the first one too. With two tools listed and no change, no tool is guessed.
#[test]
fn a_router_program_with_one_listed_tool_and_no_tool_change_cuts_with_it() {
    let program = "(T1  D=3.175 CR=0 - ZMIN=-3 - flat end mill)\nG90 G94 G17 G21\nS20000 M3\nG0 X10 Y10 Z5\nG1 Z-3 F100\nG0 Z5\nX20\nG1 Z-3\nG0 Z5\nM30\n";
    let a = analyze("linuxcnc", program);
    assert_eq!(tools(&a), [(1, Some(3.175), ToolKind::EndMill)]);
    assert!(a.diagnostics.iter().any(|d| d.code.as_str() == "plan::tool-from-list" && d.message.contains("T1")), "{:?}", a.diagnostics);
    assert!(!a.diagnostics.iter().any(|d| d.code.as_str() == "plan::no-tool"), "{:?}", a.diagnostics);
    let holes: usize = a
        .plan
        .features
        .iter()
        .map(|f| match &f.kind {
            ncplan::plan::FeatureKind::RoundHole { diameter, positions, .. } => {
                assert_eq!(*diameter, Some(3.175));
                positions.len()
            }
            _ => 0,
        })
        .sum();
    assert_eq!(holes, 2, "{:#?}", a.plan.features);
    let two = program.replace("(T1 ", "(T2  D=6. - drill)\n(T1 ");
    let a = analyze("linuxcnc", &two);
    assert!(matches!(tools(&a)[..], [(0, None, _)]), "{:?}", a.plan.tools);
}

/// A comment's sizes are in the program's units unless it states its own: a Fusion inch post
/// writes `(T1 D=0.25 ...)` for a quarter-inch end mill, shops name drills by inch fractions
/// (`1/4" DRILL`) and give a metric size with `MM` in an inch program.
#[test]
fn tool_comment_sizes_follow_the_programs_units_unless_they_state_their_own() {
    let program = "%\nO1000\n(T1 D=0.25 CR=0. - ZMIN=-0.2 - flat end mill)\n(T2 = 1/4\" DRILL, 140 Point Angle)\n(T3 6MM FLAT END MILL)\n\
                   G20 G90 G17\nT1 M6\nS8000 M3\nG0 X0 Y0 Z0.2\nG1 Z-0.2 F10.\nX2.\nY1.\nX0\nY0\nG0 Z0.5\n\
                   T2 M6\nS1500 M3\nG0 X3. Y3. Z0.1\nG81 Z-0.5 R0.1 F5.\nG80\n\
                   T3 M6\nS6000 M3\nG0 X5. Y5. Z0.1\nG1 Z-0.1 F5.\nX6.\nG0 Z0.5\nM30\n%\n";
    let a = analyze("fanuc", program);
    let t = tools(&a);
    assert_eq!(t[0].1, Some(6.35), "{t:?}");
    assert_eq!(t[1].1, Some(6.35), "{t:?}");
    assert_eq!(t[2].1, Some(6.0), "{t:?}");
    assert_eq!(a.plan.tools[1].point_angle, Some(140.0));
    // The same comment in a metric program is millimetres.
    let metric = program.replace("G20", "G21");
    assert_eq!(tools(&analyze("fanuc", &metric))[0].1, Some(0.25));
}

/// MeshCAM's header: the cutter as `TOOL/MILL,d,r,l,a` and the stock as `STOCK/BLOCK, w, l,
/// h, x, y, z` (the program zero from the stock's lowest corner). Plunges through a plate
/// 0.19" thick make through holes as deep as the plate, as wide as the cutter.
#[test]
fn a_meshcam_header_gives_the_cutter_and_the_plate() {
    let program = "%\n(TOOL/MILL,0.1060,0,1.0000,0.0)\nG20\n(STOCK/BLOCK, 4.000, 2.000, 0.190, -0.000, -0.000, 0.190)\nM6 T1\nM3 S10000\n\
                   G0X0.0000Y0.0000Z0.1000\nG0X1.0000Y1.0000\nG1Z-0.2050F1.0\nG0Z0.1000\nG0X2.0000Y1.0000\nG1Z-0.2050F1.0\nG0Z0.1000\nM30\n%\n";
    let a = analyze("fanuc", program);
    assert_eq!(tools(&a), [(1, Some(2.6924), ToolKind::EndMill)]);
    let f = &a.plan.features[0];
    match &f.kind {
        ncplan::plan::FeatureKind::RoundHole { diameter, bottom, positions, .. } => {
            assert_eq!((*diameter, *bottom, positions.len()), (Some(2.6924), ncplan::plan::HoleBottom::Through, 2));
        }
        other => panic!("{other:?}"),
    }
    assert!((f.depth - 4.826).abs() < 1e-9, "{}", f.depth);
}

//! Dialects written as the differences from another (`extends`), and the general
//! capabilities they brought: Haas M97 local subprograms, Mitsubishi `M98 P H` start blocks,
//! Mazak's next tool in a tool-change block, cycles kept as intent, and foreign formats told
//! apart, G10 data forms and Heidenhain polar coordinates. None of these dialects has a line
//! of Rust of its own.

use ncplan::canon::{CanonOp, write_call};
use ncplan::dialect::Registry;
use ncplan::interp::{Profile, interpret};

/// The canonical calls of `program`, one per line, without the internal bookkeeping, and the
/// codes of its error findings.
fn canon(dialect: &str, program: &str) -> (String, Vec<&'static str>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut out = Vec::new();
    let diags = interpret(program, &d, &Profile::default(), &mut out);
    let mut text = String::new();
    for c in &out {
        if matches!(
            c.op,
            CanonOp::StraightTraverse(_)
                | CanonOp::StraightFeed(_)
                | CanonOp::ArcFeed { .. }
                | CanonOp::SelectTool(_)
                | CanonOp::ChangeTool(_)
                | CanonOp::SetFeedRate(_)
        ) {
            write_call(&mut text, &c.op);
        }
    }
    (text, diags.iter().filter(|d| d.is_error()).map(|d| d.code.as_str()).collect())
}

/// Every canonical call of `program`, one per line, and all its findings.
fn every_call(dialect: &str, program: &str) -> (String, Vec<ncplan::diag::Diagnostic>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut out = Vec::new();
    let diags = interpret(program, &d, &Profile::default(), &mut out);
    let mut text = String::new();
    for c in &out {
        write_call(&mut text, &c.op);
    }
    (text, diags)
}

fn moves(text: &str) -> Vec<&str> {
    text.lines().filter(|l| l.starts_with("STRAIGHT")).collect()
}

#[test]
fn haas_m97_calls_a_block_number_of_the_same_file_with_repeats() {
    let program = "%\nO00001\nG21 G90 G0 X0 Y0 Z5.\nM97 P100 L2\nG0 X50.\nM30\nN100 G91 G1 X10. F100.\nG90\nM99\n%\n";
    let (text, errors) = canon("haas", program);
    assert!(errors.is_empty(), "{errors:?}");
    let xs: Vec<&str> = moves(&text).iter().map(|l| l.split(['(', ',']).nth(1).unwrap().trim()).collect();
    assert_eq!(xs, ["0.0000", "10.0000", "20.0000", "50.0000"], "{text}");
    // A missing block is an error that names it.
    let (_, errors) = canon("haas", "G21 G90\nM97 P200\nM30\n");
    assert_eq!(errors, ["flow::missing-label"]);
}

#[test]
fn mitsubishi_m98_h_starts_the_subprogram_at_a_block() {
    let program = "O1\nG21 G90 G0 X0 Y0 Z5.\nM98 P100 H20\nM30\nO100\nN10 G0 X10.\nN20 G0 X20.\nM99\n";
    let (text, errors) = canon("mitsubishi", program);
    assert!(errors.is_empty(), "{errors:?}");
    let m = moves(&text);
    assert_eq!(m.len(), 2, "{text}");
    assert!(m[1].starts_with("STRAIGHT_TRAVERSE(20.0000,"), "{text}");
    // Fanuc has no start block: its M98 runs O100 from the top.
    let (text, _) = canon("fanuc", program);
    assert_eq!(moves(&text).len(), 3, "{text}");
    // Without P, H names a block of the running program, run L times up to its M99, on both
    // the machining centre and the lathe.
    let local = "O1\nG21 G90 G0 X0 Y0 Z5.\nM98 H20 L2\nG0 Z50.\nM30\nN20 G91 G0 X10.\nG90\nM99\n";
    let turned = "O1\nG21 G0 X0 Z5.\nM98 H20 L2\nG0 Z50.\nM30\nN20 G0 U10.\nM99\n";
    for (dialect, program) in [("mitsubishi", local), ("mitsubishi_lathe", turned)] {
        let (text, errors) = canon(dialect, program);
        assert!(errors.is_empty(), "{dialect}: {errors:?}");
        assert_eq!(moves(&text).len(), 4, "{dialect}: {text}");
    }
    let (_, errors) = canon("mitsubishi", "O1\nM98 H30\nM30\n");
    assert_eq!(errors, ["flow::missing-label"]);
    let (_, errors) = canon("fanuc", local);
    assert!(errors.contains(&"syntax::missing-parameter"), "{errors:?}");
}

#[test]
fn mazak_reads_the_second_t_as_the_next_tool() {
    let (text, errors) = canon("mazak", "G21 G90\nT02 T05 M06\nG0 X1 Y1 Z1\nM06\nM30\n");
    assert!(errors.is_empty(), "{errors:?}");
    let tools: Vec<&str> = text.lines().filter(|l| l.contains("TOOL")).collect();
    assert_eq!(tools, ["SELECT_TOOL(2)", "CHANGE_TOOL(2)", "SELECT_TOOL(5)", "CHANGE_TOOL(5)"], "{text}");
    // On Fanuc a second T is still a mistake.
    let (_, errors) = canon("fanuc", "G21 G90\nT02 T05 M06\nM30\n");
    assert_eq!(errors, ["syntax::duplicate-word"]);
}

#[test]
fn a_mazatrol_export_is_named_once_instead_of_failing_on_every_block() {
    let program = "O01040301(MG3-231)\nG300U0(414C554D494E554D)Z100.A0B3\nG420U0\nN1X0.Y0.E0.Z0.\nG421\n";
    let d = Registry::shipped().get("mazak").unwrap();
    let diags = interpret(program, &d, &Profile::default(), &mut Vec::new());
    assert_eq!(diags.len(), 1, "{diags:?}");
    assert_eq!(diags[0].code.as_str(), "text::foreign-format");
    assert!(diags[0].message.contains("Mazatrol"), "{}", diags[0].message);
    assert_eq!(&program[diags[0].range.start as usize..diags[0].range.end as usize], "G300U0");
    // An editor's template with `{$NAME=...}` fields is named the same way, in every dialect
    // that extends Fanuc (Mazak too, beside its own foreign format).
    let template = "%\nO4113 (MACRO EXAMPLE)\n{$DRILLVC=100}\nG0 X{$DIA1}\nM30\n%\n";
    for name in ["fanuc", "mazak", "haas"] {
        let diags = interpret(template, &Registry::shipped().get(name).unwrap(), &Profile::default(), &mut Vec::new());
        assert_eq!(diags.len(), 1, "{name}: {diags:?}");
        assert!(diags[0].message.contains("template"), "{name}: {}", diags[0].message);
    }
}

#[test]
fn haas_pocket_and_engraving_cycles_are_kept_as_intent_without_moving() {
    let (text, errors) =
        canon("haas", "G20 G90 G0 X0 Y0 Z0.1\nG12 I1.5 F10. Z-1.2 D01\nG47 P0 (ABC) X2. Y2. I45. J0.5 R0.05 Z-0.005 F15. E10.\nM30\n");
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(moves(&text).len(), 1, "the depth of G12 is not a move of its own: {text}");
    let d = Registry::shipped().get("haas").unwrap();
    let diags = interpret("G20 G90\nG12 I1.5 F10. Z-1.2 D01\nM30\n", &d, &Profile::default(), &mut Vec::new());
    assert!(diags.iter().any(|d| d.message.contains("G12 (circular pocket milling CW) is kept as intent")), "{diags:?}");
}

#[test]
fn a_user_dialect_extends_another_in_any_file_order() {
    let base = r#"<dialect xmlns="urn:ncplan:dialect:1" name="shop_haas" extends="haas" title="Our Haas">
  <behaviour decimal-input="calculator"/>
</dialect>"#;
    let child = r#"<dialect xmlns="urn:ncplan:dialect:1" name="shop_haas_vf2" extends="shop_haas">
  <groups><group id="flow" letter="M" step="flow"><code value="198" meaning="subprogram-call" name="call from memory card" required="P"/></group></groups>
</dialect>"#;
    let mut r = Registry::shipped();
    // The derived file comes first; it is retried once its base is in.
    r.add_all(&[("b.xml".into(), child.into()), ("a.xml".into(), base.into())]).unwrap();
    let d = r.get("shop_haas_vf2").unwrap();
    assert_eq!(d.family, "haas", "inherited through two levels");
    assert_eq!(d.behaviour.decimal_input, ncplan::dialect::DecimalInput::Calculator);
    assert!(d.codes.iter().any(|c| c.name == "local subprogram call (block number P)"), "Haas's M97 is inherited");
    assert!(d.codes.iter().any(|c| c.name == "call from memory card"));
    assert!(d.codes.iter().any(|c| c.name == "subprogram call"), "Fanuc's M98 stays beside the new M198");
    assert!(d.recognise.is_empty(), "evidence is never inherited");

    // An unknown base is an error at the `extends` attribute.
    let bad = "<dialect xmlns=\"urn:ncplan:dialect:1\"\n  name=\"x\" extends=\"nosuch\"/>";
    let errors = Registry::shipped().add("x.xml", bad).unwrap_err();
    assert_eq!(errors.len(), 1);
    assert!(errors[0].starts_with("x.xml:2:") && errors[0].contains("`nosuch`"), "{errors:?}");
}

/// Okuma's alarm output: a number written to `VDOUT[992]` (its message set in `VUACM[1]`
/// before it) raises the program's alarm and the run stops there, as public OSP macros use it
/// (`NER04` `VUACM[1]='NO DATA "PA"'` `VDOUT[992]=1004` `GOTO NER04`): not a loop that never ends.
#[test]
fn okuma_vdout_992_raises_the_program_s_alarm() {
    let program = "OROTA\n PA=0\n IF[PA EQ 0]NER04\n GOTO N0001\nNER04\n  VUACM[1]='NO DATA \"PA\"'\n  VDOUT[992]=1004\n  GOTO NER04\nN0001\nG0 X10. Y5.\nRTS\n";
    let errors = |program: &str| -> Vec<String> {
        every_call("okuma", program).1.iter().filter(|d| d.is_error()).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect()
    };
    let found = errors(program);
    assert!(found.iter().any(|e| e.starts_with("interp::alarm") && e.contains("raises alarm 1004")), "{found:?}");
    assert!(!found.iter().any(|e| e.starts_with("flow::loop-limit")), "{found:?}");
    // Another element of the array is an output like any other, no alarm.
    let found = errors(&program.replace("VDOUT[992]", "VDOUT[993]"));
    assert!(!found.iter().any(|e| e.starts_with("interp::alarm")), "{found:?}");
}

#[test]
fn okuma_named_blocks_programs_arguments_and_machine_variables() {
    let program = "\
%
O1234
G15 H01
T1 M06
S2000 M03
G00 X10. Y10.
G00 G56 Z50. H01
VC1=0
NLOOP VC1=VC1+1
G01 X=VC1*10 F100
IF [VC1 LT 3] NLOOP
CALL OSUB PZ=-5. PF=500.
G04 F1.000
X=VNTOL
M02
OSUB
G01 Z=PZ F=PF
G00 Z50.
RTS
";
    let (text, errors) = canon("okuma", program);
    assert!(errors.is_empty(), "{errors:?}");
    let xz: Vec<String> = moves(&text)
        .iter()
        .map(|l| {
            let v: Vec<&str> = l.split(['(', ',']).map(str::trim).collect();
            format!("{} {}", v[1], v[3])
        })
        .collect();
    assert_eq!(
        xz,
        [
            "10.0000 0.0000",
            "10.0000 50.0000",
            // The named-block loop runs three times.
            "10.0000 50.0000",
            "20.0000 50.0000",
            "30.0000 50.0000",
            // The named program, with its named arguments.
            "30.0000 -5.0000",
            "30.0000 50.0000",
            // VNTOL is machine data, unknown here: `X=VNTOL` moves nowhere ncplan could say.
        ],
        "{text}"
    );
    assert!(text.contains("SET_FEED_RATE(500.0000)"), "PF=500. reaches the called program");
    let d = Registry::shipped().get("okuma").unwrap();
    let diags = interpret(program, &d, &Profile::default(), &mut Vec::new());
    let unknown: Vec<&str> = diags.iter().filter(|d| d.code.as_str() == "interp::unknown-value").map(|d| d.message.as_str()).collect();
    assert_eq!(unknown.len(), 1, "{unknown:?}");
    assert!(unknown[0].starts_with("`vntol` is neither declared nor set in this file"), "{unknown:?}");
    // Fanuc reads G15 as polar coordinates off and has no named programs.
    let (_, errors) = canon("fanuc", program);
    assert!(!errors.is_empty());
}

#[test]
fn fagor_statements_parameters_and_local_subroutines() {
    let program = "\
; PART1
G90 G94 G17
G71
G51 A45 E0.002
G54
T1 M6
S3000 M3
P1=0
$WHILE P1 < 3
  P1=P1+1
  G1 X P1 Y0 F500
$ENDWHILE
$FOR P2=10,30,10
  G0 X P2 Y5
$ENDFOR
$IF P1 == 3
  #CALL L100
$ELSE
  G0 X999
$ENDIF
$GOTO N20
G0 X888
N20 G4 K0.5
M30
%L 100
G0 X10 Y10
G1 Z-2 F100
G0 Z5
M17
";
    let (text, errors) = canon("fagor", program);
    assert!(errors.is_empty(), "{errors:?}");
    let xyz: Vec<String> = moves(&text)
        .iter()
        .map(|l| {
            let v: Vec<&str> = l.split(['(', ',']).map(str::trim).collect();
            format!("{} {} {}", v[1], v[2], v[3])
        })
        .collect();
    let want = [
        // $WHILE, three passes.
        "1.0000 0.0000 0.0000",
        "2.0000 0.0000 0.0000",
        "3.0000 0.0000 0.0000",
        // $FOR with a step of 10.
        "10.0000 5.0000 0.0000",
        "20.0000 5.0000 0.0000",
        "30.0000 5.0000 0.0000",
        // #CALL L100 runs %L 100 up to M17; $ELSE and the block $GOTO skips do not run.
        "10.0000 10.0000 0.0000",
        "10.0000 10.0000 -2.0000",
        "10.0000 10.0000 5.0000",
    ];
    assert_eq!(xyz, want, "{text}");
    // G51 is look-ahead here: its A word is not a rotary move, and nothing is scaled.
    let d = Registry::shipped().get("fagor").unwrap();
    let diags = interpret(program, &d, &Profile::default(), &mut Vec::new());
    assert!(diags.is_empty(), "{diags:?}");
}

#[test]
fn a_non_motion_code_keeps_the_axis_words_it_takes() {
    // Fanuc `G4 X1.5` dwells 1.5 s; it does not also move X under the modal G1.
    let (text, errors) = canon("fanuc", "G21 G90 G1 X0 Y0 F100.\nG4 X1.5\nM30\n");
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(moves(&text).len(), 1, "{text}");
    // G9 lists no axis words: those of its block belong to the modal move.
    let (text, errors) = canon("fanuc", "G21 G90 G1 X0 Y0 F100.\nG09 X10. Y5.\nM30\n");
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(moves(&text).len(), 2, "{text}");
}

#[test]
fn g10_sets_what_each_dialect_says_its_l_values_set() {
    let offsets = |dialect: &str, program: &str| -> Vec<String> {
        let d = Registry::shipped().get(dialect).unwrap();
        let mut out = Vec::new();
        let diags = interpret(program, &d, &Profile::default(), &mut out);
        assert!(diags.iter().all(|d| !d.is_error()), "{diags:?}");
        out.iter()
            .filter(|c| matches!(c.op, CanonOp::UseToolLengthOffset(_)))
            .map(|c| {
                let mut s = String::new();
                write_call(&mut s, &c.op);
                s.split(", ").next().unwrap().rsplit(' ').next().unwrap().to_owned()
            })
            .collect()
    };
    // Fanuc memory C: L10 length geometry, L11 length wear (added to it; in G91 added to
    // the old wear), L12/L13 radius geometry and wear.
    let fanuc = "G21 G90\nG10 L10 P5 R100.\nG10 L11 P5 R-0.5\nG43 H5 Z10.\nG91 G10 L11 P5 R-0.5\nG90 G43 H5 Z10.\nG10 L12 P5 R4.\nM30\n";
    assert_eq!(offsets("fanuc", fanuc), ["99.5000", "99.0000"]);
    // LinuxCNC: L1 sets tool P's length, L10 so that the current Z reads as given.
    let linuxcnc = "G21 G90\nG10 L1 P5 Z100\nG43 H5\nG0 Z10\nG10 L10 P5 Z0\nG43 H5\nM2\n";
    assert_eq!(offsets("linuxcnc", linuxcnc), ["100.0000", "110.0000"]);
    // Fanuc's L20 sets an additional work offset (`G54.1 P1`), not LinuxCNC's "set from here":
    // the move after selecting it lands 10 further in machine X and Y.
    let d = Registry::shipped().get("fanuc").unwrap();
    let mut canon = Vec::new();
    let diags = interpret("G21 G90\nG10 L20 P1 X10. Y10.\nG54.1 P1\nG0 X0 Y0\nG54\nG0 X0 Y0\nM30\n", &d, &Profile::default(), &mut canon);
    assert!(diags.iter().all(|d| !d.is_error() && d.severity != ncplan::diag::Severity::Warning), "{diags:?}");
    let offsets: Vec<(u16, f64)> =
        canon.iter().filter_map(|c| if let CanonOp::SetG5xOffset(i, v) = c.op { Some((i, v[0])) } else { None }).collect();
    assert!(offsets.contains(&(ncplan::canon::EXTENDED_WCS + 1, 10.0)), "{offsets:?}");
    assert!(offsets.contains(&(1, 0.0)), "{offsets:?}");
    // An L the dialect does not list is named.
    let diags = interpret("G21 G90\nG10 L50 P1\nM30\n", &d, &Profile::default(), &mut Vec::new());
    assert!(diags.iter().any(|d| d.message.contains("G10 L50 is not a data-setting form of the fanuc dialect")), "{diags:?}");
}

#[test]
fn heidenhain_polar_lines_and_arcs_about_the_pole() {
    let program = "\
0 BEGIN PGM POLAR MM
1 TOOL CALL 1 Z S1000
2 CC X+50 Y+50
3 L X+80 Y+50 Z-2 R0 FMAX
4 LP PA+90 F200
5 LP PR+10
6 CP IPA+90 DR+
7 LP IPA-90 IPR+5
8 END PGM POLAR MM
";
    let (text, errors) = canon("heidenhain", program);
    assert!(errors.is_empty(), "{errors:?}");
    let calls: Vec<&str> = text.lines().filter(|l| !l.starts_with("SET_FEED") && !l.contains("TOOL")).collect();
    assert_eq!(
        calls,
        [
            "STRAIGHT_TRAVERSE(80.0000, 50.0000, -2.0000, 0.0000, 0.0000, 0.0000)",
            // PA alone keeps the distance to the pole (30); PR alone keeps the angle (90°).
            "STRAIGHT_FEED(50.0000, 80.0000, -2.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(50.0000, 60.0000, -2.0000, 0.0000, 0.0000, 0.0000)",
            // CP: a quarter circle about the pole, counter-clockwise, to 180°.
            "ARC_FEED(40.0000, 50.0000, 50.0000, 50.0000, 1, -2.0000, 0.0000, 0.0000, 0.0000)",
            // IPA and IPR add to the current angle and distance.
            "STRAIGHT_FEED(50.0000, 65.0000, -2.0000, 0.0000, 0.0000, 0.0000)",
        ],
        "{text}"
    );
}

#[test]
fn siemens_arcs_by_opening_angle_and_through_an_intermediate_point() {
    let program = "\
%_N_ARCS_MPF
N10 G17 G710 G90 G94
N20 T1 D1
N30 M6
N40 S1000 M3
N50 G0 X0 Y0 Z2
N60 G1 Z-1 F200
N70 G1 X10 Y0
N80 G3 X10 Y20 AR=180
N90 G2 I0 J-10 AR=90
N100 CIP X30 Y0 I1=28 J1=6
N110 M30
";
    let (text, errors) = canon("siemens", program);
    assert!(errors.is_empty(), "{errors:?}");
    let arcs: Vec<&str> = text.lines().filter(|l| l.starts_with("ARC")).collect();
    assert_eq!(
        arcs,
        [
            // End point and opening angle: the centre is on the chord's bisector.
            "ARC_FEED(10.0000, 20.0000, 10.0000, 10.0000, 1, -1.0000, 0.0000, 0.0000, 0.0000)",
            // Centre and opening angle: the end point is the start turned by AR.
            "ARC_FEED(20.0000, 10.0000, 10.0000, 10.0000, -1, -1.0000, 0.0000, 0.0000, 0.0000)",
            // Three points: the circle through them, clockwise as they run.
            "ARC_FEED(30.0000, 0.0000, 20.0000, 0.0000, -1, -1.0000, 0.0000, 0.0000, 0.0000)",
        ],
        "{text}"
    );
    let (_, errors) = canon("siemens", "G17 G90 G0 X0 Y0\nG1 F100\nCIP X20 Y0 I1=10 J1=0\nM30\n");
    assert_eq!(errors, ["interp::bad-arc"], "three points on a line");
}

/// Siemens hole patterns: `HOLES1` (a row), `HOLES2` (a circle) and `CYCLE801` (a grid)
/// run the modal cycle of `MCALL` at each position; without one they only approach the
/// positions. The row is the reference's example (dialects.md §9.4): holes at X10, X20, X30.
#[test]
fn siemens_hole_patterns_run_the_modal_cycle_at_each_position() {
    let holes = |program: &str| -> Vec<String> {
        let (text, errors) = canon("siemens", program);
        assert!(errors.is_empty(), "{errors:?}");
        // The plunges: one feed to the bottom per hole.
        text.lines()
            .filter(|l| l.starts_with("STRAIGHT_FEED"))
            .map(|l| l[14..l.find(", 0.0000, 0.0000, 0.0000)").unwrap()].to_owned())
            .collect()
    };
    let row = "N10 G0 X0 Y0 Z100\nN15 T1 D1 M6\nN16 S1000 M3 F100\nN20 MCALL CYCLE81(10, 0, 2, -10, 0)\nN30 HOLES1(0, 0, 0, 10, 10, 3)\nN40 MCALL\nN50 M30\n";
    assert_eq!(holes(row), ["10.0000, 0.0000, -10.0000", "20.0000, 0.0000, -10.0000", "30.0000, 0.0000, -10.0000"]);
    // A circle of four from -90°, the angle between them left to the cycle (INDA 0); then a
    // row at 45°.
    let circle =
        "G0 X0 Y0 Z10\nF100\nMCALL CYCLE81(10, 0, 2, , 5)\nHOLES2(50, 50, 20, -90, 0, 4)\nHOLES1(0, 0, 45, 10, 10, 1)\nMCALL\nM30\n";
    assert_eq!(
        holes(circle),
        [
            "50.0000, 30.0000, -5.0000",
            "70.0000, 50.0000, -5.0000",
            "50.0000, 70.0000, -5.0000",
            "30.0000, 50.0000, -5.0000",
            "7.0711, 7.0711, -5.0000"
        ]
    );
    // A grid of three columns and two rows, the second row run back.
    let grid = "G0 X0 Y0 Z10\nF100\nMCALL CYCLE82(10, 0, 2, -3, , 0.5)\nCYCLE801(100, 0, 0, 10, 5, 3, 2)\nMCALL\nM30\n";
    assert_eq!(
        holes(grid),
        [
            "100.0000, 0.0000, -3.0000",
            "110.0000, 0.0000, -3.0000",
            "120.0000, 0.0000, -3.0000",
            "120.0000, 5.0000, -3.0000",
            "110.0000, 5.0000, -3.0000",
            "100.0000, 5.0000, -3.0000"
        ]
    );
    // Without a modal cycle the positions are only approached.
    let (text, errors) = canon("siemens", "G0 X0 Y0 Z10\nHOLES1(0, 0, 90, 5, 5, 2)\nM30\n");
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(text.lines().filter(|l| l.starts_with("STRAIGHT_TRAVERSE")).count(), 3, "{text}");
    assert!(!text.contains("FEED("), "{text}");
    // The plan sees drilled holes, as from any other drilling cycle.
    let d = Registry::shipped().get("siemens").unwrap();
    let a = ncplan::pipeline::analyze(row.as_bytes(), &d, &Profile::default());
    let positions: Vec<usize> = a
        .plan
        .features
        .iter()
        .filter_map(|f| match &f.kind {
            ncplan::plan::FeatureKind::RoundHole { positions, .. } => Some(positions.len()),
            _ => None,
        })
        .collect();
    assert_eq!(positions, [3], "{:?}", a.plan.features);
    // A pattern without its count, or with an absurd one, is named and skipped.
    let (_, errors) = canon("siemens", "MCALL CYCLE81(10, 0, 2, -10)\nHOLES1(0, 0, 0, 10, 10)\nHOLES2(0, 0, 5, 0, 0, 1EX9)\nMCALL\nM30\n");
    assert_eq!(errors, ["syntax::missing-parameter"; 2]);
}

/// Haas bolt-hole patterns through the code's own argument roles (`args="I:pattern-radius
/// ..."`): G70 spreads L holes on a circle of radius I from angle J about the current
/// position, G71 steps K degrees (a negative I runs clockwise); the canned cycle in force
/// drills each. Without a canned cycle, the pattern is named and skipped.
#[test]
fn haas_bolt_hole_patterns_drill_with_the_canned_cycle_in_force() {
    let program =
        "T1 M6\nG0 G90 G54 X0. Y0. S1000 M3\nG43 H1 Z1.\nG81 G98 Z-0.5 R0.1 F10. L0\nG70 I1. J0. L4\nG71 I-2. J90. K30. L3\nG80\nM30\n";
    let (text, errors) = canon("haas", program);
    assert!(errors.is_empty(), "{errors:?}");
    let holes: Vec<&str> = text.lines().filter(|l| l.starts_with("STRAIGHT_FEED")).collect();
    assert_eq!(
        holes,
        [
            // L0 on the G81 block: no hole at the centre; then four on the circle from 3 o'clock.
            "STRAIGHT_FEED(1.0000, 0.0000, -0.5000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(0.0000, 1.0000, -0.5000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(-1.0000, 0.0000, -0.5000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(0.0000, -1.0000, -0.5000, 0.0000, 0.0000, 0.0000)",
            // About the last hole, X0 Y-1 (a G0 would end the canned cycle), radius 2, from 90°
            // clockwise by 30°: three holes on an arc.
            "STRAIGHT_FEED(0.0000, 1.0000, -0.5000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(1.0000, 0.7321, -0.5000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(1.7321, 0.0000, -0.5000, 0.0000, 0.0000, 0.0000)",
        ],
        "{text}"
    );
    let (_, errors) = canon("haas", "G0 X0. Y0. Z1.\nG70 I1. J0. L4\nM30\n");
    assert_eq!(errors, ["interp::cycle-incomplete"]);
}

/// Siemens polar coordinates by dictionary: G111 sets the pole from the work zero, G110 from
/// the last point, G112 from the last pole; `AP=` and `RP=` place the end point about it (a
/// missing one keeps the current point's), and an arc with a polar end point turns about it.
#[test]
fn siemens_polar_coordinates_about_the_pole() {
    let program = "G17 G90 T1 D1 M6\nS1000 M3 F200\nG0 X0 Y0 Z2\nG111 X10 Y10\nG1 AP=0 RP=20\nG3 AP=90\nG1 RP=10\nG110 X5\nG1 AP=180 RP=10\nG112 Y1\nG0 AP=90 RP=1\nM30\n";
    let (text, errors) = canon("siemens", program);
    assert!(errors.is_empty(), "{errors:?}");
    let moves: Vec<String> =
        text.lines().filter(|l| l.contains("FEED(") || l.contains("TRAVERSE(")).map(|l| l.replace(".0000", "")).collect();
    assert_eq!(
        moves,
        [
            "STRAIGHT_TRAVERSE(0, 0, 2, 0, 0, 0)",
            // Pole X10 Y10: 20 along 0°.
            "STRAIGHT_FEED(30, 10, 2, 0, 0, 0)",
            // A quarter circle about the pole to 90°.
            "ARC_FEED(10, 30, 10, 10, 1, 2, 0, 0, 0)",
            // RP=10 keeps the angle.
            "STRAIGHT_FEED(10, 20, 2, 0, 0, 0)",
            // G110 X5: the pole 5 right of that point, X15 Y20; 10 along 180°.
            "STRAIGHT_FEED(5, 20, 2, 0, 0, 0)",
            // G112 Y1: the pole 1 above the last, X15 Y21.
            "STRAIGHT_TRAVERSE(15, 22, 2, 0, 0, 0)",
        ],
        "{text}"
    );
}

/// Siemens number notations and system variables, both switched on in `siemens.xml`:
/// `EX` exponents, `'H..'` and `'B..'` constants, and `$` names for the control's own data,
/// which the program may write; read before it writes them, they are unknown values (the
/// machine has them, this file does not), so `X=_R` from `$AC_CTOL` leaves X where it is.
#[test]
fn siemens_exponents_radix_constants_and_system_variables() {
    let program = "\
DEF REAL _R
N10 G1 F100 X=10EX-1 Y=.5EX2
N20 R1='H1F'+'B101'
N30 G1 X=R1 Z30.4EX-4
N40 $R10=5
N50 G1 Y=$R10
N60 _R=$AC_CTOL*2+1
N70 G1 X=_R
N80 IF $A_IN[1]==1 GOTOF SKIP
N90 G1 Z-1
SKIP:
N100 M30
";
    let (text, errors) = canon("siemens", program);
    assert!(errors.is_empty(), "{errors:?}");
    let feeds: Vec<&str> = text.lines().filter(|l| l.starts_with("STRAIGHT_FEED")).collect();
    assert_eq!(
        feeds,
        [
            "STRAIGHT_FEED(1.0000, 50.0000, 0.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(36.0000, 50.0000, 0.0030, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(36.0000, 5.0000, 0.0030, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(36.0000, 5.0000, -1.0000, 0.0000, 0.0000, 0.0000)",
        ],
        "{text}"
    );
    let (_, diags) = every_call("siemens", program);
    let unknown: Vec<&str> = diags.iter().filter(|d| d.code.as_str() == "interp::unknown-value").map(|d| d.message.as_str()).collect();
    assert!(unknown.iter().any(|m| m.contains("$ac_ctol")) && unknown.iter().any(|m| m.contains("$a_in[1]")), "{unknown:?}");
    assert!(!diags.iter().any(|d| d.code.as_str() == "interp::unset-variable"), "never a made-up 0: {diags:?}");

    let (_, errors) = canon("siemens", "R1='H1G'\nR2=1EX\nR3='X12'\nM30\n");
    assert_eq!(errors, ["syntax::malformed-number"; 3]);
    // Elsewhere `E` is no exponent: Fanuc reads `X1E3` as X1 and an E word.
    let (text, _) = canon("fanuc", "G1 F100 X1EX3\nM30\n");
    assert!(!text.contains("1000.0000"), "{text}");
}

/// Heidenhain `RND R` and `CHF` between two straight moves: the first move stops at the
/// tangent point, the arc (about a centre inside the turn) or the chamfer follows, and the
/// next move starts at the second tangent point. A feed on the corner block applies from the
/// corner on. A corner without a straight move after it stays sharp with a warning.
#[test]
fn heidenhain_rounds_and_chamfers_corners_written_between_moves() {
    let program = "0 BEGIN PGM CORNERS MM\n1 TOOL CALL 1 Z S1000\n2 L X+0 Y+0 Z-5 R0 F100 M3\n\
                   3 L X+20 Y+0\n4 RND R5 F50\n5 L X+20 Y+20\n6 CHF 2\n7 L X+0 Y+20\n8 RND R3\n9 L Z+10 FMAX\n10 END PGM CORNERS MM\n";
    let d = Registry::shipped().get("heidenhain").unwrap();
    let mut out = Vec::new();
    let diags = interpret(program, &d, &Profile::default(), &mut out);
    let mut text = String::new();
    for c in &out {
        if matches!(c.op, CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. } | CanonOp::SetFeedRate(_)) {
            write_call(&mut text, &c.op);
        }
    }
    expect_test::expect![[r#"
        SET_FEED_RATE(100.0000)
        STRAIGHT_FEED(0.0000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(15.0000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        SET_FEED_RATE(50.0000)
        ARC_FEED(20.0000, 5.0000, 15.0000, 5.0000, 1, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(20.0000, 18.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(18.0000, 20.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(0.0000, 20.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(0.0000, 20.0000, 10.0000, 0.0000, 0.0000, 0.0000)
        SET_FEED_RATE(0.0000)
    "#]]
    .assert_eq(&text);
    let warnings: Vec<_> = diags.iter().map(|d| (d.code.as_str(), d.message.as_str())).collect();
    assert_eq!(warnings.len(), 1, "{warnings:?}");
    assert!(warnings[0].1.contains("followed by a straight feed move"), "{warnings:?}");
    // A radius too large for the moves beside the corner is reported, and the corner stays sharp.
    let (text, _) = canon("heidenhain", "0 BEGIN PGM C MM\n1 L X+0 Y+0 R0 F100\n2 L X+4 Y+0\n3 RND R10\n4 L X+4 Y+4\n5 END PGM C MM\n");
    assert!(text.contains("STRAIGHT_FEED(4.0000, 0.0000"), "{text}");
}

/// Fanuc's optional chamfering and corner R (`,C` `,R` at the end of a move; Haas, Mitsubishi
/// and Mazak inherit them) and Siemens `CHF=`, a chamfer measured along itself, make the same
/// corners as the corner blocks; a lathe's corners are made in its ZX plane, with `,C` in
/// radius. Fagor, which blends with G36/G39, does not read the comma words.
#[test]
fn corner_words_round_and_chamfer_in_the_working_plane() {
    let mill = "O1000\nG21 G90 G17\nG0 X0 Y0 Z5.\nG1 Z-2. F100.\nG1 X50. ,R5.\nY30. ,C2.\nX0\nY0\nM30\n";
    for dialect in ["fanuc", "haas", "mitsubishi", "mazak"] {
        let (text, errors) = canon(dialect, mill);
        assert!(errors.is_empty(), "{dialect}: {errors:?}");
        expect_test::expect![[r#"
            STRAIGHT_TRAVERSE(0.0000, 0.0000, 5.0000, 0.0000, 0.0000, 0.0000)
            SET_FEED_RATE(100.0000)
            STRAIGHT_FEED(0.0000, 0.0000, -2.0000, 0.0000, 0.0000, 0.0000)
            STRAIGHT_FEED(45.0000, 0.0000, -2.0000, 0.0000, 0.0000, 0.0000)
            ARC_FEED(50.0000, 5.0000, 45.0000, 5.0000, 1, -2.0000, 0.0000, 0.0000, 0.0000)
            STRAIGHT_FEED(50.0000, 28.0000, -2.0000, 0.0000, 0.0000, 0.0000)
            STRAIGHT_FEED(48.0000, 30.0000, -2.0000, 0.0000, 0.0000, 0.0000)
            STRAIGHT_FEED(0.0000, 30.0000, -2.0000, 0.0000, 0.0000, 0.0000)
            STRAIGHT_FEED(0.0000, 0.0000, -2.0000, 0.0000, 0.0000, 0.0000)
            SET_FEED_RATE(0.0000)
        "#]]
        .assert_eq(&text);
    }
    let (_, errors) = canon("fagor", "G90 G17\nG1 X50 ,R5 F100\nY30\nM30\n");
    assert!(errors.contains(&"syntax::unknown-address"), "{errors:?}");
    // A turned shoulder: a 2 mm chamfer at X40, an R3 fillet at Z-30, in the ZX plane
    // (X in radius in the canonical calls; ARC_FEED's first axis is Z).
    let (text, errors) =
        canon("fanuc_lathe", "G18 G21 G40\nT0101\nG97 S500 M3\nG0 X20. Z2.\nG1 Z0 F.2\nX40. ,C2.\nZ-30. ,R3.\nX60.\nM30\n");
    assert!(errors.is_empty(), "{errors:?}");
    assert!(text.contains("STRAIGHT_FEED(18.0000, 0.0000, 0.0000,"), "{text}");
    assert!(text.contains("STRAIGHT_FEED(20.0000, 0.0000, -2.0000,"), "{text}");
    assert!(text.contains("STRAIGHT_FEED(20.0000, 0.0000, -27.0000,"), "{text}");
    assert!(text.contains("ARC_FEED(-30.0000, 23.0000, -27.0000, 23.0000, -1, 0.0000,"), "{text}");
    // Siemens: CHF= 2.828427 on a right angle cuts back 2 along each move, as CHR=2 does.
    let (chf, _) = canon("siemens", "G17 G90 G71\nG1 X0 Y0 Z-2 F100\nX50 CHF=2.828427\nY30\nM30\n");
    let (chr, _) = canon("siemens", "G17 G90 G71\nG1 X0 Y0 Z-2 F100\nX50 CHR=2\nY30\nM30\n");
    assert!(chf.contains("STRAIGHT_FEED(48.0000, 0.0000, -2.0000,") && chf.contains("STRAIGHT_FEED(50.0000, 2.0000, -2.0000,"), "{chf}");
    assert_eq!(chf, chr);
}

/// Heidenhain `APPR LT`/`APPR LN` reach the contour point from an auxiliary point LEN away,
/// along the first contour element or perpendicular to it on the compensation side (known
/// only when that element arrives); `DEP LT`/`DEP LN` leave along the last element or
/// perpendicular to it. Arc forms go straight, with a warning.
#[test]
fn heidenhain_approaches_and_departures_follow_the_contour() {
    let program = "0 BEGIN PGM A MM\n1 TOOL CALL 1 Z S1000\n2 L X-20 Y-20 Z-5 R0 FMAX M3\n\
                   3 APPR LT X+0 Y+0 LEN 10 R0 F100\n4 L X+20 Y+0\n5 L X+20 Y+20\n6 DEP LT LEN 5\n\
                   7 APPR LN X+0 Y+0 LEN 3 RL\n8 CC X+0 Y+10\n9 C X+0 Y+20 DR+\n10 DEP LN LEN 4 R0\n\
                   11 APPR CT X+5 Y+5 CCA 90 R5\n12 L Z+10 FMAX\n13 END PGM A MM\n";
    let (text, errors) = canon("heidenhain", program);
    assert!(errors.is_empty(), "{errors:?}");
    expect_test::expect![[r#"
        STRAIGHT_TRAVERSE(-20.0000, -20.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(-10.0000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(0.0000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(20.0000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(20.0000, 20.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(20.0000, 25.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(0.0000, 3.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(0.0000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(0.0000, 16.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_FEED(5.0000, 5.0000, -5.0000, 0.0000, 0.0000, 0.0000)
        STRAIGHT_TRAVERSE(5.0000, 5.0000, 10.0000, 0.0000, 0.0000, 0.0000)"#]]
    .assert_eq(&moves(&text).join("\n"));
}

/// FreeCAD posted the same jobs for Centroid and for LinuxCNC (`../shared/corpus`): read in
/// their own dialects, with no error, both give the same cutting moves. Centroid's `M25` is
/// read as Z straight home (a rapid, not compared); the Centroid preamble's `G53 G00` has no
/// axes.
#[test]
fn centroid_and_linuxcnc_posts_of_one_job_give_the_same_moves() {
    let Some(corpus) = crate::shared_corpus("derived::centroid_and_linuxcnc_posts_of_one_job_give_the_same_moves") else { return };
    for (centroid, linuxcnc) in [
        ("freecad__test_centroid_01.ngc", "freecad__test_linuxcnc_01.ngc"),
        ("freecad__test_centroid_metric_ref.ngc", "freecad__test_linuxcnc_metric_ref.ngc"),
    ] {
        let read = |folder: &str, file: &str| std::fs::read_to_string(corpus.join(folder).join(file)).unwrap();
        let (a, a_errors) = canon("centroid", &read("centroid", centroid));
        let (b, b_errors) = canon("linuxcnc", &read("linuxcnc", linuxcnc));
        assert!(a_errors.is_empty() && b_errors.is_empty(), "{a_errors:?} {b_errors:?}");
        let cutting = |t: &str| {
            t.lines().filter(|l| l.starts_with("STRAIGHT_FEED") || l.starts_with("ARC_FEED")).map(str::to_owned).collect::<Vec<_>>()
        };
        assert!(cutting(&a).len() > 5);
        assert_eq!(cutting(&a), cutting(&b), "{centroid}");
    }
}

#[test]
fn mach3_probes_with_g31_and_records_output_triggers_and_user_macros() {
    let program =
        "G20 G90 F55\nG0 X1 Y1 Z0.2\nM900 (THC check)\nG31 Z-11.8\n#1=#2002\nG92 Z0\nM3 S1000\nM11P1\nG1 X2 F140\nM10P1\nM5 M30\n";
    let (text, diags) = every_call("mach3", program);
    assert!(!diags.iter().any(|x| x.is_error()), "{diags:?}");
    assert!(text.contains("TURN_PROBE_ON()\nSTRAIGHT_PROBE(1.0000, 1.0000, -11.8000, 0.0000, 0.0000, 0.0000)\nTURN_PROBE_OFF()"), "{text}");
    // M900 is a user macro: recorded, named, no effect.
    assert!(diags.iter().any(|x| x.message.contains("`M900` is a machine-builder M code")), "{diags:?}");
    // LinuxCNC has neither G31 nor M10/M11 with P.
    let linuxcnc = Registry::shipped().get("linuxcnc").unwrap();
    let errors: Vec<_> = interpret(program, &linuxcnc, &Profile::default(), &mut Vec::new())
        .into_iter()
        .filter(|x| x.is_error())
        .map(|x| x.message)
        .collect();
    assert!(errors.iter().any(|m| m.contains("G31")) && errors.iter().any(|m| m.contains("M11")), "{errors:?}");
    // The sniffer tells a Mach3 plasma program from LinuxCNC.
    let sniffed = Registry::shipped().sniff(program, Some("part.tap"), "linuxcnc");
    assert_eq!(sniffed.dialect, "mach3", "{sniffed:?}");
}

#[test]
fn okuma_lathe_reads_diameters_in_the_zx_plane() {
    let program = "$SHAFT.MIN%\nO100\nVGRIN[2]=40\nG50 S3000\nG0 X=VGRIN[2] Z5\nG96 S200 M3\nG1 Z-10 F0.2\nG2 X50 Z-15 K-5\nG1 X60\nM2\n";
    let (text, diags) = every_call("okuma_lathe", program);
    assert!(!diags.iter().any(|x| x.is_error()), "{diags:?}");
    assert!(text.starts_with("SELECT_PLANE(CANON_PLANE_XZ)\n"), "{text}");
    // X40 is a diameter: the tool is 20 from the axis; the arc turns about Z-15, X20 (K is
    // along Z, the radius 5 is not halved) to diameter 50.
    assert!(text.contains("STRAIGHT_TRAVERSE(20.0000, 0.0000, 5.0000,"), "{text}");
    assert!(text.contains("ARC_FEED(-15.0000, 25.0000, -15.0000, 20.0000, -1,"), "{text}");
    assert!(text.contains("STRAIGHT_FEED(30.0000, 0.0000, -15.0000,"), "{text}");
    // G50 S limits the speed, and G96 takes that limit; only G96's S sets the speed.
    assert!(!text.contains("SET_SPINDLE_SPEED(0, 3000.0000)"), "{text}");
    assert!(text.contains("SET_SPINDLE_MODE(0 3000.0000)\nSET_SPINDLE_SPEED(0, 200.0000)\n"), "{text}");
    // The machining-centre dialect reads the same words in the XY plane, as radii.
    let (text, _) = canon("okuma", program);
    assert!(text.contains("STRAIGHT_TRAVERSE(40.0000, 0.0000, 5.0000,"), "{text}");
    assert_eq!(Registry::shipped().sniff(program, Some("SHAFT.MIN"), "fanuc").dialect, "okuma_lathe");
}

/// A Fanuc lathe in G-code system A, by dictionary alone: diameters, U/W increments, a
/// turret that changes on the T word (`T0202`: tool 2, offset 2), feed per revolution from
/// the start, G50 S as the speed limit and G50 X Z as the coordinate system; in system B,
/// G92 S, G90/G91 and G94/G95 instead.
#[test]
fn fanuc_lathe_reads_diameters_turret_tools_and_its_own_codes() {
    let program = "%\nO0358\nG50 S2000\nT0202\nG96 S200 M3\nG0 X50. Z2.\nG1 Z-20. F0.2\nU10. W-5.\nX70\nG0 X100. Z100. T0200\nT0505\nG97 S500\nG0 X40. Z5.\nG32 Z-10. F1.5\nG50 X100. Z50.\nG0 X80.\nM30\n%\n";
    let (text, diags) = every_call("fanuc_lathe", program);
    assert!(!diags.iter().any(|x| x.is_error()), "{diags:?}");
    assert!(text.starts_with("SELECT_PLANE(CANON_PLANE_XZ)\nSET_FEED_MODE(0, 1)\n"), "{text}");
    // The turret indexes on T: no M6.
    assert!(text.contains("SELECT_TOOL(2)\nCHANGE_TOOL(2)\n"), "{text}");
    assert!(text.contains("SELECT_TOOL(5)\nCHANGE_TOOL(5)\n"), "{text}");
    assert_eq!(text.matches("CHANGE_TOOL(2)").count(), 1, "T0200 cancels the offset and keeps tool 2: {text}");
    // Diameters: X50. is 25 from the axis; U10. W-5. moves 5 out and 5 along Z.
    assert!(text.contains("STRAIGHT_TRAVERSE(25.0000, 0.0000, 2.0000,"), "{text}");
    assert!(text.contains("STRAIGHT_FEED(30.0000, 0.0000, -25.0000,"), "{text}");
    // `X70` without a point beside lengths with one: 70 µm, and a warning that says so.
    assert!(text.contains("STRAIGHT_FEED(0.0350, 0.0000, -25.0000,"), "{text}");
    let warning = diags.iter().find(|d| d.code.as_str() == "interp::no-decimal-point").expect("a warning for X70");
    assert!(warning.message.contains("0.07 mm") && warning.message.contains("write `X70.`"), "{}", warning.message);
    // G50 S limits the speed under G96; G32 cuts the thread synchronised with the spindle.
    assert!(text.contains("SET_SPINDLE_MODE(0 2000.0000)"), "{text}");
    assert!(text.contains("START_SPEED_FEED_SYNC(1.500000,0)\nSTRAIGHT_FEED(20.0000, 0.0000, -10.0000,"), "{text}");
    // G50 X100. Z50. makes the position there (X20 Z-10 from the axis and origin) X100
    // (diameter) Z50, as G92 does: an offset of -30 and -60, and X80. is 40 from the new axis.
    assert!(
        text.contains("SET_G92_OFFSET(-30.0000, 0.0000, -60.0000, 0.0000, 0.0000, 0.0000)\nSTRAIGHT_TRAVERSE(40.0000, 0.0000, 50.0000,"),
        "{text}"
    );

    // System B: G92 S is the limit, G95 feed per revolution, G90 absolute; U is no increment.
    let b = "G92 S1500\nG95\nG90 G0 X40. Z2.\nG91 G1 Z-10. F0.2\nM30\n";
    let (text, diags) = every_call("fanuc_lathe_b", b);
    assert!(!diags.iter().any(|x| x.is_error()), "{diags:?}");
    assert!(text.contains("STRAIGHT_FEED(20.0000, 0.0000, -8.0000,"), "{text}");
    let shipped = Registry::shipped();
    assert_eq!(shipped.sniff(program, Some("O0358.NC"), "fanuc").dialect, "fanuc_lathe");
    assert_eq!(shipped.sniff(b, Some("O0001.NC"), "fanuc").dialect, "fanuc_lathe_b");
}

/// A Fanuc lathe's single-pass cycles, modal and with their data carried over: G90 turns
/// (rapid in, feed along Z, feed out, rapid back), G94 faces, G92 threads one pass; R is the
/// taper as a radius.
#[test]
fn fanuc_lathe_single_pass_cycles_run_as_four_moves() {
    let program = "T0101\nG97 S800 M3\nG0 X52. Z2.\nG90 X48. Z-30. F0.25\nX44.\nX40. R-2.\nG0 X52. Z2.\nG94 X20. Z-2. F0.2\nZ-4.\nG0 X40. Z5.\nG92 X38. Z-20. F1.5\nX37.4\nM30\n";
    let (text, diags) = every_call("fanuc_lathe", program);
    assert!(!diags.iter().any(|x| x.is_error()), "{diags:?}");
    let moves: Vec<String> = text
        .lines()
        .filter(|l| l.starts_with("STRAIGHT") || l.starts_with("START_SPEED"))
        .map(|l| l.replace(", 0.0000, 0.0000, 0.0000)", ")").replace(".0000", ""))
        .collect();
    let expected = [
        "STRAIGHT_TRAVERSE(26, 0, 2)",
        // G90 X48. Z-30.: the start point is X26 Z2 (radii).
        "STRAIGHT_TRAVERSE(24, 0, 2)",
        "STRAIGHT_FEED(24, 0, -30)",
        "STRAIGHT_FEED(26, 0, -30)",
        "STRAIGHT_TRAVERSE(26, 0, 2)",
        // X44.: again, to Z-30.
        "STRAIGHT_TRAVERSE(22, 0, 2)",
        "STRAIGHT_FEED(22, 0, -30)",
        "STRAIGHT_FEED(26, 0, -30)",
        "STRAIGHT_TRAVERSE(26, 0, 2)",
        // X40. R-2.: a taper from radius 18 at the start to 20 at Z-30.
        "STRAIGHT_TRAVERSE(18, 0, 2)",
        "STRAIGHT_FEED(20, 0, -30)",
        "STRAIGHT_FEED(26, 0, -30)",
        "STRAIGHT_TRAVERSE(26, 0, 2)",
        "STRAIGHT_TRAVERSE(26, 0, 2)",
        // G94 X20. Z-2.: in along Z, feed down to X10, back along Z, out.
        "STRAIGHT_TRAVERSE(26, 0, -2)",
        "STRAIGHT_FEED(10, 0, -2)",
        "STRAIGHT_FEED(10, 0, 2)",
        "STRAIGHT_TRAVERSE(26, 0, 2)",
        "STRAIGHT_TRAVERSE(26, 0, -4)",
        "STRAIGHT_FEED(10, 0, -4)",
        "STRAIGHT_FEED(10, 0, 2)",
        "STRAIGHT_TRAVERSE(26, 0, 2)",
        "STRAIGHT_TRAVERSE(20, 0, 5)",
        // G92: one threaded pass with the spindle, F the lead; out and back at rapid.
        "STRAIGHT_TRAVERSE(19, 0, 5)",
        "START_SPEED_FEED_SYNC(1.500000,0)",
        "STRAIGHT_FEED(19, 0, -20)",
        "STRAIGHT_TRAVERSE(20, 0, -20)",
        "STRAIGHT_TRAVERSE(20, 0, 5)",
        "STRAIGHT_TRAVERSE(18.7000, 0, 5)",
        "START_SPEED_FEED_SYNC(1.500000,0)",
        "STRAIGHT_FEED(18.7000, 0, -20)",
        "STRAIGHT_TRAVERSE(20, 0, -20)",
        "STRAIGHT_TRAVERSE(20, 0, 5)",
    ];
    assert_eq!(moves, expected, "{text}");
}

/// Fanuc G71 (two-block form) roughs the contour between N10 and N20 in passes along Z, 2 mm
/// deep, each ending at the contour shifted by the allowances (U0.4 on the diameter, W0.1)
/// and retracted at 45° by R0.5; a last pass follows the shifted contour and the run skips
/// the contour blocks. G70 then runs them as written and returns to the start point. Passes
/// end on arcs where the circle meets them.
#[test]
fn fanuc_lathe_roughing_and_finishing_cycles_follow_the_contour() {
    let program = "T0101\nG97 S1000 M3\nG0 X52. Z2.\nG71 U2. R0.5\nG71 P10 Q20 U0.4 W0.1 F0.25\nN10 G0 X30.\nG1 Z-20.\nX40. Z-30.\nN20 X52.\nG70 P10 Q20\nG0 X100. Z100.\nM30\n";
    let moves = |program: &str| {
        let (text, diags) = every_call("fanuc_lathe", program);
        assert!(!diags.iter().any(|x| x.is_error()), "{diags:?}");
        text.lines()
            .filter(|l| l.contains("TRAVERSE(") || l.contains("FEED(") || l.starts_with("ARC"))
            .map(|l| l.replace(", 0.0000, 0.0000, 0.0000)", ")").replace(".0000", ""))
            .collect::<Vec<_>>()
    };
    let mut want = vec!["STRAIGHT_TRAVERSE(26, 0, 2)".to_owned()];
    // Passes at X24 and X22 end at the shoulder (Z-30 + W0.1); X20, X18, X16 on the taper.
    for (x, z) in [("24", "-29.9000"), ("22", "-29.9000"), ("20", "-29.5000"), ("18", "-25.5000"), ("16", "-21.5000")] {
        let (xr, zr) = (format!("{x}.5000"), format!("{:.4}", z.parse::<f64>().unwrap() + 0.5));
        want.push(format!("STRAIGHT_TRAVERSE({x}, 0, 2)"));
        want.push(format!("STRAIGHT_FEED({x}, 0, {z})"));
        want.push(format!("STRAIGHT_TRAVERSE({xr}, 0, {})", zr.replace(".0000", "")));
        want.push(format!("STRAIGHT_TRAVERSE({xr}, 0, 2)"));
    }
    for m in [
        // Along the contour shifted by 0.2 (U0.4 on the diameter) and 0.1.
        "STRAIGHT_TRAVERSE(15.2000, 0, 2.1000)",
        "STRAIGHT_FEED(15.2000, 0, -19.9000)",
        "STRAIGHT_FEED(20.2000, 0, -29.9000)",
        "STRAIGHT_FEED(26.2000, 0, -29.9000)",
        "STRAIGHT_TRAVERSE(26, 0, 2)",
        // G70: the contour as written, and back.
        "STRAIGHT_TRAVERSE(15, 0, 2)",
        "STRAIGHT_FEED(15, 0, -20)",
        "STRAIGHT_FEED(20, 0, -30)",
        "STRAIGHT_FEED(26, 0, -30)",
        "STRAIGHT_TRAVERSE(26, 0, 2)",
        "STRAIGHT_TRAVERSE(50, 0, 100)",
    ] {
        want.push(m.to_owned());
    }
    assert_eq!(moves(program), want);
    // The roughing moves come from the G71 block (line 5), the finishing ones from N10-N20.
    let mut out = Vec::new();
    interpret(program, &Registry::shipped().get("fanuc_lathe").unwrap(), &Profile::default(), &mut out);
    let lines: Vec<u32> = out.iter().filter(|c| matches!(c.op, CanonOp::StraightFeed(_))).map(|c| c.line).collect();
    assert_eq!(lines, [5, 5, 5, 5, 5, 5, 5, 5, 7, 8, 9], "{lines:?}");

    // An arc in the contour: the pass at X17 ends where the circle about X20 Z-10 (R10) is
    // 17 from the axis, at Z-10-sqrt(91).
    let arc = "T0101\nG97 S1000 M3\nG0 X52. Z2.\nG71 U3. R1.\nG71 P10 Q20 U0. W0. F0.25\nN10 G0 X20.\nG1 Z-10.\nG2 X40. Z-20. R10.\nN20 G1 X52.\nM30\n";
    let got = moves(arc);
    assert!(got.contains(&"STRAIGHT_FEED(17, 0, -19.5394)".to_owned()), "{got:?}");
    assert!(got.contains(&"ARC_FEED(-20, 20, -10, 20, -1, 0)".to_owned()), "{got:?}");

    // G72 faces: passes along X, 2 mm apart in Z, each ending at the contour shifted by U0.4
    // (0.2 on the radius) and W0.1; the pass at Z-2 ends on the taper, at X10.45.
    let facing =
        "T0101\nG97 S1000 M3\nG0 X82. Z2.\nG72 W2. R0.5\nG72 P10 Q20 U0.4 W0.1 F0.25\nN10 G0 Z-6.\nG1 X40.\nX20. Z-2.\nN20 Z2.\nM30\n";
    let got = moves(facing);
    let passes: Vec<&str> = got.iter().filter(|l| l.starts_with("STRAIGHT_FEED")).map(String::as_str).collect();
    assert_eq!(
        passes,
        [
            "STRAIGHT_FEED(10.2000, 0, 0)",
            "STRAIGHT_FEED(10.4500, 0, -2)",
            "STRAIGHT_FEED(15.4500, 0, -4)",
            "STRAIGHT_FEED(20.2000, 0, -5.9000)",
            "STRAIGHT_FEED(10.2000, 0, -1.9000)",
            "STRAIGHT_FEED(10.2000, 0, 2.1000)",
        ],
        "{got:?}"
    );
    assert!(got.contains(&"STRAIGHT_TRAVERSE(10.7000, 0, 0.5000)".to_owned()), "the 45° retract: {got:?}");

    // Without the first block, the depth of cut is missing; without P and Q, the contour.
    let (_, errors) = canon("fanuc_lathe", "G0 X52. Z2.\nG71 P10 Q20 U0.4 W0.1 F0.25\nN10 G0 X30.\nN20 G1 Z-20.\nM30\n");
    assert_eq!(errors, ["syntax::missing-parameter"]);
    let (_, errors) = canon("fanuc_lathe", "G0 X52. Z2.\nG70 P10\nM30\n");
    assert_eq!(errors, ["syntax::missing-parameter"]);
    let (_, errors) = canon("fanuc_lathe", "G0 X52. Z2.\nG71 U2. R0.5\nG71 P10 Q20 F0.25\nN10 G0 X30.\nG1 Z-20.\nM30\n");
    assert_eq!(errors, ["flow::missing-label"], "no N20 ends the contour");
}

#[test]
fn the_tool_radius_and_diameter_read_the_tool_table() {
    let mut profile = Profile::default();
    profile.tools.insert(1, ncplan::interp::ToolData { diameter: Some(6.0), ..Default::default() });
    let moves = |dialect: &str, program: &str, profile: &Profile| {
        let mut out = Vec::new();
        let diags = interpret(program, &Registry::shipped().get(dialect).unwrap(), profile, &mut out);
        assert!(!diags.iter().any(|d| d.is_error()), "{diags:?}");
        out.iter().filter(|c| matches!(c.op, CanonOp::StraightTraverse(_))).map(|c| call_text(&c.op)).collect::<Vec<_>>()
    };
    // Heidenhain's Q108 is the radius; LinuxCNC's #5410 the diameter (rs274 -g with a tool
    // table of T1 D6 gives X6), in inches in an inch program.
    let heidenhain = "BEGIN PGM T MM\nTOOL CALL 1 Z S1000\nQ1 = Q108 * 2\nL X+Q1 Y+0 R0 FMAX M3\nEND PGM T MM\n";
    assert_eq!(moves("heidenhain", heidenhain, &profile), ["STRAIGHT_TRAVERSE(6.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)"]);
    let linuxcnc = "G21 T1 M6\nG0 X#5410\nG20\nG0 X#5410\nM2\n";
    let got = moves("linuxcnc", linuxcnc, &profile);
    assert_eq!(got[0], "STRAIGHT_TRAVERSE(6.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)");
    assert!(got[1].starts_with("STRAIGHT_TRAVERSE(0.2362,"), "{got:?}");
    // A tool the table does not hold reads 0.
    assert_eq!(moves("linuxcnc", linuxcnc, &Profile::default())[0], "STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)");
}

fn call_text(op: &CanonOp) -> String {
    let mut s = String::new();
    write_call(&mut s, op);
    s.trim_end().to_owned()
}

#[test]
fn arithmetic_on_data_read_from_the_machine_is_a_warning_that_says_so() {
    // Q5 stays 0 here: on the machine FN 18 fills Q311 from a position the operator jogged to.
    let read = "BEGIN PGM P MM\nFN18 : SYSREAD Q311 = ID240 NR1 IDX1\nQ5 = Q311 - 0\nQ7 = 10 / Q5\nEND PGM P MM\n";
    let (_, diags) = every_call("heidenhain", read);
    let codes: Vec<_> = diags.iter().map(|d| (d.code.as_str(), d.is_error())).collect();
    assert_eq!(codes, [("interp::unsupported", false), ("interp::arithmetic", false)], "{diags:?}");
    assert!(diags[0].message.contains("reads data only the machine has at run time"), "{diags:?}");
    // A global Q parameter (Q0-Q199) read before the program sets it is unknown: the
    // division by it is unknown too, no finding.
    let (_, diags) = every_call("heidenhain", &read.replace("Q311", "Q11"));
    assert_eq!(diags.iter().map(|d| d.code.as_str()).collect::<Vec<_>>(), ["interp::unsupported"], "{diags:?}");
    // Without the read, the same division is the program's own fault.
    let (_, diags) = every_call("heidenhain", "BEGIN PGM P MM\nQ5 = 0\nQ7 = 10 / Q5\nEND PGM P MM\n");
    assert_eq!(diags.iter().map(|d| (d.code.as_str(), d.is_error())).collect::<Vec<_>>(), [("interp::arithmetic", true)]);
}

#[test]
fn tool_offsets_along_x_y_and_z_move_the_program_position_as_rs274_does() {
    let mut profile = Profile::default();
    profile.tools.insert(1, ncplan::interp::ToolData { length: 1.0, ..Default::default() });
    let calls = |program: &str, profile: &Profile| {
        let mut out = Vec::new();
        let diags = interpret(program, &Registry::shipped().get("linuxcnc").unwrap(), profile, &mut out);
        assert!(!diags.iter().any(|d| d.is_error()), "{diags:?}");
        out.iter()
            .filter(|c| matches!(c.op, CanonOp::StraightTraverse(_) | CanonOp::UseToolLengthOffset(_)))
            .map(|c| call_text(&c.op))
            .collect::<Vec<_>>()
    };
    // G43 leaves the tool where it is: its program Z drops by the length, so the incremental
    // move ends at Z-2 and #5422 reads it (rs274 -g, with the length in the tool table).
    let got = calls("G21 G0 Z0\nT1 M6\nG43 H1\nG91 G0 Z-1\nG90\nG0 X#5422\nM2\n", &profile);
    assert_eq!(
        got[got.len() - 2..],
        [
            "STRAIGHT_TRAVERSE(0.0000, 0.0000, -2.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_TRAVERSE(-2.0000, 0.0000, -2.0000, 0.0000, 0.0000, 0.0000)"
        ]
    );
    // G10 L10 in a system rotated 45°: offsets are worked out along the rotated axes, an
    // axis not given keeping the tool's, and applied along the machine's (rs274 -g).
    let rotated = "G20\nG10 L2 P1 R45\nG0 X0 Y0 Z0\nG10 L10 P1 X0 Y0 Z0\nT1 M6 G43\nG10 L10 P1 X1\nG43\n\
                   G0 X#5420 Y#5421\nG10 L10 P1 Y1\nG43\nM2\n";
    let got = calls(rotated, &Profile::default());
    assert_eq!(
        got[got.len() - 3..],
        [
            "USE_TOOL_LENGTH_OFFSET(-0.7071 -0.7071 0.0000, 0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000)",
            "STRAIGHT_TRAVERSE(1.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)",
            "USE_TOOL_LENGTH_OFFSET(-0.0000 -1.4142 0.0000, 0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000)",
        ]
    );
}

/// Live-tool drilling on C-axis lathes, as posts write it: Fanuc's face and side cycles
/// (G83-G85, G87-G89; Mitsubishi and Mazak lathes alike) and Haas's axial G81-G89 and radial
/// G241-G249 with M133 P (the live tool's rpm). They are read and raise no error. Fanuc's run
/// their holes (a following block with only C drills the next one): a face hole at its radius
/// and angle in the face's XY plane, a side hole on the plane turned to its radial direction
/// (`interp::live`); Haas's are kept as intent, a block with only C moving to the next hole.
#[test]
fn live_tool_drilling_cycles_on_lathes_are_read() {
    let fanuc = "O1000\nG18 G21 G99\nT0505\nM45\nG98\nG0 X50. Z5. C0.\nM63 S1500\n\
                 G83 Z-40. R-5. Q2000 P500 F50.\nC90.\nC180.\nG80\nG0 X60. Z-10.\nG87 X20. R-5. P500 F50.\nG80\nM65\nM30\n";
    // G-code system B/C feeds with G94/G95, and G98 is the return to the initial level there.
    let system_b = fanuc.replace("G99\n", "G95\n").replace("G98\n", "G94 G98\n");
    for (dialect, program) in [("fanuc_lathe", fanuc), ("fanuc_lathe_b", &system_b), ("mitsubishi_lathe", fanuc), ("mazak_lathe", fanuc)] {
        let d = Registry::shipped().get(dialect).unwrap();
        let mut out = Vec::new();
        let diags = interpret(program, &d, &Profile::default(), &mut out);
        let errors: Vec<_> = diags.iter().filter(|d| d.is_error()).map(|d| d.message.clone()).collect();
        assert!(errors.is_empty(), "{dialect}: {errors:?}");
        assert!(!diags.iter().any(|d| d.message.contains("kept as intent")), "{dialect}: {diags:?}");
        // (x, y, bottom, R) of each hole, and the tool axis of each tilted plane.
        let holes: Vec<[f64; 4]> = out
            .iter()
            .filter_map(|c| match &c.op {
                CanonOp::CycleBegin(i) => Some([i.x, i.y, i.bottom, i.r_plane].map(|v| (v * 1e6).round() / 1e6 + 0.0)),
                _ => None,
            })
            .collect();
        // X50 is Ø50: the face holes at radius 25 and C0, C90, C180, from Z0 (R-5 below the
        // initial Z5) to Z-40; the side hole at C180 and Z-10 from radius 25 (R-5 in from X60)
        // to radius 10, on the plane whose X runs along -Z.
        assert_eq!(
            holes,
            [[25.0, 0.0, -40.0, 0.0], [0.0, 25.0, -40.0, 0.0], [-25.0, 0.0, -40.0, 0.0], [10.0, 0.0, 10.0, 25.0]],
            "{dialect}"
        );
        let axes: Vec<[f64; 3]> = out
            .iter()
            .filter_map(|c| match &c.op {
                CanonOp::WorkPlane(Some(f)) => Some([0, 1, 2].map(|i| (f.rotation[i][2] * 1e6).round() / 1e6 + 0.0)),
                _ => None,
            })
            .collect();
        assert_eq!(axes, [[-1.0, 0.0, 0.0]], "{dialect}");
    }
    let haas = "%\nO01000 (FLANGE)\n(T5 D=6. - DRILL)\nG18 G21 G99\nG28 U0.\nT505\nM154\nG98\nM133 P1500\nG0 X60. Z5. C0.\n\
                G83 Z-12. R2. Q3. F120.\nC120.\nC240.\nG80\nG0 X60. Z-8.\nG241 X20. R54. C60. F100.\nG80\nM135\nM155\nG28 U0. W0.\nM30\n%\n";
    let (_, errors) = canon("haas_lathe", haas);
    assert!(errors.is_empty(), "{errors:?}");
    let d = Registry::shipped().get("haas_lathe").unwrap();
    let diags = interpret(haas, &d, &Profile::default(), &mut Vec::new());
    assert!(!diags.iter().any(|d| d.code.as_str() == "syntax::unused-word"), "{diags:?}");
    assert_eq!(Registry::shipped().sniff(haas, Some("O01000.NC"), "fanuc").dialect, "haas_lathe");
}

/// OSP-L's graphic display commands (`CLEAR`, `DRAW`) are a lathe's: a bar-puller
/// subprogram with nothing else lathe-specific is read as the Okuma lathe, where they are
/// statements, not as the machining centre, where they are not.
#[test]
fn okuma_lathe_graphics_commands_tell_the_lathe() {
    let program = "$OPULL.SSB%\nOPULL\nVC1=100\nCLEAR\nDRAW\nG0 X50 Z10\nG1 Z-20 F0.2\nRTS\n%\n";
    assert_eq!(Registry::shipped().sniff(program, Some("OPULL.SSB"), "fanuc").dialect, "okuma_lathe");
    let (_, errors) = canon("okuma_lathe", program);
    assert!(errors.is_empty(), "{errors:?}");
}

/// Siemens `ATAN2(y, x)` is the arc tangent of two arguments in degrees; `<<` joins text,
/// which is not evaluated (a variable first too: `LINE=NAME<<"["<<N<<"]"`). The variable is
/// not named `ANG`: that is the 840D's contour-angle address (`ANG=`), read as such.
#[test]
fn siemens_atan2_and_text_joins() {
    let (text, errors) = canon(
        "siemens",
        "DEF REAL WINK\nDEF STRING[40] LINE\nWINK=ATAN2(30,30)\nLINE=\"A\"<<WINK\nLINE=LINE<<\"[\"<<WINK<<\"]\"\nG0 X=WINK\nM30\n",
    );
    assert!(errors.is_empty(), "{errors:?}");
    assert!(text.contains("STRAIGHT_TRAVERSE(45.0000,"), "{text}");
    // Fanuc's two-argument form in brackets still reads.
    let (text, errors) = canon("fanuc", "#1=ATAN[1,-1]\nG0 X#1\nM30\n");
    assert!(errors.is_empty(), "{errors:?}");
    assert!(text.contains("STRAIGHT_TRAVERSE(135.0000,"), "{text}");
}

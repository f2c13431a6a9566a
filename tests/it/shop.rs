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
/// base, and said to be a guess (low): a Haas or a Mitsubishi control would read it too.
#[test]
fn a_program_any_of_a_family_would_read_is_not_sure_of_the_maker() {
    let r = Registry::shipped();
    let s = r.sniff("%\nO0001\nT1 M6\nG0 G90 G54 X1. Y2.\nG43 H1 Z1.\nG1 Z-1. F10.\nM30\n%\n", Some("p.nc"), "linuxcnc");
    assert_eq!(s.dialect, "fanuc");
    assert_eq!(s.confidence, Confidence::Low, "{s:?}");
}

/// Evidence against the winner makes the choice a guess: a lathe program's codes beside a
/// mill's Y words and G17.
#[test]
fn a_winner_with_evidence_against_it_is_said_low() {
    let r = Registry::shipped();
    let lathe = "%\nO0001\n(HAAS ST-20)\nG50 S3000\nG96 S200 M3\nT0101\nG0 X52. Z2.\nG99 G1 Z-20. F0.2\nU2. W1.\nM30\n%\n";
    let s = r.sniff(lathe, Some("p.nc"), "linuxcnc");
    assert_eq!(s.dialect, "haas_lathe");
    assert_ne!(s.confidence, Confidence::Low, "{s:?}");
    let mixed = lathe.replacen("G0 X52. Z2.", "G17 G0 X52. Y10. Z2.", 1);
    let s = r.sniff(&mixed, Some("p.nc"), "linuxcnc");
    assert_eq!((s.dialect.as_str(), s.confidence), ("haas_lathe", Confidence::Low), "{s:?}");
}

/// `.ngc` is LinuxCNC's extension, not Mach3's: a LinuxCNC program that only mentions Mach3
/// in a comment stays LinuxCNC's.
#[test]
fn a_mach3_mention_in_an_ngc_program_does_not_make_it_mach3() {
    let r = Registry::shipped();
    let text = "( Note: modified for compatibility with Mach3 )\nG21 G90 G64 P0.01\nG0 X1 Y1 Z5\nG1 Z-1 F100\nM2\n";
    assert_eq!(r.sniff(text, Some("chips.ngc"), "fanuc").dialect, "linuxcnc");
    assert_eq!(r.sniff(text, Some("chips.tap"), "fanuc").dialect, "mach3");
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

// ---- §2: programs and cycles that live in the control ----

/// The 840D's built-in procedures and language commands are read: they set how the control
/// moves, not where, so the moves around them are the program's.
#[test]
fn siemens_built_ins_are_read_without_findings() {
    let program = "\
%_N_PART_MPF
G17 G90 G54 G64
FGROUP(X,Y,Z)
COMPCAD
SOFT
FFWON
SBLOF
SBLON
CYCLE832(0.05,_ORI_ROUGH,1)
CYCLE800(1,\"TABLE\",0,57,0,0,0,0,0,0,0,0,0,1,100,1)
TRAORI
G642
T=\"MILL_10\" M6
S5000 M3 D1
G0 X10 Y20 Z5
G1 Z-1 F500
COMPOF
FFWOF
BRISK
TRAFOOF
SETAL(61000)
G505 G0 X0
G599 G0 Y0
M30
";
    let (_, diags) = run("siemens", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let m = moves("siemens", program);
    assert_eq!(m.len(), 4, "{m:?}");
    assert!(m[1].starts_with("STRAIGHT_FEED(10.0000, 20.0000, -1.0000"), "{m:?}");
}

/// `AX[X]=`, `POS[A]=` move the axis named in brackets; `VELOLIM[A]=`, `FA[A]=`, `ACC[X]=`
/// set that axis's data; `DC`/`ACP`/`ACN` give a rotary axis an absolute position. None of
/// them reads a variable; an axis named by a variable is the caller's, said in a note.
#[test]
fn siemens_axis_indexed_words_and_rotary_positions() {
    let program = "\
%_N_AXES_MPF
G17 G90 G71
T=\"F10\" M6
S2000 M3
G0 X0 Y0 Z5
G1 Z-1 F200
G1 AX[X]=20 AX[Y]=IC(5)
POS[A]=DC(90) FA[A]=1000
VELOLIM[A]=50 ACC[X]=80 JERKLIM[Y]=60
G0 C=DC(270) B=ACP(10)
G1 AX[_X]=5 Y7
M30
";
    let (_, diags) = run("siemens", program);
    assert!(diags.iter().all(|d| d.severity == Severity::Note), "{diags:?}");
    let notes: Vec<&str> = diags.iter().map(|d| d.message.as_str()).collect();
    // The rotary positions index the tool axis (no tool centre point control): how it is
    // read is said once.
    assert_eq!(notes.len(), 2, "{notes:?}");
    assert!(notes[0].starts_with("the tool axis the rotary axes index to (no tool centre point control) is taken"), "{notes:?}");
    assert!(notes[1].contains("`AX[_X]` names its axis by `_x`, which the caller"), "{notes:?}");
    let m = moves("siemens", program);
    assert!(m[2].starts_with("STRAIGHT_FEED(20.0000, 5.0000, -1.0000, 0.0000"), "{m:?}");
    assert!(m[3].starts_with("STRAIGHT_FEED(20.0000, 5.0000, -1.0000, 90.0000, 0.0000, 0.0000"), "{m:?}");
    assert!(m[4].starts_with("STRAIGHT_TRAVERSE(20.0000, 5.0000, -1.0000, 90.0000, 10.0000, 270.0000"), "{m:?}");
    // The known axis of the last block still moves.
    assert!(m[5].starts_with("STRAIGHT_FEED(20.0000, 7.0000, -1.0000"), "{m:?}");
}

/// A call to a program that is neither in the file nor in the program directory may be one
/// the control holds (a machine maker's cycle, a shop subprogram): a warning, in every
/// dialect but LinuxCNC, which keeps rs274's error. The run goes on after it.
#[test]
fn a_call_to_a_program_the_control_may_hold_is_a_warning() {
    for (dialect, program) in [
        ("siemens", "G0 X0\nTOL(0.1,1,1)\nRAPORT(\"START\")\nT_INI\nL9021\nG0 X5\nM30\n"),
        ("fanuc", "G0 X0.\nM98 P9021\nG65 P9810 X1. Y2.\nG0 X5.\nM30\n"),
        ("haas", "G0 X0.\nM98 P9021\nG0 X5.\nM30\n"),
        ("heidenhain", "0 BEGIN PGM A MM\n1 L X+0 FMAX\n2 CALL PGM TNC:\\CYCLES\\RAPORT.H\n3 L X+5 FMAX\n4 END PGM A MM\n"),
    ] {
        let (_, diags) = run(dialect, program);
        assert!(errors(&diags).is_empty(), "{dialect}: {:?}", errors(&diags));
        assert!(has(&diags, "flow::missing-program", Severity::Warning), "{dialect}: {diags:?}");
        let m = moves(dialect, program);
        assert!(m.last().is_some_and(|l| l.starts_with("STRAIGHT_TRAVERSE(5.0000")), "{dialect}: the run goes on: {m:?}");
    }
    // `T_INI` is one name, not a T word without a value.
    let (_, diags) = run("siemens", "T_INI\nM30\n");
    assert!(diags.iter().any(|d| d.message.contains("`T_INI`")), "{diags:?}");
    // LinuxCNC looks a named subroutine up on its SUBROUTINE_PATH (issue 43): a warning where
    // stand-alone rs274, without the machine's path, stops; a numbered one must be in the file.
    let (_, diags) = run("linuxcnc", "G0 X0\no<probe> call\nM2\n");
    assert!(errors(&diags).is_empty() && has(&diags, "flow::missing-program", Severity::Warning), "{diags:?}");
    let (_, diags) = run("linuxcnc", "G0 X0\no100 call\nM2\n");
    assert!(!errors(&diags).is_empty(), "a numbered subroutine not in the program: {diags:?}");
}

/// `check --strict` makes such calls errors.
#[test]
fn check_strict_makes_a_missing_program_an_error() {
    let dir = std::env::temp_dir().join(format!("ncplan-strict-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let file = dir.join("part.mpf");
    std::fs::write(&file, "G0 X0\nTOL(0.1,1,1)\nM30\n").unwrap();
    let out = std::process::Command::new(crate::bin()).args(["check", "-d", "siemens"]).arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(0), "{}", String::from_utf8_lossy(&out.stdout));
    let out = std::process::Command::new(crate::bin()).args(["check", "--strict", "-d", "siemens"]).arg(&file).output().unwrap();
    assert_eq!(out.status.code(), Some(1), "{}", String::from_utf8_lossy(&out.stdout));
    assert!(String::from_utf8_lossy(&out.stdout).contains("error[flow::missing-program]"));
    std::fs::remove_dir_all(&dir).ok();
}

// ---- §4: arcs ----

/// An inch program written to 4 decimals (a Fusion 360 post) makes arcs whose radii differ
/// by up to 0.0002 in: within what its own rounding allows on Fanuc-family controls.
#[test]
fn arc_tolerance_follows_the_programs_resolution() {
    // Centre (1, 0), start (0, 0), end on the circle rounded: radius to the end 1.0002.
    let program = "G20 G17 G90 G54\nS1000 M3\nG0 X0. Y0.\nG1 Z-0.1 F20.\nG2 X2.0002 Y0. I1. J0.\nM30\n";
    for dialect in ["fanuc", "haas", "siemens"] {
        let (_, diags) = run(dialect, program);
        assert!(!has(&diags, "interp::bad-arc", Severity::Error), "{dialect}: {diags:?}");
    }
    // 0.001 in off is more than a 4-decimal program's rounding.
    let off = program.replace("X2.0002", "X2.0013");
    let (_, diags) = run("fanuc", &off);
    assert!(has(&diags, "interp::bad-arc", Severity::Error), "{diags:?}");
    // LinuxCNC keeps rs274's rule.
    let (_, diags) = run("linuxcnc", "G20 G17 G90\nG0 X0 Y0\nG1 Z-0.1 F20\nG2 X2.01 Y0 I1 J0\nM2\n");
    assert!(has(&diags, "interp::bad-arc", Severity::Error), "{diags:?}");
}

/// A rejected arc leaves the tool at its programmed end point: the next arc, right in
/// itself, is not rejected too.
#[test]
fn one_bad_arc_is_one_finding() {
    let program = "G21 G17 G90\nS1000 M3\nG0 X0. Y0.\nG1 Z-1. F100.\nG2 X20.5 Y0. I10. J0.\nG2 X40.5 Y0. I10. J0.\nG1 X50.\nM30\n";
    let (_, diags) = run("fanuc", program);
    let bad: Vec<_> = diags.iter().filter(|d| d.code.as_str() == "interp::bad-arc").collect();
    assert_eq!(bad.len(), 1, "{diags:?}");
    let m = moves("fanuc", program);
    assert!(m.iter().any(|l| l.starts_with("ARC_FEED(40.5000, 0.0000, 30.5000, 0.0000, -1")), "{m:?}");
}

/// An NX listing header before the opening `%` is tape leader: Fanuc-family controls skip
/// it, with a note; a `%` that only ends the program leaves what comes before it alone.
#[test]
fn text_before_the_opening_percent_is_tape_leader() {
    let program = "==========\nInformation listing created by : lili\nDate : 8/31/2006\n==========\n%\nO0001\nG0 G90 X1. Y2.\nM30\n%\n";
    for dialect in ["fanuc", "mitsubishi", "haas"] {
        let (_, diags) = run(dialect, program);
        assert!(errors(&diags).is_empty(), "{dialect}: {:?}", errors(&diags));
        assert!(has(&diags, "syntax::leader", Severity::Note), "{diags:?}");
        assert_eq!(moves(dialect, program), ["STRAIGHT_TRAVERSE(1.0000, 2.0000, 0.0000, 0.0000, 0.0000, 0.0000)"]);
    }
    let (_, diags) = run("fanuc", "O0001\nG0 G90 X1. Y2.\nM30\n%\n");
    assert!(!has(&diags, "syntax::leader", Severity::Note), "{diags:?}");
    assert_eq!(moves("fanuc", "O0001\nG0 G90 X1. Y2.\nM30\n%\n").len(), 1);
    // A DNC sender's control character and header on the opening `%`'s own line (a Fanuc 18T
    // shop's files: DC2, `&HE:%`, then `:0115 ;`) are leader too; the program after it reads
    // without an error (written before the run).
    let dnc = "\u{12}&HE:%\n:0115 ;\nN5 G21 G40 G99 ;\nN10 G00 X25. Z2. ;\nM30 ;\n%\n";
    let (_, diags) = run("fanuc_lathe", dnc);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(has(&diags, "syntax::leader", Severity::Note), "{diags:?}");
    // A first line that is program text holds no leader, whatever it ends with.
    let (_, diags) = run("fanuc", "O0001 (PART A)\nG0 G90 X1. Y2.\nM30\n%\n");
    assert!(!has(&diags, "syntax::leader", Severity::Note), "{diags:?}");
}

/// Heidenhain: PLANE (applied, RESET read), M140 MB MAX, cycle 32 TOLERANCE, M128
/// with F and FQ, TCH PROBE (intent), FN 17: SYSWRITE, cycle names in the control's language;
/// a CC with one coordinate keeps the other from the last CC.
#[test]
fn heidenhain_plane_tolerance_probe_and_one_coordinate_pole() {
    let program = "\
0 BEGIN PGM H2 MM
1 TOOL CALL 1 Z S3000
2 PLANE RESET STAY
3 M140 MB MAX
4 CYCL DEF 32.0 TOLERANCE
5 CYCL DEF 32.1 T0.015
6 CYCL DEF 32.2 HSC-MODE:0
7 CYCL DEF 19.0 PLAN D'USINAGE
8 M128 F1000
9 M128 FQ2
10 TCH PROBE 400 BASIC ROTATION
11 FN 17: SYSWRITE ID 990 NR6 IDX0 =+1
12 PLANE SPATIAL SPA+0 SPB+30 SPC+0 TURN MB MAX FMAX SEQ- TABLE ROT
13 PLANE RESET STAY
14 M129
15 L X+0 Y+0 Z+5 R0 FMAX M3
16 CC X+50 Y+50
17 L X+60 Y+50 Z-1 F500
18 C X+40 Y+50 DR+
19 CC X+30
20 C X+20 Y+50 DR+
21 END PGM H2 MM
";
    let (_, diags) = run("heidenhain", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    // The plane is applied (and reset before the moves), not kept as intent.
    assert!(!diags.iter().any(|d| d.message.contains("PLANE")), "{diags:?}");
    let m = moves("heidenhain", program);
    assert_eq!(m.last().unwrap(), "ARC_FEED(20.0000, 50.0000, 30.0000, 50.0000, 1, -1.0000, 0.0000, 0.0000, 0.0000)", "{m:?}");
}

/// Okuma: text in a system variable (`VUACM[1]='END OF BAR'`) and the lathe's G136/G137;
/// Haas: the 5-axis codes G254/G255, G234, G268/G269 are read (the ones that change the
/// coordinates kept as intent, with a warning).
#[test]
fn okuma_strings_and_haas_five_axis_codes() {
    let okuma = "$A.MIN%\nVUACM[1]='END OF BAR'\nG136\nG0 X10. Z5.\nG137\nM30\n";
    let (_, diags) = run("okuma_lathe", okuma);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert_eq!(moves("okuma_lathe", okuma).len(), 1);
    let haas = "O1000\nG0 G90 G54 X0. Y0.\nG254\nG234 H1\nG0 X1.\nG255\nG268 X0. Y0. Z0. I0. J45. K0.\nG269\nM30\n";
    let (_, diags) = run("haas", haas);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(has(&diags, "interp::unsupported", Severity::Warning), "{diags:?}");
}

/// Fanuc: K in a drilling cycle counts its repeats, also under least-increment input (`K3`
/// is three holes, not 0.003); a cycle without R feeds from the initial level, with a
/// warning, where LinuxCNC keeps rs274's error.
#[test]
fn fanuc_cycle_repeat_count_and_missing_r() {
    let k = "O1\nG21 G17 G90 G54\nS1000 M3\nG0 X0. Y0. Z10.\nG91 G81 X10. Z-5. R-8. K3 F100.\nG80 G90\nM30\n";
    let (_, diags) = run("fanuc", k);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(!diags.iter().any(|d| d.code.as_str() == "interp::no-decimal-point"), "{diags:?}");
    assert_eq!(moves("fanuc", k).iter().filter(|m| m.starts_with("STRAIGHT_FEED")).count(), 3);
    let r = "O1\nG21 G17 G90 G54\nS1000 M3\nG0 X0. Y0. Z2.\nG81 X10. Z-5. F100.\nG80\nM30\n";
    let (_, diags) = run("fanuc", r);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(has(&diags, "interp::cycle-incomplete", Severity::Warning), "{diags:?}");
    assert!(moves("fanuc", r).contains(&"STRAIGHT_FEED(10.0000, 0.0000, -5.0000, 0.0000, 0.0000, 0.0000)".to_owned()));
    let (_, diags) = run("linuxcnc", "G21 G17 G90\nG0 X0 Y0 Z2\nG81 X10 Z-5 F100\nG80\nM2\n");
    assert!(has(&diags, "interp::cycle-incomplete", Severity::Error), "{diags:?}");
}

/// Siemens arrays: declared (`DEF REAL _RICH[4]`, elements at 0), written (`_RICH[0]=5`,
/// `VAR5[R2]=3`, several in one block) and read (`FOR ... TO _RICH[1]-1`); a system
/// variable's index may hold anything (`$TC_SCP13[$P_TOOLNO,1]`, also inside IF).
#[test]
fn siemens_arrays_and_system_variable_indexes() {
    let program = "\
DEF REAL _RICH[4]
DEF INT VAR5[3]
DEF INT IDX
R2=1
_RICH[0]=5 _RICH[1]=3
VAR5[R2]=_RICH[0]+1
G0 X0 Y0 Z5
FOR IDX=0 TO _RICH[1]-1
G1 X=VAR5[1]*IDX F100
ENDFOR
IF $TC_SCP13[$P_TOOLNO,1]>0
G0 Z50
ENDIF
M30
";
    let (_, diags) = run("siemens", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let m = moves("siemens", program);
    let xs: Vec<&str> = m.iter().filter(|l| l.starts_with("STRAIGHT_FEED")).map(|l| &l[14..20]).collect();
    assert_eq!(xs, ["0.0000", "6.0000", "12.000"], "{m:?}");
}

/// Nested parentheses in comments are a dictionary option: Fanuc closes a comment at the
/// first `)`, a dialect that says `nested="true"` reads the whole comment. A teaching
/// simulator's `$` command (`($SetPartSize(4, 4, 1, 1) )`) is read to its matching `)`, as
/// the simulator reads it, with a warning (issue 34).
#[test]
fn nested_comments_are_a_dictionary_option() {
    let program = "O1\n(PLATE (REV B) DONE)\nG0 G90 X1. Y2.\nM30\n";
    let (_, diags) = run("fanuc", program);
    assert!(!errors(&diags).is_empty(), "Fanuc closes the comment at the first `)`");
    let simulator = "O1\n($SetPartSize(4, 4, 1, 1) )\n($Message(\"Load (Fanuc) settings\"))\nG0 G90 X1. Y2.\nM30\n";
    let (_, diags) = run("fanuc", simulator);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert_eq!(
        diags.iter().filter(|d| d.code.as_str() == "syntax::simulator-directive" && d.severity == Severity::Warning).count(),
        2,
        "{diags:?}"
    );
    let mut r = Registry::shipped();
    let nested = r#"<dialect xmlns="urn:ncplan:dialect:1" name="sim" extends="fanuc" title="A simulator">
  <lexical><comment open="(" close=")" nested="true"/></lexical>
</dialect>"#;
    r.add("sim.xml", nested).unwrap();
    let d = r.get("sim").unwrap();
    let diags = interpret(program, &d, &Profile::default(), &mut Vec::new());
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
}

/// Haas NGC's #10000+ and Mitsubishi's #900000+ variables are variables of those controls:
/// written and read back, and, unwritten, set outside the file (unknown, a warning). A
/// control without them still rejects the number.
#[test]
fn haas_and_mitsubishi_high_variables() {
    let haas = "%\nO0001\n#10001=5.\nG0 G90 G54 X#10001 Y0.\n#10002=[#10001*2]\nG1 Y#10002 F10.\nG1 X#10500\nM30\n%\n";
    let (_, diags) = run("haas", haas);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert_eq!(
        moves("haas", haas),
        [
            "STRAIGHT_TRAVERSE(5.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(5.0000, 10.0000, 0.0000, 0.0000, 0.0000, 0.0000)"
        ]
    );
    assert!(has(&diags, "interp::unknown-value", Severity::Warning), "{diags:?}");
    let mitsubishi = "%\nO0001\n#900001=2.5\nG0 G90 G54 X#900001 Y#907400\nM30\n%\n";
    let (_, diags) = run("mitsubishi", mitsubishi);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert_eq!(moves("mitsubishi", mitsubishi), ["STRAIGHT_TRAVERSE(2.5000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)"]);
    let (_, diags) = run("fanuc", mitsubishi);
    assert!(errors(&diags).iter().any(|e| e.contains("900001 is out of range")), "{diags:?}");
    let (_, diags) = run("haas", "%\nO0001\n#60000=1.\nM30\n%\n");
    assert!(errors(&diags).iter().any(|e| e.contains("60000 is out of range")), "{diags:?}");
}

/// A cell program that jumps back to its first label runs until the operator stops it: a
/// warning, as a return in a Fanuc main program is. An endless jump to a later label stays
/// an error.
#[test]
fn a_cell_program_looping_to_its_first_label_is_a_warning() {
    let cell = "N10 G90 G54\nSTART:\nG0 X0 Y0 Z10\nM0\nG0 X50\nGOTOB START\nM30\n";
    let (_, diags) = run("siemens", cell);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(has(&diags, "flow::loop-limit", Severity::Warning), "{diags:?}");
    let stuck = "N10 G90 G54\nSTART:\nG0 X0 Y0 Z10\nAGAIN:\nG0 X50\nGOTOB AGAIN\nM30\n";
    let (_, diags) = run("siemens", stuck);
    assert!(errors(&diags).iter().any(|e| e.starts_with("flow::loop-limit")), "{diags:?}");
}

/// One cause, one error: a Fanuc program that writes `X4` beside `X3.9` under
/// least-increment input gets one finding about the decimal point; the arcs that fail
/// because the tool stands at X0.004 are notes that point at it. Once every axis is
/// written with a point again, a bad arc is an error of its own.
#[test]
fn a_missing_decimal_point_is_one_finding_not_a_cascade_of_arcs() {
    let program = "%\nO0001\nG21 G90 G54 G17\nT1 M6\nS1000 M3\nG0 X0 Y0\nG43 H1 Z5.\nG1 Z-1. F100.\nG1 X4 Y0\nG2 X3.9 Y0.1 R0.1\nG1 Y4\nG3 X3.8 Y4.1 I-0.1 J0\nG1 X0.5\nG2 X0.4 Y4. R0.1\nG1 X1. Y1.\nG2 X1.5 Y1. I0.1 J0.\nG0 Z5.\nM30\n%\n";
    let (_, diags) = run("fanuc", program);
    let decimal: Vec<_> = diags.iter().filter(|d| d.code.as_str() == "interp::no-decimal-point" && d.severity != Severity::Note).collect();
    assert_eq!(decimal.len(), 1, "{diags:?}");
    assert!(decimal[0].message.contains("`X4`"), "{decimal:?}");
    let consequences = diags.iter().filter(|d| d.code.as_str() == "interp::bad-arc" && d.severity == Severity::Note).count();
    assert_eq!(consequences, 2, "{diags:?}");
    // The last arc (to X1.5 from X1. about X1.1) is wrong by itself.
    let errors = errors(&diags);
    assert_eq!(errors.len(), 1, "{errors:?}");
    assert!(errors[0].starts_with("interp::bad-arc") && !errors[0].contains("follows from"), "{errors:?}");
}

/// `G41 D01` or `RL` after `TOOL CALL 5`, with no tool table: the radius is the control's
/// offset, machine data: a note that names the register, not a warning on every CAM post
/// that compensates in the control. Without any register (no D, no tool) it stays a warning.
#[test]
fn cutter_compensation_by_an_unknown_register_is_a_note() {
    for (dialect, program, register) in [
        ("fanuc", "T1 M6\nS1000 M3\nG0 X-10 Y-10\nG1 Z-2 F200\nG41 D01 X0 Y0\nX50\nG40 X60\nM30\n", "D1"),
        (
            "heidenhain",
            "0 BEGIN PGM C MM\n1 TOOL CALL 5 Z S3000\n2 L X-10 Y-10 R0 FMAX M3\n3 L Z-2 F200\n4 L X+0 Y+0 RL\n5 L X+50\n6 L X+60 R0\n7 END PGM C MM\n",
            "tool 5",
        ),
    ] {
        let (_, diags) = run(dialect, program);
        assert!(!has(&diags, "interp::comp-without-offset", Severity::Warning), "{dialect}: {diags:?}");
        let note = diags.iter().find(|d| d.code.as_str() == "interp::unknown-value").unwrap_or_else(|| panic!("{dialect}: {diags:?}"));
        assert_eq!(note.severity, Severity::Note);
        assert!(note.message.contains(&format!("the radius of {register} is in the control's tool offsets")), "{}", note.message);
    }
    let (_, diags) = run("fanuc", "G0 X-10 Y-10\nG1 Z-2 F200\nG41 X0 Y0\nX50\nG40 X60\nM30\n");
    assert!(has(&diags, "interp::comp-without-offset", Severity::Warning), "{diags:?}");
}

/// `CYCL CALL POS X Y Z`: the defined cycle at that position, the tool-axis word being the
/// surface instead of Q203; below the set-up clearance over it, the tool first rises.
#[test]
fn heidenhain_cycle_call_at_a_position_drills_from_its_own_surface() {
    let program = "0 BEGIN PGM P MM\n1 TOOL CALL 12 Z S2500 F250\n2 L Z+50 R0 FMAX M3\n\
        3 CYCL DEF 200 DRILLING ~\n  Q200=+2 ;SET-UP CLEARANCE ~\n  Q201=-20 ;DEPTH ~\n  Q206=+250 ;FEED ~\n\
          Q202=+20 ;PLUNGING DEPTH ~\n  Q210=+0 ;DWELL ~\n  Q203=+0 ;SURFACE COORDINATE ~\n  Q204=+50 ;2ND SET-UP CLEARANCE ~\n\
          Q211=+0 ;DWELL AT DEPTH\n\
        4 CYCL CALL POS X+10 Y+10 Z-5 FMAX\n5 L Z-10 R0 FMAX\n6 CYCL CALL POS X+30 Y+10 Z+0 FMAX\n7 END PGM P MM\n";
    let (_, diags) = run("heidenhain", program);
    assert!(diags.is_empty(), "{diags:?}");
    let m = moves("heidenhain", program);
    let want = [
        "STRAIGHT_TRAVERSE(10.0000, 10.0000, 50.0000",
        "STRAIGHT_TRAVERSE(10.0000, 10.0000, -3.0000",
        "STRAIGHT_FEED(10.0000, 10.0000, -25.0000",
        "STRAIGHT_TRAVERSE(10.0000, 10.0000, 45.0000",
        // Below the next set-up clearance: up first, then across.
        "STRAIGHT_TRAVERSE(10.0000, 10.0000, -10.0000",
        "STRAIGHT_TRAVERSE(10.0000, 10.0000, 2.0000",
        "STRAIGHT_TRAVERSE(30.0000, 10.0000, 2.0000",
        "STRAIGHT_FEED(30.0000, 10.0000, -20.0000",
    ];
    for (i, w) in want.iter().enumerate() {
        assert!(m.get(i + 1).is_some_and(|l| l.starts_with(w)), "move {}: want {w}\n{m:#?}", i + 1);
    }
}

/// What Fanuc-family CAM posts write around operations: AI contour control, high-precision
/// contour control, look-ahead, tool centre point control, the tilted working plane. None is
/// an unknown code; the tilted plane is applied without a warning, TCP applies the length
/// offset. Fagor's G05/G08 are not these.
#[test]
fn fanuc_high_speed_and_five_axis_codes_of_cam_posts() {
    let program = "%\nO1 (P)\nG21 G17 G90\nG05.1 Q1 R5\nG5 P10000\nG08 P1\nT1 M6\nS8000 M3\nG0 X0 Y0\nG43.4 H1 Z25.\n\
        G68.2 X0 Y0 Z0 I0 J30. K0\nG53.1\nG1 Z-1. F500\nX10.\nG69\nG49\nG05.1 Q0\nG5 P0\nG8 P0\nM30\n%\n";
    for dialect in ["fanuc", "haas", "mitsubishi", "mazak"] {
        let (_, diags) = run(dialect, program);
        assert!(errors(&diags).is_empty(), "{dialect}: {:?}", errors(&diags));
        // G68.2 is applied (the moves stay in the tilted plane's coordinates), not a warning.
        let warnings: Vec<&str> = diags.iter().filter(|d| d.severity == Severity::Warning).map(|d| d.message.as_str()).collect();
        assert!(warnings.is_empty(), "{dialect}: {warnings:?}");
        let m = moves(dialect, program);
        // The tool, at Z25 over the origin when the plane tilts 30° about X, stands at Y12.5
        // (25·sin 30°) in the plane's coordinates; `G1 Z-1.` keeps that Y.
        assert!(m.iter().any(|l| l.starts_with("STRAIGHT_FEED(10.0000, 12.5000, -1.0000")), "{dialect}: {m:?}");
    }
    // Fagor's G08 is an arc tangent to the path before: documented, not modelled, so kept as
    // intent with a warning (issue 43), never read as a smoothing code.
    let (_, diags) = run("fagor", "G90 G17\nG08 X10 Y10\nM30\n");
    assert!(errors(&diags).is_empty(), "{diags:?}");
    assert!(diags.iter().any(|d| d.message.contains("`G08` (arc tangent")), "{diags:?}");
}

/// Issue 43, sweep 4: Fanuc takes the last of two G codes of one group in a block
/// (`G91 G28 X0 Y0 Z100. G90`, hand-written safety blocks of a shop's Fusion programs), with
/// a note, and the move runs in the mode that wins; LinuxCNC keeps rs274's error, and the
/// makers whose manuals at hand do not say so keep theirs.
#[test]
fn fanuc_takes_the_last_g_code_of_a_group_in_a_block() {
    let program = "%\nO6600\nG21 G17 G90 G54\nG0 X10. Y10. Z50.\nG91 G28 X0 Y0 Z100. G90\nG0 X5.\nM30\n%\n";
    let (_, diags) = run("fanuc", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(has(&diags, "syntax::modal-group-last-wins", Severity::Note), "{diags:?}");
    // G90 wins: the intermediate point is X0 Y0 Z100 absolute, and X5. after it absolute too.
    let m = moves("fanuc", program);
    assert!(m.iter().any(|l| l.starts_with("STRAIGHT_TRAVERSE(0.0000, 0.0000, 100.0000")), "{m:?}");
    assert!(m.last().is_some_and(|l| l.starts_with("STRAIGHT_TRAVERSE(5.0000")), "{m:?}");
    for dialect in ["linuxcnc", "haas", "okuma", "fagor", "mitsubishi", "mazak"] {
        let (_, diags) = run(dialect, "G21 G90\nG91 G0 X1. G90\nM30\n");
        assert!(has(&diags, "syntax::modal-group-conflict", Severity::Error), "{dialect}: {diags:?}");
    }
}

/// Issue 43, sweep 4: Okuma's tool data by tool and data number (`VTOHT[[VTLCN],10001]`, two
/// subscripts) is read and written as one element, without an error; a `.LIB` file (a library
/// program registered on the OSP) is Okuma evidence.
#[test]
fn okuma_two_subscript_system_variables_and_lib_files() {
    let lib = "OINS2\nVC100 = 5\nVC99 = 12.5\nVTOHT[[VC100] , 10001] = [VC99]\nVC81 = VTOHT[[VC100],10001]\nIF [VC81 EQ 12.5] NOK\nVDOUT[992]=1\nNOK\nG4 F1.\nRTS\n";
    let (_, diags) = run("okuma", lib);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    // The element written is the one read: the check passes and no alarm is raised.
    assert!(!diags.iter().any(|d| d.code.as_str() == "interp::alarm"), "{diags:?}");
    let r = Registry::shipped();
    let s = r.sniff("OTCH\nG30 P1\nM1\nRTS\n", Some("OTCH.LIB"), "linuxcnc");
    assert_eq!(s.dialect, "okuma", "{s:?}");
}

/// Fanuc's modal T (#4120) is the control's, kept from before the program: a check on it
/// before the program commands a tool reads the machine's tool, unknown here, and takes the
/// way a run without alarm takes, with a note; after `T5 M6` it reads 5. LinuxCNC keeps
/// rs274's power-on tool 0.
#[test]
fn the_modal_tool_before_the_program_commands_one_is_the_machine_s() {
    let check = "O1000\nIF[#4120LT2]GOTO8000\nG0 X1.\nM30\nN8000 #3000=100(TOOL?)\nM30\n";
    let (_, diags) = run("fanuc", check);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(has(&diags, "flow::unknown-condition", Severity::Note), "{diags:?}");
    // Commanded, the tool is known: the check passes with no condition left to choose.
    let known = check.replace("O1000\n", "O1000\nT5 M6\n");
    let (_, diags) = run("fanuc", &known);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(!has(&diags, "flow::unknown-condition", Severity::Note), "{diags:?}");
    let (_, diags) = run("fanuc", &known.replace("T5 M6", "T1 M6"));
    assert!(has(&diags, "interp::alarm", Severity::Error), "{diags:?}");
    // LinuxCNC's #5400 (its tool in the spindle) reads 0 before a change, as in rs274.
    let (_, diags) = run("linuxcnc", "o1 if [#5400 EQ 0]\n(msg,none)\no1 else\n(abort,tool)\no1 endif\nM2\n");
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
}

/// Weak evidence among Fanuc-like makers (one code of one maker, or little more than another
/// maker's) leaves the choice to the first reading without an error: a Mitsubishi shop's
/// extended common variable (#900001-#907400) beside Haas's chip-conveyor M31 and an NGC
/// variable is read as Mitsubishi, where a Haas reading stops on the variable it has not;
/// the evidence's own choice stays when every reading is as clean, and the report says why.
#[test]
fn weak_evidence_is_settled_by_the_reading_with_the_fewest_errors() {
    let r = Registry::shipped();
    let path = std::path::Path::new("/nonexistent-ncplan-test/O9191.nc");
    let text = "%\nO9191\nM31\n#10001=1\n#26=#901064\nG0 X1. Y1.\nM30\n%\n";
    assert_eq!(r.sniff(text, Some("O9191.nc"), "linuxcnc").dialect, "haas", "the evidence alone");
    let s = ncplan::pipeline::sniff(&r, text.as_bytes(), path);
    assert_eq!(s.dialect, "mitsubishi", "{s:?}");
    assert!(s.evidence.iter().any(|e| e.starts_with("weak evidence: the first reading without an error")), "{s:?}");
    let d = r.get(&s.dialect).unwrap();
    let mut out = Vec::new();
    assert!(errors(&interpret(text, &d, &Profile::default(), &mut out)).is_empty());
    // Every candidate reads it cleanly: the evidence's choice stays.
    let clean = "%\nO9191\nM31\n#10001=1\nG0 X1. Y1.\nM30\n%\n";
    assert_eq!(ncplan::pipeline::sniff(&r, clean.as_bytes(), path).dialect, "haas");
    // Sure evidence is not second-guessed by another maker: Haas's own G187 and M97 decide
    // (its lathe dialect stays a candidate, as the mill's codes are the lathe's too).
    let sure = "%\nO9191\nG187 P1\nM97 P100\nG0 X1. Y1.\nM30\nN100 M99\n%\n";
    let s = r.sniff(sure, Some("O9191.nc"), "linuxcnc");
    assert!(s.candidates.iter().all(|c| r.get(c).unwrap().family == "haas"), "{s:?}");
}

/// A text after `;` on a block's line is a comment to LinuxCNC and the end of the block to a
/// Fanuc-like control, which would run the text as a block: a `%`/`O0000` program written
/// so is LinuxCNC's, and reads there without an error.
#[test]
fn a_semicolon_comment_after_a_block_tells_against_fanuc() {
    let r = Registry::shipped();
    let text =
        "%\nO0000(MY GCODE)\nN1 G21; mm mode\nN2 G0 G17 G40 G49 G80 G90; rapid\nN3 G0 X0.0 Y0.0 Z10.0 F600\nN4 M30; End of program\n%\n";
    let s = r.sniff(text, Some("p.gcode"), "linuxcnc");
    assert_eq!(s.dialect, "linuxcnc", "{s:?}");
    assert!(errors(&run("linuxcnc", text).1).is_empty());
    assert!(!errors(&run("fanuc", text).1).is_empty(), "Fanuc runs `mm mode` as a block");
    // A bare `;` closing a block, as some Fanuc posts write it, tells nothing.
    let fanuc = "%\nO1234\nG0 G90 X1. Y1.;\nM30;\n%\n";
    assert_eq!(r.sniff(fanuc, Some("p.nc"), "linuxcnc").dialect, "fanuc");
}

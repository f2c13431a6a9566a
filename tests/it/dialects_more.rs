//! Dialects and readings real shop programs needed (issue 17): Heidenhain TNC programs in
//! DIN/ISO format, numbered block-skip switches, a lathe's roughing cycle under tool-nose
//! compensation. Small programs of our own in each control's style.

use ncplan::canon::write_call;
use ncplan::diag::{Diagnostic, Severity};
use ncplan::dialect::Registry;
use ncplan::interp::{Profile, interpret};

fn program(name: &str) -> String {
    std::fs::read_to_string(crate::root().join("tests/programs/dialects_more").join(name)).unwrap()
}

/// The canonical calls of `text` in `dialect` (one per line), and the findings.
fn run_with(dialect: &str, text: &str, profile: &Profile) -> (Vec<String>, Vec<Diagnostic>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut out = Vec::new();
    let diags = interpret(text, &d, profile, &mut out);
    let calls = out
        .iter()
        .map(|c| {
            let mut t = String::new();
            write_call(&mut t, &c.op);
            t.trim().to_owned()
        })
        .collect();
    (calls, diags)
}

fn run(dialect: &str, text: &str) -> (Vec<String>, Vec<Diagnostic>) {
    run_with(dialect, text, &Profile::default())
}

fn moves(calls: &[String]) -> Vec<&str> {
    calls.iter().map(String::as_str).filter(|c| c.starts_with("STRAIGHT_") || c.starts_with("ARC_FEED")).collect()
}

fn errors(diags: &[Diagnostic]) -> Vec<String> {
    diags.iter().filter(|d| d.is_error()).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect()
}

// ---- Heidenhain DIN/ISO ----

/// A TNC program in ISO: the `%NAME G71` header, N blocks ending in `*`, G30/G31 blank,
/// G99 tool definition, `T1 G17 S` tool call, absolute I J centres kept as the pole (a
/// G02 without them turns about it, a block of I J alone moves it), G11/G13 polar moves
/// with R and H, G91, a G200 cycle defined by the Q lines after it and called by M99 and G79.
#[test]
fn a_tnc_iso_program_reads_its_arcs_polar_moves_and_cycles() {
    let (calls, diags) = run("heidenhain_iso", &program("tnc_iso_pocket.i"));
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(!diags.iter().any(|d| d.code.as_str() == "syntax::unused-word"), "{diags:?}");
    assert!(calls.iter().any(|c| c == "USE_LENGTH_UNITS(CANON_UNITS_MM)"), "{calls:?}");
    assert!(calls.iter().any(|c| c == "CHANGE_TOOL(1)"), "{calls:?}");
    assert!(calls.iter().any(|c| c == "SET_SPINDLE_SPEED(0, 3000.0000)"), "{calls:?}");
    let m = moves(&calls);
    let want = [
        // G02 X+70 Y+50 I+50 J+50: clockwise about (50, 50); then G02 X+30 Y+50 about the same pole
        "ARC_FEED(70.0000, 50.0000, 50.0000, 50.0000, -1, -5.0000, 0.0000, 0.0000, 0.0000)",
        "ARC_FEED(30.0000, 50.0000, 50.0000, 50.0000, -1, -5.0000, 0.0000, 0.0000, 0.0000)",
        // I+40 J+50 alone moves the pole; G11 R+20 H+0 is 20 mm from it at 0°
        "STRAIGHT_FEED(60.0000, 50.0000, 50.0000, 0.0000, 0.0000, 0.0000)",
        // G13 H+90: counter-clockwise about the pole to 90°
        "ARC_FEED(40.0000, 70.0000, 40.0000, 50.0000, 1, 50.0000, 0.0000, 0.0000, 0.0000)",
        // G91 G01 X-10
        "STRAIGHT_FEED(30.0000, 70.0000, 50.0000, 0.0000, 0.0000, 0.0000)",
    ];
    let mut at = 0;
    for w in want {
        let k = m[at..].iter().position(|c| *c == w).unwrap_or_else(|| panic!("{w} not after move {at}: {m:#?}"));
        at += k + 1;
    }
    // Cycle 200 at X10 Y10 (M99), X90 Y10 (G79): from the set-up clearance to Q201 below Q203.
    for (x, y) in [("10", "10"), ("90", "10")] {
        let hole = format!("STRAIGHT_FEED({x}.0000, {y}.0000, -15.0000, 0.0000, 0.0000, 0.0000)");
        let clear = format!("STRAIGHT_TRAVERSE({x}.0000, {y}.0000, 2.0000, 0.0000, 0.0000, 0.0000)");
        assert!(m.contains(&hole.as_str()) && m.contains(&clear.as_str()), "{hole}: {m:#?}");
    }
    assert_eq!(calls.iter().filter(|c| c.starts_with("STRAIGHT_FEED") && c.contains("-15.0000")).count(), 2, "{m:#?}");
    assert!(calls.iter().any(|c| c == "PROGRAM_END()"), "{calls:?}");
}

/// `%1 G70 *` opens an inch program: the header's units are read.
#[test]
fn a_tnc_iso_header_gives_the_units() {
    let (calls, diags) = run("heidenhain_iso", "%1 G70 *\nN10 G00 G90 X+1 Y+1 Z+1 *\nN20 M30 *\nN99999999 %1 G70 *\n");
    assert!(diags.is_empty(), "{diags:?}");
    assert_eq!(calls[0], "USE_LENGTH_UNITS(CANON_UNITS_INCHES)", "{calls:?}");
    assert_eq!(moves(&calls), ["STRAIGHT_TRAVERSE(1.0000, 1.0000, 1.0000, 0.0000, 0.0000, 0.0000)"]);
}

/// Told from its text: an ISO program is heidenhain_iso, a Klartext one heidenhain, both of
/// the heidenhain family; a Fanuc program is neither.
#[test]
fn tnc_iso_is_told_from_klartext_and_from_fanuc() {
    let r = Registry::shipped();
    let iso = program("tnc_iso_pocket.i");
    let s = r.sniff(&iso, Some("POCKET.I"), "linuxcnc");
    assert_eq!(s.dialect, "heidenhain_iso", "{s:?}");
    let s = r.sniff(&iso, Some("pocket.nc"), "linuxcnc");
    assert_eq!(s.dialect, "heidenhain_iso", "{s:?}");
    assert_eq!(r.get("heidenhain_iso").unwrap().family, "heidenhain");
    let klartext = "0 BEGIN PGM P1 MM\n1 BLK FORM 0.1 Z X+0 Y+0 Z-20\n2 TOOL CALL 1 Z S3000\n3 L X+10 Y+10 R0 FMAX M3\n\
                    4 CYCL DEF 200 DRILLING ~\n  Q200=+2 ;SET-UP CLEARANCE ~\n  Q201=-10 ;DEPTH\n5 L X+20 FMAX M99\n6 END PGM P1 MM\n";
    assert_eq!(r.sniff(klartext, Some("P1.H"), "linuxcnc").dialect, "heidenhain");
    let fanuc = "%\nO1234\nG90 G54 G0 X10. Y5.\nG43 H1 Z5.\nG81 Z-5. R2. F100.\nM30\n%\n";
    assert_eq!(r.sniff(fanuc, Some("p.nc"), "linuxcnc").dialect, "fanuc");
}

// ---- numbered block skip ----

/// `/1`-`/9` name the optional block skip switches (Fanuc's additional block skip, in
/// Mazak's EIA and Haas programs too): each such block is a skipped block, read when the
/// switch is off and left out when it is on.
#[test]
fn numbered_block_skips_are_skipped_blocks() {
    let text = program("bskip_flags.eia");
    for dialect in ["mazak", "fanuc", "haas"] {
        let (calls, diags) = run(dialect, &text);
        assert!(errors(&diags).is_empty(), "{dialect}: {:?}", errors(&diags));
        assert!(moves(&calls).contains(&"STRAIGHT_TRAVERSE(0.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)"), "{dialect}: {calls:?}");
        let on = Profile { block_delete: true, ..Profile::default() };
        let (calls, diags) = run_with(dialect, &text, &on);
        assert!(errors(&diags).is_empty(), "{dialect}: {:?}", errors(&diags));
        assert!(moves(&calls).contains(&"STRAIGHT_TRAVERSE(1.0000, 1.0000, 1.0000, 0.0000, 0.0000, 0.0000)"), "{dialect}: {calls:?}");
    }
    // LinuxCNC has no switch numbers: `/1` is a block delete followed by a stray number.
    let (_, diags) = run("linuxcnc", "G0 X0\n/1 G0 X1\nM2\n");
    assert!(diags.iter().any(|d| d.is_error()), "{diags:?}");
}

// ---- a lathe's roughing cycle under tool-nose compensation ----

/// G42 in force before a Fanuc-style G71/G70: the cycle runs (passes along Z, then the
/// finishing pass), with the tool-nose radius in the control's offsets a note, not an error.
#[test]
fn a_lathe_roughing_cycle_runs_under_tool_nose_compensation() {
    let text = program("turn_g71_nose_comp.nc");
    let (calls, diags) = run("fanuc_lathe", &text);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(diags.iter().any(|d| d.code.as_str() == "interp::unknown-value" && d.severity == Severity::Note), "{diags:?}");
    let m = moves(&calls);
    // The first pass, 2 mm deep on the diameter from X52: X48 (radius 24) to the allowance.
    assert!(m.contains(&"STRAIGHT_FEED(24.0000, 0.0000, -49.9000, 0.0000, 0.0000, 0.0000)"), "{m:#?}");
    // The roughing's last pass follows the contour shifted by U0.4 W0.1.
    assert!(m.contains(&"STRAIGHT_FEED(20.2000, 0.0000, -29.9000, 0.0000, 0.0000, 0.0000)"), "{m:#?}");
    // G70 then finishes on the contour itself.
    assert!(m.contains(&"STRAIGHT_FEED(20.0000, 0.0000, -30.0000, 0.0000, 0.0000, 0.0000)"), "{m:#?}");
    // Haas's one-block G71 under G41/G42 reads the same way.
    let haas = text.replace("G71 U2. R0.5\nG71 P100 Q200 U0.4 W0.1 F0.25", "G71 P100 Q200 U0.4 W0.1 D2. F0.25");
    let (calls, diags) = run("haas_lathe", &haas);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(moves(&calls).contains(&"STRAIGHT_FEED(20.2000, 0.0000, -29.9000, 0.0000, 0.0000, 0.0000)"), "{calls:#?}");
}

// ---- issue 43: arcs in the plane their centre names; Okuma lathe arcs by L ----

/// An older TNC program's arc about a centre given in Y and Z while the tool is along Z
/// (`CC Y Z`, then `C Y Z DR+`): the circle lies in the plane of the centre's axes, so its
/// radii agree; the plane of the tool call is back after it.
#[test]
fn a_heidenhain_circle_centre_in_y_and_z_puts_the_arc_in_that_plane() {
    let text = "0 BEGIN PGM YZ MM\n1 TOOL CALL 1 Z S1000\n2 L X+0 Y+0 Z+0 R0 F100\n3 CC Y+0 Z+5\n4 C Y+5 Z+5 DR+\n5 CC X+5 Y+5\n6 C X+10 Y+5 DR-\n7 END PGM YZ MM\n";
    let (calls, diags) = run("heidenhain", text);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let planes: Vec<&String> = calls.iter().filter(|c| c.starts_with("SELECT_PLANE")).collect();
    assert!(planes.iter().any(|c| c.contains("YZ")), "{calls:?}");
    assert!(planes.last().is_some_and(|c| c.contains("XY")), "{calls:?}");
    assert_eq!(moves(&calls).iter().filter(|c| c.starts_with("ARC_FEED")).count(), 2, "{calls:?}");
    // The same centre in X and Y (the tool call's plane) keeps the plane: no plane change.
    let xy = text.replace("3 CC Y+0 Z+5\n4 C Y+5 Z+5 DR+\n", "");
    let (calls, _) = run("heidenhain", &xy);
    assert!(!calls.iter().any(|c| c.starts_with("SELECT_PLANE") && c.contains("YZ")), "{calls:?}");
}

/// An Okuma OSP-L arc sized by L (`G02 X Z L`, alarm B 2255 of the OSP): the radius, read
/// as such; I K and L together are refused.
#[test]
fn an_okuma_lathe_arc_takes_its_radius_in_l() {
    let (calls, diags) = run("okuma_lathe", "G00 X20. Z20.\nG02 X20. Z10. L5. F0.1\nM02\n");
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert_eq!(moves(&calls).iter().filter(|c| c.starts_with("ARC_FEED")).count(), 1, "{calls:?}");
    let (_, diags) = run("okuma_lathe", "G00 X20. Z20.\nG02 X20. Z10. L5. K-5. F0.1\nM02\n");
    assert!(!errors(&diags).is_empty(), "{diags:?}");
    let sniffed = Registry::shipped().sniff(
        "%\nG140\nN10 G00 X20. Z20.\nN20 G50 S2400\nN30 G96 S350 M03\nN40 G02 X2.0286 Z4.745 L.0407 F.02\n",
        None,
        "fanuc",
    );
    assert_eq!(sniffed.dialect, "okuma_lathe", "{sniffed:?}");
}

// ---- Centroid CNC12 macros ----

/// A CNC12 macro in the style of the Avid/Corbin tool-changer macros (our own text): an
/// included defines file called by G65 and its quoted name, `DEFINE <NAME>` and `<NAME>`
/// reads and writes, a defined statement standing alone, bare and bracketed IF conditions
/// with `!`, `!=`, `&&`, `#T` (the call's argument), `#[z]` and `#(expr)`, the formatted
/// string M codes with their variables, PLC-bit waits after `/`, and no M30: the file's end
/// is a return. Every form reads without an error, and `<NAME> = 2` then `G1 X<NAME>` moves
/// to X2; an unclosed quote is still an error.
#[test]
fn a_centroid_cnc12_macro_reads_its_defines_prompts_and_plc_waits() {
    let text = "G65 \"\\cncm\\shop\\defines.cnc\"\n\
                DEFINE <OFFSET> #101\n\
                <OFFSET> = 2\n\
                G90 G1 X<OFFSET> F100\n\
                <PREVENT_LOOK_AHEAD>\n\
                IF <GRAPHING_OR_SEARCHING> THEN #121 = 1 ; note\n\
                #[z] = 1\n\
                IF [#(100+#z) == 0] || !<ENABLED> THEN #120 = #T\n\
                M225 #130 \"Waiting %.0f seconds\" #130\n\
                m222 q0 #110 \"Tool %.0f ready? Y for yes\" #1\n\
                IF #110 != 121 THEN #122 = 1\n\
                M200 \"Install tool %.0f\" #1\n\
                M101/50001\n\
                M95 /1/2/19\n\
                M116/Z P[#z] F10\n\
                G1 X3\n";
    let (calls, diags) = run("centroid", text);
    assert_eq!(errors(&diags), Vec::<String>::new());
    let feeds: Vec<&str> = calls.iter().map(String::as_str).filter(|c| c.starts_with("STRAIGHT_FEED(")).collect();
    assert!(feeds.first().is_some_and(|c| c.starts_with("STRAIGHT_FEED(2.0000,")), "G1 X<OFFSET> moves to X2: {calls:?}");
    assert!(feeds.last().is_some_and(|c| c.starts_with("STRAIGHT_FEED(3.0000,")), "the run reaches the last block: {calls:?}");
    assert!(diags.iter().any(|d| d.message.contains("`DEFINE` gave stands for a statement")), "{diags:?}");
    let (_, bad) = run("centroid", "M200 \"Install tool\n");
    assert!(bad.iter().any(|d| d.is_error() && d.message.contains("not closed")), "{bad:?}");
}

/// A single-point groove cut in passes with G32 (the Doosan shop's style, our own text): the
/// lead F is given on the first pass only; the later passes cut at the F in force, as the
/// feed word is modal under feed per revolution. A G32 with no F ever given under feed per
/// minute is still skipped with an error.
#[test]
fn a_lathe_thread_pass_without_f_cuts_at_the_lead_in_force() {
    let text = "O1\nG20 G99\nG97 S100 M3\nG0 X2.81 Z.05\nG32 Z-.77 F.625\nG0 X2.7\nZ.05\nX2.825\nG32 Z-.77\nG0 X2.7\nZ.05\nM30\n";
    let (calls, diags) = run("fanuc_lathe", text);
    assert_eq!(errors(&diags), Vec::<String>::new());
    let syncs = calls.iter().filter(|c| c.starts_with("START_SPEED_FEED_SYNC(0.625")).count();
    assert_eq!(syncs, 2, "{calls:?}");
    let (_, bad) = run("fanuc_lathe", "O1\nG98\nG97 S100 M3\nG0 X2.81 Z.05\nG32 Z-.77\nM30\n");
    assert!(bad.iter().any(|d| d.is_error() && d.message.contains("without F")), "{bad:?}");
}

/// A TNC formula too long for its line goes on after `~` on the next, and a TNC set to the
/// decimal comma writes `0,001` in it (issue 43, a Klartext curve program): one formula, its
/// value computed; no error.
#[test]
fn a_tnc_formula_continues_after_a_tilde_with_decimal_commas() {
    let text = "0 BEGIN PGM K MM\n1 TOOL CALL 1 Z S900\n2 Q4 = 0,5\n3 Q2 = ( 1,5 + Q4 ) * ~\n    ( 2 + 0,25 ) + 10\n\
                4 L X+Q2 Y+0 Z+5 R0 FMAX\n5 END PGM K MM\n";
    let (calls, diags) = run("heidenhain", text);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    // (1.5 + 0.5) * 2.25 + 10 = 14.5
    assert!(moves(&calls).iter().any(|m| m.starts_with("STRAIGHT_TRAVERSE(14.5000, 0.0000, 5.0000")), "{calls:?}");
}

/// `CYCL DEF 14.1 CONTOUR LABEL1 /2 /3` (and the older German `KONTURLABEL1 /2 /3`): the
/// contour's labels, the first run into the name, `/` between them (TNC cycle programming
/// manual, cycle 14). Read without an error; the first label is the contour's.
#[test]
fn a_contour_label_list_is_read_in_its_written_forms() {
    for line in ["CONTOUR LABEL1 /2 /3", "KONTURLABEL1 /2", "CONTOUR LABEL 1 /2 /3", "CONTOUR LABEL 1/2", "CONTOUR LABEL 1"] {
        let text = format!(
            "0 BEGIN PGM C MM\n1 TOOL CALL 1 Z S1000\n2 CYCL DEF 14.0 CONTOUR\n3 CYCL DEF 14.1 {line}\n4 L Z+100 R0 FMAX M2\n\
             5 LBL 1\n6 L X+0 Y+0 RR\n7 L X+10 Y+0\n8 LBL 0\n9 LBL 2\n10 L X+5 Y+5 RL\n11 LBL 0\n12 END PGM C MM\n"
        );
        let (_, diags) = run("heidenhain", &text);
        assert!(errors(&diags).is_empty(), "{line}: {:?}", errors(&diags));
    }
    // A list in the sub-block of a cycle only: an address run into digits stays an address.
    let (_, diags) = run("heidenhain", "0 BEGIN PGM C MM\n1 L X+10 Y+0 R0 FMAX /2\n2 END PGM C MM\n");
    assert!(!errors(&diags).is_empty(), "a slash after a move is not a label list");
}

/// A call of a cycle the dictionary does not model (`CYCL DEF 22 ROUGH-OUT`, then `CYCL
/// CALL`) runs that cycle on the control: a warning, kept as intent, never "no cycle defined"
/// and never a call of the cycle defined before it. A call with no cycle defined at all stays
/// an error.
#[test]
fn a_call_of_an_unmodelled_cycle_is_intent_not_an_error() {
    let text = "0 BEGIN PGM P MM\n1 TOOL CALL 1 Z S1000\n2 CYCL DEF 200 DRILLING ~\n  Q200=2 ;SET-UP ~\n  Q201=-10 ;DEPTH ~\n\
                Q206=100 ;FEED ~\n  Q202=10 ;PLUNGE ~\n  Q203=+0 ;SURFACE ~\n  Q204=50 ;2ND\n3 CYCL DEF 22 ROUGH-OUT ~\n\
                Q10=-2 ;INFEED\n4 L X+10 Y+10 Z+50 R0 FMAX\n5 CYCL CALL M3\n6 END PGM P MM\n";
    let (calls, diags) = run("heidenhain", text);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(diags.iter().any(|d| d.severity == Severity::Warning && d.message.contains("runs cycle 22")), "{diags:?}");
    // Cycle 200 is not run in its place: no feed move down to the depth.
    assert!(!moves(&calls).iter().any(|m| m.starts_with("STRAIGHT_FEED") && m.contains("-10.0000")), "{calls:?}");
    let (_, diags) = run("heidenhain", "0 BEGIN PGM P MM\n1 TOOL CALL 1 Z S1000\n2 CYCL CALL\n3 END PGM P MM\n");
    assert!(errors(&diags).iter().any(|e| e.contains("without a cycle defined")), "{diags:?}");
}

/// `BLK FORM 0.2 X+Q1 Y+Q2 Z+0`: the TNC takes Q parameters there. Known, the blank is
/// theirs; set outside the file, the blank is unknown (no stock with a corner at 0). No error.
#[test]
fn a_blank_given_by_q_parameters() {
    let known = "0 BEGIN PGM B MM\n1 Q1 = 50\n2 Q2 = 60,5\n3 BLK FORM 0.1 Z X+0 Y+0 Z-20\n4 BLK FORM 0.2 X+Q1 Y+Q2 Z+0\n5 END PGM B MM\n";
    let (calls, diags) = run("heidenhain", known);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(calls.iter().any(|c| c.contains("STOCK X0 Y0 Z-20 X50 Y60.5 Z0")), "{calls:?}");
    let unknown = "0 BEGIN PGM B MM\n1 BLK FORM 0.1 Z X+0 Y+0 Z-Q92\n2 BLK FORM 0.2 X+Q1 Y+Q2 Z+0\n3 END PGM B MM\n";
    let (calls, diags) = run("heidenhain", unknown);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(!calls.iter().any(|c| c.contains("STOCK")), "{calls:?}");
}

/// `DEF REAL ANG`: a user variable may not take a name the control has already (the 840D's
/// own addresses `ANG`, `RND`, `CR`, an axis): an error at the name. An ordinary name is fine.
#[test]
fn a_siemens_variable_named_as_an_address_is_an_error() {
    for name in ["ANG", "RND", "CR", "X"] {
        let (_, diags) = run("siemens", &format!("DEF REAL {name}\nG0 X0 Y0\nM30\n"));
        let found = diags.iter().find(|d| d.is_error()).unwrap_or_else(|| panic!("{name}: {diags:?}"));
        assert_eq!(found.code.as_str(), "syntax::malformed-expression", "{name}");
        assert!(found.message.contains(name), "{name}: {}", found.message);
    }
    let (_, diags) = run("siemens", "DEF REAL ANGLE, _ANG\nANGLE=5\nG0 X=ANGLE Y0\nM30\n");
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
}

/// The legacy cycles' sub-blocks as older TNCs write them, the value run into its name with
/// its sign and a decimal comma (`CYCL DEF 1.1 ABST+1`, `1.2 TIEFE-11,5`, `5.3 ZUSTLG+3 F1000`,
/// `10.1 ROT+45`, `11.1 SCL0,75`), a `STOP M0` block and `RND R0,5`: read without an error,
/// the peck drilling cycle with its depth (TNC 155/355/426 user's manuals, fixed cycles).
#[test]
fn legacy_cycle_sub_blocks_with_glued_signed_values() {
    let text = "0 BEGIN PGM R MM\n1 TOOL CALL 1 Z S100\n2 CYCL DEF 10.0 ROTATION\n3 CYCL DEF 10.1 ROT+45\n\
                4 CYCL DEF 11.0 SCALING\n5 CYCL DEF 11.1 SCL0,75\n6 CYCL DEF 1.0 TIEFBOHREN\n7 CYCL DEF 1.1 ABST+1\n\
                8 CYCL DEF 1.2 TIEFE-11,5\n9 CYCL DEF 1.3 ZUSTLG+3\n10 CYCL DEF 1.4 V.ZEIT0\n11 CYCL DEF 1.5 F80\n\
                12 L X+0 Y+0 Z+2 R0 FMAX M3\n13 L M99\n14 STOP M0\n15 CYCL DEF 5.0 KREISTASCHE\n16 CYCL DEF 5.1 ABST+1\n\
                17 CYCL DEF 5.2 TIEFE-5\n18 CYCL DEF 5.3 ZUSTLG+3 F1000\n19 CYCL DEF 5.4 RADIUS10\n20 CYCL DEF 5.5 F500 DR+\n\
                21 L X-60 Y+0 Z-5 R0 FMAX\n22 L X+40 F450\n23 RND R0,5\n24 L X+40 Y-18,376\n25 L Z+10 R0 FMAX M30\n26 END PGM R MM\n";
    let (calls, diags) = run("heidenhain", text);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    // Surface 1 below the start (Z+2 less ABST 1), the hole 11.5 deep: its bottom at -10.5.
    assert!(moves(&calls).iter().any(|m| m.starts_with("STRAIGHT_FEED(0.0000, 0.0000, -10.5000")), "{calls:?}");
    // Words that are addresses stay addresses: `DL+0,2` in a tool call is not a name and value.
    let (_, diags) = run("heidenhain", "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S100 DL+0,2 DR-0,1\n2 END PGM T MM\n");
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
}

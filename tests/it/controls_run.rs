//! What a control runs is read without an error (issue 43, sweep 9's misses): Siemens arrays
//! of several dimensions, oscillation settings given as a pair, skip levels, an addressed
//! spindle's expression value, a rounding beside an arc; Haas's `IF [..]` with a statement
//! and no THEN; and what the control rejects stays an error (Fanuc's `IF` with neither GOTO
//! nor THEN); Centroid's one-line `IF .. THEN GOTO n` and its `ELSE`, and its `IF cond` alone
//! (lookahead stop); a LinuxCNC subroutine file whose `endsub` names another subroutine.

use ncplan::interp::Profile;

fn errors(dialect: &str, program: &str) -> Vec<String> {
    let (_, diags) = crate::moves_and_findings(dialect, program, &Profile::default());
    diags.iter().filter(|d| d.is_error()).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect()
}

fn moves(dialect: &str, program: &str) -> Vec<String> {
    crate::moves_and_findings(dialect, program, &Profile::default()).0
}

#[test]
fn siemens_arrays_of_two_and_three_dimensions_are_read_and_evaluated() {
    let program = "DEF REAL POZZ[3,4]\nDEF INT IDX[2,2,2]\nPOZZ[1,2]=5\nPOZZ[2,1]=7\nIDX[1,1,1]=POZZ[1,2]+POZZ[2,1]\nG1 X=POZZ[1,2] Y=IDX[1,1,1] F100\nM30\n";
    assert_eq!(errors("siemens", program), Vec::<String>::new());
    // The elements are kept apart: [1,2] is 5, [2,1] is 7, their sum 12.
    assert_eq!(moves("siemens", program).last().unwrap(), "STRAIGHT_FEED(5.0000, 12.0000, 0.0000, 0.0000, 0.0000, 0.0000)");
}

#[test]
fn siemens_oscillation_options_are_a_pair_of_values() {
    assert_eq!(errors("siemens", "OSP1[Z]=1 OST1[Z]=-2\nOSCTRL[Z]=(1+2,16+32+64)\nM30\n"), Vec::<String>::new());
}

#[test]
fn siemens_skip_levels_zero_to_nine_skip_the_block() {
    let program = "G1 X10 F100\n/0 G1 X20\n/9 G1 X30\n/ G1 X40\nM30\n";
    assert_eq!(errors("siemens", program), Vec::<String>::new());
    // Each level's block is a skippable block as `/` is: with the switch on, only the first
    // move is made; off, all four.
    assert_eq!(moves("siemens", program).len(), 4);
    let on = Profile { block_delete: true, ..Profile::default() };
    let (on, _) = crate::moves_and_findings("siemens", program, &on);
    assert_eq!(on, vec!["STRAIGHT_FEED(10.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)"]);
}

#[test]
fn an_addressed_spindle_word_takes_an_expression() {
    assert_eq!(errors("siemens", "S2=90000/3 M2=3\nG4 F1\nM2=5\nM30\n"), Vec::<String>::new());
}

#[test]
fn a_rounding_beside_an_arc_is_the_controls_to_make_not_an_error() {
    let program = "G17 G90 G1 X0 Y0 F500\nG2 X10 Y10 CR=10 RND=2\nG1 X20 Y10\nG1 X20 Y0 RND=2\nG3 X30 Y10 CR=10\nM30\n";
    let (_, diags) = crate::moves_and_findings("siemens", program, &Profile::default());
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:?}");
    let sharp = diags.iter().filter(|d| d.message.contains("next to an arc")).count();
    assert_eq!(sharp, 2, "{diags:?}");
    // A corner between two lines is still made.
    let lines = "G17 G90 G1 X0 Y0 F500\nG1 X10 Y0 RND=2\nG1 X10 Y10\nM30\n";
    assert!(moves("siemens", lines).len() > 3);
    assert_eq!(errors("siemens", lines), Vec::<String>::new());
}

#[test]
fn haas_runs_a_statement_after_an_if_without_then() {
    let program = "O1000\n#1=1\n#2=0\nIF [#1 EQ 1] #2=5\nIF [#1 EQ 2] #2=7\nG0 X#2\nM30\n";
    assert_eq!(errors("haas", program), Vec::<String>::new());
    assert_eq!(moves("haas", program), vec!["STRAIGHT_TRAVERSE(5.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)"]);
}

#[test]
fn fanucs_if_with_neither_goto_nor_then_stops_whatever_the_condition() {
    for cond in ["1", "2"] {
        let program = format!("O1000\n#1=1\nIF [#1 EQ {cond}] #2=5\nG0 X1\nM30\n");
        let found = errors("fanuc", &program);
        assert_eq!(found.len(), 1, "{found:?}");
        assert!(found[0].contains("neither `GOTO` nor `THEN`"), "{found:?}");
    }
}

/// Fanuc lathe direct drawing dimensions (0i-TF/30i T series): `G01 X51.,A-45.` gives one end
/// coordinate and the line's angle from +Z; the other coordinate follows (sweep 10's Fanuc
/// lathe programs, found after its measurement). Both coordinates and an angle in one block
/// (no angle-only block before it) is no form of it: a warning, the move to the coordinates given.
#[test]
fn fanuc_lathe_direct_drawing_angle_gives_the_left_out_coordinate() {
    let program = "G21 G18 G99\nT0101\nG0 X45. Z2.\nG1 Z0 F0.1\nG1 X51.,A-45.\nG1 Z-20.\nG1 X60.\nG1 W-5.,A-30.\nM30\n";
    assert_eq!(errors("fanuc_lathe", program), Vec::<String>::new());
    let m = moves("fanuc_lathe", program);
    // Ø45 → Ø51 at 45°: 3 mm out in radius is 3 mm along -Z, a 3 × 45° chamfer.
    assert!(m.contains(&"STRAIGHT_FEED(25.5000, 0.0000, -3.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{m:?}");
    // 5 mm along -Z at -30°: 5 · tan 30° = 2.8868 mm out in radius.
    assert!(m.contains(&"STRAIGHT_FEED(32.8868, 0.0000, -25.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{m:?}");
    let (_, diags) = crate::moves_and_findings("fanuc_lathe", "G18 G99\nG0 X40. Z0\nG1 X50. Z-10.,A20. F0.1\nM30\n", &Profile::default());
    assert!(diags.iter().any(|d| d.code.as_str() == "interp::unsupported" && d.message.contains("line angle")), "{diags:?}");
}

/// The two-block direct drawing form (Fanuc 0i-TF / 30i T series): `G01 ,A150.` gives a line's
/// angle alone; the next block's end point and angle give a second line, and the first move
/// ends where the two meet. A move of that form with nothing to meet is left out, and said so.
#[test]
fn fanuc_lathe_direct_drawing_two_blocks_meet_at_their_lines_intersection() {
    // From Ø20 Z0 along -Z (A180), then a face at Z-30 up to Ø60 (A90): the corner is Ø20 Z-30.
    let program = "G21 G18 G99\nT0101\nG0 X20. Z2.\nG1 Z0 F0.1\nG1 ,A180.\nG1 X60. Z-30.,A90.\nM30\n";
    assert_eq!(errors("fanuc_lathe", program), Vec::<String>::new());
    let m = moves("fanuc_lathe", program);
    let at = m.iter().position(|x| x == "STRAIGHT_FEED(10.0000, 0.0000, -30.0000, 0.0000, 0.0000, 0.0000)").expect("the corner");
    assert_eq!(m[at + 1], "STRAIGHT_FEED(30.0000, 0.0000, -30.0000, 0.0000, 0.0000, 0.0000)", "{m:?}");
    // From Ø20 Z0 at 150° (out in X by half of what it goes along -Z), then along Ø60 (A180) to
    // Z-40: the lines meet at radius 30, 40 · cos 30° = 34.641 along -Z.
    let program = "G21 G18 G99\nT0101\nG0 X20. Z2.\nG1 Z0 F0.1\nG1 ,A150.\nG1 X60. Z-40.,A180.\nM30\n";
    assert_eq!(errors("fanuc_lathe", program), Vec::<String>::new());
    let m = moves("fanuc_lathe", program);
    assert!(m.contains(&"STRAIGHT_FEED(30.0000, 0.0000, -34.6410, 0.0000, 0.0000, 0.0000)".to_owned()), "{m:?}");
    assert_eq!(m.last().unwrap(), "STRAIGHT_FEED(30.0000, 0.0000, -40.0000, 0.0000, 0.0000, 0.0000)");
    // An angle alone, then a rapid: nothing to meet.
    let (m, diags) = crate::moves_and_findings("fanuc_lathe", "G18 G99\nG0 X20. Z0\nG1 ,A180. F0.1\nG0 X50.\nM30\n", &Profile::default());
    assert!(diags.iter().any(|d| d.code.as_str() == "interp::unsupported" && d.message.contains("left out")), "{diags:?}");
    assert!(!m.iter().any(|x| x.starts_with("STRAIGHT_FEED")), "{m:?}");
}

/// LinuxCNC stops where rs274 does: a bare o-word inside a subroutine's body starts another
/// definition ("Nested subroutine definition"), and an `endif` no `if` of its label opened
/// ("undefined O-word label"). Sweep 10's toolchange.ngc of jakefreese/LCNC_BMC20 had both.
#[test]
fn linuxcnc_stray_o_word_closers_stop_the_program() {
    let nested = errors("linuxcnc", "o<a> sub\nO103\nG0 X1\no<a> endsub\nM2\n");
    assert!(nested.iter().any(|e| e.starts_with("flow::nested-definition")), "{nested:?}");
    // An o-word followed by anything but a comment is no definition but an unknown control
    // command (rs274: "Unknown control command in o word"), where the control stops.
    let command = errors("linuxcnc", "o<a> sub\nO1 #<d> = 1 (set)\no<a> endsub\no<a> call\nM2\n");
    assert!(command.iter().all(|e| !e.starts_with("flow::nested-definition")), "{command:?}");
    assert!(command.iter().any(|e| e.starts_with("syntax::unknown-address")), "{command:?}");
    // A comment after it, in either form, leaves it a definition.
    for bare in ["O103 (next)", "O103 ; next"] {
        let commented = errors("linuxcnc", &format!("o<a> sub\n{bare}\nG0 X1\no<a> endsub\nM2\n"));
        assert!(commented.iter().any(|e| e.starts_with("flow::nested-definition")), "{bare}: {commented:?}");
    }
    let unmatched = errors("linuxcnc", "G0 X0\nO108 endif\nM2\n");
    assert!(unmatched.iter().any(|e| e.starts_with("flow::unmatched")), "{unmatched:?}");
    // Matched ones, and a Fanuc-style numbered subprogram outside any definition, read clean.
    assert_eq!(errors("linuxcnc", "#1=1\nO108 if [#1 GT 0]\nG0 X1\nO108 endif\nM2\n"), Vec::<String>::new());
    assert_eq!(errors("linuxcnc", "G0 X0\nO1000\nG0 X1\nM99\nM2\n"), Vec::<String>::new());
}

/// A subroutine file (RS274NGC "Calling Files": the file opens with its one definition, read
/// when a call or an M6 remap's `ngc=` opens it) runs from its `sub` line: an `endsub` inside
/// one of its `if`s returns early, as `return` does, and the definition ends at the `endsub` no
/// block encloses (sweep 11's flexgui-style toolchange.ngc, `o105 if` .. `o<toolchange> endsub
/// [1]` .. `o105 endif`, had 19 errors). Met in the flow of a main program, a definition is
/// skipped to its first `endsub`, as rs274 does, and the `endif` left over stops the run.
#[test]
fn linuxcnc_a_subroutine_file_may_end_its_sub_early_inside_an_if() {
    let file = "o<tc> sub\no105 if [#<selected_tool> EQ #<tool_in_spindle>]\n  o<tc> endsub [1]\no105 endif\nG53 G0 Z0\nM6\no<tc> endsub [1]\nM2\n";
    assert_eq!(errors("linuxcnc", file), Vec::<String>::new());
    let in_flow = "G0 X0\no100 sub\no101 if [#1 GT 0]\no100 endsub [1]\no101 endif\nG0 X1\no100 endsub\no100 call [1]\nM2\n";
    assert!(!errors("linuxcnc", in_flow).is_empty());
}

/// Siemens `ROUNDUP` rounds up (840D sl job planning, "ROUNDUP: Round up": 3.1 → 4, -3.1 → -3),
/// also with a blank before its bracket (sweep 10's CYCLE189.spf).
#[test]
fn siemens_roundup_rounds_up_with_or_without_a_blank() {
    let program = "R1=ROUNDUP (3.1)\nR2=ROUNDUP(-3.1)\nG1 X=R1 Y=R2 F100\nM30\n";
    assert_eq!(errors("siemens", program), Vec::<String>::new());
    assert_eq!(moves("siemens", program).last().unwrap(), "STRAIGHT_FEED(4.0000, -3.0000, 0.0000, 0.0000, 0.0000, 0.0000)");
}

/// Fanuc custom macro words may be written by their first two letters: `WH[..]DO1` is a
/// WHILE loop (a Fanuc 0i-MD shop's macro, sweep 7's O3001: its `END1` was unmatched).
#[test]
fn fanuc_wh_is_while() {
    let program = "O3001\n#1=3\nWH[#1GT0]DO1\nG91G1X1.F100\n#1=#1-1\nEND1\nM99\n";
    assert_eq!(errors("fanuc", program), Vec::<String>::new());
    assert_eq!(moves("fanuc", program).iter().filter(|m| m.starts_with("STRAIGHT_FEED(")).count(), 3);
}

/// Between the two Sinumerik dictionaries, codes only one has decide: a program whose only
/// marks are `( )` remarks and shared codes (`%MPF`, R parameters, `L100 P2`) is the older
/// controls', since the 840D's round brackets hold arithmetic and its remarks follow `;`; one
/// with the 840D's own language (DEF, IF/ENDIF, CYCLE8x, TRANS) is the 840D's, and the older
/// dictionary does not read that language (it is not theirs).
#[test]
fn sinumerik_810_or_840d_by_the_codes_only_one_has() {
    let r = ncplan::dialect::Registry::shipped();
    let remarks = "%MPF1\n(PART 1234 SHAFT)\nN10 G90 G0 X10 Y10 S500 M3 (START POINT)\nN20 G1 X20 F100 (FIRST CUT)\nN25 L100 P2\nN30 M30\n";
    assert_eq!(r.sniff(remarks, Some("PART.MPF"), "linuxcnc").dialect, "siemens_810");
    assert_eq!(r.sniff(remarks, None, "linuxcnc").dialect, "siemens_810");
    let d840 = "%_N_PART_MPF\nDEF REAL DEPTH\nN10 G90 G0 X10 Y10 S500 M3 ; start\nN20 CYCLE81(10, 0, 2, -5)\nN30 IF R1>0 GOTOF ENDE\nN40 TRANS X10\nENDE:\nN50 M30\n";
    assert_eq!(r.sniff(d840, Some("PART.MPF"), "linuxcnc").dialect, "siemens");
    assert_eq!(errors("siemens", d840), Vec::<String>::new());
    assert!(!errors("siemens_810", "N10 DEF REAL DEPTH\nN20 TRANS X10\nN30 M30\n").is_empty());
    // A Fanuc program's remarks count for neither.
    let fanuc = "%\nO1234 (SHAFT)\nN10 G90 G54 G0 X10. Y10. (START POINT)\nN20 M30\n%\n";
    assert_eq!(r.sniff(fanuc, Some("O1234.NC"), "linuxcnc").dialect, "fanuc");
}

/// The older SINUMERIK controls (810/820/840C): `( )` remarks, `B` the arc radius, `G58` the
/// programmable zero offset, `G4 X` a dwell, `G92 S` the speed limit, and the @ codes of
/// program flow kept as intent (a warning each, the blocks run once in order); told from the
/// 840D by them.
#[test]
fn older_sinumerik_remarks_b_radius_and_at_codes() {
    let program = "%MPF1005\n(Nullpunktverschiebung)\nN5 G54\nN10 G58 X0 Z45\nN15 G92 S3000\nN20 T1 D1 G96 S300 F0.2 M3\nN25 G0 X20 Z2\nN30 G1 Z0\nN35 G2 X30 Z-5 B5\nN40 R102=1 (Laufvariable)\nN45 @136 R102 K2 K60\nN50 R102=R102+1\nN55 @100 K-45\nN60 G4 X1\nN65 M30\n";
    let r = ncplan::dialect::Registry::shipped();
    let sniffed = r.sniff(program, Some("MPF1005"), "linuxcnc");
    assert_eq!(sniffed.dialect, "siemens_810", "{sniffed:?}");
    assert_eq!(errors("siemens_810", program), Vec::<String>::new());
    let (m, diags) = crate::moves_and_findings("siemens_810", program, &Profile::default());
    assert!(diags.iter().filter(|d| d.code.as_str() == "interp::unsupported" && d.message.contains('@')).count() >= 2, "{diags:?}");
    // G58 Z45 shifts Z: the arc ends 45 above its programmed Z-5 in machine terms; read in
    // program coordinates the move list holds the arc's end at X radius 15.
    assert!(m.iter().any(|x| x.starts_with("ARC_FEED(")), "{m:?}");
    // The 840D reads the same text with errors (`( )` is arithmetic there).
    assert!(!errors("siemens", program).is_empty());
}

/// A LinuxCNC subroutine file runs when a call opens it (RS274NGC "Calling Files"): a block of
/// its body whose expression the control cannot read stops it then, as rs274 stops at Probe
/// Screen NG's `[<#_value> EQ -1]` ("bad number format"); the same file written right reads
/// without an error, and a main program's branch not taken is not read (rs274 skips it too).
#[test]
fn a_subroutine_files_unreadable_block_is_an_error() {
    let bad = "o<probe> sub\nG90\no<_probe_z> call [5]\nO1 if [<#_value> EQ -1]\n  (ABORT, tripped)\nO1 endif\no<probe> endsub\nM2\n";
    let found = errors("linuxcnc", bad);
    assert_eq!(found.len(), 1, "{found:?}");
    assert!(found[0].starts_with("syntax::malformed-expression"), "{found:?}");
    let good = bad.replace("<#_value>", "#<_value>");
    assert_eq!(errors("linuxcnc", &good), Vec::<String>::new());
    let untaken = "#1 = 0\nO1 if [#1 EQ 1]\n#2 = [<#_value> + 1]\nO1 endif\nG0 X1\nM2\n";
    assert_eq!(errors("linuxcnc", untaken), Vec::<String>::new());
}

/// A Klartext block starts with its path function: a block that starts with an axis word, or
/// with an axis letter alone (a broken `TOOL CALL`'s `80 Z DR+0.0`), is no block the TNC
/// reads; `C X.. Y.. DR+` (the circle function) and an M function alone are blocks of their own.
#[test]
fn a_klartext_block_without_its_function_stops_the_tnc() {
    let good =
        "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000\n2 L X+10 Y+5 R0 FMAX M3\n3 CC X+0 Y+0\n4 C X-10 Y+5 DR+ F200\n5 M5\n6 END PGM T MM\n";
    assert_eq!(errors("heidenhain", good), Vec::<String>::new());
    let broken = good.replace("5 M5", "5 Z DR+0.0");
    let found = errors("heidenhain", &broken);
    assert!(found.len() == 1 && found[0].starts_with("syntax::no-function"), "{found:?}");
    let bare_axis = good.replace("5 M5", "5 X+20 F100");
    assert!(errors("heidenhain", &bare_axis).iter().any(|e| e.starts_with("syntax::no-function")));
}

/// Fanuc's `WH` abbreviation of WHILE is no Fagor statement (the 8055 T's high-level
/// language is written in brackets, the 8070's loops as `$WHILE`): on the Fagor lathe `WH` is
/// no loop, as on the Fagor mill; on the Fanuc lathe it is.
#[test]
fn fagor_lathes_have_no_wh_abbreviation() {
    let r = ncplan::dialect::Registry::shipped();
    for (name, has) in [("fagor_lathe", false), ("fagor", false), ("fanuc_lathe", true)] {
        let d = r.get(name).unwrap();
        assert_eq!(d.macros.statements.iter().any(|(k, _)| k == "WH"), has, "{name}");
    }
}

/// The one-block G76 (`G76 X Z K D F`: K the thread height, D the first depth of cut) is the
/// Haas lathe's only form and Fanuc's FS15 tape format: read without an error in both, as
/// passes down to the height; Fanuc's two-block form reads as before. A one-block G76 or G75
/// with its own words is the Haas lathe's evidence (as G71's one block with D), and Haas's
/// reading wins there; a program without them stays the Fanuc lathe's.
#[test]
fn the_one_block_g76_threads_on_fanuc_and_haas_lathes() {
    let one =
        "O2007\nG18 G20 G99\nT0303\nG97 S1000 M03\nG00 X0.6 Z0.1\nG76 X0.4069 Z-1.5 K0.043075 D0.01076875 F0.07692308\nG00 Z0.1\nM30\n";
    for d in ["fanuc_lathe", "haas_lathe"] {
        assert_eq!(errors(d, one), Vec::<String>::new(), "{d}");
        // The cycle runs as its passes (it was skipped with an error on the Fanuc lathe).
        let m = moves(d, one);
        assert!(m.len() > 6, "{d}: {m:?}");
    }
    // A, the tool's included angle in degrees, is no length: no least increments on either.
    let angle = "O2\nG18 G21 G99\nT0303\nG97 S800 M03\nG00 X26. Z5.\nG76 X22.2 Z-20. K0.92 D0.3 F1.5 A60\nG00 Z5.\nM30\n";
    for d in ["fanuc_lathe", "haas_lathe"] {
        let (_, diags) = crate::moves_and_findings(d, angle, &Profile::default());
        let found: Vec<_> = diags.iter().map(|d| d.code.as_str()).collect();
        assert!(!found.contains(&"interp::no-decimal-point"), "{d}: {found:?}");
        assert!(diags.iter().all(|d| !d.is_error()), "{d}: {found:?}");
    }
    let two = "O1\nG18 G21 G99\nT0303\nG97 S800 M03\nG00 X22. Z5.\nG76 P020060 Q50 R0.02\nG76 X18.16 Z-20. P920 Q300 F1.5\nG00 Z5.\nM30\n";
    assert_eq!(errors("fanuc_lathe", two), Vec::<String>::new());
    let r = ncplan::dialect::Registry::shipped();
    let text = format!("%\n{one}%\n");
    assert_eq!(r.sniff(&text, Some("p.nc"), "fanuc").dialect, "haas_lathe");
    let groove = "%\nO2008\nT1212\nG50 S2500\nG97 S2000 M03\nG00 X1.5 Z-2.097\nG75 X0.0 I0.005\nG00 X1.5\nM30\n%\n";
    assert_eq!(r.sniff(groove, Some("p.nc"), "fanuc").dialect, "haas_lathe");
    assert_eq!(r.sniff(&format!("%\n{two}%\n"), Some("p.nc"), "fanuc").dialect, "fanuc_lathe");
}

/// The Fagor 8055 T's parameters and high-level language (`P100`, `(P100 = 5)`, `(IF P100 EQ 5
/// GOTO N30)`, `;` comments) are read, and Fanuc's Custom Macro B, which the Fagor does not
/// have, is not: `#1=5` and `WHILE [..] DO1` stop it.
#[test]
fn the_fagor_lathe_reads_its_parameters_not_fanuc_macro_b() {
    let program = "%\nN10 G90 G95\nG96 S180 M3\n(P100 = 20)\nG0 X P100 Z10\n(IF P100 EQ 20 GOTO N30)\nN20 G1 X40 F0.1\nN30 G1 X30 Z0 F0.1 ; done\nM30\n%\n";
    assert_eq!(errors("fagor_lathe", program), Vec::<String>::new());
    assert_eq!(moves("fagor_lathe", program)[0], "STRAIGHT_TRAVERSE(10.0000, 0.0000, 10.0000, 0.0000, 0.0000, 0.0000)");
    let macro_b = "%\nO100\n#1=5\nWHILE [#1 GT 0] DO1\n#1=#1-1\nEND1\nM30\n%\n";
    assert!(!errors("fagor_lathe", macro_b).is_empty());
    assert!(errors("fanuc_lathe", macro_b).is_empty());
}

#[test]
fn an_indirect_write_to_a_variable_set_outside_is_not_followed_and_never_lands_on_vacant() {
    // Renishaw's `#[#111+5]=1280` with #111 the caller's: which variable is written is not
    // known, so nothing is written; before, the unknown index rounded to #0, after which
    // `IF[#8EQ#0]` (E not given) read as unknown and `GOTO#149` jumped to the vacant value.
    let program = "O1000\n#149=5\n#[#111+5]=3\nIF[#8EQ#0]GOTO10\n#149=#8\nN10\nGOTO#149\nN5\nM30\n";
    assert_eq!(errors("fanuc", program), Vec::<String>::new());
    let (_, diags) = crate::moves_and_findings("fanuc", program, &Profile::default());
    assert!(diags.iter().any(|d| d.code.as_str() == "interp::unknown-value" && d.message.contains("which one is written")), "{diags:?}");
    // A known index still writes, and a jump to a block that is not there is still an error.
    assert_eq!(errors("fanuc", "O1000\n#1=100\n#[#1+5]=5\nGOTO#105\nN5\nM30\n"), Vec::<String>::new());
    assert_eq!(errors("fanuc", "O1000\n#1=100\n#[#1+5]=7\nGOTO#105\nN5\nM30\n").len(), 1);
}

#[test]
fn a_legacy_cycle_name_run_into_its_value_is_read_as_name_and_value() {
    // The Hungarian dialogue's cycle 9 as hyperMILL writes it: `9.1 V.IDO2` is DWELL 2.
    let program = "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000\n2 L Z+10 R0 FMAX M3\n3 CYCL DEF9.0 VARAKOZASI IDO\n4 CYCL DEF9.1 V.IDO2\n5 END PGM T MM\n";
    assert_eq!(errors("heidenhain", program), Vec::<String>::new());
    // Read as cycle 9's dwell of 2 s.
    let d = ncplan::dialect::Registry::shipped().get("heidenhain").unwrap();
    let mut canon: Vec<ncplan::canon::Canon> = Vec::new();
    ncplan::interp::interpret(program, &d, &Profile::default(), &mut canon);
    assert!(canon.iter().any(|c| matches!(c.op, ncplan::canon::CanonOp::Dwell(s) if s == 2.0)), "{canon:?}");
}

/// Only a sub-block the dictionary gives a value splits a name run into a number: cycle 12's
/// program name `SUB1` and cycle 14's label `LABEL1` are names, not a name and the value 1.
#[test]
fn a_program_or_label_name_ending_in_a_digit_is_not_split_into_name_and_value() {
    let d = ncplan::dialect::Registry::shipped().get("heidenhain").unwrap();
    let values = |line: &str| {
        let (mut block, mut diags) = (ncplan::syntax::Block::default(), Vec::new());
        let mut p = ncplan::syntax::Parser::new(line, &d);
        assert!(p.next_block(&mut block, &mut diags));
        block.words.iter().filter(|w| w.role == ncplan::dialect::Role::CycleValue).count()
    };
    assert_eq!(values("7 CYCL DEF 12.1 PGM SUB1\n"), 0);
    assert_eq!(values("8 CYCL DEF 14.1 CONTOUR LABEL1\n"), 0);
    assert_eq!(values("4 CYCL DEF9.1 V.IDO2\n"), 1);
    assert_eq!(values("5 CYCL DEF 1.2 DEPTH -15\n"), 1);
}

#[test]
fn a_macro_calls_w_argument_is_no_lathe_evidence() {
    let registry = ncplan::dialect::Registry::shipped();
    // Renishaw's calibration on a mill: the W and U are G65 arguments (#23, #21).
    let mill = "%\nO9801\nG65P9732S1.W2.\nG65P9725Z#14F#119U1.\nG43H#4111Z#5003\nM99\n%\n";
    let sniffed = ncplan::pipeline::sniff(&registry, mill.as_bytes(), std::path::Path::new("O9801"));
    assert_eq!(sniffed.dialect, "fanuc");
    // A U/W move outside a call still counts.
    let lathe = "%\nO1000\nG65P9732S1.\nG0 U1. W-2.\nM30\n%\n";
    let sniffed = ncplan::pipeline::sniff(&registry, lathe.as_bytes(), std::path::Path::new("O1000"));
    assert_eq!(sniffed.dialect, "fanuc_lathe");
}

/// The X of each move, in order.
fn xs(dialect: &str, program: &str) -> Vec<String> {
    moves(dialect, program).iter().map(|m| m.split(['(', ',']).nth(1).unwrap_or("").to_owned()).collect()
}

/// Centroid CNC12 `IF cond THEN GOTO n` (its manual's IF/THEN, the form Avid's macros write:
/// `IF #9701 EQ 0 THEN GOTO 1000`): the jump is taken only when the condition holds. It was
/// read as `IF cond THEN` and then a `GOTO` of its own, taken whatever the condition.
#[test]
fn centroid_if_then_goto_jumps_only_when_the_condition_holds() {
    for (value, expected) in [("0", vec!["1.0000", "3.0000"]), ("121", vec!["3.0000"])] {
        let program = format!("G90 F10\n#111={value}\nIF #111 != 0 THEN GOTO 1000\nG1 X1\nN1000 G1 X3\nM30\n");
        assert_eq!(errors("centroid", &program), Vec::<String>::new());
        assert_eq!(xs("centroid", &program), expected, "#111={value}");
    }
    // A bracketed condition and a lower-case `then`, as the Avid macros write some.
    let program = "G90 F10\n#1=1\nIF [#1 == 1] then GOTO 20\nG1 X1\nN20 G1 X2\nM30\n";
    assert_eq!(xs("centroid", program), vec!["2.0000"]);
}

/// `IF cond THEN GOTO a ELSE GOTO b` and a trailing `ELSE` with nothing after it (Avid's
/// CNC12 macros: `IF #110 EQ #9718 THEN GOTO 200 ELSE GOTO 300`, `IF #111 EQ 1 THEN GOTO
/// 100 ELSE`): one line, one of the two jumps, or on to the next line; no block `ELSE` that
/// looks for an `ENDIF`.
#[test]
fn centroid_one_line_else_takes_the_other_jump_or_goes_on() {
    for (value, expected) in [("1", vec!["2.0000", "4.0000"]), ("0", vec!["3.0000", "4.0000"])] {
        let program = format!(
            "G90 F10\n#5={value}\nIF #5 EQ 1 THEN GOTO 200 ELSE GOTO 300 ;which\nG1 X1\nN200 G1 X2\nGOTO 400\nN300 G1 X3\nN400 G1 X4\nM30\n"
        );
        assert_eq!(errors("centroid", &program), Vec::<String>::new());
        assert_eq!(xs("centroid", &program), expected, "#5={value}");
    }
    for (value, expected) in [("1", vec!["2.0000"]), ("0", vec!["1.0000", "2.0000"])] {
        let program = format!("G90 F10\n#5={value}\nIF #5 EQ 1 THEN GOTO 100 ELSE\nG1 X1\nN100 G1 X2\nM30\n");
        assert_eq!(errors("centroid", &program), Vec::<String>::new());
        assert_eq!(xs("centroid", &program), expected, "#5={value}");
    }
}

/// `IF [c] THEN #a = 1 ELSE #b = 1` (Centroid's own CNC11 system-test macro) and `THEN
/// G1 X5 ELSE G1 X6`: the THEN clause's statement when the condition holds, else the ELSE's,
/// never both.
#[test]
fn centroid_one_line_else_runs_one_of_two_statements() {
    for (value, expected) in [("1", vec!["5.0000", "7.0000"]), ("0", vec!["6.0000", "8.0000"])] {
        let program = format!(
            "G90 F10\n#1=0\n#2=0\n#5={value}\nIF [#5 == 1] THEN #1 = 7 ELSE #2 = 8\nIF #5 == 1 THEN G1 X5 ELSE G1 X6\nG1 X[#1+#2]\nM30\n"
        );
        assert_eq!(errors("centroid", &program), Vec::<String>::new());
        assert_eq!(xs("centroid", &program), expected, "#5={value}");
    }
}

/// The one-line forms of the other dialects still run by their condition: Fanuc's and Haas's
/// `IF [..] THEN #1=..` and `IF [..] GOTO n`, Okuma's `IF [..] N<name>`.
#[test]
fn other_dialects_one_line_if_forms_still_follow_their_condition() {
    for dialect in ["fanuc", "haas"] {
        for (value, expected) in [("1", vec!["5.0000", "9.0000"]), ("0", vec!["0.0000", "8.0000", "9.0000"])] {
            let program = format!(
                "O1000\nG90 F100\n#1={value}\n#2=0\nIF [#1 EQ 1] THEN #2=5.\nG1 X#2\nIF [#1 EQ 1] GOTO 10\nG1 X8.\nN10 G1 X9.\nM30\n"
            );
            assert_eq!(errors(dialect, &program), Vec::<String>::new());
            assert_eq!(xs(dialect, &program), expected, "{dialect} #1={value}");
        }
    }
    for (value, expected) in [("1", vec!["9.0000"]), ("0", vec!["8.0000", "9.0000"])] {
        let program = format!("G90 F100\nVC1={value}\nIF [VC1 EQ 1] NSKIP\nG1 X8.\nNSKIP G1 X9.\nM30\n");
        assert_eq!(errors("okuma", &program), Vec::<String>::new());
        assert_eq!(xs("okuma", &program), expected, "okuma VC1={value}");
    }
}

/// Heidenhain string parameters and the local and nonvolatile banks (TNC 640 user's manual,
/// "Q parameters: principle and overview" and "String functions"): `DECLARE STRING QS1 =
/// "TEXT"`, `QS3 = QS1 || QS2`, the string functions read whole, `QL`/`QR` numbers. Each
/// documented form reads without an error; a `;` inside the quotes is text, after them a comment.
#[test]
fn heidenhain_string_and_local_parameters_are_statements() {
    let program = "0 BEGIN PGM STR MM\n\
        1 DECLARE STRING QS10 = \"WORKPIECE\"\n\
        2 QS3 = \"%0x\" ;temp string\n\
        3 QS11 = QS10 || QS3\n\
        4 QS13 = TOCHAR ( DAT+Q5 DECIMALS3 )\n\
        5 QS14 = SUBSTR ( SRC_QS10 BEG2 LEN4 )\n\
        6 Q5 = TONUMB ( SRC_QS3 )\n\
        7 Q6 = STRLEN ( SRC_QS10 )\n\
        8 Q7 = INSTR ( SRC_QS10 SEA_QS3 BEG0 )\n\
        9 Q8 = STRCOMP ( SRC_QS10 SEA_QS3 )\n\
        10 QS15 = \"A;B\" ; comment\n\
        11 QL1 = 5\n\
        12 QL2 = QL1 * 2\n\
        13 L X+QL1 Y+QL2 R0 FMAX\n\
        14 END PGM STR MM\n";
    assert_eq!(errors("heidenhain", program), Vec::<String>::new());
    // QL1 is 5 and QL2 twice that: the move goes there.
    assert_eq!(moves("heidenhain", program).last().unwrap(), "STRAIGHT_TRAVERSE(5.0000, 10.0000, 0.0000, 0.0000, 0.0000, 0.0000)");
    // The comment after the text is a comment, the `;` in the quotes is not one.
    let (_, diags) = crate::moves_and_findings("heidenhain", program, &Profile::default());
    assert!(diags.is_empty(), "{diags:?}");
    let d = ncplan::dialect::Registry::shipped().get("heidenhain").unwrap();
    let mut out = Vec::new();
    let _ = ncplan::interp::interpret(program, &d, &Profile::default(), &mut out);
    let mut canon = String::new();
    for c in &out {
        ncplan::canon::write_call(&mut canon, &c.op);
    }
    assert!(canon.contains("COMMENT(\" comment\")") && !canon.contains("COMMENT(\"B"), "{canon}");
    // A text not closed is the TNC's error, once.
    let broken = program.replace("\"WORKPIECE\"", "\"WORKPIECE");
    let found = errors("heidenhain", &broken);
    assert!(found.len() == 1 && found[0].contains("not closed"), "{found:?}");
    // A QR parameter keeps its value over a power interruption: read before this file sets
    // it, it is unknown (the word left out, a warning), never an error.
    let retained = "0 BEGIN PGM R MM\n1 L X+QR1 R0 FMAX\n2 END PGM R MM\n";
    assert_eq!(errors("heidenhain", retained), Vec::<String>::new());
    let (_, diags) = crate::moves_and_findings("heidenhain", retained, &Profile::default());
    assert!(diags.iter().any(|d| d.message.contains("QR1, which is set outside")), "{diags:?}");
}

fn findings(dialect: &str, program: &str) -> Vec<String> {
    let (_, diags) = crate::moves_and_findings(dialect, program, &Profile::default());
    diags.iter().map(|d| d.code.as_str().to_owned()).collect()
}

/// Centroid CNC12 `M224 #111 "prompt"` waits for the operator's number and stores it in #111
/// (CNC12 manual, chapter 13): a menu that asks again until a known choice is typed (Avid's
/// utilsrouter.mac) is read with #111 unknown: its choice is a condition not known here, a
/// warning, never an endless loop.
#[test]
fn centroid_m224_menu_loop_waits_for_the_operator() {
    let program = "G90 F10\nN1\nM224 #111 \"Which?\\n#)1: one\\n#)2: two\\n#)\" #111\nIF #111 EQ 1 THEN GOTO 100 ELSE\nIF #111 EQ 2 THEN GOTO 200 ELSE\nGOTO 1\nN100 G1 X1\nGOTO 1000\nN200 G1 X2\nN1000\nM30\n";
    assert_eq!(errors("centroid", program), Vec::<String>::new());
    assert!(findings("centroid", program).iter().any(|c| c == "flow::unknown-condition"), "{:?}", findings("centroid", program));
    // The same loop with #111 set by the program and nothing asked still never ends.
    let program = "G90 F10\n#111=3\nN1\nIF #111 EQ 1 THEN GOTO 100 ELSE\nGOTO 1\nN100 G1 X1\nM30\n";
    assert!(errors("centroid", program).iter().any(|e| e.starts_with("flow::loop-limit")), "{:?}", errors("centroid", program));
}

/// M225's variable is how long its text shows (read, not written): #5 keeps its value.
#[test]
fn centroid_m225_reads_its_variable() {
    let program = "G90 F10\n#5=2\nM225 #5 \"Wait\"\nIF #5 EQ 2 THEN GOTO 10\nG1 X1\nN10 G1 X3\nM30\n";
    assert_eq!(xs("centroid", program), vec!["3.0000"]);
}

/// CNC12 has no LinuxCNC `M61 Q` (set the current tool): an M61 the builder's macro runs
/// needs no Q word.
#[test]
fn centroid_m61_is_a_machine_m_code_without_a_required_q() {
    assert_eq!(errors("centroid", "G90 F10\nM61\nG1 X1\nM30\n"), Vec::<String>::new());
    assert!(errors("linuxcnc", "G90 F10\nM61\nG1 X1\nM30\n").iter().any(|e| e.starts_with("syntax::missing-parameter")));
}

/// Centroid's template M-function macros (the mfuncN.mac files CNC12 installs, "see TB300
/// for tips on writing custom macros") open with `IF #50010 ;Prevent lookahead from parsing
/// past here`: an IF with nothing after its condition, which reads the PLC input (lookahead
/// stops there) and runs nothing. CNC12 has no block IF, so it opens nothing that an ENDIF
/// must close (sweep 17's Acroloc mfunc6.mac: "no matching `endif`", and the rest unread).
/// Where the language does have a block IF (LinuxCNC's `o100 if`) it still needs its endif,
/// and Fanuc's IF with neither GOTO nor THEN still stops the control.
#[test]
fn centroid_if_alone_reads_its_condition_and_runs_nothing() {
    for input in ["0", "1"] {
        let program =
            format!("G90 F10\n#50001={input}\nIF #50001 ;Prevent lookahead from parsing past here\nN100\nG1 X1\nN1000\nG1 X2\nM30\n");
        assert_eq!(errors("centroid", &program), Vec::<String>::new(), "#50001={input}");
        assert_eq!(xs("centroid", &program), vec!["1.0000", "2.0000"], "#50001={input}");
    }
    // Read from the PLC (not set by the file), as the macros do.
    let program = "G90 F10\nIF #50010\nG1 X1\nM30\n";
    assert_eq!(errors("centroid", program), Vec::<String>::new());
    assert_eq!(xs("centroid", program), vec!["1.0000"]);
    assert!(!errors("linuxcnc", "G90 F10\no100 if [#1 GT 0]\nG1 X1\nM2\n").is_empty());
    assert!(!errors("fanuc", "O1000\n#1=1\nIF [#1 EQ 1]\nG0 X1\nM30\n").is_empty());
}

/// A LinuxCNC subroutine file copied from another and renamed on its `sub` line only
/// (Pocket NC's tool-probe.ngc: `O<tool-probe> SUB` .. `O<tool-change> ENDSUB`): a call runs
/// the file from its `sub` line and returns at the first `endsub` it meets, whatever its label
/// (rs274 -g on a copy that calls it: no error), so the file reads with a warning naming the
/// leftover label. In the flow of a main program the definition is skipped to an `endsub` of
/// its own label, and without one the run stops (rs274: the file ends with no program end).
#[test]
fn linuxcnc_a_subroutine_files_endsub_of_another_name_returns_with_a_warning() {
    let file = "o<tool-probe> sub\nG91\nG38.2 Z-10 F20\nG90\no<tool-change> endsub\n";
    assert_eq!(errors("linuxcnc", file), Vec::<String>::new());
    assert!(findings("linuxcnc", file).iter().any(|c| c == "flow::foreign-end-label"), "{:?}", findings("linuxcnc", file));
    // Its own label, when the file has it, ends the definition: no warning.
    let own = "o<tp> sub\nG0 X1\no<tp> endsub\n";
    assert!(!findings("linuxcnc", own).iter().any(|c| c == "flow::foreign-end-label"));
    let in_flow = "G0 X0\no<a> sub\nG0 X1\no<b> endsub\no<a> call\nM2\n";
    assert!(errors("linuxcnc", in_flow).iter().any(|e| e.starts_with("flow::missing-label")), "{:?}", errors("linuxcnc", in_flow));
}

/// Sweep 16 (g006): the SINUMERIK's smooth approach and retraction (840D sl programming
/// manual, fundamentals, "Approach and retraction (G140 to G143, G147, G148, G247, G248, G347,
/// G348, G340, G341, DISR, DISCL, DISRP, FAD)") is the control's to make: the codes and their
/// words read with a warning that the inserted path is kept as intent, and the program's own
/// moves are made as written. A code the control does not have stays an error.
#[test]
fn siemens_smooth_approach_and_retraction_are_kept_as_intent() {
    let program = "G18 G90 G95 DIAMON\nT1 D1\nS200 M4\nG0 X30 Z2\nG42 G147 DISR=1 DISCL=2 FAD=0.1\nG1 X30 Z0 F0.2\n\
G1 X50 Z-25\nG40 G148 DISR=1\nG0 X150 Z50\nG41 G247 G341 DISR=5 F0.1\nG1 X40 Z-5\nG40 G348 DISR=5\nM30\n";
    assert_eq!(errors("siemens", program), Vec::<String>::new());
    let (moves, diags) = crate::moves_and_findings("siemens", program, &Profile::default());
    // The first three such codes are told; the others counted in a note.
    for code in ["G147", "G148", "G247"] {
        assert!(diags.iter().any(|d| d.code.as_str() == "syntax::unmodelled" && d.message.contains(code)), "{code}: {diags:?}");
    }
    // The cone as written, in radii: no approach path invented.
    assert!(moves.contains(&"STRAIGHT_FEED(15.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{moves:?}");
    assert!(moves.contains(&"STRAIGHT_FEED(25.0000, 0.0000, -25.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{moves:?}");
    assert!(!errors("siemens", "G18 G90\nG149 X10\nM30\n").is_empty());
}

/// Sweep 16 (g017): a block may set several spindles, each by its numbered words (840D sl
/// programming manual, fundamentals: `S<n>=`, `M<n>=` address spindle n): `S1=100 S2=100` is
/// no address written twice. The analysis follows the block's first spindle and keeps the
/// other's words as intent; an S written twice for one spindle stays the error it is.
#[test]
fn siemens_speeds_of_two_numbered_spindles_in_one_block_are_no_error() {
    let program = "G18 G90 G95\nS1=100 S2=200 M1=4 M2=3\nG4 F0.5\nM1=5 M2=5\nM30\n";
    assert_eq!(errors("siemens", program), Vec::<String>::new());
    let (_, diags) = crate::moves_and_findings("siemens", program, &Profile::default());
    assert!(
        diags
            .iter()
            .any(|d| d.code.as_str() == "syntax::unmodelled" && d.message.contains("`S2=200`") && d.message.contains("several spindles")),
        "{diags:?}"
    );
    // The first spindle's speed is the one read.
    let d = ncplan::dialect::Registry::shipped().get("siemens").unwrap();
    let mut out = Vec::new();
    ncplan::interp::interpret(program, &d, &Profile::default(), &mut out);
    assert!(out.iter().any(|c| c.op == ncplan::canon::CanonOp::SetSpindleSpeed(100.0)), "{out:?}");
    assert!(!out.iter().any(|c| c.op == ncplan::canon::CanonOp::SetSpindleSpeed(200.0)), "{out:?}");
    assert!(errors("siemens", "S1=100 S1=200 M1=3\nM30\n").iter().any(|e| e.starts_with("syntax::duplicate-word")));
}

/// Sweep 16 (g014): `DIAM90` is diameter programming for absolute dimensions only (840D sl
/// programming manual, fundamentals: an X in G90 a diameter, in G91 a radius), and under it
/// an arc centre's absolute X (`I=AC(20)`) is a diameter as the contour editor writes it
/// (SINUMERIK Operate, contour turning, circle element: "I circle centre point ∅ (abs) or
/// (inc)"). Written before the run: a Ø20 shoulder, an arc of radius 10 about Z-20 Ø20 to
/// Ø40, 5 more on the radius in G91. An arc whose radii really disagree stays an error.
#[test]
fn siemens_diam90_reads_absolute_x_and_absolute_centres_as_diameters() {
    let program = "G18 G90 DIAM90\nG0 Z0 X0\nG1 X20 F0.2\nZ-10\nG2 Z-20 X40 K=AC(-20) I=AC(20)\nG91 G1 X5\nG90 Z-30\nM30\n";
    assert_eq!(errors("siemens", program), Vec::<String>::new());
    let moves = moves("siemens", program);
    assert_eq!(
        moves[3..],
        [
            "ARC_FEED(-20.0000, 20.0000, -20.0000, 10.0000, -1, 0.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(25.0000, 0.0000, -20.0000, 0.0000, 0.0000, 0.0000)",
            "STRAIGHT_FEED(25.0000, 0.0000, -30.0000, 0.0000, 0.0000, 0.0000)",
        ],
        "{moves:?}"
    );
    let wrong = program.replace("I=AC(20)", "I=AC(30)");
    assert!(errors("siemens", &wrong).iter().any(|e| e.starts_with("interp::bad-arc")), "{:?}", errors("siemens", &wrong));
}

/// Sweep 16 (g009): a straight line by one end coordinate and its angle `ANG=` from the Z axis,
/// counter-clockwise (840D sl programming manual, fundamentals, "Contour definitions": "the
/// angle is always referred to the Z axis (normal case: G18 active)"), and modal rounding
/// `RNDM=` of every corner until `RNDM=0`. Written before the run.
#[test]
fn siemens_contour_angles_and_modal_rounding_make_the_contour() {
    // From Z-15 Ø25 at 135° to Z-25: 10 out on the radius (Ø45); then at 135° to Ø65: 10 back.
    let program = "G18 G90 DIAMON\nG1 X0 Z0 F0.2\nG1 X25\nG1 Z-15\nG1 Z-25 ANG=135\nG1 X65 ANG=135\nG1 Z-50\nM30\n";
    assert_eq!(errors("siemens", program), Vec::<String>::new());
    let cone = moves("siemens", program);
    assert_eq!(cone[3], "STRAIGHT_FEED(22.5000, 0.0000, -25.0000, 0.0000, 0.0000, 0.0000)", "{cone:?}");
    assert_eq!(cone[4], "STRAIGHT_FEED(32.5000, 0.0000, -35.0000, 0.0000, 0.0000, 0.0000)", "{cone:?}");
    // RNDM=2 rounds the corner at its own block's end and the next; RNDM=0 ends it.
    let square = "G17 G90 G1 X0 Y0 F500\nG1 X20 RNDM=2\nG1 Y20\nG1 X0 RNDM=0\nG1 Y0\nM30\n";
    assert_eq!(errors("siemens", square), Vec::<String>::new());
    let rounded = moves("siemens", square);
    assert_eq!(rounded.iter().filter(|m| m.starts_with("ARC_FEED")).count(), 2, "{rounded:?}");
    assert!(rounded.contains(&"STRAIGHT_FEED(18.0000, 0.0000, 0.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{rounded:?}");
    assert!(rounded.contains(&"STRAIGHT_FEED(0.0000, 20.0000, 0.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{rounded:?}");
}

/// A rounding too large for a move beside its corner is made smaller to fit on the 840D
/// ("automatically reduced if the contour length of an involved block is insufficient",
/// programming manual, fundamentals, "Chamfer, rounding"): RND=5 after a move of 2 is a
/// rounding of 2, no error. Heidenhain's `RND` too large stays an error (tests/it/derived.rs).
#[test]
fn siemens_rounding_too_large_for_its_move_is_reduced() {
    let program = "G17 G90 G1 X0 Y0 F500\nG1 X2 RND=5\nG1 Y20\nM30\n";
    assert_eq!(errors("siemens", program), Vec::<String>::new());
    let moves = moves("siemens", program);
    assert!(moves.contains(&"ARC_FEED(2.0000, 2.0000, 0.0000, 2.0000, 1, 0.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{moves:?}");
}

/// Sweep 16 (g011): `CYCLE62("PROG",3,"START","END")` names a contour by labels in another
/// program (SinuTrain's "labels in a subprogram"), found as a called program is: beside the
/// file. Labels that are not in it stay an error, as a program that is nowhere.
#[test]
fn siemens_contour_labels_in_a_called_program_are_found() {
    struct Beside;
    impl ncplan::interp::ProgramSource for Beside {
        fn load(&self, name: &str) -> Option<String> {
            name.eq_ignore_ascii_case("SHAFT")
                .then(|| "; contour\nN100 E_LAB_A_S:\nG18 G90 DIAM90\nG0 Z0 X0\nG1 X30\nZ-20\nX40\nE_LAB_E_S:\nM17\n".to_owned())
        }
    }
    let run = |main: &str| {
        let d = ncplan::dialect::Registry::shipped().get("siemens").unwrap();
        let mut out = Vec::new();
        let diags = ncplan::interp::run(main, &d, &Profile::default(), &Beside, &mut out);
        diags.into_iter().filter(|d| d.is_error()).map(|d| d.message).collect::<Vec<_>>()
    };
    let main = "G18 G90 G95\nT1 D1\nG96 S200 LIMS=3000 M4\nCYCLE62(\"SHAFT\",3,\"E_LAB_A_S\",\"E_LAB_E_S\")\n\
CYCLE952(\"ROUGH\",,\"\",2101311,0.3,0,0,2,0.1,0.1,0.3,0.3,0.1,0,1,0,0,,,,,2,2,,,0,1,,11111000,12,1100110,1,0)\nG0 X100 Z100\nM30\n";
    assert_eq!(run(main), Vec::<String>::new());
    assert!(!run(&main.replace("E_LAB_E_S", "E_LAB_E_T")).is_empty());
    assert!(!run(&main.replace("\"SHAFT\"", "\"ELSEWHERE\"")).is_empty());
}

/// Review 17a: a LinuxCNC main program that opens with a definition (subroutines first, its
/// own blocks after them) and closes it with another name's `endsub` is no subroutine file:
/// rs274 -g reads it as a main program, looks past `o<b> endsub` for the `endsub` of `o<a>`
/// and stops ("File ended with no percent sign or program end"), running nothing. It stays an
/// error, with no move. The same text in the subroutine's own file (`a.ngc`, which
/// `o<a> call` opens; or checked `--as called`) is a called file: a call returns at that
/// `endsub` (rs274 -g on a caller), so a warning says the blocks after it never run, and none
/// is run. A file where nothing but `M2` follows that `endsub` is a subroutine file whatever
/// its name.
#[test]
fn linuxcnc_a_main_program_opening_with_a_definition_needs_its_own_endsub() {
    let main = "o<a> sub\nG0 X1\no<b> endsub\nG0 X5\no<a> call\nM2\n";
    let (moves, diags) = crate::moves_and_findings("linuxcnc", main, &Profile::default());
    assert!(diags.iter().any(|d| d.is_error() && d.code.as_str() == "flow::missing-label"), "{diags:?}");
    assert!(!diags.iter().any(|d| d.code.as_str() == "flow::foreign-end-label"), "{diags:?}");
    assert_eq!(moves, Vec::<String>::new());
    let named = |name: &str| Profile { file_name: Some(name.to_owned()), ..Profile::default() };
    let (moves, diags) = crate::moves_and_findings("linuxcnc", main, &named("main.ngc"));
    assert!(diags.iter().any(|d| d.is_error()), "{diags:?}");
    assert_eq!(moves, Vec::<String>::new());
    // Its own file: a called file, whose blocks after the `endsub` never run.
    for profile in [named("a.ngc"), named("A.NGC"), Profile { role: ncplan::interp::ProgramRole::Called, ..Profile::default() }] {
        let (moves, diags) = crate::moves_and_findings("linuxcnc", main, &profile);
        assert!(!diags.iter().any(|d| d.is_error()), "{diags:?}");
        let warning = diags.iter().find(|d| d.code.as_str() == "flow::foreign-end-label").expect("the warning");
        assert!(warning.message.contains("never run"), "{}", warning.message);
        assert_eq!(moves, Vec::<String>::new());
    }
    // Nothing but comments and a program end after it: a subroutine file by its form.
    let sub_file = "o<a> sub\nG0 X1\no<b> endsub\n(end)\nM2\n";
    assert_eq!(errors("linuxcnc", sub_file), Vec::<String>::new());
    assert!(findings("linuxcnc", sub_file).iter().any(|c| c == "flow::foreign-end-label"));
    assert!(!errors("linuxcnc", &sub_file.replace("M2", "G0 X5\nM2")).is_empty());
}

/// Review 17a: a definition whose own `endsub` comes after an `endsub` of another name returns
/// at that one when called (rs274 -g: a caller of `o<a2> sub`, `G0 X1`, `o<b> endsub`, `G0 X7`,
/// `o<a2> endsub` moves to X1 only, in the subroutine's file or in the caller's), so the blocks
/// between never run: a warning says so, in a subroutine file and in the flow of a program.
#[test]
fn linuxcnc_an_endsub_of_another_name_before_the_own_one_ends_the_call() {
    let file = "o<a2> sub\nG0 X1\no<b> endsub\nG0 X7\no<a2> endsub\nM2\n";
    assert_eq!(errors("linuxcnc", file), Vec::<String>::new());
    let (_, diags) = crate::moves_and_findings("linuxcnc", file, &Profile::default());
    let warning = diags.iter().find(|d| d.code.as_str() == "flow::foreign-end-label").expect("the warning");
    assert!(warning.message.contains("lines 4 to 4") && warning.message.contains("never run"), "{}", warning.message);
    let in_flow = "G0 X9\no<a> sub\nG0 X1\no<b> endsub\nG0 X7\no<a> endsub\no<a> call\nM2\n";
    let (moves, diags) = crate::moves_and_findings("linuxcnc", in_flow, &Profile::default());
    assert!(!diags.iter().any(|d| d.is_error()), "{diags:?}");
    assert!(diags.iter().any(|d| d.code.as_str() == "flow::foreign-end-label"), "{diags:?}");
    assert_eq!(moves.len(), 2, "X9 and X1, never X7: {moves:?}");
    assert!(moves[1].starts_with("STRAIGHT_TRAVERSE(1.0000,"), "{moves:?}");
}

/// Review 17a: `IF #100 == 1 N10` is no IF alone: a block number follows the condition (the
/// block keeps it apart from its words), so CNC12's lookahead-stop reading does not take it;
/// an IF with only a comment after its condition still is one.
#[test]
fn centroid_if_alone_has_nothing_but_a_comment_after_its_condition() {
    let alone = [
        "G90 F10\nIF #100 == 1 ;\nG1 X1\nM30\n",
        "G90 F10\nIF #100 == 1 (wait)\nG1 X1\nM30\n",
        "G90 F10\nIF #100 == 1 ; N10\nG1 X1\nM30\n",
    ];
    for program in alone {
        assert_eq!(errors("centroid", program), Vec::<String>::new(), "{program}");
        assert_eq!(xs("centroid", program), vec!["1.0000"], "{program}");
    }
    let numbered = "G90 F10\nIF #100 == 1 N10\nG1 X1\nM30\n";
    assert!(!errors("centroid", numbered).is_empty(), "{:?}", findings("centroid", numbered));
}

/// Modal rounding (`RNDM`) is inserted only between two straight feeds in the working plane:
/// the 840D rounds "all following contour corners" and inserts nothing, with no alarm, where
/// the path leaves the plane (an infeed in Z) or a rapid follows (840D sl programming manual,
/// fundamentals, "Chamfer, rounding"). A block with `RNDM=` alone has no corner of its own.
/// Review17c: these gave three `interp::bad-arc` errors. A rounding written on one corner
/// (`RND=`) that cannot be made stays the error it is.
#[test]
fn siemens_modal_rounding_is_left_out_where_the_path_leaves_the_plane() {
    let program = "G17 G90 G94 F100\nG0 X0 Y0 Z5\nG1 Z-1\nRNDM=2\nG1 X20\nY20\nG0 Z10\nX50 Y50\nM30\n";
    assert_eq!(errors("siemens", program), Vec::<String>::new());
    let rounded = moves("siemens", program);
    // The one corner in the plane, X20 Y0, is rounded; the infeed and the retract are as written.
    assert_eq!(rounded.iter().filter(|m| m.starts_with("ARC_FEED")).count(), 1, "{rounded:?}");
    assert!(rounded.contains(&"STRAIGHT_FEED(18.0000, 0.0000, -1.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{rounded:?}");
    assert!(rounded.contains(&"STRAIGHT_FEED(20.0000, 20.0000, -1.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{rounded:?}");
    assert!(rounded.contains(&"STRAIGHT_TRAVERSE(20.0000, 20.0000, 10.0000, 0.0000, 0.0000, 0.0000)".to_owned()), "{rounded:?}");
    // RNDM=0 before the retract: nothing left to round, nothing said.
    let ended = program.replace("G0 Z10", "RNDM=0\nG0 Z10");
    assert_eq!(errors("siemens", &ended), Vec::<String>::new());
    // A rounding of its own on a corner with an infeed beside it is still refused.
    let own = "G17 G90 G94 F100\nG0 X0 Y0 Z5\nG1 Z-1 RND=2\nG1 X20\nM30\n";
    assert!(errors("siemens", own).iter().any(|e| e.starts_with("interp::bad-arc")), "{:?}", errors("siemens", own));
}

/// The analysis follows the main spindle (spindle 1; `SETMS` is kept as intent) where a block
/// numbers several, in whatever order they are written; the other's words are kept as intent
/// (840D sl programming manual, fundamentals: `S<n>=`, `M<n>=` address spindle n). Review17c:
/// `S2=500 M2=3 S1=1000 M1=4` followed spindle 2 at 500 and dropped the main spindle.
#[test]
fn siemens_the_main_spindle_is_followed_wherever_the_block_writes_it() {
    let program = "G18 G90 G95\nT1 D1\nS2=500 M2=3 S1=1000 M1=4\nG0 X20 Z2\nG1 Z-20 F0.2\nM30\n";
    assert_eq!(errors("siemens", program), Vec::<String>::new());
    let (_, diags) = crate::moves_and_findings("siemens", program, &Profile::default());
    for kept in ["`S2=500`", "`M2=3`"] {
        assert!(diags.iter().any(|d| d.code.as_str() == "syntax::unmodelled" && d.message.contains(kept)), "{kept}: {diags:?}");
    }
    let d = ncplan::dialect::Registry::shipped().get("siemens").unwrap();
    let mut out = Vec::new();
    ncplan::interp::interpret(program, &d, &Profile::default(), &mut out);
    use ncplan::canon::CanonOp;
    assert!(out.iter().any(|c| c.op == CanonOp::SetSpindleSpeed(1000.0)), "{out:?}");
    assert!(out.iter().any(|c| c.op == CanonOp::StartSpindleCounterclockwise), "{out:?}");
    assert!(!out.iter().any(|c| c.op == CanonOp::SetSpindleSpeed(500.0)), "{out:?}");
    assert!(!out.iter().any(|c| matches!(c.op, CanonOp::Spindle(_))), "the main spindle throughout: {out:?}");
}

/// Kept addresses of one role (`DISR=`, `DISCL=`) are told apart by name, and each is compared
/// with every earlier one of the block, not only the last: `DISR=1 DISCL=2 DISR=3` writes DISR
/// twice, which the control rejects. Review17c: no finding.
#[test]
fn siemens_a_kept_address_written_twice_apart_is_a_duplicate() {
    let errs = errors("siemens", "G17 G90 G94 F100\nG0 X0 Y0\nG1 X10 DISR=1 DISCL=2 DISR=3\nM30\n");
    assert!(errs.iter().any(|e| e.starts_with("syntax::duplicate-word") && e.contains("DISR")), "{errs:?}");
    assert_eq!(errors("siemens", "G17 G90 G94 F100\nG0 X0 Y0\nG1 X10 DISR=1 DISCL=2 FAD=3\nM30\n"), Vec::<String>::new());
}

/// The 840D's manual makes a rounding too large for its move smaller; no manual of the older
/// SINUMERIK 810/820/840C at hand says so, so there it stays refused, as it was before the
/// 840D's rule (review17c).
#[test]
fn sinumerik_810_still_refuses_a_rounding_too_large_for_its_move() {
    let program = "G17 G90 G94 F100\nG0 X0 Y0\nG1 X20 RND=30\nY1\nM30\n";
    assert!(errors("siemens_810", program).iter().any(|e| e.starts_with("interp::bad-arc")), "{:?}", errors("siemens_810", program));
    assert_eq!(errors("siemens", program), Vec::<String>::new());
}

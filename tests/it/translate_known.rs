//! Safe output: a translation never writes a position the program does not know. The program
//! starts wherever the machine was; a reference return (`G28`, `G30`) or a move in machine
//! coordinates (`G53`) leaves its axes where only the machine knows; a block that states an
//! axis absolutely makes it known again. So a translation
//! - never restates a homed axis at the 0 the analysis gives it (`G53 G0 Z0.` / `T1 M6` /
//!   `G0 X-20. Y-8.` must not become `G0 X-20. Y-8. Z0.` before the `G43 Z15. H1`);
//! - writes every word of the first move that states an axis, even one equal to 0
//!   (`G0 G54 X10. Y0. Z0.` keeps its `Y0. Z0.`: left out, the tool plunges wherever the tool
//!   change left it);
//! - refuses (`post::unknown-start`) a move that goes incrementally from a position the
//!   program does not know (`G91` first, lathe `U`/`W`, Heidenhain `IX`), never writing it as
//!   an absolute position counted from an assumed 0;
//! - and the proof (`pipeline::check_translation`) refuses a text that does any of these.

use ncplan::diag::Diagnostic;
use ncplan::interp::Profile;
use ncplan::pipeline::{self, TranslateOptions};

use crate::translate::{MILLS, dialect};

/// The lathe targets (as `translate_lathe`).
const LATHES: [&str; 9] =
    ["fanuc_lathe", "fanuc_lathe_b", "haas_lathe", "mazak_lathe", "mitsubishi_lathe", "okuma_lathe", "fagor_lathe", "siemens", "linuxcnc"];

/// `text` from `from` to `to` as `ncplan translate` writes it: the text and the findings, the
/// proof's among them where the writer gave no error.
pub(crate) fn translate(text: &str, from: &str, to: &str) -> (String, Vec<Diagnostic>) {
    let (f, t) = (dialect(from), dialect(to));
    let mut out = Vec::new();
    let opts = TranslateOptions { follow_source_units: true, ..TranslateOptions::for_program("O1000") };
    let mut diags = pipeline::translate(text, &f, &t, &Profile::default(), opts, |b| out.extend_from_slice(b));
    let written = String::from_utf8(out).expect("UTF-8");
    if !diags.iter().any(Diagnostic::is_error) {
        diags.extend(check(text, from, &written, to));
    }
    (written, diags)
}

/// The proof of `written` (in `to`) against `text` (in `from`).
fn check(text: &str, from: &str, written: &str, to: &str) -> Vec<Diagnostic> {
    pipeline::check_translation(text.into(), &dialect(from), written, &dialect(to), &Profile::default(), &[])
}

pub(crate) fn errors(diags: &[Diagnostic]) -> Vec<&Diagnostic> {
    diags.iter().filter(|d| d.is_error()).collect()
}

/// The words of a line, without a block number.
fn words(line: &str) -> Vec<&str> {
    line.split_whitespace().filter(|w| !w.starts_with('N')).collect()
}

/// Whether `line` is a block that names axis `axis` (`Z`, or Heidenhain's `Z+`/`Z-`).
fn names_axis(line: &str, axis: char) -> bool {
    words(line).iter().any(|w| w.starts_with(axis) && w[1..].starts_with(|c: char| c.is_ascii_digit() || c == '-' || c == '+' || c == '.'))
}

#[test]
fn a_homed_axis_is_not_restated_at_zero_before_the_length_offset() {
    let path = crate::root().join("tests/programs/shops/haas/fusion_ngc_pocket.nc");
    let src = std::fs::read_to_string(path).unwrap();
    for to in ["haas", "fanuc", "linuxcnc", "mitsubishi", "mazak"] {
        let (out, diags) = translate(&src, "haas", to);
        assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{to}:\n{out}");
        // From the tool change to the length offset's block, no move names Z.
        let lines: Vec<&str> = out.lines().collect();
        let tc = lines.iter().position(|l| l.contains("T1") && l.contains("M6")).expect("the tool change");
        let g43 = tc + lines[tc..].iter().position(|l| l.contains("G43")).expect("the length offset");
        for l in &lines[tc..g43] {
            assert!(!names_axis(l, 'Z'), "{to}: {l:?} states Z before the length offset:\n{out}");
        }
        assert!(names_axis(lines[g43], 'Z'), "{to}: the length offset's own Z is kept: {:?}", lines[g43]);
    }
    // The old wrong output, planted: the proof refuses it.
    let (good, _) = translate(&src, "haas", "haas");
    assert!(good.contains("G0 X-20. Y-8.\n"), "{good}");
    let planted = good.replacen("G0 X-20. Y-8.\n", "G0 X-20. Y-8. Z0.\n", 1);
    let refused = check(&src, "haas", &planted, "haas");
    assert_eq!(refused.len(), 1, "{refused:?}");
    assert_eq!(refused[0].code.as_str(), "post::motion-differs");
    assert!(refused[0].message.contains("the translation states Z where the program does not know the position"), "{}", refused[0].message);
}

#[test]
fn lathe_reference_returns_one_axis_at_a_time_get_no_rapid_between() {
    let src = "O0001\nG21 G40 G99\nG28 U0.\nG28 W0.\nT0101\nG97 S1000 M3\nG0 X50. Z2.\nG1 Z-10. F0.2\nG0 X60.\nG28 U0.\nG28 W0.\nM30\n";
    let mut written = 0;
    for to in LATHES {
        let (out, diags) = translate(src, "fanuc_lathe", to);
        if !errors(&diags).is_empty() {
            // Refused (a target without a reference return): nothing is given out.
            continue;
        }
        written += 1;
        // Every block that names X or Z is a reference return or the program's own moves.
        for l in out.lines() {
            let own = ["X50", "Z2", "Z-10", "X60", "X100", "X120"].iter().any(|w| l.contains(w));
            let home = l.contains("G28") || l.contains("G53") || l.contains("M91") || l.contains("SUPA") || l.contains("G74");
            if names_axis(l, 'X') || names_axis(l, 'Z') {
                assert!(own || home, "{to}: {l:?} moves a homed axis to a made-up position:\n{out}");
            }
        }
    }
    assert!(written >= 7, "the lathe targets with a reference return write it: {written}");
    // The old wrong output: a rapid to the centreline between the returns.
    let (good, _) = translate(src, "fanuc_lathe", "haas_lathe");
    let planted = good.replacen("G28 U0.\nG28 W0.\n", "G28 U0.\nG0 X0.\nG28 W0.\n", 1);
    assert_ne!(planted, good);
    let refused = check(src, "fanuc_lathe", &planted, "haas_lathe");
    assert!(refused.iter().any(|d| d.code.as_str() == "post::motion-differs"), "{refused:?}");
}

#[test]
fn mill_reference_returns_in_turn_get_no_rapid_to_zero_between() {
    let src = "O1000\nG21 G17 G90 G54\nT1 M6\nS1000 M3\nG0 X10. Y20.\nG43 Z5. H1\nG1 Z-1. F100.\nG90 G28 Z5.\nG91 G28 X0. Y0.\nG90\nM30\n";
    for to in MILLS {
        let (out, diags) = translate(src, "fanuc", to);
        if !errors(&diags).is_empty() {
            continue;
        }
        let homes: Vec<usize> = out.lines().enumerate().filter(|(_, l)| l.contains("G28")).map(|(i, _)| i).collect();
        assert_eq!(homes.len(), 2, "{to}:\n{out}");
        for l in out.lines().skip(homes[0] + 1).take(homes[1] - homes[0] - 1) {
            assert!(!names_axis(l, 'Z'), "{to}: {l:?} between the returns:\n{out}");
        }
    }
}

#[test]
fn the_first_move_keeps_its_words_equal_to_zero() {
    let src = "O1000\nG21 G17 G90\nT1 M6\nS1000 M3\nG0 G54 X10. Y0. Z0.\nG1 X20. F100.\nM30\n";
    for to in MILLS {
        let (out, diags) = translate(src, "fanuc", to);
        assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{to}:\n{out}");
        let first = out.lines().find(|l| names_axis(l, 'X')).expect("the first move");
        assert!(names_axis(first, 'Y') && names_axis(first, 'Z'), "{to}: {first:?} lost Y0 or Z0:\n{out}");
    }
    // The old wrong output, planted: the proof refuses it.
    let (good, _) = translate(src, "fanuc", "fanuc");
    let planted = good.replacen("X10. Y0. Z0.", "X10.", 1);
    assert_ne!(planted, good);
    let refused = check(src, "fanuc", &planted, "fanuc");
    assert_eq!(refused.len(), 1, "{refused:?}");
    assert!(
        refused[0].message.contains("the program states Y Z, which the translation leaves where the machine happens to be"),
        "{}",
        refused[0].message
    );
}

/// The refusals `post::unknown-start` of a translation, as `line:col` of the source.
fn unknown_start(src: &str, from: &str, to: &str) -> Vec<(usize, usize)> {
    let (_, diags) = translate(src, from, to);
    diags
        .iter()
        .filter(|d| d.code.as_str() == "post::unknown-start")
        .map(|d| {
            let before = &src[..d.range.start as usize];
            (before.matches('\n').count() + 1, before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1)
        })
        .collect()
}

#[test]
fn an_incremental_move_from_an_unknown_start_is_refused_never_counted_from_zero() {
    // G91 before any absolute word.
    let mill = "O1000\nG21 G17\nG91 G0 X10. Y5.\nG1 X5. F100.\nG90 G0 X0. Y0. Z10.\nM30\n";
    for to in MILLS {
        assert_eq!(unknown_start(mill, "fanuc", to), vec![(3, 1)], "{to}");
    }
    // After a reference return, the homed axis again.
    let homed = "O1000\nG21 G17 G90\nG0 X0. Y0. Z10.\nG91 G28 Z0.\nG0 Z-5.\nG90\nM30\n";
    assert_eq!(unknown_start(homed, "fanuc", "haas"), vec![(5, 1)]);
    // Incremental from a known start is a move like any other.
    let known = "O1000\nG21 G17 G90\nG0 X0. Y0. Z10.\nG91 G1 X10. F100.\nG90\nM30\n";
    for to in MILLS {
        let (out, diags) = translate(known, "fanuc", to);
        assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{to}:\n{out}");
    }
    // A lathe's U and W before any X or Z.
    let lathe = "O0001\nG21 G99\nT0101\nG97 S1000 M3\nG0 U-2. W-1.\nG0 X50. Z2.\nM30\n";
    for to in ["fanuc_lathe", "haas_lathe", "linuxcnc"] {
        assert_eq!(unknown_start(lathe, "fanuc_lathe", to), vec![(5, 1)], "{to}");
    }
    // Heidenhain's IX.
    let tnc = "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000\n2 L IX+10 R0 FMAX\n3 L X+0 Y+0 Z+10 R0 FMAX\n4 END PGM T MM\n";
    assert_eq!(unknown_start(tnc, "heidenhain", "fanuc"), vec![(3, 1)]);
    // The old wrong output (absolute positions from an assumed 0), planted: the proof refuses it.
    let planted = "%\nO1000\nG17 G40 G80 G90\nG21\nG0 X10. Y5.\nG1 X15. F100.\nG0 X0. Y0. Z10.\nM30\n%\n";
    let refused = check(mill, "fanuc", planted, "fanuc");
    assert_eq!(refused.len(), 1, "{refused:?}");
    assert!(
        refused[0].message.contains("the translation states X Y where the program does not know the position"),
        "{}",
        refused[0].message
    );
}

/// The source lines `post::unknown-start` refuses a translation at.
fn refused_lines(src: &str, from: &str, to: &str) -> Vec<usize> {
    let mut lines: Vec<usize> = unknown_start(src, from, to).into_iter().map(|(l, _)| l).collect();
    lines.dedup();
    lines
}

/// The written block after the first one containing `after` that names `axis`, and the
/// blocks between.
fn block_after<'a>(out: &'a str, after: &str) -> Vec<&'a str> {
    let lines: Vec<&str> = out.lines().collect();
    let at = lines.iter().position(|l| l.contains(after)).unwrap_or_else(|| panic!("no {after:?} in:\n{out}"));
    lines[at..].to_vec()
}

#[test]
fn a_coordinate_set_where_the_position_is_unknown_is_refused() {
    // G92 before any absolute word: rs274 sets the shift and moves nothing; written in the
    // work offset's frame it would be a move counted from an assumed 0.
    let g92 = "O1000\nG21 G17\nG90 G92 X10. Y10.\nG0 X10. Y10.\nG1 X20. F100.\nM30\n";
    for to in MILLS {
        assert_eq!(refused_lines(g92, "fanuc", to), vec![3], "{to}");
    }
    // After a reference return of the axis set.
    let homed = "O1000\nG28 G91 Z0.\nG90 G54 G0 X0. Y0.\nG92 Z100.\nG1 X10. F100.\nM30\n";
    assert_eq!(refused_lines(homed, "fanuc", "haas"), vec![4]);
    // A lathe's G50 X.. Z.. before any position is known.
    let lathe = "O2002\nG50 X200. Z100.\nT0101\nG0 X50. Z2.\nG1 Z-20. F0.2\nM30\n";
    assert_eq!(refused_lines(lathe, "fanuc_lathe", "haas_lathe"), vec![2]);
    // Where every axis set is known, the shift is applied to the positions written.
    let known = "O1000\nG21 G17 G90 G54\nG0 X0. Y0. Z50.\nG92 X10. Y10.\nG0 X20. Y10.\nM30\n";
    for to in MILLS {
        assert_eq!(refused_lines(known, "fanuc", to), Vec::<usize>::new(), "{to}");
    }
}

#[test]
fn a_work_offset_change_makes_every_axis_unknown_in_the_new_frame() {
    // G55's offsets are the control's: the rapid to X0 Y0 in it is a move, written though
    // the words equal the last written ones.
    let src = "O1001\nG21 G17\nG90 G54 G0 X0. Y0. Z50.\nG55\nG0 X0. Y0.\nG1 Z-1. F100.\nM30\n";
    for to in ["haas", "fanuc", "linuxcnc", "mitsubishi"] {
        let (out, diags) = translate(src, "fanuc", to);
        assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{to}:\n{out}");
        let after = block_after(&out, "G55");
        let xy = after.iter().find(|l| names_axis(l, 'X')).unwrap_or_else(|| panic!("{to}: the rapid in G55 is lost:\n{out}"));
        assert!(names_axis(xy, 'Y') && !l_has(xy, "G1"), "{to}: {xy:?}:\n{out}");
        assert!(after.iter().any(|l| l.contains("Z-1")), "{to}:\n{out}");
    }
    // An incremental move in the new frame before an absolute one is refused.
    let inc = "O1001\nG21 G17\nG90 G54 G0 X0. Y0. Z50.\nG55\nG91 G0 X10.\nG90 G0 X0. Y0. Z50.\nM30\n";
    assert_eq!(refused_lines(inc, "fanuc", "haas"), vec![5]);
    // Known again from the absolute words: an incremental move after them is a move.
    let after = "O1001\nG21 G17\nG90 G54 G0 X0. Y0. Z50.\nG55\nG0 X0. Y0. Z50.\nG91 G1 X10. F100.\nG90\nM30\n";
    assert_eq!(refused_lines(after, "fanuc", "haas"), Vec::<usize>::new());
}

fn l_has(line: &str, word: &str) -> bool {
    words(line).contains(&word)
}

#[test]
fn a_tool_or_length_offset_change_makes_z_unknown() {
    let src = "O1002\nG21 G17\nT1 M6\nG90 G54 G0 X0. Y0.\nG43 H1 Z10.\nG1 Z5. F100.\nG0 Z10.\nT2 M6\nG43 H2 Z10.\nG1 X10.\nM30\n";
    for to in ["haas", "fanuc", "linuxcnc", "mitsubishi"] {
        let (out, diags) = translate(src, "fanuc", to);
        assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{to}:\n{out}");
        let after = block_after(&out, "H2");
        assert!(names_axis(after[0], 'Z'), "{to}: the second tool's Z10. is lost: {:?}:\n{out}", after[0]);
    }
    // An incremental Z after the change, before an absolute one, is refused.
    let inc = "O1002\nG21 G17\nT1 M6\nG90 G54 G0 X0. Y0. Z10.\nT2 M6\nG91 G0 Z-5.\nG90 G0 Z10.\nM30\n";
    assert_eq!(refused_lines(inc, "fanuc", "haas"), vec![6]);
}

#[test]
fn a_frame_change_without_motion_is_no_incremental_move() {
    // The active offset's values set before any move: X5. Y0. then G43 Z50. are written.
    let g10 = "O1010\nG10 L2 P1 X-100. Y-100. Z-500.\nT1 M6\nG0 G54 X5. Y0.\nG43 Z50. H1\nG1 Z-1. F100.\nM30\n";
    let (out, diags) = translate(g10, "haas", "fanuc");
    assert_eq!(refused_lines(g10, "haas", "fanuc"), Vec::<usize>::new(), "{diags:?}\n{out}");
    assert!(out.lines().any(|l| l.contains("X5.") && l.contains("Y0.")), "{out}");
    assert!(out.lines().any(|l| l.contains("G43") && l.contains("Z50.")), "{out}");
    // G55 after a reference return: the returned axes stay unknown, no move of them.
    let g28 = "O1012\nG10 L2 P2 X50. Y0. Z0.\nG90 G54 G0 X0. Y0. Z50.\nG91 G28 X0. Y0.\nG90 G55\nG0 Z20.\nM30\n";
    assert_eq!(refused_lines(g28, "fanuc", "haas"), Vec::<usize>::new());
}

/// The lines of `out` after its change to tool 1 (`T1 M6`).
fn after_tool_change(out: &str) -> Vec<&str> {
    let at = out.lines().position(|l| words(l).iter().any(|w| *w == "T1" || w.starts_with("T1M"))).expect("a tool change");
    out.lines().skip(at + 1).collect()
}

/// A drilling cycle called right after a tool change positions the tool axis itself: 840D
/// CYCLE81 goes at rapid to the reference plane brought forward by the safety distance
/// (RFP+SDIS, absolute), Heidenhain cycle 200 to the set-up clearance above the surface
/// (Q203+Q200). The translation states no Z before it (the tool change left it where only the
/// machine knows), writes the target's cycle where that states its planes the same way, the
/// cycle's own moves where it does not, and the proof agrees.
#[test]
fn a_defined_cycle_after_a_tool_change_makes_the_tool_axis_known_at_its_r_level() {
    let sinumerik = "N10 G0 G90 G54 X0 Y0 Z100\nN20 T1 M6\nN30 G0 X10 Y10 S1000 F100 M3\nN40 MCALL CYCLE81(50,0,2,-10)\nN50 X10 Y10\nN60 X30 Y10\nN70 MCALL\nN80 G0 Z100\nN90 M30\n";
    for to in MILLS {
        let (out, diags) = translate(sinumerik, "siemens", to);
        // No error: the proof agrees, the known axes move by move among it (a Z from
        // before the tool change restated would be a difference).
        assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{to}:\n{out}");
    }
    // Heidenhain states the same planes: cycle 200 from Q203 with Q204 above it.
    let (out, _) = translate(sinumerik, "siemens", "heidenhain");
    assert!(out.contains("Q203=+0") && out.contains("Q204=+50") && out.contains("Q200=+2"), "{out}");
    // A G8x target returns to its initial level or R, not to RTP: the first hole is its moves,
    // the tool axis written from R on.
    let (out, _) = translate(sinumerik, "siemens", "fanuc");
    let after = after_tool_change(&out);
    let first_z = after.iter().find(|l| names_axis(l, 'Z')).unwrap_or(&"");
    assert!(words(first_z).contains(&"Z2."), "{first_z}\n{out}");

    let tnc = "0 BEGIN PGM T MM\n1 L X+0 Y+0 Z+100 R0 FMAX\n2 TOOL CALL 1 Z S1000\n3 CYCL DEF 200 DRILLING ~\n  Q200=+2 ;SET-UP CLEARANCE ~\n  Q201=-10 ;DEPTH ~\n  Q206=+150 ;FEED RATE FOR PLNGNG ~\n  Q202=+10 ;PLUNGING DEPTH ~\n  Q210=+0 ;DWELL TIME AT TOP ~\n  Q203=+0 ;SURFACE COORDINATE ~\n  Q204=+50 ;2ND SET-UP CLEARANCE ~\n  Q211=+0 ;DWELL TIME AT DEPTH\n4 L X+10 Y+10 R0 FMAX M3 M99\n5 L X+30 FMAX M99\n6 L Z+100 FMAX\n7 END PGM T MM\n";
    for to in MILLS {
        let (out, diags) = translate(tnc, "heidenhain", to);
        assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{to}:\n{out}");
    }
    let (out, _) = translate(tnc, "heidenhain", "siemens");
    assert!(out.contains("MCALL CYCLE81(50.,0.,2.,-10.)") || out.contains("CYCLE81(50"), "{out}");
    // The surface stated relative to where the tool stands (`CYCL CALL POS` with an
    // incremental tool-axis word) is known nowhere: refused, never counted from an assumed 0.
    let relative = tnc.replace("4 L X+10 Y+10 R0 FMAX M3 M99", "4 CYCL CALL POS X+10 Y+10 IZ+0 FMAX M3");
    assert_ne!(refused_lines(&relative, "heidenhain", "fanuc"), Vec::<usize>::new(), "{relative}");
}

/// A G8x cycle from a Z the program does not know (after a tool change): its move to R is
/// absolute under G90, so Z is known from there; under G98 it returns to the unknown initial
/// level, so Z is unknown again. The moves one by one cannot state that return, and a G8x
/// target's cycle from an unknown level may not move as the source's: refused, never a
/// return to a number counted from before the tool change.
#[test]
fn a_g98_cycle_from_an_unknown_z_is_refused() {
    let src = "O1000\nG21 G17 G90\nG0 G54 X0. Y0. Z50.\nT1 M6\nG0 X10. Y10. S1000 M3\nG98 G81 X10. Y10. Z-10. R2. F100.\nX30.\nG80\nG0 Z100.\nM30\n";
    // Controls differ from an unknown level (rs274 rises to R first where the tool stands
    // below it and returns to the higher of the two; Fanuc moves to the hole at that level):
    // not written as the target's G8x cycle; its moves cannot state the G98 return.
    for to in ["fanuc", "haas", "mitsubishi", "mazak", "okuma", "linuxcnc", "siemens", "heidenhain"] {
        assert_eq!(refused_lines(src, "fanuc", to), vec![6], "{to}");
    }
    // G99: back to R, known from there: the first hole as its moves, then a G8x target writes G99.
    let g99 = src.replace("G98 G81", "G99 G81");
    let (out, diags) = translate(&g99, "fanuc", "linuxcnc");
    assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{out}");
    assert!(out.lines().any(|l| words(l).contains(&"G99") && l.contains("G81")), "{out}");
    // In G91 R counts from the unknown initial level: known nowhere, refused.
    let g91 = src.replace("G98 G81 X10. Y10. Z-10. R2. F100.\nX30.", "G91 G98 G81 X0. Y0. Z-12. R-48. F100.\nX20.\nG90");
    assert_eq!(refused_lines(&g91, "fanuc", "haas"), vec![6]);
}

/// Heidenhain `M140 MB MAX` retracts the tool axis to its travel limit: a move in the machine's
/// frame (as a reference return), after which the tool axis is unknown in the work frame. A
/// target that has it writes it; one that has not refuses it as unwritable, never drops it.
/// `M140 MB n` stays unmodelled and refused (`a_code_whose_motion_is_unknown_refuses_the_translation`).
#[test]
fn m140_mb_max_is_a_retract_to_the_travel_limit() {
    let tnc = "0 BEGIN PGM H1 MM\n1 TOOL CALL 1 Z S2000\n2 L X+10 Y+10 R0 FMAX M3\n3 L Z+100 R0 FMAX\n4 L Z-5 R0 F100\n5 M140 MB MAX\n6 L X+50 Y+50 R0 FMAX\n7 L Z+10 R0 FMAX\n8 END PGM H1 MM\n";
    let (out, diags) = translate(tnc, "heidenhain", "heidenhain");
    assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{out}");
    let after = block_after(&out, "M140 MB MAX");
    // The move after it states X Y, not the Z it left (unknown): Z is written only where
    // the program states it again.
    assert!(!names_axis(after[1], 'Z'), "{out}");
    assert!(words(after[2]).contains(&"Z+10"), "{out}");
    for to in ["fanuc", "siemens", "linuxcnc"] {
        let (out, diags) = translate(tnc, "heidenhain", to);
        let e = errors(&diags);
        assert!(e.iter().any(|d| d.code.as_str() == "post::unwritable" && d.message.contains("travel limit")), "{to}: {e:?}\n{out}");
        assert!(!e.iter().any(|d| d.code.as_str() == "post::motion-unknown"), "{to}: {e:?}");
    }
}

/// The Heidenhain target's tilted plane turns the rotary axes with no retraction first: a
/// source's tilt (G68.2, CYCLE800 without its retract) makes none.
#[test]
fn the_heidenhain_tilted_plane_adds_no_retract() {
    let src = "O1000\nG21 G17 G90\nT1 M6\nG0 G54 X0. Y0. S1000 M3\nG43 H1 Z50.\nG68.2 X0. Y0. Z0. I0. J30. K0.\nG53.1\nG0 X10. Y10.\nG1 Z-1. F100.\nG0 Z50.\nG69\nM30\n";
    let (out, _) = translate(src, "fanuc", "heidenhain");
    let plane = out.lines().find(|l| l.contains("PLANE SPATIAL")).unwrap_or_else(|| panic!("no PLANE in\n{out}"));
    assert!(plane.contains("TURN FMAX") && !plane.contains("MB"), "{plane}");
}

/// The errors of translating `src` from `from` to `to`: (code, source line), and the text.
fn refusals(src: &str, from: &str, to: &str) -> (Vec<(&'static str, usize)>, Vec<String>, String) {
    let (out, diags) = translate(src, from, to);
    let errs: Vec<&Diagnostic> = errors(&diags);
    let at = errs.iter().map(|d| (d.code.as_str(), src[..d.range.start as usize].matches('\n').count() + 1)).collect();
    (at, errs.iter().map(|d| d.message.clone()).collect(), out)
}

#[test]
fn a_g8x_cycle_from_an_unknown_level_is_refused_never_written_before_its_length_offset() {
    // `G43 H1` alone after the tool change, then a G98 cycle: the old output drilled without
    // the offset (`G43` held back to after `G80`), and the controls differ from an unknown Z.
    let src = "O1000\nG21 G17 G90\nG0 G54 X0. Y0. Z50.\nT1 M6\nG0 X10. Y10. S1000 M3\nG43 H1\nG98 G81 X10. Y10. Z-10. R-5. F100.\nX30.\nG80\nG0 Z100.\nM30\n";
    for to in ["linuxcnc", "haas", "fanuc"] {
        let (at, _, out) = refusals(src, "fanuc", to);
        assert_eq!(at, vec![("post::unknown-start", 7)], "{to}:\n{out}");
    }
    // G99 at the hole's place: the moves from R on, the offset written before them.
    let g99 = src.replace("G98 G81", "G99 G81");
    let (at, _, out) = refusals(&g99, "fanuc", "linuxcnc");
    assert_eq!(at, vec![], "{out}");
    let lines: Vec<&str> = out.lines().collect();
    let g43 = lines.iter().position(|l| l.contains("G43")).expect("G43 written");
    let first_z = lines.iter().position(|l| l.contains("Z-5")).expect("R level written");
    assert!(g43 <= first_z, "{out}");
    // After a reference return: refused for what the cycle does, not as an incremental move.
    let homed = "O1000\nG21 G17 G90\nG0 G54 X0. Y0. Z-5.\nG91 G28 Z0.\nG90\nG0 X10. Y10. S1000 M3\nG98 G81 X10. Y10. Z-10. R2. F100.\nX30.\nG80\nG0 Z100.\nM30\n";
    let (at, msgs, _) = refusals(homed, "fanuc", "linuxcnc");
    assert_eq!(at, vec![("post::unknown-start", 7)]);
    assert!(msgs[0].contains("drilling cycle begins") && !msgs[0].contains("incrementally"), "{}", msgs[0]);
}

#[test]
fn a_swivel_with_a_retract_is_refused_one_without_is_written() {
    let src = "N10 G0 G90 G54 X0 Y0 Z100\nN20 T1 M6\nN25 G0 X0 Y0 Z100 S1000 M3\nN30 CYCLE800(1,\"TC1\",0,57,0,0,0,0,30,0,0,0,0,1,100,1)\nN40 G0 X10 Y10 Z20\nN50 G1 Z-1 F100\nN60 G0 Z20\nN70 CYCLE800()\nN80 M30\n";
    let (at, msgs, _) = refusals(src, "siemens", "heidenhain");
    assert_eq!(at, vec![("post::motion-unknown", 4)]);
    assert!(msgs[0].contains("_FR=1"), "{}", msgs[0]);
    let none = src.replace("CYCLE800(1,", "CYCLE800(0,");
    let (at, _, out) = refusals(&none, "siemens", "heidenhain");
    assert_eq!(at, vec![], "{out}");
    assert!(out.contains("PLANE SPATIAL SPA+0 SPB+30 SPC+0 TURN FMAX"), "{out}");
}

#[test]
fn a_cycle_call_at_a_position_from_an_unknown_level_is_refused() {
    let src = "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000\n2 L X+0 Y+0 R0 FMAX M3\n3 L Z+100 R0 FMAX\n4 L Z-5 R0 F100\n5 M140 MB MAX\n6 CYCL DEF 200 DRILLING ~\n  Q200=+2 ;SET-UP CLEARANCE ~\n  Q201=-10 ;DEPTH ~\n  Q206=+150 ;FEED RATE FOR PLNGNG ~\n  Q202=+10 ;PLUNGING DEPTH ~\n  Q210=+0 ;DWELL TIME AT TOP ~\n  Q203=+0 ;SURFACE COORDINATE ~\n  Q204=+50 ;2ND SET-UP CLEARANCE ~\n  Q211=+0 ;DWELL TIME AT DEPTH\n7 CYCL CALL POS X+10 Y+10 Z+0 FMAX\n8 CYCL CALL POS X+30 Y+10 Z+0 FMAX\n9 L Z+100 FMAX\n10 END PGM T MM\n";
    let (at, msgs, _) = refusals(src, "heidenhain", "heidenhain");
    assert_eq!(at, vec![("post::motion-unknown", 16)], "{msgs:?}");
    // M140 MB MAX is modelled: no `kept as intent` warning.
    let (_, diags) = translate(src, "heidenhain", "heidenhain");
    assert!(!diags.iter().any(|d| d.code.as_str() == "interp::unsupported"), "{diags:?}");
    // From a known level, written.
    let known = src.replace("5 M140 MB MAX", "5 L Z+100 R0 FMAX");
    for to in ["heidenhain", "linuxcnc", "siemens"] {
        let (at, _, out) = refusals(&known, "heidenhain", to);
        assert_eq!(at, vec![], "{to}:\n{out}");
    }
}

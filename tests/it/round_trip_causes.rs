//! The general causes of round trips that came back different (issue 21), one small program
//! each in the style that showed the cause, translated to every other mill dialect and read
//! back (`translate::round_trip`): equal, or explained by the code that says why.

use crate::translate::{MILLS, Source, dialect, round_trip};

/// Every target but the source's own: the verdicts that are not `want`.
fn failures(text: &str, from: &str, want: impl Fn(&str, &str) -> bool) -> Vec<String> {
    let src = Source::read(text.as_bytes(), dialect(from), "cause").expect("the program reads without errors");
    let mut out = Vec::new();
    for to in MILLS.iter().copied().filter(|t| *t != from) {
        let (written, verdict) = round_trip(&src, to);
        if !want(to, &verdict) {
            out.push(format!("{from} → {to}: {verdict}\n{written}"));
        }
    }
    out
}

/// A post's safe start that cancels the length offset (`G49`) before the tool change and no
/// `G43` after it (a LinuxCNC post relying on the tool table's zero lengths): the plan reads
/// "no length offset", and the translation says the cancel too, so the plan read back is not
/// "the tool's own".
#[test]
fn a_length_offset_the_source_cancels_stays_cancelled() {
    let text = "G21 G90 G17\nG40 G49 G80\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\nG1 Y10\nG0 Z5\nM2\n";
    let bad = failures(text, "linuxcnc", |to, v| {
        v == "equal"
            || (["siemens", "heidenhain"].contains(&to)
                && v.starts_with("untranslatable: post::unwritable: the program cuts with the length offset cancelled"))
    });
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// A LinuxCNC arc whose radii at start and end differ by 0.014 mm (LinuxCNC takes up to
/// 0.028 mm): stricter targets get the centre on the chord's bisector, the path moving by
/// less than the difference, and the translation says so (`post::arc-centre`).
#[test]
fn an_arc_whose_radii_differ_moves_its_centre_and_says_so() {
    let text = "G21 G90 G17\nT1 M6\nS1000 M3\nF100\nG0 X0 Y0 Z5\nG1 Z-1\nG2 X50 Y0 I24.986 J0\nG0 Z5\nM2\n";
    let bad = failures(text, "linuxcnc", |_, v| v == "equal" || v.starts_with("rounded: post::arc-centre: "));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    // Heidenhain and Fanuc check the radii to 0.002 mm: the centre moves there.
    let src = Source::read(text.as_bytes(), dialect("linuxcnc"), "cause").unwrap();
    for to in ["heidenhain", "fanuc"] {
        assert!(round_trip(&src, to).1.starts_with("rounded: post::arc-centre: "), "{to}");
    }
}

/// A long arc over a short chord (a CAM's near-straight arc, radius 1274.7 mm over 32.7 mm):
/// the centre written to three decimals and put on the bisector is 0.005 mm from the
/// source's, yet every point of the path is within the resolution. The toolpath is compared
/// by the path, not by the ill-conditioned centre.
#[test]
fn a_long_radius_over_a_short_chord_is_the_same_path() {
    let text = "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X-1.974 Y8.147 Z6.\nG1 Z-1. F1200.\nG2 X-1.346 Y40.813 I1274.739 J-8.173 F3600.\nG1 X-1.246 Y43.543\nG0 Z6.\nM2\n";
    let bad = failures(text, "linuxcnc", |_, v| v == "equal" || v.starts_with("rounded: post::"));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// A small arc (radius 0.125 mm) in a four-decimal program written with three decimals:
/// rounding the end moves its angle by 0.004 rad, a few microns along the path, within the
/// resolution the translation says (`post::rounded`).
#[test]
fn a_small_arc_rounded_to_three_decimals_is_the_same_arc() {
    let text = "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X3.8605 Y1.5828 Z1.\nG1 Z-0.485 F100.\nG3 X3.9761 Y1.5052 I0.1157 J0.0474 F400.\nG1 X10.3461\nG0 Z1.\nM2\n";
    let bad = failures(text, "linuxcnc", |_, v| v == "equal" || v.starts_with("rounded: post::rounded: "));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// A `G92` shift (LinuxCNC) is written into the positions: the machine makes the same moves
/// (the toolpath is equal), the plan read back is in the work offset's frame, and the
/// translation says so (`post::shift-applied`).
#[test]
fn a_g92_shift_is_written_into_the_positions_and_said() {
    let text = "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z25\nG92 Z12.7\nG0 X2 Y0\nG1 Z-1 F100\nG1 X20\nG1 Y10\nG0 Z5\nG92.1\nM2\n";
    let bad = failures(text, "linuxcnc", |_, v| v == "equal" || v.starts_with("restated: post::shift-applied: plan: "));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let src = Source::read(text.as_bytes(), dialect("linuxcnc"), "cause").unwrap();
    assert!(round_trip(&src, "fanuc").1.starts_with("restated: post::shift-applied: "), "{}", round_trip(&src, "fanuc").1);
}

/// A face cleared in passes 0.6251 mm apart, written with four decimals: rounded to three,
/// the width the plan measures between passes comes back 3.126 mm for 3.1255 mm, within the
/// two ends' rounding (`post::rounded`), not an operator's change of the feature.
#[test]
fn a_dimension_between_rounded_passes_is_rounding() {
    let mut text = String::from("G21 G90 G17\nT3 M6\nS1000 M3\nF100\nG0 X4.1011 Y1.7552 Z1\nG1 Z-0.485\n");
    for i in 0..6 {
        let y = 1.7552 + 0.6251 * f64::from(i);
        let (x0, x1) = if i % 2 == 0 { (4.1011, 10.3461) } else { (10.3461, 4.1011) };
        text.push_str(&format!("G1 X{x0:.4} Y{y:.4}\nG1 X{x1:.4}\n"));
    }
    text.push_str("G0 Z1\nM2\n");
    let bad = failures(&text, "linuxcnc", |_, v| v == "equal" || v.starts_with("rounded: post::rounded: "));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let src = Source::read(text.as_bytes(), dialect("linuxcnc"), "cause").unwrap();
    assert!(round_trip(&src, "fanuc").1.starts_with("rounded: post::rounded: "), "{}", round_trip(&src, "fanuc").1);
}

/// The diff measures how far a path moved to the arcs themselves, not to chords of them: a
/// 60° arc by R (centre X18.6603 Y-5) whose centre is written to three decimals moves by
/// 0.0003 mm, not by the 0.04 mm between two samplings of it 10° apart.
#[test]
fn an_arc_whose_centre_is_rounded_moves_by_the_rounding() {
    let text = "G21 G90 G17\nT1 M6\nS1000 M3\nF1000\nG0 X0 Y0 Z5\nG1 Z-1\nG1 X10\nG3 Y-10 R10\nG0 Z5\nM2\n";
    let bad = failures(text, "linuxcnc", |_, v| v == "equal" || v.starts_with("rounded: post::rounded: "));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    // The diff of the two plans is that rounding, no more.
    let src = Source::read(text.as_bytes(), dialect("linuxcnc"), "cause").unwrap();
    let (written, _) = round_trip(&src, "fanuc");
    let a = ncplan::pipeline::analyze_plan(text.as_bytes(), &dialect("linuxcnc"), &ncplan::interp::Profile::default()).plan;
    let b = ncplan::pipeline::analyze_plan(written.as_bytes(), &dialect("fanuc"), &ncplan::interp::Profile::default()).plan;
    let changes = ncplan::diff::diff(&a, &b);
    assert!(changes.iter().all(|c| c.deviation.is_some_and(|d| d < 0.001)), "{changes:?}\n{written}");
}

/// A LinuxCNC arc of two and a quarter turns (`P3`) is written as its whole turns and the
/// rest, or two halves per turn where the target states arcs by R: the same path the same
/// way, which the diff does not take for a change.
#[test]
fn an_arc_written_in_turns_is_the_same_toolpath() {
    let text = "G21 G90 G17\nT1 M6\nS1000 M3\nF500\nG0 X0 Y0 Z5\nG1 Z-1\nG1 X20\nG3 X30 Y10 I0 J10 P3\nG0 Z5\nM2\n";
    let bad = failures(text, "linuxcnc", |_, v| v == "equal");
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// A thread (`G33 K`) and a rigid tap (`G33.1 K`) feed their pitch per revolution: the
/// feed rate set before (or none) does not apply, and a Fanuc-family target's `G33 F` (the
/// lead in F) and tapping cycle at pitch × speed per minute make the same moves. A tap's
/// plan is a tapping workingstep whose first plunge is a cut, without a dwell, however the
/// tap is written. Siemens and Heidenhain have no thread or tap output rules yet.
#[test]
fn threads_and_rigid_taps_feed_their_pitch() {
    let thread = "G20 G90\nG0 X1 Z0.1\nS100 M3\nG33 Z-2 K0.025\nG0 X1.25\nZ0.1\nM5\nM2\n";
    let bad = failures(thread, "linuxcnc", |to, v| {
        v == "equal" || to == "heidenhain" && v.starts_with("untranslatable: post::unwritable: a thread (G33")
    });
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let tap = "G20 G90 G40\nM3 S200\nG0 X1 Y1 Z0.1\nG33.1 Z-0.75 K0.05\nG0 X2 Y1 Z0.1\nS500\nG33.1 Z-0.75 K0.05\nM5\nM2\n";
    let bad = failures(tap, "linuxcnc", |to, v| {
        v == "equal" || ["siemens", "heidenhain"].contains(&to) && v.starts_with("untranslatable: post::unwritable: a rigid tap (G33.1)")
    });
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// A feed to where the tool already is (a post's repeated `G1 X0` at X0, a move of 1e-9
/// inch) cuts nothing: the plan has no workingstep for it, whether the translation writes
/// it or leaves it out.
#[test]
fn a_feed_that_goes_nowhere_is_no_cut() {
    let text = "G20 G90 G17\nG0 X0 Y0 Z0\nG0 X0.1\nG0 X0\nG1 X0.000000001 F100\nG1 X0\nM30\n";
    let bad = failures(text, "linuxcnc", |_, v| v == "equal");
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let cut = "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\nG1 X10\nG1 Y10\nG0 Z5\nM2\n";
    let bad = failures(cut, "linuxcnc", |_, v| v == "equal");
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// A Fanuc program that cuts with another tool's length offset (`G43 H3` with no tool
/// change, the operator loading the tool): Siemens and Heidenhain apply the length of the
/// tool called, so the translation says it cannot state H3; the G-code targets write it.
#[test]
fn another_tools_length_offset_is_unwritable_where_the_tool_call_applies_the_length() {
    let text = "%\nO0097\nG55 G40 G0 X2. Y0 M3 S580\nG43 H3 Z39. M8\nG1 Z29.88 F39\nX-114. F117\nG0 Z39.\nM30\n%\n";
    let bad = failures(text, "fanuc", |to, v| {
        v == "equal"
            || ["siemens", "heidenhain"].contains(&to)
                && v == "untranslatable: post::unwritable: the length offset H3 while tool T0 is in the spindle: the target applies the tool's own length"
    });
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// A program that sets the values of the work offset it cuts in (`G10 L20` while G54 is in
/// force) moves the machine as a shift would; the translation, written in the offset's
/// frame, cannot set them and says so rather than losing the moves.
#[test]
fn setting_the_active_work_offset_is_said() {
    let text = "G21 G90 G17 G54\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG10 L20 P1 X-10\nG1 X0\nG0 Z5\nM2\n";
    let bad = failures(text, "linuxcnc", |_, v| {
        v.starts_with("untranslatable: post::unwritable: the program changes the values of the work offset it moves in")
    });
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// A tapping cycle written as a cycle reverses the spindle itself: its expansion's spindle
/// calls (`M4`, `M3` after each hole) are not written too.
#[test]
fn a_tapping_cycle_writes_no_spindle_calls_of_its_own_moves() {
    let text = "%\nO1000\nT3 M6\nG90 G54 G0 X10. Y10. S500 M3\nG43 H3 Z50.\nG99 G84 Z-10. R5. F500.\nX20.\nG80\nM30\n%\n";
    let bad = failures(text, "fanuc", |_, v| v == "equal" || v.starts_with("restated: post::cycle-as-moves: "));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let src = Source::read(text.as_bytes(), dialect("fanuc"), "cause").unwrap();
    let (written, verdict) = round_trip(&src, "haas");
    assert_eq!(verdict, "equal");
    assert!(!written.lines().any(|l| l == "M4" || l == "M3"), "{written}");
}

/// LinuxCNC's G84 feeds out of the hole all the way to the clear level (G98: where the
/// cycle began); Fanuc's feeds out to R and rapids on. A G98 tap from above R is written as
/// the moves on the Fanuc family, and one retracting to R (G99) stays a cycle.
#[test]
fn a_tap_fed_out_past_r_is_written_as_moves_where_the_target_rapids_from_r() {
    let text = "G20 G90 G17\nT1 M6\nM3 S1000\nF10\nG0 X0 Y0 Z2\nG98 G84 X1 Y1 Z-1 R1\nG80\nG0 Z2\nG99 G84 X2 Y1 Z-1 R1\nG80\nM2\n";
    let bad = failures(text, "linuxcnc", |to, v| {
        v == "equal"
            || ["fanuc", "haas", "mitsubishi", "mazak", "okuma", "fagor"].contains(&to) && v.starts_with("restated: post::cycle-as-moves: ")
            || ["siemens", "heidenhain"].contains(&to) && v.starts_with("restated: post::cycle-as-moves: ")
    });
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let src = Source::read(text.as_bytes(), dialect("linuxcnc"), "cause").unwrap();
    let (written, _) = round_trip(&src, "fanuc");
    assert!(written.contains("G99 G84") && !written.contains("G98 G84"), "{written}");
}

/// A Siemens drilling cycle returns to its retract plane (RTP), which a G98 cycle states as
/// the level the cycle began at: the Fanuc family first rapids down to it. One whose RTP is
/// above where it begins, or below its R level, cannot be a G98/G99 cycle: written as moves.
/// A G8x cycle has no word for the surface (RFP) either: the plan read back takes the hole
/// tops from elsewhere, which the translation says.
#[test]
fn a_retract_plane_is_where_a_g98_cycle_begins() {
    let text =
        "T9 D1\nM6\nG17 G54 G90\nS2450 F740 M3\nG0 X0 Y42 Z300\nMCALL CYCLE81(144.9,124.9,2,,106.7)\nX0 Y42\nY142\nMCALL\nG0 Z300\nM30\n";
    let bad = failures(text, "siemens", |to, v| {
        v == "equal" || to != "heidenhain" && v.starts_with("restated: post::surface-restated: plan: feature 1: round hole")
    });
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let src = Source::read(text.as_bytes(), dialect("siemens"), "cause").unwrap();
    let (written, _) = round_trip(&src, "fanuc");
    assert!(written.contains("Z144.9\nG98 G81"), "{written}");
    let above = "T9 D1\nM6\nG17 G54 G90\nS2450 F740 M3\nG0 X0 Y42 Z180\nCYCLE81(200,124.9,2,,106.7)\nG0 Z300\nM30\n";
    let bad = failures(above, "siemens", |to, v| v == "equal" || to != "heidenhain" && v.starts_with("restated: post::cycle-as-moves: "));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// A modal cycle's next position that also turns a rotary axis (`MCALL` … `B225.`) is a
/// move of its own, not just the next hole's position: the B turn and the hole after it are
/// written.
#[test]
fn a_modal_cycle_position_that_turns_a_rotary_axis_is_written() {
    let text = "T9 D1\nM6\nG17 G54 G90\nS2450 F740 M3\nG0 X0 Y42 B0 Z144.9\nMCALL CYCLE81(144.9,126.9,0,,106.7)\nX0 Y42\nY142\nB225.\nMCALL\nG0 Z300\nM30\n";
    let src = Source::read(text.as_bytes(), dialect("siemens"), "cause").unwrap();
    for to in ["fanuc", "linuxcnc"] {
        let (written, verdict) = round_trip(&src, to);
        assert_eq!(verdict, "equal", "{to}\n{written}");
        assert!(written.contains("G0 B225"), "{written}");
    }
}

/// Okuma dwells with `G04 F` in seconds: a dwell is written so, not as Fanuc's `G4 P` in
/// milliseconds (which Okuma would read as a thousand times longer).
#[test]
fn okuma_dwells_in_seconds() {
    let text = "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG4 P1.5\nG1 Z-1 F100\nG1 X10\nG0 Z5\nM2\n";
    let src = Source::read(text.as_bytes(), dialect("linuxcnc"), "cause").unwrap();
    let (written, verdict) = round_trip(&src, "okuma");
    assert_eq!(verdict, "equal", "{written}");
    assert!(written.contains("G4 F1.5"), "{written}");
}

/// A thread's lead written with fewer decimals than the source states (LinuxCNC G76 passes
/// with a taper, 1.70888 mm per revolution written F1.709) is a feed rounded, said.
#[test]
fn a_rounded_thread_lead_is_a_rounded_feed() {
    let text = "G20 G90 G18\nT4 M6\nS800 M3\nG0 X0.2 Z0.2\nG33 X0.2 Z-0.4 K0.05\nG33 X0.162 Z-0.479 K0.0672787\nG0 X0.3\nM5\nM2\n";
    let bad = failures(text, "linuxcnc", |to, v| {
        v == "equal" || v.starts_with("rounded: post::rounded: ") || to == "heidenhain" && v.starts_with("untranslatable: ")
    });
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// Heidenhain changes the speed alone with a tool call that names no tool (`TOOL CALL Z
/// S2000`): read as a speed, not a tool change, so a LinuxCNC program that raises the
/// speed while cutting stays one workingstep in Heidenhain.
#[test]
fn a_tool_call_without_a_tool_changes_the_speed_only() {
    let text = "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100\nG1 X10\nS2000 M3\nG1 X20\nG0 Z5\nM2\n";
    let src = Source::read(text.as_bytes(), dialect("linuxcnc"), "cause").unwrap();
    let (written, verdict) = round_trip(&src, "heidenhain");
    assert_eq!(verdict, "equal", "{written}");
    assert!(written.contains("TOOL CALL Z S2000"), "{written}");
}

/// Heidenhain's cycle 9 dwells where it is written (`CYCL DEF 9.1 DWELL 0.5`): the dwell a
/// translation writes so is read back.
#[test]
fn heidenhain_cycle_9_dwells() {
    let text = "G21 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F100 G4 P0.5\nG1 X10\nG0 Z5\nM2\n";
    let src = Source::read(text.as_bytes(), dialect("linuxcnc"), "cause").unwrap();
    let (written, verdict) = round_trip(&src, "heidenhain");
    assert_eq!(verdict, "equal", "{written}");
    assert!(written.contains("CYCL DEF 9.1 DWELL 0.5"), "{written}");
}

/// A Siemens peck cycle's own re-approach distance (`CYCLE83`'s _DIS1, 1.6 mm here) is the
/// one a target that states it (Heidenhain Q258) is given, not the dictionary's default.
#[test]
fn a_peck_cycles_own_reapproach_distance_is_kept() {
    let text = "T=\"DRILL 8.5\"\nM6\nG17 G54 G90\nS5000 M3 F300\nG0 X0 Y0 Z50\nMCALL CYCLE83(10,0,5,,20,,4,100,0,0.5,100,1,0,1.2,1.4,0,1.6,0,1,11211111)\nG0 X0 Y0\nMCALL\nG0 Z50\nM30\n";
    let src = Source::read(text.as_bytes(), dialect("siemens"), "cause").unwrap();
    let (written, verdict) = round_trip(&src, "heidenhain");
    assert_eq!(verdict, "equal", "{written}");
    assert!(written.contains("Q258=+1.6"), "{written}");
}

/// Fagor's cycles dwell with K in seconds; P is an arithmetic parameter there (a `P1000`
/// is read as a parameter without its `=`). A drilling cycle's levels written rounded are
/// positions rounded, said; a dwell under half a millisecond (Haas `P.01` read in
/// milliseconds) is none, as a target writing `P0` has it.
#[test]
fn cycle_dwells_and_levels_are_written_as_the_target_reads_them() {
    let text = "%\nO1000\nG20\nT3 M6\nG90 G54 G0 X0.5 Y0.5 S500 M3\nG43 H3 Z1.25\nG98 G82 Z0.6253 R0.85 P500 F27.5\nX1.5\nG80\nM30\n%\n";
    let bad = failures(text, "haas", |_, v| v == "equal" || v.starts_with("rounded: post::rounded: "));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
    let src = Source::read(text.as_bytes(), dialect("haas"), "cause").unwrap();
    let (written, _) = round_trip(&src, "fagor");
    assert!(written.contains("G82 X0.5 Y0.5 Z0.6253 R0.85 K0.5"), "{written}");
    // A bottom of five decimals written with four: said.
    let fine = text.replace("Z0.6253", "Z0.62534");
    let (_, diags) = crate::translate::translate(&fine, &dialect("haas"), &dialect("fanuc"), "cause");
    assert!(diags.iter().any(|d| d.code == ncplan::diag::Code::PostRounded), "{diags:?}");
    let tiny = text.replace("P500", "P.01");
    let bad = failures(&tiny, "haas", |_, v| v == "equal" || v.starts_with("rounded: post::rounded: "));
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

//! Rigid taps of cycles defined by their pitch (Heidenhain 207 `Q239`, 840D `CYCLE84` `PIT` /
//! `MPIT`) feed the pitch per turn of the spindle, not the feed in force: the reading feeds
//! pitch x speed (per minute), the sign of the pitch the hand; a translation writes the
//! target's tap at that feed, or refuses where the feed is not known.

use ncplan::diag::Diagnostic;

use crate::translate_known::{errors, translate};

/// The F word of the first line holding `code` (a `G84` or `G74` word).
fn tap_feed(out: &str, code: &str) -> Option<f64> {
    let line = out.lines().find(|l| l.split_whitespace().any(|w| w == code))?;
    line.split_whitespace().find_map(|w| w.strip_prefix('F').and_then(|v| v.parse::<f64>().ok()))
}

const TNC: &str = "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S500\n2 L X+0 Y+0 Z+50 R0 FMAX M3\n3 L Z+20 R0 F250\n4 CYCL DEF 207 RIGID TAPPING ~\n  Q200=+3 ;SET-UP CLEARANCE ~\n  Q201=-12 ;DEPTH ~\n  Q239=+1.25 ;THREAD PITCH ~\n  Q203=+0 ;SURFACE COORDINATE ~\n  Q204=+20 ;2ND SET-UP CLEARANCE\n5 L X+10 Y+10 R0 FMAX M99\n6 L X+20 Y+10 R0 F250\n7 L Z+50 R0 FMAX\n8 END PGM T MM\n";

#[test]
fn heidenhain_207_taps_at_its_pitch_times_the_speed() {
    for to in ["fanuc", "linuxcnc", "haas"] {
        let (out, diags) = translate(TNC, "heidenhain", to);
        assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{to}:\n{out}");
        // 1.25 mm a turn at 500 rpm: 625 mm/min, not the F250 in force (LinuxCNC's output
        // writes the tap as its moves).
        if to == "linuxcnc" {
            assert!(out.lines().any(|l| l == "G1 Z-12 F625"), "{to}:\n{out}");
        } else {
            assert_eq!(tap_feed(&out, "G84"), Some(625.0), "{to}:\n{out}");
        }
        // The feed in force comes back after the cycle.
        let after = out.lines().skip_while(|l| !l.contains("G80")).collect::<Vec<_>>().join("\n");
        assert!(after.contains("F250"), "{to}:\n{out}");
    }
    // A negative pitch is a left-hand thread: the target's left-hand tap.
    let left = TNC.replace("Q239=+1.25", "Q239=-1.25").replace("M3", "M4");
    let (out, diags) = translate(&left, "heidenhain", "fanuc");
    assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{out}");
    assert_eq!(tap_feed(&out, "G74"), Some(625.0), "{out}");
    // Without a spindle speed the tap's feed is not known: refused, never written at F250.
    let no_speed = TNC.replace("TOOL CALL 1 Z S500", "TOOL CALL 1 Z");
    let (out, diags) = translate(&no_speed, "heidenhain", "fanuc");
    assert!(errors(&diags).iter().any(|d| d.code.as_str() == "post::motion-unknown"), "{diags:?}\n{out}");
}

#[test]
fn cycle84_taps_at_pit_or_the_coarse_pitch_of_mpit() {
    let src = "N10 G0 G17 G90 G54 X0 Y0 Z50\nN20 T1 M6\nN30 G0 X10 Y10 Z20 S400 M3\nN40 G1 F250\nN50 MCALL CYCLE84(15,0,5,-12,,0,3,,1.5,0,400,400)\nN60 X10 Y10\nN70 MCALL\nN80 G0 Z50\nN90 M30\n";
    let (out, diags) = translate(src, "siemens", "fanuc");
    assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{out}");
    assert_eq!(tap_feed(&out, "G84"), Some(600.0), "{out}");
    // MPIT 8: M8's coarse pitch 1.25.
    let mpit = src.replace("CYCLE84(15,0,5,-12,,0,3,,1.5,0,400,400)", "CYCLE84(15,0,5,-12,,0,3,8,,0,400,400)");
    let (out, diags) = translate(&mpit, "siemens", "fanuc");
    assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{out}");
    assert_eq!(tap_feed(&out, "G84"), Some(500.0), "{out}");
    // A tapping speed SST other than the speed in force: not modelled, refused.
    let sst = src.replace(",0,400,400)", ",0,300,300)");
    let (out, diags) = translate(&sst, "siemens", "fanuc");
    assert!(errors(&diags).iter().any(|d| d.code.as_str() == "post::motion-unknown"), "{diags:?}\n{out}");
}

/// Heidenhain `PLANE … TURN MB MAX` retracts the tool axis to its travel limit before the
/// rotary axes turn, as `M140 MB MAX`: a target without that move refuses the translation as
/// unwritable; `MB n` retracts by n along the tool axis, a known move written before the tilt.
#[test]
fn plane_turn_mb_retracts_before_the_tilt() {
    let tnc = "0 BEGIN PGM P MM\n1 TOOL CALL 1 Z S2000\n2 L X+0 Y+0 Z+20 R0 FMAX M3\n3 L Z-2 R0 F100\n4 PLANE SPATIAL SPA+0 SPB+30 SPC+0 TURN MB MAX FMAX\n5 L X+10 Y+0 R0 FMAX\n6 L Z+5 R0 FMAX\n7 L Z-1 R0 F100\n8 L Z+50 R0 FMAX\n9 PLANE RESET STAY\n10 END PGM P MM\n";
    for to in ["fanuc", "siemens"] {
        let (out, diags) = translate(tnc, "heidenhain", to);
        let e = errors(&diags);
        assert!(e.iter().any(|d| d.code.as_str() == "post::unwritable" && d.message.contains("travel limit")), "{to}: {e:?}\n{out}");
    }
    let (out, diags) = translate(tnc, "heidenhain", "heidenhain");
    assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{out}");
    let lines: Vec<&str> = out.lines().collect();
    let limit = lines.iter().position(|l| l.contains("MB MAX")).unwrap_or_else(|| panic!("no MB MAX in\n{out}"));
    let plane = lines.iter().position(|l| l.contains("PLANE SPATIAL")).unwrap_or_else(|| panic!("no PLANE in\n{out}"));
    assert!(limit <= plane, "{out}");
    // MB 50: up 50 from Z-2 before the plane turns.
    let by = tnc.replace("TURN MB MAX FMAX", "TURN MB50 FMAX");
    let (out, diags) = translate(&by, "heidenhain", "fanuc");
    assert_eq!(errors(&diags), Vec::<&Diagnostic>::new(), "{out}");
    let lines: Vec<&str> = out.lines().collect();
    let tilt = lines.iter().position(|l| l.contains("G68.2")).unwrap_or_else(|| panic!("no G68.2 in\n{out}"));
    assert!(lines[..tilt].iter().any(|l| l.split_whitespace().any(|w| w == "Z48.")), "{out}");
}

//! Turning workingsteps compared in a turner's terms: the feed per revolution, the cutting
//! speed and its clamp (`spindle clamp 2500 → 1800 /min`), the cycle's finishing allowance
//! (`U0.4 W0.1 → U0.6 W0.2`), depth of cut and retract, a thread's pitch, height and passes,
//! a groove's pecks. The feed per minute and the lowest Z are not compared: on a lathe they
//! follow the diameter, the clamp and the allowance, which are said instead. A lathe cycle's
//! word is located by the role the dictionary gives it (`cycle_role`: Haas `G71 … D` the depth
//! of cut, `G76 … A` the tool's angle, never an offset or a rotary axis); a turret's T word with
//! another offset is the tool's offset (`turret_offset`); passes written one by one (a CAM
//! post's G1 roughing, G92's repeated X words) are told as passes; turned features read in
//! diameters (`Ø24`), a face by its Z and a face groove by its floor's Z, width and walls
//! (`turned_dims`); a feature's change shared by the
//! workingsteps that rough and finish it is told once (`merge_feature_repeats`), and a thread's
//! major diameter derived from the height told is not told again (`fold_derived`).

use std::collections::BTreeSet;

use super::{ChangeKind, Fmt, Push, TOLERANCE, coolant_words, num, spindle_words};
use crate::dialect::{Dialect, Role};
use crate::plan::{Turned, Turning, Workingstep};

/// The first cut's start, as a diameter and Z, where the workingstep's moves are its own:
/// a cycle's passes start where its start point and depth of cut put them, which its
/// parameters' changes say.
pub(super) fn start(a: &Workingstep, b: &Workingstep, u: Fmt, push: &mut Push<'_>) {
    let cycle = |w: &Workingstep| w.turning.as_deref().is_some_and(|t| t.intent.is_some());
    if cycle(a) || cycle(b) {
        return;
    }
    if let (Some(x), Some(y)) = (a.start_point, b.start_point)
        && crate::plan::geom::dist(x, y) > TOLERANCE
    {
        let p = |q: crate::plan::P3| format!("Ø{} Z{}", u.c(2.0 * q[0]), u.c(q[2]));
        push(ChangeKind::StartPointMoved, "start_point", p(x), p(y), (Some(a.lines.0), Some(b.lines.0)));
    }
}

/// The way the tool leaves the part after its last cut (ISO 14649's retract), move by move:
/// where each move goes (a diameter and Z) and whether in rapid or at feed. On a lathe no
/// retract height says it (the heights compared on a mill are along the spindle, here along
/// the part): a back-off rapid along the part's diameter to the face (`G00 X0.385 Z0`) taken
/// out, so that the tool rapids from the last cut straight to its change position, is a path
/// the tool no longer takes, told where the two ways part. Moves that go nowhere are not in the
/// plan, so restating where the tool already is changes nothing here. Moves the program writes
/// itself only, not a cycle's. The way stops at a reference return or a machine-coordinate
/// move (`returns`, each side's lines): where those go only the machine knows (the plan takes
/// the reference at work zero, "rapid to Ø0 Z0", a place the program never states), and an
/// edit of them is told by their statements' rows.
pub(super) fn retract(a: &Workingstep, b: &Workingstep, u: Fmt, returns: super::ReturnLines<'_>, push: &mut Push<'_>) {
    // A cycle's passes retract where its start point and parameters put them, which their
    // changes say (as for the start point).
    let cycle = |w: &Workingstep| w.turning.as_deref().is_some_and(|t| t.intent.is_some() || t.cycle.is_some());
    if cycle(a) || cycle(b) {
        return;
    }
    use crate::plan::geom::dist;
    // Where the cuts differ, their change says the rest (the last pass elsewhere leaves from
    // elsewhere): the way off is told only where the tool cut the same path.
    let cuts = |w: &Workingstep| -> Vec<(crate::plan::P3, crate::plan::P3)> {
        w.toolpath.iter().filter(|m| m.phase == crate::plan::Phase::Cut).map(|m| (m.from, m.to)).collect()
    };
    let (ca, cb) = (cuts(a), cuts(b));
    if ca.is_empty() || ca.len() != cb.len() || ca.iter().zip(&cb).any(|(x, y)| dist(x.0, y.0) > TOLERANCE || dist(x.1, y.1) > TOLERANCE) {
        return;
    }
    // The moves that go somewhere (a return written twice, a reference return where the tool
    // already is, are none).
    // With whether it was cut short by a reference return.
    let way = |w: &Workingstep, returns: &BTreeSet<u32>| -> (Vec<(bool, crate::plan::P3, u32)>, bool) {
        let Some(last_cut) = w.toolpath.iter().rposition(|m| m.phase == crate::plan::Phase::Cut) else { return (Vec::new(), false) };
        let after = || w.toolpath.iter().skip(last_cut + 1);
        let cut = after().any(|m| returns.contains(&m.line));
        let way = after()
            .take_while(|m| !returns.contains(&m.line))
            .filter(|m| m.phase == crate::plan::Phase::Retract && dist(m.from, m.to) > TOLERANCE)
            .map(|m| (m.kind == crate::plan::MoveKind::Rapid, m.to, m.line))
            .collect();
        (way, cut)
    };
    let ((wa, cut_a), (wb, cut_b)) = (way(a, returns.0), way(b, returns.1));
    if wa.is_empty() || wb.is_empty() {
        return;
    }
    let same =
        |x: &(bool, crate::plan::P3, u32), y: &(bool, crate::plan::P3, u32)| x.0 == y.0 && crate::plan::geom::dist(x.1, y.1) <= TOLERANCE;
    let Some(k) = (0..wa.len().max(wb.len())).find(|&k| match (wa.get(k), wb.get(k)) {
        (Some(x), Some(y)) => !same(x, y),
        _ => true,
    }) else {
        return;
    };
    // The ways part only where one of them reaches its reference return: the return's own
    // statement rows say what took its place.
    if (cut_a && k >= wa.len()) || (cut_b && k >= wb.len()) {
        return;
    }
    let text = |w: &[(bool, crate::plan::P3, u32)]| {
        w.iter()
            .map(|(rapid, q, _)| format!("{} Ø{} Z{}", if *rapid { "rapid to" } else { "feed to" }, u.c(2.0 * q[0]), u.c(q[2])))
            .collect::<Vec<_>>()
            .join(", then ")
    };
    let line = |w: &[(bool, crate::plan::P3, u32)]| w.get(k).or(w.last()).map(|m| m.2);
    push(ChangeKind::RetractChanged, "retract_path", text(&wa), text(&wb), (line(&wa), line(&wb)));
}

/// Compares the technology of two turning workingsteps; whether the feeds differ.
pub(super) fn technology(a: &Workingstep, b: &Workingstep, u: Fmt, push: &mut Push<'_>) -> bool {
    let at = (Some(a.lines.0), Some(b.lines.0));
    let (Some(ta), Some(tb)) = (a.turning.as_deref(), b.turning.as_deref()) else { return false };
    let (ka, kb) = (&a.technology, &b.technology);
    // Per revolution in the original's units (G99 F0.01 in an inch program is 0.01 in/rev).
    let per_rev = |v: Option<f64>| v.map_or_else(|| "none".to_owned(), |f| format!("F{} {}/rev", u.c(f), if u.inch { "in" } else { "mm" }));
    let feeds_differ = differs(ta.feed_per_rev, tb.feed_per_rev)
        || (ta.feed_per_rev.is_none() && ta.pitch.is_none() && (ka.feed - kb.feed).abs() > TOLERANCE);
    if differs(ta.feed_per_rev, tb.feed_per_rev) {
        push(ChangeKind::FeedChanged, "feed", per_rev(ta.feed_per_rev), per_rev(tb.feed_per_rev), at);
    } else if feeds_differ {
        push(ChangeKind::FeedChanged, "feed", u.feed(ka.feed), u.feed(kb.feed), at);
    }
    match (ka.surface_speed, kb.surface_speed) {
        (Some(x), Some(y)) => {
            if (x - y).abs() > TOLERANCE {
                push(ChangeKind::SpindleSpeedChanged, "cutting_speed", u.surface(x), u.surface(y), at);
            }
        }
        (None, None) => {
            if (ka.spindle_speed - kb.spindle_speed).abs() > TOLERANCE {
                let s = |v: f64| format!("S{} /min", num(v));
                push(ChangeKind::SpindleSpeedChanged, "spindle_speed", s(ka.spindle_speed), s(kb.spindle_speed), at);
            }
        }
        (x, y) => {
            let mode = |v: Option<f64>, rpm: f64| match v {
                Some(v) => format!("constant cutting speed {} (G96)", u.surface(v)),
                None => format!("S{} /min (G97)", num(rpm)),
            };
            push(ChangeKind::SpindleModeChanged, "spindle_mode", mode(x, ka.spindle_speed), mode(y, kb.spindle_speed), at);
        }
    }
    if differs(ta.spindle_limit, tb.spindle_limit) {
        let clamp = |v: Option<f64>| v.map_or_else(|| "none".to_owned(), |v| format!("{} /min", num(v)));
        push(ChangeKind::SpindleSpeedChanged, "spindle_clamp", clamp(ta.spindle_limit), clamp(tb.spindle_limit), at);
    }
    if ka.spindle != kb.spindle {
        push(
            ChangeKind::SpindleDirectionChanged,
            "spindle_direction",
            spindle_words(ka.spindle).into(),
            spindle_words(kb.spindle).into(),
            at,
        );
    }
    if ka.coolant != kb.coolant {
        push(ChangeKind::CoolantChanged, "coolant", coolant_words(ka.coolant).into(), coolant_words(kb.coolant).into(), at);
    }
    feeds_differ
}

/// Compares what the lathe cycles state; whether anything did differ (it explains a changed
/// toolpath).
pub(super) fn cutting(a: &Workingstep, b: &Workingstep, u: Fmt, push: &mut Push<'_>) -> bool {
    let at = (Some(a.lines.0), Some(b.lines.0));
    let (Some(ta), Some(tb)) = (a.turning.as_deref(), b.turning.as_deref()) else { return false };
    let mut explained = false;
    let (ia, ib) = (ta.intent.clone().unwrap_or_default(), tb.intent.clone().unwrap_or_default());
    let len = |v: Option<f64>| v.map_or_else(|| "none".to_owned(), |v| u.c(v));
    if differs(ia.allowance_x, ib.allowance_x) || differs(ia.allowance_z, ib.allowance_z) {
        let uw = |x: Option<f64>, z: Option<f64>| format!("U{} W{}", len(x), len(z));
        push(
            ChangeKind::AllowanceChanged,
            "finishing_allowance",
            uw(ia.allowance_x, ia.allowance_z),
            uw(ib.allowance_x, ib.allowance_z),
            at,
        );
        explained = true;
    }
    if differs(ia.depth_of_cut, ib.depth_of_cut) {
        push(ChangeKind::AxialDepthChanged, "depth_of_cut", len(ia.depth_of_cut), len(ib.depth_of_cut), at);
        explained = true;
    }
    let (pa, pb) = (pitch(ta), pitch(tb));
    if differs(pa, pb) {
        push(ChangeKind::ThreadPitchChanged, "thread_pitch", len(pa), len(pb), at);
        explained = true;
    }
    for (field, x, y) in [
        ("retract", ia.retract, ib.retract),
        ("thread_height", ia.thread_depth, ib.thread_depth),
        ("first_depth_of_cut", ia.first_cut, ib.first_cut),
        ("least_depth_of_cut", ia.min_cut, ib.min_cut),
        ("thread_finishing_allowance", ia.finish_allowance, ib.finish_allowance),
        ("peck", ia.peck, ib.peck),
        ("groove_shift", ia.step, ib.step),
    ] {
        if differs(x, y) {
            push(ChangeKind::CycleParameterChanged, field, len(x), len(y), at);
            explained = true;
        }
    }
    if differs(ia.angle, ib.angle) {
        let deg = |v: Option<f64>| v.map_or_else(|| "none".to_owned(), |v| format!("{}°", num(v)));
        push(ChangeKind::CycleParameterChanged, "thread_angle", deg(ia.angle), deg(ib.angle), at);
        explained = true;
    }
    // Passes the program writes one by one (a CAM post's G1 roughing, the single-pass cycles
    // G90/G92/G94 repeated by their X or Z words), not those a cycle works out from its depth
    // of cut: one taken out or added is a pass, not a changed toolpath.
    let written = |t: &Turning| {
        let single = t.intent.as_ref().is_some_and(|i| {
            matches!(i.kind, Some(crate::canon::TurnKind::TurnPass | crate::canon::TurnKind::FacePass | crate::canon::TurnKind::ThreadPass))
        });
        single || (t.intent.is_none() && t.cycle.is_none())
    };
    // Each pass written in blocks of its own: not a cycle's moves from one block, whatever the
    // plan kept of it (LinuxCNC `G71`), nor a loop running the same blocks again (a grinder's
    // parts per series), whose bound says the change.
    let blocks = |w: &Workingstep, passes: u32| {
        let lines: BTreeSet<u32> = w.toolpath.iter().filter(|m| m.kind != crate::plan::MoveKind::Rapid).map(|m| m.line).collect();
        lines.len() > 1 && lines.len() >= passes as usize
    };
    if ta.passes != tb.passes
        && ta.passes > 0
        && tb.passes > 0
        && written(ta)
        && written(tb)
        && ta.rough == tb.rough
        && blocks(a, ta.passes)
        && blocks(b, tb.passes)
    {
        let field = if pitch(ta).is_some() {
            "thread_passes"
        } else if ta.rough {
            "roughing_passes"
        } else {
            "passes"
        };
        push(ChangeKind::CycleParameterChanged, field, ta.passes.to_string(), tb.passes.to_string(), at);
        explained = true;
    }
    // A pattern repeating cycle's relief (how far its first pass lies off its last) and
    // number of passes, as G73 writes them: U (per side) and W, and R.
    if differs(ia.relief.map(|r| r[0]), ib.relief.map(|r| r[0])) || differs(ia.relief.map(|r| r[1]), ib.relief.map(|r| r[1])) {
        let uw = |r: Option<[f64; 2]>| r.map_or_else(|| "none".to_owned(), |[x, z]| format!("U{} W{}", u.c(x), u.c(z)));
        push(ChangeKind::CycleParameterChanged, "pattern_relief", uw(ia.relief), uw(ib.relief), at);
        explained = true;
    }
    if ia.divisions != ib.divisions {
        let n = |v: Option<u32>| v.map_or_else(|| "none".to_owned(), |v| v.to_string());
        push(ChangeKind::CycleParameterChanged, "pattern_passes", n(ia.divisions), n(ib.divisions), at);
        explained = true;
    }
    if ia.finish_passes != ib.finish_passes {
        let n = |v: Option<u32>| v.map_or_else(|| "none".to_owned(), |v| v.to_string());
        push(ChangeKind::CycleParameterChanged, "finishing_passes", n(ia.finish_passes), n(ib.finish_passes), at);
        explained = true;
    }
    explained
}

/// A thread's lead: its cycle's, or that of its synchronised moves.
fn pitch(t: &Turning) -> Option<f64> {
    t.intent.as_ref().and_then(|i| i.pitch).or(t.pitch)
}

fn differs(x: Option<f64>, y: Option<f64>) -> bool {
    match (x, y) {
        (Some(x), Some(y)) => (x - y).abs() > TOLERANCE,
        (None, None) => false,
        _ => true,
    }
}

/// A turned feature's sizes as a turner reads them: diameters as `Ø24`, a round's radius, a
/// groove's width, a thread's diameters; `dim` pushes one that differs (field, before, after).
pub(super) fn turned_dims(a: (&Turned, f64), b: (&Turned, f64), u: Fmt, dim: &mut dyn FnMut(&str, String, String)) {
    let ((a, za), (b, zb)) = (a, b);
    // A face across the axis is where it stands along Z (`face Z0 → Z-0.2`).
    if matches!((a, b), (Turned::RevolvedFlat { .. }, Turned::RevolvedFlat { .. })) && (za - zb).abs() > TOLERANCE {
        dim("face", format!("Z{}", u.c(za)), format!("Z{}", u.c(zb)));
    }
    // A face groove's floor is where it stands along Z (`face groove floor Z-13.589 → Z-14`).
    if matches!((a, b), (Turned::FaceGroove { .. }, Turned::FaceGroove { .. })) && (za - zb).abs() > TOLERANCE {
        dim("face_groove_floor", format!("Z{}", u.c(za)), format!("Z{}", u.c(zb)));
    }
    let mut size = |field: &str, x: Option<f64>, y: Option<f64>, diameter: bool| {
        if let (Some(x), Some(y)) = (x, y)
            && (x - y).abs() > TOLERANCE
        {
            let show = |v: f64| if diameter { format!("Ø{}", u.c(v)) } else { u.len(v) };
            dim(field, show(x), show(y));
        }
    };
    match (a, b) {
        (Turned::RevolvedFlat { outer: oa, inner: ia }, Turned::RevolvedFlat { outer: ob, inner: ib }) => {
            size("outer_diameter", Some(*oa), Some(*ob), true);
            size("inner_diameter", Some(*ia), Some(*ib), true);
        }
        (Turned::Diameter { diameter: da, .. }, Turned::Diameter { diameter: db, .. }) => size("diameter", Some(*da), Some(*db), true),
        (Turned::RevolvedRound { radius: ra, .. }, Turned::RevolvedRound { radius: rb, .. }) => {
            size("round_radius", Some(*ra), Some(*rb), false);
        }
        (Turned::Groove { diameter: da, width: wa, .. }, Turned::Groove { diameter: db, width: wb, .. }) => {
            size("groove_diameter", Some(*da), Some(*db), true);
            size("groove_width", *wa, *wb, false);
        }
        (Turned::FaceGroove { outer: oa, inner: ia }, Turned::FaceGroove { outer: ob, inner: ib }) => {
            size("face_groove_width", a.face_groove_width(), b.face_groove_width(), false);
            size("face_groove_outer_diameter", Some(*oa), Some(*ob), true);
            size("face_groove_inner_diameter", Some(*ia), Some(*ib), true);
        }
        (Turned::Revolution { outer: oa, inner: ia, .. }, Turned::Revolution { outer: ob, inner: ib, .. }) => {
            size("outer_diameter", Some(*oa), Some(*ob), true);
            size("inner_diameter", Some(*ia), Some(*ib), true);
        }
        (Turned::Thread { diameter: da, root: ra, .. }, Turned::Thread { diameter: db, root: rb, .. }) => {
            size("thread_diameter", *da, *db, true);
            size("thread_root_diameter", Some(*ra), Some(*rb), true);
        }
        _ => {}
    }
}

/// The role a lathe cycle gives a word of its block by the dictionary (`G71 P Q U W D F` on a
/// Haas lathe: `D:cut-depth`; Haas G76: `K:profile-depth`, `D:cut-depth`, `A:tool-angle`), where
/// the word's letter means something else outside the cycle (D an offset, A a rotary axis).
pub(super) fn cycle_role(letter: Role, code: Option<(char, u32)>, d: &Dialect) -> Option<Role> {
    let (l, n) = code?;
    d.code(l, n)?.args.iter().find(|(word, _)| *word == letter).map(|&(_, role)| role)
}

/// Whether a plan change of `kind` is what a lathe cycle's word of this role states: the
/// depth of cut (or a thread's first cut), the allowances, a thread's height, angle and pitch,
/// the retract; the plan tells these in a turner's terms, so the word needs no row of its own.
pub(super) fn role_shows(role: Role, kind: ChangeKind) -> bool {
    use ChangeKind as K;
    match role {
        Role::CutDepth => matches!(kind, K::AxialDepthChanged | K::CycleParameterChanged),
        Role::AllowanceX | Role::AllowanceZ | Role::Allowance => kind == K::AllowanceChanged,
        Role::Pitch | Role::ThreadSize => kind == K::ThreadPitchChanged,
        Role::ProfileDepth => matches!(kind, K::CycleParameterChanged | K::FeatureChanged),
        _ => kind == K::CycleParameterChanged,
    }
}

/// Sizes that follow from a cycle's parameter told above are not told again: a thread's major
/// diameter where the cycle states the root and the height (Fanuc and Haas `G76 X… P…`/`K…`:
/// X the root diameter, the height per side; the diameter is X plus twice the height, which
/// the turner did not change).
pub(super) fn fold_derived(first: usize, out: &mut Vec<super::Change>) {
    let told = |field: &str| out[first..].iter().any(|c| c.field == field);
    if told("thread_height") && !told("thread_root_diameter") {
        let mut k = first;
        while k < out.len() {
            if out[k].kind == ChangeKind::FeatureChanged && out[k].field == "thread_diameter" {
                out.remove(k);
            } else {
                k += 1;
            }
        }
    }
}

/// A feature's change told the same at several workingsteps that share the feature (a contour
/// roughed and finished: `G71`/`G70 P Q`, or explicit passes then a finishing pass): told once,
/// at the statements that show it in any of them, with the workingsteps it is also in. The
/// feature is the same where a statement shows the change in both (the contour's blocks both
/// cycles run), or where only one of them is shown at statements; two grooves changed alike,
/// each at its own blocks, stay two changes.
pub(super) fn merge_feature_repeats(changes: &mut Vec<super::Change>) {
    let shared = |c: &super::Change, d: &super::Change| match (c.detail.at.is_empty(), d.detail.at.is_empty()) {
        (true, true) => (c.original_line, c.line) == (d.original_line, d.line),
        // One side shown at no statement (a roughing's passes the finishing pass's edit moved):
        // the statements of the other show it for both.
        (true, false) | (false, true) => true,
        (false, false) => c.detail.at.iter().any(|x| d.detail.at.contains(x)),
    };
    super::fold_repeats(
        changes,
        |c| c.kind == ChangeKind::FeatureChanged,
        |c, d| d.workingstep != c.workingstep && shared(c, d),
        |c, d| {
            if c.detail.at.is_empty() {
                (c.original_line, c.line) = (d.original_line, d.line);
            }
            c.detail.at.extend(d.detail.at);
            c.detail.at.sort_by_key(|&(o, e)| (e.or(o), o));
            c.detail.at.dedup();
        },
    );
}

/// Whether a named cycle (Siemens `CYCLE95`, `CYCLE97`) turns, by its meaning in the dictionary.
pub(super) fn named_turning(name: &str, d: &Dialect) -> bool {
    use crate::dialect::Meaning as M;
    d.cycles.iter().any(|c| {
        c.name.eq_ignore_ascii_case(name)
            && matches!(
                c.meaning,
                M::CycleRoughTurn
                    | M::CycleRoughFace
                    | M::CycleThreadMultiple
                    | M::CycleGroove
                    | M::CycleStockCorner
                    | M::CycleContourTurn
                    | M::CyclePartOff
                    | M::CycleFacePeck
            )
    })
}

//! Pockets milled by a cycle (Siemens `POCKET3` rectangular, `POCKET4` circular; the
//! dictionary's `mill-pocket-rect` and `mill-pocket-circle`): the pocket the cycle's
//! arguments state, on the working plane in force (a swivelled plane included); a pocket
//! cycle called at a position (Heidenhain 251, 252) is centred there. Slots (`mill-slot`:
//! Heidenhain 253 at its centre; Siemens `SLOT1`, slots on a circle, each where its arguments
//! place it: [`slots_on_circle`]); under `MCALL` each is centred at the position the blocks
//! after it reach (`define`'s call of the cycle in force). And bores milled in a helix
//! (Heidenhain 208, `mill-bore`): [`Interpreter::mill_bore`].
//!
//! The moves written are the cycle's finishing pass on the wall at the floor: the tool down at
//! the pocket's centre, out to the wall, once round it (counter-clockwise), and up to the
//! retract plane, as a contour programmed under cutter compensation (the control offsets it
//! by the tool's radius). The roughing passes and their infeeds are not expanded, so the
//! pocket is what the plan reads, not the time the cycle takes: said once in a note.

use super::Interpreter;
use crate::canon::{CanonOp, CanonSink, CompOn, Setting};
use crate::diag::{Code, Diagnostic, Severity};
use crate::dialect::{Meaning, Role};
use crate::text::TextRange;

/// The shape a pocket cycle states, in the plane's coordinates.
#[derive(Clone, Copy)]
enum Shape {
    /// Centre, length along the angle, width, corner radius, angle (degrees).
    Rect { c: [f64; 2], len: f64, wid: f64, r: f64, angle: f64 },
    /// Centre and radius.
    Circle { c: [f64; 2], r: f64 },
    /// Centre, length from end to end along the angle, width (its ends half circles), angle.
    Slot { c: [f64; 2], len: f64, wid: f64, angle: f64 },
}

impl Interpreter<'_> {
    /// A pocket cycle (`mill-pocket-rect`, `mill-pocket-circle`) with its arguments by role.
    pub(super) fn mill_pocket(
        &mut self,
        meaning: Meaning,
        name: &str,
        args: &[(Role, f64)],
        range: TextRange,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let get = |r: Role| args.iter().rev().find(|(a, _)| *a == r).map(|(_, v)| *v);
        // A pocket placed by a corner (Heidenhain 251 `Q367` 1-4) rather than its centre.
        if get(Role::Geometry).is_some_and(|p| p != 0.0) {
            let msg = format!("{name} placed by a corner of the pocket, not its centre: kept as intent only, its moves are not expanded");
            self.limited(diags, "cycle-not-expanded", Diagnostic::new(Code::Unsupported, range, msg));
            return;
        }
        let centre = [get(Role::PocketX).unwrap_or(0.0), get(Role::PocketY).unwrap_or(0.0)];
        let shape = match meaning {
            Meaning::MillPocketRect => match (get(Role::PocketLength), get(Role::Width)) {
                (Some(len), Some(wid)) if len > 0.0 && wid > 0.0 => {
                    let r = get(Role::CornerRadius).unwrap_or(0.0).abs().min(len.min(wid) / 2.0);
                    Some(Shape::Rect { c: centre, len, wid, r, angle: get(Role::PocketAngle).unwrap_or(0.0) })
                }
                _ => None,
            },
            Meaning::MillSlot => match (get(Role::PocketLength), get(Role::Width)) {
                (Some(len), Some(wid)) if wid > 0.0 && len > wid => {
                    Some(Shape::Slot { c: centre, len, wid, angle: get(Role::PocketAngle).unwrap_or(0.0) })
                }
                _ => None,
            },
            // Its radius, or its diameter as its width (Heidenhain Q223).
            _ => get(Role::PocketRadius).or(get(Role::Width).map(|d| d / 2.0)).filter(|r| *r > 0.0).map(|r| Shape::Circle { c: centre, r }),
        };
        let (Some(surface), Some(shape)) = (get(Role::ReferencePlane), shape) else {
            let msg = format!("{name} states no reference plane or no size: kept as intent only, its moves are not expanded");
            let mut d = Diagnostic::new(Code::CycleIncomplete, range, msg);
            d.severity = Severity::Warning;
            diags.push(d);
            return;
        };
        let floor = match (get(Role::DepthRelative), get(Role::Depth)) {
            (Some(d), _) => surface - d.abs(),
            (None, Some(d)) => d,
            (None, None) => {
                let mut d = Diagnostic::new(Code::CycleIncomplete, range, format!("{name} has no depth: kept as intent only"));
                d.severity = Severity::Warning;
                diags.push(d);
                return;
            }
        };
        let safe = surface + get(Role::SafetyDistance).unwrap_or(0.0).abs();
        let retract = get(Role::RetractPlane).or(get(Role::RetractDistance).map(|d| surface + d)).unwrap_or(safe).max(safe);
        let mut d = Diagnostic::new(
            Code::Unsupported,
            range,
            format!(
                "{name}: the pocket's finishing pass on its wall is written as the cycle's moves; its roughing passes are not expanded"
            ),
        );
        d.severity = Severity::Note;
        self.limited(diags, "pocket-passes", d);
        let shapes = match slots_on_circle(&shape, &get) {
            Ok(Some(slots)) => slots,
            Ok(None) => vec![shape],
            Err(problem) => {
                let msg = format!("{name}: {problem}: kept as intent only, its moves are not expanded");
                let mut d = Diagnostic::new(Code::CycleIncomplete, range, msg);
                d.severity = Severity::Warning;
                diags.push(d);
                return;
            }
        };
        // One bound for the whole run, as a pattern's positions have one: a modal call repeats the
        // cycle at each of a pattern's positions, and each call may lay a circle of slots.
        if self.pocket_passes + shapes.len() > MAX_POCKET_PASSES {
            let msg = format!(
                "{name}: more than {MAX_POCKET_PASSES} pocket and slot passes in the program: this call is kept as intent only, its moves are not expanded"
            );
            let mut d = Diagnostic::new(Code::Unsupported, range, msg);
            d.severity = Severity::Warning;
            self.limited(diags, "cycle-not-expanded", d);
            return;
        }
        self.pocket_passes += shapes.len();
        for shape in shapes {
            self.pocket_pass(name, shape, surface, safe, floor, retract, sink);
        }
    }

    /// One pocket's finishing pass between its `MillCycle` markers: down at its centre, round
    /// its wall under cutter compensation, up to the retract plane.
    #[allow(clippy::too_many_arguments)]
    fn pocket_pass(&mut self, name: &str, shape: Shape, surface: f64, safe: f64, floor: f64, retract: f64, sink: &mut dyn CanonSink) {
        let (a0, a1, n) = self.st.plane.axes();
        let at = |me: &Self, x: f64, y: f64, z: f64| {
            let mut p = me.st.pos;
            (p[a0], p[a1], p[n]) = (x, y, z);
            p
        };
        let (cx, cy) = match shape {
            Shape::Rect { c, .. } | Shape::Circle { c, .. } | Shape::Slot { c, .. } => (c[0], c[1]),
        };
        self.emit(sink, CanonOp::Setting(Setting::MillCycle(Some(name.to_owned()))));
        self.emit(sink, CanonOp::Setting(Setting::CycleSurface(surface)));
        let over = self.st.pos[n].max(retract);
        self.go_to(sink, at(self, self.st.pos[a0], self.st.pos[a1], over), false);
        self.go_to(sink, at(self, cx, cy, over), false);
        self.go_to(sink, at(self, cx, cy, safe), false);
        self.go_to(sink, at(self, cx, cy, floor), true);
        self.emit(sink, CanonOp::Setting(Setting::CutterComp(Some(CompOn { left: true, number: None, radius: None, tip: None }))));
        match shape {
            Shape::Circle { c, r } => {
                let start = [c[0] + r, c[1]];
                self.go_to(sink, at(self, start[0], start[1], floor), true);
                let half = [c[0] - r, c[1]];
                self.arc_to(sink, half, c, floor, true);
                self.arc_to(sink, start, c, floor, true);
            }
            Shape::Slot { c, len, wid, angle } => {
                // Counter-clockwise from the middle of the side at -width/2: along it, round the
                // far end, back along the other side, round the near end.
                let (s, co) = angle.to_radians().sin_cos();
                let to_plane = |u: f64, v: f64| [c[0] + u * co - v * s, c[1] + u * s + v * co];
                let (e, hw) = (len / 2.0 - wid / 2.0, wid / 2.0);
                let start = to_plane(0.0, -hw);
                self.go_to(sink, at(self, start[0], start[1], floor), true);
                for (k, (u0, v0)) in [(e, -hw), (-e, hw)].into_iter().enumerate() {
                    let side = to_plane(u0, v0);
                    self.go_to(sink, at(self, side[0], side[1], floor), true);
                    let (end, centre) = (to_plane(u0, -v0), to_plane(u0, 0.0));
                    self.arc_to(sink, end, centre, floor, true);
                    if k == 1 {
                        self.go_to(sink, at(self, start[0], start[1], floor), true);
                    }
                }
            }
            Shape::Rect { c, len, wid, r, angle } => {
                let (s, co) = angle.to_radians().sin_cos();
                let to_plane = |u: f64, v: f64| [c[0] + u * co - v * s, c[1] + u * s + v * co];
                let (hl, hw) = (len / 2.0, wid / 2.0);
                let start = to_plane(hl, 0.0);
                self.go_to(sink, at(self, start[0], start[1], floor), true);
                // Counter-clockwise from the middle of the side at +length/2: each side, then its
                // corner's arc about the point `r` in from both sides.
                let corners = [(hl, hw), (-hl, hw), (-hl, -hw), (hl, -hw)];
                for (k, &(u, v)) in corners.iter().enumerate() {
                    let (su, sv) = (u.signum(), v.signum());
                    // Where the side before the corner ends, and where the next side begins.
                    let (end, begin) = if k % 2 == 0 { ((u, v - sv * r), (u - su * r, v)) } else { ((u - su * r, v), (u, v - sv * r)) };
                    let e = to_plane(end.0, end.1);
                    self.go_to(sink, at(self, e[0], e[1], floor), true);
                    if r > 0.0 {
                        let b = to_plane(begin.0, begin.1);
                        let centre = to_plane(u - su * r, v - sv * r);
                        self.arc_to(sink, b, centre, floor, true);
                    }
                }
                self.go_to(sink, at(self, start[0], start[1], floor), true);
            }
        }
        self.emit(sink, CanonOp::Setting(Setting::CutterComp(None)));
        let p = self.st.pos;
        self.go_to(sink, at(self, p[a0], p[a1], retract), false);
        self.emit(sink, CanonOp::Setting(Setting::MillCycle(None)));
    }

    /// A bore milled in a helix (`mill-bore`: Heidenhain 208 BORE MILLING) about the position
    /// in force, as the TNC 640 cycles manual describes its run: to the set-up clearance above
    /// the surface, out to the wall of the nominal diameter, a helix down by the infeed per
    /// turn (`pitch`) to the depth, a full circle at the floor, back to the centre and up to
    /// the set-up clearance, then the 2nd one. Climb milling (`machining-type` positive or not
    /// given) runs counter-clockwise under left compensation, as for a clockwise spindle; the
    /// wall is written as programmed under cutter compensation, as the pockets' are.
    pub(super) fn mill_bore(
        &mut self,
        name: &str,
        args: &[(Role, f64)],
        range: TextRange,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let get = |r: Role| args.iter().rev().find(|(a, _)| *a == r).map(|(_, v)| *v);
        let (Some(diameter), Some(depth)) = (get(Role::Width).filter(|d| *d > 0.0), get(Role::DepthRelative)) else {
            let mut d =
                Diagnostic::new(Code::CycleIncomplete, range, format!("{name} states no diameter or no depth: kept as intent only"));
            d.severity = Severity::Warning;
            diags.push(d);
            return;
        };
        if depth == 0.0 {
            // The TNC does not run a cycle of depth 0.
            return;
        }
        let (a0, a1, n) = self.st.plane.axes();
        let c = [self.st.pos[a0], self.st.pos[a1]];
        let r = diameter / 2.0;
        let surface = get(Role::ReferencePlane).unwrap_or(0.0);
        let floor = surface - depth.abs();
        let safe = surface + get(Role::SafetyDistance).unwrap_or(0.0).abs();
        let clear = get(Role::RetractDistance).map_or(safe, |d| (surface + d).max(safe));
        let ccw = get(Role::MachiningType).is_none_or(|v| v >= 0.0);
        let pitch = get(Role::Pitch).map(f64::abs).filter(|p| *p > 0.0).unwrap_or(safe - floor);
        // Half turns, each as deep as the others, down to the floor; counted as a float first, so
        // that an infeed per turn of a micron over a deep bore, or a tiny one, is not a loop of
        // billions. A bound on each call, and a larger one for the whole run (a modal call
        // repeats the cycle at each of a pattern's positions: 84 bores of 120 half turns each
        // are a valid program, a million half turns are no longer worth drawing).
        let halves = (((safe - floor) / (pitch / 2.0)) - 1e-9).ceil().max(1.0);
        let call = !halves.is_finite() || halves > MAX_HELIX_HALVES as f64;
        if call || self.helix_halves as f64 + halves > MAX_HELIX_HALVES_RUN as f64 {
            let msg = if call {
                format!(
                    "{name}: more than {MAX_HELIX_HALVES} half turns in one bore milled in a helix: this call is kept as intent only, its moves are not expanded"
                )
            } else {
                format!(
                    "{name}: more than {MAX_HELIX_HALVES_RUN} half turns of bores milled in a helix in the program: this call is kept as intent only, its moves are not expanded"
                )
            };
            let mut d = Diagnostic::new(Code::Unsupported, range, msg);
            d.severity = Severity::Warning;
            self.limited(diags, "cycle-not-expanded", d);
            return;
        }
        let halves = halves as usize;
        self.helix_halves += halves;
        let at = |me: &Self, x: f64, y: f64, z: f64| {
            let mut p = me.st.pos;
            (p[a0], p[a1], p[n]) = (x, y, z);
            p
        };
        self.emit(sink, CanonOp::Setting(Setting::HoleMilled(format!("Ø{diameter} from {surface} to {floor}"))));
        self.emit(sink, CanonOp::Setting(Setting::MillCycle(Some(name.to_owned()))));
        self.emit(sink, CanonOp::Setting(Setting::CycleSurface(surface)));
        if let Some(f) = get(Role::PlungeFeed).filter(|f| *f > 0.0 && *f != self.st.feed) {
            self.st.feed = f;
            self.emit(sink, CanonOp::SetFeedRate(f));
        }
        let over = self.st.pos[n].max(clear);
        if self.st.pos[n] < over {
            self.go_to(sink, at(self, c[0], c[1], over), false);
        }
        self.go_to(sink, at(self, c[0], c[1], safe), false);
        self.emit(sink, CanonOp::Setting(Setting::CutterComp(Some(CompOn { left: ccw, number: None, radius: None, tip: None }))));
        let start = [c[0] + r, c[1]];
        let half = [c[0] - r, c[1]];
        self.go_to(sink, at(self, start[0], start[1], safe), true);
        let drop = (safe - floor) / halves as f64;
        for k in 1..=halves {
            let end = if k % 2 == 1 { half } else { start };
            let level = if k == halves { floor } else { safe - drop * k as f64 };
            self.arc_to(sink, end, c, level, ccw);
        }
        // The full circle at the floor, from where the helix ended.
        let (here, there) = if halves % 2 == 1 { (half, start) } else { (start, half) };
        self.arc_to(sink, there, c, floor, ccw);
        self.arc_to(sink, here, c, floor, ccw);
        self.emit(sink, CanonOp::Setting(Setting::CutterComp(None)));
        self.go_to(sink, at(self, c[0], c[1], floor), true);
        self.go_to(sink, at(self, c[0], c[1], safe), false);
        if clear > safe {
            self.go_to(sink, at(self, c[0], c[1], clear), false);
        }
        self.emit(sink, CanonOp::Setting(Setting::MillCycle(None)));
    }

    /// An arc in the plane to `end` about `centre` (counter-clockwise or not), ending at `level`
    /// on the normal axis (a helix where that is not where it starts).
    pub(super) fn arc_to(&mut self, sink: &mut dyn CanonSink, end: [f64; 2], centre: [f64; 2], level: f64, ccw: bool) {
        let (a0, a1, n) = self.st.plane.axes();
        let abc = [self.st.pos[3], self.st.pos[4], self.st.pos[5]];
        self.emit(
            sink,
            CanonOp::ArcFeed {
                first_end: end[0],
                second_end: end[1],
                first_axis: centre[0],
                second_axis: centre[1],
                rotation: if ccw { 1 } else { -1 },
                axis_end: level,
                abc,
            },
        );
        (self.st.pos[a0], self.st.pos[a1], self.st.pos[n]) = (end[0], end[1], level);
    }
}

/// The most slots one cycle call is expanded into: a circle of slots holds a few dozen at most,
/// and a modal call repeats the call at each of up to 10 000 pattern positions.
const MAX_SLOTS: f64 = 100.0;

/// The most pocket and slot passes one run expands in all: as many as a pattern has positions
/// at most. Past it a call is kept as intent only (a modal slot cycle over a large pattern
/// would otherwise write up to a million passes).
const MAX_POCKET_PASSES: usize = 10_000;

/// The most half turns one bore milled in a helix expands into (each half turn an arc): as
/// many as the pocket and slot passes. Past it the call is kept as intent only (an infeed per
/// turn of 0.001 mm down a bore 100 mm deep would otherwise write 200 000 arcs).
const MAX_HELIX_HALVES: usize = 10_000;

/// The most half turns the bores milled in a helix of one run expand into in all: a modal call
/// repeats the cycle at each of a pattern's positions (84 bores of 120 half turns, 10 080, is an
/// ordinary program); past a million the later calls are kept as intent only.
const MAX_HELIX_HALVES_RUN: usize = 1_000_000;

/// Slots on a circle (Siemens `SLOT1`, "slots on a circle" in the 840D cycles manual): `NUM`
/// slots of the length and width the slot states, each along the radius of the circle about
/// the centre `CPA CPO` of radius `RAD`, the first at the start angle `STA1` from the plane's
/// first axis and each next one `INDA` further (`INDA` 0: spread evenly round the full
/// circle, as `HOLES2` reads it). Each slot is centred on the circle [the manual's figure as
/// read; unconfirmed on a control]. `None` where the cycle names no circle (Heidenhain 253:
/// one slot at its centre).
fn slots_on_circle(shape: &Shape, get: &impl Fn(Role) -> Option<f64>) -> Result<Option<Vec<Shape>>, String> {
    let Shape::Slot { c, len, wid, .. } = *shape else { return Ok(None) };
    let (Some(radius), Some(count)) = (get(Role::PatternRadius), get(Role::PatternCount)) else { return Ok(None) };
    if count.fract() != 0.0 || !(1.0..=MAX_SLOTS).contains(&count) {
        return Err(format!("the number of slots must be a whole number from 1 to {MAX_SLOTS}, not {count}"));
    }
    let n = count as usize;
    let start = get(Role::PatternAngle).unwrap_or(0.0);
    let step = match get(Role::PatternStepAngle).unwrap_or(0.0) {
        0.0 => 360.0 / n as f64,
        a => a,
    };
    Ok(Some(
        (0..n)
            .map(|i| {
                let angle = start + i as f64 * step;
                let (s, co) = angle.to_radians().sin_cos();
                Shape::Slot { c: [c[0] + radius * co, c[1] + radius * s], len, wid, angle }
            })
            .collect(),
    ))
}

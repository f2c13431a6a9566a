//! Motion: straight moves (a feed synchronised with the spindle as the target's thread),
//! arcs (the centre brought within the target's tolerance, extra turns and R-form full
//! circles written piece by piece), the tilted working plane the moves run on, and what the
//! target cannot state of a move (a NURBS feed's spline, a tilted tool axis), said.
//!
//! The door: [`Post::motion_op`] for the motion ops, and [`Post::straight`], which
//! [`Post::op`] calls at once for the common straight move.

use super::{EPS, Post, ROUNDED_NOTE, Vals};
use crate::canon::{Canon, CanonOp, Frame, Units};
use crate::diag::Code;
use crate::dialect::output::Value;

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// Writes a motion op: a straight move, an arc, a NURBS feed (its end: said), the tool
    /// axis (said where it tilts).
    pub(super) fn motion_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::StraightTraverse(p) => self.straight(canon, p, true),
            CanonOp::StraightFeed(p) => self.straight(canon, p, false),
            CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, abc, .. } => {
                self.check_axis(canon, *abc);
                let (a, b, n) = self.plane.axes();
                let mut end = [0.0; 3];
                end[a] = self.to_out(*first_end) + self.g92[a];
                end[b] = self.to_out(*second_end) + self.g92[b];
                end[n] = self.to_out(*axis_end) + self.g92[n];
                let mut centre = [0.0; 3];
                centre[a] = self.to_out(*first_axis) + self.g92[a];
                centre[b] = self.to_out(*second_axis) + self.g92[b];
                centre[n] = end[n];
                self.arc(canon, end, centre, *rotation > 0, rotation.unsigned_abs());
            }
            CanonOp::ToolAxis(v) => {
                self.source_axis = *v;
                let along_z = v[0].abs() < 1e-9 && v[1].abs() < 1e-9 && v[2] > 0.0;
                if self.tcp || (!self.source_tcp && !along_z) {
                    // The rotary axes of the next move turn the tool: checked there. Without
                    // tool centre point control in the source as in the output, the source
                    // indexed its rotary axes to this axis (3+2 by rotary positioning): the
                    // same rotary words written give it, and only an axis they do not give
                    // is unwritable.
                    self.axis_check = Some(*v);
                } else if !along_z {
                    // The source's moves are the tool tip's under tool centre point control,
                    // which the target does not write.
                    self.no_tool_orientation(canon, *v);
                }
            }
            CanonOp::WorkPlane(f) => self.work_plane(canon, f.as_deref()),
            CanonOp::NurbsFeed { points, end } => {
                self.note(
                    Code::PostUnwritable,
                    canon,
                    "nurbs",
                    format!(
                        "a NURBS feed ({points} control points) is not written: the canonical ops keep its end point, not its control points and weights, so no target can state it as a spline"
                    ),
                );
                let q = self.point(end);
                self.moved(q);
            }
            // Not a motion op: [`Post::other_op`] hands none here.
            _ => {}
        }
    }

    /// A tilted working plane, or the untilted one again: the target's `work-plane` with the
    /// plane's origin and its rotation in the angles the template takes, or its
    /// `work-plane-reset`; unwritable where it has none, or where its template states no origin
    /// and the plane's is not the program zero. The moves that follow stay in the plane's
    /// coordinates, as the canon has them.
    fn work_plane(&mut self, canon: &Canon, f: Option<&Frame>) {
        let ev = if f.is_some() { "work-plane" } else { "work-plane-reset" };
        let out = self.out;
        let Some((t, _)) = out.template(ev) else {
            if let Some(f) = f {
                let z = f.axis();
                self.note(
                    Code::PostUnwritable,
                    canon,
                    "work-plane",
                    format!(
                        "the working plane tilts (tool axis I{:.4} J{:.4} K{:.4}): the target's output rules write no tilted plane (`work-plane`), so the moves that follow are written in the tilted plane's coordinates as they stand",
                        z[0], z[1], z[2]
                    ),
                );
            } else if self.tilt.is_some() {
                self.note(
                    Code::PostUnwritable,
                    canon,
                    "work-plane-reset",
                    "the untilted plane is not written: the target's output rules have no `work-plane-reset`",
                );
            }
            return;
        };
        let mut vals = Vals::new();
        let next = f.map(|f| Frame { origin: self.point(&f.origin), rotation: f.rotation });
        if let Some(n) = &next {
            let states_origin = [Value::PlaneX, Value::PlaneY, Value::PlaneZ].iter().any(|v| t.uses(*v));
            if !states_origin && n.origin.iter().any(|v| v.abs() > EPS) {
                let o = n.origin;
                self.note(
                    Code::PostUnwritable,
                    canon,
                    "work-plane-origin",
                    format!(
                        "the tilted plane's origin X{:.4} Y{:.4} Z{:.4} is not written: the target's `work-plane` states none",
                        o[0], o[1], o[2]
                    ),
                );
                return;
            }
            vals.set(Value::PlaneX, n.origin[0]).set(Value::PlaneY, n.origin[1]).set(Value::PlaneZ, n.origin[2]);
            for (vs, angles) in [
                ([Value::SpatialA, Value::SpatialB, Value::SpatialC], n.spatial_angles()),
                ([Value::EulerA, Value::EulerB, Value::EulerC], n.euler_zxz()),
                ([Value::TurnA, Value::TurnB, Value::TurnC], n.axis_by_axis_xyz()),
            ] {
                for (v, a) in vs.into_iter().zip(angles) {
                    vals.set(v, a);
                }
            }
        }
        if !self.event(ev, &mut vals) {
            self.note(Code::PostUnwritable, canon, ev, format!("the target's `{ev}` cannot state this plane"));
            return;
        }
        let (old, new) = (self.tilt.unwrap_or(Frame::IDENTITY), next.unwrap_or(Frame::IDENTITY));
        // The control restates its position in the new plane, as the interpreter does: an
        // axis the next move leaves as it is stays unwritten, as in the source.
        self.pos = new.from_base(old.to_base(self.pos));
        self.tilt = next;
        for (k, name) in ["X", "Y", "Z"].into_iter().enumerate() {
            let w = self.key_of(name, self.pos[k]);
            self.set_written(k, w);
        }
    }

    /// Tool centre point control on or off, by the target's `tcp-on` and `tcp-off`. A target
    /// without them writes the moves without it: where the tool axis then tilts, the marker
    /// says it is unwritable; along Z, the tool tip's moves are the same.
    ///
    /// A target whose code for it carries the length offset (Fanuc `G43.4 H1`, ended by
    /// `G43 H1`) says the offset in force with it, instead of a length offset still waiting for
    /// the next move; where the length offset was cancelled already (`G49`), that ended it.
    pub(super) fn tool_centre_point(&mut self, canon: &Canon, on: bool) {
        self.source_tcp = on;
        let ev = if on { "tcp-on" } else { "tcp-off" };
        let mut vals = Vals::new();
        let takes_h = self.out.template(ev).is_some_and(|(t, _)| t.uses(Value::H));
        if takes_h {
            vals.set(Value::H, f64::from(self.length));
        }
        let said = takes_h && !on && self.length == 0;
        if self.out.template(ev).is_some() && (on || self.tcp) && !said {
            if takes_h {
                self.mods.retain(|(g, _)| g != "length");
            }
            if self.event(ev, &mut vals) {
                self.tcp = on;
            }
        }
        if !on {
            self.tcp = false;
            self.axis_check = None;
        } else if !self.tcp {
            // The rotary axes indexed the tool axis before: under tool centre point control
            // the moves that follow are the tool tip's on the turned part, which the target
            // does not write.
            let v = self.source_axis;
            if v[0].abs() > 1e-9 || v[1].abs() > 1e-9 || v[2] <= 0.0 {
                self.no_tool_orientation(canon, v);
            }
        }
    }

    /// Under tool centre point control written, or where source and output index the rotary
    /// axes without it, the tool axis the source turned to must be the one the rotary axes
    /// written (`abc`, degrees) give; otherwise (a tool axis stated as a vector, `A3=` or
    /// CLDATA `GOTO/x,y,z,i,j,k`) it is not written.
    fn check_axis(&mut self, canon: &Canon, abc: [f64; 3]) {
        let Some(v) = self.axis_check.take() else { return };
        let got = crate::canon::rotary_tool_axis(abc);
        if (0..3).any(|k| (got[k] - v[k]).abs() > 1e-6) {
            self.note(
                Code::PostUnwritable,
                canon,
                "tool-axis",
                format!(
                    "the tool axis tilts to I{:.4} J{:.4} K{:.4}, which the rotary axes written do not give: the target's output rules write no tool orientation vector",
                    v[0], v[1], v[2]
                ),
            );
        }
    }

    /// Says the source tilts the tool axis to `v` under tool centre point control, which the
    /// target's output rules cannot write (only the tool tip's moves).
    fn no_tool_orientation(&mut self, canon: &Canon, v: [f64; 3]) {
        self.note(
            Code::PostUnwritable,
            canon,
            "tool-axis",
            format!(
                "the tool axis tilts to I{:.4} J{:.4} K{:.4}: the target's output rules write no tool orientation (5-axis), only the tool tip's moves",
                v[0], v[1], v[2]
            ),
        );
    }

    /// Writes a straight move to `p` (program coordinates, rotary axes in degrees), at
    /// rapid or at the feed; a move of a hole drilled as a cycle is the cycle's.
    pub(super) fn straight(&mut self, canon: &Canon, p: &[f64; 6], rapid: bool) {
        let event = if rapid { "rapid" } else { "feed" };
        self.check_axis(canon, [p[3], p[4], p[5]]);
        let rotary = [Value::A, Value::B, Value::C];
        let writes = |v: Value| self.out.template(event).is_some_and(|(t, _)| t.uses(v));
        if (0..3).any(|k| p[3 + k].abs() > EPS && !writes(rotary[k])) {
            self.note(
                Code::PostUnwritable,
                canon,
                "rotary",
                "a rotary axis (A, B, C) moves, and the target's output rules do not write it",
            );
        }
        let q = self.point(p);
        if self.in_cycle {
            self.moved(q);
            return;
        }
        self.cancel_cycle();
        // The moves' values, kept between moves: each sets all it uses (NaN: absent).
        let mut vals = self.move_vals.take().unwrap_or_else(|| Box::new(Vals::new()));
        vals.set(Value::X, q[0]).set(Value::Y, q[1]).set(Value::Z, q[2]).set(Value::Pitch, f64::NAN);
        // A feed synchronised with the spindle: the target's thread move, else said.
        let mut thread = false;
        let event = match self.sync {
            Some(pitch) if !rapid => {
                thread = true;
                vals.set(Value::Pitch, pitch);
                if self.out.template("thread").is_none() {
                    self.note(
                        Code::PostUnwritable,
                        canon,
                        "thread",
                        "a thread (G33: a feed synchronised with the spindle) is not written: the target's output rules have no `thread` template",
                    );
                    self.moved(q);
                    return;
                }
                "thread"
            }
            _ => event,
        };
        // Rotary axes in degrees, not scaled.
        vals.set(Value::A, p[3]).set(Value::B, p[4]).set(Value::C, p[5]);
        vals.set(Value::F, if rapid { f64::NAN } else { self.feed });
        self.unknown_out(&mut vals);
        let template = match (thread, rapid) {
            (true, _) => self.out.template(event).map(|(t, _)| t),
            (false, true) => self.moves.0,
            (false, false) => self.moves.1,
        };
        if let Some(t) = template {
            self.rules(event, true);
            self.render(t, &mut vals, false, true);
            self.rules(event, false);
        } else {
            self.note(Code::PostUnwritable, canon, event, format!("the target's output rules have no `{event}` template"));
        }
        self.move_vals = Some(vals);
        self.moved(q);
    }

    /// Writes an arc to `end` about `centre` (target units, work offset frame), counter-
    /// clockwise or not, going round `turns` times (1: once, a whole turn at most); an arc
    /// of a hole drilled as a cycle is the cycle's.
    #[allow(clippy::too_many_arguments)]
    fn arc(&mut self, canon: &Canon, end: [f64; 3], centre: [f64; 3], ccw: bool, turns: u32) {
        if self.in_cycle {
            self.moved(end);
            return;
        }
        self.cancel_cycle();
        let (a, b, n) = self.plane.axes();
        let start = self.pos;
        let event = if ccw { "arc-ccw" } else { "arc-cw" };
        let Some((t, _)) = self.out.template(event) else {
            self.note(Code::PostUnwritable, canon, event, format!("the target's output rules have no `{event}` template"));
            self.moved(end);
            return;
        };
        let centre = self.arc_centre(canon, start, end, centre, a, b);
        let r = ((start[a] - centre[a]).hypot(start[b] - centre[b])).max(EPS);
        let ang = |p: [f64; 3]| (p[b] - centre[b]).atan2(p[a] - centre[a]);
        let (sweep, same) = arc_sweep(start, end, centre, a, b, ccw);
        let total = sweep.abs() + std::f64::consts::TAU * f64::from(turns.saturating_sub(1));
        let uses_r = t.uses(Value::R);
        // Pieces: the extra full turns, then the last arc; an R-form full circle goes in halves.
        let mut pieces: Vec<(f64, bool)> = Vec::new();
        for _ in 1..turns.max(1) {
            pieces.push((std::f64::consts::TAU, true));
        }
        pieces.push((sweep.abs(), same));
        let mut from = start;
        let mut done = 0.0;
        for (piece, full) in pieces {
            let halves = if uses_r && (full || piece > std::f64::consts::TAU - 1e-9) { 2 } else { 1 };
            for h in 0..halves {
                let part = piece / f64::from(halves);
                done += part;
                let frac = done / total;
                let a0 = ang(from);
                let a1 = a0 + if ccw { part } else { -part };
                let mut to = [0.0; 3];
                let last = (done - total).abs() < 1e-9;
                if last && h + 1 == halves {
                    to = end;
                } else {
                    to[a] = centre[a] + r * a1.cos();
                    to[b] = centre[b] + r * a1.sin();
                    to[n] = start[n] + (end[n] - start[n]) * frac;
                }
                let mut vals = Vals::new();
                vals.set(Value::X, to[0]).set(Value::Y, to[1]).set(Value::Z, to[2]).set(Value::F, self.feed);
                let ij = [Value::I, Value::J, Value::K];
                let cc = [Value::Cx, Value::Cy, Value::Cz];
                for k in [a, b] {
                    vals.set(ij[k], centre[k] - from[k]);
                    vals.set(cc[k], centre[k]);
                }
                vals.set(Value::R, if part > std::f64::consts::PI + 1e-9 { -r } else { r });
                self.unknown_out(&mut vals);
                // A full circle: its end words must be written even though unchanged (those
                // of axes whose position is unknown are not written at all).
                if halves == 1 && (full || (to[a] - from[a]).hypot(to[b] - from[b]) < 1e-7) {
                    for k in 0..3 {
                        if self.known & 1 << k != 0 {
                            self.set_written(k, None);
                        }
                    }
                }
                self.rules(event, true);
                self.render(t, &mut vals, false, true);
                self.rules(event, false);
                from = to;
                self.moved(to);
            }
        }
    }

    /// The centre an arc from `start` to `end` about `centre` (on its plane's axes `a`, `b`)
    /// is written with: moved where the target may not take the difference of its radii at
    /// start and end, and said where they differ by more than [`ROUNDED_NOTE`].
    fn arc_centre(&mut self, canon: &Canon, start: [f64; 3], end: [f64; 3], centre: [f64; 3], a: usize, b: usize) -> [f64; 3] {
        // The source's tolerance let the two radii differ; the target's may not. The centre
        // goes onto the perpendicular bisector of the chord (moving it by about the radius
        // error), so both radii agree whatever the target checks.
        // Where the target takes the difference, rounding of the written numbers included
        // (two steps), the centre stays: moved onto the bisector of a short chord it would
        // move far more than the radius error.
        let mut centre = centre;
        let (dx, dy) = (end[a] - start[a], end[b] - start[b]);
        let chord = dx.hypot(dy);
        let step = self.out.formats.iter().find(|f| f.name == "X").map_or(1e-3, |f| {
            let d = if self.opts.units == Units::Inch { f.inch_decimals } else { f.decimals };
            10f64.powi(-i32::from(d))
        });
        let tolerance = if self.opts.units == Units::Inch { self.opts.arc_tolerance.1 } else { self.opts.arc_tolerance.0 };
        let radius_error = ((start[a] - centre[a]).hypot(start[b] - centre[b]) - (end[a] - centre[a]).hypot(end[b] - centre[b])).abs();
        if chord > 1e-9 && radius_error + 2.0 * step > tolerance {
            let (mx, my) = ((start[a] + end[a]) / 2.0, (start[b] + end[b]) / 2.0);
            let (ux, uy) = (-dy / chord, dx / chord);
            let t = (centre[a] - mx) * ux + (centre[b] - my) * uy;
            centre[a] = mx + t * ux;
            centre[b] = my + t * uy;
            let mm = radius_error * self.opts.units.to_mm();
            if mm > ROUNDED_NOTE {
                self.note(
                    Code::PostArcCentre,
                    canon,
                    "arc-centre",
                    format!(
                        "the arc's radii at start and end differ by {mm:.4} mm, more than the target takes: its centre is moved so that both agree, and its path by up to that much (the first such arc; others may follow)"
                    ),
                );
            }
        }
        centre
    }
}

/// The angle an arc from `start` to `end` about `centre` (on its plane's axes `a`, `b`)
/// sweeps, counter-clockwise (positive) or not, a whole turn where it ends where it starts;
/// and whether it does.
fn arc_sweep(start: [f64; 3], end: [f64; 3], centre: [f64; 3], a: usize, b: usize, ccw: bool) -> (f64, bool) {
    let ang = |p: [f64; 3]| (p[b] - centre[b]).atan2(p[a] - centre[a]);
    let mut sweep = ang(end) - ang(start);
    if ccw {
        while sweep <= 1e-12 {
            sweep += std::f64::consts::TAU;
        }
    } else {
        while sweep >= -1e-12 {
            sweep -= std::f64::consts::TAU;
        }
    }
    let same = (end[a] - start[a]).hypot(end[b] - start[b]) < 1e-7;
    if same {
        sweep = if ccw { std::f64::consts::TAU } else { -std::f64::consts::TAU };
    }
    (sweep, same)
}

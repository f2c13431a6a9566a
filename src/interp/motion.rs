//! Straight and circular motion.

use super::{Interpreter, Spindle};
use crate::canon::{CanonOp, CanonSink, DistanceMode, Plane, Units};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::syntax::{Block, WordMode};
use crate::text::TextRange;

/// Offset roles along X, Y and Z.
const OFFSETS: [Role; 3] = [Role::I, Role::J, Role::K];

impl Interpreter<'_> {
    /// The end point of a move: axis words in the distance mode, in program coordinates.
    pub(super) fn target(&self) -> [f64; 6] {
        let machine = self.codes.iter().any(|&(c, _)| self.code(c).meaning == Meaning::MachineCoords);
        if machine && self.st.wcs_rotation[self.st.wcs as usize - 1] != 0.0 {
            // In a rotated system the machine point maps to program X and Y together.
            let mut m = self.machine_pos();
            for (i, &role) in Role::AXES.iter().enumerate() {
                if let Some(v) = self.slot(role) {
                    m[i] = v;
                }
            }
            let mut t = self.program_pos(m);
            if self.slot(Role::Z).is_some() {
                t[2] -= self.st.tool_offset;
            }
            return t;
        }
        let mut t = self.st.pos;
        for (i, &role) in Role::AXES.iter().enumerate() {
            if let Some(slot) = self.slots[role as usize] {
                let v = slot.value;
                let incremental = match slot.mode {
                    WordMode::Modal => self.st.distance == DistanceMode::Incremental,
                    WordMode::Absolute => false,
                    WordMode::Incremental => true,
                };
                t[i] = if machine {
                    // The tool length offset moves the controlled point along Z.
                    let tlo = if i == 2 { self.st.tool_offset } else { 0.0 };
                    v - self.st.wcs_offsets[self.st.wcs as usize - 1][i] - self.st.g92[i] - tlo
                } else if incremental {
                    self.st.pos[i] + v
                } else {
                    v
                };
            }
        }
        if self.slots[Role::PolarRadius as usize].is_some() || self.slots[Role::PolarAngle as usize].is_some() {
            self.polar_target(&mut t);
        }
        t
    }

    /// `LP PR+30 PA+45`, `CP IPA+90`: the end point in the plane from its distance to the pole
    /// and its angle about it; a missing one keeps the current point's, an incremental one
    /// (`IPR`, `IPA`) adds to it.
    fn polar_target(&self, t: &mut [f64; 6]) {
        let (a0, a1, _) = self.st.plane.axes();
        let (px, py) = self.st.pole;
        let (dx, dy) = (self.st.pos[a0] - px, self.st.pos[a1] - py);
        let polar = |role: Role, current: f64| match self.slots[role as usize] {
            None => current,
            Some(s) if self.incremental(role) => current + s.value,
            Some(s) => s.value,
        };
        let r = polar(Role::PolarRadius, dx.hypot(dy));
        let a = polar(Role::PolarAngle, dy.atan2(dx).to_degrees()).to_radians();
        t[a0] = px + r * a.cos();
        t[a1] = py + r * a.sin();
    }

    /// Whether the axis word for `role` is incremental (per word, or by G91).
    pub(super) fn incremental(&self, role: Role) -> bool {
        match self.slots[role as usize].map(|s| s.mode) {
            Some(WordMode::Absolute) => false,
            Some(WordMode::Incremental) => true,
            _ => self.st.distance == DistanceMode::Incremental,
        }
    }

    pub(super) fn motion(&mut self, def: &CodeDef, range: TextRange, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.motions += 1;
        let rapid_block = !self.codes.is_empty() && self.codes.iter().any(|&(c, _)| self.code(c).meaning == Meaning::RapidBlock);
        match def.meaning {
            Meaning::Rapid | Meaning::Linear if rapid_block => {
                let t = self.target();
                self.note_tangent(t);
                self.emit(sink, CanonOp::StraightTraverse(t));
                self.st.pos = t;
            }
            Meaning::Rapid => {
                let t = self.target();
                self.note_tangent(t);
                self.emit(sink, CanonOp::StraightTraverse(t));
                self.st.pos = t;
            }
            Meaning::Linear => {
                self.check_technology(def, block.range, diags);
                let t = self.target();
                if self.st.inverse_time {
                    let length = (0..3).map(|i| (t[i] - self.st.pos[i]).powi(2)).sum::<f64>().sqrt();
                    if !self.inverse_time_feed(def, length, block, sink, diags) {
                        return;
                    }
                }
                self.note_tangent(t);
                self.emit(sink, CanonOp::StraightFeed(t));
                self.st.pos = t;
            }
            Meaning::ArcCw | Meaning::ArcCcw | Meaning::ArcPole | Meaning::ArcRadius | Meaning::ArcTangent => {
                self.arc(def, range, block, sink, diags)
            }
            _ => self.cycle(def, range, block, sink, diags),
        }
    }

    /// In inverse-time mode (G93), sets the feed rate that makes a move of `length` last
    /// 1/F minutes. False when the block lacks the F it needs.
    fn inverse_time_feed(
        &mut self,
        def: &CodeDef,
        length: f64,
        block: &Block,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) -> bool {
        if !self.st.inverse_time {
            return true;
        }
        let Some(f) = self.slot(Role::F) else {
            diags.push(Diagnostic::new(
                Code::MissingParameter,
                block.range,
                format!("{} in inverse-time mode (G93) needs an F word in every block", def.label()),
            ));
            return false;
        };
        if self.comp.borrow().is_some() {
            let d = Diagnostic::new(
                Code::Unsupported,
                block.range,
                "inverse-time feed under cutter compensation is taken from the programmed path length, not the compensated one",
            );
            self.limited(diags, "inverse-time-comp", d);
        }
        self.st.feed = length * f;
        self.emit(sink, CanonOp::SetFeedRate(self.st.feed));
        true
    }

    pub(super) fn check_technology(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        if self.st.tech_warned {
            return;
        }
        let problem = if self.st.feed <= 0.0 {
            Some("the feed rate is zero")
        } else if self.st.spindle == Spindle::Stopped {
            Some("the spindle is stopped")
        } else {
            None
        };
        if let Some(p) = problem {
            self.st.tech_warned = true;
            let d = Diagnostic::new(Code::CuttingWithoutTechnology, range, format!("{} cuts while {p}", def.label()));
            self.limited(diags, "technology", d);
        }
    }

    /// After a straight move to `t`: its direction in the plane, for a following tangent arc.
    fn note_tangent(&mut self, t: [f64; 6]) {
        let (a0, a1, _) = self.st.plane.axes();
        let (d1, d2) = (t[a0] - self.st.pos[a0], t[a1] - self.st.pos[a1]);
        if d1 != 0.0 || d2 != 0.0 {
            self.st.tangent = Some((d1, d2)); // normalised where a tangent arc needs it
        }
    }

    fn arc(&mut self, def: &CodeDef, range: TextRange, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.check_technology(def, block.range, diags);
        let stated = self.codes.iter().find_map(|&(c, _)| match self.code(c).meaning {
            Meaning::ArcDirCw => Some(true),
            Meaning::ArcDirCcw => Some(false),
            _ => None,
        });
        let start = self.st.pos;
        let end = self.target();
        let (a0, a1, n) = self.st.plane.axes();
        let (s1, s2, e1, e2) = (start[a0], start[a1], end[a0], end[a1]);
        let mut cw = match def.meaning {
            Meaning::ArcCw => true,
            Meaning::ArcCcw => false,
            _ => stated.unwrap_or(self.st.arc_cw),
        };
        let mut given_centre = None;
        match def.meaning {
            Meaning::ArcPole => given_centre = Some(self.st.pole),
            Meaning::ArcRadius if self.slot(Role::R).is_none() => {
                diags.push(Diagnostic::new(Code::MissingParameter, block.range, format!("{} needs a radius R", def.label())));
                return;
            }
            Meaning::ArcTangent => {
                // The centre lies on the normal to the incoming direction, as far from the
                // start as from the end.
                let Some((t1, t2)) = self.st.tangent.map(|(x, y)| {
                    let len = x.hypot(y);
                    (x / len, y / len)
                }) else {
                    diags.push(Diagnostic::new(
                        Code::BadArc,
                        block.range,
                        format!("{}: no previous element to be tangent to", def.label()),
                    ));
                    return;
                };
                let (d1, d2) = (e1 - s1, e2 - s2);
                let (n1, n2) = (-t2, t1);
                let dn = d1 * n1 + d2 * n2;
                if dn.abs() < 1e-9 {
                    diags.push(Diagnostic::new(
                        Code::BadArc,
                        block.range,
                        format!("{}: the end point lies on the tangent; no arc", def.label()),
                    ));
                    return;
                }
                let k = (d1 * d1 + d2 * d2) / (2.0 * dn);
                given_centre = Some((s1 + k * n1, s2 + k * n2));
                cw = k < 0.0;
            }
            _ => {}
        }
        let tol = self.dialect.behaviour.arc_tolerance_mm / self.st.units.to_mm();
        let turns = match self.slot(Role::P) {
            None => 1,
            Some(p) if p >= 1.0 && p.fract() == 0.0 && p < 10_000.0 => p as i32,
            Some(p) => {
                diags.push(Diagnostic::new(Code::BadArc, range, format!("the number of turns P{p} must be a positive whole number")));
                return;
            }
        };
        let center = if let Some(c) = given_centre {
            let r_start = (s1 - c.0).hypot(s2 - c.1);
            let r_end = (e1 - c.0).hypot(e2 - c.1);
            if (r_start - r_end).abs() > tol {
                diags.push(Diagnostic::new(
                    Code::BadArc,
                    block.range,
                    format!("the end point is {r_end:.4} from the circle centre, the start {r_start:.4}; they must agree"),
                ));
                return;
            }
            c
        } else if let Some(r) = self.slot(Role::R) {
            match arc_center_from_radius(s1, s2, e1, e2, r, cw, tol) {
                Ok(c) => c,
                Err(msg) => {
                    diags.push(Diagnostic::new(Code::BadArc, block.range, msg));
                    return;
                }
            }
        } else {
            let off = |axis: usize| self.slot(OFFSETS[axis]);
            if off(a0).is_none() && off(a1).is_none() {
                let needs = if self.st.plane == Plane::Xy {
                    "I or J"
                } else if self.st.plane == Plane::Xz {
                    "I or K"
                } else {
                    "J or K"
                };
                diags.push(Diagnostic::new(
                    Code::MissingParameter,
                    block.range,
                    format!("{} in this plane needs {needs}, or R", def.label()),
                ));
                return;
            }
            // Centre words are incremental from the start (G91.1) or absolute (G90.1), or per word (`I=AC(28)`).
            let centre = |axis: usize, start: f64| {
                let o = off(axis).unwrap_or(0.0);
                let incremental = match self.slots[OFFSETS[axis] as usize].map(|s| s.mode) {
                    Some(WordMode::Absolute) => false,
                    Some(WordMode::Incremental) => true,
                    _ => self.st.arc_incremental,
                };
                if incremental { start + o } else { o }
            };
            let c = (centre(a0, s1), centre(a1, s2));
            let r_start = (s1 - c.0).hypot(s2 - c.1);
            let r_end = (e1 - c.0).hypot(e2 - c.1);
            if (r_start - r_end).abs() > tol {
                let unit = if self.st.units == Units::Mm { "mm" } else { "in" };
                diags.push(Diagnostic::new(
                    Code::BadArc,
                    block.range,
                    format!("radius to the end of the arc ({r_end:.4} {unit}) differs from the radius to its start ({r_start:.4} {unit}) by more than {tol} {unit}"),
                ));
                return;
            }
            c
        };
        let rotation = if cw { -turns } else { turns };
        let length = arc_length(start, end, center, (a0, a1, n), cw, turns);
        if !self.inverse_time_feed(def, length, block, sink, diags) {
            return;
        }
        self.emit(
            sink,
            CanonOp::ArcFeed {
                first_end: e1,
                second_end: e2,
                first_axis: center.0,
                second_axis: center.1,
                rotation,
                axis_end: end[n],
                abc: [end[3], end[4], end[5]],
            },
        );
        self.st.pos = end;
        self.st.arc_cw = cw;
        // The direction at the end: along the circle, perpendicular to the radius.
        let (r1, r2) = (e1 - center.0, e2 - center.1);
        let len = r1.hypot(r2);
        if len > 1e-12 {
            self.st.tangent = Some(if cw { (r2 / len, -r1 / len) } else { (-r2 / len, r1 / len) });
        }
    }
}

/// The length of a (helical) arc along its path.
fn arc_length(start: [f64; 6], end: [f64; 6], center: (f64, f64), (a0, a1, n): (usize, usize, usize), cw: bool, turns: i32) -> f64 {
    let r = (start[a0] - center.0).hypot(start[a1] - center.1);
    let a_start = (start[a1] - center.1).atan2(start[a0] - center.0);
    let a_end = (end[a1] - center.1).atan2(end[a0] - center.0);
    let tau = std::f64::consts::TAU;
    let mut sweep = if cw { a_start - a_end } else { a_end - a_start };
    sweep = sweep.rem_euclid(tau);
    if sweep < 1e-12 {
        sweep = tau;
    }
    sweep += tau * f64::from(turns - 1);
    (r * sweep).hypot(end[n] - start[n])
}

/// The centre of an arc given by its radius, as LinuxCNC computes it: a positive radius
/// takes the short way (at most 180°), a negative one the long way.
fn arc_center_from_radius(s1: f64, s2: f64, e1: f64, e2: f64, r: f64, cw: bool, tol: f64) -> Result<(f64, f64), String> {
    let abs_r = r.abs();
    let (m1, m2) = ((s1 + e1) / 2.0, (s2 + e2) / 2.0);
    let half = (m1 - e1).hypot(m2 - e2);
    if half < 1e-12 {
        return Err("an arc given by R cannot be a full circle (start and end coincide)".into());
    }
    if half - abs_r > tol {
        return Err(format!("arc radius {abs_r} is too small to reach the end point ({:.4} away)", 2.0 * half));
    }
    let half = half.min(abs_r);
    let chord = (e2 - s2).atan2(e1 - s1);
    let theta = if cw == (r > 0.0) { chord - std::f64::consts::FRAC_PI_2 } else { chord + std::f64::consts::FRAC_PI_2 };
    let offset = (abs_r * abs_r - half * half).max(0.0).sqrt();
    Ok((m1 + offset * theta.cos(), m2 + offset * theta.sin()))
}

#[cfg(test)]
mod tests {
    use super::arc_center_from_radius;

    #[test]
    fn r_arcs_take_the_short_or_long_way() {
        // G2 X10 Y0 R5 from the origin: a semicircle about (5, 0).
        let (c1, c2) = arc_center_from_radius(0.0, 0.0, 10.0, 0.0, 5.0, true, 0.002).unwrap();
        assert!((c1 - 5.0).abs() < 1e-9 && c2.abs() < 1e-9);
        // G3 X10 Y0 R-7: centre (5, -4.899), the long way (verified with rs274).
        let (c1, c2) = arc_center_from_radius(0.0, 0.0, 10.0, 0.0, -7.0, false, 0.002).unwrap();
        assert!((c1 - 5.0).abs() < 1e-9 && (c2 + 24f64.sqrt()).abs() < 1e-9, "{c1} {c2}");
        assert!(arc_center_from_radius(0.0, 0.0, 10.0, 0.0, 2.0, true, 0.002).is_err());
    }
}

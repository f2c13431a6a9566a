//! Programmable rotation (G68, G69) and scaling (G51, G50 on a mill): the codes that set
//! them, and what they do to every op on its way out. The programmable frames (`TRANS`,
//! `ROT`, `SCALE`) are in `interp/define.rs`.
//!
//! Doors: [`Interpreter::rotation_code`], [`Interpreter::scaling_code`], and
//! [`Interpreter::transform`] for the ops [`Interpreter::emit`] sends.

use crate::canon::{CanonOp, Plane};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::interp::Interpreter;
use crate::syntax::{Block, Value};
use crate::text::TextRange;

impl Interpreter<'_> {
    /// G68 (rotation about X Y by R degrees, in the XY plane) and G69 (none).
    pub(super) fn rotation_code(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        if def.meaning == Meaning::RotationCancel {
            self.st.rotation = None;
            return;
        }
        if self.st.plane != Plane::Xy {
            self.unsupported(def, range, diags);
            return;
        }
        let cx = self.slot(Role::X).unwrap_or(self.st.pos[0]);
        let cy = self.slot(Role::Y).unwrap_or(self.st.pos[1]);
        let angle = self.slot(Role::R).unwrap_or(0.0).to_radians();
        self.st.rotation = Some((cx, cy, angle.cos(), angle.sin()));
    }

    /// G51 (scaling about the block's point by P, or by I J K per axis) and its cancel.
    pub(super) fn scaling_code(&mut self, def: &CodeDef, range: TextRange, block: &Block, diags: &mut Vec<Diagnostic>) {
        if def.meaning == Meaning::ScalingCancel {
            self.st.scaling = None;
            return;
        }
        let uniform = block.words.iter().find(|w| w.role == Role::P).map(|w| match w.value {
            // Without a decimal point, P counts in 0.001 (parameter 5400#7 off).
            Value::Number { decimal: false, value } => value * 0.001,
            _ => self.slot(Role::P).unwrap_or(1.0),
        });
        let k = match uniform {
            Some(p) => [p; 3],
            None => [Role::I, Role::J, Role::K].map(|r| {
                let w = block.words.iter().find(|w| w.role == r);
                match w.map(|w| w.value) {
                    Some(Value::Number { decimal: false, value }) => value * 0.001,
                    Some(_) => self.slot(r).unwrap_or(1.0),
                    None => 1.0,
                }
            }),
        };
        if k.iter().any(|&f| f <= 0.0 || !f.is_finite()) {
            diags.push(Diagnostic::new(Code::MalformedNumber, range, format!("{}: scale factors must be positive", def.label())));
            return;
        }
        let centre = [0, 1, 2].map(|i| self.slot(Role::AXES[i]).unwrap_or(self.st.pos[i]));
        if k[0] != k[1] {
            self.limited(
                diags,
                "scaling",
                Diagnostic::new(
                    Code::Unsupported,
                    range,
                    format!("{}: unequal X and Y factors distort arcs; arcs keep their radius ratio from X", def.label()),
                ),
            );
        }
        self.st.scaling = Some((centre, k));
    }

    /// A point through programmable scaling (G51), then rotation (G68), as the control moves.
    fn xform(&self, p: [f64; 3]) -> [f64; 3] {
        let mut q = p;
        if let Some((c, k)) = self.st.scaling {
            for i in 0..3 {
                q[i] = c[i] + (q[i] - c[i]) * k[i];
            }
        }
        if let Some((cx, cy, cos, sin)) = self.st.rotation {
            let (dx, dy) = (q[0] - cx, q[1] - cy);
            q[0] = cx + dx * cos - dy * sin;
            q[1] = cy + dx * sin + dy * cos;
        }
        q
    }

    /// An op with its points through scaling and rotation (see [`Interpreter::xform`]).
    pub(in crate::interp) fn transform(&self, op: CanonOp) -> CanonOp {
        let at = |p: [f64; 6]| {
            let q = self.xform([p[0], p[1], p[2]]);
            [q[0], q[1], q[2], p[3], p[4], p[5]]
        };
        match op {
            CanonOp::StraightTraverse(p) => CanonOp::StraightTraverse(at(p)),
            CanonOp::StraightFeed(p) => CanonOp::StraightFeed(at(p)),
            CanonOp::NurbsFeed { points, end } => CanonOp::NurbsFeed { points, end: at(end) },
            CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, abc } => {
                let (a0, a1, n) = self.st.plane.axes();
                let mut end = [0.0; 3];
                let mut centre = [0.0; 3];
                (end[a0], end[a1], end[n]) = (first_end, second_end, axis_end);
                (centre[a0], centre[a1], centre[n]) = (first_axis, second_axis, axis_end);
                let (end, centre) = (self.xform(end), self.xform(centre));
                CanonOp::ArcFeed {
                    first_end: end[a0],
                    second_end: end[a1],
                    first_axis: centre[a0],
                    second_axis: centre[a1],
                    rotation,
                    axis_end: end[n],
                    abc,
                }
            }
            CanonOp::CycleBegin(mut c) => {
                let q = self.xform([c.x, c.y, c.bottom]);
                (c.x, c.y) = (q[0], q[1]);
                CanonOp::CycleBegin(c)
            }
            CanonOp::RigidTap(p) => CanonOp::RigidTap(self.xform(p)),
            op => op,
        }
    }
}

//! Cylindrical interpolation (Fanuc `G07.1`, SINUMERIK `TRACYL`): the mode written by the
//! target's `cylinder-on` (the cylinder's radius or diameter) and `cylinder-off`, and the moves
//! on the developed surface in the words the control takes there.
//!
//! The canon keeps those moves on the developed surface's plane laid tangent to the cylinder
//! (`interp::lathe`'s `cylinder_mode`: X along the spindle axis' -Z, Y the length round the
//! cylinder from the angle the plane is laid at, Z the radius the tool cuts at). Under the mode
//! the target's words are the lathe's again: X the depth (a diameter where the target reads
//! diameters), Z along the spindle axis, and the way round the cylinder as the target's
//! `round` says: C in degrees (Fanuc: the control turns the angle into the length at the
//! radius) or Y, the length itself (TRACYL). The plane the canon lays is the mode's, not a
//! tilted plane: it is not written, and a plane laid anew at another angle (a rapid round the
//! cylinder) only moves where the lengths are counted from. An arc there is written by its
//! radius (`cylinder-arc-cw`, `cylinder-arc-ccw`): neither control takes a centre in degrees.
//! A target without the rules refuses the mode with the reason, never writing the developed
//! surface's moves on a flat plane.
//!
//! The door: [`Post::cylinder_wrap`], [`Post::cylinder_plane`], [`Post::cylinder_words`].

use super::{EPS, Post, Vals};
use crate::canon::{Canon, Frame, Plane};
use crate::diag::Code;
use crate::dialect::output::{CylinderRound, Value};

/// Cylindrical interpolation written, and the developed surface's plane in force.
#[derive(Clone, Copy, Debug)]
pub(super) struct CylinderOut {
    /// The cylinder's radius (target units).
    radius: f64,
    /// The developed surface's plane (target units), once the source lays it.
    frame: Option<Frame>,
    /// The angle of C (degrees) the plane is laid tangent at: where its lengths count from.
    c0: f64,
    /// How the target writes the way round the cylinder.
    round: CylinderRound,
    /// The plane in force before the mode, which its end gives back.
    plane: Plane,
}

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// Cylindrical interpolation on the cylinder of radius `r` (source units), or off (`None`):
    /// the target's `cylinder-on` or `cylinder-off`; unwritable where it has none.
    pub(super) fn cylinder_wrap(&mut self, canon: &Canon, r: Option<f64>) {
        let Some(r) = r else {
            let Some(cyl) = self.cylinder.take() else { return };
            // The untilted plane that follows ends the mode's plane: not written.
            self.cylinder_ending = true;
            if let Some(f) = cyl.frame {
                self.pos = f.to_base(self.pos);
            }
            if !self.event("cylinder-off", &mut Vals::new()) {
                self.note(
                    Code::PostUnwritable,
                    canon,
                    "cylinder-off",
                    "the end of cylindrical interpolation is not written: the target's output rules have no `cylinder-off`",
                );
            }
            // The control gives back the plane in force before the mode.
            self.plane = cyl.plane;
            // Where the lengths round the cylinder were written as Y, the control's Y is gone
            // with the mode (the interpreter's too: 0), and C stands where the mode left it,
            // not where it was last written: the next position that states C writes it. As
            // angles, C was written where it stands.
            if cyl.round == CylinderRound::Length {
                let y = self.key_of("Y", 0.0);
                self.set_written(1, y);
                self.set_written(7, None);
            }
            return;
        };
        let radius = self.to_out(r);
        let mut vals = Vals::new();
        vals.set(Value::CylRadius, radius).set(Value::CylDiameter, 2.0 * radius);
        let shifted = self.g92.iter().any(|v| v.abs() > EPS);
        if self.out.template("cylinder-on").is_none() || shifted {
            let why = if shifted {
                "a G92-style shift is added to the positions, and lengths round the cylinder cannot carry it"
            } else {
                "the target's output rules have no cylinder mode (`cylinder-on`)"
            };
            let what = format!(
                "cylindrical interpolation (radius {}) is not written: {why}, so the moves on the developed surface would be written on a flat plane laid tangent to the cylinder, cutting there instead of round the cylinder",
                crate::text::num(r)
            );
            self.note(Code::PostUnwritable, canon, "cylinder", what);
            return;
        }
        if !self.event("cylinder-on", &mut vals) {
            self.note(Code::PostUnwritable, canon, "cylinder", "the target's `cylinder-on` cannot state this cylinder");
            return;
        }
        // A new radius while on: the same developed surface, measured anew.
        let (frame, c0, plane) = self.cylinder.map_or((None, 0.0, self.plane), |c| (c.frame, c.c0, c.plane));
        self.cylinder = Some(CylinderOut { radius, frame, c0, round: self.out.cylinder_round, plane });
    }

    /// A working plane while cylindrical interpolation is written: the developed surface's,
    /// laid tangent at an angle of C (its Y row `[0, cos, sin]` of that angle), kept and not
    /// written, the tool's position carried into it; the untilted plane that ends the mode,
    /// not written. Whether the plane was the mode's.
    pub(super) fn cylinder_plane(&mut self, f: Option<&Frame>) -> bool {
        if f.is_none() && std::mem::take(&mut self.cylinder_ending) {
            return true;
        }
        let (Some(cyl), Some(f)) = (self.cylinder.as_mut(), f) else { return false };
        let next = Frame { origin: [0.0; 3], rotation: f.rotation };
        let old = cyl.frame.unwrap_or(Frame::IDENTITY);
        self.pos = next.from_base(old.to_base(self.pos));
        cyl.c0 = f.rotation[1][2].atan2(f.rotation[1][1]).to_degrees();
        cyl.frame = Some(next);
        true
    }

    /// The target's words for `d`, a point on the developed surface (target units): X the
    /// radius the tool stands at, Y the length round the cylinder (NaN where C states it), Z
    /// along the spindle axis, and C in degrees (NaN where Y states it). `None` while the mode
    /// is not written.
    pub(super) fn cylinder_words(&self, d: [f64; 3]) -> Option<([f64; 3], f64)> {
        let cyl = self.cylinder?;
        Some(match cyl.round {
            CylinderRound::Angle => ([d[2], f64::NAN, -d[0]], cyl.c0 + (d[1] / cyl.radius).to_degrees()),
            CylinderRound::Length => ([d[2], d[1] + cyl.radius * cyl.c0.to_radians(), -d[0]], f64::NAN),
        })
    }
}

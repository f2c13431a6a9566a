//! Drilling cycles for a driven tool on a C-axis lathe (Fanuc T series G83 to G85 on the face,
//! G87 to G89 into the cylinder; the dictionary marks them with `hole-axis`): each hole is
//! placed by the spindle's C angle and the other linear axis, and runs along the axis the
//! code names.
//!
//! The moves of a hole are written as milling: a face hole in the face's XY plane (X the
//! radius at C0, as polar coordinate interpolation writes it, the tool along Z), a hole into
//! the cylinder on a tilted working plane whose Z is the radial direction at its C angle (X
//! along the spindle axis), so that the plan places each hole on its face with its axis. The
//! plane the lathe was in, and the untilted frame, come back at the end of the block.
//!
//! From the 0i-TF operator's manual's "canned cycle for drilling" as the public examples
//! quote it: R is the distance from the initial level to the R point (signed, along the hole
//! axis; taken as a radius into the cylinder [unconfirmed]); the bottom is X or Z (U or W:
//! from the R point); Q the peck, in least increments without a decimal point; P the dwell;
//! K the repeats. In G-code system A the tool returns to the initial level (G98/G99 are the
//! feed modes there) [unconfirmed: from the manual's note as remembered]. Haas lathes' live
//! cycles (`r-level="absolute"`): R is the R plane's position, a diameter into the cylinder.

use super::cycle::HoleRun;
use super::{Interpreter, Retract};
use crate::canon::{CanonOp, CanonSink, CycleKind, Frame, Plane, Units};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Role};
use crate::syntax::{Block, WordMode};

impl Interpreter<'_> {
    /// A driven tool's drilling cycle along `axis` (0 X, 2 Z) of `kind`: its holes at the
    /// block's C angle and position, as milling holes on the face or the cylinder.
    pub(super) fn live_cycle(
        &mut self,
        def: &CodeDef,
        kind: CycleKind,
        axis: usize,
        block: &Block,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        // The position along the other linear axis: Z for a side hole, X (a radius) on the face.
        let across = if axis == 0 { 2 } else { 0 };
        let word = |me: &Self, role: Role| me.slots[role as usize];
        let along_word = word(self, Role::AXES[axis]);
        // The first block of a cycle after G80 or another motion: G80 and the group 01 codes
        // clear the drilling data (0i-TF manual, "canned cycle cancel"), so R, Q and P come from
        // this block only; a side hole after a face cycle does not peck by the face's Q.
        if self.st.cycle_initial.is_none() {
            (self.st.sticky_r, self.st.sticky_q, self.st.sticky_p) = (None, None, None);
        }
        if let Some(r) = self.slot(Role::R) {
            self.st.sticky_r = Some(r);
        }
        if let Some(q) = self.slot(Role::Q) {
            let decimal = self.slots[Role::Q as usize].is_some_and(|s| block.text(s.range).contains('.'));
            let increment = if self.st.units == Units::Mm { 0.001 } else { 0.0001 };
            self.st.sticky_q = Some(if decimal { q } else { q * increment });
        }
        if let Some(p) = self.slot(Role::P) {
            self.st.sticky_p = Some(p);
        }
        let pos = self.st.pos;
        let initial = *self.st.cycle_initial.get_or_insert(pos[axis]);
        // Haas: R the R plane's position, a diameter for a hole into the cylinder.
        let r = match self.st.sticky_r {
            Some(r) if def.r_absolute => r / if axis == 0 && self.st.diameter { 2.0 } else { 1.0 },
            r => initial + r.unwrap_or(0.0),
        };
        let bottom = match along_word {
            Some(s) if s.mode == WordMode::Incremental => Some(r + s.value),
            Some(s) => Some(s.value),
            None => self.st.sticky_z,
        };
        let Some(bottom) = bottom else {
            let d = Diagnostic::new(Code::CycleIncomplete, block.range, format!("{} has no hole bottom", def.label()));
            diags.push(d);
            return;
        };
        self.st.sticky_z = Some(bottom);
        let peck = match kind {
            CycleKind::PeckDrilling | CycleKind::ChipBreaking => self.st.sticky_q.filter(|q| *q > 0.0),
            _ => None,
        };
        // Without Q, G83 and G87 drill in one feed.
        let kind =
            if peck.is_none() && matches!(kind, CycleKind::PeckDrilling | CycleKind::ChipBreaking) { CycleKind::Drilling } else { kind };
        let dwell = self.st.sticky_p.filter(|p| *p > 0.0).map(|p| self.dwell_seconds(p));
        let kind = if kind == CycleKind::Drilling && dwell.is_some() { CycleKind::CounterBoring } else { kind };
        let clearance =
            if self.st.units == Units::Mm { self.dialect.behaviour.peck_clearance_mm } else { self.dialect.behaviour.peck_clearance_inch };
        let repeats = self.slot(Role::K).unwrap_or(1.0).max(1.0) as u64;
        let run = HoleRun {
            kind,
            code: def.label(),
            r,
            bottom,
            clear: if self.st.retract == Retract::RPlane { r } else { initial },
            old_z: initial,
            peck,
            peck_from: r,
            dwell,
            shift: 0.0,
            clearance,
            still: false,
            surface: None,
            r_known: false,
            returns_initial: false,
        };
        let target = self.target();
        self.live_holes(&run, axis, repeats, target[5], target[across], sink);
    }

    /// `repeats` holes of `run` along `axis` (0 X, 2 Z) at angle `c` and position `place` on
    /// the other linear axis, from the current position: milling in the XY plane of the face
    /// or of the cylinder's tilted plane; the lathe's plane and the untilted frame come back
    /// after them.
    pub(super) fn live_holes(&mut self, run: &HoleRun, axis: usize, repeats: u64, c: f64, place: f64, sink: &mut dyn CanonSink) {
        let old_plane = self.st.plane;
        self.st.plane = Plane::Xy;
        self.emit(sink, CanonOp::SelectPlane(Plane::Xy));
        let mut at = self.st.pos;
        for _ in 0..repeats {
            at = self.live_hole(run, axis, c, place, at, sink);
        }
        if axis == 0 {
            self.emit(sink, CanonOp::WorkPlane(None));
        }
        self.st.plane = old_plane;
        self.emit(sink, CanonOp::SelectPlane(old_plane));
        self.st.pos = at;
    }

    /// One hole at angle `c` (degrees) and position `place` on the other linear axis, from
    /// `from` (lathe coordinates); returns the lathe position after it.
    fn live_hole(&mut self, run: &HoleRun, axis: usize, c: f64, place: f64, from: [f64; 6], sink: &mut dyn CanonSink) -> [f64; 6] {
        let (s, co) = c.to_radians().sin_cos();
        let (s0, c0) = from[5].to_radians().sin_cos();
        // The point the tool is at, in the part's frame (X at C0, Z the spindle axis).
        let here = [from[0] * c0, from[0] * s0, from[2]];
        let mut p = from;
        let (x, y) = if axis == 2 {
            (p[0], p[1], p[2]) = (here[0], here[1], here[2]);
            (place * co, place * s)
        } else {
            // The face turned 90° about Y, then by C about the spindle axis (Rz(C)·Ry(90°), as
            // a mill-turn's B head at 90° sees it): Z the radial direction at C, X along -Z.
            let frame = Frame { origin: [0.0; 3], rotation: [[0.0, -s, co], [0.0, co, s], [-1.0, 0.0, 0.0]] };
            [p[0], p[1], p[2]] = frame.from_base(here);
            self.emit(sink, CanonOp::WorkPlane(Some(Box::new(frame))));
            (-place, 0.0)
        };
        // The machine's C is at the hole; the coordinates above already turn with it.
        p[5] = c;
        let end = self.hole(run, x, y, p, sink);
        let mut after = from;
        after[axis] = end[2];
        after[if axis == 0 { 2 } else { 0 }] = place;
        after[5] = c;
        after
    }
}

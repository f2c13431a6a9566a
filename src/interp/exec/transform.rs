//! Programmable rotation (G68, G69), scaling (G51, G50 on a mill) and mirror image (G51.1,
//! G50.1; Siemens `MIRROR`/`AMIRROR`; Heidenhain cycle 8): the codes that set them, and what
//! they do to every op on its way out. The programmable frames (`TRANS`, `ROT`, `SCALE`) are
//! in `interp/define.rs`.
//!
//! Mirroring, as the controls document it (Fanuc's programmable mirror image; the SINUMERIK
//! ISO milling manual's G51.1; Siemens frames; the TNC's cycle 8): each axis named changes
//! sign about its mirror's position (Fanuc and Haas: the coordinate the axis word gives;
//! Siemens and Heidenhain: the program zero in force); where one axis of the working plane is
//! mirrored, arcs turn the other way and radius compensation changes sides. The mirror comes
//! first, then scaling, then rotation. Features cut under it lie where the mirrored moves run.
//!
//! Doors: [`Interpreter::rotation_code`], [`Interpreter::scaling_code`],
//! [`Interpreter::mirror_code`], [`Interpreter::frame_mirror`], and
//! [`Interpreter::transform`] for the ops [`Interpreter::emit`] sends.

use crate::canon::{CanonOp, CanonSink, DistanceMode, Plane};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::interp::Interpreter;
use crate::syntax::WordMode;
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
            self.set_mirror_and_scale(self.st.mirror, None);
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
        self.set_mirror_and_scale(self.st.mirror, Some((centre, k)));
    }

    /// G51.1 (each axis named mirrored about the coordinate its word gives; Haas G101 about
    /// the work zero, the word's value not read) and G50.1 (the
    /// axes named no longer mirrored; with none, every axis); Siemens `MIRROR`/`AMIRROR`
    /// ([`Interpreter::frame_mirror`]).
    pub(super) fn mirror_code(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        let named = [0, 1, 2].map(|i| self.slot(Role::AXES[i]));
        if def.meaning == Meaning::FrameMirror {
            // A replacing frame instruction: the frame programmed before it deleted.
            self.frame_replaced(sink);
        }
        if matches!(def.meaning, Meaning::FrameMirror | Meaning::FrameMirrorAdd) {
            self.frame_mirror(def.meaning == Meaning::FrameMirrorAdd, named.map(|v| v.is_some()));
            return;
        }
        let mut mirror = self.st.mirror;
        let cancel = def.meaning == Meaning::MirrorCancel;
        for i in 0..3 {
            match (cancel, named[i]) {
                (true, Some(_)) => mirror[i] = None,
                (true, None) if named.iter().all(Option::is_none) => mirror[i] = None,
                (false, Some(at)) => mirror[i] = Some(if def.meaning == Meaning::MirrorAboutZero { 0.0 } else { at }),
                _ => {}
            }
        }
        self.set_mirror_and_scale(mirror, self.st.scale_set);
    }

    /// Siemens `MIRROR X0` (the axes named, about the program zero, replacing the mirroring in
    /// force; alone, none) and `AMIRROR X0` (added: an axis mirrored already is mirrored back);
    /// Heidenhain cycle 8 (`CYCL DEF 8.1 X Y`, replacing; without axes, none). The axis
    /// words' values are not read.
    pub(in crate::interp) fn frame_mirror(&mut self, additive: bool, named: [bool; 3]) {
        let mut mirror = if additive { self.st.mirror } else { [None; 3] };
        for i in 0..3 {
            if named[i] {
                mirror[i] = if additive && mirror[i].is_some() { None } else { Some(0.0) };
            }
        }
        self.set_mirror_and_scale(mirror, self.st.scale_set);
    }

    /// Puts mirroring and scaling in force: the point map they make together, mirror first
    /// (`p → 2m − p`), then scaling (`p → c + (p − c)·k`), kept as one centre and factor per
    /// axis (a mirrored axis's factor negative).
    pub(in crate::interp) fn set_mirror_and_scale(&mut self, mirror: [Option<f64>; 3], scale: Option<([f64; 3], [f64; 3])>) {
        self.st.mirror = mirror;
        self.st.scale_set = scale;
        if mirror.iter().all(Option::is_none) {
            self.st.scaling = scale;
            return;
        }
        let (c, k) = scale.unwrap_or(([0.0; 3], [1.0; 3]));
        let mut centre = [0.0; 3];
        let mut factor = [1.0; 3];
        for i in 0..3 {
            // q = o + t·p with o = c(1 − k) + k·a, t = k·s (a = 2m, s = −1 mirrored; 0 and 1 not).
            let (a, s) = mirror[i].map_or((0.0, 1.0), |m| (2.0 * m, -1.0));
            let (o, t) = (c[i] * (1.0 - k[i]) + k[i] * a, k[i] * s);
            factor[i] = t;
            centre[i] = if (1.0 - t).abs() > 1e-12 { o / (1.0 - t) } else { 0.0 };
        }
        self.st.scaling = Some((centre, factor));
    }

    /// Whether the mirroring in force turns the plane's arcs the other way (one of its two
    /// axes mirrored): arcs and radius compensation's side swap.
    pub(in crate::interp) fn mirrored_in_plane(&self, plane: Plane) -> bool {
        let (a0, a1, _) = plane.axes();
        self.st.mirror[a0].is_some() != self.st.mirror[a1].is_some()
    }

    /// A point through programmable scaling (G51), then rotation (G68), as the control moves,
    /// and on by the quill's stroke along the tool axis ([`Interpreter::quill_shift`]).
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
        if self.st.quill != 0.0 {
            let d = self.quill_shift();
            for i in 0..3 {
                q[i] += d[i];
            }
        }
        q
    }

    /// A mill's W axis word in a move (`G1 W-10`): the quill, a linear axis along the spindle
    /// (ISO 841 names W the secondary motion parallel to Z), goes to its new position, absolute
    /// or incremental as the block's distance mode says. On a lathe's dictionary or machine W
    /// is left as it was read (an incremental Z there, or a tailstock or counter-spindle axis
    /// that moves no tool).
    pub(in crate::interp) fn quill_word(&mut self) {
        let Some(slot) = self.slots[Role::W as usize] else { return };
        if self.taken_by_code(Role::W) || !self.quill_moves_tool() {
            return;
        }
        let incremental = match slot.mode {
            WordMode::Modal => self.st.distance == DistanceMode::Incremental,
            WordMode::Absolute => false,
            WordMode::Incremental => true,
        };
        self.st.quill = if incremental { self.st.quill + slot.value } else { slot.value };
    }

    /// Whether the W axis is a quill that moves the tool: not on a lathe's dictionary or
    /// machine, in diameter mode, or where a dictionary shared with lathes turns in the ZX
    /// plane; there W is an incremental Z or moves a tailstock or counter-spindle.
    pub(in crate::interp) fn quill_moves_tool(&self) -> bool {
        let b = &self.dialect.behaviour;
        // A dictionary shared by mills and lathes (SINUMERIK: `lathe-x-words`) turning in the
        // ZX plane, radius words or not: its W is a tailstock or counter-spindle, never a quill.
        let turning = b.lathe_x_diameter && self.st.plane == crate::canon::Plane::Xz;
        !(self.st.diameter || b.x_diameter || self.profile.lathe_reset || turning)
    }

    /// Where the quill's stroke puts the tool tip from the X Y Z the program gives: W along the
    /// tool axis, from the tip towards the holder, as a quill or ram moves the spindle (LinuxCNC's
    /// trivial kinematics with W a joint parallel to Z; its bridge mill's `5axiskins` adds W to
    /// the tool's length along the tilted spindle, kins(9): "the W coordinate values (typically
    /// used for tool motion) are incorporated into XYZ positioning"). On a tilted working plane
    /// the spindle is the plane's Z.
    pub(in crate::interp) fn quill_shift(&self) -> [f64; 3] {
        let axis = if self.st.frame.is_some() { [0.0, 0.0, 1.0] } else { self.tool_axis };
        axis.map(|a| a * self.st.quill)
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
                    rotation: if self.mirrored_in_plane(self.st.plane) { -rotation } else { rotation },
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

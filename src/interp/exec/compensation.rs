//! Cutter radius compensation codes: G40 (off), G41/G42 (left or right, by the tool's
//! radius or the D register) and G41.1/G42.1 (by a diameter the block gives, with a lathe
//! tool's orientation). The offset path itself is worked out by `interp/comp.rs`.
//!
//! Doors: [`Interpreter::comp_off_code`], [`Interpreter::comp_on`].

use crate::canon::{CanonOp, CanonSink, CompOn, Plane, Setting};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::interp::{Interpreter, comp};
use crate::text::TextRange;

impl Interpreter<'_> {
    /// G40: compensation ends; the next move leaves the compensated path.
    pub(super) fn comp_off_code(&mut self, sink: &mut dyn CanonSink) {
        self.emit(sink, CanonOp::Setting(Setting::CutterComp(None)));
        self.st.leaving_comp = self.comp.borrow().is_some();
        self.st.comp_on = false;
        self.comp_off(sink);
    }

    /// G41, G42, G41.1, G42.1: compensation starts (or goes on, written again) on the side
    /// the code says, or the other for a negative offset.
    pub(super) fn comp_on(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let by_diameter = matches!(def.meaning, Meaning::CompLeftDiameter | Meaning::CompRightDiameter);
        let radius = self.comp_radius(by_diameter);
        let left = matches!(def.meaning, Meaning::CompLeft | Meaning::CompLeftDiameter);
        // A negative offset (`G41.1 D-0.3`) runs on the other side, as in rs274.
        let left = left != radius.is_some_and(|r| r < 0.0);
        // Under a mirror image of one axis of the plane the control runs it on the other side
        // of the mirrored path (`interp/exec/transform.rs`).
        let left = left != self.mirrored_in_plane(self.st.plane);
        let radius = radius.map(f64::abs);
        let side = if left { comp::Side::Left } else { comp::Side::Right };
        self.st.comp_left = left;
        self.st.comp_on = true;
        let number = self.slot(Role::D).filter(|_| !by_diameter).map(|d| d as u32);
        // A lathe tool's tip as the block states it (`G42.1 D0.8 L3`).
        let tip = self.slot(Role::L).filter(|l| by_diameter && l.fract() == 0.0 && (1.0..=9.0).contains(l)).map(|l| l as u8);
        self.emit(sink, CanonOp::Setting(Setting::CutterComp(Some(CompOn { left, number, radius, tip }))));
        if let Some(r) = radius
            && self.comp.borrow().as_ref().is_some_and(|c| c.runs(side, r))
        {
            // Written again on a later block (`L X+10 RL`): compensation goes on.
            return;
        }
        self.comp_off(sink);
        // Moves held before compensation starts are not compensated.
        self.corners_out(sink);
        if radius == Some(0.0) {
            // A zero offset leaves the path as programmed (rs274 does the same).
            return;
        }
        if let Some(r) = radius.filter(|_| matches!(self.st.plane, Plane::Xy | Plane::Xz)) {
            self.start_comp(side, r, by_diameter);
            return;
        }
        self.comp_not_computed(def, range, radius.is_none(), number, diags);
    }

    /// The radius compensation runs at, in program units, signed as written: half the
    /// diameter the block gives (`by_diameter`), else the tool table's radius of the D
    /// register's tool or the tool in the spindle.
    fn comp_radius(&self, by_diameter: bool) -> Option<f64> {
        let radius = if by_diameter { self.slot(Role::D).map(|d| d / 2.0) } else { None };
        let radius = radius.or_else(|| {
            let tool = self.slot(Role::D).map_or(self.st.tool, |d| d as u32);
            let diameter = self.tool_diameter(tool);
            diameter.filter(|_| !by_diameter).map(|d| d / 2.0)
        });
        // A D diameter is in program units; the tool table is in millimetres.
        radius.map(|r| if by_diameter { r } else { r / self.st.units.to_mm() })
    }

    /// Starts compensation of radius `r` on `side`, from the current position.
    fn start_comp(&mut self, side: comp::Side, r: f64, by_diameter: bool) {
        let axes = self.st.plane.axes();
        // A lathe tool's orientation (`G42.1 D0.4 L3`) puts the controlled point at
        // its imaginary tip (in the ZX plane, Z first).
        let orientation = self.slot(Role::L).filter(|l| by_diameter && l.fract() == 0.0 && *l >= 0.0).unwrap_or(0.0);
        let (tx, tz) = comp::tip_offset(orientation as u32);
        let tip = if self.st.plane == Plane::Xz { (tz * r, tx * r) } else { (0.0, 0.0) };
        let at = (self.st.pos[axes.0], self.st.pos[axes.1]);
        *self.comp.borrow_mut() = Some(comp::Comp::new(side, r, axes, tip, at));
    }

    /// Compensation that is not computed: the radius is unknown (`no_radius`, in the
    /// control's offsets or nowhere), or the plane is one compensation does not run in. The
    /// programmed path is used, and the finding says why.
    fn comp_not_computed(&mut self, def: &CodeDef, range: TextRange, no_radius: bool, number: Option<u32>, diags: &mut Vec<Diagnostic>) {
        let register = match number.filter(|&d| d != 0) {
            Some(d) => Some(format!("D{d}")),
            None => (self.st.tool != 0).then(|| format!("tool {}", self.st.tool)),
        };
        if no_radius && let Some(register) = register {
            // `G41 D01`, `RL` after `TOOL CALL 5`, with no tool table: the radius is in
            // the control's offset table, machine data like any other; CAM posts that
            // compensate only wear write the tool centre's path, so the programmed path
            // is the plan.
            let msg = format!(
                "{}: the radius of {register} is in the control's tool offsets, unknown here; the programmed path is used",
                def.label()
            );
            self.limited(diags, "cutter-comp", Diagnostic::new(Code::UnknownValue, range, msg));
        } else if no_radius {
            let msg =
                format!("{} without an offset: no D word and no tool diameter in the tool table; the programmed path is used", def.label());
            self.limited(diags, "cutter-comp", Diagnostic::new(Code::CompWithoutOffset, range, msg));
        } else {
            let msg = format!("{}: the compensated path is not computed yet; the programmed path is used", def.label());
            self.limited(diags, "cutter-comp", Diagnostic::new(Code::Unsupported, range, msg));
        }
    }
}

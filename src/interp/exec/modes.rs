//! The modal groups that change how later words read: the plane (G17–G19), the units
//! (G20/G21), the distance modes (G90/G91, and G90.1/G91.1 for arc centres), the lathe's
//! diameter mode (G7/G8) and the canned cycles' return mode (G98/G99).
//!
//! Doors: [`Interpreter::plane`], [`Interpreter::units`], [`Interpreter::distance_mode`],
//! [`Interpreter::arc_distance_mode`], [`Interpreter::diameter_mode`],
//! [`Interpreter::retract_mode`], and [`Interpreter::set_units`] for the saved modes.

use crate::canon::{CanonOp, CanonSink, DistanceMode, Plane, Units};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning};
use crate::interp::{Interpreter, Retract};
use crate::text::TextRange;

impl Interpreter<'_> {
    /// G17, G18, G19: the plane of arcs, compensation and cycles. Another plane while cutter
    /// radius compensation is on stops a control whose dictionary says so
    /// (`plane-under-comp="stops"`: Fanuc PS0037 "CAN NOT CHANGE PLANE IN G41/G42"; or
    /// `modes-under-comp="locked"`: LinuxCNC "Cannot change planes with cutter radius
    /// compensation on"; the same plane again runs, as `rs274` shows); elsewhere it is a
    /// warning, the control's behaviour not being in its dictionary. The plane is taken either way.
    pub(super) fn plane(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let plane = match def.meaning {
            Meaning::PlaneXy => Plane::Xy,
            Meaning::PlaneXz => Plane::Xz,
            _ => Plane::Yz,
        };
        if self.st.comp_on && plane != self.st.plane && self.st.cylinder.is_none() {
            let (code, what) = if self.dialect.behaviour.plane_under_comp_stops {
                (Code::PlaneUnderComp, "the control stops: cannot change planes with cutter radius compensation on")
            } else {
                (
                    Code::PlaneUnderCompUnknown,
                    "the plane changes with cutter radius compensation on; whether the control runs it is not known",
                )
            };
            self.limited(diags, "plane-under-comp", Diagnostic::new(code, range, format!("{}: {what}", def.label())));
        }
        // Under cylindrical interpolation the moves stay on the developed surface (its XY):
        // the plane code (G19, the cylinder's plane) is the one the mode's end gives back.
        if self.st.cylinder.is_some() {
            self.st.face_plane = Some(plane);
            return;
        }
        self.st.plane = plane;
        self.stated_plane = Some(plane);
        self.emit(sink, CanonOp::SelectPlane(plane));
    }

    /// G20, G21: inch or millimetre lengths.
    pub(super) fn units(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        let units = if def.meaning == Meaning::UnitsInch { Units::Inch } else { Units::Mm };
        self.units_stated = true;
        self.set_units(units);
        self.emit(sink, CanonOp::UseLengthUnits(units));
    }

    /// G90, G91: absolute or incremental axis words.
    pub(super) fn distance_mode(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        let mode = if def.meaning == Meaning::DistanceAbsolute { DistanceMode::Absolute } else { DistanceMode::Incremental };
        if mode != self.st.distance {
            self.st.distance = mode;
            self.emit(sink, CanonOp::DistanceMode(mode));
        }
    }

    /// G90.1, G91.1: absolute or incremental arc centres (I, J, K).
    pub(super) fn arc_distance_mode(&mut self, def: &CodeDef) {
        self.st.arc_incremental = def.meaning == Meaning::ArcDistanceIncremental;
    }

    /// G7, G8 (lathe): X words give diameters or radii; SINUMERIK `DIAM90` diameters in
    /// absolute dimensions only.
    pub(super) fn diameter_mode(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        // Said either way: G7 and G8 are lathe codes, so the program turns.
        let on = def.meaning != Meaning::RadiusMode;
        self.st.diameter_absolute = def.meaning == Meaning::DiameterAbsolute;
        // DIAMOF, or DIAMON before any move, tells the reading; DIAMON later shows a lathe, as
        // DIAM90 anywhere does (the contour editor writes it at each contour's start, which a
        // cycle reads wherever it is called).
        if !on || (self.motions == 0 && !self.st.diameter_absolute) {
            self.lathe_words.1 = true;
        } else {
            self.lathe_words.0 += 1;
        }
        self.emit(sink, CanonOp::Setting(crate::canon::Setting::DiameterMode(on)));
        self.st.diameter = on;
        self.tool_words.2 |= on;
    }

    /// G98, G99: a canned cycle returns to its initial level or to the R plane.
    pub(super) fn retract_mode(&mut self, def: &CodeDef) {
        self.st.retract = if def.meaning == Meaning::RetractInitial { Retract::Initial } else { Retract::RPlane };
    }

    /// Changes the units, converting the lengths the state holds (position, offsets).
    pub(in crate::interp) fn set_units(&mut self, units: Units) {
        if units == self.st.units {
            return;
        }
        let k = self.st.units.to_mm() / units.to_mm();
        for i in 0..3 {
            self.st.pos[i] *= k;
            self.st.g92[i] *= k;
            for w in self.st.wcs_offsets.iter_mut().chain(self.st.wcs_extended.values_mut()) {
                w[i] *= k;
            }
        }
        for v in &mut self.st.tool_offset {
            *v *= k;
        }
        self.st.units = units;
    }
}

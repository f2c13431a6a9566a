//! Stops and the end of the program: M0 and M1, a stop with the program's message (`#3006`),
//! dwells (G4), and M2/M30, which end the program and reset the modes as the control does.
//!
//! Doors: [`Interpreter::stop`], [`Interpreter::stop_with_message`], [`Interpreter::dwell`],
//! and [`Interpreter::program_end`], [`Interpreter::dwell_seconds`] for the flow driver and
//! the cycles.

use crate::canon::{CanonOp, CanonSink, DistanceMode};
use crate::diag::Diagnostic;
use crate::dialect::{CodeDef, Meaning, Role, Step, TimeUnit};
use crate::interp::{Interpreter, Spindle};
use crate::syntax::Block;

impl Interpreter<'_> {
    /// M0, M1 (the program stops, or may), M2, M30 (it ends).
    pub(super) fn stop(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        match def.meaning {
            Meaning::ProgramStop => self.emit(sink, CanonOp::ProgramStop),
            Meaning::OptionalStop => self.emit(sink, CanonOp::OptionalProgramStop),
            _ => self.program_end(sink),
        }
    }

    /// The stop step of a block that set a stop message (`#3006 = 1 (CHECK PART)`): the
    /// message, the stop, then the block's codes of that step.
    pub(super) fn stop_with_message(&mut self, step: Step, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let msg = self.stop_message.take().unwrap_or_default();
        self.emit(sink, CanonOp::Message(msg));
        self.emit(sink, CanonOp::ProgramStop);
        self.run_codes(step, block, sink, diags);
    }

    /// G4: a dwell of P (in the dialect's time unit), or X, F or K seconds where the code
    /// takes them (on a lathe in diameter mode X and U are seconds too, not diameters).
    pub(super) fn dwell(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        let seconds = match (self.slot(Role::P), self.slot(Role::X)) {
            (Some(p), _) => self.dwell_seconds(p),
            // X (or a lathe's U) gives seconds: no diameter, though *read* halved it as one.
            (None, Some(x)) if self.st.diameter => 2.0 * x,
            (None, Some(x)) => x,
            (None, None) if def.params.takes(Role::F) && self.slot(Role::F).is_some() => self.slot(Role::F).unwrap_or(0.0),
            (None, None) if def.params.takes(Role::K) => self.slot(Role::K).unwrap_or(0.0),
            (None, None) => 0.0,
        };
        self.emit(sink, CanonOp::Dwell(seconds));
    }

    /// A dwell's P in seconds.
    pub(in crate::interp) fn dwell_seconds(&self, p: f64) -> f64 {
        match self.dialect.behaviour.dwell_unit {
            TimeUnit::Seconds => p,
            TimeUnit::Milliseconds => p / 1000.0,
        }
    }

    /// M2, M30 (and a main program's return where it ends the program): compensation ends,
    /// the modes go back to the control's defaults, and the program ends.
    pub(in crate::interp) fn program_end(&mut self, sink: &mut dyn CanonSink) {
        self.comp_off(sink);
        self.st.comp_on = false;
        self.st.wcs = 1;
        self.emit(sink, CanonOp::SetG5xOffset(1, self.st.wcs_offsets[0]));
        let initial = if self.profile.lathe_reset { crate::canon::Plane::Xz } else { self.dialect.behaviour.initial_plane };
        if self.st.plane != initial {
            self.st.plane = initial;
            self.emit(sink, CanonOp::SelectPlane(initial));
        }
        self.st.distance = DistanceMode::Absolute;
        self.st.feed = 0.0;
        self.emit(sink, CanonOp::SetFeedRate(0.0));
        self.st.spindle = Spindle::Stopped;
        self.emit(sink, CanonOp::StopSpindleTurning);
        if self.st.css_max.take().is_some() {
            self.emit(sink, CanonOp::SetSpindleMode(None));
        }
        if self.st.mist {
            self.emit(sink, CanonOp::MistOff);
        }
        if self.st.flood {
            self.emit(sink, CanonOp::FloodOff);
        }
        self.st.mist = false;
        self.st.flood = false;
        self.emit(sink, CanonOp::ProgramEnd);
        self.st.ended = true;
    }
}

//! The motion group: which motion mode is in force (G0 to G3, the canned cycles, probes,
//! splines, threading), and its cancel (G80). The moves themselves are made by
//! `interp/motion.rs` and the cycles' files.
//!
//! Doors: [`Interpreter::motion_mode`], [`Interpreter::nurbs_end_code`],
//! [`Interpreter::cycle_cancel`].

use crate::canon::{CanonOp, CanonSink};
use crate::diag::Diagnostic;
use crate::dialect::{CodeDef, Meaning, Role};
use crate::interp::Interpreter;
use crate::syntax::Block;
use crate::text::TextRange;

impl Interpreter<'_> {
    /// A motion code (`c`, written at `range`): it becomes the mode in force, and moves when
    /// the block gives it somewhere to go.
    pub(super) fn motion_mode(
        &mut self,
        c: usize,
        def: &CodeDef,
        range: TextRange,
        block: &Block,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        self.st.motion_continued = self.st.motion_code == Some(c);
        if !self.st.motion_continued {
            self.st.sticky_z = None;
            self.st.turn_cycle = None;
            // Another motion mode drops the NURBS points collected (as rs274 does).
            self.st.nurbs = None;
        }
        if !def.meaning.is_cycle() {
            self.st.cycle_initial = None;
        }
        self.st.motion_code = Some(c);
        let full_circle = matches!(def.meaning, Meaning::ArcCw | Meaning::ArcCcw)
            && [Role::I, Role::J, Role::K].iter().any(|&r| self.slots[r as usize].is_some());
        let in_place = self.dialect.behaviour.motion_in_place && matches!(def.meaning, Meaning::Rapid | Meaning::Linear);
        if self.has_axes || full_circle || in_place {
            self.motion(def, range, block, sink, diags);
        }
    }

    /// The end of a NURBS (G5.3): the curve collected goes out, and no motion mode is in force.
    pub(super) fn nurbs_end_code(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.st.motion_code = None;
        self.nurbs_end(def, range, sink, diags);
    }

    /// G80: the canned cycle in force ends.
    pub(super) fn cycle_cancel(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        // G80 ends a canned cycle; where it has a group of its own (Fanuc group 09) a
        // G0/G1 mode set in the same block stays.
        if self.st.motion_code.is_none_or(|m| self.code(m).meaning.is_cycle() || self.code(m).group == def.group) {
            self.st.motion_code = None;
        }
        self.st.sticky_z = None;
        // The dwell goes with it: Fanuc's G80 clears the drilling data besides R and Z, and
        // rs274 asks a G82 after G80 for its P again. Kept, a G84 after `G82 … P1000` and
        // G80 would dwell at every tapped hole's bottom.
        self.st.sticky_p = None;
        self.st.cycle_initial = None;
        self.emit(sink, CanonOp::CycleCancel);
    }
}

//! The fast lane: the block that makes up most of any CAM program, literal X, Y and Z words
//! continuing a modal G0 or G1 (`X12.5 Y-3.2 Z-1.05`).
//!
//! Such a block needs none of the general machinery: no codes to sort into steps, no
//! expressions, no parameter checks, no cycle or macro after it. The lane does exactly what
//! `read`, `step(Motion)` and `motion` do for it, in the same order and with the same state
//! changes, and turns down anything else, which then goes the general way. Emitting still
//! goes through `emit`, so transforms, corners and cutter compensation apply as usual.
//!
//! `Profile::fast_lane` switches it off; the corpus test `fast_lane_changes_nothing` runs
//! every program both ways and compares the canonical text and the findings.

use super::{Interpreter, Slot};
use crate::canon::{CanonOp, CanonSink, DistanceMode};
use crate::diag::Diagnostic;
use crate::dialect::{DecimalInput, Meaning, Role};
use crate::syntax::{Block, Value, WordMode};

impl Interpreter<'_> {
    /// Executes `block` when it is a plain move; false, with nothing changed, when it is not.
    pub(super) fn fast_move(&mut self, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) -> bool {
        let Some(code) = self.st.motion_code else { return false };
        let def = self.code(code);
        let rapid = match def.meaning {
            Meaning::Rapid => true,
            Meaning::Linear if !self.st.inverse_time => false,
            _ => return false,
        };
        if block.words.is_empty()
            || !block.comments.is_empty()
            || !block.assigns.is_empty()
            || !block.exprs.is_empty()
            || block.control.is_some()
            || self.st.cycle_modal
            || self.st.modal_macro.is_some()
            || self.stop_message.is_some()
            || self.st.diameter
        {
            return false;
        }
        // Integers that count increments (`X10` is 10 µm on such a control) go the general way.
        let integers_scale = matches!(self.dialect.behaviour.decimal_input, DecimalInput::LeastIncrement { .. });
        let incremental = self.st.distance == DistanceMode::Incremental;
        let mut to = self.st.pos;
        let mut seen = 0u32;
        for w in &block.words {
            let axis = match w.role {
                Role::X => 0,
                Role::Y => 1,
                Role::Z => 2,
                _ => return false,
            };
            let Value::Number { value, decimal } = w.value else { return false };
            if w.mode != WordMode::Modal || seen & 1 << axis != 0 || (integers_scale && !decimal) {
                return false;
            }
            seen |= 1 << axis;
            to[axis] = if incremental { self.st.pos[axis] + value } else { value };
        }

        // The block's words, as `read` leaves them for whatever looks at them next.
        self.clear_block();
        for w in &block.words {
            let Value::Number { value, .. } = w.value else { unreachable!("checked above") };
            self.slots[w.role as usize] = Some(Slot { value, range: w.range, mode: w.mode });
            self.filled |= 1 << w.role as u32;
        }
        self.has_axes = true;
        // As `execute_code` and `motion` do for the modal motion code.
        self.st.motion_continued = true;
        self.motions += 1;
        self.st.leaving_comp = false;
        if rapid {
            self.note_tangent(to);
            self.emit(sink, CanonOp::StraightTraverse(to));
        } else {
            self.check_technology(def, block.range, diags);
            self.note_tangent(to);
            self.emit(sink, CanonOp::StraightFeed(to));
        }
        self.st.pos = to;
        true
    }
}

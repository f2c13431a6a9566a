//! Codes that neither move nor set a mode, only recorded or noted: the blank a program
//! defines (`BLK FORM`), a read of data only the machine has (`FN 18`), and a cycle kept as
//! intent without its moves.
//!
//! Doors: [`Interpreter::stock_corner`], [`Interpreter::machine_data_read`],
//! [`Interpreter::cycle_intent`].

use crate::canon::CanonSink;
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::interp::{Interpreter, stock_comment};
use crate::syntax::WordMode;
use crate::text::TextRange;

impl Interpreter<'_> {
    /// `BLK FORM 0.1 Z X+0 Y+0 Z-40` then `BLK FORM 0.2 X+100 Y+100 Z+0`: the blank's corners
    /// (the second may be incremental from the first). Passed on as the stock comment that
    /// plan recovery reads, as a CAM system writes it.
    pub(super) fn stock_corner(&mut self, sink: &mut dyn CanonSink) {
        let corner = |s: &Self, base: [f64; 3]| {
            [Role::X, Role::Y, Role::Z].map(|r| {
                let i = r as usize;
                match s.slots[i] {
                    Some(slot) if slot.mode == WordMode::Incremental => base[i] + slot.value,
                    Some(slot) => slot.value,
                    None => base[i],
                }
            })
        };
        let second = self.slot(Role::Extra).is_some_and(|v| (v - 0.2).abs() < 1e-9);
        // A corner given by a Q parameter set outside the file (`BLK FORM 0.2 X+Q1`, which
        // the TNC accepts): the blank is unknown, never one with a corner at 0.
        if [Role::X, Role::Y, Role::Z].into_iter().any(|r| self.word_unknown(r)) {
            self.st.blank_min = None;
            return;
        }
        match (second, self.st.blank_min) {
            (false, _) => self.st.blank_min = Some(corner(self, [0.0; 3])),
            (true, Some(min)) => {
                let max = corner(self, min);
                self.emit(sink, stock_comment(min, max));
                self.st.blank_min = None;
            }
            (true, None) => {}
        }
    }

    /// `FN 18` and the like: a read of data only the machine has. What follows from it may
    /// differ on the machine, and later arithmetic faults say so.
    pub(super) fn machine_data_read(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let msg = format!(
            "{} ({}) reads data only the machine has at run time: the parameter it sets keeps its value here, so what follows from it may differ on the machine",
            def.label(),
            def.name
        );
        self.st.machine_data_read = true;
        self.limited(diags, "machine-data-read", Diagnostic::new(Code::Unsupported, range, msg));
    }

    /// A cycle this interpreter keeps as intent only: its moves are not expanded.
    pub(super) fn cycle_intent(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        // A turning machine's cycle is a lathe's word, expanded or not.
        if def.meaning == Meaning::CycleTurnIntent {
            self.lathe_word();
        }
        let msg = format!("{} ({}) is kept as intent only: its moves are not expanded", def.label(), def.name);
        self.limited(diags, "cycle-not-expanded", Diagnostic::new(Code::Unsupported, range, msg));
    }
}

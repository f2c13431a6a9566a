//! Subprogram and macro calls and returns: `M98`, `M97`, `M99`, `G65`, and the modal macro
//! call (`G66`, `G67`). The interpreter does not run the called program itself: it leaves a
//! [`Request`] that the flow driver carries out after the block.
//!
//! Doors: [`Interpreter::call`], [`Interpreter::macro_codes`],
//! [`Interpreter::modal_macro_after`].

use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::interp::{Interpreter, ModalMacro, Request};
use crate::syntax::Block;
use crate::text::TextRange;

impl Interpreter<'_> {
    /// M98 (a program by number), M97 (a block of this file), M99 (a return, to block P).
    pub(super) fn call(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        match def.meaning {
            Meaning::SubprogramCall => {
                let start = match self.dialect.macros.call_start.and_then(|l| self.dialect.letter_role(l)) {
                    Some(role) if self.slots[role as usize].is_some() => match self.program_number(role, range, diags) {
                        Some(n) => Some(n),
                        None => return,
                    },
                    _ => None,
                };
                if self.slots[Role::P as usize].is_none()
                    && let Some(number) = start
                {
                    // `M98 H20` (Mitsubishi), `M98 Q20` (Fanuc 0i-F, 30i): without a program, block
                    // N20 of this one.
                    let repeats = self.repeat_count(diags, range);
                    self.request = Some(Request::CallLocal { number, repeats });
                    return;
                }
                let Some(p) = self.program_number(Role::P, range, diags) else { return };
                let mut repeats = self.repeat_count(diags, range);
                let mut program = p;
                if self.dialect.macros.repeat_in_p && self.slot(Role::L).is_none() && p > 9999 {
                    (repeats, program) = (p / 10_000, p % 10_000);
                }
                self.request = Some(Request::Call { program, repeats, macro_call: false, args: Vec::new(), start });
            }
            Meaning::LocalSubprogramCall => {
                let Some(number) = self.program_number(Role::P, range, diags) else { return };
                let repeats = self.repeat_count(diags, range);
                self.request = Some(Request::CallLocal { number, repeats });
            }
            _ => {
                let goto = self.slot(Role::P).filter(|p| *p >= 0.0 && p.fract() == 0.0).map(|p| p as u32);
                self.request = Some(Request::Return { goto });
            }
        }
    }

    /// G65 (a macro call), G66 (a modal macro call), G67 (its cancel): true when the block
    /// has one, and then nothing else of it runs (its other words are arguments).
    pub(in crate::interp) fn macro_codes(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        if let Some(k) = self.codes.iter().position(|&(c, _)| self.code(c).meaning == Meaning::MacroCall) {
            self.macro_call(block, self.codes[k].1, diags);
            return true;
        }
        if let Some(&(c, range)) =
            self.codes.iter().find(|&&(c, _)| matches!(self.code(c).meaning, Meaning::ModalMacroCall | Meaning::ModalMacroCancel))
        {
            // G66 registers the call (its words are arguments, nothing moves); G67 drops it.
            self.st.modal_macro = None;
            if self.code(c).meaning == Meaning::ModalMacroCall
                && let Some(program) = self.program_number(Role::P, range, diags)
            {
                let repeats = self.repeat_count(diags, range);
                let args = self.macro_args(block, diags);
                self.st.modal_macro = Some(ModalMacro { program, repeats, args, depth: self.depth });
            }
            return true;
        }
        false
    }

    /// After a block that moved, the registered G66 macro is called (not from inside it).
    pub(in crate::interp) fn modal_macro_after(&mut self, motions: u64) {
        if let Some(m) = &self.st.modal_macro
            && self.motions != motions
            && self.request.is_none()
            && m.depth == self.depth
        {
            self.request =
                Some(Request::Call { program: m.program, repeats: m.repeats, macro_call: true, args: m.args.clone(), start: None });
        }
    }

    /// `G65 P9010 L2 A1 B2`: a macro call; the other words are arguments by letter.
    fn macro_call(&mut self, block: &Block, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let Some(program) = self.program_number(Role::P, range, diags) else { return };
        let repeats = self.repeat_count(diags, range);
        let args = self.macro_args(block, diags);
        self.request = Some(Request::Call { program, repeats, macro_call: true, args, start: None });
    }

    /// The argument words of a macro call (all but G, P and L) as (local, value).
    fn macro_args(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> Vec<(u16, f64)> {
        let mut args = Vec::new();
        for w in &block.words {
            if matches!(w.role, Role::G | Role::P | Role::L) {
                continue;
            }
            let Some(local) = self.dialect.macros.arguments.get((w.letter.wrapping_sub(b'A')) as usize).copied().flatten() else {
                let shown = block.text(w.range);
                diags.push(Diagnostic::new(Code::UnusedWord, w.range, format!("`{shown}` is not a macro argument in this dialect")));
                continue;
            };
            // Arguments keep the value as written: the least-increment rule does not apply.
            if let Some(v) = self.value(block, w.value, w.range, diags) {
                args.push((local, v));
            }
        }
        args
    }

    /// A program number from the word `role`, checked.
    fn program_number(&mut self, role: Role, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<u32> {
        let slot = self.slots[role as usize]?;
        // The least-increment rule may have scaled P; program numbers are read as written.
        let v = slot.value;
        if v < 0.0 || v.fract() != 0.0 || v > 99_999_999.0 {
            diags.push(Diagnostic::new(Code::MalformedNumber, range, format!("program number {v} must be a whole number")));
            return None;
        }
        Some(v as u32)
    }

    /// The repeat count of a call: L, or 1.
    fn repeat_count(&mut self, diags: &mut Vec<Diagnostic>, range: TextRange) -> u32 {
        match self.slot(Role::L) {
            None => 1,
            Some(l) if l >= 0.0 && l.fract() == 0.0 && l < 1e6 => l as u32,
            Some(l) => {
                diags.push(Diagnostic::new(Code::MalformedNumber, range, format!("repeat count L{l} must be a whole number")));
                1
            }
        }
    }
}

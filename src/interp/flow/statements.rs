//! The control statements, one function each: conditions (`IF`, `elseif`, `else`), loops
//! (`while`, `WHILE .. DO`, `do`, `repeat`, `FOR`, `REPEAT .. UNTIL`, `LOOP`, and their ends,
//! `break`, `continue`), jumps (`GOTO` and its forms, `CASE`), calls and returns (`o-call`,
//! `CALL LBL`, `REPEAT` of a section, `CALL PGM`, `PROC`, `endsub`, `return`), labels and
//! subroutine definitions met in the flow, `DPRNT`, and the statements that are skipped.
//! The driver (`flow/mod.rs`) keeps what they change: the loops, frames and jumps.
//!
//! Door: [`Driver::control`], which looks up the statement's function by its kind.

use super::{
    Direction, Driver, FrameKind, LoopKind, LoopPart, Mark, Pos, block_if, normalise_label, print_format, set_variable, statement_head,
};
use crate::canon::{Canon, CanonOp, CanonSink};
use crate::diag::{Code, Diagnostic, Severity};
use crate::dialect::{MainReturn, Statement};
use crate::interp::{Interpreter, eval};
use crate::syntax::{Block, Control, Expr, Otherwise};
use crate::text::TextRange;

impl<'a> Driver<'a, '_> {
    /// Carries out control statement `c` of `block` (which starts at `start`): the statement's
    /// label first (`o#<sub> call` reads it from a parameter), then the function of its kind.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn control(
        &mut self,
        c: &Control,
        block: &Block,
        start: Pos,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let here = self.pos();
        let Some(statement) = c.statement else {
            self.unknown_statement(c, block, interp, diags);
            return;
        };
        let mut label = match c.label_expr {
            // `o#<sub> call`: the label is the parameter's value, a whole number.
            Some(e) => match self.value(interp, block, e, diags) {
                Some(v) if v.fract() == 0.0 && (0.0..1e9).contains(&v) => Some(format!("{v}")),
                Some(v) => {
                    self.error(diags, Code::MalformedNumber, c.range, format!("a label from a parameter must be a whole number, not {v}"));
                    return;
                }
                None => return,
            },
            None => self.label_text(block, c),
        };
        match statement {
            Statement::If => self.if_statement(c, block, start, &label, interp, sink, diags),
            Statement::ElseIf => self.else_if(c, block, start, &label, interp, diags),
            Statement::Else => self.else_statement(c, start, &label, interp, diags),
            // `O108 endif` with no `O108 if` before it: RS274NGC stops (undefined O-word label).
            Statement::EndIf if label.is_some() && self.dialect.lexical.control_word.is_some() && !self.opened_before(start, &label) => {
                self.unmatched(c, "endif", "if", diags);
            }
            Statement::EndIf | Statement::Then | Statement::Output | Statement::Declare => {}
            Statement::Print => print_statement(c, block, interp, sink),
            // `o100 while [..]`, or the tail of `o100 do`; else `WHILE [..] DO m`.
            Statement::While if label.is_some() || c.then != Some(Statement::Do) => {
                self.while_statement(c, block, start, here, &label, interp, diags)
            }
            Statement::While => self.while_do(c, block, start, here, interp, diags),
            Statement::Do if label.is_some() => self.push_loop(LoopKind::Do, label.take(), None, start, here),
            Statement::Do => self.numbered_do(c, block, start, here, interp, diags),
            Statement::EndWhile => self.end_while(c, start, &label, interp, diags),
            Statement::EndDo => self.end_do(c, block, start, interp, diags),
            Statement::Repeat => self.repeat(c, block, start, here, label.take(), interp, diags),
            Statement::EndRepeat => self.end_repeat(c, start, &label, interp, diags),
            Statement::Break | Statement::Continue => self.break_or_continue(statement, c, start, &label, interp, diags),
            Statement::Sub => self.sub_definition(c, start, &label, interp, diags),
            Statement::EndSub | Statement::Return => self.end_sub_or_return(statement, c, block, interp, sink, diags),
            Statement::Call => self.call_sub(c, label.take(), block, start, interp, diags),
            Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet | Statement::GotoLabel => {
                self.jump_statement(statement, c, block, start, interp, diags)
            }
            Statement::For => self.for_head(c, block, start, here, interp, diags),
            Statement::EndFor | Statement::EndLoop => self.end_for_or_loop(statement, c, start, interp, diags),
            Statement::RepeatUntil => self.repeat_until(start, here),
            Statement::Until => self.until(c, block, start, interp, diags),
            Statement::Loop => self.loop_statement(c, start, here, interp, diags),
            Statement::Label => self.label_statement(c, block, interp, diags),
            Statement::CallLabel => self.call_label(c, block, start, interp, diags),
            Statement::Case => self.case(c, block, start, interp, diags),
            Statement::RepeatSection | Statement::RepeatBlock => self.repeat_section(statement, c, block, start, interp, diags),
            Statement::CallProgram => self.call_program(c, block, start, interp, diags),
            Statement::Procedure => self.procedure(c, block, interp),
            Statement::Inert => {}
            Statement::Unsupported => unsupported_statement(c, block, interp, diags),
        }
        // Its room kept for the next statement's label.
        if let Some(s) = label {
            self.spare_label = s;
        }
    }

    /// A statement keyword the dialect does not have: the statement is skipped, and said so.
    fn unknown_statement(&self, c: &Control, block: &Block, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        if let Some(k) = c.keyword {
            let word = block.text(k);
            let head = statement_head(block, c);
            interp.limited(
                diags,
                "statement",
                Diagnostic::new(
                    Code::UnknownStatement,
                    k,
                    format!("`{word}` is not a statement of the {} dialect; `{head}` was skipped", self.dialect.name),
                ),
            );
        }
    }

    /// `IF [..] GOTO n`, `IF [..] THEN ...` (one line, or a block IF up to its `ELSE`/`ENDIF`),
    /// and the structured `IF` of the languages that have one.
    #[allow(clippy::too_many_arguments)]
    fn if_statement(
        &mut self,
        c: &Control,
        block: &Block,
        start: Pos,
        label: &Option<String>,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let Some(cond) = self.condition(interp, c, block, diags) else { return };
        // `IF [..] #9=#4109` where THEN may be left out: the statement after the condition.
        let then = match c.then {
            None if self.dialect.macros.if_then_optional && !(block.words.is_empty() && block.assigns.is_empty()) => Some(Statement::Then),
            t => t,
        };
        match then {
            Some(st @ (Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet | Statement::GotoLabel)) => {
                if cond {
                    self.jump_statement(st, c, block, start, interp, diags);
                } else if let Some(o) = &c.otherwise {
                    self.otherwise(c, o, block, start, interp, sink, diags);
                }
            }
            Some(Statement::Then) if block_if(block, c, self.dialect) => {
                if !cond {
                    self.next_branch(label, start, c.range, interp, diags);
                }
            }
            Some(Statement::Then) if c.otherwise.is_some() => {
                // `IF [c] THEN #1 = 1 ELSE #2 = 1`: the THEN clause's part of the block, or
                // the ELSE's. On a condition not known here, the way `condition` chose (its
                // note says which).
                let Some(o) = &c.otherwise else { return };
                if cond {
                    interp.execute(&branch_of(block, o, true), sink, diags);
                } else {
                    self.otherwise(c, o, block, start, interp, sink, diags);
                }
            }
            Some(Statement::Then) => {
                if self.undecided && !block.assigns.is_empty() && !self.is_alarm(block) {
                    // Whether the assignment ran is not known (`IF [#24 NE #0] THEN
                    // #30 = #24` on an argument): what it sets holds either value.
                    interp.execute_either(block, self.undecided_from.clone(), sink, diags);
                } else if cond {
                    interp.execute(block, sink, diags);
                }
            }
            None if c.statement == Some(Statement::If)
                && self.dialect.macros.if_alone_reads
                && nothing_after(block, c, &self.dialect.lexical) =>
            {
                // `IF #50010`: the condition is read (on CNC12 a PLC input, which stops
                // lookahead there) and nothing else runs, whichever way it goes.
            }
            None if c.statement == Some(Statement::If) && !self.dialect.macros.statements.iter().any(|(_, st)| *st == Statement::EndIf) => {
                // No block IF in the language (Fanuc Custom Macro B: `IF [..] GOTO n`,
                // `IF [..] THEN`): the control stops at the block whatever the condition.
                let forms = self.if_forms();
                self.error(
                    diags,
                    Code::MissingLabel,
                    c.range,
                    format!("an `IF` condition with neither {forms} after it; the control stops here"),
                );
            }
            _ => {
                if !cond {
                    self.next_branch(label, start, c.range, interp, diags);
                }
            }
        }
    }

    /// The `ELSE` of a one-line `IF` whose condition is false: its jump, or its part of the
    /// block's words and assignments.
    #[allow(clippy::too_many_arguments)]
    fn otherwise(
        &mut self,
        c: &Control,
        o: &Otherwise,
        block: &Block,
        start: Pos,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        if let Some(jump) = o.jump {
            let control = Control { range: c.range, statement: Some(jump), name: o.name, target: o.target, ..Control::default() };
            self.jump_statement(jump, &control, block, start, interp, diags);
        } else if (o.words as usize) < block.words.len() || (o.assigns as usize) < block.assigns.len() {
            interp.execute(&branch_of(block, o, false), sink, diags);
        }
    }

    /// `elseif`: reached by a jump from a false condition, its own condition decides; reached
    /// from the branch before it, that branch is done and the run goes past `endif`.
    #[allow(clippy::too_many_arguments)]
    fn else_if(
        &mut self,
        c: &Control,
        block: &Block,
        start: Pos,
        label: &Option<String>,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        if self.landing == Some((self.cur, start.at)) {
            self.landing = None;
            let Some(cond) = self.condition(interp, c, block, diags) else { return };
            if !cond {
                self.next_branch(label, start, c.range, interp, diags);
            }
        } else {
            self.skip_structure(label, start, c.range, Statement::If, Statement::EndIf, &[Statement::EndIf], interp, diags);
        }
    }

    /// `else`: reached by a jump from a false condition, its branch runs; reached from the
    /// branch before it, the run goes past `endif`.
    fn else_statement(
        &mut self,
        c: &Control,
        start: Pos,
        label: &Option<String>,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        if self.landing == Some((self.cur, start.at)) {
            self.landing = None;
        } else {
            self.skip_structure(label, start, c.range, Statement::If, Statement::EndIf, &[Statement::EndIf], interp, diags);
        }
    }

    /// `o100 while [..]`: the head of a while loop, or, after `o100 do`, the tail of a
    /// do-loop, which goes round again while the condition holds.
    #[allow(clippy::too_many_arguments)]
    fn while_statement(
        &mut self,
        c: &Control,
        block: &Block,
        start: Pos,
        here: Pos,
        label: &Option<String>,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let Some(cond) = self.condition(interp, c, block, diags) else { return };
        if let Some(k) = self.top_loop(|l| l.kind == LoopKind::Do && l.label == *label) {
            // The tail of a do-loop.
            if cond {
                if self.count_iteration(k, c.range, interp, diags) {
                    self.loop_jump(k, LoopPart::Body, start, interp, diags);
                }
            } else {
                self.loops.truncate(k);
            }
            return;
        }
        if self.loop_head(LoopKind::While, label, None, cond, start, here, c.range, interp, diags) {
            self.skip_structure(label, start, c.range, Statement::While, Statement::EndWhile, &[Statement::EndWhile], interp, diags);
        }
    }

    /// `WHILE [c] DO m`: the head of a numbered loop, whose end is `END m`.
    fn while_do(&mut self, c: &Control, block: &Block, start: Pos, here: Pos, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        let id = self.loop_id(c, block, interp, diags);
        let Some(cond) = self.condition(interp, c, block, diags) else { return };
        if self.loop_head(LoopKind::Numbered, &None, id, cond, start, here, c.range, interp, diags) {
            self.skip_numbered_end(id, start, c.range, interp, diags);
        }
    }

    /// `DO m` without WHILE: an endless loop that only a jump leaves.
    fn numbered_do(
        &mut self,
        c: &Control,
        block: &Block,
        start: Pos,
        here: Pos,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let id = self.loop_id(c, block, interp, diags);
        match self.top_loop(|l| l.kind == LoopKind::Numbered && l.head == start) {
            Some(k) => {
                self.count_iteration(k, c.range, interp, diags);
            }
            None => self.push_loop(LoopKind::Numbered, None, id, start, here),
        }
    }

    /// `o100 endwhile`: back to the loop's head.
    fn end_while(&mut self, c: &Control, start: Pos, label: &Option<String>, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        match self.top_loop(|l| l.kind == LoopKind::While && l.label == *label) {
            Some(k) => {
                self.loop_jump(k, LoopPart::Head, start, interp, diags);
            }
            None => self.unmatched(c, "endwhile", "while", diags),
        }
    }

    /// `END m`: back to the head of numbered loop m.
    fn end_do(&mut self, c: &Control, block: &Block, start: Pos, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        let id = self.loop_id(c, block, interp, diags);
        match self.top_loop(|l| l.kind == LoopKind::Numbered && l.id == id) {
            Some(k) => {
                self.loop_jump(k, LoopPart::Head, start, interp, diags);
            }
            None => self.unmatched(c, "END", "WHILE ... DO", diags),
        }
    }

    /// `o100 repeat [n]`: a loop that runs n times; none at all for n below 1.
    #[allow(clippy::too_many_arguments)]
    fn repeat(
        &mut self,
        c: &Control,
        block: &Block,
        start: Pos,
        here: Pos,
        label: Option<String>,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let count = match c.args.first() {
            Some(&e) => self.value(interp, block, e, diags).map_or(0.0, |v| if eval::is_null(v) { 0.0 } else { v }),
            None => 0.0,
        };
        if count >= 1.0 {
            self.push_loop(LoopKind::Repeat, label, None, start, here);
            if let Some(l) = self.loops.last_mut() {
                l.remaining = count.min(u64::MAX as f64) as u64;
            }
        } else {
            self.skip_to(start, c.range, "endrepeat", |m| same_label(m, &label, &[Statement::EndRepeat]), interp, diags);
        }
    }

    /// `o100 endrepeat`: the end of one pass of a counted loop.
    fn end_repeat(&mut self, c: &Control, start: Pos, label: &Option<String>, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        match self.top_loop(|l| l.kind == LoopKind::Repeat && l.label == *label) {
            Some(k) => self.next_repeat(k, true, start, c.range, interp, diags),
            None => self.unmatched(c, "endrepeat", "repeat", diags),
        }
    }

    /// `o100 break` (out of the loop, past its end) and `o100 continue` (to its next pass).
    #[allow(clippy::too_many_arguments)]
    fn break_or_continue(
        &mut self,
        statement: Statement,
        c: &Control,
        start: Pos,
        label: &Option<String>,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let Some(k) = self.top_loop(|l| l.label == *label && l.kind != LoopKind::Numbered) else {
            self.unmatched(c, if statement == Statement::Break { "break" } else { "continue" }, "a loop", diags);
            return;
        };
        let kind = self.loops[k].kind;
        let end: &[Statement] = match kind {
            LoopKind::While => &[Statement::EndWhile],
            LoopKind::Repeat => &[Statement::EndRepeat],
            LoopKind::Do | LoopKind::Numbered => &[Statement::While],
            LoopKind::For => &[Statement::EndFor],
            LoopKind::Until => &[Statement::Until],
            LoopKind::Forever => &[Statement::EndLoop],
        };
        match (statement, kind) {
            (Statement::Break, _) => {
                self.loops.truncate(k);
                self.skip_to(start, c.range, "the loop end", |m| same_label(m, label, end), interp, diags);
            }
            (_, LoopKind::While) => {
                self.loop_jump(k, LoopPart::Head, start, interp, diags);
            }
            (_, LoopKind::Repeat) => self.next_repeat(k, false, start, c.range, interp, diags),
            _ => {
                // Continue in a do-loop: evaluate its tail.
                self.loops.truncate(k + 1);
                if let Some(m) = self.find_after(start.at, |m| same_label(m, label, end)) {
                    self.jump(self.cur, m.start, start, interp, diags);
                }
            }
        }
    }

    /// `o100 sub`: a definition met in the flow of the program is skipped, past its `endsub`.
    fn sub_definition(
        &mut self,
        c: &Control,
        start: Pos,
        label: &Option<String>,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        // Definitions do not nest: one inside another's body stops the control.
        if self.frames.last().is_some_and(|f| f.kind == FrameKind::Sub) {
            let msg = "a subroutine definition inside a running subroutine: definitions do not nest";
            diags.push(Diagnostic::new(Code::NestedDefinition, c.range, msg));
        }
        // Where o-words are control words, a bare one (`O103`) starts a numbered subprogram
        // too (RS274NGC: "Nested subroutine definition" inside another's body).
        let bare = self.dialect.lexical.control_word.is_some();
        let inner = self.find_after(start.at, |m| {
            same_label(m, label, &[Statement::EndSub])
                || m.statement == Some(Statement::Sub)
                || (bare && m.statement.is_none() && m.program.is_some())
        });
        if let Some(m) = inner.filter(|m| m.statement == Some(Statement::Sub) || m.statement.is_none()) {
            let msg = format!("another subroutine is defined inside this one (line {}): definitions do not nest", m.start.line);
            diags.push(Diagnostic::new(Code::NestedDefinition, c.range, msg));
        }
        let head = self.frames.is_empty() && self.cur == 0;
        let ends = enclosing_end(self.marks(self.cur), start.at, label);
        if let (Some((own, _)), Some((foreign, after))) = (ends.own, ends.foreign) {
            let msg = format!(
                "the `endsub` of line {} names another subroutine, yet a call of this one returns there whatever its name (rs274){}",
                foreign.line,
                if after.line < own.line {
                    format!(": lines {} to {}, before this definition's own `endsub`, never run", after.line, own.line - 1)
                } else {
                    String::new()
                }
            );
            diags.push(Diagnostic::new(Code::ForeignEndLabel, c.range, msg));
        }
        // A definition that opens the file is a subroutine file, which the control reads
        // only when a call opens it (RS274NGC "Calling Files", an M6 remap's `ngc=`): run
        // from its `sub` line, an `endsub` inside one of its `if`s or loops returns like
        // `return`, and the definition ends at the `endsub` no block of it encloses.
        if head && !self.main_work {
            if let Some((_, next)) = ends.own {
                self.library = true;
                self.unreadable_body(start, next, diags);
                self.switch_to(self.cur, next, interp);
                return;
            }
            if let Some(foreign) = ends.foreign {
                self.foreign_end(c, start, label, foreign, interp, diags);
                return;
            }
        }
        self.library |= head;
        self.skip_to(start, c.range, "endsub", |m| same_label(m, label, &[Statement::EndSub]), interp, diags);
    }

    /// A subroutine file's definition with no `endsub` of its own label, and the `endsub` of
    /// another label `(start, next)` no block of its body encloses. A call of the subroutine
    /// opens its own file (`o<probe> call` opens `probe.ngc`), runs it from its `sub` line and
    /// returns at that `endsub` (`rs274 -g`); read as a main program, rs274 looks past it for
    /// this definition's own `endsub` and stops ("File ended with no percent sign or program
    /// end"). So the file is a subroutine file with a copy's leftover label (a warning) when it
    /// is the subroutine's own file (by its name, or called as `check --as called` says), or
    /// when nothing but a program end, `%` lines or comments follows that `endsub`: no main
    /// program is written after it. Otherwise (a main program that opens with a definition,
    /// subroutines first and its own blocks after them) the definition is not closed, and the
    /// control stops.
    fn foreign_end(
        &mut self,
        c: &Control,
        start: Pos,
        label: &Option<String>,
        (end, next): (Pos, Pos),
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let name = label.as_deref().unwrap_or_default();
        let own_file = self.profile.role == crate::interp::ProgramRole::Called
            || self.profile.file_name.as_deref().is_some_and(|f| f.rsplit_once('.').map_or(f, |(stem, _)| stem).eq_ignore_ascii_case(name));
        let end_follows = self.only_end_follows(next);
        if !own_file && !end_follows {
            let msg = format!(
                "no `endsub` of `o<{name}>` follows: the one of line {} names another subroutine, and ends this definition only in the subroutine's own file `{name}.ngc` that a call opens; read as a main program, the control looks past it for this definition's end and stops at the end of the file",
                end.line
            );
            self.library = true;
            self.error(diags, Code::MissingLabel, c.range, msg);
            return;
        }
        let msg = format!(
            "this subroutine file's definition ends at the `endsub` of line {}, which names another subroutine: a call runs the file from its `sub` line and returns at that `endsub` whatever its name (rs274), so the label looks like a copy's leftover{}",
            end.line,
            if end_follows { "" } else { "; the blocks after it never run" }
        );
        diags.push(Diagnostic::new(Code::ForeignEndLabel, c.range, msg));
        self.library = true;
        self.unreadable_body(start, next, diags);
        if end_follows {
            self.switch_to(self.cur, next, interp);
        } else {
            // A call returns at that `endsub`: what the file holds after it is never run.
            self.stop = true;
        }
    }

    /// Whether nothing but a program end (`M2`, `M30`), `%` lines or comments follows `from`
    /// up to the first program end or the end of the text.
    fn only_end_follows(&self, from: Pos) -> bool {
        let mut parser = self.parser.fork(self.sources[self.cur].text, from.at, from.line);
        let mut block = Block::default();
        let mut scratch = Vec::new();
        while parser.next_block(&mut block, &mut scratch) {
            if !block.assigns.is_empty() || block.control.is_some() || block.program_number.is_some() || block.label.is_some() {
                return false;
            }
            if !block.words.is_empty() {
                return block.words.iter().all(|w| {
                    matches!(self.word_meaning(w), Some(crate::dialect::Meaning::ProgramEnd | crate::dialect::Meaning::ProgramEndRewind))
                });
            }
        }
        true
    }

    /// The blocks of a subroutine file's body (from its `sub` line to `end`) whose text the
    /// control cannot read: a malformed number or expression, a comment left open. The file
    /// runs when a call opens it (RS274NGC "Calling Files"), and rs274 stops at such a block
    /// when it runs ("bad number format" for `[<#_value> EQ -1]`); its moves here are not run.
    fn unreadable_body(&self, start: Pos, end: Pos, diags: &mut Vec<Diagnostic>) {
        const UNREADABLE: [Code; 3] = [Code::MalformedNumber, Code::MalformedExpression, Code::UnterminatedComment];
        let mut parser = self.parser.fork(self.sources[self.cur].text, start.at, start.line);
        let mut block = crate::syntax::Block::default();
        let mut scratch = Vec::new();
        // The `sub` line itself, read already.
        if !parser.next_block(&mut block, &mut scratch) {
            return;
        }
        scratch.clear();
        while parser.offset() < end.at && parser.next_block(&mut block, &mut scratch) {
            if block.range.start as usize >= end.at {
                break;
            }
            // The first such finding of a block: the control stops there.
            diags.extend(scratch.drain(..).find(|d| d.is_error() && UNREADABLE.contains(&d.code)));
            scratch.clear();
        }
    }

    /// `o100 endsub`, `o100 return [value]`: back to the caller, with the value; a return in
    /// the main program ends it where the dialect says so.
    fn end_sub_or_return(
        &mut self,
        statement: Statement,
        c: &Control,
        block: &Block,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        if let Some(&e) = c.args.first()
            && let Some(v) = self.value(interp, block, e, diags)
        {
            Self::set_return_value(self.dialect, interp, v, true);
        }
        match self.frames.last() {
            Some(f) if f.kind == FrameKind::Sub || statement == Statement::Return => self.return_from(None, block, interp, diags),
            None if statement == Statement::Return && self.dialect.macros.main_return == MainReturn::End => {
                self.main_return(block, interp, sink, diags)
            }
            _ => self.unmatched(c, if statement == Statement::Return { "return" } else { "endsub" }, "call", diags),
        }
    }

    /// `ENDFOR`, `ENDLOOP`: back to the head of the loop.
    fn end_for_or_loop(
        &mut self,
        statement: Statement,
        c: &Control,
        start: Pos,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let (kind, what, opener) =
            if statement == Statement::EndFor { (LoopKind::For, "ENDFOR", "FOR") } else { (LoopKind::Forever, "ENDLOOP", "LOOP") };
        match self.top_loop(|l| l.kind == kind) {
            Some(k) => self.loop_jump(k, LoopPart::Head, start, interp, diags),
            None => self.unmatched(c, what, opener, diags),
        }
    }

    /// `REPEAT` (before `UNTIL`): the loop opens, the first time it is met.
    fn repeat_until(&mut self, start: Pos, here: Pos) {
        if self.top_loop(|l| l.kind == LoopKind::Until && l.head == start).is_none() {
            self.push_loop(LoopKind::Until, None, None, start, here);
        }
    }

    /// `UNTIL [c]`: the loop ends once the condition holds, else goes round again.
    fn until(&mut self, c: &Control, block: &Block, start: Pos, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        let Some(k) = self.top_loop(|l| l.kind == LoopKind::Until) else {
            self.unmatched(c, "UNTIL", "REPEAT", diags);
            return;
        };
        let Some(cond) = self.condition(interp, c, block, diags) else { return };
        if cond {
            self.loops.truncate(k);
        } else if self.count_iteration(k, c.range, interp, diags) {
            self.loop_jump(k, LoopPart::Body, start, interp, diags);
        }
    }

    /// `LOOP` (up to `ENDLOOP`): an endless loop that only a jump leaves; each time it comes
    /// round counts.
    fn loop_statement(&mut self, c: &Control, start: Pos, here: Pos, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        match self.top_loop(|l| l.kind == LoopKind::Forever && l.head == start) {
            Some(k) => {
                self.count_iteration(k, c.range, interp, diags);
            }
            None => self.push_loop(LoopKind::Forever, None, None, start, here),
        }
    }

    /// A label (`LBL 5`): the end label (`LBL 0`) returns from a label call.
    fn label_statement(&mut self, c: &Control, block: &Block, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        let end = self.dialect.macros.end_label.as_deref();
        let in_label = self.frames.last().is_some_and(|f| f.kind == FrameKind::Label);
        // A literal label outside a label call has nothing to say (an expression is still
        // read, for its findings).
        let literal = c.name.is_some() || c.target.is_some_and(|e| matches!(block.exprs.get(e as usize), Some(Expr::Num(_))));
        if end.is_none() || (!in_label && literal) {
            return;
        }
        let returns = self.target_label(c, block, interp, diags).as_deref() == end;
        if returns && self.frames.last().is_some_and(|f| f.kind == FrameKind::Label) {
            self.return_from(None, block, interp, diags);
        }
    }

    /// `FOR var = a TO b`: sets the counter on entry, steps it by one when the loop comes
    /// round, and leaves past `ENDFOR` once it is above `b`.
    fn for_head(&mut self, c: &Control, block: &Block, start: Pos, here: Pos, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        let (Some(var), [first, last, rest @ ..]) = (c.target, c.args.as_slice()) else { return };
        let step = match rest.first() {
            Some(&e) => match self.value(interp, block, e, diags) {
                Some(s) if s != 0.0 && s.is_finite() => s,
                Some(_) => {
                    self.error(diags, Code::MalformedExpression, c.range, "a loop step of 0 never ends the loop; the run stops here");
                    return;
                }
                None => return,
            },
            None => 1.0,
        };
        let again = self.top_loop(|l| l.kind == LoopKind::For && l.head == start);
        let value = match again {
            Some(_) => self.value(interp, block, var, diags).map(|v| v + step),
            None => self.value(interp, block, *first, diags),
        };
        let (Some(value), Some(last)) = (value, self.value(interp, block, *last, diags)) else { return };
        if let Err(e) = set_variable(interp, block, var, value) {
            diags.push(interp.eval_diag(e, c.range));
            return;
        }
        let go_on = if step > 0.0 { value <= last } else { value >= last };
        if self.loop_head(LoopKind::For, &None, None, go_on, start, here, c.range, interp, diags) {
            self.skip_structure(&None, start, c.range, Statement::For, Statement::EndFor, &[Statement::EndFor], interp, diags);
        }
    }

    /// `GOTO 10`, `GOTOF MARK1`, `GOTOB N100`, `GOTO LBL "X"`: a jump to a block number or a label.
    fn jump_statement(
        &mut self,
        st: Statement,
        c: &Control,
        block: &Block,
        start: Pos,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let dir = match st {
            Statement::GotoForward => Direction::Forward,
            Statement::GotoBack => Direction::Back,
            _ => Direction::Any,
        };
        let quiet = st == Statement::GotoQuiet;
        if st != Statement::GotoLabel && c.name.is_none() {
            if let Some(n) = self.target_number(c.target, block, interp, diags) {
                self.goto_number(n, dir, quiet, block.range, start, interp, diags);
            }
            return;
        }
        // A target written as a name or a constant is found once: a loop's jump comes again.
        let fixed = c.name.is_some() || c.target.is_some_and(|e| super::constant(block, e));
        let key = (self.cur, start.at);
        if let Some((pos, name)) = self.jump_targets.get(&key).filter(|_| fixed).cloned() {
            self.jump_to(pos, &name, block.range, start, interp, diags);
            return;
        }
        let Some(name) = self.target_label(c, block, interp, diags) else {
            self.error(diags, Code::MissingLabel, block.range, "the jump has no target");
            return;
        };
        let found = {
            let marks = self.marks(self.cur);
            let at = |m: &&Mark| m.defines.as_deref() == Some(name.as_str());
            match dir {
                Direction::Forward => marks.iter().filter(at).find(|m| m.start.at > start.at),
                Direction::Back => marks.iter().filter(at).rev().find(|m| m.start.at < start.at),
                Direction::Any => marks.iter().filter(at).find(|m| m.start.at > start.at).or_else(|| marks.iter().find(at)),
            }
            .map(|m| m.start)
        };
        match found {
            Some(pos) => {
                if fixed {
                    self.jump_targets.insert(key, (pos, name.as_str().into()));
                }
                self.jump_to(pos, &name, block.range, start, interp, diags);
            }
            None => {
                // A label that is a block number: `GOTOF N100`.
                let letter = self.dialect.lexical.block_number.map(|c| c.to_ascii_lowercase());
                let number = name.strip_prefix(|c| Some(c) == letter).and_then(|n| n.parse::<u32>().ok());
                if let Some(n) = number.filter(|_| st != Statement::GotoLabel) {
                    self.goto_number(n, dir, quiet, block.range, start, interp, diags);
                } else if !quiet {
                    let whither = match dir {
                        Direction::Forward => " after this block",
                        Direction::Back => " before this block",
                        Direction::Any => "",
                    };
                    self.error(
                        diags,
                        Code::MissingLabel,
                        block.range,
                        format!("no label `{name}`{whither} to jump to; the run stops here"),
                    );
                }
            }
        }
    }

    /// `CASE R1 OF 1 GOTOF A 2 GOTOF B DEFAULT GOTOF C`: the first branch whose value equals
    /// the operand, or `DEFAULT`, jumps; with neither the run goes on.
    fn case(&mut self, c: &Control, block: &Block, start: Pos, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        let Some(operand) = c.args.first().and_then(|&e| self.value(interp, block, e, diags)) else { return };
        for branch in &c.cases {
            let taken = match branch.value {
                None => true,
                Some(e) => match self.value(interp, block, e, diags) {
                    Some(v) => v == operand,
                    None => return,
                },
            };
            if taken {
                let jump = Control {
                    range: c.range,
                    statement: Some(branch.jump),
                    name: branch.name,
                    target: branch.target,
                    ..Control::default()
                };
                self.jump_statement(branch.jump, &jump, block, start, interp, diags);
                return;
            }
        }
    }

    fn call_sub(
        &mut self,
        c: &Control,
        label: Option<String>,
        block: &Block,
        start: Pos,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let Some(label) = label else { return };
        let mut args = Vec::with_capacity(c.args.len());
        for &e in &c.args {
            let Some(v) = self.value(interp, block, e, diags) else { return };
            args.push(v);
        }
        let is_sub = |m: &Mark| m.label.as_deref() == Some(label.as_str()) && m.statement == Some(Statement::Sub);
        let Some((source, body)) = self.locate(&label, is_sub) else {
            // A numbered subroutine lives in the program itself: its absence is a missing
            // label. A named one is a file the control looks up in its subroutine path
            // (LinuxCNC `SUBROUTINE_PATH`): the machine's library, so the call is skipped with
            // a warning where the dialect says the control has such a path.
            if self.dialect.behaviour.subroutine_path && !label.bytes().all(|b| b.is_ascii_digit()) {
                let msg = format!(
                    "subroutine o<{label}> is neither in this program nor in the program directory; the control looks it up in its subroutine path, but this analysis skips the call and lacks its moves"
                );
                let mut d = Diagnostic::new(Code::MissingProgram, c.range, msg);
                d.severity = Severity::Warning;
                interp.limited(diags, "program", d);
            } else {
                let msg = format!("subroutine o<{label}> is neither in this program nor in the program directory");
                self.error(diags, Code::MissingLabel, c.range, msg);
            }
            return;
        };
        Self::set_return_value(self.dialect, interp, 0.0, false);
        let (first, last) = self.dialect.macros.locals;
        let args: Vec<(u16, f64)> = args.into_iter().enumerate().map(|(i, v)| (first + i as u16, v)).filter(|(n, _)| *n <= last).collect();
        self.enter(FrameKind::Sub, source, body, 1, args, true, block, start, interp, diags);
    }

    /// `CALL LBL 1 REP 2`: runs the section after the label, as a subprogram up to the end
    /// label or, for a label before the call, up to this call again.
    fn call_label(&mut self, c: &Control, block: &Block, start: Pos, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        if let Some(f) = self.frames.last()
            && f.kind == FrameKind::Label
            && f.call_at == (self.cur, start.at)
        {
            // The end of a repeated section.
            self.return_from(None, block, interp, diags);
            return;
        }
        let Some(name) = self.target_label(c, block, interp, diags) else {
            self.error(diags, Code::MissingLabel, block.range, "the call names no label");
            return;
        };
        let Some(m) = self.marks(self.cur).iter().find(|m| m.defines.as_deref() == Some(name.as_str())).cloned() else {
            self.error(diags, Code::MissingLabel, block.range, format!("no label `{name}` to call; the run stops here"));
            return;
        };
        let Some(mut passes) = self.passes(c, block, interp, diags) else { return };
        // A section before the call, with no end label between, has run once on the way
        // here: the call adds the passes after the first.
        let end = self.dialect.macros.end_label.clone();
        let section = m.start.at < start.at
            && !self
                .marks(self.cur)
                .iter()
                .any(|e| e.start.at > m.start.at && e.start.at < start.at && e.defines.is_some() && e.defines == end);
        if section {
            passes = passes.saturating_sub(1);
        }
        let source = self.cur;
        self.enter(FrameKind::Label, source, m.next, passes, Vec::new(), false, block, start, interp, diags);
    }

    /// `REPEAT START END P=2`, `REPEAT START P=2`, `REPEATB MARK P=2`: runs again, P times,
    /// the blocks from the first label's through the second label's, up to this statement, or
    /// the labelled block alone; then goes on after the statement.
    fn repeat_section(
        &mut self,
        st: Statement,
        c: &Control,
        block: &Block,
        start: Pos,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let Some(name) = self.target_label(c, block, interp, diags) else {
            self.error(diags, Code::MissingLabel, block.range, "the repeat names no label");
            return;
        };
        let before = |m: &&Mark, name: &str, from: usize| m.defines.as_deref() == Some(name) && m.start.at >= from && m.start.at < start.at;
        let Some(first) = self.marks(self.cur).iter().rev().find(|m| before(m, &name, 0)).cloned() else {
            self.error(diags, Code::MissingLabel, block.range, format!("no label `{name}` before this repeat; the run stops here"));
            return;
        };
        let until = match (st, c.label) {
            (Statement::RepeatBlock, _) => first.next.at,
            (_, Some(r)) => {
                let last = normalise_label(block.text(r));
                let Some(m) = self.marks(self.cur).iter().find(|m| before(m, &last, first.start.at)) else {
                    let msg = format!("no label `{last}` between `{name}` and this repeat; the run stops here");
                    self.error(diags, Code::MissingLabel, block.range, msg);
                    return;
                };
                m.next.at
            }
            (_, None) => start.at,
        };
        let Some(passes) = self.passes(c, block, interp, diags) else { return };
        let source = self.cur;
        let depth = self.frames.len();
        self.enter(FrameKind::Section, source, first.start, passes, Vec::new(), false, block, start, interp, diags);
        if self.frames.len() > depth
            && let Some(f) = self.frames.last_mut()
        {
            f.until = until;
        }
    }

    /// `CALL PGM NAME`, `L123 P2`, `NAME(1.5, 3)`: runs the program of that name, from a
    /// `PROC NAME` in this file or from the program directory.
    fn call_program(&mut self, c: &Control, block: &Block, start: Pos, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        let written = match c.name {
            Some(r) => block.text(r),
            None => {
                self.error(diags, Code::MissingLabel, block.range, "the call names no program");
                return;
            }
        };
        // `TNC:\PARTS\SUB.H` → `SUB.H`.
        let file = written.rsplit(['\\', '/', ':']).next().unwrap_or(written);
        let key = normalise_label(file.split('.').next().unwrap_or(file));
        let mut args = Vec::with_capacity(c.args.len());
        for &e in &c.args {
            let Some(v) = self.value(interp, block, e, diags) else { return };
            args.push(v);
        }
        let Some(passes) = self.passes(c, block, interp, diags) else { return };
        // Named arguments (`CALL OTBOX PZ=-5. PF=500.`) are set before the call.
        if !block.assigns.is_empty() {
            interp.assign(block, diags);
        }
        // A procedure named by a number is known by its keyword and number (`%L 100` is
        // `L100`); a call by the bare number (`(CALL 3)` of `(SUB 3)`, Fagor 8055) finds it too.
        let numbered = |n: &str| {
            let digits = n.trim_start_matches(|c: char| c.is_ascii_alphabetic());
            digits.len() < n.len() && digits == key && key.bytes().all(|b| b.is_ascii_digit())
        };
        let is_proc = |m: &Mark| m.statement == Some(Statement::Procedure) && m.name.as_deref().is_some_and(|n| n == key || numbered(n));
        let starts = |m: &Mark| is_proc(m) || m.program_name.as_deref() == Some(key.as_str());
        let Some((source, body)) = self.locate(file, starts) else {
            let keyword = c.keyword.map_or(written, |k| block.text(k));
            let d = if c.keyword == c.name {
                // A bare name may be a statement this dialect file lacks as well as a program
                // (a machine maker's cycle, `T_INI`): a warning where the control keeps such.
                let msg = format!(
                    "`{keyword}` is neither a statement of the {} dialect nor a program in this file or the program directory; the call was skipped",
                    self.dialect.name
                );
                let mut d = Diagnostic::new(Code::MissingProgram, block.range, msg);
                if self.dialect.behaviour.resident_programs {
                    d.severity = Severity::Warning;
                }
                d
            } else {
                self.program_not_found(format!("program `{written}`"), block.range)
            };
            interp.limited(diags, "program", d);
            return;
        };
        // A procedure's body starts at its PROC statement, which binds the arguments.
        let body = match self.marks(source).iter().find(|m| is_proc(m)) {
            Some(m) => m.start,
            None => body,
        };
        let depth = self.frames.len();
        self.enter(FrameKind::Program, source, body, passes, Vec::new(), false, block, start, interp, diags);
        if self.frames.len() > depth
            && let Some(f) = self.frames.last_mut()
        {
            f.proc_args = Some(args);
        }
    }

    /// `PROC NAME(REAL A, INT B=2) SAVE`: binds the call's arguments to the parameter names,
    /// in order (a missing one keeps its default, else 0).
    fn procedure(&mut self, c: &Control, block: &Block, interp: &mut Interpreter<'a>) {
        let line = block.text(c.range);
        let alone = self.frames.is_empty();
        if alone {
            interp.called_by(|| "it starts with a PROC header".to_owned());
        }
        let args = self.frames.last_mut().and_then(|f| f.proc_args.take()).unwrap_or_default();
        let Some(open) = line.find('(') else { return };
        let close = line.rfind(')').filter(|&p| p > open).unwrap_or(line.len());
        for (k, param) in line[open + 1..close].split(',').enumerate() {
            let (decl, default) = match param.split_once('=') {
                Some((d, v)) => (d, v.trim().parse::<f64>().ok()),
                None => (param, None),
            };
            let Some(name) = decl.split_whitespace().last() else { continue };
            let name = name.trim_end_matches(|c: char| c == ']' || c == '[' || c.is_ascii_digit() && name.contains('['));
            if name.is_empty() {
                continue;
            }
            // Analysed on its own, the procedure's arguments are the caller's: unknown here.
            let v = args.get(k).copied().or(default).unwrap_or(if alone { eval::UNKNOWN } else { 0.0 });
            interp.params.set_named(&eval::normalised(name), v);
        }
    }
}

impl Driver<'_, '_> {
    /// Whether an `if` with `label` stands before `start` in the running source.
    fn opened_before(&mut self, start: Pos, label: &Option<String>) -> bool {
        let cur = self.cur;
        self.marks(cur).iter().take_while(|m| m.start.at < start.at).any(|m| same_label(m, label, &[Statement::If]))
    }
}

/// Where a subroutine definition's body ends, as the `endsub` statements after its `sub` line
/// tell it: the start and the end of each.
#[derive(Clone, Copy, Debug, Default)]
struct Ends {
    /// Its first `endsub` of its own label that no labelled `if`, `while`, `do` or `repeat` of
    /// its body encloses (opened after the definition and still open there).
    own: Option<(Pos, Pos)>,
    /// The first `endsub` of another label before that one (or before the end of the text)
    /// that no block encloses, and before any other `sub`: rs274 returns from a call at the
    /// first `endsub` the call meets, whatever its label (`rs274 -g`: a called `o<a> sub`,
    /// `G0 X1`, `o<b> endsub`, `G0 X7`, `o<a> endsub` moves to X1 only), so a call of this
    /// definition ends there.
    foreign: Option<(Pos, Pos)>,
}

/// The `endsub` statements that end the definition opened at `after` (see [`Ends`]). One
/// pass, the open blocks kept as a stack of labels; a label reused by a later block after its
/// own closed is another block.
fn enclosing_end(marks: &[Mark], after: usize, label: &Option<String>) -> Ends {
    let from = marks.partition_point(|m| m.start.at <= after);
    // The labels open at each point, and whether each was opened by `do` (its `while` closes it).
    let mut open: Vec<(&Option<String>, bool)> = Vec::new();
    let mut ends = Ends::default();
    // Another definition inside this one is an error of its own (nested definitions).
    let mut nested = false;
    for m in &marks[from..] {
        let Some(st) = m.statement else { continue };
        nested |= st == Statement::Sub;
        if m.label.is_none() {
            continue;
        }
        if st == Statement::EndSub && open.is_empty() && m.label != *label && !nested {
            ends.foreign = ends.foreign.or(Some((m.start, m.next)));
        }
        if m.label == *label {
            if st == Statement::EndSub && open.is_empty() {
                ends.own = Some((m.start, m.next));
                return ends;
            }
            continue;
        }
        let closes_do = st == Statement::While && open.iter().rev().any(|(l, d)| *d && **l == m.label);
        match st {
            Statement::If | Statement::Do | Statement::Repeat => open.push((&m.label, st == Statement::Do)),
            Statement::While if !closes_do => open.push((&m.label, false)),
            Statement::EndIf | Statement::EndWhile | Statement::EndRepeat | Statement::While => {
                if let Some(k) = open.iter().rposition(|(l, _)| **l == m.label) {
                    open.truncate(k);
                }
            }
            _ => {}
        }
    }
    ends
}

/// Whether the block holds nothing after the statement `c` but blanks and comments (`IF #50010
/// ;Prevent lookahead`, not `IF #100 == 1 N10`, whose block number the block keeps apart from
/// its words).
fn nothing_after(block: &Block, c: &Control, lexical: &crate::dialect::Lexical) -> bool {
    use crate::dialect::CommentClose;
    let delimiter = |ch: char| {
        lexical.comments.iter().any(|r| {
            r.open == ch
                || r.open2 == Some(ch)
                || match r.close {
                    CommentClose::Char(x) => x == ch,
                    CommentClose::Pair(a, b) => a == ch || b == ch,
                    CommentClose::EndOfLine => false,
                }
        })
    };
    let from = c.range.end.max(block.range.start);
    let rest = block.text(TextRange { start: from, end: block.range.end });
    rest.char_indices().all(|(i, ch)| {
        let at = from + i as u32;
        ch.is_whitespace() || delimiter(ch) || block.comments.iter().any(|r| r.start <= at && at < r.end)
    })
}

/// Whether mark `m` is one of the statements `sts` labelled `label` (`o100 endwhile` for
/// `o100 while`).
fn same_label(m: &Mark, label: &Option<String>, sts: &[Statement]) -> bool {
    m.label == *label && m.statement.is_some_and(|s| sts.contains(&s))
}

/// `DPRNT[X#100[53]]`: the line it prints to the data output, with its variables' values
/// (see [`print_format`]), as a message in the canon.
fn print_statement(c: &Control, block: &Block, interp: &Interpreter<'_>, sink: &mut dyn CanonSink) {
    let head = c.keyword.map_or(c.range.start, |k| k.end);
    let format = block.text(TextRange { start: head, end: c.range.end });
    let message = print_format(format, |n| interp.params.get(f64::from(n)).ok());
    sink.emit(Canon { op: CanonOp::Message(message), origin: block.range, line: block.line });
}

/// A statement the dialect has but this analysis does not simulate: skipped, and said once
/// per keyword, so that each kind is named at least once.
fn unsupported_statement(c: &Control, block: &Block, interp: &mut Interpreter<'_>, diags: &mut Vec<Diagnostic>) {
    let msg = format!("`{}` is not simulated; it was skipped", statement_head(block, c));
    // Counted per keyword: each kind of statement is named at least once.
    let key = format!("statement {}", c.keyword.map_or("", |k| block.text(k)).to_ascii_uppercase());
    interp.limited(diags, &key, Diagnostic::new(Code::Unsupported, c.range, msg));
}

/// The part of `block` one branch of a one-line `IF .. ELSE` runs: the THEN clause's words
/// and assignments (`then`), or the ELSE's, without the statement.
fn branch_of(block: &Block, o: &Otherwise, then: bool) -> Block {
    let mut b = block.clone();
    b.control = None;
    let (w, a) = ((o.words as usize).min(b.words.len()), (o.assigns as usize).min(b.assigns.len()));
    if then {
        b.words.truncate(w);
        b.assigns.truncate(a);
        b.axis_refs.retain(|r| r.0 < w);
    } else {
        b.words.drain(..w);
        b.assigns.drain(..a);
        b.axis_refs.retain(|r| r.0 >= w);
        for r in &mut b.axis_refs {
            r.0 -= w;
        }
    }
    // What a kept block caches by assignment no longer lines up: read afresh.
    b.resolved.clear();
    b.flat.clear();
    b.flat_spans.clear();
    b.reads_no_system = false;
    b.reads_no_outside = false;
    b
}

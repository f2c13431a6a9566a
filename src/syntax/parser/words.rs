//! Address words: a letter or a name and its value (`X10.5`, `CR=5`, `X=AC(10)`), labels
//! and named blocks, axis-indexed words (`AX[X]=10`), variable and parameter assignments
//! (`_X_HOME=0`, `#1=2`) and strings. Its doors are `Lexer::plain_word`, `Lexer::address`
//! and `Lexer::assignment` (from the block loop) and `Lexer::value`,
//! `Lexer::assigned_value` and `Lexer::string` (for the keyword and statement readers).

use super::super::expr::{BinOp, Expr, ExprId, Func};
use super::super::{Assign, ParamTarget, Value, Word, WordMode};
use super::Lexer;
use super::numbers::plain_number;
use crate::diag::{Code, Diagnostic};
use crate::dialect::{Meaning, Role, SkipPosition};
use crate::text::TextRange;

/// The spindle the analysis follows where a block numbers several (`S1=`, `M1=`): the main
/// one, as the engine's `SpindleId::Main` is spindle 1.
const MAIN_SPINDLE: u8 = 1;

impl Lexer<'_, '_> {
    /// The lexer's fast path: `X10.5`, `Y-.25`, a plain address with a literal number. False,
    /// with nothing consumed, when the word is anything else.
    #[inline]
    pub(super) fn plain_word(&mut self, role: Role) -> bool {
        let start = self.i;
        let b = self.b;
        let signed = matches!(b.get(start + 1), Some(b'-' | b'+'));
        let spaces = self.dialect.lexical.spaces_in_numbers;
        // The common case in one pass; anything unusual goes through `number`, which also
        // reports what is wrong with it.
        // A decimal comma after the digits (`X+10,5`) is read by `number`.
        let comma = self.dialect.lexical.numbers.decimal_comma;
        let comma_after = |end: usize| comma && b.get(end) == Some(&b',') && b.get(end + 1).is_some_and(u8::is_ascii_digit);
        let plain = plain_number(b, start + 1 + usize::from(signed), spaces).filter(|&(_, end, point)| point || !comma_after(end));
        let (value, decimal) = match plain {
            Some((v, end, point)) => {
                self.i = end;
                (if signed && b[start + 1] == b'-' { -v } else { v }, point)
            }
            None => {
                let digit_at = |j: usize| b.get(j).is_some_and(|&c| c.is_ascii_digit() || c == b'.');
                if !(digit_at(start + 1) || signed && digit_at(start + 2)) {
                    return false;
                }
                self.i += 1;
                match self.number() {
                    Some(n) => n,
                    None => return true,
                }
            }
        };
        self.block.words.push(Word {
            role,
            letter: b[start].to_ascii_uppercase(),
            value: Value::Number { value, decimal },
            range: self.range(start, self.i),
            mode: WordMode::Modal,
            cycle_arg: false,
        });
        // `G200 DRILLING`: a code the dictionary names in the block after it.
        if matches!(role, Role::G | Role::M)
            && (0.0..10_000.0).contains(&value)
            && self.dialect.code(b[start].to_ascii_uppercase() as char, (value * 10.0).round() as u32).is_some_and(|c| c.named)
        {
            self.display_name();
        }
        true
    }

    /// What starts with a letter (or `_`, or a system variable's prefix) at the cursor, tried
    /// in turn: a label, a named block or program, an axis-indexed word, a keyword code, a
    /// named cycle, a variable assignment, a multi-letter address, then by its first letter.
    pub(super) fn address(&mut self) {
        let start = self.i;
        if self.label(start) || self.block_or_program_name(start) {
            return;
        }
        if self.axis_indexed()
            || self.keyword()
            || self.cycle_call()
            || self.spindle_address(start)
            || self.variable_assignment()
            || self.long_address(start)
        {
            return;
        }
        self.letter_address(start);
    }

    /// A label before the dialect's suffix (`MARKE1:`), first in its block.
    fn label(&mut self, start: usize) -> bool {
        let Some(suffix) = self.dialect.lexical.label_suffix else { return false };
        let end = self.b[start..].iter().position(|x| !(x.is_ascii_alphanumeric() || *x == b'_')).map_or(self.b.len(), |p| start + p);
        if self.b.get(end) == Some(&(suffix as u8)) && end - start >= 2 && self.block.label.is_none() && self.block.words.is_empty() {
            self.block.label = Some(self.range(start, end));
            self.i = end + 1;
            return true;
        }
        false
    }

    /// A named block (`NLOOP G0 X1`) or program (`OTBOX`) at block start.
    fn block_or_program_name(&mut self, start: usize) -> bool {
        let lex = &self.dialect.lexical;
        let at_start = self.block.words.is_empty() && self.block.label.is_none() && self.block.control.is_none();
        if !(at_start && self.b.get(start + 1).is_some_and(u8::is_ascii_alphabetic)) {
            return false;
        }
        let letter = Some(self.b[start].to_ascii_uppercase() as char);
        let end = self.identifier_end(start);
        // `NLAB=1` assigns a variable of that name instead.
        let assigned = self.b[end..].iter().find(|c| !matches!(c, b' ' | b'\t')) == Some(&b'=');
        if lex.named_blocks && letter == lex.block_number && !assigned {
            self.block.label = Some(self.range(start, end));
            self.i = end;
            return true;
        }
        if lex.named_programs && letter == lex.program_number && self.block.assigns.is_empty() && !assigned {
            self.block.program_name = Some(self.range(start, end));
            self.i = end;
            return true;
        }
        false
    }

    /// Multi-letter addresses such as `CR=` (longest first), with their value.
    pub(super) fn long_address(&mut self, start: usize) -> bool {
        for a in self.dialect.long_addresses() {
            let n = a.name.len();
            if self.b.len() >= start + n && self.b[start..start + n].eq_ignore_ascii_case(a.name.as_bytes()) {
                let mut j = start + n;
                while matches!(self.b.get(j), Some(b' ' | b'\t')) {
                    j += 1;
                }
                let next = self.b.get(j).copied();
                let ok = if a.assign { next == Some(b'=') } else { !next.is_some_and(|x| x.is_ascii_alphabetic()) };
                if ok {
                    self.i = if a.assign { j + 1 } else { start + n };
                    // The word's letter: `C` for `CR=`, `R` for `,R`.
                    let letter = a.name.bytes().find(u8::is_ascii_alphabetic).unwrap_or(b',');
                    let role = a.role;
                    let mode = if a.incremental { WordMode::Incremental } else { WordMode::Modal };
                    let value = if a.assign { self.assigned_value(start) } else { self.value(start).map(|v| (v, WordMode::Modal)) };
                    if let Some((value, wrapped)) = value {
                        let m = if wrapped == WordMode::Modal { mode } else { wrapped };
                        self.block.words.push(Word { role, letter, value, range: self.range(start, self.i), mode: m, cycle_arg: false });
                    }
                    return true;
                }
            }
        }
        false
    }

    /// What the first letter at `start` makes of it: a control word, a post's missing value
    /// (`Xnan`), a statement or call by name, a block or program number, or an address word.
    fn letter_address(&mut self, start: usize) {
        let lex = &self.dialect.lexical;
        let letter = self.b[start].to_ascii_uppercase();
        let next = self.b.get(start + 1).copied();
        if lex.control_word == Some(letter as char) {
            self.i += 1;
            self.control_word(start);
            return;
        }
        let sigil = self.dialect.lexical.parameter.map(|(s, _)| s as u8);
        let param_value =
            next.is_some_and(|x| Some(x.to_ascii_uppercase()) == sigil) && self.b.get(start + 2).is_some_and(u8::is_ascii_digit);
        // A name such as `L123` or `T_INI` (an address's value never starts with `_`).
        let named_call = self.dialect.macros.call_by_name
            && (self.dialect.letter_role(letter).is_none() && next.is_some_and(|x| x.is_ascii_digit()) || next == Some(b'_'));
        if self.dialect.letter_role(letter).is_some() && self.not_a_number_after(start + 1) {
            return;
        }
        // A keyword with `_` after its first letter (LNC `W_REG`) is a statement too.
        let underscored = next == Some(b'_') && self.dialect.lexical.control_word.is_none() && self.statement_at(start).is_some();
        if (next.is_some_and(|x| x.is_ascii_alphabetic()) && !param_value) || named_call || underscored {
            self.keyword_statement(start);
            return;
        }
        self.i += 1;
        // After a code that takes it, the block-number letter is that code's argument: the
        // block it names (Okuma LAP `G85 N0508`).
        let after_code = self.block.words.iter().any(|w| match (w.role, w.value) {
            (Role::G, Value::Number { value, .. }) => {
                let code = self.dialect.code_id('G', (value * 10.0).round() as u32);
                code.is_some_and(|c| self.dialect.codes[c].params.takes(Role::N))
            }
            _ => false,
        });
        if lex.block_number == Some(letter as char) && !after_code {
            self.block_number(start);
            return;
        }
        if lex.block_number == Some(letter as char) {
            return self.letter_word(start, letter, Role::N);
        }
        if lex.program_number == Some(letter as char) {
            if let Some(n) = self.integer(start) {
                self.block.program_number = Some(n);
            }
            return;
        }
        let Some(role) = self.dialect.letter_role(letter) else {
            let _ = self.value(start);
            self.error(
                Code::UnknownAddress,
                start,
                self.i.max(start + 1),
                format!("`{}` is not an address in the {} dialect", letter as char, self.dialect.name),
            );
            return;
        };
        self.letter_word(start, letter, role);
    }

    /// A block number after its letter (`N120`), and a block skip after it where the dialect
    /// puts one there (`N10 /2 G0`).
    fn block_number(&mut self, start: usize) {
        let lex = &self.dialect.lexical;
        if let Some(n) = self.integer(start) {
            self.block.number = Some(n);
        }
        if let Some((skip, SkipPosition::LineStartOrAfterNumber)) = lex.block_skip {
            self.skip_blanks();
            if self.peek() == Some(skip as u8) {
                self.block.skip = true;
                self.i += 1;
                if lex.block_skip_levels && self.peek().is_some_and(|c| (b'0' + lex.block_skip_first_level..=b'9').contains(&c)) {
                    self.i += 1;
                }
            }
        }
    }

    /// The value of the address `letter` (of `role`) after it, `=` first where the dialect
    /// assigns values (`X=10`), as a word.
    fn letter_word(&mut self, start: usize, letter: u8, role: Role) {
        let assigned = self.dialect.lexical.assign_values && {
            let j = self.b[self.i..].iter().position(|c| !matches!(c, b' ' | b'\t')).map_or(self.b.len(), |p| self.i + p);
            let eq = self.b.get(j) == Some(&b'=');
            if eq {
                self.i = j + 1;
            }
            eq
        };
        let bare = !assigned && self.expression_without_assign();
        let value = if assigned { self.assigned_value(start) } else { self.value(start).map(|v| (v, WordMode::Modal)) };
        if bare {
            // Read as the value it would be with `=`, so that what follows still reads; the
            // control stops at the block.
            let word = self.text[start..self.i].trim().to_owned();
            let letter = letter as char;
            self.error(
                Code::MalformedExpression,
                start,
                self.i.max(start + 1),
                format!("`{word}`: an address takes an expression only after `=` on this control (`{letter}=(…)`)"),
            );
        }
        if let Some((value, mode)) = value {
            // A letter that is always incremental (a lathe's `U`) marks its words so.
            let mode = if mode == WordMode::Modal && self.dialect.letter_incremental(letter) { WordMode::Incremental } else { mode };
            self.block.words.push(Word { role, letter, value, range: self.range(start, self.i), mode, cycle_arg: false });
        }
    }

    /// Whether a bracketed expression follows the address at the cursor without `=`, where the
    /// dictionary says an address takes one only after `=` (`<expression after-address=
    /// "assign">`: Sinumerik `J(R109*(-1))` for `J=(R109*(-1))`).
    fn expression_without_assign(&self) -> bool {
        let Some((open, _)) = self.dialect.lexical.expression.filter(|_| self.dialect.lexical.expression_needs_assign) else {
            return false;
        };
        let j = self.b[self.i..].iter().position(|c| !matches!(c, b' ' | b'\t')).map_or(self.b.len(), |p| self.i + p);
        self.b.get(j) == Some(&(open as u8))
    }

    /// A value after `=`: a string, `AC(..)`/`IC(..)`, or an infix expression (`X=R1*2`);
    /// with the measure an `AC`/`IC` wrapper gives it (else modal).
    pub(super) fn assigned_value(&mut self, start: usize) -> Option<(Value, WordMode)> {
        self.skip_blanks();
        if let Some(q) = self.dialect.lexical.string_quote
            && self.peek() == Some(q as u8)
        {
            return self.string(start).map(|r| (Value::Text(r), WordMode::Modal));
        }
        if let Some((abs, inc)) = &self.dialect.lexical.axis_modes {
            let run = self.alpha_run();
            let word = &self.text[run.start as usize..run.end as usize];
            let mode =
                if word.eq_ignore_ascii_case(abs) || self.dialect.lexical.rotary_absolute.iter().any(|r| word.eq_ignore_ascii_case(r)) {
                    Some(WordMode::Absolute)
                } else if word.eq_ignore_ascii_case(inc) {
                    Some(WordMode::Incremental)
                } else {
                    None
                };
            if let Some(mode) = mode {
                self.i = run.end as usize;
                let e = self.unary(1)?;
                return Some((Value::Expr(e), mode));
            }
        }
        let save = self.i;
        if let Some((value, decimal)) = self.plain_number() {
            return Some((Value::Number { value, decimal }, WordMode::Modal));
        }
        self.i = save;
        self.expr(1, 0).map(|e| (Value::Expr(e), WordMode::Modal))
    }

    /// A literal number that is the whole value (no operator follows it).
    fn plain_number(&mut self) -> Option<(f64, bool)> {
        let c = self.peek()?;
        if !(c.is_ascii_digit() || c == b'.' || c == b'+' || c == b'-') {
            return None;
        }
        let mark = self.diags.len();
        let n = self.number();
        if n.is_none() {
            self.diags.truncate(mark);
            return None;
        }
        let mut j = self.i;
        while matches!(self.b.get(j), Some(b' ' | b'\t')) {
            j += 1;
        }
        let operator = matches!(self.b.get(j), Some(b'*' | b'/' | b'+' | b'-' | b'<' | b'>' | b'='))
            || self.b.get(j).is_some_and(|&x| x.is_ascii_alphabetic()) && {
                let end = self.b[j..].iter().position(|x| !x.is_ascii_alphabetic()).map_or(self.b.len(), |p| j + p);
                super::super::expr::BinOp::named(&self.text[j..end].to_ascii_uppercase()).is_some()
            };
        if operator { None } else { n }
    }

    /// A quoted string at the cursor; the range inside the quotes.
    pub(super) fn string(&mut self, start: usize) -> Option<TextRange> {
        let q = self.b[self.i];
        let from = self.i + 1;
        let eol = self.line_end();
        match self.b[from..eol].iter().position(|&c| c == q) {
            Some(p) => {
                self.i = from + p + 1;
                Some(self.range(from, from + p))
            }
            None => {
                self.error(Code::MalformedExpression, start, eol, format!("the string is not closed with `{}`", q as char));
                self.i = eol;
                None
            }
        }
    }

    /// `Xnan`, `Y-inf`: what a post writes for a value it could not compute. A finding that
    /// says so, and the word is skipped; false, with nothing read, for anything else.
    fn not_a_number_after(&mut self, at: usize) -> bool {
        let from = at + usize::from(matches!(self.b.get(at), Some(b'+' | b'-')));
        // Most words have a digit here: nothing to look at.
        if !matches!(self.b.get(from), Some(b'n' | b'N' | b'i' | b'I')) {
            return false;
        }
        let end = self.b[from.min(self.b.len())..].iter().position(|c| !c.is_ascii_alphanumeric()).map_or(self.b.len(), |p| from + p);
        let word = &self.b[from.min(end)..end];
        if !(word.eq_ignore_ascii_case(b"nan") || word.eq_ignore_ascii_case(b"inf")) {
            return false;
        }
        let start = at - 1;
        let shown = &self.text[start..end];
        self.error(
            Code::MalformedNumber,
            start,
            end,
            format!("`{shown}` has no number: the program was written with a value its post could not compute"),
        );
        self.i = end;
        true
    }

    /// The end of an identifier (letters, digits, `_`) starting at `at`.
    /// A system variable's name includes its prefix and a constant index (`$AC_TIME`,
    /// `$A_IN[1]`, `$TC_DP1[1,2]`): the control's data is unknown here whatever the index.
    pub(super) fn identifier_end(&self, at: usize) -> usize {
        let system = self.at_system_variable(at);
        let from = if system { at + 1 } else { at };
        let end = self.b[from..].iter().position(|x| !(x.is_ascii_alphanumeric() || *x == b'_')).map_or(self.b.len(), |p| from + p);
        if system && self.b.get(end) == Some(&b'[') {
            // The index, whatever it holds (`$TC_SCP13[$P_TOOLNO,1]`), up to the matching `]`
            // on the line.
            let mut depth = 0;
            for (p, &c) in self.b[end..].iter().enumerate() {
                match c {
                    b'[' => depth += 1,
                    b']' if depth == 1 => return end + p + 1,
                    b']' => depth -= 1,
                    b'\n' | b'\r' | b';' => break,
                    _ => {}
                }
            }
        }
        end
    }

    /// An array element's index at the cursor (`[R2+1]`, in the dialect's array brackets):
    /// `None` when none is there, `Some(None)` when it is malformed.
    pub(super) fn array_index(&mut self, depth: u32) -> Option<Option<ExprId>> {
        let (open, close) = self.dialect.lexical.array_brackets?;
        if self.peek() != Some(open) {
            return None;
        }
        let at = self.i;
        self.i += 1;
        let Some(mut e) = self.expr(depth + 1, 0) else { return Some(None) };
        self.skip_blanks();
        // `A[i,j]`, `A[i,j,k]`: an element of an array of several dimensions reads as one
        // element, each index after the first added to the one before times 1 000 000 (an
        // index stays below that), as named arrays' subscripts do.
        let mut dims = 1;
        while self.peek() == Some(b',') && dims < self.dialect.lexical.array_dimensions {
            self.i += 1;
            let Some(next) = self.expr(depth + 1, 0) else { return Some(None) };
            let scale = self.push(Expr::Num(1_000_000.0));
            let row = self.push(Expr::Binary(BinOp::Mul, e, scale));
            e = self.push(Expr::Binary(BinOp::Add, row, next));
            dims += 1;
            self.skip_blanks();
        }
        if self.peek() != Some(close) {
            let end = self.i.max(at + 1);
            self.error(Code::MalformedExpression, at, end, format!("an array element's index is closed with `{}`", close as char));
            return Some(None);
        }
        self.i += 1;
        Some(Some(e))
    }

    /// `(a,b)` at the cursor, in expression brackets: two or more comma-separated values, as
    /// an axis setting takes them. The cursor goes past it; false, with nothing read, where
    /// there is no such list.
    fn setting_pair(&mut self) -> bool {
        self.skip_blanks();
        let Some((open, close)) = self.dialect.lexical.expression else { return false };
        if self.peek() != Some(open as u8) {
            return false;
        }
        let (save, marks, exprs) = (self.i, self.diags.len(), self.block.exprs.len());
        self.i += 1;
        let mut values = 0;
        loop {
            if self.expr(1, 0).is_none() {
                break;
            }
            values += 1;
            self.skip_blanks();
            match self.peek() {
                Some(b',') => self.i += 1,
                Some(c) if c == close as u8 && values > 1 => {
                    self.i += 1;
                    return true;
                }
                _ => break,
            }
        }
        self.diags.truncate(marks);
        self.block.exprs.truncate(exprs);
        self.i = save;
        false
    }

    /// Whether a system variable's name starts at `at` (`$AC_TIME`).
    pub(super) fn at_system_variable(&self, at: usize) -> bool {
        self.b.get(at).is_some_and(|&c| Some(c as char) == self.dialect.lexical.system_variable_prefix)
            && self.b.get(at + 1).is_some_and(|c| c.is_ascii_alphabetic() || *c == b'_')
    }

    /// `AX[X]=10`, `POS[A]=DC(90)`, `VELOLIM[A]=50`: a dictionary name whose bracketed index
    /// is an axis name. A move becomes that axis's word; a setting is read and has no effect on
    /// the toolpath. An axis named by a variable (`AX[_X]`, an `AXIS` argument) is the
    /// caller's: the word is left out, with a note.
    fn axis_indexed(&mut self) -> bool {
        let lex = &self.dialect.lexical;
        let Some((open, close)) = lex.array_brackets else { return false };
        let start = self.i;
        let end = self.identifier_end(start);
        if self.b.get(end) != Some(&open) {
            return false;
        }
        let name = &self.text[start..end];
        let Some(entry) = lex.axis_indexed.iter().find(|a| a.name.eq_ignore_ascii_case(name)) else { return false };
        let inner = end + 1;
        let Some(close_at) = self.b[inner..].iter().position(|&c| c == close || c == b'\n').map(|p| inner + p) else { return false };
        if self.b[close_at] != close {
            return false;
        }
        let axis = self.text[inner..close_at].trim();
        let mut j = close_at + 1;
        while matches!(self.b.get(j), Some(b' ' | b'\t')) {
            j += 1;
        }
        if self.b.get(j) != Some(&b'=') || self.b.get(j + 1) == Some(&b'=') {
            return false;
        }
        let moves = entry.moves;
        let letter = match axis.as_bytes() {
            [c] => Some(c.to_ascii_uppercase()),
            _ => None,
        };
        let role = letter.and_then(|c| self.dialect.letter_role(c)).filter(|r| r.is_axis());
        // `AX[_X]`: the axis a variable holds, read when the block runs.
        let by_variable = if role.is_none() && moves && self.dialect.lexical.identifier_variables {
            self.i = inner;
            let e = self.expr(1, 0);
            self.skip_blanks();
            e.filter(|_| self.i == close_at)
        } else {
            None
        };
        self.i = j + 1;
        // `OSCTRL[Z]=(1+2,16+32+64)`: a setting given as a pair of values in brackets (the
        // options to set, then those to reset); read, and no toolpath depends on it.
        if !moves && self.setting_pair() {
            return true;
        }
        let value = self.assigned_value(start);
        let range = self.range(start, self.i);
        match (role, letter, value) {
            (Some(role), Some(letter), Some((value, mode))) if moves => {
                self.block.words.push(Word { role, letter, value, range, mode, cycle_arg: false });
            }
            (None, _, Some((value, mode))) if by_variable.is_some() => {
                let index = by_variable.unwrap_or_default();
                self.block.axis_refs.push((self.block.words.len(), index));
                self.block.words.push(Word { role: Role::Extra, letter: b'#', value, range, mode, cycle_arg: false });
            }
            (None, _, _) if moves => {
                let what = &self.text[start..close_at + 1];
                self.diags.push(Diagnostic::new(
                    Code::UnknownValue,
                    range,
                    format!(
                        "`{what}` names its axis by `{axis}`, an axis the caller or the machine's data gives: the move along it is left out"
                    ),
                ));
            }
            _ => {}
        }
        true
    }

    /// `M2=3`, `S2=2000` (Siemens): a spindle word with the number of the spindle it addresses
    /// before `=`, where the dialect's address takes one (`spindle-index`). A number value only:
    /// `M1=DIR` in a procedure (a value the caller gives) stays what it was read as before.
    /// Likewise an axis named by letter and number (`C4=120`, `axis-index`): the letter's axis.
    fn spindle_address(&mut self, start: usize) -> bool {
        let letter = self.b[start].to_ascii_uppercase();
        let Some(a) = self.dialect.addresses.iter().find(|a| (a.spindle_index || a.axis_index) && a.name.as_bytes() == [letter]) else {
            return false;
        };
        let (role, spindle) = (a.role, a.spindle_index);
        let digits = self.b[start + 1..].iter().take_while(|c| c.is_ascii_digit()).count();
        if !(1..=2).contains(&digits) {
            return false;
        }
        let eq = start + 1 + digits;
        if self.b.get(eq) != Some(&b'=') || self.b.get(eq + 1) == Some(&b'=') {
            return false;
        }
        // A number, then the block's end, a blank or a comment.
        let mut j = eq + 1;
        if matches!(self.b.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        let number = self.b[j..].iter().take_while(|c| c.is_ascii_digit() || **c == b'.').count();
        if number == 0 || self.b.get(j + number).is_some_and(|c| c.is_ascii_alphanumeric() || matches!(c, b'_' | b'(' | b'[' | b'$')) {
            return false;
        }
        // An address the dictionary declares by that name (`C3=`, the tool axis' K under
        // TRAORI) is that address, not the letter's axis numbered.
        if !spindle && self.dialect.long_addresses().any(|a| a.name.as_bytes().eq_ignore_ascii_case(&self.b[start..eq])) {
            return false;
        }
        let Ok(index) = self.text[start + 1..eq].parse::<u8>() else { return false };
        self.i = eq + 1;
        // `S2=90000/3`: the value may be an expression (an arithmetic operator after the number).
        let operator = matches!(self.b.get(j + number), Some(b'+' | b'-' | b'*' | b'/'));
        let value = if operator { self.assigned_value(start).map(|(v, _)| v) } else { self.value(start) };
        let Some(value) = value else { return true };
        let range = self.range(start, self.i);
        if spindle {
            // `S1=100 S2=100 M1=4 M2=4`: one block may set several spindles, each by its own
            // numbered words (840D sl programming manual, fundamentals: "Spindle speed S,
            // spindle direction of rotation M3, M4, M5": `S<n>=`, `M<n>=` address spindle n;
            // "several spindles can be programmed in one block"). The analysis follows one
            // spindle a block: the main one where the block numbers it, wherever it is written
            // (the manual's master spindle, spindle 1 here: `SETMS(n)` is kept as intent, so
            // the engine's main spindle stays 1), else the first it numbers; another spindle's
            // words are kept as intent.
            match self.block.spindle {
                Some(first) if first != index && (index != MAIN_SPINDLE || first == MAIN_SPINDLE) => {
                    self.spindle_kept_as_intent(start, range, first);
                    return true;
                }
                Some(first) if first != index => {
                    self.drop_spindle_words(first, index);
                    self.block.spindle = Some(index);
                }
                _ => self.block.spindle = Some(index),
            }
        }
        self.block.words.push(Word { role, letter, value, range, mode: WordMode::Modal, cycle_arg: false });
        true
    }

    /// The numbered spindle word at `start` (`range`) beside spindle `followed`'s: kept as intent.
    fn spindle_kept_as_intent(&mut self, start: usize, range: TextRange, followed: u8) {
        let shown = &self.text[start..self.i];
        let msg = format!(
            "`{shown}` beside spindle {followed}'s words: this block addresses several spindles by number, each its own words; ncplan follows the main spindle, else the first of a block, so `{shown}` is kept as intent"
        );
        self.diags.push(Diagnostic::new(Code::Unmodelled, range, msg));
    }

    /// The words of spindle `other` read so far in this block (`S2=500 M2=3` before `S1=`)
    /// leave it, kept as intent, now that the block numbers spindle `main`, which it follows.
    fn drop_spindle_words(&mut self, other: u8, main: u8) {
        let numbered = |t: &str| {
            let t = t.as_bytes();
            let digits = t.iter().skip(1).take_while(|c| c.is_ascii_digit()).count();
            matches!(t.first(), Some(b'S' | b's' | b'M' | b'm'))
                && std::str::from_utf8(&t[1..1 + digits]).ok().and_then(|d| d.parse::<u8>().ok()) == Some(other)
                && t.get(1 + digits) == Some(&b'=')
        };
        let base = self.base;
        let text = self.text;
        let mut kept = Vec::with_capacity(self.block.words.len());
        for w in std::mem::take(&mut self.block.words) {
            let local = (w.range.start as usize).checked_sub(base).zip((w.range.end as usize).checked_sub(base));
            match local.and_then(|(a, b)| text.get(a..b)) {
                Some(shown) if numbered(shown) => {
                    let msg = format!(
                        "`{shown}` beside the main spindle {main}'s words: this block addresses several spindles by number, each its own words; ncplan follows the main spindle, so `{shown}` is kept as intent"
                    );
                    self.diags.push(Diagnostic::new(Code::Unmodelled, w.range, msg));
                }
                _ => kept.push(w),
            }
        }
        self.block.words = kept;
    }

    /// `_X_HOME=0`, `LEN=LEN+1`: a variable assignment, where identifiers name variables. A
    /// single letter is an address, not a variable.
    fn variable_assignment(&mut self) -> bool {
        if !self.dialect.lexical.identifier_variables {
            return false;
        }
        let start = self.i;
        let end = self.identifier_end(start);
        let name = &self.b[start..end];
        if name.len() < 2 && name.first() != Some(&b'_') {
            return false;
        }
        if self.dialect.long_addresses().any(|a| a.name.as_bytes().eq_ignore_ascii_case(name)) {
            return false;
        }
        let mut j = end;
        // `VGRIN[6]=19`: an element of a named array, where the dialect indexes with brackets.
        let mut index = None;
        let (marks, exprs) = (self.diags.len(), self.block.exprs.len());
        let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
        let indexed = expr_open.is_some() && self.b.get(end).copied() == expr_open;
        if indexed {
            self.i = end;
            index = self.subscripts(1);
            j = self.i;
        } else if self.dialect.lexical.array_brackets.is_some_and(|(o, _)| self.b.get(end) == Some(&o)) {
            self.i = end;
            index = self.array_index(0).flatten();
            if index.is_none() {
                self.diags.truncate(marks);
                self.block.exprs.truncate(exprs);
                self.i = start;
                return false;
            }
            j = self.i;
        }
        while matches!(self.b.get(j), Some(b' ' | b'\t')) {
            j += 1;
        }
        if (indexed && index.is_none()) || self.b.get(j) != Some(&b'=') || self.b.get(j + 1) == Some(&b'=') {
            // Not an assignment: whatever the index left behind goes.
            self.diags.truncate(marks);
            self.block.exprs.truncate(exprs);
            self.i = start;
            return false;
        }
        self.i = j + 1;
        // Text (`VUACM[1]='END OF BAR'`, a Siemens STRING): what an alarm or a message shows,
        // no number the toolpath depends on; read and not kept.
        self.skip_blanks();
        if let Some(q) = self.dialect.lexical.string_quote
            && self.peek() == Some(q as u8)
        {
            let _ = self.string(start);
            // A concatenation (`"A" << R1`) is text too, to the end of the line.
            self.skip_blanks();
            if self.b[self.i..].starts_with(b"<<") {
                self.i = self.line_end();
            }
            return true;
        }
        let Some(value) = self.expr(1, 0) else {
            self.i = self.line_end();
            return true;
        };
        let name = self.range(start, end);
        self.block.assigns.push(Assign {
            target: index.map_or(ParamTarget::Named(name), |i| ParamTarget::NamedIndex(name, i)),
            value,
            range: self.range(start, self.i),
        });
        true
    }

    /// Reads a word value after its address.
    pub(super) fn value(&mut self, start: usize) -> Option<Value> {
        self.skip_blanks();
        let Some(c) = self.peek() else {
            self.error(Code::MissingValue, start, self.i, format!("`{}` has no value", &self.text[start..self.i].trim()));
            return None;
        };
        let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
        let sigil = self.dialect.lexical.parameter.map(|(s, _)| s as u8);
        let global = self.dialect.lexical.global_parameter.map(|(s, _)| s as u8);
        // After a sign, blanks may stand before the operand where the dialect allows blanks in numbers (`Z + Q13`).
        let after_sign = if matches!(c, b'+' | b'-') && self.dialect.lexical.spaces_in_numbers {
            self.b[self.i + 1..].iter().position(|c| !matches!(c, b' ' | b'\t')).map_or(self.b.len(), |p| self.i + 1 + p)
        } else {
            self.i + 1
        };
        // Blanks between a sign and a bracket or a variable (`Z - [0.5 * #5]`, Haas's own
        // Renishaw macros) leave nothing to misread on any control that ignores blanks in a
        // block (Fanuc, Haas): the sign applies to the expression.
        let blanks_then_expr = matches!(c, b'+' | b'-') && {
            let j = self.b[self.i + 1..].iter().position(|c| !matches!(c, b' ' | b'\t')).map_or(self.b.len(), |p| self.i + 1 + p);
            self.b.get(j).is_some_and(|&n| Some(n) == expr_open || Some(n.to_ascii_uppercase()) == sigil)
        };
        let sign_then_expr = blanks_then_expr
            || matches!(c, b'+' | b'-')
                && self
                    .b
                    .get(after_sign)
                    .is_some_and(|&n| Some(n) == expr_open || Some(n.to_ascii_uppercase()) == sigil || n.is_ascii_alphabetic());
        if c.is_ascii_digit() || c == b'.' || (matches!(c, b'+' | b'-') && !sign_then_expr) {
            return self.number().map(|(value, decimal)| Value::Number { value, decimal });
        }
        let is_func = c.is_ascii_alphabetic() && {
            let end = self.b[self.i..].iter().position(|x| !x.is_ascii_alphabetic()).map_or(self.b.len(), |p| self.i + p);
            Func::named(&self.text[self.i..end].to_ascii_uppercase()).is_some()
        };
        let radix = self.dialect.lexical.numbers.radix.is_some_and(|(q, _, _)| c == q as u8);
        if Some(c) == expr_open
            || self.at_define_name(self.i)
            || Some(c) == sigil
            || (Some(c) == global && self.b.get(self.i + 1).is_some_and(u8::is_ascii_digit))
            || self.parameter_bank_at(self.i).is_some()
            || sign_then_expr
            || is_func
            || radix
        {
            return self.unary(0).map(Value::Expr);
        }
        self.error(Code::MissingValue, start, self.i, format!("`{}` has no value", self.text[start..self.i].trim()));
        None
    }

    /// Whether the block so far holds an M code that stores the operator's input in the
    /// variable written after it (the dictionary's `operator-input`).
    fn reads_operator_input(&self) -> bool {
        self.block.words.iter().any(|w| {
            w.letter == b'M'
                && matches!(w.value, Value::Number { value, .. } if (0.0..100_000.0).contains(&value)
                    && self.dialect.code('M', (value * 10.0).round() as u32).is_some_and(|d| d.meaning == Meaning::OperatorInput))
        })
    }

    pub(super) fn assignment(&mut self) {
        let start = self.i;
        let bank = self.global_bank();
        self.i += bank.map_or(1, |(_, len)| len);
        self.skip_blanks();
        let target = if self.peek() == Some(b'<') && bank.is_none() && self.dialect.lexical.parameter.is_some_and(|(_, n)| n) {
            match self.name(start) {
                Some(r) => ParamTarget::Named(r),
                None => return,
            }
        } else if let Some(r) = self.letter_variable() {
            ParamTarget::Named(r)
        } else {
            match self.parameter_number(0, bank.map(|(first, _)| first)) {
                Some(e) => ParamTarget::Numbered(e),
                None => {
                    self.i = self.line_end();
                    return;
                }
            }
        };
        self.skip_blanks();
        if self.peek() != Some(b'=') {
            // `M225 #130 "text" #1`: the variables a formatted text shows, or the one an input
            // goes to, are the code's arguments where the dialect writes them so.
            let quote = self.dialect.lexical.string_quote.map(|q| q as u8);
            if self.dialect.lexical.text_arguments && quote.is_some_and(|q| self.b[self.line_start()..self.line_end()].contains(&q)) {
                // The first variable after a code that reads the operator's number (Centroid
                // CNC12 manual, chapter 13: `M224 #111 "prompt"` stores the number typed in
                // #111) is set by the run: an assignment of a value not known here.
                if self.block.assigns.is_empty() && self.reads_operator_input() {
                    let value = self.block.exprs.len() as ExprId;
                    self.block.exprs.push(Expr::Text(self.range(start, self.i)));
                    self.block.assigns.push(Assign { target, value, range: self.range(start, self.i) });
                }
                return;
            }
            // A parameter read without assignment is meaningless in a block.
            self.error(Code::MalformedExpression, start, self.i.max(start + 1), "a parameter here must be assigned with `=`");
            return;
        }
        self.i += 1;
        let after = self.i;
        let Some(value) = self.expr(1, 0) else {
            // An empty value (`#4= (FEED)`, `R1= ; depth`): the control stops at it, and what
            // follows it is still the comment it is written as, never the value.
            let blank = self.b[after..].iter().take_while(|c| matches!(c, b' ' | b'\t')).count();
            let comment = self.dialect.lexical.comments.iter().any(|r| r.opens(&self.b[after + blank..]));
            self.i = if comment { after + blank } else { self.line_end() };
            return;
        };
        self.block.assigns.push(Assign { target, value, range: self.range(start, self.i) });
    }
}

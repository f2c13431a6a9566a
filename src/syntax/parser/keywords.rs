//! Keyword codes (`TRANS`, `TOOL CALL 5`, `SPOS=90`) with their values and display names
//! (`CYCL DEF 200 DRILLING`), and named cycles with positional arguments
//! (`CYCLE83(50,0,2)`). Its doors are `Lexer::keyword`, `Lexer::cycle_call` and
//! `Lexer::display_name`.

use super::super::{Value, Word, WordMode};
use super::Lexer;
use crate::diag::Code;
use crate::dialect::{KeywordRest, Role};

impl Lexer<'_, '_> {
    /// A keyword code whose value is assigned (`SPOS=90`, `SPOS[1]=DC(45)`, `SPOSA=IC(90)`):
    /// the code's word and the value's; without `=` after it the text is no such keyword.
    fn assigned_keyword(&mut self, start: usize, end: usize, idx: usize, role: Option<Role>) -> bool {
        let mut j = end;
        let skip = |b: &[u8], mut j: usize| {
            while matches!(b.get(j), Some(b' ' | b'\t')) {
                j += 1;
            }
            j
        };
        j = skip(self.b, j);
        // The spindle's number in brackets (`SPOS[2]=90`): the block addresses that spindle.
        let mut spindle = None;
        if let Some((open, close)) = self.dialect.lexical.array_brackets
            && self.b.get(j) == Some(&open)
        {
            match self.b[j..].iter().position(|&c| c == close || c == b'\n') {
                Some(p) if self.b[j + p] == close => {
                    spindle = self.text[j + 1..j + p].trim().parse::<u8>().ok();
                    j = skip(self.b, j + p + 1);
                }
                _ => return false,
            }
        }
        if self.b.get(j) != Some(&b'=') || self.b.get(j + 1) == Some(&b'=') {
            return false;
        }
        let letter = self.push_keyword(start, end, idx);
        if spindle.is_some() {
            self.block.spindle = spindle;
        }
        self.i = j + 1;
        if let (Some(role), Some((value, mode))) = (role, self.assigned_value(start)) {
            self.block.words.push(Word { role, letter, value, range: self.range(start, self.i), mode, cycle_arg: false });
        }
        true
    }

    /// Pushes the keyword code `idx` spelled at `start..end`; its first letter, upper case.
    fn push_keyword(&mut self, start: usize, end: usize, idx: usize) -> u8 {
        let letter = self.b[start].to_ascii_uppercase();
        let value = Value::Number { value: idx as f64, decimal: false };
        self.block.words.push(Word {
            role: Role::Keyword,
            letter,
            value,
            range: self.range(start, end),
            mode: WordMode::Modal,
            cycle_arg: false,
        });
        letter
    }

    /// A keyword code at the cursor (`TRANS`, `TOOL CALL 5`, `DR+`), longest first. Blanks in
    /// a keyword match any run of blanks; the keyword must end at a word boundary.
    pub(super) fn keyword(&mut self) -> bool {
        let start = self.i;
        let Some(&first) = self.b.get(start) else { return false };
        let mut found = None;
        // Only the keywords that start with this letter can match here (longest first).
        for (idx, k) in self.dialect.keyword_codes_starting(first) {
            let end = if k.assigned {
                // `SPOS=90`, `SPOS[1]=`: the name runs into `=` or its index.
                let end = start + k.text.len();
                let named = self.b.get(start..end).is_some_and(|t| t.eq_ignore_ascii_case(k.text.as_bytes()));
                (named && matches!(self.b.get(end), Some(b'=' | b'[' | b' ' | b'\t'))).then_some(end)
            } else {
                self.match_keyword(start, &k.text, k.value_role.is_some())
            };
            if let Some(end) = end {
                found = Some((idx, end, k.value_role, k.rest, k.assigned));
                break;
            }
        }
        let Some((idx, end, value_role, rest, assigned)) = found else { return false };
        if assigned && value_role.is_some() {
            return self.assigned_keyword(start, end, idx, value_role);
        }
        self.push_keyword(start, end, idx);
        self.i = end;
        self.skip_blanks();
        if let Some(role) = value_role {
            let vstart = self.i;
            let c = self.peek();
            let sigil = self.dialect.lexical.parameter.map(|(s, _)| s as u8);
            let value = if c.is_some_and(|c| c.is_ascii_digit() || c == b'.' || c == b'+' || c == b'-') {
                self.number().map(|(value, decimal)| Value::Number { value, decimal })
            } else if c.is_some() && c == self.dialect.lexical.string_quote.map(|q| q as u8) {
                self.string(vstart).map(Value::Text)
            } else if c.is_some()
                && (c == sigil || c == self.expr_open())
                && self.b.get(self.i + 1).is_some_and(|n| n.is_ascii_digit() || c != sigil)
            {
                self.unary(1).map(Value::Expr)
            } else {
                None
            };
            if let Some(value) = value {
                self.block.words.push(Word {
                    role,
                    letter: b'#',
                    value,
                    range: self.range(vstart, self.i),
                    mode: WordMode::Modal,
                    cycle_arg: false,
                });
            }
            self.skip_blanks();
            if self.peek() == Some(b':') {
                self.i += 1; // `FN 0:`
            }
        }
        match rest {
            KeywordRest::None => {}
            KeywordRest::Name => {
                self.skip_blanks();
                while self.peek().is_some_and(|c| !matches!(c, b' ' | b'\t' | b'\r' | b'\n')) {
                    self.i += 1;
                }
            }
            KeywordRest::Line => self.i = self.rest_of_line_end(),
            KeywordRest::Words => {
                let named = self.display_name();
                if named && value_role.is_some() {
                    self.value_after_name();
                }
            }
        }
        true
    }

    /// Where the rest of a line a keyword keeps unread ends: at the line's end, or at a comment
    /// that opens there outside quoted text, which stays a comment. The TNC writes a comment
    /// after such a function's values (TNC 426/430 technical manual, "FN17: SYSWRITE IDxxxx
    /// NRxxxx IDXxxxx = Qxxx or numerical value; comment"); `IDXQ8 = "" ; NAME` ends at `;`, a
    /// `;` inside the quotes does not end it.
    fn rest_of_line_end(&self) -> usize {
        let end = self.line_end();
        let quote = self.dialect.lexical.string_quote.map(|q| q as u8);
        let mut quoted = false;
        for p in self.i..end {
            let c = self.b[p];
            if Some(c) == quote {
                quoted = !quoted;
            } else if !quoted && self.dialect.lexical.comments.iter().any(|r| !r.block_start && r.opens(&self.b[p..end])) {
                return p;
            }
        }
        end
    }

    /// The value after a numbered code's display name (`CYCL DEF 1.1 SET UP .1181`,
    /// `1.2 DEPTH -15`): a bare number, sign optional, the last word of the line. A legacy
    /// cycle's sub-block number says which argument it is.
    fn value_after_name(&mut self) {
        let vstart = self.i;
        if !(self.bare_number_ends_line(vstart) || self.in_sub_block() && self.sub_block_value(vstart)) {
            return;
        }
        if let Some((value, decimal)) = self.number() {
            self.block.words.push(Word {
                role: Role::CycleValue,
                letter: b'#',
                value: Value::Number { value, decimal },
                range: self.range(vstart, self.i),
                mode: WordMode::Modal,
                cycle_arg: false,
            });
        }
    }

    /// Where the value starts in a name run into it (`V.IDO2`, `ABST+1` from `from` to `end`):
    /// a name of two or more letters (dots between), not an address of the dictionary, then
    /// a number (sign optional, a decimal comma where the dialect has one) that ends the
    /// line or is followed by address words, in the sub-block of a cycle (`CYCL DEF 9.1`,
    /// `1.2`, `10.1 ROT+45`, `5.3 ZUSTLG+3 F1000`): the legacy cycles write each argument so,
    /// after a name in the control's language (TNC 155/355/426 user's manuals, "Fixed
    /// cycles"). `None` for anything else: `CYCL DEF 14.1 CONTOUR LABEL1 /2` names labels.
    fn glued_name_value(&self, from: usize, end: usize) -> Option<usize> {
        if !self.in_sub_block() {
            return None;
        }
        let word = &self.b[from..end];
        // The name ends at the value's digits or sign (`TIEFE-11,5`: `-` runs on in a word).
        let split = word.iter().position(|c| c.is_ascii_digit() || matches!(c, b'+' | b'-')).unwrap_or(word.len());
        // A name alone is followed by its signed value (`ABST+1`).
        if split == word.len() && !matches!(self.b.get(end), Some(b'+' | b'-')) {
            return None;
        }
        let name = &word[..split];
        let letters = name.iter().filter(|c| c.is_ascii_alphabetic()).count();
        if letters < 2 || !name.iter().all(|c| c.is_ascii_alphabetic() || *c == b'.') || !name[0].is_ascii_alphabetic() {
            return None;
        }
        let name = name.strip_suffix(b".").unwrap_or(name);
        if self.dialect.addresses.iter().any(|a| a.name.as_bytes().eq_ignore_ascii_case(name)) {
            return None;
        }
        // Digits run into a name make a value only where the dictionary gives the sub-block
        // one (`9.1 V.IDO2`): `12.1 PGM SUB1` and `14.1 CONTOUR LABEL1` are names. A sign
        // never belongs to a name (`ABST+1`).
        if word.get(split).is_some_and(u8::is_ascii_digit) && !self.sub_block_has_value() {
            return None;
        }
        self.sub_block_value(from + split).then_some(from + split)
    }

    /// Whether the cycle of this sub-block is one the dictionary knows and gives this sub-block
    /// a value (`CYCL DEF 1.2`: cycle 1's depth).
    fn sub_block_has_value(&self) -> bool {
        self.sub_block_cycle()
            .is_some_and(|(ci, sub)| self.dialect.cycles[ci].args.iter().any(|a| a.sub.is_some_and(|s| f64::from(s) == sub)))
    }

    /// The dictionary's cycle of this sub-block and the sub-block's number (`1.2`: cycle 1,
    /// 2); `None` where the block is no sub-block or the cycle is not in the dictionary.
    fn sub_block_cycle(&self) -> Option<(usize, f64)> {
        let number = self.block.words.iter().rev().find(|w| w.role == Role::CycleNumber).and_then(|w| match w.value {
            Value::Number { value, .. } => Some(value),
            _ => None,
        })?;
        let sub = (number.fract() * 10.0).round();
        (sub >= 1.0).then_some(())?;
        Some((self.dialect.cycle(&format!("{}", number.trunc()))?, sub))
    }

    /// Whether the block is the sub-block of a cycle definition (`CYCL DEF 1.2`, not `1.0`).
    fn in_sub_block(&self) -> bool {
        self.block.words.iter().rev().find(|w| w.role == Role::CycleNumber).is_some_and(|w| match w.value {
            Value::Number { value, .. } => (value.fract() * 10.0).round() >= 1.0,
            _ => false,
        })
    }

    /// Whether a number starts at `at` (sign optional, digits with one decimal point, or
    /// comma where the dialect writes one) and the line ends after it, or a comment, or
    /// blanks and an address word (`ZUSTLG+3 F1000`).
    fn sub_block_value(&self, at: usize) -> bool {
        let b = self.b;
        let mut j = at;
        if matches!(b.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        let comma = self.dialect.lexical.numbers.decimal_comma;
        let (mut digits, mut points) = (0, 0);
        while let Some(&c) = b.get(j) {
            if c.is_ascii_digit() {
                digits += 1;
            } else if c == b'.' || (comma && c == b',' && b.get(j + 1).is_some_and(u8::is_ascii_digit)) {
                points += 1;
            } else {
                break;
            }
            j += 1;
        }
        if digits == 0 || points > 1 {
            return false;
        }
        let rest = &b[j..];
        let blanks = rest.iter().take_while(|c| matches!(c, b' ' | b'\t')).count();
        let after = &rest[blanks..];
        match after.first() {
            None | Some(b'\n' | b'\r') => true,
            Some(c) if c.is_ascii_alphabetic() => blanks > 0,
            Some(_) => self.dialect.lexical.comments.iter().any(|r| r.opens(after)),
        }
    }

    /// Where a list of numbers ends that runs to the line's end (or a comment) in the
    /// sub-block of a cycle (`CYCL DEF 14.1`): `1 /2 /3` or `1/2/3` after a name, with a `/`
    /// at least; or a name of two letters or more run into the list's first number
    /// (`LABEL1 /2`, `KONTURLABEL1`), the name no address of the dictionary. `None` for
    /// anything else.
    fn sub_block_list(&self, from: usize, end: usize, named: bool) -> Option<usize> {
        if !self.in_sub_block() {
            return None;
        }
        let word = &self.b[from..end];
        let split = word.iter().position(u8::is_ascii_digit)?;
        let name = &word[..split];
        let glued = name.len() >= 2 && name.iter().all(u8::is_ascii_alphabetic);
        if !(glued || named && name.is_empty()) {
            return None;
        }
        if glued && self.dialect.addresses.iter().any(|a| a.name.as_bytes().eq_ignore_ascii_case(name)) {
            return None;
        }
        // The numbers and slashes up to the line's end or a comment there.
        let eol = self.b[from..].iter().position(|&c| c == b'\n' || c == b'\r').map_or(self.b.len(), |p| from + p);
        let comments = &self.dialect.lexical.comments;
        let stop = (from + split..eol).find(|&p| comments.iter().any(|r| r.opens(&self.b[p..eol]))).unwrap_or(eol);
        let list = self.b[from + split..stop].trim_ascii_end();
        let shape = list.iter().all(|c| c.is_ascii_digit() || matches!(c, b'/' | b' ' | b'\t'))
            && list.split(|&c| c == b'/').all(|n| !n.trim_ascii().is_empty() && n.trim_ascii().iter().all(u8::is_ascii_digit));
        let slashed = list.contains(&b'/');
        (shape && (slashed || glued)).then_some(from + split + list.len())
    }

    /// Whether a bare number (`5`, `-15`, `.1181`, `+0.5`) starts at `at` and only blanks
    /// follow it on the line.
    fn bare_number_ends_line(&self, at: usize) -> bool {
        let eol = self.b[at..].iter().position(|&c| c == b'\n' || c == b'\r').map_or(self.b.len(), |p| at + p);
        // Up to a comment at the end of the block (`1.2 DEPTH -15 ; hole`).
        let comments = &self.dialect.lexical.comments;
        let end = (at..eol).find(|&p| comments.iter().any(|r| r.opens(&self.b[p..eol]))).unwrap_or(eol);
        let word = self.b[at..end].trim_ascii_end();
        let digits = word.strip_prefix(b"+").or_else(|| word.strip_prefix(b"-")).unwrap_or(word);
        !digits.is_empty()
            && digits.iter().any(u8::is_ascii_digit)
            && digits.iter().all(|c| c.is_ascii_digit() || *c == b'.')
            && digits.iter().filter(|c| **c == b'.').count() <= 1
    }

    /// A display name after a code, in the control's language (`DRILLING`, `DATUM SHIFT`,
    /// `PLAN D'USINAGE`), read past up to the first address word, or up to a bare number
    /// that ends the line after a name (`SET UP .1181`: the name's value). Whether a name
    /// was read.
    pub(super) fn display_name(&mut self) -> bool {
        let mut named = false;
        loop {
            self.skip_blanks();
            let from = self.i;
            let end = self.b[from..]
                .iter()
                .position(|c| !(c.is_ascii_alphanumeric() || matches!(c, b'_' | b'-' | b'.' | b'/' | b'\'') || *c >= 0x80))
                .map_or(self.b.len(), |p| from + p);
            let word = &self.b[from..end];
            // A display name in the control's language (`DRILLING`, `DATUM SHIFT`,
            // `PLAN D'USINAGE`, `PERÇAGE`) or a plain number; not an address
            // word such as `X+0`, `Q200=2` or a lone axis letter.
            let single_letter = word.len() == 1 && word[0].is_ascii_alphabetic();
            let mixed = word.iter().any(u8::is_ascii_digit) && !word.first().is_some_and(u8::is_ascii_digit);
            let plain = !word.is_empty() && !mixed && !single_letter && !matches!(self.b.get(end), Some(b'=' | b'+'));
            // A legacy cycle's sub-block name run into its value at the line's end, as older
            // TNCs and posts write it (`9.1 TIME5`, the Hungarian `9.1 V.IDO2` of DWELL 2):
            // the name is read past and the number left as its value. Never an address word
            // (`X10`, `Q200`, `DR5`: a letter or the dictionary's address before the digits).
            // The sub-block of a cycle the dictionary does not know (`CYCL DEF 5.4 RADIUS10`,
            // `10.1 ROT+45`): the definition is skipped with a warning, its words are its text.
            if self.in_sub_block() && self.sub_block_cycle().is_none() {
                self.i = self.rest_of_line_end();
                named = true;
                break;
            }
            let signed = !word.is_empty() && matches!(self.b.get(end), Some(b'+' | b'-'));
            if (mixed || signed)
                && let Some(split) = self.glued_name_value(from, end)
            {
                self.i = split;
                named = true;
                break;
            }
            // A list of numbers the TNC writes after a sub-block's name, `/` between them
            // (`CYCL DEF 14.1 CONTOUR LABEL 1 /2 /3`, older `KONTURLABEL1 /2 /3`: the labels of
            // the contour's subprograms, TNC cycle programming manual, cycle 14): read past
            // whole, the interpreter reads the labels from the block's text.
            if let Some(list_end) = self.sub_block_list(from, end, named) {
                self.i = list_end;
                named = true;
                break;
            }
            if !plain || (named && self.bare_number_ends_line(from)) {
                break;
            }
            named |= !word.first().is_some_and(u8::is_ascii_digit);
            self.i = end;
            // A setting shown with its value (`HSC-MODE:0` in cycle 32).
            if self.peek() == Some(b':') && self.b.get(self.i + 1).is_some_and(|c| c.is_ascii_digit() || matches!(c, b'+' | b'-')) {
                self.i += 1;
                let _ = self.number();
            }
        }
        named
    }

    /// The end of keyword `kw` when it stands at `at`.
    fn match_keyword(&self, at: usize, kw: &str, takes_value: bool) -> Option<usize> {
        let mut i = at;
        for part in kw.as_bytes().split(|&c| c == b' ') {
            if i > at {
                let j = i;
                while matches!(self.b.get(i), Some(b' ' | b'\t')) {
                    i += 1;
                }
                if i == j {
                    return None;
                }
            }
            let end = i + part.len();
            if self.b.len() < end || !self.b[i..end].eq_ignore_ascii_case(part) {
                return None;
            }
            i = end;
        }
        // The keyword must end where a word ends: `L X+1` and `DR+ F100`, not `LBL 1`,
        // `L-4.5` or `DR+0.2`. A keyword that takes a value may run into it (`FN18:`).
        let last = *kw.as_bytes().last()?;
        let next = self.b.get(i).copied();
        let joined = next.is_some_and(|c| {
            (c.is_ascii_alphanumeric() && !(takes_value && c.is_ascii_digit()))
                || matches!(c, b'_' | b'.' | b'=' | b'(')
                || (last.is_ascii_alphanumeric() && matches!(c, b'+' | b'-') && !takes_value)
                || (!last.is_ascii_alphanumeric() && c.is_ascii_digit())
                // A decimal comma goes on with the number (`RND R0,5` is R 0.5, not `R0`).
                || (self.dialect.lexical.numbers.decimal_comma
                    && c == b','
                    && last.is_ascii_digit()
                    && self.b.get(i + 1).is_some_and(u8::is_ascii_digit))
        });
        // A keyword spelt like an address (`Z`, the tool axis) is the address when a value follows.
        let is_address = self.dialect.addresses.iter().any(|a| a.name.eq_ignore_ascii_case(kw));
        let value_follows = is_address && {
            let j = self.b[i..].iter().position(|c| !matches!(c, b' ' | b'\t')).map_or(self.b.len(), |p| i + p);
            self.b.get(j).is_some_and(|c| c.is_ascii_digit() || matches!(c, b'+' | b'-' | b'.'))
        };
        (!joined && !value_follows).then_some(i)
    }

    /// A named cycle with positional arguments: `CYCLE83(50,0,2,-30,,-5)`. Empty slots are
    /// skipped; each argument becomes a word of the role the dialect gives its position.
    pub(super) fn cycle_call(&mut self) -> bool {
        if self.dialect.cycles.is_empty() {
            return false;
        }
        let start = self.i;
        let end = self.b[start..].iter().position(|x| !(x.is_ascii_alphanumeric() || *x == b'_')).map_or(self.b.len(), |p| start + p);
        let mut open = end;
        while matches!(self.b.get(open), Some(b' ' | b'\t')) {
            open += 1;
        }
        if self.b.get(open) != Some(&b'(') {
            return false;
        }
        let Some(ci) = self.dialect.cycle(&self.text[start..end]) else { return false };
        let letter = self.b[start].to_ascii_uppercase();
        self.block.words.push(Word {
            role: Role::Cycle,
            letter,
            value: Value::Number { value: ci as f64, decimal: false },
            range: self.range(start, end),
            mode: WordMode::Modal,
            cycle_arg: false,
        });
        self.i = open + 1;
        let dialect = self.dialect;
        let args = &dialect.cycles[ci].args;
        let mut n = 0;
        loop {
            self.skip_blanks();
            match self.peek() {
                Some(b')') => {
                    self.i += 1;
                    break;
                }
                Some(b',') => {
                    self.i += 1;
                    n += 1;
                    continue;
                }
                None | Some(b'\n' | b'\r') => {
                    self.error(Code::MalformedExpression, start, self.i, "the cycle's argument list is not closed with `)`");
                    return true;
                }
                _ => {}
            }
            let from = self.i;
            // A string argument (`CYCLE800(1,"TABLE",...)`, `EXTCALL("ROUGH")`) names
            // something: a text value.
            let value = match self.dialect.lexical.string_quote {
                Some(q) if self.peek() == Some(q as u8) => self.string(from).map(Value::Text),
                _ => self.expr(1, 0).map(Value::Expr),
            };
            let Some(value) = value else {
                self.i = self.line_end();
                return true;
            };
            match args.get(n) {
                // An argument the engine does not use (`extra`) is read but not evaluated: it
                // may name what only the control knows (`_ORI_ROUGH`, an axis `X`).
                Some(a) if a.role == Role::Extra => {}
                Some(a) => self.block.words.push(Word {
                    role: a.role,
                    letter: a.name.as_bytes()[0],
                    value,
                    range: self.range(from, self.i),
                    mode: WordMode::Modal,
                    cycle_arg: true,
                }),
                None => self.error(
                    Code::UnusedWord,
                    from,
                    self.i.max(from + 1),
                    format!("{} takes {} arguments; this is argument {}", dialect.cycles[ci].name, args.len(), n + 1),
                ),
            }
            self.skip_blanks();
            match self.peek() {
                Some(b',') => {
                    self.i += 1;
                    n += 1;
                }
                Some(b')') => {
                    self.i += 1;
                    break;
                }
                _ => {
                    let at = self.i;
                    let end = if at < self.b.len() { at + self.char_len(at) } else { at };
                    self.error(Code::MalformedExpression, at, end, "expected `,` or `)` in the cycle's arguments");
                    self.i = self.line_end();
                    return true;
                }
            }
        }
        true
    }
}

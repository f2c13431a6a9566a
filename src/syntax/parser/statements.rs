//! Control statements: RS274NGC control words (`o100 while [..]`), statement keywords
//! (`IF [..] GOTO 10`, `WHILE [..] DO 1`, `CASE .. OF`, `FOR .. TO ..`, `REPEAT`), calls by
//! name and declarations (`DEF REAL LEN=10.5`), each into the block's `Control`. Its doors
//! are `Lexer::control_word` and `Lexer::keyword_statement`.

use super::super::expr::Expr;
use super::super::{Assign, CaseBranch, Control, Otherwise, ParamTarget};
use super::Lexer;
use crate::diag::{Code, Diagnostic};
use crate::dialect::Statement;
use crate::text::TextRange;

impl Lexer<'_, '_> {
    /// An alphabetic run at the cursor, as a range in the window (not the whole text).
    pub(super) fn alpha_run(&self) -> TextRange {
        let end = self.b[self.i..].iter().position(|x| !x.is_ascii_alphabetic()).map_or(self.b.len(), |p| self.i + p);
        TextRange { start: self.i as u32, end: end as u32 }
    }

    /// The keyword of a control word at the cursor and its statement. Blanks do not count
    /// in RS274NGC, so `o100 end sub` is `endsub` and `o1 else if` is `elseif`: the longest
    /// run of blank-separated letter runs that spells a statement wins. The range is in the
    /// window, as [`Lexer::alpha_run`]'s.
    fn control_keyword(&self) -> (TextRange, Option<Statement>) {
        let first = self.alpha_run();
        let mut best = (first, self.dialect.macros.statement(&self.text[first.start as usize..first.end as usize]));
        let mut joined = self.text[first.start as usize..first.end as usize].to_string();
        let mut at = first.end as usize;
        while !joined.is_empty() {
            let next = at + self.b[at..].iter().take_while(|c| matches!(c, b' ' | b'\t')).count();
            let end = next + self.b[next..].iter().take_while(|c| c.is_ascii_alphabetic()).count();
            if next == at || end == next {
                break;
            }
            joined.push_str(&self.text[next..end]);
            at = end;
            if let Some(st) = self.dialect.macros.statement(&joined) {
                best = (TextRange { start: first.start, end: end as u32 }, Some(st));
            }
        }
        best
    }

    /// `o100 while [#1 LT 3]`: the label after the control word, then a statement keyword
    /// and its bracketed operands.
    pub(super) fn control_word(&mut self, start: usize) {
        let mark = self.diags.len();
        self.skip_blanks();
        let mut label_expr = None;
        let label = if self.peek() == Some(b'<') {
            let from = self.i + 1;
            let eol = self.line_end();
            match self.b[from..eol].iter().position(|&c| c == b'>') {
                Some(p) => {
                    self.i = from + p + 1;
                    Some(self.range(from, from + p))
                }
                None => {
                    self.error(Code::MalformedExpression, start, eol, "label name is not closed with `>`");
                    self.i = eol;
                    return;
                }
            }
        } else if self.peek().is_some()
            && (self.peek() == self.dialect.lexical.parameter.map(|(s, _)| s as u8) || self.peek() == self.expr_open())
        {
            // `o#<sub> call`, `o[#1+100] call`: the number comes from a parameter.
            let from = self.i;
            label_expr = self.unary(0);
            if label_expr.is_none() {
                self.i = self.line_end();
                return;
            }
            Some(self.range(from, self.i))
        } else {
            let from = self.i;
            while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                self.i += 1;
            }
            (self.i > from).then(|| self.range(from, self.i))
        };
        if label.is_none() {
            self.error(Code::MalformedNumber, start, self.i.max(start + 1), "a control word needs a label such as o100 or o<name>");
            self.i = self.line_end();
            return;
        }
        self.skip_blanks();
        let (kw, statement) = self.control_keyword();
        let mut control = Control { label, label_expr, ..Control::default() };
        if !kw.is_empty() {
            control.keyword = Some(self.abs(kw));
            control.statement = statement;
            self.i = kw.end as usize;
            if control.statement.is_none() {
                self.i = self.line_end();
            }
            self.operands(&mut control);
        }
        control.range = self.range(start, self.i);
        let named = !kw.is_empty();
        self.block.control = Some(control);
        // A statement whose operands were already found wrong is not told twice.
        if self.diags.len() == mark {
            self.nothing_after_control_word(start, named);
        }
    }

    /// RS274NGC stops at a control word with no statement after its label (`O1 #<d> = 1`:
    /// "unknown control command in o word") and at text after its statement
    /// (`o1 if [..]abort`: "unexpected character after O-word"); a comment may follow. The rest
    /// of the line is skipped, as the control reads none of it.
    fn nothing_after_control_word(&mut self, start: usize, named: bool) {
        self.skip_blanks();
        let eol = self.line_end();
        let Some(c) = self.peek().filter(|_| self.i < eol) else { return };
        let lex = &self.dialect.lexical;
        if lex.comments.iter().any(|r| r.opens(&self.b[self.i..])) || lex.block_end.is_some_and(|e| e as u32 == u32::from(c)) {
            return;
        }
        let rest = self.text[self.i..eol].trim_end().to_owned();
        let message = if named {
            format!("`{rest}` after the control word's statement: the control stops at any text after it but a comment")
        } else {
            format!("the control word is followed by no statement (`sub`, `if`, `call`, ...) but by `{rest}`: the control stops at it")
        };
        self.error(Code::UnknownAddress, if named { self.i } else { start }, eol, message);
        self.i = eol;
    }

    /// Whether statement keywords open blocks: in a dialect without a control word, or one
    /// that says so beside it.
    fn keywords_open_blocks(&self) -> bool {
        self.dialect.lexical.control_word.is_none() || self.dialect.lexical.keyword_statements
    }

    /// `IF [#1 GT 0] GOTO 10`, `WHILE [#2 LT 5] DO 1`, `END 1`, `GOTO #3`, `CALL LBL 1 REP 2`:
    /// a statement that starts with a keyword. Where the dialect calls programs by name, an
    /// unknown name is such a call (`DRILLING`, `L123 P2`, `MYPROC(1.5, 3)`). Any other run of
    /// letters is kept as an unknown statement, so that the interpreter can name it.
    pub(super) fn keyword_statement(&mut self, start: usize) {
        let known = if self.keywords_open_blocks() { self.statement_at(start) } else { None };
        let mut control = Control::default();
        match known {
            Some((end, Statement::Else)) if self.one_line_else() => {
                self.else_branch(start, end);
                return;
            }
            Some((end, mut st)) => {
                self.i = end;
                // One keyword for both (Siemens `REPEAT`): a label after it makes a section repeat.
                let pair = [Statement::RepeatUntil, Statement::RepeatSection];
                if pair.contains(&st) && pair.iter().all(|&p| self.dialect.macros.has_statement(p)) {
                    st = if self.label_follows() { Statement::RepeatSection } else { Statement::RepeatUntil };
                }
                control.keyword = Some(self.range(start, end));
                control.statement = Some(st);
                match st {
                    Statement::Declare => {
                        self.declaration();
                        return;
                    }
                    Statement::Print | Statement::Output | Statement::Inert | Statement::Unsupported | Statement::Procedure => {
                        // A print format, output setting, declaration or parameter list is not
                        // an expression: kept as text (a procedure's name is its target).
                        if st == Statement::Procedure {
                            self.skip_blanks();
                            let end = self.identifier_end(self.i);
                            control.name = (end > self.i).then(|| self.range(self.i, end));
                        }
                        let end = self.line_end();
                        let lex = &self.dialect.lexical;
                        // An unsupported or inert statement's text stops at a comment too.
                        let plain = matches!(st, Statement::Inert | Statement::Unsupported);
                        // Any statement's stops at a `//` comment outside quotes (LNC `W_REG[5, 1] // note`).
                        let b = self.b;
                        let mut quoted = false;
                        let mut stops = |p: usize| {
                            quoted ^= lex.string_quote.is_some_and(|q| q as u8 == b[p]);
                            let comment =
                                |r: &crate::dialect::CommentRule| (plain || (r.open2.is_some() && !quoted)) && r.opens(&b[p..end]);
                            lex.block_end.is_some_and(|e| b[p] == e as u8) || lex.comments.iter().any(comment)
                        };
                        let from = self.i;
                        self.i = (self.i..end).find(|&p| stops(p)).unwrap_or(end);
                        // A text opened and never closed (`MSG("` at the line's end): the control
                        // cannot read the statement (Siemens alarm 12080, syntax error).
                        if let Some(q) = lex.string_quote.filter(|_| !plain) {
                            let at = b[from..self.i].iter().rposition(|&c| c == q as u8).map(|p| from + p);
                            let open = b[from..self.i].iter().filter(|&&c| c == q as u8).count() % 2 == 1;
                            if let (true, Some(at)) = (open, at) {
                                self.error(Code::MalformedExpression, at, self.i, format!("the string is not closed with `{q}`"));
                            }
                        }
                    }
                    _ => self.operands(&mut control),
                }
            }
            None if self.dialect.macros.call_by_name && self.call_by_name(start, &mut control) => {}
            None => {
                let end = self.line_end();
                let lex = &self.dialect.lexical;
                // An unknown statement's text stops at the block's end, or at a comment to the
                // end of the line outside quotes (`QS3 = "%0x" ;temp string`): the comment is a comment still.
                let mut quoted = false;
                let b = self.b;
                let mut stops = |p: usize| {
                    let c = b[p];
                    quoted ^= lex.string_quote.is_some_and(|q| q as u8 == c);
                    let comment = |r: &crate::dialect::CommentRule| {
                        r.opens(&b[p..end]) && !r.block_start && r.close == crate::dialect::CommentClose::EndOfLine
                    };
                    !quoted && (lex.block_end.is_some_and(|e| e as u8 == c) || lex.comments.iter().any(comment))
                };
                let end = (start..end).find(|&p| stops(p)).unwrap_or(end);
                control.keyword = Some(self.abs(self.alpha_run()));
                self.i = end;
            }
        }
        control.range = self.range(start, self.i);
        self.block.control = Some(control);
    }

    /// `DEF REAL LEN=10.5, WID`: each declared variable starts at its value, or 0.
    fn declaration(&mut self) {
        self.skip_blanks();
        let type_end = self.identifier_end(self.i);
        self.i = type_end;
        // `STRING[20]`, array bounds: skipped.
        if self.peek() == Some(b'[') {
            while self.peek().is_some_and(|c| c != b']' && c != b'\n' && c != b'\r') {
                self.i += 1;
            }
            if self.peek() == Some(b']') {
                self.i += 1;
            }
        }
        loop {
            self.skip_blanks();
            let start = self.i;
            let end = self.identifier_end(start);
            if end == start {
                break;
            }
            // `DEF REAL ANG`: a name the control already has (an address of its own: `ANG`,
            // `RND`, `CHR`, `CR`, an axis) cannot be a user variable's; the 840D rejects the
            // definition (SINUMERIK 840D sl Job Planning, "Definition of user variables": the
            // name must not be one of the predefined identifiers).
            let name = &self.text[start..end];
            if self.dialect.addresses.iter().any(|a| a.name.eq_ignore_ascii_case(name)) {
                let msg = format!("`{name}` is a name of the control's own (an address): a user variable cannot be defined with it");
                self.error(Code::MalformedExpression, start, end, msg);
                self.i = self.line_end();
                return;
            }
            self.i = end;
            self.skip_blanks();
            // `DEF REAL _RICH[4]`: a one-dimensional array whose elements start at 0.
            if let Some((open, close)) = self.dialect.lexical.array_brackets
                && self.peek() == Some(open)
            {
                let inner = self.i + 1;
                let stop = self.b[inner..].iter().position(|&c| c == close || c == b'\n').map_or(self.b.len(), |p| inner + p);
                let size = self.text[inner..stop].trim().parse::<u32>().ok().filter(|n| (1..=1000).contains(n));
                let after = self.b[(stop + 1).min(self.b.len())..].iter().find(|c| !matches!(c, b' ' | b'\t')).copied();
                if let Some(n) = size.filter(|_| self.b.get(stop) == Some(&close) && after != Some(open)) {
                    let name = self.range(start, end);
                    for k in 0..n {
                        let (index, zero) = (self.push(Expr::Num(f64::from(k))), self.push(Expr::Num(0.0)));
                        self.block.assigns.push(Assign { target: ParamTarget::NamedIndex(name, index), value: zero, range: name });
                    }
                    self.i = stop + 1;
                    self.skip_blanks();
                    if self.peek() == Some(b'=') {
                        let d = Diagnostic::new(
                            Code::Unsupported,
                            self.range(start, end),
                            "an array's initial values are not read: its elements start at 0 here",
                        );
                        self.diags.push(d);
                        self.i = self.line_end();
                        return;
                    }
                    if self.peek() == Some(b',') {
                        self.i += 1;
                        continue;
                    }
                    break;
                }
            }
            if self.peek() == Some(b'[') {
                let d = Diagnostic::new(
                    Code::Unsupported,
                    self.range(start, end),
                    "array variables are not supported; the declaration is skipped",
                );
                self.diags.push(d);
                self.i = self.line_end();
                return;
            }
            let value = if self.peek() == Some(b'=') {
                self.i += 1;
                match self.expr(1, 0) {
                    Some(v) => v,
                    None => {
                        self.i = self.line_end();
                        return;
                    }
                }
            } else {
                self.push(Expr::Num(0.0))
            };
            self.block.assigns.push(Assign { target: ParamTarget::Named(self.range(start, end)), value, range: self.range(start, self.i) });
            self.skip_blanks();
            if self.peek() == Some(b',') {
                self.i += 1;
            } else {
                break;
            }
        }
    }

    /// `CASE R1 OF 1 GOTOF A 2 GOTOB B DEFAULT GOTOF C`: the operand, then each value (or
    /// `DEFAULT`) with its jump.
    fn case_branches(&mut self, control: &mut Control) {
        let start = self.i;
        let Some(operand) = self.expr(1, 0) else {
            self.i = self.line_end();
            return;
        };
        control.args.push(operand);
        self.skip_blanks();
        let of = self.alpha_run();
        if !self.text[of.start as usize..of.end as usize].eq_ignore_ascii_case("OF") {
            let end = self.i.max(start + 1).min(self.b.len());
            self.error(Code::MalformedExpression, self.i, end, "expected `OF` and the branches of the CASE");
            self.i = self.line_end();
            return;
        }
        self.i = of.end as usize;
        loop {
            self.skip_blanks();
            if self.at_block_end() {
                break;
            }
            let at = self.i;
            let word = self.alpha_run();
            let value = if self.text[word.start as usize..word.end as usize].eq_ignore_ascii_case("DEFAULT") {
                self.i = word.end as usize;
                None
            } else {
                match self.unary(1) {
                    Some(v) => Some(v),
                    None => {
                        self.i = self.line_end();
                        return;
                    }
                }
            };
            self.skip_blanks();
            let jump = self
                .statement_at(self.i)
                .filter(|(_, st)| matches!(st, Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet));
            let Some((end, jump)) = jump else {
                let end = self.line_end();
                self.error(
                    Code::MalformedExpression,
                    at,
                    end.max(at + 1).min(self.b.len()),
                    "each CASE branch needs a jump (GOTOF, GOTOB, GOTO)",
                );
                self.i = end;
                return;
            };
            self.i = end;
            let mut target = Control { statement: Some(jump), ..Control::default() };
            self.target(&mut target);
            control.cases.push(CaseBranch { value, jump, name: target.name, target: target.target });
        }
    }

    /// Whether a name follows on this line (`REPEAT MARK1`), not a comment or the line end.
    fn label_follows(&self) -> bool {
        let rest = &self.b[self.i..];
        let at = rest.iter().position(|c| !matches!(c, b' ' | b'\t')).unwrap_or(rest.len());
        rest.get(at).is_some_and(|c| c.is_ascii_alphabetic() || *c == b'_')
    }

    /// `REPEAT START [END] [P=n]`, `REPEATB MARK [P=n]`: the first label is the name, the
    /// second (if any) the label, the passes the repeat.
    fn repeat_section(&mut self, control: &mut Control) {
        self.target(control);
        self.skip_blanks();
        let repeat_word = self.dialect.macros.call_repeat.as_deref().unwrap_or("");
        if control.statement == Some(Statement::RepeatSection) && self.label_follows() {
            let end = self.identifier_end(self.i);
            let word = &self.text[self.i..end];
            if !word.eq_ignore_ascii_case(repeat_word) {
                control.label = Some(self.range(self.i, end));
                self.i = end;
            }
        }
        self.call_repeat(control);
    }

    /// The statement keyword at `at` and where it ends, longest first. A keyword of several
    /// words matches them separated by any blanks (`CALL  LBL`); it must not run into a
    /// letter (`IFX`), though a number may follow directly (`GOTO10`, `DO1`).
    pub(super) fn statement_at(&self, at: usize) -> Option<(usize, Statement)> {
        'keywords: for (k, st) in &self.dialect.macros.statements {
            let mut i = at;
            for (n, part) in k.split(' ').enumerate() {
                if n > 0 {
                    let j = i;
                    while matches!(self.b.get(i), Some(b' ' | b'\t')) {
                        i += 1;
                    }
                    if i == j {
                        continue 'keywords;
                    }
                }
                let end = i + part.len();
                if self.b.len() < end || !self.b[i..end].eq_ignore_ascii_case(part.as_bytes()) {
                    continue 'keywords;
                }
                i = end;
            }
            if self.b.get(i).is_some_and(|c| c.is_ascii_alphabetic() || *c == b'_') {
                continue;
            }
            // `@100` is not the start of `@1000`.
            if k.ends_with(|c: char| c.is_ascii_digit()) && self.b.get(i).is_some_and(u8::is_ascii_digit) {
                continue;
            }
            return Some((i, *st));
        }
        None
    }

    /// `NAME`, `NAME P3`, `L123`, `NAME(1.5, , 3)`: a call of the program `NAME`. False (and
    /// nothing consumed) when the block holds anything else after the name.
    fn call_by_name(&mut self, start: usize, control: &mut Control) -> bool {
        let end = self.identifier_end(start);
        if end == start {
            return false;
        }
        let (save, mark, exprs) = (self.i, self.diags.len(), self.block.exprs.len());
        self.i = end;
        self.skip_blanks();
        if self.peek().is_some() && self.peek() == self.expr_open() {
            self.i += 1;
            loop {
                self.skip_blanks();
                match self.peek() {
                    Some(b')' | b']') if Some(self.b[self.i]) == self.dialect.lexical.expression.map(|(_, c)| c as u8) => {
                        self.i += 1;
                        break;
                    }
                    Some(b',') => {
                        // An empty argument keeps its default.
                        let zero = self.push(Expr::Num(0.0));
                        control.args.push(zero);
                        self.i += 1;
                        continue;
                    }
                    _ => {}
                }
                // A string argument (`RAPORT("START")`) names something; it passes no number.
                if let Some(q) = self.dialect.lexical.string_quote
                    && self.peek() == Some(q as u8)
                {
                    if self.string(self.i).is_none() {
                        self.i = save;
                        self.diags.truncate(mark);
                        self.block.exprs.truncate(exprs);
                        control.args.clear();
                        return false;
                    }
                    let zero = self.push(Expr::Num(0.0));
                    control.args.push(zero);
                    self.skip_blanks();
                    if self.peek() == Some(b',') {
                        self.i += 1;
                    }
                    continue;
                }
                let Some(e) = self.expr(1, 0) else {
                    self.i = save;
                    self.diags.truncate(mark);
                    self.block.exprs.truncate(exprs);
                    control.args.clear();
                    return false;
                };
                control.args.push(e);
                self.skip_blanks();
                if self.peek() == Some(b',') {
                    self.i += 1;
                }
            }
        }
        self.call_repeat(control);
        self.skip_blanks();
        if !self.at_block_end() {
            self.i = save;
            self.diags.truncate(mark);
            self.block.exprs.truncate(exprs);
            control.args.clear();
            control.repeat = None;
            return false;
        }
        control.keyword = Some(self.range(start, end));
        control.name = Some(self.range(start, end));
        control.statement = Some(Statement::CallProgram);
        true
    }

    /// Whether the cursor is at the end of the block: end of line, a comment or a block end.
    fn at_block_end(&self) -> bool {
        if self.paren == Some(self.i) {
            return true;
        }
        match self.peek() {
            None | Some(b'\r' | b'\n') => true,
            Some(c) => {
                self.dialect.lexical.block_end == Some(c as char)
                    || self.dialect.lexical.comments.iter().any(|r| r.opens(&self.b[self.i..]))
            }
        }
    }

    /// The repeat word of a call (`P3`, `P=3`, `REP 2`), if the dialect has one.
    fn call_repeat(&mut self, control: &mut Control) {
        let Some(word) = self.dialect.macros.call_repeat.as_deref() else { return };
        self.skip_blanks();
        let end = self.i + word.len();
        if self.b.len() < end
            || !self.b[self.i..end].eq_ignore_ascii_case(word.as_bytes())
            || self.b.get(end).is_some_and(|c| c.is_ascii_alphabetic() || *c == b'_')
        {
            return;
        }
        self.i = end;
        self.skip_blanks();
        if self.peek() == Some(b'=') {
            self.i += 1;
        }
        control.repeat = self.unary(1);
        // The control's display form `REP 20/20` (passes set / passes left).
        if self.peek() == Some(b'/') && self.b.get(self.i + 1).is_some_and(u8::is_ascii_digit) {
            self.i += 1;
            while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                self.i += 1;
            }
        }
    }

    /// The target of a jump, label or call: a string (`LBL "NAME"`), a name (`GOTOF MARK1`,
    /// `CALL PGM TNC:\\PARTS\\SUB.H`) or a number (`GOTO 10`, `GOTO #1`).
    fn target(&mut self, control: &mut Control) {
        self.skip_blanks();
        let Some(c) = self.peek() else { return };
        let quote = self.dialect.lexical.string_quote.map(|q| q as u8);
        let sigil = self.dialect.lexical.parameter.map(|(s, _)| s as u8);
        if Some(c) == quote {
            control.name = self.string(self.i);
        } else if control.statement == Some(Statement::CallProgram) && !self.at_block_end() {
            let from = self.i;
            // A comma ends the name too: its arguments follow (`(PCALL 3, P0=1)`).
            while self.peek().is_some_and(|c| !matches!(c, b' ' | b'\t' | b'\r' | b'\n' | b',')) && !self.at_block_end() {
                self.i += self.char_len(self.i);
            }
            control.name = Some(self.range(from, self.i));
        } else if c.is_ascii_alphabetic() || c == b'_' {
            let param = Some(c.to_ascii_uppercase()) == sigil && self.b.get(self.i + 1).is_some_and(u8::is_ascii_digit);
            if param {
                control.target = self.unary(1);
            } else {
                let end = self.identifier_end(self.i);
                control.name = Some(self.range(self.i, end));
                self.i = end;
            }
        } else if c.is_ascii_digit() || matches!(c, b'+' | b'-' | b'.') || Some(c) == self.expr_open() || Some(c) == sigil {
            control.target = self.unary(1);
        }
    }

    /// `FOR R1=0 TO 10`, `$FOR P1=0,10,2`: the counter (target), its first and last value and
    /// an optional step (operands).
    fn for_head(&mut self, control: &mut Control) {
        let start = self.i;
        self.skip_blanks();
        let Some(var) = self.unary(1) else {
            self.i = self.line_end();
            return;
        };
        control.target = Some(var);
        self.skip_blanks();
        if !self.expect(b'=', "after the loop counter", start) {
            self.i = self.line_end();
            return;
        }
        let Some(first) = self.expr(1, 0) else {
            self.i = self.line_end();
            return;
        };
        self.skip_blanks();
        if self.peek() == Some(b',') {
            // `$FOR P1 = 1, 10, 2`: the last value, then an optional step.
            self.i += 1;
            let Some(last) = self.expr(1, 0) else {
                self.i = self.line_end();
                return;
            };
            control.args.extend([first, last]);
            self.skip_blanks();
            if self.peek() == Some(b',') {
                self.i += 1;
                if let Some(step) = self.expr(1, 0) {
                    control.args.push(step);
                }
            }
            return;
        }
        let to = self.alpha_run();
        if !self.text[to.start as usize..to.end as usize].eq_ignore_ascii_case("TO") {
            self.error(
                Code::MalformedExpression,
                self.i,
                self.i.max(to.end as usize).max(self.i + 1).min(self.b.len()),
                "expected `TO` and the last value",
            );
            self.i = self.line_end();
            return;
        }
        self.i = to.end as usize;
        let Some(last) = self.expr(1, 0) else {
            self.i = self.line_end();
            return;
        };
        control.args.extend([first, last]);
    }

    /// The operands after a statement keyword: a target for jumps, labels, calls and loop
    /// ends, the counter of a `FOR`, a condition (bracketed operands, or one bare expression),
    /// then an optional second keyword and its target.
    fn operands(&mut self, control: &mut Control) {
        let Some(st) = control.statement else { return };
        self.skip_blanks();
        if self.operands_of_their_own(st, control) || !self.condition(st, control) {
            return;
        }
        self.then_clause(st, control);
    }

    /// The operands of statements that have a form of their own: a loop's number (`DO 1`,
    /// `END 1`), a section repeat, `CASE`, the target of a jump, label or call, `FOR`. False,
    /// with nothing read, for any other statement (and a `DO` or `END` without a number).
    fn operands_of_their_own(&mut self, st: Statement, control: &mut Control) -> bool {
        let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
        let takes_target = |st: Statement| {
            matches!(
                st,
                Statement::Goto
                    | Statement::GotoForward
                    | Statement::GotoBack
                    | Statement::GotoQuiet
                    | Statement::GotoLabel
                    | Statement::EndDo
                    | Statement::Do
                    | Statement::Label
                    | Statement::CallLabel
                    | Statement::CallProgram
            )
        };
        let starts_operand = |c: Option<u8>, sigil: Option<u8>| {
            c.is_some_and(|c| c.is_ascii_digit() || c == b'+' || c == b'-' || c == b'.' || Some(c) == sigil || Some(c) == expr_open)
        };
        let sigil = self.dialect.lexical.parameter.map(|(s, _)| s as u8);
        if matches!(st, Statement::Do | Statement::EndDo) {
            if starts_operand(self.peek(), sigil) {
                control.target = self.unary(1);
                return true;
            }
        } else if matches!(st, Statement::RepeatSection | Statement::RepeatBlock) {
            self.repeat_section(control);
            return true;
        } else if st == Statement::Case {
            self.case_branches(control);
            return true;
        } else if takes_target(st) {
            if self.keywords_open_blocks() {
                self.target(control);
                if matches!(st, Statement::CallLabel | Statement::CallProgram) {
                    self.call_repeat(control);
                }
            } else if starts_operand(self.peek(), sigil) {
                control.target = self.unary(1);
            }
            return true;
        }
        if st == Statement::For {
            self.for_head(control);
            return true;
        }
        false
    }

    /// A condition into `control.args`: one bare expression where the dialect writes
    /// conditions bare, else each bracketed operand (`o<x> call [1] [2]`). False when an
    /// operand could not be read.
    fn condition(&mut self, st: Statement, control: &mut Control) -> bool {
        let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
        let condition = matches!(st, Statement::If | Statement::ElseIf | Statement::While | Statement::Until);
        if condition && self.dialect.macros.bare_conditions {
            if !self.at_block_end() {
                match self.expr(1, 0) {
                    Some(e) => control.args.push(e),
                    None => return false,
                }
            }
        } else {
            loop {
                self.skip_blanks();
                // Comments may sit between operands: `o<x> call [1] (note) [2]`.
                while let Some(rule) = self.dialect.lexical.comments.iter().find(|r| r.opens(&self.b[self.i..])) {
                    let close = rule.close.clone();
                    self.comment(&close);
                    self.skip_blanks();
                }
                if self.peek().is_none() || self.peek() != expr_open {
                    break;
                }
                match self.unary(1) {
                    Some(e) => control.args.push(e),
                    None => return false,
                }
            }
        }
        true
    }

    /// A second keyword after the condition and its target: `GOTO 10`, `THEN`, `DO 1`; or,
    /// where the dialect allows, a bare block name after an `IF` condition.
    fn then_clause(&mut self, st: Statement, control: &mut Control) {
        self.skip_blanks();
        if !self.keywords_open_blocks() || !self.peek().is_some_and(|c| c.is_ascii_alphabetic()) {
            return;
        }
        let Some((end, then)) = self.statement_at(self.i) else {
            // `IF [VC1 EQ 0] NLOOP`: a condition and a block name, with no GOTO.
            let lex = &self.dialect.lexical;
            if st == Statement::If
                && self.dialect.macros.bare_if_jump
                && lex.named_blocks
                && self.peek().map(|c| c.to_ascii_uppercase() as char) == lex.block_number
            {
                control.then = Some(Statement::Goto);
                self.target(control);
            }
            return;
        };
        let jump =
            matches!(then, Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet | Statement::GotoLabel);
        if !(jump || matches!(then, Statement::Then | Statement::Do)) {
            return;
        }
        self.i = end;
        control.then = Some(then);
        self.skip_blanks();
        if then == Statement::Do {
            control.target = self.unary(1);
        } else if jump {
            self.target(control);
        } else if then == Statement::Then
            && let Some((end, jump)) = self.statement_at(self.i).filter(|&(_, st)| is_jump(st))
        {
            // `IF #111 != 121 THEN GOTO 1000` (Centroid CNC12's IF .. THEN with a jump, the
            // Avid macros' form): the jump is the THEN clause's one statement, taken only
            // when the condition holds, as `IF [..] GOTO n`.
            self.i = end;
            control.then = Some(jump);
            self.target(control);
        }
    }

    /// Whether an `ELSE` at `start` is the else of this line's one-line `IF`: the block holds
    /// an `IF` whose condition has a THEN clause or a jump after it.
    fn one_line_else(&self) -> bool {
        self.block.control.as_ref().is_some_and(|c| {
            c.statement == Some(Statement::If) && c.otherwise.is_none() && c.then.is_some_and(|t| t == Statement::Then || is_jump(t))
        })
    }

    /// `ELSE GOTO 2`, `ELSE #2 = 1`, or `ELSE` alone after a one-line `IF` (see
    /// [`crate::syntax::Otherwise`]): noted on the `IF`, whose statement the block keeps. The
    /// words and assignments after it are read as the block's, from the places noted.
    fn else_branch(&mut self, start: usize, end: usize) {
        let mut otherwise = Otherwise {
            keyword: self.range(start, end),
            words: self.block.words.len() as u32,
            assigns: self.block.assigns.len() as u32,
            ..Otherwise::default()
        };
        self.i = end;
        self.skip_blanks();
        if let Some((end, jump)) = self.statement_at(self.i).filter(|&(_, st)| is_jump(st)) {
            self.i = end;
            let mut target = Control { statement: Some(jump), ..Control::default() };
            self.target(&mut target);
            otherwise.jump = Some(jump);
            otherwise.target = target.target;
            otherwise.name = target.name;
        }
        let end = self.range(start, self.i).end;
        if let Some(c) = self.block.control.as_mut() {
            c.otherwise = Some(otherwise);
            c.range.end = end;
        }
    }
}

/// Whether `st` is a jump: `GOTO` and its forms.
fn is_jump(st: Statement) -> bool {
    matches!(st, Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet | Statement::GotoLabel)
}

//! Expressions into the block's arena: precedence climbing over binary operators, and
//! operands (signs, numbers, brackets, parameters, variables, function calls). Its doors are
//! `Lexer::expr` (a whole expression) and `Lexer::unary` (one operand).

use super::super::expr::{BinOp, Expr, ExprId, Func};
use super::Lexer;
use crate::diag::Code;
use crate::text::TextRange;

impl Lexer<'_, '_> {
    pub(super) fn push(&mut self, e: Expr) -> ExprId {
        self.block.exprs.push(e);
        (self.block.exprs.len() - 1) as ExprId
    }

    pub(super) fn expect(&mut self, c: u8, what: &str, start: usize) -> bool {
        self.skip_expr_blanks();
        if self.peek() == Some(c) {
            self.i += 1;
            true
        } else {
            let end = self.i.max(start + 1).min(self.b.len());
            self.error(Code::MalformedExpression, start, end, format!("expected `{}` {what}", c as char));
            false
        }
    }

    /// Blanks inside an expression, and the dialect's continuation mark at a line's end with
    /// the line break after it: a TNC formula too long for one line goes on after `~` on the
    /// next (`Q2 = COS ( Q4 ) * 27,73 + ( 5 * ~` / `SIN ( Q4 ) ) + 50`), as a cycle
    /// definition's parameter lines do (TNC user's manual, "Programming Q parameters").
    fn skip_expr_blanks(&mut self) {
        self.skip_blanks();
        let Some(k) = self.dialect.lexical.continuation else { return };
        if self.peek() != Some(k as u8) {
            return;
        }
        let save = self.i;
        self.i += 1;
        self.skip_blanks();
        if self.continue_line() {
            self.skip_blanks();
        } else {
            self.i = save;
        }
    }

    /// A full expression with binary operators, by precedence climbing.
    pub(super) fn expr(&mut self, depth: u32, min_prec: u8) -> Option<ExprId> {
        let mut lhs = self.unary(depth)?;
        loop {
            self.skip_expr_blanks();
            let save = self.i;
            let Some(op) = self.binop() else { break };
            if op.precedence() < min_prec {
                self.i = save;
                break;
            }
            let rhs = self.expr(depth + 1, op.precedence() + 1)?;
            lhs = self.push(Expr::Binary(op, lhs, rhs));
        }
        Some(lhs)
    }

    fn binop(&mut self) -> Option<BinOp> {
        let c = self.peek()?;
        let op = match c {
            b'*' if self.b.get(self.i + 1) == Some(&b'*') => {
                self.i += 2;
                return Some(BinOp::Pow);
            }
            b'*' => BinOp::Mul,
            // `QS1 = QS2 || QS3`: texts joined (TNC 640 user's manual, "String functions").
            b'|' if self.dialect.lexical.bar_concatenation && self.b.get(self.i + 1) == Some(&b'|') => {
                self.i += 2;
                return Some(BinOp::Concat);
            }
            b'/' if self.dialect.lexical.comments.iter().any(|r| r.open2.is_some() && r.opens(&self.b[self.i..])) => return None,
            b'/' => BinOp::Div,
            b'+' => BinOp::Add,
            b'-' => BinOp::Sub,
            b'=' | b'<' | b'>' | b'!' | b'&' | b'|' if self.dialect.lexical.symbolic_comparisons => {
                let next = self.b.get(self.i + 1).copied();
                let (op, len) = match (c, next) {
                    (b'=', Some(b'=')) => (BinOp::Eq, 2),
                    (b'!', Some(b'=')) => (BinOp::Ne, 2),
                    (b'&', Some(b'&')) => (BinOp::And, 2),
                    (b'|', Some(b'|')) => (BinOp::Or, 2),
                    (b'<', Some(b'>')) => (BinOp::Ne, 2),
                    (b'<', Some(b'<')) => (BinOp::Concat, 2),
                    (b'<', Some(b'=')) => (BinOp::Le, 2),
                    (b'>', Some(b'=')) => (BinOp::Ge, 2),
                    (b'<', _) => (BinOp::Lt, 1),
                    (b'>', _) => (BinOp::Gt, 1),
                    _ => return None,
                };
                self.i += len;
                return Some(op);
            }
            c if c.is_ascii_alphabetic() => {
                let end = self.b[self.i..].iter().position(|x| !x.is_ascii_alphabetic()).map_or(self.b.len(), |p| self.i + p);
                let word = self.text[self.i..end].to_ascii_uppercase();
                if let Some(op) = BinOp::named(&word) {
                    self.i = end;
                    return Some(op);
                }
                // Fanuc-style macro text runs keywords together (`IF[#20NEFIX[#20]]`): an
                // operator directly followed by a function name, whose bracket comes next.
                let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
                if expr_open.is_some() && self.b.get(end).copied() == expr_open {
                    for len in [3, 2] {
                        let (op, rest) = (word.get(..len)?, word.get(len..)?);
                        if let (Some(op), Some(_)) = (BinOp::named(op), Func::named(rest)) {
                            self.i += len;
                            return Some(op);
                        }
                    }
                }
                return None;
            }
            _ => return None,
        };
        self.i += 1;
        Some(op)
    }

    /// A signed operand: number, bracketed expression, parameter, variable or function call.
    /// Past [`MAX_DEPTH`] nested operands, a finding and the rest of the line is skipped.
    pub(super) fn unary(&mut self, depth: u32) -> Option<ExprId> {
        let start = self.i;
        if depth > MAX_DEPTH {
            self.error(Code::MalformedExpression, start, start + 1, "expression is nested too deeply");
            self.i = self.line_end();
            return None;
        }
        self.skip_expr_blanks();
        let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
        let Some(c) = self.peek() else {
            self.error(Code::MalformedExpression, start, start, "expression ends early");
            return None;
        };
        match c {
            b'-' | b'+' => {
                self.i += 1;
                let inner = self.unary(depth + 1)?;
                Some(if c == b'-' { self.push(Expr::Unary(Func::Neg, inner)) } else { inner })
            }
            b'0'..=b'9' | b'.' => {
                let (v, _) = self.number()?;
                Some(self.push(Expr::Num(v)))
            }
            c if self.dialect.lexical.numbers.radix.is_some_and(|(q, _, _)| c == q as u8) => {
                let (q, hex, binary) = self.dialect.lexical.numbers.radix.unwrap_or_default();
                let v = self.radix_constant(q as u8, hex as u8, binary as u8)?;
                Some(self.push(Expr::Num(v)))
            }
            c if Some(c) == expr_open => self.bracketed(depth, start),
            b'(' if self.dialect.lexical.paren_grouping => {
                self.i += 1;
                let e = self.expr(depth + 1, 0)?;
                if !self.expect(b')', "to close the group", start) {
                    return None;
                }
                Some(e)
            }
            c if Some(c) == self.dialect.lexical.string_quote.map(|q| q as u8) => {
                let r = self.string(start)?;
                Some(self.push(Expr::Text(r)))
            }
            b'<' if self.at_define_name(self.i) => {
                let name = self.name(start)?;
                Some(self.push(Expr::Named(name)))
            }
            // `!<ENABLED>`: not, where comparisons are written as symbols (`!=`, `&&`).
            b'!' if self.dialect.lexical.symbolic_comparisons && self.b.get(self.i + 1) != Some(&b'=') => {
                self.i += 1;
                let inner = self.unary(depth + 1)?;
                Some(self.push(Expr::Unary(Func::Not, inner)))
            }
            c if self.at_parameter(c, expr_open) => self.parameter(depth, start),
            c if self.at_variable(c, expr_open) => self.variable(depth, expr_open),
            c if c.is_ascii_alphabetic() => self.function_call(depth, start),
            _ => self.unexpected(start),
        }
    }

    /// The bracket that closes an expression in this dialect (`]` where it names none).
    fn expr_close(&self) -> u8 {
        self.dialect.lexical.expression.map(|(_, c)| c as u8).unwrap_or(b']')
    }

    /// `[expr]` at the cursor: the expression inside the dialect's brackets.
    fn bracketed(&mut self, depth: u32, start: usize) -> Option<ExprId> {
        self.i += 1;
        let e = self.expr(depth + 1, 0)?;
        if !self.expect(self.expr_close(), "to close the expression", start) {
            return None;
        }
        Some(e)
    }

    /// Whether `c` at the cursor is the parameter sigil starting a parameter (`#1`, `#[..]`,
    /// `#<name>`); a letter sigil (`Q`, `R`) only before a digit or a bracket.
    fn at_parameter(&self, c: u8, expr_open: Option<u8>) -> bool {
        let sigil = self.dialect.lexical.parameter.map(|(s, _)| s as u8);
        let global = self.dialect.lexical.global_parameter.map(|(s, _)| s as u8);
        let operand = || self.b.get(self.i + 1).is_some_and(|n| n.is_ascii_digit() || Some(*n) == expr_open);
        (Some(c.to_ascii_uppercase()) == sigil && (!c.is_ascii_alphabetic() || operand()))
            || (Some(c) == global && operand())
            || self.parameter_bank_at(self.i).is_some()
    }

    /// A parameter at its sigil: `#<name>` where parameters have names, else `#` and the
    /// operand that gives its number (`#1`, `##2`, `#[#1+1]`).
    fn parameter(&mut self, depth: u32, start: usize) -> Option<ExprId> {
        let bank = self.global_bank();
        self.i += bank.map_or(1, |(_, len)| len);
        self.skip_blanks();
        if self.peek() == Some(b'<') && bank.is_none() && self.dialect.lexical.parameter.is_some_and(|(_, named)| named) {
            let name = self.name(start)?;
            return Some(self.push(Expr::Named(name)));
        }
        if let Some(name) = self.letter_variable() {
            return Some(self.push(Expr::Named(name)));
        }
        let inner = self.parameter_number(depth, bank.map(|(first, _)| first))?;
        Some(self.push(Expr::Param(inner)))
    }

    /// Where the cursor is at the sigil of the dialect's second bank of variables (`@1`),
    /// the number its variable 0 is kept as.
    /// Or at the letters of a bank of variables named by letters and a number (Heidenhain
    /// `QL1`): the number its variable 0 is kept as, and the length of its mark.
    pub(super) fn global_bank(&self) -> Option<(u32, usize)> {
        match self.dialect.lexical.global_parameter.filter(|&(s, _)| self.peek() == Some(s as u8)) {
            Some((_, first)) => Some((first, 1)),
            None => self.parameter_bank_at(self.i),
        }
    }

    /// The bank of variables whose letters start at `at` before a digit (`QL1`, `QS10`): the
    /// number its variable 0 is kept as, and the length of its letters.
    pub(super) fn parameter_bank_at(&self, at: usize) -> Option<(u32, usize)> {
        self.dialect.lexical.parameter_banks.iter().find_map(|(prefix, first)| {
            let end = at + prefix.len();
            let named = self.b.get(at..end).is_some_and(|w| w.eq_ignore_ascii_case(prefix.as_bytes()));
            (named && self.b.get(end).is_some_and(u8::is_ascii_digit)).then_some((*first, prefix.len()))
        })
    }

    /// The operand after a parameter's sigil that gives its number, moved into its bank.
    pub(super) fn parameter_number(&mut self, depth: u32, bank: Option<u32>) -> Option<ExprId> {
        let inner = self.unary(depth + 1)?;
        Some(match bank {
            Some(first) => {
                let base = self.push(Expr::Num(f64::from(first)));
                self.push(Expr::Binary(BinOp::Add, base, inner))
            }
            None => inner,
        })
    }

    /// Whether a variable's name starts at the cursor (`c`), where identifiers name variables:
    /// an identifier or system variable that is not a function called with brackets.
    fn at_variable(&self, c: u8, expr_open: Option<u8>) -> bool {
        self.dialect.lexical.identifier_variables && (c.is_ascii_alphabetic() || c == b'_' || self.at_system_variable(self.i)) && {
            let end = self.identifier_end(self.i);
            Func::named(&self.text[self.i..end].to_ascii_uppercase()).is_none()
                || self.b[end..].iter().find(|x| !matches!(x, b' ' | b'\t')).is_none_or(|x| Some(*x) != expr_open)
        }
    }

    /// A variable at the cursor (`LEN`, `$AC_TIME`), an element of a named array (`VTOFD[1]`,
    /// `_RICH[2]`), or a lone axis letter standing for its axis.
    fn variable(&mut self, depth: u32, expr_open: Option<u8>) -> Option<ExprId> {
        let end = self.identifier_end(self.i);
        let r = self.range(self.i, end);
        // A lone axis letter (`DEF AXIS _X=X`, `_AX1=Z`, `MOVE(Y, 10)`) is that axis, as an
        // axis variable's value: a single letter is never a variable.
        let after = self.b[end..].iter().find(|x| !matches!(x, b' ' | b'\t')).copied();
        if end == self.i + 1
            && self.dialect.letter_role(self.b[self.i].to_ascii_uppercase()).is_some_and(|r| r.is_axis())
            && !matches!(after, Some(b'[' | b'=' | b'('))
            && after != expr_open
        {
            let letter = self.b[self.i];
            self.i = end;
            return Some(self.push(Expr::Num(super::super::axis_value(letter))));
        }
        self.i = end;
        if self.peek().is_some() && self.peek() == expr_open {
            // `VTOFD[1]`: an element of a named array.
            let index = self.subscripts(depth + 1)?;
            return Some(self.push(Expr::NamedIndex(r, index)));
        }
        if let Some(index) = self.array_index(depth) {
            return Some(self.push(Expr::NamedIndex(r, index?)));
        }
        Some(self.push(Expr::Named(r)))
    }

    /// A named array's subscripts in expression brackets: one (`VTOFD[1]`), or several
    /// where the brackets are square (Okuma's tool data `VTOHT[[VTLCN],10001]`, a tool
    /// number and a data number). Several read as one element: the first subscript times
    /// 1 000 000 plus the next (a tool data number stays below that).
    pub(super) fn subscripts(&mut self, depth: u32) -> Option<ExprId> {
        if self.peek() != Some(b'[') || self.dialect.lexical.expression.is_none_or(|(o, _)| o != '[') {
            return self.unary(depth);
        }
        let start = self.i;
        self.i += 1;
        let mut index = self.expr(depth + 1, 0)?;
        self.skip_blanks();
        while self.peek() == Some(b',') {
            self.i += 1;
            let next = self.expr(depth + 1, 0)?;
            let scale = self.push(Expr::Num(1_000_000.0));
            let row = self.push(Expr::Binary(BinOp::Mul, index, scale));
            index = self.push(Expr::Binary(BinOp::Add, row, next));
            self.skip_blanks();
        }
        if !self.expect(self.expr_close(), "to close the subscripts", start) {
            return None;
        }
        Some(index)
    }

    /// A function call at its name (`SIN[30]`, `ATAN[1]/[2]`, `EXISTS[#<x>]`); its argument
    /// in brackets, or bare where the dialect allows (`SIN +Q1`).
    fn function_call(&mut self, depth: u32, start: usize) -> Option<ExprId> {
        let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
        let mut end = self.b[self.i..].iter().position(|x| !x.is_ascii_alphabetic()).map_or(self.b.len(), |p| self.i + p);
        // Siemens `ATAN2(y, x)`: the arc tangent of two arguments, by its own name.
        if self.b.get(end) == Some(&b'2') && self.text[self.i..end].eq_ignore_ascii_case("ATAN") {
            end += 1;
        }
        let word = self.text[self.i..end].to_ascii_uppercase();
        if let Some(e) = self.machine_function(start, expr_open) {
            return Some(e);
        }
        let Some(func) = Func::named(&word) else {
            self.error(Code::MalformedExpression, start, end, format!("unknown function `{word}`"));
            self.i = end;
            return None;
        };
        self.i = end;
        self.skip_blanks();
        if func == Func::Exists {
            return self.exists(depth, start);
        }
        let grouped = self.dialect.lexical.paren_grouping && self.peek() == Some(b'(');
        if self.peek() != expr_open && !grouped {
            if self.dialect.lexical.bare_function_arguments && self.peek().is_some() {
                // `SIN +Q1`, `SQRT 25`: the operand follows without brackets.
                let inner = self.unary(depth + 1)?;
                return Some(self.push(Expr::Unary(func, inner)));
            }
            self.error(Code::MalformedExpression, start, self.i, format!("`{word}` needs its argument in brackets"));
            return None;
        }
        if matches!(func, Func::Atan | Func::Pow) && self.has_comma_before_close() {
            return self.two_arguments(func, depth, start);
        }
        if func == Func::Pow {
            self.error(Code::MalformedExpression, start, self.i, "POW needs two arguments: POW[a,b]");
            // Skip its bracket, so that the rest of the block reads on.
            let _ = self.unary(depth + 1);
            return None;
        }
        let arg = self.unary(depth + 1)?;
        if func == Func::Atan {
            self.skip_blanks();
            if self.peek() == Some(b'/') && self.b.get(self.i + 1).is_some_and(|&n| Some(n) == expr_open || n == b' ') {
                self.i += 1;
                let x = self.unary(depth + 1)?;
                return Some(self.push(Expr::Atan2(arg, x)));
            }
        }
        Some(self.push(Expr::Unary(func, arg)))
    }

    /// `EXISTS[#<name>]`, `EXISTS[#1]`: whether a parameter is set, after the function's name.
    fn exists(&mut self, depth: u32, start: usize) -> Option<ExprId> {
        let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
        let sigil = self.dialect.lexical.parameter.map(|(s, _)| s as u8);
        if !self.expect(expr_open.unwrap_or(b'['), "after EXISTS", start) {
            return None;
        }
        self.skip_blanks();
        let has_sigil = sigil.is_some() && self.peek() == sigil;
        if has_sigil {
            self.i += 1;
        }
        self.skip_blanks();
        let n = if self.peek() == Some(b'<') {
            let name = self.name(start)?;
            self.push(Expr::Named(name))
        } else if !has_sigil {
            let end = self.line_end();
            self.error(Code::MalformedExpression, start, end, "EXISTS takes a parameter: `EXISTS[#<name>]` or `EXISTS[#1]`");
            self.i = end;
            return None;
        } else {
            // `EXISTS[#1]`, `EXISTS[##2]`: whether the index names a parameter.
            let index = self.unary(depth + 1)?;
            self.push(Expr::Param(index))
        };
        if !self.expect(self.expr_close(), "to close EXISTS", start) {
            return None;
        }
        Some(self.push(Expr::Unary(Func::Exists, n)))
    }

    /// Two arguments in one bracket: `ATAN[y,x]`, `POW[a,b]` (Fanuc 30i).
    fn two_arguments(&mut self, func: Func, depth: u32, start: usize) -> Option<ExprId> {
        self.i += 1;
        let a = self.expr(depth + 1, 0)?;
        if !self.expect(b',', "between the two arguments", start) {
            return None;
        }
        let b = self.expr(depth + 1, 0)?;
        if !self.expect(self.expr_close(), "to close the arguments", start) {
            return None;
        }
        let e = if func == Func::Atan { Expr::Atan2(a, b) } else { Expr::Binary(BinOp::Pow, a, b) };
        Some(self.push(e))
    }

    /// A finding for what cannot start an operand at `start`.
    fn unexpected(&mut self, start: usize) -> Option<ExprId> {
        let len = self.char_len(start);
        let shown = &self.text[start..start + len];
        let msg = if matches!(shown, "" | "\r" | "\n") {
            "expression ends early".to_owned()
        } else {
            format!("unexpected `{shown}` in expression")
        };
        self.error(Code::MalformedExpression, start, (start + len).max(start), msg);
        None
    }

    /// Whether the bracket at the cursor holds a comma at its own nesting level.
    fn has_comma_before_close(&self) -> bool {
        let (open, close) = (self.dialect.lexical.expression.map_or(b'[', |(o, _)| o as u8), self.expr_close());
        let mut depth = 0u32;
        for &c in &self.b[self.i..self.line_end()] {
            match c {
                c if c == open => depth += 1,
                c if c == close => {
                    depth = depth.saturating_sub(1);
                    if depth == 0 {
                        return false;
                    }
                }
                b',' if depth == 1 => return true,
                _ => {}
            }
        }
        false
    }

    /// A function of the dictionary's whose value comes from the machine (`R_REG[#100]`,
    /// `INPUT["title", "text", "", 1, 99, 4]`): its name and bracketed arguments read past, a
    /// value the analysis does not know. Blanks may stand before the bracket (Heidenhain
    /// `Q1 = STRLEN ( SRC_QS1 )`).
    fn machine_function(&mut self, start: usize, expr_open: Option<u8>) -> Option<ExprId> {
        let open = expr_open?;
        let name_end =
            self.b[self.i..].iter().position(|x| !(x.is_ascii_alphanumeric() || *x == b'_')).map_or(self.b.len(), |p| self.i + p);
        let name = self.text[self.i..name_end].to_ascii_uppercase();
        let end = self.b[name_end..].iter().position(|x| !matches!(x, b' ' | b'\t')).map_or(self.b.len(), |p| name_end + p);
        if self.b.get(end) != Some(&open) || !self.dialect.macros.machine_functions.contains(&name) {
            return None;
        }
        let close = self.expr_close();
        let quote = self.dialect.lexical.string_quote.map_or(b'"', |q| q as u8);
        let eol = self.line_end();
        let (mut depth, mut quoted) = (0u32, false);
        for p in end..eol {
            let c = self.b[p];
            if c == quote {
                quoted = !quoted;
            } else if !quoted && c == open {
                depth += 1;
            } else if !quoted && c == close {
                depth -= 1;
                if depth == 0 {
                    self.i = p + 1;
                    let r = self.range(start, p + 1);
                    return Some(self.push(Expr::Text(r)));
                }
            }
        }
        self.error(Code::MalformedExpression, start, eol, format!("`{name}` is not closed"));
        self.i = eol;
        None
    }

    /// Whether a name `DEFINE` gave (`<TOOL_NUMBER>`, no sigil) starts at `at`, where the
    /// dialect has them: `<`, a letter or `_`, letters, digits or `_`, and `>`.
    pub(super) fn at_define_name(&self, at: usize) -> bool {
        if !self.dialect.lexical.define_names || self.b.get(at) != Some(&b'<') {
            return false;
        }
        let from = at + 1;
        if !self.b.get(from).is_some_and(|c| c.is_ascii_alphabetic() || *c == b'_') {
            return false;
        }
        let end = self.b[from..].iter().position(|c| !(c.is_ascii_alphanumeric() || *c == b'_')).map_or(self.b.len(), |p| from + p);
        self.b.get(end) == Some(&b'>')
    }

    /// After the parameter sigil, where the dialect has them, a variable named by one letter
    /// (`#T`, `#z`, `#[z]`): the letter's range, read past; none, with nothing read, else.
    pub(super) fn letter_variable(&mut self) -> Option<TextRange> {
        if !self.dialect.lexical.letter_variables {
            return None;
        }
        let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
        let is_letter = |j: usize| self.b.get(j).is_some_and(u8::is_ascii_alphabetic);
        let ends = |j: usize| !self.b.get(j).is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_');
        let at = self.i;
        if is_letter(at) && ends(at + 1) {
            self.i = at + 1;
            return Some(self.range(at, at + 1));
        }
        if self.b.get(at).copied() == expr_open && is_letter(at + 1) && self.b.get(at + 2).copied() == Some(self.expr_close()) {
            self.i = at + 3;
            return Some(self.range(at + 1, at + 2));
        }
        None
    }

    /// `<name>` after a sigil; returns the range of the name.
    pub(super) fn name(&mut self, start: usize) -> Option<TextRange> {
        self.i += 1; // '<'
        let from = self.i;
        let eol = self.line_end();
        match self.b[self.i..eol].iter().position(|&c| c == b'>') {
            Some(p) => {
                self.i += p + 1;
                Some(self.range(from, from + p))
            }
            None => {
                self.error(Code::MalformedExpression, start, eol, "parameter name is not closed with `>`");
                self.i = eol;
                None
            }
        }
    }
}

/// Nesting limit for brackets, against stack exhaustion on hostile input.
const MAX_DEPTH: u32 = 64;

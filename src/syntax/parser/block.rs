//! One block, mark by mark: the block skip, program delimiters and header lines, a leading
//! block number, then each word, comment, statement or assignment in turn up to the block's
//! end; comments (to their close, nested, continued) and continuation lines. Its door is
//! `Lexer::block`, which `Parser::next_block` calls when the fast path declines a block.

use super::super::{Block, Word, WordMode};
use super::Lexer;
use crate::diag::Code;
use crate::dialect::{CommentClose, Statement};

impl Lexer<'_, '_> {
    /// Lexes one block; returns the end of its text (before any terminator).
    pub(super) fn block(&mut self) -> usize {
        if self.block_head() {
            return self.i;
        }
        let lex = &self.dialect.lexical;
        loop {
            self.skip_blanks();
            let Some(c) = self.peek() else { break };
            if self.paren == Some(self.i) {
                self.close_paren();
                continue;
            }
            // In brackets, commas separate a call's arguments (`(PCALL 3, P0=1, P1=2)`).
            if c == b',' && self.paren.is_some() {
                self.i += 1;
                continue;
            }
            // Most words are a letter and a number; the dialect's index guarantees that no
            // other rule below claims a letter that has a plain role.
            if let Some(role) = self.dialect.plain_role(c)
                && self.plain_word(role)
            {
                continue;
            }
            if lex.continuation == Some(c as char) {
                // `~` continues the block on the next line.
                self.i += 1;
                self.skip_blanks();
                if !self.continue_line() && self.peek().is_some() {
                    self.error(Code::UnknownAddress, self.i - 1, self.i, "the continuation mark must end its line");
                }
                continue;
            }
            if c == b'\n' || c == b'\r' {
                break;
            }
            if lex.block_end == Some(c as char) {
                let end = self.i;
                return end;
            }
            self.item(c);
        }
        self.i
    }

    /// What may open a block: a block skip (`/`, `/2`), a program delimiter or header line
    /// (`%`, `%_N_PART_MPF`), a bare leading block number. True when the block is a delimiter
    /// line, read to its end.
    fn block_head(&mut self) -> bool {
        let lex = &self.dialect.lexical;
        self.skip_blanks();
        if let Some((skip, _)) = lex.block_skip
            && self.peek() == Some(skip as u8)
            && !lex.comments.iter().any(|r| r.open2.is_some() && r.opens(&self.b[self.i..]))
        {
            self.block.skip = true;
            self.i += 1;
            if lex.block_skip_levels && self.peek().is_some_and(|c| (b'0' + lex.block_skip_first_level..=b'9').contains(&c)) {
                self.i += 1; // `/2`: the second switch
            }
            self.skip_blanks();
        }
        if let Some(d) = lex.program_delimiter
            && self.peek() == Some(d as u8)
            && self.block.words.is_empty()
        {
            // A bare `%` (perhaps with a comment) opens or closes the program; `%_N_PART_MPF`
            // is a header line, skipped without ending anything.
            let end = self.line_end();
            let rest = self.text[self.i + 1..end].trim_start();
            self.block.delimiter = rest.is_empty() || lex.comments.iter().any(|r| r.opens(rest.as_bytes()));
            if lex.header_words && !self.block.delimiter {
                self.header_name();
            } else {
                self.i = end;
                return true;
            }
        }
        if lex.leading_block_number && self.peek().is_some_and(|c| c.is_ascii_digit()) {
            let start = self.i;
            if let Some(n) = self.integer(start) {
                self.block.number = Some(n);
            }
        }
        false
    }

    /// What `c` at the cursor starts, other than a plain word or the block's end, read past:
    /// a header's program name, a comment, a statement after its prefix, a parameter
    /// assignment, an address, a program number after its alternate mark, a symbol address;
    /// anything else is a finding.
    fn item(&mut self, c: u8) {
        let lex = &self.dialect.lexical;
        if lex.header_words && lex.program_delimiter == Some(c as char) && self.block.words.is_empty() && self.block.number.is_some() {
            // `N99999999 %123 G71 *`: the program's end names it again.
            self.header_name();
            return;
        }
        let at_start = |b: &Block| b.words.is_empty() && b.assigns.is_empty() && b.control.is_none();
        if c == b'(' && lex.paren_statements && at_start(self.block) && self.open_paren() {
            return;
        }
        if let Some(rule) = lex.comments.iter().find(|r| r.opens(&self.b[self.i..]) && (!r.block_start || at_start(self.block))) {
            let close = rule.close.clone();
            self.comment(&close);
            return;
        }
        // `@100 K-122`, `@136 R102 K2 K133`: a statement keyword written as a mark and digits
        // (the @ codes of the older SINUMERIK controls), where the dialect lists that keyword.
        if self.dialect.macros.marked_keywords && !c.is_ascii_alphanumeric() && c != b'_' && self.statement_at(self.i).is_some() {
            self.keyword_statement(self.i);
            return;
        }
        if lex.statement_prefix.contains(&c) && self.b.get(self.i + 1).is_some_and(u8::is_ascii_alphabetic) {
            // `#CALL L100`, `$IF P1 == 0`, `%L 100`: the mark says a statement follows.
            self.i += 1;
            self.keyword_statement(self.i);
            return;
        }
        if let Some((sigil, _)) = lex.parameter
            && c.eq_ignore_ascii_case(&(sigil as u8))
            && (!c.is_ascii_alphabetic() || self.b.get(self.i + 1).is_some_and(|n| n.is_ascii_digit() || Some(*n) == self.expr_open()))
        {
            self.assignment();
            return;
        }
        if let Some((_, len)) = self.global_bank()
            && self.b.get(self.i + len).is_some_and(|n| n.is_ascii_digit() || Some(*n) == self.expr_open())
        {
            self.assignment();
            return;
        }
        // `DECLARE STRING QS1 = "TEXT"`: words that declare the parameter, then its assignment.
        if let Some(at) = self.after_assignment_prefix() {
            self.i = at;
            self.assignment();
            return;
        }
        if self.at_define_name(self.i) {
            self.define_name_item();
            return;
        }
        if lex.text_arguments && lex.string_quote == Some(c as char) {
            // `G65 "\\cncm\\defines.cnc"`, `M200 "Install tool %.0f"`: the code's text argument.
            let start = self.i;
            let _ = self.string(start);
            return;
        }
        if lex.slash_arguments && c == b'/' && !self.block.words.is_empty() {
            // `M95 /1/2/19`, `M105/X2.0/Y3.0`, `M116/Z`: the code's arguments, a number, an
            // axis letter and the bound it moves to, or an axis letter alone.
            self.i += 1;
            self.skip_blanks();
            let letter = self.peek().is_some_and(|c| c.is_ascii_alphabetic());
            if letter {
                self.i += 1;
            }
            let operand = self.peek().is_some_and(|c| !c.is_ascii_whitespace() && c != b'/' && !c.is_ascii_alphabetic());
            if operand || !letter {
                let start = self.i;
                let _ = self.value(start);
            }
            return;
        }
        if c.is_ascii_alphabetic() || (c == b'_' && lex.identifier_variables) || self.at_system_variable(self.i) {
            self.address();
            return;
        }
        if lex.program_number_alt == Some(c as char) {
            let start = self.i;
            self.i += 1;
            if let Some(n) = self.integer(start) {
                self.block.program_number = Some(n);
            }
            return;
        }
        // `,R5` `,C2`: an address written as a comma and a letter.
        if c == b',' && self.long_address(self.i) {
            return;
        }
        if !self.symbol_address(c) {
            self.unexpected_characters();
        }
    }

    /// `<NAME>` where a block's item starts (Centroid CNC12, `DEFINE <NAME> text`): `<NAME> = expr`
    /// assigns what it names; a name alone stands for a text (a statement such as `IF #50001`),
    /// not known here: skipped with a warning.
    /// Where the parameter starts after words that declare it (Heidenhain `DECLARE STRING
    /// QS1 = "TEXT"`, TNC 640 user's manual, "String functions": DECLARE STRING assigns a text
    /// to a QS parameter): the dictionary's words, blanks between them, then a parameter.
    fn after_assignment_prefix(&self) -> Option<usize> {
        let blanks = |mut j: usize| {
            while matches!(self.b.get(j), Some(b' ' | b'\t')) {
                j += 1;
            }
            j
        };
        self.dialect.lexical.assignment_prefixes.iter().find_map(|prefix| {
            let mut j = self.i;
            for (n, word) in prefix.split_ascii_whitespace().enumerate() {
                if n > 0 {
                    let k = blanks(j);
                    if k == j {
                        return None;
                    }
                    j = k;
                }
                let end = j + word.len();
                if !self.b.get(j..end).is_some_and(|w| w.eq_ignore_ascii_case(word.as_bytes())) {
                    return None;
                }
                j = end;
            }
            let at = blanks(j);
            if at == j {
                return None;
            }
            let sigil = self.dialect.lexical.parameter.map(|(s, _)| s.to_ascii_uppercase() as u8);
            let numbered = self.b.get(at).map(u8::to_ascii_uppercase) == sigil && self.b.get(at + 1).is_some_and(u8::is_ascii_digit);
            (numbered || self.parameter_bank_at(at).is_some()).then_some(at)
        })
    }

    fn define_name_item(&mut self) {
        let start = self.i;
        let Some(name) = self.name(start) else { return };
        self.skip_blanks();
        if self.peek() == Some(b'=') && self.b.get(self.i + 1) != Some(&b'=') {
            self.i += 1;
            let Some(value) = self.expr(1, 0) else {
                self.i = self.line_end();
                return;
            };
            self.block.assigns.push(super::super::Assign {
                target: super::super::ParamTarget::Named(name),
                value,
                range: self.range(start, self.i),
            });
            return;
        }
        let d = crate::diag::Diagnostic::new(
            Code::Unsupported,
            self.range(start, self.i),
            "a name `DEFINE` gave stands for a statement here: its text is not known, the rest of the block is skipped",
        );
        self.diags.push(d);
        self.i = self.line_end();
    }

    /// `(` opening a statement in brackets (`(P100 = 5)`, `(IF P1 EQ 0 GOTO N10)`, `(RET)`):
    /// a statement keyword of the dialect or a parameter assignment after it, and its `)`
    /// closing the line. Steps into the brackets and notes where they close; false (nothing
    /// read) for any other bracket, a comment.
    fn open_paren(&mut self) -> bool {
        let end = {
            let rest = &self.b[self.i..];
            self.i + rest.iter().position(|&c| c == b'\n' || c == b'\r').unwrap_or(rest.len())
        };
        let mut j = self.i + 1;
        while matches!(self.b.get(j), Some(b' ' | b'\t')) {
            j += 1;
        }
        let statement = self.statement_at(j).is_some();
        let assignment = self.dialect.lexical.parameter.is_some_and(|(sigil, _)| {
            let mut k = j;
            if !self.b.get(k).is_some_and(|c| c.eq_ignore_ascii_case(&(sigil as u8))) {
                return false;
            }
            k += 1;
            let digits = k;
            while self.b.get(k).is_some_and(u8::is_ascii_digit) {
                k += 1;
            }
            while matches!(self.b.get(k), Some(b' ' | b'\t')) {
                k += 1;
            }
            k > digits && self.b.get(k) == Some(&b'=') && self.b.get(k + 1) != Some(&b'=')
        });
        // The last `)` of the line closes the brackets (an expression may hold others).
        let Some(close) = self.b[j..end].iter().rposition(|&c| c == b')').map(|p| j + p) else { return false };
        if !(statement || assignment) {
            return false;
        }
        self.i = j;
        self.paren = Some(close);
        if statement {
            self.keyword_statement(j);
        } else {
            self.assignment();
        }
        true
    }

    /// Past the `)` that closes a statement in brackets. What follows an unsupported or
    /// inert statement on its line belongs to it (`(RPT N10, N20) N3`: the count).
    fn close_paren(&mut self) {
        self.i += 1;
        self.paren = None;
        let plain =
            self.block.control.as_ref().and_then(|c| c.statement).is_some_and(|s| matches!(s, Statement::Unsupported | Statement::Inert));
        if plain {
            self.i = self.line_end();
        }
    }

    /// A symbol address (`@-.0025 ^4.5`): punctuation the dialect gives a role.
    fn symbol_address(&mut self, c: u8) -> bool {
        let start = self.i;
        let Some(role) = self.dialect.letter_role(c).filter(|_| c.is_ascii_punctuation()) else { return false };
        self.i += 1;
        if let Some(value) = self.value(start) {
            let range = self.range(start, self.i);
            self.block.words.push(Word { role, letter: c, value, range, mode: WordMode::Modal, cycle_arg: false });
        }
        true
    }

    /// A finding for a character that starts nothing, read past. Digits, signs, points and
    /// brackets right after it are the same slip (a value with no address, `M202(0.0024)`):
    /// one finding for the run.
    fn unexpected_characters(&mut self) {
        let start = self.i;
        let mut end = start + self.char_len(start);
        while self.text.as_bytes().get(end).is_some_and(|b| b"0123456789.+-()".contains(b)) {
            end += 1;
        }
        let shown = &self.text[start..end];
        let what = if shown.chars().count() > 1 { "characters" } else { "character" };
        self.error(Code::UnknownAddress, start, end, format!("unexpected {what} `{shown}`"));
        self.i = end;
    }

    /// After a continuation mark: steps over the line end. False when the line does not end here.
    pub(super) fn continue_line(&mut self) -> bool {
        match self.peek() {
            Some(b'\r') => {
                self.i += 1;
                if self.peek() == Some(b'\n') {
                    self.i += 1;
                }
            }
            Some(b'\n') => self.i += 1,
            _ => return false,
        }
        self.block.extra_lines += 1;
        true
    }

    /// Continued comment lines: each is comment text up to a closing `~` or the line end.
    fn comment_lines(&mut self) {
        let Some(k) = self.dialect.lexical.continuation.map(|k| k as u8) else { return };
        loop {
            let from = self.i;
            let eol = self.line_end();
            let text = &self.b[from..eol];
            let trimmed = text.len() - text.iter().rev().take_while(|c| matches!(c, b' ' | b'\t')).count();
            let cont = trimmed > 0 && text[trimmed - 1] == k;
            self.block.comments.push(self.range(from, if cont { from + trimmed - 1 } else { eol }));
            self.i = eol;
            if !cont || !self.continue_line() {
                return;
            }
        }
    }

    pub(super) fn comment(&mut self, close: &CommentClose) {
        let open = self.i;
        // A two-character opener (`//`) is read past whole.
        let len = self.dialect.lexical.comments.iter().find(|r| r.open2.is_some() && r.opens(&self.b[open..])).map_or(1, |r| r.open_len());
        self.i += len;
        let eol = self.line_end();
        match close {
            CommentClose::EndOfLine => {
                // A comment that ends with the continuation mark continues the block (`Q200=2 ;CLEARANCE ~`).
                let text = &self.b[open + len..eol];
                let trimmed = text.len() - text.iter().rev().take_while(|c| matches!(c, b' ' | b'\t')).count();
                let cont = self.dialect.lexical.continuation.is_some_and(|k| trimmed > 0 && text[trimmed - 1] == k as u8);
                let end = if cont { open + len - 1 + trimmed } else { eol };
                self.block.comments.push(self.range(open + len, end));
                self.i = eol;
                if cont {
                    self.continue_line();
                    // A block that is only a comment continues as comment text (`;long text~`).
                    let only_comment = self.block.words.is_empty() && self.block.assigns.is_empty() && self.block.control.is_none();
                    if only_comment {
                        self.comment_lines();
                    }
                }
            }
            CommentClose::Char(c) => {
                let rest = &self.b[self.i..eol];
                let opener = self.b[open];
                // A teaching simulator's command (`($SetPartSize(42, 12, 2, 1))`) runs to its
                // matching close, past quoted text, as the simulator reads it.
                let simulator = self.simulator_directive(rest);
                let nested = simulator || self.dialect.lexical.comments.iter().any(|r| r.open as u8 == opener && r.nested);
                let (mut depth, mut quoted) = (0u32, false);
                let mut closing = |x: u8| {
                    if simulator && x == b'"' {
                        quoted = !quoted;
                    } else if quoted {
                    } else if nested && x == opener && x != *c as u8 {
                        depth += 1;
                    } else if x == *c as u8 {
                        if depth == 0 {
                            return true;
                        }
                        depth -= 1;
                    }
                    false
                };
                let found = rest.iter().position(|&x| closing(x));
                if simulator
                    && let Some(p) = found
                    && rest[..p].iter().position(|&x| x == *c as u8).is_some_and(|first| first < p)
                {
                    self.error(
                        Code::SimulatorDirective,
                        open,
                        self.i + p + 1,
                        format!("a teaching simulator's command, read to its matching `{c}` as the simulator reads it; a control ends the comment at its first `{c}` and reads the rest as words"),
                    );
                }
                // Where the control stops at an opening character inside a comment (rs274ngc).
                if let Some(p) = found
                    && !simulator
                    && self.dialect.lexical.comments.iter().any(|r| r.open as u8 == opener && r.nested_error)
                    && let Some(q) = rest[..p].iter().position(|&x| x == opener)
                {
                    let at = self.i + q;
                    self.error(
                        Code::NestedComment,
                        at,
                        at + 1,
                        format!("a `{}` inside a comment: comments may not be nested, and the control stops here", opener as char),
                    );
                }
                match found {
                    Some(p) => {
                        self.block.comments.push(self.range(self.i, self.i + p));
                        self.i += p + 1;
                    }
                    None => self.unclosed_comment(open, eol, &c.to_string()),
                }
            }
            CommentClose::Pair(a, b) => {
                // `/* ... */` (LNC): the comment ends at the first `*/`; what follows on the
                // line is read as the block's words.
                let rest = &self.b[self.i..eol];
                match rest.windows(2).position(|w| w[0] == *a as u8 && w[1] == *b as u8) {
                    Some(p) => {
                        self.block.comments.push(self.range(self.i, self.i + p));
                        self.i += p + 2;
                    }
                    None => self.unclosed_comment(open, eol, &format!("{a}{b}")),
                }
            }
        }
    }

    /// Whether the comment text `rest` (after its opener) starts with a teaching simulator's
    /// command prefix from the dictionary (`$`).
    /// A comment opened at `open` that its line ends without `close`: the rest of the line
    /// is the comment, and an error says so.
    fn unclosed_comment(&mut self, open: usize, eol: usize, close: &str) {
        self.block.comments.push(self.range(self.i, eol));
        self.error(Code::UnterminatedComment, open, eol, format!("comment is not closed with `{close}` before the end of the line"));
        self.i = eol;
    }

    fn simulator_directive(&self, rest: &[u8]) -> bool {
        let start = rest.iter().position(|c| !matches!(c, b' ' | b'\t')).unwrap_or(rest.len());
        let t = &rest[start..];
        self.dialect.lexical.directives.iter().any(|(prefix, d)| {
            *d == crate::dialect::Directive::Simulator
                && t.len() >= prefix.len()
                && t[..prefix.len()].eq_ignore_ascii_case(prefix.as_bytes())
        })
    }

    /// Past a header's `%` and the program name after it (`%123`, `% 123`), where the dialect
    /// reads the words after the name (`G71`).
    fn header_name(&mut self) {
        self.i += 1;
        self.skip_blanks();
        while self.peek().is_some_and(|c| c.is_ascii_alphanumeric() || c == b'_') {
            self.i += 1;
        }
    }
}

//! The streaming block parser.

use super::expr::{BinOp, Expr, ExprId, Func};
use super::{Assign, Block, CaseBranch, Control, ParamTarget, Value, Word, WordMode};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CommentClose, Dialect, KeywordRest, Role, SkipPosition, Statement};
use crate::text::{Text, TextRange};

/// Nesting limit for brackets, against stack exhaustion on hostile input.
const MAX_DEPTH: u32 = 64;

/// The tape leader the dialect skips: the text before the first line that is only the
/// program delimiter (`%`) with program text after it, when there is text before it (an NX
/// listing header, a title), and the 1-based line the program starts on.
pub fn leader<'t>(text: impl Into<Text<'t>>, dialect: &Dialect) -> Option<(TextRange, u32)> {
    let d = dialect.lexical.program_delimiter.filter(|_| dialect.lexical.leader_skipped)?;
    let text = text.into();
    let head = text.head();
    let blank = |s: &str| s.chars().all(|c| c.is_whitespace() || c == '\u{feff}' || c == d);
    let mut at = 0;
    for (n, line) in head.split_inclusive('\n').enumerate() {
        let t = line.trim().trim_start_matches('\u{feff}');
        if t.len() == d.len_utf8() && t.starts_with(d) {
            let before = &head[..at];
            let after = at + line.len();
            // Program text after the line: in the head, or else anywhere after it.
            let text_after = !blank(&head[after..]) || (head.len() < text.len() && !rest_blank(text, head.len(), &blank));
            return (!blank(before) && text_after).then(|| (TextRange::new(0, at), n as u32 + 1));
        }
        at += line.len();
    }
    None
}

/// Whether the text from `from` on is all `blank`, read piece by piece.
fn rest_blank(text: Text<'_>, mut from: usize, blank: &dyn Fn(&str) -> bool) -> bool {
    while from < text.len() {
        let piece = text.piece(from, 64 * 1024);
        if piece.is_empty() {
            return true;
        }
        if !blank(&piece) {
            return false;
        }
        from += piece.len();
    }
    true
}

/// A cursor over a program text that yields one block at a time.
///
/// A text read piece by piece ([`Text::Read`]) is lexed in a window that holds the text from
/// the current block on: refilled as the cursor passes its end, grown when a block runs past
/// it (a block is lexed again, whole, from a larger window), and read again from the file
/// after a seek outside it. Ranges and lines are those of the whole text either way.
pub struct Parser<'a> {
    text: Text<'a>,
    /// The window of a read text: its text from `base` on.
    win: String,
    base: usize,
    /// How much the next refill reads: doubling up to the reader's window.
    span: usize,
    /// Where the text ends (or where it could no longer be read).
    end: usize,
    pos: usize,
    line: u32,
    dialect: &'a Dialect,
    /// The role of each byte that starts a plain word (`X1.5`), in either case: see
    /// [`Dialect::plain_role`].
    plain: [Option<Role>; 256],
    /// The block-number letter where a block number needs no general rule
    /// ([`plain_block_number`]).
    number: Option<u8>,
    /// Whether blocks of plain words take the fast path ([`plain_block`]).
    fast: bool,
    /// The record reader's state, where the dialect's programs are records (CLDATA).
    records: Option<Box<super::records::RecordState>>,
}

impl<'a> Parser<'a> {
    /// A parser at the start of `text` (after its tape leader, where the dialect skips one).
    pub fn new(text: impl Into<Text<'a>>, dialect: &'a Dialect) -> Parser<'a> {
        let text = text.into();
        let (pos, line) = leader(text, dialect).map_or((0, 1), |(r, line)| (r.end as usize, line));
        Parser::at(text, dialect, pos, line)
    }

    /// A parser at `offset` (a block start seen before) on 1-based `line`.
    pub fn at(text: impl Into<Text<'a>>, dialect: &'a Dialect, offset: usize, line: u32) -> Parser<'a> {
        let text = text.into();
        let records = dialect.records.as_ref().map(|_| Box::default());
        let end = text.len();
        let mut plain = [None; 256];
        for c in 0..128u8 {
            plain[c as usize] = dialect.plain_role(c);
        }
        let number = plain_block_number(dialect);
        Parser { text, win: String::new(), base: 0, span: 0, end, pos: offset.min(end), line, dialect, plain, number, fast: true, records }
    }

    /// A parser of `text` at `offset` on `line` in this one's dialect, with its fast path
    /// setting, without working out again what the dialect's letters are (a look-ahead made
    /// many times costs little).
    pub fn fork(&self, text: impl Into<Text<'a>>, offset: usize, line: u32) -> Parser<'a> {
        let text = text.into();
        let end = text.len();
        Parser {
            text,
            win: String::new(),
            base: 0,
            span: 0,
            end,
            pos: offset.min(end),
            line,
            dialect: self.dialect,
            plain: self.plain,
            number: self.number,
            fast: self.fast,
            records: self.dialect.records.as_ref().map(|_| Box::default()),
        }
    }

    /// The byte offset of the next block.
    pub fn offset(&self) -> usize {
        self.pos
    }

    /// The 1-based line of the next block.
    pub fn line(&self) -> u32 {
        self.line
    }

    /// The text the parser reads.
    pub fn text(&self) -> Text<'a> {
        self.text
    }

    /// Turns the fast path for blocks of plain words on or off (on by default); off, every
    /// block goes the general way, which gives the same blocks and findings.
    pub fn set_fast_path(&mut self, on: bool) {
        self.fast = on;
    }

    /// Moves the cursor to `offset` (a block start previously seen) on 1-based `line`. Outside
    /// the window of a read text, the next refill reads little and grows again as reading goes
    /// on: a jump to a subprogram and back costs a few kilobytes, not two windows.
    pub fn seek(&mut self, offset: usize, line: u32) {
        self.pos = offset.min(self.end);
        self.line = line;
        if self.outside() {
            self.span = 0;
        }
    }

    /// The window and the offset of its first byte.
    fn window(&self) -> (&str, usize) {
        match self.text {
            Text::Whole(s) => (s, 0),
            Text::Read(_) => (&self.win, self.base),
        }
    }

    /// Makes the window of a read text start at the cursor; with `more`, hold more than it
    /// does. False when it holds no more than before.
    fn fill(&mut self, more: bool) -> bool {
        let Text::Read(r) = self.text else { return false };
        if (self.base..=self.base + self.win.len()).contains(&self.pos) {
            self.win.drain(..self.pos - self.base);
        } else {
            self.win.clear();
        }
        self.base = self.pos;
        let held = self.win.len();
        let max = r.window().max(1);
        self.span = if self.span == 0 { max.min(4096) } else { self.span.saturating_mul(2).min(max) };
        if more {
            self.span = self.span.max(held.saturating_mul(2)).max(held + 1);
        }
        while self.win.len() < self.span && self.base + self.win.len() < self.end {
            let at = self.base + self.win.len();
            let before = self.win.len();
            let start = r.read(at, self.span - before, &mut self.win);
            if self.win.len() == before || start != at {
                // The text could not be read on (the shell reports why): it ends here.
                self.win.truncate(before);
                self.end = at;
            }
        }
        self.win.len() > held
    }

    /// Whether the window of a read text lacks the cursor's text.
    fn outside(&self) -> bool {
        matches!(self.text, Text::Read(_)) && (self.pos < self.base || self.pos >= self.base + self.win.len())
    }

    /// Reads the next block into `block`. Returns false at the end of the text.
    pub fn next_block(&mut self, block: &mut Block, diags: &mut Vec<Diagnostic>) -> bool {
        if self.records.is_some() {
            return self.next_record(block, diags);
        }
        loop {
            if self.pos >= self.end {
                return false;
            }
            if self.outside() {
                self.fill(false);
                continue;
            }
            let mark = diags.len();
            let dialect = self.dialect;
            let (win, base) = self.window();
            let bytes = win.as_bytes();
            block.clear();
            block.line = self.line;
            let start = self.pos - base;
            let plain = if self.fast { plain_block(&self.plain, self.number, dialect, bytes, start, base, block) } else { None };
            let (end, mut i) = match plain {
                Some(end) => (end, end),
                None => {
                    block.clear();
                    block.line = self.line;
                    let mut lx = Lexer { text: win, b: bytes, i: start, base, dialect, block, diags };
                    let end = lx.block();
                    (end, lx.i)
                }
            };
            let mut lines = block.extra_lines;
            match bytes.get(i) {
                Some(b'\r') => {
                    i += 1;
                    if bytes.get(i) == Some(&b'\n') {
                        i += 1;
                    }
                    lines += 1;
                }
                Some(b'\n') => {
                    i += 1;
                    lines += 1;
                }
                Some(_) => i += 1, // the end-of-block character
                None => {}
            }
            // A block that reached the window's end may go on past it: lexed again from more.
            if i >= bytes.len() && base + bytes.len() < self.end {
                diags.truncate(mark);
                if !self.fill(true) {
                    self.end = self.base + self.win.len();
                }
                continue;
            }
            block.range = TextRange::new(base + start, base + end);
            block.set_source(&win[start..end.max(start)]);
            self.line += lines;
            self.pos = base + i;
            return true;
        }
    }

    /// Reads the lines of plain words from the cursor on, each wholly in the window (see
    /// [`plain_block`]), into `line` one by one, and hands each to `run`. It moves past each
    /// line `run` takes (true), and stops at the first it turns down, at the first other block
    /// (which [`Parser::next_block`] reads as a [`Block`]), or after `max` lines; the number
    /// taken. A line's words, range and line are those `next_block` would give; its block
    /// number is not kept.
    ///
    /// Reading plain lines never moves the window, so it is looked up once for them all.
    pub fn plain_lines(&mut self, line: &mut PlainLine, max: u64, mut run: impl FnMut(&PlainLine) -> bool) -> u64 {
        if !self.fast || self.records.is_some() || self.outside() {
            return 0;
        }
        let (win, base) = self.window();
        let bytes = win.as_bytes();
        let (mut pos, mut number, mut taken) = (self.pos, self.line, 0);
        while taken < max && pos < self.end {
            let Some((next, lines)) = self.plain_at(bytes, base, pos, line) else { break };
            line.line = number;
            if !run(line) {
                break;
            }
            (pos, number, taken) = (next, number + lines, taken + 1);
        }
        (self.pos, self.line) = (pos, number);
        taken
    }

    /// The line of plain words at `pos`, in the window `bytes` that starts at `base`, into
    /// `line` (all but its line number); where the next block starts, and the lines to it.
    #[inline(always)]
    fn plain_at(&self, bytes: &[u8], base: usize, pos: usize, line: &mut PlainLine) -> Option<(usize, u32)> {
        let start = pos - base;
        line.len = 0;
        let end = plain_block(&self.plain, self.number, self.dialect, bytes, start, base, line)?;
        let (next, lines) = match bytes.get(end) {
            Some(b'\r') if bytes.get(end + 1) == Some(&b'\n') => (end + 2, 1),
            Some(b'\r' | b'\n') => (end + 1, 1),
            _ => return None,
        };
        // A line that ends at the window's end may go on past it: read the general way.
        if next >= bytes.len() && base + bytes.len() < self.end {
            return None;
        }
        line.range = TextRange::new(base + start, base + end);
        Some((base + next, lines))
    }

    /// The next record of a record-form text (CLDATA).
    fn next_record(&mut self, block: &mut Block, diags: &mut Vec<Diagnostic>) -> bool {
        let dialect = self.dialect;
        let Some(recs) = dialect.records.as_deref() else { return false };
        if self.records.as_deref().is_some_and(|st| !st.started()) {
            let head = self.text.head();
            if let Some(st) = self.records.as_deref_mut() {
                st.start(&head, recs, dialect, diags);
            }
        }
        loop {
            let Some(st) = self.records.as_deref_mut() else { return false };
            if self.pos >= self.end {
                super::records::finish(st, recs, diags);
                return false;
            }
            if self.outside() {
                self.fill(false);
                continue;
            }
            let (win, base) = match self.text {
                Text::Whole(s) => (s, 0),
                Text::Read(_) => (self.win.as_str(), self.base),
            };
            let Some(st) = self.records.as_deref_mut() else { return false };
            let (next, line) = super::records::gather(st, recs, win, base, self.pos, self.line, block);
            if next - base >= win.len() && base + win.len() < self.end {
                if !self.fill(true) {
                    self.end = self.base + self.win.len();
                }
                continue;
            }
            block.set_source(&win[block.range.start as usize - base..block.range.end as usize - base]);
            (self.pos, self.line) = (next, line);
            super::records::finish_record(st, recs, dialect, block, diags);
            return true;
        }
    }
}

/// The block-number letter (`N`) when `N` and digits can only be a block number in `d`, as
/// [`Dialect::plain_role`] tells plain words: no label, variable, keyword, cycle, long address,
/// axis setting, call by name or lexer mark can start with the letter.
fn plain_block_number(d: &Dialect) -> Option<u8> {
    let lex = &d.lexical;
    let n = lex.block_number.filter(char::is_ascii_uppercase)?;
    let starts = |s: &str| s.chars().next().is_some_and(|c| c.eq_ignore_ascii_case(&n));
    let marks = [
        lex.continuation,
        lex.block_end,
        lex.program_delimiter,
        lex.block_skip.map(|(k, _)| k),
        lex.control_word,
        lex.program_number,
        lex.program_number_alt,
        lex.system_variable_prefix,
        lex.parameter.map(|(s, _)| s),
    ];
    let mark = marks.iter().flatten().any(|c| c.eq_ignore_ascii_case(&n))
        || lex.statement_prefix.iter().any(|c| c.eq_ignore_ascii_case(&(n as u8)))
        || lex.comments.iter().any(|r| r.open.eq_ignore_ascii_case(&n));
    let named = d.codes.iter().filter_map(|k| k.keyword.as_ref()).any(|k| starts(&k.text))
        || d.cycles.iter().any(|c| starts(&c.name))
        || d.addresses.iter().any(|a| a.name.len() > 1 && starts(&a.name))
        || lex.axis_indexed.iter().any(|a| starts(&a.name));
    let call = d.macros.call_by_name && d.letter_role(n as u8).is_none();
    (lex.label_suffix.is_none() && !lex.identifier_variables && !mark && !named && !call).then_some(n as u8)
}

/// The common block, plain words only (`X1.5 Y-2 Z0.25`), perhaps after a block number
/// (`N120`, where `number` is the letter), read in one tight loop: its words into `block` and
/// where its text ends (at its line end), as the general lexer reads them; `None` at anything
/// else (a comment, an expression, a named code, a malformed number: the general lexer reads
/// the block again from its start).
#[inline(always)]
fn plain_block(
    plain: &[Option<Role>; 256],
    number: Option<u8>,
    dialect: &Dialect,
    b: &[u8],
    start: usize,
    base: usize,
    out: &mut impl PlainWords,
) -> Option<usize> {
    let blanks = |mut i: usize| {
        while let Some(b' ' | b'\t' | 0x0c) = b.get(i) {
            i += 1;
        }
        i
    };
    let mut i = blanks(start);
    if let Some(n) = number
        && b.get(i).is_some_and(|c| c.to_ascii_uppercase() == n)
        && b.get(i + 1).is_some_and(u8::is_ascii_digit)
    {
        // `N120`: up to nine digits, no point, not followed by a block skip.
        let mut j = i + 1;
        let mut v = 0u32;
        while let Some(&c) = b.get(j).filter(|c| c.is_ascii_digit())
            && j - i <= 9
        {
            v = v * 10 + u32::from(c - b'0');
            j += 1;
        }
        if matches!(b.get(j), Some(b'0'..=b'9' | b'.')) {
            return None;
        }
        if let Some((skip, SkipPosition::LineStartOrAfterNumber)) = dialect.lexical.block_skip
            && b.get(blanks(j)) == Some(&(skip as u8))
        {
            return None;
        }
        out.number(v);
        i = j;
    }
    loop {
        let Some(&c) = b.get(i) else { return Some(i) };
        let Some(role) = plain[c as usize] else {
            // A blank between words (the one test most bytes that are no letter take).
            if matches!(c, b' ' | b'\t' | 0x0c) {
                i += 1;
                continue;
            }
            return matches!(c, b'\n' | b'\r').then_some(i);
        };
        let sign = b.get(i + 1).copied().unwrap_or(0);
        let negative = sign == b'-';
        let signed = negative || sign == b'+';
        // Blanks inside a number (`X1 5`, where the dialect allows them) need not be looked for
        // here: a digit after blanks is no plain word, and the general lexer reads the block.
        let (v, end, decimal) = plain_number(b, i + 1 + usize::from(signed), false)?;
        // The sign as its bit: `-v` for the magnitude `v`, without a branch.
        let value = f64::from_bits(v.to_bits() | u64::from(negative) << 63);
        // `G200 DRILLING`: a code the dictionary names in the block after it.
        if matches!(role, Role::G | Role::M)
            && (0.0..10_000.0).contains(&value)
            && dialect.code(c.to_ascii_uppercase() as char, (value * 10.0).round() as u32).is_some_and(|c| c.named)
        {
            return None;
        }
        if !out.word(role, c.to_ascii_uppercase(), value, decimal, TextRange::new(base + i, base + end)) {
            return None;
        }
        // The one blank that parts most words, passed here rather than round the loop.
        i = end + usize::from(b.get(end) == Some(&b' '));
    }
}

/// Where [`plain_block`] puts what it reads.
trait PlainWords {
    /// The block number.
    fn number(&mut self, n: u32);
    /// A word; false when it cannot be taken (the block then goes the general way).
    fn word(&mut self, role: Role, letter: u8, value: f64, decimal: bool, range: TextRange) -> bool;
}

impl PlainWords for Block {
    #[inline(always)]
    fn number(&mut self, n: u32) {
        self.number = Some(n);
    }

    #[inline(always)]
    fn word(&mut self, role: Role, letter: u8, value: f64, decimal: bool, range: TextRange) -> bool {
        self.words.push(Word { role, letter, value: Value::Number { value, decimal }, range, mode: WordMode::Modal, cycle_arg: false });
        true
    }
}

impl PlainWords for PlainLine {
    #[inline(always)]
    fn number(&mut self, _: u32) {}

    #[inline(always)]
    fn word(&mut self, role: Role, _: u8, value: f64, decimal: bool, _: TextRange) -> bool {
        let Some(w) = self.words.get_mut(self.len) else { return false };
        *w = PlainWord { role, value, decimal };
        self.len += 1;
        true
    }
}

/// A line of plain words read by [`Parser::plain_lines`] without a [`Block`]: the block that
/// makes up most of a CAM program (`X12.5 Y-3.2 Z-1.05`), for the interpreter's plain lane.
#[derive(Clone, Debug)]
pub struct PlainLine {
    words: [PlainWord; PLAIN_WORDS],
    len: usize,
    /// Source range of the block, without its line terminator.
    pub range: TextRange,
    /// 1-based line of the block.
    pub line: u32,
}

/// The most words a [`PlainLine`] holds; a longer block goes the general way.
const PLAIN_WORDS: usize = 8;

/// One word of a [`PlainLine`]: a letter with a literal number.
#[derive(Clone, Copy, Debug)]
pub struct PlainWord {
    /// What the value means to the engine.
    pub role: Role,
    /// The number as written.
    pub value: f64,
    /// Whether it was written with a decimal point.
    pub decimal: bool,
}

impl Default for PlainLine {
    fn default() -> PlainLine {
        let w = PlainWord { role: Role::X, value: 0.0, decimal: false };
        PlainLine { words: [w; PLAIN_WORDS], len: 0, range: TextRange::default(), line: 0 }
    }
}

impl PlainLine {
    /// The words in source order.
    pub fn words(&self) -> &[PlainWord] {
        &self.words[..self.len]
    }
}

struct Lexer<'t, 'b> {
    /// The window: the text from `base` on. Indices are into it; ranges add `base`.
    text: &'t str,
    b: &'t [u8],
    i: usize,
    base: usize,
    dialect: &'t Dialect,
    block: &'b mut Block,
    diags: &'b mut Vec<Diagnostic>,
}

impl Lexer<'_, '_> {
    /// The range of `start..end` in the window, in the whole text.
    fn range(&self, start: usize, end: usize) -> TextRange {
        TextRange::new(self.base + start, self.base + end)
    }

    /// A range in the window (see [`Lexer::alpha_run`]) as a range in the whole text.
    fn abs(&self, r: TextRange) -> TextRange {
        self.range(r.start as usize, r.end as usize)
    }

    fn peek(&self) -> Option<u8> {
        self.b.get(self.i).copied()
    }

    fn skip_blanks(&mut self) {
        while matches!(self.peek(), Some(b' ' | b'\t' | 0x0c)) {
            self.i += 1;
        }
    }

    /// Records a finding. Its range is widened to whole characters, so that a range
    /// computed in bytes never splits a multi-byte character.
    fn error(&mut self, code: Code, start: usize, end: usize, msg: impl Into<String>) {
        let mut start = start.min(self.text.len());
        while !self.text.is_char_boundary(start) {
            start -= 1;
        }
        let mut end = end.clamp(start, self.text.len());
        while !self.text.is_char_boundary(end) {
            end += 1;
        }
        self.diags.push(Diagnostic::new(code, self.range(start, end), msg));
    }

    /// Index of the end of the physical line from `i`.
    fn line_end(&self) -> usize {
        let rest = &self.b[self.i..];
        self.i + rest.iter().position(|&c| c == b'\n' || c == b'\r').unwrap_or(rest.len())
    }

    fn char_len(&self, at: usize) -> usize {
        self.text[at..].chars().next().map_or(1, char::len_utf8)
    }

    /// Lexes one block; returns the end of its text (before any terminator).
    fn block(&mut self) -> usize {
        let lex = &self.dialect.lexical;
        self.skip_blanks();
        if let Some((skip, _)) = lex.block_skip
            && self.peek() == Some(skip as u8)
        {
            self.block.skip = true;
            self.i += 1;
            if lex.block_skip_levels && self.peek().is_some_and(|c| matches!(c, b'1'..=b'9')) {
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
            self.block.delimiter = rest.is_empty() || lex.comments.iter().any(|r| rest.starts_with(r.open));
            if lex.header_words && !self.block.delimiter {
                self.header_name();
            } else {
                self.i = end;
                return self.i;
            }
        }
        if lex.leading_block_number && self.peek().is_some_and(|c| c.is_ascii_digit()) {
            let start = self.i;
            if let Some(n) = self.integer(start) {
                self.block.number = Some(n);
            }
        }
        loop {
            self.skip_blanks();
            let Some(c) = self.peek() else { break };
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
            if lex.header_words && lex.program_delimiter == Some(c as char) && self.block.words.is_empty() && self.block.number.is_some() {
                // `N99999999 %123 G71 *`: the program's end names it again.
                self.header_name();
                continue;
            }
            let at_start = |b: &Block| b.words.is_empty() && b.assigns.is_empty() && b.control.is_none();
            if let Some(rule) = lex.comments.iter().find(|r| r.open as u8 == c && (!r.block_start || at_start(self.block))) {
                let close = rule.close.clone();
                self.comment(&close);
                continue;
            }
            if lex.statement_prefix.contains(&c) && self.b.get(self.i + 1).is_some_and(u8::is_ascii_alphabetic) {
                // `#CALL L100`, `$IF P1 == 0`, `%L 100`: the mark says a statement follows.
                self.i += 1;
                self.keyword_statement(self.i);
                continue;
            }
            if let Some((sigil, _)) = lex.parameter
                && c.eq_ignore_ascii_case(&(sigil as u8))
                && (!c.is_ascii_alphabetic() || self.b.get(self.i + 1).is_some_and(|n| n.is_ascii_digit() || Some(*n) == self.expr_open()))
            {
                self.assignment();
                continue;
            }
            if c.is_ascii_alphabetic() || (c == b'_' && lex.identifier_variables) || self.at_system_variable(self.i) {
                self.address();
                continue;
            }
            if lex.program_number_alt == Some(c as char) {
                let start = self.i;
                self.i += 1;
                if let Some(n) = self.integer(start) {
                    self.block.program_number = Some(n);
                }
                continue;
            }
            let start = self.i;
            if let Some(role) = self.dialect.letter_role(c).filter(|_| c.is_ascii_punctuation()) {
                // A symbol address (`@-.0025 ^4.5`).
                self.i += 1;
                if let Some(value) = self.value(start) {
                    let range = self.range(start, self.i);
                    self.block.words.push(Word { role, letter: c, value, range, mode: WordMode::Modal, cycle_arg: false });
                }
                continue;
            }
            // Digits, signs, points and brackets right after it are the same slip (a value
            // with no address, `M202(0.0024)`): one finding for the run.
            let mut end = start + self.char_len(start);
            while self.text.as_bytes().get(end).is_some_and(|b| b"0123456789.+-()".contains(b)) {
                end += 1;
            }
            let shown = &self.text[start..end];
            let what = if shown.chars().count() > 1 { "characters" } else { "character" };
            self.error(Code::UnknownAddress, start, end, format!("unexpected {what} `{shown}`"));
            self.i = end;
        }
        self.i
    }

    /// After a continuation mark: steps over the line end. False when the line does not end here.
    fn continue_line(&mut self) -> bool {
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

    fn expr_open(&self) -> Option<u8> {
        self.dialect.lexical.expression.map(|(o, _)| o as u8)
    }

    fn comment(&mut self, close: &CommentClose) {
        let open = self.i;
        self.i += 1;
        let eol = self.line_end();
        match close {
            CommentClose::EndOfLine => {
                // A comment that ends with the continuation mark continues the block (`Q200=2 ;CLEARANCE ~`).
                let text = &self.b[open + 1..eol];
                let trimmed = text.len() - text.iter().rev().take_while(|c| matches!(c, b' ' | b'\t')).count();
                let cont = self.dialect.lexical.continuation.is_some_and(|k| trimmed > 0 && text[trimmed - 1] == k as u8);
                let end = if cont { open + trimmed } else { eol };
                self.block.comments.push(self.range(open + 1, end));
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
                match found {
                    Some(p) => {
                        self.block.comments.push(self.range(self.i, self.i + p));
                        self.i += p + 1;
                    }
                    None => {
                        self.block.comments.push(self.range(self.i, eol));
                        self.error(
                            Code::UnterminatedComment,
                            open,
                            eol,
                            format!("comment is not closed with `{c}` before the end of the line"),
                        );
                        self.i = eol;
                    }
                }
            }
        }
    }

    /// Whether the comment text `rest` (after its opener) starts with a teaching simulator's
    /// command prefix from the dictionary (`$`).
    fn simulator_directive(&self, rest: &[u8]) -> bool {
        let start = rest.iter().position(|c| !matches!(c, b' ' | b'\t')).unwrap_or(rest.len());
        let t = &rest[start..];
        self.dialect.lexical.directives.iter().any(|(prefix, d)| {
            *d == crate::dialect::Directive::Simulator
                && t.len() >= prefix.len()
                && t[..prefix.len()].eq_ignore_ascii_case(prefix.as_bytes())
        })
    }

    /// The lexer's fast path: `X10.5`, `Y-.25`, a plain address with a literal number. False,
    /// with nothing consumed, when the word is anything else.
    #[inline]
    fn plain_word(&mut self, role: Role) -> bool {
        let start = self.i;
        let b = self.b;
        let signed = matches!(b.get(start + 1), Some(b'-' | b'+'));
        let spaces = self.dialect.lexical.spaces_in_numbers;
        // The common case in one pass; anything unusual goes through `number`, which also
        // reports what is wrong with it.
        let (value, decimal) = match plain_number(b, start + 1 + usize::from(signed), spaces) {
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

    fn address(&mut self) {
        let start = self.i;
        let lex = &self.dialect.lexical;
        if let Some(suffix) = lex.label_suffix {
            let end = self.b[start..].iter().position(|x| !(x.is_ascii_alphanumeric() || *x == b'_')).map_or(self.b.len(), |p| start + p);
            if self.b.get(end) == Some(&(suffix as u8)) && end - start >= 2 && self.block.label.is_none() && self.block.words.is_empty() {
                self.block.label = Some(self.range(start, end));
                self.i = end + 1;
                return;
            }
        }
        // A named block (`NLOOP G0 X1`) or program (`OTBOX`) at block start.
        let at_start = self.block.words.is_empty() && self.block.label.is_none() && self.block.control.is_none();
        if at_start && self.b.get(start + 1).is_some_and(u8::is_ascii_alphabetic) {
            let letter = Some(self.b[start].to_ascii_uppercase() as char);
            let end = self.identifier_end(start);
            // `NLAB=1` assigns a variable of that name instead.
            let assigned = self.b[end..].iter().find(|c| !matches!(c, b' ' | b'\t')) == Some(&b'=');
            if lex.named_blocks && letter == lex.block_number && !assigned {
                self.block.label = Some(self.range(start, end));
                self.i = end;
                return;
            }
            if lex.named_programs && letter == lex.program_number && self.block.assigns.is_empty() && !assigned {
                self.block.program_name = Some(self.range(start, end));
                self.i = end;
                return;
            }
        }
        if self.axis_indexed() || self.keyword() || self.cycle_call() || self.variable_assignment() {
            return;
        }
        // Multi-letter addresses such as `CR=` (longest first).
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
                    let (role, letter) = (a.role, a.name.as_bytes()[0]);
                    let mode = if a.incremental { WordMode::Incremental } else { WordMode::Modal };
                    let value = if a.assign { self.assigned_value(start) } else { self.value(start).map(|v| (v, WordMode::Modal)) };
                    if let Some((value, wrapped)) = value {
                        let m = if wrapped == WordMode::Modal { mode } else { wrapped };
                        self.block.words.push(Word { role, letter, value, range: self.range(start, self.i), mode: m, cycle_arg: false });
                    }
                    return;
                }
            }
        }
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
        if (next.is_some_and(|x| x.is_ascii_alphabetic()) && !param_value) || named_call {
            self.keyword_statement(start);
            return;
        }
        self.i += 1;
        if lex.block_number == Some(letter as char) {
            if let Some(n) = self.integer(start) {
                self.block.number = Some(n);
            }
            if let Some((skip, SkipPosition::LineStartOrAfterNumber)) = lex.block_skip {
                self.skip_blanks();
                if self.peek() == Some(skip as u8) {
                    self.block.skip = true;
                    self.i += 1;
                    if lex.block_skip_levels && self.peek().is_some_and(|c| matches!(c, b'1'..=b'9')) {
                        self.i += 1;
                    }
                }
            }
            return;
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
        let assigned = lex.assign_values && {
            let j = self.b[self.i..].iter().position(|c| !matches!(c, b' ' | b'\t')).map_or(self.b.len(), |p| self.i + p);
            let eq = self.b.get(j) == Some(&b'=');
            if eq {
                self.i = j + 1;
            }
            eq
        };
        let value = if assigned { self.assigned_value(start) } else { self.value(start).map(|v| (v, WordMode::Modal)) };
        if let Some((value, mode)) = value {
            // A letter that is always incremental (a lathe's `U`) marks its words so.
            let mode = if mode == WordMode::Modal && self.dialect.letter_incremental(letter) { WordMode::Incremental } else { mode };
            self.block.words.push(Word { role, letter, value, range: self.range(start, self.i), mode, cycle_arg: false });
        }
    }

    /// A value after `=`: a string, `AC(..)`/`IC(..)`, or an infix expression (`X=R1*2`);
    /// with the measure an `AC`/`IC` wrapper gives it (else modal).
    fn assigned_value(&mut self, start: usize) -> Option<(Value, WordMode)> {
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
                super::expr::BinOp::named(&self.text[j..end].to_ascii_uppercase()).is_some()
            };
        if operator { None } else { n }
    }

    /// A quoted string at the cursor; the range inside the quotes.
    fn string(&mut self, start: usize) -> Option<TextRange> {
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

    /// A keyword code at the cursor (`TRANS`, `TOOL CALL 5`, `DR+`), longest first. Blanks in
    /// a keyword match any run of blanks; the keyword must end at a word boundary.
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
        // The spindle's number in brackets: there is one spindle in the toolpath.
        if let Some((open, close)) = self.dialect.lexical.array_brackets
            && self.b.get(j) == Some(&open)
        {
            match self.b[j..].iter().position(|&c| c == close || c == b'\n') {
                Some(p) if self.b[j + p] == close => j = skip(self.b, j + p + 1),
                _ => return false,
            }
        }
        if self.b.get(j) != Some(&b'=') || self.b.get(j + 1) == Some(&b'=') {
            return false;
        }
        let letter = self.push_keyword(start, end, idx);
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

    fn keyword(&mut self) -> bool {
        if self.dialect.keyword_codes().next().is_none() {
            return false;
        }
        let start = self.i;
        let mut found = None;
        for (idx, k) in self.dialect.keyword_codes() {
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
            KeywordRest::Line => self.i = self.line_end(),
            KeywordRest::Words => {
                let named = self.display_name();
                if named && value_role.is_some() {
                    self.value_after_name();
                }
            }
        }
        true
    }

    /// The value after a numbered code's display name (`CYCL DEF 1.1 SET UP .1181`,
    /// `1.2 DEPTH -15`): a bare number, sign optional, the last word of the line. A legacy
    /// cycle's sub-block number says which argument it is.
    fn value_after_name(&mut self) {
        let vstart = self.i;
        if !self.bare_number_ends_line(vstart) {
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

    /// Whether a bare number (`5`, `-15`, `.1181`, `+0.5`) starts at `at` and only blanks
    /// follow it on the line.
    fn bare_number_ends_line(&self, at: usize) -> bool {
        let eol = self.b[at..].iter().position(|&c| c == b'\n' || c == b'\r').map_or(self.b.len(), |p| at + p);
        // Up to a comment at the end of the block (`1.2 DEPTH -15 ; hole`).
        let comments = &self.dialect.lexical.comments;
        let end = (at..eol).find(|&p| comments.iter().any(|r| self.b[p] == r.open as u8)).unwrap_or(eol);
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
    fn display_name(&mut self) -> bool {
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

    /// Past a header's `%` and the program name after it (`%123`, `% 123`), where the dialect
    /// reads the words after the name (`G71`).
    fn header_name(&mut self) {
        self.i += 1;
        self.skip_blanks();
        while self.peek().is_some_and(|c| c.is_ascii_alphanumeric() || c == b'_') {
            self.i += 1;
        }
    }

    /// The end of an identifier (letters, digits, `_`) starting at `at`.
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

    /// A system variable's name includes its prefix and a constant index (`$AC_TIME`,
    /// `$A_IN[1]`, `$TC_DP1[1,2]`): the control's data is unknown here whatever the index.
    fn identifier_end(&self, at: usize) -> usize {
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
    fn array_index(&mut self, depth: u32) -> Option<Option<ExprId>> {
        let (open, close) = self.dialect.lexical.array_brackets?;
        if self.peek() != Some(open) {
            return None;
        }
        let at = self.i;
        self.i += 1;
        let Some(e) = self.expr(depth + 1, 0) else { return Some(None) };
        self.skip_blanks();
        if self.peek() != Some(close) {
            let end = self.i.max(at + 1);
            self.error(Code::MalformedExpression, at, end, format!("an array element's index is closed with `{}`", close as char));
            return Some(None);
        }
        self.i += 1;
        Some(Some(e))
    }

    /// Whether a system variable's name starts at `at` (`$AC_TIME`).
    fn at_system_variable(&self, at: usize) -> bool {
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
            index = self.unary(1);
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
    fn cycle_call(&mut self) -> bool {
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

    /// An alphabetic run at the cursor, as a range in the window (not the whole text).
    fn alpha_run(&self) -> TextRange {
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
    fn control_word(&mut self, start: usize) {
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
        self.block.control = Some(control);
    }

    /// `IF [#1 GT 0] GOTO 10`, `WHILE [#2 LT 5] DO 1`, `END 1`, `GOTO #3`, `CALL LBL 1 REP 2`:
    /// a statement that starts with a keyword. Where the dialect calls programs by name, an
    /// unknown name is such a call (`DRILLING`, `L123 P2`, `MYPROC(1.5, 3)`). Any other run of
    /// letters is kept as an unknown statement, so that the interpreter can name it.
    fn keyword_statement(&mut self, start: usize) {
        let known = if self.dialect.lexical.control_word.is_none() { self.statement_at(start) } else { None };
        let mut control = Control::default();
        match known {
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
                        let stops = |c: char| lex.block_end == Some(c) || (plain && lex.comments.iter().any(|r| r.open == c));
                        self.i = self.text[self.i..end].find(stops).map_or(end, |p| self.i + p);
                    }
                    _ => self.operands(&mut control),
                }
            }
            None if self.dialect.macros.call_by_name && self.call_by_name(start, &mut control) => {}
            None => {
                let end = self.line_end();
                let lex = &self.dialect.lexical;
                let end = self.text[start..end].find(|c| lex.block_end == Some(c)).map_or(end, |p| start + p);
                control.keyword = Some(self.abs(self.alpha_run()));
                self.i = end;
            }
        }
        control.range = self.range(start, self.i);
        self.block.control = Some(control);
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
    fn statement_at(&self, at: usize) -> Option<(usize, Statement)> {
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
        match self.peek() {
            None | Some(b'\r' | b'\n') => true,
            Some(c) => self.dialect.lexical.block_end == Some(c as char) || self.dialect.lexical.comments.iter().any(|r| r.open as u8 == c),
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
            while self.peek().is_some_and(|c| !matches!(c, b' ' | b'\t' | b'\r' | b'\n')) && !self.at_block_end() {
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
        let Some(st) = control.statement else { return };
        self.skip_blanks();
        if matches!(st, Statement::Do | Statement::EndDo) {
            if starts_operand(self.peek(), sigil) {
                control.target = self.unary(1);
                return;
            }
        } else if matches!(st, Statement::RepeatSection | Statement::RepeatBlock) {
            self.repeat_section(control);
            return;
        } else if st == Statement::Case {
            self.case_branches(control);
            return;
        } else if takes_target(st) {
            if self.dialect.lexical.control_word.is_none() {
                self.target(control);
                if matches!(st, Statement::CallLabel | Statement::CallProgram) {
                    self.call_repeat(control);
                }
            } else if starts_operand(self.peek(), sigil) {
                control.target = self.unary(1);
            }
            return;
        }
        if st == Statement::For {
            self.for_head(control);
            return;
        }
        let condition = matches!(st, Statement::If | Statement::ElseIf | Statement::While | Statement::Until);
        if condition && self.dialect.macros.bare_conditions {
            if !self.at_block_end() {
                match self.expr(1, 0) {
                    Some(e) => control.args.push(e),
                    None => return,
                }
            }
        } else {
            loop {
                self.skip_blanks();
                // Comments may sit between operands: `o<x> call [1] (note) [2]`.
                while let Some(rule) = self.peek().and_then(|c| self.dialect.lexical.comments.iter().find(|r| r.open as u8 == c)) {
                    let close = rule.close.clone();
                    self.comment(&close);
                    self.skip_blanks();
                }
                if self.peek().is_none() || self.peek() != expr_open {
                    break;
                }
                match self.unary(1) {
                    Some(e) => control.args.push(e),
                    None => return,
                }
            }
        }
        self.skip_blanks();
        if self.dialect.lexical.control_word.is_some() || !self.peek().is_some_and(|c| c.is_ascii_alphabetic()) {
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
        }
    }

    fn integer(&mut self, start: usize) -> Option<u32> {
        self.skip_blanks();
        let from = self.i;
        while self.peek().is_some_and(|c| c.is_ascii_digit()) {
            self.i += 1;
        }
        if self.peek() == Some(b'.') {
            self.i += 1;
            while self.peek().is_some_and(|c| c.is_ascii_digit()) {
                self.i += 1;
            }
        }
        let digits = &self.text[from..self.i];
        let int = digits.split('.').next().unwrap_or("");
        match int.parse::<u32>() {
            Ok(n) => Some(n),
            Err(_) => {
                let what = self.text[start..start + 1].to_owned();
                self.error(Code::MalformedNumber, start, self.i.max(start + 1), format!("`{what}` needs a whole number"));
                None
            }
        }
    }

    /// Reads a word value after its address.
    fn value(&mut self, start: usize) -> Option<Value> {
        self.skip_blanks();
        let Some(c) = self.peek() else {
            self.error(Code::MissingValue, start, self.i, format!("`{}` has no value", &self.text[start..self.i].trim()));
            return None;
        };
        let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
        let sigil = self.dialect.lexical.parameter.map(|(s, _)| s as u8);
        // After a sign, blanks may stand before the operand where the dialect allows blanks in numbers (`Z + Q13`).
        let after_sign = if matches!(c, b'+' | b'-') && self.dialect.lexical.spaces_in_numbers {
            self.b[self.i + 1..].iter().position(|c| !matches!(c, b' ' | b'\t')).map_or(self.b.len(), |p| self.i + 1 + p)
        } else {
            self.i + 1
        };
        let sign_then_expr = matches!(c, b'+' | b'-')
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
        if Some(c) == expr_open || Some(c) == sigil || sign_then_expr || is_func || radix {
            return self.unary(0).map(Value::Expr);
        }
        self.error(Code::MissingValue, start, self.i, format!("`{}` has no value", self.text[start..self.i].trim()));
        None
    }

    /// Reads a literal number: sign, digits, at most one point; returns it and whether a
    /// decimal point was written.
    fn number(&mut self) -> Option<(f64, bool)> {
        let start = self.i;
        let spaces = self.dialect.lexical.spaces_in_numbers;
        let mut negative = false;
        if let Some(s @ (b'+' | b'-')) = self.peek() {
            negative = s == b'-';
            self.i += 1;
            if spaces {
                self.skip_blanks();
            }
        }
        let (mut mantissa, mut digits, mut frac, mut point, mut exact) = (0u64, 0u32, 0u32, false, true);
        // Fast path: plain digits, at most one point, up to 18 digits, then a byte that ends
        // the number. Anything else (blanks inside the number, a second point, long runs)
        // goes through the general loop below from the same position.
        if let Some((v, end, pt)) = plain_number(self.b, self.i, spaces) {
            self.i = end;
            let v = if self.dialect.lexical.numbers.exponent.is_some() { self.exponent(start, v)? } else { v };
            return Some((if negative { -v } else { v }, pt));
        }
        loop {
            match self.peek() {
                Some(d @ b'0'..=b'9') => {
                    if digits < 19 {
                        mantissa = mantissa * 10 + u64::from(d - b'0');
                        if point {
                            frac += 1;
                        }
                    } else {
                        exact = false;
                    }
                    digits += 1;
                    self.i += 1;
                }
                Some(b'.') if !point => {
                    point = true;
                    self.i += 1;
                }
                Some(b'.') => {
                    let s = self.i;
                    while matches!(self.peek(), Some(b'0'..=b'9' | b'.')) {
                        self.i += 1;
                    }
                    self.error(
                        Code::MalformedNumber,
                        start,
                        self.i,
                        format!("`{}` has more than one decimal point", &self.text[start..self.i]),
                    );
                    let _ = s;
                    return None;
                }
                Some(b' ' | b'\t') if spaces => {
                    let mut j = self.i;
                    while matches!(self.b.get(j), Some(b' ' | b'\t')) {
                        j += 1;
                    }
                    if matches!(self.b.get(j), Some(b'0'..=b'9' | b'.')) && digits > 0 && !self.b[j..].starts_with(b"..") {
                        self.i = j;
                    } else {
                        break;
                    }
                }
                _ => break,
            }
        }
        if digits == 0 {
            self.error(
                Code::MalformedNumber,
                start,
                self.i.max(start + 1),
                format!("`{}` is not a number", self.text[start..self.i.max(start + 1).min(self.b.len())].trim()),
            );
            return None;
        }
        let v = if exact && mantissa < (1 << 53) && frac <= 22 {
            mantissa as f64 / POW10[frac as usize]
        } else {
            let s: String = self.text[start..self.i].chars().filter(|c| c.is_ascii_digit() || *c == '.').collect();
            s.parse::<f64>().unwrap_or(0.0)
        };
        let v = if self.dialect.lexical.numbers.exponent.is_some() { self.exponent(start, v)? } else { v };
        Some((if negative { -v } else { v }, point))
    }

    /// A decimal exponent after the digits of the number that starts at `start` and has
    /// (unsigned) value `v`: `10EX3`, `.5EX-2`. Returns the scaled value. The digits are read
    /// again as text, so that `1EX-3` is exactly the double nearest to 0.001.
    fn exponent(&mut self, start: usize, v: f64) -> Option<f64> {
        let marker = self.dialect.lexical.numbers.exponent.as_deref().unwrap_or_default();
        let at = self.i;
        let rest = &self.b[at..];
        if marker.is_empty() || rest.len() < marker.len() || !rest[..marker.len()].eq_ignore_ascii_case(marker.as_bytes()) {
            return Some(v);
        }
        let mut j = at + marker.len();
        let sign_at = j;
        if matches!(self.b.get(j), Some(b'+' | b'-')) {
            j += 1;
        }
        let digits_at = j;
        while self.b.get(j).is_some_and(u8::is_ascii_digit) {
            j += 1;
        }
        if j == digits_at {
            self.error(
                Code::MalformedNumber,
                start,
                j.max(at + marker.len()),
                format!("`{}` needs the digits of its exponent after `{marker}`", &self.text[start..j]),
            );
            self.i = j;
            return None;
        }
        self.i = j;
        let mantissa: String = self.text[start..at].chars().filter(|c| c.is_ascii_digit() || *c == '.').collect();
        let text = format!("{mantissa}e{}", &self.text[sign_at..j]);
        match text.parse::<f64>() {
            Ok(x) if x.is_finite() => Some(x),
            _ => {
                self.error(Code::MalformedNumber, start, j, format!("`{}` is too large", &self.text[start..j]));
                None
            }
        }
    }

    /// A constant in another base, at the opening quote: `'H1F'` (hexadecimal), `'B101'`
    /// (binary).
    fn radix_constant(&mut self, quote: u8, hex: u8, binary: u8) -> Option<f64> {
        let start = self.i;
        let base = match self.b.get(start + 1).map(u8::to_ascii_uppercase) {
            Some(c) if c == hex => 16,
            Some(c) if c == binary => 2,
            _ => {
                let end = (start + 1 + self.char_len(start + 1).min(self.b.len() - start - 1)).min(self.b.len());
                self.error(Code::MalformedNumber, start, end, "a quoted constant names its base first: `'H1F'` or `'B101'`");
                self.i = self.line_end();
                return None;
            }
        };
        let eol = self.line_end();
        let Some(close) = self.b[start + 2..eol].iter().position(|&c| c == quote).map(|p| start + 2 + p) else {
            self.error(Code::MalformedNumber, start, eol, "the quoted constant is not closed");
            self.i = eol;
            return None;
        };
        self.i = close + 1;
        let digits = &self.text[start + 2..close];
        match u64::from_str_radix(digits, base) {
            Ok(v) if !digits.starts_with(['+', '-']) => Some(v as f64),
            _ => {
                let kind = if base == 16 { "hexadecimal" } else { "binary" };
                self.error(Code::MalformedNumber, start, self.i, format!("`{}` is not a {kind} number", &self.text[start..self.i]));
                None
            }
        }
    }

    fn push(&mut self, e: Expr) -> ExprId {
        self.block.exprs.push(e);
        (self.block.exprs.len() - 1) as ExprId
    }

    fn expect(&mut self, c: u8, what: &str, start: usize) -> bool {
        self.skip_blanks();
        if self.peek() == Some(c) {
            self.i += 1;
            true
        } else {
            let end = self.i.max(start + 1).min(self.b.len());
            self.error(Code::MalformedExpression, start, end, format!("expected `{}` {what}", c as char));
            false
        }
    }

    /// A full expression with binary operators, by precedence climbing.
    fn expr(&mut self, depth: u32, min_prec: u8) -> Option<ExprId> {
        let mut lhs = self.unary(depth)?;
        loop {
            self.skip_blanks();
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
            b'/' => BinOp::Div,
            b'+' => BinOp::Add,
            b'-' => BinOp::Sub,
            b'=' | b'<' | b'>' if self.dialect.lexical.symbolic_comparisons => {
                let next = self.b.get(self.i + 1).copied();
                let (op, len) = match (c, next) {
                    (b'=', Some(b'=')) => (BinOp::Eq, 2),
                    (b'<', Some(b'>')) => (BinOp::Ne, 2),
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
                let op = BinOp::named(&word)?;
                self.i = end;
                return Some(op);
            }
            _ => return None,
        };
        self.i += 1;
        Some(op)
    }

    /// A signed operand: number, bracketed expression, parameter or function call.
    fn unary(&mut self, depth: u32) -> Option<ExprId> {
        let start = self.i;
        if depth > MAX_DEPTH {
            self.error(Code::MalformedExpression, start, start + 1, "expression is nested too deeply");
            self.i = self.line_end();
            return None;
        }
        self.skip_blanks();
        let expr_open = self.dialect.lexical.expression.map(|(o, _)| o as u8);
        let expr_close = self.dialect.lexical.expression.map(|(_, c)| c as u8);
        let sigil = self.dialect.lexical.parameter.map(|(s, _)| s as u8);
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
            c if Some(c) == expr_open => {
                self.i += 1;
                let e = self.expr(depth + 1, 0)?;
                if !self.expect(expr_close.unwrap_or(b']'), "to close the expression", start) {
                    return None;
                }
                Some(e)
            }
            c if Some(c.to_ascii_uppercase()) == sigil
                && (!c.is_ascii_alphabetic() || self.b.get(self.i + 1).is_some_and(|n| n.is_ascii_digit() || Some(*n) == expr_open)) =>
            {
                self.i += 1;
                self.skip_blanks();
                if self.peek() == Some(b'<') && self.dialect.lexical.parameter.is_some_and(|(_, named)| named) {
                    let name = self.name(start)?;
                    return Some(self.push(Expr::Named(name)));
                }
                let inner = self.unary(depth + 1)?;
                Some(self.push(Expr::Param(inner)))
            }
            c if self.dialect.lexical.identifier_variables
                && (c.is_ascii_alphabetic() || c == b'_' || self.at_system_variable(self.i))
                && {
                    let end = self.identifier_end(self.i);
                    Func::named(&self.text[self.i..end].to_ascii_uppercase()).is_none()
                        || self.b[end..].iter().find(|x| !matches!(x, b' ' | b'\t')).is_none_or(|x| Some(*x) != expr_open)
                } =>
            {
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
                    return Some(self.push(Expr::Num(super::axis_value(letter))));
                }
                self.i = end;
                if self.peek().is_some() && self.peek() == expr_open {
                    // `VTOFD[1]`: an element of a named array.
                    let index = self.unary(depth + 1)?;
                    return Some(self.push(Expr::NamedIndex(r, index)));
                }
                if let Some(index) = self.array_index(depth) {
                    return Some(self.push(Expr::NamedIndex(r, index?)));
                }
                Some(self.push(Expr::Named(r)))
            }
            c if c.is_ascii_alphabetic() => {
                let end = self.b[self.i..].iter().position(|x| !x.is_ascii_alphabetic()).map_or(self.b.len(), |p| self.i + p);
                let word = self.text[self.i..end].to_ascii_uppercase();
                let Some(func) = Func::named(&word) else {
                    self.error(Code::MalformedExpression, start, end, format!("unknown function `{word}`"));
                    self.i = end;
                    return None;
                };
                self.i = end;
                self.skip_blanks();
                if func == Func::Exists {
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
                    if !self.expect(expr_close.unwrap_or(b']'), "to close EXISTS", start) {
                        return None;
                    }
                    return Some(self.push(Expr::Unary(Func::Exists, n)));
                }
                if self.peek() != expr_open {
                    if self.dialect.lexical.bare_function_arguments && self.peek().is_some() {
                        // `SIN +Q1`, `SQRT 25`: the operand follows without brackets.
                        let inner = self.unary(depth + 1)?;
                        return Some(self.push(Expr::Unary(func, inner)));
                    }
                    self.error(Code::MalformedExpression, start, self.i, format!("`{word}` needs its argument in brackets"));
                    return None;
                }
                if matches!(func, Func::Atan | Func::Pow) && self.has_comma_before_close() {
                    // Two arguments in one bracket: `ATAN[y,x]`, `POW[a,b]` (Fanuc 30i).
                    self.i += 1;
                    let a = self.expr(depth + 1, 0)?;
                    if !self.expect(b',', "between the two arguments", start) {
                        return None;
                    }
                    let b = self.expr(depth + 1, 0)?;
                    if !self.expect(expr_close.unwrap_or(b']'), "to close the arguments", start) {
                        return None;
                    }
                    let e = if func == Func::Atan { Expr::Atan2(a, b) } else { Expr::Binary(BinOp::Pow, a, b) };
                    return Some(self.push(e));
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
            _ => {
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
        }
    }

    /// Whether the bracket at the cursor holds a comma at its own nesting level.
    fn has_comma_before_close(&self) -> bool {
        let mut depth = 0u32;
        for &c in &self.b[self.i..self.line_end()] {
            match c {
                b'[' => depth += 1,
                b']' => {
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

    /// `<name>` after a sigil; returns the range of the name.
    fn name(&mut self, start: usize) -> Option<TextRange> {
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

    fn assignment(&mut self) {
        let start = self.i;
        self.i += 1;
        self.skip_blanks();
        let target = if self.peek() == Some(b'<') && self.dialect.lexical.parameter.is_some_and(|(_, n)| n) {
            match self.name(start) {
                Some(r) => ParamTarget::Named(r),
                None => return,
            }
        } else {
            match self.unary(1) {
                Some(e) => ParamTarget::Numbered(e),
                None => {
                    self.i = self.line_end();
                    return;
                }
            }
        };
        self.skip_blanks();
        if self.peek() != Some(b'=') {
            // A parameter read without assignment is meaningless in a block.
            self.error(Code::MalformedExpression, start, self.i.max(start + 1), "a parameter here must be assigned with `=`");
            return;
        }
        self.i += 1;
        let Some(value) = self.expr(1, 0) else {
            self.i = self.line_end();
            return;
        };
        self.block.assigns.push(Assign { target, value, range: self.range(start, self.i) });
    }
}

/// Reads the digits from `*j` on into `m` (ten times `m` plus each digit, wrapping past 19
/// digits) and steps past them.
#[inline(always)]
fn digits(b: &[u8], j: &mut usize, m: &mut u64) {
    let (mut v, mut k) = (*m, *j);
    for &c in b.get(k..).unwrap_or_default() {
        let d = c.wrapping_sub(b'0');
        if d > 9 {
            break;
        }
        v = v.wrapping_mul(10).wrapping_add(u64::from(d));
        k += 1;
    }
    (*m, *j) = (v, k);
}

/// The top bit of every byte of `x` (a word of bytes less `0`) that is no digit: 10 and up
/// with 0x76 added, or wrapped round below zero. Only the lowest such byte is exact: a borrow
/// or carry goes to the bytes after it.
#[inline(always)]
fn not_digits(x: u64) -> u64 {
    (x.wrapping_add(0x7676_7676_7676_7676) | x) & 0x8080_8080_8080_8080
}

/// The number eight digit values (0 to 9, one a byte, the first at the lowest address) spell:
/// pairs of bytes into two-digit numbers, pairs of those into four-digit ones, and the two
/// halves into one; no lane overflows into the next.
#[inline(always)]
fn eight_digits(d: u64) -> u64 {
    let d = (d.wrapping_mul(10).wrapping_add(d >> 8)) & 0x00FF_00FF_00FF_00FF;
    let d = (d.wrapping_mul(100).wrapping_add(d >> 16)) & 0x0000_FFFF_0000_FFFF;
    (d.wrapping_mul(10_000).wrapping_add(d >> 32)) & 0xFFFF_FFFF
}

/// A number that ends, with at most one point, within the eight bytes from `i` (`0.9950`,
/// `-222.899` after its sign, `1500`), read from one word: its mantissa, digits before and
/// after the point, whether it has one, and its end. `None` for any other (longer, or no
/// digit), which the byte-by-byte way reads.
#[inline(always)]
fn short_number(b: &[u8], i: usize) -> Option<(u64, usize, usize, bool, usize)> {
    const ZEROS: u64 = 0x3030_3030_3030_3030;
    let w = u64::from_le_bytes(*b.get(i..)?.first_chunk::<8>()?);
    let x = w.wrapping_sub(ZEROS);
    let at = (not_digits(x).trailing_zeros() / 8) as usize;
    if at == 8 {
        return None;
    }
    if (w >> (8 * at)) as u8 != b'.' {
        // Digits only: they sit at the top of the word, zeros (leading zeros) below.
        return (at > 0).then(|| (eight_digits(x << (8 * (8 - at))), at, 0, false, i + at));
    }
    // The point as a `0` (no carry: `.` is two below it), so the digits after it read on;
    // then the bytes above it moved down one, over it.
    let x = (w + (2 << (8 * at))).wrapping_sub(ZEROS);
    let end = (not_digits(x).trailing_zeros() / 8) as usize;
    let n = end - 1;
    if end == 8 || n == 0 {
        return None;
    }
    let below = (1u64 << (8 * at)) - 1;
    let d = (x & below) | ((x >> 8) & !below);
    Some((eight_digits(d << (8 * (8 - n))), at, n - at, true, i + end))
}

/// A number of plain digits with at most one point, at most 18 digits, and a byte after it
/// that cannot continue it: its value, end and whether it has a point. `None` sends the
/// caller to the general path.
///
/// The digits before and after the point make one mantissa below 2^53, exactly a double,
/// divided by a power of ten up to 10^18, also exact: the one rounding of the division gives
/// the double nearest to the decimal, as `str::parse` does.
#[inline(always)]
fn plain_number(b: &[u8], i: usize, spaces: bool) -> Option<(f64, usize, bool)> {
    // A short number has one to seven digits: its mantissa is exact.
    let (m, n_frac, point, end) = match short_number(b, i) {
        Some((m, _, n_frac, point, end)) => (m, n_frac, point, end),
        None => {
            let mut end = i;
            let mut m = 0u64;
            digits(b, &mut end, &mut m);
            let n_int = end - i;
            let point = b.get(end) == Some(&b'.');
            let mut n_frac = 0;
            if point {
                end += 1;
                digits(b, &mut end, &mut m);
                n_frac = end - i - n_int - 1;
            }
            // Past 2^53 the mantissa is no longer exact as a float; the general path parses it.
            if n_int + n_frac == 0 || n_int + n_frac > 18 || m >= 1 << 53 {
                return None;
            }
            (m, n_frac, point, end)
        }
    };
    match b.get(end) {
        Some(b'.') => return None,
        Some(b' ' | b'\t') if spaces => {
            // `X1 5` is X15 where blanks may sit inside numbers.
            let j = b[end..].iter().position(|&c| c != b' ' && c != b'\t').map_or(b.len(), |p| end + p);
            if matches!(b.get(j), Some(b'0'..=b'9' | b'.')) {
                return None;
            }
        }
        _ => {}
    }
    Some((m as f64 / POW10[n_frac], end, point))
}

const POW10: [f64; 23] =
    [1e0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15, 1e16, 1e17, 1e18, 1e19, 1e20, 1e21, 1e22];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dialect::Registry;

    /// The decimal `int.frac` as `str::parse` reads it (an empty side is a zero).
    fn parsed(int: &str, frac: Option<&str>) -> f64 {
        let int = if int.is_empty() { "0" } else { int };
        match frac {
            Some(f) => format!("{int}.{f}0").parse().unwrap(),
            None => int.parse().unwrap(),
        }
    }

    #[test]
    fn the_plain_block_path_takes_numbered_blocks_of_plain_words() {
        let registry = Registry::shipped();
        for name in ["fanuc", "linuxcnc", "haas", "mazak"] {
            let d = registry.get(name).unwrap();
            let p = Parser::new("", &d);
            let text = b"N9920X-222.899Y96.966 Z.5\nG1";
            let mut block = Block::default();
            assert_eq!(plain_block(&p.plain, p.number, &d, text, 0, 0, &mut block), Some(25), "{name}");
            assert_eq!((block.number, block.words.len()), (Some(9920), 3), "{name}");
            // A comment, an expression: the general lexer's.
            for other in [&b"N10 X1 (HOLE)\n"[..], b"X[1+2]\n", b"G1 X#1\n"] {
                assert_eq!(plain_block(&p.plain, p.number, &d, other, 0, 0, &mut Block::default()), None, "{name}");
            }
        }
    }

    #[test]
    fn short_numbers_read_from_one_word_as_byte_by_byte() {
        // Byte by byte, as `plain_number` reads a number that does not fit in a word.
        let slow = |b: &[u8], i: usize| {
            let (mut end, mut m) = (i, 0u64);
            digits(b, &mut end, &mut m);
            let n_int = end - i;
            let point = b.get(end) == Some(&b'.');
            if point {
                end += 1;
                digits(b, &mut end, &mut m);
            }
            (m, n_int, end - i - n_int - usize::from(point), point, end)
        };
        let stops = ["", "/", ":", ".", "..", " ", "X", "\n", "\u{e9}", "\u{ff}", "-", "+"];
        let mut read = 0;
        for int in 0..9 {
            for frac in [None, Some(0), Some(1), Some(3), Some(4), Some(6), Some(7), Some(8)] {
                for stop in stops {
                    for from in 0..3 {
                        let digit = |k: usize| char::from(b'0' + ((k * 7 + int) % 10) as u8);
                        let mut text: String = "X9."[..from].into();
                        text.extend((0..int).map(digit));
                        if let Some(f) = frac {
                            text.push('.');
                            text.extend((0..f).map(|k| digit(k + 3)));
                        }
                        text.push_str(stop);
                        text.push_str("Y-1.25 Z0.5");
                        let b = text.as_bytes();
                        if let Some(n) = short_number(b, from) {
                            assert_eq!(n, slow(b, from), "{text:?} from {from}");
                            read += 1;
                        } else {
                            // Only what does not fit, or holds no digit, is left to the bytes.
                            let (_, n_int, n_frac, point, end) = slow(b, from);
                            assert!(end - from >= 8 || n_int + n_frac == 0, "{text:?} from {from}: {point}");
                        }
                    }
                }
            }
        }
        assert!(read > 900, "{read}");
    }

    proptest::proptest! {
        /// The fast path gives the very double `str::parse` gives, or declines.
        #[test]
        fn plain_numbers_are_the_doubles_parse_gives(
            int in "[0-9]{0,20}",
            frac in proptest::option::of("[0-9]{0,20}"),
            after in "[ \n\tXY;)(]",
            spaces: bool,
        ) {
            let text = format!("{int}{}{after}", frac.as_ref().map_or(String::new(), |f| format!(".{f}")));
            let digits = int.len() + frac.as_ref().map_or(0, String::len);
            match plain_number(text.as_bytes(), 0, spaces) {
                Some((v, end, point)) => {
                    proptest::prop_assert_eq!(v.to_bits(), parsed(&int, frac.as_deref()).to_bits(), "{}", text);
                    proptest::prop_assert_eq!(end, text.len() - 1);
                    proptest::prop_assert_eq!(point, frac.is_some());
                }
                None => proptest::prop_assert!(digits == 0 || digits > 15, "{} declined", text),
            }
        }

        /// Blocks of plain words (perhaps numbered) read by the fast path are the blocks, with
        /// the findings, the general lexer reads, in every dialect.
        #[test]
        fn the_plain_block_path_reads_what_the_general_lexer_reads(parts in proptest::collection::vec(proptest::prop_oneof![
            proptest::strategy::Just("N10"), proptest::strategy::Just("N0100"), proptest::strategy::Just("n5"),
            proptest::strategy::Just("N123456789"), proptest::strategy::Just("N1234567890"), proptest::strategy::Just("N10.5"),
            proptest::strategy::Just("N 10"), proptest::strategy::Just("X1.5"), proptest::strategy::Just("x-2"),
            proptest::strategy::Just("Y.5"), proptest::strategy::Just("Z-0.25"), proptest::strategy::Just("Z+3."),
            proptest::strategy::Just("G1"), proptest::strategy::Just("G01"), proptest::strategy::Just("M3"),
            proptest::strategy::Just("G200"), proptest::strategy::Just("G200 DRILLING"), proptest::strategy::Just("F100."),
            proptest::strategy::Just("S12000"), proptest::strategy::Just("T1"), proptest::strategy::Just(" "),
            proptest::strategy::Just("\t"), proptest::strategy::Just("(c)"), proptest::strategy::Just(";c"),
            proptest::strategy::Just("/"), proptest::strategy::Just("%"), proptest::strategy::Just("X1 5"),
            proptest::strategy::Just("#1=2"), proptest::strategy::Just("\r\n"), proptest::strategy::Just("\n"),
            proptest::strategy::Just("\r"), proptest::strategy::Just("X"), proptest::strategy::Just("-"),
            proptest::strategy::Just("."), proptest::strategy::Just("X1..5"), proptest::strategy::Just("Q200=2"),
            proptest::strategy::Just("L10"), proptest::strategy::Just("R1=5"), proptest::strategy::Just("X12345678901234567890"),
            proptest::strategy::Just("CYCLE81(1,2)"), proptest::strategy::Just("Xnan"), proptest::strategy::Just("é"),
            proptest::strategy::Just("~"), proptest::strategy::Just("*"), proptest::strategy::Just("O1234"),
        ], 0..24)) {
            static REGISTRY: std::sync::OnceLock<Registry> = std::sync::OnceLock::new();
            let registry = REGISTRY.get_or_init(Registry::shipped);
            let text = parts.concat();
            for name in registry.names() {
                let d = registry.get(name).unwrap();
                let read = |fast: bool| {
                    let mut p = Parser::new(text.as_str(), &d);
                    p.set_fast_path(fast);
                    let (mut block, mut diags, mut out) = (Block::default(), Vec::new(), Vec::new());
                    while p.next_block(&mut block, &mut diags) {
                        out.push(format!("{block:?} next {} line {}", p.offset(), p.line()));
                    }
                    (out, format!("{diags:?}"))
                };
                proptest::prop_assert_eq!(read(true), read(false), "{:?} in {}", text, name);
            }
        }

        /// Whatever path a word's number takes (the fast one, or the general one for long
        /// numbers), its value is the double `str::parse` gives.
        #[test]
        fn word_values_are_the_doubles_parse_gives(int in "[0-9]{0,24}", frac in proptest::option::of("[0-9]{0,24}"), neg: bool) {
            proptest::prop_assume!(!int.is_empty() || frac.as_ref().is_some_and(|f| !f.is_empty()));
            static REGISTRY: std::sync::OnceLock<Registry> = std::sync::OnceLock::new();
            let registry = REGISTRY.get_or_init(Registry::shipped);
            for name in ["linuxcnc", "fanuc", "siemens", "heidenhain"] {
                let d = registry.get(name).unwrap();
                let number = format!("{}{int}{}", if neg { "-" } else { "" }, frac.as_ref().map_or(String::new(), |f| format!(".{f}")));
                let text = format!("X{number}\n");
                let mut p = Parser::new(text.as_str(), &d);
                let (mut block, mut diags) = (Block::default(), Vec::new());
                proptest::prop_assert!(p.next_block(&mut block, &mut diags));
                let want = parsed(&int, frac.as_deref()) * if neg { -1.0 } else { 1.0 };
                match block.words.first().map(|w| w.value) {
                    Some(Value::Number { value, decimal }) => {
                        proptest::prop_assert_eq!(value.to_bits(), want.to_bits(), "{} in {}", text, name);
                        proptest::prop_assert_eq!(decimal, frac.is_some());
                    }
                    other => proptest::prop_assert!(false, "{} in {}: {:?} {:?}", text, name, other, diags),
                }
            }
        }
    }
}

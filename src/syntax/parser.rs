//! The streaming block parser.
//!
//! This file is the door: [`Parser`] (the cursor, its window over a read text, the record
//! form's loop), [`leader`], [`PlainLine`], and the general lexer's state (`Lexer`) with its
//! primitive moves. The lexer's readers are `Lexer` methods in the files below, by what they
//! read: `block.rs` (a block, mark by mark, and comments), `words.rs` (address words and
//! assignments), `keywords.rs` (keyword codes and named cycles), `statements.rs` (control
//! statements), `expression.rs` (expressions), `numbers.rs` (literal numbers) and `plain.rs`
//! (the fast path for blocks of plain words).

use super::Block;
use crate::diag::{Code, Diagnostic};
use crate::dialect::{Dialect, Role};
use crate::text::{Text, TextRange};

mod block;
mod expression;
mod keywords;
mod numbers;
mod plain;
mod statements;
mod words;

use plain::{plain_block, plain_block_number};

/// The tape leader the dialect skips: the text before the first line that is only the
/// program delimiter (`%`) with program text after it, when there is text before it (an NX
/// listing header, a title), and the 1-based line the program starts on. The first line may
/// also end with the delimiter after a sender's leader of its own (a device control code and a
/// DNC header, `\x12&HE:%`): the leader then ends where the delimiter starts.
pub fn leader<'t>(text: impl Into<Text<'t>>, dialect: &Dialect) -> Option<(TextRange, u32)> {
    let d = dialect.lexical.program_delimiter.filter(|_| dialect.lexical.leader_skipped)?;
    let text = text.into();
    let head = text.head();
    let blank = |s: &str| s.chars().all(|c| c.is_whitespace() || c == '\u{feff}' || c == d);
    let mut at = 0;
    for (n, line) in head.split_inclusive('\n').enumerate() {
        let t = line.trim().trim_start_matches('\u{feff}');
        // (Only behind a device control code, DC1-DC4, that a tape punch or DNC sender writes:
        // a first line such as Okuma's `$NAME.MIN%` is the program's own header.)
        let sender = t.chars().any(|c| ('\u{11}'..='\u{14}').contains(&c));
        let first_ends = n == 0 && sender && t.ends_with(d) && t.matches(d).count() == 1;
        if t.len() == d.len_utf8() && t.starts_with(d) || first_ends {
            let start = if first_ends { at + line.rfind(d).unwrap_or(0) } else { at };
            let before = &head[..start];
            let after = at + line.len();
            // Program text after the line: in the head, or else anywhere after it.
            let text_after = !blank(&head[after..]) || (head.len() < text.len() && !rest_blank(text, head.len(), &blank));
            return (!blank(before) && text_after).then(|| (TextRange::new(0, start), n as u32 + 1));
        }
        at += line.len();
    }
    None
}

/// A keyword-first block (Klartext) whose first word is an axis (`80 Z DR+0.0`, a broken
/// `TOOL CALL`): the TNC writes and reads every positioning block with its path function
/// (`L X+10`, `C X.. DR+`; the TNC programming manuals' "Path functions"), and has no modal
/// motion to carry a bare axis word, so the block stops the program. An M function alone
/// (`79 M5`) is a block of its own.
fn no_function(block: &Block, diags: &mut Vec<Diagnostic>) {
    if block.control.is_some() || !block.assigns.is_empty() {
        return;
    }
    // An axis word with its value (`X+20`, `C+90`), or X, Y or Z alone (read as TOOL CALL's
    // tool axis); a `C` alone is the circle function.
    let axis = |w: &&super::Word| {
        let t = block.text(w.range).trim_end().as_bytes();
        match t {
            [c] => b"XYZ".contains(&c.to_ascii_uppercase()),
            [c, next, ..] => b"XYZABCUVW".contains(&c.to_ascii_uppercase()) && !next.is_ascii_alphabetic(),
            [] => false,
        }
    };
    if let Some(w) = block.words.first().filter(axis) {
        let letter = char::from(block.text(w.range).as_bytes()[0].to_ascii_uppercase());
        diags.push(Diagnostic::new(
            Code::NoFunction,
            w.range,
            format!("the block starts with the axis `{letter}` and no function (`L`, `C`, ...): the control reads no such block"),
        ));
    }
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
                    let mut lx = Lexer { text: win, b: bytes, i: start, base, dialect, block, diags, paren: None };
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
            if dialect.lexical.block_form == crate::dialect::BlockForm::KeywordFirst {
                no_function(block, diags);
            }
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
        (line.len, line.read) = (0, 0);
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

/// A line of plain words read by [`Parser::plain_lines`] without a [`Block`]: the block that
/// makes up most of a CAM program (`X12.5 Y-3.2 Z-1.05`), for the interpreter's plain lane.
/// Its X, Y and Z words are kept by axis ([`PlainLine::axes`]), each at most once (a line that
/// writes an axis twice is read as a [`Block`]); its other words in source order
/// ([`PlainLine::words`]).
#[derive(Clone, Debug)]
pub struct PlainLine {
    words: [PlainWord; PLAIN_WORDS],
    len: usize,
    /// The values of its X, Y and Z words, by axis.
    axes: [f64; 3],
    /// Which axes it writes: bit 0 X, bit 1 Y, bit 2 Z.
    read: u32,
    /// By axis: whether its word is written with a decimal point (of an axis it writes).
    points: [bool; 3],
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
        PlainLine { words: [w; PLAIN_WORDS], len: 0, axes: [0.0; 3], read: 0, points: [false; 3], range: TextRange::default(), line: 0 }
    }
}

impl PlainLine {
    /// Its words other than X, Y and Z, in source order.
    pub fn words(&self) -> &[PlainWord] {
        &self.words[..self.len]
    }

    /// Its X, Y and Z words: which it writes (bit 0 X, bit 1 Y, bit 2 Z), by axis whether
    /// written with a decimal point, and their values by axis (only those of the axes it
    /// writes mean anything).
    #[inline(always)]
    pub fn axes(&self) -> (u8, &[bool; 3], &[f64; 3]) {
        (self.read as u8, &self.points, &self.axes)
    }
}

/// The general lexer: one block of the window into `block`, its findings into `diags`.
struct Lexer<'t, 'b> {
    /// The window: the text from `base` on. Indices are into it; ranges add `base`.
    text: &'t str,
    b: &'t [u8],
    i: usize,
    base: usize,
    dialect: &'t Dialect,
    block: &'b mut Block,
    diags: &'b mut Vec<Diagnostic>,
    /// The closing `)` of a statement in brackets (`(IF P1 EQ 0 GOTO N10)`): the statement's
    /// text ends there, as at a line's end.
    paren: Option<usize>,
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

    /// Where the line at the cursor starts.
    fn line_start(&self) -> usize {
        self.b[..self.i].iter().rposition(|&c| c == b'\n' || c == b'\r').map_or(0, |p| p + 1)
    }

    /// Index of the end of the physical line from `i`.
    fn line_end(&self) -> usize {
        let rest = &self.b[self.i..];
        let end = self.i + rest.iter().position(|&c| c == b'\n' || c == b'\r').unwrap_or(rest.len());
        self.paren.filter(|&p| p >= self.i).map_or(end, |p| p.min(end))
    }

    fn char_len(&self, at: usize) -> usize {
        self.text[at..].chars().next().map_or(1, char::len_utf8)
    }

    fn expr_open(&self) -> Option<u8> {
        self.dialect.lexical.expression.map(|(o, _)| o as u8)
    }
}

#[cfg(test)]
mod tests {
    use super::numbers::{digits, plain_number, short_number};
    use super::*;
    use crate::dialect::Registry;
    use crate::syntax::Value;

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

    /// A number read byte by byte, as `plain_number` reads one that does not fit in a word:
    /// (mantissa, integer digits, fraction digits, point, end).
    fn byte_by_byte(b: &[u8], i: usize) -> (u64, usize, usize, bool, usize) {
        let (mut end, mut m) = (i, 0u64);
        digits(b, &mut end, &mut m);
        let n_int = end - i;
        let point = b.get(end) == Some(&b'.');
        if point {
            end += 1;
            digits(b, &mut end, &mut m);
        }
        (m, n_int, end - i - n_int - usize::from(point), point, end)
    }

    #[test]
    fn short_numbers_read_from_one_word_as_byte_by_byte() {
        let slow = byte_by_byte;
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

    /// Any bytes at all after and among the digits (points, signs, bytes below `0` and above
    /// `9`, bytes of 0x80 and up): the word gives what the bytes give, or declines.
    #[test]
    fn short_numbers_among_any_bytes_read_as_byte_by_byte() {
        let slow = byte_by_byte;
        let mut rng = 0x2545_f491_4f6c_dd1d_u64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        let mut read = 0;
        for _ in 0..300_000 {
            // Mostly digits and points, with any byte among them.
            let b: Vec<u8> = (0..12)
                .map(|_| match next() % 8 {
                    0..=4 => b'0' + (next() % 10) as u8,
                    5 => b'.',
                    _ => next() as u8,
                })
                .collect();
            for from in 0..4 {
                match short_number(&b, from) {
                    Some(n) => {
                        assert_eq!(n, slow(&b, from), "{b:?} from {from}");
                        read += 1;
                    }
                    None => {
                        let (_, n_int, n_frac, _, end) = slow(&b, from);
                        assert!(end - from >= 8 || n_int + n_frac == 0, "{b:?} from {from}");
                    }
                }
            }
        }
        assert!(read > 100_000, "{read}");
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

    #[test]
    fn the_rest_of_line_a_keyword_keeps_ends_at_its_comment() {
        // `FN 17: SYSWRITE … = value ; comment`: the comment is one, a `;` inside quotes is text.
        let registry = Registry::shipped();
        let d = registry.get("heidenhain").unwrap();
        let text = "FN 17: SYSWRITE ID50 NR0 IDXQ8 = \"A;B\" ; NAME, untested!\n";
        let mut p = Parser::new(text, &d);
        let (mut block, mut diags) = (Block::default(), Vec::new());
        assert!(p.next_block(&mut block, &mut diags));
        let comments: Vec<&str> = block.comments.iter().map(|r| &text[r.start as usize..r.end as usize]).collect();
        assert_eq!(comments, [" NAME, untested!"], "{diags:?}");
    }
}

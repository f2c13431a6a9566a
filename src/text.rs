//! Source text: byte ranges, line/column lookup and decoding of raw program bytes.
//!
//! Every position in ncplan is a byte offset into the *decoded* text (UTF-8). Line and
//! column numbers are computed only when a diagnostic is rendered or stored.
//!
//! A text is whole in memory or read piece by piece ([`Text`]): a long file is surveyed once
//! as its bytes go by ([`Survey`] → [`Layout`]), then decoded where the reader asks
//! ([`Layout::read`]), with the same text and offsets as [`decode`] gives. The shell does the
//! reading ([`TextReader`]); the core never holds such a text whole.
//!
//! `TextRange` (u32 byte ranges into the decoded text), `LineIndex` (line:col on
//! demand), `decode` (UTF-8, BOM, Windows-1252 fallback, binary detection; what it notices is a
//! `DecodeNote`, which `diag` words as a diagnostic: text sits below diag). `Text` is what the
//! core reads: the whole text (`Text::Whole(&str)`) or a text read piece by piece through the
//! shell (`Text::Read(&dyn TextReader)`: its length, the decoded text from an offset), with the
//! same offsets either way; `head` (the first 64 KiB the dialect's checks read), `piece`,
//! `trimmed_end`. A file is surveyed once as its bytes go by (`Survey`, in chunks of any size:
//! encoding, byte-order mark, stray carriage returns, decoded length) into a `Layout` that
//! decodes any piece of it by offset (`Layout::read`; Windows-1252 from marks every 64 KiB of
//! bytes), giving the text and findings `decode` gives. `locate` gives the line:col of sorted
//! offsets in one pass up to the last of them, without an index of every line. `BytesReader`
//! reads bytes in memory as a file is, with windows as small as a test likes.

use std::borrow::Cow;

use serde::{Deserialize, Serialize};

/// A half-open byte range `start..end` into a decoded source text.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
pub struct TextRange {
    /// First byte.
    pub start: u32,
    /// One past the last byte.
    pub end: u32,
}

impl TextRange {
    /// Creates a range; `end` is clamped so that the range is never inverted.
    pub fn new(start: usize, end: usize) -> TextRange {
        let start = u32::try_from(start).unwrap_or(u32::MAX);
        let end = u32::try_from(end).unwrap_or(u32::MAX).max(start);
        TextRange { start, end }
    }

    /// The smallest range covering both.
    pub fn cover(self, other: TextRange) -> TextRange {
        TextRange { start: self.start.min(other.start), end: self.end.max(other.end) }
    }

    /// Length in bytes.
    pub fn len(self) -> u32 {
        self.end - self.start
    }

    /// True when the range is empty.
    pub fn is_empty(self) -> bool {
        self.start == self.end
    }
}

/// A 1-based line and column; columns count characters, not bytes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct LineCol {
    /// 1-based line number.
    pub line: u32,
    /// 1-based column, in characters.
    pub col: u32,
}

/// Maps byte offsets to lines and columns. Built once per text, on demand.
#[derive(Clone, Debug)]
pub struct LineIndex {
    line_starts: Vec<u32>,
}

impl LineIndex {
    /// Indexes `text`. A line ends at `\n`, at `\r\n`, or at a lone `\r`.
    pub fn new(text: &str) -> LineIndex {
        let bytes = text.as_bytes();
        let mut line_starts = vec![0u32];
        let mut i = 0;
        while i < bytes.len() {
            match bytes[i] {
                b'\n' => line_starts.push(to_u32(i + 1)),
                b'\r' if bytes.get(i + 1) != Some(&b'\n') => line_starts.push(to_u32(i + 1)),
                _ => {}
            }
            i += 1;
        }
        LineIndex { line_starts }
    }

    /// Line and column of `offset` in `text` (the text this index was built from).
    pub fn line_col(&self, text: &str, offset: u32) -> LineCol {
        let offset = offset.min(to_u32(text.len()));
        let line = self.line_starts.partition_point(|&s| s <= offset) - 1;
        let start = self.line_starts[line] as usize;
        let mut end = offset as usize;
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let col = text[start..end].chars().count();
        LineCol { line: to_u32(line + 1), col: to_u32(col + 1) }
    }

    /// The text of 1-based `line`, without its line terminator.
    pub fn line_text<'a>(&self, text: &'a str, line: u32) -> &'a str {
        let i = (line.max(1) - 1) as usize;
        let Some(&start) = self.line_starts.get(i) else { return "" };
        let end = self.line_starts.get(i + 1).map_or(text.len(), |&e| e as usize);
        text[start as usize..end].trim_end_matches(['\r', '\n'])
    }
}

fn to_u32(n: usize) -> u32 {
    u32::try_from(n).unwrap_or(u32::MAX)
}

/// How the raw bytes were decoded.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Encoding {
    /// Valid UTF-8 (a byte-order mark, if any, is dropped).
    Utf8,
    /// Not UTF-8: decoded as Windows-1252, whose printable range is a superset of Latin-1.
    Windows1252,
    /// Binary data; the text is empty.
    Binary,
}

/// A decoded program text.
#[derive(Clone, Debug)]
pub struct SourceText {
    /// The decoded text.
    pub text: String,
    /// How it was decoded.
    pub encoding: Encoding,
}

/// What decoding noticed about the bytes. [`crate::diag`] words each as a diagnostic
/// (`Diagnostic::from`): text sits below diag.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecodeNote {
    /// The bytes look like binary data (NUL or control bytes), not a part program.
    Binary,
    /// The bytes are not valid UTF-8, first at byte `at`; they were read as Windows-1252.
    NotUtf8 {
        /// The offset of the first invalid byte, after any byte-order mark.
        at: u64,
    },
}

/// Decodes raw program bytes. Never fails: binary input yields an empty text and an error
/// diagnostic; non-UTF-8 input is decoded as Windows-1252 with a note.
pub fn decode(bytes: &[u8]) -> (SourceText, Vec<DecodeNote>) {
    let mut diags = Vec::new();
    let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if looks_binary(body) {
        diags.push(DecodeNote::Binary);
        return (SourceText { text: String::new(), encoding: Encoding::Binary }, diags);
    }
    match std::str::from_utf8(body) {
        Ok(s) => (SourceText { text: blank_end_marks(blank_stray_returns(s.to_owned())), encoding: Encoding::Utf8 }, diags),
        Err(e) => {
            let text: String = body.iter().map(|&b| windows_1252(b)).collect();
            diags.push(DecodeNote::NotUtf8 { at: e.valid_up_to() as u64 });
            (SourceText { text: blank_end_marks(blank_stray_returns(text)), encoding: Encoding::Windows1252 }, diags)
        }
    }
}

/// In a file whose lines end in LF or CRLF, a carriage return on its own inside a line (a
/// post processor's stray byte) is a blank, not a line end; only a file without any LF
/// (classic Mac) ends its lines in CR. The text keeps its length, so offsets hold.
fn blank_stray_returns(text: String) -> String {
    let b = text.as_bytes();
    let stray = |i: usize| b[i] == b'\r' && b.get(i + 1) != Some(&b'\n');
    if !b.contains(&b'\r') || !b.contains(&b'\n') || !(0..b.len()).any(stray) {
        return text;
    }
    let mut bytes = text.into_bytes();
    for i in 0..bytes.len() {
        if bytes[i] == b'\r' && bytes.get(i + 1) != Some(&b'\n') {
            bytes[i] = b' ';
        }
    }
    String::from_utf8(bytes).expect("an ASCII byte replaced by another keeps UTF-8 valid")
}

/// The end-of-file mark: SUB (0x1A, Ctrl-Z), which MS-DOS text files and the DNC and
/// tape-punch software of that era write after a file's last line (CP/M and MS-DOS end a text
/// file there; `COPY /A` writes it). It is no character of the ISO 840 tape code a control
/// reads (a Fanuc reads a file up to its closing `%`; LinuxCNC's interpreter stops with "Bad
/// character" at one inside the program), so only the run at the file's end is the mark.
const END_MARK: u8 = 0x1a;

/// Whether `b` may stand in the run of end-of-file marks at a file's end: the mark itself and
/// the line ends and blanks among the marks.
fn in_end_run(b: u8) -> bool {
    matches!(b, END_MARK | b'\n' | b'\r' | b' ' | b'\t')
}

/// The end-of-file marks after a program's last line blanked: a file saved again without them
/// is the same program, and a mark on a line of its own is no unexpected character. Blanked,
/// not removed, so every byte offset stays the source's; a mark anywhere before the trailing
/// run of marks, line ends and blanks stays (the lexer reports it). [`Survey`] finds the same
/// run as the bytes go by, so that a file read piece by piece reads the same.
fn blank_end_marks(text: String) -> String {
    let b = text.as_bytes();
    let run = b.iter().rev().take_while(|&&c| in_end_run(c)).count();
    if !b[b.len() - run..].contains(&END_MARK) {
        return text;
    }
    let mut bytes = text.into_bytes();
    let n = bytes.len();
    for c in &mut bytes[n - run..] {
        if *c == END_MARK {
            *c = b' ';
        }
    }
    String::from_utf8(bytes).expect("an ASCII byte replaced by another keeps UTF-8 valid")
}

/// [`decode`] that takes the bytes and, for UTF-8 input (the common case), keeps them as the
/// text without a copy: a large program is held in memory once.
pub fn decode_owned(mut bytes: Vec<u8>) -> (SourceText, Vec<DecodeNote>) {
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        bytes.drain(..3);
    }
    if looks_binary(&bytes) {
        return decode(&bytes);
    }
    match String::from_utf8(bytes) {
        Ok(text) => (SourceText { text: blank_end_marks(blank_stray_returns(text)), encoding: Encoding::Utf8 }, Vec::new()),
        Err(e) => decode(e.as_bytes()),
    }
}

/// Binary when the sample holds a NUL byte or more than 5% control characters.
fn looks_binary(bytes: &[u8]) -> bool {
    let sample = &bytes[..bytes.len().min(64 * 1024)];
    if sample.contains(&0) {
        return true;
    }
    let controls = sample.iter().filter(|&&b| b < 0x20 && !matches!(b, b'\n' | b'\r' | b'\t' | 0x0c | 0x1a)).count();
    controls * 20 > sample.len().max(1)
}

fn windows_1252(b: u8) -> char {
    const HIGH: [char; 32] = [
        '€', '\u{81}', '‚', 'ƒ', '„', '…', '†', '‡', 'ˆ', '‰', 'Š', '‹', 'Œ', '\u{8d}', 'Ž', '\u{8f}', '\u{90}', '‘', '’', '“', '”', '•',
        '–', '—', '˜', '™', 'š', '›', 'œ', '\u{9d}', 'ž', 'Ÿ',
    ];
    match b {
        0x80..=0x9f => HIGH[(b - 0x80) as usize],
        _ => char::from(b),
    }
}

/// The first bytes of a text that the dialect's checks look at (sniffing, tape leaders,
/// foreign formats, a CL file's producer).
pub const HEAD: usize = 64 * 1024;

/// A program's text as the core reads it: whole in memory, or read piece by piece through
/// the shell ([`TextReader`]), so that a long file is never held whole. Offsets are the
/// same either way: byte offsets into the decoded text.
#[derive(Clone, Copy)]
pub enum Text<'a> {
    /// The whole text.
    Whole(&'a str),
    /// A text read where it is needed.
    Read(&'a dyn TextReader),
}

impl std::fmt::Debug for Text<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Text::Whole(s) => write!(f, "Text::Whole({} bytes)", s.len()),
            Text::Read(r) => write!(f, "Text::Read({} bytes)", r.len()),
        }
    }
}

impl<'a> From<&'a str> for Text<'a> {
    fn from(s: &'a str) -> Text<'a> {
        Text::Whole(s)
    }
}

impl<'a> From<&'a String> for Text<'a> {
    fn from(s: &'a String) -> Text<'a> {
        Text::Whole(s)
    }
}

/// A decoded text read piece by piece: the shell implements it over a file (the core does
/// no IO). Reads may come from several threads at once.
pub trait TextReader: Sync {
    /// The length of the whole decoded text, in bytes.
    fn len(&self) -> usize;

    /// Whether the text is empty.
    fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Appends the text from the first character boundary at or after `at` to `buf`, about
    /// `want` bytes of whole characters (perhaps fewer, at least one character unless the
    /// text ends; nothing once the text could no longer be read, which the shell reports
    /// after the run). Returns the offset the appended text starts at.
    fn read(&self, at: usize, want: usize, buf: &mut String) -> usize;

    /// How many bytes a reader of this text keeps at most in its window, as a rule (a line
    /// longer than it is held whole).
    fn window(&self) -> usize {
        256 * 1024
    }
}

impl<'a> Text<'a> {
    /// Length in bytes.
    pub fn len(&self) -> usize {
        match self {
            Text::Whole(s) => s.len(),
            Text::Read(r) => r.len(),
        }
    }

    /// Whether the text is empty.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The whole text, when it is in memory.
    pub fn whole(&self) -> Option<&'a str> {
        match self {
            Text::Whole(s) => Some(s),
            Text::Read(_) => None,
        }
    }

    /// At most `n` bytes of whole characters from `at` (a character boundary).
    pub fn piece(&self, at: usize, n: usize) -> Cow<'a, str> {
        match *self {
            Text::Whole(s) => {
                let at = floor_char_boundary(s, at);
                Cow::Borrowed(&s[at..floor_char_boundary(s, at.saturating_add(n))])
            }
            Text::Read(r) => {
                let (_, mut buf) = read_from(r, at, n);
                buf.truncate(floor_char_boundary(&buf, n));
                Cow::Owned(buf)
            }
        }
    }

    /// The first [`HEAD`] bytes (whole characters).
    pub fn head(&self) -> Cow<'a, str> {
        self.piece(0, HEAD)
    }

    /// The end of the text without its trailing whitespace.
    pub fn trimmed_end(&self) -> usize {
        match *self {
            Text::Whole(s) => s.trim_end().len(),
            Text::Read(r) => {
                let len = r.len();
                let mut back = 4096usize;
                loop {
                    let (start, buf) = read_from(r, len.saturating_sub(back), back);
                    let t = buf.trim_end();
                    if !t.is_empty() {
                        return start + t.len();
                    }
                    if start == 0 || buf.is_empty() {
                        return 0;
                    }
                    back = back.saturating_mul(4);
                }
            }
        }
    }
}

/// About `n` bytes of `r` from the first character boundary at or after `at` (up to the end),
/// however little each read gives; where they start.
fn read_from(r: &dyn TextReader, at: usize, n: usize) -> (usize, String) {
    let mut buf = String::new();
    let mut start = at;
    let mut from = at;
    while buf.len() < n && from < r.len() {
        let before = buf.len();
        let s = r.read(from, n - buf.len(), &mut buf);
        if buf.len() == before || (before > 0 && s != from) {
            buf.truncate(before);
            break;
        }
        if before == 0 {
            start = s;
        }
        from = s + (buf.len() - before);
    }
    (start, buf)
}

/// A number as a planner writes it: at most four decimals, no trailing zeros.
pub fn num(v: f64) -> String {
    let s = format!("{:.4}", v);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// The largest character boundary of `s` at or before `at`.
pub fn floor_char_boundary(s: &str, at: usize) -> usize {
    let mut at = at.min(s.len());
    while !s.is_char_boundary(at) {
        at -= 1;
    }
    at
}

/// Line and column of each offset in `offsets` (ascending), in one pass over the text up to
/// the last of them: what [`LineIndex::line_col`] gives, without an index of every line.
pub fn locate(text: Text<'_>, offsets: &[u32]) -> Vec<LineCol> {
    debug_assert!(offsets.windows(2).all(|w| w[0] <= w[1]));
    let mut out = Vec::with_capacity(offsets.len());
    let Some(&last) = offsets.last() else { return out };
    let len = text.len();
    let last = (last as usize).min(len);
    let mut lines = LineCounter::default();
    let mut next = 0;
    let mut place = |lines: &LineCounter, piece_at: usize, piece: &str, out: &mut Vec<LineCol>, upto: usize| {
        while next < offsets.len() && (offsets[next] as usize).min(len) < upto {
            let off = (offsets[next] as usize).min(len);
            out.push(lines.at(piece_at, piece, off));
            next += 1;
        }
    };
    match text {
        Text::Whole(s) => {
            let end = (last + 1).min(len);
            let end = {
                let mut e = end;
                while !s.is_char_boundary(e) {
                    e += 1;
                }
                e
            };
            // Whole characters up to one past the last offset, so that a pending `\r` is decided.
            let piece = &s[..end];
            lines.feed(0, piece, end == len);
            place(&lines, 0, piece, &mut out, end.max(1));
        }
        Text::Read(r) => {
            let mut at = 0;
            let mut buf = String::new();
            loop {
                buf.clear();
                // No more than the pieces up to one past the last offset.
                let start = r.read(at, (last + 2 - at).clamp(4096, 1 << 20), &mut buf);
                if buf.is_empty() || start != at {
                    break;
                }
                let end = at + buf.len();
                lines.feed(at, &buf, end >= len);
                place(&lines, at, &buf, &mut out, end);
                if end > last || end >= len {
                    break;
                }
                at = end;
            }
        }
    }
    // Offsets at the end of the text (or past what could be read).
    while out.len() < offsets.len() {
        out.push(lines.at_end());
    }
    out
}

/// Counts lines piece by piece, as [`LineIndex`] splits them.
#[derive(Default)]
struct LineCounter {
    /// Lines started before the current piece's end (0-based index of the current line).
    line: u32,
    /// Where the current line starts.
    line_start: usize,
    /// Characters of the current line before the current piece, when it started earlier.
    carried: usize,
    /// A `\r` ended the previous piece: its line ends unless a `\n` follows.
    cr_pending: bool,
    /// The line starts in the current piece, in order, with their line numbers (kept for
    /// the offsets placed in it).
    starts: Vec<(usize, u32)>,
    /// The line and start of the line in force at the current piece's start.
    entry: (u32, usize, usize),
}

impl LineCounter {
    /// Takes in the piece at `at`; `last`: no text follows it.
    fn feed(&mut self, at: usize, piece: &str, last: bool) {
        // The state at the piece's start, for offsets before its first line start.
        let b = piece.as_bytes();
        if self.cr_pending {
            self.cr_pending = false;
            if b.first() != Some(&b'\n') && !b.is_empty() {
                self.line += 1;
                self.line_start = at;
                self.carried = 0;
            }
        }
        self.entry = (self.line, self.line_start, self.carried);
        self.starts.clear();
        let mut i = 0;
        while let Some(p) = memchr::memchr2(b'\n', b'\r', &b[i..]) {
            let j = i + p;
            let starts_line = match b[j] {
                b'\n' => true,
                _ => match b.get(j + 1) {
                    Some(&n) => n != b'\n',
                    None if last => true,
                    None => {
                        self.cr_pending = true;
                        false
                    }
                },
            };
            if starts_line {
                self.line += 1;
                self.line_start = at + j + 1;
                self.starts.push((self.line_start, self.line));
            }
            i = j + 1;
        }
        if self.line_start > at {
            self.carried = piece[self.line_start - at..].chars().count();
        } else {
            self.carried += piece.chars().count();
        }
    }

    /// The line and column of `off`, which lies in the piece at `at`.
    fn at(&self, at: usize, piece: &str, off: usize) -> LineCol {
        let k = self.starts.partition_point(|&(s, _)| s <= off);
        let (line, start, carried) = match k {
            0 => self.entry,
            _ => (self.starts[k - 1].1, self.starts[k - 1].0, 0),
        };
        let from = start.max(at) - at;
        let to = floor_char_boundary(piece, off - at);
        let col = carried + piece[from.min(to)..to].chars().count();
        LineCol { line: to_u32(line as usize + 1), col: to_u32(col + 1) }
    }

    /// The line and column of the end of the text.
    fn at_end(&self) -> LineCol {
        LineCol { line: to_u32(self.line as usize + 1), col: to_u32(self.carried + 1) }
    }
}

/// How many body bytes apart [`Layout`] keeps its Windows-1252 marks.
const MARK_EVERY: u64 = 64 * 1024;

/// What decoding a file needs to know of the whole of it, gathered as its bytes go by once
/// (in chunks of any size): whether it is UTF-8, binary or Windows-1252, its byte-order
/// mark, whether lone carriage returns are blanks, the decoded length. Gives a [`Layout`].
#[derive(Debug, Default)]
pub struct Survey {
    /// The first bytes, until the byte-order mark is decided.
    start: Vec<u8>,
    bom: Option<usize>,
    /// Body bytes seen (after the mark).
    body_len: u64,
    /// The first [`HEAD`] bytes of the body, for the binary check.
    sample: Vec<u8>,
    /// An incomplete UTF-8 sequence at the end of the bytes seen.
    carry: Vec<u8>,
    /// The first byte that is not UTF-8, as an offset into the body.
    invalid_at: Option<u64>,
    has_cr: bool,
    has_lf: bool,
    stray: bool,
    cr_pending: bool,
    /// Decoded bytes beyond one per body byte, read as Windows-1252.
    extra: u64,
    /// `extra` before each multiple of [`MARK_EVERY`] body bytes.
    marks: Vec<u64>,
    /// Where the run of end-of-file marks, line ends and blanks at the end of the bytes seen
    /// starts (a body offset), and whether it holds a mark (see `blank_end_marks`).
    run_start: u64,
    run_mark: bool,
}

/// How a surveyed file decodes: enough to decode any piece of it ([`Layout::read`]).
#[derive(Clone, Debug)]
pub struct Layout {
    /// How the bytes are decoded.
    pub encoding: Encoding,
    /// Bytes of the byte-order mark before the body.
    bom: u64,
    /// Length of the body (the file without its mark).
    body_len: u64,
    /// Length of the decoded text.
    text_len: usize,
    /// Whether lone carriage returns are blanks (see `blank_stray_returns`).
    blank_stray: bool,
    /// Where the end-of-file marks that are blanks start in the decoded text (see
    /// `blank_end_marks`); the text's length where there are none.
    end_marks: usize,
    /// Windows-1252: decoded bytes beyond one per body byte before each multiple of
    /// [`MARK_EVERY`] body bytes.
    marks: Vec<u64>,
}

/// The file no longer holds what its survey saw (it was changed or cut while being read).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Changed;

const BOM: &[u8] = b"\xEF\xBB\xBF";

impl Survey {
    /// A survey before any byte.
    pub fn new() -> Survey {
        Survey { marks: vec![0], ..Survey::default() }
    }

    /// Takes in the next bytes of the file.
    pub fn feed(&mut self, mut chunk: &[u8]) {
        if self.bom.is_none() {
            let take = (3 - self.start.len()).min(chunk.len());
            self.start.extend_from_slice(&chunk[..take]);
            chunk = &chunk[take..];
            if self.start.len() < 3 {
                return;
            }
            let start = std::mem::take(&mut self.start);
            let bom = if start == BOM { 3 } else { 0 };
            self.bom = Some(bom);
            self.body(&start[bom..]);
        }
        self.body(chunk);
    }

    fn body(&mut self, mut bytes: &[u8]) {
        while !bytes.is_empty() {
            // Pieces end at the marks' places.
            let room = (MARK_EVERY - self.body_len % MARK_EVERY) as usize;
            let (seg, rest) = bytes.split_at(room.min(bytes.len()));
            self.segment(seg);
            bytes = rest;
            if self.body_len % MARK_EVERY == 0 {
                self.marks.push(self.extra);
            }
        }
    }

    fn segment(&mut self, seg: &[u8]) {
        if self.sample.len() < HEAD {
            let n = (HEAD - self.sample.len()).min(seg.len());
            self.sample.extend_from_slice(&seg[..n]);
        }
        if self.cr_pending {
            self.cr_pending = false;
            self.stray |= seg[0] != b'\n';
        }
        if !self.has_lf {
            self.has_lf = memchr::memchr(b'\n', seg).is_some();
        }
        if !self.stray {
            for p in memchr::memchr_iter(b'\r', seg) {
                self.has_cr = true;
                match seg.get(p + 1) {
                    Some(b'\n') => {}
                    Some(_) => {
                        self.stray = true;
                        break;
                    }
                    None => self.cr_pending = true,
                }
            }
        }
        let ascii = seg.is_ascii();
        if !ascii {
            self.extra += seg.iter().filter(|&&b| b >= 0x80).map(|&b| (windows_1252(b).len_utf8() - 1) as u64).sum::<u64>();
        }
        if self.invalid_at.is_none() {
            self.validate(seg, ascii);
        }
        match seg.iter().rposition(|&c| !in_end_run(c)) {
            Some(p) => {
                self.run_start = self.body_len + p as u64 + 1;
                self.run_mark = seg[p + 1..].contains(&END_MARK);
            }
            None => self.run_mark |= seg.contains(&END_MARK),
        }
        self.body_len += seg.len() as u64;
    }

    /// UTF-8 validation of `seg`, which follows `carry`.
    fn validate(&mut self, mut seg: &[u8], ascii: bool) {
        let mut at = self.body_len;
        if !self.carry.is_empty() {
            // `from_utf8` said the sequence was cut short: its lead byte is a valid one.
            let width = utf8_width(self.carry[0]).max(self.carry.len() + 1);
            let need = (width - self.carry.len()).min(seg.len());
            self.carry.extend_from_slice(&seg[..need]);
            seg = &seg[need..];
            at += need as u64;
            if self.carry.len() < width {
                return;
            }
            if std::str::from_utf8(&self.carry).is_err() {
                self.invalid_at = Some(at - width as u64);
                return;
            }
            self.carry.clear();
        } else if ascii {
            return;
        }
        if let Err(e) = std::str::from_utf8(seg) {
            match e.error_len() {
                Some(_) => self.invalid_at = Some(at + e.valid_up_to() as u64),
                None => self.carry.extend_from_slice(&seg[e.valid_up_to()..]),
            }
        }
    }

    /// The layout, with the findings [`decode`] would give.
    pub fn finish(mut self) -> (Layout, Vec<DecodeNote>) {
        if self.bom.is_none() {
            let start = std::mem::take(&mut self.start);
            self.bom = Some(0);
            self.body(&start);
        }
        if !self.carry.is_empty() && self.invalid_at.is_none() {
            self.invalid_at = Some(self.body_len - self.carry.len() as u64);
        }
        if self.cr_pending {
            self.stray = true;
        }
        let mut diags = Vec::new();
        let bom = self.bom.unwrap_or(0) as u64;
        let blank_stray = self.has_cr && self.has_lf && self.stray;
        let (encoding, text_len) = if looks_binary(&self.sample) {
            diags.push(DecodeNote::Binary);
            (Encoding::Binary, 0)
        } else if let Some(at) = self.invalid_at {
            diags.push(DecodeNote::NotUtf8 { at });
            (Encoding::Windows1252, (self.body_len + self.extra) as usize)
        } else {
            (Encoding::Utf8, self.body_len as usize)
        };
        let marks = if encoding == Encoding::Windows1252 { self.marks } else { Vec::new() };
        // The run is ASCII: it ends the decoded text as it ends the bytes.
        let end_marks = if self.run_mark { text_len.saturating_sub((self.body_len - self.run_start) as usize) } else { text_len };
        (Layout { encoding, bom, body_len: self.body_len, text_len, blank_stray, end_marks, marks }, diags)
    }
}

/// The length of the UTF-8 sequence lead byte `b` begins (0: no lead byte).
fn utf8_width(b: u8) -> usize {
    match b {
        0x00..=0x7F => 1,
        0xC2..=0xDF => 2,
        0xE0..=0xEF => 3,
        0xF0..=0xF4 => 4,
        _ => 0,
    }
}

impl Layout {
    /// The length of the decoded text.
    pub fn text_len(&self) -> usize {
        self.text_len
    }

    /// Appends the decoded text from the first character boundary at or after `at` to `out`,
    /// `want` bytes or up to a character's end beyond them (fewer at the end), reading the
    /// file's bytes through `read_at` (file offset, most bytes, buffer → bytes appended to
    /// the buffer: appended, so that no room is cleared for them first). Returns where the
    /// appended text starts; `Changed` when the file no longer holds what was surveyed.
    pub fn read(
        &self,
        at: usize,
        want: usize,
        read_at: &mut dyn FnMut(u64, usize, &mut Vec<u8>) -> usize,
        out: &mut String,
    ) -> Result<usize, Changed> {
        let at = at.min(self.text_len);
        let want = want.min(self.text_len - at).max(1);
        if at >= self.text_len {
            return Ok(at);
        }
        match self.encoding {
            Encoding::Binary => Ok(at),
            Encoding::Utf8 => self.read_utf8(at, want, read_at, out),
            Encoding::Windows1252 => self.read_1252(at, want, read_at, out),
        }
    }

    fn read_utf8(
        &self,
        at: usize,
        want: usize,
        read_at: &mut dyn FnMut(u64, usize, &mut Vec<u8>) -> usize,
        out: &mut String,
    ) -> Result<usize, Changed> {
        // Up to 3 bytes to the first boundary, the end of the last character and the byte after
        // it (is a `\r` alone?) lie within 8 more bytes.
        let len = (want as u64 + 8).min(self.body_len - at as u64) as usize;
        // Read into the text's own bytes: no buffer between.
        let mut bytes = std::mem::take(out).into_bytes();
        let kept = bytes.len();
        let restore = |mut bytes: Vec<u8>, out: &mut String| {
            bytes.truncate(kept);
            *out = String::from_utf8(bytes).unwrap_or_else(|e| String::from_utf8_lossy(e.as_bytes()).into_owned());
        };
        if read_full(read_at, self.bom + at as u64, len, &mut bytes) < len {
            restore(bytes, out);
            return Err(Changed);
        }
        let buf = &mut bytes[kept..];
        let start = buf.iter().take(3).take_while(|&&c| c & 0xC0 == 0x80).count();
        let mut end = (start + want).min(len);
        while end < len && buf[end] & 0xC0 == 0x80 {
            end += 1;
        }
        let body_end = at as u64 + len as u64 == self.body_len;
        if self.blank_stray {
            let mut from = 0;
            while let Some(q) = memchr::memchr(b'\r', &buf[from..end]) {
                let p = from + q;
                if buf.get(p + 1) != Some(&b'\n') && (p + 1 < len || body_end) {
                    buf[p] = b' ';
                }
                from = p + 1;
            }
        }
        if at + end > self.end_marks {
            let from = self.end_marks.saturating_sub(at);
            for c in &mut buf[from..end] {
                if *c == END_MARK {
                    *c = b' ';
                }
            }
        }
        bytes.truncate(kept + end);
        bytes.drain(kept..kept + start);
        match String::from_utf8(bytes) {
            Ok(s) => *out = s,
            Err(e) => {
                restore(e.into_bytes(), out);
                return Err(Changed);
            }
        }
        Ok(at + start)
    }

    fn read_1252(
        &self,
        at: usize,
        want: usize,
        read_at: &mut dyn FnMut(u64, usize, &mut Vec<u8>) -> usize,
        out: &mut String,
    ) -> Result<usize, Changed> {
        // The last mark at or before `at`, and decoding on from it.
        let decoded = |k: usize| k as u64 * MARK_EVERY + self.marks[k];
        let (mut lo, mut hi) = (0, self.marks.len());
        while lo < hi {
            let mid = (lo + hi) / 2;
            if decoded(mid) <= at as u64 {
                lo = mid + 1;
            } else {
                hi = mid;
            }
        }
        let k = lo.saturating_sub(1);
        let mut body = (k as u64 * MARK_EVERY).min(self.body_len);
        let mut dec = if self.marks.is_empty() { 0 } else { decoded(k) };
        let mut first = None;
        let mut written = 0;
        let kept = out.len();
        let chunk = want.clamp(64, 1 << 20);
        let mut buf = Vec::with_capacity(chunk + 1);
        'read: while body < self.body_len {
            let len = ((chunk + 1) as u64).min(self.body_len - body) as usize;
            buf.clear();
            if read_full(read_at, self.bom + body, len, &mut buf) < len {
                out.truncate(kept);
                return Err(Changed);
            }
            let last = body + len as u64 == self.body_len;
            let usable = if last { len } else { len - 1 };
            for p in 0..usable {
                let c = windows_1252(buf[p]);
                if dec >= at as u64 {
                    if written >= want {
                        break 'read;
                    }
                    first.get_or_insert(dec as usize);
                    let lone = buf[p] == b'\r' && self.blank_stray && buf[..len].get(p + 1).is_none_or(|&n| n != b'\n');
                    let end_mark = buf[p] == END_MARK && dec >= self.end_marks as u64;
                    out.push(if lone || end_mark { ' ' } else { c });
                    written += c.len_utf8();
                }
                dec += c.len_utf8() as u64;
            }
            body += usable as u64;
        }
        // Nothing from `at` on: it was inside the last character.
        Ok(first.unwrap_or((dec as usize).max(at)))
    }
}

/// Appends `len` bytes from `offset` on to `buf` through `read_at` (fewer where the file
/// ends before); the bytes appended.
fn read_full(read_at: &mut dyn FnMut(u64, usize, &mut Vec<u8>) -> usize, offset: u64, len: usize, buf: &mut Vec<u8>) -> usize {
    buf.reserve(len);
    let mut got = 0;
    while got < len {
        let n = read_at(offset + got as u64, len - got, buf);
        if n == 0 {
            break;
        }
        got += n;
    }
    got
}

/// A file's bytes held in memory and read as a file is, piece by piece ([`TextReader`]):
/// for tests of the readers, with a window as small as they like.
pub struct BytesReader {
    bytes: Vec<u8>,
    layout: Layout,
    window: usize,
}

impl BytesReader {
    /// Surveys `bytes` (in chunks of `chunk` bytes) for reading with windows of `window`.
    pub fn new(bytes: Vec<u8>, chunk: usize, window: usize) -> (BytesReader, Vec<DecodeNote>) {
        let mut survey = Survey::new();
        for c in bytes.chunks(chunk.max(1)) {
            survey.feed(c);
        }
        let (layout, diags) = survey.finish();
        (BytesReader { bytes, layout, window }, diags)
    }

    /// How the bytes decode.
    pub fn layout(&self) -> &Layout {
        &self.layout
    }
}

impl TextReader for BytesReader {
    fn len(&self) -> usize {
        self.layout.text_len
    }

    fn read(&self, at: usize, want: usize, buf: &mut String) -> usize {
        let mut read_at = |off: u64, most: usize, b: &mut Vec<u8>| {
            let off = (off as usize).min(self.bytes.len());
            let n = most.min(self.bytes.len() - off);
            b.extend_from_slice(&self.bytes[off..off + n]);
            n
        };
        self.layout.read(at, want, &mut read_at, buf).unwrap_or(at)
    }

    fn window(&self) -> usize {
        self.window
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_end_of_file_marks_after_the_last_line_are_blanks() {
        // A DOS-era file closed by Ctrl-Z after the tape end `%`, or on a line of its own:
        // blanked, same length, read whole or piece by piece; a mark inside the program stays
        // (the lexer reports it), and so does one before the last line.
        for (input, want) in [
            (&b"%\nO1\nM30\n%\x1a"[..], "%\nO1\nM30\n% "),
            (b"G0 X1\r\n\x1a\x1a", "G0 X1\r\n  "),
            (b"G0 X1\r\n\x1a\r\n\t\x1a \n", "G0 X1\r\n \r\n\t  \n"),
            (b"G0 X1\n", "G0 X1\n"),
            (b"G0 \x1a X1\n", "G0 \x1a X1\n"),
            (b"G0 X1\n\x1a\nM30\n", "G0 X1\n\x1a\nM30\n"),
            (b"(\xe9)\nM30\n%\x1a", "(\u{e9})\nM30\n% "),
            (b"\x1a", " "),
        ] {
            assert_eq!(decode(input).0.text, want);
            assert_eq!(decode_owned(input.to_vec()).0.text, want);
            for chunk in [1, 3, 64] {
                let (r, _) = BytesReader::new(input.to_vec(), chunk, 4);
                let mut got = String::new();
                while got.len() < r.len() {
                    let at = got.len();
                    r.read(at, 2, &mut got);
                }
                assert_eq!(got, want, "read piece by piece in chunks of {chunk}");
            }
        }
    }

    #[test]
    fn a_stray_carriage_return_is_a_blank_unless_the_file_ends_lines_in_cr() {
        let (t, _) = decode(b"N1 ;COMMENT\r REST\nN2 G0\r\nN3\r");
        assert_eq!(t.text, "N1 ;COMMENT  REST\nN2 G0\r\nN3 ");
        let (t, _) = decode_owned(b"N1 G0\rN2 G1\r".to_vec());
        assert_eq!(t.text, "N1 G0\rN2 G1\r", "a CR-only file keeps its line ends");
    }

    #[test]
    fn owned_decoding_agrees_with_borrowed() {
        for input in [&b"\xEF\xBB\xBFG0 X1\n"[..], b"G0 (caf\xe9)\n", b"G0\0\x01", b"", "G1 (é)".as_bytes()] {
            let (a, da) = decode(input);
            let (b, db) = decode_owned(input.to_vec());
            assert_eq!((a.text, a.encoding, da), (b.text, b.encoding, db));
        }
    }

    #[test]
    fn line_col_handles_crlf_cr_and_multibyte() {
        let text = "G0\r\nX1 (é)\rY2\nZ3";
        let idx = LineIndex::new(text);
        assert_eq!(idx.line_col(text, 0), LineCol { line: 1, col: 1 });
        assert_eq!(idx.line_col(text, 4), LineCol { line: 2, col: 1 });
        let after_e = text.find(')').unwrap() as u32;
        assert_eq!(idx.line_col(text, after_e), LineCol { line: 2, col: 6 });
        assert_eq!(idx.line_col(text, text.find('Y').unwrap() as u32).line, 3);
        assert_eq!(idx.line_text(text, 2), "X1 (é)");
        assert_eq!(idx.line_col(text, text.find('Z').unwrap() as u32).line, 4);
    }

    #[test]
    fn decode_bom_latin1_and_binary() {
        let (s, d) = decode(b"\xEF\xBB\xBFG0 X1");
        assert_eq!((s.text.as_str(), s.encoding, d.len()), ("G0 X1", Encoding::Utf8, 0));
        let (s, d) = decode(b"(M\xfcller \x80)\nG0");
        assert_eq!(s.text, "(Müller €)\nG0");
        assert_eq!((s.encoding, d[0]), (Encoding::Windows1252, DecodeNote::NotUtf8 { at: 2 }));
        let (s, d) = decode(b"\x7fELF\x02\x01\x01\x00\x00");
        assert_eq!((s.encoding, d[0]), (Encoding::Binary, DecodeNote::Binary));
    }

    /// Bytes of the kinds decoding distinguishes: line ends, stray returns, multi-byte
    /// UTF-8, Windows-1252 bytes, a byte-order mark, NULs, end-of-file marks.
    fn program_bytes() -> impl proptest::strategy::Strategy<Value = Vec<u8>> {
        use proptest::prelude::*;
        let piece = prop_oneof![
            Just(b"G1 X1.5\n".to_vec()),
            Just(b"\r\n".to_vec()),
            Just(b"\r".to_vec()),
            Just(b"\n".to_vec()),
            Just("(é€)".as_bytes().to_vec()),
            Just(b"\xe9\x80".to_vec()),
            Just(b"\xEF\xBB\xBF".to_vec()),
            Just(b"\xE2\x82".to_vec()),
            Just(vec![0u8]),
            Just(b"\x1a".to_vec()),
            Just(b"%\x1a".to_vec()),
            proptest::collection::vec(any::<u8>(), 0..4),
            "[ -~]{0,12}".prop_map(String::into_bytes),
        ];
        proptest::collection::vec(piece, 0..40).prop_map(|v| v.concat())
    }

    proptest::proptest! {
        #[test]
        fn surveyed_reading_gives_the_decoded_text(bytes in program_bytes(), chunk in 1usize..9, window in 1usize..13, step in 1usize..17) {
            let (whole, dw) = decode(&bytes);
            let (r, dr) = BytesReader::new(bytes.clone(), chunk, window);
            proptest::prop_assert_eq!(&dw, &dr);
            proptest::prop_assert_eq!(r.layout().encoding, whole.encoding);
            proptest::prop_assert_eq!(r.len(), whole.text.len());
            // Piece by piece, from the start.
            let mut got = String::new();
            while got.len() < r.len() {
                let at = got.len();
                let start = r.read(at, step, &mut got);
                proptest::prop_assert_eq!(start, at);
                proptest::prop_assert!(got.len() > at);
            }
            proptest::prop_assert_eq!(&got, &whole.text);
            // From any offset: the next character boundary on.
            for at in 0..=whole.text.len() {
                let mut piece = String::new();
                let start = r.read(at, step, &mut piece);
                let boundary = (at..=whole.text.len()).find(|&b| whole.text.is_char_boundary(b)).unwrap_or(whole.text.len());
                proptest::prop_assert_eq!(start, boundary);
                proptest::prop_assert!(whole.text[start..].starts_with(&piece));
                proptest::prop_assert!(piece.len() >= step.min(whole.text.len() - start));
            }
            let t = Text::Read(&r);
            proptest::prop_assert_eq!(t.trimmed_end(), whole.text.trim_end().len());
            proptest::prop_assert_eq!(t.head(), Text::Whole(&whole.text).head());
        }

        #[test]
        fn located_lines_agree_with_the_index(bytes in program_bytes(), window in 1usize..13, picks in proptest::collection::vec(0u32..400, 0..8)) {
            let (whole, _) = decode(&bytes);
            let text = whole.text.as_str();
            let idx = LineIndex::new(text);
            let mut offsets: Vec<u32> = picks.iter().map(|&p| p.min(text.len() as u32 + 2)).collect();
            offsets.sort_unstable();
            let want: Vec<LineCol> = offsets.iter().map(|&o| idx.line_col(text, o)).collect();
            proptest::prop_assert_eq!(&locate(Text::Whole(text), &offsets), &want);
            let (r, _) = BytesReader::new(bytes.clone(), 5, window);
            proptest::prop_assert_eq!(&locate(Text::Read(&r), &offsets), &want);
        }
    }

    #[test]
    fn a_survey_of_a_large_latin1_file_reads_from_its_marks() {
        // Past several marks: every piece decodes as the whole text does.
        let mut bytes = Vec::new();
        for i in 0..30_000u32 {
            bytes.extend_from_slice(format!("N{i} (M\u{fc}LLER)\r\n").as_bytes());
            if i % 7 == 0 {
                bytes.extend_from_slice(b"X1 (\xe9\x80)\r\n");
            }
        }
        let (whole, _) = decode(&bytes);
        let (r, _) = BytesReader::new(bytes, 1 << 16, 4096);
        assert_eq!(r.layout().encoding, Encoding::Windows1252);
        for at in (0..whole.text.len()).step_by(9_973) {
            let mut piece = String::new();
            let start = r.read(at, 300, &mut piece);
            assert!(whole.text[start..].starts_with(&piece), "at {at}");
            assert!(start - at < 3);
        }
    }
}

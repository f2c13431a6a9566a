//! Source text: byte ranges, line/column lookup and decoding of raw program bytes.
//!
//! Every position in ncplan is a byte offset into the *decoded* text (UTF-8). Line and
//! column numbers are computed only when a diagnostic is rendered or stored.

use serde::{Deserialize, Serialize};

use crate::diag::{Code, Diagnostic};

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

/// Decodes raw program bytes. Never fails: binary input yields an empty text and an error
/// diagnostic; non-UTF-8 input is decoded as Windows-1252 with a note.
pub fn decode(bytes: &[u8]) -> (SourceText, Vec<Diagnostic>) {
    let mut diags = Vec::new();
    let body = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    if looks_binary(body) {
        diags.push(Diagnostic::new(
            Code::BinaryInput,
            TextRange::default(),
            "the file looks like binary data (NUL or control bytes), not a part program",
        ));
        return (SourceText { text: String::new(), encoding: Encoding::Binary }, diags);
    }
    match std::str::from_utf8(body) {
        Ok(s) => (SourceText { text: blank_stray_returns(s.to_owned()), encoding: Encoding::Utf8 }, diags),
        Err(e) => {
            let text: String = body.iter().map(|&b| windows_1252(b)).collect();
            let msg = format!("the file is not valid UTF-8 (first at byte {}); it was read as Windows-1252 (Latin-1)", e.valid_up_to());
            diags.push(Diagnostic::new(Code::NotUtf8, TextRange::default(), msg));
            (SourceText { text: blank_stray_returns(text), encoding: Encoding::Windows1252 }, diags)
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

/// [`decode`] that takes the bytes and, for UTF-8 input (the common case), keeps them as the
/// text without a copy: a large program is held in memory once.
pub fn decode_owned(mut bytes: Vec<u8>) -> (SourceText, Vec<Diagnostic>) {
    if bytes.starts_with(b"\xEF\xBB\xBF") {
        bytes.drain(..3);
    }
    if looks_binary(&bytes) {
        return decode(&bytes);
    }
    match String::from_utf8(bytes) {
        Ok(text) => (SourceText { text: blank_stray_returns(text), encoding: Encoding::Utf8 }, Vec::new()),
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

#[cfg(test)]
mod tests {
    use super::*;

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
        assert_eq!((s.encoding, d[0].code), (Encoding::Windows1252, Code::NotUtf8));
        let (s, d) = decode(b"\x7fELF\x02\x01\x01\x00\x00");
        assert_eq!((s.encoding, d[0].code), (Encoding::Binary, Code::BinaryInput));
    }
}

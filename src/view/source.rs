//! Source views: G-code colouring by token, and the two programs' lines aligned so that
//! cosmetic differences (block numbers, comments, spacing, case, number spellings) are told
//! from real ones.

/// What a piece of a line is, for its colour.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Token {
    /// A comment (`(…)`, `;…`).
    Comment,
    /// A block number (`N100`) or a leading line number.
    BlockNumber,
    /// A G code or another preparatory keyword.
    GCode,
    /// An M code.
    MCode,
    /// A tool, feed or speed word (`T1`, `F800`, `S1200`).
    Technology,
    /// An axis or arc word (`X10.5`, `I-3`).
    Axis,
    /// Anything else (variables, keywords, blanks).
    Plain,
}

impl Token {
    /// The CSS class (`c`, `n`, `g`, `m`, `t`, `a`); plain text has none.
    pub fn class(self) -> Option<&'static str> {
        match self {
            Token::Comment => Some("c"),
            Token::BlockNumber => Some("n"),
            Token::GCode => Some("g"),
            Token::MCode => Some("m"),
            Token::Technology => Some("t"),
            Token::Axis => Some("a"),
            Token::Plain => None,
        }
    }
}

/// Whether `c` is a Unicode bidirectional control (embeddings, overrides, isolates, marks),
/// which would reorder what a reader sees of program text.
fn bidi_control(c: char) -> bool {
    matches!(c, '\u{202A}'..='\u{202E}' | '\u{2066}'..='\u{2069}' | '\u{200E}' | '\u{200F}' | '\u{061C}')
}

/// Program text as it is to be shown: each bidirectional control written out as `[U+202E]`,
/// so that it is seen and reorders nothing. Other text is borrowed as it is.
pub fn visible(text: &str) -> std::borrow::Cow<'_, str> {
    if !text.chars().any(bidi_control) {
        return std::borrow::Cow::Borrowed(text);
    }
    let mut out = String::with_capacity(text.len() + 16);
    for c in text.chars() {
        if bidi_control(c) {
            out.push_str(&format!("[U+{:04X}]", u32::from(c)));
        } else {
            out.push(c);
        }
    }
    std::borrow::Cow::Owned(out)
}

/// Splits a line into coloured pieces (byte ranges that cover the line, in order).
pub fn colour(line: &str) -> Vec<(Token, std::ops::Range<usize>)> {
    let b = line.as_bytes();
    let mut out: Vec<(Token, std::ops::Range<usize>)> = Vec::new();
    let push = |t: Token, r: std::ops::Range<usize>, out: &mut Vec<(Token, std::ops::Range<usize>)>| {
        if let Some(last) = out.last_mut()
            && last.0 == t
            && last.1.end == r.start
        {
            last.1.end = r.end;
        } else if !r.is_empty() {
            out.push((t, r));
        }
    };
    let mut i = 0;
    let mut first_word = true;
    while i < b.len() {
        let c = b[i];
        if c == b'(' {
            let end = line[i..].find(')').map_or(b.len(), |e| i + e + 1);
            push(Token::Comment, i..end, &mut out);
            i = end;
        } else if c == b';' {
            push(Token::Comment, i..b.len(), &mut out);
            i = b.len();
        } else if c.is_ascii_alphabetic() && b.get(i + 1).is_some_and(|n| n.is_ascii_digit() || matches!(n, b'-' | b'+' | b'.' | b'#')) {
            let mut end = i + 1;
            while end < b.len() && (b[end].is_ascii_digit() || matches!(b[end], b'-' | b'+' | b'.' | b'#')) {
                end += 1;
            }
            let t = match c.to_ascii_uppercase() {
                b'N' if first_word => Token::BlockNumber,
                b'G' => Token::GCode,
                b'M' => Token::MCode,
                b'T' | b'F' | b'S' | b'D' | b'H' => Token::Technology,
                b'X' | b'Y' | b'Z' | b'I' | b'J' | b'K' | b'A' | b'B' | b'C' | b'U' | b'V' | b'W' | b'R' | b'Q' | b'P' => Token::Axis,
                _ => Token::Plain,
            };
            push(t, i..end, &mut out);
            first_word = false;
            i = end;
        } else if c.is_ascii_digit() && first_word {
            // A Heidenhain line number.
            let mut end = i;
            while end < b.len() && b[end].is_ascii_digit() {
                end += 1;
            }
            push(Token::BlockNumber, i..end, &mut out);
            first_word = false;
            i = end;
        } else {
            let ch = line[i..].chars().next().map_or(1, char::len_utf8);
            if !c.is_ascii_whitespace() {
                first_word = false;
            }
            push(Token::Plain, i..i + ch, &mut out);
            i += ch;
        }
    }
    out
}

/// A line as the machine reads it: no comments, block numbers or blanks, upper case, numbers
/// in one spelling (`X10.` and `X10.000` are `X10`).
pub fn normalize(line: &str) -> String {
    let mut out = String::new();
    for (t, r) in colour(line) {
        let piece = &line[r];
        match t {
            Token::Comment | Token::BlockNumber => {}
            Token::GCode | Token::MCode | Token::Technology | Token::Axis => {
                let (letter, value) = piece.split_at(1);
                out.push_str(&letter.to_ascii_uppercase());
                match value.parse::<f64>() {
                    Ok(v) => out.push_str(&crate::diff::num(v)),
                    Err(_) => out.push_str(value),
                }
            }
            Token::Plain => out.extend(piece.chars().filter(|c| !c.is_whitespace()).map(|c| c.to_ascii_uppercase())),
        }
    }
    out
}

/// How a line compares with its counterpart.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LineState {
    /// The same text.
    Same,
    /// Other text, the same for the machine (block numbers, comments, spelling): greyed.
    Cosmetic,
    /// Only in this program, or read differently.
    Differs,
}

/// Aligned lines of two programs: for each line of each, its state and its counterpart
/// (0-based), where it has one.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Alignment {
    /// For each line of the original.
    pub original: Vec<(LineState, Option<usize>)>,
    /// For each line of the edited program.
    pub edited: Vec<(LineState, Option<usize>)>,
}

/// The largest middle (lines that differ after the common start and end, product of both
/// counts) aligned line by line; beyond it, lines are paired in order.
const ALIGN_CELLS: usize = 4_000_000;

/// Aligns the lines of two programs: the common start and end, then a longest common
/// subsequence of the normalized lines in between.
pub fn align(a: &[&str], b: &[&str]) -> Alignment {
    // Equal text is the common case of long programs: only the lines between the common
    // start and end of equal (or equally read) lines are normalized for the LCS.
    let same = |i: usize, j: usize| a[i] == b[j] || normalize(a[i]) == normalize(b[j]);
    let mut out = Alignment { original: vec![(LineState::Differs, None); a.len()], edited: vec![(LineState::Differs, None); b.len()] };
    let pair = |i: usize, j: usize, out: &mut Alignment| {
        let state = if a[i] == b[j] { LineState::Same } else { LineState::Cosmetic };
        out.original[i] = (state, Some(j));
        out.edited[j] = (state, Some(i));
    };
    let mut start = 0;
    while start < a.len() && start < b.len() && same(start, start) {
        pair(start, start, &mut out);
        start += 1;
    }
    let mut end = 0;
    while end < a.len() - start && end < b.len() - start && same(a.len() - 1 - end, b.len() - 1 - end) {
        pair(a.len() - 1 - end, b.len() - 1 - end, &mut out);
        end += 1;
    }
    let na: Vec<String> = a[start..a.len() - end].iter().map(|l| normalize(l)).collect();
    let nb: Vec<String> = b[start..b.len() - end].iter().map(|l| normalize(l)).collect();
    let (ma, mb) = (&na[..], &nb[..]);
    if ma.len().saturating_mul(mb.len()) <= ALIGN_CELLS {
        // LCS table, from the end.
        let w = mb.len() + 1;
        let mut t = vec![0u32; (ma.len() + 1) * w];
        for i in (0..ma.len()).rev() {
            for j in (0..mb.len()).rev() {
                t[i * w + j] = if ma[i] == mb[j] { t[(i + 1) * w + j + 1] + 1 } else { t[(i + 1) * w + j].max(t[i * w + j + 1]) };
            }
        }
        let (mut i, mut j) = (0, 0);
        while i < ma.len() && j < mb.len() {
            if ma[i] == mb[j] {
                pair(start + i, start + j, &mut out);
                i += 1;
                j += 1;
            } else if t[(i + 1) * w + j] >= t[i * w + j + 1] {
                i += 1;
            } else {
                j += 1;
            }
        }
    } else {
        for k in 0..ma.len().min(mb.len()) {
            if ma[k] == mb[k] {
                pair(start + k, start + k, &mut out);
            } else {
                out.original[start + k].1 = Some(start + k);
                out.edited[start + k].1 = Some(start + k);
            }
        }
    }
    out
}

/// The 0-based line ranges to show of a program of `total` lines: all of it when it has at
/// most `whole` lines, else its first `context` lines and `context` lines around each line
/// of interest (1-based), merged.
pub fn windows(total: usize, interest: &[usize], whole: usize, context: usize) -> Vec<std::ops::Range<usize>> {
    if total <= whole {
        return std::iter::once(0..total).collect();
    }
    let mut ranges: Vec<std::ops::Range<usize>> = std::iter::once(0..context.min(total)).collect();
    let mut lines: Vec<usize> = interest.iter().filter(|l| **l >= 1 && **l <= total).map(|l| l - 1).collect();
    lines.sort_unstable();
    for l in lines {
        let r = l.saturating_sub(context)..(l + context + 1).min(total);
        match ranges.last_mut() {
            Some(last) if r.start <= last.end => last.end = last.end.max(r.end),
            _ => ranges.push(r),
        }
    }
    ranges
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bidirectional_controls_are_written_out() {
        assert_eq!(visible("(\u{202E}DESREVER\u{202C}) \u{2066}X\u{2069}"), "([U+202E]DESREVER[U+202C]) [U+2066]X[U+2069]");
        assert!(matches!(visible("G1 X10 (ÄÖ)"), std::borrow::Cow::Borrowed(_)));
    }

    #[test]
    fn colours_a_block() {
        let line = "N10 G1 X10.5 F800 M8 (FACE <b>)";
        let got: Vec<(Token, &str)> = colour(line).into_iter().map(|(t, r)| (t, &line[r])).collect();
        assert_eq!(
            got,
            vec![
                (Token::BlockNumber, "N10"),
                (Token::Plain, " "),
                (Token::GCode, "G1"),
                (Token::Plain, " "),
                (Token::Axis, "X10.5"),
                (Token::Plain, " "),
                (Token::Technology, "F800"),
                (Token::Plain, " "),
                (Token::MCode, "M8"),
                (Token::Plain, " "),
                (Token::Comment, "(FACE <b>)"),
            ]
        );
    }

    #[test]
    fn block_numbers_comments_and_spellings_are_cosmetic() {
        assert_eq!(normalize("N10 G1 X10. (A)"), normalize("n20 g1 x10.000 (B)"));
        assert_ne!(normalize("G1 X10"), normalize("G1 X10.1"));
        let a = ["%", "O1234", "N10 G0 X90. Y20.", "N20 G1 Z-1 F800", "M30"];
        let b = ["%", "O1234", "N15 G0 X83 Y20", "G1 Z-1. F800 (OP)", "M30"];
        let al = align(&a, &b);
        assert_eq!(al.original[1], (LineState::Same, Some(1)));
        assert_eq!(al.edited[2], (LineState::Differs, None));
        assert_eq!(al.edited[3], (LineState::Cosmetic, Some(3)));
        assert_eq!(al.edited[4], (LineState::Same, Some(4)));
    }

    #[test]
    fn windows_merge_around_lines_of_interest() {
        assert_eq!(windows(10, &[3], 100, 2), vec![0..10]);
        assert_eq!(windows(1000, &[50, 53, 900], 100, 5), vec![0..5, 44..58, 894..905]);
    }
}

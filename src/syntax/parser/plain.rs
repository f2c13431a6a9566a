//! The fast path for the common block, plain words only (`X1.5 Y-2 Z0.25`): `plain_block`
//! reads it in one tight loop, and `plain_block_number` tells when a block number needs no
//! general rule. Its door is `plain_block`, which `Parser::next_block` and
//! `Parser::plain_lines` call.

use super::super::{Block, Value, Word, WordMode};
use super::numbers::plain_number;
use super::{PlainLine, PlainWord};
use crate::dialect::{Dialect, Role, SkipPosition};
use crate::text::TextRange;

/// The block-number letter (`N`) when `N` and digits can only be a block number in `d`, as
/// [`Dialect::plain_role`] tells plain words: no label, variable, keyword, cycle, long address,
/// axis setting, call by name or lexer mark can start with the letter.
pub(super) fn plain_block_number(d: &Dialect) -> Option<u8> {
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
pub(super) fn plain_block(
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
        let signed = negative | (sign == b'+');
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

/// X, Y and Z are the first three roles, in that order: a [`PlainLine`] finds a word's axis
/// from its role's number.
const _: () = assert!(Role::X as usize == 0 && Role::Y as usize == 1 && Role::Z as usize == 2);

/// Where [`plain_block`] puts what it reads.
pub(super) trait PlainWords {
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
        // X, Y and Z are the first roles: their number is the axis (asserted below).
        let axis = role as usize;
        if let Some(v) = self.axes.get_mut(axis) {
            // An axis written twice: the block goes the general way, which says what it means.
            let read = self.read;
            if (read >> axis) & 1 != 0 {
                return false;
            }
            *v = value;
            self.read = read | 1 << axis;
            self.points[axis] = decimal;
            return true;
        }
        let Some(w) = self.words.get_mut(self.len) else { return false };
        *w = PlainWord { role, value, decimal };
        self.len += 1;
        true
    }
}

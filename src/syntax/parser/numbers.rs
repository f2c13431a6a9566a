//! Literal numbers: whole numbers after an address (`N120`), word values with a sign, a
//! point, blanks where the dialect allows them and an exponent (`10EX3`), and constants in
//! another base (`'H1F'`). Its doors are `Lexer::number`, `Lexer::integer` and
//! `Lexer::radix_constant`, and for the fast paths `plain_number`, which reads the common
//! number in one pass (from one 64-bit word when it is short).

use super::Lexer;
use crate::diag::Code;

impl Lexer<'_, '_> {
    pub(super) fn integer(&mut self, start: usize) -> Option<u32> {
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

    /// Reads a literal number: sign, digits, at most one point; returns it and whether a
    /// decimal point was written.
    pub(super) fn number(&mut self) -> Option<(f64, bool)> {
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
        // A decimal comma (`L Z+100,000`, older TNCs) leaves the fast path at the comma.
        let comma = self.dialect.lexical.numbers.decimal_comma;
        let comma_at = |b: &[u8], j: usize| comma && b.get(j) == Some(&b',') && b.get(j + 1).is_some_and(u8::is_ascii_digit);
        if let Some((v, end, pt)) = plain_number(self.b, self.i, spaces).filter(|&(_, end, pt)| pt || !comma_at(self.b, end)) {
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
                Some(b',') if !point && comma_at(self.b, self.i) => {
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
            let s: String = self.text[start..self.i]
                .chars()
                .filter(|c| c.is_ascii_digit() || matches!(c, '.' | ','))
                .map(|c| if c == ',' { '.' } else { c })
                .collect();
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
    pub(super) fn radix_constant(&mut self, quote: u8, hex: u8, binary: u8) -> Option<f64> {
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
}

/// Reads the digits from `*j` on into `m` (ten times `m` plus each digit, wrapping past 19
/// digits) and steps past them.
#[inline(always)]
pub(super) fn digits(b: &[u8], j: &mut usize, m: &mut u64) {
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

/// The top bit of every byte of `x` (a word of bytes, each with `0` taken out by exclusive or:
/// a digit 0 to 9, any other byte 10 or more) that is no digit: 10 and up with 0x76 added, or
/// 0x80 and up already. Only a byte of 0x8A and up carries into the next, and it is no digit
/// itself: every byte up to the second that is no digit (the first a point, 0x1E) is exact.
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
pub(super) fn short_number(b: &[u8], i: usize) -> Option<(u64, usize, usize, bool, usize)> {
    const ZEROS: u64 = 0x3030_3030_3030_3030;
    let w = u64::from_le_bytes(*b.get(i..)?.first_chunk::<8>()?);
    // `0` taken out of each byte by exclusive or: no borrow between bytes, as a subtraction
    // has below any byte under `0`, so the point's flag and the next one are both exact.
    let x = w ^ ZEROS;
    let stops = not_digits(x);
    let at = (stops.trailing_zeros() / 8) as usize;
    if at == 8 {
        return None;
    }
    if (w >> (8 * at)) as u8 != b'.' {
        // Digits only: they sit at the top of the word, zeros (leading zeros) below.
        return (at > 0).then(|| (eight_digits(x << (8 * (8 - at))), at, 0, false, i + at));
    }
    // The digits after the point end at the next byte that is no digit.
    let end = ((stops & (stops - 1)).trailing_zeros() / 8) as usize;
    let n = end - 1;
    if end == 8 || n == 0 {
        return None;
    }
    // The bytes above the point moved down one, over it.
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
pub(super) fn plain_number(b: &[u8], i: usize, spaces: bool) -> Option<(f64, usize, bool)> {
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

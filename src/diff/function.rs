//! A parameter function's keyword code: Heidenhain `FN 17: SYSWRITE ID50 NR1 IDXQ8 = +0`
//! (write system data: ID50 is the tool table, NR the column, IDX the tool), `FN 27:
//! TABWRITE 5/"L,R" = Q2` (write a table's row). The TNC user's manuals write the function's
//! number, a colon and its keyword, then its values and `; comment` ("Q parameter
//! programming: additional functions"). An edit of such a statement is that function's
//! change, told whole by the dictionary's name for it (`typed::parameter_function`), not as a
//! variable `IDXQ8` set.

use super::statement::{Sort, Token};
use crate::dialect::Dialect;

/// The keyword code written after a parameter function's number (`FN17:SYSWRITE`: the code
/// `SYSWRITE`), by the dictionary: the number's code takes a value (`FN`), the keyword is a
/// code of its own.
pub(super) fn code_after_number(tok: &Token, d: &Dialect) -> Option<usize> {
    if !matches!(tok.sort, Sort::Other | Sort::Assign) {
        return None;
    }
    let (head, rest) = tok.text.split_once(':')?;
    let letters = head.trim_end_matches(|c: char| c.is_ascii_digit());
    if letters.is_empty() || letters.len() == head.len() || rest.is_empty() {
        return None;
    }
    let numbered = d.keyword_codes().any(|(_, spec)| spec.value_role.is_some() && spec.text.eq_ignore_ascii_case(letters));
    // The keyword, then its values, perhaps written against it (`TABWRITE5/"L,R"=Q2`).
    let (i, _) = d.keyword_codes().find(|(_, spec)| {
        let k = spec.text.split(' ').next().unwrap_or_default();
        rest.len() >= k.len()
            && rest.is_char_boundary(k.len())
            && rest[..k.len()].eq_ignore_ascii_case(k)
            && !rest[k.len()..].starts_with(|c: char| c.is_ascii_alphabetic() || c == '-')
    })?;
    numbered.then_some(i)
}

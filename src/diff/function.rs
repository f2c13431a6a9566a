//! A parameter function's keyword code: Heidenhain `FN 17: SYSWRITE ID50 NR1 IDXQ8 = +0`
//! (write system data: ID50 is the tool table, NR the column, IDX the tool), `FN 27:
//! TABWRITE 5/"L,R" = Q2` (write a table's row). The TNC user's manuals write the function's
//! number, a colon and its keyword, then its values and `; comment` ("Q parameter
//! programming: additional functions"). An edit of such a statement is that function's
//! change, told whole by the dictionary's name for it, not as a variable `IDXQ8` set.

use super::statement::{Sort, Token};
use super::typed::{Typed, keyword_function};
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

/// The statement's change as its function's, where the function is a machine function the
/// plan has no kind for (a system datum or a table row written), or a read of data only the
/// machine has into a parameter (`FN 18: SYSREAD Q1600 = ID50 NR0 IDXQ1`, told whole as a
/// statement, not as the parameter set to `ID50`): the words that differ on each side.
pub(super) fn whole(diffs: &[(Option<Token>, Option<Token>)], code: Option<usize>, d: &Dialect) -> Option<Typed> {
    let (i, spec) = d.keyword_codes().find(|&(i, _)| Some(i) == code)?;
    let head = Token { key: spec.text.clone(), value: String::new(), text: spec.text.clone(), sort: Sort::Other };
    let (kind, field) = match keyword_function(&head, d) {
        Some(field) => (super::ChangeKind::MachineFunctionChanged, field),
        None if d.codes[i].meaning == crate::dialect::Meaning::MachineDataRead => (super::ChangeKind::StatementChanged, "statement".into()),
        None => return None,
    };
    let side = |after: bool| {
        let words = diffs.iter().filter_map(|(x, y)| if after { y.as_ref() } else { x.as_ref() });
        words.map(|t| t.text.as_str()).collect::<Vec<_>>().join(" ")
    };
    Some(Typed { kind, field, before: side(false), after: side(true) })
}

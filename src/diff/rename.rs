//! Labels renamed consistently: a subprogram renumbered with every call of it (`O1` → `O1000`
//! with `M98 P1` → `M98 P1000`), an O-word's label on all its statements (`o250 if` … `o250
//! endif` → `o400 …`, `o<a> call` with `o<a> sub` → `o<b> …`), a block number a jump names
//! with the jump (`GOTO 10` → `GOTO 20` with `N10` → `N20`). The control runs the same blocks in
//! the same order: the differing statements only spell the names otherwise, so they are no
//! change.
//!
//! A rename is taken only when it is one to one over both whole programs: each old label
//! becomes one new label in every statement that names it, the old label is defined in the
//! original and named nowhere in the edited program, the new one defined in the edited program
//! and named nowhere in the original. A call of a program in another file renamed alone
//! (`M98 P1` → `M98 P1000`, no `O1000` here) calls another program: a change; so is a
//! subroutine called by name (`o<name> sub`) renamed where its file does not call it (its
//! callers, in other files, call it by that name).

use std::collections::{BTreeMap, BTreeSet};

use super::statement::{self, Sort, Stmt, Token};
use super::typed::{About, about};
use crate::dialect::{Dialect, Meaning, Statement};

/// The labels a statement's tokens name: (token index, label). Programs and O-words as `O…`
/// (`O1000`, `O<NAME>`), block numbers as `N…`.
pub(super) fn labels(tokens: &[Token], d: &Dialect) -> Vec<(usize, String)> {
    let mut out = Vec::new();
    if let Some(l) = tokens.first().and_then(|t| o_label(&t.text)) {
        out.push((0, l));
    }
    let code = |m: fn(Meaning) -> bool| tokens.iter().any(|t| matches!(about(t, d), About::Code(x) if m(x)));
    let calls =
        code(|m| matches!(m, Meaning::SubprogramCall | Meaning::LocalSubprogramCall | Meaning::MacroCall | Meaning::ModalMacroCall));
    let returns = code(|m| m == Meaning::SubprogramReturn);
    let jumps: Vec<&str> = d
        .macros
        .statements
        .iter()
        .filter(|(_, s)| matches!(s, Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet))
        .map(|(k, _)| k.as_str())
        .collect();
    let number = |t: &Token| t.sort == Sort::Word && !t.value.is_empty() && t.value.bytes().all(|c| c.is_ascii_digit());
    for (i, t) in tokens.iter().enumerate() {
        if !number(t) {
            continue;
        }
        // A number as the control reads it: `GOTO0800` jumps to `N800` (leading zeros are no
        // digits of it), as a block's and a program's own numbers are written here.
        let value = match t.value.trim_start_matches('0') {
            "" => "0",
            v => v,
        };
        let label = match t.key.as_str() {
            // The program a call names (`M98 P1000`, `G65 P9010`), or alone on its block (a
            // control that calls by `P` without `M98`).
            "P" if calls || tokens.len() == 1 => format!("O{value}"),
            // The block a return or a call starts at (`M99 P20`, `M98 Q2100`).
            "P" if returns => format!("N{value}"),
            "Q" if calls => format!("N{value}"),
            k if jumps.iter().any(|j| j.eq_ignore_ascii_case(k)) => format!("N{value}"),
            _ => continue,
        };
        out.push((i, label));
    }
    out
}

/// The O-word label at the start of a statement's first token (`O100IF[…]`, `O<NAME>CALL[…]`,
/// `O1`).
fn o_label(text: &str) -> Option<String> {
    let rest = text.strip_prefix('O')?;
    if rest.starts_with('<') {
        let end = rest.find('>')?;
        return Some(format!("O{}", &rest[..=end]));
    }
    let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
    (digits > 0).then(|| format!("O{}", rest[..digits].trim_start_matches('0')))
}

/// A token with its label written as `new` (`P1` → `P1000`, `O1IF[…]` → `O1000IF[…]`).
fn relabel(t: &Token, new: &str, first: bool) -> String {
    if first && let Some(l) = o_label(&t.text) {
        let len = if l.contains('<') { l.len() } else { 1 + t.text[1..].bytes().take_while(u8::is_ascii_digit).count() };
        return format!("{new}{}", &t.text[len..]);
    }
    format!("{}{}", t.key, &new[1..])
}

/// The differing statement pairs (original index, edited index) that only rename labels
/// consistently over both programs; `pairs` are the hunks' paired statements.
pub(super) fn renamed(pairs: &[(usize, usize)], (ta, tb): (&str, &str), (sa, sb): (&[Stmt], &[Stmt]), d: &Dialect) -> Vec<(usize, usize)> {
    let mut map: BTreeMap<String, String> = BTreeMap::new();
    let mut back: BTreeMap<String, String> = BTreeMap::new();
    let mut taken = Vec::new();
    for &(i, j) in pairs {
        let (x, y) =
            (statement::tokens_in(&statement::text_of(ta, d, &sa[i]), d), statement::tokens_in(&statement::text_of(tb, d, &sb[j]), d));
        let (lx, ly) = (labels(&x, d), labels(&y, d));
        if x.len() != y.len() || lx.len() != ly.len() || lx.is_empty() || lx.iter().zip(&ly).any(|(p, q)| p.0 != q.0) {
            continue;
        }
        // Every token the same but the labels, and the labels written anew.
        let same_rest = x.iter().zip(&y).enumerate().all(|(k, (p, q))| match lx.iter().position(|l| l.0 == k) {
            Some(n) => relabel(p, &ly[n].1, k == 0) == q.text,
            None => p.text == q.text,
        });
        if !same_rest || lx.iter().zip(&ly).all(|(p, q)| p.1 == q.1) {
            continue;
        }
        let mut consistent = true;
        for ((_, old), (_, new)) in lx.iter().zip(&ly) {
            consistent &= *map.entry(old.clone()).or_insert_with(|| new.clone()) == *new;
            consistent &= *back.entry(new.clone()).or_insert_with(|| old.clone()) == *old;
        }
        if !consistent {
            return Vec::new();
        }
        taken.push((i, j));
    }
    map.retain(|o, n| o != n);
    if map.is_empty() {
        return Vec::new();
    }
    // One to one over the whole programs: the old labels defined in the original and named
    // nowhere in the edited one, the new ones the reverse.
    let olds: BTreeSet<String> = map.keys().cloned().collect();
    let news: BTreeSet<String> = map.values().cloned().collect();
    let (ua, ub) = (label_uses(ta, d, &olds, &news), label_uses(tb, d, &news, &olds));
    let whole = map.iter().all(|(o, n)| {
        ua.0.get(o).is_some_and(|u| u.defined) && !ua.1.contains_key(n) && ub.0.get(n).is_some_and(|u| u.defined) && !ub.1.contains_key(o)
    });
    // A subroutine called by its name (`o<name> sub` … `o<name> endsub`) that no statement
    // here calls is called from other programs by that name, which they must then change:
    // LinuxCNC finds `o<name> call`'s subroutine in the file `name.ngc` holding `o<name> sub`
    // (LinuxCNC manual, O Codes, "Calling Files"). Its rename is a change, not a respelling.
    let called_elsewhere = map.keys().any(|o| o.starts_with("O<") && !ua.0.get(o).is_some_and(|u| u.called));
    if !whole || called_elsewhere {
        return Vec::new();
    }
    taken
}

/// How a program uses a label (it is named there): whether it defines it (a program number, a
/// block number, an O-word's own statement other than a call).
#[derive(Clone, Copy, Debug, Default)]
struct LabelUse {
    defined: bool,
    /// Named by a call (or a jump, a return to it) here.
    called: bool,
}

/// The uses in `text` of the labels of `first` and of `second` (as [`labels`] writes them),
/// each set's found ones apart.
fn label_uses(
    text: &str,
    d: &Dialect,
    first: &BTreeSet<String>,
    second: &BTreeSet<String>,
) -> (BTreeMap<String, LabelUse>, BTreeMap<String, LabelUse>) {
    let (mut u1, mut u2) = (BTreeMap::new(), BTreeMap::new());
    let mut note = |label: &str, defined: bool| {
        for (set, uses) in [(first, &mut u1), (second, &mut u2)] {
            if set.contains(label) {
                let u: &mut LabelUse = uses.entry(label.to_owned()).or_default();
                u.defined |= defined;
                u.called |= !defined;
            }
        }
    };
    statement::visit(text, d, |block, stmt| {
        if let Some(n) = block.number {
            note(&format!("N{n}"), true);
        }
        if let Some(n) = block.program_number {
            note(&format!("O{n}"), true);
        }
        let Some(stmt) = stmt else { return };
        let tokens = statement::tokens_in(stmt, d);
        let call = block.control.as_ref().is_some_and(|c| c.statement == Some(Statement::Call));
        for (k, label) in labels(&tokens, d) {
            note(&label, k == 0 && label.starts_with('O') && !call && tokens[0].text.starts_with('O'));
        }
    });
    (u1, u2)
}

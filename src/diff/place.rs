//! The lines of an edit's place: a row names the lines `git diff` shows changed beside the
//! statement it tells, where those lines hold no statement.
//!
//! A statement commented out (`o<task>call` → `;o<task>call`, `M0 (…)` → `(M0 …)`) or written
//! over a blank line is, to the edit's author, one line changed: the row that tells the
//! statement removed (or added) names the comment or blank line that took its place in the
//! other program too. The texts are paired line by line as git pairs them (the longest common
//! subsequence of exact lines, runs slid as git slides them); in each run of lines that
//! differ on both sides, every line without a statement that no row names is named by the
//! row of that run nearest to it. A run only removed or only added names nothing more: its
//! comments went with its statements. Statement lines are left alone: the accounting names
//! them where they differ, but for one case: a statement only re-indented in a run a row
//! names (the body of a condition changed or removed, `o<l1> if` taken away from around
//! `T#<toolno> M6 G43`) is named by that row, which governs it.
//!
//! A row that tells a jump (`GOTO 10` removed, `GOTO2004` → `GOTO1005`, a jump to a missing
//! block) names, in each program, the line of the block it jumps to where that line differs
//! (the label `N10` taken out with its jump, a new `N1005`): the jump and its target are one
//! edit (Fanuc, Siemens and Heidenhain manuals: a jump goes to the block of that number or
//! label). That is done first, so that the label's run then names its other side.

use std::collections::BTreeMap;

use super::statement::{self, Stmt};
use super::{Change, ChangeKind};
use crate::dialect::{Dialect, Statement as DStatement};

/// The lines of one side a change names: its first to last line, and its `at`.
fn named(c: &Change, original: bool) -> impl Iterator<Item = u32> + '_ {
    let (first, end) = if original { (c.original_line, c.detail.original_line_end) } else { (c.line, c.detail.line_end) };
    let run = first.map(|f| f..=end.unwrap_or(f).max(f)).into_iter().flatten();
    run.chain(c.detail.at.iter().filter_map(move |&(o, e)| if original { o } else { e }))
}

/// A jump's target: a block number or a label's name (upper case).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Target {
    Number(u32),
    Name(String),
}

/// The blocks a program's jumps may land on (target, line), and the targets of the jumps on
/// each line.
/// The labels of a program (target, line) and the targets of the jumps on each line.
type Jumps = (Vec<(Target, u32)>, BTreeMap<u32, Vec<Target>>);

/// Labels are kept only on the lines that differ (`!same[line]`).
fn jumps_of(text: &str, dialect: &Dialect, same: &[bool]) -> Jumps {
    let mut labels = Vec::new();
    let mut jumps: BTreeMap<u32, Vec<Target>> = BTreeMap::new();
    let slice = |r: crate::text::TextRange| text.get(r.start as usize..r.end as usize).unwrap_or("").trim().to_ascii_uppercase();
    statement::visit(text, dialect, |block, _| {
        if !same.get(block.line as usize).copied().unwrap_or(true) {
            if let Some(n) = block.number {
                labels.push((Target::Number(n), block.line));
            }
            if let Some(r) = block.label {
                labels.push((Target::Name(slice(r)), block.line));
            }
        }
        let Some(c) = block.control.as_ref() else { return };
        let goto = |s: Option<DStatement>| {
            matches!(
                s,
                Some(DStatement::Goto | DStatement::GotoForward | DStatement::GotoBack | DStatement::GotoQuiet | DStatement::GotoLabel)
            )
        };
        if !(goto(c.statement) || goto(c.then)) {
            return;
        }
        let number = c.target.and_then(|e| match block.exprs.get(e as usize) {
            Some(crate::syntax::Expr::Num(v)) if *v >= 0.0 && v.fract() == 0.0 && *v <= 99_999_999.0 => Some(*v as u32),
            _ => None,
        });
        let target = number.map(Target::Number).or_else(|| c.name.map(|r| Target::Name(slice(r))));
        if let Some(t) = target {
            jumps.entry(block.line).or_default().push(t);
        }
    });
    (labels, jumps)
}

/// The lines `range` (1-based) of `text`.
fn lines_in<'t>(text: &'t str, range: &std::ops::Range<u32>) -> Vec<&'t str> {
    text.split('\n').skip(range.start as usize - 1).take(range.len()).collect()
}

/// Names, in `changes`, the lines without a statement that differ beside the lines they
/// name (see the module doc).
pub(super) fn name_places(changes: &mut [Change], (ta, tb): (&str, &str), (sa, sb): (&[Stmt], &[Stmt]), (da, db): (&Dialect, &Dialect)) {
    if changes.is_empty() {
        return;
    }
    let (la, lb) = (statement::line_hashes(ta), statement::line_hashes(tb));
    let kept = statement::compact(&la, &lb, &statement::matches(&la, &lb));
    // Whether a line (1-based) is one git's diff keeps.
    let (mut same_a, mut same_b) = (vec![false; la.len() + 2], vec![false; lb.len() + 2]);
    for &(x, y) in &kept {
        same_a[x + 1] = true;
        same_b[y + 1] = true;
    }
    let flows = |c: &Change| matches!(c.kind, ChangeKind::FlowChanged | ChangeKind::ProgramFixed | ChangeKind::ProgramBroken);
    let ((label_a, jump_a), (label_b, jump_b)) = (jumps_of(ta, da, &same_a), jumps_of(tb, db, &same_b));
    {
        for c in changes.iter_mut().filter(|c| flows(c)) {
            let mut targets: Vec<Target> = named(c, true)
                .filter_map(|l| jump_a.get(&l))
                .chain(named(c, false).filter_map(|l| jump_b.get(&l)))
                .flatten()
                .cloned()
                .collect();
            targets.sort();
            targets.dedup();
            let mut at = Vec::new();
            for t in &targets {
                at.extend(label_a.iter().filter(|(u, _)| u == t).map(|&(_, l)| (Some(l), None)));
                at.extend(label_b.iter().filter(|(u, _)| u == t).map(|&(_, l)| (None, Some(l))));
            }
            at.retain(|a| !c.detail.at.contains(a));
            if !at.is_empty() {
                c.detail.at.extend(at);
                c.detail.at.sort_by_key(|&(o, e)| (e.or(o), o));
                c.detail.at.dedup();
            }
        }
    }
    // Lines (1-based) that hold a statement, or a part of one.
    let held = |s: &[Stmt], n: usize| {
        let mut v = vec![false; n + 2];
        for t in s {
            for l in t.line..=t.last.max(t.line) {
                if let Some(x) = v.get_mut(l as usize) {
                    *x = true;
                }
            }
        }
        v
    };
    let (ha, hb) = (held(sa, la.len()), held(sb, lb.len()));
    // The first row naming each line of a side.
    let rows = |original: bool, n: usize| {
        let mut v: Vec<Option<usize>> = vec![None; n + 2];
        for (k, c) in changes.iter().enumerate() {
            for l in named(c, original) {
                if let Some(x) = v.get_mut(l as usize) {
                    x.get_or_insert(k);
                }
            }
        }
        v
    };
    let (na, nb) = (rows(true, la.len()), rows(false, lb.len()));
    // The runs of lines that differ on both sides, 1-based.
    let mut runs = Vec::new();
    let (mut i, mut j) = (0usize, 0usize);
    for (x, y) in kept.into_iter().chain(std::iter::once((la.len(), lb.len()))) {
        if x > i || y > j {
            runs.push(((i + 1) as u32..(x + 1) as u32, (j + 1) as u32..(y + 1) as u32));
        }
        (i, j) = (x + 1, y + 1);
    }
    let mut touched = vec![false; changes.len()];
    let row_at =
        |original: bool, l: u32| if original { na.get(l as usize).copied().flatten() } else { nb.get(l as usize).copied().flatten() };
    for (ra, rb) in runs {
        // Statements only re-indented under a condition a row changes: each original one
        // paired with the next edited one of the same text, in order, and named by the row
        // of a condition in the run nearest to it.
        let mut conditions: Vec<(usize, u32)> = Vec::new();
        for (k, c) in changes.iter().enumerate().filter(|(_, c)| c.kind == ChangeKind::FlowChanged) {
            conditions.extend(named(c, true).filter(|l| ra.contains(l)).map(|l| (k, l - ra.start)));
            conditions.extend(named(c, false).filter(|l| rb.contains(l)).map(|l| (k, l - rb.start)));
        }
        if !conditions.is_empty() && !ra.is_empty() && !rb.is_empty() {
            let (ea, eb) = (lines_in(ta, &ra), lines_in(tb, &rb));
            let mut from = rb.start;
            for l in ra.clone().filter(|&l| ha[l as usize] && na[l as usize].is_none()) {
                let text = ea[(l - ra.start) as usize].trim();
                let Some(m) = (from..rb.end).find(|&m| hb[m as usize] && eb[(m - rb.start) as usize].trim() == text) else { continue };
                from = m + 1;
                if nb[m as usize].is_some() {
                    continue;
                }
                let place = l - ra.start;
                let Some(&(k, _)) = conditions.iter().min_by_key(|&&(k, p)| (p.abs_diff(place), k)) else { continue };
                changes[k].detail.at.push((Some(l), Some(m)));
                touched[k] = true;
            }
        }
        for (original, range, other, held, names) in [(true, &ra, &rb, &ha, &na), (false, &rb, &ra, &hb, &nb)] {
            let labels = if original { &label_a } else { &label_b };
            for l in range.clone() {
                if held.get(l as usize).copied().unwrap_or(true) || names.get(l as usize).is_none_or(Option::is_some) {
                    continue;
                }
                // The row of the line in the same place of the other side (git shows the two
                // as one line changed); for a label, the row of the block it heads.
                let across = other.start + (l - range.start);
                let k = if other.contains(&across) { row_at(!original, across) } else { None };
                let k = k.or_else(|| labels.iter().any(|&(_, x)| x == l).then(|| row_at(original, l + 1)).flatten());
                let Some(k) = k else { continue };
                // The place of a statement the row tells removed (added) there: the pair
                // completed; else a line of its own.
                let open = changes[k]
                    .detail
                    .at
                    .iter_mut()
                    .find(|(o, e)| if original { o.is_none() && *e == Some(across) } else { e.is_none() && *o == Some(across) });
                match open {
                    Some(at) if original => at.0 = Some(l),
                    Some(at) => at.1 = Some(l),
                    None => changes[k].detail.at.push(if original { (Some(l), None) } else { (None, Some(l)) }),
                }
                touched[k] = true;
            }
        }
    }
    for c in changes.iter_mut().zip(touched).filter_map(|(c, t)| t.then_some(c)) {
        c.detail.at.sort_by_key(|&(o, e)| (e.or(o), o));
        c.detail.at.dedup();
    }
}

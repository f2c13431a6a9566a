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
//! them where they differ.

use super::Change;
use super::statement::{self, Stmt};

/// The lines of one side a change names: its first to last line, and its `at`.
fn named(c: &Change, original: bool) -> impl Iterator<Item = u32> + '_ {
    let (first, end) = if original { (c.original_line, c.detail.original_line_end) } else { (c.line, c.detail.line_end) };
    let run = first.map(|f| f..=end.unwrap_or(f).max(f)).into_iter().flatten();
    run.chain(c.detail.at.iter().filter_map(move |&(o, e)| if original { o } else { e }))
}

/// Names, in `changes`, the lines without a statement that differ beside the lines they
/// name (see the module doc).
pub(super) fn name_places(changes: &mut [Change], (ta, tb): (&str, &str), (sa, sb): (&[Stmt], &[Stmt])) {
    if changes.is_empty() {
        return;
    }
    let (la, lb) = (statement::line_hashes(ta), statement::line_hashes(tb));
    let kept = statement::compact(&la, &lb, &statement::matches(&la, &lb));
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
    let all_named = |original: bool, n: usize| {
        let mut v = vec![false; n + 2];
        for c in changes.iter() {
            for l in named(c, original) {
                if let Some(x) = v.get_mut(l as usize) {
                    *x = true;
                }
            }
        }
        v
    };
    let (na, nb) = (all_named(true, la.len()), all_named(false, lb.len()));
    // The runs of lines that differ on both sides, 1-based.
    let mut runs = Vec::new();
    let (mut i, mut j) = (0usize, 0usize);
    for (x, y) in kept.into_iter().chain(std::iter::once((la.len(), lb.len()))) {
        if x > i && y > j {
            runs.push(((i + 1) as u32..(x + 1) as u32, (j + 1) as u32..(y + 1) as u32));
        }
        (i, j) = (x + 1, y + 1);
    }
    let mut touched = vec![false; changes.len()];
    for (ra, rb) in runs {
        // The rows naming a line of the run, with that line's place in the run.
        let mut near: Vec<(usize, u32)> = Vec::new();
        for (k, c) in changes.iter().enumerate() {
            near.extend(named(c, true).filter(|l| ra.contains(l)).map(|l| (k, l - ra.start)));
            near.extend(named(c, false).filter(|l| rb.contains(l)).map(|l| (k, l - rb.start)));
        }
        if near.is_empty() {
            continue;
        }
        for (original, range, held, names) in [(true, ra.clone(), &ha, &na), (false, rb.clone(), &hb, &nb)] {
            for l in range.clone() {
                if held.get(l as usize).copied().unwrap_or(true) || names.get(l as usize).copied().unwrap_or(true) {
                    continue;
                }
                let place = l - range.start;
                let Some(&(k, _)) = near.iter().min_by_key(|&&(k, p)| (p.abs_diff(place), k)) else { continue };
                // The place of a statement the row tells removed (added) in this run: the
                // pair completed; else a line of its own.
                let other = if original { &rb } else { &ra };
                let open = changes[k].detail.at.iter_mut().find(|(o, e)| {
                    if original { o.is_none() && e.is_some_and(|e| other.contains(&e)) } else { e.is_none() && o.is_some_and(|o| other.contains(&o)) }
                });
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

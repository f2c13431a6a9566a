//! The lines of an edit's place: a row names the lines `git diff` shows changed beside the
//! statement it tells, where those lines hold no statement.
//!
//! A statement commented out (`o<task>call` → `;o<task>call`, `M0 (…)` → `(M0 …)`) or written
//! over a blank line is, to the edit's author, one line changed: the row that tells the
//! statement removed (or added) names the comment or blank line that took its place in the
//! other program too. The texts are paired line by line as git pairs them (the longest common
//! subsequence of exact lines, runs slid as git slides them); in each run of lines that
//! differ on both sides, every line without a statement that no row names is named by the
//! row that names the line at the same offset in the other side's part of the run (git shows
//! the two as one line changed), and by none where that line is past the other side's part or
//! no row names it. A run only removed or only added names nothing more: its comments went
//! with its statements, but for a label line, named by the row of the block it heads, or,
//! where that block stays, by the row of the nearest statement above it in the run.
//! Statement lines are left alone: the accounting names them where they differ, but for one
//! case: a statement only re-indented in a run a row names (the body of a condition changed
//! or removed, `o<l1> if` taken away from around `T#<toolno> M6 G43`) is named by that row,
//! which governs it.
//!
//! A row that tells a jump (`GOTO 10` removed, `GOTO2004` → `GOTO1005`, a jump to a missing
//! block) names, in each program, the line of the block it jumps to where that line differs
//! (the label `N10` taken out with its jump, a new `N1005`): the jump and its target are one
//! edit (Fanuc, Siemens and Heidenhain manuals: a jump goes to the block of that number or
//! label). That is done first, so that the label's run then names its other side.

use std::collections::{BTreeMap, BTreeSet, VecDeque};

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

/// Line `l` (1-based) of `lines`, without the blanks around it.
fn trimmed<'t>(lines: &[&'t str], l: u32) -> &'t str {
    lines.get((l as usize).wrapping_sub(1)).map_or("", |t| t.trim())
}

/// The places of a row with their line on one side only, by (whether the original side's
/// line is the one missing, the other side's line): their indices in `at`, first first.
fn open_places(at: &[(Option<u32>, Option<u32>)]) -> BTreeMap<(bool, u32), VecDeque<usize>> {
    let mut v: BTreeMap<(bool, u32), VecDeque<usize>> = BTreeMap::new();
    for (s, &(o, e)) in at.iter().enumerate() {
        match (o, e) {
            (None, Some(e)) => v.entry((true, e)).or_default().push_back(s),
            (Some(o), None) => v.entry((false, o)).or_default().push_back(s),
            _ => {}
        }
    }
    v
}

/// The lines the condition rows name on one side, with their rows, by line.
fn conditions_of(changes: &[Change], original: bool) -> Vec<(u32, usize)> {
    let mut v: Vec<(u32, usize)> = Vec::new();
    for (k, c) in changes.iter().enumerate().filter(|(_, c)| c.kind == ChangeKind::FlowChanged) {
        v.extend(named(c, original).map(|l| (l, k)));
    }
    v.sort_unstable();
    v
}

/// A jump row also names the lines of the labels its jumps go to (both sides).
fn name_jump_targets(changes: &mut [Change], (label_a, jump_a): &Jumps, (label_b, jump_b): &Jumps) {
    let flows = |c: &Change| matches!(c.kind, ChangeKind::FlowChanged | ChangeKind::ProgramFixed | ChangeKind::ProgramBroken);
    // The lines of each target's labels, in the order of the text.
    let by_target = |labels: &[(Target, u32)]| {
        let mut v: BTreeMap<Target, Vec<u32>> = BTreeMap::new();
        for (t, l) in labels {
            v.entry(t.clone()).or_default().push(*l);
        }
        v
    };
    let (target_a, target_b) = (by_target(label_a), by_target(label_b));
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
            at.extend(target_a.get(t).into_iter().flatten().map(|&l| (Some(l), None)));
            at.extend(target_b.get(t).into_iter().flatten().map(|&l| (None, Some(l))));
        }
        if !at.is_empty() {
            let had: BTreeSet<(Option<u32>, Option<u32>)> = c.detail.at.iter().copied().collect();
            at.retain(|a| !had.contains(a));
        }
        if !at.is_empty() {
            c.detail.at.extend(at);
            c.detail.at.sort_by_key(|&(o, e)| (e.or(o), o));
            c.detail.at.dedup();
        }
    }
}

/// An assignment moved with its value (no change of its own, `follow::moved_same`) whose
/// new or old line lies in a run of lines that differ that a row names (`INI[146]=3` moved
/// down among the `R210=0.6` … `R213=3` added): git shows the move inside that row's hunk, so
/// the row names both its lines, as one place. A move in runs no row names stays silent.
fn name_moves(changes: &mut [Change], moved: &[(u32, u32)], runs: &[(std::ops::Range<u32>, std::ops::Range<u32>)], touched: &mut [bool]) {
    if moved.is_empty() {
        return;
    }
    for &(o, e) in moved {
        let Some((ra, rb)) = runs.iter().find(|(_, rb)| rb.contains(&e)).or_else(|| runs.iter().find(|(ra, _)| ra.contains(&o))) else {
            continue;
        };
        // The row naming a line of the run nearest to the moved line, on the edited side
        // first: the first row at a tie.
        let nearest = |original: bool, r: &std::ops::Range<u32>, l: u32| {
            changes
                .iter()
                .enumerate()
                .filter_map(|(k, c)| named(c, original).filter(|m| r.contains(m) && *m != l).map(|m| (m.abs_diff(l), k)).min())
                .min()
        };
        let row = nearest(false, rb, e).or_else(|| nearest(true, ra, o)).map(|(_, k)| k);
        // Also the run of the other line, where it is another run.
        let row = row.or_else(|| {
            let (ra2, rb2) = runs.iter().find(|(ra, _)| ra.contains(&o))?;
            nearest(true, ra2, o).or_else(|| nearest(false, rb2, e)).map(|(_, k)| k)
        });
        let Some(k) = row else { continue };
        changes[k].detail.at.push((Some(o), Some(e)));
        touched[k] = true;
    }
}

/// The first row naming each line of a side.
fn first_rows(changes: &[Change], original: bool) -> BTreeMap<u32, usize> {
    let mut v: BTreeMap<u32, usize> = BTreeMap::new();
    for (k, c) in changes.iter().enumerate() {
        for l in named(c, original) {
            v.entry(l).or_insert(k);
        }
    }
    v
}

/// The runs of lines that differ, 1-based, between the line pairs git's diff keeps (0-based,
/// in order) of two texts of `len` lines.
fn differing_runs(kept: &[(usize, usize)], len: (usize, usize)) -> Vec<(std::ops::Range<u32>, std::ops::Range<u32>)> {
    let mut runs = Vec::new();
    let (mut i, mut j) = (0usize, 0usize);
    for &(x, y) in kept.iter().chain(std::iter::once(&len)) {
        if x > i || y > j {
            runs.push(((i + 1) as u32..(x + 1) as u32, (j + 1) as u32..(y + 1) as u32));
        }
        (i, j) = (x + 1, y + 1);
    }
    runs
}

/// Names, in `changes`, the lines without a statement that differ beside the lines they
/// name (see the module doc).
pub(super) fn name_places(
    changes: &mut [Change],
    (ta, tb): (&str, &str),
    (sa, sb): (&[Stmt], &[Stmt]),
    (da, db): (&Dialect, &Dialect),
    moved: &[(u32, u32)],
) {
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
    // Lines (1-based) that hold a statement, or a part of one (the statements are in order).
    let holds = |s: &[Stmt], l: u32| {
        let i = s.partition_point(|t| t.last.max(t.line) < l);
        i < s.len() && s[i].line <= l
    };
    let runs = differing_runs(&kept, (la.len(), lb.len()));
    let flows = |c: &Change| matches!(c.kind, ChangeKind::FlowChanged | ChangeKind::ProgramFixed | ChangeKind::ProgramBroken);
    // The blocks are read again only where a jump row or a line without a statement asks.
    let (na, nb) = (first_rows(changes, true), first_rows(changes, false));
    let open = |ra: &std::ops::Range<u32>, s: &[Stmt], n: &BTreeMap<u32, usize>| ra.clone().any(|l| !holds(s, l) && !n.contains_key(&l));
    let need = changes.iter().any(flows) || runs.iter().any(|(ra, rb)| open(ra, sa, &na) || open(rb, sb, &nb));
    let (ja, jb): (Jumps, Jumps) = if need { (jumps_of(ta, da, &same_a), jumps_of(tb, db, &same_b)) } else { Default::default() };
    if changes.iter().any(flows) {
        name_jump_targets(changes, &ja, &jb);
    }
    let mut touched = vec![false; changes.len()];
    name_moves(changes, moved, &runs, &mut touched);
    let (label_a, label_b) = (&ja.0, &jb.0);
    let (na, nb) = (first_rows(changes, true), first_rows(changes, false));
    let label_lines = |labels: &[(Target, u32)]| labels.iter().map(|&(_, l)| l).collect::<std::collections::BTreeSet<u32>>();
    let (lla, llb) = (label_lines(label_a), label_lines(label_b));
    // The lines the condition rows name, by line, and the texts' lines, where there are any.
    let (ca, cb) = (conditions_of(changes, true), conditions_of(changes, false));
    let (ea, eb): (Vec<&str>, Vec<&str>) =
        if ca.is_empty() && cb.is_empty() { Default::default() } else { (ta.split('\n').collect(), tb.split('\n').collect()) };
    // The open places of each row a line below asks for (a place with its line on one side
    // only), by (whether the original side's line is the one missing, the other side's line):
    // their indices in the row's `at`, first first, each taken once it is completed. Built
    // for a row when first asked; places are only appended to `at` until the end.
    let mut open_of: BTreeMap<usize, BTreeMap<(bool, u32), VecDeque<usize>>> = BTreeMap::new();
    let row_at = |original: bool, l: u32| if original { na.get(&l).copied() } else { nb.get(&l).copied() };
    let within = |v: &[(u32, usize)], r: &std::ops::Range<u32>| {
        let from = v.partition_point(|&(l, _)| l < r.start);
        let to = v.partition_point(|&(l, _)| l < r.end);
        v[from..to].to_vec()
    };
    for (ra, rb) in runs {
        // Statements only re-indented under a condition a row changes: each original one
        // paired with the next edited one of the same text, in order, and named by the row
        // of a condition in the run nearest to it.
        // (place in the run, row), in order.
        let mut conditions: Vec<(u32, usize)> = within(&ca, &ra)
            .into_iter()
            .map(|(l, k)| (l - ra.start, k))
            .chain(within(&cb, &rb).into_iter().map(|(l, k)| (l - rb.start, k)))
            .collect();
        conditions.sort_unstable();
        // The nearest condition's row, the first row of the nearest at a tie: the first at or
        // after the place, or the first of the last place before it.
        let nearest = |place: u32| {
            let i = conditions.partition_point(|&(p, _)| p < place);
            let after = conditions.get(i);
            let before = i.checked_sub(1).map(|b| conditions[conditions.partition_point(|&(p, _)| p < conditions[b].0)]);
            after.copied().into_iter().chain(before).min_by_key(|&(p, k)| (p.abs_diff(place), k)).map(|(_, k)| k)
        };
        if !conditions.is_empty() && !ra.is_empty() && !rb.is_empty() {
            // The edited run's statement lines by their text, in order.
            let mut lines_of: BTreeMap<&str, Vec<u32>> = BTreeMap::new();
            for m in rb.clone().filter(|&m| holds(sb, m)) {
                lines_of.entry(trimmed(&eb, m)).or_default().push(m);
            }
            let mut from = rb.start;
            for l in ra.clone().filter(|&l| holds(sa, l) && !na.contains_key(&l)) {
                let text = trimmed(&ea, l);
                let Some(ms) = lines_of.get(text) else { continue };
                let Some(&m) = ms.get(ms.partition_point(|&m| m < from)) else { continue };
                from = m + 1;
                if nb.contains_key(&m) {
                    continue;
                }
                let place = l - ra.start;
                let Some(k) = nearest(place) else { continue };
                changes[k].detail.at.push((Some(l), Some(m)));
                touched[k] = true;
            }
        }
        for (original, range, other, stmts, names) in [(true, &ra, &rb, sa, &na), (false, &rb, &ra, sb, &nb)] {
            let labels = if original { &lla } else { &llb };
            for l in range.clone() {
                if holds(stmts, l) || names.contains_key(&l) {
                    continue;
                }
                // The row of the line in the same place of the other side (git shows the two
                // as one line changed); for a label in a run only added or removed (a section
                // with its own block number, `N0034`), the row of the block it heads. A label
                // renumbered in place is a respelling.
                let across = other.start + (l - range.start);
                let k = if other.contains(&across) { row_at(!original, across) } else { None };
                let k = k.or_else(|| (other.is_empty() && labels.contains(&l)).then(|| row_at(original, l + 1)).flatten());
                // A label at the end of a run only removed or added whose block stays (`N800`
                // after the `G65 …` and `GOTO 1000` of the section before it, taken out): it
                // went with the statements above it in the hunk git shows, named by the row of
                // the nearest of them.
                let k = k.or_else(|| {
                    (other.is_empty() && labels.contains(&l)).then(|| (range.start..l).rev().find_map(|p| row_at(original, p))).flatten()
                });
                let Some(k) = k else { continue };
                // The place of a statement the row tells removed (added) there: the pair
                // completed; else a line of its own.
                let open = open_of.entry(k).or_insert_with(|| open_places(&changes[k].detail.at));
                let at = &mut changes[k].detail.at;
                match open.get_mut(&(original, across)).and_then(VecDeque::pop_front) {
                    Some(s) if original => at[s].0 = Some(l),
                    Some(s) => at[s].1 = Some(l),
                    None => {
                        // An open place of its own, which a line of the other side may complete.
                        open.entry((!original, l)).or_default().push_back(at.len());
                        at.push(if original { (Some(l), None) } else { (None, Some(l)) });
                    }
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

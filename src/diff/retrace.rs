//! Straight moves written in other pieces along the same path at the same feed: no change.
//!
//! A hunk whose statements on both sides are only straight moves (a motion code, axis words
//! with numbers, a feed) is the same machining where the moves the plan makes from its lines
//! run the same way: from the same point, through the same corners (a line written in two
//! pieces, `G91 G1 Y5` twice for `G1 Y10`, has no corner between them), to the same point, of
//! the same kind, at the same feed. The control moves the tool the same way; only the blocks
//! differ.

use std::collections::{BTreeMap, BTreeSet};

use super::Program;
use super::statement::{self, Hunk, Sort, Stmt};
use super::typed::{About, about};
use crate::dialect::{Meaning, Role};
use crate::plan::{Move, MoveKind, P3};

/// How many statements a hunk may have on a side to be looked at.
const MOST: usize = 8;

/// Where every statement of `r` in `p` is a straight move and nothing else: the motion code
/// and the feed the last of them leaves in force for the blocks after (`None` where none says
/// one), as written.
fn straight_only(p: Program<'_>, s: &[Stmt], r: &std::ops::Range<usize>) -> Option<(Option<String>, Option<String>)> {
    let (mut motion, mut feed) = (None, None);
    for k in r.clone() {
        let tokens = statement::tokens_in(&statement::text_of(p.text, p.dialect, &s[k]), p.dialect);
        if tokens.is_empty() {
            return None;
        }
        for t in &tokens {
            if t.sort != Sort::Word {
                return None;
            }
            match about(t, p.dialect) {
                About::Code(Meaning::Linear | Meaning::Rapid) => motion = Some(t.key.clone()),
                About::Address(Role::F) if t.value.parse::<f64>().is_ok() => feed = t.value.parse::<f64>().ok().map(|f| f.to_string()),
                About::Address(Role::X | Role::Y | Role::Z) if t.value.parse::<f64>().is_ok() => {}
                _ => return None,
            }
        }
    }
    Some((motion, feed))
}

/// The corners of a run of straight moves: the start of each stretch that goes one way at one
/// kind and feed (a new one where the direction, the kind or the feed changes, or after a gap),
/// with that kind and feed; then the run's end.
fn corners(moves: &[Move]) -> Vec<(P3, Option<(MoveKind, f64)>)> {
    let dir = |m: &Move| {
        let d = [m.to[0] - m.from[0], m.to[1] - m.from[1], m.to[2] - m.from[2]];
        let n = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
        (n > 0.0).then(|| [d[0] / n, d[1] / n, d[2] / n])
    };
    let mut out = Vec::new();
    let mut last: Option<([f64; 3], MoveKind, f64, P3)> = None;
    for m in moves {
        // A move that goes nowhere is a stretch of its own: nothing to trace it by.
        let Some(d) = dir(m) else {
            out.push((m.from, Some((m.kind, m.feed))));
            last = None;
            continue;
        };
        let goes_on = last.is_some_and(|(e, k, f, end)| {
            k == m.kind
                && f == m.feed
                && d[0] * e[0] + d[1] * e[1] + d[2] * e[2] > 1.0 - 1e-9
                && (0..3).all(|i| (end[i] - m.from[i]).abs() <= super::TOLERANCE)
        });
        if !goes_on {
            out.push((m.from, Some((m.kind, m.feed))));
        }
        last = Some((d, m.kind, m.feed, m.to));
    }
    if let Some((.., end)) = last {
        out.push((end, None));
    }
    out
}

/// The statements of hunks that only cut the same straight path in other pieces (see the
/// module): as (original line, None) and (None, edited line).
pub(super) fn retraced(hunks: &[Hunk], a: Program<'_>, b: Program<'_>, sa: &[Stmt], sb: &[Stmt]) -> Vec<(Option<u32>, Option<u32>)> {
    let small = |h: &&Hunk| !h.original.is_empty() && !h.edited.is_empty() && h.original.len() <= MOST && h.edited.len() <= MOST;
    // Both sides leave the same motion code and feed in force for the blocks after them.
    let candidates: Vec<&Hunk> = hunks
        .iter()
        .filter(small)
        .filter(|h| straight_only(a, sa, &h.original).is_some_and(|x| straight_only(b, sb, &h.edited).is_some_and(|y| x == y)))
        .collect();
    if candidates.is_empty() {
        return Vec::new();
    }
    let lines = |s: &[Stmt], r: &std::ops::Range<usize>| r.clone().map(|k| s[k].line).collect::<Vec<u32>>();
    let moves = |p: Program<'_>, wanted: BTreeSet<u32>| {
        let mut by_line: BTreeMap<u32, Vec<Move>> = BTreeMap::new();
        for w in &p.plan.workingsteps {
            for m in w.toolpath.iter().filter(|m| wanted.contains(&m.line)) {
                by_line.entry(m.line).or_default().push(m);
            }
        }
        by_line
    };
    let ma = moves(a, candidates.iter().flat_map(|h| lines(sa, &h.original)).collect());
    let mb = moves(b, candidates.iter().flat_map(|h| lines(sb, &h.edited)).collect());
    let near = |p: P3, q: P3| (0..3).all(|i| (p[i] - q[i]).abs() <= super::TOLERANCE);
    let mut out = Vec::new();
    for h in candidates {
        let run =
            |m: &BTreeMap<u32, Vec<Move>>, l: Vec<u32>| l.iter().flat_map(|l| m.get(l).cloned().unwrap_or_default()).collect::<Vec<Move>>();
        let (la, lb) = (lines(sa, &h.original), lines(sb, &h.edited));
        let (xa, xb) = (run(&ma, la.clone()), run(&mb, lb.clone()));
        // One pass over the lines only: a line the run comes back to is left as it is.
        if xa.is_empty() || xb.is_empty() || xa.len() > la.len() || xb.len() > lb.len() {
            continue;
        }
        let (ca, cb) = (corners(&xa), corners(&xb));
        let same = ca.len() == cb.len() && ca.iter().zip(&cb).all(|(p, q)| near(p.0, q.0) && p.1 == q.1);
        if same {
            out.extend(la.into_iter().map(|l| (Some(l), None)));
            out.extend(lb.into_iter().map(|l| (None, Some(l))));
        }
    }
    out
}

//! The accounting of a comparison: every statement that differs between the two programs is
//! named by at least one change.
//!
//! A plan change is *located* at the differing statements of its workingstep whose words say
//! what it is about (a feed change at the statements whose `F` differs, a depth change at
//! those whose axis words do). A differing statement no plan change is located at becomes a
//! *statement change* in program terms: a variable set to another value, an argument of a
//! call, a word added or removed. So is every change of a variable, a call or a jump, which
//! the plan sees, if at all, only through what it drives: such a statement change names the
//! plan changes no statement explains as its effect. A statement that only shows or writes
//! text is an [`ChangeKind::OutputChanged`], which reports may leave out.

use std::ops::RangeInclusive;

use super::statement::{self, Class, Fault, Hunk, Sort, Stmt, Token};
use super::typed::{self, About, Context, about};
use super::{Change, ChangeKind, control, follow, height, retrace, verdict};
use crate::dialect::{Dialect, Meaning, Role};
use crate::plan::{ProcessPlan, Workingstep};

/// One program as the diff reads it: its plan, and its text in its dialect for the statements.
#[derive(Clone, Copy)]
pub struct Program<'a> {
    /// The recovered plan.
    pub plan: &'a ProcessPlan,
    /// The decoded text.
    pub text: &'a str,
    /// The dialect it was read in.
    pub dialect: &'a Dialect,
}

/// Hunks with more statements than this on either side are reported as one change.
const DETAILED: usize = 24;

/// A differing statement, or a pair of them, and how their tokens differ.
struct Item {
    original: Option<usize>,
    edited: Option<usize>,
    /// Token differences: (before, after); one side `None` for an added or removed token.
    diffs: Vec<(Option<Token>, Option<Token>)>,
    class: Class,
    /// What its statements move ([`statement::RETURN_MOVE`], [`statement::ROTARY_MOVE`]).
    moves: u8,
    /// Whether a plan change is located here.
    located: bool,
    /// The codes of its statements that give their words a sense (a dwell's time, a cycle's parameters).
    ctx: Context,
    /// Whether a plan change is located at a call's arguments (a swivel cycle's): those
    /// arguments need no statement change of their own.
    call_located: bool,
    /// The kinds of the plan changes located here: a named cycle's argument whose role one of
    /// them states (`CYCLE95 MID`, told as the depth of cut) needs no change of its own.
    located_kinds: Vec<ChangeKind>,
    /// Whether the original's statement and the edited one call a program or label, as the
    /// parser reads them ([`statement::CALL`]).
    calls: (bool, bool),
    /// The texts of its statements' words (both sides) that name a jump's target, and of
    /// those that stand before the jump keyword, its condition
    /// ([`control::jump_target_tokens`]); both empty where no statement jumps.
    jump_words: (Vec<String>, Vec<String>),
    /// Its statements' tokens whole, the original's and the edited one's (empty for a side
    /// that has none): a statement told from all its words (a tool table's column written).
    tokens: (Vec<Token>, Vec<Token>),
    /// For a statement that writes a table's row (the dictionary's `tool-table` write keyword,
    /// Heidenhain `FN 27: TABWRITE`): the table each side's program opened last before it
    /// (`FN 26: TABOPEN TNC:\TOOL.T`), as written.
    tables: (Option<String>, Option<String>),
}

/// A hunk too large to tell statement by statement.
struct Bulk {
    hunk: Hunk,
    class: Class,
}

/// Locates `changes` (the plan's, aligned by `pairs`) at the statements that differ between
/// `a` and `b`, and adds a statement change for every differing statement none is located
/// at.
/// What the edit breaks or fixes comes first: the errors of `findings` (the two analyses'),
/// and those reading every block finds where the analysis did not run it (a subprogram no
/// line of the file calls, a branch not taken): the control stops there when it runs it.
pub(super) fn account(
    a: Program<'_>,
    b: Program<'_>,
    pairs: &[(Option<usize>, Option<usize>)],
    changes: &mut Vec<Change>,
    findings: (&[Fault], &[Fault]),
) {
    let ((sa, fa), (sb, fb)) = (statement::read(a.text, a.dialect), statement::read(b.text, b.dialect));
    let (fa, fb) = (verdict::joined(findings.0, fa), verdict::joined(findings.1, fb));
    let (fa, fb) = (verdict::library_stops(&fa, a.dialect), verdict::library_stops(&fb, b.dialect));
    let hunks = statement::hunks_in(&sa, &sb, Some((a.text, b.text)));
    // Whether the original cuts anything with a feed, where the control removes material.
    let cuts = || {
        a.plan
            .workingsteps
            .iter()
            .flat_map(|w| w.toolpath.iter())
            .any(|m| m.phase == crate::plan::Phase::Cut && m.kind != crate::plan::MoveKind::Rapid && m.feed > 0.0)
    };
    // A file of definitions only stops only when run as a program; called, its subroutines
    // run (and stop at their own errors).
    let stops = |f: &[Fault]| f.iter().any(|f| f.code != crate::diag::Code::Library);
    let cuts = !stops(&fa) || !stops(&fb) || cuts();
    let told = verdict::verdicts(&fa, &fb, &|l| verdict::same_line(l, (&sa, &sb), &hunks), cuts);
    // An edit only inside remarks (a parenthesis nested in one added or taken out): the
    // control's words are the same in both, and what changes is only that the control stops
    // at the remark closed early, or no longer does. The plan changes that follow from the
    // analysis reading the remark's rest as words (a block it skipped, a statement of remark
    // text) are that same fix or break, not an edit of their own.
    if !told.is_empty() && only_remarks_differ(a, b) {
        changes.clear();
        // One row per side, saying what the control met there, at its line in both programs.
        let same = |o: u32| verdict::same_line(o, (&sa, &sb), &hunks);
        for mut c in told {
            for at in c.detail.at.iter_mut() {
                match *at {
                    (Some(o), None) => at.1 = same(o),
                    (None, Some(e)) => at.0 = sa.iter().map(|s| s.line).find(|&o| same(o) == Some(e)),
                    _ => {}
                }
            }
            if let Some(k) = changes.iter().position(|d: &Change| d.kind == c.kind) {
                let d = &mut changes[k];
                d.field = format!("{}, {}", d.field, c.field);
                d.detail.at.append(&mut c.detail.at);
                d.detail.at.dedup();
                continue;
            }
            let what = |m: &str| format!("a remark closed early by a parenthesis nested in it, its rest read as words ({m})");
            if c.kind == ChangeKind::ProgramFixed {
                c.before = what(&c.before);
            } else {
                c.after = what(&c.after);
            }
            changes.push(c);
        }
        return;
    }
    // Assignments moved with their value, as (original line, edited line): no change of their
    // own, but part of the hunk a row tells (`place::name_moves`).
    let moved: Vec<(u32, u32)> = follow::moved_same(&hunks, a, b, &sa, &sb)
        .chunks_exact(2)
        .filter_map(|p| match p {
            [(Some(o), None), (None, Some(e))] => Some((*o, *e)),
            _ => None,
        })
        .collect();
    restopped(changes, &|o| verdict::same_line(o, (&sa, &sb), &hunks));
    locate(a, b, (&sa, &sb), hunks, pairs, changes);
    changes.splice(0..0, told);
    super::place::name_places(changes, (a.text, b.text), (&sa, &sb), (a.dialect, b.dialect), &moved);
}

/// Stops that stayed where they were, told as removed from one workingstep and added to
/// another only because the edit moved a workingstep's first line past them (a `STOP` between
/// two workingsteps is the earlier one's where the later one now opens with a `TOOL CALL`
/// before its spindle start): a stop removed at an original statement and the same stop added
/// at that statement's line in the edited program (`same`: the edited line of an original
/// one, where the statements around it are unchanged) are no change.
fn restopped(changes: &mut Vec<Change>, same: &dyn Fn(u32) -> Option<u32>) {
    let single = |c: &Change| c.detail.at.len() <= 1;
    let mut k = 0;
    while k < changes.len() {
        let c = &changes[k];
        let (ChangeKind::StopRemoved, Some(o)) = (c.kind, c.original_line) else {
            k += 1;
            continue;
        };
        let Some(e) = same(o).filter(|_| single(c)) else {
            k += 1;
            continue;
        };
        let words = c.before.clone();
        match changes.iter().position(|d| d.kind == ChangeKind::StopAdded && d.line == Some(e) && d.after == words && single(d)) {
            Some(j) => {
                changes.remove(k.max(j));
                changes.remove(k.min(j));
                k = k.min(j);
            }
            None => k += 1,
        }
    }
}

/// Whether the two programs differ only inside `( )` remarks, read as if a remark's own
/// parentheses nested in it (`(Copyright (c) 2024 ...)`, `(... M3(rechtsdrehend) ...)`): the
/// control closes such a remark at its first `)` (DIN 66025: a remark holds no further
/// parentheses; Fanuc and LinuxCNC alike), so the edit matters only for where the control
/// stops. False where the dictionary has no `( )` remarks, or they already nest.
fn only_remarks_differ(a: Program<'_>, b: Program<'_>) -> bool {
    use crate::dialect::CommentClose;
    let paren = |r: &crate::dialect::CommentRule| r.open == '(' && r.open2.is_none() && r.close == CommentClose::Char(')') && !r.nested;
    if a.dialect.name != b.dialect.name || !a.dialect.lexical.comments.iter().any(paren) {
        return false;
    }
    // Each line without its remarks, nested ones whole, and without blanks.
    let words = |text: &str| -> Vec<String> {
        text.lines()
            .map(|line| {
                let mut depth = 0u32;
                let mut out = String::new();
                for ch in line.chars() {
                    match ch {
                        '(' => depth += 1,
                        ')' if depth > 0 => depth -= 1,
                        c if depth == 0 && !c.is_whitespace() => out.push(c),
                        _ => {}
                    }
                }
                out
            })
            .filter(|l| !l.is_empty())
            .collect()
    };
    words(a.text) == words(b.text)
}

/// [`account`] without the verdicts: the plan's changes located, and the statement changes.
fn locate(
    a: Program<'_>,
    b: Program<'_>,
    (sa, sb): (&[Stmt], &[Stmt]),
    hunks: Vec<Hunk>,
    pairs: &[(Option<usize>, Option<usize>)],
    changes: &mut Vec<Change>,
) {
    if hunks.is_empty() {
        // The machine reads the same statements: what recognition took from comments (a
        // stock, a tool's size) changed, not the machining. Called programs may still have.
        changes.retain(|c| !derived(c.kind));
        return;
    }
    let (mut items, mut bulks) = itemize(&hunks, a, b, sa, sb);
    let line = |s: &[Stmt], i: Option<usize>| i.map(|i| s[i].line);
    let same = same_machining(&items, &hunks, a, b, sa, sb);
    // A hunk too large to tell statement by statement whose every statement is the same.
    bulks.retain(|bk| !all_same(bk, sa, sb, &same));
    let tolerance = arc_tolerance(a);
    changes.retain(|c| {
        let only_respelled = c.kind == ChangeKind::ToolpathChanged
            && c.deviation.is_some_and(|d| d <= tolerance)
            && same.iter().any(|&(o, e)| (o, e) == (c.original_line, c.line) || (c.original_line.is_none() && e == c.line));
        !only_respelled
    });
    let exempt = |o: Option<u32>, e: Option<u32>| {
        (o.is_some() || e.is_some())
            && o.is_none_or(|o| same.iter().any(|s| s.0 == Some(o)))
            && e.is_none_or(|e| same.iter().any(|s| s.1 == Some(e)))
    };
    items.retain(|it| !exempt(line(sa, it.original), line(sb, it.edited)));
    let spans_a = spans(&a.plan.workingsteps);
    let spans_b = spans(&b.plan.workingsteps);
    // Locate each plan change at the statements of its workingstep that show it.
    let mut explained = vec![false; changes.len()];
    for (n, c) in changes.iter_mut().enumerate() {
        let Some((i, j)) = pair_of(c, a.plan, b.plan, pairs) else { continue };
        let in_a = |l: u32| i.is_some_and(|i| spans_a[i].contains(&l));
        let in_b = |l: u32| j.is_some_and(|j| spans_b[j].contains(&l));
        let mut at: Vec<(Option<u32>, Option<u32>)> = Vec::new();
        for it in items.iter_mut() {
            let (lo, le) = (line(sa, it.original), line(sb, it.edited));
            if !(lo.is_some_and(in_a) || le.is_some_and(in_b)) {
                continue;
            }
            if it.diffs.iter().any(|d| shows(c.kind, d, a.dialect, it.ctx)) {
                it.located = true;
                it.located_kinds.push(c.kind);
                it.call_located |= c.kind == ChangeKind::WorkPlaneChanged
                    && it.diffs.iter().any(|d| d.1.as_ref().is_some_and(|t| t.sort == Sort::Call) && shows(c.kind, d, a.dialect, it.ctx));
                at.push((lo, le));
            }
        }
        for bk in &bulks {
            let lo = bk.hunk.original.clone().map(|k| sa[k].line).find(|l| in_a(*l));
            let le = bk.hunk.edited.clone().map(|k| sb[k].line).find(|l| in_b(*l));
            if lo.is_some() || le.is_some() {
                at.push((lo, le));
            }
        }
        if at.is_empty() {
            continue;
        }
        explained[n] = true;
        at.sort_by_key(|&(o, e)| (e.or(o), o));
        at.dedup();
        if !at.iter().any(|&(o, e)| (e.is_some() && e == c.line) || (e.is_none() && o.is_some() && o == c.original_line)) {
            (c.original_line, c.line) = at[0];
        }
        c.detail.at = at;
    }
    // What no statement explains: the effects of changed variables, calls and jumps.
    let effects: Vec<String> = changes
        .iter()
        .zip(&explained)
        .filter(|(c, e)| !**e && c.kind != ChangeKind::RiskyEdit)
        .map(|(c, _)| format!("workingstep {}: {}", c.workingstep, c.phrase()))
        .collect();
    let effect = match effects.len() {
        0 => None,
        1..=2 => Some(effects.join("; ")),
        n => Some(format!("{}; and {} more", effects[..2].join("; "), n - 2)),
    };
    super::turning::merge_feature_repeats(changes);
    merge_repeats(changes);
    let mut added = Vec::new();
    let mut budget = height::Budget::default();
    for it in &mut items {
        let lo = line(sa, it.original);
        let le = line(sb, it.edited);
        let ws = workingstep_at(lo, le, a.plan, b.plan, &spans_a, &spans_b, pairs);
        // An absolute height the later incremental moves start from, the plan not showing it.
        if let Some(mut c) = inherited_height(it, (a, b), (sa, sb), &mut budget) {
            (c.workingstep, c.operation) = ws.clone();
            (c.original_line, c.line) = (lo, le);
            c.detail.at = vec![(lo, le)];
            added.push(c);
            if it.diffs.is_empty() {
                continue;
            }
        }
        // A statement over several lines (`CYCL DEF 200 ~`) is named whole.
        let last = |s: &[Stmt], i: Option<usize>| i.map(|i| s[i].last).filter(|&l| Some(l) != line(s, i));
        for mut c in statement_changes(it, lo, le, ws, b.dialect) {
            if it.class == Class::Machining && untyped(c.kind) {
                c.detail.effect.clone_from(&effect);
            }
            (c.detail.original_line_end, c.detail.line_end) = (last(sa, it.original), last(sb, it.edited));
            added.push(c);
        }
    }
    for bk in &bulks {
        let (ra, rb) = (&bk.hunk.original, &bk.hunk.edited);
        let first = |s: &[Stmt], r: &std::ops::Range<usize>| (!r.is_empty()).then(|| s[r.start].line);
        let last = |s: &[Stmt], r: &std::ops::Range<usize>| (!r.is_empty()).then(|| s[r.end - 1].last);
        let (lo, le) = (first(sa, ra), first(sb, rb));
        let ws = workingstep_at(lo, le, a.plan, b.plan, &spans_a, &spans_b, pairs);
        let lines = |n: usize, f: Option<u32>, l: Option<u32>| match (f, l) {
            (Some(f), Some(l)) if f != l => format!("{n} statements at lines {f}–{l}"),
            (Some(f), _) => format!("{n} statement{} at line {f}", if n == 1 { "" } else { "s" }),
            _ => "nothing".to_owned(),
        };
        let mut c = blank(if bk.class == Class::Output { ChangeKind::OutputChanged } else { ChangeKind::StatementChanged }, ws);
        c.field = "statements".into();
        c.before = lines(ra.len(), lo, last(sa, ra));
        c.after = lines(rb.len(), le, last(sb, rb));
        (c.original_line, c.line) = (lo, le);
        c.detail.original_line_end = last(sa, ra);
        c.detail.line_end = last(sb, rb);
        c.detail.at = vec![(lo, le)];
        if bk.class == Class::Machining {
            c.detail.effect.clone_from(&effect);
        }
        added.push(c);
    }
    follow::follow(&mut added, a, b, (sa, sb));
    merge_typed(&mut added);
    changes.extend(added);
    fold_length_offset(changes);
    // Stable: the plan's changes first within a workingstep, statements by line.
    changes.sort_by_key(|c| c.workingstep);
    if cfg!(debug_assertions) {
        let missing = uncovered(changes, &hunks, sa, sb, &same);
        assert!(missing.is_empty(), "differing statements no change names (original, edited line): {missing:?}");
    }
}

/// The height change of an item whose height word alone (of its moves) differs, in absolute
/// distances, both programs reaching the later heights by incremental steps from it
/// ([`height::inherited`]): that word taken out of the item's differences, told as the start
/// height of the later moves.
fn inherited_height(
    it: &mut Item,
    (a, b): (Program<'_>, Program<'_>),
    (sa, sb): (&[Stmt], &[Stmt]),
    budget: &mut height::Budget,
) -> Option<Change> {
    let (Some(oi), Some(ei)) = (it.original, it.edited) else { return None };
    if it.located || it.class != Class::Machining {
        return None;
    }
    let axis = height::axis(b.dialect)?;
    let number = |t: &Option<Token>| t.as_ref().filter(|t| t.sort == Sort::Word && t.key == axis).and_then(|t| t.value.parse::<f64>().ok());
    let n = it.diffs.iter().position(|(x, y)| number(x).zip(number(y)).is_some_and(|(p, q)| p != q))?;
    if !(height::inherited(b, sb, ei, axis, budget) && height::inherited(a, sa, oi, axis, budget)) {
        return None;
    }
    let (x, y) = it.diffs.remove(n);
    let mut c = blank(ChangeKind::DepthChanged, (0, String::new()));
    c.field = "start height of the later incremental moves".into();
    c.before = x.map(|t| t.text).unwrap_or_default();
    c.after = y.map(|t| t.text).unwrap_or_default();
    Some(c)
}

/// Kinds that feature recognition derives, which comments (stock and tool sizes) feed.
fn derived(kind: ChangeKind) -> bool {
    use ChangeKind as K;
    matches!(kind, K::FeatureChanged | K::AxialDepthChanged | K::StepoverChanged | K::AllowanceChanged | K::StrategyChanged)
}

/// The same plan change in several places seen at the same statements, or carried on into
/// later workingsteps from where it is seen (one `M7` for the whole program, one dwell in a
/// loop): told once, naming the other workingsteps.
fn merge_repeats(changes: &mut Vec<Change>) {
    super::fold_repeats(
        changes,
        |c| !c.detail.at.is_empty(),
        |c, d| d.detail.at == c.detail.at || (d.detail.at.is_empty() && d.workingstep > c.workingstep),
        |_, _| {},
    );
}

/// The differing statements no change names: (original line, edited line), one side `None`.
/// The differing statements of `a` and `b` no change in `changes` names (see [`uncovered`]).
pub(super) fn unaccounted(a: Program<'_>, b: Program<'_>, changes: &[Change]) -> Vec<(Option<u32>, Option<u32>)> {
    let ((sa, _), (sb, _)) = (statement::read(a.text, a.dialect), statement::read(b.text, b.dialect));
    let hunks = statement::hunks_in(&sa, &sb, Some((a.text, b.text)));
    let (items, _) = itemize(&hunks, a, b, &sa, &sb);
    let same = same_machining(&items, &hunks, a, b, &sa, &sb);
    uncovered(changes, &hunks, &sa, &sb, &same)
}

/// The differing statements that machine the same (each as (original line, edited line), one
/// side `None` where only one side's line is named): arcs written another way that run the
/// same path (`R2.5` for `I0 J2.5`), modal words re-blocked, labels renamed one to one, straight
/// moves in other pieces, a motion word restating the motion in force.
fn same_machining(
    items: &[Item],
    hunks: &[Hunk],
    a: Program<'_>,
    b: Program<'_>,
    sa: &[Stmt],
    sb: &[Stmt],
) -> Vec<(Option<u32>, Option<u32>)> {
    let mut same = respelled(items, a, b, sa, sb);
    same.extend(reblocked(hunks, a, b, sa, sb));
    same.extend(relabelled(items, a, b, sa, sb));
    same.extend(retrace::retraced(hunks, a, b, sa, sb));
    same.extend(restated(hunks, a, b, sa, sb));
    same.extend(follow::moved_same(hunks, a, b, sa, sb));
    same
}

/// Whether every statement of a hunk too large to tell statement by statement machines the
/// same ([`same_machining`]).
fn all_same(bk: &Bulk, sa: &[Stmt], sb: &[Stmt], same: &[(Option<u32>, Option<u32>)]) -> bool {
    let o: std::collections::BTreeSet<u32> = same.iter().filter_map(|s| s.0).collect();
    let e: std::collections::BTreeSet<u32> = same.iter().filter_map(|s| s.1).collect();
    bk.hunk.original.clone().all(|k| o.contains(&sa[k].line)) && bk.hunk.edited.clone().all(|k| e.contains(&sb[k].line))
}

/// The statements of hunks that only set modal states, re-blocked (`G54 G18 G21 F400` written
/// as `G54 G18 G21` and `F400`; a safety block `G20 G90 G17 G94 G49 G40 G80` split into one
/// code a block): none of their words moves, calls, switches anything on or reads a variable,
/// so no move runs between them, and both sides leave the same state for what runs next — each
/// modal group they set (the dictionary's group of a code; a feed, `F`) set by both, to the
/// same last word. A code that gives way in its group to a later one is overridden the same as
/// in one block, so the order within a group counts (`G91` then `G90` is not `G90` then
/// `G91`); the order across groups does not, save where the control stops at a plane or units
/// code under cutter radius compensation (the dictionary's `modes-under-comp`: RS274/NGC,
/// LinuxCNC; `plane-under-comp`: Fanuc PS0037, the plane only): there `G40` then `G18` runs and `G18` then `G40` stops the program, so a plane or
/// units code is told apart by whether a `G40` of the hunk's earlier statements comes before
/// it (in one block the control sets the plane and units before compensation: LinuxCNC's order
/// of execution). Each as (original line, None) or (None, edited line).
fn reblocked(hunks: &[Hunk], a: Program<'_>, b: Program<'_>, sa: &[Stmt], sb: &[Stmt]) -> Vec<(Option<u32>, Option<u32>)> {
    let mut out = Vec::new();
    for h in hunks.iter().filter(|h| !h.original.is_empty() && !h.edited.is_empty() && h.original.len() + h.edited.len() <= 8) {
        if let (Some(x), Some(y)) = (modal_state(a, sa, &h.original), modal_state(b, sb, &h.edited))
            && !x.is_empty()
            && x == y
        {
            out.extend(h.original.clone().map(|k| (Some(sa[k].line), None)));
            out.extend(h.edited.clone().map(|k| (None, Some(sb[k].line))));
        }
    }
    out
}

/// The modal state the statements `r` of `p` set, by group: each group's last word, in one
/// spelling (`G0090` is `G90`); `None` where one of their words is not a modal state's
/// (see [`reblocked`]).
fn modal_state(p: Program<'_>, s: &[Stmt], r: &std::ops::Range<usize>) -> Option<std::collections::BTreeMap<String, String>> {
    use Meaning as M;
    let mut state = std::collections::BTreeMap::new();
    // Whether a `G40` stands in an earlier statement of `r` (see [`reblocked`]).
    let (mut comp_off, mut comp_off_here) = (false, false);
    for k in r.clone() {
        comp_off |= std::mem::take(&mut comp_off_here);
        for t in statement::tokens_in(&statement::text_of(p.text, p.dialect, &s[k]), p.dialect) {
            let code = about(&t, p.dialect);
            comp_off_here |= matches!(code, About::Code(M::CompOff));
            let locked = (p.dialect.behaviour.comp_locks_modes && matches!(code, About::Code(M::UnitsInch | M::UnitsMm)))
                || (p.dialect.behaviour.plane_under_comp_stops && matches!(code, About::Code(M::PlaneXy | M::PlaneXz | M::PlaneYz)));
            let group = match code {
                About::Code(
                    m @ (M::PlaneXy
                    | M::PlaneXz
                    | M::PlaneYz
                    | M::UnitsInch
                    | M::UnitsMm
                    | M::DistanceAbsolute
                    | M::DistanceIncremental
                    | M::ArcDistanceAbsolute
                    | M::ArcDistanceIncremental
                    | M::FeedInverseTime
                    | M::FeedPerMinute
                    | M::FeedPerRev
                    | M::Wcs
                    | M::PathMode
                    | M::RetractInitial
                    | M::RetractR
                    | M::CycleCancel
                    | M::CompOff
                    | M::LengthCompCancel),
                ) => code_group(&t, p.dialect).map_or_else(|| format!("{m:?}"), |g| format!("group {g}")),
                About::Address(Role::F) if t.value.parse::<f64>().is_ok() => "F".to_owned(),
                _ => return None,
            };
            let word = if locked && comp_off { format!("{} after G40", t.text) } else { t.text };
            state.insert(group, word);
        }
    }
    Some(state)
}

/// The dictionary's modal group of a G or M code token (`G90`).
fn code_group(t: &Token, d: &Dialect) -> Option<usize> {
    let letter @ ('G' | 'M') = t.key.chars().next()? else { return None };
    let n = t.key[1..].parse::<f64>().ok()?;
    d.code(letter, (n * 10.0).round().max(0.0) as u32).map(|c| c.group)
}

/// The moves `p`'s plan makes from each of `lines`, by line.
fn moves_at(p: Program<'_>, lines: &std::collections::BTreeSet<u32>) -> std::collections::BTreeMap<u32, Vec<crate::plan::Move>> {
    let mut by_line: std::collections::BTreeMap<u32, Vec<crate::plan::Move>> = std::collections::BTreeMap::new();
    for w in &p.plan.workingsteps {
        for m in w.toolpath.iter().filter(|m| lines.contains(&m.line)) {
            by_line.entry(m.line).or_default().push(m);
        }
    }
    by_line
}

/// Whether two moves run the same path within `tolerance`: the same ends, and the same arc
/// (centre, turns, axis) or none.
fn same_path(x: &crate::plan::Move, y: &crate::plan::Move, tolerance: f64) -> bool {
    let near = |p: crate::plan::P3, q: crate::plan::P3| (0..3).all(|i| (p[i] - q[i]).abs() <= tolerance);
    near(x.from, y.from)
        && near(x.to, y.to)
        && match (x.arc, y.arc) {
            (Some(u), Some(v)) => near(u.center, v.center) && u.turns == v.turns && near(u.axis, v.axis),
            (None, None) => true,
            _ => false,
        }
}

/// How many statements [`restated`] reads at most in one diff: a bound on its work.
const RESTATED_MOST: usize = 20_000;

/// The differing statements that only write the motion code in force (`X0.5 Y0.9` written
/// `G0 X0.5 Y0.9` after a rapid): hunks with as many statements on each side, paired in order,
/// each pair differing only by motion codes one side has, and the moves both programs make
/// from the pair the same (kind, ends, feed, arc), so that the code was the mode in force. A
/// pair from which neither program moves (a move to where the tool stands) is the same where
/// its hunk has a pair that moves alike and none that moves otherwise. As (original line,
/// edited line).
fn restated(hunks: &[Hunk], a: Program<'_>, b: Program<'_>, sa: &[Stmt], sb: &[Stmt]) -> Vec<(Option<u32>, Option<u32>)> {
    let motion =
        |t: &Token, d: &Dialect| matches!(about(t, d), About::Code(Meaning::Rapid | Meaning::Linear | Meaning::ArcCw | Meaning::ArcCcw));
    let mut budget = RESTATED_MOST;
    let mut candidates = Vec::new();
    for h in hunks.iter().filter(|h| !h.original.is_empty() && h.original.len() == h.edited.len()) {
        if budget < h.original.len() {
            break;
        }
        budget -= h.original.len();
        for (i, j) in h.original.clone().zip(h.edited.clone()) {
            let ta = statement::tokens_in(&statement::text_of(a.text, a.dialect, &sa[i]), a.dialect);
            let tb = statement::tokens_in(&statement::text_of(b.text, b.dialect, &sb[j]), b.dialect);
            let diffs = token_diffs(&ta, &tb);
            let only_motion = !diffs.is_empty()
                && diffs.iter().all(|d| match d {
                    (Some(t), None) => motion(t, a.dialect),
                    (None, Some(t)) => motion(t, b.dialect),
                    _ => false,
                });
            if only_motion {
                candidates.push((sa[i].line, sb[j].line, h.original.start));
            }
        }
    }
    if candidates.is_empty() {
        return Vec::new();
    }
    let (ma, mb) = (moves_at(a, &candidates.iter().map(|c| c.0).collect()), moves_at(b, &candidates.iter().map(|c| c.1).collect()));
    let alike = |x: &crate::plan::Move, y: &crate::plan::Move| x.kind == y.kind && x.feed == y.feed && same_path(x, y, super::TOLERANCE);
    // By pair: Some(true) moves alike, Some(false) otherwise, None: neither moves.
    let verdict = |lo: &u32, le: &u32| match (ma.get(lo), mb.get(le)) {
        (Some(x), Some(y)) => Some(x.len() == y.len() && x.iter().zip(y).all(|(x, y)| alike(x, y))),
        (None, None) => None,
        _ => Some(false),
    };
    let mut hunk_ok: std::collections::BTreeMap<usize, (bool, bool)> = std::collections::BTreeMap::new();
    for (lo, le, h) in &candidates {
        let e = hunk_ok.entry(*h).or_insert((false, false));
        match verdict(lo, le) {
            Some(true) => e.0 = true,
            Some(false) => e.1 = true,
            None => {}
        }
    }
    candidates
        .iter()
        .filter(|(lo, le, h)| match verdict(lo, le) {
            Some(same) => same,
            None => hunk_ok.get(h).is_some_and(|&(alike, other)| alike && !other),
        })
        .map(|&(lo, le, _)| (Some(lo), Some(le)))
        .collect()
}

/// The differing statements that only rename labels one to one over both programs (a
/// subprogram renumbered with its calls, an O-word's label on all its statements): see
/// [`super::rename`]. As (original line, edited line).
fn relabelled(items: &[Item], a: Program<'_>, b: Program<'_>, sa: &[Stmt], sb: &[Stmt]) -> Vec<(Option<u32>, Option<u32>)> {
    if a.dialect.name != b.dialect.name {
        return Vec::new();
    }
    let pairs: Vec<(usize, usize)> = items.iter().filter_map(|it| Some((it.original?, it.edited?))).collect();
    if pairs.is_empty() {
        return Vec::new();
    }
    super::rename::renamed(&pairs, (a.text, b.text), (sa, sb), a.dialect)
        .into_iter()
        .map(|(i, j)| (Some(sa[i].line), Some(sb[j].line)))
        .collect()
}

/// The control's arc tolerance for `p`, mm: how far apart two arcs' end points and centres
/// may lie and still be the same arc to it.
fn arc_tolerance(p: Program<'_>) -> f64 {
    let b = &p.dialect.behaviour;
    let t = if p.plan.units == Some(crate::canon::Units::Inch) { b.arc_tolerance_inch * 25.4 } else { b.arc_tolerance_mm };
    t.max(super::TOLERANCE)
}

/// The differing statements that only write an arc another way (`R2.5` for `I0 J2.5`, a
/// centre rounded otherwise): their differing words are all arc-centre or radius words, and
/// the moves both programs make from them are the same arcs, end points and centres within
/// the control's arc tolerance. As (original line, edited line).
fn respelled(items: &[Item], a: Program<'_>, b: Program<'_>, sa: &[Stmt], sb: &[Stmt]) -> Vec<(Option<u32>, Option<u32>)> {
    let centre_words = |it: &Item| {
        it.original.is_some()
            && it.edited.is_some()
            && it.diffs.iter().all(|(x, y)| {
                let t = y.as_ref().or(x.as_ref()).expect("a difference has a side");
                t.is_address() && matches!(about(t, a.dialect), About::Address(Role::I | Role::J | Role::K | Role::R))
            })
    };
    let candidates: Vec<(u32, u32)> =
        items.iter().filter(|it| centre_words(it)).filter_map(|it| Some((sa[it.original?].line, sb[it.edited?].line))).collect();
    if candidates.is_empty() {
        return Vec::new();
    }
    let (ma, mb) = (moves_at(a, &candidates.iter().map(|c| c.0).collect()), moves_at(b, &candidates.iter().map(|c| c.1).collect()));
    let tolerance = arc_tolerance(a);
    // Arcs both, on the same path.
    let alike = |x: &crate::plan::Move, y: &crate::plan::Move| x.arc.is_some() && same_path(x, y, tolerance);
    candidates
        .into_iter()
        .filter(|(lo, le)| match (ma.get(lo), mb.get(le)) {
            (Some(x), Some(y)) => x.len() == y.len() && x.iter().zip(y).all(|(x, y)| alike(x, y)),
            _ => false,
        })
        .map(|(lo, le)| (Some(lo), Some(le)))
        .collect()
}

/// The differing statements no change names: (original line, edited line), one side `None`;
/// the arcs only written another way (`same`) apart.
pub(super) fn uncovered(
    changes: &[Change],
    hunks: &[Hunk],
    sa: &[Stmt],
    sb: &[Stmt],
    same: &[(Option<u32>, Option<u32>)],
) -> Vec<(Option<u32>, Option<u32>)> {
    let names = |side: usize, line: u32| {
        changes.iter().any(|c| {
            let (first, end) = if side == 0 { (c.original_line, c.detail.original_line_end) } else { (c.line, c.detail.line_end) };
            let in_range = first.is_some_and(|f| line >= f && line <= end.unwrap_or(f));
            in_range || c.detail.at.iter().any(|&(o, e)| if side == 0 { o == Some(line) } else { e == Some(line) })
        })
    };
    let mut out = Vec::new();
    let same_a = |l: u32| same.iter().any(|s| s.0 == Some(l));
    // (A hunk's statements re-blocked are listed one side at a time.)
    let same_b = |l: u32| same.iter().any(|s| s.1 == Some(l));
    for h in hunks {
        for k in h.original.clone() {
            if same_a(sa[k].line) {
                continue;
            }
            if !names(0, sa[k].line) {
                out.push((Some(sa[k].line), None));
            }
        }
        for k in h.edited.clone() {
            if same_b(sb[k].line) {
                continue;
            }
            if !names(1, sb[k].line) {
                out.push((None, Some(sb[k].line)));
            }
        }
    }
    out
}

/// Each hunk's statements paired and their tokens compared, or the hunk whole where large.
fn itemize(hunks: &[Hunk], a: Program<'_>, b: Program<'_>, sa: &[Stmt], sb: &[Stmt]) -> (Vec<Item>, Vec<Bulk>) {
    let mut items = Vec::new();
    let mut bulks = Vec::new();
    // What the blocks around each statement make of it, read only for a lathe's dictionary.
    let around = |p: Program<'_>, s: &[Stmt]| {
        if hunks.is_empty() || !super::around::applies(p.dialect) { Vec::new() } else { super::around::read(p.text, p.dialect, s) }
    };
    let (around_a, around_b) = (around(a, sa), around(b, sb));
    for h in hunks {
        let class_of = |s: &[Stmt], r: &std::ops::Range<usize>| r.clone().all(|k| s[k].class == Class::Output);
        if h.original.len() > DETAILED || h.edited.len() > DETAILED {
            let output = class_of(sa, &h.original) && class_of(sb, &h.edited);
            bulks.push(Bulk { hunk: h.clone(), class: if output { Class::Output } else { Class::Machining } });
            continue;
        }
        let ta: Vec<Vec<Token>> =
            h.original.clone().map(|k| statement::tokens_in(&statement::text_of(a.text, a.dialect, &sa[k]), a.dialect)).collect();
        let tb: Vec<Vec<Token>> =
            h.edited.clone().map(|k| statement::tokens_in(&statement::text_of(b.text, b.dialect, &sb[k]), b.dialect)).collect();
        // Whole branches that only choose what to show (`o100 if` … `(msg, …)` … `o100 endif`):
        // output, as the messages they choose between.
        let shows_only = only_output(&ta, &h.original, sa, a.dialect) && only_output(&tb, &h.edited, sb, b.dialect);
        let (ca, cb): (Vec<Class>, Vec<Class>) =
            (h.original.clone().map(|k| sa[k].class).collect(), h.edited.clone().map(|k| sb[k].class).collect());
        for (x, y) in pair_statements((&ta, &ca), (&tb, &cb), a.dialect) {
            let diffs = match (x, y) {
                (Some(x), Some(y)) => token_diffs(&ta[x], &tb[y]),
                (Some(x), None) => ta[x].iter().map(|t| (Some(t.clone()), None)).collect(),
                (None, Some(y)) => tb[y].iter().map(|t| (None, Some(t.clone()))).collect(),
                (None, None) => Vec::new(),
            };
            let oi = x.map(|x| h.original.start + x);
            let ei = y.map(|y| h.edited.start + y);
            let output = shows_only || (oi.is_none_or(|k| sa[k].class == Class::Output) && ei.is_none_or(|k| sb[k].class == Class::Output));
            let class = if output { Class::Output } else { Class::Machining };
            let diffs = if diffs.is_empty() {
                // Equal tokens, other text (a blank inside a name): the statements whole.
                let whole = |t: &[Token]| Token {
                    key: String::new(),
                    value: String::new(),
                    text: t.iter().map(|t| t.text.as_str()).collect::<Vec<_>>().join(" "),
                    sort: Sort::Other,
                };
                vec![(x.map(|x| whole(&ta[x])), y.map(|y| whole(&tb[y])))]
            } else {
                diffs
            };
            let moves = oi.map_or(0, |k| sa[k].moves) | ei.map_or(0, |k| sb[k].moves);
            let ctx_of = |t: &[Vec<Token>], i: Option<usize>, d: &Dialect| i.map_or_else(Context::default, |i| Context::of(&t[i], d));
            let mut ctx = ctx_of(&ta, x, a.dialect).or(ctx_of(&tb, y, b.dialect));
            let at = |v: &[Option<super::around::Around>], i: Option<usize>| i.and_then(|k| v.get(k).copied().flatten());
            ctx.around = at(&around_b, ei).or(at(&around_a, oi));
            let calls = (oi.is_some_and(|k| sa[k].moves & statement::CALL != 0), ei.is_some_and(|k| sb[k].moves & statement::CALL != 0));
            // A call the parser reads anywhere in the block (`R910=25 … L100 P1`): flow.
            if ctx.flow.is_none() && (calls.0 || calls.1) {
                ctx.flow = Some(control::Flow::Call);
            }
            let mut jump_words = (Vec::new(), Vec::new());
            for (t, d) in [(x.map(|x| &ta[x]), a.dialect), (y.map(|y| &tb[y]), b.dialect)] {
                let Some(t) = t else { continue };
                let target = control::jump_target_tokens(t, d);
                jump_words.0.extend(target.iter().map(|t| t.text.clone()));
                jump_words.1.extend(t[..t.len() - target.len()].iter().filter(|_| !target.is_empty()).map(|t| t.text.clone()));
            }
            let tokens = (x.map(|x| ta[x].clone()).unwrap_or_default(), y.map(|y| tb[y].clone()).unwrap_or_default());
            let tables = (open_table(a, sa, oi, &tokens.0), open_table(b, sb, ei, &tokens.1));
            items.push(Item {
                tables,
                tokens,
                jump_words,
                calls,
                original: oi,
                edited: ei,
                diffs,
                class,
                moves,
                located: false,
                call_located: false,
                located_kinds: Vec::new(),
                ctx,
            });
        }
    }
    (items, bulks)
}

/// The table `p` opened last before its statement `k` (the dictionary's `tool-table` open
/// keyword: Heidenhain `FN 26: TABOPEN TNC:\TOOL.T`), as written, where that statement (its
/// `tokens`) writes a table's row (the `tool-table` write keyword, `FN 27: TABWRITE`).
fn open_table(p: Program<'_>, s: &[Stmt], k: Option<usize>, tokens: &[Token]) -> Option<String> {
    let tt = p.dialect.macros.tool_table.as_ref()?;
    let k = k?;
    let writes = tokens.iter().any(|t| t.text.to_ascii_uppercase().contains(&tt.write));
    if !writes {
        return None;
    }
    s[..k].iter().rev().find_map(|st| {
        let text = statement::text_of(p.text, p.dialect, st);
        let at = text.to_ascii_uppercase().find(&tt.open)? + tt.open.len();
        Some(text[at..].trim().to_owned())
    })
}

/// Whether a hunk's statements on one side are whole branches (as many opened as closed) whose
/// other statements only write text, with at least one such: nothing the machine does depends on
/// them. An empty side is.
fn only_output(tokens: &[Vec<Token>], range: &std::ops::Range<usize>, s: &[Stmt], d: &Dialect) -> bool {
    if range.is_empty() {
        return true;
    }
    let (mut depth, mut shown) = (0, false);
    for (t, k) in tokens.iter().zip(range.clone()) {
        if s[k].class == Class::Output {
            shown = true;
            continue;
        }
        match control::branch_depth(t, d) {
            Some(n) => depth += n,
            None => return false,
        }
        if depth < 0 {
            return false;
        }
    }
    shown && depth == 0
}

/// The statements of a hunk paired: first those whose first token has the same key (in
/// order, by a longest common subsequence), then the rest between them in order where the
/// two share a role (a code, an address, a variable, a call or keyword of the same key: `G1
/// X10 F500` for `X10 F800`); two that share none are one removed and one added (`M65 P…`
/// is not `G53 G0 Z…` written another way). Two moves that begin with one motion code pair
/// only where they share more than it (an axis: `G0 Z0` and `G0 A0` are one removed, one added).
fn pair_statements(
    (a, ca): (&[Vec<Token>], &[Class]),
    (b, cb): (&[Vec<Token>], &[Class]),
    d: &Dialect,
) -> Vec<(Option<usize>, Option<usize>)> {
    let key = |t: &[Token]| t.first().map(|t| t.key.clone()).unwrap_or_default();
    let (ka, kb): (Vec<String>, Vec<String>) = (a.iter().map(|t| key(t)).collect(), b.iter().map(|t| key(t)).collect());
    let mut anchors = Vec::new();
    statement::lcs(&ka, &kb, 0, 0, &mut anchors);
    // A statement's roles: each word's kind where the dictionary gives it one (`G20` and
    // `G21` both the units), else its key; a call; a control statement's sort; text shown.
    let roles = |t: &[Token], class: Class| -> Vec<String> {
        let ctx = Context::of(t, d);
        // A motion code alone is no shared role: the axes it moves are (`G0 Z0` is not `G0 A0`).
        let mut r: Vec<String> = Vec::new();
        for t in t.iter().filter(|t| !t.key.is_empty() && !motion_code(t, d)) {
            match (t.sort, typed::kind_of(t, ctx, d)) {
                (Sort::Call, _) => r.push("call".to_owned()),
                (_, Some((kind, _))) if kind != ChangeKind::MachineFunctionChanged => r.push(kind.as_str().to_owned()),
                _ => {}
            }
            // A word under the block-delete slash is the same word (`/Y40.` and `Y40.`).
            let key = t.key.trim_start_matches(|c: char| c == '/' || c.is_ascii_digit());
            if !key.is_empty() {
                r.push(format!("{:?} {key}", t.sort));
            }
        }
        // An O-word statement by its keyword (`O<A>SUB` and `O<B>SUB`: a subroutine's head).
        if let Some(first) = t.first() {
            let k = control::keyword(&first.key);
            if k.len() < first.key.len() {
                r.push(format!("O-word {}", k.split(|c: char| !c.is_ascii_alphabetic()).next().unwrap_or("")));
            }
        }
        // A control statement by its keyword (`O250IF` and `O400IF` both an `IF`, not an
        // `ENDIF`).
        if let Some(f) = control::flow_of(t, d) {
            let k = t.first().map_or("", |t| control::keyword(&t.key));
            r.push(format!("{f:?} {}", k.split(|c: char| !c.is_ascii_alphabetic()).next().unwrap_or("")));
        }
        if class == Class::Output || r.is_empty() {
            r.push("text".to_owned());
        }
        r
    };
    // A statement put under the block-delete slash (`/N160 Y40.`, read as one piece) is itself.
    let plain = |t: &[Token]| t.iter().map(|t| t.text.as_str()).collect::<String>().trim_start_matches('/').to_owned();
    let shared = |x: usize, y: usize| {
        if plain(&a[x]) == plain(&b[y]) {
            return true;
        }
        let rb = roles(&b[y], cb[y]);
        roles(&a[x], ca[x]).iter().any(|r| rb.contains(r))
    };
    // Two moves of one motion code share its key, not a role: they pair only where they move
    // an axis in common (`G0 Z0` is not `G0 A0` written another way).
    let motion_key = |t: &[Token]| t.first().is_some_and(|t| motion_code(t, d));
    let mut out = Vec::new();
    for pair in statement::pairs_along(anchors, a.len(), b.len()) {
        match pair {
            (Some(x), Some(y)) if (ka[x] != kb[y] || motion_key(&a[x])) && !shared(x, y) => {
                out.push((Some(x), None));
                out.push((None, Some(y)));
            }
            p => out.push(p),
        }
    }
    out
}

/// Whether a token is a motion code (`G0`, `G1`, `G2`, `G3`).
fn motion_code(t: &Token, d: &Dialect) -> bool {
    matches!(about(t, d), About::Code(Meaning::Rapid | Meaning::Linear | Meaning::ArcCw | Meaning::ArcCcw | Meaning::RapidBlock))
}

/// How the tokens of two statements differ: each token of `a` matched to the first unused
/// one of `b` with the same key.
fn token_diffs(a: &[Token], b: &[Token]) -> Vec<(Option<Token>, Option<Token>)> {
    let mut used = vec![false; b.len()];
    let mut out = Vec::new();
    for x in a {
        match (0..b.len()).find(|&j| !used[j] && b[j].key == x.key && b[j].sort == x.sort) {
            Some(j) => {
                used[j] = true;
                // An expression of the same value (`572.86/2` for `286.43`) is no difference.
                let value = |t: &Token| statement::constant(&t.value).or_else(|| t.value.parse::<f64>().ok());
                let same = value(x).zip(value(&b[j])).is_some_and(|(u, v)| (u - v).abs() <= 1e-9 * u.abs().max(1.0));
                if b[j].text != x.text && !same {
                    out.push((Some(x.clone()), Some(b[j].clone())));
                }
            }
            None => out.push((Some(x.clone()), None)),
        }
    }
    for (y, u) in b.iter().zip(&used) {
        if !u {
            out.push((None, Some(y.clone())));
        }
    }
    out
}

/// Whether a token difference shows a plan change of `kind`: a word whose code or address the
/// dictionary says is about what the change is about. Variables, calls and jumps show no
/// plan change by themselves.
fn shows(kind: ChangeKind, d: &(Option<Token>, Option<Token>), dialect: &Dialect, ctx: Context) -> bool {
    let tok = d.1.as_ref().or(d.0.as_ref()).expect("a difference has a side");
    // A swivel cycle's arguments (`CYCLE800(…)`) state the work plane; a cylinder surface
    // transformation's (`TRACYL(d)`) the cylinder whose developed surface it is.
    if kind == ChangeKind::WorkPlaneChanged && tok.sort == statement::Sort::Call {
        return dialect
            .cycles
            .iter()
            .any(|c| matches!(c.meaning, Meaning::TiltCycle | Meaning::CylindricalInterpolation) && c.name.eq_ignore_ascii_case(&tok.key));
    }
    // A named cycle's argument states what its role names (`CYCLE95(…, MID, …)`: the depth of
    // cut); a turning cycle's (`CYCLE97(…, TDEP, …)`) what the plan tells in a turner's terms.
    if let (Some(x), Some(y)) = d
        && x.sort == statement::Sort::Call
        && x.key == y.key
    {
        let turning = typed::cycle_args(&x.key, dialect).is_some() && super::turning::named_turning(&x.key, dialect);
        return differing_roles(x, y, dialect).any(|r| {
            argument_kind(r) == Some(kind) || (turning && kind == ChangeKind::CycleParameterChanged && super::turning::role_shows(r, kind))
        });
    }
    // The spindle's limit under constant surface speed as an assignment (Siemens `LIMS=2500`).
    if kind == ChangeKind::SpindleSpeedChanged
        && tok.sort == statement::Sort::Assign
        && about(tok, dialect) == About::Address(Role::SpindleLimit)
    {
        return true;
    }
    if !tok.is_address() && !typed::axis_indexed_move(tok, dialect) {
        return false;
    }
    // A lathe cycle's word the dictionary gives a role (Haas `G71 … D0.06`: the depth of cut;
    // `G76 … K0.92 A60`: the thread's height, the tool's angle) states what its role names.
    // Where the role does not show the change, the word may mean something else in the block
    // (Fanuc's two-block `G71`: the first block's `U` the depth of cut, the second's, beside P
    // and Q, the finishing allowance), which the rules below tell.
    if let About::Address(letter) = about(tok, dialect)
        && let Some(role) = super::turning::cycle_role(letter, ctx.turn_cycle, dialect)
        && super::turning::role_shows(role, kind)
    {
        return true;
    }
    use ChangeKind as K;
    // A lathe cycle's own words (LinuxCNC `G76 … H2`: the spring passes) are its parameters,
    // not the offsets or feeds their letters name elsewhere.
    if ctx.other_cycle
        && matches!(kind, K::CycleParameterChanged | K::AxialDepthChanged | K::AllowanceChanged)
        && !matches!(about(tok, dialect), About::Address(Role::F | Role::S | Role::T | Role::G | Role::M | Role::N))
        && about(tok, dialect) != About::Unknown
        && matches!(about(tok, dialect), About::Address(_))
    {
        return true;
    }
    // A word its statement's codes give another sense (a dwell's `F`, a cycle's `H`) shows
    // that, not the technology its letter names elsewhere.
    let technology =
        matches!(kind, K::FeedChanged | K::SpindleSpeedChanged | K::LengthOffsetChanged | K::CutterCompChanged | K::ToolRenamed);
    if technology && ctx.special() && typed::kind_of(tok, ctx, dialect).is_some_and(|(k, _)| k != kind) {
        return false;
    }
    use Meaning as M;
    use Role as R;
    let a = about(tok, dialect);
    let code = |list: &[Meaning]| matches!(a, About::Code(m) if list.contains(&m));
    let address = |list: &[Role]| matches!(a, About::Address(r) if list.contains(&r));
    const FEED: [Meaning; 4] = [M::FeedInverseTime, M::FeedPerMinute, M::FeedPerRev, M::RapidBlock];
    const SPEED: [Meaning; 3] = [M::SpindleCss, M::SpindleRpm, M::SpindleLimit];
    const SPINDLE: [Meaning; 4] = [M::SpindleCw, M::SpindleCcw, M::SpindleStop, M::SpindleOrient];
    const COOLANT: [Meaning; 3] = [M::CoolantMist, M::CoolantFlood, M::CoolantOff];
    const LENGTH: [Meaning; 4] = [M::LengthCompPlus, M::LengthCompDynamic, M::LengthCompMinus, M::LengthCompCancel];
    const COMP: [Meaning; 5] = [M::CompOff, M::CompLeft, M::CompRight, M::CompLeftDiameter, M::CompRightDiameter];
    const STOPS: [Meaning; 2] = [M::ProgramStop, M::OptionalStop];
    const OVERRIDES: [Meaning; 3] = [M::OverridesOn, M::OverridesOff, M::FeedOverrideSwitch];
    match kind {
        K::FeedChanged => address(&[R::F, R::E, R::PlungeFeed]) || code(&FEED),
        // Under constant surface speed, its other word is the spindle's limit (LinuxCNC `G96 D2500`).
        K::SpindleSpeedChanged | K::SpindleModeChanged => {
            address(&[R::S, R::SpindleLimit]) || code(&SPEED) || (ctx.css && address(&[R::D]))
        }
        K::SpindleDirectionChanged => code(&SPINDLE),
        K::CoolantChanged => code(&COOLANT),
        K::ToolRenamed => address(&[R::T, R::D, R::ToolEdge, R::NextTool]) || code(&[M::ToolChange]),
        K::LengthOffsetChanged => address(&[R::H, R::ToolEdge]) || code(&LENGTH),
        K::CutterCompChanged => address(&[R::D, R::ToolEdge]) || code(&COMP),
        K::WorkOffsetChanged => address(&[R::P]) || code(&[M::Wcs, M::WcsExtended]),
        K::StopAdded | K::StopRemoved => code(&STOPS),
        K::DwellChanged => address(&[R::P, R::DwellTime]) || code(&[M::Dwell]),
        K::FeedOverrideChanged => code(&OVERRIDES),
        K::OptionalBlockChanged => tok.text.starts_with('/'),
        // The lead of a thread: F (Fanuc G32/G76), K (G33, the lathes that write the lead so).
        K::ThreadPitchChanged => address(&[R::F, R::K, R::P]),
        K::RiskyEdit => false,
        K::WorkingstepAdded | K::WorkingstepRemoved => true,
        K::StatementChanged | K::OutputChanged | K::ReturnMoveChanged | K::RotaryMoveChanged => false,
        // Geometry: anything but technology.
        _ => {
            let codes: [&[Meaning]; 8] = [&FEED, &SPEED, &SPINDLE, &COOLANT, &LENGTH, &COMP, &STOPS, &OVERRIDES];
            let technology = codes.iter().any(|l| code(l)) || address(&[R::F, R::S, R::T, R::H, R::D, R::ToolEdge, R::E]);
            !technology
        }
    }
}

/// The plan change a named cycle's argument states, by its role: the finishing allowance, the
/// depth of cut, a thread's pitch, a groove's or slot's width. The plan compares these in the
/// machine's terms (`depth of cut changed from 2.5 to 2`), so the argument needs no row of its own.
fn argument_kind(role: Role) -> Option<ChangeKind> {
    match role {
        Role::Allowance | Role::AllowanceX | Role::AllowanceZ => Some(ChangeKind::AllowanceChanged),
        Role::CutDepth => Some(ChangeKind::AxialDepthChanged),
        Role::Pitch | Role::ThreadSize => Some(ChangeKind::ThreadPitchChanged),
        Role::Width => Some(ChangeKind::FeatureChanged),
        _ => None,
    }
}

/// The roles of the arguments that differ between two calls of one named cycle.
fn differing_roles<'d>(x: &Token, y: &Token, d: &'d Dialect) -> impl Iterator<Item = Role> + 'd {
    let (pa, pb) = (statement::arguments(&x.value), statement::arguments(&y.value));
    let args = typed::cycle_args(&x.key, d).unwrap_or(&[]);
    args.iter().enumerate().filter(move |(k, _)| pa.get(*k) != pb.get(*k)).map(|(_, a)| a.role)
}

/// The lines each workingstep may be seen at: its own, and those between it and its
/// neighbours (a stop or a feed set between two workingsteps may belong to either); the
/// first's run from the start, the last's to the end.
fn spans(ws: &[Workingstep]) -> Vec<RangeInclusive<u32>> {
    (0..ws.len())
        .map(|k| {
            let from = if k == 0 { 1 } else { ws[k - 1].lines.1.saturating_add(1).min(ws[k].lines.0) };
            let to = if k + 1 == ws.len() { u32::MAX } else { ws[k + 1].lines.0.saturating_sub(1).max(ws[k].lines.1) };
            from..=to
        })
        .collect()
}

/// The positions of a change's workingstep in the two plans.
fn pair_of(
    c: &Change,
    a: &ProcessPlan,
    b: &ProcessPlan,
    pairs: &[(Option<usize>, Option<usize>)],
) -> Option<(Option<usize>, Option<usize>)> {
    if c.kind == ChangeKind::WorkingstepAdded {
        let j = b.workingsteps.iter().position(|w| w.index == c.workingstep)?;
        return pairs.iter().find(|p| p.1 == Some(j)).copied();
    }
    let i = a.workingsteps.iter().position(|w| w.index == c.workingstep)?;
    pairs.iter().find(|p| p.0 == Some(i)).copied()
}

/// The workingstep (the original's index and label) a statement at these lines belongs to;
/// 0 and `program` before any.
fn workingstep_at(
    lo: Option<u32>,
    le: Option<u32>,
    a: &ProcessPlan,
    b: &ProcessPlan,
    spans_a: &[RangeInclusive<u32>],
    spans_b: &[RangeInclusive<u32>],
    pairs: &[(Option<usize>, Option<usize>)],
) -> (u32, String) {
    // Its own workingstep's lines, else the next one's setup, else the last one's end.
    let find = |ws: &[Workingstep], spans: &[RangeInclusive<u32>], l: u32| {
        ws.iter()
            .position(|w| (w.lines.0..=w.lines.1).contains(&l))
            .or_else(|| ws.iter().position(|w| w.lines.0 > l))
            .or_else(|| spans.iter().position(|s| s.contains(&l)))
    };
    if let Some(l) = lo
        && let Some(i) = find(&a.workingsteps, spans_a, l)
    {
        let w = &a.workingsteps[i];
        return (w.index, w.label());
    }
    if let Some(l) = le
        && let Some(j) = find(&b.workingsteps, spans_b, l)
    {
        let orig = pairs.iter().find(|p| p.1 == Some(j)).and_then(|p| p.0);
        return match orig {
            Some(i) => (a.workingsteps[i].index, a.workingsteps[i].label()),
            None => (b.workingsteps[j].index, b.workingsteps[j].label()),
        };
    }
    (0, "program".into())
}

fn blank(kind: ChangeKind, (workingstep, operation): (u32, String)) -> Change {
    Change {
        kind,
        workingstep,
        operation,
        field: String::new(),
        before: String::new(),
        after: String::new(),
        line: None,
        original_line: None,
        region: None,
        deviation: None,
        detail: crate::diff::Detail::default(),
    }
}

/// Kinds that tell a statement in program terms rather than by what it does.
fn untyped(kind: ChangeKind) -> bool {
    matches!(kind, ChangeKind::StatementChanged | ChangeKind::OutputChanged | ChangeKind::ReturnMoveChanged | ChangeKind::RotaryMoveChanged)
}

/// Typed statement changes alike in kind, field and values within one workingstep (`F500`
/// instead of `F800` on four lines) told once, at all their lines; a tool renamed together
/// with a length offset renamed the same way told as one sentence.
fn merge_typed(changes: &mut Vec<Change>) {
    let mut k = 0;
    while k < changes.len() {
        if untyped(changes[k].kind) {
            k += 1;
            continue;
        }
        let mut j = k + 1;
        while j < changes.len() {
            let (c, d) = (&changes[k], &changes[j]);
            if d.kind == c.kind && d.field == c.field && d.before == c.before && d.after == c.after && d.workingstep == c.workingstep {
                let d = changes.remove(j);
                let c = &mut changes[k];
                for a in d.detail.at {
                    if !c.detail.at.contains(&a) {
                        c.detail.at.push(a);
                    }
                }
                (c.detail.line_end, c.detail.original_line_end) = (None, None);
            } else {
                j += 1;
            }
        }
        k += 1;
    }
}

/// A tool renamed (`T1` → `T8`) and a length offset renamed with it (`H1` → `H8`, the offset
/// of the tool's own number): one change, "T1 renamed T8, with its length offset H8".
fn fold_length_offset(changes: &mut Vec<Change>) {
    let number = |s: &str| s.trim_start_matches(|c: char| c.is_ascii_alphabetic()).parse::<f64>().ok();
    let mut k = 0;
    while k < changes.len() {
        let c = &changes[k];
        let (tb, ta) = (number(&c.before), number(&c.after));
        let tool = c.kind == ChangeKind::ToolRenamed && tb.is_some() && ta.is_some() && tb != ta;
        let found = tool.then(|| {
            changes.iter().position(|d| {
                d.kind == ChangeKind::LengthOffsetChanged
                    && d.workingstep == c.workingstep
                    && d.before.split(' ').filter_map(number).any(|h| Some(h) == tb)
                    && d.after.split(' ').filter_map(number).any(|h| Some(h) == ta)
            })
        });
        if let Some(Some(j)) = found {
            let d = changes.remove(j);
            let k = if j < k { k - 1 } else { k };
            let c = &mut changes[k];
            let h = d.after.split(' ').find(|w| number(w) == ta).unwrap_or(&d.after).to_owned();
            c.after = format!("{}, with its length offset {h}", c.after);
            for a in d.detail.at {
                if !c.detail.at.contains(&a) {
                    c.detail.at.push(a);
                }
            }
        }
        k += 1;
    }
}

/// A call's argument as a change writes it: `empty` for an empty slot, `none` for none.
fn argument(v: Option<&String>) -> String {
    v.map_or_else(|| "none".to_owned(), |v| if v.is_empty() { "empty".into() } else { v.clone() })
}

/// The changes of a call's arguments: a named cycle's by the dictionary's names, as cycle
/// parameter changes; any other call's by position, an argument inserted or removed told as
/// such rather than as a shift of every later one.
fn call_changes(
    x: &Token,
    y: &Token,
    (kind, located): (ChangeKind, &[ChangeKind]),
    ws: &(u32, String),
    d: &Dialect,
    out: &mut Vec<Change>,
) {
    let (pa, pb) = (statement::arguments(&x.value), statement::arguments(&y.value));
    if let Some(args) = typed::cycle_args(&x.key, d) {
        for k in 0..pa.len().max(pb.len()) {
            let (va, vb) = (pa.get(k), pb.get(k));
            // An argument the plan's change located here already tells in the machine's terms.
            // (By the plan's kinds of the argument's role, or by the kind its own row would have.)
            let told = args.get(k).is_some_and(|a| {
                let own = Some(typed::arg_kind(a.role)).filter(|&kind| kind != ChangeKind::CycleParameterChanged);
                [argument_kind(a.role), own].into_iter().flatten().any(|kind| located.contains(&kind))
            });
            if va == vb || told {
                continue;
            }
            // A touch probe's measuring cycle (`CYCLE977(…)`): its arguments are the probing's.
            let probing = typed::probing(x, false, d);
            let kind = match args.get(k) {
                _ if probing => ChangeKind::ProbingChanged,
                Some(a) => typed::arg_kind(a.role),
                None => ChangeKind::CycleParameterChanged,
            };
            let mut c = blank(kind, ws.clone());
            c.field = match args.get(k) {
                Some(a) => format!("{} {}", x.key, typed::arg_name(a)),
                None => format!("{} argument {}", x.key, k + 1),
            };
            if probing {
                c.field = format!("probing {}", c.field);
            }
            (c.before, c.after) = (argument(va), argument(vb));
            out.push(c);
        }
        return;
    }
    for (i, j) in typed::align_args(&pa, &pb) {
        let (va, vb) = (i.and_then(|i| pa.get(i)), j.and_then(|j| pb.get(j)));
        if va == vb {
            continue;
        }
        let mut c = blank(kind, ws.clone());
        c.field = format!("call {} argument {}", x.key, j.or(i).unwrap_or(0) + 1);
        (c.before, c.after) = (argument(va), argument(vb));
        out.push(c);
    }
}

/// The statement changes of a control-flow statement told as what they change: its
/// condition, its jump's target, its repeat count, the call or loop added or removed; the
/// arguments a call passes and the variables it sets stay as they are.
///
/// A condition is shown with its word operators apart (`#156 LT 7`, not the statement's
/// `#156LT7`), as a planner reads it.
fn flow_changes(out: &mut [Change], it: &Item, flow: control::Flow, d: &Dialect) {
    let whole = it.original.is_none() || it.edited.is_none();
    let condition = it.diffs.iter().any(|(x, y)| {
        let t = y.as_ref().or(x.as_ref()).expect("a difference has a side");
        t.sort == Sort::Call && !matches!(flow, control::Flow::Call)
    });
    let repeat =
        flow == control::Flow::Call && it.diffs.iter().any(|(x, y)| y.as_ref().or(x.as_ref()).is_some_and(|t| control::repeat_word(t, d)));
    for c in out.iter_mut().filter(|c| c.kind == ChangeKind::StatementChanged) {
        let argument = c.field.starts_with("call ");
        if c.field.starts_with("variable ") || (argument && flow == control::Flow::Call) {
            continue;
        }
        let field = match flow {
            _ if whole => flow.field().to_owned(),
            // A call written into a statement that stays (`R910=25 … L100 P1`), or taken out of
            // one: the call added or removed, with the passes its repeat word gives.
            control::Flow::Call if it.calls.0 != it.calls.1 && (c.before.is_empty() || c.after.is_empty()) => {
                for side in [&mut c.before, &mut c.after] {
                    if side.is_empty() {
                        continue;
                    }
                    let repeat: Vec<&str> = side.split(' ').filter(|w| control::passes(w, d).is_some()).collect();
                    if let Some(n) = control::passes(&repeat.join(" "), d) {
                        *side = format!("{side} ({n} pass{})", if n == 1 { "" } else { "es" });
                    }
                }
                "call".to_owned()
            }
            control::Flow::Branch if argument || condition => "condition".to_owned(),
            // A count loop's count (LinuxCNC `o100 repeat [5]` → `[6]`): its passes, where
            // both are numbers.
            control::Flow::Loop if argument && count_loop(&c.field, d) && passes_of(&c.before).zip(passes_of(&c.after)).is_some() => {
                let (b, a) = (passes_of(&c.before).unwrap_or(0), passes_of(&c.after).unwrap_or(0));
                (c.before, c.after) = (b.to_string(), a.to_string());
                "loop passes".to_owned()
            }
            control::Flow::Loop if argument || condition => "loop condition".to_owned(),
            control::Flow::Call if repeat => match (control::passes(&c.before, d), control::passes(&c.after, d)) {
                // `L2` → `L3`: the call runs 2 → 3 times.
                (Some(b), Some(a)) if !(c.before.is_empty() && c.after.is_empty()) => {
                    (c.before, c.after) = (b.to_string(), a.to_string());
                    "passes".to_owned()
                }
                _ => "repeat count".to_owned(),
            },
            // A jump, conditional or not: its differing words after the jump keyword name the
            // target (`GOTOF MARKE1` → `MARKE2`), those before it the condition (Heidenhain
            // `FN 9: IF +Q1 EQU +0 GOTO LBL 5` → `EQU +1`, `IF R1<3 GOTOB` → `R1<4`).
            control::Flow::Branch | control::Flow::Jump if !it.jump_words.0.is_empty() => jump_field(it).to_owned(),
            control::Flow::Branch if c.after.contains("GOTO") || c.before.contains("GOTO") => {
                control::jump_part(&c.before, &c.after).to_owned()
            }
            control::Flow::Jump if !it.diffs.iter().any(|x| control::jump_target_word(x, d)) => "condition".to_owned(),
            control::Flow::Jump => "jump target".to_owned(),
            _ => flow.field().to_owned(),
        };
        if argument {
            // The bracketed condition whole: `[#1LT6]` for `O100WHILE` argument 1.
            (c.before, c.after) = (unbracketed(&c.before), unbracketed(&c.after));
        }
        if field.ends_with("condition") {
            (c.before, c.after) = (spaced(&c.before), spaced(&c.after));
        }
        // A conditional jump's condition changed (Heidenhain `FN 9: IF +Q3 EQU +0 GOTO LBL 1`,
        // `IF [#1 LT 6] GOTO 10`): the whole condition and its target on each side, left,
        // relation, right and label, not the one word that differs.
        if field.contains("condition") && !whole && !it.jump_words.0.is_empty() && !argument {
            let text = |t: &[Token]| spaced(&t.iter().map(|t| readable(&t.text, d)).collect::<Vec<_>>().join(" "));
            (c.before, c.after) = (text(&it.tokens.0), text(&it.tokens.1));
        }
        if !argument && whole && c.before.is_empty() && c.after.is_empty() {
            c.after = "statement".into();
        }
        c.kind = ChangeKind::FlowChanged;
        c.field = field;
    }
}

/// What a jump statement's differing words change (see [`Item::jump_words`]): its target where
/// every one names it, its condition where none does, else both.
fn jump_field(it: &Item) -> &'static str {
    let target = |t: &Option<Token>| t.as_ref().is_some_and(|t| it.jump_words.0.contains(&t.text) && !it.jump_words.1.contains(&t.text));
    let targets = it.diffs.iter().filter(|(x, y)| target(x) || target(y)).count();
    match targets {
        0 => "condition",
        n if n == it.diffs.len() => "jump target",
        _ => "condition and jump target",
    }
}

/// Whether a call-like statement's key (`call O100REPEAT argument 1`) is a loop that runs its
/// body the number its argument says: the dictionary's repeat statement after the O-word.
fn count_loop(field: &str, d: &Dialect) -> bool {
    field.strip_prefix("call ").and_then(|r| r.rsplit_once(" argument ")).is_some_and(|(k, _)| control::count_loop_key(k, d))
}

/// A count written as a whole number or a constant expression (`[5]`, `5`, `[2*3]`): the
/// passes it makes; none for a variable, which the statement change then tells as it is.
fn passes_of(v: &str) -> Option<u64> {
    let v = unbracketed(v);
    let x = v.trim().parse::<f64>().ok().or_else(|| statement::constant(&v))?;
    (x >= 0.0 && x.fract() == 0.0 && x < 1e9).then_some(x as u64)
}

/// A condition as a change writes it, without the brackets the statement reads it in.
fn unbracketed(s: &str) -> String {
    s.strip_prefix('[').and_then(|s| s.strip_suffix(']')).unwrap_or(s).to_owned()
}

/// A subroutine's end or return whose value alone differs (`O100ENDSUB` →
/// `O100ENDSUB[#<EDGE>]`): the value the caller reads afterwards (the dictionary's
/// return-value parameter, LinuxCNC `#<_value>`), told as that global's change.
fn return_change(it: &Item, ws: &(u32, String), d: &Dialect) -> Option<Change> {
    let mut var = None;
    let (mut before, mut after) = (String::new(), String::new());
    for (x, y) in &it.diffs {
        for (t, side) in [(x, &mut before), (y, &mut after)] {
            let Some(t) = t else { continue };
            let (v, value) = control::return_value(t, d)?;
            (var, *side) = (Some(v), value);
        }
    }
    let var = var?;
    if before == after || it.original.is_none() || it.edited.is_none() {
        return None;
    }
    let mut c = blank(ChangeKind::GlobalVariableChanged, ws.clone());
    (c.field, c.before, c.after) = (format!("return value {var}"), before, after);
    Some(c)
}

/// The statement changes of one item: those of its variables and calls always, the rest
/// where no plan change is located at it; words the dictionary gives a sense are told by
/// their kind ([`typed`]).
fn statement_changes(it: &Item, lo: Option<u32>, le: Option<u32>, ws: (u32, String), d: &Dialect) -> Vec<Change> {
    let kind = if it.class == Class::Output {
        ChangeKind::OutputChanged
    } else if it.moves & statement::RETURN_MOVE != 0 {
        ChangeKind::ReturnMoveChanged
    } else if it.moves & statement::ROTARY_MOVE != 0 {
        ChangeKind::RotaryMoveChanged
    } else {
        ChangeKind::StatementChanged
    };
    if kind == ChangeKind::StatementChanged
        && let Some(c) = return_change(it, &ws, d)
    {
        let mut c = c;
        (c.original_line, c.line) = (lo, le);
        c.detail.at = vec![(lo, le)];
        return vec![c];
    }
    let mut out = Vec::new();
    let (kinds, told) = if it.located || kind != ChangeKind::StatementChanged {
        (Vec::new(), vec![false; it.diffs.len()])
    } else if let Some(t) = typed::tool_column(&it.tokens.0, &it.tokens.1, it.ctx.function_keyword, d) {
        (vec![t], vec![true; it.diffs.len()])
    } else if let Some(t) = typed::table_write((&it.tokens.0, &it.tokens.1), (it.tables.0.as_deref(), it.tables.1.as_deref()), d) {
        (vec![t], vec![true; it.diffs.len()])
    } else {
        typed::typed(&it.diffs, it.ctx, d)
    };
    for t in kinds {
        let mut c = blank(t.kind, ws.clone());
        (c.field, c.before, c.after) = (t.field, t.before, t.after);
        out.push(c);
    }
    let mut words: (Vec<&str>, Vec<&str>) = (Vec::new(), Vec::new());
    let mut plain = false;
    for ((x, y), told) in it.diffs.iter().zip(told) {
        if told {
            continue;
        }
        let sort = y.as_ref().or(x.as_ref()).map_or(Sort::Other, |t| t.sort);
        match (sort, x, y) {
            // The spindle's limit (Siemens `LIMS=2500`) told by the plan where it is located.
            (Sort::Assign, _, _)
                if it.located && y.as_ref().or(x.as_ref()).is_some_and(|t| about(t, d) == About::Address(Role::SpindleLimit)) => {}
            (Sort::Assign, _, _) if y.as_ref().or(x.as_ref()).is_some_and(|t| typed::sets_variable(t, d)) => {
                let key = y.as_ref().or(x.as_ref()).map(|t| t.key.clone()).unwrap_or_default();
                let param = typed::cycle_param(&key, it.ctx.cycle, d);
                // A parameter of a touch probe's cycle (`TCH PROBE 430` … `Q262=+80`): the probing's.
                let probing = it.ctx.probe_cycle && kind == ChangeKind::StatementChanged;
                // A cutting edge's offset data (`$TC_DP4[t,d]=…`): the tool's length or radius.
                let data = typed::tool_data(&key, d).filter(|_| kind == ChangeKind::StatementChanged);
                let mut c = blank(
                    match param {
                        _ if probing => ChangeKind::ProbingChanged,
                        _ if data.is_some() => data.as_ref().expect("checked").0,
                        Some(a) if kind == ChangeKind::StatementChanged => typed::arg_kind(a.role),
                        _ => kind,
                    },
                    ws.clone(),
                );
                c.field = match param {
                    _ if probing => format!("probing parameter {key}"),
                    _ if data.is_some() => data.expect("checked").1,
                    Some(a) if c.kind == typed::arg_kind(a.role) => format!("cycle parameter {}", typed::arg_name(a)),
                    _ => format!("variable {key}"),
                };
                c.before = x.as_ref().map(|t| t.value.clone()).unwrap_or_default();
                c.after = y.as_ref().map(|t| t.value.clone()).unwrap_or_default();
                out.push(c);
            }
            (Sort::Call, _, _) if it.call_located => {}
            (Sort::Call, Some(x), Some(y)) if x.key == y.key => call_changes(x, y, (kind, &it.located_kinds), &ws, d, &mut out),
            // A control-flow statement is told even where a plan change is located at it: the
            // plan says what it did, the statement why.
            _ if it.located
                && it.ctx.flow.is_none()
                && y.as_ref().or(x.as_ref()).is_some_and(|t| t.is_address() || typed::axis_indexed_move(t, d)) => {}
            _ => {
                plain = true;
                if let Some(x) = x {
                    words.0.push(&x.text);
                }
                if let Some(y) = y {
                    words.1.push(&y.text);
                }
            }
        }
    }
    if plain {
        let mut c = blank(kind, ws.clone());
        c.field = "statement".into();
        c.before = words.0.join(" ");
        c.after = words.1.join(" ");
        out.push(c);
    }
    if out.is_empty() && !it.located {
        // Nothing to tell apart: the statement whole.
        let mut c = blank(kind, ws);
        c.field = "statement".into();
        out.push(c);
    }
    if kind == ChangeKind::StatementChanged
        && let Some(flow) = it.ctx.flow
    {
        flow_changes(&mut out, it, flow, d);
        // A condition told whole once, however many of its words differ.
        let mut seen: Vec<(String, String, String)> = Vec::new();
        out.retain(|c| {
            if c.kind != ChangeKind::FlowChanged {
                return true;
            }
            let key = (c.field.clone(), c.before.clone(), c.after.clone());
            let new = !seen.contains(&key);
            seen.push(key);
            new
        });
    }
    for c in &mut out {
        (c.original_line, c.line) = (lo, le);
        c.detail.at = vec![(lo, le)];
    }
    out
}

/// A word of a statement as a planner reads it: a parameter function's number apart from its
/// letters and keyword (`FN11:IF+Q11` → `FN 11: IF +Q11`), a statement keyword of the
/// dictionary apart from the operand written against it.
fn readable(t: &str, d: &Dialect) -> String {
    let mut out = String::new();
    let mut rest = t;
    let letters = t.bytes().take_while(u8::is_ascii_alphabetic).count();
    let digits = t[letters..].bytes().take_while(u8::is_ascii_digit).count();
    if letters > 0 && digits > 0 && t[letters + digits..].starts_with(':') {
        out.push_str(&format!("{} {}: ", &t[..letters], &t[letters..letters + digits]));
        rest = &t[letters + digits + 1..];
    }
    let keyword = d.macros.statements.iter().map(|(k, _)| k.as_str()).filter(|k| !k.contains(' ')).find(|k| {
        rest.len() > k.len()
            && rest.is_char_boundary(k.len())
            && rest[..k.len()].eq_ignore_ascii_case(k)
            && !rest[k.len()..].starts_with(|c: char| c.is_ascii_alphanumeric() || c == '_' || c == ' ')
    });
    if let Some(k) = keyword {
        out.push_str(&rest[..k.len()]);
        out.push(' ');
        rest = &rest[k.len()..];
    }
    // A word operator written against the number after it (`EQU0`, the statement's spelling
    // of `EQU +0`): the relation apart from its operand.
    let word = rest.bytes().take_while(u8::is_ascii_alphabetic).count();
    if word > 0
        && word < rest.len()
        && crate::syntax::BinOp::named(&rest[..word].to_ascii_uppercase()).is_some()
        && rest[word..].starts_with(|c: char| c.is_ascii_digit() || matches!(c, '.' | '+' | '-'))
    {
        out.push_str(&rest[..word]);
        out.push(' ');
        rest = &rest[word..];
    }
    out.push_str(rest);
    out
}

/// A condition with its word operators set apart by blanks (`#1LT3` → `#1 LT 3`,
/// `#<A>EQ#<B>` → `#<A> EQ #<B>`, `[#1GT0]AND[#2LT5]` → `[#1 GT 0] AND [#2 LT 5]`): an operator
/// only between an operand's end (a digit, `]`, `>`, `.`) and the next one's start (`#`, `[`,
/// a digit, a sign, `.`), never inside a `#<name>`.
fn spaced(s: &str) -> String {
    const OPS: [&str; 10] = ["AND", "XOR", "MOD", "OR", "EQ", "NE", "LT", "LE", "GT", "GE"];
    let b = s.as_bytes();
    let mut out = String::with_capacity(s.len() + 8);
    let (mut i, mut name) = (0, false);
    while i < b.len() {
        let c = b[i];
        if name {
            name = c != b'>';
        } else if c == b'<' && i > 0 && b[i - 1] == b'#' {
            name = true;
        } else if i > 0 && (b[i - 1].is_ascii_digit() || matches!(b[i - 1], b']' | b'>' | b'.')) {
            let op = OPS.iter().find(|op| {
                s[i..].starts_with(**op)
                    && b.get(i + op.len()).is_some_and(|n| n.is_ascii_digit() || matches!(n, b'#' | b'[' | b'-' | b'+' | b'.'))
            });
            if let Some(op) = op {
                out.push(' ');
                out.push_str(op);
                out.push(' ');
                i += op.len();
                continue;
            }
        }
        let ch = s[i..].chars().next().unwrap_or(' ');
        out.push(ch);
        i += ch.len_utf8();
    }
    out
}

#[cfg(test)]
mod tests {
    #[test]
    fn conditions_read_with_their_operators_apart() {
        use super::spaced;
        assert_eq!(spaced("#1LT3"), "#1 LT 3");
        assert_eq!(spaced("#<LOAD>EQ#<PROBE_NE>"), "#<LOAD> EQ #<PROBE_NE>");
        assert_eq!(spaced("[#1GT0]AND[#2LE-5]"), "[#1 GT 0] AND [#2 LE -5]");
        assert_eq!(spaced("R1<3"), "R1<3");
        assert_eq!(spaced("#1 LT 3"), "#1 LT 3");
        assert_eq!(spaced("Ø5GT2"), "Ø5 GT 2");
    }

    #[test]
    fn a_stop_counted_to_the_next_workingstep_where_it_stayed_is_no_change() {
        use super::{ChangeKind, blank, restopped};
        // r759: a `STOP` at original line 337 is edited line 358 (the statements around it
        // unchanged); removed from workingstep 16, added to workingstep 15: no change. A stop
        // added at another line stays.
        let stop = |kind, ws: u32, o: Option<u32>, e: Option<u32>| {
            let mut c = blank(kind, (ws, String::new()));
            (c.field, c.original_line, c.line) = ("stop".into(), o, e);
            if kind == ChangeKind::StopRemoved {
                c.before = "program stop (M00)".into()
            } else {
                c.after = "program stop (M00)".into()
            }
            c
        };
        let same = |o: u32| (o == 337).then_some(358);
        let mut changes = vec![stop(ChangeKind::StopAdded, 15, None, Some(358)), stop(ChangeKind::StopRemoved, 16, Some(337), None)];
        restopped(&mut changes, &same);
        assert!(changes.is_empty(), "{changes:#?}");
        let mut changes = vec![stop(ChangeKind::StopAdded, 15, None, Some(360)), stop(ChangeKind::StopRemoved, 16, Some(337), None)];
        restopped(&mut changes, &same);
        assert_eq!(changes.len(), 2, "{changes:#?}");
    }
}

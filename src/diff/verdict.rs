//! What an edit breaks or fixes: the errors a control stops at in one version and not in the
//! other (a malformed expression, a comment closed early by a nested parenthesis so that its
//! rest is read as words, an arc whose radii disagree, a jump to a label that is gone), those
//! of the analysis and those reading every block finds in blocks the analysis did not run.
//!
//! The errors of both versions are matched by their kind (the diagnostic's code): at the same
//! statement of both first (by the statements' alignment), then the same sentence, then in
//! order, so that an error that only moved with the lines around it is no change, and one an
//! edited line brings in is told at that line, not at an unchanged one further on. An error left over in the edited version is a [`ChangeKind::ProgramBroken`],
//! one left over in the original a [`ChangeKind::ProgramFixed`], one change per kind at all
//! its lines. They are listed first: a program the control stops in does not machine. An
//! original that cuts nothing with a feed and stops at an error the edit leaves is not broken
//! by another error: neither version machines anything.

use std::collections::BTreeMap;

use super::statement::{Fault, Hunk, Stmt};
use super::{Change, ChangeKind, Detail};
use crate::diag::Diagnostic;
use crate::text::LineIndex;

/// The errors among `findings` (an analysis of `text`), as faults at their lines, and the
/// words the analysis left out for a value the file never sets (`interp::unknown-value`: a
/// global another program sets, a caller's argument), which no size may be told from.
///
/// An error the run met only on the way values the file does not set sent it is no stop
/// whatever those values are: the program's own alarm (`#3000`, `SETAL`) reached after a
/// condition on such a value, a value left unknown or a call of a program not there (which
/// may end the run or jump away before it), and a missing `endif` (or loop end, or label)
/// found at a statement whose condition reads such a value (the control looks for the `endif`
/// only when it skips the body; LinuxCNC runs `o100 if` without one to the end when the
/// condition holds). A jump to a block number the program lacks is found by reading every
/// block ([`super::statement::read`]), taken or not.
pub fn faults(text: &str, findings: &[Diagnostic]) -> Vec<Fault> {
    use crate::diag::Code;
    let index = LineIndex::new(text);
    let line = |d: &Diagnostic| index.line_col(text, d.range.start).line;
    let guessed: std::collections::BTreeSet<u32> = findings.iter().filter(|d| d.code == Code::UnknownCondition).map(line).collect();
    let runtime = !guessed.is_empty() || findings.iter().any(|d| matches!(d.code, Code::UnknownValue | Code::MissingProgram));
    let on_values = |d: &Diagnostic| match d.code {
        Code::ProgramAlarm => runtime,
        Code::MissingLabel => guessed.contains(&line(d)),
        _ => false,
    };
    // A file that only defines subroutines (`flow::library`): nothing to stop at when a call
    // opens it, but run as a program by itself the control reads past the definitions to the
    // file's end without a program end ([`library_stops`] keeps it where the dictionary
    // requires one).
    let errors: Vec<&Diagnostic> = findings
        .iter()
        .filter(|d| (d.is_error() && !global_unset(d) && !on_values(d)) || matches!(d.code, Code::UnknownValue | Code::Library))
        .collect();
    if errors.is_empty() {
        return Vec::new();
    }
    errors.into_iter().map(|d| Fault { code: d.code, line: index.line_col(text, d.range.start).line, message: d.message.clone() }).collect()
}

/// The faults of a program read in `d`, a file that only defines subroutines (`flow::library`)
/// kept as the stop it is when the file is run as a program, where the dictionary requires a
/// program end: the control skips the definitions (RS274NGC: a `sub` is read, not run, until
/// a call) and meets the file's end with no M2, M30 or `%` (LinuxCNC: "File ended with no
/// percent sign or program end"). An edit that wraps a program into a definition, or takes the
/// wrapper away so that its blocks run, is then told as breaking or fixing the program run by
/// itself. Where the dictionary needs no program end, the library is no stop at all.
pub(super) fn library_stops(faults: &[Fault], d: &crate::dialect::Dialect) -> Vec<Fault> {
    faults
        .iter()
        .filter(|f| f.code != crate::diag::Code::Library || d.behaviour.end_required)
        .map(|f| {
            let mut f = f.clone();
            if f.code == crate::diag::Code::Library {
                f.message = "a file of subroutine definitions only, with no M2, M30 or `%` outside them: run as a program, the control skips the definitions and stops at the end of the file".into();
            }
            f
        })
        .collect()
}

/// Whether a finding is a global variable read before the file sets it (LinuxCNC `#<_td>`,
/// global by its leading `_` as the interpreter keeps it): another program on the machine may
/// have set it, the control keeps globals between programs, so it is no error the edit
/// brings in or takes away.
fn global_unset(d: &Diagnostic) -> bool {
    d.code == crate::diag::Code::UndefinedParameter && d.message.starts_with("parameter `#<_")
}

/// The errors of an analysis (`found`) and those reading every block finds (`read`): a read
/// error is added where the analysis has none of its kind on its line, for a block the
/// analysis did not run (a subprogram the file does not call, a branch it did not take) is
/// still a block the control stops at when it runs it.
pub(super) fn joined(found: &[Fault], read: Vec<Fault>) -> Vec<Fault> {
    let mut out = found.to_vec();
    out.extend(read.into_iter().filter(|r| !found.iter().any(|f| f.code == r.code && f.line == r.line)));
    out
}

/// The edited program's line of an original line where the statements around it are the same
/// in both (outside every hunk), by the statements' alignment; `None` where it differs.
pub(super) fn same_line(line: u32, (sa, sb): (&[Stmt], &[Stmt]), hunks: &[Hunk]) -> Option<u32> {
    // The statement at or before the line.
    let k = sa.partition_point(|s| s.line <= line).checked_sub(1)?;
    let mut shift: isize = 0;
    for h in hunks {
        if h.original.contains(&k) && h.original.len() == h.edited.len() && line <= sa[k].last {
            // A statement edited in place (as many on both sides): its counterpart.
            let (x, y) = (&sa[k], sb.get(h.edited.start + (k - h.original.start))?);
            return Some(y.line + (line - x.line).min(y.last - y.line));
        }
        if h.original.contains(&k) || (h.original.is_empty() && h.original.start == k + 1 && line > sa[k].last) {
            return None;
        }
        if h.original.start > k {
            break;
        }
        shift += h.edited.len() as isize - h.original.len() as isize;
    }
    let j = usize::try_from(k as isize + shift).ok()?;
    let (x, y) = (&sa[k], sb.get(j)?);
    Some(if line <= x.last { y.line + (line - x.line) } else { y.last + (line - x.last) })
}

/// The faults of `a` and `b` matched by kind: first those at the same statement of both
/// programs (`same`: the edited line of an original one), then those that say the same, then
/// in order; what is left over, per side.
fn unmatched<'f>(a: &'f [Fault], b: &'f [Fault], same: &dyn Fn(u32) -> Option<u32>) -> (Vec<&'f Fault>, Vec<&'f Fault>) {
    let mut by_code: BTreeMap<&str, (Vec<&Fault>, Vec<&Fault>)> = BTreeMap::new();
    for f in a {
        by_code.entry(f.code.as_str()).or_default().0.push(f);
    }
    for f in b {
        by_code.entry(f.code.as_str()).or_default().1.push(f);
    }
    let (mut left_a, mut left_b) = (Vec::new(), Vec::new());
    for (_, (mut xa, mut xb)) in by_code {
        // At the same statement first.
        xa.retain(|fa| match same(fa.line).and_then(|l| xb.iter().position(|fb| fb.line == l)) {
            Some(j) => {
                xb.remove(j);
                false
            }
            None => true,
        });
        // A jump never taken answers only its counterpart at the same statement.
        let live = |f: &&Fault| !f.message.starts_with(super::statement::NEVER_TAKEN);
        xa.retain(live);
        xb.retain(live);
        // Then the same sentence, then in order.
        xa.retain(|fa| match xb.iter().position(|fb| fb.message == fa.message) {
            Some(j) => {
                xb.remove(j);
                false
            }
            None => true,
        });
        let n = xa.len().min(xb.len());
        left_a.extend(xa.into_iter().skip(n));
        left_b.extend(xb.into_iter().skip(n));
    }
    (left_a, left_b)
}

/// The changes that say what the edit breaks and what it fixes. `cuts`: whether the original
/// cuts anything with a feed.
pub(super) fn verdicts(a: &[Fault], b: &[Fault], same: &dyn Fn(u32) -> Option<u32>, cuts: bool) -> Vec<Change> {
    // A value left unknown is no error the control stops at.
    let stops = |f: &[Fault]| f.iter().filter(|f| f.code != crate::diag::Code::UnknownValue).cloned().collect::<Vec<Fault>>();
    let (a, b) = (stops(a), stops(b));
    let (mut fixed, mut broken) = unmatched(&a, &b, same);
    // The control stops at the first error it meets. Where the original cuts nothing with a
    // feed (no feed is programmed: the control refuses its first cut; or it has no cut) and
    // the edit leaves the error it stops at, another error breaks nothing: neither version
    // machines.
    let live = |f: &&Fault| !f.message.starts_with(super::statement::NEVER_TAKEN);
    // A file of definitions only (`flow::library`) stops only run as a program: its
    // subroutines, called, still run into the errors the edit brings in.
    let idle = !cuts && a.iter().filter(live).any(|f| f.code != crate::diag::Code::Library && !fixed.iter().any(|g| std::ptr::eq(*g, f)));
    if idle {
        broken.clear();
    }
    // A statement the control stopped at in both versions (a comment nested in an empty
    // assignment's): another error on it neither breaks nor fixes the program.
    let stopped_a: std::collections::BTreeSet<u32> = a.iter().filter(live).filter_map(|g| same(g.line)).collect();
    let stopped_b: std::collections::BTreeSet<u32> = b.iter().filter(live).map(|f| f.line).collect();
    broken.retain(|f| !stopped_a.contains(&f.line));
    fixed.retain(|g| same(g.line).is_none_or(|l| !stopped_b.contains(&l)));
    let mut out = Vec::new();
    for (kind, list) in [(ChangeKind::ProgramBroken, broken), (ChangeKind::ProgramFixed, fixed)] {
        let mut by_code: BTreeMap<&str, Vec<&Fault>> = BTreeMap::new();
        for f in list {
            by_code.entry(f.code.as_str()).or_default().push(f);
        }
        for (code, fs) in by_code {
            let first = fs[0];
            let edited = kind == ChangeKind::ProgramBroken;
            let at: Vec<(Option<u32>, Option<u32>)> =
                fs.iter().map(|f| if edited { (None, Some(f.line)) } else { (Some(f.line), None) }).collect();
            let (before, after) = if edited { (String::new(), first.message.clone()) } else { (first.message.clone(), String::new()) };
            out.push(Change {
                kind,
                workingstep: 0,
                operation: "program".into(),
                field: code.into(),
                before,
                after,
                line: edited.then_some(first.line),
                original_line: (!edited).then_some(first.line),
                region: None,
                deviation: None,
                detail: Detail { at, ..Detail::default() },
            });
        }
    }
    out
}

//! The work plane a workingstep runs on, compared: a changed tilt is told as the machine's
//! rotation (`work plane tilted 30° → 25° about A`), with what it moves on the part (`3 holes
//! moved`), not as the words that state it (`SPA+25` for `SPA+30`). The toolpath stays in the
//! plane's coordinates, so an edit that only turns the plane changes nothing else.
//!
//! Door: [`compare`], called by `compare_workingsteps` after the other comparisons.

use super::{Change, ChangeKind, Detail, Fmt, TOLERANCE};
use crate::plan::{ProcessPlan, Setup, Workingstep};

/// The plane in words: `tilted 30° about A`, `untilted`.
fn tilt(s: Option<&Setup>) -> String {
    Setup::tilt_words(s)
}

/// The two tilts as one phrase: `tilted 30° → 25° about A` where one axis turns on both
/// sides, else `tilted A20° B0° C0° → untilted`.
pub(super) fn phrase(before: &str, after: &str) -> String {
    // What the report adds after the value (`(also in workingstep 2)`) stays at the end.
    let (after, note) = after.split_once(" (").map_or((after, String::new()), |(a, n)| (a, format!(" ({n}")));
    let about = |s: &str| s.strip_prefix("tilted ").and_then(|r| r.split_once(" about ")).map(|(a, k)| (a.to_owned(), k.to_owned()));
    match (about(before), about(after)) {
        (Some((x, k)), Some((y, l))) if k == l => format!("work plane tilted {x} → {y} about {k}{note}"),
        _ => format!("work plane {before} → {after}{note}"),
    }
}

fn same(a: Option<&Setup>, b: Option<&Setup>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(x), Some(y)) => {
            same_cylinder(x, y)
                && (0..3).all(|i| {
                    (x.origin[i] - y.origin[i]).abs() <= TOLERANCE
                        && (x.axis[i] - y.axis[i]).abs() <= 1e-9
                        && (x.ref_direction[i] - y.ref_direction[i]).abs() <= 1e-9
                })
        }
        _ => false,
    }
}

/// Whether two planes are the developed surfaces of the same cylinder, or both of none.
fn same_cylinder(x: &Setup, y: &Setup) -> bool {
    match (x.cylinder, y.cylinder) {
        (Some(a), Some(b)) => (a - b).abs() <= TOLERANCE,
        (a, b) => a.is_none() && b.is_none(),
    }
}

/// A cylinder's developed surface in words: `the developed surface of the Ø50 cylinder`.
fn cylinder(s: Option<&Setup>, u: Fmt) -> String {
    match s.and_then(|s| s.cylinder) {
        Some(d) => format!("the developed surface of the Ø{} cylinder", u.c(d)),
        None => "no cylinder's developed surface".to_owned(),
    }
}

/// Whether two toolpaths make the same moves in their planes' coordinates (their lines
/// apart).
fn same_moves(a: &Workingstep, b: &Workingstep) -> bool {
    a.toolpath.len() == b.toolpath.len()
        && a.toolpath.iter().zip(b.toolpath.iter()).all(|(x, y)| {
            x.kind == y.kind
                && x.arc == y.arc
                && (x.feed - y.feed).abs() <= TOLERANCE
                && (0..3).all(|i| (x.from[i] - y.from[i]).abs() <= TOLERANCE && (x.to[i] - y.to[i]).abs() <= TOLERANCE)
        })
}

/// The work plane change of two aligned workingsteps (pushed onto `out`, whose changes of
/// this pair begin at `first`), with what it moves on the part. Where the moves are the same
/// in the planes' coordinates, the plane's change is the whole change: what feature
/// recognition read differently from the stock on the other plane is no edit.
pub(super) fn compare(pa: &ProcessPlan, a: &Workingstep, b: &Workingstep, u: Fmt, first: usize, out: &mut Vec<Change>) {
    let (sa, sb) = (a.setup.as_ref(), b.setup.as_ref());
    if same(sa, sb) {
        return;
    }
    // The same moves wrapped round another cylinder cut another depth: what recognition reads
    // of the features there is the edit's.
    let rewrapped = match (sa.and_then(|s| s.cylinder), sb.and_then(|s| s.cylinder)) {
        (Some(x), Some(y)) => (x - y).abs() > TOLERANCE,
        (x, y) => x.is_some() != y.is_some(),
    };
    if same_moves(a, b) && !rewrapped {
        use ChangeKind as K;
        let mut k = 0;
        out.retain(|c| {
            k += 1;
            k <= first
                || !matches!(
                    c.kind,
                    K::FeatureChanged | K::AxialDepthChanged | K::StepoverChanged | K::AllowanceChanged | K::StrategyChanged
                )
        });
    }
    let (ta, tb) = (tilt(sa), tilt(sb));
    // Cylindrical interpolation on another diameter (`TRACYL(50)` → `TRACYL(60)`): the same
    // developed path wrapped round another cylinder, told as the cylinder's diameter.
    let (field, before, after) = if rewrapped {
        ("cylinder", cylinder(sa, u), cylinder(sb, u))
    } else if ta != tb {
        ("work_plane", ta, tb)
    } else {
        let origin = |s: Option<&Setup>| {
            let o = s.map_or([0.0; 3], |s| s.origin);
            format!("X{} Y{} Z{}", u.c(o[0]), u.c(o[1]), u.c(o[2]))
        };
        ("work_plane_origin", origin(sa), origin(sb))
    };
    let feature = a.feature.and_then(|f| pa.feature(f)).map_or("toolpath", |f| f.kind.label());
    let moved = if field == "cylinder" {
        format!("the {feature} wrapped round it")
    } else if a.holes.is_empty() {
        format!("the {feature} moved")
    } else {
        let n = a.holes.len();
        format!("{n} hole{} moved", if n == 1 { "" } else { "s" })
    };
    out.push(Change {
        kind: ChangeKind::WorkPlaneChanged,
        workingstep: a.index,
        operation: a.operation.label().into(),
        field: field.into(),
        before,
        after,
        line: Some(b.lines.0),
        original_line: Some(a.lines.0),
        region: None,
        deviation: None,
        detail: Detail { effect: Some(moved), ..Detail::default() },
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_axis_is_told_once() {
        assert_eq!(phrase("tilted 30° about A", "tilted 25° about A"), "work plane tilted 30° → 25° about A");
        assert_eq!(phrase("untilted", "tilted 25° about B"), "work plane untilted → tilted 25° about B");
        assert_eq!(
            phrase("tilted 90° about B", "tilted 85° about B (also in workingstep 2)"),
            "work plane tilted 90° → 85° about B (also in workingstep 2)"
        );
    }
}

//! A hole moved: a hole the original drills that the edited program drills elsewhere, with
//! the same cycle (bottom, feed-start level, peck, dwell, retract plane, block-delete switch),
//! in the same aligned workingstep (so by the same tool and operation), is told as that hole
//! moved (`hole at X0 Y20 moved to Y19.6962`), not as one removed and another added: a
//! live tool's face hole at C90 → C100, a pattern shifted by a coordinate edit.
//!
//! Pairing: where as many holes were removed as added, the i-th removed (in the original's
//! order) with the i-th added (in the edited program's order), each pair made alike; a pair
//! made otherwise (another depth, another peck), and every hole where the counts differ, stay
//! removed and added, since which one moved is then not the program's to say.
//!
//! A drilling workingstep's start point is its first hole: where that hole is told as moved,
//! the start point's move is the same change, not told again.
//!
//! Doors: [`tell`], called by `compare_holes` with the holes it found no counterpart for;
//! [`fold_start`], called by `compare_workingsteps` with the changes of one pair.

use super::{Change, ChangeKind, Fmt, Push, TOLERANCE};
use crate::plan::Hole;

/// Whether two holes are made by the same cycle: bottom (or the workingstep's depth change
/// from `depth.0` to `depth.1`, told on its own), feed-start level, peck, dwell, retract plane
/// and block-delete switch.
fn alike(h: &Hole, k: &Hole, depth: Option<(f64, f64)>) -> bool {
    let near = |x: f64, y: f64| (x - y).abs() <= TOLERANCE;
    let opt = |x: Option<f64>, y: Option<f64>| match (x, y) {
        (Some(x), Some(y)) => near(x, y),
        (None, None) => true,
        _ => false,
    };
    let bottom = match depth {
        Some((old, new)) if near(h.bottom, old) => near(new, k.bottom),
        _ => near(h.bottom, k.bottom),
    };
    bottom
        && near(h.r_plane, k.r_plane)
        && opt(h.peck, k.peck)
        && opt(h.dwell, k.dwell)
        && opt(h.retract, k.retract)
        && h.optional == k.optional
}

/// Tells the holes only one side drills: moved where paired (see the module), else removed
/// and added. Whether anything was told.
pub(super) fn tell(removed: &[&Hole], added: &[&Hole], depth: Option<(f64, f64)>, u: Fmt, push: &mut Push<'_>) -> bool {
    let paired: Vec<bool> = if removed.len() == added.len() {
        removed.iter().zip(added).map(|(h, k)| alike(h, k, depth)).collect()
    } else {
        vec![false; removed.len()]
    };
    for (i, h) in removed.iter().enumerate() {
        if paired[i] {
            let k = added[i];
            push(ChangeKind::HoleMoved, "hole", u.xy([h.x, h.y]), u.xy([k.x, k.y]), (None, None));
        }
    }
    for (i, h) in removed.iter().enumerate() {
        if !paired[i] {
            push(ChangeKind::HoleRemoved, "hole", u.xy([h.x, h.y]), String::new(), (None, None));
        }
    }
    for (i, k) in added.iter().enumerate() {
        if !paired.get(i).copied().unwrap_or(false) {
            push(ChangeKind::HoleAdded, "hole", String::new(), u.xy([k.x, k.y]), (None, None));
        }
    }
    !removed.is_empty() || !added.is_empty()
}

/// Drops the start point's move of the pair whose changes begin at `first` where a hole moved
/// from and to the same places: the first hole moved, told once.
pub(super) fn fold_start(first: usize, out: &mut Vec<Change>) {
    let told = |c: &Change| out[first..].iter().any(|h| h.kind == ChangeKind::HoleMoved && h.before == c.before && h.after == c.after);
    let drop: Vec<usize> = (first..out.len()).filter(|&k| out[k].kind == ChangeKind::StartPointMoved && told(&out[k])).collect();
    for k in drop.into_iter().rev() {
        out.remove(k);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn hole(x: f64, y: f64, bottom: f64) -> Hole {
        Hole { x, y, bottom, r_plane: 2.0, top: None, peck: None, dwell: None, retract: None, optional: false }
    }

    fn told(removed: &[Hole], added: &[Hole]) -> Vec<String> {
        let mut out = Vec::new();
        let mut push = |k: ChangeKind, _: &str, b: String, a: String, _: (Option<u32>, Option<u32>)| {
            out.push(format!("{} {b}|{a}", k.as_str()));
        };
        let (r, a): (Vec<&Hole>, Vec<&Hole>) = (removed.iter().collect(), added.iter().collect());
        tell(&r, &a, None, Fmt { inch: false }, &mut push);
        out
    }

    #[test]
    fn a_hole_made_alike_elsewhere_moved() {
        assert_eq!(told(&[hole(0.0, 20.0, -5.0)], &[hole(3.0, 20.0, -5.0)]), ["hole_moved X0 Y20|X3 Y20"]);
        // Another depth: another hole, not this one moved.
        assert_eq!(told(&[hole(0.0, 20.0, -5.0)], &[hole(3.0, 20.0, -8.0)]), ["hole_removed X0 Y20|", "hole_added |X3 Y20"]);
        // One removed, two added: which one moved is not the program's to say.
        assert_eq!(
            told(&[hole(0.0, 0.0, -5.0)], &[hole(1.0, 0.0, -5.0), hole(2.0, 0.0, -5.0)]),
            ["hole_removed X0 Y0|", "hole_added |X1 Y0", "hole_added |X2 Y0"]
        );
    }
}

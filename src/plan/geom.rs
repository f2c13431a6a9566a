//! Toolpath geometry: arc sweep, lengths, sampling and boxes (nalgebra).

use nalgebra::{Point3, Rotation3, Unit, Vector3};

use super::model::{BBox, Move, MoveKind, P3};

fn p(a: P3) -> Point3<f64> {
    Point3::new(a[0], a[1], a[2])
}

/// Signed sweep angle of an arc move about its axis, radians (positive counter-clockwise).
pub fn sweep(m: &Move) -> f64 {
    let (Some(c), Some(axis), Some(turns)) = (m.center(), m.axis(), m.turns()) else { return 0.0 };
    let axis = Vector3::from(axis);
    let c = p(c);
    let u = p(m.from) - c;
    let mut v = p(m.to) - c;
    // Project the end onto the arc plane (helical arcs rise along the axis).
    v -= axis * v.dot(&axis);
    let theta = u.cross(&v).dot(&axis).atan2(u.dot(&v));
    let tau = std::f64::consts::TAU;
    let extra = tau * f64::from(turns.unsigned_abs().saturating_sub(1));
    if turns > 0 {
        let t = if theta <= 1e-12 { theta + tau } else { theta };
        t + extra
    } else {
        let t = if theta >= -1e-12 { theta - tau } else { theta };
        t - extra
    }
}

/// Length of a move, mm.
pub fn length(m: &Move) -> f64 {
    match m.kind {
        MoveKind::Rapid | MoveKind::Line => (p(m.to) - p(m.from)).norm(),
        MoveKind::Arc => {
            let (Some(c), Some(axis)) = (m.center(), m.axis()) else { return 0.0 };
            let axis = Vector3::from(axis);
            let r = (p(m.from) - p(c)).norm();
            let rise = (p(m.to) - p(m.from)).dot(&axis);
            (r * sweep(m)).hypot(rise)
        }
    }
}

/// Points along a move, excluding its start; arcs are sampled every 10° at most.
pub fn sample(m: &Move, out: &mut Vec<P3>) {
    if m.kind != MoveKind::Arc {
        out.push(m.to);
        return;
    }
    let (Some(c), Some(axis)) = (m.center(), m.axis()) else {
        out.push(m.to);
        return;
    };
    let total = sweep(m);
    let n = ((total.abs() / 10f64.to_radians()).ceil() as usize).clamp(1, 3600);
    let axis_v = Vector3::from(axis);
    let rise = (p(m.to) - p(m.from)).dot(&axis_v);
    let unit = Unit::new_normalize(axis_v);
    let r0 = p(m.from) - p(c);
    for i in 1..=n {
        let t = i as f64 / n as f64;
        let q = p(c) + Rotation3::from_axis_angle(&unit, total * t) * r0 + axis_v * (rise * t);
        out.push([q.x, q.y, q.z]);
    }
    if let Some(last) = out.last_mut() {
        *last = m.to;
    }
}

/// The point at fraction `f` (0 to 1) of a move's way: along a line, or by angle (and rise)
/// along an arc.
pub fn point_at(m: &Move, f: f64) -> P3 {
    let lerp = |a: P3, b: P3| -> P3 { std::array::from_fn(|i| a[i] + (b[i] - a[i]) * f) };
    let (Some(c), Some(axis), MoveKind::Arc) = (m.center(), m.axis(), m.kind) else { return lerp(m.from, m.to) };
    if f >= 1.0 {
        return m.to;
    }
    let axis_v = Vector3::from(axis);
    let rise = (p(m.to) - p(m.from)).dot(&axis_v);
    let q = p(c) + Rotation3::from_axis_angle(&Unit::new_normalize(axis_v), sweep(m) * f) * (p(m.from) - p(c)) + axis_v * (rise * f);
    [q.x, q.y, q.z]
}

/// A move's end and, for an arc, the points where it is furthest along each axis within its
/// sweep: with its start, the exact box of the move (samples would miss the extremes by
/// their spacing, and by different amounts however the arc is cut into pieces).
pub fn extremes(m: &Move, out: &mut Vec<P3>) {
    out.push(m.to);
    let (Some(c), Some(axis), MoveKind::Arc) = (m.center(), m.axis(), m.kind) else { return };
    let total = sweep(m);
    let a = Vector3::from(axis);
    let mut u = p(m.from) - p(c);
    u -= a * u.dot(&a);
    let r = u.norm();
    if r < 1e-12 || total == 0.0 {
        return;
    }
    u /= r;
    let v = a.cross(&u);
    let pi = std::f64::consts::PI;
    // After a whole turn the values across the axis repeat (the rise is along the axis).
    let (lo, hi) = if total > 0.0 { (0.0, total) } else { (total, 0.0) };
    let hi = hi.min(lo + std::f64::consts::TAU);
    for k in 0..3 {
        if u[k].abs() + v[k].abs() < 1e-12 {
            continue;
        }
        // Along axis k the arc goes as cos(θ − t0): furthest at t0 and t0 + π.
        let t0 = v[k].atan2(u[k]);
        let mut j = ((lo - t0) / pi).ceil();
        while t0 + j * pi <= hi {
            out.push(point_at(m, (t0 + j * pi) / total));
            j += 1.0;
        }
    }
}

/// Grows `bbox` to hold `pt`.
pub fn extend(bbox: &mut Option<BBox>, pt: P3) {
    match bbox {
        None => *bbox = Some(BBox { min: pt, max: pt }),
        Some(b) => {
            for (i, v) in pt.into_iter().enumerate() {
                b.min[i] = b.min[i].min(v);
                b.max[i] = b.max[i].max(v);
            }
        }
    }
}

/// Distance between two points.
pub fn dist(a: P3, b: P3) -> f64 {
    (p(a) - p(b)).norm()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::model::Phase;

    fn arc(from: P3, to: P3, center: P3, turns: i32) -> Move {
        Move {
            kind: MoveKind::Arc,
            phase: Phase::Cut,
            from,
            to,
            arc: Some(crate::plan::ArcGeometry { center, axis: [0.0, 0.0, 1.0], turns }),
            feed: 100.0,
            line: 1,
        }
    }

    #[test]
    fn arc_sweep_and_length() {
        let half_cw = arc([0.0, 0.0, 0.0], [10.0, 0.0, 0.0], [5.0, 0.0, 0.0], -1);
        assert!((sweep(&half_cw) + std::f64::consts::PI).abs() < 1e-12);
        assert!((length(&half_cw) - 5.0 * std::f64::consts::PI).abs() < 1e-9);
        let full = arc([10.0, 0.0, 0.0], [10.0, 0.0, -2.0], [0.0, 0.0, 0.0], 2);
        assert!((sweep(&full) - 2.0 * std::f64::consts::TAU).abs() < 1e-9);
        let mut pts = Vec::new();
        sample(&half_cw, &mut pts);
        assert_eq!(pts.len(), 18);
        // A clockwise half circle from (0,0) to (10,0) about (5,0) passes through (5, 5).
        assert!(pts.iter().any(|q| (q[0] - 5.0).abs() < 1e-9 && (q[1] - 5.0).abs() < 1e-9));
    }

    #[test]
    fn arc_extremes_are_exact_whatever_the_pieces() {
        // A counter-clockwise arc about Z from 30° to 300° (radius 10): furthest at 90°
        // (Y+10), 180° (X−10) and 270° (Y−10), not at 0° (outside the sweep).
        let at = |deg: f64| [10.0 * deg.to_radians().cos(), 10.0 * deg.to_radians().sin(), 0.0];
        let m = arc(at(30.0), at(300.0), [0.0, 0.0, 0.0], 1);
        let mut pts = Vec::new();
        extremes(&m, &mut pts);
        let near = |p: P3, q: P3| (0..3).all(|i| (p[i] - q[i]).abs() < 1e-9);
        for q in [at(90.0), at(180.0), at(270.0), at(300.0)] {
            assert!(pts.iter().any(|p| near(*p, q)), "{q:?} in {pts:?}");
        }
        assert!(!pts.iter().any(|p| near(*p, at(0.0))), "{pts:?}");
        // Two helical turns in the YZ plane (axis X) reach Z−r exactly, as one turn does.
        let mut helix = arc([0.0, 0.0, 0.0], [5.0, 0.0, 0.0], [0.0, 0.0, -10.0], 2);
        helix.arc = Some(crate::plan::ArcGeometry { center: [0.0, 0.0, -10.0], axis: [1.0, 0.0, 0.0], turns: 2 });
        pts.clear();
        extremes(&helix, &mut pts);
        let low = pts.iter().map(|p| p[2]).fold(f64::INFINITY, f64::min);
        assert!((low + 20.0).abs() < 1e-9, "{low}");
    }
}

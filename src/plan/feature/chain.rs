//! Plane geometry of the horizontal cuts at a workingstep's bottom: pieces (lines and
//! arcs in XY), chains of them, their loops, areas, bounds and offsets.

use std::collections::BTreeMap;

use super::*;

/// A horizontal cutting move, projected to XY.
#[derive(Clone, Copy, Debug)]
pub(super) struct Piece {
    pub(super) from: P2,
    pub(super) to: P2,
    pub(super) arc: Option<(P2, bool)>,
}

impl Piece {
    pub(super) fn len(&self) -> f64 {
        match self.arc {
            None => dist(self.from, self.to),
            Some((c, ccw)) => dist(self.from, c) * sweep(self.from, self.to, c, ccw).abs(),
        }
    }
    pub(super) fn dir(&self) -> P2 {
        let d = [self.to[0] - self.from[0], self.to[1] - self.from[1]];
        let n = d[0].hypot(d[1]).max(EPS);
        [d[0] / n, d[1] / n]
    }
    /// Unit tangent at the start and at the end.
    pub(super) fn tangents(&self) -> (P2, P2) {
        match self.arc {
            None => (self.dir(), self.dir()),
            Some((c, ccw)) => {
                let t = |p: P2| {
                    let r = [p[0] - c[0], p[1] - c[1]];
                    let n = r[0].hypot(r[1]).max(EPS);
                    if ccw { [-r[1] / n, r[0] / n] } else { [r[1] / n, -r[0] / n] }
                };
                (t(self.from), t(self.to))
            }
        }
    }
}

pub(super) fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

pub(super) fn cross(a: P2, b: P2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Signed sweep of an arc in XY from `a` to `b` about `c`, radians; a closed arc is a full turn.
pub(super) fn sweep(a: P2, b: P2, c: P2, ccw: bool) -> f64 {
    let u = [a[0] - c[0], a[1] - c[1]];
    let v = [b[0] - c[0], b[1] - c[1]];
    let mut t = cross(u, v).atan2(u[0] * v[0] + u[1] * v[1]);
    if ccw && t <= 1e-12 {
        t += std::f64::consts::TAU;
    }
    if !ccw && t >= -1e-12 {
        t -= std::f64::consts::TAU;
    }
    t
}

/// Signed area of a closed chain (positive counter-clockwise), arcs included.
pub(super) fn signed_area(chain: &[Piece]) -> f64 {
    let mut a = 0.0;
    for p in chain {
        a += cross(p.from, p.to) / 2.0;
        if let Some((c, ccw)) = p.arc {
            // The circular segment between the chord and the arc.
            let r = dist(p.from, c);
            let t = sweep(p.from, p.to, c, ccw);
            a += r * r * (t - t.sin()) / 2.0;
        }
    }
    a
}

pub(super) fn total_turning(chain: &[Piece]) -> f64 {
    let mut total = 0.0;
    for (i, p) in chain.iter().enumerate() {
        if let Some((c, ccw)) = p.arc {
            total += sweep(p.from, p.to, c, ccw);
        }
        if let Some(q) = chain.get(i + 1) {
            let (_, t0) = p.tangents();
            let (t1, _) = q.tangents();
            total += cross(t0, t1).atan2(t0[0] * t1[0] + t0[1] * t1[1]);
        }
    }
    total
}

pub(super) fn bounds(chain: &[Piece]) -> (P2, P2) {
    let mut min = [f64::INFINITY; 2];
    let mut max = [f64::NEG_INFINITY; 2];
    let mut add = |p: P2| {
        for k in 0..2 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    };
    for p in chain {
        add(p.from);
        add(p.to);
        if let Some((c, ccw)) = p.arc {
            let r = dist(p.from, c);
            let a0 = (p.from[1] - c[1]).atan2(p.from[0] - c[0]);
            let t = sweep(p.from, p.to, c, ccw);
            for k in 1..=36 {
                let a = a0 + t * f64::from(k) / 36.0;
                add([c[0] + r * a.cos(), c[1] + r * a.sin()]);
            }
        }
    }
    (min, max)
}

/// Whether `p` lies inside the closed chain (by its vertices and arc midpoints); `None` on it.
pub(super) fn inside(chain: &[Piece], p: P2) -> Option<bool> {
    let mut poly: Vec<P2> = Vec::new();
    for q in chain {
        poly.push(q.from);
        if let Some((c, ccw)) = q.arc {
            let r = dist(q.from, c);
            let a0 = (q.from[1] - c[1]).atan2(q.from[0] - c[0]);
            let t = sweep(q.from, q.to, c, ccw);
            for k in 1..8 {
                let a = a0 + t * f64::from(k) / 8.0;
                poly.push([c[0] + r * a.cos(), c[1] + r * a.sin()]);
            }
        }
    }
    let n = poly.len();
    let mut odd = false;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        // On the boundary: no evidence.
        let ab = [b[0] - a[0], b[1] - a[1]];
        let l2 = ab[0] * ab[0] + ab[1] * ab[1];
        let t = if l2 > 0.0 { (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / l2).clamp(0.0, 1.0) } else { 0.0 };
        if dist(p, [a[0] + t * ab[0], a[1] + t * ab[1]]) < 1e-3 {
            return None;
        }
        if (a[1] > p[1]) != (b[1] > p[1]) && p[0] < a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) {
            odd = !odd;
        }
    }
    Some(odd)
}

/// Joins straight pieces that continue one another, also across the loop's start.
pub(super) fn join_collinear(chain: &[Piece]) -> Vec<Piece> {
    let along = |q: &Piece, p: &Piece| {
        q.arc.is_none()
            && p.arc.is_none()
            && cross(q.dir(), p.dir()).abs() < 1e-6
            && q.dir()[0] * p.dir()[0] + q.dir()[1] * p.dir()[1] > 0.0
    };
    let mut out: Vec<Piece> = Vec::new();
    for p in chain {
        match out.last_mut() {
            Some(q) if along(q, p) => q.to = p.to,
            _ => out.push(*p),
        }
    }
    if out.len() > 2 && along(&out[out.len() - 1], &out[0]) {
        let last = out.pop().expect("more than two pieces");
        out[0].from = last.from;
    }
    out
}

/// A chain that comes back onto the line it left, short of its first point on that line or
/// past it by at most `gap`, closed there: the loop ends where it began. Chains that close
/// exactly, or that do not come back, are as they were.
pub(super) fn close_gap(chain: &[Piece], gap: f64) -> Vec<Piece> {
    if chain.len() < 4 {
        return chain.to_vec();
    }
    let on_line = |a: &Piece, b: &Piece| {
        a.arc.is_none()
            && b.arc.is_none()
            && cross(a.dir(), b.dir()).abs() < 1e-6
            && a.dir()[0] * b.dir()[0] + a.dir()[1] * b.dir()[1] > 0.0
            && cross(a.dir(), [b.from[0] - a.from[0], b.from[1] - a.from[1]]).abs() < 1e-4
    };
    // The longest loop first: the last piece coming back onto the line of the earliest one.
    // Lead-ins and lead-outs lie near the chain's ends: the search stays there, bounded.
    const NEAR_END: usize = 64;
    for i in 0..chain.len().min(NEAR_END) {
        for j in (chain.len().saturating_sub(NEAR_END).max(i + 3)..chain.len()).rev() {
            let (a, b) = (chain[i], chain[j]);
            if !on_line(&a, &b) {
                continue;
            }
            let u = a.dir();
            let along = |p: P2| (p[0] - a.from[0]) * u[0] + (p[1] - a.from[1]) * u[1];
            let (end, b_start) = (along(b.to), along(b.from));
            // Short of the start (a gap before it) or past it (an overlap), within `gap`.
            if end < 0.0 && -end <= gap || end >= 0.0 && b_start <= 0.0 && end <= gap.max(a.len()) {
                let mut out = chain.to_vec();
                out[j].to = a.from;
                // A loop encloses something: passes to and fro along one line do not.
                if signed_area(&out[i..=j]).abs() > 1e-3 {
                    return out;
                }
            }
        }
    }
    chain.to_vec()
}

/// Splits a chain into the closed loops it traces (a point met again closes a loop) and the
/// pieces between them.
pub(super) fn split_loops(chain: &[Piece]) -> (Vec<Vec<Piece>>, Vec<Piece>) {
    // Start points of the open pieces, quantised to 1e-4 mm, for a lookup in log time.
    let key = |p: P2| ((p[0] * 1e4).round() as i64, (p[1] * 1e4).round() as i64);
    let mut loops = Vec::new();
    let mut rest = Vec::new();
    let mut open: Vec<Piece> = Vec::new();
    let mut starts: BTreeMap<(i64, i64), usize> = BTreeMap::new();
    for p in chain {
        starts.entry(key(p.from)).or_insert(open.len());
        open.push(*p);
        if let Some(&k) = starts.get(&key(p.to)) {
            let lp: Vec<Piece> = open.drain(k..).collect();
            // A loop encloses something: a pass out and back along one line does not.
            if lp.iter().any(|p| p.arc.is_some()) || lp.len() >= 2 && signed_area(&lp).abs() > 1e-6 {
                loops.push(lp);
            } else {
                rest.extend(lp);
            }
            rest.append(&mut open);
            starts.clear();
        }
    }
    rest.extend(open);
    (loops, rest)
}

/// Two parallel straight sides joined by two half circles of one radius: the circles'
/// centres and the radius.
pub(super) fn stadium(chain: &[Piece]) -> Option<(P2, P2, f64)> {
    let joined = join_collinear(chain);
    if joined.len() != 4 {
        return None;
    }
    let first = joined.iter().position(|p| p.arc.is_some())?;
    let at = |k: usize| joined[(first + k) % 4];
    let (a0, l0, a1, l1) = (at(0), at(1), at(2), at(3));
    let ((c0, ccw0), (c1, ccw1)) = (a0.arc?, a1.arc?);
    let half = |p: &Piece, c: P2, ccw: bool| (sweep(p.from, p.to, c, ccw).abs() - std::f64::consts::PI).abs() < 1e-4;
    let r = dist(a0.from, c0);
    let lines = l0.arc.is_none() && l1.arc.is_none() && cross(l0.dir(), l1.dir()).abs() < 1e-6;
    (lines && half(&a0, c0, ccw0) && half(&a1, c1, ccw1) && (dist(a1.from, c1) - r).abs() < 1e-4 && dist(c0, c1) > 1e-4)
        .then(|| if c0[0] < c1[0] || c0[0] == c1[0] && c0[1] <= c1[1] { (c0, c1, r) } else { (c1, c0, r) })
}

/// An axis-aligned rectangle, with sharp corners or four quarter arcs of one radius: its
/// extent of straight edges (corner arcs included) and the corner radius (0 when sharp).
pub(super) fn rect_shape(chain: &[Piece]) -> Option<(P2, P2, f64)> {
    let joined = join_collinear(chain);
    let axis_line = |p: &Piece| p.arc.is_none() && (p.dir()[0].abs() < 1e-9 || p.dir()[1].abs() < 1e-9);
    let sharp = joined.len() == 4 && joined.iter().all(axis_line);
    // Four axis-aligned edges joined by four quarter arcs of one radius.
    let arc_radius = |p: &Piece| p.arc.map(|(c, ccw)| (dist(p.from, c), sweep(p.from, p.to, c, ccw).abs()));
    let rounded = (joined.len() == 8)
        .then(|| {
            let first = joined.iter().position(|p| p.arc.is_some())?;
            let arcs: Vec<(f64, f64)> = joined.iter().filter_map(arc_radius).collect();
            let alternate = (0..8).all(|k| joined[(first + k) % 8].arc.is_some() == (k % 2 == 0));
            let same = arcs.len() == 4
                && arcs.iter().all(|(ra, t)| (ra - arcs[0].0).abs() < 1e-4 && (t - std::f64::consts::FRAC_PI_2).abs() < 1e-4);
            (alternate && same && joined.iter().filter(|p| p.arc.is_none()).all(axis_line)).then_some(arcs[0].0)
        })
        .flatten();
    if !sharp && rounded.is_none() {
        return None;
    }
    let (min, max) = bounds(&joined);
    Some((min, max, rounded.unwrap_or(0.0)))
}

pub(super) fn rectangle(min: P2, max: P2) -> Vec<Piece> {
    let c = [min, [max[0], min[1]], max, [min[0], max[1]]];
    (0..4).map(|i| Piece { from: c[i], to: c[(i + 1) % 4], arc: None }).collect()
}

pub(super) fn to_contour(chain: &[Piece]) -> Contour {
    Contour {
        start: chain.first().map_or([0.0; 2], |p| p.from),
        segments: chain.iter().map(|p| Segment { to: p.to, arc: p.arc }).collect(),
    }
}

/// The contour moved so that `placement` is its origin, rounded to 1e-6 mm.
pub(super) fn relative(c: &Contour, placement: P3) -> Contour {
    let rel = |p: P2| [round6(p[0] - placement[0]), round6(p[1] - placement[1])];
    Contour {
        start: rel(c.start),
        segments: c.segments.iter().map(|s| Segment { to: rel(s.to), arc: s.arc.map(|(c, ccw)| (rel(c), ccw)) }).collect(),
    }
}

/// Offsets a chain by `d` to the left of travel (negative: to the right). Outside corners
/// get an arc about the corner; inside corners between lines are trimmed to their
/// intersection, other inside corners are joined by a line.
pub(super) fn offset(chain: &[Piece], d: f64) -> Vec<Piece> {
    if d.abs() < EPS {
        return chain.to_vec();
    }
    let shifted: Vec<Piece> = chain
        .iter()
        .filter_map(|p| match p.arc {
            None => {
                let u = p.dir();
                let n = [-u[1] * d, u[0] * d];
                Some(Piece { from: [p.from[0] + n[0], p.from[1] + n[1]], to: [p.to[0] + n[0], p.to[1] + n[1]], arc: None })
            }
            Some((c, ccw)) => {
                let r0 = dist(p.from, c);
                let r1 = if ccw { r0 - d } else { r0 + d };
                if r1 <= EPS {
                    return None;
                }
                let k = r1 / r0;
                let at = |q: P2| [c[0] + (q[0] - c[0]) * k, c[1] + (q[1] - c[1]) * k];
                Some(Piece { from: at(p.from), to: at(p.to), arc: Some((c, ccw)) })
            }
        })
        .collect();
    let closed = chain.len() > 1 && dist(chain[0].from, chain[chain.len() - 1].to) < 1e-4;
    let n = shifted.len();
    let mut out: Vec<Piece> = Vec::new();
    let mut pieces = shifted.clone();
    let joints = if closed { n } else { n.saturating_sub(1) };
    let mut joins: Vec<Option<Piece>> = vec![None; n];
    for i in 0..joints {
        let j = (i + 1) % n;
        let (a, b) = (pieces[i], pieces[j]);
        if dist(a.to, b.from) < 1e-6 {
            continue;
        }
        let (_, ta) = a.tangents();
        let (tb, _) = b.tangents();
        let turn = cross(ta, tb);
        if turn * d < 0.0 {
            let corner = chain.get(i).map_or(a.to, |p| p.to);
            joins[i] = Some(Piece { from: a.to, to: b.from, arc: Some((corner, turn > 0.0)) });
        } else if a.arc.is_none() && b.arc.is_none() {
            let denom = cross(a.dir(), b.dir());
            if denom.abs() > 1e-12 {
                let w = [b.from[0] - a.from[0], b.from[1] - a.from[1]];
                let t = cross(w, b.dir()) / denom;
                let x = [a.from[0] + a.dir()[0] * t, a.from[1] + a.dir()[1] * t];
                pieces[i].to = x;
                pieces[j].from = x;
            }
        } else {
            joins[i] = Some(Piece { from: a.to, to: b.from, arc: None });
        }
    }
    for (p, j) in pieces.into_iter().zip(joins) {
        out.push(p);
        if let Some(j) = j {
            out.push(j);
        }
    }
    // A closed chain starts where its first piece starts after trimming.
    if closed && let (Some(first), Some(last)) = (out.first().map(|p| p.from), out.last_mut()) {
        last.to = first;
    }
    out
}

/// The width and length of a contour that is an axis-aligned rectangle (see
/// [`rect_contour`]), and its corner radius when it has one.
pub fn rectangle_of(c: &Contour) -> Option<((f64, f64), Option<f64>)> {
    let mut from = c.start;
    let pieces: Vec<Piece> = c
        .segments
        .iter()
        .map(|s| {
            let p = Piece { from, to: s.to, arc: s.arc };
            from = s.to;
            p
        })
        .collect();
    let (min, max, corner) = rect_shape(&pieces)?;
    Some(((round6(max[0] - min[0]), round6(max[1] - min[1])), (corner > 0.0).then_some(round6(corner))))
}

/// The wall of a rectangular pocket `w` × `l` centred on its placement, with vertical corner
/// radius `r`: counter-clockwise from the middle of the bottom edge.
pub fn rect_contour(w: f64, l: f64, r: Option<f64>) -> Contour {
    let (hw, hl) = (w / 2.0, l / 2.0);
    let r = r.unwrap_or(0.0).clamp(0.0, hw.min(hl));
    let mut segments = Vec::new();
    let corners = [([hw, -hl], [-1.0, 1.0]), ([hw, hl], [-1.0, -1.0]), ([-hw, hl], [1.0, -1.0]), ([-hw, -hl], [1.0, 1.0])];
    for (k, (c, inward)) in corners.iter().enumerate() {
        // Along the edge towards corner k, then around it.
        let along: P2 = match k {
            0 => [c[0] - r, c[1]],
            1 => [c[0], c[1] - r],
            2 => [c[0] + r, c[1]],
            _ => [c[0], c[1] + r],
        };
        segments.push(Segment { to: along, arc: None });
        if r > 0.0 {
            let centre = [c[0] + inward[0] * r, c[1] + inward[1] * r];
            let out: P2 = match k {
                0 => [c[0], c[1] + r],
                1 => [c[0] - r, c[1]],
                2 => [c[0], c[1] - r],
                _ => [c[0] + r, c[1]],
            };
            segments.push(Segment { to: out, arc: Some((centre, true)) });
        }
    }
    segments.push(Segment { to: [0.0, -hl], arc: None });
    Contour { start: [0.0, -hl], segments }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_square_outward_gets_corner_arcs() {
        let sq = rectangle([0.0, 0.0], [10.0, 10.0]);
        assert!(signed_area(&sq) > 0.0);
        let out = offset(&sq, -2.0);
        assert_eq!(out.len(), 8);
        let (min, max) = bounds(&out);
        assert!((min[0] + 2.0).abs() < 1e-9 && (max[1] - 12.0).abs() < 1e-9, "{min:?} {max:?}");
        let inner = offset(&sq, 2.0);
        assert_eq!(inner.len(), 4);
        let (min, max) = bounds(&inner);
        assert!((min[0] - 2.0).abs() < 1e-9 && (max[0] - 8.0).abs() < 1e-9);
    }
}

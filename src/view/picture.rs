//! Toolpath pictures: the original's and the edited program's toolpaths overlaid, as SVG, in a
//! top view and two side views.
//!
//! Each view projects the moves to pixels and simplifies every run of moves with
//! Douglas–Peucker at half a pixel, so that a picture's size follows the screen, not the
//! program. Moves inside a changed region are never simplified: what changed is drawn exactly.
//! Rapids, feeds and changed segments have their own classes; start points are marked; each
//! changed region is a box with an id (`region-N`) that its sentence links to.

use std::fmt::Write as _;

use crate::plan::{BBox, MoveKind, P3, ProcessPlan, geom};

/// Which plane a view shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Projection {
    /// From above: X right, Y up.
    Top,
    /// From the front: X right, Z up.
    Front,
    /// From the side: Y right, Z up.
    Side,
}

impl Projection {
    /// The three views, in the order they are shown.
    pub const ALL: [Projection; 3] = [Projection::Top, Projection::Front, Projection::Side];

    /// Its name in the page (`top`, `front`, `side`).
    pub fn name(self) -> &'static str {
        match self {
            Projection::Top => "top",
            Projection::Front => "front",
            Projection::Side => "side",
        }
    }

    fn axes(self) -> (usize, usize) {
        match self {
            Projection::Top => (0, 1),
            Projection::Front => (0, 2),
            Projection::Side => (1, 2),
        }
    }

    /// The axis letters, for the caption.
    pub fn label(self) -> &'static str {
        match self {
            Projection::Top => "top (X–Y)",
            Projection::Front => "front (X–Z)",
            Projection::Side => "side (Y–Z)",
        }
    }
}

/// A changed region to box, with the id of the change it belongs to.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// The change's id (the box is `region-{id}`).
    pub id: i64,
    /// Where, mm.
    pub bbox: BBox,
}

/// Which program a path belongs to.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Side {
    Original,
    Edited,
}

impl Side {
    fn class(self) -> &'static str {
        match self {
            Side::Original => "o",
            Side::Edited => "e",
        }
    }
}

/// Half a pixel: the Douglas–Peucker tolerance.
pub const TOLERANCE_PX: f64 = 0.5;

/// One view's frame: pixel size and the mapping from mm.
#[derive(Clone, Copy, Debug)]
struct Frame {
    w: f64,
    h: f64,
    scale: f64,
    origin: [f64; 2],
    axes: (usize, usize),
}

impl Frame {
    fn new(projection: Projection, bbox: BBox, w: f64, h: f64) -> Frame {
        let axes = projection.axes();
        let pad = 12.0;
        let (dx, dy) = (bbox.max[axes.0] - bbox.min[axes.0], bbox.max[axes.1] - bbox.min[axes.1]);
        let scale = ((w - 2.0 * pad) / dx.max(1e-6)).min((h - 2.0 * pad) / dy.max(1e-6));
        let scale = if scale.is_finite() && scale > 0.0 { scale } else { 1.0 };
        // Centred.
        let ox = pad + ((w - 2.0 * pad) - dx * scale) / 2.0;
        let oy = pad + ((h - 2.0 * pad) - dy * scale) / 2.0;
        Frame { w, h, scale, origin: [bbox.min[axes.0] - ox / scale, bbox.max[axes.1] + oy / scale], axes }
    }

    fn px(&self, p: P3) -> [f64; 2] {
        [(p[self.axes.0] - self.origin[0]) * self.scale, (self.origin[1] - p[self.axes.1]) * self.scale]
    }
}

/// The box around every move and start point of both plans.
pub fn extent(plans: &[&ProcessPlan]) -> Option<BBox> {
    let mut bbox = None;
    for plan in plans {
        for w in &plan.workingsteps {
            if let Some(b) = w.bbox {
                geom::extend(&mut bbox, b.min);
                geom::extend(&mut bbox, b.max);
            }
            for m in &w.toolpath {
                geom::extend(&mut bbox, m.from);
                geom::extend(&mut bbox, m.to);
            }
            if let Some(p) = w.start_point {
                geom::extend(&mut bbox, p);
            }
        }
    }
    bbox
}

fn inside(b: &BBox, p: P3) -> bool {
    let e = 1e-6;
    (0..3).all(|i| p[i] >= b.min[i] - e && p[i] <= b.max[i] + e)
}

/// Douglas–Peucker over `pts`: sets `keep` for the points that stay, in chunks of at most
/// [`CHUNK`] points (their ends kept), so that a run of a million points costs a million
/// times a chunk's kept points at worst, not a million times the run's.
fn simplify(pts: &[[f64; 2]], keep: &mut [bool], tolerance: f64) {
    let mut lo = 0;
    while lo + 1 < pts.len() {
        let hi = (lo + CHUNK).min(pts.len() - 1);
        simplify_chunk(&pts[lo..=hi], &mut keep[lo..=hi], tolerance);
        lo = hi;
    }
    if pts.len() == 1 {
        keep[0] = true;
    }
}

/// The most points Douglas–Peucker looks at together.
const CHUNK: usize = 2048;

/// Douglas–Peucker over one chunk. Iterative, so a long chunk does not recurse deep.
fn simplify_chunk(pts: &[[f64; 2]], keep: &mut [bool], tolerance: f64) {
    if pts.len() < 3 {
        keep.iter_mut().for_each(|k| *k = true);
        return;
    }
    let last = pts.len() - 1;
    keep[0] = true;
    keep[last] = true;
    let mut stack = vec![(0usize, last)];
    while let Some((lo, hi)) = stack.pop() {
        if hi <= lo + 1 {
            continue;
        }
        let (a, b) = (pts[lo], pts[hi]);
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let len = dx.hypot(dy);
        let mut worst = (0.0f64, lo);
        for (i, p) in pts.iter().enumerate().take(hi).skip(lo + 1) {
            let d = if len < 1e-12 { (p[0] - a[0]).hypot(p[1] - a[1]) } else { ((p[0] - a[0]) * dy - (p[1] - a[1]) * dx).abs() / len };
            if d > worst.0 {
                worst = (d, i);
            }
        }
        if worst.0 > tolerance {
            keep[worst.1] = true;
            stack.push((lo, worst.1));
            stack.push((worst.1, hi));
        }
    }
}

/// Path data of a polyline: `M x y L x y …`, a tenth of a pixel, repeated points dropped.
fn path_data(out: &mut String, pts: impl Iterator<Item = [f64; 2]>) {
    let mut last: Option<(i64, i64)> = None;
    let mut n = 0;
    for p in pts {
        let q = ((p[0] * 10.0).round() as i64, (p[1] * 10.0).round() as i64);
        if last == Some(q) {
            continue;
        }
        let cmd = match n {
            0 => "M",
            1 => "L",
            _ => " ",
        };
        let _ = write!(out, "{cmd}{} {}", Tenth(q.0), Tenth(q.1));
        last = Some(q);
        n += 1;
    }
    if n == 1 {
        // A single point still shows as a dot.
        out.push_str("h0.1");
    }
}

/// Tenths as a decimal without trailing zeros.
struct Tenth(i64);

impl std::fmt::Display for Tenth {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (sign, v) = if self.0 < 0 { ("-", -self.0) } else { ("", self.0) };
        if v % 10 == 0 { write!(f, "{sign}{}", v / 10) } else { write!(f, "{sign}{}.{}", v / 10, v % 10) }
    }
}

/// A run of moves of one kind, projected: its pixels, and whether each point lies in a
/// changed region ([`EXACT`] in one drawn exactly, [`WIDE`] in one that is not).
struct Run {
    rapid: bool,
    pts: Vec<[f64; 2]>,
    changed: Vec<u8>,
}

/// A point in a region that covers much of the view (the whole part, say): drawn as changed,
/// simplified at a quarter pixel, so that the picture's size stays bounded by the view.
const WIDE: u8 = 1;
/// A point in a region drawn exactly.
const EXACT: u8 = 2;

/// The share of the drawing (of its width times of its height) a region may cover and still be drawn exactly.
const EXACT_SHARE: f64 = 0.125;

/// How a point lies in the regions: the highest of [`WIDE`], [`EXACT`], or 0.
fn in_regions(regions: &[(Region, u8)], p: P3) -> u8 {
    regions.iter().filter(|(r, _)| inside(&r.bbox, p)).map(|(_, k)| *k).max().unwrap_or(0)
}

/// Writes the paths of one workingstep, for one program, into `out`.
fn workingstep_paths(
    out: &mut String,
    frame: &Frame,
    w: &crate::plan::Workingstep,
    regions: &[(Region, u8)],
    side: Side,
    stats: &mut Stats,
) {
    let mut runs: Vec<Run> = Vec::new();
    let mut samples = Vec::new();
    let mut last_end: Option<P3> = None;
    for m in &w.toolpath {
        let rapid = m.kind == MoveKind::Rapid;
        let contiguous = last_end == Some(m.from);
        if !contiguous || runs.last().is_none_or(|r| r.rapid != rapid) {
            let start_in = in_regions(regions, m.from);
            let carry = if contiguous { runs.last().and_then(|r| r.pts.last().copied()) } else { None };
            runs.push(Run { rapid, pts: vec![carry.unwrap_or_else(|| frame.px(m.from))], changed: vec![start_in] });
        }
        samples.clear();
        geom::sample(&m, &mut samples);
        let run = runs.last_mut().expect("a run was pushed");
        for p in &samples {
            run.pts.push(frame.px(*p));
            run.changed.push(in_regions(regions, *p));
        }
        last_end = Some(m.to);
        stats.moves += 1;
    }
    let mut rapid_d = String::new();
    let mut feed_d = String::new();
    let mut changed_d = String::new();
    for run in &runs {
        stats.points += run.pts.len();
        // Pieces: a changed piece is each segment whose both ends are in a region, kept exact;
        // between them, pieces simplified at half a pixel.
        let n = run.pts.len();
        let mut i = 0;
        // A segment is changed as the lesser of its ends.
        let seg = |k: usize| run.changed[k].min(run.changed[k + 1]);
        while i + 1 < n {
            let state = seg(i);
            let mut j = i + 1;
            while j + 1 < n && seg(j) == state {
                j += 1;
            }
            let piece = &run.pts[i..=j];
            if state == EXACT && !run.rapid {
                path_data(&mut changed_d, piece.iter().copied());
                stats.drawn += piece.len();
            } else {
                let mut keep = vec![false; piece.len()];
                let (tolerance, target) = match (run.rapid, state) {
                    (true, _) => (TOLERANCE_PX, &mut rapid_d),
                    (false, WIDE) => (TOLERANCE_PX / 2.0, &mut changed_d),
                    _ => (TOLERANCE_PX, &mut feed_d),
                };
                simplify(piece, &mut keep, tolerance);
                let kept = piece.iter().zip(&keep).filter(|(_, k)| **k).map(|(p, _)| *p);
                stats.drawn += keep.iter().filter(|k| **k).count();
                path_data(target, kept);
            }
            i = j;
        }
    }
    let c = side.class();
    for (d, class) in [(&rapid_d, "rapid"), (&feed_d, "feed"), (&changed_d, "chg")] {
        if !d.is_empty() {
            let _ = write!(out, "<path class=\"{c} {class}\" d=\"{d}\"/>");
        }
    }
    if let Some(p) = w.start_point {
        let q = frame.px(p);
        let _ = write!(
            out,
            "<circle class=\"{c} start\" cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\"><title>{} start point of workingstep {}</title></circle>",
            q[0],
            q[1],
            match side {
                Side::Original => "original's",
                Side::Edited => "edited",
            },
            w.index
        );
    }
}

/// What a picture holds, for the benchmark and the tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Moves read (both plans, every view).
    pub moves: usize,
    /// Points projected.
    pub points: usize,
    /// Points drawn after simplification.
    pub drawn: usize,
}

/// One view of both plans as an SVG element `width` × `height` pixels: workingstep layers
/// (`<g class="layer" data-layer="o1">`: original workingstep 1, `e1`: edited), changed
/// regions boxed (`<rect id="region-{view}-{id}" class="region">`, in a link to
/// `#change-{id}`), start points marked, and a moved start point joined by an arrow.
pub fn view_svg(
    projection: Projection,
    original: &ProcessPlan,
    edited: &ProcessPlan,
    regions: &[Region],
    size: (f64, f64),
    stats: &mut Stats,
) -> String {
    let bbox = extent(&[original, edited]).unwrap_or(BBox { min: [0.0; 3], max: [1.0; 3] });
    // Regions count towards the extent, so a box is never off the picture.
    let bbox = regions.iter().fold(bbox, |mut b, r| {
        for i in 0..3 {
            b.min[i] = b.min[i].min(r.bbox.min[i]);
            b.max[i] = b.max[i].max(r.bbox.max[i]);
        }
        b
    });
    let frame = Frame::new(projection, bbox, size.0, size.1);
    let name = projection.name();
    // A region's share of the drawing: of its width times of its height.
    let (e0, e1) = (frame.px(bbox.min), frame.px(bbox.max));
    let (ew, eh) = ((e0[0] - e1[0]).abs().max(1.0), (e0[1] - e1[1]).abs().max(1.0));
    let regions: Vec<(Region, u8)> = regions
        .iter()
        .map(|r| {
            let (a, b) = (frame.px(r.bbox.min), frame.px(r.bbox.max));
            let share = ((a[0] - b[0]).abs() / ew).min(1.0) * ((a[1] - b[1]).abs() / eh).min(1.0);
            (*r, if share <= EXACT_SHARE { EXACT } else { WIDE })
        })
        .collect();
    let mut out = String::new();
    let _ = write!(
        out,
        "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"toolpath\" data-view=\"{name}\" viewBox=\"0 0 {} {}\" width=\"{}\" height=\"{}\" role=\"img\"><title>{}</title><rect class=\"bg\" width=\"{}\" height=\"{}\"/><g class=\"zoom\">",
        frame.w,
        frame.h,
        frame.w,
        frame.h,
        projection.label(),
        frame.w,
        frame.h
    );
    for (side, plan) in [(Side::Original, original), (Side::Edited, edited)] {
        for w in &plan.workingsteps {
            let _ = write!(out, "<g class=\"layer\" data-layer=\"{}{}\">", side.class(), w.index);
            workingstep_paths(&mut out, &frame, w, &regions, side, stats);
            out.push_str("</g>");
        }
    }
    for (r, _) in &regions {
        let (a, b) = (frame.px(r.bbox.min), frame.px(r.bbox.max));
        let (x0, x1) = (a[0].min(b[0]) - 3.0, a[0].max(b[0]) + 3.0);
        let (y0, y1) = (a[1].min(b[1]) - 3.0, a[1].max(b[1]) + 3.0);
        let _ = write!(
            out,
            "<a href=\"#change-{id}\"><rect id=\"region-{name}-{id}\" class=\"region\" data-change=\"{id}\" x=\"{x0:.1}\" y=\"{y0:.1}\" width=\"{:.1}\" height=\"{:.1}\"><title>change {id}</title></rect></a>",
            x1 - x0,
            y1 - y0,
            id = r.id
        );
    }
    out.push_str("</g></svg>");
    out
}

/// Whether two start points differ by more than the diff's tolerance.
pub fn moved(a: P3, b: P3) -> bool {
    geom::dist(a, b) > crate::diff::TOLERANCE
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{Move, Phase};

    fn line(kind: MoveKind, from: P3, to: P3) -> Move {
        Move { kind, phase: Phase::Cut, from, to, arc: None, feed: 100.0, line: 1 }
    }

    #[test]
    fn douglas_peucker_keeps_corners_and_drops_collinear_points() {
        let pts: Vec<[f64; 2]> = (0..=100).map(|i| [f64::from(i), 0.0]).chain((1..=100).map(|i| [100.0, f64::from(i)])).collect();
        let mut keep = vec![false; pts.len()];
        simplify(&pts, &mut keep, TOLERANCE_PX);
        let kept: Vec<[f64; 2]> = pts.iter().zip(&keep).filter(|(_, k)| **k).map(|(p, _)| *p).collect();
        assert_eq!(kept, vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0]]);
    }

    #[test]
    fn path_data_is_short_and_drops_repeats() {
        let mut s = String::new();
        path_data(&mut s, [[0.0, 0.0], [0.04, 0.0], [10.25, -3.0], [12.0, 5.55]].into_iter());
        assert_eq!(s, "M0 0L10.3 -3 12 5.6");
    }

    #[test]
    fn a_changed_region_is_drawn_exactly_and_boxed() {
        let mut a = ProcessPlan::default();
        let technology = crate::plan::Technology {
            feed: 100.0,
            feeds: vec![100.0],
            spindle_speed: 1000.0,
            surface_speed: None,
            spindle: crate::plan::SpindleDir::Cw,
            coolant: crate::plan::Coolant::Off,
        };
        // 200 collinear feeds; 10 of them fall in the region.
        let toolpath = (0..200).map(|i| line(MoveKind::Line, [f64::from(i), 0.0, 0.0], [f64::from(i + 1), 0.0, 0.0])).collect();
        let mut w = crate::plan::Workingstep::unmeasured(
            1,
            crate::plan::Operation::PlaneFinishMilling,
            1,
            technology,
            10.0,
            toolpath,
            crate::text::TextRange::default(),
            (1, 1),
        );
        w.start_point = Some([0.0, 0.0, 0.0]);
        a.workingsteps.push(w);
        let b = a.clone();
        let regions = [Region { id: 7, bbox: BBox { min: [50.0, -1.0, -1.0], max: [60.0, 1.0, 1.0] } }];
        let mut stats = Stats::default();
        let svg = view_svg(Projection::Top, &a, &b, &regions, (600.0, 300.0), &mut stats);
        assert!(svg.contains("id=\"region-top-7\""), "{svg}");
        assert!(svg.contains("href=\"#change-7\""));
        assert!(svg.contains("class=\"o chg\"") && svg.contains("class=\"e chg\""));
        assert!(svg.contains("class=\"o feed\"") && svg.contains("class=\"e start\""));
        // 11 exact points in each region piece, a handful elsewhere.
        assert!(stats.drawn < 40, "{stats:?}");
        assert_eq!(stats.moves, 400);
        // A region over the whole part is drawn as changed, but simplified.
        let wide = [Region { id: 8, bbox: BBox { min: [-1.0, -1.0, -1.0], max: [201.0, 1.0, 1.0] } }];
        let mut stats = Stats::default();
        let svg = view_svg(Projection::Top, &a, &b, &wide, (600.0, 300.0), &mut stats);
        assert!(svg.contains("class=\"e chg\"") && !svg.contains("class=\"e feed\""), "{svg}");
        assert!(stats.drawn <= 4, "{stats:?}");
    }
}

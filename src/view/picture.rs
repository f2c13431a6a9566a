//! Toolpath pictures: the original's and the edited program's toolpaths overlaid, as SVG, in a
//! top view and two side views.
//!
//! [`pictures`] reads each toolpath once and streams every point into the three views: each
//! view projects it to pixels and simplifies each polyline as it comes, by a cone test that
//! keeps every dropped point within half a pixel of the segment drawn for it (no buffers of
//! points, one square root a point), so that a picture's size follows the screen, not the
//! program. The moves of a change — inside its region's box, from its first changed line
//! on — are drawn exactly, every end point, up to [`EXACT_MOVES`] moves per region and
//! program; a region with more (a change over the whole part) draws the rest at a quarter
//! pixel and says so in the picture. Rapids, feeds and changed moves have their own classes;
//! start points are marked; each changed region is a box with an id (`region-{view}-{id}`)
//! that its sentence links to.

use std::fmt::Write as _;

use crate::plan::{BBox, Move, MoveKind, P3, ProcessPlan, Workingstep, geom};

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

/// A changed region to box: the change it belongs to, where, and from which line on its
/// moves are the change's.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Region {
    /// The change's id (the box is `region-{view}-{id}`).
    pub id: i64,
    /// Where, mm.
    pub bbox: BBox,
    /// The change's first line in the original and in the edited program: a move in the
    /// box before it is not the change's. `None`: every move in the box is.
    pub lines: (Option<u32>, Option<u32>),
}

/// Half a pixel: the simplification's tolerance.
pub const TOLERANCE_PX: f64 = 0.5;

/// The most moves of one program drawn exactly in one changed region; a change with more
/// (over the whole part, say) draws the rest within a quarter pixel, and the picture says so.
pub const EXACT_MOVES: usize = 10_000;

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

/// Path data of polylines: `M x y L x y …`, a tenth of a pixel, repeated points dropped.
#[derive(Default)]
struct PathData {
    d: String,
    last: Option<(i64, i64)>,
    /// Points written of the open polyline.
    n: usize,
    /// Points written in all.
    drawn: usize,
}

impl PathData {
    fn point(&mut self, p: [f64; 2]) {
        let q = ((p[0] * 10.0).round() as i64, (p[1] * 10.0).round() as i64);
        if self.last == Some(q) {
            return;
        }
        let cmd = match self.n {
            0 => "M",
            1 => "L",
            _ => " ",
        };
        let _ = write!(self.d, "{cmd}{} {}", Tenth(q.0), Tenth(q.1));
        self.last = Some(q);
        self.n += 1;
        self.drawn += 1;
    }

    /// Ends the open polyline; a single point still shows as a dot.
    fn end(&mut self) {
        if self.n == 1 {
            self.d.push_str("h0.1");
        }
        self.n = 0;
        self.last = None;
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

fn cross(a: [f64; 2], b: [f64; 2]) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// One polyline drawn as its points come, simplified by the cone test (or exactly, at a
/// tolerance of 0).
///
/// From the anchor (the last point written), a point at distance `d > tol` allows the
/// directions within `asin(tol / d)` of its own; the allowed directions of all points since
/// the anchor are intersected. A point is taken as the segment's new end while its direction
/// is allowed and it lies at least as far from the anchor as every point before it; then
/// each of those lies within `tol` of the line through the end and projects onto the
/// segment, so within `tol` of the segment. Otherwise the end is written and becomes the
/// anchor. Constant memory and one square root a point.
struct Pen {
    out: PathData,
    tol: f64,
    open: bool,
    anchor: [f64; 2],
    end: Option<[f64; 2]>,
    /// The allowed directions, from `lo` counter-clockwise to `hi`, once a point lies
    /// farther than `tol`.
    cone: Option<([f64; 2], [f64; 2])>,
    /// The largest squared distance from the anchor so far.
    dmax2: f64,
}

impl Pen {
    fn new(tol: f64) -> Pen {
        Pen { out: PathData::default(), tol, open: false, anchor: [0.0; 2], end: None, cone: None, dmax2: 0.0 }
    }

    /// Starts a polyline at `p`.
    fn begin(&mut self, p: [f64; 2]) {
        self.close();
        self.out.point(p);
        self.restart(p);
        self.open = true;
    }

    fn restart(&mut self, anchor: [f64; 2]) {
        self.anchor = anchor;
        self.end = None;
        self.cone = None;
        self.dmax2 = 0.0;
    }

    /// The polyline goes on to `p`.
    fn to(&mut self, p: [f64; 2]) {
        if self.tol <= 0.0 {
            self.out.point(p);
            return;
        }
        if !self.extend(p) {
            let e = self.end.unwrap_or(p);
            self.out.point(e);
            self.restart(e);
            // The first point after an anchor is always taken.
            self.extend(p);
        }
    }

    /// Takes `p` as the segment's end, if every point since the anchor stays within `tol`.
    /// Squared distances, and directions as vectors of any length: one square root a point.
    fn extend(&mut self, p: [f64; 2]) -> bool {
        let v = [p[0] - self.anchor[0], p[1] - self.anchor[1]];
        let d2 = v[0] * v[0] + v[1] * v[1];
        let t2 = self.tol * self.tol;
        if d2 < self.dmax2 && self.dmax2 > t2 {
            // A point before lies farther away: beyond this end.
            return false;
        }
        if d2 <= t2 {
            self.dmax2 = self.dmax2.max(d2);
            self.end = Some(p);
            return true;
        }
        if let Some((lo, hi)) = self.cone
            && (cross(lo, v) < 0.0 || cross(v, hi) < 0.0)
        {
            return false;
        }
        // The directions within asin(tol / d) of v's, as v turned by that angle (scaled by d).
        let k = (d2 - t2).sqrt();
        let clo = [v[0] * k + v[1] * self.tol, v[1] * k - v[0] * self.tol];
        let chi = [v[0] * k - v[1] * self.tol, v[1] * k + v[0] * self.tol];
        self.cone = Some(match self.cone {
            None => (clo, chi),
            Some((lo, hi)) => (if cross(lo, clo) > 0.0 { clo } else { lo }, if cross(hi, chi) < 0.0 { chi } else { hi }),
        });
        self.dmax2 = d2;
        self.end = Some(p);
        true
    }

    /// Ends the open polyline at its last point.
    fn close(&mut self) {
        if self.open {
            if let Some(e) = self.end.take() {
                self.out.point(e);
            }
            self.out.end();
            self.open = false;
        }
    }
}

/// How a move is drawn: the index of its pen.
const RAPID: usize = 0;
const FEED: usize = 1;
/// Changed, beyond its region's exact moves: within a quarter pixel.
const WIDE: usize = 2;
/// Changed, every point.
const EXACT: usize = 3;

/// One view being drawn.
struct View {
    projection: Projection,
    frame: Frame,
    out: String,
    pens: [Pen; 4],
}

impl View {
    fn new(projection: Projection, frame: Frame) -> View {
        let pens = [Pen::new(TOLERANCE_PX), Pen::new(TOLERANCE_PX), Pen::new(TOLERANCE_PX / 2.0), Pen::new(0.0)];
        View { projection, frame, out: String::new(), pens }
    }

    /// Writes the paths drawn since the last call, as `side`'s, and starts afresh.
    fn flush(&mut self, side: &str) {
        for p in &mut self.pens {
            p.close();
        }
        let [rapid, feed, wide, exact] = &mut self.pens;
        for (class, parts) in [
            ("rapid", [&mut rapid.out, &mut PathData::default()]),
            ("feed", [&mut feed.out, &mut PathData::default()]),
            ("chg", [&mut exact.out, &mut wide.out]),
        ] {
            if parts.iter().any(|p| !p.d.is_empty()) {
                let _ = write!(self.out, "<path class=\"{side} {class}\" d=\"");
                for p in parts {
                    self.out.push_str(&p.d);
                    p.d.clear();
                }
                self.out.push_str("\"/>");
            }
        }
    }

    fn drawn(&self) -> usize {
        self.pens.iter().map(|p| p.out.drawn).sum()
    }
}

/// What a picture holds, for the benchmark and the tests.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Stats {
    /// Moves read (both plans, once for all views).
    pub moves: usize,
    /// Points projected (every view).
    pub points: usize,
    /// Points drawn after simplification (every view).
    pub drawn: usize,
}

/// How a changed region was drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RegionDrawn {
    /// The change's id.
    pub id: i64,
    /// The change's moves in the region: the original's and the edited program's.
    pub moves: [usize; 2],
}

impl RegionDrawn {
    /// Whether every one of its moves was drawn exactly.
    pub fn exact(&self) -> bool {
        self.moves.iter().all(|&n| n <= EXACT_MOVES)
    }
}

/// The pictures of both plans: one SVG element per projection, of its size in pixels.
pub struct Pictures {
    /// Each view's SVG, in the order asked.
    pub views: Vec<(Projection, String)>,
    /// What they hold.
    pub stats: Stats,
    /// How each region was drawn, in the order given.
    pub regions: Vec<RegionDrawn>,
}

/// Draws both plans in each of `views` (a projection and its width and height in pixels).
///
/// Each SVG has workingstep layers (`<g class="layer" data-layer="o1">`: original
/// workingstep 1, `e1`: edited), paths of class `rapid`, `feed` and `chg` (the changed
/// moves), start points marked, and each changed region boxed (`<rect
/// id="region-{view}-{id}" class="region">`, in a link to `#change-{id}`). Each toolpath is
/// read once for all views.
pub fn pictures(original: &ProcessPlan, edited: &ProcessPlan, regions: &[Region], views: &[(Projection, (f64, f64))]) -> Pictures {
    let bbox = extent(&[original, edited]).unwrap_or(BBox { min: [0.0; 3], max: [1.0; 3] });
    // Regions count towards the extent, so a box is never off the picture.
    let bbox = regions.iter().fold(bbox, |mut b, r| {
        for i in 0..3 {
            b.min[i] = b.min[i].min(r.bbox.min[i]);
            b.max[i] = b.max[i].max(r.bbox.max[i]);
        }
        b
    });
    let mut vs: Vec<View> = views.iter().map(|(p, (w, h))| View::new(*p, Frame::new(*p, bbox, *w, *h))).collect();
    for v in &mut vs {
        let (f, name) = (v.frame, v.projection.name());
        let _ = write!(
            v.out,
            "<svg xmlns=\"http://www.w3.org/2000/svg\" class=\"toolpath\" data-view=\"{name}\" viewBox=\"0 0 {w} {h}\" width=\"{w}\" height=\"{h}\" role=\"img\"><title>{}</title><rect class=\"bg\" width=\"{w}\" height=\"{h}\"/><g class=\"zoom\">",
            v.projection.label(),
            w = f.w,
            h = f.h,
        );
    }
    let mut counts = vec![[0usize; 2]; regions.len()];
    let mut stats = Stats::default();
    let mut samples = Vec::new();
    for (s, plan) in [original, edited].into_iter().enumerate() {
        let side = if s == 0 { "o" } else { "e" };
        for w in &plan.workingsteps {
            for v in &mut vs {
                let _ = write!(v.out, "<g class=\"layer\" data-layer=\"{side}{}\">", w.index);
            }
            let mut last: Option<(P3, usize)> = None;
            for m in w.toolpath.iter() {
                let pen = pen_of(&m, s, regions, &mut counts);
                if last != Some((m.from, pen)) {
                    for v in &mut vs {
                        let p = v.frame.px(m.from);
                        v.pens[pen].begin(p);
                    }
                    stats.points += vs.len();
                }
                if m.kind == MoveKind::Arc {
                    samples.clear();
                    geom::sample(&m, &mut samples);
                    for v in &mut vs {
                        for q in &samples {
                            let p = v.frame.px(*q);
                            v.pens[pen].to(p);
                        }
                    }
                    stats.points += samples.len() * vs.len();
                } else {
                    for v in &mut vs {
                        let p = v.frame.px(m.to);
                        v.pens[pen].to(p);
                    }
                    stats.points += vs.len();
                }
                stats.moves += 1;
                last = Some((m.to, pen));
            }
            for v in &mut vs {
                v.flush(side);
                start_point(&mut v.out, &v.frame, w, s == 0);
                v.out.push_str("</g>");
            }
        }
    }
    stats.drawn = vs.iter().map(View::drawn).sum();
    let drawn: Vec<RegionDrawn> = regions.iter().zip(&counts).map(|(r, c)| RegionDrawn { id: r.id, moves: *c }).collect();
    for v in &mut vs {
        boxes(v, regions, &drawn);
    }
    Pictures { views: vs.into_iter().map(|v| (v.projection, v.out)).collect(), stats, regions: drawn }
}

/// The pen a move of program `side` (0: the original) is drawn with; counts it in the
/// regions it is a change's move of.
fn pen_of(m: &Move, side: usize, regions: &[Region], counts: &mut [[usize; 2]]) -> usize {
    if m.kind == MoveKind::Rapid {
        return RAPID;
    }
    let mut pen = FEED;
    for (r, n) in regions.iter().zip(counts.iter_mut()) {
        let first = if side == 0 { r.lines.0 } else { r.lines.1 };
        if first.is_none_or(|l| m.line >= l) && inside(&r.bbox, m.to) {
            n[side] += 1;
            pen = pen.max(if n[side] <= EXACT_MOVES { EXACT } else { WIDE });
        }
    }
    pen
}

fn start_point(out: &mut String, frame: &Frame, w: &Workingstep, original: bool) {
    if let Some(p) = w.start_point {
        let q = frame.px(p);
        let _ = write!(
            out,
            "<circle class=\"{} start\" cx=\"{:.1}\" cy=\"{:.1}\" r=\"4\"><title>{} start point of workingstep {}</title></circle>",
            if original { "o" } else { "e" },
            q[0],
            q[1],
            if original { "original's" } else { "edited" },
            w.index
        );
    }
}

/// The regions' boxes, and a note for each region not drawn exactly; closes the SVG.
fn boxes(v: &mut View, regions: &[Region], drawn: &[RegionDrawn]) {
    let (frame, name) = (v.frame, v.projection.name());
    for r in regions {
        let (a, b) = (frame.px(r.bbox.min), frame.px(r.bbox.max));
        let (x0, x1) = (a[0].min(b[0]) - 3.0, a[0].max(b[0]) + 3.0);
        let (y0, y1) = (a[1].min(b[1]) - 3.0, a[1].max(b[1]) + 3.0);
        let _ = write!(
            v.out,
            "<a href=\"#change-{id}\"><rect id=\"region-{name}-{id}\" class=\"region\" data-change=\"{id}\" x=\"{x0:.1}\" y=\"{y0:.1}\" width=\"{:.1}\" height=\"{:.1}\"><title>change {id}</title></rect></a>",
            x1 - x0,
            y1 - y0,
            id = r.id
        );
    }
    v.out.push_str("</g>");
    // Outside the zoom group, so that it stays put.
    for (k, d) in drawn.iter().filter(|d| !d.exact()).enumerate() {
        let _ = write!(
            v.out,
            "<text class=\"note\" data-change=\"{id}\" x=\"6\" y=\"{y:.1}\">change {id}: {a} + {b} moves, the first {EXACT_MOVES} of each exact</text>",
            id = d.id,
            a = d.moves[0],
            b = d.moves[1],
            y = frame.h - 6.0 - 14.0 * k as f64,
        );
    }
    v.out.push_str("</svg>");
}

/// Whether two start points differ by more than the diff's tolerance.
pub fn moved(a: P3, b: P3) -> bool {
    geom::dist(a, b) > crate::diff::TOLERANCE
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::{Move, Phase};

    fn line(kind: MoveKind, from: P3, to: P3, line: u32) -> Move {
        Move { kind, phase: Phase::Cut, from, to, arc: None, feed: 100.0, line }
    }

    /// The points of path data, in tenths of a pixel.
    fn points(d: &str) -> Vec<(i64, i64)> {
        let nums: Vec<i64> = d
            .replace(['M', 'L'], " ")
            .replace("h0.1", " ")
            .split_whitespace()
            .map(|n| (n.parse::<f64>().unwrap() * 10.0).round() as i64)
            .collect();
        nums.chunks(2).map(|c| (c[0], c[1])).collect()
    }

    /// The path data of `class` (`o chg`) in an SVG.
    fn path_of(svg: &str, class: &str) -> String {
        let mut out = String::new();
        let key = format!("class=\"{class}\" d=\"");
        let mut rest = svg;
        while let Some(i) = rest.find(&key) {
            rest = &rest[i + key.len()..];
            let end = rest.find('"').unwrap();
            out.push_str(&rest[..end]);
            rest = &rest[end..];
        }
        out
    }

    /// Runs a pen over `pts`; the points it wrote.
    fn drawn(pts: &[[f64; 2]], tol: f64) -> Vec<[f64; 2]> {
        let mut pen = Pen::new(tol);
        pen.begin(pts[0]);
        for p in &pts[1..] {
            pen.to(*p);
        }
        pen.close();
        points(&pen.out.d).into_iter().map(|(x, y)| [x as f64 / 10.0, y as f64 / 10.0]).collect()
    }

    fn segment_distance(p: [f64; 2], a: [f64; 2], b: [f64; 2]) -> f64 {
        let (dx, dy) = (b[0] - a[0], b[1] - a[1]);
        let l2 = dx * dx + dy * dy;
        let t = if l2 == 0.0 { 0.0 } else { (((p[0] - a[0]) * dx + (p[1] - a[1]) * dy) / l2).clamp(0.0, 1.0) };
        (p[0] - a[0] - t * dx).hypot(p[1] - a[1] - t * dy)
    }

    #[test]
    fn the_cone_test_keeps_corners_and_drops_collinear_points() {
        let pts: Vec<[f64; 2]> = (0..=100).map(|i| [f64::from(i), 0.0]).chain((1..=100).map(|i| [100.0, f64::from(i)])).collect();
        assert_eq!(drawn(&pts, TOLERANCE_PX), vec![[0.0, 0.0], [100.0, 0.0], [100.0, 100.0]]);
        // Exact: every point.
        assert_eq!(drawn(&pts, 0.0).len(), 201);
    }

    #[test]
    fn every_point_dropped_lies_within_the_tolerance_of_the_drawn_path() {
        // A wavy zig-zag with reversals, tiny steps and a spike.
        let mut pts = Vec::new();
        for i in 0..3000 {
            let t = f64::from(i) * 0.05;
            let x = if (i / 500) % 2 == 0 { f64::from(i % 500) * 0.3 } else { 150.0 - f64::from(i % 500) * 0.3 };
            pts.push([x, 40.0 + 8.0 * t.sin() + 0.3 * (t * 7.0).cos() + if i == 1234 { 25.0 } else { 0.0 }]);
        }
        let kept = drawn(&pts, TOLERANCE_PX);
        assert!(kept.len() < pts.len() / 4, "{} of {}", kept.len(), pts.len());
        // The rounding to a tenth of a pixel adds at most 0.071 px.
        let worst =
            pts.iter().map(|p| kept.windows(2).map(|s| segment_distance(*p, s[0], s[1])).fold(f64::INFINITY, f64::min)).fold(0.0, f64::max);
        assert!(worst <= TOLERANCE_PX + 0.071, "{worst}");
        let spike = pts[1234];
        assert!(kept.iter().any(|p| (p[0] - spike[0]).abs() < 0.1 && (p[1] - spike[1]).abs() < 0.1), "the spike is drawn: {kept:?}");
    }

    #[test]
    fn path_data_is_short_and_drops_repeats() {
        let mut s = PathData::default();
        for p in [[0.0, 0.0], [0.04, 0.0], [10.25, -3.0], [12.0, 5.55]] {
            s.point(p);
        }
        assert_eq!(s.d, "M0 0L10.3 -3 12 5.6");
    }

    fn technology() -> crate::plan::Technology {
        crate::plan::Technology {
            feed: 100.0,
            feeds: vec![100.0],
            spindle_speed: 1000.0,
            surface_speed: None,
            spindle: crate::plan::SpindleDir::Cw,
            coolant: crate::plan::Coolant::Off,
            spindle_id: crate::plan::SpindleId::Main,
        }
    }

    /// A plan of one workingstep: a rapid, then `n` short feeds along X that wiggle by a
    /// hundredth of a millimetre (lost at screen resolution), feed `i` on line `i + 10`.
    fn plan(n: u32, dz: impl Fn(u32) -> f64) -> ProcessPlan {
        let at = |i: u32| [f64::from(i) * 0.1, if i % 2 == 0 { 0.0 } else { 0.01 }, dz(i)];
        // A rapid down from above, so that no view is scaled to the wiggle.
        let approach = line(MoveKind::Rapid, [0.0, 20.0, 20.0], at(0), 5);
        let toolpath = std::iter::once(approach).chain((0..n).map(|i| line(MoveKind::Line, at(i), at(i + 1), i + 10))).collect();
        let mut w = crate::plan::Workingstep::unmeasured(
            1,
            crate::plan::Operation::PlaneFinishMilling,
            1,
            technology(),
            10.0,
            toolpath,
            crate::text::TextRange::default(),
            (1, 1),
        );
        w.start_point = Some([0.0, 0.0, 0.0]);
        let mut p = ProcessPlan::default();
        p.workingsteps.push(w);
        p
    }

    /// The projected end points, in tenths of a pixel, of the moves of `plan` whose line is in `lines`.
    fn ends(
        plan: &ProcessPlan,
        both: &[&ProcessPlan],
        regions: &[Region],
        view: (Projection, (f64, f64)),
        lines: std::ops::Range<u32>,
    ) -> Vec<(i64, i64)> {
        let mut bbox = extent(both).unwrap();
        for r in regions {
            for i in 0..3 {
                bbox.min[i] = bbox.min[i].min(r.bbox.min[i]);
                bbox.max[i] = bbox.max[i].max(r.bbox.max[i]);
            }
        }
        let f = Frame::new(view.0, bbox, view.1.0, view.1.1);
        plan.workingsteps[0]
            .toolpath
            .iter()
            .filter(|m| lines.contains(&m.line))
            .map(|m| {
                let p = f.px(m.to);
                ((p[0] * 10.0).round() as i64, (p[1] * 10.0).round() as i64)
            })
            .collect()
    }

    #[test]
    fn every_move_of_a_change_is_drawn_exactly_and_boxed() {
        // 2000 moves; the edit lowers moves 1000–1099 (lines 1010–1109) by 0.2 mm.
        let a = plan(2000, |_| 0.0);
        let b = plan(2000, |i| if (1000..1100).contains(&i) { -0.2 } else { 0.0 });
        let regions = [Region { id: 7, bbox: BBox { min: [99.9, 0.0, -0.2], max: [110.0, 0.01, 0.0] }, lines: (Some(1010), Some(1010)) }];
        let views = [(Projection::Top, (640.0, 420.0)), (Projection::Front, (640.0, 230.0)), (Projection::Side, (460.0, 230.0))];
        let pics = pictures(&a, &b, &regions, &views);
        assert_eq!(pics.stats.moves, 4002);
        assert_eq!(pics.regions, vec![RegionDrawn { id: 7, moves: [100, 100] }]);
        for (k, (p, svg)) in pics.views.iter().enumerate() {
            assert!(svg.contains(&format!("id=\"region-{}-7\"", p.name())) && svg.contains("href=\"#change-7\""), "{svg}");
            assert!(!svg.contains("class=\"note\""), "every move is exact: {svg}");
            for (side, plan) in [("o", &a), ("e", &b)] {
                let drawn: std::collections::BTreeSet<(i64, i64)> = points(&path_of(svg, &format!("{side} chg"))).into_iter().collect();
                let want = ends(plan, &[&a, &b], &regions, views[k], 1010..1110);
                assert_eq!(want.len(), 100);
                for q in &want {
                    assert!(drawn.contains(q), "{} {side}: the changed move ending at {q:?} is not drawn", p.name());
                }
                // Outside the change, the wiggle is simplified away.
                assert!(points(&path_of(svg, &format!("{side} feed"))).len() < 20, "{svg}");
            }
        }
        // Less than the exact points of the changes and a handful more.
        assert!(pics.stats.drawn < 3 * 2 * (100 + 40), "{:?}", pics.stats);
    }

    #[test]
    fn a_change_over_the_whole_part_is_exact_up_to_its_bound_and_says_so() {
        let n = EXACT_MOVES as u32 + 5000;
        let a = plan(n, |_| 0.0);
        let b = plan(n, |_| -0.2);
        let all = Region {
            id: 8,
            bbox: BBox { min: [-1.0, -1.0, -1.0], max: [f64::from(n) * 0.1 + 1.0, 1.0, 1.0] },
            lines: (Some(10), Some(10)),
        };
        let views = [(Projection::Front, (640.0, 230.0))];
        let pics = pictures(&a, &b, &[all], &views);
        assert_eq!(pics.regions, vec![RegionDrawn { id: 8, moves: [n as usize, n as usize] }]);
        let svg = &pics.views[0].1;
        assert!(svg.contains(&format!("change 8: {n} + {n} moves, the first {EXACT_MOVES} of each exact")), "{}", &svg[svg.len() - 400..]);
        assert!(!svg.contains("class=\"e feed\""), "every move is drawn as changed");
        let drawn: std::collections::BTreeSet<(i64, i64)> = points(&path_of(svg, "e chg")).into_iter().collect();
        for q in ends(&b, &[&a, &b], &[all], views[0], 10..10 + EXACT_MOVES as u32) {
            assert!(drawn.contains(&q), "{q:?}");
        }
        // Bounded: the exact moves, and the rest at screen resolution.
        assert!(svg.len() < 2 * 13 * EXACT_MOVES + 20_000, "{} bytes", svg.len());
    }
}

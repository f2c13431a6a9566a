//! Cutter radius compensation (G41/G42) in the XY plane, or in a lathe's ZX plane (its
//! first axis Z, its second X, as in `ARC_FEED`), computed as LinuxCNC does.
//!
//! The programmed path is offset by the tool radius to the left (G41) or right (G42) of the
//! direction of travel. The move that turns compensation on ends at its programmed end point
//! moved sideways by the radius. After that, each move is offset whole, and the corner with
//! the move before it is resolved when the new move arrives: an outside (convex) corner gets
//! an arc of the tool radius about the programmed corner; an inside (concave) corner trims
//! both moves to the intersection of their offset paths. Because a move's end is only known
//! once the next move arrives, the last offset move is held back, together with the ops that
//! follow it (feed changes, Z moves), and released in order. Memory stays bounded: one move
//! and the ops of one block or so.
//!
//! A lathe tool's orientation (G41.1/G42.1 `L1`–`L9`) makes the controlled point its imaginary
//! tip, not the nose's centre: every compensated point moves by the nose radius towards the
//! tip ([`tip_offset`]), as rs274 moves it.

use crate::canon::{Canon, CanonOp, CanonSink};

pub(super) type V2 = (f64, f64);

pub(super) fn sub(a: V2, b: V2) -> V2 {
    (a.0 - b.0, a.1 - b.1)
}

pub(super) fn add(a: V2, b: V2) -> V2 {
    (a.0 + b.0, a.1 + b.1)
}

pub(super) fn scale(a: V2, k: f64) -> V2 {
    (a.0 * k, a.1 * k)
}

pub(super) fn len(a: V2) -> f64 {
    a.0.hypot(a.1)
}

pub(super) fn unit(a: V2) -> V2 {
    let l = len(a);
    if l < 1e-12 { (0.0, 0.0) } else { scale(a, 1.0 / l) }
}

pub(super) fn cross(a: V2, b: V2) -> f64 {
    a.0 * b.1 - a.1 * b.0
}

fn dot(a: V2, b: V2) -> f64 {
    a.0 * b.0 + a.1 * b.1
}

/// The smallest turn between two moves, radians, that makes a corner (rs274's tolerance).
const SMALL_TURN: f64 = 0.05;

/// Which side of the path the tool runs on.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Side {
    /// G41.
    Left,
    /// G42.
    Right,
}

/// One offset element: a line or an arc about a centre (with its offset radius).
#[derive(Clone, Copy, Debug)]
enum Shape {
    Line,
    /// The offset circle's radius, from the arc's end point (rs274 measures an arc's radius
    /// there; its start point moves along its own radius).
    Arc {
        centre: V2,
        end_radius: f64,
    },
}

/// A move offset by the radius: its shape, its directions of travel at its start and at its
/// end, and its offset start and end points.
#[derive(Clone, Copy, Debug)]
struct Offset {
    shape: Shape,
    t_start: V2,
    t_end: V2,
    start: V2,
    end: V2,
}

/// The held-back move: its op (end still adjustable), shape, programmed end and the
/// directions of travel at its end.
#[derive(Clone, Debug)]
struct Held {
    canon: Canon,
    shape: Shape,
    /// Offset start (for line intersections).
    start: V2,
    /// Programmed end point (the corner with the next move).
    corner: V2,
    /// Direction of travel at the end.
    tangent: V2,
}

/// Why a corner or move could not be compensated.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum CompProblem {
    /// The tool is larger than an inside arc.
    Gouge,
    /// Two offset elements of an inside corner do not meet.
    NoIntersection,
    /// Compensation cannot start with an arc.
    ArcEntry,
}

/// Compensation state for one run.
#[derive(Clone, Debug)]
pub(super) struct Comp {
    side: Side,
    radius: f64,
    /// The plane's first, second and normal axes (positions in a straight move's array).
    axes: (usize, usize, usize),
    /// Where the controlled point is from the nose's centre, in the plane's axes.
    tip: V2,
    /// Whether the next XY move is the one that turns compensation on.
    entry: bool,
    held: Option<Held>,
    /// Ops that came after the held move.
    queue: Vec<Canon>,
    /// Last programmed XY point (the control point) and the tool's XY point.
    programmed: V2,
    tool: V2,
}

impl Comp {
    /// Whether the tool is kept to the left of the path (G41).
    pub(super) fn left(&self) -> bool {
        self.side == Side::Left
    }
}

impl Comp {
    /// Compensation starting at programmed (and tool) point `at`, in the plane of `axes`,
    /// with the controlled point `tip` from the nose's centre.
    pub(super) fn new(side: Side, radius: f64, axes: (usize, usize, usize), tip: V2, at: V2) -> Comp {
        Comp { side, radius, axes, tip, entry: true, held: None, queue: Vec::new(), programmed: at, tool: sub(at, tip) }
    }

    fn end_of(&self, op: &CanonOp) -> Option<V2> {
        match op {
            CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) => Some((p[self.axes.0], p[self.axes.1])),
            CanonOp::ArcFeed { first_end, second_end, .. } => Some((*first_end, *second_end)),
            _ => None,
        }
    }

    fn set_end(&self, op: &mut CanonOp, at: V2) {
        match op {
            CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) => (p[self.axes.0], p[self.axes.1]) = at,
            CanonOp::ArcFeed { first_end, second_end, .. } => (*first_end, *second_end) = at,
            _ => {}
        }
    }

    /// Sends an op on, its points moved from the nose's centre to the controlled point.
    fn out(&self, mut canon: Canon, sink: &mut dyn CanonSink) {
        if self.tip != (0.0, 0.0) {
            if let Some(end) = self.end_of(&canon.op) {
                self.set_end(&mut canon.op, add(end, self.tip));
            }
            if let CanonOp::ArcFeed { first_axis, second_axis, .. } = &mut canon.op {
                (*first_axis, *second_axis) = add((*first_axis, *second_axis), self.tip);
            }
        }
        sink.emit(canon);
    }

    /// Whether compensation runs to this side with this radius already (a repeated `RL`).
    pub(super) fn runs(&self, side: Side, radius: f64) -> bool {
        self.side == side && (self.radius - radius).abs() < 1e-12
    }

    fn normal(&self, t: V2) -> V2 {
        match self.side {
            Side::Left => (-t.1, t.0),
            Side::Right => (t.1, -t.0),
        }
    }

    /// Takes one op while compensation is on; emits what is settled.
    pub(super) fn push(&mut self, canon: Canon, sink: &mut dyn CanonSink) -> Result<(), CompProblem> {
        let Some(end) = self.end_of(&canon.op) else {
            self.hold_or_emit(canon, sink);
            return Ok(());
        };
        let start = self.programmed;
        if len(sub(end, start)) < 1e-12 && !matches!(canon.op, CanonOp::ArcFeed { .. }) {
            // No XY motion (a Z move): it keeps the tool's XY, which the corner may still move.
            let mut canon = canon;
            self.set_end(&mut canon.op, self.tool);
            self.hold_or_emit(canon, sink);
            return Ok(());
        }
        let offset = self.offset(&canon.op, start, end)?;
        if self.entry {
            return self.enter(canon, offset, end, sink);
        }
        let (corner_arc, new_start) = self.corner(offset, matches!(canon.op, CanonOp::StraightTraverse(_)))?;
        let mut canon = canon;
        let queued = std::mem::take(&mut self.queue);
        if let Some(h) = self.held.take() {
            self.out(h.canon, sink);
        }
        for q in queued {
            self.out(q, sink);
        }
        if let Some(op) = corner_arc {
            self.out(Canon { op, origin: canon.origin, line: canon.line }, sink);
        }
        self.set_end(&mut canon.op, offset.end);
        self.held = Some(Held { canon, shape: offset.shape, start: new_start, corner: end, tangent: offset.t_end });
        self.programmed = end;
        self.tool = offset.end;
        Ok(())
    }

    /// The move `op` from programmed `start` to `end`, offset by the radius to the side.
    fn offset(&self, op: &CanonOp, start: V2, end: V2) -> Result<Offset, CompProblem> {
        match *op {
            CanonOp::ArcFeed { first_axis, second_axis, rotation, .. } => {
                let centre = (first_axis, second_axis);
                let ccw = rotation > 0;
                let radial = |p: V2| unit(sub(p, centre));
                let tangent = |p: V2| {
                    let u = radial(p);
                    if ccw { (-u.1, u.0) } else { (u.1, -u.0) }
                };
                // Left of a counter-clockwise arc is inside. Each end moves along its own
                // radius (a programmed arc's ends may lie at slightly different distances
                // from its centre), as rs274 moves them.
                let inside = (self.side == Side::Left) == ccw;
                let offset = |p: V2| {
                    let r = len(sub(p, centre));
                    if inside { r - self.radius } else { r + self.radius }
                };
                let (r0, r1) = (offset(start), offset(end));
                if r0.min(r1) <= 1e-9 {
                    return Err(CompProblem::Gouge);
                }
                Ok(Offset {
                    shape: Shape::Arc { centre, end_radius: r1 },
                    t_start: tangent(start),
                    t_end: tangent(end),
                    start: add(centre, scale(radial(start), r0)),
                    end: add(centre, scale(radial(end), r1)),
                })
            }
            _ => {
                let t = unit(sub(end, start));
                let n = scale(self.normal(t), self.radius);
                Ok(Offset { shape: Shape::Line, t_start: t, t_end: t, start: add(start, n), end: add(end, n) })
            }
        }
    }

    /// The move that turns compensation on (to programmed `end`): straight to the offset end
    /// point. It cannot be an arc.
    fn enter(&mut self, mut canon: Canon, offset: Offset, end: V2, sink: &mut dyn CanonSink) -> Result<(), CompProblem> {
        if let CanonOp::ArcFeed { .. } = canon.op {
            return Err(CompProblem::ArcEntry);
        }
        self.entry = false;
        self.set_end(&mut canon.op, offset.end);
        self.release(sink);
        // For the corner with the next move, the entry counts as its programmed line offset
        // whole (LinuxCNC trims along that parallel, not along the actual approach).
        self.held = Some(Held { canon, shape: Shape::Line, start: offset.start, corner: end, tangent: offset.t_end });
        self.programmed = end;
        self.tool = offset.end;
        Ok(())
    }

    /// The corner between the held move and the next one (`offset`, a rapid when `rapid`):
    /// an arc about the programmed corner (a rapid before a rapid) where it is outside, the
    /// held move trimmed to where the two meet where it is inside, nothing for a turn too
    /// small. Returns the corner's op, if any, and where the next move starts.
    fn corner(&mut self, offset: Offset, rapid: bool) -> Result<(Option<CanonOp>, V2), CompProblem> {
        let Offset { shape, t_start, start: off_start, end: off_end, .. } = offset;
        let mut corner_arc = None;
        let mut new_start = off_start;
        if let Some(h) = &mut self.held {
            let a = self.tool;
            // A corner that turns by less than rs274's 0.05 radian gets neither an arc nor a
            // trim: the next move starts where the tool is.
            let turn_angle = cross(h.tangent, t_start).atan2(dot(h.tangent, t_start));
            if len(sub(a, off_start)) > 1e-9 && turn_angle.abs() > SMALL_TURN {
                let turn = cross(h.tangent, t_start);
                // Back the way it came: the corner is inside where the two offset elements
                // meet (an arc's offset circle and the way back), else outside, as rs274
                // takes it.
                let reversal = turn.abs() < 1e-12 && dot(h.tangent, t_start) < 0.0;
                // Of two meeting points, the one the new move heads for.
                let meet = if reversal { intersect(h.shape, h.start, a, shape, off_start, off_end, h.corner, Some(t_start)) } else { None };
                let convex = match self.side {
                    _ if reversal => meet.is_none(),
                    Side::Left => turn < 0.0,
                    Side::Right => turn > 0.0,
                };
                if convex && rapid {
                    // Before a rapid the corner is a rapid too, straight to the arc's end.
                    let mut p = [0.0; 6];
                    (p[self.axes.0], p[self.axes.1], p[self.axes.2]) = (off_start.0, off_start.1, axis_of(&h.canon.op, self.axes.2));
                    p[3..].copy_from_slice(&abc_of(&h.canon.op));
                    corner_arc = Some(CanonOp::StraightTraverse(p));
                } else if convex {
                    corner_arc = Some(CanonOp::ArcFeed {
                        first_end: off_start.0,
                        second_end: off_start.1,
                        first_axis: h.corner.0,
                        second_axis: h.corner.1,
                        rotation: if self.side == Side::Left { -1 } else { 1 },
                        axis_end: axis_of(&h.canon.op, self.axes.2),
                        abc: abc_of(&h.canon.op),
                    });
                } else {
                    let x = meet
                        .or_else(|| intersect(h.shape, h.start, a, shape, off_start, off_end, h.corner, None))
                        .ok_or(CompProblem::NoIntersection)?;
                    let mut held = h.canon.op.clone();
                    self.set_end(&mut held, x);
                    let mut queue = std::mem::take(&mut self.queue);
                    // Z moves queued behind the held move follow its end.
                    for q in &mut queue {
                        if self.end_of(&q.op).is_some() {
                            self.set_end(&mut q.op, x);
                        }
                    }
                    self.queue = queue;
                    if let Some(h) = &mut self.held {
                        h.canon.op = held;
                    }
                    self.tool = x;
                    new_start = x;
                }
            }
        }
        Ok((corner_arc, new_start))
    }

    fn hold_or_emit(&mut self, canon: Canon, sink: &mut dyn CanonSink) {
        if self.held.is_some() {
            self.queue.push(canon);
        } else {
            self.out(canon, sink);
        }
    }

    fn release(&mut self, sink: &mut dyn CanonSink) {
        if let Some(h) = self.held.take() {
            self.out(h.canon, sink);
        }
        for q in std::mem::take(&mut self.queue) {
            self.out(q, sink);
        }
    }

    /// Compensation ends (G40, program end): everything held goes out. Returns the
    /// controlled point in the plane.
    pub(super) fn finish(mut self, sink: &mut dyn CanonSink) -> V2 {
        self.release(sink);
        add(self.tool, self.tip)
    }
}

fn axis_of(op: &CanonOp, normal: usize) -> f64 {
    match op {
        CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) => p[normal],
        CanonOp::ArcFeed { axis_end, .. } => *axis_end,
        _ => 0.0,
    }
}

fn abc_of(op: &CanonOp) -> [f64; 3] {
    match op {
        CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) => [p[3], p[4], p[5]],
        CanonOp::ArcFeed { abc, .. } => *abc,
        _ => [0.0; 3],
    }
}

/// The meeting point of two offset elements nearest to the programmed corner, or the one
/// furthest from it along `ahead`.
#[allow(clippy::too_many_arguments)]
fn intersect(a: Shape, a_start: V2, a_end: V2, b: Shape, b_start: V2, b_end: V2, corner: V2, ahead: Option<V2>) -> Option<V2> {
    let candidates: Vec<V2> = match (a, b) {
        (Shape::Line, Shape::Line) => {
            let (d1, d2) = (sub(a_end, a_start), sub(b_end, b_start));
            let den = cross(d1, d2);
            if den.abs() < 1e-12 {
                return None;
            }
            let t = cross(sub(b_start, a_start), d2) / den;
            vec![add(a_start, scale(d1, t))]
        }
        (Shape::Line, Shape::Arc { centre, end_radius, .. }) => line_circle(a_start, a_end, centre, end_radius),
        (Shape::Arc { centre, end_radius, .. }, Shape::Line) => line_circle(b_start, b_end, centre, end_radius),
        (Shape::Arc { centre: c1, end_radius: r1, .. }, Shape::Arc { centre: c2, end_radius: r2, .. }) => circle_circle(c1, r1, c2, r2),
    };
    match ahead {
        Some(d) => candidates.into_iter().max_by(|p, q| dot(sub(*p, corner), d).total_cmp(&dot(sub(*q, corner), d))),
        None => candidates.into_iter().min_by(|p, q| len(sub(*p, corner)).total_cmp(&len(sub(*q, corner)))),
    }
}

fn line_circle(p: V2, q: V2, c: V2, r: f64) -> Vec<V2> {
    let d = unit(sub(q, p));
    let f = sub(p, c);
    let b = dot(f, d);
    let disc = b * b - (dot(f, f) - r * r);
    if disc < -1e-12 {
        return Vec::new();
    }
    let s = disc.max(0.0).sqrt();
    vec![add(p, scale(d, -b - s)), add(p, scale(d, -b + s))]
}

fn circle_circle(c1: V2, r1: f64, c2: V2, r2: f64) -> Vec<V2> {
    let d = len(sub(c2, c1));
    if d < 1e-12 || d > r1 + r2 + 1e-12 || d < (r1 - r2).abs() - 1e-12 {
        return Vec::new();
    }
    let a = (r1 * r1 - r2 * r2 + d * d) / (2.0 * d);
    let h = (r1 * r1 - a * a).max(0.0).sqrt();
    let u = unit(sub(c2, c1));
    let m = add(c1, scale(u, a));
    let n = (-u.1, u.0);
    vec![add(m, scale(n, h)), add(m, scale(n, -h))]
}

/// Where a lathe tool's controlled point (its imaginary tip) is from the nose's centre, for
/// orientation `orientation` (1 to 9), in nose radii along X and Z: 1 to 4 the corners,
/// 5 to 8 the sides, 0 and 9 the centre itself. Read from rs274's output for each.
pub(super) fn tip_offset(orientation: u32) -> (f64, f64) {
    match orientation {
        1 => (-1.0, 1.0),
        2 => (-1.0, -1.0),
        3 => (1.0, -1.0),
        4 => (1.0, 1.0),
        5 => (0.0, 1.0),
        6 => (-1.0, 0.0),
        7 => (0.0, -1.0),
        8 => (1.0, 0.0),
        _ => (0.0, 0.0),
    }
}

//! Corners between two straight moves in the working plane, written as blocks of their own
//! (Heidenhain `RND R5`, `CHF 2`) or as words on the first move (Siemens `RND=5`, `CHR=2`,
//! `CHF=2`; Fanuc `,R5`, `,C2`): rounded or chamfered; and approaches to a contour in the XY
//! plane that follow its first element (`APPR LT`, `APPR LN`).
//!
//! The corner block stands between the two moves, so the first move cannot go out until the
//! second is known. Where the dialect has corner blocks, the last straight feed is held back
//! here, with the ops that follow it (a feed change on the corner block), until the next move
//! arrives. A marked corner then shortens the held move to the first tangent point, adds the
//! arc or chamfer from the corner block, and the next move starts at the second tangent
//! point. Memory stays bounded: one move and the ops of about one block.

use super::comp::{V2, add, cross, len, scale, sub, unit};
use crate::canon::{Canon, CanonOp, Plane};
use crate::text::TextRange;

/// What a corner block asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Corner {
    /// An arc of this radius, tangent to both moves.
    Round(f64),
    /// A straight cut this far back from the corner along each move (Siemens `CHR=`,
    /// Fanuc `,C`, Heidenhain `CHF`).
    Chamfer(f64),
    /// A straight cut this long itself, cutting back equally along each move (Siemens `CHF=`).
    ChamferLength(f64),
}

/// An approach to a contour point, waiting for the contour's first element to know its direction.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Approach {
    /// Perpendicular to the first element (`APPR LN`) rather than along it (`APPR LT`).
    pub normal: bool,
    /// Distance of the auxiliary point from the contour point.
    pub len: f64,
    /// The side of the radius compensation (left for `RL`): where a perpendicular approach comes from.
    pub left: bool,
    /// Where the tool is, and the contour point.
    pub from: [f64; 6],
    pub to: [f64; 6],
    pub origin: TextRange,
    pub line: u32,
}

/// Why a corner was left sharp.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum CornerProblem {
    /// The corner block does not follow a straight feed move.
    NoMoveBefore,
    /// The corner block is not followed by a straight feed move (an arc, a rapid, the end).
    NoMoveAfter,
    /// A move of the corner leaves the working plane.
    NotPlanar,
    /// The arc or chamfer is longer than one of the moves.
    TooLarge,
    /// An approach is not followed by a contour element in the XY plane.
    NoContourAfterApproach,
    /// An arc is on one side of the corner: the control rounds or chamfers it (Siemens,
    /// Fanuc and Heidenhain document line and arc elements in any combination), but the
    /// element is not computed here.
    ArcNeighbour,
}

impl CornerProblem {
    /// Whether the control makes the corner and only the analysis does not (a warning, not
    /// an error).
    pub(super) fn only_unmodelled(self) -> bool {
        self == CornerProblem::ArcNeighbour
    }

    pub(super) fn describe(self) -> &'static str {
        match self {
            CornerProblem::NoMoveBefore => "it must follow a straight feed move in the XY plane",
            CornerProblem::NoMoveAfter => "it must be followed by a straight feed move in the XY plane",
            CornerProblem::NotPlanar => "rounding and chamfers are computed for corners in the working plane only",
            CornerProblem::TooLarge => "it does not fit: it is longer than one of the moves beside the corner",
            CornerProblem::ArcNeighbour => {
                "the control rounds or chamfers a corner next to an arc too, but that element is not computed here: the toolpath keeps the sharp corner"
            }
            CornerProblem::NoContourAfterApproach => {
                "the approach is not followed by a contour element in the XY plane; the tool went straight to the contour point"
            }
        }
    }
}

/// A straight feed the stage holds: where it starts and ends, and its block's range and line.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Held {
    pub from: [f64; 6],
    pub to: [f64; 6],
    pub origin: TextRange,
    pub line: u32,
}

impl Held {
    /// The move as its op.
    fn canon(&self) -> Canon {
        Canon { op: CanonOp::StraightFeed(self.to), origin: self.origin, line: self.line }
    }
}

/// The corner stage between the interpreter and cutter compensation.
#[derive(Default)]
pub(super) struct Corners {
    /// Where the tool is after the last move seen, when known.
    pos: Option<[f64; 6]>,
    /// The held straight feed, then the ops that followed it.
    held: Option<Held>,
    after: Vec<Canon>,
    /// A corner block waiting for the next move: what, and its block's range and line.
    pending: Option<(Corner, TextRange, u32)>,
    /// Whether the pending corner is a modal rounding's (`RNDM`), made only where it falls
    /// between two straight feeds in the plane and silently left out elsewhere.
    pending_modal: bool,
    /// An approach waiting for the contour's first element.
    approach: Option<Approach>,
    /// Ops settled and ready to go on, in order.
    pub(super) released: Vec<Canon>,
    /// The last corner that could not be made.
    pub(super) problem: Option<CornerProblem>,
    /// The working plane the last `SELECT_PLANE` chose (`None`: XY, where runs start).
    plane: Option<Plane>,
    /// Whether the last move was an arc feed (a corner after it has an arc beside it).
    after_arc: bool,
    /// Whether the control makes a corner too large for a move beside it smaller, to fit
    /// (the dialect's `corner-too-large="reduced"`), rather than refusing it.
    reduce: bool,
}

impl Corners {
    /// A stage opened in the middle of a run (at the first corner word): the tool is at `pos`
    /// (as the canonical calls have it) in `plane`.
    pub(super) fn starting_at(plane: Plane, pos: [f64; 6]) -> Corners {
        Corners { pos: Some(pos), plane: Some(plane), ..Corners::default() }
    }

    /// The stage, making corners too large for their moves smaller where `reduce`.
    pub(super) fn reducing(self, reduce: bool) -> Corners {
        Corners { reduce, ..self }
    }

    /// A corner block: the corner at the end of the held move is to be rounded or chamfered.
    ///
    /// A `modal` corner (`RNDM`) is only made between two straight feeds in the plane: the
    /// 840D inserts no rounding where the path leaves the plane or a rapid follows, and
    /// raises no alarm (840D sl programming manual, fundamentals, "Chamfer, rounding": modal
    /// rounding is inserted "at all following contour corners"; a corner with a rapid or an
    /// infeed beside it is none), so there it is left out without a finding.
    pub(super) fn mark(&mut self, corner: Corner, origin: TextRange, line: u32, modal: bool) {
        if self.held.is_none() || self.pending.is_some() {
            let arc = self.held.is_none() && self.pending.is_none() && self.after_arc;
            if arc {
                self.problem = Some(CornerProblem::ArcNeighbour);
            } else {
                self.fail(CornerProblem::NoMoveBefore, modal);
            }
            return;
        }
        self.pending = Some((corner, origin, line));
        self.pending_modal = modal;
    }

    /// Corner `p` cannot be made: a finding, but for a modal rounding's corner off the plane
    /// or without a straight feed on both sides, which the control silently leaves out.
    fn fail(&mut self, p: CornerProblem, modal: bool) {
        let skipped = modal && matches!(p, CornerProblem::NoMoveBefore | CornerProblem::NoMoveAfter | CornerProblem::NotPlanar);
        if !skipped {
            self.problem = Some(p);
        }
    }

    /// An approach block: its moves go out when the first contour element arrives.
    pub(super) fn approach(&mut self, a: Approach) {
        self.moved_otherwise();
        self.approach = Some(a);
        self.pos = Some(a.to);
    }

    /// Takes one op; what is settled goes to [`Corners::released`].
    pub(super) fn push(&mut self, canon: Canon) {
        if let Some(a) = self.approach {
            // Non-moving ops of the next block wait; a move settles the approach.
            match canon.op {
                CanonOp::StraightFeed(end) => self.make_approach(a, Some((end[0] - a.to[0], end[1] - a.to[1]))),
                CanonOp::ArcFeed { first_axis, second_axis, rotation, .. } => {
                    let r = (a.to[0] - first_axis, a.to[1] - second_axis);
                    let along = if rotation > 0 { (-r.1, r.0) } else { (r.1, -r.0) };
                    self.make_approach(a, Some(along));
                }
                CanonOp::StraightTraverse(_) | CanonOp::SelectPlane(_) | CanonOp::SetG5xOffset(..) | CanonOp::SetG92Offset(_) => {
                    self.make_approach(a, None)
                }
                _ => {
                    self.after.push(canon);
                    return;
                }
            }
        }
        self.after_arc = match canon.op {
            CanonOp::ArcFeed { .. } => true,
            CanonOp::StraightFeed(_) | CanonOp::StraightTraverse(_) | CanonOp::SelectPlane(_) => false,
            _ => self.after_arc,
        };
        match canon.op {
            CanonOp::StraightFeed(end) => {
                let start = self.pos.unwrap_or(end);
                if let Some((corner, origin, line)) = self.pending.take() {
                    let modal = std::mem::take(&mut self.pending_modal);
                    self.make_corner(corner, (origin, line, modal), start, end);
                } else {
                    self.release_held();
                }
                // The move starts where the corner left the tool (its second tangent point).
                let from = self.pos.unwrap_or(start);
                self.held = Some(Held { from, to: end, origin: canon.origin, line: canon.line });
                self.pos = Some(end);
            }
            CanonOp::StraightTraverse(p) => {
                self.moved_otherwise();
                self.pos = Some(p);
                self.released.push(canon);
            }
            CanonOp::ArcFeed { first_end, second_end, axis_end, abc, .. } => {
                if self.pending.take().is_some() {
                    // A line, the corner, then an arc.
                    self.pending_modal = false;
                    self.problem = Some(CornerProblem::ArcNeighbour);
                }
                self.moved_otherwise();
                let (a0, a1, n) = self.axes();
                let mut end = [0.0, 0.0, 0.0, abc[0], abc[1], abc[2]];
                (end[a0], end[a1], end[n]) = (first_end, second_end, axis_end);
                self.pos = Some(end);
                self.released.push(canon);
            }
            CanonOp::SelectPlane(plane) => {
                self.moved_otherwise();
                self.pos = None;
                self.plane = Some(plane);
                self.released.push(canon);
            }
            CanonOp::SetG5xOffset(..) | CanonOp::SetG92Offset(_) | CanonOp::UseToolLengthOffset(_) => {
                // The coordinates change meaning: nothing held may span the change.
                self.moved_otherwise();
                self.pos = None;
                self.released.push(canon);
            }
            _ if self.held.is_some() => self.after.push(canon),
            _ => self.released.push(canon),
        }
    }

    /// A straight move (a traverse when `rapid`) to `to` from the block at `origin`, `line`,
    /// taken as [`Corners::push`] takes its op where nothing waits but perhaps a held move (no
    /// corner block, no approach, no op behind the held move or settled and not yet sent on):
    /// the held move, which goes out now, is returned (a traverse goes out after it, and a
    /// feed is held in its place). `None`, with nothing changed, where something waits: the
    /// op then goes [`Corners::push`]'s way. The same ops in the same order, without an op
    /// made and moved through the stage's lists for every move.
    #[inline(always)]
    pub(super) fn pass_straight(&mut self, rapid: bool, to: [f64; 6], origin: TextRange, line: u32) -> Option<Option<Held>> {
        if self.approach.is_some() || self.pending.is_some() || !self.after.is_empty() || !self.released.is_empty() {
            return None;
        }
        let out = self.held.take();
        if !rapid {
            // Nothing pending: the move starts where the last one left the tool.
            self.held = Some(Held { from: self.pos.unwrap_or(to), to, origin, line });
        }
        self.pos = Some(to);
        self.after_arc = false;
        Some(out)
    }

    /// The end of the run (or of the stage): everything held goes out.
    pub(super) fn finish(&mut self) {
        if let Some(a) = self.approach {
            self.make_approach(a, None);
        }
        self.moved_otherwise();
    }

    /// The approach's moves, now that the first contour element leaves the contour point in
    /// direction `along` (`None`: no element; straight to the contour point).
    fn make_approach(&mut self, a: Approach, along: Option<V2>) {
        self.approach = None;
        let at = |p: V2, z: &[f64; 6]| [p.0, p.1, z[2], z[3], z[4], z[5]];
        let to = (a.to[0], a.to[1]);
        match along.map(unit).filter(|t| len(*t) > 0.5) {
            Some(t) => {
                let aux = if a.normal {
                    let n = if a.left { (-t.1, t.0) } else { (t.1, -t.0) };
                    add(to, scale(n, a.len))
                } else {
                    sub(to, scale(t, a.len))
                };
                // To the auxiliary point at the height the tool is at, then onto the contour.
                self.released.push(Canon { op: CanonOp::StraightFeed(at(aux, &a.from)), origin: a.origin, line: a.line });
            }
            None => self.problem = Some(CornerProblem::NoContourAfterApproach),
        }
        self.released.push(Canon { op: CanonOp::StraightFeed(a.to), origin: a.origin, line: a.line });
        self.released.append(&mut self.after);
    }

    fn moved_otherwise(&mut self) {
        if self.pending.take().is_some() {
            let modal = std::mem::take(&mut self.pending_modal);
            self.fail(CornerProblem::NoMoveAfter, modal);
        }
        self.release_held();
    }

    fn release_held(&mut self) {
        if let Some(h) = self.held.take() {
            self.released.push(h.canon());
        }
        self.released.append(&mut self.after);
    }

    /// The working plane's axes: first, second, normal (as `ARC_FEED` orders them).
    fn axes(&self) -> (usize, usize, usize) {
        self.plane.unwrap_or(Plane::Xy).axes()
    }

    /// Resolves the corner between the held move (ending at the corner) and the move to `end`,
    /// in the working plane's (first, second) coordinates.
    /// `block`: the corner block's range and line, and whether its corner is a modal rounding's.
    fn make_corner(&mut self, corner: Corner, block: (TextRange, u32, bool), at: [f64; 6], end: [f64; 6]) {
        let (origin, line, modal) = block;
        let Some(first) = self.held.take() else { return };
        let from = first.from;
        let (a0, a1, n) = self.axes();
        let planar = from[n] == at[n] && end[n] == at[n] && from[3..] == at[3..] && end[3..] == at[3..];
        let (s, c, e): (V2, V2, V2) = ((from[a0], from[a1]), (at[a0], at[a1]), (end[a0], end[a1]));
        let put = |p: V2| {
            let mut q = at;
            (q[a0], q[a1]) = p;
            q
        };
        let (d1, d2) = (unit(sub(c, s)), unit(sub(e, c)));
        let turn = cross(d1, d2);
        let cos = d1.0 * d2.0 + d1.1 * d2.1;
        if !planar {
            self.fail(CornerProblem::NotPlanar, modal);
        }
        // Along each move, how far from the corner the new element starts and ends.
        let mut back = match corner {
            Corner::Chamfer(l) => l,
            // Equal legs l under a chord c: c = 2·l·cos(θ/2), θ the turn between the moves.
            Corner::ChamferLength(c) => c / (2.0 * (1.0 + cos)).max(1e-24).sqrt(),
            Corner::Round(r) => r * ((1.0 - cos) / (1.0 + cos).max(1e-12)).sqrt(), // r·tan(θ/2)
        };
        let room = len(sub(c, s)).min(len(sub(e, c)));
        let mut corner = corner;
        if back > room + 1e-9 && self.reduce && planar {
            // Made smaller to fit the shorter move (SINUMERIK: "the programmed value for
            // chamfer and rounding is automatically reduced if the contour length of an
            // involved block is insufficient"); how much the control takes off where one short
            // move has a corner at each end is not documented: here the first takes its share.
            let k = room / back;
            back = room;
            corner = match corner {
                Corner::Round(r) => Corner::Round(r * k),
                other => other,
            };
        }
        let fits = back <= room + 1e-9;
        if !fits {
            self.problem = Some(CornerProblem::TooLarge);
        }
        if !planar || !fits || turn.abs() < 1e-12 || back <= 0.0 {
            // A straight continuation has no corner to make; the others were reported.
            self.held = Some(first);
            self.release_held();
            return;
        }
        let t1 = sub(c, scale(d1, back));
        let t2 = add(c, scale(d2, back));
        self.released.push(Held { to: put(t1), ..first }.canon());
        self.released.append(&mut self.after);
        let op = match corner {
            Corner::Chamfer(_) | Corner::ChamferLength(_) => CanonOp::StraightFeed(put(t2)),
            Corner::Round(r) => {
                // The centre lies inside the turn, a radius from the first tangent point.
                let side = turn.signum();
                let centre = add(t1, scale((-d1.1, d1.0), side * r));
                CanonOp::ArcFeed {
                    first_end: t2.0,
                    second_end: t2.1,
                    first_axis: centre.0,
                    second_axis: centre.1,
                    rotation: if side > 0.0 { 1 } else { -1 },
                    axis_end: at[n],
                    abc: [at[3], at[4], at[5]],
                }
            }
        };
        self.released.push(Canon { op, origin, line });
        self.pos = Some(put(t2));
    }
}

//! What a lathe program's moves show of its machine where no arc tells: X words written as
//! radii. CAM posts and turners cut chamfers at 45° and pull off each pass at 45°; written as
//! a radius, such a move changes X by as much as Z, written as a diameter by twice as much.
//! Read as diameters (the lathe dictionary's start), the moves of a program written for a
//! machine set to radius programming come out at half that slope: the 45° moves change X by
//! half of Z. Where many moves have that slope and nearly none the slope of a 45° move
//! written as a diameter, and no arc's centre could tell otherwise, the program is written
//! for radius programming (the same finding as arcs whose centres fit only so).
//!
//! The tally is a [`CanonSink`]: it sees the ops as the interpreter emits them, beside the sink
//! that keeps them ([`Tee`]).

use crate::canon::{Canon, CanonOp, CanonSink, Setting};
use crate::diag::{Code, Diagnostic};
use crate::text::TextRange;

/// At least this many moves must have the radius-written slope.
const MIN_VOTES: u32 = 10;
/// And at most one in this many the diameter-written one (a radius program has some moves
/// at that slope too: approaches, 63° flanks).
const RATIO: u32 = 5;

/// The slopes of a lathe program's straight feed moves in diameter mode, outside cycles.
#[derive(Debug, Default)]
pub struct RadiusVotes {
    diameter: bool,
    in_cycle: bool,
    pos: Option<[f64; 3]>,
    /// Moves whose X changes by half their Z (45° written as a radius, read as a diameter).
    radius: u32,
    /// Moves whose X changes by as much as their Z (45° written as a diameter).
    diameter_votes: u32,
    /// Arcs in diameter mode: their centres tell the reading (the interpreter weighs them).
    arcs: u32,
}

impl RadiusVotes {
    /// Takes one op.
    pub fn see(&mut self, c: &Canon) {
        match &c.op {
            CanonOp::Setting(Setting::DiameterMode(on)) => self.diameter = *on,
            CanonOp::CycleBegin(_) | CanonOp::Turning(_) => self.in_cycle = true,
            CanonOp::CycleEnd | CanonOp::TurningEnd => self.in_cycle = false,
            CanonOp::StraightTraverse(p) => self.pos = Some([p[0], p[1], p[2]]),
            CanonOp::StraightFeed(p) => {
                let to = [p[0], p[1], p[2]];
                if let Some(from) = self.pos
                    && self.diameter
                    && !self.in_cycle
                {
                    self.weigh(from, to);
                }
                self.pos = Some(to);
            }
            CanonOp::ArcFeed { .. } => {
                self.arcs += u32::from(self.diameter);
                self.pos = None;
            }
            _ => {}
        }
    }

    fn weigh(&mut self, from: [f64; 3], to: [f64; 3]) {
        let (dx, dy, dz) = ((to[0] - from[0]).abs(), (to[1] - from[1]).abs(), (to[2] - from[2]).abs());
        if dy > 1e-9 || dz < 0.005 || dx < 0.002 {
            return;
        }
        // Within 2 % and the words' last digit (0.001, as read in either unit).
        let tol = 0.02 * dz + 0.0015;
        if (2.0 * dx - dz).abs() <= tol {
            self.radius += 1;
        } else if (dx - dz).abs() <= tol {
            self.diameter_votes += 1;
        }
    }

    /// The finding that the X words are radii, where the moves show it and nothing else has
    /// (`x_radius`: the machine is known or found to be so already).
    pub fn finding(&self, x_radius: bool) -> Option<Diagnostic> {
        let shown = self.arcs == 0 && self.radius >= MIN_VOTES && self.diameter_votes * RATIO <= self.radius;
        (!x_radius && shown).then(|| {
            let msg = format!(
                "{} moves change X by half as much as Z and {} by as much (no arc to tell): the 45° chamfers and pull-offs are written with X as a radius; the program is written for a machine set to radius programming, and is read so",
                self.radius, self.diameter_votes
            );
            Diagnostic::new(Code::XWordsRadius, TextRange::default(), msg)
        })
    }
}

impl CanonSink for RadiusVotes {
    fn emit(&mut self, canon: Canon) {
        self.see(&canon);
    }

    fn kept_bytes(&self, _: u64) -> u64 {
        0
    }
}

/// A sink that tallies the ops it passes on.
pub struct Tee<'a, S: CanonSink + ?Sized> {
    /// The sink the ops go to.
    pub sink: &'a mut S,
    /// The tally.
    pub votes: &'a mut RadiusVotes,
}

impl<S: CanonSink + ?Sized> CanonSink for Tee<'_, S> {
    fn emit(&mut self, canon: Canon) {
        self.votes.see(&canon);
        self.sink.emit(canon);
    }

    fn kept_bytes(&self, moves: u64) -> u64 {
        self.sink.kept_bytes(moves)
    }
}

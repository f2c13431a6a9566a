//! Proof by motion: two canonical call streams (a program and its translation, each read in
//! its own dialect) compared as the machine would run them. Every move is compared in the
//! frame it runs in: the work offset the program stated (or the one the machine had, where it
//! stated none), the G92 shift, and the moves that go to a position in the machine's own frame
//! (a reference return, a move in machine coordinates) as those, not as the numbers the
//! analysis gives them with its offsets at zero. With each move: the tool axis (turned under
//! tool centre point control, or stated). With each cutting move: the tool, the feed,
//! the spindle's turning and speed, its mode (revolutions, or constant surface speed with the
//! same clamp: the speed is then a cutting speed, compared in m/min, an inch program's ft/min
//! converted), and the coolant.
//!
//! The door: [`Trace`] (a [`CanonSink`] that keeps what the comparison needs of a stream, in
//! millimetres) and [`difference`], the first way one trace differs from another within a
//! tolerance, or `None`. Streamed: [`Trace::streaming`] hands its finished moves on in
//! batches, and [`Comparison`] takes the two streams as they come, holding only the moves
//! neither has yet been compared with (the translation's pieces of one arc at most ahead of
//! the program's): two interpretations compared on their own threads in bounded memory.
//!
//! Lines of reasoning kept from the translation tests, which this room now serves: an arc may
//! come back in pieces about the same centre, or on the same path within the tolerance and the
//! source's own radius difference where its centre is ill-conditioned; rapids on along the
//! line of the one before are one rapid (a writer stopping at a cycle's return level); a
//! spindle-synchronised move feeds its pitch times the speed; a rigid tap is its moves in and
//! out; values a program changes in the work offset it moved in are a shift of the machine.

use crate::canon::{Canon, CanonOp, CanonSink, Frame, MachineTarget, Plane, Setting};
use crate::text::TextRange;

/// How a move moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kind {
    /// At rapid.
    Rapid,
    /// At the feed, straight.
    Feed,
    /// Clockwise arc.
    ArcCw,
    /// Counter-clockwise arc.
    ArcCcw,
    /// To a reference position (which one), in the axes marked.
    Reference(u8),
    /// In machine coordinates, to the values given.
    Machine,
    /// To a fixed point (which one), in the axes marked.
    Fixed(u8),
    /// From the machine builder's datum, to the values given.
    Builder,
    /// To the travel limit, in the axes marked (Heidenhain `M140 MB MAX`).
    Limit,
}

impl Kind {
    fn label(self) -> &'static str {
        match self {
            Kind::Rapid => "rapid",
            Kind::Feed => "feed",
            Kind::ArcCw => "cw arc",
            Kind::ArcCcw => "ccw arc",
            Kind::Reference(_) => "reference return",
            Kind::Machine => "machine-coordinate move",
            Kind::Fixed(_) => "fixed-point approach",
            Kind::Builder => "move from the machine builder's datum",
            Kind::Limit => "retract to the travel limit",
        }
    }

    fn is_arc(self) -> bool {
        matches!(self, Kind::ArcCw | Kind::ArcCcw)
    }

    fn cuts(self) -> bool {
        matches!(self, Kind::Feed | Kind::ArcCw | Kind::ArcCcw)
    }
}

/// One move as the machine runs it, in millimetres, with the technology in force.
#[derive(Clone, Debug)]
pub struct Move {
    /// How it moves.
    pub kind: Kind,
    /// The work offset it moves in: the one the program stated, or `None` for the machine's.
    pub frame: Option<u16>,
    /// Where it starts and ends (work offset frame plus the program's shifts); for a move in
    /// the machine's frame, the machine coordinates (reference returns: 0) of the axes it
    /// moves and NaN for the others.
    pub from: [f64; 3],
    /// See [`Move::from`].
    pub to: [f64; 3],
    /// Rotary axes at the end, degrees.
    pub abc: [f64; 3],
    /// An arc's plane axes (first, second, normal), its centre and its sweep (radians).
    pub axes: (usize, usize, usize),
    /// See [`Move::axes`].
    pub centre: [f64; 3],
    /// See [`Move::axes`].
    pub sweep: f64,
    /// How far the arc's radii at start and end differ: a writer may move the centre by that
    /// much to make them agree for a stricter target.
    pub slack: f64,
    /// Feed (mm/min or per revolution as the program has it), speed (1/min), spindle
    /// direction (1, -1, 0), coolant (1 flood, 2 mist) and tool.
    pub feed: f64,
    /// See [`Move::feed`].
    pub speed: f64,
    /// See [`Move::feed`].
    pub spindle: i8,
    /// See [`Move::feed`].
    pub coolant: u8,
    /// See [`Move::feed`].
    pub tool: u32,
    /// Constant surface speed in force, with its spindle speed clamp (1/min; the canon's
    /// no-limit value where none is stated): `speed` is then the cutting speed in m/min
    /// (an inch program's ft/min converted), not revolutions.
    pub css: Option<f64>,
    /// The tilted working plane it runs on (its origin in millimetres), `None` untilted: the
    /// move's numbers are in its coordinates.
    pub tilt: Option<Frame>,
    /// The tool axis it runs with (a unit vector in the plane's coordinates; +Z but where a
    /// `ToolAxis` marker turned it: under tool centre point control, or stated).
    pub axis: [f64; 3],
    /// Seconds the machine dwells (`G4`, a cycle's dwell at the bottom) after the move
    /// before and before this one.
    pub dwell: f64,
    /// The axes whose position the program knows at the move (bit `k`: X Y Z A B C,
    /// [`CanonOp::Known`]); the others' numbers count from an assumed 0 on both sides.
    pub known: u8,
    /// The source line, and the block's range.
    pub line: u32,
    /// See [`Move::line`].
    pub origin: TextRange,
}

/// The moves of a canonical stream, made as the stream is fed in ([`CanonSink`]).
pub struct Trace {
    /// The moves so far (streaming: those not yet handed on).
    pub moves: Vec<Move>,
    /// Streaming: where full batches of finished moves go, and how many went.
    outlet: Option<Outlet>,
    handed: usize,
    /// The largest radius difference of the stream's arcs so far.
    slack: f64,
    /// How close two points must be to count as one (the rapids' merging, zero moves).
    tol: f64,
    scale: f64,
    plane: Plane,
    pos: [f64; 3],
    rot: [f64; 3],
    feed: f64,
    speed: f64,
    spindle: i8,
    coolant: u8,
    tool: u32,
    sync: Option<f64>,
    css: Option<f64>,
    /// The G92 shift and the work offset's change since first moved in (mm), and their sum.
    shifts: [[f64; 3]; 2],
    g92: [f64; 3],
    wcs: (Option<u16>, [f64; 6]),
    frames: Vec<(Option<u16>, [f64; 6])>,
    /// The points a merged rapid passes through.
    chain: Vec<[f64; 3]>,
    /// The tilted working plane in force (origin in millimetres).
    tilt: Option<Frame>,
    /// The tool axis in force.
    axis: [f64; 3],
    /// A move in the machine's frame under way: its kind, axes and how many moves it has left.
    machine: Option<(Kind, [Option<f64>; 6], usize)>,
    /// The axes whose position the program knows ([`CanonOp::Known`]; none at the start, and
    /// a machine-frame move's axes none after it).
    known: u8,
    /// The index of the move that starts where an axis just became known (`usize::MAX`:
    /// none): its start on that axis counts from an assumed number, so no rapid after it is
    /// merged into it (which would depend on that number).
    fresh: usize,
    /// Seconds dwelt since the last move: the next move's [`Move::dwell`], or, at the end,
    /// the dwell after the last move.
    dwell: f64,
    ended: bool,
    /// The range of the block being fed in.
    origin: TextRange,
}

/// Where a streaming trace hands its finished moves: a full batch in, an empty one back to
/// fill.
type Outlet = Box<dyn FnMut(Vec<Move>) -> Vec<Move>>;

/// Finished moves a streaming trace hands on at a time.
pub const BATCH: usize = 1024;

impl std::fmt::Debug for Trace {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Trace").field("moves", &self.moves).field("handed", &self.handed).finish_non_exhaustive()
    }
}

impl Trace {
    /// An empty trace; points within `tol` mm are one.
    pub fn new(tol: f64) -> Trace {
        Trace {
            moves: Vec::new(),
            outlet: None,
            handed: 0,
            slack: 0.0,
            tol,
            scale: 1.0,
            plane: Plane::Xy,
            pos: [0.0; 3],
            rot: [0.0; 3],
            feed: 0.0,
            speed: 0.0,
            spindle: 0,
            coolant: 0,
            tool: 0,
            sync: None,
            css: None,
            shifts: [[0.0; 3]; 2],
            g92: [0.0; 3],
            wcs: (None, [0.0; 6]),
            frames: Vec::new(),
            chain: Vec::new(),
            tilt: None,
            axis: [0.0, 0.0, 1.0],
            machine: None,
            known: 0,
            fresh: usize::MAX,
            dwell: 0.0,
            ended: false,
            origin: TextRange::default(),
        }
    }

    /// An empty trace that keeps no more than a batch of moves: each move is final once the
    /// next one is made (only the last may still take a rapid on along its line), and
    /// [`BATCH`] finished ones at a time go to `outlet`, which gives an empty buffer back.
    /// [`Trace::finish`] hands on the rest.
    pub fn streaming(tol: f64, outlet: impl FnMut(Vec<Move>) -> Vec<Move> + 'static) -> Trace {
        Trace { outlet: Some(Box::new(outlet)), moves: Vec::with_capacity(BATCH), ..Trace::new(tol) }
    }

    /// Hands the moves not yet handed on to the outlet (a streaming trace) and returns the
    /// seconds dwelt after the last move.
    pub fn finish(&mut self) -> f64 {
        if let Some(out) = &mut self.outlet
            && !self.moves.is_empty()
        {
            self.handed += self.moves.len();
            let full = std::mem::take(&mut self.moves);
            self.moves = out(full);
        }
        self.dwell
    }

    /// How many moves the trace has made (a streaming one: handed on or held).
    fn made(&self) -> usize {
        self.handed + self.moves.len()
    }

    /// The trace of a whole stream.
    pub fn of(canon: &[Canon], tol: f64) -> Trace {
        let mut t = Trace::new(tol);
        for c in canon {
            t.emit(c.clone());
        }
        t
    }

    /// Whether the stream was last in inches.
    pub fn in_inches(&self) -> bool {
        self.scale != 1.0
    }

    /// The largest radius difference of the stream's arcs.
    pub fn slack(&self) -> f64 {
        self.slack
    }

    /// A coordinate in mm in the frame the move runs in: the G92 shift added on the untilted
    /// plane; a tilted plane's origin already stands on the datum it moved (`interp::exec::tilt`).
    fn mm(&self, v: f64, k: usize) -> f64 {
        v * self.scale + if self.tilt.is_some() { 0.0 } else { self.g92[k] }
    }

    fn point(&self, p: &[f64]) -> [f64; 3] {
        [self.mm(p[0], 0), self.mm(p[1], 1), self.mm(p[2], 2)]
    }

    fn push(&mut self, kind: Kind, to: [f64; 3], line: u32) {
        // The moves held are final once another comes: a full batch goes on.
        if self.moves.len() >= BATCH
            && let Some(out) = &mut self.outlet
        {
            self.handed += self.moves.len();
            let full = std::mem::take(&mut self.moves);
            self.moves = out(full);
        }
        let origin = self.origin;
        let feed = if kind == Kind::Feed { self.sync.map_or(self.feed, |k| k * self.speed) } else { self.feed };
        self.moves.push(Move {
            kind,
            frame: self.wcs.0,
            from: self.pos,
            to,
            abc: self.rot,
            axes: (0, 1, 2),
            centre: [0.0; 3],
            sweep: 0.0,
            slack: 0.0,
            feed,
            // Under constant surface speed, S is a cutting speed in the program's units:
            // m/min, or ft/min in inches (0.3048 m each, 12/1000 of the inch scale).
            speed: if self.css.is_some() && self.scale != 1.0 { self.speed * self.scale * 0.012 } else { self.speed },
            css: self.css,
            spindle: self.spindle,
            coolant: self.coolant,
            tool: self.tool,
            tilt: self.tilt,
            axis: self.axis,
            dwell: std::mem::take(&mut self.dwell),
            known: self.known,
            line,
            origin,
        });
    }

    fn straight(&mut self, p: &[f64; 6], rapid: bool, line: u32) {
        let to = self.point(p);
        let abc = [p[3], p[4], p[5]];
        let tol = self.tol;
        if let Some((kind, axes, left)) = self.machine.take() {
            if left > 1 {
                self.machine = Some((kind, axes, left - 1));
            } else {
                // The machine's frame: which position, not the numbers the analysis gave it.
                let at = std::array::from_fn(|k| {
                    axes[k].map_or(f64::NAN, |v| if matches!(kind, Kind::Machine | Kind::Builder) { v * self.scale } else { 0.0 })
                });
                // Where only the machine knows: unknown in the work offset's frame after it.
                self.known &= !(0..6).filter(|&k| axes[k].is_some()).fold(0u8, |m, k| m | 1 << k);
                self.push(kind, at, line);
                self.chain.clear();
                self.pos = to;
                self.rot = abc;
                return;
            }
        }
        if (0..3).all(|k| (to[k] - self.pos[k]).abs() <= 1.5 * tol && (abc[k] - self.rot[k]).abs() <= 1.5 * tol) {
            self.pos = to;
            return;
        }
        // A rapid on along the line of the rapids before goes the same way: one rapid, every
        // point between within the tolerance of it.
        let pos = self.pos;
        let merged = rapid
            && self.dwell == 0.0
            && self.made().checked_sub(1) != Some(self.fresh)
            && self.moves.last().is_some_and(|l| {
                let (u, v) = (sub(to, l.from), sub(to, pos));
                l.kind == Kind::Rapid
                    && l.known == self.known
                    && l.abc == abc
                    && l.to == pos
                    && l.frame == self.wcs.0
                    && dot(sub(pos, l.from), v) > 0.0
                    && self.chain.iter().chain([&pos]).all(|q| norm(cross(u, sub(*q, l.from))) <= tol * norm(u))
            });
        if merged {
            if let Some(l) = self.moves.last_mut() {
                l.to = to;
            }
            self.chain.push(pos);
            self.pos = to;
            return;
        }
        self.chain.clear();
        self.rot = abc;
        self.push(if rapid { Kind::Rapid } else { Kind::Feed }, to, line);
        self.pos = to;
    }

    fn arc(&mut self, ends: (f64, f64), centre2: (f64, f64), rotation: i32, axis_end: f64, line: u32) {
        let (a, b, n) = self.plane.axes();
        let mut to = [0.0; 3];
        to[a] = self.mm(ends.0, a);
        to[b] = self.mm(ends.1, b);
        to[n] = self.mm(axis_end, n);
        let mut centre = [0.0; 3];
        centre[a] = self.mm(centre2.0, a);
        centre[b] = self.mm(centre2.1, b);
        let pos = self.pos;
        let ang = |p: [f64; 3]| (p[b] - centre[b]).atan2(p[a] - centre[a]);
        let tau = std::f64::consts::TAU;
        let mut sweep = ang(to) - ang(pos);
        if rotation > 0 {
            while sweep <= 1e-9 {
                sweep += tau;
            }
        } else {
            while sweep >= -1e-9 {
                sweep -= tau;
            }
        }
        let sweep = sweep.abs() + tau * f64::from(rotation.unsigned_abs().saturating_sub(1));
        let slack = ((pos[a] - centre[a]).hypot(pos[b] - centre[b]) - (to[a] - centre[a]).hypot(to[b] - centre[b])).abs();
        self.push(if rotation > 0 { Kind::ArcCcw } else { Kind::ArcCw }, to, line);
        if let Some(m) = self.moves.last_mut() {
            (m.axes, m.centre, m.sweep, m.slack) = ((a, b, n), centre, sweep, slack);
        }
        self.slack = self.slack.max(slack);
        self.chain.clear();
        self.pos = to;
    }

    fn rigid_tap(&mut self, p: &[f64; 3], line: u32) {
        // In to the point at the pitch and back out with the spindle reversed, as a tapping
        // cycle's moves go.
        let to = self.point(p);
        let back = self.pos;
        self.push(Kind::Feed, to, line);
        self.pos = to;
        self.spindle = -self.spindle;
        self.push(Kind::Feed, back, line);
        self.spindle = -self.spindle;
        self.pos = back;
        self.chain.clear();
    }

    fn refresh_g92(&mut self) {
        self.g92 = std::array::from_fn(|k| self.shifts[0][k] + self.shifts[1][k]);
    }

    fn select(&mut self, frame: Option<u16>, values: [f64; 6]) {
        self.wcs = (frame, values);
        // Values the program changes in an offset after moving in it move the machine as a
        // shift would.
        let first = self.frames.iter().find(|(k, _)| *k == frame).map_or(values, |(_, f)| *f);
        self.shifts[1] = std::array::from_fn(|k| (values[k] - first[k]) * self.scale);
        self.refresh_g92();
    }
}

impl CanonSink for Trace {
    fn emit(&mut self, c: Canon) {
        if self.ended {
            return;
        }
        self.origin = c.origin;
        let moving =
            matches!(c.op, CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. } | CanonOp::RigidTap(_));
        if moving && !self.frames.iter().any(|(k, _)| *k == self.wcs.0) {
            self.frames.push(self.wcs);
        }
        match &c.op {
            CanonOp::UseLengthUnits(u) => self.scale = u.to_mm(),
            CanonOp::WorkPlane(f) => {
                self.tilt = f.as_deref().map(|f| Frame { origin: f.origin.map(|v| v * self.scale), rotation: f.rotation })
            }
            CanonOp::SelectPlane(p) => self.plane = *p,
            CanonOp::ToolAxis(v) => self.axis = *v,
            CanonOp::Known(m) => {
                if *m & !self.known != 0 {
                    self.fresh = self.made();
                }
                self.known = *m;
            }
            CanonOp::SetG92Offset(o) => {
                self.shifts[0] = [o[0] * self.scale, o[1] * self.scale, o[2] * self.scale];
                self.refresh_g92();
            }
            CanonOp::SetG5xOffset(i, v) => self.select(Some(*i), *v),
            CanonOp::Setting(Setting::WorkOffset(i)) => self.select(Some(*i), self.wcs.1),
            CanonOp::MachineMove(m) => {
                let kind = match m.target {
                    // A straight approach moves as a return through the current position.
                    MachineTarget::Reference(k) | MachineTarget::Direct(k) => Kind::Reference(k),
                    MachineTarget::Fixed(k) => Kind::Fixed(k),
                    MachineTarget::Machine => Kind::Machine,
                    MachineTarget::Builder => Kind::Builder,
                    MachineTarget::Limit => Kind::Limit,
                };
                self.machine = Some((kind, m.axes, m.moves()));
            }
            CanonOp::SetFeedRate(f) => self.feed = f * self.scale,
            CanonOp::SetSpindleSpeed(s) => self.speed = *s,
            CanonOp::SetSpindleMode(m) => self.css = *m,
            CanonOp::StartSpindleClockwise => self.spindle = 1,
            CanonOp::StartSpindleCounterclockwise => self.spindle = -1,
            CanonOp::StopSpindleTurning => self.spindle = 0,
            CanonOp::ChangeTool(t) => self.tool = *t,
            CanonOp::FloodOn => self.coolant |= 1,
            CanonOp::MistOn => self.coolant |= 2,
            CanonOp::FloodOff => self.coolant &= !1,
            CanonOp::MistOff => self.coolant &= !2,
            CanonOp::ProgramEnd => self.ended = true,
            CanonOp::Dwell(s) => self.dwell += s.max(0.0),
            CanonOp::StartSpeedFeedSync(p) => self.sync = Some(p * self.scale),
            CanonOp::StopSpeedFeedSync => self.sync = None,
            CanonOp::RigidTap(p) => self.rigid_tap(p, c.line),
            CanonOp::StraightTraverse(p) => self.straight(p, true, c.line),
            CanonOp::StraightFeed(p) => self.straight(p, false, c.line),
            CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, .. } => {
                self.arc((*first_end, *second_end), (*first_axis, *second_axis), *rotation, *axis_end, c.line);
            }
            _ => {}
        }
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// Whether two points agree within `tol` on each axis (NaN, an axis a machine move leaves
/// alone, agrees only with NaN).
fn near(a: [f64; 3], b: [f64; 3], tol: f64) -> bool {
    (0..3).all(|k| (a[k].is_nan() && b[k].is_nan()) || (a[k] - b[k]).abs() <= tol)
}

fn fmt(p: [f64; 3]) -> String {
    let axis = |n: &str, v: f64| if v.is_nan() { String::new() } else { format!(" {n}{v:.4}") };
    format!("{}{}{}", axis("X", p[0]), axis("Y", p[1]), axis("Z", p[2])).trim_start().to_owned()
}

fn frame(f: Option<u16>) -> String {
    match f {
        None => "the machine's work offset".into(),
        Some(i) if i > crate::canon::EXTENDED_WCS => format!("additional work offset {}", i - crate::canon::EXTENDED_WCS),
        Some(i) => format!("work offset {i}"),
    }
}

/// How far two tilted planes' rotations may differ, entry by entry: angles written to four
/// decimals of a degree turn a plane by under 1e-6.
const TILT_TOL: f64 = 2e-5;

/// Whether two moves run on the same tilted plane: origins within `tol` mm, rotations within
/// [`TILT_TOL`].
fn same_tilt(a: Option<&Frame>, b: Option<&Frame>, tol: f64) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(x), Some(y)) => {
            near(x.origin, y.origin, tol) && (0..3).all(|i| (0..3).all(|j| (x.rotation[i][j] - y.rotation[i][j]).abs() <= TILT_TOL))
        }
        _ => false,
    }
}

fn tilt(f: Option<&Frame>) -> String {
    match f {
        None => "the untilted plane".into(),
        Some(f) => {
            let z = f.axis();
            format!("the plane tilted to the tool axis I{:.4} J{:.4} K{:.4} about {}", z[0], z[1], z[2], fmt(f.origin))
        }
    }
}

/// A difference between two traces: the line of the first one where they part, and what.
#[derive(Clone, Debug, PartialEq)]
pub struct Difference {
    /// The line of the first program's move (0 where the second one has more).
    pub line: u32,
    /// Its block's range (empty where the second one has more).
    pub origin: TextRange,
    /// The second program's line, where it has a move there.
    pub other_line: Option<u32>,
    /// What differs, in words.
    pub what: String,
}

impl std::fmt::Display for Difference {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.line > 0 {
            write!(f, "line {}: ", self.line)?;
        }
        f.write_str(&self.what)
    }
}

/// Whether two moves run with the same spindle mode: revolutions, or constant surface speed
/// clamped at the same speed (within half a revolution per minute).
fn same_clamp(a: Option<f64>, b: Option<f64>) -> bool {
    match (a, b) {
        (None, None) => true,
        (Some(x), Some(y)) => x == y || (x - y).abs() <= 0.5,
        _ => false,
    }
}

/// The spindle mode as the proof says it: nothing for revolutions, ` (constant surface speed,
/// clamp S2500)` else.
fn css_text(c: Option<f64>) -> String {
    match c {
        None => String::new(),
        Some(m) if m >= crate::canon::NO_SPINDLE_LIMIT => " (constant surface speed)".into(),
        Some(m) => format!(" (constant surface speed, clamp S{m})"),
    }
}

/// The first way trace `b` runs differently from `a`, with positions within `tol` mm.
pub fn difference(ta: &Trace, tb: &Trace, tol: f64) -> Option<Difference> {
    let mut c = Comparison::new(tol);
    c.take(Side::Program, ta.moves.iter().cloned());
    c.end(Side::Program, ta.dwell);
    c.take(Side::Translation, tb.moves.iter().cloned());
    c.end(Side::Translation, tb.dwell);
    c.verdict().flatten()
}

/// One of the two streams a [`Comparison`] compares.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Side {
    /// The program (`a` of [`difference`]).
    Program,
    /// Its translation (`b`).
    Translation,
}

/// [`difference`] made as the two streams come: moves are taken from either side in any
/// batches, each compared as soon as the other side has what it needs (one move; the pieces
/// of an arc), and dropped once compared. The verdict is the same whatever the batches.
#[derive(Debug)]
pub struct Comparison {
    tol: f64,
    /// The moves of each side not yet compared.
    a: std::collections::VecDeque<Move>,
    b: std::collections::VecDeque<Move>,
    /// Each side's dwell after its last move, once it has ended.
    a_end: Option<f64>,
    b_end: Option<f64>,
    /// The line and range of the program's last move compared, and the translation's last
    /// line taken: the places of a difference in the dwell after the last move.
    a_last: Option<(u32, TextRange)>,
    b_last: Option<u32>,
    /// The first difference (`Some(None)`: none), once known.
    verdict: Option<Option<Difference>>,
}

/// What a comparison step found: the two moves alike so far (and how many of the
/// translation's made the program's move), a verdict, or a side whose moves it waits for.
enum Step {
    Alike(usize),
    Done(Option<Difference>),
    Wait(Side),
}

impl Comparison {
    /// A comparison of nothing yet, positions within `tol` mm.
    pub fn new(tol: f64) -> Comparison {
        Comparison {
            tol,
            a: Default::default(),
            b: Default::default(),
            a_end: None,
            b_end: None,
            a_last: None,
            b_last: None,
            verdict: None,
        }
    }

    /// Takes `moves`, the next ones of `side`, and compares what it can.
    pub fn take(&mut self, side: Side, moves: impl IntoIterator<Item = Move>) {
        if self.verdict.is_some() {
            return;
        }
        match side {
            Side::Program => self.a.extend(moves),
            Side::Translation => {
                let before = self.b.len();
                self.b.extend(moves);
                if self.b.len() > before {
                    self.b_last = self.b.back().map(|n| n.line);
                }
            }
        }
        self.run();
    }

    /// `side` has no more moves; it dwells `dwell` seconds after its last one.
    pub fn end(&mut self, side: Side, dwell: f64) {
        match side {
            Side::Program => self.a_end = Some(dwell),
            Side::Translation => self.b_end = Some(dwell),
        }
        self.run();
    }

    /// The side whose moves the comparison waits for, or `None` once it has its verdict.
    pub fn wants(&self) -> Option<Side> {
        if self.verdict.is_some() {
            return None;
        }
        match self.step() {
            Step::Wait(side) => Some(side),
            // Not reached: `run` steps until it waits or decides.
            Step::Alike(_) | Step::Done(_) => None,
        }
    }

    /// Whether the verdict is known.
    pub fn decided(&self) -> bool {
        self.verdict.is_some()
    }

    /// The first difference, `Some(None)` for none, or `None` while undecided.
    pub fn verdict(self) -> Option<Option<Difference>> {
        self.verdict
    }

    fn run(&mut self) {
        while self.verdict.is_none() {
            match self.step() {
                Step::Wait(_) => return,
                Step::Done(d) => {
                    self.verdict = Some(d);
                    self.a.clear();
                    self.b.clear();
                }
                Step::Alike(k) => {
                    if let Some(m) = self.a.pop_front() {
                        self.a_last = Some((m.line, m.origin));
                    }
                    self.b.drain(..k);
                }
            }
        }
    }

    /// Compares the program's next move with the translation's next ones.
    fn step(&self) -> Step {
        let tol = self.tol;
        let differ = |m: &Move, n: Option<&Move>, what: String| {
            Step::Done(Some(Difference { line: m.line, origin: m.origin, other_line: n.map(|n| n.line), what }))
        };
        let Some(m) = self.a.front() else {
            let Some(da) = self.a_end else { return Step::Wait(Side::Program) };
            if let Some(n) = self.b.front() {
                return Step::Done(Some(Difference {
                    line: 0,
                    origin: TextRange::default(),
                    other_line: Some(n.line),
                    what: format!("the translation has more moves: {} to {}", n.kind.label(), fmt(n.to)),
                }));
            }
            let Some(db) = self.b_end else { return Step::Wait(Side::Translation) };
            return Step::Done((!same_dwell(da, db)).then(|| Difference {
                line: self.a_last.map_or(0, |l| l.0),
                origin: self.a_last.map_or_else(TextRange::default, |l| l.1),
                other_line: self.b_last,
                what: format!("dwells {} after the last move, the translation {}", secs(da), secs(db)),
            }));
        };
        let Some(n) = self.b.front() else {
            if self.b_end.is_none() {
                return Step::Wait(Side::Translation);
            }
            return differ(m, None, format!("the translation ends before the {} to {}", m.kind.label(), fmt(m.to)));
        };
        if let Some(what) = same_setting(m, n, tol) {
            return differ(m, Some(n), what);
        }
        let mut took = 1;
        if !m.kind.is_arc() {
            // An axis neither side knows the position of has no number to compare: each side's
            // counts from an assumed one, which a frame change the target is not told of
            // (`G10 L2` values before any move) moves. Its words are never written, and a move
            // of it is refused by the writer (`post::unknown-start`).
            let unknown = if matches!(m.kind, Kind::Rapid | Kind::Feed) { !m.known & !n.known } else { 0 };
            let mask = |p: [f64; 3], first: usize| std::array::from_fn(|k| if unknown & 1 << (k + first) != 0 { f64::NAN } else { p[k] });
            if n.kind != m.kind || !near(mask(m.to, 0), mask(n.to, 0), tol) || !near(mask(m.abc, 3), mask(n.abc, 3), tol) {
                return differ(m, Some(n), format!("{} to {} became {} to {}", m.kind.label(), fmt(m.to), n.kind.label(), fmt(n.to)));
            }
        } else {
            match arc_pieces(m, self.b.iter(), tol) {
                Ok(k) => took = k,
                Err(None) if self.b_end.is_none() => return Step::Wait(Side::Translation),
                Err(None) => return differ(m, Some(n), "the translation ends within the arc".into()),
                Err(Some(what)) => return differ(m, Some(n), what),
            }
        }
        // Safe output: a translation states no axis the program leaves where the machine
        // happens to be, and leaves none there that the program states.
        if m.known != n.known {
            return differ(m, Some(n), format!("{} to {}: {}", m.kind.label(), fmt(m.to), known_difference(m.known, n.known)));
        }
        Step::Alike(took)
    }
}

/// How move `n` runs in another frame, plane, tool axis, technology or after another dwell
/// than `m`, in words, if it does.
fn same_setting(m: &Move, n: &Move, tol: f64) -> Option<String> {
    if m.frame != n.frame && !matches!(m.kind, Kind::Reference(_) | Kind::Fixed(_) | Kind::Machine | Kind::Builder) {
        return Some(format!("moves in {}, the translation in {}", frame(m.frame), frame(n.frame)));
    }
    if !same_tilt(m.tilt.as_ref(), n.tilt.as_ref(), tol) {
        return Some(format!("moves on {}, the translation on {}", tilt(m.tilt.as_ref()), tilt(n.tilt.as_ref())));
    }
    // The tool axis: rotary axes written to a few decimals turn it by some 1e-5.
    if !near(m.axis, n.axis, 1e-4) {
        let v = |a: [f64; 3]| format!("I{:.4} J{:.4} K{:.4}", a[0], a[1], a[2]);
        return Some(format!("moves with the tool axis {}, the translation with {}", v(m.axis), v(n.axis)));
    }
    // The spindle, its speed and the coolant as they cut: on a rapid they make nothing (a
    // target whose tool change stops the spindle positions with it stopped).
    let state = |x: &Move| (x.spindle, x.coolant);
    let cuts = m.kind.cuts();
    if m.tool != n.tool
        || (cuts && state(m) != state(n))
        || (cuts && m.spindle != 0 && (m.speed - n.speed).abs() > 0.5)
        || (cuts && m.spindle != 0 && !same_clamp(m.css, n.css))
        || (cuts && (m.feed - n.feed).abs() > 1e-3 * m.feed.max(1.0))
    {
        return Some(format!(
            "tool/spindle/coolant/feed/speed T{} {} {} F{} S{}{} became T{} {} {} F{} S{}{}",
            m.tool,
            m.spindle,
            m.coolant,
            m.feed,
            m.speed,
            css_text(m.css),
            n.tool,
            n.spindle,
            n.coolant,
            n.feed,
            n.speed,
            css_text(n.css)
        ));
    }
    (!same_dwell(m.dwell, n.dwell))
        .then(|| format!("dwells {} before the {} to {}, the translation {}", secs(m.dwell), m.kind.label(), fmt(m.to), secs(n.dwell)))
}

/// How the axes the translation knows (`b`) differ from those the program knows (`a`).
fn known_difference(a: u8, b: u8) -> String {
    const NAMES: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
    let names = |m: u8| (0..6).filter(|&k| m & 1 << k != 0).map(|k| NAMES[k]).collect::<Vec<_>>().join(" ");
    let mut parts = Vec::new();
    if b & !a != 0 {
        parts.push(format!(
            "the translation states {} where the program does not know the position (it would send the tool to a position counted from an assumed 0)",
            names(b & !a)
        ));
    }
    if a & !b != 0 {
        parts.push(format!("the program states {}, which the translation leaves where the machine happens to be", names(a & !b)));
    }
    parts.join("; ")
}

/// Two dwells alike as a control times them: within a millisecond (the finest unit a
/// dictionary writes one in) and a thousandth of the dwell.
fn same_dwell(a: f64, b: f64) -> bool {
    (a - b).abs() <= 1e-3 + 1e-3 * a.abs()
}

fn secs(s: f64) -> String {
    format!("{} s", (s * 1000.0).round() / 1000.0)
}

/// How many moves of `b` make arc `m`: the same direction, and each piece about the same
/// centre or, where the centre is ill-conditioned (a long radius over a short chord, radii
/// that differ at the ends), on the same path within `tol` and the source's radius
/// difference.
/// `Err(None)`: the pieces given end within the arc.
fn arc_pieces<'m>(m: &Move, b: impl IntoIterator<Item = &'m Move>, tol: f64) -> Result<usize, Option<String>> {
    let (a0, b0, _) = m.axes;
    let r0 = (m.from[a0] - m.centre[a0]).hypot(m.from[b0] - m.centre[b0]);
    let angle_tol = (2.0 * tol + m.slack) / r0.max(1e-9) + 1e-3;
    let mut swept = 0.0;
    const PLANES: [&str; 3] = ["X", "Y", "Z"];
    let plane = |x: &Move| format!("{}{}", PLANES[x.axes.0], PLANES[x.axes.1]);
    for (k, n) in b.into_iter().enumerate() {
        if n.kind.is_arc() && n.axes != m.axes {
            return Err(Some(format!("arc in the {} plane became one in the {} plane", plane(m), plane(n))));
        }
        let same_centre = near(n.centre, m.centre, 2.0 * tol + m.slack);
        if n.kind != m.kind || !(same_centre || arc_deviation(m, n) <= tol + m.slack) {
            return Err(Some(format!("arc about {} became {} about {}", fmt(m.centre), n.kind.label(), fmt(n.centre))));
        }
        swept += n.sweep;
        // Done at the source's end point with its sweep; the pieces past its sweep without
        // reaching it are another arc.
        if near(n.to, m.to, tol) && (swept - m.sweep).abs() <= angle_tol.max(1e-2) {
            return Ok(k + 1);
        }
        if swept >= m.sweep - 1e-3 {
            return Err(Some(format!("arc to {} became one to {}", fmt(m.to), fmt(n.to))));
        }
    }
    Err(None)
}

/// How far piece `n` of a translated arc strays from the source's arc `m` (infinite when `m`
/// turns more than once): `m` runs from its start radius to its end radius and along its axis
/// in proportion to the angle, as controls that take differing radii move.
fn arc_deviation(m: &Move, n: &Move) -> f64 {
    let tau = std::f64::consts::TAU;
    if m.sweep > tau + 1e-9 || n.axes != m.axes {
        return f64::INFINITY;
    }
    let (a, b, k) = m.axes;
    let ang = |p: [f64; 3], c: [f64; 3]| (p[b] - c[b]).atan2(p[a] - c[a]);
    let dir = if m.kind == Kind::ArcCcw { 1.0 } else { -1.0 };
    let r = |p: [f64; 3], c: [f64; 3]| (p[a] - c[a]).hypot(p[b] - c[b]);
    let (r0, r1) = (r(m.from, m.centre), r(m.to, m.centre));
    let (s0, rn) = (ang(n.from, n.centre), r(n.from, n.centre));
    let rn1 = r(n.to, n.centre);
    let mut worst: f64 = 0.0;
    for i in 0..=32 {
        let f = f64::from(i) / 32.0;
        let t = s0 + dir * n.sweep * f;
        let rr = rn + (rn1 - rn) * f;
        let mut q = [0.0; 3];
        q[a] = n.centre[a] + rr * t.cos();
        q[b] = n.centre[b] + rr * t.sin();
        q[k] = n.from[k] + (n.to[k] - n.from[k]) * f;
        // The point's angle along `m`, from its start in its direction.
        let theta = (dir * (ang(q, m.centre) - ang(m.from, m.centre))).rem_euclid(tau);
        let d = if theta <= m.sweep + 1e-9 {
            let g = if m.sweep > 0.0 { theta / m.sweep } else { 0.0 };
            let radial = r(q, m.centre) - (r0 + (r1 - r0) * g);
            let axial = q[k] - (m.from[k] + (m.to[k] - m.from[k]) * g);
            radial.hypot(axial)
        } else {
            let dist = |p: [f64; 3]| (0..3).map(|x| (q[x] - p[x]).powi(2)).sum::<f64>().sqrt();
            dist(m.from).min(dist(m.to))
        };
        worst = worst.max(d);
    }
    worst
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::canon::MachineMove;

    fn c(op: CanonOp, line: u32) -> Canon {
        Canon { op, origin: crate::text::TextRange::default(), line }
    }

    fn home_z() -> CanonOp {
        CanonOp::MachineMove(Box::new(MachineMove { target: MachineTarget::Reference(1), axes: [None, None, Some(0.0), None, None, None] }))
    }

    /// A dwell lost, or written in the wrong unit (`G4 P1000` read as seconds), is a
    /// difference: at a hole's bottom or before a cut it changes what the part gets.
    #[test]
    fn a_dwell_of_another_length_differs() {
        let feed = |x: f64| CanonOp::StraightFeed([x, 0.0, -5.0, 0.0, 0.0, 0.0]);
        let with = |s: f64| Trace::of(&[c(feed(1.0), 1), c(CanonOp::Dwell(s), 2), c(feed(2.0), 3)], 1e-3);
        assert_eq!(difference(&with(1.0), &with(1.0), 1e-3), None);
        // A millisecond's rounding is the same dwell.
        assert_eq!(difference(&with(0.5), &with(0.5004), 1e-3), None);
        let d = difference(&with(1.0), &with(1000.0), 1e-3).expect("1 s is not 1000 s");
        assert_eq!(d.line, 3);
        assert_eq!(d.what, "dwells 1 s before the feed to X2.0000 Y0.0000 Z-5.0000, the translation 1000 s");
        // After the last move.
        let end = |s: f64| Trace::of(&[c(feed(1.0), 1), c(CanonOp::Dwell(s), 2)], 1e-3);
        let d = difference(&end(2.0), &end(0.0), 1e-3).expect("a dwell at the end dropped");
        assert_eq!(d.what, "dwells 2 s after the last move, the translation 0 s");
        // Two rapids with a dwell between are two moves: the dwell stays where it is.
        let rapid = |x: f64| CanonOp::StraightTraverse([x, 0.0, 5.0, 0.0, 0.0, 0.0]);
        let t = Trace::of(&[c(rapid(1.0), 1), c(CanonOp::Dwell(1.0), 2), c(rapid(2.0), 3)], 1e-3);
        assert_eq!(t.moves.len(), 2);
    }

    #[test]
    fn a_reference_return_is_not_a_rapid_to_the_same_numbers() {
        let z50 = CanonOp::StraightTraverse([0.0, 0.0, 50.0, 0.0, 0.0, 0.0]);
        let z0 = CanonOp::StraightTraverse([0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let source = Trace::of(&[c(z50.clone(), 1), c(home_z(), 2), c(z50.clone(), 2), c(z0.clone(), 2)], 1e-3);
        let dropped = Trace::of(&[c(z50.clone(), 1), c(z0.clone(), 2)], 1e-3);
        let d = difference(&source, &dropped, 1e-3).expect("a rapid to Z0 is not a return home");
        assert_eq!(d.line, 2);
        assert_eq!(d.what, "reference return to Z0.0000 became rapid to X0.0000 Y0.0000 Z0.0000");
        let kept = Trace::of(&[c(z50.clone(), 1), c(home_z(), 5), c(z50, 5), c(z0, 5)], 1e-3);
        assert_eq!(difference(&source, &kept, 1e-3), None);
    }

    #[test]
    fn a_stated_work_offset_is_not_the_machines() {
        let mv = CanonOp::StraightTraverse([1.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
        let source = Trace::of(&[c(CanonOp::Setting(Setting::WorkOffset(1)), 1), c(mv.clone(), 2)], 1e-3);
        let dropped = Trace::of(&[c(mv.clone(), 2)], 1e-3);
        let d = difference(&source, &dropped, 1e-3).expect("G54 dropped");
        assert_eq!(d.what, "moves in work offset 1, the translation in the machine's work offset");
        let other = Trace::of(&[c(CanonOp::SetG5xOffset(2, [0.0; 6]), 1), c(mv, 2)], 1e-3);
        assert!(difference(&source, &other, 1e-3).is_some());
    }

    #[test]
    fn moves_on_another_tilted_plane_differ() {
        let (s, k) = 30f64.to_radians().sin_cos();
        let a30 = Frame { origin: [0.0; 3], rotation: [[1.0, 0.0, 0.0], [0.0, k, -s], [0.0, s, k]] };
        let plane = |f: Option<Frame>| CanonOp::WorkPlane(f.map(Box::new));
        let mv = CanonOp::StraightTraverse([20.0, 10.0, 5.0, 0.0, 0.0, 0.0]);
        let source = Trace::of(&[c(plane(Some(a30)), 1), c(mv.clone(), 2)], 1e-3);
        let untilted = Trace::of(&[c(mv.clone(), 2)], 1e-3);
        let d = difference(&source, &untilted, 1e-3).expect("the plane dropped");
        assert_eq!(
            d.what,
            "moves on the plane tilted to the tool axis I0.0000 J-0.5000 K0.8660 about X0.0000 Y0.0000 Z0.0000, the translation on the untilted plane"
        );
        // Angles written to four decimals turn the plane by less than the tolerance.
        let near = Frame { rotation: [[1.0, 0.0, 0.0], [0.0, k + 1e-6, -s], [0.0, s, k + 1e-6]], ..a30 };
        assert_eq!(difference(&source, &Trace::of(&[c(plane(Some(near)), 1), c(mv.clone(), 2)], 1e-3), 1e-3), None);
        let shifted = Frame { origin: [0.0, 0.0, 1.0], ..a30 };
        assert!(difference(&source, &Trace::of(&[c(plane(Some(shifted)), 1), c(mv, 2)], 1e-3), 1e-3).is_some());
    }

    #[test]
    fn a_move_with_another_tool_axis_differs() {
        let tilted = CanonOp::ToolAxis([0.258819, 0.0, 0.965926]);
        let mv = CanonOp::StraightFeed([20.0, 10.0, 5.0, 0.0, 15.0, 0.0]);
        let source = Trace::of(&[c(tilted.clone(), 2), c(mv.clone(), 2)], 1e-3);
        let untilted = Trace::of(&[c(mv.clone(), 2)], 1e-3);
        let d = difference(&source, &untilted, 1e-3).expect("the tool axis dropped");
        assert_eq!(d.what, "moves with the tool axis I0.2588 J0.0000 K0.9659, the translation with I0.0000 J0.0000 K1.0000");
        assert_eq!(difference(&source, &Trace::of(&[c(tilted, 2), c(mv, 2)], 1e-3), 1e-3), None);
    }

    #[test]
    fn a_changed_plane_turns_an_arc_elsewhere() {
        let arc = CanonOp::ArcFeed {
            first_end: 10.0,
            second_end: 0.0,
            first_axis: 5.0,
            second_axis: 0.0,
            rotation: 1,
            axis_end: 0.0,
            abc: [0.0; 3],
        };
        let start = [c(CanonOp::SetFeedRate(100.0), 1), c(CanonOp::StraightFeed([0.0; 6]), 1)];
        let mut xy = start.to_vec();
        xy.push(c(arc.clone(), 2));
        let mut xz = start.to_vec();
        xz.extend([c(CanonOp::SelectPlane(Plane::Xz), 2), c(arc, 2)]);
        // In XZ the first axis is Z: the same numbers end at Z10, not X10.
        assert!(difference(&Trace::of(&xy, 1e-3), &Trace::of(&xz, 1e-3), 1e-3).is_some());
    }

    /// The moves a streaming trace hands on, batch by batch, are those of a whole one: a
    /// rapid merged along its line across a batch's end, arcs, a rigid tap, a fresh axis.
    #[test]
    fn a_streaming_trace_hands_on_the_moves_of_a_whole_one() {
        let feed = |x: f64, y: f64| CanonOp::StraightFeed([x, y, -1.0, 0.0, 0.0, 0.0]);
        let rapid = |x: f64| CanonOp::StraightTraverse([x, 0.0, 5.0, 0.0, 0.0, 0.0]);
        let mut ops = vec![c(CanonOp::Known(0b111), 1)];
        for k in 0..2 * BATCH + 37 {
            let line = ops.len() as u32;
            ops.push(c(feed((k % 2) as f64 * 50.0, k as f64 * 0.01), line));
            // Rapids along one line, the chain running over the end of a batch.
            if k % (BATCH - 3) == 0 {
                ops.extend((0..9).map(|x| c(rapid(f64::from(x)), line)));
                ops.push(c(CanonOp::RigidTap([3.0, 0.0, -4.0]), line));
                let arc = CanonOp::ArcFeed {
                    first_end: 13.0,
                    second_end: 0.0,
                    first_axis: 8.0,
                    second_axis: 0.0,
                    rotation: -1,
                    axis_end: -4.0,
                    abc: [0.0; 3],
                };
                ops.extend([c(arc, line), c(CanonOp::Known(0b11), line), c(CanonOp::Known(0b111), line), c(CanonOp::Dwell(0.5), line)]);
            }
        }
        let whole = Trace::of(&ops, 1e-3);
        let handed = std::rc::Rc::new(std::cell::RefCell::new(Vec::new()));
        let into = handed.clone();
        let mut t = Trace::streaming(1e-3, move |mut batch| {
            assert!(batch.len() <= BATCH);
            into.borrow_mut().append(&mut batch);
            batch
        });
        ops.iter().for_each(|op| t.emit(op.clone()));
        assert!(t.moves.len() <= BATCH);
        assert_eq!(t.finish(), whole.dwell);
        assert_eq!(t.slack(), whole.slack());
        assert!(t.moves.is_empty());
        assert!(whole.moves.len() > 2 * BATCH);
        assert_eq!(format!("{:?}", handed.borrow()), format!("{:?}", whole.moves));
    }

    /// A comparison fed in any batches, the two sides in either order, gives the verdict of
    /// the whole traces: alike, a move that differs, an arc whose pieces come apart.
    #[test]
    fn a_comparison_fed_in_batches_gives_the_whole_verdict() {
        let arc = |x: f64, y: f64, cx: f64, cy: f64, rotation: i32| CanonOp::ArcFeed {
            first_end: x,
            second_end: y,
            first_axis: cx,
            second_axis: cy,
            rotation,
            axis_end: -1.0,
            abc: [0.0; 3],
        };
        let start = |line: u32| {
            vec![
                c(CanonOp::SetFeedRate(100.0), line),
                c(CanonOp::StraightFeed([0.0, 0.0, -1.0, 0.0, 0.0, 0.0]), line),
                c(CanonOp::StraightFeed([10.0, 0.0, -1.0, 0.0, 0.0, 0.0]), line),
            ]
        };
        let mut source = start(1);
        source.extend([c(arc(30.0, 0.0, 20.0, 0.0, 1), 2), c(CanonOp::StraightFeed([30.0, 5.0, -1.0, 0.0, 0.0, 0.0]), 3)]);
        let pieces = |second: CanonOp| {
            let mut t = start(1);
            t.extend([c(arc(20.0, -10.0, 20.0, 0.0, 1), 2), c(second, 3), c(CanonOp::StraightFeed([30.0, 5.0, -1.0, 0.0, 0.0, 0.0]), 4)]);
            t
        };
        let a = Trace::of(&source, 1e-3);
        let cases = [
            (pieces(arc(30.0, 0.0, 20.0, 0.0, 1)), None),
            (pieces(arc(30.0, 0.0, 20.0, 0.0, -1)), Some((2, Some(2)))),
            (pieces(arc(30.0, 0.5, 20.0, 0.0, 1)), Some((2, Some(2)))),
            (start(1), Some((2, None))),
        ];
        for (b, expected) in cases {
            let b = Trace::of(&b, 1e-3);
            let whole = difference(&a, &b, 1e-3);
            assert_eq!(whole.as_ref().map(|d| (d.line, d.other_line)), expected, "{whole:?}");
            for size in 1..=4 {
                for first in [Side::Program, Side::Translation] {
                    let mut cmp = Comparison::new(1e-3);
                    let mut left = [(Side::Program, &a), (Side::Translation, &b)].map(|(s, t)| (s, t.moves.chunks(size), t.dwell));
                    if first == Side::Translation {
                        left.reverse();
                    }
                    // The side the comparison waits for next, else in turn.
                    let mut turn = 0;
                    while !cmp.decided() {
                        let side = cmp.wants().unwrap_or(left[turn % 2].0);
                        let (s, chunks, dwell) = left.iter_mut().find(|(s, ..)| *s == side).unwrap();
                        match chunks.next() {
                            Some(batch) => cmp.take(*s, batch.iter().cloned()),
                            None => cmp.end(*s, *dwell),
                        }
                        turn += 1;
                    }
                    assert_eq!(cmp.verdict(), Some(whole.clone()), "batches of {size}, {first:?} first");
                }
            }
        }
    }
}

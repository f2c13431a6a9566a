//! Canned drilling and boring cycles, expanded into moves the way LinuxCNC does, wrapped in
//! intent markers so that plan recovery keeps what was asked for.

use super::{Interpreter, Retract, Spindle};
use crate::canon::{CanonOp, CanonSink, CycleIntent, CycleKind, DistanceMode, TurnIntent, TurnKind, Units};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role, TapStyle};
use crate::syntax::Block;
use crate::text::TextRange;

/// What one hole of a cycle needs, in program coordinates along the hole axis.
#[derive(Clone, Debug)]
pub(super) struct HoleRun {
    pub kind: CycleKind,
    /// The cycle as written (`G83`, `CYCLE83`, `CYCL DEF 200`).
    pub code: String,
    /// Where feeding starts (the R plane).
    pub r: f64,
    pub bottom: f64,
    /// Where the tool goes after the hole.
    pub clear: f64,
    /// The level before the cycle (back boring returns there).
    pub old_z: f64,
    /// Peck depth.
    pub peck: Option<f64>,
    /// The level the peck depths count from (Fanuc: R; Siemens and Heidenhain: the surface).
    pub peck_from: f64,
    pub dwell: Option<f64>,
    /// Fine and back boring shift.
    pub shift: f64,
    /// Re-approach distance above the last peck.
    pub clearance: f64,
    /// Whether the hole is at the current position, so no move in the plane is needed.
    pub still: bool,
    /// The workpiece surface a defined cycle states (`RFP`, `Q203`).
    pub surface: Option<f64>,
    /// Whether the R level is known wherever the tool stands: an absolute level (G90 R,
    /// Siemens `RFP`+`SDIS`, Heidenhain `Q203`+`Q200`), or one counted from a known level.
    /// From a hole axis the program does not know, the cycle's move to it makes it known.
    pub r_known: bool,
    /// Whether the tool returns to the level the cycle began at (G98; above R, as rs274
    /// has it): from a level the program does not know, an unknown one.
    pub returns_initial: bool,
}

impl Interpreter<'_> {
    /// A canned drilling or boring cycle (G73, G74, G76, G81 to G89): its words, kept for the
    /// cycle blocks after it, then its holes, as many as L (or K) says, at the block's point.
    pub(super) fn cycle(&mut self, def: &CodeDef, range: TextRange, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let Some(kind) = self.hole_kind(def, range, diags) else { return };
        // The hole's position the block states is known before the cycle's marker: a writer
        // states it in the cycle.
        self.mark_known(sink);
        if let Some(axis) = def.hole_axis {
            return self.live_cycle(def, kind, axis as usize, block, sink, diags);
        }
        // The hole axis is the plane's normal: Z in G17, Y in G18, X in G19.
        let (a0, a1, n) = self.st.plane.axes();
        if n != 2 && matches!(kind, CycleKind::Tapping | CycleKind::LeftTapping) {
            let d = Diagnostic::new(
                Code::Unsupported,
                range,
                format!(
                    "{} outside G17 is tapped along the plane's normal axis; LinuxCNC's rs274 feeds another axis here, so check the machine",
                    def.label()
                ),
            );
            self.limited(diags, "tap-plane", d);
        }
        self.check_technology(def, block.range, diags);
        let dwell_word = self.sticky_words(def, n, block, diags);
        let (Some(r_word), Some(z_word)) = (self.st.sticky_r, self.st.sticky_z) else {
            let missing = if self.st.sticky_r.is_none() { "R (the feed-start plane)" } else { "Z (the hole bottom)" };
            diags.push(Diagnostic::new(Code::CycleIncomplete, block.range, format!("{} has no {missing}", def.label())));
            return;
        };
        let incremental = self.st.distance == DistanceMode::Incremental;
        let old_z = self.st.pos[n];
        // The initial level is where the first of the cycles in force began: in G91, R counts
        // from it in every later cycle block too, as rs274 and Fanuc's manuals do. Whether the
        // program knows it is kept with it.
        if self.st.cycle_initial.is_none() {
            self.cycle_initial_unknown = !self.knows(n);
        }
        let initial = *self.st.cycle_initial.get_or_insert(old_z);
        let r_known = !incremental || !self.cycle_initial_unknown;
        let returns_initial = self.st.retract == Retract::Initial;
        let r = if incremental { initial + r_word } else { r_word };
        let bottom = if incremental { r + z_word } else { z_word };
        let peck = if matches!(kind, CycleKind::PeckDrilling | CycleKind::ChipBreaking) {
            match self.st.sticky_q {
                Some(q) if q > 0.0 => Some(q),
                _ => {
                    diags.push(Diagnostic::new(
                        Code::MissingParameter,
                        block.range,
                        format!("{} needs a positive Q (peck increment)", def.label()),
                    ));
                    return;
                }
            }
        } else {
            None
        };
        let dwell = matches!(
            kind,
            CycleKind::CounterBoring
                | CycleKind::BoringDwell
                | CycleKind::BoringSpindleStop
                | CycleKind::Tapping
                | CycleKind::LeftTapping
                | CycleKind::FineBoring
                | CycleKind::BackBoring
                | CycleKind::BoringManual
        )
        .then(|| self.dwell_seconds(self.st.sticky_p.unwrap_or(0.0)));
        // The shift of fine and back boring: Q, in the direction the control's parameters set
        // (Fanuc 5101 RD1/RD2), after an oriented stop at the angle they set: read along +X
        // for the plan, but the program states neither, so where the shifted moves go is not
        // known here and a translation refuses rather than write moves that may drag or crash
        // the bar (back boring rapids down through the bore on the shift alone).
        let shift = if matches!(kind, CycleKind::FineBoring | CycleKind::BackBoring) { self.st.sticky_q.unwrap_or(0.0).abs() } else { 0.0 };
        if shift != 0.0 {
            let msg = format!(
                "{} orients the spindle and shifts the bar by Q in a direction the control's parameters set (Fanuc 5101 RD1/RD2), which the program does not state: where the shifted moves go is not known here, so a translation cannot write them as moves",
                def.label()
            );
            self.limited(diags, "motion-unknown", Diagnostic::new(Code::MotionUnknown, block.range, msg));
        }
        let repeats = self.slot(Role::L).or(self.slot(Role::K).filter(|_| dwell_word != Role::K)).unwrap_or(1.0);
        if repeats < 0.0 || repeats.fract() != 0.0 {
            diags.push(Diagnostic::new(Code::MalformedNumber, block.range, "the repeat count must be a whole number"));
            return;
        }
        let clearance =
            if self.st.units == Units::Mm { self.dialect.behaviour.peck_clearance_mm } else { self.dialect.behaviour.peck_clearance_inch };
        let code = def.label();

        // Up to R when the initial level is below it, in every cycle block (rs274 then moves
        // even where a G99 retract already left the tool at R). From a level the program does
        // not know, with R absolute, no rise from the level assumed: the hole's own first move
        // goes to R, known from there (as a defined cycle's, `define.rs`).
        let mut p = self.st.pos;
        if initial < r && (self.knows(n) || !r_known) {
            p[n] = r;
            self.emit(sink, CanonOp::StraightTraverse(p));
        }
        let clear = if self.st.retract == Retract::Initial { initial.max(r) } else { r };
        let (dx, dy) = (self.slot(Role::AXES[a0]), self.slot(Role::AXES[a1]));
        // Polar words (`@`, `^`) place a hole as they place a move's end point. In G91 each
        // repeat adds them again to the distance and angle of the hole before, as rs274 does
        // (`G91 G81 ^60 L6`: six holes round the origin, not six steps along one chord).
        let polar = self.slots[Role::PolarRadius as usize].is_some() || self.slots[Role::PolarAngle as usize].is_some();
        let run = HoleRun {
            kind,
            code,
            r,
            bottom,
            clear,
            old_z,
            peck,
            peck_from: r,
            dwell,
            shift,
            clearance,
            still: false,
            surface: None,
            r_known,
            returns_initial,
        };
        for _ in 0..repeats as u64 {
            let (x, y) = if polar {
                let mut t = p;
                self.polar_target(if incremental { p } else { self.st.pos }, &mut t);
                (t[a0], t[a1])
            } else if incremental {
                (p[a0] + dx.unwrap_or(0.0), p[a1] + dy.unwrap_or(0.0))
            } else {
                (dx.unwrap_or(p[a0]), dy.unwrap_or(p[a1]))
            };
            p = self.hole(&run, x, y, p, sink);
        }
        self.st.pos = p;
    }

    /// The kind of hole a G8x code makes; `None`, reported, for one not expanded (the I/J
    /// form of back boring).
    fn hole_kind(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<CycleKind> {
        Some(match def.meaning {
            Meaning::CycleDrill => CycleKind::Drilling,
            Meaning::CycleDrillDwell => CycleKind::CounterBoring,
            Meaning::CyclePeckDrill => CycleKind::PeckDrilling,
            Meaning::CycleChipBreak => CycleKind::ChipBreaking,
            Meaning::CycleBore => CycleKind::Boring,
            Meaning::CycleBoreDwell => CycleKind::BoringDwell,
            Meaning::CycleBoreStop => CycleKind::BoringSpindleStop,
            Meaning::CycleTap => CycleKind::Tapping,
            Meaning::CycleTapLeft => CycleKind::LeftTapping,
            Meaning::CycleFineBore => CycleKind::FineBoring,
            // The Q-shift form (Fanuc); the I/J form of RS274NGC is not expanded.
            Meaning::CycleBackBore if self.slot(Role::I).is_none() && self.slot(Role::J).is_none() => CycleKind::BackBoring,
            Meaning::CycleBoreManual => CycleKind::BoringManual,
            _ => {
                self.unsupported(def, range, diags);
                return None;
            }
        })
    }

    /// Keeps the cycle words of the block for the cycle blocks after it (`n` is the hole
    /// axis), and, where the control feeds from the initial level without R, that level as R
    /// (with a warning). Returns the word that gives the dwell.
    fn sticky_words(&mut self, def: &CodeDef, n: usize, block: &Block, diags: &mut Vec<Diagnostic>) -> Role {
        // Sticky words: R always, Z while the same cycle stays active, Q and P as given.
        if let Some(r) = self.slot(Role::R) {
            self.st.sticky_r = Some(r);
        }
        if let Some(z) = self.slot(Role::AXES[n]) {
            self.st.sticky_z = Some(z);
        }
        if let Some(q) = self.slot(Role::Q) {
            self.st.sticky_q = Some(q);
        }
        // The dwell's word: the one the code's `args` give the role `p` (Fagor `K:p`), else P.
        let dwell_word = def.args.iter().find(|(_, to)| *to == Role::P).map_or(Role::P, |(from, _)| *from);
        if let Some(p) = self.slot(dwell_word) {
            self.st.sticky_p = Some(p);
        }
        // Without R, Fanuc-family controls feed from the initial level (where the tool is when
        // the first cycle begins): a warning where the dictionary says so, else an error.
        if self.st.sticky_r.is_none() && self.st.sticky_z.is_some() && self.dialect.behaviour.cycle_r_defaults_to_initial {
            let initial = self.st.cycle_initial.unwrap_or(self.st.pos[n]);
            let r = if self.st.distance == DistanceMode::Incremental { 0.0 } else { initial };
            self.st.sticky_r = Some(r);
            let mut d = Diagnostic::new(
                Code::CycleIncomplete,
                block.range,
                format!("{} has no R: the control feeds from the initial level, {r}", def.label()),
            );
            d.severity = crate::diag::Severity::Warning;
            diags.push(d);
        }
        dwell_word
    }

    /// One hole of a cycle at (`x`, `y`) in the plane, from position `p`: the intent marker,
    /// the moves, the end marker. Returns the position after it.
    pub(super) fn hole(&mut self, run: &HoleRun, x: f64, y: f64, p: [f64; 6], sink: &mut dyn CanonSink) -> [f64; 6] {
        let (a0, a1, n) = self.st.plane.axes();
        let HoleRun { kind, r, bottom, clear, old_z, peck, peck_from, dwell, shift, clearance, still, .. } = *run;
        // From a hole axis the program does not know (after a tool change, a reference
        // return), the cycle's move to an R level known wherever the tool stands makes it
        // known (840D CYCLE81 "approach of the reference plane brought forward by the safety
        // distance with G0"; Heidenhain cycle 200 "to the set-up clearance above the workpiece
        // surface at FMAX"; G81 in G90: to the absolute R). A return to the level the cycle
        // began at (G98) is to an unknown level again. Back boring goes down beside the hole
        // from its start: left unknown. So is a tap of a cycle called over the tool (Heidenhain
        // 207, 840D CYCLE84): it feeds its pitch (Q239, PIT) times the speed, which the
        // reading does not model (it takes the feed in force), so no translation of it could
        // be proven; from an unknown level it stays refused as before.
        let defined_tap = still && matches!(kind, CycleKind::Tapping | CycleKind::LeftTapping);
        let known_at_r = run.r_known && kind != CycleKind::BackBoring && !defined_tap && !self.knows(n);
        let returns_unknown = known_at_r && run.returns_initial;
        let away = |s: &Self, sink: &mut dyn CanonSink| {
            if returns_unknown {
                s.forget(1 << n, sink);
            }
        };
        {
            let intent = CycleIntent {
                kind,
                code: run.code.clone(),
                x,
                y,
                bottom,
                r_plane: r,
                clear,
                peck,
                dwell,
                positioned: still,
                surface: run.surface,
                peck_clearance: peck.map(|_| clearance),
                known_at_r,
                returns_unknown,
            };
            self.emit(sink, CanonOp::CycleBegin(Box::new(intent)));
            let place = |first: f64, z: f64| {
                let mut q = p;
                (q[a0], q[a1], q[n]) = (first, y, z);
                q
            };
            let at = |z: f64| place(x, z);
            if !(still && p[a0] == x && p[a1] == y) {
                self.emit(sink, CanonOp::StraightTraverse(at(p[n])));
            }
            // From an unknown level the move to R is made whatever number the analysis gives
            // that level (equal to R, it would be no move at all in the stream). Back boring goes
            // down to R (below the part) only with the bar shifted, the spindle oriented: its own
            // moves below.
            if known_at_r {
                self.learn(1 << n, sink);
            }
            if (p[n] != r || known_at_r) && kind != CycleKind::BackBoring {
                self.emit(sink, CanonOp::StraightTraverse(at(r)));
            }
            // Fine and back boring stop the spindle oriented (Fanuc's G76/G87 sequence), so the
            // shift moves the cutting edge off the wall.
            let orient = CanonOp::OrientSpindle { angle: 0.0, mode: 0 };
            match kind {
                CycleKind::Drilling => {
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    away(self, sink);
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                }
                CycleKind::CounterBoring => {
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    self.emit(sink, CanonOp::Dwell(dwell.unwrap_or(0.0)));
                    away(self, sink);
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                }
                CycleKind::PeckDrilling | CycleKind::ChipBreaking => {
                    let q = peck.unwrap_or(1.0);
                    let full = kind == CycleKind::PeckDrilling;
                    let mut depth = peck_from - q;
                    while depth > bottom {
                        self.emit(sink, CanonOp::StraightFeed(at(depth)));
                        if full {
                            self.emit(sink, CanonOp::StraightTraverse(at(r)));
                        }
                        self.emit(sink, CanonOp::StraightTraverse(at(depth + clearance)));
                        depth -= q;
                    }
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    away(self, sink);
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                }
                CycleKind::Boring | CycleKind::BoringDwell => {
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    if let (CycleKind::BoringDwell, Some(d)) = (kind, dwell) {
                        self.emit(sink, CanonOp::Dwell(d));
                    }
                    self.emit(sink, CanonOp::StraightFeed(at(r)));
                    if clear != r {
                        away(self, sink);
                        self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                    }
                }
                CycleKind::Tapping | CycleKind::LeftTapping => {
                    let (reverse, forward) = if kind == CycleKind::Tapping {
                        (CanonOp::StartSpindleCounterclockwise, CanonOp::StartSpindleClockwise)
                    } else {
                        (CanonOp::StartSpindleClockwise, CanonOp::StartSpindleCounterclockwise)
                    };
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    match self.dialect.behaviour.tapping {
                        TapStyle::RPlane => {
                            if let Some(d) = dwell.filter(|d| *d > 0.0) {
                                self.emit(sink, CanonOp::Dwell(d));
                            }
                            self.emit(sink, reverse);
                            self.emit(sink, CanonOp::StraightFeed(at(r)));
                            self.emit(sink, forward);
                            if clear != r {
                                away(self, sink);
                                self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                            }
                        }
                        TapStyle::Clear => {
                            self.emit(sink, CanonOp::StopSpindleTurning);
                            self.emit(sink, reverse);
                            self.emit(sink, CanonOp::Dwell(dwell.unwrap_or(0.0)));
                            away(self, sink);
                            self.emit(sink, CanonOp::StraightFeed(at(clear)));
                            self.emit(sink, CanonOp::StopSpindleTurning);
                            self.emit(sink, forward);
                        }
                    }
                }
                CycleKind::FineBoring => {
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    if let Some(d) = dwell.filter(|d| *d > 0.0) {
                        self.emit(sink, CanonOp::Dwell(d));
                    }
                    self.emit(sink, orient.clone());
                    let shifted = |z: f64| place(x + shift, z);
                    self.emit(sink, CanonOp::StraightTraverse(shifted(bottom)));
                    away(self, sink);
                    self.emit(sink, CanonOp::StraightTraverse(shifted(clear)));
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                    self.restart_spindle(sink);
                }
                CycleKind::BackBoring => {
                    // From the initial level: stop, shift, rapid down to R below the part,
                    // shift back, bore upwards to Z, stop, shift, rapid out.
                    let shifted = |z: f64| place(x + shift, z);
                    self.emit(sink, orient.clone());
                    self.emit(sink, CanonOp::StraightTraverse(shifted(p[n])));
                    self.emit(sink, CanonOp::StraightTraverse(shifted(r)));
                    self.emit(sink, CanonOp::StraightTraverse(at(r)));
                    self.restart_spindle(sink);
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    if let Some(d) = dwell.filter(|d| *d > 0.0) {
                        self.emit(sink, CanonOp::Dwell(d));
                    }
                    self.emit(sink, orient.clone());
                    self.emit(sink, CanonOp::StraightTraverse(shifted(bottom)));
                    self.emit(sink, CanonOp::StraightTraverse(shifted(old_z)));
                    self.emit(sink, CanonOp::StraightTraverse(at(old_z)));
                    self.restart_spindle(sink);
                }
                CycleKind::BoringManual => {
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    self.emit(sink, CanonOp::Dwell(dwell.unwrap_or(0.0)));
                    self.emit(sink, CanonOp::StopSpindleTurning);
                    // The operator jogs out; the control then continues from the clear level.
                    self.emit(sink, CanonOp::ProgramStop);
                    away(self, sink);
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                    self.restart_spindle(sink);
                }
                CycleKind::BoringSpindleStop => {
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    self.emit(sink, CanonOp::Dwell(dwell.unwrap_or(0.0)));
                    self.emit(sink, CanonOp::StopSpindleTurning);
                    away(self, sink);
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                    self.restart_spindle(sink);
                }
            }
            // Where the return made no move (R the analysis's level), the tool is still where
            // the cycle began or at R: unknown which.
            away(self, sink);
            self.emit(sink, CanonOp::CycleEnd);
            if kind == CycleKind::BackBoring { at(old_z) } else { at(clear) }
        }
    }

    /// Turns the spindle back on in its programmed direction after a cycle stopped it.
    fn restart_spindle(&self, sink: &mut dyn CanonSink) {
        match self.st.spindle {
            Spindle::Cw => self.emit(sink, CanonOp::StartSpindleClockwise),
            Spindle::Ccw => self.emit(sink, CanonOp::StartSpindleCounterclockwise),
            Spindle::Stopped => {}
        }
    }
}

/// How a lathe roughing cycle cuts (Fanuc G71, G72): the depth of each pass (a radius for
/// G71), the retract at 45° after it, and the finishing allowances it leaves (X as a radius,
/// and Z).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Rough {
    depth: f64,
    retract: f64,
    allow_x: f64,
    allow_z: f64,
    /// Passes along X, the depth stepping in Z (G72), rather than along Z (G71).
    pub(super) facing: bool,
    /// The contour cut again in passes shifted towards it (G73 pattern repeating), rather
    /// than passes along Z or X up to it.
    pattern: Option<Pattern>,
}

impl Rough {
    /// A roughing of `depth` per pass, retracting `retract`, leaving `allow_x` (a radius,
    /// negative inside) and `allow_z`; along X when `facing`.
    pub(super) fn new(depth: f64, retract: f64, allow_x: f64, allow_z: f64, facing: bool) -> Rough {
        Rough { depth, retract, allow_x, allow_z, facing, pattern: None }
    }
}

/// How a pattern repeating cycle (Fanuc G73) cuts: the first pass lies `relief_x` (a radius)
/// and `relief_z` off the last, which lies on the contour shifted by the allowances; `passes`
/// passes in all, evenly apart.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) struct Pattern {
    relief_x: f64,
    relief_z: f64,
    passes: u32,
}

/// A contour element in the ZX plane, as (X, Z) points: a line, or an arc about a centre
/// (counter-clockwise as the canon's rotation says, in the plane's first-second frame).
#[derive(Clone, Copy, Debug)]
enum Element {
    Line { from: (f64, f64), to: (f64, f64) },
    Arc { from: (f64, f64), to: (f64, f64), centre: (f64, f64), rotation: i32 },
}

impl Element {
    fn shifted(self, dx: f64, dz: f64) -> Element {
        let s = |p: (f64, f64)| (p.0 + dx, p.1 + dz);
        match self {
            Element::Line { from, to } => Element::Line { from: s(from), to: s(to) },
            Element::Arc { from, to, centre, rotation } => Element::Arc { from: s(from), to: s(to), centre: s(centre), rotation },
        }
    }

    fn end(self) -> (f64, f64) {
        match self {
            Element::Line { to, .. } | Element::Arc { to, .. } => to,
        }
    }

    /// Where the element first reaches the level `x` (its first coordinate), as its second
    /// coordinate, going from its start.
    fn z_at(self, x: f64) -> Option<f64> {
        match self {
            Element::Line { from, to } => {
                // A line along Z at that X is met where the next element leaves it.
                if (from.0 - x) * (to.0 - x) > 0.0 || from.0 == to.0 {
                    return None;
                }
                Some(from.1 + (x - from.0) / (to.0 - from.0) * (to.1 - from.1))
            }
            Element::Arc { from, to, centre, rotation } => {
                // In the plane's frame (Z first, X second): angles about the centre.
                let r = (from.1 - centre.1).hypot(from.0 - centre.0);
                let s = (x - centre.0) / r;
                if !(-1.0..=1.0).contains(&s) || r == 0.0 {
                    return None;
                }
                let angle = |p: (f64, f64)| (p.0 - centre.0).atan2(p.1 - centre.1);
                let (a, b) = (angle(from), angle(to));
                let tau = std::f64::consts::TAU;
                let along = |t: f64| if rotation > 0 { (t - a).rem_euclid(tau) } else { (a - t).rem_euclid(tau) };
                let mut sweep = along(b);
                if sweep == 0.0 {
                    sweep = tau;
                }
                let t1 = s.asin();
                [t1, std::f64::consts::PI - t1]
                    .into_iter()
                    .filter(|&t| along(t) <= sweep + 1e-12)
                    .min_by(|p, q| along(*p).total_cmp(&along(*q)))
                    .map(|t| centre.1 + r * t.cos())
            }
        }
    }
}

/// What a contour cycle states, for the plan: its depth of cut, retract and allowances (X on
/// the diameter), in program units; a pattern repeating cycle its relief and passes instead
/// of a depth of cut and retract.
fn contour_intent(def: &CodeDef, rough: Option<Rough>, cut: Option<(f64, f64)>) -> TurnIntent {
    let kind = match rough {
        Some(r) if r.facing => TurnKind::RoughFace,
        Some(_) => TurnKind::RoughTurn,
        None => TurnKind::Finish,
    };
    let mut t = TurnIntent { kind: Some(kind), code: def.label(), ..TurnIntent::default() };
    if let Some(r) = rough {
        t.allowance_x = Some(2.0 * r.allow_x);
        t.allowance_z = Some(r.allow_z);
        if let Some(p) = r.pattern {
            t.relief = Some([p.relief_x, p.relief_z]);
            t.divisions = Some(p.passes);
        } else {
            t.depth_of_cut = cut.map(|c| c.0);
            t.retract = Some(r.retract);
        }
    }
    t
}

/// Roughing passes a cycle may make at most: more is a slip in the depth of cut.
const MAX_ROUGH_PASSES: f64 = 10_000.0;

/// Moves a pattern repeating cycle may make at most (its passes times its contour's moves).
const MAX_PATTERN_MOVES: f64 = 1_000_000.0;

impl Interpreter<'_> {
    /// Fanuc's G71 and G70 (`cycle-rough-turn`, `cycle-finish-contour`): the first block of
    /// G71's two-block form keeps the depth of cut and retract; a block with P and Q asks the
    /// flow driver for the contour between those blocks.
    pub(super) fn contour_cycle(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        // The words the code gives roles of its own, as written: U is an X word, halved in
        // diameter mode by the read.
        let arg = |s: &Self, role: Role| {
            let (from, _) = *def.args.iter().find(|(_, to)| *to == role)?;
            let v = s.slot(from)?;
            Some(if from == Role::X && s.st.diameter { 2.0 * v } else { v })
        };
        // The contour's first and last blocks: P and Q, or the words the dictionary names
        // (Okuma LAP `G85 N0508`: the first block, the contour running up to its end code).
        let named = |s: &Self, role: Role| def.args.iter().find(|(_, to)| *to == role).and_then(|(from, _)| s.slot(*from));
        let (p, q) = (named(self, Role::P).or(self.slot(Role::P)), self.slot(Role::Q));
        let to_end = q.is_none() && self.dialect.codes.iter().any(|c| c.meaning == Meaning::ContourEnd);
        if def.meaning == Meaning::CycleRoughPattern {
            return self.pattern_cycle(def, p, q, range, diags);
        }
        if matches!(def.meaning, Meaning::CycleRoughTurn | Meaning::CycleRoughFace) && p.is_none() && q.is_none() {
            let (depth, retract) = self.st.rough_cut.unwrap_or((0.0, 0.0));
            self.st.rough_cut = Some((arg(self, Role::CutDepth).unwrap_or(depth), arg(self, Role::RetractDistance).unwrap_or(retract)));
            return;
        }
        let block_number = |v: Option<f64>| v.filter(|v| *v >= 0.0 && v.fract() == 0.0 && *v < 1e9).map(|v| v as u32);
        let last = block_number(q);
        let (Some(first), true) = (block_number(p), last.is_some() || to_end) else {
            let msg = format!("{} needs P and Q, the block numbers where its contour begins and ends; the cycle is skipped", def.label());
            diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
            return;
        };
        let facing = def.meaning == Meaning::CycleRoughFace;
        // The one-block form (`G71 P Q U W D F`: Haas, Fanuc 10/11/15) names words for both
        // allowances, and the block with P and Q gives the depth of cut (and any retract).
        let one_block = [Role::AllowanceX, Role::AllowanceZ].iter().all(|r| def.args.iter().any(|(_, to)| to == r));
        if one_block {
            let (depth, retract) = self.st.rough_cut.unwrap_or((0.0, 0.0));
            self.st.rough_cut = Some((arg(self, Role::CutDepth).unwrap_or(depth), arg(self, Role::RetractDistance).unwrap_or(retract)));
        }
        let rough = if matches!(def.meaning, Meaning::CycleRoughTurn | Meaning::CycleRoughFace) {
            let depth = self.st.rough_cut.map_or(0.0, |(d, _)| d);
            if !(depth > 0.0 && depth.is_finite()) {
                let msg = format!(
                    "{} has no depth of cut: a {} block with only the depth of cut and the retract, before this one, gives it; the cycle is skipped",
                    def.label(),
                    def.label()
                );
                diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
                return;
            }
            let retract = self.st.rough_cut.map_or(0.0, |(_, e)| e).abs();
            // With P and Q, the word that gave the depth of cut gives the allowance along the
            // depth's axis (G71's U, G72's W); U is a diameter.
            let (allow_x, allow_z) = if one_block {
                (arg(self, Role::AllowanceX).unwrap_or(0.0) / 2.0, arg(self, Role::AllowanceZ).unwrap_or(0.0))
            } else if facing {
                (arg(self, Role::AllowanceX).unwrap_or(0.0) / 2.0, arg(self, Role::CutDepth).unwrap_or(0.0))
            } else {
                (arg(self, Role::CutDepth).unwrap_or(0.0) / 2.0, arg(self, Role::AllowanceZ).unwrap_or(0.0))
            };
            if ![retract, allow_x, allow_z].iter().all(|v| v.is_finite()) {
                let msg = format!("{}: the retract and the allowances must be numbers; the cycle is skipped", def.label());
                diags.push(Diagnostic::new(Code::BadValue, range, msg));
                return;
            }
            Some(Rough { depth, retract, allow_x, allow_z, facing, pattern: None })
        } else {
            None
        };
        if self.st.plane != crate::canon::Plane::Xz {
            let msg = format!("{} turns in the ZX plane (G18); the cycle is skipped", def.label());
            diags.push(Diagnostic::new(Code::Unsupported, range, msg));
            return;
        }
        self.turn_intent = Some(Box::new(contour_intent(def, rough, self.st.rough_cut)));
        self.request = Some(super::Request::Contour { first, last, rough });
    }

    /// Fanuc's G73 (`cycle-rough-pattern`): the block without P and Q keeps the relief and the
    /// number of passes; the block with them (its U and W the allowances) asks the flow driver
    /// for the contour between those blocks, to be cut again in passes (`pattern_passes`).
    fn pattern_cycle(&mut self, def: &CodeDef, p: Option<f64>, q: Option<f64>, range: TextRange, diags: &mut Vec<Diagnostic>) {
        // A word as written (an X word is halved in diameter mode by the read; the relief in
        // X is a radius as written, the allowance a diameter).
        let written = |s: &Self, from: Role| s.slot(from).map(|v| if from == Role::X && s.st.diameter { 2.0 * v } else { v });
        // The words the args name for the relief (as the X and Z displacement) and the passes.
        let named = |role: Role| def.args.iter().find(|(_, to)| *to == role).map(|(from, _)| *from);
        let (relief_x, relief_z) = (named(Role::X), named(Role::Z));
        let passes = named(Role::Passes).unwrap_or(Role::R);
        // The words of the allowances, as the args name them (Fanuc `U:allowance-x
        // W:allowance-z`: U and W are X and Z words in G-code system A, words of their own in
        // systems B and C), else the X and Z words.
        let (allow_xw, allow_zw) = (named(Role::AllowanceX).unwrap_or(Role::X), named(Role::AllowanceZ).unwrap_or(Role::Z));
        // The first block of the two-block form gives the relief in the allowances' words (U,
        // W); a one-block form in the words its args name (Haas I and K), with P and Q.
        let with_contour = p.is_some() || q.is_some();
        let (wx, wz) = if with_contour { (relief_x, relief_z) } else { (relief_x.or(Some(allow_xw)), relief_z.or(Some(allow_zw))) };
        let stated = (wx.and_then(|r| written(self, r)), wz.and_then(|r| written(self, r)), written(self, passes));
        let stated = if with_contour && relief_x.is_none() { (None, None, None) } else { stated };
        if stated != (None, None, None) {
            let was = self.st.pattern_cut;
            let n = stated.2.map(|n| if n.fract() == 0.0 && (1.0..=MAX_ROUGH_PASSES).contains(&n) { n as u32 } else { 0 });
            self.st.pattern_cut = Some(Pattern {
                relief_x: stated.0.or(was.map(|w| w.relief_x)).unwrap_or(0.0),
                relief_z: stated.1.or(was.map(|w| w.relief_z)).unwrap_or(0.0),
                passes: n.or(was.map(|w| w.passes)).unwrap_or(0),
            });
        }
        if !with_contour {
            return;
        }
        let block_number = |v: Option<f64>| v.filter(|v| *v >= 0.0 && v.fract() == 0.0 && *v < 1e9).map(|v| v as u32);
        let (Some(first), Some(last)) = (block_number(p), block_number(q)) else {
            let msg = format!("{} needs P and Q, the block numbers where its contour begins and ends; the cycle is skipped", def.label());
            diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
            return;
        };
        let Some(pattern) = self.st.pattern_cut.filter(|p| p.passes >= 1) else {
            let msg = format!(
                "{} has no number of passes (a whole number from 1): a {} block with the relief and the passes, before this one, gives it; the cycle is skipped",
                def.label(),
                def.label()
            );
            diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
            return;
        };
        // With P and Q, U and W are the allowances, X on the diameter (as written).
        let allow_x = written(self, allow_xw).unwrap_or(0.0) / 2.0;
        let allow_z = written(self, allow_zw).unwrap_or(0.0);
        if ![pattern.relief_x, pattern.relief_z, allow_x, allow_z].iter().all(|v| v.is_finite()) {
            let msg = format!("{}: the relief and the allowances must be numbers; the cycle is skipped", def.label());
            diags.push(Diagnostic::new(Code::BadValue, range, msg));
            return;
        }
        if self.st.plane != crate::canon::Plane::Xz {
            let msg = format!("{} turns in the ZX plane (G18); the cycle is skipped", def.label());
            diags.push(Diagnostic::new(Code::Unsupported, range, msg));
            return;
        }
        let rough = Rough { depth: 0.0, retract: 0.0, allow_x, allow_z, facing: false, pattern: Some(pattern) };
        self.turn_intent = Some(Box::new(contour_intent(def, Some(rough), None)));
        self.request = Some(super::Request::Contour { first, last: Some(last), rough: Some(rough) });
    }

    /// The passes of a pattern repeating cycle (Fanuc G73): the contour's blocks (`contour`,
    /// run from `start`) cut as written, each pass shifted by the allowances and its share of
    /// the relief, the whole relief on the first pass and none on the last; the P block's
    /// move (at rapid or feed as written) takes the tool from the start point onto each
    /// pass, and the tool returns to the start point at rapid after each.
    fn pattern_passes(&mut self, r: Rough, pattern: Pattern, start: [f64; 6], contour: &[crate::canon::Canon], sink: &mut dyn CanonSink) {
        let (a0, a1, _) = self.st.plane.axes();
        let n = pattern.passes.max(1);
        for k in 0..n {
            let share = if n > 1 { f64::from(n - 1 - k) / f64::from(n - 1) } else { 0.0 };
            let (dx, dz) = (r.allow_x + pattern.relief_x * share, r.allow_z + pattern.relief_z * share);
            let shift = |p: &[f64; 6]| {
                let mut q = *p;
                q[0] += dx;
                q[2] += dz;
                q
            };
            for c in contour {
                match &c.op {
                    CanonOp::StraightTraverse(p) => self.go(sink, shift(p), false),
                    CanonOp::StraightFeed(p) => self.go(sink, shift(p), true),
                    CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, abc } => {
                        let (mut end, mut centre) = ([0.0; 6], [0.0; 6]);
                        (end[a0], end[a1], centre[a0], centre[a1]) = (*first_end, *second_end, *first_axis, *second_axis);
                        end[3 - a0 - a1] = *axis_end;
                        (end[3], end[4], end[5]) = (abc[0], abc[1], abc[2]);
                        let (end, centre) = (shift(&end), shift(&centre));
                        self.emit(
                            sink,
                            CanonOp::ArcFeed {
                                first_end: end[a0],
                                second_end: end[a1],
                                first_axis: centre[a0],
                                second_axis: centre[a1],
                                rotation: *rotation,
                                axis_end: *axis_end,
                                abc: *abc,
                            },
                        );
                        self.st.pos = end;
                    }
                    _ => {}
                }
            }
            self.go(sink, start, false);
        }
    }

    /// Roughs out `contour` (the canon of its blocks, run from `start`) as G71 and G72 type I
    /// do: passes `depth` apart from the start point towards the contour, along Z (turning)
    /// or along X (facing), each ending where it meets the contour shifted by the allowances
    /// and retracted at 45°; then one pass along the shifted contour, and back to the start
    /// point. The work is done in (level, pass) coordinates: (X, Z) turning, (Z, X) facing.
    pub(super) fn rough_turn(
        &mut self,
        r: Rough,
        start: [f64; 6],
        contour: &[crate::canon::Canon],
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        if let Some(pattern) = r.pattern {
            if f64::from(pattern.passes) * contour.len() as f64 > MAX_PATTERN_MOVES {
                let msg = format!(
                    "the pattern repeating cycle would cut its contour of {} moves {} times; the cycle is skipped",
                    contour.len(),
                    pattern.passes
                );
                diags.push(Diagnostic::new(Code::BadValue, self.origin, msg));
                return;
            }
            return self.pattern_passes(r, pattern, start, contour, sink);
        }
        let (a0, a1, _) = self.st.plane.axes();
        // Exchanging the axes mirrors the plane: arcs turn the other way.
        let flip = if r.facing { -1 } else { 1 };
        let lp = |p: &[f64; 6]| if r.facing { (p[2], p[0]) } else { (p[0], p[2]) };
        let point = |l: f64, q: f64| {
            let mut p = start;
            (p[0], p[2]) = if r.facing { (q, l) } else { (l, q) };
            p
        };
        let mut at = lp(&start);
        let mut elements = Vec::new();
        for c in contour {
            let e = match &c.op {
                CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) => Element::Line { from: at, to: lp(p) },
                CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, .. } => {
                    // First and second axes of the ZX plane: Z then X.
                    let (mut to, mut centre) = ([0.0; 6], [0.0; 6]);
                    (to[a0], to[a1], centre[a0], centre[a1]) = (*first_end, *second_end, *first_axis, *second_axis);
                    Element::Arc { from: at, to: lp(&to), centre: lp(&centre), rotation: rotation * flip }
                }
                _ => continue,
            };
            at = e.end();
            elements.push(e);
        }
        // The first element reaches the contour's start A' from the start point A.
        let Some((first, rest)) = elements.split_first() else {
            diags.push(Diagnostic::new(
                Code::CycleIncomplete,
                self.origin,
                "the contour of the roughing cycle has no moves; the cycle is skipped",
            ));
            return;
        };
        let a = lp(&start);
        let a1_ = first.end();
        let outward = if a1_.0 < a.0 { 1.0 } else { -1.0 };
        // The allowances leave stock outside the contour (U negative for a bore).
        let (allow_level, allow_pass) = if r.facing { (r.allow_z, r.allow_x) } else { (r.allow_x, r.allow_z) };
        let shifted: Vec<Element> = rest.iter().map(|e| e.shifted(allow_level, allow_pass)).collect();
        let contour_start = (a1_.0 + allow_level, a1_.1 + allow_pass);
        let end_pass = shifted.last().map_or(contour_start.1, |e| e.end().1);
        // Passes up to the contour's start; the last pass along the contour takes the rest.
        let passes = ((a.0 - contour_start.0) * outward / r.depth - 1e-9).ceil() - 1.0;
        if !(passes.is_finite() && passes <= MAX_ROUGH_PASSES) {
            let msg = format!("the roughing cycle would take {passes} passes of {} each; the cycle is skipped", r.depth);
            diags.push(Diagnostic::new(Code::BadValue, self.origin, msg));
            return;
        }
        let e = r.retract;
        for k in 1..=passes.max(0.0) as u32 {
            let level = a.0 - outward * r.depth * f64::from(k);
            let end = shifted.iter().find_map(|el| el.z_at(level)).unwrap_or(end_pass);
            let back = (a.1 - end).signum();
            self.go(sink, point(level, a.1), false);
            self.go(sink, point(level, end), true);
            self.go(sink, point(level + outward * e, end + back * e), false);
            self.go(sink, point(level + outward * e, a.1), false);
        }
        // The last pass follows the shifted contour.
        self.go(sink, point(contour_start.0, contour_start.1), false);
        for el in &shifted {
            match *el {
                Element::Line { to, .. } => self.go(sink, point(to.0, to.1), true),
                Element::Arc { to, centre, rotation, .. } => {
                    let end = point(to.0, to.1);
                    let c = point(centre.0, centre.1);
                    let axis_end = end[3 - a0 - a1];
                    self.emit(
                        sink,
                        CanonOp::ArcFeed {
                            first_end: end[a0],
                            second_end: end[a1],
                            first_axis: c[a0],
                            second_axis: c[a1],
                            rotation: rotation * flip,
                            axis_end,
                            abc: [end[3], end[4], end[5]],
                        },
                    );
                    self.st.pos = end;
                }
            }
        }
        self.go(sink, start, false);
    }

    /// A straight move to `p`, at feed or at rapid.
    fn go(&mut self, sink: &mut dyn CanonSink, p: [f64; 6], feed: bool) {
        self.emit(sink, if feed { CanonOp::StraightFeed(p) } else { CanonOp::StraightTraverse(p) });
        self.st.pos = p;
    }

    /// After a finishing pass (G70): back to the start point at rapid.
    pub(super) fn back_to(&mut self, start: [f64; 6], sink: &mut dyn CanonSink) {
        self.go(sink, start, false);
    }
}

//! Canned drilling and boring cycles, expanded into moves the way LinuxCNC does, wrapped in
//! intent markers so that plan recovery keeps what was asked for.

use super::{Interpreter, Retract, Spindle};
use crate::canon::{CanonOp, CanonSink, CycleIntent, CycleKind, DistanceMode, Units};
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
}

impl Interpreter<'_> {
    pub(super) fn cycle(&mut self, def: &CodeDef, range: TextRange, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let kind = match def.meaning {
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
                return;
            }
        };
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
        if let Some(p) = self.slot(Role::P) {
            self.st.sticky_p = Some(p);
        }
        let (Some(r_word), Some(z_word)) = (self.st.sticky_r, self.st.sticky_z) else {
            let missing = if self.st.sticky_r.is_none() { "R (the feed-start plane)" } else { "Z (the hole bottom)" };
            diags.push(Diagnostic::new(Code::CycleIncomplete, block.range, format!("{} has no {missing}", def.label())));
            return;
        };
        let incremental = self.st.distance == DistanceMode::Incremental;
        let old_z = self.st.pos[n];
        // The initial level is where the first of the cycles in force began: in G91, R counts
        // from it in every later cycle block too, as rs274 and Fanuc's manuals do.
        let initial = *self.st.cycle_initial.get_or_insert(old_z);
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
        // The shift of fine and back boring: Q along +X (parameter 5101 RD1 = RD2 = 0).
        let shift = if matches!(kind, CycleKind::FineBoring | CycleKind::BackBoring) { self.st.sticky_q.unwrap_or(0.0).abs() } else { 0.0 };
        let repeats = self.slot(Role::L).or(self.slot(Role::K)).unwrap_or(1.0);
        if repeats < 0.0 || repeats.fract() != 0.0 {
            diags.push(Diagnostic::new(Code::MalformedNumber, block.range, "the repeat count must be a whole number"));
            return;
        }
        let clearance =
            if self.st.units == Units::Mm { self.dialect.behaviour.peck_clearance_mm } else { self.dialect.behaviour.peck_clearance_inch };
        let code = def.label();

        // Up to R when the initial level is below it, in every cycle block (rs274 then moves
        // even where a G99 retract already left the tool at R).
        let mut p = self.st.pos;
        if initial < r {
            p[n] = r;
            self.emit(sink, CanonOp::StraightTraverse(p));
        }
        let clear = if self.st.retract == Retract::Initial { initial.max(r) } else { r };
        let (dx, dy) = (self.slot(Role::AXES[a0]), self.slot(Role::AXES[a1]));
        let run = HoleRun { kind, code, r, bottom, clear, old_z, peck, peck_from: r, dwell, shift, clearance, still: false };
        for _ in 0..repeats as u64 {
            let (x, y) = if incremental {
                (p[a0] + dx.unwrap_or(0.0), p[a1] + dy.unwrap_or(0.0))
            } else {
                (dx.unwrap_or(p[a0]), dy.unwrap_or(p[a1]))
            };
            p = self.hole(&run, x, y, p, sink);
        }
        self.st.pos = p;
    }

    /// One hole of a cycle at (`x`, `y`) in the plane, from position `p`: the intent marker,
    /// the moves, the end marker. Returns the position after it.
    pub(super) fn hole(&mut self, run: &HoleRun, x: f64, y: f64, p: [f64; 6], sink: &mut dyn CanonSink) -> [f64; 6] {
        let (a0, a1, n) = self.st.plane.axes();
        let HoleRun { kind, r, bottom, clear, old_z, peck, peck_from, dwell, shift, clearance, still, .. } = *run;
        {
            let intent = CycleIntent { kind, code: run.code.clone(), x, y, bottom, r_plane: r, clear, peck, dwell, positioned: still };
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
            if p[n] != r {
                self.emit(sink, CanonOp::StraightTraverse(at(r)));
            }
            match kind {
                CycleKind::Drilling => {
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                }
                CycleKind::CounterBoring => {
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    self.emit(sink, CanonOp::Dwell(dwell.unwrap_or(0.0)));
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
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                }
                CycleKind::Boring | CycleKind::BoringDwell => {
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    if let (CycleKind::BoringDwell, Some(d)) = (kind, dwell) {
                        self.emit(sink, CanonOp::Dwell(d));
                    }
                    self.emit(sink, CanonOp::StraightFeed(at(r)));
                    if clear != r {
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
                                self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                            }
                        }
                        TapStyle::Clear => {
                            self.emit(sink, CanonOp::StopSpindleTurning);
                            self.emit(sink, reverse);
                            self.emit(sink, CanonOp::Dwell(dwell.unwrap_or(0.0)));
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
                    self.emit(sink, CanonOp::StopSpindleTurning);
                    let shifted = |z: f64| place(x + shift, z);
                    self.emit(sink, CanonOp::StraightTraverse(shifted(bottom)));
                    self.emit(sink, CanonOp::StraightTraverse(shifted(clear)));
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                    self.restart_spindle(sink);
                }
                CycleKind::BackBoring => {
                    // From the initial level: stop, shift, rapid down to R below the part,
                    // shift back, bore upwards to Z, stop, shift, rapid out.
                    let shifted = |z: f64| place(x + shift, z);
                    self.emit(sink, CanonOp::StopSpindleTurning);
                    self.emit(sink, CanonOp::StraightTraverse(shifted(p[n])));
                    self.emit(sink, CanonOp::StraightTraverse(shifted(r)));
                    self.emit(sink, CanonOp::StraightTraverse(at(r)));
                    self.restart_spindle(sink);
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    if let Some(d) = dwell.filter(|d| *d > 0.0) {
                        self.emit(sink, CanonOp::Dwell(d));
                    }
                    self.emit(sink, CanonOp::StopSpindleTurning);
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
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                    self.restart_spindle(sink);
                }
                CycleKind::BoringSpindleStop => {
                    self.emit(sink, CanonOp::StraightFeed(at(bottom)));
                    self.emit(sink, CanonOp::Dwell(dwell.unwrap_or(0.0)));
                    self.emit(sink, CanonOp::StopSpindleTurning);
                    self.emit(sink, CanonOp::StraightTraverse(at(clear)));
                    self.restart_spindle(sink);
                }
            }
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

//! The spindle and the coolant: turning (M3, M4, M5), orienting (M19), its speed modes
//! (G96 constant surface speed, G97 revolutions per minute, a lathe's `G50 S` limit), the S
//! word, and the coolant (M7, M8, M9).
//!
//! Doors: [`Interpreter::spindle_turn`], [`Interpreter::orient_spindle`],
//! [`Interpreter::spindle_speed_mode`], [`Interpreter::speed_word`], [`Interpreter::coolant`].

use crate::canon::{CanonOp, CanonSink, SpindleId};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::interp::{Interpreter, Spindle};
use crate::syntax::WordMode;
use crate::text::TextRange;

impl Interpreter<'_> {
    /// The spindle ops that follow address spindle `n` as the program numbers it (spindle 1
    /// the main one, as a Siemens control numbers them), `None` the main one: a marker where
    /// that changes.
    pub(in crate::interp) fn address_spindle(&mut self, n: Option<u8>, sink: &mut dyn CanonSink) {
        let id = match n {
            None | Some(1) => SpindleId::Main,
            Some(n) => SpindleId::Number(n),
        };
        self.address(id, sink);
    }

    fn address(&mut self, id: SpindleId, sink: &mut dyn CanonSink) {
        if id != self.st.spindle_id {
            self.st.spindle_id = id;
            self.emit(sink, CanonOp::Spindle(id));
        }
    }

    /// M3, M4, M5: the spindle turns clockwise, counterclockwise, or stops. A driven tool's own
    /// code (Haas `M133 P2500`) turns that drive, at P.
    pub(super) fn spindle_turn(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        if def.driven {
            let before = self.st.spindle_id;
            self.address(SpindleId::Driven, sink);
            if let Some(p) = self.slot(Role::P).filter(|p| *p > 0.0) {
                self.emit(sink, CanonOp::SetSpindleSpeed(p));
            }
            self.turn(def, sink);
            self.address(before, sink);
            return;
        }
        self.turn(def, sink);
    }

    fn turn(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        match def.meaning {
            Meaning::SpindleCw => {
                self.st.spindle = Spindle::Cw;
                self.st.tech_warned = false;
                self.emit(sink, CanonOp::StartSpindleClockwise);
            }
            Meaning::SpindleCcw => {
                self.st.spindle = Spindle::Ccw;
                self.st.tech_warned = false;
                self.emit(sink, CanonOp::StartSpindleCounterclockwise);
            }
            _ => {
                self.st.spindle = Spindle::Stopped;
                self.st.spindle_unknown = false;
                self.emit(sink, CanonOp::StopSpindleTurning);
            }
        }
    }

    /// M19: the spindle stops at an angle (R, degrees) turning the way P says (0 shorter,
    /// 1 clockwise, 2 counterclockwise); Q waits that many seconds for it. A code that takes
    /// no R orients to the angle the machine is set up with, given as 0.
    pub(super) fn orient_spindle(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.st.spindle = Spindle::Stopped;
        let (angle, mode) = (self.slot(Role::R), self.slot(Role::P));
        if angle.is_some() || mode.is_some() || !def.params.takes(Role::R) {
            let mode = match mode {
                None => 0,
                Some(p) if [0.0, 1.0, 2.0].contains(&p) => p as u8,
                Some(p) => {
                    let d = Diagnostic::new(Code::BadValue, range, format!("{}: P{p} is no direction; P takes 0, 1 or 2", def.label()));
                    diags.push(d);
                    return;
                }
            };
            self.emit(sink, CanonOp::OrientSpindle { angle: angle.unwrap_or(0.0), mode });
            // On a lathe (X read as a diameter) the oriented main spindle is the C axis in
            // position control (Siemens `SPOS=90`): the part stands at that angle for the
            // driven tool's work that follows.
            // `SPOS=IC(90)` turns it on by that much.
            if self.st.diameter && self.st.spindle_id == SpindleId::Main {
                let incremental = self.slots[Role::R as usize].is_some_and(|s| s.mode == WordMode::Incremental);
                self.st.pos[5] = if incremental { self.st.pos[5] + angle.unwrap_or(0.0) } else { angle.unwrap_or(0.0) };
            }
        }
        match self.slot(Role::Q) {
            Some(t) if t > 0.0 => self.emit(sink, CanonOp::WaitOrientComplete(t)),
            Some(t) => {
                diags.push(Diagnostic::new(Code::BadValue, range, format!("{}: a wait of Q{t} seconds; Q must be above 0", def.label())))
            }
            None => {}
        }
    }

    /// G96 (constant surface speed, with its limit), G97 (revolutions per minute), and a
    /// lathe's G50 (the speed limit, and with axis words the coordinate system).
    pub(super) fn spindle_speed_mode(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        match def.meaning {
            Meaning::SpindleLimit => {
                if let Some(max) = self.slot(Role::S) {
                    self.set_spindle_limit(max, sink);
                }
                // A lathe's `G50 X.. Z..` (G-code system A) also sets the coordinate system,
                // as G92 does, where the dictionary lets the code take axis words.
                if Role::AXES.iter().any(|&r| self.slot(r).is_some() && def.params.takes(r)) {
                    self.origin_shift(sink);
                }
            }
            Meaning::SpindleCss => {
                self.lathe_word();
                // LinuxCNC's D or Siemens' LIMS in the block, else the limit set before (a
                // lathe's `G50 S`), else none (rs274 says 1e30).
                let max = self
                    .slot(Role::D)
                    .or(self.slot(Role::SpindleLimit))
                    .or(self.st.spindle_limit)
                    .unwrap_or(crate::canon::NO_SPINDLE_LIMIT);
                self.st.css_max = Some(max);
                self.emit(sink, CanonOp::SetSpindleMode(Some(max)));
            }
            _ => {
                self.st.css_max = None;
                self.emit(sink, CanonOp::SetSpindleMode(None));
            }
        }
    }

    /// A code's second effect (`CodeDef::also`), where the control keeps the spindle's speed
    /// mode and the feed's type in one group (Siemens group 15): a feed mode, or constant
    /// surface speed turned on or off where it changes (`G95` after `G96` ends it).
    pub(super) fn second_effect(&mut self, m: Meaning, sink: &mut dyn CanonSink) {
        match m {
            Meaning::SpindleCss if self.st.css_max.is_none() => {
                let max = self.slot(Role::SpindleLimit).or(self.st.spindle_limit).unwrap_or(crate::canon::NO_SPINDLE_LIMIT);
                self.st.css_max = Some(max);
                self.emit(sink, CanonOp::SetSpindleMode(Some(max)));
            }
            Meaning::SpindleRpm if self.st.css_max.is_some() => {
                self.st.css_max = None;
                self.emit(sink, CanonOp::SetSpindleMode(None));
            }
            Meaning::FeedPerMinute | Meaning::FeedPerRev | Meaning::FeedInverseTime => self.feed_mode(m, sink),
            _ => {}
        }
    }

    /// The speed step: the block's S word sets the spindle speed, and `LIMS=` the limit.
    pub(super) fn speed_word(&mut self, sink: &mut dyn CanonSink) {
        // `LIMS=3000` (Siemens) sets the limit of constant surface speed, now or later.
        if let Some(max) = self.slot(Role::SpindleLimit) {
            self.lathe_word();
            self.set_spindle_limit(max, sink);
        }
        // `G50 S3200` on a lathe limits the speed; it does not set it.
        let limit = self.codes.iter().any(|&(c, _)| self.code(c).meaning == Meaning::SpindleLimit);
        if let Some(s) = self.slot(Role::S).filter(|_| !limit) {
            self.st.speed = s;
            self.emit(sink, CanonOp::SetSpindleSpeed(s));
        }
    }

    /// Limits the spindle speed under constant surface speed (`G50 S`, `LIMS=`), at once when
    /// it is on.
    fn set_spindle_limit(&mut self, max: f64, sink: &mut dyn CanonSink) {
        self.st.spindle_limit = Some(max);
        if self.st.css_max.is_some_and(|m| m != max) {
            self.st.css_max = Some(max);
            self.emit(sink, CanonOp::SetSpindleMode(Some(max)));
        }
    }

    /// M7 (mist), M8 (flood), M9 (both off).
    pub(super) fn coolant(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        match def.meaning {
            Meaning::CoolantMist => {
                self.st.mist = true;
                self.emit(sink, CanonOp::MistOn);
            }
            Meaning::CoolantFlood => {
                self.st.flood = true;
                self.emit(sink, CanonOp::FloodOn);
            }
            _ => {
                self.st.mist = false;
                self.st.flood = false;
                self.emit(sink, CanonOp::MistOff);
                self.emit(sink, CanonOp::FloodOff);
            }
        }
    }
}

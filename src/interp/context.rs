//! Saved modal state (LinuxCNC's M70 to M73): a snapshot per call level, restored on
//! request or when the call that saved it returns.

use super::eval::UnknownSource;
use super::{Interpreter, Retract, Spindle};
use crate::canon::{CanonOp, CanonSink, DistanceMode, FeedMode, Plane, Units};
use crate::diag::{Code, Diagnostic};
use crate::dialect::CodeDef;
use crate::syntax::{Block, ParamTarget};
use crate::text::TextRange;

/// The modes a save keeps: those LinuxCNC restores.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Context {
    units: Units,
    plane: Plane,
    distance: DistanceMode,
    arc_incremental: bool,
    inverse_time: bool,
    feed_per_rev: bool,
    feed: f64,
    speed: f64,
    spindle: Spindle,
    mist: bool,
    flood: bool,
    wcs: u16,
    retract: Retract,
    /// Restored when the call that saved it returns (M73).
    autorestore: bool,
}

impl Interpreter<'_> {
    fn snapshot(&self, autorestore: bool) -> Context {
        let st = &self.st;
        Context {
            units: st.units,
            plane: st.plane,
            distance: st.distance,
            arc_incremental: st.arc_incremental,
            inverse_time: st.inverse_time,
            feed_per_rev: st.feed_per_rev,
            feed: st.feed,
            speed: st.speed,
            spindle: st.spindle,
            mist: st.mist,
            flood: st.flood,
            wcs: st.wcs,
            retract: st.retract,
            autorestore,
        }
    }

    /// M70 and M73 save, M71 forgets, M72 restores: each at the current call level.
    pub(super) fn modal_context(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        use crate::dialect::Meaning;
        let level = self.depth as usize;
        if self.contexts.len() <= level {
            self.contexts.resize(level + 1, None);
        }
        match def.meaning {
            Meaning::StateSave => self.contexts[level] = Some(self.snapshot(false)),
            Meaning::StateSaveAutorestore => self.contexts[level] = Some(self.snapshot(true)),
            Meaning::StateInvalidate => self.contexts[level] = None,
            _ => match self.contexts[level].clone() {
                Some(saved) => self.restore(&saved, sink),
                None => diags.push(Diagnostic::new(
                    Code::UnmatchedStatement,
                    range,
                    format!("{}: no state was saved at this call level (M70 or M73 first)", def.label()),
                )),
            },
        }
    }

    /// The call at `level` returns: its saved state goes, restored first if M73 saved it.
    pub(super) fn leave_level(&mut self, level: usize, sink: &mut dyn CanonSink) {
        if let Some(saved) = self.contexts.get_mut(level).and_then(Option::take)
            && saved.autorestore
        {
            self.restore(&saved, sink);
        }
    }

    /// Sets the saved modes again, with the calls LinuxCNC makes, in its order (units, feed,
    /// speed, spindle, coolant, plane, system, distance); only what changed is set. Coolant
    /// follows LinuxCNC: a saved mist or flood is switched on, and both go off only when
    /// neither was on. A changed feed mode leaves the feed rate as the mode change sets it.
    fn restore(&mut self, saved: &Context, sink: &mut dyn CanonSink) {
        if saved.units != self.st.units {
            self.set_units(saved.units);
            self.emit(sink, CanonOp::UseLengthUnits(saved.units));
        }
        let mode_changed = (saved.inverse_time, saved.feed_per_rev) != (self.st.inverse_time, self.st.feed_per_rev);
        if mode_changed {
            self.st.inverse_time = saved.inverse_time;
            self.st.feed_per_rev = saved.feed_per_rev;
            self.emit(sink, CanonOp::SetFeedMode(if saved.feed_per_rev { FeedMode::PerRevolution } else { FeedMode::PerMinute }));
            if self.dialect.behaviour.feed_mode_resets_feed {
                self.st.feed = 0.0;
                self.emit(sink, CanonOp::SetFeedRate(0.0));
            }
        } else if saved.feed != self.st.feed {
            self.st.feed = saved.feed;
            self.emit(sink, CanonOp::SetFeedRate(saved.feed));
        }
        if saved.speed != self.st.speed {
            self.st.speed = saved.speed;
            self.emit(sink, CanonOp::SetSpindleSpeed(saved.speed));
        }
        if saved.spindle != self.st.spindle {
            self.st.spindle = saved.spindle;
            self.emit(
                sink,
                match saved.spindle {
                    Spindle::Cw => CanonOp::StartSpindleClockwise,
                    Spindle::Ccw => CanonOp::StartSpindleCounterclockwise,
                    Spindle::Stopped => CanonOp::StopSpindleTurning,
                },
            );
        }
        if saved.mist && !self.st.mist {
            self.st.mist = true;
            self.emit(sink, CanonOp::MistOn);
        }
        if saved.flood && !self.st.flood {
            self.st.flood = true;
            self.emit(sink, CanonOp::FloodOn);
        }
        if !saved.mist && !saved.flood && (self.st.mist || self.st.flood) {
            self.st.mist = false;
            self.st.flood = false;
            self.emit(sink, CanonOp::MistOff);
            self.emit(sink, CanonOp::FloodOff);
        }
        if saved.plane != self.st.plane {
            self.st.plane = saved.plane;
            self.emit(sink, CanonOp::SelectPlane(saved.plane));
        }
        if saved.wcs != self.st.wcs {
            self.select_wcs(saved.wcs, sink);
        }
        if saved.distance != self.st.distance {
            self.st.distance = saved.distance;
            self.emit(sink, CanonOp::DistanceMode(saved.distance));
        }
        self.st.arc_incremental = saved.arc_incremental;
        self.st.retract = saved.retract;
    }
}

/// A parameter an assignment sets, and the value it held before.
enum Before {
    Numbered(f64, f64),
    Named(String, f64),
}

impl Interpreter<'_> {
    /// Runs `block`, whose condition the analysis could not decide: each parameter it sets
    /// then holds either its old value or the new one, and one that changed is unknown, as
    /// the outside value the condition read (`from`), which a message then names.
    pub(super) fn execute_either(
        &mut self,
        block: &Block,
        from: Option<UnknownSource>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let mut scratch = Vec::new();
        let mut before = Vec::new();
        for a in &block.assigns {
            match a.target {
                ParamTarget::Numbered(e) => {
                    if let Ok(n) = self.eval(block, e, a.range, &mut scratch)
                        && let Ok(v) = self.params.get(n)
                    {
                        before.push(Before::Numbered(n, v));
                    }
                }
                ParamTarget::Named(r) => {
                    let name = super::eval::normalise_name(block.text(r));
                    let v = self.params.get_named(&name).unwrap_or(super::eval::UNKNOWN);
                    before.push(Before::Named(name, v));
                }
                ParamTarget::NamedIndex(..) => {}
            }
        }
        self.params.take_unknown_read();
        self.execute(block, sink, diags);
        let same = |a: f64, b: f64| a.to_bits() == b.to_bits() || a == b;
        for b in before {
            match b {
                Before::Numbered(n, old) => {
                    if self.params.get(n).is_ok_and(|v| !same(v, old)) {
                        let _ = self.params.set(n, super::eval::UNKNOWN);
                        if n >= 0.0 && n.fract() == 0.0 && n <= f64::from(u32::MAX) {
                            self.params.derive(UnknownSource::Numbered(n as u32), from.clone());
                        }
                    }
                }
                Before::Named(name, old) => {
                    if self.params.get_named(&name).is_ok_and(|v| !same(v, old)) {
                        self.params.set_named(&name, super::eval::UNKNOWN);
                        self.params.derive(UnknownSource::Named(name), from.clone());
                    }
                }
            }
        }
        self.params.take_unknown_read();
    }
}

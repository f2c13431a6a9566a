//! The feed: its modes (G93 inverse time, G94 per minute, G95 per revolution), the F word,
//! and the feed and speed override switches (M48 to M51).
//!
//! Doors: [`Interpreter::feed_mode`], [`Interpreter::feed_word`], [`Interpreter::overrides`].

use crate::canon::{CanonOp, CanonSink, FeedMode};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::interp::Interpreter;

impl Interpreter<'_> {
    /// G93, G94, G95: how F reads.
    pub(super) fn feed_mode(&mut self, meaning: Meaning, sink: &mut dyn CanonSink) {
        if meaning == Meaning::FeedInverseTime {
            self.st.inverse_time = true;
            if self.st.feed_per_rev {
                self.st.feed_per_rev = false;
                self.emit(sink, CanonOp::SetFeedMode(FeedMode::PerMinute));
            }
            return;
        }
        self.st.inverse_time = false;
        let per_rev = meaning == Meaning::FeedPerRev;
        if per_rev != self.st.feed_per_rev {
            self.st.feed_per_rev = per_rev;
            self.emit(sink, CanonOp::SetFeedMode(if per_rev { FeedMode::PerRevolution } else { FeedMode::PerMinute }));
        }
        if self.dialect.behaviour.feed_mode_resets_feed {
            self.st.feed = 0.0;
            self.st.feed_unknown = false;
            self.st.feed_outside = false;
            self.emit(sink, CanonOp::SetFeedRate(0.0));
        }
    }

    /// The feed step: the block's F word sets the feed rate.
    pub(super) fn feed_word(&mut self, sink: &mut dyn CanonSink) {
        // A dwell that takes F (Siemens `G4 F2.5`) reads it as seconds, not as a feed.
        // So does a cycle definition (`CYCL DEF 1.5 F80`): the cycle's own feed.
        let dwell_f = self.codes.iter().any(|&(c, _)| {
            let d = self.code(c);
            (d.meaning == Meaning::Dwell && d.params.takes(Role::F)) || d.meaning == Meaning::CycleDefine
        });
        if let Some(f) = self.slot(Role::F).filter(|_| !dwell_f) {
            if self.st.inverse_time {
                // Each feed move of the block turns F into a rate (see `inverse_time_feed`).
                return;
            }
            if self.st.feed_per_rev && f > 0.0 {
                self.per_rev_feeds = (self.per_rev_feeds.0 + 1, self.per_rev_feeds.1.max(f));
                self.css_units_evidence();
            }
            self.st.feed = f;
            self.st.feed_unknown = false;
            self.st.feed_outside = false;
            self.st.tech_warned = false;
            self.emit(sink, CanonOp::SetFeedRate(f));
        }
    }

    /// Under constant surface speed with a limit, at the diameter the tool stands on: whether
    /// the surface speed fits only inches (see `css_fit`).
    fn css_units_evidence(&mut self) {
        let (Some(max), s, d) = (self.st.css_max, self.st.speed, 2.0 * self.st.pos[0].abs()) else { return };
        if max >= crate::canon::NO_SPINDLE_LIMIT || s <= 0.0 || d <= 0.0 {
            return;
        }
        let rpm_mm = 1000.0 * s / (std::f64::consts::PI * d);
        let rpm_inch = 12.0 * s / (std::f64::consts::PI * d);
        if rpm_mm <= max {
            self.css_fit.0 += 1;
        } else if rpm_inch <= max {
            self.css_fit.1 += 1;
        }
    }

    /// M48, M49 (both overrides on or off), M50 (feed), M51 (speed): `P0` turns one off.
    pub(super) fn overrides(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        match def.meaning {
            Meaning::FeedOverrideSwitch => {
                let on = self.slot(Role::P).is_none_or(|p| p != 0.0);
                self.st.overrides.0 = on;
                self.emit(sink, CanonOp::FeedOverride(on));
            }
            Meaning::SpeedOverrideSwitch => {
                let on = self.slot(Role::P).is_none_or(|p| p != 0.0);
                self.st.overrides.1 = on;
                self.emit(sink, CanonOp::SpeedOverride(on));
            }
            _ => {
                let on = def.meaning == Meaning::OverridesOn;
                self.st.overrides = (on, on);
                self.emit(sink, CanonOp::FeedOverride(on));
                self.emit(sink, CanonOp::SpeedOverride(on));
            }
        }
    }
}

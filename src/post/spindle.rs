//! The spindle: its speed (written with the next cut or spindle start, or in the tool
//! change's block), its turning, constant surface speed, its orientation, and the feeds
//! synchronised with it (threads, rigid taps).
//!
//! The door: [`Post::spindle_op`] for the spindle ops, [`Post::sync_op`] for the
//! spindle-synchronised ones, and [`Post::flush_speed`], which writes a new speed before
//! what needs it.

use super::{EPS, Post, Vals};
use crate::canon::{Canon, CanonOp, FeedMode};
use crate::diag::Code;
use crate::dialect::output::Value;

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// Writes a spindle op: its speed, its start and stop, constant surface speed, its
    /// orientation.
    pub(super) fn spindle_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::SetSpindleSpeed(s) => {
                // Under constant surface speed S is a cutting speed in the program's units
                // (m/min, ft/min in inches): converted with them.
                let s = if self.css { *s * self.css_factor() } else { *s };
                if (s - self.speed).abs() > EPS {
                    self.speed_dirty = true;
                }
                self.speed = s;
                self.check_limits(canon);
            }
            // A cycle written as a cycle turns the spindle as it does (a tapping cycle's
            // reversal at the bottom): its expansion's spindle calls are not written.
            CanonOp::StartSpindleClockwise | CanonOp::StartSpindleCounterclockwise | CanonOp::StopSpindleTurning if self.in_cycle => {}
            CanonOp::StartSpindleClockwise | CanonOp::StartSpindleCounterclockwise => self.start_spindle(canon),
            CanonOp::StopSpindleTurning if self.spindle_on => {
                self.spindle_on = false;
                self.event("spindle-stop", &mut Vals::new());
            }
            CanonOp::SetSpindleMode(max) => self.spindle_mode(canon, max),
            CanonOp::OrientSpindle { angle, mode } => self.orient_spindle(canon, angle, mode),
            // The wait for the orientation (LinuxCNC's `M19 Q`): every target's orientation code
            // ends once the spindle is oriented, before the next block runs.
            CanonOp::WaitOrientComplete(_) => {}
            // The spindle already stopped, or not a spindle op ([`Post::other_op`] hands none).
            _ => {}
        }
    }

    /// What a cutting speed in the source's units is multiplied by in the target's: 1, or
    /// ft/min ↔ m/min (0.3048 m a foot) where the program is written in other units.
    fn css_factor(&self) -> f64 {
        if self.scale > 1.0 + 1e-9 {
            0.3048
        } else if self.scale < 1.0 - 1e-9 {
            1.0 / 0.3048
        } else {
            1.0
        }
    }

    /// Writes a new speed before a cut (even with the spindle off: the technology says it),
    /// or before anything else while the spindle turns.
    pub(super) fn flush_speed(&mut self, cutting: bool) {
        if self.speed_dirty && (self.spindle_on || cutting) {
            self.speed_dirty = false;
            let mut vals = Vals::new();
            vals.set(Value::S, self.speed);
            self.event("speed", &mut vals);
        }
    }

    /// Starts the spindle turning (clockwise or not, as `canon` says), with the speed in force.
    fn start_spindle(&mut self, canon: &Canon) {
        let cw = matches!(canon.op, CanonOp::StartSpindleClockwise);
        let ev = if cw { "spindle-cw" } else { "spindle-ccw" };
        if self.speed_dirty && self.out.template(ev).is_some_and(|(t, _)| !t.uses(Value::S)) {
            let mut vals = Vals::new();
            vals.set(Value::S, self.speed);
            self.event("speed", &mut vals);
            self.speed_dirty = false;
        }
        let mut vals = Vals::new();
        vals.set(Value::S, self.speed);
        if self.speed_dirty {
            self.set_written(4, None);
        }
        self.speed_dirty = false;
        self.spindle_on = true;
        self.event(if cw { "spindle-cw" } else { "spindle-ccw" }, &mut vals);
    }

    /// Puts constant surface speed in force up to spindle speed `max` (G96), or out of force
    /// (`None`, G97).
    fn spindle_mode(&mut self, canon: &Canon, max: &Option<f64>) {
        let on = max.is_some();
        if on || self.css {
            let ev = self.css_event(on);
            let mut vals = Vals::new();
            let limit = max.filter(|m| *m < crate::canon::NO_SPINDLE_LIMIT);
            if let Some(m) = limit {
                vals.set(Value::SpindleMax, m);
            }
            let states_limit = self.out.template(ev).is_some_and(|(t, _)| t.uses(Value::SpindleMax));
            if let Some(m) = limit.filter(|_| on && !states_limit && self.out.template(ev).is_some()) {
                // Written without it, the limit would be lost without a word.
                self.note(
                    Code::PostUnwritable,
                    canon,
                    "css-limit",
                    format!("constant surface speed up to S{m}: the target's `css-on` states no spindle speed limit"),
                );
            } else if self.event(ev, &mut vals) {
                self.css = on;
                self.css_limit = limit;
                self.radius_for_lathe();
            } else {
                self.note(
                    Code::PostUnwritable,
                    canon,
                    ev,
                    format!("constant surface speed (G96/G97) is not written: the target's output rules have no `{ev}` template"),
                );
            }
        }
    }

    /// The event that puts constant surface speed in force (`on`) or out of it, keeping the
    /// feed type: on a target whose G96/G97 also set the feed per revolution, the per-minute
    /// forms (G961/G971) where the feed is per minute.
    pub(super) fn css_event(&self, on: bool) -> &'static str {
        match (on, self.opts.css_sets_feed_per_rev && self.feed_mode == FeedMode::PerMinute) {
            (true, false) => "css-on",
            (false, false) => "css-off",
            (true, true) => "css-on-per-minute",
            (false, true) => "css-off-per-minute",
        }
    }

    /// Stops the spindle at `angle` degrees, turning the way `mode` says (M19, SPOS).
    fn orient_spindle(&mut self, canon: &Canon, angle: &f64, mode: &u8) {
        self.spindle_on = false;
        let t = self.out.template("spindle-orient").map(|(t, _)| (t.uses(Value::Angle), t.uses(Value::OrientDir)));
        match t {
            Some((a, d)) if (a || angle.abs() < EPS) && (d || *mode == 0) => {
                let mut vals = Vals::new();
                vals.set(Value::Angle, *angle).set(Value::OrientDir, f64::from(*mode));
                self.event("spindle-orient", &mut vals);
            }
            Some(_) => self.note(
                Code::PostUnwritable,
                canon,
                "spindle-orient",
                format!(
                    "a spindle orientation to {angle}° (direction {mode}) is not written: the target's `spindle-orient` states no angle or direction"
                ),
            ),
            None => self.note(
                Code::PostUnwritable,
                canon,
                "spindle-orient",
                "a spindle orientation (M19, SPOS) is not written: the target's output rules have no `spindle-orient` template",
            ),
        }
    }

    /// Writes an op of the feeds synchronised with the spindle: the moves that follow
    /// advance a pitch per revolution (a thread, [`Post::straight`]), or no longer do; a
    /// rigid tap.
    pub(super) fn sync_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::StartSpeedFeedSync(p) => self.sync = Some(self.to_out(*p)),
            CanonOp::StopSpeedFeedSync => {
                self.sync = None;
                // The thread's lead may have been written in the feed's address (Fanuc G33 F).
                self.set_written(3, None);
                self.motion = None;
            }
            CanonOp::RigidTap(t) => {
                let q = self.point(t);
                if self.in_cycle {
                    // The tapping cycle written for it drills it.
                } else if self.out.template("rigid-tap").is_some() {
                    let mut vals = Vals::new();
                    vals.set(Value::X, q[0]).set(Value::Y, q[1]).set(Value::Z, q[2]).set(Value::Pitch, self.sync.unwrap_or(0.0));
                    self.unknown_out(&mut vals);
                    self.event("rigid-tap", &mut vals);
                    self.motion = None;
                } else {
                    self.note(
                        Code::PostUnwritable,
                        canon,
                        "rigid-tap",
                        "a rigid tap (G33.1) is not written: the target has neither a tapping cycle nor a `rigid-tap` template",
                    );
                }
            }
            // Not a synchronised op: [`Post::other_op`] hands none here.
            _ => {}
        }
    }
}

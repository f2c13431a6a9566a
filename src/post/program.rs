//! The program's own events: stops and its end, comments and messages, dwells, coolant,
//! and what the target has no rule for (said, never silently dropped).
//!
//! The door: [`Post::stop_op`], [`Post::comment`], [`Post::dwell`], [`Post::coolant_op`] and
//! [`Post::unwritable`].

use super::{Post, Vals};
use crate::canon::{Canon, CanonOp};
use crate::diag::Code;
use crate::dialect::output::Value;

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// Writes a stop op: a program stop, an optional stop, the program's end (once; what
    /// follows it is not written). The end at the closing `%` writes nothing: the footer ends
    /// the program ([`Post::finish`]).
    pub(super) fn stop_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::ProgramStop => {
                self.cancel_cycle();
                self.event("stop", &mut Vals::new());
            }
            CanonOp::OptionalProgramStop => {
                self.cancel_cycle();
                self.event("optional-stop", &mut Vals::new());
            }
            CanonOp::ProgramEnd => {
                self.cancel_cycle();
                if !self.ended {
                    self.ended = true;
                    self.event("end", &mut Vals::new());
                }
            }
            CanonOp::Finish => {}
            // Not a stop op: [`Post::other_op`] hands none here.
            _ => {}
        }
    }

    /// Writes `text` as the target's `event` (`comment`, `message`), or as a comment where
    /// the target has no such event, without the characters its comments may not hold.
    pub(super) fn comment(&mut self, text: &str, event: &str) {
        let mut t: String = text.chars().map(|c| if self.out.comment_forbidden.contains(c) || c.is_control() { ' ' } else { c }).collect();
        if self.out.comment_upper {
            t = t.to_uppercase();
        }
        let t = t.trim();
        let mut vals = Vals::new();
        vals.text = Some(t.to_owned());
        if !self.event(event, &mut vals) && event != "comment" {
            self.event("comment", &mut vals);
        }
    }

    /// Writes a dwell of `s` seconds; a dwell within a cycle written as a cycle is the
    /// cycle's.
    pub(super) fn dwell(&mut self, canon: &Canon, s: &f64) {
        let mut vals = Vals::new();
        vals.set(Value::Seconds, *s).set(Value::Millis, s * 1000.0);
        if !self.in_cycle && !self.event("dwell", &mut vals) {
            self.note(Code::PostUnwritable, canon, "dwell", "the target's output rules have no `dwell` template");
        }
    }

    /// Writes a coolant op: flood or mist on (flood where the target has no mist), off.
    pub(super) fn coolant_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::FloodOn | CanonOp::MistOn => {
                self.coolant = true;
                let ev = if matches!(canon.op, CanonOp::FloodOn) { "flood-on" } else { "mist-on" };
                if !self.event(ev, &mut Vals::new()) {
                    self.event("flood-on", &mut Vals::new());
                }
            }
            CanonOp::FloodOff | CanonOp::MistOff if self.coolant => {
                self.coolant = false;
                self.event("coolant-off", &mut Vals::new());
            }
            // The coolant already off, or not a coolant op ([`Post::other_op`] hands none).
            _ => {}
        }
    }

    /// Says that an op the target's output rules have nothing for is not written, once for
    /// each kind of op.
    pub(super) fn unwritable(&mut self, canon: &Canon) {
        let name = format!("{:?}", canon.op);
        let key = name.split(['(', ' ', '{']).next().unwrap_or("").to_owned();
        self.note(Code::PostUnwritable, canon, &key, format!("`{key}` is not written: the target's output rules have nothing for it"));
    }
}

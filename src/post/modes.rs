//! The modal settings that say how the moves' numbers are read: units, plane and distance
//! mode, feed rate and feed mode, work offsets and coordinate shifts (G92). Positions are
//! written absolute, in the target's units, in the work offset's frame with the shift added.
//!
//! The door: [`Post::mode_op`] (units, plane, distance mode), [`Post::feed_op`] (feed rate
//! and mode), [`Post::offset_op`] (work offsets, shifts), and [`Post::check_work_offset`],
//! which each move asks.

use super::{Post, ROUNDED_NOTE, Vals};
use crate::canon::{Canon, CanonOp, FeedMode, Plane, Setting, Units};
use crate::diag::Code;
use crate::dialect::output::Value;

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// Writes a mode op: the units, the plane, the distance mode (nothing: positions are
    /// written absolute).
    pub(super) fn mode_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::UseLengthUnits(u) => self.use_units(canon, u),
            CanonOp::SelectPlane(p) if *p != self.plane => {
                self.plane = *p;
                let ev = match p {
                    Plane::Xy => "plane-xy",
                    Plane::Xz => "plane-xz",
                    Plane::Yz => "plane-yz",
                };
                if !self.event(ev, &mut Vals::new()) {
                    self.note(Code::PostUnwritable, canon, ev, format!("the target's output rules have no `{ev}` template"));
                }
            }
            CanonOp::DistanceMode(_) => {}
            // The plane unchanged, or not a mode op ([`Post::other_op`] hands none).
            _ => {}
        }
    }

    /// The source states the diameter or the radius mode (G7/G8, DIAMON/DIAMOF, or a lathe
    /// dictionary's diameters from the start). X words are then written as the target reads
    /// them: a target that reads diameters from the start (a lathe's dictionary) takes them
    /// doubled with no code; one with a diameter mode (`diameter-on`: G7, DIAMON) is put in it
    /// and takes them doubled; one with only a radius mode (`diameter-off`: G8, DIAMOF) is put
    /// in that and takes radii. The radius mode the source states is written where the target
    /// has one (`diameter-off`); where it has none but reads diameters, X stays written as
    /// diameters, which runs the same. A target with neither mode that reads radii is a
    /// milling control's: a program in diameters is not written for it (unwritable), since
    /// read back it would not be known to turn; the radius mode needs no code there.
    pub(super) fn diameter_mode(&mut self, canon: &Canon, on: bool) {
        self.turns = true;
        self.x_told = true;
        let has = |p: &Self, e: &str| p.out.template(e).is_some();
        if !self.opts.x_diameter && !has(self, "diameter-on") && !has(self, "diameter-off") {
            if on {
                self.note(
                    Code::PostUnwritable,
                    canon,
                    "diameter-mode",
                    "the program turns (the diameter mode: X words as diameters), and the target is a milling control: its output rules have no diameter or radius mode (`diameter-on`, `diameter-off`) and it reads X words as radii; a lathe program is translated only for a lathe's dictionary (or LinuxCNC, Siemens)",
                );
            } else {
                // X words as radii are what a mill reads: the motion is the same.
                self.note(
                    Code::PostModeImplied,
                    canon,
                    "radius-mode",
                    "the radius mode (X words as radii) is not written: the target reads X words as radii and its output rules have no `diameter-off` template; read back, the program is not known to turn",
                );
            }
            return;
        }
        if on {
            if self.x_diam {
                // The target reads diameters already.
            } else if self.event("diameter-on", &mut Vals::new()) {
                self.set_x_diameter(true);
            } else {
                // The radius mode: X is written as the canonical radius.
                self.event("diameter-off", &mut Vals::new());
            }
        } else if self.event("diameter-off", &mut Vals::new()) {
            self.set_x_diameter(false);
        }
    }

    /// A program that turns with X words as radii, written for a target whose lathes read
    /// them as diameters from reset (`Options::lathe_reset_diameter`: SINUMERIK DIAMON) with
    /// constant surface speed, which shows the control a lathe: its radius mode is stated
    /// once, where nothing stated it (read back, the program reads radii throughout).
    pub(super) fn radius_for_lathe(&mut self) {
        if self.opts.lathe_reset_diameter && self.turns && self.css && !self.x_diam && !self.x_told {
            self.x_told = true;
            self.event("diameter-off", &mut Vals::new());
        }
    }

    /// X words are written as diameters (`on`) or radii from here: the last X written is
    /// forgotten, so that the next move states X in the new reading.
    fn set_x_diameter(&mut self, on: bool) {
        if self.x_diam != on {
            self.x_diam = on;
            self.set_written(0, None);
        }
    }

    /// The first move: a target that reads X words as diameters (a lathe's dictionary) takes
    /// only a program that turns. One that never said so (no diameter or radius mode, no
    /// lathe cycle, not in the ZX plane) is a milling program: not written for a lathe.
    pub(super) fn first_move(&mut self, canon: &Canon) {
        self.moved_yet = true;
        self.turns |= self.plane == Plane::Xz;
        self.radius_for_lathe();
        if self.opts.x_diameter && !self.turns {
            self.note(
                Code::PostUnwritable,
                canon,
                "mill-to-lathe",
                "the program does not turn (it states no diameter or radius mode and no lathe cycle, and moves first outside the ZX plane), and the target is a lathe's dictionary, which reads X words as diameters: a milling program is not translated for a lathe",
            );
        }
    }

    /// A lathe cycle (G71, CYCLE95, G76): written as the moves it makes, which follow.
    pub(super) fn lathe_cycle(&mut self, canon: &Canon, t: &crate::canon::TurnIntent) {
        self.turns = true;
        self.radius_for_lathe();
        self.note(
            Code::PostCycleAsMoves,
            canon,
            &format!("lathe-cycle {}", t.code),
            format!("the lathe cycle {} is written as the moves it makes: the output rules write no lathe cycle", t.code),
        );
    }

    /// The program's numbers are in units `u` from here on: the program is written in them
    /// where it follows the source's units and nothing is written yet; else converted, and
    /// said.
    fn use_units(&mut self, canon: &Canon, u: &Units) {
        if self.opts.follow_source_units && !self.started && *u != self.opts.units {
            // What was set before the units (a feed: `G20 F60` sets F first, in
            // the units then in force) is held in the target's units: it changes
            // units with them, so that F60 mm/min comes out as F2.3622 inch/min.
            let k = self.opts.units.to_mm() / u.to_mm();
            self.feed *= k;
            self.g92 = self.g92.map(|v| v * k);
            self.pos = self.pos.map(|v| v * k);
            self.opts.units = *u;
            // What was written, known in the other units, is rounded again.
            for k in 0..8 {
                let w = self.written[k];
                self.set_written(k, w);
            }
        }
        self.scale = u.to_mm() / self.opts.units.to_mm();
        if *u != self.opts.units {
            self.note(
                Code::PostUnitsConverted,
                canon,
                "units",
                format!("the program is in {}; it is written in {} for the target machine", unit_name(*u), unit_name(self.opts.units)),
            );
        }
    }

    /// Writes a feed op: the feed rate (checked against the machine's), the feed mode.
    pub(super) fn feed_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::SetFeedRate(f) => {
                self.feed = self.to_out(*f);
                self.check_limits(canon);
            }
            CanonOp::SetFeedMode(m) if *m != self.feed_mode => {
                self.feed_mode = *m;
                let ev = if *m == FeedMode::PerMinute { "feed-per-minute" } else { "feed-per-rev" };
                if !self.event(ev, &mut Vals::new()) {
                    self.note(Code::PostUnwritable, canon, ev, format!("the target's output rules have no `{ev}` template"));
                } else if self.css && self.opts.feed_mode_ends_css {
                    // The target's feed type ends constant surface speed (SINUMERIK group 15):
                    // it is put in force again, with its limit.
                    let mut vals = Vals::new();
                    if let Some(m) = self.css_limit {
                        vals.set(Value::SpindleMax, m);
                    }
                    let ev = self.css_event(true);
                    if !self.event(ev, &mut vals) {
                        let msg = format!(
                            "constant surface speed under this feed type is not written: the target's output rules have no `{ev}` template"
                        );
                        self.note(Code::PostUnwritable, canon, ev, msg);
                    }
                }
            }
            // The feed mode unchanged, or not a feed op ([`Post::other_op`] hands none).
            _ => {}
        }
    }

    /// Writes an offset op: a work offset put in force (or its values changed), a shift.
    pub(super) fn offset_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::SetG5xOffset(i, v) => {
                // An axis whose position is unknown stays where it was: its number in the new
                // frame moves by the offsets' difference, as the source's does (not a move).
                let (old, known) = (self.wcs_now, self.known);
                for (k, (was, now)) in old.iter().zip(v.iter()).enumerate() {
                    if known & 1 << k == 0 {
                        if k < 3 {
                            let d = self.to_out(was - now);
                            self.pos[k] += d;
                        } else {
                            self.abc[k - 3] += was - now;
                        }
                    }
                }
                self.work_offset(canon, i, v);
            }
            // Stated though in force: written where the target has not written it yet.
            CanonOp::Setting(Setting::WorkOffset(i)) => {
                let v = self.wcs_now;
                self.work_offset(canon, i, &v);
            }
            CanonOp::SetG92Offset(o) => {
                self.g92 = [self.to_out(o[0]), self.to_out(o[1]), self.to_out(o[2])];
                if self.g92.iter().any(|v| v.abs() * self.opts.units.to_mm() > ROUNDED_NOTE) {
                    self.note(
                        Code::PostShiftApplied,
                        canon,
                        "shift",
                        "the program shifts its coordinates (G92, a datum shift): the positions are written with the shift added, in the work offset's frame",
                    );
                }
            }
            // Not an offset op: [`Post::other_op`] hands none here.
            _ => {}
        }
    }

    /// Work offset `i` (with values `v`) is in force: written where it changes, by its own
    /// template or the general one; said where the target has no code for it.
    fn work_offset(&mut self, canon: &Canon, i: &u16, v: &[f64; 6]) {
        self.wcs_now = *v;
        self.wcs_checked = false;
        if self.wcs != Some(*i) {
            self.wcs = Some(*i);
            let mut vals = Vals::new();
            vals.set(Value::Wcs, f64::from(*i)).set(Value::WcsCode, 53.0 + f64::from(*i));
            // A work offset of its own (`work-offset-7`: G59.1, G507) before the
            // general rule, which states G54…G59 only; an empty one says the target
            // has no code for it.
            let extended = *i > crate::canon::EXTENDED_WCS;
            // An additional work offset (`G54.1 P12`) by its own number.
            let own = if extended { "work-offset-extended".to_owned() } else { format!("work-offset-{i}") };
            if extended {
                vals.set(Value::Wcs, f64::from(*i - crate::canon::EXTENDED_WCS));
            }
            let out = self.out;
            let wrote = match out.template(&own) {
                Some((t, _)) if t.0.is_empty() => false,
                Some(_) => self.event(&own, &mut vals),
                None if extended => false,
                // No settable work offset (Siemens G500): only a target that says how.
                None if *i == 0 => false,
                None if *i > 6 && out.template("work-offset").is_some_and(|(t, _)| t.uses(Value::WcsCode)) => false,
                None => self.event("work-offset", &mut vals),
            };
            if !wrote && extended {
                let n = *i - crate::canon::EXTENDED_WCS;
                self.note(
                    Code::PostUnwritable,
                    canon,
                    &own,
                    format!("the target's output rules have no code for additional work offset {n} (G54.1 P{n}: `{own}`)"),
                );
            } else if !wrote && *i == 0 {
                let msg = "the target's output rules have no code that switches the settable work offset off (Siemens G500, `work-offset-0`): the program's positions from here on are in the basic frame";
                self.note(Code::PostUnwritable, canon, &own, msg);
            } else if !wrote && *i != 1 {
                self.note(
                    Code::PostUnwritable,
                    canon,
                    &own,
                    format!("the target's output rules have no code for work offset {i} (`{own}`, `work-offset`)"),
                );
            }
        }
    }

    /// A move in the work offset in force: its values are the frame the translation is
    /// written in, unless the program changed them after moving in it.
    pub(super) fn check_work_offset(&mut self, canon: &Canon) {
        if self.wcs_checked {
            return;
        }
        self.wcs_checked = true;
        let i = self.wcs.unwrap_or(1);
        let now = self.wcs_now;
        match self.wcs_values.iter().find(|(k, _)| *k == i) {
            None => self.wcs_values.push((i, now)),
            Some((_, first)) if first.iter().zip(&now).any(|(a, b)| (a - b).abs() > 1e-9) => self.note(
                Code::PostUnwritable,
                canon,
                "work-offset-set",
                "the program changes the values of the work offset it moves in (G10 L2/L20 while active): the translation is written in the offset's frame as the program first used it, and the target's output rules cannot change it",
            ),
            Some(_) => {}
        }
    }
}

/// The name of units `u`, in a note.
fn unit_name(u: Units) -> &'static str {
    match u {
        Units::Mm => "millimetres",
        Units::Inch => "inches",
    }
}

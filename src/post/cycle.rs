//! Canned cycles: a hole of a cycle whose kind the target maps is written as the target's
//! cycle (defined once, then each further hole), unless the two cycles would drill it
//! another way; every other hole is left to the moves the interpreter expands it into, with
//! a note saying why.
//!
//! The door: [`Post::cycle_op`] for the cycle ops (`CycleBegin`, `CycleEnd`, `CycleCancel`),
//! [`Post::cancel_cycle`] for whatever ends the output cycle in force, and [`ActiveCycle`],
//! that cycle as the writer keeps it.

use super::{Post, Vals};
use crate::canon::{Canon, CanonOp, CycleIntent, CycleKind, FeedMode, Plane};
use crate::diag::Code;
use crate::dialect::output::{CycleOut, Value};

/// The output cycle in force: its mapping and the parameters it was defined with.
pub(super) struct ActiveCycle {
    index: usize,
    params: [f64; 7],
}

/// The levels of a cycle's hole, in the target's units and the work offset's frame.
#[derive(Clone, Copy)]
struct Hole {
    x: f64,
    y: f64,
    bottom: f64,
    r: f64,
    clear: f64,
}

/// Whether one output cycle writes the workpiece surface.
fn states_surface_cycle(c: &CycleOut) -> bool {
    [Value::Surface, Value::Sdis, Value::Depth, Value::ClearDist].iter().any(|v| c.define.uses(*v) || c.at.uses(*v))
}

impl<'a, F: FnMut(&[u8])> Post<'a, F> {
    /// Writes a cycle op: a hole begins ([`Post::cycle_begin`]) or ends, or the cycle is
    /// cancelled (G80).
    pub(super) fn cycle_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::CycleBegin(intent) => self.cycle_begin(canon, intent),
            CanonOp::CycleEnd if self.in_cycle => {
                self.in_cycle = false;
                let p = self.pos;
                for (k, f) in ["X", "Y", "Z"].iter().enumerate() {
                    // Its rounding not yet kept: the next move rounds it again.
                    let w = self.key_of(f, p[k]).map(|(key, _)| (key, f64::NAN));
                    self.set_written(k, w);
                }
            }
            CanonOp::CycleCancel => self.cancel_cycle(),
            // A hole not drilled as a cycle ends, or not a cycle op ([`Post::other_op`] hands none).
            _ => {}
        }
    }

    /// Ends the output cycle in force, if there is one.
    pub(super) fn cancel_cycle(&mut self) {
        if let Some(a) = self.active.take() {
            let out = self.out;
            self.render(&out.cycles[a.index].cancel, &mut Vals::new(), false, false);
            self.motion = None;
        }
    }

    /// A cycle's hole begins: written as the target's cycle where it drills the hole as the
    /// source's does (the next hole of the cycle in force where its parameters are the same,
    /// else the cycle defined anew); otherwise said, and left to the moves that follow.
    fn cycle_begin(&mut self, canon: &Canon, intent: &CycleIntent) {
        self.flush_tool();
        if !self.cycle_written(canon, intent) {
            self.unknown_cycle_as_moves(canon, intent);
        }
    }

    /// Writes the hole as the target's cycle where it drills it as the source's does; false
    /// where it is left to its moves.
    fn cycle_written(&mut self, canon: &Canon, intent: &CycleIntent) -> bool {
        let out = self.out;
        let unknown = self.known & 1 << self.plane.axes().2 == 0;
        let Some(index) = self.output_cycle(canon, intent) else { return false };
        let m: &CycleOut = &out.cycles[index];
        if unknown && !self.unknown_start_written(intent, m) {
            self.cancel_cycle();
            if intent.known_at_r && intent.positioned {
                self.note(
                    Code::PostCycleAsMoves,
                    canon,
                    "unknown-level",
                    format!(
                        "the source's {} cycle begins where the program does not know the tool axis's position and goes to its R level first; the target's would rise to R only from below it and return to that unknown level: written as the moves it makes",
                        intent.kind.label()
                    ),
                );
            }
            return false;
        }
        let src_clear = self.source_peck_clearance(intent);
        if self.peck_clearance_differs(canon, intent, m, src_clear) {
            return false;
        }
        let hole = self.hole(intent);
        if self.tap_retract_differs(canon, intent, hole) {
            return false;
        }
        let (surface, restated) = self.surface(intent, m, hole);
        if self.peck_level_differs(canon, intent, m, hole, surface) {
            return false;
        }
        let (params, mut vals) = self.cycle_values(intent, hole, surface, src_clear);
        let same =
            self.active.as_ref().is_some_and(|a| a.index == index && a.params.iter().zip(&params).all(|(p, q)| (p - q).abs() < 1e-9));
        if same {
            self.render(&m.at, &mut vals, false, false);
        } else {
            self.cancel_cycle();
            if !self.reach_return_level(canon, intent, m, hole) {
                self.motion = None;
                return false;
            }
            if let Some(why) = restated {
                self.note(
                    Code::PostSurfaceRestated,
                    canon,
                    "surface-restated",
                    format!("{why} ({}): the plan read back takes the holes' top from elsewhere", intent.kind.label()),
                );
            }
            self.render(&m.define, &mut vals, false, false);
            if !m.inline {
                self.render(&m.at, &mut vals, false, false);
            }
            self.active = Some(ActiveCycle { index, params });
        }
        self.motion = None;
        self.in_cycle = true;
        true
    }

    /// The target's cycle for `intent`, by its index in [`crate::dialect::output::Output::cycles`]; none
    /// (said, and the cycle in force cancelled) where the target has no cycle of its kind or
    /// the hole is drilled outside the XY plane.
    fn output_cycle(&mut self, canon: &Canon, intent: &CycleIntent) -> Option<usize> {
        let out = self.out;
        let Some(index) = out.cycles.iter().position(|c| c.kinds.contains(&intent.kind)) else {
            self.cancel_cycle();
            self.note(
                Code::PostCycleAsMoves,
                canon,
                intent.kind.label(),
                format!("the target has no {} cycle: it is written as the moves it makes", intent.kind.label()),
            );
            return None;
        };
        if self.plane != Plane::Xy {
            self.cancel_cycle();
            self.note(
                Code::PostCycleAsMoves,
                canon,
                "cycle-plane",
                format!("a {} cycle outside the XY plane is written as the moves it makes", intent.kind.label()),
            );
            return None;
        }
        Some(index)
    }

    /// Whether a hole begun where the program does not know the hole axis's position is
    /// written as the target's cycle `m`, which then makes the same moves on the machine from
    /// wherever the tool stands; otherwise it is left to its moves (said where those would
    /// not be the source's).
    ///
    /// - An R level counted from the unknown one (G91) is known nowhere: left to the moves,
    ///   which are refused where they move that axis.
    /// - A G8x hole (the cycle itself moves in the plane, from the level it begins at, and
    ///   first rises to R where below it) is the target's G8x cycle (`G98`/`G99` stated,
    ///   read alike by every such control): it returns where the source's does, the unknown
    ///   initial level under G98 too. As moves its order would depend on where the tool
    ///   stands: refused.
    /// - A hole of a cycle called over the tool's position (Siemens `MCALL CYCLE81`,
    ///   Heidenhain cycle 200 with `M99`), whose first move goes to its R level along the
    ///   hole axis, is the target's cycle where that is one of the same kind, stating its
    ///   return level (RTP, Q203+Q204); otherwise its moves, known from R on (a G8x cycle
    ///   would rise to R first from below it and return to its initial level).
    fn unknown_start_written(&self, intent: &CycleIntent, m: &CycleOut) -> bool {
        if !intent.known_at_r {
            return false;
        }
        let g8x_target = m.define.uses(Value::Retract);
        if !intent.positioned {
            // A G8x cycle from an unknown level: controls differ on what it does there (rs274
            // rises to R first where the tool stands below it and returns to the higher of
            // the two; Fanuc moves to the hole at that level), and a tool length offset still
            // pending would be written only after the cycle. Not written as the target's
            // cycle: left to its moves, refused where they cannot be stated.
            return false;
        }
        !g8x_target && (m.define.uses(Value::Clear) || m.define.uses(Value::ClearDist))
    }

    /// Refuses a G8x hole begun where the program does not know the hole axis's position,
    /// left to its moves: the source's cycle moves in the plane at that level, or first
    /// rises to R where the tool stands below it, which moves written one by one cannot
    /// follow (`post::unknown-start`).
    fn unknown_cycle_as_moves(&mut self, canon: &Canon, intent: &CycleIntent) {
        let n = self.plane.axes().2;
        if self.known & 1 << n != 0 || !intent.known_at_r || intent.positioned {
            return;
        }
        let moves = self.known & 0b11 != 0b11
            || (intent.x * self.scale + self.g92[0] - self.pos[0]).abs() > 1e-6
            || (intent.y * self.scale + self.g92[1] - self.pos[1]).abs() > 1e-6;
        if moves || intent.returns_unknown {
            let msg = format!(
                "the translation is refused: the {} cycle begins where the program does not know the position along its axis (no absolute word for it since a tool change or a reference return); the source's control {}, which the target's moves cannot state",
                intent.kind.label(),
                if intent.returns_unknown {
                    "returns to that level after the hole (G98)"
                } else {
                    "moves to the hole at that level, or first rises to R where the tool stands below it"
                }
            );
            self.note(Code::PostUnknownStart, canon, "unknown-start", msg);
        }
    }

    /// How far above the last peck the source's cycle comes back down at rapid, mm.
    fn source_peck_clearance(&self, intent: &CycleIntent) -> f64 {
        let (src_clear, _) = self.opts.peck_clearance;
        // The distance the source's cycle itself states (Siemens _DIS1), mm.
        intent.peck_clearance.map_or(src_clear, |c| c * self.scale * self.opts.units.to_mm())
    }

    /// Whether a peck cycle re-approaches another distance above the last peck in the
    /// target (`src_clear` in the source, mm) and the target's cycle cannot state it: said,
    /// and the cycle in force cancelled; the hole is written as its moves.
    fn peck_clearance_differs(&mut self, canon: &Canon, intent: &CycleIntent, m: &CycleOut, src_clear: f64) -> bool {
        let (_, dst_clear) = self.opts.peck_clearance;
        if matches!(intent.kind, CycleKind::PeckDrilling | CycleKind::ChipBreaking)
            && !m.define.uses(Value::PeckClearance)
            && (src_clear - dst_clear).abs() > 1e-9
        {
            self.cancel_cycle();
            self.note(
                Code::PostCycleAsMoves,
                canon,
                "peck-clearance",
                format!(
                    "the target's {} cycle re-approaches {dst_clear} mm above the last peck, the source's {src_clear} mm: written as the moves it makes",
                    intent.kind.label()
                ),
            );
            return true;
        }
        false
    }

    /// Where `intent`'s hole and its levels are in the target.
    fn hole(&self, intent: &CycleIntent) -> Hole {
        let s = self.scale;
        let (zoff, xoff, yoff) = (self.g92[2], self.g92[0], self.g92[1]);
        let x = intent.x * s + xoff;
        let y = intent.y * s + yoff;
        let bottom = intent.bottom * s + zoff;
        let r = intent.r_plane * s + zoff;
        let clear = intent.clear * s + zoff;
        Hole { x, y, bottom, r, clear }
    }

    /// Whether the source's tap feeds out of the hole another way than the target's: said,
    /// and the cycle in force cancelled; the hole is written as its moves.
    fn tap_retract_differs(&mut self, canon: &Canon, intent: &CycleIntent, hole: Hole) -> bool {
        let Hole { r, clear, .. } = hole;
        // A tap fed out to the clear level where the target's cycle feeds out to R and rapids
        // on (or the reverse) is another move above R: written as the moves.
        let tapping = matches!(intent.kind, CycleKind::Tapping | CycleKind::LeftTapping);
        if tapping && self.opts.tap_to_clear.0 != self.opts.tap_to_clear.1 && (clear - r).abs() > 1e-9 {
            self.cancel_cycle();
            self.note(
                Code::PostCycleAsMoves,
                canon,
                "tap-retract",
                format!(
                    "the target's {} cycle feeds out of the hole {}, the source's {}: written as the moves it makes",
                    intent.kind.label(),
                    if self.opts.tap_to_clear.1 { "to the clear level" } else { "to R and rapids on" },
                    if self.opts.tap_to_clear.0 { "to the clear level" } else { "to R and rapids on" },
                ),
            );
            return true;
        }
        false
    }

    /// The workpiece surface the target's cycle `m` states for the hole (the R level where
    /// none is known, or where it would reverse the depth), and why it is restated, where it
    /// goes another way than the source's plan has it. The plan's hole tops are asked for
    /// here, where a cycle first needs them.
    fn surface(&mut self, intent: &CycleIntent, m: &CycleOut, hole: Hole) -> (f64, Option<&'static str>) {
        let Hole { bottom, r, .. } = hole;
        let s = self.scale;
        let zoff = self.g92[2];
        let src_mm = s * self.opts.units.to_mm();
        if intent.surface.is_none() && self.opts.hole_tops.is_empty() && states_surface_cycle(m) {
            if let Some(f) = self.tops_source.take() {
                self.opts.hole_tops = f();
            }
        }
        let found = self
            .opts
            .hole_tops
            .iter()
            .find(|h| (h[0] - intent.x * src_mm).abs() < 1e-3 && (h[1] - intent.y * src_mm).abs() < 1e-3)
            .map(|h| h[2] / self.opts.units.to_mm() + zoff);
        // A surface at or below the bottom (a hole top the plan put under a cycle drilling
        // above it) would make a depth stated from the surface positive, which such a cycle
        // reads as reversed: the R level is the surface then. A cycle stating its bottom
        // absolutely keeps that surface.
        let relative = m.define.uses(Value::Depth);
        let stated = intent.surface.map(|v| v * s + zoff).or(found);
        let surface = stated.filter(|v| *v <= r + 1e-9 && (!relative || *v > bottom + 1e-9)).unwrap_or(r);
        // Where the surface goes another way than the source's plan has it (see
        // `post::surface-restated`).
        let restated = if states_surface_cycle(m) {
            stated.is_none_or(|v| (v - surface).abs() > 1e-6).then_some("the target's cycle states a workpiece surface the source's plan has none for above the hole's bottom: the R level is written for it")
        } else {
            intent
                .surface
                .is_some_and(|v| (v * s + zoff - r).abs() > 1e-6)
                .then_some("the source's cycle states the workpiece surface, which the target's cannot")
        };
        (surface, restated)
    }

    /// Whether the target's peck cycle counts its pecks from another level than the
    /// source's: said, and the cycle in force cancelled; the hole is written as its moves.
    fn peck_level_differs(&mut self, canon: &Canon, intent: &CycleIntent, m: &CycleOut, hole: Hole, surface: f64) -> bool {
        let Hole { bottom, r, .. } = hole;
        let s = self.scale;
        let zoff = self.g92[2];
        // The level the pecks count from: the surface for a cycle that states it (Siemens,
        // Heidenhain), the R level for a G8x cycle. A peck cycle counted from another level
        // than the source's drills other depths: written as its moves.
        let pecking = matches!(intent.kind, CycleKind::PeckDrilling | CycleKind::ChipBreaking);
        let src_from = intent.surface.map_or(r, |v| v * s + zoff);
        let dst_from = if states_surface_cycle(m) { surface } else { r };
        if pecking && intent.peck.is_some_and(|p| p * s < src_from - bottom - 1e-9) && (src_from - dst_from).abs() > 1e-6 {
            self.cancel_cycle();
            self.note(
                Code::PostCycleAsMoves,
                canon,
                "peck-level",
                format!(
                    "the target's {} cycle counts its pecks from {}, the source's from {}: written as the moves it makes",
                    intent.kind.label(),
                    if states_surface_cycle(m) { "the workpiece surface" } else { "the R level" },
                    if intent.surface.is_some() { "the workpiece surface" } else { "the R level" },
                ),
            );
            return true;
        }
        false
    }

    /// The parameters a cycle is defined with (the next hole of the cycle in force is one
    /// with the same), and the values of the cycle's templates.
    fn cycle_values(&self, intent: &CycleIntent, hole: Hole, surface: f64, src_clear: f64) -> ([f64; 7], Vals) {
        let Hole { x, y, bottom, r, clear } = hole;
        let s = self.scale;
        let peck = intent.peck.map_or(surface - bottom, |p| p * s);
        let dwell = intent.dwell.unwrap_or(0.0);
        // A rigid tap (G33.1) feeds its pitch per revolution: a tapping cycle states it as
        // the feed per minute, pitch × speed.
        let feed = match self.sync {
            Some(p) if self.feed_mode == FeedMode::PerMinute && self.speed > 0.0 => p * self.speed,
            _ => self.feed,
        };
        let params = [bottom, r, clear, surface, peck, dwell, feed];
        let mut vals = Vals::new();
        vals.set(Value::X, x).set(Value::Y, y).set(Value::Bottom, bottom).set(Value::RPlane, r).set(Value::Clear, clear);
        vals.set(Value::Surface, surface).set(Value::Sdis, r - surface).set(Value::Depth, bottom - surface);
        vals.set(Value::ClearDist, clear - surface).set(Value::Peck, peck).set(Value::CycleDwell, dwell);
        // From an unknown level under G98 the cycle returns to that level: the target's G98.
        let initial = intent.returns_unknown || clear > r + 1e-6;
        vals.set(Value::Retract, if initial { 98.0 } else { 99.0 }).set(Value::F, feed);
        vals.set(Value::Seconds, dwell).set(Value::Millis, dwell * 1000.0).set(Value::PeckClearance, src_clear / self.opts.units.to_mm());
        // A hole where the tool stands, at a position the program does not know: the cycle
        // drills there, without the numbers the analysis gives it.
        self.unknown_out(&mut vals);
        (params, vals)
    }

    /// Brings the tool to where the source's cycle returns, before the target's cycle is
    /// defined, where the target's cycle returns to its initial level: a rapid up to a clear
    /// level above the tool. False (said) where the target's cycle cannot return there.
    fn reach_return_level(&mut self, canon: &Canon, intent: &CycleIntent, m: &CycleOut, hole: Hole) -> bool {
        let Hole { r, clear, .. } = hole;
        // A cycle that returns to its initial level (G98) returns to where it began: a
        // clear level below the tool is reached first, one above it cannot be; nor can
        // one below R (G99 returns to R; Heidenhain's second set-up clearance counts only
        // above the first) unless the target states the clear level itself.
        let below_r = clear < r - 1e-6 && !m.define.uses(Value::Clear);
        // From an unknown level the tool stands nowhere the writer could compare: the cycle
        // is written only where it returns as the source's does (`unknown_start_written`).
        let unknown = self.known & 1 << self.plane.axes().2 == 0;
        if unknown && !below_r {
            return true;
        }
        if below_r || m.define.uses(Value::Retract) && clear > r + 1e-6 && (self.pos[2] - clear).abs() > 1e-6 {
            if below_r || self.pos[2] < clear {
                self.note(
                    Code::PostCycleAsMoves,
                    canon,
                    "initial-level",
                    format!(
                        "the source's {} cycle returns {}; the target's returns to its initial level or R: written as the moves it makes",
                        intent.kind.label(),
                        if below_r { "below its R level" } else { "above where it begins" }
                    ),
                );
                return false;
            }
            if let Some((t, _)) = self.out.template("rapid") {
                let to = [self.pos[0], self.pos[1], clear];
                let mut v = Vals::new();
                v.set(Value::X, to[0]).set(Value::Y, to[1]).set(Value::Z, to[2]);
                self.unknown_out(&mut v);
                self.rules("rapid", true);
                self.render(t, &mut v, false, true);
                self.rules("rapid", false);
                self.moved(to);
            }
        }
        true
    }
}

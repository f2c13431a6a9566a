//! The turning cycles a control calls by name with positional arguments (SINUMERIK
//! `CYCLE93` grooving, `CYCLE95` stock removal, `CYCLE97` threading), read by the roles the
//! dictionary gives their arguments and expanded into moves between the `Turning` marker,
//! with what the cycle states, and `TurningEnd`.
//!
//! - Stock removal (`cycle-rough-turn` with a `contour-name`): the flow driver reads the
//!   contour the name gives (a subprogram, a label, or a label range `START:END`) without
//!   effect, then [`Interpreter::stock_removal`] roughs it out as Fanuc's G71/G72 do (passes
//!   `cut-depth` apart, the contour shifted by the allowances) and, where the machining type
//!   asks for it, finishes it as written: two workingsteps from one call.
//! - Grooving (`cycle-groove`): plunges at both edges of the groove in steps of the infeed,
//!   stopping the base allowance short of the bottom, then the flanks and the base finished.
//!   The moves are the tool's cutting point; the tool's width, which the control takes from
//!   its offset data, is not in the program. A groove in a face is kept as intent.
//! - Threading (`cycle-thread-multiple`): roughing passes to the depth less the finishing
//!   allowance (a constant infeed, or a constant cross-section of cut: depth ∝ √n), one pass
//!   taking the allowance, then the idle passes; each from the run-in before the start to the
//!   run-out after the end, infeeding along the flank by the infeed angle.
//!
//! The machining type (Siemens `VARI`) says roughing or finishing, along Z or across X,
//! outside or inside, and for a groove from which edge; the dictionary documents its values.

use super::Interpreter;
use super::cycle::Rough;
use crate::canon::{Canon, CanonOp, CanonSink, Plane, TurnIntent, TurnKind};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{Meaning, Role};
use crate::text::TextRange;

/// Passes a threading cycle or plunges a groove may make at most: more is a slip.
const MAX_PASSES: f64 = 10_000.0;

/// ISO 261 coarse pitches of the metric sizes M3 to M60 (a thread given by its size).
const COARSE_PITCH: [(u32, f64); 24] = [
    (3, 0.5),
    (4, 0.7),
    (5, 0.8),
    (6, 1.0),
    (8, 1.25),
    (10, 1.5),
    (12, 1.75),
    (14, 2.0),
    (16, 2.0),
    (18, 2.5),
    (20, 2.5),
    (22, 2.5),
    (24, 3.0),
    (27, 3.0),
    (30, 3.5),
    (33, 3.5),
    (36, 4.0),
    (39, 4.0),
    (42, 4.5),
    (45, 4.5),
    (48, 5.0),
    (52, 5.0),
    (56, 5.5),
    (60, 5.5),
];

/// The coarse pitch of a metric thread of size `m` (M3 to M60), if the table has it.
pub(super) fn coarse_pitch(m: f64) -> Option<f64> {
    COARSE_PITCH.iter().find(|(size, _)| f64::from(*size) == m).map(|(_, p)| *p)
}

/// What a stock-removal call asks of its contour, for the flow driver and back.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct StockRemoval {
    /// How to rough the contour out, if the call roughs.
    pub rough: Option<Rough>,
    /// Whether the call finishes the contour as written.
    pub finish: bool,
    /// The roughing feed and the finishing feed, where the call gives them.
    pub feeds: (Option<f64>, Option<f64>),
    /// What the roughing and the finishing workingsteps state.
    pub intents: (TurnIntent, TurnIntent),
    /// Where the cycle starts from outside the contour's extent by this distance, not from
    /// where the tool stands (SINUMERIK `CYCLE952`); a face the contour begins with at its
    /// front is then left to facing.
    pub clear: Option<f64>,
}

/// A cycle's arguments by role.
struct Args<'x>(&'x [(Role, f64)]);

impl Args<'_> {
    fn get(&self, r: Role) -> Option<f64> {
        self.0.iter().find(|(a, _)| *a == r).map(|(_, v)| *v)
    }
}

impl Interpreter<'_> {
    /// A named turning cycle (`cycle-rough-turn`, `cycle-groove`, `cycle-thread-multiple`)
    /// called with `args`.
    pub(super) fn named_turn_cycle(
        &mut self,
        ci: usize,
        args: &[(Role, f64)],
        range: TextRange,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        self.lathe_word();
        let cycle = &self.dialect.cycles[ci];
        let (name, meaning) = (cycle.name.clone(), cycle.meaning);
        let contour = self.cycle_text.take();
        if self.st.plane != Plane::Xz {
            let msg = format!("{name} turns in the ZX plane (G18); the cycle is skipped");
            return diags.push(Diagnostic::new(Code::Unsupported, range, msg));
        }
        let a = Args(args);
        match meaning {
            Meaning::CycleRoughTurn => self.stock_removal_call(&name, contour, &a, range, diags),
            Meaning::CycleGroove => self.groove_call(&name, &a, range, sink, diags),
            Meaning::CycleStockCorner => self.stock_corner_call(&name, &a, range, sink, diags),
            Meaning::CycleContourTurn => self.contour_turn_call(&name, &a, range, diags),
            Meaning::CyclePartOff => self.part_off_call(&name, &a, range, sink, diags),
            _ => self.thread_call(&name, &a, range, sink, diags),
        }
    }

    /// A position across the axis as written (a diameter in diameter mode), as a radius.
    fn across(&self, v: f64) -> f64 {
        if self.st.diameter { v / 2.0 } else { v }
    }

    /// The machining type (1-12), or a finding.
    fn machining_type(&self, name: &str, a: &Args<'_>, most: u32, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<u32> {
        let v = a.get(Role::MachiningType).unwrap_or(1.0);
        let t = (v.round().max(0.0) as u32) % 100;
        if v.fract() != 0.0 || !(1..=most).contains(&t) {
            let msg = format!("{name}: the machining type (VARI) {v} is not one of 1 to {most}; the cycle is skipped");
            diags.push(Diagnostic::new(Code::BadValue, range, msg));
            return None;
        }
        Some(t)
    }

    /// CYCLE95: asks the flow driver for the contour the call names.
    fn stock_removal_call(&mut self, name: &str, contour: Option<String>, a: &Args<'_>, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let Some(contour) = contour.filter(|c| !c.trim().is_empty()) else {
            let msg = format!("{name} names no contour (its first argument, a subprogram or \"START:END\"); the cycle is skipped");
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        };
        let Some(t) = self.machining_type(name, a, 12, range, diags) else { return };
        let (roughs, finishes) = (!(5..=8).contains(&t), t >= 5);
        let facing = t % 2 == 0;
        let inside = matches!((t - 1) % 4, 2 | 3);
        let depth = a.get(Role::CutDepth).map(f64::abs).unwrap_or(0.0);
        if roughs && !(depth > 0.0 && depth.is_finite()) {
            let msg = format!("{name} roughs with no infeed depth (MID); the cycle is skipped");
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        }
        let all = a.get(Role::Allowance).map_or(0.0, f64::abs);
        let side = if inside { -1.0 } else { 1.0 };
        let allow_x = side * (a.get(Role::AllowanceX).map_or(0.0, f64::abs) + all);
        let allow_z = a.get(Role::AllowanceZ).map_or(0.0, f64::abs) + all;
        let retract = a.get(Role::RetractDistance).map_or(1.0, f64::abs);
        let rough = roughs.then(|| Rough::new(depth, retract, allow_x, allow_z, facing));
        let rough_intent = TurnIntent {
            kind: Some(if facing { TurnKind::RoughFace } else { TurnKind::RoughTurn }),
            code: name.to_owned(),
            depth_of_cut: Some(depth),
            retract: Some(retract),
            allowance_x: Some(2.0 * allow_x),
            allowance_z: Some(allow_z),
            finish_allowance: (all > 0.0).then_some(all),
            ..TurnIntent::default()
        };
        let finish_intent = TurnIntent { kind: Some(TurnKind::Finish), code: name.to_owned(), ..TurnIntent::default() };
        let feeds = (a.get(Role::F).filter(|f| *f > 0.0), a.get(Role::FinishFeed).filter(|f| *f > 0.0));
        let job = StockRemoval { rough, finish: finishes, feeds, intents: (rough_intent, finish_intent), clear: None };
        self.request = Some(super::Request::NamedContour { name: contour, job: Box::new(job) });
    }

    /// Cuts a stock-removal call's contour (`shape`, its canon read from the start point):
    /// roughed out, then finished, each a workingstep of its own; back to the start point.
    pub(super) fn stock_removal(&mut self, job: &StockRemoval, shape: &[Canon], sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let cleared;
        let shape = match job.clear {
            Some(clear) => {
                let Some((start, outside)) = clear_of(shape, self.st.pos, clear, job.rough.is_some_and(|r| r.facing)) else {
                    return;
                };
                self.go_to(sink, start, false);
                cleared = outside;
                &cleared[..]
            }
            None => shape,
        };
        let start = self.st.pos;
        if let Some(r) = job.rough {
            self.emit(sink, CanonOp::Turning(Box::new(job.intents.0.clone())));
            self.cycle_feed(job.feeds.0, sink);
            self.rough_turn(r, start, shape, sink, diags);
            self.emit(sink, CanonOp::TurningEnd);
        }
        if job.finish {
            self.emit(sink, CanonOp::Turning(Box::new(job.intents.1.clone())));
            self.cycle_feed(job.feeds.1, sink);
            let mut first = true;
            for c in shape {
                let op = match &c.op {
                    // The move to the contour's first point comes in at rapid.
                    CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) if first => CanonOp::StraightTraverse(*p),
                    op @ (CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. }) => op.clone(),
                    _ => continue,
                };
                first = false;
                if let CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) = &op {
                    self.st.pos = *p;
                }
                if let CanonOp::ArcFeed { first_end, second_end, axis_end, .. } = &op {
                    let (a0, a1, a2) = self.st.plane.axes();
                    (self.st.pos[a0], self.st.pos[a1], self.st.pos[a2]) = (*first_end, *second_end, *axis_end);
                }
                self.emit(sink, op);
            }
            self.emit(sink, CanonOp::StraightTraverse(start));
            self.st.pos = start;
            self.emit(sink, CanonOp::TurningEnd);
        }
    }

    /// The machining type of a ShopTurn cycle (`CYCLE951`, `CYCLE952`): its units digit the
    /// direction (1 along Z, 2 across X: a face), its tens digit the machining (1 roughing, 2
    /// finishing); the higher digits (position, residual material) are not read. `None`, with
    /// a finding, for another value.
    fn shopturn_type(&self, name: &str, a: &Args<'_>, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<(bool, bool)> {
        let v = a.get(Role::MachiningType).unwrap_or(0.0);
        let n = v.round().max(0.0) as u64;
        let (direction, machining) = (n % 10, (n / 10) % 10);
        if v.fract() != 0.0 || !matches!(machining, 1 | 2) || !matches!(direction, 1 | 2) {
            let msg = format!(
                "{name}: the machining type {v} is not read (units 1 along Z or 2 across X, tens 1 roughing or 2 finishing); the cycle is kept as intent"
            );
            diags.push(Diagnostic::new(Code::Unsupported, range, msg));
            return None;
        }
        Some((machining == 1, direction == 2))
    }

    /// CYCLE951: stock removal of a corner. The stock lies between the start point (SPD, SPL)
    /// and the end point (EPD, EPL); the finished corner runs from the end diameter at the
    /// start Z through the intermediate point (ZPD, ZPL: the end point for a square corner) to
    /// the start diameter at the end Z. It is cut from outside the start point by the safety
    /// distance, as the stock removal of a contour is, and the tool returns there.
    fn stock_corner_call(&mut self, name: &str, a: &Args<'_>, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let (Some(sx), Some(sz), Some(ex), Some(ez)) = (a.get(Role::X), a.get(Role::Z), a.get(Role::EndX), a.get(Role::EndZ)) else {
            let msg = format!("{name} needs its start point (SPD, SPL) and end point (EPD, EPL); the cycle is skipped");
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        };
        let Some((roughs, facing)) = self.shopturn_type(name, a, range, diags) else { return };
        let (mx, mz) = (a.get(Role::ViaX).unwrap_or(ex), a.get(Role::ViaZ).unwrap_or(ez));
        let (sx, ex, mx) = (self.across(sx), self.across(ex), self.across(mx));
        // A bore opened: the end diameter beyond the start one, the tool inside.
        let inside = ex > sx;
        let out = if inside { -1.0 } else { 1.0 };
        let depth = a.get(Role::CutDepth).map(f64::abs).unwrap_or(0.0);
        if roughs && !(depth > 0.0 && depth.is_finite()) {
            let msg = format!("{name} roughs with no infeed depth; the cycle is skipped");
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        }
        let clear = a.get(Role::SafetyDistance).map_or(1.0, f64::abs);
        // The X allowance is written as X positions are (on the diameter under DIAMON).
        let (ux, uz) = (a.get(Role::AllowanceX).map_or(0.0, f64::abs), a.get(Role::AllowanceZ).map_or(0.0, f64::abs));
        let allow_x = self.across(ux);
        let mut start = self.st.pos;
        (start[0], start[2]) = (sx + out * clear, sz + clear);
        let at = |x: f64, z: f64| {
            let mut p = start;
            (p[0], p[2]) = (x, z);
            p
        };
        let mut corner = vec![at(ex, sz), at(mx, mz), at(sx, ez)];
        if facing {
            corner.reverse();
            corner.insert(0, at(start[0], ez));
            corner.push(at(ex, start[2]));
        } else {
            corner.insert(0, at(ex, start[2]));
            corner.push(at(start[0], ez));
        }
        corner.dedup();
        // Cut along the corner, then left at rapid to the start's diameter (or Z).
        let last = corner.len().saturating_sub(1);
        let shape: Vec<Canon> = corner
            .into_iter()
            .enumerate()
            .map(|(k, p)| {
                let op = if k == last { CanonOp::StraightTraverse(p) } else { CanonOp::StraightFeed(p) };
                Canon { op, origin: range, line: self.line }
            })
            .collect();
        let (mut rough_intent, finish_intent) = shopturn_intents(name, facing, depth, clear);
        // Stated where the call leaves some (a corner roughed to size states none).
        if ux > 0.0 || uz > 0.0 {
            (rough_intent.allowance_x, rough_intent.allowance_z) = (Some(2.0 * allow_x), Some(uz));
        }
        let feed = a.get(Role::F).filter(|f| *f > 0.0);
        let rough = roughs.then(|| Rough::new(depth, clear, out * allow_x, uz, facing));
        let job = StockRemoval { rough, finish: !roughs, feeds: (feed, feed), intents: (rough_intent, finish_intent), clear: None };
        self.go_to(sink, start, false);
        self.stock_removal(&job, &shape, sink, diags);
    }

    /// CYCLE952: the contour the last `CYCLE62` named, roughed out or finished along Z or
    /// across X, from outside it by the safety distance; asks the flow driver for the contour.
    fn contour_turn_call(&mut self, name: &str, a: &Args<'_>, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let Some(contour) = self.contour_named.clone().filter(|c| !c.trim().is_empty()) else {
            let msg = format!("{name} turns the contour a CYCLE62 before it names, and none is named; the cycle is skipped");
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        };
        let Some((roughs, facing)) = self.shopturn_type(name, a, range, diags) else { return };
        let depth = a.get(Role::CutDepth).map(f64::abs).unwrap_or(0.0);
        if roughs && !(depth > 0.0 && depth.is_finite()) {
            let msg = format!("{name} roughs with no infeed depth (D); the cycle is skipped");
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        }
        let clear = a.get(Role::SafetyDistance).map_or(1.0, f64::abs);
        let (rough_intent, finish_intent) = shopturn_intents(name, facing, depth, clear);
        let feed = a.get(Role::F).filter(|f| *f > 0.0);
        let rough = roughs.then(|| Rough::new(depth, clear, 0.0, 0.0, facing));
        let job = StockRemoval { rough, finish: !roughs, feeds: (feed, feed), intents: (rough_intent, finish_intent), clear: Some(clear) };
        self.request = Some(super::Request::NamedContour { name: contour, job: Box::new(job) });
    }

    /// CYCLE92: parting off at Z (SPL) from the diameter (SPD) to the end diameter (X2), the
    /// feed reduced (FF2) from the diameter X1 on; from outside the part by the safety
    /// distance, and back out.
    fn part_off_call(&mut self, name: &str, a: &Args<'_>, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let (Some(d), Some(z), Some(end)) = (a.get(Role::X), a.get(Role::Z), a.get(Role::EndX)) else {
            let msg = format!("{name} needs its diameter (SPD), its Z (SPL) and the end diameter (X2); the cycle is skipped");
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        };
        let (top, bottom) = (self.across(d), self.across(end));
        let slow = a.get(Role::ViaX).map(|x| self.across(x)).filter(|x| *x < top && *x > bottom);
        let clear = a.get(Role::SafetyDistance).map_or(1.0, f64::abs);
        let intent = TurnIntent { kind: Some(TurnKind::Groove), code: name.to_owned(), span: Some([z, z]), ..TurnIntent::default() };
        let back = self.st.pos;
        self.emit(sink, CanonOp::Turning(Box::new(intent)));
        let mut p = back;
        (p[0], p[2]) = (top + clear, z);
        self.go_to(sink, p, false);
        self.cycle_feed(a.get(Role::F).filter(|f| *f > 0.0), sink);
        if let Some(x) = slow {
            p[0] = x;
            self.go_to(sink, p, true);
            self.cycle_feed(a.get(Role::FinishFeed).filter(|f| *f > 0.0), sink);
        }
        p[0] = bottom;
        self.go_to(sink, p, true);
        p[0] = top + clear;
        self.go_to(sink, p, false);
        self.emit(sink, CanonOp::TurningEnd);
    }

    /// The feed a cycle states for its cuts, put in force.
    fn cycle_feed(&mut self, f: Option<f64>, sink: &mut dyn CanonSink) {
        if let Some(f) = f.filter(|f| *f != self.st.feed) {
            self.st.feed = f;
            self.emit(sink, CanonOp::SetFeedRate(f));
        }
    }

    /// CYCLE93: a groove in a diameter, plunged at both edges in steps of the infeed, then
    /// its flanks and base finished.
    fn groove_call(&mut self, name: &str, a: &Args<'_>, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let Some(t) = self.machining_type(name, a, 8, range, diags) else { return };
        let (Some(x), Some(z), Some(width), Some(depth)) = (a.get(Role::X), a.get(Role::Z), a.get(Role::Width), a.get(Role::ProfileDepth))
        else {
            let msg = format!("{name} needs its start point (SPD, SPL), width (WIDG) and depth (DIAG); the cycle is skipped");
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        };
        let (width, depth) = (width.abs(), depth.abs());
        let inside = matches!(t, 3 | 4 | 7 | 8);
        let along = if t <= 4 { 1.0 } else { -1.0 };
        let (z0, z1) = (z, z + along * width);
        let intent = TurnIntent {
            kind: Some(TurnKind::Groove),
            code: name.to_owned(),
            peck: a.get(Role::CutDepth).map(f64::abs).filter(|p| *p > 0.0),
            finish_allowance: a.get(Role::Allowance).map(f64::abs).filter(|v| *v > 0.0),
            span: Some([z0.min(z1), z0.max(z1)]),
            ..TurnIntent::default()
        };
        if t % 2 == 0 {
            self.emit(sink, CanonOp::Turning(Box::new(intent)));
            self.emit(sink, CanonOp::TurningEnd);
            let msg = format!("{name}: a groove in a face is kept as intent: its moves are not expanded");
            return diags.push(Diagnostic::new(Code::Unsupported, range, msg));
        }
        let top = self.across(x);
        let out = if inside { -1.0 } else { 1.0 };
        let bottom = top - out * depth;
        let allowance = intent.finish_allowance.unwrap_or(0.0).min(depth);
        let peck = intent.peck.unwrap_or(depth).max(depth / MAX_PASSES);
        let retract = a.get(Role::RetractDistance).map_or(1.0, f64::abs);
        let start = self.st.pos;
        self.emit(sink, CanonOp::Turning(Box::new(intent)));
        for edge in [z0, z1] {
            let mut p = start;
            (p[0], p[2]) = (top + out * retract, edge);
            self.go_to(sink, p, false);
            let mut reached = 0.0;
            while reached < depth - allowance - 1e-9 {
                reached = (reached + peck).min(depth - allowance);
                p[0] = top - out * reached;
                self.go_to(sink, p, true);
                if reached < depth - allowance - 1e-9 {
                    p[0] += out * retract.min(peck);
                    self.go_to(sink, p, false);
                }
            }
            p[0] = top + out * retract;
            self.go_to(sink, p, false);
        }
        // Finishing: down the first flank, along the base, up the other.
        let mut p = start;
        (p[0], p[2]) = (top + out * retract, z0);
        self.go_to(sink, p, false);
        p[0] = bottom;
        self.go_to(sink, p, true);
        p[2] = z1;
        self.go_to(sink, p, true);
        p[0] = top + out * retract;
        self.go_to(sink, p, true);
        self.go_to(sink, start, false);
        self.emit(sink, CanonOp::TurningEnd);
    }

    /// CYCLE97: the passes of a thread from its run-in to its run-out.
    fn thread_call(&mut self, name: &str, a: &Args<'_>, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let Some(t) = self.machining_type(name, a, 4, range, diags) else { return };
        let size = a.get(Role::ThreadSize).filter(|s| *s > 0.0);
        let pitch = a.get(Role::Pitch).filter(|p| *p > 0.0).or_else(|| {
            let s = size?;
            COARSE_PITCH.iter().find(|(m, _)| f64::from(*m) == s).map(|(_, p)| *p)
        });
        let (Some(pitch), Some(z0), Some(z1), Some(d1), Some(height)) =
            (pitch, a.get(Role::Z), a.get(Role::EndZ), a.get(Role::X), a.get(Role::ProfileDepth).map(f64::abs))
        else {
            let msg = format!(
                "{name} needs the pitch (PIT, or MPIT a metric size), the start and end (SPL, FPL), the diameter (DM1) and the depth (TDEP); the cycle is skipped"
            );
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        };
        let allowance = a.get(Role::Allowance).map_or(0.0, f64::abs).min(height);
        let rough_passes = a.get(Role::Passes).map_or(1.0, |n| n.round().max(1.0));
        let idle = a.get(Role::IdlePasses).map_or(0.0, |n| n.round().max(0.0));
        if !(height > 0.0 && rough_passes + idle <= MAX_PASSES && (z1 - z0).abs() > 0.0) {
            let msg = format!("{name}: the depth (TDEP) must be above 0, the thread longer than 0 and the passes not too many");
            return diags.push(Diagnostic::new(Code::BadValue, range, msg));
        }
        let inside = t % 2 == 0;
        let out = if inside { -1.0 } else { 1.0 };
        let (r0, r1) = (self.across(d1), self.across(a.get(Role::EndX).unwrap_or(d1)));
        let along = (z1 - z0).signum();
        let (run_in, run_out) = (a.get(Role::RunIn).map_or(0.0, f64::abs), a.get(Role::RunOut).map_or(0.0, f64::abs));
        let tan = a.get(Role::InfeedAngle).map_or(0.0, |g| g.abs().min(60.0).to_radians().tan());
        let constant_section = t >= 3;
        let mut depths: Vec<f64> = (1..=rough_passes as u32)
            .map(|k| {
                let share = f64::from(k) / rough_passes;
                (height - allowance) * if constant_section { share.sqrt() } else { share }
            })
            .collect();
        if allowance > 0.0 {
            depths.push(height);
        }
        depths.extend(std::iter::repeat_n(height, idle as usize));
        let intent = TurnIntent {
            kind: Some(TurnKind::Thread),
            code: name.to_owned(),
            pitch: Some(pitch),
            thread_depth: Some(height),
            first_cut: depths.first().copied(),
            finish_allowance: Some(allowance),
            finish_passes: Some(u32::from(allowance > 0.0) + idle as u32),
            span: Some([z0.min(z1), z0.max(z1)]),
            ..TurnIntent::default()
        };
        let start = self.st.pos;
        let clear = |r: f64| if inside { start[0].min(r - 1.0) } else { start[0].max(r + 1.0) };
        self.emit(sink, CanonOp::Turning(Box::new(intent)));
        for d in depths {
            let mut p = start;
            (p[0], p[2]) = (clear(r0), z0 - along * (run_in + d * tan));
            self.go_to(sink, p, false);
            p[0] = r0 - out * d;
            self.go_to(sink, p, false);
            let mut q = p;
            (q[0], q[2]) = (r1 - out * d, z1 + along * run_out);
            self.emit(sink, CanonOp::StartSpeedFeedSync(pitch));
            self.go_to(sink, q, true);
            self.emit(sink, CanonOp::StopSpeedFeedSync);
            q[0] = clear(r1);
            self.go_to(sink, q, false);
        }
        self.go_to(sink, start, false);
        self.emit(sink, CanonOp::TurningEnd);
    }
}

/// A ShopTurn stock-removal cycle's intents: the roughing (along Z, or across X where it
/// faces) with its depth of cut and retract, and the finishing.
fn shopturn_intents(name: &str, facing: bool, depth: f64, clear: f64) -> (TurnIntent, TurnIntent) {
    let kind = if facing { TurnKind::RoughFace } else { TurnKind::RoughTurn };
    let rough =
        TurnIntent { kind: Some(kind), code: name.to_owned(), depth_of_cut: Some(depth), retract: Some(clear), ..TurnIntent::default() };
    (rough, TurnIntent { kind: Some(TurnKind::Finish), code: name.to_owned(), ..TurnIntent::default() })
}

/// A contour cycle's start outside the contour `shape` (its moves) by `clear`: beyond its
/// largest diameter (its smallest, for a contour inside a bore, one that starts at a larger
/// diameter than it ends) and in front of its front; and the contour from there, the face it
/// begins with at the front (moves across X from its first point, for passes along Z; along
/// Z, for passes across X) left out: roughing along the part takes the material to the
/// contour, the face is another workingstep's. `None` for a contour without moves.
fn clear_of(shape: &[Canon], from: [f64; 6], clear: f64, facing: bool) -> Option<([f64; 6], Vec<Canon>)> {
    let moves: Vec<(usize, [f64; 6])> = shape
        .iter()
        .enumerate()
        .filter_map(|(k, c)| match c.op {
            CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) => Some((k, p)),
            _ => None,
        })
        .collect();
    let (&(first_k, first), &(_, last)) = (moves.first()?, moves.last()?);
    let inside = first[0] > last[0] + 1e-9 && !facing;
    let xs = moves.iter().map(|(_, p)| p[0]);
    let x = if inside { xs.fold(f64::INFINITY, f64::min) - clear } else { xs.fold(f64::NEG_INFINITY, f64::max) + clear };
    let z = moves.iter().map(|(_, p)| p[2]).fold(f64::NEG_INFINITY, f64::max) + clear;
    let mut start = from;
    (start[0], start[2]) = (x, z);
    // The leading face: the moves after the first that keep its Z (its X, facing).
    let fixed = if facing { 0 } else { 2 };
    let mut skip = first_k;
    for &(k, p) in &moves[1..] {
        if (p[fixed] - first[fixed]).abs() > 1e-9 {
            break;
        }
        skip = k;
    }
    Some((start, shape[skip..].to_vec()))
}

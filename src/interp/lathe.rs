//! A lathe's multiple repetitive cycles that peck and thread, in Fanuc's two-block form:
//! `G74` (pecking along Z: a face groove, or a hole on the axis), `G75` (grooving across X
//! with pecks) and `G76` (multiple-pass threading). The first block states what the passes
//! share (`G74 R` / `G75 R`: the retract after each peck; `G76 P(m)(r)(a) Q R`: finishing
//! passes, chamfer, tool angle, least depth of cut and finishing allowance); the second, with
//! the end point, makes the moves. P and Q of the second block are in the least input
//! increment (µm, 0.0001 inch), as the controls read them.
//!
//! The passes are made from the start point as the T-series manuals draw them: G75 plunges
//! in X by Δi (P) and backs off R after each peck, to the bottom, out, then shifts Δk (Q) in
//! Z to the next plunge up to Z; G74 the same with X and Z exchanged; G76 cuts pass n at
//! depth Δd·√n (Q the first depth, never less than the least depth of cut more than the
//! pass before), infeeding along the flank (half the tool angle), up to the thread height (P)
//! less the finishing allowance, then the full height once per finishing pass.

use super::{Interpreter, Slot};
use crate::canon::{CanonOp, CanonSink, DistanceMode, Frame, Plane, Setting, TurnIntent, TurnKind, Units};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Role};
use crate::syntax::WordMode;
use crate::text::TextRange;

/// Most plunges or passes a cycle makes: more is a slip in a peck or shift.
const MAX_PASSES: f64 = 10_000.0;

/// A thread's passes as its block states them.
struct ThreadSpec {
    /// Thread height and first depth of cut, per side; taper (radius, start less end).
    height: f64,
    first: f64,
    taper: f64,
    /// The lead.
    lead: f64,
    setup: LatheSetup,
    /// Each pass the first depth deeper (else the depth grows as √n: a constant amount).
    constant_depth: bool,
    /// Infeed along both flanks in turn.
    alternate: bool,
}

/// What the first block of a G74/G75/G76 states, kept for the second.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct LatheSetup {
    /// The retract after each peck (G74/G75 R).
    pub peck_retract: f64,
    /// Finishing passes of a thread (G76 P, first two digits).
    pub finish_passes: u32,
    /// The tool's included angle, degrees (G76 P, last two digits).
    pub angle: f64,
    /// Least depth of cut, program units (G76 Q).
    pub min_cut: f64,
    /// Finishing allowance, program units (G76 R).
    pub finish_allowance: f64,
}

impl Interpreter<'_> {
    /// G74, G75 and G76 (`cycle-face-peck`, `cycle-groove`, `cycle-thread-multiple`).
    pub(super) fn lathe_cycle(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let given = |s: &Self, r: Role| s.slots[r as usize].is_some();
        let second = [Role::X, Role::Z].iter().any(|&r| given(self, r)) || given(self, Role::F);
        let mut setup = self.st.lathe_setup;
        if !second {
            if def.meaning == Meaning::CycleThreadMultiple {
                if let Some(p) = self.slot(Role::P) {
                    let p = p.round().max(0.0) as u32;
                    setup.finish_passes = (p / 10_000).max(1);
                    setup.angle = f64::from(p % 100);
                }
                setup.min_cut = self.slot(Role::Q).map_or(setup.min_cut, |q| self.increments(q));
                setup.finish_allowance = self.slot(Role::R).unwrap_or(setup.finish_allowance);
            } else {
                setup.peck_retract = self.slot(Role::R).unwrap_or(setup.peck_retract);
            }
            self.st.lathe_setup = setup;
            return;
        }
        if self.st.plane != crate::canon::Plane::Xz {
            let msg = format!("{} turns in the ZX plane (G18); the cycle is skipped", def.label());
            return diags.push(Diagnostic::new(Code::Unsupported, range, msg));
        }
        if def.meaning == Meaning::CycleThreadMultiple {
            if !self.spindle_turns(def, range, diags) {
                return;
            }
            return self.thread_multiple(def, range, setup, sink, diags);
        }
        self.check_technology(def, range, diags);
        self.peck_cycle(def, range, setup, sink, diags);
    }

    /// A length given in least input increments (µm, or 0.0001 inch).
    fn increments(&self, v: f64) -> f64 {
        v * if self.st.units == Units::Mm { 0.001 } else { 0.0001 }
    }

    /// G75 (plunges across X, shifting along Z) and G74 (pecks along Z, shifting in X).
    fn peck_cycle(&mut self, def: &CodeDef, range: TextRange, setup: LatheSetup, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let t = self.target();
        let start = self.st.pos;
        let grooving = def.meaning == Meaning::CycleGroove;
        // (depth axis, shift axis): X then Z grooving, Z then X pecking along the axis.
        let (d, s) = if grooving { (0, 2) } else { (2, 0) };
        // Fanuc's P (X) and Q (Z), in least increments; a dictionary may name other words for
        // them, lengths as written (Haas `G74`/`G75`: I the X and K the Z increment, P the dwell).
        let amount = |s: &Self, role: Role| match def.args.iter().find(|(_, to)| *to == role) {
            Some((from, _)) => s.slot(*from),
            None => s.slot(role).map(|v| s.increments(v)),
        };
        let peck = amount(self, Role::P);
        let shift = amount(self, Role::Q);
        let (peck, shift) = if grooving { (peck, shift) } else { (shift, peck) };
        let depth_total = (t[d] - start[d]).abs();
        let span = (t[s] - start[s]).abs();
        // A block that states no peck cuts the whole depth in one plunge, and one that states
        // no shift plunges once per tool width (Fanuc G74/G75, Haas G74/G75: both optional):
        // the intent keeps only what the block states, not a size made up from the depth.
        let (peck_stated, shift_stated) = (peck.filter(|p| *p > 0.0), shift.filter(|q| *q > 0.0));
        let peck = peck_stated.unwrap_or(depth_total);
        let shift = shift_stated.unwrap_or(span.max(1.0));
        let plunges = (span / shift - 1e-9).ceil();
        let pecks = (depth_total / peck.max(1e-9) - 1e-9).ceil();
        if !(plunges.is_finite() && pecks.is_finite() && plunges <= MAX_PASSES && pecks * (plunges + 1.0) <= MAX_PASSES * 10.0) {
            let msg = format!("{}: {} plunges of {} pecks are too many; the cycle is skipped", def.label(), plunges, pecks);
            return diags.push(Diagnostic::new(Code::BadValue, range, msg));
        }
        let intent = TurnIntent {
            kind: Some(if grooving { TurnKind::Groove } else { TurnKind::FacePeck }),
            code: def.label(),
            retract: Some(setup.peck_retract),
            peck: peck_stated,
            step: shift_stated.filter(|_| span > 0.0),
            ..TurnIntent::default()
        };
        self.emit(sink, CanonOp::Turning(Box::new(intent)));
        let dir_d = (t[d] - start[d]).signum();
        let dir_s = (t[s] - start[s]).signum();
        for k in 0..=plunges as u32 {
            let mut at = start;
            at[s] = if f64::from(k) * shift >= span { t[s] } else { start[s] + dir_s * f64::from(k) * shift };
            if k > 0 {
                self.go_to(sink, at, false);
            }
            let mut reached = 0.0;
            while reached < depth_total - 1e-9 {
                reached = (reached + peck).min(depth_total);
                let mut p = at;
                p[d] = start[d] + dir_d * reached;
                self.go_to(sink, p, true);
                if reached < depth_total - 1e-9 && setup.peck_retract > 0.0 {
                    p[d] -= dir_d * setup.peck_retract;
                    self.go_to(sink, p, false);
                }
            }
            self.go_to(sink, at, false);
        }
        self.go_to(sink, start, false);
        self.emit(sink, CanonOp::TurningEnd);
    }

    /// G76: the passes of a thread from the start point to the end point (X the minor
    /// diameter, Z the thread's end), R the taper (radius) and F the lead; in Fanuc's
    /// two-block form P and Q of the second block are the height and first depth in least
    /// increments, in the one-block form (Haas `G76 X Z K D F A P I`) the dictionary names
    /// the words of the height, the first depth, the tool's angle, the infeed method and the
    /// taper.
    fn thread_multiple(
        &mut self,
        def: &CodeDef,
        range: TextRange,
        setup: LatheSetup,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let named = |s: &Self, role: Role| def.args.iter().find(|(_, to)| *to == role).and_then(|(from, _)| s.slot(*from));
        // The one-block form where the block gives the word the dictionary names for the height
        // (Haas `G76 X Z K D F`, Fanuc's FS15 tape format); else Fanuc's two-block P and Q.
        let one_block = named(self, Role::ProfileDepth).is_some();
        let mut spec = if one_block {
            let method = named(self, Role::MachiningType).map_or(1, |p| p.round() as i64);
            ThreadSpec {
                height: named(self, Role::ProfileDepth).map_or(0.0, f64::abs),
                first: named(self, Role::CutDepth).map_or(0.0, f64::abs),
                taper: named(self, Role::R).unwrap_or(0.0),
                setup: LatheSetup { finish_passes: 1, angle: named(self, Role::ToolAngle).unwrap_or(0.0), ..setup },
                constant_depth: matches!(method, 3 | 4),
                alternate: matches!(method, 2 | 4),
                lead: 0.0,
            }
        } else {
            ThreadSpec {
                height: self.slot(Role::P).map(|v| self.increments(v)).unwrap_or(0.0),
                first: self.slot(Role::Q).map(|v| self.increments(v)).unwrap_or(0.0),
                taper: self.slot(Role::R).unwrap_or(0.0),
                setup,
                constant_depth: false,
                alternate: false,
                lead: 0.0,
            }
        };
        let Some(lead) = self.slot(Role::F).or((self.st.feed > 0.0).then_some(self.st.feed)) else {
            let msg = format!("{} without F (the lead) was skipped", def.label());
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        };
        spec.lead = lead;
        if !(spec.height > 0.0 && spec.first > 0.0 && spec.first <= spec.height) {
            let msg = format!("{}: the thread height and the first depth of cut (at most the height) must be above 0", def.label());
            return diags.push(Diagnostic::new(Code::BadValue, range, msg));
        }
        let rough_to = (spec.height - spec.setup.finish_allowance).max(spec.first);
        if rough_to / spec.first > MAX_PASSES {
            return diags.push(Diagnostic::new(Code::BadValue, range, format!("{}: too many passes", def.label())));
        }
        self.thread_passes(def, &spec, sink);
    }

    /// The passes of a thread: pass n at depth Δd·√n (or n·Δd at a constant depth), never less
    /// than the least cut more than the one before, up to the height less the finishing
    /// allowance, then the finishing passes at the full height; each infeeds along a flank
    /// (both in turn when `alternate`).
    fn thread_passes(&mut self, def: &CodeDef, spec: &ThreadSpec, sink: &mut dyn CanonSink) {
        let (end, start) = (self.target(), self.st.pos);
        let setup = spec.setup;
        let rough_to = (spec.height - setup.finish_allowance).max(spec.first);
        let intent = TurnIntent {
            kind: Some(TurnKind::Thread),
            code: def.label(),
            pitch: Some(spec.lead),
            thread_depth: Some(spec.height),
            first_cut: Some(spec.first),
            min_cut: Some(setup.min_cut),
            finish_allowance: Some(setup.finish_allowance),
            finish_passes: Some(setup.finish_passes.max(1)),
            angle: Some(setup.angle),
            ..TurnIntent::default()
        };
        self.emit(sink, CanonOp::Turning(Box::new(intent)));
        // Outside (the start above the thread) or inside; the crest is the bottom plus the height.
        let out = if start[0] >= end[0] { 1.0 } else { -1.0 };
        let crest = end[0] + out * spec.height;
        let along = (end[2] - start[2]).signum();
        let tan = (setup.angle / 2.0).to_radians().tan();
        let mut depths = Vec::new();
        let mut n = 1.0_f64;
        let mut last = 0.0_f64;
        loop {
            let step = if spec.constant_depth { spec.first * n } else { spec.first * n.sqrt() };
            let d = step.max(last + setup.min_cut).min(rough_to);
            depths.push(d);
            last = d;
            if d >= rough_to - 1e-9 {
                break;
            }
            n += 1.0;
        }
        depths.extend(std::iter::repeat_n(spec.height, setup.finish_passes.max(1) as usize));
        for (k, d) in depths.into_iter().enumerate() {
            let mut p = start;
            p[0] = crest - out * d - spec.taper;
            // Infeed along the flank: each pass starts further back by its depth's share
            // (forward on the other flank every second pass when alternating).
            let flank = if spec.alternate && k % 2 == 1 { -1.0 } else { 1.0 };
            p[2] = start[2] - flank * along * d * tan;
            self.go_to(sink, p, false);
            let mut q = end;
            q[0] = crest - out * d;
            self.emit(sink, CanonOp::StartSpeedFeedSync(spec.lead));
            self.go_to(sink, q, true);
            self.emit(sink, CanonOp::StopSpeedFeedSync);
            let mut back = q;
            back[0] = start[0];
            self.go_to(sink, back, false);
            self.go_to(sink, start, false);
        }
        self.emit(sink, CanonOp::TurningEnd);
    }

    pub(super) fn go_to(&mut self, sink: &mut dyn CanonSink, p: [f64; 6], feed: bool) {
        self.emit(sink, if feed { CanonOp::StraightFeed(p) } else { CanonOp::StraightTraverse(p) });
        self.st.pos = p;
    }

    /// Polar coordinate interpolation on (G12.1, TRANSMIT) or off (G13.1, TRAFOOF): the
    /// moves between are milling on the face, in its XY plane with the tool along Z.
    pub(super) fn face_mode(&mut self, on: bool, sink: &mut dyn CanonSink) {
        // TRAFOOF ends any transformation: cylindrical interpolation too.
        if !on && self.st.cylinder.is_some() {
            self.cylinder_mode(None, TextRange::default(), sink, &mut Vec::new());
            return;
        }
        let plane = match (on, self.st.face_plane) {
            (true, None) => {
                self.st.face_plane = Some(self.st.plane);
                crate::canon::Plane::Xy
            }
            (false, Some(p)) => {
                self.st.face_plane = None;
                // The face's second axis is the C axis turned: no lathe axis stays there.
                self.st.pos[1] = 0.0;
                p
            }
            _ => return,
        };
        self.st.plane = plane;
        self.emit(sink, CanonOp::SelectPlane(plane));
    }

    /// In polar coordinate interpolation, a C word is the face's second linear axis (Y).
    pub(super) fn face_words(&mut self) {
        if let Some(c) = self.slots[Role::C as usize].take() {
            self.slots[Role::Y as usize] = Some(c);
            self.filled |= 1 << Role::Y as u32;
        }
    }
}

/// Cylindrical interpolation in force: the cylinder's radius and the C angle (degrees) it
/// began at, where the developed surface is laid tangent to the cylinder.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Cylinder {
    radius: f64,
    c0: f64,
    /// Where the moves are a cylinder surface cycle's contour (Heidenhain 27, 28, 29, 39:
    /// `interp::cylsurf`), how its words are read (`SurfaceWords`).
    surface: Option<SurfaceWords>,
}

impl Cylinder {
    /// The working plane of the developed surface, tangent to the cylinder at `c0`: its Z the
    /// radial direction there (the driven tool's axis), its X along -Z (the spindle axis), its
    /// Y the way C turns, as `interp::live` drills a side hole.
    fn frame(&self) -> Frame {
        let (s, co) = self.c0.to_radians().sin_cos();
        Frame { origin: [0.0; 3], rotation: [[0.0, -s, co], [0.0, co, s], [-1.0, 0.0, 0.0]] }
    }

    /// A length on the developed surface for `degrees` of C.
    fn developed(&self, degrees: f64) -> f64 {
        self.radius * degrees.to_radians()
    }
}

/// How a cylinder surface cycle's contour is read on the developed surface.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct SurfaceWords {
    /// Whether its C words are lengths round the cylinder (`Q17=1`) rather than degrees.
    pub(super) mm: bool,
    /// The way an X word runs along the developed surface's X (the cylinder's -Z): +1 or -1,
    /// as the tilted working plane's X runs along the cylinder (`PLANE SPATIAL SPB+90`: its X
    /// is the part's -Z, so +1).
    pub(super) x_sense: f64,
}

impl Interpreter<'_> {
    /// Under cylindrical interpolation, reads the blocks that follow as a cylinder surface
    /// cycle's contour (`Some`) or as written (`None`): see `cylinder_words`.
    pub(super) fn cylinder_contour_words(&mut self, surface: Option<SurfaceWords>) {
        if let Some(cyl) = self.st.cylinder.as_mut() {
            cyl.surface = surface;
        }
    }
}

impl Interpreter<'_> {
    /// Cylindrical interpolation's code (Fanuc `G07.1 C25.`, `G107 C25.`): the word the
    /// dictionary maps to `extra` gives the cylinder's radius, 0 ends the mode. Without that
    /// word (`TRACYL` as a keyword) the cycle form's argument gives it (`cycles_after`).
    pub(super) fn cylinder_code(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let Some(&(from, _)) = def.args.iter().find(|(_, to)| *to == Role::Extra) else { return };
        if let Some(r) = self.slot(from) {
            self.cylinder_mode((r.abs() > 1e-9).then_some(r.abs()), range, sink, diags);
        }
    }

    /// Cylindrical interpolation on with the cylinder's `radius`, or off (`None`). The
    /// moves between are milling on the cylinder by a driven tool whose axis is radial. They
    /// are written in the working plane of the developed surface laid tangent to the
    /// cylinder at the C angle the mode began at (`Cylinder::frame`): X along -Z, Y the
    /// developed length (the radius times C in radians), Z the radius the tool cuts at. The
    /// cylinder goes first as a `CylinderWrap` marker, so that the plan wraps what is cut
    /// there round it (`plan::Setup::wrapped_at`: a feature placed where it begins, at its own
    /// angle with its radial axis, and each move's radial tool axis taken from where it ends,
    /// `Recoverer::wrap_axis`) [the toolpath itself stays on the developed surface]. The
    /// radial axis is not sent as `ToolAxis` markers: the moves are the developed surface's as
    /// the program writes them, not a tool axis indexed by rotary axes.
    pub(super) fn cylinder_mode(&mut self, radius: Option<f64>, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let p = self.st.pos;
        match (radius, self.st.cylinder) {
            (Some(radius), None) => {
                if self.st.face_plane.is_some() {
                    self.face_mode(false, sink);
                }
                let cyl = Cylinder { radius, c0: p[5], surface: None };
                self.st.face_plane = Some(self.st.plane);
                self.st.cylinder = Some(cyl);
                self.st.plane = Plane::Xy;
                self.emit(sink, CanonOp::SelectPlane(Plane::Xy));
                self.emit(sink, CanonOp::Setting(Setting::CylinderWrap(Some(radius))));
                self.emit(sink, CanonOp::WorkPlane(Some(Box::new(cyl.frame()))));
                // The cylinder's surface is the top the slot or profile is cut from.
                self.emit(sink, CanonOp::Setting(Setting::CycleSurface(radius)));
                // The tool where it is, in the plane's coordinates: recovery carries a lathe
                // point into the plane as if at C0, so the point is told again.
                self.go_to(sink, [-p[2], 0.0, p[0], p[3], p[4], p[5]], false);
                let msg = format!(
                    "cylindrical interpolation (radius {}): the moves are milling on the cylinder, on its developed surface laid tangent at C{} (its Y the length round the cylinder): what they cut is wrapped round it, placed where it begins with its axis radial there and the tool axis radial at each move, but the toolpath itself is kept on the developed surface",
                    crate::text::num(radius),
                    crate::text::num(p[5]),
                );
                self.limited(diags, "cylinder-developed", Diagnostic::new(Code::Unsupported, range, msg));
            }
            (None, Some(cyl)) => {
                let c = cyl.c0 + (p[1] / cyl.radius).to_degrees();
                self.st.pos = [p[2], 0.0, -p[0], p[3], p[4], c];
                self.st.cylinder = None;
                let plane = self.st.face_plane.take().unwrap_or(Plane::Xz);
                self.st.plane = plane;
                self.emit(sink, CanonOp::Setting(Setting::MillCycle(None)));
                self.emit(sink, CanonOp::Setting(Setting::CylinderWrap(None)));
                self.emit(sink, CanonOp::WorkPlane(None));
                self.emit(sink, CanonOp::SelectPlane(plane));
            }
            // A new radius while on: the same developed surface, measured anew.
            (Some(radius), Some(cyl)) => {
                let cyl = Cylinder { radius, ..cyl };
                self.st.cylinder = Some(cyl);
                self.emit(sink, CanonOp::Setting(Setting::CylinderWrap(Some(radius))));
                self.emit(sink, CanonOp::WorkPlane(Some(Box::new(cyl.frame()))));
            }
            (None, None) => {}
        }
    }

    /// Under cylindrical interpolation, a rapid round the cylinder (along the developed length)
    /// that ends clear of it (its radius at or above the cylinder's) lays the developed surface's plane anew,
    /// tangent at the angle the tool now stands over: the developed length is the angle times
    /// the radius (Fanuc G07.1, Siemens TRACYL), so the tool stands over C0 + Y / radius. What it
    /// cuts next then lies on the cylinder at its own angle with its radial axis there, as a side
    /// hole does (`interp::live`), not on the plane laid at the angle the mode began at. A cut
    /// that runs round the cylinder from there is wrapped by the plan (`Setting::CylinderWrap`).
    ///
    /// The rapid to `t` (the plane's coordinates) is made so, on the plane laid anew, and true;
    /// false where it stays on the plane in force.
    pub(super) fn cylinder_rapid(&mut self, t: [f64; 6], sink: &mut dyn CanonSink) -> bool {
        let Some(cyl) = self.st.cylinder else { return false };
        // Only a rapid round the cylinder: a retract where a cut ended stays on its plane, so
        // that the passes of one cut back from there lie with it.
        if t[2] < cyl.radius - 1e-6 || t[1].abs() < 1e-6 || (t[1] - self.st.pos[1]).abs() < 1e-6 {
            return false;
        }
        let c0 = cyl.c0 + (t[1] / cyl.radius).to_degrees();
        let cyl = Cylinder { c0, ..cyl };
        self.st.cylinder = Some(cyl);
        self.emit(sink, CanonOp::WorkPlane(Some(Box::new(cyl.frame()))));
        self.emit(sink, CanonOp::Setting(Setting::CycleSurface(cyl.radius)));
        self.go_to(sink, [t[0], 0.0, t[2], t[3], t[4], t[5]], false);
        true
    }

    /// Under cylindrical interpolation, the words in the developed surface's plane
    /// (`cylinder_mode`): Z along its -X, C (degrees, from the angle the mode began at) or Y
    /// (a length) its Y, X (the radius the tool cuts at) its Z. The cylinder code's own word
    /// (`G07.1 C0`) stays the code's.
    pub(super) fn cylinder_words(&mut self, cyl: Cylinder) {
        let take = |me: &mut Self, role: Role| {
            if me.taken_by_code(role) {
                return None;
            }
            me.filled &= !(1 << role as u32);
            me.slots[role as usize].take()
        };
        let (x, y, z, c) = (take(self, Role::X), take(self, Role::Y), take(self, Role::Z), take(self, Role::C));
        let absolute = |s: &Slot| match s.mode {
            WordMode::Modal => self.st.distance != DistanceMode::Incremental,
            WordMode::Absolute => true,
            WordMode::Incremental => false,
        };
        let put = |me: &mut Self, role: Role, slot: Option<Slot>| {
            if let Some(slot) = slot {
                me.slots[role as usize] = Some(slot);
                me.filled |= 1 << role as u32;
            }
        };
        // A cylinder surface cycle's contour (TNC 640 cycles 27, 28, 29, 39): drawn in the
        // rotary axis and the linear axis parallel to it, X where the working plane is tilted
        // so that its X runs along the cylinder (`SurfaceWords::x_sense`), Z where it is not
        // (along -X here); C in degrees or, where the cycle says so (`Q17=1`),
        // as a length round the cylinder. Its depth is the cycle's (`Q1`), so no word is the
        // radius.
        if let Some(words) = cyl.surface {
            let along = c.map(|s| {
                let length = |v: f64| if words.mm { v } else { cyl.developed(v) };
                Slot { value: if absolute(&s) { length(s.value) - cyl.developed(cyl.c0) } else { length(s.value) }, ..s }
            });
            let x = x.map(|s| Slot { value: words.x_sense * s.value, ..s });
            put(self, Role::X, x.or(z.map(|s| Slot { value: -s.value, ..s })));
            put(self, Role::Y, along);
            return;
        }
        let along = c
            .map(|s| Slot { value: cyl.developed(if absolute(&s) { s.value - cyl.c0 } else { s.value }), ..s })
            .or(y.map(|s| Slot { value: if absolute(&s) { s.value - cyl.developed(cyl.c0) } else { s.value }, ..s }));
        put(self, Role::X, z.map(|s| Slot { value: -s.value, ..s }));
        put(self, Role::Y, along);
        put(self, Role::Z, x);
    }
}

//! Straight and circular motion.

use super::{Interpreter, Spindle};
use crate::canon::{
    CanonOp, CanonSink, CycleIntent, CycleKind, DistanceMode, MachineMove, MachineTarget, Plane, TurnIntent, TurnKind, Units,
};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, DecimalInput, Meaning, Role, SystemVar};
use crate::syntax::{Block, WordMode};
use crate::text::TextRange;

/// Offset roles along X, Y and Z.
const OFFSETS: [Role; 3] = [Role::I, Role::J, Role::K];

impl Interpreter<'_> {
    /// The end point of a move: axis words in the distance mode, in program coordinates.
    pub(super) fn target(&self) -> [f64; 6] {
        let machine =
            self.codes.iter().any(|&(c, _)| matches!(self.code(c).meaning, Meaning::MachineCoords | Meaning::MachineBuilderCoords));
        if machine && self.st.rotation(self.st.wcs) != 0.0 {
            // In a rotated system the machine point maps to program X and Y together.
            let mut m = self.machine_pos();
            for (i, &role) in Role::AXES.iter().enumerate() {
                if let Some(v) = self.slot(role).filter(|_| !self.taken_by_code(role)) {
                    m[i] = v;
                }
            }
            let mut t = self.program_pos(m);
            for (i, &role) in [Role::X, Role::Y, Role::Z].iter().enumerate() {
                if self.slot(role).is_some() {
                    t[i] -= self.st.tool_offset[i];
                }
            }
            return t;
        }
        let mut t = self.st.pos;
        for (i, &role) in Role::AXES.iter().enumerate() {
            if let Some(slot) = self.slots[role as usize].filter(|_| !self.taken_by_code(role)) {
                let v = slot.value;
                let incremental = match slot.mode {
                    WordMode::Modal => self.st.distance == DistanceMode::Incremental,
                    WordMode::Absolute => false,
                    WordMode::Incremental => true,
                };
                t[i] = if machine {
                    // The tool offsets move the controlled point along X, Y and Z.
                    let tlo = if i < 3 { self.st.tool_offset[i] } else { 0.0 };
                    v - self.st.offset(self.st.wcs)[i] - self.st.g92[i] - tlo
                } else if incremental {
                    self.st.pos[i] + v
                } else {
                    v
                };
            }
        }
        if self.slots[Role::PolarRadius as usize].is_some() || self.slots[Role::PolarAngle as usize].is_some() {
            self.polar_target(self.st.pos, &mut t);
        }
        t
    }

    /// A straight feed given by its line's angle from +Z (Fanuc lathe direct drawing
    /// dimensions, 0i-TF / 30i T series): with one end coordinate (`G01 X51.,A-45.`) the one
    /// the block leaves out is where that line meets the given one (X in the radius the slots
    /// hold); with the angle alone (`G01 ,A150.`) the move waits for the next block, which
    /// gives its end point and its own line's angle (`G01 X60. Z-30.,A90.`): the first move
    /// ends where the two lines meet ([`Interpreter::angle_corner`]). Other forms (a corner
    /// `,R`/`,C` between the two blocks, arcs) are not computed, and said so. True when the
    /// move waits.
    fn direct_drawing(&mut self, angle: f64, t: &mut [f64; 6], range: TextRange, diags: &mut Vec<Diagnostic>) -> bool {
        let given = |r: Role| self.slots[r as usize].is_some() && !self.taken_by_code(r);
        let tan = angle.to_radians().tan();
        let from = self.st.pos;
        let xz = self.st.plane == Plane::Xz;
        match (given(Role::X), given(Role::Z)) {
            (true, false) if xz && tan.abs() > 1e-9 => t[2] = from[2] + (t[0] - from[0]) / tan,
            (false, true) if xz && tan.abs() < 1e9 => t[0] = from[0] + (t[2] - from[2]) * tan,
            (false, false) if xz && self.filled & super::CORNER_WORDS == 0 => {
                self.st.angle_line = Some((angle, range));
                return true;
            }
            _ => {
                let msg = format!(
                    "the line angle A{angle} with this block's coordinates (a corner between two angle blocks, or not in G18) is not computed: the move goes to the coordinates given"
                );
                diags.push(Diagnostic::new(Code::Unsupported, range, msg));
            }
        }
        false
    }

    /// The waiting angle-only move (`G01 ,A150.`) ended where its line meets this block's
    /// line through its end point `t` at `angle`: emitted now. False (and said so) where the
    /// two lines do not meet, or this block does not give both end coordinates.
    fn angle_corner(
        &mut self,
        first: (f64, TextRange),
        angle: Option<f64>,
        t: &[f64; 6],
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let given = |r: Role| self.slots[r as usize].is_some() && !self.taken_by_code(r);
        let (a1, at) = first;
        let from = self.st.pos;
        let meet = angle.filter(|_| given(Role::X) && given(Role::Z) && self.st.plane == Plane::Xz).and_then(|a2| {
            let (d1, d2) = ((a1.to_radians().sin(), a1.to_radians().cos()), (a2.to_radians().sin(), a2.to_radians().cos()));
            let det = d2.0 * d1.1 - d1.0 * d2.1;
            (det.abs() > 1e-9).then(|| {
                let (ex, ez) = (t[0] - from[0], t[2] - from[2]);
                let s = (d2.0 * ez - ex * d2.1) / det;
                (from[0] + s * d1.0, from[2] + s * d1.1)
            })
        });
        let Some((x, z)) = meet else {
            let msg = format!(
                "the line angle A{a1} alone waits for a next block giving its end point and an angle whose line meets it; this one does not: that move is left out"
            );
            diags.push(Diagnostic::new(Code::Unsupported, at, msg));
            return;
        };
        let mut p = from;
        (p[0], p[2]) = (x, z);
        self.note_tangent(p);
        self.emit(sink, CanonOp::StraightFeed(p));
        self.st.pos = p;
    }

    /// Whether a code of the block gives this axis letter's word another meaning (Haas
    /// lathe `G76 ... A60`: A is the tool's angle, `args="A:tool-angle"`), so the word is
    /// no axis target in that block.
    pub(super) fn taken_by_code(&self, role: Role) -> bool {
        self.codes.iter().any(|&(c, _)| self.code(c).args.iter().any(|&(from, _)| from == role))
    }

    /// Whether a code of the block reads this axis letter's word as an angle (the one-block
    /// lathe `G76 ... A60`: the tool's included angle in degrees, `args="A:tool-angle"`): no
    /// length, so no least increments.
    pub(super) fn taken_as_angle(&self, role: Role) -> bool {
        self.codes.iter().any(|&(c, _)| self.code(c).args.iter().any(|&(from, to)| from == role && to == Role::ToolAngle))
    }

    /// `LP PR+30 PA+45`, `CP IPA+90`: the end point in the plane from its distance to the pole
    /// and its angle about it; a missing one keeps the current point's, an incremental one
    /// (`IPR`, `IPA`) adds to the distance and angle of `from`, the point the move starts at.
    pub(super) fn polar_target(&self, from: [f64; 6], t: &mut [f64; 6]) {
        let (a0, a1, _) = self.st.plane.axes();
        // Fanuc G16: the pole is the work origin (an incremental radius, which would move it,
        // is refused where it is read, `polar_command_words`).
        let (px, py) = if self.st.polar_command { (0.0, 0.0) } else { self.st.pole };
        let (dx, dy) = (from[a0] - px, from[a1] - py);
        let polar = |role: Role, current: f64| match self.slots[role as usize] {
            None => current,
            Some(s) if self.incremental(role) => current + s.value,
            Some(s) => s.value,
        };
        let r = polar(Role::PolarRadius, dx.hypot(dy));
        let a = polar(Role::PolarAngle, dy.atan2(dx).to_degrees()).to_radians();
        t[a0] = px + r * a.cos();
        t[a1] = py + r * a.sin();
    }

    /// The arc centre the block's I, J or K words give in the plane of axes `a0`, `a1`: they are
    /// incremental from the start (G91.1) or absolute (G90.1), or per word (`I=AC(28)`).
    /// `None` when the block has none in that plane.
    pub(super) fn centre_words(&self, a0: usize, a1: usize, start: [f64; 6]) -> Option<(f64, f64)> {
        let off = |axis: usize| self.slot(OFFSETS[axis]);
        if off(a0).is_none() && off(a1).is_none() {
            return None;
        }
        let centre = |axis: usize| {
            let o = off(axis).unwrap_or(0.0);
            let incremental = match self.slots[OFFSETS[axis] as usize].map(|s| s.mode) {
                Some(WordMode::Absolute) => false,
                Some(WordMode::Incremental) => true,
                // Where the centre is the pole (Heidenhain ISO), G91 makes it incremental.
                _ if self.dialect.behaviour.arc_centres_pole => self.st.distance == DistanceMode::Incremental,
                _ => self.st.arc_incremental,
            };
            // Under diameter programming an absolute X centre is a diameter where the control
            // reads it so (SINUMERIK `I=AC(50)`: `arc-centre-x="diameter-absolute"`).
            let halved = axis == 0 && self.st.diameter && self.dialect.behaviour.absolute_centre_x_diameter;
            if incremental {
                start[axis] + o
            } else if halved {
                o / 2.0
            } else {
                o
            }
        };
        Some((centre(a0), centre(a1)))
    }

    /// Marks a straight move the block states in machine coordinates (`G53`, `SUPA`, `M91`)
    /// with the machine coordinates it names, so that a writer keeps it one; likewise one
    /// from the machine builder's datum (`M92`), which only the machine knows.
    fn machine_marker(&mut self, sink: &mut dyn CanonSink) {
        if self.codes.is_empty() {
            return;
        }
        let target = self.codes.iter().find_map(|&(c, _)| match self.code(c).meaning {
            Meaning::MachineCoords => Some(MachineTarget::Machine),
            Meaning::MachineBuilderCoords => Some(MachineTarget::Builder),
            _ => None,
        });
        let Some(target) = target else { return };
        let axes = std::array::from_fn(|i| self.slot(Role::AXES[i]));
        if axes.iter().any(Option::is_some) {
            self.emit(sink, CanonOp::MachineMove(Box::new(MachineMove { target, axes })));
        }
    }

    /// The axes the block's words state absolutely (bit `k` for axis `k`), which its move
    /// makes known ([`crate::canon::CanonOp::Known`]): a straight move's, an arc's, an approach's
    /// or a thread's end; a hole cycle's position in the plane (its hole axis returns to a
    /// level counted from where it began). Not words in machine coordinates, not the end of a
    /// single-pass lathe cycle or a tap (both go back to where they began), not a probe's
    /// (it stops where it touches).
    fn stated_by(&self, meaning: Meaning, arc: bool) -> u8 {
        let absolute = |role: Role| self.slots[role as usize].is_some() && !self.taken_by_code(role) && !self.incremental(role);
        let mut m = 0u8;
        for (i, &role) in Role::AXES.iter().enumerate() {
            if absolute(role) {
                m |= 1 << i;
            }
        }
        let (a0, a1, _) = self.st.plane.axes();
        // Polar words: absolute distance and angle about the pole state the plane's axes.
        if absolute(Role::PolarRadius) && absolute(Role::PolarAngle) {
            m |= 1 << a0 | 1 << a1;
        }
        let machine = !self.codes.is_empty() && self.codes.iter().any(|&(c, _)| self.code(c).meaning == Meaning::MachineCoords);
        match meaning {
            _ if machine => 0,
            Meaning::Rapid | Meaning::Linear | Meaning::SpindleSync => m,
            _ if arc => m,
            // Its first move goes to a point in the plane worked out from the stated one, at
            // the height the tool is at.
            Meaning::ApproachTangent
            | Meaning::ApproachNormal
            | Meaning::ApproachArc
            | Meaning::DepartTangent
            | Meaning::DepartNormal
            | Meaning::DepartArc => m & (1 << a0 | 1 << a1),
            Meaning::RigidTap
            | Meaning::CycleThread
            | Meaning::CycleTurn
            | Meaning::CycleFace
            | Meaning::CycleThreadPass
            | Meaning::Probe
            | Meaning::ProbeQuiet
            | Meaning::SplineQuadratic
            | Meaning::Nurbs => 0,
            // A hole cycle: its position in the plane.
            _ => m & (1 << a0 | 1 << a1),
        }
    }

    /// Whether the axis word for `role` is incremental (per word, or by G91).
    pub(super) fn incremental(&self, role: Role) -> bool {
        match self.slots[role as usize].map(|s| s.mode) {
            Some(WordMode::Absolute) => false,
            Some(WordMode::Incremental) => true,
            _ => self.st.distance == DistanceMode::Incremental,
        }
    }

    pub(super) fn motion(&mut self, def: &CodeDef, range: TextRange, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.motions += 1;
        if def.meaning != Meaning::Linear
            && let Some((a1, at)) = self.st.angle_line.take()
        {
            let msg = format!(
                "the line angle A{a1} alone waits for a next straight feed with its end point and angle; {} followed: that move is left out",
                def.label()
            );
            diags.push(Diagnostic::new(Code::Unsupported, at, msg));
        }
        // A block of a rapid code (`FMAX`), or in machine coordinates on a control whose G53
        // always positions at rapid traverse (`machine-coords-rapid`), moves at rapid whatever
        // the motion mode in force.
        let rapid_of = |m: Meaning| {
            m == Meaning::RapidBlock
                || (matches!(m, Meaning::MachineCoords | Meaning::MachineBuilderCoords) && self.dialect.behaviour.machine_coords_rapid)
        };
        let rapid_block = !self.codes.is_empty() && self.codes.iter().any(|&(c, _)| rapid_of(self.code(c).meaning));
        let arc = matches!(
            def.meaning,
            Meaning::ArcCw | Meaning::ArcCcw | Meaning::ArcPole | Meaning::ArcRadius | Meaning::ArcTangent | Meaning::ArcThreePoint
        );
        if std::mem::take(&mut self.st.leaving_comp) && arc {
            // The move that takes the tool off its compensated path has to be straight.
            let msg = format!("{}: the move just after cutter compensation ends must be straight, not an arc", def.label());
            diags.push(Diagnostic::new(Code::BadArc, range, msg));
            return;
        }
        if matches!(def.meaning, Meaning::Rapid | Meaning::Linear) {
            self.machine_marker(sink);
        }
        self.stated.set(self.stated_by(def.meaning, arc));
        if self.slots[Role::W as usize].is_some() && (arc || matches!(def.meaning, Meaning::Rapid | Meaning::Linear)) {
            self.quill_word();
        }
        match def.meaning {
            Meaning::Rapid | Meaning::Linear if rapid_block => {
                let t = self.target();
                self.note_tangent(t);
                self.emit(sink, CanonOp::StraightTraverse(t));
                self.st.pos = t;
            }
            Meaning::Rapid => {
                let t = self.target();
                self.note_tangent(t);
                if self.st.cylinder.is_some() && self.cylinder_rapid(t, sink) {
                    return;
                }
                self.emit(sink, CanonOp::StraightTraverse(t));
                self.st.pos = t;
            }
            Meaning::Linear => {
                self.check_technology(def, block.range, diags);
                let mut t = self.target();
                let angle = self.slots[Role::LineAngle as usize].map(|a| a.value);
                if let Some(first) = self.st.angle_line.take() {
                    self.angle_corner(first, angle, &t, sink, diags);
                } else if let Some(a) = angle
                    && self.direct_drawing(a, &mut t, range, diags)
                {
                    return;
                }
                if self.st.inverse_time {
                    let length = (0..3).map(|i| (t[i] - self.st.pos[i]).powi(2)).sum::<f64>().sqrt();
                    if !self.inverse_time_feed(def, length, block, sink, diags) {
                        return;
                    }
                }
                self.note_tangent(t);
                self.emit(sink, CanonOp::StraightFeed(t));
                self.st.pos = t;
            }
            Meaning::ArcCw | Meaning::ArcCcw | Meaning::ArcPole | Meaning::ArcRadius | Meaning::ArcTangent | Meaning::ArcThreePoint => {
                let before = diags.len();
                // An arc about a pole given in another plane (`CC Y Z`, then `C Y Z DR+`) runs
                // in the pole's plane; the active plane is back after it.
                let pole_plane = self.st.pole_plane.filter(|p| def.meaning == Meaning::ArcPole && *p != self.st.plane);
                let active = self.st.plane;
                if let Some(p) = pole_plane {
                    self.st.plane = p;
                    self.emit(sink, CanonOp::SelectPlane(p));
                }
                self.arc(def, range, block, sink, diags);
                if pole_plane.is_some() {
                    self.st.plane = active;
                    self.emit(sink, CanonOp::SelectPlane(active));
                }
                self.misread_consequences(&mut diags[before..]);
            }
            Meaning::SpindleSync | Meaning::RigidTap => self.synchronised(def, range, sink, diags),
            Meaning::CycleThread => self.threading_cycle(def, range, sink, diags),
            Meaning::CycleTurn | Meaning::CycleFace | Meaning::CycleThreadPass => self.single_pass_cycle(def, range, sink, diags),
            Meaning::Probe | Meaning::ProbeQuiet => self.probe(def, range, sink, diags),
            Meaning::SplineQuadratic | Meaning::Nurbs => self.spline(def, range, sink, diags),
            Meaning::ApproachTangent | Meaning::ApproachNormal | Meaning::ApproachArc => self.approach(def, range, block, sink, diags),
            Meaning::DepartTangent | Meaning::DepartNormal | Meaning::DepartArc => self.depart(def, range, block, sink, diags),
            _ => self.cycle(def, range, block, sink, diags),
        }
    }

    /// G33 (a thread: a feed move advancing K per spindle revolution) and G33.1 (rigid
    /// tapping: synchronised to the target and back out to where it started). The feed rate
    /// does not apply; the spindle speed does. The dictionary makes the lead required.
    fn synchronised(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        if !self.spindle_turns(def, range, diags) {
            return;
        }
        // The lead is K (LinuxCNC, Siemens), or F where the dictionary gives the code F
        // (Fanuc); a lathe dictionary that gives it both reads whichever the block has (NX
        // posts for Mazak, Mitsubishi, Okuma and Fagor lathes write `G32 Z K`).
        let leads: Vec<Role> = [Role::F, Role::K].into_iter().filter(|r| def.params.takes(*r)).collect();
        // Where F is the lead, it is the feed word and modal as any feed: under feed per
        // revolution a later thread block without F cuts at the F in force (the Haas lathe
        // manual, G32: "Feedrate is equivalent to thread lead", G99 active; a G32 sequence).
        let modal = (leads.first() == Some(&Role::F) && self.st.feed_per_rev && self.st.feed > 0.0).then_some(self.st.feed);
        let Some(pitch) = leads.iter().find_map(|r| self.slot(*r)).or(modal) else {
            let names: Vec<&str> = leads.iter().map(|r| if *r == Role::F { "F" } else { "K" }).collect();
            let names = if names.is_empty() { "K".to_owned() } else { names.join(" or ") };
            let msg = format!("{} without {names} (the advance per revolution) was skipped", def.label());
            diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
            return;
        };
        let t = self.target();
        self.emit(sink, CanonOp::StartSpeedFeedSync(pitch));
        if def.meaning == Meaning::RigidTap {
            let from = self.st.pos;
            let intent = CycleIntent {
                kind: CycleKind::Tapping,
                code: def.label(),
                x: t[0],
                y: t[1],
                bottom: t[2],
                r_plane: from[2],
                clear: from[2],
                peck: None,
                dwell: None,
                positioned: false,
                surface: None,
                peck_clearance: None,
                known_at_r: false,
                returns_unknown: false,
            };
            self.emit(sink, CanonOp::CycleBegin(Box::new(intent)));
            self.emit(sink, CanonOp::RigidTap([t[0], t[1], t[2]]));
            self.emit(sink, CanonOp::CycleEnd);
        } else {
            self.note_tangent(t);
            self.emit(sink, CanonOp::StraightFeed(t));
            self.st.pos = t;
        }
        self.emit(sink, CanonOp::StopSpeedFeedSync);
    }

    /// A lathe's single-pass cycle (Fanuc G90, G94, G92): four moves from the start point and
    /// back to it. X is the radial axis, Z the axis of turning. Words the block leaves out
    /// keep the cycle's previous X, Z and taper R.
    fn single_pass_cycle(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let t = self.target();
        let previous = self.st.turn_cycle;
        let given = |role: Role| self.slots[role as usize].is_some();
        let x = if given(Role::X) { t[0] } else { previous.map_or(t[0], |p| p[0]) };
        let z = if given(Role::Z) { t[2] } else { previous.map_or(t[2], |p| p[1]) };
        let r = self.slot(Role::R).or(previous.map(|p| p[2])).unwrap_or(0.0);
        self.st.turn_cycle = Some([x, z, r]);
        let start = self.st.pos;
        let at = |x: f64, z: f64| {
            let mut p = start;
            (p[0], p[2]) = (x, z);
            p
        };
        let thread = def.meaning == Meaning::CycleThreadPass;
        if thread && !self.spindle_turns(def, range, diags) {
            return;
        }
        if !thread {
            self.check_technology(def, range, diags);
        }
        let kind = match def.meaning {
            Meaning::CycleTurn => TurnKind::TurnPass,
            Meaning::CycleFace => TurnKind::FacePass,
            _ => TurnKind::ThreadPass,
        };
        let pitch = if thread { Some(self.slot(Role::F).unwrap_or(self.st.feed)) } else { None };
        self.emit(sink, CanonOp::Turning(Box::new(TurnIntent { kind: Some(kind), code: def.label(), pitch, ..TurnIntent::default() })));
        let moves = match def.meaning {
            // Rapid to the cut's start, feed to the target, feed out, rapid back.
            Meaning::CycleTurn => [(at(x + r, start[2]), true), (at(x, z), false), (at(start[0], z), false), (start, true)],
            Meaning::CycleFace => [(at(start[0], z + r), true), (at(x, z), false), (at(x, start[2]), false), (start, true)],
            _ => [(at(x + r, start[2]), true), (at(x, z), false), (at(start[0], z), true), (start, true)],
        };
        for (i, (p, rapid)) in moves.into_iter().enumerate() {
            if thread && i == 1 {
                let lead = self.slot(Role::F).unwrap_or(self.st.feed);
                self.emit(sink, CanonOp::StartSpeedFeedSync(lead));
                self.emit(sink, CanonOp::StraightFeed(p));
                self.emit(sink, CanonOp::StopSpeedFeedSync);
            } else if rapid {
                self.emit(sink, CanonOp::StraightTraverse(p));
            } else {
                self.emit(sink, CanonOp::StraightFeed(p));
            }
            self.st.pos = p;
        }
        self.emit(sink, CanonOp::TurningEnd);
    }

    /// Whether the spindle turns, as a move synchronised with it needs; else an error (the
    /// control stops: there is no rotation to follow) and false.
    pub(super) fn spindle_turns(&self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) -> bool {
        if self.st.spindle != Spindle::Stopped {
            return true;
        }
        let msg = format!("{} follows the spindle's rotation, and the spindle is not turning (M3 or M4 first)", def.label());
        let mut d = Diagnostic::new(Code::CuttingWithoutTechnology, range, msg);
        d.severity = crate::diag::Severity::Error;
        diags.push(d);
        false
    }

    /// G38.2 to G38.5: a feed towards the end point that stops where the probe touches (or,
    /// away, leaves contact). Where that is, only the machine knows: the analysis takes the
    /// programmed end point for the probe result variables (written once, then the program's
    /// to change) and, backed off towards the start by the dictionary's `probe-backoff`, for
    /// the position, as rs274's simulator does. The tripped variable reads the dictionary's
    /// `probe-tripped`: unknown by default (only the machine knows whether it touched: a loop
    /// `while [#5070 NE 0]` round a quiet probe ends, as it does under rs274's simulator,
    /// which never trips, and a check `if [#5070 EQ 0]` that aborts takes the way a
    /// successful probe goes), or the 1 or 0 a dictionary gives. Only a quiet probe may have
    /// no length: one that must touch stops the run, as rs274 stops.
    fn probe(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let bad = |code: Code, msg: &str| Diagnostic::new(code, range, format!("{}: {msg}", def.label()));
        if self.comp.borrow().is_some() {
            return diags.push(bad(Code::BadValue, "cannot probe with cutter compensation on"));
        }
        if self.st.inverse_time {
            return diags.push(bad(Code::NoFeed, "cannot probe at a zero feed rate (or in inverse time)"));
        }
        // A feed word from outside the file (`F#9`, the caller's argument) is not a zero feed;
        // without one, a called program's feed is its caller's.
        if self.st.feed == 0.0 && !self.word_unknown(Role::F) && !self.st.feed_outside {
            let d = bad(Code::NoFeed, "cannot probe at a zero feed rate (or in inverse time)");
            if !self.st.feed_unknown {
                return diags.push(d);
            }
            let note = format!("{} probes with a feed this file does not set: the feed comes from the caller", def.label());
            self.caller_state(diags, "technology", d, note);
        }
        let t = self.target();
        let start = self.st.pos;
        let length = (0..3).map(|i| (t[i] - start[i]).powi(2)).sum::<f64>().sqrt();
        // An axis word from outside the file was left out: the probe's end is not known.
        let unknown_end = [Role::X, Role::Y, Role::Z].iter().any(|&r| self.word_unknown(r));
        if length < 1e-9 && def.meaning == Meaning::Probe && !unknown_end {
            self.st.ended = true;
            return diags.push(bad(Code::BadValue, "the probe move has no length: it starts at its end point; the run stops here"));
        }
        self.emit(sink, CanonOp::TurnProbeOn);
        self.emit(sink, CanonOp::StraightProbe(t));
        self.emit(sink, CanonOp::TurnProbeOff);
        let b = &self.dialect.behaviour;
        let backoff = if self.st.units == Units::Mm { b.probe_backoff_mm } else { b.probe_backoff_inch };
        let mut stop = t;
        if length >= 1e-9 {
            for i in 0..3 {
                stop[i] += backoff * (start[i] - t[i]) / length;
            }
        }
        self.st.pos = stop;
        self.sent.set(stop);
        for &(n, var) in &self.dialect.macros.system {
            let v = match var {
                SystemVar::ProbeX => t[0],
                SystemVar::ProbeY => t[1],
                SystemVar::ProbeZ => t[2],
                SystemVar::ProbeTripped => self.dialect.behaviour.probe_tripped.unwrap_or(super::eval::UNKNOWN),
                _ => continue,
            };
            let _ = self.params.set(f64::from(n), v);
        }
        let note = bad(
            Code::Unsupported,
            "the probe stops where it touches, which only the machine knows; the analysis goes on from the programmed end point",
        );
        self.limited(diags, "probe", note);
    }

    /// An arc that fails where its start, end or radius comes from a length word that
    /// least-increment input shrank (and that finding was made) fails because of it: one
    /// cause, one error. Its findings become notes that point at that word.
    fn misread_consequences(&self, found: &mut [Diagnostic]) {
        let (a0, a1, _) = self.st.plane.axes();
        let tainted = self.block_misread || [a0, a1].iter().any(|&i| self.misread[i] || self.misread_before[i]);
        let Some(word) = self.misread_word.as_deref().filter(|_| tainted) else { return };
        for d in found.iter_mut().filter(|d| d.code == Code::BadArc && d.is_error()) {
            d.severity = crate::diag::Severity::Note;
            d.message.push_str(&format!("; it follows from {word} (no decimal point), the finding to fix"));
        }
    }

    /// G5.1 (a quadratic spline, run at once) and G5.2 (a NURBS control point, kept until
    /// G5.3): in the XY plane, without Z or rotary motion, and not under cutter
    /// compensation, as rs274 requires.
    fn spline(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let bad = |msg: &str| Diagnostic::new(Code::BadValue, range, format!("{}: {msg}", def.label()));
        if self.st.plane != Plane::Xy {
            return diags.push(bad("splines are in the XY plane only (G17)"));
        }
        if [Role::Z, Role::A, Role::B, Role::C].iter().any(|&r| self.slots[r as usize].is_some()) {
            return diags.push(bad("splines may not move Z, A, B or C"));
        }
        if self.comp.borrow().is_some() {
            return diags.push(bad("splines cannot run with cutter compensation on"));
        }
        let t = self.target();
        if def.meaning == Meaning::SplineQuadratic {
            if self.slot(Role::I).is_none() || self.slot(Role::J).is_none() {
                return diags.push(bad("a quadratic spline needs both I and J (its control point)"));
            }
            self.check_technology(def, range, diags);
            self.emit(sink, CanonOp::NurbsFeed { points: 3, end: t });
            self.st.pos = t;
            return;
        }
        if self.slot(Role::P).is_none_or(|p| p <= 0.0) {
            return diags.push(bad("every control point needs a positive weight P"));
        }
        let (n, _) = self.st.nurbs.unwrap_or((1, self.st.pos));
        self.st.nurbs = Some((n + 1, t));
    }

    /// G5.3: the NURBS collected since G5.2 runs to its last control point.
    pub(super) fn nurbs_end(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let Some((points, end)) = self.st.nurbs.take() else {
            let msg = format!("{}: no NURBS block to end (G5.2 first)", def.label());
            return diags.push(Diagnostic::new(Code::BadValue, range, msg));
        };
        self.check_technology(def, range, diags);
        self.emit(sink, CanonOp::NurbsFeed { points, end });
        self.st.pos = end;
    }

    /// LinuxCNC's G76 lathe threading cycle, pass by pass as its interpreter makes them. X is
    /// the depth axis and Z runs along the thread; the start point is the drive line.
    /// P is the pitch, I the offset from the drive line to the thread crests (negative for an
    /// outside thread), J the first depth, K the full depth, R the degression (pass n cuts to
    /// J·n^(1/R)), Q the compound angle, H the spring passes, E the taper length along Z and
    /// L which ends taper (1 entry, 2 exit, 3 both). The tool ends at the block's end point.
    fn threading_cycle(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        if !self.spindle_turns(def, range, diags) {
            return;
        }
        let mut bad = |msg: &str| diags.push(Diagnostic::new(Code::BadValue, range, format!("{}: {msg}", def.label())));
        if self.comp.borrow().is_some() {
            bad("the threading cycle cannot run with cutter compensation on");
            return;
        }
        // In diameter mode (G7) the depths are diameters too, as rs274 reads them.
        let half = if self.st.diameter { 0.5 } else { 1.0 };
        let (i, j, k) = (self.slot(Role::I).unwrap_or(0.0), self.slot(Role::J).unwrap_or(0.0), self.slot(Role::K).unwrap_or(0.0));
        let (i, j, k) = (i * half, j * half, k * half);
        let Some(pitch) = self.slot(Role::P) else { return };
        if i == 0.0 {
            return bad("I, the offset to the thread crests, must not be 0");
        }
        if j <= 0.0 {
            return bad("J, the first cut depth, must be above 0");
        }
        if k <= j {
            return bad("K, the full thread depth, must be more than J");
        }
        let end = self.target();
        let start = self.st.pos;
        let boring = i > 0.0;
        let crest = i.abs();
        let full = k;
        let bottom = k + crest;
        let along = end[2] > start[2];
        let mut angle = self.slot(Role::Q).filter(|&q| q != -1.0).unwrap_or(0.0).to_radians();
        if along {
            angle = -angle;
        }
        let springs = self.slot(Role::H).map_or(0, |h| h.max(0.0) as u32);
        let degression = self.slot(Role::R).filter(|&r| r >= 1.0).unwrap_or(1.0);
        let mut taper = self.slot(Role::E).unwrap_or(0.0).max(0.0);
        let taper_pitch = if taper > 0.0 { pitch * taper.hypot(full) / taper } else { pitch };
        if along {
            taper = -taper;
        }
        let flags = self.slot(Role::L).map_or(0, |l| l.max(0.0) as u32);
        let t = Thread {
            start,
            boring,
            crest,
            full,
            bottom,
            tan: angle.tan(),
            target_z: end[2] + k * angle.tan(),
            pitch,
            taper,
            taper_pitch,
            entry: taper != 0.0 && flags & 1 != 0,
            exit: taper != 0.0 && flags & 2 != 0,
        };
        let intent = TurnIntent {
            kind: Some(TurnKind::Thread),
            code: def.label(),
            pitch: Some(pitch),
            thread_depth: Some(k),
            first_cut: Some(j),
            finish_passes: Some(springs),
            ..TurnIntent::default()
        };
        self.emit(sink, CanonOp::Turning(Box::new(intent)));
        let mut pass = 1.0_f64;
        let mut depth = crest + j;
        while depth < bottom {
            self.thread_pass(&t, depth, sink);
            pass += 1.0;
            depth = crest + j * pass.powf(1.0 / degression);
        }
        // The full depth, once and then once per spring pass.
        for _ in 0..=springs {
            self.thread_pass(&t, bottom, sink);
        }
        self.emit(sink, CanonOp::StraightTraverse(end));
        self.st.pos = end;
        self.emit(sink, CanonOp::TurningEnd);
    }

    /// One threading pass at `depth` below the drive line: in at the clearance, across
    /// synchronised (tapering in and out where asked), and back out.
    fn thread_pass(&mut self, t: &Thread, depth: f64, sink: &mut dyn CanonSink) {
        let x_at = |d: f64| if t.boring { t.start[0] + d } else { t.start[0] - d };
        let zoff = (depth - t.crest) * t.tan;
        let clear = x_at(depth - t.bottom);
        let at = |x: f64, z: f64| {
            let mut p = t.start;
            p[0] = x;
            p[2] = z;
            p
        };
        self.emit(sink, CanonOp::StraightTraverse(at(clear, t.start[2] - zoff)));
        if t.entry {
            self.emit(sink, CanonOp::StartSpeedFeedSync(t.taper_pitch));
            self.emit(sink, CanonOp::StraightFeed(at(x_at(depth - t.full), t.start[2] - zoff)));
            self.emit(sink, CanonOp::StraightFeed(at(x_at(depth), t.start[2] - zoff - t.taper)));
        } else {
            self.emit(sink, CanonOp::StraightTraverse(at(x_at(depth), t.start[2] - zoff)));
        }
        self.emit(sink, CanonOp::StartSpeedFeedSync(t.pitch));
        if t.exit {
            self.emit(sink, CanonOp::StraightFeed(at(x_at(depth), t.target_z - zoff + t.taper)));
            self.emit(sink, CanonOp::StartSpeedFeedSync(t.taper_pitch));
            self.emit(sink, CanonOp::StraightFeed(at(x_at(depth - t.full), t.target_z - zoff)));
        } else {
            self.emit(sink, CanonOp::StraightFeed(at(x_at(depth), t.target_z - zoff)));
        }
        self.emit(sink, CanonOp::StopSpeedFeedSync);
        self.emit(sink, CanonOp::StraightTraverse(at(clear, t.target_z - zoff)));
    }

    /// In inverse-time mode (G93), sets the feed rate that makes a move of `length` last
    /// 1/F minutes. False when the block lacks the F it needs.
    fn inverse_time_feed(
        &mut self,
        def: &CodeDef,
        length: f64,
        block: &Block,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) -> bool {
        if !self.st.inverse_time {
            return true;
        }
        let Some(f) = self.slot(Role::F) else {
            diags.push(Diagnostic::new(
                Code::MissingParameter,
                block.range,
                format!("{} in inverse-time mode (G93) needs an F word in every block", def.label()),
            ));
            return false;
        };
        if self.comp.borrow().is_some() {
            let d = Diagnostic::new(
                Code::Unsupported,
                block.range,
                "inverse-time feed under cutter compensation is taken from the programmed path length, as LinuxCNC does; a control that times the compensated path feeds differently",
            );
            self.limited(diags, "inverse-time-comp", d);
        }
        self.st.feed = length * f;
        self.emit(sink, CanonOp::SetFeedRate(self.st.feed));
        true
    }

    #[inline]
    pub(super) fn check_technology(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        // Warned already, or a feed and a turning spindle (the common cut): nothing to say.
        let unfed = self.st.feed <= 0.0 && !self.st.inverse_time;
        if self.st.tech_warned || (!unfed && self.st.spindle != Spindle::Stopped) {
            return;
        }
        self.check_technology_once(def, range, diags);
    }

    /// [`Interpreter::check_technology`] until a warning is given.
    fn check_technology_once(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        // In inverse time each feed move brings its own F (see `inverse_time_feed`).
        // A feed read from outside the file (`F#650`) is the machine's: the word's note said so.
        let problem = if self.st.feed <= 0.0 && !self.st.inverse_time && !self.st.feed_outside {
            Some((Code::NoFeed, "the feed rate is zero", self.st.feed_unknown, "feed"))
        } else if self.st.spindle == Spindle::Stopped {
            Some((Code::CuttingWithoutTechnology, "the spindle is stopped", self.st.spindle_unknown, "spindle"))
        } else {
            None
        };
        if let Some((code, p, outside, what)) = problem {
            self.st.tech_warned = true;
            let d = Diagnostic::new(code, range, format!("{} cuts while {p}", def.label()));
            if outside {
                let note = format!("{} cuts with a {what} this file does not set: the {what} comes from the caller", def.label());
                self.caller_state(diags, "technology", d, note);
            } else {
                self.limited(diags, "technology", d);
            }
        }
    }

    /// After a straight move to `t`: its direction in the plane, for a following tangent arc.
    /// `APPR LT/LN X Y LEN`: the contour point is the block's end point; the auxiliary point
    /// before it depends on the first contour element, so the corner stage holds the approach
    /// until that element arrives. An arc approach goes straight to the contour point.
    fn approach(&mut self, def: &CodeDef, range: TextRange, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.check_technology(def, block.range, diags);
        let to = self.target();
        let len = self.slot(Role::Geometry).unwrap_or(0.0);
        let left = self.codes.iter().find_map(|&(c, _)| match self.code(c).meaning {
            Meaning::CompLeft | Meaning::CompLeftDiameter => Some(true),
            Meaning::CompRight | Meaning::CompRightDiameter => Some(false),
            _ => None,
        });
        if let Some(l) = left {
            self.st.comp_left = l;
        }
        let staged = def.meaning != Meaning::ApproachArc && len > 0.0 && self.st.plane == Plane::Xy;
        if staged && let Some(k) = self.corners.get_mut().as_mut() {
            let (origin, line) = (self.origin, self.line);
            let normal = def.meaning == Meaning::ApproachNormal;
            k.approach(super::corner::Approach { normal, len, left: self.st.comp_left, from: self.st.pos, to, origin, line });
        } else {
            if def.meaning == Meaning::ApproachArc {
                let msg = format!("{}: the approach arc is not computed; the tool goes straight to the contour point", def.label());
                diags.push(Diagnostic::new(Code::Unsupported, range, msg));
            }
            self.emit(sink, CanonOp::StraightFeed(to));
        }
        self.st.pos = to;
    }

    /// `DEP LT/LN LEN`: a straight line of length LEN from the contour end, along its last
    /// element or perpendicular to it on the side of the compensation. An arc departure is
    /// not computed: the tool stays at the contour end.
    fn depart(&mut self, def: &CodeDef, range: TextRange, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let (a0, a1, _) = self.st.plane.axes();
        let len = self.slot(Role::Geometry).unwrap_or(0.0);
        let direction = self.st.tangent.map(|(x, y)| {
            let l = x.hypot(y);
            let t = (x / l, y / l);
            match def.meaning {
                Meaning::DepartNormal if self.st.comp_left => (-t.1, t.0),
                Meaning::DepartNormal => (t.1, -t.0),
                _ => t,
            }
        });
        let Some(d) = direction.filter(|_| def.meaning != Meaning::DepartArc) else {
            let why = if def.meaning == Meaning::DepartArc {
                "the departure arc is not computed"
            } else {
                "no contour element before it gives the direction"
            };
            diags.push(Diagnostic::new(Code::Unsupported, range, format!("{}: {why}; the tool stays at the contour end", def.label())));
            return;
        };
        self.check_technology(def, block.range, diags);
        let mut to = self.target();
        to[a0] = self.st.pos[a0] + len * d.0;
        to[a1] = self.st.pos[a1] + len * d.1;
        self.emit(sink, CanonOp::StraightFeed(to));
        self.st.pos = to;
    }

    #[inline(always)]
    pub(super) fn note_tangent(&mut self, t: [f64; 6]) {
        let (a0, a1, _) = self.st.plane.axes();
        let (d1, d2) = (t[a0] - self.st.pos[a0], t[a1] - self.st.pos[a1]);
        if d1 != 0.0 || d2 != 0.0 {
            self.st.tangent = Some((d1, d2)); // normalised where a tangent arc needs it
        }
    }

    /// An arc in the plane (G2, G3, and the forms of the contour languages): its direction,
    /// its centre by the form the block writes, checked against its end point, then the arc
    /// feed; the direction at its end is the next element's tangent.
    fn arc(&mut self, def: &CodeDef, range: TextRange, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.check_technology(def, block.range, diags);
        let stated = self.codes.iter().find_map(|&(c, _)| match self.code(c).meaning {
            Meaning::ArcDirCw => Some(true),
            Meaning::ArcDirCcw => Some(false),
            _ => None,
        });
        let start = self.st.pos;
        let mut end = self.target();
        let (a0, a1, n) = self.st.plane.axes();
        // A word of the arc's shape read a value this file does not know (`CR=RAD`, `X=DX` in
        // a procedure, `I#5` in a called macro): the note on the word said so. The arc cannot
        // be drawn or checked; the tool is taken to its known end.
        const SHAPE: [Role; 14] = [
            Role::X,
            Role::Y,
            Role::Z,
            Role::I,
            Role::J,
            Role::K,
            Role::R,
            Role::OpeningAngle,
            Role::ViaX,
            Role::ViaY,
            Role::ViaZ,
            Role::PolarAngle,
            Role::PolarRadius,
            Role::P,
        ];
        if SHAPE.iter().any(|&r| self.word_unknown(r)) {
            self.rejected_arc(end);
            return;
        }
        let mut cw = match def.meaning {
            Meaning::ArcCw => true,
            Meaning::ArcCcw => false,
            _ => stated.unwrap_or(self.st.arc_cw),
        };
        let mut given_centre = None;
        if let Some(ar) = self.slot(Role::OpeningAngle) {
            let Some(c) = self.opening_angle(ar, cw, start, &mut end, block, diags) else { return };
            given_centre = Some(c);
        }
        if self.dialect.behaviour.arc_centres_pole && given_centre.is_none() && matches!(def.meaning, Meaning::ArcCw | Meaning::ArcCcw) {
            // I J K are the circle centre and stay the pole; without them (and without R) the
            // arc turns about the pole.
            given_centre = self.centre_words(a0, a1, start).or_else(|| self.slot(Role::R).is_none().then_some(self.st.pole));
            if let Some(c) = given_centre {
                self.st.pole = c;
            }
        }
        match def.meaning {
            Meaning::ArcThreePoint => {
                let Some((c, dir)) = self.three_point_centre(def, start, end, block, diags) else { return };
                (given_centre, cw) = (Some(c), dir);
            }
            Meaning::ArcPole => given_centre = Some(self.st.pole),
            Meaning::ArcRadius if self.slot(Role::R).is_none() => {
                diags.push(Diagnostic::new(Code::MissingParameter, block.range, format!("{} needs a radius R", def.label())));
                return;
            }
            Meaning::ArcTangent => {
                let Some((c, dir)) = self.tangent_centre(def, start, end, block, diags) else { return };
                (given_centre, cw) = (Some(c), dir);
            }
            // A polar end point and nothing else to place the centre (Siemens `G2 AP=90`):
            // the arc turns about the pole.
            _ if given_centre.is_none()
                && [Role::PolarAngle, Role::PolarRadius].iter().any(|&r| self.slots[r as usize].is_some())
                && [Role::I, Role::J, Role::K, Role::R].iter().all(|&r| self.slots[r as usize].is_none()) =>
            {
                given_centre = Some(self.st.pole);
            }
            _ => {}
        }
        let turns = match self.slot(Role::P) {
            None => 1,
            Some(p) if p >= 1.0 && p.fract() == 0.0 && p < 10_000.0 => p as i32,
            Some(p) => {
                diags.push(Diagnostic::new(Code::BadArc, range, format!("the number of turns P{p} must be a positive whole number")));
                return;
            }
        };
        let center = match (given_centre, self.slot(Role::R)) {
            (Some(c), _) => self.checked_centre(c, start, end, block, diags),
            (None, Some(r)) => self.radius_centre(r, cw, start, end, block, diags),
            (None, None) => self.offset_centre(def, start, end, block, diags),
        };
        let Some(center) = center else { return };
        let rotation = if cw { -turns } else { turns };
        let length = arc_length(start, end, center, (a0, a1, n), cw, turns);
        if !self.inverse_time_feed(def, length, block, sink, diags) {
            return;
        }
        self.emit(
            sink,
            CanonOp::ArcFeed {
                first_end: end[a0],
                second_end: end[a1],
                first_axis: center.0,
                second_axis: center.1,
                rotation,
                axis_end: end[n],
                abc: [end[3], end[4], end[5]],
            },
        );
        self.st.pos = end;
        self.st.arc_cw = cw;
        // The direction at the end: along the circle, perpendicular to the radius.
        let (r1, r2) = (end[a0] - center.0, end[a1] - center.1);
        let len = r1.hypot(r2);
        if len > 1e-12 {
            self.st.tangent = Some(if cw { (r2 / len, -r1 / len) } else { (-r2 / len, r1 / len) });
        }
    }

    /// `G2 X Y AR=90` (end point and opening angle) or `G3 I J AR=90` (centre and angle, the
    /// end point worked out into `end`): the arc's centre; `None`, with the finding, when the
    /// angle or the words cannot make one.
    fn opening_angle(
        &self,
        ar: f64,
        cw: bool,
        start: [f64; 6],
        end: &mut [f64; 6],
        block: &Block,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<(f64, f64)> {
        let (a0, a1, _) = self.st.plane.axes();
        if !(ar > 0.0 && ar < 360.0) {
            diags.push(Diagnostic::new(Code::BadArc, block.range, format!("the opening angle AR={ar} must lie between 0 and 360 degrees")));
            return None;
        }
        let sign = if cw { -1.0 } else { 1.0 };
        if self.slots[Role::AXES[a0] as usize].is_some() || self.slots[Role::AXES[a1] as usize].is_some() {
            let (d1, d2) = (end[a0] - start[a0], end[a1] - start[a1]);
            let chord = d1.hypot(d2);
            if chord < 1e-9 {
                diags.push(Diagnostic::new(Code::BadArc, block.range, "an opening angle needs an end point away from the start"));
                return None;
            }
            // The centre lies on the chord's bisector, left of it for counter-clockwise.
            let h = chord / 2.0 / (ar / 2.0).to_radians().tan();
            let mid = ((start[a0] + end[a0]) / 2.0, (start[a1] + end[a1]) / 2.0);
            Some((mid.0 - sign * h * d2 / chord, mid.1 + sign * h * d1 / chord))
        } else if let Some(c) = self.centre_words(a0, a1, start) {
            let (sin, cos) = (sign * ar.to_radians()).sin_cos();
            let (r1, r2) = (start[a0] - c.0, start[a1] - c.1);
            end[a0] = c.0 + r1 * cos - r2 * sin;
            end[a1] = c.1 + r1 * sin + r2 * cos;
            Some(c)
        } else {
            diags.push(Diagnostic::new(Code::MissingParameter, block.range, "AR= needs an end point or a centre (I, J, K)"));
            None
        }
    }

    /// `CIP` and its kind: the circle through the start, the intermediate point and the end;
    /// its centre and whether it runs clockwise. `None`, with the finding, when the three
    /// points lie on one line.
    fn three_point_centre(
        &self,
        def: &CodeDef,
        start: [f64; 6],
        end: [f64; 6],
        block: &Block,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<((f64, f64), bool)> {
        let (a0, a1, _) = self.st.plane.axes();
        let (s1, s2, e1, e2) = (start[a0], start[a1], end[a0], end[a1]);
        let via = |axis: usize, role: Role| match self.slots[role as usize] {
            Some(s) if self.incremental(role) => start[axis] + s.value,
            Some(s) => s.value,
            None => start[axis],
        };
        let vias = [Role::ViaX, Role::ViaY, Role::ViaZ];
        let (m1, m2) = (via(a0, vias[a0]), via(a1, vias[a1]));
        let d = 2.0 * (s1 * (m2 - e2) + m1 * (e2 - s2) + e1 * (s2 - m2));
        if d.abs() < 1e-9 {
            diags.push(Diagnostic::new(Code::BadArc, block.range, format!("{}: the three points lie on one line", def.label())));
            return None;
        }
        let (ss, mm, ee) = (s1 * s1 + s2 * s2, m1 * m1 + m2 * m2, e1 * e1 + e2 * e2);
        let u1 = (ss * (m2 - e2) + mm * (e2 - s2) + ee * (s2 - m2)) / d;
        let u2 = (ss * (e1 - m1) + mm * (s1 - e1) + ee * (m1 - s1)) / d;
        // `+ 0.0` turns a -0.0 quotient into 0.0, which prints without a sign.
        Some(((u1 + 0.0, u2 + 0.0), (m1 - s1) * (e2 - m2) - (m2 - s2) * (e1 - m1) < 0.0))
    }

    /// `CT` and its kind: the arc that goes on tangent to the element before it; its centre
    /// and whether it runs clockwise. `None`, with the finding, without an element before it
    /// or with the end point on the tangent.
    fn tangent_centre(
        &self,
        def: &CodeDef,
        start: [f64; 6],
        end: [f64; 6],
        block: &Block,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<((f64, f64), bool)> {
        let (a0, a1, _) = self.st.plane.axes();
        let (s1, s2, e1, e2) = (start[a0], start[a1], end[a0], end[a1]);
        // The centre lies on the normal to the incoming direction, as far from the
        // start as from the end.
        let Some((t1, t2)) = self.st.tangent.map(|(x, y)| {
            let len = x.hypot(y);
            (x / len, y / len)
        }) else {
            diags.push(Diagnostic::new(Code::BadArc, block.range, format!("{}: no previous element to be tangent to", def.label())));
            return None;
        };
        let (d1, d2) = (e1 - s1, e2 - s2);
        let (n1, n2) = (-t2, t1);
        let dn = d1 * n1 + d2 * n2;
        if dn.abs() < 1e-9 {
            diags.push(Diagnostic::new(Code::BadArc, block.range, format!("{}: the end point lies on the tangent; no arc", def.label())));
            return None;
        }
        let k = (d1 * d1 + d2 * d2) / (2.0 * dn);
        Some(((s1 + k * n1, s2 + k * n2), k < 0.0))
    }

    /// The control's tolerance on an arc's radii, and its relative tolerance where the
    /// dialect has one.
    fn arc_tolerance(&self, block: &Block) -> (f64, Option<f64>) {
        let b = &self.dialect.behaviour;
        // The control's tolerance, or what the program's own resolution allows where the
        // dictionary says so: with each coordinate rounded to the step it is written in
        // (`X1.2345`: 0.0001), the radii to the start and to the end may differ by 2√2 steps.
        let tol = if self.st.units == Units::Mm { b.arc_tolerance_mm } else { b.arc_tolerance_inch };
        let tol = tol.max(b.arc_tolerance_steps * written_step(block) * (1.0 + 1e-9));
        (tol, b.arc_relative_tolerance)
    }

    /// A centre the block gives otherwise than by I J K offsets (an opening angle, the pole,
    /// three points, a tangent), if start and end lie on one circle about it; else `None`,
    /// with the finding, and the program goes on from the end point.
    fn checked_centre(
        &mut self,
        c: (f64, f64),
        start: [f64; 6],
        end: [f64; 6],
        block: &Block,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<(f64, f64)> {
        let (a0, a1, _) = self.st.plane.axes();
        let (tol, relative) = self.arc_tolerance(block);
        let r_start = (start[a0] - c.0).hypot(start[a1] - c.1);
        let r_end = (end[a0] - c.0).hypot(end[a1] - c.1);
        if radii_disagree(r_start, r_end, tol, relative) {
            diags.push(Diagnostic::new(
                Code::BadArc,
                block.range,
                format!("the end point is {r_end:.4} from the circle centre, the start {r_start:.4}; they must agree"),
            ));
            self.rejected_arc(end);
            return None;
        }
        Some(c)
    }

    /// The centre of an arc given by radius `r` (see [`arc_center_from_radius`]); `None`,
    /// with the finding, when no arc of that radius reaches the end point.
    fn radius_centre(
        &mut self,
        r: f64,
        cw: bool,
        start: [f64; 6],
        end: [f64; 6],
        block: &Block,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<(f64, f64)> {
        let (a0, a1, _) = self.st.plane.axes();
        let (tol, _) = self.arc_tolerance(block);
        let found = arc_center_from_radius(start[a0], start[a1], end[a0], end[a1], r, cw, tol);
        // An R written without a point, read as least increments: does the arc reach its end
        // so, or only with the R in whole units (the evidence of calculator-type input)?
        if let Some(units) = self.radius_in_units(block, r) {
            let fits_units = arc_center_from_radius(start[a0], start[a1], end[a0], end[a1], units, cw, tol).is_ok();
            match (found.is_ok(), fits_units) {
                (false, true) => {
                    self.radius_units[0] += 1;
                    // The R word, or the main program's call while a subprogram from another
                    // file runs (the finding is told against the main program).
                    if self.first_radius_units.is_none() {
                        let word = block.words.iter().rfind(|w| w.role == Role::R).map(|w| w.range);
                        self.first_radius_units = self.origin_override.map(|(call, _)| call).or(word);
                    }
                }
                (true, _) => self.radius_units[1] += 1,
                _ => {}
            }
        }
        match found {
            Ok(c) => Some(c),
            Err(msg) => {
                diags.push(Diagnostic::new(Code::BadArc, block.range, msg));
                self.rejected_arc(end);
                None
            }
        }
    }

    /// The radius `r` read in whole units, where the block's R word has no decimal point and
    /// least-increment input scaled it; `None` otherwise.
    fn radius_in_units(&self, block: &Block, r: f64) -> Option<f64> {
        let DecimalInput::LeastIncrement { scaled, .. } = &self.dialect.behaviour.decimal_input else { return None };
        if !self.integers_scale || !scaled.contains(&Role::R) {
            return None;
        }
        let w = block.words.iter().rfind(|w| w.role == Role::R)?;
        // The number as written (the sign of the radius read kept).
        let crate::syntax::Value::Number { value, decimal: false } = w.value else { return None };
        (value != 0.0).then(|| value.abs() * r.signum())
    }

    /// The centre of an arc given by I J K offsets (from the start, or absolute), if start
    /// and end lie on one circle about it; `None`, with the finding, without the offsets of
    /// the plane or when the radii to the start and to the end disagree.
    fn offset_centre(
        &mut self,
        def: &CodeDef,
        start: [f64; 6],
        end: [f64; 6],
        block: &Block,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<(f64, f64)> {
        let (a0, a1, _) = self.st.plane.axes();
        let off = |axis: usize| self.slot(OFFSETS[axis]);
        if off(a0).is_none() && off(a1).is_none() {
            let needs = if self.st.plane == Plane::Xy {
                "I or J"
            } else if self.st.plane == Plane::Xz {
                "I or K"
            } else {
                "J or K"
            };
            diags.push(Diagnostic::new(Code::MissingParameter, block.range, format!("{} in this plane needs {needs}, or R", def.label())));
            return None;
        }
        let c = self.centre_words(a0, a1, start)?;
        let (tol, relative) = self.arc_tolerance(block);
        let r_start = (start[a0] - c.0).hypot(start[a1] - c.1);
        let r_end = (end[a0] - c.0).hypot(end[a1] - c.1);
        self.weigh_radius_words(start, end, (r_start, r_end), tol, relative);
        if radii_disagree(r_start, r_end, tol, relative) {
            let unit = if self.st.units == Units::Mm { "mm" } else { "in" };
            let mut msg = format!(
                "radius to the end of the arc ({r_end:.4} {unit}) differs from the radius to its start ({r_start:.4} {unit}) by more than {tol} {unit}{}",
                match relative {
                    Some(rel) => format!(" and {}% of the radius", rel * 100.0),
                    None => String::new(),
                }
            );
            if self.reversed_offsets_fit(start, end, c, tol, relative) {
                msg.push_str(
                    "; the offsets fit read from the centre to the start, as a post set to write them so gives them (NX Post Builder's \"Vector - Arc Center to Start\"), but the control reads them from the start to the centre",
                );
            }
            diags.push(Diagnostic::new(Code::BadArc, block.range, msg));
            self.rejected_arc(end);
            return None;
        }
        Some(c)
    }
}

impl Interpreter<'_> {
    /// Whether an arc whose I J K offsets from the start miss its end fits with them read the
    /// other way, from the centre to the start (`centre` = start − offsets): a post's setting,
    /// told beside the finding so that the reader sees why, never used for the move.
    fn reversed_offsets_fit(&self, start: [f64; 6], end: [f64; 6], centre: (f64, f64), tol: f64, relative: Option<f64>) -> bool {
        let (a0, a1, _) = self.st.plane.axes();
        let incremental = [a0, a1].iter().all(|&axis| match self.slots[OFFSETS[axis] as usize].map(|s| s.mode) {
            Some(WordMode::Absolute) => false,
            Some(WordMode::Incremental) => true,
            _ => !self.dialect.behaviour.arc_centres_pole && self.st.arc_incremental,
        });
        if !incremental {
            return false;
        }
        let c = (2.0 * start[a0] - centre.0, 2.0 * start[a1] - centre.1);
        let r_start = (start[a0] - c.0).hypot(start[a1] - c.1);
        let r_end = (end[a0] - c.0).hypot(end[a1] - c.1);
        r_start > tol && !radii_disagree(r_start, r_end, tol, relative)
    }

    /// Under diameter programming in the ZX plane, whether an arc's centre (I, K from the
    /// start) fits as the X words were read or only with them read as radii: evidence of a
    /// machine set to radius programming (see `lathe_evidence`).
    fn weigh_radius_words(&mut self, start: [f64; 6], end: [f64; 6], radii: (f64, f64), tol: f64, relative: Option<f64>) {
        let incremental = self.slots[OFFSETS[0] as usize].map_or(self.st.arc_incremental, |s| s.mode != WordMode::Absolute);
        if !self.st.diameter || self.st.plane != Plane::Xz || !incremental {
            return;
        }
        let (Some(i), k) = (self.slot(OFFSETS[0]), self.slot(OFFSETS[2]).unwrap_or(0.0)) else { return };
        // Read as radii, the X words place the points at twice the X they have now.
        let (s, e) = ((2.0 * start[0], start[2]), (2.0 * end[0], end[2]));
        // Some posts write I with the sign of a mirrored X (the tool behind the centre line).
        let fits = |s: (f64, f64), e: (f64, f64), i: f64| {
            let c = (s.0 + i, s.1 + k);
            !radii_disagree((s.0 - c.0).hypot(s.1 - c.1), (e.0 - c.0).hypot(e.1 - c.1), tol, relative)
        };
        let read = ((start[0], start[2]), (end[0], end[2]));
        let as_read = !radii_disagree(radii.0, radii.1, tol, relative) || fits(read.0, read.1, -i);
        let as_radius = fits(s, e, i) || fits(s, e, -i);
        match (as_read, as_radius) {
            (false, true) => self.arc_fit[0] += 1,
            (true, false) => self.arc_fit[1] += 1,
            _ => {}
        }
    }

    /// After an arc that cannot be made: the program goes on from its programmed end point,
    /// as the next blocks expect, so one bad arc is one finding and not every later one.
    fn rejected_arc(&mut self, end: [f64; 6]) {
        self.st.pos = end;
        self.st.tangent = None;
    }
}

/// The finest step among the lengths an arc block writes with a decimal point (`X1.2345`:
/// 0.0001; a trimmed `X10.` says nothing finer); 0 when none has a fraction.
fn written_step(block: &Block) -> f64 {
    let roles = [Role::X, Role::Y, Role::Z, Role::I, Role::J, Role::K, Role::R];
    let digits = block
        .words
        .iter()
        .filter(|w| roles.contains(&w.role))
        .filter_map(|w| match w.value {
            crate::syntax::Value::Number { value, decimal: true } => (0..=6).find(|&d| {
                let scaled = value.abs() * 10f64.powi(d);
                (scaled - scaled.round()).abs() < 1e-6 * scaled.max(1.0)
            }),
            _ => None,
        })
        .max()
        .unwrap_or(0);
    if digits == 0 { 0.0 } else { 10f64.powi(-digits) }
}

/// Whether the radii of an arc to its start and to its end disagree beyond the dialect's
/// tolerance: `tol`, and where the dialect has one the `relative` share of the radius (then
/// 100 times `tol` always counts).
fn radii_disagree(r_start: f64, r_end: f64, tol: f64, relative: Option<f64>) -> bool {
    let err = (r_start - r_end).abs();
    match relative {
        None => err > tol,
        Some(rel) => err > 100.0 * tol || (err > tol && err / r_start.max(r_end) > rel),
    }
}

/// The length of a (helical) arc along its path.
fn arc_length(start: [f64; 6], end: [f64; 6], center: (f64, f64), (a0, a1, n): (usize, usize, usize), cw: bool, turns: i32) -> f64 {
    let r = (start[a0] - center.0).hypot(start[a1] - center.1);
    let a_start = (start[a1] - center.1).atan2(start[a0] - center.0);
    let a_end = (end[a1] - center.1).atan2(end[a0] - center.0);
    let tau = std::f64::consts::TAU;
    let mut sweep = if cw { a_start - a_end } else { a_end - a_start };
    sweep = sweep.rem_euclid(tau);
    if sweep < 1e-12 {
        sweep = tau;
    }
    sweep += tau * f64::from(turns - 1);
    (r * sweep).hypot(end[n] - start[n])
}

/// The centre of an arc given by its radius, as LinuxCNC computes it: a positive radius
/// takes the short way (at most 180°), a negative one the long way.
fn arc_center_from_radius(s1: f64, s2: f64, e1: f64, e2: f64, r: f64, cw: bool, tol: f64) -> Result<(f64, f64), String> {
    let abs_r = r.abs();
    let (m1, m2) = ((s1 + e1) / 2.0, (s2 + e2) / 2.0);
    let half = (m1 - e1).hypot(m2 - e2);
    if half < 1e-12 {
        return Err("an arc given by R cannot be a full circle (start and end coincide)".into());
    }
    if half - abs_r > tol {
        return Err(format!("arc radius {abs_r} is too small to reach the end point ({:.4} away)", 2.0 * half));
    }
    let half = half.min(abs_r);
    let chord = (e2 - s2).atan2(e1 - s1);
    let theta = if cw == (r > 0.0) { chord - std::f64::consts::FRAC_PI_2 } else { chord + std::f64::consts::FRAC_PI_2 };
    let offset = (abs_r * abs_r - half * half).max(0.0).sqrt();
    Ok((m1 + offset * theta.cos(), m2 + offset * theta.sin()))
}

/// The fixed quantities of a G76 threading cycle (see `threading_cycle`).
struct Thread {
    /// The start point: X on the drive line.
    start: [f64; 6],
    /// An inside thread: depths go towards +X.
    boring: bool,
    /// From the drive line to the thread crests (|I|).
    crest: f64,
    /// The thread height (K).
    full: f64,
    /// From the drive line to the thread root (|I| + K).
    bottom: f64,
    /// Tangent of the compound angle (signed by the direction along Z).
    tan: f64,
    /// Where the passes end along Z, before the compound shift.
    target_z: f64,
    pitch: f64,
    /// Taper length along Z (signed by the direction along Z).
    taper: f64,
    /// The advance per revolution on the taper, along its slant.
    taper_pitch: f64,
    entry: bool,
    exit: bool,
}

#[cfg(test)]
mod tests {
    use super::arc_center_from_radius;

    #[test]
    fn r_arcs_take_the_short_or_long_way() {
        // G2 X10 Y0 R5 from the origin: a semicircle about (5, 0).
        let (c1, c2) = arc_center_from_radius(0.0, 0.0, 10.0, 0.0, 5.0, true, 0.002).unwrap();
        assert!((c1 - 5.0).abs() < 1e-9 && c2.abs() < 1e-9);
        // G3 X10 Y0 R-7: centre (5, -4.899), the long way (verified with rs274).
        let (c1, c2) = arc_center_from_radius(0.0, 0.0, 10.0, 0.0, -7.0, false, 0.002).unwrap();
        assert!((c1 - 5.0).abs() < 1e-9 && (c2 + 24f64.sqrt()).abs() < 1e-9, "{c1} {c2}");
        assert!(arc_center_from_radius(0.0, 0.0, 10.0, 0.0, 2.0, true, 0.002).is_err());
    }
}

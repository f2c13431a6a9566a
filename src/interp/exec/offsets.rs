//! Work offsets and coordinate systems: the work coordinate systems (G54 to G59.3, the
//! additional ones of G54.1 P), setting them (`G10 L2`, `L20`), the G92 shift and its
//! family (G92.1 to G92.3, G52), the reference positions (G28, G30 and their `.1` forms),
//! and the conversions between program and machine coordinates the rest of the interpreter
//! reads positions by.
//!
//! Doors: [`Interpreter::work_offset`], [`Interpreter::set_data`],
//! [`Interpreter::origin_offset`], [`Interpreter::home_code`], and for the rest of the
//! interpreter [`Interpreter::machine_pos`], [`Interpreter::program_pos`],
//! [`Interpreter::select_wcs`], [`Interpreter::shift_origin`].

use crate::canon::{CanonOp, CanonSink, DistanceMode, MachineMove, MachineTarget, Setting};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, DataForm, Meaning, Role};
use crate::interp::{Interpreter, State, rotate};
use crate::syntax::WordMode;
use crate::text::TextRange;

impl Interpreter<'_> {
    /// G54 to G59.3, and G54.1 Pn (G154 Pn, G15 Hn): the work coordinate system in force.
    pub(super) fn work_offset(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        if def.meaning == Meaning::Wcs {
            self.state_wcs(u16::from(def.index), sink);
            return;
        }
        // G54.1 Pn, G154 Pn, G15 Hn: additional work offset n, its own system (0 until
        // the program sets it, as every offset here), so that a change of fixture
        // offset is seen as one. Without a number: the first. With a number the caller
        // gives (`G54.1 P#1` in a called program), which one is not known: the system in
        // force stays, and the note on the word says why.
        if self.word_unknown(Role::P) || self.word_unknown(Role::H) {
            return;
        }
        let n = self.slot(Role::P).or(self.slot(Role::H)).or(Some(1.0));
        match self.extended_wcs(n) {
            Some(index) => self.state_wcs(index, sink),
            None => {
                // `G15 H=VC32` with the variable 0 here: the machine's value is not.
                let msg = format!(
                    "{}: an additional work offset is numbered 1 to {}; the system in force stays",
                    def.label(),
                    crate::canon::MAX_EXTENDED_WCS
                );
                self.limited(diags, "wcs-extended", Diagnostic::new(Code::Unsupported, range, msg));
            }
        }
    }

    /// `G10 L..`: sets a work offset or tool data, as the dialect's forms say for this L.
    pub(super) fn set_data(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let l = self.slot(Role::L).unwrap_or(0.0);
        let form = def.forms.iter().find(|(n, _)| f64::from(*n) == l).map(|&(_, f)| f);
        match form {
            Some(DataForm::Wcs | DataForm::WcsHere) => self.set_wcs(def, form == Some(DataForm::WcsHere), range, sink, diags),
            Some(DataForm::WcsExtended) => match self.extended_wcs(self.slot(Role::P)) {
                Some(index) => self.set_wcs_offsets(index, false, sink),
                // `G10 L20 P#1`: which offset is not known; the note on the word says so.
                None if self.word_unknown(Role::P) => {}
                None => {
                    let msg = format!(
                        "{} L{l}: an additional work offset is numbered 1 to {}; the setting is not kept",
                        def.label(),
                        crate::canon::MAX_EXTENDED_WCS
                    );
                    self.limited(diags, "wcs-extended", Diagnostic::new(Code::Unsupported, range, msg));
                }
            },
            Some(f) => self.set_tool_data(def, f, range, diags),
            None => {
                let known: Vec<String> = def.forms.iter().map(|(n, _)| format!("L{n}")).collect();
                let msg = format!(
                    "{} L{l} is not a data-setting form of the {} dialect (known: {})",
                    def.label(),
                    self.dialect.name,
                    known.join(", ")
                );
                diags.push(Diagnostic::new(Code::Unsupported, range, msg));
            }
        }
    }

    /// `G10 L2/L20 P..`: work offset P (0: the active one) to the given values, or so that
    /// the current point has them.
    fn set_wcs(&mut self, def: &CodeDef, here: bool, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let p = self.slot(Role::P).unwrap_or(0.0).round() as i64;
        if !(0..=9).contains(&p) {
            self.unsupported(def, range, diags);
            return;
        }
        let index = if p == 0 { self.st.wcs } else { p as u16 };
        self.set_wcs_offsets(index, here, sink);
    }

    /// Work offset `index` from the block's axis words: the values (L2, `G10 L20 Pn` on
    /// Fanuc), or, `here`, those that make the current point read them (LinuxCNC's L20).
    fn set_wcs_offsets(&mut self, index: u16, here: bool, sink: &mut dyn CanonSink) {
        let l = if here { 20 } else { 2 };
        let rotation = self.slot(Role::R).unwrap_or(self.st.rotation(index));
        let mut off = self.st.offset(index);
        if l == 20 {
            // L20: the current point becomes the given coordinates in that system, whose
            // rotation applies to them (machine = offset + R·(program + G92)).
            let machine = self.machine_pos();
            let mut p = self.st.pos;
            for (i, &role) in Role::AXES.iter().enumerate() {
                if let Some(v) = self.slot(role) {
                    p[i] = v;
                }
            }
            let local = rotate([p[0] + self.st.g92[0], p[1] + self.st.g92[1]], rotation);
            // In a rotated system X or Y moves the origin along both machine axes.
            let xy = rotation != 0.0 && (self.slot(Role::X).is_some() || self.slot(Role::Y).is_some());
            for (i, &role) in Role::AXES.iter().enumerate() {
                if xy && i < 2 {
                    off[i] = machine[i] - local[i];
                } else if self.slot(role).is_some() {
                    off[i] = machine[i] - self.st.g92[i] - p[i];
                }
            }
        } else {
            for (i, &role) in Role::AXES.iter().enumerate() {
                if let Some(v) = self.slot(role) {
                    off[i] = v;
                }
            }
        }
        if index == self.st.wcs {
            // The active frame moves: no axis's position is known in it (whatever the control
            // held before, the program's positions in it are the control's).
            self.forget(crate::canon::ALL_KNOWN, sink);
            self.switch_wcs(|st| st.set_offset(index, off, rotation));
            self.emit(sink, CanonOp::SetG5xOffset(index, off));
        } else {
            self.st.set_offset(index, off, rotation);
        }
    }

    /// G92 (the shift that makes the current point read the given coordinates), G52 (a
    /// local origin), G92.1 (cancel), G92.2 (suspend) and G92.3 (restore).
    pub(super) fn origin_offset(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        match def.meaning {
            Meaning::OriginShift => self.origin_shift(sink),
            Meaning::LocalOffset => {
                // G52: the given axes of the local origin, relative to the work origin; kept in
                // the same offset register as G92 (as LinuxCNC does).
                let old = self.st.g92;
                for (i, &role) in Role::AXES.iter().enumerate() {
                    if let Some(v) = self.slot(role) {
                        self.st.g92[i] = v;
                    }
                }
                let new = self.st.g92;
                self.shift_origin(old, new);
                self.emit(sink, CanonOp::SetG92Offset(new));
            }
            Meaning::OriginShiftSuspend => {
                let old = self.st.g92;
                if old != [0.0; 6] {
                    self.st.g92_saved = old;
                }
                self.st.g92 = [0.0; 6];
                self.shift_origin(old, [0.0; 6]);
                self.emit(sink, CanonOp::SetG92Offset([0.0; 6]));
            }
            Meaning::OriginShiftRestore => {
                let (old, new) = (self.st.g92, self.st.g92_saved);
                self.st.g92 = new;
                self.shift_origin(old, new);
                self.emit(sink, CanonOp::SetG92Offset(new));
            }
            _ => {
                for i in 0..6 {
                    self.st.pos[i] += self.st.g92[i];
                }
                self.st.g92 = [0.0; 6];
                self.emit(sink, CanonOp::SetG92Offset([0.0; 6]));
            }
        }
    }

    /// G28, G30 (to a reference position, through the block's point) and G28.1, G30.1 (the
    /// current position becomes it).
    pub(super) fn home_code(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        match def.meaning {
            Meaning::Home1 => {
                self.taught_home(1, def, range, diags);
                self.home(1, sink);
            }
            // Fanuc `G30 P3`: the third reference position (P2 to P4; without P the second).
            Meaning::Home2 => {
                let p = self.slot(Role::P).filter(|_| def.params.takes(Role::P)).map(f64::round);
                let k = p.filter(|p| (2.0..=4.0).contains(p)).map_or(2, |p| p as u8);
                if k == 2 {
                    self.taught_home(2, def, range, diags);
                }
                self.home(k, sink);
            }
            Meaning::ReferenceApproach | Meaning::FixedPointApproach => self.reference_approach(def, sink),
            Meaning::TravelLimit => self.travel_limit(sink),
            _ => {
                // The reference positions are kept in machine coordinates, mm.
                let m = self.machine_pos();
                let mut home = [0.0; 6];
                for (i, v) in home.iter_mut().enumerate() {
                    *v = if i < 3 { m[i] * self.st.units.to_mm() } else { m[i] };
                }
                if def.meaning == Meaning::Home1Set {
                    self.st.home1 = home;
                    self.st.home_taught |= 1;
                } else {
                    self.st.home2 = home;
                    self.st.home_taught |= 2;
                }
            }
        }
    }

    /// A return to reference position `k` (1 or 2) after the program stored it itself (G28.1,
    /// G30.1): it goes to where the tool stood then, which the target's return (to its own
    /// stored position) does not, so a translation refuses it (`interp::motion-unknown`).
    fn taught_home(&mut self, k: u8, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        if self.st.home_taught & k == 0 {
            return;
        }
        let msg = format!(
            "{} returns to the position this program stored (G28.1/G30.1), not to the machine's own reference position: a translation's return goes to the target machine's stored position, so it cannot be written",
            def.label()
        );
        self.limited(diags, "motion-unknown", Diagnostic::new(Code::MotionUnknown, range, msg));
    }

    /// The current position in machine coordinates.
    pub(in crate::interp) fn machine_pos(&self) -> [f64; 6] {
        self.to_machine(self.st.pos)
    }

    /// A program position in machine coordinates: offset + R(rotation)·(program + G92).
    fn to_machine(&self, pos: [f64; 6]) -> [f64; 6] {
        let (off, rotation) = (self.st.offset(self.st.wcs), self.st.rotation(self.st.wcs));
        let mut m: [f64; 6] = std::array::from_fn(|i| pos[i] + self.st.g92[i]);
        if rotation != 0.0 {
            [m[0], m[1]] = rotate([m[0], m[1]], rotation);
        }
        std::array::from_fn(|i| m[i] + off[i])
    }

    /// Program coordinates of a machine position in the active system.
    pub(in crate::interp) fn program_pos(&self, machine: [f64; 6]) -> [f64; 6] {
        self.machine_to_system(machine, self.st.wcs, true)
    }

    /// A machine position in work coordinate system `wcs` (1 for G54), with or without the
    /// G92 shift.
    pub(super) fn machine_to_system(&self, machine: [f64; 6], wcs: u16, g92: bool) -> [f64; 6] {
        let (off, rotation) = (self.st.offset(wcs), self.st.rotation(wcs));
        let mut p: [f64; 6] = std::array::from_fn(|i| machine[i] - off[i]);
        if rotation != 0.0 {
            [p[0], p[1]] = rotate([p[0], p[1]], -rotation);
        }
        std::array::from_fn(|i| p[i] - if g92 { self.st.g92[i] } else { 0.0 })
    }

    /// The index of additional work offset `n` (`G54.1 P3`: [`crate::canon::EXTENDED_WCS`] + 3).
    fn extended_wcs(&self, n: Option<f64>) -> Option<u16> {
        let n = n?;
        (n.fract() == 0.0 && (1.0..=f64::from(crate::canon::MAX_EXTENDED_WCS)).contains(&n)).then(|| crate::canon::EXTENDED_WCS + n as u16)
    }

    /// A work coordinate system the program states: made the active one, or, where it is in
    /// force already, marked as stated (the program does not rely on what the machine had).
    pub(in crate::interp) fn state_wcs(&mut self, index: u16, sink: &mut dyn CanonSink) {
        if index == self.st.wcs {
            self.emit(sink, CanonOp::Setting(Setting::WorkOffset(index)));
        } else {
            self.select_wcs(index, sink);
        }
    }

    /// Makes work coordinate system `index` (1 for G54) the active one.
    pub(in crate::interp) fn select_wcs(&mut self, index: u16, sink: &mut dyn CanonSink) {
        let new = self.st.offset(index);
        // The offsets are the control's: in the new frame no axis's position is known.
        self.forget(crate::canon::ALL_KNOWN, sink);
        self.switch_wcs(|st| st.wcs = index);
        self.emit(sink, CanonOp::SetG5xOffset(index, new));
        // LinuxCNC restates the G92 offset with every switch of system.
        self.emit(sink, CanonOp::SetG92Offset(self.st.g92));
    }

    /// Changes the active coordinate system (which one, its offsets or rotation) keeping the
    /// machine position.
    fn switch_wcs(&mut self, change: impl FnOnce(&mut State)) {
        let (old, old_rotation) = (self.st.offset(self.st.wcs), self.st.rotation(self.st.wcs));
        let machine = self.machine_pos();
        change(&mut self.st);
        let (new, new_rotation) = (self.st.offset(self.st.wcs), self.st.rotation(self.st.wcs));
        if old_rotation == 0.0 && new_rotation == 0.0 {
            self.shift_origin(old, new);
        } else {
            self.st.pos = self.program_pos(machine);
        }
    }

    /// Keeps the machine position when the active origin moves from `old` to `new`.
    pub(in crate::interp) fn shift_origin(&mut self, old: [f64; 6], new: [f64; 6]) {
        for i in 0..6 {
            self.st.pos[i] += old[i] - new[i];
        }
    }

    /// G92 (and a lathe's `G50 X.. Z..`): the shift that makes the current point read the
    /// block's axis words.
    pub(super) fn origin_shift(&mut self, sink: &mut dyn CanonSink) {
        // A shift set where the axis's position is unknown is counted from an assumed one.
        let mut unknown = 0u8;
        for (i, &role) in Role::AXES.iter().enumerate() {
            if self.slot(role).is_some() && !self.knows(i) {
                unknown |= 1 << i;
            }
        }
        if unknown != 0 {
            self.emit(sink, CanonOp::ShiftUnknown(unknown));
        }
        for (i, &role) in Role::AXES.iter().enumerate() {
            if let Some(v) = self.slot(role) {
                let machine_rel = self.st.pos[i] + self.st.g92[i];
                self.st.g92[i] = machine_rel - v;
                self.st.pos[i] = v;
            }
        }
        self.emit(sink, CanonOp::SetG92Offset(self.st.g92));
    }

    /// SINUMERIK `G74` / Centroid `M25` (reference point approach) and `G75 FP=n` (fixed point
    /// approach, FP 1 to 4, 1 without it): the axes the block names (their values are
    /// ignored: 840D programming manual, "G74 reference point approach", "G75 fixed point
    /// approach"), else the code's `home-axes`, else all of them, go straight there in one
    /// traverse, with no intermediate point. Where that is, only the machine knows: the
    /// analysis takes the reference position it keeps and 0 for a fixed point, as rs274 takes
    /// an unset reference position.
    fn reference_approach(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        let named: [bool; 6] = std::array::from_fn(|i| self.slots[Role::AXES[i] as usize].is_some());
        let moves: [bool; 6] = if named.iter().any(|&b| b) {
            named
        } else if def.home_axes != 0 {
            std::array::from_fn(|i| def.home_axes & 1 << i != 0)
        } else {
            [true; 6]
        };
        let (target, at) = if def.meaning == Meaning::ReferenceApproach {
            (MachineTarget::Direct(1), self.st.home1)
        } else {
            let n = self.slot(Role::P).map_or(1.0, f64::round);
            (MachineTarget::Fixed(if (1.0..=4.0).contains(&n) { n as u8 } else { 1 }), [0.0; 6])
        };
        let axes = std::array::from_fn(|i| moves[i].then_some(0.0));
        self.emit(sink, CanonOp::MachineMove(Box::new(MachineMove { target, axes })));
        let k = |i: usize| if i < 3 { 1.0 / self.st.units.to_mm() } else { 1.0 };
        let tlo = |i: usize| if i < 3 { self.st.tool_offset[i] } else { 0.0 };
        let mut end = self.st.pos;
        if self.st.rotation(self.st.wcs) != 0.0 {
            let mut m = self.to_machine(std::array::from_fn(|i| self.st.pos[i] + tlo(i)));
            for (i, v) in m.iter_mut().enumerate() {
                if moves[i] {
                    *v = at[i] * k(i);
                }
            }
            let p = self.program_pos(m);
            end = std::array::from_fn(|i| p[i] - tlo(i));
        } else {
            for i in 0..6 {
                if moves[i] {
                    end[i] = at[i] * k(i) - self.st.offset(self.st.wcs)[i] - self.st.g92[i] - tlo(i);
                }
            }
        }
        self.emit(sink, CanonOp::StraightTraverse(end));
        self.st.pos = end;
    }

    /// Heidenhain `M140 MB MAX` (TNC 640 user's manual, "Retraction in the tool axis
    /// direction: M140"): the tool axis alone, in the tilted plane the tool axis in force,
    /// retracts to just before its software limit switch, in one traverse. Where that is,
    /// only the machine knows: the analysis leaves the position as it was, and the axis is
    /// unknown in the work frame after it, as after a reference return.
    pub(super) fn travel_limit(&mut self, sink: &mut dyn CanonSink) {
        let (_, _, n) = self.st.plane.axes();
        let axes = std::array::from_fn(|i| (i == n).then_some(0.0));
        self.emit(sink, CanonOp::MachineMove(Box::new(MachineMove { target: MachineTarget::Limit, axes })));
        self.emit(sink, CanonOp::StraightTraverse(self.st.pos));
    }

    /// G28 (`k` 1) or G30 (`k` 2 to 4): a rapid through the block's point, then to the
    /// reference position along the axes the block names (all of them without any).
    fn home(&mut self, k: u8, sink: &mut dyn CanonSink) {
        let first = k == 1;
        // A mill's quill (`W`) is an axis of the return too (LinuxCNC stores W's reference in
        // #5169/#5189; 0 unless set): `G28 W0` homes the quill alone, `G28` all axes with it.
        let quill = self.slots[Role::W as usize].filter(|_| self.quill_moves_tool());
        let any = Role::AXES.iter().any(|&r| self.slots[r as usize].is_some()) || quill.is_some();
        // The intermediate point's words are incremental per word too, as a move's are: a
        // lathe's `U`/`W` are incremental X/Z whatever G90/G91 says (Fanuc 0i-TF, Haas lathe
        // manual: `G28 U0 W0` returns through the current position, never through X0 Z0).
        let mut mid = self.st.pos;
        let mut stated = 0u8;
        for (i, &role) in Role::AXES.iter().enumerate() {
            if let Some(v) = self.slot(role) {
                let incremental = self.incremental(role);
                mid[i] = if incremental { self.st.pos[i] + v } else { v };
                if !incremental {
                    stated |= 1 << i;
                }
            }
        }
        // An absolute intermediate point is known on the way (`G90 G28 Z5`); the axes the
        // return moves are unknown after it (`CanonOp::MachineMove`).
        self.stated.set(stated);
        let home = if first { self.st.home1 } else { self.st.home2 };
        // Without axis words every axis returns; a rotary axis the program never used, at 0 and
        // with its reference at 0, is left out: it does not move, and a target writing it
        // (`A0. B0. C0.`) would name axes a three-axis machine rejects.
        let homed: [bool; 6] = std::array::from_fn(|i| {
            if any {
                self.slots[Role::AXES[i] as usize].is_some()
            } else {
                i < 3 || self.knows(i) || self.st.pos[i] != 0.0 || home[i] != 0.0
            }
        });
        let axes = std::array::from_fn(|i| homed[i].then_some(0.0));
        let target = MachineTarget::Reference(k);
        self.emit(sink, CanonOp::MachineMove(Box::new(MachineMove { target, axes })));
        if let Some(w) = quill {
            let incremental = match w.mode {
                WordMode::Modal => self.st.distance == DistanceMode::Incremental,
                WordMode::Absolute => false,
                WordMode::Incremental => true,
            };
            self.st.quill = if incremental { self.st.quill + w.value } else { w.value };
        }
        self.emit(sink, CanonOp::StraightTraverse(mid));
        if !any || quill.is_some() {
            self.st.quill = 0.0;
        }
        let mut end = mid;
        let moves = |i: usize| homed[i];
        let k = |i: usize| if i < 3 { 1.0 / self.st.units.to_mm() } else { 1.0 };
        // The tool offsets move the controlled point: the tool's tip reaches the reference
        // position, so its program position is short of it by the offset (rs274).
        let tlo = |i: usize| if i < 3 { self.st.tool_offset[i] } else { 0.0 };
        if self.st.rotation(self.st.wcs) != 0.0 {
            let mut m = self.to_machine(std::array::from_fn(|i| mid[i] + tlo(i)));
            for (i, v) in m.iter_mut().enumerate() {
                if moves(i) {
                    *v = home[i] * k(i);
                }
            }
            let p = self.program_pos(m);
            end = std::array::from_fn(|i| p[i] - tlo(i));
        } else {
            for i in 0..6 {
                if moves(i) {
                    end[i] = home[i] * k(i) - self.st.offset(self.st.wcs)[i] - self.st.g92[i] - tlo(i);
                }
            }
        }
        self.emit(sink, CanonOp::StraightTraverse(end));
        self.st.pos = end;
    }
}

//! Cycles that are defined and then called (`CYCLE81(...)`, `MCALL`, `CYCL DEF 200` with
//! `CYCL CALL` or `M99`), and the programmable frame (`TRANS`, `ROT`, `SCALE`).
//!
//! A defined cycle states its geometry by planes rather than by R and Z words: a reference
//! plane (the surface), a safety distance above it, a depth (absolute or below the surface)
//! and a retract plane. The moves are the same as those of the G8x cycles (`cycle.rs`).
//!
//! Hole patterns (`HOLES1`, `HOLES2`, `CYCLE801`; Haas `G70`/`G71`) give the positions at
//! which the cycle in force runs: the modal defined cycle, or the G8x cycle.

use super::cycle::HoleRun;
use super::{Interpreter, Slot};
use crate::canon::{CanonOp, CanonSink, CycleKind, DistanceMode, Units};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, CycleDef, Meaning, Role};
use crate::syntax::{Block, WordMode};
use crate::text::TextRange;

/// A cycle waiting to be called.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct Defined {
    /// Index into the dialect's cycles.
    cycle: usize,
    /// Positional arguments as given; parameter-defined cycles read theirs at the call.
    args: Vec<(Role, f64)>,
    /// Where the definition was written, for messages.
    range: TextRange,
}

impl Interpreter<'_> {
    /// `CYCL DEF 200`: remembers cycle 200 for later calls; a cycle that acts where it is
    /// written (`CYCL DEF 7.1 X+10`, a datum shift) acts now.
    pub(super) fn define_numbered_cycle(
        &mut self,
        def: &CodeDef,
        range: TextRange,
        block: &Block,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        // `CYCL DEF 200` gives the number as its value; a G code (`G200`) is the number.
        let own = def.keyword.is_none().then(|| f64::from(def.number) / 10.0);
        let Some(number) = self.slot(Role::CycleNumber).or(own) else {
            diags.push(Diagnostic::new(Code::MissingParameter, range, format!("{} needs a cycle number", def.label())));
            return;
        };
        let name = format!("{}", number.trunc());
        let Some(ci) = self.dialect.cycle(&name) else {
            let d = Diagnostic::new(
                Code::Unsupported,
                range,
                format!("{} {name}: the {} dialect has no cycle {name}; skipped", def.label(), self.dialect.name),
            );
            self.limited(diags, "cycle-unknown", d);
            // The control runs this cycle at the next call: the call is intent, never a call
            // of an earlier cycle (whose moves would be invented) nor a call of no cycle.
            self.st.defined_cycle = None;
            self.st.unmodelled_cycle = Some(name);
            return;
        };
        let cycle = &self.dialect.cycles[ci];
        if !cycle.immediate {
            self.st.unmodelled_cycle = None;
            // `CYCL DEF 1.0` (or `CYCL DEF 200`) starts the definition; the sub-blocks
            // `CYCL DEF 1.1 DIST2` ... add their words to it.
            let sub = (number.fract() * 10.0).round();
            let same = self.st.defined_cycle.as_ref().is_some_and(|d| d.cycle == ci);
            if sub == 0.0 || !same {
                self.st.defined_cycle = Some(Defined { cycle: ci, args: Vec::new(), range });
            }
            let mut words: Vec<(Role, f64)> =
                cycle.args.iter().filter(|a| a.param.is_none()).filter_map(|a| self.slot(a.role).map(|v| (a.role, v))).collect();
            // `CYCL DEF 1.2 DEPTH -15`: the value after the name is the sub-block's argument.
            if let Some(v) = self.slot(Role::CycleValue) {
                let arg = cycle.args.iter().find(|a| a.sub.is_some_and(|s| f64::from(s) == sub));
                if let Some(a) = arg.filter(|a| !words.iter().any(|(r, _)| *r == a.role)) {
                    words.push((a.role, v));
                }
            }
            if let Some(d) = self.st.defined_cycle.as_mut() {
                d.args.extend(words);
            }
            return;
        }
        match cycle.meaning {
            Meaning::LocalOffset => self.datum_shift(sink),
            Meaning::TiltSpatial => self.tilt_by_axis_words(sink),
            // `CYCL DEF 8.1 X Y`: the axes listed (their words without values); `8.0` names the cycle.
            Meaning::FrameMirror => {
                if (number.fract() * 10.0).round() != 0.0 {
                    let rest = block.text(TextRange { start: range.end, end: block.range.end });
                    let listed = |letter: char| rest.split_ascii_whitespace().any(|w| w.len() == 1 && w.starts_with(letter));
                    let named = [0, 1, 2].map(|i| self.slots[Role::AXES[i] as usize].is_some() || listed(['X', 'Y', 'Z'][i]));
                    self.frame_mirror(false, named);
                }
            }
            // `CYCL DEF 9.1 DWELL 1.5`: the sub-block's value, seconds.
            Meaning::Dwell => {
                if let Some(seconds) = self.slot(Role::CycleValue) {
                    self.emit(sink, CanonOp::Dwell(seconds));
                }
            }
            Meaning::Wcs => self.select_preset(ci, &name, range, sink, diags),
            // `CYCL DEF 14.1 CONTOUR LABEL 1`: the subprogram label whose blocks draw the
            // contour of the contour cycles after it; of `LABEL 1/2/3` the first.
            Meaning::ContourDefine => {
                if (number.fract() * 10.0).round() != 0.0 {
                    let rest = block.text(TextRange { start: range.end, end: block.range.end });
                    // The first label after the sub-block number: a quoted name, or the first
                    // number, alone or run into the name before it (`LABEL 1 /2`, `LABEL1 /2`,
                    // older `KONTURLABEL1`).
                    let mut words = rest.split_ascii_whitespace().skip(1);
                    let written = words.find(|w| w.starts_with('"') || w.bytes().any(|c| c.is_ascii_digit())).map(|w| {
                        let first = w.split('/').find(|p| !p.is_empty()).unwrap_or_default();
                        if first.starts_with('"') {
                            first.trim_matches('"')
                        } else {
                            first.trim_start_matches(|c: char| c.is_ascii_alphabetic())
                        }
                        .to_owned()
                    });
                    let label = written.filter(|w| !w.is_empty()).or(self.slot(Role::CycleValue).map(crate::text::num));
                    if let Some(label) = label {
                        self.contour_named = Some(label);
                    }
                }
            }
            Meaning::Other | Meaning::Output => {}
            _ => {
                let d = Diagnostic::new(
                    Code::Unsupported,
                    range,
                    format!("{} {name} ({}) is not supported yet; skipped", def.label(), cycle.meaning.as_str()),
                );
                self.limited(diags, "cycle-unsupported", d);
            }
        }
    }

    /// `CYCL DEF 247 DATUM SETTING ~ Q339=+2`: selects the work offset (preset row) its
    /// parameter numbers, 1 to 9 as G54 to G59.3 are.
    fn select_preset(&mut self, ci: usize, name: &str, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let param = self.dialect.cycles[ci].args.iter().find_map(|a| a.param);
        let n = param.and_then(|p| self.params.get(f64::from(p)).ok()).filter(|v| !super::eval::is_null(*v));
        match n {
            Some(n) if n.fract() == 0.0 && (1.0..=9.0).contains(&n) => self.state_wcs(n as u16, sink),
            _ => {
                let msg = format!("cycle {name} names no work offset from 1 to 9; the system in force stays");
                self.limited(diags, "cycle-wcs", Diagnostic::new(Code::Unsupported, range, msg));
            }
        }
    }

    /// A datum shift of the given axes (absolute, or incremental per word), kept with G52.
    fn datum_shift(&mut self, sink: &mut dyn CanonSink) {
        let old = self.st.g92;
        for (i, &role) in Role::AXES.iter().enumerate() {
            if let Some(v) = self.slot(role) {
                self.st.g92[i] = if self.incremental(role) { old[i] + v } else { v };
            }
        }
        if self.st.g92 != old {
            let new = self.st.g92;
            self.shift_origin(old, new);
            self.emit(sink, CanonOp::SetG92Offset(new));
        }
    }

    /// After a block ran: defines its named cycle, switches modal calls on or off, and calls
    /// the defined cycle where the block asks for it or, while modal, after a move.
    pub(super) fn cycles_after(&mut self, motions: u64, block_range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let has = |s: &Self, m: Meaning| s.codes.iter().any(|&(c, _)| s.code(c).meaning == m);
        let modal = has(self, Meaning::CycleModal);
        if let Some(ci) = self.block_cycle.take_if(|&mut ci| pattern_kind(self.dialect.cycles[ci].meaning)) {
            // A hole pattern leaves the modal cycle defined, and runs it at its positions.
            let args = std::mem::take(&mut self.cycle_args);
            self.run_pattern(ci, &args, block_range, sink, diags);
            return;
        }
        if self.block_cycle.take_if(|&mut ci| self.dialect.cycles[ci].meaning == Meaning::PolarInterpolation).is_some() {
            self.cycle_args.clear();
            self.face_mode(true, sink);
            return;
        }
        if self.block_cycle.take_if(|&mut ci| self.dialect.cycles[ci].meaning == Meaning::CylindricalInterpolation).is_some() {
            // `TRACYL(d)`: the working diameter, the argument the dictionary gives the role of
            // geometry.
            let args = std::mem::take(&mut self.cycle_args);
            let d = args.iter().find(|(r, _)| *r == Role::Geometry).map(|(_, v)| *v);
            self.cylinder_mode(d.map(|d| d / 2.0), block_range, sink, diags);
            return;
        }
        if self.block_cycle.take_if(|&mut ci| self.dialect.cycles[ci].meaning == Meaning::TcpOn).is_some() {
            self.cycle_args.clear();
            self.tcp(true, sink, diags);
            return;
        }
        if self.block_cycle.take_if(|&mut ci| self.dialect.cycles[ci].meaning == Meaning::TiltCycle).is_some() {
            let args = std::mem::take(&mut self.cycle_args);
            self.tilt_cycle(&args, block_range, sink, diags);
            return;
        }
        // A pocket cycle mills where it is called; under a modal call (`MCALL SLOT1`) it is the
        // cycle in force, called after each block that moves (below, as a drilling cycle is):
        // the 840D runs the cycle `MCALL` names after every block with a movement until `MCALL`
        // alone (Programming Manual Fundamentals, modal subprogram call).
        let pocket = |m: Meaning| matches!(m, Meaning::MillPocketRect | Meaning::MillPocketCircle | Meaning::MillSlot);
        if !modal && let Some(ci) = self.block_cycle.take_if(|&mut ci| pocket(self.dialect.cycles[ci].meaning)) {
            let args = std::mem::take(&mut self.cycle_args);
            let cycle = &self.dialect.cycles[ci];
            let (meaning, name) = (cycle.meaning, cycle.name.clone());
            self.mill_pocket(meaning, &name, &args, block_range, sink, diags);
            return;
        }
        if self.block_cycle.take_if(|&mut ci| self.dialect.cycles[ci].meaning == Meaning::ContourDefine).is_some() {
            self.cycle_args.clear();
            self.contour_named = self.cycle_text.take();
            return;
        }
        let turning = |m: Meaning| {
            matches!(
                m,
                Meaning::CycleRoughTurn
                    | Meaning::CycleGroove
                    | Meaning::CycleThreadMultiple
                    | Meaning::CycleStockCorner
                    | Meaning::CycleContourTurn
                    | Meaning::CyclePartOff
            )
        };
        if let Some(ci) = self.block_cycle.take_if(|&mut ci| turning(self.dialect.cycles[ci].meaning)) {
            let args = std::mem::take(&mut self.cycle_args);
            self.named_turn_cycle(ci, &args, block_range, sink, diags);
            return;
        }
        if self.block_cycle.take_if(|&mut ci| self.dialect.cycles[ci].meaning == Meaning::Stock).is_some() {
            let args = std::mem::take(&mut self.cycle_args);
            self.blank(&args, sink);
            return;
        }
        if let Some(ci) = self.block_cycle.take() {
            self.st.unmodelled_cycle = None;
            self.st.defined_cycle = Some(Defined { cycle: ci, args: std::mem::take(&mut self.cycle_args), range: block_range });
            if modal {
                self.st.cycle_modal = true;
            } else if self.dialect.cycles[ci].immediate {
                self.call_defined(block_range, sink, diags);
            }
            return;
        }
        if modal {
            self.st.cycle_modal = false;
        }
        if has(self, Meaning::CycleCall) || has(self, Meaning::CycleCallAt) || (self.st.cycle_modal && self.motions != motions) {
            self.call_defined(block_range, sink, diags);
        }
    }

    /// A blank the program defines by arguments (Siemens `WORKPIECE`): its corners, passed on
    /// as the stock comment that plan recovery reads (as `BLK FORM` is). A blank with no
    /// second corner is centred on the origin, its first numbers its length and width.
    fn blank(&mut self, args: &[(Role, f64)], sink: &mut dyn CanonSink) {
        let get = |r: Role| args.iter().find(|(a, _)| *a == r).map(|(_, v)| *v);
        let flags = get(Role::BlankFlags).unwrap_or(0.0) as u32;
        let absolute = |bit: u32| flags & (1 << bit) != 0;
        let (Some(top), Some(z1), Some(x0), Some(y0)) =
            (get(Role::BlankTop), get(Role::BlankBottom), get(Role::BlankX0), get(Role::BlankY0))
        else {
            return;
        };
        let bottom = if absolute(6) { z1 } else { top - z1.abs() };
        let (x, y) = match (get(Role::BlankX1), get(Role::BlankY1)) {
            (Some(x1), Some(y1)) => {
                let x1 = if absolute(4) { x1 } else { x0 + x1 };
                let y1 = if absolute(5) { y1 } else { y0 + y1 };
                ([x0.min(x1), x0.max(x1)], [y0.min(y1), y0.max(y1)])
            }
            _ => ([-x0.abs() / 2.0, x0.abs() / 2.0], [-y0.abs() / 2.0, y0.abs() / 2.0]),
        };
        let z = [bottom.min(top), bottom.max(top)];
        if x[0] >= x[1] || y[0] >= y[1] || z[0] >= z[1] {
            return;
        }
        self.emit(sink, super::stock_comment([x[0], y[0], z[0]], [x[1], y[1], z[1]]));
    }

    /// `HOLES1(...)`, `HOLES2(...)`, `CYCLE801(...)`: to each position of the pattern at the
    /// current height, rapid, and the modal cycle there if one is on.
    fn run_pattern(&mut self, ci: usize, args: &[(Role, f64)], range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let cycle = &self.dialect.cycles[ci];
        let Some(points) = pattern_at(&cycle.name, cycle.meaning, args, range, diags) else { return };
        let (a0, a1, _) = self.st.plane.axes();
        // The pattern's positions are absolute: known from the first one on.
        self.stated.set(self.stated.get() | 1 << a0 | 1 << a1);
        for (x, y) in points {
            let mut p = self.st.pos;
            (p[a0], p[a1]) = (x, y);
            if p != self.st.pos {
                self.emit(sink, CanonOp::StraightTraverse(p));
                self.st.pos = p;
            }
            if self.st.cycle_modal && self.st.defined_cycle.is_some() {
                self.call_defined(range, sink, diags);
            }
        }
    }

    /// A hole pattern a code states (Haas `G70 I1.5 J0 L6`): about the current position
    /// unless the code's words place it, the canned cycle in force makes a hole at each
    /// position, as a block naming that position would.
    pub(super) fn code_pattern(
        &mut self,
        def: &CodeDef,
        range: TextRange,
        block: &Block,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let Some(cycle) = self.st.motion_code.filter(|&c| self.code(c).meaning.is_cycle()) else {
            let msg = format!("{} drills with the canned cycle in force (G81 to G89), and none is; the pattern is skipped", def.label());
            diags.push(Diagnostic::new(Code::CycleIncomplete, range, msg));
            return;
        };
        let (a0, a1, _) = self.st.plane.axes();
        let mut args: Vec<(Role, f64)> = def.args.iter().filter_map(|&(from, to)| self.slot(from).map(|v| (to, v))).collect();
        for (role, axis) in [(Role::PatternX, a0), (Role::PatternY, a1)] {
            if !args.iter().any(|(r, _)| *r == role) {
                args.push((role, self.st.pos[axis]));
            }
        }
        let Some(points) = pattern_at(&def.label(), def.meaning, &args, range, diags) else { return };
        // The block's own words are the pattern's: the cycle sees only the position (its L
        // would be a repeat count).
        let (saved, filled) = (self.slots, self.filled);
        let incremental = self.st.distance == DistanceMode::Incremental;
        // Positions about a centre the block states absolutely are known; about the current
        // position, as that position is.
        let stated = [(Role::PatternX, a0), (Role::PatternY, a1)]
            .iter()
            .filter(|(role, _)| !incremental && def.args.iter().any(|&(from, to)| to == *role && self.slot(from).is_some()))
            .fold(0u8, |m, &(_, axis)| m | 1 << axis);
        for (x, y) in points {
            self.slots = [None; Role::COUNT];
            for (axis, v) in [(a0, x), (a1, y)] {
                let value = if incremental { v - self.st.pos[axis] } else { v };
                self.slots[Role::AXES[axis] as usize] = Some(Slot { value, range, mode: WordMode::Modal });
            }
            let cycle_def = self.code(cycle);
            self.stated.set(stated);
            self.cycle(cycle_def, range, block, sink, diags);
        }
        self.slots = saved;
        self.filled = filled;
    }

    /// `CYCL CALL POS X Y Z`: the position for the cycle the block calls. Below the set-up
    /// clearance over the new surface, the tool first rises to it; then it moves in the plane.
    /// The tool-axis word is the cycle's surface (the block's call, in [`Self::cycles_after`],
    /// takes it).
    /// From a tool-axis position the program does not know (after a tool call, a reference
    /// return, `M140 MB MAX`) where the control goes first depends on it (along the tool
    /// axis where the tool stands below the set-up clearance, else in the plane at that
    /// level): `interp::motion-unknown`, and a translation refuses.
    pub(super) fn call_at_position(&mut self, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let (a0, a1, n) = self.st.plane.axes();
        if !self.knows(n) {
            let msg = "the cycle call at a position begins where the program does not know the tool axis's position (no absolute word for it since a tool call, a reference return or a retract to the travel limit): the control first moves along the tool axis where the tool stands below the set-up clearance over the surface, else in the plane at that level, so where the tool goes is not known";
            self.limited(diags, "motion-unknown", Diagnostic::new(Code::MotionUnknown, range, msg));
        }
        let target = |s: &Self, axis: usize| {
            let role = Role::AXES[axis];
            s.slot(role).map(|v| if s.incremental(role) { s.st.pos[axis] + v } else { v })
        };
        let surface = target(self, n);
        // An incremental surface counts from where the tool stands.
        let surface_known = !self.incremental(Role::AXES[n]) || self.knows(n);
        let safety = self.defined_arg(Role::SafetyDistance).map_or(0.0, f64::abs);
        let mut p = self.st.pos;
        if let Some(top) = surface.map(|s| s + safety).filter(|&top| p[n] < top && self.knows(n)) {
            p[n] = top;
            self.emit(sink, CanonOp::StraightTraverse(p));
        }
        let mut stated = 0u8;
        for axis in [a0, a1] {
            if let Some(v) = target(self, axis) {
                p[axis] = v;
                if !self.incremental(Role::AXES[axis]) {
                    stated |= 1 << axis;
                }
            }
        }
        // Known from the move in the plane on (not the rise before it).
        self.stated.set(stated);
        if p != self.st.pos {
            self.emit(sink, CanonOp::StraightTraverse(p));
            self.st.pos = p;
        }
        self.call_surface = surface.map(|s| (s, surface_known));
    }

    /// The defined cycle's values: its own arguments, then the parameters it reads (the
    /// last value of a role is the one in force).
    fn defined_values(&self, defined: &Defined) -> Vec<(Role, f64)> {
        let cycle = &self.dialect.cycles[defined.cycle];
        let mut args = defined.args.clone();
        for a in cycle.args.iter().filter(|a| a.param.is_some()) {
            if let Some(v) = a.param.and_then(|p| self.params.get(f64::from(p)).ok()).filter(|v| !super::eval::is_null(*v)) {
                args.push((a.role, v));
            }
        }
        args
    }

    /// The value the defined cycle has for `role`.
    fn defined_arg(&self, role: Role) -> Option<f64> {
        let args = self.defined_values(self.st.defined_cycle.as_ref()?);
        args.iter().rev().find(|(r, _)| *r == role).map(|&(_, v)| v)
    }

    /// Runs the defined cycle at the current position.
    fn call_defined(&mut self, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let surface = self.call_surface.take();
        let Some(defined) = self.st.defined_cycle.clone() else {
            if let Some(name) = self.st.unmodelled_cycle.clone() {
                let msg = format!("the call runs cycle {name}, which is not modelled: kept as intent, its moves unknown");
                self.limited(diags, "cycle-not-expanded", Diagnostic::new(Code::Unsupported, range, msg));
                return;
            }
            diags.push(Diagnostic::new(Code::CycleIncomplete, range, "a cycle call without a cycle defined before it"));
            return;
        };
        let cycle = &self.dialect.cycles[defined.cycle];
        let mut args = self.defined_values(&defined);
        if let Some((surface, _)) = surface {
            args.push((Role::ReferencePlane, surface));
        }
        // The R level is known wherever the tool stands where the surface is an absolute
        // level (the cycle's own, `RFP`, `Q203`, or none: 0), not one below the tool.
        let r_known = surface.map_or(args.iter().any(|(r, _)| *r == Role::ReferencePlane) || !cycle.surface_below_start, |(_, k)| k);
        let get = |role: Role| args.iter().rev().find(|(r, _)| *r == role).map(|&(_, v)| v);
        if !self.defined_args_given(cycle, &defined, &args, diags) {
            return;
        }
        if cycle.meaning == Meaning::MillBore {
            let label = format!("CYCL DEF {}", cycle.name);
            self.mill_bore(&label, &args, range, sink, diags);
            return;
        }
        // A pocket cycle called at a position (Heidenhain 251, 252): the position is its centre.
        // So is a Siemens pocket or slot cycle under `MCALL` (`MCALL SLOT1`): SINUMERIK Operate
        // writes the modal call for its "position pattern" choice, the cycle machined at each
        // position the blocks after it reach, its own position arguments not read [unconfirmed
        // against the manual; a course's keyways at `C4=0 X10` and `C4=120 X10` lie so on the
        // shaft's centre line]; a slot on a circle is laid about that position.
        if matches!(cycle.meaning, Meaning::MillPocketRect | Meaning::MillPocketCircle | Meaning::MillSlot) {
            // A cycle with position arguments of its own is named as written, not as `CYCL DEF`.
            let own_position = args.iter().any(|(r, _)| matches!(r, Role::PocketX | Role::PocketY));
            let label = if own_position { cycle.name.clone() } else { format!("CYCL DEF {}", cycle.name) };
            let meaning = cycle.meaning;
            let (a0, a1, _) = self.st.plane.axes();
            let mut at = args.clone();
            at.extend([(Role::PocketX, self.st.pos[a0]), (Role::PocketY, self.st.pos[a1])]);
            self.mill_pocket(meaning, &label, &at, range, sink, diags);
            return;
        }
        // A cylinder surface cycle (Heidenhain 27, 28, 29, 39): the contour cycle 14 named,
        // cut on the cylinder's developed surface (`interp::cylsurf`).
        if cycle.meaning == Meaning::MillCylinderSurface {
            let label = format!("CYCL DEF {}", cycle.name);
            self.cylinder_surface(&label, &args, range, diags);
            return;
        }
        let Some(kind) = self.defined_kind(cycle, range, diags) else { return };
        let (a0, a1, n) = self.st.plane.axes();
        let surface = match get(Role::ReferencePlane) {
            Some(s) => s,
            None if cycle.surface_below_start => self.st.pos[n] - get(Role::SafetyDistance).unwrap_or(0.0).abs(),
            None => 0.0,
        };
        let r = surface + get(Role::SafetyDistance).unwrap_or(0.0).abs();
        let bottom = match (get(Role::Depth), get(Role::DepthRelative)) {
            (Some(d), _) => d,
            (None, Some(rel)) => surface - rel.abs(),
            (None, None) => {
                diags.push(Diagnostic::new(Code::CycleIncomplete, range, format!("{} has no depth", cycle.name)));
                return;
            }
        };
        let clear = match (get(Role::RetractPlane), get(Role::RetractDistance)) {
            (Some(rtp), _) => rtp,
            (None, Some(d)) => (surface + d).max(r),
            (None, None) => r,
        };
        let dwell = get(Role::DwellTime).filter(|d| *d > 0.0);
        // Pecking: the first depth below the surface; a peck as deep as the hole is one plunge.
        let first = get(Role::PeckFirst).map(f64::abs).or(get(Role::PeckFirstAbsolute).map(|d| surface - d));
        let peck = first.filter(|q| *q > 0.0 && *q < surface - bottom);
        if peck.is_some() && get(Role::PeckDecrement).is_some_and(|d| d != 0.0) {
            let msg = format!("{}: the peck degression is not applied; every peck is as deep as the first", cycle.name);
            self.limited(diags, "peck-degression", Diagnostic::new(Code::Unsupported, range, msg));
        }
        let kind = match (kind, peck, dwell) {
            (CycleKind::Drilling, Some(_), _) if get(Role::PeckMode) == Some(0.0) || cycle.meaning == Meaning::CycleChipBreak => {
                CycleKind::ChipBreaking
            }
            (CycleKind::Drilling, Some(_), _) => CycleKind::PeckDrilling,
            (CycleKind::Drilling, None, Some(_)) => CycleKind::CounterBoring,
            (k, _, _) => k,
        };
        let units_clearance =
            if self.st.units == Units::Mm { self.dialect.behaviour.peck_clearance_mm } else { self.dialect.behaviour.peck_clearance_inch };
        let clearance = get(Role::PreStop).map_or(units_clearance, f64::abs);
        if let Some(f) = get(Role::PlungeFeed).or(get(Role::F)).filter(|f| *f > 0.0 && *f != self.st.feed) {
            self.st.feed = f;
            self.emit(sink, CanonOp::SetFeedRate(f));
        }
        let label = match cycle.name.parse::<u32>() {
            Ok(_) => format!("CYCL DEF {}", cycle.name),
            Err(_) => cycle.name.clone(),
        };
        // A tap defined by its pitch feeds pitch x speed (`tap_feed`); the feed returns after.
        let restore_feed = self.st.feed;
        let (kind, tapped) = self.tap_feed(cycle, kind, &label, &args, range, sink, diags);
        let mut p = self.st.pos;
        let old_z = p[n];
        let run = HoleRun {
            kind,
            code: label,
            r,
            bottom,
            clear,
            old_z,
            peck,
            peck_from: surface,
            dwell,
            shift: 0.0,
            clearance,
            still: true,
            surface: Some(surface),
            r_known,
            returns_initial: false,
        };
        // On a lathe (X read as a diameter) a driven tool drills in G17 along Z on the face at
        // the spindle's C angle, in G19 along X into the cylinder (Siemens 840D turning: the
        // main spindle in position control is the C axis, `SPOS` turns it): a hole at (radius,
        // C) or (Z, C) with its own axis, as the C-axis lathe cycles make them (interp::live).
        // The cycle's planes along X are read as radii, as the X words are [unconfirmed].
        if self.st.diameter && n != 1 {
            let run = HoleRun { still: false, r_known: false, ..run };
            let across = if n == 0 { 2 } else { 0 };
            self.live_holes(&run, n, 1, p[5], p[across], sink);
            if tapped && self.st.feed != restore_feed {
                self.st.feed = restore_feed;
                self.emit(sink, CanonOp::SetFeedRate(restore_feed));
            }
            return;
        }
        // From a tool-axis position the program does not know, the hole's own first move goes
        // to R (known from there); from a known one below R, the tool rises to it first.
        if p[n] < r && (self.knows(n) || !r_known) {
            p[n] = r;
            self.emit(sink, CanonOp::StraightTraverse(p));
        }
        self.st.pos = self.hole(&run, p[a0], p[a1], p, sink);
        if tapped && self.st.feed != restore_feed {
            self.st.feed = restore_feed;
            self.emit(sink, CanonOp::SetFeedRate(restore_feed));
        }
    }

    /// A rigid tap defined by its pitch (Heidenhain 207 Q239, 840D CYCLE84 PIT or MPIT, a
    /// metric size's coarse pitch) feeds the pitch per turn of the spindle, whatever F is
    /// in force; the sign of the pitch is the thread's hand (+ right, as M3; - left). Its
    /// feed is the pitch times the speed in force (per minute) or the pitch (per turn);
    /// the feed in force returns after it. Without a pitch or a speed known here (or at
    /// a tapping speed of its own, CYCLE84 SST, other than the one in force), where it
    /// feeds is not known: a translation refuses.
    /// Returns the kind (its hand) and whether the feed was set (to be restored after).
    #[allow(clippy::too_many_arguments)]
    fn tap_feed(
        &mut self,
        cycle: &CycleDef,
        kind: CycleKind,
        label: &str,
        args: &[(Role, f64)],
        range: TextRange,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) -> (CycleKind, bool) {
        let get = |role: Role| args.iter().rev().find(|(r, _)| *r == role).map(|&(_, v)| v);
        let mut tapped = false;
        let mut kind = kind;
        if cycle.meaning == Meaning::CycleTap && cycle.args.iter().any(|a| matches!(a.role, Role::Pitch | Role::ThreadSize)) {
            let pitch = get(Role::Pitch).filter(|p| *p != 0.0).or_else(|| {
                let s = get(Role::ThreadSize).filter(|s| *s != 0.0)?;
                let pitch = super::named_turn::coarse_pitch(s.abs())?;
                Some(pitch.copysign(s))
            });
            let speed = self.st.speed;
            let own_speed = get(Role::S).filter(|s| *s > 0.0);
            match pitch {
                Some(pitch) if speed > 0.0 && own_speed.is_none_or(|s| s == speed) => {
                    if pitch < 0.0 {
                        kind = CycleKind::LeftTapping;
                    }
                    let f = if self.st.feed_per_rev { pitch.abs() } else { pitch.abs() * speed };
                    tapped = true;
                    if f != self.st.feed {
                        self.st.feed = f;
                        self.emit(sink, CanonOp::SetFeedRate(f));
                    }
                }
                _ => {
                    let msg = format!(
                        "{label} taps at its pitch times the spindle speed; without its pitch or the speed known here (or at a tapping speed of its own), its feed is not known"
                    );
                    self.limited(diags, "tap-pitch", Diagnostic::new(Code::MotionUnknown, range, msg));
                }
            }
        }
        (kind, tapped)
    }

    /// Whether the defined cycle's required arguments all have values in `args` (the values
    /// of `defined`): one set outside this file leaves its moves unexpanded, with a note;
    /// one missing is an error.
    fn defined_args_given(&mut self, cycle: &CycleDef, defined: &Defined, args: &[(Role, f64)], diags: &mut Vec<Diagnostic>) -> bool {
        let get = |role: Role| args.iter().rev().find(|(r, _)| *r == role).map(|&(_, v)| v);
        // A parameter set from outside the file (`Q201=-Q1`, the caller's Q1) has a value the
        // control knows: the cycle runs there, but where it goes is not known here.
        let outside = |p: Option<u32>| p.is_some_and(|p| self.params.get(f64::from(p)).is_ok_and(super::eval::is_unknown));
        if let Some(a) = cycle.args.iter().find(|a| a.required && get(a.role).is_none() && outside(a.param)) {
            let msg = format!(
                "{} reads {} ({}), which is set outside this file: its moves are not expanded",
                cycle.name,
                a.name,
                a.role.as_str()
            );
            self.limited(diags, "unknown-value", Diagnostic::new(Code::UnknownValue, defined.range, msg));
            return false;
        }
        for a in cycle.args.iter().filter(|a| a.required) {
            if get(a.role).is_none() {
                let msg = format!("{} needs {} ({})", cycle.name, a.name, a.role.as_str());
                diags.push(Diagnostic::new(Code::MissingParameter, defined.range, msg));
                return false;
            }
        }
        true
    }

    /// The kind of hole the defined cycle makes; `None` for a cycle that moves nothing, or one
    /// kept as intent only (with a note).
    fn defined_kind(&mut self, cycle: &CycleDef, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<CycleKind> {
        Some(match cycle.meaning {
            Meaning::CycleDrill | Meaning::CyclePeckDrill | Meaning::CycleChipBreak | Meaning::CycleDrillDwell => CycleKind::Drilling,
            Meaning::CycleBore => CycleKind::Boring,
            Meaning::CycleBoreDwell => CycleKind::BoringDwell,
            Meaning::CycleBoreStop => CycleKind::BoringSpindleStop,
            Meaning::CycleBoreManual => CycleKind::BoringManual,
            Meaning::CycleTap => CycleKind::Tapping,
            Meaning::CycleTapLeft => CycleKind::LeftTapping,
            Meaning::CycleFineBore => CycleKind::FineBoring,
            Meaning::Other | Meaning::Output => return None,
            m => {
                // A turning machine's cycle is a lathe's word, expanded or not.
                if m == Meaning::CycleTurnIntent {
                    self.lathe_word();
                }
                let msg = format!("{} ({}) is kept as intent only: its moves are not expanded", cycle.name, m.as_str());
                self.limited(diags, "cycle-not-expanded", Diagnostic::new(Code::Unsupported, range, msg));
                return None;
            }
        })
    }

    /// The programmable frame deleted, as each replacing frame instruction (`TRANS`, `ROT`,
    /// `SCALE`, `MIRROR`) does before it sets its own component (SINUMERIK 840D sl
    /// Programming Manual Fundamentals, "Frame instructions": a substitutional instruction
    /// resets all frame instructions programmed before it; the additive `A…` forms keep them).
    pub(super) fn frame_replaced(&mut self, sink: &mut dyn CanonSink) {
        self.frame_cleared_but_translation(sink);
        let old = self.st.g92;
        if old != [0.0; 6] {
            self.st.g92 = [0.0; 6];
            self.shift_origin(old, self.st.g92);
            self.emit(sink, CanonOp::SetG92Offset(self.st.g92));
        }
    }

    /// The plane a rotation in space turned put back about the datum it turned on, then the
    /// rotation, mirroring and scaling cleared.
    fn frame_cleared_but_translation(&mut self, sink: &mut dyn CanonSink) {
        self.programmable_rotation_cleared(sink);
        self.st.rotation = None;
        self.set_mirror_and_scale([None; 3], None);
    }

    /// `TRANS X10 Y5` replaces the programmable frame with a translation (alone: no frame);
    /// `ATRANS` adds to it. Kept in the G52/G92 offset, as G52 is.
    pub(super) fn frame_trans(&mut self, additive: bool, sink: &mut dyn CanonSink) {
        let old = self.st.g92;
        let mut new = if additive { old } else { [0.0; 6] };
        if !additive {
            self.frame_cleared_but_translation(sink);
        }
        for (i, &role) in Role::AXES.iter().enumerate() {
            if let Some(v) = self.slot(role) {
                new[i] += v;
            }
        }
        self.st.g92 = new;
        self.shift_origin(old, new);
        self.emit(sink, CanonOp::SetG92Offset(new));
    }

    /// `ROT RPL=30` / `ROT Z30` rotates the frame in the plane about the program origin;
    /// `AROT` adds to the rotation. An angle about X or Y turns the frame in space: a tilted
    /// working plane ([`Interpreter::frame_rotation_in_space`]). A replacing `ROT` puts back
    /// the plane a rotation in space had turned.
    pub(super) fn frame_rot(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        let additive = def.meaning == Meaning::FrameRotAdd;
        let about_z = self.slot(Role::R).or(self.slot(Role::Z)).unwrap_or(0.0);
        let [x, y] = [Role::X, Role::Y].map(|r| self.slot(r).unwrap_or(0.0));
        if !additive {
            self.frame_replaced(sink);
        }
        if x != 0.0 || y != 0.0 {
            self.frame_rotation_in_space([x, y, about_z], additive, sink);
            return;
        }
        let base = match (additive, self.st.rotation) {
            (true, Some((_, _, c, s))) => s.atan2(c).to_degrees(),
            _ => 0.0,
        };
        let total = (base + about_z).to_radians();
        self.st.rotation = if total == 0.0 { None } else { Some((0.0, 0.0, total.cos(), total.sin())) };
    }

    /// `SCALE X2 Y2` replaces the frame with a scale per axis (1 where not given); `ASCALE`
    /// multiplies the scale in force.
    pub(super) fn frame_scale(&mut self, additive: bool, sink: &mut dyn CanonSink) {
        if !additive {
            self.frame_replaced(sink);
        }
        let mut k = match (additive, self.st.scale_set) {
            (true, Some((_, k))) => k,
            _ => [1.0; 3],
        };
        for (i, &role) in [Role::X, Role::Y, Role::Z].iter().enumerate() {
            if let Some(v) = self.slot(role).filter(|v| *v > 0.0 && v.is_finite()) {
                k[i] *= v;
            }
        }
        self.set_mirror_and_scale(self.st.mirror, if k == [1.0; 3] { None } else { Some(([0.0; 3], k)) });
    }
}

/// Positions a pattern may have at most: a count past this is a slip, not a part.
const MAX_PATTERN_POINTS: f64 = 10_000.0;

/// The positions of the pattern `name` states with `args`; none, with a finding that says
/// why, when they do not make one.
fn pattern_at(
    name: &str,
    meaning: Meaning,
    args: &[(Role, f64)],
    range: TextRange,
    diags: &mut Vec<Diagnostic>,
) -> Option<Vec<(f64, f64)>> {
    let get = |role: Role| args.iter().rev().find(|(r, _)| *r == role).map(|&(_, v)| v);
    pattern_points(meaning, get)
        .map_err(|problem| diags.push(Diagnostic::new(Code::MissingParameter, range, format!("{name}: {problem}; the pattern is skipped"))))
        .ok()
}

/// Whether a cycle of this meaning is a hole pattern.
fn pattern_kind(meaning: Meaning) -> bool {
    matches!(meaning, Meaning::PatternRow | Meaning::PatternCircle | Meaning::PatternGrid)
}

/// The positions of a hole pattern in the plane, in the order they are visited, from its
/// arguments by role; or what is wrong with them.
fn pattern_points(meaning: Meaning, get: impl Fn(Role) -> Option<f64>) -> Result<Vec<(f64, f64)>, String> {
    let count = |role: Role, what: &str| match get(role) {
        Some(n) if n.fract() == 0.0 && (1.0..=MAX_PATTERN_POINTS).contains(&n) => Ok(n as usize),
        Some(n) => Err(format!("{what} must be a whole number from 1 to {MAX_PATTERN_POINTS}, not {n}")),
        None => Err(format!("{what} ({}) is missing", role.as_str())),
    };
    let (x0, y0) = (get(Role::PatternX).unwrap_or(0.0), get(Role::PatternY).unwrap_or(0.0));
    let angle = get(Role::PatternAngle).unwrap_or(0.0).to_radians();
    let (c, s) = (angle.cos(), angle.sin());
    let points: Vec<(f64, f64)> = match meaning {
        Meaning::PatternRow => {
            let (first, spacing) = (get(Role::PatternFirst).unwrap_or(0.0), get(Role::PatternSpacing).unwrap_or(0.0));
            (0..count(Role::PatternCount, "the number of holes")?)
                .map(|i| {
                    let d = first + i as f64 * spacing;
                    (x0 + d * c, y0 + d * s)
                })
                .collect()
        }
        Meaning::PatternCircle => {
            let n = count(Role::PatternCount, "the number of holes")?;
            // A negative radius runs the circle clockwise (Haas `I-1.5`).
            let radius = get(Role::PatternRadius).unwrap_or(0.0);
            // A full circle: the step the control calculates from the count (a step angle 0, or
            // Siemens Operate's `_VARI` units digit 0, the machining type the dictionary gives
            // that role; the pitch circle's step angle is then not read).
            let full = get(Role::MachiningType).is_some_and(|v| v.rem_euclid(10.0) == 0.0);
            let step = match get(Role::PatternStepAngle).unwrap_or(0.0) {
                a if a == 0.0 || full => 360.0 / n as f64,
                a => a,
            } * radius.signum();
            let radius = radius.abs();
            (0..n)
                .map(|i| {
                    let a = angle + (i as f64 * step).to_radians();
                    (x0 + radius * a.cos(), y0 + radius * a.sin())
                })
                .collect()
        }
        _ => {
            let (columns, rows) =
                (count(Role::PatternCount, "the number of columns")?, count(Role::PatternRowCount, "the number of rows")?);
            if columns as f64 * rows as f64 > MAX_PATTERN_POINTS {
                return Err(format!("{columns} columns by {rows} rows is more than {MAX_PATTERN_POINTS} positions"));
            }
            let (dx, dy) = (get(Role::PatternSpacing).unwrap_or(0.0), get(Role::PatternRowSpacing).unwrap_or(0.0));
            let mut out = Vec::with_capacity(columns * rows);
            for row in 0..rows {
                for k in 0..columns {
                    // Meander: every other row runs back.
                    let col = if row % 2 == 0 { k } else { columns - 1 - k };
                    let (u, v) = (col as f64 * dx, row as f64 * dy);
                    out.push((x0 + u * c - v * s, y0 + u * s + v * c));
                }
            }
            out
        }
    };
    // Cosines of right angles leave residues like 6e-17: round those away, so that a hole on
    // an axis is exactly on it (and never prints as -0.0000).
    let clean = |v: f64| {
        let r = (v * 1e9).round() / 1e9;
        if (v - r).abs() < 1e-12 { r + 0.0 } else { v }
    };
    Ok(points.into_iter().map(|(x, y): (f64, f64)| (clean(x), clean(y))).collect())
}

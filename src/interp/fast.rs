//! The fast lane: the block that makes up most of any CAM program, a straight move with
//! literal X, Y and Z words, perhaps its G0 or G1 (or a keyword's straight move, Heidenhain's
//! `L`) and an F (`X12.5 Y-3.2 Z-1.05`, `G1 X3 Y4 F600`); and the move of a macro program's
//! loop, whose words are expressions of ordinary numbers (`G1 X#<x> Y#<y>`, `G1 X=XP`,
//! `L X+Q3 Y+Q4`), evaluated as `read` would evaluate them.
//!
//! Such a block needs none of the general machinery: no codes to sort into steps, no
//! expressions, no parameter checks, no cycle or macro after it. The lane does exactly what
//! `read`, `step(Feed)`, `step(Motion)` and `motion` do for it, in the same order and with the
//! same state changes, and turns down anything else, which then goes the general way.
//! Its op goes through `emit_straight`, which sends it straight to the sink unless a
//! transform, corners or cutter compensation apply, and then goes the usual way (`emit`). The
//! block's words are not put in the slots: nothing after a plain move reads them.
//!
//! `Profile::fast_lane` switches it off; the corpus test `fast_lane_changes_nothing` runs
//! every program both ways and compares the canonical text and the findings.

use super::{Interpreter, eval};
use crate::canon::{CanonOp, CanonSink, DistanceMode};
use crate::diag::Diagnostic;
use crate::dialect::{Dialect, Meaning, Role, Step};
use crate::syntax::{Block, PlainLine, Value, WordMode};
use crate::text::TextRange;

/// What a run of plain lines may take for granted ([`Interpreter::plain_ready`]).
#[derive(Clone, Copy, Debug)]
pub struct PlainRun {
    /// Whether a stage stands between a move and the sink ([`Interpreter::staged`]).
    staged: bool,
}

impl Interpreter<'_> {
    /// Executes `block` when it is a plain move; false, with nothing changed, when it is not.
    /// A word's value may be an expression of ordinary numbers ([`eval::eval_fast`]: a loop's
    /// `G1 X#<x> Y#<y>`, `G1 X=XP`, `L X+Q3`) where the block reads no system variable, so
    /// that `read` would only have evaluated it; such a value counts as written without a
    /// point (a control that scales those takes the general way, which leaves it unscaled).
    pub(super) fn fast_move(&mut self, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) -> bool {
        if !block.comments.is_empty() || !block.assigns.is_empty() || block.control.is_some() {
            return false;
        }
        if !self.plain_state() {
            return false;
        }
        // `X1=10` (a machine axis name): the general way says it. Each word's bytes are taken
        // from the block's source by offset, as `Block::text` takes its text, without the
        // character-boundary checks of a `str` slice: a Siemens program asks this of every
        // block (the words of `G1 X=XP Y=YP` cost more to slice as text than to look at).
        if self.machine_axis_names {
            let (src, at) = (block.source().as_bytes(), block.range.start);
            let word = |r: TextRange| src.get(r.start.wrapping_sub(at) as usize..r.end.wrapping_sub(at) as usize).unwrap_or_default();
            if block.words.iter().any(|w| numbered_axis(word(w.range))) {
                return false;
            }
        }
        let exprs = !block.exprs.is_empty();
        if exprs && !self.plain_expressions(block) {
            return false;
        }
        let mut words = [None; 8];
        if block.words.len() > words.len() {
            return false;
        }
        for (slot, w) in words.iter_mut().zip(&block.words) {
            *slot = match w.value {
                Value::Number { value, decimal } if w.mode == WordMode::Modal => Some((w.role, value, decimal)),
                Value::Expr(e) if w.mode == WordMode::Modal && !w.cycle_arg => {
                    match eval::eval_fast(block, e, &self.params).filter(|v| v.is_finite()) {
                        Some(v) => Some((w.role, v, false)),
                        None => return false,
                    }
                }
                _ => return false,
            };
        }
        if exprs {
            // As `eval` leaves it: no unknown value read.
            self.params.take_unknown_read();
        }
        let none = (0, &[true; 3], &[0.0; 3]);
        self.plain_move(words[..block.words.len()].iter().copied(), none, block.range, self.staged(), true, sink, diags)
    }

    /// Whether the expressions of `block` leave `read` nothing to do but evaluate them: the
    /// block reads no system variable (its names resolved, [`eval::resolve`]), names no axis
    /// by a variable, and no face plane maps its words.
    fn plain_expressions(&self, block: &Block) -> bool {
        let macros = &self.dialect.macros;
        (block.reads_no_system || (macros.system.is_empty() && macros.system_named.is_empty()))
            && block.axis_refs.is_empty()
            && self.st.face_plane.is_none()
    }

    /// Whether lines of plain words may run by [`Interpreter::run_plain`] now, and what they
    /// may take for granted. A plain move turns on nothing this looks at, so the driver asks
    /// once for a run of them. It may turn one stage off: compensation stops at a move it
    /// cannot compensate. The rest of the run, still counted as staged, then sends its moves
    /// through [`Interpreter::emit`], which finds no stage and sends them as they are: the same
    /// ops.
    pub fn plain_ready(&self) -> Option<PlainRun> {
        (!self.st.ended && self.profile.fast_lane && self.plain_state()).then(|| PlainRun { staged: self.staged() })
    }

    /// Whether the state lets a block be a plain move at all: no modal cycle or macro, no
    /// message waiting for a stop, no diameter programming, no modal rounding (`RNDM`), no NURBS curve under way, no
    /// face (`TRANSMIT`, `G12.1`) or cylinder (`TRACYL`, `G7.1`) interpolation, whose words
    /// are not the machine's axes (`face_plane` is set under both), no polar coordinate
    /// command (Fanuc `G16`: X and Y are a radius and an angle).
    #[inline(always)]
    fn plain_state(&self) -> bool {
        !(self.st.cycle_modal
            || self.st.modal_macro.is_some()
            || self.stop_message.is_some()
            || self.st.diameter
            || self.st.round_modal.is_some()
            || self.st.face_plane.is_some()
            || self.st.tcp
            || self.st.polar_command
            || self.st.nurbs.is_some())
    }

    /// Runs `line`, a block of plain words the driver read without a [`Block`], exactly as
    /// `execute` runs the same block; false, with nothing changed, when it is no plain move
    /// (it then goes the general way). Only where [`Interpreter::plain_ready`] says so.
    ///
    /// Not inlined: the parser's loop that calls it for each line keeps its own values in
    /// registers.
    #[inline(never)]
    pub fn run_plain(&mut self, run: PlainRun, line: &PlainLine, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) -> bool {
        // Stages only go off during a run ([`Interpreter::plain_ready`]).
        debug_assert!(self.plain_ready().is_some_and(|r| run.staged || !r.staged));
        // The op's origin, as `execute` sets it first (and sets it again for a block it runs
        // the general way).
        self.origin = line.range;
        self.line = line.line;
        let words = line.words().iter().map(|w| Some((w.role, w.value, w.decimal)));
        if !self.plain_move(words, line.axes(), line.range, run.staged, false, sink, diags) {
            return false;
        }
        // What `execute` does after its block; without stages there is nothing to report.
        if run.staged {
            if self.comp_problem.get().is_some() {
                self.comp_report(diags);
            }
            if self.corners.get_mut().is_some() {
                self.corner_report(diags);
            }
        }
        true
    }

    /// The plain move of `words` (role, value, whether written with a point; `None` for a
    /// word that is no literal number) and of X, Y and Z words read by axis (`read`: which
    /// axes, by axis whether with a point, their values; as [`PlainLine::axes`] gives them) in
    /// the block at `range`, in a state that admits one ([`Interpreter::plain_state`]);
    /// `staged` as [`Interpreter::staged`] says. `keywords`: whether the words may hold a
    /// keyword code (a block's may, a plain line's may not: the plain lane's loop is then
    /// without the case).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn plain_move(
        &mut self,
        words: impl Iterator<Item = Option<(Role, f64, bool)>>,
        read: (u8, &[bool; 3], &[f64; 3]),
        range: TextRange,
        staged: bool,
        keywords: bool,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) -> bool {
        // Integers that count increments (`X10` is 10 µm on such a control) go the general way.
        let integers_scale = self.integers_scale;
        let incremental = self.st.distance == DistanceMode::Incremental;
        let mut to = self.st.pos;
        let (mut axes, mut code, mut feed) = (0u32, None, None);
        // Its lengths written as whole numbers (`X55.`) and as fractions, as `read` counts them.
        let mut whole_points = [0u32; 2];
        for w in words {
            let Some((role, value, decimal)) = w else { return false };
            if integers_scale && !decimal {
                return false;
            }
            let axis = match role {
                Role::X => 0,
                Role::Y => 1,
                Role::Z => 2,
                Role::G if code.is_none() => {
                    let Some(c) = self.plain_motion_code(value) else { return false };
                    code = Some(c);
                    continue;
                }
                // A keyword motion code (Heidenhain `L`): its value is the code's index.
                Role::Keyword if keywords && code.is_none() => {
                    let Some(c) = self.plain_keyword_code(value) else { return false };
                    code = Some(c);
                    continue;
                }
                Role::F if feed.is_none() && self.feed_before_motion => {
                    feed = Some(value);
                    continue;
                }
                _ => return false,
            };
            if axes & 1 << axis != 0 {
                return false;
            }
            axes |= 1 << axis;
            if integers_scale {
                // Only such a control counts them (`fract` is a call where the target has no
                // rounding instruction).
                whole_points[usize::from(value.fract() != 0.0)] += 1;
            }
            to[axis] = if incremental { self.st.pos[axis] + value } else { value };
        }
        // The axes read by axis: as the loop takes X, Y and Z words (an axis the words wrote
        // too, or a length an integer counts, goes the general way).
        let (mask, points, values) = read;
        if mask != 0 {
            if axes & u32::from(mask) != 0 {
                return false;
            }
            axes |= u32::from(mask);
            if integers_scale {
                for (axis, &value) in values.iter().enumerate() {
                    if mask & 1 << axis != 0 {
                        if !points[axis] {
                            return false;
                        }
                        whole_points[usize::from(value.fract() != 0.0)] += 1;
                    }
                }
            }
            if mask == 0b111 && !incremental {
                // X, Y and Z, absolute (a 3D surface's every line): one copy.
                to[..3].copy_from_slice(values);
            } else {
                for (axis, &value) in values.iter().enumerate() {
                    if mask & 1 << axis != 0 {
                        to[axis] = if incremental { self.st.pos[axis] + value } else { value };
                    }
                }
            }
        }
        let Some(c) = code.or(self.st.motion_code) else { return false };
        let def = self.code(c);
        let rapid = match def.meaning {
            Meaning::Rapid => true,
            Meaning::Linear => false,
            _ => return false,
        };
        // In inverse time F is each move's time (`inverse_time_feed`), not a rate.
        if axes == 0 || (self.st.inverse_time && (!rapid || feed.is_some())) {
            return false;
        }

        // The block's words and code are not put in the slots: nothing after a plain move
        // reads them (a profile's moves look for A and C words, which go the general way), and
        // the next block's `read` clears them. What `read` left of a block before is cleared.
        if self.block_read {
            self.clear_block();
            self.block_read = false;
        }
        self.has_axes = true;
        if integers_scale {
            // Every length here has its decimal point (integers went the general way).
            self.st.length_points = true;
            self.point_habit[0] += whole_points[0];
            self.point_habit[1] += whole_points[1];
        }
        // The feed step, as `step(Feed)` does.
        if let Some(f) = feed {
            self.st.feed = f;
            self.st.feed_unknown = false;
            self.st.feed_outside = false;
            self.st.tech_warned = false;
            self.emit(sink, CanonOp::SetFeedRate(f));
        }
        // As `execute_code` and `motion` do for the motion code.
        self.st.motion_continued = self.st.motion_code == Some(c);
        if !self.st.motion_continued {
            self.st.sticky_z = None;
        }
        self.st.cycle_initial = None;
        self.st.motion_code = Some(c);
        self.motions += 1;
        self.st.leaving_comp = false;
        if !rapid {
            self.check_technology(def, range, diags);
        }
        self.note_tangent(to);
        // Absolute words make their axes known (`CanonOp::Known`); incremental ones do not.
        if !incremental {
            self.stated.set((axes & 0x3f) as u8);
        }
        self.emit_straight(sink, rapid, to, staged);
        self.st.pos = to;
        true
    }

    /// The G0 or G1 that G word `value` names, when its block needs nothing but the move:
    /// a motion code that requires no other word.
    fn plain_motion_code(&self, value: f64) -> Option<usize> {
        let x10 = (value * 10.0).round();
        if (value * 10.0 - x10).abs() >= 1e-3 || !(0.0..10_000.0).contains(&x10) {
            return None;
        }
        let c = self.dialect.code_id('G', x10 as u32)?;
        self.plain_code(c).then_some(c)
    }

    /// The straight motion code a keyword word names (its value is the code's index), when
    /// its block needs nothing but the move, and the code gives no word another role
    /// ([`straight_keyword`], asked once for each code).
    fn plain_keyword_code(&self, value: f64) -> Option<usize> {
        let c = value as usize;
        (value >= 0.0 && c as f64 == value && self.straight_keywords.get(c) == Some(&true)).then_some(c)
    }

    /// Whether code `c` is a straight move (G0, G1, `L`) that requires no other word.
    fn plain_code(&self, c: usize) -> bool {
        plain_code(self.dialect, c)
    }
}

/// Whether code `c` of `d` is a straight move (G0, G1, `L`) that requires no other word.
fn plain_code(d: &Dialect, c: usize) -> bool {
    let def = &d.codes[c];
    matches!(def.meaning, Meaning::Rapid | Meaning::Linear)
        && d.groups[def.group].step == Step::Motion
        && def.params.required.is_empty()
        && def.params.any_of.is_empty()
        && def.params.exclusive.is_empty()
}

/// Whether a keyword word naming code `c` of `d` (`c` < the number of codes) makes a plain
/// straight move: the code is one ([`plain_code`]) and gives no word another role.
pub(super) fn straight_keyword(d: &Dialect, c: usize) -> bool {
    d.codes[c].args.is_empty() && plain_code(d, c)
}

/// `X1=10`: a letter, one or two digits, then `=` (not `X10`, not `X=10`).
fn numbered_axis(t: &[u8]) -> bool {
    // Most words with no number after their letter (`X=XP`) end here.
    if !t.get(1).is_some_and(u8::is_ascii_digit) {
        return false;
    }
    let digits = t.iter().skip(1).take_while(|c| c.is_ascii_digit()).count();
    (1..=2).contains(&digits) && t.get(1 + digits) == Some(&b'=')
}

//! The steady lane: the common straight move written without the general path's checks.
//!
//! Nearly every op of a machining program is a straight move while nothing else is under way:
//! no tool change or speed waiting, no cycle in force, no words put off to the next move, no
//! rules, no repeated run being gathered, the work offset checked, the move's G code in
//! force. The general path ([`Post::op`], [`Post::straight`], [`Post::render`]) asks all of
//! that again for every move, and walks the move's template through its general layout,
//! with its values set in a [`super::Vals`]; together that is most of the writer's work.
//!
//! So the writer keeps one flag per move template ([`Post::lane_ready`]), worked out once
//! after every op the general path takes ([`Post::refresh_lane`]), since only the general
//! path changes what the flag says: a move the lane takes leaves it as it was. While it is
//! set, a straight move that needs nothing unusual itself (a rotary axis the template does
//! not write, a jump back to a line already run) goes from the op's coordinates straight to
//! the block's text ([`Post::steady_move`]): per word of a [`Lane`], the literal text or the
//! number, by the same steps the general path takes ([`Post::put_num`]: left out when
//! unchanged, rounded, the rounding kept, staged; the block left out when it moves nothing;
//! [`Post::block_start`], [`Post::line_end`], [`Post::new_line`], [`Post::moved`]), so that
//! the text, the modal state and the findings are the general path's. Anything else, and
//! any move while the flag is clear, takes the general path, which stays the one place
//! every unusual case is handled.

use super::layout::{Class, Layout, Part};
use super::{CanonOp, EPS, Key, POW10F, Post, ThreeDecimals, push_number_in, round_scaled};
use crate::canon::{Canon, Units};
use crate::dialect::output::{Output, Piece, Template, Value};

/// A move template (one block) as the steady lane writes it, made once from its
/// [`Layout`]. Empty (no words) when the template cannot be written so.
#[derive(Default)]
pub(super) struct Lane {
    /// The motion code that starts the block: the lane writes only while it is in force.
    pub code: Option<String>,
    /// Written without block number.
    raw: bool,
    /// Whether it is numbered ([`super::numbered`]).
    numbered: bool,
    /// Whether the block is left out when it moves no axis ([`super::layout::LayoutBlock::moves`]).
    moves: bool,
    /// Whether the template writes A, B, C: a move of one it does not write is said, by the
    /// general path.
    rotary: [bool; 3],
    /// Whether it writes all three (nothing to check).
    all_rotary: bool,
    /// The block's words, in order, without its motion code and the words put off to a move
    /// (none while the lane is taken).
    words: Vec<Word>,
}

/// One word of a [`Lane`].
enum Word {
    /// Text written as it is (Heidenhain's `L`, `FMAX`): its bytes, with at least 16 after
    /// them (zeros) for a copy of a fixed 16 taken back to its length, and that length.
    Lit(Box<[u8]>, usize),
    /// A number.
    Num(LaneNum),
}

/// A number placeholder of a [`Lane`], with what the general path works out for it at every
/// block ([`super::layout::Num`], its [`crate::dialect::output::NumberFormat`]) worked out once.
#[derive(Clone, Copy)]
struct LaneNum {
    /// The index of its value in [`Post::steady_move`]'s list (X, Y, Z, A, B, C, F).
    at: usize,
    /// The modal slot ([`super::modal_slot`]).
    slot: usize,
    /// Its number format.
    fi: u32,
    /// Left out when its text is unchanged.
    modal: bool,
    /// Whether writing it moves the block (not the feed).
    moves: bool,
    /// What its rounding counts towards.
    class: Class,
    /// The decimals the format writes in a millimetre and an inch program ([`super::decimals`]).
    decimals: [usize; 2],
    /// The format as [`ThreeDecimals`], in each units, where it writes three decimals after
    /// a short address (the usual format); else the number goes by [`push_number_in`].
    three: [Option<ThreeDecimals>; 2],
}

impl Lane {
    /// The lane of move template `t`, if it has one block whose words are a motion code,
    /// the words put off to a move, literal text and numbers of the values a straight move
    /// sets; otherwise an empty lane (never taken).
    pub(super) fn of(t: Option<&Template>, out: &Output) -> Lane {
        let Some(t) = t else { return Lane::default() };
        let [block] = t.0.as_slice() else { return Lane::default() };
        let layout = Layout::of(t, out, true);
        let [lb] = layout.0.as_slice() else { return Lane::default() };
        let rotary = [Value::A, Value::B, Value::C].map(|v| t.uses(v));
        let mut lane = Lane {
            code: None,
            raw: lb.raw,
            numbered: super::numbered(out, lb.raw, false),
            moves: lb.moves,
            rotary,
            all_rotary: rotary.iter().all(|r| *r),
            words: Vec::with_capacity(lb.parts.len()),
        };
        // The slots written so far: a value written twice in the block is left to the general
        // path, which stages the first until the block is written.
        let mut slots = 0u16;
        for (i, part) in lb.parts.iter().enumerate() {
            match part {
                Part::Code(c) if i == 0 => lane.code = Some(c.clone()),
                Part::Mods(_) => {}
                Part::Num(num) => {
                    let at = match num.value {
                        Value::X => 0,
                        Value::Y => 1,
                        Value::Z => 2,
                        Value::A => 3,
                        Value::B => 4,
                        Value::C => 5,
                        Value::F => 6,
                        _ => return Lane::default(),
                    };
                    if slots & (1 << num.slot) != 0 {
                        return Lane::default();
                    }
                    slots |= 1 << num.slot;
                    let f = &out.formats[num.fi as usize];
                    let decimals = [super::decimals(f, false), super::decimals(f, true)];
                    let three = ThreeDecimals::of(f);
                    lane.words.push(Word::Num(LaneNum {
                        at,
                        slot: usize::from(num.slot),
                        fi: num.fi,
                        modal: num.modal,
                        moves: !(3..5).contains(&num.slot),
                        class: num.class,
                        decimals,
                        three: decimals.map(|d| three.filter(|_| d == 3)),
                    }));
                }
                Part::Word(wi) => {
                    let mut text = Vec::new();
                    for p in &block.words[*wi].0 {
                        match p {
                            Piece::Lit(l) => text.extend_from_slice(l.as_bytes()),
                            Piece::Var { .. } => return Lane::default(),
                        }
                    }
                    // An empty word is taken back: nothing to write.
                    if !text.is_empty() {
                        let len = text.len();
                        text.resize(len + 16, 0);
                        lane.words.push(Word::Lit(text.into(), len));
                    }
                }
                Part::Code(_) => return Lane::default(),
            }
        }
        if lane.words.is_empty() {
            return Lane::default();
        }
        lane
    }
}

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// Works out [`Post::lane_ready`] after an op the general path took: bit 0 for rapids,
    /// bit 1 for feeds, set where the writer is in the steady state and the template's motion
    /// code (if it has one) is in force.
    pub(super) fn refresh_lane(&mut self) {
        let steady = self.started
            && !self.ended
            && self.pending_move.is_none()
            && self.active.is_none()
            && !self.in_cycle
            && self.pending_tool.is_none()
            && !self.speed_dirty
            && !self.length_unsaid
            && self.wcs_checked
            && self.sync.is_none()
            && self.mods.is_empty()
            && self.repeat.is_none()
            && self.out.rules.is_empty();
        self.lane_ready = 0;
        if let Some(lanes) = self.lanes.as_deref()
            && steady
        {
            for (k, lane) in lanes.iter().enumerate() {
                let in_force = lane.code.is_none() || lane.code.as_deref() == self.motion.as_deref();
                if !lane.words.is_empty() && in_force {
                    self.lane_ready |= 1 << k;
                }
            }
        }
    }

    /// [`Post::op`] for a straight move while [`Post::lane_ready`] says the steady state
    /// holds; false, having done nothing, when the move takes the general path.
    #[inline]
    pub(super) fn steady_move(&mut self, canon: &Canon) -> bool {
        let (p, k) = match &canon.op {
            CanonOp::StraightTraverse(p) => (p, 0),
            CanonOp::StraightFeed(p) => (p, 1),
            _ => return false,
        };
        if self.lane_ready & (1 << k) == 0 {
            return false;
        }
        let Some(lanes) = self.lanes.take() else { return false };
        let lane = &lanes[k];
        // A rotary axis the template does not write is said; a jump back to a line that ran
        // may start a repeated run.
        let line = canon.line;
        let new_line = line != self.line && line > 0;
        if !lane.all_rotary && (0..3).any(|r| p[3 + r].abs() > EPS && !lane.rotary[r]) || new_line && line < self.line && self.has_run(line)
        {
            self.lanes = Some(lanes);
            return false;
        }
        // From here, what the general path does for this move ([`Post::op`], [`Post::new_line`],
        // [`Post::straight`]).
        self.abc = [p[3], p[4], p[5]];
        if new_line {
            self.mark_seen(line);
            self.line_starts(line);
        }
        self.line = line;
        self.origin = canon.origin;
        let q = self.point(p);
        let feed = if k == 0 { f64::NAN } else { self.feed };
        self.lane_block(lane, &[q[0], q[1], q[2], p[3], p[4], p[5], feed, f64::NAN]);
        self.lanes = Some(lanes);
        self.moved(q);
        true
    }

    /// [`Post::render`]'s block, for `lane` with the values `xs` (X, Y, Z, A, B, C, F; NaN
    /// where absent; an eighth that no word uses).
    #[inline(always)]
    fn lane_block(&mut self, lane: &Lane, xs: &[f64; 8]) {
        let mut buf = std::mem::take(&mut self.buf);
        let start = buf.len();
        self.start_block(&mut buf, lane.raw, lane.numbered);
        let body = buf.len();
        let sep = self.out.separator.as_bytes();
        let inch = self.opts.units == Units::Inch;
        let mut moved = false;
        for w in &lane.words {
            match w {
                Word::Num(num) => moved |= self.lane_num(&mut buf, body, sep, num, xs[num.at & 7], inch, moved),
                Word::Lit(text, len) => {
                    if buf.len() > body {
                        super::append(&mut buf, sep);
                    }
                    super::append_tail(&mut buf, text, 0, *len);
                }
            }
        }
        if !moved && lane.moves {
            self.staged_mask = 0;
            buf.truncate(start);
            self.buf = buf;
            return;
        }
        // What was staged before the first word that moves (a feed written first).
        if self.staged_mask != 0 {
            self.commit_staged();
        }
        let empty = buf.len() == body;
        if empty {
            buf.truncate(start);
        }
        self.buf = buf;
        if !empty {
            self.line_end(start, lane.raw, lane.numbered);
        }
    }

    /// [`Post::put_num`] for number `num` of a lane with `x`: left out when absent or
    /// unchanged, else rounded (the rounding kept) and written after the separator; whether
    /// it moves the block. Its modal value counts as written at once when the block is sure
    /// to be written (it moves, or a word before it did: `moved`), else it is staged.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn lane_num(&mut self, buf: &mut Vec<u8>, body: usize, sep: &[u8], num: &LaneNum, x: f64, inch: bool, moved: bool) -> bool {
        // A lane's slots are X to C, 0 to 7 (the mask only spares the bounds check).
        if num.modal && self.last[num.slot & 7] == (x, num.fi) || x.is_nan() {
            return false;
        }
        let d = num.decimals[usize::from(inch)];
        let scaled = x * POW10F[d];
        let n = round_scaled(scaled);
        self.count_rounding(num.class, n, scaled, x, d);
        let key = Key { fi: num.fi, inch, n };
        if num.modal
            && let Some((w, _)) = self.written[num.slot]
            && self.same_text(w, key)
        {
            // The text written is this number's: the next time it is not rounded.
            self.set_written(num.slot, Some((key, x)));
            return false;
        }
        if num.moves || moved {
            self.set_written(num.slot, Some((key, x)));
        } else {
            self.staged[num.slot] = (key, x);
            self.staged_mask |= 1 << num.slot;
        }
        if buf.len() > body {
            super::append(buf, sep);
        }
        if !num.three[usize::from(inch)].is_some_and(|t| t.push(buf, n)) {
            push_number_in(buf, &self.out.formats[num.fi as usize], n, d);
        }
        num.moves
    }
}

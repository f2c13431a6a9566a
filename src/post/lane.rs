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
//! the text, the modal state and the findings are the general path's. The block's text is put
//! together apart, where no word needs a check of room, and appended to the buffer at once. Anything else, and
//! any move while the flag is clear, takes the general path, which stays the one place
//! every unusual case is handled.

use super::layout::{Class, Layout, LayoutBlock, Num, Part};
use super::{CanonOp, EPS, FLUSH_AT, INV_POW10, Key, POW10F, Post, ThreeDecimals, number_text, round_scaled};
use crate::canon::{ALL_KNOWN, Canon, Units};
use crate::dialect::output::{Block, NumberFormat, Output, Piece, Template, Value};

/// The most words a [`Lane`] has: one bit each in [`Lane::words_of`].
const MAX_WORDS: usize = 16;

/// In [`Lane::formats`], a slot the lane has no word for.
const NO_WORD: u32 = u32::MAX - 1;

/// The room for a block's text in [`Post::lane_text`]: a template whose longest block, with
/// 64 bytes to spare for the copies of fixed length, passes it has no lane.
pub(super) const LANE_TEXT: usize = 512;

/// Where a block's words start in [`Post::lane_text`]: what goes before them (the optional
/// block's `/`, the block number, the lead) is put right before, from the end back.
const WORDS_AT: usize = 64;

/// A move template (one block) as the steady lane writes it, made once from its
/// [`Layout`]. Empty (no words) when the template cannot be written so.
pub(super) struct Lane {
    /// The motion code that starts the block: the lane writes only while it is in force.
    pub code: Option<String>,
    /// Written without block number.
    raw: bool,
    /// Whether it is numbered ([`super::numbered`]).
    numbered: bool,
    /// The literal words the block starts with (Heidenhain's `L`), as long as they fit in 16
    /// bytes, written as a copy of a fixed 16 and taken out of [`Lane::words`], each after
    /// the separator but for the block's first word; their length.
    lead: [u8; 16],
    lead_len: usize,
    /// The length of the separator the block's first word is written with and that is left
    /// out of the block's text (none where a number or the lead comes before the words).
    drop: usize,
    /// What ends its block: the end of block (unless it is raw) and the line's end, 16 bytes
    /// at most (a template whose end is longer has no lane), written as a copy of a fixed 16;
    /// their length.
    tail: [u8; 16],
    tail_len: usize,
    /// Whether the block is left out when it moves no axis ([`super::layout::LayoutBlock::moves`]).
    moves: bool,
    /// Whether the template writes A, B, C: a move of one it does not write is said, by the
    /// general path.
    rotary: [bool; 3],
    /// Whether it writes all three (nothing to check).
    all_rotary: bool,
    /// The block's words, in order, without its motion code and the words put off to a move
    /// (none while the lane is taken), then empty text up to [`MAX_WORDS`] (a word's index
    /// needs no check): as a millimetre and as an inch program writes them. How many there are.
    words: [[Word; MAX_WORDS]; 2],
    len: usize,
    /// For each modal slot X to C, the format of the lane's word, or [`NO_WORD`].
    formats: [u32; 8],
    /// The slots of the words left out when unchanged (one bit each).
    modal: u8,
    /// For each set of slots whose number is the one written last (bit k: slot k), the words
    /// the block may write (bit j: word j): all but the modal words of those slots. A block
    /// goes through those alone.
    words_of: Box<[u16; 256]>,
}

impl Default for Lane {
    /// The empty lane, never taken.
    fn default() -> Lane {
        Lane {
            code: None,
            raw: false,
            numbered: false,
            lead: [0; 16],
            lead_len: 0,
            drop: 0,
            tail: [0; 16],
            tail_len: 0,
            moves: false,
            rotary: [false; 3],
            all_rotary: false,
            words: [(); 2].map(|_| std::array::from_fn(|_| Word::Lit(Box::default(), 0, 0))),
            len: 0,
            formats: [NO_WORD; 8],
            modal: 0,
            words_of: Box::new([0; 256]),
        }
    }
}

/// One word of a [`Lane`].
enum Word {
    /// Text written as it is (Heidenhain's `L`, `FMAX`): the separator and the text, with at
    /// least 16 bytes after them (zeros) for a copy of a fixed 16 taken back to its length;
    /// where the text starts (after the separator) and where it ends.
    Lit(Box<[u8]>, usize, usize),
    /// A number.
    Num(LaneNum),
}

/// A number placeholder of a [`Lane`], with what the general path works out for it at every
/// block ([`super::layout::Num`], its [`crate::dialect::output::NumberFormat`] in the units
/// of the program) worked out once.
#[derive(Clone, Copy)]
struct LaneNum {
    /// The modal slot ([`super::modal_slot`]), which is also the index of its value in
    /// [`Post::lane_block`]'s list.
    slot: usize,
    /// Its number format.
    fi: u32,
    /// Left out when its text is unchanged.
    modal: bool,
    /// Whether writing it moves the block (not the feed).
    moves: bool,
    /// What its rounding counts towards.
    class: Class,
    /// The decimals the format writes ([`super::decimals`]).
    decimals: usize,
    /// 10 to the power of that, and its inverse.
    scale: f64,
    inv: f64,
    /// The format as [`ThreeDecimals`] with the separator before it (every word of a lane is
    /// written after it, [`Lane::drop`]), where it writes three decimals after a short address
    /// (the usual format); else the number goes by [`number_text`].
    three: Option<ThreeDecimals>,
}

impl Lane {
    /// The lanes of the `rapid` and `feed` templates of `out` ([`Lane::of`]). Where the two
    /// write a value in formats of their own, neither is taken: a block of either finds the
    /// number written last in its own format ([`Post::refresh_lane`]).
    pub(super) fn pair(out: &Output) -> Box<[Lane; 2]> {
        let lanes = [Lane::of(out.template("rapid").map(|(t, _)| t), out), Lane::of(out.template("feed").map(|(t, _)| t), out)];
        let [r, f] = &lanes;
        if r.formats.iter().zip(&f.formats).any(|(a, b)| *a != NO_WORD && *b != NO_WORD && a != b) {
            return Box::default();
        }
        Box::new(lanes)
    }

    /// The lane of move template `t`, if it has one block whose words are a motion code,
    /// the words put off to a move, literal text and numbers of the values a straight move
    /// sets, [`MAX_WORDS`] at most; otherwise an empty lane (never taken).
    fn of(t: Option<&Template>, out: &Output) -> Lane {
        t.and_then(|t| Lane::of_template(t, out)).unwrap_or_default()
    }

    /// [`Lane::of`] a template; none where it has no lane.
    fn of_template(t: &Template, out: &Output) -> Option<Lane> {
        let [block] = t.0.as_slice() else { return None };
        let layout = Layout::of(t, out, true);
        let [lb] = layout.0.as_slice() else { return None };
        let rotary = [Value::A, Value::B, Value::C].map(|v| t.uses(v));
        let sep = out.separator.as_bytes();
        let BlockWords { code, mut words, formats, modal, longest } = BlockWords::of(block, lb, out)?;
        // Room for what goes before the words: the block number (20 digits at most) and the
        // lead, and the `/` before them.
        if words[0].is_empty()
            || words[0].len() > MAX_WORDS
            || longest + 64 + WORDS_AT > LANE_TEXT
            || 1 + out.number_address.len() + 20 + 16 > WORDS_AT
        {
            return None;
        }
        let numbered = super::numbered(out, lb.raw, false);
        let (lead, lead_len) = take_lead(&mut words, numbered)?;
        let drop = if numbered || lead_len > 0 { 0 } else { sep.len() };
        let len = words[0].len();
        let mut tail = if lb.raw { Vec::new() } else { out.end_of_block.as_bytes().to_vec() };
        tail.push(b'\n');
        let tail_len = tail.len();
        // A longer end of block gets no lane: `resize` would cut it short.
        if tail_len > 16 {
            return None;
        }
        tail.resize(16, 0);
        let Ok(tail) = <[u8; 16]>::try_from(tail) else { return None };
        let words_of = words_by_unchanged(&words[0]);
        Some(Lane {
            code,
            raw: lb.raw,
            numbered,
            lead,
            lead_len,
            drop,
            tail,
            tail_len,
            moves: lb.moves,
            rotary,
            all_rotary: rotary.iter().all(|r| *r),
            words: words.map(|words| {
                let mut words = words.into_iter();
                std::array::from_fn(|_| words.next().unwrap_or(Word::Lit(Box::default(), 0, 0)))
            }),
            len,
            formats,
            modal,
            words_of,
        })
    }
}

/// The words of a move template's one block as a [`Lane`] writes them ([`BlockWords::of`]).
struct BlockWords {
    /// The motion code the block starts with.
    code: Option<String>,
    /// Its words but the motion code and the words put off to a move, as a millimetre and as
    /// an inch program writes them.
    words: [Vec<Word>; 2],
    /// For each modal slot X to C, the format of its word, or [`NO_WORD`].
    formats: [u32; 8],
    /// The slots of the words left out when unchanged (one bit each).
    modal: u8,
    /// The longest text of the block.
    longest: usize,
}

impl BlockWords {
    /// The words of `block`, laid out as `lb`, if each is the motion code that starts it,
    /// the words put off to a move, literal text, or a number of a value a straight move
    /// sets, each value once.
    fn of(block: &Block, lb: &LayoutBlock, out: &Output) -> Option<BlockWords> {
        let sep = out.separator.as_bytes();
        let mut code = None;
        let mut words = [Vec::with_capacity(lb.parts.len()), Vec::with_capacity(lb.parts.len())];
        let mut formats = [NO_WORD; 8];
        let mut modal = 0u8;
        // The longest text of the block: the optional block's `/`, the block number (20
        // digits at most) and the separator after it, the words, the end of block and the
        // line's end.
        let mut longest = 1 + out.number_address.len() + 20 + sep.len() + out.end_of_block.len() + 1;
        for (i, part) in lb.parts.iter().enumerate() {
            match part {
                Part::Code(c) if i == 0 => code = Some(c.clone()),
                Part::Mods(_) => {}
                Part::Num(num) => {
                    if !matches!(num.value, Value::X | Value::Y | Value::Z | Value::A | Value::B | Value::C | Value::F) {
                        return None;
                    }
                    let slot = usize::from(num.slot);
                    // A value written twice in the block is left to the general path, which
                    // stages the first until the block is written.
                    if formats[slot] != NO_WORD {
                        return None;
                    }
                    formats[slot] = num.fi;
                    if num.modal {
                        modal |= 1 << slot;
                    }
                    let f = &out.formats[num.fi as usize];
                    // The separator, the address, a sign, 20 digits, the point and 15
                    // decimals at most ([`number_text`]).
                    longest += sep.len() + f.address.len() + 37;
                    let three = ThreeDecimals::after(f, sep);
                    for (inch, words) in words.iter_mut().enumerate() {
                        words.push(Word::Num(LaneNum::of(num, f, three, inch == 1)));
                    }
                }
                Part::Word(wi) => {
                    let mut text = sep.to_vec();
                    for p in &block.words[*wi].0 {
                        match p {
                            Piece::Lit(l) => text.extend_from_slice(l.as_bytes()),
                            Piece::Var { .. } => return None,
                        }
                    }
                    // An empty word is taken back: nothing to write.
                    if text.len() > sep.len() {
                        let end = text.len();
                        longest += end;
                        text.resize(end + 16, 0);
                        for words in &mut words {
                            words.push(Word::Lit(text.clone().into(), sep.len(), end));
                        }
                    }
                }
                Part::Code(_) => return None,
            }
        }
        Some(BlockWords { code, words, formats, modal, longest })
    }
}

impl LaneNum {
    /// Number placeholder `num` in format `f` (as [`ThreeDecimals`] after the separator:
    /// `three`), as an inch program (`inch`) or a millimetre one writes it.
    fn of(num: &Num, f: &NumberFormat, three: Option<ThreeDecimals>, inch: bool) -> LaneNum {
        let slot = usize::from(num.slot);
        let decimals = super::decimals(f, inch);
        LaneNum {
            slot,
            fi: num.fi,
            modal: num.modal,
            moves: !(3..5).contains(&slot),
            class: num.class,
            decimals,
            scale: POW10F[decimals],
            inv: INV_POW10[decimals],
            three: three.filter(|_| decimals == 3),
        }
    }
}

/// The lead of a lane ([`Lane::lead`]) whose words are `words`, taken out of them: as a
/// fixed 16 bytes, and its length. The block's first word is written without the separator
/// before it where the block is not `numbered`.
fn take_lead(words: &mut [Vec<Word>; 2], numbered: bool) -> Option<([u8; 16], usize)> {
    // The literal words the block starts with go into its lead, while it is short.
    let mut lead = Vec::new();
    while let Some(Word::Lit(text, at, end)) = words[0].first() {
        let from = if lead.is_empty() && !numbered { *at } else { 0 };
        if lead.len() + end - from > 16 {
            break;
        }
        lead.extend_from_slice(&text[from..*end]);
        for words in &mut *words {
            words.remove(0);
        }
    }
    let lead_len = lead.len();
    lead.resize(16, 0);
    let Ok(lead) = <[u8; 16]>::try_from(lead) else { return None };
    Some((lead, lead_len))
}

/// [`Lane::words_of`] for the lane's `words`: for each set of slots whose number is the one
/// written last, the words but the modal ones of those slots.
fn words_by_unchanged(words: &[Word]) -> Box<[u16; 256]> {
    let mut words_of = Box::new([0u16; 256]);
    for (same, written) in words_of.iter_mut().enumerate() {
        for (j, w) in words.iter().enumerate() {
            if !matches!(w, Word::Num(num) if num.modal && same & (1 << num.slot) != 0) {
                *written |= 1 << j;
            }
        }
    }
    words_of
}

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// Works out [`Post::lane_ready`] after an op the general path took: bit 0 for rapids,
    /// bit 1 for feeds, set where the writer is in the steady state, the template's motion
    /// code (if it has one) is in force, and the numbers written last of the lane's modal
    /// words are in the words' formats (or none is): a block then tells an unchanged word by
    /// its number alone ([`Post::lane_block`]). The lanes keep it so: their words write
    /// each value in one format ([`Lane::pair`]).
    pub(super) fn refresh_lane(&mut self, lanes: &[Lane; 2]) {
        let steady = self.started
            && !self.ended
            && self.pending_move.is_none()
            && self.held.is_empty()
            && self.machine.is_none()
            && self.active.is_none()
            && !self.in_cycle
            && self.pending_tool.is_none()
            && !self.speed_dirty
            && !self.length_unsaid
            && self.wcs_checked
            && self.sync.is_none()
            && self.axis_check.is_none()
            && self.mods.is_empty()
            && self.repeat.is_none()
            && !self.x_diam
            && self.out.rules.is_empty();
        self.lane_ready = 0;
        if steady {
            for (k, lane) in lanes.iter().enumerate() {
                let in_force = lane.code.is_none() || lane.code.as_deref() == self.motion.as_deref();
                let formats = (0..8).all(|s| lane.modal & (1 << s) == 0 || [lane.formats[s], u32::MAX].contains(&self.last_fi[s]));
                if lane.len > 0 && in_force && formats {
                    self.lane_ready |= 1 << k;
                }
            }
        }
    }

    /// [`Post::op`] for a straight move while [`Post::lane_ready`] says the steady state
    /// holds, by its lane of `lanes`; false, having done nothing, when the move takes the
    /// general path.
    #[inline(always)]
    pub(super) fn steady_move(&mut self, lanes: &[Lane; 2], canon: &Canon) -> bool {
        let (p, k) = match &canon.op {
            CanonOp::StraightTraverse(p) => (p, 0),
            CanonOp::StraightFeed(p) => (p, 1),
            _ => return false,
        };
        if self.lane_ready & (1 << k) == 0 {
            return false;
        }
        let lane = &lanes[k];
        // A rotary axis the template does not write is said; a jump back to a line that ran
        // may start a repeated run.
        let line = canon.line;
        let new_line = line != self.line && line > 0;
        if !lane.all_rotary && (0..3).any(|r| p[3 + r].abs() > EPS && !lane.rotary[r]) || new_line && line < self.line && self.has_run(line)
        {
            return false;
        }
        let q = self.point(p);
        // An axis whose position the source does not know that moves: the general way, which
        // refuses it (`Post::check_unknown`).
        let known = self.known;
        if known != ALL_KNOWN
            && ((0..3).any(|k| known & 1 << k == 0 && (q[k] - self.pos[k]).abs() > EPS)
                || (0..3).any(|r| known & 8 << r == 0 && (p[3 + r] - self.abc[r]).abs() > EPS))
        {
            return false;
        }
        // From here, what the general path does for this move ([`Post::op`], [`Post::new_line`],
        // [`Post::straight`]).
        self.abc = [p[3], p[4], p[5]];
        if new_line {
            self.mark_seen(line);
            self.line_starts(line, self.block);
        }
        self.line = line;
        self.origin = canon.origin;
        let feed = if k == 0 { f64::NAN } else { self.feed };
        let mut xs = [q[0], q[1], q[2], feed, f64::NAN, p[3], p[4], p[5]];
        if known != ALL_KNOWN {
            // Never a word of an axis whose position is unknown (NaN: absent).
            for (k, slot) in [0, 1, 2, 5, 6, 7].into_iter().enumerate() {
                if known & 1 << k == 0 {
                    xs[slot] = f64::NAN;
                }
            }
        }
        self.lane_block(lane, &xs);
        self.moved(q);
        true
    }

    /// [`Post::render`]'s block, for `lane` with the values `xs` by modal slot (X, Y, Z, F,
    /// S, A, B, C; NaN where absent, as S always is). The block's text is put together in
    /// [`Post::lane_text`] (from its start, with no check of room: the lane's longest block
    /// fits, [`LANE_TEXT`]) and appended to the buffer at once when it is written.
    #[inline(always)]
    fn lane_block(&mut self, lane: &Lane, xs: &[f64; 8]) {
        // The slots whose number is the one written last: with the formats kept
        // ([`Post::refresh_lane`]), their modal words are left out unchanged
        // ([`Post::unchanged`]). Only the slots of the lane's modal words matter
        // ([`Lane::words_of`]): X, Y, Z and F, and A, B, C where it has one of them (S is
        // never written by a move, its value NaN).
        let last = &self.last;
        let mut same = usize::from(xs[0] == last[0])
            | usize::from(xs[1] == last[1]) << 1
            | usize::from(xs[2] == last[2]) << 2
            | usize::from(xs[3] == last[3]) << 3;
        if lane.modal & 0xe0 != 0 {
            same |= usize::from(xs[5] == last[5]) << 5 | usize::from(xs[6] == last[6]) << 6 | usize::from(xs[7] == last[7]) << 7;
        }
        let mut todo = lane.words_of[same];
        // The block number and the lead, before the words.
        let head = if lane.numbered || lane.lead_len > 0 { self.lane_head(lane) } else { 0 };
        let mut at = WORDS_AT;
        let inch = self.opts.units == Units::Inch;
        let words = &lane.words[usize::from(inch)];
        let mut moved = false;
        while todo != 0 {
            let j = todo.trailing_zeros() as usize % MAX_WORDS;
            todo &= todo - 1;
            match &words[j] {
                Word::Num(num) => {
                    if let Some(end) = self.lane_num(at, num, xs[num.slot & 7], inch, moved) {
                        at = end;
                        moved |= num.moves;
                    }
                }
                Word::Lit(text, _, end) => at = self.lane_put_tail(at, text, 0, *end),
            }
        }
        if !moved && lane.moves {
            self.staged_mask = 0;
            return;
        }
        // What was staged before the first word that moves (a feed written first).
        if self.staged_mask != 0 {
            self.commit_staged();
        }
        if at > WORDS_AT || lane.lead_len > 0 {
            // The first word's separator left out where nothing comes before it; the
            // optional block's `/` before all.
            let mut start = WORDS_AT + lane.drop - head;
            if !lane.raw && self.optional_line == Some(self.line) {
                start -= 1;
                self.lane_text[start] = b'/';
            }
            self.lane_end(start, at, lane);
        }
    }

    /// [`Post::start_block`] in [`Post::lane_text`] for `lane`, but for the `/`: its block
    /// number where it is numbered, and its lead ([`Lane::lead`]), ending at [`WORDS_AT`];
    /// their length.
    #[inline(always)]
    fn lane_head(&mut self, lane: &Lane) -> usize {
        let mut len = lane.lead_len;
        if lane.numbered {
            let address = self.out.number_address.as_bytes();
            let digits = self.block_digits();
            len += address.len() + digits;
            let at = self.lane_put(WORDS_AT - len, address);
            let (text, number) = (&mut self.lane_text, &self.number_text.0);
            text[at..at + 16].copy_from_slice(&number[..16]);
            if digits > 16 {
                text[at + 16..at + digits].copy_from_slice(&number[16..digits]);
            }
        }
        if lane.lead_len > 0 {
            let at = WORDS_AT - lane.lead_len;
            self.lane_text[at..at + 16].copy_from_slice(&lane.lead);
        }
        len
    }

    /// [`Post::line_end`] for the block from `start` to `at` in [`Post::lane_text`] by
    /// `lane`, which it appends to the buffer: one copy, of a fixed 32 or 64 bytes taken back
    /// to its length where it is no longer.
    #[inline(always)]
    fn lane_end(&mut self, start: usize, at: usize, lane: &Lane) {
        if lane.numbered {
            self.block += self.out.number_step;
        }
        // The line's length, without its end.
        let line = at - start + lane.tail_len - 1;
        if line > self.max_line {
            self.line_too_long(line);
        }
        self.lane_text[at..at + 16].copy_from_slice(&lane.tail);
        let len = at + lane.tail_len - start;
        let was = self.buf.len();
        if len <= 32 {
            self.buf.extend_from_slice(&self.lane_text[start..start + 32]);
            self.buf.truncate(was + len);
        } else if len <= 64 {
            self.buf.extend_from_slice(&self.lane_text[start..start + 64]);
            self.buf.truncate(was + len);
        } else {
            self.buf.extend_from_slice(&self.lane_text[start..start + len]);
        }
        if self.buf.len() >= FLUSH_AT {
            self.hand_over();
        }
    }

    /// Puts `s` in [`Post::lane_text`] at `at`; where it ends. A single byte (a separator)
    /// or nothing without a call to copy.
    #[inline(always)]
    fn lane_put(&mut self, at: usize, s: &[u8]) -> usize {
        match s {
            [] => {}
            [c] => self.lane_text[at] = *c,
            _ => self.lane_text[at..at + s.len()].copy_from_slice(s),
        }
        at + s.len()
    }

    /// Puts `b[i..end]` in [`Post::lane_text`] at `at`, as a copy of a fixed 16 where it is
    /// no longer (`b` has 16 bytes after `end`, [`super::append_tail`]); where it ends.
    #[inline(always)]
    fn lane_put_tail(&mut self, at: usize, b: &[u8], i: usize, end: usize) -> usize {
        let len = end - i;
        if len <= 16 {
            self.lane_text[at..at + 16].copy_from_slice(&b[i..i + 16]);
        } else {
            self.lane_text[at..at + len].copy_from_slice(&b[i..end]);
        }
        at + len
    }

    /// [`Post::put_num`] for number `num` of a lane with `x`, not left out unchanged: left out
    /// when absent or when its text is the one written, else rounded (the rounding kept) and
    /// put in [`Post::lane_text`] at `at`, after the separator; where it ends, or none when it
    /// is left out. Its modal value counts as
    /// written at once when the block is sure to be written (it moves, or a word before it
    /// did: `moved`), else it is staged.
    #[inline(always)]
    fn lane_num(&mut self, at: usize, num: &LaneNum, x: f64, inch: bool, moved: bool) -> Option<usize> {
        if x.is_nan() {
            return None;
        }
        let d = num.decimals;
        let scaled = x * num.scale;
        let n = round_scaled(scaled);
        self.count_rounding(num.class, n, scaled, x, d, num.inv);
        let key = Key { fi: num.fi, inch, n };
        let k = num.slot & 7;
        if num.modal
            && let Some((w, _)) = &self.written[k]
            && self.same_text(*w, key)
        {
            // The text written is this number's: the next time it is not rounded.
            self.lane_written(k, key, x);
            return None;
        }
        if num.moves || moved {
            self.lane_written(k, key, x);
        } else {
            self.staged[k] = (key, x);
            self.staged_mask |= 1 << k;
        }
        if let Some(t) = &num.three
            && let Some((prefix, plen, digits, dlen)) = t.parts(n)
        {
            self.lane_text[at..at + 8].copy_from_slice(&prefix.to_le_bytes());
            self.lane_text[at + plen..at + plen + 8].copy_from_slice(&digits.to_le_bytes());
            return Some(at + plen + dlen);
        }
        let out = self.out;
        let mut at = self.lane_put(at, out.separator.as_bytes());
        let f = &out.formats[num.fi as usize];
        if f.address.len() > 8 {
            at = self.lane_put(at, f.address.as_bytes());
        }
        let mut b = [0u8; 64];
        let i = number_text(&mut b, f, n, d);
        Some(self.lane_put_tail(at, &b, i, 48))
    }

    /// [`Post::set_written`] of slot `k` with `key` in the units of the program (as a lane's
    /// keys are): its number and format are the ones written last at once.
    #[inline(always)]
    fn lane_written(&mut self, k: usize, key: Key, x: f64) {
        self.written[k] = Some((key, x));
        self.last[k] = x;
        self.last_fi[k] = key.fi;
    }
}

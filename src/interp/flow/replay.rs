//! The replay lane: the blocks of a loop or called body, kept lexed (`Driver::kept`), run
//! one after another without the driver's general loop (`Driver::drive`).
//!
//! When a block is kept, its lane is decided once ([`lane`]): a block the interpreter runs
//! (assignments, a move, any codes), a control statement the driver carries out, or neither
//! (a `%` line, a program number: what the general loop's look at the main program must
//! see). The lane then runs kept block after kept block, each found from the one before
//! (`Lexed::after`), and does for each exactly what `drive` does for a kept block, without
//! the questions whose answer a replay knows already: no plain lane, no lexing, no findings
//! of the lexer, no definition block, no `%` line. What a block may change (a return to a
//! caller, a way chosen on an unknown value, a section repeat, a budget reached, a stop) ends
//! the lane before the next block, which then goes the general way. Nothing else differs:
//! the blocks run by the same functions (`Interpreter::execute`, `Driver::control`) with the
//! same counts, so the canonical text and the findings are the same (the corpus test
//! `fast_lane_changes_nothing` and `replay_lane_changes_nothing` in `tests/it`).

use super::{Driver, FrameKind, Interpreter, Pos};
use crate::canon::CanonSink;
use crate::diag::Diagnostic;
use crate::syntax::Block;

/// How the replay lane runs a kept block.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Lane {
    /// Not on the lane: the general loop runs it.
    Off,
    /// A block without a control statement: the interpreter runs it.
    Execute,
    /// A control statement: the driver carries it out.
    Control,
}

/// The lane of a block about to be kept: off for what the general loop's look at the main
/// program must see (a `%` line, a program number).
pub(super) fn lane(block: &Block) -> Lane {
    if block.delimiter || block.program_number.is_some() {
        Lane::Off
    } else if block.control.is_some() {
        Lane::Control
    } else {
        Lane::Execute
    }
}

impl<'a> Driver<'a, '_> {
    /// Runs kept blocks from the cursor on, while the run replays and each block is kept and
    /// on the lane; true when it ran any. Only where `drive` would have taken them from the
    /// cache (`Driver::next_block`) and run them as they are.
    #[inline(never)]
    pub(super) fn replay(
        &mut self,
        block: &mut Box<Block>,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) -> bool {
        // What no block on the lane changes: asked once.
        if !self.profile.fast_lane || !self.profile.replay_lane || self.dialect.macros.definition_block.is_some() {
            return false;
        }
        let profile = self.profile;
        let mut ran = false;
        // Where the next block starts: the parser is sought there only where something reads
        // it (a control statement, a call, the general loop after the lane).
        let mut at = Pos { at: self.parser.offset(), line: self.parser.line() };
        loop {
            // What a block may change, asked before the next: the general loop's questions.
            if interp.left_level.is_some()
                || interp.finished()
                || self.stop
                || self.guess_merge.is_some()
                || self.definition.is_some()
                || self.frames.last().is_some_and(|f| f.kind == FrameKind::Section)
                || (!self.main_work && self.cur == 0 && self.frames.is_empty())
            {
                break;
            }
            let (start, src) = (at, self.cur);
            self.give_back(block);
            let Some((k, linked)) = self.peek_kept((src, start.at)) else { break };
            let l = &self.kept[k as usize];
            let (next, lane) = (l.next, l.lane);
            match lane {
                Lane::Off => break,
                Lane::Control if !self.broken_blocks.is_empty() && self.broken_blocks.contains(&(src, start.at)) => break,
                _ => {}
            }
            // The budgets, as `over_budget` counts them for this block: one reached, the
            // general loop takes the block and says so.
            if self.repeated >= profile.max_repeated_blocks || self.executed >= profile.max_blocks {
                break;
            }
            if profile.max_repeated_bytes != u64::MAX {
                let kept = sink.kept_bytes(interp.motions);
                if kept.saturating_sub(*self.replay_kept.get_or_insert(kept)) > profile.max_repeated_bytes {
                    break;
                }
            }
            // As `next_block` takes a kept block and `drive` counts it.
            self.take_kept(k, linked);
            self.repeated += 1;
            self.executed += 1;
            // A kept control block is not broken (asked above); any other is not either.
            self.broken = false;
            let mark = diags.len();
            at = next;
            if lane == Lane::Control {
                self.lend_kept(block, k, next);
                self.run_block(block, start, interp, sink, diags);
                at = Pos { at: self.parser.offset(), line: self.parser.line() };
            } else {
                // Read where it is kept: the interpreter's block is not lent for its run.
                interp.execute(&self.kept[k as usize].block, sink, diags);
                if let Some(r) = interp.request.take() {
                    self.lend_kept(block, k, next);
                    self.request(r, block, interp, sink, diags);
                    at = Pos { at: self.parser.offset(), line: self.parser.line() };
                }
            }
            self.tidy(src, mark, diags);
            ran = true;
        }
        self.parser.seek(at.at, at.line);
        ran
    }

    /// Lends kept block `k` to `block` for its run, and seeks the parser to the block after
    /// it (`next`), as `next_block` does for a block the general loop runs.
    #[inline(always)]
    fn lend_kept(&mut self, block: &mut Box<Block>, k: u32, next: Pos) {
        let l = &mut self.kept[k as usize];
        std::mem::swap(block, &mut l.block);
        l.lent = true;
        self.lent = Some(k);
        self.parser.seek(next.at, next.line);
    }
}

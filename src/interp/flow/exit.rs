//! A loop's exit on a value the analysis does not know.
//!
//! A loop written with a jump back (`DOSKOK:` … `GOTOB DOSKOK`, Fanuc `N10` … `GOTO 10`,
//! Heidenhain `LBL 1` … `FN 9: IF +0 EQU +0 GOTO LBL 1`) or as `LOOP` … `ENDLOOP` ends only
//! by a jump forward past its end. Where that jump's condition reads the control's data
//! (`IF (IndeksFaze>=MaxFaza) GOTOF KRAJ` on a global the machine's data sets), the control
//! leaves the loop when the data says so; the analysis does not know when. Taking the
//! condition as false runs the loop until the analysis bound (a grinder's infeed summed
//! round after round to depths no part has): a run that ends leaves its loops, so the exit
//! is taken once the loop's body has run one whole pass, that is once the loop has come round
//! since the exit was first declined in this entry of the loop (Sinumerik 840D programming manual,
//! "Program jumps to jump markers": `GOTOB`/`GOTOF`/`GOTO` with `IF`; a loop is the
//! program's own jump back, repeated until the condition holds). The diagnostic says the
//! pass is an assumption.

use super::{Driver, LoopKind, Pos, constant};
use crate::dialect::Statement;
use crate::interp::Interpreter;
use crate::interp::eval;
use crate::syntax::Block;

/// How many blocks [`Driver::loop_exit`] reads between a jump and its target.
const EXIT_SCAN: usize = 4096;

/// A jump forward that leaves the loop it stands in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) struct LoopExit {
    /// The exit: source, offset after the jump, target offset (the key of the pass it waits for).
    key: (usize, usize, usize),
    /// What counts the loop's rounds: its jump back (source, target offset), or none for a
    /// `LOOP` … `ENDLOOP` (the open loop's count).
    back: Option<(usize, usize)>,
}

impl<'a> Driver<'a, '_> {
    /// Whether the forward jump of the block that ends at `here`, to `target`, leaves a loop
    /// it stands in: between them lies a jump back without condition (or on a constant one)
    /// to `here` or before it, or the end of the innermost open `LOOP`. Read once per jump
    /// and target.
    pub(super) fn loop_exit(&mut self, here: Pos, target: Pos, interp: &mut Interpreter<'a>) -> Option<LoopExit> {
        if target.at <= here.at {
            return None;
        }
        let key = (self.cur, here.at, target.at);
        if let Some(&found) = self.exits.get(&key) {
            return found;
        }
        let found = self.scan_exit(here, target, interp);
        self.exits.insert(key, found);
        found
    }

    fn scan_exit(&mut self, here: Pos, target: Pos, interp: &mut Interpreter<'a>) -> Option<LoopExit> {
        let forever = self
            .top_loop(|_| true)
            .filter(|&k| self.loops[k].kind == LoopKind::Forever && self.loops[k].source == self.cur)
            .map(|k| self.loops[k].body);
        let mut p = self.parser.fork(self.sources[self.cur].text, here.at, here.line);
        let (mut b, mut scratch) = (Block::default(), Vec::new());
        // `LOOP`s opened after `here` and not yet closed.
        let mut depth = 0u32;
        let mut found = None;
        for _ in 0..EXIT_SCAN {
            if p.offset() >= target.at || !p.next_block(&mut b, &mut scratch) {
                break;
            }
            scratch.clear();
            let at = Pos { at: p.offset(), line: p.line() };
            let Some(c) = b.control.clone() else { continue };
            match c.statement {
                Some(Statement::Loop) => depth += 1,
                Some(Statement::EndLoop) if depth == 0 => {
                    found = forever.map(|_| LoopExit { key: (self.cur, here.at, target.at), back: None }).or(found);
                }
                Some(Statement::EndLoop) => depth -= 1,
                Some(st) => {
                    let jump = matches!(
                        c.then,
                        Some(Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet | Statement::GotoLabel)
                    );
                    let always = match st {
                        Statement::Goto | Statement::GotoBack | Statement::GotoLabel => true,
                        // `FN 9: IF +0 EQU +0 GOTO LBL 1`: a jump whatever the values.
                        Statement::If if jump => c.args.first().is_some_and(|&e| {
                            constant(&b, e) && interp.eval(&b, e, b.range, &mut scratch).is_ok_and(|v| !eval::is_null(v) && v != 0.0)
                        }),
                        _ => false,
                    };
                    scratch.clear();
                    if !always {
                        continue;
                    }
                    if let Some(t) = self.jump_target_from(&c, &b, interp, at)
                        && t.at < here.at
                    {
                        found = Some(LoopExit { key: (self.cur, here.at, target.at), back: Some((self.cur, t.at)) });
                    }
                }
                None => {}
            }
        }
        found
    }

    /// How many times the loop `exit` leaves has come round.
    pub(super) fn exit_rounds(&self, exit: LoopExit) -> u64 {
        match exit.back {
            Some(key) => self.back_jumps.get(&key).copied().unwrap_or(0),
            None => self.top_loop(|_| true).map_or(0, |k| self.loops[k].iterations),
        }
    }

    /// Whether an exit on an unknown condition is taken now: once the loop has come round
    /// since the exit was first declined, so that its whole body (before and after the exit)
    /// has run one pass. The round count is kept per exit and forgotten when the exit is taken,
    /// so each entry into the loop (an outer loop's next round, the subprogram called again)
    /// runs its pass. A count that moved on by more than one round (the loop was left another
    /// way and entered again) starts a new wait.
    pub(super) fn exit_now(&mut self, exit: LoopExit) -> bool {
        let rounds = self.exit_rounds(exit);
        match self.exit_waits.get(&exit.key) {
            Some(&declined) if rounds == declined + 1 => {
                self.exit_waits.remove(&exit.key);
                true
            }
            _ => {
                self.exit_waits.insert(exit.key, rounds);
                false
            }
        }
    }
}

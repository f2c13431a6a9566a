//! The nesting of control structures, read over every block of a program before it runs,
//! where the dictionary says its control checks it (`checks-nesting`).
//!
//! Sinumerik keeps the control structures it has entered (`IF` … `ELSE` … `ENDIF`, `WHILE` …
//! `ENDWHILE`, `FOR` … `ENDFOR`, `REPEAT` … `UNTIL`, `LOOP` … `ENDLOOP`) and stops with alarm
//! 12640 (invalid nesting of control structures) at an end with no structure of its kind open,
//! and where a structure is left open (SINUMERIK 840D sl programming manual, job planning,
//! "Control structures": the structures must be nested properly; a program that mixes them
//! with jumps is not checked completely while it runs, a precompiled cycle is). Every block is
//! read, not only those the run takes: a stray `ENDIF` after a call in a loop, or an `IF`
//! whose `ENDIF` was never written, is an error wherever it lies.

use super::block_if;
use crate::diag::{Code, Diagnostic};
use crate::dialect::{Dialect, Statement};
use crate::syntax::{Block, Control, Parser};
use crate::text::{Text, TextRange};

/// Most structures kept open: deeper nesting is not followed (the control's limit is lower).
const MAX_OPEN: usize = 256;

/// What a finding says the control does, where the run meets the statement.
pub(super) const STOP: &str = "the control checks the nesting of its control structures and stops with an alarm (invalid nesting)";

/// What it says instead where the run does not reach the statement: the 840D sl checks the
/// block structure in interpreter mode only as it runs (job planning, Arbeitsvorbereitung
/// 02/2011, p.107).
pub(super) const UNREACHED: &str = "no run reaches this block (it follows a jump without condition, before the next label), and in interpreter mode the control checks the block structure only where it runs: an alarm (invalid nesting) only if the control comes here";

/// The structure a statement opens, by the statement that closes it.
fn closer_of(st: Statement) -> Option<Statement> {
    match st {
        Statement::If => Some(Statement::EndIf),
        Statement::While => Some(Statement::EndWhile),
        Statement::For => Some(Statement::EndFor),
        Statement::RepeatUntil => Some(Statement::Until),
        Statement::Loop => Some(Statement::EndLoop),
        _ => None,
    }
}

/// Whether an `IF` opens a block: nothing follows its condition (`IF GRIND[0]<>1`), or `THEN`
/// alone.
fn opens_block(block: &Block, c: &Control, dialect: &Dialect) -> bool {
    match c.then {
        Some(Statement::Then) => block_if(block, c, dialect),
        None => !dialect.macros.if_then_optional || (block.words.is_empty() && block.assigns.is_empty()),
        _ => false,
    }
}

/// The keyword a structure's end is written with, for a message.
fn end_word(st: Statement) -> &'static str {
    match st {
        Statement::EndIf => "ENDIF",
        Statement::EndWhile => "ENDWHILE",
        Statement::EndFor => "ENDFOR",
        Statement::Until => "UNTIL",
        _ => "ENDLOOP",
    }
}

/// The finding of a program's control-structure nesting where the control stops: the first
/// end with no structure open, end of another structure than the one open or `ELSE` outside
/// an `IF`; else the outermost structure left open at the end of the text. Nothing where the dictionary does not check.
pub(super) fn check(text: Text<'_>, dialect: &Dialect) -> Vec<(Diagnostic, bool)> {
    if !dialect.macros.checks_nesting {
        return Vec::new();
    }
    let mut parser = Parser::new(text, dialect);
    let (mut block, mut scratch) = (Block::default(), Vec::new());
    // The structures open: (the statement that closes it, the opening statement's range).
    let mut open: Vec<(Statement, TextRange)> = Vec::new();
    let mut out = Vec::new();
    let stop = STOP;
    // Structures opened past `MAX_OPEN` deep: not recorded, but counted, so that their ends
    // close them (of whatever kind) and not the recorded ones below.
    let mut deep = 0usize;
    // Whether the block lies after a jump without condition and before the next label: the
    // run cannot reach it (a fault there is a warning, see `UNREACHED`).
    let mut dead = false;
    while parser.next_block(&mut block, &mut scratch) {
        scratch.clear();
        if block.label.is_some() {
            dead = false;
        }
        let Some(c) = block.control.as_ref() else { continue };
        let Some(st) = c.statement else { continue };
        let here_dead = dead;
        if c.then.is_none()
            && matches!(st, Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet | Statement::GotoLabel)
        {
            dead = true;
        }
        let closes = match st {
            // A block `IF` (its body the lines after it, up to `ELSE`/`ENDIF`), not one that
            // jumps or runs the statement after its condition.
            Statement::If if !opens_block(&block, c, dialect) => None,
            Statement::If | Statement::While | Statement::For | Statement::RepeatUntil | Statement::Loop => {
                if open.len() < MAX_OPEN {
                    open.push((closer_of(st).unwrap_or(Statement::EndIf), c.range));
                } else {
                    deep += 1;
                }
                continue;
            }
            // Inside a structure not recorded: its kind is not known, nothing is checked.
            Statement::Else if deep > 0 => None,
            Statement::Else if open.last().is_some_and(|&(e, _)| e == Statement::EndIf) => None,
            Statement::Else => {
                out.push((Diagnostic::new(Code::UnmatchedStatement, c.range, format!("`ELSE` outside an open IF: {stop}")), here_dead));
                None
            }
            Statement::EndIf | Statement::EndWhile | Statement::EndFor | Statement::Until | Statement::EndLoop => Some(st),
            _ => None,
        };
        let Some(end) = closes else { continue };
        if deep > 0 {
            deep -= 1;
            continue;
        }
        match open.last() {
            Some(&(e, _)) if e == end => {
                open.pop();
            }
            Some(&(e, _)) => {
                let msg = format!("`{}` where the open structure ends with `{}`: {stop}", end_word(end), end_word(e));
                out.push((Diagnostic::new(Code::UnmatchedStatement, c.range, msg), here_dead));
                // The end closes the innermost structure of its kind, where one is open.
                if let Some(k) = open.iter().rposition(|&(e, _)| e == end) {
                    open.truncate(k);
                }
            }
            None => {
                let msg = format!("`{}` with no structure open: {stop}", end_word(end));
                out.push((Diagnostic::new(Code::UnmatchedStatement, c.range, msg), here_dead));
            }
        }
    }
    // The control stops at the first: what follows it is not read.
    if !out.is_empty() {
        out.truncate(1);
        return out;
    }
    // The outermost structure left open: the control stops at the end of the program.
    if let Some(&(end, range)) = open.first() {
        let msg = format!("this structure is never closed (no `{}`): {stop}", end_word(end));
        out.push((Diagnostic::new(Code::UnmatchedStatement, range, msg), false));
    }
    out
}

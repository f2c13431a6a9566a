//! Control flow: the driver that feeds blocks to the [`Interpreter`] and carries out
//! subroutines, macro calls, conditionals, loops and jumps.
//!
//! One engine serves both styles the dialect dictionary can describe: labelled O-word
//! statements (`o100 while [..]`, `o<probe> call [1]`) and keyword statements (`IF [..] GOTO
//! 10`, `WHILE [..] DO 1`, `G65 P9010`, `M98 P1000 L2`). The driver never looks ahead in the
//! normal case: a program without control flow streams block by block. The first jump builds
//! an index of the source's statements and program numbers (its size follows the number of
//! statements, not of blocks), and jumps seek the parser within the text.
//!
//! Runaway programs stop with a diagnostic: every loop and every backward jump target has an
//! iteration limit, and the whole run has a block budget ([`Profile`]).
//!
//! The driver owns control flow as data (the open calls, loops and jumps, the source index);
//! the interpreter executes a block. This file holds the driver's loop ([`run`], `drive`) and
//! the machinery of calls, loops and jumps; each control statement is carried out by its own
//! function in `statements.rs`.

use std::collections::{BTreeMap, BTreeSet};

use typed_arena::Arena;

mod contour;
mod exit;
mod nesting;
mod replay;
mod statements;

use super::eval::{self, NULL};
use super::{Interpreter, Profile, Request};
use crate::canon::{Canon, CanonOp, CanonSink};
use crate::diag::{Code, Diagnostic, Severity};
use crate::dialect::{Dialect, MainReturn, Statement};
use crate::syntax::{Block, Control, Expr, ExprId, Parser, PlainLine};
use crate::text::{LineIndex, Text, TextRange};

/// Why a loop that changes nothing is stopped.
const ENDLESS: &str = "with every parameter and mode as the round before left them, so it would never end";

/// Where the driver finds subprograms that are not in the program's own text. The shell
/// implements it over a configured program directory; the core never reads files.
pub trait ProgramSource {
    /// The text of the program called `name`: `O1000` for a numbered program, or the label
    /// of an O-word subroutine (`probe` for `o<probe> call`).
    fn load(&self, name: &str) -> Option<String>;
}

/// A [`ProgramSource`] without programs: calls resolve within the text only.
pub struct NoPrograms;

impl ProgramSource for NoPrograms {
    fn load(&self, _name: &str) -> Option<String> {
        None
    }
}

/// Interprets `text` with its subprograms, pushing canonical ops into `sink`.
pub fn run<'t>(
    text: impl Into<Text<'t>>,
    dialect: &Dialect,
    profile: &Profile,
    programs: &dyn ProgramSource,
    sink: &mut dyn CanonSink,
) -> Vec<Diagnostic> {
    let text = text.into();
    let arena = Arena::new();
    let mut diags = Vec::new();
    let mut driver = Driver {
        dialect,
        profile,
        programs,
        arena: &arena,
        sources: vec![Source::new(text, String::new())],
        cur: 0,
        parser: {
            let mut p = Parser::new(text, dialect);
            p.set_fast_path(profile.fast_lane);
            p
        },
        frames: Vec::new(),
        loops: Vec::new(),
        back_jumps: BTreeMap::new(),
        landing: None,
        undecided: false,
        undecided_from: None,
        cond_reads: Vec::new(),
        round_guessed: false,
        guess_merge: None,
        exits: BTreeMap::new(),
        exit_waits: BTreeMap::new(),
        executed: 0,
        replaying: false,
        not_found: BTreeSet::new(),
        round: None,
        seen: BTreeSet::new(),
        stop: false,
        delimiters: 0,
        started: false,
        main_work: false,
        library: false,
        lexed: BTreeMap::new(),
        kept: Vec::new(),
        last_kept: None,
        lent: None,
        jump_targets: BTreeMap::new(),
        spare_label: String::new(),
        reached: Vec::new(),
        broken_blocks: BTreeSet::new(),
        broken: false,
        repeated: 0,
        replay_moves: 0,
        replay_kept: None,
        definition: None,
    };
    // The nesting of the control structures, read over the whole text.
    let nest = nesting::check(text, dialect);
    let mut interp = Interpreter::new(dialect, profile);
    interp.start(sink);
    driver.drive(&mut interp, sink, &mut diags);
    interp.flush(sink);
    interp.finish(&mut diags);
    // In interpreter mode the control checks the block structure only as it runs, not
    // completely (SINUMERIK 840D sl job planning, Arbeitsvorbereitung 02/2011, p.107,
    // "Control structures"): a nesting fault is said once (not again where the run already
    // said it: `ENDFOR without an open FOR`), and one in blocks no run reaches (after a jump
    // without condition, before the next label) is a warning. Blocks the analysis skips on a
    // value it does not know may still be run by the control: their faults stay errors.
    for (mut d, dead) in nest {
        if diags.iter().any(|e| e.code == Code::UnmatchedStatement && e.range == d.range) {
            continue;
        }
        if dead {
            d.severity = Severity::Warning;
            d.message = d.message.replace(nesting::STOP, nesting::UNREACHED);
        }
        diags.push(d);
    }
    diags
}

/// A block position: its byte offset and 1-based line.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Pos {
    at: usize,
    line: u32,
}

/// A control statement, label or program start found by the index.
#[derive(Clone, Debug)]
struct Mark {
    /// The O-word label of the statement (`o100 while`).
    label: Option<String>,
    /// The jump label the block defines (`MARK1:`, `LBL 5`), normalised.
    defines: Option<String>,
    /// The statement's named target (`PROC NAME`, `CALL PGM NAME`), normalised.
    name: Option<String>,
    statement: Option<Statement>,
    then: Option<Statement>,
    id: Option<i64>,
    program: Option<u32>,
    /// The program a named program start begins (`OTBOX`), normalised.
    program_name: Option<String>,
    start: Pos,
    next: Pos,
}

struct Source<'a> {
    text: Text<'a>,
    /// Empty for the main program.
    name: String,
    marks: Option<Vec<Mark>>,
    numbers: BTreeMap<u32, Vec<Pos>>,
    lines: Option<LineIndex>,
}

impl<'a> Source<'a> {
    fn new(text: Text<'a>, name: String) -> Source<'a> {
        Source { text, name, marks: None, numbers: BTreeMap::new(), lines: None }
    }

    /// The line and column of `offset`: by an index of its lines for a text in memory (a
    /// called program's file), else by reading up to it.
    fn line_col(&mut self, offset: u32) -> crate::text::LineCol {
        match self.text {
            Text::Whole(t) => self.lines.get_or_insert_with(|| LineIndex::new(t)).line_col(t, offset),
            Text::Read(_) => crate::text::locate(self.text, &[offset])[0],
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum FrameKind {
    /// `o100 call`: returns at `endsub`/`return`.
    Sub,
    /// `G65`, `M98`, `CALL PGM`, `NAME`: returns at `M99`, `M17`, `RET` or the end of its text.
    Program,
    /// `CALL LBL 1`: returns at the end label (`LBL 0`), or on meeting the call again when
    /// the label stands before it (a section repeat).
    Label,
    /// `REPEAT START END P=2`: returns on reaching the frame's `until` offset.
    Section,
}

struct Frame {
    kind: FrameKind,
    /// Source and position to return to.
    ret_source: usize,
    ret: Pos,
    /// Source and start of the body, for repeats.
    source: usize,
    body: Pos,
    repeats_left: u32,
    args: Vec<(u16, f64)>,
    saved_locals: Option<Vec<f64>>,
    saved_names: Option<eval::SavedNames>,
    loops_base: usize,
    call: (TextRange, u32),
    /// Source and offset of the calling block.
    call_at: (usize, usize),
    /// Arguments of a procedure call, bound by the callee's `PROC` statement.
    proc_args: Option<Vec<f64>>,
    /// For a section repeat: the offset in the source where the section ends.
    until: usize,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LoopKind {
    While,
    Do,
    Repeat,
    Numbered,
    /// `FOR var = a TO b`.
    For,
    /// `REPEAT` ... `UNTIL c`.
    Until,
    /// `LOOP` ... `ENDLOOP`.
    Forever,
}

/// Where a loop comes round to: its head statement, or the first block of its body.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum LoopPart {
    Head,
    Body,
}

/// Where a jump looks for its target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Direction {
    /// Forward, then from the top (`GOTO`).
    Any,
    Forward,
    Back,
}

struct Loop {
    kind: LoopKind,
    label: Option<String>,
    id: Option<i64>,
    source: usize,
    head: Pos,
    body: Pos,
    remaining: u64,
    iterations: u64,
}

/// The state at one pass of a backward jump or loop end, to compare with the next pass.
struct Round {
    /// The jump or loop: source and target offset.
    key: (usize, usize),
    /// The pass number.
    pass: u64,
    /// The calls and loops open (see [`Driver::open`]).
    open: Vec<(usize, usize, u64)>,
    state: super::RoundState,
}

struct Driver<'a, 'p> {
    dialect: &'a Dialect,
    profile: &'a Profile,
    programs: &'p dyn ProgramSource,
    arena: &'a Arena<String>,
    sources: Vec<Source<'a>>,
    cur: usize,
    parser: Parser<'a>,
    frames: Vec<Frame>,
    loops: Vec<Loop>,
    back_jumps: BTreeMap<(usize, usize), u64>,
    /// An `elseif`/`else` reached by a jump from a false condition (source, offset).
    landing: Option<(usize, usize)>,
    /// Whether the last condition read an unknown value (the way was chosen, not known).
    undecided: bool,
    /// The outside value that condition read, which what its `THEN` sets then depends on.
    undecided_from: Option<eval::UnknownSource>,
    /// The numbered parameters the conditions read (by number, `#890`) since the last
    /// backward jump or loop end: what a loop that changes nothing may be waiting for. Each
    /// once, in the order read: a loop round clears it, and a tree would allocate a node and
    /// free it again every round.
    cond_reads: Vec<u32>,
    /// Whether a condition on an unknown value was met since the last backward jump or loop
    /// end: a round that reads the machine's or the caller's data may not come round alike.
    round_guessed: bool,
    /// Where the way a forward jump on an unknown condition did not take meets the run again
    /// (its source, the call depth, the target's offset): the run is on a chosen way until then.
    guess_merge: Option<(usize, usize, usize)>,
    /// Whether a forward jump (source, offset after it, target) leaves a loop it stands in
    /// ([`Driver::loop_exit`]): read once.
    exits: BTreeMap<(usize, usize, usize), Option<exit::LoopExit>>,
    /// The loop exits on an unknown condition declined in the current entry of their loop (by
    /// [`exit::LoopExit`]'s key), with the loop's round count then: taken once it came round.
    exit_waits: BTreeMap<(usize, usize, usize), u64>,
    executed: u64,
    /// Whether any block may run a second time: diagnostics are then deduplicated.
    replaying: bool,
    /// The state at a recent pass of a backward jump or loop end.
    round: Option<Round>,
    /// Program names the [`ProgramSource`] did not have: asked once, not on every call.
    not_found: BTreeSet<String>,
    seen: BTreeSet<(u32, u32, Code)>,
    stop: bool,
    /// `%` lines met in the main program: the second one ends it.
    delimiters: u32,
    /// Whether the main program has had a non-blank line.
    started: bool,
    /// Whether the main program has run a block outside subroutine definitions.
    main_work: bool,
    /// Whether the main program has skipped a subroutine definition.
    library: bool,
    /// Blocks lexed on their second run, by source and offset (their index in `kept`), for
    /// their later runs: a loop body is lexed twice, not once per iteration. Bounded by
    /// [`BLOCK_CACHE`].
    lexed: BTreeMap<(usize, usize), u32>,
    /// The blocks `lexed` indexes.
    kept: Vec<Lexed>,
    /// The kept block the run took last, whose `after` may name the next one.
    last_kept: Option<u32>,
    /// Where the jumps to a target written as a name or a constant go, by source and offset
    /// of the jump's block, with the target's name (found once, in the source's index).
    jump_targets: BTreeMap<(usize, usize), (Pos, std::rc::Rc<str>)>,
    /// The room of the last statement's label, for the next one's ([`Driver::label_text`]):
    /// a loop's `o101 while` and `o101 endwhile` come in every pass, and their labels then
    /// allocate nothing.
    spare_label: String,
    /// The kept block lent to [`Driver::drive`]'s block for its run (see
    /// [`Driver::give_back`]).
    lent: Option<u32>,
    /// Per source, the furthest offset lexed: a block before it has run before.
    reached: Vec<usize>,
    /// Control blocks whose lexing found errors (source, offset): their conditions are
    /// not what the program says.
    broken_blocks: BTreeSet<(usize, usize)>,
    /// Whether the block being run is one of them.
    broken: bool,
    /// Blocks run again so far (see [`Profile::max_repeated_blocks`]).
    repeated: u64,
    /// The interpreter's moves when the run began to replay.
    replay_moves: u64,
    /// What the sink kept when the run began to replay (taken at the first block of the
    /// replay): what it keeps beyond counts towards [`Profile::max_repeated_bytes`].
    replay_kept: Option<u64>,
    /// Inside a definition block (see [`crate::dialect::Macros::definition_block`]): where it
    /// started.
    definition: Option<TextRange>,
}

/// A block as the parser left it, and where the next one starts. Its lexical findings are
/// not kept: a block that runs again does not repeat them (see `tidy`).
struct Lexed {
    /// Boxed, so that lending it exchanges two pointers.
    block: Box<Block>,
    next: Pos,
    /// Its source and offset.
    key: (usize, usize),
    /// The kept block that came after it last time (a loop body's next block): found
    /// without a look-up in `lexed` when it comes after it again.
    after: Option<u32>,
    /// Whether the block is lent to the block being run (its place here holds a spare).
    lent: bool,
    /// How the replay lane runs it, decided when it is kept.
    lane: replay::Lane,
}

/// Most blocks kept lexed (a few megabytes at most).
const BLOCK_CACHE: usize = 16_384;

/// How many blocks [`Driver::fall_through`] reads along the way a condition does not jump.
const ALARM_SCAN: usize = 256;

/// Where the way on from a conditional jump goes ([`Driver::fall_through`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Way {
    /// Into an alarm (`#3000 = 1`, `FN 14: ERROR=`).
    Alarm,
    /// Back to the condition or before it: round a loop again.
    Back,
    /// Elsewhere, or where the analysis cannot tell.
    On,
}

/// Whether `v` is a whole number a variable may be numbered by (compared, not `fract`: a
/// call to `trunc` per condition).
fn whole(v: f64) -> bool {
    v >= 0.0 && v <= f64::from(u32::MAX) && f64::from(v as u32) == v
}

/// Whether no expression of `block` reads by number a variable in `outside` (the
/// dictionary's `outside-variables`): what [`Driver::note_reads`] would find in none of its
/// conditions, found once for a block kept to run again ([`Block::reads_no_outside`]).
fn reads_no_outside(block: &Block, outside: &[(u32, u32)]) -> bool {
    !block.exprs.iter().any(|e| match *e {
        Expr::Param(n) => match block.exprs.get(n as usize) {
            Some(&Expr::Num(v)) if whole(v) => outside.iter().any(|&(lo, hi)| (lo..=hi).contains(&(v as u32))),
            _ => false,
        },
        _ => false,
    })
}

/// Whether expression `e` reads no parameter (`+0 EQU +0`).
fn constant(b: &Block, e: ExprId) -> bool {
    match b.exprs.get(e as usize) {
        Some(Expr::Num(_)) => true,
        Some(&Expr::Unary(_, x)) => constant(b, x),
        Some(&Expr::Atan2(x, y) | &Expr::Binary(_, x, y)) => constant(b, x) && constant(b, y),
        _ => false,
    }
}

/// Whether a statement decides where the run goes (a condition, a jump, a loop): one the
/// lexer could not read is skipped rather than carried out on what was left of it.
fn branches(st: Statement) -> bool {
    matches!(
        st,
        Statement::If
            | Statement::ElseIf
            | Statement::While
            | Statement::Until
            | Statement::For
            | Statement::Goto
            | Statement::GotoForward
            | Statement::GotoBack
            | Statement::GotoQuiet
            | Statement::GotoLabel
    )
}

/// The first 40 characters of a control statement, for a message.
fn statement_head<'t>(block: &'t Block, c: &Control) -> &'t str {
    let t = block.text(c.range);
    t.char_indices().nth(40).map_or(t, |(i, _)| &t[..i]).trim()
}

/// The label of whole number `n`, as [`normalise_label`] writes it (without the formatter:
/// a jump back to `LBL 2` runs in every pass of its loop).
fn integer_label(n: i64) -> String {
    let mut digits = [0u8; 20];
    let (mut at, mut m) = (digits.len(), n.unsigned_abs());
    loop {
        at -= 1;
        digits[at] = b'0' + (m % 10) as u8;
        m /= 10;
        if m == 0 {
            break;
        }
    }
    let mut s = String::with_capacity(digits.len() - at + 1);
    if n < 0 {
        s.push('-');
    }
    s.extend(digits[at..].iter().map(|&d| char::from(d)));
    s
}

/// Whether label text `s` is normal already (`100`, `row`), as [`normalise_label`] would
/// write it: lower case, digits and `_`, and no leading zero of a number.
fn normal_label(s: &str) -> bool {
    let b = s.as_bytes();
    !b.is_empty()
        && b.iter().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == b'_')
        && (b[0] != b'0' || b.len() == 1 || !b.iter().all(u8::is_ascii_digit))
}

fn normalise_label(s: &str) -> String {
    // The usual label is normal already (`100`, `row`): copied as it is.
    if normal_label(s) {
        return s.to_owned();
    }
    let s: String = s.chars().filter(|c| !c.is_whitespace()).flat_map(char::to_lowercase).collect();
    if s.bytes().all(|b| b.is_ascii_digit()) {
        let t = s.trim_start_matches('0');
        if t.is_empty() { "0".into() } else { t.into() }
    } else {
        s
    }
}

impl<'a> Driver<'a, '_> {
    fn pos(&self) -> Pos {
        Pos { at: self.parser.offset(), line: self.parser.line() }
    }

    /// The run: block after block of the current source, up to the end of the main program,
    /// a stop or a budget. Plain lines take the plain lane; a control statement is carried
    /// out here, any other block by the interpreter ([`Driver::run_block`]).
    fn drive(&mut self, interp: &mut Interpreter<'a>, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let mut block = Box::<Block>::default();
        let mut plain = PlainLine::default();
        loop {
            if let Some(level) = interp.left_level.take() {
                // A call returned; the state it saved with M73 comes back first.
                interp.leave_level(level, sink);
            }
            // A replay never takes the plain lane (`plain_lane_open`): asked here, without a call.
            if !self.replaying && self.run_plain(&mut plain, interp, sink, diags) {
                if interp.finished() {
                    break;
                }
                continue;
            }
            // A replay takes the replay lane, kept block after kept block (`replay.rs`).
            if self.replaying && self.replay(&mut block, interp, sink, diags) {
                if interp.finished() || self.stop {
                    break;
                }
                continue;
            }
            let start = self.pos();
            let src = self.cur;
            if let Some((s, depth, at)) = self.guess_merge
                && s == src
                && self.frames.len() == depth
                && start.at >= at
            {
                // The way not taken meets the run here.
                self.guess_merge = None;
                interp.st.guessed = None;
            }
            let mark = diags.len();
            self.give_back(&mut block);
            if !self.next_block(&mut block, start, interp, true, diags) {
                if self.source_ended(interp, diags) {
                    break;
                }
                continue;
            }
            if self.definition_block(&block, mark, diags) {
                continue;
            }
            if self.guess_merge.is_some() && !block.assigns.is_empty() {
                // A value set on the way chosen: where the ways meet, the values differ still;
                // the run stays on the chosen way to its end.
                self.guess_merge = None;
            }
            self.note_broken(&block, src, start, &diags[mark..]);
            if let Some(f) = self.frames.last()
                && f.kind == FrameKind::Section
                && self.cur == f.source
                && block.range.start as usize >= f.until
            {
                // The end of a repeated section: again from its start, or back after the repeat.
                self.return_from(None, &block, interp, diags);
                self.tidy(src, mark, diags);
                continue;
            }
            self.executed += 1;
            if self.over_budget(&block, src, mark, interp.motions, &*sink, diags) {
                break;
            }
            if src == 0 && self.frames.is_empty() && !self.main_program_block(&block, interp, sink, diags) {
                break;
            }
            if self.broken_statement(&block, diags) {
                self.tidy(src, mark, diags);
                continue;
            }
            self.run_block(&mut block, start, interp, sink, diags);
            self.tidy(src, mark, diags);
            if interp.finished() || self.stop {
                break;
            }
        }
        self.give_back(&mut block);
    }

    /// The end of the current source: a definition block still open is said; a called
    /// program's file returns to its caller. True at the end of the main program.
    fn source_ended(&mut self, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) -> bool {
        if let Some(range) = self.definition.take() {
            let msg = "the definition block is not closed: the rest of the file was read as its data";
            diags.push(Diagnostic::new(Code::UnmatchedStatement, range, msg));
        }
        if !self.end_of_source(interp, diags) {
            self.end_of_main(interp, diags);
            return true;
        }
        false
    }

    /// Whether the block (at `start` of source `src`) is a control block whose lexing found
    /// errors (`found`, its findings): kept in `broken` for this run of it, and remembered for
    /// its later runs, which are not lexed again.
    #[inline]
    fn note_broken(&mut self, block: &Block, src: usize, start: Pos, found: &[Diagnostic]) {
        if block.control.is_some() {
            let range = block.range;
            if found.iter().any(|d| d.is_error() && d.range.start >= range.start && d.range.start < range.end.max(range.start + 1)) {
                self.broken_blocks.insert((src, start.at));
            }
            self.broken = !self.broken_blocks.is_empty() && self.broken_blocks.contains(&(src, start.at));
        } else {
            self.broken = false;
        }
    }

    /// Whether the run stops before `block` for a budget of the profile: the blocks run again
    /// ([`Profile::max_repeated_blocks`]) or all blocks run ([`Profile::max_blocks`]); the
    /// finding says which.
    #[inline]
    fn over_budget(
        &mut self,
        block: &Block,
        src: usize,
        mark: usize,
        moves: u64,
        sink: &dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) -> bool {
        let profile = self.profile;
        // Without a bound in memory (a streamed run) nothing kept is counted: no call to the sink.
        let repeated_bytes = if self.replaying && profile.max_repeated_bytes != u64::MAX {
            let kept = sink.kept_bytes(moves);
            kept.saturating_sub(*self.replay_kept.get_or_insert(kept))
        } else {
            0
        };
        if self.repeated > profile.max_repeated_blocks || repeated_bytes > profile.max_repeated_bytes {
            self.tidy(src, mark, diags);
            let bound = if self.repeated > profile.max_repeated_blocks {
                format!(
                    "its bound in time ({} blocks run again: loops, jumps back, repeated calls; about {} s)",
                    profile.max_repeated_blocks,
                    profile.max_repeated_blocks.div_ceil(super::REPEATED_BLOCKS_PER_SECOND)
                )
            } else {
                format!(
                    "its bound in memory ({} moves made by blocks run again, {} MB kept of them; about {} MB)",
                    moves.saturating_sub(self.replay_moves),
                    repeated_bytes.div_ceil(1_000_000),
                    profile.max_repeated_bytes.div_ceil(1_000_000)
                )
            };
            let msg = format!(
                "the analysis reached {bound}: it stops here, and what the program does after it is not analysed (`[analysis] max_seconds` and `max_memory_mb` raise the bound)"
            );
            diags.push(Diagnostic::new(Code::RepeatBudget, block.range, msg));
            return true;
        }
        if self.executed > self.profile.max_blocks {
            self.tidy(src, mark, diags);
            diags.push(Diagnostic::new(Code::LoopLimit, block.range, self.block_budget_message()));
            return true;
        }
        false
    }

    /// What a block of the main program at its top level tells about the program: a program
    /// number the control reserves for called programs, the `%` lines that open and close
    /// it, whether its work has begun. False when a `%` line stops the control.
    fn main_program_block(
        &mut self,
        block: &Block,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) -> bool {
        if let Some(n) = block.program_number.filter(|&n| !self.main_work && self.dialect.macros.is_called_number(n)) {
            interp.called_by(|| format!("its number O{n:04} is one the control reserves for called programs"));
        }
        if block.delimiter {
            if self.delimiters > 0 {
                interp.finish_at_delimiter(sink);
            } else if self.started && self.dialect.lexical.delimiter_first_line {
                let msg = "a `%` line closes a program only when another opens it on the first line; the control stops here";
                diags.push(Diagnostic::new(Code::UnmatchedStatement, block.range, msg));
                return false;
            }
            self.delimiters += 1;
        } else if !self.main_work {
            // Settled by the first blocks of a program; not looked at again.
            self.started = self.started || !block.source().trim().is_empty();
            self.main_work = !block.words.is_empty()
                || !block.assigns.is_empty()
                || block.control.as_ref().is_some_and(|c| c.statement != Some(Statement::Sub));
        }
        true
    }

    /// Whether the block is a statement that decides where the run goes but could not be
    /// read: it is skipped, and said so.
    fn broken_statement(&self, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        let Some(control) = block.control.as_ref().filter(|c| self.broken && c.statement.is_some_and(branches)) else { return false };
        // The lexer could not read the statement: what it kept of it (a condition cut
        // short, a jump without its IF) is not what the program says, and the control
        // stops with an alarm at a block it cannot read.
        let head = statement_head(block, control);
        let msg = format!(
            "the statement `{head}` could not be read and is skipped: no jump, branch or loop is taken on what was left of it (the control alarms here)"
        );
        diags.push(Diagnostic::new(Code::BrokenCondition, block.range, msg));
        true
    }

    /// Carries out a block: a control statement here, as control flow is the driver's; any
    /// other block by the interpreter, then the call or return it asks for.
    fn run_block(
        &mut self,
        block: &mut Block,
        start: Pos,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        if block.control.as_ref().is_some_and(|c| c.then == Some(Statement::Then)) {
            // `IF [..] THEN #1 = 2`: the block's own words run with the statement taken off.
            if let Some(control) = block.control.take() {
                self.control(&control, block, start, interp, sink, diags);
                block.control = Some(control);
            }
        } else if let Some(control) = &block.control {
            // Lent, not moved out and back: a statement is carried out on every pass of a loop.
            self.control(control, block, start, interp, sink, diags);
        } else {
            interp.execute(block, sink, diags);
            if let Some(r) = interp.request.take() {
                self.request(r, block, interp, sink, diags);
            }
        }
    }

    /// Whether the next block may take the plain lane (a line of plain words, read and run
    /// without a [`Block`]): in the main program's first run, past its first blocks, outside
    /// any call, loop or definition block, where the general way would do nothing for such a
    /// block but run it (no frame to return from, no findings to tidy, no repeat to count).
    #[inline(always)]
    fn plain_lane_open(&self) -> bool {
        self.cur == 0
            && self.main_work
            && !self.replaying
            && !self.stop
            && self.frames.is_empty()
            && self.definition.is_none()
            && self.dialect.macros.definition_block.is_none()
    }

    /// Runs the plain lines from the cursor on (see [`Parser::plain_lines`]) as the general way
    /// runs their blocks, and moves past them, up to the first that must go the general way
    /// (it is no plain move, or a block budget ends there); false, with nothing changed, when
    /// none ran. What a plain move cannot change (the lane is open, the run is a first one, the
    /// interpreter's state admits plain moves) is asked once for the whole run.
    #[inline(never)]
    fn run_plain(
        &mut self,
        line: &mut PlainLine,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) -> bool {
        let reached = self.reached.get(self.cur).copied().unwrap_or(0);
        if !self.plain_lane_open() || self.parser.offset() < reached || self.repeated > self.profile.max_repeated_blocks {
            return false;
        }
        let Some(run) = interp.plain_ready() else { return false };
        let room = self.profile.max_blocks.saturating_sub(self.executed);
        let ran = self.parser.plain_lines(line, room, |line| interp.run_plain(run, line, sink, diags));
        if ran == 0 {
            return false;
        }
        // As `next_block` and `drive` keep count for each block.
        if self.reached.len() <= self.cur {
            self.reached.resize(self.cur + 1, 0);
        }
        self.reached[self.cur] = self.parser.offset();
        self.executed += ran;
        self.broken = false;
        true
    }

    /// Whether the block belongs to a definition block (Okuma `DEF WORK` / `PT ...` / `END`):
    /// its lines are data for the control, not statements, so they are skipped (with their
    /// lexical findings) and the start says so once.
    fn definition_block(&mut self, block: &Block, mark: usize, diags: &mut Vec<Diagnostic>) -> bool {
        let Some((start_kw, end_kw)) = self.dialect.macros.definition_block.as_ref() else { return false };
        let text = block.source().trim_start();
        let starts = |kw: &str| {
            text.get(..kw.len()).is_some_and(|h| h.eq_ignore_ascii_case(kw))
                && !text[kw.len()..].chars().next().is_some_and(|c| c.is_ascii_alphanumeric() || c == '_')
        };
        if self.definition.is_some() {
            diags.truncate(mark);
            if starts(end_kw) {
                self.definition = None;
            }
            return true;
        }
        if !starts(start_kw) {
            return false;
        }
        diags.truncate(mark);
        self.definition = Some(block.range);
        let head = text.lines().next().unwrap_or("").trim();
        let msg = format!("`{head}` opens a definition (data for the control, up to `{end_kw}`): skipped, no motion");
        diags.push(Diagnostic::new(Code::DefinitionSkipped, block.range, msg));
        true
    }

    /// The block at `start` of the current source: lexed by the parser, or, when it has run
    /// twice before with the run replaying, as it was lexed then (its findings would not be
    /// shown again), its names resolved to the slots of the interpreter's parameters. A kept
    /// block is copied into `block`, or, with `lend`, exchanged with it, to be given back
    /// before the next ([`Driver::give_back`]). False at the end of the source.
    fn next_block(
        &mut self,
        block: &mut Box<Block>,
        start: Pos,
        interp: &mut Interpreter<'a>,
        lend: bool,
        diags: &mut Vec<Diagnostic>,
    ) -> bool {
        let key = (self.cur, start.at);
        // Only while replaying: a block lexed then has had its findings noted in `seen`, so a
        // later run that skips lexing loses nothing (`tidy` would drop them again).
        let cache = self.profile.fast_lane && self.replaying;
        if cache && let Some(k) = self.kept_at(key) {
            let l = &mut self.kept[k as usize];
            if lend {
                std::mem::swap(block, &mut l.block);
                l.lent = true;
                self.lent = Some(k);
            } else {
                block.clone_from(&l.block);
            }
            let next = l.next;
            self.parser.seek(next.at, next.line);
            self.repeated += 1;
            return true;
        }
        if !self.parser.next_block(block, diags) {
            return false;
        }
        if self.reached.len() <= self.cur {
            self.reached.resize(self.cur + 1, 0);
        }
        let reached = &mut self.reached[self.cur];
        if start.at < *reached {
            self.repeated += 1;
            // Run before: probably in a loop, so kept for the runs to come (unless it is
            // kept already, and lent to the block being run).
            if cache && self.lexed.len() < BLOCK_CACHE && !self.lexed.contains_key(&key) {
                // Its names resolved once, for the runs to come.
                eval::resolve(block, &mut interp.params);
                let macros = &self.dialect.macros;
                eval::resolve_numbered(block, |n| macros.system_var(n).is_none() && !(n == 0 && macros.null_value));
                block.reads_no_system = !interp.reads_system(block);
                block.reads_no_outside = reads_no_outside(block, &self.dialect.macros.outside);
                let k = self.kept.len() as u32;
                self.lexed.insert(key, k);
                let lane = replay::lane(block);
                self.kept.push(Lexed { block: block.clone(), next: self.pos(), key, after: None, lent: false, lane });
            }
        } else {
            *reached = self.parser.offset();
        }
        true
    }

    /// The kept block at `key`, unless it is lent: the one that came after the last kept
    /// block taken before, or else looked up.
    #[inline]
    fn kept_at(&mut self, key: (usize, usize)) -> Option<u32> {
        let (k, linked) = self.peek_kept(key)?;
        self.take_kept(k, linked);
        Some(k)
    }

    /// The kept block at `key`, unless it is lent, and whether it is the one the last kept
    /// block names as its `after`; nothing changed (see [`Driver::take_kept`]).
    #[inline(always)]
    fn peek_kept(&self, key: (usize, usize)) -> Option<(u32, bool)> {
        let last = self.last_kept.map(|p| p as usize);
        let (k, linked) = match last.and_then(|p| self.kept[p].after).filter(|&k| self.kept[k as usize].key == key) {
            Some(k) => (k, true),
            None => (*self.lexed.get(&key)?, false),
        };
        (!self.kept[k as usize].lent).then_some((k, linked))
    }

    /// Takes kept block `k` (found by [`Driver::peek_kept`]) as the run's last: the one
    /// before it names it as its `after` when it did not.
    #[inline(always)]
    fn take_kept(&mut self, k: u32, linked: bool) {
        if !linked && let Some(p) = self.last_kept {
            self.kept[p as usize].after = Some(k);
        }
        self.last_kept = Some(k);
    }

    /// Gives the kept block lent to `block` back to its place (see [`Driver::next_block`]).
    #[inline]
    fn give_back(&mut self, block: &mut Box<Block>) {
        if let Some(k) = self.lent.take() {
            let l = &mut self.kept[k as usize];
            std::mem::swap(block, &mut l.block);
            l.lent = false;
        }
    }

    /// Post-processes the diagnostics of one block: those from another file point at the
    /// call in the main program; a block that runs again does not repeat its findings. An
    /// error in the other file's text as such (its reader's: a word, code or statement the
    /// control does not read, whoever calls it) is that file's, not the caller's: it is said
    /// at the call as a warning naming the file, which read on its own reports it as its
    /// error. An error of the run (a division by zero with the caller's arguments, a
    /// definition inside a running subroutine) stays the caller's: the control stops there.
    /// (Nothing to do in the main program's first run, the bulk of the blocks.)
    #[inline(always)]
    fn tidy(&mut self, src: usize, mark: usize, diags: &mut Vec<Diagnostic>) {
        if src != 0 || (self.replaying && diags.len() > mark) {
            self.tidy_findings(src, mark, diags);
        }
    }

    /// [`Driver::tidy`] where there is something to do.
    fn tidy_findings(&mut self, src: usize, mark: usize, diags: &mut Vec<Diagnostic>) {
        if src != 0 {
            let call = self.external_call().map_or(TextRange::default(), |c| c.0);
            let source = &mut self.sources[src];
            for d in &mut diags[mark..] {
                if d.range != call {
                    let lc = source.line_col(d.range.start);
                    d.message = if d.is_error() && (d.code.as_str().starts_with("syntax::") || d.code == Code::UnknownStatement) {
                        d.severity = Severity::Warning;
                        format!(
                            "in {}:{}:{}: {} (an error of the called program {}, reported against it)",
                            source.name, lc.line, lc.col, d.message, source.name
                        )
                    } else {
                        format!("in {}:{}:{}: {}", source.name, lc.line, lc.col, d.message)
                    };
                    d.range = call;
                }
            }
        }
        if self.replaying {
            let mut k = mark;
            while k < diags.len() {
                let d = &diags[k];
                if self.seen.insert((d.range.start, d.range.end, d.code)) {
                    k += 1;
                } else {
                    diags.remove(k);
                }
            }
        }
    }

    /// The call block in the main program through which a subprogram file runs.
    fn external_call(&self) -> Option<(TextRange, u32)> {
        self.frames.iter().find(|f| f.source != 0 && f.ret_source == 0).map(|f| f.call)
    }

    fn switch_to(&mut self, source: usize, pos: Pos, interp: &mut Interpreter<'a>) {
        if source != self.cur {
            self.cur = source;
            self.parser = self.parser.fork(self.sources[source].text, pos.at, pos.line);
            interp.origin_override = if source == 0 { None } else { self.external_call() };
        }
        self.parser.seek(pos.at, pos.line);
    }

    /// Jumps to `pos` in `source`; a jump backwards turns on replay deduplication.
    fn jump(&mut self, source: usize, pos: Pos, here: Pos, interp: &mut Interpreter<'a>, diags: &[Diagnostic]) {
        if !self.replaying && (source != self.cur || pos.at <= here.at) {
            self.replaying = true;
            self.replay_moves = interp.motions;
            self.seen.extend(diags.iter().map(|d| (d.range.start, d.range.end, d.code)));
        }
        self.switch_to(source, pos, interp);
    }

    /// Counts one more block run; over the run's budget, says so at `range` and is true.
    fn over_block_budget(&mut self, range: TextRange, diags: &mut Vec<Diagnostic>) -> bool {
        self.executed += 1;
        let over = self.executed > self.profile.max_blocks;
        if over {
            let msg = self.block_budget_message();
            self.error(diags, Code::LoopLimit, range, msg);
        }
        over
    }

    fn block_budget_message(&self) -> String {
        format!("the run executed more than {} blocks; it stops here (a runaway loop?)", self.profile.max_blocks)
    }

    fn error(&mut self, diags: &mut Vec<Diagnostic>, code: Code, range: TextRange, msg: impl Into<String>) {
        let d = Diagnostic::new(code, range, msg);
        if d.severity == Severity::Error && matches!(code, Code::MissingLabel | Code::LoopLimit | Code::CallDepth) {
            self.stop = true;
        }
        diags.push(d);
    }

    /// The finding for an explicit call to a program found neither in the file nor in the
    /// program directory. A control that keeps programs in its own memory may hold it: then
    /// it is a warning that the analysis lacks the program's moves.
    fn program_not_found(&self, what: String, range: TextRange) -> Diagnostic {
        if self.dialect.behaviour.resident_programs {
            let msg = format!(
                "{what} is neither in this file nor in the program directory; the control may hold it in its memory, but this analysis skips the call and lacks its moves"
            );
            let mut d = Diagnostic::new(Code::MissingProgram, range, msg);
            d.severity = Severity::Warning;
            d
        } else {
            Diagnostic::new(
                Code::MissingProgram,
                range,
                format!("{what} is neither in this file nor in the program directory; the call was skipped"),
            )
        }
    }

    fn marks(&mut self, source: usize) -> &[Mark] {
        let dialect = self.dialect;
        let src = &mut self.sources[source];
        src.marks.get_or_insert_with(|| index(src.text, dialect))
    }

    /// The first mark after `after` in the current source that `pred` accepts.
    fn find_after(&mut self, after: usize, pred: impl Fn(&Mark) -> bool) -> Option<Mark> {
        let marks = self.marks(self.cur);
        let from = marks.partition_point(|m| m.start.at <= after);
        marks[from..].iter().find(|m| pred(m)).cloned()
    }

    /// The label `control` names, as [`normalise_label`] writes it, in the room the last
    /// statement's label left ([`Driver::spare_label`]; the caller gives it back).
    fn label_text(&mut self, block: &Block, control: &Control) -> Option<String> {
        control.label.map(|r| {
            let text = block.text(r);
            let mut s = std::mem::take(&mut self.spare_label);
            s.clear();
            if normal_label(text) {
                s.push_str(text);
            } else {
                s.push_str(&normalise_label(text));
            }
            s
        })
    }

    /// Evaluates operand `e` of a control block with the interpreter's parameters.
    fn value(&self, interp: &mut Interpreter<'a>, block: &Block, e: ExprId, diags: &mut Vec<Diagnostic>) -> Option<f64> {
        // A condition may read the position or the tool (`o1 if [#5420 GT 3]`, `o1 if [#<_x> GT 3]`).
        if !self.dialect.macros.system.is_empty() || !self.dialect.macros.system_named.is_empty() {
            interp.refresh_system_vars(block);
        }
        match interp.eval(block, e, block.range, diags) {
            Ok(v) => Some(v),
            Err(err) => {
                diags.push(interp.eval_diag(err, block.range));
                None
            }
        }
    }

    fn condition(&mut self, interp: &mut Interpreter<'a>, c: &Control, block: &Block, diags: &mut Vec<Diagnostic>) -> Option<bool> {
        let Some(&e) = c.args.first() else {
            diags.push(Diagnostic::new(Code::MalformedExpression, c.range, "the statement needs a bracketed condition"));
            return None;
        };
        self.note_reads(block, e);
        let v = self.value(interp, block, e, diags)?;
        self.undecided = eval::is_unknown(v);
        if self.undecided {
            self.undecided_from = interp.params.unknown_read_peek();
            return Some(self.unknown_condition(interp, c, block, diags));
        }
        Some(!eval::is_null(v) && v != 0.0)
    }

    /// The way a condition on an unknown value goes: the one a run without alarm takes; for
    /// a loop, the way out of it (a successful run ends its loops); else the config's or the
    /// dictionary's choice (`unknown-conditions`). A note names the condition.
    fn unknown_condition(&mut self, interp: &mut Interpreter<'a>, c: &Control, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        let here = self.pos();
        let what = interp.unknown_what();
        let choice = self.profile.unknown_conditions.unwrap_or(self.dialect.macros.unknown_conditions);
        let jump = matches!(
            c.then,
            Some(Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet | Statement::GotoLabel)
        );
        let mut forward = None;
        let mut loop_exit = false;
        let (value, why) = match c.statement {
            // A block IF's body is the lines after it.
            Some(Statement::If) if block_if(block, c, self.dialect) => self.alarm_choice(self.alarm_at(here), false, choice),
            Some(Statement::If) if c.then == Some(Statement::Then) => self.alarm_choice(self.is_alarm(block), self.alarm_at(here), choice),
            Some(Statement::If) if jump => match self.jump_target(c, block, interp) {
                Some(target) if target.at <= here.at => (false, "the jump back is not taken: a run that ends leaves its loops"),
                target => {
                    forward = target;
                    // The way from the target on, past the blocks that only stop the spindle
                    // or coolant before the alarm (`N900 M05` `#3000=91`), to its first statement.
                    let at_target = target.is_some_and(|t| self.leads_to_alarm(t, interp, 0));
                    match self.fall_through(here, interp) {
                        // Not jumping goes round the loop again (`IF [found] GOTO 20` …
                        // `GOTO 10`): the jump leaves the loop, as a run that ends does.
                        Way::Back if !at_target => (true, "the jump leaves the loop: a run that ends leaves its loops"),
                        // A jump past the loop's end with more between (`IF (F>=MAX) GOTOF END`
                        // … `GOTOB LOOP`): it leaves the loop after one pass (see `exit`).
                        Way::On if !at_target && let Some(exit) = target.and_then(|t| self.loop_exit(here, t, interp)) => {
                            loop_exit = true;
                            if self.exit_now(exit) {
                                (
                                    true,
                                    "the jump leaves the loop it stands in, after one pass of it: a run that ends leaves its loops, where the control's data says (one pass assumed)",
                                )
                            } else {
                                (
                                    false,
                                    "the loop runs one whole pass first, then the jump leaves the loop it stands in: a run that ends leaves its loops, where the control's data says (one pass assumed)",
                                )
                            }
                        }
                        way => self.alarm_choice(at_target, self.alarm_at(here) || way == Way::Alarm, choice),
                    }
                }
            },
            Some(Statement::If | Statement::ElseIf) => self.alarm_choice(self.alarm_at(here), false, choice),
            Some(Statement::Until) => (true, "the loop is left: a run that ends leaves its loops"),
            _ => (false, "the loop is left: a run that ends leaves its loops"),
        };
        let head = statement_head(block, c);
        if let Some(t) = forward
            && interp.st.guessed.is_none()
        {
            if !value {
                // A forward jump not taken: until the run reaches its target, where both ways
                // meet, it goes the way chosen here, which the control may not go (nor what a
                // program it calls on the way hands back).
                interp.st.guessed = Some(head.to_string());
                self.guess_merge = Some((self.cur, self.frames.len(), t.at));
            } else if self.sources[self.cur].text.piece(here.at, t.at.saturating_sub(here.at)).contains('=') {
                // A forward jump taken over blocks that set values (`#149=0` … `GOTO9` `N7`
                // `#149=1`): what the run computes from here on comes of the way chosen, to
                // the end of the run (a called program hands it back to its caller).
                interp.st.guessed = Some(head.to_string());
                self.guess_merge = None;
            }
        }
        self.round_guessed = true;
        let msg = format!("the condition of `{head}` reads {what}; taken as {value}: {why}");
        let mut d = Diagnostic::new(Code::UnknownCondition, c.range, msg);
        if loop_exit {
            // How many passes the loop makes is a guess: a warning, not a note.
            d.severity = Severity::Warning;
        }
        diags.push(d);
        value
    }

    /// The value of a condition whose true way leads to an alarm or not, and its false way.
    fn alarm_choice(&self, true_alarm: bool, false_alarm: bool, choice: bool) -> (bool, &'static str) {
        match (true_alarm, false_alarm) {
            (true, false) => (false, "the other way raises the program's alarm"),
            (false, true) => (true, "the other way raises the program's alarm"),
            _ => (choice, "the dictionary's (or config's) choice for a condition on an unknown value"),
        }
    }

    /// Where a conditional jump goes, without going there (block numbers and labels).
    fn jump_target(&mut self, c: &Control, block: &Block, interp: &mut Interpreter<'a>) -> Option<Pos> {
        self.jump_target_from(c, block, interp, self.pos())
    }

    /// Where a jump at `here` goes: the first target at or after it, else the first.
    fn jump_target_from(&mut self, c: &Control, block: &Block, interp: &mut Interpreter<'a>, here: Pos) -> Option<Pos> {
        let mut scratch = Vec::new();
        // `GOTO LBL 99` names a label by a number; `GOTO 99` a block.
        let label = c.then == Some(Statement::GotoLabel) || c.statement == Some(Statement::GotoLabel);
        if c.name.is_none() && !label {
            let e = c.target?;
            let v = self.value(interp, block, e, &mut scratch)?;
            if eval::is_null(v) || v < 0.0 || v.fract() != 0.0 || v > 99_999_999.0 {
                return None;
            }
            let positions = self.numbered_blocks(self.cur, v as u32);
            return positions.iter().find(|p| p.at >= here.at).or(positions.first()).copied();
        }
        let name = self.target_label(c, block, interp, &mut scratch)?;
        let marks = self.marks(self.cur);
        let at = |m: &&Mark| m.defines.as_deref() == Some(name.as_str());
        marks.iter().filter(at).find(|m| m.start.at >= here.at).or_else(|| marks.iter().find(at)).map(|m| m.start)
    }

    /// Whether the first block with content at `at` (of the next few) raises an alarm.
    fn alarm_at(&self, at: Pos) -> bool {
        let mut p = self.parser.fork(self.sources[self.cur].text, at.at, at.line);
        let (mut b, mut scratch) = (Block::default(), Vec::new());
        for _ in 0..4 {
            if !p.next_block(&mut b, &mut scratch) {
                return false;
            }
            // A conditional alarm (`IF [..] THEN #3000=1`) is another question, not this way's end.
            if b.control.is_none() && self.is_alarm(&b) {
                return true;
            }
            if !b.words.is_empty() || !b.assigns.is_empty() || b.control.as_ref().is_some_and(|c| c.statement != Some(Statement::Label)) {
                return false;
            }
        }
        false
    }

    /// Where the way on from `from` goes, block after block, up to its first statement
    /// (at most [`ALARM_SCAN`] blocks): into an alarm, back to `from` or before it by a jump
    /// that is always taken (`GOTO 10`, `FN 9: IF +0 EQU +0 GOTO LBL 1`), or elsewhere. A
    /// conditional jump into an alarm on the way is passed (a successful run does not take
    /// it): `IF [#890 EQ 3] GOTO 2` `IF [#890 EQ 4] GOTO 3` (N3 alarms) `G4` `GOTO 1` is a way
    /// back round the loop from the first condition. So is a conditional jump back, a loop's
    /// end that a run leaves: `IF [#1004 EQ 0] GOTO 999` `#33=#33+1` `IF [#33 LT 4] GOTO 1`
    /// `#3000=146` is a way into the alarm.
    fn fall_through(&mut self, from: Pos, interp: &mut Interpreter<'a>) -> Way {
        self.fall_through_within(from, interp, 0)
    }

    /// Whether the way from `at` raises an alarm: at once, or down its fall-through.
    fn leads_to_alarm(&mut self, at: Pos, interp: &mut Interpreter<'a>, depth: u32) -> bool {
        self.alarm_at(at) || self.fall_through_within(at, interp, depth) == Way::Alarm
    }

    fn fall_through_within(&mut self, from: Pos, interp: &mut Interpreter<'a>, depth: u32) -> Way {
        let mut p = self.parser.fork(self.sources[self.cur].text, from.at, from.line);
        let (mut b, mut scratch) = (Block::default(), Vec::new());
        for _ in 0..ALARM_SCAN {
            if !p.next_block(&mut b, &mut scratch) {
                return Way::On;
            }
            let Some(c) = b.control.clone() else {
                if self.is_alarm(&b) {
                    return Way::Alarm;
                }
                if self.ends_program(&b) {
                    return Way::On;
                }
                continue;
            };
            let jump = matches!(
                c.then,
                Some(Statement::Goto | Statement::GotoForward | Statement::GotoBack | Statement::GotoQuiet | Statement::GotoLabel)
            );
            let always = match c.statement {
                Some(Statement::Label) => continue,
                // A loop's end: a run that ends leaves the loop there, so its way goes on past it.
                Some(Statement::EndWhile | Statement::EndDo | Statement::EndRepeat | Statement::EndFor | Statement::EndLoop) => continue,
                Some(Statement::Goto | Statement::GotoBack | Statement::GotoLabel) => true,
                Some(Statement::If) if jump => c.args.first().is_some_and(|&e| {
                    constant(&b, e) && interp.eval(&b, e, b.range, &mut scratch).is_ok_and(|v| !eval::is_null(v) && v != 0.0)
                }),
                _ => false,
            };
            // Where it jumps to, seen from the jump's own block.
            let at = Pos { at: p.offset(), line: p.line() };
            if !always {
                let target = (c.statement == Some(Statement::If) && jump && depth < 2).then(|| self.jump_target_from(&c, &b, interp, at));
                match target.flatten() {
                    // A conditional jump back ends a loop (`IF [#33 LT 4] GOTO 1`, a retry
                    // count): a run that ends leaves the loop there, so its way goes on past it.
                    Some(t) if t.at < at.at => continue,
                    Some(t) if t.at > from.at && self.leads_to_alarm(t, interp, depth + 1) => continue,
                    _ => return Way::On,
                }
            }
            return match self.jump_target_from(&c, &b, interp, at) {
                Some(t) if t.at <= from.at => Way::Back,
                // `GOTO 800` where N800 raises the alarm (an argument check's last word).
                Some(t) if depth < 2 && self.leads_to_alarm(t, interp, depth + 1) => Way::Alarm,
                _ => Way::On,
            };
        }
        Way::On
    }

    /// Whether `b` ends the program or returns from it (`M30`, `M2`, `M99`): a way that gets
    /// there raises no alarm.
    fn ends_program(&self, b: &Block) -> bool {
        b.words.iter().any(|w| {
            // A return ends the way too: the alarms after `M99` are other ways'.
            matches!(
                self.word_meaning(w),
                Some(
                    crate::dialect::Meaning::ProgramEnd
                        | crate::dialect::Meaning::ProgramEndRewind
                        | crate::dialect::Meaning::SubprogramReturn
                )
            )
        })
    }

    /// What an M word or a keyword with a constant value means in the dictionary.
    fn word_meaning(&self, w: &crate::syntax::Word) -> Option<crate::dialect::Meaning> {
        let crate::syntax::Value::Number { value, .. } = w.value else { return None };
        let code = match w.role {
            crate::dialect::Role::Keyword => Some(value as usize),
            crate::dialect::Role::M if value >= 0.0 && value.fract() == 0.0 => self.dialect.code_id('M', (value * 10.0) as u32),
            _ => None,
        };
        code.and_then(|i| self.dialect.codes.get(i)).map(|c| c.meaning)
    }

    /// Whether `b` raises an alarm: it sets the alarm variable (`#3000 = 1`), names an error
    /// (`FN 14: ERROR=`), or aborts in a comment (`(abort, …)`).
    fn is_alarm(&self, b: &Block) -> bool {
        let alarm_var = |e: ExprId| match b.exprs.get(e as usize) {
            Some(&Expr::Num(n)) if n >= 0.0 && n.fract() == 0.0 => {
                self.dialect.macros.system_var(n as u32) == Some(crate::dialect::SystemVar::Alarm)
            }
            _ => false,
        };
        // An element of a named array the dictionary names the alarm (`VDOUT[992] = 1004`).
        let alarm_element = |r: TextRange, e: ExprId| match b.exprs.get(e as usize) {
            Some(&Expr::Num(n)) => {
                self.dialect.macros.system_element(&eval::normalised(b.text(r)), n) == Some(crate::dialect::SystemVar::Alarm)
            }
            _ => false,
        };
        b.assigns.iter().any(|a| matches!(a.target, crate::syntax::ParamTarget::Numbered(e) if alarm_var(e)))
            || b.assigns.iter().any(|a| matches!(a.target, crate::syntax::ParamTarget::NamedIndex(r, e) if alarm_element(r, e)))
            || b.words.iter().any(|w| w.role == crate::dialect::Role::AlarmNumber)
            || b.comments.iter().any(|r| matches!(self.dialect.lexical.directive(b.text(*r)), Some((crate::dialect::Directive::Abort, _))))
    }

    fn count_iteration(&mut self, k: usize, range: TextRange, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) -> bool {
        self.loops[k].iterations += 1;
        let l = &self.loops[k];
        if l.iterations > self.profile.max_loop_iterations {
            let limit = self.profile.max_loop_iterations;
            self.error(diags, Code::LoopLimit, range, format!("the loop ran more than {limit} times; the run stops here"));
            return false;
        }
        // A loop that counts its rounds itself ends; one that runs on a condition may not.
        let conditional = matches!(l.kind, LoopKind::While | LoopKind::Do | LoopKind::Numbered | LoopKind::Until | LoopKind::Forever);
        let (key, count) = ((l.source, l.head.at), l.iterations);
        if conditional && self.endless(key, count, interp) && !self.waits_for_outside(interp, range, diags) {
            if self.waits_on_unknown(range, diags) {
                return false;
            }
            self.error(diags, Code::LoopLimit, range, format!("the loop comes round {ENDLESS}; the run stops here"));
            return false;
        }
        self.cond_reads.clear();
        self.round_guessed = false;
        true
    }

    /// The outside variables (the dictionary's `outside-variables`) condition `e` of `block`
    /// reads by number (`#890`, `R5`). Without allocation: conditions run in every loop round.
    fn note_reads(&mut self, block: &Block, e: ExprId) {
        let outside = &self.dialect.macros.outside;
        // A kept block was looked into once, when it was kept.
        if outside.is_empty() || block.reads_no_outside {
            return;
        }
        // Conditions are small: a fixed stack, and what does not fit is not looked into.
        let mut stack = [e; 16];
        let mut len = 1;
        while len > 0 {
            len -= 1;
            let (a, b) = match block.exprs.get(stack[len] as usize) {
                Some(&Expr::Param(n)) => match block.exprs.get(n as usize) {
                    Some(&Expr::Num(v)) if whole(v) => {
                        let v = v as u32;
                        if outside.iter().any(|&(lo, hi)| (lo..=hi).contains(&v)) && !self.cond_reads.contains(&v) {
                            self.cond_reads.push(v);
                        }
                        continue;
                    }
                    _ => (Some(n), None),
                },
                Some(&(Expr::Unary(_, a) | Expr::NamedIndex(_, a))) => (Some(a), None),
                Some(&(Expr::Binary(_, a, b) | Expr::Atan2(a, b))) => (Some(a), Some(b)),
                _ => continue,
            };
            for x in [a, b].into_iter().flatten() {
                if len < stack.len() {
                    stack[len] = x;
                    len += 1;
                }
            }
        }
    }

    /// A loop that comes round with nothing changed while its conditions read a variable
    /// the outside writes (the dictionary's `outside-variables`: common variables a PLC, a
    /// robot or a remote client sets, inputs): a handshake that waits for it to change
    /// (`#890=1` … `N1 IF [#890 EQ 3] GOTO 2` `G4 P1.` `GOTO 1`). Those variables become
    /// unknown, with a warning, and the loop's condition then takes the way a run that ends
    /// takes. False when there is no such variable, or all are unknown already.
    fn waits_for_outside(&mut self, interp: &mut Interpreter<'a>, range: TextRange, diags: &mut Vec<Diagnostic>) -> bool {
        // `cond_reads` holds outside variables only (see `note_reads`).
        let mut waited: Vec<u32> =
            self.cond_reads.iter().copied().filter(|&n| interp.params.get(f64::from(n)).is_ok_and(|v| !eval::is_unknown(v))).collect();
        waited.sort_unstable();
        if waited.is_empty() {
            return false;
        }
        let sigil = self.dialect.lexical.parameter.map_or('#', |(c, _)| c);
        let names: Vec<String> = waited.iter().map(|n| format!("{sigil}{n}")).collect();
        for &n in &waited {
            let _ = interp.params.set(f64::from(n), eval::UNKNOWN);
        }
        interp.params.take_unknown_read();
        self.cond_reads.clear();
        self.round_guessed = false;
        let msg = format!(
            "the loop waits for {} to change: nothing in the program changes it, so something outside it must (the PLC, a robot, a remote client); taken as changed: the loop is left, as a run that ends leaves it",
            names.join(", ")
        );
        diags.push(Diagnostic::new(Code::WaitLoop, range, msg));
        true
    }

    /// A loop that comes round alike while its round took a way at a condition on a value
    /// unknown here (the control's data, `IF $A_DBB[2]==1 GOTOF END` … `GOTOB LOOP`; the
    /// caller's): it waits for that value, which the machine changes. The way out is not known:
    /// said with a warning, and the analysis follows the run no further. False when no
    /// condition of the round was unknown.
    fn waits_on_unknown(&mut self, range: TextRange, diags: &mut Vec<Diagnostic>) -> bool {
        if !self.round_guessed {
            return false;
        }
        let msg = "the loop comes round alike while its conditions read values unknown here (the control's data, the caller's): it waits for them to change, as the machine does; where it leaves is not known, and the analysis follows the run no further";
        diags.push(Diagnostic::new(Code::WaitLoop, range, msg));
        self.stop = true;
        true
    }

    fn top_loop(&self, pred: impl Fn(&Loop) -> bool) -> Option<usize> {
        let base = self.frames.last().map_or(0, |f| f.loops_base);
        (base..self.loops.len()).rev().find(|&k| pred(&self.loops[k]))
    }

    /// The label a statement names: its string or name, or its number (`LBL 5`, `GOTO LBL 5`).
    fn target_label(&self, c: &Control, block: &Block, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) -> Option<String> {
        if let Some(r) = c.name {
            return Some(normalise_label(block.text(r)));
        }
        let v = self.value(interp, block, c.target?, diags)?;
        (!eval::is_null(v) && v.fract() == 0.0 && v.abs() < 1e9).then(|| integer_label(v as i64))
    }

    /// Jumps to a found target; a jump backwards counts against the loop limit, and stops
    /// the run when the round before it changed nothing.
    fn jump_to(&mut self, pos: Pos, what: &str, range: TextRange, start: Pos, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        if pos.at <= start.at {
            let key = (self.cur, pos.at);
            let count = self.back_jumps.entry(key).or_insert(0);
            *count += 1;
            let count = *count;
            let limit = self.profile.max_loop_iterations;
            let over = count > limit;
            if over || (self.endless(key, count, interp) && !self.waits_for_outside(interp, range, diags)) {
                if !over && self.waits_on_unknown(range, diags) {
                    return;
                }
                // Back to the main program's first label, with nothing open: the program runs
                // until the operator stops it, by design (a cell's loop), as a return in a
                // main program restarts it.
                let cur = self.cur;
                // The target is a label (`START:`), and no label comes before it.
                let marks = self.marks(cur);
                let labelled = marks.iter().any(|m| m.defines.is_some() && (m.start.at == pos.at || m.next.at == pos.at));
                let first_label = labelled && !marks.iter().any(|m| m.defines.is_some() && m.next.at < pos.at && m.start.at < pos.at);
                if cur == 0 && self.frames.is_empty() && self.loops.is_empty() && first_label {
                    let msg = format!(
                        "the jump back to {what} restarts the program from its first label: a program that runs until the operator stops it (a cell's loop); the analysis stops here"
                    );
                    let mut d = Diagnostic::new(Code::LoopLimit, range, msg);
                    d.severity = Severity::Warning;
                    diags.push(d);
                    self.stop = true;
                } else if over {
                    let msg = format!("the jump back to {what} ran more than {limit} times; the run stops here");
                    self.error(diags, Code::LoopLimit, range, msg);
                } else {
                    self.error(diags, Code::LoopLimit, range, format!("the jump back to {what} comes round {ENDLESS}; the run stops here"));
                }
                return;
            }
        }
        if pos.at <= start.at {
            self.cond_reads.clear();
            self.round_guessed = false;
        }
        self.jump(self.cur, pos, start, interp, diags);
    }

    /// Whether pass `count` of the backward jump or loop end `key` finds everything as the
    /// pass before it left it: every parameter, mode and call level. The run is then
    /// deterministic and repeats for ever. The state is kept at passes 1, 2, 4, 8, ... and
    /// every 4096th, so a loop that changes nothing stops within a few rounds, at the cost
    /// of a copy of the modes now and then.
    fn endless(&mut self, key: (usize, usize), count: u64, interp: &Interpreter<'a>) -> bool {
        if let Some(r) = &self.round
            && r.key == key
            && r.pass + 1 == count
            && r.open == self.open()
            && interp.same_round(&r.state)
        {
            return true;
        }
        if count.is_power_of_two() || count % 4096 == 0 {
            self.round = Some(Round { key, pass: count, open: self.open(), state: interp.round_state() });
        }
        false
    }

    /// The calls open (where each returns to, and its repeats left) and the loops open (where
    /// each comes round to, and its rounds left): where the run goes after this point.
    fn open(&self) -> Vec<(usize, usize, u64)> {
        let calls = self.frames.iter().map(|f| (f.ret_source, f.ret.at, u64::from(f.repeats_left)));
        calls.chain(self.loops.iter().map(|l| (l.source, l.head.at, l.remaining))).collect()
    }

    /// How many times a call runs, from its repeat word.
    fn passes(&self, c: &Control, block: &Block, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) -> Option<u32> {
        let Some(e) = c.repeat else { return Some(1) };
        let v = self.value(interp, block, e, diags)?;
        if eval::is_null(v) || v < 0.0 || v.fract() != 0.0 || v > 65_535.0 {
            diags.push(Diagnostic::new(Code::MalformedNumber, c.range, format!("repeat count {v} is not a whole number from 0 to 65535")));
            return None;
        }
        let n = v as u32;
        Some(if self.dialect.macros.call_repeat_additional { n + 1 } else { n })
    }

    /// A loop head, met for the first time or again: counts the iteration, or enters the
    /// loop, or (when the condition is false) drops it. True when the loop is to be left.
    #[allow(clippy::too_many_arguments)]
    fn loop_head(
        &mut self,
        kind: LoopKind,
        label: &Option<String>,
        id: Option<i64>,
        cond: bool,
        start: Pos,
        here: Pos,
        range: TextRange,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) -> bool {
        let again = self.top_loop(|l| l.kind == kind && l.head == start);
        match (cond, again) {
            (true, Some(k)) => {
                self.count_iteration(k, range, interp, diags);
                false
            }
            (true, None) => {
                // Copied only here: a loop's head comes again in every pass.
                self.push_loop(kind, label.clone(), id, start, here);
                false
            }
            (false, again) => {
                if let Some(k) = again {
                    self.loops.truncate(k);
                }
                true
            }
        }
    }

    /// Back to loop `k`'s head (to test it again) or body, dropping the loops inside it.
    fn loop_jump(&mut self, k: usize, part: LoopPart, start: Pos, interp: &mut Interpreter<'a>, diags: &[Diagnostic]) {
        let l = &self.loops[k];
        let (src, to) = (l.source, if part == LoopPart::Head { l.head } else { l.body });
        self.loops.truncate(k + 1);
        self.jump(src, to, start, interp, diags);
    }

    fn push_loop(&mut self, kind: LoopKind, label: Option<String>, id: Option<i64>, head: Pos, body: Pos) {
        self.loops.push(Loop { kind, label, id, source: self.cur, head, body, remaining: 0, iterations: 0 });
    }

    fn loop_id(&self, c: &Control, block: &Block, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) -> Option<i64> {
        let v = self.value(interp, block, c.target?, diags)?;
        (!eval::is_null(v)).then(|| v.round() as i64)
    }

    fn unmatched(&mut self, c: &Control, what: &str, opener: &str, diags: &mut Vec<Diagnostic>) {
        diags.push(Diagnostic::new(Code::UnmatchedStatement, c.range, format!("`{what}` without an open {opener}; ignored")));
    }

    /// The end of one pass of a counted loop, at its `endrepeat` or at a `continue`.
    fn next_repeat(
        &mut self,
        k: usize,
        at_end: bool,
        start: Pos,
        range: TextRange,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        self.loops[k].remaining = self.loops[k].remaining.saturating_sub(1);
        if self.loops[k].remaining > 0 {
            if self.count_iteration(k, range, interp, diags) {
                self.loop_jump(k, LoopPart::Body, start, interp, diags);
            }
            return;
        }
        let label = self.loops[k].label.clone();
        self.loops.truncate(k);
        if !at_end {
            self.skip_to(start, range, "endrepeat", |m| m.label == label && m.statement == Some(Statement::EndRepeat), interp, diags);
        }
    }

    /// After a false condition: the next `elseif`/`else` of the same label, or past `endif`.
    fn next_branch(
        &mut self,
        label: &Option<String>,
        start: Pos,
        range: TextRange,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let m = self.find_structure_end(
            label,
            start.at,
            Statement::If,
            Statement::EndIf,
            &[Statement::ElseIf, Statement::Else, Statement::EndIf],
        );
        match m {
            Some(m) if m.statement == Some(Statement::EndIf) => self.switch_to(self.cur, m.next, interp),
            Some(m) => {
                self.landing = Some((self.cur, m.start.at));
                self.switch_to(self.cur, m.start, interp);
            }
            None => self.error(diags, Code::MissingLabel, range, "no matching `endif` follows this `if`; the run stops here"),
        }
    }

    /// The dialect's keywords that may follow an `IF` condition (`GOTO` or `THEN`), for a
    /// finding.
    pub(super) fn if_forms(&self) -> String {
        let mut forms: Vec<String> = self
            .dialect
            .macros
            .statements
            .iter()
            .filter(|(_, st)| matches!(st, Statement::Goto | Statement::Then))
            .map(|(k, _)| format!("`{k}`"))
            .collect();
        forms.dedup();
        if forms.is_empty() { "a jump".to_owned() } else { forms.join(" nor ") }
    }

    /// The first of `targets` after `after` that belongs to the structure opened there: by
    /// label where statements carry one (`o100 endif`), else by nesting depth, counting
    /// `open` ... `close` pairs in between (`IF` ... `ENDIF` inside `IF` ... `ELSE`).
    fn find_structure_end(
        &mut self,
        label: &Option<String>,
        after: usize,
        open: Statement,
        close: Statement,
        targets: &[Statement],
    ) -> Option<Mark> {
        if label.is_some() {
            return self.find_after(after, |m| m.label == *label && m.statement.is_some_and(|s| targets.contains(&s)));
        }
        let marks = self.marks(self.cur);
        let from = marks.partition_point(|m| m.start.at <= after);
        let mut depth = 0u32;
        for m in &marks[from..] {
            let Some(st) = m.statement.filter(|_| m.label.is_none()) else { continue };
            if depth == 0 && targets.contains(&st) {
                return Some(m.clone());
            }
            if st == open && m.then.is_none() {
                depth += 1;
            } else if st == close {
                depth = depth.saturating_sub(1);
            }
        }
        None
    }

    /// Continues after the end of the structure opened at `start` (see [`Self::find_structure_end`]).
    #[allow(clippy::too_many_arguments)]
    fn skip_structure(
        &mut self,
        label: &Option<String>,
        start: Pos,
        range: TextRange,
        open: Statement,
        close: Statement,
        targets: &[Statement],
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        match self.find_structure_end(label, start.at, open, close, targets) {
            Some(m) => self.switch_to(self.cur, m.next, interp),
            None => {
                let what = targets.last().map_or("end", |s| s.as_str());
                self.error(diags, Code::MissingLabel, range, format!("no matching `{what}` follows; the run stops here"));
            }
        }
    }

    /// Continues after the first mark that `pred` accepts.
    fn skip_to(
        &mut self,
        start: Pos,
        range: TextRange,
        what: &str,
        pred: impl Fn(&Mark) -> bool,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        match self.find_after(start.at, pred) {
            Some(m) => self.switch_to(self.cur, m.next, interp),
            None => self.error(diags, Code::MissingLabel, range, format!("no matching `{what}` follows; the run stops here")),
        }
    }

    /// After `WHILE [false] DO m`: past the matching `END m`, counting nested loops of the
    /// same number.
    fn skip_numbered_end(
        &mut self,
        id: Option<i64>,
        start: Pos,
        range: TextRange,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let marks = self.marks(self.cur);
        let from = marks.partition_point(|m| m.start.at <= start.at);
        let mut depth = 0u32;
        let mut found = None;
        for m in &marks[from..] {
            let opens = m.id == id && (m.then == Some(Statement::Do) || (m.statement == Some(Statement::Do) && m.label.is_none()));
            if opens {
                depth += 1;
            } else if m.id == id && m.statement == Some(Statement::EndDo) {
                if depth == 0 {
                    found = Some(m.next);
                    break;
                }
                depth -= 1;
            }
        }
        match found {
            Some(next) => self.switch_to(self.cur, next, interp),
            None => {
                let n = id.map_or_else(|| "?".to_owned(), |n| n.to_string());
                self.error(diags, Code::MissingLabel, range, format!("no `END {n}` closes this loop; the run stops here"));
            }
        }
    }

    /// The block number a jump names (`GOTO 10`, `GOTO #1`).
    fn target_number(
        &mut self,
        target: Option<ExprId>,
        block: &Block,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<u32> {
        let Some(e) = target else {
            self.error(diags, Code::MissingLabel, block.range, "the jump has no target");
            return None;
        };
        let v = self.value(interp, block, e, diags)?;
        if eval::is_unknown(v) {
            // `GOTO [#4 + 10]` on the caller's arguments: the block it goes to is the control's
            // to know. The run follows it no further, and that is no fault of the program.
            let what = interp.unknown_what();
            let msg = format!("the jump's target reads {what}: where it goes is not known here, and the analysis follows it no further");
            diags.push(Diagnostic::new(Code::UnknownValue, block.range, msg));
            self.stop = true;
            return None;
        }
        if eval::is_null(v) || v < 0.0 || v.fract() != 0.0 || v > 99_999_999.0 {
            self.error(diags, Code::MissingLabel, block.range, format!("jump target {v} is not a block number"));
            return None;
        }
        Some(v as u32)
    }

    /// Where the blocks numbered `n` start in source `source`, in text order (found once).
    fn numbered_blocks(&mut self, source: usize, n: u32) -> &[Pos] {
        let dialect = self.dialect;
        let src = &mut self.sources[source];
        let text = src.text;
        src.numbers.entry(n).or_insert_with(|| numbered(text, dialect, n))
    }

    /// Jumps to the block numbered `n`: forward from here, backward, or forward and then
    /// from the top. A missing block stops the run, unless the jump is `quiet`.
    #[allow(clippy::too_many_arguments)]
    fn goto_number(
        &mut self,
        n: u32,
        dir: Direction,
        quiet: bool,
        range: TextRange,
        start: Pos,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        let positions = self.numbered_blocks(self.cur, n);
        let pick = match dir {
            Direction::Forward => positions.iter().find(|p| p.at > start.at),
            Direction::Back => positions.iter().rev().find(|p| p.at < start.at),
            Direction::Any => positions.iter().find(|p| p.at > start.at).or(positions.first()),
        }
        .copied();
        let Some(pos) = pick else {
            if !quiet {
                self.error(
                    diags,
                    Code::MissingLabel,
                    range,
                    format!("no block N{n} to jump to; the run stops here, as the control would alarm"),
                );
            }
            return;
        };
        self.jump_to(pos, &format!("N{n}"), range, start, interp, diags);
    }

    /// Sets the dialect's return-value parameters (`_value`, `_value_returned`), if it has them.
    fn set_return_value(dialect: &Dialect, interp: &mut Interpreter<'_>, v: f64, returned: bool) {
        if let Some(name) = &dialect.macros.return_value {
            interp.params.set_named(name, v);
            interp.params.set_named(&format!("{name}_returned"), f64::from(u8::from(returned)));
        }
    }

    /// Where a called program's body starts: after the first mark `starts` accepts in this
    /// source or the main program, else in the file `name` from the [`ProgramSource`] (after
    /// such a mark, or at its top).
    fn locate(&mut self, name: &str, starts: impl Fn(&Mark) -> bool) -> Option<(usize, Pos)> {
        for source in [self.cur, 0] {
            if let Some(m) = self.marks(source).iter().find(|m| starts(m)) {
                return Some((source, m.next));
            }
        }
        let source = self.load(name)?;
        let body = self.marks(source).iter().find(|m| starts(m)).map_or(Pos { at: 0, line: 1 }, |m| m.next);
        Some((source, body))
    }

    /// Loads subprogram `name` through the [`ProgramSource`] (once); returns its source index.
    fn load(&mut self, name: &str) -> Option<usize> {
        if let Some(k) = self.sources.iter().position(|s| s.name == name) {
            return Some(k);
        }
        if self.not_found.contains(name) {
            return None;
        }
        let Some(text) = self.programs.load(name) else {
            self.not_found.insert(name.to_owned());
            return None;
        };
        let text: &'a str = self.arena.alloc(text);
        self.sources.push(Source::new(Text::Whole(text), name.to_owned()));
        Some(self.sources.len() - 1)
    }

    #[allow(clippy::too_many_arguments)]
    fn enter(
        &mut self,
        kind: FrameKind,
        source: usize,
        body: Pos,
        repeats: u32,
        args: Vec<(u16, f64)>,
        locals: bool,
        block: &Block,
        start: Pos,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) {
        if self.frames.len() as u32 >= self.dialect.macros.call_depth {
            let depth = self.dialect.macros.call_depth;
            self.error(diags, Code::CallDepth, block.range, format!("calls are nested deeper than {depth} levels; the run stops here"));
            return;
        }
        if repeats == 0 {
            return;
        }
        let (first, last) = self.dialect.macros.locals;
        let reset = if self.dialect.macros.null_value { NULL } else { 0.0 };
        let saved_locals = locals.then(|| interp.params.push_locals(first, last, reset));
        let saved_names = (locals && kind == FrameKind::Sub).then(|| interp.params.take_local_names());
        for &(n, v) in &args {
            let _ = interp.params.set(f64::from(n), v);
        }
        let (origin, line) = interp.origin_override.unwrap_or((block.range, block.line));
        self.frames.push(Frame {
            kind,
            ret_source: self.cur,
            ret: self.pos(),
            source,
            body,
            repeats_left: repeats,
            args,
            saved_locals,
            saved_names,
            loops_base: self.loops.len(),
            call: (origin, line),
            call_at: (self.cur, start.at),
            proc_args: None,
            until: usize::MAX,
        });
        interp.depth = self.frames.len() as u32;
        self.jump(source, body, start, interp, diags);
    }

    fn request(&mut self, r: Request, block: &Block, interp: &mut Interpreter<'a>, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let start = Pos { at: block.range.start as usize, line: block.line };
        match r {
            Request::Call { program, repeats, macro_call, args, start: first } => {
                let starts = |m: &Mark| m.program == Some(program) && m.statement.is_none();
                let Some((source, mut body)) = self.locate(&format!("O{program:04}"), starts) else {
                    let name = format!("program O{program:04}");
                    if self.dialect.behaviour.resident_programs {
                        diags.push(self.program_not_found(name, block.range));
                    } else {
                        let msg = format!("{name} is neither in this file nor in the program directory");
                        self.error(diags, Code::MissingLabel, block.range, msg);
                    }
                    return;
                };
                if let Some(n) = first {
                    let Some(at) = self.numbered_blocks(source, n).iter().find(|p| p.at >= body.at).copied() else {
                        self.error(diags, Code::MissingLabel, block.range, format!("program O{program:04} has no block N{n} to start at"));
                        return;
                    };
                    body = at;
                }
                self.enter(FrameKind::Program, source, body, repeats, args, macro_call, block, start, interp, diags);
            }
            Request::CallLocal { number, repeats } => {
                let Some(&body) = self.numbered_blocks(self.cur, number).first() else {
                    self.error(diags, Code::MissingLabel, block.range, format!("no block N{number} in this file to call"));
                    return;
                };
                self.enter(FrameKind::Program, self.cur, body, repeats, Vec::new(), false, block, start, interp, diags);
            }
            Request::Remap { sub } => {
                let is_sub = |m: &Mark| m.label.as_deref() == Some(sub.as_str()) && m.statement == Some(Statement::Sub);
                let Some((source, body)) = self.locate(&sub, is_sub) else {
                    let msg = format!(
                        "the machine's configuration ({}) remaps this code to o<{sub}>, which is not on its subroutine path: this analysis skips the call and lacks what it does",
                        interp.profile.machine.source
                    );
                    let mut d = Diagnostic::new(Code::MissingProgram, block.range, msg);
                    d.severity = Severity::Warning;
                    interp.limited(diags, "program", d);
                    return;
                };
                self.enter(FrameKind::Sub, source, body, 1, Vec::new(), true, block, start, interp, diags);
            }
            Request::Return { goto } => {
                if self.frames.is_empty() {
                    self.main_return(block, interp, sink, diags);
                    return;
                }
                self.return_from(goto, block, interp, diags);
            }
            Request::Contour { first, last, rough } => self.contour(first, last, rough, block, interp, sink, diags),
            Request::Profile { name, cycle } => self.profile(&name, cycle, block, interp, sink, diags),
            Request::NamedContour { name, job } => self.named_contour(&name, &job, block, interp, sink, diags),
            Request::CylinderContour { name, job } => self.cylinder_contour(&name, &job, block, interp, sink, diags),
        }
    }

    /// A lathe cycle's contour, the blocks numbered `first` to `last` after the cycle's
    /// block: for roughing, run without effect to read its shape (the state is put back),
    /// roughed out, and skipped; for finishing, run as written, and the tool back to where
    /// it started.
    #[allow(clippy::too_many_arguments)]
    fn contour(
        &mut self,
        first: u32,
        last: Option<u32>,
        rough: Option<super::cycle::Rough>,
        block: &Block,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        /// Blocks a contour may have at most.
        const MAX_CONTOUR_BLOCKS: usize = 100_000;
        // A roughing cycle's contour follows it; a finishing cycle's is usually before it.
        let after = block.range.end as usize;
        let blocks = self.numbered_blocks(self.cur, first);
        let found = blocks.iter().find(|p| p.at >= after).or(if rough.is_none() { blocks.first() } else { None }).copied();
        let Some(from) = found else {
            // The control searches the program for the block P names and stops with an
            // alarm where it finds none: no contour is run, roughed or guessed.
            let msg = format!(
                "no block N{first} after this cycle starts its contour: the control stops here with an alarm (the sequence number P names is not found)"
            );
            self.error(diags, Code::MissingLabel, block.range, msg);
            return;
        };
        let start = interp.st.pos;
        // Reading a contour changes nothing: the modal state, the parameters and the
        // compensation and corner stages (which would hold its moves back) are put back.
        let saved = rough.map(|_| {
            let corners = interp.corners.replace(None);
            (interp.st.clone(), interp.params.clone(), interp.comp.borrow().clone(), corners, interp.comp_problem.take())
        });
        let mut intent = interp.turn_intent.take();
        if let Some(t) = intent.as_mut() {
            // The blocks P and Q name, for pairing a finishing cycle with its roughing.
            let to = last.and_then(|n| self.numbered_blocks(self.cur, n).iter().find(|p| p.at >= from.at).map(|p| p.at));
            t.contour = Some([from.at, to.unwrap_or(from.at)].map(|at| u32::try_from(at).unwrap_or(u32::MAX)));
        }
        if rough.is_none()
            && let Some(t) = intent.clone()
        {
            interp.emit(sink, CanonOp::Turning(t));
        }
        let mut parser = self.parser.fork(self.sources[self.cur].text, from.at, from.line);
        let mut shape: Vec<Canon> = Vec::new();
        let known = interp.known_state();
        let mut b = Block::default();
        let mut end = None;
        for _ in 0..MAX_CONTOUR_BLOCKS {
            if !parser.next_block(&mut b, diags) {
                break;
            }
            // The contour's blocks count towards the run's budget, as any block run does.
            if self.over_block_budget(b.range, diags) {
                break;
            }
            if rough.is_some() {
                interp.execute(&b, &mut shape, diags);
            } else {
                interp.execute(&b, sink, diags);
            }
            // A contour holds moves only; a call in it is not followed.
            interp.request = None;
            let ends = match last {
                Some(n) => b.number == Some(n),
                None => self.ends_contour(&b),
            };
            if ends {
                end = Some(Pos { at: parser.offset(), line: parser.line() });
                break;
            }
        }
        if let Some((st, params, comp, corners, problem)) = saved {
            interp.restore_known(known);
            interp.st = st;
            interp.params.restore_values(params);
            interp.comp.replace(comp);
            interp.corners.replace(corners);
            interp.comp_problem.set(problem);
        }
        let Some(end) = end else {
            let msg = match last {
                Some(last) => format!("no block N{last} after N{first} ends this cycle's contour"),
                None => format!("no end of the contour definition after N{first} ends this cycle's contour"),
            };
            self.error(diags, Code::MissingLabel, block.range, msg);
            return;
        };
        // The cycle's own moves come from the cycle's block.
        (interp.origin, interp.line) = (block.range, block.line);
        match rough {
            Some(r) => {
                if let Some(t) = intent {
                    interp.emit(sink, CanonOp::Turning(t));
                }
                interp.rough_turn(r, start, &shape, sink, diags);
                self.switch_to(self.cur, end, interp);
            }
            // A contour defined where the cycle stands is left behind; one named by its block
            // numbers is finished from the start point and back to it.
            None if last.is_none() => self.switch_to(self.cur, end, interp),
            None => interp.back_to(start, sink),
        }
        interp.emit(sink, CanonOp::TurningEnd);
    }

    /// A lathe profile cycle (LinuxCNC G70–G72): the subroutine `name`'s blocks are run
    /// without effect from the cycle's start point to read the profile (the state is put
    /// back), then the cycle cuts it.
    fn profile(
        &mut self,
        name: &str,
        cycle: super::g7x::Cycle,
        block: &Block,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let label = normalise_label(name);
        let is_sub = |m: &Mark| m.label.as_deref() == Some(label.as_str()) && m.statement == Some(Statement::Sub);
        let Some((source, body)) = self.locate(&label, is_sub) else {
            let msg = format!("the profile subroutine o<{label}> (Q) is neither in this program nor in the program directory");
            self.error(diags, Code::MissingLabel, block.range, msg);
            return;
        };
        let corners = interp.corners.replace(None);
        let saved = (interp.st.clone(), interp.params.clone(), interp.comp.borrow().clone(), corners, interp.comp_problem.take());
        interp.comp.replace(None);
        let start = interp.st.pos;
        (interp.st.pos[0], interp.st.pos[2]) = (cycle.x, cycle.z);
        // The cycle's move to its start point leaves G0 in force for the profile's blocks.
        interp.st.motion_code = self.dialect.codes.iter().position(|c| c.letter == 'G' && c.meaning == crate::dialect::Meaning::Rapid);
        let (shape, finishes) = self.profile_blocks(source, body, usize::MAX, interp, diags);
        let (st, params, comp, corners, problem) = saved;
        interp.st = st;
        interp.params.restore_values(params);
        interp.comp.replace(comp);
        interp.corners.replace(corners);
        interp.comp_problem.set(problem);
        interp.st.pos = start;
        (interp.origin, interp.line) = (block.range, block.line);
        interp.profile_run(cycle, &shape, &finishes, sink, diags);
    }

    /// Runs a profile subroutine's body from `body` in `source` to its end, into a shape
    /// buffer: its statements too (`o101 repeat [3]` round moves from `#<_x>`), by the run's
    /// own machinery on the subroutine's text; the run's cursor, loops and last round are put
    /// back afterwards. Returns the moves and the corners that A and C words ask to round or
    /// chamfer (index in the shape after the move, round or not, size). The run stops at
    /// `until` (an offset in `source`) too.
    #[allow(clippy::type_complexity)]
    fn profile_blocks(
        &mut self,
        source: usize,
        body: Pos,
        until: usize,
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) -> (Vec<Canon>, Vec<(usize, bool, f64)>) {
        /// Blocks a profile may have at most.
        const MAX_PROFILE_BLOCKS: usize = 100_000;
        let fork = self.parser.fork(self.sources[source].text, body.at, body.line);
        let outer = (std::mem::replace(&mut self.parser, fork), std::mem::replace(&mut self.cur, source));
        let (loops, frames, round, origin) = (self.loops.len(), self.frames.len(), self.round.take(), interp.origin_override);
        let mut shape: Vec<Canon> = Vec::new();
        let known = interp.known_state();
        let mut finishes = Vec::new();
        let mut b = Box::<Block>::default();
        for _ in 0..MAX_PROFILE_BLOCKS {
            let at = self.pos();
            if at.at >= until && self.frames.len() <= frames {
                break;
            }
            let src = self.cur;
            let mark = diags.len();
            if !self.next_block(&mut b, at, interp, false, diags) {
                break;
            }
            let end = b.control.as_ref().is_some_and(|c| matches!(c.statement, Some(Statement::EndSub | Statement::Return)));
            if end && self.frames.len() <= frames {
                break;
            }
            if self.over_block_budget(b.range, diags) {
                break;
            }
            if let Some(control) = b.control.take() {
                self.control(&control, &b, at, interp, &mut shape, diags);
                b.control = Some(control);
            } else {
                let before = shape.len();
                interp.execute(&b, &mut shape, diags);
                // A and C words on a profile's move ask for a rounded or chamfered corner.
                let moved = shape[before..]
                    .iter()
                    .any(|c| matches!(c.op, CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. }));
                let finish =
                    interp.slot(crate::dialect::Role::A).map(|a| (true, a)).or(interp.slot(crate::dialect::Role::C).map(|c| (false, c)));
                if let (true, Some((round, size))) = (moved, finish) {
                    finishes.push((shape.len(), round, size));
                }
            }
            interp.request = None;
            self.tidy(src, mark, diags);
            if self.stop || interp.finished() {
                break;
            }
        }
        self.loops.truncate(loops);
        self.frames.truncate(frames);
        interp.depth = self.frames.len() as u32;
        (self.parser, self.cur) = outer;
        self.round = round;
        interp.origin_override = origin;
        interp.restore_known(known);
        (shape, finishes)
    }

    /// Returns from the innermost call, or runs its body again while repeats are left.
    fn return_from(&mut self, goto: Option<u32>, block: &Block, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        let start = Pos { at: block.range.start as usize, line: block.line };
        let Some(f) = self.frames.last_mut() else { return };
        if f.repeats_left > 1 {
            f.repeats_left -= 1;
            let (source, body) = (f.source, f.body);
            let (first, last) = self.dialect.macros.locals;
            if f.saved_locals.is_some() {
                let reset = if self.dialect.macros.null_value { NULL } else { 0.0 };
                let _ = interp.params.push_locals(first, last, reset);
                for &(n, v) in &f.args {
                    let _ = interp.params.set(f64::from(n), v);
                }
            }
            self.loops.truncate(f.loops_base);
            self.jump(source, body, start, interp, diags);
            return;
        }
        let Some(f) = self.frames.pop() else { return };
        interp.left_level = Some(self.frames.len() + 1);
        interp.depth = self.frames.len() as u32;
        if let Some(saved) = &f.saved_locals {
            interp.params.restore(self.dialect.macros.locals.0, saved);
        }
        if let Some(names) = f.saved_names {
            interp.params.restore_named(names);
        }
        self.loops.truncate(f.loops_base);
        self.switch_to(f.ret_source, f.ret, interp);
        if let Some(n) = goto {
            let here = self.pos();
            self.goto_number(n, Direction::Any, false, block.range, here, interp, diags);
        }
    }

    /// A return in the main program: its end (a subprogram checked on its own), or on a
    /// control that restarts the program, the end of the analysis after one pass.
    fn main_return(&mut self, block: &Block, interp: &mut Interpreter<'a>, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        if self.cur == 0 && self.dialect.macros.return_tells_called {
            interp.called_by(|| "it ends with a return (M99, M17, RET), not a program end".to_owned());
        }
        if interp.is_called() {
            // A called program analysed on its own: its return ends the analysis.
            interp.program_end(sink);
            self.stop = true;
            return;
        }
        match self.dialect.macros.main_return {
            MainReturn::Restart => diags.push(Diagnostic::new(
                Code::Unsupported,
                block.range,
                "a return in the main program restarts it endlessly on the control; the analysis stops after one pass",
            )),
            MainReturn::End => interp.program_end(sink),
            MainReturn::Error => {
                diags.push(Diagnostic::new(Code::UnmatchedStatement, block.range, "a return without an open call; ignored"));
                return;
            }
        }
        self.stop = true;
    }

    /// The main program's text ran out: an error where the dialect requires an end, unless
    /// the file only defines subroutines.
    fn end_of_main(&mut self, interp: &Interpreter<'a>, diags: &mut Vec<Diagnostic>) {
        if interp.finished() || self.cur != 0 {
            return;
        }
        if !self.main_work {
            if self.library {
                let msg = "the file only defines subroutines: a library for other programs, with nothing to run by itself";
                diags.push(Diagnostic::new(Code::Library, TextRange::default(), msg));
            }
            return;
        }
        if !self.dialect.behaviour.end_required || interp.is_called() {
            return;
        }
        let end = self.sources[0].text.trimmed_end();
        let msg = if self.delimiters > 0 {
            "the file ends without the `%` that closes the program opened by the first line"
        } else {
            "the program runs off the end of the file without M2, M30 or a closing `%`"
        };
        diags.push(Diagnostic::new(Code::NoProgramEnd, TextRange::new(end, end), msg));
    }

    /// The end of a source text: the end of the run, or an implicit return from a
    /// subprogram. Returns false when the run is over.
    fn end_of_source(&mut self, interp: &mut Interpreter<'a>, diags: &mut Vec<Diagnostic>) -> bool {
        let Some(f) = self.frames.last() else { return false };
        let msg = match f.kind {
            FrameKind::Sub => "the called subroutine ends without endsub; it returns at the end of its text",
            FrameKind::Program => "the called program ends without its return (M99, M17, RET); it returns at the end of its text",
            FrameKind::Label => "the called section runs to the end of the program without its end label; it returns there",
            FrameKind::Section => "the repeated section runs to the end of the program (a jump left it); it returns there",
        };
        let (range, _) = f.call;
        diags.push(Diagnostic::new(Code::UnmatchedStatement, range, msg));
        let mut block = Block::default();
        (block.range, block.line) = (range, self.pos().line);
        if let Some(f) = self.frames.last_mut() {
            f.repeats_left = 1;
        }
        self.return_from(None, &block, interp, diags);
        true
    }
}

/// Sets the variable expression `var` (`R1`, `#5`, `COUNT`) to `v`.
fn set_variable(interp: &mut Interpreter<'_>, block: &Block, var: ExprId, v: f64) -> Result<(), eval::EvalError> {
    match block.exprs.get(var as usize) {
        Some(&Expr::Param(n)) => {
            let n = eval::eval(block, n, &interp.params)?;
            interp.params.set(n, v)
        }
        Some(&Expr::Named(r)) => {
            interp.params.set_named(&eval::normalised(block.text(r)), v);
            Ok(())
        }
        _ => Err(eval::EvalError::Domain("the loop counter is not a variable")),
    }
}

/// Indexes the control statements and program numbers of `text`.
/// Whether `block` is an `IF [..] THEN` with nothing after `THEN`, where the dictionary has
/// `ELSE`/`ENDIF` (Mazak's block IF): the lines up to the `ELSE` or `ENDIF` are its body.
fn block_if(block: &Block, c: &Control, dialect: &Dialect) -> bool {
    c.statement == Some(Statement::If)
        && c.then == Some(Statement::Then)
        && c.otherwise.is_none()
        && block.words.is_empty()
        && block.assigns.is_empty()
        && dialect.macros.statements.iter().any(|(_, st)| *st == Statement::EndIf)
}

fn index(text: Text<'_>, dialect: &Dialect) -> Vec<Mark> {
    let mut parser = Parser::new(text, dialect);
    let mut block = Block::default();
    let mut scratch = Vec::new();
    let mut marks = Vec::new();
    let mut delimiters = 0;
    loop {
        let start = Pos { at: parser.offset(), line: parser.line() };
        if !parser.next_block(&mut block, &mut scratch) {
            break;
        }
        scratch.clear();
        let next = Pos { at: parser.offset(), line: parser.line() };
        if block.delimiter {
            // Nothing after the closing `%` belongs to the program.
            delimiters += 1;
            if delimiters == 2 {
                break;
            }
        }
        if block.control.is_none() && block.program_number.is_none() && block.label.is_none() && block.program_name.is_none() {
            continue;
        }
        let c = block.control.as_ref();
        let literal = |e: Option<ExprId>| match e.and_then(|e| block.exprs.get(e as usize)) {
            Some(Expr::Num(v)) => Some(v.round() as i64),
            _ => None,
        };
        let name = c.and_then(|c| {
            let n = block.text(c.name?);
            // A procedure named by a number takes its keyword's name too: `%L 100` is `L100`.
            match c.keyword {
                Some(k) if c.statement == Some(Statement::Procedure) && n.starts_with(|ch: char| ch.is_ascii_digit()) => {
                    Some(normalise_label(&format!("{}{n}", block.text(k))))
                }
                _ => Some(normalise_label(n)),
            }
        });
        let defines = match c {
            Some(c) if c.statement == Some(Statement::Label) => {
                name.clone().or_else(|| literal(c.target).map(|n| normalise_label(&n.to_string())))
            }
            _ => block.label.map(|r| normalise_label(block.text(r))),
        };
        marks.push(Mark {
            label: c.and_then(|c| c.label).map(|r| normalise_label(block.text(r))),
            defines,
            name,
            statement: c.and_then(|c| c.statement),
            then: c.and_then(|c| c.then).filter(|_| !c.is_some_and(|c| block_if(&block, c, dialect))),
            id: c.and_then(|c| literal(c.target)),
            program: block.program_number.or_else(|| {
                // An O-word label alone on its line starts a numbered program (`O1000` + M99);
                // followed by anything else (`O1 #<dir> = 1`) it is an unknown control command.
                let c = c?;
                if c.keyword.is_some() || !alone(&block, c.range) {
                    return None;
                }
                block.text(c.label?).parse().ok()
            }),
            program_name: block.program_name.map(|r| normalise_label(block.text(r))),
            start,
            next,
        });
    }
    marks
}

/// Whether nothing but blanks and comments follows the statement at `r` in `block`.
fn alone(block: &Block, r: TextRange) -> bool {
    let last = block.range.end;
    let mut at = r.end.min(last);
    let mut comments: Vec<TextRange> = block.comments.iter().copied().filter(|c| c.end > r.end).collect();
    comments.sort_by_key(|c| c.start);
    for c in comments.iter().chain(std::iter::once(&TextRange { start: last, end: last })) {
        // A comment's range lies inside its delimiters: the byte before it opens it, the byte
        // after it (where there is one: `;` runs to the line's end) closes it.
        let gap = TextRange { start: at, end: c.start.saturating_sub(1).clamp(at, last) };
        if !block.text(gap).trim().is_empty() {
            return false;
        }
        at = at.max(c.end.saturating_add(1)).min(last);
    }
    true
}

/// The blocks of `text` numbered `n`.
fn numbered(text: Text<'_>, dialect: &Dialect, n: u32) -> Vec<Pos> {
    let mut parser = Parser::new(text, dialect);
    let mut block = Block::default();
    let mut scratch = Vec::new();
    let mut out = Vec::new();
    loop {
        let start = Pos { at: parser.offset(), line: parser.line() };
        if !parser.next_block(&mut block, &mut scratch) {
            break;
        }
        scratch.clear();
        if block.number == Some(n) {
            out.push(start);
        }
    }
    out
}

/// The line a Fanuc `DPRNT[...]` prints: characters as written, `*` as a space, and
/// `#n[ab]` as variable n with `a` integer and `b` decimal digits (leading zeros as spaces;
/// a vacant variable prints as blanks).
pub(super) fn print_format(format: &str, value: impl Fn(u32) -> Option<f64>) -> String {
    let inner = format.trim();
    let inner = inner.strip_prefix('[').unwrap_or(inner);
    let inner = inner.strip_suffix(']').unwrap_or(inner);
    let b = inner.as_bytes();
    let mut out = String::new();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            b'*' => {
                out.push(' ');
                i += 1;
            }
            b'#' => {
                let start = i + 1;
                let mut j = start;
                while j < b.len() && b[j].is_ascii_digit() {
                    j += 1;
                }
                let n: u32 = inner[start..j].parse().unwrap_or(0);
                let (mut int_digits, mut dec_digits) = (8usize, 0usize);
                if j < b.len() && b[j] == b'[' {
                    let close = inner[j..].find(']').map_or(b.len(), |p| j + p);
                    let spec = &inner[j + 1..close];
                    let digits: Vec<usize> = spec.bytes().filter(u8::is_ascii_digit).map(|d| usize::from(d - b'0')).collect();
                    int_digits = digits.first().copied().unwrap_or(8);
                    dec_digits = digits.get(1).copied().unwrap_or(0);
                    j = (close + 1).min(b.len());
                }
                let width = int_digits + 1 + if dec_digits > 0 { dec_digits + 1 } else { 0 };
                match value(n).filter(|v| !v.is_nan()) {
                    Some(v) => out.push_str(&format!("{v:>width$.dec_digits$}")),
                    None => out.push_str(&" ".repeat(width)),
                }
                i = j;
            }
            _ => {
                let ch = inner[i..].chars().next().unwrap_or(' ');
                out.push(ch);
                i += ch.len_utf8();
            }
        }
    }
    out
}

//! The modal interpreter: blocks → canonical ops, with modal state.
//!
//! Each block goes through *read* (evaluate values, look up codes, check groups and
//! parameters) and then *execute*, step by step in the order the dialect's
//! `<execution-order>` gives. Everything the interpreter knows about a dialect comes from
//! [`Dialect`]: meanings, roles and behaviour flags. It never fails: findings become
//! diagnostics and an erroneous block is skipped.
//!
//! This file holds the interpreter's state and [`Interpreter::execute`], which runs a block
//! through the phases, and the stages an op passes on its way to the sink. *Read* is
//! `read.rs`; *execute* is `exec/`, one file per group of meanings (`exec/mod.rs` lists
//! them); the moves are `motion.rs`, the cycles `cycle.rs`, `define.rs`, `g7x.rs` and
//! `lathe.rs` (Fanuc's two-block G74, G75 and G76, expanded into their passes). A lathe
//! cycle's moves are said between `CanonOp::Turning` (with the values it states) and
//! `CanonOp::TurningEnd`, and the diameter mode by a `Setting::DiameterMode` marker. The
//! driver that feeds blocks and carries out control flow (calls, loops, jumps) is `flow`
//! ([`run`]).
//!
//! `Interpreter::execute`: *read* (evaluate, look up codes, check modal groups and
//! parameters) then the dialect's `<execution-order>` steps. A non-motion code claims the axis
//! words its parameter lists name (`G4 X1.5`, `G10 L2 X`), so the modal move does not take them.
//! *Read* also halves X words in diameter mode (the block's own G7/G8 counts), so every command
//! sees radii; the plane starts at the dictionary's `initial-plane` and returns to it at the
//! program's end. `eval.rs` parameters and
//! expressions (a dense table below #10000 and a sparse one above it, up to the dictionary's
//! `highest-variable`: Haas #10000+, Mitsubishi #900000+; vacant `#0` values as NaN; a field of machine data read with a fraction (`#30057.25`) unknown as the whole is; *unknown* values, from outside the file, as a NaN
//! with its own payload that arithmetic keeps unknown, `eval::UNKNOWN`); `motion.rs` lines and arcs; `cycle.rs` canned cycles
//! expanded as LinuxCNC does (tapping and boring variants by dialect behaviour; K in a
//! drilling cycle's block is a count, never scaled as least increments — unless the code's
//! `args` give K the role `p`, as Fagor's `K:p`: then K is the dwell, P's role; without R, Fanuc
//! feeds from the initial level with a warning, `cycle-without-r`), wrapped in
//! `CycleBegin`/`CycleEnd` (`cycle::hole` expands one hole for every cycle style); `define.rs`
//! defined cycles (a reference plane, safety distance, depth and retract plane instead of R and
//! Z; called where written, by `CYCL CALL`/`M99`, or after every move while `MCALL` is on; hole
//! patterns — `pattern-row`, `pattern-circle`, `pattern-grid` — approach each position and
//! run the modal cycle there, leaving it defined; a code that states a pattern, such as Haas
//! G70, has the G8x cycle in force drill at each position, `code_pattern`) and
//! the programmable frame (`TRANS`/`ROT`/`SCALE`, kept with G52, G68 and G51); `motion.rs` also
//! runs a lathe's single-pass cycles (`single_pass_cycle`: G90, G94, G92); `g7x.rs` runs
//! LinuxCNC's profile cycles (`profile-finish`, `profile-rough-turn`, `profile-rough-face`:
//! G70, G71/G71.1/G71.2, G72/G72.1/G72.2; the code's `index` says what is done with pockets)
//! on the O-word subroutine named by Q, which `flow`'s `profile` runs without effect from
//! the cycle's start point, its statements (loops, branches) by the run's own machinery
//! (`profile_blocks`) (A and C words on its moves ask for a rounded or chamfered
//! corner), worked out as rs274 works them out (offset by D in steps, turned so that Z and X
//! fall, cut level by level with a 45° retract R; complex numbers, Z real and X imaginary),
//! so that the canon agrees with rs274 to 1e-4; `cycle.rs` roughs a
//! lathe contour (`rough_turn`: Fanuc G71 and G72 type I in the two-block form, or the
//! one-block `G71 P Q U W D` of Haas and Fanuc 10/11/15 where the code's args name both
//! allowances, passes along Z or X to the contour
//! shifted by the allowances, worked out in (level, pass) coordinates, which `flow`'s `contour` reads by running its P–Q blocks into a buffer and
//! putting the state back), draws arcs about a pole (`CC` + `C`), by radius with a stated direction (`CR ... DR-`) and
//! tangent to the previous element (`CT`); `corner.rs` the stage before compensation where the
//! dictionary has corner blocks or approaches: it holds the last straight feed (and the ops
//! behind it) until the next move shows the corner, then rounds or chamfers it (`RND`, `CHF`),
//! and places an approach's auxiliary point once the first contour element gives its
//! direction (`APPR LT`/`LN`); `comp.rs` cutter radius compensation (G41/G42, G41.1/G42.1) in
//! XY or a lathe's ZX plane (Z first; a lathe tool's orientation `L1`–`L9` moves the
//! controlled point to the imaginary tip): offset lines and arcs, arcs round outside corners
//! (a rapid before a rapid), trims at inside corners, neither for a turn under 0.05 rad,
//! holding back one move and the ops behind it as LinuxCNC does. G68 rotation and G51 scaling
//! transform emitted moves (`Interpreter::transform`); G10 L2 R rotates a work coordinate
//! system as LinuxCNC does (canon stays in the rotated program frame; where the dictionary says
//! `position-after-tool-change="last-move"`, a block with a tool change leaves the program
//! position at the last move's end (`Interpreter::sent`), as rs274 reads it back after M6, so
//! a G43 beside the M6 does not shift it; `h0="spindle-tool"` makes `G43 H0` the spindle's tool; a tool-change keyword
//! whose value names no tool (`TOOL CALL Z S2000`) changes only the speed; `machine_pos` and
//! `program_pos` convert for G53, G28/G30 and L20, `switch_wcs` keeps the machine position).
//! Tool offsets are kept along X, Y and Z (G10 L1/L10/L11, worked out along a rotated
//! system's axes); G43 puts them in force and, the tool staying put, moves its program
//! position by them (`use_tool_offset`), as rs274 does.
//! G66 registers a macro the interpreter requests after every block that moves, at the call
//! depth it was registered at; `DPRNT` statements become `MESSAGE`s (`flow::print_format`). `flow` is the driver
//! (`run`): it feeds blocks to the interpreter and carries out calls (`o-call`, `G65`, `M98`),
//! returns, conditionals, loops and jumps by seeking the parser; on the first jump it indexes the
//! source's statements (not its blocks). Subprograms from other files come through the
//! `ProgramSource` trait, which the shell implements (`config::DirPrograms`); a name it does
//! not have is asked for once per run. Where the dictionary says the control keeps programs
//! in its memory (`resident-programs`), an explicit call to one not found is a warning and
//! the run goes on (`program_not_found`; also for a bare name that is no statement, such as
//! `TOL(0.1,1,1)` or `T_INI`, and `check --strict` makes these errors); LinuxCNC's calls stop
//! with an error, as rs274's do. Loop and block budgets stop runaway programs with
//! `flow::loop-limit`, and a loop that comes round with every parameter, mode and open call as
//! the round before left them stops at once, an error unless the jump goes back to the main
//! program's first label with nothing open (a cell's loop: a warning) (`Driver::endless` compares the interpreter's
//! `RoundState` at passes 1, 2, 4, … and every 4096th). Blocks and conditions read the system
//! variables (the position, the tool, the modes; LinuxCNC's `#5420` and `#<_x>`: `<system-variable>`)
//! as they are at the statement: `refresh_system_vars` sets those the block reads, and no others.
//! The analysis bound (`Profile::max_repeated_blocks` in time, `max_repeated_bytes` in memory;
//! `[analysis] max_seconds`, `max_memory_mb`) stops a run that would go on past it with
//! `flow::repeat-budget`, which every command says on stderr. A condition on an
//! unknown value (`unknown_condition`) takes the way whose first block raises no alarm
//! (`alarm_at`: `#3000=`, `FN 14: ERROR=`, `(abort, …)`; `fall_through` follows the way on
//! past moves to its first statement: into an alarm, or round the loop again by a jump that
//! is always taken, when the jump is the way out; the way from a jump's target is followed
//! the same way, past the spindle and coolant stops before an alarm, and a loop's end is
//! passed, as a run that ends leaves its loops), leaves a loop, or else the
//! dictionary's `unknown-conditions` (or `Profile::unknown_conditions`), with a note. An
//! `IF [..] THEN #30 = #24` on an unknown value runs, and what it sets holds either value:
//! unknown where it changed (`Interpreter::execute_either`). A block IF (`IF [..] THEN`
//! alone on its line, where the dictionary has `ENDIF`: Mazak) runs its body up to `ELSE` or
//! `ENDIF`. A jump to a block number computed from unknown values ends the run with a note. A
//! control block whose lexing found errors is skipped (`flow::broken-statement`), not run on
//! what was left of it. `Profile::role` says whether the file is a main program or a called
//! one; in `Auto` the run tells it from the form (`Interpreter::called_by`: a top-level
//! return where `return-tells-called`, a `PROC` header, an O-number in `called-programs`, an
//! argument read before written). Findings that only follow from the caller's missing state
//! (its feed, its spindle) are `interp::caller-state` notes meanwhile, and `finish` puts the
//! original findings back when nothing showed the file to be called. The same driver runs the Siemens and
//! Heidenhain statements the dictionary names: jumps to labels or block numbers (`GOTOF`,
//! `GOTOB`, `GOTO`, `GOTOC`, `GOTO LBL`), structured statements without labels, matched by
//! nesting depth (`find_structure_end`), `FOR`/`REPEAT…UNTIL`/`LOOP`, calls by name with `PROC`
//! arguments and passes, label calls (`FrameKind::Label`: a subprogram up to the end label,
//! or a section before the call that returns on meeting its call again), section repeats
//! (`FrameKind::Section`: `REPEAT A B P=n` runs again from label A's block until the driver
//! reaches the frame's `until` offset) and `CASE ... OF ... DEFAULT` jumps. `context.rs` keeps
//! the modal state saved per call level (M70/M73; M72 restores, M73 restores when the call
//! returns, through `left_level`, before the next block). `motion.rs` also expands LinuxCNC's
//! G76 threading cycle pass by pass (`threading_cycle`), makes probe moves (G38.x: the run goes
//! on backed off from the programmed end point by the dictionary's `probe-backoff` as rs274's
//! simulator does; the probe result variables, written once there, hold the end point and are
//! the program's to change, the tripped one the dictionary's `probe-tripped`, unknown unless a
//! dictionary says 1 or 0 (a loop on it ends as under rs274's never-tripping simulator, an
//! abort on no contact takes the successful way); a
//! quiet probe, `probe-quiet`, may have no length, another stops the run), draws
//! G5.1/G5.2–G5.3 splines as `NurbsFeed` (rs274's `NURBS_FEED(n, ...)`, ending at the last
//! control point; the plan follows the chord), places canned-cycle holes by polar words
//! (`@`/`^`, also in repeat-only blocks), and refuses an arc
//! as the first move after cutter compensation ends (`leaving_comp`). `fast.rs` is the fast
//! lane: a straight move of literal X/Y/Z words, perhaps with its own G0/G1 and an F, skips
//! *read* and the step dispatch and does what they would do (same state changes, same ops);
//! it leaves the block's slots and codes empty, since nothing after a plain move reads them
//! (`block_read` says when *read* has filled them since, so a run of plain moves clears
//! nothing), and sends its op straight to the sink where no call origin, transform, corner or
//! compensation stage stands between (`emit_straight`);
//! anything else, or `Profile::fast_lane = false`, goes the general way. In the main
//! program's first run (no call, loop, replay or definition block under way, past its first
//! blocks) such a line does not even become a `Block`: the driver's *plain lane* has the
//! parser read it into a fixed `PlainLine` (`Parser::plain_lines`, the same `plain_block`
//! loop), run it through the same core (`Interpreter::run_plain`, `plain_move`), and only
//! then move past it; a line the lane declines is read and run the general way from the same
//! place. The lane takes a whole *run* of plain lines in one call (`Driver::run_plain`): what
//! a plain move cannot change (the lane is open, the run is a first one, the repeat budget,
//! the interpreter's state, whether a stage stands before the sink: `Interpreter::plain_ready`
//! gives a `PlainRun`; the parser's window) is asked once for the run (a stage may only go
//! off in it: compensation stops at a move it cannot compensate, and the run's later moves
//! then go through `emit`, which finds none), and the block count,
//! the cursor and `reached` are settled at its end. `flow` keeps a
//! block lexed on its second run while replaying, so loop bodies are not lexed every time.

mod comp;
mod context;
mod corner;
mod cycle;
mod cylsurf;
mod define;
pub mod eval;
mod exec;
mod fast;
mod flow;
mod g7x;
mod lathe;
mod live;
pub mod machine;
mod motion;
mod named_turn;
mod pocket;
mod read;
pub mod shown;

pub use flow::{NoPrograms, ProgramSource, run};
pub use machine::MachineSetup;

use std::collections::{BTreeMap, BTreeSet};

use crate::canon::{Canon, CanonOp, CanonSink, DistanceMode, FeedMode, Plane, Setting, Units};
use crate::diag::{Code, Diagnostic, Severity};
use crate::dialect::{CodeDef, DecimalInput, Dialect, Meaning, Role, Step, SystemVar};
use crate::syntax::{Block, Expr, ParamTarget, WordMode};
use crate::text::{Text, TextRange};
use eval::{EvalError, Params};

/// What the interpreter knows about one tool (lengths in mm).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ToolData {
    /// Cutter diameter.
    pub diameter: Option<f64>,
    /// Length offset.
    pub length: f64,
    /// Description.
    pub name: Option<String>,
    /// Kind, as a plan tool kind name (`end_mill`, `twist_drill`, …).
    pub kind: Option<String>,
    /// Corner radius.
    pub corner_radius: Option<f64>,
    /// Number of flutes.
    pub flutes: Option<u32>,
    /// Included point angle of a drill, degrees.
    pub point_angle: Option<f64>,
}

/// Machine settings that are not part of the dialect (from config).
#[derive(Clone, Debug)]
pub struct Profile {
    /// Whether the block-delete switch is on (skip `/` blocks).
    pub block_delete: bool,
    /// Tool table by tool number.
    pub tools: BTreeMap<u32, ToolData>,
    /// G28 reference position, machine coordinates, mm.
    pub home1: [f64; 6],
    /// G30 reference position, machine coordinates, mm.
    pub home2: [f64; 6],
    /// Most iterations of one loop (or backward jumps to one block) before the run stops.
    pub max_loop_iterations: u64,
    /// Most blocks one run executes, counting repeats, before it stops.
    pub max_blocks: u64,
    /// The analysis bound in time: most blocks one run executes again (loop passes, backward
    /// jumps, repeated calls) before the analysis stops with a warning, whatever the loop
    /// budgets ([`Profile::bound`] sets it from seconds). Blocks run for the first time do not
    /// count, so a long program streams whole.
    pub max_repeated_blocks: u64,
    /// The analysis bound in memory: most bytes the result keeps of what the blocks run again
    /// make before the analysis stops with a warning (the sink says what it keeps:
    /// [`crate::canon::CanonSink::kept_bytes`]; [`Profile::bound_memory`] sets it from
    /// megabytes).
    pub max_repeated_bytes: u64,
    /// Where subprograms outside the program's text come from (the shell's program directory).
    pub programs: Option<std::sync::Arc<dyn ProgramSource + Send + Sync>>,
    /// The raw stock as two corners (min, max) in program coordinates, mm, when configured.
    pub stock: Option<[[f64; 3]; 2]>,
    /// Whether the fast paths are on: plain moves (`X.. Y.. Z..` under a modal G0 or G1) take
    /// the fast lane, a block of plain words is lexed by the lexer's fast path, and a block
    /// that runs a third time (a loop body) is not lexed again.
    /// Off, every block is lexed and goes the general way; both give the same result, and
    /// tests check it.
    pub fast_lane: bool,
    /// Whether a replay runs its kept blocks on the replay lane (`flow/replay.rs`), without
    /// the driver's general loop; only with `fast_lane`. Off, they go the general loop: the
    /// same result, and tests check it.
    pub replay_lane: bool,
    /// Whether the file is a main program, a program others call, or to be told from its
    /// form (the config's `role`, `check --as`).
    pub role: ProgramRole,
    /// The file's name, without its folders (`probe.ngc`), where the shell knows it: a call
    /// opens a subroutine's own file by the subroutine's name (RS274NGC "Calling Files":
    /// `o<probe> call` opens `probe.ngc`).
    pub file_name: Option<String>,
    /// How a condition on an unknown value goes when neither way leads to an alarm; `None`
    /// takes the dictionary's choice (`unknown-conditions`).
    pub unknown_conditions: Option<bool>,
    /// The machine reads X words as radii on a control whose dialect reads them as diameters
    /// (Fanuc parameter DIAx off): found from a program's arcs (`interp::x-words-radius`).
    pub x_radius: bool,
    /// The machine is a lathe of a control whose turning machines read X words as diameters
    /// in the ZX plane from reset (the dictionary's `lathe-x-words`): found from a program's
    /// turning words (`interp::x-words-diameter`).
    pub lathe_reset: bool,
    /// The machine is such a lathe and changes the tool with the T word (the dictionary's
    /// `lathe-tool-word`): found from a lathe program that never says M6
    /// (`interp::tool-word-changes`).
    pub tool_word_changes: bool,
    /// The machine powers on in inch (Fanuc parameter INI): found from a program's feeds
    /// (`interp::units-inferred`).
    pub inch: bool,
    /// The machine reads a length without a decimal point in whole units (calculator-type
    /// input, Fanuc parameter DPI on) on a control whose dialect reads it in least increments:
    /// found from how a program writes its lengths (`interp::decimal-input-inferred`).
    pub calculator_input: bool,
    /// The program turns from its start: a first reading found it a lathe's (plan recovery's
    /// `Recoverer::turns_throughout`), so that recovery reads every move as turning.
    pub turns: bool,
    /// What the machine's own configuration adds to the language (LinuxCNC's INI: remapped
    /// codes, HAL pins, switchable kinematics), read by the shell; empty by default.
    pub machine: std::sync::Arc<MachineSetup>,
    /// The dialect was guessed from weak evidence (the sniff's low confidence: no code of the
    /// maker's own, or evidence another maker's dictionary shares), not configured or given:
    /// a finding that holds for that maker's control alone ([`Code::maker_specific`]: the
    /// Fanuc dwell-point alarm) is a warning that says so, since another maker's control of
    /// the family may run the block.
    pub guessed: bool,
}

/// Whether a file is a main program or a called one (a subprogram, a macro, a `PROC`).
///
/// A called program analysed on its own relies on state its caller sets: the modal feed and
/// spindle, its arguments. Findings that only follow from that missing state are notes on a
/// called program; on a main program they keep their severity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum ProgramRole {
    /// Told from the program's form: a return (`M99`, `M17`, `RET`) at its top level, a
    /// `PROC` header, a program number the control reserves for macros (O9xxx), an argument
    /// read before it is written, or the file extension (`.SPF`, see [`role_from_file_name`]).
    #[default]
    Auto,
    /// A main program: it starts from the control's power-on state.
    Main,
    /// A program another one calls.
    Called,
}

/// The role a file's name says, where the dictionary lists extensions of called programs
/// (Siemens `.SPF`).
pub fn role_from_file_name(name: &str, dialect: &Dialect) -> Option<ProgramRole> {
    let (_, ext) = name.rsplit_once('.')?;
    dialect.macros.called_extensions.iter().any(|e| e.eq_ignore_ascii_case(ext)).then_some(ProgramRole::Called)
}

/// The role a program is read with: the one `given` (by the config or `check --as`) unless it
/// is `Auto`, else the one its file name says, else `Auto` (its form will tell).
pub fn role_for(given: ProgramRole, path: &std::path::Path, dialect: &Dialect) -> ProgramRole {
    match given {
        ProgramRole::Auto => path.file_name().and_then(|n| role_from_file_name(&n.to_string_lossy(), dialect)).unwrap_or(ProgramRole::Auto),
        given => given,
    }
}

impl std::fmt::Debug for dyn ProgramSource + Send + Sync {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("ProgramSource")
    }
}

/// Blocks run again per second of analysis, at the least: the rate that turns the time
/// bound into a count of blocks (`ncplan bench`'s macro programs run 5 to 10 million
/// blocks a second on a release build; a block of a real program's loop may do more).
/// A count, not a clock, so that the same program gives the same analysis on any machine.
pub const REPEATED_BLOCKS_PER_SECOND: u64 = 1_000_000;

pub use crate::canon::BYTES_PER_MOVE;

/// The analysis bound by default: a minute of analysis, and 64 MB of what the result keeps of
/// the moves blocks run again make (a plan: some 160,000 moves, a macro program rs274 runs to
/// its end in a second or two). A command that keeps no moves (`canon` streams them) has no
/// bound in memory.
pub const DEFAULT_BOUND_SECONDS: u64 = 60;
/// See [`DEFAULT_BOUND_SECONDS`].
pub const DEFAULT_BOUND_MB: u64 = 64;

impl Profile {
    /// Sets the analysis bound in time: `seconds` of analysis at the most for the blocks run
    /// again (at least one).
    pub fn bound_time(&mut self, seconds: u64) {
        self.max_repeated_blocks = seconds.max(1).saturating_mul(REPEATED_BLOCKS_PER_SECOND);
    }

    /// Sets the analysis bound in memory: `megabytes` kept at the most of the moves of blocks
    /// run again (at least one).
    pub fn bound_memory(&mut self, megabytes: u64) {
        self.max_repeated_bytes = megabytes.max(1).saturating_mul(1_000_000);
    }

    /// No bound in memory: for a run whose moves are streamed, not kept.
    pub fn streamed(&mut self) {
        self.max_repeated_bytes = u64::MAX;
    }
}

impl Default for Profile {
    fn default() -> Profile {
        Profile {
            block_delete: false,
            tools: BTreeMap::new(),
            home1: [0.0; 6],
            home2: [0.0; 6],
            max_loop_iterations: 1_000_000,
            max_blocks: 200_000_000,
            max_repeated_blocks: DEFAULT_BOUND_SECONDS * REPEATED_BLOCKS_PER_SECOND,
            max_repeated_bytes: DEFAULT_BOUND_MB * 1_000_000,
            programs: None,
            stock: None,
            fast_lane: true,
            replay_lane: true,
            role: ProgramRole::Auto,
            file_name: None,
            unknown_conditions: None,
            x_radius: false,
            lathe_reset: false,
            tool_word_changes: false,
            inch: false,
            calculator_input: false,
            turns: false,
            machine: std::sync::Arc::default(),
            guessed: false,
        }
    }
}

/// A blank the program defines (`BLK FORM`, `WORKPIECE`), passed on as the stock comment plan
/// recovery reads, as a CAM system writes it: `STOCK X0 Y0 Z-40 X100 Y100 Z0`.
fn stock_comment(min: [f64; 3], max: [f64; 3]) -> CanonOp {
    let n = |v: f64| format!("{}", v + 0.0);
    CanonOp::Comment(format!("STOCK X{} Y{} Z{} X{} Y{} Z{}", n(min[0]), n(min[1]), n(min[2]), n(max[0]), n(max[1]), n(max[2])))
}

/// Rotates a point about the origin by `degrees`, counter-clockwise.
fn rotate(p: [f64; 2], degrees: f64) -> [f64; 2] {
    let (sin, cos) = degrees.to_radians().sin_cos();
    [p[0] * cos - p[1] * sin, p[0] * sin + p[1] * cos]
}

/// Interprets a whole program text, pushing canonical ops into `sink`. Subprograms come from
/// the same text or from the profile's [`ProgramSource`]. Streams: memory does not grow
/// with the program's length, and a text read piece by piece is never held whole.
pub fn interpret<'t>(text: impl Into<Text<'t>>, dialect: &Dialect, profile: &Profile, sink: &mut dyn CanonSink) -> Vec<Diagnostic> {
    let text = text.into();
    if !dialect.lexical.foreign.is_empty()
        && let Some(d) = foreign(&text.head(), dialect)
    {
        return vec![d];
    }
    let mut diags = match &profile.programs {
        Some(p) => run(text, dialect, profile, p.as_ref(), sink),
        None => run(text, dialect, profile, &NoPrograms, sink),
    };
    if let Some((range, line)) = crate::syntax::leader(text, dialect) {
        let msg = format!("the text before the `%` on line {line} is tape leader: the control skips it, and so does this analysis");
        diags.insert(0, Diagnostic::new(Code::Leader, range, msg));
    }
    if profile.guessed {
        guessed_maker(&mut diags, dialect);
    }
    diags
}

/// On a dialect guessed from weak evidence, a finding that holds for its maker's control alone
/// ([`Code::maker_specific`]) is no error: nothing in the program shows that maker, and
/// another maker's control of the family runs the block. It stays a warning that says the
/// family was guessed and what that maker's control would do.
/// A plane change under compensation is the maker's only where the dictionary says so
/// (`plane-under-comp="stops"`); the RS274/NGC language's `modes-under-comp="locked"` holds
/// for every control that reads that language.
fn guessed_maker(diags: &mut [Diagnostic], dialect: &Dialect) {
    let language = |d: &Diagnostic| d.code == Code::PlaneUnderComp && dialect.behaviour.comp_locks_modes;
    for d in diags.iter_mut().filter(|d| d.is_error() && d.code.maker_specific() && !language(d)) {
        d.severity = Severity::Warning;
        d.message = format!(
            "{}; the dialect ({}) was guessed from evidence that shows no code of its maker's own, and another maker's control of the family may run it: give --dialect to choose",
            d.message, dialect.name
        );
    }
}

/// A program in a format the dialect names as foreign (Mazatrol unit blocks in a Mazak
/// folder), in the text's `head`: one error at the evidence instead of a finding for every
/// block.
fn foreign(head: &str, dialect: &Dialect) -> Option<Diagnostic> {
    let text = head;
    dialect.lexical.foreign.iter().find_map(|(re, name)| {
        let m = re.regex().find(text.as_bytes())?;
        // An ASCII pattern can match part of a character; the range covers whole ones.
        let (mut start, mut stop) = (m.start(), m.end());
        while !text.is_char_boundary(start) {
            start -= 1;
        }
        while !text.is_char_boundary(stop) {
            stop += 1;
        }
        let msg = format!("this is {name}, not a program in the {} dialect; it was stored but not interpreted", dialect.name);
        Some(Diagnostic::new(Code::ForeignFormat, TextRange::new(start, stop), msg))
    })
}

/// Tool data a program set with G10, in millimetres.
#[derive(Clone, Copy, Debug, Default)]
struct ToolEdit {
    /// Offsets along X and Y (lathe and angled tools), mm.
    xy: [Option<f64>; 2],
    length: Option<f64>,
    length_wear: f64,
    radius: Option<f64>,
    radius_wear: f64,
}

/// What the interpreter asks the control-flow driver to do after a block.
#[derive(Clone, Debug, PartialEq)]
pub(crate) enum Request {
    /// Run program `program` `repeats` times; `args` set locals (macro calls only).
    Call {
        /// Program number.
        program: u32,
        /// Repeat count.
        repeats: u32,
        /// Whether the call opens a new level of local variables (G65) or not (M98).
        macro_call: bool,
        /// Local variable number and value.
        args: Vec<(u16, f64)>,
        /// The block number in the program to start at (`M98 P100 H20`), else its top.
        start: Option<u32>,
    },
    /// Run the current file from its block numbered `number` up to a return, `repeats` times.
    CallLocal {
        /// Block number.
        number: u32,
        /// Repeat count.
        repeats: u32,
    },
    /// Run the O-word subroutine `sub`, which the machine's configuration remaps a code of
    /// the block to (LinuxCNC `REMAP=`), with no arguments.
    Remap {
        /// The subroutine's name.
        sub: String,
    },
    /// Return from a subprogram, optionally to block number `goto` of the caller.
    Return {
        /// Block number to continue at.
        goto: Option<u32>,
    },
    /// A lathe cycle over the contour between the blocks numbered `first` and `last` after
    /// this one: roughed out from the start point (then the run goes on after `last`), or,
    /// without `rough`, run as written and left to the start point again (G70).
    Contour {
        /// The contour's first block number (P).
        first: u32,
        /// Its last block number (Q); none: up to the dictionary's `contour-end` code, the run
        /// going on after it whether the cycle roughs or finishes (Okuma LAP).
        last: Option<u32>,
        /// How to rough it out (G71); `None` finishes it (G70).
        rough: Option<cycle::Rough>,
    },
    /// A lathe profile cycle over the O-word subroutine `name` (LinuxCNC G70–G72).
    Profile {
        /// The subroutine's label.
        name: String,
        /// The cycle.
        cycle: g7x::Cycle,
    },
    /// A named turning cycle's contour (Siemens CYCLE95): the subprogram, label or label
    /// range `name` gives, read without effect, then cut as `job` says.
    NamedContour {
        /// The contour's name as written (`"KONTUR"`, `"START:END"`).
        name: String,
        /// What the cycle does with it.
        job: Box<named_turn::StockRemoval>,
    },
    /// A cylinder surface cycle's contour (Heidenhain 27, 28, 29, 39): the label cycle 14
    /// named, read without effect on the cylinder's developed surface, then cut as `job` says.
    CylinderContour {
        /// The label (`1`).
        name: String,
        /// The cycle.
        job: Box<cylsurf::CylinderSurface>,
    },
}

#[derive(Clone, Copy, Debug)]
struct Slot {
    value: f64,
    range: TextRange,
    mode: WordMode,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Spindle {
    Stopped,
    Cw,
    Ccw,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Retract {
    Initial,
    RPlane,
}

/// A macro registered by G66, called after every move at the call depth it was made at.
#[derive(Clone, Debug, PartialEq)]
struct ModalMacro {
    program: u32,
    repeats: u32,
    args: Vec<(u16, f64)>,
    depth: u32,
}

/// An assignment of the block being executed, evaluated and waiting for the block's reads.
#[derive(Clone, Copy, Debug)]
struct PendingAssign {
    /// The parameter number (`#5=`), or `None` for a named one.
    number: Option<f64>,
    /// The name of a named parameter (`VC1=`, `#<depth>=`).
    name: TextRange,
    /// The element of a named array (`VGRIN[6]=`).
    index: Option<f64>,
    /// The named parameter's slot, where the block has its names resolved.
    slot: Option<u32>,
    value: f64,
    range: TextRange,
}

/// Modal state.
#[derive(Clone, Debug, PartialEq)]
struct State {
    units: Units,
    plane: Plane,
    distance: DistanceMode,
    arc_incremental: bool,
    feed: f64,
    speed: f64,
    spindle: Spindle,
    mist: bool,
    flood: bool,
    selected_tool: u32,
    tool: u32,
    /// Whether the program has commanded a tool (a T word, a tool change) in this run.
    tool_commanded: bool,
    motion_code: Option<usize>,
    retract: Retract,
    /// The active work coordinate system: 1 to 9, or an additional one (see
    /// [`crate::canon::EXTENDED_WCS`]).
    wcs: u16,
    wcs_offsets: [[f64; 6]; 9],
    /// Rotation of each work coordinate system about its origin in XY (G10 L2 R), degrees.
    wcs_rotation: [f64; 9],
    /// The additional work offsets a program set (`G10 L20 P..`), by index; the others are 0.
    wcs_extended: std::collections::BTreeMap<u16, [f64; 6]>,
    /// The registered G66 modal macro call.
    modal_macro: Option<ModalMacro>,
    /// G28 and G30 reference positions, machine coordinates, mm (from the profile; G28.1
    /// and G30.1 store new ones).
    home1: [f64; 6],
    home2: [f64; 6],
    /// The reference positions the program stored itself (bit 1: G28.1, bit 2: G30.1): a
    /// return to one goes where only this program says, not to the machine's own.
    home_taught: u8,
    g92: [f64; 6],
    /// The shift G92.2 suspended, for G92.3.
    g92_saved: [f64; 6],
    /// The tool offset in force along X, Y and Z, program units.
    tool_offset: [f64; 3],
    pos: [f64; 6],
    sticky_r: Option<f64>,
    sticky_z: Option<f64>,
    /// A lathe's single-pass cycle in force: its X (radius) and Z targets and taper, which a
    /// following block repeats with what it changes.
    turn_cycle: Option<[f64; 3]>,
    /// The NURBS being collected (G5.2): control points so far, the start among them, and
    /// the last one.
    nurbs: Option<(u32, [f64; 6])>,
    sticky_q: Option<f64>,
    sticky_p: Option<f64>,
    ended: bool,
    tech_warned: bool,
    /// Programmable rotation (G68) in the XY plane: centre and angle's cosine and sine.
    rotation: Option<(f64, f64, f64, f64)>,
    /// The tilted working plane in force (`PLANE SPATIAL`, `CYCLE800`, `G68.2`).
    frame: Option<crate::canon::Frame>,
    /// The tilted working plane as it was put in force, and the C axis's position then: a C
    /// move under it turns the part about its Z ([`Interpreter::turn_part_under_plane`]).
    frame_set: Option<(crate::canon::Frame, f64)>,
    /// Where the programmable frame turns the plane in space (Siemens `ROT`/`AROT` about X or
    /// Y): the plane in force before it (`None`: untilted), which a replacing `TRANS` or `ROT`
    /// puts back ([`Interpreter::frame_rotation_in_space`]).
    frame_before_rot: Option<Option<crate::canon::Frame>>,
    /// Tool centre point control (`M128`, `TRAORI`, `G43.4`): the rotary axes turn the tool axis.
    tcp: bool,
    /// Whether tool centre point control is the machine's kinematics' (a switchable
    /// kinematics type, `profile.machine`), which a length offset code does not end.
    tcp_machine: bool,
    /// A tilted plane stated over several blocks (Fanuc `G68.2 P2 Q0..Q3` three points,
    /// `G68.2 P3 Q1 Q2` two vectors): what its blocks have given so far.
    tilt_steps: Option<Box<exec::tilt::TiltSteps>>,
    /// What programmable mirroring and scaling do to a point, together (mirror first, then
    /// scale: `Interpreter::set_mirror_and_scale`): centre and factor per linear axis, a
    /// mirrored axis's factor negative.
    scaling: Option<([f64; 3], [f64; 3])>,
    /// Programmable scaling as stated (G51, `SCALE`): centre and factor per linear axis.
    scale_set: Option<([f64; 3], [f64; 3])>,
    /// Programmable mirroring (G51.1, `MIRROR`, cycle 8): per linear axis, the coordinate it is
    /// mirrored about.
    mirror: [Option<f64>; 3],
    /// Whether the block's motion mode was already active before it.
    motion_continued: bool,
    /// G93: F is the inverse of each move's time in minutes.
    inverse_time: bool,
    /// Feed per spindle revolution (G95).
    feed_per_rev: bool,
    /// The circle centre / pole in the plane's two axes (`CC X Y`), program coordinates.
    pole: (f64, f64),
    /// The polar coordinate command in force (Fanuc `G16`, off by `G15`): a move's first
    /// axis word of the plane is a radius, the second an angle, about the work origin.
    polar_command: bool,
    /// The plane of the pole when its block named the two axes of another plane than the
    /// active one (Heidenhain `CC Y+0.2 Z-0.2` with tool axis Z): the arcs about it (`C`, `CP`)
    /// run in that plane.
    pole_plane: Option<Plane>,
    /// The direction of the last arc, for arcs that do not state one (`C X Y` after `DR-`).
    arc_cw: bool,
    /// The cycle defined last (`CYCL DEF 200`, `MCALL CYCLE81(...)`), for later calls.
    defined_cycle: Option<define::Defined>,
    /// A cycle the dictionary does not model, defined last (`CYCL DEF 22 ROUGH-OUT`): a call
    /// runs it on the control, so the call is kept as intent, its moves unknown.
    unmodelled_cycle: Option<String>,
    /// Whether the defined cycle runs after every move (`MCALL`, `M89`).
    cycle_modal: bool,
    /// The direction of travel at the end of the last move in the plane (unit vector).
    tangent: Option<(f64, f64)>,
    /// The side of the last radius compensation (left: G41, `RL`), which perpendicular
    /// approaches and departures take.
    comp_left: bool,
    /// The first corner of a workpiece blank (`BLK FORM 0.1`), waiting for the second.
    blank_min: Option<[f64; 3]>,
    /// A straight feed given by its line's angle alone (Fanuc lathe direct drawing `G01 ,A150.`)
    /// and where its block was: it ends where the next block's line meets it.
    angle_line: Option<(f64, TextRange)>,
    /// Cutter compensation has just ended: the next move leaves the compensated path.
    leaving_comp: bool,
    /// Cutter radius compensation is on (G41/G42 until G40 or the program's end): a plane
    /// code that changes the plane then stops a control whose dictionary locks the modes.
    comp_on: bool,
    /// Lathe diameter mode (G7): X words give diameters.
    diameter: bool,
    /// With `diameter`, only absolute X words give diameters; incremental ones radii
    /// (SINUMERIK `DIAM90`).
    diameter_absolute: bool,
    /// Modal rounding (Siemens `RNDM=`): the radius every corner between two moves is
    /// rounded with, until `RNDM=0`.
    round_modal: Option<f64>,
    /// Constant surface speed (G96): S is a surface speed, and this is the spindle's
    /// speed limit; `None` in G97, where S is in revolutions per minute.
    css_max: Option<f64>,
    /// The spindle speed limit a lathe's `G50 S` set, which a G96 without D keeps.
    spindle_limit: Option<f64>,
    /// A lathe roughing cycle's depth of cut and retract, as its first block (`G71 U2. R.5`)
    /// set them for the ones after it.
    rough_cut: Option<(f64, f64)>,
    /// A pattern repeating cycle's relief (X a radius, Z) and number of passes, as its first
    /// block (`G73 U14. W4. R3`) set them for the ones after it.
    pattern_cut: Option<cycle::Pattern>,
    /// What the first block of a lathe's G74/G75/G76 set for the ones after it.
    lathe_setup: lathe::LatheSetup,
    /// Polar coordinate interpolation on a lathe (G12.1, TRANSMIT) in force: the plane it
    /// replaced. X and C are then a plane on the face (`lathe::face_words`).
    face_plane: Option<Plane>,
    /// Cylindrical interpolation in force (G07.1, TRACYL): the cylinder's radius and the C
    /// angle it began at (`lathe::cylinder_mode`); `face_plane` then holds the plane it
    /// replaced.
    cylinder: Option<lathe::Cylinder>,
    /// The initial level of the canned cycles in force: the hole axis position when the
    /// first of them began. G98 returns to it, and in G91 R counts from it.
    cycle_initial: Option<f64>,
    /// Whether the program has read data only the machine has (FN 18): arithmetic faults
    /// after it may come from that data.
    machine_data_read: bool,
    /// The first condition on an unknown value the run took a way at (its text): after it,
    /// the run follows the way the analysis chose, which the control may not take.
    guessed: Option<String>,
    /// Whether a length with a decimal point has been read under least-increment input:
    /// after one, a length without (`X118`, 0.118 mm) is suspect.
    length_points: bool,
    /// Whether the feed is the caller's (a called program that has set none) or an unknown
    /// value: not zero.
    feed_unknown: bool,
    /// Whether the last F word read a value from outside the file (`F#650`, a feed the shop
    /// keeps in a common variable): the feed is the machine's, not zero, whoever calls.
    feed_outside: bool,
    /// Whether the spindle is the caller's (a called program that has not set it).
    spindle_unknown: bool,
    /// The spindle the spindle ops address (the main one unless a block numbers another).
    spindle_id: crate::canon::SpindleId,
    /// Whether the feed and the spindle speed overrides are enabled (M48 to M51).
    overrides: (bool, bool),
    /// The W axis of a mill, a linear axis along the spindle (ISO 841: the secondary motion
    /// parallel to Z; a quill): where it stands, program units. The tool tip stands that far
    /// along the tool axis from the X Y Z the program gives ([`Interpreter::quill_shift`]).
    quill: f64,
}

impl State {
    /// The control's power-on state, as the dialect and the profile set it.
    fn power_on(dialect: &Dialect, profile: &Profile) -> State {
        State {
            units: if profile.inch { Units::Inch } else { Units::Mm },
            plane: if profile.lathe_reset { Plane::Xz } else { dialect.behaviour.initial_plane },
            distance: DistanceMode::Absolute,
            arc_incremental: true,
            feed: 0.0,
            speed: 0.0,
            spindle: Spindle::Stopped,
            mist: false,
            flood: false,
            selected_tool: 0,
            tool: 0,
            tool_commanded: false,
            motion_code: None,
            retract: if dialect.behaviour.initial_retract_r { Retract::RPlane } else { Retract::Initial },
            wcs: 1,
            wcs_offsets: [[0.0; 6]; 9],
            wcs_extended: std::collections::BTreeMap::new(),
            wcs_rotation: [0.0; 9],
            modal_macro: None,
            home1: profile.home1,
            home2: profile.home2,
            home_taught: 0,
            g92: [0.0; 6],
            g92_saved: [0.0; 6],
            tool_offset: [0.0; 3],
            pos: [0.0; 6],
            sticky_r: None,
            sticky_z: None,
            turn_cycle: None,
            nurbs: None,
            rough_cut: None,
            pattern_cut: None,
            lathe_setup: lathe::LatheSetup::default(),
            face_plane: None,
            cylinder: None,
            sticky_q: None,
            sticky_p: None,
            ended: false,
            tech_warned: false,
            inverse_time: false,
            feed_per_rev: dialect.behaviour.initial_feed_per_rev,
            motion_continued: false,
            rotation: None,
            frame: None,
            frame_set: None,
            frame_before_rot: None,
            tcp: false,
            tcp_machine: false,
            tilt_steps: None,
            scaling: None,
            scale_set: None,
            mirror: [None; 3],
            pole: (0.0, 0.0),
            polar_command: false,
            pole_plane: None,
            arc_cw: true,
            defined_cycle: None,
            unmodelled_cycle: None,
            cycle_modal: false,
            tangent: None,
            comp_left: true,
            blank_min: None,
            angle_line: None,
            leaving_comp: false,
            comp_on: false,
            diameter: (dialect.behaviour.x_diameter || profile.lathe_reset) && !profile.x_radius,
            diameter_absolute: false,
            round_modal: None,
            css_max: None,
            spindle_limit: None,
            cycle_initial: None,
            machine_data_read: false,
            guessed: None,
            length_points: false,
            feed_unknown: profile.role != ProgramRole::Main,
            feed_outside: false,
            spindle_unknown: profile.role != ProgramRole::Main,
            spindle_id: crate::canon::SpindleId::Main,
            overrides: (true, true),
            quill: 0.0,
        }
    }

    /// The offsets of work coordinate system `wcs` (1 for G54; an additional one is 0 until
    /// the program sets it; 0, no settable offset in force (Siemens `G500`), is 0).
    fn offset(&self, wcs: u16) -> [f64; 6] {
        match wcs {
            1..=9 => self.wcs_offsets[wcs as usize - 1],
            _ => self.wcs_extended.get(&wcs).copied().unwrap_or([0.0; 6]),
        }
    }

    /// The rotation of work coordinate system `wcs` (the additional ones have none).
    fn rotation(&self, wcs: u16) -> f64 {
        match wcs {
            1..=9 => self.wcs_rotation[wcs as usize - 1],
            _ => 0.0,
        }
    }

    fn set_offset(&mut self, wcs: u16, off: [f64; 6], rotation: f64) {
        match wcs {
            1..=9 => {
                self.wcs_offsets[wcs as usize - 1] = off;
                self.wcs_rotation[wcs as usize - 1] = rotation;
            }
            _ => {
                self.wcs_extended.insert(wcs, off);
            }
        }
    }
}

/// The parameters at power-on: vacant, but for those the dialect says come from outside the
/// file (unknown), a called program's arguments, and the return value's.
fn power_on_params(dialect: &Dialect, profile: &Profile) -> Params {
    let mut p = Params::new(dialect.macros.null_value);
    // The named system variables take the first slots (see `system_by_slot`).
    for (name, ..) in &dialect.macros.system_named {
        p.slot(name);
    }
    p.magnitude_rounding = dialect.behaviour.magnitude_rounding;
    p.hal_pins = profile.machine.hal_pins;
    p.set_highest(dialect.macros.highest_variable);
    for &(a, b) in &dialect.macros.outside {
        p.mark_unknown(a, b);
    }
    if profile.role != ProgramRole::Main && dialect.macros.arguments.iter().any(Option::is_some) {
        // The caller's arguments: unknown, not vacant, in a program that may be called.
        p.mark_unknown(u32::from(dialect.macros.locals.0), u32::from(dialect.macros.locals.1));
    }
    if let Some(name) = &dialect.macros.return_value {
        p.set_named(name, 0.0);
        p.set_named(&format!("{name}_returned"), 0.0);
    }
    p
}

/// For the first slots, which [`power_on_params`] gives the named system variables in their
/// order, the index of the variable each holds (the last of a name listed twice).
fn system_by_slot(dialect: &Dialect) -> Vec<usize> {
    let mut names: Vec<&str> = Vec::new();
    let mut by_slot = Vec::new();
    for (k, (name, ..)) in dialect.macros.system_named.iter().enumerate() {
        match names.iter().position(|n| n == name) {
            Some(slot) => by_slot[slot] = k,
            None => {
                names.push(name);
                by_slot.push(k);
            }
        }
    }
    by_slot
}

/// The corner stage from the start, where the dialect has corner blocks (`RND`, `CHF`,
/// `APPR`): the move before such a block must be held. Corner words (`,R5`, `RND=5`) open it
/// at their first block instead (see [`Interpreter::open_corner_stage`]), so that the many
/// programs without them keep the fast lane.
fn corner_stage(dialect: &Dialect) -> Option<corner::Corners> {
    dialect
        .codes
        .iter()
        .any(|c| matches!(c.meaning, Meaning::CornerRound | Meaning::CornerChamfer | Meaning::ApproachTangent | Meaning::ApproachNormal))
        .then(|| corner::Corners::default().reducing(dialect.behaviour.corners_reduced))
}

/// The roles of corner words, as bits of `Interpreter::filled`.
const CORNER_WORDS: u128 = 1 << Role::CornerRadius as u32 | 1 << Role::CornerChamfer as u32 | 1 << Role::CornerChamferLength as u32;

/// What decides how a run goes on from a point: the parameters, the modes, the saved modes
/// and the call depth. Equal readings at two passes of the same jump mean the stretch between
/// them left everything as it was, so it will repeat for ever.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct RoundState {
    params: Params,
    depth: u32,
    st: State,
    contexts: Vec<Option<context::Context>>,
}

/// The interpreter for one program run.
pub struct Interpreter<'a> {
    dialect: &'a Dialect,
    profile: &'a Profile,
    st: State,
    params: Params,
    slots: [Option<Slot>; Role::COUNT],
    /// Bit per role whose slot is filled, so that clearing touches only those.
    filled: u128,
    /// The tool axis vector (from the tip towards the holder) the canon last stated; +Z
    /// until a block gives another (CLDATA `GOTO/x,y,z,i,j,k`).
    tool_axis: [f64; 3],
    /// Bit per [`Step`] at which one of the block's codes takes effect.
    code_steps: u32,
    /// Bit per role whose word in the block has an unknown value (left out of the slots).
    unknown_roles: u128,
    /// How many words with unknown values the run has left out.
    unknown_words: u32,
    /// Whether the block being executed has axis words (set by `read`).
    has_axes: bool,
    /// Whether `read` has filled the block's slots, codes or cycle arguments since they were
    /// last cleared (the fast lane leaves them empty, so the next plain move need not clear).
    block_read: bool,
    codes: Vec<(usize, TextRange)>,
    origin: TextRange,
    line: u32,
    notes: BTreeMap<String, u32>,
    /// The limited findings listed so far (range and message), so that a loop's later passes
    /// over the same block do not count again.
    noted: BTreeSet<(u32, u32, String)>,
    after_end_noted: bool,
    /// Arcs given by I and K under diameter programming whose centre fits only with X read
    /// as a radius, and only as a diameter.
    arc_fit: [u32; 2],
    /// Whether the program stated its units (G20, G21).
    units_stated: bool,
    /// Whether a comment names a tool by an inch size (`(T04 - 3/4" BORING BAR)`): see
    /// `comments::inch_tool_size`.
    inch_tool_comment: bool,
    /// Feeds per revolution read: how many, and the largest.
    per_rev_feeds: (u32, f64),
    /// Feeds per revolution set under constant surface speed with a speed limit, at a known
    /// diameter: how many of them the surface speed read in m/min turns within the limit
    /// (millimetres plausible), and how many it turns only read in ft/min (in millimetres the
    /// cut would sit at the limit: the program is written in inches). Cuts at the limit
    /// either way tell nothing.
    css_fit: (u32, u32),
    /// Set by a block that calls or returns; taken by the flow driver.
    request: Option<Request>,
    /// The intent of the lathe contour cycle a request runs, said before its moves.
    turn_intent: Option<Box<crate::canon::TurnIntent>>,
    /// Call depth (0 in the main program), kept by the flow driver.
    pub(super) depth: u32,
    /// Modal state saved per call level (M70, M73), index 0 for the main program.
    contexts: Vec<Option<context::Context>>,
    /// A call level left whose saved state waits to be restored before the next block.
    pub(super) left_level: Option<usize>,
    /// Motion commands executed so far (to tell whether a block moved).
    motions: u64,
    /// Pocket and slot finishing passes written so far in the whole run (`pocket`'s bound).
    pocket_passes: usize,
    /// Half turns of bores milled in a helix written so far in the whole run (`pocket`'s bound).
    helix_halves: usize,
    /// Whether the dialect sets the feed before it moves (the fast lane takes F only then).
    /// Whether integers count least increments (`X10` is 10 µm): the dictionary's
    /// `decimal-input`, looked at by every plain move.
    integers_scale: bool,
    feed_before_motion: bool,
    /// By code: whether a keyword word naming it makes a plain straight move (Heidenhain's
    /// `L`; [`Interpreter::plain_keyword_code`]), asked of the dictionary once, not at every
    /// move.
    straight_keywords: Vec<bool>,
    /// By code: whether a keyword word naming it, with its value, is an inert code (Heidenhain's
    /// `FN` before its assignment or jump; [`read::inert_keyword`]), asked of the dictionary
    /// once, not at every `FN` block.
    inert_keywords: Vec<bool>,
    /// By code: whether the code, as the motion mode in force, reads the extra word as a polar
    /// word (an inert code's value then goes the general way), asked once.
    extra_polar: Vec<bool>,
    /// Whether the dialect names a linear axis (or A, B) by letter and number (`X1=10`, the
    /// SINUMERIK machine axis names): such a block goes the general way, which says it.
    machine_axis_names: bool,
    /// Assignments of the block being executed, waiting for its reads (reused).
    pending: Vec<PendingAssign>,
    /// A `#3006` stop message to emit at the stop step.
    stop_message: Option<String>,
    /// Tool data the program set with G10 (millimetres), over the profile's tool table.
    tool_edits: BTreeMap<u32, ToolEdit>,
    /// Cutter radius compensation while G41/G42 is on with a known radius.
    comp: std::cell::RefCell<Option<comp::Comp>>,
    /// Corner blocks (`RND`, `CHF`), where the dialect has them: the stage before compensation.
    corners: std::cell::RefCell<Option<corner::Corners>>,
    /// A compensation problem met while emitting, reported after the block.
    comp_problem: std::cell::Cell<Option<comp::CompProblem>>,
    /// The end of the last move sent (program coordinates, before transforms), which a
    /// control that re-reads its position after a tool change takes as the program position
    /// (`position-after-tool-change="last-move"`).
    sent: std::cell::Cell<[f64; 6]>,
    /// The axes whose position the program knows in the work offset's frame (bit `k` for
    /// axis `k`: X Y Z A B C; none at the start), the mask last sent as a
    /// [`CanonOp::Known`] marker, the axes the block being executed states absolutely (known
    /// from its first move on), and a machine-frame move under way (its axes, its moves
    /// left): its axes are unknown after its last move.
    known: std::cell::Cell<u8>,
    known_sent: std::cell::Cell<u8>,
    stated: std::cell::Cell<u8>,
    machine_known: std::cell::Cell<(u8, u8)>,
    /// Per axis, whether its position comes from a length word without a decimal point that
    /// least-increment input shrank (`X4` read as 0.004 mm) and that was said; as the block
    /// began, and after its words. An arc that fails from it is that finding's consequence.
    misread: [bool; 6],
    misread_before: [bool; 6],
    /// Whether one of this block's own words (an R, I, J or K) was shrunk so.
    block_misread: bool,
    /// The word that was, as the finding showed it (`` `X4` read as 0.004 mm ``).
    misread_word: Option<String>,
    /// How the program writes its lengths under least-increment input: whole numbers with a
    /// decimal point (`X55.`), fractions (`X-0.5`), whole numbers without one (`X55`, not 0):
    /// the evidence of calculator-type input (`lathe_evidence`).
    point_habit: [u32; 3],
    /// The first whole number written without a decimal point that `point_habit` counted:
    /// where the finding of calculator-type input points.
    first_bare: Option<TextRange>,
    /// Arcs given by an R written without a decimal point under least-increment input: how
    /// many reach their end point only with the R read in whole units (mm or inch), and how
    /// many reach it as least increments: the evidence of calculator-type input (`lathe_evidence`).
    radius_units: [u32; 2],
    /// The R word of the first arc that reached its end point only with its R in whole units.
    first_radius_units: Option<TextRange>,
    /// A lathe's words read (a turning cycle, a speed limit, constant cutting rate, `DIAMON`
    /// after the first move), and whether the program told its X words before moving
    /// (`DIAMON` first) or ever stated radius programming (`DIAMOF`): the evidence of a
    /// lathe's reset state (`lathe_evidence`).
    lathe_words: (u32, bool),
    /// The plane the program last stated (G17, G18, G19), if it stated one: a turning word
    /// read while a stated milling plane is in force is no evidence of a lathe's reset state
    /// (`lathe_word`).
    stated_plane: Option<crate::canon::Plane>,
    /// T words read, M6 (a tool change) read, `DIAMON` read: the evidence of a lathe's tool
    /// change with the T word (`lathe-tool-word`).
    tool_words: (u32, bool, bool),
    /// Whether the block has a code of the control's vocabulary that ncplan does not model
    /// (kept as intent): the words no modelled command takes are that code's.
    intent_words: bool,
    /// Whether the block addresses a spindle by its number (Siemens `M2=5`): then several
    /// spindle codes may stand in it, one a spindle (`M2=5 M3=5 M5`).
    numbered_spindles: bool,
    /// The subroutine a code of the block calls by the machine's remap (`profile.machine`).
    remap_call: Option<String>,
    /// Where ops come from while a subprogram from another file runs: the call block.
    origin_override: Option<(TextRange, u32)>,
    /// The block's named cycle (`CYCLE81(...)`) and its arguments, in order.
    block_cycle: Option<usize>,
    cycle_args: Vec<(Role, f64)>,
    /// The block's named cycle's text argument naming a contour (`CYCLE95("START:END", ...)`).
    cycle_text: Option<String>,
    /// The contour a contour-defining call named last (SINUMERIK `CYCLE62`: `"START:END"`),
    /// which the contour cycles after it turn.
    contour_named: Option<String>,
    /// The surface a cycle call at a position gives the cycle (`CYCL CALL POS ... Z+0`), and
    /// whether it is known wherever the tool stands (absolute, or counted from a known level).
    call_surface: Option<(f64, bool)>,
    /// Whether the initial level of the G8x cycles in force (`State::cycle_initial`) is where
    /// the program does not know the hole axis's position.
    cycle_initial_unknown: bool,
    /// Tool names met in `T="NAME"` that the tool table does not know, numbered from 10001.
    tool_names: Vec<String>,
    /// Why the file reads as a called program, once something shows it (see [`ProgramRole`]).
    called: Option<String>,
    /// Findings that follow from state a caller would set, as they stand if the file turns
    /// out to be a main program; meanwhile they are notes (`interp::caller-state`).
    provisional: Vec<Diagnostic>,
    /// For each of the first slots, the named system variable it holds: the dialect's last
    /// entry of that name (`power_on_params` gives them their slots first).
    system_by_slot: Vec<usize>,
}

const NOTE_LIMIT: u32 = 3;

/// Whole-number lengths written without a decimal point from which, when they are also more
/// than twice those written with one, the program is read as written for calculator-type
/// input: one or two are slips in any program, more a habit.
const CALCULATOR_BARE: u32 = 3;

/// Arcs whose radius written without a decimal point fits only in whole units from which the
/// program is read as written for calculator-type input: one is a slip, more a habit.
const CALCULATOR_ARCS: u32 = 2;

impl<'a> Interpreter<'a> {
    /// A fresh interpreter in the control's power-on state.
    pub fn new(dialect: &'a Dialect, profile: &'a Profile) -> Interpreter<'a> {
        Interpreter {
            dialect,
            profile,
            st: State::power_on(dialect, profile),
            params: power_on_params(dialect, profile),
            slots: [None; Role::COUNT],
            filled: 0,
            tool_axis: [0.0, 0.0, 1.0],
            unknown_roles: 0,
            unknown_words: 0,
            code_steps: 0,
            has_axes: false,
            block_read: false,
            codes: Vec::new(),
            origin: TextRange::default(),
            line: 0,
            notes: BTreeMap::new(),
            noted: BTreeSet::new(),
            after_end_noted: false,
            arc_fit: [0, 0],
            units_stated: false,
            inch_tool_comment: false,
            per_rev_feeds: (0, 0.0),
            css_fit: (0, 0),
            request: None,
            turn_intent: None,
            depth: 0,
            contexts: Vec::new(),
            left_level: None,
            motions: 0,
            pocket_passes: 0,
            helix_halves: 0,
            pending: Vec::new(),
            integers_scale: matches!(dialect.behaviour.decimal_input, DecimalInput::LeastIncrement { .. }) && !profile.calculator_input,
            feed_before_motion: {
                let at = |step: Step| dialect.execution_order.iter().position(|&s| s == step);
                matches!((at(Step::Feed), at(Step::Motion)), (Some(f), Some(m)) if f < m)
            },
            straight_keywords: (0..dialect.codes.len()).map(|c| fast::straight_keyword(dialect, c)).collect(),
            inert_keywords: (0..dialect.codes.len()).map(|c| read::inert_keyword(dialect, profile, c)).collect(),
            extra_polar: dialect.codes.iter().map(|def| def.args.iter().any(|&(from, _)| from == Role::Extra)).collect(),
            machine_axis_names: dialect
                .addresses
                .iter()
                .any(|a| a.axis_index && matches!(a.role, Role::X | Role::Y | Role::Z | Role::A | Role::B)),
            stop_message: None,
            tool_edits: BTreeMap::new(),
            comp: std::cell::RefCell::new(None),
            corners: std::cell::RefCell::new(corner_stage(dialect)),
            comp_problem: std::cell::Cell::new(None),
            sent: std::cell::Cell::new([0.0; 6]),
            known: std::cell::Cell::new(0),
            known_sent: std::cell::Cell::new(0),
            stated: std::cell::Cell::new(0),
            machine_known: std::cell::Cell::new((0, 0)),
            misread: [false; 6],
            misread_before: [false; 6],
            block_misread: false,
            misread_word: None,
            point_habit: [0; 3],
            first_bare: None,
            radius_units: [0; 2],
            first_radius_units: None,
            lathe_words: (0, false),
            stated_plane: None,
            tool_words: (0, false, false),
            intent_words: false,
            numbered_spindles: false,
            remap_call: None,
            origin_override: None,
            block_cycle: None,
            cycle_args: Vec::new(),
            cycle_text: None,
            contour_named: None,
            call_surface: None,
            cycle_initial_unknown: false,
            tool_names: Vec::new(),
            called: (profile.role == ProgramRole::Called)
                .then(|| "its role is given: the configuration, `--as` or its file name".to_owned()),
            provisional: Vec::new(),
            system_by_slot: system_by_slot(dialect),
        }
    }

    /// The closing `%` of the main program: the end of the program without M2/M30.
    fn finish_at_delimiter(&mut self, sink: &mut dyn CanonSink) {
        self.comp_off(sink);
        self.emit(sink, CanonOp::Finish);
        self.st.ended = true;
    }

    /// True once the program has ended (M2/M30).
    pub fn finished(&self) -> bool {
        self.st.ended
    }

    /// Notes that the file reads as a called program, for `why`, unless that is known
    /// already or the profile says it is a main program.
    pub(super) fn called_by(&mut self, why: impl FnOnce() -> String) {
        if self.called.is_none() && self.profile.role != ProgramRole::Main {
            self.called = Some(why());
        }
    }

    /// Whether the file reads as a called program so far.
    pub(super) fn is_called(&self) -> bool {
        self.called.is_some()
    }

    /// A finding that only follows from state a caller sets: a note that says what was
    /// assumed (`note`), and `main`, the finding as it stands on a main program, kept for
    /// [`Interpreter::finish`] to put back should the file not read as a called one.
    /// Both are limited as [`Interpreter::limited`] limits findings: a loop's later passes
    /// add nothing.
    fn caller_state(&mut self, diags: &mut Vec<Diagnostic>, key: &str, main: Diagnostic, note: String) {
        if self.profile.role == ProgramRole::Main {
            return self.limited(diags, key, main);
        }
        let range = main.range;
        let mut provisional = std::mem::take(&mut self.provisional);
        self.limited(&mut provisional, key, main);
        self.provisional = provisional;
        self.limited(diags, "caller-state", Diagnostic::new(Code::CallerState, range, note));
    }

    /// Final checks after the last block.
    pub fn finish(&mut self, diags: &mut Vec<Diagnostic>) {
        if self.called.is_none() && !self.provisional.is_empty() {
            // Nothing showed the file to be a called program: the caller's state was the
            // power-on state after all.
            let provisional: BTreeSet<(u32, u32)> = self.provisional.iter().map(|d| (d.range.start, d.range.end)).collect();
            diags.retain(|d| d.code != Code::CallerState || !provisional.contains(&(d.range.start, d.range.end)));
            diags.append(&mut self.provisional);
        } else if let Some(why) = &self.called {
            let msg = format!("read as a called program ({why}): its caller sets the state it starts from");
            diags.push(Diagnostic::new(Code::CalledProgram, TextRange::default(), msg));
        }
        self.lathe_evidence(diags);
        for (what, count) in &self.notes {
            if *count > NOTE_LIMIT {
                diags.push(Diagnostic::new(
                    Code::FindingsOmitted,
                    TextRange::default(),
                    format!("{} more findings like `{what}` were not listed", count - NOTE_LIMIT),
                ));
            }
        }
    }

    /// A lathe's word read (a turning cycle, expanded or kept as intent, a spindle speed
    /// limit, constant cutting rate): evidence that the machine is a lathe, which reads X as a
    /// diameter in the ZX plane from reset, unless the program has stated a milling plane (G17,
    /// G19) that is in force. A lathe's turning plane is G18 (SINUMERIK Fundamentals: plane
    /// selection; turning cycles run in G18): a program that says G17 and machines in it is a
    /// mill's, and a cycle it names (CYCLE930 kept as intent) must not re-read its stated
    /// milling moves as a lathe's.
    fn lathe_word(&mut self) {
        if !matches!(self.stated_plane, Some(crate::canon::Plane::Xy | crate::canon::Plane::Yz)) {
            self.lathe_words.0 += 1;
        }
    }

    /// What a lathe program's own words show of the machine's settings the dialect cannot
    /// know: X words as radii (arcs whose centres fit only so), inch units (no unit stated,
    /// every feed per revolution at most 0.06 and a constant surface speed that fits only
    /// inches). Each is a finding; the pipeline reads the
    /// program again so.
    fn lathe_evidence(&self, diags: &mut Vec<Diagnostic>) {
        let [radius, diameter] = self.arc_fit;
        if !self.profile.x_radius && radius >= 2 && diameter == 0 {
            let msg = format!(
                "{radius} arcs' centres (I, K) fit only with X read as a radius: the program is written for a machine set to radius programming, and is read so"
            );
            diags.push(Diagnostic::new(Code::XWordsRadius, TextRange::default(), msg));
        }
        let (count, largest) = self.per_rev_feeds;
        // Small feeds alone are no proof: a Swiss-type lathe turns small metric parts at
        // 0.02-0.05 mm/rev. The constant surface speed must also fit inches only: in
        // millimetres nearly every cut would turn above the spindle limit.
        let (metric, inch_only) = self.css_fit;
        // A short program (a boring bar's `G71` and `G70`: two feeds) tells it only with
        // evidence of its own: two feeds are no pattern, and a metric boring bar in a small
        // bore (Ø7 at S100, F0.05/F0.03) turns above its clamp as often as not. A comment that
        // names a tool by an inch size (`3/4" BORING BAR`, as shops in inch label their tools)
        // is that evidence: an invented ×25.4 is far worse than a missed one.
        let css_inch = (inch_only >= 3 && metric * 10 <= inch_only + metric)
            || (inch_only == 2 && metric == 0 && count == 2 && self.inch_tool_comment);
        if !self.profile.inch && !self.units_stated && count >= 2 && largest <= 0.06 && css_inch {
            let msg = format!(
                "no units stated; all {count} feeds per revolution are at most 0.06 (the largest F{largest}): no turning feed in mm/rev, ordinary in inch/rev; and the constant surface speed turns {inch_only} cuts within the spindle limit only in ft/min ({metric} in m/min); read in inch"
            );
            diags.push(Diagnostic::new(Code::UnitsInferred, TextRange::default(), msg));
        }
        // A programmer who writes for least-increment input puts the point on whole numbers
        // (`X55.`, `Z0.`), save a slip or two: one who mostly leaves it off (more than twice as
        // often as not) and writes fractions with it wrote for calculator-type input, where
        // `X55` is 55 mm (and on least-increment input the tool would run into the part at
        // X0.055).
        let b = &self.dialect.behaviour;
        let (lathe_words, told) = self.lathe_words;
        if b.lathe_x_diameter
            && !b.x_diameter
            && !b.x_words_stated
            && !self.profile.x_radius
            && !self.profile.lathe_reset
            && !told
            && lathe_words > 0
        {
            let msg = format!(
                "{lathe_words} words of a lathe (turning cycles, a spindle speed limit, constant cutting rate) and no radius programming stated: on this control's turning machines X is a diameter in the ZX plane from reset (DIAMON, G18), and the program is read so"
            );
            diags.push(Diagnostic::new(Code::XWordsDiameter, TextRange::default(), msg));
        }
        // The same lathe, or one that says DIAMON: a control whose turning machines change
        // the tool with the T word does so where the program never says M6.
        let (t_words, m6, diamon) = self.tool_words;
        let lathe = lathe_words > 0 || diamon || self.profile.lathe_reset;
        if b.lathe_tool_word_changes
            && !b.tool_word_changes
            && !b.tool_change_stated
            && !self.profile.tool_word_changes
            && lathe
            && t_words > 0
            && !m6
        {
            let msg = format!(
                "a lathe program with {t_words} T words and no M6: on this control's turning machines the T command changes the tool (MD22550 TOOL_CHANGE_MODE 0), and the program is read so"
            );
            diags.push(Diagnostic::new(Code::ToolWordChanges, TextRange::default(), msg));
        }
        let [whole_points, fractions, bare] = self.point_habit;
        let stated = self.dialect.behaviour.decimal_input_stated;
        let [units, increments] = self.radius_units;
        if self.integers_scale && !stated && fractions >= 1 && bare >= CALCULATOR_BARE && bare > 2 * whole_points {
            let msg = format!(
                "{bare} lengths are whole numbers written without a decimal point, {whole_points} with one, and {fractions} fractions with one: the program is written for calculator-type decimal input (a whole number is mm or inch, Fanuc parameter DPI on), and is read so"
            );
            diags.push(Diagnostic::new(Code::DecimalInputInferred, self.first_bare.unwrap_or_default(), msg));
        } else if self.integers_scale && !stated && units >= CALCULATOR_ARCS && increments == 0 {
            // Arcs the program gives by a radius without a point (`G3 X89. Z-1. R1`), none of
            // which a control on least-increment input could run (R1 is 0.001 mm, too small
            // to reach the end point: an alarm), and each of which fits read in whole units:
            // the program ran on a machine set for calculator-type input (Fanuc parameter DPI,
            // 3401#0: a number without a point is in mm or inch).
            let msg = format!(
                "{units} arcs given by a radius written without a decimal point reach their end point only with the radius in whole units (none as least increments): the program is written for calculator-type decimal input (a whole number is mm or inch, Fanuc parameter DPI on), and is read so"
            );
            diags.push(Diagnostic::new(Code::DecimalInputInferred, self.first_radius_units.unwrap_or_default(), msg));
        }
    }

    /// Before a move: the axes the block states absolutely are known from it on; where that
    /// changes what the stream was last told, a [`CanonOp::Known`] marker goes first.
    #[inline(always)]
    fn mark_known(&self, sink: &mut dyn CanonSink) {
        // Axes lost since the stream was last told (`position_lost`) go first, so that one
        // the block states again is written again.
        if self.known_sent.get() & !self.known.get() != 0 {
            self.known_sent.set(self.known.get());
            self.emit(sink, CanonOp::Known(self.known.get()));
        }
        let k = self.known.get() | self.stated.get();
        self.known.set(k);
        if k != self.known_sent.get() {
            self.known_sent.set(k);
            self.emit(sink, CanonOp::Known(k));
        }
    }

    /// After a move: the last move of a machine-frame move leaves its axes unknown (a
    /// reader of the stream takes them so from the [`CanonOp::MachineMove`] marker itself).
    #[inline(always)]
    fn machine_moved(&self) {
        let (axes, left) = self.machine_known.get();
        if left > 0 {
            self.machine_known.set((axes, left - 1));
            if left == 1 {
                self.known.set(self.known.get() & !axes);
                self.known_sent.set(self.known_sent.get() & !axes);
                self.stated.set(self.stated.get() & !axes);
            }
        }
    }

    /// What the position bookkeeping holds ([`CanonOp::Known`]), to be put back with
    /// [`Interpreter::restore_known`] after blocks run into a sink of their own (a contour
    /// read for its shape): their markers never reach the stream.
    pub(super) fn known_state(&self) -> (u8, u8, u8, (u8, u8)) {
        (self.known.get(), self.known_sent.get(), self.stated.get(), self.machine_known.get())
    }

    /// Puts back what [`Interpreter::known_state`] gave.
    pub(super) fn restore_known(&self, (known, sent, stated, machine): (u8, u8, u8, (u8, u8))) {
        self.known.set(known);
        self.known_sent.set(sent);
        self.stated.set(stated);
        self.machine_known.set(machine);
    }

    /// The position is unknown in every axis from here (a code moved the machine in a way
    /// the reading does not know).
    pub(super) fn position_lost(&self) {
        self.known.set(0);
        self.stated.set(0);
    }

    /// `axes` (bit `k` for axis `k`) are unknown from here, and the stream is told at once: a
    /// change of work offset (its values unknown to the reading: every axis), a tool change or
    /// a length offset change (the tool axis). The next word stating one is written whatever
    /// was written last; an incremental move of one before that is counted from nothing known.
    pub(in crate::interp) fn forget(&self, axes: u8, sink: &mut dyn CanonSink) {
        self.known.set(self.known.get() & !axes);
        self.stated.set(self.stated.get() & !axes);
        let k = self.known.get();
        if k != self.known_sent.get() {
            self.known_sent.set(k);
            self.emit(sink, CanonOp::Known(k));
        }
    }

    /// `axes` (bit `k` for axis `k`) are known from the next move on: a cycle's move to a level
    /// known wherever the tool stands (its absolute R level). The stream is told at once.
    pub(in crate::interp) fn learn(&self, axes: u8, sink: &mut dyn CanonSink) {
        let k = self.known.get() | axes;
        self.known.set(k);
        if k != self.known_sent.get() {
            self.known_sent.set(k);
            self.emit(sink, CanonOp::Known(k));
        }
    }

    /// Whether the program knows the position of axis `k` (a word of the block being executed
    /// stating it absolutely counts).
    pub(in crate::interp) fn knows(&self, k: usize) -> bool {
        (self.known.get() | self.stated.get()) & 1 << k != 0
    }

    fn emit(&self, sink: &mut dyn CanonSink, op: CanonOp) {
        let moves = matches!(
            op,
            CanonOp::StraightTraverse(_)
                | CanonOp::StraightFeed(_)
                | CanonOp::ArcFeed { .. }
                | CanonOp::NurbsFeed { .. }
                | CanonOp::RigidTap(_)
                | CanonOp::StraightProbe(_)
        );
        if moves {
            self.mark_known(sink);
        } else if let CanonOp::MachineMove(m) = &op {
            let axes = (0..6).filter(|&k| m.axes[k].is_some()).fold(0u8, |a, k| a | 1 << k);
            self.machine_known.set((axes, m.moves() as u8));
        }
        self.emit_op(sink, op);
        if moves {
            self.machine_moved();
        }
    }

    fn emit_op(&self, sink: &mut dyn CanonSink, op: CanonOp) {
        let (origin, line) = self.origin_override.unwrap_or((self.origin, self.line));
        match &op {
            CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) | CanonOp::NurbsFeed { end: p, .. } => self.sent.set(*p),
            CanonOp::ArcFeed { first_end, second_end, axis_end, abc, .. } => {
                let (a0, a1, n) = self.st.plane.axes();
                let mut p = [0.0; 6];
                (p[a0], p[a1], p[n]) = (*first_end, *second_end, *axis_end);
                p[3..].copy_from_slice(abc);
                self.sent.set(p);
            }
            _ => {}
        }
        let op = if self.st.rotation.is_some() || self.st.scaling.is_some() || self.st.quill != 0.0 { self.transform(op) } else { op };
        let canon = Canon { op, origin, line };
        // Neither corners nor compensation (the common case): the op goes straight out.
        if self.comp.borrow().is_none() && self.corners.borrow().is_none() {
            sink.emit(canon);
            return;
        }
        let mut corners = self.corners.borrow_mut();
        match corners.as_mut() {
            None => self.compensate(canon, sink),
            Some(k) => {
                k.push(canon);
                for c in k.released.drain(..) {
                    self.compensate(c, sink);
                }
            }
        }
    }

    /// Whether a stage stands between a move and the sink: a call's origin, rotation,
    /// scaling, corners or compensation. Only the general way turns one on; compensation
    /// turns itself off at a move it cannot compensate.
    fn staged(&self) -> bool {
        self.origin_override.is_some()
            || self.st.rotation.is_some()
            || self.st.scaling.is_some()
            || self.st.quill != 0.0
            || self.comp.borrow().is_some()
            || self.corners.borrow().is_some()
    }

    /// A straight move to `to`, as [`Interpreter::emit`] sends it: where no stage stands
    /// between (`staged`, as [`Interpreter::staged`] says), straight to the sink without
    /// moving the op through the general way.
    #[inline(always)]
    fn emit_straight(&self, sink: &mut dyn CanonSink, rapid: bool, to: [f64; 6], staged: bool) {
        let op = |to| if rapid { CanonOp::StraightTraverse(to) } else { CanonOp::StraightFeed(to) };
        if self.known.get() | self.stated.get() != self.known_sent.get() || self.known_sent.get() & !self.known.get() != 0 {
            self.mark_known(sink);
        }
        if staged {
            if self.corners_pass(sink, rapid, to) {
                return;
            }
            return self.emit(sink, op(to));
        }
        self.sent.set(to);
        sink.straight(rapid, &to, self.origin, self.line);
    }

    /// A straight move to `to` where the corner stage is the only stage and nothing waits in
    /// it but perhaps a held move ([`corner::Corners::pass_straight`]): what the stage lets
    /// go goes straight to the sink (`CanonSink::straight`), as [`Interpreter::emit`] would
    /// send the same ops through the stage. False, with nothing changed, otherwise. A dialect
    /// with corner blocks (Heidenhain's `RND`, `CHF`) has the stage open from the start
    /// ([`corner_stage`]), so that each of its moves passes here.
    #[inline(always)]
    fn corners_pass(&self, sink: &mut dyn CanonSink, rapid: bool, to: [f64; 6]) -> bool {
        if self.st.rotation.is_some() || self.st.scaling.is_some() || self.st.quill != 0.0 || self.comp.borrow().is_some() {
            return false;
        }
        let (origin, line) = self.origin_override.unwrap_or((self.origin, self.line));
        let out = match self.corners.borrow_mut().as_mut() {
            Some(k) => k.pass_straight(rapid, to, origin, line),
            None => None,
        };
        let Some(out) = out else { return false };
        self.sent.set(to);
        if let Some(h) = out {
            sink.straight(false, &h.to, h.origin, h.line);
        }
        if rapid {
            sink.straight(true, &to, origin, line);
        }
        true
    }

    /// The stage after corners: cutter compensation when it is on, else the sink.
    fn compensate(&self, canon: Canon, sink: &mut dyn CanonSink) {
        let mut comp = self.comp.borrow_mut();
        match comp.as_mut() {
            None => sink.emit(canon),
            Some(c) => {
                if let Err(problem) = c.push(canon.clone(), sink) {
                    // Compensation stops here; the move runs as programmed.
                    if let Some(c) = comp.take() {
                        c.finish(sink);
                    }
                    sink.emit(canon);
                    self.comp_problem.set(Some(problem));
                }
            }
        }
    }

    /// Sends on what the corner stage holds (before compensation changes or ends).
    fn corners_out(&self, sink: &mut dyn CanonSink) {
        let mut corners = self.corners.borrow_mut();
        if let Some(k) = corners.as_mut() {
            k.finish();
            for c in k.released.drain(..) {
                self.compensate(c, sink);
            }
        }
    }

    /// Ends cutter compensation: the held-back moves go out.
    fn comp_off(&self, sink: &mut dyn CanonSink) {
        if self.comp.borrow().is_none() {
            return;
        }
        self.corners_out(sink);
        if let Some(c) = self.comp.borrow_mut().take() {
            c.finish(sink);
        }
    }

    /// Ends the run: nothing stays held back.
    pub fn flush(&self, sink: &mut dyn CanonSink) {
        self.comp_off(sink);
        // A move the corner stage holds goes out too when the run stops without an end
        // (an error, the end of the text).
        self.corners_out(sink);
    }

    /// The finding for an expression without a value. After a read of data only the machine
    /// has, an arithmetic fault may come from that data: it is a warning that says so.
    pub(super) fn eval_diag(&self, e: EvalError, range: TextRange) -> Diagnostic {
        match e {
            EvalError::Undefined(name) => {
                Diagnostic::new(Code::UndefinedParameter, range, format!("parameter `#<{name}>` is used before it is set"))
            }
            // A whole number above the dictionary's highest variable: that maker's limit.
            EvalError::BadIndex(n) if n >= 0.0 && n.fract() == 0.0 => {
                Diagnostic::new(Code::VariableOutOfRange, range, format!("parameter number {n} is out of range"))
            }
            EvalError::BadIndex(n) => Diagnostic::new(Code::UndefinedParameter, range, format!("parameter number {n} is out of range")),
            EvalError::Domain(what) if self.st.machine_data_read => {
                let mut d = Diagnostic::new(
                    Code::ArithmeticError,
                    range,
                    format!("{what}, after the program read data only the machine has at run time: on the machine the values may differ"),
                );
                d.severity = Severity::Warning;
                d
            }
            EvalError::Domain(what) => Diagnostic::new(Code::ArithmeticError, range, what),
        }
    }

    /// The reading of [`RoundState`] now.
    pub(super) fn round_state(&self) -> RoundState {
        RoundState { params: self.params.clone(), depth: self.depth, st: self.st.clone(), contexts: self.contexts.clone() }
    }

    /// Whether the state now reads as `r` does (without a copy of it).
    pub(super) fn same_round(&self, r: &RoundState) -> bool {
        r.depth == self.depth && r.st == self.st && r.contexts == self.contexts && r.params == self.params
    }

    /// Sets the system variables `block` reads (the position, the tool, the modes: the
    /// interpreter's state) to what they read now. A numbered one is found by its number
    /// where the block writes it as a number (`#5420`), all of them where it computes the
    /// number (`#[5420 + #1]`); a named one by its slot, all of them where the block reads
    /// an element of a named array.
    #[inline(always)]
    pub(super) fn refresh_system_vars(&mut self, block: &Block) {
        // Asked at every block of a loop, most of which read none: no call for those.
        if !block.reads_no_system {
            self.refresh_system_vars_of(block);
        }
    }

    /// [`Interpreter::refresh_system_vars`] for a block that may read some.
    #[inline(never)]
    fn refresh_system_vars_of(&mut self, block: &Block) {
        let macros = &self.dialect.macros;
        for (id, e) in block.exprs.iter().enumerate() {
            match *e {
                Expr::Param(inner) if !macros.system.is_empty() => match block.exprs.get(inner as usize) {
                    Some(&Expr::Num(n)) => {
                        if n >= 0.0
                            && n.fract() == 0.0
                            && n <= f64::from(u32::MAX)
                            && let Some(var) = macros.system_var(n as u32)
                            && let Some(v) = self.system_value(var, 0.0)
                        {
                            let _ = self.params.set(n, v);
                        }
                    }
                    _ => self.refresh_numbered(),
                },
                Expr::Named(r) if !macros.system_named.is_empty() => {
                    let slot = match eval::resolved(block, id as crate::syntax::ExprId) {
                        Some(s) => Some(s),
                        None => self.params.slot_of(&eval::normalised(block.text(r))),
                    };
                    if let Some(s) = slot.filter(|&s| (s as usize) < self.system_by_slot.len()) {
                        let (_, var, constant) = macros.system_named[self.system_by_slot[s as usize]];
                        if let Some(v) = self.system_value(var, constant) {
                            self.params.set_slot(s, v);
                        }
                    }
                }
                Expr::NamedIndex(..) => self.refresh_named(),
                _ => {}
            }
        }
    }

    /// Whether [`Interpreter::refresh_system_vars`] has anything to do for `block`, whose
    /// names are resolved ([`eval::resolve`]): it reads a system variable, or a parameter whose
    /// number or name it computes. Asked once for a block kept to run again.
    pub(super) fn reads_system(&self, block: &Block) -> bool {
        let macros = &self.dialect.macros;
        block.exprs.iter().enumerate().any(|(id, e)| match *e {
            Expr::Param(inner) if !macros.system.is_empty() => match block.exprs.get(inner as usize) {
                Some(&Expr::Num(n)) => n >= 0.0 && n.fract() == 0.0 && n <= f64::from(u32::MAX) && macros.system_var(n as u32).is_some(),
                _ => true,
            },
            Expr::Named(_) if !macros.system_named.is_empty() => {
                eval::resolved(block, id as crate::syntax::ExprId).is_none_or(|s| (s as usize) < self.system_by_slot.len())
            }
            Expr::NamedIndex(..) => true,
            _ => false,
        })
    }

    /// Sets every numbered system variable to what it reads now.
    fn refresh_numbered(&mut self) {
        for &(n, var) in &self.dialect.macros.system {
            if let Some(v) = self.system_value(var, 0.0) {
                let _ = self.params.set(f64::from(n), v);
            }
        }
    }

    /// Sets every named system variable to what it reads now.
    fn refresh_named(&mut self) {
        for s in 0..self.system_by_slot.len() {
            let (_, var, constant) = self.dialect.macros.system_named[self.system_by_slot[s]];
            if let Some(v) = self.system_value(var, constant) {
                self.params.set_slot(s as u32, v);
            }
        }
    }

    /// What system variable `var` reads now; `None` for the ones written, not read (the
    /// probe results, which a probe move sets, and alarms).
    fn system_value(&self, var: SystemVar, constant: f64) -> Option<f64> {
        let st = &self.st;
        let flag = |b: bool| f64::from(u8::from(b));
        let machine = |i: usize| self.machine_pos()[i];
        Some(match var {
            SystemVar::PositionX => st.pos[0],
            SystemVar::PositionY => st.pos[1],
            SystemVar::PositionZ => st.pos[2],
            SystemVar::PositionA => st.pos[3],
            SystemVar::PositionB => st.pos[4],
            SystemVar::PositionC => st.pos[5],
            SystemVar::MachineX => machine(0),
            SystemVar::MachineY => machine(1),
            SystemVar::MachineZ => machine(2),
            SystemVar::MachineA => machine(3),
            SystemVar::MachineB => machine(4),
            SystemVar::MachineC => machine(5),
            // Before the program commands one, the tool the machine last took: unknown where
            // the dictionary says so, else rs274's power-on 0.
            SystemVar::Tool if !st.tool_commanded && self.dialect.macros.modal_tool_unknown => eval::UNKNOWN,
            SystemVar::Tool => f64::from(st.tool),
            SystemVar::SelectedTool => f64::from(st.selected_tool),
            SystemVar::Feed => st.feed,
            SystemVar::Speed => st.speed,
            SystemVar::ToolRadius | SystemVar::ToolDiameter => {
                // A tool the tool table does not list: its radius is the machine's.
                let unlisted = if self.dialect.macros.unlisted_tools_unknown { eval::UNKNOWN } else { 0.0 };
                let half = if var == SystemVar::ToolRadius { 2.0 } else { 1.0 };
                self.tool_diameter(st.tool).map_or(unlisted, |d| d / half / st.units.to_mm())
            }
            SystemVar::MotionMode => st.motion_code.map_or(800.0, |c| f64::from(self.code(c).number)),
            SystemVar::Plane => match st.plane {
                Plane::Xy => 170.0,
                Plane::Xz => 180.0,
                Plane::Yz => 190.0,
            },
            SystemVar::CutterComp => match self.comp.borrow().as_ref() {
                None => 400.0,
                Some(c) if c.left() => 410.0,
                Some(_) => 420.0,
            },
            SystemVar::Metric => flag(st.units == Units::Mm),
            SystemVar::Imperial => flag(st.units != Units::Mm),
            SystemVar::Absolute => flag(st.distance == DistanceMode::Absolute),
            SystemVar::Incremental => flag(st.distance == DistanceMode::Incremental),
            SystemVar::InverseTime => flag(st.inverse_time),
            SystemVar::UnitsPerMinute => flag(!st.inverse_time && !st.feed_per_rev),
            SystemVar::UnitsPerRev => flag(!st.inverse_time && st.feed_per_rev),
            SystemVar::CoordSystem => match st.wcs {
                1..=6 => 530.0 + 10.0 * f64::from(st.wcs),
                7..=9 => 584.0 + f64::from(st.wcs),
                _ => 540.0,
            },
            SystemVar::ToolOffsetOn => flag(st.tool_offset.iter().any(|&o| o != 0.0)),
            SystemVar::RetractRPlane => flag(st.retract == Retract::RPlane),
            SystemVar::RetractOldZ => flag(st.retract == Retract::Initial),
            SystemVar::SpindleRpmMode => flag(st.css_max.is_none()),
            SystemVar::SpindleCssMode => flag(st.css_max.is_some()),
            SystemVar::IjkAbsolute => flag(!st.arc_incremental),
            SystemVar::DiameterMode => flag(st.diameter),
            SystemVar::RadiusMode => flag(!st.diameter),
            SystemVar::SpindleOn => flag(st.spindle != Spindle::Stopped),
            SystemVar::SpindleCw => flag(st.spindle == Spindle::Cw),
            SystemVar::Mist => flag(st.mist),
            SystemVar::Flood => flag(st.flood),
            SystemVar::FeedOverride => flag(st.overrides.0),
            SystemVar::SpeedOverride => flag(st.overrides.1),
            SystemVar::CallLevel => f64::from(self.depth),
            SystemVar::Line => f64::from(self.line),
            SystemVar::Constant => constant,
            // The probe results are written when a probe move ends, and the program may
            // write them too, as any parameter.
            SystemVar::ProbeX | SystemVar::ProbeY | SystemVar::ProbeZ | SystemVar::ProbeTripped => return None,
            SystemVar::Alarm | SystemVar::StopMessage => return None,
        })
    }

    /// An unused word: ignored, or an error where the dialect rejects it.
    fn unused(&self, mut d: Diagnostic) -> Diagnostic {
        if self.dialect.behaviour.unused_words_rejected {
            d.severity = Severity::Error;
            d.message.push_str("; the control stops here");
        } else {
            d.message.push_str("; ignored");
        }
        d
    }

    /// Reports a finding, at most [`NOTE_LIMIT`] times per kind, and counts the rest; an error
    /// every time at a new place, for the control stops at each (a fourth unknown statement is
    /// where a program edited there stops, and what an edit breaks or fixes is told from
    /// them). A listed finding met again (a loop's next pass) is neither listed nor counted;
    /// only the listed ones are remembered, so memory stays bounded by the program's text.
    fn limited(&mut self, diags: &mut Vec<Diagnostic>, key: &str, d: Diagnostic) {
        let error = d.is_error();
        let listed = (d.range.start, d.range.end, d.message);
        if self.noted.contains(&listed) {
            return;
        }
        let n = match self.notes.get_mut(key) {
            Some(n) => n,
            None => self.notes.entry(key.to_owned()).or_insert(0),
        };
        if !error {
            *n += 1;
        }
        if *n <= NOTE_LIMIT || error {
            let d = Diagnostic { message: listed.2.clone(), ..d };
            self.noted.insert(listed);
            diags.push(d);
        }
    }

    /// Opens the corner stage at the first block with a corner word (`X50 ,R5`): its move is
    /// held until the next one shows the corner. The stage starts where the tool is.
    fn open_corner_stage(&mut self) {
        if self.corners.get_mut().is_some() {
            return;
        }
        let at = self.sent.get();
        let at = if self.st.rotation.is_some() || self.st.scaling.is_some() || self.st.quill != 0.0 {
            match self.transform(CanonOp::StraightTraverse(at)) {
                CanonOp::StraightTraverse(p) => p,
                _ => at,
            }
        } else {
            at
        };
        let reduce = self.dialect.behaviour.corners_reduced;
        *self.corners.get_mut() = Some(corner::Corners::starting_at(self.st.plane, at).reducing(reduce));
    }

    fn slot(&self, role: Role) -> Option<f64> {
        self.slots[role as usize].map(|s| s.value)
    }

    /// Whether the block's word of `role` read an unknown value (and was left out, with a note).
    fn word_unknown(&self, role: Role) -> bool {
        self.unknown_roles & (1 << role as u32) != 0
    }

    fn code(&self, i: usize) -> &'a CodeDef {
        &self.dialect.codes[i]
    }

    /// Reports a compensation problem met while emitting the last block.
    fn comp_report(&mut self, diags: &mut Vec<Diagnostic>) {
        if let Some(p) = self.comp_problem.take() {
            let why = match p {
                comp::CompProblem::Gouge => "the tool radius is larger than an inside arc",
                comp::CompProblem::NoIntersection => "the offset paths of an inside corner do not meet",
                comp::CompProblem::ArcEntry => "compensation cannot start with an arc",
            };
            let d = Diagnostic::new(
                Code::CompGouge,
                self.origin,
                format!("cutter compensation stops: {why}; the programmed path is used from here"),
            );
            diags.push(d);
        }
    }

    /// Executes one block.
    pub fn execute(&mut self, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.execute_block(block, sink, diags);
        if self.comp_problem.get().is_some() {
            self.comp_report(diags);
        }
        self.corner_report(diags);
    }

    /// Reports a corner block that could not be made while emitting the last block.
    #[inline(always)]
    fn corner_report(&mut self, diags: &mut Vec<Diagnostic>) {
        // At every block: without a call where the corner stage holds no problem.
        if self.corners.get_mut().as_ref().is_some_and(|k| k.problem.is_some()) {
            self.corner_problem(diags);
        }
    }

    /// [`Interpreter::corner_report`] where the corner stage holds a problem.
    #[cold]
    #[inline(never)]
    fn corner_problem(&mut self, diags: &mut Vec<Diagnostic>) {
        let problem = self.corners.get_mut().as_mut().and_then(|k| k.problem.take());
        if let Some(p) = problem {
            let code = if p.only_unmodelled() { Code::Unsupported } else { Code::BadArc };
            let mut d = Diagnostic::new(code, self.origin, format!("the corner is left sharp: {}", p.describe()));
            if !p.only_unmodelled() && self.unknown_words > 0 {
                // A move before it kept a position for an axis whose value is unknown here.
                d.severity = Severity::Note;
                d.message.push_str("; moves before it left out words whose values come from outside the file, so the machine may make it");
            }
            diags.push(d);
        }
    }

    /// A block's tool axis words (CLDATA `GOTO/x,y,z,i,j,k`): the axis goes into the canon
    /// where it changes, before the block's move.
    fn tool_axis(&mut self, sink: &mut dyn CanonSink) {
        let mut axis = self.tool_axis;
        for (k, role) in [Role::ToolAxisI, Role::ToolAxisJ, Role::ToolAxisK].into_iter().enumerate() {
            if let Some(v) = self.slots[role as usize] {
                axis[k] = v.value;
            }
        }
        if axis != self.tool_axis {
            self.tool_axis = axis;
            self.emit(sink, CanonOp::ToolAxis(axis));
        }
    }

    /// Executes one block: the fast lane's plain move, or the read phase and then the
    /// execute phase's steps in the dialect's order.
    fn execute_block(&mut self, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.origin = block.range;
        self.line = block.line;
        self.stated.set(0);
        if self.st.ended {
            if !block.is_empty() && !block.delimiter && !self.after_end_noted {
                self.after_end_noted = true;
                diags.push(Diagnostic::new(Code::AfterProgramEnd, block.range, "blocks after the end of the program are not executed"));
            }
            return;
        }
        if block.skip && self.profile.block_delete {
            return;
        }
        if block.skip {
            // The plan tells the moves that hang on the block-delete switch.
            self.emit(sink, CanonOp::Setting(Setting::BlockDelete));
        }
        if self.profile.fast_lane
            && (self.fast_move(block, sink, diags) || self.assignments_only(block, diags) || self.inert_code(block, diags))
        {
            return;
        }
        if !self.read_and_assign(block, diags) {
            return;
        }
        if self.filled & (1 << Role::ToolAxisI as u32 | 1 << Role::ToolAxisJ as u32 | 1 << Role::ToolAxisK as u32) != 0 {
            self.tool_axis(sink);
        } else if self.filled & (1 << Role::A as u32 | 1 << Role::B as u32 | 1 << Role::C as u32) != 0 && self.rotary_turns_tool() {
            self.rotary_tool_axis(sink, diags);
        } else if self.filled & (1 << Role::C as u32) != 0 && self.st.frame_set.is_some() && !self.st.tcp {
            self.turn_part_under_plane(sink);
        }
        if let Some(sub) = self.remap_call.take() {
            // Carried out after the block (a call or return its own codes ask for goes instead).
            self.request = Some(Request::Remap { sub });
        }
        if self.macro_codes(block, diags) {
            return;
        }
        let motions = self.motions;
        if self.filled & CORNER_WORDS != 0 {
            self.open_corner_stage();
        }
        if self.is_plain(block) {
            // The common block: axis words only, so only the motion step has work.
            self.step(Step::Motion, block, sink, diags);
            self.modal_macro_after(motions);
            if self.st.cycle_modal {
                self.cycles_after(motions, block.range, sink, diags);
            }
            return;
        }
        if !self.run_steps(block, sink, diags) {
            return;
        }
        // Codes the dialect files under `misc` take effect last; most are only recorded.
        if self.code_steps & (1 << Step::Misc as u32) != 0 {
            self.run_codes(Step::Misc, block, sink, diags);
        }
        // After a tool change, such a control reads its position back from the machine: the
        // last move's end, so what the block shifted without moving (a G43 beside the M6) is
        // not where the next block starts.
        if self.dialect.behaviour.tool_change_rereads_position
            && self.codes.iter().any(|&(c, _)| self.code(c).meaning == Meaning::ToolChange)
        {
            self.st.pos = self.sent.get();
        }
        self.corner_words(block.range, diags);
        self.modal_macro_after(motions);
        self.cycles_after(motions, block.range, sink, diags);
    }

    /// The read phase with the block's assignments, before or after its reads as the dialect
    /// says, and the alarm the block raises by its word. False when the block does not go on
    /// to execute: it has an error, or the alarm ended the program.
    fn read_and_assign(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        if !self.around_assignments(block, diags, |me, diags| me.read(block, diags)) {
            return false;
        }
        if let Some(s) = self.slots[Role::AlarmNumber as usize] {
            self.alarm(block, 0.0, s.value, s.range, diags);
        }
        !self.st.ended
    }

    /// The block's system variables refreshed, then its `read` and its assignments in the
    /// dialect's order (`assign_before_reads`); false when `read` is.
    #[inline]
    fn around_assignments(
        &mut self,
        block: &Block,
        diags: &mut Vec<Diagnostic>,
        read: impl FnOnce(&mut Self, &mut Vec<Diagnostic>) -> bool,
    ) -> bool {
        let system_vars = !self.dialect.macros.system.is_empty() || !self.dialect.macros.system_named.is_empty();
        if system_vars && !block.exprs.is_empty() {
            self.refresh_system_vars(block);
        }
        let early = self.dialect.behaviour.assign_before_reads;
        if early {
            self.assign(block, diags);
        }
        if !read(self, diags) {
            return false;
        }
        if !early {
            self.assign(block, diags);
        }
        true
    }

    /// Runs `block` when it holds assignments and nothing else (`#<x> = [#<col> * 0.1]`,
    /// `R1=R1+1`, `Q4 = Q1 * 0.5`), the most of a macro program's blocks, or nothing at all (a
    /// jump's label on a line of its own, Siemens `POINT:`, met at every pass of its loop);
    /// false, with nothing changed, when it holds more, or the state has work after any block
    /// (a modal cycle or macro, a stop message). It does what `read_and_assign` and the motion
    /// step do for such a block, without their look at words and codes it has none of (with
    /// no word read, no slot is filled: no axis, so the motion step finds no move).
    fn assignments_only(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        if !block.words.is_empty()
            || !block.comments.is_empty()
            || block.control.is_some()
            || self.st.cycle_modal
            || self.st.modal_macro.is_some()
            || self.stop_message.is_some()
        {
            return false;
        }
        self.assignments_alone(block, diags);
        true
    }

    /// What `read_and_assign` and the motion step do for a block whose words `read` leaves
    /// nothing of: the state a block without words leaves, then its assignments.
    #[inline(always)]
    fn assignments_alone(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) {
        // What `read` leaves for a block without words.
        self.clear_block();
        self.block_read = true;
        self.misread_before = self.misread;
        self.block_misread = false;
        self.numbered_spindles = false;
        self.has_axes = false;
        if !self.dialect.macros.system.is_empty() || !self.dialect.macros.system_named.is_empty() {
            self.refresh_system_vars(block);
        }
        self.assign(block, diags);
    }

    /// Runs `block` when it holds one inert keyword code with its value, and perhaps
    /// assignments (Heidenhain's `FN 0:` to `FN 4:` arithmetic, `FN 12: IF ... GOTO LBL 2`
    /// whose jump the driver makes): the code means nothing to execute, so the block does
    /// what `read_and_assign` does and no step has work. False, with nothing changed, for any
    /// other block, or where the state has work after any block (as `assignments_only`).
    fn inert_code(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        if block.words.len() != 2
            || !block.comments.is_empty()
            || self.st.cycle_modal
            || self.st.modal_macro.is_some()
            || self.stop_message.is_some()
        {
            return false;
        }
        let Some((c, word)) = self.inert_code_words(block) else { return false };
        if !block.assigns.is_empty() {
            // Heidenhain's `FN 3: Q3 = +Q2 * +0.1`: the code means nothing to execute, and what
            // `read` would put of it (the block's code, its value's slot) nothing reads after
            // the block (the next block's `read`, or a plain move, clears it; no step runs for
            // it here): the block is its assignments, as `Q3 = Q2 * 0.1` is
            // (`assignments_only`), without the code read for nobody.
            self.assignments_alone(block, diags);
            return true;
        }
        let at = block.words.iter().find(|w| w.role == Role::Keyword).map_or(block.range, |w| w.range);
        self.around_assignments(block, diags, |me, _| {
            me.read_inert_code(c, at, word);
            true
        })
    }

    /// Whether the block, read, has work only at the motion step: no codes, no named cycle,
    /// no comments or stop message, and none of the words other steps take (F, S, T, the
    /// corner words).
    fn is_plain(&self, block: &Block) -> bool {
        self.block_cycle.is_none()
            && self.code_steps == 0
            && block.comments.is_empty()
            && self.stop_message.is_none()
            && self.st.round_modal.is_none()
            && self.filled
                & (1 << Role::F as u32 | 1 << Role::S as u32 | 1 << Role::T as u32 | 1 << Role::SpindleLimit as u32 | CORNER_WORDS)
                == 0
    }

    /// Runs the steps of the dialect's execution order that the block has work at (the
    /// motion step always). False once the program has ended.
    fn run_steps(&mut self, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) -> bool {
        for &step in &self.dialect.execution_order {
            let needed = match step {
                Step::Comment => !block.comments.is_empty(),
                Step::Feed => self.slots[Role::F as usize].is_some(),
                Step::Speed => self.slots[Role::S as usize].is_some() || self.slots[Role::SpindleLimit as usize].is_some(),
                Step::ToolSelect => self.slots[Role::T as usize].is_some(),
                Step::Motion => true,
                Step::Stop => self.stop_message.is_some() || self.code_steps & (1 << step as u32) != 0,
                _ => self.code_steps & (1 << step as u32) != 0,
            };
            if !needed {
                continue;
            }
            self.step(step, block, sink, diags);
            if self.st.ended {
                return false;
            }
        }
        if block.spindle.is_some() {
            self.address_spindle(None, sink);
        }
        true
    }

    /// Before the first block: a control that starts in inches, in another plane than XY (a
    /// lathe in ZX), or with feed per revolution, says so, as its program would, so that the
    /// canon is read in the right units, plane and feed mode.
    fn start(&mut self, sink: &mut dyn CanonSink) {
        // The units first: what follows is said in them (a writer that follows the program's
        // units takes them before it writes anything).
        if self.st.units == Units::Inch {
            self.emit(sink, CanonOp::UseLengthUnits(Units::Inch));
        }
        if self.st.plane != Plane::Xy {
            self.emit(sink, CanonOp::SelectPlane(self.st.plane));
        }
        if self.st.feed_per_rev {
            self.emit(sink, CanonOp::SetFeedMode(FeedMode::PerRevolution));
        }
        if self.st.diameter {
            self.emit(sink, CanonOp::Setting(crate::canon::Setting::DiameterMode(true)));
        }
        // A machine whose kinematics start in a 5-axis model (LinuxCNC switchkins type 0 of
        // `5axiskins`, `xyzac-trt-kins` without `sparm=identityfirst`) keeps the tool centre
        // point on the part from power-on.
        let types = self.profile.machine.kinematics.as_ref().map(|k| k.types.as_slice());
        if types.and_then(<[_]>::first) == Some(&machine::Kinematics::ToolCentrePoint) {
            (self.st.tcp, self.st.tcp_machine) = (true, true);
            self.emit(sink, CanonOp::Setting(Setting::ToolCentrePoint(true)));
        }
    }

    /// Evaluates `e` of `block`. On a control where an unset variable reads as 0,
    /// each one met is set to 0, with a note, and the expression evaluated again.
    pub(super) fn eval(
        &mut self,
        block: &Block,
        e: crate::syntax::ExprId,
        range: TextRange,
        diags: &mut Vec<Diagnostic>,
    ) -> Result<f64, EvalError> {
        self.params.take_unknown_read();
        if let Some(v) = eval::eval_fast(block, e, &self.params) {
            // Ordinary numbers only: nothing unknown was read, nothing to say.
            return Ok(v);
        }
        loop {
            match eval::eval(block, e, &self.params) {
                Err(EvalError::Undefined(name)) if self.dialect.lexical.system_variable_prefix.is_some_and(|p| name.starts_with(p)) => {
                    // The control's own data (`$P_TOOLNO`, `$AA_IM[X]`, `$TC_DP6[1,1]`): a value
                    // the machine has and this file does not, so unknown, never a made-up 0.
                    let msg = format!("system variable `{name}` is the control's data, unknown here");
                    self.limited(diags, "unknown-variable", Diagnostic::new(Code::UnknownValue, range, msg));
                    self.st.machine_data_read = true;
                    self.params.set_named(&name, eval::UNKNOWN);
                }
                Err(EvalError::Undefined(name)) if self.dialect.macros.unset_unknown => {
                    // Global user data (Siemens GUD) or the caller's: it has a value, unknown here.
                    let msg = format!("`{name}` is neither declared nor set in this file: global data or the caller's, unknown here");
                    self.limited(diags, "unknown-variable", Diagnostic::new(Code::UnknownValue, range, msg));
                    self.params.set_named(&name, eval::UNKNOWN);
                }
                Err(EvalError::Undefined(name))
                    if eval::is_global(&name) && self.dialect.lexical.parameter.is_some_and(|(_, named)| named) =>
                {
                    // A global read before this file sets it (`#<_td>`): the control stops unless
                    // another program set it before (globals persist between programs); said,
                    // then read as unknown, so that what it feeds is not lost with it.
                    diags.push(self.eval_diag(EvalError::Undefined(name.clone()), range));
                    self.params.set_named(&name, eval::UNKNOWN);
                }
                Err(EvalError::Undefined(name)) if self.dialect.macros.unset_reads_zero => {
                    let msg = format!("`{name}` is read before this program sets it (machine data or set elsewhere); taken as 0");
                    diags.push(Diagnostic::new(Code::UnsetVariable, range, msg));
                    self.params.set_named(&name, 0.0);
                }
                r => {
                    if let Some(eval::UnknownSource::Numbered(n)) = self.params.unknown_read_peek()
                        && self.depth == 0
                        && self.is_argument(n)
                    {
                        self.called_by(|| format!("it reads argument #{n} before writing it"));
                    }
                    return r;
                }
            }
        }
    }

    /// Whether local `n` is one a macro call's arguments set.
    fn is_argument(&self, n: u32) -> bool {
        self.dialect.macros.arguments.iter().flatten().any(|&a| u32::from(a) == n)
    }

    /// What an unknown value read last came from, for a message.
    pub(super) fn unknown_what(&self) -> String {
        match self.params.take_unknown_read() {
            Some(eval::UnknownSource::Numbered(n)) if self.depth == 0 && self.is_argument(n) => {
                format!("argument #{n}, which the caller gives")
            }
            Some(eval::UnknownSource::Numbered(n)) => {
                let sigil = self.dialect.lexical.parameter.map_or('#', |(c, _)| c);
                match self.dialect.macros.system_var(n) {
                    Some(SystemVar::ToolRadius | SystemVar::ToolDiameter) => {
                        format!(
                            "{sigil}{n}, the tool's size, which the configured tool table does not give (the machine's tool table holds it)"
                        )
                    }
                    // A variable of the second bank by its own sigil (LNC `@100`).
                    _ => match self.dialect.lexical.global_parameter.filter(|&(_, first)| n >= first) {
                        Some((g, first)) => format!("{g}{}, which is set outside this file (a global variable)", n - first),
                        // A variable of a bank named by letters (Heidenhain `QR1`).
                        None => match self
                            .dialect
                            .lexical
                            .parameter_banks
                            .iter()
                            .filter(|(_, first)| n >= *first)
                            .max_by_key(|(_, first)| *first)
                        {
                            Some((prefix, first)) => {
                                format!("{prefix}{}, which is set outside this file (retained, or machine data)", n - first)
                            }
                            None => format!("{sigil}{n}, which is set outside this file (retained, or machine data)"),
                        },
                    },
                }
            }
            Some(eval::UnknownSource::Named(name)) => format!("`{name}`, which the caller or the control's global data sets"),
            Some(eval::UnknownSource::Text) => "a text value, which the analysis does not compare".to_owned(),
            None => "a value set outside this file".to_owned(),
        }
    }

    fn assign(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) {
        if let [a] = block.assigns.as_slice()
            && self.assign_one_fast(block, a)
        {
            return;
        }
        // All reads of a block happen before its assignments take effect.
        let mut pending = std::mem::take(&mut self.pending);
        pending.clear();
        // Where each unknown value assigned came from, by the pending assignment.
        let mut origins = Vec::new();
        for (k, a) in block.assigns.iter().enumerate() {
            let value = match self.eval(block, a.value, a.range, diags) {
                Ok(v) => {
                    // Kept only for unknown values: the usual block allocates nothing here.
                    if eval::is_unknown(v) {
                        origins.resize(pending.len(), None);
                        origins.push(self.params.unknown_read_peek());
                    }
                    v
                }
                Err(e) => {
                    diags.push(self.eval_diag(e, a.range));
                    continue;
                }
            };
            match a.target {
                ParamTarget::Numbered(e) => match self.eval(block, e, a.range, diags) {
                    Ok(n) => pending.push(PendingAssign {
                        number: Some(n),
                        name: TextRange::default(),
                        index: None,
                        slot: None,
                        value,
                        range: a.range,
                    }),
                    Err(e) => diags.push(self.eval_diag(e, a.range)),
                },
                ParamTarget::Named(name) => {
                    let slot = eval::resolved_assign(block, k);
                    pending.push(PendingAssign { number: None, name, index: None, slot, value, range: a.range });
                }
                ParamTarget::NamedIndex(name, e) => match self.eval(block, e, a.range, diags) {
                    Ok(i) => pending.push(PendingAssign { number: None, name, index: Some(i), slot: None, value, range: a.range }),
                    Err(e) => diags.push(self.eval_diag(e, a.range)),
                },
            }
        }
        for (k, &PendingAssign { number, name, index, slot, value, range }) in pending.iter().enumerate() {
            let origin = origins.get(k).cloned().flatten();
            match number {
                // `#[#111+5] = 1280` with #111 the caller's: which variable the control writes
                // is not known here. The write is not followed (it must never land on #0, the
                // vacant value, as the unknown index would round to), and that is no fault.
                Some(n) if eval::is_unknown(n) => {
                    let msg = "the number of the variable this assigns is set outside this file: which one is written is not known here, and the analysis does not follow the write";
                    diags.push(Diagnostic::new(Code::UnknownValue, range, msg));
                }
                Some(n) => {
                    // A whole number (compared, not `fract`: no call to `trunc` per assignment).
                    let whole = n >= 0.0 && n <= f64::from(u32::MAX) && f64::from(n as u32) == n;
                    let system = if whole { self.dialect.macros.system_var(n as u32) } else { None };
                    match system {
                        Some(SystemVar::Alarm) => self.alarm(block, n, value, range, diags),
                        Some(SystemVar::StopMessage) => {
                            let msg = self.block_comment(block);
                            diags.push(Diagnostic::new(Code::ProgramMessage, range, format!("the program stops with message: {msg}")));
                            self.stop_message = Some(msg);
                        }
                        _ if n == 0.0 && self.dialect.macros.null_value => {
                            diags.push(Diagnostic::new(Code::UndefinedParameter, range, "#0 is the vacant value and cannot be assigned"));
                        }
                        _ => {
                            if let Err(e) = self.params.set(n, value) {
                                diags.push(self.eval_diag(e, range));
                            } else if self.params.derives(&origin) && n >= 0.0 && n.fract() == 0.0 {
                                self.params.derive(eval::UnknownSource::Numbered(n as u32), origin);
                            }
                        }
                    }
                }
                None if slot.is_some() && index.is_none() => {
                    let slot = slot.unwrap_or(eval::NO_SLOT);
                    self.params.set_slot(slot, value);
                    if self.params.derives(&origin) {
                        self.params.derive(eval::UnknownSource::Named(self.params.slot_name(slot).to_owned()), origin);
                    }
                }
                None => {
                    let name = eval::normalised(block.text(name));
                    match index {
                        // `WERT[R1] = 5` with R1 set outside this file: which element is written
                        // is not known here, as for `#[#111+5]` above; the write is not
                        // followed (it must not land on a key a later read through another
                        // unknown index finds).
                        Some(i) if eval::is_unknown(i) => {
                            let msg = format!(
                                "the element of `{name}` this assigns is numbered by a value set outside this file: which one is written is not known here, and the analysis does not follow the write"
                            );
                            diags.push(Diagnostic::new(Code::UnknownValue, range, msg));
                        }
                        Some(i) if self.dialect.macros.system_element(&name, i) == Some(SystemVar::Alarm) => {
                            self.alarm(block, 0.0, value, range, diags)
                        }
                        // The key a read of `name[i]` looks up (`eval`).
                        Some(i) => self.params.set_named(&format!("{name}[{i}]"), value),
                        None => {
                            self.params.set_named(&name, value);
                            if self.params.derives(&origin) {
                                self.params.derive(eval::UnknownSource::Named(name.into_owned()), origin);
                            }
                        }
                    }
                }
            }
        }
        self.pending = pending;
    }

    /// A block's only assignment where its value and target are ordinary numbers
    /// ([`eval::eval_fast`]) and it sets a named parameter by its slot or an ordinary numbered
    /// one (no system variable, no `#0`, in the table), with no unknown value's origin to
    /// forget: what [`Interpreter::assign`] does for it, without the list of pending
    /// assignments. False, with nothing changed, otherwise.
    #[inline]
    fn assign_one_fast(&mut self, block: &Block, a: &crate::syntax::Assign) -> bool {
        if self.params.derives(&None) {
            return false;
        }
        let Some(value) = eval::eval_fast(block, a.value, &self.params) else { return false };
        match a.target {
            ParamTarget::Named(_) => {
                let Some(slot) = eval::resolved_assign(block, 0) else { return false };
                self.params.take_unknown_read();
                self.params.set_slot(slot, value);
            }
            ParamTarget::Numbered(e) => {
                if let Some(i) = eval::resolved_assign(block, 0) {
                    // An ordinary parameter, resolved once when the block was kept.
                    self.params.set_resolved(i, value);
                    self.params.take_unknown_read();
                    return true;
                }
                let Some(n) = eval::eval_fast(block, e, &self.params) else { return false };
                let whole = n >= 0.0 && n <= f64::from(u32::MAX) && f64::from(n as u32) == n;
                if !whole || self.dialect.macros.system_var(n as u32).is_some() || (n == 0.0 && self.dialect.macros.null_value) {
                    return false;
                }
                // Out of the table: the general way says so.
                if self.params.set_whole(n as u32, value).is_err() {
                    return false;
                }
                self.params.take_unknown_read();
            }
            ParamTarget::NamedIndex(..) => return false,
        }
        true
    }

    /// The text of the block's first comment, or an empty string.
    fn block_comment(&self, block: &Block) -> String {
        block.comments.first().map(|r| block.text(*r).trim().to_owned()).unwrap_or_default()
    }

    /// `#3000 = n (MESSAGE)`: the control stops with an alarm.
    fn alarm(&mut self, block: &Block, var: f64, value: f64, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let msg = self.block_comment(block);
        let number = if eval::is_null(value) { var } else { var + value.trunc() };
        let sep = if msg.is_empty() { "" } else { ": " };
        let d = match &self.st.guessed {
            // Reached on the way chosen at a condition on a value only the machine or the
            // caller has: the control stops here only if it goes this way, which is not known.
            Some(head) => {
                let mut d = Diagnostic::new(
                    Code::ProgramAlarm,
                    range,
                    format!(
                        "the program raises alarm {number}{sep}{msg} on the way taken at `{head}`, a condition on a value unknown here: the control stops here only if it goes this way; the analysis follows it no further"
                    ),
                );
                d.severity = crate::diag::Severity::Warning;
                d
            }
            None => {
                Diagnostic::new(Code::ProgramAlarm, range, format!("the program raises alarm {number}{sep}{msg}; execution stops here"))
            }
        };
        diags.push(d);
        self.st.ended = true;
    }
}

// Role and step sets are bit masks.
const _: () = assert!(Role::COUNT <= 128 && Step::ALL.len() <= 32);

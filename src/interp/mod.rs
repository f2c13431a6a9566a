//! The modal interpreter: blocks → canonical ops, with modal state.
//!
//! Each block goes through *read* (evaluate values, look up codes, check groups and
//! parameters) and then *execute*, step by step in the order the dialect's
//! `<execution-order>` gives. Everything the interpreter knows about a dialect comes from
//! [`Dialect`]: meanings, roles and behaviour flags. It never fails: findings become
//! diagnostics and an erroneous block is skipped.

mod comp;
mod context;
mod corner;
mod cycle;
mod define;
pub mod eval;
mod fast;
mod flow;
mod g7x;
mod motion;

use crate::dialect::DataForm;
pub use flow::{NoPrograms, ProgramSource, run};

use std::collections::{BTreeMap, BTreeSet};

use crate::canon::{Canon, CanonOp, CanonSink, DistanceMode, FeedMode, Plane, Setting, Units};
use crate::diag::{Code, Diagnostic, Severity};
use crate::dialect::{CodeDef, DecimalInput, Dialect, Directive, Meaning, Role, Step, SystemVar, TimeUnit};
use crate::syntax::{Block, ParamTarget, Value, WordMode};
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
    /// Most blocks one run executes again (loop passes, backward jumps, repeated calls)
    /// before the analysis stops with a warning: this bounds the time and memory of any run
    /// by the size of the file, whatever the loop budgets. Blocks run for the first time do
    /// not count, so a long program streams whole.
    pub max_repeated_blocks: u64,
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
    /// Whether the file is a main program, a program others call, or to be told from its
    /// form (the config's `role`, `check --as`).
    pub role: ProgramRole,
    /// How a condition on an unknown value goes when neither way leads to an alarm; `None`
    /// takes the dictionary's choice (`unknown-conditions`).
    pub unknown_conditions: Option<bool>,
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

impl Default for Profile {
    fn default() -> Profile {
        Profile {
            block_delete: false,
            tools: BTreeMap::new(),
            home1: [0.0; 6],
            home2: [0.0; 6],
            max_loop_iterations: 1_000_000,
            max_blocks: 200_000_000,
            max_repeated_blocks: 250_000,
            programs: None,
            stock: None,
            fast_lane: true,
            role: ProgramRole::Auto,
            unknown_conditions: None,
        }
    }
}

/// Rotates a point about the origin by `degrees`, counter-clockwise.
/// A blank the program defines (`BLK FORM`, `WORKPIECE`), passed on as the stock comment plan
/// recovery reads, as a CAM system writes it: `STOCK X0 Y0 Z-40 X100 Y100 Z0`.
fn stock_comment(min: [f64; 3], max: [f64; 3]) -> CanonOp {
    let n = |v: f64| format!("{}", v + 0.0);
    CanonOp::Comment(format!("STOCK X{} Y{} Z{} X{} Y{} Z{}", n(min[0]), n(min[1]), n(min[2]), n(max[0]), n(max[1]), n(max[2])))
}

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
    diags
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
        /// Its last block number (Q).
        last: u32,
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
    /// Programmable scaling (G51): centre and factor per linear axis.
    scaling: Option<([f64; 3], [f64; 3])>,
    /// Whether the block's motion mode was already active before it.
    motion_continued: bool,
    /// G93: F is the inverse of each move's time in minutes.
    inverse_time: bool,
    /// Feed per spindle revolution (G95).
    feed_per_rev: bool,
    /// The circle centre / pole in the plane's two axes (`CC X Y`), program coordinates.
    pole: (f64, f64),
    /// The direction of the last arc, for arcs that do not state one (`C X Y` after `DR-`).
    arc_cw: bool,
    /// The cycle defined last (`CYCL DEF 200`, `MCALL CYCLE81(...)`), for later calls.
    defined_cycle: Option<define::Defined>,
    /// Whether the defined cycle runs after every move (`MCALL`, `M89`).
    cycle_modal: bool,
    /// The direction of travel at the end of the last move in the plane (unit vector).
    tangent: Option<(f64, f64)>,
    /// The side of the last radius compensation (left: G41, `RL`), which perpendicular
    /// approaches and departures take.
    comp_left: bool,
    /// The first corner of a workpiece blank (`BLK FORM 0.1`), waiting for the second.
    blank_min: Option<[f64; 3]>,
    /// Cutter compensation has just ended: the next move leaves the compensated path.
    leaving_comp: bool,
    /// Lathe diameter mode (G7): X words give diameters.
    diameter: bool,
    /// Constant surface speed (G96): S is a surface speed, and this is the spindle's
    /// speed limit; `None` in G97, where S is in revolutions per minute.
    css_max: Option<f64>,
    /// The spindle speed limit a lathe's `G50 S` set, which a G96 without D keeps.
    spindle_limit: Option<f64>,
    /// A lathe roughing cycle's depth of cut and retract, as its first block (`G71 U2. R.5`)
    /// set them for the ones after it.
    rough_cut: Option<(f64, f64)>,
    /// The initial level of the canned cycles in force: the hole axis position when the
    /// first of them began. G98 returns to it, and in G91 R counts from it.
    cycle_initial: Option<f64>,
    /// Whether the program has read data only the machine has (FN 18): arithmetic faults
    /// after it may come from that data.
    machine_data_read: bool,
    /// Whether a length with a decimal point has been read under least-increment input:
    /// after one, a length without (`X118`, 0.118 mm) is suspect.
    length_points: bool,
    /// Whether the feed is the caller's (a called program that has set none) or an unknown
    /// value: not zero.
    feed_unknown: bool,
    /// Whether the spindle is the caller's (a called program that has not set it).
    spindle_unknown: bool,
    /// Whether the feed and the spindle speed overrides are enabled (M48 to M51).
    overrides: (bool, bool),
}

impl State {
    /// The offsets of work coordinate system `wcs` (1 for G54; an additional one is 0 until
    /// the program sets it).
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
    /// Set by a block that calls or returns; taken by the flow driver.
    request: Option<Request>,
    /// Call depth (0 in the main program), kept by the flow driver.
    pub(super) depth: u32,
    /// Modal state saved per call level (M70, M73), index 0 for the main program.
    contexts: Vec<Option<context::Context>>,
    /// A call level left whose saved state waits to be restored before the next block.
    pub(super) left_level: Option<usize>,
    /// Motion commands executed so far (to tell whether a block moved).
    motions: u64,
    /// Whether the dialect sets the feed before it moves (the fast lane takes F only then).
    /// Whether integers count least increments (`X10` is 10 µm): the dictionary's
    /// `decimal-input`, looked at by every plain move.
    integers_scale: bool,
    feed_before_motion: bool,
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
    /// Per axis, whether its position comes from a length word without a decimal point that
    /// least-increment input shrank (`X4` read as 0.004 mm) and that was said; as the block
    /// began, and after its words. An arc that fails from it is that finding's consequence.
    misread: [bool; 6],
    misread_before: [bool; 6],
    /// Whether one of this block's own words (an R, I, J or K) was shrunk so.
    block_misread: bool,
    /// The word that was, as the finding showed it (`` `X4` read as 0.004 mm ``).
    misread_word: Option<String>,
    /// Where ops come from while a subprogram from another file runs: the call block.
    origin_override: Option<(TextRange, u32)>,
    /// The block's named cycle (`CYCLE81(...)`) and its arguments, in order.
    block_cycle: Option<usize>,
    cycle_args: Vec<(Role, f64)>,
    /// The surface a cycle call at a position gives the cycle (`CYCL CALL POS ... Z+0`).
    call_surface: Option<f64>,
    /// Tool names met in `T="NAME"` that the tool table does not know, numbered from 10001.
    tool_names: Vec<String>,
    /// Why the file reads as a called program, once something shows it (see [`ProgramRole`]).
    called: Option<String>,
    /// Findings that follow from state a caller would set, as they stand if the file turns
    /// out to be a main program; meanwhile they are notes (`interp::caller-state`).
    provisional: Vec<Diagnostic>,
}

const NOTE_LIMIT: u32 = 3;

impl<'a> Interpreter<'a> {
    /// A fresh interpreter in the control's power-on state.
    pub fn new(dialect: &'a Dialect, profile: &'a Profile) -> Interpreter<'a> {
        Interpreter {
            dialect,
            profile,
            st: State {
                units: Units::Mm,
                plane: dialect.behaviour.initial_plane,
                distance: DistanceMode::Absolute,
                arc_incremental: true,
                feed: 0.0,
                speed: 0.0,
                spindle: Spindle::Stopped,
                mist: false,
                flood: false,
                selected_tool: 0,
                tool: 0,
                motion_code: None,
                retract: if dialect.behaviour.initial_retract_r { Retract::RPlane } else { Retract::Initial },
                wcs: 1,
                wcs_offsets: [[0.0; 6]; 9],
                wcs_extended: std::collections::BTreeMap::new(),
                wcs_rotation: [0.0; 9],
                modal_macro: None,
                home1: profile.home1,
                home2: profile.home2,
                g92: [0.0; 6],
                g92_saved: [0.0; 6],
                tool_offset: [0.0; 3],
                pos: [0.0; 6],
                sticky_r: None,
                sticky_z: None,
                turn_cycle: None,
                nurbs: None,
                rough_cut: None,
                sticky_q: None,
                sticky_p: None,
                ended: false,
                tech_warned: false,
                inverse_time: false,
                feed_per_rev: dialect.behaviour.initial_feed_per_rev,
                motion_continued: false,
                rotation: None,
                scaling: None,
                pole: (0.0, 0.0),
                arc_cw: true,
                defined_cycle: None,
                cycle_modal: false,
                tangent: None,
                comp_left: true,
                blank_min: None,
                leaving_comp: false,
                diameter: dialect.behaviour.x_diameter,
                css_max: None,
                spindle_limit: None,
                cycle_initial: None,
                machine_data_read: false,
                length_points: false,
                feed_unknown: profile.role != ProgramRole::Main,
                spindle_unknown: profile.role != ProgramRole::Main,
                overrides: (true, true),
            },
            params: {
                let mut p = Params::new(dialect.macros.null_value);
                p.magnitude_rounding = dialect.behaviour.magnitude_rounding;
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
            },
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
            request: None,
            depth: 0,
            contexts: Vec::new(),
            left_level: None,
            motions: 0,
            pending: Vec::new(),
            integers_scale: matches!(dialect.behaviour.decimal_input, DecimalInput::LeastIncrement { .. }),
            feed_before_motion: {
                let at = |step: Step| dialect.execution_order.iter().position(|&s| s == step);
                matches!((at(Step::Feed), at(Step::Motion)), (Some(f), Some(m)) if f < m)
            },
            stop_message: None,
            tool_edits: BTreeMap::new(),
            comp: std::cell::RefCell::new(None),
            corners: std::cell::RefCell::new(
                dialect
                    .codes
                    .iter()
                    .any(|c| {
                        matches!(
                            c.meaning,
                            Meaning::CornerRound | Meaning::CornerChamfer | Meaning::ApproachTangent | Meaning::ApproachNormal
                        )
                    })
                    .then_some(())
                    .or_else(|| dialect.addresses.iter().any(|a| matches!(a.role, Role::CornerRadius | Role::CornerChamfer)).then_some(()))
                    .map(|()| corner::Corners::default()),
            ),
            comp_problem: std::cell::Cell::new(None),
            sent: std::cell::Cell::new([0.0; 6]),
            misread: [false; 6],
            misread_before: [false; 6],
            block_misread: false,
            misread_word: None,
            origin_override: None,
            block_cycle: None,
            cycle_args: Vec::new(),
            call_surface: None,
            tool_names: Vec::new(),
            called: (profile.role == ProgramRole::Called)
                .then(|| "its role is given: the configuration, `--as` or its file name".to_owned()),
            provisional: Vec::new(),
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

    fn emit(&self, sink: &mut dyn CanonSink, op: CanonOp) {
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
        let op = if self.st.rotation.is_some() || self.st.scaling.is_some() { self.transform(op) } else { op };
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
            || self.comp.borrow().is_some()
            || self.corners.borrow().is_some()
    }

    /// A straight move to `to`, as [`Interpreter::emit`] sends it: where no stage stands
    /// between (`staged`, as [`Interpreter::staged`] says), straight to the sink without
    /// moving the op through the general way.
    #[inline(always)]
    fn emit_straight(&self, sink: &mut dyn CanonSink, rapid: bool, to: [f64; 6], staged: bool) {
        let op = |to| if rapid { CanonOp::StraightTraverse(to) } else { CanonOp::StraightFeed(to) };
        if staged {
            return self.emit(sink, op(to));
        }
        self.sent.set(to);
        sink.emit(Canon { op: op(to), origin: self.origin, line: self.line });
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

    /// A point through programmable scaling (G51), then rotation (G68), as the control moves.
    fn xform(&self, p: [f64; 3]) -> [f64; 3] {
        let mut q = p;
        if let Some((c, k)) = self.st.scaling {
            for i in 0..3 {
                q[i] = c[i] + (q[i] - c[i]) * k[i];
            }
        }
        if let Some((cx, cy, cos, sin)) = self.st.rotation {
            let (dx, dy) = (q[0] - cx, q[1] - cy);
            q[0] = cx + dx * cos - dy * sin;
            q[1] = cy + dx * sin + dy * cos;
        }
        q
    }

    fn transform(&self, op: CanonOp) -> CanonOp {
        let at = |p: [f64; 6]| {
            let q = self.xform([p[0], p[1], p[2]]);
            [q[0], q[1], q[2], p[3], p[4], p[5]]
        };
        match op {
            CanonOp::StraightTraverse(p) => CanonOp::StraightTraverse(at(p)),
            CanonOp::StraightFeed(p) => CanonOp::StraightFeed(at(p)),
            CanonOp::NurbsFeed { points, end } => CanonOp::NurbsFeed { points, end: at(end) },
            CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, abc } => {
                let (a0, a1, n) = self.st.plane.axes();
                let mut end = [0.0; 3];
                let mut centre = [0.0; 3];
                (end[a0], end[a1], end[n]) = (first_end, second_end, axis_end);
                (centre[a0], centre[a1], centre[n]) = (first_axis, second_axis, axis_end);
                let (end, centre) = (self.xform(end), self.xform(centre));
                CanonOp::ArcFeed {
                    first_end: end[a0],
                    second_end: end[a1],
                    first_axis: centre[a0],
                    second_axis: centre[a1],
                    rotation,
                    axis_end: end[n],
                    abc,
                }
            }
            CanonOp::CycleBegin(mut c) => {
                let q = self.xform([c.x, c.y, c.bottom]);
                (c.x, c.y) = (q[0], q[1]);
                CanonOp::CycleBegin(c)
            }
            CanonOp::RigidTap(p) => CanonOp::RigidTap(self.xform(p)),
            op => op,
        }
    }

    /// The finding for an expression without a value. After a read of data only the machine
    /// has, an arithmetic fault may come from that data: it is a warning that says so.
    pub(super) fn eval_diag(&self, e: EvalError, range: TextRange) -> Diagnostic {
        match e {
            EvalError::Undefined(name) => {
                Diagnostic::new(Code::UndefinedParameter, range, format!("parameter `#<{name}>` is used before it is set"))
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

    /// Limits the spindle speed under constant surface speed (`G50 S`, `LIMS=`), at once when
    /// it is on.
    fn set_spindle_limit(&mut self, max: f64, sink: &mut dyn CanonSink) {
        self.st.spindle_limit = Some(max);
        if self.st.css_max.is_some_and(|m| m != max) {
            self.st.css_max = Some(max);
            self.emit(sink, CanonOp::SetSpindleMode(Some(max)));
        }
    }

    /// The reading of [`RoundState`] now.
    pub(super) fn round_state(&self) -> RoundState {
        RoundState { params: self.params.clone(), depth: self.depth, st: self.st.clone(), contexts: self.contexts.clone() }
    }

    /// Sets the system variables that read the interpreter's state (the position, the tool,
    /// the modes) to what they read now, and the named ones too when `named` (a block or a
    /// condition that reads a named parameter).
    pub(super) fn refresh_system_vars(&mut self, named: bool) {
        for &(n, var) in &self.dialect.macros.system {
            if let Some(v) = self.system_value(var, 0.0) {
                let _ = self.params.set(f64::from(n), v);
            }
        }
        if named {
            for (name, var, constant) in &self.dialect.macros.system_named {
                if let Some(v) = self.system_value(*var, *constant) {
                    self.params.set_named(name, v);
                }
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

    /// Reports a finding, at most [`NOTE_LIMIT`] times per kind, and counts the rest. A
    /// listed finding met again (a loop's next pass) is neither listed nor counted; only the
    /// listed ones are remembered, so memory stays bounded on any program.
    fn limited(&mut self, diags: &mut Vec<Diagnostic>, key: &str, d: Diagnostic) {
        let listed = (d.range.start, d.range.end, d.message);
        if self.noted.contains(&listed) {
            return;
        }
        let n = match self.notes.get_mut(key) {
            Some(n) => n,
            None => self.notes.entry(key.to_owned()).or_insert(0),
        };
        *n += 1;
        if *n <= NOTE_LIMIT {
            let d = Diagnostic { message: listed.2.clone(), ..d };
            self.noted.insert(listed);
            diags.push(d);
        }
    }

    fn slot(&self, role: Role) -> Option<f64> {
        self.slots[role as usize].map(|s| s.value)
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
    #[inline]
    fn corner_report(&mut self, diags: &mut Vec<Diagnostic>) {
        if self.corners.get_mut().is_none() {
            return;
        }
        let problem = self.corners.get_mut().as_mut().and_then(|k| k.problem.take());
        if let Some(p) = problem {
            let mut d = Diagnostic::new(Code::BadArc, self.origin, format!("the corner is left sharp: {}", p.describe()));
            if self.unknown_words > 0 {
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

    fn execute_block(&mut self, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.origin = block.range;
        self.line = block.line;
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
        if self.profile.fast_lane && self.fast_move(block, sink, diags) {
            return;
        }
        let system_vars = !self.dialect.macros.system.is_empty() || !self.dialect.macros.system_named.is_empty();
        if system_vars && !block.exprs.is_empty() {
            let named = !self.dialect.macros.system_named.is_empty()
                && block.exprs.iter().any(|e| matches!(e, crate::syntax::Expr::Named(_) | crate::syntax::Expr::NamedIndex(..)));
            self.refresh_system_vars(named);
        }
        let early = self.dialect.behaviour.assign_before_reads;
        if early {
            self.assign(block, diags);
        }
        if !self.read(block, diags) {
            return;
        }
        if !early {
            self.assign(block, diags);
        }
        if let Some(s) = self.slots[Role::AlarmNumber as usize] {
            self.alarm(block, 0.0, s.value, s.range, diags);
        }
        if self.st.ended {
            return;
        }
        if self.filled & (1 << Role::ToolAxisI as u32 | 1 << Role::ToolAxisJ as u32 | 1 << Role::ToolAxisK as u32) != 0 {
            self.tool_axis(sink);
        }
        if let Some(k) = self.codes.iter().position(|&(c, _)| self.code(c).meaning == Meaning::MacroCall) {
            self.macro_call(block, self.codes[k].1, diags);
            return;
        }
        if let Some(&(c, range)) =
            self.codes.iter().find(|&&(c, _)| matches!(self.code(c).meaning, Meaning::ModalMacroCall | Meaning::ModalMacroCancel))
        {
            // G66 registers the call (its words are arguments, nothing moves); G67 drops it.
            self.st.modal_macro = None;
            if self.code(c).meaning == Meaning::ModalMacroCall
                && let Some(program) = self.program_number(Role::P, range, diags)
            {
                let repeats = self.repeat_count(diags, range);
                let args = self.macro_args(block, diags);
                self.st.modal_macro = Some(ModalMacro { program, repeats, args, depth: self.depth });
            }
            return;
        }
        let motions = self.motions;
        let plain = self.block_cycle.is_none()
            && self.code_steps == 0
            && block.comments.is_empty()
            && self.stop_message.is_none()
            && self.filled
                & (1 << Role::F as u32
                    | 1 << Role::S as u32
                    | 1 << Role::T as u32
                    | 1 << Role::SpindleLimit as u32
                    | 1 << Role::CornerRadius as u32
                    | 1 << Role::CornerChamfer as u32)
                == 0;
        if plain {
            // The common block: axis words only, so only the motion step has work.
            self.step(Step::Motion, block, sink, diags);
            self.modal_macro_after(motions);
            if self.st.cycle_modal {
                self.cycles_after(motions, block.range, sink, diags);
            }
            return;
        }
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
                return;
            }
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

    /// A corner the block's own words round or chamfer (Siemens `X65 RND=5`): marked after the
    /// block's move, between it and the next, as a corner block between them would be.
    fn corner_words(&mut self, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let (size, corner) = match (self.slot(Role::CornerRadius), self.slot(Role::CornerChamfer)) {
            (Some(r), _) => (r, corner::Corner::Round(r)),
            (None, Some(c)) => (c, corner::Corner::Chamfer(c)),
            (None, None) => return,
        };
        if size > 0.0 {
            self.mark_corner(corner);
        } else {
            diags.push(Diagnostic::new(Code::MissingParameter, range, "a corner rounding or chamfer needs a size above zero"));
        }
    }

    /// Marks the corner between the move the corner stage holds and the next.
    fn mark_corner(&mut self, corner: corner::Corner) {
        if let Some(k) = self.corners.get_mut().as_mut() {
            k.mark(corner, self.origin, self.line);
        }
    }

    /// After a block that moved, the registered G66 macro is called (not from inside it).
    fn modal_macro_after(&mut self, motions: u64) {
        if let Some(m) = &self.st.modal_macro
            && self.motions != motions
            && self.request.is_none()
            && m.depth == self.depth
        {
            self.request =
                Some(Request::Call { program: m.program, repeats: m.repeats, macro_call: true, args: m.args.clone(), start: None });
        }
    }

    /// Before the first block: a control that starts in another plane than XY (a lathe in
    /// ZX), or with feed per revolution, says so, as its program would, so that the canon is
    /// read in the right plane and feed mode.
    fn start(&mut self, sink: &mut dyn CanonSink) {
        if self.st.plane != Plane::Xy {
            self.emit(sink, CanonOp::SelectPlane(self.st.plane));
        }
        if self.st.feed_per_rev {
            self.emit(sink, CanonOp::SetFeedMode(FeedMode::PerRevolution));
        }
    }

    /// Forgets the previous block's words and codes.
    fn clear_block(&mut self) {
        let mut filled = std::mem::take(&mut self.filled);
        while filled != 0 {
            self.slots[filled.trailing_zeros() as usize] = None;
            filled &= filled - 1;
        }
        self.code_steps = 0;
        self.unknown_roles = 0;
        self.codes.clear();
        self.block_cycle = None;
        self.cycle_args.clear();
    }

    /// Read phase: values, codes, groups and parameter checks. False when the block must be skipped.
    fn read(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        self.clear_block();
        self.block_read = true;
        self.misread_before = self.misread;
        self.block_misread = false;
        let mut ok = true;
        // Codes first: a unit change in this block affects how its numbers scale.
        for w in &block.words {
            if !matches!(w.role, Role::G | Role::M | Role::Keyword | Role::Cycle) {
                continue;
            }
            if w.role == Role::Cycle {
                if let Value::Number { value, .. } = w.value {
                    self.block_cycle = Some(value as usize);
                }
                continue;
            }
            if w.role == Role::Keyword {
                let Value::Number { value, .. } = w.value else { continue };
                ok &= self.push_code(value as usize, w.range, diags);
                continue;
            }
            if !matches!(w.role, Role::G | Role::M) {
                continue;
            }
            let Some(v) = self.value(block, w.value, w.range, diags) else {
                ok = false;
                continue;
            };
            if eval::is_unknown(v) {
                self.unknown_word(block, w.range, diags);
                continue;
            }
            if eval::is_null(v) {
                continue; // a word whose value is vacant is omitted
            }
            let x10 = (v * 10.0).round();
            let letter = w.letter as char;
            let found = if (v * 10.0 - x10).abs() < 1e-3 && (0.0..10_000.0).contains(&x10) {
                self.dialect.code_id(letter, x10 as u32)
            } else {
                None
            };
            let Some(idx) = found else {
                let shown = block.text(w.range);
                if letter == 'M' && self.dialect.behaviour.machine_m_codes && (0.0..10_000.0).contains(&x10) {
                    let d = Diagnostic::new(
                        Code::MachineCode,
                        w.range,
                        format!("`{shown}` is a machine-builder M code; recorded, with no effect on the toolpath"),
                    );
                    self.limited(diags, "machine-m-code", d);
                    continue;
                }
                diags.push(Diagnostic::new(
                    Code::UnknownCode,
                    w.range,
                    format!("`{shown}` is not a code of the {} dialect", self.dialect.name),
                ));
                ok = false;
                continue;
            };
            ok &= self.push_code(idx, w.range, diags);
        }
        let units = self.codes.iter().rev().find_map(|(c, _)| match self.code(*c).meaning {
            Meaning::UnitsInch => Some(Units::Inch),
            Meaning::UnitsMm => Some(Units::Mm),
            _ => None,
        });
        let units = units.unwrap_or(self.st.units);
        // G7 in this block already reads its X words as diameters.
        let diameter = self.codes.iter().rev().find_map(|(c, _)| match self.code(*c).meaning {
            Meaning::DiameterMode => Some(true),
            Meaning::RadiusMode => Some(false),
            _ => None,
        });
        let diameter = diameter.unwrap_or(self.st.diameter);
        // In a drilling cycle's block (its own or the one in force) K counts repeats: no length.
        let is_hole_cycle = |m: Meaning| {
            matches!(
                m,
                Meaning::CycleDrill
                    | Meaning::CycleDrillDwell
                    | Meaning::CyclePeckDrill
                    | Meaning::CycleChipBreak
                    | Meaning::CycleBore
                    | Meaning::CycleBoreDwell
                    | Meaning::CycleBoreStop
                    | Meaning::CycleTap
                    | Meaning::CycleTapLeft
                    | Meaning::CycleFineBore
                    | Meaning::CycleBackBore
                    | Meaning::CycleBoreManual
            )
        };
        let k_counts = self.codes.iter().any(|&(c, _)| is_hole_cycle(self.code(c).meaning))
            || self.st.motion_code.is_some_and(|c| is_hole_cycle(self.code(c).meaning));
        for (k, w) in block.words.iter().enumerate() {
            if matches!(w.role, Role::G | Role::M | Role::Keyword | Role::Cycle) {
                continue;
            }
            let mut w = *w;
            if let Some(&(_, index)) = block.axis_refs.iter().find(|&&(i, _)| i == k) {
                match self.axis_by_variable(block, index, w.range, diags) {
                    Some(letter) => {
                        w.letter = letter;
                        w.role = self.dialect.letter_role(letter).unwrap_or(Role::Extra);
                    }
                    None => continue,
                }
            }
            let w = &w;
            if w.cycle_arg {
                match self.value(block, w.value, w.range, diags) {
                    Some(v) if eval::is_unknown(v) => self.unknown_word(block, w.range, diags),
                    Some(v) if !eval::is_null(v) => self.cycle_args.push((w.role, v)),
                    Some(_) => {}
                    None => ok = false,
                }
                continue;
            }
            let mut role = w.role;
            if self.slots[role as usize].is_some() {
                // An address that may appear twice gives its second occurrence another role.
                let again = self.dialect.addresses.iter().find(|a| a.role == role).and_then(|a| a.again);
                if let Some(r) = again.filter(|r| self.slots[*r as usize].is_none()) {
                    role = r;
                }
            }
            if self.slots[role as usize].is_some() {
                let shown = block.text(w.range);
                diags.push(Diagnostic::new(
                    Code::DuplicateWord,
                    w.range,
                    format!("`{shown}`: the address {} appears twice in this block", w.letter as char),
                ));
                ok = false;
                continue;
            }
            let mut v = match w.value {
                Value::Number { value, .. } => value,
                Value::Text(r) => match self.text_value(block, role, r, w.range, diags) {
                    Some(v) => v,
                    None => {
                        ok = false;
                        continue;
                    }
                },
                Value::Expr(_) => match self.value(block, w.value, w.range, diags) {
                    Some(v) if eval::is_unknown(v) => {
                        if role == Role::F {
                            // Not zero: the feed the control has, which this file does not know.
                            self.st.feed_unknown = true;
                            self.st.feed = self.st.feed.max(0.0);
                        }
                        self.unknown_roles |= 1 << role as u32;
                        self.unknown_word(block, w.range, diags);
                        continue;
                    }
                    Some(v) if eval::is_null(v) => continue,
                    Some(v) => v,
                    None => {
                        ok = false;
                        continue;
                    }
                },
            };
            if let (Value::Number { decimal, .. }, DecimalInput::LeastIncrement { mm, inch, scaled }) =
                (w.value, &self.dialect.behaviour.decimal_input)
                && scaled.contains(&role)
                && !(k_counts && role == Role::K)
            {
                let axis = Role::AXES.iter().position(|&a| a == role);
                let absolute = match w.mode {
                    WordMode::Modal => self.st.distance == DistanceMode::Absolute,
                    WordMode::Absolute => true,
                    WordMode::Incremental => false,
                };
                if decimal {
                    self.st.length_points = true;
                    if let Some(i) = axis.filter(|_| absolute) {
                        self.misread[i] = false;
                    }
                } else {
                    if v != 0.0 && self.st.length_points {
                        let shown = block.text(w.range);
                        let unit = if units == Units::Mm { "mm" } else { "inch" };
                        let scaled_to = (v * if units == Units::Mm { *mm } else { *inch } * 1e9).round() / 1e9;
                        let msg = format!(
                            "`{shown}` has no decimal point: least-increment input reads it as {scaled_to} {unit}, while this program writes its other lengths with points; if {v} {unit} was meant, write `{shown}.` (or, if the machine reads whole numbers as units, set its decimal_input to calculator in the config)"
                        );
                        let mut d = Diagnostic::new(Code::NoDecimalPoint, w.range, msg);
                        // The first such word is the finding; the others repeat it.
                        if self.misread_word.is_some() {
                            d.severity = Severity::Note;
                        }
                        self.limited(diags, "no-decimal-point", d);
                        match axis {
                            Some(i) => self.misread[i] = true,
                            None => self.block_misread = true,
                        }
                        self.misread_word = Some(format!("`{shown}` read as {scaled_to} {unit}"));
                    } else if let Some(i) = axis.filter(|_| absolute) {
                        self.misread[i] = false;
                    }
                    v *= if units == Units::Mm { *mm } else { *inch };
                }
            }
            if diameter && role == Role::X {
                v /= 2.0;
            }
            self.slots[role as usize] = Some(Slot { value: v, range: w.range, mode: w.mode });
            self.filled |= 1 << role as u32;
        }
        // A motion code may give a word the role of a polar coordinate (Heidenhain ISO's
        // `G11 R+20 H+30`: R is the polar radius there, an arc's radius elsewhere).
        if let Some(c) = self.active_motion_code() {
            let def = self.code(c);
            for &(from, to) in &def.args {
                if matches!(to, Role::PolarRadius | Role::PolarAngle) && self.slots[to as usize].is_none() {
                    if let Some(s) = self.slots[from as usize].take() {
                        self.slots[to as usize] = Some(s);
                        self.filled |= 1 << to as u32;
                    }
                }
            }
        }
        // Where I J K are the circle centre and the pole (Heidenhain ISO), a block that
        // writes them sets the pole, with or without an arc.
        if self.dialect.behaviour.arc_centres_pole {
            let (a0, a1, _) = self.st.plane.axes();
            if let Some(c) = self.centre_words(a0, a1, self.st.pos) {
                self.st.pole = c;
            }
        }
        // Polar words (`PA+90`) name an end point as axis words do.
        const POSITION: u128 = {
            let mut m = 1 << Role::PolarRadius as u32 | 1 << Role::PolarAngle as u32;
            let mut k = 0;
            while k < Role::AXES.len() {
                m |= 1 << Role::AXES[k] as u32;
                k += 1;
            }
            m
        };
        self.has_axes = self.filled & POSITION != 0;
        if ok {
            ok = self.check_params(block, diags);
        }
        ok
    }

    /// Adds code `idx` to the block's codes; false (with a diagnostic) when its group already has one.
    fn push_code(&mut self, idx: usize, range: TextRange, diags: &mut Vec<Diagnostic>) -> bool {
        let def = self.code(idx);
        if let Some(k) = self.codes.iter().position(|(c, _)| self.code(*c).group == def.group) {
            let other = self.codes[k].0;
            if def.gives_way {
                return true;
            }
            if self.code(other).gives_way {
                self.codes[k] = (idx, range);
                return true;
            }
            diags.push(Diagnostic::new(
                Code::ModalGroupConflict,
                range,
                format!(
                    "{} and {} are both in modal group `{}`; a block may hold only one",
                    self.code(other).label(),
                    def.label(),
                    self.dialect.groups[def.group].id
                ),
            ));
            return false;
        }
        self.codes.push((idx, range));
        self.code_steps |= 1 << self.dialect.groups[def.group].step as u32;
        true
    }

    /// A quoted value: a tool name (`T="DRILL_8"`) becomes the number the tool table gives
    /// it, or a number from 10001 on in the order names first appear.
    fn text_value(&mut self, block: &Block, role: Role, r: TextRange, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<f64> {
        let name = block.text(r);
        if role == Role::Extra {
            return Some(0.0); // a name the engine only records (`LBL "NAME"`)
        }
        if role != Role::T {
            diags.push(Diagnostic::new(Code::MalformedNumber, range, format!("\"{name}\" is text; this address takes a number")));
            return None;
        }
        if let Some((&n, _)) = self.profile.tools.iter().find(|(_, t)| t.name.as_deref().is_some_and(|t| t.eq_ignore_ascii_case(name))) {
            return Some(f64::from(n));
        }
        let k = match self.tool_names.iter().position(|t| t.eq_ignore_ascii_case(name)) {
            Some(k) => k,
            None => {
                self.tool_names.push(name.to_owned());
                self.tool_names.len() - 1
            }
        };
        Some(10_001.0 + k as f64)
    }

    fn value(&mut self, block: &Block, v: Value, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<f64> {
        match v {
            Value::Number { value, .. } => Some(value),
            Value::Text(_) => {
                diags.push(Diagnostic::new(Code::MalformedNumber, range, "text where a number is needed"));
                None
            }
            Value::Expr(e) => match self.eval(block, e, range, diags) {
                Ok(x) if x.is_finite() || (eval::is_null(x) && self.dialect.macros.null_value) || eval::is_unknown(x) => Some(x),
                Ok(_) => {
                    diags.push(Diagnostic::new(Code::ArithmeticError, range, "the expression has no finite value"));
                    None
                }
                Err(err) => {
                    diags.push(self.eval_diag(err, range));
                    None
                }
            },
        }
    }

    fn check_params(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> bool {
        let mut ok = true;
        // A word whose value is unknown is there on the machine: it meets the requirement.
        let present = |s: &Self, r: Role| s.slots[r as usize].is_some() || s.unknown_roles & (1 << r as u32) != 0;
        let has_axes = self.has_axes;
        for &(c, range) in &self.codes {
            let def = self.code(c);
            let is_motion = self.dialect.groups[def.group].step == Step::Motion;
            for &r in &def.params.required {
                if !present(self, r) {
                    diags.push(Diagnostic::new(Code::MissingParameter, range, format!("{} needs {}", def.label(), self.address_name(r))));
                    ok = false;
                }
            }
            for set in &def.params.any_of {
                if !set.iter().any(|&r| present(self, r)) && (!is_motion || has_axes) {
                    let names: Vec<_> = set.iter().map(|&r| self.address_name(r)).collect();
                    diags.push(Diagnostic::new(
                        Code::MissingParameter,
                        range,
                        format!("{} needs one of {}", def.label(), names.join(", ")),
                    ));
                    ok = false;
                }
            }
            for (a, b) in &def.params.exclusive {
                if a.iter().any(|&r| present(self, r)) && b.iter().any(|&r| present(self, r)) {
                    let an: Vec<_> = a.iter().map(|&r| self.address_name(r)).collect();
                    let bn: Vec<_> = b.iter().map(|&r| self.address_name(r)).collect();
                    diags.push(Diagnostic::new(
                        Code::MissingParameter,
                        range,
                        format!("{} mixes {} with {}", def.label(), an.join(" "), bn.join(" ")),
                    ));
                    ok = false;
                }
            }
        }
        // Words that no command in this block takes.
        let mut motion = None;
        for w in &block.words {
            if !matches!(w.role, Role::P | Role::Q | Role::L | Role::R | Role::I | Role::J | Role::K | Role::H | Role::D | Role::E) {
                continue;
            }
            // The centre words set the pole in any block.
            if self.dialect.behaviour.arc_centres_pole && matches!(w.role, Role::I | Role::J | Role::K) {
                continue;
            }
            let motion = *motion.get_or_insert_with(|| self.active_motion_code());
            // A keyword code takes the value it is written with (`SPOS=90`).
            let takes = |c: &CodeDef, r: Role| c.params.takes(r) || c.keyword.as_ref().is_some_and(|k| k.value_role == Some(r));
            let taken = self.codes.iter().any(|&(c, _)| takes(self.code(c), w.role)) || motion.is_some_and(|c| takes(self.code(c), w.role));
            if !taken {
                let shown = block.text(w.range);
                let d =
                    Diagnostic::new(Code::UnusedWord, w.range, format!("`{shown}`: no command in this block takes {}", w.letter as char));
                diags.push(self.unused(d));
            }
        }
        ok
    }

    fn address_name(&self, role: Role) -> String {
        self.dialect.addresses.iter().find(|a| a.role == role).map_or_else(|| role.as_str().to_owned(), |a| a.name.clone())
    }

    /// The motion code this block executes: explicit, or the modal one when axes are given
    /// and no other code claims them: one whose meaning uses axis words, or whose parameters
    /// list an axis word the block has (`G4 X1.5`, `G51 A45 E0.002`).
    fn active_motion_code(&self) -> Option<usize> {
        if let Some(&(c, _)) = self.codes.iter().find(|(c, _)| self.dialect.groups[self.code(*c).group].step == Step::Motion) {
            return Some(c);
        }
        let claimed = self.codes.iter().any(|&(c, _)| {
            matches!(
                self.code(c).meaning,
                Meaning::SetData
                    | Meaning::ModalMacroCall
                    | Meaning::LengthCompDynamic
                    | Meaning::Home1
                    | Meaning::Home2
                    | Meaning::OriginShift
                    | Meaning::LocalOffset
                    | Meaning::Scaling
                    | Meaning::Rotation
                    | Meaning::Pole
                    | Meaning::PoleKeeping
                    | Meaning::CycleDefine
                    | Meaning::FrameTrans
                    | Meaning::FrameTransAdd
                    | Meaning::FrameRot
                    | Meaning::FrameRotAdd
                    | Meaning::FrameScale
                    | Meaning::FrameScaleAdd
                    | Meaning::FrameMirror
                    | Meaning::Stock
                    | Meaning::CycleIntent
            ) || (self.dialect.groups[self.code(c).group].step != Step::Motion && self.claims_axes(c))
        });
        if self.has_axes && !claimed { self.st.motion_code } else { None }
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
                    _ => format!("{sigil}{n}, which is set outside this file (retained, or machine data)"),
                }
            }
            Some(eval::UnknownSource::Named(name)) => format!("`{name}`, which the caller or the control's global data sets"),
            None => "a value set outside this file".to_owned(),
        }
    }

    /// A word whose value is unknown: omitted, as a vacant one is, so that a move keeps its
    /// known axes; said once per block.
    fn unknown_word(&mut self, block: &Block, range: TextRange, diags: &mut Vec<Diagnostic>) {
        self.unknown_words += 1;
        let shown = block.text(range).to_owned();
        let what = self.unknown_what();
        let msg = format!("`{shown}` reads {what}; the word is left out and the block keeps its known words");
        let mut d = Diagnostic::new(Code::UnknownValue, range, msg);
        if !self.is_called() {
            d.severity = Severity::Warning;
        }
        self.limited(diags, "unknown-value", d);
    }

    /// The axis an axis variable names (`AX[_X]=10` after `DEF AXIS _X=X`); none, with a
    /// note, when its value comes from outside the file (a `PROC`'s `AXIS` argument) or is
    /// no axis.
    fn axis_by_variable(
        &mut self,
        block: &Block,
        index: crate::syntax::ExprId,
        range: TextRange,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<u8> {
        // An undeclared name is said once, by the note below.
        let mut read = Vec::new();
        let v = match self.eval(block, index, range, &mut read) {
            Ok(v) => v,
            Err(e) => {
                diags.append(&mut read);
                diags.push(self.eval_diag(e, range));
                return None;
            }
        };
        if !eval::is_unknown(v) {
            diags.append(&mut read);
        }
        if let Some(letter) = crate::syntax::axis_of(v).filter(|&c| self.dialect.letter_role(c).is_some_and(|r| r.is_axis())) {
            return Some(letter);
        }
        let shown = block.text(range).trim();
        // The name with its index (`AX[_X]`), without the value.
        let shown = shown.find(']').map_or(shown, |i| &shown[..=i]).to_owned();
        if eval::is_unknown(v) {
            let what = self.unknown_what();
            let msg = format!("`{shown}` names its axis by {what}: the move along it is left out");
            self.limited(diags, "unknown-value", Diagnostic::new(Code::UnknownValue, range, msg));
        } else {
            let msg = format!("`{shown}`: the variable holds no axis here; the word is left out");
            let mut d = Diagnostic::new(Code::BadValue, range, msg);
            d.severity = Severity::Warning;
            self.limited(diags, "axis-variable", d);
        }
        None
    }

    /// Whether code `c` takes one of the axis words the block has.
    fn claims_axes(&self, c: usize) -> bool {
        Role::AXES.iter().any(|&r| self.slots[r as usize].is_some() && self.code(c).params.takes(r))
    }

    fn assign(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) {
        // All reads of a block happen before its assignments take effect.
        let mut pending = std::mem::take(&mut self.pending);
        pending.clear();
        // Where each unknown value assigned came from, by the pending assignment.
        let mut origins = Vec::new();
        for a in &block.assigns {
            let value = match self.eval(block, a.value, a.range, diags) {
                Ok(v) => {
                    origins.resize(pending.len(), None);
                    origins.push(if eval::is_unknown(v) { self.params.unknown_read_peek() } else { None });
                    v
                }
                Err(e) => {
                    diags.push(self.eval_diag(e, a.range));
                    continue;
                }
            };
            match a.target {
                ParamTarget::Numbered(e) => match self.eval(block, e, a.range, diags) {
                    Ok(n) => {
                        pending.push(PendingAssign { number: Some(n), name: TextRange::default(), index: None, value, range: a.range })
                    }
                    Err(e) => diags.push(self.eval_diag(e, a.range)),
                },
                ParamTarget::Named(name) => pending.push(PendingAssign { number: None, name, index: None, value, range: a.range }),
                ParamTarget::NamedIndex(name, e) => match self.eval(block, e, a.range, diags) {
                    Ok(i) => pending.push(PendingAssign { number: None, name, index: Some(i), value, range: a.range }),
                    Err(e) => diags.push(self.eval_diag(e, a.range)),
                },
            }
        }
        for (k, &PendingAssign { number, name, index, value, range }) in pending.iter().enumerate() {
            let origin = origins.get(k).cloned().flatten();
            match number {
                Some(n) => {
                    let system = if n >= 0.0 && n.fract() == 0.0 { self.dialect.macros.system_var(n as u32) } else { None };
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
                            } else if n >= 0.0 && n.fract() == 0.0 {
                                self.params.derive(eval::UnknownSource::Numbered(n as u32), origin);
                            }
                        }
                    }
                }
                None => {
                    let name = eval::normalised(block.text(name));
                    match index {
                        // The key a read of `name[i]` looks up (`eval`).
                        Some(i) => self.params.set_named(&format!("{name}[{i}]"), value),
                        None => {
                            self.params.set_named(&name, value);
                            self.params.derive(eval::UnknownSource::Named(name.into_owned()), origin);
                        }
                    }
                }
            }
        }
        self.pending = pending;
    }

    /// What a log-file directive writes: the file's name as written, nothing for a close, or
    /// the line with each parameter (`#1`, `#<depth>`) replaced by its value with six
    /// decimals, as rs274 writes it (`######` for one it cannot read; a `#` ending the text
    /// goes).
    fn log_text(&self, kind: crate::dialect::LogFile, rest: &str) -> String {
        use crate::dialect::LogFile;
        match kind {
            LogFile::Close => return String::new(),
            LogFile::Open | LogFile::Append => return rest.trim().to_owned(),
            LogFile::Line => {}
        }
        let mut out = String::with_capacity(rest.len());
        let mut rest = rest;
        while let Some(at) = rest.find('#') {
            out.push_str(&rest[..at]);
            let after = &rest[at + 1..];
            let digits = after.bytes().take_while(u8::is_ascii_digit).count();
            let (value, used) = if digits > 0 {
                (after[..digits].parse::<f64>().ok().and_then(|n| self.params.get(n).ok()), digits)
            } else if let Some(raw) = after.strip_prefix('<').and_then(|a| a.find('>').map(|e| &a[..e])) {
                let name = eval::normalise_name(raw);
                // A system parameter reads the state now, as in an expression.
                let system = self.dialect.macros.system_named.iter().find(|(n, ..)| *n == name);
                let value = match system {
                    Some(&(_, var, constant)) => self.system_value(var, constant),
                    None => self.params.get_named(&name).ok(),
                };
                (value, raw.len() + 2)
            } else {
                (None, 0)
            };
            match value {
                Some(v) => out.push_str(&format!("{v:.6}")),
                None if used > 0 => out.push_str("######"),
                None if after.is_empty() => {}
                None => out.push('#'),
            }
            rest = &after[used..];
        }
        out.push_str(rest);
        out
    }

    /// The text of the block's first comment, or an empty string.
    fn block_comment(&self, block: &Block) -> String {
        block.comments.first().map(|r| block.text(*r).trim().to_owned()).unwrap_or_default()
    }

    /// `#3000 = n (MESSAGE)`: the control stops with an alarm.
    fn alarm(&mut self, block: &Block, var: f64, value: f64, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let msg = self.block_comment(block);
        let number = if eval::is_null(value) { var } else { var + value.trunc() };
        diags.push(Diagnostic::new(
            Code::ProgramAlarm,
            range,
            format!("the program raises alarm {number}{}{msg}; execution stops here", if msg.is_empty() { "" } else { ": " }),
        ));
        self.st.ended = true;
    }

    /// `G65 P9010 L2 A1 B2`: a macro call; the other words are arguments by letter.
    fn macro_call(&mut self, block: &Block, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let Some(program) = self.program_number(Role::P, range, diags) else { return };
        let repeats = self.repeat_count(diags, range);
        let args = self.macro_args(block, diags);
        self.request = Some(Request::Call { program, repeats, macro_call: true, args, start: None });
    }

    /// The argument words of a macro call (all but G, P and L) as (local, value).
    fn macro_args(&mut self, block: &Block, diags: &mut Vec<Diagnostic>) -> Vec<(u16, f64)> {
        let mut args = Vec::new();
        for w in &block.words {
            if matches!(w.role, Role::G | Role::P | Role::L) {
                continue;
            }
            let Some(local) = self.dialect.macros.arguments.get((w.letter.wrapping_sub(b'A')) as usize).copied().flatten() else {
                let shown = block.text(w.range);
                diags.push(Diagnostic::new(Code::UnusedWord, w.range, format!("`{shown}` is not a macro argument in this dialect")));
                continue;
            };
            // Arguments keep the value as written: the least-increment rule does not apply.
            if let Some(v) = self.value(block, w.value, w.range, diags) {
                args.push((local, v));
            }
        }
        args
    }

    /// A program number from the word `role`, checked.
    fn program_number(&mut self, role: Role, range: TextRange, diags: &mut Vec<Diagnostic>) -> Option<u32> {
        let slot = self.slots[role as usize]?;
        // The least-increment rule may have scaled P; program numbers are read as written.
        let v = slot.value;
        if v < 0.0 || v.fract() != 0.0 || v > 99_999_999.0 {
            diags.push(Diagnostic::new(Code::MalformedNumber, range, format!("program number {v} must be a whole number")));
            return None;
        }
        Some(v as u32)
    }

    /// The repeat count of a call: L, or 1.
    fn repeat_count(&mut self, diags: &mut Vec<Diagnostic>, range: TextRange) -> u32 {
        match self.slot(Role::L) {
            None => 1,
            Some(l) if l >= 0.0 && l.fract() == 0.0 && l < 1e6 => l as u32,
            Some(l) => {
                diags.push(Diagnostic::new(Code::MalformedNumber, range, format!("repeat count L{l} must be a whole number")));
                1
            }
        }
    }

    fn step(&mut self, step: Step, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        match step {
            Step::Comment => {
                for r in &block.comments {
                    let text = block.text(*r);
                    let op = match self.dialect.lexical.directive(text) {
                        Some((Directive::Message, m)) => CanonOp::Message(m.to_owned()),
                        Some((Directive::Abort, m)) => {
                            let msg = format!("the program aborts: {}; execution stops here", m.trim());
                            diags.push(Diagnostic::new(Code::ProgramAlarm, *r, msg));
                            self.st.ended = true;
                            return;
                        }
                        // `(LOGCLOSE)` only: with more after it, rs274 takes it for a comment.
                        Some((Directive::LogFile(crate::dialect::LogFile::Close), rest)) if !rest.trim().is_empty() => {
                            CanonOp::Comment(text.to_owned())
                        }
                        Some((Directive::LogFile(kind), rest)) => CanonOp::Log(kind, self.log_text(kind, rest)),
                        Some((Directive::Log | Directive::Simulator, _)) | None => CanonOp::Comment(text.to_owned()),
                    };
                    self.emit(sink, op);
                }
            }
            Step::Feed => {
                // A dwell that takes F (Siemens `G4 F2.5`) reads it as seconds, not as a feed.
                // So does a cycle definition (`CYCL DEF 1.5 F80`): the cycle's own feed.
                let dwell_f = self.codes.iter().any(|&(c, _)| {
                    let d = self.code(c);
                    (d.meaning == Meaning::Dwell && d.params.takes(Role::F)) || d.meaning == Meaning::CycleDefine
                });
                if let Some(f) = self.slot(Role::F).filter(|_| !dwell_f) {
                    if self.st.inverse_time {
                        // Each feed move of the block turns F into a rate (see `inverse_time_feed`).
                        return;
                    }
                    self.st.feed = f;
                    self.st.feed_unknown = false;
                    self.st.tech_warned = false;
                    self.emit(sink, CanonOp::SetFeedRate(f));
                }
            }
            Step::Speed => {
                // `LIMS=3000` (Siemens) sets the limit of constant surface speed, now or later.
                if let Some(max) = self.slot(Role::SpindleLimit) {
                    self.set_spindle_limit(max, sink);
                }
                // `G50 S3200` on a lathe limits the speed; it does not set it.
                let limit = self.codes.iter().any(|&(c, _)| self.code(c).meaning == Meaning::SpindleLimit);
                if let Some(s) = self.slot(Role::S).filter(|_| !limit) {
                    self.st.speed = s;
                    self.emit(sink, CanonOp::SetSpindleSpeed(s));
                }
            }
            Step::ToolSelect => {
                if let Some(t) = self.slot(Role::T) {
                    if t < 0.0 || t.fract() != 0.0 {
                        diags.push(Diagnostic::new(
                            Code::MalformedNumber,
                            self.slots[Role::T as usize].map_or(block.range, |s| s.range),
                            "a tool number must be a whole number of zero or more",
                        ));
                    } else {
                        self.tool_word(t, sink);
                    }
                }
            }
            Step::Misc => {}
            Step::Stop if self.stop_message.is_some() => {
                let msg = self.stop_message.take().unwrap_or_default();
                self.emit(sink, CanonOp::Message(msg));
                self.emit(sink, CanonOp::ProgramStop);
                self.run_codes(step, block, sink, diags);
            }
            _ => {
                let ran = self.run_codes(step, block, sink, diags);
                if step == Step::Motion && !ran {
                    if let Some(c) = self.active_motion_code() {
                        self.execute_code(c, block.range, block, sink, diags);
                    } else if self.has_axes && !self.codes.iter().any(|&(c, _)| self.claims_axes(c)) {
                        let d = Diagnostic::new(
                            Code::UnusedWord,
                            block.range,
                            "axis words without an active motion mode (after G80 or at program start)",
                        );
                        diags.push(self.unused(d));
                    }
                }
            }
        }
    }

    /// Executes the block's codes that take effect at `step`; true if there were any.
    fn run_codes(&mut self, step: Step, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) -> bool {
        // Index loop: `execute_code` needs `&mut self`, and the hot path must not allocate.
        let mut ran = false;
        for k in 0..self.codes.len() {
            let (c, range) = self.codes[k];
            if self.dialect.groups[self.code(c).group].step == step {
                ran = true;
                self.execute_code(c, range, block, sink, diags);
            }
        }
        ran
    }

    fn unsupported(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let key: &'static str = def.meaning.as_str();
        self.limited(
            diags,
            key,
            Diagnostic::new(Code::Unsupported, range, format!("{} ({}) is not supported yet; it was skipped", def.label(), def.name)),
        );
    }

    /// M19: the spindle stops at an angle (R, degrees) turning the way P says (0 shorter,
    /// 1 clockwise, 2 counterclockwise); Q waits that many seconds for it. A code that takes
    /// no R orients to the angle the machine is set up with, given as 0.
    fn orient_spindle(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.st.spindle = Spindle::Stopped;
        let (angle, mode) = (self.slot(Role::R), self.slot(Role::P));
        if angle.is_some() || mode.is_some() || !def.params.takes(Role::R) {
            let mode = match mode {
                None => 0,
                Some(p) if [0.0, 1.0, 2.0].contains(&p) => p as u8,
                Some(p) => {
                    let d = Diagnostic::new(Code::BadValue, range, format!("{}: P{p} is no direction; P takes 0, 1 or 2", def.label()));
                    diags.push(d);
                    return;
                }
            };
            self.emit(sink, CanonOp::OrientSpindle { angle: angle.unwrap_or(0.0), mode });
        }
        match self.slot(Role::Q) {
            Some(t) if t > 0.0 => self.emit(sink, CanonOp::WaitOrientComplete(t)),
            Some(t) => {
                diags.push(Diagnostic::new(Code::BadValue, range, format!("{}: a wait of Q{t} seconds; Q must be above 0", def.label())))
            }
            None => {}
        }
    }

    fn execute_code(&mut self, c: usize, range: TextRange, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let def = self.code(c);
        match def.meaning {
            Meaning::FeedPerMinute | Meaning::FeedPerRev => {
                self.st.inverse_time = false;
                let per_rev = def.meaning == Meaning::FeedPerRev;
                if per_rev != self.st.feed_per_rev {
                    self.st.feed_per_rev = per_rev;
                    self.emit(sink, CanonOp::SetFeedMode(if per_rev { FeedMode::PerRevolution } else { FeedMode::PerMinute }));
                }
                if self.dialect.behaviour.feed_mode_resets_feed {
                    self.st.feed = 0.0;
                    self.st.feed_unknown = false;
                    self.emit(sink, CanonOp::SetFeedRate(0.0));
                }
            }
            Meaning::FeedInverseTime => {
                self.st.inverse_time = true;
                if self.st.feed_per_rev {
                    self.st.feed_per_rev = false;
                    self.emit(sink, CanonOp::SetFeedMode(FeedMode::PerMinute));
                }
            }
            // A tool call whose keyword names no tool (`TOOL CALL Z S2000`) changes only what
            // else its block says (the speed): no tool change.
            Meaning::ToolChange if def.keyword.as_ref().is_some_and(|k| k.value_role == Some(Role::T)) && self.slot(Role::T).is_none() => {}
            Meaning::ToolChange => {
                if self.dialect.behaviour.tool_change_stops_spindle {
                    self.emit(sink, CanonOp::StopSpindleTurning);
                    self.st.spindle = Spindle::Stopped;
                    self.st.spindle_unknown = false;
                }
                self.st.tool = self.st.selected_tool;
                self.emit(sink, CanonOp::ChangeTool(self.st.tool));
                if let Some(next) = self.slot(Role::NextTool).filter(|t| *t >= 0.0 && t.fract() == 0.0) {
                    self.st.selected_tool = next as u32;
                    self.emit(sink, CanonOp::SelectTool(next as u32));
                }
                if self.dialect.behaviour.tool_change_applies_length {
                    // A tool change that applies the length (Siemens D, Heidenhain TOOL CALL)
                    // keeps the program position: such programs place Z after the call.
                    self.st.tool_offset = self.tool_offsets(self.st.tool);
                    self.emit(sink, CanonOp::UseToolLengthOffset(self.st.tool_offset));
                }
            }
            Meaning::ToolSet => {
                // `M61 Q3`: the machine is told the spindle holds tool 3; nothing moves. The
                // interpreter goes on reading the tool the last change loaded (#5400, the
                // length G43 takes), as rs274 reads it back after CHANGE_TOOL_NUMBER.
                match self.slot(Role::Q) {
                    Some(q) if q >= 0.0 && q.fract() == 0.0 && q < f64::from(u32::MAX) => {
                        self.emit(sink, CanonOp::ChangeToolNumber(q as u32));
                    }
                    _ => diags.push(Diagnostic::new(Code::BadValue, range, format!("{}: Q must be a tool number", def.label()))),
                }
            }
            Meaning::SpindleCw => {
                self.st.spindle = Spindle::Cw;
                self.st.tech_warned = false;
                self.emit(sink, CanonOp::StartSpindleClockwise);
            }
            Meaning::SpindleCcw => {
                self.st.spindle = Spindle::Ccw;
                self.st.tech_warned = false;
                self.emit(sink, CanonOp::StartSpindleCounterclockwise);
            }
            Meaning::SpindleStop => {
                self.st.spindle = Spindle::Stopped;
                self.st.spindle_unknown = false;
                self.emit(sink, CanonOp::StopSpindleTurning);
            }
            Meaning::SpindleOrient => self.orient_spindle(def, range, sink, diags),
            Meaning::CoolantMist => {
                self.st.mist = true;
                self.emit(sink, CanonOp::MistOn);
            }
            Meaning::CoolantFlood => {
                self.st.flood = true;
                self.emit(sink, CanonOp::FloodOn);
            }
            Meaning::CoolantOff => {
                self.st.mist = false;
                self.st.flood = false;
                self.emit(sink, CanonOp::MistOff);
                self.emit(sink, CanonOp::FloodOff);
            }
            Meaning::Dwell => {
                let seconds = match (self.slot(Role::P), self.slot(Role::X)) {
                    (Some(p), _) => self.dwell_seconds(p),
                    (None, Some(x)) => x,
                    (None, None) if def.params.takes(Role::F) && self.slot(Role::F).is_some() => self.slot(Role::F).unwrap_or(0.0),
                    (None, None) if def.params.takes(Role::K) => self.slot(Role::K).unwrap_or(0.0),
                    (None, None) => 0.0,
                };
                self.emit(sink, CanonOp::Dwell(seconds));
            }
            Meaning::PlaneXy | Meaning::PlaneXz | Meaning::PlaneYz => {
                let plane = match def.meaning {
                    Meaning::PlaneXy => Plane::Xy,
                    Meaning::PlaneXz => Plane::Xz,
                    _ => Plane::Yz,
                };
                self.st.plane = plane;
                self.emit(sink, CanonOp::SelectPlane(plane));
            }
            Meaning::UnitsInch | Meaning::UnitsMm => {
                let units = if def.meaning == Meaning::UnitsInch { Units::Inch } else { Units::Mm };
                self.set_units(units);
                self.emit(sink, CanonOp::UseLengthUnits(units));
            }
            Meaning::CompOff => {
                self.emit(sink, CanonOp::Setting(Setting::CutterComp(None)));
                self.st.leaving_comp = self.comp.borrow().is_some();
                self.comp_off(sink);
            }
            Meaning::CompLeft | Meaning::CompRight | Meaning::CompLeftDiameter | Meaning::CompRightDiameter => {
                let by_diameter = matches!(def.meaning, Meaning::CompLeftDiameter | Meaning::CompRightDiameter);
                let radius = if by_diameter { self.slot(Role::D).map(|d| d / 2.0) } else { None };
                let radius = radius.or_else(|| {
                    let tool = self.slot(Role::D).map_or(self.st.tool, |d| d as u32);
                    let diameter = self.tool_diameter(tool);
                    diameter.filter(|_| !by_diameter).map(|d| d / 2.0)
                });
                let left = matches!(def.meaning, Meaning::CompLeft | Meaning::CompLeftDiameter);
                // A D diameter is in program units; the tool table is in millimetres.
                let radius = radius.map(|r| if by_diameter { r } else { r / self.st.units.to_mm() });
                // A negative offset (`G41.1 D-0.3`) runs on the other side, as in rs274.
                let left = left != radius.is_some_and(|r| r < 0.0);
                let radius = radius.map(f64::abs);
                let side = if left { comp::Side::Left } else { comp::Side::Right };
                self.st.comp_left = left;
                let number = self.slot(Role::D).filter(|_| !by_diameter).map(|d| d as u32);
                self.emit(sink, CanonOp::Setting(Setting::CutterComp(Some((left, number)))));
                if let Some(r) = radius
                    && self.comp.borrow().as_ref().is_some_and(|c| c.runs(side, r))
                {
                    // Written again on a later block (`L X+10 RL`): compensation goes on.
                    return;
                }
                self.comp_off(sink);
                // Moves held before compensation starts are not compensated.
                self.corners_out(sink);
                if radius == Some(0.0) {
                    // A zero offset leaves the path as programmed (rs274 does the same).
                    return;
                }
                if let Some(r) = radius.filter(|_| matches!(self.st.plane, Plane::Xy | Plane::Xz)) {
                    let axes = self.st.plane.axes();
                    // A lathe tool's orientation (`G42.1 D0.4 L3`) puts the controlled point at
                    // its imaginary tip (in the ZX plane, Z first).
                    let orientation = self.slot(Role::L).filter(|l| by_diameter && l.fract() == 0.0 && *l >= 0.0).unwrap_or(0.0);
                    let (tx, tz) = comp::tip_offset(orientation as u32);
                    let tip = if self.st.plane == Plane::Xz { (tz * r, tx * r) } else { (0.0, 0.0) };
                    let at = (self.st.pos[axes.0], self.st.pos[axes.1]);
                    *self.comp.borrow_mut() = Some(comp::Comp::new(side, r, axes, tip, at));
                    return;
                }
                let register = match number.filter(|&d| d != 0) {
                    Some(d) => Some(format!("D{d}")),
                    None => (self.st.tool != 0).then(|| format!("tool {}", self.st.tool)),
                };
                if radius.is_none()
                    && let Some(register) = register
                {
                    // `G41 D01`, `RL` after `TOOL CALL 5`, with no tool table: the radius is in
                    // the control's offset table, machine data like any other; CAM posts that
                    // compensate only wear write the tool centre's path, so the programmed path
                    // is the plan.
                    let msg = format!(
                        "{}: the radius of {register} is in the control's tool offsets, unknown here; the programmed path is used",
                        def.label()
                    );
                    self.limited(diags, "cutter-comp", Diagnostic::new(Code::UnknownValue, range, msg));
                } else if radius.is_none() {
                    let msg = format!(
                        "{} without an offset: no D word and no tool diameter in the tool table; the programmed path is used",
                        def.label()
                    );
                    self.limited(diags, "cutter-comp", Diagnostic::new(Code::CompWithoutOffset, range, msg));
                } else {
                    let msg = format!("{}: the compensated path is not computed yet; the programmed path is used", def.label());
                    self.limited(diags, "cutter-comp", Diagnostic::new(Code::Unsupported, range, msg));
                }
            }
            Meaning::LengthCompPlus | Meaning::LengthCompMinus => {
                let h = match self.slot(Role::H) {
                    Some(h) if h != 0.0 || !self.dialect.behaviour.h0_spindle_tool => h as u32,
                    _ => self.st.tool,
                };
                self.emit(sink, CanonOp::Setting(Setting::LengthOffset(h)));
                let mut offsets = self.tool_offsets(h);
                if def.meaning == Meaning::LengthCompMinus {
                    offsets = offsets.map(|v| -v);
                }
                self.use_tool_offset(offsets, sink);
            }
            Meaning::LengthCompDynamic => {
                // G43.1: the offsets are the axis words themselves, in program units.
                let offsets = [Role::X, Role::Y, Role::Z].map(|r| self.slot(r).unwrap_or(0.0));
                self.use_tool_offset(offsets, sink);
            }
            Meaning::LengthCompCancel => {
                self.emit(sink, CanonOp::Setting(Setting::LengthOffset(0)));
                self.use_tool_offset([0.0; 3], sink);
            }
            Meaning::Wcs => {
                if u16::from(def.index) != self.st.wcs {
                    self.select_wcs(u16::from(def.index), sink);
                }
            }
            Meaning::StateSave | Meaning::StateSaveAutorestore | Meaning::StateInvalidate | Meaning::StateRestore => {
                self.modal_context(def, range, sink, diags);
            }
            Meaning::PathMode => {}
            Meaning::SpindleLimit => {
                if let Some(max) = self.slot(Role::S) {
                    self.set_spindle_limit(max, sink);
                }
                // A lathe's `G50 X.. Z..` (G-code system A) also sets the coordinate system,
                // as G92 does, where the dictionary lets the code take axis words.
                if Role::AXES.iter().any(|&r| self.slot(r).is_some() && def.params.takes(r)) {
                    self.origin_shift(sink);
                }
            }
            Meaning::SpindleCss => {
                // LinuxCNC's D or Siemens' LIMS in the block, else the limit set before (a
                // lathe's `G50 S`), else none (rs274 says 1e30).
                let max = self
                    .slot(Role::D)
                    .or(self.slot(Role::SpindleLimit))
                    .or(self.st.spindle_limit)
                    .unwrap_or(crate::canon::NO_SPINDLE_LIMIT);
                self.st.css_max = Some(max);
                self.emit(sink, CanonOp::SetSpindleMode(Some(max)));
            }
            Meaning::SpindleRpm => {
                self.st.css_max = None;
                self.emit(sink, CanonOp::SetSpindleMode(None));
            }
            Meaning::DistanceAbsolute | Meaning::DistanceIncremental => {
                let mode = if def.meaning == Meaning::DistanceAbsolute { DistanceMode::Absolute } else { DistanceMode::Incremental };
                if mode != self.st.distance {
                    self.st.distance = mode;
                    self.emit(sink, CanonOp::DistanceMode(mode));
                }
            }
            Meaning::ArcDistanceAbsolute => self.st.arc_incremental = false,
            Meaning::ArcDistanceIncremental => self.st.arc_incremental = true,
            Meaning::RetractInitial => self.st.retract = Retract::Initial,
            Meaning::RetractR => self.st.retract = Retract::RPlane,
            Meaning::SetData => self.set_data(def, range, sink, diags),
            Meaning::OriginShift => self.origin_shift(sink),
            Meaning::Rotation => {
                if self.st.plane != Plane::Xy {
                    self.unsupported(def, range, diags);
                    return;
                }
                let cx = self.slot(Role::X).unwrap_or(self.st.pos[0]);
                let cy = self.slot(Role::Y).unwrap_or(self.st.pos[1]);
                let angle = self.slot(Role::R).unwrap_or(0.0).to_radians();
                self.st.rotation = Some((cx, cy, angle.cos(), angle.sin()));
            }
            Meaning::RotationCancel => self.st.rotation = None,
            Meaning::Scaling => {
                let uniform = block.words.iter().find(|w| w.role == Role::P).map(|w| match w.value {
                    // Without a decimal point, P counts in 0.001 (parameter 5400#7 off).
                    Value::Number { decimal: false, value } => value * 0.001,
                    _ => self.slot(Role::P).unwrap_or(1.0),
                });
                let k = match uniform {
                    Some(p) => [p; 3],
                    None => [Role::I, Role::J, Role::K].map(|r| {
                        let w = block.words.iter().find(|w| w.role == r);
                        match w.map(|w| w.value) {
                            Some(Value::Number { decimal: false, value }) => value * 0.001,
                            Some(_) => self.slot(r).unwrap_or(1.0),
                            None => 1.0,
                        }
                    }),
                };
                if k.iter().any(|&f| f <= 0.0 || !f.is_finite()) {
                    diags.push(Diagnostic::new(Code::MalformedNumber, range, format!("{}: scale factors must be positive", def.label())));
                    return;
                }
                let centre = [0, 1, 2].map(|i| self.slot(Role::AXES[i]).unwrap_or(self.st.pos[i]));
                if k[0] != k[1] {
                    self.limited(
                        diags,
                        "scaling",
                        Diagnostic::new(
                            Code::Unsupported,
                            range,
                            format!("{}: unequal X and Y factors distort arcs; arcs keep their radius ratio from X", def.label()),
                        ),
                    );
                }
                self.st.scaling = Some((centre, k));
            }
            Meaning::ScalingCancel => self.st.scaling = None,
            Meaning::WcsExtended => {
                // G54.1 Pn, G154 Pn, G15 Hn: additional work offset n, its own system (0 until
                // the program sets it, as every offset here), so that a change of fixture
                // offset is seen as one. Without a number: the first.
                let n = self.slot(Role::P).or(self.slot(Role::H)).or(Some(1.0));
                match self.extended_wcs(n) {
                    Some(index) if index != self.st.wcs => self.select_wcs(index, sink),
                    Some(_) => {}
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
            Meaning::OriginShiftCancel => {
                for i in 0..6 {
                    self.st.pos[i] += self.st.g92[i];
                }
                self.st.g92 = [0.0; 6];
                self.emit(sink, CanonOp::SetG92Offset([0.0; 6]));
            }
            Meaning::Home1 | Meaning::Home2 => self.home(def.meaning == Meaning::Home1, sink),
            Meaning::Home1Set | Meaning::Home2Set => {
                // The reference positions are kept in machine coordinates, mm.
                let m = self.machine_pos();
                let mut home = [0.0; 6];
                for (i, v) in home.iter_mut().enumerate() {
                    *v = if i < 3 { m[i] * self.st.units.to_mm() } else { m[i] };
                }
                if def.meaning == Meaning::Home1Set {
                    self.st.home1 = home;
                } else {
                    self.st.home2 = home;
                }
            }
            Meaning::MachineCoords => {}
            m if matches!(
                m,
                Meaning::Rapid
                    | Meaning::Linear
                    | Meaning::ArcCw
                    | Meaning::ArcCcw
                    | Meaning::ArcPole
                    | Meaning::ArcRadius
                    | Meaning::ArcTangent
                    | Meaning::ArcThreePoint
                    | Meaning::SpindleSync
                    | Meaning::RigidTap
                    | Meaning::CycleThread
                    | Meaning::CycleTurn
                    | Meaning::CycleFace
                    | Meaning::CycleThreadPass
                    | Meaning::Probe
                    | Meaning::ProbeQuiet
                    | Meaning::SplineQuadratic
                    | Meaning::Nurbs
            ) || m.is_cycle() =>
            {
                self.st.motion_continued = self.st.motion_code == Some(c);
                if !self.st.motion_continued {
                    self.st.sticky_z = None;
                    self.st.turn_cycle = None;
                    // Another motion mode drops the NURBS points collected (as rs274 does).
                    self.st.nurbs = None;
                }
                if !m.is_cycle() {
                    self.st.cycle_initial = None;
                }
                self.st.motion_code = Some(c);
                let full_circle = matches!(def.meaning, Meaning::ArcCw | Meaning::ArcCcw)
                    && [Role::I, Role::J, Role::K].iter().any(|&r| self.slots[r as usize].is_some());
                let in_place = self.dialect.behaviour.motion_in_place && matches!(def.meaning, Meaning::Rapid | Meaning::Linear);
                if self.has_axes || full_circle || in_place {
                    self.motion(def, range, block, sink, diags);
                }
            }
            Meaning::NurbsEnd => {
                self.st.motion_code = None;
                self.nurbs_end(def, range, sink, diags);
            }
            Meaning::CycleCancel => {
                // G80 ends a canned cycle; where it has a group of its own (Fanuc group 09) a
                // G0/G1 mode set in the same block stays.
                if self.st.motion_code.is_none_or(|m| self.code(m).meaning.is_cycle() || self.code(m).group == def.group) {
                    self.st.motion_code = None;
                }
                self.st.sticky_z = None;
                self.st.cycle_initial = None;
                self.emit(sink, CanonOp::CycleCancel);
            }
            Meaning::ProgramStop => self.emit(sink, CanonOp::ProgramStop),
            Meaning::OptionalStop => self.emit(sink, CanonOp::OptionalProgramStop),
            Meaning::OverridesOn | Meaning::OverridesOff => {
                let on = def.meaning == Meaning::OverridesOn;
                self.st.overrides = (on, on);
                self.emit(sink, CanonOp::FeedOverride(on));
                self.emit(sink, CanonOp::SpeedOverride(on));
            }
            Meaning::FeedOverrideSwitch => {
                let on = self.slot(Role::P).is_none_or(|p| p != 0.0);
                self.st.overrides.0 = on;
                self.emit(sink, CanonOp::FeedOverride(on));
            }
            Meaning::SpeedOverrideSwitch => {
                let on = self.slot(Role::P).is_none_or(|p| p != 0.0);
                self.st.overrides.1 = on;
                self.emit(sink, CanonOp::SpeedOverride(on));
            }
            Meaning::ProgramEnd | Meaning::ProgramEndRewind => self.program_end(sink),
            Meaning::SubprogramCall => {
                let Some(p) = self.program_number(Role::P, range, diags) else { return };
                let mut repeats = self.repeat_count(diags, range);
                let mut program = p;
                if self.dialect.macros.repeat_in_p && self.slot(Role::L).is_none() && p > 9999 {
                    (repeats, program) = (p / 10_000, p % 10_000);
                }
                let start = match self.dialect.macros.call_start.and_then(|l| self.dialect.letter_role(l)) {
                    Some(role) if self.slots[role as usize].is_some() => match self.program_number(role, range, diags) {
                        Some(n) => Some(n),
                        None => return,
                    },
                    _ => None,
                };
                self.request = Some(Request::Call { program, repeats, macro_call: false, args: Vec::new(), start });
            }
            Meaning::LocalSubprogramCall => {
                let Some(number) = self.program_number(Role::P, range, diags) else { return };
                let repeats = self.repeat_count(diags, range);
                self.request = Some(Request::CallLocal { number, repeats });
            }
            Meaning::SubprogramReturn => {
                let goto = self.slot(Role::P).filter(|p| *p >= 0.0 && p.fract() == 0.0).map(|p| p as u32);
                self.request = Some(Request::Return { goto });
            }
            Meaning::DiameterMode => self.st.diameter = true,
            Meaning::RadiusMode => self.st.diameter = false,
            Meaning::Other | Meaning::Output | Meaning::ProgramBegin => {}
            Meaning::Stock => self.stock_corner(sink),
            Meaning::ArcDirCw | Meaning::ArcDirCcw | Meaning::RapidBlock => {}
            Meaning::ApproachTangent
            | Meaning::ApproachNormal
            | Meaning::ApproachArc
            | Meaning::DepartTangent
            | Meaning::DepartNormal
            | Meaning::DepartArc => self.motion(def, range, block, sink, diags),
            Meaning::CornerRound | Meaning::CornerChamfer => {
                let size = if def.meaning == Meaning::CornerRound { self.slot(Role::R) } else { self.slot(Role::Geometry) };
                match size {
                    Some(v) if v > 0.0 => self.mark_corner(if def.meaning == Meaning::CornerRound {
                        corner::Corner::Round(v)
                    } else {
                        corner::Corner::Chamfer(v)
                    }),
                    // An unknown size (the tool radius, `RND RQ108`): the word was left out
                    // and said so; the corner stays sharp.
                    None if self.unknown_roles
                        & (1 << (if def.meaning == Meaning::CornerRound { Role::R } else { Role::Geometry }) as u32)
                        != 0 => {}
                    _ => diags.push(Diagnostic::new(Code::MissingParameter, range, format!("{} needs a size above zero", def.label()))),
                }
            }
            Meaning::Pole => {
                let t = self.target();
                let (a0, a1, _) = self.st.plane.axes();
                self.st.pole = (t[a0], t[a1]);
            }
            Meaning::PoleKeeping => {
                let t = self.target();
                let (a0, a1, _) = self.st.plane.axes();
                let given = |axis: usize| self.slots[Role::AXES[axis] as usize].is_some();
                self.st.pole = match (given(a0), given(a1)) {
                    (false, false) => (t[a0], t[a1]),
                    (g0, g1) => (if g0 { t[a0] } else { self.st.pole.0 }, if g1 { t[a1] } else { self.st.pole.1 }),
                };
            }
            Meaning::PoleIncremental | Meaning::PoleFromPole => {
                let (a0, a1, _) = self.st.plane.axes();
                let (b0, b1) = if def.meaning == Meaning::PoleIncremental { (self.st.pos[a0], self.st.pos[a1]) } else { self.st.pole };
                let word = |axis: usize| self.slot(Role::AXES[axis]).unwrap_or(0.0);
                self.st.pole = (b0 + word(a0), b1 + word(a1));
            }
            Meaning::FrameTrans | Meaning::FrameTransAdd => self.frame_trans(def.meaning == Meaning::FrameTransAdd, sink),
            Meaning::FrameRot | Meaning::FrameRotAdd => self.frame_rot(def, range, diags),
            Meaning::FrameScale | Meaning::FrameScaleAdd => self.frame_scale(def.meaning == Meaning::FrameScaleAdd),
            Meaning::FrameMirror => self.unsupported(def, range, diags),
            Meaning::CycleDefine => self.define_numbered_cycle(def, range, sink, diags),
            Meaning::CycleCall | Meaning::CycleModal => {}
            Meaning::CycleCallAt => self.call_at_position(sink),
            Meaning::MachineDataRead => {
                let msg = format!(
                    "{} ({}) reads data only the machine has at run time: the parameter it sets keeps its value here, so what follows from it may differ on the machine",
                    def.label(),
                    def.name
                );
                self.st.machine_data_read = true;
                self.limited(diags, "machine-data-read", Diagnostic::new(Code::Unsupported, range, msg));
            }
            Meaning::PatternRow | Meaning::PatternCircle | Meaning::PatternGrid => self.code_pattern(def, range, block, sink, diags),
            Meaning::CycleRoughTurn | Meaning::CycleRoughFace | Meaning::CycleFinishContour => self.contour_cycle(def, range, diags),
            Meaning::ProfileFinish | Meaning::ProfileRoughTurn | Meaning::ProfileRoughFace => self.profile_cycle(def, range, diags),
            Meaning::CycleIntent => {
                let msg = format!("{} ({}) is kept as intent only: its moves are not expanded", def.label(), def.name);
                self.limited(diags, "cycle-not-expanded", Diagnostic::new(Code::Unsupported, range, msg));
            }
            _ => {
                if self.dialect.groups[def.group].step == Step::Motion {
                    self.st.motion_code = None;
                }
                self.unsupported(def, range, diags);
            }
        }
    }

    /// `BLK FORM 0.1 Z X+0 Y+0 Z-40` then `BLK FORM 0.2 X+100 Y+100 Z+0`: the blank's corners
    /// (the second may be incremental from the first). Passed on as the stock comment that
    /// plan recovery reads, as a CAM system writes it.
    fn stock_corner(&mut self, sink: &mut dyn CanonSink) {
        let corner = |s: &Self, base: [f64; 3]| {
            [Role::X, Role::Y, Role::Z].map(|r| {
                let i = r as usize;
                match s.slots[i] {
                    Some(slot) if slot.mode == WordMode::Incremental => base[i] + slot.value,
                    Some(slot) => slot.value,
                    None => base[i],
                }
            })
        };
        let second = self.slot(Role::Extra).is_some_and(|v| (v - 0.2).abs() < 1e-9);
        match (second, self.st.blank_min) {
            (false, _) => self.st.blank_min = Some(corner(self, [0.0; 3])),
            (true, Some(min)) => {
                let max = corner(self, min);
                self.emit(sink, stock_comment(min, max));
                self.st.blank_min = None;
            }
            (true, None) => {}
        }
    }

    fn dwell_seconds(&self, p: f64) -> f64 {
        match self.dialect.behaviour.dwell_unit {
            TimeUnit::Seconds => p,
            TimeUnit::Milliseconds => p / 1000.0,
        }
    }

    fn set_units(&mut self, units: Units) {
        if units == self.st.units {
            return;
        }
        let k = self.st.units.to_mm() / units.to_mm();
        for i in 0..3 {
            self.st.pos[i] *= k;
            self.st.g92[i] *= k;
            for w in self.st.wcs_offsets.iter_mut().chain(self.st.wcs_extended.values_mut()) {
                w[i] *= k;
            }
        }
        for v in &mut self.st.tool_offset {
            *v *= k;
        }
        self.st.units = units;
    }

    /// Puts tool offsets (program units) in force. The controlled point stays where it is, so
    /// its program coordinates change by the difference, as rs274's do.
    fn use_tool_offset(&mut self, offsets: [f64; 3], sink: &mut dyn CanonSink) {
        // The offsets are along the machine's axes; a rotated system sees X and Y turned.
        let mut delta: [f64; 3] = std::array::from_fn(|i| offsets[i] - self.st.tool_offset[i]);
        let rotation = self.st.rotation(self.st.wcs);
        if rotation != 0.0 {
            [delta[0], delta[1]] = rotate([delta[0], delta[1]], -rotation);
        }
        for (p, d) in self.st.pos.iter_mut().zip(delta) {
            *p -= d;
        }
        self.st.tool_offset = offsets;
        self.emit(sink, CanonOp::UseToolLengthOffset(offsets));
    }

    /// A T word: selects the tool. Where the dictionary splits the word (`T0202`), its last
    /// digits name the offset; where the T word changes the tool (a turret), the change and
    /// the offset take effect at once, the program position kept as after a tool change.
    fn tool_word(&mut self, t: f64, sink: &mut dyn CanonSink) {
        let digits = self.dialect.addresses.iter().find(|a| a.role == Role::T).and_then(|a| a.offset_digits);
        let (tool, offset) = match digits {
            Some(d) => {
                let base = 10u32.pow(u32::from(d));
                let t = t as u64;
                ((t / u64::from(base)).min(u64::from(u32::MAX)) as u32, Some((t % u64::from(base)) as u32))
            }
            None => (t.min(f64::from(u32::MAX)) as u32, None),
        };
        self.st.selected_tool = tool;
        self.emit(sink, CanonOp::SelectTool(tool));
        if let Some(name) = tool.checked_sub(10_001).and_then(|k| self.tool_names.get(k as usize)) {
            self.emit(sink, CanonOp::Setting(Setting::ToolName(tool, name.clone())));
        }
        if !self.dialect.behaviour.tool_word_changes {
            return;
        }
        if tool != self.st.tool {
            self.st.tool = tool;
            self.emit(sink, CanonOp::ChangeTool(tool));
        }
        let offsets = match offset {
            Some(0) => [0.0; 3],
            Some(n) => self.tool_offsets(n),
            None => self.tool_offsets(tool),
        };
        if offsets != self.st.tool_offset {
            self.st.tool_offset = offsets;
            self.emit(sink, CanonOp::UseToolLengthOffset(offsets));
        }
    }

    /// Tool `n`'s offsets along X, Y and Z in program units: X and Y as the program set them
    /// (G10 L1/L10/L11), Z its length.
    fn tool_offsets(&self, n: u32) -> [f64; 3] {
        let xy = self.tool_edits.get(&n).map_or([None; 2], |e| e.xy);
        let mm = self.st.units.to_mm();
        [xy[0].unwrap_or(0.0) / mm, xy[1].unwrap_or(0.0) / mm, self.tool_length(n) / mm]
    }

    /// Tool `n`'s length offset in millimetres: the profile's, as the program changed it.
    fn tool_length(&self, n: u32) -> f64 {
        let edit = self.tool_edits.get(&n);
        edit.and_then(|e| e.length).unwrap_or_else(|| self.profile.tools.get(&n).map_or(0.0, |t| t.length))
            + edit.map_or(0.0, |e| e.length_wear)
    }

    /// Tool `n`'s diameter in millimetres, if known: the profile's, as the program changed it.
    fn tool_diameter(&self, n: u32) -> Option<f64> {
        let edit = self.tool_edits.get(&n);
        let geometry = edit.and_then(|e| e.radius).map(|r| 2.0 * r).or_else(|| self.profile.tools.get(&n).and_then(|t| t.diameter));
        geometry.map(|d| d + 2.0 * edit.map_or(0.0, |e| e.radius_wear))
    }

    /// `G10 L..`: sets a work offset or tool data, as the dialect's forms say for this L.
    fn set_data(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let l = self.slot(Role::L).unwrap_or(0.0);
        let form = def.forms.iter().find(|(n, _)| f64::from(*n) == l).map(|&(_, f)| f);
        match form {
            Some(DataForm::Wcs | DataForm::WcsHere) => self.set_wcs(def, form == Some(DataForm::WcsHere), range, sink, diags),
            Some(DataForm::WcsExtended) => match self.extended_wcs(self.slot(Role::P)) {
                Some(index) => self.set_wcs_offsets(index, false, sink),
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

    /// `G10 L1/L10/L11` (LinuxCNC) and `G10 L10–L13` (Fanuc): tool P's length or radius.
    fn set_tool_data(&mut self, def: &CodeDef, form: DataForm, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let Some(p) = self.slot(Role::P).filter(|p| *p >= 0.0 && p.fract() == 0.0 && *p < 1e6) else {
            if self.unknown_roles & (1 << Role::P as u32) != 0 {
                // `G10 L10 P#20`: the caller's tool number; the word was left out and said so.
                return;
            }
            diags.push(Diagnostic::new(Code::MissingParameter, range, format!("{} needs P, a tool or offset number", def.label())));
            return;
        };
        let n = p as u32;
        let mm = self.st.units.to_mm();
        if matches!(form, DataForm::Tool | DataForm::ToolHere | DataForm::ToolHereFixture)
            && [Role::A, Role::B, Role::C].iter().any(|&r| self.slots[r as usize].is_some())
        {
            let msg = format!("{}: tool offsets along rotary axes are not kept; only X, Y, Z and R are", def.label());
            self.limited(diags, "tool-offset-axes", Diagnostic::new(Code::Unsupported, range, msg));
        }
        // Fanuc: in G91 the value is added to the offset.
        let incremental = self.st.distance == DistanceMode::Incremental;
        let current = (self.tool_length(n), self.tool_diameter(n).map(|d| d / 2.0));
        let given = [Role::X, Role::Y, Role::Z].map(|r| self.slots[r as usize].map(|s| s.value));
        // For L10/L11: offsets that make the spindle's point read the given coordinates, in the
        // active system with G92 (L10) or in G59.3 without it (L11). They are worked out in
        // that system's (perhaps rotated) axes, an axis not given keeping the tool's offset,
        // and turned back to the machine's axes, as rs274 does.
        let here = {
            let (w, g92) = if form == DataForm::ToolHereFixture { (9, false) } else { (self.st.wcs, true) };
            let rotation = self.st.rotation(w);
            let machine = self.machine_pos();
            let spindle: [f64; 6] = std::array::from_fn(|i| machine[i] + if i < 3 { self.st.tool_offset[i] } else { 0.0 });
            let q = self.machine_to_system(spindle, w, g92);
            let stored = self.tool_offsets(n);
            let [sx, sy] = rotate([stored[0], stored[1]], -rotation);
            let xy = rotate([given[0].map_or(sx, |v| q[0] - v), given[1].map_or(sy, |v| q[1] - v)], rotation);
            [xy[0], xy[1], given[2].map_or(stored[2], |z| q[2] - z)]
        };
        let xy_given = given[0].is_some() || given[1].is_some();
        let edit = self.tool_edits.entry(n).or_default();
        let value = |v: f64, old: f64| if incremental { old + v * mm } else { v * mm };
        match form {
            DataForm::Tool => {
                for (slot, v) in edit.xy.iter_mut().zip(given) {
                    if let Some(v) = v {
                        *slot = Some(v * mm);
                    }
                }
                if let Some(z) = given[2] {
                    (edit.length, edit.length_wear) = (Some(z * mm), 0.0);
                }
                if let Some(r) = self.slots[Role::R as usize].map(|s| s.value) {
                    (edit.radius, edit.radius_wear) = (Some(r * mm), 0.0);
                }
            }
            DataForm::ToolHere | DataForm::ToolHereFixture => {
                if xy_given {
                    edit.xy = [Some(here[0] * mm), Some(here[1] * mm)];
                }
                if given[2].is_some() {
                    (edit.length, edit.length_wear) = (Some(here[2] * mm), 0.0);
                }
                if let Some(r) = self.slots[Role::R as usize].map(|s| s.value) {
                    (edit.radius, edit.radius_wear) = (Some(r * mm), 0.0);
                }
            }
            DataForm::ToolLength | DataForm::ToolLengthWear | DataForm::ToolRadius | DataForm::ToolRadiusWear => {
                let Some(r) = self.slots[Role::R as usize].map(|s| s.value) else {
                    diags.push(Diagnostic::new(Code::MissingParameter, range, format!("{} needs R, the offset value", def.label())));
                    return;
                };
                match form {
                    DataForm::ToolLength => edit.length = Some(value(r, current.0 - edit.length_wear)),
                    DataForm::ToolLengthWear => edit.length_wear = value(r, edit.length_wear),
                    DataForm::ToolRadius => edit.radius = Some(value(r, current.1.unwrap_or(0.0) - edit.radius_wear)),
                    _ => edit.radius_wear = value(r, edit.radius_wear),
                }
            }
            DataForm::Wcs | DataForm::WcsHere | DataForm::WcsExtended => {}
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
            self.switch_wcs(|st| st.set_offset(index, off, rotation));
            self.emit(sink, CanonOp::SetG5xOffset(index, off));
        } else {
            self.st.set_offset(index, off, rotation);
        }
    }

    /// The current position in machine coordinates.
    pub(super) fn machine_pos(&self) -> [f64; 6] {
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
    pub(super) fn program_pos(&self, machine: [f64; 6]) -> [f64; 6] {
        self.machine_to_system(machine, self.st.wcs, true)
    }

    /// A machine position in work coordinate system `wcs` (1 for G54), with or without the
    /// G92 shift.
    fn machine_to_system(&self, machine: [f64; 6], wcs: u16, g92: bool) -> [f64; 6] {
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

    /// Makes work coordinate system `index` (1 for G54) the active one.
    fn select_wcs(&mut self, index: u16, sink: &mut dyn CanonSink) {
        let new = self.st.offset(index);
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
    fn shift_origin(&mut self, old: [f64; 6], new: [f64; 6]) {
        for i in 0..6 {
            self.st.pos[i] += old[i] - new[i];
        }
    }

    fn origin_shift(&mut self, sink: &mut dyn CanonSink) {
        for (i, &role) in Role::AXES.iter().enumerate() {
            if let Some(v) = self.slot(role) {
                let machine_rel = self.st.pos[i] + self.st.g92[i];
                self.st.g92[i] = machine_rel - v;
                self.st.pos[i] = v;
            }
        }
        self.emit(sink, CanonOp::SetG92Offset(self.st.g92));
    }

    fn home(&mut self, first: bool, sink: &mut dyn CanonSink) {
        let any = Role::AXES.iter().any(|&r| self.slots[r as usize].is_some());
        let mut mid = self.st.pos;
        for (i, &role) in Role::AXES.iter().enumerate() {
            if let Some(v) = self.slot(role) {
                mid[i] = if self.st.distance == DistanceMode::Incremental { self.st.pos[i] + v } else { v };
            }
        }
        self.emit(sink, CanonOp::StraightTraverse(mid));
        let home = if first { self.st.home1 } else { self.st.home2 };
        let mut end = mid;
        let moves = |i: usize| !any || self.slots[Role::AXES[i] as usize].is_some();
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

    pub(super) fn program_end(&mut self, sink: &mut dyn CanonSink) {
        self.comp_off(sink);
        self.st.wcs = 1;
        self.emit(sink, CanonOp::SetG5xOffset(1, self.st.wcs_offsets[0]));
        let initial = self.dialect.behaviour.initial_plane;
        if self.st.plane != initial {
            self.st.plane = initial;
            self.emit(sink, CanonOp::SelectPlane(initial));
        }
        self.st.distance = DistanceMode::Absolute;
        self.st.feed = 0.0;
        self.emit(sink, CanonOp::SetFeedRate(0.0));
        self.st.spindle = Spindle::Stopped;
        self.emit(sink, CanonOp::StopSpindleTurning);
        if self.st.css_max.take().is_some() {
            self.emit(sink, CanonOp::SetSpindleMode(None));
        }
        if self.st.mist {
            self.emit(sink, CanonOp::MistOff);
        }
        if self.st.flood {
            self.emit(sink, CanonOp::FloodOff);
        }
        self.st.mist = false;
        self.st.flood = false;
        self.emit(sink, CanonOp::ProgramEnd);
        self.st.ended = true;
    }
}

// Role and step sets are bit masks.
const _: () = assert!(Role::COUNT <= 128 && Step::ALL.len() <= 32);

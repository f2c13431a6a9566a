//! The post-processor: canonical ops (with cycle intent and plan facts) → program text for
//! a target control, by the `<output>` rules of its dictionary.
//!
//! [`Post`] is a [`CanonSink`]: the interpreter pushes ops into it and it appends text to a
//! buffer that it hands to a caller-given function whenever the buffer passes 64 KiB, so
//! memory holds one buffer, not the program. It keeps only the modal state it needs to
//! leave out unchanged words. Positions are written absolute, in the target's units, in
//! the work offset's frame (a G92-style shift is added to the positions). Canned cycles
//! whose kind the target maps stay cycles; the others are written as their moves, with a
//! note. Everything the target has no rule for is said in a diagnostic, never silently
//! dropped. Safe output: the canon says which axes the program knows (`CanonOp::Known`:
//! none at the start, a machine-frame move's axes none after it); an axis it does not know
//! is never written (not at the 0 the analysis counts from), one that becomes known is
//! written at its move whatever the word written last, and a move of an unknown axis (an
//! incremental move from an unknown start) refuses the translation (`post::unknown-start`).
//!
//! The ops are written by kind: [`Post::op`] hands each to the writer of its group, in a
//! file of its own: `motion.rs` the moves, `cycle.rs` canned cycles, `tool.rs` the tool
//! and its offsets, `spindle.rs` the spindle and the feeds synchronised with it, `modes.rs`
//! units, plane, feed and work offsets, `program.rs` stops and the end, comments, dwells,
//! coolant and what is not written. `lane.rs` writes the common straight move in the steady
//! state, from the templates `layout.rs` sorts. This file keeps the writer's state, renders
//! templates and numbers, and gathers repeated runs.
//!
//! the post-processor: `Post` is a `CanonSink` that writes program text by a
//! dialect's `<output>` rules (`src/dialect/output/`: number formats, templates of words
//! with `{value:FORMAT}` placeholders per event, cycle mappings, rules with a checked
//! condition expression). It streams (a 64 KiB buffer handed to the caller's function; `translate` interprets on a
//! thread of its own and hands the ops over in batches through a bounded channel, order kept,
//! `interpret_beside`) and keeps only modal state: the last written X, Y, Z, F, S, G code, the cycle in force.
//! A modal word's last text is kept as its key (format, inch or not, the rounded integer:
//! one format writes distinct integers as distinct texts), so an unchanged word is told
//! without writing it; `post::layout` sorts each template once into parts (the motion code,
//! one number with its format, modal slot and rounding class, the words put off to a move,
//! any other word); a block in the common move's order (code, put-off words, numbers:
//! `layout::Simple`) is walked without the general cases. Each block is written in place at
//! the end of the buffer and taken back when empty. Numbers are written by integer
//! arithmetic (`push_number`; three decimals from digit tables); a block number's text is
//! counted on in place (`block_digits`: the usual step in its last two digits at once, any
//! other by `count_on`); the rounding error is worked out only where it may pass the
//! largest so far (`below`), counted towards positions, centres (2√2 times) or feeds
//! (`layout::Class`). `post::lane` is the writer's steady lane: while nothing is under way
//! but moves (no tool, speed or move waiting, no cycle, no put-off words, no rules, no repeat
//! being gathered; one flag per move template, `Post::lane_ready`, worked out again after
//! every op the general path takes, the only path that changes it), a straight move goes
//! from its coordinates to its block's text by the same steps (`put_num`, `block_start`,
//! `line_end`, `moved`), so text, modal state and findings are the general path's. The lane
//! puts the block together in a fixed array (`Post::lane_text`; a template whose longest
//! block does not fit has no lane), the block number and leading literal words (`L`) first,
//! then each word after its separator, and appends it at once.
//! Positions are written absolute in the work offset's frame (a G92-style shift added);
//! units follow the machine or the source (what was set before the source's units, a
//! LinuxCNC `G20 F60` feed, changes units with them); an arc whose radii differ by more than the
//! target's arc tolerance (its `behaviour`, two output steps kept for rounding) gets its
//! centre on the chord's bisector (`post::arc-centre` where the path moves by more than the
//! diff's tolerance); whole turns and R-form full circles are split. A G92-style shift added
//! to the positions is said (`post::shift-applied`: the plan read back is in the work
//! offset's frame). A length offset the source cancels (`G49`) is written, and cancelled
//! again after a target's tool change that applies the length; a target that cannot cancel
//! it is an error, and so is another tool's length offset (`G43 H3` with T0) where the
//! target's tool call applies the tool's own. Changes a program makes to the values of the
//! work offset it moved in (G10 L2/L20 while active) are an error: the translation is written
//! in the offset's frame as the program first used it. Positions
//! rounded by more than the diff's tolerance are said once (`post::rounded`; an arc centre
//! counts 2√2 times its rounding, the path moving through the fixed start by that much;
//! cycle levels count), and so are
//! feeds and thread leads (an inch program's four decimals do not state 60 mm/min). Compensation by another
//! offset than the tool's, where the target's `comp-left`/`comp-right` has no `{d}`, is an
//! error. A cycle whose
//! kind the target maps is written as a cycle (its expansion moves are not written), a rapid
//! while a modal output cycle is in force waits to see whether it positions the next hole; a
//! cycle the target cannot state (no mapping, a peck re-approach it cannot set — the
//! cycle's own, `CycleIntent::peck_clearance` —, pecks counted from another level: R for
//! G8x, the surface for cycles that state it, a tap fed out to the clear level where the
//! target's feeds out to R, `Options::tap_to_clear`, a clear level a G98/G99 cycle cannot
//! return to: above where it begins or below R) is written as moves with a note; a G98
//! cycle's clear level below the tool is reached by a rapid first (the initial level); the
//! expansion's spindle calls of a cycle written as a cycle are not written; a surface stated
//! otherwise (a cycle stating it written as G8x, or the R level written for a target's
//! surface where the source's plan has none above the bottom) is `post::surface-restated`;
//! a modal cycle's next position that turns a rotary axis is a move of its own; a cycle
//! stating its depth from the surface (`{depth}`) takes the R level as
//! surface where the hole top is not above its bottom. Spindle-synchronised moves (`thread`, `rigid-tap` with `{pitch}`), constant
//! surface speed (`css-on {smax}`, `css-off`), `spindle-orient {angle} {orient-dir}` and
//! work offsets by index (`work-offset-N`, empty text: none; the additional ones by their own
//! number, `work-offset-extended {wcs}`: `G54.1 P12`, `G154 P12`, `G15 H12`; a `<format min max>`
//! states the values an address takes, Haas's G154 P1–P99, and an event whose template would
//! write another is unwritable, `Output::fits`) are templates
//! (a `css-on` without `{smax}` cannot state a speed limit: unwritable then). A diameter or
//! radius mode the source states (G7/G8, DIAMON/DIAMOF, or a lathe dictionary's diameters at
//! its start) is written as the target reads X: a target that reads diameters from the start
//! (`x-words="diameter"`, `Options::x_diameter`) takes X doubled with no code, one with a
//! `diameter-on` (G7, DIAMON) is put in it and takes X doubled, one with only `diameter-off`
//! takes radii; X positions (and machine X) are doubled as they are written, arc centres and
//! radii not (`Post::as_diameter`; the steady lane stands aside meanwhile). A target with
//! neither mode that reads radii is a milling control: a program in diameters is unwritable
//! there (one that states the radius mode needs no code, `post::mode-implied`), and a program that never says it turns (no diameter or radius mode, no lathe cycle,
//! not in the ZX plane at its first move) is unwritable for a target that reads diameters.
//! A target that starts in feed per revolution is told the source's starting feed mode after
//! the header (`Options::feed_per_rev_at_start`); a cutting speed under constant surface speed
//! converts with the units (ft/min ↔ m/min); a tool change whose template is
//! empty or cannot take the number (`digits`, `min`/`max` of a format: a lathe's `T0101`) is
//! unwritable. A lathe cycle is written as its moves (`post::cycle-as-moves`). A tilted working plane is the target's `work-plane` with
//! its origin (`{px} {py} {pz}`) and its rotation in the angles the control takes (spatial
//! `{spa} {spb} {spc}`: Heidenhain `PLANE SPATIAL`; Euler `{eul-a} {eul-b} {eul-c}`: Fanuc
//! `G68.2`; axis by axis `{rot-a} {rot-b} {rot-c}`: Siemens `CYCLE800` mode 57), the
//! untilted plane its `work-plane-reset`; a template without the origin cannot state a plane
//! off the program zero. Without a template, or
//! for a tilted tool axis or a NURBS feed (the canon keeps no control points), an error
//! diagnostic. A run of blocks the source runs again (loop, subprogram called N times) is
//! held in the buffer (found by `line_offsets`, the text since each source line): while each
//! pass writes the same text (the first may differ by what was in force before it, and is
//! then left before the loop) it is written once, as the target's dictionary says: between
//! `repeat-begin` and `repeat-end` where it ran (`o100 repeat [{count}]`; Siemens `MARK1:` …
//! `REPEAT MARK1 P={again}`, Heidenhain `LBL 1` … `CALL LBL 1 REP {again}`, `{again}` the
//! passes after the first), or as a subprogram after the program's end (`sub-begin {sub}` …
//! `sub-end`, `{sub}` above 1000 and the main program's number) called where it ran
//! (`repeat-call`: Fanuc `M98 P1001 L3`, Haas `M97 P1001 L3` to `N1001`); otherwise unrolled
//! with `post::unrolled`. Numbered blocks are compared without their numbers (the ones the
//! passes were written with, in sequence) and renumbered when the loop's blocks go in. Numbers are formatted into a stack buffer, an unchanged modal value is
//! left out without formatting it. Plan facts: hole tops (`hole_tops`) for targets whose
//! cycles state the surface, tool facts from a tool table (`tool_facts`) as a tool comment
//! (`T4 D=10 END MILL`) the target's plan reads. `translate` runs the interpreter into it;
//! `ncplan translate` is in `cli`.

use std::collections::BTreeSet;

mod cycle;
mod lane;
mod layout;
mod machine;
mod modes;
mod motion;
mod program;
mod spindle;
mod tool;
use cycle::ActiveCycle;
use lane::Lane;
use layout::{Class, Layout, NO_SLOT, Num, Part};

use crate::canon::{ALL_KNOWN, Canon, CanonOp, CanonSink, FeedMode, Plane, Setting, Units};
use crate::diag::{Code, Diagnostic};
use crate::dialect::output::{Cmp, Expr, NumberFormat, Numbered, Output, Piece, Point, StateVar, Template, Value};

/// What the caller tells the writer about the program.
#[derive(Clone, Debug)]
pub struct Options {
    /// The program's name (`BEGIN PGM NAME`, `%_N_NAME_MPF`).
    pub name: String,
    /// The program's number (`O1234`).
    pub number: u32,
    /// The target machine's units.
    pub units: Units,
    /// Whether, instead, the program is written in the units the source starts in (no
    /// machine named).
    pub follow_source_units: bool,
    /// The target machine's limits.
    pub limits: Limits,
    /// Plan facts: the top of each hole the source's plan found (X, Y, top, mm), for cycles
    /// that state the workpiece surface where the source's cycle did not (G81 → `CYCLE81`'s
    /// RFP, `Q203`). See [`hole_tops`].
    pub hole_tops: Vec<[f64; 3]>,
    /// The re-approach distance of the source's peck cycles (mm), and the target's: a peck
    /// cycle whose target cannot state it and whose distance differs is written as moves.
    pub peck_clearance: (f64, f64),
    /// Whether the source's tool change puts the tool's length offset in force, and the
    /// target's (set by [`translate`] from the dictionaries).
    pub length_at_tool_change: (bool, bool),
    /// Plan facts: the tools whose diameter the source's reading took from a tool table
    /// (the shop's, or the program's own definitions), written as a tool comment the plan
    /// reads back (`T4 D=10 END MILL`) before each change to them. See [`tool_facts`].
    pub tools: Vec<ToolFact>,
    /// How far the target lets an arc's start and end radii differ: mm, inch (set by
    /// [`translate`] from the target's dictionary; 0: not at all).
    pub arc_tolerance: (f64, f64),
    /// Whether the source's tapping cycle feeds out of the hole all the way to the clear
    /// level (RS274NGC G84), and the target's; otherwise it feeds out to R and rapids on
    /// (Fanuc). Set by [`translate`] from the dictionaries.
    pub tap_to_clear: (bool, bool),
    /// Whether the target reads X words as diameters from the start (a lathe dictionary's
    /// default). Set by [`translate`] from the target's dictionary.
    pub x_diameter: bool,
    /// Whether the source's control starts in feed per revolution, and the target's (a
    /// lathe's): a target that does is told the source's feed mode at the program's start,
    /// so that it never runs in the mode a previous program left. Set by [`translate`].
    pub feed_per_rev_at_start: (bool, bool),
    /// Whether the target's lathes read X words as diameters from reset where its mills do
    /// not (SINUMERIK DIAMON): a program that turns with X as radii states its radius mode.
    /// Set by [`translate`] from the target's dictionary.
    pub lathe_reset_diameter: bool,
    /// Whether the target's feed-type codes end constant surface speed (SINUMERIK group 15:
    /// G95 after G96 turns at a constant speed): where the feed mode is written while it is
    /// in force, it is stated again after it. Set by [`translate`] from the target's dictionary.
    pub feed_mode_ends_css: bool,
    /// Whether the target's constant surface speed codes also set the feed per revolution
    /// (SINUMERIK G96, G97): under a feed per minute, its `css-on-per-minute` and
    /// `css-off-per-minute` are written instead (G961, G971). Set by [`translate`].
    pub css_sets_feed_per_rev: bool,
}

impl Options {
    /// Options for a program named `name` ([`program_identifier`], [`program_number`]),
    /// written in the units it starts in, without machine limits or plan facts. The fields
    /// [`translate`] sets from the dictionaries start neutral.
    pub fn for_program(name: &str) -> Options {
        Options {
            name: program_identifier(name),
            number: program_number(name),
            units: Units::Mm,
            follow_source_units: true,
            limits: Limits::default(),
            hole_tops: Vec::new(),
            peck_clearance: (0.0, 0.0),
            length_at_tool_change: (false, false),
            tools: Vec::new(),
            arc_tolerance: (0.0, 0.0),
            tap_to_clear: (false, false),
            x_diameter: false,
            feed_per_rev_at_start: (false, false),
            lathe_reset_diameter: false,
            feed_mode_ends_css: false,
            css_sets_feed_per_rev: false,
        }
    }
}

/// What the writer says of a tool at its change.
#[derive(Clone, Debug, PartialEq)]
pub struct ToolFact {
    /// Tool number.
    pub number: u32,
    /// Diameter, mm.
    pub diameter: f64,
    /// Corner radius, mm.
    pub corner_radius: Option<f64>,
    /// Kind.
    pub kind: crate::plan::ToolKind,
}

/// The tools of a plan whose facts came from a tool table, for [`Options::tools`]: a
/// comment that names them reads back in every dialect's plan, a table may not be there.
pub fn tool_facts(plan: &crate::plan::ProcessPlan) -> Vec<ToolFact> {
    plan.tools
        .iter()
        .filter(|t| t.source == crate::plan::ToolSource::Table)
        .filter_map(|t| {
            let diameter = t.diameter.filter(|d| *d > 0.0)?;
            Some(ToolFact { number: t.number, diameter, corner_radius: t.corner_radius, kind: t.kind })
        })
        .collect()
}

/// The hole tops of a plan, for [`Options::hole_tops`].
pub fn hole_tops(plan: &crate::plan::ProcessPlan) -> Vec<[f64; 3]> {
    let mut out = Vec::new();
    for f in &plan.features {
        if let crate::plan::FeatureKind::RoundHole { positions, heights, .. } = &f.kind {
            for (k, p) in positions.iter().enumerate() {
                out.push([f.placement[0] + p[0], f.placement[1] + p[1], f.placement[2] + heights.get(k).copied().unwrap_or(0.0)]);
            }
        }
    }
    out
}

/// A machine's limits, in millimetres, mm/min and 1/min; `None` where not known.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Limits {
    /// Highest spindle speed.
    pub max_spindle_speed: Option<f64>,
    /// Highest feed.
    pub max_feed: Option<f64>,
    /// Lowest and highest X, Y, Z.
    pub travel: Option<([f64; 3], [f64; 3])>,
}

/// How far (mm) a position `target` writes may be from the one it was given: half its X
/// format's last digit, in inches or millimetres.
pub fn resolution(target: &crate::dialect::Dialect, inch: bool) -> f64 {
    let Some(f) = target.output.as_ref().and_then(|o| o.formats.iter().find(|f| f.name == "X")) else { return 0.001 };
    let d = if inch { f.inch_decimals } else { f.decimals };
    0.5 * 10f64.powi(-i32::from(d)) * if inch { 25.4 } else { 1.0 } * (1.0 + 1e-6) + 1e-9
}

/// The program number a name states (`O1234` → 1234), else 1.
pub fn program_number(name: &str) -> u32 {
    let digits: String = name.chars().skip_while(|c| !c.is_ascii_digit()).take_while(char::is_ascii_digit).collect();
    digits.parse().ok().filter(|&n| n > 0 && n <= 9999).unwrap_or(1)
}

/// A name every control takes: letters, digits and `_`, upper case, starting with a letter.
pub fn program_identifier(name: &str) -> String {
    let mut s: String = name.chars().map(|c| if c.is_ascii_alphanumeric() { c.to_ascii_uppercase() } else { '_' }).take(24).collect();
    if !s.starts_with(|c: char| c.is_ascii_alphabetic()) {
        s.insert(0, 'P');
    }
    s
}

/// Translates program `text`, read in `from`, into `to`'s dialect, handing the text to
/// `sink` as it is written. Returns the findings of reading and writing. Never fails: a
/// target without output rules gets an error diagnostic and no text.
pub fn translate<'t>(
    text: impl Into<crate::text::Text<'t>>,
    from: &crate::dialect::Dialect,
    to: &crate::dialect::Dialect,
    profile: &crate::interp::Profile,
    opts: Options,
    sink: impl FnMut(&[u8]),
) -> Vec<Diagnostic> {
    translate_with_facts(text, from, to, profile, opts, &mut Vec::new, sink)
}

/// [`translate`], with the hole tops ([`Options::hole_tops`]) asked of `hole_tops` only when
/// a cycle needs them (a G81 written as a cycle that states the surface): a program without
/// such cycles is not analysed twice.
pub fn translate_with_facts<'t>(
    text: impl Into<crate::text::Text<'t>>,
    from: &crate::dialect::Dialect,
    to: &crate::dialect::Dialect,
    profile: &crate::interp::Profile,
    opts: Options,
    hole_tops: &mut dyn FnMut() -> Vec<[f64; 3]>,
    sink: impl FnMut(&[u8]),
) -> Vec<Diagnostic> {
    let Some(out) = &to.output else {
        return vec![Diagnostic::new(
            Code::PostUnwritable,
            Default::default(),
            format!("the dialect `{}` has no <output> rules: ncplan cannot write programs for it", to.name),
        )];
    };
    if let Some(why) = &out.refused {
        return vec![Diagnostic::new(
            Code::PostUnwritable,
            Default::default(),
            format!("ncplan cannot write programs for `{}`: {why}", to.name),
        )];
    }
    let mut opts = opts;
    opts.peck_clearance = (from.behaviour.peck_clearance_mm, to.behaviour.peck_clearance_mm);
    opts.length_at_tool_change = (from.behaviour.tool_change_applies_length, to.behaviour.tool_change_applies_length);
    opts.arc_tolerance = (to.behaviour.arc_tolerance_mm, to.behaviour.arc_tolerance_inch);
    let clear = |d: &crate::dialect::Dialect| d.behaviour.tapping == crate::dialect::TapStyle::Clear;
    opts.tap_to_clear = (clear(from), clear(to));
    opts.x_diameter = to.behaviour.x_diameter;
    opts.lathe_reset_diameter = to.behaviour.lathe_x_diameter && !to.behaviour.x_diameter;
    use crate::dialect::Meaning as M;
    opts.feed_mode_ends_css =
        to.codes.iter().any(|c| matches!(c.meaning, M::FeedPerRev | M::FeedPerMinute) && c.also == Some(M::SpindleRpm));
    opts.css_sets_feed_per_rev =
        to.codes.iter().any(|c| matches!(c.meaning, M::SpindleCss | M::SpindleRpm) && c.also == Some(M::FeedPerRev));
    opts.feed_per_rev_at_start = (from.behaviour.initial_feed_per_rev, to.behaviour.initial_feed_per_rev);
    let mut post = Post::new(out, opts, sink);
    post.tops_source = Some(hole_tops);
    let mut diags = interpret_beside(text.into(), from, profile, &mut post);
    diags.extend(post.finish());
    diags.extend(refusals(&diags));
    diags.sort_by_key(|d| (d.range.start, d.range.end));
    diags
}

/// Safe output: a translation is given out only if every motion of the source is known and
/// written. Each motion the reading could not know (`interp::motion-unknown`: a code whose
/// documented effect moves the machine, kept as intent) refuses the translation at its
/// place, as an error the caller does not write past.
/// A program called but not found (`flow::missing-program`, even where the control may hold
/// it) is such a motion too: its moves are dropped, and the block after the call would be
/// written as if the position had not changed. An error of the reading refuses the
/// translation at the first one (`post::source-error`): past it, the reading is not the
/// control's. So does a maker's own finding read as a warning on a guessed dialect: the
/// source maker's control stops there.
fn refusals(diags: &[Diagnostic]) -> Vec<Diagnostic> {
    let mut out: Vec<Diagnostic> = diags
        .iter()
        .filter(|d| matches!(d.code, Code::MotionUnknown | Code::MissingProgram))
        .map(|d| {
            let msg = format!("the translation is refused: {}; written without it, the program would move elsewhere", d.message);
            Diagnostic::new(Code::PostMotionUnknown, d.range, msg)
        })
        .collect();
    // A maker's own finding kept as a warning on a guessed dialect ([`Code::maker_specific`])
    // still refuses: the source maker's control stops there, and the target's may too.
    let source_error = |d: &&Diagnostic| {
        (d.is_error() || d.code.maker_specific()) && !d.code.as_str().starts_with("post::") && d.code != Code::MissingProgram
    };
    if let Some(first) = diags.iter().filter(source_error).min_by_key(|d| (d.range.start, d.range.end)) {
        let msg = format!(
            "the translation is refused: the program has an error here ({}: {}); past it the reading is not the control's, so nothing is written",
            first.code.as_str(),
            first.message
        );
        out.push(Diagnostic::new(Code::PostSourceError, first.range, msg));
    }
    out
}

/// Ops handed from the reading thread to the writing one at a time.
const BATCH: usize = 2048;
/// Batches under way at once: what the reader may run ahead of the writer.
const BATCHES: usize = 4;

/// Interprets `text` into `post` as [`crate::interp::interpret`] does, with the reading on a
/// thread of its own: the interpreter sends its ops in batches, in order, through a bounded
/// channel, and `post` takes each batch on this thread ([`Post::emit_all`], the ops read
/// where they lie) while the next is read. The ops, and so the text written, are the same
/// as a serial run's; memory holds at most a few batches.
fn interpret_beside<F: FnMut(&[u8])>(
    text: crate::text::Text<'_>,
    from: &crate::dialect::Dialect,
    profile: &crate::interp::Profile,
    post: &mut Post<'_, F>,
) -> Vec<Diagnostic> {
    use std::sync::mpsc;
    let (full, filled) = mpsc::sync_channel::<Vec<Canon>>(BATCHES);
    let (empty, emptied) = mpsc::channel::<Vec<Canon>>();
    std::thread::scope(|scope| {
        let reader = scope.spawn(move || {
            let mut batcher = Batcher { batch: Vec::with_capacity(BATCH), full, emptied };
            let diags = crate::interp::interpret(text, from, profile, &mut batcher);
            let last = std::mem::take(&mut batcher.batch);
            if !last.is_empty() {
                let _ = batcher.full.send(last);
            }
            diags
        });
        for mut batch in filled {
            post.emit_all(&batch);
            // The emptied batch goes back to the reader, which refills it without allocating.
            batch.clear();
            let _ = empty.send(batch);
        }
        reader.join().unwrap_or_else(|e| std::panic::resume_unwind(e))
    })
}

/// The reading thread's sink: collects ops into batches and sends each full one.
struct Batcher {
    batch: Vec<Canon>,
    full: std::sync::mpsc::SyncSender<Vec<Canon>>,
    emptied: std::sync::mpsc::Receiver<Vec<Canon>>,
}

impl CanonSink for Batcher {
    fn emit(&mut self, canon: Canon) {
        self.batch.push(canon);
        if self.batch.len() >= BATCH {
            self.send();
        }
    }
}

impl Batcher {
    /// Sends the full batch on, and takes an emptied one back (or a new one) to fill. Out of
    /// line: `emit` is then a push and a test, with nothing to save around them.
    #[cold]
    #[inline(never)]
    fn send(&mut self) {
        let next = self.emptied.try_recv().unwrap_or_else(|_| Vec::with_capacity(BATCH));
        let batch = std::mem::replace(&mut self.batch, next);
        // The writer gone (it panicked): the panic comes out of the join.
        let _ = self.full.send(batch);
    }
}

const FLUSH_AT: usize = 64 * 1024;
const NVALUES: usize = Value::MachineC as usize + 1;
const EPS: f64 = 1e-9;

/// Values for one event's template: numbers (NaN when absent) and texts.
struct Vals {
    num: [f64; NVALUES],
    text: Option<String>,
}

impl Vals {
    fn new() -> Vals {
        Vals { num: [f64::NAN; NVALUES], text: None }
    }

    fn set(&mut self, v: Value, x: f64) -> &mut Vals {
        self.num[v as usize] = x;
        self
    }
}

/// The writer. Feed it with [`CanonSink::emit`], then call [`Post::finish`].
pub struct Post<'a, F: FnMut(&[u8])> {
    out: &'a Output,
    /// Where the hole tops come from when a cycle first needs them.
    tops_source: Option<&'a mut dyn FnMut() -> Vec<[f64; 3]>>,
    opts: Options,
    sink: F,
    buf: Vec<u8>,
    diags: Vec<Diagnostic>,
    noted: BTreeSet<String>,
    /// The milling cycle about to begin makes a hole (`Setting::HoleMilled` came first).
    hole_milled: bool,
    started: bool,
    ended: bool,
    block: u64,
    /// Millimetres → target units, times source units → millimetres.
    scale: f64,
    g92: [f64; 3],
    plane: Plane,
    wcs: Option<u16>,
    feed_mode: FeedMode,
    /// The machine position (target units, work offset frame).
    pos: [f64; 3],
    /// The tilted working plane written (in output units), `None` while untilted.
    tilt: Option<crate::canon::Frame>,
    /// Whether tool centre point control is written on (`tcp-on`): the rotary axes written
    /// then turn the tool as in the source.
    tcp: bool,
    /// A tool axis the source turned to under tool centre point control, or by indexing its
    /// rotary axes without it, to be checked against the rotary axes of the next move written
    /// (the steady lane waits for it).
    axis_check: Option<[f64; 3]>,
    /// Whether the source has tool centre point control on (whatever the target writes).
    source_tcp: bool,
    /// The source's tool axis in force (its last `ToolAxis` marker).
    source_axis: [f64; 3],
    /// The axes whose position the source knows (bit `k`: X Y Z A B C, [`CanonOp::Known`]):
    /// the others are never written (a word counted from an assumed 0), and a move that
    /// changes one is refused (`post::unknown-start`).
    known: u8,
    /// The last written text of the modal values X, Y, Z, F, S, A, B, C, by its key, and a
    /// number known to be written so (NaN: none): that number again is left out at once.
    written: [Option<(Key, f64)>; 8],
    /// For each modal slot, the number [`Post::written`] knows to be written so, for the check
    /// of an unchanged word (NaN: none); the ninth never matches ([`NO_SLOT`]).
    last: [f64; 9],
    /// The format [`Post::last`]'s number is written in (`u32::MAX`: none): the numbers and
    /// their formats apart, so that the steady lane compares all its slots at once.
    last_fi: [u32; 9],
    motion: Option<String>,
    mods: Vec<(String, String)>,
    tool: u32,
    tool_names: Vec<(u32, String)>,
    pending_tool: Option<u32>,
    speed: f64,
    speed_dirty: bool,
    spindle_on: bool,
    feed: f64,
    coolant: bool,
    /// The length offset in force; `u32::MAX` until the source states one, so that a
    /// cancel the source says (`G49`, read by the plan as "none") is said in the target too.
    length: u32,
    /// The source cut with its length offset cancelled, which the target's tool change puts
    /// in force and the target cannot cancel: said at the first cut.
    length_unsaid: bool,
    comp_d: u32,
    comp: Option<(bool, Option<u32>)>,
    pending_move: Option<Canon>,
    /// A change of work offset not yet written, with the plane selected after it on its line:
    /// the program end's own resets (LinuxCNC's M2 puts G54 and G17 back) are the source
    /// control's behaviour, not statements of the program, and the target's end does its
    /// own; written as soon as anything else follows them.
    held: Vec<Canon>,
    /// A move in the machine's frame under way ([`machine`]).
    machine: Option<machine::PendingMachine>,
    optional_line: Option<u32>,
    line: u32,
    origin: crate::text::TextRange,
    /// The cycle being drilled as a cycle (its moves are not written).
    in_cycle: bool,
    active: Option<ActiveCycle>,
    /// Modal values of the block being rendered, written once the block is.
    staged: [(Key, f64); 8],
    /// The slots staged, one bit each.
    staged_mask: u8,
    /// The text of the block number written last ([`Post::push_block_number`]): its digits
    /// (room for 20, and 16 bytes after them for [`append_tail`]), their count, the number.
    number_text: ([u8; 36], usize, u64),
    /// The values of a straight move, kept for the next (see [`Post::straight`]).
    move_vals: Option<Box<Vals>>,
    /// The `rapid` and `feed` templates.
    moves: (Option<&'a Template>, Option<&'a Template>),
    /// The templates' layouts, by the template's address (and whether it renders a move),
    /// made at their first use; `None` while in use.
    layouts: Vec<(usize, bool, Option<Layout>)>,
    /// The largest rounding of a written position (target units), and where it first
    /// passed [`ROUNDED_NOTE`].
    rounded: f64,
    rounded_at: Option<crate::text::TextRange>,
    /// The same for a written feed (target units per minute or revolution): an inch
    /// program's four decimals cannot state every millimetre feed.
    rounded_feed: f64,
    rounded_feed_at: Option<crate::text::TextRange>,
    /// The advance per spindle revolution of the moves in a spindle-synchronised run (target
    /// units).
    sync: Option<f64>,
    /// Whether constant surface speed is in force.
    css: bool,
    /// The spindle speed limit constant surface speed was put in force with.
    css_limit: Option<f64>,
    /// Whether X words are written as diameters (twice the canonical radius): from the start
    /// on a target that reads them so (`Options::x_diameter`), or after its `diameter-on`.
    x_diam: bool,
    /// Whether the source said it turns (a diameter or radius mode, a lathe cycle, the ZX
    /// plane before its first move), and whether a move was written yet: a target that reads
    /// X as diameters takes no program that does not turn.
    turns: bool,
    moved_yet: bool,
    /// Whether the X words' reading was stated (a diameter or radius mode written).
    x_told: bool,
    /// Where each source line's text begins in `buf` (since the last hand-over): a run the
    /// program repeats is found there.
    line_offsets: Vec<(u32, usize, u64)>,
    /// The run of blocks being repeated, while each pass writes the same text.
    repeat: Option<Repeat>,
    /// Runs written as the target's loop so far.
    loops: u32,
    /// Runs written as subprograms, written after the program's end: the subprogram's
    /// number, its text and the block number that text starts at.
    subs: Vec<(u32, Vec<u8>, u64)>,
    /// The source lines that have run, one bit each.
    seen: Vec<u64>,
    /// The values of the work offset in force, and of each offset as the first move in it
    /// found them: the translation is written in that frame, so values the program changes
    /// after it moved in the offset (G10 L2/L20 while active) cannot be followed.
    wcs_now: [f64; 6],
    wcs_values: Vec<(u16, [f64; 6])>,
    /// Whether the offset in force and its values were checked since they last changed
    /// ([`Post::check_work_offset`] has nothing new to find until they change).
    wcs_checked: bool,
    /// The rotary axes where the moves so far left them (degrees).
    abc: [f64; 3],
    /// The `rapid` and `feed` templates as the steady lane writes them ([`lane`]).
    lanes: Option<Box<[Lane; 2]>>,
    /// Whether the steady lane takes the next rapid (bit 0) or feed (bit 1): the writer is
    /// in the steady state ([`Post::refresh_lane`]).
    lane_ready: u8,
    /// The longest block the target takes (`usize::MAX`: any), for [`Post::line_end`].
    max_line: usize,
    /// Where the steady lane puts a block's text together before it appends it at once
    /// ([`Post::lane_block`]).
    lane_text: [u8; lane::LANE_TEXT],
}

/// A run of blocks the source runs again, kept as one pass while the passes write the same.
struct Repeat {
    /// The source line the run starts at.
    first: u32,
    /// Its source lines.
    lines: (u32, u32),
    /// Where its first pass begins and ends in `buf`.
    start: usize,
    end: usize,
    /// Passes that wrote the same text.
    count: u32,
    /// Whether the first pass, which differed, was left written before the loop.
    shifted: bool,
    /// The block numbers the first pass starts and ends at (the next one after it).
    block_start: u64,
    block_end: u64,
    origin: crate::text::TextRange,
}

/// A modal word's text: number format `fi` (with its inch decimals or not) applied to the
/// rounded number `n` ([`round`]). One format writes distinct numbers as distinct texts, so
/// an unchanged word is told by its key, without writing or comparing text.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Key {
    fi: u32,
    inch: bool,
    n: i64,
}

/// A repeated run is given up (written unrolled) past this much text.
const REPEAT_MAX: usize = 4 << 20;

/// A position rounded by more than this (mm) is said in a note: the diff's tolerance.
const ROUNDED_NOTE: f64 = crate::diff::TOLERANCE;

/// How far an arc's rounded centre moves its path, per unit of the centre's rounding: by up
/// to 2√2 times it, through the start that stays ([`Class::Centre`]).
const CENTRE_FACTOR: f64 = 2.0 * std::f64::consts::SQRT_2;

fn modal_slot(v: Value) -> Option<usize> {
    match v {
        Value::X => Some(0),
        Value::Y => Some(1),
        Value::Z => Some(2),
        Value::F => Some(3),
        Value::S => Some(4),
        Value::A => Some(5),
        Value::B => Some(6),
        Value::C => Some(7),
        _ => None,
    }
}

const POW10: [u64; 20] = {
    let mut t = [1u64; 20];
    let mut i = 1;
    while i < 20 {
        t[i] = t[i - 1] * 10;
        i += 1;
    }
    t
};

/// Writes `v` in format `f` (address included) onto `out`; returns how far the written
/// number is from `v`. Formats into a stack buffer: no allocation, one append.
pub fn format_number(out: &mut String, f: &NumberFormat, v: f64, inch: bool) -> f64 {
    let (n, err) = round(f, v, inch);
    let mut b = Vec::with_capacity(f.address.len() + 40);
    push_number(&mut b, f, n, inch);
    // Only the address's text and ASCII digits: always UTF-8.
    out.push_str(&String::from_utf8_lossy(&b));
    err
}

/// The decimals `f` writes (in an inch program or not).
fn decimals(f: &NumberFormat, inch: bool) -> usize {
    if f.point == Point::Never && !f.increment {
        0
    } else if inch {
        f.inch_decimals as usize
    } else {
        f.decimals as usize
    }
    .min(15)
}

/// `v` rounded for format `f`: the integer count of its last decimal's steps (half away from
/// zero), which the text is written from, and how far that is from `v`.
fn round(f: &NumberFormat, v: f64, inch: bool) -> (i64, f64) {
    let p = POW10F[decimals(f, inch)];
    let n = round_scaled(v * p);
    (n, (n as f64 / p - v).abs())
}

/// A scaled number rounded half away from zero, by truncation (no libm call).
#[inline]
fn round_scaled(x: f64) -> i64 {
    if x >= 0.0 { (x + 0.5) as i64 } else { (x - 0.5) as i64 }
}

/// 10^k as a float (exact: below 2^53), for the scaling by the decimals [`decimals`] gives.
const POW10F: [f64; 16] = [1.0, 1e1, 1e2, 1e3, 1e4, 1e5, 1e6, 1e7, 1e8, 1e9, 1e10, 1e11, 1e12, 1e13, 1e14, 1e15];

/// 10^-k, for [`below`].
const INV_POW10: [f64; 16] = [1.0, 1e-1, 1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7, 1e-8, 1e-9, 1e-10, 1e-11, 1e-12, 1e-13, 1e-14, 1e-15];

/// Whether the error [`round`] gives for `v` (scaled by 10^`d` to `scaled`, rounded to `n`)
/// is surely not above `kept`, told without a division: |n − scaled| / 10^d with a margin
/// far above the rounding of either computation (a few units in the last place of `v`).
#[inline]
fn below(n: i64, scaled: f64, v: f64, d: usize, kept: f64) -> bool {
    // `d` is 15 at most ([`decimals`]): the mask spares the bounds check.
    below_by(n, scaled, v, INV_POW10[d & 15], kept)
}

/// [`below`] with 10^-d given (`inv`).
#[inline(always)]
fn below_by(n: i64, scaled: f64, v: f64, inv: f64, kept: f64) -> bool {
    (n as f64 - scaled).abs() * inv + 1e-12 * (v.abs() + 1.0) < kept
}

/// The two-digit numbers `00` to `99`, for writing digits two at a time.
const DIGITS2: [u8; 200] = {
    let mut t = [0u8; 200];
    let mut i = 0;
    while i < 100 {
        t[2 * i] = b'0' + (i / 10) as u8;
        t[2 * i + 1] = b'0' + (i % 10) as u8;
        i += 1;
    }
    t
};

/// For each fraction 0 to 999 of a three-decimal number: the point and its three digits (the
/// point in the lowest byte), and above them how many of the four are left without the
/// digits' trailing zeros (none for 0, not even the point).
const FRAC3: [u64; 1000] = {
    let mut t = [0u64; 1000];
    let mut i = 0;
    while i < 1000 {
        let d = [b'0' + (i / 100) as u8, b'0' + (i / 10 % 10) as u8, b'0' + (i % 10) as u8];
        let len = if i == 0 {
            0
        } else if i % 100 == 0 {
            2
        } else if i % 10 == 0 {
            3
        } else {
            4
        };
        t[i] = u64::from_le_bytes([b'.', d[0], d[1], d[2], len, 0, 0, 0]);
        i += 1;
    }
    t
};

/// For each whole number 0 to 999: its digits without leading zeros (the first in the lowest
/// byte), and in the highest byte their count.
const INT3: [u32; 1000] = {
    let mut t = [0u32; 1000];
    let mut i = 0;
    while i < 1000 {
        let (a, b, c) = (b'0' + (i / 100) as u8, b'0' + (i / 10 % 10) as u8, b'0' + (i % 10) as u8);
        t[i] = u32::from_le_bytes(if i >= 100 {
            [a, b, c, 3]
        } else if i >= 10 {
            [b, c, 0, 2]
        } else {
            [c, 0, 0, 1]
        });
        i += 1;
    }
    t
};

/// The usual number format, three decimals after a short address, with what writing it
/// needs at hand ([`ThreeDecimals::push`]): made once per format by the writer's steady lane,
/// on the spot by [`push_number`].
#[derive(Clone, Copy, Debug, Default)]
struct ThreeDecimals {
    /// What goes before the digits, for a number not below zero and for one below: the
    /// address and the sign (`X`, `X-`; `X+`, `X-` where the format writes a plus), 8 bytes
    /// at most (the first in the lowest byte), and their length in bytes. The steady lane puts
    /// the separator before them, for a word written after another ([`ThreeDecimals::after`]).
    prefix: [(u64, usize); 2],
    trailing_zeros: bool,
    leading_zero: bool,
    /// The fewest bytes of the point and its digits written: 4 where the format keeps
    /// trailing zeros, 1 (the point) where it always writes the point, else none.
    least_fraction: u64,
}

impl ThreeDecimals {
    /// Format `f` as such, if its address is short and it is no least-increment format.
    #[inline]
    fn of(f: &NumberFormat) -> Option<ThreeDecimals> {
        Self::after(f, b"")
    }

    /// [`ThreeDecimals::of`] with `sep` written before the address, if both together are short.
    fn after(f: &NumberFormat, sep: &[u8]) -> Option<ThreeDecimals> {
        if f.increment || f.digits > 0 {
            return None;
        }
        let prefix = |sign: &[u8]| {
            let mut bytes = [0u8; 8];
            let mut len = 0;
            for part in [sep, f.address.as_bytes(), sign] {
                bytes.get_mut(len..len + part.len())?.copy_from_slice(part);
                len += part.len();
            }
            Some((u64::from_le_bytes(bytes), len))
        };
        Some(ThreeDecimals {
            prefix: [prefix(if f.plus { b"+" } else { b"" })?, prefix(b"-")?],
            trailing_zeros: f.trailing_zeros,
            leading_zero: f.leading_zero,
            least_fraction: if f.trailing_zeros { 4 } else { u64::from(f.point == Point::Always) },
        })
    }

    /// The text [`ThreeDecimals::push`] writes for `n` (in thousandths), in two words (the
    /// first byte lowest), each with its length in bytes: the address and sign, and the
    /// number (7 bytes at most), put together from the tables [`INT3`] and [`FRAC3`]; none for
    /// a million thousandths or more, left to the general way. The bytes of either word past
    /// its length are not the text's.
    #[inline(always)]
    fn parts(&self, n: i64) -> Option<(u64, usize, u64, usize)> {
        let a = n.unsigned_abs();
        if a >= 1_000_000 {
            return None;
        }
        let (whole, frac) = ((a / 1000) as usize, (a % 1000) as usize);
        let fr = FRAC3[frac];
        // The fraction written: all of the point and its digits where the format keeps
        // trailing zeros (4 is the most the table says), else those left, or the point alone
        // where it is always written.
        let no_digits = frac == 0 && !self.trailing_zeros;
        let flen = (fr >> 32).max(self.least_fraction);
        // Three digits, point, three digits: 7 bytes at most, put together in a word (the
        // first byte lowest), `k` bits of it written so far.
        let mut v = 0u64;
        let mut k = 0;
        // `.5`: no digit before the point.
        if whole != 0 || self.leading_zero || no_digits {
            let w = INT3[whole];
            v = u64::from(w & 0xff_ffff);
            k = 8 * u64::from(w >> 24);
        }
        // At most 24 bits so far: the point and three digits fit.
        v |= (fr & 0xffff_ffff) << k;
        k += 8 * flen;
        let (prefix, len) = self.prefix[usize::from(n < 0)];
        Some((prefix, len, v, k as usize / 8))
    }

    /// [`push_number`] of `n` (in thousandths) onto `out` ([`ThreeDecimals::parts`]); false
    /// for a million thousandths or more, left to the general way.
    #[inline(always)]
    fn push(&self, out: &mut Vec<u8>, n: i64) -> bool {
        let Some((prefix, plen, v, vlen)) = self.parts(n) else { return false };
        // The address and sign, then the number: 16 bytes written at once, taken back to
        // their length.
        let text = u128::from(prefix) | u128::from(v) << (8 * plen);
        let len = out.len();
        out.extend_from_slice(&text.to_le_bytes());
        out.truncate(len + plen + vlen);
        true
    }
}

/// `a` split at `decimals` decimal digits: the whole part and the fraction's digits. The
/// usual counts divide by a constant (a multiplication, no divide instruction).
fn split_decimals(a: u64, decimals: usize) -> (u64, u64) {
    match decimals {
        1 => (a / 10, a % 10),
        2 => (a / 100, a % 100),
        3 => (a / 1000, a % 1000),
        4 => (a / 10_000, a % 10_000),
        5 => (a / 100_000, a % 100_000),
        6 => (a / 1_000_000, a % 1_000_000),
        d => (a / POW10[d], a % POW10[d]),
    }
}

/// The text of the rounded number `n` (from [`round`]) in format `f`, address included, by
/// integer arithmetic: the characters are put into a stack buffer from the right, two digits
/// at a time, and appended at once. One format writes distinct numbers as distinct texts.
fn push_number(out: &mut Vec<u8>, f: &NumberFormat, n: i64, inch: bool) {
    push_number_in(out, f, n, decimals(f, inch));
}

/// [`push_number`] with the format's decimals for the units in force, [`decimals`].
#[inline]
fn push_number_in(out: &mut Vec<u8>, f: &NumberFormat, n: i64, decimals: usize) {
    if decimals == 3 && ThreeDecimals::of(f).is_some_and(|t| t.push(out, n)) {
        return;
    }
    // An address too long for the buffer goes first on its own.
    if f.address.len() > 8 {
        out.extend_from_slice(f.address.as_bytes());
    }
    let mut b = [0u8; 64];
    let i = number_text(&mut b, f, n, decimals);
    append_tail(out, &b, i, 48);
}

/// The text of [`push_number_in`] put together in `b` from the right, ending at 48 (the 16
/// bytes after it let a short text be copied as a fixed 16, [`append_tail`]); where it
/// starts. The address is in it when it is 8 bytes or shorter; a longer one is the caller's
/// to write first.
fn number_text(b: &mut [u8; 64], f: &NumberFormat, n: i64, decimals: usize) -> usize {
    // A sign, 20 digits, a point and 15 decimals at most, and the short address.
    let mut i = 48;
    let mut int = n.unsigned_abs();
    let mut whole = true;
    if f.increment || decimals == 0 {
        if !f.increment && f.point == Point::Always {
            i -= 1;
            b[i] = b'.';
        }
    } else {
        let (q, mut frac) = split_decimals(int, decimals);
        int = q;
        // The fraction's digits, without trailing zeros unless the format keeps them.
        let mut flen = decimals;
        if !f.trailing_zeros {
            if frac == 0 {
                flen = 0;
            } else {
                while frac % 10 == 0 {
                    frac /= 10;
                    flen -= 1;
                }
            }
        }
        let mut k = flen;
        while k >= 2 {
            let d = (frac % 100) as usize * 2;
            frac /= 100;
            i -= 2;
            b[i..i + 2].copy_from_slice(&DIGITS2[d..d + 2]);
            k -= 2;
        }
        if k == 1 {
            i -= 1;
            b[i] = b'0' + frac as u8;
        }
        if flen > 0 || f.point == Point::Always {
            i -= 1;
            b[i] = b'.';
        }
        // `.5`: no digit before the point.
        whole = int != 0 || f.leading_zero || flen == 0;
    }
    if whole {
        while int >= 100 {
            let d = (int % 100) as usize * 2;
            int /= 100;
            i -= 2;
            b[i..i + 2].copy_from_slice(&DIGITS2[d..d + 2]);
        }
        if int >= 10 {
            let d = int as usize * 2;
            i -= 2;
            b[i..i + 2].copy_from_slice(&DIGITS2[d..d + 2]);
        } else {
            i -= 1;
            b[i] = b'0' + int as u8;
        }
    }
    // Zero-padded to the fewest digits the format writes before the point (`T0101`).
    if f.digits > 0 {
        let point = b[i..48].iter().position(|c| *c == b'.').unwrap_or(48 - i);
        for _ in point..usize::from(f.digits) {
            i -= 1;
            b[i] = b'0';
        }
    }
    if n < 0 {
        i -= 1;
        b[i] = b'-';
    } else if f.plus {
        i -= 1;
        b[i] = b'+';
    }
    // The address goes before it in the same buffer: one append.
    let address = f.address.as_bytes();
    if address.len() <= 8 {
        i -= address.len();
        b[i..i + address.len()].copy_from_slice(address);
    }
    i
}

/// Appends `b[i..end]`; a text of 16 bytes or less as a copy of a fixed 16 taken back to its
/// length (no call to copy: most numbers are short). `b` has 16 bytes after `end`.
#[inline]
fn append_tail(out: &mut Vec<u8>, b: &[u8], i: usize, end: usize) {
    if end - i <= 16 {
        let at = out.len();
        out.extend_from_slice(&b[i..i + 16]);
        out.truncate(at + end - i);
    } else {
        out.extend_from_slice(&b[i..end]);
    }
}

/// Appends motion code `c` after the separator `sep` (none at the block's `body` start); an
/// empty code writes nothing.
#[inline]
fn push_code(buf: &mut Vec<u8>, body: usize, sep: &[u8], c: &str) {
    if !c.is_empty() {
        if buf.len() > body {
            append(buf, sep);
        }
        buf.extend_from_slice(c.as_bytes());
    }
}

/// Appends `s`; a single byte (a separator) or nothing without a call to copy.
#[inline]
fn append(buf: &mut Vec<u8>, s: &[u8]) {
    match s {
        [] => {}
        [c] => buf.push(*c),
        _ => buf.extend_from_slice(s),
    }
}

/// Whether a block (without number: `raw`; of a tool change or not) gets a block number.
#[inline]
fn numbered(out: &Output, raw: bool, tool_change: bool) -> bool {
    match out.numbered {
        Numbered::All => !raw,
        Numbered::ToolChange => tool_change && !raw,
        Numbered::None => false,
    }
}

/// Appends the decimal digits of `n` without allocating: written straight into `out`
/// ([`write_u64`]).
fn push_u64(out: &mut Vec<u8>, n: u64) {
    let at = out.len();
    out.extend_from_slice(&[b'0'; 20]);
    let len = write_u64(&mut out[at..], n);
    out.truncate(at + len);
}

/// Writes the decimal digits of `n` at the start of `digits` (20 bytes at least): their count
/// first, then the digits two at a time from the right; returns the count.
fn write_u64(digits: &mut [u8], mut n: u64) -> usize {
    let len = n.checked_ilog10().map_or(1, |k| k as usize + 1);
    let digits = &mut digits[..len];
    let mut i = len;
    while i >= 2 {
        let d = (n % 100) as usize * 2;
        n /= 100;
        i -= 2;
        digits[i..i + 2].copy_from_slice(&DIGITS2[d..d + 2]);
    }
    if i == 1 {
        digits[0] = b'0' + n as u8;
    }
    len
}

/// Adds `delta` to the decimal number written in `digits`, in place, from its last digit
/// (the block numbers' step: a digit or two); false, the digits spoilt, when the sum has
/// more digits.
fn count_on(digits: &mut [u8], mut delta: u64) -> bool {
    let mut i = digits.len();
    while delta != 0 {
        if i == 0 {
            return false;
        }
        i -= 1;
        let d = u64::from(digits[i] - b'0') + delta % 10;
        delta /= 10;
        if d >= 10 {
            digits[i] = b'0' + (d - 10) as u8;
            delta += 1;
        } else {
            digits[i] = b'0' + d as u8;
        }
    }
    true
}

impl<'a, F: FnMut(&[u8])> Post<'a, F> {
    /// A writer by the rules `out`, handing text to `sink` as it grows.
    pub fn new(out: &'a Output, opts: Options, sink: F) -> Post<'a, F> {
        let x_diam = opts.x_diameter;
        let feed_mode = if opts.feed_per_rev_at_start == (true, true) { FeedMode::PerRevolution } else { FeedMode::PerMinute };
        Post {
            out,
            tops_source: None,
            opts,
            sink,
            buf: Vec::with_capacity(FLUSH_AT + 4096),
            diags: Vec::new(),
            noted: BTreeSet::new(),
            hole_milled: false,
            started: false,
            ended: false,
            block: 0,
            scale: 1.0,
            g92: [0.0; 3],
            plane: Plane::Xy,
            wcs: None,
            feed_mode,
            pos: [0.0; 3],
            tilt: None,
            tcp: false,
            axis_check: None,
            source_tcp: false,
            source_axis: [0.0, 0.0, 1.0],
            known: 0,
            written: Default::default(),
            last: [f64::NAN; 9],
            last_fi: [u32::MAX; 9],
            motion: None,
            mods: Vec::new(),
            tool: 0,
            tool_names: Vec::new(),
            pending_tool: None,
            speed: 0.0,
            speed_dirty: false,
            spindle_on: false,
            feed: 0.0,
            coolant: false,
            length: u32::MAX,
            length_unsaid: false,
            comp_d: 0,
            comp: None,
            pending_move: None,
            held: Vec::new(),
            machine: None,
            optional_line: None,
            line: 0,
            origin: Default::default(),
            in_cycle: false,
            active: None,
            staged: [(Key { fi: 0, inch: false, n: 0 }, 0.0); 8],
            staged_mask: 0,
            layouts: Vec::new(),
            number_text: ([b'0'; 36], 1, 0),
            move_vals: None,
            moves: (out.template("rapid").map(|(t, _)| t), out.template("feed").map(|(t, _)| t)),
            rounded: 0.0,
            rounded_at: None,
            rounded_feed: 0.0,
            rounded_feed_at: None,
            sync: None,
            css: false,
            css_limit: None,
            x_diam,
            turns: false,
            moved_yet: false,
            x_told: false,
            line_offsets: Vec::new(),
            repeat: None,
            loops: 0,
            subs: Vec::new(),
            seen: Vec::new(),
            wcs_now: [0.0; 6],
            wcs_values: Vec::new(),
            wcs_checked: false,
            abc: [0.0; 3],
            lanes: Some(Lane::pair(out)),
            lane_ready: 0,
            max_line: if out.max_line > 0 { out.max_line } else { usize::MAX },
            lane_text: [0; lane::LANE_TEXT],
        }
    }

    fn note(&mut self, code: Code, canon: &Canon, key: &str, msg: impl Into<String>) {
        if self.noted.insert(key.to_owned()) {
            self.diags.push(Diagnostic::new(code, canon.origin, msg));
        }
    }

    /// The key of `v` written in the format named `name`, if there is one.
    fn key_of(&self, name: &str, v: f64) -> Option<(Key, f64)> {
        let inch = self.opts.units == Units::Inch;
        let fi = self.out.formats.iter().position(|x| x.name == name)?;
        Some((Key { fi: fi as u32, inch, n: round(&self.out.formats[fi], v, inch).0 }, v))
    }

    /// Sets what modal slot `k` has written.
    fn set_written(&mut self, k: usize, w: Option<(Key, f64)>) {
        self.written[k] = w;
        let inch = self.opts.units == Units::Inch;
        (self.last[k], self.last_fi[k]) = match w {
            Some((key, v)) if key.inch == inch => (v, key.fi),
            _ => (f64::NAN, u32::MAX),
        };
    }

    /// Whether two modal words' texts are the same.
    #[inline]
    fn same_text(&self, a: Key, b: Key) -> bool {
        if a.fi == b.fi && a.inch == b.inch {
            return a.n == b.n;
        }
        self.same_text_apart(a, b)
    }

    /// [`Post::same_text`] of two formats or units: the texts compared.
    #[inline(never)]
    fn same_text_apart(&self, a: Key, b: Key) -> bool {
        let (mut x, mut y) = (Vec::new(), Vec::new());
        push_number(&mut x, &self.out.formats[a.fi as usize], a.n, a.inch);
        push_number(&mut y, &self.out.formats[b.fi as usize], b.n, b.inch);
        x == y
    }

    fn to_out(&self, v: f64) -> f64 {
        v * self.scale
    }

    fn point(&self, p: &[f64]) -> [f64; 3] {
        [self.to_out(p[0]) + self.g92[0], self.to_out(p[1]) + self.g92[1], self.to_out(p[2]) + self.g92[2]]
    }

    fn start(&mut self) {
        if self.started {
            return;
        }
        self.started = true;
        self.block = self.out.number_start;
        // The tool starts where the machine was, not at the program zero the interpreter
        // counts from: nothing is written of any axis, and each axis the source states is
        // written at its first move whatever its number (`Post::know`).
        let units = match self.opts.units {
            Units::Mm => "units-mm",
            Units::Inch => "units-inch",
        };
        for ev in ["header", "safe-start", units] {
            self.event(ev, &mut Vals::new());
        }
        // A target that starts in feed per revolution (a lathe) is told the mode the
        // source starts in, whatever a previous program left.
        if self.opts.feed_per_rev_at_start.1 {
            let ev = if self.feed_mode == FeedMode::PerMinute { "feed-per-minute" } else { "feed-per-rev" };
            self.event(ev, &mut Vals::new());
        }
    }

    /// Renders `event`'s template (and the rules around it); false when it has none.
    fn event(&mut self, event: &str, vals: &mut Vals) -> bool {
        let out = self.out;
        // A number its address does not take (`<format min max>`): the event is unwritable.
        if out.template(event).is_some_and(|(t, _)| !out.fits(t, |v| vals.num[v as usize])) {
            return false;
        }
        self.rules(event, true);
        let found = match out.template(event) {
            Some((t, true)) => {
                let mut text = String::new();
                for b in &t.0 {
                    for w in &b.words {
                        let mut s = Vec::new();
                        if self.word(w, vals, &mut s, &mut 0) {
                            if !text.is_empty() {
                                text.push_str(&out.separator);
                            }
                            // The words' texts and ASCII numbers: UTF-8.
                            text.push_str(&String::from_utf8_lossy(&s));
                        }
                    }
                }
                // A later word of the same kind replaces the one still waiting (G49 then G43 H1).
                let group = event.split('-').next().unwrap_or(event).to_owned();
                self.mods.retain(|(g, _)| *g != group);
                if !text.is_empty() {
                    self.mods.push((group, text));
                }
                true
            }
            Some((t, false)) => {
                self.render(t, vals, event == "tool-change", false);
                true
            }
            None => false,
        };
        self.rules(event, false);
        found
    }

    /// Writes the blocks of the rules that hold at `event`, before or after its own.
    #[inline]
    fn rules(&mut self, event: &str, before: bool) {
        // Most targets have none: no call for every move.
        if !self.out.rules.is_empty() {
            self.rules_at(event, before);
        }
    }

    fn rules_at(&mut self, event: &str, before: bool) {
        let out = self.out;
        for r in &out.rules {
            if self.holds(&r.when, event) {
                let t = if before { &r.before } else { &r.after };
                self.render(t, &mut Vals::new(), false, false);
            }
        }
    }

    fn holds(&self, e: &Expr, event: &str) -> bool {
        match e {
            Expr::Event(n) => n == event,
            Expr::Compare(var, op, n) => {
                let v = match var {
                    StateVar::Tool => f64::from(self.tool),
                    StateVar::Speed => self.speed,
                    StateVar::Feed => self.feed,
                    StateVar::Block => self.block as f64,
                };
                match op {
                    Cmp::Eq => (v - n).abs() < EPS,
                    Cmp::Ne => (v - n).abs() >= EPS,
                    Cmp::Lt => v < *n,
                    Cmp::Le => v <= *n,
                    Cmp::Gt => v > *n,
                    Cmp::Ge => v >= *n,
                }
            }
            Expr::And(a, b) => self.holds(a, event) && self.holds(b, event),
            Expr::Or(a, b) => self.holds(a, event) || self.holds(b, event),
            Expr::Not(a) => !self.holds(a, event),
        }
    }

    /// The rounded number ([`round`]) to write for placeholder `value` with `x` in format
    /// `fi`, or `None` when it is left out: a modal value (`slot`, `modal`) whose text is
    /// unchanged. Keeps the largest rounding, stages modal values and counts the moving ones
    /// in `moved`.
    #[inline(always)]
    fn number(&mut self, num: Num, x: f64, d: usize, moved: &mut u32) -> Option<i64> {
        let Num { fi, modal, class, .. } = num;
        let inch = self.opts.units == Units::Inch;
        let scaled = x * POW10F[d];
        let n = round_scaled(scaled);
        self.count_rounding(class, n, scaled, x, d, INV_POW10[d & 15]);
        if num.slot != NO_SLOT {
            let slot = usize::from(num.slot);
            let key = Key { fi, inch, n };
            if modal
                && let Some((w, _)) = self.written[slot]
                && self.same_text(w, key)
            {
                // The text written is this number's (in this format): the next time it is not
                // rounded.
                self.set_written(slot, Some((key, x)));
                return None;
            }
            if !(3..5).contains(&slot) {
                *moved += 1;
            }
            // Staged: it counts as written once the block is.
            self.staged[slot] = (key, x);
            self.staged_mask |= 1 << slot;
        }
        Some(n)
    }

    /// Keeps the largest rounding of positions and of feeds ([`Class`]) with that of `x`
    /// (scaled by 10^`d` to `scaled`, rounded to `n`): `round`'s error, worked out only where
    /// it may pass the largest so far. `inv` is 10^-`d`.
    #[inline(always)]
    fn count_rounding(&mut self, class: Class, n: i64, scaled: f64, x: f64, d: usize, inv: f64) {
        // A position, the common number, here; the others apart (no jump through a table
        // for every number).
        if class == Class::Position {
            if !below_by(n, scaled, x, inv, self.rounded) {
                self.keep_rounding(class, n, x, d);
            }
        } else {
            self.count_rounding_apart(class, n, scaled, x, d);
        }
    }

    /// [`Post::count_rounding`] for a number that is no position.
    #[inline(never)]
    fn count_rounding_apart(&mut self, class: Class, n: i64, scaled: f64, x: f64, d: usize) {
        let kept = match class {
            Class::Feed => self.rounded_feed,
            Class::Centre => self.rounded / CENTRE_FACTOR,
            Class::Position | Class::Other => return,
        };
        if !below(n, scaled, x, d, kept) {
            self.keep_rounding(class, n, x, d);
        }
    }

    /// [`Post::count_rounding`] for a rounding that may pass the largest so far.
    #[inline(never)]
    fn keep_rounding(&mut self, class: Class, n: i64, x: f64, d: usize) {
        let err = (n as f64 / POW10F[d] - x).abs();
        if class == Class::Feed {
            if err > self.rounded_feed {
                self.rounded_feed = err;
                if self.rounded_feed_at.is_none() && err * self.opts.units.to_mm() > ROUNDED_NOTE {
                    self.rounded_feed_at = Some(self.origin);
                }
            }
            return;
        }
        let off = if class == Class::Centre { err * CENTRE_FACTOR } else { err };
        if off > self.rounded {
            self.rounded = off;
            if self.rounded_at.is_none() && off * self.opts.units.to_mm() > ROUNDED_NOTE {
                self.rounded_at = Some(self.origin);
            }
        }
    }

    /// Whether modal placeholder `slot` with `x` in format `fi` is the number written last:
    /// its text again, left out at once (the common case of a move's unchanged axes).
    #[inline]
    fn unchanged(&self, num: Num, x: f64) -> bool {
        let k = usize::from(num.slot);
        num.modal && self.last[k] == x && self.last_fi[k] == num.fi
    }

    /// Writes number part `num` with value `x` after the separator `sep` (none at the block's
    /// `body` start): the common word, one number, absent (NaN), unchanged, or written here
    /// (and taken back when it writes nothing).
    #[inline(always)]
    fn put_num(&mut self, buf: &mut Vec<u8>, body: usize, sep: &[u8], num: Num, x: f64, moved: &mut u32) {
        let x = if self.x_diam { self.as_diameter(num.value, x) } else { x };
        if x.is_nan() || self.unchanged(num, x) {
            return;
        }
        let mark = buf.len();
        if mark > body {
            append(buf, sep);
        }
        if !self.write_value(buf, num, x, moved) {
            buf.truncate(mark);
        }
    }

    /// A number as written while X words are diameters: an X position (the work offset's or
    /// the machine's) doubled; arc centres (I, the radius from the start), radii and the
    /// rest as they are.
    #[inline(never)]
    fn as_diameter(&self, value: Value, x: f64) -> f64 {
        if matches!(value, Value::X | Value::MachineX) { 2.0 * x } else { x }
    }

    /// Writes number placeholder `value` with `x` in format `fi` onto `s`, unless it is left
    /// out; whether it was written.
    #[inline]
    fn push_value(&mut self, s: &mut Vec<u8>, num: Num, x: f64, moved: &mut u32) -> bool {
        let x = if self.x_diam { self.as_diameter(num.value, x) } else { x };
        if x.is_nan() || self.unchanged(num, x) {
            return false;
        }
        self.write_value(s, num, x, moved)
    }

    /// [`Post::push_value`] for a number that is there and not [`Post::unchanged`].
    #[inline(always)]
    fn write_value(&mut self, s: &mut Vec<u8>, num: Num, x: f64, moved: &mut u32) -> bool {
        let f = &self.out.formats[num.fi as usize];
        let d = decimals(f, self.opts.units == Units::Inch);
        match self.number(num, x, d, moved) {
            Some(n) => {
                push_number_in(s, f, n, d);
                true
            }
            None => false,
        }
    }

    /// Renders one word onto `s`; false when it comes out empty (every placeholder absent or
    /// unchanged). Counts the modal values written in `moved`.
    fn word(&mut self, w: &crate::dialect::output::Word, vals: &Vals, s: &mut Vec<u8>, moved: &mut u32) -> bool {
        let mut any_var = false;
        let mut any_out = false;
        for p in &w.0 {
            match p {
                Piece::Lit(l) => s.extend_from_slice(l.as_bytes()),
                Piece::Var { value, format, force } => {
                    any_var = true;
                    if value.is_text() {
                        let t = match value {
                            // Nothing waiting (the common move): nothing to gather.
                            Value::Mods if self.mods.is_empty() => continue,
                            Value::Mods => {
                                std::mem::take(&mut self.mods).into_iter().map(|(_, t)| t).collect::<Vec<_>>().join(&self.out.separator)
                            }
                            Value::Name => self.opts.name.clone(),
                            Value::UnitName => if self.opts.units == Units::Mm { "MM" } else { "INCH" }.to_owned(),
                            Value::Tname => self
                                .tool_names
                                .iter()
                                .find(|(n, _)| *n == self.tool)
                                .map_or_else(|| self.tool.to_string(), |(_, t)| format!("\"{t}\"")),
                            _ => vals.text.clone().unwrap_or_default(),
                        };
                        if !t.is_empty() {
                            any_out = true;
                            if *value == Value::Mods {
                                // Words put off to a move are written with it, moving or not.
                                *moved += 1;
                            }
                            s.extend_from_slice(t.as_bytes());
                        }
                        continue;
                    }
                    let Some(fi) = *format else { continue };
                    any_out |= self.push_value(s, Num::new(*value, fi, *force, self.out), vals.num[*value as usize], moved);
                }
            }
        }
        !any_var || any_out
    }

    /// The layout of template `t` ([`Layout`]), made at its first use and kept.
    fn layout(&mut self, t: &Template, motion: bool) -> Layout {
        let key = (std::ptr::from_ref(t) as usize, motion);
        if let Some(k) = self.layouts.iter().position(|(at, m, _)| (*at, *m) == key) {
            // The most used (the moves') come first.
            if k > 0 {
                self.layouts.swap(k, k - 1);
            }
            let k = k.saturating_sub(1);
            if let Some(l) = self.layouts[k].2.take() {
                return l;
            }
            // In use further up (rendered again while it renders): a copy of its own.
            return Layout::of(t, self.out, motion);
        }
        self.layouts.push((key.0, key.1, None));
        Layout::of(t, self.out, motion)
    }

    /// Keeps `layout` for template `t` again, after [`Post::layout`].
    fn layout_done(&mut self, t: &Template, motion: bool, layout: Layout) {
        let key = (std::ptr::from_ref(t) as usize, motion);
        if let Some(entry) = self.layouts.iter_mut().find(|(at, m, _)| (*at, *m) == key) {
            entry.2.get_or_insert(layout);
        }
    }

    /// Writes the blocks of `t`. A motion template's block that moves no axis is left out
    /// (with its modal values unwritten), and its G code is left out when unchanged. Each
    /// block is written in place at the end of the buffer (its number first) and taken back
    /// when it comes out empty.
    fn render(&mut self, t: &'a Template, vals: &mut Vals, tool_change: bool, motion: bool) {
        // The header (and the modal state it starts from) before the first block's words.
        self.start();
        let layout = self.layout(t, motion);
        let sep = self.out.separator.as_bytes();
        for (b, lb) in t.0.iter().zip(&layout.0) {
            let start = self.buf.len();
            let numbered = self.block_start(lb.raw, tool_change);
            let mut buf = std::mem::take(&mut self.buf);
            let body = buf.len();
            let mut moved = 0;
            let mut code: Option<&str> = None;
            // The common move: its code, nothing put off to it, numbers.
            if let Some(simple) = &lb.simple
                && (!simple.mods || self.mods.is_empty())
            {
                if let Some(c) = &simple.code
                    && self.motion.as_deref() != Some(c.as_str())
                {
                    code = Some(c);
                    push_code(&mut buf, body, sep, c);
                }
                for &num in &simple.nums {
                    self.put_num(&mut buf, body, sep, num, vals.num[num.value as usize], &mut moved);
                }
            } else {
                for part in &lb.parts {
                    let w = match *part {
                        Part::Code(ref c) => {
                            if self.motion.as_deref() == Some(c.as_str()) {
                                continue;
                            }
                            code = Some(c);
                            push_code(&mut buf, body, sep, c);
                            continue;
                        }
                        Part::Num(num) => {
                            self.put_num(&mut buf, body, sep, num, vals.num[num.value as usize], &mut moved);
                            continue;
                        }
                        Part::Mods(_) if self.mods.is_empty() => continue,
                        Part::Mods(wi) | Part::Word(wi) => &b.words[wi],
                    };
                    // Written in place after the separator, and taken back when it comes out empty.
                    let mark = buf.len();
                    if mark > body {
                        append(&mut buf, sep);
                    }
                    let at = buf.len();
                    if !(self.word(w, vals, &mut buf, &mut moved) && buf.len() > at) {
                        buf.truncate(mark);
                    }
                }
            }
            if motion && moved == 0 && lb.moves {
                self.staged_mask = 0;
                buf.truncate(start);
                self.buf = buf;
                continue;
            }
            self.commit_staged();
            if let Some(c) = code {
                if self.motion.as_deref() != Some(c) {
                    self.motion = Some(c.to_owned());
                }
            }
            let empty = buf.len() == body;
            if empty {
                buf.truncate(start);
            }
            self.buf = buf;
            if !empty {
                self.line_end(start, lb.raw, numbered);
            }
        }
        self.layout_done(t, motion, layout);
    }

    /// The modal values staged while a block was rendered ([`Post::number`]) count as
    /// written: the block is.
    #[inline]
    fn commit_staged(&mut self) {
        let mut staged = std::mem::take(&mut self.staged_mask);
        while staged != 0 {
            let k = staged.trailing_zeros() as usize;
            self.set_written(k, Some(self.staged[k]));
            staged &= staged - 1;
        }
    }

    /// Starts a block at the end of the buffer: the optional block's `/` and the block number
    /// where the target numbers it (counted once the block is written, [`Post::line_end`]);
    /// whether it is numbered.
    #[inline]
    fn block_start(&mut self, raw: bool, tool_change: bool) -> bool {
        let numbered = numbered(self.out, raw, tool_change);
        self.start_block(raw, numbered);
        numbered
    }

    /// [`Post::block_start`] with whether the block is numbered ([`numbered`]) known.
    #[inline(always)]
    fn start_block(&mut self, raw: bool, numbered: bool) {
        if !raw && self.optional_line == Some(self.line) {
            self.buf.push(b'/');
        }
        if numbered {
            let out = self.out;
            append(&mut self.buf, out.number_address.as_bytes());
            self.push_block_number();
            append(&mut self.buf, out.separator.as_bytes());
        }
    }

    /// Appends the block number [`Post::block`] ([`Post::block_digits`]).
    #[inline]
    fn push_block_number(&mut self) {
        let len = self.block_digits();
        append_tail(&mut self.buf, &self.number_text.0, 0, len);
    }

    /// Brings the text of [`Post::number_text`] to the block number [`Post::block`]; how many
    /// digits it has. The usual step, one that leaves the digits before the last two as they
    /// are, is counted on in those two at once; any other by [`Post::block_digits_apart`].
    #[inline]
    fn block_digits(&mut self) -> usize {
        let (digits, len, n) = &mut self.number_text;
        let l = *len;
        if *n == self.block {
            return l;
        }
        let delta = self.block.wrapping_sub(*n);
        if self.block > *n && delta < 100 && l >= 2 {
            let v = usize::from(digits[l - 2] - b'0') * 10 + usize::from(digits[l - 1] - b'0') + delta as usize;
            if v < 100 {
                digits[l - 2..l].copy_from_slice(&DIGITS2[2 * v..2 * v + 2]);
                *n = self.block;
                return l;
            }
        }
        self.block_digits_apart()
    }

    /// [`Post::block_digits`] for any step: the last number's text counted on by the
    /// difference ([`count_on`]), else written afresh.
    #[inline(never)]
    fn block_digits_apart(&mut self) -> usize {
        let (digits, len, n) = &mut self.number_text;
        if !(self.block > *n && count_on(&mut digits[..*len], self.block - *n)) {
            *len = write_u64(digits, self.block);
        }
        *n = self.block;
        *len
    }

    /// Ends the block that starts at `start` in the buffer, and hands the buffer over when
    /// it is full.
    #[inline]
    fn line_end(&mut self, start: usize, raw: bool, numbered: bool) {
        if numbered {
            self.block += self.out.number_step;
        }
        if !raw {
            append(&mut self.buf, self.out.end_of_block.as_bytes());
        }
        let line = self.buf.len() - start;
        if line > self.max_line {
            self.line_too_long(line);
        }
        self.buf.push(b'\n');
        if self.buf.len() >= FLUSH_AT {
            self.hand_over();
        }
    }

    /// A block of `len` characters is longer than the target takes: said once.
    #[inline(never)]
    fn line_too_long(&mut self, len: usize) {
        if self.noted.insert("line-too-long".into()) {
            self.diags.push(Diagnostic::new(
                Code::PostLineTooLong,
                Default::default(),
                format!("a written line has {len} characters, over the {} the target takes", self.out.max_line),
            ));
        }
    }

    /// Hands the full buffer over ([`Post::line_end`]), unless a repeated run still fits.
    #[inline(never)]
    fn hand_over(&mut self) {
        if self.repeat.is_some() && self.buf.len() < REPEAT_MAX {
            return;
        }
        // Too long to hold: the passes counted so far are written as a loop.
        self.end_repeat();
        (self.sink)(&self.buf);
        self.buf.clear();
        self.line_offsets.clear();
    }

    /// The tool moved to `p`: kept, and checked against the machine's travel.
    #[inline]
    fn moved(&mut self, p: [f64; 3]) {
        self.pos = p;
        if self.opts.limits.travel.is_some() {
            self.check_travel(p);
        }
    }

    #[inline(never)]
    fn check_travel(&mut self, p: [f64; 3]) {
        if let Some((lo, hi)) = self.opts.limits.travel {
            let mm = self.opts.units.to_mm();
            if (0..3).any(|k| p[k] * mm < lo[k] - 1e-6 || p[k] * mm > hi[k] + 1e-6) && self.noted.insert("travel".into()) {
                self.diags.push(Diagnostic::new(
                    Code::PostMachineLimit,
                    self.origin,
                    format!("the tool goes to X{:.3} Y{:.3} Z{:.3} mm, outside the machine's travel", p[0] * mm, p[1] * mm, p[2] * mm),
                ));
            }
        }
    }

    fn check_limits(&mut self, canon: &Canon) {
        let mm = self.opts.units.to_mm();
        if let Some(max) = self.opts.limits.max_spindle_speed
            && self.speed > max + EPS
        {
            let msg = format!("S{} is over the machine's highest spindle speed, {max}", self.speed);
            self.note(Code::PostMachineLimit, canon, "speed-limit", msg);
        }
        if let Some(max) = self.opts.limits.max_feed
            && self.feed * mm > max + EPS
        {
            let msg = format!("F{} mm/min is over the machine's highest feed, {max}", self.feed * mm);
            self.note(Code::PostMachineLimit, canon, "feed-limit", msg);
        }
    }

    /// Ends the program (the footer) and hands over the rest of the text; returns the
    /// findings.
    pub fn finish(mut self) -> Vec<Diagnostic> {
        self.start();
        for h in std::mem::take(&mut self.held) {
            self.op(&h);
        }
        if let Some(p) = self.pending_move.take() {
            self.op(&p);
        }
        self.end_repeat();
        self.flush_tool();
        self.cancel_cycle();
        if !self.ended {
            self.event("end", &mut Vals::new());
        }
        self.write_subs();
        self.event("footer", &mut Vals::new());
        if !self.buf.is_empty() {
            (self.sink)(&self.buf);
            self.buf.clear();
        }
        if let Some(at) = self.rounded_at {
            let mm = self.rounded * self.opts.units.to_mm();
            self.diags.push(Diagnostic::new(
                Code::PostRounded,
                at,
                format!(
                    "the program states positions finer than the target writes them: they are rounded to its resolution, up to {} mm off",
                    format!("{:.5}", (mm * 1e5).ceil() / 1e5).trim_end_matches('0')
                ),
            ));
        }
        if let Some(at) = self.rounded_feed_at {
            let mm = self.rounded_feed * self.opts.units.to_mm();
            self.diags.push(Diagnostic::new(
                Code::PostRounded,
                at,
                format!(
                    "the program states feeds finer than the target writes them: they are rounded to its format, up to {} mm per minute (or revolution) off",
                    format!("{:.5}", (mm * 1e5).ceil() / 1e5).trim_end_matches('0')
                ),
            ));
        }
        self.diags
    }
}

impl<F: FnMut(&[u8])> CanonSink for Post<'_, F> {
    fn emit(&mut self, canon: Canon) {
        self.emit_all(std::slice::from_ref(&canon));
    }
}

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// [`CanonSink::emit`] for each op of `batch`, in order, read where it lies: the common
    /// straight move in the steady state by the steady lane ([`lane`]), else by the general
    /// path, after which the steady state is worked out again. The lanes are taken out of
    /// the writer once for the batch, not for every move.
    fn emit_all(&mut self, batch: &[Canon]) {
        let Some(lanes) = self.lanes.take() else {
            batch.iter().for_each(|canon| self.emit_general(canon));
            return;
        };
        for canon in batch {
            if self.lane_ready != 0 && self.steady_move(&lanes, canon) {
                continue;
            }
            self.emit_general(canon);
            self.refresh_lane(&lanes);
        }
        self.lanes = Some(lanes);
    }

    /// [`CanonSink::emit`] by the general path.
    ///
    /// A change of work offset waits for the op after it ([`Post::held`]): the end of the
    /// program on the same line drops it (the control's other resets before the end are
    /// written as ever); anything else writes it first.
    fn emit_general(&mut self, canon: &Canon) {
        if !self.hold_offset(canon) {
            return;
        }
        // A rapid while an output cycle is in force may be the positioning before the next
        // hole of a modal cycle (`MCALL`, `M99`): it waits for the op after it.
        if let Some(p) = self.pending_move.take() {
            let positions = match (&p.op, &canon.op) {
                // Not one that turns a rotary axis too: the cycle's hole position cannot say it.
                (CanonOp::StraightTraverse(q), CanonOp::CycleBegin(i)) => {
                    i.positioned
                        && (q[0] - i.x).abs() < 1e-9
                        && (q[1] - i.y).abs() < 1e-9
                        && (0..3).all(|k| (q[3 + k] - self.abc[k]).abs() < 1e-9)
                }
                _ => false,
            };
            if !positions {
                self.op(&p);
            }
        }
        if self.active.is_some() && !self.in_cycle && !self.ended {
            if let CanonOp::StraightTraverse(q) = &canon.op {
                if (self.point(q)[2] - self.pos[2]).abs() < 1e-9 {
                    self.pending_move = Some(canon.clone());
                    return;
                }
            }
        }
        self.op(canon);
    }
}

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// [`Post::emit_general`]'s hold of a work offset change: false where `canon` is held
    /// or dropped, true where it goes on to be written.
    fn hold_offset(&mut self, canon: &Canon) -> bool {
        let same_line = self.held.first().is_some_and(|h| h.line == canon.line);
        match &canon.op {
            _ if self.held.is_empty() => {}
            CanonOp::ProgramEnd if same_line => self.held.clear(),
            // The plane the end puts back: held with the offset.
            CanonOp::SelectPlane(_) if same_line => {
                self.held.push(canon.clone());
                return false;
            }
            // The end's other resets, in the order `program_end` emits them: written (the
            // stops a post writes before its end), the offset still held.
            CanonOp::SetFeedRate(_) | CanonOp::StopSpindleTurning | CanonOp::SetSpindleMode(_) | CanonOp::MistOff | CanonOp::FloodOff
                if same_line => {}
            _ => {
                for h in std::mem::take(&mut self.held) {
                    self.op(&h);
                }
            }
        }
        if matches!(canon.op, CanonOp::SetG5xOffset(..)) && !self.ended {
            // A rapid waiting for the op after it goes first: it runs in the offset before.
            if let Some(p) = self.pending_move.take() {
                self.op(&p);
            }
            self.held.push(canon.clone());
            return false;
        }
        true
    }

    fn op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::StraightTraverse(q) | CanonOp::StraightFeed(q) => {
                if self.known != ALL_KNOWN && !self.ended {
                    let end = self.point(q);
                    self.check_unknown(canon, end, [q[3], q[4], q[5]]);
                }
                self.abc = [q[3], q[4], q[5]];
            }
            CanonOp::ArcFeed { first_end, second_end, axis_end, abc, .. } => {
                if self.known != ALL_KNOWN && !self.ended {
                    let (a, b, n) = self.plane.axes();
                    let mut end = [0.0; 3];
                    end[a] = self.to_out(*first_end) + self.g92[a];
                    end[b] = self.to_out(*second_end) + self.g92[b];
                    end[n] = self.to_out(*axis_end) + self.g92[n];
                    self.check_unknown(canon, end, *abc);
                }
                self.abc = *abc;
            }
            CanonOp::Known(m) => {
                self.know(*m);
                return;
            }
            CanonOp::ShiftUnknown(m) => {
                if !self.ended {
                    self.shift_unknown(canon, *m);
                }
                return;
            }
            _ => {}
        }
        if canon.line != self.line && canon.line > 0 && !self.ended {
            self.new_line(canon);
        }
        self.line = canon.line;
        self.origin = canon.origin;
        if self.ended {
            // What follows the end is the control's reset, not the program.
            return;
        }
        match &canon.op {
            // What a tool change's block may still take (its speed), or what writes nothing.
            CanonOp::SetSpindleSpeed(_)
            | CanonOp::Setting(Setting::ToolName(..) | Setting::LengthOffset(_) | Setting::DiameterMode(_))
            | CanonOp::Turning(_)
            | CanonOp::TurningEnd
            | CanonOp::SelectTool(_)
            | CanonOp::UseToolLengthOffset(_)
            | CanonOp::SetFeedRate(_) => {}
            _ => self.flush_tool(),
        }
        if matches!(
            canon.op,
            CanonOp::StraightTraverse(_)
                | CanonOp::StraightFeed(_)
                | CanonOp::ArcFeed { .. }
                | CanonOp::CycleBegin(_)
                | CanonOp::RigidTap(_)
                | CanonOp::NurbsFeed { .. }
                | CanonOp::StraightProbe(_)
        ) {
            self.check_work_offset(canon);
            if !self.moved_yet {
                self.first_move(canon);
            }
        }
        match &canon.op {
            // Another spindle than the main one (a driven tool, `M2=3`): no target's output
            // rules address one, and written as the main spindle's it would turn the part.
            CanonOp::Spindle(crate::canon::SpindleId::Main) => {}
            CanonOp::Spindle(id) => {
                let what = format!(
                    "the speed and turning of the {} are not written: the target's output rules address the main spindle only",
                    id.words()
                );
                self.note(Code::PostUnwritable, canon, "spindle-number", what);
            }
            CanonOp::SetSpindleSpeed(_)
            | CanonOp::StartSpindleClockwise
            | CanonOp::StartSpindleCounterclockwise
            | CanonOp::StopSpindleTurning
            | CanonOp::Setting(_)
            | CanonOp::Turning(_)
            | CanonOp::TurningEnd
            | CanonOp::SelectTool(_)
            | CanonOp::ChangeTool(_) => {}
            CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. } | CanonOp::CycleBegin(_) => {
                self.flush_speed(true);
                if self.length_unsaid && self.tool != 0 {
                    self.note(
                        Code::PostUnwritable,
                        canon,
                        "length-offset-off",
                        "the program cuts with the length offset cancelled (G49), but the target's tool change puts the tool's length in force and its output rules have no `length-offset-off` to cancel it",
                    );
                }
            }
            _ => self.flush_speed(false),
        }
        // The common op, a straight move, apart from the rest (a small frame for it).
        match &canon.op {
            CanonOp::StraightTraverse(p) if self.machine.is_some() => self.machine_step(canon, p, true),
            CanonOp::StraightFeed(p) if self.machine.is_some() => self.machine_step(canon, p, false),
            CanonOp::StraightTraverse(p) => self.straight(canon, p, true),
            CanonOp::StraightFeed(p) => self.straight(canon, p, false),
            _ => self.other_op(canon),
        }
    }

    /// The axes the source knows from here ([`CanonOp::Known`]): one that becomes known is
    /// written at its next move even where its number is the one written last (no modal
    /// suppression across an unknown stretch: the machine is not where that word put it).
    fn know(&mut self, m: u8) {
        const AXES: [Value; 6] = [Value::X, Value::Y, Value::Z, Value::A, Value::B, Value::C];
        let new = m & !self.known;
        for (k, v) in AXES.into_iter().enumerate() {
            if new & 1 << k != 0
                && let Some(slot) = modal_slot(v)
            {
                self.set_written(slot, None);
            }
        }
        self.known = m;
    }

    /// A move to `end` (target units) with rotary axes at `abc`: an axis the source does not
    /// know the position of that it moves was moved incrementally from an unknown start
    /// (`G91`, `U`/`W`, `IX` before any absolute word, or after a reference return): its
    /// number here is counted from an assumed 0. No target's output rules write a move
    /// incrementally, so the translation is refused at the move. The moves of a cycle written
    /// as a cycle and of a machine-frame move are the target's own.
    fn check_unknown(&mut self, canon: &Canon, end: [f64; 3], abc: [f64; 3]) {
        if self.in_cycle || self.machine.as_ref().is_some_and(machine::PendingMachine::last_step) {
            return;
        }
        const NAMES: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
        let moved: Vec<&str> = (0..6)
            .filter(|&k| {
                let (from, to) = if k < 3 { (self.pos[k], end[k]) } else { (self.abc[k - 3], abc[k - 3]) };
                self.known & 1 << k == 0 && (to - from).abs() > EPS
            })
            .map(|k| NAMES[k])
            .collect();
        if !moved.is_empty() {
            let msg = format!(
                "the translation is refused: {} moves incrementally from a position the program does not know (no absolute word for it since the start or a reference return); the target's output rules write no incremental move, and an absolute position counted from an assumed 0 would send the tool elsewhere",
                moved.join(" ")
            );
            self.note(Code::PostUnknownStart, canon, "unknown-start", msg);
        }
    }

    /// A coordinate set (`G92`, `G50 X.. Z..`) of axes `m` whose position the source does not
    /// know: the shift is counted from an assumed position, so neither the positions written
    /// in the work offset's frame nor a shift stated by the target would be the program's.
    /// No target's output rules write a coordinate set, so the translation is refused.
    fn shift_unknown(&mut self, canon: &Canon, m: u8) {
        const NAMES: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
        let axes: Vec<&str> = (0..6).filter(|&k| m & 1 << k != 0).map(|k| NAMES[k]).collect();
        let msg = format!(
            "the translation is refused: the program sets its coordinates (G92, G50) of {} where it does not know the position (no absolute word for it since the start, a reference return, a tool or work offset change); the shift is counted from an assumed position, and the target's output rules write no coordinate set",
            axes.join(" ")
        );
        self.note(Code::PostUnknownStart, canon, "unknown-start", msg);
    }

    /// The values of the axes whose position the source does not know taken out of `vals`
    /// (NaN: not written), so that no word counted from an assumed 0 is.
    fn unknown_out(&self, vals: &mut Vals) {
        if self.known != ALL_KNOWN {
            for (k, v) in [Value::X, Value::Y, Value::Z, Value::A, Value::B, Value::C].into_iter().enumerate() {
                if self.known & 1 << k == 0 {
                    vals.set(v, f64::NAN);
                }
            }
        }
    }

    /// [`Post::op`] for the ops other than straight moves: each kind of op to the writer of
    /// its group ([`cycle`], [`modes`], [`motion`], [`program`], [`spindle`], [`tool`]).
    #[inline(never)]
    fn other_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::UseLengthUnits(_) | CanonOp::SelectPlane(_) | CanonOp::DistanceMode(_) => self.mode_op(canon),
            CanonOp::SetFeedRate(_) | CanonOp::SetFeedMode(_) => self.feed_op(canon),
            CanonOp::SetG5xOffset(..) | CanonOp::SetG92Offset(_) | CanonOp::Setting(Setting::WorkOffset(_)) => self.offset_op(canon),
            CanonOp::MachineMove(m) => self.machine_op(canon, m),
            CanonOp::SelectTool(_)
            | CanonOp::ChangeTool(_)
            | CanonOp::UseToolLengthOffset(_)
            | CanonOp::Setting(Setting::ToolName(..) | Setting::LengthOffset(_)) => self.tool_op(canon),
            CanonOp::Setting(Setting::CutterComp(_)) => self.comp_op(canon),
            CanonOp::SetSpindleSpeed(_)
            | CanonOp::StartSpindleClockwise
            | CanonOp::StartSpindleCounterclockwise
            | CanonOp::StopSpindleTurning
            | CanonOp::SetSpindleMode(_)
            | CanonOp::OrientSpindle { .. }
            | CanonOp::WaitOrientComplete(_) => self.spindle_op(canon),
            CanonOp::StartSpeedFeedSync(_) | CanonOp::StopSpeedFeedSync | CanonOp::RigidTap(_) => self.sync_op(canon),
            CanonOp::StraightTraverse(_)
            | CanonOp::StraightFeed(_)
            | CanonOp::ArcFeed { .. }
            | CanonOp::NurbsFeed { .. }
            | CanonOp::ToolAxis(_)
            | CanonOp::WorkPlane(_) => self.motion_op(canon),
            CanonOp::CycleBegin(_) | CanonOp::CycleEnd | CanonOp::CycleCancel => self.cycle_op(canon),
            CanonOp::FloodOn | CanonOp::MistOn | CanonOp::FloodOff | CanonOp::MistOff => self.coolant_op(canon),
            CanonOp::Dwell(s) => self.dwell(canon, s),
            CanonOp::ProgramStop | CanonOp::OptionalProgramStop | CanonOp::ProgramEnd | CanonOp::Finish => self.stop_op(canon),
            CanonOp::Comment(t) => self.comment(t, "comment"),
            CanonOp::Message(t) => self.comment(t, "message"),
            CanonOp::Setting(Setting::BlockDelete) => self.optional_line = Some(canon.line),
            CanonOp::Turning(t) => self.lathe_cycle(canon, t),
            CanonOp::Setting(Setting::DiameterMode(on)) => self.diameter_mode(canon, *on),
            CanonOp::Setting(Setting::ToolCentrePoint(on)) => self.tool_centre_point(canon, *on),
            CanonOp::Setting(Setting::HoleMilled(_)) => self.hole_milled = true,
            CanonOp::Setting(Setting::MillCycle(Some(name))) if std::mem::take(&mut self.hole_milled) => {
                let what = format!(
                    "{name} is read as its helix along the bore's wall and its circle at the floor, the wall as programmed under compensation: written as moves, the target would not cut the core a bore wider than twice the tool leaves, which the control's cycle does"
                );
                self.note(Code::PostUnwritable, canon, "mill-bore", what);
            }
            CanonOp::Setting(Setting::MillCycle(Some(name))) => {
                let what = format!(
                    "{name} is read as its finishing pass only (its roughing is not expanded): written as moves, the target would cut the wall at full depth without roughing the pocket"
                );
                self.note(Code::PostUnwritable, canon, "mill-cycle", what);
            }
            // Cylindrical interpolation (Fanuc G07.1/G107, SINUMERIK TRACYL): the canon keeps
            // its moves on the developed surface's plane laid tangent to the cylinder, which
            // the target writes as a tilted plane; no output rules write the mode itself, so
            // the written program cuts on that flat plane where the source's cut wraps round
            // the cylinder (the moves read back are the same, the part is not).
            CanonOp::Setting(Setting::CylinderWrap(Some(r))) => {
                let what = format!(
                    "cylindrical interpolation (radius {}) is not written: the target's output rules have no cylinder mode, so the moves on the developed surface would be written on a flat plane laid tangent to the cylinder, cutting there instead of round the cylinder",
                    crate::text::num(*r)
                );
                self.note(Code::PostUnwritable, canon, "cylinder", what);
            }
            CanonOp::Setting(Setting::MillCycle(None) | Setting::CycleSurface(_) | Setting::CylinderWrap(None)) | CanonOp::TurningEnd => {}
            // The rest (probing, overrides, the log file, M61): said, not written.
            _ => self.unwritable(canon),
        }
    }
}

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// Whether the target writes repeated runs as a loop where they run (`repeat-begin` …
    /// `repeat-end`) or as a subprogram it calls there (`repeat-call`, `sub-begin` …
    /// `sub-end`). Numbered blocks are compared without their numbers and renumbered.
    fn writes_repeats(&self) -> bool {
        let has = |e: &str| self.out.template(e).is_some();
        (has("repeat-begin") && has("repeat-end")) || self.writes_calls()
    }

    /// Whether the target writes a repeated run as a subprogram after the program's end.
    fn writes_calls(&self) -> bool {
        let has = |e: &str| self.out.template(e).is_some();
        has("repeat-call") && has("sub-begin") && has("sub-end")
    }

    /// The source moves to another line: a jump back to where a run began ends its pass.
    fn new_line(&mut self, canon: &Canon) {
        let line = canon.line;
        if let Some(r) = &self.repeat {
            if line == r.first {
                self.pass_ended();
                return;
            }
            if line < r.lines.0 || line > r.lines.1 {
                self.end_repeat();
            }
        }
        let again = self.mark_seen(line);
        if again && line < self.line && self.repeat.is_none() {
            // A jump back to a line that ran: the run from its text to here may repeat.
            let at = self.line_offsets.iter().rev().find(|(l, _, _)| *l == line).map(|(_, o, b)| (*o, *b));
            match at {
                Some((start, block_start)) if self.writes_repeats() => {
                    let seen = self.line_offsets.iter().filter(|(_, o, _)| *o >= start).map(|(l, _, _)| *l);
                    let lines = seen.fold((line, line), |(lo, hi), l| (lo.min(l), hi.max(l)));
                    self.repeat = Some(Repeat {
                        first: line,
                        lines,
                        start,
                        end: self.buf.len(),
                        count: 1,
                        shifted: false,
                        block_start,
                        block_end: self.next_block(),
                        origin: canon.origin,
                    });
                    return;
                }
                _ => self.note_unrolled(canon.origin),
            }
        }
        self.line_starts(line, self.next_block());
    }

    /// Marks source line `line` as run ([`Post::seen`]); whether it had run before.
    #[inline]
    fn mark_seen(&mut self, line: u32) -> bool {
        let (word, bit) = (line as usize / 64, 1u64 << (line % 64));
        let Some(w) = self.seen.get_mut(word) else {
            self.seen.resize(word + 1, 0);
            self.seen[word] = bit;
            return false;
        };
        let again = *w & bit != 0;
        *w |= bit;
        again
    }

    /// Whether source line `line` has run ([`Post::mark_seen`]).
    #[inline]
    fn has_run(&self, line: u32) -> bool {
        self.seen.get(line as usize / 64).is_some_and(|w| w & (1 << (line % 64)) != 0)
    }

    /// Records where source line `line`'s text begins ([`Post::line_offsets`]), at the block
    /// numbered `block` ([`Post::next_block`]).
    #[inline]
    fn line_starts(&mut self, line: u32, block: u64) {
        if self.line_offsets.last().is_none_or(|(l, _, _)| *l != line) {
            self.line_offsets.push((line, self.buf.len(), block));
        }
    }

    /// The number the next numbered block gets.
    fn next_block(&self) -> u64 {
        if self.started { self.block } else { self.out.number_start }
    }

    fn note_unrolled(&mut self, at: crate::text::TextRange) {
        if self.noted.insert("unrolled".into()) {
            self.diags.push(Diagnostic::new(
                Code::PostUnrolled,
                at,
                "the program runs blocks again (a loop, a jump back or a subprogram) and its passes write other text: it is written as the path that runs, unrolled",
            ));
        }
    }

    /// Whether the text written from `b` on is the pass at `a..b` again (numbered from
    /// `na` and `nb`): the same lines but for their block numbers.
    fn same_pass(&self, a: usize, b: usize, na: u64, nb: u64) -> bool {
        let (x, y) = (&self.buf[a..b], &self.buf[b..]);
        if self.out.numbered == Numbered::None {
            return x == y;
        }
        let (mut xs, mut ys) = (x.split_inclusive(|c| *c == b'\n'), y.split_inclusive(|c| *c == b'\n'));
        let (mut na, mut nb) = (na, nb);
        loop {
            match (xs.next(), ys.next()) {
                (None, None) => return true,
                (Some(p), Some(q)) => {
                    let (p, q) = (split_number(self.out, p, na), split_number(self.out, q, nb));
                    if p != q {
                        return false;
                    }
                    if p.1 {
                        na += self.out.number_step;
                        nb += self.out.number_step;
                    }
                }
                _ => return false,
            }
        }
    }

    /// Appends `text`, written with block numbers from `from` on, numbered from the next
    /// block number on.
    fn push_renumbered(&mut self, text: &[u8], from: u64) {
        if self.out.numbered == Numbered::None {
            self.buf.extend_from_slice(text);
            return;
        }
        let mut n = from;
        for l in text.split_inclusive(|c| *c == b'\n') {
            let (slash, numbered, rest) = split_number(self.out, l, n);
            if !numbered {
                self.buf.extend_from_slice(l);
                continue;
            }
            if slash {
                self.buf.push(b'/');
            }
            self.buf.extend_from_slice(self.out.number_address.as_bytes());
            push_u64(&mut self.buf, self.block);
            self.buf.extend_from_slice(self.out.separator.as_bytes());
            self.buf.extend_from_slice(rest);
            self.block += self.out.number_step;
            n += self.out.number_step;
        }
    }

    /// A pass of the run ended: the same text as the first is dropped and counted; other
    /// text ends the run (it stays written, unrolled).
    fn pass_ended(&mut self) {
        let Some(r) = self.repeat.as_ref() else { return };
        let (start, end, bs, be) = (r.start, r.end, r.block_start, r.block_end);
        if self.same_pass(start, end, bs, be) {
            self.buf.truncate(end);
            self.block = be;
            if let Some(r) = self.repeat.as_mut() {
                r.count += 1;
            }
        } else if r.count == 1 && !r.shifted {
            // The first pass may differ by what the blocks before it left in force (a feed
            // written once): the second pass is the one the others are compared with.
            let next = self.block;
            let len = self.buf.len();
            if let Some(r) = self.repeat.as_mut() {
                r.start = end;
                r.end = len;
                r.block_start = be;
                r.block_end = next;
                r.shifted = true;
            }
        } else {
            let origin = r.origin;
            self.end_repeat();
            self.note_unrolled(origin);
        }
    }

    /// The run is over: a last whole pass is counted, and a run of two passes or more is
    /// written once between the target's loop blocks, or as a subprogram called where it ran.
    fn end_repeat(&mut self) {
        let Some(r) = self.repeat.as_ref() else { return };
        let (start, end, bs, be) = (r.start, r.end, r.block_start, r.block_end);
        if self.same_pass(start, end, bs, be) {
            self.buf.truncate(end);
            self.block = be;
            if let Some(r) = self.repeat.as_mut() {
                r.count += 1;
            }
        }
        let Some(r) = self.repeat.take() else { return };
        if r.count < 2 || end == start {
            if r.count >= 2 {
                return;
            }
            self.note_unrolled(r.origin);
            return;
        }
        let call = self.writes_calls();
        let sub = self.opts.number.max(1000) + self.loops + 1;
        if call && sub > 9999 {
            // No number left for the subprogram: the passes stay written.
            self.note_unrolled(r.origin);
            return;
        }
        self.loops += 1;
        let tail = self.buf.split_off(r.end);
        let body = self.buf.split_off(r.start);
        self.block = r.block_start;
        let mut vals = Vals::new();
        vals.set(Value::Count, f64::from(r.count)).set(Value::Loop, f64::from(self.loops));
        vals.set(Value::Again, f64::from(r.count - 1)).set(Value::Sub, f64::from(sub));
        // The loop's own blocks are no optional blocks, whatever the line they are written at.
        let optional = self.optional_line.take();
        if call {
            self.event("repeat-call", &mut vals);
            self.subs.push((sub, body, r.block_start));
        } else {
            self.event("repeat-begin", &mut vals);
            self.push_renumbered(&body, r.block_start);
            self.event("repeat-end", &mut vals);
        }
        self.optional_line = optional;
        self.push_renumbered(&tail, r.block_end);
        // The text after the loop follows its last pass: the writer's state is that pass's end.
        self.line_offsets.clear();
    }

    /// The subprograms the repeated runs became, after the program's end.
    fn write_subs(&mut self) {
        for (sub, body, from) in std::mem::take(&mut self.subs) {
            let mut vals = Vals::new();
            vals.set(Value::Sub, f64::from(sub));
            self.event("sub-begin", &mut vals);
            self.push_renumbered(&body, from);
            self.event("sub-end", &mut vals);
        }
    }
}

/// A written line: whether it starts with `/`, whether block number `n` follows, and the
/// rest after that number.
fn split_number<'b>(out: &Output, line: &'b [u8], n: u64) -> (bool, bool, &'b [u8]) {
    let (slash, l) = match line.strip_prefix(b"/") {
        Some(r) => (true, r),
        None => (false, line),
    };
    let Some(rest) = l.strip_prefix(out.number_address.as_bytes()) else { return (slash, false, l) };
    let mut digits = Vec::with_capacity(20);
    push_u64(&mut digits, n);
    match rest.strip_prefix(digits.as_slice()).and_then(|r| r.strip_prefix(out.separator.as_bytes())) {
        Some(r) => (slash, true, r),
        None => (slash, false, l),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn f(point: Point, decimals: u8, trailing: bool, leading: bool, plus: bool, increment: bool) -> NumberFormat {
        NumberFormat {
            name: "X".into(),
            address: "X".into(),
            decimals,
            inch_decimals: decimals + 1,
            point,
            trailing_zeros: trailing,
            leading_zero: leading,
            plus,
            increment,
            modal: false,
            digits: 0,
        }
    }

    fn s(fmt: &NumberFormat, v: f64) -> String {
        let mut out = String::new();
        format_number(&mut out, fmt, v, false);
        out
    }

    #[test]
    fn a_format_pads_its_whole_digits() {
        // A lathe's tool and offset, two digits each (`T0101`, `T1212`).
        let tn = NumberFormat { address: String::new(), digits: 2, ..f(Point::Never, 0, false, true, false, false) };
        assert_eq!(s(&tn, 1.0), "01");
        assert_eq!(s(&tn, 12.0), "12");
        assert_eq!(s(&tn, 0.0), "00");
        assert_eq!(s(&tn, 123.0), "123");
        let x = NumberFormat { digits: 3, ..f(Point::Always, 3, false, true, false, false) };
        assert_eq!(s(&x, 1.5), "X001.5");
        assert_eq!(s(&x, -1.5), "X-001.5");
    }

    #[test]
    fn numbers_follow_their_format() {
        let always = f(Point::Always, 3, false, true, false, false);
        assert_eq!(s(&always, 10.0), "X10.");
        assert_eq!(s(&always, -0.5), "X-0.5");
        assert_eq!(s(&always, -0.0001), "X0.");
        assert_eq!(s(&always, 1.23456), "X1.235");
        assert_eq!(s(&f(Point::Needed, 3, false, true, true, false), 20.0), "X+20");
        assert_eq!(s(&f(Point::Needed, 3, false, true, true, false), -2.5), "X-2.5");
        assert_eq!(s(&f(Point::Always, 3, true, false, false, false), 0.5), "X.500");
        assert_eq!(s(&f(Point::Needed, 3, false, true, false, true), 10.0), "X10000");
        assert_eq!(s(&f(Point::Never, 0, false, true, false, false), 1500.4), "X1500");
    }

    fn options() -> Options {
        Options { name: "T".into(), ..Options::for_program("T") }
    }

    #[test]
    fn block_numbers_are_their_decimal_text() {
        let siemens = crate::dialect::Registry::shipped().get("siemens").expect("siemens");
        let out = siemens.output.as_ref().expect("output rules");
        let mut post = Post::new(out, options(), |_: &[u8]| {});
        let mut checked = 0;
        // Every digit count, each power of ten and its neighbours, the largest numbers.
        let mut ns: Vec<u64> = (0..1_000).collect();
        for &p in &POW10[1..] {
            ns.extend([p - 1, p, p + 1, p.saturating_mul(9).saturating_add(99)]);
        }
        ns.extend([u64::MAX - 1, u64::MAX]);
        for &n in &ns {
            post.block = n;
            post.buf = b"N".to_vec();
            post.push_block_number();
            assert_eq!(String::from_utf8(std::mem::take(&mut post.buf)).unwrap(), format!("N{n}"));
            checked += 1;
        }
        assert_eq!(checked, ns.len());
    }

    #[test]
    fn the_rounding_left_unworked_is_never_above_the_largest() {
        // `below` says an error is not above the largest kept without dividing; whenever it
        // says so, the error `round` works out is not above it.
        let mut seed = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            seed
        };
        let mut shortcuts = 0;
        for k in 0..200_000 {
            let d = (next() % 7) as usize;
            let magnitude = [1e-6, 1e-3, 1.0, 25.4, 1e3, 1e6, 1e9][(next() % 7) as usize];
            let v = ((next() >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 2.0 * magnitude;
            // An exact number at the format's resolution now and then.
            let v = if k % 5 == 0 { (v * POW10F[d]).round() / POW10F[d] } else { v };
            let scaled = v * POW10F[d];
            let n = round_scaled(scaled);
            let err = (n as f64 / POW10F[d] - v).abs();
            for kept in [0.0, err * 0.999_999, err, err * 1.000_001, err + 1e-9, 0.5 / POW10F[d], 1.0] {
                if below(n, scaled, v, d, kept) {
                    assert!(err <= kept, "{v} at {d} decimals: error {err} above {kept}");
                    shortcuts += 1;
                }
            }
        }
        assert!(shortcuts > 100_000, "the shortcut is taken ({shortcuts})");
    }

    /// Haas's G154 takes P1-P99, as its dictionary says (`<format min max>`): an additional
    /// work offset beyond it is unwritable for a Haas, not a `G154 P120` the control rejects;
    /// Fanuc's `G54.1 P` states no range and writes it.
    #[test]
    fn a_number_outside_its_formats_range_is_unwritable() {
        let registry = crate::dialect::Registry::shipped();
        let (fanuc, haas) = (registry.get("fanuc").unwrap(), registry.get("haas").unwrap());
        let out = haas.output.as_ref().unwrap();
        let p154 = out.formats.iter().position(|f| f.name == "P154").unwrap();
        assert_eq!(out.bounds, vec![crate::dialect::output::Bound { format: p154, min: 1.0, max: 99.0 }]);
        assert!(fanuc.output.as_ref().unwrap().bounds.is_empty());
        let write = |p: u32, to: &crate::dialect::Dialect| {
            let text = format!("%\nO0003\nG21 G90 G17\nT1 M6\nS1000 M3\nG54.1 P{p}\nG0 X10. Y10. Z5.\nG1 Z-1. F100.\nG0 Z50.\nM30\n%\n");
            let mut bytes = Vec::new();
            let opts = Options::for_program("O0003");
            let diags = translate(&text, &fanuc, to, &crate::interp::Profile::default(), opts, |b| bytes.extend_from_slice(b));
            let errors: Vec<String> =
                diags.iter().filter(|d| d.is_error()).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect();
            (String::from_utf8(bytes).unwrap(), errors)
        };
        for p in [1, 99] {
            let (text, errors) = write(p, &haas);
            assert!(text.contains(&format!("\nG154 P{p}\n")) && errors.is_empty(), "P{p}: {errors:?}\n{text}");
        }
        for p in [100, 120] {
            let (text, errors) = write(p, &haas);
            assert!(!text.contains("G154"), "P{p}:\n{text}");
            assert_eq!(
                errors,
                [format!(
                    "post::unwritable: the target's output rules have no code for additional work offset {p} (G54.1 P{p}: `work-offset-extended`)"
                )],
                "{text}"
            );
            let (text, errors) = write(p, &fanuc);
            assert!(text.contains(&format!("\nG54.1 P{p}\n")) && errors.is_empty(), "fanuc P{p}: {errors:?}\n{text}");
        }
    }
}

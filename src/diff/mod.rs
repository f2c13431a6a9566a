//! Plan diff: align two plans' workingsteps by what they do and report typed changes.
//!
//! Alignment is a global sequence alignment (Needleman–Wunsch) whose score rewards the same
//! operation family, the same tool geometry and overlapping toolpaths. Tool numbers and
//! block numbers play no part, so a renamed tool or renumbered program still aligns.
//!
//! Aligned workingsteps are compared by the machine state they run under (work offset,
//! offset numbers, compensation side, stops, dwells, optional blocks), their technology,
//! their holes (position and cycle parameters), their features and strategy, and last their
//! toolpaths, localised to the moves that differ. Every value is written in the original
//! program's units, so one report speaks one unit system.
//!
//! the door is `diff::compare(Program, Program)` (plan, text and dialect of each
//! side); `diff::diff(plan, plan)` is the plan-only part for callers without the texts.
//! `statement.rs` reads each program's blocks with the dialect's parser into statements (one
//! spelling: no block numbers, comments, blanks, case or number spellings, no program name;
//! messages and aborts kept; the dictionary's `log` comment directives and `output` codes mark
//! statements that only write text) and aligns them (prefix and suffix, a full LCS up to 4M
//! cells, patience anchors beyond: near-linear whatever the edit; statements on lines git's
//! diff keeps anchor the pairing where that pairs as many, and runs slide as git slides them).
//! `place.rs` names, in the rows, the lines git shows beside them that hold no statement (a
//! statement commented out, a jump's label, a condition's re-indented body). `account.rs` locates each
//! plan change at the differing statements of its workingstep whose words show it, turns every
//! other differing statement into a statement change (variables, call arguments, words, jumps;
//! output apart), names unexplained plan changes as their effect, tells a change carried into
//! later workingsteps once, and in debug builds asserts that every differing statement is
//! named. `typed.rs` tells a differing statement by what its words do where the plan does
//! not show it (a feed, a dwell, a cycle parameter: the kinds plan changes use), by the
//! dictionary's meanings and roles in the context of the statement's codes; `follow.rs`
//! follows a variable set to another value to the words it feeds (`clearance height (via
//! #<_z_clearance>)`), an assignment written elsewhere with another value as one change of
//! it (`moved`; one moved with its number, read nowhere between, is no change: `moved_same`),
//! and compares a call whose argument count changed with its subroutine as
//! each version has it (`rebound`); a probing move's words (the dictionary's probe codes) are
//! a `probing_changed`, and so are a measuring cycle's words, arguments and parameters (the
//! dictionary's `probe-programs` and `probe="true"`: Renishaw `G65 P9810`, Siemens
//! `CYCLE977`, Heidenhain `TCH PROBE`); `around.rs` tells a lathe program's statement by the
//! blocks around it (the move before a lathe cycle its start point, the blocks its `P` and `Q`
//! name its contour); `rename.rs` finds labels renamed one to one over both
//! programs (no change); `retrace.rs` finds straight moves written in other pieces along
//! the same path at the same feed (no change); `height.rs` tells an absolute height the later
//! incremental moves start from; `verdict.rs` says what the edit breaks or fixes (errors the control
//! stops at in one version only, matched by kind at the same statement first; a file of
//! subroutine definitions only, with no program end outside them, where the dictionary requires
//! one, as the stop it is run as a program), listed first.
//! Toolpath changes whose moves read values the file never sets are told without sizes. `mod.rs`: alignment of workingsteps (Needleman–Wunsch on a similarity of operation,
//! tool geometry, cutting length and toolpath box) and typed `Change`s: machine state (work
//! offset, offset numbers, compensation, stops, dwells, block delete, spindle mode),
//! technology, holes and cycle parameters, features, strategy and depths of cut, risky edits,
//! and toolpath changes localised to the moves that differ (the shared start and end set
//! aside in linear time, the rest measured with a grid of pieces: lines in both programs,
//! region, largest deviation, each point's distance taken to the other side's arcs
//! themselves, not to chords of them). Moves that go the same way along the same path in
//! other pieces (an arc written in turns or halves, a line in two: `same_trace`, every
//! sampled point within the tolerance of the other side's point as far along) are no change.
//! Values are written in the original's units. Heights (clearance between cuts, approach,
//! retract) and plunge feeds are compared where no cycle's parameters say them; a start point
//! moved with the cuts otherwise the same folds the feature change it causes into its own
//! sentence.

mod account;
mod around;
mod control;
mod follow;
mod function;
mod height;
mod moved;
mod place;
mod rename;
mod retrace;
mod setup;
pub mod statement;
mod turning;
mod typed;
pub mod verdict;

use std::collections::BTreeSet;

use serde::{Deserialize, Serialize};

use crate::canon::Units;
use crate::plan::risk::{self, work_offset_name};
use crate::plan::{
    BBox, Coolant, Dwell, FeatureKind, Hole, Move, MoveKind, P3, Phase, ProcessPlan, SpindleDir, Stop, StrategyKind, Toolpath, Workingstep,
    geom,
};

/// Kind of change.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChangeKind {
    /// Same operation, other tool number.
    ToolRenamed,
    /// The first cutting position moved.
    StartPointMoved,
    /// A cutting feed changed.
    FeedChanged,
    /// The spindle speed changed.
    SpindleSpeedChanged,
    /// The spindle direction changed.
    SpindleDirectionChanged,
    /// Coolant changed.
    CoolantChanged,
    /// The lowest cutting Z changed.
    DepthChanged,
    /// The cutting moves changed beyond start point and depth.
    ToolpathChanged,
    /// A workingstep exists only in the edited program.
    WorkingstepAdded,
    /// A workingstep exists only in the original.
    WorkingstepRemoved,
    /// The work offset (G54…) changed.
    WorkOffsetChanged,
    /// The length offset number (H) changed.
    LengthOffsetChanged,
    /// Cutter compensation side or offset number changed.
    CutterCompChanged,
    /// A program stop (M00) or optional stop (M01) was added.
    StopAdded,
    /// A program stop or optional stop was removed.
    StopRemoved,
    /// A dwell was added, removed or changed.
    DwellChanged,
    /// Moves now depend, or no longer depend, on the block-delete switch.
    OptionalBlockChanged,
    /// Constant surface speed was turned on or off.
    SpindleModeChanged,
    /// The feed override was turned off (M49, M50 P0) or on again for the workingstep.
    FeedOverrideChanged,
    /// A canned-cycle parameter changed: peck, dwell, R level, retract plane.
    CycleParameterChanged,
    /// A hole exists only in the edited program.
    HoleAdded,
    /// A hole exists only in the original.
    HoleRemoved,
    /// A hole the edited program drills elsewhere by the same cycle (`moved.rs`).
    HoleMoved,
    /// A feature's kind or dimensions changed.
    FeatureChanged,
    /// A wall or floor allowance changed.
    AllowanceChanged,
    /// The stepover between passes changed.
    StepoverChanged,
    /// The depth of cut per layer changed.
    AxialDepthChanged,
    /// The milling strategy changed.
    StrategyChanged,
    /// The edited program has a risky setting the original has not.
    RiskyEdit,
    /// The height of the rapids between cuts (ISO 14649's security plane) changed.
    ClearanceChanged,
    /// The height the tool comes down to in rapid before it feeds changed.
    ApproachChanged,
    /// The height the tool leaves to after its last cut (the retract plane) changed.
    RetractChanged,
    /// The feed of the moves straight down changed, the cutting feeds not.
    PlungeFeedChanged,
    /// A statement differs in program terms: a variable, a call's argument, a word, a jump.
    StatementChanged,
    /// A statement that only shows or writes text (a message, `DPRNT`) or names the program.
    OutputChanged,
    /// A return-point or machine-coordinate move (`G28`, `G30`, `G53`) added, removed or changed.
    ReturnMoveChanged,
    /// A move of a rotary axis (`G0 A90.`) added, removed or changed.
    RotaryMoveChanged,
    /// The working plane (`G17`, `G18`, `G19`) changed.
    PlaneChanged,
    /// The units lengths are read in (`G20`, `G21`) changed.
    UnitsChanged,
    /// The edited program has an error the control stops at that the original has not.
    ProgramBroken,
    /// The original's error the control stops at is gone from the edited program.
    ProgramFixed,
    /// The tilted work plane the workingstep runs on changed (`PLANE SPATIAL`, `CYCLE800`,
    /// `G68.2`): its angles, or its origin.
    WorkPlaneChanged,
    /// A thread's pitch (the lead of its synchronised moves) changed.
    ThreadPitchChanged,
    /// Which blocks run, or how often, changed: a condition, a loop's bound, a jump's target,
    /// a repeat count, a break or return, a call of a subprogram added or removed.
    FlowChanged,
    /// A machine function the plan has no kind for changed: an M-code or G-code the dictionary
    /// names (an output, a wait on an input, the path mode, a lookahead limit) or one it does
    /// not know (a machine builder's M88), with its words.
    MachineFunctionChanged,
    /// A global variable the file sets and does not read (LinuxCNC `#<_paranoid>`) changed,
    /// was set or no longer is: a value for the subroutines and programs that run after it.
    GlobalVariableChanged,
    /// A probing move (LinuxCNC `G38.2`–`G38.5`, Fanuc's skip `G31`: the dictionary's probe
    /// codes) changed where the plan does not tell it: its target, its feed, or which probe
    /// move it is, also through a variable it reads; or a measuring cycle's (the dictionary's
    /// `probe-programs` and `probe="true"`: Renishaw `G65 P9810`, Siemens `CYCLE977`,
    /// Heidenhain `TCH PROBE`) target, feed, cycle or parameter.
    ProbingChanged,
    /// A tool table's entry the program writes (Heidenhain `FN 17: SYSWRITE ID50 NR9 IDX5 =
    /// +30`) other than a length or radius, which are length-offset and cutter-compensation
    /// changes: a tool life, the number of teeth, a wear or break tolerance, a column the
    /// dictionary does not name; with the column, the tool and the values.
    ToolDataChanged,
}

impl ChangeKind {
    /// snake_case name, as stored.
    pub fn as_str(self) -> &'static str {
        match self {
            ChangeKind::ToolRenamed => "tool_renamed",
            ChangeKind::StartPointMoved => "start_point_moved",
            ChangeKind::FeedChanged => "feed_changed",
            ChangeKind::SpindleSpeedChanged => "spindle_speed_changed",
            ChangeKind::SpindleDirectionChanged => "spindle_direction_changed",
            ChangeKind::CoolantChanged => "coolant_changed",
            ChangeKind::DepthChanged => "depth_changed",
            ChangeKind::ToolpathChanged => "toolpath_changed",
            ChangeKind::WorkingstepAdded => "workingstep_added",
            ChangeKind::WorkingstepRemoved => "workingstep_removed",
            ChangeKind::WorkOffsetChanged => "work_offset_changed",
            ChangeKind::LengthOffsetChanged => "length_offset_changed",
            ChangeKind::CutterCompChanged => "cutter_comp_changed",
            ChangeKind::StopAdded => "stop_added",
            ChangeKind::StopRemoved => "stop_removed",
            ChangeKind::DwellChanged => "dwell_changed",
            ChangeKind::OptionalBlockChanged => "optional_block_changed",
            ChangeKind::SpindleModeChanged => "spindle_mode_changed",
            ChangeKind::FeedOverrideChanged => "feed_override_changed",
            ChangeKind::CycleParameterChanged => "cycle_parameter_changed",
            ChangeKind::HoleAdded => "hole_added",
            ChangeKind::HoleRemoved => "hole_removed",
            ChangeKind::HoleMoved => "hole_moved",
            ChangeKind::FeatureChanged => "feature_changed",
            ChangeKind::AllowanceChanged => "allowance_changed",
            ChangeKind::StepoverChanged => "stepover_changed",
            ChangeKind::AxialDepthChanged => "axial_depth_changed",
            ChangeKind::StrategyChanged => "strategy_changed",
            ChangeKind::RiskyEdit => "risky_edit",
            ChangeKind::ClearanceChanged => "clearance_changed",
            ChangeKind::ApproachChanged => "approach_changed",
            ChangeKind::RetractChanged => "retract_changed",
            ChangeKind::PlungeFeedChanged => "plunge_feed_changed",
            ChangeKind::StatementChanged => "statement_changed",
            ChangeKind::OutputChanged => "output_changed",
            ChangeKind::ReturnMoveChanged => "return_move_changed",
            ChangeKind::RotaryMoveChanged => "rotary_move_changed",
            ChangeKind::PlaneChanged => "plane_changed",
            ChangeKind::UnitsChanged => "units_changed",
            ChangeKind::ProgramBroken => "program_broken",
            ChangeKind::ProgramFixed => "program_fixed",
            ChangeKind::WorkPlaneChanged => "work_plane_changed",
            ChangeKind::ThreadPitchChanged => "thread_pitch_changed",
            ChangeKind::FlowChanged => "flow_changed",
            ChangeKind::MachineFunctionChanged => "machine_function_changed",
            ChangeKind::GlobalVariableChanged => "global_variable_changed",
            ChangeKind::ProbingChanged => "probing_changed",
            ChangeKind::ToolDataChanged => "tool_data_changed",
        }
    }
}

/// Where a change is seen: its line in the original and in the edited program; one side
/// `None` for a statement only the other program has.
pub type Located = (Option<u32>, Option<u32>);

/// One semantic change.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Change {
    /// Kind.
    pub kind: ChangeKind,
    /// Workingstep index: the original's, or the edited plan's for an added one.
    pub workingstep: u32,
    /// The workingstep's operation label.
    pub operation: String,
    /// The changed field.
    pub field: String,
    /// Value in the original, as a planner writes it.
    pub before: String,
    /// Value in the edited program.
    pub after: String,
    /// 1-based line in the edited program, when the change is visible there.
    pub line: Option<u32>,
    /// 1-based line in the original, when the change is visible there.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub original_line: Option<u32>,
    /// For a toolpath change: the box around the moves that differ, in both programs, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub region: Option<BBox>,
    /// For a toolpath change: the largest distance from a point of one toolpath to the
    /// other where they differ, mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub deviation: Option<f64>,
    /// Where else it is seen, what it may cause, where its statements end.
    #[serde(flatten)]
    pub detail: Detail,
}

/// What a change says beyond its row's columns: where else it is seen, what it causes, where
/// its run of statements ends. Stored as JSON beside the row.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Detail {
    /// The differing statements the change is seen at, as (original line, edited line); one
    /// side `None` for a statement only the other program has.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub at: Vec<Located>,
    /// For a statement change: the plan changes no statement explains, which it may cause.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub effect: Option<String>,
    /// Last line of a run of statements in the edited program, from `line`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub line_end: Option<u32>,
    /// Last line of a run of statements in the original, from `original_line`.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub original_line_end: Option<u32>,
}

impl Change {
    /// The change's detail as stored: JSON, or empty when it has none.
    pub fn detail_json(&self) -> String {
        if self.detail == Detail::default() { String::new() } else { serde_json::to_string(&self.detail).unwrap_or_default() }
    }

    /// Sets the detail from its stored JSON (empty or unreadable: none).
    pub fn set_detail(&mut self, json: &str) {
        if !json.is_empty() {
            self.detail = serde_json::from_str(json).unwrap_or_default();
        }
    }

    /// The change as a planner reads it: `tool T1 renamed T8`.
    pub fn phrase(&self) -> String {
        // The kind's words with blanks (`work_plane`), a variable it came through and a
        // subprogram a parameter belongs to as written.
        // (A parameter's field is its name as written: `parameter #<z_clearance> of O<PROBE>`.)
        let named = if self.field.starts_with("parameter ") { Some(0) } else { None };
        let field = match named.or_else(|| self.field.find(" (via ")) {
            Some(i) => format!("{}{}", self.field[..i].replace('_', " "), &self.field[i..]),
            None => self.field.replace('_', " "),
        };
        let at = |l: Option<u32>| l.map_or(String::new(), |l| format!(" at line {l}"));
        if let Some(s) = self.tool_table_phrase(&field) {
            return s;
        }
        let core = match self.kind {
            ChangeKind::ToolRenamed if !self.before.is_empty() && !self.after.is_empty() => {
                format!("tool {} renamed {}", self.before, self.after)
            }
            ChangeKind::ProgramBroken => {
                return format!("the edit breaks the program: {}{} ({})", self.after, at(self.line), self.field);
            }
            ChangeKind::ProgramFixed => {
                let at = at(self.original_line).replace("line", "original line");
                return format!("the edit fixes the program: no longer {}{at} ({})", self.before, self.field);
            }
            ChangeKind::StartPointMoved => format!("start point moved from {} to {}", self.before, self.after),
            // The workingsteps a repeated one is also in, after its own parenthesis, not inside it.
            ChangeKind::WorkingstepAdded | ChangeKind::WorkingstepRemoved => {
                let (verb, what) =
                    if self.kind == ChangeKind::WorkingstepAdded { ("added", &self.after) } else { ("removed", &self.before) };
                match what.rfind(" (also in workingstep").filter(|_| what.ends_with(')')) {
                    Some(i) => return format!("workingstep {verb} ({}){}, {}", &what[..i], self.located(), &what[i + 2..what.len() - 1]),
                    None => format!("workingstep {verb} ({what})"),
                }
            }
            // Stops at several statements (identical `M0`s removed together) at all their lines.
            ChangeKind::StopAdded if self.detail.at.len() > 1 => return format!("{} added{}", self.after, self.located()),
            ChangeKind::StopRemoved if self.detail.at.len() > 1 => return format!("{} removed{}", self.before, self.located()),
            ChangeKind::StopAdded => return format!("{} added{}", self.after, at(self.line)),
            ChangeKind::StopRemoved => {
                return format!("{} removed{}", self.before, at(self.original_line).replace("line", "original line"));
            }
            ChangeKind::HoleAdded => format!("hole added at {}", self.after),
            ChangeKind::HoleRemoved => format!("hole at {} removed", self.before),
            ChangeKind::HoleMoved => format!("hole at {} moved to {}", self.before, self.after),
            ChangeKind::RiskyEdit => return format!("warning: {}", self.after),
            ChangeKind::OptionalBlockChanged => format!("{} {}", self.before, self.after),
            ChangeKind::GlobalVariableChanged if self.field.starts_with("return value ") => {
                let var = &self.field["return value ".len()..];
                let what = match (self.before.is_empty(), self.after.is_empty()) {
                    (true, _) => format!("now returns {}", self.after),
                    (_, true) => format!("no longer returns a value (was {})", self.before),
                    _ => format!("returns {} instead of {}", self.after, self.before),
                };
                return format!("the subroutine {what}{}: `{var}` for the program that called it", at(self.line));
            }
            ChangeKind::GlobalVariableChanged => {
                let var = self.field.strip_prefix("variable ").unwrap_or(&self.field);
                let what = match (self.before.is_empty(), self.after.is_empty()) {
                    (true, _) => format!("set to {}", self.after),
                    (_, true) => format!("no longer set (was {})", self.before),
                    _ => format!("{} → {}", self.before, self.after),
                };
                format!("global variable `{var}` {what}, for the subroutines and programs that run after (this file does not read it)")
            }
            ChangeKind::FlowChanged if self.field == "passes" => format!("call runs {} → {} times", self.before, self.after),
            ChangeKind::RetractChanged if self.field == "retract_path" => {
                format!("the way the tool leaves the part after its last cut changed: {} → {}", self.before, self.after)
            }
            ChangeKind::ClearanceChanged if self.field == "rapid height" => {
                return match (self.before.is_empty(), self.after.is_empty()) {
                    (true, _) => format!("rapid height (clearance, approach) `{}` added{}", self.after, at(self.line)),
                    (_, true) => format!(
                        "rapid height (clearance, approach) `{}` removed{}",
                        self.before,
                        at(self.original_line).replace("line", "original line")
                    ),
                    _ => format!("rapid height (clearance, approach) changed from `{}` to `{}`{}", self.before, self.after, at(self.line)),
                };
            }
            ChangeKind::ClearanceChanged => {
                let via = self.field.find(" (via ").map_or("", |i| &self.field[i..]);
                format!("clearance height between cuts changed from {} to {}{via}", self.before, self.after)
            }
            ChangeKind::ToolpathChanged if self.field == FROM_UNKNOWN => {
                let mut s = format!("toolpath changed{}", at(self.line));
                if let Some(l) = self.original_line
                    && Some(l) != self.line
                {
                    s.push_str(&format!(" (line {l} in the original)"));
                }
                return format!("{s}: {}", self.after);
            }
            // A contour a lathe cycle names (`contour of G71`), in its words.
            ChangeKind::ToolpathChanged if !self.field.starts_with("moves") && !self.field.starts_with("contour of ") => {
                let mut s = format!("toolpath changed{}", at(self.line));
                if let Some(l) = self.original_line
                    && Some(l) != self.line
                {
                    s.push_str(&format!(" (line {l} in the original)"));
                }
                return format!("{s}: {} became {}", self.before, self.after);
            }
            ChangeKind::StatementChanged | ChangeKind::OutputChanged => return self.statement_phrase(),
            // A value followed to such a move (`G53 G0 X#<setter_x>`) reads as the others.
            ChangeKind::ReturnMoveChanged if !self.field.contains(" (via ") => {
                return format!("return move: {}", self.statement_phrase());
            }
            ChangeKind::RotaryMoveChanged => return format!("rotary axis move: {}", self.statement_phrase()),
            // A tilt statement no plan row names (no cut follows it), as written.
            ChangeKind::WorkPlaneChanged if self.field == "work plane" => return format!("work plane: {}", self.statement_phrase()),
            ChangeKind::WorkPlaneChanged => {
                let mut s = match self.field.as_str() {
                    "work_plane" => setup::phrase(&self.before, &self.after),
                    "cylinder" => format!("work plane {} → {}", self.before, self.after),
                    _ => format!("work plane origin {} → {}", self.before, self.after),
                };
                if let Some(e) = &self.detail.effect {
                    s.push_str(&format!("; {e}"));
                }
                s
            }
            ChangeKind::MachineFunctionChanged => {
                // `machine function M66: wait on input`: the code, and what the dictionary calls it.
                // A variable or argument it came through (` (via #<raw_width>)`) is told after it.
                let what = self.field.strip_prefix("machine function ").unwrap_or(&self.field);
                let (what, via) = what.find(" (via ").map_or((what, ""), |i| (&what[..i], &what[i..]));
                let what = what.strip_prefix("machine function").unwrap_or(what).trim();
                let paren = |t: &str| if t.is_empty() { String::new() } else { format!(" ({t})") };
                match (self.before.is_empty(), self.after.is_empty()) {
                    (true, _) => format!("machine function `{}` added{}{via}", self.after, paren(what)),
                    (_, true) => format!("machine function `{}` removed{}{via}", self.before, paren(what)),
                    _ => {
                        let (code, name) = what.split_once(": ").unwrap_or(("", what));
                        let code = if code.is_empty() { String::new() } else { format!(" {code}") };
                        format!("machine function{code}{}{via} changed from {} to {}", paren(name), self.before, self.after)
                    }
                }
            }
            _ if self.before.is_empty() => format!("{field} {} added", self.after),
            _ if self.after.is_empty() => format!("{field} {} removed", self.before),
            _ => format!("{field} changed from {} to {}", self.before, self.after),
        };
        format!("{core}{}", self.located())
    }

    /// A tool table's entry written or read as system data (`FN 17: SYSWRITE ID50 NR1 IDX5 =
    /// +0`, `FN 18: SYSREAD Q1 = ID50 NR1 IDX5`), where the change is one.
    fn tool_table_phrase(&self, field: &str) -> Option<String> {
        let read = self.kind == ChangeKind::StatementChanged
            && (self.field.contains(" read from tool table ") || self.field.starts_with("read from tool table "));
        let written = matches!(self.kind, ChangeKind::ToolDataChanged | ChangeKind::LengthOffsetChanged | ChangeKind::CutterCompChanged)
            && self.field.starts_with("tool table ");
        let core = match (self.before.is_empty(), self.after.is_empty()) {
            _ if !read && !written => return None,
            (true, _) if read => format!("{field} added"),
            (_, true) if read => format!("{field} removed"),
            (true, _) => format!("{field} set to {}", self.after),
            (_, true) => format!("{field} no longer set (was {})", self.before),
            _ => format!("{field} changed from {} to {}", self.before, self.after),
        };
        Some(format!("{core}{}", self.located()))
    }

    /// Where a located plan change is seen: ` at line 12`, ` at lines 12, 18 and 24`,
    /// ` at original line 7` where only the original has the statements.
    fn located(&self) -> String {
        let edited: Vec<u32> = self.detail.at.iter().filter_map(|a| a.1).collect();
        let (lines, prefix) = if edited.is_empty() {
            (self.detail.at.iter().filter_map(|a| a.0).collect::<Vec<u32>>(), " at original line")
        } else {
            (edited, " at line")
        };
        let shown: Vec<String> = lines.iter().take(3).map(u32::to_string).collect();
        let more = lines.len().saturating_sub(3);
        match (shown.len(), more) {
            (0, _) => String::new(),
            (1, _) => format!("{prefix} {}", shown[0]),
            (n, 0) => format!("{prefix}s {} and {}", shown[..n - 1].join(", "), shown[n - 1]),
            _ => format!("{prefix}s {} and {more} more", shown.join(", ")),
        }
    }

    /// A statement change in program terms.
    fn statement_phrase(&self) -> String {
        let loc = match (self.original_line, self.line) {
            (Some(o), Some(e)) if o != e => format!(" at line {e} (line {o} in the original)"),
            (_, Some(e)) => format!(" at line {e}"),
            (Some(o), None) => format!(" at original line {o}"),
            (None, None) => String::new(),
        };
        let (b, a) = (&self.before, &self.after);
        let mut s = if let Some(var) = self.field.strip_prefix("variable ") {
            match (b.is_empty(), a.is_empty()) {
                (false, false) => format!("variable `{var}` set to {a} instead of {b}{loc}"),
                (true, _) => format!("variable `{var}` set to {a}{loc}"),
                (false, true) => format!("`{var}={b}` removed{loc}"),
            }
        } else if let Some(name) = self.field.strip_prefix("call ").and_then(|c| c.strip_suffix(" rebound")) {
            format!(
                "call `{name}` passes {a} instead of {b}, its subroutine's parameters renumbered alike: each parameter it reads gets the value it got{loc}"
            )
        } else if let Some(call) = self.field.strip_prefix("call ") {
            let (name, arg) = call.rsplit_once(" argument ").unwrap_or((call, "?"));
            match (b.as_str(), a.as_str()) {
                ("none", _) => format!("call `{name}`: argument {arg} ({a}) inserted{loc}"),
                (_, "none") => format!("call `{name}`: argument {arg} ({b}) removed{loc}"),
                _ => format!("call `{name}` argument {arg}: {a} instead of {b}{loc}"),
            }
        } else if self.field == "statements" {
            let from = match (self.original_line, self.detail.original_line_end) {
                (Some(f), Some(l)) if f != l => format!(" at original lines {f}–{l}"),
                (Some(f), _) => format!(" at original line {f}"),
                _ => String::new(),
            };
            // The original's lines once: where the replaced statements already name them, not again.
            let named = self.original_line.is_some_and(|f| b.contains(&format!("line {f}")) || b.contains(&format!("lines {f}–")));
            format!("{a} in place of {b}{}", if from.is_empty() || named { String::new() } else { format!(" ({})", from.trim_start()) })
        } else {
            match (b.is_empty(), a.is_empty()) {
                (false, false) => format!("`{a}` instead of `{b}`{loc}"),
                (true, false) => format!("`{a}` added{loc}"),
                (false, true) => format!("`{b}` removed{loc}"),
                (true, true) => format!("statement changed{loc}"),
            }
        };
        if self.kind == ChangeKind::OutputChanged {
            s.push_str(" (output only)");
        }
        if let Some(e) = &self.detail.effect {
            s.push_str(&format!("; its effect: {e}"));
        }
        s
    }

    /// Whether the change is about what the machine does (not only what it shows or writes).
    pub fn is_machining(&self) -> bool {
        self.kind != ChangeKind::OutputChanged
    }
}

/// Geometric tolerance for positions, mm.
pub const TOLERANCE: f64 = 1e-4;

/// How values are written: in the original program's units.
#[derive(Clone, Copy)]
pub(crate) struct Fmt {
    pub(crate) inch: bool,
}

impl Fmt {
    /// A coordinate, without a unit.
    fn c(self, mm: f64) -> String {
        num(if self.inch { mm / 25.4 } else { mm })
    }

    /// A length with its unit.
    fn len(self, mm: f64) -> String {
        format!("{} {}", self.c(mm), if self.inch { "in" } else { "mm" })
    }

    fn feed(self, mm_per_min: f64) -> String {
        format!("F{}", self.c(mm_per_min))
    }

    fn surface(self, m_per_min: f64) -> String {
        if self.inch { format!("{} ft/min", num(m_per_min / 0.3048)) } else { format!("{} m/min", num(m_per_min)) }
    }

    fn xy(self, p: [f64; 2]) -> String {
        format!("X{} Y{}", self.c(p[0]), self.c(p[1]))
    }

    fn point(self, p: P3, other: Option<P3>) -> String {
        let mut s = self.xy([p[0], p[1]]);
        if other.is_none_or(|o| (o[2] - p[2]).abs() > TOLERANCE) {
            s.push_str(&format!(" Z{}", self.c(p[2])));
        }
        s
    }
}

pub use account::Program;

/// The changes from `original` to `edited`: the plan's changes, each located at the
/// statements that show it, and a statement change for every other statement that differs
/// after the cosmetic normalisation (block numbers, comments, blanks, case, number
/// spellings). Every differing statement is named by at least one change; debug builds
/// check it.
pub fn compare(original: Program<'_>, edited: Program<'_>) -> Vec<Change> {
    compare_with_findings(original, edited, (&[], &[]))
}

/// [`compare`], with what the edit breaks or fixes told from the errors of the two programs'
/// analyses (`findings`: the original's and the edited one's, as [`verdict::faults`] gives
/// them); without any, from the errors reading their blocks finds.
pub fn compare_with_findings(
    original: Program<'_>,
    edited: Program<'_>,
    findings: (&[statement::Fault], &[statement::Fault]),
) -> Vec<Change> {
    // The lines of reference returns and machine-coordinate moves (`G28 U0. W0.`, `G53`): the
    // positions their moves reach are the machine's, which the plan takes at work zero, so a
    // lathe's way off the part stops there ([`turning::retract`]).
    let returns = |p: &Program<'_>| -> BTreeSet<u32> {
        if !p.plan.workingsteps.iter().any(|w| w.turning.is_some()) {
            return BTreeSet::new();
        }
        let (stmts, _) = statement::read(p.text, p.dialect);
        stmts.iter().filter(|s| s.moves & statement::RETURN_MOVE != 0).flat_map(|s| s.line..=s.last).collect()
    };
    let (ra, rb) = (returns(&original), returns(&edited));
    let (mut changes, pairs) = plan_changes(original.plan, edited.plan, (&ra, &rb));
    // Statements compare within one language; a program and its translation, or a CL file
    // and its post, compare by their plans.
    if original.dialect.name == edited.dialect.name {
        account::account(original, edited, &pairs, &mut changes, findings);
    }
    unknown_sizes(&mut changes, (original.plan, edited.plan), findings);
    changes
}

/// The field of a toolpath change whose moves read values the file never sets.
const FROM_UNKNOWN: &str = "toolpath from unknown values";

/// Toolpath changes whose moves, on either side, read a value the file never sets (a global
/// another program sets, `X[#<xe>+#<_td>/2]`; a caller's argument): the analysis leaves such a
/// word out and keeps the tool where it was, so the sizes and places it would tell (a path
/// "56.7 mm shorter", a start point at X0) are the analysis's, not the machine's. Told
/// without them, with the lines that read the unknown values; a start point moved there is
/// that same change.
fn unknown_sizes(changes: &mut Vec<Change>, (pa, pb): (&ProcessPlan, &ProcessPlan), (fa, fb): (&[statement::Fault], &[statement::Fault])) {
    let unknown = |f: &[statement::Fault]| -> BTreeSet<u32> {
        f.iter().filter(|f| f.code == crate::diag::Code::UnknownValue).map(|f| f.line).collect()
    };
    let (ua, ub) = (unknown(fa), unknown(fb));
    if ua.is_empty() && ub.is_empty() {
        return;
    }
    // The lines of the unknown values a workingstep's moves read, at a line of it.
    let reads = |p: &ProcessPlan, u: &BTreeSet<u32>, line: Option<u32>| -> Vec<u32> {
        let Some(line) = line else { return Vec::new() };
        p.workingsteps
            .iter()
            .filter(|w| (w.lines.0..=w.lines.1).contains(&line) || w.toolpath.iter().any(|m| m.line == line))
            .flat_map(|w| w.toolpath.iter().map(|m| m.line).filter(|l| u.contains(l)))
            .collect::<BTreeSet<u32>>()
            .into_iter()
            .collect()
    };
    let mut seen: BTreeSet<u32> = BTreeSet::new();
    let mut k = 0;
    while k < changes.len() {
        let c = &changes[k];
        let sized = matches!(c.kind, ChangeKind::ToolpathChanged | ChangeKind::StartPointMoved) && !c.field.starts_with("moves");
        let (ra, rb) = if sized { (reads(pa, &ua, c.original_line), reads(pb, &ub, c.line)) } else { (Vec::new(), Vec::new()) };
        if ra.is_empty() && rb.is_empty() {
            k += 1;
            continue;
        }
        // One such change for a workingstep.
        if !seen.insert(c.workingstep) {
            let mut at = changes[k].detail.at.clone();
            at.push((changes[k].original_line, changes[k].line));
            let first = changes.iter().position(|d| d.field == FROM_UNKNOWN && d.workingstep == changes[k].workingstep);
            if let Some(f) = first {
                changes[f].detail.at.extend(at);
                changes[f].detail.at.sort_by_key(|&(o, e)| (e.or(o), o));
                changes[f].detail.at.dedup();
            }
            changes.remove(k);
            continue;
        }
        let list = |side: &str, l: &[u32]| {
            (!l.is_empty()).then(|| format!("line{} {} {side}", if l.len() == 1 { "" } else { "s" }, join_lines(l)))
        };
        let sides: Vec<String> = [list("in the original", &ra), list("in the edited program", &rb)].into_iter().flatten().collect();
        let c = &mut changes[k];
        c.kind = ChangeKind::ToolpathChanged;
        c.field = FROM_UNKNOWN.into();
        c.before = String::new();
        c.after = format!("its moves read values the file never sets ({}): no size is told", sides.join("; "));
        c.region = None;
        c.deviation = None;
        k += 1;
    }
}

/// Lines as a planner reads them: `91, 95 and 99`, the first three and how many more.
fn join_lines(l: &[u32]) -> String {
    let shown: Vec<String> = l.iter().take(3).map(u32::to_string).collect();
    match (shown.len(), l.len().saturating_sub(3)) {
        (1, _) => shown[0].clone(),
        (n, 0) => format!("{} and {}", shown[..n - 1].join(", "), shown[n - 1]),
        (_, more) => format!("{} and {more} more", shown.join(", ")),
    }
}

/// [`compare_with_findings`]'s changes with a call's arguments followed into the subroutines
/// the edited program calls from other files (`programs`: those beside it, as its analysis
/// found them): an argument changed in place (same argument count) is told as what the parameter it
/// binds does there (a feed, a height, a condition), where the dictionary knows it.
pub fn follow_calls(changes: &mut Vec<Change>, edited: Program<'_>, programs: &dyn crate::interp::ProgramSource) {
    follow::calls(changes, edited, programs);
}

/// [`compare_with_findings`]'s changes with each call whose argument count changed compared
/// by what reaches the subroutine it calls (`before`: the programs beside the original,
/// `after`: those beside the edited one): old call with old subroutine against new call with
/// new subroutine, parameter by parameter (see `follow::rebound`). Before [`follow_calls`].
pub fn follow_rebound_calls(
    changes: &mut Vec<Change>,
    original: (Program<'_>, &dyn crate::interp::ProgramSource),
    edited: (Program<'_>, &dyn crate::interp::ProgramSource),
) {
    follow::rebound(changes, original, edited);
}

/// The differing statements of two programs no change in `changes` names, as (original
/// line, edited line): empty when the comparison accounts for every edit.
pub fn unaccounted(original: Program<'_>, edited: Program<'_>, changes: &[Change]) -> Vec<Located> {
    if original.dialect.name != edited.dialect.name {
        return Vec::new();
    }
    account::unaccounted(original, edited, changes)
}

/// The changes from `original` to `edited` the plans alone show, in workingstep order
/// (for plans whose programs are not at hand).
pub fn diff(original: &ProcessPlan, edited: &ProcessPlan) -> Vec<Change> {
    plan_changes(original, edited, (&BTreeSet::new(), &BTreeSet::new())).0
}

/// The source lines of each side's reference returns and machine-coordinate moves.
type ReturnLines<'r> = (&'r BTreeSet<u32>, &'r BTreeSet<u32>);

/// Aligned workingsteps: positions in the original's and the edited plan's list.
type Pairs = Vec<(Option<usize>, Option<usize>)>;

fn plan_changes(original: &ProcessPlan, edited: &ProcessPlan, returns: ReturnLines<'_>) -> (Vec<Change>, Pairs) {
    let (a, b) = (&original.workingsteps, &edited.workingsteps);
    let u = Fmt { inch: original.units == Some(Units::Inch) };
    let pairs = align(original, edited);
    let mut out = Vec::new();
    let mut features_seen = BTreeSet::new();
    for &(i, j) in &pairs {
        match (i, j) {
            (Some(i), Some(j)) => compare_workingsteps(original, &a[i], edited, &b[j], u, returns, &mut features_seen, &mut out),
            (Some(i), None) => out.push(Change {
                kind: ChangeKind::WorkingstepRemoved,
                workingstep: a[i].index,
                operation: a[i].label(),
                field: "workingstep".into(),
                before: summary(original, &a[i], u),
                after: String::new(),
                line: None,
                original_line: Some(a[i].lines.0),
                region: None,
                deviation: None,
                detail: crate::diff::Detail::default(),
            }),
            (None, Some(j)) => out.push(Change {
                kind: ChangeKind::WorkingstepAdded,
                workingstep: b[j].index,
                operation: b[j].label(),
                field: "workingstep".into(),
                before: String::new(),
                after: summary(edited, &b[j], u),
                line: Some(b[j].lines.0),
                original_line: None,
                region: None,
                deviation: None,
                detail: crate::diff::Detail::default(),
            }),
            (None, None) => {}
        }
    }
    // Risky settings the edit brought in, on the workingstep they concern.
    let had: BTreeSet<(crate::diag::Code, String)> = risk::risks(original)
        .into_iter()
        .map(|r| (r.code, a.iter().find(|w| w.index == r.workingstep).map_or(String::new(), |w| format!("T{}", w.tool))))
        .collect();
    for r in risk::risks(edited) {
        let Some(j) = b.iter().position(|w| w.index == r.workingstep) else { continue };
        if had.contains(&(r.code, format!("T{}", b[j].tool))) {
            continue;
        }
        let orig = pairs.iter().find(|p| p.1 == Some(j)).and_then(|p| p.0);
        let (index, operation) = orig.map_or((b[j].index, b[j].operation), |i| (a[i].index, a[i].operation));
        out.push(Change {
            kind: ChangeKind::RiskyEdit,
            workingstep: index,
            operation: operation.label().into(),
            field: r.code.as_str().trim_start_matches("plan::").into(),
            before: String::new(),
            after: r.message,
            line: Some(b[j].lines.0),
            original_line: orig.map(|i| a[i].lines.0),
            region: None,
            deviation: None,
            detail: crate::diff::Detail::default(),
        });
    }
    (out, pairs)
}

fn summary(plan: &ProcessPlan, ws: &Workingstep, u: Fmt) -> String {
    format!("{} with {}, {} of cut", ws.label(), tool_label(plan, ws.tool), u.len(ws.cutting_length))
}

/// A tool as the program names it: `T4`, or `T="EM10"` for a tool selected by name.
fn tool_label(plan: &ProcessPlan, t: u32) -> String {
    match plan.tool(t).and_then(|x| x.name.as_deref()) {
        Some(name) if t > 10_000 => format!("T=\"{name}\""),
        _ => format!("T{t}"),
    }
}

fn tool_diameter(plan: &ProcessPlan, t: u32) -> Option<f64> {
    plan.tools.iter().find(|x| x.number == t).and_then(|x| x.diameter)
}

/// Similarity of two workingsteps in 0..=1; pairs below [`MATCH_THRESHOLD`] do not align.
fn similarity(pa: &ProcessPlan, a: &Workingstep, pb: &ProcessPlan, b: &Workingstep) -> f64 {
    if !a.operation.same_family(b.operation) {
        return 0.0;
    }
    let mut s = 0.2;
    if a.operation == b.operation {
        s += 0.1;
    }
    match (tool_diameter(pa, a.tool), tool_diameter(pb, b.tool)) {
        (Some(x), Some(y)) if (x - y).abs() > 1e-3 => s -= 0.3,
        (Some(_), Some(_)) => s += 0.1,
        _ => {}
    }
    let (la, lb) = (a.cutting_length, b.cutting_length);
    if la.max(lb) > 0.0 {
        s += 0.2 * la.min(lb) / la.max(lb);
    } else {
        s += 0.2;
    }
    s += 0.4
        * match (a.bbox, b.bbox) {
            (Some(x), Some(y)) => {
                // The plane the two spread over: XY, or XZ where both are turning workingsteps
                // (the plan read them as a lathe's turning), neither leaves Y = 0 and one
                // spreads along Z (a lathe's turning, whose Y is always 0: in XY no two of its
                // workingsteps would ever overlap). A milling or drilling workingstep flat in
                // Y is compared in XY as any other.
                let flat = |bb: crate::plan::BBox, i: usize| bb.max[i] - bb.min[i] <= 1e-9;
                let turning = a.turning.is_some() && b.turning.is_some();
                let xz = turning && flat(x, 1) && flat(y, 1) && x.min[1] == y.min[1] && !(flat(x, 2) && flat(y, 2));
                let axes = if xz { [0, 2] } else { [0, 1] };
                let inter: f64 = axes.iter().map(|&i| (x.max[i].min(y.max[i]) - x.min[i].max(y.min[i])).max(0.0)).product();
                let area = |bb: crate::plan::BBox| axes.iter().map(|&i| (bb.max[i] - bb.min[i]).max(1e-3)).product::<f64>();
                let union = area(x) + area(y) - inter;
                if union > 0.0 { inter / union } else { 0.0 }
            }
            (None, None) => 1.0,
            _ => 0.0,
        };
    s.clamp(0.0, 1.0)
}

const MATCH_THRESHOLD: f64 = 0.35;

/// Global alignment maximising total similarity; deterministic tie-breaking prefers a match,
/// then a removal.
fn align(pa: &ProcessPlan, pb: &ProcessPlan) -> Vec<(Option<usize>, Option<usize>)> {
    let (a, b) = (&pa.workingsteps, &pb.workingsteps);
    let (n, m) = (a.len(), b.len());
    let sim: Vec<Vec<f64>> = a.iter().map(|x| b.iter().map(|y| similarity(pa, x, pb, y)).collect()).collect();
    let mut score = vec![vec![0.0f64; m + 1]; n + 1];
    for i in (0..n).rev() {
        for j in (0..m).rev() {
            let mut best = score[i + 1][j].max(score[i][j + 1]);
            if sim[i][j] >= MATCH_THRESHOLD {
                best = best.max(sim[i][j] + score[i + 1][j + 1]);
            }
            score[i][j] = best;
        }
    }
    let (mut i, mut j, mut out) = (0, 0, Vec::new());
    while i < n || j < m {
        if i < n && j < m && sim[i][j] >= MATCH_THRESHOLD && (score[i][j] - (sim[i][j] + score[i + 1][j + 1])).abs() < 1e-12 {
            out.push((Some(i), Some(j)));
            i += 1;
            j += 1;
        } else if i < n && (j == m || (score[i][j] - score[i + 1][j]).abs() < 1e-12) {
            out.push((Some(i), None));
            i += 1;
        } else {
            out.push((None, Some(j)));
            j += 1;
        }
    }
    out
}

pub use crate::text::num;

fn spindle_words(s: SpindleDir) -> &'static str {
    match s {
        SpindleDir::Cw => "clockwise (M3)",
        SpindleDir::Ccw => "counter-clockwise (M4)",
        SpindleDir::Off => "stopped (M5)",
    }
}

fn coolant_words(c: Coolant) -> &'static str {
    match c {
        Coolant::Off => "off",
        Coolant::Mist => "mist (M7)",
        Coolant::Flood => "flood (M8)",
        Coolant::Both => "mist and flood (M7 and M8)",
    }
}

fn strategy_words(k: StrategyKind) -> &'static str {
    match k {
        StrategyKind::Bidirectional => "zig-zag passes",
        StrategyKind::Unidirectional => "one-way passes",
        StrategyKind::ContourParallel => "contour-parallel loops",
        StrategyKind::ContourSpiral => "a spiral",
        StrategyKind::CenterMilling => "along the centre line",
        StrategyKind::Explicit => "the programmed toolpath",
    }
}

fn stop_words(s: &Stop) -> &'static str {
    if s.optional { "optional stop (M01)" } else { "program stop (M00)" }
}

fn length_offset_words(list: &[u32], tool: u32) -> String {
    if list.is_empty() {
        return format!("the tool's own (H{tool})");
    }
    list.iter().map(|h| if *h == 0 { "none (H0)".to_owned() } else { format!("H{h}") }).collect::<Vec<_>>().join(", ")
}

fn comp_words(list: &[crate::plan::CompUse], tool: u32) -> String {
    if list.is_empty() {
        return "off (G40)".into();
    }
    list.iter()
        .map(|c| {
            let side = if c.left { "left (G41)" } else { "right (G42)" };
            match c.number {
                Some(n) => format!("{side} with D{n}"),
                None => format!("{side} with the tool's own D{tool}"),
            }
        })
        .collect::<Vec<_>>()
        .join(", ")
}

#[allow(clippy::too_many_arguments)]
fn compare_workingsteps(
    pa: &ProcessPlan,
    a: &Workingstep,
    pb: &ProcessPlan,
    b: &Workingstep,
    u: Fmt,
    returns: ReturnLines<'_>,
    features_seen: &mut BTreeSet<(u32, u32)>,
    out: &mut Vec<Change>,
) {
    let first = out.len();
    let mut push = |kind: ChangeKind, field: &str, before: String, after: String, lines: (Option<u32>, Option<u32>)| {
        out.push(Change {
            kind,
            workingstep: a.index,
            operation: a.label(),
            field: field.into(),
            before,
            after,
            line: lines.1,
            original_line: lines.0,
            region: None,
            deviation: None,
            detail: crate::diff::Detail::default(),
        });
    };
    let at_start = (Some(a.lines.0), Some(b.lines.0));
    if tool_label(pa, a.tool) != tool_label(pb, b.tool) {
        push(ChangeKind::ToolRenamed, "tool", tool_label(pa, a.tool), tool_label(pb, b.tool), at_start);
    }
    // On a lathe, in a turner's terms (`turning`): no feed per minute, no lowest Z.
    let lathe = a.turning.is_some() && b.turning.is_some();
    if lathe {
        turning::start(a, b, u, &mut push);
        turning::retract(a, b, u, returns, &mut push);
    } else {
        compare_start(a, b, u, &mut push);
    }
    compare_state(a, b, &mut push);
    let (feeds_differ, depth_change) =
        if lathe { (turning::technology(a, b, u, &mut push), None) } else { compare_technology(a, b, u, &mut push) };
    // Heights and feeds beside the cutting ones, where no canned cycle's parameters say them.
    if a.holes.is_empty() && b.holes.is_empty() && !lathe {
        heights(a, b, (feeds_differ, part_top(pb)), u, &mut push, at_start);
    }
    let mut explained = false;
    // Holes and their cycle parameters.
    if a.operation.is_hole() || b.operation.is_hole() {
        explained |= compare_holes(&a.holes, &b.holes, depth_change, u, &mut push);
    }
    // Where one plan knows the stock and the other not, what follows from the stock (a face
    // or pocket clipped to it, and not swept by the tool; the depth of a single layer below
    // its top) differs by knowledge, not by machining: not compared (the toolpath still tells
    // a change).
    let stock_alike = pa.workpiece.is_some() == pb.workpiece.is_some();
    explained |= if lathe { turning::cutting(a, b, u, &mut push) } else { compare_cutting(a, b, stock_alike, u, &mut push) };
    // The features, once per pair.
    if let (Some(fa), Some(fb)) = (a.feature.and_then(|f| pa.feature(f)), b.feature.and_then(|f| pb.feature(f)))
        && stock_alike
    {
        if features_seen.insert((fa.id, fb.id)) {
            explained |= compare_features(fa, fb, depth_change.is_some(), u, &mut push);
        } else if lathe {
            // A contour roughed and finished (`G71`/`G70 P Q`, or in explicit passes) is one
            // feature: its edit is what changed this workingstep's cuts too (told once, with
            // the workingsteps it is also in).
            explained |= compare_features(fa, fb, depth_change.is_some(), u, &mut push);
        }
    }
    if lathe {
        turning::fold_derived(first, out);
    }
    if !explained && let Some(tp) = toolpath_difference(a, b, depth_change, u) {
        out.push(Change {
            kind: ChangeKind::ToolpathChanged,
            workingstep: a.index,
            operation: a.label(),
            field: "toolpath".into(),
            before: tp.before,
            after: tp.after,
            line: tp.lines.1,
            original_line: tp.lines.0,
            region: tp.region,
            deviation: Some(tp.deviation),
            detail: crate::diff::Detail::default(),
        });
    }
    fold_into_start_point(a, b, depth_change, u, first, out);
    moved::fold_start(first, out);
    setup::compare(pa, a, b, u, first, out);
}

/// The start point, unless it only sinks with the depth or only rises over a hole (the
/// depth's, the R level's or the axial depth's change says it).
fn compare_start(a: &Workingstep, b: &Workingstep, u: Fmt, push: &mut Push<'_>) {
    let at_start = (Some(a.lines.0), Some(b.lines.0));
    let depth_delta = match (a.depth, b.depth) {
        (Some(x), Some(y)) => y - x,
        _ => 0.0,
    };
    if let (Some(x), Some(y)) = (a.start_point, b.start_point)
        && geom::dist(x, y) > TOLERANCE
    {
        // A start point that only sinks with the depth is the depth change, reported below.
        let only_depth =
            (x[0] - y[0]).abs() <= TOLERANCE && (x[1] - y[1]).abs() <= TOLERANCE && (y[2] - x[2] - depth_delta).abs() <= TOLERANCE;
        // Over a hole, only the height moves: the R level's change says it.
        // Over a hole, or with another depth of cut, only the height moves: the R level's or
        // the axial depth's change says it.
        let axial = match (a.axial_depth, b.axial_depth) {
            (Some(p), Some(q)) => (p - q).abs() > TOLERANCE,
            (p, q) => p.is_some() != q.is_some(),
        };
        let hole_height = (a.operation.is_hole() || axial) && (x[0] - y[0]).abs() <= TOLERANCE && (x[1] - y[1]).abs() <= TOLERANCE;
        if !only_depth && !hole_height {
            push(ChangeKind::StartPointMoved, "start_point", u.point(x, Some(y)), u.point(y, Some(x)), at_start);
        }
    }
}

/// The machine state the workingstep runs in: feed override, work offset, length offset,
/// cutter compensation, stops, dwells and block-delete.
fn compare_state(a: &Workingstep, b: &Workingstep, push: &mut Push<'_>) {
    let at_start = (Some(a.lines.0), Some(b.lines.0));
    // The machine state.
    let (sa, sb) = (&a.state, &b.state);
    if sa.feed_override_off != sb.feed_override_off {
        let words = |off: bool| if off { "off (the programmed feed, whatever the dial)" } else { "on" }.to_owned();
        push(ChangeKind::FeedOverrideChanged, "feed_override", words(sa.feed_override_off), words(sb.feed_override_off), at_start);
    }
    if sa.work_offset != sb.work_offset {
        push(ChangeKind::WorkOffsetChanged, "work_offset", work_offset_name(sa.work_offset), work_offset_name(sb.work_offset), at_start);
    }
    // By the numbers in force: `T1 H1` renamed `T8 H1` keeps its offset (the risk is told apart).
    let numbers = |list: &[u32], tool: u32| if list.is_empty() { vec![tool] } else { list.to_vec() };
    let both_own = sa.length_offsets.is_empty() && sb.length_offsets.is_empty();
    if !both_own && numbers(&sa.length_offsets, a.tool) != numbers(&sb.length_offsets, b.tool) {
        let (x, y) = (length_offset_words(&sa.length_offsets, a.tool), length_offset_words(&sb.length_offsets, b.tool));
        push(ChangeKind::LengthOffsetChanged, "length_offset", x, y, at_start);
    }
    let (ca, cb) = (comp_words(&sa.cutter_comp, a.tool), comp_words(&sb.cutter_comp, b.tool));
    if sa.cutter_comp != sb.cutter_comp && ca != cb {
        push(ChangeKind::CutterCompChanged, "cutter_compensation", ca, cb, at_start);
    }
    let (removed, added) = unmatched(&sa.stops, &sb.stops, |s| (s.optional, s.at), |s| s.optional);
    for s in removed {
        push(ChangeKind::StopRemoved, "stop", stop_words(s).into(), String::new(), (Some(s.line), None));
    }
    for s in added {
        push(ChangeKind::StopAdded, "stop", String::new(), stop_words(s).into(), (None, Some(s.line)));
    }
    dwells(&sa.dwells, &sb.dwells, push);
    if !a.operation.is_hole() && sa.optional_lines.is_empty() != sb.optional_lines.is_empty() {
        let lines = |v: &[u32]| match v {
            [l] => format!("line {l}"),
            [f, .., l] => format!("lines {f}–{l}"),
            [] => String::new(),
        };
        let (o, e) = (sa.optional_lines.first().copied(), sb.optional_lines.first().copied());
        if sb.optional_lines.is_empty() {
            push(
                ChangeKind::OptionalBlockChanged,
                "optional_block",
                format!("the moves at {}", lines(&sa.optional_lines)),
                "no longer depend on the block-delete switch".into(),
                (o, e),
            );
        } else {
            push(
                ChangeKind::OptionalBlockChanged,
                "optional_block",
                format!("the moves at {}", lines(&sb.optional_lines)),
                "now depend on the block-delete switch".into(),
                (o, e),
            );
        }
    }
}

/// Feeds, spindle, coolant and depth; whether the feeds differ, and the depth's change.
fn compare_technology(a: &Workingstep, b: &Workingstep, u: Fmt, push: &mut Push<'_>) -> (bool, Option<(f64, f64)>) {
    let at_start = (Some(a.lines.0), Some(b.lines.0));
    // Technology.
    let (ta, tb) = (&a.technology, &b.technology);
    let feeds_differ = ta.feeds.len() != tb.feeds.len() || ta.feeds.iter().zip(&tb.feeds).any(|(x, y)| (x - y).abs() > TOLERANCE);
    if feeds_differ {
        let f = |v: &[f64]| v.iter().map(|x| u.feed(*x)).collect::<Vec<_>>().join(", ");
        push(ChangeKind::FeedChanged, "feed", f(&ta.feeds), f(&tb.feeds), at_start);
    }
    match (ta.surface_speed, tb.surface_speed) {
        (None, None) => {
            if (ta.spindle_speed - tb.spindle_speed).abs() > TOLERANCE {
                let s = |v: f64| format!("S{}", num(v));
                push(ChangeKind::SpindleSpeedChanged, "spindle_speed", s(ta.spindle_speed), s(tb.spindle_speed), at_start);
            }
        }
        (Some(x), Some(y)) => {
            if (x - y).abs() > TOLERANCE {
                push(ChangeKind::SpindleSpeedChanged, "surface_speed", u.surface(x), u.surface(y), at_start);
            }
        }
        (x, y) => {
            let mode = |v: Option<f64>, rpm: f64| match v {
                Some(v) => format!("constant surface speed {} (G96)", u.surface(v)),
                None => format!("S{} 1/min (G97)", num(rpm)),
            };
            push(ChangeKind::SpindleModeChanged, "spindle_mode", mode(x, ta.spindle_speed), mode(y, tb.spindle_speed), at_start);
        }
    }
    if ta.spindle != tb.spindle {
        push(
            ChangeKind::SpindleDirectionChanged,
            "spindle_direction",
            spindle_words(ta.spindle).into(),
            spindle_words(tb.spindle).into(),
            at_start,
        );
    }
    if ta.coolant != tb.coolant {
        push(ChangeKind::CoolantChanged, "coolant", coolant_words(ta.coolant).into(), coolant_words(tb.coolant).into(), at_start);
    }
    let depth_change = match (a.depth, b.depth) {
        (Some(x), Some(y)) if (x - y).abs() > TOLERANCE => Some((x, y)),
        _ => None,
    };
    // On a cylinder's developed surface (cylindrical interpolation) the plane's Z is the radius
    // the tool cuts at: told as the diameter of the bottom and the depth below the cylinder.
    let cylinders = (a.setup.and_then(|s| s.cylinder), b.setup.and_then(|s| s.cylinder));
    if let (Some((x, y)), (Some(da), Some(db))) = (depth_change, cylinders) {
        let words = |z: f64, d: f64| format!("Ø{} ({} deep on the Ø{} cylinder)", u.c(2.0 * z), u.c(d / 2.0 - z), u.c(d));
        push(ChangeKind::DepthChanged, "depth", words(x, da), words(y, db), at_start);
    } else if let Some((x, y)) = depth_change {
        push(ChangeKind::DepthChanged, "depth", format!("Z{}", u.c(x)), format!("Z{}", u.c(y)), at_start);
    }
    (feeds_differ, depth_change)
}

/// Strategy, depths of cut and allowances; whether any of them explains a toolpath change.
fn compare_cutting(a: &Workingstep, b: &Workingstep, stock_alike: bool, u: Fmt, push: &mut Push<'_>) -> bool {
    let at_start = (Some(a.lines.0), Some(b.lines.0));
    let mut explained = false;
    // Strategy, depths of cut and allowances.
    let opt = |v: Option<f64>| v.map_or_else(|| "none".to_owned(), |v| u.len(v));
    let differs = |x: Option<f64>, y: Option<f64>| match (x, y) {
        (Some(x), Some(y)) => (x - y).abs() > TOLERANCE,
        (None, None) => false,
        _ => true,
    };
    if !a.operation.is_hole() && differs(a.radial_depth, b.radial_depth) {
        push(ChangeKind::StepoverChanged, "stepover", opt(a.radial_depth), opt(b.radial_depth), at_start);
        explained = true;
    }
    // A single layer's depth is known from the stock's top only.
    let axial_known_alike = stock_alike || a.axial_depth.is_some() == b.axial_depth.is_some();
    if !a.operation.is_hole() && axial_known_alike && differs(a.axial_depth, b.axial_depth) {
        push(ChangeKind::AxialDepthChanged, "axial_depth", opt(a.axial_depth), opt(b.axial_depth), at_start);
        explained = true;
    }
    if differs(a.allowance_side, b.allowance_side) {
        push(ChangeKind::AllowanceChanged, "wall_allowance", opt(a.allowance_side), opt(b.allowance_side), at_start);
        explained = true;
    }
    if differs(a.allowance_bottom, b.allowance_bottom) {
        push(ChangeKind::AllowanceChanged, "floor_allowance", opt(a.allowance_bottom), opt(b.allowance_bottom), at_start);
        explained = true;
    }
    if let (Some(x), Some(y)) = (&a.strategy, &b.strategy)
        && x.kind != y.kind
    {
        push(ChangeKind::StrategyChanged, "strategy", strategy_words(x.kind).into(), strategy_words(y.kind).into(), at_start);
        explained = true;
    }
    explained
}

/// A start point moved with the cuts otherwise the same: a feature that grows or shrinks by
/// it only restates it. The feature changes go, and the start point's change says what the
/// move means (`the first cut now starts 14 mm further out, in air`).
fn fold_into_start_point(a: &Workingstep, b: &Workingstep, depth: Option<(f64, f64)>, u: Fmt, first: usize, out: &mut Vec<Change>) {
    let Some(k) = (first..out.len()).find(|&k| out[k].kind == ChangeKind::StartPointMoved) else { return };
    if !out[first..].iter().any(|c| c.kind == ChangeKind::FeatureChanged) || toolpath_difference(a, b, depth, u).is_some() {
        return;
    }
    let (Some(x), Some(y)) = (a.start_point, b.start_point) else { return };
    let d = ((y[0] - x[0]).powi(2) + (y[1] - x[1]).powi(2)).sqrt();
    let mut note = format!(" (the first cut now starts {}", u.len(d));
    if let Some(bb) = a.bbox {
        let centre = [(bb.min[0] + bb.max[0]) / 2.0, (bb.min[1] + bb.max[1]) / 2.0];
        let from_centre = |p: P3| (p[0] - centre[0]).hypot(p[1] - centre[1]);
        note.push_str(if from_centre(y) > from_centre(x) { " further out" } else { " further in" });
        let inside = (0..2).all(|i| y[i] >= bb.min[i] - TOLERANCE && y[i] <= bb.max[i] + TOLERANCE);
        if !inside {
            note.push_str(", in air");
        }
    }
    note.push(')');
    out[k].after.push_str(&note);
    let mut i = 0;
    out.retain(|c| {
        let keep = i < first || c.kind != ChangeKind::FeatureChanged;
        i += 1;
        keep
    });
}

/// The top of the part, where the program or the configuration states its stock: the
/// stock's top face, and where its size comes from.
#[derive(Clone, Copy)]
pub(crate) struct PartTop {
    /// Z of the stock's top, mm.
    pub z: f64,
    /// The program line that states the stock (`BLK FORM`, a stock comment); `None` for the
    /// configured stock.
    pub line: Option<u32>,
}

/// The part's top in `plan`, where its stock is known.
pub(crate) fn part_top(plan: &ProcessPlan) -> Option<PartTop> {
    plan.workpiece.as_ref().map(|s| PartTop { z: s.max()[2], line: s.line })
}

impl PartTop {
    /// What a height moved from `before` to `after` (mm) says about the part: that it now lies
    /// below the part's top, naming the reference; `None` where it does not cross it.
    pub(crate) fn crossed(self, before: f64, after: f64, u: Fmt) -> Option<String> {
        if !(before >= self.z - TOLERANCE && after < self.z - TOLERANCE) {
            return None;
        }
        let from = match self.line {
            Some(l) => format!("the stock stated at line {l}"),
            None => "the configured stock".to_owned(),
        };
        Some(format!(" (now below the part's top Z{}, the top of {from})", u.c(self.z)))
    }
}

type Push<'a> = dyn FnMut(ChangeKind, &str, String, String, (Option<u32>, Option<u32>)) + 'a;

/// The heights a workingstep moves at between its cuts (ISO 14649's security plane), comes
/// down to before it feeds (the approach height) and leaves to (the retract plane), and the
/// feeds it plunges at, where the cutting feeds did not change.
fn heights(
    a: &Workingstep,
    b: &Workingstep,
    (feeds_differ, top): (bool, Option<PartTop>),
    u: Fmt,
    push: &mut Push<'_>,
    at: (Option<u32>, Option<u32>),
) {
    let z = |v: f64| format!("Z{}", u.c(v));
    // Heights that read the same in the program's units are the same (a rounding).
    let differs = |x: Option<f64>, y: Option<f64>| match (x, y) {
        (Some(x), Some(y)) => (x - y).abs() > TOLERANCE && z(x) != z(y),
        _ => false,
    };
    let (ca, cb) = (clearance(a), clearance(b));
    if differs(ca, cb) {
        let (x, y) = (ca.unwrap_or_default(), cb.unwrap_or_default());
        let note = top.and_then(|t| t.crossed(x, y, u)).unwrap_or_default();
        push(ChangeKind::ClearanceChanged, "clearance_height", z(x), format!("{}{note}", z(y)), at);
    }
    let (pa, pb) = (approach(a), approach(b));
    if differs(pa.map(|p| p.0), pb.map(|p| p.0)) {
        let (x, y) = (pa.expect("compared"), pb.expect("compared"));
        let note = top.and_then(|t| t.crossed(x.0, y.0, u)).unwrap_or_default();
        push(ChangeKind::ApproachChanged, "approach_height", z(x.0), format!("{}{note}", z(y.0)), (Some(x.1), Some(y.1)));
    }
    let (ra, rb) = (retract(a), retract(b));
    if differs(ra.map(|r| r.0), rb.map(|r| r.0)) {
        let (x, y) = (ra.expect("compared"), rb.expect("compared"));
        let note = top.and_then(|t| t.crossed(x.0, y.0, u)).unwrap_or_default();
        push(ChangeKind::RetractChanged, "retract_height", z(x.0), format!("{}{note}", z(y.0)), (Some(x.1), Some(y.1)));
    }
    let (fa, fb) = (plunge_feeds(a), plunge_feeds(b));
    if !feeds_differ
        && !fa.is_empty()
        && !fb.is_empty()
        && (fa.len() != fb.len() || fa.iter().zip(&fb).any(|(x, y)| (x - y).abs() > TOLERANCE))
    {
        let f = |v: &[f64]| v.iter().map(|x| u.feed(*x)).collect::<Vec<_>>().join(", ");
        push(ChangeKind::PlungeFeedChanged, "plunge_feed", f(&fa), f(&fb), at);
    }
}

/// The security plane: the highest rapid between the cuts, where the workingstep has more
/// than one cut to go between.
fn clearance(w: &Workingstep) -> Option<f64> {
    let between = w.toolpath.iter().any(|m| m.phase == Phase::Connect);
    between.then_some(w.security_plane)
}

/// The height the tool comes down to in rapid before its first feed, and that line.
fn approach(w: &Workingstep) -> Option<(f64, u32)> {
    let mut last_rapid = None;
    for m in w.toolpath.iter() {
        if m.kind == MoveKind::Rapid {
            last_rapid = Some(m);
        } else {
            return last_rapid.filter(|r| r.to[2] > m.to[2] + TOLERANCE).map(|r| (r.to[2], r.line));
        }
    }
    None
}

/// The height the tool leaves to after its last cut, and that line.
fn retract(w: &Workingstep) -> Option<(f64, u32)> {
    let last_cut = w.toolpath.iter().rposition(|m| m.phase == Phase::Cut)?;
    w.toolpath.iter().skip(last_cut + 1).filter(|m| m.to[2] > m.from[2] + TOLERANCE).map(|m| (m.to[2], m.line)).next()
}

/// The distinct feeds of the moves straight down along Z, in order of first use.
fn plunge_feeds(w: &Workingstep) -> Vec<f64> {
    let mut out: Vec<f64> = Vec::new();
    for m in w.toolpath.iter() {
        let down = m.kind == MoveKind::Line && (m.to[0] - m.from[0]).abs() <= TOLERANCE && (m.to[1] - m.from[1]).abs() <= TOLERANCE;
        if down && m.to[2] < m.from[2] - TOLERANCE && !out.iter().any(|f| (f - m.feed).abs() <= TOLERANCE) {
            out.push(m.feed);
        }
    }
    out
}

/// The items of `a` and `b` that have no counterpart: first paired by `key`, then what is
/// left by `kind` in order (the same stop after a toolpath that changed before it).
fn unmatched<'x, T, K: PartialEq, G: PartialEq>(
    a: &'x [T],
    b: &'x [T],
    key: impl Fn(&T) -> K,
    kind: impl Fn(&T) -> G,
) -> (Vec<&'x T>, Vec<&'x T>) {
    let mut used = vec![false; b.len()];
    let mut left = Vec::new();
    for x in a {
        match (0..b.len()).find(|&j| !used[j] && key(&b[j]) == key(x)) {
            Some(j) => used[j] = true,
            None => left.push(x),
        }
    }
    let mut removed = Vec::new();
    for x in left {
        match (0..b.len()).find(|&j| !used[j] && kind(&b[j]) == kind(x)) {
            Some(j) => used[j] = true,
            None => removed.push(x),
        }
    }
    let added = b.iter().zip(&used).filter(|(_, u)| !**u).map(|(x, _)| x).collect();
    (removed, added)
}

fn dwells(a: &[Dwell], b: &[Dwell], push: &mut Push<'_>) {
    let secs = |d: &Dwell| format!("{} s", num(d.seconds));
    let n = a.len().min(b.len());
    for (x, y) in a.iter().zip(b) {
        if (x.seconds - y.seconds).abs() > 1e-9 {
            push(ChangeKind::DwellChanged, "dwell", secs(x), secs(y), (Some(x.line), Some(y.line)));
        }
    }
    for x in &a[n..] {
        push(ChangeKind::DwellChanged, "dwell", secs(x), String::new(), (Some(x.line), None));
    }
    for y in &b[n..] {
        push(ChangeKind::DwellChanged, "dwell", String::new(), secs(y), (None, Some(y.line)));
    }
}

/// Holes added, removed, optional, and cycle parameters changed; whether anything was.
fn compare_holes(a: &[Hole], b: &[Hole], depth: Option<(f64, f64)>, u: Fmt, push: &mut Push<'_>) -> bool {
    let same_xy = |h: &Hole, k: &Hole| (h.x - k.x).abs() <= TOLERANCE && (h.y - k.y).abs() <= TOLERANCE;
    let mut used = vec![false; b.len()];
    let mut pairs = Vec::new();
    let mut removed = Vec::new();
    for h in a {
        match (0..b.len()).find(|&j| !used[j] && same_xy(h, &b[j])) {
            Some(j) => {
                used[j] = true;
                pairs.push((h, &b[j]));
            }
            None => removed.push(h),
        }
    }
    let added: Vec<&Hole> = b.iter().zip(&used).filter(|(_, u)| !**u).map(|(k, _)| k).collect();
    // Moved where made alike, else removed and added.
    let mut any = moved::tell(&removed, &added, depth, u, push);
    for (h, k) in &pairs {
        if h.optional != k.optional {
            let what = format!("the hole at {}", u.xy([h.x, h.y]));
            let now = if k.optional { "now depends on the block-delete switch" } else { "no longer depends on the block-delete switch" };
            push(ChangeKind::OptionalBlockChanged, "optional_block", what, now.into(), (None, None));
            any = true;
        }
    }
    // One change per parameter: all holes alike, or the first that differs, by position.
    type Param = (&'static str, fn(&Hole) -> Option<f64>, fn(Fmt, f64) -> String);
    let params: [Param; 5] = [
        ("peck", |h| h.peck, |u, v| format!("Q{}", u.c(v))),
        ("dwell", |h| h.dwell, |_, v| format!("{} s", num(v))),
        ("r_level", |h| Some(h.r_plane), |u, v| format!("Z{}", u.c(v))),
        ("retract_plane", |h| h.retract, |u, v| format!("Z{}", u.c(v))),
        ("hole_bottom", |h| Some(h.bottom), |u, v| format!("Z{}", u.c(v))),
    ];
    for (field, get, show) in params {
        let map_bottom = |h: &Hole, v: Option<f64>| match (field, depth) {
            ("hole_bottom", Some((old, new))) if (h.bottom - old).abs() <= TOLERANCE => Some(new),
            _ => v,
        };
        let differs: Vec<&(&Hole, &Hole)> = pairs
            .iter()
            .filter(|(h, k)| {
                let (x, y) = (map_bottom(h, get(h)), get(k));
                match (x, y) {
                    (Some(x), Some(y)) => (x - y).abs() > TOLERANCE,
                    (None, None) => false,
                    _ => true,
                }
            })
            .collect();
        let Some((h, k)) = differs.first() else { continue };
        let v = |x: Option<f64>| x.map_or_else(|| "none".to_owned(), |x| show(u, x));
        let (mut before, mut after) = (v(get(h)), v(get(k)));
        // A hole that kept the depth the others left: compared with the depth told above,
        // not with its own unchanged one (no "Z-10 to Z-10").
        let told = map_bottom(h, get(h));
        if told != get(h) {
            before = format!("{} (the depth told above)", v(told));
        }
        if differs.len() < pairs.len() {
            before = format!("{before} at {}", u.xy([h.x, h.y]));
            after = format!("{after} at {}", u.xy([k.x, k.y]));
        }
        push(ChangeKind::CycleParameterChanged, field, before, after, (None, None));
        any = true;
    }
    any
}

/// A feature's kind and dimensions; whether anything changed.
fn compare_features(fa: &crate::plan::Feature, fb: &crate::plan::Feature, depth_reported: bool, u: Fmt, push: &mut Push<'_>) -> bool {
    let mut any = false;
    if fa.kind.label() != fb.kind.label() {
        push(ChangeKind::FeatureChanged, "feature", fa.kind.label().into(), fb.kind.label().into(), (Some(fa.lines.0), Some(fb.lines.0)));
        return true;
    }
    let mut dim = |field: &str, x: Option<f64>, y: Option<f64>| {
        if let (Some(x), Some(y)) = (x, y)
            && (x - y).abs() > TOLERANCE
        {
            push(ChangeKind::FeatureChanged, field, u.len(x), u.len(y), (Some(fa.lines.0), Some(fb.lines.0)));
            any = true;
        }
    };
    // A hole's depth to its full diameter follows from what is known of the drill (its
    // diameter, its point): known on one side only, the depths differ by knowledge, not by
    // machining; the programmed bottom is compared with the cycle's parameters.
    let known_alike = |f: &crate::plan::Feature| (f.sources.size, f.sources.point_angle, std::mem::discriminant(&f.kind));
    let hole = matches!(fa.kind, FeatureKind::RoundHole { .. });
    if !depth_reported && (!hole || known_alike(fa) == known_alike(fb)) {
        dim("feature_depth", Some(fa.depth), Some(fb.depth));
    }
    match (&fa.kind, &fb.kind) {
        (
            FeatureKind::ClosedPocket { rectangle: ra, corner_radius: cra, .. },
            FeatureKind::ClosedPocket { rectangle: rb, corner_radius: crb, .. },
        ) => {
            dim("pocket_width", ra.map(|r| r.0), rb.map(|r| r.0));
            dim("pocket_length", ra.map(|r| r.1), rb.map(|r| r.1));
            dim("corner_radius", *cra, *crb);
        }
        (FeatureKind::RoundHole { diameter: da, .. }, FeatureKind::RoundHole { diameter: db, .. }) => dim("hole_diameter", *da, *db),
        (FeatureKind::PlanarFace { length: la, width: wa, .. }, FeatureKind::PlanarFace { length: lb, width: wb, .. })
        | (FeatureKind::Step { length: la, width: wa, .. }, FeatureKind::Step { length: lb, width: wb, .. }) => {
            dim("feature_length", Some(*la), Some(*lb));
            dim("feature_width", Some(*wa), Some(*wb));
        }
        (FeatureKind::Slot { width: wa, .. }, FeatureKind::Slot { width: wb, .. }) => dim("slot_width", Some(*wa), Some(*wb)),
        (FeatureKind::Turned(ta), FeatureKind::Turned(tb)) => {
            let at = (Some(fa.lines.0), Some(fb.lines.0));
            turning::turned_dims((ta, fa.placement[2]), (tb, fb.placement[2]), u, &mut |field, x, y| {
                push(ChangeKind::FeatureChanged, field, x, y, at);
                any = true;
            });
        }
        _ => {}
    }
    any
}

/// What differs between two toolpaths, and where.
struct ToolpathDifference {
    before: String,
    after: String,
    /// First differing line in the original and in the edited program.
    lines: (Option<u32>, Option<u32>),
    region: Option<BBox>,
    deviation: f64,
}

/// Compares the cutting moves; a depth change maps the old lowest Z onto the new one first,
/// so that it is not reported twice. The moves both toolpaths share at their start and at
/// their end are set aside (linear time), and the rest is measured: its lines, its box and
/// the largest distance from a point of one side to the other side's path (a grid of
/// segments keeps that near-linear).
fn toolpath_difference(a: &Workingstep, b: &Workingstep, depth: Option<(f64, f64)>, u: Fmt) -> Option<ToolpathDifference> {
    let (ca, cb) = (Cuts::of(a), Cuts::of(b));
    let at = |t: &Cuts<'_>, i: usize| t.get(i).expect("an index within the cuts");
    let map_z = |z: f64| match depth {
        Some((old, new)) if (z - old).abs() <= TOLERANCE => new,
        _ => z,
    };
    let close =
        |p: P3, q: P3| (p[0] - q[0]).abs() <= TOLERANCE && (p[1] - q[1]).abs() <= TOLERANCE && (map_z(p[2]) - q[2]).abs() <= TOLERANCE;
    let same = |x: &Move, y: &Move| {
        x.kind == y.kind
            && close(x.to, y.to)
            && x.turns() == y.turns()
            && match (x.center(), y.center()) {
                (Some(p), Some(q)) => (p[0] - q[0]).abs() <= TOLERANCE && (p[1] - q[1]).abs() <= TOLERANCE,
                (None, None) => true,
                _ => false,
            }
    };
    let (na, nb) = (ca.len(), cb.len());
    let mut p = 0;
    {
        let mut both = ca.iter().zip(cb.iter());
        while p < na.min(nb) && both.next().is_some_and(|(x, y)| same(&x, &y)) {
            p += 1;
        }
    }
    let mut s = 0;
    while s < na.min(nb) - p && same(&at(&ca, na - 1 - s), &at(&cb, nb - 1 - s)) {
        s += 1;
    }
    if p == na && p == nb {
        return None;
    }
    // The same way along the same path, in other pieces (an arc written in turns or halves,
    // a line in two): no change. Measured from the end, a move is shared only where it also
    // starts where its counterpart does (the second half of a line written in two ends where
    // the whole line does, and is not it).
    let mut whole = 0;
    while whole < s && {
        let (x, y) = (at(&ca, na - 1 - whole), at(&cb, nb - 1 - whole));
        close(x.from, y.from)
    } {
        whole += 1;
    }
    if same_trace(&ca, p..na - whole, &cb, p..nb - whole, &map_z) {
        return None;
    }
    // The differing moves of each side, as index ranges.
    let (ma, mb) = (p..na - s, p..nb - s);
    // The paths around the difference: from where the shared start ends to where the shared
    // end begins, so that a removed move is measured against the path that replaces it.
    let path = |all: &Cuts<'_>, from: usize, to: usize, z: &dyn Fn(f64) -> f64| -> Path {
        let mut pts = Vec::new();
        let mut arcs = vec![None];
        let start = if from > 0 { at(all, from - 1).to } else { all.get(from).map_or([0.0; 3], |m| m.from) };
        pts.push([start[0], start[1], z(start[2])]);
        let mut buf = Vec::new();
        for m in all.iter().take(to.min(all.len()) + 1).skip(from) {
            let piece = m.arc.map(|a| (a.center, a.axis));
            // An arc's pieces start at its start (after rapids, the last cut ended elsewhere).
            let start = [m.from[0], m.from[1], z(m.from[2])];
            if piece.is_some() && pts.last().is_some_and(|q| geom::dist(*q, start) > 1e-9) {
                pts.push(start);
                arcs.push(None);
            }
            buf.clear();
            geom::sample(&m, &mut buf);
            pts.extend(buf.iter().map(|q| [q[0], q[1], z(q[2])]));
            arcs.extend(buf.iter().map(|_| piece));
        }
        Path { pts, arcs }
    };
    let ident = |z: f64| z;
    // Original points in edited Z (the depth change mapped), so depth is not counted again.
    let pa = path(&ca, p, na - s, &map_z);
    let pb = path(&cb, p, nb - s, &ident);
    let deviation = hausdorff(&pa, &pb);
    let mut region = None;
    for q in pa.pts.iter().chain(&pb.pts) {
        geom::extend(&mut region, *q);
    }
    let first_line = |m: &std::ops::Range<usize>, all: &Cuts<'_>| {
        if m.is_empty() { all.get(p).or_else(|| all.last()) } else { all.get(m.start) }.map(|m| m.line)
    };
    let lines = (first_line(&ma, &ca), first_line(&mb, &cb));
    let len = |m: &std::ops::Range<usize>, all: &Cuts<'_>| all.iter().skip(m.start).take(m.len()).map(|m| geom::length(&m)).sum::<f64>();
    // The ends are written with Z only where the two differ in it.
    let end = |m: &std::ops::Range<usize>, all: &Cuts<'_>| (!m.is_empty()).then(|| at(all, m.end - 1).to);
    let (ea, eb) = (end(&ma, &ca), end(&mb, &cb));
    let describe = |m: &std::ops::Range<usize>, all: &Cuts<'_>, other: Option<P3>| -> String {
        match m.len() {
            0 => "no cut".into(),
            1 => {
                let one = at(all, m.start);
                format!("the cut at line {} to {}", one.line, u.point(one.to, other))
            }
            n => {
                let (f, l) = (at(all, m.start), at(all, m.end - 1));
                let (lo, hi) = (f.line.min(l.line), f.line.max(l.line));
                let at = if lo == hi { format!("line {lo}") } else { format!("lines {lo}–{hi}") };
                format!("the {n} cuts at {at}, ending at {}", u.point(l.to, other))
            }
        }
    };
    let before = describe(&ma, &ca, eb);
    let mut after = describe(&mb, &cb, ea);
    let (la, lb) = (len(&ma, &ca), len(&mb, &cb));
    if (la - lb).abs() > TOLERANCE {
        after.push_str(&format!(" ({} {})", u.len((la - lb).abs()), if lb < la { "shorter" } else { "longer" }));
    }
    if let Some(r) = region {
        after.push_str(&format!(", in X{}…{} Y{}…{}", u.c(r.min[0]), u.c(r.max[0]), u.c(r.min[1]), u.c(r.max[1])));
    }
    after.push_str(&format!(", at most {} from the original path", u.len(deviation)));
    Some(ToolpathDifference { before, after, lines, region, deviation: (deviation * 1e6).round() / 1e6 })
}

/// Whether moves `ra` of `a` and `rb` of `b` go the same way along the same path: every
/// point either side samples is within [`TOLERANCE`] of the other side's point as far along
/// its way, and the two ways are as long. Gaps between the cuts (rapids) count for nothing.
/// Passes over the toolpaths; no moves are collected.
fn same_trace(a: &Cuts<'_>, ra: std::ops::Range<usize>, b: &Cuts<'_>, rb: std::ops::Range<usize>, map_z: &dyn Fn(f64) -> f64) -> bool {
    let total = |t: &Cuts<'_>, r: &std::ops::Range<usize>| t.iter().skip(r.start).take(r.len()).map(|m| geom::length(&m)).sum::<f64>();
    if ra.is_empty() || rb.is_empty() || (total(a, &ra) - total(b, &rb)).abs() > TOLERANCE {
        return false;
    }
    let za = |q: P3| [q[0], q[1], map_z(q[2])];
    let ident = |q: P3| q;
    follows(a, &ra, &za, b, &rb, &ident) && follows(b, &rb, &ident, a, &ra, &za)
}

/// Whether every point moves `rx` of `x` sample (starts, arc samples, ends) lies within
/// [`TOLERANCE`] of the point as far along moves `ry` of `y`.
fn follows(
    x: &Cuts<'_>,
    rx: &std::ops::Range<usize>,
    xz: &dyn Fn(P3) -> P3,
    y: &Cuts<'_>,
    ry: &std::ops::Range<usize>,
    yz: &dyn Fn(P3) -> P3,
) -> bool {
    let mut ys = y.iter().skip(ry.start).take(ry.len());
    let Some(first) = ys.next() else { return false };
    // The move of `y` in hand and where along the way it starts and ends.
    let (mut cur, mut s0) = (first, 0.0);
    let mut s1 = geom::length(&cur);
    let mut next = ys.next();
    let mut xs = 0.0;
    let mut buf = Vec::new();
    for m in x.iter().skip(rx.start).take(rx.len()) {
        let len = geom::length(&m);
        buf.clear();
        buf.push(m.from);
        geom::sample(&m, &mut buf);
        let n = (buf.len() - 1).max(1) as f64;
        for (k, q) in buf.iter().enumerate() {
            // Samples are evenly spaced along the move (by angle on an arc).
            let s = xs + len * (k as f64 / n).min(1.0);
            // A move's start goes with the `y` move that starts there (after a gap), its
            // other points with the one they fall within.
            while let Some(nm) = next.filter(|_| if k == 0 { s >= s1 - 1e-9 } else { s > s1 + 1e-9 }) {
                (cur, s0) = (nm, s1);
                s1 += geom::length(&cur);
                next = ys.next();
            }
            let f = if s1 > s0 { ((s - s0) / (s1 - s0)).clamp(0.0, 1.0) } else { 1.0 };
            if geom::dist(xz(*q), yz(geom::point_at(&cur, f))) > TOLERANCE {
                return false;
            }
        }
        xs += len;
    }
    true
}

/// The cutting moves of a workingstep, by index into its toolpath: 4 bytes a move, so two
/// million-move toolpaths are compared without copies of them.
struct Cuts<'a> {
    toolpath: &'a Toolpath,
    index: Vec<u32>,
}

impl<'a> Cuts<'a> {
    fn of(w: &'a Workingstep) -> Cuts<'a> {
        let index = w
            .toolpath
            .iter()
            .enumerate()
            .filter(|(_, m)| m.phase == Phase::Cut && m.kind != MoveKind::Rapid)
            .map(|(i, _)| i as u32)
            .collect();
        Cuts { toolpath: &w.toolpath, index }
    }

    fn len(&self) -> usize {
        self.index.len()
    }

    fn get(&self, i: usize) -> Option<Move> {
        self.index.get(i).and_then(|&k| self.toolpath.get(k as usize))
    }

    fn last(&self) -> Option<Move> {
        self.len().checked_sub(1).and_then(|i| self.get(i))
    }

    fn iter(&self) -> impl Iterator<Item = Move> + '_ {
        self.index.iter().filter_map(|&k| self.toolpath.get(k as usize))
    }
}

/// A path as points along it (arcs sampled) and, for the piece ending at each point, the
/// arc it lies on (centre and axis), so that distances to it are taken to the arc itself and
/// not to a chord: two samplings of the same arc are then the same path.
struct Path {
    pts: Vec<P3>,
    arcs: Vec<Option<(P3, P3)>>,
}

/// The larger of the two directed distances between paths, each point of one measured to
/// the nearest piece (segment or arc piece) of the other.
fn hausdorff(a: &Path, b: &Path) -> f64 {
    directed(a, b).max(directed(b, a))
}

fn directed(from: &Path, to: &Path) -> f64 {
    let grid = Grid::new(&to.pts, &to.arcs);
    from.pts.iter().map(|p| grid.nearest(*p)).fold(0.0, f64::max)
}

/// Where piece `a`–`b` of an arc about `c` (axis `n`) is at the fraction `t` of its angle,
/// the radius and the height along the axis going from `a`'s to `b`'s in proportion; `None`
/// where the piece has no angle to speak of (a point at the centre, a piece of no sweep).
fn arc_point(a: P3, b: P3, (c, n): (P3, P3), p: Option<P3>, t: f64) -> Option<(P3, f64)> {
    let sub = |x: P3, y: P3| [x[0] - y[0], x[1] - y[1], x[2] - y[2]];
    let dot = |x: P3, y: P3| x[0] * y[0] + x[1] * y[1] + x[2] * y[2];
    let cross = |x: P3, y: P3| [x[1] * y[2] - x[2] * y[1], x[2] * y[0] - x[0] * y[2], x[0] * y[1] - x[1] * y[0]];
    let flat = |x: P3| {
        let v = sub(x, c);
        let h = dot(v, n);
        ([v[0] - h * n[0], v[1] - h * n[1], v[2] - h * n[2]], h)
    };
    let ((wa, ha), (wb, hb)) = (flat(a), flat(b));
    let (ra, rb) = (dot(wa, wa).sqrt(), dot(wb, wb).sqrt());
    let phi = dot(n, cross(wa, wb)).atan2(dot(wa, wb));
    if ra < 1e-9 || rb < 1e-9 || phi.abs() < 1e-12 {
        return None;
    }
    // The fraction of the piece's angle at which `p` lies, if given.
    let t = match p {
        Some(p) => {
            let (wp, _) = flat(p);
            dot(n, cross(wa, wp)).atan2(dot(wa, wp)) / phi
        }
        None => t,
    };
    let theta = phi * t;
    let u = [wa[0] / ra, wa[1] / ra, wa[2] / ra];
    let v = cross(n, u);
    let (r, h) = (ra + (rb - ra) * t, ha + (hb - ha) * t);
    let (s, k) = theta.sin_cos();
    Some((std::array::from_fn(|i| c[i] + r * (u[i] * k + v[i] * s) + h * n[i]), t))
}

/// Pieces of a path binned in XY cells, for nearest-piece queries.
struct Grid<'a> {
    pts: &'a [P3],
    arcs: &'a [Option<(P3, P3)>],
    cell: f64,
    min: [f64; 2],
    cols: i64,
    rows: i64,
    /// (cell, segment) sorted by cell.
    bins: Vec<((i64, i64), u32)>,
}

impl<'a> Grid<'a> {
    fn new(pts: &'a [P3], arcs: &'a [Option<(P3, P3)>]) -> Grid<'a> {
        let mut min = [f64::INFINITY; 2];
        let mut max = [f64::NEG_INFINITY; 2];
        for p in pts {
            for i in 0..2 {
                min[i] = min[i].min(p[i]);
                max[i] = max[i].max(p[i]);
            }
        }
        let n = pts.len().max(1) as f64;
        let extent = (max[0] - min[0]).max(max[1] - min[1]).max(1e-3);
        let total: f64 = pts.windows(2).map(|w| (w[1][0] - w[0][0]).hypot(w[1][1] - w[0][1])).sum();
        let cell = (total / n).max(extent / n.sqrt()).max(1e-3);
        let cols = ((max[0] - min[0]) / cell).floor() as i64 + 1;
        let rows = ((max[1] - min[1]) / cell).floor() as i64 + 1;
        let mut g = Grid { pts, arcs, cell, min, cols, rows, bins: Vec::with_capacity(pts.len()) };
        if pts.len() == 1 {
            g.bins.push(((0, 0), 0));
        }
        for i in 0..pts.len().saturating_sub(1) {
            let (c0, r0) = g.at(pts[i]);
            let (c1, r1) = g.at(pts[i + 1]);
            // An arc piece bulges past its chord: its middle point widens the cells.
            let mid = g.piece(i).and_then(|arc| arc_point(pts[i], pts[i + 1], arc, None, 0.5)).map_or((c0, r0), |(q, _)| g.at(q));
            let (clo, chi) = (c0.min(c1).min(mid.0), c0.max(c1).max(mid.0));
            let (rlo, rhi) = (r0.min(r1).min(mid.1), r0.max(r1).max(mid.1));
            for c in clo..=chi {
                for r in rlo..=rhi {
                    g.bins.push(((c, r), i as u32));
                }
            }
        }
        g.bins.sort_unstable();
        g
    }

    fn at(&self, p: P3) -> (i64, i64) {
        (((p[0] - self.min[0]) / self.cell).floor() as i64, ((p[1] - self.min[1]) / self.cell).floor() as i64)
    }

    /// The arc piece `i` (from point `i` to point `i + 1`) lies on, if any.
    fn piece(&self, i: usize) -> Option<(P3, P3)> {
        self.arcs.get(i + 1).copied().flatten()
    }

    fn seg_dist(&self, i: usize, p: P3) -> f64 {
        let a = self.pts[i];
        let b = *self.pts.get(i + 1).unwrap_or(&a);
        if let Some(arc) = self.piece(i).filter(|_| i + 1 < self.pts.len()) {
            // To the arc at `p`'s angle where that is within the piece, else to its nearer end.
            return match arc_point(a, b, arc, Some(p), 0.0) {
                Some((q, t)) if (0.0..=1.0).contains(&t) => geom::dist(p, q),
                Some(_) => geom::dist(p, a).min(geom::dist(p, b)),
                None => Self::chord_dist(a, b, p),
            };
        }
        Self::chord_dist(a, b, p)
    }

    /// Distance from `p` to the segment `a`–`b`.
    fn chord_dist(a: P3, b: P3, p: P3) -> f64 {
        let d = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
        let l2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
        let t = if l2 > 0.0 { (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1] + (p[2] - a[2]) * d[2]) / l2).clamp(0.0, 1.0) } else { 0.0 };
        geom::dist(p, [a[0] + t * d[0], a[1] + t * d[1], a[2] + t * d[2]])
    }

    /// Distance from `p` to the nearest segment: rings of cells outwards until no cell
    /// further out can hold a nearer one.
    fn nearest(&self, p: P3) -> f64 {
        let (c, r) = self.at(p);
        let mut best = f64::INFINITY;
        // Rings wholly outside the grid hold nothing.
        let outside = |v: i64, n: i64| (-v).max(v - (n - 1)).max(0);
        let first = outside(c, self.cols).max(outside(r, self.rows));
        let far = first + self.cols.max(self.rows);
        let visit = |key: (i64, i64), best: &mut f64| {
            let from = self.bins.partition_point(|b| b.0 < key);
            for &(_, i) in self.bins[from..].iter().take_while(|b| b.0 == key) {
                *best = best.min(self.seg_dist(i as usize, p));
            }
        };
        // Only the cells of each ring that lie within the grid: a point far outside it (a
        // program rewritten in other units) costs the rings' width, not their area.
        for ring in first..=far {
            let (c0, c1) = ((c - ring).max(0), (c + ring).min(self.cols - 1));
            for row in [r - ring, r + ring] {
                if (0..self.rows).contains(&row) {
                    for col in c0..=c1 {
                        visit((col, row), &mut best);
                    }
                    if ring == 0 {
                        break;
                    }
                }
            }
            let (r0, r1) = ((r - ring + 1).max(0), (r + ring - 1).min(self.rows - 1));
            for col in [c - ring, c + ring] {
                if ring > 0 && (0..self.cols).contains(&col) {
                    for row in r0..=r1 {
                        visit((col, row), &mut best);
                    }
                }
            }
            if best <= ring as f64 * self.cell {
                break;
            }
        }
        if best.is_finite() { best } else { 0.0 }
    }
}

/// Groups changes per workingstep as sentences:
/// `workingstep 1 (plane finish milling): tool T1 renamed T8; start point moved from X90 Y20 to X83 Y20`.
pub fn render_plain(changes: &[Change]) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut i = 0;
    while i < changes.len() {
        let c = &changes[i];
        let mut j = i;
        let mut phrases = Vec::new();
        while j < changes.len()
            && changes[j].workingstep == c.workingstep
            && changes[j].operation == c.operation
            && (changes[j].kind == ChangeKind::WorkingstepAdded) == (c.kind == ChangeKind::WorkingstepAdded)
        {
            phrases.push(changes[j].phrase());
            j += 1;
        }
        if c.workingstep == 0 {
            lines.push(format!("program: {}", phrases.join("; ")));
        } else {
            lines.push(format!("workingstep {} ({}): {}", c.workingstep, c.operation, phrases.join("; ")));
        }
        i = j;
    }
    lines
}

/// Folds each change that `first` takes into it the later ones alike (the same kind, field,
/// before and after) that `joins` says are that change seen again, `absorb` keeping what a
/// later one adds; the first then names the other workingsteps it is also in. The door of
/// `account`'s repeats at the same statements and `turning`'s feature shared by workingsteps.
fn fold_repeats(
    changes: &mut Vec<Change>,
    first: impl Fn(&Change) -> bool,
    joins: impl Fn(&Change, &Change) -> bool,
    absorb: impl Fn(&mut Change, Change),
) {
    let mut k = 0;
    while k < changes.len() {
        if !first(&changes[k]) {
            k += 1;
            continue;
        }
        let mut also = Vec::new();
        let mut j = k + 1;
        while j < changes.len() {
            let (c, d) = (&changes[k], &changes[j]);
            let same = d.kind == c.kind && d.field == c.field && d.before == c.before && d.after == c.after;
            if same && joins(c, d) {
                let d = changes.remove(j);
                if d.workingstep != changes[k].workingstep && !also.contains(&d.workingstep) {
                    also.push(d.workingstep);
                }
                absorb(&mut changes[k], d);
            } else {
                j += 1;
            }
        }
        if !also.is_empty() {
            let list = also.iter().map(u32::to_string).collect::<Vec<_>>().join(", ");
            changes[k].after.push_str(&format!(" (also in workingstep{} {list})", if also.len() == 1 { "" } else { "s" }));
        }
        k += 1;
    }
}

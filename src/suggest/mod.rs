//! Knowledge back to CAM: the shop's recurring overrides, as suggestions with their evidence.
//!
//! A pure room (no IO, clock or SQL): the store hands it the edits planners accepted
//! ([`Edit`]: a typed change with the tool as the CAM knows it, the material, the machine, the
//! operation and the parameter, old and new value in metric units), and [`suggest`] groups
//! them by tool, material, machine, operation class and parameter and asks each group the
//! gates of [`Rules`]: enough edits, programs and days (or operators) that one operator's bad
//! day cannot make a suggestion, nearly all of them the same way (the exact sign test), an
//! effect of at least 10 %, a robust centre (the median of the log ratios after dropping
//! outliers by the median absolute deviation), no reversal among the latest edits, and a
//! cautious estimate (the median shrunk toward no change, kept inside its interval). The shell
//! adds one more gate from the CAM's posts (`review::carried`): a value the CAM took up on its
//! own after the group's last edit is no suggestion.
//!
//! A `feed_changed` row lists every feed of a workingstep: [`feed_roles`] tells which is the
//! cutting feed, a plunge's or a ramp's from the moves at each, and [`feed_edits`] makes one
//! edit per role that changed. The operator of an edit is read where the share tells it
//! ([`header_operator`]).
//!
//! `stats` holds the statistics; `review` the review states (proposed, accepted, rejected,
//! snoozed, exported, adopted, reopened) from the recorded events, and the watch after export
//! (a new CAM post that carries the value and edits that stop: adopted; edits that go on:
//! reopened); `library` reads the CAM side's tool libraries (Autodesk Fusion / Inventor CAM /
//! HSM JSON in its older `start-values` `*` form and its newer `presets` form) and writes the
//! copies with one preset per accepted suggestion, and takes tool tables as the CAM's tools;
//! `freecad` reads FreeCAD's tool bits and libraries; `render` the neutral CSV, the one-line
//! evidence and the pictures (edits over time, their spread).

pub mod freecad;
pub mod library;
pub mod render;
pub mod review;
pub mod stats;

use std::collections::BTreeMap;

use serde::Serialize;
use sha2::{Digest, Sha256};

/// A machining parameter a suggestion is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Parameter {
    /// The cutting feed, mm/min.
    CuttingFeed,
    /// The feed of the moves straight down (plunges), mm/min.
    PlungeFeed,
    /// The feed of the moves down along a slope or a helix (ramps, helical entries), mm/min.
    RampFeed,
    /// The spindle speed, 1/min.
    SpindleSpeed,
    /// The cutting speed (constant surface speed), m/min.
    CuttingSpeed,
    /// The depth of cut per layer, mm.
    Stepdown,
    /// The stepover between passes, mm.
    Stepover,
    /// The peck depth of a drilling cycle, mm.
    PeckDepth,
    /// The height of the rapids between cuts, mm (a height: compared by difference).
    ClearanceHeight,
}

/// How a parameter's edits are measured: as a ratio (feeds, speeds, depths) or as an offset
/// (a height, whose zero is the part's and whose ratio means nothing).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Scale {
    /// `ln(after / before)`.
    Ratio,
    /// `after - before`, mm.
    Offset,
}

impl Parameter {
    /// Every parameter, in order.
    pub const ALL: [Parameter; 9] = [
        Parameter::CuttingFeed,
        Parameter::PlungeFeed,
        Parameter::RampFeed,
        Parameter::SpindleSpeed,
        Parameter::CuttingSpeed,
        Parameter::Stepdown,
        Parameter::Stepover,
        Parameter::PeckDepth,
        Parameter::ClearanceHeight,
    ];

    /// The parameter a stored change is about: by its kind and field (`diff`'s names). A
    /// `feed_changed` row lists every feed of the workingstep; [`feed_roles`] tells which of
    /// them is the cutting feed, which a plunge's and which a ramp's.
    pub fn of_change(kind: &str, field: &str) -> Option<Parameter> {
        Some(match (kind, field) {
            ("feed_changed", "feed") => Parameter::CuttingFeed,
            ("plunge_feed_changed", _) => Parameter::PlungeFeed,
            ("spindle_speed_changed", "spindle_speed") => Parameter::SpindleSpeed,
            ("spindle_speed_changed", "surface_speed" | "cutting_speed") => Parameter::CuttingSpeed,
            ("axial_depth_changed", _) => Parameter::Stepdown,
            ("stepover_changed", _) => Parameter::Stepover,
            ("cycle_parameter_changed", "peck") => Parameter::PeckDepth,
            ("clearance_changed", _) => Parameter::ClearanceHeight,
            _ => return None,
        })
    }

    /// Its name in files and URLs.
    pub fn name(self) -> &'static str {
        match self {
            Parameter::CuttingFeed => "cutting_feed",
            Parameter::PlungeFeed => "plunge_feed",
            Parameter::RampFeed => "ramp_feed",
            Parameter::SpindleSpeed => "spindle_speed",
            Parameter::CuttingSpeed => "cutting_speed",
            Parameter::Stepdown => "stepdown",
            Parameter::Stepover => "stepover",
            Parameter::PeckDepth => "peck_depth",
            Parameter::ClearanceHeight => "clearance_height",
        }
    }

    /// Its name for a planner.
    pub fn label(self) -> &'static str {
        match self {
            Parameter::CuttingFeed => "cutting feed",
            Parameter::PlungeFeed => "plunge feed",
            Parameter::RampFeed => "ramp feed",
            Parameter::SpindleSpeed => "spindle speed",
            Parameter::CuttingSpeed => "cutting speed",
            Parameter::Stepdown => "stepdown",
            Parameter::Stepover => "stepover",
            Parameter::PeckDepth => "peck depth",
            Parameter::ClearanceHeight => "clearance height",
        }
    }

    /// Its unit (metric).
    pub fn unit(self) -> &'static str {
        match self {
            Parameter::CuttingFeed | Parameter::PlungeFeed | Parameter::RampFeed => "mm/min",
            Parameter::SpindleSpeed => "1/min",
            Parameter::CuttingSpeed => "m/min",
            _ => "mm",
        }
    }

    /// How its edits are measured.
    pub fn scale(self) -> Scale {
        if self == Parameter::ClearanceHeight { Scale::Offset } else { Scale::Ratio }
    }

    /// Whether a tool library holds it; the others (peck depth, clearance height) belong to
    /// an operation and are notes for the CAM template or the post.
    pub fn of_tool(self) -> bool {
        !matches!(self, Parameter::PeckDepth | Parameter::ClearanceHeight)
    }

    /// A value written in a program of inch units, in metric units.
    pub fn metric(self, v: f64, inch: bool) -> f64 {
        match (inch, self) {
            (false, _) | (true, Parameter::SpindleSpeed) => v,
            (true, Parameter::CuttingSpeed) => v * 0.3048,
            (true, _) => v * 25.4,
        }
    }
}

/// What a feed of a workingstep does, from its moves in the original's plan: the cutting
/// feed (the plan's technology feed), the feed of moves straight down (plunges) or of moves
/// down while moving across (ramps and helical entries).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FeedRole {
    /// The cutting feed.
    Cutting,
    /// Straight down along the tool axis.
    Plunge,
    /// Down along a slope or a helix.
    Ramp,
}

impl FeedRole {
    /// The parameter of a feed of this role.
    pub fn parameter(self) -> Parameter {
        match self {
            FeedRole::Cutting => Parameter::CuttingFeed,
            FeedRole::Plunge => Parameter::PlungeFeed,
            FeedRole::Ramp => Parameter::RampFeed,
        }
    }
}

/// A move of a workingstep's toolpath as the roles need it: a feed move (not rapid), its
/// start and end, and its feed.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FeedMove {
    /// Start point.
    pub from: [f64; 3],
    /// End point.
    pub to: [f64; 3],
    /// Feed, in the unit the change's text writes it.
    pub feed: f64,
}

/// The role of each feed of a workingstep (`feeds` as the plan lists them: its technology feed
/// first, then the others in order of first use), from its feed `moves`: a feed whose moves all
/// go straight down is a plunge's, one whose moves all go down while moving across a ramp's
/// (or a helical entry's), one whose moves include level ones a cutting feed (a finishing
/// pass's second feed too). The first is the cutting feed where no feed cuts level (a drill,
/// plunge milling) or its moves are mixed (a 3D contour); a feed no move runs at, or a later
/// one whose moves are mixed, has no role: checked against the moves, never guessed.
pub fn feed_roles(feeds: &[f64], moves: &[FeedMove]) -> Vec<Option<FeedRole>> {
    const EPS: f64 = 1e-6;
    let down = |m: &FeedMove| m.to[2] < m.from[2] - EPS;
    let across = |m: &FeedMove| (m.to[0] - m.from[0]).hypot(m.to[1] - m.from[1]) > EPS;
    // By the moves alone: Some(role), or None for mixed or unused.
    let alone: Vec<Option<FeedRole>> = feeds
        .iter()
        .map(|f| {
            let at: Vec<&FeedMove> = moves.iter().filter(|m| (m.feed - f).abs() <= EPS * f.abs().max(1.0)).collect();
            if at.is_empty() {
                None
            } else if at.iter().all(|m| down(m) && !across(m)) {
                Some(FeedRole::Plunge)
            } else if at.iter().all(|m| down(m)) {
                Some(FeedRole::Ramp)
            } else if at.iter().all(|m| !down(m)) {
                Some(FeedRole::Cutting)
            } else {
                None
            }
        })
        .collect();
    let cuts_level = alone.contains(&Some(FeedRole::Cutting));
    alone
        .iter()
        .enumerate()
        .map(|(i, r)| match r {
            _ if i == 0 && (!cuts_level || r.is_none()) => Some(FeedRole::Cutting),
            r => *r,
        })
        .collect()
}

/// The numbers of a list of feeds as a change writes it (`F800, F300`).
pub fn feed_list(text: &str) -> Vec<f64> {
    text.split(',').filter_map(first_number).collect()
}

/// The edits a `feed_changed` row holds, by role: `before` and `after` its lists, `roles` the
/// original's ([`feed_roles`]). The lists are compared place by place (an operator edits a
/// feed where it stands, so it keeps its place); lists of another length cannot be told apart
/// by role and give `None`. A role's feeds that all change the same way make one edit (the
/// first one's values); a feed that stays is none, so that a ramp's edit is not also an edit of
/// "no change" to the cutting feed. A workingstep of one feed whose plan is not known: that
/// feed is its cutting feed.
pub fn feed_edits(before: &[f64], after: &[f64], roles: &[Option<FeedRole>]) -> Option<Vec<(Parameter, f64, f64)>> {
    if before.len() != after.len() {
        return None;
    }
    let role = |i: usize| match roles.get(i) {
        Some(r) => *r,
        None if roles.is_empty() && before.len() == 1 => Some(FeedRole::Cutting),
        None => None,
    };
    let pairs: Vec<(FeedRole, f64, f64)> =
        before.iter().zip(after).enumerate().filter_map(|(i, (b, a))| Some((role(i)?, *b, *a))).collect();
    let mut out: Vec<(Parameter, f64, f64)> = Vec::new();
    for r in [FeedRole::Cutting, FeedRole::Plunge, FeedRole::Ramp] {
        let of: Vec<&(FeedRole, f64, f64)> = pairs.iter().filter(|p| p.0 == r && (p.1 - p.2).abs() > 1e-9).collect();
        let Some(first) = of.first() else { continue };
        let up = first.2 > first.1;
        if of.iter().all(|p| (p.2 > p.1) == up) {
            out.push((r.parameter(), first.1, first.2));
        }
    }
    Some(out)
}

/// What kind of work a workingstep does, for grouping: a finishing cut is edited for other
/// reasons than a roughing one.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum OpClass {
    /// Roughing.
    Roughing,
    /// Finishing.
    Finishing,
    /// Drilling, centring, reaming, boring, tapping.
    Holemaking,
    /// Anything else (a free-form toolpath, a turning operation).
    Other,
}

impl OpClass {
    /// The class of an operation by its label (`plan::Operation::label`, the diff's `operation`).
    pub fn of_operation(label: &str) -> OpClass {
        let l = label.to_ascii_lowercase();
        if l.contains("rough") {
            OpClass::Roughing
        } else if l.contains("finish") {
            OpClass::Finishing
        } else if ["drill", "ream", "bor", "tap"].iter().any(|w| l.contains(w)) {
            OpClass::Holemaking
        } else {
            OpClass::Other
        }
    }

    /// Its name.
    pub fn name(self) -> &'static str {
        match self {
            OpClass::Roughing => "roughing",
            OpClass::Finishing => "finishing",
            OpClass::Holemaking => "holemaking",
            OpClass::Other => "other",
        }
    }
}

/// A tool as the CAM side knows it: its number and what the program's tool comments or the
/// tool table say of it.
#[derive(Clone, Debug, Default, PartialEq, PartialOrd, Serialize)]
pub struct ToolKey {
    /// Tool number.
    pub number: u32,
    /// Description (the tool comment, the library's name), empty when unknown.
    pub description: String,
    /// Cutter diameter, mm.
    pub diameter: Option<f64>,
    /// Number of flutes.
    pub flutes: Option<u32>,
    /// Corner radius, mm.
    pub corner_radius: Option<f64>,
}

impl ToolKey {
    /// `T5 Ø10 Z4 R0.5 "description"`, with what is known.
    pub fn label(&self) -> String {
        let mut s = format!("T{}", self.number);
        if let Some(d) = self.diameter {
            s.push_str(&format!(" Ø{}", num(d)));
        }
        if let Some(z) = self.flutes {
            s.push_str(&format!(" Z{z}"));
        }
        if let Some(r) = self.corner_radius.filter(|r| *r > 0.0) {
            s.push_str(&format!(" R{}", num(r)));
        }
        if !self.description.is_empty() {
            s.push_str(&format!(" {}", self.description));
        }
        s
    }
}

/// What a tool comment says of the tool itself, as the CAM library names it: without the tool
/// number, the geometry the key holds apart (`D=`, `CR=`, `TAPER=`) and what the post writes per
/// operation (`ZMIN=`, `ZMAX=`), which would split one tool's edits by program. A Fusion or
/// HSM post's `T1 D=12. CR=0. - ZMIN=-10. - FLAT END MILL` is `FLAT END MILL`.
pub fn tool_description(comment: &str) -> String {
    let per_operation = ["D=", "CR=", "TAPER=", "ZMIN=", "ZMAX="];
    let words: Vec<&str> = comment
        .split_whitespace()
        .enumerate()
        .filter(|(i, w)| {
            let upper = w.to_ascii_uppercase();
            let number = *i == 0 && upper.len() > 1 && upper.starts_with('T') && upper[1..].chars().all(|c| c.is_ascii_digit());
            !number && *w != "-" && !per_operation.iter().any(|p| upper.starts_with(p))
        })
        .map(|(_, w)| w)
        .collect();
    words.join(" ")
}

/// A number as a planner reads it: up to four decimals, no trailing zeros.
pub fn num(v: f64) -> String {
    let s = format!("{v:.4}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// What a suggestion is about: a group of edits.
#[derive(Clone, Debug, PartialEq, PartialOrd, Serialize)]
pub struct GroupKey {
    /// The tool.
    pub tool: ToolKey,
    /// The material (from the program's header comments or the configuration), `unknown`.
    pub material: String,
    /// The machine.
    pub machine: String,
    /// The operation class.
    pub class: OpClass,
    /// The parameter.
    pub parameter: Parameter,
}

impl GroupKey {
    /// The key as text: what the suggestion's id is made from and the store records.
    pub fn text(&self) -> String {
        let t = &self.tool;
        let o = |v: Option<f64>| v.map(num).unwrap_or_default();
        format!(
            "T{}|{}|{}|{}|{}|{}|{}|{}|{}",
            t.number,
            o(t.diameter),
            t.flutes.map(|z| z.to_string()).unwrap_or_default(),
            o(t.corner_radius),
            t.description,
            self.material,
            self.machine,
            self.class.name(),
            self.parameter.name()
        )
    }

    /// The suggestion's id: the first 12 hex digits of the SHA-256 of [`GroupKey::text`].
    pub fn id(&self) -> String {
        let h = Sha256::digest(self.text().as_bytes());
        h.iter().take(6).map(|b| format!("{b:02x}")).collect()
    }
}

/// One accepted edit: a stored change with everything the grouping needs.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Edit {
    /// The change's id (the comparison page's anchor).
    pub change_id: i64,
    /// The edited revision (the comparison page).
    pub revision_id: i64,
    /// The program as the machine's folder names it.
    pub program: String,
    /// The CAM original's path.
    pub original: String,
    /// The workingstep (the original's index).
    pub workingstep: u32,
    /// The workingstep's operation label.
    pub operation: String,
    /// The machine.
    pub machine: String,
    /// When the edited revision was seen (RFC 3339).
    pub at: String,
    /// Who edited, where the share tells it.
    pub operator: Option<String>,
    /// The CAM workingstep's spindle speed, 1/min (for feed per tooth), where the plan tells it.
    pub spindle: Option<f64>,
    /// The tool.
    pub tool: ToolKey,
    /// The material.
    pub material: String,
    /// The parameter.
    pub parameter: Parameter,
    /// The CAM value, metric.
    pub before: f64,
    /// The operator's value, metric.
    pub after: f64,
}

impl Edit {
    /// The group it belongs to.
    pub fn key(&self) -> GroupKey {
        GroupKey {
            tool: self.tool.clone(),
            material: self.material.clone(),
            machine: self.machine.clone(),
            class: OpClass::of_operation(&self.operation),
            parameter: self.parameter,
        }
    }

    /// Its effect: `ln(after / before)` for a ratio, `after - before` for an offset; `None`
    /// when a ratio has no meaning (a value of zero or below).
    pub fn effect(&self) -> Option<f64> {
        match self.parameter.scale() {
            Scale::Ratio => (self.before > 0.0 && self.after > 0.0).then(|| (self.after / self.before).ln()),
            Scale::Offset => Some(self.after - self.before),
        }
    }

    /// The day it was made (`YYYY-MM-DD`).
    pub fn day(&self) -> &str {
        self.at.get(..10).unwrap_or(&self.at)
    }
}

/// The gates and their thresholds; every one configurable (`[suggest]` in the configuration).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Rules {
    /// Edits a suggestion needs after outliers are dropped (5: fewer cannot pass a sign
    /// test at 5 % anyway, 5 of 5 gives p = 0.0625 two-sided, so 6 agreeing ones are the
    /// least that pass at the default `alpha`).
    pub min_edits: usize,
    /// Distinct programs (2: one program's odd fixture is not the tool's data).
    pub min_programs: usize,
    /// Distinct days (3) …
    pub min_days: usize,
    /// … spread over at least this many days from the first to the last (14: one
    /// operator's bad week fits in 7) …
    pub min_span_days: i64,
    /// … or, where the share names who edited, this many operators (2).
    pub min_operators: usize,
    /// Share of the kept edits that go the suggestion's way (0.9: "nearly all").
    pub min_agreement: f64,
    /// The sign test's significance level, two-sided (0.05).
    pub alpha: f64,
    /// Smallest effect worth a change of the CAM data: 10 % for a ratio (a planner does not
    /// retune a library for less, and feed override steps are 10 %).
    pub min_effect: f64,
    /// Smallest change of a height, mm (2).
    pub min_offset_mm: f64,
    /// Edits farther than this many scaled MADs from the median are outliers (3, the usual
    /// cut-off for the MAD scaled by 1.4826 to a normal's standard deviation).
    pub mad_cutoff: f64,
    /// The least scale the MAD cut-off uses, as a log ratio (0.02): edits that all agree
    /// exactly would otherwise make every other one an outlier.
    pub mad_floor: f64,
    /// How many of the latest edits must not go the other way (3).
    pub reversal_window: usize,
    /// Edits of "no change" the estimate is shrunk with (3): a suggestion from 6 edits moves
    /// the CAM value two thirds of the way, one from 30 almost all the way.
    pub prior_edits: f64,
    /// The interval's confidence (0.95).
    pub confidence: f64,
    /// Edits after an export that reopen a suggestion (2).
    pub reopen_edits: usize,
    /// How close a new CAM post's value must be to the suggested one to count as adopting it (5 %).
    pub adopt_tolerance: f64,
    /// Days a snoozed suggestion stays out of the list (30).
    pub snooze_days: i64,
    /// Edits a rejected suggestion's evidence must grow by before it is proposed again (3).
    pub rejected_growth: usize,
}

impl Default for Rules {
    fn default() -> Rules {
        Rules {
            min_edits: 5,
            min_programs: 2,
            min_days: 3,
            min_span_days: 14,
            min_operators: 2,
            min_agreement: 0.9,
            alpha: 0.05,
            min_effect: 0.10,
            min_offset_mm: 2.0,
            mad_cutoff: 3.0,
            mad_floor: 0.02,
            reversal_window: 3,
            prior_edits: 3.0,
            confidence: 0.95,
            reopen_edits: 2,
            adopt_tolerance: 0.05,
            snooze_days: 30,
            rejected_growth: 3,
        }
    }
}

/// Why an edit was left out of a suggestion's centre.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "why")]
pub enum LeftOut {
    /// Farther from the median than the MAD cut-off allows (by this many scaled MADs).
    Outlier {
        /// Its distance in scaled MADs.
        mads: f64,
    },
    /// Its value has no ratio (zero or below).
    NoRatio,
}

impl LeftOut {
    /// In words.
    pub fn words(&self) -> String {
        match self {
            LeftOut::Outlier { mads } => format!("an outlier: {} MADs from the median", num(*mads)),
            LeftOut::NoRatio => "a value of zero or below has no ratio".into(),
        }
    }
}

/// A gate a group did not pass.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "gate")]
pub enum Held {
    /// Too few edits, programs, or days and operators.
    TooFew {
        /// What there were too few of.
        what: String,
    },
    /// Not nearly all the same way, or the sign test not significant.
    Disagree {
        /// Share going the majority's way.
        agreement: f64,
        /// The sign test's p-value.
        p: f64,
    },
    /// The effect is smaller than the threshold.
    Small {
        /// The effect: relative (`-0.05` for 5 % less), or mm for a height.
        effect: f64,
        /// Whether it is relative.
        relative: bool,
    },
    /// The latest edits go the other way.
    Reversal {
        /// The change ids of the reversing edits.
        edits: Vec<i64>,
    },
    /// The CAM posts the value already: a post after the group's last edit carries it, none
    /// since carries the old value, and nobody edited since (`review::carried`).
    CamCarries {
        /// The first such CAM revision.
        revision: i64,
        /// When it was stored.
        at: String,
    },
}

impl Held {
    /// In words.
    pub fn words(&self) -> String {
        match self {
            Held::TooFew { what } => format!("too few {what}"),
            Held::Disagree { agreement, p } => {
                format!("the edits disagree: {} % the same way, sign test p = {}", num(agreement * 100.0), num(*p))
            }
            Held::Small { effect, relative: true } => format!("the effect is small: {} %", num((effect * 1000.0).round() / 10.0)),
            Held::Small { effect, relative: false } => format!("the effect is small: {} mm", num(*effect)),
            Held::Reversal { edits } => format!("reversed by the latest edits ({} of them)", edits.len()),
            Held::CamCarries { revision, at } => {
                format!("the CAM posts it already (revision {revision} of {}) and nobody edited it since", &at[..at.len().min(10)])
            }
        }
    }
}

/// One group's verdict: its figures, and what held it back (empty for a suggestion).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Suggestion {
    /// The id ([`GroupKey::id`]).
    pub id: String,
    /// What it is about.
    pub key: GroupKey,
    /// The CAM value: the value the CAM posted most often (ties: the smaller).
    pub cam_value: f64,
    /// The suggested value (the shrunk centre, kept inside the interval).
    pub suggested: f64,
    /// The interval of the centre, as values.
    pub interval: (f64, f64),
    /// The median effect of the kept edits (log ratio, or mm).
    pub centre: f64,
    /// The kept edits, oldest first.
    pub edits: Vec<Edit>,
    /// The edits left out and why.
    pub left_out: Vec<(Edit, LeftOut)>,
    /// Kept edits the suggestion's way and the other way.
    pub agree: usize,
    /// Kept edits the other way.
    pub disagree: usize,
    /// The sign test's p-value.
    pub p: f64,
    /// Distinct programs, days and operators.
    pub programs: usize,
    /// Distinct days.
    pub days: usize,
    /// Distinct operators (0 where the share does not tell).
    pub operators: usize,
    /// What held it back; empty when it is a suggestion.
    pub held: Vec<Held>,
}

impl Suggestion {
    /// Whether every gate passed.
    pub fn passed(&self) -> bool {
        self.held.is_empty()
    }

    /// The change the suggestion makes, relative (`-0.3` for 30 % less) or in mm for a height.
    pub fn change(&self) -> f64 {
        match self.key.parameter.scale() {
            Scale::Ratio if self.cam_value != 0.0 => self.suggested / self.cam_value - 1.0,
            _ => self.suggested - self.cam_value,
        }
    }
}

/// Every group of `edits` with its verdict, in key order: those that passed every gate of
/// `rules` are suggestions, the others say what held them back.
pub fn suggest(edits: &[Edit], rules: &Rules) -> Vec<Suggestion> {
    let mut groups: Vec<(GroupKey, Vec<Edit>)> = Vec::new();
    let mut index: BTreeMap<String, usize> = BTreeMap::new();
    for e in edits {
        let key = e.key();
        let i = *index.entry(key.text()).or_insert_with(|| {
            groups.push((key, Vec::new()));
            groups.len() - 1
        });
        groups[i].1.push(e.clone());
    }
    let mut out: Vec<Suggestion> = index.values().map(|&i| judge(&groups[i].0, &groups[i].1, rules)).collect();
    out.sort_by_key(|s| s.key.text());
    out
}

/// One group's verdict.
pub fn judge(key: &GroupKey, edits: &[Edit], rules: &Rules) -> Suggestion {
    let mut sorted: Vec<Edit> = edits.to_vec();
    sorted.sort_by(|a, b| a.at.cmp(&b.at).then(a.change_id.cmp(&b.change_id)));
    let (kept, left_out) = drop_outliers(&sorted, rules);
    let effects: Vec<f64> = kept.iter().filter_map(Edit::effect).collect();
    let centre = stats::median(&effects).unwrap_or(0.0);
    let up = centre >= 0.0;
    let agree = effects.iter().filter(|e| if up { **e > 0.0 } else { **e < 0.0 }).count();
    let disagree = effects.iter().filter(|e| if up { **e < 0.0 } else { **e > 0.0 }).count();
    let p = stats::sign_test(agree, disagree);
    let cam_value = cam_value(&kept);
    let (lo, hi) = stats::median_interval(&effects, rules.confidence).unwrap_or((0.0, 0.0));
    let shrunk = stats::shrink(centre, effects.len(), rules.prior_edits).clamp(lo, hi);
    let value = |e: f64| match key.parameter.scale() {
        Scale::Ratio => cam_value * e.exp(),
        Scale::Offset => cam_value + e,
    };
    let count = |f: &dyn Fn(&Edit) -> Option<String>| kept.iter().filter_map(f).collect::<std::collections::BTreeSet<_>>().len();
    let programs = count(&|e| Some(e.original.clone()));
    let days = count(&|e| Some(e.day().to_owned()));
    let operators = count(&|e| e.operator.clone());
    let mut s = Suggestion {
        id: key.id(),
        key: key.clone(),
        cam_value,
        suggested: value(shrunk),
        interval: (value(lo), value(hi)),
        centre,
        agree,
        disagree,
        p,
        programs,
        days,
        operators,
        held: Vec::new(),
        edits: kept,
        left_out,
    };
    s.held = gates(&s, &sorted, rules);
    s
}

/// The kept edits and those left out: outliers by the MAD cut-off, values without a ratio.
fn drop_outliers(edits: &[Edit], rules: &Rules) -> (Vec<Edit>, Vec<(Edit, LeftOut)>) {
    let mut left_out = Vec::new();
    let mut with: Vec<(Edit, f64)> = Vec::new();
    for e in edits {
        match e.effect() {
            Some(x) => with.push((e.clone(), x)),
            None => left_out.push((e.clone(), LeftOut::NoRatio)),
        }
    }
    let effects: Vec<f64> = with.iter().map(|w| w.1).collect();
    let centre = stats::median(&effects).unwrap_or(0.0);
    let floor = match edits.first().map(|e| e.parameter.scale()) {
        Some(Scale::Offset) => rules.min_offset_mm / 4.0,
        _ => rules.mad_floor,
    };
    let scale = (1.4826 * stats::mad(&effects, centre)).max(floor);
    let mut kept = Vec::new();
    for (e, x) in with {
        let mads = (x - centre).abs() / scale;
        if mads > rules.mad_cutoff { left_out.push((e, LeftOut::Outlier { mads })) } else { kept.push(e) }
    }
    (kept, left_out)
}

/// The value the CAM posted most often among `edits` (ties: the smaller).
fn cam_value(edits: &[Edit]) -> f64 {
    let mut counts: BTreeMap<i64, (usize, f64)> = BTreeMap::new();
    for e in edits {
        let c = counts.entry((e.before * 1000.0).round() as i64).or_insert((0, e.before));
        c.0 += 1;
    }
    counts.values().fold((0usize, 0.0f64), |best, c| if c.0 > best.0 { *c } else { best }).1
}

/// The gates `s` does not pass; `all` is every edit of the group, oldest first: a reversal
/// is looked for among them (an operator going back is an outlier to the centre, and must
/// still block).
fn gates(s: &Suggestion, all: &[Edit], rules: &Rules) -> Vec<Held> {
    let mut held = Vec::new();
    let n = s.agree + s.disagree;
    if s.edits.len() < rules.min_edits {
        held.push(Held::TooFew { what: format!("edits ({} of {})", s.edits.len(), rules.min_edits) });
    }
    if s.programs < rules.min_programs {
        held.push(Held::TooFew { what: format!("programs ({} of {})", s.programs, rules.min_programs) });
    }
    let span = match (s.edits.first(), s.edits.last()) {
        (Some(a), Some(b)) => days_between(a.day(), b.day()),
        _ => 0,
    };
    let spread = s.days >= rules.min_days && span >= rules.min_span_days;
    if !spread && s.operators < rules.min_operators {
        held.push(Held::TooFew {
            what: format!(
                "days ({} days over {} days; {} and {} days asked) or operators ({} of {})",
                s.days, span, rules.min_days, rules.min_span_days, s.operators, rules.min_operators
            ),
        });
    }
    let agreement = if n == 0 { 0.0 } else { s.agree as f64 / n as f64 };
    if n == 0 || agreement < rules.min_agreement || s.p > rules.alpha {
        held.push(Held::Disagree { agreement, p: s.p });
    }
    let effect = match s.key.parameter.scale() {
        Scale::Ratio => s.centre.exp() - 1.0,
        Scale::Offset => s.centre,
    };
    let threshold = if s.key.parameter.scale() == Scale::Ratio { rules.min_effect } else { rules.min_offset_mm };
    if effect.abs() < threshold {
        held.push(Held::Small { effect, relative: s.key.parameter.scale() == Scale::Ratio });
    }
    let up = s.centre >= 0.0;
    let latest = all.iter().rev().filter(|e| e.effect().is_some()).take(rules.reversal_window);
    let reversing: Vec<i64> =
        latest.filter(|e| e.effect().is_some_and(|x| if up { x < 0.0 } else { x > 0.0 })).map(|e| e.change_id).collect();
    if !reversing.is_empty() {
        held.push(Held::Reversal { edits: reversing });
    }
    held
}

/// Days from `a` to `b` (`YYYY-MM-DD`), 0 when either does not read as a date.
pub fn days_between(a: &str, b: &str) -> i64 {
    match (day_number(a), day_number(b)) {
        (Some(x), Some(y)) => y - x,
        _ => 0,
    }
}

/// The day's number since 1970-01-01 (civil calendar), from `YYYY-MM-DD…`.
pub fn day_number(d: &str) -> Option<i64> {
    let y: i64 = d.get(0..4)?.parse().ok()?;
    let m: i64 = d.get(5..7)?.parse().ok()?;
    let day: i64 = d.get(8..10)?.parse().ok()?;
    let y2 = if m <= 2 { y - 1 } else { y };
    let era = y2.div_euclid(400);
    let yoe = y2 - era * 400;
    let mp = (m + 9) % 12;
    let doy = (153 * mp + 2) / 5 + day - 1;
    let doe = yoe * 365 + yoe / 4 - yoe / 100 + doy;
    Some(era * 146_097 + doe - 719_468)
}

/// The first number in a change's text (`F800`, `S12000`, `Z-5.`, `Q2.5 at X10 Y20`, `120 m/min`).
pub fn first_number(text: &str) -> Option<f64> {
    let b = text.as_bytes();
    let start = (0..b.len()).find(|&i| {
        b[i].is_ascii_digit() || ((b[i] == b'-' || b[i] == b'.') && b.get(i + 1).is_some_and(|c| c.is_ascii_digit() || *c == b'.'))
    })?;
    let end = (start + 1..b.len()).find(|&i| !(b[i].is_ascii_digit() || b[i] == b'.')).unwrap_or(b.len());
    text[start..end].parse().ok()
}

/// The operator a program's header comments name (`(OPERATOR: ANNA)`, `; Bediener: Jo`,
/// `(OPERATEUR = LUC)`), in its first `lines` lines: a name after the word and a colon or an
/// equals sign, as shops write it when they sign an edit.
pub fn header_operator(text: &str, lines: usize) -> Option<String> {
    header_value(text, lines, &["OPERATOR", "BEDIENER", "OPERATEUR"])
}

/// The value after one of `words` and a colon or an equals sign in a comment of the first
/// `lines` lines (at most 60 characters).
fn header_value(text: &str, lines: usize, words: &[&str]) -> Option<String> {
    for line in text.lines().take(lines) {
        let upper = line.to_uppercase();
        for word in words {
            let Some(at) = upper.find(word) else { continue };
            // The upper-case text may be longer than the line (ß); the word's end is the same
            // byte offset in both only where it is ASCII before it.
            let Some(rest) = line.get(at + word.len()..) else { continue };
            let Some(rest) = rest.trim_start().strip_prefix([':', '=']) else { continue };
            let value = rest.trim().trim_end_matches([')', ';']).trim();
            if !value.is_empty() {
                return Some(value.chars().take(60).collect());
            }
        }
    }
    None
}

/// The material a program's header comments name (`(MATERIAL: AL6061)`, `(MAT = 1.4301)`,
/// `; Werkstoff: C45`), in its first `lines` lines.
pub fn header_material(text: &str, lines: usize) -> Option<String> {
    header_value(text, lines, &["MATERIAL", "WERKSTOFF", "MATIERE", "MAT"])
}

#[cfg(test)]
mod tests;

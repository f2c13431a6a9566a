//! A suggestion's review: the states it goes through and the watch after its export.
//!
//! The store records every step as an event (who, when, why, the value and the evidence at
//! that step); the state is the last event's, read against what the evidence says now: a
//! rejected suggestion comes back when its evidence has grown by `rejected_growth` edits, a
//! snoozed one when its `snooze_days` are over. After an export the watch ([`watch`]) looks at
//! the CAM posts and the edits that came after it: a new CAM revision carrying the suggested
//! value with no edits of the group after it adopts the suggestion; `reopen_edits` edits
//! after the export (or after the adopting post) reopen it.

use serde::Serialize;

use super::{Edit, Rules, Suggestion, days_between, num};

/// A review state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum State {
    /// Made by the rules, waiting for a planner.
    Proposed,
    /// A planner accepted it: it goes into the next export.
    Accepted,
    /// A planner rejected it (with a reason); held back until its evidence grows.
    Rejected,
    /// A planner put it off.
    Snoozed,
    /// Written into the outbox.
    Exported,
    /// A new CAM post carries its value and the edits stopped.
    Adopted,
    /// Operators kept editing after it was exported or adopted.
    Reopened,
}

impl State {
    /// Its name, as stored.
    pub fn name(self) -> &'static str {
        match self {
            State::Proposed => "proposed",
            State::Accepted => "accepted",
            State::Rejected => "rejected",
            State::Snoozed => "snoozed",
            State::Exported => "exported",
            State::Adopted => "adopted",
            State::Reopened => "reopened",
        }
    }

    /// The state of a stored name.
    pub fn parse(s: &str) -> Option<State> {
        [State::Proposed, State::Accepted, State::Rejected, State::Snoozed, State::Exported, State::Adopted, State::Reopened]
            .into_iter()
            .find(|x| x.name() == s)
    }

    /// The states a planner may move a suggestion to from this one.
    pub fn planner_moves(self) -> &'static [State] {
        match self {
            State::Proposed | State::Reopened => &[State::Accepted, State::Rejected, State::Snoozed],
            State::Accepted => &[State::Rejected, State::Snoozed],
            State::Rejected | State::Snoozed => &[State::Accepted],
            State::Exported | State::Adopted => &[State::Rejected],
        }
    }
}

/// One recorded step.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Event {
    /// The suggestion's id.
    pub suggestion: String,
    /// Its number among the suggestion's steps, from 1.
    pub step: i64,
    /// The state it moved to.
    pub state: State,
    /// Why (a rejection's reason, what the watch saw).
    pub reason: String,
    /// The suggested value at that step.
    pub value: f64,
    /// The kept edits behind it at that step.
    pub evidence: i64,
    /// Who (a planner, `ncplan` for the watch and the export).
    pub by: String,
    /// When (RFC 3339).
    pub at: String,
}

/// The state a suggestion is in now: its last event's, unless a rejection's evidence has grown
/// or a snooze is over (then proposed again). `None` events: proposed.
pub fn current(events: &[Event], evidence: usize, now: &str, rules: &Rules) -> State {
    let Some(last) = events.last() else { return State::Proposed };
    match last.state {
        State::Rejected if evidence >= last.evidence.max(0) as usize + rules.rejected_growth => State::Proposed,
        State::Snoozed if days_between(&last.at, now) >= rules.snooze_days => State::Proposed,
        s => s,
    }
}

/// A workingstep of a CAM post after an export: where and what it posts.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct CamStep {
    /// The CAM program's path.
    pub original: String,
    /// The revision.
    pub revision: i64,
    /// When it was seen.
    pub at: String,
    /// The workingstep's index.
    pub workingstep: u32,
    /// Its tool number.
    pub tool: u32,
    /// The parameter's value, metric, where the plan tells it.
    pub value: Option<f64>,
}

/// What the watch concluded.
#[derive(Clone, Debug, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "watch")]
pub enum Watch {
    /// Nothing yet.
    Waiting,
    /// A CAM post carries the value and no edits came after it.
    Adopted {
        /// The CAM revision.
        revision: i64,
        /// When it was seen.
        at: String,
    },
    /// Edits after the export (or the adopting post).
    Reopened {
        /// How many.
        edits: usize,
    },
}

impl Watch {
    /// In words, for the event's reason.
    pub fn words(&self) -> String {
        match self {
            Watch::Waiting => "waiting for a new CAM post".into(),
            Watch::Adopted { revision, at } => {
                format!("CAM revision {revision} of {} carries the value; no edits since", &at[..at.len().min(10)])
            }
            Watch::Reopened { edits } => format!("{edits} edits of the same parameter after the export"),
        }
    }
}

/// The watch over an exported suggestion `s` since `since` (the export's time): `edits`
/// are the group's edits (reviewed or not, rejected ones left out), `cam` the CAM posts seen
/// since of the programs behind the suggestion.
pub fn watch(s: &Suggestion, since: &str, edits: &[Edit], cam: &[CamStep], rules: &Rules) -> Watch {
    let after: Vec<&Edit> = edits.iter().filter(|e| e.at.as_str() > since).collect();
    if after.len() >= rules.reopen_edits {
        return Watch::Reopened { edits: after.len() };
    }
    let programs: Vec<&str> = s.edits.iter().map(|e| e.original.as_str()).collect();
    let carries = |c: &&CamStep| {
        c.at.as_str() > since
            && c.tool == s.key.tool.number
            && programs.contains(&c.original.as_str())
            && s.edits.iter().any(|e| e.original == c.original && e.workingstep == c.workingstep)
            && c.value.is_some_and(|v| close(v, s.suggested, rules.adopt_tolerance))
    };
    let mut posts: Vec<&CamStep> = cam.iter().filter(carries).collect();
    posts.sort_by(|a, b| a.at.cmp(&b.at).then(a.revision.cmp(&b.revision)));
    match posts.first() {
        Some(c) if !after.iter().any(|e| e.at > c.at) => Watch::Adopted { revision: c.revision, at: c.at.clone() },
        _ => Watch::Waiting,
    }
}

/// Whether the CAM adopted a group's value on its own, without an export: the first CAM post
/// (in `cam`) after the group's last edit (of `edits`, every edit of the group, accepted or
/// not) of a program and workingstep behind `s`, with its tool, that carries the value the
/// operators run (the suggested value, or the kept edits' median before shrinking: a CAM
/// programmer takes the operators' figure, not ncplan's cautious one) within
/// `adopt_tolerance`, where no post since still carries the old CAM value. A group the CAM
/// posts already is no suggestion: it would ask for what the CAM does.
pub fn carried(s: &Suggestion, edits: &[Edit], cam: &[CamStep], rules: &Rules) -> Option<(i64, String)> {
    let last = edits.iter().map(|e| e.at.as_str()).max()?;
    let behind = |c: &&CamStep| {
        c.at.as_str() > last
            && c.tool == s.key.tool.number
            && s.edits.iter().any(|e| e.original == c.original && e.workingstep == c.workingstep)
    };
    let mut posts: Vec<&CamStep> = cam.iter().filter(behind).collect();
    posts.sort_by(|a, b| a.at.cmp(&b.at).then(a.revision.cmp(&b.revision)));
    let run = match s.key.parameter.scale() {
        super::Scale::Ratio => s.cam_value * s.centre.exp(),
        super::Scale::Offset => s.cam_value + s.centre,
    };
    let carries = |v: f64| close(v, s.suggested, rules.adopt_tolerance) || close(v, run, rules.adopt_tolerance);
    if posts.iter().any(|c| c.value.is_some_and(|v| close(v, s.cam_value, rules.adopt_tolerance) && !carries(v))) {
        return None;
    }
    posts.into_iter().find(|c| c.value.is_some_and(carries)).map(|c| (c.revision, c.at.clone()))
}

/// Whether `v` is within `tolerance` (relative) of `target`.
fn close(v: f64, target: f64, tolerance: f64) -> bool {
    (v - target).abs() <= tolerance * target.abs().max(1e-9)
}

/// The event the watch asks for, if any, for a suggestion in `state`.
pub fn watch_move(state: State, w: &Watch) -> Option<State> {
    match (state, w) {
        (State::Exported, Watch::Adopted { .. }) => Some(State::Adopted),
        (State::Exported | State::Adopted, Watch::Reopened { .. }) => Some(State::Reopened),
        _ => None,
    }
}

/// A one-line account of an event.
pub fn event_line(e: &Event, unit: &str) -> String {
    let mut s = format!("{} by {} at {}: {} {unit}, {} edits", e.state.name(), e.by, e.at, num(e.value), e.evidence);
    if !e.reason.is_empty() {
        s.push_str(&format!(" ({})", e.reason));
    }
    s
}

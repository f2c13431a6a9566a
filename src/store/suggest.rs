//! The rows knowledge back to CAM reads and the review steps it writes (migration 11), on
//! SQLite; `pg/suggest.rs` is the PostgreSQL twin (the same rows in the same order).

use rusqlite::params;

use super::Result;
use super::sqlite::{Lite, sql};

/// An edit the suggestion rules may use: a change of a parameter they know, from the view
/// `suggestion_edits`, with its newest adopt or reject mark.
#[derive(Debug, Clone, PartialEq)]
pub struct EditRow {
    /// The change.
    pub change_id: i64,
    /// The edited revision.
    pub revision_id: i64,
    /// The CAM original's revision.
    pub original_revision_id: i64,
    /// The program's name.
    pub program: String,
    /// The original's path.
    pub original_path: String,
    /// The workingstep.
    pub workingstep: i64,
    /// Its operation label.
    pub operation: String,
    /// The change's kind and field.
    pub kind: String,
    /// The field.
    pub field: String,
    /// Old and new value as text.
    pub before: String,
    /// The new value.
    pub after: String,
    /// The machine ('' when none).
    pub machine: String,
    /// When the edited revision was seen.
    pub seen_at: String,
    /// The original workingstep's tool number.
    pub tool: Option<i64>,
    /// The original workingstep's spindle speed, 1/min.
    pub spindle_speed: Option<f64>,
    /// `adopt` or `reject`, the newest such mark; `None` unreviewed.
    pub review: Option<String>,
    /// Who made that mark.
    pub reviewed_by: Option<String>,
}

/// A workingstep of a CAM revision, with the values the watch compares (plan units: mm, mm/min, 1/min).
#[derive(Debug, Clone, PartialEq)]
pub struct CamRow {
    /// The CAM program's path.
    pub path: String,
    /// The revision.
    pub revision: i64,
    /// When it was seen.
    pub seen_at: String,
    /// The workingstep's index.
    pub workingstep: i64,
    /// Its tool.
    pub tool: i64,
    /// Feed, spindle speed, axial depth, radial depth, security plane.
    pub feed: Option<f64>,
    /// Spindle speed.
    pub spindle_speed: Option<f64>,
    /// Depth of cut per layer.
    pub axial_depth: Option<f64>,
    /// Stepover.
    pub radial_depth: Option<f64>,
    /// Height of the rapids between cuts.
    pub security_plane: Option<f64>,
}

/// One step of a suggestion's review, as stored.
#[derive(Debug, Clone, PartialEq)]
pub struct SuggestionStep {
    /// The suggestion's id.
    pub suggestion: String,
    /// Its number, from 1.
    pub step: i64,
    /// The group's key as text.
    pub group_key: String,
    /// The state it moved to.
    pub state: String,
    /// Why.
    pub reason: String,
    /// The suggested value then.
    pub value: f64,
    /// The kept edits then.
    pub evidence: i64,
    /// Who.
    pub by: String,
    /// When.
    pub at: String,
}

/// The edits, oldest first (the SQL the knowledge page shows).
pub const SUGGESTION_EDITS: &str =
    "SELECT change_id, revision_id, original_revision_id, program, original_path, workingstep, operation, kind, field,
       before, after, machine, seen_at, tool, spindle_speed, review, reviewed_by
FROM suggestion_edits ORDER BY seen_at, change_id";

/// The steps, by suggestion and step.
pub const SUGGESTION_STEPS: &str = "SELECT suggestion, step, group_key, state, reason, value, evidence, decided_by, decided_at
FROM suggestion_events ORDER BY suggestion, step";

impl Lite {
    pub(super) fn suggestion_edits(&self) -> Result<Vec<EditRow>> {
        let mut stmt = self.conn.prepare_cached(SUGGESTION_EDITS).map_err(sql("preparing a query"))?;
        let rows = stmt
            .query_map([], |r| {
                Ok(EditRow {
                    change_id: r.get(0)?,
                    revision_id: r.get(1)?,
                    original_revision_id: r.get(2)?,
                    program: r.get(3)?,
                    original_path: r.get(4)?,
                    workingstep: r.get(5)?,
                    operation: r.get(6)?,
                    kind: r.get(7)?,
                    field: r.get(8)?,
                    before: r.get(9)?,
                    after: r.get(10)?,
                    machine: r.get(11)?,
                    seen_at: r.get(12)?,
                    tool: r.get(13)?,
                    spindle_speed: r.get(14)?,
                    review: r.get(15)?,
                    reviewed_by: r.get(16)?,
                })
            })
            .map_err(sql("reading the edits suggestions are made from"))?;
        rows.collect::<std::result::Result<_, _>>().map_err(sql("reading the edits suggestions are made from"))
    }

    pub(super) fn cam_steps_since(&self, since: &str) -> Result<Vec<CamRow>> {
        let mut stmt = self
            .conn
            .prepare_cached(
                "SELECT p.path, r.id, r.seen_at, w.idx, w.tool, w.feed, w.spindle_speed, w.axial_depth, w.radial_depth, w.security_plane
                 FROM revisions r JOIN programs p ON p.id = r.program_id JOIN workingsteps w ON w.revision_id = r.id
                 WHERE p.role = 'cam' AND r.seen_at > ?1 ORDER BY r.seen_at, r.id, w.idx",
            )
            .map_err(sql("preparing a query"))?;
        let rows = stmt
            .query_map([since], |r| {
                Ok(CamRow {
                    path: r.get(0)?,
                    revision: r.get(1)?,
                    seen_at: r.get(2)?,
                    workingstep: r.get(3)?,
                    tool: r.get(4)?,
                    feed: r.get(5)?,
                    spindle_speed: r.get(6)?,
                    axial_depth: r.get(7)?,
                    radial_depth: r.get(8)?,
                    security_plane: r.get(9)?,
                })
            })
            .map_err(sql("reading CAM posts"))?;
        rows.collect::<std::result::Result<_, _>>().map_err(sql("reading CAM posts"))
    }

    pub(super) fn suggestion_steps(&self) -> Result<Vec<SuggestionStep>> {
        let mut stmt = self.conn.prepare_cached(SUGGESTION_STEPS).map_err(sql("preparing a query"))?;
        let rows = stmt
            .query_map([], |r| {
                Ok(SuggestionStep {
                    suggestion: r.get(0)?,
                    step: r.get(1)?,
                    group_key: r.get(2)?,
                    state: r.get(3)?,
                    reason: r.get(4)?,
                    value: r.get(5)?,
                    evidence: r.get(6)?,
                    by: r.get(7)?,
                    at: r.get(8)?,
                })
            })
            .map_err(sql("reading suggestion steps"))?;
        rows.collect::<std::result::Result<_, _>>().map_err(sql("reading suggestion steps"))
    }

    pub(super) fn add_suggestion_step(&self, s: &SuggestionStep) -> Result<Option<i64>> {
        use rusqlite::OptionalExtension;
        self.conn
            .query_row(
                "INSERT INTO suggestion_events(suggestion, step, group_key, state, reason, value, evidence, decided_by, decided_at)
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9) ON CONFLICT (suggestion, step) DO NOTHING
                 RETURNING step",
                params![s.suggestion, s.step, s.group_key, s.state, s.reason, s.value, s.evidence, s.by, s.at],
                |r| r.get(0),
            )
            .optional()
            .map_err(sql("recording a suggestion step"))
    }
}

//! The PostgreSQL twin of `store/suggest.rs`: the same rows in the same order.

use super::Pg;
use crate::store::Result;
use crate::store::suggest::{CamRow, EditRow, SUGGESTION_EDITS, SUGGESTION_STEPS, SuggestionStep};

impl Pg {
    pub(in crate::store) fn suggestion_edits(&self) -> Result<Vec<EditRow>> {
        let rows = self.conn.rows("reading the edits suggestions are made from", SUGGESTION_EDITS, &[])?;
        Ok(rows
            .iter()
            .map(|r| EditRow {
                change_id: r.get(0),
                revision_id: r.get(1),
                original_revision_id: r.get(2),
                program: r.get(3),
                original_path: r.get(4),
                workingstep: r.get(5),
                operation: r.get(6),
                kind: r.get(7),
                field: r.get(8),
                before: r.get(9),
                after: r.get(10),
                machine: r.get(11),
                seen_at: r.get(12),
                tool: r.get(13),
                spindle_speed: r.get(14),
                review: r.get(15),
                reviewed_by: r.get(16),
            })
            .collect())
    }

    pub(in crate::store) fn cam_steps_since(&self, since: &str) -> Result<Vec<CamRow>> {
        let rows = self.conn.rows(
            "reading CAM posts",
            "SELECT p.path, r.id, r.seen_at, w.idx, w.tool, w.feed, w.spindle_speed, w.axial_depth, w.radial_depth, w.security_plane
             FROM revisions r JOIN programs p ON p.id = r.program_id JOIN workingsteps w ON w.revision_id = r.id
             WHERE p.role = 'cam' AND r.seen_at > $1 ORDER BY r.seen_at, r.id, w.idx",
            &[&since],
        )?;
        Ok(rows
            .iter()
            .map(|r| CamRow {
                path: r.get(0),
                revision: r.get(1),
                seen_at: r.get(2),
                workingstep: r.get(3),
                tool: r.get(4),
                feed: r.get(5),
                spindle_speed: r.get(6),
                axial_depth: r.get(7),
                radial_depth: r.get(8),
                security_plane: r.get(9),
            })
            .collect())
    }

    pub(in crate::store) fn suggestion_steps(&self) -> Result<Vec<SuggestionStep>> {
        let rows = self.conn.rows("reading suggestion steps", SUGGESTION_STEPS, &[])?;
        Ok(rows
            .iter()
            .map(|r| SuggestionStep {
                suggestion: r.get(0),
                step: r.get(1),
                group_key: r.get(2),
                state: r.get(3),
                reason: r.get(4),
                value: r.get(5),
                evidence: r.get(6),
                by: r.get(7),
                at: r.get(8),
            })
            .collect())
    }

    pub(in crate::store) fn add_suggestion_step(&self, s: &SuggestionStep) -> Result<Option<i64>> {
        let row = self.conn.opt(
            "recording a suggestion step",
            "INSERT INTO suggestion_events(suggestion, step, group_key, state, reason, value, evidence, decided_by, decided_at)
             VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9) ON CONFLICT (suggestion, step) DO NOTHING
             RETURNING step",
            &[&s.suggestion, &s.step, &s.group_key, &s.state, &s.reason, &s.value, &s.evidence, &s.by, &s.at],
        )?;
        Ok(row.map(|r| r.get(0)))
    }
}

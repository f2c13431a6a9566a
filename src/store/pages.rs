//! Read queries for the planners' workspace (`ncplan serve`, `report --format html|csv`) and
//! its one write: review marks (migration 4), which never touch the analysis tables.
//!
//! The knowledge pages' SQL is public (`KNOWLEDGE`), so that each page can show what it ran.

use rusqlite::{OptionalExtension, params};

use super::sqlite::{Lite, sql};
use super::{Result, StoreError};
use crate::diff::{Change, ChangeKind};

/// A configured machine as the store knows it.
#[derive(Debug, Clone)]
pub struct MachineSummary {
    /// Name.
    pub name: String,
    /// Dialect.
    pub dialect: String,
    /// Watched folder (the share).
    pub folder: String,
    /// Programs seen.
    pub programs: i64,
    /// Revisions stored.
    pub revisions: i64,
    /// When its newest revision was seen.
    pub last_seen: Option<String>,
    /// Changes without a review mark.
    pub to_review: i64,
}

/// A review mark.
#[derive(Debug, Clone, PartialEq)]
pub struct Mark {
    /// `adopt`, `reject` or `note`.
    pub mark: String,
    /// The note (free text; may be empty for adopt and reject).
    pub note: String,
    /// Who.
    pub by: String,
    /// When (RFC 3339).
    pub at: String,
}

/// A stored change with where it is and its review marks.
#[derive(Debug, Clone)]
pub struct ChangeRow {
    /// `changes.id`.
    pub id: i64,
    /// The edited revision.
    pub revision_id: i64,
    /// The original revision.
    pub original_revision_id: i64,
    /// Machine.
    pub machine: String,
    /// Program name the revision stated.
    pub program: String,
    /// When it was detected.
    pub detected_at: String,
    /// The change.
    pub change: Change,
    /// Its marks, oldest first.
    pub marks: Vec<Mark>,
}

/// One program of a machine with its newest revision.
#[derive(Debug, Clone)]
pub struct ProgramRow {
    /// `programs.id`.
    pub id: i64,
    /// Path.
    pub path: String,
    /// Name.
    pub name: String,
    /// Newest revision id.
    pub last_revision: i64,
    /// When it was seen.
    pub last_seen: String,
    /// Its size.
    pub size: i64,
    /// Number of revisions.
    pub revisions: i64,
    /// Changes of the newest revision.
    pub changes: i64,
}

/// A program.
#[derive(Debug, Clone)]
pub struct ProgramInfo {
    /// `programs.id`.
    pub id: i64,
    /// Path.
    pub path: String,
    /// Name.
    pub name: String,
    /// `cam` or `machine`.
    pub role: String,
    /// Machine, for machine programs.
    pub machine: Option<String>,
    /// Dialect.
    pub dialect: String,
}

/// One revision on a program's timeline.
#[derive(Debug, Clone)]
pub struct TimelineRow {
    /// Revision id.
    pub id: i64,
    /// When it was seen.
    pub seen_at: String,
    /// Size in bytes.
    pub size: i64,
    /// SHA-256.
    pub hash: String,
    /// Status.
    pub status: String,
    /// Number of findings, and of errors among them.
    pub findings: (i64, i64),
    /// The original it was compared with (revision, path, rule) and the number of changes.
    pub original: Option<(i64, String, String, i64)>,
    /// Whether it is a partial write.
    pub partial: bool,
}

/// A most-edited program.
#[derive(Debug, Clone)]
pub struct EditedProgram {
    /// Machine.
    pub machine: String,
    /// Program name.
    pub program: String,
    /// `programs.id`.
    pub program_id: i64,
    /// Revisions with changes.
    pub edited_revisions: i64,
    /// Changes in all.
    pub changes: i64,
}

/// A revision whose analysis found errors.
#[derive(Debug, Clone)]
pub struct ErrorRevision {
    /// Revision id.
    pub id: i64,
    /// Program path.
    pub path: String,
    /// When it was seen.
    pub seen_at: String,
    /// Number of errors.
    pub errors: i64,
}

/// What to search the changes for; empty fields do not filter.
#[derive(Debug, Clone, Default)]
pub struct ChangeFilter {
    /// Part of the program name, or its number.
    pub program: String,
    /// Machine name.
    pub machine: String,
    /// Detected on or after this date (`YYYY-MM-DD`).
    pub since: String,
    /// Detected on or before this date.
    pub until: String,
    /// Change kind (`tool_renamed`).
    pub kind: String,
    /// Only those without a review mark.
    pub to_review: bool,
}

/// A query a planner saved in the SQL console (`saved_queries`, migration 7).
#[derive(Debug, Clone, PartialEq)]
pub struct SavedQuery {
    /// `saved_queries.id`.
    pub id: i64,
    /// The name it was saved under (free text: shown as text).
    pub name: String,
    /// Its SQL.
    pub sql: String,
    /// Who saved it.
    pub by: String,
    /// When (RFC 3339).
    pub at: String,
}

/// The SQL console's answer: the columns, the rows, and whether rows were left off.
pub type Limited = (Vec<String>, Vec<Vec<String>>, bool);

/// A knowledge page's query: its name, its title and its SQL.
#[derive(Debug, Clone, Copy)]
pub struct Knowledge {
    /// URL name.
    pub name: &'static str,
    /// Title.
    pub title: &'static str,
    /// The SQL the page runs on SQLite (read-only).
    pub sql: &'static str,
    /// Its twin on PostgreSQL: the same rows in the same order.
    pub pg_sql: &'static str,
}

/// The knowledge pages.
pub const KNOWLEDGE: &[Knowledge] = &[
    Knowledge {
        name: "feeds",
        title: "Feeds and speeds as run versus as posted",
        sql: "SELECT c.kind, m.name AS machine, COALESCE(r.name, p.name) AS program,
       (SELECT json_extract(t.value, '$.kind') FROM plans pl, json_each(pl.plan_json, '$.tools') t
         WHERE pl.revision_id = c.original_revision_id AND json_extract(t.value, '$.number') = w.tool) AS tool_kind,
       (SELECT json_extract(t.value, '$.diameter') FROM plans pl, json_each(pl.plan_json, '$.tools') t
         WHERE pl.revision_id = c.original_revision_id AND json_extract(t.value, '$.number') = w.tool) AS diameter,
       c.before AS posted, c.after AS run
FROM changes c
JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id LEFT JOIN machines m ON m.id = p.machine_id
LEFT JOIN workingsteps w ON w.revision_id = c.original_revision_id AND w.idx = c.workingstep
WHERE c.kind IN ('feed_changed', 'spindle_speed_changed')
  AND NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')
ORDER BY c.kind, tool_kind, diameter, machine, program, c.id",
        pg_sql: "SELECT kind, machine, program, tool_kind, diameter, posted, run FROM (
SELECT c.kind, m.name AS machine, COALESCE(r.name, p.name) AS program, t.kind AS tool_kind, t.diameter, c.before AS posted, c.after AS run, c.id
FROM changes c
JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id LEFT JOIN machines m ON m.id = p.machine_id
LEFT JOIN workingsteps w ON w.revision_id = c.original_revision_id AND w.idx = c.workingstep
LEFT JOIN (SELECT DISTINCT ON (pl.revision_id, (x.t->>'number')::float8) pl.revision_id, (x.t->>'number')::float8 AS number,
                  x.t->>'kind' AS kind, (x.t->>'diameter')::float8 AS diameter
           FROM plans pl, json_array_elements(CASE json_typeof(pl.plan_json::json->'tools') WHEN 'array' THEN pl.plan_json::json->'tools' ELSE '[]'::json END)
                WITH ORDINALITY AS x(t, n)
           WHERE pl.revision_id IN (SELECT original_revision_id FROM changes WHERE kind IN ('feed_changed', 'spindle_speed_changed'))
           ORDER BY pl.revision_id, (x.t->>'number')::float8, x.n) t ON t.revision_id = c.original_revision_id AND t.number = w.tool
WHERE c.kind IN ('feed_changed', 'spindle_speed_changed')
  AND NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')) q
ORDER BY kind COLLATE \"C\", tool_kind COLLATE \"C\" NULLS FIRST, diameter NULLS FIRST, machine COLLATE \"C\" NULLS FIRST, program COLLATE \"C\", id",
    },
    Knowledge {
        name: "tools",
        title: "Tool substitutions",
        sql: "SELECT before AS posted, after AS used, COUNT(*) AS times, COUNT(DISTINCT machine) AS machines,
       COUNT(DISTINCT program) AS programs, group_concat(DISTINCT machine ORDER BY machine) AS on_machines
FROM shopfloor_changes WHERE kind = 'tool_renamed'
GROUP BY before, after ORDER BY times DESC, before, after",
        pg_sql: "SELECT before AS posted, after AS used, COUNT(*) AS times, COUNT(DISTINCT machine) AS machines,
       COUNT(DISTINCT program) AS programs, string_agg(DISTINCT machine, ',' ORDER BY machine) AS on_machines
FROM shopfloor_changes WHERE kind = 'tool_renamed'
GROUP BY before, after ORDER BY times DESC, before COLLATE \"C\", after COLLATE \"C\"",
    },
    Knowledge {
        name: "start-points",
        title: "Start points that keep moving",
        sql: "SELECT machine, program, workingstep, MIN(operation) AS operation, COUNT(*) AS moves, COUNT(DISTINCT after) AS places,
       group_concat(after, ' | ' ORDER BY change_id) AS moved_to, MAX(detected_at) AS last
FROM shopfloor_changes WHERE kind = 'start_point_moved'
GROUP BY machine, program, workingstep ORDER BY moves DESC, machine, program, workingstep",
        pg_sql: "SELECT machine, program, workingstep, MIN(operation COLLATE \"C\") AS operation, COUNT(*) AS moves, COUNT(DISTINCT after) AS places,
       string_agg(after, ' | ' ORDER BY change_id) AS moved_to, MAX(detected_at) AS last
FROM shopfloor_changes WHERE kind = 'start_point_moved'
GROUP BY machine, program, workingstep ORDER BY moves DESC, machine COLLATE \"C\" NULLS FIRST, program COLLATE \"C\", workingstep",
    },
    Knowledge {
        name: "depths",
        title: "Depth changes",
        sql: "SELECT machine, program, workingstep, MIN(operation) AS operation, before AS posted, after AS run, COUNT(*) AS times, MAX(detected_at) AS last
FROM shopfloor_changes WHERE kind IN ('depth_changed', 'axial_depth_changed')
GROUP BY machine, program, workingstep, before, after ORDER BY times DESC, machine, program, workingstep, before, after",
        pg_sql: "SELECT machine, program, workingstep, MIN(operation COLLATE \"C\") AS operation, before AS posted, after AS run, COUNT(*) AS times,
       MAX(detected_at) AS last
FROM shopfloor_changes WHERE kind IN ('depth_changed', 'axial_depth_changed')
GROUP BY machine, program, workingstep, before, after
ORDER BY times DESC, machine COLLATE \"C\" NULLS FIRST, program COLLATE \"C\", workingstep, before COLLATE \"C\", after COLLATE \"C\"",
    },
];

/// Saved queries of the SQL console: a title and the SQL, which both engines run alike.
pub const SAVED_QUERIES: &[(&str, &str)] = &[
    (
        "The newest changes",
        "SELECT machine, program, kind, before, after, detected_at FROM shopfloor_changes ORDER BY detected_at DESC, change_id DESC LIMIT 50",
    ),
    (
        "Programs whose feeds are changed most, per machine",
        "SELECT machine, program, COUNT(*) n FROM shopfloor_changes WHERE kind = 'feed_changed' GROUP BY 1, 2 ORDER BY n DESC, 1, 2",
    ),
    (
        "Revisions with errors",
        "SELECT r.id, p.path, r.seen_at, COUNT(*) errors FROM diagnostics d JOIN revisions r ON r.id = d.revision_id JOIN programs p ON p.id = r.program_id WHERE d.severity = 'error' GROUP BY r.id, p.path, r.seen_at ORDER BY r.id DESC",
    ),
    (
        "Hole diameters drilled",
        "SELECT diameter, SUM(positions) holes FROM features WHERE kind = 'round_hole' GROUP BY 1 ORDER BY 2 DESC, 1",
    ),
    (
        "Review marks",
        "SELECT change_id, revision_id, kind, before, after, mark, note, marked_by, marked_at FROM review_marks ORDER BY id DESC",
    ),
];

/// The changes of `shopfloor_changes` with the columns [`ChangeRow`] reads; `{where}` filters.
pub(super) const CHANGE_ROWS: &str =
    "SELECT c.id, c.revision_id, c.original_revision_id, COALESCE(m.name, ''), COALESCE(r.name, p.name), c.detected_at,
        c.workingstep, c.operation, c.kind, c.field, c.before, c.after, c.line, c.original_line,
        c.region_min_x, c.region_min_y, c.region_min_z, c.region_max_x, c.region_max_y, c.region_max_z, c.deviation, c.detail
 FROM changes c JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id LEFT JOIN machines m ON m.id = p.machine_id
 WHERE NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')";

/// Rows waiting for review: no mark names the change.
pub(super) const UNMARKED: &str = "NOT EXISTS (SELECT 1 FROM review_marks v WHERE v.change_id = c.id)";

fn change_row(r: &rusqlite::Row<'_>) -> rusqlite::Result<ChangeRow> {
    let kind: String = r.get(8)?;
    let region = match (r.get::<_, Option<f64>>(14)?, r.get::<_, Option<f64>>(17)?) {
        (Some(_), Some(_)) => Some(crate::plan::BBox {
            min: [r.get(14)?, r.get::<_, Option<f64>>(15)?.unwrap_or(0.0), r.get::<_, Option<f64>>(16)?.unwrap_or(0.0)],
            max: [r.get(17)?, r.get::<_, Option<f64>>(18)?.unwrap_or(0.0), r.get::<_, Option<f64>>(19)?.unwrap_or(0.0)],
        }),
        _ => None,
    };
    let mut row = ChangeRow {
        id: r.get(0)?,
        revision_id: r.get(1)?,
        original_revision_id: r.get(2)?,
        machine: r.get(3)?,
        program: r.get(4)?,
        detected_at: r.get(5)?,
        change: Change {
            kind: serde_json::from_value(serde_json::Value::String(kind)).unwrap_or(ChangeKind::ToolpathChanged),
            workingstep: r.get(6)?,
            operation: r.get(7)?,
            field: r.get(9)?,
            before: r.get(10)?,
            after: r.get(11)?,
            line: r.get(12)?,
            original_line: r.get(13)?,
            region,
            deviation: r.get(20)?,
            detail: crate::diff::Detail::default(),
        },
        marks: Vec::new(),
    };
    row.change.set_detail(&r.get::<_, String>(21)?);
    Ok(row)
}

/// The longest value a console query may make (a string or blob, in bytes).
const CONSOLE_LENGTH: i32 = 1 << 20;
/// The most columns a console query may have (with [`CONSOLE_LENGTH`], what one row may take).
const CONSOLE_COLUMNS: i32 = 64;
/// The cells of the rows a console query shows, in bytes, after which the rest is left off.
const CONSOLE_BYTES: usize = 2 << 20;
/// The most of one text cell the console shows, in bytes.
const CONSOLE_CELL: usize = 16 << 10;

/// A console cell's text: its first [`CONSOLE_CELL`] bytes (to a character's start), and
/// how long it is when that is not all (a page of 99 columns of 1 MiB took 144 s to render).
pub(in crate::store) fn console_text(t: &[u8]) -> String {
    if t.len() <= CONSOLE_CELL {
        return String::from_utf8_lossy(t).into_owned();
    }
    let mut end = CONSOLE_CELL;
    while end > 0 && t[end] & 0xC0 == 0x80 {
        end -= 1;
    }
    format!("{} … ({} bytes in all)", String::from_utf8_lossy(&t[..end]), t.len())
}
/// Virtual machine steps between two looks at a console query's clock.
const CONSOLE_STEPS: i32 = 100;

impl Lite {
    fn rows<T>(
        &self,
        about: &'static str,
        query: &str,
        args: impl rusqlite::Params,
        f: impl FnMut(&rusqlite::Row<'_>) -> rusqlite::Result<T>,
    ) -> Result<Vec<T>> {
        let mut stmt = self.conn.prepare_cached(query).map_err(sql("preparing a query"))?;
        let rows = stmt.query_map(args, f).map_err(sql(about))?;
        rows.collect::<std::result::Result<_, _>>().map_err(sql(about))
    }

    /// The machines with their programs, revisions, newest revision and review queue.
    pub(super) fn machines(&self) -> Result<Vec<MachineSummary>> {
        self.rows(
            "listing machines",
            &format!(
                "WITH pr AS (SELECT machine_id AS mid, COUNT(*) AS n FROM programs GROUP BY machine_id),
                      rv AS (SELECT p.machine_id AS mid, COUNT(*) AS n, MAX(r.seen_at) AS last
                             FROM revisions r JOIN programs p ON p.id = r.program_id GROUP BY p.machine_id),
                      q AS (SELECT p.machine_id AS mid, COUNT(*) AS n
                            FROM changes c JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id
                            WHERE {UNMARKED}
                              AND NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')
                            GROUP BY p.machine_id)
                 SELECT m.name, m.dialect, m.folder, COALESCE(pr.n, 0), COALESCE(rv.n, 0), rv.last, COALESCE(q.n, 0)
                 FROM machines m LEFT JOIN pr ON pr.mid = m.id LEFT JOIN rv ON rv.mid = m.id LEFT JOIN q ON q.mid = m.id
                 ORDER BY m.name"
            ),
            [],
            |r| {
                Ok(MachineSummary {
                    name: r.get(0)?,
                    dialect: r.get(1)?,
                    folder: r.get(2)?,
                    programs: r.get(3)?,
                    revisions: r.get(4)?,
                    last_seen: r.get(5)?,
                    to_review: r.get(6)?,
                })
            },
        )
    }

    /// The rows with their review marks, read in one query.
    fn with_marks(&self, mut rows: Vec<ChangeRow>) -> Result<Vec<ChangeRow>> {
        if rows.is_empty() {
            return Ok(rows);
        }
        let ids = serde_json::to_string(&rows.iter().map(|r| r.id).collect::<Vec<_>>()).unwrap_or_else(|_| "[]".into());
        let marks = self.rows(
            "reading review marks",
            "SELECT change_id, mark, note, marked_by, marked_at FROM review_marks
             WHERE change_id IN (SELECT value FROM json_each(?1)) ORDER BY id",
            [ids],
            |r| Ok((r.get::<_, i64>(0)?, Mark { mark: r.get(1)?, note: r.get(2)?, by: r.get(3)?, at: r.get(4)? })),
        )?;
        let mut by_change: std::collections::BTreeMap<i64, Vec<Mark>> = std::collections::BTreeMap::new();
        for (id, m) in marks {
            by_change.entry(id).or_default().push(m);
        }
        for row in &mut rows {
            row.marks = by_change.remove(&row.id).unwrap_or_default();
        }
        Ok(rows)
    }

    /// The review marks of a change, oldest first.
    pub(super) fn marks(&self, change_id: i64) -> Result<Vec<Mark>> {
        self.rows(
            "reading review marks",
            "SELECT mark, note, marked_by, marked_at FROM review_marks WHERE change_id = ?1 ORDER BY id",
            [change_id],
            |r| Ok(Mark { mark: r.get(0)?, note: r.get(1)?, by: r.get(2)?, at: r.get(3)? }),
        )
    }

    /// The changes that match `filter`, newest first, at most `limit`.
    pub(super) fn search_changes(&self, filter: &ChangeFilter, limit: usize) -> Result<Vec<ChangeRow>> {
        let program_number = filter.program.trim().trim_start_matches(['O', 'o']).parse::<u64>().ok().map(|n| format!("O{n}"));
        let query = format!(
            "{CHANGE_ROWS}
               AND (?1 = '' OR COALESCE(r.name, p.name) LIKE '%' || ?1 || '%' OR p.path LIKE '%' || ?1 || '%' OR COALESCE(r.name, p.name) = ?2)
               AND (?3 = '' OR m.name = ?3)
               AND (?4 = '' OR c.detected_at >= ?4)
               AND (?5 = '' OR c.detected_at < date(?5, '+1 day'))
               AND (?6 = '' OR c.kind = ?6)
               AND (?7 = 0 OR {UNMARKED})
             ORDER BY c.detected_at DESC, c.id DESC LIMIT ?8"
        );
        let rows = self.rows(
            "searching changes",
            &query,
            params![
                filter.program.trim(),
                program_number.unwrap_or_default(),
                filter.machine.trim(),
                filter.since.trim(),
                filter.until.trim(),
                filter.kind.trim(),
                filter.to_review,
                limit as i64
            ],
            change_row,
        )?;
        self.with_marks(rows)
    }

    /// The changes of one edited revision, in their order.
    pub(super) fn change_rows(&self, revision: i64) -> Result<Vec<ChangeRow>> {
        let rows = self.rows("reading changes", &format!("{CHANGE_ROWS} AND c.revision_id = ?1 ORDER BY c.id"), [revision], change_row)?;
        self.with_marks(rows)
    }

    /// Changes per ISO week (`YYYY-Www`) per machine, oldest week first, for the last `weeks` weeks with changes.
    pub(super) fn changes_per_week(&self, weeks: usize) -> Result<Vec<(String, String, i64)>> {
        self.rows(
            "counting changes per week",
            "WITH w AS (SELECT strftime('%Y-W%W', c.detected_at) AS week, COALESCE(m.name, '') AS machine
                        FROM changes c JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id
                        LEFT JOIN machines m ON m.id = p.machine_id
                        WHERE c.detected_at >= date((SELECT MAX(detected_at) FROM changes), '-' || (?1 * 7) || ' days')
                          AND NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')),
                  last AS (SELECT DISTINCT week FROM w ORDER BY week DESC LIMIT ?1)
             SELECT week, machine, COUNT(*) FROM w WHERE week IN (SELECT week FROM last) GROUP BY week, machine ORDER BY week, machine",
            [weeks as i64],
            |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)),
        )
    }

    /// The programs edited most: by revisions with changes.
    pub(super) fn most_edited(&self, limit: usize) -> Result<Vec<EditedProgram>> {
        self.rows(
            "listing the most edited programs",
            "SELECT COALESCE(m.name, ''), p.name, p.id, COUNT(DISTINCT c.revision_id), COUNT(*)
             FROM changes c JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id LEFT JOIN machines m ON m.id = p.machine_id
             WHERE NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')
             GROUP BY p.id ORDER BY 4 DESC, 5 DESC, p.name LIMIT ?1",
            [limit as i64],
            |r| Ok(EditedProgram { machine: r.get(0)?, program: r.get(1)?, program_id: r.get(2)?, edited_revisions: r.get(3)?, changes: r.get(4)? }),
        )
    }

    /// How often each change kind occurs, most often first.
    pub(super) fn kind_counts(&self) -> Result<Vec<(String, i64)>> {
        self.rows(
            "counting change kinds",
            "SELECT kind, COUNT(*) FROM changes c
             WHERE NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')
             GROUP BY kind ORDER BY 2 DESC, 1",
            [],
            |r| Ok((r.get(0)?, r.get(1)?)),
        )
    }

    /// The newest revisions whose analysis found errors.
    pub(super) fn error_revisions(&self, limit: usize) -> Result<Vec<ErrorRevision>> {
        self.rows(
            "listing revisions with errors",
            "SELECT r.id, p.path, r.seen_at, (SELECT COUNT(*) FROM diagnostics d WHERE d.revision_id = r.id AND d.severity = 'error') AS n
             FROM revisions r JOIN programs p ON p.id = r.program_id
             WHERE r.id IN (SELECT DISTINCT revision_id FROM diagnostics WHERE severity = 'error')
             ORDER BY r.id DESC LIMIT ?1",
            [limit as i64],
            |r| Ok(ErrorRevision { id: r.get(0)?, path: r.get(1)?, seen_at: r.get(2)?, errors: r.get(3)? }),
        )
    }

    /// When the newest revision of each CAM or machine folder was seen: `(folder, when)`.
    pub(super) fn last_seen_per_folder(&self) -> Result<Vec<(String, String)>> {
        self.rows(
            "reading the last event per share",
            "SELECT COALESCE(m.folder, 'cam'), MAX(r.seen_at) FROM revisions r JOIN programs p ON p.id = r.program_id
             LEFT JOIN machines m ON m.id = p.machine_id GROUP BY 1 ORDER BY 1",
            [],
            |r| Ok((r.get(0)?, r.get(1)?)),
        )
    }

    /// One machine.
    pub(super) fn machine(&self, name: &str) -> Result<Option<MachineSummary>> {
        Ok(self.machines()?.into_iter().find(|m| m.name == name))
    }

    /// A machine's programs with their newest revision.
    pub(super) fn machine_programs(&self, machine: &str) -> Result<Vec<ProgramRow>> {
        self.rows(
            "listing a machine's programs",
            "SELECT p.id, p.path, COALESCE(r.name, p.name), r.id, r.seen_at, r.size,
                    (SELECT COUNT(*) FROM revisions x WHERE x.program_id = p.id),
                    (SELECT COUNT(*) FROM changes c WHERE c.revision_id = r.id)
             FROM programs p JOIN machines m ON m.id = p.machine_id
             JOIN revisions r ON r.id = (SELECT MAX(id) FROM revisions WHERE program_id = p.id)
             WHERE m.name = ?1 ORDER BY p.path",
            [machine],
            |r| {
                Ok(ProgramRow {
                    id: r.get(0)?,
                    path: r.get(1)?,
                    name: r.get(2)?,
                    last_revision: r.get(3)?,
                    last_seen: r.get(4)?,
                    size: r.get(5)?,
                    revisions: r.get(6)?,
                    changes: r.get(7)?,
                })
            },
        )
    }

    /// One program.
    pub(super) fn program(&self, id: i64) -> Result<Option<ProgramInfo>> {
        self.conn
            .query_row(
                "SELECT p.id, p.path, p.name, p.role, m.name, p.dialect FROM programs p LEFT JOIN machines m ON m.id = p.machine_id WHERE p.id = ?1",
                [id],
                |r| Ok(ProgramInfo { id: r.get(0)?, path: r.get(1)?, name: r.get(2)?, role: r.get(3)?, machine: r.get(4)?, dialect: r.get(5)? }),
            )
            .optional()
            .map_err(sql("reading a program"))
    }

    /// The program a revision belongs to.
    pub(super) fn program_of(&self, revision: i64) -> Result<Option<i64>> {
        self.conn
            .query_row("SELECT program_id FROM revisions WHERE id = ?1", [revision], |r| r.get(0))
            .optional()
            .map_err(sql("reading a revision"))
    }

    /// Every revision of a program, oldest first.
    pub(super) fn timeline(&self, program: i64) -> Result<Vec<TimelineRow>> {
        self.rows(
            "reading a program's revisions",
            "SELECT r.id, r.seen_at, r.size, r.hash, r.status,
                    (SELECT COUNT(*) FROM diagnostics d WHERE d.revision_id = r.id),
                    (SELECT COUNT(*) FROM diagnostics d WHERE d.revision_id = r.id AND d.severity = 'error'),
                    c.original_revision_id, (SELECT op.path FROM revisions o JOIN programs op ON op.id = o.program_id WHERE o.id = c.original_revision_id),
                    c.rule, c.changes,
                    EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = r.id AND k.mark = 'partial')
             FROM revisions r LEFT JOIN comparisons c ON c.revision_id = r.id WHERE r.program_id = ?1 ORDER BY r.id",
            [program],
            |r| {
                Ok(TimelineRow {
                    id: r.get(0)?,
                    seen_at: r.get(1)?,
                    size: r.get(2)?,
                    hash: r.get(3)?,
                    status: r.get(4)?,
                    findings: (r.get(5)?, r.get(6)?),
                    original: match (r.get::<_, Option<i64>>(7)?, r.get::<_, Option<String>>(8)?) {
                        (Some(id), Some(path)) => Some((id, path, r.get::<_, Option<String>>(9)?.unwrap_or_default(), r.get(10)?)),
                        _ => None,
                    },
                    partial: r.get(11)?,
                })
            },
        )
    }

    /// The CAM originals a program's revisions were compared with: `(program id, path, newest revision)`.
    pub(super) fn originals_of(&self, program: i64) -> Result<Vec<(i64, String, i64)>> {
        self.rows(
            "reading a program's originals",
            "SELECT op.id, op.path, MAX(o.id) FROM comparisons c JOIN revisions r ON r.id = c.revision_id
             JOIN revisions o ON o.id = c.original_revision_id JOIN programs op ON op.id = o.program_id
             WHERE r.program_id = ?1 GROUP BY op.id ORDER BY op.path",
            [program],
            |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)),
        )
    }

    /// Adds a review mark to a change: `adopt`, `reject` or `note`. Returns the revision the
    /// change belongs to, or `None` when there is no such change. Analysis tables are only read.
    pub(super) fn add_mark(&self, change_id: i64, mark: &str, note: &str, by: &str, at: &str) -> Result<Option<i64>> {
        let n = self
            .conn
            .execute(
                "INSERT INTO review_marks(change_id, revision_id, kind, before, after, mark, note, marked_by, marked_at)
                 SELECT id, revision_id, kind, before, after, ?2, ?3, ?4, ?5 FROM changes WHERE id = ?1",
                params![change_id, mark, note, by, at],
            )
            .map_err(sql("recording a review mark"))?;
        if n == 0 {
            return Ok(None);
        }
        self.conn
            .query_row("SELECT revision_id FROM changes WHERE id = ?1", [change_id], |r| r.get(0))
            .optional()
            .map_err(sql("recording a review mark"))
    }

    /// The planners' saved queries, oldest first.
    pub(super) fn saved_queries(&self) -> Result<Vec<SavedQuery>> {
        self.rows("reading saved queries", "SELECT id, name, sql, saved_by, saved_at FROM saved_queries ORDER BY id", [], |r| {
            Ok(SavedQuery { id: r.get(0)?, name: r.get(1)?, sql: r.get(2)?, by: r.get(3)?, at: r.get(4)? })
        })
    }

    /// Saves a query under `name`; returns its id.
    pub(super) fn save_query(&self, name: &str, sql_text: &str, by: &str, at: &str) -> Result<i64> {
        self.conn
            .query_row(
                "INSERT INTO saved_queries(name, sql, saved_by, saved_at) VALUES (?1, ?2, ?3, ?4) RETURNING id",
                params![name, sql_text, by, at],
                |r| r.get(0),
            )
            .map_err(sql("saving a query"))
    }

    /// Records a sign-in session (by its token's hash) until `expires_at`, and forgets the
    /// sessions that ended by `created_at`.
    pub(super) fn start_session(&self, token_hash: &str, user: &str, created_at: &str, expires_at: &str) -> Result<()> {
        self.conn.execute("DELETE FROM web_sessions WHERE expires_at <= ?1", [created_at]).map_err(sql("forgetting ended sessions"))?;
        self.conn
            .execute(
                "INSERT INTO web_sessions(token_hash, user_name, created_at, expires_at) VALUES (?1, ?2, ?3, ?4)",
                params![token_hash, user, created_at, expires_at],
            )
            .map_err(sql("recording a session"))?;
        Ok(())
    }

    /// The planner of the session whose token hashes to `token_hash`, unless it ended by `now`.
    pub(super) fn session_user(&self, token_hash: &str, now: &str) -> Result<Option<String>> {
        self.conn
            .query_row("SELECT user_name FROM web_sessions WHERE token_hash = ?1 AND expires_at > ?2", [token_hash, now], |r| r.get(0))
            .optional()
            .map_err(sql("reading a session"))
    }

    /// Ends a session.
    pub(super) fn end_session(&self, token_hash: &str) -> Result<()> {
        self.conn.execute("DELETE FROM web_sessions WHERE token_hash = ?1", [token_hash]).map_err(sql("ending a session"))?;
        Ok(())
    }

    /// Runs one read-only statement for the SQL console: at most `max_rows` rows and
    /// [`CONSOLE_BYTES`] of cells, [`CONSOLE_COLUMNS`] columns, stopped (SQLite's progress handler, every
    /// [`CONSOLE_STEPS`] virtual machine steps) once it has run `limit`, no value longer than
    /// [`CONSOLE_LENGTH`] (so that no one step, such as `hex(zeroblob(1e9))`, runs long or
    /// takes much memory). Returns the columns, the rows and whether rows were left off.
    pub(super) fn query_limited(
        &self,
        sql_text: &str,
        max_rows: usize,
        limit: std::time::Duration,
    ) -> std::result::Result<Limited, super::QueryError> {
        use rusqlite::limits::Limit;
        let first = super::one_reading_statement(sql_text)?;
        let started = std::time::Instant::now();
        let length = self.conn.set_limit(Limit::SQLITE_LIMIT_LENGTH, CONSOLE_LENGTH);
        let columns = self.conn.set_limit(Limit::SQLITE_LIMIT_COLUMN, CONSOLE_COLUMNS);
        self.conn.progress_handler(CONSOLE_STEPS, Some(move || started.elapsed() > limit));
        let result = self.query_capped(first, max_rows);
        self.conn.progress_handler(0, None::<fn() -> bool>);
        self.conn.set_limit(Limit::SQLITE_LIMIT_LENGTH, length);
        self.conn.set_limit(Limit::SQLITE_LIMIT_COLUMN, columns);
        result.map_err(|e| match e {
            StoreError::Sql { source, .. } => match source.downcast_ref::<rusqlite::Error>() {
                Some(rusqlite::Error::SqliteFailure(f, _)) if f.code == rusqlite::ErrorCode::OperationInterrupted => {
                    super::QueryError::Refused(format!("the query ran past its time limit of {} ms and was stopped", limit.as_millis()))
                }
                Some(rusqlite::Error::SqliteFailure(f, _)) if f.code == rusqlite::ErrorCode::TooBig => super::QueryError::Refused(format!(
                    "the query made a value longer than the console's limit of {} bytes and was stopped",
                    CONSOLE_LENGTH
                )),
                Some(e) => super::QueryError::Sql(super::sqlite::plain(e)),
                None => super::QueryError::Sql(source.to_string()),
            },
            other => super::QueryError::Sql(other.to_string()),
        })
    }

    fn query_capped(&self, sql_text: &str, max_rows: usize) -> Result<Limited> {
        let mut stmt = self.conn.prepare(sql_text).map_err(sql("preparing the query"))?;
        if !stmt.readonly() {
            return Err(StoreError::Sql {
                about: "checking the query",
                source: Box::new(rusqlite::Error::SqliteFailure(
                    rusqlite::ffi::Error::new(rusqlite::ffi::SQLITE_READONLY),
                    Some("the statement would change the database; queries only read".into()),
                )),
            });
        }
        let names: Vec<String> = stmt.column_names().iter().map(|s| (*s).to_owned()).collect();
        let mut rows = stmt.query([]).map_err(sql("running the query"))?;
        let mut out = Vec::new();
        let (mut more, mut bytes) = (false, 0);
        while let Some(row) = rows.next().map_err(sql("reading a row"))? {
            if out.len() == max_rows || bytes > CONSOLE_BYTES {
                more = true;
                break;
            }
            let mut cells = Vec::with_capacity(names.len());
            for i in 0..names.len() {
                use rusqlite::types::ValueRef;
                cells.push(match row.get_ref(i).map_err(sql("reading a cell"))? {
                    ValueRef::Text(t) => console_text(t),
                    ValueRef::Null => String::new(),
                    ValueRef::Integer(x) => x.to_string(),
                    ValueRef::Real(x) => x.to_string(),
                    ValueRef::Blob(b) => format!("<{} bytes>", b.len()),
                });
            }
            bytes += cells.iter().map(String::len).sum::<usize>();
            out.push(cells);
        }
        Ok((names, out, more))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn store_with_a_change() -> Lite {
        let s = Lite::open_in_memory("").unwrap();
        s.conn
            .execute_batch(
                "INSERT INTO machines(id, name, dialect, folder) VALUES (1, 'DMU50', 'fanuc', '/share');
                 INSERT INTO programs(id, path, role, machine_id, name, program_key, stem, dialect) VALUES (1, '/cam/O1.nc', 'cam', NULL, 'O1', 'O1', 'O1', 'fanuc');
                 INSERT INTO programs(id, path, role, machine_id, name, program_key, stem, dialect) VALUES (2, '/share/O1.nc', 'machine', 1, 'O1', 'O1', 'O1', 'fanuc');
                 INSERT INTO blobs VALUES ('a', 1, x'00'), ('b', 1, x'01');
                 INSERT INTO revisions(id, program_id, hash, size, seen_at, encoding, status) VALUES
                   (1, 1, 'a', 1, '2026-11-01T00:00:00.000Z', 'utf-8', 'analysed'),
                   (2, 2, 'b', 1, '2026-11-02T00:00:00.000Z', 'utf-8', 'analysed');
                 INSERT INTO comparisons VALUES (2, 1, '2026-11-02T00:00:00.000Z', 2, 'file-name');
                 INSERT INTO changes(id, revision_id, original_revision_id, workingstep, operation, kind, field, before, after, detected_at) VALUES
                   (10, 2, 1, 1, 'plane finish milling', 'tool_renamed', 'tool', 'T1', 'T8', '2026-11-02T00:00:00.000Z'),
                   (11, 2, 1, 1, 'plane finish milling', 'feed_changed', 'feed', '240 mm/min', '200 mm/min', '2026-11-02T00:00:00.000Z');",
            )
            .unwrap();
        s
    }

    #[test]
    fn a_mark_takes_a_change_off_the_queue_and_leaves_the_analysis_alone() {
        let s = store_with_a_change();
        let queue = ChangeFilter { to_review: true, ..ChangeFilter::default() };
        assert_eq!(s.search_changes(&queue, 10).unwrap().len(), 2);
        assert_eq!(s.machines().unwrap()[0].to_review, 2);
        assert_eq!(s.add_mark(10, "adopt", "", "ada", "2026-11-03T00:00:00.000Z").unwrap(), Some(2));
        assert_eq!(s.add_mark(99, "adopt", "", "ada", "2026-11-03T00:00:00.000Z").unwrap(), None);
        let left = s.search_changes(&queue, 10).unwrap();
        assert_eq!(left.iter().map(|r| r.id).collect::<Vec<_>>(), vec![11]);
        assert_eq!(s.machines().unwrap()[0].to_review, 1);
        let rows = s.change_rows(2).unwrap();
        assert_eq!(
            rows[0].marks,
            vec![Mark { mark: "adopt".into(), note: String::new(), by: "ada".into(), at: "2026-11-03T00:00:00.000Z".into() }]
        );
        assert!(s.add_mark(11, "maybe", "", "ada", "t").is_err(), "only adopt, reject and note");
        assert!(s.conn.execute_batch("UPDATE review_marks SET mark = 'reject'").is_err(), "marks are a record");
        // The change rows are as they were.
        let (_, changes) = s.query("SELECT kind, before, after FROM changes ORDER BY id").unwrap();
        assert_eq!(changes[0], vec!["tool_renamed", "T1", "T8"]);
    }

    #[test]
    fn saved_queries_are_kept_with_who_and_when() {
        let s = store_with_a_change();
        assert!(s.saved_queries().unwrap().is_empty());
        let id = s.save_query("<b>feeds</b>", "SELECT 1", "ada", "2026-11-03T00:00:00.000Z").unwrap();
        s.save_query("second", "SELECT 2", "bob", "2026-11-04T00:00:00.000Z").unwrap();
        let saved = s.saved_queries().unwrap();
        assert_eq!(
            saved[0],
            SavedQuery { id, name: "<b>feeds</b>".into(), sql: "SELECT 1".into(), by: "ada".into(), at: "2026-11-03T00:00:00.000Z".into() }
        );
        assert_eq!(saved.iter().map(|q| q.name.as_str()).collect::<Vec<_>>(), ["<b>feeds</b>", "second"]);
    }

    #[test]
    fn search_filters_by_program_number_machine_dates_and_kind() {
        let s = store_with_a_change();
        let f = |program: &str, machine: &str, since: &str, until: &str, kind: &str| ChangeFilter {
            program: program.into(),
            machine: machine.into(),
            since: since.into(),
            until: until.into(),
            kind: kind.into(),
            to_review: false,
        };
        let n = |filter: ChangeFilter| s.search_changes(&filter, 10).unwrap().len();
        assert_eq!(n(f("1", "", "", "", "")), 2, "by number");
        assert_eq!(n(f("O1", "DMU50", "2026-11-02", "2026-11-02", "feed_changed")), 1);
        assert_eq!(n(f("", "HAAS1", "", "", "")), 0);
        assert_eq!(n(f("", "", "2026-11-03", "", "")), 0);
    }

    #[test]
    fn the_console_limits_rows_and_time_and_refuses_writes() {
        let s = store_with_a_change();
        let (_, rows, more) =
            s.query_limited("SELECT value FROM generate_series(1, 100)", 10, std::time::Duration::from_secs(5)).unwrap_or_else(|_| {
                s.query_limited(
                    "WITH RECURSIVE n(x) AS (SELECT 1 UNION ALL SELECT x + 1 FROM n WHERE x < 100) SELECT x FROM n",
                    10,
                    std::time::Duration::from_secs(5),
                )
                .unwrap()
            });
        assert_eq!((rows.len(), more), (10, true));
        let forever = "WITH RECURSIVE n(x) AS (SELECT 1 UNION ALL SELECT x + 1 FROM n) SELECT COUNT(*) FROM n";
        let err = s.query_limited(forever, 10, std::time::Duration::from_millis(100)).unwrap_err();
        assert!(err.to_string().contains("time limit"), "{err}");
        assert!(s.query_limited("DELETE FROM changes", 10, std::time::Duration::from_secs(1)).is_err());
        // No value past the length limit, whatever makes it; a long text cell is shown in part.
        for huge in ["SELECT hex(zeroblob(1e9))", "SELECT replace(hex(zeroblob(300000)), '0', 'ab')", "SELECT length(randomblob(2e6))"] {
            let err = s.query_limited(huge, 10, std::time::Duration::from_secs(5)).unwrap_err();
            assert!(err.to_string().contains("longer than the console's limit"), "{huge}: {err}");
        }
        // printf stops at the limit too, with an empty text.
        let (_, rows, _) = s.query_limited("SELECT printf('%.*c', 2000000, 'x')", 10, std::time::Duration::from_secs(5)).unwrap();
        assert_eq!(rows, [[""]]);
        let (_, rows, _) = s.query_limited("SELECT 'é' || hex(zeroblob(400000))", 10, std::time::Duration::from_secs(5)).unwrap();
        assert!(rows[0][0].len() < CONSOLE_CELL + 40 && rows[0][0].ends_with(" … (800002 bytes in all)"), "{}", rows[0][0].len());
        let cut = console_text("aé€".repeat(5_000).as_bytes());
        assert!(!cut.contains('\u{FFFD}') && cut.ends_with(" … (30000 bytes in all)"), "cut inside a character");
        // The limits are the console's: the connection's own queries are as before.
        s.query("SELECT length(hex(zeroblob(2000000)))").unwrap();
        for k in KNOWLEDGE {
            s.query(k.sql).unwrap_or_else(|e| panic!("{}: {e}", k.name));
        }
    }
}

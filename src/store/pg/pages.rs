//! The workspace's read queries and review marks on PostgreSQL: the twin of each SQLite
//! query in `store/pages.rs`, with the same rows in the same order (the same tie-breaks;
//! text ordered by code point, `COLLATE "C"`, as SQLite orders it; NULLs first as SQLite
//! puts them), so that `ncplan serve` renders the same pages on both engines. Times are
//! fixed-width RFC 3339 text, which every collation orders alike: they are compared without
//! `COLLATE "C"`, so that the indexes on them serve.

use std::collections::BTreeMap;

use postgres::Row;

use super::{Pg, plain, sql};
use crate::diff::Change;
use crate::store::pages::{CHANGE_ROWS, UNMARKED};
use crate::store::{
    ChangeFilter, ChangeRow, EditedProgram, ErrorRevision, Limited, MachineSummary, Mark, ProgramInfo, ProgramRow, QueryError, Result,
    SavedQuery, TimelineRow,
};

/// A row of `pages::CHANGE_ROWS`.
fn change_row(r: &Row) -> ChangeRow {
    let kind: String = r.get(8);
    let region = match (r.get::<_, Option<f64>>(14), r.get::<_, Option<f64>>(17)) {
        (Some(a), Some(b)) => Some(crate::plan::BBox {
            min: [a, r.get::<_, Option<f64>>(15).unwrap_or(0.0), r.get::<_, Option<f64>>(16).unwrap_or(0.0)],
            max: [b, r.get::<_, Option<f64>>(18).unwrap_or(0.0), r.get::<_, Option<f64>>(19).unwrap_or(0.0)],
        }),
        _ => None,
    };
    let mut row = ChangeRow {
        id: r.get(0),
        revision_id: r.get(1),
        original_revision_id: r.get(2),
        machine: r.get(3),
        program: r.get(4),
        detected_at: r.get(5),
        change: Change {
            kind: serde_json::from_value(serde_json::Value::String(kind)).unwrap_or(crate::diff::ChangeKind::ToolpathChanged),
            workingstep: r.get::<_, i64>(6) as u32,
            operation: r.get(7),
            field: r.get(9),
            before: r.get(10),
            after: r.get(11),
            line: r.get::<_, Option<i64>>(12).map(|l| l as u32),
            original_line: r.get::<_, Option<i64>>(13).map(|l| l as u32),
            region,
            deviation: r.get(20),
            detail: crate::diff::Detail::default(),
        },
        marks: Vec::new(),
    };
    row.change.set_detail(&r.get::<_, String>(21));
    row
}

fn machine_summary(r: &Row) -> MachineSummary {
    MachineSummary {
        name: r.get(0),
        dialect: r.get(1),
        folder: r.get(2),
        programs: r.get(3),
        revisions: r.get(4),
        last_seen: r.get(5),
        to_review: r.get(6),
    }
}

/// The machines query of `pages.rs` (`UNMARKED` written out: the statement is prepared once).
const MACHINES: &str = "WITH pr AS (SELECT machine_id AS mid, COUNT(*) AS n FROM programs GROUP BY machine_id),
      rv AS (SELECT p.machine_id AS mid, COUNT(*) AS n, MAX(r.seen_at) AS last
             FROM revisions r JOIN programs p ON p.id = r.program_id GROUP BY p.machine_id),
      q AS (SELECT p.machine_id AS mid, COUNT(*) AS n
            FROM changes c JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id
            WHERE NOT EXISTS (SELECT 1 FROM review_marks v WHERE v.change_id = c.id)
              AND NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')
            GROUP BY p.machine_id)
 SELECT m.name, m.dialect, m.folder, COALESCE(pr.n, 0), COALESCE(rv.n, 0), rv.last, COALESCE(q.n, 0)
 FROM machines m LEFT JOIN pr ON pr.mid = m.id LEFT JOIN rv ON rv.mid = m.id LEFT JOIN q ON q.mid = m.id
 ORDER BY m.name COLLATE \"C\", m.id";

/// The workspace's reads and its one write, review marks, on PostgreSQL.
impl Pg {
    fn with_marks(&self, mut rows: Vec<ChangeRow>) -> Result<Vec<ChangeRow>> {
        if rows.is_empty() {
            return Ok(rows);
        }
        let ids: Vec<i64> = rows.iter().map(|r| r.id).collect();
        let marks = self.conn.rows(
            "reading review marks",
            "SELECT change_id, mark, note, marked_by, marked_at FROM review_marks WHERE change_id = ANY($1) ORDER BY id",
            &[&ids],
        )?;
        let mut by_change: BTreeMap<i64, Vec<Mark>> = BTreeMap::new();
        for r in marks {
            by_change.entry(r.get(0)).or_default().push(Mark { mark: r.get(1), note: r.get(2), by: r.get(3), at: r.get(4) });
        }
        for row in &mut rows {
            row.marks = by_change.remove(&row.id).unwrap_or_default();
        }
        Ok(rows)
    }

    pub(in crate::store) fn marks(&self, change_id: i64) -> Result<Vec<Mark>> {
        let rows = self.conn.rows(
            "reading review marks",
            "SELECT mark, note, marked_by, marked_at FROM review_marks WHERE change_id = $1 ORDER BY id",
            &[&change_id],
        )?;
        Ok(rows.iter().map(|r| Mark { mark: r.get(0), note: r.get(1), by: r.get(2), at: r.get(3) }).collect())
    }

    /// As SQLite's: the name or path contains the text (ASCII case ignored, as SQLite's
    /// `LIKE`), dates compared as the stored text is.
    pub(in crate::store) fn search_changes(&self, filter: &ChangeFilter, limit: usize) -> Result<Vec<ChangeRow>> {
        let program_number = filter.program.trim().trim_start_matches(['O', 'o']).parse::<u64>().ok().map(|n| format!("O{n}"));
        let query = format!(
            "{CHANGE_ROWS}
               AND ($1 = '' OR COALESCE(r.name, p.name) ILIKE '%' || $1 || '%' OR p.path ILIKE '%' || $1 || '%' OR COALESCE(r.name, p.name) = $2)
               AND ($3 = '' OR m.name = $3)
               AND ($4 = '' OR c.detected_at >= $4)
               AND ($5 = '' OR c.detected_at < (CASE WHEN $5 ~ '^[0-9]{{4}}-[0-9]{{2}}-[0-9]{{2}}$' THEN to_char($5::date + 1, 'YYYY-MM-DD') END))
               AND (NOT $6::bool OR {UNMARKED})
               AND ($7 = '' OR c.kind = $7)
             ORDER BY c.detected_at DESC, c.id DESC LIMIT $8"
        );
        let rows = self
            .conn
            .client
            .borrow_mut()
            .query(
                query.as_str(),
                &[
                    &filter.program.trim(),
                    &program_number.unwrap_or_default(),
                    &filter.machine.trim(),
                    &filter.since.trim(),
                    &filter.until.trim(),
                    &filter.to_review,
                    &filter.kind.trim(),
                    &(limit as i64),
                ],
            )
            .map_err(sql("searching changes"))?;
        self.with_marks(rows.iter().map(change_row).collect())
    }

    pub(in crate::store) fn change_rows(&self, revision: i64) -> Result<Vec<ChangeRow>> {
        let query = format!("{CHANGE_ROWS} AND c.revision_id = $1 ORDER BY c.id");
        let rows = self.conn.client.borrow_mut().query(query.as_str(), &[&revision]).map_err(sql("reading changes"))?;
        self.with_marks(rows.iter().map(change_row).collect())
    }

    pub(in crate::store) fn machines(&self) -> Result<Vec<MachineSummary>> {
        Ok(self.conn.rows("listing machines", MACHINES, &[])?.iter().map(machine_summary).collect())
    }

    pub(in crate::store) fn machine(&self, name: &str) -> Result<Option<MachineSummary>> {
        Ok(self.machines()?.into_iter().find(|m| m.name == name))
    }

    /// SQLite's `strftime('%Y-W%W')`: the year, and the week from 00, each starting on a
    /// Monday (days before the year's first Monday are week 00), of the UTC time.
    pub(in crate::store) fn changes_per_week(&self, weeks: usize) -> Result<Vec<(String, String, i64)>> {
        let rows = self.conn.rows(
            "counting changes per week",
            "WITH w AS (SELECT to_char(t, 'YYYY') || '-W'
                               || lpad(((extract(doy FROM t)::int - 1 + 7 - ((extract(dow FROM t)::int + 6) % 7)) / 7)::text, 2, '0') AS week,
                               machine
                        FROM (SELECT (c.detected_at::timestamptz AT TIME ZONE 'UTC') AS t, COALESCE(m.name, '') AS machine
                              FROM changes c JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id
                              LEFT JOIN machines m ON m.id = p.machine_id
                              WHERE c.detected_at >= to_char(((SELECT MAX(detected_at) FROM changes)::timestamptz
                                                                   AT TIME ZONE 'UTC')::date - ($1::bigint * 7)::int, 'YYYY-MM-DD')
                                AND NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')) x),
                  last AS (SELECT DISTINCT week COLLATE \"C\" AS week FROM w ORDER BY 1 DESC LIMIT $1)
             SELECT week, machine, COUNT(*) FROM w WHERE week IN (SELECT week FROM last)
             GROUP BY week, machine ORDER BY week COLLATE \"C\", machine COLLATE \"C\"",
            &[&(weeks as i64)],
        )?;
        Ok(rows.iter().map(|r| (r.get(0), r.get(1), r.get(2))).collect())
    }

    pub(in crate::store) fn most_edited(&self, limit: usize) -> Result<Vec<EditedProgram>> {
        let rows = self.conn.rows(
            "listing the most edited programs",
            "SELECT COALESCE(m.name, ''), p.name, p.id, COUNT(DISTINCT c.revision_id), COUNT(*)
             FROM changes c JOIN revisions r ON r.id = c.revision_id JOIN programs p ON p.id = r.program_id LEFT JOIN machines m ON m.id = p.machine_id
             WHERE NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')
             GROUP BY p.id, m.name ORDER BY 4 DESC, 5 DESC, p.name COLLATE \"C\", p.id LIMIT $1",
            &[&(limit as i64)],
        )?;
        Ok(rows
            .iter()
            .map(|r| EditedProgram {
                machine: r.get(0),
                program: r.get(1),
                program_id: r.get(2),
                edited_revisions: r.get(3),
                changes: r.get(4),
            })
            .collect())
    }

    pub(in crate::store) fn kind_counts(&self) -> Result<Vec<(String, i64)>> {
        let rows = self.conn.rows(
            "counting change kinds",
            "SELECT kind, COUNT(*) FROM changes c
             WHERE NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = c.revision_id AND k.mark = 'partial')
             GROUP BY kind ORDER BY 2 DESC, kind COLLATE \"C\"",
            &[],
        )?;
        Ok(rows.iter().map(|r| (r.get(0), r.get(1))).collect())
    }

    pub(in crate::store) fn error_revisions(&self, limit: usize) -> Result<Vec<ErrorRevision>> {
        let rows = self.conn.rows(
            "listing revisions with errors",
            "SELECT r.id, p.path, r.seen_at, (SELECT COUNT(*) FROM diagnostics d WHERE d.revision_id = r.id AND d.severity = 'error') AS n
             FROM revisions r JOIN programs p ON p.id = r.program_id
             WHERE r.id IN (SELECT DISTINCT revision_id FROM diagnostics WHERE severity = 'error')
             ORDER BY r.id DESC LIMIT $1",
            &[&(limit as i64)],
        )?;
        Ok(rows.iter().map(|r| ErrorRevision { id: r.get(0), path: r.get(1), seen_at: r.get(2), errors: r.get(3) }).collect())
    }

    pub(in crate::store) fn last_seen_per_folder(&self) -> Result<Vec<(String, String)>> {
        let rows = self.conn.rows(
            "reading the last event per share",
            "SELECT COALESCE(m.folder, 'cam') COLLATE \"C\", MAX(r.seen_at) FROM revisions r JOIN programs p ON p.id = r.program_id
             LEFT JOIN machines m ON m.id = p.machine_id GROUP BY 1 ORDER BY 1",
            &[],
        )?;
        Ok(rows.iter().map(|r| (r.get(0), r.get(1))).collect())
    }

    pub(in crate::store) fn machine_programs(&self, machine: &str) -> Result<Vec<ProgramRow>> {
        let rows = self.conn.rows(
            "listing a machine's programs",
            "SELECT p.id, p.path, COALESCE(r.name, p.name), r.id, r.seen_at, r.size,
                    (SELECT COUNT(*) FROM revisions x WHERE x.program_id = p.id),
                    (SELECT COUNT(*) FROM changes c WHERE c.revision_id = r.id)
             FROM programs p JOIN machines m ON m.id = p.machine_id
             JOIN revisions r ON r.id = (SELECT MAX(id) FROM revisions WHERE program_id = p.id)
             WHERE m.name = $1 ORDER BY p.path COLLATE \"C\", p.id",
            &[&machine],
        )?;
        Ok(rows
            .iter()
            .map(|r| ProgramRow {
                id: r.get(0),
                path: r.get(1),
                name: r.get(2),
                last_revision: r.get(3),
                last_seen: r.get(4),
                size: r.get(5),
                revisions: r.get(6),
                changes: r.get(7),
            })
            .collect())
    }

    pub(in crate::store) fn program(&self, id: i64) -> Result<Option<ProgramInfo>> {
        let row = self.conn.opt(
            "reading a program",
            "SELECT p.id, p.path, p.name, p.role, m.name, p.dialect FROM programs p LEFT JOIN machines m ON m.id = p.machine_id WHERE p.id = $1",
            &[&id],
        )?;
        Ok(row.map(|r| ProgramInfo { id: r.get(0), path: r.get(1), name: r.get(2), role: r.get(3), machine: r.get(4), dialect: r.get(5) }))
    }

    pub(in crate::store) fn program_of(&self, revision: i64) -> Result<Option<i64>> {
        Ok(self.conn.opt("reading a revision", "SELECT program_id FROM revisions WHERE id = $1", &[&revision])?.map(|r| r.get(0)))
    }

    pub(in crate::store) fn timeline(&self, program: i64) -> Result<Vec<TimelineRow>> {
        let rows = self.conn.rows(
            "reading a program's revisions",
            "SELECT r.id, r.seen_at, r.size, r.hash, r.status,
                    (SELECT COUNT(*) FROM diagnostics d WHERE d.revision_id = r.id),
                    (SELECT COUNT(*) FROM diagnostics d WHERE d.revision_id = r.id AND d.severity = 'error'),
                    c.original_revision_id, (SELECT op.path FROM revisions o JOIN programs op ON op.id = o.program_id WHERE o.id = c.original_revision_id),
                    c.rule, c.changes,
                    EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = r.id AND k.mark = 'partial')
             FROM revisions r LEFT JOIN comparisons c ON c.revision_id = r.id WHERE r.program_id = $1 ORDER BY r.id",
            &[&program],
        )?;
        Ok(rows
            .iter()
            .map(|r| TimelineRow {
                id: r.get(0),
                seen_at: r.get(1),
                size: r.get(2),
                hash: r.get(3),
                status: r.get(4),
                findings: (r.get(5), r.get(6)),
                original: match (r.get::<_, Option<i64>>(7), r.get::<_, Option<String>>(8)) {
                    (Some(id), Some(path)) => Some((id, path, r.get::<_, Option<String>>(9).unwrap_or_default(), r.get(10))),
                    _ => None,
                },
                partial: r.get(11),
            })
            .collect())
    }

    pub(in crate::store) fn originals_of(&self, program: i64) -> Result<Vec<(i64, String, i64)>> {
        let rows = self.conn.rows(
            "reading a program's originals",
            "SELECT op.id, op.path, MAX(o.id) FROM comparisons c JOIN revisions r ON r.id = c.revision_id
             JOIN revisions o ON o.id = c.original_revision_id JOIN programs op ON op.id = o.program_id
             WHERE r.program_id = $1 GROUP BY op.id, op.path ORDER BY op.path COLLATE \"C\", op.id",
            &[&program],
        )?;
        Ok(rows.iter().map(|r| (r.get(0), r.get(1), r.get(2))).collect())
    }

    /// The mark copies the change's kind and values, so that it still says what was
    /// reviewed; the analysis tables are only read.
    pub(in crate::store) fn add_mark(&self, change_id: i64, mark: &str, note: &str, by: &str, at: &str) -> Result<Option<i64>> {
        let row = self.conn.opt(
            "recording a review mark",
            "INSERT INTO review_marks(change_id, revision_id, kind, before, after, mark, note, marked_by, marked_at)
             SELECT id, revision_id, kind, before, after, $2, $3, $4, $5 FROM changes WHERE id = $1 RETURNING revision_id",
            &[&change_id, &mark, &note, &by, &at],
        )?;
        Ok(row.map(|r| r.get(0)))
    }

    pub(in crate::store) fn saved_queries(&self) -> Result<Vec<SavedQuery>> {
        let rows =
            self.conn.rows("reading saved queries", "SELECT id, name, sql, saved_by, saved_at FROM saved_queries ORDER BY id", &[])?;
        Ok(rows.iter().map(|r| SavedQuery { id: r.get(0), name: r.get(1), sql: r.get(2), by: r.get(3), at: r.get(4) }).collect())
    }

    pub(in crate::store) fn save_query(&self, name: &str, sql_text: &str, by: &str, at: &str) -> Result<i64> {
        let row = self.conn.one(
            "saving a query",
            "INSERT INTO saved_queries(name, sql, saved_by, saved_at) VALUES ($1, $2, $3, $4) RETURNING id",
            &[&name, &sql_text, &by, &at],
        )?;
        Ok(row.get(0))
    }

    pub(in crate::store) fn start_session(&self, token_hash: &str, user: &str, created_at: &str, expires_at: &str) -> Result<()> {
        self.conn.exec("forgetting ended sessions", "DELETE FROM web_sessions WHERE expires_at <= $1", &[&created_at])?;
        self.conn.exec(
            "recording a session",
            "INSERT INTO web_sessions(token_hash, user_name, created_at, expires_at) VALUES ($1, $2, $3, $4)",
            &[&token_hash, &user, &created_at, &expires_at],
        )?;
        Ok(())
    }

    pub(in crate::store) fn session_user(&self, token_hash: &str, now: &str) -> Result<Option<String>> {
        let row = self.conn.opt(
            "reading a session",
            "SELECT user_name FROM web_sessions WHERE token_hash = $1 AND expires_at > $2",
            &[&token_hash, &now],
        )?;
        Ok(row.map(|r| r.get(0)))
    }

    pub(in crate::store) fn end_session(&self, token_hash: &str) -> Result<()> {
        self.conn.exec("ending a session", "DELETE FROM web_sessions WHERE token_hash = $1", &[&token_hash])?;
        Ok(())
    }

    /// Why the SQL console must not run through this connection's role, if it must not: a
    /// superuser, or a role that may read or write the server's files or run its programs
    /// (`pg_read_file`, `pg_read_server_files`, `lo_import`, …), reads what no planner should
    /// whatever the transaction's `READ ONLY`.
    pub(in crate::store) fn console_refusal(&self) -> Result<Option<String>> {
        let row = self.conn.one(
            "checking the console's role",
            "SELECT current_user::text, r.rolsuper,
                    pg_has_role(current_user, 'pg_read_server_files', 'MEMBER')
                 OR pg_has_role(current_user, 'pg_write_server_files', 'MEMBER')
                 OR pg_has_role(current_user, 'pg_execute_server_program', 'MEMBER'),
                    has_function_privilege('pg_read_file(text)', 'EXECUTE')
                 OR has_function_privilege('pg_read_binary_file(text)', 'EXECUTE')
                 OR has_function_privilege('pg_ls_dir(text)', 'EXECUTE')
                 OR has_function_privilege('lo_import(text)', 'EXECUTE')
             FROM pg_roles r WHERE r.rolname = current_user",
            &[],
        )?;
        let (role, superuser, files, functions): (String, bool, bool, bool) = (row.get(0), row.get(1), row.get(2), row.get(3));
        let what = if superuser {
            "is a superuser"
        } else if files {
            "may read or write the server's files or run its programs (pg_read_server_files, pg_write_server_files, pg_execute_server_program)"
        } else if functions {
            "may call pg_read_file, pg_read_binary_file, pg_ls_dir or lo_import"
        } else {
            return Ok(None);
        };
        Ok(Some(format!(
            "the SQL console does not run as the database role `{role}`: it {what}; give `serve` a role that is neither \
             (the README's `ncplan_web`)"
        )))
    }

    /// The SQL console on PostgreSQL: one statement in a `READ ONLY` transaction that is
    /// rolled back, `statement_timeout` as the time limit, and at most `max_rows` rows fetched
    /// from a cursor (so that a huge answer is not read whole).
    pub(in crate::store) fn query_limited(
        &self,
        first: &str,
        max_rows: usize,
        limit: std::time::Duration,
    ) -> std::result::Result<Limited, QueryError> {
        let ms = limit.as_millis().max(1);
        let refused = |e: postgres::Error| match e.as_db_error() {
            Some(db) if db.code() == &postgres::error::SqlState::QUERY_CANCELED => {
                QueryError::Refused(format!("the query ran past its time limit of {ms} ms and was stopped"))
            }
            // A `WITH` that writes cannot be a cursor's query: it would write.
            Some(db) if db.code() == &postgres::error::SqlState::FEATURE_NOT_SUPPORTED && db.message().contains("data-modifying") => {
                QueryError::Refused("the query would write; queries only read".into())
            }
            _ => QueryError::Sql(plain(&e)),
        };
        if let Some(why) = self.console_refusal().map_err(|e| QueryError::Sql(e.to_string()))? {
            return Err(QueryError::Refused(why));
        }
        let mut client = self.conn.client.borrow_mut();
        let mut tx = client.transaction().map_err(refused)?;
        tx.batch_execute(&format!("SET TRANSACTION READ ONLY; SET LOCAL statement_timeout = {ms}")).map_err(refused)?;
        let stmt = tx.prepare(first).map_err(refused)?;
        let names: Vec<String> = stmt.columns().iter().map(|c| c.name().to_owned()).collect();
        let types: Vec<postgres::types::Type> = stmt.columns().iter().map(|c| c.type_().clone()).collect();
        let explain = first.trim_start().get(..7).is_some_and(|k| k.eq_ignore_ascii_case("EXPLAIN"));
        let messages = if explain {
            tx.simple_query(first).map_err(refused)?
        } else {
            tx.batch_execute(&format!("DECLARE ncplan_console NO SCROLL CURSOR FOR {first}")).map_err(refused)?;
            tx.simple_query(&format!("FETCH {} FROM ncplan_console", max_rows + 1)).map_err(refused)?
        };
        let mut rows = super::text_cells(&messages, &types);
        for cell in rows.iter_mut().flatten() {
            if cell.len() > 16 << 10 {
                *cell = crate::store::pages::console_text(cell.as_bytes());
            }
        }
        let more = rows.len() > max_rows;
        rows.truncate(max_rows);
        drop(tx);
        Ok((names, rows, more))
    }
}

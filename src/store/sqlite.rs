//! The SQLite backend: one file, WAL, writers serialised by `BEGIN IMMEDIATE`.

use std::path::Path;

use rusqlite::{Connection, OpenFlags, OptionalExtension, Transaction, params};

use super::copy::Val;
use super::schema;
use super::*;
use crate::pairing::{Candidate, Key, Rule};

pub(super) fn sql(about: &'static str) -> impl FnOnce(rusqlite::Error) -> StoreError {
    move |source| StoreError::Sql { about, source: source.into() }
}

/// An open SQLite database.
pub(super) struct Lite {
    pub(super) conn: Connection,
    pub(super) site: String,
}

impl Lite {
    /// Opens (creating if needed) the database in WAL mode and applies migrations.
    pub(super) fn open(path: &Path, site: &str) -> Result<Lite> {
        let conn = Connection::open(path).map_err(sql("opening the database"))?;
        // A huge program's revision is one transaction, so the write-ahead log grows to its size;
        // `journal_size_limit` gives that space back after the checkpoint instead of keeping a
        // log as large as the largest program ever stored beside the database.
        conn.execute_batch(
            "PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL; PRAGMA foreign_keys=ON; PRAGMA busy_timeout=5000; \
             PRAGMA journal_size_limit=4194304;",
        )
        .map_err(sql("setting pragmas"))?;
        let mut s = Lite { conn, site: site.to_owned() };
        s.migrate()?;
        Ok(s)
    }

    /// An in-memory database, for tests.
    pub(super) fn open_in_memory(site: &str) -> Result<Lite> {
        let conn = Connection::open_in_memory().map_err(sql("opening the database"))?;
        conn.execute_batch("PRAGMA foreign_keys=ON;").map_err(sql("setting pragmas"))?;
        let mut s = Lite { conn, site: site.to_owned() };
        s.migrate()?;
        Ok(s)
    }

    /// Opens the database read-only: no statement can change it.
    pub(super) fn open_read_only(path: &Path) -> Result<Lite> {
        let conn = Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX)
            .map_err(sql("opening the database read-only"))?;
        conn.execute_batch("PRAGMA query_only=ON; PRAGMA busy_timeout=5000;").map_err(sql("setting pragmas"))?;
        Ok(Lite { conn, site: String::new() })
    }

    fn migrate(&mut self) -> Result<()> {
        let version: usize = self.conn.query_row("PRAGMA user_version", [], |r| r.get(0)).map_err(sql("reading the schema version"))?;
        if version > MIGRATIONS.len() {
            return Err(StoreError::TooNew { found: version, known: MIGRATIONS.len() });
        }
        for (i, m) in MIGRATIONS.iter().enumerate().skip(version) {
            let tx = self.conn.transaction().map_err(sql("starting a migration"))?;
            tx.execute_batch(m).map_err(sql("applying a migration"))?;
            tx.pragma_update(None, "user_version", i + 1).map_err(sql("recording the schema version"))?;
            tx.commit().map_err(sql("committing a migration"))?;
        }
        Ok(())
    }

    /// How long a statement waits for another connection's transaction before it fails.
    pub(super) fn set_busy_timeout(&mut self, wait: std::time::Duration) -> Result<()> {
        self.conn.busy_timeout(wait).map_err(sql("setting the busy timeout"))
    }

    /// Schema version.
    pub(super) fn version(&self) -> Result<usize> {
        self.conn.query_row("PRAGMA user_version", [], |r| r.get(0)).map_err(sql("reading the schema version"))
    }

    /// The hash of the latest revision of the program at `path`.
    pub(super) fn latest_hash(&self, path: &str) -> Result<Option<String>> {
        self.conn
            .query_row(
                "SELECT r.hash FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.path = ?1 ORDER BY r.id DESC LIMIT 1",
                [path],
                |r| r.get(0),
            )
            .optional()
            .map_err(sql("looking up the latest revision"))
    }

    /// Whether the program at `path` has a revision with the content `hash`, at any time.
    pub(super) fn has_revision(&self, path: &str, hash: &str) -> Result<bool> {
        self.conn
            .query_row(
                "SELECT EXISTS (SELECT 1 FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.path = ?1 AND r.hash = ?2)",
                [path, hash],
                |r| r.get(0),
            )
            .map_err(sql("looking up a revision"))
    }

    /// Notes that the content `hash` is about to be analysed, and returns how many earlier
    /// analyses of it never finished (a kill by the kernel's out-of-memory killer, a memory
    /// limit, a crash). The note is removed when its revision is recorded, or by [`Store::finish_attempt`].
    pub(super) fn begin_attempt(&self, hash: &str, path: &str, at: &str) -> Result<u32> {
        let tries: Option<u32> = self
            .conn
            .query_row("SELECT tries FROM attempts WHERE hash = ?1 AND path = ?2", [hash, path], |r| r.get(0))
            .optional()
            .map_err(sql("reading the attempt journal"))?;
        self.conn
            .execute(
                "INSERT INTO attempts(hash, path, started_at, tries, site) VALUES (?1, ?2, ?3, 1, ?4)
                 ON CONFLICT(hash, path) DO UPDATE SET tries = tries + 1, started_at = excluded.started_at",
                params![hash, path, at, self.site],
            )
            .map_err(sql("writing the attempt journal"))?;
        Ok(tries.unwrap_or(0))
    }

    /// Removes the note of an analysis that ended without recording a revision.
    pub(super) fn finish_attempt(&self, hash: &str, path: &str) -> Result<()> {
        self.conn
            .execute("DELETE FROM attempts WHERE hash = ?1 AND path = ?2", [hash, path])
            .map_err(sql("writing the attempt journal"))?;
        Ok(())
    }

    /// Starts the one transaction in which a revision and everything it enables are recorded.
    pub(super) fn begin(&mut self) -> Result<LiteTxn<'_>> {
        let tx = Transaction::new_unchecked(&self.conn, rusqlite::TransactionBehavior::Immediate).map_err(sql("starting a transaction"))?;
        Ok(LiteTxn { tx, conn: &self.conn, site: &self.site, written: std::cell::Cell::new(0) })
    }

    /// One stored revision, for `ncplan show`.
    pub(super) fn revision(&self, id: i64) -> Result<Option<RevisionInfo>> {
        self.conn
            .query_row(
                "SELECT r.id, p.path, p.role, m.name, COALESCE(r.name, p.name), p.dialect, r.hash, r.size, r.seen_at, r.encoding, r.status,
                        (SELECT superseded_by FROM revision_marks k WHERE k.revision_id = r.id AND k.mark = 'partial'),
                        c.original_revision_id, (SELECT op.path FROM revisions orv JOIN programs op ON op.id = orv.program_id WHERE orv.id = c.original_revision_id),
                        c.rule, c.changes, pl.plan_json IS NOT NULL
                 FROM revisions r JOIN programs p ON p.id = r.program_id LEFT JOIN machines m ON m.id = p.machine_id
                 LEFT JOIN comparisons c ON c.revision_id = r.id LEFT JOIN plans pl ON pl.revision_id = r.id
                 WHERE r.id = ?1",
                [id],
                |r| {
                    Ok(RevisionInfo {
                        id: r.get(0)?,
                        path: r.get(1)?,
                        role: r.get(2)?,
                        machine: r.get(3)?,
                        name: r.get(4)?,
                        dialect: r.get(5)?,
                        hash: r.get(6)?,
                        size: r.get::<_, i64>(7)? as u64,
                        seen_at: r.get(8)?,
                        encoding: r.get(9)?,
                        status: r.get(10)?,
                        partial_of: r.get(11)?,
                        original: match (r.get::<_, Option<i64>>(12)?, r.get::<_, Option<String>>(13)?) {
                            (Some(id), Some(path)) => Some((id, path, r.get::<_, Option<String>>(14)?.unwrap_or_default(), r.get::<_, i64>(15)? as usize)),
                            _ => None,
                        },
                        has_plan: r.get(16)?,
                    })
                },
            )
            .optional()
            .map_err(sql("reading a revision"))
    }

    /// The newest revision of the program at `path` (a whole path, or its end after a `/`)
    /// seen at or before `at` (RFC 3339 or a date; `None`: the newest of all). Several
    /// programs whose paths end so are an error that lists them.
    pub(super) fn revision_of_path(&self, path: &str, at: Option<&str>) -> Result<std::result::Result<Option<i64>, Vec<String>>> {
        let mut stmt = self
            .conn
            .prepare("SELECT id, path FROM programs WHERE path = ?1 OR path LIKE '%/' || ?1 ESCAPE '\\' ORDER BY path")
            .map_err(sql("preparing a query"))?;
        let escaped = path.replace('\\', "\\\\").replace('%', "\\%").replace('_', "\\_");
        let found: Vec<(i64, String)> = stmt
            .query_map([&escaped], |r| Ok((r.get(0)?, r.get(1)?)))
            .map_err(sql("looking up a path"))?
            .collect::<std::result::Result<_, _>>()
            .map_err(sql("looking up a path"))?;
        let exact: Vec<(i64, String)> = found.iter().filter(|(_, p)| p == path).cloned().collect();
        let program = match (exact.as_slice(), found.as_slice()) {
            ([one], _) | ([], [one]) => one.0,
            ([], []) => return Ok(Ok(None)),
            _ => return Ok(Err(found.into_iter().map(|(_, p)| p).collect())),
        };
        // A bare date means the whole day.
        let at = at.map(|a| if a.len() == 10 { format!("{a}T23:59:59.999Z") } else { a.to_owned() });
        let id = self
            .conn
            .query_row(
                "SELECT MAX(id) FROM revisions WHERE program_id = ?1 AND (?2 IS NULL OR julianday(seen_at) <= julianday(?2))",
                params![program, at],
                |r| r.get::<_, Option<i64>>(0),
            )
            .map_err(sql("looking up a revision"))?;
        Ok(Ok(id))
    }

    /// A stored revision's program and plan, to rebuild its whole plan from.
    pub(super) fn source(&self, revision: i64) -> Result<Option<StoredSource>> {
        source_of(&self.conn, revision)
    }

    /// The stored bytes of a revision.
    pub(super) fn content(&self, revision: i64) -> Result<Option<Vec<u8>>> {
        self.conn
            .query_row("SELECT b.content FROM revisions r JOIN blobs b ON b.hash = r.hash WHERE r.id = ?1", [revision], |r| r.get(0))
            .optional()
            .map_err(sql("reading program bytes"))
    }

    /// The findings of a revision, in source order.
    pub(super) fn findings(&self, revision: i64) -> Result<Vec<StoredFinding>> {
        findings_on(&self.conn, revision)
    }

    /// The changes found in a revision against its original.
    pub(super) fn changes(&self, revision: i64) -> Result<Vec<Change>> {
        let mut stmt = self
            .conn
            .prepare(
                "SELECT workingstep, operation, kind, field, before, after, line, original_line,
                        region_min_x, region_min_y, region_min_z, region_max_x, region_max_y, region_max_z, deviation, detail
                 FROM changes WHERE revision_id = ?1 ORDER BY id",
            )
            .map_err(sql("preparing a query"))?;
        let rows = stmt
            .query_map([revision], |r| {
                let kind: String = r.get(2)?;
                let detail: String = r.get(15)?;
                let mut c = Change {
                    kind: serde_json::from_value(serde_json::Value::String(kind)).unwrap_or(crate::diff::ChangeKind::ToolpathChanged),
                    workingstep: r.get(0)?,
                    operation: r.get(1)?,
                    field: r.get(3)?,
                    before: r.get(4)?,
                    after: r.get(5)?,
                    line: r.get(6)?,
                    original_line: r.get(7)?,
                    region: match (r.get::<_, Option<f64>>(8)?, r.get::<_, Option<f64>>(11)?) {
                        (Some(_), Some(_)) => {
                            Some(crate::plan::BBox { min: [r.get(8)?, r.get(9)?, r.get(10)?], max: [r.get(11)?, r.get(12)?, r.get(13)?] })
                        }
                        _ => None,
                    },
                    deviation: r.get(14)?,
                    detail: crate::diff::Detail::default(),
                };
                c.set_detail(&detail);
                Ok(c)
            })
            .map_err(sql("reading changes"))?;
        rows.collect::<std::result::Result<_, _>>().map_err(sql("reading changes"))
    }

    /// Runs one read-only statement (`SELECT`, `WITH`, `VALUES`, `EXPLAIN`) for `ncplan query`,
    /// with refusals in plain words.
    pub(super) fn query_read_only(&self, sql_text: &str) -> std::result::Result<(Vec<String>, Vec<Vec<String>>), QueryError> {
        let (first, rest) = split_statement(sql_text);
        if !rest.is_empty() {
            return Err(QueryError::Refused(format!("one statement at a time: `{}` was not run", rest.trim())));
        }
        let keyword = first.trim_start().split(|c: char| !c.is_ascii_alphabetic()).next().unwrap_or("").to_ascii_uppercase();
        if !matches!(keyword.as_str(), "SELECT" | "WITH" | "VALUES" | "EXPLAIN") {
            let what = if keyword.is_empty() { "an empty statement".to_owned() } else { format!("`{keyword}`") };
            return Err(QueryError::Refused(format!("{what} is refused: queries only read (SELECT, WITH, VALUES, EXPLAIN)")));
        }
        let stmt = self.conn.prepare(first).map_err(|e| QueryError::Sql(plain(&e)))?;
        if !stmt.readonly() {
            return Err(QueryError::Refused("the statement would change the database; queries only read".into()));
        }
        drop(stmt);
        self.query(first).map_err(|e| match e {
            StoreError::Sql { source, .. } => {
                QueryError::Sql(source.downcast_ref::<rusqlite::Error>().map_or_else(|| source.to_string(), plain))
            }
            other => QueryError::Sql(other.to_string()),
        })
    }

    /// Runs a query and returns column names and rows as text.
    pub(super) fn query(&self, sql_text: &str) -> Result<(Vec<String>, Vec<Vec<String>>)> {
        let mut stmt = self.conn.prepare(sql_text).map_err(sql("preparing the query"))?;
        let names: Vec<String> = stmt.column_names().iter().map(|s| (*s).to_owned()).collect();
        let n = names.len();
        let mut rows = stmt.query([]).map_err(sql("running the query"))?;
        let mut out = Vec::new();
        while let Some(row) = rows.next().map_err(sql("reading a row"))? {
            out.push(cells(row, n)?);
        }
        Ok((names, out))
    }
}

/// The first `n` cells of a row as text.
pub(super) fn cells(row: &rusqlite::Row<'_>, n: usize) -> Result<Vec<String>> {
    let mut cells = Vec::with_capacity(n);
    for i in 0..n {
        use rusqlite::types::ValueRef;
        let v = row.get_ref(i).map_err(sql("reading a cell"))?;
        cells.push(match v {
            ValueRef::Null => String::new(),
            ValueRef::Integer(x) => x.to_string(),
            ValueRef::Real(x) => x.to_string(),
            ValueRef::Text(t) => String::from_utf8_lossy(t).into_owned(),
            ValueRef::Blob(b) => format!("<{} bytes>", b.len()),
        });
    }
    Ok(cells)
}

/// A stored revision's program and plan; its bytes only when the plan is not complete.
fn source_of(conn: &Connection, revision: i64) -> Result<Option<StoredSource>> {
    let found = conn
        .query_row(
            "SELECT p.path, p.dialect, r.status, pl.plan_json, pl.complete, r.hash FROM revisions r JOIN programs p ON p.id = r.program_id
             LEFT JOIN plans pl ON pl.revision_id = r.id WHERE r.id = ?1",
            [revision],
            |r| {
                let plan = match r.get::<_, Option<String>>(3)? {
                    Some(json) => Some((json, r.get::<_, Option<bool>>(4)?.unwrap_or(true))),
                    None => None,
                };
                Ok((StoredSource { path: r.get(0)?, dialect: r.get(1)?, status: r.get(2)?, plan, bytes: None }, r.get::<_, String>(5)?))
            },
        )
        .optional()
        .map_err(sql("reading a revision"))?;
    let Some((mut src, hash)) = found else { return Ok(None) };
    if !src.plan.as_ref().is_some_and(|(_, complete)| *complete) {
        src.bytes = conn
            .query_row("SELECT content FROM blobs WHERE hash = ?1", [&hash], |r| r.get(0))
            .optional()
            .map_err(sql("reading program bytes"))?;
    }
    Ok(Some(src))
}

/// SQLite's message, without its internals.
pub(super) fn plain(e: &rusqlite::Error) -> String {
    match e {
        rusqlite::Error::SqliteFailure(_, Some(msg)) => msg.clone(),
        rusqlite::Error::SqliteFailure(f, None) => match f.code {
            rusqlite::ErrorCode::ReadOnly | rusqlite::ErrorCode::SystemIoFailure | rusqlite::ErrorCode::CannotOpen => {
                "the query would write; queries only read".into()
            }
            rusqlite::ErrorCode::OperationInterrupted => "the query ran past its time limit".into(),
            _ => f.to_string(),
        },
        other => other.to_string(),
    }
}

/// One unit of work: a revision, its findings, the partial-write mark of the one before, and
/// every comparison it enables commit together or not at all.
pub(super) struct LiteTxn<'c> {
    tx: Transaction<'c>,
    conn: &'c Connection,
    site: &'c str,
    /// Program bytes written in this transaction.
    written: std::cell::Cell<usize>,
}

/// Above this many program bytes in one transaction, the commit is followed by a truncating
/// checkpoint, so the write-ahead log does not stay as large as the program beside the database.
const BIG_TRANSACTION: usize = 4 << 20;

impl LiteTxn<'_> {
    /// Commits. After a huge program, the write-ahead log is checkpointed and truncated (best
    /// effort: a reader that holds an old snapshot only delays it to the next one).
    pub(super) fn commit(self) -> Result<()> {
        let big = self.written.get() > BIG_TRANSACTION;
        let conn = self.conn;
        self.tx.commit().map_err(sql("committing a revision"))?;
        if big {
            let _ = conn.execute_batch("PRAGMA wal_checkpoint(TRUNCATE);");
        }
        Ok(())
    }

    /// The newest revision of the program at `path`, with its age at `now` (RFC 3339).
    pub(super) fn latest(&self, path: &str, now: &str) -> Result<Option<Latest>> {
        self.tx
            .query_row(
                "SELECT r.id, r.hash, r.size, (julianday(?2) - julianday(r.seen_at)) * 86400.0
                 FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.path = ?1 ORDER BY r.id DESC LIMIT 1",
                params![path, now],
                |r| {
                    Ok(Latest {
                        id: r.get(0)?,
                        hash: r.get(1)?,
                        size: r.get::<_, i64>(2)? as u64,
                        age_s: r.get::<_, Option<f64>>(3)?.unwrap_or(f64::INFINITY),
                    })
                },
            )
            .optional()
            .map_err(sql("looking up the latest revision"))
    }

    /// The stored bytes with `hash`.
    pub(super) fn blob(&self, hash: &str) -> Result<Option<Vec<u8>>> {
        self.tx
            .query_row("SELECT content FROM blobs WHERE hash = ?1", [hash], |r| r.get(0))
            .optional()
            .map_err(sql("reading program bytes"))
    }

    /// Records a revision with its program, keys, bytes, plan and diagnostics.
    pub(super) fn insert_revision(&self, rev: &NewRevision<'_>) -> Result<i64> {
        let tx = &self.tx;
        let machine_id: Option<i64> = match rev.machine {
            Some((name, dialect, folder)) => {
                tx.execute(
                    "INSERT INTO machines(name, dialect, folder, site) VALUES (?1, ?2, ?3, ?4)
                     ON CONFLICT(name) DO UPDATE SET dialect = excluded.dialect, folder = excluded.folder, site = excluded.site",
                    params![name, dialect, folder, self.site],
                )
                .map_err(sql("recording a machine"))?;
                Some(tx.query_row("SELECT id FROM machines WHERE name = ?1", [name], |r| r.get(0)).map_err(sql("recording a machine"))?)
            }
            None => None,
        };
        let first_key = rev.keys.first().map_or(rev.stem, |k| k.value.as_str());
        tx.execute(
            "INSERT INTO programs(path, role, machine_id, name, program_key, stem, dialect, site) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)
             ON CONFLICT(path) DO UPDATE SET role = excluded.role, machine_id = excluded.machine_id, name = excluded.name,
               program_key = excluded.program_key, stem = excluded.stem, dialect = excluded.dialect, site = excluded.site",
            params![rev.path, rev.role, machine_id, rev.name, first_key, rev.stem, rev.dialect, self.site],
        )
        .map_err(sql("recording a program"))?;
        let program_id: i64 =
            tx.query_row("SELECT id FROM programs WHERE path = ?1", [rev.path], |r| r.get(0)).map_err(sql("recording a program"))?;
        tx.execute("DELETE FROM program_keys WHERE program_id = ?1", [program_id]).map_err(sql("recording program keys"))?;
        for k in rev.keys {
            tx.execute(
                "INSERT OR IGNORE INTO program_keys(program_id, rule, key) VALUES (?1, ?2, ?3)",
                params![program_id, k.rule.as_str(), k.value],
            )
            .map_err(sql("recording program keys"))?;
        }
        match rev.content {
            Content::Bytes(bytes) => {
                tx.execute(
                    "INSERT OR IGNORE INTO blobs(hash, size, content) VALUES (?1, ?2, ?3)",
                    params![rev.hash, bytes.len() as i64, bytes],
                )
                .map_err(sql("storing program bytes"))?;
            }
            Content::Absent { size } => write_blob(tx, rev.hash, size, 0, &mut std::io::empty())?,
        }
        let size = rev.content.len() as i64;
        self.written.set(self.written.get() + if let Content::Bytes(b) = rev.content { b.len() } else { 0 });
        tx.execute(
            "INSERT INTO revisions(program_id, hash, size, mtime_ns, seen_at, encoding, status, name) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)",
            params![program_id, rev.hash, size, rev.mtime_ns, rev.seen_at, rev.encoding, rev.status, rev.name],
        )
        .map_err(sql("recording a revision"))?;
        let revision_id = tx.last_insert_rowid();
        tx.execute("DELETE FROM attempts WHERE hash = ?1 AND path = ?2", [rev.hash, rev.path]).map_err(sql("closing an attempt"))?;
        if let Some(plan) = rev.plan_json {
            tx.execute(
                "INSERT INTO plans(revision_id, plan_json, workingsteps, tools, complete) VALUES (?1, ?2, ?3, ?4, ?5)",
                params![revision_id, plan, rev.counts.0 as i64, rev.counts.1 as i64, rev.plan_complete],
            )
            .map_err(sql("storing a plan"))?;
            tx.execute(schema::FILL_WORKINGSTEPS, params![revision_id]).map_err(sql("storing workingsteps"))?;
            tx.execute(schema::FILL_FEATURES, params![revision_id]).map_err(sql("storing features"))?;
        }
        for d in rev.diagnostics {
            self.insert_finding(revision_id, d)?;
        }
        Ok(revision_id)
    }

    /// A stored revision's program and plan, to rebuild its whole plan from.
    pub(super) fn source(&self, revision: i64) -> Result<Option<StoredSource>> {
        source_of(&self.tx, revision)
    }

    pub(super) fn content(&self, revision: i64) -> Result<Option<Vec<u8>>> {
        self.tx
            .query_row("SELECT b.content FROM revisions r JOIN blobs b ON b.hash = r.hash WHERE r.id = ?1", [revision], |r| r.get(0))
            .optional()
            .map_err(sql("reading program bytes"))
    }

    pub(super) fn findings(&self, revision: i64) -> Result<Vec<StoredFinding>> {
        findings_on(&self.tx, revision)
    }

    fn insert_finding(&self, revision_id: i64, d: &DiagnosticJson) -> Result<()> {
        self.tx
            .prepare_cached(
                "INSERT INTO diagnostics(revision_id, code, severity, line, col, byte_start, byte_end, message) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)",
            )
            .and_then(|mut stmt| stmt.execute(params![revision_id, d.code, d.severity.as_str(), d.line, d.col, d.start, d.end, d.message]))
            .map_err(sql("storing diagnostics"))?;
        Ok(())
    }

    /// Adds a finding to a stored revision, unless it has the same one (code and message).
    pub(super) fn add_finding(&self, revision_id: i64, d: &DiagnosticJson) -> Result<bool> {
        let known: bool = self
            .tx
            .query_row(
                "SELECT EXISTS (SELECT 1 FROM diagnostics WHERE revision_id = ?1 AND code = ?2 AND message = ?3)",
                params![revision_id, d.code, d.message],
                |r| r.get(0),
            )
            .map_err(sql("looking up diagnostics"))?;
        if !known {
            self.insert_finding(revision_id, d)?;
        }
        Ok(!known)
    }

    /// Marks `revision` as a partial write of `by` (the revision whose start it is).
    pub(super) fn mark_partial(&self, revision: i64, by: i64, at: &str) -> Result<()> {
        self.tx
            .execute(
                "INSERT OR IGNORE INTO revision_marks(revision_id, mark, superseded_by, noted_at) VALUES (?1, 'partial', ?2, ?3)",
                params![revision, by, at],
            )
            .map_err(sql("marking a partial write"))?;
        Ok(())
    }

    /// The CAM originals that have the key `key`: for each, its newest usable revision.
    pub(super) fn originals(&self, key: &str) -> Result<Vec<Candidate>> {
        let found: Vec<(i64, String, i64)> = {
            let mut stmt = self
                .tx
                .prepare_cached(&format!(
                    "SELECT p.id, p.path, (SELECT MAX(r.id) FROM revisions r WHERE r.program_id = p.id AND {USABLE})
                     FROM programs p
                     WHERE p.role = 'cam' AND p.id IN (SELECT program_id FROM program_keys WHERE key = ?1)
                     ORDER BY p.path"
                ))
                .map_err(sql("preparing a query"))?;
            // A SQLite file is one server's: all its programs are its site's (rows stored
            // before migration 5, or before `site` was configured, have a blank site).
            let rows = stmt
                .query_map([key], |r| Ok((r.get(0)?, r.get(1)?, r.get::<_, Option<i64>>(2)?)))
                .map_err(sql("looking up CAM originals"))?;
            let mut out = Vec::new();
            for row in rows {
                if let (id, path, Some(rev)) = row.map_err(sql("looking up CAM originals"))? {
                    out.push((id, path, rev));
                }
            }
            out
        };
        found.into_iter().map(|(id, path, revision)| Ok(Candidate { revision, path, keys: self.keys_of(id)? })).collect()
    }

    fn keys_of(&self, program_id: i64) -> Result<Vec<Key>> {
        let mut stmt =
            self.tx.prepare_cached("SELECT rule, key FROM program_keys WHERE program_id = ?1").map_err(sql("preparing a query"))?;
        let rows =
            stmt.query_map([program_id], |r| Ok((r.get::<_, String>(0)?, r.get::<_, String>(1)?))).map_err(sql("reading program keys"))?;
        let mut keys = Vec::new();
        for row in rows {
            let (rule, value) = row.map_err(sql("reading program keys"))?;
            if let Some(rule) = Rule::parse(&rule) {
                keys.push(Key { rule, value });
            }
        }
        keys.sort_by_key(|k| k.rule);
        Ok(keys)
    }

    /// Usable machine revisions without a comparison: of the programs with the key `key`, or
    /// of every program.
    pub(super) fn uncompared(&self, key: Option<&str>) -> Result<Vec<Comparable>> {
        let query = format!(
            "SELECT r.id, p.path, p.id FROM revisions r JOIN programs p ON p.id = r.program_id
             WHERE p.role = 'machine' AND {USABLE}
               AND NOT EXISTS (SELECT 1 FROM comparisons c WHERE c.revision_id = r.id)
               AND (?1 IS NULL OR p.id IN (SELECT program_id FROM program_keys WHERE key = ?1))
             ORDER BY r.id"
        );
        self.comparables(&query, &[rusqlite::types::Value::from(key.map(str::to_owned))])
    }

    /// Machine revisions compared with `original`.
    pub(super) fn add_calls(&self, revision: i64, names: &[String]) -> Result<()> {
        let mut stmt = self.tx.prepare_cached("INSERT INTO calls(revision_id, name) VALUES (?1, ?2)").map_err(sql("storing calls"))?;
        for n in names {
            stmt.execute(params![revision, n]).map_err(sql("storing calls"))?;
        }
        Ok(())
    }

    pub(super) fn callers(&self, name: &str) -> Result<Vec<i64>> {
        let mut stmt = self
            .tx
            .prepare_cached(
                "SELECT DISTINCT k.revision_id FROM calls k JOIN comparisons c ON c.revision_id = k.revision_id
                 JOIN revisions r ON r.id = k.revision_id
                 WHERE k.name = ?1 AND r.id = (SELECT MAX(id) FROM revisions WHERE program_id = r.program_id) ORDER BY k.revision_id",
            )
            .map_err(sql("preparing a query"))?;
        let rows = stmt.query_map([name], |r| r.get(0)).map_err(sql("listing callers"))?;
        rows.collect::<std::result::Result<_, _>>().map_err(sql("listing callers"))
    }

    pub(super) fn compared_with(&self, original: i64) -> Result<Vec<Comparable>> {
        let query = "SELECT r.id, p.path, p.id FROM comparisons c JOIN revisions r ON r.id = c.revision_id
                     JOIN programs p ON p.id = r.program_id WHERE c.original_revision_id = ?1 ORDER BY r.id";
        self.comparables(query, &[rusqlite::types::Value::from(original)])
    }

    fn comparables(&self, query: &str, args: &[rusqlite::types::Value]) -> Result<Vec<Comparable>> {
        let found: Vec<(i64, String, i64)> = {
            let mut stmt = self.tx.prepare_cached(query).map_err(sql("preparing a query"))?;
            let rows = stmt
                .query_map(rusqlite::params_from_iter(args), |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?)))
                .map_err(sql("listing revisions to compare"))?;
            rows.collect::<std::result::Result<_, _>>().map_err(sql("listing revisions to compare"))?
        };
        found.into_iter().map(|(revision, path, id)| Ok(Comparable { revision, path, keys: self.keys_of(id)? })).collect()
    }

    /// Records the comparison of `revision` with `original`, paired by `rule`, replacing an
    /// earlier one of the same revision.
    pub(super) fn record_comparison(&self, revision: i64, original: i64, rule: &str, changes: &[Change], at: &str) -> Result<()> {
        let tx = &self.tx;
        let analysis: String = tx
            .query_row("SELECT COALESCE((SELECT analysis FROM plans WHERE revision_id = ?1), '')", [revision], |r| r.get(0))
            .map_err(sql("reading a plan's analysis"))?;
        let old: Vec<super::OldChange> = {
            let mut stmt = tx
                .prepare_cached(
                    "SELECT id, workingstep, kind, field, before, after, detected_at FROM changes WHERE revision_id = ?1 ORDER BY id",
                )
                .map_err(sql("reading changes"))?;
            let rows = stmt
                .query_map([revision], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?, r.get(3)?, r.get(4)?, r.get(5)?, r.get(6)?)))
                .map_err(sql("reading changes"))?;
            rows.collect::<std::result::Result<_, _>>().map_err(sql("reading changes"))?
        };
        let kept = super::continued(&old, changes);
        if !old.is_empty() {
            tx.execute(
                &format!(
                    "INSERT INTO old_changes(change_id, revision_id, original_revision_id, analysis, replaced_by, replaced_at, {cols})
                     SELECT id, revision_id, original_revision_id, analysis, ?2, ?3, {cols} FROM changes WHERE revision_id = ?1 ORDER BY id",
                    cols = super::OLD_CHANGE_COLUMNS
                ),
                params![revision, analysis, at],
            )
            .map_err(sql("keeping the old changes"))?;
        }
        tx.execute("DELETE FROM changes WHERE revision_id = ?1", [revision]).map_err(sql("replacing a comparison"))?;
        // New ids come after every id a change ever had, kept ones included: a mark on a
        // vanished change never names a new one.
        let mut next: i64 = tx
            .query_row(
                "SELECT MAX(COALESCE((SELECT MAX(id) FROM changes), 0), COALESCE((SELECT MAX(change_id) FROM old_changes), 0)) + 1",
                [],
                |r| r.get(0),
            )
            .map_err(sql("numbering changes"))?;
        tx.execute(
            "INSERT OR REPLACE INTO comparisons(revision_id, original_revision_id, compared_at, changes, rule) VALUES (?1, ?2, ?3, ?4, ?5)",
            params![revision, original, at, changes.len() as i64, rule],
        )
        .map_err(sql("recording a comparison"))?;
        let mut stmt = tx
            .prepare_cached(
                "INSERT INTO changes(revision_id, original_revision_id, workingstep, operation, kind, field, before, after, line, detected_at,
                                     original_line, region_min_x, region_min_y, region_min_z, region_max_x, region_max_y, region_max_z, deviation,
                                     id, analysis, detail)
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10, ?11, ?12, ?13, ?14, ?15, ?16, ?17, ?18, ?19, ?20, ?21)",
            )
            .map_err(sql("storing changes"))?;
        for (c, kept) in changes.iter().zip(kept) {
            let (id, detected_at) = match kept {
                Some((id, when)) => (id, when),
                None => {
                    next += 1;
                    (next - 1, at.to_owned())
                }
            };
            let (lo, hi) = match &c.region {
                Some(b) => (b.min.map(Some), b.max.map(Some)),
                None => ([None; 3], [None; 3]),
            };
            stmt.execute(params![
                revision,
                original,
                c.workingstep,
                c.operation,
                c.kind.as_str(),
                c.field,
                c.before,
                c.after,
                c.line,
                detected_at,
                c.original_line,
                lo[0],
                lo[1],
                lo[2],
                hi[0],
                hi[1],
                hi[2],
                c.deviation,
                id,
                analysis,
                c.detail_json()
            ])
            .map_err(sql("storing changes"))?;
        }
        Ok(())
    }
}

/// Findings as the re-analysis keeps and compares them: JSON of (severity, code, line, col,
/// message), and the set of (code, message).
pub(super) fn findings_record(found: &[StoredFinding]) -> (String, std::collections::BTreeSet<(String, String)>) {
    let rows: Vec<(&str, &str, i64, i64, &str)> =
        found.iter().map(|f| (f.severity.as_str(), f.code.as_str(), f.line, f.col, f.message.as_str())).collect();
    (serde_json::to_string(&rows).unwrap_or_default(), found.iter().map(|f| (f.code.clone(), f.message.clone())).collect())
}

/// What a re-analysis changed, from the old and new plan and findings.
pub(super) fn reanalysed(old_plan: Option<&str>, old: &std::collections::BTreeSet<(String, String)>, a: &NewAnalysis<'_>) -> Reanalysed {
    let new: std::collections::BTreeSet<(String, String)> = a.diagnostics.iter().map(|d| (d.code.to_owned(), d.message.clone())).collect();
    Reanalysed {
        plan_changed: old_plan != Some(a.plan_json),
        new_findings: new.difference(old).count(),
        vanished_findings: old.difference(&new).count(),
    }
}

impl Lite {
    pub(super) fn queue_reanalysis(&self, version: &str, since: Option<&str>, dialect: Option<&str>) -> Result<usize> {
        self.conn
            .execute(
                "INSERT OR IGNORE INTO reanalysis_queue(revision_id, version)
                 SELECT r.id, ?1 FROM revisions r JOIN programs p ON p.id = r.program_id
                 WHERE r.status = 'analysed' AND (?2 IS NULL OR julianday(r.seen_at) >= julianday(?2)) AND (?3 IS NULL OR p.dialect = ?3)
                   AND NOT EXISTS (SELECT 1 FROM analyses a WHERE a.revision_id = r.id AND a.version = ?1)
                 ORDER BY r.id",
                params![version, since, dialect],
            )
            .map_err(sql("queueing revisions"))?;
        self.reanalysis_left(version)
    }

    pub(super) fn claim_reanalysis(&self, version: &str, worker: &str, n: usize, now: &str, lease_until: &str) -> Result<Vec<i64>> {
        let mut stmt = self
            .conn
            .prepare_cached(
                "UPDATE reanalysis_queue SET worker = ?1, lease_until = ?2
                 WHERE rowid IN (SELECT rowid FROM reanalysis_queue WHERE version = ?3 AND (lease_until IS NULL OR lease_until < ?4)
                                 ORDER BY revision_id LIMIT ?5)
                 RETURNING revision_id",
            )
            .map_err(sql("preparing a query"))?;
        let rows = stmt.query_map(params![worker, lease_until, version, now, n as i64], |r| r.get(0)).map_err(sql("claiming revisions"))?;
        let mut ids: Vec<i64> = rows.collect::<std::result::Result<_, _>>().map_err(sql("claiming revisions"))?;
        ids.sort_unstable();
        Ok(ids)
    }

    pub(super) fn reanalysis_left(&self, version: &str) -> Result<usize> {
        self.conn
            .query_row("SELECT COUNT(*) FROM reanalysis_queue WHERE version = ?1", [version], |r| r.get::<_, i64>(0))
            .map(|n| n as usize)
            .map_err(sql("counting the queue"))
    }
}

impl LiteTxn<'_> {
    pub(super) fn comparison_of(&self, revision: i64) -> Result<Option<(i64, String)>> {
        self.tx
            .query_row("SELECT original_revision_id, COALESCE(rule, '') FROM comparisons WHERE revision_id = ?1", [revision], |r| {
                Ok((r.get(0)?, r.get(1)?))
            })
            .optional()
            .map_err(sql("reading a comparison"))
    }

    pub(super) fn record_analysis(&self, a: &NewAnalysis<'_>) -> Result<Option<Reanalysed>> {
        let tx = &self.tx;
        let old: Option<(String, String)> = tx
            .query_row("SELECT plan_json, analysis FROM plans WHERE revision_id = ?1", [a.revision], |r| Ok((r.get(0)?, r.get(1)?)))
            .optional()
            .map_err(sql("reading a plan"))?;
        let found = {
            let mut stmt = tx
                .prepare_cached("SELECT severity, code, line, col, message FROM diagnostics WHERE revision_id = ?1 ORDER BY byte_start, id")
                .map_err(sql("preparing a query"))?;
            let rows = stmt
                .query_map([a.revision], |r| {
                    Ok(StoredFinding { severity: r.get(0)?, code: r.get(1)?, line: r.get(2)?, col: r.get(3)?, message: r.get(4)? })
                })
                .map_err(sql("reading findings"))?;
            rows.collect::<std::result::Result<Vec<_>, _>>().map_err(sql("reading findings"))?
        };
        let (old_json, old_set) = findings_record(&found);
        let outcome = reanalysed(old.as_ref().map(|o| o.0.as_str()), &old_set, a);
        let inserted = tx
            .execute(
                "INSERT OR IGNORE INTO analyses(revision_id, version, analysed_at, worker, previous, previous_plan, previous_findings,
                                               plan_changed, new_findings, vanished_findings)
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
                params![
                    a.revision,
                    a.version,
                    a.at,
                    a.worker,
                    old.as_ref().map_or("", |o| o.1.as_str()),
                    old.as_ref().map(|o| o.0.as_str()),
                    old_json,
                    outcome.plan_changed,
                    outcome.new_findings as i64,
                    outcome.vanished_findings as i64
                ],
            )
            .map_err(sql("recording an analysis"))?;
        if inserted == 0 {
            return Ok(None);
        }
        for table in ["workingsteps", "features", "plans", "diagnostics"] {
            tx.execute(&format!("DELETE FROM {table} WHERE revision_id = ?1"), [a.revision]).map_err(sql("replacing an analysis"))?;
        }
        tx.execute(
            "INSERT INTO plans(revision_id, plan_json, workingsteps, tools, complete, analysis) VALUES (?1, ?2, ?3, ?4, 0, ?5)",
            params![a.revision, a.plan_json, a.counts.0 as i64, a.counts.1 as i64, a.version],
        )
        .map_err(sql("storing a plan"))?;
        tx.execute(schema::FILL_WORKINGSTEPS, params![a.revision]).map_err(sql("storing workingsteps"))?;
        tx.execute(schema::FILL_FEATURES, params![a.revision]).map_err(sql("storing features"))?;
        for d in a.diagnostics {
            self.insert_finding(a.revision, d)?;
        }
        tx.execute("DELETE FROM reanalysis_queue WHERE revision_id = ?1 AND version = ?2", params![a.revision, a.version])
            .map_err(sql("closing a queue entry"))?;
        Ok(Some(outcome))
    }
}

/// Stores `kept` bytes read from `from` as the blob `hash` of a file of `size` bytes, unless
/// the blob is there: in chunks (bounded memory), checking that bytes kept whole still hash
/// to `hash` ([`StoreError::ContentChanged`] if not).
fn write_blob(conn: &Connection, hash: &str, size: u64, kept: u64, from: &mut dyn std::io::Read) -> Result<()> {
    use sha2::Digest as _;
    use std::io::Write as _;
    let inserted = conn
        .execute("INSERT OR IGNORE INTO blobs(hash, size, content) VALUES (?1, ?2, zeroblob(?3))", params![hash, size as i64, kept as i64])
        .map_err(sql("storing program bytes"))?;
    if inserted == 0 || kept == 0 {
        return Ok(());
    }
    let rowid: i64 =
        conn.query_row("SELECT rowid FROM blobs WHERE hash = ?1", [hash], |r| r.get(0)).map_err(sql("storing program bytes"))?;
    let mut blob = conn.blob_open(rusqlite::DatabaseName::Main, "blobs", "content", rowid, false).map_err(sql("storing program bytes"))?;
    let mut hasher = sha2::Sha256::new();
    let mut buf = vec![0u8; 1 << 20];
    let mut copied = 0u64;
    loop {
        let n = from.read(&mut buf).map_err(|e| StoreError::Io { about: "reading a program to store", source: e })?;
        if n == 0 {
            break;
        }
        if copied + n as u64 > kept {
            return Err(StoreError::ContentChanged);
        }
        hasher.update(&buf[..n]);
        blob.write_all(&buf[..n]).map_err(|e| StoreError::Io { about: "storing program bytes", source: e })?;
        copied += n as u64;
    }
    if copied != kept || (kept == size && format!("{:x}", hasher.finalize()) != hash) {
        return Err(StoreError::ContentChanged);
    }
    Ok(())
}

/// A SQLite database as an end of `ncplan migrate` ([`super::copy`]).
pub(super) struct LiteEnd<'a>(pub(super) &'a Connection);

impl super::copy::End for LiteEnd<'_> {
    fn by_site(&self) -> bool {
        false
    }

    fn rows(&self, sql_text: &str, params: &[Val]) -> Result<Vec<Vec<Val>>> {
        let mut stmt = self.0.prepare_cached(sql_text).map_err(sql("reading rows to copy"))?;
        let n = stmt.column_count();
        let mut rows = stmt.query(rusqlite::params_from_iter(params.iter().map(lite_value))).map_err(sql("reading rows to copy"))?;
        let mut out = Vec::new();
        while let Some(row) = rows.next().map_err(sql("reading rows to copy"))? {
            let mut cells = Vec::with_capacity(n);
            for i in 0..n {
                use rusqlite::types::ValueRef;
                cells.push(match row.get_ref(i).map_err(sql("reading rows to copy"))? {
                    ValueRef::Null => Val::Null,
                    ValueRef::Integer(x) => Val::Int(x),
                    ValueRef::Real(x) => Val::Real(x),
                    ValueRef::Text(t) => Val::Text(String::from_utf8_lossy(t).into_owned()),
                    ValueRef::Blob(b) => Val::Bytes(b.to_vec()),
                });
            }
            out.push(cells);
        }
        Ok(out)
    }

    fn exec(&self, sql_text: &str, params: &[Val]) -> Result<u64> {
        let mut stmt = self.0.prepare_cached(sql_text).map_err(sql("copying rows"))?;
        Ok(stmt.execute(rusqlite::params_from_iter(params.iter().map(lite_value))).map_err(sql("copying rows"))? as u64)
    }

    fn batch(&self, sql_text: &str) -> Result<()> {
        // One writer at a time: the transaction takes the write lock at its start.
        let sql_text = if sql_text == "BEGIN" { "BEGIN IMMEDIATE" } else { sql_text };
        self.0.execute_batch(sql_text).map_err(sql("copying rows"))
    }

    fn columns_sql(&self) -> &'static str {
        "SELECT name FROM pragma_table_info(?1) ORDER BY cid"
    }

    fn same(&self, column: &str, n: usize) -> String {
        format!("{column} IS ?{n}")
    }

    fn blob(&self, hash: &str) -> Result<Option<super::copy::Blob<'_>>> {
        let found: Option<(i64, i64, i64)> = self
            .0
            .query_row("SELECT rowid, size, length(content) FROM blobs WHERE hash = ?1", [hash], |x| Ok((x.get(0)?, x.get(1)?, x.get(2)?)))
            .optional()
            .map_err(sql("reading program bytes"))?;
        let Some((rowid, size, stored)) = found else { return Ok(None) };
        if stored == 0 {
            return Ok(Some((size, 0, Box::new(std::io::empty()))));
        }
        let blob = self.0.blob_open(rusqlite::DatabaseName::Main, "blobs", "content", rowid, true).map_err(sql("reading program bytes"))?;
        Ok(Some((size, stored, Box::new(blob))))
    }

    fn write_blob(&self, hash: &str, size: i64, stored: i64, from: &mut dyn std::io::Read) -> Result<()> {
        write_blob(self.0, hash, size as u64, stored as u64, from)
    }

    fn reserve_ids(&self, _table: &str, _at_least: i64) -> Result<()> {
        // SQLite numbers a row it is given no id for after the greatest there.
        Ok(())
    }

    fn new_id(&self, table: &str, above: i64) -> Result<i64> {
        let max = |sql_text: &str| -> Result<i64> {
            Ok(self
                .rows(sql_text, &[])?
                .first()
                .and_then(|r| match r[0] {
                    Val::Int(i) => Some(i),
                    _ => None,
                })
                .unwrap_or(0))
        };
        let mut m = max(&format!("SELECT MAX(id) FROM {table}"))?;
        if table == "changes" {
            // A change's id is never one an old change had.
            m = m.max(max("SELECT MAX(change_id) FROM old_changes")?);
        }
        Ok(m.max(above) + 1)
    }
}

/// A cell as SQLite takes it.
fn lite_value(v: &Val) -> rusqlite::types::Value {
    use rusqlite::types::Value;
    match v {
        Val::Null => Value::Null,
        Val::Int(i) => Value::Integer(*i),
        Val::Real(x) => Value::Real(*x),
        Val::Text(t) => Value::Text(t.clone()),
        Val::Bytes(b) => Value::Blob(b.clone()),
    }
}

/// The findings of a revision, in source order.
fn findings_on(conn: &rusqlite::Connection, revision: i64) -> Result<Vec<StoredFinding>> {
    let mut stmt = conn
        .prepare("SELECT severity, code, line, col, message FROM diagnostics WHERE revision_id = ?1 ORDER BY byte_start, id")
        .map_err(sql("preparing a query"))?;
    let rows = stmt
        .query_map([revision], |r| {
            Ok(StoredFinding { severity: r.get(0)?, code: r.get(1)?, line: r.get(2)?, col: r.get(3)?, message: r.get(4)? })
        })
        .map_err(sql("reading findings"))?;
    rows.collect::<std::result::Result<_, _>>().map_err(sql("reading findings"))
}

#[cfg(test)]
mod tests {
    use crate::store::Store;

    #[test]
    fn migrations_apply_and_protect_revisions() {
        let s = Store::open_in_memory().unwrap();
        assert_eq!(s.version().unwrap(), super::schema::MIGRATIONS.len());
        let s = super::Lite::open_in_memory("").unwrap();
        let (cols, _) = s.query("SELECT * FROM shopfloor_changes").unwrap();
        let want = "machine program original_path edited_path revision_id workingstep kind field before after detected_at operation change_id \
                    line original_line region_min_x region_min_y region_min_z region_max_x region_max_y region_max_z deviation site";
        assert_eq!(cols.join(" "), want);
        s.conn.execute_batch("INSERT INTO blobs VALUES ('h', 1, x'00')").unwrap();
        assert!(s.conn.execute_batch("UPDATE blobs SET size = 2").is_err());
        assert!(s.conn.execute_batch("DELETE FROM blobs").is_err());
    }
}

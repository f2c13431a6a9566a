//! The SQLite store: the only module that knows SQL.
//!
//! Revisions are content-addressed and never overwritten (triggers forbid it). Each
//! revision is recorded with its plan, diagnostics and changes in one transaction, so a
//! crash leaves either all of it or none of it, and the next scan picks the file up again.

mod schema;

use std::path::Path;

use rusqlite::{Connection, OpenFlags, OptionalExtension, Transaction, params};

use crate::pairing::{Candidate, Key, Rule};
pub use schema::MIGRATIONS;

use crate::diag::DiagnosticJson;
use crate::diff::Change;

/// Operational store errors.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum StoreError {
    /// SQLite failed.
    #[error("database error while {about}")]
    Sql {
        /// What was being done.
        about: &'static str,
        /// The SQLite error.
        #[source]
        source: rusqlite::Error,
    },
    /// The database was written by a newer ncplan.
    #[error("the database schema version {found} is newer than this ncplan knows ({known})")]
    TooNew {
        /// Version found.
        found: usize,
        /// Latest version known.
        known: usize,
    },
}

type Result<T> = std::result::Result<T, StoreError>;

fn sql(about: &'static str) -> impl FnOnce(rusqlite::Error) -> StoreError {
    move |source| StoreError::Sql { about, source }
}

/// An open database.
pub struct Store {
    conn: Connection,
}

/// A revision to record.
#[derive(Debug)]
pub struct NewRevision<'a> {
    /// Absolute path of the program file.
    pub path: &'a str,
    /// `cam` or `machine`.
    pub role: &'a str,
    /// Machine name, dialect and folder, for machine folders.
    pub machine: Option<(&'a str, &'a str, &'a str)>,
    /// Program name shown in reports (the name this revision states).
    pub name: &'a str,
    /// The keys the program is paired by, most specific first (at least one).
    pub keys: &'a [Key],
    /// Upper-case file stem.
    pub stem: &'a str,
    /// Dialect name.
    pub dialect: &'a str,
    /// Raw bytes.
    pub bytes: &'a [u8],
    /// SHA-256 of the bytes, hex.
    pub hash: &'a str,
    /// File modification time, ns since the epoch.
    pub mtime_ns: Option<i64>,
    /// When ncplan saw it (RFC 3339, from the injected clock).
    pub seen_at: &'a str,
    /// Text encoding.
    pub encoding: &'a str,
    /// `analysed`, `too_large` or `empty`.
    pub status: &'a str,
    /// Plan JSON, when analysed.
    pub plan_json: Option<&'a str>,
    /// Number of workingsteps and tools.
    pub counts: (usize, usize),
    /// Diagnostics.
    pub diagnostics: &'a [DiagnosticJson],
}

/// The newest revision of a path.
#[derive(Debug, Clone)]
pub struct Latest {
    /// Revision id.
    pub id: i64,
    /// Content hash.
    pub hash: String,
    /// Size in bytes.
    pub size: u64,
    /// Seconds between its `seen_at` and the time asked about.
    pub age_s: f64,
}

/// A machine revision that may be compared: its id, path and the keys of its program.
#[derive(Debug, Clone)]
pub struct Comparable {
    /// Revision id.
    pub revision: i64,
    /// Program path.
    pub path: String,
    /// The program's keys.
    pub keys: Vec<Key>,
}

impl Store {
    /// Opens (creating if needed) the database in WAL mode and applies migrations.
    pub fn open(path: &Path) -> Result<Store> {
        let conn = Connection::open(path).map_err(sql("opening the database"))?;
        conn.execute_batch("PRAGMA journal_mode=WAL; PRAGMA synchronous=NORMAL; PRAGMA foreign_keys=ON; PRAGMA busy_timeout=5000;")
            .map_err(sql("setting pragmas"))?;
        let mut s = Store { conn };
        s.migrate()?;
        Ok(s)
    }

    /// An in-memory database, for tests.
    pub fn open_in_memory() -> Result<Store> {
        let conn = Connection::open_in_memory().map_err(sql("opening the database"))?;
        conn.execute_batch("PRAGMA foreign_keys=ON;").map_err(sql("setting pragmas"))?;
        let mut s = Store { conn };
        s.migrate()?;
        Ok(s)
    }

    /// Opens the database read-only: no statement can change it.
    pub fn open_read_only(path: &Path) -> Result<Store> {
        let conn = Connection::open_with_flags(path, OpenFlags::SQLITE_OPEN_READ_ONLY | OpenFlags::SQLITE_OPEN_NO_MUTEX)
            .map_err(sql("opening the database read-only"))?;
        conn.execute_batch("PRAGMA query_only=ON; PRAGMA busy_timeout=5000;").map_err(sql("setting pragmas"))?;
        Ok(Store { conn })
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

    /// Schema version.
    pub fn version(&self) -> Result<usize> {
        self.conn.query_row("PRAGMA user_version", [], |r| r.get(0)).map_err(sql("reading the schema version"))
    }

    /// The hash of the latest revision of the program at `path`.
    pub fn latest_hash(&self, path: &str) -> Result<Option<String>> {
        self.conn
            .query_row(
                "SELECT r.hash FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.path = ?1 ORDER BY r.id DESC LIMIT 1",
                [path],
                |r| r.get(0),
            )
            .optional()
            .map_err(sql("looking up the latest revision"))
    }

    /// Starts the one transaction in which a revision and everything it enables are recorded.
    pub fn begin(&mut self) -> Result<Txn<'_>> {
        let tx = self.conn.transaction_with_behavior(rusqlite::TransactionBehavior::Immediate).map_err(sql("starting a transaction"))?;
        Ok(Txn { tx })
    }

    /// Runs a query and returns column names and rows as text.
    pub fn query(&self, sql_text: &str) -> Result<(Vec<String>, Vec<Vec<String>>)> {
        let mut stmt = self.conn.prepare(sql_text).map_err(sql("preparing the query"))?;
        let names: Vec<String> = stmt.column_names().iter().map(|s| (*s).to_owned()).collect();
        let n = names.len();
        let mut rows = stmt.query([]).map_err(sql("running the query"))?;
        let mut out = Vec::new();
        while let Some(row) = rows.next().map_err(sql("reading a row"))? {
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
            out.push(cells);
        }
        Ok((names, out))
    }
}

/// One unit of work: a revision, its findings, the partial-write mark of the one before, and
/// every comparison it enables commit together or not at all.
pub struct Txn<'c> {
    tx: Transaction<'c>,
}

/// `(revision_id)` of revisions that may serve as originals or be compared: analysed, with a
/// plan, and not a partial write.
const USABLE: &str = "r.status = 'analysed' AND EXISTS (SELECT 1 FROM plans pl WHERE pl.revision_id = r.id)
     AND NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = r.id AND k.mark = 'partial')";

impl Txn<'_> {
    /// Commits.
    pub fn commit(self) -> Result<()> {
        self.tx.commit().map_err(sql("committing a revision"))
    }

    /// The newest revision of the program at `path`, with its age at `now` (RFC 3339).
    pub fn latest(&self, path: &str, now: &str) -> Result<Option<Latest>> {
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
    pub fn blob(&self, hash: &str) -> Result<Option<Vec<u8>>> {
        self.tx
            .query_row("SELECT content FROM blobs WHERE hash = ?1", [hash], |r| r.get(0))
            .optional()
            .map_err(sql("reading program bytes"))
    }

    /// Records a revision with its program, keys, bytes, plan and diagnostics.
    pub fn insert_revision(&self, rev: &NewRevision<'_>) -> Result<i64> {
        let tx = &self.tx;
        let machine_id: Option<i64> = match rev.machine {
            Some((name, dialect, folder)) => {
                tx.execute(
                    "INSERT INTO machines(name, dialect, folder) VALUES (?1, ?2, ?3)
                     ON CONFLICT(name) DO UPDATE SET dialect = excluded.dialect, folder = excluded.folder",
                    params![name, dialect, folder],
                )
                .map_err(sql("recording a machine"))?;
                Some(tx.query_row("SELECT id FROM machines WHERE name = ?1", [name], |r| r.get(0)).map_err(sql("recording a machine"))?)
            }
            None => None,
        };
        let first_key = rev.keys.first().map_or(rev.stem, |k| k.value.as_str());
        tx.execute(
            "INSERT INTO programs(path, role, machine_id, name, program_key, stem, dialect) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)
             ON CONFLICT(path) DO UPDATE SET role = excluded.role, machine_id = excluded.machine_id, name = excluded.name,
               program_key = excluded.program_key, stem = excluded.stem, dialect = excluded.dialect",
            params![rev.path, rev.role, machine_id, rev.name, first_key, rev.stem, rev.dialect],
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
        tx.execute(
            "INSERT OR IGNORE INTO blobs(hash, size, content) VALUES (?1, ?2, ?3)",
            params![rev.hash, rev.bytes.len() as i64, rev.bytes],
        )
        .map_err(sql("storing program bytes"))?;
        tx.execute(
            "INSERT INTO revisions(program_id, hash, size, mtime_ns, seen_at, encoding, status, name) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)",
            params![program_id, rev.hash, rev.bytes.len() as i64, rev.mtime_ns, rev.seen_at, rev.encoding, rev.status, rev.name],
        )
        .map_err(sql("recording a revision"))?;
        let revision_id = tx.last_insert_rowid();
        if let Some(plan) = rev.plan_json {
            tx.execute(
                "INSERT INTO plans(revision_id, plan_json, workingsteps, tools) VALUES (?1, ?2, ?3, ?4)",
                params![revision_id, plan, rev.counts.0 as i64, rev.counts.1 as i64],
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
    pub fn add_finding(&self, revision_id: i64, d: &DiagnosticJson) -> Result<bool> {
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
    pub fn mark_partial(&self, revision: i64, by: i64, at: &str) -> Result<()> {
        self.tx
            .execute(
                "INSERT OR IGNORE INTO revision_marks(revision_id, mark, superseded_by, noted_at) VALUES (?1, 'partial', ?2, ?3)",
                params![revision, by, at],
            )
            .map_err(sql("marking a partial write"))?;
        Ok(())
    }

    /// The CAM originals that have the key `key`: for each, its newest usable revision.
    pub fn originals(&self, key: &str) -> Result<Vec<Candidate>> {
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

    /// The plan JSON of a revision.
    pub fn plan_json(&self, revision: i64) -> Result<Option<String>> {
        self.tx
            .query_row("SELECT plan_json FROM plans WHERE revision_id = ?1", [revision], |r| r.get(0))
            .optional()
            .map_err(sql("reading a plan"))
    }

    /// Usable machine revisions without a comparison: of the programs with the key `key`, or
    /// of every program.
    pub fn uncompared(&self, key: Option<&str>) -> Result<Vec<Comparable>> {
        let query = format!(
            "SELECT r.id, p.path, p.id FROM revisions r JOIN programs p ON p.id = r.program_id
             WHERE p.role = 'machine' AND {USABLE}
               AND NOT EXISTS (SELECT 1 FROM comparisons c WHERE c.revision_id = r.id)
               AND (?1 IS NULL OR p.id IN (SELECT program_id FROM program_keys WHERE key = ?1))
             ORDER BY r.id"
        );
        self.comparables(&query, rusqlite::types::Value::from(key.map(str::to_owned)))
    }

    /// Machine revisions compared with `original`.
    pub fn compared_with(&self, original: i64) -> Result<Vec<Comparable>> {
        let query = "SELECT r.id, p.path, p.id FROM comparisons c JOIN revisions r ON r.id = c.revision_id
                     JOIN programs p ON p.id = r.program_id WHERE c.original_revision_id = ?1 ORDER BY r.id";
        self.comparables(query, rusqlite::types::Value::from(original))
    }

    fn comparables(&self, query: &str, arg: rusqlite::types::Value) -> Result<Vec<Comparable>> {
        let found: Vec<(i64, String, i64)> = {
            let mut stmt = self.tx.prepare_cached(query).map_err(sql("preparing a query"))?;
            let rows = stmt.query_map([arg], |r| Ok((r.get(0)?, r.get(1)?, r.get(2)?))).map_err(sql("listing revisions to compare"))?;
            rows.collect::<std::result::Result<_, _>>().map_err(sql("listing revisions to compare"))?
        };
        found.into_iter().map(|(revision, path, id)| Ok(Comparable { revision, path, keys: self.keys_of(id)? })).collect()
    }

    /// Records the comparison of `revision` with `original`, paired by `rule`, replacing an
    /// earlier one of the same revision.
    pub fn record_comparison(&self, revision: i64, original: i64, rule: &str, changes: &[Change], at: &str) -> Result<()> {
        let tx = &self.tx;
        tx.execute("DELETE FROM changes WHERE revision_id = ?1", [revision]).map_err(sql("replacing a comparison"))?;
        tx.execute(
            "INSERT OR REPLACE INTO comparisons(revision_id, original_revision_id, compared_at, changes, rule) VALUES (?1, ?2, ?3, ?4, ?5)",
            params![revision, original, at, changes.len() as i64, rule],
        )
        .map_err(sql("recording a comparison"))?;
        let mut stmt = tx
            .prepare_cached(
                "INSERT INTO changes(revision_id, original_revision_id, workingstep, operation, kind, field, before, after, line, detected_at)
                 VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
            )
            .map_err(sql("storing changes"))?;
        for c in changes {
            stmt.execute(params![revision, original, c.workingstep, c.operation, c.kind.as_str(), c.field, c.before, c.after, c.line, at])
                .map_err(sql("storing changes"))?;
        }
        Ok(())
    }
}

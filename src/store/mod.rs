//! The SQLite store: the only module that knows SQL.
//!
//! Revisions are content-addressed and never overwritten (triggers forbid it). Each
//! revision is recorded with its plan, diagnostics and changes in one transaction, so a
//! crash leaves either all of it or none of it, and the next scan picks the file up again.

mod schema;

use std::path::Path;

use rusqlite::{Connection, OpenFlags, OptionalExtension, Transaction, params};
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
    /// Machine name, for machine folders.
    pub machine: Option<(&'a str, &'a str, &'a str)>,
    /// Program name shown in reports.
    pub name: &'a str,
    /// Matching key (pattern key, else program number, else upper-case stem).
    pub key: &'a str,
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
    /// `analysed` or `too_large`.
    pub status: &'a str,
    /// Plan JSON, when analysed.
    pub plan_json: Option<&'a str>,
    /// Number of workingsteps and tools.
    pub counts: (usize, usize),
    /// Diagnostics.
    pub diagnostics: &'a [DiagnosticJson],
    /// The comparison with the CAM original, when one was found.
    pub comparison: Option<(i64, &'a [Change])>,
}

/// A stored revision that a diff can use.
#[derive(Debug, Clone)]
pub struct StoredPlan {
    /// Revision id.
    pub revision_id: i64,
    /// Program path.
    pub path: String,
    /// Plan JSON.
    pub plan_json: String,
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

    /// The latest analysed CAM revision whose key is one of `keys` (first key wins).
    pub fn find_original(&self, keys: &[String]) -> Result<Option<StoredPlan>> {
        for key in keys {
            let found = self
                .conn
                .query_row(
                    "SELECT r.id, p.path, pl.plan_json FROM revisions r JOIN programs p ON p.id = r.program_id
                     JOIN plans pl ON pl.revision_id = r.id
                     WHERE p.role = 'cam' AND (p.program_key = ?1 OR p.stem = ?1)
                       AND r.id = (SELECT MAX(id) FROM revisions WHERE program_id = p.id)
                     ORDER BY r.id DESC LIMIT 1",
                    [key],
                    |r| Ok(StoredPlan { revision_id: r.get(0)?, path: r.get(1)?, plan_json: r.get(2)? }),
                )
                .optional()
                .map_err(sql("looking up a CAM original"))?;
            if found.is_some() {
                return Ok(found);
            }
        }
        Ok(None)
    }

    /// Latest machine revisions with `key` that have not been compared with an original yet.
    pub fn uncompared_machine_revisions(&self, key: &str) -> Result<Vec<StoredPlan>> {
        let mut stmt = self
            .conn
            .prepare(
                "SELECT r.id, p.path, pl.plan_json FROM revisions r JOIN programs p ON p.id = r.program_id
                 JOIN plans pl ON pl.revision_id = r.id
                 WHERE p.role = 'machine' AND (p.program_key = ?1 OR p.stem = ?1)
                   AND r.id = (SELECT MAX(id) FROM revisions WHERE program_id = p.id)
                   AND NOT EXISTS (SELECT 1 FROM comparisons c WHERE c.revision_id = r.id)
                 ORDER BY r.id",
            )
            .map_err(sql("preparing a query"))?;
        let rows = stmt
            .query_map([key], |r| Ok(StoredPlan { revision_id: r.get(0)?, path: r.get(1)?, plan_json: r.get(2)? }))
            .map_err(sql("listing uncompared revisions"))?;
        rows.collect::<std::result::Result<_, _>>().map_err(sql("listing uncompared revisions"))
    }

    /// Records a revision with its plan, diagnostics and changes in one transaction.
    /// Returns `None` when the latest stored revision already has this content.
    pub fn record(&mut self, rev: &NewRevision<'_>) -> Result<Option<i64>> {
        let tx = self.conn.transaction().map_err(sql("starting a transaction"))?;
        let latest: Option<String> = tx
            .query_row(
                "SELECT r.hash FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.path = ?1 ORDER BY r.id DESC LIMIT 1",
                [rev.path],
                |r| r.get(0),
            )
            .optional()
            .map_err(sql("looking up the latest revision"))?;
        if latest.as_deref() == Some(rev.hash) {
            return Ok(None);
        }
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
        tx.execute(
            "INSERT INTO programs(path, role, machine_id, name, program_key, stem, dialect) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)
             ON CONFLICT(path) DO UPDATE SET role = excluded.role, machine_id = excluded.machine_id, name = excluded.name,
               program_key = excluded.program_key, stem = excluded.stem, dialect = excluded.dialect",
            params![rev.path, rev.role, machine_id, rev.name, rev.key, rev.stem, rev.dialect],
        )
        .map_err(sql("recording a program"))?;
        let program_id: i64 =
            tx.query_row("SELECT id FROM programs WHERE path = ?1", [rev.path], |r| r.get(0)).map_err(sql("recording a program"))?;
        tx.execute(
            "INSERT OR IGNORE INTO blobs(hash, size, content) VALUES (?1, ?2, ?3)",
            params![rev.hash, rev.bytes.len() as i64, rev.bytes],
        )
        .map_err(sql("storing program bytes"))?;
        tx.execute(
            "INSERT INTO revisions(program_id, hash, size, mtime_ns, seen_at, encoding, status) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7)",
            params![program_id, rev.hash, rev.bytes.len() as i64, rev.mtime_ns, rev.seen_at, rev.encoding, rev.status],
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
        {
            let mut stmt = tx
                .prepare("INSERT INTO diagnostics(revision_id, code, severity, line, col, byte_start, byte_end, message) VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8)")
                .map_err(sql("storing diagnostics"))?;
            for d in rev.diagnostics {
                stmt.execute(params![revision_id, d.code, d.severity.as_str(), d.line, d.col, d.start, d.end, d.message])
                    .map_err(sql("storing diagnostics"))?;
            }
        }
        if let Some((original, changes)) = rev.comparison {
            insert_comparison(&tx, revision_id, original, changes, rev.seen_at)?;
        }
        tx.commit().map_err(sql("committing a revision"))?;
        Ok(Some(revision_id))
    }

    /// Records the comparison of an already stored revision (when its original arrives later).
    pub fn record_comparison(&mut self, revision_id: i64, original: i64, changes: &[Change], at: &str) -> Result<()> {
        let tx = self.conn.transaction().map_err(sql("starting a transaction"))?;
        insert_comparison(&tx, revision_id, original, changes, at)?;
        tx.commit().map_err(sql("committing a comparison"))
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

fn insert_comparison(tx: &Transaction<'_>, revision_id: i64, original: i64, changes: &[Change], at: &str) -> Result<()> {
    tx.execute(
        "INSERT OR REPLACE INTO comparisons(revision_id, original_revision_id, compared_at, changes) VALUES (?1, ?2, ?3, ?4)",
        params![revision_id, original, at, changes.len() as i64],
    )
    .map_err(sql("recording a comparison"))?;
    let mut stmt = tx
        .prepare(
            "INSERT INTO changes(revision_id, original_revision_id, workingstep, operation, kind, field, before, after, line, detected_at)
             VALUES (?1, ?2, ?3, ?4, ?5, ?6, ?7, ?8, ?9, ?10)",
        )
        .map_err(sql("storing changes"))?;
    for c in changes {
        stmt.execute(params![revision_id, original, c.workingstep, c.operation, c.kind.as_str(), c.field, c.before, c.after, c.line, at])
            .map_err(sql("storing changes"))?;
    }
    Ok(())
}

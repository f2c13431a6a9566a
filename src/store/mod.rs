//! The store: the only module that knows SQL, on two engines behind one interface.
//!
//! [`Store`] and [`Txn`] are the interface; `sqlite.rs` (one file per DNC server) and `pg.rs`
//! (one PostgreSQL database for a plant) are the backends, with the same schema, views,
//! migrations and semantics. The rest of the program does not know which one it talks to.
//!
//! Revisions are content-addressed and never overwritten (triggers forbid it). Each
//! revision is recorded with its plan, diagnostics and changes in one transaction, so a
//! crash leaves either all of it or none of it, and the next scan picks the file up again.
//!
//! the only SQL, on two engines behind one interface: `Store` and `Txn` in
//! `mod.rs` dispatch to `sqlite.rs` (`Lite`: WAL, one writer at a time by `BEGIN IMMEDIATE`)
//! or `pg.rs` (`Pg`: the synchronous `postgres` client, TLS by rustls, the password from the
//! environment or a private file, `Location` shows URLs without it; writers of one program
//! path, and of one pairing key, meet through transaction advisory locks, shared rows are
//! written `ON CONFLICT`). `copy.rs` is `ncplan migrate` (`Store::copy_from`): a site's history
//! between any two databases through one `End` per engine (`LiteEnd`, `PgEnd`: SQL written once
//! with `?1` parameters, cells as `Val`s, blobs streamed 1 MiB at a time); every table in
//! `COPIED` (a unit test holds it to the tables the migrations create), ids kept where the
//! target has them free and references followed where not, what the target has left as it is.
//! The rest of the program sees
//! `Location` and `Store` only. `schema.rs` holds SQLite's migrations, `pg_schema.rs` their
//! PostgreSQL twins, one for one (BIGINT identities, DOUBLE PRECISION, BYTEA, triggers that
//! raise, the plan tables filled with `json_array_elements` where SQLite uses `json_each`).
//! The re-analysis queue: `queue_reanalysis`, `claim_reanalysis` (`FOR UPDATE SKIP LOCKED` on
//! PostgreSQL), `Txn::record_analysis`.
//! Immutable blobs and revisions, `Store::begin` → `Txn`, the one transaction in which a revision, its keys and
//! findings, the partial-write mark of the revision before and every comparison it enables
//! commit; `Content::Absent` keeps a file over the size limit as its hash and size only; the
//! attempt journal (`begin_attempt`) notes analyses in progress (a content's own analysis only:
//! closed when it returns, before the store is waited for; after two unfinished analyses,
//! `ingest::UNFINISHED_ANALYSES`, the content is tried in a child `ncplan plan` and stored
//! unanalysed only when that dies too, since such a revision never serves an edit); `query_read_only` runs one
//! read-only statement with plain refusals; read methods for `show`. `pages.rs`: the read
//! queries of the workspace (machines, timelines, change rows with their review marks,
//! search, weekly counts, health), the knowledge pages' SQL (`KNOWLEDGE`, shown by the pages),
//! the console's saved queries and `query_limited` (row limit, and a time limit by SQLite's
//! progress handler), and the web's writes: `add_mark` into `review_marks` (migration 4),
//! `save_query` into `saved_queries` (migration 7) and the sign-in sessions in `web_sessions`
//! (migration 8: by the token's SHA-256, with expiry; `start_session`, `session_user`,
//! `end_session`). `pg/pages.rs` holds the PostgreSQL
//! twin of each (the same rows in the same order: text by code point, `COLLATE "C"`, NULLs
//! first, SQLite's tie-breaks), so `serve` renders the same bytes on both engines; each
//! knowledge page has its SQL per engine (`Knowledge::sql`, `pg_sql`; `Store::knowledge_sql`),
//! the built-in saved queries run on both as written. PostgreSQL's `query_limited` runs in a
//! `READ ONLY` transaction rolled back after, `SET LOCAL statement_timeout` as the time limit,
//! at most the row cap fetched from a cursor (`EXPLAIN` directly).
//! A comparison made again (`Txn::record_comparison`, after a re-analysis or a better pairing)
//! moves the rows it replaces to `old_changes` (migration 7: with `analysis`, the version that
//! made them, `replaced_by` and `replaced_at`), so the current tables hold the newest analysis
//! only and every read (pages, report, show, the view) shows it. **How a mark relates to a
//! re-analysed change**: `review_marks.change_id` names a change row; a change found again by
//! the new analysis — same revision and the same stable key (workingstep, kind, field, before,
//! after), each old row used once (`store::continued`) — keeps its id and its first
//! `detected_at`, so its marks stay on it and it stays off the review queue; a change the new
//! analysis does not find leaves `changes`, and its marks name its row in `old_changes` (same
//! `change_id`). New change ids are never an id a change had before (SQLite numbers past
//! `old_changes` too; PostgreSQL's identity never reuses). The mark also copies the change's
//! kind, before and after, so it says what was reviewed whatever happens to the row.

mod copy;
pub mod location;
mod pages;
mod pg;
mod pg_schema;
mod schema;
mod sqlite;
mod suggest;

use crate::pairing::{Candidate, Key};
pub use copy::CopySummary;
pub use location::Location;
pub use pages::{
    ChangeFilter, ChangeRow, EditedProgram, ErrorRevision, KNOWLEDGE, Knowledge, Limited, MachineSummary, Mark, ProgramInfo, ProgramRow,
    SAVED_QUERIES, SavedQuery, TimelineRow,
};
pub use pg::PLANT_QUERIES;
pub use schema::MIGRATIONS;
pub use suggest::{CamRow, EditRow, SUGGESTION_EDITS, SUGGESTION_STEPS, SuggestionStep};

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
        /// The engine's error.
        #[source]
        source: Box<dyn std::error::Error + Send + Sync + 'static>,
    },
    /// A file could not be read or its bytes not copied.
    #[error("IO error while {about}")]
    Io {
        /// What was being done.
        about: &'static str,
        /// The error.
        #[source]
        source: std::io::Error,
    },
    /// The database cannot be reached as configured (its URL, password file or TLS).
    #[error("{0}")]
    Setup(String),
    /// A file streamed into its blob no longer had the size and hash it was read with.
    #[error("the file changed while it was stored")]
    ContentChanged,
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

/// `(revision_id)` of revisions that may serve as originals or be compared: analysed, with a
/// plan, and not a partial write. The same SQL on both engines.
macro_rules! usable {
    () => {
        "r.status = 'analysed' AND EXISTS (SELECT 1 FROM plans pl WHERE pl.revision_id = r.id)
     AND NOT EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = r.id AND k.mark = 'partial')"
    };
}
use usable;
const USABLE: &str = usable!();

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
    /// The program's bytes.
    pub content: Content<'a>,
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
    /// Plan JSON, when analysed: a summary without toolpaths unless `plan_complete`.
    pub plan_json: Option<&'a str>,
    /// Whether `plan_json` holds the whole plan, toolpaths included.
    pub plan_complete: bool,
    /// Number of workingsteps and tools.
    pub counts: (usize, usize),
    /// Diagnostics.
    pub diagnostics: &'a [DiagnosticJson],
}

/// A revision's bytes: in memory, or absent (a file over the size limit, of which only the
/// size and the hash are kept: the limit bounds what is stored).
#[derive(Debug, Clone, Copy)]
pub enum Content<'a> {
    /// The bytes.
    Bytes(&'a [u8]),
    /// Not kept: a file of `size` bytes whose SHA-256 is the revision's hash.
    Absent {
        /// Its size.
        size: u64,
    },
}

impl Content<'_> {
    /// Size in bytes.
    pub fn len(&self) -> u64 {
        match self {
            Content::Bytes(b) => b.len() as u64,
            Content::Absent { size } => *size,
        }
    }

    /// Whether there are no bytes.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// The largest blob SQLite keeps (`SQLITE_MAX_LENGTH`); bigger files keep their hash and size only.
pub const MAX_BLOB: u64 = 1_000_000_000;

/// A stored revision's program, to rebuild its plan from.
#[derive(Debug, Clone)]
pub struct StoredSource {
    /// Program path.
    pub path: String,
    /// Dialect it was read in.
    pub dialect: String,
    /// Revision status.
    pub status: String,
    /// The stored plan JSON and whether it is complete.
    pub plan: Option<(String, bool)>,
    /// The bytes (read only when the plan is not complete).
    pub bytes: Option<Vec<u8>>,
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

/// A stored finding.
#[derive(Debug, Clone)]
pub struct StoredFinding {
    /// `error`, `warning` or `note`.
    pub severity: String,
    /// Code.
    pub code: String,
    /// Line, from 1.
    pub line: i64,
    /// Column, from 1.
    pub col: i64,
    /// Message.
    pub message: String,
}

/// A stored revision as `ncplan show` tells it.
#[derive(Debug, Clone)]
pub struct RevisionInfo {
    /// Revision id.
    pub id: i64,
    /// Program path.
    pub path: String,
    /// `cam` or `machine`.
    pub role: String,
    /// Machine name.
    pub machine: Option<String>,
    /// The name the revision stated.
    pub name: String,
    /// Dialect.
    pub dialect: String,
    /// Content hash.
    pub hash: String,
    /// Size in bytes.
    pub size: u64,
    /// When ncplan saw it.
    pub seen_at: String,
    /// Text encoding.
    pub encoding: String,
    /// `analysed`, `too_large` or `empty`.
    pub status: String,
    /// The revision this one is the start of, when it was a partial write.
    pub partial_of: Option<i64>,
    /// The original it was compared with: revision, path, pairing rule, number of changes.
    pub original: Option<(i64, String, String, usize)>,
    /// Whether a plan is stored.
    pub has_plan: bool,
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

/// Why `ncplan query` did not run a statement.
#[derive(Debug, thiserror::Error)]
pub enum QueryError {
    /// The statement is not one read-only statement.
    #[error("{0}")]
    Refused(String),
    /// SQLite rejected it.
    #[error("{0}")]
    Sql(String),
}

/// The first statement of `sql` and what follows it (blank when nothing does): `;` inside
/// quotes or comments does not end a statement.
pub fn split_statement(sql: &str) -> (&str, &str) {
    let b = sql.as_bytes();
    let mut i = 0;
    while i < b.len() {
        match b[i] {
            q @ (b'\'' | b'"' | b'`') => {
                i += 1;
                while i < b.len() && b[i] != q {
                    i += 1;
                }
            }
            b'[' => {
                while i < b.len() && b[i] != b']' {
                    i += 1;
                }
            }
            b'-' if b.get(i + 1) == Some(&b'-') => {
                while i < b.len() && b[i] != b'\n' {
                    i += 1;
                }
            }
            b'/' if b.get(i + 1) == Some(&b'*') => {
                i += 2;
                while i + 1 < b.len() && !(b[i] == b'*' && b[i + 1] == b'/') {
                    i += 1;
                }
                i += 1;
            }
            b';' => {
                let rest = &sql[i + 1..];
                let rest_code = split_statement_blank(rest);
                return (&sql[..i], if rest_code { "" } else { rest });
            }
            _ => {}
        }
        i += 1;
    }
    (sql, "")
}

/// The one statement of `sql_text`, refused in plain words when more follow or it does not
/// start as a reading statement does (`SELECT`, `WITH`, `VALUES`, `EXPLAIN`). The engine
/// still runs it read-only: a `WITH` that deletes is refused there.
pub(crate) fn one_reading_statement(sql_text: &str) -> std::result::Result<&str, QueryError> {
    let (first, rest) = split_statement(sql_text);
    if !rest.is_empty() {
        return Err(QueryError::Refused(format!("one statement at a time: `{}` was not run", rest.trim())));
    }
    let keyword = first.trim_start().split(|c: char| !c.is_ascii_alphabetic()).next().unwrap_or("").to_ascii_uppercase();
    if !matches!(keyword.as_str(), "SELECT" | "WITH" | "VALUES" | "EXPLAIN") {
        let what = if keyword.is_empty() { "an empty statement".to_owned() } else { format!("`{keyword}`") };
        return Err(QueryError::Refused(format!("{what} is refused: queries only read (SELECT, WITH, VALUES, EXPLAIN)")));
    }
    Ok(first)
}

/// Whether `s` holds only blanks, semicolons and comments.
fn split_statement_blank(s: &str) -> bool {
    let mut t = s.trim_start_matches(|c: char| c.is_whitespace() || c == ';');
    loop {
        if let Some(r) = t.strip_prefix("--") {
            t = r.split_once('\n').map_or("", |x| x.1);
        } else if let Some(r) = t.strip_prefix("/*") {
            t = r.split_once("*/").map_or("", |x| x.1);
        } else {
            return t.is_empty();
        }
        t = t.trim_start_matches(|c: char| c.is_whitespace() || c == ';');
    }
}

/// A stored change as a comparison made again matches it: its id, workingstep, kind,
/// field, before, after, and when it was detected.
pub(crate) type OldChange = (i64, i64, String, String, String, String, String);

/// For each of a comparison's `new` changes, the id and detection time of the stored change
/// it continues: the first not yet taken with the same workingstep, kind, field, before and
/// after (the change's stable key). A change found again keeps its id, so the review marks
/// made on it stay on it, and the time it was first detected.
pub(crate) fn continued(old: &[OldChange], new: &[Change]) -> Vec<Option<(i64, String)>> {
    let mut taken = vec![false; old.len()];
    new.iter()
        .map(|c| {
            let i = old.iter().enumerate().position(|(i, o)| {
                !taken[i]
                    && o.1 == i64::from(c.workingstep)
                    && o.2 == c.kind.as_str()
                    && o.3 == c.field
                    && o.4 == c.before
                    && o.5 == c.after
            })?;
            taken[i] = true;
            Some((old[i].0, old[i].6.clone()))
        })
        .collect()
}

/// The columns `old_changes` copies from `changes` (after its own change_id, revision_id,
/// original_revision_id, analysis, replaced_by and replaced_at).
pub(crate) const OLD_CHANGE_COLUMNS: &str = "workingstep, operation, kind, field, before, after, line, detected_at, original_line,
     region_min_x, region_min_y, region_min_z, region_max_x, region_max_y, region_max_z, deviation";

/// A re-analysis to record ([`Txn::record_analysis`]).
#[derive(Debug)]
pub struct NewAnalysis<'a> {
    /// The revision.
    pub revision: i64,
    /// The analysis version (ncplan's and the dictionary's).
    pub version: &'a str,
    /// Who did it (host and process).
    pub worker: &'a str,
    /// When (RFC 3339).
    pub at: &'a str,
    /// The new plan summary JSON.
    pub plan_json: &'a str,
    /// Workingsteps and tools.
    pub counts: (usize, usize),
    /// The new findings.
    pub diagnostics: &'a [DiagnosticJson],
}

/// What a re-analysis changed.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Reanalysed {
    /// Whether the plan differs from the one it replaced.
    pub plan_changed: bool,
    /// Findings (code and message) the old analysis did not have.
    pub new_findings: usize,
    /// Findings of the old analysis this one does not have.
    pub vanished_findings: usize,
}

/// An open database, on either engine.
pub struct Store {
    engine: Engine,
}

enum Engine {
    Lite(sqlite::Lite),
    Pg(Box<pg::Pg>),
}

/// One unit of work: a revision, its findings, the partial-write mark of the one before, and
/// every comparison it enables commit together or not at all.
pub struct Txn<'c> {
    engine: TxnEngine<'c>,
}

enum TxnEngine<'c> {
    Lite(sqlite::LiteTxn<'c>),
    Pg(pg::PgTxn<'c>),
}

macro_rules! on {
    ($self:expr, $e:ident => $call:expr) => {
        match &$self.engine {
            Engine::Lite($e) => $call,
            Engine::Pg($e) => $call,
        }
    };
}

macro_rules! on_tx {
    ($self:expr, $e:ident => $call:expr) => {
        match &$self.engine {
            TxnEngine::Lite($e) => $call,
            TxnEngine::Pg($e) => $call,
        }
    };
}

impl Store {
    /// Opens (creating if needed) the database at `at` and applies migrations; what this
    /// process writes belongs to `site`.
    pub fn open(at: &Location, site: &str) -> Result<Store> {
        let engine = match at {
            Location::Sqlite(path) => Engine::Lite(sqlite::Lite::open(path, site)?),
            Location::Postgres(target) => Engine::Pg(Box::new(pg::Pg::open(target, site)?)),
        };
        Ok(Store { engine })
    }

    /// An in-memory SQLite database, for tests.
    pub fn open_in_memory() -> Result<Store> {
        Ok(Store { engine: Engine::Lite(sqlite::Lite::open_in_memory("")?) })
    }

    /// Opens the database read-only: no statement can change it (SQLite opened read-only;
    /// on PostgreSQL every transaction of the session is read-only).
    pub fn open_read_only(at: &Location) -> Result<Store> {
        let engine = match at {
            Location::Sqlite(path) => Engine::Lite(sqlite::Lite::open_read_only(path)?),
            Location::Postgres(target) => Engine::Pg(Box::new(pg::Pg::open_read_only(target)?)),
        };
        Ok(Store { engine })
    }

    /// The same store reading as `site` (whose program paths [`Store::latest_hash`] looks up).
    pub fn for_site(mut self, site: &str) -> Store {
        match &mut self.engine {
            Engine::Lite(e) => e.site = site.to_owned(),
            Engine::Pg(e) => e.set_site(site),
        }
        self
    }

    /// Copies the history of `site` from `from` into this database (`ncplan migrate`): from
    /// a PostgreSQL database the site's rows, from a SQLite file (one server's) all of them,
    /// written as `site`'s. Every table is copied; ids are kept where this database has them
    /// free, and references follow where not; what is here already is left as it is, so a
    /// stopped run goes on where it was. `progress` hears (done, of) revisions.
    pub fn copy_from(&self, from: &Store, site: &str, progress: &dyn Fn(usize, usize)) -> Result<CopySummary> {
        if let Engine::Lite(lite) = &from.engine {
            let version = lite.version()?;
            if version < 3 {
                return Err(StoreError::Setup(format!(
                    "the SQLite database has schema version {version}; run this ncplan's `watch` on it once to bring it to the current one"
                )));
            }
        }
        let (src, dst) = (from.end(), self.end());
        copy::copy(src.as_ref(), dst.as_ref(), site, progress)
    }

    /// This database as an end of [`Store::copy_from`].
    fn end(&self) -> Box<dyn copy::End + '_> {
        match &self.engine {
            Engine::Lite(e) => Box::new(sqlite::LiteEnd(&e.conn)),
            Engine::Pg(e) => Box::new(e.end()),
        }
    }

    /// Fills a PostgreSQL database with a simulated plant of `revisions` revisions (see
    /// [`PLANT_QUERIES`]) for `ncplan bench --simulate`; returns how many there are.
    pub fn simulate_plant(&self, revisions: i64) -> Result<i64> {
        match &self.engine {
            Engine::Pg(pg) => pg.simulate_plant(revisions),
            Engine::Lite(_) => Err(StoreError::Setup("the plant simulation runs on PostgreSQL (--postgres URL)".into())),
        }
    }

    /// Queues every analysed revision (seen since `since`, of `dialect`) that has no analysis
    /// of `version` yet; returns how many are queued for it now.
    pub fn queue_reanalysis(&self, version: &str, since: Option<&str>, dialect: Option<&str>) -> Result<usize> {
        on!(self, e => e.queue_reanalysis(version, since, dialect))
    }

    /// Claims up to `n` queued revisions of `version` for `worker` until `lease_until`: those
    /// no one holds, or whose lease ran out before `now` (its worker died). On PostgreSQL
    /// concurrent workers skip each other's rows (`FOR UPDATE SKIP LOCKED`).
    pub fn claim_reanalysis(&self, version: &str, worker: &str, n: usize, now: &str, lease_until: &str) -> Result<Vec<i64>> {
        on!(self, e => e.claim_reanalysis(version, worker, n, now, lease_until))
    }

    /// Revisions of `version` still queued.
    pub fn reanalysis_left(&self, version: &str) -> Result<usize> {
        on!(self, e => e.reanalysis_left(version))
    }

    /// The SQL a knowledge page runs on this engine.
    pub fn knowledge_sql(&self, page: &Knowledge) -> &'static str {
        match self.engine {
            Engine::Lite(_) => page.sql,
            Engine::Pg(_) => page.pg_sql,
        }
    }

    /// Which engine, for messages: `SQLite` or `PostgreSQL`.
    pub fn engine_name(&self) -> &'static str {
        match self.engine {
            Engine::Lite(_) => "SQLite",
            Engine::Pg(_) => "PostgreSQL",
        }
    }

    /// How long a statement waits for another connection's transaction before it fails.
    pub fn set_busy_timeout(&mut self, wait: std::time::Duration) -> Result<()> {
        match &mut self.engine {
            Engine::Lite(e) => e.set_busy_timeout(wait),
            Engine::Pg(e) => e.set_busy_timeout(wait),
        }
    }

    /// Schema version: how many migrations have run.
    pub fn version(&self) -> Result<usize> {
        on!(self, e => e.version())
    }

    /// The hash of the latest revision of the program at `path` (of this site).
    pub fn latest_hash(&self, path: &str) -> Result<Option<String>> {
        on!(self, e => e.latest_hash(path))
    }

    /// Whether the program at `path` has a revision with the content `hash`, at any time.
    pub fn has_revision(&self, path: &str, hash: &str) -> Result<bool> {
        on!(self, e => e.has_revision(path, hash))
    }

    /// Notes that the content `hash` is about to be analysed, and returns how many earlier
    /// analyses of it never finished (a kill by the kernel's out-of-memory killer, a memory
    /// limit, a crash). The note is removed when its revision is recorded, or by [`Store::finish_attempt`].
    pub fn begin_attempt(&self, hash: &str, path: &str, at: &str) -> Result<u32> {
        on!(self, e => e.begin_attempt(hash, path, at))
    }

    /// Removes the note of an analysis that ended without recording a revision.
    pub fn finish_attempt(&self, hash: &str, path: &str) -> Result<()> {
        on!(self, e => e.finish_attempt(hash, path))
    }

    /// Starts the one transaction in which a revision and everything it enables are recorded.
    /// Writers of other programs do not wait for it (PostgreSQL) or wait for one
    /// transaction at most (SQLite's single writer).
    pub fn begin(&mut self) -> Result<Txn<'_>> {
        let engine = match &mut self.engine {
            Engine::Lite(e) => TxnEngine::Lite(e.begin()?),
            Engine::Pg(e) => TxnEngine::Pg(e.begin()?),
        };
        Ok(Txn { engine })
    }

    /// One stored revision, for `ncplan show`.
    pub fn revision(&self, id: i64) -> Result<Option<RevisionInfo>> {
        on!(self, e => e.revision(id))
    }

    /// The newest revision of the program at `path` (a whole path, or its end after a `/`)
    /// seen at or before `at` (RFC 3339 or a date; `None`: the newest of all). Several
    /// programs whose paths end so are an error that lists them.
    pub fn revision_of_path(&self, path: &str, at: Option<&str>) -> Result<std::result::Result<Option<i64>, Vec<String>>> {
        on!(self, e => e.revision_of_path(path, at))
    }

    /// A stored revision's program and plan, to rebuild its whole plan from.
    pub fn source(&self, revision: i64) -> Result<Option<StoredSource>> {
        on!(self, e => e.source(revision))
    }

    /// The stored bytes of a revision.
    pub fn content(&self, revision: i64) -> Result<Option<Vec<u8>>> {
        on!(self, e => e.content(revision))
    }

    /// The findings of a revision, in source order.
    pub fn findings(&self, revision: i64) -> Result<Vec<StoredFinding>> {
        on!(self, e => e.findings(revision))
    }

    /// The changes found in a revision against its original.
    pub fn changes(&self, revision: i64) -> Result<Vec<Change>> {
        on!(self, e => e.changes(revision))
    }

    /// Runs one read-only statement (`SELECT`, `WITH`, `VALUES`, `EXPLAIN`) for `ncplan query`,
    /// with refusals in plain words. On PostgreSQL it runs in a read-only transaction.
    pub fn query_read_only(&self, sql_text: &str) -> std::result::Result<(Vec<String>, Vec<Vec<String>>), QueryError> {
        let first = one_reading_statement(sql_text)?;
        on!(self, e => e.query_read_only(first))
    }

    /// Runs a query and returns column names and rows as text (NULL as blank, a blob as
    /// `<n bytes>`, a truth value as 1 or 0, on both engines).
    pub fn query(&self, sql_text: &str) -> Result<(Vec<String>, Vec<Vec<String>>)> {
        on!(self, e => e.query(sql_text))
    }
}

impl Txn<'_> {
    /// Commits.
    pub fn commit(self) -> Result<()> {
        match self.engine {
            TxnEngine::Lite(t) => t.commit(),
            TxnEngine::Pg(t) => t.commit(),
        }
    }

    /// The newest revision of the program at `path`, with its age at `now` (RFC 3339). On
    /// PostgreSQL this also makes other writers of the same program wait for this transaction,
    /// so that one content is stored once however many processes see it.
    pub fn latest(&self, path: &str, now: &str) -> Result<Option<Latest>> {
        on_tx!(self, e => e.latest(path, now))
    }

    /// The stored bytes with `hash`.
    pub fn blob(&self, hash: &str) -> Result<Option<Vec<u8>>> {
        on_tx!(self, e => e.blob(hash))
    }

    /// Records a revision with its program, keys, bytes, plan and diagnostics.
    pub fn insert_revision(&self, rev: &NewRevision<'_>) -> Result<i64> {
        on_tx!(self, e => e.insert_revision(rev))
    }

    /// A stored revision's program and plan, to rebuild its whole plan from.
    pub fn source(&self, revision: i64) -> Result<Option<StoredSource>> {
        on_tx!(self, e => e.source(revision))
    }

    /// The stored bytes of a revision.
    pub fn content(&self, revision: i64) -> Result<Option<Vec<u8>>> {
        on_tx!(self, e => e.content(revision))
    }

    /// The findings of a revision, in source order (those stored in this transaction too).
    pub fn findings(&self, revision: i64) -> Result<Vec<StoredFinding>> {
        on_tx!(self, e => e.findings(revision))
    }

    /// Adds a finding to a stored revision, unless it has the same one (code and message).
    pub fn add_finding(&self, revision_id: i64, d: &DiagnosticJson) -> Result<bool> {
        on_tx!(self, e => e.add_finding(revision_id, d))
    }

    /// Marks `revision` as a partial write of `by` (the revision whose start it is).
    pub fn mark_partial(&self, revision: i64, by: i64, at: &str) -> Result<()> {
        on_tx!(self, e => e.mark_partial(revision, by, at))
    }

    /// The CAM originals of this site that have the key `key`: for each, its newest usable revision.
    pub fn originals(&self, key: &str) -> Result<Vec<Candidate>> {
        on_tx!(self, e => e.originals(key))
    }

    /// Usable machine revisions of this site without a comparison: of the programs with the
    /// key `key`, or of every program.
    pub fn uncompared(&self, key: Option<&str>) -> Result<Vec<Comparable>> {
        on_tx!(self, e => e.uncompared(key))
    }

    /// Records the programs `revision` called from outside its text (lower-case file stems).
    pub fn add_calls(&self, revision: i64, names: &[String]) -> Result<()> {
        on_tx!(self, e => e.add_calls(revision, names))
    }

    /// The newest revisions of programs that call `name` (a lower-case file stem) and have a
    /// comparison.
    pub fn callers(&self, name: &str) -> Result<Vec<i64>> {
        on_tx!(self, e => e.callers(name))
    }

    /// Machine revisions compared with `original`.
    pub fn compared_with(&self, original: i64) -> Result<Vec<Comparable>> {
        on_tx!(self, e => e.compared_with(original))
    }

    /// Records the comparison of `revision` with `original`, paired by `rule`, replacing an
    /// earlier one of the same revision: its change rows move to `old_changes` with the
    /// analysis version that made them, and a change found again keeps its id ([`continued`]).
    /// The new rows name the analysis of the revision's plan.
    pub fn record_comparison(&self, revision: i64, original: i64, rule: &str, changes: &[Change], at: &str) -> Result<()> {
        on_tx!(self, e => e.record_comparison(revision, original, rule, changes, at))
    }

    /// The original `revision` was compared with, and the rule that paired them.
    pub fn comparison_of(&self, revision: i64) -> Result<Option<(i64, String)>> {
        on_tx!(self, e => e.comparison_of(revision))
    }

    /// Records a re-analysis of a revision: its new plan and findings replace the current
    /// ones, which are kept in `analyses` with the version that made them, and its queue entry
    /// goes. `None` when this version's analysis of the revision is recorded already (by
    /// another worker): each revision is analysed once per version.
    pub fn record_analysis(&self, a: &NewAnalysis<'_>) -> Result<Option<Reanalysed>> {
        on_tx!(self, e => e.record_analysis(a))
    }
}

/// Knowledge back to CAM (`suggest.rs`, migration 11): the edits the rules read, the CAM
/// posts the watch compares, and the review steps.
impl Store {
    /// The changes of the parameters suggestions are about, with their newest adopt or reject mark, oldest first.
    pub fn suggestion_edits(&self) -> Result<Vec<EditRow>> {
        on!(self, e => e.suggestion_edits())
    }

    /// The workingsteps of CAM revisions seen after `since`, oldest first.
    pub fn cam_steps_since(&self, since: &str) -> Result<Vec<CamRow>> {
        on!(self, e => e.cam_steps_since(since))
    }

    /// Every suggestion's review steps, by suggestion and step.
    pub fn suggestion_steps(&self) -> Result<Vec<SuggestionStep>> {
        on!(self, e => e.suggestion_steps())
    }

    /// Records a review step as step `s.step` of its suggestion, the one after the last step
    /// the caller read, unless that step is recorded already: two writers that read the same
    /// state (two daemons on one database, two planners) record one step, not two (the key
    /// `(suggestion, step)` decides, on both engines). Returns the step, or `None` when
    /// another writer recorded that step first.
    pub fn add_suggestion_step(&self, s: &SuggestionStep) -> Result<Option<i64>> {
        on!(self, e => e.add_suggestion_step(s))
    }
}

/// The planners' workspace (`ncplan serve`): its read queries and review marks (`pages.rs`).
impl Store {
    /// The machines with their programs, revisions, newest revision and review queue.
    pub fn machines(&self) -> Result<Vec<MachineSummary>> {
        on!(self, e => e.machines())
    }

    /// The review marks of a change, oldest first.
    pub fn marks(&self, change_id: i64) -> Result<Vec<Mark>> {
        on!(self, e => e.marks(change_id))
    }

    /// The changes that match `filter`, newest first, at most `limit`.
    pub fn search_changes(&self, filter: &ChangeFilter, limit: usize) -> Result<Vec<ChangeRow>> {
        on!(self, e => e.search_changes(filter, limit))
    }

    /// The changes of one edited revision, in their order.
    pub fn change_rows(&self, revision: i64) -> Result<Vec<ChangeRow>> {
        on!(self, e => e.change_rows(revision))
    }

    /// Changes per ISO week (`YYYY-Www`) per machine, oldest week first, for the last `weeks` weeks with changes.
    pub fn changes_per_week(&self, weeks: usize) -> Result<Vec<(String, String, i64)>> {
        on!(self, e => e.changes_per_week(weeks))
    }

    /// The programs edited most: by revisions with changes.
    pub fn most_edited(&self, limit: usize) -> Result<Vec<EditedProgram>> {
        on!(self, e => e.most_edited(limit))
    }

    /// How often each change kind occurs, most often first.
    pub fn kind_counts(&self) -> Result<Vec<(String, i64)>> {
        on!(self, e => e.kind_counts())
    }

    /// The newest revisions whose analysis found errors.
    pub fn error_revisions(&self, limit: usize) -> Result<Vec<ErrorRevision>> {
        on!(self, e => e.error_revisions(limit))
    }

    /// When the newest revision of each CAM or machine folder was seen: `(folder, when)`.
    pub fn last_seen_per_folder(&self) -> Result<Vec<(String, String)>> {
        on!(self, e => e.last_seen_per_folder())
    }

    /// One machine.
    pub fn machine(&self, name: &str) -> Result<Option<MachineSummary>> {
        on!(self, e => e.machine(name))
    }

    /// A machine's programs with their newest revision.
    pub fn machine_programs(&self, machine: &str) -> Result<Vec<ProgramRow>> {
        on!(self, e => e.machine_programs(machine))
    }

    /// One program.
    pub fn program(&self, id: i64) -> Result<Option<ProgramInfo>> {
        on!(self, e => e.program(id))
    }

    /// The program a revision belongs to.
    pub fn program_of(&self, revision: i64) -> Result<Option<i64>> {
        on!(self, e => e.program_of(revision))
    }

    /// Every revision of a program, oldest first.
    pub fn timeline(&self, program: i64) -> Result<Vec<TimelineRow>> {
        on!(self, e => e.timeline(program))
    }

    /// The CAM originals a program's revisions were compared with: `(program id, path, newest revision)`.
    pub fn originals_of(&self, program: i64) -> Result<Vec<(i64, String, i64)>> {
        on!(self, e => e.originals_of(program))
    }

    /// Adds a review mark to a change: `adopt`, `reject` or `note`. Returns the revision the
    /// change belongs to, or `None` when there is no such change. Analysis tables are only read.
    pub fn add_mark(&self, change_id: i64, mark: &str, note: &str, by: &str, at: &str) -> Result<Option<i64>> {
        on!(self, e => e.add_mark(change_id, mark, note, by, at))
    }

    /// The queries planners saved in the SQL console, oldest first.
    pub fn saved_queries(&self) -> Result<Vec<SavedQuery>> {
        on!(self, e => e.saved_queries())
    }

    /// Saves a console query under `name` (who, when); the SQL must be one reading
    /// statement. Returns its id. Analysis tables are only read.
    pub fn save_query(&self, name: &str, sql_text: &str, by: &str, at: &str) -> std::result::Result<i64, QueryError> {
        let name = name.trim();
        if name.is_empty() {
            return Err(QueryError::Refused("a saved query needs a name".into()));
        }
        if name.chars().count() > 200 {
            return Err(QueryError::Refused("a saved query's name is at most 200 characters".into()));
        }
        let first = one_reading_statement(sql_text)?;
        on!(self, e => e.save_query(name, first.trim(), by, at)).map_err(|e| QueryError::Sql(e.to_string()))
    }

    /// Records a planner's sign-in session until `expires_at` (RFC 3339), by the SHA-256 of
    /// its cookie's token (`token_hash`: the database holds no cookie that works), and forgets
    /// the sessions that had ended by `created_at`.
    pub fn start_session(&self, token_hash: &str, user: &str, created_at: &str, expires_at: &str) -> Result<()> {
        on!(self, e => e.start_session(token_hash, user, created_at, expires_at))
    }

    /// The planner whose session's token hashes to `token_hash`, unless it had ended by `now`.
    pub fn session_user(&self, token_hash: &str, now: &str) -> Result<Option<String>> {
        on!(self, e => e.session_user(token_hash, now))
    }

    /// Ends a session (the planner signed out).
    pub fn end_session(&self, token_hash: &str) -> Result<()> {
        on!(self, e => e.end_session(token_hash))
    }

    /// Why the SQL console must not run through this connection's database role (a
    /// PostgreSQL superuser, or a role that may read the server's files), if it must not; a
    /// SQLite file has no roles.
    pub fn console_refusal(&self) -> Result<Option<String>> {
        match &self.engine {
            Engine::Lite(_) => Ok(None),
            Engine::Pg(e) => e.console_refusal(),
        }
    }

    /// Runs one read-only statement for the SQL console: at most `max_rows` rows, stopped
    /// (SQLite's progress handler) once it has run `limit`. Returns the columns, the rows and
    /// whether rows were left off.
    pub fn query_limited(&self, sql_text: &str, max_rows: usize, limit: std::time::Duration) -> std::result::Result<Limited, QueryError> {
        let first = one_reading_statement(sql_text)?;
        on!(self, e => e.query_limited(first, max_rows, limit))
    }
}

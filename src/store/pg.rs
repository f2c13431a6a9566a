//! The PostgreSQL backend: one database for a plant's DNC servers.
//!
//! The same tables, views and rules as SQLite (`pg_schema.rs` holds the twin of each
//! migration). Concurrent writers never wait for each other beyond one revision's
//! transaction: a transaction-scoped advisory lock per program path (taken by
//! [`PgTxn::latest`]) makes two processes that see the same content store it once, and one
//! per pairing key (taken by [`PgTxn::insert_revision`], in a fixed order) makes an original
//! and its edit, arriving at once on two connections, meet in whichever commits second.
//! Rows that many revisions share (machines, blobs) are written with `ON CONFLICT`.

use std::cell::{Cell, RefCell};
use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use postgres::types::{ToSql, Type};
use postgres::{Client, Row, SimpleQueryMessage, Statement};

use super::copy::{End as _, Val};
use super::location::{PASSWORD_ENV, PASSWORD_FILE_ENV, PgTarget};
use super::pg_schema;
use super::*;
use crate::pairing::Rule;

mod pages;
mod suggest;

fn sql(about: &'static str) -> impl FnOnce(postgres::Error) -> StoreError {
    move |source| StoreError::Sql { about, source: Box::new(source) }
}

/// Lock classes of `pg_advisory_xact_lock(class, key)`.
const LOCK_PATH: i32 = 1;
const LOCK_KEY: i32 = 2;
/// Session lock class and key that serialise migrations of concurrent starts.
const LOCK_MIGRATE: (i32, i32) = (3, 0);

/// An open PostgreSQL connection.
pub(super) struct Pg {
    conn: Conn,
}

/// The connection with its prepared statements and the site it writes for.
struct Conn {
    client: RefCell<Client>,
    prepared: RefCell<BTreeMap<&'static str, Statement>>,
    site: String,
}

/// Connects, with TLS as `sslmode` says (rustls, the system's trusted roots): `disable`
/// never, `prefer` (the default) when the server offers it, `require`, `verify-ca` and
/// `verify-full` always, and always verifying the server's certificate and name.
fn connect(target: &PgTarget) -> Result<Client> {
    let (url, root) = take_rootcert(&target.url);
    let (url, mode) = take_sslmode(&url)?;
    let mut config: postgres::Config =
        url.parse().map_err(|_| StoreError::Setup(format!("the database URL {} cannot be read", target.shown())))?;
    if config.get_password().is_none()
        && let Some(password) = password(target)?
    {
        config.password(password);
    }
    if config.get_application_name().is_none() {
        config.application_name("ncplan");
    }
    let connected = match mode {
        SslMode::Disable => {
            config.ssl_mode(postgres::config::SslMode::Disable);
            config.connect(postgres::NoTls)
        }
        SslMode::Prefer | SslMode::Require => {
            config.ssl_mode(if mode == SslMode::Prefer { postgres::config::SslMode::Prefer } else { postgres::config::SslMode::Require });
            config.connect(tls(root.as_deref())?)
        }
    };
    connected.map_err(|e| StoreError::Sql { about: "connecting to PostgreSQL", source: Box::new(e) })
}

#[derive(Clone, Copy, PartialEq, Eq)]
enum SslMode {
    Disable,
    Prefer,
    Require,
}

/// The URL without its `sslmode` parameter, and the mode (libpq's names).
fn take_sslmode(url: &str) -> Result<(String, SslMode)> {
    let Some((base, query)) = url.split_once('?') else { return Ok((url.to_owned(), SslMode::Prefer)) };
    let mut mode = SslMode::Prefer;
    let mut kept = Vec::new();
    for p in query.split('&') {
        match p.strip_prefix("sslmode=") {
            Some("disable") => mode = SslMode::Disable,
            Some("allow" | "prefer") => mode = SslMode::Prefer,
            Some("require" | "verify-ca" | "verify-full") => mode = SslMode::Require,
            Some(other) => {
                return Err(StoreError::Setup(format!(
                    "sslmode `{other}` is not one of disable, allow, prefer, require, verify-ca, verify-full"
                )));
            }
            None => kept.push(p),
        }
    }
    Ok((if kept.is_empty() { base.to_owned() } else { format!("{base}?{}", kept.join("&")) }, mode))
}

/// The URL without its `sslrootcert` parameter (libpq's name), and the file it names.
fn take_rootcert(url: &str) -> (String, Option<String>) {
    let Some((base, query)) = url.split_once('?') else { return (url.to_owned(), None) };
    let mut root = None;
    let mut kept = Vec::new();
    for p in query.split('&') {
        match p.strip_prefix("sslrootcert=") {
            Some(file) => root = Some(file.to_owned()),
            None => kept.push(p),
        }
    }
    (if kept.is_empty() { base.to_owned() } else { format!("{base}?{}", kept.join("&")) }, root)
}

/// The TLS client: the system's trusted roots, and the certificates of `root` (a PEM file:
/// the plant's CA, or a server's own self-signed certificate) when given.
fn tls(root: Option<&str>) -> Result<tokio_postgres_rustls::MakeRustlsConnect> {
    use rustls::pki_types::pem::PemObject as _;
    let mut roots = rustls::RootCertStore::empty();
    for cert in rustls_native_certs::load_native_certs().certs {
        let _ = roots.add(cert);
    }
    if let Some(file) = root {
        let certs = rustls::pki_types::CertificateDer::pem_file_iter(file)
            .map_err(|e| StoreError::Setup(format!("sslrootcert {file} cannot be read: {e}")))?;
        let mut added = 0;
        for cert in certs {
            let cert = cert.map_err(|e| StoreError::Setup(format!("sslrootcert {file} is not a PEM certificate file: {e}")))?;
            roots.add(cert).map_err(|e| StoreError::Setup(format!("sslrootcert {file}: {e}")))?;
            added += 1;
        }
        if added == 0 {
            return Err(StoreError::Setup(format!("sslrootcert {file} holds no certificate")));
        }
    }
    let config = rustls::ClientConfig::builder_with_provider(Arc::new(rustls::crypto::ring::default_provider()))
        .with_safe_default_protocol_versions()
        .map_err(|e| StoreError::Setup(format!("TLS: {e}")))?
        .with_root_certificates(roots)
        .with_no_client_auth();
    Ok(tokio_postgres_rustls::MakeRustlsConnect::new(config))
}

/// The password: from `NCPLAN_DB_PASSWORD`, else from the file `NCPLAN_DB_PASSWORD_FILE` or
/// the config's `password_file` names, which only its owner may read.
fn password(target: &PgTarget) -> Result<Option<String>> {
    if let Ok(p) = std::env::var(PASSWORD_ENV) {
        return Ok(Some(p));
    }
    let file = std::env::var_os(PASSWORD_FILE_ENV).map(std::path::PathBuf::from).or_else(|| target.password_file.clone());
    let Some(file) = file else { return Ok(None) };
    read_password_file(&file).map(Some)
}

/// Reads a password file, refusing one that others than its owner may read.
pub(super) fn read_password_file(file: &Path) -> Result<String> {
    use std::os::unix::fs::PermissionsExt as _;
    let meta = std::fs::metadata(file).map_err(|e| StoreError::Io { about: "reading the database password file", source: e })?;
    let mode = meta.permissions().mode();
    if mode & 0o077 != 0 {
        return Err(StoreError::Setup(format!(
            "the password file {} may be read by others (mode {:o}); make it readable by the service user alone (chmod 600)",
            file.display(),
            mode & 0o777
        )));
    }
    let text = std::fs::read_to_string(file).map_err(|e| StoreError::Io { about: "reading the database password file", source: e })?;
    Ok(text.trim_end_matches(['\r', '\n']).to_owned())
}

impl Pg {
    /// Connects and applies migrations; writes belong to `site`.
    pub(super) fn open(target: &PgTarget, site: &str) -> Result<Pg> {
        let pg = Pg { conn: Conn { client: RefCell::new(connect(target)?), prepared: RefCell::default(), site: site.to_owned() } };
        pg.migrate()?;
        Ok(pg)
    }

    /// Connects with every transaction read-only.
    pub(super) fn open_read_only(target: &PgTarget) -> Result<Pg> {
        let mut client = connect(target)?;
        client.batch_execute("SET default_transaction_read_only = on").map_err(sql("making the session read-only"))?;
        Ok(Pg { conn: Conn { client: RefCell::new(client), prepared: RefCell::default(), site: String::new() } })
    }

    pub(super) fn set_site(&mut self, site: &str) {
        self.conn.site = site.to_owned();
    }

    fn migrate(&self) -> Result<()> {
        let mut c = self.conn.client.borrow_mut();
        // A current database is only read: a role that may only read (a deployment's
        // read-only role) opens it too, and is refused when it writes.
        let current = c
            .query_one("SELECT CASE WHEN to_regclass('schema_version') IS NULL THEN -1 ELSE 0 END", &[])
            .map_err(sql("reading the schema version"))?
            .get::<_, i32>(0)
            == 0
            && c.query_one("SELECT COALESCE(MAX(version), 0) FROM schema_version", &[])
                .map_err(sql("reading the schema version"))?
                .get::<_, i64>(0) as usize
                == pg_schema::MIGRATIONS.len();
        if current {
            return Ok(());
        }
        c.execute("SELECT pg_advisory_lock($1, $2)", &[&LOCK_MIGRATE.0, &LOCK_MIGRATE.1]).map_err(sql("waiting for a migration"))?;
        let result = (|| {
            c.batch_execute("CREATE TABLE IF NOT EXISTS schema_version (version BIGINT NOT NULL)")
                .map_err(sql("reading the schema version"))?;
            let version = c
                .query_one("SELECT COALESCE(MAX(version), 0) FROM schema_version", &[])
                .map_err(sql("reading the schema version"))?
                .get::<_, i64>(0) as usize;
            let known = pg_schema::MIGRATIONS.len();
            if version > known {
                return Err(StoreError::TooNew { found: version, known });
            }
            for (i, m) in pg_schema::MIGRATIONS.iter().enumerate().skip(version) {
                let mut tx = c.transaction().map_err(sql("starting a migration"))?;
                tx.batch_execute(m).map_err(sql("applying a migration"))?;
                tx.execute("DELETE FROM schema_version", &[]).map_err(sql("recording the schema version"))?;
                tx.execute("INSERT INTO schema_version(version) VALUES ($1)", &[&((i + 1) as i64)])
                    .map_err(sql("recording the schema version"))?;
                tx.commit().map_err(sql("committing a migration"))?;
            }
            Ok(())
        })();
        c.execute("SELECT pg_advisory_unlock($1, $2)", &[&LOCK_MIGRATE.0, &LOCK_MIGRATE.1]).map_err(sql("ending a migration"))?;
        result
    }

    /// How long a statement waits for a lock another transaction holds.
    pub(super) fn set_busy_timeout(&mut self, wait: std::time::Duration) -> Result<()> {
        self.conn
            .client
            .borrow_mut()
            .batch_execute(&format!("SET lock_timeout = {}", wait.as_millis()))
            .map_err(sql("setting the lock timeout"))
    }

    pub(super) fn version(&self) -> Result<usize> {
        let row = self.conn.one("reading the schema version", "SELECT COALESCE(MAX(version), 0) FROM schema_version", &[])?;
        Ok(row.get::<_, i64>(0) as usize)
    }

    pub(super) fn latest_hash(&self, path: &str) -> Result<Option<String>> {
        let row = self.conn.opt(
            "looking up the latest revision",
            "SELECT r.hash FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.site = $1 AND p.path = $2 ORDER BY r.id DESC LIMIT 1",
            &[&self.conn.site, &path],
        )?;
        Ok(row.map(|r| r.get(0)))
    }

    pub(super) fn has_revision(&self, path: &str, hash: &str) -> Result<bool> {
        let row = self.conn.one(
            "looking up a revision",
            "SELECT EXISTS (SELECT 1 FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.site = $1 AND p.path = $2 AND r.hash = $3)",
            &[&self.conn.site, &path, &hash],
        )?;
        Ok(row.get(0))
    }

    pub(super) fn begin_attempt(&self, hash: &str, path: &str, at: &str) -> Result<u32> {
        let row = self.conn.one(
            "writing the attempt journal",
            "INSERT INTO attempts(site, hash, path, started_at, tries) VALUES ($1, $2, $3, $4, 1)
             ON CONFLICT (site, hash, path) DO UPDATE SET tries = attempts.tries + 1, started_at = EXCLUDED.started_at
             RETURNING tries",
            &[&self.conn.site, &hash, &path, &at],
        )?;
        Ok(row.get::<_, i64>(0).saturating_sub(1) as u32)
    }

    pub(super) fn finish_attempt(&self, hash: &str, path: &str) -> Result<()> {
        self.conn.exec(
            "writing the attempt journal",
            "DELETE FROM attempts WHERE site = $1 AND hash = $2 AND path = $3",
            &[&self.conn.site, &hash, &path],
        )?;
        Ok(())
    }

    pub(super) fn begin(&mut self) -> Result<PgTxn<'_>> {
        self.conn.client.borrow_mut().batch_execute("BEGIN").map_err(sql("starting a transaction"))?;
        Ok(PgTxn { conn: &self.conn, done: Cell::new(false) })
    }

    pub(super) fn revision(&self, id: i64) -> Result<Option<RevisionInfo>> {
        let row = self.conn.opt(
            "reading a revision",
            "SELECT r.id, p.path, p.role, m.name, COALESCE(r.name, p.name), p.dialect, r.hash, r.size, r.seen_at, r.encoding, r.status,
                    (SELECT superseded_by FROM revision_marks k WHERE k.revision_id = r.id AND k.mark = 'partial'),
                    c.original_revision_id, (SELECT op.path FROM revisions orv JOIN programs op ON op.id = orv.program_id WHERE orv.id = c.original_revision_id),
                    c.rule, c.changes, pl.plan_json IS NOT NULL
             FROM revisions r JOIN programs p ON p.id = r.program_id LEFT JOIN machines m ON m.id = p.machine_id
             LEFT JOIN comparisons c ON c.revision_id = r.id LEFT JOIN plans pl ON pl.revision_id = r.id
             WHERE r.id = $1",
            &[&id],
        )?;
        Ok(row.map(|r| RevisionInfo {
            id: r.get(0),
            path: r.get(1),
            role: r.get(2),
            machine: r.get(3),
            name: r.get(4),
            dialect: r.get(5),
            hash: r.get(6),
            size: r.get::<_, i64>(7) as u64,
            seen_at: r.get(8),
            encoding: r.get(9),
            status: r.get(10),
            partial_of: r.get(11),
            original: match (r.get::<_, Option<i64>>(12), r.get::<_, Option<String>>(13)) {
                (Some(id), Some(path)) => {
                    Some((id, path, r.get::<_, Option<String>>(14).unwrap_or_default(), r.get::<_, Option<i64>>(15).unwrap_or(0) as usize))
                }
                _ => None,
            },
            has_plan: r.get(16),
        }))
    }

    pub(super) fn revision_of_path(&self, path: &str, at: Option<&str>) -> Result<std::result::Result<Option<i64>, Vec<String>>> {
        let escaped = path.replace('\\', "\\\\").replace('%', "\\%").replace('_', "\\_");
        let found: Vec<(i64, String)> = self
            .conn
            .rows(
                "looking up a path",
                "SELECT id, path FROM programs WHERE path = $1 OR path LIKE '%/' || $2 ESCAPE '\\' ORDER BY path, site",
                &[&path, &escaped],
            )?
            .iter()
            .map(|r| (r.get(0), r.get(1)))
            .collect();
        let exact: Vec<(i64, String)> = found.iter().filter(|(_, p)| p == path).cloned().collect();
        let program = match (exact.as_slice(), found.as_slice()) {
            ([one], _) | ([], [one]) => one.0,
            ([], []) => return Ok(Ok(None)),
            _ => return Ok(Err(found.into_iter().map(|(_, p)| p).collect())),
        };
        let at = at.map(|a| if a.len() == 10 { format!("{a}T23:59:59.999Z") } else { a.to_owned() });
        let row = self.conn.one(
            "looking up a revision",
            "SELECT MAX(id) FROM revisions WHERE program_id = $1 AND ($2::text IS NULL OR seen_at::timestamptz <= $2::timestamptz)",
            &[&program, &at],
        )?;
        Ok(Ok(row.get(0)))
    }

    pub(super) fn source(&self, revision: i64) -> Result<Option<StoredSource>> {
        self.conn.source(revision)
    }

    pub(super) fn content(&self, revision: i64) -> Result<Option<Vec<u8>>> {
        let row = self.conn.opt(
            "reading program bytes",
            "SELECT b.content FROM revisions r JOIN blobs b ON b.hash = r.hash WHERE r.id = $1",
            &[&revision],
        )?;
        Ok(row.map(|r| r.get(0)))
    }

    pub(super) fn findings(&self, revision: i64) -> Result<Vec<StoredFinding>> {
        self.conn.findings(revision)
    }

    pub(super) fn changes(&self, revision: i64) -> Result<Vec<Change>> {
        let rows = self.conn.rows(
            "reading changes",
            "SELECT workingstep, operation, kind, field, before, after, line, original_line,
                    region_min_x, region_min_y, region_min_z, region_max_x, region_max_y, region_max_z, deviation, detail
             FROM changes WHERE revision_id = $1 ORDER BY id",
            &[&revision],
        )?;
        Ok(rows
            .iter()
            .map(|r| {
                let kind: String = r.get(2);
                let mut c = Change {
                    kind: serde_json::from_value(serde_json::Value::String(kind)).unwrap_or(crate::diff::ChangeKind::ToolpathChanged),
                    workingstep: r.get::<_, i64>(0) as u32,
                    operation: r.get(1),
                    field: r.get(3),
                    before: r.get(4),
                    after: r.get(5),
                    line: r.get::<_, Option<i64>>(6).map(|l| l as u32),
                    original_line: r.get::<_, Option<i64>>(7).map(|l| l as u32),
                    region: match (r.get::<_, Option<f64>>(8), r.get::<_, Option<f64>>(11)) {
                        (Some(_), Some(_)) => {
                            Some(crate::plan::BBox { min: [r.get(8), r.get(9), r.get(10)], max: [r.get(11), r.get(12), r.get(13)] })
                        }
                        _ => None,
                    },
                    deviation: r.get(14),
                    detail: crate::diff::Detail::default(),
                };
                c.set_detail(&r.get::<_, String>(15));
                c
            })
            .collect())
    }

    /// One statement in a read-only transaction (`SET TRANSACTION READ ONLY`).
    pub(super) fn query_read_only(&self, sql_text: &str) -> std::result::Result<(Vec<String>, Vec<Vec<String>>), QueryError> {
        let mut c = self.conn.client.borrow_mut();
        c.batch_execute("BEGIN; SET TRANSACTION READ ONLY").map_err(|e| QueryError::Sql(plain(&e)))?;
        let result = text_rows(&mut c, sql_text).map_err(|e| QueryError::Sql(plain(&e)));
        let _ = c.batch_execute("ROLLBACK");
        result
    }

    pub(super) fn query(&self, sql_text: &str) -> Result<(Vec<String>, Vec<Vec<String>>)> {
        text_rows(&mut self.conn.client.borrow_mut(), sql_text).map_err(sql("running the query"))
    }
}

/// Runs `sql_text` and returns its columns and rows as text, as the SQLite backend renders
/// them: NULL blank, BYTEA `<n bytes>`, a truth value 1 or 0.
fn text_rows(c: &mut Client, sql_text: &str) -> std::result::Result<(Vec<String>, Vec<Vec<String>>), postgres::Error> {
    let stmt = c.prepare(sql_text)?;
    let names: Vec<String> = stmt.columns().iter().map(|c| c.name().to_owned()).collect();
    let types: Vec<Type> = stmt.columns().iter().map(|c| c.type_().clone()).collect();
    let out = text_cells(&c.simple_query(sql_text)?, &types);
    Ok((names, out))
}

/// The rows among a simple query's messages as text, as [`text_rows`] gives them.
fn text_cells(messages: &[SimpleQueryMessage], types: &[Type]) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for m in messages {
        if let SimpleQueryMessage::Row(row) = m {
            let mut cells = Vec::with_capacity(types.len());
            for (i, t) in types.iter().enumerate() {
                let v = row.get(i).unwrap_or("");
                cells.push(if row.get(i).is_none() {
                    String::new()
                } else if *t == Type::BOOL {
                    if v == "t" { "1".into() } else { "0".into() }
                } else if *t == Type::BYTEA {
                    format!("<{} bytes>", v.len().saturating_sub(2) / 2)
                } else {
                    v.to_owned()
                });
            }
            out.push(cells);
        }
    }
    out
}

/// PostgreSQL's message, without its internals.
fn plain(e: &postgres::Error) -> String {
    match e.as_db_error() {
        Some(db) if db.code() == &postgres::error::SqlState::READ_ONLY_SQL_TRANSACTION => "the query would write; queries only read".into(),
        Some(db) if db.code() == &postgres::error::SqlState::QUERY_CANCELED => "the query ran past its time limit".into(),
        Some(db) if db.code() == &postgres::error::SqlState::INSUFFICIENT_PRIVILEGE => {
            format!("the database role may not do this ({}); queries only read", db.message())
        }
        Some(db) => db.message().to_owned(),
        None => e.to_string(),
    }
}

impl Conn {
    /// A revision's stored findings, in their order (read by the workspace and by a
    /// transaction comparing what an edit breaks or fixes).
    fn findings(&self, revision: i64) -> Result<Vec<StoredFinding>> {
        let rows = self.rows(
            "reading findings",
            "SELECT severity, code, line, col, message FROM diagnostics WHERE revision_id = $1 ORDER BY byte_start, id",
            &[&revision],
        )?;
        Ok(rows
            .iter()
            .map(|r| StoredFinding { severity: r.get(0), code: r.get(1), line: r.get(2), col: r.get(3), message: r.get(4) })
            .collect())
    }

    fn statement(&self, about: &'static str, text: &'static str) -> Result<Statement> {
        if let Some(s) = self.prepared.borrow().get(text) {
            return Ok(s.clone());
        }
        let s = self.client.borrow_mut().prepare(text).map_err(sql(about))?;
        self.prepared.borrow_mut().insert(text, s.clone());
        Ok(s)
    }

    fn rows(&self, about: &'static str, text: &'static str, params: &[&(dyn ToSql + Sync)]) -> Result<Vec<Row>> {
        let s = self.statement(about, text)?;
        self.client.borrow_mut().query(&s, params).map_err(sql(about))
    }

    fn one(&self, about: &'static str, text: &'static str, params: &[&(dyn ToSql + Sync)]) -> Result<Row> {
        let s = self.statement(about, text)?;
        self.client.borrow_mut().query_one(&s, params).map_err(sql(about))
    }

    fn opt(&self, about: &'static str, text: &'static str, params: &[&(dyn ToSql + Sync)]) -> Result<Option<Row>> {
        let s = self.statement(about, text)?;
        self.client.borrow_mut().query_opt(&s, params).map_err(sql(about))
    }

    fn exec(&self, about: &'static str, text: &'static str, params: &[&(dyn ToSql + Sync)]) -> Result<u64> {
        let s = self.statement(about, text)?;
        self.client.borrow_mut().execute(&s, params).map_err(sql(about))
    }

    fn source(&self, revision: i64) -> Result<Option<StoredSource>> {
        let Some(r) = self.opt(
            "reading a revision",
            "SELECT p.path, p.dialect, r.status, pl.plan_json, pl.complete, r.hash FROM revisions r JOIN programs p ON p.id = r.program_id
             LEFT JOIN plans pl ON pl.revision_id = r.id WHERE r.id = $1",
            &[&revision],
        )?
        else {
            return Ok(None);
        };
        let plan = r.get::<_, Option<String>>(3).map(|json| (json, r.get::<_, Option<i64>>(4).is_none_or(|c| c != 0)));
        let hash: String = r.get(5);
        let mut src = StoredSource { path: r.get(0), dialect: r.get(1), status: r.get(2), plan, bytes: None };
        if !src.plan.as_ref().is_some_and(|(_, complete)| *complete) {
            src.bytes = self.opt("reading program bytes", "SELECT content FROM blobs WHERE hash = $1", &[&hash])?.map(|r| r.get(0));
        }
        Ok(Some(src))
    }

    /// Stores `size` bytes read from `from` as the blob `hash`, 1 MiB at a time (the chunks
    /// meet in a temporary table and are joined by the server), so memory stays bounded
    /// whatever the size; bytes that are not `size` long or do not hash to `hash` are
    /// [`StoreError::ContentChanged`].
    fn stream_into_blob(&self, hash: &str, size: u64, from: &mut dyn std::io::Read) -> Result<()> {
        use sha2::Digest as _;
        let c = self;
        c.client
            .borrow_mut()
            .batch_execute(
                "CREATE TEMPORARY TABLE IF NOT EXISTS blob_chunks (n BIGINT PRIMARY KEY, data BYTEA NOT NULL) ON COMMIT DELETE ROWS",
            )
            .map_err(sql("storing program bytes"))?;
        c.exec("storing program bytes", "DELETE FROM blob_chunks", &[])?;
        let mut hasher = sha2::Sha256::new();
        let mut buf = vec![0u8; 1 << 20];
        let (mut copied, mut n) = (0u64, 0i64);
        loop {
            let got = from.read(&mut buf).map_err(|e| StoreError::Io { about: "reading a program to store", source: e })?;
            if got == 0 {
                break;
            }
            if copied + got as u64 > size {
                return Err(StoreError::ContentChanged);
            }
            hasher.update(&buf[..got]);
            c.exec("storing program bytes", "INSERT INTO blob_chunks(n, data) VALUES ($1, $2)", &[&n, &&buf[..got]])?;
            copied += got as u64;
            n += 1;
        }
        if copied != size || format!("{:x}", hasher.finalize()) != hash {
            return Err(StoreError::ContentChanged);
        }
        c.exec(
            "storing program bytes",
            "INSERT INTO blobs(hash, size, content) SELECT $1, $2, COALESCE(string_agg(data, ''::bytea ORDER BY n), ''::bytea) FROM blob_chunks
             ON CONFLICT (hash) DO NOTHING",
            &[&hash, &(size as i64)],
        )?;
        c.exec("storing program bytes", "DELETE FROM blob_chunks", &[])?;
        Ok(())
    }

    fn keys_of(&self, program_id: i64) -> Result<Vec<Key>> {
        let rows = self.rows("reading program keys", "SELECT rule, key FROM program_keys WHERE program_id = $1", &[&program_id])?;
        let mut keys: Vec<Key> =
            rows.iter().filter_map(|r| Rule::parse(&r.get::<_, String>(0)).map(|rule| Key { rule, value: r.get(1) })).collect();
        keys.sort_by_key(|k| k.rule);
        Ok(keys)
    }
}

/// A transaction on the connection: `BEGIN` … `COMMIT`, rolled back when dropped uncommitted.
pub(super) struct PgTxn<'c> {
    conn: &'c Conn,
    done: Cell<bool>,
}

impl Drop for PgTxn<'_> {
    fn drop(&mut self) {
        if !self.done.get() {
            let _ = self.conn.client.borrow_mut().batch_execute("ROLLBACK");
        }
    }
}

impl PgTxn<'_> {
    pub(super) fn commit(self) -> Result<()> {
        self.conn.client.borrow_mut().batch_execute("COMMIT").map_err(sql("committing a revision"))?;
        self.done.set(true);
        Ok(())
    }

    pub(super) fn latest(&self, path: &str, now: &str) -> Result<Option<Latest>> {
        let c = self.conn;
        c.exec(
            "waiting for the program's other writers",
            "SELECT pg_advisory_xact_lock($1, hashtext($2::text || '/' || $3::text))",
            &[&LOCK_PATH, &c.site, &path],
        )?;
        let row = c.opt(
            "looking up the latest revision",
            "SELECT r.id, r.hash, r.size, EXTRACT(EPOCH FROM ($3::text::timestamptz - r.seen_at::timestamptz))::float8
             FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.site = $1 AND p.path = $2 ORDER BY r.id DESC LIMIT 1",
            &[&c.site, &path, &now],
        )?;
        Ok(row.map(|r| Latest {
            id: r.get(0),
            hash: r.get(1),
            size: r.get::<_, i64>(2) as u64,
            age_s: r.get::<_, Option<f64>>(3).unwrap_or(f64::INFINITY),
        }))
    }

    pub(super) fn blob(&self, hash: &str) -> Result<Option<Vec<u8>>> {
        Ok(self.conn.opt("reading program bytes", "SELECT content FROM blobs WHERE hash = $1", &[&hash])?.map(|r| r.get(0)))
    }

    pub(super) fn insert_revision(&self, rev: &NewRevision<'_>) -> Result<i64> {
        let c = self.conn;
        let site = c.site.as_str();
        // Writers of a program with one of these keys (its original, its edits) go one after the other.
        let keys: Vec<&str> = rev.keys.iter().map(|k| k.value.as_str()).chain(std::iter::once(rev.stem)).collect();
        c.exec(
            "waiting for the writers of the same keys",
            "SELECT pg_advisory_xact_lock($1, h) FROM (SELECT DISTINCT hashtext($2::text || '/' || k) AS h FROM unnest($3::text[]) k ORDER BY h) x",
            &[&LOCK_KEY, &site, &keys],
        )?;
        let machine_id: Option<i64> = match rev.machine {
            Some((name, dialect, folder)) => {
                let known = c.opt(
                    "recording a machine",
                    "SELECT id FROM machines WHERE site = $1 AND name = $2 AND dialect = $3 AND folder = $4",
                    &[&site, &name, &dialect, &folder],
                )?;
                Some(match known {
                    Some(r) => r.get(0),
                    None => c
                        .one(
                            "recording a machine",
                            "INSERT INTO machines(site, name, dialect, folder) VALUES ($1, $2, $3, $4)
                             ON CONFLICT (site, name) DO UPDATE SET dialect = EXCLUDED.dialect, folder = EXCLUDED.folder RETURNING id",
                            &[&site, &name, &dialect, &folder],
                        )?
                        .get(0),
                })
            }
            None => None,
        };
        let first_key = rev.keys.first().map_or(rev.stem, |k| k.value.as_str());
        let program_id: i64 = c
            .one(
                "recording a program",
                "INSERT INTO programs(site, path, role, machine_id, name, program_key, stem, dialect) VALUES ($1, $2, $3, $4, $5, $6, $7, $8)
                 ON CONFLICT (site, path) DO UPDATE SET role = EXCLUDED.role, machine_id = EXCLUDED.machine_id, name = EXCLUDED.name,
                   program_key = EXCLUDED.program_key, stem = EXCLUDED.stem, dialect = EXCLUDED.dialect
                 RETURNING id",
                &[&site, &rev.path, &rev.role, &machine_id, &rev.name, &first_key, &rev.stem, &rev.dialect],
            )?
            .get(0);
        c.exec("recording program keys", "DELETE FROM program_keys WHERE program_id = $1", &[&program_id])?;
        let rules: Vec<&str> = rev.keys.iter().map(|k| k.rule.as_str()).collect();
        let values: Vec<&str> = rev.keys.iter().map(|k| k.value.as_str()).collect();
        c.exec(
            "recording program keys",
            "INSERT INTO program_keys(program_id, rule, key) SELECT $1, r, k FROM unnest($2::text[], $3::text[]) AS u(r, k) ON CONFLICT DO NOTHING",
            &[&program_id, &rules, &values],
        )?;
        match rev.content {
            Content::Bytes(bytes) => {
                c.exec(
                    "storing program bytes",
                    "INSERT INTO blobs(hash, size, content) VALUES ($1, $2, $3) ON CONFLICT (hash) DO NOTHING",
                    &[&rev.hash, &(bytes.len() as i64), &bytes],
                )?;
            }
            Content::Absent { size } => {
                c.exec(
                    "storing program bytes",
                    "INSERT INTO blobs(hash, size, content) VALUES ($1, $2, '') ON CONFLICT (hash) DO NOTHING",
                    &[&rev.hash, &(size as i64)],
                )?;
            }
        }
        let size = rev.content.len() as i64;
        let revision_id: i64 = c
            .one(
                "recording a revision",
                "INSERT INTO revisions(program_id, hash, size, mtime_ns, seen_at, encoding, status, name) VALUES ($1, $2, $3, $4, $5, $6, $7, $8)
                 RETURNING id",
                &[&program_id, &rev.hash, &size, &rev.mtime_ns, &rev.seen_at, &rev.encoding, &rev.status, &rev.name],
            )?
            .get(0);
        c.exec("closing an attempt", "DELETE FROM attempts WHERE site = $1 AND hash = $2 AND path = $3", &[&site, &rev.hash, &rev.path])?;
        if let Some(plan) = rev.plan_json {
            c.exec(
                "storing a plan",
                "INSERT INTO plans(revision_id, plan_json, workingsteps, tools, complete) VALUES ($1, $2, $3, $4, $5)",
                &[&revision_id, &plan, &(rev.counts.0 as i64), &(rev.counts.1 as i64), &i64::from(rev.plan_complete)],
            )?;
            c.exec("storing workingsteps", pg_schema::FILL_WORKINGSTEPS, &[&revision_id])?;
            c.exec("storing features", pg_schema::FILL_FEATURES, &[&revision_id])?;
        }
        self.insert_findings(revision_id, rev.diagnostics)?;
        Ok(revision_id)
    }

    pub(super) fn source(&self, revision: i64) -> Result<Option<StoredSource>> {
        self.conn.source(revision)
    }

    pub(super) fn content(&self, revision: i64) -> Result<Option<Vec<u8>>> {
        let row = self.conn.opt(
            "reading program bytes",
            "SELECT b.content FROM revisions r JOIN blobs b ON b.hash = r.hash WHERE r.id = $1",
            &[&revision],
        )?;
        Ok(row.map(|r| r.get(0)))
    }

    pub(super) fn findings(&self, revision: i64) -> Result<Vec<StoredFinding>> {
        self.conn.findings(revision)
    }

    /// All findings of a revision in one statement, in their order (ids follow it).
    fn insert_findings(&self, revision_id: i64, ds: &[DiagnosticJson]) -> Result<()> {
        if ds.is_empty() {
            return Ok(());
        }
        let code: Vec<&str> = ds.iter().map(|d| d.code).collect();
        let severity: Vec<&str> = ds.iter().map(|d| d.severity.as_str()).collect();
        let line: Vec<i64> = ds.iter().map(|d| d.line as i64).collect();
        let col: Vec<i64> = ds.iter().map(|d| d.col as i64).collect();
        let start: Vec<i64> = ds.iter().map(|d| d.start as i64).collect();
        let end: Vec<i64> = ds.iter().map(|d| d.end as i64).collect();
        let message: Vec<&str> = ds.iter().map(|d| d.message.as_str()).collect();
        self.conn.exec(
            "storing diagnostics",
            "INSERT INTO diagnostics(revision_id, code, severity, line, col, byte_start, byte_end, message)
             SELECT $1, code, severity, line, col, s, e, message
             FROM unnest($2::text[], $3::text[], $4::int8[], $5::int8[], $6::int8[], $7::int8[], $8::text[]) WITH ORDINALITY
                  AS u(code, severity, line, col, s, e, message, n)
             ORDER BY n",
            &[&revision_id, &code, &severity, &line, &col, &start, &end, &message],
        )?;
        Ok(())
    }

    pub(super) fn add_finding(&self, revision_id: i64, d: &DiagnosticJson) -> Result<bool> {
        let known: bool = self
            .conn
            .one(
                "looking up diagnostics",
                "SELECT EXISTS (SELECT 1 FROM diagnostics WHERE revision_id = $1 AND code = $2 AND message = $3)",
                &[&revision_id, &d.code, &d.message],
            )?
            .get(0);
        if !known {
            self.insert_findings(revision_id, std::slice::from_ref(d))?;
        }
        Ok(!known)
    }

    pub(super) fn mark_partial(&self, revision: i64, by: i64, at: &str) -> Result<()> {
        self.conn.exec(
            "marking a partial write",
            "INSERT INTO revision_marks(revision_id, mark, superseded_by, noted_at) VALUES ($1, 'partial', $2, $3) ON CONFLICT DO NOTHING",
            &[&revision, &by, &at],
        )?;
        Ok(())
    }

    pub(super) fn originals(&self, key: &str) -> Result<Vec<Candidate>> {
        const Q: &str = concat!(
            "SELECT p.id, p.path, (SELECT MAX(r.id) FROM revisions r WHERE r.program_id = p.id AND ",
            usable!(),
            ") FROM programs p
             WHERE p.role = 'cam' AND p.site = $2 AND p.id IN (SELECT program_id FROM program_keys WHERE key = $1)
             ORDER BY p.path"
        );
        let rows = self.conn.rows("looking up CAM originals", Q, &[&key, &self.conn.site])?;
        let mut out = Vec::new();
        for r in rows {
            if let Some(revision) = r.get::<_, Option<i64>>(2) {
                out.push(Candidate { revision, path: r.get(1), keys: self.conn.keys_of(r.get(0))? });
            }
        }
        Ok(out)
    }

    pub(super) fn uncompared(&self, key: Option<&str>) -> Result<Vec<Comparable>> {
        const Q: &str = concat!(
            "SELECT r.id, p.path, p.id FROM revisions r JOIN programs p ON p.id = r.program_id
             WHERE p.role = 'machine' AND ",
            usable!(),
            "
               AND NOT EXISTS (SELECT 1 FROM comparisons c WHERE c.revision_id = r.id)
               AND ($1::text IS NULL OR p.id IN (SELECT program_id FROM program_keys WHERE key = $1))
               AND p.site = $2
             ORDER BY r.id"
        );
        let rows = self.conn.rows("listing revisions to compare", Q, &[&key, &self.conn.site])?;
        self.comparables(rows)
    }

    pub(super) fn add_calls(&self, revision: i64, names: &[String]) -> Result<()> {
        for n in names {
            self.conn.exec("storing calls", "INSERT INTO calls(revision_id, name) VALUES ($1, $2)", &[&revision, n])?;
        }
        Ok(())
    }

    pub(super) fn callers(&self, name: &str) -> Result<Vec<i64>> {
        let rows = self.conn.rows(
            "listing callers",
            "SELECT DISTINCT k.revision_id FROM calls k JOIN comparisons c ON c.revision_id = k.revision_id
             JOIN revisions r ON r.id = k.revision_id
             WHERE k.name = $1 AND r.id = (SELECT MAX(id) FROM revisions WHERE program_id = r.program_id) ORDER BY k.revision_id",
            &[&name],
        )?;
        Ok(rows.iter().map(|r| r.get(0)).collect())
    }

    pub(super) fn compared_with(&self, original: i64) -> Result<Vec<Comparable>> {
        let rows = self.conn.rows(
            "listing revisions to compare",
            "SELECT r.id, p.path, p.id FROM comparisons c JOIN revisions r ON r.id = c.revision_id
             JOIN programs p ON p.id = r.program_id WHERE c.original_revision_id = $1 ORDER BY r.id",
            &[&original],
        )?;
        self.comparables(rows)
    }

    fn comparables(&self, rows: Vec<Row>) -> Result<Vec<Comparable>> {
        rows.iter().map(|r| Ok(Comparable { revision: r.get(0), path: r.get(1), keys: self.conn.keys_of(r.get(2))? })).collect()
    }

    pub(super) fn record_comparison(&self, revision: i64, original: i64, rule: &str, changes: &[Change], at: &str) -> Result<()> {
        let c = self.conn;
        let analysis: String = c
            .one("reading a plan's analysis", "SELECT COALESCE((SELECT analysis FROM plans WHERE revision_id = $1), '')", &[&revision])?
            .get(0);
        let old: Vec<OldChange> = c
            .rows(
                "reading changes",
                "SELECT id, workingstep, kind, field, before, after, detected_at FROM changes WHERE revision_id = $1 ORDER BY id",
                &[&revision],
            )?
            .iter()
            .map(|r| (r.get(0), r.get(1), r.get(2), r.get(3), r.get(4), r.get(5), r.get(6)))
            .collect();
        let kept = continued(&old, changes);
        if !old.is_empty() {
            c.exec("keeping the old changes", KEEP_OLD_CHANGES, &[&revision, &analysis, &at])?;
        }
        c.exec("replacing a comparison", "DELETE FROM changes WHERE revision_id = $1", &[&revision])?;
        c.exec(
            "recording a comparison",
            "INSERT INTO comparisons(revision_id, original_revision_id, compared_at, changes, rule) VALUES ($1, $2, $3, $4, $5)
             ON CONFLICT (revision_id) DO UPDATE SET original_revision_id = EXCLUDED.original_revision_id,
               compared_at = EXCLUDED.compared_at, changes = EXCLUDED.changes, rule = EXCLUDED.rule",
            &[&revision, &original, &at, &(changes.len() as i64), &rule],
        )?;
        if changes.is_empty() {
            return Ok(());
        }
        let ws: Vec<i64> = changes.iter().map(|c| c.workingstep as i64).collect();
        let op: Vec<&str> = changes.iter().map(|c| c.operation.as_str()).collect();
        let kind: Vec<&str> = changes.iter().map(|c| c.kind.as_str()).collect();
        let field: Vec<&str> = changes.iter().map(|c| c.field.as_str()).collect();
        let before: Vec<&str> = changes.iter().map(|c| c.before.as_str()).collect();
        let after: Vec<&str> = changes.iter().map(|c| c.after.as_str()).collect();
        let line: Vec<Option<i64>> = changes.iter().map(|c| c.line.map(i64::from)).collect();
        let oline: Vec<Option<i64>> = changes.iter().map(|c| c.original_line.map(i64::from)).collect();
        let corner = |f: fn(&crate::plan::BBox) -> f64| -> Vec<Option<f64>> { changes.iter().map(|c| c.region.as_ref().map(f)).collect() };
        let (x0, y0, z0) = (corner(|b| b.min[0]), corner(|b| b.min[1]), corner(|b| b.min[2]));
        let (x1, y1, z1) = (corner(|b| b.max[0]), corner(|b| b.max[1]), corner(|b| b.max[2]));
        let dev: Vec<Option<f64>> = changes.iter().map(|c| c.deviation).collect();
        let id: Vec<Option<i64>> = kept.iter().map(|k| k.as_ref().map(|k| k.0)).collect();
        let detected: Vec<&str> = kept.iter().map(|k| k.as_ref().map_or(at, |k| k.1.as_str())).collect();
        let detail: Vec<String> = changes.iter().map(Change::detail_json).collect();
        c.exec(
            "storing changes",
            "INSERT INTO changes(id, revision_id, original_revision_id, workingstep, operation, kind, field, before, after, line, detected_at,
                                 original_line, region_min_x, region_min_y, region_min_z, region_max_x, region_max_y, region_max_z, deviation,
                                 analysis, detail)
             SELECT COALESCE(id, nextval(pg_get_serial_sequence('changes', 'id'))), $1, $2, ws, op, kind, field, before, after, line, at,
                    oline, x0, y0, z0, x1, y1, z1, dev, $3, detail
             FROM unnest($4::int8[], $5::text[], $6::text[], $7::text[], $8::text[], $9::text[], $10::int8[], $11::int8[],
                         $12::float8[], $13::float8[], $14::float8[], $15::float8[], $16::float8[], $17::float8[], $18::float8[],
                         $19::int8[], $20::text[], $21::text[])
                  WITH ORDINALITY AS u(ws, op, kind, field, before, after, line, oline, x0, y0, z0, x1, y1, z1, dev, id, at, detail, n)
             ORDER BY n",
            &[
                &revision, &original, &analysis, &ws, &op, &kind, &field, &before, &after, &line, &oline, &x0, &y0, &z0, &x1, &y1, &z1,
                &dev, &id, &detected, &detail,
            ],
        )?;
        Ok(())
    }
}

/// `record_comparison`'s copy of the rows it replaces (`$1` revision, `$2` the analysis that
/// replaces them, `$3` when).
const KEEP_OLD_CHANGES: &str = "INSERT INTO old_changes(change_id, revision_id, original_revision_id, analysis, replaced_by, replaced_at,
        workingstep, operation, kind, field, before, after, line, detected_at, original_line,
        region_min_x, region_min_y, region_min_z, region_max_x, region_max_y, region_max_z, deviation)
 SELECT id, revision_id, original_revision_id, analysis, $2, $3, workingstep, operation, kind, field, before, after, line, detected_at,
        original_line, region_min_x, region_min_y, region_min_z, region_max_x, region_max_y, region_max_z, deviation
 FROM changes WHERE revision_id = $1 ORDER BY id";

/// The plant-scale queries `ncplan bench --simulate` times, by name.
pub const PLANT_QUERIES: &[(&str, &str)] = &[
    (
        "one machine's changes of a week",
        "SELECT machine, program, kind, before, after, detected_at FROM shopfloor_changes
         WHERE site = 'SIM7' AND machine = 'M3' AND detected_at >= '2025-06-01' AND detected_at < '2025-06-08' ORDER BY detected_at DESC",
    ),
    (
        "the plant's newest 50 changes",
        "SELECT site, machine, program, kind, before, after FROM shopfloor_changes ORDER BY detected_at DESC LIMIT 50",
    ),
    (
        "feed changes per machine of a site",
        "SELECT machine, COUNT(*) FROM shopfloor_changes WHERE site = 'SIM42' AND kind = 'feed_changed' GROUP BY machine ORDER BY 2 DESC",
    ),
    (
        "every revision of one program with its errors",
        "SELECT r.id, r.seen_at, (SELECT COUNT(*) FROM diagnostics d WHERE d.revision_id = r.id AND d.severity = 'error')
         FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.site = 'SIM13' AND p.path = '/srv/share/M5/O7.nc' ORDER BY r.id",
    ),
];

impl Pg {
    /// Fills the database with a simulated plant of `revisions` machine revisions (sites
    /// `SIM1`…`SIM100`, 10 machines each, 20 programs a machine, revisions three minutes
    /// apart since 2024, two changes and a comparison each), unless it has them already;
    /// returns how many simulated revisions there are.
    pub(super) fn simulate_plant(&self, revisions: i64) -> Result<i64> {
        let c = &self.conn;
        let have: i64 = c
            .one(
                "counting the simulation",
                "SELECT COUNT(*) FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.site LIKE 'SIM%'",
                &[],
            )?
            .get(0);
        if have >= revisions {
            return Ok(have);
        }
        if have > 0 {
            return Err(StoreError::Setup(format!(
                "the database holds a smaller simulation ({have} revisions); simulate on an empty database"
            )));
        }
        let mut client = c.client.borrow_mut();
        let mut tx = client.transaction().map_err(sql("starting the simulation"))?;
        tx.batch_execute(
            "INSERT INTO machines(site, name, dialect, folder)
               SELECT 'SIM' || s, 'M' || m, 'fanuc', '/srv/share/M' || m FROM generate_series(1, 100) s, generate_series(1, 10) m;
             INSERT INTO programs(site, path, role, machine_id, name, program_key, stem, dialect)
               SELECT m.site, '/srv/share/' || m.name || '/O' || p || '.nc', 'machine', m.id, 'O' || p, 'O' || p, 'O' || p, 'fanuc'
               FROM machines m, generate_series(1, 20) p WHERE m.site LIKE 'SIM%';
             INSERT INTO programs(site, path, role, machine_id, name, program_key, stem, dialect)
               SELECT 'SIM' || s, '/srv/cam/O' || p || '.nc', 'cam', NULL, 'O' || p, 'O' || p, 'O' || p, 'fanuc'
               FROM generate_series(1, 100) s, generate_series(1, 20) p;",
        )
        .map_err(sql("simulating programs"))?;
        tx.execute(
            "INSERT INTO blobs(hash, size, content) SELECT 'sim' || g, 12, convert_to('G1 X' || g, 'UTF8') FROM generate_series(1, $1::bigint) g",
            &[&revisions],
        )
        .map_err(sql("simulating blobs"))?;
        tx.execute(
            "WITH mp AS (SELECT id, name, row_number() OVER (ORDER BY id) - 1 AS k FROM programs WHERE role = 'machine' AND site LIKE 'SIM%')
             INSERT INTO revisions(program_id, hash, size, seen_at, encoding, status, name)
             SELECT mp.id, 'sim' || g, 12,
                    to_char(timestamp '2024-01-01' + g * interval '3 minutes', 'YYYY-MM-DD\"T\"HH24:MI:SS.MS\"Z\"'), 'utf-8', 'analysed', mp.name
             FROM generate_series(1, $1::bigint) g JOIN mp ON mp.k = g % (SELECT COUNT(*) FROM mp)",
            &[&revisions],
        )
        .map_err(sql("simulating revisions"))?;
        tx.batch_execute(
            "INSERT INTO comparisons(revision_id, original_revision_id, compared_at, changes, rule)
               SELECT r.id, r.id, r.seen_at, 2, 'file-name' FROM revisions r WHERE r.hash LIKE 'sim%';
             INSERT INTO changes(revision_id, original_revision_id, workingstep, operation, kind, field, before, after, line, detected_at)
               SELECT r.id, r.id, 1, 'plane finish milling', k.kind, k.field, k.before, (250 + r.id % 50)::text, 7, r.seen_at
               FROM revisions r, (VALUES ('feed_changed', 'feed', '250'), ('spindle_speed_changed', 'spindle_speed', '1800')) k(kind, field, before)
               WHERE r.hash LIKE 'sim%';
             INSERT INTO diagnostics(revision_id, code, severity, line, col, byte_start, byte_end, message)
               SELECT r.id, 'interp::unknown-code', 'error', 3, 1, 10, 14, 'simulated' FROM revisions r WHERE r.hash LIKE 'sim%' AND r.id % 10 = 0;",
        )
        .map_err(sql("simulating comparisons"))?;
        tx.commit().map_err(sql("committing the simulation"))?;
        client.batch_execute("ANALYZE").map_err(sql("analysing the simulation"))?;
        Ok(revisions)
    }
}

impl Pg {
    pub(super) fn queue_reanalysis(&self, version: &str, since: Option<&str>, dialect: Option<&str>) -> Result<usize> {
        self.conn.exec(
            "queueing revisions",
            "INSERT INTO reanalysis_queue(revision_id, version)
             SELECT r.id, $1 FROM revisions r JOIN programs p ON p.id = r.program_id
             WHERE r.status = 'analysed' AND ($2::text IS NULL OR r.seen_at::timestamptz >= $2::text::timestamptz)
               AND ($3::text IS NULL OR p.dialect = $3)
               AND NOT EXISTS (SELECT 1 FROM analyses a WHERE a.revision_id = r.id AND a.version = $1)
             ON CONFLICT DO NOTHING",
            &[&version, &since, &dialect],
        )?;
        self.reanalysis_left(version)
    }

    pub(super) fn claim_reanalysis(&self, version: &str, worker: &str, n: usize, now: &str, lease_until: &str) -> Result<Vec<i64>> {
        let rows = self.conn.rows(
            "claiming revisions",
            "UPDATE reanalysis_queue q SET worker = $1, lease_until = $2
             FROM (SELECT revision_id FROM reanalysis_queue WHERE version = $3 AND (lease_until IS NULL OR lease_until < $4)
                   ORDER BY revision_id LIMIT $5 FOR UPDATE SKIP LOCKED) c
             WHERE q.revision_id = c.revision_id AND q.version = $3
             RETURNING q.revision_id",
            &[&worker, &lease_until, &version, &now, &(n as i64)],
        )?;
        let mut ids: Vec<i64> = rows.iter().map(|r| r.get(0)).collect();
        ids.sort_unstable();
        Ok(ids)
    }

    pub(super) fn reanalysis_left(&self, version: &str) -> Result<usize> {
        let row = self.conn.one("counting the queue", "SELECT COUNT(*) FROM reanalysis_queue WHERE version = $1", &[&version])?;
        Ok(row.get::<_, i64>(0) as usize)
    }
}

impl PgTxn<'_> {
    pub(super) fn comparison_of(&self, revision: i64) -> Result<Option<(i64, String)>> {
        let row = self.conn.opt(
            "reading a comparison",
            "SELECT original_revision_id, COALESCE(rule, '') FROM comparisons WHERE revision_id = $1",
            &[&revision],
        )?;
        Ok(row.map(|r| (r.get(0), r.get(1))))
    }

    pub(super) fn record_analysis(&self, a: &NewAnalysis<'_>) -> Result<Option<Reanalysed>> {
        let c = self.conn;
        // The queue entry's row lock: a worker whose lease ran out and one that took it over meet here.
        c.exec(
            "locking a queue entry",
            "SELECT 1 FROM reanalysis_queue WHERE revision_id = $1 AND version = $2 FOR UPDATE",
            &[&a.revision, &a.version],
        )?;
        let old = c
            .opt("reading a plan", "SELECT plan_json, analysis FROM plans WHERE revision_id = $1", &[&a.revision])?
            .map(|r| (r.get::<_, String>(0), r.get::<_, String>(1)));
        let found: Vec<StoredFinding> = c
            .rows(
                "reading findings",
                "SELECT severity, code, line, col, message FROM diagnostics WHERE revision_id = $1 ORDER BY byte_start, id",
                &[&a.revision],
            )?
            .iter()
            .map(|r| StoredFinding { severity: r.get(0), code: r.get(1), line: r.get(2), col: r.get(3), message: r.get(4) })
            .collect();
        let (old_json, old_set) = super::sqlite::findings_record(&found);
        let outcome = super::sqlite::reanalysed(old.as_ref().map(|o| o.0.as_str()), &old_set, a);
        let inserted = c.exec(
            "recording an analysis",
            "INSERT INTO analyses(revision_id, version, analysed_at, worker, previous, previous_plan, previous_findings,
                                  plan_changed, new_findings, vanished_findings)
             VALUES ($1, $2, $3, $4, $5, $6, $7, $8, $9, $10) ON CONFLICT DO NOTHING",
            &[
                &a.revision,
                &a.version,
                &a.at,
                &a.worker,
                &old.as_ref().map_or("", |o| o.1.as_str()),
                &old.as_ref().map(|o| o.0.as_str()),
                &old_json,
                &i64::from(outcome.plan_changed),
                &(outcome.new_findings as i64),
                &(outcome.vanished_findings as i64),
            ],
        )?;
        if inserted == 0 {
            return Ok(None);
        }
        c.exec("replacing an analysis", "DELETE FROM workingsteps WHERE revision_id = $1", &[&a.revision])?;
        c.exec("replacing an analysis", "DELETE FROM features WHERE revision_id = $1", &[&a.revision])?;
        c.exec("replacing an analysis", "DELETE FROM plans WHERE revision_id = $1", &[&a.revision])?;
        c.exec("replacing an analysis", "DELETE FROM diagnostics WHERE revision_id = $1", &[&a.revision])?;
        c.exec(
            "storing a plan",
            "INSERT INTO plans(revision_id, plan_json, workingsteps, tools, complete, analysis) VALUES ($1, $2, $3, $4, 0, $5)",
            &[&a.revision, &a.plan_json, &(a.counts.0 as i64), &(a.counts.1 as i64), &a.version],
        )?;
        c.exec("storing workingsteps", pg_schema::FILL_WORKINGSTEPS, &[&a.revision])?;
        c.exec("storing features", pg_schema::FILL_FEATURES, &[&a.revision])?;
        self.insert_findings(a.revision, a.diagnostics)?;
        c.exec(
            "closing a queue entry",
            "DELETE FROM reanalysis_queue WHERE revision_id = $1 AND version = $2",
            &[&a.revision, &a.version],
        )?;
        Ok(Some(outcome))
    }
}

/// A PostgreSQL database as an end of `ncplan migrate` ([`super::copy`]): its statements
/// prepared once each, cells converted to the types the server asks for.
pub(super) struct PgEnd<'a> {
    conn: &'a Conn,
    prepared: RefCell<BTreeMap<String, Statement>>,
}

impl Pg {
    /// This database as an end of `ncplan migrate`.
    pub(super) fn end(&self) -> PgEnd<'_> {
        PgEnd { conn: &self.conn, prepared: RefCell::default() }
    }
}

impl PgEnd<'_> {
    /// `sql_text` with `?1` written `$1`, prepared.
    fn statement(&self, sql_text: &str) -> Result<Statement> {
        if let Some(s) = self.prepared.borrow().get(sql_text) {
            return Ok(s.clone());
        }
        let mut text = String::with_capacity(sql_text.len());
        let mut chars = sql_text.chars().peekable();
        while let Some(c) = chars.next() {
            text.push(if c == '?' && chars.peek().is_some_and(char::is_ascii_digit) { '$' } else { c });
        }
        let s = self.conn.client.borrow_mut().prepare(&text).map_err(sql("preparing a copy"))?;
        self.prepared.borrow_mut().insert(sql_text.to_owned(), s.clone());
        Ok(s)
    }

    /// The parameters of `s` from `params`, each as the type the server asks for.
    fn params(s: &Statement, params: &[Val]) -> Result<Vec<Box<dyn ToSql + Sync>>> {
        s.params()
            .iter()
            .zip(params)
            .map(|(ty, v)| -> Result<Box<dyn ToSql + Sync>> {
                Ok(match (v, ty) {
                    (Val::Null, &Type::INT8) => Box::new(None::<i64>),
                    (Val::Null, &Type::INT4) => Box::new(None::<i32>),
                    (Val::Null, &Type::FLOAT8) => Box::new(None::<f64>),
                    (Val::Null, &Type::BYTEA) => Box::new(None::<Vec<u8>>),
                    (Val::Null, _) => Box::new(None::<String>),
                    (Val::Int(i), &Type::INT8) => Box::new(*i),
                    (Val::Int(i), &Type::INT4) => Box::new(i32::try_from(*i).map_err(|_| mismatch(v, ty))?),
                    (Val::Int(i), &Type::FLOAT8) => Box::new(*i as f64),
                    (Val::Int(i), &Type::TEXT | &Type::VARCHAR) => Box::new(i.to_string()),
                    (Val::Real(x), &Type::FLOAT8) => Box::new(*x),
                    (Val::Real(x), &Type::INT8) if x.fract() == 0.0 => Box::new(*x as i64),
                    (Val::Text(t), &Type::TEXT | &Type::VARCHAR | &Type::NAME | &Type::BPCHAR) => Box::new(t.clone()),
                    (Val::Bytes(b), &Type::BYTEA) => Box::new(b.clone()),
                    (Val::Bytes(b), &Type::TEXT) => Box::new(String::from_utf8(b.clone()).map_err(|_| mismatch(v, ty))?),
                    _ => return Err(mismatch(v, ty)),
                })
            })
            .collect()
    }
}

/// A cell whose value the column's type cannot hold.
fn mismatch(v: &Val, ty: &Type) -> StoreError {
    StoreError::Setup(format!("a value {v:?} cannot be copied into a column of type {ty}"))
}

/// The cells of a row, by the types of its columns.
fn vals(row: &Row) -> Result<Vec<Val>> {
    let cell = |i: usize, ty: &Type| -> std::result::Result<Val, postgres::Error> {
        Ok(match *ty {
            Type::INT8 => row.try_get::<_, Option<i64>>(i)?.map_or(Val::Null, Val::Int),
            Type::INT4 => row.try_get::<_, Option<i32>>(i)?.map_or(Val::Null, |x| Val::Int(x.into())),
            Type::INT2 => row.try_get::<_, Option<i16>>(i)?.map_or(Val::Null, |x| Val::Int(x.into())),
            Type::FLOAT8 => row.try_get::<_, Option<f64>>(i)?.map_or(Val::Null, Val::Real),
            Type::FLOAT4 => row.try_get::<_, Option<f32>>(i)?.map_or(Val::Null, |x| Val::Real(x.into())),
            Type::BOOL => row.try_get::<_, Option<bool>>(i)?.map_or(Val::Null, |x| Val::Int(x.into())),
            Type::BYTEA => row.try_get::<_, Option<Vec<u8>>>(i)?.map_or(Val::Null, Val::Bytes),
            _ => row.try_get::<_, Option<String>>(i)?.map_or(Val::Null, Val::Text),
        })
    };
    row.columns().iter().enumerate().map(|(i, c)| cell(i, c.type_()).map_err(sql("reading rows to copy"))).collect()
}

impl super::copy::End for PgEnd<'_> {
    fn by_site(&self) -> bool {
        true
    }

    fn rows(&self, sql_text: &str, params: &[Val]) -> Result<Vec<Vec<Val>>> {
        let s = self.statement(sql_text)?;
        let p = Self::params(&s, params)?;
        let refs: Vec<&(dyn ToSql + Sync)> = p.iter().map(|b| b.as_ref()).collect();
        let rows = self.conn.client.borrow_mut().query(&s, &refs).map_err(sql("reading rows to copy"))?;
        rows.iter().map(vals).collect()
    }

    fn exec(&self, sql_text: &str, params: &[Val]) -> Result<u64> {
        let s = self.statement(sql_text)?;
        let p = Self::params(&s, params)?;
        let refs: Vec<&(dyn ToSql + Sync)> = p.iter().map(|b| b.as_ref()).collect();
        self.conn.client.borrow_mut().execute(&s, &refs).map_err(sql("copying rows"))
    }

    fn batch(&self, sql_text: &str) -> Result<()> {
        self.conn.client.borrow_mut().batch_execute(sql_text).map_err(sql("copying rows"))
    }

    fn columns_sql(&self) -> &'static str {
        "SELECT column_name::text FROM information_schema.columns WHERE table_schema = current_schema() AND table_name = ?1
         ORDER BY ordinal_position"
    }

    fn same(&self, column: &str, n: usize) -> String {
        format!("{column} IS NOT DISTINCT FROM ?{n}")
    }

    fn blob(&self, hash: &str) -> Result<Option<super::copy::Blob<'_>>> {
        let found = self.rows("SELECT size, length(content)::bigint FROM blobs WHERE hash = ?1", &[Val::Text(hash.to_owned())])?;
        let Some([Val::Int(size), Val::Int(stored)]) = found.first().map(Vec::as_slice) else { return Ok(None) };
        let reader = BlobReader { end: self, hash: hash.to_owned(), at: 0, stored: *stored };
        Ok(Some((*size, *stored, Box::new(reader))))
    }

    fn write_blob(&self, hash: &str, size: i64, stored: i64, from: &mut dyn std::io::Read) -> Result<()> {
        if stored == size {
            return self.conn.stream_into_blob(hash, size as u64, from);
        }
        // Kept without its bytes (over the size limit).
        self.conn.exec(
            "storing program bytes",
            "INSERT INTO blobs(hash, size, content) VALUES ($1, $2, '') ON CONFLICT (hash) DO NOTHING",
            &[&hash, &size],
        )?;
        Ok(())
    }

    fn reserve_ids(&self, table: &str, at_least: i64) -> Result<()> {
        self.rows(
            "SELECT setval(pg_get_serial_sequence(?1, 'id'), GREATEST(nextval(pg_get_serial_sequence(?1, 'id')), ?2))",
            &[Val::Text(table.to_owned()), Val::Int(at_least)],
        )?;
        Ok(())
    }

    fn new_id(&self, table: &str, above: i64) -> Result<i64> {
        let row = self.rows("SELECT nextval(pg_get_serial_sequence(?1, 'id'))", &[Val::Text(table.to_owned())])?;
        match row.first().map(Vec::as_slice) {
            // The sequence was set past the source's ids when the copy began.
            Some([Val::Int(i)]) if *i > above => Ok(*i),
            _ => Err(StoreError::Setup(format!("the identity of {table} gave no id above {above}"))),
        }
    }
}

/// A blob's stored bytes read 1 MiB at a time.
struct BlobReader<'a> {
    end: &'a PgEnd<'a>,
    hash: String,
    at: i64,
    stored: i64,
}

impl std::io::Read for BlobReader<'_> {
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<usize> {
        let want = (self.stored - self.at).min(buf.len() as i64).min(1 << 20);
        if want <= 0 {
            return Ok(0);
        }
        let rows = self
            .end
            .rows(
                "SELECT substring(content FROM ?2 FOR ?3) FROM blobs WHERE hash = ?1",
                &[Val::Text(self.hash.clone()), Val::Int(self.at + 1), Val::Int(want)],
            )
            .map_err(std::io::Error::other)?;
        let Some(Val::Bytes(b)) = rows.into_iter().next().and_then(|r| r.into_iter().next()) else {
            return Err(std::io::Error::other(format!("the blob {} went away", self.hash)));
        };
        buf[..b.len()].copy_from_slice(&b);
        self.at += b.len() as i64;
        Ok(b.len())
    }
}

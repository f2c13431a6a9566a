//! One file → one stored revision: read, hash, analyse, pair with the CAM original, diff,
//! record. Synchronous; runs on the daemon's worker thread (and in tests).
//!
//! A revision and everything it enables commit in one transaction: the comparisons of edited
//! programs that were waiting for this original, and the partial-write mark of the revision
//! before it. A kill at any moment leaves all of it or none of it, and [`reconcile`] at start
//! compares whatever an older ncplan left waiting.

use std::io::Read as _;
use std::os::unix::fs::MetadataExt;
use std::path::Path;
use std::time::SystemTime;

use anyhow::{Context, Result};
use sha2::{Digest, Sha256};

use crate::config::{Config, Folder, Role};
use crate::diag::{Code, Diagnostic, DiagnosticJson};
use crate::dialect::Registry;
use crate::diff;
use crate::pairing::{self, Key, Pairing};
use crate::pipeline;
use crate::plan::ProcessPlan;
use crate::sharefile;
use crate::store::{Comparable, Content, NewRevision, Store, Txn};
use crate::text::{Encoding, LineIndex, TextRange};

/// A revision that is the start of the next one, stored at most this many seconds before it,
/// was a partial write.
pub const PARTIAL_WINDOW_S: f64 = 30.0;

/// How many analyses of one content must have ended the process before it is stored without
/// analysis. One unfinished analysis is no evidence against the content: a kill from outside
/// (an operator, a stop that timed out, a power cut) lands on whatever is being analysed, and
/// a revision stored unanalysed is final, so an original would never serve its waiting edits.
/// A content that ends the process again when it is tried again is the cause.
pub const UNFINISHED_ANALYSES: u32 = 2;

/// Why a content may be stored without its analysis.
#[derive(Debug, Clone)]
enum Trial {
    /// Analyses of it this many times began and never finished (the attempt journal).
    Earlier(u32),
    /// A worker's analysis of it ran past the worker bound: stored unanalysed, with this finding.
    Quarantined(String),
}

/// What happened to a file.
#[derive(Debug, PartialEq, Eq)]
pub enum Outcome {
    /// A new revision was stored; with its change count when it was compared.
    Stored {
        /// Revision id.
        revision: i64,
        /// Changes found against the CAM original, if one was found.
        changes: Option<usize>,
        /// Edited programs that were waiting for this original and are now compared.
        compared: usize,
    },
    /// The content equals the latest stored revision.
    Unchanged,
    /// The path is not a regular file (or vanished).
    Gone,
    /// The file changed while it was read, or since it settled: it must settle again.
    Changing,
    /// The path is not read: a link out of the watched folder, a hard link, or not a regular
    /// file (a FIFO, a socket, a device); the reason.
    Refused(String),
}

/// The size and modification time a file had when it was found settled.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Snapshot {
    /// Size in bytes.
    pub size: u64,
    /// Modification time.
    pub mtime: Option<SystemTime>,
}

/// Hex SHA-256.
pub fn sha256_hex(bytes: &[u8]) -> String {
    format!("{:x}", Sha256::digest(bytes))
}

/// Whether the bytes hold no program: nothing, or only blanks and NUL bytes (a truncated save,
/// an aborted or preallocated copy).
pub fn is_blank(bytes: &[u8]) -> bool {
    bytes.iter().all(|&b| b == 0 || b.is_ascii_whitespace())
}

enum Read {
    Bytes(Vec<u8>, std::fs::Metadata),
    /// Over the size limit: its hash, taken in chunks; its bytes are not kept.
    TooLarge(String, std::fs::Metadata),
    Done(Outcome),
}

/// Why a share's file is not read, by what its path leads to: it is not a regular file, or it
/// has other names (hard links), any of which may lie outside the watched folder, like a link
/// out of it.
pub fn refusal_of(meta: &std::fs::Metadata) -> Option<String> {
    if !meta.is_file() {
        return Some(not_regular(sharefile::kind(meta.file_type())));
    }
    (meta.nlink() > 1)
        .then(|| format!("it has {} hard links, and another of its names may lie outside the watched folder; it is not read", meta.nlink()))
}

fn not_regular(what: &str) -> String {
    format!("it is {what}, not a regular file; it is never read")
}

/// Reads a file that lies in the folder whose real path is `root`, and makes sure that what
/// was read is one whole state of it: the same file the path names, unchanged while read,
/// and the state the settle logic saw (`expected`). Only a regular file with one name is
/// read, and its open never blocks ([`sharefile::open`]).
fn read_settled(path: &Path, root: &Path, expected: Option<Snapshot>, limit: u64) -> Result<Read> {
    let opened = match sharefile::open(path) {
        Ok(o) => o,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Read::Done(Outcome::Gone)),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", sharefile::path_text(path))),
    };
    let (file, before) = match opened {
        sharefile::Opened::File(f, m) => (f, m),
        sharefile::Opened::NotRegular(what) => return Ok(Read::Done(Outcome::Refused(not_regular(what)))),
    };
    if let Some(why) = refusal_of(&before) {
        return Ok(Read::Done(Outcome::Refused(why)));
    }
    match std::fs::canonicalize(path) {
        Ok(real) if real.starts_with(root) => {}
        Ok(real) => {
            let why = format!("it leads to {}, outside the watched folder", sharefile::path_text(&real));
            return Ok(Read::Done(Outcome::Refused(why)));
        }
        Err(_) => return Ok(Read::Done(Outcome::Gone)),
    }
    if let Some(exp) = expected
        && (exp.size != before.len() || exp.mtime != before.modified().ok())
    {
        return Ok(Read::Done(Outcome::Changing));
    }
    let (bytes, hash) = if before.len() > limit {
        let mut hasher = Sha256::new();
        std::io::copy(&mut (&file).take(before.len()), &mut hasher)
            .with_context(|| format!("cannot read {}", sharefile::path_text(path)))?;
        (None, Some(format!("{:x}", hasher.finalize())))
    } else {
        let mut bytes = Vec::with_capacity(before.len() as usize);
        (&file)
            .take(limit.saturating_add(1))
            .read_to_end(&mut bytes)
            .with_context(|| format!("cannot read {}", sharefile::path_text(path)))?;
        (Some(bytes), None)
    };
    let after = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Read::Done(Outcome::Gone)),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", sharefile::path_text(path))),
    };
    let same_file = (after.dev(), after.ino()) == (before.dev(), before.ino());
    let read = bytes.as_ref().map_or(before.len(), |b| b.len() as u64);
    if !same_file || after.len() != read || after.len() != before.len() || after.modified().ok() != before.modified().ok() {
        return Ok(Read::Done(Outcome::Changing));
    }
    Ok(match (bytes, hash) {
        (Some(b), _) => Read::Bytes(b, before),
        (None, h) => Read::TooLarge(h.unwrap_or_default(), before),
    })
}

fn finding(code: Code, message: String) -> DiagnosticJson {
    DiagnosticJson::new(&Diagnostic::new(code, TextRange::default(), message), "", &LineIndex::new(""))
}

/// Ingests `path`, which lies in `folder` (whose real path is `root`). `now` is the injected
/// clock's reading; `expected` the state the file settled in, when the caller watched it.
#[allow(clippy::too_many_arguments)]
pub fn ingest(
    path: &Path,
    folder: &Folder,
    root: &Path,
    config: &Config,
    registry: &Registry,
    store: &mut Store,
    now: &str,
    expected: Option<Snapshot>,
) -> Result<Outcome> {
    let (bytes, meta) = match read_settled(path, root, expected, config.max_file_bytes)? {
        Read::Bytes(b, m) => (b, m),
        Read::TooLarge(hash, meta) => return store_too_large(path, folder, config, store, now, &hash, &meta),
        Read::Done(outcome) => return Ok(outcome),
    };
    let hash = sha256_hex(&bytes);
    let path_str = sharefile::path_text(path);
    if store.latest_hash(&path_str)?.as_deref() == Some(hash.as_str()) {
        return Ok(Outcome::Unchanged);
    }
    journaled(path, path, folder, config, registry, store, now, bytes, &hash, &meta)
}

/// [`record`] with the attempt journal around it: a content whose analysis ended the process
/// [`UNFINISHED_ANALYSES`] times is not tried again. The journal covers the content's own
/// analysis only: `record` closes it as soon as the analysis returns, before it waits for the
/// store and compares other programs, so a kill there never counts against this content. Any
/// other end closes it here.
#[allow(clippy::too_many_arguments)]
fn journaled(
    path: &Path,
    stored_as: &Path,
    folder: &Folder,
    config: &Config,
    registry: &Registry,
    store: &mut Store,
    now: &str,
    bytes: Vec<u8>,
    hash: &str,
    meta: &std::fs::Metadata,
) -> Result<Outcome> {
    let stored_str = sharefile::path_text(stored_as);
    let earlier = store.begin_attempt(hash, &stored_str, now)?;
    let result = record(path, stored_as, folder, config, registry, store, now, bytes, hash, meta, Trial::Earlier(earlier));
    if !matches!(result, Ok(Outcome::Stored { .. })) {
        store.finish_attempt(hash, &stored_str)?;
    }
    result
}

/// Imports `file`, a copy of the program at `stored_as` (a share's file, from an archive or
/// a dated backup), as a revision seen at `seen_at` (its file time). Content the program
/// already has as any revision is skipped, so an import that was killed resumes.
#[allow(clippy::too_many_arguments)]
pub fn import_file(
    file: &Path,
    stored_as: &Path,
    folder: &Folder,
    config: &Config,
    registry: &Registry,
    store: &mut Store,
    seen_at: &str,
) -> Result<Outcome> {
    // A folder of backups is read like a share, but hard links are no fault there (snapshot
    // tools link the files that did not change).
    let (file_handle, meta) = match sharefile::open(file).with_context(|| format!("cannot read {}", sharefile::path_text(file)))? {
        sharefile::Opened::File(f, m) => (f, m),
        sharefile::Opened::NotRegular(what) => return Ok(Outcome::Refused(not_regular(what))),
    };
    let stored_str = sharefile::path_text(stored_as);
    if meta.len() > config.max_file_bytes {
        let mut hasher = Sha256::new();
        std::io::copy(&mut (&file_handle).take(meta.len()), &mut hasher)
            .with_context(|| format!("cannot read {}", sharefile::path_text(file)))?;
        return store_too_large(stored_as, folder, config, store, seen_at, &format!("{:x}", hasher.finalize()), &meta);
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    (&file_handle)
        .take(config.max_file_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .with_context(|| format!("cannot read {}", sharefile::path_text(file)))?;
    let hash = sha256_hex(&bytes);
    if store.has_revision(&stored_str, &hash)? {
        return Ok(Outcome::Unchanged);
    }
    journaled(file, stored_as, folder, config, registry, store, seen_at, bytes, &hash, &meta)
}

/// Records a file over the size limit (`max_file_bytes`) as a revision with its hash
/// (`hash`, taken in chunks) and size, but not its bytes, and a finding that says so: the
/// limit bounds what is stored, not only what is analysed (a sparse file of hundreds of
/// megabytes costs a row). It is analysed by no one.
fn store_too_large(
    stored_as: &Path,
    folder: &Folder,
    config: &Config,
    store: &mut Store,
    now: &str,
    hash: &str,
    meta: &std::fs::Metadata,
) -> Result<Outcome> {
    let path_str = sharefile::path_text(stored_as);
    if store.latest_hash(&path_str)?.as_deref() == Some(hash) {
        return Ok(Outcome::Unchanged);
    }
    let d = pipeline::too_large(meta.len(), config.max_file_bytes);
    let diagnostics = vec![
        DiagnosticJson::new(&d, "", &LineIndex::new("")),
        finding(
            Code::TooLarge,
            format!("over the size limit of {} bytes: only its size and hash are kept, not its bytes", config.max_file_bytes),
        ),
    ];
    let file_name = stored_as.file_name().map(sharefile::os_text).unwrap_or_default();
    let keys = pairing::keys(config.pattern.as_ref(), &file_name, None);
    let stem = pairing::file_stem(&file_name);
    let folder_text = sharefile::path_text(&folder.path);
    let tx = store.begin()?;
    let revision = tx.insert_revision(&NewRevision {
        path: &path_str,
        role: folder.role.as_str(),
        machine: (folder.role == Role::Machine).then_some((folder.name.as_str(), folder.dialect.as_str(), folder_text.as_str())),
        name: &stem,
        keys: &keys,
        stem: &stem,
        dialect: &folder.dialect,
        content: Content::Absent { size: meta.len() },
        hash,
        mtime_ns: mtime_ns(meta),
        seen_at: now,
        encoding: "unknown",
        status: "too_large",
        plan_json: None,
        plan_complete: false,
        counts: (0, 0),
        diagnostics: &diagnostics,
    })?;
    tx.commit()?;
    Ok(Outcome::Stored { revision, changes: None, compared: 0 })
}

fn mtime_ns(meta: &std::fs::Metadata) -> Option<i64> {
    meta.modified().ok().and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok()).map(|d| d.as_nanos() as i64)
}

/// Why `bytes` are stored without analysis, if they are: a quarantine, or analyses of them
/// that ended the process [`UNFINISHED_ANALYSES`] times and a trial in a process of its own
/// that ended too.
fn unanalysed(trial: &Trial, config: &Config, bytes: &[u8], dialect: &str, path: &Path, hash: &str) -> Option<String> {
    match trial {
        Trial::Quarantined(message) => Some(message.clone()),
        Trial::Earlier(earlier) if *earlier >= UNFINISHED_ANALYSES && ends_a_process(config, bytes, dialect, path) => {
            tracing::error!(path = %sharefile::path_text(path), hash, "An earlier analysis of this content never finished; storing it without analysis.");
            Some(format!(
                "analysing this content ended the process {earlier} time(s) before (out of memory, a memory limit or a crash); stored, not analysed"
            ))
        }
        Trial::Earlier(_) => None,
    }
}

/// Stores the file a worker's analysis got stuck on (past the worker bound, `bound_s`)
/// without analysis, with a finding that says so, when it still holds the state it was handed
/// out in (`expected`): the same content is then never tried again (an edit is a new content
/// and is analysed). A file that changed since is left to settle again.
#[allow(clippy::too_many_arguments)]
pub fn quarantine(
    path: &Path,
    folder: &Folder,
    root: &Path,
    config: &Config,
    registry: &Registry,
    store: &mut Store,
    now: &str,
    expected: Snapshot,
    bound_s: u64,
) -> Result<Outcome> {
    let (bytes, meta) = match read_settled(path, root, Some(expected), config.max_file_bytes)? {
        Read::Bytes(b, m) => (b, m),
        Read::TooLarge(hash, meta) => return store_too_large(path, folder, config, store, now, &hash, &meta),
        Read::Done(outcome) => return Ok(outcome),
    };
    let hash = sha256_hex(&bytes);
    if store.latest_hash(&sharefile::path_text(path))?.as_deref() == Some(hash.as_str()) {
        return Ok(Outcome::Unchanged);
    }
    let message = format!(
        "the analysis did not finish within the worker bound of {bound_s} s ([daemon] worker_timeout_s); the worker was replaced and the content is stored, not analysed"
    );
    record(path, path, folder, config, registry, store, now, bytes, &hash, &meta, Trial::Quarantined(message))
}

/// Analyses the bytes (unless analyses of them ended the process [`UNFINISHED_ANALYSES`] times) and
/// records the revision with everything it enables, in one transaction.
#[allow(clippy::too_many_arguments)]
fn record(
    path: &Path,
    stored_as: &Path,
    folder: &Folder,
    config: &Config,
    registry: &Registry,
    store: &mut Store,
    now: &str,
    bytes: Vec<u8>,
    hash: &str,
    meta: &std::fs::Metadata,
    trial: Trial,
) -> Result<Outcome> {
    let path_str = sharefile::path_text(stored_as);
    // A folder with `dialect = "auto"` has each program's dialect told from its text.
    let dialect_name = if folder.dialect == crate::config::AUTO_DIALECT {
        // Read with the programs beside it, as `ncplan check` reads it.
        let beside = crate::config::DirPrograms::beside(&config.profile, path, config.max_file_bytes);
        let s = pipeline::sniff_in(registry, &bytes, path, &beside);
        tracing::info!(path = %sharefile::path_text(path), dialect = %s.dialect, sure = s.confidence.as_str(), evidence = %s.evidence.join(", "), "Dialect told from the program.");
        s.dialect
    } else {
        folder.dialect.clone()
    };
    let reader = Reader { config, registry };
    let blank = is_blank(&bytes);
    let mut calls: Vec<String> = Vec::new();
    let (analysis, diagnostics, status) = if blank {
        let what = if bytes.is_empty() { "empty".to_owned() } else { format!("{} bytes of blanks or NUL bytes", bytes.len()) };
        let message = format!("the file holds no program ({what}): a truncated save or an aborted copy; stored, never compared");
        (None, vec![finding(Code::EmptyFile, message)], "empty")
    } else if let Some(message) = unanalysed(&trial, config, &bytes, &dialect_name, path, hash) {
        (None, vec![finding(Code::AnalysisFailed, message)], "failed")
    } else {
        let (a, called) = reader.analyse(path, folder, &dialect_name, &bytes)?;
        calls = called;
        // The analysis finished: what follows (waiting for the store, comparing the edits that
        // waited for this original) is no fault of this content's if the process ends there.
        store.finish_attempt(hash, &path_str)?;
        let idx = LineIndex::new(&a.source.text);
        let ds = a.diagnostics.iter().map(|d| DiagnosticJson::new(d, &a.source.text, &idx)).collect();
        (Some(a), ds, "analysed")
    };
    let program = analysis.as_ref().and_then(|a| a.plan.program.clone());
    let file_name = path.file_name().map(sharefile::os_text).unwrap_or_default();
    let keys = pairing::keys(config.pattern.as_ref(), &file_name, program.as_deref());
    let mut analysis = analysis;
    let summary = analysis.as_mut().map(|a| summary_json(&mut a.plan)).transpose()?;
    let encoding = match analysis.as_ref().map(|a| a.source.encoding) {
        Some(Encoding::Utf8) => "utf-8",
        Some(Encoding::Windows1252) => "windows-1252",
        Some(Encoding::Binary) => "binary",
        None => "unknown",
    };
    let folder_text = sharefile::path_text(&folder.path);
    let machine = (folder.role == Role::Machine).then_some((folder.name.as_str(), dialect_name.as_str(), folder_text.as_str()));
    let stem = pairing::file_stem(&file_name);
    let name = program.clone().unwrap_or_else(|| stem.clone());
    // Only the plan is needed from here on: the decoded text goes.
    let plan: Option<ProcessPlan> = analysis.map(|a| a.plan);

    let tx = store.begin()?;
    let previous = tx.latest(&path_str, now)?;
    if previous.as_ref().is_some_and(|p| p.hash == hash) {
        return Ok(Outcome::Unchanged);
    }
    let revision = tx.insert_revision(&NewRevision {
        path: &path_str,
        role: folder.role.as_str(),
        machine,
        name: &name,
        keys: &keys,
        stem: &stem,
        dialect: &dialect_name,
        content: Content::Bytes(&bytes),
        hash,
        mtime_ns: mtime_ns(meta),
        seen_at: now,
        encoding,
        status,
        plan_json: summary.as_deref(),
        plan_complete: false,
        counts: plan.as_ref().map_or((0, 0), |p| (p.workingsteps.len(), p.tools.len())),
        diagnostics: &diagnostics,
    })?;
    tx.add_calls(revision, &calls)?;
    // The revision before, if it is this one's start and came seconds earlier, was a partial write.
    let mut recompare = Vec::new();
    if let Some(p) = &previous
        && p.size < bytes.len() as u64
        && p.age_s <= PARTIAL_WINDOW_S
        && tx.blob(&p.hash)?.is_some_and(|old| bytes.starts_with(&old))
    {
        tx.mark_partial(p.id, revision, now)?;
        let message = format!(
            "a partial write: the first {} bytes of revision {revision}, stored {:.1} s later; kept out of the change report",
            p.size, p.age_s
        );
        tx.add_finding(p.id, &finding(Code::PartialWrite, message))?;
        tracing::info!(path = %sharefile::path_text(path), partial = p.id, complete = revision, "The previous revision was a partial write.");
        // Edited programs compared with a partial original are compared again.
        recompare = tx.compared_with(p.id)?;
    }
    // The bytes are stored: only the plan is needed for the comparisons.
    drop(bytes);
    let mut changes = None;
    let mut compared = 0;
    if let Some(plan) = &plan {
        let known = Known { revision, plan };
        match folder.role {
            Role::Machine => changes = settle(&tx, &reader, revision, &pair(&tx, &keys)?, known, now)?,
            Role::Cam => {
                // Edited programs that arrived before their original are compared now.
                let mut waiting: Vec<Comparable> = recompare;
                for key in &keys {
                    waiting.extend(tx.uncompared(Some(&key.value))?);
                }
                waiting.sort_by_key(|w| w.revision);
                waiting.dedup_by_key(|w| w.revision);
                for w in &waiting {
                    if settle(&tx, &reader, w.revision, &pair(&tx, &w.keys)?, known, now)?.is_some() {
                        compared += 1;
                    }
                }
            }
        }
    }
    // A changed subprogram: the programs that call it are compared again.
    if plan.is_some() {
        compared += recompare_callers(&tx, &reader, (stored_as, folder.role), &stem, revision, now)?;
    }
    tx.commit()?;
    Ok(Outcome::Stored { revision, changes, compared })
}

/// The stored form of a plan: everything but the toolpaths and the holes of each
/// workingstep, which the immutable program rebuilds (`Reader::plan`), so that a revision
/// costs about its program's bytes.
pub fn summary_json(plan: &mut ProcessPlan) -> Result<String> {
    let taken: Vec<_> = plan.workingsteps.iter_mut().map(|w| (std::mem::take(&mut w.toolpath), std::mem::take(&mut w.holes))).collect();
    let json = serde_json::to_string(plan);
    for (w, (toolpath, holes)) in plan.workingsteps.iter_mut().zip(taken) {
        (w.toolpath, w.holes) = (toolpath, holes);
    }
    Ok(json?)
}

/// Reads programs as the daemon does: in their folder's dialect, with the configured
/// profile, called programs beside them. Rebuilds stored plans from their bytes.
pub struct Reader<'a> {
    /// The configuration.
    pub config: &'a Config,
    /// The dialects.
    pub registry: &'a Registry,
}

impl Reader<'_> {
    /// Analyses `bytes` of `path` in `folder` read in `dialect`; the canonical ops are not kept.
    /// Also gives the programs the run called from outside its text, as lower-case file stems.
    pub fn analyse(&self, path: &Path, folder: &Folder, dialect: &str, bytes: &[u8]) -> Result<(pipeline::Analysis, Vec<String>)> {
        let d = folder.dialect_for(self.registry.get(dialect).with_context(|| format!("unknown dialect `{dialect}`"))?);
        let mut profile = self.profile(path, folder, &d, bytes);
        let recording = profile.programs.take().map(|inner| std::sync::Arc::new(Recording { inner, asked: Default::default() }));
        profile.programs = recording.clone().map(|r| r as std::sync::Arc<dyn crate::interp::ProgramSource + Send + Sync>);
        let a = pipeline::analyze_plan(bytes, &d, &profile);
        let called = recording.map(|r| r.asked.lock().map(|s| s.iter().cloned().collect()).unwrap_or_default()).unwrap_or_default();
        Ok((a, called))
    }

    /// The profile a program of `folder` is read with: called programs from the configured
    /// directory, else from beside it; main or called as the folder says, else as its file
    /// name says (`.SPF`), else as its form tells. In a folder whose programs' dialect is told
    /// from their text, a dialect guessed from weak evidence is read as `ncplan check` reads it
    /// ([`crate::interp::Profile::guessed`]).
    fn profile(&self, path: &Path, folder: &Folder, dialect: &crate::dialect::Dialect, bytes: &[u8]) -> crate::interp::Profile {
        let mut profile = crate::config::DirPrograms::beside(&self.config.profile, path, self.config.max_file_bytes);
        // Without a configured program directory: beside the program, then in the CAM folders.
        if self.config.profile.programs.is_none() {
            let beside = path.parent().map(Path::to_path_buf).unwrap_or_default();
            let mut sources: Vec<std::sync::Arc<dyn crate::interp::ProgramSource + Send + Sync>> = Vec::new();
            let dirs = std::iter::once(beside.clone())
                .chain(self.config.folders.iter().filter(|f| f.role == Role::Cam && f.path != beside).map(|f| f.path.clone()));
            for dir in dirs {
                // Beside the program in a watched folder, its subfolders too (the daemon's folder
                // holds them); a CAM folder's own files only.
                let subfolders = dir == beside;
                sources.push(std::sync::Arc::new(crate::config::DirPrograms { dir, max_bytes: self.config.max_file_bytes, subfolders }));
            }
            profile.programs = Some(std::sync::Arc::new(crate::config::FirstFound(sources)));
        }
        // The machine's configuration beside the program (a LinuxCNC INI in its folder or
        // above, within the watched folder): remapped codes, HAL pins, switchable kinematics.
        if let Some(machine) = crate::machine_config::find_within(path, &folder.path) {
            profile = crate::machine_config::apply(&profile, &machine, self.config.max_file_bytes);
        }
        profile.role = crate::interp::role_for(folder.program_role, path, dialect);
        profile.tools.extend(folder.tools.iter().map(|(n, t)| (*n, t.clone())));
        profile.guessed = self.guessed_in(folder, path, &dialect.name, bytes);
        profile
    }

    /// Whether the program `bytes` at the stored `path`, read in `dialect`, is read on a
    /// guessed dialect: its folder tells each program's dialect from its text (`auto`), and
    /// that evidence is weak ([`crate::dialect::sniff::Sniffed::guessed`]). The web's
    /// translation reads it so.
    pub fn guessed(&self, path: &str, dialect: &str, bytes: &[u8]) -> bool {
        let path = &sharefile::text_path(path);
        self.config.folder_at(path).is_some_and(|i| self.guessed_in(&self.config.folders[i], path, dialect, bytes))
    }

    /// [`Reader::guessed`] in `folder`: the sniff reads the programs beside, as ingest's does.
    fn guessed_in(&self, folder: &Folder, path: &Path, dialect: &str, bytes: &[u8]) -> bool {
        folder.dialect == crate::config::AUTO_DIALECT && {
            let beside = crate::config::DirPrograms::beside(&self.config.profile, path, self.config.max_file_bytes);
            let s = pipeline::sniff_in(self.registry, bytes, path, &beside);
            s.guessed() && s.dialect == dialect
        }
    }
}

impl Reader<'_> {
    /// A stored revision as the diff reads it: its whole plan, its text and its dialect.
    /// `None` when it was never analysed.
    pub fn program(&self, tx: &Txn<'_>, revision: i64, known: Option<&ProcessPlan>) -> Result<Option<Stored>> {
        let Some(src) = tx.source(revision)? else { return Ok(None) };
        let Some(bytes) = tx.content(revision)? else { return Ok(None) };
        let dialect = self.dialect_of(&src.path, &src.dialect)?;
        let plan = match known {
            Some(p) => p.clone(),
            None => match self.rebuild(src)? {
                Some(p) => p,
                None => return Ok(None),
            },
        };
        let faults = stored_faults(&tx.findings(revision)?);
        Ok(Some(Stored { plan, text: crate::text::decode_owned(bytes).0.text, dialect, faults }))
    }

    /// The dialect a stored program of `path` is read in: its folder's, with the folder's
    /// overrides; a folder no longer configured: the stored one.
    pub fn dialect_of(&self, path: &str, dialect: &str) -> Result<std::sync::Arc<crate::dialect::Dialect>> {
        let base = self.registry.get(dialect).with_context(|| format!("unknown dialect `{dialect}`"))?;
        Ok(match self.config.folder_at(&sharefile::text_path(path)) {
            Some(i) => self.config.folders[i].dialect_for(base),
            None => base,
        })
    }

    /// The whole plan of a stored revision: the stored one when it is complete (older
    /// revisions), else rebuilt from its bytes. `None` when it was never analysed.
    pub fn plan(&self, tx: &Txn<'_>, revision: i64) -> Result<Option<ProcessPlan>> {
        match tx.source(revision)? {
            Some(src) => self.rebuild(src),
            None => Ok(None),
        }
    }

    /// The whole plan of a stored program: its stored plan when complete, else its bytes read again.
    pub fn rebuild(&self, src: crate::store::StoredSource) -> Result<Option<ProcessPlan>> {
        match (&src.plan, src.bytes) {
            (Some((json, true)), _) => Ok(Some(serde_json::from_str(json).context("stored plan is unreadable")?)),
            (Some(_), Some(bytes)) => Ok(Some(self.reanalyse(&src.path, &src.dialect, bytes)?.plan)),
            _ => Ok(None),
        }
    }

    /// Analyses a stored program's bytes again, with today's dictionary and engine, as the
    /// folder it lies in reads it (a folder no longer configured: its stored dialect, no overrides).
    pub fn reanalyse(&self, path: &str, dialect: &str, bytes: Vec<u8>) -> Result<pipeline::Analysis> {
        self.reanalyse_on(path, dialect, bytes, pipeline::MachineShown::default())
    }

    /// [`Reader::reanalyse`] on the machine another revision showed (`pipeline::analyze_pair`).
    fn reanalyse_on(&self, path: &str, dialect: &str, bytes: Vec<u8>, machine: pipeline::MachineShown) -> Result<pipeline::Analysis> {
        let path = &sharefile::text_path(path);
        let folder = match self.config.folder_at(path) {
            Some(i) => self.config.folders[i].clone(),
            None => Folder {
                role: Role::Machine,
                name: String::new(),
                path: path.parent().map(Path::to_path_buf).unwrap_or_default(),
                dialect: dialect.to_owned(),
                poll: false,
                poll_ms: 0,
                decimal_input: None,
                x_diameter: None,
                swivel_axes: None,
                tool_word_changes: None,
                program_role: crate::interp::ProgramRole::Auto,
                limits: Default::default(),
                tools: Default::default(),
            },
        };
        let d = folder.dialect_for(self.registry.get(dialect).with_context(|| format!("unknown dialect `{dialect}`"))?);
        let profile = self.profile(path, &folder, &d, &bytes);
        Ok(pipeline::analyze_plan_owned(bytes, &d, &machine.on(&profile)))
    }

    /// Two stored revisions to compare, read on one machine as `ncplan diff` reads them
    /// (`pipeline::analyze_pair`): where one's findings show what the machine is (X words as
    /// radii, inch at power-on, calculator-type input) and the other's do not, the other is read again on it.
    fn on_one_machine(&self, tx: &Txn<'_>, before: (i64, Stored), after: (i64, Stored)) -> Result<(Stored, Stored)> {
        let shown = |id: i64| -> Result<pipeline::MachineShown> {
            Ok(pipeline::MachineShown::from_codes(tx.findings(id)?.iter().map(|f| f.code.as_str())))
        };
        let (in_before, in_after) = (shown(before.0)?, shown(after.0)?);
        let both = in_before.union(in_after);
        let again = |(id, mut stored): (i64, Stored), shown: pipeline::MachineShown| -> Result<Stored> {
            // The statements compared as the machine reads their words.
            if let std::borrow::Cow::Owned(d) = both.reads(&stored.dialect) {
                stored.dialect = std::sync::Arc::new(d);
            }
            if shown == both {
                return Ok(stored);
            }
            let (Some(src), Some(bytes)) = (tx.source(id)?, tx.content(id)?) else { return Ok(stored) };
            let a = self.reanalyse_on(&src.path, &src.dialect, bytes, both)?;
            let faults = diff::verdict::faults(&a.source.text, &a.diagnostics);
            Ok(Stored { plan: a.plan, text: a.source.text, dialect: stored.dialect, faults })
        };
        Ok((again(before, in_before)?, again(after, in_after)?))
    }
}

/// The longest a suspect content's trial in a process of its own may take.
const PROBE_LIMIT: std::time::Duration = std::time::Duration::from_secs(120);

/// Whether reading `bytes` ends a process: a child `ncplan plan` reads a private copy (in the
/// temporary directory, never a watched folder) and dies by a signal (a crash, a memory
/// limit) or runs past [`PROBE_LIMIT`]. Analyses this daemon began and never finished are no
/// proof: kills from outside land on whatever is being analysed, and after a restart on the
/// same content again. When no trial can be made, the unfinished analyses decide.
fn ends_a_process(config: &Config, bytes: &[u8], dialect: &str, path: &Path) -> bool {
    let exe = match config.probe_exe.clone().map_or_else(std::env::current_exe, Ok) {
        Ok(e) => e,
        Err(_) => return true,
    };
    let ext = path.extension().map(|e| e.to_string_lossy().into_owned()).unwrap_or_default();
    let copy = std::env::temp_dir().join(format!("ncplan-trial-{}-{}.{ext}", std::process::id(), &sha256_hex(bytes)[..16]));
    if std::fs::write(&copy, bytes).is_err() {
        return true;
    }
    let child = std::process::Command::new(&exe)
        .args(["plan", "-d", dialect])
        .arg(&copy)
        .stdin(std::process::Stdio::null())
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn();
    let verdict = match child {
        Err(_) => true,
        Ok(mut child) => {
            let started = std::time::Instant::now();
            loop {
                match child.try_wait() {
                    Ok(Some(status)) => break status.code().is_none(),
                    Ok(None) if started.elapsed() < PROBE_LIMIT => std::thread::sleep(std::time::Duration::from_millis(20)),
                    _ => {
                        let _ = child.kill();
                        let _ = child.wait();
                        break true;
                    }
                }
            }
        }
    };
    let _ = std::fs::remove_file(&copy);
    tracing::info!(path = %sharefile::path_text(path), ends_a_process = verdict, "A content whose analyses were cut short was tried in a process of its own.");
    verdict
}

/// A program source that notes the names asked of it, as the file stems they may mean.
struct Recording {
    inner: std::sync::Arc<dyn crate::interp::ProgramSource + Send + Sync>,
    asked: std::sync::Mutex<std::collections::BTreeSet<String>>,
}

impl crate::interp::ProgramSource for Recording {
    fn load(&self, name: &str) -> Option<String> {
        if let Ok(mut asked) = self.asked.lock() {
            asked.extend(crate::config::program_file_stems(name).into_iter().map(|s| s.to_lowercase()));
        }
        self.inner.load(name)
    }
}

/// The programs that call the program stored as `revision` under `stem` (a changed
/// subprogram at `path`), and were compared before, compared again with it, naming it as the
/// cause: those beside it, or every caller when it is a CAM original's (the originals read
/// their subprograms from there).
fn recompare_callers(tx: &Txn<'_>, reader: &Reader<'_>, at: (&Path, Role), stem: &str, revision: i64, now: &str) -> Result<usize> {
    let mut n = 0;
    for caller in tx.callers(&stem.to_lowercase())? {
        if caller == revision {
            continue;
        }
        let Some((original, rule)) = tx.comparison_of(caller)? else { continue };
        let Some(src) = tx.source(caller)? else { continue };
        if at.1 != Role::Cam && sharefile::text_path(&src.path).parent() != at.0.parent() {
            continue;
        }
        let Some(bytes) = tx.content(caller)? else { continue };
        // Read again as today: its called programs from where they lie now.
        let a = reader.reanalyse(&src.path, &src.dialect, bytes)?;
        let d = reader.dialect_of(&src.path, &src.dialect)?;
        let Some(op) = reader.program(tx, original, None)? else { continue };
        let faults = diff::verdict::faults(&a.source.text, &a.diagnostics);
        let edited = Stored { plan: a.plan, text: a.source.text, dialect: d, faults };
        let (op, edited) = reader.on_one_machine(tx, (original, op), (caller, edited))?;
        let changes = op.compare(edited.program(), &edited.faults);
        let base = rule.split("; recomputed:").next().unwrap_or_default();
        let rule = format!("{base}; recomputed: the called program {stem} changed (revision {revision})");
        tx.record_comparison(caller, original, &rule, &changes, now)?;
        tracing::info!(caller, called = stem, revision, "A program that calls a changed program was compared again.");
        n += 1;
    }
    Ok(n)
}

/// A stored program as the diff reads it.
pub struct Stored {
    /// Its whole plan.
    pub plan: ProcessPlan,
    /// Its decoded text.
    pub text: String,
    /// The dialect it is read in.
    pub dialect: std::sync::Arc<crate::dialect::Dialect>,
    /// The errors its analysis found, as stored: what the control stops at, which a
    /// comparison tells as broken or fixed.
    pub faults: Vec<diff::statement::Fault>,
}

impl Stored {
    /// The program for [`diff::compare`].
    pub fn program(&self) -> diff::Program<'_> {
        diff::Program { plan: &self.plan, text: &self.text, dialect: &self.dialect }
    }

    /// The changes from this program to `edited` (with the errors its analysis found), through
    /// the same door as `ncplan diff`: what the edit breaks or fixes from both analyses' errors.
    pub fn compare(&self, edited: diff::Program<'_>, edited_faults: &[diff::statement::Fault]) -> Vec<diff::Change> {
        diff::compare_with_findings(self.program(), edited, (&self.faults, edited_faults))
    }
}

/// The errors among a revision's stored findings, as the diff reads them (and the values left
/// unknown, and a file of subroutine definitions only, see `diff::verdict::faults`); the
/// findings the daemon adds of its own (a partial write, an ambiguous pairing) are no
/// program's errors. The same faults as the diff keeps from a fresh analysis, so a comparison
/// against a stored revision tells what one of two fresh ones tells.
fn stored_faults(findings: &[crate::store::StoredFinding]) -> Vec<diff::statement::Fault> {
    let kept = |code: &str| code == Code::UnknownValue.as_str() || code == Code::Library.as_str();
    findings
        .iter()
        .filter(|f| (f.severity == "error" || kept(&f.code)) && f.line > 0)
        .filter_map(|f| {
            let code = *Code::ALL.iter().find(|c| c.as_str() == f.code)?;
            Some(diff::statement::Fault { code, line: u32::try_from(f.line).ok()?, message: f.message.clone() })
        })
        .collect()
}

/// A plan at hand, so that it need not be read back from the store.
#[derive(Clone, Copy)]
struct Known<'a> {
    revision: i64,
    plan: &'a ProcessPlan,
}

/// Pairs the machine revision `revision` (with the program keys `keys`) with its original
/// and records the comparison, or the ambiguity. Returns the number of changes when compared.
fn settle(tx: &Txn<'_>, reader: &Reader<'_>, revision: i64, pairing: &Pairing, known: Known<'_>, now: &str) -> Result<Option<usize>> {
    match pairing {
        Pairing::Unpaired => Ok(None),
        Pairing::Ambiguous { .. } => {
            let message = pairing.message().unwrap_or_default();
            tx.add_finding(revision, &finding(Code::PairingAmbiguous, message))?;
            Ok(None)
        }
        Pairing::Paired { revision: original, rule, .. } => {
            let original = *original;
            let load = |id: i64| reader.program(tx, id, (id == known.revision).then_some(known.plan));
            let (Some(before), Some(after)) = (load(original)?, load(revision)?) else { return Ok(None) };
            let (before, after) = reader.on_one_machine(tx, (original, before), (revision, after))?;
            let changes = before.compare(after.program(), &after.faults);
            tx.record_comparison(revision, original, rule, &changes, now)?;
            Ok(Some(changes.len()))
        }
    }
}

/// The original a program with `keys` is paired with, among the stored CAM originals.
fn pair(tx: &Txn<'_>, keys: &[Key]) -> Result<Pairing> {
    Ok(pairing::choose(keys, |k| tx.originals(k))?)
}

/// Compares every usable machine revision that has no comparison yet but whose original is
/// stored (an older ncplan, killed between the two, left such). Returns how many it compared.
pub fn reconcile(store: &mut Store, reader: &Reader<'_>, now: &str) -> Result<usize> {
    let tx = store.begin()?;
    let mut compared = 0;
    for w in tx.uncompared(None)? {
        // Only those an original is stored for are rebuilt.
        let pairing = pair(&tx, &w.keys)?;
        if !matches!(pairing, Pairing::Paired { .. }) {
            continue;
        }
        let Some(plan) = reader.plan(&tx, w.revision)? else { continue };
        if settle(&tx, reader, w.revision, &pairing, Known { revision: w.revision, plan: &plan }, now)?.is_some() {
            compared += 1;
        }
    }
    tx.commit()?;
    Ok(compared)
}

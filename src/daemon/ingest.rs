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
use crate::store::{Comparable, NewRevision, Store, Txn};
use crate::text::{Encoding, LineIndex, TextRange};

/// A revision that is the start of the next one, stored at most this many seconds before it,
/// was a partial write.
pub const PARTIAL_WINDOW_S: f64 = 30.0;

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
    /// The path leads out of the watched folder (a symbolic link); it is not read.
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
    use std::fmt::Write as _;
    let digest = Sha256::digest(bytes);
    let mut s = String::with_capacity(64);
    for b in digest {
        let _ = write!(s, "{b:02x}");
    }
    s
}

/// Whether the bytes hold no program: nothing, or only blanks and NUL bytes (a truncated save,
/// an aborted or preallocated copy).
pub fn is_blank(bytes: &[u8]) -> bool {
    bytes.iter().all(|&b| b == 0 || b.is_ascii_whitespace())
}

enum Read {
    Bytes(Vec<u8>, std::fs::Metadata),
    Done(Outcome),
}

/// Reads a file that lies in the folder whose real path is `root`, and makes sure that what
/// was read is one whole state of it: the same file the path names, unchanged while read,
/// and the state the settle logic saw (`expected`).
fn read_settled(path: &Path, root: &Path, expected: Option<Snapshot>) -> Result<Read> {
    let file = match std::fs::File::open(path) {
        Ok(f) => f,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Read::Done(Outcome::Gone)),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    let before = file.metadata().with_context(|| format!("cannot read {}", path.display()))?;
    if !before.is_file() {
        return Ok(Read::Done(Outcome::Gone));
    }
    match std::fs::canonicalize(path) {
        Ok(real) if real.starts_with(root) => {}
        Ok(real) => return Ok(Read::Done(Outcome::Refused(format!("it leads to {}, outside the watched folder", real.display())))),
        Err(_) => return Ok(Read::Done(Outcome::Gone)),
    }
    if let Some(exp) = expected
        && (exp.size != before.len() || exp.mtime != before.modified().ok())
    {
        return Ok(Read::Done(Outcome::Changing));
    }
    let mut bytes = Vec::with_capacity(before.len() as usize);
    (&file).read_to_end(&mut bytes).with_context(|| format!("cannot read {}", path.display()))?;
    let after = match std::fs::metadata(path) {
        Ok(m) => m,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Read::Done(Outcome::Gone)),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    let same_file = (after.dev(), after.ino()) == (before.dev(), before.ino());
    if !same_file || after.len() != bytes.len() as u64 || after.modified().ok() != before.modified().ok() {
        return Ok(Read::Done(Outcome::Changing));
    }
    Ok(Read::Bytes(bytes, before))
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
    let (bytes, meta) = match read_settled(path, root, expected)? {
        Read::Bytes(b, m) => (b, m),
        Read::Done(outcome) => return Ok(outcome),
    };
    let hash = sha256_hex(&bytes);
    let path_str = path.to_string_lossy().into_owned();
    if store.latest_hash(&path_str)?.as_deref() == Some(hash.as_str()) {
        return Ok(Outcome::Unchanged);
    }
    // A folder with `dialect = "auto"` has each program's dialect told from its text.
    let dialect_name = if folder.dialect == crate::config::AUTO_DIALECT {
        let s = pipeline::sniff(registry, &bytes, path);
        tracing::info!(path = %path.display(), dialect = %s.dialect, sure = s.confidence.as_str(), evidence = %s.evidence.join(", "), "Dialect told from the program.");
        s.dialect
    } else {
        folder.dialect.clone()
    };
    let dialect = folder.dialect_for(registry.get(&dialect_name).with_context(|| format!("unknown dialect `{dialect_name}`"))?);
    let mtime_ns = meta.modified().ok().and_then(|t| t.duration_since(std::time::UNIX_EPOCH).ok()).map(|d| d.as_nanos() as i64);
    let too_large = bytes.len() as u64 > config.max_file_bytes;
    let blank = is_blank(&bytes);
    let (analysis, diagnostics) = if too_large {
        let d = pipeline::too_large(bytes.len() as u64, config.max_file_bytes);
        (None, vec![DiagnosticJson::new(&d, "", &LineIndex::new(""))])
    } else if blank {
        let what = if bytes.is_empty() { "empty".to_owned() } else { format!("{} bytes of blanks or NUL bytes", bytes.len()) };
        let message = format!("the file holds no program ({what}): a truncated save or an aborted copy; stored, never compared");
        (None, vec![finding(Code::EmptyFile, message)])
    } else {
        // Subprograms come from the configured directory, else from beside the program.
        let profile = crate::config::DirPrograms::beside(&config.profile, path, config.max_file_bytes);
        let a = pipeline::analyze(&bytes, &dialect, &profile);
        let idx = LineIndex::new(&a.source.text);
        let ds = a.diagnostics.iter().map(|d| DiagnosticJson::new(d, &a.source.text, &idx)).collect();
        (Some(a), ds)
    };
    let program = analysis.as_ref().and_then(|a| a.plan.program.clone());
    let file_name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let keys = pairing::keys(config.pattern.as_ref(), &file_name, program.as_deref());
    let plan_json = analysis.as_ref().map(|a| serde_json::to_string(&a.plan)).transpose()?;
    let encoding = match analysis.as_ref().map(|a| a.source.encoding) {
        Some(Encoding::Utf8) => "utf-8",
        Some(Encoding::Windows1252) => "windows-1252",
        Some(Encoding::Binary) => "binary",
        None => "unknown",
    };
    let machine = (folder.role == Role::Machine).then(|| (folder.name.as_str(), dialect_name.as_str(), folder.path.to_str().unwrap_or("")));
    let stem = pairing::file_stem(&file_name);
    let name = program.clone().unwrap_or_else(|| stem.clone());
    let status = if too_large {
        "too_large"
    } else if blank {
        "empty"
    } else {
        "analysed"
    };

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
        bytes: &bytes,
        hash: &hash,
        mtime_ns,
        seen_at: now,
        encoding,
        status,
        plan_json: plan_json.as_deref(),
        counts: analysis.as_ref().map_or((0, 0), |a| (a.plan.workingsteps.len(), a.plan.tools.len())),
        diagnostics: &diagnostics,
    })?;
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
        tracing::info!(path = %path.display(), partial = p.id, complete = revision, "The previous revision was a partial write.");
        // Edited programs compared with a partial original are compared again.
        recompare = tx.compared_with(p.id)?;
    }
    let mut changes = None;
    let mut compared = 0;
    if let Some(a) = &analysis {
        let known = Known { revision, plan: &a.plan };
        match folder.role {
            Role::Machine => changes = settle(&tx, revision, &keys, known, now)?,
            Role::Cam => {
                // Edited programs that arrived before their original are compared now.
                let mut waiting: Vec<Comparable> = recompare;
                for key in &keys {
                    waiting.extend(tx.uncompared(Some(&key.value))?);
                }
                waiting.sort_by_key(|w| w.revision);
                waiting.dedup_by_key(|w| w.revision);
                for w in &waiting {
                    if settle(&tx, w.revision, &w.keys, known, now)?.is_some() {
                        compared += 1;
                    }
                }
            }
        }
    }
    tx.commit()?;
    Ok(Outcome::Stored { revision, changes, compared })
}

/// A plan at hand, so that it need not be read back from the store.
#[derive(Clone, Copy)]
struct Known<'a> {
    revision: i64,
    plan: &'a ProcessPlan,
}

fn stored_plan(tx: &Txn<'_>, revision: i64) -> Result<Option<ProcessPlan>> {
    match tx.plan_json(revision)? {
        Some(json) => Ok(Some(serde_json::from_str(&json).context("stored plan is unreadable")?)),
        None => Ok(None),
    }
}

/// Pairs the machine revision `revision` (with the program keys `keys`) with its original
/// and records the comparison, or the ambiguity. Returns the number of changes when compared.
fn settle(tx: &Txn<'_>, revision: i64, keys: &[Key], known: Known<'_>, now: &str) -> Result<Option<usize>> {
    let pairing = pairing::choose(keys, |k| tx.originals(k))?;
    match &pairing {
        Pairing::Unpaired => Ok(None),
        Pairing::Ambiguous { .. } => {
            let message = pairing.message().unwrap_or_default();
            tx.add_finding(revision, &finding(Code::PairingAmbiguous, message))?;
            Ok(None)
        }
        Pairing::Paired { revision: original, rule, .. } => {
            use std::borrow::Cow;
            let load = |id: i64| -> Result<Option<Cow<'_, ProcessPlan>>> {
                if id == known.revision { Ok(Some(Cow::Borrowed(known.plan))) } else { Ok(stored_plan(tx, id)?.map(Cow::Owned)) }
            };
            let (Some(before), Some(after)) = (load(*original)?, load(revision)?) else { return Ok(None) };
            let changes = diff::diff(&before, &after);
            tx.record_comparison(revision, *original, rule, &changes, now)?;
            Ok(Some(changes.len()))
        }
    }
}

/// Compares every usable machine revision that has no comparison yet but whose original is
/// stored (an older ncplan, killed between the two, left such). Returns how many it compared.
pub fn reconcile(store: &mut Store, now: &str) -> Result<usize> {
    let tx = store.begin()?;
    let mut compared = 0;
    for w in tx.uncompared(None)? {
        let Some(plan) = stored_plan(&tx, w.revision)? else { continue };
        if settle(&tx, w.revision, &w.keys, Known { revision: w.revision, plan: &plan }, now)?.is_some() {
            compared += 1;
        }
    }
    tx.commit()?;
    Ok(compared)
}

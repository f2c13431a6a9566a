//! One file → one stored revision: read, hash, analyse, find the CAM original, diff, record.
//! Synchronous; runs on the daemon's worker thread (and in tests).

use std::path::Path;

use anyhow::{Context, Result};
use sha2::{Digest, Sha256};

use crate::config::{Config, Folder, Role};
use crate::diag::DiagnosticJson;
use crate::dialect::Registry;
use crate::diff;
use crate::pipeline;
use crate::plan::ProcessPlan;
use crate::store::{NewRevision, Store};
use crate::text::{Encoding, LineIndex};

/// What happened to a file.
#[derive(Debug, PartialEq, Eq)]
pub enum Outcome {
    /// A new revision was stored; with its change count when it was compared.
    Stored {
        /// Revision id.
        revision: i64,
        /// Changes found against the CAM original, if one was found.
        changes: Option<usize>,
    },
    /// The content equals the latest stored revision.
    Unchanged,
    /// The path is not a regular file (or vanished).
    Gone,
}

/// The matching keys of a program, most specific first: the configured pattern's `key`, the
/// program number or name stated in the program, the upper-case file stem.
pub fn keys(config: &Config, path: &Path, program: Option<&str>) -> Vec<String> {
    let file = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
    let mut out = Vec::new();
    if let Some(re) = &config.pattern
        && let Some(k) = re.captures(&file).and_then(|c| c.name("key"))
    {
        out.push(k.as_str().to_ascii_uppercase());
    }
    if let Some(p) = program {
        out.push(p.to_ascii_uppercase());
    }
    out.push(stem(path));
    out.dedup();
    out
}

fn stem(path: &Path) -> String {
    path.file_stem().map(|s| s.to_string_lossy().to_ascii_uppercase()).unwrap_or_default()
}

/// Hex SHA-256.
pub fn sha256_hex(bytes: &[u8]) -> String {
    let digest = Sha256::digest(bytes);
    let mut s = String::with_capacity(64);
    for b in digest {
        s.push_str(&format!("{b:02x}"));
    }
    s
}

/// Ingests `path`, which lies in `folder`. `now` is the injected clock's reading.
pub fn ingest(path: &Path, folder: &Folder, config: &Config, registry: &Registry, store: &mut Store, now: &str) -> Result<Outcome> {
    let meta = match std::fs::metadata(path) {
        Ok(m) if m.is_file() => m,
        Ok(_) => return Ok(Outcome::Gone),
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Outcome::Gone),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
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
    let (analysis, diagnostics) = if too_large {
        let d = pipeline::too_large(bytes.len() as u64, config.max_file_bytes);
        (None, vec![DiagnosticJson::new(&d, "", &LineIndex::new(""))])
    } else {
        // Subprograms come from the configured directory, else from beside the program.
        let profile = crate::config::DirPrograms::beside(&config.profile, path, config.max_file_bytes);
        let a = pipeline::analyze(&bytes, &dialect, &profile);
        let idx = LineIndex::new(&a.source.text);
        let ds = a.diagnostics.iter().map(|d| DiagnosticJson::new(d, &a.source.text, &idx)).collect();
        (Some(a), ds)
    };
    let program = analysis.as_ref().and_then(|a| a.plan.program.clone());
    let keys = keys(config, path, program.as_deref());
    let plan_json = analysis.as_ref().map(|a| serde_json::to_string(&a.plan)).transpose()?;
    let mut comparison = None;
    if folder.role == Role::Machine
        && let Some(a) = &analysis
        && let Some(original) = store.find_original(&keys)?
    {
        let before: ProcessPlan = serde_json::from_str(&original.plan_json).context("stored plan is unreadable")?;
        comparison = Some((original.revision_id, diff::diff(&before, &a.plan)));
    }
    let encoding = match analysis.as_ref().map(|a| a.source.encoding) {
        Some(Encoding::Utf8) => "utf-8",
        Some(Encoding::Windows1252) => "windows-1252",
        Some(Encoding::Binary) => "binary",
        None => "unknown",
    };
    let machine = (folder.role == Role::Machine).then(|| (folder.name.as_str(), dialect_name.as_str(), folder.path.to_str().unwrap_or("")));
    let stem = stem(path);
    let name = program.clone().unwrap_or_else(|| stem.clone());
    let rev = NewRevision {
        path: &path_str,
        role: folder.role.as_str(),
        machine,
        name: &name,
        key: &keys[0],
        stem: &stem,
        dialect: &dialect_name,
        bytes: &bytes,
        hash: &hash,
        mtime_ns,
        seen_at: now,
        encoding,
        status: if too_large { "too_large" } else { "analysed" },
        plan_json: plan_json.as_deref(),
        counts: analysis.as_ref().map_or((0, 0), |a| (a.plan.workingsteps.len(), a.plan.tools.len())),
        diagnostics: &diagnostics,
        comparison: comparison.as_ref().map(|(id, ch)| (*id, ch.as_slice())),
    };
    let Some(revision) = store.record(&rev)? else { return Ok(Outcome::Unchanged) };
    if folder.role == Role::Cam
        && let Some(a) = &analysis
    {
        // Edited programs that arrived before their original are compared now.
        for key in &keys {
            for m in store.uncompared_machine_revisions(key)? {
                let after: ProcessPlan = serde_json::from_str(&m.plan_json).context("stored plan is unreadable")?;
                let changes = diff::diff(&a.plan, &after);
                store.record_comparison(m.revision_id, revision, &changes, now)?;
            }
        }
    }
    Ok(Outcome::Stored { revision, changes: comparison.map(|(_, c)| c.len()) })
}

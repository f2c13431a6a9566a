//! `ncplan reanalyze` and `ncplan worker`: every stored revision read again with today's
//! dictionary and engine. The revisions wait in the store's queue; each worker (threads of
//! one process on SQLite; any number of processes on any hosts on PostgreSQL) claims a batch
//! under a lease, analyses each revision from its immutable bytes and records the new plan,
//! findings and comparison in one transaction per revision, which the store lets happen once
//! per analysis version. A killed worker's batch returns to the queue when its lease runs out.

use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Duration;

use anyhow::{Context, Result};
use sha2::Digest as _;

use crate::config::Config;
use crate::daemon::ingest::{Reader, summary_json};
use crate::diag::DiagnosticJson;
use crate::dialect::Registry;
use crate::store::{NewAnalysis, Store};
use crate::text::LineIndex;

/// Revisions a worker claims at once.
pub const BATCH: usize = 8;

/// What a run did.
#[derive(Debug, Default, Clone)]
pub struct Summary {
    /// Revisions read again by this run.
    pub reread: usize,
    /// Of them, those whose plan changed.
    pub plans_changed: usize,
    /// Findings that are new.
    pub new_findings: usize,
    /// Findings that vanished.
    pub vanished_findings: usize,
    /// Comparisons made again.
    pub compared: usize,
    /// Revisions another worker had recorded already.
    pub skipped: usize,
    /// Revisions that could not be read again, with why.
    pub errors: Vec<(i64, String)>,
}

/// The analysis version: this ncplan's version and a digest of the dialect files it reads
/// (the shipped ones and `dialects_dir`'s).
pub fn version(config: &Config) -> Result<String> {
    let mut h = sha2::Sha256::new();
    for (name, text) in crate::dialect::registry::SHIPPED {
        h.update(name.as_bytes());
        h.update(text.as_bytes());
    }
    if let Some(dir) = &config.dialects_dir {
        let mut files: Vec<_> = std::fs::read_dir(dir)
            .with_context(|| format!("cannot read {}", dir.display()))?
            .flatten()
            .map(|e| e.path())
            .filter(|p| p.extension().is_some_and(|e| e == "xml"))
            .collect();
        files.sort();
        for f in files {
            h.update(f.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default().as_bytes());
            h.update(std::fs::read(&f).with_context(|| format!("cannot read {}", f.display()))?);
        }
    }
    Ok(format!("{}+{}", env!("CARGO_PKG_VERSION"), &format!("{:x}", h.finalize())[..12]))
}

/// Works the queue of `version` with `threads` connections until nothing is left, waiting
/// for leases of killed workers to run out. `progress` hears (revisions done by this run,
/// left in the queue).
#[allow(clippy::too_many_arguments)]
pub fn work(
    config: &Config,
    registry: &Registry,
    stores: Vec<Store>,
    version: &str,
    worker: &str,
    lease: Duration,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Summary> {
    let total = Mutex::new(Summary::default());
    let done = AtomicUsize::new(0);
    let failed: Mutex<Option<anyhow::Error>> = Mutex::new(None);
    std::thread::scope(|scope| {
        for (i, store) in stores.into_iter().enumerate() {
            let (total, done, failed) = (&total, &done, &failed);
            let name = format!("{worker}/{i}");
            scope.spawn(move || {
                let mut store = store;
                if let Err(e) = work_one(config, registry, &mut store, version, &name, lease, total, done, progress) {
                    *failed.lock().unwrap_or_else(std::sync::PoisonError::into_inner) = Some(e);
                }
            });
        }
    });
    if let Some(e) = failed.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner) {
        return Err(e);
    }
    Ok(total.into_inner().unwrap_or_else(std::sync::PoisonError::into_inner))
}

#[allow(clippy::too_many_arguments)]
fn work_one(
    config: &Config,
    registry: &Registry,
    store: &mut Store,
    version: &str,
    worker: &str,
    lease: Duration,
    total: &Mutex<Summary>,
    done: &AtomicUsize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<()> {
    let reader = Reader { config, registry };
    loop {
        let now = at(Duration::ZERO);
        let until = at(lease);
        let batch = store.claim_reanalysis(version, worker, BATCH, &now, &until)?;
        if batch.is_empty() {
            if store.reanalysis_left(version)? == 0 {
                return Ok(());
            }
            // Another worker holds the rest: it finishes, or its lease runs out.
            std::thread::sleep(Duration::from_millis(200));
            continue;
        }
        for id in batch {
            let mut s = Summary::default();
            match reread(&reader, store, id, version, worker, &at(Duration::ZERO)) {
                Ok(Some((changed, new, vanished, compared))) => {
                    s.reread = 1;
                    s.plans_changed = usize::from(changed);
                    s.new_findings = new;
                    s.vanished_findings = vanished;
                    s.compared = usize::from(compared);
                }
                Ok(None) => s.skipped = 1,
                Err(e) => s.errors.push((id, format!("{e:#}"))),
            }
            let mut t = total.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
            t.reread += s.reread;
            t.plans_changed += s.plans_changed;
            t.new_findings += s.new_findings;
            t.vanished_findings += s.vanished_findings;
            t.compared += s.compared;
            t.skipped += s.skipped;
            t.errors.extend(s.errors);
            drop(t);
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            progress(n, store.reanalysis_left(version).unwrap_or(0));
        }
    }
}

/// Reads one revision again and records it; `None` when this version's analysis of it is
/// recorded already.
fn reread(
    reader: &Reader<'_>,
    store: &mut Store,
    id: i64,
    version: &str,
    worker: &str,
    now: &str,
) -> Result<Option<(bool, usize, usize, bool)>> {
    let src = store.source(id)?.with_context(|| format!("no revision {id}"))?;
    let bytes = store.content(id)?.with_context(|| format!("revision {id} has no stored bytes"))?;
    let mut a = reader.reanalyse(&src.path, &src.dialect, bytes)?;
    let idx = LineIndex::new(&a.source.text);
    let diagnostics: Vec<DiagnosticJson> = a.diagnostics.iter().map(|d| DiagnosticJson::new(d, &a.source.text, &idx)).collect();
    let plan_json = summary_json(&mut a.plan)?;
    let tx = store.begin()?;
    let Some(outcome) = tx.record_analysis(&NewAnalysis {
        revision: id,
        version,
        worker,
        at: now,
        plan_json: &plan_json,
        counts: (a.plan.workingsteps.len(), a.plan.tools.len()),
        diagnostics: &diagnostics,
    })?
    else {
        return Ok(None);
    };
    // An edit compared before is compared again, with its original's plan as it reads today.
    let mut compared = false;
    if let Some((original, rule)) = tx.comparison_of(id)?
        && let Some(op) = reader.program(&tx, original, None)?
    {
        let d = reader.dialect_of(&src.path, &src.dialect)?;
        let edited = crate::diff::Program { plan: &a.plan, text: &a.source.text, dialect: &d };
        let changes = op.compare(edited, &crate::diff::verdict::faults(&a.source.text, &a.diagnostics));
        tx.record_comparison(id, original, &rule, &changes, now)?;
        compared = true;
    }
    tx.commit()?;
    Ok(Some((outcome.plan_changed, outcome.new_findings, outcome.vanished_findings, compared)))
}

/// The time `after` from now, as the store writes times.
fn at(after: Duration) -> String {
    let d = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).unwrap_or_default() + after;
    crate::daemon::rfc3339(d.as_secs() as i64, d.subsec_millis())
}

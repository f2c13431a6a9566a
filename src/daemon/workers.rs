//! The daemon's worker threads: a bounded pool, each with its own database connection, so
//! that one huge program does not hold up the others. Each takes one settled file at a time
//! and reports the outcome to the main loop. The door is [`start`], after [`open_stores`].

use std::path::PathBuf;
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use tokio::sync::mpsc;

use super::ingest::{self, Snapshot};
use super::{Clock, Event};
use crate::config::Config;
use crate::dialect::Registry;
use crate::store::Store;

/// A settled file for a worker.
pub(super) struct Job {
    pub(super) path: PathBuf,
    pub(super) folder: usize,
    pub(super) snapshot: Snapshot,
    /// The folder's real path.
    pub(super) root: PathBuf,
}

/// Workers: one per core, at least one and at most `[daemon] workers` (default 4).
fn worker_count(config: &Config) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    cores.clamp(1, config.workers.max(1))
}

/// One database connection per worker, after checking that each folder's dialect is known
/// and making the database's folder.
pub(super) fn open_stores(config: &Config, registry: &Registry) -> Result<Vec<Store>> {
    for f in config.folders.iter().filter(|f| f.dialect != crate::config::AUTO_DIALECT) {
        registry.get(&f.dialect).with_context(|| format!("folder {} uses the unknown dialect `{}`", f.path.display(), f.dialect))?;
    }
    if let Some(parent) = config.database.file().and_then(std::path::Path::parent) {
        std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
    }
    let open = || -> Result<Store> {
        let mut store =
            Store::open(&config.database, &config.site).with_context(|| format!("cannot open the database {}", config.database))?;
        // Workers wait for each other's transactions (one revision and what it enables).
        store.set_busy_timeout(Duration::from_secs(600))?;
        Ok(store)
    };
    let workers = worker_count(config);
    // Opened on a thread of their own: a store's connection may block (PostgreSQL's client
    // runs its own runtime), which a thread driving this one may not.
    std::thread::scope(|s| s.spawn(|| (0..workers).map(|_| open()).collect::<Result<Vec<Store>>>()).join())
        .map_err(|_| anyhow::anyhow!("opening the database panicked"))?
}

/// What every worker holds: the configuration, the dialects, the way back to the main loop,
/// the clock, and the queue of jobs they take turns at.
struct Shared {
    config: Arc<Config>,
    registry: Arc<Registry>,
    tx: mpsc::UnboundedSender<Event>,
    clock: Arc<dyn Clock>,
    jobs: Arc<Mutex<std::sync::mpsc::Receiver<Job>>>,
}

/// Starts a worker thread per store; the jobs go in by the sender returned, and the threads
/// end when it is dropped. The first worker compares what an earlier run left waiting.
pub(super) fn start(
    stores: Vec<Store>,
    config: &Arc<Config>,
    registry: &Arc<Registry>,
    tx: &mpsc::UnboundedSender<Event>,
    clock: &Arc<dyn Clock>,
) -> Result<(std::sync::mpsc::Sender<Job>, Vec<JoinHandle<()>>)> {
    let (job_tx, job_rx) = std::sync::mpsc::channel::<Job>();
    let job_rx = Arc::new(Mutex::new(job_rx));
    let mut pool = Vec::new();
    for (i, store) in stores.into_iter().enumerate() {
        let shared = Shared {
            config: Arc::clone(config),
            registry: Arc::clone(registry),
            tx: tx.clone(),
            clock: Arc::clone(clock),
            jobs: Arc::clone(&job_rx),
        };
        pool.push(std::thread::Builder::new().name(format!("ncplan-worker-{i}")).spawn(move || shared.work(i, store))?);
    }
    Ok((job_tx, pool))
}

impl Shared {
    /// A worker's life: (the first) the waiting comparisons, then one job after another,
    /// until the jobs' sender or the main loop goes away. A panicking analysis is an error
    /// for its file, not the end of the worker.
    fn work(self, i: usize, mut store: Store) {
        let Shared { config, registry, tx, clock, jobs } = self;
        if i == 0 {
            match ingest::reconcile(&mut store, &ingest::Reader { config: &config, registry: &registry }, &clock.now()) {
                Ok(0) => {}
                Ok(n) => tracing::info!(compared = n, "Compared the edited programs that were waiting for their original."),
                Err(error) => tracing::error!(error = format!("{error:#}"), "Could not compare the waiting edited programs."),
            }
        }
        loop {
            let job = match jobs.lock() {
                Ok(rx) => rx.recv(),
                Err(_) => break,
            };
            let Ok(Job { path, folder, snapshot, root }) = job else { break };
            let started = Instant::now();
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                ingest::ingest(&path, &config.folders[folder], &root, &config, &registry, &mut store, &clock.now(), Some(snapshot))
            }))
            .unwrap_or_else(|_| Err(anyhow::anyhow!("analysis panicked")));
            if tx.send(Event::Done { path, folder, result, elapsed: started.elapsed() }).is_err() {
                break;
            }
        }
    }
}

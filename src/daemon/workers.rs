//! The daemon's worker threads: a bounded pool, each with its own database connection, so
//! that one huge program does not hold up the others. Each takes one settled file at a time
//! and reports the outcome to the main loop. The door is [`Pool::start`], after [`open_stores`].
//!
//! A worker that takes longer than the worker bound (`[daemon] worker_timeout_s`) over one
//! file is given up ([`Pool::overdue`]): its slot gets a fresh thread with a connection of
//! its own, and the file goes back to the queue to be stored unanalysed (quarantined). A
//! thread cannot be killed, so the one given up runs on; should it ever finish, its result is
//! dropped. [`Pool::advancing`] says whether work advances (the watchdog is pinged only
//! then), and [`Pool::stop`] waits for the files in progress within a bound only.
//!
//! After a worker stored a revision of a CAM post or an edit with changes, it runs the watch
//! over exported suggestions (`export::watch`, one worker at a time): a post that carries a
//! suggested value adopts it, edits that go on reopen it, recorded at once.

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
use crate::sharefile::path_text;
use crate::store::Store;

/// A settled file for a worker.
#[derive(Clone, Debug)]
pub(super) struct Job {
    pub(super) path: PathBuf,
    pub(super) folder: usize,
    pub(super) snapshot: Snapshot,
    /// The folder's real path.
    pub(super) root: PathBuf,
    /// A file a worker got stuck on: stored without analysis ([`ingest::quarantine`]).
    pub(super) quarantine: bool,
}

/// Workers: one per core, at least one and at most `[daemon] workers` (default 4).
pub(super) fn worker_count(config: &Config) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get);
    cores.clamp(1, config.workers.max(1))
}

/// One worker's connection.
fn open_store(config: &Config) -> Result<Store> {
    let mut store = Store::open(&config.database, &config.site).with_context(|| format!("cannot open the database {}", config.database))?;
    // Workers wait for each other's transactions (one revision and what it enables).
    store.set_busy_timeout(Duration::from_secs(600))?;
    Ok(store)
}

/// One database connection per worker, after checking that each folder's dialect is known
/// and making the database's folder.
pub(super) fn open_stores(config: &Config, registry: &Registry) -> Result<Vec<Store>> {
    for f in config.folders.iter().filter(|f| f.dialect != crate::config::AUTO_DIALECT) {
        registry.get(&f.dialect).with_context(|| format!("folder {} uses the unknown dialect `{}`", path_text(&f.path), f.dialect))?;
    }
    if let Some(parent) = config.database.file().and_then(std::path::Path::parent) {
        std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
    }
    let workers = worker_count(config);
    // Opened on a thread of their own: a store's connection may block (PostgreSQL's client
    // runs its own runtime), which a thread driving this one may not.
    std::thread::scope(|s| s.spawn(|| (0..workers).map(|_| open_store(config)).collect::<Result<Vec<Store>>>()).join())
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

/// A worker's state, shared with the main loop: the job it is on and since when, and whether
/// it was given up. Both change under one lock, so a job is either finished by its worker or
/// given up by the main loop, never both.
#[derive(Default)]
struct State {
    busy: Option<(Job, Instant)>,
    given_up: bool,
}

/// One place in the pool: the thread that fills it now.
struct Slot {
    state: Arc<Mutex<State>>,
    thread: JoinHandle<()>,
}

/// The worker pool.
pub(super) struct Pool {
    shared: Arc<Shared>,
    sender: std::sync::mpsc::Sender<Job>,
    slots: Vec<Slot>,
    /// Threads given up: stuck past the bound, still running.
    given_up: Vec<JoinHandle<()>>,
    bound: Duration,
}

impl Pool {
    /// Starts a worker thread per store. The first worker compares what an earlier run left
    /// waiting.
    pub(super) fn start(
        stores: Vec<Store>,
        config: &Arc<Config>,
        registry: &Arc<Registry>,
        tx: &mpsc::UnboundedSender<Event>,
        clock: &Arc<dyn Clock>,
    ) -> Result<Pool> {
        let (sender, jobs) = std::sync::mpsc::channel::<Job>();
        let shared = Arc::new(Shared {
            config: Arc::clone(config),
            registry: Arc::clone(registry),
            tx: tx.clone(),
            clock: Arc::clone(clock),
            jobs: Arc::new(Mutex::new(jobs)),
        });
        let mut slots = Vec::new();
        for (i, store) in stores.into_iter().enumerate() {
            slots.push(spawn(&shared, i, Some(store), i == 0)?);
        }
        let bound = Duration::from_secs(config.worker_timeout_s);
        Ok(Pool { shared, sender, slots, given_up: Vec::new(), bound })
    }

    /// Hands a job to the workers. An error when they have all stopped.
    pub(super) fn send(&self, job: Job) -> Result<()> {
        self.sender.send(job).map_err(|_| anyhow::anyhow!("the workers stopped"))
    }

    /// The jobs whose workers ran past the bound, with how long they ran: each worker is
    /// given up and its slot filled by a fresh thread with a connection of its own.
    pub(super) fn overdue(&mut self) -> Vec<(Job, Duration)> {
        let mut late = Vec::new();
        for i in 0..self.slots.len() {
            let taken = {
                let Ok(mut state) = self.slots[i].state.lock() else { continue };
                let late = state
                    .busy
                    .as_ref()
                    .filter(|(_, since)| since.elapsed() > self.bound)
                    .map(|(job, since)| (job.clone(), since.elapsed()));
                state.given_up |= late.is_some();
                late
            };
            let Some(job) = taken else { continue };
            match spawn(&self.shared, i, None, false) {
                Ok(fresh) => {
                    let old = std::mem::replace(&mut self.slots[i], fresh);
                    self.given_up.push(old.thread);
                }
                Err(error) => tracing::error!(error = format!("{error:#}"), "Cannot start a worker in place of a stuck one."),
            }
            late.push(job);
        }
        self.given_up.retain(|t| !t.is_finished());
        late
    }

    /// Whether work advances: every worker runs (a fresh one that could not open the database
    /// has ended), and none is on one file past the bound and not yet replaced.
    pub(super) fn advancing(&self) -> bool {
        self.slots.iter().all(|s| {
            !s.thread.is_finished()
                && s.state.lock().is_ok_and(|st| st.busy.as_ref().is_none_or(|(_, since)| since.elapsed() <= self.bound))
        })
    }

    /// How many threads were given up and still run.
    pub(super) fn stuck(&self) -> usize {
        self.given_up.iter().filter(|t| !t.is_finished()).count()
    }

    /// Ends the pool: no more jobs; the files in progress are waited for at most `grace`,
    /// after which the workers still running are left to end with the process.
    pub(super) async fn stop(self, grace: Duration) {
        let Pool { sender, slots, given_up, .. } = self;
        drop(sender);
        let deadline = Instant::now() + grace;
        while slots.iter().any(|s| !s.thread.is_finished()) && Instant::now() < deadline {
            tokio::time::sleep(Duration::from_millis(20)).await;
        }
        let running = slots.iter().filter(|s| !s.thread.is_finished()).count() + given_up.iter().filter(|t| !t.is_finished()).count();
        if running > 0 {
            tracing::warn!(workers = running, seconds = grace.as_secs(), "Workers still busy at the end of the stop bound; leaving them.");
        }
    }
}

/// Starts the worker of slot `i`, with `store` or (a replacement) a connection it opens itself.
fn spawn(shared: &Arc<Shared>, i: usize, store: Option<Store>, first: bool) -> Result<Slot> {
    let state = Arc::new(Mutex::new(State::default()));
    let (shared, mine) = (Arc::clone(shared), Arc::clone(&state));
    let thread = std::thread::Builder::new().name(format!("ncplan-worker-{i}")).spawn(move || {
        let store = match store {
            Some(s) => s,
            None => match open_store(&shared.config) {
                Ok(s) => s,
                Err(error) => return tracing::error!(error = format!("{error:#}"), "A fresh worker cannot open the database."),
            },
        };
        shared.work(first, store, &mine);
    })?;
    Ok(Slot { state, thread })
}

/// One watch at a time in this daemon: two workers that stored revisions at once would both
/// see an exported suggestion adopted (the store records the step once, `Store::
/// add_suggestion_step`, which is what keeps two daemons on one database apart; this spares
/// the second worker the reading).
static WATCH: Mutex<()> = Mutex::new(());

/// The watch over exported suggestions after a revision was stored (a CAM post that carries a
/// suggested value adopts it, edits that go on reopen it), recorded on this worker's store; a
/// failure is logged, never the file's.
fn watch_suggestions(store: &Store, config: &Config, now: &str) {
    let _one = WATCH.lock().unwrap_or_else(std::sync::PoisonError::into_inner);
    match crate::export::watch(store, config, now) {
        Ok(0) => {}
        Ok(n) => tracing::info!(steps = n, "Recorded what the watch over exported suggestions saw."),
        Err(error) => tracing::error!(error = format!("{error:#}"), "Could not watch the exported suggestions."),
    }
}

impl Shared {
    /// A worker's life: (the first) the waiting comparisons, then one job after another,
    /// until the jobs' sender or the main loop goes away, or it is given up. A panicking
    /// analysis is an error for its file, not the end of the worker.
    fn work(&self, first: bool, mut store: Store, state: &Mutex<State>) {
        let Shared { config, registry, tx, clock, jobs } = self;
        if first {
            match ingest::reconcile(&mut store, &ingest::Reader { config, registry }, &clock.now()) {
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
            let Ok(job) = job else { break };
            match state.lock() {
                Ok(mut s) => s.busy = Some((job.clone(), Instant::now())),
                Err(_) => break,
            }
            let started = Instant::now();
            let Job { path, folder, snapshot, root, quarantine } = job;
            let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                let f = &config.folders[folder];
                if quarantine {
                    ingest::quarantine(&path, f, &root, config, registry, &mut store, &clock.now(), snapshot, config.worker_timeout_s)
                } else {
                    ingest::ingest(&path, f, &root, config, registry, &mut store, &clock.now(), Some(snapshot))
                }
            }))
            .unwrap_or_else(|_| Err(anyhow::anyhow!("analysis panicked")));
            if let Ok(ingest::Outcome::Stored { changes, compared, .. }) = &result {
                let cam = config.folders[folder].role == crate::config::Role::Cam;
                if cam || changes.is_some_and(|n| n > 0) || *compared > 0 {
                    watch_suggestions(&store, config, &clock.now());
                }
            }
            let given_up = match state.lock() {
                Ok(mut s) => {
                    s.busy = None;
                    s.given_up
                }
                Err(_) => true,
            };
            if given_up {
                tracing::warn!(path = %path_text(&path), "A worker given up as stuck finished its file after all; its result is dropped.");
                break;
            }
            if tx.send(Event::Done { path, folder, result, elapsed: started.elapsed() }).is_err() {
                break;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A worker on one file past the bound holds the watchdog back until it is replaced; the
    /// replacement takes its place, and the one given up is counted as stuck.
    #[test]
    fn a_worker_past_the_bound_holds_the_watchdog_until_it_is_replaced() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("share")).unwrap();
        let text = "[database]\npath = 'db.sqlite'\n[daemon]\nworker_timeout_s = 1\nworkers = 1\n\
                    [analysis]\nmax_repeated_blocks = 1000000000\n[[machine]]\nname = 'M1'\npath = 'share'\ndialect = 'fanuc'\n";
        let config = Arc::new(Config::parse(text, dir.path()).unwrap());
        let registry = Arc::new(Registry::shipped());
        // Nested loops of a million passes each: minutes of analysis.
        let file = dir.path().join("share/O9.nc");
        std::fs::write(&file, "%\nO9\n#1=0\nWHILE[#1LT1000000]DO1\n#2=0\nWHILE[#2LT1000000]DO2\n#2=#2+1\nEND2\n#1=#1+1\nEND1\nM30\n%\n")
            .unwrap();
        let meta = std::fs::metadata(&file).unwrap();
        let snapshot = Snapshot { size: meta.len(), mtime: meta.modified().ok() };
        let stores = open_stores(&config, &registry).unwrap();
        let (tx, _rx) = mpsc::unbounded_channel();
        let clock: Arc<dyn Clock> = Arc::new(super::super::SystemClock);
        let mut pool = Pool::start(stores, &config, &registry, &tx, &clock).unwrap();
        assert!(pool.advancing());
        let root = std::fs::canonicalize(dir.path().join("share")).unwrap();
        pool.send(Job { path: file.clone(), folder: 0, snapshot, root, quarantine: false }).unwrap();
        let deadline = Instant::now() + Duration::from_secs(60);
        while pool.advancing() {
            assert!(Instant::now() < deadline, "the worker never ran past the bound");
            std::thread::sleep(Duration::from_millis(50));
        }
        let late = pool.overdue();
        assert_eq!(late.len(), 1);
        assert_eq!((late[0].0.path.as_path(), late[0].0.quarantine), (file.as_path(), false));
        assert!(late[0].1 > Duration::from_secs(1));
        assert!(pool.advancing(), "the replaced worker still holds the watchdog");
        assert_eq!(pool.stuck(), 1);
        assert!(pool.overdue().is_empty());
    }
}

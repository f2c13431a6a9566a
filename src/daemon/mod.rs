//! The watch daemon: the only code that knows tokio, notify and systemd.
//!
//! One `tokio::select!` loop consumes a closed set of events (file-system events, ticks,
//! worker results, signals). A file is handed to the worker thread once its size and mtime
//! have held still for `settle_ms`. The worker owns the database connection and ingests one
//! file at a time, each in one transaction, so a kill at any moment loses nothing: the
//! catch-up scan at the next start finds what was not stored.

pub mod ingest;
mod systemd;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant, SystemTime};

use anyhow::{Context, Result};
use notify::{PollWatcher, RecommendedWatcher, RecursiveMode, Watcher};
use tokio::sync::mpsc;

use crate::config::Config;
use crate::dialect::Registry;
use crate::store::Store;
pub use ingest::{Outcome, ingest};
use systemd::Notifier;

/// A wall clock, injected so that tests and replays are deterministic.
pub trait Clock: Send + Sync {
    /// Now, as RFC 3339 UTC with milliseconds.
    fn now(&self) -> String;
}

/// The system clock.
pub struct SystemClock;

impl Clock for SystemClock {
    fn now(&self) -> String {
        let d = SystemTime::now().duration_since(SystemTime::UNIX_EPOCH).unwrap_or_default();
        rfc3339(d.as_secs() as i64, d.subsec_millis())
    }
}

/// Formats seconds since the epoch as `YYYY-MM-DDTHH:MM:SS.mmmZ`.
pub fn rfc3339(secs: i64, millis: u32) -> String {
    let days = secs.div_euclid(86_400);
    let rem = secs.rem_euclid(86_400);
    // Civil date from days since 1970-01-01 (Howard Hinnant's algorithm).
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + i64::from(month <= 2);
    format!("{year:04}-{month:02}-{day:02}T{:02}:{:02}:{:02}.{millis:03}Z", rem / 3600, rem % 3600 / 60, rem % 60)
}

/// Events of the main loop.
enum Event {
    Fs(notify::Result<notify::Event>),
    Done { path: PathBuf, result: Result<Outcome>, elapsed: Duration },
}

struct Pending {
    folder: usize,
    size: u64,
    mtime: Option<SystemTime>,
    since: Instant,
}

/// Runs the daemon until SIGTERM or SIGINT.
pub fn run(config: Config, registry: Registry, clock: Arc<dyn Clock>) -> Result<()> {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().context("cannot start the runtime")?;
    runtime.block_on(main_loop(config, registry, clock))
}

async fn main_loop(config: Config, registry: Registry, clock: Arc<dyn Clock>) -> Result<()> {
    let notifier = Notifier::from_env();
    for f in config.folders.iter().filter(|f| f.dialect != crate::config::AUTO_DIALECT) {
        registry.get(&f.dialect).with_context(|| format!("folder {} uses the unknown dialect `{}`", f.path.display(), f.dialect))?;
    }
    if let Some(parent) = config.database.parent() {
        std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
    }
    let store = Store::open(&config.database).with_context(|| format!("cannot open the database {}", config.database.display()))?;
    let config = Arc::new(config);
    let (tx, mut rx) = mpsc::unbounded_channel::<Event>();

    // The worker thread owns the database connection.
    let (job_tx, job_rx) = std::sync::mpsc::channel::<(PathBuf, usize)>();
    let worker = {
        let (config, tx, clock) = (Arc::clone(&config), tx.clone(), Arc::clone(&clock));
        std::thread::Builder::new().name("ncplan-worker".into()).spawn(move || {
            let mut store = store;
            while let Ok((path, folder)) = job_rx.recv() {
                let started = Instant::now();
                let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                    ingest(&path, &config.folders[folder], &config, &registry, &mut store, &clock.now())
                }))
                .unwrap_or_else(|_| Err(anyhow::anyhow!("analysis panicked")));
                if tx.send(Event::Done { path, result, elapsed: started.elapsed() }).is_err() {
                    break;
                }
            }
        })?
    };

    let mut watchers: Vec<Option<Box<dyn Watcher + Send>>> = (0..config.folders.len()).map(|_| None).collect();
    arm_watchers(&config, &mut watchers, &tx);
    let mut pending: BTreeMap<PathBuf, Pending> = BTreeMap::new();
    let mut in_flight: BTreeSet<PathBuf> = BTreeSet::new();
    scan(&config, &mut pending);
    tracing::info!(files = pending.len(), "Catch-up scan queued.");
    notifier.notify("READY=1");
    notifier.notify(&format!("STATUS=Watching {} folders.", config.folders.len()));

    let settle = Duration::from_millis(config.settle_ms);
    let mut tick = tokio::time::interval((settle / 4).max(Duration::from_millis(25)));
    let mut rescan = tokio::time::interval(Duration::from_secs(config.rescan_s));
    rescan.tick().await;
    let mut retry = tokio::time::interval(Duration::from_secs(5));
    let mut watchdog = tokio::time::interval(notifier.watchdog_interval().unwrap_or(Duration::from_secs(3600)));
    let mut sigterm = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())?;
    let mut sigint = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::interrupt())?;

    loop {
        tokio::select! {
            Some(event) = rx.recv() => match event {
                Event::Fs(Ok(ev)) => {
                    if ev.need_rescan() {
                        tracing::warn!("The event queue overflowed; rescanning every folder.");
                        scan(&config, &mut pending);
                    }
                    for p in ev.paths {
                        consider(&config, &p, &mut pending);
                    }
                }
                Event::Fs(Err(error)) => {
                    tracing::warn!(%error, "The watcher reported an error; rescanning every folder.");
                    scan(&config, &mut pending);
                }
                Event::Done { path, result, elapsed } => {
                    in_flight.remove(&path);
                    match result {
                        Ok(Outcome::Stored { revision, changes }) => tracing::info!(path = %path.display(), revision, ?changes, ms = elapsed.as_millis() as u64, "Stored a revision."),
                        Ok(Outcome::Unchanged) => tracing::debug!(path = %path.display(), "Content unchanged."),
                        Ok(Outcome::Gone) => tracing::debug!(path = %path.display(), "File vanished."),
                        Err(error) => {
                            // Runtime error: keep the file for the next rescan and go on.
                            tracing::error!(path = %path.display(), error = format!("{error:#}"), "Could not ingest a file; it will be retried.");
                        }
                    }
                }
            },
            _ = tick.tick() => {
                let now = Instant::now();
                let mut ready = Vec::new();
                pending.retain(|path, p| {
                    let Ok(meta) = std::fs::metadata(path) else { return false };
                    let (size, mtime) = (meta.len(), meta.modified().ok());
                    if size != p.size || mtime != p.mtime {
                        (p.size, p.mtime, p.since) = (size, mtime, now);
                        return true;
                    }
                    if now.duration_since(p.since) >= settle && !in_flight.contains(path) {
                        ready.push((path.clone(), p.folder));
                        return false;
                    }
                    true
                });
                for (path, folder) in ready {
                    in_flight.insert(path.clone());
                    if job_tx.send((path, folder)).is_err() {
                        anyhow::bail!("the worker thread stopped");
                    }
                }
            }
            _ = rescan.tick() => scan(&config, &mut pending),
            _ = retry.tick() => {
                if watchers.iter().any(Option::is_none) {
                    arm_watchers(&config, &mut watchers, &tx);
                }
            }
            _ = watchdog.tick() => notifier.notify("WATCHDOG=1"),
            _ = sigterm.recv() => break,
            _ = sigint.recv() => break,
        }
    }
    tracing::info!("Stopping: finishing the file in progress.");
    notifier.notify("STOPPING=1");
    drop(job_tx);
    drop(watchers);
    let _ = tokio::task::spawn_blocking(move || worker.join()).await;
    Ok(())
}

fn arm_watchers(config: &Config, watchers: &mut [Option<Box<dyn Watcher + Send>>], tx: &mpsc::UnboundedSender<Event>) {
    for (i, f) in config.folders.iter().enumerate() {
        if watchers[i].is_some() {
            continue;
        }
        let tx = tx.clone();
        let handler = move |res: notify::Result<notify::Event>| {
            let _ = tx.send(Event::Fs(res));
        };
        let made: notify::Result<Box<dyn Watcher + Send>> = if f.poll {
            let cfg = notify::Config::default().with_poll_interval(Duration::from_millis(f.poll_ms));
            PollWatcher::new(handler, cfg).map(|w| Box::new(w) as Box<dyn Watcher + Send>)
        } else {
            RecommendedWatcher::new(handler, notify::Config::default()).map(|w| Box::new(w) as Box<dyn Watcher + Send>)
        };
        match made.and_then(|mut w| w.watch(&f.path, RecursiveMode::Recursive).map(|()| w)) {
            Ok(w) => {
                tracing::info!(folder = %f.path.display(), machine = %f.name, dialect = %f.dialect, poll = f.poll, "Watching a folder.");
                watchers[i] = Some(w);
            }
            Err(error) => tracing::error!(folder = %f.path.display(), %error, "Cannot watch a folder (share down?); retrying every 5 s."),
        }
    }
}

/// The folder holding `path` (the longest matching prefix).
fn folder_of(config: &Config, path: &Path) -> Option<usize> {
    config
        .folders
        .iter()
        .enumerate()
        .filter(|(_, f)| path.starts_with(&f.path))
        .max_by_key(|(_, f)| f.path.as_os_str().len())
        .map(|(i, _)| i)
}

fn consider(config: &Config, path: &Path, pending: &mut BTreeMap<PathBuf, Pending>) {
    let Some(folder) = folder_of(config, path) else { return };
    let Ok(rel) = path.strip_prefix(&config.folders[folder].path) else { return };
    // Editor and temporary files, and anything inside hidden folders, are not programs.
    if rel.components().any(|c| c.as_os_str().to_str().is_none_or(|s| config.ignored(s))) {
        return;
    }
    let Ok(meta) = std::fs::metadata(path) else { return };
    if !meta.is_file() {
        return;
    }
    let entry = pending.entry(path.to_path_buf()).or_insert(Pending { folder, size: u64::MAX, mtime: None, since: Instant::now() });
    entry.folder = folder;
}

/// Queues every file of every folder (to depth 4); the worker skips unchanged content.
fn scan(config: &Config, pending: &mut BTreeMap<PathBuf, Pending>) {
    fn walk(config: &Config, dir: &Path, depth: u32, pending: &mut BTreeMap<PathBuf, Pending>) {
        let Ok(entries) = std::fs::read_dir(dir) else {
            tracing::warn!(folder = %dir.display(), "Cannot list a folder (share down?).");
            return;
        };
        let mut paths: Vec<PathBuf> = entries.filter_map(|e| e.ok().map(|e| e.path())).collect();
        paths.sort();
        for p in paths {
            if p.is_dir() {
                if depth < 4 {
                    walk(config, &p, depth + 1, pending);
                }
            } else {
                consider(config, &p, pending);
            }
        }
    }
    for f in &config.folders {
        walk(config, &f.path, 0, pending);
    }
}

#[cfg(test)]
mod tests {
    use super::rfc3339;

    #[test]
    fn formats_utc() {
        assert_eq!(rfc3339(0, 0), "1970-01-01T00:00:00.000Z");
        assert_eq!(rfc3339(1_795_307_239, 5), "2026-11-22T00:27:19.005Z");
        assert_eq!(rfc3339(951_782_400, 0), "2000-02-29T00:00:00.000Z");
    }
}

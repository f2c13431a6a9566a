//! The watch daemon: the only code that knows tokio, notify and systemd.
//!
//! One `tokio::select!` loop consumes a closed set of events (file-system events, ticks,
//! worker results, signals). A file is handed to the worker thread once its size and mtime
//! have held still for `settle_ms`. The worker owns the database connection and ingests one
//! file at a time, each in one transaction, so a kill at any moment loses nothing: the
//! catch-up scan at the next start finds what was not stored.
//!
//! the only tokio/notify/systemd code: `mod.rs` (select loop; `trigger`
//! classifies events, so opens and reads never queue a file; settle logic with the writer's
//! `IN_CLOSE_WRITE`; shares looked at every second, re-armed and rescanned alone when down,
//! back or remounted; links out of a share, hard links and files that are not regular (FIFOs,
//! sockets, devices) refused once; names logged as escaped text (`sharefile::path_text`); a
//! bounded pool of workers, each with its own connection, a worker past `worker_timeout_s`
//! replaced and its file quarantined; catch-up progress; signals, a stop bounded in time; the
//! watchdog pinged only while work advances), `workers.rs` (the pool), `ingest.rs` (one file → one
//! revision: a read checked against the settled state, pairing and diff inside the revision's
//! transaction, `Reader` rebuilding a stored plan from its bytes and reading called programs
//! beside the program, then in the CAM folders, noting the names each run asked for
//! (`calls`); a stored revision of a called program compares again every program that calls
//! it and has a comparison, naming it in the rule; `reconcile` at start, `import_file`),
//! `systemd.rs` (sd_notify).

pub mod ingest;
mod systemd;
mod workers;

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant, SystemTime};

use anyhow::{Context, Result};
use notify::{PollWatcher, RecommendedWatcher, RecursiveMode, Watcher};
use tokio::sync::mpsc;

use crate::config::Config;
use crate::dialect::Registry;
use crate::sharefile::path_text;
pub use ingest::{Outcome, Snapshot, ingest};
use systemd::Notifier;
use workers::{Job, Pool};

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
    Fs { folder: usize, event: notify::Result<notify::Event> },
    Done { path: PathBuf, folder: usize, result: Result<Outcome>, elapsed: Duration },
}

/// What a file-system event means for the file it names.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Trigger {
    /// The content may have changed (created, written, renamed into place).
    Content,
    /// A writer closed the file after writing (inotify `IN_CLOSE_WRITE`).
    Closed,
    /// Nothing that changes content: opens, reads, closes without writing, attribute changes
    /// on a native share, removals. The daemon's own reads are such events.
    Ignore,
}

/// Classifies an event kind. A poll watcher reports a changed mtime as a metadata change,
/// so there metadata counts as content; a native watcher reports writes as such.
pub fn trigger(kind: &notify::EventKind, polled: bool) -> Trigger {
    use notify::EventKind as K;
    use notify::event::{AccessKind, AccessMode, ModifyKind};
    match kind {
        K::Access(AccessKind::Close(AccessMode::Write)) => Trigger::Closed,
        K::Access(_) | K::Remove(_) => Trigger::Ignore,
        K::Modify(ModifyKind::Metadata(_)) if !polled => Trigger::Ignore,
        K::Create(_) | K::Modify(_) | K::Any | K::Other => Trigger::Content,
    }
}

struct Pending {
    folder: usize,
    size: u64,
    mtime: Option<SystemTime>,
    /// When size or mtime last changed.
    since: Instant,
    /// A native share said it was written and has not said that the writer closed it.
    writing: bool,
}

/// A file still open for writing is taken anyway once it held still this many settle windows
/// (a writer that died holding it); the partial-write mark catches it if it grows later.
const OPEN_WRITER_SETTLES: u32 = 60;

/// A watched folder's state: its watcher, and the identity (device, inode) it was armed on.
struct Share {
    watcher: Option<Box<dyn Watcher + Send>>,
    identity: Option<(u64, u64)>,
    /// Whether the folder could be read at the last look; state changes are logged once.
    up: bool,
    /// The folder's real path (links resolved): stored content must lie below it.
    root: PathBuf,
}

/// Runs the daemon until SIGTERM or SIGINT.
pub fn run(config: Config, registry: Registry, clock: Arc<dyn Clock>) -> Result<()> {
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().context("cannot start the runtime")?;
    runtime.block_on(main_loop(config, registry, clock))
}

struct Daemon {
    config: Arc<Config>,
    shares: Vec<Share>,
    pending: BTreeMap<PathBuf, Pending>,
    in_flight: BTreeSet<PathBuf>,
    /// Paths refused (links out of a share), said once each.
    refused: BTreeSet<PathBuf>,
    /// Paths inside a share the watcher reported errors on, said once each.
    said: BTreeSet<PathBuf>,
    tx: mpsc::UnboundedSender<Event>,
}

/// The daemon's life: workers started, shares armed and scanned (the catch-up), then the
/// event loop until a signal, then the file in progress finished.
async fn main_loop(config: Config, registry: Registry, clock: Arc<dyn Clock>) -> Result<()> {
    let notifier = Notifier::from_env();
    let stores = workers::open_stores(&config, &registry)?;
    let config = Arc::new(config);
    let registry = Arc::new(registry);
    let (tx, mut rx) = mpsc::unbounded_channel::<Event>();
    let roots: Vec<PathBuf> = config.folders.iter().map(|f| std::fs::canonicalize(&f.path).unwrap_or_else(|_| f.path.clone())).collect();
    let mut pool = Pool::start(stores, &config, &registry, &tx, &clock)?;

    let shares = roots.into_iter().map(|root| Share { watcher: None, identity: None, up: true, root }).collect();
    let mut d = Daemon {
        config: Arc::clone(&config),
        shares,
        pending: BTreeMap::new(),
        in_flight: BTreeSet::new(),
        refused: BTreeSet::new(),
        said: BTreeSet::new(),
        tx,
    };
    for i in 0..config.folders.len() {
        d.check_share(i, true);
    }
    tracing::info!(files = d.pending.len(), "Catch-up scan queued.");
    let mut catch_up = CatchUp { files: d.pending.len(), looked: 0, stored: 0, started: Instant::now(), said: Instant::now(), done: false };
    notifier.notify("READY=1");
    notifier.notify(&format!("STATUS=Watching {} folders.", config.folders.len()));

    let settle = Duration::from_millis(config.settle_ms);
    let mut tick = tokio::time::interval((settle / 4).max(Duration::from_millis(25)));
    let mut rescan = tokio::time::interval(Duration::from_secs(config.rescan_s));
    rescan.tick().await;
    let mut health = tokio::time::interval(Duration::from_secs(1));
    let mut watchdog = tokio::time::interval(notifier.watchdog_interval().unwrap_or(Duration::from_secs(3600)));
    let mut sigterm = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate())?;
    let mut sigint = tokio::signal::unix::signal(tokio::signal::unix::SignalKind::interrupt())?;

    let mut stalled = false;
    let end = loop {
        tokio::select! {
            Some(event) = rx.recv() => match event {
                Event::Fs { folder, event: Ok(ev) } => d.file_event(folder, &ev),
                Event::Fs { folder, event: Err(error) } => d.watch_failed(folder, &error),
                Event::Done { path, folder, result, elapsed } => {
                    catch_up.finished(&result);
                    d.finished(path, folder, result, elapsed);
                }
            },
            _ = tick.tick() => {
                catch_up.report(d.pending.is_empty() && d.in_flight.is_empty());
                if let Err(error) = d.hand_out_settled(settle, &pool).and_then(|()| d.give_up_stuck(&mut pool)) {
                    break Err(error);
                }
            }
            _ = rescan.tick() => d.rescan(),
            _ = health.tick() => d.check_shares(),
            _ = watchdog.tick() => {
                // Pinged only while work advances: a main loop that runs while every worker
                // is stuck is no sign of health.
                let advancing = pool.advancing();
                if advancing {
                    notifier.notify("WATCHDOG=1");
                } else if !stalled {
                    tracing::error!("No worker advances; the watchdog is no longer pinged.");
                }
                stalled = !advancing;
            }
            _ = sigterm.recv() => break Ok(()),
            _ = sigint.recv() => break Ok(()),
        }
    };
    tracing::info!(seconds = STOP_GRACE.as_secs(), "Stopping: finishing the files in progress, within the stop bound.");
    notifier.notify("STOPPING=1");
    drop(d);
    pool.stop(STOP_GRACE).await;
    end
}

/// How long a stop waits for the files in progress. A worker cut short loses nothing (a file
/// is stored in one transaction, and the catch-up scan at the next start finds it), so a stop
/// never waits on a stuck worker beyond this.
const STOP_GRACE: Duration = Duration::from_secs(10);

/// Progress of the first pass over what the folders already hold: a line every 10 s while it
/// lasts (a first start over a large archive), and one when it is done.
struct CatchUp {
    files: usize,
    looked: usize,
    stored: usize,
    started: Instant,
    said: Instant,
    done: bool,
}

impl CatchUp {
    /// A worker finished a file (stored or not).
    fn finished(&mut self, result: &Result<Outcome>) {
        self.looked += 1;
        self.stored += usize::from(matches!(result, Ok(Outcome::Stored { .. })));
    }

    /// Says how far the catch-up is (every 10 s), or that it is done once nothing is pending
    /// or in flight (`idle`).
    fn report(&mut self, idle: bool) {
        if self.done {
            return;
        }
        if idle {
            self.done = true;
            if self.files > 0 {
                tracing::info!(
                    files = self.files,
                    stored = self.stored,
                    seconds = self.started.elapsed().as_secs(),
                    "Caught up with the folders."
                );
            }
        } else if self.said.elapsed() >= Duration::from_secs(10) {
            self.said = Instant::now();
            tracing::info!(done = self.looked, of = self.files, stored = self.stored, "Catching up with the folders.");
        }
    }
}

fn identity(meta: &std::fs::Metadata) -> (u64, u64) {
    use std::os::unix::fs::MetadataExt;
    (meta.dev(), meta.ino())
}

impl Daemon {
    /// A file-system event from the watcher of `folder`: a rescan when the event queue
    /// overflowed, then the files it names queued (content events) or marked closed.
    fn file_event(&mut self, folder: usize, ev: &notify::Event) {
        if ev.need_rescan() {
            tracing::warn!(folder = %path_text(&self.config.folders[folder].path), "The event queue overflowed; rescanning the folder.");
            self.scan(folder);
        }
        let polled = self.config.folders[folder].poll;
        match trigger(&ev.kind, polled) {
            Trigger::Ignore => {}
            Trigger::Content => {
                let written = matches!(ev.kind, notify::EventKind::Modify(notify::event::ModifyKind::Data(_))) && !polled;
                for p in &ev.paths {
                    self.consider(p, written);
                }
            }
            Trigger::Closed => {
                for p in &ev.paths {
                    if let Some(entry) = self.pending.get_mut(p) {
                        entry.writing = false;
                    }
                }
            }
        }
    }

    /// A worker's outcome for `path`, logged; a file that changed while it was read settles
    /// again, a refused one is said once.
    fn finished(&mut self, path: PathBuf, folder: usize, result: Result<Outcome>, elapsed: Duration) {
        self.in_flight.remove(&path);
        match result {
            Ok(Outcome::Stored { revision, changes, compared }) => {
                tracing::info!(path = %path_text(&path), revision, ?changes, compared, ms = elapsed.as_millis() as u64, "Stored a revision.")
            }
            Ok(Outcome::Unchanged) => tracing::debug!(path = %path_text(&path), "Content unchanged."),
            Ok(Outcome::Gone) => tracing::debug!(path = %path_text(&path), "File vanished."),
            Ok(Outcome::Changing) => {
                tracing::debug!(path = %path_text(&path), "The file changed while it was read; it must settle again.");
                self.queue(path, folder, false);
            }
            Ok(Outcome::Refused(why)) => self.refuse(&path, &why),
            Err(error) => {
                // Runtime error: keep the file for the next rescan and go on.
                tracing::error!(path = %path_text(&path), error = format!("{error:#}"), "Could not ingest a file; it will be retried.");
            }
        }
    }

    /// Hands each file that settled to the workers. An error when they have stopped.
    fn hand_out_settled(&mut self, settle: Duration, pool: &Pool) -> Result<()> {
        for (path, folder, snapshot) in self.settled(settle) {
            tracing::debug!(path = %path_text(&path), "Queued a settled file.");
            self.in_flight.insert(path.clone());
            let root = self.shares[folder].root.clone();
            pool.send(Job { path, folder, snapshot, root, quarantine: false })?;
        }
        Ok(())
    }

    /// Workers past the worker bound: each is reported and replaced, and its file handed out
    /// again to be quarantined (stored unanalysed, so that the content is not tried again). An
    /// error, which ends the daemon for its service manager to start it again, when the
    /// threads given up outnumber the pool: only a new process frees the cores they hold.
    fn give_up_stuck(&mut self, pool: &mut Pool) -> Result<()> {
        for (job, ran) in pool.overdue() {
            tracing::error!(
                path = %path_text(&job.path),
                seconds = ran.as_secs(),
                bound_s = self.config.worker_timeout_s,
                "A worker did not finish a file within the worker bound; it is replaced and the file quarantined (stored without analysis)."
            );
            pool.send(Job { quarantine: true, ..job })?;
        }
        if pool.stuck() > workers::worker_count(&self.config) {
            anyhow::bail!(
                "{} workers are stuck past the worker bound; stopping so that the service manager starts ncplan afresh",
                pool.stuck()
            );
        }
        Ok(())
    }

    /// The periodic full rescan of every share that is up.
    fn rescan(&mut self) {
        for i in 0..self.config.folders.len() {
            if self.shares[i].up {
                self.scan(i);
            }
        }
    }

    /// The health check: each share looked at again (see [`Daemon::check_share`]).
    fn check_shares(&mut self) {
        for i in 0..self.config.folders.len() {
            self.check_share(i, false);
        }
    }

    /// Looks at a share: arms its watcher when it is up and has none, and re-arms it (and
    /// rescans the folder) when the folder was replaced or remounted, which a watch on the old
    /// folder would never report. Each change of state is logged once.
    fn check_share(&mut self, i: usize, first: bool) {
        let f = &self.config.folders[i];
        let meta = std::fs::metadata(&f.path).ok().filter(std::fs::Metadata::is_dir);
        let Some(meta) = meta else {
            let share = &mut self.shares[i];
            if share.up || first {
                tracing::warn!(folder = %path_text(&f.path), machine = %f.name, "The share cannot be read (down or unmounted); watching for it to come back.");
            }
            share.up = false;
            share.watcher = None;
            return;
        };
        let id = identity(&meta);
        let share = &self.shares[i];
        if share.up && share.watcher.is_some() && share.identity == Some(id) {
            return;
        }
        let (was_up, was_armed, replaced) = (share.up, share.identity.is_some(), share.identity.is_some_and(|old| old != id));
        self.shares[i].watcher = None;
        match self.arm(i) {
            Ok(w) => {
                let share = &mut self.shares[i];
                share.watcher = Some(w);
                share.identity = Some(id);
                share.up = true;
                share.root = std::fs::canonicalize(&f.path).unwrap_or_else(|_| f.path.clone());
                if replaced {
                    tracing::warn!(folder = %path_text(&f.path), machine = %f.name, "The share was remounted or replaced; watching it again and rescanning it.");
                } else if was_armed || !was_up {
                    tracing::warn!(folder = %path_text(&f.path), machine = %f.name, "The share is back; watching it again and rescanning it.");
                } else {
                    tracing::info!(folder = %path_text(&f.path), machine = %f.name, dialect = %f.dialect, poll = f.poll, "Watching a folder.");
                }
                self.scan(i);
            }
            Err(error) => {
                let share = &mut self.shares[i];
                if share.up || first {
                    tracing::error!(folder = %path_text(&f.path), %error, "Cannot watch a folder; retrying every second.");
                }
                share.up = false;
            }
        }
    }

    fn arm(&self, i: usize) -> notify::Result<Box<dyn Watcher + Send>> {
        let f = &self.config.folders[i];
        let tx = self.tx.clone();
        let handler = move |event: notify::Result<notify::Event>| {
            let _ = tx.send(Event::Fs { folder: i, event });
        };
        // Links are never followed by the watcher: what a link leads to is judged per file.
        let cfg = notify::Config::default().with_follow_symlinks(false);
        let mut w: Box<dyn Watcher + Send> = if f.poll {
            Box::new(PollWatcher::new(handler, cfg.with_poll_interval(Duration::from_millis(f.poll_ms)))?)
        } else {
            Box::new(RecommendedWatcher::new(handler, cfg)?)
        };
        w.watch(&f.path, RecursiveMode::Recursive)?;
        Ok(w)
    }

    /// A watcher reported an error: the watch may be dead, so the share is looked at again
    /// at the next health check (which re-arms and rescans it), and the error is said once.
    fn watch_failed(&mut self, folder: usize, error: &notify::Error) {
        let f = &self.config.folders[folder];
        // An error about something inside a share that can still be read (an unreadable
        // subfolder, a file that vanished while polled) is said once per path; the watch lives.
        if std::fs::read_dir(&f.path).is_ok() && !error.paths.is_empty() && !error.paths.contains(&f.path) {
            for p in &error.paths {
                if self.said.insert(p.clone()) {
                    tracing::warn!(path = %path_text(p), %error, "The watcher cannot read a path inside the share.");
                }
            }
            return;
        }
        let share = &mut self.shares[folder];
        if share.up {
            tracing::warn!(folder = %path_text(&f.path), %error, "The watcher reported an error; the share is looked at again.");
        }
        share.up = false;
        share.watcher = None;
    }

    /// A file that is not read (a link out of the share, a hard link, not a regular file),
    /// said once until it changes.
    fn refuse(&mut self, path: &Path, why: &str) {
        if self.refused.insert(path.to_path_buf()) {
            tracing::warn!(path = %path_text(path), reason = why, "Refused a file of the watched folder; it is not read.");
        }
        self.pending.remove(path);
    }

    /// Queues `path` if it is a program file of a watched folder.
    fn consider(&mut self, path: &Path, written: bool) {
        let Some(folder) = self.config.folder_at(path) else { return };
        let Ok(rel) = path.strip_prefix(&self.config.folders[folder].path) else { return };
        // Editor and temporary files, and anything inside hidden folders, are not programs; a
        // name that is not UTF-8 (Latin-1 from a Windows share) is judged by its readable part.
        if rel.components().any(|c| self.config.ignored(&c.as_os_str().to_string_lossy())) {
            return;
        }
        let Ok(meta) = std::fs::symlink_metadata(path) else { return };
        if meta.file_type().is_symlink() {
            match std::fs::canonicalize(path) {
                Ok(real) if !real.starts_with(&self.shares[folder].root) => {
                    return self.refuse(path, &format!("it leads to {}, outside the watched folder", path_text(&real)));
                }
                Ok(real) if real.is_dir() => return,
                Ok(_) => {}
                Err(_) => return,
            }
        } else if meta.is_dir() {
            return;
        }
        // What the path leads to: a regular file with one name, or refused (FIFOs, sockets,
        // devices, hard links), said once.
        match std::fs::metadata(path) {
            Ok(m) => {
                if let Some(why) = ingest::refusal_of(&m) {
                    return self.refuse(path, &why);
                }
            }
            Err(_) => return,
        }
        self.refused.remove(path);
        self.queue(path.to_path_buf(), folder, written);
    }

    fn queue(&mut self, path: PathBuf, folder: usize, written: bool) {
        let entry =
            self.pending.entry(path).or_insert(Pending { folder, size: u64::MAX, mtime: None, since: Instant::now(), writing: false });
        entry.folder = folder;
        entry.writing |= written;
    }

    /// The pending files whose size and mtime held still for `settle` (and whose writer closed
    /// them, where the share tells), removed from the pending set with the state they settled in.
    fn settled(&mut self, settle: Duration) -> Vec<(PathBuf, usize, Snapshot)> {
        let now = Instant::now();
        let mut ready = Vec::new();
        let in_flight = &self.in_flight;
        self.pending.retain(|path, p| {
            let Ok(meta) = std::fs::metadata(path) else { return false };
            let (size, mtime) = (meta.len(), meta.modified().ok());
            if size != p.size || mtime != p.mtime {
                (p.size, p.mtime, p.since) = (size, mtime, now);
                return true;
            }
            let still = now.duration_since(p.since);
            let closed = !p.writing || still >= settle * OPEN_WRITER_SETTLES;
            if still >= settle && closed && !in_flight.contains(path) {
                ready.push((path.clone(), p.folder, Snapshot { size, mtime }));
                return false;
            }
            true
        });
        ready
    }

    /// Queues every program file of a folder (`Config::program_files`); the worker skips
    /// unchanged content.
    fn scan(&mut self, folder: usize) {
        let config = Arc::clone(&self.config);
        match config.program_files(&config.folders[folder]) {
            Ok(files) => {
                for p in files {
                    self.consider(&p, false);
                }
            }
            Err(error) => {
                if self.shares[folder].up {
                    tracing::warn!(folder = %path_text(&config.folders[folder].path), %error, "Cannot list a folder (share down?).");
                }
                self.shares[folder].up = false;
                self.shares[folder].watcher = None;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::rfc3339;

    #[test]
    fn only_events_that_can_change_content_queue_a_file() {
        use super::{Trigger, trigger};
        use notify::EventKind as K;
        use notify::event::{AccessKind, AccessMode, CreateKind, DataChange, MetadataKind, ModifyKind, RemoveKind, RenameMode};
        // The daemon's own reads: opening, reading and closing without writing.
        for k in [
            K::Access(AccessKind::Open(AccessMode::Any)),
            K::Access(AccessKind::Read),
            K::Access(AccessKind::Close(AccessMode::Read)),
            K::Remove(RemoveKind::File),
        ] {
            assert_eq!(trigger(&k, false), Trigger::Ignore, "{k:?}");
            assert_eq!(trigger(&k, true), Trigger::Ignore, "{k:?}");
        }
        let attrib = K::Modify(ModifyKind::Metadata(MetadataKind::Any));
        assert_eq!(trigger(&attrib, false), Trigger::Ignore);
        // A poll watcher reports a new mtime as a metadata change.
        assert_eq!(trigger(&K::Modify(ModifyKind::Metadata(MetadataKind::WriteTime)), true), Trigger::Content);
        for k in [K::Create(CreateKind::File), K::Modify(ModifyKind::Data(DataChange::Any)), K::Modify(ModifyKind::Name(RenameMode::To))] {
            assert_eq!(trigger(&k, false), Trigger::Content, "{k:?}");
        }
        assert_eq!(trigger(&K::Access(AccessKind::Close(AccessMode::Write)), false), Trigger::Closed);
    }

    #[test]
    fn formats_utc() {
        assert_eq!(rfc3339(0, 0), "1970-01-01T00:00:00.000Z");
        assert_eq!(rfc3339(1_795_307_239, 5), "2026-11-22T00:27:19.005Z");
        assert_eq!(rfc3339(951_782_400, 0), "2000-02-29T00:00:00.000Z");
    }
}

//! `ncplan import`: a shop's existing program folder, or its dated backups, stored as
//! revisions of one machine's (or the CAM folder's) programs with their file times, so that
//! a new installation starts with history.
//!
//! Shell code. Files are grouped by program (their file name: `2024-03-01/O1234.nc` and
//! `2024-05-12/O1234.nc` are two revisions of the share's `O1234.nc`). A file under a folder
//! named by its date (`2024-03-01`, `2024-03-01_late`) was saved that day, whatever its file
//! time says (a copy or a checkout dates every file the day it was made): its time is the
//! file time where that falls on the folder's day, else noon of that day. Each program's
//! files go, oldest first, to one worker of a pool with a connection each, so that every core
//! analyses and each program's revisions are stored in time order. Content a program already
//! has is skipped, so an import that was killed resumes where it was.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::{Duration, Instant, SystemTime};

use anyhow::{Context, Result};

use crate::config::{Config, Folder};
use crate::daemon::{Outcome, ingest};
use crate::dialect::Registry;
use crate::store::Store;

/// What an import did.
#[derive(Debug, Default, Clone, PartialEq, Eq)]
pub struct Summary {
    /// Files found.
    pub files: usize,
    /// Programs they are revisions of.
    pub programs: usize,
    /// Revisions stored.
    pub stored: usize,
    /// Files whose content their program already had (an earlier import, a copy).
    pub known: usize,
    /// Stored revisions compared with their CAM original.
    pub compared: usize,
    /// Files that could not be read or stored, with the reason.
    pub errors: Vec<(PathBuf, String)>,
    /// Wall time.
    pub elapsed: Duration,
}

/// The files under `dir` (any depth, links not followed, editor and temp files skipped),
/// grouped by program file name, each group sorted by file time then path.
pub fn programs(config: &Config, dir: &Path) -> Result<BTreeMap<String, Vec<(PathBuf, SystemTime)>>> {
    fn walk(config: &Config, dir: &Path, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
        for e in std::fs::read_dir(dir)?.flatten() {
            let (p, Ok(kind)) = (e.path(), e.file_type()) else { continue };
            if p.file_name().is_none_or(|n| config.ignored(&n.to_string_lossy())) {
                continue;
            }
            if kind.is_dir() {
                walk(config, &p, out)?;
            } else if kind.is_file() {
                out.push(p);
            }
        }
        Ok(())
    }
    let mut files = Vec::new();
    walk(config, dir, &mut files).with_context(|| format!("cannot list {}", dir.display()))?;
    let mut groups: BTreeMap<String, Vec<(PathBuf, SystemTime)>> = BTreeMap::new();
    for f in files {
        let mtime = std::fs::metadata(&f).and_then(|m| m.modified()).unwrap_or(SystemTime::UNIX_EPOCH);
        let mtime = folder_day(dir, &f).map_or(mtime, |day| on_day(mtime, day));
        let name = f.file_name().map(crate::sharefile::os_text).unwrap_or_default();
        groups.entry(name).or_default().push((f, mtime));
    }
    for g in groups.values_mut() {
        g.sort_by(|a, b| a.1.cmp(&b.1).then_with(|| a.0.cmp(&b.0)));
    }
    Ok(groups)
}

/// The day (since 1970) of the innermost folder between `dir` and `file` named by a date
/// (`YYYY-MM-DD`, maybe followed by more).
fn folder_day(dir: &Path, file: &Path) -> Option<i64> {
    let rel = file.strip_prefix(dir).ok()?.parent()?;
    rel.components().rev().find_map(|c| {
        let name = c.as_os_str().to_str()?;
        let date = name.get(..10)?;
        let shaped = date.bytes().enumerate().all(|(i, b)| if i == 4 || i == 7 { b == b'-' } else { b.is_ascii_digit() });
        let day = crate::suggest::day_number(date).filter(|_| shaped)?;
        // A real date: it reads back the same (no 2024-02-31).
        let back = crate::daemon::rfc3339(day * 86_400, 0);
        back.starts_with(date).then_some(day)
    })
}

/// `t` where it falls on `day`, else noon of `day` (UTC).
fn on_day(t: SystemTime, day: i64) -> SystemTime {
    let secs = t.duration_since(SystemTime::UNIX_EPOCH).map_or(0, |d| d.as_secs() as i64);
    if secs.div_euclid(86_400) == day {
        return t;
    }
    let noon = day * 86_400 + 12 * 3600;
    if noon >= 0 { SystemTime::UNIX_EPOCH + Duration::from_secs(noon as u64) } else { SystemTime::UNIX_EPOCH }
}

fn rfc3339(t: SystemTime) -> String {
    let d = t.duration_since(SystemTime::UNIX_EPOCH).unwrap_or_default();
    crate::daemon::rfc3339(d.as_secs() as i64, d.subsec_millis())
}

/// Imports `dir` into `folder` (a configured machine share or CAM folder): each file becomes
/// a revision of `folder/<file name>` seen at its file time. `progress(done, total)` is called
/// after each file.
pub fn run(
    config: &Config,
    registry: &Registry,
    folder: &Folder,
    dir: &Path,
    workers: usize,
    progress: &(dyn Fn(usize, usize) + Sync),
) -> Result<Summary> {
    let started = Instant::now();
    let groups = programs(config, dir)?;
    let total: usize = groups.values().map(Vec::len).sum();
    let mut summary = Summary { files: total, programs: groups.len(), ..Summary::default() };
    if let Some(parent) = config.database.file().and_then(Path::parent) {
        std::fs::create_dir_all(parent).with_context(|| format!("cannot create {}", parent.display()))?;
    }
    let queue = Mutex::new(groups.into_iter().collect::<Vec<_>>().into_iter());
    let done = AtomicUsize::new(0);
    let result = Mutex::new(Summary::default());
    let workers = workers.max(1);
    let mut stores = Vec::with_capacity(workers);
    for _ in 0..workers {
        let mut s = Store::open(&config.database, &config.site).with_context(|| format!("cannot open the database {}", config.database))?;
        s.set_busy_timeout(Duration::from_secs(600))?;
        stores.push(s);
    }
    std::thread::scope(|scope| {
        for mut store in stores {
            let (queue, done, result) = (&queue, &done, &result);
            scope.spawn(move || {
                loop {
                    let next = queue.lock().ok().and_then(|mut q| q.next());
                    let Some((name, files)) = next else { break };
                    let stored_as = folder.path.join(crate::sharefile::text_path(&name));
                    for (file, mtime) in files {
                        let outcome = ingest::import_file(&file, &stored_as, folder, config, registry, &mut store, &rfc3339(mtime));
                        if let Ok(mut r) = result.lock() {
                            match outcome {
                                Ok(Outcome::Stored { changes, compared, .. }) => {
                                    r.stored += 1;
                                    r.compared += usize::from(changes.is_some()) + compared;
                                }
                                Ok(Outcome::Unchanged) => r.known += 1,
                                Ok(other) => r.errors.push((file.clone(), format!("{other:?}"))),
                                Err(e) => r.errors.push((file.clone(), format!("{e:#}"))),
                            }
                        }
                        progress(done.fetch_add(1, Ordering::Relaxed) + 1, total);
                    }
                }
            });
        }
    });
    let r = result.into_inner().unwrap_or_default();
    summary.stored = r.stored;
    summary.known = r.known;
    summary.compared = r.compared;
    summary.errors = r.errors;
    summary.errors.sort();
    summary.elapsed = started.elapsed();
    Ok(summary)
}

#[cfg(test)]
mod tests {
    use std::path::Path;
    use std::time::{Duration, SystemTime};

    #[test]
    fn a_dated_folder_gives_the_day() {
        let dir = Path::new("/backups/m1");
        let day = crate::suggest::day_number("2026-03-14");
        assert_eq!(super::folder_day(dir, Path::new("/backups/m1/2026-03-14/O1.nc")), day);
        assert_eq!(super::folder_day(dir, Path::new("/backups/m1/2026-03-14_late/x/O1.nc")), day);
        assert_eq!(super::folder_day(dir, Path::new("/backups/m1/2026-02-31/O1.nc")), None, "no such day");
        assert_eq!(super::folder_day(dir, Path::new("/backups/m1/010/O1.nc")), None);
        assert_eq!(super::folder_day(Path::new("/2026-03-14"), Path::new("/2026-03-14/O1.nc")), None, "only below the imported folder");
        let day = day.unwrap();
        let same = SystemTime::UNIX_EPOCH + Duration::from_secs((day * 86_400 + 8 * 3600) as u64);
        assert_eq!(super::on_day(same, day), same);
        let later = SystemTime::UNIX_EPOCH + Duration::from_secs(((day + 200) * 86_400) as u64);
        assert_eq!(super::on_day(later, day), SystemTime::UNIX_EPOCH + Duration::from_secs((day * 86_400 + 12 * 3600) as u64));
    }
}

//! `ncplan reanalyze` and `ncplan worker`: read every stored revision again with today's
//! dictionary and engine, the revisions queued and worked by all cores (and other hosts).

use std::io::Write;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{Context, Result, bail};

use super::common::{WorkArgs, load_config, registry_for};
use crate::store::{Location, Store};

/// The arguments of `ncplan reanalyze`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    /// Only revisions seen on or after this date (or RFC 3339 time).
    #[arg(long)]
    since: Option<String>,
    /// Only programs read in this dialect.
    #[arg(long)]
    dialect: Option<String>,
    #[command(flatten)]
    work: WorkArgs,
}

/// Runs `ncplan reanalyze`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { since, dialect, work } = args;
    reanalyze(&mut out, &work, Some((since.as_deref(), dialect.as_deref())))
}

/// The arguments of `ncplan worker`.
#[derive(Debug, clap::Args)]
pub(super) struct WorkerArgs {
    #[command(flatten)]
    work: WorkArgs,
}

/// Runs `ncplan worker`.
pub(super) fn worker(args: WorkerArgs, mut out: impl Write) -> Result<ExitCode> {
    let WorkerArgs { work } = args;
    reanalyze(&mut out, &work, None)
}

/// `reanalyze` (queueing what `filter` selects) and `worker`.
fn reanalyze(out: &mut impl Write, work: &WorkArgs, filter: Option<(Option<&str>, Option<&str>)>) -> Result<ExitCode> {
    let config = load_config(work.config.as_deref())?;
    let registry = registry_for(Some(&config))?;
    let db = work.db.as_deref().map_or_else(|| config.database.clone(), Location::parse);
    if !db.exists() {
        bail!("no database at {db} (has `ncplan watch` run?)");
    }
    let jobs = work.jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get)).max(1);
    let mut stores = Vec::with_capacity(jobs);
    for _ in 0..jobs {
        let mut s = Store::open(&db, &config.site).with_context(|| format!("cannot open the database {db}"))?;
        s.set_busy_timeout(Duration::from_secs(600))?;
        stores.push(s);
    }
    let version = crate::reanalyze::version(&config)?;
    let queued = match filter {
        Some((since, dialect)) => stores[0].queue_reanalysis(&version, since, dialect)?,
        None => stores[0].reanalysis_left(&version)?,
    };
    let host = std::fs::read_to_string("/proc/sys/kernel/hostname").map(|h| h.trim().to_owned()).unwrap_or_else(|_| "host".into());
    let worker = format!("{host}:{}", std::process::id());
    let bar = indicatif::ProgressBar::new(queued as u64);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} revisions, {per_sec}, {eta} left")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let progress = |done: usize, left: usize| {
        bar.set_length((done + left) as u64);
        bar.set_position(done as u64);
    };
    let summary = crate::reanalyze::work(&config, &registry, stores, &version, &worker, Duration::from_secs(work.lease), &progress)?;
    bar.finish_and_clear();
    writeln!(
        out,
        "analysis {version}: {} revisions read again, {} plans changed, {} new findings, {} vanished; {} comparisons made again; {} done by another worker; {} errors",
        summary.reread,
        summary.plans_changed,
        summary.new_findings,
        summary.vanished_findings,
        summary.compared,
        summary.skipped,
        summary.errors.len()
    )?;
    for (id, why) in &summary.errors {
        writeln!(out, "  revision {id}: {why}")?;
    }
    out.flush()?;
    Ok(if summary.errors.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

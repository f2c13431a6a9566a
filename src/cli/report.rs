//! `ncplan report`: the shopfloor change report, as Markdown, one self-contained HTML file,
//! or the change rows as CSV.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};
use clap::ValueEnum;

use super::common::{StoreArgs, db_path, demo_config_here, load_config, registry_for};
use crate::config::Config;
use crate::pipeline::{self, Change};
use crate::store::{Location, Store};

/// The arguments of `ncplan report`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    #[command(flatten)]
    store: StoreArgs,
    /// First wait until every file in the watched folders is stored (at most this many
    /// seconds; 30 when given without a number), so that a file just copied is reported.
    #[arg(long, num_args = 0..=1, default_missing_value = "30", value_name = "SECONDS")]
    wait: Option<u64>,
    #[arg(long, value_enum, default_value = "markdown")]
    format: ReportFormat,
    /// Write the report to this file instead of standard output.
    #[arg(long, short)]
    output: Option<PathBuf>,
    /// Only changes detected on or after this date (YYYY-MM-DD, UTC), in every format.
    #[arg(long, value_name = "DATE", value_parser = parse_date)]
    since: Option<String>,
    /// Only changes of this machine (a configured or stored one), in every format.
    #[arg(long, value_name = "NAME")]
    machine: Option<String>,
    /// Leave out changes of what a program only shows or writes (messages, prints:
    /// `output_changed`).
    #[arg(long)]
    machining_only: bool,
}

/// Runs `ncplan report`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { store, wait, format, output, since, machine, machining_only } = args;
    if let Some(seconds) = wait {
        let config = match &store.config {
            Some(p) => load_config(Some(p))?,
            None => demo_config_here()?,
        };
        let db = store.db.as_deref().map_or_else(|| config.database.clone(), Location::parse);
        let left = wait_until_stored(&config, &db, Duration::from_secs(seconds))?;
        if left > 0 {
            eprintln!("ncplan: {left} files in the watched folders are not stored yet (is `ncplan watch` running?); reporting what is");
        }
    }
    let db = db_path(&store)?;
    let config_path = store.config.clone();
    let store = Store::open_read_only(&db)?;
    if let Some(m) = &machine {
        check_machine(&store, config_path.as_deref(), m)?;
    }
    let filter = crate::web::report::Filter { since, machine, machining_only };
    let text = match format {
        ReportFormat::Markdown => {
            let mut buf = Vec::new();
            write_report(&mut buf, &store, &filter)?;
            buf
        }
        ReportFormat::Html => {
            use crate::daemon::Clock;
            // The configuration reads the programs as the daemon did, to draw their toolpaths.
            let config = load_config(config_path.as_deref())?;
            let registry = registry_for(Some(&config))?;
            crate::web::report::html(&store, &config, &registry, &filter, &crate::daemon::SystemClock.now())?.into_bytes()
        }
        ReportFormat::Csv => crate::web::report::csv(&store, &filter)?.into_bytes(),
    };
    match output {
        Some(o) => std::fs::write(&o, text).with_context(|| format!("cannot write {}", o.display()))?,
        None => out.write_all(&text)?,
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ReportFormat {
    Markdown,
    Html,
    Csv,
}

/// Waits until every program file in the configured folders is stored as the newest revision
/// of its path, or `timeout` passed. Returns how many were still not stored.
fn wait_until_stored(config: &Config, db: &Location, timeout: Duration) -> Result<usize> {
    let deadline = Instant::now() + timeout;
    loop {
        let mut files = Vec::new();
        for f in &config.folders {
            files.extend(config.program_files(f).unwrap_or_default().into_iter().filter(|p| Config::stays_inside(f, p)));
        }
        let store = if db.exists() { Store::open_read_only(db).ok().map(|s| s.for_site(&config.site)) } else { None };
        let mut left = 0;
        for p in &files {
            // What the daemon refuses (FIFOs, devices, hard links) is never stored: not waited for.
            let bytes = std::fs::metadata(p)
                .ok()
                .filter(|m| crate::daemon::ingest::refusal_of(m).is_none())
                .and_then(|_| crate::sharefile::read_regular(p, u64::MAX));
            let stored = match (&store, bytes) {
                (Some(s), Some(bytes)) => {
                    s.latest_hash(&crate::sharefile::path_text(p))?.as_deref() == Some(crate::daemon::ingest::sha256_hex(&bytes).as_str())
                }
                (_, None) => true,
                (None, _) => false,
            };
            left += usize::from(!stored);
        }
        if left == 0 || Instant::now() >= deadline {
            return Ok(left);
        }
        std::thread::sleep(Duration::from_millis(100));
    }
}

/// A `--since` date: `YYYY-MM-DD`, a day that exists; anything else is an error, never a
/// filter that silently means nothing.
fn parse_date(s: &str) -> std::result::Result<String, String> {
    let fail = || format!("`{s}` is not a date: give one as YYYY-MM-DD (UTC), such as 2026-12-01");
    let b = s.as_bytes();
    if b.len() != 10 || b[4] != b'-' || b[7] != b'-' || !s.bytes().enumerate().all(|(i, c)| i == 4 || i == 7 || c.is_ascii_digit()) {
        return Err(fail());
    }
    let (year, month, day): (u32, u32, u32) =
        (s[..4].parse().map_err(|_| fail())?, s[5..7].parse().map_err(|_| fail())?, s[8..].parse().map_err(|_| fail())?);
    let leap = year % 4 == 0 && (year % 100 != 0 || year % 400 == 0);
    let days = match month {
        1 | 3 | 5 | 7 | 8 | 10 | 12 => 31,
        4 | 6 | 9 | 11 => 30,
        2 if leap => 29,
        2 => 28,
        _ => return Err(fail()),
    };
    if day == 0 || day > days {
        return Err(fail());
    }
    Ok(s.to_owned())
}

/// `--machine NAME` must name a machine the store has or the configuration (`--config`) lists.
fn check_machine(store: &Store, config: Option<&std::path::Path>, name: &str) -> Result<()> {
    let mut known: Vec<String> = store.machines()?.into_iter().map(|m| m.name).collect();
    if let Some(path) = config {
        let config = load_config(Some(path))?;
        known.extend(config.folders.iter().filter(|f| f.role == crate::config::Role::Machine).map(|f| f.name.clone()));
    }
    if known.iter().any(|k| k == name) {
        return Ok(());
    }
    known.sort();
    known.dedup();
    let list = if known.is_empty() { "none".to_owned() } else { known.join(", ") };
    anyhow::bail!("no machine `{name}` is configured or stored (known: {list})")
}

fn write_report(out: &mut impl Write, store: &Store, filter: &crate::web::report::Filter) -> Result<()> {
    let (_, mut rows) = store.query(
        "SELECT machine, program, original_path, edited_path, revision_id, workingstep, kind, field, before, after, detected_at, operation
         FROM shopfloor_changes ORDER BY machine, program, revision_id, change_id",
    )?;
    // The same filter as the HTML and CSV reports: the machine, and changes detected on or
    // after the day (`detected_at` is RFC 3339 UTC, so it compares as text).
    rows.retain(|r| {
        filter.machine.as_ref().is_none_or(|m| &r[0] == m) && filter.since.as_ref().is_none_or(|s| r[10].as_str() >= s.as_str())
    });
    let machining_only = filter.machining_only;
    writeln!(out, "# Shopfloor changes\n")?;
    if rows.is_empty() {
        writeln!(out, "No changes recorded.")?;
        return Ok(());
    }
    let mut i = 0;
    while i < rows.len() {
        let r = &rows[i];
        writeln!(out, "## machine {}, program {} (revision {}, {})\n", r[0], r[1], r[4], r[10])?;
        writeln!(out, "original `{}`, edited `{}`\n", r[2], r[3])?;
        let revision: i64 = r[4].parse().unwrap_or(0);
        while i < rows.len() && rows[i][4] == r[4] {
            i += 1;
        }
        let mut changes = store.changes(revision)?;
        if machining_only {
            changes.retain(Change::is_machining);
            if changes.is_empty() {
                continue;
            }
        }
        for line in pipeline::render_plain(&changes) {
            writeln!(out, "- {line}")?;
        }
        writeln!(out)?;
    }
    Ok(())
}

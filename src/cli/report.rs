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
    /// Only changes detected on or after this date (YYYY-MM-DD; html and csv).
    #[arg(long, value_name = "DATE")]
    since: Option<String>,
    /// Only changes of this machine (html and csv).
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
    let filter = crate::web::report::Filter { since, machine, machining_only };
    let text = match format {
        ReportFormat::Markdown => {
            let mut buf = Vec::new();
            write_report(&mut buf, &store, machining_only)?;
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
            let stored = match (&store, std::fs::read(p)) {
                (Some(s), Ok(bytes)) => {
                    s.latest_hash(&p.to_string_lossy())?.as_deref() == Some(crate::daemon::ingest::sha256_hex(&bytes).as_str())
                }
                (_, Err(_)) => true,
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

fn write_report(out: &mut impl Write, store: &Store, machining_only: bool) -> Result<()> {
    let (_, rows) = store.query(
        "SELECT machine, program, original_path, edited_path, revision_id, workingstep, kind, field, before, after, detected_at, operation
         FROM shopfloor_changes ORDER BY machine, program, revision_id, change_id",
    )?;
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

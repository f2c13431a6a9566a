//! `ncplan migrate`: copy a site's history, every table of it, between a SQLite file and the
//! plant's PostgreSQL database.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};

use super::common::load_config;
use crate::store::{Location, Store};

/// The arguments of `ncplan migrate`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    /// Where the history is: a SQLite file (`var/ncplan.db`) or a PostgreSQL database
    /// (`postgresql://user@host/db`; the password from NCPLAN_DB_PASSWORD or the file
    /// NCPLAN_DB_PASSWORD_FILE names).
    #[arg(long, value_name = "FILE|URL")]
    from: String,
    /// Where it goes: a PostgreSQL database, or a SQLite file (created when absent).
    #[arg(long, value_name = "URL|FILE")]
    to: String,
    /// The site the history belongs to; by default the configuration's `site`.
    #[arg(long)]
    site: Option<String>,
    /// Configuration whose `site` to use.
    #[arg(long)]
    config: Option<PathBuf>,
}

/// Runs `ncplan migrate`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { from, to, site, config } = args;
    let site = match (site, &config) {
        (Some(s), _) => s,
        (None, Some(c)) => load_config(Some(c))?.site,
        (None, None) => String::new(),
    };
    anyhow::ensure!(!site.trim().is_empty(), "name the site the history belongs to: --site HALL2 (or --config with site = \"HALL2\")");
    let (source, target) = (Location::parse(&from), Location::parse(&to));
    anyhow::ensure!(source.to_string() != target.to_string(), "--from and --to name the same database");
    if let Some(file) = source.file() {
        anyhow::ensure!(file.is_file(), "no SQLite database at {}", file.display());
    }
    // The source is only read (a SQLite file keeps its schema version).
    let source_store = Store::open_read_only(&source).with_context(|| format!("cannot open the database {source}"))?;
    let store = Store::open(&target, &site).with_context(|| format!("cannot open the database {target}"))?;
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} revisions, {per_sec}, {eta} left")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let progress = |done: usize, total: usize| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    };
    let summary = store.copy_from(&source_store, &site, &progress)?;
    bar.finish_and_clear();
    let rows: Vec<String> = summary.rows.iter().map(|(t, n)| format!("{t} {n}")).collect();
    writeln!(
        out,
        "migrated {source} into {target} as site {site}: {} revisions, {} copied now, {} already there; {} comparisons copied; {} review marks; rows copied now: {}",
        summary.revisions,
        summary.copied,
        summary.revisions - summary.copied,
        summary.comparisons,
        summary.review_marks,
        if rows.is_empty() { "none".to_owned() } else { rows.join(", ") }
    )?;
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

//! `ncplan suggest` and `ncplan export-suggestions`: knowledge back to CAM from the command line.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result, bail};
use clap::ValueEnum;

use super::common::{StoreArgs, load_config};
use crate::config::Config;
use crate::export::{self, Entry, Knowledge, files};
use crate::store::{Location, Store};

/// The arguments of `ncplan suggest`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    #[command(flatten)]
    store: StoreArgs,
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
    /// Only suggestions in this state (proposed, accepted, rejected, snoozed, exported, adopted, reopened).
    #[arg(long)]
    state: Option<String>,
    /// Only this machine's.
    #[arg(long)]
    machine: Option<String>,
    /// Only this parameter's (cutting_feed, plunge_feed, ramp_feed, spindle_speed, cutting_speed,
    /// stepdown, stepover, peck_depth, clearance_height).
    #[arg(long)]
    parameter: Option<String>,
    /// Only this tool number's.
    #[arg(long)]
    tool: Option<u32>,
    /// List the groups the gates held back too, with why.
    #[arg(long)]
    all: bool,
    /// Accept, reject (with --reason) or snooze the suggestion of this id, then list.
    #[arg(long, value_name = "ID", conflicts_with_all = ["reject", "snooze"])]
    accept: Option<String>,
    /// Reject the suggestion of this id (give --reason): held back until its evidence grows.
    #[arg(long, value_name = "ID", conflicts_with = "snooze")]
    reject: Option<String>,
    /// Snooze the suggestion of this id.
    #[arg(long, value_name = "ID")]
    snooze: Option<String>,
    /// Why (a rejection needs it).
    #[arg(long, default_value = "")]
    reason: String,
    /// Who decides (the steps record it).
    #[arg(long, default_value = "planner")]
    by: String,
    /// The time the steps are dated by (RFC 3339), instead of now.
    #[arg(long, value_name = "TIME")]
    now: Option<String>,
}

#[derive(Clone, Copy, Debug, ValueEnum)]
enum Format {
    Text,
    Json,
}

/// The arguments of `ncplan export-suggestions`.
#[derive(Debug, clap::Args)]
pub(super) struct ExportArgs {
    #[command(flatten)]
    store: StoreArgs,
    /// What to write: a Fusion / Inventor CAM / HSM tool library (`.json` and `.tools`), the
    /// neutral CSV, a fragment of NX's `tool_machining_data.dat`, or the HTML evidence report.
    #[arg(long, value_parser = ["fusion", "csv", "nx", "html"])]
    to: String,
    /// The outbox folder (by default `[suggest] outbox`); never a watched folder.
    outdir: Option<PathBuf>,
    /// Who exports (the steps record it).
    #[arg(long, default_value = "planner")]
    by: String,
    /// The time the steps are dated by (RFC 3339), instead of now.
    #[arg(long, value_name = "TIME")]
    now: Option<String>,
}

/// The configuration and the store: writable, or read-only for a listing (which writes
/// nothing, so that it works on a database the user may only read).
fn open(args: &StoreArgs, writable: bool) -> Result<(Config, Store)> {
    let mut config = load_config(args.config.as_deref())?;
    if let Some(db) = &args.db {
        config.database = Location::parse(db);
    }
    if !config.database.exists() {
        bail!("no database at {} (has `ncplan watch` run?)", config.database);
    }
    let store = if writable { Store::open(&config.database, &config.site) } else { Store::open_read_only(&config.database) };
    let store = store.with_context(|| format!("cannot open the database {}", config.database))?;
    Ok((config, store))
}

fn now(given: &Option<String>) -> String {
    use crate::daemon::Clock;
    given.clone().unwrap_or_else(|| crate::daemon::SystemClock.now())
}

/// Whether `e` passes the listing's filters.
fn shown(e: &Entry, a: &Args) -> bool {
    let k = &e.s.key;
    (a.all || e.s.passed() || !e.events.is_empty())
        && a.state.as_ref().is_none_or(|s| e.state.name() == s)
        && a.machine.as_ref().is_none_or(|m| &k.machine == m)
        && a.parameter.as_ref().is_none_or(|p| k.parameter.name() == p)
        && a.tool.is_none_or(|t| k.tool.number == t)
}

/// Runs `ncplan suggest`: a listing reads (the states it shows are those the rules and the
/// watch give now); a planner's step first records what they found, then the step.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let decided = [(&args.accept, "accepted"), (&args.reject, "rejected"), (&args.snooze, "snoozed")];
    let decision = decided.iter().find(|(id, _)| id.is_some()).map(|(id, to)| ((*id).clone().unwrap_or_default(), *to));
    let (config, store) = open(&args.store, decision.is_some())?;
    let at = now(&args.now);
    let k = if let Some((id, to)) = decision {
        let state = export::State::parse(to).expect("a known state");
        let k = export::load(&store, &config, &at)?;
        export::record(&store, &k, &at)?;
        let k = export::load(&store, &config, &at)?;
        export::review(&store, &k, &id, state, &args.reason, &args.by, &at)?;
        export::load(&store, &config, &at)?
    } else {
        export::load(&store, &config, &at)?
    };
    let entries: Vec<&Entry> = k.entries.iter().filter(|e| shown(e, &args)).collect();
    match args.format {
        Format::Json => {
            serde_json::to_writer_pretty(&mut out, &entries)?;
            writeln!(out)?;
        }
        Format::Text => print_text(&k, &entries, &mut out)?,
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

fn print_text(k: &Knowledge, entries: &[&Entry], out: &mut impl Write) -> Result<()> {
    if entries.is_empty() {
        writeln!(out, "no suggestions")?;
    }
    for e in entries {
        writeln!(out, "{}", export::line(e))?;
        for h in &e.s.held {
            writeln!(out, "    held back: {}", h.words())?;
        }
        if let Some(w) = &e.watch {
            writeln!(out, "    watch: {}", w.words())?;
        }
    }
    if !k.unread.is_empty() {
        writeln!(out, "{} edits had no value to read", k.unread.len())?;
    }
    Ok(())
}

/// Runs `ncplan export-suggestions`.
pub(super) fn export_run(args: ExportArgs, mut out: impl Write) -> Result<ExitCode> {
    let (config, store) = open(&args.store, true)?;
    let Some(dir) = args.outdir.clone().or_else(|| config.suggest.outbox.clone()) else {
        bail!("give the outbox folder, or set [suggest] outbox in the configuration");
    };
    let format = files::Format::parse(&args.to).expect("clap checked it");
    let at = now(&args.now);
    let k = export::load(&store, &config, &at)?;
    export::record(&store, &k, &at)?;
    let k = export::load(&store, &config, &at)?;
    let (written, ids) = files::write(&k, format, &dir, &config, crate::web::suggest::report_html)?;
    export::mark_exported(&store, &k, &ids, &dir, &args.by, &at)?;
    for f in &written {
        writeln!(out, "{}", f.display())?;
    }
    if format.hands_over() {
        writeln!(out, "{} accepted suggestions exported", ids.len())?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

//! The command line: the only module that prints.
//!
//! Exit codes: 0 success; 1 the input has errors (`check`) or changes were found (`diff`
//! with `--exit-code`); 2 usage or operational failure.
//!
//! Each command is a module with its arguments (`Args`) and its `run`; what several share (the
//! input program, the configuration and dialects, the database) is in `common`. This module
//! only parses the command line and routes each command to its module.
//!
//! clap commands; the only code that prints (and draws progress bars).
//! `src/main.rs` calls `cli::run`. `mod.rs` parses the command line and routes each command to
//! its module (`check.rs`, `canon.rs`, `plan.rs`, `stepnc.rs`, `diff.rs`, `query.rs`,
//! `report.rs`, `serve.rs`, `show.rs`, `bench.rs`, `import.rs`, `reanalyze.rs` with `worker`,
//! `migrate.rs`, `translate.rs`, `dialects.rs`, `watch.rs`), each with its `Args` and `run`;
//! `common.rs` holds what they share (the input program, configuration, dialects, database). `canon` and `translate` read a program file piece by piece
//! (`textfile::Program`): their memory does not grow with the file; findings are placed by
//! `text::locate`. The file's survey and the loading of the dialects it names run at once
//! (`open_while_loading`). `translate -o` writes beside the output and renames when done, so a run
//! that fails (the input changed while it was read) leaves no half file.

#![allow(clippy::print_stdout, clippy::print_stderr)]

mod bench;
mod canon;
mod check;
mod common;
mod dialects;
mod diff;
mod import;
mod migrate;
mod plan;
mod query;
mod reanalyze;
mod report;
mod serve;
mod show;
mod stepnc;
mod suggest;
mod translate;
mod watch;

use std::io::BufWriter;
use std::process::ExitCode;

use anyhow::Result;
use clap::{Parser, Subcommand};

/// Recover process plans from CNC programs, diff them against the CAM original, keep the
/// shopfloor's changes.
#[derive(Debug, Parser)]
#[command(name = "ncplan", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Watch the configured folders and store every revision and its changes.
    Watch(watch::Args),
    /// Report every finding in a program; exits 1 when there are errors.
    Check(check::Args),
    /// Print the NIST canonical machining functions, one call per line.
    Canon(canon::Args),
    /// Print the recovered process plan.
    Plan(plan::Args),
    /// Write the recovered plan as STEP-NC: ISO 10303-21 in the ISO 14649 flavour.
    Stepnc(stepnc::Args),
    /// Compare two programs by what they do.
    Diff(diff::Args),
    /// Run one read-only SQL statement against the database.
    Query(query::Args),
    /// Print the shopfloor change report: Markdown, or one self-contained HTML file (inline
    /// CSS and SVG: toolpath pictures and sources), or the change rows as CSV.
    Report(report::Args),
    /// Serve the planners' workspace: overview, machines, programs, comparisons with toolpath
    /// pictures, review, knowledge pages, SQL console and search.
    Serve(serve::Args),
    /// Print one stored revision: what it is, its findings and its changes; with flags, its
    /// source or its plan.
    Show(show::Args),
    /// Generate the benchmark programs and time `canon` on them, beside `rs274` if installed.
    Bench(bench::Args),
    /// Store an existing program folder, or its dated backups, as revisions of a machine's
    /// programs with their file times; resumes after a kill; ends with a summary.
    Import(import::Args),
    /// Read every stored revision again with today's dictionary and engine: new plans,
    /// findings and comparisons, the old ones kept with their analysis version. Queues the
    /// revisions and works them with all cores; resumes after a kill; ends with a summary.
    Reanalyze(reanalyze::Args),
    /// Work the re-analysis queue `ncplan reanalyze` filled (on PostgreSQL, from any host):
    /// claim batches, read them again, until the queue is empty.
    Worker(reanalyze::WorkerArgs),
    /// Copy a site's history, every table of it: a server's SQLite file into the plant's
    /// PostgreSQL database as its site's, or the site's rows of the plant back into a SQLite
    /// file. Ids are kept where the target has them free; run again after a stop, it goes on
    /// where it was.
    Migrate(migrate::Args),
    /// Write a program for another control: read it in its dialect, write it by the
    /// target dialect's output rules; macros, loops and subprograms come out unrolled.
    Translate(translate::Args),
    /// List the known dialects, or check dialect files.
    Dialects(dialects::Args),
    /// List the suggestions for CAM made from the edits planners adopted (recording new ones
    /// as proposed and what the watch saw since an export); accept, reject or snooze one.
    Suggest(suggest::Args),
    /// Write the accepted suggestions into an outbox folder: a Fusion / Inventor CAM / HSM
    /// tool library (`.json`, `.tools`), the neutral CSV, or the HTML evidence report.
    ExportSuggestions(suggest::ExportArgs),
}

/// Runs the command line and returns the process exit code.
pub fn run() -> ExitCode {
    let cli = Cli::parse();
    let code = dispatch(cli.command);
    // For `ncplan bench`: the peak resident memory of this run.
    if std::env::var_os("NCPLAN_REPORT_PEAK").is_some()
        && let Some(peak) = crate::bench::peak_rss(std::process::id())
    {
        eprintln!("ncplan: peak resident memory {peak} bytes");
    }
    match code {
        Ok(code) => code,
        Err(e) => {
            if e.downcast_ref::<std::io::Error>().is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe) {
                return ExitCode::SUCCESS;
            }
            eprintln!("error: {e:#}");
            ExitCode::from(2)
        }
    }
}

/// Routes a command to its module.
fn dispatch(command: Command) -> Result<ExitCode> {
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    match command {
        Command::Watch(args) => watch::run(args),
        Command::Check(args) => check::run(args, &mut out),
        Command::Canon(args) => canon::run(args, &mut out),
        Command::Plan(args) => plan::run(args, &mut out),
        Command::Stepnc(args) => stepnc::run(args, &mut out),
        Command::Diff(args) => diff::run(args, &mut out),
        Command::Query(args) => query::run(args, &mut out),
        Command::Report(args) => report::run(args, &mut out),
        Command::Serve(args) => serve::run(args),
        Command::Show(args) => show::run(args, &mut out),
        Command::Bench(args) => bench::run(args, &mut out),
        Command::Import(args) => import::run(args, &mut out),
        Command::Reanalyze(args) => reanalyze::run(args, &mut out),
        Command::Worker(args) => reanalyze::worker(args, &mut out),
        Command::Migrate(args) => migrate::run(args, &mut out),
        Command::Translate(args) => translate::run(args, &mut out),
        Command::Dialects(args) => dialects::run(args, &mut out),
        Command::Suggest(args) => suggest::run(args, &mut out),
        Command::ExportSuggestions(args) => suggest::export_run(args, &mut out),
    }
}

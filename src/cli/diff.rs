//! `ncplan diff`: compare two programs by what they do.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};

use super::common::{Format, analysis_config, dialect, registry_for, say_stops, sniff_report, with_tool_table};
use crate::config;
use crate::pipeline::{self, Change};

/// The arguments of `ncplan diff`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    /// The CAM original.
    original: PathBuf,
    /// The edited program.
    edited: PathBuf,
    /// Dialect of both (unless overridden); without it, each file's is told from its text.
    #[arg(long, short)]
    dialect: Option<String>,
    /// Dialect of the edited program.
    #[arg(long)]
    edited_dialect: Option<String>,
    #[arg(long)]
    config: Option<PathBuf>,
    /// A tool table for both programs (LinuxCNC `tool.tbl`, Heidenhain `TOOL.T`, Fanuc
    /// `G10` offsets), over the configuration's tools.
    #[arg(long, value_name = "FILE")]
    tool_table: Option<PathBuf>,
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
    /// Exit 1 when there are machining changes (not only messages or output).
    #[arg(long)]
    exit_code: bool,
}

/// Runs `ncplan diff`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { original, edited, dialect: dname, edited_dialect, config, tool_table, format, exit_code } = args;
    let mut config = analysis_config(config.as_deref())?;
    with_tool_table(&mut config, tool_table.as_deref())?;
    let registry = registry_for(Some(&config))?;
    let read = |p: &Path| std::fs::read(p).with_context(|| format!("cannot read {}", p.display()));
    let (bytes_a, bytes_b) = (read(&original)?, read(&edited)?);
    // Each program with the subprograms kept beside it.
    let beside = |p: &Path| config::DirPrograms::beside(&config.profile, p, config.max_file_bytes);
    // A dialect told from weak evidence is read as `ncplan check` reads it: the programs
    // beside as evidence, a maker's own finding a warning.
    let pick = |given: Option<&str>, path: &Path, bytes: &[u8]| -> Result<_> {
        let mut profile = beside(path);
        let d = match given {
            Some(n) => dialect(&registry, n)?,
            None => {
                let s = pipeline::sniff_in(&registry, bytes, path, &profile);
                eprintln!("{}: {}", path.display(), sniff_report(&s));
                profile.guessed = s.guessed();
                dialect(&registry, &s.dialect)?
            }
        };
        Ok((d, profile))
    };
    let (da, pa) = pick(dname.as_deref(), &original, &bytes_a)?;
    let (db, pb) = pick(edited_dialect.as_deref().or(dname.as_deref()), &edited, &bytes_b)?;
    // Both read on one machine: what either's words show of it holds for both.
    let (a, b) = pipeline::analyze_pair((bytes_a, &da, &pa), (bytes_b, &db, &pb));
    say_stops(&original, &a.source.text, &a.diagnostics);
    say_stops(&edited, &b.source.text, &b.diagnostics);
    let changes = pipeline::diff_beside(&a, &da, &b, &db, (&pa, &pb));
    let machining = changes.iter().any(Change::is_machining);
    match format {
        Format::Json => {
            serde_json::to_writer_pretty(&mut out, &changes)?;
            writeln!(out)?;
        }
        Format::Text => {
            if changes.is_empty() {
                writeln!(out, "no semantic changes")?;
            } else if !machining {
                writeln!(out, "no machining changes; only what the program shows or writes:")?;
            }
            for line in pipeline::render_plain(&changes) {
                writeln!(out, "{line}")?;
            }
        }
    }
    out.flush()?;
    Ok(if exit_code && machining { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

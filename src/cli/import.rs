//! `ncplan import`: store an existing program folder, or its dated backups, as revisions of a
//! machine's programs with their file times.

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result};

use super::common::{load_config, registry_for};
use crate::config;

/// The arguments of `ncplan import`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    /// The folder: a copy of a share, or dated backups of it (`2024-03-01/O1234.nc` and
    /// `2024-05-12/O1234.nc` are two revisions of the share's `O1234.nc`).
    dir: PathBuf,
    /// The configured machine whose programs these are.
    #[arg(long, conflicts_with = "cam", required_unless_present = "cam")]
    machine: Option<String>,
    /// They are CAM originals (of the first [[cam]] folder).
    #[arg(long)]
    cam: bool,
    /// Configuration; without it, the built-in demo configuration.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Files analysed at once; by default one per core.
    #[arg(long)]
    jobs: Option<usize>,
}

/// Runs `ncplan import`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { dir, machine, cam, config, jobs } = args;
    let config = load_config(config.as_deref())?;
    let registry = registry_for(Some(&config))?;
    let folder = match &machine {
        Some(name) => config.folders.iter().find(|f| f.role == config::Role::Machine && &f.name == name).with_context(|| {
            let known: Vec<&str> = config.folders.iter().filter(|f| f.role == config::Role::Machine).map(|f| f.name.as_str()).collect();
            format!("no machine `{name}` in the configuration; configured: {}", known.join(", "))
        })?,
        None => config.folders.iter().find(|f| f.role == config::Role::Cam).context("no [[cam]] folder in the configuration")?,
    };
    anyhow::ensure!(!cam || machine.is_none(), "give --machine or --cam, not both");
    let real = |p: &Path| std::fs::canonicalize(p).unwrap_or_else(|_| p.to_path_buf());
    let (dir_real, folder_real) = (real(&dir), real(&folder.path));
    anyhow::ensure!(
        !dir_real.starts_with(&folder_real) && !folder_real.starts_with(&dir_real),
        "{} is the watched folder itself: the daemon stores it; import takes a copy or backups",
        dir.display()
    );
    let jobs = jobs.unwrap_or_else(|| std::thread::available_parallelism().map_or(1, std::num::NonZeroUsize::get));
    let bar = indicatif::ProgressBar::new(0);
    bar.set_style(
        indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} files, {per_sec}, {eta} left")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let progress = |done: usize, total: usize| {
        bar.set_length(total as u64);
        bar.set_position(done as u64);
    };
    let summary = crate::import::run(&config, &registry, folder, &dir, jobs, &progress)?;
    bar.finish_and_clear();
    writeln!(
        out,
        "imported {} into {} ({}): {} files of {} programs; {} revisions stored, {} already stored, {} compared with their original, {} errors; {:.1} s",
        dir.display(),
        folder.name,
        folder.path.display(),
        summary.files,
        summary.programs,
        summary.stored,
        summary.known,
        summary.compared,
        summary.errors.len(),
        summary.elapsed.as_secs_f64()
    )?;
    for (file, why) in &summary.errors {
        writeln!(out, "  {}: {why}", crate::sharefile::path_text(file))?;
    }
    out.flush()?;
    Ok(if summary.errors.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
}

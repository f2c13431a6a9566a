//! What the commands share: their common arguments, the configuration and dialects they
//! load, how they read an input program and report how its dialect was told.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use clap::ValueEnum;

use crate::config::{self, Config};
use crate::pipeline::{self, Diagnostic, Dialect, Registry, Sniffed, Text};
use crate::store::Location;
use crate::{machine_config, textfile};

/// How a command writes what it found (`--format`).
#[derive(Debug, Clone, Copy, ValueEnum)]
pub(super) enum Format {
    Text,
    Json,
}

/// The program a command reads, and how to read it.
#[derive(Debug, clap::Args)]
pub(super) struct Input {
    /// Program file.
    pub(super) file: PathBuf,
    /// Dialect name (see `ncplan dialects`); without it, the dialect is told from the
    /// program's text and file name, and how sure that is goes to stderr.
    #[arg(long, short)]
    pub(super) dialect: Option<String>,
    /// Configuration (for the tool table and extra dialects).
    #[arg(long)]
    pub(super) config: Option<PathBuf>,
    /// A tool table whose diameters, corner radii and point angles the plan uses (LinuxCNC
    /// `tool.tbl`, Heidenhain `TOOL.T`, Fanuc `G10` offsets), over the configuration's tools.
    #[arg(long, value_name = "FILE")]
    pub(super) tool_table: Option<PathBuf>,
    /// The machine's configuration (LinuxCNC INI: codes remapped to subroutines on its
    /// SUBROUTINE_PATH, HAL pins, switchable kinematics); without it, an INI in the program's
    /// folder or up to two folders above is taken.
    #[arg(long, value_name = "FILE")]
    pub(super) machine_config: Option<PathBuf>,
    /// The analysis bound in time: seconds of analysis for the blocks a run executes again
    /// (loops, jumps back, repeated calls), over the configuration's `[analysis] max_seconds`
    /// (60 by default). A run that reaches it stops and says so.
    #[arg(long, value_name = "SECONDS", value_parser = clap::value_parser!(u64).range(1..))]
    pub(super) max_seconds: Option<u64>,
    /// The analysis bound in memory: megabytes of the moves those blocks make, over the
    /// configuration's `[analysis] max_memory_mb` (64 by default; `canon`, which keeps no
    /// moves, has none unless given here).
    #[arg(long, value_name = "MB", value_parser = clap::value_parser!(u64).range(1..))]
    pub(super) max_memory_mb: Option<u64>,
}

impl Input {
    /// Puts the bound the command line gives over the configuration's.
    pub(super) fn bound(&self, config: &mut Config) {
        if let Some(s) = self.max_seconds {
            config.profile.bound_time(s);
        }
        if let Some(mb) = self.max_memory_mb {
            config.profile.bound_memory(mb);
        }
    }
}

/// Where the database is.
#[derive(Debug, clap::Args)]
pub(super) struct StoreArgs {
    /// The database: a SQLite file or a `postgresql://` URL (its password from
    /// NCPLAN_DB_PASSWORD or the file NCPLAN_DB_PASSWORD_FILE names); by default the one the
    /// configuration names.
    #[arg(long, value_name = "FILE|URL")]
    pub(super) db: Option<String>,
    /// Configuration whose database (and, for `report --wait`, folders) to use; without it,
    /// the built-in demo configuration.
    #[arg(long, value_name = "FILE")]
    pub(super) config: Option<PathBuf>,
}

#[derive(Debug, clap::Args)]
pub(super) struct WorkArgs {
    /// The database (a SQLite file or a postgresql:// URL); by default the configuration's.
    #[arg(long, value_name = "FILE|URL")]
    pub(super) db: Option<String>,
    /// Configuration (dialects, folders, tool table); without it, the built-in demo's.
    #[arg(long)]
    pub(super) config: Option<PathBuf>,
    /// Connections working at once; by default one per core.
    #[arg(long)]
    pub(super) jobs: Option<usize>,
    /// Seconds a claimed batch stays this worker's; after that a killed worker's batch
    /// returns to the queue.
    #[arg(long, default_value_t = 300)]
    pub(super) lease: u64,
}

pub(super) fn load_config(path: Option<&Path>) -> Result<Config> {
    match path {
        Some(p) => {
            // Relative paths in the file are resolved against the working directory, as those
            // of the built-in configuration are: `--config config/ncplan.toml` in a checkout
            // names the same folders as no `--config` at all.
            let text = std::fs::read_to_string(p).with_context(|| format!("cannot read the configuration {}", p.display()))?;
            let here = std::env::current_dir()?;
            Config::parse(&text, &here).with_context(|| format!("in the configuration {}", p.display()))
        }
        None => {
            let here = std::env::current_dir()?;
            Config::parse(config::DEMO, &here).context("in the built-in demo configuration")
        }
    }
}

/// The built-in demo configuration names folders of the checkout: it runs from its root.
pub(super) fn demo_config_here() -> Result<Config> {
    let here = std::env::current_dir()?;
    if !here.join("demo/cam").is_dir() {
        bail!(
            "without --config, ncplan runs the demo, whose folders are in the checkout (demo/cam, demo/shares); \
             {} has no demo/ folder: run it from the checkout's root, or give --config FILE",
            here.display()
        );
    }
    load_config(None)
}

/// How to run this binary again, as the user can type it: a path relative to the working
/// directory when it lies below it.
pub(super) fn this_binary() -> String {
    let exe = std::env::current_exe().ok();
    let here = std::env::current_dir().ok();
    match (exe, here) {
        (Some(exe), Some(here)) => exe.strip_prefix(&here).map_or_else(|_| exe.display().to_string(), |r| r.display().to_string()),
        _ => "ncplan".into(),
    }
}

pub(super) fn registry_for(config: Option<&Config>) -> Result<Registry> {
    config::dialect_registry(config.and_then(|c| c.dialects_dir.as_deref()))
}

pub(super) fn dialect(registry: &Registry, name: &str) -> Result<Arc<Dialect>> {
    registry.get(name).with_context(|| format!("unknown dialect `{name}`; known: {}", registry.names().collect::<Vec<_>>().join(", ")))
}

/// Opens the program file `path` while the dialects `names` load on another thread: a large
/// file's survey ([`textfile::Program::open`]) and the reading of the dictionary files go on
/// at once, not one after the other. A dialect that does not load says so when it is asked for.
pub(super) fn open_while_loading(
    registry: &Registry,
    names: &[Option<&str>],
    path: &Path,
) -> std::io::Result<(textfile::Program, Vec<Diagnostic>)> {
    std::thread::scope(|s| {
        s.spawn(|| names.iter().flatten().for_each(|n| drop(registry.get(n))));
        textfile::Program::open(path)
    })
}

/// The config for commands that analyse files: the given one, or an empty tool table.
pub(super) fn analysis_config(path: Option<&Path>) -> Result<Config> {
    match path {
        Some(p) => load_config(Some(p)),
        None => Config::parse("[database]\npath = 'unused.db'\n", Path::new("/")),
    }
}

/// Puts the tools of a `--tool-table` file over the configuration's.
pub(super) fn with_tool_table(config: &mut Config, table: Option<&Path>) -> Result<()> {
    if let Some(path) = table {
        config.profile.tools.extend(config::read_tool_table(path)?);
    }
    Ok(())
}

/// The dialect, config and bytes of an input file. Without a configured program directory,
/// called subprograms are looked for beside the file.
pub(super) fn input_setup(input: &Input) -> Result<(Arc<Dialect>, Config, Vec<u8>)> {
    let mut config = analysis_config(input.config.as_deref())?;
    input.bound(&mut config);
    with_tool_table(&mut config, input.tool_table.as_deref())?;
    config.profile = config::DirPrograms::beside(&config.profile, &input.file, config.max_file_bytes);
    config.profile = machine_config::for_program(&config.profile, &input.file, input.machine_config.as_deref(), config.max_file_bytes)?;
    let registry = registry_for(Some(&config))?;
    let bytes = std::fs::read(&input.file).with_context(|| format!("cannot read {}", input.file.display()))?;
    let name = match &input.dialect {
        Some(n) => n.clone(),
        None => {
            let s = pipeline::sniff_in(&registry, &bytes, &input.file, &config.profile);
            eprintln!("{}", sniff_report(&s));
            config.profile.guessed = s.guessed();
            s.dialect
        }
    };
    let d = dialect(&registry, &name)?;
    Ok((d, config, bytes))
}

/// [`input_setup`] for the commands that stream (`canon`): the program is read piece by piece
/// ([`textfile::Program`]), with the findings of decoding it.
pub(super) fn input_program(input: &Input) -> Result<(Arc<Dialect>, Config, textfile::Program, Vec<Diagnostic>)> {
    let mut config = analysis_config(input.config.as_deref())?;
    input.bound(&mut config);
    with_tool_table(&mut config, input.tool_table.as_deref())?;
    config.profile = config::DirPrograms::beside(&config.profile, &input.file, config.max_file_bytes);
    config.profile = machine_config::for_program(&config.profile, &input.file, input.machine_config.as_deref(), config.max_file_bytes)?;
    let registry = registry_for(Some(&config))?;
    let opened = open_while_loading(&registry, &[input.dialect.as_deref()], &input.file);
    let (program, diags) = opened.with_context(|| format!("cannot read {}", input.file.display()))?;
    let name = match &input.dialect {
        Some(n) => n.clone(),
        None => {
            let s = pipeline::sniff_in(&registry, program.head_bytes(), &input.file, &config.profile);
            eprintln!("{}", sniff_report(&s));
            config.profile.guessed = s.guessed();
            s.dialect
        }
    };
    let d = dialect(&registry, &name)?;
    Ok((d, config, program, diags))
}

/// Prints `shown` findings on stderr as `path:line:col: ...`, in their order; their lines are
/// counted in one pass over the text, up to the last of them.
pub(super) fn print_short(path: &str, text: Text<'_>, shown: &[&Diagnostic]) {
    let mut offsets: Vec<u32> = shown.iter().map(|d| d.range.start).collect();
    offsets.sort_unstable();
    offsets.dedup();
    let places = pipeline::locate(text, &offsets);
    for d in shown {
        let k = offsets.binary_search(&d.range.start).unwrap_or(0);
        eprintln!("{}", pipeline::render_short_at(path, places[k], d));
    }
}

/// Says on stderr where the analysis of the program at `path` stopped before its end (its
/// bound, a runaway loop), if it did: a command that shows no findings still says that.
pub(super) fn say_stops(path: &Path, text: &str, diags: &[Diagnostic]) {
    let stops: Vec<&Diagnostic> = diags.iter().filter(|d| d.stops_analysis()).collect();
    if stops.is_empty() {
        return;
    }
    let index = pipeline::LineIndex::new(text);
    for d in stops {
        eprintln!("{}", pipeline::render_short(&path.display().to_string(), text, &index, d));
    }
}

pub(super) fn sniff_report(s: &Sniffed) -> String {
    let why = if s.evidence.is_empty() { "no evidence; the default".to_owned() } else { s.evidence.join(", ") };
    let next = s.runner_up.as_ref().map(|(n, score)| format!("; next: {n} ({score})")).unwrap_or_default();
    format!("ncplan: dialect {} (sure: {}; score {}: {why}{next}); give --dialect to choose", s.dialect, s.confidence.as_str(), s.score)
}

pub(super) fn db_path(args: &StoreArgs) -> Result<Location> {
    let db = match (&args.db, &args.config) {
        (Some(d), _) => Location::parse(d),
        (None, Some(c)) => load_config(Some(c))?.database,
        (None, None) => load_config(None)?.database,
    };
    if !db.exists() {
        bail!("no database at {db} (has `ncplan watch` run?)");
    }
    Ok(db)
}

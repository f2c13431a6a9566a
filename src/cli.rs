//! The command line: the only module that prints.
//!
//! Exit codes: 0 success; 1 the input has errors (`check`) or changes were found (`diff`
//! with `--exit-code`); 2 usage or operational failure.

#![allow(clippy::print_stdout, clippy::print_stderr)]

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand, ValueEnum};

use crate::canon::{CallWriter, Canon, CanonSink};
use crate::config::{self, Config};
use crate::diag::{self, DiagnosticJson};
use crate::dialect::{Dialect, Registry};
use crate::diff;
use crate::pipeline;
use crate::store::{Location, Store};
use crate::text::{LineIndex, Text};
use crate::textfile;

/// Recover process plans from CNC programs, diff them against the CAM original, keep the
/// shopfloor's changes.
#[derive(Debug, Parser)]
#[command(name = "ncplan", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum ReportFormat {
    Markdown,
    Html,
    Csv,
}

#[derive(Debug, Clone, Copy, ValueEnum)]
enum Format {
    Text,
    Json,
}

#[derive(Debug, clap::Args)]
struct Input {
    /// Program file.
    file: PathBuf,
    /// Dialect name (see `ncplan dialects`); without it, the dialect is told from the
    /// program's text and file name, and how sure that is goes to stderr.
    #[arg(long, short)]
    dialect: Option<String>,
    /// Configuration (for the tool table and extra dialects).
    #[arg(long)]
    config: Option<PathBuf>,
    /// A tool table whose diameters, corner radii and point angles the plan uses (LinuxCNC
    /// `tool.tbl`, Heidenhain `TOOL.T`, Fanuc `G10` offsets), over the configuration's tools.
    #[arg(long, value_name = "FILE")]
    tool_table: Option<PathBuf>,
}

/// Where the database is.
#[derive(Debug, clap::Args)]
struct StoreArgs {
    /// The database: a SQLite file or a `postgresql://` URL (its password from
    /// NCPLAN_DB_PASSWORD or the file NCPLAN_DB_PASSWORD_FILE names); by default the one the
    /// configuration names.
    #[arg(long, value_name = "FILE|URL")]
    db: Option<String>,
    /// Configuration whose database (and, for `report --wait`, folders) to use; without it,
    /// the built-in demo configuration.
    #[arg(long, value_name = "FILE")]
    config: Option<PathBuf>,
}

#[derive(Debug, Args)]
struct WorkArgs {
    /// The database (a SQLite file or a postgresql:// URL); by default the configuration's.
    #[arg(long, value_name = "FILE|URL")]
    db: Option<String>,
    /// Configuration (dialects, folders, tool table); without it, the built-in demo's.
    #[arg(long)]
    config: Option<PathBuf>,
    /// Connections working at once; by default one per core.
    #[arg(long)]
    jobs: Option<usize>,
    /// Seconds a claimed batch stays this worker's; after that a killed worker's batch
    /// returns to the queue.
    #[arg(long, default_value_t = 300)]
    lease: u64,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Watch the configured folders and store every revision and its changes.
    Watch {
        /// Configuration file; without it, the built-in demo configuration.
        #[arg(long)]
        config: Option<PathBuf>,
    },
    /// Report every finding in a program; exits 1 when there are errors.
    Check {
        #[command(flatten)]
        input: Input,
        #[arg(long, value_enum, default_value = "text")]
        format: Format,
        /// Read the file as a main program, as one others call (its caller sets the feed,
        /// spindle and arguments), or tell it from its form and file name.
        #[arg(long = "as", value_enum, default_value = "auto")]
        role: RoleArg,
        /// Calls to programs the analysis does not have (a control's resident cycles, shop
        /// subprograms) are errors, not warnings.
        #[arg(long)]
        strict: bool,
        /// More program files: each is checked in turn (its dialect told from it unless
        /// --dialect is given), with a progress bar on a terminal and a summary line.
        more: Vec<PathBuf>,
    },
    /// Print the NIST canonical machining functions, one call per line.
    Canon {
        #[command(flatten)]
        input: Input,
        /// Prefix each call with its source line.
        #[arg(long)]
        lines: bool,
    },
    /// Print the recovered process plan.
    Plan {
        #[command(flatten)]
        input: Input,
        #[arg(long, value_enum, default_value = "text")]
        format: Format,
    },
    /// Write the recovered plan as STEP-NC: ISO 10303-21 in the ISO 14649 flavour.
    Stepnc {
        #[command(flatten)]
        input: Input,
        /// Conformance class 1: explicit toolpaths (toolpath features, freeform operations).
        #[arg(long, conflicts_with = "cc2", required_unless_present = "cc2")]
        cc1: bool,
        /// Conformance class 2: features, operations and strategies, toolpaths included.
        #[arg(long)]
        cc2: bool,
        /// Output file; standard output when absent.
        #[arg(long, short)]
        output: Option<PathBuf>,
        /// Header time stamp (ISO 8601); by default the current time (UTC).
        #[arg(long)]
        timestamp: Option<String>,
    },
    /// Compare two programs by what they do.
    Diff {
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
    },
    /// Run one read-only SQL statement against the database.
    Query {
        /// SQL: one SELECT, WITH, VALUES or EXPLAIN statement.
        sql: String,
        #[command(flatten)]
        store: StoreArgs,
        #[arg(long, value_enum, default_value = "text")]
        format: Format,
    },
    /// Print the shopfloor change report: Markdown, or one self-contained HTML file (inline
    /// CSS and SVG: toolpath pictures and sources), or the change rows as CSV.
    Report {
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
    },
    /// Serve the planners' workspace: overview, machines, programs, comparisons with toolpath
    /// pictures, review, knowledge pages, SQL console and search.
    Serve {
        /// Configuration (database, folders, [[web.user]]); without it, the built-in demo's.
        #[arg(long)]
        config: Option<PathBuf>,
        /// Address to listen on (default 127.0.0.1:8480, or the configuration's [web] listen);
        /// another than loopback needs users configured.
        #[arg(long, value_name = "ADDR")]
        listen: Option<String>,
        /// The database instead of the configuration's: a SQLite file or a `postgresql://` URL.
        #[arg(long, value_name = "FILE|URL")]
        db: Option<String>,
    },
    /// Print one stored revision: what it is, its findings and its changes; with flags, its
    /// source or its plan.
    Show {
        /// A revision id, or a program's path (whole, or its end such as `DMU50/O1234.nc`).
        revision: String,
        /// With a path: the newest revision seen at or before this time (RFC 3339, or a date).
        #[arg(long, value_name = "TIME")]
        at: Option<String>,
        /// Print the stored program bytes as they were, and nothing else.
        #[arg(long, conflicts_with = "plan")]
        source: bool,
        /// Print the stored plan as JSON, and nothing else.
        #[arg(long)]
        plan: bool,
        #[command(flatten)]
        store: StoreArgs,
    },
    /// Generate the benchmark programs and time `canon` on them, beside `rs274` if installed.
    Bench {
        /// Where to write the programs.
        #[arg(long, default_value = "target/bench")]
        dir: PathBuf,
        /// Rows of 500 blocks in the surfacing program (2000 rows: 1 million blocks, ~27 MB).
        #[arg(long, default_value_t = 2000)]
        rows: usize,
        /// Runs per measurement; the best is kept.
        #[arg(long, default_value_t = 3)]
        runs: u32,
        /// Measure the daemon instead: the huge program's ingest, memory and stored size beside
        /// plan, diff and stepnc; idle CPU; edit latency; a burst; a kill loop.
        #[arg(long)]
        daemon: bool,
        /// Measure `check` on every program in this folder and its subfolders (a corpus)
        /// instead: the slowest files' time and peak memory, and the largest of each.
        #[arg(long, value_name = "DIR", conflicts_with = "daemon")]
        corpus: Option<PathBuf>,
        /// With --daemon: files stored before the idle measurement (also the burst).
        #[arg(long, default_value_t = 2000)]
        files: usize,
        /// With --daemon: SIGKILLs in the kill loop.
        #[arg(long, default_value_t = 100)]
        kills: usize,
        /// Measure `ncplan serve` instead: every page's render time on a database of
        /// 10,000 revisions across 20 machines, and a 1M-move comparison page.
        #[arg(long, conflicts_with = "daemon")]
        web: bool,
        /// Measure ingest throughput on SQLite and on this PostgreSQL database instead
        /// (`--files` programs at once); the daemon writes as a site of its own. With --web:
        /// the pages rendered on this database too (the same 10,000 revisions, copied in by
        /// `migrate` as site WEBBENCH once; give it a database of its own).
        #[arg(long, value_name = "URL", conflicts_with_all = ["daemon"])]
        postgres: Option<String>,
        /// With --postgres: time the report queries on a simulated plant of this many
        /// revisions instead (made once in that database).
        #[arg(long, value_name = "REVISIONS", requires = "postgres")]
        simulate: Option<i64>,
    },
    /// Store an existing program folder, or its dated backups, as revisions of a machine's
    /// programs with their file times; resumes after a kill; ends with a summary.
    Import {
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
    },
    /// Read every stored revision again with today's dictionary and engine: new plans,
    /// findings and comparisons, the old ones kept with their analysis version. Queues the
    /// revisions and works them with all cores; resumes after a kill; ends with a summary.
    Reanalyze {
        /// Only revisions seen on or after this date (or RFC 3339 time).
        #[arg(long)]
        since: Option<String>,
        /// Only programs read in this dialect.
        #[arg(long)]
        dialect: Option<String>,
        #[command(flatten)]
        work: WorkArgs,
    },
    /// Work the re-analysis queue `ncplan reanalyze` filled (on PostgreSQL, from any host):
    /// claim batches, read them again, until the queue is empty.
    Worker {
        #[command(flatten)]
        work: WorkArgs,
    },
    /// Copy a site's history, every table of it: a server's SQLite file into the plant's
    /// PostgreSQL database as its site's, or the site's rows of the plant back into a SQLite
    /// file. Ids are kept where the target has them free; run again after a stop, it goes on
    /// where it was.
    Migrate {
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
    },
    /// Write a program for another control: read it in its dialect, write it by the
    /// target dialect's output rules; macros, loops and subprograms come out unrolled.
    Translate {
        /// Program file (or give --revision).
        #[arg(required_unless_present = "revision")]
        file: Option<PathBuf>,
        /// The program's dialect; without it, told from the program (or the stored one).
        #[arg(long, short)]
        dialect: Option<String>,
        /// The target dialect; by default the --machine's.
        #[arg(long, required_unless_present = "machine")]
        to: Option<String>,
        /// Output file; standard output when absent. Never inside a watched folder.
        #[arg(long, short)]
        output: Option<PathBuf>,
        /// The configured machine to write for: its units and limits (travel, spindle
        /// speed, feed), and its dialect unless --to is given.
        #[arg(long)]
        machine: Option<String>,
        /// A stored revision (the as-run program) instead of a file.
        #[arg(long, conflicts_with = "file")]
        revision: Option<i64>,
        #[command(flatten)]
        store: StoreArgs,
    },
    /// List the known dialects, or check dialect files.
    Dialects {
        /// Dialect files to check.
        files: Vec<PathBuf>,
    },
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

fn load_config(path: Option<&Path>) -> Result<Config> {
    match path {
        Some(p) => {
            let text = std::fs::read_to_string(p).with_context(|| format!("cannot read the configuration {}", p.display()))?;
            let base = p.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf);
            let base = if base.as_os_str().is_empty() { PathBuf::from(".") } else { base };
            Config::parse(&text, &std::path::absolute(&base)?).with_context(|| format!("in the configuration {}", p.display()))
        }
        None => {
            let here = std::env::current_dir()?;
            Config::parse(config::DEMO, &here).context("in the built-in demo configuration")
        }
    }
}

/// The built-in demo configuration names folders of the checkout: it runs from its root.
fn demo_config_here() -> Result<Config> {
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
fn this_binary() -> String {
    let exe = std::env::current_exe().ok();
    let here = std::env::current_dir().ok();
    match (exe, here) {
        (Some(exe), Some(here)) => exe.strip_prefix(&here).map_or_else(|_| exe.display().to_string(), |r| r.display().to_string()),
        _ => "ncplan".into(),
    }
}

fn registry_for(config: Option<&Config>) -> Result<Registry> {
    config::dialect_registry(config.and_then(|c| c.dialects_dir.as_deref()))
}

fn dialect(registry: &Registry, name: &str) -> Result<Arc<Dialect>> {
    registry.get(name).with_context(|| format!("unknown dialect `{name}`; known: {}", registry.names().collect::<Vec<_>>().join(", ")))
}

/// Opens the program file `path` while the dialects `names` load on another thread: a large
/// file's survey ([`textfile::Program::open`]) and the reading of the dictionary files go on
/// at once, not one after the other. A dialect that does not load says so when it is asked for.
fn open_while_loading(
    registry: &Registry,
    names: &[Option<&str>],
    path: &Path,
) -> std::io::Result<(textfile::Program, Vec<diag::Diagnostic>)> {
    std::thread::scope(|s| {
        s.spawn(|| names.iter().flatten().for_each(|n| drop(registry.get(n))));
        textfile::Program::open(path)
    })
}

/// The config for commands that analyse files: the given one, or an empty tool table.
fn analysis_config(path: Option<&Path>) -> Result<Config> {
    match path {
        Some(p) => load_config(Some(p)),
        None => Config::parse("[database]\npath = 'unused.db'\n", Path::new("/")),
    }
}

/// The dialect, config and bytes of an input file. Without a configured program directory,
/// called subprograms are looked for beside the file.
/// `check --as`: the role of the program checked.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum RoleArg {
    Auto,
    Main,
    Called,
}

/// Puts the tools of a `--tool-table` file over the configuration's.
fn with_tool_table(config: &mut Config, table: Option<&Path>) -> Result<()> {
    if let Some(path) = table {
        config.profile.tools.extend(config::read_tool_table(path)?);
    }
    Ok(())
}

fn input_setup(input: &Input) -> Result<(Arc<Dialect>, Config, Vec<u8>)> {
    let mut config = analysis_config(input.config.as_deref())?;
    with_tool_table(&mut config, input.tool_table.as_deref())?;
    config.profile = config::DirPrograms::beside(&config.profile, &input.file, config.max_file_bytes);
    let registry = registry_for(Some(&config))?;
    let bytes = std::fs::read(&input.file).with_context(|| format!("cannot read {}", input.file.display()))?;
    let name = match &input.dialect {
        Some(n) => n.clone(),
        None => {
            let s = pipeline::sniff(&registry, &bytes, &input.file);
            eprintln!("{}", sniff_report(&s));
            s.dialect
        }
    };
    let d = dialect(&registry, &name)?;
    Ok((d, config, bytes))
}

/// [`input_setup`] for the commands that stream (`canon`): the program is read piece by piece
/// ([`textfile::Program`]), with the findings of decoding it.
fn input_program(input: &Input) -> Result<(Arc<Dialect>, Config, textfile::Program, Vec<diag::Diagnostic>)> {
    let mut config = analysis_config(input.config.as_deref())?;
    with_tool_table(&mut config, input.tool_table.as_deref())?;
    config.profile = config::DirPrograms::beside(&config.profile, &input.file, config.max_file_bytes);
    let registry = registry_for(Some(&config))?;
    let opened = open_while_loading(&registry, &[input.dialect.as_deref()], &input.file);
    let (program, diags) = opened.with_context(|| format!("cannot read {}", input.file.display()))?;
    let name = match &input.dialect {
        Some(n) => n.clone(),
        None => {
            let s = pipeline::sniff(&registry, program.head_bytes(), &input.file);
            eprintln!("{}", sniff_report(&s));
            s.dialect
        }
    };
    let d = dialect(&registry, &name)?;
    Ok((d, config, program, diags))
}

/// Prints `shown` findings on stderr as `path:line:col: ...`, in their order; their lines are
/// counted in one pass over the text, up to the last of them.
fn print_short(path: &str, text: Text<'_>, shown: &[&diag::Diagnostic]) {
    let mut offsets: Vec<u32> = shown.iter().map(|d| d.range.start).collect();
    offsets.sort_unstable();
    offsets.dedup();
    let places = crate::text::locate(text, &offsets);
    for d in shown {
        let k = offsets.binary_search(&d.range.start).unwrap_or(0);
        eprintln!("{}", diag::render_short_at(path, places[k], d));
    }
}

fn sniff_report(s: &crate::dialect::sniff::Sniffed) -> String {
    let why = if s.evidence.is_empty() { "no evidence; the default".to_owned() } else { s.evidence.join(", ") };
    let next = s.runner_up.as_ref().map(|(n, score)| format!("; next: {n} ({score})")).unwrap_or_default();
    format!("ncplan: dialect {} (sure: {}; score {}: {why}{next}); give --dialect to choose", s.dialect, s.confidence.as_str(), s.score)
}

fn dispatch(command: Command) -> Result<ExitCode> {
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    match command {
        Command::Watch { config: given } => {
            let demo = given.is_none();
            let config = if demo { demo_config_here()? } else { load_config(given.as_deref())? };
            config.check_watchable()?;
            let registry = registry_for(Some(&config))?;
            for f in config.folders.iter().filter(|f| f.dialect != config::AUTO_DIALECT) {
                dialect(&registry, &f.dialect).with_context(|| format!("folder {}", f.path.display()))?;
            }
            init_tracing();
            println!(
                "ncplan watch: database {}{}",
                config.database,
                if config.site.is_empty() { String::new() } else { format!(", site {}", config.site) }
            );
            for f in &config.folders {
                println!(
                    "  {:<8} {:<10} {:<9} {}{}",
                    f.role.as_str(),
                    f.name,
                    f.dialect,
                    f.path.display(),
                    if f.poll { " (polled)" } else { "" }
                );
            }
            if demo {
                println!("Try, in another terminal: cp demo/examples/O1234_edited.nc demo/shares/DMU50/O1234.nc");
                println!("then: {} report --wait", this_binary());
            }
            crate::daemon::run(config, registry, Arc::new(crate::daemon::SystemClock))?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Check { input, format, role, strict, more } => {
            let mut config = analysis_config(input.config.as_deref())?;
            let registry = registry_for(Some(&config))?;
            let base = config.profile.clone();
            let files: Vec<PathBuf> = std::iter::once(input.file.clone()).chain(more).collect();
            let many = files.len() > 1;
            let bar = indicatif::ProgressBar::new(if many { files.len() as u64 } else { 0 });
            if many {
                bar.set_style(
                    indicatif::ProgressStyle::with_template("{bar:40} {pos}/{len} files, {eta} left")
                        .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
                );
            } else {
                bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
            }
            let (mut with_errors, mut errors, mut others, mut unreadable) = (0usize, 0usize, 0usize, 0usize);
            let mut reports = Vec::new();
            for file in &files {
                let Ok(bytes) = std::fs::read(file) else {
                    if !many {
                        bail!("cannot read {}", file.display());
                    }
                    bar.suspend(|| eprintln!("error: cannot read {}", file.display()));
                    unreadable += 1;
                    bar.inc(1);
                    continue;
                };
                let name = match &input.dialect {
                    Some(n) => n.clone(),
                    None => {
                        let s = pipeline::sniff(&registry, &bytes, file);
                        bar.suspend(|| {
                            eprintln!("{}{}", if many { format!("{}: ", file.display()) } else { String::new() }, sniff_report(&s))
                        });
                        s.dialect
                    }
                };
                let d = dialect(&registry, &name)?;
                config.profile = config::DirPrograms::beside(&base, file, config.max_file_bytes);
                let given = match role {
                    RoleArg::Main => crate::interp::ProgramRole::Main,
                    RoleArg::Called => crate::interp::ProgramRole::Called,
                    RoleArg::Auto => base.role,
                };
                config.profile.role = crate::interp::role_for(given, file, &d);
                let mut a = pipeline::analyze_plan_owned(bytes, &d, &config.profile);
                if strict {
                    for x in a.diagnostics.iter_mut().filter(|x| x.code == diag::Code::MissingProgram) {
                        x.severity = diag::Severity::Error;
                    }
                }
                let path = file.display().to_string();
                let idx = LineIndex::new(&a.source.text);
                let n_errors = a.diagnostics.iter().filter(|x| x.is_error()).count();
                (errors, others) = (errors + n_errors, others + a.diagnostics.len() - n_errors);
                with_errors += usize::from(n_errors > 0);
                match format {
                    Format::Json => {
                        let ds: Vec<DiagnosticJson> = a.diagnostics.iter().map(|x| DiagnosticJson::new(x, &a.source.text, &idx)).collect();
                        reports.push(serde_json::json!({ "file": path, "dialect": d.name, "diagnostics": ds }));
                    }
                    Format::Text => {
                        let mut text = String::new();
                        for x in &a.diagnostics {
                            text.push_str(&diag::render_human(&path, &a.source.text, &idx, x));
                        }
                        text.push_str(&format!("{path}: {n_errors} errors, {} other findings\n", a.diagnostics.len() - n_errors));
                        bar.suspend(|| out.write_all(text.as_bytes()))?;
                    }
                }
                bar.inc(1);
            }
            bar.finish_and_clear();
            match format {
                Format::Json if many => serde_json::to_writer_pretty(&mut out, &reports)?,
                Format::Json => serde_json::to_writer_pretty(&mut out, &reports[0])?,
                Format::Text if many => write!(
                    out,
                    "checked {} files: {with_errors} with errors ({errors} errors, {others} other findings){}",
                    files.len(),
                    if unreadable > 0 { format!("; {unreadable} could not be read") } else { String::new() }
                )?,
                Format::Text => {}
            }
            if matches!(format, Format::Json) || many {
                writeln!(out)?;
            }
            out.flush()?;
            Ok(if with_errors > 0 || unreadable > 0 { ExitCode::from(1) } else { ExitCode::SUCCESS })
        }
        Command::Bench { dir, rows, runs, daemon, corpus, files, kills, web, postgres, simulate } => {
            if web {
                crate::web::bench::run(&dir.join("web"), rows, postgres.as_deref(), &mut LineFlush(&mut out))?;
            } else if let (Some(url), Some(n)) = (&postgres, simulate) {
                crate::bench::run_simulation(url, n, &mut LineFlush(&mut out))?;
            } else if let Some(url) = postgres {
                crate::bench::run_engines(&dir.join("engines"), &url, files, &mut LineFlush(&mut out))?;
            } else if let Some(corpus) = corpus {
                crate::bench::run_corpus(&corpus, &mut LineFlush(&mut out))?;
            } else if daemon {
                crate::bench::run_daemon(&dir.join("daemon"), rows, files, kills, &mut LineFlush(&mut out))?;
            } else {
                crate::bench::run(&dir, rows, runs, &mut out)?;
            }
            out.flush()?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Canon { input, lines } => {
            // Read piece by piece: memory does not grow with the program.
            let (d, config, program, mut diags) = input_program(&input)?;
            let mut printer = Printer {
                out: &mut out,
                buf: Vec::with_capacity(Printer::<Vec<u8>>::CHUNK + 256),
                writer: CallWriter::default(),
                lines,
                error: None,
            };
            diags.extend(crate::interp::interpret(program.text(), &d, &config.profile, &mut printer));
            printer.flush();
            if let Some(e) = printer.error.take() {
                return Err(e.into());
            }
            out.flush()?;
            if let Some(why) = program.trouble() {
                bail!("{why}");
            }
            let errors: Vec<&diag::Diagnostic> = diags.iter().filter(|x| x.is_error()).collect();
            print_short(&input.file.display().to_string(), program.text(), &errors);
            Ok(ExitCode::SUCCESS)
        }
        Command::Plan { input, format } => {
            let (d, config, bytes) = input_setup(&input)?;
            let a = pipeline::analyze_plan_owned(bytes, &d, &config.profile);
            match format {
                Format::Json => {
                    serde_json::to_writer_pretty(&mut out, &a.plan)?;
                    writeln!(out)?;
                }
                Format::Text => write_plan(&mut out, &a.plan)?,
            }
            out.flush()?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Stepnc { input, cc1, cc2: _, output, timestamp } => {
            let (d, config, bytes) = input_setup(&input)?;
            let a = pipeline::analyze_plan_owned(bytes, &d, &config.profile);
            let class = if cc1 { crate::part21::stepnc::Class::Cc1 } else { crate::part21::stepnc::Class::Cc2 };
            let timestamp = timestamp.unwrap_or_else(|| {
                use crate::daemon::Clock;
                crate::daemon::SystemClock.now()
            });
            // Streamed: the export is written as it is made, never held whole in memory. A file
            // is written beside its place and renamed, so a failed export leaves no half file.
            let diags = match &output {
                Some(o) => {
                    let tmp = o.with_file_name(format!(".{}.partial", o.file_name().map(|n| n.to_string_lossy()).unwrap_or_default()));
                    let file = std::fs::File::create(&tmp).with_context(|| format!("cannot write {}", tmp.display()))?;
                    match crate::part21::stepnc::write(&a.plan, class, &timestamp, std::io::BufWriter::new(file)) {
                        Ok((_, diags)) => {
                            std::fs::rename(&tmp, o).with_context(|| format!("cannot write {}", o.display()))?;
                            diags
                        }
                        Err(e) => {
                            let _ = std::fs::remove_file(&tmp);
                            return Err(anyhow::Error::new(e).context(format!("cannot write {}", o.display())));
                        }
                    }
                }
                None => crate::part21::stepnc::write(&a.plan, class, &timestamp, &mut out)?.1,
            };
            out.flush()?;
            let path = input.file.display().to_string();
            let idx = LineIndex::new(&a.source.text);
            for x in diags.iter().chain(a.diagnostics.iter().filter(|x| x.is_error())) {
                eprintln!("{}", diag::render_short(&path, &a.source.text, &idx, x));
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Diff { original, edited, dialect: dname, edited_dialect, config, tool_table, format, exit_code } => {
            let mut config = analysis_config(config.as_deref())?;
            with_tool_table(&mut config, tool_table.as_deref())?;
            let registry = registry_for(Some(&config))?;
            let read = |p: &Path| std::fs::read(p).with_context(|| format!("cannot read {}", p.display()));
            let (bytes_a, bytes_b) = (read(&original)?, read(&edited)?);
            let pick = |given: Option<&str>, path: &Path, bytes: &[u8]| match given {
                Some(n) => dialect(&registry, n),
                None => {
                    let s = pipeline::sniff(&registry, bytes, path);
                    eprintln!("{}: {}", path.display(), sniff_report(&s));
                    dialect(&registry, &s.dialect)
                }
            };
            let da = pick(dname.as_deref(), &original, &bytes_a)?;
            let db = pick(edited_dialect.as_deref().or(dname.as_deref()), &edited, &bytes_b)?;
            // Each program with the subprograms kept beside it.
            let beside = |p: &Path| config::DirPrograms::beside(&config.profile, p, config.max_file_bytes);
            let a = pipeline::analyze_plan_owned(bytes_a, &da, &beside(&original));
            let b = pipeline::analyze_plan_owned(bytes_b, &db, &beside(&edited));
            let changes = diff::compare(
                diff::Program { plan: &a.plan, text: &a.source.text, dialect: &da },
                diff::Program { plan: &b.plan, text: &b.source.text, dialect: &db },
            );
            let machining = changes.iter().any(diff::Change::is_machining);
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
                    for line in diff::render_plain(&changes) {
                        writeln!(out, "{line}")?;
                    }
                }
            }
            out.flush()?;
            Ok(if exit_code && machining { ExitCode::from(1) } else { ExitCode::SUCCESS })
        }
        Command::Query { sql, store, format } => {
            let db = db_path(&store)?;
            let store = Store::open_read_only(&db)?;
            let (cols, rows) = match store.query_read_only(&sql) {
                Ok(r) => r,
                Err(e) => {
                    eprintln!("error: {e}");
                    return Ok(ExitCode::from(2));
                }
            };
            match format {
                Format::Json => {
                    let objs: Vec<serde_json::Map<String, serde_json::Value>> = rows
                        .iter()
                        .map(|r| cols.iter().cloned().zip(r.iter().map(|v| serde_json::Value::String(v.clone()))).collect())
                        .collect();
                    serde_json::to_writer_pretty(&mut out, &objs)?;
                    writeln!(out)?;
                }
                Format::Text => {
                    writeln!(out, "{}", cols.join("\t"))?;
                    for r in rows {
                        writeln!(out, "{}", r.join("\t"))?;
                    }
                }
            }
            out.flush()?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Serve { config: given, listen, db } => {
            let mut config = load_config(given.as_deref())?;
            if let Some(db) = db {
                config.database = Location::parse(&db);
            }
            if !config.database.exists() {
                bail!("no database at {} (has `ncplan watch` run?)", config.database);
            }
            let registry = registry_for(Some(&config))?;
            let db = config.database.clone();
            let options = crate::web::Options { config, registry, listen, clock: Arc::new(crate::daemon::SystemClock) };
            crate::web::serve(options, |addr| {
                println!("ncplan serve: http://{addr}/ (database {db})");
                let _ = std::io::stdout().flush();
            })?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Report { store, wait, format, output, since, machine, machining_only } => {
            if let Some(seconds) = wait {
                let config = match &store.config {
                    Some(p) => load_config(Some(p))?,
                    None => demo_config_here()?,
                };
                let db = store.db.as_deref().map_or_else(|| config.database.clone(), Location::parse);
                let left = wait_until_stored(&config, &db, Duration::from_secs(seconds))?;
                if left > 0 {
                    eprintln!(
                        "ncplan: {left} files in the watched folders are not stored yet (is `ncplan watch` running?); reporting what is"
                    );
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
        Command::Show { revision, at, source, plan, store: store_args } => {
            let db = db_path(&store_args)?;
            let store = Store::open_read_only(&db)?;
            let id = match revision.parse::<i64>() {
                Ok(id) if at.is_none() => id,
                _ => match store.revision_of_path(&revision, at.as_deref())? {
                    Ok(Some(id)) => id,
                    Ok(None) => bail!("no stored revision of `{revision}`{}", at.map(|a| format!(" at or before {a}")).unwrap_or_default()),
                    Err(paths) => bail!("`{revision}` names several programs; give more of the path:\n  {}", paths.join("\n  ")),
                },
            };
            let Some(info) = store.revision(id)? else { bail!("no revision {id}") };
            if source {
                out.write_all(&store.content(id)?.unwrap_or_default())?;
            } else if plan {
                // The stored plan is a summary; the whole plan is rebuilt from the stored bytes.
                let config = match &store_args.config {
                    Some(p) => load_config(Some(p))?,
                    None => load_config(None)?,
                };
                let registry = registry_for(Some(&config))?;
                let reader = crate::daemon::ingest::Reader { config: &config, registry: &registry };
                match store.source(id)?.map(|src| reader.rebuild(src)).transpose()?.flatten() {
                    Some(plan) => {
                        serde_json::to_writer_pretty(&mut out, &plan)?;
                        writeln!(out)?;
                    }
                    None => bail!("revision {id} has no plan (status {})", info.status),
                }
            } else {
                write_revision(&mut out, &store, &info)?;
            }
            out.flush()?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Import { dir, machine, cam, config, jobs } => {
            let config = load_config(config.as_deref())?;
            let registry = registry_for(Some(&config))?;
            let folder = match &machine {
                Some(name) => config.folders.iter().find(|f| f.role == config::Role::Machine && &f.name == name).with_context(|| {
                    let known: Vec<&str> =
                        config.folders.iter().filter(|f| f.role == config::Role::Machine).map(|f| f.name.as_str()).collect();
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
                writeln!(out, "  {}: {why}", file.display())?;
            }
            out.flush()?;
            Ok(if summary.errors.is_empty() { ExitCode::SUCCESS } else { ExitCode::from(1) })
        }
        Command::Reanalyze { since, dialect, work } => reanalyze(&mut out, &work, Some((since.as_deref(), dialect.as_deref()))),
        Command::Worker { work } => reanalyze(&mut out, &work, None),
        Command::Migrate { from, to, site, config } => {
            let site = match (site, &config) {
                (Some(s), _) => s,
                (None, Some(c)) => load_config(Some(c))?.site,
                (None, None) => String::new(),
            };
            anyhow::ensure!(
                !site.trim().is_empty(),
                "name the site the history belongs to: --site HALL2 (or --config with site = \"HALL2\")"
            );
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
        Command::Translate { file, dialect: from, to, output, machine, revision, store: store_args } => {
            translate_command(file, from, to, output, machine, revision, &store_args, &mut out)
        }
        Command::Dialects { files } => {
            if files.is_empty() {
                let r = Registry::shipped();
                for name in r.names() {
                    let d = dialect(&r, name)?;
                    writeln!(out, "{name}\t{}\t{}", d.family, d.title)?;
                }
                return Ok(ExitCode::SUCCESS);
            }
            let mut bad = false;
            for f in files {
                let text = std::fs::read_to_string(&f).with_context(|| format!("cannot read {}", f.display()))?;
                match Registry::shipped().add(&f.display().to_string(), &text) {
                    Ok(d) => writeln!(out, "{}: ok ({} codes, {} addresses)", f.display(), d.codes.len(), d.addresses.len())?,
                    Err(errors) => {
                        bad = true;
                        for e in errors {
                            writeln!(out, "{e}")?;
                        }
                    }
                }
            }
            out.flush()?;
            Ok(if bad { ExitCode::from(1) } else { ExitCode::SUCCESS })
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn translate_command(
    file: Option<PathBuf>,
    from: Option<String>,
    to: Option<String>,
    output: Option<PathBuf>,
    machine: Option<String>,
    revision: Option<i64>,
    store_args: &StoreArgs,
    out: &mut impl Write,
) -> Result<ExitCode> {
    let config = analysis_config(store_args.config.as_deref())?;
    let registry = registry_for(Some(&config))?;
    let folder = match &machine {
        Some(m) => Some(
            config
                .folders
                .iter()
                .find(|f| f.role == config::Role::Machine && &f.name == m)
                .with_context(|| format!("no [[machine]] named `{m}` in the configuration"))?,
        ),
        None => None,
    };
    // A file is read piece by piece: memory does not grow with the program.
    let ((program, mut diags), path, stored_dialect) = match (revision, &file) {
        (Some(id), _) => {
            let store = Store::open_read_only(&db_path(store_args)?)?;
            let Some(src) = store.source(id)? else { bail!("no revision {id}") };
            let bytes = match src.bytes {
                Some(b) => b,
                None => store.content(id)?.unwrap_or_default(),
            };
            (textfile::Program::from_bytes(bytes), PathBuf::from(&src.path), Some(src.dialect))
        }
        (None, Some(f)) => {
            let names = [from.as_deref(), to.as_deref().or(folder.map(|f| f.dialect.as_str()))];
            let opened = open_while_loading(&registry, &names, f);
            (opened.with_context(|| format!("cannot read {}", f.display()))?, f.clone(), None)
        }
        (None, None) => bail!("give a program file or --revision"),
    };
    let from_name = match (from, stored_dialect) {
        (Some(n), _) => n,
        (None, Some(n)) if n != config::AUTO_DIALECT => n,
        _ => {
            let s = pipeline::sniff(&registry, program.head_bytes(), &path);
            eprintln!("{}", sniff_report(&s));
            s.dialect
        }
    };
    let source_dialect = dialect(&registry, &from_name)?;
    let to_name = to.or_else(|| folder.map(|f| f.dialect.clone())).context("give --to DIALECT")?;
    let target = dialect(&registry, &to_name)?;
    if let Some(o) = &output {
        let abs = std::path::absolute(o)?;
        let dir = abs.parent().map(Path::to_path_buf).unwrap_or_default();
        let dir = dir.canonicalize().unwrap_or(dir);
        for f in &config.folders {
            let watched = f.path.canonicalize().unwrap_or_else(|_| f.path.clone());
            if dir.starts_with(&watched) {
                bail!(
                    "{} lies in the watched folder {} ({}): ncplan never writes into a watched folder",
                    o.display(),
                    f.path.display(),
                    f.name
                );
            }
        }
    }
    let text = program.text();
    let name = pipeline::program_name(&text.head())
        .or_else(|| path.file_stem().map(|s| s.to_string_lossy().into_owned()))
        .unwrap_or_else(|| "PROGRAM".into());
    let limits = folder.map(|f| f.limits.clone()).unwrap_or_default();
    // Plan facts for the writer: where each hole's top is (a G81 states only its R level).
    // Only a program with such cycles needs it: the plan holds the toolpath, and a program
    // without them is written in constant memory.
    // They are asked for when the first such cycle needs them. Tool facts from the shop's
    // tool table go into tool comments, which read back where the table is not: they need
    // the plan first, only when the table has tools.
    let (hole_tops, tools) = pipeline::translation_facts(text, &source_dialect, &config.profile);
    let opts = crate::post::Options {
        hole_tops,
        tools,
        units: limits.units.unwrap_or(crate::canon::Units::Mm),
        follow_source_units: limits.units.is_none(),
        limits: crate::post::Limits { max_spindle_speed: limits.max_spindle_speed, max_feed: limits.max_feed, travel: limits.travel },
        ..crate::post::Options::for_program(&name)
    };
    let mut profile = config.profile.clone();
    if let Some(f) = &file {
        profile = config::DirPrograms::beside(&profile, f, config.max_file_bytes);
    }
    // A file is written beside its place and renamed when done: a run that fails (the input
    // changed while it was read, a full disk) leaves no half file, and an earlier one stays.
    let partial =
        output.as_ref().map(|o| o.with_file_name(format!(".{}.partial", o.file_name().map(|n| n.to_string_lossy()).unwrap_or_default())));
    let mut file_out: Box<dyn Write> = match &partial {
        Some(p) => Box::new(BufWriter::new(std::fs::File::create(p).with_context(|| format!("cannot write {}", p.display()))?)),
        None => Box::new(&mut *out),
    };
    let mut error: Option<std::io::Error> = None;
    let mut tops = || crate::post::hole_tops(&pipeline::plan_of_text(text, &source_dialect, &config.profile).0);
    diags.extend(crate::post::translate_with_facts(text, &source_dialect, &target, &profile, opts, &mut tops, |chunk| {
        if error.is_none()
            && let Err(e) = file_out.write_all(chunk)
        {
            error = Some(e);
        }
    }));
    let flushed = match error {
        Some(e) => Err(e),
        None => file_out.flush(),
    };
    drop(file_out);
    let failed = match (flushed, program.trouble()) {
        (Err(e), _) => Some(anyhow::Error::from(e)),
        (Ok(()), Some(why)) => Some(anyhow::anyhow!("{why}; nothing was written")),
        (Ok(()), None) => None,
    };
    if let (Some(p), Some(o)) = (&partial, &output) {
        if failed.is_some() {
            let _ = std::fs::remove_file(p);
        } else {
            std::fs::rename(p, o).with_context(|| format!("cannot write {}", o.display()))?;
        }
    }
    if let Some(e) = failed {
        return Err(e);
    }
    // Lines are counted only as far as the last finding shown: a million-line program with a
    // note near its start is not read to its end again.
    let shown_diags: Vec<&diag::Diagnostic> =
        diags.iter().filter(|x| x.severity != diag::Severity::Note || x.code.as_str().starts_with("post::")).collect();
    print_short(&path.display().to_string(), text, &shown_diags);
    Ok(if diags.iter().any(|x| x.is_error()) { ExitCode::from(1) } else { ExitCode::SUCCESS })
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

fn db_path(args: &StoreArgs) -> Result<Location> {
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

/// Logs to stderr: coloured only on a terminal; under systemd, to the journal with its fields.
fn init_tracing() {
    use std::io::IsTerminal;
    use tracing_subscriber::layer::SubscriberExt;
    use tracing_subscriber::util::SubscriberInitExt;
    let filter = tracing_subscriber::EnvFilter::try_from_env("NCPLAN_LOG").unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    if std::env::var_os("JOURNAL_STREAM").is_some()
        && let Ok(journal) = tracing_journald::layer()
    {
        let _ = tracing_subscriber::registry().with(filter).with(journal.with_syslog_identifier("ncplan".into())).try_init();
        return;
    }
    let _ = tracing_subscriber::fmt()
        .with_env_filter(filter)
        .with_ansi(std::io::stderr().is_terminal())
        .with_writer(std::io::stderr)
        .try_init();
}

fn write_revision(out: &mut impl Write, store: &Store, r: &crate::store::RevisionInfo) -> Result<()> {
    let place = r.machine.as_deref().map_or_else(|| "CAM original".to_owned(), |m| format!("machine {m}"));
    writeln!(out, "revision {}: {place}, program {} ({})", r.id, r.name, r.dialect)?;
    writeln!(out, "  path     {}", r.path)?;
    writeln!(out, "  seen     {}", r.seen_at)?;
    writeln!(out, "  content  {} bytes, {}, sha256 {}", r.size, r.encoding, r.hash)?;
    let status = match (r.status.as_str(), r.partial_of) {
        (_, Some(by)) => format!("a partial write of revision {by}; kept out of the change report"),
        ("too_large", _) => "too large; stored, not analysed".into(),
        ("empty", _) => "holds no program; stored, never compared".into(),
        _ => "analysed".into(),
    };
    writeln!(out, "  status   {status}")?;
    match &r.original {
        Some((id, path, rule, n)) => writeln!(out, "  compared with revision {id} ({path}), paired by {rule}: {n} changes")?,
        None if r.role == "machine" => writeln!(out, "  not compared (no CAM original paired)")?,
        None => {}
    }
    let findings = store.findings(r.id)?;
    writeln!(out, "\nfindings ({}):", findings.len())?;
    for f in &findings {
        writeln!(out, "  {}:{}: {}[{}]: {}", f.line, f.col, f.severity, f.code, f.message)?;
    }
    let changes = store.changes(r.id)?;
    if r.original.is_some() {
        writeln!(out, "\nchanges ({}):", changes.len())?;
        for line in diff::render_plain(&changes) {
            writeln!(out, "  - {line}")?;
        }
    }
    writeln!(out, "\n(--source prints the program, --plan its plan)")?;
    Ok(())
}

/// A writer that flushes at every line, so that a long benchmark shows each figure as it comes.
struct LineFlush<'w, W: Write>(&'w mut W);

impl<W: Write> Write for LineFlush<'_, W> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        let n = self.0.write(buf)?;
        if buf[..n].contains(&b'\n') {
            self.0.flush()?;
        }
        Ok(n)
    }

    fn flush(&mut self) -> std::io::Result<()> {
        self.0.flush()
    }
}

struct Printer<'w, W: Write> {
    out: &'w mut W,
    buf: Vec<u8>,
    writer: CallWriter,
    lines: bool,
    error: Option<std::io::Error>,
}

impl<W: Write> Printer<'_, W> {
    /// Lines are gathered into chunks of about this size before they are written.
    const CHUNK: usize = 64 * 1024;

    fn flush(&mut self) {
        if self.error.is_none()
            && let Err(e) = self.out.write_all(&self.buf)
        {
            self.error = Some(e);
        }
        self.buf.clear();
    }
}

impl<W: Write> CanonSink for Printer<'_, W> {
    fn emit(&mut self, canon: Canon) {
        if self.error.is_some() {
            return;
        }
        if self.lines {
            let _ = write!(self.buf, "{:>6} ", canon.line);
        }
        self.writer.write(&mut self.buf, &canon.op);
        if self.buf.len() >= Self::CHUNK {
            self.flush();
        }
    }
}

/// Where a feature's numbers came from, in words: `size from the tool table, top from the
/// stock`, or the tool-centre path when the size is unknown.
fn feature_sources(f: &crate::plan::Feature) -> String {
    use crate::diff::num;
    use crate::plan::Source;
    let size = match (f.sources.size, f.centre_path) {
        (Source::Unknown, Some((w, l))) => {
            format!("size unknown (the tool's diameter is not known; the tool-centre path spans {} x {})", num(w), num(l))
        }
        (Source::Unknown, None) => "size unknown (the tool's diameter is not known)".to_owned(),
        (Source::Program, _) => "size from the program (the contour as programmed)".to_owned(),
        (s, _) => format!("size from {}", s.words()),
    };
    let angle = match f.sources.point_angle {
        Some(Source::Assumption) => ", point angle assumed (the tool's is not known)".to_owned(),
        Some(s) => format!(", point angle from {}", s.words()),
        None => String::new(),
    };
    format!("{size}, top from {}{angle}", f.sources.top.words())
}

fn write_plan(out: &mut impl Write, plan: &crate::plan::ProcessPlan) -> Result<()> {
    use crate::diff::num;
    writeln!(out, "program {}", plan.program.as_deref().unwrap_or("(unnamed)"))?;
    match &plan.workpiece {
        Some(s) => writeln!(
            out,
            "stock X{} Y{} Z{} size {} x {} x {} (from the {})",
            num(s.origin[0]),
            num(s.origin[1]),
            num(s.origin[2]),
            num(s.size[0]),
            num(s.size[1]),
            num(s.size[2]),
            match (s.source, s.line) {
                (crate::plan::StockSource::Config, _) => "configuration".to_owned(),
                (crate::plan::StockSource::Program, Some(l)) => format!("program, line {l}"),
                (crate::plan::StockSource::Program, None) => "program".to_owned(),
            }
        )?,
        None => writeln!(out, "stock unknown")?,
    }
    for t in &plan.tools {
        let d = t.diameter.map(|d| format!(" D{}", num(d))).unwrap_or_default();
        let r = t.corner_radius.map(|d| format!(" R{}", num(d))).unwrap_or_default();
        let z = t.flutes.map(|d| format!(" Z{d}")).unwrap_or_default();
        let l = t.length_offset.map(|d| format!(" L{}", num(d))).unwrap_or_default();
        writeln!(out, "tool T{} {}{d}{r}{z}{l} {}", t.number, t.kind.as_str().replace('_', " "), t.name.as_deref().unwrap_or(""))?;
    }
    for f in &plan.features {
        let p = f.placement;
        let ws: Vec<String> = f.workingsteps.iter().map(u32::to_string).collect();
        let shape = match &f.kind {
            crate::plan::FeatureKind::PlanarFace { length, width, .. } => format!(" {} x {}", num(*length), num(*width)),
            crate::plan::FeatureKind::RoundHole { diameter, positions, bottom } => {
                let bottom = match bottom {
                    crate::plan::HoleBottom::Through => "through".to_owned(),
                    crate::plan::HoleBottom::Flat => "flat bottom".to_owned(),
                    crate::plan::HoleBottom::Conical(angle) => format!("drill-point bottom {}°", num(*angle)),
                };
                format!(" D{} x{} {bottom}", diameter.map_or("?".into(), num), positions.len())
            }
            crate::plan::FeatureKind::ClosedPocket { rectangle: Some((w, l)), corner_radius, .. }
            | crate::plan::FeatureKind::OutsideProfile { rectangle: Some((w, l)), corner_radius, .. } => {
                format!(" {} x {}{}", num(*w), num(*l), corner_radius.map(|r| format!(" r{}", num(r))).unwrap_or_default())
            }
            crate::plan::FeatureKind::Slot { width, .. } | crate::plan::FeatureKind::Step { width, .. } => {
                format!(" width {}", num(*width))
            }
            _ => String::new(),
        };
        writeln!(
            out,
            "feature {} {}{shape} at X{} Y{} Z{} depth {}{}; workingsteps {}",
            f.id,
            f.kind.label(),
            num(p[0]),
            num(p[1]),
            num(p[2]),
            num(f.depth),
            if f.top_inferred { " (top inferred)" } else { "" },
            ws.join(", ")
        )?;
        if !matches!(f.kind, crate::plan::FeatureKind::Toolpath) {
            writeln!(out, "  {}", feature_sources(f))?;
        }
    }
    for w in &plan.workingsteps {
        let t = &w.technology;
        writeln!(
            out,
            "workingstep {} ({}{}) T{} F{} {} spindle {}, coolant {}, lines {}-{}",
            w.index,
            w.operation.label(),
            w.feature.map(|f| format!(" of feature {f}")).unwrap_or_default(),
            w.tool,
            num(t.feed),
            match t.surface_speed {
                Some(v) => format!("surface speed {} m/min (S at most {})", num(v), num(t.spindle_speed)),
                None => format!("S{}", num(t.spindle_speed)),
            },
            match t.spindle {
                crate::plan::SpindleDir::Cw => "clockwise",
                crate::plan::SpindleDir::Ccw => "counter-clockwise",
                crate::plan::SpindleDir::Off => "off",
            },
            match t.coolant {
                crate::plan::Coolant::Off => "off",
                crate::plan::Coolant::Mist => "mist",
                crate::plan::Coolant::Flood => "flood",
                crate::plan::Coolant::Both => "mist and flood",
            },
            w.lines.0,
            w.lines.1
        )?;
        if let Some(p) = w.start_point {
            writeln!(out, "  start X{} Y{} Z{}; security plane Z{}", num(p[0]), num(p[1]), num(p[2]), num(w.security_plane))?;
        }
        if let Some(s) = &w.strategy {
            // The snake-case names the JSON uses, in words.
            let words =
                |v: serde_json::Result<serde_json::Value>| v.ok().and_then(|v| v.as_str().map(|s| s.replace('_', " "))).unwrap_or_default();
            let mut parts = vec![words(serde_json::to_value(s.kind))];
            if let Some(r) = s.rotation {
                parts.push(match r {
                    crate::plan::Rotation::Cw => "clockwise".into(),
                    crate::plan::Rotation::Ccw => "counter-clockwise".into(),
                });
            }
            if let Some(c) = s.cutmode {
                parts.push(words(serde_json::to_value(c)) + " milling");
            }
            for (name, v) in [
                ("axial depth", w.axial_depth),
                ("stepover", w.radial_depth),
                ("side allowance", w.allowance_side),
                ("bottom allowance", w.allowance_bottom),
            ] {
                if let Some(v) = v {
                    parts.push(format!("{name} {}", num(v)));
                }
            }
            writeln!(out, "  strategy {}", parts.join(", "))?;
        }
        if let (Some(b), Some(d)) = (w.bbox, w.depth) {
            writeln!(
                out,
                "  box X{}..{} Y{}..{} Z{}..{}; depth Z{}; {} mm of cut in {} moves",
                num(b.min[0]),
                num(b.max[0]),
                num(b.min[1]),
                num(b.max[1]),
                num(b.min[2]),
                num(b.max[2]),
                num(d),
                num(w.cutting_length),
                w.toolpath.len()
            )?;
        }
        for h in &w.holes {
            writeln!(out, "  hole X{} Y{} bottom Z{} from R{}", num(h.x), num(h.y), num(h.bottom), num(h.r_plane))?;
        }
    }
    Ok(())
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
            changes.retain(diff::Change::is_machining);
            if changes.is_empty() {
                continue;
            }
        }
        for line in diff::render_plain(&changes) {
            writeln!(out, "- {line}")?;
        }
        writeln!(out)?;
    }
    Ok(())
}

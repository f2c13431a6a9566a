//! The command line: the only module that prints.
//!
//! Exit codes: 0 success; 1 the input has errors (`check`) or changes were found (`diff`
//! with `--exit-code`); 2 usage or operational failure.

#![allow(clippy::print_stdout, clippy::print_stderr)]

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::Arc;

use anyhow::{Context, Result, bail};
use clap::{Parser, Subcommand, ValueEnum};

use crate::canon::{CallWriter, Canon, CanonSink};
use crate::config::{self, Config};
use crate::diag::{self, DiagnosticJson};
use crate::dialect::{Dialect, Registry};
use crate::diff;
use crate::pipeline;
use crate::store::Store;
use crate::text::LineIndex;

/// Recover process plans from CNC programs, diff them against the CAM original, keep the
/// shopfloor's changes.
#[derive(Debug, Parser)]
#[command(name = "ncplan", version)]
struct Cli {
    #[command(subcommand)]
    command: Command,
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
        /// Calls to programs the analysis does not have (a control's resident cycles, shop
        /// subprograms) are errors, not warnings.
        #[arg(long)]
        strict: bool,
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
        #[arg(long, value_enum, default_value = "text")]
        format: Format,
        /// Exit 1 when there are changes.
        #[arg(long)]
        exit_code: bool,
    },
    /// Run read-only SQL against the database.
    Query {
        /// SQL.
        sql: String,
        #[arg(long)]
        db: Option<PathBuf>,
        #[arg(long, value_enum, default_value = "text")]
        format: Format,
    },
    /// Print the shopfloor change report in Markdown.
    Report {
        #[arg(long)]
        db: Option<PathBuf>,
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
    match dispatch(cli.command) {
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
            let text = std::fs::read_to_string(p).with_context(|| format!("cannot read {}", p.display()))?;
            let base = p.parent().map_or_else(|| PathBuf::from("."), Path::to_path_buf);
            let base = if base.as_os_str().is_empty() { PathBuf::from(".") } else { base };
            Config::parse(&text, &std::path::absolute(&base)?)
        }
        None => Config::parse(config::DEMO, &std::env::current_dir()?),
    }
}

fn registry_for(config: Option<&Config>) -> Result<Registry> {
    config::dialect_registry(config.and_then(|c| c.dialects_dir.as_deref()))
}

fn dialect(registry: &Registry, name: &str) -> Result<Arc<Dialect>> {
    registry.get(name).with_context(|| format!("unknown dialect `{name}`; known: {}", registry.names().collect::<Vec<_>>().join(", ")))
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
fn input_setup(input: &Input) -> Result<(Arc<Dialect>, Config, Vec<u8>)> {
    let mut config = analysis_config(input.config.as_deref())?;
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

fn sniff_report(s: &crate::dialect::sniff::Sniffed) -> String {
    let why = if s.evidence.is_empty() { "no evidence; the default".to_owned() } else { s.evidence.join(", ") };
    let next = s.runner_up.as_ref().map(|(n, score)| format!("; next: {n} ({score})")).unwrap_or_default();
    format!("ncplan: dialect {} (sure: {}; score {}: {why}{next}); give --dialect to choose", s.dialect, s.confidence.as_str(), s.score)
}

fn dispatch(command: Command) -> Result<ExitCode> {
    let stdout = std::io::stdout();
    let mut out = BufWriter::new(stdout.lock());
    match command {
        Command::Watch { config } => {
            let config = load_config(config.as_deref())?;
            let registry = registry_for(Some(&config))?;
            init_tracing();
            println!("ncplan watch: database {}", config.database.display());
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
            if let Some(m) = config.folders.iter().find(|f| f.role == config::Role::Machine) {
                println!("Try: cp demo/examples/O1234_edited.nc {}/O1234.nc", m.path.display());
                println!("then: ncplan report --db {}", config.database.display());
            }
            crate::daemon::run(config, registry, Arc::new(crate::daemon::SystemClock))?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Check { input, format, strict } => {
            let (d, config, bytes) = input_setup(&input)?;
            let mut a = pipeline::analyze(&bytes, &d, &config.profile);
            if strict {
                for x in a.diagnostics.iter_mut().filter(|x| x.code == diag::Code::MissingProgram) {
                    x.severity = diag::Severity::Error;
                }
            }
            let path = input.file.display().to_string();
            let idx = LineIndex::new(&a.source.text);
            match format {
                Format::Json => {
                    let ds: Vec<DiagnosticJson> = a.diagnostics.iter().map(|x| DiagnosticJson::new(x, &a.source.text, &idx)).collect();
                    serde_json::to_writer_pretty(&mut out, &serde_json::json!({ "file": path, "dialect": d.name, "diagnostics": ds }))?;
                    writeln!(out)?;
                }
                Format::Text => {
                    for x in &a.diagnostics {
                        write!(out, "{}", diag::render_human(&path, &a.source.text, &idx, x))?;
                    }
                    let errors = a.diagnostics.iter().filter(|x| x.is_error()).count();
                    writeln!(out, "{path}: {errors} errors, {} other findings", a.diagnostics.len() - errors)?;
                }
            }
            out.flush()?;
            Ok(if a.has_errors() { ExitCode::from(1) } else { ExitCode::SUCCESS })
        }
        Command::Bench { dir, rows, runs } => {
            crate::bench::run(&dir, rows, runs, &mut out)?;
            out.flush()?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Canon { input, lines } => {
            let (d, config, bytes) = input_setup(&input)?;
            let (source, mut diags) = crate::text::decode_owned(bytes);
            let mut printer = Printer {
                out: &mut out,
                buf: Vec::with_capacity(Printer::<Vec<u8>>::CHUNK + 256),
                writer: CallWriter::default(),
                lines,
                error: None,
            };
            diags.extend(crate::interp::interpret(&source.text, &d, &config.profile, &mut printer));
            printer.flush();
            if let Some(e) = printer.error.take() {
                return Err(e.into());
            }
            out.flush()?;
            if diags.iter().any(|x| x.is_error()) {
                let idx = LineIndex::new(&source.text);
                let path = input.file.display().to_string();
                for x in diags.iter().filter(|x| x.is_error()) {
                    eprintln!("{}", diag::render_short(&path, &source.text, &idx, x));
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Command::Plan { input, format } => {
            let (d, config, bytes) = input_setup(&input)?;
            let a = pipeline::analyze(&bytes, &d, &config.profile);
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
            let a = pipeline::analyze(&bytes, &d, &config.profile);
            let class = if cc1 { crate::part21::stepnc::Class::Cc1 } else { crate::part21::stepnc::Class::Cc2 };
            let timestamp = timestamp.unwrap_or_else(|| {
                use crate::daemon::Clock;
                crate::daemon::SystemClock.now()
            });
            let (exchange, diags) = crate::part21::stepnc::write(&a.plan, class, &timestamp);
            let text = crate::part21::write(&exchange);
            let path = input.file.display().to_string();
            let idx = LineIndex::new(&a.source.text);
            for x in diags.iter().chain(a.diagnostics.iter().filter(|x| x.is_error())) {
                eprintln!("{}", diag::render_short(&path, &a.source.text, &idx, x));
            }
            match output {
                Some(o) => std::fs::write(&o, text).with_context(|| format!("cannot write {}", o.display()))?,
                None => out.write_all(text.as_bytes())?,
            }
            out.flush()?;
            Ok(ExitCode::SUCCESS)
        }
        Command::Diff { original, edited, dialect: dname, edited_dialect, config, format, exit_code } => {
            let config = analysis_config(config.as_deref())?;
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
            let a = pipeline::analyze(&bytes_a, &da, &config.profile);
            let b = pipeline::analyze(&bytes_b, &db, &config.profile);
            let changes = diff::diff(&a.plan, &b.plan);
            match format {
                Format::Json => {
                    serde_json::to_writer_pretty(&mut out, &changes)?;
                    writeln!(out)?;
                }
                Format::Text => {
                    if changes.is_empty() {
                        writeln!(out, "no semantic changes")?;
                    }
                    for line in diff::render_plain(&changes) {
                        writeln!(out, "{line}")?;
                    }
                }
            }
            out.flush()?;
            Ok(if exit_code && !changes.is_empty() { ExitCode::from(1) } else { ExitCode::SUCCESS })
        }
        Command::Query { sql, db, format } => {
            let db = db_path(db)?;
            let store = Store::open_read_only(&db)?;
            let (cols, rows) = store.query(&sql)?;
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
        Command::Report { db } => {
            let db = db_path(db)?;
            let store = Store::open_read_only(&db)?;
            write_report(&mut out, &store)?;
            out.flush()?;
            Ok(ExitCode::SUCCESS)
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

fn db_path(db: Option<PathBuf>) -> Result<PathBuf> {
    let db = match db {
        Some(d) => d,
        None => load_config(None)?.database,
    };
    if !db.exists() {
        bail!("no database at {} (has `ncplan watch` run?)", db.display());
    }
    Ok(db)
}

fn init_tracing() {
    let filter = tracing_subscriber::EnvFilter::try_from_env("NCPLAN_LOG").unwrap_or_else(|_| tracing_subscriber::EnvFilter::new("info"));
    let _ = tracing_subscriber::fmt().with_env_filter(filter).with_writer(std::io::stderr).try_init();
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

fn write_plan(out: &mut impl Write, plan: &crate::plan::ProcessPlan) -> Result<()> {
    use crate::diff::num;
    writeln!(out, "program {}", plan.program.as_deref().unwrap_or("(unnamed)"))?;
    match &plan.workpiece {
        Some(s) => writeln!(
            out,
            "stock X{} Y{} Z{} size {} x {} x {} (from {:?})",
            num(s.origin[0]),
            num(s.origin[1]),
            num(s.origin[2]),
            num(s.size[0]),
            num(s.size[1]),
            num(s.size[2]),
            s.source
        )?,
        None => writeln!(out, "stock unknown")?,
    }
    for t in &plan.tools {
        let d = t.diameter.map(|d| format!(" D{}", num(d))).unwrap_or_default();
        let r = t.corner_radius.map(|d| format!(" R{}", num(d))).unwrap_or_default();
        let z = t.flutes.map(|d| format!(" Z{d}")).unwrap_or_default();
        let l = t.length_offset.map(|d| format!(" L{}", num(d))).unwrap_or_default();
        writeln!(out, "tool T{} {}{d}{r}{z}{l} {}", t.number, t.kind.as_str(), t.name.as_deref().unwrap_or(""))?;
    }
    for f in &plan.features {
        let p = f.placement;
        let ws: Vec<String> = f.workingsteps.iter().map(u32::to_string).collect();
        let shape = match &f.kind {
            crate::plan::FeatureKind::PlanarFace { length, width, .. } => format!(" {} x {}", num(*length), num(*width)),
            crate::plan::FeatureKind::RoundHole { diameter, positions, bottom } => {
                format!(" D{} x{} {bottom:?}", diameter.map_or("?".into(), num), positions.len())
            }
            crate::plan::FeatureKind::ClosedPocket { rectangle: Some((w, l)), .. } => format!(" {} x {}", num(*w), num(*l)),
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
    }
    for w in &plan.workingsteps {
        let t = &w.technology;
        writeln!(
            out,
            "workingstep {} ({}{}) T{} F{} {} {:?} coolant {:?}, lines {}-{}",
            w.index,
            w.operation.label(),
            w.feature.map(|f| format!(" of feature {f}")).unwrap_or_default(),
            w.tool,
            num(t.feed),
            match t.surface_speed {
                Some(v) => format!("surface speed {} m/min (S at most {})", num(v), num(t.spindle_speed)),
                None => format!("S{}", num(t.spindle_speed)),
            },
            t.spindle,
            t.coolant,
            w.lines.0,
            w.lines.1
        )?;
        if let Some(p) = w.start_point {
            writeln!(out, "  start X{} Y{} Z{}; security plane Z{}", num(p[0]), num(p[1]), num(p[2]), num(w.security_plane))?;
        }
        if let Some(s) = &w.strategy {
            let mut parts = vec![format!("{:?}", s.kind).to_lowercase()];
            if let Some(r) = s.rotation {
                parts.push(format!("{r:?}").to_lowercase());
            }
            if let Some(c) = s.cutmode {
                parts.push(format!("{c:?}").to_lowercase());
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

fn write_report(out: &mut impl Write, store: &Store) -> Result<()> {
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
        let mut changes = Vec::new();
        while i < rows.len() && rows[i][4] == r[4] {
            let x = &rows[i];
            changes.push(diff::Change {
                kind: serde_json::from_value(serde_json::Value::String(x[6].clone())).unwrap_or(diff::ChangeKind::ToolpathChanged),
                workingstep: x[5].parse().unwrap_or(0),
                operation: x[11].clone(),
                field: x[7].clone(),
                before: x[8].clone(),
                after: x[9].clone(),
                line: None,
            });
            i += 1;
        }
        for line in diff::render_plain(&changes) {
            writeln!(out, "- {line}")?;
        }
        writeln!(out)?;
    }
    Ok(())
}

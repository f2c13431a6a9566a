//! `ncplan translate`: write a program for another control: read it in its dialect, write it
//! by the target dialect's output rules.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::process::ExitCode;

use anyhow::{Context, Result, bail};

use super::common::{StoreArgs, analysis_config, db_path, dialect, open_while_loading, print_short, registry_for, sniff_report};
use crate::config;
use crate::pipeline::{self, Diagnostic, Limits, Severity, TranslateOptions, Units};
use crate::store::Store;
use crate::textfile;

/// The arguments of `ncplan translate`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
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
    /// The proof is always made (safe output): the translation is read back in the target's
    /// dialect and every move (in its frame: the work offset, a reference return, machine
    /// coordinates), tool, feed, spindle and coolant compared with the program's before it is
    /// given out; one the target's reader rejects or that runs otherwise is not written
    /// (exit 1). It is read back from the file written beside the output (held in memory only
    /// on its way to standard output). The flag is kept so that scripts giving it still run.
    #[arg(long)]
    check: bool,
    #[command(flatten)]
    store: StoreArgs,
}

/// Runs `ncplan translate`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { file, dialect: from, to, output, machine, revision, check: _, store: store_args } = args;
    // Safe output: the translation is always read back and proven before it is given out, so
    // text the target's own reader rejects, or a toolpath that differs, never leaves.
    let (store_args, out) = (&store_args, &mut out);
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
    let (from_name, guessed) = match (from, stored_dialect) {
        (Some(n), _) => (n, false),
        (None, Some(n)) if n != config::AUTO_DIALECT => (n, false),
        _ => sniffed(&registry, program.head_bytes(), &path, &config),
    };
    let source_dialect = dialect(&registry, &from_name)?;
    let to_name = to.or_else(|| folder.map(|f| f.dialect.clone())).context("give --to DIALECT")?;
    let target = dialect(&registry, &to_name)?;
    if let Some(o) = &output {
        let abs = std::path::absolute(o)?;
        let dir = abs.parent().map(Path::to_path_buf).unwrap_or_default();
        let dir = dir.canonicalize().unwrap_or(dir);
        // Without --config, the folders `ncplan watch` would watch here: the default's.
        let default = if store_args.config.is_none() { super::common::load_config(None).ok() } else { None };
        for f in config.folders.iter().chain(default.iter().flat_map(|c| &c.folders)) {
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
    // The target machine's units and limits; the plan facts the writer needs (hole tops, the
    // tool table's tools) are taken by `pipeline::translate`.
    let opts = TranslateOptions {
        units: limits.units.unwrap_or(Units::Mm),
        follow_source_units: limits.units.is_none(),
        limits: Limits { max_spindle_speed: limits.max_spindle_speed, max_feed: limits.max_feed, travel: limits.travel },
        ..TranslateOptions::for_program(&name)
    };
    let mut profile = config.profile.clone();
    profile.guessed = guessed; // a maker's own finding a warning, which still refuses
    if let Some(f) = &file {
        profile = config::DirPrograms::beside(&profile, f, config.max_file_bytes);
    }
    // A file is written beside its place and renamed when done: a run that fails (the input
    // changed while it was read, a full disk) leaves no half file, and an earlier one stays.
    // The proof reads it back from there, piece by piece; only a translation to standard
    // output is held in memory until it is proven.
    let partial =
        output.as_ref().map(|o| o.with_file_name(format!(".{}.partial", o.file_name().map(|n| n.to_string_lossy()).unwrap_or_default())));
    let mut held = Vec::new();
    let mut file_out: Box<dyn Write> = match &partial {
        Some(p) => Box::new(BufWriter::new(std::fs::File::create(p).with_context(|| format!("cannot write {}", p.display()))?)),
        None => Box::new(&mut held),
    };
    let mut error: Option<std::io::Error> = None;
    diags.extend(pipeline::translate(text, &source_dialect, &target, &profile, opts, |chunk| {
        if error.is_none()
            && let Err(e) = file_out.write_all(chunk)
        {
            error = Some(e);
        }
    }));
    let flushed = match error {
        Some(e) => Err(anyhow::Error::from(e)),
        None => file_out.flush().map_err(anyhow::Error::from),
    };
    drop(file_out);
    // A translation the writer refused is not proven: the refusal says why it is not given out.
    let refused_by_writer = diags.iter().any(|x| x.is_error() && x.code.as_str().starts_with("post::"));
    let proved = match (&flushed, program.trouble(), &partial) {
        (Ok(()), None, _) if refused_by_writer => Ok(()),
        (Ok(()), None, Some(p)) => prove_file(p, text, (&source_dialect, &target), &profile, &mut diags),
        (Ok(()), None, None) => {
            let written = String::from_utf8_lossy(&held);
            let checked = pipeline::check_translation(text, &source_dialect, &*written, &target, &profile, &diags);
            diags.extend(checked);
            Ok(())
        }
        _ => Ok(()),
    };
    // A translation the writer could not make whole, or that runs otherwise, is refused: what
    // it would have written is not given out.
    let refused = diags.iter().any(|x| x.is_error() && x.code.as_str().starts_with("post::"));
    let failed = match (flushed.and(proved), program.trouble()) {
        (Err(e), _) => Some(e),
        (Ok(()), Some(why)) => Some(anyhow::anyhow!("{why}; nothing was written")),
        (Ok(()), None) => None,
    };
    if failed.is_none() && !refused && partial.is_none() {
        out.write_all(&held)?;
    }
    if let (Some(p), Some(o)) = (&partial, &output) {
        if failed.is_some() || refused {
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
    let shown_diags: Vec<&Diagnostic> =
        diags.iter().filter(|x| x.severity != Severity::Note || x.code.as_str().starts_with("post::")).collect();
    print_short(&path.display().to_string(), text, &shown_diags);
    if refused {
        eprintln!("translate: the translation is refused: nothing was written");
    }
    Ok(if diags.iter().any(|x| x.is_error()) { ExitCode::from(1) } else { ExitCode::SUCCESS })
}

/// Proves the translation written to `partial` (`pipeline::check_translation`), reading it
/// back from the file piece by piece; its findings go to `diags`. A file that changed while
/// it was read back is an error: what was proven would not be what is given out.
fn prove_file(
    partial: &Path,
    source: pipeline::Text<'_>,
    (from, to): (&pipeline::Dialect, &pipeline::Dialect),
    profile: &pipeline::Profile,
    diags: &mut Vec<Diagnostic>,
) -> Result<()> {
    let (written, _) = textfile::Program::open(partial).with_context(|| format!("cannot read back {}", partial.display()))?;
    let checked = pipeline::check_translation(source, from, written.text(), to, profile, diags);
    diags.extend(checked);
    match written.trouble() {
        Some(why) => bail!("{why}; nothing was written"),
        None => Ok(()),
    }
}

/// The dialect of a program told from its text, as `ncplan check` tells it (the programs
/// beside as evidence), and whether it is a guess ([`crate::interp::Profile::guessed`]).
fn sniffed(registry: &pipeline::Registry, head: &[u8], path: &Path, config: &crate::config::Config) -> (String, bool) {
    let beside = config::DirPrograms::beside(&config.profile, path, config.max_file_bytes);
    let s = pipeline::sniff_in(registry, head, path, &beside);
    eprintln!("{}", sniff_report(&s));
    let guessed = s.guessed();
    (s.dialect, guessed)
}

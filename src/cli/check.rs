//! `ncplan check`: report every finding in a program; exits 1 when there are errors.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Result, bail};
use clap::ValueEnum;

use super::common::{Format, Input, analysis_config, dialect, registry_for, sniff_report};
use crate::config;
use crate::pipeline::{self, Code, DiagnosticJson, LineIndex, ProgramRole, Severity};

/// The arguments of `ncplan check`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
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
}

/// Runs `ncplan check`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { input, format, role, strict, more } = args;
    let mut config = analysis_config(input.config.as_deref())?;
    input.bound(&mut config);
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
        let (name, guessed) = match &input.dialect {
            Some(n) => (n.clone(), false),
            None => {
                let beside = config::DirPrograms::beside(&base, file, config.max_file_bytes);
                let s = pipeline::sniff_in(&registry, &bytes, file, &beside);
                bar.suspend(|| eprintln!("{}{}", if many { format!("{}: ", file.display()) } else { String::new() }, sniff_report(&s)));
                let guessed = s.guessed();
                (s.dialect, guessed)
            }
        };
        let d = dialect(&registry, &name)?;
        config.profile = config::DirPrograms::beside(&base, file, config.max_file_bytes);
        config.profile = crate::machine_config::for_program(&config.profile, file, input.machine_config.as_deref(), config.max_file_bytes)?;
        let given = match role {
            RoleArg::Main => ProgramRole::Main,
            RoleArg::Called => ProgramRole::Called,
            RoleArg::Auto => base.role,
        };
        config.profile.role = pipeline::role_for(given, file, &d);
        config.profile.guessed = guessed;
        let mut a = pipeline::analyze_plan_owned(bytes, &d, &config.profile);
        if strict {
            for x in a.diagnostics.iter_mut().filter(|x| x.code == Code::MissingProgram) {
                x.severity = Severity::Error;
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
                    text.push_str(&pipeline::render_human(&path, &a.source.text, &idx, x));
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

/// `check --as`: the role of the program checked.
#[derive(Clone, Copy, Debug, ValueEnum)]
enum RoleArg {
    Auto,
    Main,
    Called,
}

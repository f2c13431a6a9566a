//! `ncplan stepnc`: write the recovered plan as STEP-NC: ISO 10303-21 in the ISO 14649 flavour.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};

use super::common::{Input, input_setup};
use crate::pipeline::{self, LineIndex, StepNcClass};

/// The arguments of `ncplan stepnc`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
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
}

/// Runs `ncplan stepnc`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { input, cc1, cc2: _, output, timestamp } = args;
    let (d, config, bytes) = input_setup(&input)?;
    let a = pipeline::analyze_plan_owned(bytes, &d, &config.profile);
    let class = if cc1 { StepNcClass::Cc1 } else { StepNcClass::Cc2 };
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
            match pipeline::write_stepnc(&a.plan, class, &timestamp, std::io::BufWriter::new(file)) {
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
        None => pipeline::write_stepnc(&a.plan, class, &timestamp, &mut out)?.1,
    };
    out.flush()?;
    let path = input.file.display().to_string();
    let idx = LineIndex::new(&a.source.text);
    for x in diags.iter().chain(a.diagnostics.iter().filter(|x| x.is_error() || x.stops_analysis())) {
        eprintln!("{}", pipeline::render_short(&path, &a.source.text, &idx, x));
    }
    Ok(ExitCode::SUCCESS)
}

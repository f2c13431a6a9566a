//! `ncplan plan`: print the recovered process plan.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Result;

use super::common::{Format, Input, input_setup, say_stops};
use crate::pipeline;

/// The arguments of `ncplan plan`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    #[command(flatten)]
    input: Input,
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
}

/// Runs `ncplan plan`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { input, format } = args;
    let (d, config, bytes) = input_setup(&input)?;
    let a = pipeline::analyze_plan_owned(bytes, &d, &config.profile);
    say_stops(&input.file, &a.source.text, &a.diagnostics);
    match format {
        Format::Json => {
            serde_json::to_writer_pretty(&mut out, &a.plan)?;
            writeln!(out)?;
        }
        Format::Text => out.write_all(pipeline::describe_plan(&a.plan).as_bytes())?,
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

//! `ncplan dialects`: list the known dialects, or check dialect files.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::{Context, Result};

use super::common::dialect;
use crate::pipeline::Registry;

/// The arguments of `ncplan dialects`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    /// Dialect files to check.
    files: Vec<PathBuf>,
}

/// Runs `ncplan dialects`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { files } = args;
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

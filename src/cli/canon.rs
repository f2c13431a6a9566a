//! `ncplan canon`: print the NIST canonical machining functions, one call per line.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{Result, bail};

use super::common::{Input, input_program, print_short};
use crate::pipeline::{self, CallWriter, Canon, CanonSink, Diagnostic, TextRange};

/// The arguments of `ncplan canon`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    #[command(flatten)]
    input: Input,
    /// Prefix each call with its source line.
    #[arg(long)]
    lines: bool,
}

/// Runs `ncplan canon`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { input, lines } = args;
    // Read piece by piece: memory does not grow with the program.
    let (d, mut config, program, mut diags) = input_program(&input)?;
    // The calls are printed as they come, not kept: the bound in memory does not apply,
    // unless the command line gives one.
    if input.max_memory_mb.is_none() {
        config.profile.streamed();
    }
    let mut printer = Printer {
        out: &mut out,
        buf: Vec::with_capacity(Printer::<Vec<u8>>::CHUNK + 256),
        writer: CallWriter::default(),
        lines,
        error: None,
    };
    diags.extend(pipeline::canon(program.text(), &d, &config.profile, &mut printer));
    printer.flush();
    if let Some(e) = printer.error.take() {
        return Err(e.into());
    }
    out.flush()?;
    if let Some(why) = program.trouble() {
        bail!("{why}");
    }
    let errors: Vec<&Diagnostic> = diags.iter().filter(|x| x.is_error() || x.stops_analysis()).collect();
    print_short(&input.file.display().to_string(), program.text(), &errors);
    Ok(ExitCode::SUCCESS)
}

/// The sink `canon` prints to: each call as `rs274 -g` writes it, gathered into chunks; the
/// first write error is kept and the rest skipped.
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

    /// The common move printed from where it lies: the same line `emit` prints for its op.
    #[inline]
    fn straight(&mut self, rapid: bool, to: &[f64; 6], _origin: TextRange, line: u32) {
        if self.error.is_some() {
            return;
        }
        if self.lines {
            let _ = write!(self.buf, "{line:>6} ");
        }
        self.writer.write_straight(&mut self.buf, rapid, to);
        if self.buf.len() >= Self::CHUNK {
            self.flush();
        }
    }
}

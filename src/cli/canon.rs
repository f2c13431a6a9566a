//! `ncplan canon`: print the NIST canonical machining functions, one call per line.

use std::io::Write;
use std::process::ExitCode;

use anyhow::{Result, bail};

use super::common::{Input, input_program, print_short};
use crate::pipeline::{self, CallWriter, Canon, CanonOp, CanonSink, Diagnostic, MOVE_LINE, TextRange};

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
        buf: vec![0; Printer::<Vec<u8>>::CHUNK + MOVE_LINE],
        used: 0,
        other: Vec::with_capacity(256),
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
    /// The chunk being gathered, its first `used` bytes. Of a fixed length, a chunk and
    /// room for one straight move's line beyond it, so that a move is written where it goes
    /// ([`CallWriter::write_straight_at`]): no line put together elsewhere and copied in.
    buf: Vec<u8>,
    used: usize,
    /// Any other call is written here first, then copied into the chunk.
    other: Vec<u8>,
    writer: CallWriter,
    lines: bool,
    error: Option<std::io::Error>,
}

impl<W: Write> Printer<'_, W> {
    /// Lines are gathered into chunks of about this size before they are written.
    const CHUNK: usize = 64 * 1024;

    fn flush(&mut self) {
        self.write_out(self.used);
        self.used = 0;
    }

    /// Writes the chunk's first `n` bytes, unless a write failed before.
    fn write_out(&mut self, n: usize) {
        if self.error.is_none()
            && let Err(e) = self.out.write_all(&self.buf[..n])
        {
            self.error = Some(e);
        }
    }

    /// Puts the call written into `other` after the chunk's calls.
    fn put_other(&mut self) {
        let n = self.other.len();
        if self.used + n > self.buf.len() {
            self.flush();
        }
        if n > self.buf.len() {
            if self.error.is_none()
                && let Err(e) = self.out.write_all(&self.other)
            {
                self.error = Some(e);
            }
        } else {
            self.buf[self.used..self.used + n].copy_from_slice(&self.other);
            self.used += n;
        }
        if self.used >= Self::CHUNK {
            self.flush();
        }
    }

    /// The straight move's line, written where it goes in the chunk (where no line number
    /// goes before it); through `other` where a number needs the standard formatter.
    #[inline(always)]
    fn put_straight(&mut self, rapid: bool, to: &[f64; 6]) {
        // `used` stays below a chunk between calls: the room for a line is there.
        let room = self.buf[self.used..].first_chunk_mut::<MOVE_LINE>().expect("a chunk leaves room for a move");
        match self.writer.write_straight_at(room, rapid, to) {
            Some(n) => {
                self.used += n;
                if self.used >= Self::CHUNK {
                    self.flush();
                }
            }
            None => {
                self.other.clear();
                self.writer.write_straight(&mut self.other, rapid, to);
                self.put_other();
            }
        }
    }
}

impl<W: Write> CanonSink for Printer<'_, W> {
    fn emit(&mut self, canon: Canon) {
        // A writer's marker prints no call.
        if self.error.is_some() || matches!(canon.op, CanonOp::Known(_) | CanonOp::ShiftUnknown(_)) {
            return;
        }
        if !self.lines {
            match &canon.op {
                CanonOp::StraightTraverse(to) => return self.put_straight(true, to),
                CanonOp::StraightFeed(to) => return self.put_straight(false, to),
                _ => {}
            }
        }
        self.other.clear();
        if self.lines {
            let _ = write!(self.other, "{:>6} ", canon.line);
        }
        self.writer.write(&mut self.other, &canon.op);
        self.put_other();
    }

    /// The common move printed from where it lies: the same line `emit` prints for its op.
    #[inline]
    fn straight(&mut self, rapid: bool, to: &[f64; 6], _origin: TextRange, line: u32) {
        if self.error.is_some() {
            return;
        }
        if self.lines {
            self.other.clear();
            let _ = write!(self.other, "{line:>6} ");
            self.writer.write_straight(&mut self.other, rapid, to);
            return self.put_other();
        }
        self.put_straight(rapid, to);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::pipeline::write_call_bytes;

    /// The printer's chunks, with moves written where they go and other calls copied in,
    /// hold the lines `write_call_bytes` writes, in order, across chunk ends; with line
    /// numbers too, and for moves whose numbers only the standard formatter writes.
    #[test]
    fn the_printer_prints_the_calls_as_written_one_by_one() {
        for lines in [false, true] {
            let mut out = Vec::new();
            let mut want = Vec::new();
            let mut printer = Printer {
                out: &mut out,
                buf: vec![0; Printer::<Vec<u8>>::CHUNK + MOVE_LINE],
                used: 0,
                other: Vec::new(),
                writer: CallWriter::default(),
                lines,
                error: None,
            };
            let long = "x".repeat(3 * Printer::<Vec<u8>>::CHUNK);
            for i in 0..20_000u32 {
                let x = f64::from(i % 900) * 0.2 - 7.0;
                let ops = [
                    CanonOp::StraightFeed([x, 1.5, -x * 0.013, 0.0, 0.0, 0.0]),
                    CanonOp::StraightTraverse([x * 1e6, -x * 1e6, 0.5, 12_345.678_9, -x, 1.5]),
                    CanonOp::StraightFeed([x, f64::NAN, 1e300, 0.0, 0.0, 0.0]),
                    CanonOp::Comment(if i % 5000 == 7 { long.clone() } else { format!("c{i}") }),
                ];
                for (k, op) in ops.into_iter().enumerate() {
                    let line = i * 4 + k as u32;
                    if lines {
                        want.extend_from_slice(format!("{line:>6} ").as_bytes());
                    }
                    write_call_bytes(&mut want, &op);
                    let origin = TextRange::default();
                    match op {
                        CanonOp::StraightFeed(to) if k == 0 => printer.straight(false, &to, origin, line),
                        CanonOp::StraightTraverse(to) if i % 2 == 0 => printer.straight(true, &to, origin, line),
                        op => printer.emit(Canon { op, origin, line }),
                    }
                }
            }
            printer.flush();
            assert!(printer.error.is_none());
            assert!(out == want, "lines {lines}: the printed text differs");
        }
    }
}

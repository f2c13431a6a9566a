//! `ncplan bench`: generate the benchmark programs and time `canon` on them, beside `rs274`
//! if installed; or measure the daemon, a corpus, the web pages or the storage engines.

use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

use anyhow::Result;

/// The arguments of `ncplan bench`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    /// Where to write the programs.
    #[arg(long, default_value = "target/bench")]
    dir: PathBuf,
    /// Rows of 500 blocks in the surfacing program (2000 rows: 1 million blocks, ~27 MB).
    #[arg(long, default_value_t = 2000)]
    rows: usize,
    /// An older ncplan executable to time `canon` with beside this one (how much faster
    /// the analysis has become).
    #[arg(long, value_name = "EXE")]
    baseline: Option<PathBuf>,
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
}

/// Runs `ncplan bench`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { dir, rows, baseline, runs, daemon, corpus, files, kills, web, postgres, simulate } = args;
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
        crate::bench::run(&dir, rows, runs, baseline.as_deref(), &mut LineFlush(&mut out))?;
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
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

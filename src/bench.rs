//! `ncplan bench`: generates the benchmark programs and measures `ncplan canon` against
//! LinuxCNC's `rs274` on the same files. Shell code: it writes files, reads the clock and
//! runs processes. Timings live here and never in tests.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

/// The 3D surfacing program: a zig-zag over a sine surface, `X.. Y.. Z..` blocks with an arc
/// at every tenth row change. Deterministic; `rows × 500` linear blocks.
pub fn surfacing_program(rows: usize) -> String {
    let mut s = String::with_capacity(rows * 500 * 30);
    s.push_str("%\n(ncplan benchmark: 3D surfacing, ball end mill)\nG21 G90 G17 G54\nT1 M6\nS12000 M3\nG0 X0 Y0 Z5\nG1 Z0 F1500\n");
    let mut y = 0.0f64;
    for row in 0..rows {
        for i in 0..500 {
            let k = if row % 2 == 0 { i } else { 499 - i };
            let x = f64::from(k) * 0.2;
            let z = -1.0 + 0.5 * (x * 0.05).sin() * (y * 0.05).cos();
            let _ = writeln!(s, "X{x:.3} Y{y:.3} Z{z:.4}");
        }
        y += 0.2;
        if row % 10 == 9 {
            let x = if row % 2 == 0 { 99.8 } else { 0.0 };
            // A half-circle step-over to the next row.
            let _ = writeln!(s, "G3 X{x:.3} Y{y:.3} R0.15\nG1");
        }
    }
    s.push_str("G0 Z5\nM30\n%\n");
    s
}

/// The macro-heavy program: nested O-word loops that compute every point with named
/// parameters and trigonometry (`rows × 1000` moves).
pub fn macro_program(rows: usize) -> String {
    format!(
        "%\n(ncplan benchmark: macro-heavy surfacing)\nG21 G90 G17\nT1 M6\nS10000 M3\nF1200\nG0 X0 Y0 Z5\n\
         #<row> = 0\n\
         o100 while [#<row> LT {rows}]\n\
         \x20 #<col> = 0\n\
         \x20 o101 while [#<col> LT 1000]\n\
         \x20   #<x> = [#<col> * 0.1]\n\
         \x20   #<y> = [#<row> * 0.5]\n\
         \x20   G1 X#<x> Y#<y> Z[-1 + 0.5 * SIN[#<x> * 3.6] * COS[#<y> * 3.6]]\n\
         \x20   #<col> = [#<col> + 1]\n\
         \x20 o101 endwhile\n\
         \x20 #<row> = [#<row> + 1]\n\
         o100 endwhile\n\
         G0 Z5\nM30\n%\n"
    )
}

/// One measurement: best of `runs` wall-clock times of a command whose output goes to
/// /dev/null.
fn time_command(program: &str, args: &[&str], runs: u32) -> Result<Duration> {
    let mut best = Duration::MAX;
    for _ in 0..runs {
        let t = Instant::now();
        let status = Command::new(program)
            .args(args)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .stdin(Stdio::null())
            .status()
            .with_context(|| format!("cannot run {program}"))?;
        let elapsed = t.elapsed();
        if !status.success() && program != "rs274" {
            anyhow::bail!("{program} {} failed: {status}", args.join(" "));
        }
        best = best.min(elapsed);
    }
    Ok(best)
}

fn rs274_available() -> bool {
    Command::new("rs274").arg("--help").stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok()
}

/// Writes the benchmark programs into `dir` and prints a side-by-side table.
pub fn run(dir: &Path, rows: usize, runs: u32, out: &mut impl std::io::Write) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let exe = std::env::current_exe()?;
    let exe = exe.to_string_lossy().into_owned();
    let macro_rows = (rows / 20).max(1);
    let programs: [(&str, PathBuf, String, usize); 2] = [
        ("3D surfacing", dir.join("surface.ngc"), surfacing_program(rows), rows * 500 + rows / 10),
        ("macro-heavy", dir.join("macro.ngc"), macro_program(macro_rows), macro_rows * 1000),
    ];
    // rs274 has no tool table by default; give it an empty one.
    let table = dir.join("zero.tbl");
    std::fs::write(&table, (1..100).map(|i| format!("T{i} P{i} Z0 D0\n")).collect::<String>())?;
    let with_rs274 = rs274_available();
    writeln!(out, "program        size       moves      ncplan canon                    rs274 -g                        ratio")?;
    for (what, path, text, moves) in &programs {
        std::fs::write(path, text).with_context(|| format!("cannot write {}", path.display()))?;
        let mb = text.len() as f64 / 1e6;
        let p = path.to_string_lossy();
        let ours = time_command(&exe, &["canon", &p], runs)?;
        let rate = |t: Duration| {
            format!("{:6.3} s {:6.1} MB/s {:5.2} M moves/s", t.as_secs_f64(), mb / t.as_secs_f64(), *moves as f64 / t.as_secs_f64() / 1e6)
        };
        let theirs = if with_rs274 { Some(time_command("rs274", &["-g", "-t", &table.to_string_lossy(), &p], runs)?) } else { None };
        let theirs_text = theirs.map_or_else(|| "(rs274 not installed)".to_owned(), rate);
        let ratio = theirs.map_or_else(String::new, |t| format!("{:.1}x", t.as_secs_f64() / ours.as_secs_f64()));
        writeln!(out, "{what:<14} {mb:6.1} MB {moves:>9}  {}  {theirs_text:<31} {ratio}", rate(ours))?;
    }
    writeln!(out)?;
    writeln!(out, "side by side: hyperfine -w1 '{exe} canon {0}/surface.ngc' 'rs274 -g -t {0}/zero.tbl {0}/surface.ngc'", dir.display())?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn generated_programs_have_the_promised_shape() {
        let s = surfacing_program(20);
        assert_eq!(s.lines().filter(|l| l.starts_with('X')).count(), 20 * 500);
        assert_eq!(s.lines().filter(|l| l.starts_with("G3")).count(), 2);
        assert_eq!(s, surfacing_program(20), "deterministic");
        assert!(macro_program(3).contains("o100 while [#<row> LT 3]"));
    }
}

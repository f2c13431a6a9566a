//! `ncplan bench`: generates the benchmark programs and measures `ncplan canon` against
//! LinuxCNC's `rs274` on the same files. Shell code: it writes files, reads the clock and
//! runs processes. Timings live here and never in tests.
//!
//! `ncplan bench`: generates the 1M-block surfacing and the macro-heavy programs (LinuxCNC
//! O-words and named parameters, Siemens R parameters and `DEF` variables, Heidenhain Q
//! parameters and `FN` jumps) and times `canon` beside `rs274` (and beside an older build
//! with `--baseline`), with the moves each makes, and `translate` into a new file (the last
//! output removed first) and over the last output (a rename over a file makes ext4 write the
//! new one back at once); `--corpus DIR` times `check` on every file of a
//! corpus, one process each, with its peak memory, and lists the slowest; `--daemon` measures a real `ncplan watch` (the
//! huge program's ingest, peak memory and stored size beside `plan`, `diff`, `stepnc`; idle CPU;
//! edit latency; a burst; a kill loop); `--postgres URL` ingest on both engines, and with
//! `--simulate N` the report queries on a simulated plant of N revisions; `--web --postgres
//! URL` renders the workspace's pages on PostgreSQL too. Timings live here, never in tests.

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

/// The Siemens macro-heavy program: the same surface from `DEF` variables and R
/// parameters, rows by a `WHILE` loop, points by a backward jump to a label (`rows × 1000`
/// moves).
pub fn siemens_macro_program(rows: usize) -> String {
    format!(
        "; ncplan benchmark: Siemens macro-heavy surfacing\nDEF REAL XP, YP\nDEF INT COL\nG17 G90 G71\nT1 D1\nM6\nS10000 M3\nF1200\nG0 X0 Y0 Z5\n\
         R1=0\n\
         WHILE R1<{rows}\n\
         \x20 COL=0\n\
         \x20 POINT:\n\
         \x20 XP=COL*0.1\n\
         \x20 YP=R1*0.5\n\
         \x20 R2=-1+0.5*SIN(XP*3.6)*COS(YP*3.6)\n\
         \x20 G1 X=XP Y=YP Z=R2\n\
         \x20 COL=COL+1\n\
         \x20 IF COL<1000 GOTOB POINT\n\
         \x20 R1=R1+1\n\
         ENDWHILE\n\
         G0 Z5\nM30\n"
    )
}

/// The Heidenhain macro-heavy program: the same surface from Q parameters, by `FN`
/// arithmetic and formulas, its loops `FN 12` jumps back to labels (`rows × 1000` moves).
pub fn heidenhain_macro_program(rows: usize) -> String {
    let lines = [
        "BEGIN PGM MACRO MM".to_owned(),
        "; ncplan benchmark: Heidenhain macro-heavy surfacing".into(),
        "TOOL CALL 1 Z S10000".into(),
        "L X+0 Y+0 Z+5 R0 FMAX M3".into(),
        "L Z+0 R0 F1200".into(),
        "FN 0: Q1 = +0".into(),
        "LBL 1".into(),
        "FN 0: Q2 = +0".into(),
        "LBL 2".into(),
        "FN 3: Q3 = +Q2 * +0.1".into(),
        "Q4 = Q1 * 0.5".into(),
        "Q5 = -1 + 0.5 * SIN ( Q3 * 3.6 ) * COS ( Q4 * 3.6 )".into(),
        "L X+Q3 Y+Q4 Z+Q5".into(),
        "FN 1: Q2 = +Q2 + +1".into(),
        "FN 12: IF +Q2 LT +1000 GOTO LBL 2".into(),
        "Q1 = Q1 + 1".into(),
        format!("FN 12: IF +Q1 LT +{rows} GOTO LBL 1"),
        "L Z+5 R0 FMAX".into(),
        "M30".into(),
        "END PGM MACRO MM".into(),
    ];
    lines.iter().enumerate().map(|(n, l)| format!("{n} {l}\n")).collect()
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
pub fn run(dir: &Path, rows: usize, runs: u32, baseline: Option<&Path>, out: &mut impl std::io::Write) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let exe = std::env::current_exe()?;
    let exe = exe.to_string_lossy().into_owned();
    canon_table(dir, &exe, rows, runs, baseline, out)?;
    writeln!(out)?;
    // Translation: the surfacing program written for three controls, and at half its size,
    // to show the memory does not grow with the program.
    let surface = dir.join("surface.ngc");
    let half = dir.join("surface_half.ngc");
    std::fs::write(&half, surfacing_program((rows / 2).max(1)))?;
    // Each timed run writes a new file: the one before is removed first, so that no run pays
    // for the file system's work on another's output (writing back its pages, freeing them).
    // Writing over the file a run left costs that work too; it is timed apart.
    writeln!(
        out,
        "translate (surfacing, from linuxcnc)   output            rate of output   over its last output   peak memory (half-size program)"
    )?;
    for to in ["fanuc", "siemens", "heidenhain"] {
        let mut best: Option<(Duration, u64)> = None;
        let target = dir.join(format!("surface.{to}"));
        let args = |src: &Path, dst: &Path| {
            vec![
                "translate".to_owned(),
                src.to_string_lossy().into_owned(),
                "-d".into(),
                "linuxcnc".into(),
                "--to".into(),
                to.into(),
                "-o".into(),
                dst.to_string_lossy().into_owned(),
            ]
        };
        let full = args(&surface, &target);
        let full: Vec<&str> = full.iter().map(String::as_str).collect();
        for _ in 0..runs {
            remove_if_there(&target)?;
            let m = measured(&exe, &full)?;
            if best.is_none_or(|b| m.0 < b.0) {
                best = Some(m);
            }
        }
        let (t, peak) = best.context("no run")?;
        let mut over = Duration::MAX;
        for _ in 0..runs {
            over = over.min(measured(&exe, &full)?.0);
        }
        let small = args(&half, &dir.join(format!("surface_half.{to}")));
        let small: Vec<&str> = small.iter().map(String::as_str).collect();
        let (_, half_peak) = measured(&exe, &small)?;
        let size = std::fs::metadata(&target)?.len() as f64 / 1e6;
        writeln!(
            out,
            "  to {to:<11} {:6.3} s       {size:6.1} MB       {:7.1} MB/s      {:6.3} s {:6.1} MB/s   {:.1} MB ({:.1} MB)",
            t.as_secs_f64(),
            size / t.as_secs_f64(),
            over.as_secs_f64(),
            size / over.as_secs_f64(),
            peak as f64 / 1e6,
            half_peak as f64 / 1e6
        )?;
    }
    writeln!(out)?;
    memory_by_size(dir, &exe, rows, out)?;
    writeln!(out)?;
    diff_pairs(dir, &exe, runs, out)?;
    writeln!(out)?;
    writeln!(out, "side by side: hyperfine -w1 '{exe} canon {0}/surface.ngc' 'rs274 -g -t {0}/zero.tbl {0}/surface.ngc'", dir.display())?;
    Ok(())
}

/// A benchmark program: its name, file, text, moves, dialect and whether rs274 reads it.
struct Program {
    what: &'static str,
    path: PathBuf,
    text: String,
    moves: usize,
    dialect: &'static str,
    rs274: bool,
}

/// The programs `canon` is timed on: the surfacing program, and the macro-heavy one in
/// LinuxCNC's, Siemens' and Heidenhain's macro language.
fn canon_programs(dir: &Path, rows: usize) -> Vec<Program> {
    let macro_rows = (rows / 20).max(1);
    let program = |what, file: &str, text, moves, dialect, rs274| Program { what, path: dir.join(file), text, moves, dialect, rs274 };
    vec![
        program("3D surfacing", "surface.ngc", surfacing_program(rows), rows * 500 + rows / 10, "linuxcnc", true),
        program("macro-heavy", "macro.ngc", macro_program(macro_rows), macro_rows * 1000, "linuxcnc", true),
        program("Siemens macro", "macro.mpf", siemens_macro_program(macro_rows), macro_rows * 1000, "siemens", false),
        program("Heidenhain Q", "macro.h", heidenhain_macro_program(macro_rows), macro_rows * 1000, "heidenhain", false),
    ]
}

/// Times `canon` on each benchmark program (with the default configuration: its analysis
/// bound must let every one run to its end) beside `rs274 -g`, and beside the `baseline`
/// executable (an older ncplan) when given; then counts the moves each makes, which must be
/// the same.
fn canon_table(dir: &Path, exe: &str, rows: usize, runs: u32, baseline: Option<&Path>, out: &mut impl std::io::Write) -> Result<()> {
    // rs274 has no tool table by default; give it an empty one.
    let table = dir.join("zero.tbl");
    std::fs::write(&table, (1..100).map(|i| format!("T{i} P{i} Z0 D0\n")).collect::<String>())?;
    let table = table.to_string_lossy().into_owned();
    let with_rs274 = rs274_available();
    let baseline = baseline.map(|b| b.to_string_lossy().into_owned());
    writeln!(
        out,
        "program        size       moves      ncplan canon                    rs274 -g                        ratio  moves (ncplan / rs274)"
    )?;
    for Program { what, path, text, moves, dialect, rs274 } in canon_programs(dir, rows) {
        std::fs::write(&path, &text).with_context(|| format!("cannot write {}", path.display()))?;
        let mb = text.len() as f64 / 1e6;
        let p = path.to_string_lossy();
        let args = ["canon", "-d", dialect, &p];
        let ours = time_command(exe, &args, runs)?;
        let rate = |t: Duration| {
            format!("{:6.3} s {:6.1} MB/s {:5.2} M moves/s", t.as_secs_f64(), mb / t.as_secs_f64(), moves as f64 / t.as_secs_f64() / 1e6)
        };
        let rs274_args = ["-g", "-t", &table, &p];
        let theirs = if with_rs274 && rs274 { Some(time_command("rs274", &rs274_args, runs)?) } else { None };
        let theirs_text = match theirs {
            Some(t) => rate(t),
            None if rs274 => "(rs274 not installed)".to_owned(),
            None => "(not a LinuxCNC program)".to_owned(),
        };
        let ratio = theirs.map_or_else(String::new, |t| format!("{:.1}x", t.as_secs_f64() / ours.as_secs_f64()));
        let made = count_moves(exe, &args)?;
        let theirs_made = if theirs.is_some() { count_moves("rs274", &rs274_args)?.to_string() } else { "-".to_owned() };
        writeln!(out, "{what:<14} {mb:6.1} MB {moves:>9}  {}  {theirs_text:<31} {ratio:>6} {made} / {theirs_made}", rate(ours))?;
        if let Some(b) = &baseline {
            // An older build stopped blocks run again at 250,000 by default: lifted, so that
            // it makes every move too.
            let lift = dir.join("baseline.toml");
            std::fs::write(&lift, "[database]\npath = 'unused.db'\n[analysis]\nmax_repeated_blocks = 1000000000\n")?;
            let lift = lift.to_string_lossy().into_owned();
            let args = ["canon", "--config", &lift, "-d", dialect, &p];
            let before = time_command(b, &args, runs)?;
            let before_made = count_moves(b, &args)?;
            writeln!(
                out,
                "  baseline     {}: {:.1}x faster now; {before_made} moves",
                rate(before),
                before.as_secs_f64() / ours.as_secs_f64()
            )?;
        }
    }
    Ok(())
}

/// The moves (straight and arc, feed and traverse) a canonical text written by `program
/// args` has: ncplan's and rs274's write the same names.
fn count_moves(program: &str, args: &[&str]) -> Result<usize> {
    let output = Command::new(program).args(args).stdin(Stdio::null()).stderr(Stdio::null()).output()?;
    let text = String::from_utf8_lossy(&output.stdout);
    Ok(text.lines().filter(|l| ["STRAIGHT_FEED(", "STRAIGHT_TRAVERSE(", "ARC_FEED("].iter().any(|m| l.contains(m))).count())
}

/// A pocket cleared in zig-zag passes `step` apart, then its outline: one program of a
/// shop, `units` 21 (mm) or 20 (values divided by `scale`).
fn pocket_program(step: f64, units: u8, scale: f64) -> String {
    let mut s = format!("%\nO2000 (POCKET)\nG{units} G90 G17 G40 G80\nT3 M6\nS6000 M3\nG54 G0 X0. Y0.\nG43 H3 Z5.\n");
    let c = |v: f64| format!("{:.4}", v / scale);
    for layer in 1..=4 {
        let _ = writeln!(s, "G1 Z{} F300.", c(-f64::from(layer)));
        let mut y = 0.0;
        let mut forward = true;
        while y <= 60.0 {
            let _ = writeln!(s, "G1 X{} Y{} F1200.", c(if forward { 100.0 } else { 0.0 }), c(y));
            y += step;
            let _ = writeln!(s, "Y{}", c(y.min(60.0)));
            forward = !forward;
        }
        let _ = writeln!(s, "G0 Z5.\nX0. Y0.");
    }
    let _ = writeln!(s, "G1 Z-4. F300.\nG41 D3 X5. Y5.\nX95.\nY55.\nX5.\nY5.\nG40 X0. Y0.\nG0 Z50.\nM30\n%");
    s
}

/// The pairs of programs under 64 KB that are hardest to diff: a unit switch with the
/// contour rewritten, a program regenerated with another stepover, two operations swapped,
/// every block shuffled; and the surfacing program against itself with one line changed.
/// Prints each pair's time and peak memory, and the slowest.
fn diff_pairs(dir: &Path, exe: &str, runs: u32, out: &mut impl std::io::Write) -> Result<()> {
    // About 40 KB each: 200 passes over four layers.
    let pocket = pocket_program(0.3, 21, 1.0);
    let swapped = {
        let body: Vec<&str> = pocket.lines().collect();
        let cut = body.iter().position(|l| l.starts_with("G1 Z-3.")).unwrap_or(body.len() / 2);
        let end = body.iter().position(|l| l.starts_with("G1 Z-4.")).unwrap_or(body.len());
        let mut v: Vec<&str> = body[..8].to_vec();
        v.extend(&body[cut..end]);
        v.extend(&body[8..cut]);
        v.extend(&body[end..]);
        v.join("\n") + "\n"
    };
    let shuffled = {
        let mut v: Vec<&str> = pocket.lines().collect();
        // A fixed permutation: every 7th line first, and so on.
        v.sort_by_key(|l| l.len() % 7);
        v.join("\n") + "\n"
    };
    let pairs: [(&str, String, String); 4] = [
        ("units switched, contour rewritten", pocket.clone(), pocket_program(0.3, 20, 25.4)),
        ("regenerated, other stepover", pocket.clone(), pocket_program(0.25, 21, 1.0)),
        ("two operations swapped", pocket.clone(), swapped),
        ("every block shuffled", pocket.clone(), shuffled),
    ];
    writeln!(out, "diff (pairs under 64 KB)                 bytes          time     peak memory")?;
    let mut slowest = (Duration::ZERO, String::new());
    for (k, (what, a, b)) in pairs.iter().enumerate() {
        let (pa, pb) = (dir.join(format!("diff{k}_a.nc")), dir.join(format!("diff{k}_b.nc")));
        std::fs::write(&pa, a)?;
        std::fs::write(&pb, b)?;
        let args = ["diff", "-d", "fanuc", &pa.to_string_lossy(), &pb.to_string_lossy()].map(str::to_owned);
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let mut best: Option<(Duration, u64)> = None;
        for _ in 0..runs {
            let m = measured(exe, &args)?;
            best = Some(best.map_or(m, |b| if m.0 < b.0 { m } else { b }));
        }
        let (t, peak) = best.context("no run")?;
        if t > slowest.0 {
            slowest = (t, (*what).to_owned());
        }
        writeln!(out, "  {what:<38} {:>5} / {:>5}  {:6.3} s  {:6.1} MB", a.len(), b.len(), t.as_secs_f64(), peak as f64 / 1e6)?;
    }
    writeln!(out, "  slowest: {} ({:.3} s)", slowest.1, slowest.0.as_secs_f64())?;
    // The surfacing program against itself with one line changed: the diff of 1M blocks.
    let surface = dir.join("surface.ngc");
    let edited = dir.join("surface_edited.ngc");
    let text = std::fs::read_to_string(&surface)?;
    let middle = text.len() / 2;
    let at = middle + text[middle..].find('\n').map_or(0, |i| i + 1);
    let line_end = at + text[at..].find('\n').unwrap_or(0);
    std::fs::write(&edited, format!("{}X50.05 Y1.0 Z-1.2{}", &text[..at], &text[line_end..]))?;
    let (t, peak) = measured(exe, &["diff", "-d", "linuxcnc", &surface.to_string_lossy(), &edited.to_string_lossy()])?;
    writeln!(
        out,
        "  surfacing, one line changed            {:>5.1} MB each  {:6.3} s  {:6.1} MB",
        text.len() as f64 / 1e6,
        t.as_secs_f64(),
        peak as f64 / 1e6
    )?;
    Ok(())
}

/// Peak memory of `canon` and of `translate --to fanuc` on the surfacing program at a quarter,
/// half, once and twice its size: both read the file piece by piece, so the peak is flat in
/// the program's length (what grows is the file, not the process).
fn memory_by_size(dir: &Path, exe: &str, rows: usize, out: &mut impl std::io::Write) -> Result<()> {
    writeln!(out, "peak memory by program size (surfacing)   size        canon               translate --to fanuc")?;
    for (label, r) in [("1/4", rows / 4), ("1/2", rows / 2), ("1", rows), ("2", rows * 2)] {
        let r = r.max(1);
        let path = dir.join(format!("surface_{r}.ngc"));
        std::fs::write(&path, surfacing_program(r)).with_context(|| format!("cannot write {}", path.display()))?;
        let p = path.to_string_lossy().into_owned();
        let target = dir.join(format!("surface_{r}.fanuc")).to_string_lossy().into_owned();
        let (tc, canon) = measured(exe, &["canon", "-d", "linuxcnc", &p])?;
        let (tt, translate) = measured(exe, &["translate", &p, "-d", "linuxcnc", "--to", "fanuc", "-o", &target])?;
        let size = std::fs::metadata(&path)?.len() as f64 / 1e6;
        writeln!(
            out,
            "  {label:<3} ({:>7} blocks)                {size:6.1} MB   {:6.1} MB {:6.3} s    {:6.1} MB {:6.3} s",
            r * 500 + r / 10,
            canon as f64 / 1e6,
            tc.as_secs_f64(),
            translate as f64 / 1e6,
            tt.as_secs_f64()
        )?;
        std::fs::remove_file(&path)?;
        std::fs::remove_file(&target)?;
    }
    Ok(())
}

/// The files of a corpus `check` is measured on: every file below `dir`, in name order.
fn corpus_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut todo = vec![dir.to_path_buf()];
    while let Some(d) = todo.pop() {
        let Ok(entries) = std::fs::read_dir(&d) else { continue };
        for e in entries.flatten() {
            let p = e.path();
            match e.file_type() {
                Ok(t) if t.is_dir() => todo.push(p),
                Ok(t) if t.is_file() => out.push(p),
                _ => {}
            }
        }
    }
    out.sort();
    out
}

/// `ncplan bench --corpus DIR`: `check` on every program of a corpus, one process each
/// (the dialect told from the program, as a user runs it), with its wall time and the peak
/// resident memory it reports; the slowest files, and the largest time and memory.
pub fn run_corpus(dir: &Path, out: &mut impl std::io::Write) -> Result<()> {
    const SHOWN: usize = 15;
    let exe = std::env::current_exe()?;
    let exe = exe.to_string_lossy().into_owned();
    let files = corpus_files(dir);
    anyhow::ensure!(!files.is_empty(), "no files under {}", dir.display());
    let mut rows = Vec::with_capacity(files.len());
    for f in &files {
        let p = f.to_string_lossy();
        let (t, peak) = measured(&exe, &["check", &p])?;
        let size = std::fs::metadata(f).map_or(0, |m| m.len());
        rows.push((t, peak, size, f.strip_prefix(dir).unwrap_or(f).display().to_string()));
    }
    rows.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| a.3.cmp(&b.3)));
    writeln!(out, "check on {} files of {} (one process each); the {SHOWN} slowest:", rows.len(), dir.display())?;
    writeln!(out, "  {:>8}  {:>9}  {:>9}  file", "time", "peak", "size")?;
    for (t, peak, size, name) in rows.iter().take(SHOWN) {
        writeln!(out, "  {:6.3} s  {:6.1} MB  {:6.1} KB  {name}", t.as_secs_f64(), mb(*peak), *size as f64 / 1024.0)?;
    }
    let worst_memory = rows.iter().max_by_key(|r| r.1).map_or(0, |r| r.1);
    let small: Vec<_> = rows.iter().filter(|r| r.2 < 64 * 1024).collect();
    let small_time = small.iter().map(|r| r.0).max().unwrap_or_default();
    let small_memory = small.iter().map(|r| r.1).max().unwrap_or(0);
    writeln!(
        out,
        "largest peak {:.1} MB; files under 64 KB ({}): at most {:.3} s and {:.1} MB (the bound: 1 s, 100 MB)",
        mb(worst_memory),
        small.len(),
        small_time.as_secs_f64(),
        mb(small_memory)
    )?;
    Ok(())
}

/// The peak resident memory of a process, from `/proc/PID/status` (`VmHWM`), in bytes.
pub fn peak_rss(pid: u32) -> Option<u64> {
    let status = std::fs::read_to_string(format!("/proc/{pid}/status")).ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb * 1024)
}

/// CPU time a process used so far (user + system), from `/proc/PID/stat`.
fn cpu_time(pid: u32) -> Option<Duration> {
    let stat = std::fs::read_to_string(format!("/proc/{pid}/stat")).ok()?;
    // Fields after the command name, which is in parentheses and may hold spaces.
    let rest = &stat[stat.rfind(')')? + 2..];
    let f: Vec<&str> = rest.split_whitespace().collect();
    let ticks: u64 = f.get(11)?.parse::<u64>().ok()? + f.get(12)?.parse::<u64>().ok()?;
    // USER_HZ is 100 on Linux.
    Some(Duration::from_millis(ticks * 10))
}

/// Removes `path` if it is there.
fn remove_if_there(path: &Path) -> Result<()> {
    match std::fs::remove_file(path) {
        Err(e) if e.kind() != std::io::ErrorKind::NotFound => Err(e).with_context(|| format!("cannot remove {}", path.display())),
        _ => Ok(()),
    }
}

/// Runs `exe args` with `NCPLAN_REPORT_PEAK` set and returns its wall time and the peak
/// resident memory it reports of itself.
fn measured(exe: &str, args: &[&str]) -> Result<(Duration, u64)> {
    let t = Instant::now();
    let out = Command::new(exe).args(args).env("NCPLAN_REPORT_PEAK", "1").stdout(Stdio::null()).stderr(Stdio::piped()).output()?;
    let elapsed = t.elapsed();
    let err = String::from_utf8_lossy(&out.stderr);
    let peak =
        err.lines().find_map(|l| l.strip_prefix("ncplan: peak resident memory ")).and_then(|v| v.trim_end_matches(" bytes").parse().ok());
    Ok((elapsed, peak.with_context(|| format!("{exe} {} did not report its peak memory: {err}", args.join(" ")))?))
}

/// A watch daemon on temporary folders, for the daemon benchmarks.
struct Bed {
    dir: PathBuf,
    db: crate::store::Location,
    child: std::process::Child,
}

impl Bed {
    fn start(exe: &str, dir: &Path, settle_ms: u64) -> Result<Bed> {
        Bed::start_on(exe, dir, settle_ms, &crate::store::Location::Sqlite(dir.join("var/ncplan.db")), "")
    }

    /// A daemon of `site` writing to `db`.
    fn start_on(exe: &str, dir: &Path, settle_ms: u64, db: &crate::store::Location, site: &str) -> Result<Bed> {
        for sub in ["cam", "share"] {
            std::fs::create_dir_all(dir.join(sub))?;
        }
        let database = match db {
            crate::store::Location::Sqlite(_) => "path = 'var/ncplan.db'".to_owned(),
            crate::store::Location::Postgres(t) => format!("url = '{}'", t.url_for_config()),
        };
        let site = if site.is_empty() { String::new() } else { format!("site = '{site}'\n") };
        std::fs::write(
            dir.join("ncplan.toml"),
            format!(
                "{site}[database]\n{database}\n[daemon]\nsettle_ms = {settle_ms}\nmax_file_mb = 512\n\
                 [[cam]]\npath = 'cam'\ndialect = 'linuxcnc'\n[[machine]]\nname = 'M1'\npath = 'share'\ndialect = 'linuxcnc'\n"
            ),
        )?;
        let log = std::fs::File::create(dir.join("daemon.log"))?;
        let child = Command::new(exe)
            .current_dir(dir)
            .args(["watch", "--config"])
            .arg(dir.join("ncplan.toml"))
            .stdout(Stdio::null())
            .stderr(log)
            .spawn()?;
        let bed = Bed { dir: dir.to_path_buf(), db: db.clone(), child };
        bed.wait_log("Catch-up scan queued", 1, Duration::from_secs(30))?;
        Ok(bed)
    }

    fn log(&self) -> String {
        std::fs::read_to_string(self.dir.join("daemon.log")).unwrap_or_default()
    }

    fn wait_log(&self, needle: &str, n: usize, limit: Duration) -> Result<()> {
        let deadline = Instant::now() + limit;
        while self.log().matches(needle).count() < n {
            anyhow::ensure!(Instant::now() < deadline, "timed out waiting for {n} × '{needle}'");
            std::thread::sleep(Duration::from_millis(10));
        }
        Ok(())
    }

    fn count(&self, sql: &str) -> usize {
        crate::store::Store::open_read_only(&self.db)
            .ok()
            .and_then(|s| s.query(sql).ok())
            .and_then(|(_, r)| r.first()?.first()?.parse().ok())
            .unwrap_or(0)
    }

    fn wait_count(&self, sql: &str, n: usize, limit: Duration) -> Result<Duration> {
        let t = Instant::now();
        while self.count(sql) < n {
            anyhow::ensure!(t.elapsed() < limit, "timed out waiting for {n} rows of {sql}");
            std::thread::sleep(Duration::from_millis(5));
        }
        Ok(t.elapsed())
    }

    fn stop(mut self) -> Result<()> {
        let _ = Command::new("kill").args(["-TERM", &self.child.id().to_string()]).status();
        let _ = self.child.wait();
        Ok(())
    }

    fn kill(mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

impl Drop for Bed {
    /// A benchmark that fails half-way leaves no daemon behind.
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The daemon's figures: the 1M-block ingest (time, memory, stored size) beside `plan`,
/// `diff` and `stepnc` on the same program; idle CPU over stored files; edit latency; a burst;
/// a kill loop. Each runs a real `ncplan watch` on temporary folders.
pub fn run_daemon(dir: &Path, rows: usize, files: usize, kills: usize, out: &mut impl std::io::Write) -> Result<()> {
    let exe = std::env::current_exe()?.to_string_lossy().into_owned();
    let _ = std::fs::remove_dir_all(dir);
    std::fs::create_dir_all(dir)?;
    huge_program(&exe, dir, rows, out)?;
    let bed = burst_and_idle(&exe, dir, files, out)?;
    edit_latency(&bed, out)?;
    bed.stop()?;
    kill_loop(&exe, dir, kills, out)
}

/// Bytes as megabytes.
fn mb(b: u64) -> f64 {
    b as f64 / 1e6
}

/// The first figures, on a huge program: the CAM original, then the operator's edit (one
/// feed); the commands on it, then a daemon storing both (time, memory, changes, stored size).
fn huge_program(exe: &str, dir: &Path, rows: usize, out: &mut impl std::io::Write) -> Result<()> {
    let original = surfacing_program(rows);
    let edited = original.replacen("G1 Z0 F1500", "G1 Z0 F1200", 1);
    let moves = rows * 500 + rows / 10;
    let orig_path = dir.join("surface.ngc");
    let edit_path = dir.join("surface_edited.ngc");
    std::fs::write(&orig_path, &original)?;
    std::fs::write(&edit_path, &edited)?;
    let (o, e) = (orig_path.to_string_lossy().into_owned(), edit_path.to_string_lossy().into_owned());
    writeln!(out, "huge program: {} blocks, {:.1} MB, {moves} moves", rows * 500 + 8, mb(original.len() as u64))?;
    commands_on_huge_program(exe, &o, &e, moves, out)?;
    let bed = Bed::start(exe, &dir.join("huge"), 100)?;
    std::fs::copy(&orig_path, bed.dir.join("cam/surface.ngc"))?;
    bed.wait_count("SELECT COUNT(*) FROM revisions", 1, Duration::from_secs(300))?;
    std::fs::copy(&edit_path, bed.dir.join("share/surface.ngc"))?;
    bed.wait_count("SELECT COUNT(*) FROM comparisons", 1, Duration::from_secs(300))?;
    bed.wait_log("Stored a revision", 2, Duration::from_secs(30))?;
    let peak = peak_rss(bed.child.id()).unwrap_or(0);
    let ms: Vec<u64> = bed
        .log()
        .lines()
        .filter(|l| l.contains("Stored a revision"))
        .filter_map(|l| l.split("ms=").nth(1)?.split_whitespace().next()?.parse().ok())
        .collect();
    let changes = bed.count("SELECT COUNT(*) FROM changes");
    bed.stop()?;
    let bed_dir = dir.join("huge");
    let db = ["ncplan.db", "ncplan.db-wal"]
        .iter()
        .filter_map(|f| std::fs::metadata(bed_dir.join("var").join(f)).ok())
        .map(|m| m.len())
        .sum::<u64>();
    writeln!(
        out,
        "  daemon ingest  original {:.2} s, edited (plan and diff included) {:.2} s; peak {:.1} MB ({:.0} B/move); {changes} changes",
        ms.first().copied().unwrap_or(0) as f64 / 1e3,
        ms.get(1).copied().unwrap_or(0) as f64 / 1e3,
        mb(peak),
        peak as f64 / moves as f64
    )?;
    writeln!(
        out,
        "  stored         {:.1} MB for two revisions of {:.1} MB each: {:.2}x the program's bytes",
        mb(db),
        mb(original.len() as u64),
        db as f64 / (2.0 * original.len() as f64)
    )?;
    Ok(())
}

/// `canon`, `plan`, `diff` and `stepnc` on the huge program `o` (and its edit `e`): time and
/// peak memory, and what a move costs beyond streaming.
fn commands_on_huge_program(exe: &str, o: &str, e: &str, moves: usize, out: &mut impl std::io::Write) -> Result<()> {
    // What a move costs is measured over `canon`, which streams the same program without
    // keeping its moves: the difference is the plan's own memory.
    let (_, streamed) = measured(exe, &["canon", "-d", "linuxcnc", o])?;
    writeln!(out, "  canon          (streams, keeps no moves) peak {:7.1} MB", mb(streamed))?;
    for (what, args) in [
        ("plan", vec!["plan", "-d", "linuxcnc", o]),
        ("diff", vec!["diff", "-d", "linuxcnc", o, e]),
        ("stepnc --cc2", vec!["stepnc", "-d", "linuxcnc", "--cc2", "--timestamp", "2026-01-01T00:00:00", o]),
    ] {
        let (t, peak) = measured(exe, &args)?;
        writeln!(
            out,
            "  {what:<14} {:6.2} s  peak {:7.1} MB  {:5.0} B/move over canon ({:.0} B/move in all)",
            t.as_secs_f64(),
            mb(peak),
            peak.saturating_sub(streamed) as f64 / moves as f64,
            peak as f64 / moves as f64
        )?;
    }
    Ok(())
}

/// The second figures: a burst of `files` files, then idle CPU over them stored in a native
/// share. The daemon is left running for the latency figures.
fn burst_and_idle(exe: &str, dir: &Path, files: usize, out: &mut impl std::io::Write) -> Result<Bed> {
    let bed = Bed::start(exe, &dir.join("idle"), 200)?;
    for i in 0..files {
        std::fs::write(
            bed.dir.join(format!("share/P{i:05}.nc")),
            format!("%\nO{i}\nT1 M6\nS1000 M3\nG0 X{i} Y0 Z5\nG1 Z-1 F100\nX{}\nM30\n%\n", i + 10),
        )?;
    }
    let t = bed.wait_count("SELECT COUNT(*) FROM revisions", files, Duration::from_secs(600))?;
    writeln!(out, "burst: {files} files stored in {:.1} s", t.as_secs_f64())?;
    std::thread::sleep(Duration::from_secs(2));
    let pid = bed.child.id();
    let (c0, t0) = (cpu_time(pid).unwrap_or_default(), Instant::now());
    std::thread::sleep(Duration::from_secs(10));
    let (c1, t1) = (cpu_time(pid).unwrap_or_default(), Instant::now());
    writeln!(
        out,
        "idle: {:.2}% of a core over 10 s with {files} stored files in a native share",
        100.0 * (c1 - c0).as_secs_f64() / (t1 - t0).as_secs_f64()
    )?;
    Ok(bed)
}

/// The third figures: the latency of 20 edits, from the write to the stored revision (settle
/// window 200 ms included), on the daemon `bed`.
fn edit_latency(bed: &Bed, out: &mut impl std::io::Write) -> Result<()> {
    let mut lat = Vec::new();
    for i in 0..20 {
        let before = bed.count("SELECT COUNT(*) FROM revisions");
        let t = Instant::now();
        std::fs::write(
            bed.dir.join("share/P00000.nc"),
            format!("%\nO0\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F{}\nX10\nM30\n%\n", 200 + i),
        )?;
        while bed.count("SELECT COUNT(*) FROM revisions") <= before {
            anyhow::ensure!(t.elapsed() < Duration::from_secs(30), "an edit was never stored");
            std::thread::sleep(Duration::from_millis(2));
        }
        lat.push(t.elapsed());
    }
    lat.sort();
    writeln!(
        out,
        "latency over 20 edits (settle 200 ms): median {:.0} ms, max {:.0} ms",
        lat[lat.len() / 2].as_secs_f64() * 1e3,
        lat[lat.len() - 1].as_secs_f64() * 1e3
    )?;
    Ok(())
}

/// The fourth figures, a kill loop: files written in place in two pieces while the daemon is
/// killed -9 again and again; then what was lost, duplicated, or stored partial.
fn kill_loop(exe: &str, dir: &Path, kills: usize, out: &mut impl std::io::Write) -> Result<()> {
    let kill_dir = dir.join("kills");
    let mut bed = Bed::start(exe, &kill_dir, 100)?;
    let mut versions: std::collections::BTreeMap<String, Vec<String>> = std::collections::BTreeMap::new();
    let mut written = 0usize;
    for k in 0..kills {
        for j in 0..3 {
            let name = format!("K{:03}.nc", (k * 3 + j) % 50);
            let text = format!("%\nO{k}{j}\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F{}\nX{}\nM30\n%\n", 100 + k, 10 + j);
            let (a, b) = text.split_at(text.len() / 2);
            let mut f = std::fs::File::create(kill_dir.join("share").join(&name))?;
            std::io::Write::write_all(&mut f, a.as_bytes())?;
            std::thread::sleep(Duration::from_millis(5));
            std::io::Write::write_all(&mut f, b.as_bytes())?;
            drop(f);
            versions.entry(name).or_default().push(text);
            written += 1;
        }
        std::thread::sleep(Duration::from_millis(150 + (k as u64 * 37) % 200));
        bed.kill();
        bed = Bed {
            dir: kill_dir.clone(),
            db: crate::store::Location::Sqlite(kill_dir.join("var/ncplan.db")),
            child: Command::new(exe)
                .current_dir(&kill_dir)
                .args(["watch", "--config"])
                .arg(kill_dir.join("ncplan.toml"))
                .stdout(Stdio::null())
                .stderr(std::fs::OpenOptions::new().append(true).open(kill_dir.join("daemon.log"))?)
                .spawn()?,
        };
    }
    std::thread::sleep(Duration::from_secs(3));
    let store = crate::store::Store::open_read_only(&crate::store::Location::Sqlite(kill_dir.join("var/ncplan.db")))?;
    let (_, rows) = store.query(
        "SELECT p.path, CAST(b.content AS TEXT), EXISTS (SELECT 1 FROM revision_marks k WHERE k.revision_id = r.id) FROM revisions r
         JOIN programs p ON p.id = r.program_id JOIN blobs b ON b.hash = r.hash ORDER BY r.id",
    )?;
    let (_, dup) =
        store.query("SELECT COUNT(*) FROM (SELECT program_id, hash FROM revisions GROUP BY program_id, hash HAVING COUNT(*) > 1)")?;
    let mut lost = 0;
    for (name, texts) in &versions {
        let last = texts.last().map(String::as_str);
        let latest = rows.iter().rev().find(|r| r[0].ends_with(&format!("/{name}"))).map(|r| r[1].as_str());
        lost += usize::from(latest != last);
    }
    let partial_unmarked = rows.iter().filter(|r| r[2] == "0" && !versions.values().flatten().any(|t| t == &r[1])).count();
    let partial_marked = rows.iter().filter(|r| r[2] == "1").count();
    bed.kill();
    writeln!(
        out,
        "kill loop: {kills} SIGKILLs while {written} versions of 50 files were written in place: {lost} lost, {} duplicated, {partial_unmarked} partial revisions unmarked ({partial_marked} partial writes marked and kept out of the report); {} revisions",
        dup[0][0],
        rows.len()
    )?;
    Ok(())
}

/// The report queries on a simulated plant of `revisions` revisions in the PostgreSQL
/// database `url` (made once; the best of three runs of each query).
pub fn run_simulation(url: &str, revisions: i64, out: &mut impl std::io::Write) -> Result<()> {
    let db = crate::store::Location::parse(url);
    let store = crate::store::Store::open(&db, "BENCH")?;
    let t = Instant::now();
    let n = store.simulate_plant(revisions)?;
    writeln!(out, "simulated plant: {n} revisions, 2 changes each, on 100 sites ({:.1} s to make or find)", t.elapsed().as_secs_f64())?;
    for (name, sql) in crate::store::PLANT_QUERIES {
        let mut best = Duration::MAX;
        let mut rows = 0;
        for _ in 0..3 {
            let t = Instant::now();
            rows = store.query(sql)?.1.len();
            best = best.min(t.elapsed());
        }
        writeln!(out, "{name}: {rows} rows in {:.1} ms", best.as_secs_f64() * 1e3)?;
    }
    Ok(())
}

/// Ingest throughput on SQLite and on the PostgreSQL database `url`: `files` small programs
/// written into a share at once, timed until the daemon has stored them all. On PostgreSQL
/// the daemon is a site of its own (`BENCH` and the time), so earlier runs do not count.
pub fn run_engines(dir: &Path, url: &str, files: usize, out: &mut impl std::io::Write) -> Result<()> {
    let exe = std::env::current_exe()?.to_string_lossy().into_owned();
    let _ = std::fs::remove_dir_all(dir);
    let stamp = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_millis());
    let site = format!("BENCH{stamp}");
    let mut rates = Vec::new();
    for (name, db) in
        [("SQLite", crate::store::Location::Sqlite(dir.join("sqlite/var/ncplan.db"))), ("PostgreSQL", crate::store::Location::parse(url))]
    {
        let bed_dir = dir.join(name.to_ascii_lowercase());
        let bed = Bed::start_on(&exe, &bed_dir, 100, &db, &site)?;
        let t = Instant::now();
        for i in 0..files {
            let text = format!("G21 G90\nT1 M6\nS2000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F{}\nX100\nY{i}\nG0 Z50\nM30\n", 200 + i);
            std::fs::write(bed_dir.join(format!("share/p{i}.ngc")), text)?;
        }
        let counted = format!("SELECT COUNT(*) FROM revisions r JOIN programs p ON p.id = r.program_id WHERE p.site = '{site}'");
        // One reading connection, looking every 20 ms (a connection per look would load the server).
        let reader = crate::store::Store::open_read_only(&db)?;
        let stored = || -> usize { reader.query(&counted).ok().and_then(|(_, r)| r.first()?.first()?.parse().ok()).unwrap_or(0) };
        while stored() < files {
            anyhow::ensure!(t.elapsed() < Duration::from_secs(600), "timed out waiting for {files} revisions on {name}");
            std::thread::sleep(Duration::from_millis(20));
        }
        let secs = t.elapsed().as_secs_f64();
        bed.stop()?;
        writeln!(out, "ingest on {name}: {files} revisions in {secs:.2} s ({:.0} revisions/s)", files as f64 / secs)?;
        rates.push(files as f64 / secs);
    }
    writeln!(out, "PostgreSQL ingest takes {:.2}× SQLite's time (the issue asks for at most 2×)", rates[0] / rates[1])?;
    // Re-analysis of what was stored, by 1, 2 and 4 workers (each a version of its own).
    let config = crate::config::Config::parse(&std::fs::read_to_string(dir.join("postgresql/ncplan.toml"))?, &dir.join("postgresql"))?;
    let registry = crate::dialect::Registry::shipped();
    let db = crate::store::Location::parse(url);
    for workers in [1, 2, 4] {
        let stores = (0..workers).map(|_| crate::store::Store::open(&db, &site)).collect::<std::result::Result<Vec<_>, _>>()?;
        let version = format!("bench-{stamp}-{workers}");
        let queued = stores[0].queue_reanalysis(&version, None, None)?;
        let t = Instant::now();
        let summary = crate::reanalyze::work(&config, &registry, stores, &version, "bench", Duration::from_secs(300), &|_, _| {})?;
        let secs = t.elapsed().as_secs_f64();
        writeln!(
            out,
            "re-analysis on PostgreSQL, {workers} worker(s): {} of {queued} queued revisions in {secs:.2} s ({:.0} revisions/s)",
            summary.reread,
            summary.reread as f64 / secs
        )?;
    }
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
        assert!(siemens_macro_program(3).contains("WHILE R1<3\n"));
        let h = heidenhain_macro_program(3);
        assert!(h.starts_with("0 BEGIN PGM MACRO MM\n") && h.ends_with("19 END PGM MACRO MM\n"), "{h}");
        assert!(h.contains("16 FN 12: IF +Q1 LT +3 GOTO LBL 1\n"), "{h}");
    }
}

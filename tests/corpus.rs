//! Data-driven corpus tests (libtest-mimic, one trial per file):
//!
//! - `check/<dialect>/<file>`: every program of `../shared/corpus` goes through analysis
//!   without panicking, and its diagnostics point inside the text; its plan, written as
//!   STEP-NC CC1 and CC2, conforms to the ISO 14649 signatures and reads back unchanged;
//!   the interpreter's fast paths (the lane for plain moves, the cache of lexed loop
//!   bodies) change nothing in its calls or findings, and neither does reading its text
//!   piece by piece through a window of a few bytes.
//! - `canon/<file>`: `ncplan canon` agrees with LinuxCNC's `rs274 -g` (goldens in
//!   `tests/golden/rs274`, made by `tests/golden/regen.sh`) to 1e-4, ignoring calls that
//!   are LinuxCNC-internal. Programs listed in `tests/golden/rs274/KNOWN_DIFFERENCES` are
//!   expected to differ (each with its first difference and the diagnostic that explains
//!   it); any other difference fails, and so does a listed program that starts to match.
//!   A program that differs must say why: ncplan must report at least one warning or
//!   error on it. `UPDATE_EXPECT=1` rewrites the list.

#![allow(clippy::print_stderr)] // says why trials are skipped

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use libtest_mimic::{Arguments, Failed, Trial};
use ncplan::canon::{LINUXCNC_INTERNAL, write_call};
use ncplan::diag::{Code, Severity};
use ncplan::dialect::Registry;
use ncplan::interp::Profile;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The dialect used for a corpus folder in the checks; `None`: told from each program.
fn folder_dialect(folder: &str) -> Option<&'static str> {
    match folder {
        "haas" => Some("haas"),
        "mazak" => Some("mazak"),
        // Fanuc and Okuma folders hold machining-centre and lathe programs: told from each program.
        "siemens" => Some("siemens"),
        // Klartext and DIN/ISO programs: told from each program (the family stays heidenhain).
        "linuxcnc" => Some("linuxcnc"),
        "centroid" => Some("centroid"),
        _ => None,
    }
}

/// The controller family a corpus folder's name says its programs are for (a dialect's
/// `family`); `None` for folders of mixed or unknown origin.
fn folder_family(folder: &str) -> Option<&str> {
    match folder {
        "generic_iso" | "other" | "cldata" => None,
        "linuxcnc" => Some("rs274ngc"),
        f => Some(f),
    }
}

/// `tests/golden/corpus/sniff.tsv`: the dialect told from each program of a folder that names
/// a family, with how sure, and whether its family is the folder's; with the per-folder share
/// of right families. Rewritten with `UPDATE_EXPECT=1`, compared otherwise.
fn sniff_table(registry: &Registry, programs: &[(String, PathBuf)]) -> (String, String) {
    let mut rows = String::from("# folder\tfile\tsniffed dialect\tsure\tright family\n");
    let mut per: BTreeMap<&str, (usize, usize, usize)> = BTreeMap::new();
    for (folder, path) in programs {
        let Some(family) = folder_family(folder) else { continue };
        let bytes = std::fs::read(path).unwrap_or_default();
        let s = ncplan::pipeline::sniff(registry, &bytes, path);
        let right = registry.get(&s.dialect).is_some_and(|d| d.family == family);
        let file = path.file_name().unwrap().to_string_lossy();
        let sure = s.confidence.as_str();
        rows.push_str(&format!("{folder}\t{file}\t{}\t{sure}\t{}\n", s.dialect, if right { "yes" } else { "no" }));
        let e = per.entry(folder.as_str()).or_default();
        e.0 += 1;
        e.1 += usize::from(right);
        e.2 += usize::from(!right && s.confidence != ncplan::dialect::sniff::Confidence::Low);
    }
    let mut md = String::from(
        "\nThe dialect told from each program's text and name (`ncplan check` without `-d`), for folders that name a \
         controller family: how many are of that family, and how many of the others were not said with `sure: low`.\n\n\
         | folder | programs | right family | share | wrong and not said low |\n|---|---:|---:|---:|---:|\n",
    );
    let (mut n, mut ok, mut loud) = (0, 0, 0);
    for (folder, (k, r, l)) in &per {
        md.push_str(&format!("| {folder} | {k} | {r} | {:.1}% | {l} |\n", 100.0 * *r as f64 / *k as f64));
        (n, ok, loud) = (n + k, ok + r, loud + l);
    }
    md.push_str(&format!("| **all** | {n} | {ok} | {:.1}% | {loud} |\n", 100.0 * ok as f64 / n.max(1) as f64));
    (rows, md)
}

/// The dialect a corpus program is checked in: its folder's, or the one told from its text,
/// and whether it was a guess (told from weak evidence: `check` then keeps findings that hold
/// for its maker alone as warnings).
fn dialect_for(registry: &Registry, folder: &str, path: &Path) -> (std::sync::Arc<ncplan::dialect::Dialect>, bool) {
    let (name, guessed) = match folder_dialect(folder) {
        Some(n) => (n.to_owned(), false),
        None => {
            let bytes = std::fs::read(path).unwrap_or_default();
            let s = ncplan::pipeline::sniff(registry, &bytes, path);
            let guessed = s.guessed();
            (s.dialect, guessed)
        }
    };
    (registry.get(&name).unwrap(), guessed)
}

/// `tests/golden/corpus/errors.tsv`: per program, the dialect and the number of error
/// findings. A program with more or fewer errors than recorded fails its check (a
/// regression, or an improvement to record with `UPDATE_EXPECT=1`).
fn error_golden(dir: &Path) -> BTreeMap<String, (String, usize)> {
    let text = std::fs::read_to_string(dir.join("errors.tsv")).unwrap_or_default();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
        .filter_map(|l| {
            let mut f = l.split('\t');
            let (folder, file, dialect, errors) = (f.next()?, f.next()?, f.next()?, f.next()?.parse().ok()?);
            Some((format!("{folder}/{file}"), (dialect.to_owned(), errors)))
        })
        .collect()
}

/// The corpus flattens LinuxCNC's test folders into file names: `a/b/test.ngc` is
/// `a_b_test.ngc` and `a/b/subs/x.ngc` is `a_b_subs_x.ngc`. A program's subroutines are its
/// siblings there, found as the shell's program directory would find them in the folder.
struct FlatCorpus {
    dir: PathBuf,
    /// The file-name prefix of the program's own folder (`a_b_`).
    prefix: String,
    /// The folder's files that start with the prefix.
    files: Vec<String>,
}

impl FlatCorpus {
    fn profile(path: &Path) -> Profile {
        let name = path.file_name().unwrap_or_default().to_string_lossy();
        let prefix = name.rfind('_').map_or(String::new(), |i| name[..=i].to_owned());
        let dir = path.parent().unwrap_or(Path::new(".")).to_owned();
        let files = std::fs::read_dir(&dir)
            .map(|d| {
                d.filter_map(|e| e.ok()?.file_name().into_string().ok()).filter(|f| !prefix.is_empty() && f.starts_with(&prefix)).collect()
            })
            .unwrap_or_default();
        Profile { programs: Some(std::sync::Arc::new(FlatCorpus { dir, prefix, files })), ..Profile::default() }
    }
}

impl ncplan::interp::ProgramSource for FlatCorpus {
    fn load(&self, name: &str) -> Option<String> {
        if self.prefix.is_empty() || name.is_empty() {
            return None;
        }
        let stems = ncplan::config::program_file_stems(name);
        let wanted = ["", "subs_"].into_iter().flat_map(|sub| {
            stems.iter().flat_map(move |stem| ncplan::config::PROGRAM_EXTENSIONS.map(|ext| format!("{}{sub}{stem}{ext}", self.prefix)))
        });
        let file = wanted.into_iter().find_map(|w| self.files.iter().find(|f| f.eq_ignore_ascii_case(&w)))?;
        Some(ncplan::text::decode(&std::fs::read(self.dir.join(file)).ok()?).0.text)
    }
}

fn errors_of(path: &Path, dialect: &ncplan::dialect::Dialect, guessed: bool) -> (usize, String) {
    let bytes = std::fs::read(path).unwrap_or_default();
    let a = ncplan::pipeline::analyze(&bytes, dialect, &Profile { guessed, ..FlatCorpus::profile(path) });
    let errors: Vec<_> = a.diagnostics.iter().filter(|d| d.is_error()).collect();
    (errors.len(), errors.first().map_or(String::new(), |d| d.code.as_str().to_owned()))
}

/// How a program of the corpus fares under `check`.
#[derive(Default)]
struct Tally {
    programs: usize,
    /// No error diagnostics.
    clean: usize,
    /// Errors that LinuxCNC's rs274 reports too (its golden ends in an error).
    oracle: usize,
    /// Not a part program: binary data or a foreign format (Mazatrol, a template).
    not_program: usize,
    /// Errors that `reasons.tsv` says are genuine (or another issue's), with why.
    explained: usize,
    dialects: BTreeMap<String, usize>,
}

impl Tally {
    /// The table row of `folder`, read in `dialects`.
    fn row(&self, folder: &str, dialects: &str) -> String {
        let pct = |k: usize| 100.0 * k as f64 / self.programs.max(1) as f64;
        let ok = self.clean + self.oracle + self.not_program + self.explained;
        let (n, clean, oracle, other, why) = (self.programs, self.clean, self.oracle, self.not_program, self.explained);
        format!("| {folder} | {dialects} | {n} | {clean} | {:.1}% | {oracle} | {other} | {why} | {ok} | {:.1}% |\n", pct(clean), pct(ok))
    }
}

/// Whether rs274 stopped with an error on the LinuxCNC program `path`, per its golden.
fn rs274_rejects(path: &Path) -> bool {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    let golden = root().join("tests/golden/rs274").join(format!("{stem}.canon"));
    std::fs::read_to_string(golden).is_ok_and(|t| t.lines().any(|l| l.starts_with("# rs274 error")))
}

/// `tests/golden/corpus/reasons.tsv`, kept by hand: per program whose errors are genuine
/// (or not ncplan's to fix), why: `folder<TAB>file<TAB>reason`. The reason is copied into
/// `errors.tsv` while the program has errors.
fn reasons(dir: &Path) -> BTreeMap<String, String> {
    let text = std::fs::read_to_string(dir.join("reasons.tsv")).unwrap_or_default();
    text.lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .filter_map(|l| {
            let mut f = l.splitn(3, '\t');
            Some((format!("{}/{}", f.next()?, f.next()?), f.next()?.trim().to_owned()))
        })
        .collect()
}

/// Rewrites `errors.tsv` and the per-folder table `summary.md`.
fn update_error_golden(dir: &Path, registry: &Registry, programs: &[(String, PathBuf)]) {
    let why = reasons(dir);
    let mut rows = String::from("# folder\tfile\tdialect\terrors\tfirst error code\treason the errors are genuine (reasons.tsv)\n");
    let mut by_folder: BTreeMap<String, Tally> = BTreeMap::new();
    for (folder, path) in programs {
        let (d, guessed) = dialect_for(registry, folder, path);
        let (n, first) = errors_of(path, &d, guessed);
        let file = path.file_name().unwrap().to_string_lossy();
        let reason = if n > 0 {
            why.get(&format!("{folder}/{file}"))
                .or_else(|| {
                    why.iter().find(|(k, _)| k.strip_suffix('*').is_some_and(|p| format!("{folder}/{file}").starts_with(p))).map(|(_, v)| v)
                })
                .map_or("", String::as_str)
        } else {
            ""
        };
        rows.push_str(&format!("{folder}\t{file}\t{}\t{n}\t{first}\t{reason}\n", d.name));
        let t = by_folder.entry(folder.clone()).or_default();
        t.programs += 1;
        if n == 0 {
            t.clean += 1;
        } else if first == "text::binary" || first == "text::foreign-format" {
            t.not_program += 1;
        } else if folder == "linuxcnc" && rs274_rejects(path) {
            t.oracle += 1;
        } else if !reason.is_empty() {
            t.explained += 1;
        }
        *t.dialects.entry(d.name.clone()).or_default() += 1;
    }
    let mut md = String::from(
        "Errors are confirmed when rs274 stops on the program too, or when the file is not a part program \
         (binary data, a Mazatrol export, a template); explained when `reasons.tsv` says why they are genuine.\n\n\
         | folder | dialect | programs | without errors | share | errors rs274 confirms | not a program | explained | without unexplained errors | share |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let mut all = Tally::default();
    for (folder, t) in &by_folder {
        let ds: Vec<String> =
            t.dialects.iter().map(|(d, k)| if t.dialects.len() == 1 { d.clone() } else { format!("{d} ({k})") }).collect();
        md.push_str(&t.row(folder, &ds.join(", ")));
        all.programs += t.programs;
        all.clean += t.clean;
        all.oracle += t.oracle;
        all.not_program += t.not_program;
        all.explained += t.explained;
    }
    md.push_str(&all.row("**all**", ""));
    let (sniffed, sniff_md) = sniff_table(registry, programs);
    md.push_str(&sniff_md);
    std::fs::create_dir_all(dir).unwrap();
    std::fs::write(dir.join("sniff.tsv"), sniffed).unwrap();
    std::fs::write(dir.join("errors.tsv"), rows).unwrap();
    std::fs::write(dir.join("summary.md"), md).unwrap();
}

fn main() {
    let args = Arguments::from_args();
    let mut trials = Vec::new();
    let corpus = std::env::var_os("NCPLAN_SHARED").map_or_else(|| root().join("../shared"), PathBuf::from).join("corpus");
    if !corpus.is_dir() {
        assert!(std::env::var_os("NCPLAN_REQUIRE_SHARED").is_none(), "NCPLAN_REQUIRE_SHARED is set but {} is absent", corpus.display());
        eprintln!(
            "corpus: {} is absent: its program checks and its rs274 comparisons are skipped (ncplan's own programs still run); \
             clone the shared material beside the checkout to run them",
            corpus.display()
        );
    }
    let registry = Registry::shipped();
    let mut programs: Vec<(String, PathBuf)> = Vec::new();
    if let Ok(dirs) = std::fs::read_dir(&corpus) {
        let mut dirs: Vec<PathBuf> = dirs.filter_map(|e| e.ok().map(|e| e.path())).filter(|p| p.is_dir()).collect();
        dirs.sort();
        for dir in dirs {
            let folder = dir.file_name().unwrap().to_string_lossy().into_owned();
            let mut files: Vec<PathBuf> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok().map(|e| e.path())).collect();
            files.sort();
            programs.extend(files.into_iter().map(|f| (folder.clone(), f)));
        }
    }
    let error_dir = root().join("tests/golden/corpus");
    if std::env::var_os("UPDATE_EXPECT").is_some() && !programs.is_empty() {
        update_error_golden(&error_dir, &registry, &programs);
    }
    let expected_errors = error_golden(&error_dir);
    {
        let (registry, programs, dir) = (registry.clone(), programs.clone(), error_dir.clone());
        let available = !programs.is_empty();
        let trial = Trial::test("sniff/corpus", move || {
            let (now, _) = sniff_table(&registry, &programs);
            let recorded = std::fs::read_to_string(dir.join("sniff.tsv")).unwrap_or_default();
            match now.lines().zip(recorded.lines()).find(|(a, b)| a != b) {
                Some((a, b)) => Err(format!("sniffed `{a}`, recorded `{b}`; run with UPDATE_EXPECT=1 if intended").into()),
                None if now.lines().count() != recorded.lines().count() => Err("tests/golden/corpus/sniff.tsv is out of date".into()),
                None => Ok(()),
            }
        });
        // Without the corpus there is nothing to sniff (said once above).
        trials.push(trial.with_ignored_flag(!available));
    }
    for (folder, f) in programs {
        let (dialect, guessed) = dialect_for(&registry, &folder, &f);
        let key = format!("{folder}/{}", f.file_name().unwrap().to_string_lossy());
        let expected = expected_errors.get(&key).cloned();
        trials.push(Trial::test(format!("check/{key}"), move || check(&f, &dialect, guessed, expected)));
    }
    // What the control rejects stays rejected (issue 43): every program of
    // tests/sweeps/issue43/rejected.tsv still has an error.
    let rejected = std::fs::read_to_string(root().join("tests/sweeps/issue43/rejected.tsv")).unwrap_or_default();
    for line in rejected.lines().filter(|l| !l.starts_with('#')).skip(1) {
        let mut cols = line.split('\t');
        let (Some(program), Some(dialect)) = (cols.next(), cols.next()) else { continue };
        let path = corpus.join(program);
        let available = path.is_file();
        let dialect = registry.get(dialect);
        let trial = Trial::test(format!("rejected/{program}"), move || {
            let Some(dialect) = dialect else { return Err("no such dialect".into()) };
            match errors_of(&path, &dialect, false) {
                (0, _) => Err(format!("{} reads without an error, but its control rejects it", path.display()).into()),
                _ => Ok(()),
            }
        });
        trials.push(if available { trial } else { trial.with_ignored_flag(true) });
    }
    let goldens = root().join("tests/golden/rs274");
    let mut files: Vec<PathBuf> = std::fs::read_dir(&goldens)
        .unwrap()
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "canon"))
        .collect();
    files.sort();
    if std::env::var_os("UPDATE_EXPECT").is_some() {
        update_known_differences(&goldens, &corpus, &files);
    }
    let known = known_differences(&goldens);
    for golden in files {
        let stem = golden.file_stem().unwrap().to_string_lossy().into_owned();
        let program = program_for(&corpus, &stem);
        let available = program.exists();
        let expected_diff = known.get(&stem).cloned();
        let trial = Trial::test(format!("canon/{stem}"), move || compare(&golden, &program, expected_diff.as_deref()));
        trials.push(if available { trial } else { trial.with_ignored_flag(true) });
    }
    libtest_mimic::run(&args, trials).exit();
}

/// The program a golden belongs to: `own__<name>` goldens are ncplan's own test programs.
fn program_for(corpus: &Path, stem: &str) -> PathBuf {
    match stem.strip_prefix("own__") {
        Some(name) => root().join("tests/programs/linuxcnc").join(format!("{name}.ngc")),
        None => corpus.join("linuxcnc").join(format!("{stem}.ngc")),
    }
}

fn check(path: &Path, dialect: &ncplan::dialect::Dialect, guessed: bool, expected: Option<(String, usize)>) -> Result<(), Failed> {
    let bytes = std::fs::read(path)?;
    let a = ncplan::pipeline::analyze(&bytes, dialect, &Profile { guessed, ..FlatCorpus::profile(path) });
    let errors: Vec<_> = a.diagnostics.iter().filter(|d| d.is_error()).collect();
    match &expected {
        None => return Err("not in tests/golden/corpus/errors.tsv; run with UPDATE_EXPECT=1".into()),
        Some((d, _)) if *d != dialect.name => {
            return Err(format!("read as {}, recorded as {d}; run with UPDATE_EXPECT=1 if intended", dialect.name).into());
        }
        Some((_, n)) if errors.len() > *n => {
            let first: Vec<String> = errors.iter().take(3).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect();
            return Err(format!("{} errors, {n} recorded (a regression):\n{}", errors.len(), first.join("\n")).into());
        }
        Some((_, n)) if errors.len() < *n => {
            return Err(format!("{} errors, {n} recorded: an improvement; record it with UPDATE_EXPECT=1", errors.len()).into());
        }
        _ => {}
    }
    fast_lane_changes_nothing(&a.source.text, dialect, path)?;
    piecewise_reading_changes_nothing(&bytes, &a.source.text, dialect, path)?;
    let len = a.source.text.len() as u32;
    for d in &a.diagnostics {
        if d.range.end > len || !a.source.text.is_char_boundary(d.range.start as usize) {
            return Err(format!("diagnostic outside the text: {d:?}").into());
        }
    }
    use ncplan::part21::stepnc::{self, Class};
    for class in [Class::Cc1, Class::Cc2] {
        let (text, _) = stepnc::to_string(&a.plan, class, "2026-01-01T00:00:00");
        let x = ncplan::part21::parse(&text)?;
        let findings = ncplan::part21::schema::iso14649().check(&x);
        if !findings.is_empty() {
            return Err(format!("{class:?} does not conform:\n{}", findings.join("\n")).into());
        }
        let back = stepnc::read(&x)?;
        let expected = if class == Class::Cc1 { stepnc::toolpaths_only(&a.plan) } else { a.plan.clone() };
        if back != expected {
            let (a, b) = (serde_json::to_string_pretty(&expected)?, serde_json::to_string_pretty(&back)?);
            // The first line that differs in value: -0.0 and 0.0 are equal numbers.
            let at = a.lines().zip(b.lines()).position(|(x, y)| x.replace("-0.0", "0.0") != y.replace("-0.0", "0.0")).unwrap_or(0);
            let context = |t: &str| t.lines().skip(at.saturating_sub(6)).take(8).collect::<Vec<_>>().join("\n");
            return Err(format!("{class:?} does not read back to the same plan:\n{}\n---- read back:\n{}", context(&a), context(&b)).into());
        }
    }
    Ok(())
}

/// The interpreter's fast paths (`Profile::fast_lane`) give what the general path gives: the same
/// canonical calls with the same source ranges, and the same findings.
fn fast_lane_changes_nothing(text: &str, dialect: &ncplan::dialect::Dialect, path: &Path) -> Result<(), Failed> {
    let run = |fast_lane: bool| {
        let profile = Profile { fast_lane, ..FlatCorpus::profile(path) };
        let mut canon = Vec::new();
        let diags = ncplan::interp::interpret(text, dialect, &profile, &mut canon);
        // Compared as text: a NaN that a broken program computes is the same both ways.
        (canon.iter().map(|c| format!("{c:?}")).collect::<Vec<_>>(), diags.iter().map(|d| format!("{d:?}")).collect::<Vec<_>>())
    };
    let ((fast, fast_diags), (general, general_diags)) = (run(true), run(false));
    if let Some(i) = (0..fast.len().max(general.len())).find(|&i| fast.get(i) != general.get(i)) {
        return Err(format!("fast lane: call {i} is {:?}, the general path gives {:?}", fast.get(i), general.get(i)).into());
    }
    if fast_diags != general_diags {
        let i = fast_diags.iter().zip(&general_diags).position(|(a, b)| a != b).unwrap_or(fast_diags.len().min(general_diags.len()));
        return Err(format!("fast lane: finding {i} is {:?}, the general path gives {:?}", fast_diags.get(i), general_diags.get(i)).into());
    }
    Ok(())
}

/// Reading the text piece by piece ([`ncplan::text::Text::Read`], as `canon` and `translate`
/// read files) gives what the whole text gives: the same calls with their source ranges, and
/// the same findings. A window of 13 bytes is refilled at almost every block and grown for
/// most, and every jump back reads the text again.
fn piecewise_reading_changes_nothing(bytes: &[u8], text: &str, dialect: &ncplan::dialect::Dialect, path: &Path) -> Result<(), Failed> {
    use ncplan::text::{BytesReader, Text};
    let (reader, _) = BytesReader::new(bytes.to_vec(), 4096, 13);
    let run = |text: Text<'_>| {
        let mut canon = Vec::new();
        let diags = ncplan::interp::interpret(text, dialect, &FlatCorpus::profile(path), &mut canon);
        (canon.iter().map(|c| format!("{c:?}")).collect::<Vec<_>>(), diags.iter().map(|d| format!("{d:?}")).collect::<Vec<_>>())
    };
    let ((whole, whole_diags), (read, read_diags)) = (run(Text::Whole(text)), run(Text::Read(&reader)));
    if let Some(i) = (0..whole.len().max(read.len())).find(|&i| whole.get(i) != read.get(i)) {
        return Err(format!("read piece by piece: call {i} is {:?}, the whole text gives {:?}", read.get(i), whole.get(i)).into());
    }
    if let Some(i) = (0..whole_diags.len().max(read_diags.len())).find(|&i| whole_diags.get(i) != read_diags.get(i)) {
        return Err(
            format!("read piece by piece: finding {i} is {:?}, the whole text gives {:?}", read_diags.get(i), whole_diags.get(i)).into()
        );
    }
    Ok(())
}

fn known_differences(dir: &Path) -> BTreeMap<String, String> {
    let text = std::fs::read_to_string(dir.join("KNOWN_DIFFERENCES")).unwrap_or_default();
    text.lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| {
            let (name, why) = l.split_once('\t').unwrap_or((l, ""));
            (name.trim().to_owned(), why.trim().to_owned())
        })
        .collect()
}

fn meaningful(line: &str) -> bool {
    let name = line.split('(').next().unwrap_or("");
    !line.starts_with('#') && !line.is_empty() && !LINUXCNC_INTERNAL.contains(&name)
}

/// Splits a call into its name and argument tokens.
fn tokens(line: &str) -> Vec<&str> {
    line.split(|c: char| c == '(' || c == ')' || c == ',' || c.is_whitespace()).filter(|t| !t.is_empty()).collect()
}

fn same_call(a: &str, b: &str) -> bool {
    let (ta, tb) = (tokens(a), tokens(b));
    ta.len() == tb.len()
        && ta.iter().zip(&tb).all(|(x, y)| match (x.parse::<f64>(), y.parse::<f64>()) {
            (Ok(p), Ok(q)) => (p - q).abs() <= 1e-4,
            _ => x == y,
        })
}

/// First difference between ncplan's and rs274's meaningful calls, if any.
/// The first way ncplan's run differs from rs274's: a call, or whether the program stops
/// with an error (rs274's error against ncplan's first error diagnostic, if any).
fn difference(ours: &Ours, golden: &str) -> Option<String> {
    if let Some(d) = first_difference(&ours.canon, golden) {
        return Some(d);
    }
    let theirs = golden.lines().find_map(|l| l.strip_prefix("# rs274 error: "));
    match (theirs, &ours.error) {
        (Some(t), None) => Some(format!("rs274 stops with `{}`, ncplan reports no error", t.trim())),
        (None, Some(e)) => Some(format!("ncplan reports an error ({e}), rs274 runs to the end")),
        _ => None,
    }
}

fn first_difference(ours: &str, golden: &str) -> Option<String> {
    // rs274 starts with its own initialisation, up to the first ON_RESET.
    let start = golden.lines().position(|l| l.starts_with("ON_RESET")).map_or(0, |i| i + 1);
    let errored = golden.lines().any(|l| l.starts_with("# rs274 error"));
    let theirs: Vec<&str> = golden.lines().skip(start).filter(|l| meaningful(l)).collect();
    let mine: Vec<&str> = ours.lines().filter(|l| meaningful(l)).collect();
    for (i, t) in theirs.iter().enumerate() {
        match mine.get(i) {
            Some(m) if same_call(m, t) => {}
            Some(m) => return Some(format!("call {}: ncplan `{m}`, rs274 `{t}`", i + 1)),
            None => return Some(format!("call {}: ncplan ends, rs274 `{t}`", i + 1)),
        }
    }
    if !errored && mine.len() > theirs.len() {
        return Some(format!("call {}: ncplan `{}`, rs274 ends", theirs.len() + 1, mine[theirs.len()]));
    }
    None
}

/// ncplan's run of a corpus program.
struct Ours {
    canon: String,
    /// The code of the first error diagnostic.
    error: Option<&'static str>,
    /// The diagnostics that can explain a difference.
    explaining: Vec<String>,
}

/// ncplan's canon for a corpus program, and its diagnostics that can explain a difference.
fn run_ours(program: &Path) -> Result<Ours, Failed> {
    let registry = Registry::shipped();
    let dialect = registry.get("linuxcnc").unwrap();
    let bytes = std::fs::read(program)?;
    let (source, _) = ncplan::text::decode(&bytes);
    let mut canon = Vec::new();
    let diags = ncplan::interp::interpret(&source.text, &dialect, &FlatCorpus::profile(program), &mut canon);
    let mut ours = String::new();
    for c in &canon {
        write_call(&mut ours, &c.op);
    }
    let explaining = diags
        .iter()
        .filter(|d| (d.severity != Severity::Note || d.code == Code::Library) && d.code != Code::CuttingWithoutTechnology)
        .map(|d| format!("{}: {}", d.code.as_str(), d.message))
        .collect();
    let error = diags.iter().find(|d| d.is_error()).map(|d| d.code.as_str());
    Ok(Ours { canon: ours, error, explaining })
}

fn compare(golden: &Path, program: &Path, expected_diff: Option<&str>) -> Result<(), Failed> {
    let ours = run_ours(program)?;
    let golden = std::fs::read_to_string(golden)?;
    match (difference(&ours, &golden), expected_diff) {
        (None, None) => Ok(()),
        // A disagreement on whether the program is in error is explained by the entry itself.
        (Some(d), _) if ours.explaining.is_empty() && !d.starts_with("rs274 stops") => {
            Err(format!("differs from rs274 without a diagnostic saying why, at {d}").into())
        }
        (Some(_), Some(_)) => Ok(()),
        (Some(d), None) => Err(format!("differs from rs274 at {d}").into()),
        (None, Some(why)) => Err(format!("now matches rs274; remove it from KNOWN_DIFFERENCES ({why})").into()),
    }
}

/// A difference that comes from how the oracle runs, not from a program: the stand-alone
/// `rs274` has a fixed machine of six axes, X Y Z A B C, and no configuration can give it
/// more; LinuxCNC reads U V W on a machine configured with them, as ncplan does.
fn oracle_limit(difference: &str) -> Option<String> {
    ["u", "v", "w"]
        .iter()
        .any(|a| difference.starts_with(&format!("rs274 stops with `Bad character '{a}' used`")))
        .then(|| "rs274 (stand-alone): its fixed machine has the axes X Y Z A B C only; LinuxCNC reads U V W where the machine is configured with them".into())
}

fn update_known_differences(goldens: &Path, corpus: &Path, files: &[PathBuf]) {
    let mut out = String::from(
        "# Programs whose canon differs from rs274 today: name, first difference, and the diagnostic that explains it.\n\
         # Rewritten by `UPDATE_EXPECT=1 cargo test --test corpus`.\n",
    );
    let (mut matching, mut differing) = (0, 0);
    for golden in files {
        let stem = golden.file_stem().unwrap().to_string_lossy().into_owned();
        let program = program_for(corpus, &stem);
        let (Ok(ours), Ok(text)) = (run_ours(&program), std::fs::read_to_string(golden)) else {
            // Keep the entry of a program that is not here to run.
            if let Some(why) = known_differences(goldens).get(&stem) {
                out.push_str(&format!("{stem}\t{why}\n"));
            }
            continue;
        };
        match difference(&ours, &text) {
            None => matching += 1,
            Some(d) => {
                differing += 1;
                let why = oracle_limit(&d)
                    .or_else(|| ours.explaining.first().cloned())
                    .unwrap_or_else(|| "(no diagnostic)".into())
                    .replace(['\t', '\n'], " ");
                out.push_str(&format!("{stem}\t{d}\t{why}\n"));
            }
        }
    }
    out.push_str(&format!("# {matching} of {} programs match.\n", matching + differing));
    std::fs::write(goldens.join("KNOWN_DIFFERENCES"), out).unwrap();
}

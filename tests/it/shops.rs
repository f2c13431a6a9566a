//! Shop programs not in the corpus read without false alarms (issue 34): each program in
//! `tests/programs/shops` is read as `ncplan check FILE` reads it without `-d` (its dialect
//! told from its text and name, its role from its form, called programs looked for beside
//! it), and `expected.tsv` says, by hand, which control family it is for, whether it is a
//! valid program, and how sure the telling may be.

use ncplan::dialect::Registry;
use ncplan::dialect::sniff::Confidence;
use ncplan::interp::{Profile, ProgramRole, role_for};
use std::collections::BTreeMap;
use std::io::Write as _;
use std::path::{Path, PathBuf};

/// One row of `expected.tsv`.
struct Row {
    path: String,
    families: Vec<String>,
    valid: bool,
    not_high: bool,
}

fn rows(dir: &Path) -> Vec<Row> {
    let table = std::fs::read_to_string(dir.join("expected.tsv")).expect("tests/programs/shops/expected.tsv");
    table
        .lines()
        .filter(|l| !l.trim().is_empty() && !l.starts_with('#'))
        .map(|l| {
            let f: Vec<&str> = l.split('\t').collect();
            assert!(f.len() >= 4, "expected.tsv: a row needs path, family, valid and sure: {l:?}");
            Row {
                path: f[0].to_owned(),
                families: f[1].split('|').map(str::to_owned).collect(),
                valid: f[2] == "yes",
                not_high: f[3] == "not-high",
            }
        })
        .collect()
}

/// What `ncplan check FILE` finds: the dialect told, its family, how sure, and the errors.
struct Checked {
    dialect: String,
    family: String,
    confidence: Confidence,
    errors: Vec<String>,
}

fn check(registry: &Registry, file: &Path) -> Checked {
    let bytes = std::fs::read(file).unwrap();
    let s = ncplan::pipeline::sniff(registry, &bytes, file);
    let d = registry.get(&s.dialect).unwrap();
    let mut profile = ncplan::config::DirPrograms::beside(&Profile::default(), file, 16 << 20);
    profile.role = role_for(ProgramRole::Auto, file, &d);
    let a = ncplan::pipeline::analyze_plan_owned(bytes, &d, &profile);
    let errors = a.diagnostics.iter().filter(|x| x.is_error()).map(|x| format!("{}: {}", x.code.as_str(), x.message)).collect();
    Checked { dialect: s.dialect.clone(), family: d.family.clone(), confidence: s.confidence, errors }
}

/// Every program listed is read as its family's, and per family at least 95% of the valid
/// programs are free of errors; a program listed as invalid has the errors its control
/// would stop on.
#[test]
fn shop_programs_are_told_right_and_read_without_false_alarms() {
    let dir: PathBuf = crate::root().join("tests/programs/shops");
    let registry = Registry::shipped();
    let rows = rows(&dir);
    let listed: Vec<&str> = rows.iter().map(|r| r.path.as_str()).collect();
    // Every program in the folder has its row.
    for family in std::fs::read_dir(&dir).unwrap().flatten().filter(|e| e.path().is_dir()) {
        for f in std::fs::read_dir(family.path()).unwrap().flatten() {
            let rel = format!("{}/{}", family.file_name().to_string_lossy(), f.file_name().to_string_lossy());
            assert!(listed.contains(&rel.as_str()), "{rel} has no row in expected.tsv");
        }
    }
    let mut problems = Vec::new();
    // Per family: valid programs, and those free of errors.
    let mut tally: BTreeMap<String, (u32, u32)> = BTreeMap::new();
    for row in &rows {
        let c = check(&registry, &dir.join(&row.path));
        if !row.families.contains(&c.family) {
            problems.push(format!("{}: read as {} (family {}), not {}", row.path, c.dialect, c.family, row.families.join(" or ")));
        }
        // A program read as another family's than its first is a guess, and says so.
        if (row.not_high || c.family != row.families[0]) && c.confidence == Confidence::High {
            problems.push(format!("{}: read as {} with high confidence, though nothing of its maker is in it", row.path, c.dialect));
        }
        let t = tally.entry(row.families[0].clone()).or_default();
        if row.valid {
            t.0 += 1;
            if c.errors.is_empty() {
                t.1 += 1;
            } else {
                let _ = writeln!(std::io::stderr(), "{}: {}", row.path, c.errors.join("; "));
            }
        } else if c.errors.is_empty() {
            problems.push(format!("{}: listed as invalid, but no error was found", row.path));
        }
    }
    for (family, (valid, clean)) in &tally {
        let _ = writeln!(std::io::stderr(), "shops: {family}: {clean} of {valid} valid programs free of errors");
        if *clean * 100 < *valid * 95 {
            problems.push(format!("{family}: {clean} of {valid} valid programs free of errors (below 95%)"));
        }
    }
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

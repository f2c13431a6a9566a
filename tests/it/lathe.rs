//! Turning: the programs of `tests/programs/lathe/` (hand-written in the styles of Fanuc,
//! Haas, Mitsubishi, Mazak and Fagor lathes, LinuxCNC in G7 and Siemens with DIAMON; cycles
//! and CAM-style explicit moves), each with a sidecar `NAME.expect` written by hand before
//! the program was run: its dialect, the workingsteps a turner names, in order, and the
//! features, with their sizes. Every listed workingstep and feature must be recovered with
//! its kind and its sizes within 0.05 mm, and no milling feature may appear. The lathe
//! edits are diffed in a turner's terms (`lathe_edits`).

use std::path::{Path, PathBuf};

use ncplan::dialect::Registry;
use ncplan::interp::Profile;
use ncplan::pipeline;
use ncplan::plan::{FeatureKind, ProcessPlan, Turned, Workingstep};

/// Sizes agree within this, mm.
const TOL: f64 = 0.05;

fn dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/programs/lathe")
}

/// One expected workingstep or feature: its words and its sizes by name.
struct Expected {
    words: String,
    sizes: Vec<(String, f64)>,
}

fn parse_line(rest: &str) -> Expected {
    let mut words = Vec::new();
    let mut sizes = Vec::new();
    for w in rest.split_whitespace() {
        match w.split_once('=') {
            Some((k, v)) => sizes.push((k.to_owned(), v.parse().unwrap_or_else(|_| panic!("bad number in `{w}`")))),
            None => words.push(w),
        }
    }
    Expected { words: words.join(" "), sizes }
}

/// The sizes of a workingstep by the sidecar's names.
fn ws_size(ws: &Workingstep, key: &str) -> Option<f64> {
    let t = ws.turning.as_deref()?;
    let i = t.intent.as_ref();
    match key {
        "allowance_x" => i?.allowance_x,
        "allowance_z" => i?.allowance_z,
        "depth_of_cut" => i?.depth_of_cut,
        "thread_height" => i?.thread_depth,
        "pitch" => t.pitch.or(i.and_then(|i| i.pitch)),
        "feed_per_rev" => t.feed_per_rev,
        "cutting_speed" => ws.technology.surface_speed,
        "spindle_speed" => Some(ws.technology.spindle_speed),
        "clamp" => t.spindle_limit,
        "d_min" => t.diameter.map(|d| d[0]),
        "d_max" => t.diameter.map(|d| d[1]),
        _ => panic!("unknown workingstep size `{key}`"),
    }
}

/// The sizes of a feature by the sidecar's names.
fn feature_size(kind: &FeatureKind, z: f64, key: &str) -> Option<f64> {
    if key == "z" {
        return Some(z);
    }
    match kind {
        FeatureKind::Turned(t) => match (t, key) {
            (Turned::RevolvedFlat { outer, .. }, "outer") => Some(*outer),
            (Turned::RevolvedFlat { inner, .. }, "inner") => Some(*inner),
            (Turned::Diameter { diameter, .. }, "diameter") => Some(*diameter),
            (Turned::Diameter { length, .. }, "length") => Some(*length),
            (Turned::RevolvedRound { radius, .. }, "radius") => Some(*radius),
            (Turned::RevolvedRound { diameter, .. }, "diameter") => Some(*diameter),
            (Turned::Groove { diameter, .. }, "diameter") => Some(*diameter),
            (Turned::Groove { width, .. }, "width") => *width,
            (Turned::Thread { diameter, .. }, "diameter") => *diameter,
            (Turned::Thread { root, .. }, "root") => Some(*root),
            (Turned::Thread { pitch, .. }, "pitch") => Some(*pitch),
            (Turned::Thread { length, .. }, "length") => Some(*length),
            _ => None,
        },
        FeatureKind::RoundHole { diameter, .. } if key == "diameter" => *diameter,
        _ => None,
    }
}

fn matches(sizes: &[(String, f64)], get: impl Fn(&str) -> Option<f64>) -> bool {
    sizes.iter().all(|(k, v)| get(k).is_some_and(|g| (g - v).abs() <= TOL))
}

/// Scores one program against its sidecar: the misses, in words.
fn score(name: &str, plan: &ProcessPlan, expect: &str) -> Vec<String> {
    let mut misses = Vec::new();
    let mut next = 0;
    let mut mill_turn = false;
    for line in expect.lines().map(str::trim).filter(|l| !l.is_empty() && !l.starts_with('#')) {
        if line == "mill-turn" {
            mill_turn = true;
        } else if let Some(rest) = line.strip_prefix("ws ") {
            let e = parse_line(rest);
            let found = plan.workingsteps[next.min(plan.workingsteps.len())..]
                .iter()
                .position(|w| w.label() == e.words && matches(&e.sizes, |k| ws_size(w, k)));
            match found {
                Some(k) => next += k + 1,
                None => misses.push(format!("{name}: workingstep `{rest}` not found after workingstep {next}")),
            }
        } else if let Some(rest) = line.strip_prefix("feature ") {
            let e = parse_line(rest);
            let found =
                plan.features.iter().any(|f| f.kind.label() == e.words && matches(&e.sizes, |k| feature_size(&f.kind, f.placement[2], k)));
            if !found {
                misses.push(format!("{name}: feature `{rest}` not found"));
            }
        }
    }
    if !mill_turn {
        for f in plan.features.iter().filter(|f| ncplan::plan::turning::is_milling(&f.kind)) {
            misses.push(format!("{name}: milling feature {} ({}) on a lathe program", f.id, f.kind.label()));
        }
    }
    misses
}

fn plan_of(path: &Path, dialect: &str) -> ProcessPlan {
    let reg = Registry::shipped();
    let d = reg.get(dialect).unwrap_or_else(|| panic!("no dialect {dialect}"));
    let bytes = std::fs::read(path).unwrap();
    pipeline::analyze(&bytes, &d, &Profile::default()).plan
}

#[test]
fn lathe_suite() {
    let mut programs: Vec<PathBuf> =
        std::fs::read_dir(dir()).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e != "expect")).collect();
    programs.sort();
    let (mut listed, mut misses) = (0, Vec::new());
    for p in &programs {
        let expect = std::fs::read_to_string(p.with_extension("expect")).unwrap_or_else(|_| panic!("{} has no sidecar", p.display()));
        let dialect = expect.lines().find_map(|l| l.strip_prefix("dialect ")).expect("a dialect line").trim();
        let plan = plan_of(p, dialect);
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        listed += expect.lines().filter(|l| l.starts_with("ws ") || l.starts_with("feature ")).count();
        misses.extend(score(&name, &plan, &expect));
    }
    assert!(misses.is_empty(), "{} of {listed} listed workingsteps and features missed:\n{}", misses.len(), misses.join("\n"));
    assert!(programs.len() >= 30, "the lathe suite has {} programs", programs.len());
}

//! The CAM-style suite (`tests/programs/cam/`, made by `generate.py` there): programs written
//! the way Fusion 360, Mastercam, NX and TNC posts write them, for Fanuc/Haas, Siemens 840D
//! and Heidenhain, each with a sidecar naming its workingsteps and features. The test
//! scores feature recognition per kind and prints precision and recall.

use std::collections::BTreeMap;

use ncplan::dialect::Registry;
use ncplan::interp::Profile;
use ncplan::pipeline;
use ncplan::plan::{Feature, FeatureKind, ProcessPlan};
use serde_json::Value;

fn suite() -> Vec<(String, String, Value)> {
    let dir = crate::root().join("tests/programs/cam");
    let mut out = Vec::new();
    let mut names: Vec<_> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.path()).collect();
    names.sort();
    for side in names.iter().filter(|p| p.extension().is_some_and(|e| e == "json")) {
        let stem = side.file_stem().unwrap().to_string_lossy().into_owned();
        let program =
            names.iter().find(|p| p.file_stem().is_some_and(|s| s.to_string_lossy() == stem) && p.extension().is_some_and(|e| e != "json"));
        let v: Value = serde_json::from_str(&std::fs::read_to_string(side).unwrap()).unwrap();
        out.push((stem, std::fs::read_to_string(program.expect("a program beside its sidecar")).unwrap(), v));
    }
    out
}

fn analyze(text: &str, dialect: &str) -> ProcessPlan {
    let reg = Registry::shipped();
    let a = pipeline::analyze(text.as_bytes(), &reg.get(dialect).unwrap(), &Profile::default());
    a.plan
}

fn kind_name(k: &FeatureKind) -> String {
    k.label().replace(' ', "_")
}

/// Whether a recognised feature is the expected one: same kind, position within 0.5 mm,
/// dimensions and depth within 0.1 mm.
fn matches(f: &Feature, want: &Value) -> bool {
    let num = |k: &str| want.get(k).and_then(Value::as_f64);
    let near = |a: f64, k: &str, tol: f64| num(k).is_none_or(|b| (a - b).abs() <= tol);
    if kind_name(&f.kind) != want["kind"].as_str().unwrap() || !near(f.depth, "depth", 0.1) {
        return false;
    }
    match &f.kind {
        FeatureKind::RoundHole { diameter, positions, .. } => {
            near(f.placement[0], "x", 0.5)
                && near(f.placement[1], "y", 0.5)
                && num("count").is_none_or(|n| n as usize == positions.len())
                && diameter.is_some_and(|d| near(d, "diameter", 0.1))
        }
        FeatureKind::ClosedPocket { rectangle, corner_radius, .. } => {
            near(f.placement[0], "x", 0.5)
                && near(f.placement[1], "y", 0.5)
                && rectangle.is_some_and(|(w, l)| near(w, "width", 0.1) && near(l, "length", 0.1))
                && near(corner_radius.unwrap_or(0.0), "corner_radius", 0.1)
        }
        FeatureKind::PlanarFace { length, width, .. } => near(*length, "length", 0.1) && near(*width, "width", 0.1),
        _ => true,
    }
}

#[derive(Default)]
struct Score {
    expected: usize,
    found: usize,
    matched: usize,
}

#[test]
#[allow(clippy::print_stdout)] // the table is the test's report (`--nocapture` shows it)
fn cam_suite_precision_and_recall_per_feature_kind() {
    let programs = suite();
    assert!(programs.len() >= 30, "{} programs", programs.len());
    let mut scores: BTreeMap<String, Score> = BTreeMap::new();
    let mut misses = Vec::new();
    let (mut ws_right, mut ws_total) = (0, 0);
    for (name, text, side) in &programs {
        let plan = analyze(text, side["dialect"].as_str().unwrap());
        let wants = side["features"].as_array().unwrap();
        let mut used = vec![false; plan.features.len()];
        for w in wants {
            let s = scores.entry(w["kind"].as_str().unwrap().to_owned()).or_default();
            s.expected += 1;
            match (0..plan.features.len()).find(|&i| !used[i] && matches(&plan.features[i], w)) {
                Some(i) => {
                    used[i] = true;
                    s.matched += 1;
                }
                None => misses.push(format!("{name}: missed {w}")),
            }
        }
        for (f, u) in plan.features.iter().zip(&used) {
            scores.entry(kind_name(&f.kind)).or_default().found += 1;
            if !u {
                misses.push(format!("{name}: extra {} at {:?} depth {} {:?}", kind_name(&f.kind), f.placement, f.depth, f.kind));
            }
        }
        let ops: Vec<String> = plan.workingsteps.iter().map(|w| w.operation.label().replace(' ', "_")).collect();
        let want_ops: Vec<String> = side["workingsteps"].as_array().unwrap().iter().map(|v| v.as_str().unwrap().to_owned()).collect();
        ws_total += 1;
        if ops == want_ops {
            ws_right += 1;
        } else {
            misses.push(format!("{name}: workingsteps {ops:?}, expected {want_ops:?}"));
        }
    }
    println!("{:<26} {:>8} {:>6} {:>8} {:>10} {:>7}", "feature kind", "expected", "found", "matched", "precision", "recall");
    let mut worst: f64 = 1.0;
    for (kind, s) in &scores {
        let p = if s.found > 0 { s.matched as f64 / s.found as f64 } else { 1.0 };
        let r = if s.expected > 0 { s.matched as f64 / s.expected as f64 } else { 1.0 };
        println!("{kind:<26} {:>8} {:>6} {:>8} {p:>10.3} {r:>7.3}", s.expected, s.found, s.matched);
        worst = worst.min(p).min(r);
    }
    println!("programs with every workingstep's operation right: {ws_right} of {ws_total}");
    for m in &misses {
        println!("  {m}");
    }
    assert!(worst >= 0.95, "precision or recall below 0.95 (see the table)");
}

/// The NIST-style case: a faced top in two layers, a hole drilled by explicit moves and
/// reamed, a rectangular pocket roughed and finished with one tool at one feed: five
/// workingsteps on three features.
#[test]
fn nist_style_case_is_five_workingsteps_on_three_features() {
    let text = std::fs::read_to_string(crate::root().join("tests/programs/cam/nist_style_fanuc.nc")).unwrap();
    let plan = analyze(&text, "fanuc");
    let ops: Vec<&str> = plan.workingsteps.iter().map(|w| w.operation.label()).collect();
    assert_eq!(
        ops,
        ["plane finish milling", "multistep drilling", "reaming", "bottom and side rough milling", "side finish milling"],
        "{:#?}",
        plan.features
    );
    let kinds: Vec<String> = plan.features.iter().map(|f| kind_name(&f.kind)).collect();
    assert_eq!(kinds, ["planar_face", "round_hole", "closed_pocket"]);
    let per_feature: Vec<&[u32]> = plan.features.iter().map(|f| f.workingsteps.as_slice()).collect();
    assert_eq!(per_feature, [&[1][..], &[2, 3], &[4, 5]]);
}

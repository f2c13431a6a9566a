//! The post-style suite (`tests/programs/posts/`): parts written the way Fusion 360,
//! Mastercam, NX and TNC posts and shop programmers write them, by other hands than the
//! recognition rules, each with a sidecar of the features a planner reads from its drawing
//! (`DESIGN.md`). The test scores recognition per kind, sizes within 0.05 mm, and prints
//! precision and recall.

use std::collections::BTreeMap;

use ncplan::dialect::Registry;
use ncplan::interp::Profile;
use ncplan::pipeline;
use ncplan::plan::{Feature, FeatureKind, HoleBottom, ProcessPlan};
use serde_json::Value;

/// Size tolerance, mm: what a drawing's dimensions are read to.
const SIZE: f64 = 0.05;
/// Position tolerance, mm.
const PLACE: f64 = 0.1;

struct Part {
    name: String,
    text: String,
    side: Value,
    tools: Option<String>,
}

fn suite() -> Vec<Part> {
    let dir = crate::root().join("tests/programs/posts");
    let mut names: Vec<_> = std::fs::read_dir(&dir).unwrap().filter_map(|e| e.ok()).map(|e| e.path()).collect();
    names.sort();
    let mut out = Vec::new();
    for side in names.iter().filter(|p| p.extension().is_some_and(|e| e == "json")) {
        let stem = side.file_stem().unwrap().to_string_lossy().into_owned();
        let side_text: Value = serde_json::from_str(&std::fs::read_to_string(side).unwrap()).unwrap();
        let table = side_text["tool_table"].as_str().map(str::to_owned);
        // The program beside its sidecar: not the sidecar, not its tool table.
        let program = names
            .iter()
            .find(|p| {
                let name = p.file_name().unwrap().to_string_lossy();
                p.file_stem().is_some_and(|s| s.to_string_lossy() == stem)
                    && p.extension().is_some_and(|e| e != "json")
                    && table.as_deref() != Some(&*name)
            })
            .unwrap_or_else(|| panic!("{stem}: a program beside its sidecar"));
        let side = side_text;
        let tools = table.map(|t| std::fs::read_to_string(dir.join(t)).unwrap());
        let bytes = std::fs::read(program).unwrap();
        out.push(Part { name: stem, text: String::from_utf8_lossy(&bytes).into_owned(), side, tools });
    }
    out
}

/// The plan of a part; `with_stock`: with its design stock as the configuration's `[stock]`
/// where the program states none.
fn analyze(p: &Part, with_stock: bool) -> ProcessPlan {
    let reg = Registry::shipped();
    let mut profile = Profile::default();
    if with_stock && p.side["stock"].is_null() {
        let d = &p.side["design_stock"];
        let axis = |k: &str, i: usize| d[k][i].as_f64();
        if let (Some(x0), Some(x1), Some(y0), Some(y1), Some(z0), Some(z1)) =
            (axis("x", 0), axis("x", 1), axis("y", 0), axis("y", 1), axis("z", 0), axis("z", 1))
        {
            profile.stock = Some([[x0, y0, z0], [x1, y1, z1]]);
        }
    }
    if let Some(table) = &p.tools {
        profile.tools = ncplan::plan::tooltable::read(table, false).unwrap().1;
    }
    let dialect = reg.get(p.side["dialect"].as_str().unwrap()).unwrap();
    pipeline::analyze(p.text.as_bytes(), &dialect, &profile).plan
}

fn kind_name(k: &FeatureKind) -> String {
    k.label().replace(' ', "_")
}

/// The extent of a feature's contour, absolute.
fn extent(f: &Feature) -> Option<([f64; 2], [f64; 2])> {
    let c = match &f.kind {
        FeatureKind::ClosedPocket { boundary, .. }
        | FeatureKind::OpenPocket { boundary }
        | FeatureKind::OutsideProfile { boundary, .. } => boundary,
        _ => return None,
    };
    let mut min = [f64::INFINITY; 2];
    let mut max = [f64::NEG_INFINITY; 2];
    for p in std::iter::once(c.start).chain(c.segments.iter().map(|s| s.to)) {
        for k in 0..2 {
            min[k] = min[k].min(p[k] + f.placement[k]);
            max[k] = max[k].max(p[k] + f.placement[k]);
        }
    }
    Some((min, max))
}

/// Whether a recognised feature is the expected one: same kind, sizes and depth within
/// [`SIZE`], position within [`PLACE`].
fn matches(f: &Feature, want: &Value) -> bool {
    let num = |k: &str| want.get(k).and_then(Value::as_f64);
    let near = |a: f64, k: &str, tol: f64| num(k).is_none_or(|b| (a - b).abs() <= tol);
    if kind_name(&f.kind) != want["kind"].as_str().unwrap() {
        return false;
    }
    let depth_ok = near(f.depth, "depth", SIZE)
        || want.get("drilled").and_then(|d| d.get("depth")).and_then(Value::as_f64).is_some_and(|d| (f.depth - d).abs() <= SIZE);
    if !depth_ok {
        return false;
    }
    match &f.kind {
        FeatureKind::RoundHole { diameter, positions, bottom, .. } => {
            let at: Vec<[f64; 2]> = positions.iter().map(|p| [p[0] + f.placement[0], p[1] + f.placement[1]]).collect();
            let want_at: Vec<[f64; 2]> = want["positions"]
                .as_array()
                .map(|a| a.iter().map(|p| [p[0].as_f64().unwrap(), p[1].as_f64().unwrap()]).collect())
                .unwrap_or_default();
            let same_places = at.len() == want_at.len()
                && want_at.iter().all(|w| at.iter().any(|a| (a[0] - w[0]).abs() <= PLACE && (a[1] - w[1]).abs() <= PLACE));
            let bottom_ok = match (bottom, want["bottom"].as_str()) {
                (HoleBottom::Through, Some("through")) | (HoleBottom::Flat, Some("flat")) | (_, None) => true,
                (HoleBottom::Conical(a), Some("conical")) => near(*a, "point_angle", 0.5),
                _ => false,
            };
            let drilled = want.get("drilled").and_then(|d| d.get("diameter")).and_then(Value::as_f64);
            let diameter_ok = diameter.is_some_and(|d| near(d, "diameter", SIZE) || drilled.is_some_and(|w| (d - w).abs() <= SIZE));
            same_places && bottom_ok && diameter_ok
        }
        FeatureKind::ClosedPocket { rectangle, corner_radius, .. } => {
            near(f.placement[0], "x", PLACE)
                && near(f.placement[1], "y", PLACE)
                && rectangle.is_some_and(|(w, l)| near(w, "width", SIZE) && near(l, "length", SIZE))
                && near(corner_radius.unwrap_or(0.0), "corner_radius", SIZE)
        }
        FeatureKind::OutsideProfile { rectangle, corner_radius, .. } => {
            let centre = extent(f).map(|(a, b)| [(a[0] + b[0]) / 2.0, (a[1] + b[1]) / 2.0]).unwrap_or_default();
            near(centre[0], "x", PLACE)
                && near(centre[1], "y", PLACE)
                && rectangle.is_some_and(|(w, l)| near(w, "width", SIZE) && near(l, "length", SIZE))
                && near(corner_radius.unwrap_or(0.0), "corner_radius", SIZE)
        }
        FeatureKind::OpenPocket { .. } => {
            let Some((a, b)) = extent(f) else { return false };
            near(b[0] - a[0], "width", SIZE) && near(b[1] - a[1], "length", SIZE)
        }
        FeatureKind::PlanarFace { length, width, direction } => {
            // The face's own frame runs along its passes: width and length in X and Y.
            let (x, y) = if direction[0].abs() >= direction[1].abs() { (*length, *width) } else { (*width, *length) };
            near(x, "width", SIZE) && near(y, "length", SIZE)
        }
        FeatureKind::Step { width, length, .. } => near(*width, "width", SIZE) && near(*length, "length", SIZE),
        FeatureKind::Slot { width, path } => {
            let along: f64 = {
                let mut from = path.start;
                let mut len = 0.0;
                for s in &path.segments {
                    len += (s.to[0] - from[0]).hypot(s.to[1] - from[1]);
                    from = s.to;
                }
                len
            };
            near(*width, "width", SIZE) && near(along, "centre_line_length", SIZE)
        }
        FeatureKind::Toolpath | FeatureKind::Turned(_) => false,
    }
}

/// The least of precision and recall each kind keeps, read as the program states it. Below 1
/// only where a size needs a stock the program does not state (a face's extent, a step's
/// width, whether a hole goes through, a pocket open to a side: a Fusion Fanuc post writes
/// no stock): those programs are scored again with the shop's stock, where every kind is 1.
/// Raise, never lower.
const FLOOR: &[(&str, f64)] =
    &[("closed_pocket", 0.95), ("open_pocket", 0.66), ("planar_face", 0.54), ("round_hole", 0.66), ("slot", 0.77), ("step", 0.6)];

/// The same with the stock the shop knows (`[stock]` in the configuration, the sidecar's
/// `design_stock`) for the programs that do not state it: every kind at 1.
const FLOOR_WITH_STOCK: &[(&str, f64)] = &[];

#[derive(Default)]
struct Score {
    expected: usize,
    found: usize,
    matched: usize,
}

/// Scores every program's plan against its sidecar; prints the table and the misses and
/// returns the kinds below their floor.
#[allow(clippy::print_stdout)] // the table is the test's report (`--nocapture` shows it)
fn score(parts: &[Part], with_stock: bool, floor: &[(&str, f64)]) -> Vec<String> {
    let mut scores: BTreeMap<String, Score> = BTreeMap::new();
    let mut misses = Vec::new();
    for p in parts {
        let plan = analyze(p, with_stock);
        let wants = p.side["features"].as_array().unwrap();
        let mut used = vec![false; plan.features.len()];
        for w in wants {
            let s = scores.entry(w["kind"].as_str().unwrap().to_owned()).or_default();
            s.expected += 1;
            match (0..plan.features.len()).find(|&i| !used[i] && matches(&plan.features[i], w)) {
                Some(i) => {
                    used[i] = true;
                    s.matched += 1;
                }
                None => misses.push(format!("{}: missed {}", p.name, w)),
            }
        }
        for (f, u) in plan.features.iter().zip(&used) {
            scores.entry(kind_name(&f.kind)).or_default().found += 1;
            if !u {
                let kind = serde_json::to_string(&f.kind).unwrap_or_default();
                let kind: String = kind.chars().take(240).collect();
                misses.push(format!("{}: extra at {:?} depth {} {kind}", p.name, f.placement, f.depth));
            }
        }
    }
    println!("{}", if with_stock { "\nwith the shop's stock where the program states none:" } else { "as the programs state it:" });
    println!("{:<26} {:>8} {:>6} {:>8} {:>10} {:>7}", "feature kind", "expected", "found", "matched", "precision", "recall");
    let mut below = Vec::new();
    for (kind, s) in &scores {
        let p = if s.found > 0 { s.matched as f64 / s.found as f64 } else { 1.0 };
        let r = if s.expected > 0 { s.matched as f64 / s.expected as f64 } else { 1.0 };
        println!("{kind:<26} {:>8} {:>6} {:>8} {p:>10.3} {r:>7.3}", s.expected, s.found, s.matched);
        let least = floor.iter().find(|(k, _)| k == kind).map_or(1.0, |(_, f)| *f);
        if p.min(r) < least - 1e-9 {
            below.push(format!("{kind}: {:.3} below {least}", p.min(r)));
        }
    }
    for m in &misses {
        println!("  {m}");
    }
    below
}

#[test]
fn post_suite_precision_and_recall_per_feature_kind() {
    let parts = suite();
    assert!(parts.len() >= 40, "{} programs", parts.len());
    let below = score(&parts, false, FLOOR);
    let below_with_stock = score(&parts, true, FLOOR_WITH_STOCK);
    assert!(below.is_empty() && below_with_stock.is_empty(), "below the floor (see the tables): {below:?} {below_with_stock:?}");
}

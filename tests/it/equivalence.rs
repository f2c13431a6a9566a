//! One engine, three dialects: the same part posted for Fanuc, Siemens 840D and Heidenhain
//! (`tests/programs/equivalence/<part>.{nc,mpf,h}`, written for these tests the way each
//! control's CAM posts write them) gives the same toolpath and the same plan; and a turned
//! part for three lathe dialects (`turn.nc`, `turn_b.nc`, `turn.min`) the same toolpath.

use ncplan::canon::CanonOp;
use ncplan::dialect::Registry;
use ncplan::interp::{Profile, ToolData};
use ncplan::pipeline::{Analysis, analyze};

/// Face milling, a drilled and reamed pattern, a peck-drilled pattern, a pocket contour with arcs.
const PARTS: [&str; 4] = ["face", "drill_ream", "peck", "pocket"];

/// Each part in each dialect, by file extension.
const VERSIONS: [(&str, &str); 3] = [("nc", "fanuc"), ("mpf", "siemens"), ("h", "heidenhain")];

/// The shop's tool table: Siemens programs call some tools by name.
fn profile(named: bool) -> Profile {
    let tool = |kind: &str, diameter: f64, length: f64, name: &str| ToolData {
        diameter: Some(diameter),
        length,
        name: named.then(|| name.to_owned()),
        kind: Some(kind.to_owned()),
        ..ToolData::default()
    };
    let mut p = Profile::default();
    p.tools.insert(1, tool("face_mill", 50.0, 100.0, "FACEMILL_D50"));
    p.tools.insert(2, tool("twist_drill", 7.8, 120.0, "DRILL_D7.8"));
    p.tools.insert(3, tool("reamer", 8.0, 110.0, "REAMER_D8H7"));
    p.tools.insert(4, tool("end_mill", 10.0, 90.0, "ENDMILL_D10"));
    p.tools.insert(5, tool("twist_drill", 6.0, 115.0, "DRILL_D6"));
    p
}

fn run(part: &str, ext: &str, dialect: &str, profile: &Profile) -> Analysis {
    let path = crate::root().join("tests/programs/equivalence").join(format!("{part}.{ext}"));
    let bytes = std::fs::read(&path).unwrap();
    let d = Registry::shipped().get(dialect).unwrap();
    let a = analyze(&bytes, &d, profile);
    assert!(a.diagnostics.is_empty(), "{part}.{ext}: {:#?}", a.diagnostics);
    a
}

/// The moves: kind, end point, and for arcs the centre and turns.
fn toolpath(a: &Analysis) -> Vec<(&'static str, Vec<f64>)> {
    a.canon
        .iter()
        .filter_map(|c| match &c.op {
            CanonOp::StraightTraverse(p) => Some(("traverse", p.to_vec())),
            CanonOp::StraightFeed(p) => Some(("feed", p.to_vec())),
            CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, .. } => {
                Some(("arc", vec![*first_end, *second_end, *first_axis, *second_axis, f64::from(*rotation), *axis_end]))
            }
            _ => None,
        })
        .collect()
}

/// `got` has the moves of `want`, of the same kinds, their numbers within 1e-6.
fn assert_same_toolpath(label: &str, got: &[(&'static str, Vec<f64>)], want: &[(&'static str, Vec<f64>)]) {
    assert_eq!(got.len(), want.len(), "{label}: {got:?}");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(g.0, w.0, "{label} move {i}");
        for (x, y) in g.1.iter().zip(&w.1) {
            assert!((x - y).abs() <= 1e-6, "{label} move {i}: {g:?} against {w:?}");
        }
    }
}

/// The plan without what legitimately differs between posts: tool and program names, where
/// facts came from, and source positions.
fn comparable_plan(a: &Analysis) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                // Names and source positions differ by dialect, and so does what only some
                // dialects state: the surface a defined cycle names (`RFP`, `Q203`) is a hole's
                // `top`, which a G8x cycle leaves to the stock (the features still agree).
                for key in ["program", "name", "source", "kind_source", "lines", "line", "top"] {
                    m.remove(key);
                }
                m.values_mut().for_each(strip);
            }
            serde_json::Value::Array(items) => items.iter_mut().for_each(strip),
            _ => {}
        }
    }
    let mut v = serde_json::to_value(&a.plan).unwrap();
    strip(&mut v);
    v
}

#[test]
fn every_dialect_gives_the_same_toolpath() {
    let profile = profile(true);
    for part in PARTS {
        let reference = run(part, "nc", "fanuc", &profile);
        let want = toolpath(&reference);
        assert!(want.len() >= 10, "{part}: {} moves", want.len());
        for (ext, dialect) in &VERSIONS[1..] {
            assert_same_toolpath(&format!("{part}.{ext}"), &toolpath(&run(part, ext, dialect, &profile)), &want);
        }
    }
}

/// A turned shaft (facing, then three roughing passes) for three lathe controls: Fanuc in
/// G-code system A with its single-pass cycles G94 and G90, the same in system B (G79, G77),
/// and Okuma OSP-L with every pass written out. X words are diameters in all three.
#[test]
fn every_lathe_dialect_gives_the_same_toolpath() {
    let profile = Profile::default();
    let reference = run("turn", "nc", "fanuc_lathe", &profile);
    let want = toolpath(&reference);
    assert_eq!(want.len(), 19, "{want:?}");
    // The face cut runs to X-0.8 (a diameter of -1.6), the last pass to X20 at Z-40.
    assert!(want.contains(&("feed", vec![-0.8, 0.0, 0.0, 0.0, 0.0, 0.0])), "{want:?}");
    assert!(want.contains(&("feed", vec![20.0, 0.0, -40.0, 0.0, 0.0, 0.0])), "{want:?}");
    for (part, ext, dialect) in [("turn_b", "nc", "fanuc_lathe_b"), ("turn", "min", "okuma_lathe")] {
        assert_same_toolpath(&format!("{part}.{ext}"), &toolpath(&run(part, ext, dialect, &profile)), &want);
    }
}

#[test]
fn every_dialect_gives_the_same_plan_except_tool_names() {
    let profile = profile(true);
    for part in PARTS {
        let reference = run(part, "nc", "fanuc", &profile);
        assert!(!reference.plan.workingsteps.is_empty() && !reference.plan.features.is_empty(), "{part}");
        assert!(reference.plan.workpiece.is_some(), "{part}: the stock is stated in every version");
        let want = comparable_plan(&reference);
        for (ext, dialect) in &VERSIONS[1..] {
            let got = comparable_plan(&run(part, ext, dialect, &profile));
            assert_eq!(got, want, "{part}.{ext}");
        }
    }
}

#[test]
fn the_parts_are_what_they_claim() {
    let profile = profile(true);
    let kinds = |part: &str| {
        let a = run(part, "h", "heidenhain", &profile);
        a.plan.features.iter().map(|f| format!("{:?}", f.kind)).collect::<Vec<_>>().join(" ")
    };
    assert!(kinds("face").contains("PlanarFace"), "{}", kinds("face"));
    assert!(kinds("drill_ream").contains("RoundHole"), "{}", kinds("drill_ream"));
    assert!(kinds("peck").contains("RoundHole"), "{}", kinds("peck"));
    let peck = run("peck", "mpf", "siemens", &profile);
    assert_eq!(peck.plan.workingsteps[0].operation.label(), "multistep drilling");
    let ream = run("drill_ream", "h", "heidenhain", &profile);
    assert_eq!(ream.plan.workingsteps.iter().map(|w| w.operation.label()).collect::<Vec<_>>(), ["drilling", "reaming"]);
}

#[test]
fn diff_between_fanuc_and_siemens_reports_only_renamed_tools() {
    // Without names in the tool table, Siemens' `T="FACEMILL_D50"` is a tool of its own
    // (numbered from 10001): the diff says the tool was renamed, and nothing else.
    let profile = profile(false);
    let mut renamed = 0;
    for part in PARTS {
        let fanuc = run(part, "nc", "fanuc", &profile);
        let siemens = run(part, "mpf", "siemens", &profile);
        let changes = ncplan::diff::diff(&fanuc.plan, &siemens.plan);
        for c in &changes {
            assert_eq!(c.kind.as_str(), "tool_renamed", "{part}: {}", c.phrase());
        }
        renamed += changes.len();
    }
    assert!(renamed >= 2, "the face and drill_ream parts call tools by name");
}

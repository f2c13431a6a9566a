//! CLDATA in: CL files read by the `cldata` dictionary (`dialects/cldata.xml`) give the same
//! toolpath and the same plan as the Fanuc program a correct post makes of them.
//!
//! `tests/programs/cldata/` holds five parts (a face, drilling and reaming cycles, a peck
//! cycle, a pocket with arcs, an outside profile with cutter compensation), each as NX
//! (`_nx.cls`), Creo (`_creo.ncl`) and CATIA V5 (`_catia.aptsource`) export it, and the
//! Fanuc program (`.nc`); `generate.py` wrote them. The corpus's CL files
//! (`../shared/corpus/cldata/`) read without errors, and its NX → Haas pairs agree.

use ncplan::canon::CanonOp;
use ncplan::diag::{Code, Severity};
use ncplan::dialect::Registry;
use ncplan::interp::{Profile, ToolData};
use ncplan::pipeline::{Analysis, analyze};

const PARTS: [&str; 5] = ["face", "drill_ream", "peck", "pocket", "profile"];
const STYLES: [(&str, &str); 3] = [("nx", "cls"), ("creo", "ncl"), ("catia", "aptsource")];

/// The shop's tool table: diameters (the plan's features and the compensation need them), no lengths.
fn profile() -> Profile {
    let tool = |kind: &str, diameter: f64| ToolData { diameter: Some(diameter), kind: Some(kind.to_owned()), ..ToolData::default() };
    let mut p = Profile::default();
    p.tools.insert(1, tool("face_mill", 50.0));
    p.tools.insert(2, tool("twist_drill", 7.8));
    p.tools.insert(3, tool("reamer", 8.0));
    p.tools.insert(4, tool("end_mill", 10.0));
    p.tools.insert(5, tool("twist_drill", 6.0));
    p
}

fn read(file: &str, dialect: &str) -> Analysis {
    let path = crate::root().join("tests/programs/cldata").join(file);
    let bytes = std::fs::read(&path).unwrap();
    analyze(&bytes, &Registry::shipped().get(dialect).unwrap(), &profile())
}

/// Findings that are more than notes.
fn findings(a: &Analysis) -> Vec<String> {
    a.diagnostics.iter().filter(|d| d.severity != Severity::Note).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect()
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

/// `got` has the moves of `want`, of the same kinds, their numbers within `tol`.
fn assert_same_toolpath(label: &str, got: &[(&'static str, Vec<f64>)], want: &[(&'static str, Vec<f64>)], tol: f64) {
    assert_eq!(got.len(), want.len(), "{label}: {got:?}\nagainst {want:?}");
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        assert_eq!(g.0, w.0, "{label} move {i}");
        for (x, y) in g.1.iter().zip(&w.1) {
            assert!((x - y).abs() <= tol, "{label} move {i}: {g:?} against {w:?}");
        }
    }
}

/// The plan without what legitimately differs between a CL file and its post's program:
/// names, where facts came from, and source positions.
fn comparable_plan(a: &Analysis) -> serde_json::Value {
    fn strip(v: &mut serde_json::Value) {
        match v {
            serde_json::Value::Object(m) => {
                for key in ["program", "name", "source", "kind_source", "lines", "line"] {
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
fn every_cl_style_gives_the_fanuc_toolpath() {
    for part in PARTS {
        let fanuc = read(&format!("{part}.nc"), "fanuc");
        assert!(findings(&fanuc).is_empty(), "{part}.nc: {:#?}", findings(&fanuc));
        let want = toolpath(&fanuc);
        assert!(want.len() >= 8, "{part}: {} moves", want.len());
        for (style, ext) in STYLES {
            let file = format!("{part}_{style}.{ext}");
            let cl = read(&file, "cldata");
            assert!(findings(&cl).is_empty(), "{file}: {:#?}", findings(&cl));
            assert_same_toolpath(&file, &toolpath(&cl), &want, 0.001);
        }
    }
}

#[test]
fn every_cl_style_gives_the_fanuc_plan() {
    for part in PARTS {
        let fanuc = read(&format!("{part}.nc"), "fanuc");
        assert!(!fanuc.plan.workingsteps.is_empty() && !fanuc.plan.features.is_empty(), "{part}");
        let want = comparable_plan(&fanuc);
        for (style, ext) in STYLES {
            let file = format!("{part}_{style}.{ext}");
            let got = comparable_plan(&read(&file, "cldata"));
            assert_eq!(got, want, "{file}");
        }
    }
}

#[test]
fn the_parts_are_what_they_claim() {
    let kinds = |file: &str| read(file, "cldata").plan.features.iter().map(|f| format!("{:?}", f.kind)).collect::<Vec<_>>().join(" ");
    assert!(kinds("face_nx.cls").contains("PlanarFace"), "{}", kinds("face_nx.cls"));
    assert!(kinds("drill_ream_creo.ncl").contains("RoundHole"), "{}", kinds("drill_ream_creo.ncl"));
    assert!(kinds("peck_catia.aptsource").contains("RoundHole"), "{}", kinds("peck_catia.aptsource"));
    let ream = read("drill_ream_nx.cls", "cldata");
    assert_eq!(ream.plan.workingsteps.iter().map(|w| w.operation.label()).collect::<Vec<_>>(), ["drilling", "reaming"]);
    let peck = read("peck_creo.ncl", "cldata");
    assert_eq!(peck.plan.workingsteps[0].operation.label(), "multistep drilling");
    // The cycles keep their intent: one CycleBegin per hole, as from G81-G89.
    let begins = |a: &Analysis| a.canon.iter().filter(|c| matches!(c.op, CanonOp::CycleBegin(_))).count();
    assert_eq!(begins(&ream), 8);
    assert_eq!(begins(&read("drill_ream.nc", "fanuc")), 8);
}

/// The cutting moves (feeds and arcs) in millimetres: end point, and for arcs the centre.
fn cuts_mm(a: &Analysis) -> Vec<(&'static str, Vec<f64>)> {
    let mut scale = 1.0;
    let mut out = Vec::new();
    for c in &a.canon {
        match &c.op {
            CanonOp::UseLengthUnits(u) => scale = if matches!(u, ncplan::canon::Units::Inch) { 25.4 } else { 1.0 },
            CanonOp::StraightFeed(p) => out.push(("feed", p[..3].iter().map(|v| v * scale).collect())),
            CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, .. } => out.push((
                "arc",
                vec![*first_end * scale, *second_end * scale, *first_axis * scale, *second_axis * scale, f64::from(*rotation), *axis_end * scale],
            )),
            _ => {}
        }
    }
    out
}

fn corpus_analysis(folder: &str, file: &str, dialect: &str) -> Analysis {
    let corpus = crate::shared().join("corpus");
    let bytes = std::fs::read(corpus.join(folder).join(file)).unwrap();
    analyze(&bytes, &Registry::shipped().get(dialect).unwrap(), &Profile::default())
}

/// NX → Haas (HAAS_UMC750_5AXIS_MILL_IN, an inch post): the program the post made from each
/// corpus CL file cuts the same path, within the post's output resolution (0.0001 in =
/// 0.00254 mm, so half of it plus the CL's own 4 decimals). The rapids differ by the post's
/// safe start (G53 Z0, G28, B0 C0, X Y before Z), so only cuts are compared.
#[test]
fn nx_cl_files_cut_what_their_haas_programs_cut() {
    let Some(_) = crate::shared_corpus("cldata::nx_cl_files_cut_what_their_haas_programs_cut") else { return };
    for part in ["SimpleMillPlane", "SimpleMillPlane_ZIG", "Zig_Zag_Smoothed"] {
        let cl = corpus_analysis("cldata", &format!("mech491__APT_{part}.txt"), "cldata");
        let haas = corpus_analysis("haas", &format!("mech491__PostProcessed_{part}.txt"), "haas");
        let (got, want) = (cuts_mm(&cl), cuts_mm(&haas));
        assert!(want.len() >= 10, "{part}: {} cuts", want.len());
        assert_same_toolpath(part, &got, &want, 0.003);
        // The same workingsteps and tools; the feed differs by the post's rounding to 0.1 in/min.
        assert_eq!(cl.plan.workingsteps.len(), haas.plan.workingsteps.len(), "{part}");
        assert_eq!(cl.plan.tools.iter().map(|t| t.number).collect::<Vec<_>>(), haas.plan.tools.iter().map(|t| t.number).collect::<Vec<_>>(), "{part}");
    }
}

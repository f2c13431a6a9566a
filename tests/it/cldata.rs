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
            let cl = read(&file, "cldata");
            assert_eq!(comparable_plan(&cl), want, "{file}");
            // `ncplan diff` between the CL original and the posted program reports nothing.
            let changes = ncplan::diff::diff(&cl.plan, &fanuc.plan);
            assert!(changes.is_empty(), "{file}: {:?}", changes.iter().map(|c| c.phrase()).collect::<Vec<_>>());
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
    cuts(a, true)
}

/// As [`cuts_mm`]; without the moves of canned-cycle holes where `cycles` is false.
fn cuts(a: &Analysis, cycles: bool) -> Vec<(&'static str, Vec<f64>)> {
    let mut scale = 1.0;
    let mut out = Vec::new();
    let mut in_cycle = false;
    for c in &a.canon {
        match &c.op {
            CanonOp::CycleBegin(_) => in_cycle = true,
            CanonOp::CycleEnd => in_cycle = false,
            _ if in_cycle && !cycles => {}
            CanonOp::UseLengthUnits(u) => scale = if matches!(u, ncplan::canon::Units::Inch) { 25.4 } else { 1.0 },
            CanonOp::StraightFeed(p) => out.push(("feed", p[..3].iter().map(|v| v * scale).collect())),
            CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, .. } => out.push((
                "arc",
                vec![
                    *first_end * scale,
                    *second_end * scale,
                    *first_axis * scale,
                    *second_axis * scale,
                    f64::from(*rotation),
                    *axis_end * scale,
                ],
            )),
            _ => {}
        }
    }
    out
}

/// As [`assert_same_toolpath`], except that the post may write an arc shorter than 0.1 mm as
/// a line to the same end (the Haas post does: `CIRCLE` of 0.036 mm in Zig_Zag_Smoothed
/// became `G01 X5.9085 Y6.1023`).
fn assert_same_cuts(label: &str, got: &[(&'static str, Vec<f64>)], want: &[(&'static str, Vec<f64>)], tol: f64) {
    assert_eq!(got.len(), want.len(), "{label}");
    let mut last = [f64::NAN; 2];
    let mut linearised = 0;
    for (i, (g, w)) in got.iter().zip(want).enumerate() {
        let end = |m: &(&str, Vec<f64>)| [m.1[0], m.1[1]];
        if g.0 != w.0 {
            let chord = (end(g)[0] - last[0]).hypot(end(g)[1] - last[1]);
            assert!(chord < 0.1, "{label} move {i}: {g:?} against {w:?}");
            linearised += 1;
            for (x, y) in end(g).iter().zip(&end(w)) {
                assert!((x - y).abs() <= tol, "{label} move {i}: {g:?} against {w:?}");
            }
        } else {
            for (x, y) in g.1.iter().zip(&w.1) {
                assert!((x - y).abs() <= tol, "{label} move {i}: {g:?} against {w:?}");
            }
        }
        last = end(g);
    }
    assert!(linearised * 20 <= got.len(), "{label}: {linearised} short arcs written as lines");
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
        assert_same_cuts(part, &got, &want, 0.003);
        // The same workingsteps and tools; the feed differs by the post's rounding to 0.1 in/min.
        assert_eq!(cl.plan.workingsteps.len(), haas.plan.workingsteps.len(), "{part}");
        assert_eq!(
            cl.plan.tools.iter().map(|t| t.number).collect::<Vec<_>>(),
            haas.plan.tools.iter().map(|t| t.number).collect::<Vec<_>>(),
            "{part}"
        );
    }
}

/// Every corpus CL file reads with the `cldata` dictionary without errors; the findings left
/// are the data's own (tilted circles of a 5-axis part, the producer's cusps, NX listings'
/// header lines, post-processor words passed over).
#[test]
fn every_corpus_cl_file_reads_without_errors() {
    let Some(corpus) = crate::shared_corpus("cldata::every_corpus_cl_file_reads_without_errors") else { return };
    let registry = Registry::shipped();
    let mut files = std::fs::read_dir(corpus.join("cldata")).unwrap().map(|e| e.unwrap().path()).collect::<Vec<_>>();
    files.sort();
    assert_eq!(files.len(), 36);
    for path in &files {
        let bytes = std::fs::read(path).unwrap();
        // Sniffing tells them CL files.
        let sniffed = ncplan::pipeline::sniff(&registry, &bytes, path);
        assert_eq!(sniffed.dialect, "cldata", "{}", path.display());
        let a = analyze(&bytes, &registry.get("cldata").unwrap(), &Profile::default());
        let errors =
            a.diagnostics.iter().filter(|d| d.is_error()).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect::<Vec<_>>();
        assert!(errors.is_empty(), "{}: {errors:#?}", path.display());
        assert!(
            a.canon.iter().filter(|c| matches!(c.op, CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. })).count() > 0,
            "{}",
            path.display()
        );
        assert!(a.diagnostics.iter().any(|d| d.code == Code::RecordProducer), "{}", path.display());
    }
}

#[test]
fn sniffing_tells_cl_files_from_programs() {
    let registry = Registry::shipped();
    for part in PARTS {
        for (style, ext) in STYLES {
            let file = format!("{part}_{style}.{ext}");
            let bytes = std::fs::read(crate::root().join("tests/programs/cldata").join(&file)).unwrap();
            // By content alone, without the extension.
            let s = ncplan::pipeline::sniff(&registry, &bytes, std::path::Path::new("program.txt"));
            assert_eq!(s.dialect, "cldata", "{file}");
        }
        let bytes = std::fs::read(crate::root().join("tests/programs/cldata").join(format!("{part}.nc"))).unwrap();
        assert_eq!(ncplan::pipeline::sniff(&registry, &bytes, std::path::Path::new("program.nc")).dialect, "fanuc", "{part}.nc");
    }
}

/// The producer's circle sense decides which way an arc turns, and the tangent moves check it:
/// the pocket's arcs with their axes reversed have a cusp at both ends and say so, and are
/// read as the setting says (clockwise in XY for Creo's -Z), not guessed.
#[test]
fn a_circle_against_its_producers_sense_is_reported() {
    for (file, from, to) in [
        ("pocket_creo.ncl", "0.0000000000, 0.0000000000, 1.0000000000, 3", "0.0000000000, 0.0000000000, -1.0000000000, 3"),
        ("pocket_nx.cls", "0.0000000,0.0000000,-1.0000000,3.0000", "0.0000000,0.0000000,1.0000000,3.0000"),
    ] {
        let text = std::fs::read_to_string(crate::root().join("tests/programs/cldata").join(file)).unwrap();
        assert_eq!(text.matches(from).count(), 4, "{file}");
        let flipped = text.replace(from, to);
        let a = analyze(flipped.as_bytes(), &Registry::shipped().get("cldata").unwrap(), &profile());
        let against = a.diagnostics.iter().filter(|d| d.code == Code::CircleDirection).count();
        assert_eq!(against, 4, "{file}: {:#?}", a.diagnostics);
        // Clockwise now: negative rotations.
        let turns = a
            .canon
            .iter()
            .filter_map(|c| if let CanonOp::ArcFeed { rotation, .. } = c.op { Some(rotation) } else { None })
            .collect::<Vec<_>>();
        assert_eq!(turns, [-1, -1, -1, -1], "{file}");
        // As written, no finding.
        let a = read(file, "cldata");
        assert!(!a.diagnostics.iter().any(|d| d.code == Code::CircleDirection), "{file}");
    }
}

/// `GOTO/x,y,z,i,j,k` keeps the tool axis: a `ToolAxis` marker where it changes, the move
/// itself the tool tip's; a 3-axis file (axis +Z throughout) has none.
#[test]
fn the_tool_axis_goes_into_the_canon_where_it_changes() {
    let cl = "PARTNO/AXIS\nUNITS/MM\nLOADTL/1\nFEDRAT/500,MMPM\nGOTO/0,0,10,0,0,1\nGOTO/10,0,10,0,0.6,0.8\nGOTO/20,0,10,0,0.6,0.8\nGOTO/30,0,10\n\
                GOTO/40,0,10,0,0,1.\nFINI\n";
    let a = analyze(cl.as_bytes(), &Registry::shipped().get("cldata").unwrap(), &Profile::default());
    assert!(!a.has_errors(), "{:#?}", a.diagnostics);
    let axes = a.canon.iter().filter_map(|c| if let CanonOp::ToolAxis(v) = c.op { Some(v) } else { None }).collect::<Vec<_>>();
    assert_eq!(axes, [[0.0, 0.6, 0.8], [0.0, 0.0, 1.0]]);
    let feeds = a.canon.iter().filter_map(|c| if let CanonOp::StraightFeed(p) = c.op { Some(p[0]) } else { None }).collect::<Vec<_>>();
    assert_eq!(feeds, [0.0, 10.0, 20.0, 30.0, 40.0]);
    // It prints as a marker rs274 comparisons drop.
    let mut text = String::new();
    for c in &a.canon {
        ncplan::canon::write_call(&mut text, &c.op);
        text.push('\n');
    }
    assert!(text.contains("COMMENT(\"ncplan: tool axis 0.000000 0.600000 0.800000\")"), "{text}");
    for part in PARTS {
        let a = read(&format!("{part}_catia.aptsource"), "cldata");
        assert!(!a.canon.iter().any(|c| matches!(c.op, CanonOp::ToolAxis(_))), "{part}");
    }
}

/// The record syntax's traps (../shared/reference/cldata.md §7): a record continued inside a
/// number, a `$$` comment continued over bare lines, `$ $$` (continued and commented),
/// no-slash text records, foreign lines, unknown post-processor words, `RAPID` one-shot.
#[test]
fn the_record_syntax_traps_are_read_as_the_reference_says() {
    let cl = "Information listing created by\tphill\n\
              PARTNO PART TO BE MACHINED\n\
              $$-> CSYS / 1.0, 0.0, 0.0, 0.0,  $\n   0.0, 1.0, 0.0, 0.0,  $\n   0.0, 0.0, 1.0, 0.0\n\
              UNITS / MM\n\
              FEDRAT / 400.0,  MMPM\n\
              RAPID\n\
              GOTO  /  10.00000,  20.00000,  5.0$\n00000\n\
              GOTO / 10.0, 25.0, $ $$ trailing comment\n 5.0\n\
              AIR/ON\n\
              GOTO/15,25,5\n\
              Tool Path Listing has 3 lines.\n\
              FINI\n";
    let a = analyze(cl.as_bytes(), &Registry::shipped().get("cldata").unwrap(), &Profile::default());
    assert!(!a.has_errors(), "{:#?}", a.diagnostics);
    let moves = toolpath(&a);
    assert_eq!(
        moves,
        [
            ("traverse", vec![10.0, 20.0, 5.0, 0.0, 0.0, 0.0]),
            ("feed", vec![10.0, 25.0, 5.0, 0.0, 0.0, 0.0]),
            ("feed", vec![15.0, 25.0, 5.0, 0.0, 0.0, 0.0])
        ]
    );
    let codes = a.diagnostics.iter().map(|d| d.code).collect::<Vec<_>>();
    assert_eq!(codes.iter().filter(|c| **c == Code::NotARecord).count(), 2, "{:#?}", a.diagnostics);
    assert_eq!(codes.iter().filter(|c| **c == Code::UnknownRecord).count(), 1, "{:#?}", a.diagnostics);
    // The feed stays 400 after the rapid; the part name is a comment.
    assert!(a.canon.iter().any(|c| c.op == CanonOp::SetFeedRate(400.0)));
    assert!(a.canon.iter().any(|c| c.op == CanonOp::Comment("PART TO BE MACHINED".into())), "{:#?}", a.canon);
}

/// The loader checks the record form and points into the XML.
#[test]
fn record_form_mistakes_point_into_the_dictionary() {
    let xml = std::fs::read_to_string(crate::root().join("dialects/cldata.xml")).unwrap();
    for (from, to, says) in [
        (r#"<record major="GOTO" action="goto" codes="G1"/>"#, r#"<record major="GOTO" action="goto" codes="G7"/>"#, "`G7` is not a code"),
        (
            r#"<record major="GOTO" action="goto" codes="G1"/>"#,
            r#"<record major="GOTO" action="go" codes="G1"/>"#,
            "unknown record action `go`",
        ),
        (
            r#"<minor word="FEDTO" role="axis-z" from-point="down"/>"#,
            r#"<minor word="FEDTO" role="axis-z" from-point="below"/>"#,
            "`from-point` is up or down",
        ),
        (r#"<producer name="ISO 4343" circle="counter-clockwise"/>"#, "", "needs one <producer> without <evidence>"),
        (r#"<lexical block-form="record">"#, r#"<lexical block-form="word-address">"#, "<records> needs block-form"),
    ] {
        assert!(xml.contains(from), "{from}");
        let bad = xml.replacen(from, to, 1);
        let (dialect, diags) = ncplan::dialect::load(&bad);
        assert!(dialect.is_none(), "{says}");
        let d = diags.iter().find(|d| d.message.contains(says)).unwrap_or_else(|| panic!("{says}: {diags:#?}"));
        // The finding points at the changed element (the <records> element for what it lacks).
        let marker = if to.is_empty() || to.starts_with("<lexical") { "<records " } else { to };
        let line_of = |at: usize| bad[..at].matches('\n').count();
        assert!(d.range.end > d.range.start, "{says}");
        assert_eq!(
            line_of(d.range.start as usize),
            line_of(bad.find(marker).unwrap()),
            "{says}: {:?}",
            &bad[d.range.start as usize..d.range.end as usize]
        );
    }
}

/// A CAM folder of CL files and a machine share of Fanuc programs: the real daemon pairs the
/// shop's program with its CL original by name (the CL file's name; its `PARTNO` is a key
/// too) and reports the operator's edit, and nothing else.
#[test]
fn the_daemon_compares_a_shop_program_with_its_cl_original() {
    use std::process::{Command, Stdio};
    use std::time::{Duration, Instant};
    let dir = tempfile::tempdir().unwrap();
    let path = |rel: &str| dir.path().join(rel);
    std::fs::create_dir_all(path("cam")).unwrap();
    std::fs::create_dir_all(path("share")).unwrap();
    std::fs::write(
        path("ncplan.toml"),
        "[database]\npath = 'var/ncplan.db'\n[daemon]\nsettle_ms = 200\n\
         [[cam]]\npath = 'cam'\ndialect = 'auto'\n\
         [[machine]]\nname = 'M1'\npath = 'share'\ndialect = 'fanuc'\n",
    )
    .unwrap();
    let programs = crate::root().join("tests/programs/cldata");
    std::fs::copy(programs.join("pocket_nx.cls"), path("cam/POCKET.cls")).unwrap();
    std::fs::copy(programs.join("drill_ream_creo.ncl"), path("cam/DRILL_REAM.ncl")).unwrap();
    // A CL file whose PARTNO names the program the post writes (`O1005`), under another file name.
    let profile = std::fs::read_to_string(programs.join("profile_creo.ncl")).unwrap().replace("PARTNO / PROFILE", "PARTNO / O1005");
    std::fs::write(path("cam/PROFILE_OP10.ncl"), profile).unwrap();
    let log = std::fs::File::create(path("daemon.log")).unwrap();
    let mut child = Command::new(crate::bin())
        .current_dir(crate::support::config_dir(&path("ncplan.toml")))
        .args(["watch", "--config"])
        .arg(path("ncplan.toml"))
        .env("NCPLAN_LOG", "debug")
        .stdout(Stdio::null())
        .stderr(log)
        .spawn()
        .expect("start ncplan watch");
    let db = path("var/ncplan.db");
    let wait_for = |sql: &str, want: usize| {
        let deadline = Instant::now() + Duration::from_secs(30);
        loop {
            let r = crate::db_rows(&db, sql);
            if r.len() >= want || Instant::now() > deadline {
                return r;
            }
            std::thread::sleep(Duration::from_millis(20));
        }
    };
    assert_eq!(wait_for("SELECT id FROM revisions", 3).len(), 3);
    // The operator slows the pocket's contour feed from 600 to 450; the drilling program
    // goes to the machine as posted.
    // The CL file states its tool (`TLDATA/MILL,10,...`); the posted program says it in
    // the tool-change comment, as posts write it, so both plans know the D10 end mill.
    let pocket =
        std::fs::read_to_string(programs.join("pocket.nc")).unwrap().replace("F600.", "F450.").replace("T4 M6\n", "T4 M6 (D10 ENDMILL)\n");
    std::fs::write(path("share/POCKET.nc"), pocket).unwrap();
    std::fs::copy(programs.join("drill_ream.nc"), path("share/DRILL_REAM.nc")).unwrap();
    std::fs::copy(programs.join("profile.nc"), path("share/PROFILE.nc")).unwrap();
    let compared = wait_for(
        "SELECT p.path, c.rule, c.changes FROM comparisons c JOIN revisions r ON r.id = c.original_revision_id
         JOIN programs p ON p.id = r.program_id ORDER BY p.path",
        3,
    );
    let _ = child.kill();
    let _ = child.wait();
    assert_eq!(compared.len(), 3, "{compared:?}\n{}", std::fs::read_to_string(path("daemon.log")).unwrap_or_default());
    assert!(compared[0][0].ends_with("cam/DRILL_REAM.ncl") && compared[1][0].ends_with("cam/POCKET.cls"), "{compared:?}");
    assert!(compared[2][0].ends_with("cam/PROFILE_OP10.ncl"), "{compared:?}");
    assert_eq!(
        (compared[0][1].as_str(), compared[0][2].as_str()),
        ("file-name", "0"),
        "the posted drilling program is what its CL file says"
    );
    assert_eq!((compared[1][1].as_str(), compared[1][2].as_str()), ("file-name", "1"));
    assert_eq!((compared[2][1].as_str(), compared[2][2].as_str()), ("program-name", "0"), "paired by the CL file's PARTNO");
    let changes = crate::db_rows(&db, "SELECT program, kind, before, after FROM shopfloor_changes");
    assert_eq!(changes, [["O1004", "feed_changed", "F200, F600", "F200, F450"]]);
    // The CL originals were read as CL files, without errors.
    let errors = crate::db_rows(&db, "SELECT d.code FROM diagnostics d WHERE d.severity = 'error'");
    assert!(errors.is_empty(), "{errors:?}");
}

/// Record soup: random sequences of CL records, continuations and comments, never a panic,
/// every finding's range inside the text on character boundaries.
mod soup {
    use proptest::prelude::*;

    const PIECES: &[&str] = &[
        "GOTO/1,2,3\n",
        "GOTO/1.5,-2,3,0,0,1\n",
        "GOTO/0,0,0,0.6,0,0.8\n",
        "RAPID\n",
        "RAPID/\n",
        "CIRCLE/0,0,0,0,0,1,5\n",
        "CIRCLE/1,1,1,0,1,0,2,TIMES,3\n",
        "CIRCLE/0,0,0,0,0,0\n",
        "CYCLE/DRILL,FEDTO,5,MMPM,100,RAPTO,2\n",
        "CYCLE/OFF\n",
        "CYCLE/ON,FEDTO,-3\n",
        "FEDRAT/MMPM,250\n",
        "FEDRAT/IPM,10\n",
        "SPINDL/RPM,1000,CLW\n",
        "LOADTL/3\n",
        "LOAD/TOOL,0,ADJUST,1\n",
        "CUTCOM/LEFT,4\n",
        "CUTCOM/OFF\n",
        "COOLNT/FLOOD\n",
        "DELAY/2\n",
        "GODLTA/1,1,1\n",
        "GODLTA/5\n",
        "FROM/0,0,50\n",
        "PPRINT/a, b = c # \"d\"\n",
        "PARTNO x\n",
        "$$ comment $\n",
        "  continued comment\n",
        "GOTO / 1, 2, $\n",
        "3\n",
        "0$\n",
        ".5\n",
        "$ $$ x\n",
        "TOOL PATH/OP,TOOL,T\n",
        "END-OF-PATH\n",
        "FINI\n",
        "UNITS/INCHES\n",
        "STOP/(x)\n",
        "\u{a0}GOTO/\u{a0}1\u{a0}\n",
        "é/ü,ß\n",
        "\r\n",
        "/\n",
        ",,,\n",
        "GOTO/nan,inf,-inf\n",
        "1,2,3\n",
    ];

    proptest! {
        #![proptest_config(ProptestConfig { cases: std::env::var("NCPLAN_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256), ..ProptestConfig::default() })]

        #[test]
        fn record_soup_never_panics(picks in proptest::collection::vec(0..PIECES.len(), 0..40)) {
            let text: String = picks.iter().map(|&i| PIECES[i]).collect();
            let d = ncplan::dialect::Registry::shipped().get("cldata").unwrap();
            let a = ncplan::pipeline::analyze(text.as_bytes(), &d, &ncplan::interp::Profile::default());
            let len = a.source.text.len() as u32;
            for x in &a.diagnostics {
                prop_assert!(x.range.start <= x.range.end && x.range.end <= len, "{:?}", x);
                prop_assert!(a.source.text.is_char_boundary(x.range.start as usize) && a.source.text.is_char_boundary(x.range.end as usize), "{:?}", x);
            }
            for c in &a.canon {
                prop_assert!(c.origin.end <= len);
            }
        }
    }
}

/// The hole positions the cycle intents state, in order.
fn holes(a: &Analysis) -> Vec<[f64; 3]> {
    a.canon.iter().filter_map(|c| if let CanonOp::CycleBegin(i) = &c.op { Some([i.x, i.y, i.bottom]) } else { None }).collect()
}

/// SolidWorks CAM → Heidenhain (the aptpp repository's own post, S8 in the reference): for
/// the corpus parts machined in one untilted setup, the Heidenhain program drills the same
/// holes to the same depth and cuts the same path outside them as the CL file, within the
/// post's 3 decimals. Real differences, explained: inside the holes the pecks differ, as the
/// post writes the CL's pecking cycles as the legacy `CYCL DEF 1` with RAPTO as its plunging
/// depth (pecks every 3 mm, where the CL says 5 then 2); it numbers tools +100 (`TOOL DEF
/// 114` for `LOAD/TOOL,14`); the parts with tilted setups (`CYCL DEF 7`/`19`) are left out.
/// Outside the holes every end point of either program is one of the other's; three of the
/// four CL files have more moves to those points than their Heidenhain programs (207/204,
/// 1195/1111, 183/144: moves the post left out; not analysed move by move), so the paths
/// are compared by their points, not move by move.
#[test]
fn solidworks_cl_files_drill_and_cut_what_their_heidenhain_programs_do() {
    let Some(_) = crate::shared_corpus("cldata::solidworks_cl_files_drill_and_cut_what_their_heidenhain_programs_do") else { return };
    for part in ["2021_basemach", "2022_Dem-target2", "2022_Top-light-cover", "2023_Teflon-gasket"] {
        let cl = corpus_analysis("cldata", &format!("aptpp__parts-{part}.apt"), "cldata");
        let h = corpus_analysis("heidenhain", &format!("aptpp__tests_parts-{part}_11.h"), "heidenhain");
        let (ch, hh) = (holes(&cl), holes(&h));
        assert!(!ch.is_empty(), "{part}");
        assert_eq!(ch.len(), hh.len(), "{part}: holes");
        for (a, b) in ch.iter().zip(&hh) {
            assert!(a.iter().zip(b).all(|(x, y)| (x - y).abs() <= 0.001), "{part}: hole {a:?} against {b:?}");
        }
        let (cc, hc) = (cuts(&cl, false), cuts(&h, false));
        let ends =
            |v: &[(&str, Vec<f64>)]| v.iter().map(|m| [m.1[0], m.1[1], if m.0 == "arc" { m.1[5] } else { m.1[2] }]).collect::<Vec<_>>();
        let (ce, he) = (ends(&cc), ends(&hc));
        let near = |p: &[f64; 3], set: &[[f64; 3]]| set.iter().any(|q| p.iter().zip(q).all(|(a, b)| (a - b).abs() <= 0.001));
        let h_in_cl = he.iter().filter(|p| near(p, &ce)).count();
        let cl_in_h = ce.iter().filter(|p| near(p, &he)).count();
        assert!(hc.len() >= 100, "{part}: {} cuts", hc.len());
        assert_eq!((h_in_cl, cl_in_h), (he.len(), ce.len()), "{part}");
    }
}

/// The issue's other records, each doing what the reference says: `FROM` (a start point, no
/// motion), `GODLTA` (increments, or a distance along the tool axis), `DELAY` (seconds),
/// `OPSTOP`, `STOP` with a message, `INSERT` text, `COOLNT`, `CUTCOM` with a register,
/// `SELECT/TOOL` (a preselection), `MULTAX` and `MACHIN` (nothing to do), `SPINDL/OFF`.
#[test]
fn the_other_records_do_what_the_reference_says() {
    let cl = "PARTNO/RECORDS\nMACHIN/UNCX01,1\nUNITS/MM\nMULTAX\nLOADTL/7\nSELECT/TOOL,8\nSPINDL/2000,RPM,CCLW\nCOOLNT/MIST\n\
              FROM/0,0,100\nRAPID\nGOTO/10,10,20\nFEDRAT/300,MMPM\nGODLTA/5,0,-2\nGODLTA/-3\nDELAY/1.5\nOPSTOP\n\
              INSERT/G65 P9010 (passed through as text)\nCUTCOM/RIGHT,7\nGOTO/30,10,15\nCUTCOM/OFF\nGOTO/40,10,15\n\
              STOP/(TURN THE PART OVER)\nCOOLNT/OFF\nSPINDL/OFF\nFINI\n";
    let d = Registry::shipped().get("cldata").unwrap();
    let mut p = Profile::default();
    p.tools.insert(7, ToolData { diameter: Some(6.0), ..ToolData::default() });
    let a = analyze(cl.as_bytes(), &d, &p);
    assert!(findings(&a).is_empty(), "{:#?}", findings(&a));
    let ops = a.canon.iter().map(|c| &c.op).collect::<Vec<_>>();
    let has = |want: &CanonOp| ops.contains(&want);
    assert!(has(&CanonOp::ChangeTool(7)) && has(&CanonOp::SelectTool(8)), "{ops:#?}");
    assert!(has(&CanonOp::SetSpindleSpeed(2000.0)) && has(&CanonOp::StartSpindleCounterclockwise) && has(&CanonOp::StopSpindleTurning));
    assert!(has(&CanonOp::MistOn) && has(&CanonOp::MistOff));
    assert!(has(&CanonOp::Dwell(1.5)) && has(&CanonOp::OptionalProgramStop) && has(&CanonOp::ProgramStop) && has(&CanonOp::ProgramEnd));
    assert!(has(&CanonOp::Comment("TURN THE PART OVER".into())) || has(&CanonOp::Comment("(TURN THE PART OVER)".into())), "{ops:#?}");
    assert!(has(&CanonOp::Comment("G65 P9010 (passed through as text)".into())), "{ops:#?}");
    assert!(
        has(&CanonOp::Setting(ncplan::canon::Setting::CutterComp(Some(ncplan::canon::CompOn {
            left: false,
            number: Some(7),
            // The offset register's tool in the shop's table: Ø6.
            radius: Some(3.0),
            tip: None
        })))),
        "{ops:#?}"
    );
    // FROM moves nothing; GODLTA goes by increments from the last point, then 3 down the axis.
    let moves = toolpath(&a).into_iter().map(|(k, p)| (k, [p[0], p[1], p[2]])).collect::<Vec<_>>();
    assert_eq!(moves[0], ("traverse", [10.0, 10.0, 20.0]), "{moves:?}");
    assert_eq!(moves[1], ("feed", [15.0, 10.0, 18.0]), "{moves:?}");
    assert_eq!(moves[2], ("feed", [15.0, 10.0, 15.0]), "{moves:?}");
    assert_eq!(a.plan.program.as_deref(), Some("RECORDS"));
}

#[test]
fn a_circle_no_move_ends_is_reported() {
    let d = Registry::shipped().get("cldata").unwrap();
    for cl in [
        "UNITS/MM\nGOTO/0,0,0\nCIRCLE/5,0,0,0,0,1,5\n",
        "UNITS/MM\nGOTO/0,0,0\nCIRCLE/5,0,0,0,0,1,5\nCYCLE/DRILL,FEDTO,5,MMPM,100,RAPTO,2\nGOTO/1,1,0\nCYCLE/OFF\n",
    ] {
        let a = analyze(cl.as_bytes(), &d, &Profile::default());
        assert_eq!(a.diagnostics.iter().filter(|x| x.code == Code::CircleWithoutMove).count(), 1, "{cl}: {:#?}", a.diagnostics);
        assert!(!a.canon.iter().any(|c| matches!(c.op, CanonOp::ArcFeed { .. })), "{cl}");
    }
}

/// The 5-axis pair (NX `Variable_Axis` → Haas UMC-750, B tilting and C rotary): the tool axis
/// the CL file's `GOTO/x,y,z,i,j,k` records keep in the canon is the one the post turned into
/// B and C (B = -acos k, C = atan2(j, i) - 180°, or the other pair -B, C + 180°, within the
/// post's 0.001°), and the tool tip
/// points are the Haas program's X Y Z within a step of its 4 decimals (the post writes them unchanged, for the control's
/// tool-centre-point mode). So the data for a 5-axis output is all there.
#[test]
fn the_tool_axis_of_a_5_axis_cl_file_is_what_its_post_made_b_and_c_of() {
    let Some(_) = crate::shared_corpus("cldata::the_tool_axis_of_a_5_axis_cl_file_is_what_its_post_made_b_and_c_of") else { return };
    let cl = corpus_analysis("cldata", "mech491__APT_Variable_Axis.txt", "cldata");
    let haas = corpus_analysis("haas", "mech491__PostProcessed_Variable_Axis.txt", "haas");
    // The CL feeds with the axis in force at each.
    let mut axis = [0.0, 0.0, 1.0];
    let mut cl_cuts = Vec::new();
    for c in &cl.canon {
        match c.op {
            CanonOp::ToolAxis(a) => axis = a,
            CanonOp::StraightFeed(p) => cl_cuts.push(([p[0], p[1], p[2]], axis)),
            _ => {}
        }
    }
    let haas_cuts = haas.canon.iter().filter_map(|c| if let CanonOp::StraightFeed(p) = c.op { Some(p) } else { None }).collect::<Vec<_>>();
    assert_eq!(cl_cuts.len(), haas_cuts.len());
    assert!(cl_cuts.len() > 300, "{}", cl_cuts.len());
    let mut tilted = 0;
    for (i, ((p, a), h)) in cl_cuts.iter().zip(&haas_cuts).enumerate() {
        for k in 0..3 {
            assert!((p[k] - h[k]).abs() <= 0.00015, "cut {i}: {p:?} against {h:?}");
        }
        // Two B/C pairs give one axis: (B, C) and (-B, C + 180°); the post picks either.
        let mut b = -a[2].clamp(-1.0, 1.0).acos().to_degrees();
        let mut flip = 0.0;
        if (b + h[4]).abs() < (b - h[4]).abs() {
            b = -b;
            flip = 180.0;
        }
        assert!((b - h[4]).abs() <= 0.002, "cut {i}: B {b} against {}", h[4]);
        if b.abs() > 0.01 {
            let c = (a[1].atan2(a[0]).to_degrees() - 180.0 + flip + 540.0).rem_euclid(360.0) - 180.0;
            let d = (c - h[5] + 540.0).rem_euclid(360.0) - 180.0;
            assert!(d.abs() <= 0.002, "cut {i}: C {c} against {}", h[5]);
            tilted += 1;
        }
    }
    assert!(tilted > 300, "{tilted}");
}

/// The plan of a CL file with no tool table: what the file itself says about its tools.
fn read_bare(file: &str) -> Analysis {
    let path = crate::root().join("tests/programs/cldata").join(file);
    analyze(&std::fs::read(&path).unwrap(), &Registry::shipped().get("cldata").unwrap(), &Profile::default())
}

#[test]
fn the_tool_statements_give_the_tool_s_geometry() {
    // NX `TLDATA/MILL,10,0,75,0,0` before `LOAD/TOOL,4`: a D10 end mill, so the pocket its
    // centre line runs around is 60 x 40 with the tool's radius as its corner radius.
    for file in ["pocket_nx.cls", "pocket_catia.aptsource"] {
        let a = read_bare(file);
        assert!(findings(&a).is_empty(), "{file}: {:#?}", findings(&a));
        let t = &a.plan.tools[0];
        assert_eq!((t.number, t.diameter, t.corner_radius), (4, Some(10.0), Some(0.0)), "{file}");
        let f = a.plan.features.iter().find(|f| matches!(f.kind, ncplan::plan::FeatureKind::ClosedPocket { .. })).expect(file);
        let ncplan::plan::FeatureKind::ClosedPocket { rectangle, .. } = &f.kind else { unreachable!() };
        assert_eq!(*rectangle, Some((60.0, 40.0)), "{file}");
        // The same plan as with the shop's tool table, but for where the size came from.
        let mut with_table = read(file, "cldata").plan.features;
        assert!(with_table.iter().all(|f| f.sources.size == ncplan::plan::Source::ToolTable), "{file}");
        assert!(a.plan.features.iter().all(|f| f.sources.size == ncplan::plan::Source::ToolComment), "{file}");
        with_table.iter_mut().for_each(|f| f.sources.size = ncplan::plan::Source::ToolComment);
        assert_eq!(a.plan.features, with_table, "{file}");
    }
}

//! STEP-NC: the signature table generated from the EXPRESS schema, conformance of what
//! ncplan writes, the round trip through Part 21, and an independent parser (steputils).

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

use ncplan::part21::schema::{self, Attr, Entity, Schema, Type};

/// The schema, in the shared material beside the checkout.
fn express() -> std::path::PathBuf {
    crate::shared().join("reference/stepnc/combined_schema_iso14649_bath_v9.exp")
}
const TABLE: &str = "src/part21/iso14649_signatures.tsv";

/// A small EXPRESS reader: entities (supertypes, explicit attributes, ABSTRACT) and defined
/// types (select, enumeration, alias). Nested comments are stripped; names are lower-cased
/// (the schema mixes cases); a declaration met twice keeps the first.
fn read_express(text: &str) -> Schema {
    // Strip (* nested *) and -- comments.
    let b = text.as_bytes();
    let mut clean = String::with_capacity(text.len());
    let (mut i, mut depth) = (0, 0);
    while i < b.len() {
        if b[i..].starts_with(b"(*") {
            depth += 1;
            i += 2;
        } else if depth > 0 && b[i..].starts_with(b"*)") {
            depth -= 1;
            i += 2;
        } else if depth == 0 && b[i..].starts_with(b"--") {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
        } else {
            if depth == 0 {
                clean.push(b[i] as char);
            }
            i += 1;
        }
    }
    let clean = clean.to_ascii_lowercase();
    let mut toks: Vec<String> = Vec::new();
    let cb = clean.as_bytes();
    let mut i = 0;
    while i < cb.len() {
        let c = cb[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c.is_ascii_alphanumeric() || c == b'_' {
            let s = i;
            while i < cb.len() && (cb[i].is_ascii_alphanumeric() || cb[i] == b'_') {
                i += 1;
            }
            toks.push(clean[s..i].to_owned());
        } else if c == b'\'' {
            i += 1;
            while i < cb.len() && cb[i] != b'\'' {
                i += 1;
            }
            i += 1;
            toks.push("'str'".into());
        } else {
            toks.push((c as char).to_string());
            i += 1;
        }
    }
    #[derive(Default)]
    struct Raw {
        is_abstract: bool,
        supers: Vec<String>,
        own: Vec<Attr>,
    }
    let mut raw: BTreeMap<String, Raw> = BTreeMap::new();
    let mut types: BTreeMap<String, Type> = BTreeMap::new();
    let ty_at = |toks: &[String], k: &mut usize| -> String {
        let mut prefix = String::new();
        loop {
            match toks[*k].as_str() {
                "set" | "list" | "bag" | "array" => {
                    prefix.push('[');
                    *k += 1;
                    if toks[*k] == "[" {
                        while toks[*k] != "]" {
                            *k += 1;
                        }
                        *k += 1;
                    }
                    if toks[*k] == "of" {
                        *k += 1;
                    }
                    if toks[*k] == "unique" {
                        *k += 1;
                    }
                }
                other => {
                    let name = other.to_owned();
                    *k += 1;
                    if toks.get(*k).map(String::as_str) == Some("(") && matches!(name.as_str(), "string" | "real" | "binary") {
                        while toks[*k] != ")" {
                            *k += 1;
                        }
                        *k += 1;
                        if toks.get(*k).map(String::as_str) == Some("fixed") {
                            *k += 1;
                        }
                    }
                    return format!("{prefix}{name}");
                }
            }
        }
    };
    let mut k = 0;
    while k < toks.len() {
        match toks[k].as_str() {
            "entity" => {
                let name = toks[k + 1].clone();
                k += 2;
                let mut r = Raw::default();
                while toks[k] != ";" {
                    match toks[k].as_str() {
                        "abstract" => r.is_abstract = true,
                        "subtype" => {
                            k += 2; // subtype of
                            k += 1; // (
                            while toks[k] != ")" {
                                if toks[k] != "," {
                                    r.supers.push(toks[k].clone());
                                }
                                k += 1;
                            }
                        }
                        "(" => {
                            let mut d = 0;
                            loop {
                                match toks[k].as_str() {
                                    "(" => d += 1,
                                    ")" => d -= 1,
                                    _ => {}
                                }
                                if d == 0 {
                                    break;
                                }
                                k += 1;
                            }
                        }
                        _ => {}
                    }
                    k += 1;
                }
                k += 1;
                // Explicit attributes until a clause or the end.
                while !matches!(toks[k].as_str(), "derive" | "inverse" | "unique" | "where" | "end_entity") {
                    if toks[k] == "self" {
                        while toks[k] != ";" {
                            k += 1;
                        }
                        k += 1;
                        continue;
                    }
                    let mut names = Vec::new();
                    while toks[k] != ":" {
                        if toks[k] != "," {
                            names.push(toks[k].clone());
                        }
                        k += 1;
                    }
                    k += 1;
                    let optional = toks[k] == "optional";
                    if optional {
                        k += 1;
                    }
                    let ty = ty_at(&toks, &mut k);
                    while toks[k] != ";" {
                        k += 1;
                    }
                    k += 1;
                    for n in names {
                        r.own.push(Attr { name: n, optional, ty: ty.clone() });
                    }
                }
                while toks[k] != "end_entity" {
                    k += 1;
                }
                raw.entry(name).or_insert(r);
            }
            "type" if toks.get(k + 2).map(String::as_str) == Some("=") => {
                let name = toks[k + 1].clone();
                k += 3;
                let t = match toks[k].as_str() {
                    "select" | "enumeration" => {
                        let select = toks[k] == "select";
                        while toks[k] != "(" {
                            k += 1;
                        }
                        let mut members = Vec::new();
                        while toks[k] != ")" {
                            if toks[k] != "," && toks[k] != "(" {
                                members.push(toks[k].clone());
                            }
                            k += 1;
                        }
                        if select { Type::Select(members) } else { Type::Enumeration(members) }
                    }
                    _ => Type::Alias(ty_at(&toks, &mut k)),
                };
                types.entry(name).or_insert(t);
                while toks[k] != "end_type" {
                    k += 1;
                }
            }
            _ => {}
        }
        k += 1;
    }
    fn flatten(name: &str, raw: &BTreeMap<String, Raw>, seen: &mut BTreeSet<String>, out: &mut Vec<Attr>) {
        if !seen.insert(name.to_owned()) {
            return;
        }
        if let Some(r) = raw.get(name) {
            for s in &r.supers {
                flatten(s, raw, seen, out);
            }
            out.extend(r.own.iter().cloned());
        }
    }
    let mut s = Schema { types, ..Schema::default() };
    for (name, r) in &raw {
        let mut attrs = Vec::new();
        flatten(name, &raw, &mut BTreeSet::new(), &mut attrs);
        s.entities.insert(name.clone(), Entity { is_abstract: r.is_abstract, supertypes: r.supers.clone(), attrs });
    }
    s
}

#[test]
fn signatures_are_generated_from_express() {
    let path = express();
    let Ok(text) = std::fs::read_to_string(&path) else {
        assert!(
            std::env::var_os("NCPLAN_REQUIRE_SHARED").is_none(),
            "NCPLAN_REQUIRE_SHARED is set but {} is absent: the signature table is generated from it",
            path.display()
        );
        crate::skip(
            "stepnc::signatures_are_generated_from_express",
            &format!("{} is absent (clone the shared material beside the checkout to run it)", path.display()),
        );
        return;
    };
    let generated = read_express(&text).to_tsv("combined_schema_iso14649_bath_v9.exp");
    if std::env::var_os("UPDATE_EXPECT").is_some() {
        std::fs::write(TABLE, &generated).unwrap();
    }
    let committed = std::fs::read_to_string(TABLE).unwrap();
    assert!(committed == generated, "{TABLE} is stale; run UPDATE_EXPECT=1 cargo test --test it stepnc");
    // The counts the reference notes give for the entities ncplan writes.
    let s = schema::iso14649();
    for (entity, n) in [
        ("project", 6),
        ("workplan", 5),
        ("workpiece", 7),
        ("setup", 4),
        ("machining_workingstep", 5),
        ("planar_face", 9),
        ("round_hole", 8),
        ("closed_pocket", 11),
        ("open_pocket", 12),
        ("slot", 8),
        ("step", 8),
        ("general_outside_profile", 7),
        ("freeform_operation", 12),
        ("plane_finish_milling", 14),
        ("bottom_and_side_rough_milling", 16),
        ("drilling", 14),
        ("reaming", 17),
        ("multistep_drilling", 18),
        ("cutter_location_trajectory", 9),
        ("milling_cutting_tool", 6),
        ("milling_tool_dimension", 7),
        ("milling_technology", 9),
        ("milling_machine_functions", 10),
        ("bidirectional", 5),
        ("cartesian_point", 2),
        ("axis2_placement_3d", 4),
        ("trimmed_curve", 6),
    ] {
        assert_eq!(s.entities[entity].attrs.len(), n, "{entity}");
    }
    assert!(s.entities["machining_feature"].is_abstract);
    assert!(s.is_a("closed_pocket", "manufacturing_feature"));
}

#[test]
fn the_checker_catches_what_it_should() {
    use ncplan::part21::{Header, Stream, Value};
    let s = schema::iso14649();
    let header = Header { description: vec![], name: String::new(), timestamp: String::new(), system: String::new(), schemas: vec![] };
    let mut b = Stream::new(Vec::new(), &header);
    let p = b.add("CARTESIAN_POINT", vec![Value::str(""), Value::List(vec![Value::Real(0.0)])]);
    let bad_count = b.add("DIRECTION", vec![Value::str("")]);
    let bad_null = b.add("AXIS2_PLACEMENT_3D", vec![Value::str(""), Value::Null, Value::Null, Value::Null]);
    let bad_ref = b.add("PLANE", vec![Value::str(""), p.clone()]);
    let bad_enum = b.add(
        "MILLING_TECHNOLOGY",
        vec![
            Value::Null,
            Value::Enum("XYZ".into()),
            Value::Null,
            Value::Real(1.0),
            Value::Null,
            Value::bool(false),
            Value::bool(false),
            Value::bool(false),
            Value::Null,
        ],
    );
    b.add("NO_SUCH_ENTITY", vec![p, bad_count, bad_null, bad_ref, bad_enum]);
    let x = ncplan::part21::parse(&String::from_utf8(b.finish().unwrap()).unwrap()).unwrap();
    let found = s.check(&x).join("\n");
    for want in [
        "NO_SUCH_ENTITY: unknown entity",
        "DIRECTION: 1 attributes",
        "AXIS2_PLACEMENT_3D.location: `$` in a mandatory",
        "PLANE.position: #",
        "MILLING_TECHNOLOGY.feedrate_reference: expected one of",
    ] {
        assert!(found.contains(want), "{want} not in:\n{found}");
    }
}

/// Writes a program's plan as CC1 and CC2 Part 21 files into `dir`.
fn export(program: &str, dialect: &str, dir: &Path) -> (String, String) {
    let path = dir.join("p.nc");
    std::fs::write(&path, program).unwrap();
    let mut files = Vec::new();
    for cc in ["--cc1", "--cc2"] {
        let out = dir.join(format!("p{cc}.stp"));
        let r = std::process::Command::new(env!("CARGO_BIN_EXE_ncplan"))
            .args(["stepnc", path.to_str().unwrap(), "-d", dialect, cc, "--timestamp", "2026-01-01T00:00:00", "-o", out.to_str().unwrap()])
            .output()
            .unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        files.push(std::fs::read_to_string(out).unwrap());
    }
    (files.remove(0), files.remove(0))
}

/// The face-milling example of the G-code-to-STEP-NC paper, blocks separated by `/`.
const PAPER_FACE: &str = "G54 G90 G21 G40 G49 M5 M9 / T1 M6 / G43 H1 / M8 S720 M3 / G0 X91.90 Y-13.50 Z100.00 / Z15.00 / G1 Z0.00 F240.00 / Y133.50 / X74.80 / Y-13.50 / X57.70 / Y133.50 / X40.60 / Y-13.50 / X23.50 / Y133.50 / X6.40 / Y-13.50 / G0 Z15.00 / G49 M9 M5 / M30";

fn paper_face_program() -> String {
    PAPER_FACE.split(" / ").map(|b| format!("{b}\n")).collect()
}

#[test]
fn paper_face_milling_example_gives_one_bidirectional_planar_face() {
    let dir = tempfile::tempdir().unwrap();
    // T1 end mill 18 mm with length offset 50, as the paper states, from a tool table.
    let config = dir.path().join("ncplan.toml");
    std::fs::write(&config, "[database]\npath = \"db.sqlite\"\n[[tool]]\nnumber = 1\ndiameter = 18.0\nlength = 50.0\nkind = \"end_mill\"\nname = \"END MILL D18\"\n").unwrap();
    let prog = dir.path().join("face.nc");
    std::fs::write(&prog, paper_face_program()).unwrap();
    let run = |args: &[&str]| {
        let r = std::process::Command::new(env!("CARGO_BIN_EXE_ncplan")).args(args).output().unwrap();
        assert!(r.status.success(), "{}", String::from_utf8_lossy(&r.stderr));
        String::from_utf8(r.stdout).unwrap()
    };
    let json = run(&["plan", "--config", config.to_str().unwrap(), "-d", "fanuc", prog.to_str().unwrap(), "--format", "json"]);
    let plan: ncplan::plan::ProcessPlan = serde_json::from_str(&json).unwrap();
    assert_eq!(plan.workingsteps.len(), 1);
    let ws = &plan.workingsteps[0];
    assert_eq!(ws.operation, ncplan::plan::Operation::PlaneFinishMilling);
    assert_eq!(ws.strategy.as_ref().unwrap().kind, ncplan::plan::StrategyKind::Bidirectional);
    assert_eq!(plan.features.len(), 1);
    let ncplan::plan::FeatureKind::PlanarFace { length, width, direction } = plan.features[0].kind else {
        panic!("{:?}", plan.features[0])
    };
    // Passes along Y from -13.5 to 133.5 at X 91.9 … 6.4, swept by a Ø18 tool.
    assert_eq!((direction, length, width), ([0.0, 1.0, 0.0], 165.0, 103.5));
    assert_eq!(plan.tools[0].diameter, Some(18.0));
    assert_eq!(plan.tools[0].length_offset, Some(50.0));
    assert_eq!(ws.security_plane, 100.0);
    assert_eq!(ws.radial_depth, Some(17.1));
    for cc in ["--cc1", "--cc2"] {
        let out = dir.path().join(format!("face{cc}.stp"));
        run(&[
            "stepnc",
            "--config",
            config.to_str().unwrap(),
            "-d",
            "fanuc",
            prog.to_str().unwrap(),
            cc,
            "--timestamp",
            "2026-01-01T00:00:00",
            "-o",
            out.to_str().unwrap(),
        ]);
        let text = std::fs::read_to_string(&out).unwrap();
        let x = ncplan::part21::parse(&text).unwrap();
        assert_eq!(schema::iso14649().check(&x), Vec::<String>::new(), "{cc}");
        assert_eq!(x.ids_of("MACHINING_WORKINGSTEP").count(), 1, "{cc}");
        let feature = if cc == "--cc1" { "TOOLPATH_FEATURE" } else { "PLANAR_FACE" };
        assert_eq!(x.ids_of(feature).count(), 1, "{cc}");
        if cc == "--cc2" {
            assert_eq!(x.ids_of("BIDIRECTIONAL").count(), 1);
            assert_eq!(x.ids_of("PLANE_FINISH_MILLING").count(), 1);
            // 240 mm/min is 0.004 m/s; 720 1/min clockwise is -12 rev/s.
            assert!(text.contains("MILLING_TECHNOLOGY(0.004,.TCP.,$,-12.,"), "{text}");
        }
    }
}

#[test]
fn exports_are_deterministic_and_conform() {
    let dir = tempfile::tempdir().unwrap();
    for (name, program) in crate::plan::PROGRAMS {
        let (cc1, cc2) = export(program, "fanuc", dir.path());
        let (again1, again2) = export(program, "fanuc", dir.path());
        assert_eq!((&cc1, &cc2), (&again1, &again2), "{name}");
        for (cc, text) in [("CC1", &cc1), ("CC2", &cc2)] {
            let x = ncplan::part21::parse(text).unwrap_or_else(|e| panic!("{name} {cc}: {e}"));
            assert_eq!(schema::iso14649().check(&x), Vec::<String>::new(), "{name} {cc}");
            assert!(text.contains("FILE_SCHEMA(('MACHINING_SCHEMA','MILLING_SCHEMA'));"));
        }
    }
}

#[test]
fn plans_round_trip_through_part21() {
    use ncplan::{dialect, interp::Profile, part21::stepnc, pipeline};
    let reg = dialect::Registry::shipped();
    let fanuc = reg.get("fanuc").unwrap();
    for (name, program) in crate::plan::PROGRAMS {
        let a = pipeline::analyze(program.as_bytes(), &fanuc, &Profile::default());
        for cc in [stepnc::Class::Cc2, stepnc::Class::Cc1] {
            let (text, _) = stepnc::to_string(&a.plan, cc, "2026-01-01T00:00:00");
            let back = stepnc::read(&ncplan::part21::parse(&text).unwrap()).unwrap_or_else(|e| panic!("{name}: {e}"));
            let expected = if cc == stepnc::Class::Cc2 { a.plan.clone() } else { stepnc::toolpaths_only(&a.plan) };
            assert_eq!(back, expected, "{name} {cc:?}");
            // And the second writing is the same text.
            let (text2, _) = stepnc::to_string(&back, cc, "2026-01-01T00:00:00");
            assert_eq!(text2, text, "{name} {cc:?}");
        }
    }
}

/// steputils (PyPI, an independent Part 21 parser) reads every file ncplan writes. `.ci/run`
/// installs it in a virtual environment and sets `NCPLAN_STEPUTILS_PYTHON`; without it the
/// test says so and passes only when `NCPLAN_REQUIRE_STEPUTILS` is unset.
#[test]
fn steputils_reads_the_exports() {
    let python = std::env::var("NCPLAN_STEPUTILS_PYTHON").ok().or_else(|| {
        let local = Path::new("target/venv/bin/python");
        local.exists().then(|| local.to_string_lossy().into_owned())
    });
    let Some(python) = python else {
        assert!(
            std::env::var_os("NCPLAN_REQUIRE_STEPUTILS").is_none(),
            "NCPLAN_REQUIRE_STEPUTILS is set but no steputils python was found"
        );
        crate::skip(
            "stepnc::steputils_reads_the_exports",
            "steputils is not installed (run .ci/run, or python3 -m venv target/venv && target/venv/bin/pip install steputils)",
        );
        return;
    };
    let dir = tempfile::tempdir().unwrap();
    let mut files = Vec::new();
    for (name, program) in crate::plan::PROGRAMS.iter().chain([&("paper_face", PAPER_FACE)]) {
        let program = if *name == "paper_face" { paper_face_program() } else { program.to_string() };
        let (cc1, cc2) = export(&program, "fanuc", dir.path());
        for (cc, text) in [("cc1", cc1), ("cc2", cc2)] {
            let f = dir.path().join(format!("{name}_{cc}.stp"));
            std::fs::write(&f, text).unwrap();
            files.push(f);
        }
    }
    let script = "import sys\nfrom steputils import p21\nfor f in sys.argv[1:]:\n    d = p21.readfile(f)\n    n = sum(len(s) for s in d.data)\n    print(f, n)\n";
    let out = std::process::Command::new(python).arg("-c").arg(script).args(&files).output().unwrap();
    assert!(out.status.success(), "steputils rejected a file:\n{}", String::from_utf8_lossy(&out.stderr));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(stdout.lines().count(), files.len(), "{stdout}");
    assert!(stdout.lines().all(|l| l.split(' ').nth(1).and_then(|n| n.parse::<usize>().ok()).is_some_and(|n| n > 10)), "{stdout}");
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 256, ..proptest::prelude::ProptestConfig::default() })]

    /// A damaged exchange file gets a parse error or a read error, never a panic.
    #[test]
    fn damaged_exports_never_panic_the_reader(
        program in 0..crate::plan::PROGRAMS.len(),
        cc2 in proptest::prelude::any::<bool>(),
        edits in proptest::collection::vec((0usize..1_000_000, 0u8..128), 1..6),
    ) {
        use ncplan::{dialect, interp::Profile, part21::stepnc, pipeline};
        let fanuc = dialect::Registry::shipped().get("fanuc").unwrap();
        let a = pipeline::analyze(crate::plan::PROGRAMS[program].1.as_bytes(), &fanuc, &Profile::default());
        let class = if cc2 { stepnc::Class::Cc2 } else { stepnc::Class::Cc1 };
        let mut bytes = stepnc::to_string(&a.plan, class, "t").0.into_bytes();
        for (at, b) in edits {
            let i = at % bytes.len();
            bytes[i] = b;
        }
        if let Ok(x) = ncplan::part21::parse(&String::from_utf8_lossy(&bytes)) {
            let _ = stepnc::read(&x);
            let _ = schema::iso14649().check(&x);
        }
    }
}

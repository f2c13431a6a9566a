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
use ncplan::plan::{Feature, FeatureKind, ProcessPlan, Turned, Workingstep};

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
    // The technology of any workingstep, a mill-turn's milling and drilling ones too.
    match key {
        "cutting_speed" => return ws.technology.surface_speed,
        "spindle_speed" => return Some(ws.technology.spindle_speed),
        _ => {}
    }
    let t = ws.turning.as_deref()?;
    let i = t.intent.as_ref();
    match key {
        "allowance_x" => i?.allowance_x,
        "allowance_z" => i?.allowance_z,
        "depth_of_cut" => i?.depth_of_cut,
        "thread_height" => i?.thread_depth,
        "pitch" => t.pitch.or(i.and_then(|i| i.pitch)),
        "feed_per_rev" => t.feed_per_rev,
        "clamp" => t.spindle_limit,
        "d_min" => t.diameter.map(|d| d[0]),
        "d_max" => t.diameter.map(|d| d[1]),
        _ => panic!("unknown workingstep size `{key}`"),
    }
}

/// The sizes of a feature by the sidecar's names.
fn feature_size(f: &Feature, key: &str) -> Option<f64> {
    let axis = f.axis.unwrap_or([0.0, 0.0, 1.0]);
    match key {
        "z" => return Some(f.placement[2]),
        "depth" => return Some(f.depth),
        "axis_x" => return Some(axis[0]),
        "axis_y" => return Some(axis[1]),
        "axis_z" => return Some(axis[2]),
        _ => {}
    }
    match &f.kind {
        FeatureKind::Turned(t) => match (t, key) {
            (Turned::RevolvedFlat { outer, .. }, "outer") => Some(*outer),
            (Turned::RevolvedFlat { inner, .. }, "inner") => Some(*inner),
            (Turned::Diameter { diameter, .. }, "diameter") => Some(*diameter),
            (Turned::Diameter { length, .. }, "length") => Some(*length),
            (Turned::RevolvedRound { radius, .. }, "radius") => Some(*radius),
            (Turned::RevolvedRound { diameter, .. }, "diameter") => Some(*diameter),
            (Turned::Groove { diameter, .. }, "diameter") => Some(*diameter),
            (Turned::Groove { width, .. }, "width") => *width,
            (Turned::FaceGroove { outer, .. }, "outer") => Some(*outer),
            (Turned::FaceGroove { inner, .. }, "inner") => Some(*inner),
            (Turned::FaceGroove { .. }, "width") => t.face_groove_width(),
            (Turned::Thread { diameter, .. }, "diameter") => *diameter,
            (Turned::Thread { root, .. }, "root") => Some(*root),
            (Turned::Thread { pitch, .. }, "pitch") => Some(*pitch),
            (Turned::Thread { length, .. }, "length") => Some(*length),
            _ => None,
        },
        FeatureKind::RoundHole { diameter, .. } if key == "diameter" => *diameter,
        // Holes of one pattern: a mill-turn's face holes at several C angles.
        FeatureKind::RoundHole { positions, .. } if key == "holes" => Some(positions.len() as f64),
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
            let found = plan.features.iter().any(|f| f.kind.label() == e.words && matches(&e.sizes, |k| feature_size(f, k)));
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
    // As `ncplan plan FILE` reads it: the programs it calls (a contour `CYCLE62` names, a
    // subprogram) from beside the file.
    let profile = ncplan::config::DirPrograms::beside(&Profile::default(), path, 1 << 24);
    pipeline::analyze(&bytes, &d, &profile).plan
}

#[test]
fn lathe_suite() {
    let (listed, _, _, misses) = score_folder("lathe");
    assert!(misses.is_empty(), "{} misses among {listed} listed workingsteps and features:\n{}", misses.len(), misses.join("\n"));
    let programs =
        std::fs::read_dir(dir()).unwrap().filter(|e| e.as_ref().unwrap().path().extension().is_some_and(|e| e == "expect")).count();
    assert!(programs >= 30, "the lathe suite has {programs} programs");
}

/// Real lathe and mill-turn programs of the shared corpus (`../shared/corpus`, its MANIFEST
/// gives their sources and licences), held back from building: each sidecar in
/// `tests/programs/lathe_heldout/` names its program (`corpus PATH`) and lists, written by
/// reading the program before ncplan ran on it, the workingsteps and features a turner names.
/// Scored once on 5 December 2026: 24 of the 92 listed recovered, 4 milling features (a
/// LinuxCNC profile in radius mode, read as milling). No longer held out: issue 40 part 1 was
/// built on these programs, after which 58 of the 92 are recovered (4 milling features: the
/// LinuxCNC pawn in radius mode is still read as milling, its G70-G72 giving no turning marker,
/// since one breaks equal round trips). A program whose every move lies in the ZX plane through
/// the axis now turns (and one known to turn anywhere turns throughout): 59 of 92, no milling
/// feature. After the explicit-pass rules of branch lathe3 (6 December 2026: inside told by the
/// pull-off, stepped facing, operation comments, grooves profiled from both sides, Okuma `TG=`):
/// 67 of 92. After branch lathe5 (6 December 2026: a grooving tool the program names cuts
/// grooves): 68 of 92. After branch lathe8 (6 December 2026: back-to-back LinuxCNC `G70`-`G72`
/// parted on their passes, a contour cycle over a face is facing): 73 of 92. After branch
/// lathe11 (6 December 2026: whole numbers mostly written without a point read as calculator
/// input, the Fanuc 0T bore program) and branch lathe10 (a thread runs through its tapered
/// run-out): 76 of 92; 77 on branch lathe12 (6 December 2026: passes left towards the axis
/// work inside; measured 77 before it too). The test keeps that figure from falling and no
/// milling feature.
#[test]
fn lathe_held_out_programs() {
    /// Listed workingsteps and features recovered, no longer held out.
    const HELD_OUT_SCORE: usize = 77;
    let (programs, listed, found, milling, misses) = score_corpus_sidecars();
    assert!(programs >= 8, "{programs} held-out programs");
    assert_eq!(milling, 0, "milling features on lathe programs:\n{}", misses.join("\n"));
    assert!(
        found >= HELD_OUT_SCORE,
        "held out: {found} of {listed} recovered ({milling} milling features on lathe programs), fewer than the {HELD_OUT_SCORE} first scored:\n{}",
        misses.join("\n")
    );
}

/// Scores the sidecars of `tests/programs/lathe_heldout/` on the corpus programs they name:
/// (programs, listed, found, milling features on pure lathe programs, the misses in words).
fn score_corpus_sidecars() -> (usize, usize, usize, usize, Vec<String>) {
    let corpus = Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/corpus");
    let held = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/programs/lathe_heldout");
    let mut sidecars: Vec<PathBuf> = std::fs::read_dir(&held).unwrap().map(|e| e.unwrap().path()).collect();
    sidecars.sort();
    let (mut listed, mut misses) = (0, Vec::new());
    for p in &sidecars {
        let expect = std::fs::read_to_string(p).unwrap();
        let field = |key: &str| {
            expect.lines().find_map(|l| l.strip_prefix(key)).map(str::trim).unwrap_or_else(|| panic!("{} has no {key}", p.display()))
        };
        let program = corpus.join(field("corpus "));
        let plan = plan_of(&program, field("dialect "));
        let name = p.file_stem().unwrap().to_string_lossy().into_owned();
        listed += expect.lines().filter(|l| l.starts_with("ws ") || l.starts_with("feature ")).count();
        misses.extend(score(&name, &plan, &expect));
    }
    let milling = misses.iter().filter(|m| m.contains("milling feature")).count();
    (sidecars.len(), listed, listed - (misses.len() - milling), milling, misses)
}

/// Scores the programs of a folder of real lathe programs (each `NAME.<ext>` beside its sidecar
/// `NAME.expect`, `SOURCES.tsv` giving repository, path, commit and licence): (listed, found,
/// milling features on pure lathe programs, the misses in words).
fn score_folder(folder: &str) -> (usize, usize, usize, Vec<String>) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/programs").join(folder);
    let mut programs: Vec<PathBuf> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e != "expect" && e != "tsv" && e != "sh" && e != "md"))
        .collect();
    programs.sort();
    let (mut listed, mut misses) = (0, Vec::new());
    for p in &programs {
        let expect = std::fs::read_to_string(p.with_extension("expect")).unwrap_or_else(|_| panic!("{} has no sidecar", p.display()));
        // A contour program (the blocks a `CYCLE62` names, no tool, spindle or feed of its own)
        // is read through the main program beside it, not scored alone.
        if expect.lines().any(|l| l.trim() == "contour-only") {
            continue;
        }
        let dialect = expect.lines().find_map(|l| l.strip_prefix("dialect ")).expect("a dialect line").trim();
        let plan = plan_of(p, dialect);
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        listed += expect.lines().filter(|l| l.starts_with("ws ") || l.starts_with("feature ")).count();
        misses.extend(score(&name, &plan, &expect));
    }
    let milling = misses.iter().filter(|m| m.contains("milling feature")).count();
    (listed, listed - (misses.len() - milling), milling, misses)
}

/// Real lathe programs gathered for issue 40 part 1 to build on (`tests/programs/lathe_real/`: NX
/// post samples for Uniturn, Daewoo Puma, Mori Seiki AL-22 and NL1500 lathes), their sidecars
/// written by reading the programs before ncplan ran on them. 37 of 58 after issue 40 part 1;
/// 40 of 58 after branch lathe3 (6 December 2026). The test keeps the figure from falling and no
/// milling feature on a pure lathe program.
#[test]
fn lathe_real_build_programs() {
    /// Listed workingsteps and features recovered on the build half.
    const BUILD_SCORE: usize = 40;
    let (listed, found, milling, misses) = score_folder("lathe_real");
    assert_eq!(milling, 0, "milling features on lathe programs:\n{}", misses.join("\n"));
    assert!(found >= BUILD_SCORE, "build half: {found} of {listed} recovered, fewer than {BUILD_SCORE}:\n{}", misses.join("\n"));
}

/// The held-back half of the real lathe programs gathered for issue 40 part 1
/// (`tests/programs/lathe_real_heldout/`: LinuxCNC's lathe samples, GCodeWorkShop's Okuma and
/// Fanuc shop programs; split from the build half by repository), their sidecars written before
/// ncplan ran on them and never used to build. Measured once on 6 December 2026, after the
/// build: 37 of the 84 listed recovered, 2 milling features (on LinuxCNC's g76.ngc). The
/// turning marker of LinuxCNC's G70-G72 was then taken out (it made equal round trips of the
/// corpus unequal), which leaves 21 of 84 and 46 milling features (LinuxCNC's radius-mode
/// profile programs read as milling again). Re-scored (no longer blind) after a program known
/// to turn anywhere was made to turn throughout, and one whose every move lies in the ZX plane
/// through the axis to turn (branch lathe2): 28 of 84, no milling feature. The 46 had two
/// causes: LinuxCNC's G70-G72 programs in radius mode (g70_71_demo, g7x_face_boring,
/// g7x_quadrants: 44) told nothing a lathe's, and g76.ngc's facing and ball-end passes (2) were
/// cut before its G76 told it. No longer held back: branch lathe3 built on it (6 December 2026:
/// a face stepped down is facing, a tool that faces then turns parts its workingsteps, Okuma's
/// `TG=` names the tool, a pass from the axis after passes that never reached it is the
/// finish, and where no workingstep faces a shaft whose program zero is at its far end keeps
/// its diameters): 45 of 84. After branch lathe8 (6 December 2026: LinuxCNC's `G70`-`G72`
/// one after another parted on their passes, the front face only where a face reaches the
/// axis): 63 of 84; 64 after branch lathe10 (a thread runs through its tapered run-out); 65
/// after branch lathe12 (passes left towards the axis work inside: gcws_flange); 66 after branch
/// lathe15 (a pass pulled in off its wall by the rapid out along +Z bores: gcws_flange's rough
/// ID). The test keeps that figure from falling and no milling feature.
#[test]
fn lathe_real_held_out_programs() {
    /// Listed workingsteps and features recovered on this half, re-scored (built on).
    const HELD_OUT_SCORE: usize = 66;
    let (listed, found, milling, misses) = score_folder("lathe_real_heldout");
    assert_eq!(milling, 0, "milling features on lathe programs:\n{}", misses.join("\n"));
    assert!(
        found >= HELD_OUT_SCORE,
        "held out: {found} of {listed} recovered ({milling} milling features on lathe programs), fewer than {HELD_OUT_SCORE}:\n{}",
        misses.join("\n")
    );
}

/// A second set of real programs, gathered for branch lathe3 from repositories neither the corpus,
/// the earlier lathe folders nor the issue-43 sweep used, split by repository; their sidecars
/// written by reading each program (and, for LinuxCNC, rs274's moves) before ncplan ran on it.
/// The build part (`tests/programs/lathe_new/`: the LatheEasyStep conversational generator's
/// LinuxCNC programs, GPL-3.0): 25 of 50 when first scored, 42 of 50 after the rules were built
/// on it (6 December 2026); 45 of 50 after branch lathe5 (6 December 2026: `G17 G83 X0` drills on
/// the lathe's axis, a grooving tool named in an operation header cuts grooves); 47 of 50 after
/// branch lathe11 (a face behind a first one is facing, not parting); 48 of 50 on branch lathe15
/// (no rule changed for it: les_einstich's sidecar now names its one pass to the groove's depth
/// grooving finish, by `plan::turning`'s grooving convention). The test keeps the figure from
/// falling and no milling feature.
#[test]
fn lathe_new_build_programs() {
    /// Listed workingsteps and features recovered on the build part.
    const BUILD_SCORE: usize = 48;
    let (listed, found, milling, misses) = score_folder("lathe_new");
    assert_eq!(milling, 0, "milling features on lathe programs:\n{}", misses.join("\n"));
    assert!(found >= BUILD_SCORE, "build part: {found} of {listed} recovered, fewer than {BUILD_SCORE}:\n{}", misses.join("\n"));
}

/// The held-back part of that set (`tests/programs/lathe_new_heldout/`: Haas shop programs of
/// enier290188/cnc, whose repository states no licence: only the sidecars are committed,
/// `extract.sh` writes the programs from a mirror). Never used to build; measured once, at the
/// end of branch lathe3 (6 December 2026): 34 of the 46 listed recovered, no milling feature.
/// The misses (not looked into, the part stays unseen): the face and diameters of lathe_hp_2,
/// valve and weld_pin, both facing workingsteps of nims_1002 (a G71/G70 pair on a face-only
/// contour), valve's undercut as a groove. No longer held back: branch lathe5 read its misses
/// among the others' (6 December 2026; still 34 of 46); branch lathe8 built on it (6 December
/// 2026: a G71/G70 pair over a face is facing, the front face only where a face reaches the
/// axis): 45 of 46; 46 after branch lathe10 (valve's undercut a groove). Where the
/// programs are not extracted the test says so and checks nothing.
#[test]
fn lathe_new_held_out_programs() {
    /// Listed workingsteps and features recovered on the held-back part, measured once.
    const HELD_OUT_SCORE: usize = 46;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/programs/lathe_new_heldout");
    let extracted = std::fs::read_dir(&dir).unwrap().filter(|e| e.as_ref().unwrap().path().extension().is_some_and(|e| e == "nc")).count();
    if extracted == 0 {
        crate::skip(
            "lathe::lathe_new_held_out_programs",
            "the held-back programs are not extracted (tests/programs/lathe_new_heldout/extract.sh)",
        );
        return;
    }
    let (listed, found, milling, misses) = score_folder("lathe_new_heldout");
    assert_eq!(milling, 0, "milling features on lathe programs:\n{}", misses.join("\n"));
    assert!(found >= HELD_OUT_SCORE, "held out: {found} of {listed} recovered, fewer than {HELD_OUT_SCORE}:\n{}", misses.join("\n"));
}

/// The change rows of an edit of a lathe program (every `from` made `to`), one per line with
/// the planner's sentence.
fn lathe_edit(program: &str, from: &str, to: &str) -> String {
    let a = std::fs::read_to_string(dir().join(program)).unwrap();
    assert!(a.contains(from), "{from:?} is in {program}");
    let b = a.replace(from, to);
    let expect = std::fs::read_to_string(dir().join(program).with_extension("expect")).unwrap();
    let dialect = expect.lines().find_map(|l| l.strip_prefix("dialect ")).unwrap().trim();
    let d = Registry::shipped().get(dialect).unwrap();
    let profile = Profile::default();
    let (pa, pb) = (pipeline::analyze(a.as_bytes(), &d, &profile), pipeline::analyze(b.as_bytes(), &d, &profile));
    let (x, y) = (
        ncplan::diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d },
        ncplan::diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d },
    );
    let got = ncplan::diff::compare(x, y);
    let missing = ncplan::diff::unaccounted(x, y, &got);
    assert!(missing.is_empty(), "differing statements no change names: {missing:?}");
    let mut s = String::new();
    for c in &got {
        s.push_str(&format!("{} | {} | {} | {}\n  {}\n", c.kind.as_str(), c.field, c.before, c.after, c.phrase()));
    }
    s
}

/// An edit of a setting (the clamp, an allowance, the depth of cut) never adds or removes a
/// workingstep or a feature.
fn no_structure_change(rows: &str) {
    for word in ["workingstep_added", "workingstep_removed", "hole_added", "hole_removed", "hole_moved", "toolpath_changed"] {
        assert!(!rows.contains(word), "{word} in\n{rows}");
    }
}

#[test]
fn lathe_edits_in_a_turner_s_terms() {
    use expect_test::expect;
    let clamp = lathe_edit("fanuc_g71_shaft.nc", "G50 S2500", "G50 S1800");
    no_structure_change(&clamp);
    expect![[r#"
        spindle_speed_changed | spindle_clamp | 2500 /min | 1800 /min
          spindle clamp changed from 2500 /min to 1800 /min at line 7
    "#]]
    .assert_eq(&clamp);
    let allowance = lathe_edit("fanuc_g71_shaft.nc", "U0.4 W0.1", "U0.6 W0.2");
    no_structure_change(&allowance);
    expect![[r#"
        allowance_changed | finishing_allowance | U0.4 W0.1 | U0.6 W0.2
          finishing allowance changed from U0.4 W0.1 to U0.6 W0.2 at line 11
    "#]]
    .assert_eq(&allowance);
    let depth = lathe_edit("fanuc_g71_shaft.nc", "G71 U2. R0.5", "G71 U1.5 R0.5");
    no_structure_change(&depth);
    expect![[r#"
        axial_depth_changed | depth_of_cut | 2 | 1.5
          depth of cut changed from 2 to 1.5 at line 10
    "#]]
    .assert_eq(&depth);
    let pitch = lathe_edit("fanuc_g71_shaft.nc", "F1.5", "F1.25");
    expect![[r#"
        thread_pitch_changed | thread_pitch | 1.5 | 1.25
          thread pitch changed from 1.5 to 1.25 at line 32
    "#]]
    .assert_eq(&pitch);
    let speed = lathe_edit("fanuc_g71_shaft.nc", "G96 S200", "G96 S180");
    no_structure_change(&speed);
    expect![[r#"
        spindle_speed_changed | cutting_speed | 200 m/min | 180 m/min
          cutting speed changed from 200 m/min to 180 m/min at line 8
    "#]]
    .assert_eq(&speed);
    let feed = lathe_edit("fanuc_g71_shaft.nc", "F0.25", "F0.2");
    no_structure_change(&feed);
    expect![[r#"
        feed_changed | feed | F0.25 mm/rev | F0.2 mm/rev
          feed changed from F0.25 mm/rev to F0.2 mm/rev at line 11
    "#]]
    .assert_eq(&feed);
    let width = lathe_edit("fanuc_g75_groove.nc", "Z-20.", "Z-21.");
    expect![[r#"
        feature_changed | groove_width | 8 mm | 9 mm
          groove width changed from 8 mm to 9 mm at line 8
    "#]]
    .assert_eq(&width);
    // Every pass of a thread written as G32 moves, its lead K1.25 made K1.5.
    let explicit_pitch = lathe_edit("mazak_k_thread.nc", "K1.25", "K1.5");
    expect![[r#"
        thread_pitch_changed | thread_pitch | 1.25 | 1.5
          thread pitch changed from 1.25 to 1.5 at lines 8, 12, 16 and 1 more
    "#]]
    .assert_eq(&explicit_pitch);
}

/// Every lathe program's plan through STEP-NC and back: CC2 with the ISO 14649-121
/// operations, technology and tools and the ISO 14649-12 turned features, CC1 with its
/// explicit toolpaths and turning tools; the files conform to the signatures, and no
/// turning workingstep is left a milling operation.
#[test]
fn lathe_plans_round_trip_through_part21() {
    use ncplan::part21::{schema, stepnc};
    let mut programs: Vec<PathBuf> =
        std::fs::read_dir(dir()).unwrap().map(|e| e.unwrap().path()).filter(|p| p.extension().is_some_and(|e| e != "expect")).collect();
    programs.sort();
    let mut entities = std::collections::BTreeSet::new();
    for p in &programs {
        let expect = std::fs::read_to_string(p.with_extension("expect")).unwrap();
        let dialect = expect.lines().find_map(|l| l.strip_prefix("dialect ")).unwrap().trim();
        let plan = plan_of(p, dialect);
        let name = p.file_name().unwrap().to_string_lossy().into_owned();
        for cc in [stepnc::Class::Cc2, stepnc::Class::Cc1] {
            let (text, _) = stepnc::to_string(&plan, cc, "2026-01-01T00:00:00");
            let x = ncplan::part21::parse(&text).unwrap_or_else(|e| panic!("{name} {cc:?}: {e}"));
            assert_eq!(schema::iso14649().check(&x), Vec::<String>::new(), "{name} {cc:?}");
            let back = stepnc::read(&x).unwrap_or_else(|e| panic!("{name} {cc:?}: {e}"));
            let want = if cc == stepnc::Class::Cc2 { plan.clone() } else { stepnc::toolpaths_only(&plan) };
            assert_eq!(back, want, "{name} {cc:?}: read back");
            let (again, _) = stepnc::to_string(&back, cc, "2026-01-01T00:00:00");
            assert_eq!(again, text, "{name} {cc:?}: written again");
            // Every workingstep that turns is an ISO 14649-121 operation, never a freeform milling one.
            let turning = plan.workingsteps.iter().filter(|w| w.turning.as_ref().is_some_and(|t| t.operation.is_some())).count();
            let freeform = text.matches("=FREEFORM_OPERATION(").count();
            assert!(
                freeform + turning <= plan.workingsteps.len(),
                "{name} {cc:?}: {turning} turning workingsteps, {freeform} freeform operations"
            );
            if cc == stepnc::Class::Cc2 {
                for line in text.lines() {
                    if let Some((_, rest)) = line.split_once('=') {
                        entities.insert(rest.split('(').next().unwrap_or("").to_owned());
                    }
                }
            }
        }
    }
    // The suite exercises every turning entity ncplan writes.
    for e in [
        "TURNING_WORKINGSTEP",
        "CONTOURING_ROUGH",
        "CONTOURING_FINISH",
        "FACING_ROUGH",
        "GROOVING_FINISH",
        "THREADING_ROUGH",
        "CUTTING_IN",
        "TURNING_TECHNOLOGY",
        "CONST_CUTTING_SPEED",
        "CONST_SPINDLE_SPEED",
        "TURNING_MACHINE_FUNCTIONS",
        "TURNING_MACHINE_TOOL",
        "GENERAL_TURNING_TOOL",
        "GROOVING_TOOL",
        "TURNING_THREADING_TOOL",
        "REVOLVED_FLAT",
        "OUTER_DIAMETER",
        "REVOLVED_ROUND",
        "GROOVE",
        "GENERAL_REVOLUTION",
    ] {
        assert!(entities.contains(e), "{e} is written for none of the lathe programs: {entities:?}");
    }
}

/// Edits of the named turning cycles' arguments (Siemens CYCLE95, CYCLE93, CYCLE97), of Okuma's
/// LAP and of Haas's one-block G76 are said in a turner's terms, with no workingstep or
/// feature invented or lost.
#[test]
fn named_and_one_block_cycle_edits_in_a_turner_s_terms() {
    use expect_test::expect;
    let rough = lathe_edit("siemens_cycle95.mpf", "\"KONT_A:KONT_E\", 2.5, 0.1, 0.2,", "\"KONT_A:KONT_E\", 2, 0.1, 0.3,");
    no_structure_change(&rough);
    expect![[r#"
        allowance_changed | finishing_allowance | U0.4 W0.1 | U0.6 W0.1
          finishing allowance changed from U0.4 W0.1 to U0.6 W0.1 at line 6
        axial_depth_changed | depth_of_cut | 2.5 | 2
          depth of cut changed from 2.5 to 2 at line 6
    "#]]
    .assert_eq(&rough);
    let width = lathe_edit("siemens_cycle93.mpf", "CYCLE93(44, -20, 5, 3,", "CYCLE93(44, -20, 6, 3,");
    expect![[r#"
        feature_changed | groove_width | 5 mm | 6 mm
          groove width changed from 5 mm to 6 mm at line 7
    "#]]
    .assert_eq(&width);
    let pitch = lathe_edit("siemens_cycle97.mpf", "CYCLE97(2, , 0, -30", "CYCLE97(1.5, , 0, -30");
    expect![[r#"
        thread_pitch_changed | thread_pitch | 2 | 1.5
          thread pitch changed from 2 to 1.5 at line 6
    "#]]
    .assert_eq(&pitch);
    let lap = lathe_edit("okuma_lap.min", "G85 N0100 D2.5 F0.3 U0.4 W0.1", "G85 N0100 D2 F0.3 U0.6 W0.1");
    no_structure_change(&lap);
    expect![[r#"
        allowance_changed | finishing_allowance | U0.4 W0.1 | U0.6 W0.1
          finishing allowance changed from U0.4 W0.1 to U0.6 W0.1 at line 9
        axial_depth_changed | depth_of_cut | 2.5 | 2
          depth of cut changed from 2.5 to 2 at line 9
    "#]]
    .assert_eq(&lap);
    // 10 threads per inch made 12, in the inch section of the program.
    let haas = lathe_edit("haas_g76_one_block.nc", "F0.1 A60 P1", "F0.0833 A60 P1");
    expect![[r#"
        thread_pitch_changed | thread_pitch | 0.1 | 0.0833
          thread pitch changed from 0.1 to 0.0833 at line 9
    "#]]
    .assert_eq(&haas);
}

/// Inch read from a lathe program that states no units only on two kinds of evidence: feeds
/// per revolution no mm/rev turning feed has, and a constant surface speed that keeps within
/// the spindle limit only read in ft/min. A Swiss-type lathe's small metric part, turned at
/// 0.02-0.05 mm/rev with its surface speed well within the limit in m/min, stays metric.
#[test]
fn inch_is_read_from_feeds_and_surface_speed_together() {
    let reg = Registry::shipped();
    let d = reg.get("fanuc_lathe").unwrap();
    let inferred = |program: &str| {
        pipeline::analyze(program.as_bytes(), &d, &Profile::default())
            .diagnostics
            .iter()
            .any(|f| f.code.as_str() == "interp::units-inferred")
    };
    // An NX post's inch part: S350 ft/min at Ø2 in turns 668 1/min, within G50 S1800;
    // in m/min it would need 55,700.
    let inch = "O0001\nG50 S1800\nT0101\nG96 S350 M03\nG0 X2.1 Z0.1\nG99 G1 X2. F.01\nZ-1. F.012\nX2.1 F.02\nG0 Z0.1\nX1.9\nG1 Z-1. F.012\nX2. F.02\nG0 X4. Z2.\nM30\n";
    assert!(inferred(inch));
    // A Swiss-type part in millimetres: S80 m/min at Ø6 turns 4,244 1/min, within S8000.
    let metric = "O0002\nG50 S8000\nT0101\nG96 S80 M03\nG0 X6.2 Z0.1\nG99 G1 X6. F.02\nZ-5. F.03\nX6.2 F.05\nG0 Z0.1\nX5.8\nG1 Z-5. F.03\nX6. F.05\nG0 X20. Z5.\nM30\n";
    assert!(!inferred(metric));
    // The same metric part with no surface speed (G97) is not read in inch either.
    assert!(!inferred(&metric.replace("G96 S80", "G97 S4000")));
}

/// A program written for a machine the dialect cannot know (X words as radii, inch at
/// power-on) is translated as it is planned: on the machine its words show. Translated as the
/// dialect reads it, the radius program's part would come out at half its diameters and the
/// inch one at 1/25.4 of its size, with no warning. The translation, read back, runs as the
/// program does on that machine, and says why it was read so.
#[test]
fn translation_reads_the_machine_the_program_shows() {
    let reg = Registry::shipped();
    let lathe = reg.get("fanuc_lathe").unwrap();
    let linuxcnc = reg.get("linuxcnc").unwrap();
    let translated = |program: &str| {
        let mut out = Vec::new();
        let opts = pipeline::TranslateOptions::for_program("O0002");
        let diags = pipeline::translate(program, &lathe, &linuxcnc, &Profile::default(), opts, |b| out.extend_from_slice(b));
        let out = String::from_utf8(out).unwrap();
        let proof = pipeline::check_translation(program.into(), &lathe, &out, &linuxcnc, &Profile::default(), &diags);
        assert!(proof.is_empty(), "{proof:?}\n{out}");
        (out, diags.iter().map(|d| d.code.as_str()).collect::<Vec<_>>())
    };
    // Two arcs whose centres (I, K) fit only with X read as a radius.
    let radius = "O0002\nG18 G21 G99\nT0101\nG97 S1000 M03\nG0 X10. Z2.\nG1 Z0 F0.2\nG3 X15. Z-5. I0 K-5.\nG1 Z-20.\nG2 X20. Z-25. I5. K0\nG1 X25.\nG0 X50. Z50.\nM30\n";
    let (out, codes) = translated(radius);
    assert!(codes.contains(&"interp::x-words-radius"), "{codes:?}");
    // LinuxCNC reads X as radii (no G7): the retract to radius 50 is written X50, not the
    // X25 of the program read with X as diameters.
    assert!(out.contains("G0 X50 Z50\n"), "{out}");
    // The NX post's inch part of the test above, with no units stated.
    let inch = "O0001\nG50 S1800\nT0101\nG96 S350 M03\nG0 X2.1 Z0.1\nG99 G1 X2. F.01\nZ-1. F.012\nX2.1 F.02\nG0 Z0.1\nX1.9\nG1 Z-1. F.012\nX2. F.02\nG0 X4. Z2.\nM30\n";
    let (out, codes) = translated(inch);
    assert!(codes.contains(&"interp::units-inferred"), "{codes:?}");
    // Inch stated, or millimetres converted: the Ø4 in. retract is not 4 mm.
    assert!(out.contains("G20") || out.contains("X50.8"), "{out}");
}

/// The labels of a program's workingsteps and features, read in `dialect`.
fn labels(program: &str, dialect: &str) -> (Vec<String>, Vec<String>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let plan = pipeline::analyze(program.as_bytes(), &d, &Profile::default()).plan;
    (plan.workingsteps.iter().map(|w| w.label()).collect(), plan.features.iter().map(|f| f.kind.label().to_owned()).collect())
}

/// A program known to turn turns throughout: lathe evidence that comes after the first cuts
/// (LinuxCNC's `G76` after the facing and turning passes) makes those cuts turning too, and a
/// program whose every move lies in the ZX plane through the axis (`G18`, Y never off zero:
/// LinuxCNC's `G70`-`G72` in radius mode) is a lathe's. A `G18` program that moves in Y, or
/// one that cuts in XY, stays a mill's.
#[test]
fn a_program_known_to_turn_turns_from_its_start() {
    // Facing and a turning pass in radius mode, then a G76 thread: three turning workingsteps.
    let late = "G18 G21\nT1 M6\nS1000 M3\nG0 X12 Z0\nG1 X-0.5 F100\nG0 Z1\nX5\nG1 Z-20 F120\nG0 X12\nZ5\nT2 M6\nS500 M3\nG0 X6 Z2\n\
G76 P1.5 Z-15 I-1 J0.2 K0.9 R2 Q29.5 H1\nG0 X12 Z10\nM5\nM2\n";
    let (ws, features) = labels(late, "linuxcnc");
    assert_eq!(ws, ["facing finish", "contouring finish", "threading rough"], "{features:?}");
    assert!(features.iter().all(|f| !["toolpath feature", "round hole", "slot", "closed pocket"].contains(&f.as_str())), "{features:?}");
    // A G71 roughing and a G70 finish in radius mode, nothing else telling a lathe.
    let g7x = "G18 G21 G54\nF300\nT1 M6\nS800 M3\nO100 SUB\nG0 X4 Z1\nG1 Z-10\nX8 Z-14\nZ-20\nG0 X15\nO100 ENDSUB\n\
G0 X15 Z2\nG71 Q100 X15 Z2 D1 I0.5 R0.3\nG70 Q100 X15 Z2 D0.5 P1\nG0 X20 Z10\nM2\n";
    let (ws, features) = labels(g7x, "linuxcnc");
    assert!(!ws.is_empty() && ws.iter().all(|w| w.starts_with("contouring") || w.starts_with("facing")), "{ws:?}");
    assert!(features.iter().all(|f| f != "toolpath feature"), "{features:?}");
    // The same moves with a Y move: a mill's profile in the ZX plane, no turning.
    let (ws, _) = labels(&g7x.replace("G0 X20 Z10", "G0 X20 Y5 Z10"), "linuxcnc");
    assert!(ws.iter().all(|w| !w.contains("contouring")), "{ws:?}");
    // Cut in XY: a mill's.
    let (ws, _) = labels("G17 G21\nT1 M6\nS1000 M3\nG0 X0 Y0 Z1\nG1 Z-1 F100\nX10\nY10\nX0\nY0\nG0 Z5\nM2\n", "linuxcnc");
    assert!(ws.iter().all(|w| w.ends_with("milling")), "{ws:?}");
}

/// A third set of real programs, gathered for branch lathe5 from three repositories no earlier set
/// used (`tests/programs/lathe_s7_heldout/`: Nakamura-Tome shop programs of erdotsc/Nakamura,
/// turning with live-tool milling after it; Denford Mirac students' programs of eerth5514/ICNC;
/// Russian bar-lathe training programs of MechatronicsCherepanovMA/CNCLearn, the tool on the X-
/// side). None states a licence: only the sidecars are committed, `extract.sh` writes the programs
/// from mirrors. Their sidecars were written by reading each program before ncplan ran on it;
/// never used to build; measured once, at the end of branch lathe5 (6 December 2026):
/// 43 of the 89 listed recovered, no milling feature. The misses (printed once, not built on):
/// most of the bar-lathe programs written on the X- side (facing, G71 roughing, their
/// diameters, parting), the Denford programs' inside G71 roughing, G75 grooves and several
/// diameters, and the Nakamura programs' bores and drilled holes. No longer held back: 52 of 89
/// when branch lathe8 built on it among the other seen sets, 55 after (6 December 2026: the feed
/// a pass cuts at, not a fast feed in, decides; a face from the far side of the axis is facing).
/// After branch lathe11 (6 December 2026: a program that writes its whole numbers mostly without
/// a point is read as written for calculator-type input; a face behind a first one is facing):
/// 67 of 89; 74 after branch lathe12 (6 December 2026: passes left towards the axis, by a move
/// straight in X or a short pull-in, work inside: the Nakamura bores). The misses left include lengths written without a point in programs that mostly
/// write one (read in least increments, as the Fanuc dictionary says, with a warning).
/// Where the programs are not extracted the test says so and checks nothing.
#[test]
fn lathe_s7_held_out_programs() {
    /// Listed workingsteps and features recovered, no longer held back.
    const HELD_OUT_SCORE: usize = 74;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/programs/lathe_s7_heldout");
    let extracted = std::fs::read_dir(&dir).unwrap().filter(|e| e.as_ref().unwrap().path().extension().is_some_and(|e| e == "nc")).count();
    if extracted == 0 {
        crate::skip(
            "lathe::lathe_s7_held_out_programs",
            "the held-back programs are not extracted (tests/programs/lathe_s7_heldout/extract.sh)",
        );
        return;
    }
    let (listed, found, milling, misses) = score_folder("lathe_s7_heldout");
    assert_eq!(milling, 0, "milling features on lathe programs:\n{}", misses.join("\n"));
    assert!(found >= HELD_OUT_SCORE, "held out: {found} of {listed} recovered, fewer than {HELD_OUT_SCORE}:\n{}", misses.join("\n"));
}

/// Prints the misses of the real folders (run by hand with `--ignored --nocapture`).
///
/// `tests/programs/lathe_s8_heldout/` is sweep 8's held-back set, gathered from four repositories
/// no earlier set used: Brazilian students' shaft in Fanuc G-code system B (G75 facing, G71/G70,
/// a plunged groove, an M25x1.5 thread by G76, by G33 passes and by G78) of
/// Bruxnodev/pe-a-cil-ndrica-em-um-torno-CNC; a Fanuc portfolio shaft with M36 and M50 threads and
/// parting of leohiei/projetocnc-1-; Mazak Integrex 300SY hand-written turning and facing
/// snippets (main and second spindle) of mwinterm/fusion_post; a small teaching lathe's facing of
/// UncleEngineer/basic-cnc-lathe. Only the sidecars are committed (`extract.sh` writes the
/// programs from mirrors); they were written by reading each program, before ncplan ran on it,
/// and the set was measured once by the lead, after merging, on 6 December 2026 (integrate
/// 7be615f): 12 of 51, no milling feature; 24 of 51 after branch lathe11 built on it (no longer
/// held back: calculator-type input inferred, a `G75` stepping to the front faces). Missed: the system-B shaft's facing, roughing,
/// groove and thread in all three versions; everything of the portfolio shaft (a block that
/// lost its `G`, profile labels missing: a control stops there too); the Mazak finishing
/// passes' feed; the teaching lathe's facing from the X- side.
///
/// `tests/programs/lathe_s9_heldout/` is sweep 9's held-back set (branch gatherlt9: 11 programs,
/// 66 items), gathered from four repositories no earlier set used: a German mill-turn course's
/// Sinumerik 840D sl turning programs (ShopTurn `CYCLE951` facing and stock removal, `CYCLE952`
/// on a contour written in the program, `CYCLE99` thread, `CYCLE92` parting, explicit G1 passes)
/// of east-code/CNC-Dreh-Fraeszentrum; two Fanuc-style portfolio parts (a bore, a part turned
/// from both sides with a groove) of leohiei/projetocnc-2- and leohiei/projetocnc-3- (the author
/// of projetocnc-1-, sweep 8's); a CNC course's lab G71 exercise of KL-Mithunvel/G-M_CODE. Only the
/// sidecars are committed (`extract.sh` writes the programs from mirrors); they were written by
/// reading each program, before ncplan ran on it. Measured once on 6 December 2026 (integrate
/// 4d5e17b): 26 of 66, no milling feature. Most misses are the ShopTurn programs: a Sinumerik
/// lathe's X is a diameter by the machine's reset state (`DIAMON`), which these programs do not
/// state, so the east-code parts read X as a radius; Siemens puts `G96` in the feed-type group
/// (constant cutting rate with G95's feed per revolution), which the dictionary models apart, so
/// no feed per revolution is found; `CYCLE951`/`CYCLE952`/`CYCLE99`/`CYCLE92` give no workingsteps
/// yet. No longer held back: 63 of 66 after branch lathe13 built on it (6 December 2026: the
/// lathe's reset state inferred from its turning words, group 15's codes with both their effects,
/// the ShopTurn cycles as workingsteps); left: the chuck part's Ø56 pass with its chamfer read as
/// a general revolution, the lab exercise's Ø25, a portfolio part's groove roughing. After
/// lathe20 (7 December 2026): 64 of 66 (a roughing pass nothing finishes leaves the Ø56).
///
/// `tests/programs/lathe_s10_heldout/` is sweep 10's held-back set (branch gatherlt10: 3 programs
/// of 2 repositories, 21 items; a second gatherer found no lathe program in a repository not used
/// before): two Haas school parts with one-block `G71` (Meloc3D/MFPM) and a Sinumerik 810T-style
/// program with `G58` shifts, `B` radii and a counter-spindle second side (ph-lk/tempGCodeCNC).
/// Measured once on 6 December 2026 (integrate 9a7411f): 10 of 21, no milling feature. Missed: the
/// 810T program's facing and contouring workingsteps with their feeds per revolution and three of
/// its features (an older Sinumerik read with the 840D dictionary), the second Haas part's
/// roughing and finishing (its `G71` P/Q block numbers are duplicated: the control would not run
/// it as written) and its Ø48, the first part's face at Z0. After lathe19 (seen, 7 December
/// 2026): 13 of 21 (the 810T program's second-side facing and its Ø18: a contour running along
/// +Z read as the counter-spindle's).
///
/// `tests/programs/lathe_s11_heldout/` is sweep 11's held-back set (branch gatherlt11: 4 programs
/// of 3 repositories, 34 items; the search index gave no other lathe program in a repository not
/// used before): two Dutch shop programs for a Fanuc 18T kept as samples of a 2005 lathe
/// simulator (Planet-Source-Code/alkiman-lathe-simulator__1-61452: a stud with an M5x0.8 `G76`
/// thread; a bush with `G90` roughing, `G71`/`G70` inside, inside and outside `G76` threads), a
/// Fanuc 16T mill-turn part's face outline milled under the machine's polar interpolation
/// `G121`/`G120` (srhart/CNC-Lathe-GCode-Polar-Example) and the turning of a LinuxCNC simulation
/// config's Mazak Integrex example part, explicit G7 roughing passes
/// (Sigma1912/LinuxCNC_Demo_Configs). Only the sidecars are committed (`extract.sh` writes the
/// programs from mirrors); written before ncplan ran on them. Measured once on 6 December 2026
/// (integrate 12e72bb): 18 of 34, no milling feature. Missed: the bush's facing rough and
/// finish, its outside and inside finishing (feeds 0.11 and 0.22 mm/rev), its faces at Z0 and
/// Z-30, R3, Ø49.9 and the M50x1.5 thread; the stud's facing rough and finish and its R2.15; the
/// Integrex part's roughing at 200 m/min and Ø80.2; the polar-interpolation face outline's side
/// milling and its profile (`G121`/`G120`, a builder's codes for polar interpolation, unread).
/// After lathe17 (seen): 27 of 34.
///
/// `tests/programs/lathe_s12_heldout/` is sweep 12's held-back set (branch gatherlt12: 8 programs
/// of 4 repositories, 82 items; short of the 10 asked): four Doosan Lynx shop programs in inch
/// (mikemacfarland/Doosan-Lynx-300 and -2100: `G71`/`G70` without decimal points, `G76`, groove
/// turning, sub-spindle transfer, `G75` parting), two Haas lathe class programs written as
/// explicit passes (mark-brannan/mfgt_haas_cnc_class_assignments) and two turning samples of a
/// CNC simulator (ailtonbsj/free-cnc-simulator-wine). Only the sidecars are committed; written
/// before ncplan ran on them. Measured once on 7 December 2026 (integrate 9165117): 52 of 82, no
/// milling feature. Missed: the simulator samples' inside work, grooves, drilling and finish
/// diameters (8 + 4), the class programs' facing rough/finish with their feeds and their
/// diameters and faces (9), the Doosan programs' grooving and a few diameters, faces and the
/// 2.54-pitch thread (9). After lathe18 (seen, 7 December 2026): 65 of 82 (a face then diameters
/// turned one each from it, plunges left by a rapid, a grooving tool's `G71`/`G70`, the profile
/// after straight roughing passes); left: the simulator sample 3's tools (`T26`, `T21`, `T09`: two
/// digits, read by the Fanuc tool/offset split as tool 0, as the control reads them), the class
/// programs' `G97` steps listed with the `G50` clamp, a `G02` with no radius and an arc whose end
/// is off its circle (controls alarm on both). After lathe19 (seen, 7 December 2026): 66 of 82
/// (O0035's second side on the sub-spindle, read along +Z).
///
/// `tests/programs/lathe_s13_heldout/` is sweep 13's held-back set (branch gatherlt13: 12 programs
/// of 3 repositories, 125 items), files no test used of repositories earlier sets drew on: eleven
/// Doosan Lynx shop programs in inch (sweep 12's two repositories) and a Nakamura-Tome mill-turn
/// program (erdotsc/Nakamura, the s7 set's: G72/G71 roughing, U-drills, boring; its live-tool
/// milling not listed). Of mikemacfarland/Doosan-Lynx-300: a transmission dyno
/// shaft's OD, off-axis insert drilling and stepped boring to a floor; a bronze carrier
/// bushing's inside `G71`/`G70`, its press-in bearing's OD and two-sided chamfered groove, and
/// the trim op; a stator spline sleeve's facing, explicit OD passes and boring; a V-band
/// flange's two sides (stepped OD with a fillet, a counterbore, the inner flank bored); a drum
/// bushing with a spiral oil groove cut by `G32` passes of 0.625 in lead, an inside groove and
/// a groove-and-part-off. Of mikemacfarland/Doosan-Lynx-2100 (bar fed, `G75` parting into the
/// sub-spindle, the second side worked there): the female and male 1.5 in V-band flanges
/// (`G71` without its own F) and a drain plug with a 55° `G76` thread, a `G71` to size for its
/// relief, an O-ring seat and a broach undercut. Only the sidecars are committed; written
/// before ncplan ran on them. Measured once on 7 December 2026 (integrate 0d8fb95): 110 of 125,
/// no milling feature. Missed: the drum bushing's (O3390) four `G71`/`G70` contourings, its
/// Ø66.04 bore and part-off (the workingsteps after its `G32` oil groove not found), the
/// Nakamura program's two U-drillings, Ø127, R5, the Ø39.8 bore and its Z-30.1 face, the dyno
/// shaft's off-axis insert drilling, and O0043's Ø40.005 bore and O0044's Ø39.7764. After
/// lathe19 (seen, 7 December 2026): 119 of 125 (a counter-spindle's contour read along +Z, arcs
/// whose R without a point fits only in mm showing calculator-type input, an insert drill run
/// off the centre drilling, a bore left by a rapid pulling in); left: O3390's five workingsteps
/// listed with the `G50` clamp under `G97` (Fanuc clamps the speed by `G50 S` under constant
/// surface speed only) and the Nakamura bore's floor at Z-30.1 (its roughing pass only). After
/// lathe20 (7 December 2026): 125 of 125, O3390's sidecar corrected (its operations under `G97`
/// listed with their spindle speed, no clamp: the folder's README.md says why); a part-off
/// through to the bore, one pass then a finer pass of the same tool as roughing and finishing,
/// and a bore beyond the finishing bar's reach as the roughing profile left it.
///
/// `tests/programs/lathe_s14_heldout/` is sweep 14's held-back set (branch gatherlt14: 11 programs
/// of 4 repositories, 127 items), files no test used of repositories earlier sets drew on. Of
/// mikemacfarland/Doosan-Lynx-300 (inch, `G71`/`G70` mostly without decimal points): an idler
/// pulley's bearing bore with its shoulder and a retaining-ring groove by `G75` inside; a
/// piston's OD, `G83` drilling, a bore to a floor and an annular face groove; a discharge flange's
/// OD with a fillet and its bore; a charge tube coupler's OD, drilling, stepped bore and an
/// outside and an inside groove; a collar's stepped OD and three stepped bores; a wastegate
/// flange's counterbore and bore, its spigot roughed by grooving plunges and `G75` parting. Of
/// mikemacfarland/Doosan-Lynx-2100: a bar-fed filter coupler with two M20x1.5 `G76` threads, the
/// profile's `G70` run again after them, and a part-off into the sub-spindle. Of
/// Planet-Source-Code/alkiman-lathe-simulator__1-61452 (the s11 set's; Fanuc 18T, metric, stored
/// behind `&HE:%` and `:0117`): `G94` facing, `G71`/`G70`, `G76` and a groove; and two programs of
/// explicit facing and turning passes with a finish profile (fillets, a dome, an M60x1.5 `G76`).
/// Of erdotsc/Nakamura (the s7 and s13 sets' shop): a mill-turn program's `G72`/`G71` roughing,
/// U-drill and drill, finish, inside rough and finish (its live-tool milling not listed). Only
/// the sidecars are committed; written before ncplan ran on them. Measured once on 7 December
/// 2026 (integrate fba6f7a): 115 of 127, no milling feature. Missed: two part-offs under a `G50`
/// clamp (O0024, O4520), O4520's Ø63.373 and Ø56.007, O2301's face at Z-13.589, the Nakamura
/// program's Ø33 bore and its face at Z-25.6, O0106's four fillets (R5, R2, R6, R12) and O0117's
/// Ø30 groove. After lathe20 (7 December 2026): 125 of 127, O4520's sidecar corrected (its
/// part-off runs under `G97 S1000`: README.md); left: O2301's annular face groove floor at
/// Z-13.589 and O0117's Ø30 groove (a plunge and two flank passes parted into three
/// workingsteps).
///
/// `tests/programs/lathe_s15_heldout/` is sweep 15's held-back set (branch gatherlt15: 13 programs
/// of 4 repositories, 118 items), files no test used of repositories earlier sets drew on. Of
/// Planet-Source-Code/alkiman-lathe-simulator__1-61452 (Fanuc 18T, metric): `G94` facing with
/// `G71`/`G70` whose profile carries its own feeds; `G94`, `G71` and a finishing contour written
/// out from the back (a dome, R15, R8, R3); three programs of explicit facing and turning passes
/// with a finish profile (one with no speed clamp for its roughing tool); a bush's explicit
/// passes, drilling, inside roughing with an R3 and inside finishing.
/// Of mikemacfarland/Doosan-Lynx-300 (inch, `G71`/`G70` without decimal points): a locknut
/// retainer's stepped OD, a discharge adapter's OD and its inside cone with an R.191, a flange's
/// stepped OD, a shoulder turned with no face cut, a reducer's OD with an edge round, insert
/// drilling and a bore with an inside shoulder. Of mikemacfarland/Doosan-Lynx-2100: a bar-fed
/// plug, drilled, parted off into the sub-spindle and faced there in steps. Of erdotsc/Nakamura:
/// `G72`/`G71` roughing, two U-drills, finish, inside rough and finish with a recess (its live-tool
/// milling not listed). Only the sidecars are committed; written before ncplan ran on them.
/// Measured once on 7 December 2026 (integrate 2a0a436): 114 of 118, no milling feature. Missed:
/// O0208's inside finishing contour (Ø40 and Ø30 inner diameters and the workingstep with its
/// feed, speed and clamp) and the Nakamura B40's Ø41 inner diameter. After lathe22 (7 December
/// 2026): 118 of 118 (a finishing bar's one pass run in the bore an earlier tool roughed, the
/// outside turned beside it, finishes that bore; a recess the finishing bar passes through at a
/// smaller diameter is the roughing profile's).
///
/// `tests/programs/lathe_s16_heldout/` is sweep 16's held-back set (branch gatherlt16: 8 programs
/// of 5 repositories, 83 items), files no test used. Of mikemacfarland/Doosan-Lynx-300 (inch):
/// a discharge adapter's OD roughed by `G71` with no `G70`, a V-sided groove finished by a
/// grooving tool, insert drilling and a stepped bore; soft jaws faced by `G72`/`G70`; a flange's
/// front stepped by `G72`/`G70` with a spigot and an R.041, an annular face groove, drilling and
/// a bore; a reducer's OD, its neck turned by a grooving tool's `G71`/`G70` (R1.5625, R.4375), a
/// drill and a coned bore. Of erdotsc/Nakamura: `G72`/`G71` roughing (R3, R1), a U-drill and a
/// drill, finish, inside rough and finish with a recess (its live-tool milling not listed). Of
/// SabirHusnain/CNC-GCode-Milling-and-Lathe (files issue 43's sweep did not use): a Fusion 360
/// post's explicit profile roughing and finishing (a face at Z-2.5, Ø50, Ø70, Ø80). Of
/// enier290188/cnc: a hand-written step shaft in explicit passes, turned from both sides (R.05
/// rounds). Of madsenmj/vscode-gcode-syntax-citizen (MIT): a Citizen Swiss-type sample in
/// macro variables (facing, Ø.1 turned along +Z, parting off). Only the sidecars are committed;
/// written before ncplan ran on them. Measured once on 7 December 2026 (integrate a89f1ba): 73 of
/// 83, no milling feature. Missed: the Citizen Swiss-type sample's six items (its facing,
/// turning and part-off in macro variables along +Z read as no workingstep); O2403 and O2411's
/// `G72`/`G70` facing finish (feed and clamp); O2411's annular face groove, whose floor the
/// sidecar lists as a revolved flat where the plan now names a face groove (lathe23); the Fusion
/// 360 program's Ø50. After lathe24 (7 December 2026): 75 of 83 (a `G70` after a `G72` finishes
/// that face profile: facing finish). O2411's sidecar now names its groove's floor a face groove
/// (the program's "FACE GROOVE", a face grooving holder), still missed: its feed approach at F.02
/// above the face and the plunge at F.0035 part the groove into two workingsteps, the plunge and
/// the two wall passes, and neither is read as a face groove. Left too: the Citizen sample (its
/// `$1`/`$2` paths, `S1=`, `!L1` and `X#814+.1` unbracketed are not read) and the Fusion Ø50 (read
/// as a groove between the last V ridge and the Ø70 shoulder).
///
/// `tests/programs/lathe_s17_heldout/` is sweep 17's held-back set (branch gather17a: 8 programs
/// of 4 repositories, 91 items), files no test used. Of mikemacfarland/Doosan-Lynx-300 (inch,
/// values without a point in 0.0001 in): a discharge adapter's front by `G72`/`G70` with a
/// spigot, its bore by `G71`/`G70` and an annular face groove by `G74`; a chip cover's facing
/// pass, OD and bore by `G71`/`G70`, insert drilling and a `G75` part-off into the bore; a
/// piston's OD with R.055 rounds, a groove and an inside `G71` written with decimal points; a
/// discharge flange's OD with rounds, an inside `G71` without allowances and an explicit inside
/// finish. Of mikemacfarland/Doosan-Lynx-2100: a hose barb's OD, a `G75` groove, spade drilling,
/// a rounded bore entry and a part-off (its sub-spindle side not listed). Of erdotsc/Nakamura:
/// `G72`/`G71` roughing, a second `G71` over a recess with R2 fillets, a U-drill and a drill,
/// finish, inside rough and finish (its live-tool milling not listed). Of
/// Planet-Source-Code/alkiman-lathe-simulator__1-61452 (Fanuc 18T, metric): `G94` facing with a
/// `G73` pattern-repeating roughing and `G70`; `G94`, `G71`, a written-out finish calling an
/// undercut subprogram not in the file, and a two-block `G76` M36x1.5. All Fanuc-type controls
/// (no unused program of another lathe control was found in the index). Only the sidecars are
/// committed; written before ncplan ran on them. Measured at the session 18 start (integrate
/// 24fcaaf): 87 of 91, no milling feature. No longer held back: 91 of 91 after branch lathe18
/// (7 December 2026: `G73` pattern repeating cut as the Fanuc manual gives it, a `G74` face
/// groove and its wall passes one grooving, a face cut in short of the axis facing; the
/// adapter's groove renamed grooving finish by the grooving convention, 90 of 91 as first
/// written).
///
/// `tests/programs/lathe_s18_heldout/` is sweep 18's held-back set (branch gather18a: 6 programs
/// of 3 repositories, 60 items), files no test used. Of leohiei/projetocnc-2- and
/// leohiei/projetocnc-3- (repositories no test used: a Brazilian course's programs for a Fanuc
/// 0i-T run in SwanSoft, G-code system B with `G92 S` the clamp): a bore roughed by an inside
/// `G71` and finished by `G70` short of its cone; a part turned from two sides in `G54` and `G55`,
/// faced, `G71`/`G70` with R2 rounds, a groove by three `G75` plunges, the second side's spigot
/// (its inside `G71`, started outside the spigot, not listed). Of
/// Planet-Source-Code/alkiman-lathe-simulator__1-61452 (Fanuc 18T, metric): explicit facing and
/// turning passes at one feed, drilling, a finish profile and a bore finished in one pass; `G94`
/// facing with a two-block `G71` written `R` before `U` and a finish written out from the back
/// over a dome; `G71` with seven `G92` thread passes M36x1.5; and `G71`, a two-block `G76`
/// M20x1.5 at 55° and a cut-off, two of them finishing through an undercut subprogram not in the
/// file. Fanuc-type controls only (no unused program of another lathe control was found in the
/// index). Only the sidecars are committed; written before ncplan ran on them. Measured once on
/// 7 December 2026 (integrate c2111971): 57 of 60, no milling feature; the misses: the
/// two-sided part's groove by three `G75` plunges (no grooving rough found in its place), and
/// O0121's contouring finish and cut-off (not found in the order listed). No longer held back:
/// 59 of 60 after branch lathe19 (session 19: `G75` plunges side by side within the tool's
/// width one grooving, a plunge behind the part to a pip parting off); left: O0121's finish,
/// written in two pieces around an undercut subprogram not in the file (read as roughing).
///
/// `tests/programs/lathe_s18b_heldout/` is sweep 18's second held-back set (branch gather18c: 6
/// programs of 1 repository, 12 items), files no test used of a repository earlier sets drew on
/// (east-code/CNC-Dreh-Fraeszentrum: a German course's SINUMERIK 840D sl ShopTurn programs): a
/// `CYCLE951` facing and `CYCLE952` roughing and finishing of a contour program `CYCLE62` names
/// (not in the file), three `CYCLE952` roughings of such contours under `G96 S320 LIMS=3000`, and
/// two mill-turn programs on a turned Ø80: three radial holes drilled by `MCALL CYCLE82` over
/// `HOLES1` under `CYCLE800` and `TRACYL`, and a `POCKET3` pocket on the face under `TRANSMIT`.
/// No unused program of another lathe family (Okuma, Mazak, Mitsubishi, Fagor, Haas) was found
/// in the index. Only the sidecars are committed; written before ncplan ran on them. Measured
/// once on 7 December 2026 (integrate c2111971): 4 of 11 items the test counts, no milling
/// feature; the misses: the four `CYCLE952` roughings and the finish of contours held in the
/// `CYCLE62` programs beside them (not read with the file: no workingstep), the `POCKET3` pocket
/// under `TRANSMIT` and the `MCALL CYCLE82` drilling under `TRACYL`. No longer held back: the
/// contour programs the `CYCLE62` calls name were added beside the main programs (SOURCES rows,
/// `contour-only` sidecars: read through their main programs), the programs are read with their folder as `ncplan
/// plan` reads a file, and a drilling or milling workingstep's spindle speed is scored (the
/// harness read it only for turning ones): 10 of 11 after branch lathe19 (session 19); left: the
/// `POCKET3` roughing (its `_VARI` units digit 1) named by its finishing pass, side finish milling.
///
/// `tests/programs/lathe_s19_heldout/` is sweep 19's held-back set (branch gather19a: 7 programs
/// of 2 repositories, 61 items), files no test used of repositories earlier sets drew on. Of
/// Planet-Source-Code/alkiman-lathe-simulator__1-61452 (Fanuc 18T, metric): a pin turned from two
/// sides after `G10 P0` shifts (explicit facing and turning passes, finish profiles with a
/// shoulder face cut from outside, a groove plunged at two places); `G94` facing, `G71` and seven
/// `G32` thread passes M36x1.5; `G94` facing and a `G72` over a dome, a shaft end and a shoulder
/// with the finish written from the shoulder to the axis; a facing pass and turning passes at one
/// feed with a stepped finish. Of mikemacfarland/Doosan-Lynx-300 (inch, values without a point in
/// 0.0001 in): a pedestal flange's inside `G71`/`G70`; an intake flange faced, its OD by
/// `G71`/`G70` with a cove and a round and a counterbore by an inside `G71`/`G70` (no `G20`: inch
/// at power-on, inch tool comments); a turbine housing's inside `G71`/`G70` under `G97` (no `G20`).
/// Fanuc-type controls only (no unused program of another lathe control was found in the index).
/// Only the sidecars are committed; written before ncplan ran on them. Measured once (session 19,
/// integrate 8357e035 with this set): 45 of 61, no milling feature, the same as on b2bbfc3f; the
/// misses: the inch programs without `G20` find nothing, the pin turned from two sides after
/// `G10 P0` shifts loses everything from its groove on, the `G72` over the dome.
///
/// `tests/programs/lathe_build16/` is branch lathe22's own build set (see `lathe_build16_programs`).
#[test]
#[ignore]
#[allow(clippy::print_stdout)] // the misses are the test's report
fn print_real_misses() {
    let (_, listed, found, milling, misses) = score_corpus_sidecars();
    println!("== lathe_heldout: {found} of {listed}, {milling} milling");
    for m in &misses {
        println!("{m}");
    }
    for folder in [
        "lathe_real",
        "lathe_real_heldout",
        "lathe_new",
        "lathe_new_heldout",
        "lathe_s7_heldout",
        "lathe_s8_heldout",
        "lathe_s9_heldout",
        "lathe_s10_heldout",
        "lathe_s11_heldout",
        "lathe_s12_heldout",
        "lathe_s13_heldout",
        "lathe_s14_heldout",
        "lathe_s15_heldout",
        "lathe_s16_heldout",
        "lathe_s17_heldout",
        "lathe_s18_heldout",
        "lathe_s18b_heldout",
        "lathe_s19_heldout",
        "lathe_build16",
        "lathe_build19",
    ] {
        if !Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/programs").join(folder).exists() {
            continue;
        }
        let (listed, found, milling, misses) = score_folder(folder);
        println!("== {folder}: {found} of {listed}, {milling} milling");
        for m in &misses {
            println!("{m}");
        }
    }
}

/// Explicit passes read as a turner reads them: a bore's passes pull off towards the axis; a
/// face stepped down past a chamfer is facing, not parting; a groove profiled from both sides
/// is grooving; an operation's comment parts one tool's roughing from its finishing and makes
/// a roughing operation's one pass roughing; facing passes then turning passes at one feed are
/// two workingsteps.
#[test]
fn explicit_passes_are_read_as_a_turner_reads_them() {
    // A bore: each pass feeds along -Z and pulls off inwards (X smaller) before the rapid out.
    let bore = "O1\nG21 G99\nT0101\nG97 S800 M3\nG0 X20. Z2.\nG1 X24. Z0.5 F0.2\nZ-20.\nX23.4 Z-19.7\nG0 Z2.\nX28.\n\
G1 Z0.5\nZ-20.\nX27.4 Z-19.7\nG0 Z2.\nX100. Z50.\nM30\n";
    let (ws, _) = labels(bore, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough inside"]);
    // The same passes pulling off outwards turn the outside.
    let od = "O1\nG21 G99\nT0101\nG97 S800 M3\nG0 X50. Z2.\nG1 X28. Z0.5 F0.2\nZ-20.\nX28.6 Z-19.7\nG0 Z2.\nX24.\n\
G1 Z0.5\nZ-20.\nX24.6 Z-19.7\nG0 Z2.\nX100. Z50.\nM30\n";
    let (ws, _) = labels(od, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough"]);
    // Facing passes stepping down to Z-0.8 across to the axis, the last ones only clearing a
    // chamfer's corner behind the face: facing, the face where the last pass to the axis left it.
    let face = "O2\nG21 G99\nT0101\nG97 S1000 M3\nG0 X44. Z1.\nG1 Z0.6 F0.2\nX0.\nG0 Z1.6\nX44.\nG1 Z0.2\nX0.\nG0 Z1.2\nX44.\n\
G1 Z-0.2\nX38.\nG0 Z1.\nX44.\nG1 Z-0.6\nX39.\nG0 Z1.\nX100. Z50.\nM30\n";
    let (ws, features) = labels(face, "fanuc_lathe");
    assert_eq!(ws, ["facing rough"]);
    assert!(features.contains(&"revolved flat".to_owned()), "{features:?}");
    // A groove Ø30 between Z-10 and Z-16 finished from both sides, one flank a pass.
    let groove = "O3\nG21 G99\nT0202\nG97 S600 M3\nG0 X42. Z-8.\nG1 X40. Z-10. F0.08\nX30.\nZ-13.\nG0 X42.\nZ-18.\n\
G1 X40. Z-16.\nX30.\nZ-13.\nG0 X42.\nX100. Z50.\nM30\n";
    let (ws, features) = labels(groove, "fanuc_lathe");
    assert_eq!(ws, ["grooving finish"]);
    assert_eq!(features, ["groove"]);
    // One tool, one feed: its roughing operation's passes, then its finishing one, each
    // headed by its name as a post writes it.
    let named = "O4\nG21 G99\n(ROUGH_TURN_OD)\nT0101\nG97 S800 M3\nG0 X42. Z2.\nG1 X36. Z0.5 F0.2\nZ-30.\nX38. Z-29.\n\
G0 Z2.\n(FINISH_TURN_OD)\nG0 X35.\nG1 Z0.5\nZ-30.\nX42.\nG0 Z2.\nX100. Z50.\nM30\n";
    let (ws, _) = labels(named, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough", "contouring finish"]);
    // Facing then turning with one tool at one feed.
    let face_turn = "O5\nG21 G99\nT0101\nG97 S800 M3\nG0 X44. Z0.5\nG1 X-1. F0.2\nZ1.\nG0 X44.\nZ0.\nG1 X-1.\nZ1.\n\
G0 X38.\nG1 Z-30.\nX44.\nG0 Z1.\nX34.\nG1 Z-20.\nX40.\nG0 X100. Z50.\nM30\n";
    let (ws, _) = labels(face_turn, "fanuc_lathe");
    assert_eq!(ws, ["facing rough", "contouring rough"]);
    // Roughing passes, then at the same feed the finishing contour from the axis: two.
    let rough_finish = "O6\nG21 G99\nT0101\nG97 S800 M3\nG0 X44. Z2.\nG1 X38. Z0.5 F0.2\nZ-30.\nX44.\nG0 Z2.\nX34.\n\
G1 Z0.5\nZ-20.\nX40.\nG0 Z2.\nX-1.\nG1 Z0.\nX30.\nX32. Z-1.\nZ-20.\nX36.\nZ-30.\nX44.\nG0 X100. Z50.\nM30\n";
    let (ws, features) = labels(rough_finish, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough", "contouring finish"]);
    assert!(features.iter().filter(|f| *f == "outer diameter").count() >= 2, "{features:?}");
}

/// Facing passes as operators and posts write them: one pass across to the axis after a
/// positioning feed many times the cutting feed (air, not cut); a pass across to the axis
/// and back out along the face; the same pass twice (a spring pass) after a lead-in along the
/// diameter. Each is facing finish, the face where it ran, never parting off or contouring.
/// A groove plunged at several places along Z, each plunge left by a rapid, is grooving rough.
#[test]
fn facing_and_plunged_passes_as_operators_write_them() {
    // One pass: a diagonal approach at F2 (ten times the cut's feed), across to X-1.
    let fast = "O1\nG21 G99\nT0101\nG97 S2000 M3\nG0 X30. Z5.\nG1 X22. Z0. F2.\nX-1. F0.2\nG0 Z1.\nX40. Z20.\nM30\n";
    let (ws, features) = labels(fast, "fanuc_lathe");
    assert_eq!(ws, ["facing finish"], "{features:?}");
    assert_eq!(features, ["revolved flat"]);
    // Across to the axis and back out along the face, then away along Z.
    let back = "O2\nG21 G99\nT0101\nG97 S1500 M3\nG0 X60. Z2.\nG1 Z0. F0.04\nX0.\nX60.\nZ2.\nG0 X100. Z50.\nM30\n";
    let (ws, features) = labels(back, "fanuc_lathe");
    assert_eq!(ws, ["facing finish"], "{features:?}");
    assert_eq!(features, ["revolved flat"]);
    // The same face twice at Z-2, fed down along the diameter first: a finish and its spring
    // pass, not roughing, and no parting off (the tool feeds along Z at the diameter first).
    let spring = "O3\nG21 G99\nT0101\nG97 S500 M3\nG0 Z0. X25.5\nG1 Z-2. F0.1\nX0.\nG0 Z5.\nX25.5\nG1 Z-2.\nX0.\nG0 Z5.\nX25.5\nM30\n";
    let (ws, features) = labels(spring, "fanuc_lathe");
    assert_eq!(ws, ["facing finish"], "{features:?}");
    assert_eq!(features, ["revolved flat"]);
    // Faces stepping down are still roughing.
    let steps = "O4\nG21 G99\nT0101\nG97 S500 M3\nG0 Z0. X40.\nG1 Z-1. F0.2\nX0.\nG0 Z5.\nX40.\nG1 Z-2.\nX0.\nG0 Z5.\nX100.\nM30\n";
    let (ws, _) = labels(steps, "fanuc_lathe");
    assert_eq!(ws, ["facing rough"]);
    // A parting tool positioned by rapids plunges to the axis behind the part: parting off.
    let part = "O5\nG21 G99\nT0101\nG97 S800 M3\nG0 X42. Z2.\nG1 X40. Z0.5 F0.2\nZ-30.\nX42.\nG0 Z2.\nT0202\nG97 S500 M3\n\
G0 X42. Z-25.\nG1 X-1. F0.05\nG0 X42.\nX100. Z50.\nM30\n";
    let (ws, _) = labels(part, "fanuc_lathe");
    assert_eq!(ws.last().map(String::as_str), Some("parting off"), "{ws:?}");
    // A groove Ø21 plunged at Z-15, Z-16 and Z-17, each plunge left by a rapid.
    let groove = "O6\nG21 G99\nT0505\nG96 S120 M4\nG0 Z-15.\nX29.\nG1 X21. F0.05\nG0 X29.\nZ-16.\nG1 X21.\nG0 X29.\nZ-17.\n\
G1 X21.\nG0 X29.\nG0 X200. Z270.\nM30\n";
    let (ws, features) = labels(groove, "fanuc_lathe");
    assert_eq!(ws, ["grooving rough"], "{features:?}");
    assert_eq!(features, ["groove"]);
    // One plunge: grooving finish, as before.
    let one = "O7\nG21 G99\nT0505\nG96 S120 M4\nG0 Z-15.\nX29.\nG1 X21. F0.05\nG0 X29.\nG0 X200. Z270.\nM30\n";
    let (ws, _) = labels(one, "fanuc_lathe");
    assert_eq!(ws, ["grooving finish"]);
}

/// Grooving by the convention of `plan::turning`: plunges at several places along Z rough the
/// groove (a `G75` with its Z shift, or plunges written as moves, even where they leave stock
/// between them); one plunge to the final depth finishes it.
#[test]
fn grooving_passes_are_named_by_the_convention() {
    let stepped =
        "O1\nG21 G99\nT0505 (GROOVE W3.)\nG97 S700 M3\nG0 X42. Z-15.\nG75 R0.5\nG75 X30. Z-20. P1500 Q2500 F0.08\nG0 X100. Z100.\nM30\n";
    let (ws, features) = labels(stepped, "fanuc_lathe");
    assert_eq!(ws, ["grooving rough"], "{features:?}");
    assert_eq!(features, ["groove"]);
    // The same cycle without its Z: one plunge, pecked, at the tool's width.
    let one = stepped.replace(" Z-20. P1500 Q2500", " P1500");
    let (ws, _) = labels(&one, "fanuc_lathe");
    assert_eq!(ws, ["grooving finish"]);
    // Plunges 4 apart with a 3 mm tool leave 1 mm between them: still the groove roughed.
    let apart = "O2\nG21 G99\nT0505 (OD GROOVE W3.)\nG97 S800 M3\nG0 X34. Z-12.\nG1 X26. F0.05\nG0 X34.\nZ-16.\nG1 X26.\nG0 X34.\nX100. Z100.\nM30\n";
    let (ws, _) = labels(apart, "fanuc_lathe");
    assert_eq!(ws, ["grooving rough"]);
}

/// Passes as the seen lathe_s12 programs write them (a Haas class program, Doosan shop programs,
/// a simulator's sample), each rule in a small program of its own: a face, then diameters
/// turned from it one each (a larger one further back: the outside, finished one at a time);
/// plunges left by a rapid back out, then a pass along the floor, rough the groove; a
/// `G71`/`G70` pair a grooving tool the program names runs outside turns a groove (another
/// tool's roughing finished by it stays contouring); straight roughing passes along Z and then
/// the whole profile at the same feed are roughing and finishing.
#[test]
fn passes_of_the_seen_s12_programs_read_as_a_turner_reads_them() {
    let face_then_steps = "O1\nG21 G99\nG50 S2000\nT0202\nG96 S200 M3\nG0 X20. Z2.5\nG1 Z0. F0.03\nX-2.5\nG0 X8.\nG1 Z-3.\n\
X8.5 Z-2.9\nG0 X20.\nZ-3.\nG1 X8.\nG0 X18.7 Z-2.9\nG1 Z-27.\nX20.\nG0 X100. Z100.\nM30\n";
    let (ws, features) = labels(face_then_steps, "fanuc_lathe");
    assert_eq!(ws, ["facing finish", "contouring finish"], "{features:?}");
    let plan = pipeline::analyze(face_then_steps.as_bytes(), &Registry::shipped().get("fanuc_lathe").unwrap(), &Profile::default()).plan;
    for d in [8.0, 18.7] {
        let found = plan
            .features
            .iter()
            .any(|f| matches!(f.kind, FeatureKind::Turned(Turned::Diameter { diameter, inside: false, .. }) if (diameter - d).abs() < TOL));
        assert!(found, "Ø{d}: {features:?}");
    }
    let plunged = "O2\nG21 G99\nT0303 (OD GROOVE W3.)\nG96 S150 M3\nG0 X12. Z-25.\nG1 X4.5 F0.1\nG0 X12.\nZ-26.5\nG1 X4.5\nG0 X12.\n\
Z-28.\nG1 X4.5\nG0 X12.\nZ-29.5\nG1 X4.2\nZ-25.\nG0 X12.\nX100. Z100.\nM30\n";
    let (ws, features) = labels(plunged, "fanuc_lathe");
    assert_eq!(ws.first().map(String::as_str), Some("grooving rough"), "{ws:?}");
    assert!(features.iter().all(|f| f == "groove"), "{features:?}");
    let cycle = "O3\nG21 G99\n(OD GROOVE TURN)\nT0808\nG96 S150 M3\nG0 X113. Z-6.\nG71 U1. R0.5\nG71 P10 Q20 U0.5 W0. F0.3\n\
N10 G1 X112. Z-6.5\nX100. Z-9.\nG2 X84. Z-25. R40.\nG1 Z-26.\nN20 X113.\nG70 P10 Q20 F0.15\nG0 X150. Z100.\nM30\n";
    let (ws, features) = labels(cycle, "fanuc_lathe");
    assert_eq!(ws, ["grooving rough", "grooving finish"]);
    assert!(features.contains(&"groove".to_owned()) && features.contains(&"revolved round".to_owned()), "{features:?}");
    let plan = pipeline::analyze(cycle.as_bytes(), &Registry::shipped().get("fanuc_lathe").unwrap(), &Profile::default()).plan;
    let groove = plan.features.iter().find_map(|f| match f.kind {
        FeatureKind::Turned(Turned::Groove { diameter, .. }) => Some(diameter),
        _ => None,
    });
    assert!(groove.is_some_and(|d| (d - 84.0).abs() < TOL), "{groove:?}");
    // A turning tool's pair is contouring; so is the grooving tool's finish of a contour
    // another tool roughed.
    let (ws, _) = labels(&cycle.replace("(OD GROOVE TURN)", "(OD TURN)"), "fanuc_lathe");
    assert_eq!(ws, ["contouring rough", "contouring finish"]);
    let other = cycle.replace("(OD GROOVE TURN)\nT0808", "(OD TURN)\nT0101").replace("G70 P10", "(OD GROOVE)\nT0808\nG70 P10");
    let (ws, _) = labels(&other, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough", "contouring finish"]);
    // (The roughing passes stop 0.2 short of the shoulders: the finish runs clear of their ends.)
    let rough_then_profile = "O4\nG21 G99\nT0101\nG97 S1000 M3\nG0 X32. Z2.\nX28.\nG1 Z-29.8 F0.2\nX29. Z-28.8\nG0 Z2.\nX24.\n\
G1 Z-19.8\nX25. Z-18.8\nG0 Z2.\nX20.\nG1 Z-9.8\nX21. Z-8.8\nG0 X16. Z2.\nG1 X18. Z0.\nZ-10.\nX22. Z-20.\nX26.\nZ-30.\nX32.\n\
G0 X100. Z100.\nM30\n";
    let (ws, features) = labels(rough_then_profile, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough", "contouring finish"], "{features:?}");
    assert_eq!(features.iter().filter(|f| *f == "outer diameter").count(), 2, "{features:?}");
    // Passes that end on the profile (a roughing cycle written as moves, its last pass along
    // the contour through their ends) are one roughing.
    let cycle_as_moves = rough_then_profile.replace("Z-29.8", "Z-30.").replace("Z-19.8", "Z-20.").replace("Z-9.8", "Z-10.");
    let (ws, _) = labels(&cycle_as_moves, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough"]);
}

/// A pass along a wall left by a rapid back out along +Z that pulls in off the wall a little is a
/// boring bar leaving its bore: inside work, an inner diameter. The same pass pulled off outwards
/// turns the outside; a pass down to the axis tells nothing so.
#[test]
fn a_pass_pulled_in_off_its_wall_bores() {
    let bore = "O1\nG21 G99\nT0404\nG97 S800 M3\nG0 X40. Z2.\nG1 X45. Z0. F0.1\nZ-30.\nG0 X44.5 Z5.\nX100. Z100.\nM30\n";
    let (ws, features) = labels(bore, "fanuc_lathe");
    assert_eq!(ws, ["contouring finish inside"], "{features:?}");
    assert!(features.contains(&"inner diameter".to_owned()), "{features:?}");
    let od = bore.replace("G0 X40. Z2.\nG1 X45. Z0.", "G0 X50. Z2.\nG1 X45. Z0.").replace("X44.5 Z5.", "X45.5 Z5.");
    let (ws, features) = labels(&od, "fanuc_lathe");
    assert_eq!(ws, ["contouring finish"], "{features:?}");
    assert!(features.contains(&"outer diameter".to_owned()), "{features:?}");
}

/// A post written for a lathe set to radius programming, with no arc whose centre tells: its
/// roughing passes' 45° pull-offs and its chamfers change X by as much as Z, which read as
/// diameters is half the slope of a 45° move. Read so, the part is Ø30 and Ø40; the same
/// program written with diameters shows nothing and gives the same sizes; two chamfers alone
/// are too weak to tell, and change nothing.
#[test]
fn radius_words_shown_by_45_degree_moves() {
    let sizes = |program: &str| -> (bool, Vec<f64>) {
        let d = Registry::shipped().get("fanuc_lathe").unwrap();
        let a = pipeline::analyze(program.as_bytes(), &d, &Profile::default());
        let shown = a.diagnostics.iter().any(|d| d.code == pipeline::Code::XWordsRadius);
        let mut ds: Vec<f64> = a
            .plan
            .features
            .iter()
            .filter_map(|f| match &f.kind {
                ncplan::plan::FeatureKind::Turned(ncplan::plan::Turned::Diameter { diameter, inside: false, .. }) => Some(*diameter),
                _ => None,
            })
            .collect();
        ds.sort_by(f64::total_cmp);
        ds.dedup();
        (shown, ds)
    };
    let radius = "O1\nG21 G99\nT0101\nG97 S800 M3\nG0 X26. Z2.\nG0 X25.\nG1 Z-40. F0.25\nX25.5 Z-39.5\nG0 Z2.\nG0 X24.5\nG1 Z-40.\nX25. Z-39.5\nG0 Z2.\nG0 X24.\nG1 Z-40.\nX24.5 Z-39.5\nG0 Z2.\nG0 X23.5\nG1 Z-40.\nX24. Z-39.5\nG0 Z2.\nG0 X23.\nG1 Z-40.\nX23.5 Z-39.5\nG0 Z2.\nG0 X22.5\nG1 Z-40.\nX23. Z-39.5\nG0 Z2.\nG0 X22.\nG1 Z-40.\nX22.5 Z-39.5\nG0 Z2.\nG0 X21.5\nG1 Z-40.\nX22. Z-39.5\nG0 Z2.\nG0 X21.\nG1 Z-40.\nX21.5 Z-39.5\nG0 Z2.\nG0 X20.5\nG1 Z-40.\nX21. Z-39.5\nG0 Z2.\nG0 X14.\nG1 Z0. F0.1\nX15. Z-1.\nZ-20.\nX19.\nX20. Z-21.\nZ-40.\nX26.\nG0 X100. Z100.\nM30\n";
    let diameter = "O1\nG21 G99\nT0101\nG97 S800 M3\nG0 X52. Z2.\nG0 X50.\nG1 Z-40. F0.25\nX51. Z-39.5\nG0 Z2.\nG0 X49.\nG1 Z-40.\nX50. Z-39.5\nG0 Z2.\nG0 X48.\nG1 Z-40.\nX49. Z-39.5\nG0 Z2.\nG0 X47.\nG1 Z-40.\nX48. Z-39.5\nG0 Z2.\nG0 X46.\nG1 Z-40.\nX47. Z-39.5\nG0 Z2.\nG0 X45.\nG1 Z-40.\nX46. Z-39.5\nG0 Z2.\nG0 X44.\nG1 Z-40.\nX45. Z-39.5\nG0 Z2.\nG0 X43.\nG1 Z-40.\nX44. Z-39.5\nG0 Z2.\nG0 X42.\nG1 Z-40.\nX43. Z-39.5\nG0 Z2.\nG0 X41.\nG1 Z-40.\nX42. Z-39.5\nG0 Z2.\nG0 X28.\nG1 Z0. F0.1\nX30. Z-1.\nZ-20.\nX38.\nX40. Z-21.\nZ-40.\nX52.\nG0 X100. Z100.\nM30\n";
    assert_eq!(sizes(radius), (true, vec![30.0, 40.0]));
    assert_eq!(sizes(diameter), (false, vec![30.0, 40.0]));
    // The finish alone: two chamfers, no finding, X read as written (diameters).
    let weak =
        "O1\nG21 G99\nT0101\nG97 S800 M3\nG0 X14. Z2.\nG1 Z0. F0.1\nX15. Z-1.\nZ-20.\nX19.\nX20. Z-21.\nZ-40.\nX26.\nG0 X100. Z100.\nM30\n";
    assert_eq!(sizes(weak), (false, vec![15.0, 20.0]));
}

/// A CAM post's roughing as NX writes it: each pass feeds along Z at a step in X, follows the
/// contour after its straight cut (arcs and a shoulder: the profile clean-up) and pulls off
/// at 45° the same way. The passes are one `contouring rough` with its depth of cut (the step
/// per side), the other tool's contour after it one `contouring finish`.
#[test]
fn roughing_passes_with_profile_clean_up_are_one_workingstep() {
    // Before, each pass was a workingstep of its own, each a `contouring finish`.
    let program = "O1\nG21 G99\nT0101\nG97 S1800 M3\nG0 X52. Z2.\n\
G0 X48.\nG1 Z1.6 F0.75\nZ-30. F0.5\nX50. Z-31. F0.75\nX50.6 Z-30.7 F1.25\nG0 Z2.\n\
X44.\nG1 Z1.6 F0.75\nZ-18.\nX45.\nG3 X47. Z-19. R1.\nG1 Z-29.5\nX48. Z-30.\nX48.6 Z-29.7 F1.25\nG0 Z2.\n\
X40.\nG1 Z1.6 F0.75\nZ-18.\nX44.\nX44.6 Z-17.7 F1.25\nG0 Z2.\n\
X100. Z100.\nT0202\nG96 S250 M3\nG0 X36. Z2.\nG1 X38. Z0. F0.1\nZ-18.\nX45.\nG3 X47. Z-19. R1.\nG1 Z-30.\nX52.\nG0 X100. Z100.\nM30\n";
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let plan = pipeline::analyze(program.as_bytes(), &d, &Profile::default()).plan;
    let ws: Vec<String> = plan.workingsteps.iter().map(|w| w.label()).collect();
    assert_eq!(ws, ["contouring rough", "contouring finish"]);
    let rough = plan.workingsteps[0].turning.as_deref().unwrap();
    assert_eq!(rough.passes, 3);
    assert_eq!(rough.intent.as_ref().and_then(|i| i.depth_of_cut), Some(2.0));
    // The same passes each pulling off another way are no one operation's.
    let other = program.replace("X48.6 Z-29.7 F1.25", "X49. Z-29.5 F1.25");
    let plan = pipeline::analyze(other.as_bytes(), &d, &Profile::default()).plan;
    assert!(plan.workingsteps.len() > 2, "{:?}", plan.workingsteps.iter().map(|w| w.label()).collect::<Vec<_>>());
}

/// A word a code names for itself is no axis in its block: Haas' one-block `G76 ... A60`
/// gives the tool's angle, so the thread's passes cut in X and Z with the A axis where it
/// was (before, every cut went to A60).
#[test]
fn a_word_a_cycle_names_is_no_axis_move() {
    use ncplan::canon::{Canon, CanonOp};
    let program = "O1000\nG28 U0 W0\nT101\nG97 S500 M03\nG0 X1.1 Z0.2\nG76 X0.9 Z-1.0 K0.0625 D0.01 F0.0625 A60\nG0 X2 Z1\nM30\n";
    let d = Registry::shipped().get("haas_lathe").unwrap();
    let mut ops: Vec<Canon> = Vec::new();
    let diags = pipeline::canon(program, &d, &Profile::default(), &mut ops);
    assert!(diags.iter().all(|d| !d.is_error()), "{diags:?}");
    let cuts: Vec<[f64; 6]> = ops
        .iter()
        .filter_map(|c| match c.op {
            CanonOp::StraightFeed(p) if c.line == 6 => Some(p),
            _ => None,
        })
        .collect();
    assert!(cuts.len() > 1, "the thread is cut in passes");
    for p in &cuts {
        assert_eq!(p[3], 0.0, "A stays at 0: {p:?}");
        assert!((p[2] + 1.0).abs() < 1e-9, "each pass ends at Z-1: {p:?}");
    }
}

/// A hole cycle on the lathe's axis drills with the part turning, even where the program
/// switches to G17 for it (LinuxCNC's G83 takes its depth along Z only in G17); off the axis
/// it stays a driven tool's milling. A grooving tool named in an operation header further up
/// (German `Einstechen`) cuts a groove with its pass along the contour.
#[test]
fn drilling_on_the_axis_and_a_named_grooving_tool() {
    let drill = "G18 G7 G21 G95\nT10 M6\nG97 S1000 M3\nG0 X0 Z5\nG17\nG83 X0 Y0 Z-30 R2 Q3 F0.12\nG80\nG18\nG0 X50 Z50\nM30\n";
    let (ws, features) = labels(drill, "linuxcnc");
    assert_eq!(ws, ["drilling"]);
    assert!(features.iter().all(|f| f == "round hole"), "{features:?}");
    let off_axis = drill.replace("G83 X0 Y0", "G83 X10 Y0");
    let (ws, _) = labels(&off_axis, "linuxcnc");
    assert!(ws.iter().all(|w| w != "drilling"), "{ws:?}");
    let groove = "G18 G7 G21 G95\n(Step 1: groove | T4: Einstechen MGMN200)\n(Werkzeug T04)\n(Toolchange move)\nG53 G0 X150 Z300\nT04 M6\n\
S900 M3\nG0 X25 Z2\nG1 X23 Z-13 F0.15\nZ-10\nX25\nG53 G0 X150 Z300\nM30\n";
    let (ws, features) = labels(groove, "linuxcnc");
    assert_eq!(ws, ["grooving finish"]);
    assert_eq!(features, ["groove"]);
    // The same pass by a tool no comment names is a contour.
    let (ws, _) = labels(&groove.replace("groove | T4: Einstechen MGMN200", "turn | T4: DCMT"), "linuxcnc");
    assert_eq!(ws, ["contouring finish"]);
}

/// A bar lathe or a rear tool post writes X negative: the tool works on the far side of the
/// axis. Inside or outside is then |X| against the part and the allowance and pull-off
/// pointing away from the axis, whatever the sign: a `G71` with `U-0.4` over a contour at X
/// negative turns the outside; the same cycle at X positive with `U-0.4` bores. A face cut
/// from X-22. to the centre is facing on that side. (One that runs over the centre to leave
/// no pip, to X1., is not mirrored: a workingstep is mirrored only where every cut lies at X
/// at or below 0, as LinuxCNC's compensated lathe tests need; such a face is facing all the same, a cut
/// across over the axis.)
#[test]
fn a_tool_beyond_the_centre_turns_the_outside() {
    let rear = "O1\nG21 G99\nT0101\nG97 S1000 M3\nG0 X-22. Z2.\nG1 Z0. F0.5\nX0. F0.1\nG0 Z2.\nX-22.\n\
G71 U1. R0.5\nG71 P10 Q20 U-0.4 W0.1 F0.2\nN10 G0 X-10.\nG1 Z-15.\nX-16.\nZ-30.\nN20 X-22.\nG70 P10 Q20\nG0 X-50. Z50.\nM30\n";
    let (ws, features) = labels(rear, "fanuc_lathe");
    assert_eq!(ws, ["facing finish", "contouring rough", "contouring finish"], "{features:?}");
    assert!(features.iter().any(|f| f == "outer diameter") && features.iter().all(|f| f != "inner diameter"), "{features:?}");
    let bore = "O1\nG21 G99\nT0101\nG97 S1000 M3\nG0 X8. Z2.\n\
G71 U1. R0.5\nG71 P10 Q20 U-0.4 W0.1 F0.2\nN10 G0 X22.\nG1 Z-15.\nX16.\nZ-30.\nN20 X8.\nG70 P10 Q20\nG0 X50. Z50.\nM30\n";
    let (ws, features) = labels(bore, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough inside", "contouring finish inside"], "{features:?}");
}

/// The radii of the revolved rounds a plan lists, in its order.
fn round_radii(plan: &ncplan::plan::ProcessPlan) -> Vec<f64> {
    plan.features
        .iter()
        .filter_map(|f| match &f.kind {
            FeatureKind::Turned(Turned::RevolvedRound { radius, .. }) => Some(*radius),
            _ => None,
        })
        .collect()
}

/// Under tool nose radius compensation the moves are the nose's path: the control rounds each
/// sharp outside corner with the nose radius and runs a nose radius off each programmed round.
/// The part is what the program states: a chamfer's corners are no R0.4 rounds, a concave R4
/// and a convex R2 keep their radii (the path's 3.6 and 2.4), with or without a tip orientation.
#[test]
fn rounds_are_the_programmed_contours_not_the_nose_path() {
    for l in ["", " L2"] {
        let p = format!(
            "G18 G7 G21 G95\nT1 M6\nS1000 M3\nG0 X40 Z2\nG0 X16 Z2\nG42.1 D0.8{l}\nG1 Z0 F0.1\nX20 Z-2\nZ-20\nG2 X28 Z-24 R4\nG1 X32\n\
G3 X36 Z-26 R2\nG1 Z-40\nG40\nG0 X50\nM2\n"
        );
        let d = Registry::shipped().get("linuxcnc").unwrap();
        let plan = pipeline::analyze(p.as_bytes(), &d, &Profile::default()).plan;
        let radii = round_radii(&plan);
        assert_eq!(radii, [4.0, 2.0], "L{l}: {:?}", plan.features.iter().map(|f| f.kind.label()).collect::<Vec<_>>());
    }
}

/// Under `G42` with the nose radius in the control's offsets (unknown here) the path is the
/// programmed contour: a small fillet turning into the material (concave, `G02 … R2` into a
/// shoulder) is the part's round, not the nose going round an outside corner, and the other
/// rounds keep their programmed radii.
#[test]
fn a_small_fillet_into_a_shoulder_is_no_nose_arc() {
    let p = "O1\nG21 G99\nT1111\nG50 S3000\nG96 S250 M3\nG0 G42 X14. Z2.\nG1 X0. Z0. F0.1\nG3 X10. Z-5. R5.\nG1 Z-13.\n\
G2 X14. Z-15. R2.\nG1 X18.\nZ-24.\nG2 X30. Z-30. R6.\nG1 X40.\nG0 G40 X100. Z50.\nM30\n";
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let plan = pipeline::analyze(p.as_bytes(), &d, &Profile::default()).plan;
    let radii = round_radii(&plan);
    assert_eq!(radii, [5.0, 2.0, 6.0], "{:?}", plan.features.iter().map(|f| f.kind.label()).collect::<Vec<_>>());
}

/// LinuxCNC's `G70`, `G71` and `G72` one after another over one profile, with nothing between
/// them but the cycles' own rapids (as LinuxCNC's manual and its quadrant demo write them), are
/// one operation each: a finish, the roughing along Z ending with its pass along the contour,
/// and a finish in two passes (`P2`) whose last pass gives the part. A face cut from the far
/// side of the axis over it (`X-6.` to `X1.`), after a feed in at 2 mm/rev, is facing at the
/// feed it cuts at; a contour cycle over a contour that is only a face is facing.
#[test]
fn back_to_back_profile_cycles_and_faces_as_a_turner_names_them() {
    let g7x = "G18 G21 G54\nF300\nT1 M6\nS800 M3\nO100 SUB\nG0 X4 Z1\nG1 Z-10\nX8 Z-14\nZ-20\nG0 X15\nO100 ENDSUB\nG0 X15 Z2\n\
G70 Q100 X15 Z2\nG71 Q100 X15 Z2 D0.5 I1 R0.3\nG70 Q100 X15 Z2 D0.5 P2\nG0 X20 Z10\nM2\n";
    let (ws, features) = labels(g7x, "linuxcnc");
    assert_eq!(ws, ["contouring finish", "contouring rough", "contouring finish"], "{features:?}");
    assert_eq!(features, ["outer diameter", "outer diameter", "revolved flat"]);
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let face = "O1\nG21 G99\nT0101\nG97 S1200 M3\nG0 Z10. X-10.\nZ0.5\nX-6.\nG1 Z0. F2.\nX1. F0.05\nG0 Z2.\nX-25.\nZ10.\nM30\n";
    let plan = pipeline::analyze(face.as_bytes(), &d, &Profile::default()).plan;
    assert_eq!(plan.workingsteps.iter().map(|w| w.label()).collect::<Vec<_>>(), ["facing finish"]);
    assert_eq!(plan.workingsteps[0].turning.as_ref().and_then(|t| t.feed_per_rev), Some(0.05));
    let face_cycle = "O1\nG20 G99\nT0101\nG50 S2500\nG96 S700 M3\nG0 X3.0 Z0.1\nG71 P10 Q20 U0.01 W0.005 D0.05 F0.010\n\
N10 G0 X-0.063 Z0.1\nG1 Z0.0\nX3.0\nN20 G0 Z0.1\nG70 P10 Q20 F0.005\nG0 X6. Z2.\nM30\n";
    let (ws, features) = labels(face_cycle, "haas_lathe");
    assert_eq!(ws, ["facing rough", "facing finish"]);
    assert_eq!(features, ["revolved flat"]);
}

/// Haas `G75` grooving (Haas lathe operator's manual): `I` the X peck and `K` the Z shift,
/// lengths with their decimal point, `P` the dwell. A groove made deeper is no peck change,
/// where the block states a peck and where it states none (the cycle then cuts to depth in
/// one plunge, no peck size of its own); a peck changed is told as the peck (issue 41, r293).
#[test]
fn a_groove_s_depth_is_no_peck() {
    let a = "%\nO01000\nG20 G99\nT101\nG97 S500 M3\nG0 X1.2 Z-0.5\nG75 X0.8 I0.05 F0.003\nG0 X2.0\nM30\n%\n";
    let rows = |a: &str, b: &str| {
        let d = Registry::shipped().get("haas_lathe").unwrap();
        let profile = Profile::default();
        let (pa, pb) = (pipeline::analyze(a.as_bytes(), &d, &profile), pipeline::analyze(b.as_bytes(), &d, &profile));
        let got = ncplan::diff::compare(
            ncplan::diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d },
            ncplan::diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d },
        );
        got.iter().map(|c| format!("{} | {} | {} | {}\n", c.kind.as_str(), c.field, c.before, c.after)).collect::<String>()
    };
    let deeper = rows(a, &a.replace("X0.8 I", "X0.6 I"));
    assert!(!deeper.contains("peck"), "{deeper}");
    assert!(!deeper.is_empty());
    let no_peck = a.replace(" I0.05", "");
    let deeper = rows(&no_peck, &no_peck.replace("X0.8", "X0.6"));
    assert!(!deeper.contains("peck"), "{deeper}");
    let peck = rows(a, &a.replace("I0.05", "I0.1"));
    assert!(peck.contains("cycle_parameter_changed | peck |"), "{peck}");
}

/// The holes of a feature in the part's frame, rounded to 0.001 mm: its positions turned onto
/// its face (for a face hole at C, the point (r·cos C, r·sin C) on the face).
fn hole_points(plan: &ProcessPlan) -> Vec<(i64, i64, i64)> {
    let round = |v: f64| (v * 1000.0).round() as i64;
    plan.workingsteps
        .iter()
        .flat_map(|w| w.toolpath.iter().filter(|m| m.phase == ncplan::plan::Phase::Cut))
        .map(|m| (round(m.to[0]), round(m.to[1]), round(m.to[2])))
        .collect()
}

/// Siemens 840D turns the main spindle, in position control on a lathe, with any form of
/// `SPOS`: `SPOS=IC(90)` on by 90°, `SPOS[1]=DC(180)` to 180° the short way; the face holes of
/// `siemens_live.mpf` come out at the same four points whichever form states the angle.
#[test]
fn lathe_spos_forms_turn_the_part_alike() {
    let text = std::fs::read_to_string(dir().join("siemens_live.mpf")).unwrap();
    let forms = text
        .replace("N130 SPOS=90", "N130 SPOS=IC(90)")
        .replace("N150 SPOS=180", "N150 SPOS[1]=DC(180)")
        .replace("N170 SPOS=270", "N170 SPOS=IC(90)");
    let reg = Registry::shipped();
    let d = reg.get("siemens").unwrap();
    let plain = pipeline::analyze(text.as_bytes(), &d, &Profile::default()).plan;
    let other = pipeline::analyze(forms.as_bytes(), &d, &Profile::default()).plan;
    assert_eq!(hole_points(&plain), hole_points(&other));
    let face = plain.features.iter().find(|f| matches!(&f.kind, FeatureKind::RoundHole { positions, .. } if positions.len() == 4));
    let face = face.expect("a pattern of four face holes");
    let FeatureKind::RoundHole { positions, .. } = &face.kind else { unreachable!() };
    let mut at: Vec<(i64, i64)> =
        positions.iter().map(|p| ((face.placement[0] + p[0]).round() as i64, (face.placement[1] + p[1]).round() as i64)).collect();
    at.sort_unstable();
    assert_eq!(at, vec![(-20, 0), (0, -20), (0, 20), (20, 0)]);
}

/// On a mill (X no diameter) `SPOS` only orients the spindle and CYCLE81 under G17 drills
/// where X and Y say, along Z: no C angle turns the hole.
#[test]
fn lathe_spos_on_a_mill_orients_the_spindle_only() {
    let text = "G17 G90 G94\nT1 M6\nS2000 M3 F100\nG0 X40 Y10 Z5\nSPOS=90\nCYCLE81(5,0,2,-10)\nG0 Z50\nM30\n";
    let reg = Registry::shipped();
    let plan = pipeline::analyze(text.as_bytes(), &reg.get("siemens").unwrap(), &Profile::default()).plan;
    let hole = plan.features.iter().find(|f| matches!(f.kind, FeatureKind::RoundHole { .. })).expect("a hole");
    assert_eq!((hole.placement[0].round(), hole.placement[1].round()), (40.0, 10.0));
    assert!(hole.axis.is_none(), "{:?}", hole.axis);
}

/// The canon of a Siemens program, as `ncplan canon` prints it.
fn siemens_canon(text: &str) -> Vec<String> {
    let reg = Registry::shipped();
    let d = reg.get("siemens").unwrap();
    let a = pipeline::analyze(text.as_bytes(), &d, &Profile::default());
    a.canon
        .iter()
        .map(|c| {
            let mut s = String::new();
            ncplan::canon::write_call(&mut s, &c.op);
            s
        })
        .collect()
}

/// Siemens numbers its spindles (840D programming manual: `M2=3`, `S2=2000`, `SPOS[2]=`):
/// the speed, the turning and the orientation of spindle 2 are that spindle's, between
/// `Spindle` markers, and spindle 1 is the main one; `M1=DIR` in a procedure (a value the
/// caller gives) stays unread as before. Spindle 2 oriented does not turn the part.
#[test]
fn live_spindle_numbers_are_kept_in_the_canon() {
    let calls = siemens_canon("N10 G18 G90 G95 DIAMON\nN20 S2=2000 M2=3\nN30 SPOS[2]=90\nN40 S1=500 M1=4\nN50 M2=5\nN60 M30\n");
    let at = |s: &str| calls.iter().position(|c| c.contains(s)).unwrap_or_else(|| panic!("no {s} in {calls:#?}"));
    let two = at("ncplan: spindle ops: spindle 2");
    assert!(two < at("SET_SPINDLE_SPEED(0, 2000.0000)"));
    assert!(at("SET_SPINDLE_SPEED(0, 2000.0000)") < at("START_SPINDLE_CLOCKWISE(0)"));
    let main = at("ncplan: spindle ops: main spindle");
    assert!(main > at("START_SPINDLE_CLOCKWISE(0)") && main < at("SET_SPINDLE_SPEED(0, 500.0000)"));
    // Spindle 1 is the main spindle: no marker before its speed.
    let s500 = at("SET_SPINDLE_SPEED(0, 500.0000)");
    assert!(!calls[s500 - 1].contains("spindle 2"), "{calls:#?}");
    assert_eq!(calls.iter().filter(|c| c.contains("ncplan: spindle ops: spindle 2")).count(), 3, "{calls:#?}");
    let procedure = siemens_canon("N100 PROC CYC(REAL VELO, INT DIR)\nN160 G0 X10 M1=DIR S1=VELO\nN170 RET\n");
    assert!(
        !procedure.iter().any(|c| c.contains("SPINDLE_SPEED") || c.contains("START_SPINDLE") || c.contains("spindle ops")),
        "{procedure:#?}"
    );
}

/// A driven end mill (spindle 2) milling keyways under G19 with the main spindle held by
/// `SPOS` is milling on radial planes at the C angles, in the tool's spindle terms; the lathe's
/// turning of Ø50 stays turning (`siemens_live_keyway.mpf`).
#[test]
fn live_keyways_mill_on_the_cylinder_with_the_driven_spindle() {
    let plan = plan_of(&dir().join("siemens_live_keyway.mpf"), "siemens");
    let milling: Vec<&Workingstep> = plan.workingsteps.iter().filter(|w| w.turning.is_none()).collect();
    assert_eq!(milling.len(), 2, "{:#?}", plan.workingsteps.iter().map(Workingstep::label).collect::<Vec<_>>());
    let axes: Vec<[f64; 3]> = milling.iter().map(|w| w.setup.expect("a radial plane").axis).collect();
    assert_eq!(axes, vec![[1.0, 0.0, 0.0], [-1.0, 0.0, 0.0]]);
    for w in &milling {
        assert_eq!(w.technology.spindle_id, ncplan::plan::SpindleId::Number(2));
        assert_eq!(w.technology.spindle_speed, 3000.0);
    }
    assert!(!plan.features.iter().any(|f| matches!(&f.kind, FeatureKind::Turned(Turned::Diameter { diameter, .. }) if *diameter < 49.0)));
}

/// Haas: `M133 P2500` turns the driven tool at 2500 /min; the face and radial cycles drill
/// with it (`haas_live_tools.nc`).
#[test]
fn live_haas_tool_drive_turns_the_drill() {
    let plan = plan_of(&dir().join("haas_live_tools.nc"), "haas_lathe");
    let drill = plan.workingsteps.iter().find(|w| w.tool == 5).expect("T5's workingstep");
    assert_eq!(drill.technology.spindle_id, ncplan::plan::SpindleId::Driven);
    assert_eq!((drill.technology.spindle_speed, drill.technology.surface_speed), (2500.0, None));
    let radial = plan.workingsteps.iter().find(|w| w.tool == 7).expect("T7's workingstep");
    assert_eq!(radial.technology.spindle_speed, 3000.0);
}

/// A program that writes its whole-number lengths without a decimal point (`X55 Z2`) and its
/// fractions with one (`X-1.6`) was written for calculator-type input (Fanuc parameter DPI on,
/// as on teaching lathes and many shops' controls): read so, with a finding that says why, and
/// not as 55 µm. A program that puts the point on its whole numbers (`X55.`) and slips once
/// keeps least-increment input and its warning about the slip.
#[test]
fn whole_numbers_without_a_point_by_habit_are_read_in_millimetres() {
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let calculator = "O1\nG21 G99\nT0101\nG50 S2000\nG96 S200 M3\nG0 X55 Z2\nG1 Z0 F0.2\nX-1.6\nG0 Z2\nX50\n\
G1 Z-30 F0.25\nX55\nG0 X100 Z50\nM30\n";
    let a = pipeline::analyze(calculator.as_bytes(), &d, &Profile::default());
    let codes: Vec<&str> = a.diagnostics.iter().map(|d| d.code.as_str()).collect();
    assert!(codes.contains(&"interp::decimal-input-inferred"), "{codes:?}");
    assert!(!codes.contains(&"interp::no-decimal-point"), "{codes:?}");
    // The face at Z0 across the Ø55 bar, and the Ø50 turned 30 long.
    let od = a.plan.features.iter().find_map(|f| match f.kind {
        FeatureKind::Turned(Turned::Diameter { diameter, length, inside: false }) => Some((diameter, length)),
        _ => None,
    });
    assert_eq!(od, Some((50.0, 30.0)), "{:?}", a.plan.features);
    let flat = a.plan.features.iter().find(|f| matches!(f.kind, FeatureKind::Turned(Turned::RevolvedFlat { .. })));
    assert!(flat.is_some_and(|f| f.placement[2] == 0.0), "{:?}", a.plan.features);
    // Points on its whole numbers, one slip (`X50`): least increments, and the slip is said.
    let pointed = calculator.replace("X55 Z2", "X55. Z2.").replace("G0 Z2", "G0 Z2.").replace("Z-30", "Z-30.").replace("X55\n", "X55.\n");
    let pointed = pointed.replace("X100 Z50", "X100. Z50.");
    let b = pipeline::analyze(pointed.as_bytes(), &d, &Profile::default());
    let codes: Vec<&str> = b.diagnostics.iter().map(|d| d.code.as_str()).collect();
    assert!(!codes.contains(&"interp::decimal-input-inferred"), "{codes:?}");
    assert!(codes.contains(&"interp::no-decimal-point"), "{codes:?}");
}

/// A machine whose configuration states its decimal input (`decimal_input` of its
/// `[[machine]]`) is read so whatever its programs' habit: the inference is for machines whose
/// setting is not known. Stated least-increment input keeps `X55` at 55 µm (with the warning);
/// stated calculator input reads it as 55 mm with no inference finding.
#[test]
fn a_stated_decimal_input_is_not_overridden_by_a_program_habit() {
    let calculator = "O1\nG21 G99\nT0101\nG50 S2000\nG96 S200 M3\nG0 X55 Z2\nG1 Z0 F0.2\nX-1.6\nG0 Z2\nX50\n\
G1 Z-30 F0.25\nX55\nG0 X100 Z50\nM30\n";
    let dir = tempfile::tempdir().unwrap();
    for rule in ["least-increment", "calculator"] {
        let text =
            format!("[database]\npath = 'db'\n[[machine]]\nname = 'L1'\npath = 'l1'\ndialect = 'fanuc_lathe'\ndecimal_input = '{rule}'\n");
        let config = ncplan::config::Config::parse(&text, dir.path()).unwrap();
        let d = config.folders[0].dialect_for(Registry::shipped().get("fanuc_lathe").unwrap());
        let a = pipeline::analyze(calculator.as_bytes(), &d, &Profile::default());
        let codes: Vec<&str> = a.diagnostics.iter().map(|d| d.code.as_str()).collect();
        assert!(!codes.contains(&"interp::decimal-input-inferred"), "{rule}: {codes:?}");
        let od = a.plan.features.iter().find_map(|f| match f.kind {
            FeatureKind::Turned(Turned::Diameter { diameter, inside: false, .. }) => Some(diameter),
            _ => None,
        });
        if rule == "calculator" {
            assert_eq!(od, Some(50.0), "{:?}", a.plan.features);
        } else {
            assert!(codes.contains(&"interp::no-decimal-point"), "{codes:?}");
            assert_ne!(od, Some(50.0), "{:?}", a.plan.features);
        }
    }
}

/// A grooving cycle that plunges to the axis at several places along Z, stepping down to the
/// front at Z0, faces the bar (a turner's `G75` facing); at one place behind the part it parts
/// off.
#[test]
fn a_grooving_cycle_that_steps_to_the_front_faces() {
    let face = "O1\nG21 G99\nT0101\nG50 S3000\nG96 S250 M3\nG0 X44. Z3.\nG75 R0.5\nG75 X-1.6 Z0. P5000 Q1000 F0.1\n\
G0 X100. Z50.\nM30\n";
    let (ws, features) = labels(face, "fanuc_lathe");
    assert_eq!(ws, ["facing rough"]);
    assert_eq!(features, ["revolved flat"]);
    let part = "O2\nG21 G99\nT0505\nG97 S600 M3\nG0 X44. Z-52.\nG75 R0.5\nG75 X-1. Z-52. P5000 F0.08\nG0 X100. Z50.\nM30\n";
    let (ws, _) = labels(part, "fanuc_lathe");
    assert_eq!(ws, ["parting off"]);
}

/// A cut to the axis nearer the part's front than its back faces, though a first face lies
/// in front of it (the face taken in two steps, Z1.5 then Z0: the first pass roughs, leaving
/// the stock the second finishes); behind the part it parts off.
#[test]
fn a_second_face_behind_the_first_is_facing_not_parting() {
    let program = "O1\nG21 G99\nT0707\nG96 S255 M3\nG0 X55. Z1.5\nG1 X-0.5 F0.2\nG0 Z3.\nX53.\nZ0.\nG1 X-0.5 F0.1\n\
G0 Z1.\nX100. Z50.\nT0101\nG97 S800 M3\nG0 X50. Z1.\nG1 Z-40. F0.2\nX55.\nG0 X100. Z50.\nT0505\nG97 S600 M3\n\
G0 X55. Z-45.\nG1 X-0.5 F0.05\nG0 X100.\nZ50.\nM30\n";
    let (ws, features) = labels(program, "fanuc_lathe");
    assert_eq!(ws.first().map(String::as_str), Some("facing rough"), "{ws:?}");
    assert_eq!(ws.get(1).map(String::as_str), Some("facing finish"), "{ws:?}");
    assert_eq!(ws.last().map(String::as_str), Some("parting off"), "{ws:?}");
    assert!(features.contains(&"revolved flat".to_owned()), "{features:?}");
}

/// The thread a cycle cuts ends where its last pass leaves the work: LinuxCNC's `G76 ... E L2`
/// tapers the pass out over E before the drive line's end (rs274: the full-depth cut stops
/// 1.5 short of Z-20, the taper runs on to it), and the thread is 20 long, from the face to
/// Z-20, as without the taper.
#[test]
fn a_thread_runs_through_its_tapered_run_out() {
    let thread = |program: &str| {
        let d = Registry::shipped().get("linuxcnc").unwrap();
        let plan = pipeline::analyze(program.as_bytes(), &d, &Profile::default()).plan;
        let threads: Vec<(Option<f64>, f64, f64, f64)> = plan
            .features
            .iter()
            .filter_map(|f| match &f.kind {
                FeatureKind::Turned(Turned::Thread { diameter, root, pitch, length, .. }) => Some((*diameter, *root, *pitch, *length)),
                _ => None,
            })
            .collect();
        threads
    };
    // Radius mode: drive line at radius 6, crests at 5 (Ø10), K0.92 deep (root Ø8.16).
    let tapered = "G8 G18 G21\nT1 M6\nS600 M3\nG0 X6 Z3\nG76 P1.5 Z-20 I-1 J0.2 K0.92 R1.5 Q29.5 H1 E1.5 L2\nG0 X15\nM2\n";
    assert_eq!(thread(tapered), [(Some(10.0), 8.16, 1.5, 20.0)]);
    let straight = "G8 G18 G21\nT1 M6\nS600 M3\nG0 X6 Z3\nG76 P1.5 Z-20 I-1 J0.2 K0.92 R1.5 Q29.5 H1\nG0 X15\nM2\n";
    assert_eq!(thread(straight), [(Some(10.0), 8.16, 1.5, 20.0)]);
}

/// A recess in an outside finishing contour (an undercut: down from Ø22 to Ø18 between Z-15
/// and Z-20, up again, and on along Z) is a groove 5 wide, not a diameter; a pass over the
/// recess alone that climbs out and leaves tells none, nor does a contour that only steps
/// outwards.
#[test]
fn a_recess_in_a_finishing_contour_is_a_groove() {
    let grooves = |program: &str| {
        let d = Registry::shipped().get("fanuc_lathe").unwrap();
        let plan = pipeline::analyze(program.as_bytes(), &d, &Profile::default()).plan;
        let all: Vec<String> = plan.features.iter().map(|f| f.kind.label().to_owned()).collect();
        let grooves: Vec<(f64, Option<f64>)> = plan
            .features
            .iter()
            .filter_map(|f| match &f.kind {
                FeatureKind::Turned(Turned::Groove { diameter, width, .. }) => Some((*diameter, *width)),
                _ => None,
            })
            .collect();
        let small: Vec<f64> = plan
            .features
            .iter()
            .filter_map(|f| match &f.kind {
                FeatureKind::Turned(Turned::Diameter { diameter, .. }) if *diameter < 20.0 => Some(*diameter),
                _ => None,
            })
            .collect();
        (grooves, small, all)
    };
    let head = "O1\nG21 G99\nT0101\nG50 S2000\nG96 S200 M3\n";
    let undercut = format!(
        "{head}G0 X-1. Z2.\nG1 Z0. F0.1\nX20.\nX22. Z-1.\nZ-15.\nX18. Z-16.\nZ-20.\nX22.\nZ-30.\nX30.\nX32. Z-31.\nZ-40.\nX40.\nG0 X100. Z50.\nM30\n"
    );
    let (g, small, all) = grooves(&undercut);
    assert_eq!(g, [(18.0, Some(5.0))], "{all:?}");
    assert!(small.is_empty(), "{small:?}");
    let alone = format!("{head}G0 X24. Z-14.\nG1 X22. F0.05\nX18. Z-16.\nZ-20.\nX24.\nG0 X100. Z50.\nM30\n");
    assert!(grooves(&alone).0.iter().all(|(_, w)| *w != Some(5.0)), "{:?}", grooves(&alone));
    let stepped = format!("{head}G0 X-1. Z2.\nG1 Z0. F0.1\nX18.\nZ-15.\nX22.\nZ-30.\nX32.\nZ-40.\nX40.\nG0 X100. Z50.\nM30\n");
    assert!(grooves(&stepped).0.is_empty(), "{:?}", grooves(&stepped));
}

/// On a control that reads a length without a point in least increments (Fanuc), a program
/// that writes its whole lengths without a point and its fractions with one (`X44 ... X-1.6`)
/// is written for calculator-type input (parameter 3401#0 DPI = 1): a finding, and it is read
/// so (Ø40 turned 20 long, not Ø0.04). A program with one point dropped among lengths written
/// with points keeps its least-increment reading and its `no-decimal-point` finding; one
/// written all in increments (`X44000`, no fraction anywhere) is read in increments.
#[test]
fn whole_lengths_without_points_beside_fractions_are_calculator_input() {
    use ncplan::diag::Code;
    let read = |program: &str| {
        let d = Registry::shipped().get("fanuc_lathe").unwrap();
        let a = pipeline::analyze(program.as_bytes(), &d, &Profile::default());
        let codes: Vec<Code> = a.diagnostics.iter().map(|d| d.code).collect();
        let diameters: Vec<(f64, f64)> = a
            .plan
            .features
            .iter()
            .filter_map(|f| match &f.kind {
                FeatureKind::Turned(Turned::Diameter { diameter, length, .. }) => Some((*diameter, *length)),
                _ => None,
            })
            .collect();
        (codes, diameters)
    };
    let calculator =
        "O1\nG21 G99\nT0101\nG50 S2000\nG96 S200 M3\nG0 X44 Z2\nG1 X-1.6 Z0 F0.2\nG0 Z2\nX40\nG1 Z-20\nX44\nG0 X100 Z50\nM30\n";
    let (codes, diameters) = read(calculator);
    assert!(codes.contains(&Code::DecimalInputInferred), "{codes:?}");
    assert!(!codes.contains(&Code::NoDecimalPoint), "{codes:?}");
    assert!(diameters.contains(&(40.0, 20.0)), "{diameters:?}");
    let dropped =
        "O1\nG21 G99\nT0101\nG50 S2000\nG96 S200 M3\nG0 X44. Z2.\nG1 X-1.6 Z0. F0.2\nG0 Z2.\nX40.\nG1 Z-20.\nX44\nG0 X100. Z50.\nM30\n";
    let (codes, _) = read(dropped);
    assert!(!codes.contains(&Code::DecimalInputInferred), "{codes:?}");
    assert!(codes.contains(&Code::NoDecimalPoint), "{codes:?}");
    let increments = "O1\nG21 G99\nT0101\nG50 S2000\nG96 S200 M3\nG0 X44000 Z2000\nG1 X-1600 Z0 F0.2\nG0 Z2000\nX40000\nG1 Z-20000\nX44000\nG0 X100000 Z50000\nM30\n";
    let (codes, diameters) = read(increments);
    assert!(!codes.contains(&Code::DecimalInputInferred), "{codes:?}");
    assert!(diameters.contains(&(40.0, 20.0)), "{diameters:?}");
}

/// A cut-off tool fed from outside only just past the bore the part already has parts it off
/// (a tube falls off once the wall is cut through): by a `G75` plunge after a named drill of
/// known diameter, and by plunges written as moves after an inside turning pass. A groove
/// whose bottom stays outside the bore is still a groove.
#[test]
fn a_plunge_through_to_the_bore_parts_off() {
    // A Ø20 drill through to Z-45, then a G75 plunge at Z-30 from Ø52 to Ø19.
    let drilled = "O1\nG21 G99\nT0101 (DRILL D20)\nG97 S800 M3\nG0 X0. Z2.\nG1 Z-45. F0.15\nG0 Z2.\nX100. Z50.\n\
T0202 (PARTING TOOL W3)\nG50 S2000\nG96 S120 M3\nG0 X52. Z-30.\nG75 R0.5\nG75 X19. P2000 F0.05\nG0 X100. Z50.\nM30\n";
    let (ws, features) = labels(drilled, "fanuc_lathe");
    assert_eq!(ws.last().map(String::as_str), Some("parting off"), "{ws:?}");
    assert!(!features.contains(&"groove".to_owned()), "{features:?}");
    // The same plunge stopping at Ø30, outside the Ø20 hole: a groove.
    let (ws, features) = labels(&drilled.replace("X19. P2000", "X30. P2000"), "fanuc_lathe");
    assert_eq!(ws.last().map(String::as_str), Some("grooving finish"), "{ws:?}");
    assert!(features.contains(&"groove".to_owned()), "{features:?}");
    // A bore turned Ø40 to Z-25 (a boring bar's pass), then a plunge from Ø62 to Ø39 at Z-20
    // written as moves, left by a rapid out.
    let bored = "O2\nG21 G99\nT0303 (BORING BAR)\nG97 S900 M3\nG0 X38. Z2.\nG1 X40. Z0. F0.15\nZ-25.\nX38.\nG0 Z2.\n\
X100. Z50.\nT0404 (GROOVE W3)\nG97 S600 M3\nG0 X62. Z-20.\nG1 X39. F0.05\nG0 X70.\nX100. Z50.\nM30\n";
    let (ws, _) = labels(bored, "fanuc_lathe");
    assert_eq!(ws.last().map(String::as_str), Some("parting off"), "{ws:?}");
    // The plunge in front of the bore's end but stopping at Ø44: a groove.
    let (ws, _) = labels(&bored.replace("G1 X39. F0.05", "G1 X44. F0.05"), "fanuc_lathe");
    assert_eq!(ws.last().map(String::as_str), Some("grooving finish"), "{ws:?}");
}

/// A grooving tool the program names, finishing a profile that steps down along -Z and never
/// climbs back out (a spigot a part-off then ends), turns a contour: its diameters, not a
/// groove. The same tool turning out a recess (down, along, back up) still grooves.
#[test]
fn a_grooving_tools_descending_profile_is_a_contour() {
    let spigot = "O1\nG21 G99\nT1010 (OD GROOVE W3)\nG50 S2500\nG96 S150 M3\nG0 X66. Z1.\nG1 X61. Z0. F0.08\n\
X63. Z-1.\nZ-6.\nX56. Z-8.\nZ-17.\nX54. Z-18.\nG0 X70.\nX100. Z50.\nM30\n";
    let (ws, features) = labels(spigot, "fanuc_lathe");
    assert_eq!(ws, ["contouring finish"], "{features:?}");
    assert!(!features.contains(&"groove".to_owned()), "{features:?}");
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let plan = pipeline::analyze(spigot.as_bytes(), &d, &Profile::default()).plan;
    let diameters: Vec<f64> = plan
        .features
        .iter()
        .filter_map(|f| match &f.kind {
            FeatureKind::Turned(Turned::Diameter { diameter, inside: false, .. }) => Some(*diameter),
            _ => None,
        })
        .collect();
    assert_eq!(diameters, [63.0, 56.0]);
    // Down into a recess, along its bottom and back out: a groove.
    let recess = "O2\nG21 G99\nT1010 (OD GROOVE W3)\nG97 S800 M3\nG0 X66. Z-10.\nG1 X50. F0.08\nZ-20.\nX66.\nG0 X100. Z50.\nM30\n";
    let (ws, features) = labels(recess, "fanuc_lathe");
    assert!(ws.iter().all(|w| w.starts_with("grooving")), "{ws:?}");
    assert!(features.contains(&"groove".to_owned()), "{features:?}");
    // Plunged straight to a floor and along it, left by a rapid: a groove's floor.
    let floor = recess.replace("Z-20.\nX66.\n", "Z-20.\nG0 X66.\n");
    let (ws, _) = labels(&floor, "fanuc_lathe");
    assert!(ws.iter().all(|w| w.starts_with("grooving")), "{ws:?}");
}

/// A roughing boring bar's passes, the last along the whole bore to its floor, then a finishing
/// bar that bores only the front part: behind the finish's reach the bore is as the roughing
/// profile left it (its Ø33 and its floor at Z-25.6); in front, the finish gives the part
/// (Ø31.8, not the roughed Ø31.6). A roughing pass nothing finishes after it leaves the part.
#[test]
fn a_bore_beyond_the_finishing_bars_reach_is_the_roughing_profiles() {
    let p = "O1\nG21 G99\nT0505 (DRILL D18)\nG97 S1400 M3\nG0 X0. Z2.\nG1 Z-40. F0.08\nG0 Z2.\nX100. Z50.\n\
T0404 (BORING BAR ROUGH)\nG50 S2000\nG96 S120 M3\nG0 X25. Z2.\nZ-21.\nG1 Z-25. F0.1\nX32.2\nG0 X25.\nZ3.\n\
G1 X34.2 Z0.\nX31.6 Z-1.2\nZ-20.5\nX33. Z-22.739\nZ-25.6\nX19.\nG0 Z15.\nX100. Z50.\n\
T1111 (BORING BAR FINISH)\nG96 S150 M3\nG0 X32.8 Z3.\nG1 X31.8 Z0. F0.1\nZ-22.\nG0 X25.\nZ15.\nX100. Z50.\nM30\n";
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let plan = pipeline::analyze(p.as_bytes(), &d, &Profile::default()).plan;
    let labels: Vec<String> = plan.workingsteps.iter().map(|w| w.label()).collect();
    assert_eq!(labels, ["drilling", "contouring rough inside", "contouring finish inside"]);
    let bores: Vec<f64> = plan
        .features
        .iter()
        .filter_map(|f| match &f.kind {
            FeatureKind::Turned(Turned::Diameter { diameter, inside: true, .. }) => Some(*diameter),
            _ => None,
        })
        .collect();
    assert_eq!(bores, [33.0, 31.8]);
    let floor = plan.features.iter().find(|f| matches!(f.kind, FeatureKind::Turned(Turned::RevolvedFlat { .. })));
    assert_eq!(floor.map(|f| f.placement[2]), Some(-25.6));
    // The finishing bar on another work offset (`G55` after an optional stop) finishes another
    // part: nothing finishes the G54 bore, so its roughing profile is the part's, Ø31.6 too.
    let moved = p.replace("T1111 (BORING BAR FINISH)\n", "M1\nG55\nT1111 (BORING BAR FINISH)\n");
    let plan = pipeline::analyze(moved.as_bytes(), &d, &Profile::default()).plan;
    let bores: Vec<(f64, f64)> = plan
        .features
        .iter()
        .filter_map(|f| match &f.kind {
            FeatureKind::Turned(Turned::Diameter { diameter, length, inside: true }) => Some((*diameter, *length)),
            _ => None,
        })
        .collect();
    assert!(bores.iter().any(|&(dia, len)| dia == 31.6 && (len - 19.3).abs() < 1e-6), "{bores:?}");
    // A roughing operation's one pass (its comment names it) that nothing finishes after it:
    // the shape the program leaves is that pass's, its Ø56.
    let rough = "O2\nG21 G99\nT0101\nG50 S3000\nG96 S320 M4\n(ROUGHING)\nG0 X52. Z2.\nG1 Z0. F0.3\nX56. Z-2.\nZ-30.\nX62.\n\
G0 X200. Z50.\nM30\n";
    let plan = pipeline::analyze(rough.as_bytes(), &d, &Profile::default()).plan;
    assert_eq!(plan.workingsteps.iter().map(|w| w.label()).collect::<Vec<_>>(), ["contouring rough"]);
    let od = plan.features.iter().find_map(|f| match f.kind {
        FeatureKind::Turned(Turned::Diameter { diameter, length, inside: false }) => Some((diameter, length)),
        _ => None,
    });
    assert_eq!(od, Some((56.0, 28.0)), "{:?}", plan.features);
}

/// One pass, then the same tool over the same stretch at a finer feed: roughing, then
/// finishing. Outside (a pass at Ø72.6, then the chamfered Ø72.1 at half the feed) and in a
/// bore (a pass at Ø65.4 left by a rapid in towards the axis, then the Ø66 bore finished: the
/// pass lies inside the finished bore, so it roughed the inside).
#[test]
fn one_pass_then_a_finer_pass_of_the_same_tool_roughs_and_finishes() {
    let od = "O1\nG21 G99\nT1212\nG97 S1250 M3\nG0 X72.6 Z1.\nG1 Z-21. F0.15\nG0 X86.\nZ1.\nX70.4\nG1 Z0. F0.076\n\
X72.1 Z-1.\nZ-21.\nG0 X86.\nX100. Z50.\nM30\n";
    let (ws, features) = labels(od, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough", "contouring finish"], "{features:?}");
    let id = "O2\nG21 G99\nT0909\nG97 S890 M3\nG0 X65.4 Z1.\nG1 Z-21. F0.15\nG0 X60.\nZ1.\nX68.8\nG1 Z0. F0.1\n\
X66. Z-1.4\nZ-21.\nG0 X60.\nZ50.\nX100.\nM30\n";
    let (ws, features) = labels(id, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough inside", "contouring finish inside"], "{features:?}");
    // At one feed nothing parts them: one workingstep of two passes, as before.
    let (ws, _) = labels(&od.replace("F0.076", "F0.15"), "fanuc_lathe");
    assert_eq!(ws, ["contouring rough"]);
}

/// The finding of calculator-type input points at its evidence: the first whole number written
/// without a decimal point, or the R of the first arc that reaches its end only with that R in
/// whole units.
#[test]
fn calculator_input_finding_points_at_its_evidence() {
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let finding = |program: &str| {
        let a = pipeline::analyze(program.as_bytes(), &d, &Profile::default());
        let f = a.diagnostics.iter().find(|x| x.code.as_str() == "interp::decimal-input-inferred").cloned();
        f.map(|f| program[f.range.start as usize..f.range.end as usize].to_owned())
    };
    let bare = "O1\nG21 G99\nT0101\nG50 S2000\nG96 S200 M3\nG0 X44 Z2\nG1 X-1.6 Z0 F0.2\nG0 Z2\nX40\nG1 Z-20\nX44\nG0 X100 Z50\nM30\n";
    assert_eq!(finding(bare).as_deref(), Some("X44"));
    // Points on every length, two rounds given by `R2` (0.002 mm on least-increment input
    // cannot join the ends 4 mm apart; 2 mm can).
    let arcs = "O2\nG21 G99\nT0101\nG97 S800 M3\nG0 X30. Z2.\nG1 Z0. F0.2\nG3 X34. Z-2. R2\nG1 Z-20.\n\
G2 X38. Z-22. R2\nG1 X44.\nG0 X100. Z50.\nM30\n";
    assert_eq!(finding(arcs).as_deref(), Some("R2"));
}

/// The calculator-input finding of a program whose bare numbers stand in a subprogram file
/// it calls points at the main program's call (`M98 P1234`), not at a place in the other file.
#[test]
fn calculator_input_evidence_in_a_called_file_points_at_the_call() {
    let dir = tempfile::tempdir().unwrap();
    let main = "O1\nG21 G99\nT0101\nM98 P1234\nM30\n";
    let sub = "O1234\nG50 S2000\nG96 S200 M3\nG0 X44 Z2\nG1 X-1.6 Z0 F0.2\nG0 Z2\nX40\nG1 Z-20\nX44\nG0 X100 Z50\nM99\n";
    std::fs::write(dir.path().join("main.nc"), main).unwrap();
    std::fs::write(dir.path().join("O1234.nc"), sub).unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_ncplan"))
        .args(["check", "-d", "fanuc_lathe", "--format", "json"])
        .arg(dir.path().join("main.nc"))
        .output()
        .unwrap();
    let json: serde_json::Value =
        serde_json::from_slice(&out.stdout).unwrap_or_else(|e| panic!("{e}: {}", String::from_utf8_lossy(&out.stdout)));
    let found = json["diagnostics"].as_array().and_then(|ds| ds.iter().find(|d| d["code"] == "interp::decimal-input-inferred"));
    let f = found.unwrap_or_else(|| panic!("no calculator-input finding: {json}"));
    let call = main.find("M98 P1234").unwrap();
    assert_eq!((f["line"].as_u64(), f["start"].as_u64(), f["end"].as_u64()), (Some(4), Some(call as u64), Some((call + 9) as u64)), "{f}");
}

/// A boring bar leaves the wall it cut towards the axis (an outside tool leaves it away from
/// the axis): passes that end, and are left, by a move straight in X to a smaller diameter
/// work inside, as CAM posts and turners write bores (a bore's roughing stepping the bottom
/// out then pulling in, its finishing pass then `G0 X` below the bore).
#[test]
fn passes_left_towards_the_axis_bore() {
    // Roughing the bottom of a drilled Ø14 hole out to Ø17, then the bore Ø15.5 with a chamfer
    // at its mouth; each pass left towards the axis. Then the finishing pass Ø16, left the same way.
    let bore = "O1\nG21 G99\nT0404\nG96 S120 M4\nG50 S2000\nG0 X14. Z2.\nZ-16.\nG1 Z-19. F0.1\nX17.\nG0 X14.\nZ2.\n\
X20.\nG1 X17.5 Z0.\nX15.5 Z-1.\nZ-16.\nG0 X13.\nZ10.\nT1111\nG0 X20. Z2.\nG1 X18. Z0. F0.06\nX16. Z-1.\nZ-16.\n\
G0 X13.\nZ10.\nM30\n";
    let (ws, features) = labels(bore, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough inside", "contouring finish inside"]);
    assert!(features.contains(&"inner diameter".to_owned()), "{features:?}");
    assert!(!features.contains(&"outer diameter".to_owned()), "{features:?}");
    // A finishing pass that pulls straight in along X by feed before its rapid out along Z
    // (a Fanuc 0T tube's bore): inside.
    let pull_in = "O3\nG21 G99\nT0404\nG96 S200 M4\nG0 X31. Z1.\nG1 X30. Z0. F0.1\nZ-20.\nX28.\nG0 Z5.\nM30\n";
    let (ws, features) = labels(pull_in, "fanuc_lathe");
    assert_eq!(ws, ["contouring finish inside"]);
    assert!(features.contains(&"inner diameter".to_owned()) && !features.contains(&"outer diameter".to_owned()), "{features:?}");
    let pull_out = "O4\nG21 G99\nT0404\nG96 S200 M4\nG0 X29. Z1.\nG1 X30. Z0. F0.1\nZ-20.\nX32.\nG0 Z5.\nM30\n";
    let (ws, _) = labels(pull_out, "fanuc_lathe");
    assert_eq!(ws, ["contouring finish"]);
    // The outside counterpart, left away from the axis: outside.
    let od = "O2\nG21 G99\nT0101\nG96 S120 M4\nG50 S2000\nG0 X44. Z2.\nG1 X40. Z0. F0.2\nZ-20.\nG0 X46.\nZ2.\n\
T0303\nG0 X36. Z2.\nG1 X38. Z0. F0.06\nX39. Z-0.5\nZ-20.\nG0 X46.\nZ10.\nM30\n";
    let (ws, features) = labels(od, "fanuc_lathe");
    assert!(ws.iter().all(|w| !w.contains("inside")), "{ws:?}");
    assert!(features.contains(&"outer diameter".to_owned()), "{features:?}");
}

/// A Siemens block may stop or start several spindles together, each by its number
/// (`M2=5 M3=5 M5`: spindles 2 and 3 and the master). The control runs it; the analysis follows
/// one spindle a block and keeps the others' codes as intent: no error.
#[test]
fn several_numbered_spindles_in_one_block_are_no_error() {
    let d = Registry::shipped().get("siemens").unwrap();
    let text = "G18 G90 G95 DIAMON\nS2=2000 M2=3\nS3=1500 M3=3\nG0 X40 Z2\nG1 Z-10 F0.1\nG0 X60\nM2=5 M3=5 M5\nM30\n";
    let a = pipeline::analyze(text.as_bytes(), &d, &Profile::default());
    assert!(!a.has_errors(), "{:?}", a.diagnostics);
    assert!(
        a.diagnostics.iter().any(|x| x.code.as_str() == "syntax::unmodelled" && x.message.contains("several spindles")),
        "{:?}",
        a.diagnostics
    );
}

/// A Sinumerik lathe as the 840D sl programming manual describes it, in programs written
/// from it (expectations written before running): G93-G97 and G961-G973 one modal group (15),
/// G96 a constant cutting rate with the feed per revolution, G95 after it its end; X a
/// diameter in G18 by a lathe's reset values (DIAMON), shown by its turning words, unless the
/// program states DIAMOF.
#[test]
fn a_sinumerik_lathe_reads_as_its_reset_state_and_feed_type_say() {
    use ncplan::canon::{CanonOp, FeedMode};
    let d = Registry::shipped().get("siemens").unwrap();
    let ops = |program: &str| {
        let mut ops = Vec::new();
        pipeline::canon(program, &d, &Profile::default(), &mut ops);
        ops.into_iter().map(|c| c.op).collect::<Vec<_>>()
    };
    // G96 after G94: F is per revolution from there.
    let css = ops("G18 G90 DIAMON\nT1 D1\nG94 F100\nG96 S200 LIMS=3000 M4\nG0 X50 Z2\nG1 Z-20 F0.2\nM30\n");
    assert!(css.iter().any(|op| matches!(op, CanonOp::SetSpindleMode(Some(m)) if *m == 3000.0)), "{css:?}");
    let per_rev = css.iter().position(|op| matches!(op, CanonOp::SetFeedMode(FeedMode::PerRevolution))).expect("per revolution");
    let cut = css.iter().position(|op| matches!(op, CanonOp::StraightFeed(_))).unwrap();
    assert!(per_rev < cut, "{css:?}");
    // G95 after G96 ends the constant cutting rate; G97 keeps the feed per revolution.
    let ended = ops("G18 G90 DIAMON\nT1 D1\nG96 S200 LIMS=3000 M4\nG95 F0.2\nG0 X50 Z2\nG1 Z-20\nM30\n");
    assert!(matches!(ended.iter().rev().find(|op| matches!(op, CanonOp::SetSpindleMode(_))), Some(CanonOp::SetSpindleMode(None))));
    let g97 = ops("G18 G90 DIAMON\nT1 D1\nG96 S200 LIMS=3000 M4\nG97 S800\nG0 X50 Z2\nG1 Z-20 F0.2\nM30\n");
    assert!(!g97.iter().any(|op| matches!(op, CanonOp::SetFeedMode(FeedMode::PerMinute))), "{g97:?}");
    // No DIAMON stated: a lathe's words (G96, LIMS) show the reset state, X a diameter.
    let turned = |program: &str| {
        let a = pipeline::analyze(program.as_bytes(), &d, &Profile::default());
        let found = a.diagnostics.iter().any(|x| x.code.as_str() == "interp::x-words-diameter");
        let diameters: Vec<f64> = a
            .plan
            .features
            .iter()
            .filter_map(|f| match &f.kind {
                FeatureKind::Turned(Turned::Diameter { diameter, .. }) => Some(*diameter),
                _ => None,
            })
            .collect();
        (found, diameters)
    };
    let plain = "G18 G90\nT1 D1\nG96 S200 LIMS=3000 M4\nG0 X54 Z2\nG1 X50 Z0 F0.2\nZ-20\nX56\nG0 X60 Z2\nM30\n";
    let (found, diameters) = turned(plain);
    assert!(found);
    assert!(diameters.iter().any(|d| (d - 50.0).abs() < TOL), "{diameters:?}");
    // DIAMOF stated: radii, as written.
    let (found, diameters) = turned(&plain.replace("G18 G90\n", "G18 G90 DIAMOF\n"));
    assert!(!found);
    assert!(diameters.iter().any(|d| (d - 100.0).abs() < TOL), "{diameters:?}");
    // DIAMON before the first move: nothing to infer, nothing said.
    let (found, _) = turned(&plain.replace("G18 G90\n", "G18 G90 DIAMON\n"));
    assert!(!found);
    // A milling program (no lathe word) is not read so.
    let mill = pipeline::analyze(b"G17 G90\nT1 D1\nS1000 M3\nG0 X50 Y0 Z2\nG1 Z-2 F100\nX80\nM30\n", &d, &Profile::default());
    assert!(mill.diagnostics.iter().all(|x| x.code.as_str() != "interp::x-words-diameter"));
}

/// The ShopTurn turning cycles as their screens write them (stock removal `CYCLE951`, contour
/// turning `CYCLE952` on the labels `CYCLE62` names, parting `CYCLE92`, thread `CYCLE99`), in
/// programs written before running with their workingsteps and features by hand; no DIAMON
/// stated (a lathe's reset state).
#[test]
fn shopturn_cycles_are_turning_workingsteps() {
    let d = Registry::shipped().get("siemens").unwrap();
    let plan = |program: &str| pipeline::analyze(program.as_bytes(), &d, &Profile::default()).plan;
    let has = |p: &ProcessPlan, words: &str, sizes: &[(&str, f64)]| {
        let sizes: Vec<(String, f64)> = sizes.iter().map(|(k, v)| ((*k).to_owned(), *v)).collect();
        p.features.iter().any(|f| f.kind.label() == words && matches(&sizes, |k| feature_size(f, k)))
    };
    let step = |p: &ProcessPlan, words: &str, sizes: &[(&str, f64)]| {
        let sizes: Vec<(String, f64)> = sizes.iter().map(|(k, v)| ((*k).to_owned(), *v)).collect();
        p.workingsteps.iter().any(|w| w.label() == words && matches(&sizes, |k| ws_size(w, k)))
    };
    // Facing Ø62 at Z2 to the axis at Z0 (infeed 1), roughing Ø60 to Ø40 over 30 (infeed 2,
    // allowances X0.4 Z0.2), finishing it; an inside finish of a Ø20 bore to Ø24 over 15.
    let corner = "G18 G90 G95\nT1 D1\nG96 S250 LIMS=3000 M4\nG0 X70 Z5\n\
CYCLE951(62,2,-1.6,0,-1.6,0,1,1,0,0,12,0,0,0,1,0.2,0,2,1110000)\n\
CYCLE951(60,0,40,-30,40,-30,1,2,0.4,0.2,11,0,0,0,1,0.25,0,2,1010000)\n\
CYCLE951(60,0,40,-30,40,-30,1,2,0,0,21,0,0,0,1,0.1,0,2,1010000)\n\
T2 D1\nG0 X10 Z5\nCYCLE951(20,0,24,-15,24,-15,3,1,0,0,21,0,0,0,1,0.08,0,2,1010000)\nG0 X100 Z100\nM30\n";
    let p = plan(corner);
    let labels: Vec<String> = p.workingsteps.iter().map(|w| w.label()).collect();
    assert_eq!(labels, ["facing rough", "contouring rough", "contouring finish", "contouring finish inside"], "{labels:?}");
    assert!(step(&p, "facing rough", &[("depth_of_cut", 1.0), ("feed_per_rev", 0.2), ("cutting_speed", 250.0), ("clamp", 3000.0)]));
    assert!(step(&p, "contouring rough", &[("depth_of_cut", 2.0), ("allowance_x", 0.4), ("allowance_z", 0.2), ("feed_per_rev", 0.25)]));
    assert!(step(&p, "contouring finish", &[("feed_per_rev", 0.1)]));
    assert!(has(&p, "revolved flat", &[("z", 0.0)]));
    assert!(has(&p, "outer diameter", &[("diameter", 40.0), ("length", 30.0)]), "{:?}", p.features);
    assert!(has(&p, "inner diameter", &[("diameter", 24.0)]), "{:?}", p.features);
    // Contour turning of the labels CYCLE62 names (Ø30 over 20, a shoulder to Ø40), infeed 2.
    let contour = "G18 G90 G95\nT1 D1\nG96 S200 LIMS=3000 M4\nCYCLE62(,2,\"E_A\",\"E_E\")\n\
CYCLE952(\"ROUGH\",,\"\",2101311,0.3,0,0,2,0.1,0.1,0.3,0.3,0.1,0,1,0,0,,,,,2,2,,,0,1,,11111000,12,1100110,1,0)\n\
G0 X100 Z100\nM30\nE_A:\nG18 G90 DIAM90\nG0 Z0 X0\nG1 X30\nZ-20\nX40\nE_E:\n";
    let p = plan(contour);
    assert!(
        step(&p, "contouring rough", &[("depth_of_cut", 2.0), ("feed_per_rev", 0.3), ("cutting_speed", 200.0)]),
        "{:?}",
        p.workingsteps
    );
    assert!(has(&p, "outer diameter", &[("diameter", 30.0)]), "{:?}", p.features);
    // Parting off at Z-30 from Ø40 to X-1; a thread M20x2.5 from Z0 to Z-25, 1.227 deep.
    let part = "G18 G90 G95\nT3 D1\nG96 S120 LIMS=2000 M4\nG0 X45 Z5\nCYCLE92(40,-30,6,-1,0,1,120,1500,3,0.1,0.05,0,0,0,,2,10000)\nG0 X100 Z100\n\
T4 D1\nG97 S600 M3\nG0 X25 Z5\nCYCLE99(0,20,-25,,2,2,1.227,0.05,30,0,8,1,2.5,1310101,1,2)\nG0 X100 Z100\nM30\n";
    let p = plan(part);
    let labels: Vec<String> = p.workingsteps.iter().map(|w| w.label()).collect();
    assert_eq!(labels, ["parting off", "threading rough"], "{labels:?}");
    assert!(step(&p, "threading rough", &[("pitch", 2.5), ("thread_height", 1.227)]));
    assert!(has(&p, "thread", &[("diameter", 20.0), ("pitch", 2.5)]), "{:?}", p.features);
}

/// `CYCLE62("NAME",0,,)` names the contour by its first argument (SINUMERIK 840D sl cycles,
/// CYCLE62 KNAME): the one ShopTurn's contour editor writes under that name between the
/// labels `E_LAB_A_NAME` and `E_LAB_E_NAME`, or a contour program of that name. Written before
/// the run: the same Ø30 × 20 with its shoulder to Ø40 as the label form, roughed at infeed 2;
/// a name that is nowhere stays the error it was (the control stops there too).
#[test]
fn a_contour_named_by_cycle62_is_the_one_under_that_name() {
    let d = Registry::shipped().get("siemens").unwrap();
    let named = "G18 G90 G95\nT1 D1\nG96 S200 LIMS=3000 M4\nCYCLE62(\"SHAFT\",0,,)\n\
CYCLE952(\"ROUGH\",,\"\",2101311,0.3,0,0,2,0.1,0.1,0.3,0.3,0.1,0,1,0,0,,,,,2,2,,,0,1,,11111000,12,1100110,1,0)\n\
G0 X100 Z100\nM30\nE_LAB_A_SHAFT:\nG18 G90 DIAM90\nG0 Z0 X0\nG1 X30\nZ-20\nX40\nE_LAB_E_SHAFT:\n";
    let a = pipeline::analyze(named.as_bytes(), &d, &Profile::default());
    assert!(a.diagnostics.iter().all(|x| !x.is_error()), "{:?}", a.diagnostics);
    let labels: Vec<String> = a.plan.workingsteps.iter().map(|w| w.label()).collect();
    assert_eq!(labels, ["contouring rough"], "{labels:?}");
    assert!(
        a.plan.features.iter().any(|f| f.kind.label() == "outer diameter" && feature_size(f, "diameter") == Some(30.0)),
        "{:?}",
        a.plan.features
    );
    let nowhere = named.replace("E_LAB_A_SHAFT", "E_LAB_A_OTHER").replace("E_LAB_E_SHAFT", "E_LAB_E_OTHER");
    let a = pipeline::analyze(nowhere.as_bytes(), &d, &Profile::default());
    assert!(a.diagnostics.iter().any(|x| x.is_error() && x.message.contains("SHAFT")), "{:?}", a.diagnostics);
}

/// On a Sinumerik turning machine the T word changes the tool (MD22550 TOOL_CHANGE_MODE 0, the
/// turning setting; a milling machine's 1 changes it with M6): a program that shows a lathe
/// (its turning words, or `DIAMON`) and never says M6 is read so; one that says M6 changes
/// there; a milling program's T still only selects. Expectations written before the run.
#[test]
fn a_sinumerik_lathe_changes_the_tool_with_the_t_word() {
    let reg = Registry::shipped();
    let d = reg.get("siemens").unwrap();
    let read = |program: &str| {
        let a = pipeline::analyze(program.as_bytes(), &d, &Profile::default());
        let has = |c: &str| a.diagnostics.iter().any(|x| x.code.as_str() == c);
        let tools: Vec<u32> = a.plan.workingsteps.iter().map(|w| w.tool).collect();
        (has("interp::tool-word-changes"), has("plan::no-tool"), tools)
    };
    // No DIAMON, no M6: the lathe's words show the reset state; T3 and T5 change the tool.
    let lathe = "G18 G90\nT3 D1\nG96 S200 LIMS=3000 M4\nG0 X54 Z2\nG1 X50 Z0 F0.2\nZ-20\nX56\nG0 X100 Z50\n\
                 T5 D1\nG96 S150 M4\nG0 X44 Z2\nG1 Z-10 F0.15\nX50\nG0 X100 Z50\nM30\n";
    let (found, no_tool, tools) = read(lathe);
    assert!(found && !no_tool, "{tools:?}");
    assert!(tools.contains(&3) && tools.contains(&5) && !tools.contains(&0), "{tools:?}");
    // The same program with M6 after each T: M6 changes, nothing inferred, the same tools.
    let (found, no_tool, with_m6) = read(&lathe.replace("T3 D1\n", "T3 D1\nM6\n").replace("T5 D1\n", "T5 D1\nM6\n"));
    assert!(!found && !no_tool);
    assert_eq!(with_m6, tools);
    // DIAMON stated, no other lathe word: a lathe all the same.
    let diamon = "G18 G90 DIAMON\nT2 D1\nS800 M4\nG0 X40 Z2\nG1 Z-15 F0.2\nX46\nG0 X100 Z50\nM30\n";
    let (found, no_tool, tools) = read(diamon);
    assert!(found && !no_tool && tools.iter().all(|t| *t == 2) && !tools.is_empty(), "{tools:?}");
    // A milling program: T selects only, as before (MD22550 = 1 on milling machines).
    let (found, no_tool, _) = read("G17 G90\nT1 D1\nS1000 M3\nG0 X50 Y0 Z2\nG1 Z-2 F100\nX80\nM30\n");
    assert!(!found && no_tool);
}

/// A LinuxCNC lathe's tool-change remap (as a lathe configuration keeps it beside its INI:
/// `G53 G0 X0`, `G53 G0 Z0`, a turret M code, `G43 H`) carries no code only a lathe has (no
/// `G7`, `G18`, turning cycle, spindle-synchronised move or cut): moving X and Z without Y is
/// what a mill's change sub may do as well. Weak evidence changes nothing: it reads without an
/// error and no plan turns. Expectations written before the run.
#[test]
fn a_linuxcnc_turret_sub_without_lathe_words_is_not_made_a_lathe() {
    let reg = Registry::shipped();
    let d = reg.get("linuxcnc").unwrap();
    let sub = "o<toolchange> sub\nG53 G0 X0\nG53 G0 Z0\nM100 P#<selected_pocket>\ng43 H#<selected_tool>\no<toolchange> endsub [1]\n";
    let a = pipeline::analyze(sub.as_bytes(), &d, &Profile::default());
    let errors: Vec<_> = a.diagnostics.iter().filter(|x| x.severity == ncplan::diag::Severity::Error).collect();
    assert!(errors.is_empty(), "{errors:?}");
    assert!(a.plan.workingsteps.iter().all(|w| w.turning.is_none()));
}

/// One tool faces the front in two passes and then turns the part behind it at the same feed:
/// two operations, facing rough then contouring rough (a turner reads where the passes go,
/// not the feed). The finishing tool faces Z0 and pulls back along +Z at its feed, off the
/// face into air (no cut: the face stays at Z0), then finishes the contour under nose radius
/// compensation in two pieces that lie apart along Z (the profile, then a collar's face
/// behind a relief it leaves): facing finish, then contouring finish. A single face pass that a
/// later pass faces again a little behind it roughs.
#[test]
fn faces_then_turns_and_a_face_left_forwards() {
    let program = "O1\nG21 G99\nT0101\nG50 S3000\nG96 S200 M3\nG0 X54. Z1.\nG1 X-1.6 F0.2\nG0 Z2.\nX54.\nZ0.1\n\
G1 X-1.6\nG0 Z2.\nX46.\nG1 Z0.1\nZ-20.\nX50.\nG0 Z2.\nX42.\nG1 Z0.1\nZ-20.\nX46.\nG0 X100. Z100.\nT0202\nG96 S250 M3\n\
G0 X54. Z0.\nG1 X-1.6 F0.1\nZ1.\nG0 X36. Z2.\nG42 G1 Z0.\nX40. Z-2.\nZ-20.\nX48.\nG0 X56.\nZ-33.\nG1 X52. Z-31.\nX48.\n\
G40 G0 X100. Z100.\nM30\n";
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let plan = pipeline::analyze(program.as_bytes(), &d, &Profile::default()).plan;
    let ws: Vec<String> = plan.workingsteps.iter().map(|w| w.label()).collect();
    assert_eq!(ws, ["facing rough", "contouring rough", "facing finish", "contouring finish"]);
    let faces: Vec<f64> = plan
        .features
        .iter()
        .filter(|f| matches!(f.kind, FeatureKind::Turned(Turned::RevolvedFlat { inner, .. }) if inner < 0.1))
        .map(|f| f.placement[2])
        .collect();
    assert!(faces.iter().any(|z| z.abs() < 1e-6) && !faces.iter().any(|z| *z > 0.5), "{faces:?}");
    // One pass across, faced again 0.5 behind by the finishing tool: rough; the second, finish.
    let twice = "O2\nG21 G99\nT0101\nG96 S200 M3\nG0 X54. Z0.5\nG1 X-1.6 F0.25\nG0 Z2.\nX100. Z100.\nT0202\nG96 S250 M3\n\
G0 X54. Z0.\nG1 X-1.6 F0.1\nG0 Z2.\nX100. Z100.\nM30\n";
    let (ws, _) = labels(twice, "fanuc_lathe");
    assert_eq!(ws, ["facing rough", "facing finish"]);
}

/// A `G71` whose P names a block the program does not number (the contour written without
/// its N words, as a Brazilian shaft program has it) is the control's alarm: an error that
/// says so, the run stopped there, and no contour invented from the unnumbered blocks (no
/// roughing, no finishing pass read from them).
#[test]
fn a_contour_cycle_without_its_numbered_blocks_is_an_alarm() {
    let program = "O1\nG21 G99\nT0101\nG50 S2200\nG96 S200 M3\nG0 X105. Z5.\nG1 X102. Z0. F0.2\nX-1.5\nG0 X102. Z5.\n\
G71 U2. R4.\nG71 P140 Q220 U0.4 W0.1 F0.3\nG1 X30. Z0.\nX36. Z-3.\nZ-83.\nX105.\nG0 X200. Z200.\nM30\n";
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let a = pipeline::analyze(program.as_bytes(), &d, &Profile::default());
    let alarm = a.diagnostics.iter().find(|x| x.code == ncplan::diag::Code::MissingLabel).expect("an error at the G71");
    assert!(alarm.message.contains("N140") && alarm.message.contains("alarm"), "{}", alarm.message);
    let ws: Vec<String> = a.plan.workingsteps.iter().map(|w| w.label()).collect();
    assert_eq!(ws, ["facing finish"]);
}

/// A wide groove as operators and posts cut it: a plunge to near the floor, back out, then each
/// flank finished down to the floor, the second at a finer feed, a rapid between the passes.
/// The passes of one tool over one stretch of Z are one grooving workingstep with one groove
/// (its floor diameter, its width from flank to flank); passes stepping a face down are not.
#[test]
fn a_groove_plunged_and_its_flanks_finished_is_one_groove() {
    let plan_of_text = |program: &str| {
        let d = Registry::shipped().get("fanuc_lathe").unwrap();
        pipeline::analyze(program.as_bytes(), &d, &Profile::default()).plan
    };
    let groove = "O4\nG21 G99\nT0505\nG97 S600 M3\nG0 X52. Z-20.\nG1 X40.2 F0.1\nG0 X52.\nG1 X50. Z-21.5\nX40.\nG0 X52. Z-20.\n\
G1 X50. Z-18. F0.05\nX40.\nG0 X52.\nX100. Z50.\nM30\n";
    let plan = plan_of_text(groove);
    let ws: Vec<String> = plan.workingsteps.iter().map(|w| w.label()).collect();
    assert_eq!(ws, ["grooving finish"]);
    let grooves: Vec<(f64, Option<f64>, f64)> = plan
        .features
        .iter()
        .filter_map(|f| match &f.kind {
            FeatureKind::Turned(Turned::Groove { diameter, width, .. }) => Some((*diameter, *width, f.placement[2])),
            _ => None,
        })
        .collect();
    assert_eq!(grooves, [(40.0, Some(3.5), -18.0)]);
    // The same plunge and a flank pass far from it along Z: two grooves' passes, not joined.
    let apart = "O5\nG21 G99\nT0505\nG97 S600 M3\nG0 X52. Z-20.\nG1 X40.2 F0.1\nG0 X52.\nZ-40.\nG1 X50. Z-41.5\nX40.\nG0 X52.\n\
X100. Z50.\nM30\n";
    let plan = plan_of_text(apart);
    assert_eq!(plan.workingsteps.len(), 2, "{:?}", plan.workingsteps.iter().map(|w| w.label()).collect::<Vec<_>>());
}

/// An annular groove on the face, as a face grooving insert cuts it: plunges along -Z each
/// turned inward (its roughing), then the outer wall profiled down to the floor and across it,
/// and the inner wall down to the floor and out along it. The groove is a face groove with its
/// floor at its depth, between the walls (a revolved flat before the kind existed); the wall
/// passes are grooving.
#[test]
fn a_face_groove_profiled_from_both_walls_leaves_its_floor() {
    let program = "O6\nG21 G99\nT0808\nG96 S200 M3\nG50 S2000\nG0 X120. Z1.\nG1 Z-2. F0.1\nX100.\nZ-1.8\nG0 Z1.\n\
X120.\nG1 Z-4.\nX100.\nZ-3.8\nG0 Z1.\nX124.\nG1 Z0. F0.08\nG2 X122. Z-1. R1.\nG1 Z-5.\nX96.\nZ-4.8\nG0 Z1.\nX92.\nG1 Z0.\n\
G3 X94. Z-1. R1.\nG1 Z-5.\nX97.\nZ-4.8\nG0 Z5.\nX200. Z50.\nM30\n";
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let plan = pipeline::analyze(program.as_bytes(), &d, &Profile::default()).plan;
    let ws: Vec<String> = plan.workingsteps.iter().map(|w| w.label()).collect();
    assert!(ws.last().is_some_and(|l| l == "grooving finish"), "{ws:?}");
    let floor: Vec<(f64, f64, f64)> = plan
        .features
        .iter()
        .filter_map(|f| match &f.kind {
            FeatureKind::Turned(Turned::FaceGroove { outer, inner }) if (f.placement[2] + 5.0).abs() < 1e-6 => {
                Some((*outer, *inner, f.placement[2]))
            }
            _ => None,
        })
        .collect();
    assert_eq!(floor, [(122.0, 94.0, -5.0)]);
    assert!(plan.features.iter().all(|f| !ncplan::plan::turning::is_milling(&f.kind)));
}

/// `tests/programs/lathe_build16/`: six Doosan Lynx 300 shop programs (mikemacfarland/Doosan-Lynx-300,
/// no licence stated: only the sidecars are committed, `extract.sh` writes the texts from the
/// mirror) taken by branch lathe22 to build on, their sidecars written by hand before ncplan read
/// them: two boring-bar `G71`/`G70` programs with no `G20` (inch at power-on), a flange bore and an
/// accumulator body whose inside `G71` write a positive X allowance, a tube cut off and bored, a
/// pump bore's explicit passes; and (added later, 39 of their 44 found when first run) a drilled
/// and bored jaw cut and a press sleeve's explicit facing and boring passes. The first six 23 of 34
/// on integrate 4215ce6 (with the set registered); all eight 40 of 44 after lathe22 (7 December
/// 2026). Left: O0022's bore Ø62.959 (its last `Z-1.875` under modal `G02`
/// with no `R`, read as an error) and O0023 (one feed under constant surface speed only: its
/// inch is not told). The test keeps the figure from falling and no milling feature.
#[test]
fn lathe_build16_programs() {
    const BUILD16_SCORE: usize = 40;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/programs/lathe_build16");
    // The texts are written by extract.sh from the mirrors; without them there is nothing to score.
    if !dir.join("mmf_lynx300_o0022.nc").exists() {
        return;
    }
    let (listed, found, milling, misses) = score_folder("lathe_build16");
    assert_eq!(milling, 0, "milling features on lathe programs:\n{}", misses.join("\n"));
    assert!(found >= BUILD16_SCORE, "{found} of {listed} recovered, fewer than {BUILD16_SCORE}:\n{}", misses.join("\n"));
}

/// `tests/programs/lathe_build19/`: four SINUMERIK 840D sl programs of a German course
/// (east-code/CNC-Dreh-Fraeszentrum, no licence stated: only the sidecars are committed,
/// `extract.sh` writes the texts from the mirror) whose `CYCLE952` roughing and finishing cut a
/// contour that `CYCLE62` names in a program beside them (by its name, or by labels in it), with
/// those four contour programs: a shoulder roughed from labels in a subprogram, a double cone
/// faced, roughed and finished by two tools, a contour of arcs faced, roughed and finished, a
/// shaft with undercuts roughed and finished at another speed; the contour programs are read
/// through their main programs (`contour-only` sidecars). Sidecars written by hand before ncplan read them (branch lathe19, session
/// 19). The main programs read their contours from beside the file as `ncplan plan` does. The
/// test keeps the figure from falling and no milling feature.
#[test]
fn lathe_build19_programs() {
    const BUILD19_SCORE: usize = 24;
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/programs/lathe_build19");
    // The texts are written by extract.sh from the mirrors; without them there is nothing to score.
    if !dir.join("ec_gd2_doppelkegel2.nc").exists() {
        return;
    }
    let (listed, found, milling, misses) = score_folder("lathe_build19");
    assert_eq!(milling, 0, "milling features on lathe programs:\n{}", misses.join("\n"));
    assert!(found >= BUILD19_SCORE, "{found} of {listed} recovered, fewer than {BUILD19_SCORE}:\n{}", misses.join("\n"));
}

/// A program that selects a tool, starts the spindle and feeds turns; feed moves at a
/// programmed feed rate with neither tool nor spindle stated still cut.
#[test]
fn moves_with_a_tool_spindle_and_feed_turn_and_a_feed_alone_cuts() {
    let d = Registry::shipped().get("siemens").unwrap();
    let plan = |text: &str| pipeline::analyze(text.as_bytes(), &d, &Profile::default()).plan;
    // A tool, a spindle and a feed: the same moves turn.
    let turned = "G18 G90 G95 DIAMON\nT1 D1\nS500 M3\nG0 X50 Z2\nG1 X48 Z0 F0.2\nZ-22\nX66\nG0 X100 Z100\nM30\n";
    assert_eq!(plan(turned).workingsteps.len(), 1);
    // A feed rate alone: the control runs it (a program that never names its tool).
    let fed = "G17 G90 G94\nG0 X0 Y0 Z2\nG1 Z-1 F100\nX20\nY20\nX0\nY0\nG0 Z10\nM30\n";
    assert_eq!(plan(fed).workingsteps.len(), 1);
}

/// An inside finish as turners write it after the boring passes: a finishing bar's one pass,
/// explicit moves with nothing else telling its side, run in the bore an earlier tool roughed
/// (at most 0.5 mm beyond it on the radius) with the outside turned beside it, finishes the bore.
/// A roughing cycle started inside the diameters it cuts roughs a bore, its X allowance written
/// positive or not. A tool the program names a cut-off tool plunging once parts off, through a
/// tube's wall. A boring bar's lead-in and one cut out across the front from the bore faces the
/// front. A recess roughed beyond a bore that the finishing bar passes through at a
/// smaller diameter stays as the roughing left it.
#[test]
fn inside_finishes_and_cut_offs_as_turners_write_them() {
    // Outside passes to Ø74 and Ø70, boring passes Ø30 and Ø39 to Z-30, then T7 one pass from
    // the mouth: a chamfer in to Ø40, Ø40 to Z-30, out of the bore by a rapid.
    let bore = "O1\nG21 G99\nT0101\nG50 S3000\nG96 S200 M3\nG0 X80. Z2.\nG1 X74. Z0.5 F0.25\nZ-40.\nX80.\nG0 Z2.\nX70.\n\
G1 Z0.5\nZ-40.\nX76.\nG0 X200. Z200.\nT0505\nG96 S220 M3\nG0 X30. Z2.\nG1 Z-30. F0.2\nG0 X28. Z2.\nX35.\nG1 Z-30.\nG0 X33. Z2.\n\
X39.\nG1 Z-30.\nG0 X37. Z2.\nG0 X200. Z200.\nT0707\nG96 S270 M3\nG0 X48. Z2.\nG1 X40. Z-2. F0.11\nZ-30.\nX36.\nG0 Z2.\n\
G0 X200. Z200.\nM30\n";
    let (ws, features) = labels(bore, "fanuc_lathe");
    assert_eq!(ws.last().map(String::as_str), Some("contouring finish inside"), "{ws:?}");
    assert!(features.contains(&"inner diameter".to_owned()), "{features:?}");
    // A G71 started at X20, inside the contour Ø24-Ø30, with U0.5 written positive.
    let rough = "O2\nG21 G99\nT0404\nG50 S2000\nG96 S150 M3\nG0 X20. Z2.\nG71 U1. R0.5\nG71 P10 Q20 U0.5 W0.1 F0.2\n\
N10 G0 X30.\nG1 Z0.\nZ-10.\nX24.\nN20 Z-20.\nG70 P10 Q20 F0.1\nG0 X200. Z200.\nM30\n";
    let (ws, _) = labels(rough, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough inside", "contouring finish inside"]);
    // A cut-off tool's one plunge at Z-10 from Ø50 to Ø35 through a tube's wall, the new face
    // then faced at Z-10 in to Ø34.5 (the tube's bore, as Lynx 300 O2700 faces it): parting off;
    // the same plunge by a grooving tool the program names so is a groove, and so is the cut-off
    // tool's where nothing tells a bore there (review16a: a blade stopping in a bar's wall).
    let cut = |name: &str, face: bool| {
        let face = if face { "T0202\nG97 S300 M3\nG0 X52. Z-10.\nG1 X34.5 F0.08\nG0 X60.\nX200. Z200.\n" } else { "" };
        format!("O3\nG21 G99\n({name})\nT0101\nG50 S2000\nG96 S100 M3\nG0 X52. Z-10.\nG1 X35. F0.05\nG0 X60.\nX200. Z200.\n{face}M30\n")
    };
    assert_eq!(labels(&cut("T01 CUT OFF AT 10", true), "fanuc_lathe").0.first().map(String::as_str), Some("parting off"));
    assert_eq!(labels(&cut("T01 OD GROOVE", true), "fanuc_lathe").0.first().map(String::as_str), Some("grooving finish"));
    assert_eq!(labels(&cut("T01 CUT OFF AT 10", false), "fanuc_lathe").0, ["grooving finish"]);
    // A boring bar fed in along Z at Ø45 to the front, then out across it to Ø76: it faces the
    // front (not inside), then bores.
    let face_out = "O5\nG21 G99\nT0808 (BORING BAR)\nG50 S2500\nG96 S190 M3\nG0 X45. Z5.\nG1 Z0. F0.25\nX76. F0.15\n\
G0 Z1.\nX57.\nG1 Z-27. F0.1\nX50.\nG0 Z2.\nX200. Z200.\nM30\n";
    assert_eq!(labels(face_out, "fanuc_lathe").0.first().map(String::as_str), Some("facing finish"));
    // Inside roughing passes, the last along the whole contour (Ø39.5 to Z-25, a recess Ø41 to
    // Z-30, its floor in to Ø24), then a finishing bar's Ø39.8 to Z-27, through the recess's air:
    // the recess Ø41 is the part's.
    let recess = "O4\nG21 G99\nT0404 (ID ROUGH BORING BAR)\nG50 S2000\nG96 S120 M3\nG0 X30. Z2.\nG1 Z-30. F0.1\nX24.\nG0 Z2.\nX35.\n\
G1 Z-30.\nX30.\nG0 Z2.\nX44.\nG1 X42. Z0.\nX39.5 Z-1.25\nZ-25.\nX41. Z-26.\nZ-30.\nX24.\nG0 Z15.\nX200. Z200.\n\
T1111 (ID FINISH BORING BAR)\nG96 S120 M3\nG0 X42. Z3.\nG1 X39.8 Z0. F0.1\nZ-27.\nG0 X35.\nZ15.\nX200. Z200.\nM30\n";
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let plan = pipeline::analyze(recess.as_bytes(), &d, &Profile::default()).plan;
    let inner: Vec<f64> = plan
        .features
        .iter()
        .filter_map(|f| match &f.kind {
            FeatureKind::Turned(Turned::Diameter { diameter, inside: true, .. }) => Some(*diameter),
            _ => None,
        })
        .collect();
    assert!(inner.iter().any(|d| (d - 41.0).abs() < 0.01), "{inner:?}");
    assert!(inner.iter().any(|d| (d - 39.8).abs() < 0.01), "{inner:?}");
}

/// A face groove (issue 40): an annular groove cut along -Z into the face between two
/// diameters is a feature of its own, whichever way it is cut (Fanuc `G74` pecks, a face
/// grooving tool's plunges, its walls finished), written in STEP-NC as a GROOVE whose material
/// side is along the axis and read back so, and its edits are told as the face groove's.
#[test]
fn a_face_groove_is_its_own_feature() {
    use expect_test::expect;
    use ncplan::part21::{schema, stepnc};
    let groove = |name: &str| {
        let plan = plan_of(&dir().join(name), "fanuc_lathe");
        let grooves: Vec<(Turned, f64)> = plan
            .features
            .iter()
            .filter_map(|f| match &f.kind {
                FeatureKind::Turned(t @ Turned::FaceGroove { .. }) => Some((t.clone(), f.placement[2])),
                _ => None,
            })
            .collect();
        (plan, grooves)
    };
    // G74 off the axis: the diameters plunged, the floor where its pecks end.
    let (plan, g) = groove("fanuc_g74_face_groove.nc");
    assert_eq!(g, [(Turned::FaceGroove { outer: 80.0, inner: 60.0 }, -6.0)]);
    assert_eq!(plan.workingsteps.iter().map(|w| w.label()).collect::<Vec<_>>(), ["grooving finish"]);
    // Plunges along -Z, each straight back out: one groove between the diameters plunged.
    let (plan, g) = groove("explicit_face_plunges.nc");
    assert_eq!(g, [(Turned::FaceGroove { outer: 100.0, inner: 88.0 }, -4.0)]);
    assert_eq!(plan.workingsteps.len(), 1);
    // Roughed by plunges turned across their floors, the walls finished each by a pass: one
    // groove from wall to wall, roughing and finishing it; no revolved flat at its floor.
    let (plan, g) = groove("explicit_face_groove.nc");
    assert_eq!(g, [(Turned::FaceGroove { outer: 112.0, inner: 92.0 }, -6.0)]);
    assert_eq!(g[0].0.face_groove_width(), Some(10.0));
    assert_eq!(plan.features[0].workingsteps, [1, 2]);
    assert_eq!(plan.workingsteps.iter().map(|w| w.label()).collect::<Vec<_>>(), ["grooving rough", "grooving finish"]);
    assert!(!plan.features.iter().any(|f| f.kind.label() == "revolved flat"), "{:?}", plan.features);
    // In STEP-NC: a GROOVE with its material side along -Z, read back as the face groove.
    let (text, _) = stepnc::to_string(&plan, stepnc::Class::Cc2, "2026-01-01T00:00:00");
    let x = ncplan::part21::parse(&text).unwrap();
    assert_eq!(schema::iso14649().check(&x), Vec::<String>::new());
    assert!(text.contains("=GROOVE("), "{text}");
    assert!(text.contains("DIRECTION('',(0.,0.,-1.))"), "{text}");
    assert_eq!(stepnc::read(&x).unwrap(), plan);
    // The floor deepened, a wall moved: told as the face groove's, nothing added or removed.
    let deeper = lathe_edit("fanuc_g74_face_groove.nc", "Z-6.", "Z-7.");
    no_structure_change(&deeper);
    expect![[r#"
        feature_changed | face_groove_floor | Z-6 | Z-7
          face groove floor changed from Z-6 to Z-7 at line 11
    "#]]
    .assert_eq(&deeper);
    let wider = lathe_edit("explicit_face_groove.nc", "X112.\n", "X114.\n");
    no_structure_change(&wider);
    expect![[r#"
        feature_changed | face_groove_width | 10 mm | 11 mm (also in workingstep 2)
          face groove width changed from 10 mm to 11 mm (also in workingstep 2) at line 20
        feature_changed | face_groove_outer_diameter | Ø112 | Ø114 (also in workingstep 2)
          face groove outer diameter changed from Ø112 to Ø114 (also in workingstep 2) at line 20
        start_point_moved | start_point | Ø112 Z1 | Ø114 Z1
          start point moved from Ø112 Z1 to Ø114 Z1 at line 20
    "#]]
    .assert_eq(&wider);
}

/// A turned feature as (kind, diameter, length or width, inside).
type TurnedRow = (String, f64, f64, bool);

/// The workingsteps' labels and the turned features of a program.
fn turned_of(program: &str) -> (Vec<String>, Vec<TurnedRow>) {
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let plan = pipeline::analyze(program.as_bytes(), &d, &Profile::default()).plan;
    let features = plan
        .features
        .iter()
        .filter_map(|f| match &f.kind {
            FeatureKind::Turned(Turned::Diameter { diameter, length, inside }) => {
                Some(("diameter".to_owned(), *diameter, *length, *inside))
            }
            FeatureKind::Turned(Turned::Groove { diameter, width, inside }) => {
                Some(("groove".to_owned(), *diameter, width.unwrap_or(0.0), *inside))
            }
            _ => None,
        })
        .collect();
    (plan.workingsteps.iter().map(|w| w.label()).collect(), features)
}

/// A short metric boring program with no G20/G21: a boring bar's `G71` at F0.05 and `G70` at
/// F0.03 in a Ø7 hole, where S100 m/min turns above the G50 S3000 clamp (4547/min), as it does
/// on any small bore. Two feeds and a surface speed that fits only ft/min are no proof of inch:
/// the program stays a Ø10 × 12 bore in mm. The same program with a tool comment naming an inch
/// size (`3/4" BORING BAR`) is read in inch, as the Lynx 300's O0022.
#[test]
fn a_short_metric_boring_program_stays_metric() {
    let program = |tool: &str| {
        format!(
            "G40 G99\nT0303 ({tool})\nG50 S3000\nG96 S100 M3\nG0 X7. Z2.\nG71 U0.3 R0.2\nG71 P10 Q20 U-0.1 W0.02 F0.05\nN10 G0 X10.\n\
G1 Z-12.\nX8.\nN20 Z-20.\nG70 P10 Q20 F0.03\nM30\n"
        )
    };
    let (ws, features) = turned_of(&program("BORING BAR D6"));
    assert_eq!(ws, ["contouring rough inside", "contouring finish inside"], "{features:?}");
    let bore: Vec<_> = features.iter().filter(|f| f.0 == "diameter" && f.3).collect();
    assert!(bore.iter().any(|f| (f.1 - 10.0).abs() < 0.01 && (f.2 - 12.0).abs() < 0.01), "{features:?}");
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let a = pipeline::analyze(program("BORING BAR D6").as_bytes(), &d, &Profile::default());
    assert!(a.diagnostics.iter().all(|d| d.code.as_str() != "interp::units-inferred"), "{:?}", a.diagnostics);
    // Named by an inch size, the same tool's program is an inch shop's: Ø10 in is 254 mm.
    let (_, features) = turned_of(&program("T03 - 3/4\" BORING BAR"));
    assert!(features.iter().any(|f| f.0 == "diameter" && f.3 && (f.1 - 254.0).abs() < 0.01), "{features:?}");
    // A pipe thread's inch name in a metric shop tells nothing.
    let (_, features) = turned_of(&program("T03 BORING BAR FOR 1/2\" NPT"));
    assert!(features.iter().any(|f| f.0 == "diameter" && f.3 && (f.1 - 10.0).abs() < 0.01), "{features:?}");
}

/// An outside turning tool fed along Z into the stock at Ø20 from Z1 to Z-2, then out across to
/// Ø40: a diameter and its shoulder, not a face cut out from a bore (the lead-in ends 2 mm
/// behind the part's front and the tool is no boring bar).
#[test]
fn a_turning_tool_fed_in_along_z_then_out_turns_a_diameter() {
    let program = "G21 G99\nT0101 (OD TURNING)\nG50 S3000\nG96 S200 M3\nG0 X20. Z1.\nG1 Z-2. F0.1\nX40.\nG0 X200. Z200.\nM30\n";
    let (ws, features) = turned_of(program);
    assert!(ws.iter().all(|w| !w.starts_with("facing")), "{ws:?}");
    assert!(
        features.iter().any(|f| f.0 == "diameter" && !f.3 && (f.1 - 20.0).abs() < 0.01 && (f.2 - 2.0).abs() < 0.01),
        "{ws:?} {features:?}"
    );
}

/// A cut-off blade plunging once from Ø32 to Ø26 on a solid bar turned to Ø30: a groove Ø26 the
/// blade's 3 mm wide (shops groove with the blade they part with), not a part-off: it reaches
/// neither the axis nor a bore.
#[test]
fn a_cut_off_blade_stopping_in_the_wall_cuts_a_groove() {
    let program = "G21 G99\nT0101 (OD TURNING)\nG50 S3000\nG96 S200 M3\nG0 X32. Z2.\nG1 X30. Z0. F0.2\nZ-40.\nX34.\nG0 X200. Z200.\n\
T0505 (CUT OFF BLADE 3MM)\nG96 S100 M3\nG0 X32. Z-20.\nG1 X26. F0.05\nG0 X34.\nG0 X200. Z200.\nM30\n";
    let (ws, features) = turned_of(program);
    assert_eq!(ws.last().map(String::as_str), Some("grooving finish"), "{ws:?}");
    assert!(features.iter().any(|f| f.0 == "groove" && (f.1 - 26.0).abs() < 0.01 && (f.2 - 3.0).abs() < 0.01), "{features:?}");
}

/// A thin sleeve: roughed outside from X44, bored by a boring bar to Ø39.2, then finished
/// outside at Ø40 to Z-30 by an OD finishing tool that leaves outwards. Its pass lies within
/// 0.5 mm of the bore on the radius, but it is the outside's finish: Ø40 outside.
#[test]
fn a_thin_sleeves_outside_finish_stays_outside() {
    let program = "G21 G99\nT0101 (OD ROUGH)\nG50 S2500\nG96 S200 M3\nG0 X46. Z2.\nG1 X44. Z0. F0.25\nZ-32.\nX48.\nG0 Z2.\nX40.6\n\
G1 Z-32.\nX46.\nG0 X200. Z200.\nT0202 (BORING BAR)\nG96 S150 M3\nG0 X36. Z2.\nG1 X39.2 Z0. F0.15\nZ-32.\nX37.\nG0 Z2.\n\
G0 X200. Z200.\nT0303 (OD FINISH)\nG96 S250 M3\nG0 X38. Z2.\nG1 X40. Z0. F0.08\nZ-30.\nX44.\nG0 X200. Z200.\nM30\n";
    let (ws, features) = turned_of(program);
    assert_eq!(ws.last().map(String::as_str), Some("contouring finish"), "{ws:?}");
    assert!(features.iter().any(|f| f.0 == "diameter" && !f.3 && (f.1 - 40.0).abs() < 0.01), "{ws:?} {features:?}");
    assert!(!features.iter().any(|f| f.0 == "diameter" && f.3 && (f.1 - 40.0).abs() < 0.01), "{ws:?} {features:?}");
    // The same pass by an unnamed tool cut towards the chuck under G41 (the side Fanuc lathes
    // bore with) and left along Z: a finishing bar's, the bore Ø40.
    let bar = program
        .replace("T0303 (OD FINISH)", "T0303")
        .replace("G0 X38. Z2.\nG1 X40.", "G0 G41 X38. Z2.\nG1 X40.")
        .replace("Z-30.\nX44.\nG0 X200. Z200.\nM30", "Z-30.\nG0 Z2.\nG40 X200. Z200.\nM30");
    let (ws, features) = turned_of(&bar);
    assert_eq!(ws.last().map(String::as_str), Some("contouring finish inside"), "{ws:?} {features:?}");
}

/// Fanuc's `G70` after a `G72` finishes the face profile the face roughing cycle roughed (the
/// operator's manual: G70 finishes after rough cutting by G71, G72 or G73), once as written from
/// the outside in: facing finish, as the roughing is facing, also where the face stops at a
/// centre hole and steps over a spigot. After a `G71` the same profile is a contour.
#[test]
fn a_finish_after_face_roughing_faces() {
    let program = "O1\nG21 G99\nT0101\nG50 S3000\nG96 S200 M3\nG0 X110. Z1.\nG72 W2. R1.\nG72 P10 Q14 U0.4 W0.2 F0.3\n\
N10 G0 Z-10.\nN11 G1 X100. Z-8.\nN12 X40.\nN13 Z-2.\nN14 X5. Z0.\nG70 P10 Q14 F0.1\nG0 X200. Z200.\nM30\n";
    let (ws, features) = labels(program, "fanuc_lathe");
    assert_eq!(ws, ["facing rough", "facing finish"], "{features:?}");
    let (ws, _) = labels(&program.replace("G72 W2. R1.", "G71 U2. R1.").replace("G72 P10", "G71 P10"), "fanuc_lathe");
    assert_eq!(ws.last().map(String::as_str), Some("contouring finish"), "{ws:?}");
}

/// The Sinumerik turning cycles kept as intent (Operate's groove `CYCLE930` and undercut
/// `CYCLE940`, whose argument order the manuals found do not give, and ShopTurn's work steps
/// `F_HEAD`/`F_ROUGH`/`F_END`, whose parameters are the screens' own) read without an error and
/// show a turning machine (dictionary meaning `cycle-turn-intent`): the reading finds the lathe's
/// reset state (DIAMON, G18) from them alone, as it does from `CYCLE951`; the same program
/// without them shows no lathe. Own programs, expectations written before the run.
#[test]
fn turning_cycles_kept_as_intent_show_a_lathe() {
    let d = Registry::shipped().get("siemens").unwrap();
    let read = |program: &str| pipeline::analyze(program.as_bytes(), &d, &Profile::default()).diagnostics;
    let lathe = |diags: &[ncplan::diag::Diagnostic]| diags.iter().any(|x| x.code.as_str() == "interp::x-words-diameter");
    let kept = |diags: &[ncplan::diag::Diagnostic], name: &str| {
        diags.iter().any(|x| x.code.as_str() == "interp::unsupported" && x.message.starts_with(&format!("{name} (cycle-turn-intent)")))
    };
    let base = "G90 G95\nT=\"GROOVER_3MM\" D1\nS400 M4\nG0 X60 Z5\n";
    let groove = format!("{base}CYCLE930(50,-12,3,2.5,1,,0,0,0,0,0,0,0,0.1,1,1,10510,,1,0,0.08,1,0,0,2,1111110)\nG0 X100 Z50\nM30\n");
    let a = read(&groove);
    assert!(a.iter().all(|x| !x.is_error()), "{a:?}");
    assert!(kept(&a, "CYCLE930") && lathe(&a), "{a:?}");
    let undercut = format!("{base}CYCLE940(20,-25,\"A\",1,1,0.07,13,,,,,30,60,0.3,0.1,0,0,17,,,2,1000)\nG0 X100 Z50\nM30\n");
    let a = read(&undercut);
    assert!(a.iter().all(|x| !x.is_error()), "{a:?}");
    assert!(kept(&a, "CYCLE940") && lathe(&a), "{a:?}");
    let plain = format!("{base}G1 X50 F0.1\nG0 X100 Z50\nM30\n");
    assert!(!lathe(&read(&plain)), "{:?}", read(&plain));
    let steps = "F_HEAD(1,40,2,,-30,40,5,0,0,200,200,1,3000,3000,71,1,35535,,40,0);*RO*\n\
F_ROUGH(\"ROUGHER\",\"\",1,0.25,2,250,2,0,54273,5,40,90,2,90,-1,90,0,90,-1,90,0,90,0,0,0,0,2,0,0,0,90,90,90,0,0);*RO*\n\
F_END(0,1,0);*RO*\nM30\n";
    let a = read(steps);
    assert!(a.iter().all(|x| !x.is_error() && x.code.as_str() != "flow::missing-program"), "{a:?}");
    assert!(kept(&a, "F_ROUGH") && lathe(&a), "{a:?}");
}

/// Review 17a: Fanuc's `G70` runs the blocks its P and Q name, so it finishes the contour of
/// the roughing cycle that names the same blocks, not the last roughing cycle before it: an
/// OD contour roughed by `G71 P20 Q25` and finished by `G70 P20 Q25` after a `G72 P10 Q14`
/// facing is a contouring finish (it was labelled facing finish, and FACING_FINISH in STEP-NC,
/// as the face roughing came last); a `G70 P10 Q14` after a later `G71` finishes the face.
#[test]
fn a_finish_pairs_with_the_roughing_of_its_own_contour_blocks() {
    let program = "O1\nG21 G99\nT0101\nG50 S3000\nG96 S200 M3\nG0 X110. Z1.\nG71 U2. R1.\nG71 P20 Q25 U0.4 W0.2 F0.3\n\
N20 G0 X20.\nN21 G1 Z0.\nN22 X60.\nN23 Z-5.\nN24 X100.\nN25 Z-20.\nG0 X120. Z5.\nG72 W2. R1.\nG72 P10 Q14 U0.4 W0.2 F0.3\n\
N10 G0 Z-30.\nN11 G1 X100. Z-28.\nN12 X40.\nN13 Z-22.\nN14 X5. Z-20.\nG0 X200. Z200.\nT0303\nG0 X110. Z1.\nG70 P20 Q25 F0.1\n\
G0 X200. Z200.\nM30\n";
    let (ws, features) = labels(program, "fanuc_lathe");
    assert_eq!(ws.last().map(String::as_str), Some("contouring finish"), "{ws:?} {features:?}");
    // The face's own finish after a later OD roughing is the face's: facing.
    let face = "O1\nG21 G99\nT0101\nG50 S3000\nG96 S200 M3\nG0 X120. Z5.\nG72 W2. R1.\nG72 P10 Q14 U0.4 W0.2 F0.3\n\
N10 G0 Z-30.\nN11 G1 X100. Z-28.\nN12 X40.\nN13 Z-22.\nN14 X5. Z-20.\nG0 X110. Z1.\nG71 U2. R1.\nG71 P20 Q25 U0.4 W0.2 F0.3\n\
N20 G0 X20.\nN21 G1 Z0.\nN22 X60.\nN23 Z-5.\nN24 X100.\nN25 Z-20.\nG0 X200. Z200.\nT0303\nG0 X110. Z1.\nG70 P10 Q14 F0.1\n\
G0 X200. Z200.\nM30\n";
    let (ws, features) = labels(face, "fanuc_lathe");
    assert_eq!(ws.last().map(String::as_str), Some("facing finish"), "{ws:?} {features:?}");
}

/// A milling program that states G17 and calls a turning cycle kept as intent after its last
/// move (review17b's `m2.mpf`) stays a mill's: a lathe's turning plane is G18, and a cycle the
/// program names under its own stated milling plane must not re-read its milling moves with X
/// as a diameter. The same cycle after a stated G18 still shows the lathe.
#[test]
fn a_turning_cycle_under_a_stated_milling_plane_does_not_make_a_lathe() {
    let d = Registry::shipped().get("siemens").unwrap();
    let mill = "; mill part\nG17 G90 G54 G71\nT=\"CUTTER10\" M6\nS3000 M3 D1\nG0 X50 Y20 Z5\nG1 Z-2 F300\nG1 X80 Y20\nG1 X80 Y60\nG0 Z50\n";
    let cycle = "CYCLE930(50,0,10,10,2,0,0,0,0,0,0,0,0,0,0,0,0,1,1,0.1,0.1,0.2,0.2,1,10001,1,0,2,1,10)\n";
    let with_cycle = format!("{mill}{cycle}M30\n");
    let a = pipeline::analyze_plan(with_cycle.as_bytes(), &d, &Profile::default());
    assert!(a.diagnostics.iter().all(|x| x.code.as_str() != "interp::x-words-diameter"), "{:?}", a.diagnostics);
    let plan = a.plan;
    let xs: Vec<f64> = plan.workingsteps.iter().flat_map(|w| w.toolpath.iter().map(|m| m.to[0])).collect();
    assert!(xs.iter().any(|&x| (x - 80.0).abs() < 1e-6), "X read as written: {xs:?}");
    assert!(xs.iter().all(|&x| (x - 40.0).abs() > 1e-6), "no X halved: {xs:?}");
    // After a stated G18, the same cycle is a lathe's word.
    let turned = format!("{}G18\n{cycle}M30\n", mill.replace("G17 ", ""));
    let a = pipeline::analyze(turned.as_bytes(), &d, &Profile::default());
    assert!(a.diagnostics.iter().any(|x| x.code.as_str() == "interp::x-words-diameter"), "{:?}", a.diagnostics);
}

/// The radius and Z at which each pass of the lathe cycle `code` first cuts (its first move at
/// feed after each rapid), in the canon of `program`.
fn first_cuts(program: &str, dialect: &str, code: &str) -> Vec<(f64, f64)> {
    use ncplan::canon::CanonOp;
    let d = Registry::shipped().get(dialect).unwrap();
    let a = pipeline::analyze(program.as_bytes(), &d, &Profile::default());
    let mut out = Vec::new();
    let (mut inside, mut after_rapid) = (false, true);
    for c in &a.canon {
        match &c.op {
            CanonOp::Turning(t) => inside = t.code == code,
            CanonOp::TurningEnd => inside = false,
            CanonOp::StraightTraverse(_) => after_rapid = true,
            CanonOp::StraightFeed(p) if inside && after_rapid => {
                out.push(((p[0] * 1e4).round() / 1e4, (p[2] * 1e4).round() / 1e4));
                after_rapid = false;
            }
            _ => {}
        }
    }
    out
}

/// Fanuc's `G73` pattern repeating (0i-TF / 30i operator's manual, T series, "multiple
/// repetitive cycles"): `G73 U(Δi) W(Δk) R(d)` gives the relief (X a radius) and the number of
/// passes, `G73 P Q U(Δu) W(Δw) F` the contour's blocks and the finishing allowances (U a
/// diameter); the contour is cut d times, from Δi+Δu/2, Δk+Δw off it on the first pass to
/// Δu/2, Δw on the last. A contouring rough with its allowances, the contour's features from
/// its finish; the Haas lathe's one block (`G73 P Q U W I K D`: I and K the relief, D the
/// passes) reads alike. Edits of the relief and the passes are told as such, changing no
/// workingstep.
#[test]
fn g73_repeats_the_contour_from_its_relief_to_its_allowances() {
    let fanuc = "O1\nG21 G40 G99\nT0101\nG50 S3000\nG96 S200 M3\nG0 X80. Z2.\nG73 U14. W4. R3\nG73 P10 Q20 U1. W0.1 F0.3\n\
N10 G0 X20. Z2.\nG1 Z-7.\nX26. Z-15.\nZ-20.\nG3 X36. Z-25. R5.\nG1 Z-30.\nN20 X60.\nG70 P10 Q20 F0.15\nG0 X100. Z50.\nM30\n";
    // Pass k at (14 + 0.5)·(2-k)/2 + 0.5 off in X (radius) and 4·(2-k)/2 + 0.1 in Z.
    let passes = [(24.5, -2.9), (17.5, -4.9), (10.5, -6.9)];
    assert_eq!(first_cuts(fanuc, "fanuc_lathe", "G73"), passes);
    let (ws, features) = labels(fanuc, "fanuc_lathe");
    assert_eq!(ws, ["contouring rough", "contouring finish"]);
    for f in ["outer diameter", "revolved round"] {
        assert!(features.iter().any(|x| x == f), "{f} in {features:?}");
    }
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let plan = pipeline::analyze(fanuc.as_bytes(), &d, &Profile::default()).plan;
    let intent = plan.workingsteps[0].turning.as_deref().and_then(|t| t.intent.clone()).unwrap();
    assert_eq!(
        (intent.allowance_x, intent.allowance_z, intent.relief, intent.divisions),
        (Some(1.0), Some(0.1), Some([14.0, 4.0]), Some(3))
    );
    // The plan's line names the relief and the passes, in the cycle's words.
    let line = ncplan::plan::turning::words(&plan.workingsteps[0]).unwrap();
    assert!(line.contains("finishing allowance U1 W0.1") && line.contains("pattern relief U14 W4, pattern passes 3"), "{line}");
    // The Haas lathe's one block.
    let haas = fanuc.replace("G73 U14. W4. R3\nG73 P10 Q20 U1. W0.1 F0.3", "G73 P10 Q20 U1. W0.1 I14. K4. D3 F0.3");
    assert_eq!(first_cuts(&haas, "haas_lathe", "G73"), passes);
    // Without the first block no number of passes is known: the cycle is skipped, said so.
    let bare = fanuc.replace("G73 U14. W4. R3\n", "");
    assert!(first_cuts(&bare, "fanuc_lathe", "G73").is_empty());
    let a = pipeline::analyze(bare.as_bytes(), &d, &Profile::default());
    assert!(a.diagnostics.iter().any(|x| x.message.contains("no number of passes")), "{:?}", a.diagnostics);
    // Edits in the cycle's terms.
    let edit = |from: &str, to: &str| {
        let b = fanuc.replace(from, to);
        let (pa, pb) =
            (pipeline::analyze(fanuc.as_bytes(), &d, &Profile::default()), pipeline::analyze(b.as_bytes(), &d, &Profile::default()));
        let (x, y) = (
            ncplan::diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d },
            ncplan::diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d },
        );
        let got = ncplan::diff::compare(x, y);
        assert!(ncplan::diff::unaccounted(x, y, &got).is_empty());
        got.iter().map(|c| format!("{} | {} | {} | {}\n", c.kind.as_str(), c.field, c.before, c.after)).collect::<String>()
    };
    let relief = edit("G73 U14. W4. R3", "G73 U12. W4. R3");
    no_structure_change(&relief);
    assert_eq!(relief, "cycle_parameter_changed | pattern_relief | U14 W4 | U12 W4\n");
    let count = edit("G73 U14. W4. R3", "G73 U14. W4. R4");
    no_structure_change(&count);
    assert_eq!(count, "cycle_parameter_changed | pattern_passes | 3 | 4\n");
}

/// G-code system B/C keeps G73's words: U and W are words of their own there (G91 moves
/// incrementally), so the cycle reads its relief and allowances from them as system A does
/// from its U and W, not from X and Z (which would give no relief and no allowances).
#[test]
fn g73_in_system_b_reads_its_u_and_w() {
    let a = "O1\nG21 G99\nT0101\nG97 S500 M3\nG0 X80. Z2.\nG73 U14. W4. R3\nG73 P10 Q20 U1. W0.1 F0.3\n\
N10 G0 X20. Z2.\nG1 Z-7.\nX26. Z-15.\nZ-20.\nG3 X36. Z-25. R5.\nG1 Z-30.\nN20 X60.\nG70 P10 Q20 F0.15\nG0 X100. Z50.\nM30\n";
    let b = a.replace("G21 G99", "G21 G95");
    let passes = [(24.5, -2.9), (17.5, -4.9), (10.5, -6.9)];
    assert_eq!(first_cuts(a, "fanuc_lathe", "G73"), passes);
    assert_eq!(first_cuts(&b, "fanuc_lathe_b", "G73"), passes);
    let d = Registry::shipped().get("fanuc_lathe_b").unwrap();
    let plan = pipeline::analyze(b.as_bytes(), &d, &Profile::default()).plan;
    let intent = plan.workingsteps[0].turning.as_deref().and_then(|t| t.intent.clone()).unwrap();
    assert_eq!(
        (intent.allowance_x, intent.allowance_z, intent.relief, intent.divisions),
        (Some(1.0), Some(0.1), Some([14.0, 4.0]), Some(3))
    );
}

/// A face groove pecked by `G74` off the axis (Fanuc 0i-TF, G74 with X(U) and Z(W): pecks along
/// Z) and then, by the same tool at its feed, its walls and floor cut to size (a plunge down
/// each wall along -Z, across the floor, back up along +Z): one grooving operation that
/// finishes the groove, between the passes' smallest and largest diameter at the deepest floor.
/// Its passes across the floor are along the groove, not a boring bar's pull-off.
#[test]
fn a_face_groove_pecked_then_its_walls_cut_is_one_grooving() {
    let program = "O1\nG21 G99\n(T0606 FACE GROOVE)\nT0606\nG50 S2500\nG96 S180 M3\nG0 X89. Z1.\nZ-3.\nG74 R0.02\nG74 X89. Z-6.35 Q380 F0.13\n\
X90.78\nG1 Z-3.8\nX90.04 Z-4.18\nZ-6.48\nX89.03\nG0 Z3.\nX87.91\nG1 Z-6.48\nX89.03\nG0 Z6.\nX300. Z100.\nM30\n";
    let d = Registry::shipped().get("fanuc_lathe").unwrap();
    let plan = pipeline::analyze(program.as_bytes(), &d, &Profile::default()).plan;
    let ws: Vec<String> = plan.workingsteps.iter().map(|w| w.label()).collect();
    assert_eq!(ws, ["grooving finish"]);
    let groove = plan.features.iter().find(|f| f.kind.label() == "face groove").expect("a face groove");
    assert_eq!(
        (feature_size(groove, "inner"), feature_size(groove, "outer"), feature_size(groove, "z")),
        (Some(87.91), Some(90.78), Some(-6.48))
    );
    // Plunges of the same tool apart from the groove, with a gap to it (the tool's width not
    // in the program), are no walls of it: the groove stays as the G74 cut it.
    let apart = program.replace(
        "X90.78\nG1 Z-3.8\nX90.04 Z-4.18\nZ-6.48\nX89.03\nG0 Z3.\nX87.91\nG1 Z-6.48\nX89.03\nG0 Z6.\n",
        "G0 Z1.\nX80.\nG1 Z-4.\nG0 Z1.\nX100.\nG1 Z-4.\nG0 Z6.\n",
    );
    let plan = pipeline::analyze(apart.as_bytes(), &d, &Profile::default()).plan;
    assert_eq!(plan.workingsteps.len(), 2, "{:?}", plan.workingsteps.iter().map(|w| w.label()).collect::<Vec<_>>());
    let groove = plan.features.iter().find(|f| f.kind.label() == "face groove").expect("a face groove");
    assert_eq!((feature_size(groove, "inner"), feature_size(groove, "outer")), (Some(89.0), Some(89.0)));
    assert_eq!(groove.workingsteps, [1]);
}

/// One pass fed along -Z down to the front and then across towards the axis, stopping short of
/// it (the centre drilled and bored later), faces the front: facing, not a contour.
#[test]
fn a_face_cut_in_short_of_the_axis_faces() {
    let program = "O1\nG21 G99\nT1212\nG50 S2500\nG96 S320 M3\nG0 X140.3 Z1.3\nG1 Z0 F0.25\nX88.9 F0.2\nG0 Z1.3\nX150. Z100.\nM30\n";
    let (ws, features) = labels(program, "fanuc_lathe");
    assert_eq!(ws, ["facing finish"]);
    assert_eq!(features, ["revolved flat"]);
}

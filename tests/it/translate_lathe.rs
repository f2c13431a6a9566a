//! Lathe programs translated between lathe dialects (issue 40): every program of
//! `tests/programs/lathe/` and `tests/programs/lathe_real/` (its dialect on the sidecar's first
//! line) to every other lathe target, as `ncplan translate --check` does it: the program read on
//! the machine its words show (`pipeline::translate`), the text proven by its motion
//! (`pipeline::check_translation`: no silent change of a diameter, a feed or a depth), then read
//! back and its turning plan compared. The verdicts are `tests/golden/translate/lathe.tsv`
//! (`UPDATE_EXPECT=1` rewrites it). A lathe program is not written for a milling control, nor
//! a milling program for a lathe.

use std::path::PathBuf;

use ncplan::diag::{Code, Diagnostic};
use ncplan::interp::Profile;
use ncplan::pipeline::{self, TranslateOptions};

use crate::translate::dialect;

/// The lathe targets: the lathe dictionaries, and the two controls that turn in the same
/// dictionary as they mill (G7/G8, DIAMON/DIAMOF).
const LATHES: [&str; 9] =
    ["fanuc_lathe", "fanuc_lathe_b", "haas_lathe", "mazak_lathe", "mitsubishi_lathe", "okuma_lathe", "fagor_lathe", "siemens", "linuxcnc"];

/// The lathe programs of the repository, each with the dialect its sidecar names.
fn programs() -> Vec<(String, PathBuf)> {
    let mut out = Vec::new();
    for folder in ["tests/programs/lathe", "tests/programs/lathe_real"] {
        let dir = crate::root().join(folder);
        let mut files: Vec<PathBuf> = std::fs::read_dir(&dir)
            .unwrap()
            .filter_map(|e| e.ok().map(|e| e.path()))
            .filter(|p| p.extension().is_some_and(|e| e != "expect" && e != "tsv"))
            .collect();
        files.sort();
        for f in files {
            let Ok(expect) = std::fs::read_to_string(f.with_extension("expect")) else { continue };
            let Some(d) = expect.lines().next().and_then(|l| l.strip_prefix("dialect ")) else { continue };
            out.push((d.trim().to_owned(), f));
        }
    }
    out
}

/// Translates `text` from `from` to `to` as `ncplan translate --check` does: the text and the
/// writer's findings, with the proof's.
fn translate_checked(text: &str, from: &str, to: &str, name: &str) -> (String, Vec<Diagnostic>) {
    let (from, to) = (dialect(from), dialect(to));
    let mut out = Vec::new();
    let opts = TranslateOptions { follow_source_units: true, ..TranslateOptions::for_program(name) };
    let mut diags = pipeline::translate(text, &from, &to, &Profile::default(), opts, |b| out.extend_from_slice(b));
    let written = String::from_utf8(out).expect("UTF-8");
    if !diags.iter().any(Diagnostic::is_error) {
        diags.extend(pipeline::check_translation(text.into(), &from, &written, &to, &Profile::default(), &diags));
    }
    (written, diags)
}

/// The verdict of one translation: `untranslatable` or `refused by the proof` with the
/// reason, else `proven` and what the plan read back says of it (`same plan`, or the first
/// change the diff finds).
fn verdict(text: &str, from: &str, to: &str, name: &str) -> (String, String) {
    let (written, diags) = translate_checked(text, from, to, name);
    if let Some(e) = diags.iter().find(|d| d.is_error()) {
        let what = if e.code == Code::PostMotionDiffers { "refused by the proof" } else { "untranslatable" };
        return (written, format!("{what}: {}: {}", e.code.as_str(), e.message));
    }
    let original = pipeline::analyze(text.as_bytes(), &dialect(from), &Profile::default());
    let back = pipeline::analyze(written.as_bytes(), &dialect(to), &Profile::default());
    let kinds = |a: &pipeline::Analysis| a.plan.workingsteps.iter().map(|w| w.operation.label()).collect::<Vec<_>>().join(" ");
    let changes = pipeline::diff(&original, &dialect(from), &back, &dialect(to));
    let said: Vec<&str> = diags.iter().filter(|d| d.code.as_str().starts_with("post::")).map(|d| d.code.as_str()).collect();
    let said = if said.is_empty() { String::new() } else { format!(" [{}]", said.join(" ")) };
    let plan = if kinds(&original) != kinds(&back) {
        format!("workingsteps {} became {}", kinds(&original), kinds(&back))
    } else if let Some(c) = changes.iter().find(|c| c.kind != ncplan::diff::ChangeKind::ToolRenamed) {
        format!("diff: {}", c.phrase())
    } else {
        "same plan".into()
    };
    (written, format!("proven{said}: {plan}"))
}

fn table() -> String {
    let mut out = String::from(
        "# from\tto\tfile\tverdict (proven: `translate --check` runs it as the source, then the plan read back; untranslatable: refused with the reason)\n",
    );
    for (from, path) in programs() {
        let text = std::fs::read_to_string(&path).unwrap();
        let file = path.strip_prefix(crate::root().join("tests/programs")).unwrap().display().to_string();
        let stem = path.file_stem().unwrap().to_string_lossy().into_owned();
        for to in LATHES.iter().filter(|t| **t != from) {
            let (_, v) = verdict(&text, &from, to, &stem);
            let v: String = v.chars().take(240).collect();
            out.push_str(&format!("{from}\t{to}\t{file}\t{v}\n"));
        }
    }
    out
}

#[test]
fn lathe_programs_translate_between_lathe_dialects_proven_by_their_motion() {
    let rows = table();
    let path = crate::root().join("tests/golden/translate/lathe.tsv");
    if std::env::var_os("UPDATE_EXPECT").is_some() {
        std::fs::write(&path, &rows).unwrap();
    }
    // What the proof lets through runs as the source: no verdict says the read back reads
    // with errors or that a translation written without an error was refused for its motion
    // only after a silent change.
    let proven = rows.lines().filter(|l| l.contains("\tproven")).count();
    assert!(proven > 0, "{rows}");
    assert_eq!(std::fs::read_to_string(&path).unwrap_or_default(), rows, "tests/golden/translate/lathe.tsv is stale");
}

fn lathe_program(name: &str) -> String {
    std::fs::read_to_string(crate::root().join("tests/programs/lathe").join(name)).unwrap()
}

#[test]
fn a_lathe_program_is_not_written_for_a_mill_nor_a_mill_program_for_a_lathe() {
    let text = lathe_program("fanuc_g90_turn.nc");
    for mill in ["fanuc", "haas", "heidenhain", "okuma"] {
        let (_, diags) = translate_checked(&text, "fanuc_lathe", mill, "O1003");
        let e = diags
            .iter()
            .find(|d| d.is_error() && d.message.contains("the program turns"))
            .unwrap_or_else(|| panic!("fanuc_lathe → {mill}: {diags:?}"));
        assert_eq!(e.code, Code::PostUnwritable, "{e:?}");
        assert!(e.message.contains("the target is a milling control"), "{}", e.message);
    }
    let mill = "%\nO0001\nG21 G17 G40 G49 G80 G90\nT1 M6\nS1000 M3\nG0 X10. Y10.\nG43 Z5. H1\nG1 Z-1. F100.\nX40.\nG0 Z5.\nM30\n%\n";
    for lathe in ["fanuc_lathe", "fanuc_lathe_b", "haas_lathe", "okuma_lathe"] {
        let (_, diags) = translate_checked(mill, "fanuc", lathe, "O0001");
        let e = diags
            .iter()
            .find(|d| d.is_error() && d.message.contains("a milling program is not translated for a lathe"))
            .unwrap_or_else(|| panic!("fanuc → {lathe}: {diags:?}"));
        assert_eq!(e.code, Code::PostUnwritable, "{e:?}");
    }
}

/// A few translations written out whole (`tests/golden/translate/lathe_examples.txt`), read by
/// eye once: a Fanuc system A program with its clamp to system B, Siemens and LinuxCNC; a
/// LinuxCNC G7 program and a Siemens DIAMON one to a Fanuc lathe; a G32 thread to system B.
#[test]
fn lathe_translations_read_as_a_turner_writes_them() {
    let cases = [
        ("fanuc_css_clamp.nc", "fanuc_lathe", "fanuc_lathe_b"),
        ("fanuc_css_clamp.nc", "fanuc_lathe", "siemens"),
        ("fanuc_css_clamp.nc", "fanuc_lathe", "linuxcnc"),
        ("fanuc_g32_thread.nc", "fanuc_lathe", "fanuc_lathe_b"),
        ("lcnc_g7_turn.ngc", "linuxcnc", "fanuc_lathe"),
        ("siemens_diamon.mpf", "siemens", "linuxcnc"),
    ];
    let mut out = String::new();
    for (file, from, to) in cases {
        let text = lathe_program(file);
        let (written, diags) = translate_checked(&text, from, to, file.split('.').next().unwrap());
        assert!(!diags.iter().any(Diagnostic::is_error), "{file} → {to}: {diags:?}");
        out.push_str(&format!("==== {file} ({from}) → {to}\n{written}\n"));
    }
    let path = crate::root().join("tests/golden/translate/lathe_examples.txt");
    if std::env::var_os("UPDATE_EXPECT").is_some() {
        std::fs::write(&path, &out).unwrap();
    }
    assert_eq!(std::fs::read_to_string(&path).unwrap_or_default(), out, "tests/golden/translate/lathe_examples.txt is stale");
}

/// Feed per minute and per revolution, a dwell given in seconds by U (system A), X kept as a
/// diameter: each target's own words, written down by hand before the translation was run.
#[test]
fn feed_modes_dwells_and_diameters_in_each_targets_words() {
    let text = "%\nO2001 (DWELL AND FEED PER MINUTE)\nG21 G99\nT0202\nG97 S600 M03\nG00 X40. Z2.\nG98 G01 Z-10. F120.\nG04 U0.5\nG99 G01 X44. F0.1\nG00 X100. Z100.\nM30\n%\n";
    let expect: [(&str, &[&str]); 4] = [
        ("fanuc_lathe_b", &["G95", "T0202", "G0 X40. Z2.", "G94", "G1 Z-10. F120.", "G4 P500", "G95", "X44. F0.1", "G0 X100. Z100."]),
        ("haas_lathe", &["G99", "T0202", "G0 X40. Z2.", "G98", "G1 Z-10. F120.", "G4 P500", "G99", "X44. F0.1"]),
        ("siemens", &["DIAMON", "G0 X40 Z2", "G94", "G1 Z-10 F120", "G4 F0.5", "G95", "X44 F0.1"]),
        ("linuxcnc", &["G7", "G0 X40 Z2", "G94", "G1 Z-10 F120", "G4 P0.5", "G95", "X44 F0.1"]),
    ];
    for (to, lines) in expect {
        let (written, diags) = translate_checked(text, "fanuc_lathe", to, "O2001");
        assert!(!diags.iter().any(Diagnostic::is_error), "→ {to}: {diags:?}\n{written}");
        let got: Vec<&str> = written.lines().map(|l| l.split_once(' ').filter(|(n, _)| n.starts_with('N')).map_or(l, |(_, r)| r)).collect();
        let mut at = 0;
        for want in lines {
            let k = got[at..].iter().position(|l| l == want).unwrap_or_else(|| panic!("→ {to}: no `{want}` after line {at}:\n{written}"));
            at += k + 1;
        }
    }
}

/// The straight moves of `program` read in `dialect`, in the canon's frame (X as the radius),
/// each with whether it is a leg of a reference return, and the position each return left
/// from with its pass-through point.
#[allow(clippy::type_complexity)]
fn moves_and_returns(dialect_name: &str, program: &str) -> (Vec<([f64; 3], bool)>, Vec<([f64; 3], [f64; 3])>) {
    use ncplan::canon::{Canon, CanonOp, MachineTarget};
    let mut canon: Vec<Canon> = Vec::new();
    let diags = ncplan::interp::interpret(program, &dialect(dialect_name), &Profile::default(), &mut canon);
    assert!(!diags.iter().any(Diagnostic::is_error), "{dialect_name}: {diags:?}");
    let (mut moves, mut returns) = (Vec::new(), Vec::new());
    let (mut at, mut legs, mut from) = ([0.0; 3], 0, None);
    for c in &canon {
        match &c.op {
            CanonOp::MachineMove(m) if matches!(m.target, MachineTarget::Reference(_)) => {
                (legs, from) = (m.moves(), Some(at));
            }
            CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) => {
                let p = [p[0], p[1], p[2]];
                if let Some(f) = from.take() {
                    returns.push((f, p));
                }
                moves.push((p, legs > 0));
                legs = legs.saturating_sub(1);
                at = p;
            }
            _ => {}
        }
    }
    (moves, returns)
}

/// `G28 U0. W0.`, the return home every Fanuc and Haas lathe program ends with: U and W are
/// X and Z incremental whatever G90/G91 says (Fanuc 0i-TF and Haas lathe operator's manuals,
/// G28: the axes go through the intermediate point the words give, here the tool's own
/// position). Read as absolute it passed through X0 Z0, and a translation wrote that as a
/// rapid to the part's face centre before the G28.
#[test]
fn a_lathe_home_return_by_u_and_w_passes_through_where_the_tool_is_never_x0_z0() {
    let program = "%\nO0001\nG21 G99\nT0101\nG97 S800 M3\nG0 X44. Z2.\nG1 Z-20. F0.2\nG0 X50.\nG28 U0. W0.\nM30\n%\n";
    for from in ["fanuc_lathe", "haas_lathe"] {
        let (_, returns) = moves_and_returns(from, program);
        // X50. is a diameter: the canon holds the radius 25.
        assert_eq!(returns, vec![([25.0, 0.0, -20.0], [25.0, 0.0, -20.0])], "{from}");
    }
    // A U or W that is not zero passes through the point that far from the tool.
    let (_, returns) = moves_and_returns("fanuc_lathe", &program.replace("G28 U0. W0.", "G28 U10. W5."));
    assert_eq!(returns, vec![([25.0, 0.0, -20.0], [30.0, 0.0, -15.0])]);
    // X and Z stated absolute go through that point, as the control does.
    let (_, returns) = moves_and_returns("fanuc_lathe", &program.replace("G28 U0. W0.", "G28 X60. Z10."));
    assert_eq!(returns, vec![([25.0, 0.0, -20.0], [30.0, 0.0, 10.0])]);

    let (source, returns) = moves_and_returns("fanuc_lathe", program);
    assert_eq!(returns.len(), 1);
    for to in LATHES.iter().filter(|t| **t != "fanuc_lathe") {
        let (out, diags) = translate_checked(program, "fanuc_lathe", to, "O0001");
        // No block but the return itself names X0 and Z0: no rapid to the face centre.
        assert!(!out.lines().any(|l| !l.contains("G28") && l.contains("X0") && l.contains("Z0")), "{to} wrote a move to X0 Z0:\n{out}");
        // A target with no return through a point refuses it, naming it (Okuma and Siemens).
        if let Some(e) = diags.iter().find(|d| d.is_error() && d.message.contains("return to reference position")) {
            assert_eq!(e.code, Code::PostUnwritable, "{to}: {e:?}");
            assert!(e.message.contains("return to reference position 1 in X Z"), "{to}: {}", e.message);
            continue;
        }
        assert!(!diags.iter().any(Diagnostic::is_error), "{to}: {diags:?}\n{out}");
        // Read back: the same moves, the return through the same point.
        let (back, back_returns) = moves_and_returns(to, &out);
        assert_eq!(back_returns, returns, "{to}:\n{out}");
        let near = |a: [f64; 3], b: [f64; 3]| a.iter().zip(b).all(|(x, y)| (x - y).abs() < 1e-3);
        let stated = |m: &[([f64; 3], bool)]| m.iter().filter(|(_, leg)| !leg).map(|(p, _)| *p).collect::<Vec<_>>();
        let (a, b) = (stated(&source), stated(&back));
        assert!(a.len() == b.len() && a.iter().zip(&b).all(|(p, q)| near(*p, *q)), "{to}: {a:?} became {b:?}\n{out}");
        assert_eq!(back.len(), source.len(), "{to}:\n{out}");
    }
}

/// The motion check refuses a lathe translation that passes through X0 Z0 on its way home.
#[test]
fn the_motion_check_refuses_a_lathe_return_through_the_face_centre() {
    let program = "%\nO0001\nG21 G99\nT0101\nG97 S800 M3\nG0 X44. Z2.\nG1 Z-20. F0.2\nG0 X50.\nG28 U0. W0.\nM30\n%\n";
    let (out, diags) = translate_checked(program, "fanuc_lathe", "fanuc_lathe_b", "O0001");
    assert!(!diags.iter().any(Diagnostic::is_error), "{diags:?}");
    let planted = out.replacen("G91 G28", "G0 X0. Z0.\nG91 G28", 1);
    assert_ne!(planted, out, "{out}");
    let found =
        pipeline::check_translation(program.into(), &dialect("fanuc_lathe"), &planted, &dialect("fanuc_lathe_b"), &Profile::default(), &[]);
    assert!(found.iter().any(|d| d.code == Code::PostMotionDiffers), "{found:?}\n{planted}");
}

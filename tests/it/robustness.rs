//! Nothing panics or hangs: arbitrary bytes, mutated real programs, and the whole corpus.

use ncplan::dialect::Registry;
use ncplan::interp::Profile;
use ncplan::pipeline::analyze;
use proptest::prelude::*;

fn dialects() -> Vec<std::sync::Arc<ncplan::dialect::Dialect>> {
    let r = Registry::shipped();
    r.names().map(|n| r.get(n).unwrap()).collect::<Vec<_>>()
}

/// Every program of the shared corpus (none when it is absent).
fn corpus_files() -> Vec<std::path::PathBuf> {
    static FILES: std::sync::OnceLock<Vec<std::path::PathBuf>> = std::sync::OnceLock::new();
    FILES
        .get_or_init(|| {
            let mut out = Vec::new();
            let Some(corpus) = crate::shared_corpus("robustness (the mutated corpus programs)") else { return out };
            let Ok(dirs) = std::fs::read_dir(corpus) else { return out };
            for d in dirs.flatten().filter(|d| d.path().is_dir()) {
                out.extend(std::fs::read_dir(d.path()).into_iter().flatten().flatten().map(|e| e.path()));
            }
            out.sort();
            out
        })
        .clone()
}

/// Small loop limits, so that a mutated endless loop ends quickly.
fn profile() -> Profile {
    Profile { max_loop_iterations: 2_000, max_blocks: 50_000, ..Profile::default() }
}

fn check_ranges(bytes: &[u8]) {
    for d in dialects() {
        let a = analyze(bytes, &d, &profile());
        let len = a.source.text.len() as u32;
        for x in &a.diagnostics {
            assert!(x.range.start <= x.range.end && x.range.end <= len, "{x:?}");
            assert!(
                a.source.text.is_char_boundary(x.range.start as usize) && a.source.text.is_char_boundary(x.range.end as usize),
                "{x:?}"
            );
        }
        for c in &a.canon {
            assert!(c.origin.end <= len);
        }
        let _ = serde_json::to_string(&a.plan).unwrap();
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: std::env::var("NCPLAN_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(256), ..ProptestConfig::default() })]

    #[test]
    fn arbitrary_bytes_never_panic(bytes in proptest::collection::vec(any::<u8>(), 0..400)) {
        check_ranges(&bytes);
    }

    #[test]
    fn gcode_like_text_never_panics(s in "[GMXYZIJKRFSTPQLHN#\\[\\]()0-9.+\\-*/ =<>a-z;%\n]{0,300}") {
        check_ranges(s.as_bytes());
    }

    #[test]
    fn statement_soup_never_panics_or_hangs(parts in proptest::collection::vec(prop_oneof![
        Just("IF [#1 LT 3] GOTO 10\n"), Just("IF [#1 EQ #0] THEN #2=1\n"), Just("WHILE [#1 LT 5] DO 1\n"), Just("END 1\n"),
        Just("DO 2\n"), Just("END 2\n"), Just("GOTO 10\n"), Just("N10 #1=#1+1\n"), Just("G65 P9000 A1 B#1\n"), Just("M98 P1000 L2\n"),
        Just("M99\n"), Just("O1000\n"), Just("O9000\n"), Just("#3000=1 (STOP)\n"), Just("o1 sub\n"), Just("o1 endsub\n"),
        Just("o1 call [1] [2]\n"), Just("o2 while [#1 LT 4]\n"), Just("o2 endwhile\n"), Just("o3 if [#1]\n"), Just("o3 else\n"),
        Just("o3 endif\n"), Just("o4 repeat [3]\n"), Just("o4 endrepeat\n"), Just("o2 break\n"), Just("o2 continue\n"),
        Just("o5 do\n"), Just("o5 while [1]\n"), Just("G1 X#1 Y[#2*2] F100\n"), Just("%\n"), Just("M30\n"), Just("#[#1]=#0\n"),
        Just("G71 U2. R0.5\n"), Just("G71 P10 Q20 U0.4 W0.1 F0.25\n"), Just("N20 G2 X52. Z-5. R4.\n"), Just("G70 P10 Q20\n"),
        Just("G90 X40. Z-10. F0.2\n"), Just("HOLES2(0,0,5,0,0,4)\n"), Just("G70 I1. J0. L3\n"),
    ], 0..40)) {
        check_ranges(parts.concat().as_bytes());
    }

    /// Run only as the child of [`mutated_corpus_programs_never_panic`], which sets
    /// `NCPLAN_ROBUSTNESS_CASE` to the file each case is written to before it runs.
    #[test]
    fn mutated_corpus_case_runner(pick in any::<prop::sample::Index>(), seed in any::<u64>(), edits in proptest::collection::vec((any::<u32>(), any::<u8>()), 1..40)) {
        let Some(case_file) = std::env::var_os("NCPLAN_ROBUSTNESS_CASE") else { return Ok(()) };
        let files = corpus_files();
        if files.is_empty() {
            return Ok(());
        }
        let mut bytes = std::fs::read(pick.get(&files)).unwrap();
        bytes.truncate(64 * 1024);
        for (i, (pos, b)) in edits.iter().enumerate() {
            let at = (*pos as usize) % (bytes.len() + 1);
            match (seed as usize + i) % 4 {
                0 if at < bytes.len() => bytes[at] = *b,
                1 => bytes.insert(at, *b),
                2 if at < bytes.len() => { bytes.remove(at); }
                // Duplicate a stretch: repeated loops, labels and blocks.
                _ => {
                    let end = (at + 200).min(bytes.len());
                    let stretch = bytes[at..end].to_vec();
                    bytes.splice(at..at, stretch);
                }
            }
        }
        // Kept before it runs: a case that takes the child down (out of memory, a stack
        // overflow) is then still there to read.
        std::fs::write(&case_file, &bytes).unwrap();
        check_ranges(&bytes);
    }

    #[test]
    fn mutated_real_programs_never_panic(seed in any::<u64>(), which in 0usize..3, edits in proptest::collection::vec((any::<u16>(), any::<u8>()), 1..20)) {
        let sources = ["demo/cam/O1234.nc", "tests/programs/linuxcnc/oword_flow.ngc", "tests/programs/linuxcnc/inverse_time.ngc"];
        let demo = std::fs::read(crate::root().join(sources[which])).unwrap();
        let mut bytes = demo.clone();
        for (i, (pos, b)) in edits.iter().enumerate() {
            let at = (*pos as usize + seed as usize) % (bytes.len() + 1);
            match (seed as usize + i) % 3 {
                0 if at < bytes.len() => bytes[at] = *b,
                1 => bytes.insert(at, *b),
                _ if at < bytes.len() => { bytes.remove(at); }
                _ => {}
            }
        }
        check_ranges(&bytes);
    }
}

/// Mutated corpus programs (bytes changed, inserted, removed; stretches repeated: loops,
/// labels and blocks) neither panic nor grow without bound. The cases run in a child process
/// under a 4 GiB address-space limit, each written to a file before it runs: a case that
/// would take the whole test run down (an allocation beyond any bound kills the process
/// before a panic can be caught) fails this test instead, with the case kept to read.
#[test]
fn mutated_corpus_programs_never_panic() {
    if std::env::var_os("NCPLAN_ROBUSTNESS_CASE").is_some() {
        return;
    }
    let dir = crate::root().join("target/robustness");
    std::fs::create_dir_all(&dir).unwrap();
    let case = dir.join(format!("mutated-case-{}.bin", std::process::id()));
    let exe = std::env::current_exe().unwrap();
    let out = std::process::Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 4194304 && exec \"$0\" \"$@\"")
        .arg(&exe)
        .args(["robustness::mutated_corpus_case_runner", "--exact", "--test-threads", "1"])
        .env("NCPLAN_ROBUSTNESS_CASE", &case)
        .output()
        .unwrap();
    if out.status.success() {
        let _ = std::fs::remove_file(&case);
        return;
    }
    let tail = |b: &[u8]| {
        let s = String::from_utf8_lossy(b);
        s.lines().rev().take(40).collect::<Vec<_>>().into_iter().rev().collect::<Vec<_>>().join("\n")
    };
    panic!(
        "the mutated corpus programs failed in the child ({}); the last case run is kept in {}\n--- stdout\n{}\n--- stderr\n{}",
        out.status,
        case.display(),
        tail(&out.stdout),
        tail(&out.stderr)
    );
}

/// Reading the text piece by piece (a window of `window` bytes, refilled and grown as blocks
/// need; jumps back read again) gives what the whole text gives, in every dialect: the same
/// calls with their source ranges, and the same findings.
fn piecewise_agrees(bytes: &[u8], window: usize) {
    use ncplan::text::{BytesReader, Text};
    let (whole, _) = ncplan::text::decode(bytes);
    let (reader, _) = BytesReader::new(bytes.to_vec(), 7, window);
    for d in dialects() {
        let run = |text: Text<'_>| {
            let mut canon = Vec::new();
            let diags = ncplan::interp::interpret(text, &d, &profile(), &mut canon);
            (canon.iter().map(|c| format!("{c:?}")).collect::<Vec<_>>(), diags.iter().map(|x| format!("{x:?}")).collect::<Vec<_>>())
        };
        assert_eq!(run(Text::Whole(&whole.text)), run(Text::Read(&reader)), "{} with a window of {window}", d.name);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: std::env::var("NCPLAN_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(48), ..ProptestConfig::default() })]

    #[test]
    fn reading_piece_by_piece_changes_nothing(window in 1usize..40, parts in proptest::collection::vec(prop_oneof![
        Just("IF [#1 LT 3] GOTO 10\n".to_owned()), Just("WHILE [#1 LT 5] DO 1\n".to_owned()), Just("END 1\n".to_owned()), Just("GOTO 10\n".to_owned()), Just("N10 #1=#1+1\n".to_owned()),
        Just("M98 P1000 L2\n".to_owned()), Just("M99\n".to_owned()), Just("O1000\n".to_owned()), Just("o1 sub\n".to_owned()), Just("o1 endsub\n".to_owned()), Just("o1 call [1] [2]\n".to_owned()),
        Just("o2 while [#1 LT 4]\n".to_owned()), Just("o2 endwhile\n".to_owned()), Just("G1 X#1 Y[#2*2] F100\n".to_owned()), Just("%\n".to_owned()), Just("M30\n".to_owned()),
        Just("G1 X1.5 Y-2 (a comment é)\r\n".to_owned()), Just("Q200=2 ;CLEARANCE ~\n".to_owned()), Just("  X1 ~\n".to_owned()), Just("\r".to_owned()), Just("\n".to_owned()),
        Just("LBL 1\n".to_owned()), Just("CALL LBL 1 REP 2\n".to_owned()), Just("MARKE1:\n".to_owned()), Just("GOTOB MARKE1\n".to_owned()), Just("R1=R1+1 IF R1<3 GOTOB MARKE1\n".to_owned()),
        Just("GOTO/1,2,3\n".to_owned()), Just("CIRCLE/0,0,0,0,0,1,5\n".to_owned()), Just("FEDRAT/100,$\n 200\n".to_owned()), Just("$$ note\n".to_owned()),
        "[ -~]{0,30}\n".prop_map(|s: String| s),
    ], 0..40)) {
        piecewise_agrees(parts.concat().as_bytes(), window);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: std::env::var("NCPLAN_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(16), ..ProptestConfig::default() })]

    #[test]
    fn reading_mutated_corpus_programs_piece_by_piece_changes_nothing(window in 1usize..200, pick in any::<prop::sample::Index>(), edits in proptest::collection::vec((any::<u32>(), any::<u8>()), 0..8)) {
        let files = corpus_files();
        if files.is_empty() {
            return Ok(());
        }
        let mut bytes = std::fs::read(pick.get(&files)).unwrap();
        bytes.truncate(16 * 1024);
        for (pos, b) in edits {
            let at = pos as usize % (bytes.len() + 1);
            bytes.insert(at, b);
        }
        piecewise_agrees(&bytes, window);
    }
}

/// Runs `text` with and without the interpreter's fast paths (the lane for plain moves, the
/// cache of lexed loop bodies); both ways must give the same calls (with their source ranges)
/// and the same findings.
fn fast_lane_agrees(text: &str) {
    for d in dialects() {
        let run = |fast_lane: bool| {
            let mut canon = Vec::new();
            let diags = ncplan::interp::interpret(text, &d, &Profile { fast_lane, ..profile() }, &mut canon);
            (format!("{canon:?}"), format!("{diags:?}"))
        };
        let (fast, general) = (run(true), run(false));
        assert!(fast == general, "{}: the fast lane differs on\n{text}\nfast: {fast:?}\ngeneral: {general:?}", d.name);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: std::env::var("NCPLAN_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(64), ..ProptestConfig::default() })]

    /// Plain moves between every kind of block that changes what a plain move means: motion
    /// modes, distance and units, inverse time, cycles, compensation, rotation and scaling,
    /// tool changes, stops, block numbers, comments and integers that may count increments.
    #[test]
    fn fast_lane_changes_nothing(parts in proptest::collection::vec(prop_oneof![
        Just("X1.5 Y2.25\n"), Just("Z-1.\n"), Just("X10 Y-3\n"), Just("Y.5 X-.25 Z3\n"), Just("X1 X2\n"), Just("x4.5 z-.1\n"),
        Just("N20 X3 Y3\n"), Just("/X7 Y7\n"), Just("X2 (note)\n"), Just("G0 X0 Y0 Z5\n"), Just("G1 Z-1 F300\n"), Just("G1 X5\n"),
        Just("G2 X10 Y0 I2.5 J0\n"), Just("G91\n"), Just("G90\n"), Just("G20\n"), Just("G21\n"), Just("G93\n"), Just("G94\n"),
        Just("F0\n"), Just("F500\n"), Just("S1000 M3\n"), Just("M5\n"), Just("G81 R2 Z-5 F100\n"), Just("G80\n"), Just("G17\n"),
        Just("G18\n"), Just("G41 D1\n"), Just("G42 D1\n"), Just("G40\n"), Just("G68 X0 Y0 R30\n"), Just("G69\n"),
        Just("G51 X0 Y0 P2\n"), Just("G50\n"), Just("T1 M6\n"), Just("G43 H1\n"), Just("G54\n"), Just("G55\n"),
        Just("G92 X0 Y0\n"), Just("G53 X0\n"), Just("M0\n"), Just("#1=2\n"), Just("X#1\n"), Just("G64 P0.01\n"),
        Just("G66 P9000\n"), Just("G67\n"), Just("G7\n"), Just("G8\n"), Just("M30\n"),
        Just("o1 repeat [3]\n"), Just("o1 endrepeat\n"), Just("#1=0\n"), Just("o2 while [#1 LT 3]\n"), Just("#1=[#1+1]\n"),
        Just("G1 X5 Y2 F200\n"), Just("G01 Z-2 F50.\n"), Just("G0 X1 Y1\n"), Just("G1 X1 F0\n"), Just("G1 X2 G0 Y1\n"), Just("N5 G1 X3 F100 F200\n"),
        Just("o2 endwhile\n"), Just("WHILE [#1 LT 3] DO 1\n"), Just("END 1\n"), Just("X[#1*2] Y@\n"), Just("GOTO 20\n"), Just("N20 G0 X1\n"),
        Just("Z-2 Y1 X3\n"), Just("Y1 G1 X2 Y3\n"), Just("X.5 F200 Z1\n"), Just("Z1 Z1\n"), Just("G0 F100 Y2 X-1.\n"),
    ], 0..40)) {
        fast_lane_agrees(&parts.concat());
    }
}

/// A loop's moves whose words are expressions of ordinary numbers take the fast lane
/// (`G1 X#<x>`, `G1 X=XP`, Heidenhain's `L X+Q3`, the bench's macro programs), and so do
/// Heidenhain's literal `L` moves; with its look-alikes that must go the general way (a
/// word per axis mode, a rapid, compensation, a vacant or unknown value, a system variable),
/// both ways give the same calls and findings.
#[test]
fn moves_from_expressions_agree_with_the_general_way() {
    let heidenhain = "BEGIN PGM T MM\nTOOL CALL 1 Z S1000\nL X+0 Y+0 Z+5 R0 FMAX M3\nL Z+0 F300\nFN 0: Q1 = +0\nLBL 1\n\
        L X+Q1 Y+Q1\nL IX+Q1 Y+2\nL X+Q1 FMAX\nL X+Q1 RL F200\nL X+Q1 R0\nL X+Q108 Y+Q1\nL X+Q77 Y+1\nL X+1 Y+Q1 Z-1\n\
        FN 1: Q1 = +Q1 + +1\nFN 12: IF +Q1 LT +4 GOTO LBL 1\nL Z+5 R0 FMAX\nEND PGM T MM\n";
    let siemens = "DEF REAL XP\nG17 G90 G71\nT1 D1\nM6\nF500\nG0 X0 Y0 Z5\nR1=0\nXP=0\nP1:\nG1 X=XP Y=R1 Z=-1\n\
        G1 X=IC(XP) Y=2\nG0 X=XP\nG1 X=XP+$AA_IM[X] Y=1\nG1 X=R9 Y=R1\nXP=XP+0.5\nR1=R1+1\nIF R1<4 GOTOB P1\nM30\n";
    let linuxcnc = "G21 G90 G17\nF600\n#<i> = 0\no1 while [#<i> LT 4]\nG1 X#<i> Y[#<i> * 2] Z[-1 - #<i>]\n\
        G1 X#<_x> Y1\nG0 X[#<i> + 0.5]\nG1 X#1 Y#<i>\nX[#<i>/3] F[100 + #<i>]\n#<i> = [#<i> + 1]\no1 endwhile\nM2\n";
    let programs = [
        ("heidenhain", heidenhain.to_owned()),
        ("siemens", siemens.to_owned()),
        ("linuxcnc", linuxcnc.to_owned()),
        ("linuxcnc", ncplan::bench::macro_program(2)),
        ("siemens", ncplan::bench::siemens_macro_program(2)),
        ("heidenhain", ncplan::bench::heidenhain_macro_program(2)),
    ];
    let r = Registry::shipped();
    for (dialect, text) in programs {
        let d = r.get(dialect).unwrap();
        let run = |fast_lane: bool| {
            let mut canon = Vec::new();
            let diags = ncplan::interp::interpret(text.as_str(), &d, &Profile { fast_lane, ..profile() }, &mut canon);
            (format!("{canon:?}"), format!("{diags:?}"))
        };
        let (fast, general) = (run(true), run(false));
        assert!(fast == general, "{dialect}: the fast lane differs on\n{text}\nfast: {fast:?}\ngeneral: {general:?}");
        assert!(fast.0.matches("StraightFeed").count() >= 4, "{dialect}: no moves made: {}", fast.0);
    }
}

/// Where the dialect has corner blocks (Heidenhain's `RND`, `CHF`), the corner stage stands
/// open from the start and a plain move passes it without its lists while nothing waits in
/// it (`Corners::pass_straight`); corner words (`,R`, `,C`) open it at their first block.
/// Around corners, approaches, rapids, compensation, plane and offset changes, feeds and the
/// program's end, the fast lane and the general way give the same calls and findings, and
/// the corners are made.
#[test]
fn moves_through_the_corner_stage_agree_with_the_general_way() {
    let heidenhain = "BEGIN PGM C MM\nTOOL CALL 1 Z S1000\nL X+0 Y+0 Z+5 R0 FMAX M3\nL Z-1 F300\nL X+10\nRND R2\nL Y+10\n\
        L X+20 Y+10\nCHF 1\nL X+20 Y+0\nL X+30\nRND R1 F100\nL Y+5\nL X+40 FMAX\nL X+50\nRND R0.5\nL X+50 Y+9 FMAX\n\
        L X+60\nCHF 1\nCC X+60 Y+20\nC X+70 Y+20 DR+\nL X+70 Y+30\nRND R1\nL X+80 Y+30 Z-2\nL X+0 Y+0\n\
        APPR LT X+10 Y+10 LEN 5 RL F200\nL X+30 Y+10\nRND R3\nL X+30 Y+30\nDEP LT LEN 5\nL R0\nL X+5 Y+5\n\
        FN 0: Q1 = +0\nLBL 1\nL X+Q1 Y+0\nL X+Q1 Y+5\nRND R1\nL X+Q1 Y+5 Z+Q1\nFN 1: Q1 = +Q1 + +1\n\
        FN 12: IF +Q1 LT +4 GOTO LBL 1\nL X+9 Y+9\nCHF 50\nL X+1 Y+9\nL Z+5 R0 FMAX\nL X+0 Y+0\nEND PGM C MM\n";
    let fanuc = "%\nO1000\nG21 G90 G17\nT1 M6\nS1000 M3\nG0 X0. Y0. Z5.\nG1 Z-1. F300.\nX10.\nX10. Y10. ,R2.\nX20.\nY0. ,C1.\n\
        X30.\nX30. Y10. ,R1.\nY20.\nG0 X40.\nG1 X50. ,R1.\nY5.\nG2 X55. Y10. R5.\nG1 X60. ,R1.\nY20.\nX0. Y0.\nG0 Z5.\nM30\n%\n";
    let programs = [("heidenhain", heidenhain), ("fanuc", fanuc)];
    let r = Registry::shipped();
    for (dialect, text) in programs {
        let d = r.get(dialect).unwrap();
        let run = |fast_lane: bool| {
            let mut canon = Vec::new();
            let diags = ncplan::interp::interpret(text, &d, &Profile { fast_lane, ..profile() }, &mut canon);
            (canon, diags)
        };
        let ((fast, fast_diags), (general, general_diags)) = (run(true), run(false));
        assert_eq!(format!("{fast:?}"), format!("{general:?}"), "{dialect}: the fast lane differs on\n{text}");
        assert_eq!(format!("{fast_diags:?}"), format!("{general_diags:?}"), "{dialect}: the findings differ on\n{text}");
        // The corners are made: arcs the program does not write (`RND`, `,R`), and more
        // straight feeds than it writes (the chamfers).
        let arcs = fast.iter().filter(|c| matches!(c.op, ncplan::canon::CanonOp::ArcFeed { .. })).count();
        assert!(arcs >= 3, "{dialect}: {arcs} arcs: {fast:?}");
    }
}

/// A loop or called body's blocks, kept lexed, take the replay lane (`Profile::replay_lane`)
/// from their third run on. Generated loop and call programs of four dialects, with
/// assignments, moves, calls, nested loops, forward jumps, unknown values and tight budgets
/// in their bodies, give the same calls and findings on the lane, off it, and the general
/// way (`fast_lane` off).
fn replay_lane_agrees(dialect: &str, text: &str, (max_blocks, max_repeated_blocks): (u64, u64)) {
    let d = Registry::shipped().get(dialect).unwrap();
    let run = |fast_lane: bool, replay_lane: bool| {
        let mut canon = Vec::new();
        let p = Profile { fast_lane, replay_lane, max_blocks, max_repeated_blocks, ..profile() };
        let diags = ncplan::interp::interpret(text, &d, &p, &mut canon);
        (format!("{canon:?}"), format!("{diags:?}"))
    };
    let lane = run(true, true);
    assert!(lane == run(true, false), "{dialect}: the replay lane differs on\n{text}");
    assert!(lane == run(false, false), "{dialect}: the replay lane differs from the general way on\n{text}");
}

/// A program of `dialect` whose loop body is `body`, the loop running `rounds` times.
fn loop_program(dialect: &str, body: &str, rounds: u32) -> String {
    match dialect {
        "linuxcnc" => format!(
            "G21 G90 G17\nF600\n#<i> = 0\n#2 = 0\no100 sub\nG1 X[#2 + 1] Y#<i>\n#2 = [#2 + 1]\no100 endsub\n\
             o1 while [#<i> LT {rounds}]\n{body}#<i> = [#<i> + 1]\no1 endwhile\nG0 Z5\nM2\n"
        ),
        "fanuc" => format!(
            "O1000\nG21 G90 G17\nF600\n#1=0\n#2=0\nWHILE [#1 LT {rounds}] DO 1\n{body}#1=#1+1\nEND 1\nG0 Z5\nM30\n\
             O2000\nG1 X[#2+1] Y#1\n#2=#2+1\nM99\n"
        ),
        "siemens" => format!(
            "DEF REAL XP\nG17 G90 G71\nT1 D1\nM6\nF500\nG0 X0 Y0 Z5\nR1=0\nR2=0\nP1:\n{body}R1=R1+1\nIF R1<{rounds} GOTOB P1\nG0 Z5\nM30\n"
        ),
        _ => format!(
            "BEGIN PGM T MM\nTOOL CALL 1 Z S1000\nL X+0 Y+0 Z+5 R0 FMAX M3\nL Z+0 F300\nFN 0: Q1 = +0\nFN 0: Q2 = +0\nLBL 1\n\
             {body}FN 1: Q1 = +Q1 + +1\nFN 12: IF +Q1 LT +{rounds} GOTO LBL 1\nL Z+5 R0 FMAX\nM30\nLBL 5\nL X+Q2 Y+Q1\n\
             FN 1: Q2 = +Q2 + +1\nLBL 0\nEND PGM T MM\n"
        ),
    }
}

/// Body blocks for [`loop_program`], per dialect: what a macro program's loop holds.
fn body_parts(dialect: &str) -> &'static [&'static str] {
    match dialect {
        "linuxcnc" => &[
            "#<x> = [#<i> * 0.5]\n",
            "G1 X#<x> Y[#<i> * 2] Z[-1 - #<i>]\n",
            "G0 X[#<i> + 0.5]\n",
            "o100 call\n",
            "o2 if [#<i> GT 1]\nG1 Z-1\no2 else\nG1 Z-2\no2 endif\n",
            "o3 repeat [2]\nG1 Y#<i>\no3 endrepeat\n",
            "G2 X1 Y1 I0.5 J0.5\n",
            "S1000 M3\n",
            "G91 X1\nG90\n",
            "X#<_x> Y1\n",
            "G1 X#7\n",
            "(note)\n",
            "G81 R2 Z-5 F100\nG80\n",
            "F[100 + #<i>]\n",
            "/G1 X2\n",
            "N10 G1 X1\n",
            "#5 = [#<i> / [#<i> - 1]]\n",
        ],
        "fanuc" => &[
            "#3=#1*0.5\n",
            "G1 X#3 Y[#1*2]\n",
            "M98 P2000\n",
            "G65 P2000 A1.\n",
            "IF [#1 EQ 1] GOTO 50\nG1 Z-1\nN50 G1 Z0\n",
            "G0 X[#1+0.5]\n",
            "WHILE [#4 LT 2] DO 2\n#4=#4+1\nEND 2\n#4=0\n",
            "G1 X#9\n",
            "S1000 M3\n",
            "(NOTE)\n",
            "G81 R2. Z-5. F100.\nG80\n",
            "G91 X1.\nG90\n",
            "#5=#5+#1\n",
        ],
        "siemens" => &[
            "XP=R1*0.5\n",
            "G1 X=XP Y=R1 Z=-1\n",
            "G1 X=R9 Y=R1\n",
            "G0 X=XP+1\n",
            "IF R1==1 GOTOF SKIP1\nG1 Z-1\nSKIP1:\n",
            "WHILE R3<2\nR3=R3+1\nENDWHILE\nR3=0\n",
            "R2=R2+R1\n",
            "G1 X=IC(XP) Y=2\n",
            "S1000 M3\n",
            "; note\n",
            "G2 X1 Y1 I0.5 J0.5\n",
            "G1 X=XP+$AA_IM[X] Y=1\n",
        ],
        _ => &[
            "FN 3: Q3 = +Q1 * +0.5\n",
            "L X+Q3 Y+Q1\n",
            "Q4 = Q1 * 2\n",
            "L IX+Q1 Y+2\n",
            "CALL LBL 5\n",
            "L X+Q108 Y+Q1\n",
            "L X+Q1 FMAX\n",
            "FN 9: IF +Q1 EQU +1 GOTO LBL 7\nL Z-1\nLBL 7\n",
            "L X+Q77 Y+1\n",
            "; note\n",
            "FN 2: Q6 = +Q6 - +Q1\n",
            // FN arithmetic reading the control's data (the tool radius), and one whose
            // value is an error: the fast lane runs such a block as its assignments alone.
            "FN 0: Q9 = +Q108\n",
            "FN 4: Q7 = +Q1 DIV +0\n",
        ],
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: std::env::var("NCPLAN_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(64), ..ProptestConfig::default() })]

    #[test]
    fn replay_lane_changes_nothing(
        which in 0usize..4,
        picks in proptest::collection::vec(0usize..64, 1..8),
        rounds in 1u32..7,
        budgets in prop_oneof![Just((50_000u64, 25_000u64)), (20u64..300).prop_map(|b| (b, 1_000_000)), (10u64..150).prop_map(|r| (1_000_000, r))],
    ) {
        let dialect = ["linuxcnc", "fanuc", "siemens", "heidenhain"][which];
        let parts = body_parts(dialect);
        let body: String = picks.iter().map(|&p| parts[p % parts.len()]).collect();
        replay_lane_agrees(dialect, &loop_program(dialect, &body, rounds), budgets);
    }
}

/// The bench's macro programs, small, on the replay lane and off it.
#[test]
fn replay_lane_runs_the_bench_macro_programs_alike() {
    for (dialect, text) in [
        ("linuxcnc", ncplan::bench::macro_program(3)),
        ("siemens", ncplan::bench::siemens_macro_program(3)),
        ("heidenhain", ncplan::bench::heidenhain_macro_program(3)),
    ] {
        replay_lane_agrees(dialect, &text, (50_000, 25_000));
        // A budget reached inside the loop: the lane stops where the general loop does.
        replay_lane_agrees(dialect, &text, (157, 1_000_000));
        replay_lane_agrees(dialect, &text, (1_000_000, 93));
    }
}

#[test]
fn hostile_inputs_are_diagnosed() {
    let deep = format!("G1 X{}1{}\n", "[".repeat(10_000), "]".repeat(10_000));
    check_ranges(deep.as_bytes());
    check_ranges(b"\x00\x01\x02binary");
    check_ranges("G1 X1e5 Y\u{00e9} (caf\u{00e9}\nG2 R0 X0\n".as_bytes());
    check_ranges(&"G1 X1 Y2 Z3\n".repeat(20_000).into_bytes());
}

/// Found by `mutated_corpus_programs_never_panic`: EXISTS with something other than `#<name>` inside,
/// here a multi-byte character, once cut a name range inside the character.
#[test]
fn exists_without_a_name_is_diagnosed() {
    check_ranges("o100 if [EXISTS[\u{00d7}#<P>]]\no100 endif\n".as_bytes());
    check_ranges(b"o100 if [EXISTS[\xd7#<P>]]\no100 endif\n");
    let d = Registry::shipped().get("linuxcnc").unwrap();
    let a = analyze(b"o100 if [EXISTS[1]]\no100 endif\nM2\n", &d, &profile());
    assert!(a.diagnostics.iter().any(|x| x.message.contains("EXISTS takes a parameter")), "{:?}", a.diagnostics);
}

/// Found by `mutated_corpus_programs_never_panic` on CI: a multi-byte character where a
/// cycle's argument list expects `,` or `)` got a range that split it.
#[test]
fn a_cycle_argument_list_broken_by_a_multibyte_character_is_diagnosed() {
    check_ranges("CYCLE81(50 \u{00d7}, 0)\nDEF REAL A[3\nG0 X1\n".as_bytes());
    let d = Registry::shipped().get("siemens").unwrap();
    let a = analyze("CYCLE81(50 \u{00d7}, 0)\n".as_bytes(), &d, &profile());
    assert!(a.diagnostics.iter().any(|x| x.message.contains("expected `,` or `)`")), "{:?}", a.diagnostics);
}

/// Found by `mutated_corpus_programs_never_panic` on CI: a multi-byte character where a
/// `FOR` head expects `TO` got a one-byte range inside the character. Parser findings are
/// now widened to whole characters in one place.
#[test]
fn a_for_head_broken_by_a_multibyte_character_is_diagnosed() {
    check_ranges("FOR R1=0 \u{00d7}O 10\nENDFOR\nM30\n".as_bytes());
    let d = Registry::shipped().get("siemens").unwrap();
    let a = analyze("FOR R1=0 \u{00d7} 10\nENDFOR\nM30\n".as_bytes(), &d, &profile());
    let found = a.diagnostics.iter().find(|x| x.message.contains("expected `TO`")).expect("a finding");
    assert_eq!(&a.source.text[found.range.start as usize..found.range.end as usize], "\u{00d7}");
}

/// A post that could not compute a value writes `nan` or `inf` (the corpus has `L Xnan Ynan
/// Znan FMAX`): each such word is named with its position, and the rest of the block runs.
#[test]
fn a_value_the_post_could_not_compute_is_named() {
    for (dialect, program) in [("heidenhain", "0 BEGIN PGM P MM\n1 L Xnan Y+5 FMAX\n2 END PGM P MM\n"), ("fanuc", "G0 X-inf Y5.\nM30\n")] {
        check_ranges(program.as_bytes());
        let d = Registry::shipped().get(dialect).unwrap();
        let a = analyze(program.as_bytes(), &d, &profile());
        let named: Vec<&str> = a
            .diagnostics
            .iter()
            .filter(|x| x.code.as_str() == "syntax::malformed-number")
            .map(|x| &a.source.text[x.range.start as usize..x.range.end as usize])
            .collect();
        assert!(named == ["Xnan"] || named == ["X-inf"], "{dialect}: {:?}", a.diagnostics);
        assert!(
            a.canon.iter().any(|c| matches!(c.op, ncplan::canon::CanonOp::StraightTraverse(p) if p[1] == 5.0)),
            "{dialect}: Y5 still moves"
        );
    }
}

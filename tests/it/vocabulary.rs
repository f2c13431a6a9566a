//! Each shipped dialect's vocabulary (issue 43): the table `dialects/vocabulary/<dialect>.tsv`
//! written from the dictionary (the codes its groups model, its statements and system
//! variables, and its `<vocabulary>` entries kept as intent or known unsupported, each with
//! its manual), and a tiny program per G and M code the table marks modelled or intent,
//! which must read without an error.

use ncplan::diag::{Code, Diagnostic};
use ncplan::dialect::vocabulary::{Kind, Status, table_text};
use ncplan::dialect::{BlockForm, Dialect, Registry, Role};
use ncplan::interp::{Profile, interpret};

fn findings(d: &Dialect, text: &str) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    interpret(text, d, &Profile::default(), &mut out)
}

fn errors(diags: &[Diagnostic]) -> Vec<String> {
    diags.iter().filter(|d| d.is_error()).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect()
}

/// The tables in `dialects/vocabulary/` are the dictionaries' own: rewritten with
/// `UPDATE_EXPECT=1`, read by eye, then kept.
#[test]
fn the_vocabulary_tables_are_the_dictionaries() {
    let dir = crate::root().join("dialects/vocabulary");
    let r = Registry::shipped();
    let mut stale = Vec::new();
    for name in r.names() {
        let d = r.get(name).unwrap();
        let text = table_text(&d);
        let path = dir.join(format!("{name}.tsv"));
        if std::env::var_os("UPDATE_EXPECT").is_some() {
            std::fs::create_dir_all(&dir).unwrap();
            std::fs::write(&path, &text).unwrap();
        } else if std::fs::read_to_string(&path).ok().as_deref() != Some(text.as_str()) {
            stale.push(name.to_owned());
        }
    }
    assert!(stale.is_empty(), "stale vocabulary tables {stale:?}; run UPDATE_EXPECT=1 cargo test --test it vocabulary");
}

/// The letter of the first address with `role`.
fn letter(d: &Dialect, role: Role) -> Option<String> {
    d.addresses.iter().find(|a| a.role == role).map(|a| a.name.clone())
}

/// A block running G or M code `code` (in tenths) with a value for each word it requires
/// and for one of each set of which it needs one.
fn block(d: &Dialect, letter_: char, x10: u32, params: Option<&ncplan::dialect::ParamSpec>) -> String {
    let shown = if x10 % 10 == 0 { format!("{letter_}{}", x10 / 10) } else { format!("{letter_}{}.{}", x10 / 10, x10 % 10) };
    let mut words = vec![shown];
    if let Some(p) = params {
        let mut roles: Vec<Role> = p.required.clone();
        let extra: Vec<Role> =
            p.any_of.iter().filter(|set| !set.iter().any(|r| roles.contains(r))).filter_map(|set| set.first().copied()).collect();
        roles.extend(extra);
        for r in roles {
            if let Some(l) = letter(d, r) {
                words.push(format!("{l}1"));
            }
        }
    }
    words.join(" ")
}

/// Codes that run only after another or with what they name: the program each needs, by
/// the dialect it is written for (or one it derives from) and the code as the test writes
/// it (`{}` is where the code's block goes). A code run without
/// its context is an error on the control too (G5.3 with no NURBS block, M72 with nothing
/// saved, M98 P1 with no O1, a lathe G70 without its contour).
const CONTEXTS: &[(&str, &str, &str)] = &[
    ("linuxcnc", "G5.3", "G5.2 X0 Y0 P1 L3\nX1 Y1 P1\nX2 Y0 P1\n{}\nM30\n"),
    ("linuxcnc", "M72", "M70\n{}\nM30\n"),
    ("linuxcnc", "M98 P1", "{}\nM30\nO1\nG1 X1\nM99\n"),
    ("linuxcnc", "G70", "G18 G7\nG0 X10 Z1\n{}\nM30\no1 sub\nG1 X5 Z1\nZ-1\nX10\no1 endsub\n"),
    ("linuxcnc", "G71", "G18 G7\nG0 X10 Z1\n{}\nM30\no1 sub\nG1 X5 Z1\nZ-1\nX10\no1 endsub\n"),
    ("linuxcnc", "G71.1", "G18 G7\nG0 X10 Z1\n{}\nM30\no1 sub\nG1 X5 Z1\nZ-1\nX10\no1 endsub\n"),
    ("linuxcnc", "G71.2", "G18 G7\nG0 X10 Z1\n{}\nM30\no1 sub\nG1 X5 Z1\nZ-1\nX10\no1 endsub\n"),
    ("linuxcnc", "G72", "G18 G7\nG0 X10 Z1\n{}\nM30\no1 sub\nG1 X5 Z1\nZ-1\nX10\no1 endsub\n"),
    ("linuxcnc", "G72.1", "G18 G7\nG0 X10 Z1\n{}\nM30\no1 sub\nG1 X5 Z1\nZ-1\nX10\no1 endsub\n"),
    ("linuxcnc", "G72.2", "G18 G7\nG0 X10 Z1\n{}\nM30\no1 sub\nG1 X5 Z1\nZ-1\nX10\no1 endsub\n"),
    ("fanuc", "M97 P1", "{}\nM30\nN1 G1 X1\nM99\n"),
    ("haas", "G70", "G81 Z-1 R1\n{} I1 J0 K30 L3\nG80\nM30\n"),
    ("haas", "G71", "G81 Z-1 R1\n{} I1 J0 K30 L3\nG80\nM30\n"),
    ("haas", "G72", "G81 Z-1 R1\n{} I1 J0 K30 L3\nG80\nM30\n"),
    // On a Fagor lathe G70 is inch input, no finishing cycle.
    ("fagor_lathe", "G70", "{}\nM30\n"),
    ("fanuc_lathe", "G70", "G0 X10 Z1\n{} P10 Q20\nN10 G1 X5\nN20 Z-1\nM30\n"),
    // Okuma LAP: the contour from the block its N names (G81) to G80, right after the call.
    ("okuma_lathe", "G85", "G0 X60 Z2\n{} N10 D2 F0.3 U0.4 W0.1\nN10 G81\nG1 X40 Z0\nZ-20\nX60\nG80\nM30\n"),
    ("okuma_lathe", "G87", "G0 X60 Z2\n{} N10\nN10 G81\nG1 X40 Z0\nZ-20\nX60\nG80\nM30\n"),
    (
        "heidenhain_iso",
        "G79",
        "N10 G200 DRILLING\nQ200=2\nQ201=-5\nQ206=100\nQ202=5\nQ210=0\nQ203=0\nQ204=50\nQ211=0\nN20 {} *\nN30 M30 *\n",
    ),
    (
        "heidenhain_iso",
        "M99",
        "N10 G200 DRILLING\nQ200=2\nQ201=-5\nQ206=100\nQ202=5\nQ210=0\nQ203=0\nQ204=50\nQ211=0\nN20 {} *\nN30 M30 *\n",
    ),
];

/// The dialect's name and the names of the dialects it derives from.
fn lineage(r: &Registry, d: &Dialect) -> Vec<String> {
    let mut out = vec![d.name.clone()];
    while let Some(base) = r.get(&out[out.len() - 1]).and_then(|x| x.extends.clone()) {
        if out.contains(&base) {
            break;
        }
        out.push(base);
    }
    out
}

/// A program running `block` in the dialect's word-address form, after a block that sets
/// the feed and starts the spindle (a cutting move needs them), in the context the code
/// needs.
fn program(r: &Registry, d: &Dialect, block: &str) -> String {
    let code = block.split_whitespace().next().unwrap_or_default();
    let fits = |pat: &str| pat == block || pat == code;
    let names = lineage(r, d);
    match CONTEXTS.iter().find(|(name, pat, _)| names.iter().any(|n| n == name) && fits(pat)) {
        Some((_, _, text)) => format!("F100 S1000 M3\n{}", text.replace("{}", block)),
        None => format!("F100 S1000 M3\n{block}\nM30\n"),
    }
}

/// Every G and M code a word-address dialect's table marks modelled or intent, and every M
/// code of a Klartext dialect, reads without an error in a program of its own; an intent code
/// says it is kept as intent.
#[test]
fn every_modelled_or_intent_code_reads_without_an_error() {
    let r = Registry::shipped();
    let mut failed = Vec::new();
    let mut tried = 0;
    for name in r.names() {
        let d = r.get(name).unwrap();
        if d.lexical.block_form != BlockForm::WordAddress {
            continue;
        }
        for c in d.codes.iter().filter(|c| c.keyword.is_none()) {
            let b = block(&d, c.letter.to_ascii_uppercase(), u32::from(c.number), Some(&c.params));
            let e = errors(&findings(&d, &program(&r, &d, &b)));
            tried += 1;
            if !e.is_empty() {
                failed.push(format!("{name} modelled `{b}`: {}", e.join("; ")));
            }
        }
        for e in d.vocabulary.entries.iter().filter(|e| e.status != Status::Unsupported && matches!(e.kind, Kind::G | Kind::M)) {
            let l = if e.kind == Kind::G { 'G' } else { 'M' };
            for &(lo, hi) in &e.ranges {
                for x10 in [lo, hi] {
                    let b = block(&d, l, x10, None);
                    let diags = findings(&d, &program(&r, &d, &b));
                    tried += 1;
                    let errs = errors(&diags);
                    // Said kept as intent, or as a machine builder's M code, unless the dictionary models
                    // the code after all.
                    let said = diags.iter().any(|x| matches!(x.code, Code::Unmodelled | Code::MachineCode)) || d.code_id(l, x10).is_some();
                    if !errs.is_empty() || !said {
                        failed.push(format!("{name} intent `{b}`: {} (said intent: {said})", errs.join("; ")));
                    }
                }
            }
        }
    }
    // Klartext: an M code rides on a straight move; M99 calls the cycle defined before it.
    for name in r.names() {
        let d = r.get(name).unwrap();
        if d.lexical.block_form != BlockForm::KeywordFirst {
            continue;
        }
        for c in d.codes.iter().filter(|c| c.keyword.is_none() && c.letter.eq_ignore_ascii_case(&'M')) {
            let m = if c.number % 10 == 0 { format!("M{}", c.number / 10) } else { format!("M{}.{}", c.number / 10, c.number % 10) };
            let cycle = "2 CYCL DEF 200 BOHREN ~\n  Q200=2 ;A ~\n  Q201=-5 ;B ~\n  Q206=150 ;C ~\n  Q202=5 ;D ~\n  Q210=0 ;E ~\n  Q203=+0 ;F ~\n  Q204=50 ;G ~\n  Q211=0 ;H\n";
            let text =
                format!("0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000\n{cycle}3 L X+0 Y+0 R0 F100 M3\n4 L X+1 R0 F100 {m}\n5 END PGM T MM\n");
            let e = errors(&findings(&d, &text));
            tried += 1;
            if !e.is_empty() {
                failed.push(format!("{name} modelled `{m}`: {}", e.join("; ")));
            }
        }
    }
    assert!(tried > 500, "only {tried} codes tried");
    assert!(failed.is_empty(), "{} of {tried} codes read with errors:\n{}", failed.len(), failed.join("\n"));
}

/// The findings of `text` read in `dialect`.
fn read(dialect: &str, text: &str) -> Vec<Diagnostic> {
    let d = Registry::shipped().get(dialect).unwrap();
    findings(&d, text)
}

/// Files as shops keep them: `M98 Q` calls a sequence number of the same program (Fanuc 0i-F
/// and 30i), `M98 P Q` one of program P; Q is a number there, no length, under
/// least-increment input. A sequence number that is not there stays an error.
#[test]
fn m98_q_calls_a_sequence_number_of_this_program() {
    let ok = read("fanuc", "O1000\nG90 G54 G0 X0 Y0 S1000 M3\nM98 Q2100\nM98 P1000 Q2100 L2\nM30\nN2100 G1 X10. F100.\nM99\n");
    assert!(errors(&ok).is_empty(), "{:?}", errors(&ok));
    let missing = read("fanuc", "O1000\nM98 Q2200\nM30\nN2100 G1 X10. F100.\nM99\n");
    assert_eq!(missing.iter().filter(|d| d.is_error()).map(|d| d.code).collect::<Vec<_>>(), vec![Code::MissingLabel]);
}

/// Older TNCs write a decimal comma and leave the radius compensation a bare `R`; the values
/// are read as with a point, and `R` with a value stays the arc's radius.
#[test]
fn an_older_tnc_program_reads_its_decimal_comma() {
    let text = "0 BEGIN PGM T MM\n1 TOOL DEF 1 L+30,000 R+5,000\n2 TOOL CALL 1 Z S1500,000\n3 L Z+100,000 R F5000 M3\n\
                4 L X+10,5 Y-2,25 R0 F5000\n5 CR X+20,5 Y-2,25 R+5,000 DR-\n6 END PGM T MM\n";
    let d = Registry::shipped().get("heidenhain").unwrap();
    let mut out = Vec::new();
    let diags = interpret(text, &d, &Profile::default(), &mut out);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let calls: Vec<String> = out
        .iter()
        .map(|c| {
            let mut t = String::new();
            ncplan::canon::write_call(&mut t, &c.op);
            t
        })
        .collect();
    assert!(calls.iter().any(|c| c.starts_with("STRAIGHT_FEED(10.5000, -2.2500, 100.0000")), "{calls:#?}");
    assert!(calls.iter().any(|c| c.starts_with("ARC_FEED(20.5000, -2.2500")), "{calls:#?}");
    assert!(calls.iter().any(|c| c.starts_with("SET_SPINDLE_SPEED(0, 1500.0000)")), "{calls:#?}");
}

/// A documented code that ncplan does not model is kept as intent with a warning; a code no
/// manual lists is still an error.
#[test]
fn a_documented_code_is_intent_and_an_invented_one_an_error() {
    let intent = read("fanuc", "O1\nG90 G0 X0 Y0\nG12.1\nG1 X10. F100. S100 M3\nG13.1\nM30\n");
    assert!(errors(&intent).is_empty(), "{:?}", errors(&intent));
    assert_eq!(intent.iter().filter(|d| d.code == Code::Unmodelled).count(), 2);
    let invented = read("fanuc", "O1\nG90 G0 X0 Y0\nG12.7\nM30\n");
    assert!(invented.iter().any(|d| d.code == Code::UnknownCode && d.is_error()), "{invented:?}");
    // LinuxCNC's user M codes M100-M199 are programs on the control's USER_M_PATH.
    let user = read("linuxcnc", "M101 P1\nG0 X1\nM2\n");
    assert!(errors(&user).is_empty(), "{:?}", errors(&user));
    let beyond = read("linuxcnc", "M200\nG0 X1\nM2\n");
    assert!(beyond.iter().any(|d| d.code == Code::UnknownCode), "{beyond:?}");
}

/// A LinuxCNC program calling a subroutine by name that lies on the machine's subroutine path
/// (not beside it): a warning that the moves are missing, not an error; a numbered subroutine
/// that is not in the program stays a missing label.
#[test]
fn a_named_subroutine_on_the_subroutine_path_is_a_warning() {
    let named = read("linuxcnc", "G0 X0\no<pocket> call [1] [2]\nM2\n");
    assert!(errors(&named).is_empty(), "{:?}", errors(&named));
    assert!(named.iter().any(|d| d.code == Code::MissingProgram && !d.is_error()), "{named:?}");
    let numbered = read("linuxcnc", "G0 X0\no100 call\nM2\n");
    assert!(numbered.iter().any(|d| d.code == Code::MissingLabel && d.is_error()), "{numbered:?}");
}

/// The calls a program makes in `dialect`, as rs274 prints them, and its findings.
fn run(dialect: &str, text: &str) -> (Vec<String>, Vec<Diagnostic>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let mut out = Vec::new();
    let diags = interpret(text, &d, &Profile::default(), &mut out);
    let calls = out
        .iter()
        .map(|c| {
            let mut t = String::new();
            ncplan::canon::write_call(&mut t, &c.op);
            t.trim_end().to_owned()
        })
        .collect();
    (calls, diags)
}

/// The Fagor 8055 writes its high-level language in brackets: an assignment, a conditional
/// jump, a subroutine `(SUB 3)` ... `(RET)` called by `(CALL 3)` or with arguments by
/// `(PCALL 3, P0=1)`, a section repeat (read, not repeated); any other bracket is a comment.
#[test]
fn fagor_8055_statements_in_brackets() {
    let program = "\
(DRILL PLATE)
N10 G0 G90 X0 Y0 Z10
(P100 = 5)
(P101 = P100 * 2 + 1)
N20 G1 X P101 F500
(IF P100 EQ 5 GOTO N40)
N30 G1 Y10 F0
N40 G0 Z10
(CALL 3)
(PCALL 4, P0=7)
(RPT N10, N20) N2
M30
(SUB 3)
G0 X5
(RET)
(SUB 4)
G0 Y P0
(RET)
";
    let (calls, diags) = run("fagor", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    // P101 = 11; the jump skips N30 (its F0 would stop the feed); the subroutines run.
    assert!(calls.iter().any(|c| c.starts_with("STRAIGHT_FEED(11.0000, 0.0000, 10.0000")), "{calls:#?}");
    assert!(!calls.iter().any(|c| c.starts_with("STRAIGHT_FEED(11.0000, 10.0000")), "{calls:#?}");
    assert_eq!(calls.iter().filter(|c| *c == "SET_FEED_RATE(0.0000)").count(), 1, "N30 F0 was jumped over, only M30 resets: {calls:#?}");
    assert!(calls.iter().any(|c| c.starts_with("STRAIGHT_TRAVERSE(5.0000, 0.0000, 10.0000")), "{calls:#?}");
    assert!(calls.iter().any(|c| c.starts_with("STRAIGHT_TRAVERSE(5.0000, 7.0000, 10.0000")), "{calls:#?}");
    assert!(diags.iter().any(|d| d.message.contains("RPT") && !d.is_error()), "{diags:?}");
    // A bracket that does not open a statement stays a comment.
    assert!(calls.iter().any(|c| c == "COMMENT(\"DRILL PLATE\")"), "{calls:#?}");
    // And the program is told to be a Fagor one from its statements alone.
    let sniffed = ncplan::pipeline::sniff(&Registry::shipped(), program.as_bytes(), std::path::Path::new("P000214.PIM"));
    assert_eq!(sniffed.dialect, "fagor");
}

/// Older TNCs write a prompt left unanswered as its bare letter: `L X-.3937 M` has no
/// miscellaneous function, and reads without an error; `M3` is still the M address.
#[test]
fn a_bare_m_on_an_older_tnc_is_no_function() {
    let (calls, diags) =
        run("heidenhain", "0 BEGIN PGM T MM\n1 TOOL CALL 1 Z S1000\n2 L X+10 Y+0 R0 FMAX M3\n3 L X+20 R F100 M\n4 END PGM T MM\n");
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(calls.iter().any(|c| c.starts_with("START_SPINDLE_CLOCKWISE")), "{calls:#?}");
    assert!(calls.iter().any(|c| c.starts_with("STRAIGHT_FEED(20.0000, 0.0000")), "{calls:#?}");
    // The DIN/ISO dialect has no such prompt: an M there needs its number.
    let iso = read("heidenhain_iso", "%T G71 *\nN10 G00 X10 M *\nN99999999 %T G71 *\n");
    assert!(iso.iter().any(|d| d.is_error()), "{iso:?}");
}

/// Haas's own Renishaw macros write a sign apart from its bracket (`Z - [ 0.5 * #5 ]`): the
/// sign applies to the expression (Fanuc and Haas ignore blanks in a block). A Fanuc skip
/// (G31) of no length is no alarm: without the skip signal the move just ends.
#[test]
fn a_sign_apart_from_its_bracket_and_a_skip_of_no_length() {
    let (calls, diags) =
        run("haas", "O1\nG90 G0 X0 Y0 Z10.\n#5 = 2.\nG91 G31 Z - [ 0.5 * #5 ] F [ 50. * #5 ]\nG90 G31 X0 Y0 Z9. F100.\nM30\n");
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(calls.iter().any(|c| c.starts_with("STRAIGHT_PROBE(0.0000, 0.0000, 9.0000")), "{calls:#?}");
    // A sign with nothing after it is still no number.
    let bad = read("fanuc", "O1\nG0 X- Y1.\nM30\n");
    assert!(bad.iter().any(|d| d.is_error()), "{bad:?}");
}

/// Okuma's G code table: G11 shifts and turns the coordinate system and G10 cancels it
/// (kept as intent); it has no Fanuc G68.2 tilted plane, which stays an error.
#[test]
fn okuma_reads_its_own_g10_g11_and_has_no_g68_2() {
    let own = read("okuma", "O1\nG15 H1\nG11 X0 Y0 R30.\nG0 X10. Y0\nG10\nM02\n");
    assert!(errors(&own).is_empty(), "{:?}", errors(&own));
    assert_eq!(own.iter().filter(|d| d.code == Code::Unmodelled).count(), 2, "{own:?}");
    let fanuc_tilt = read("okuma", "O1\nG68.2 X0 Y0 Z0 I0 J30. K0\nG53.1\nM02\n");
    assert!(fanuc_tilt.iter().any(|d| d.code == Code::UnknownCode && d.is_error()), "{fanuc_tilt:?}");
    let fagor_tilt = read("fagor", "G68.2 X0 Y0 Z0 I0 J30. K0\nM30\n");
    assert!(fagor_tilt.iter().any(|d| d.code == Code::UnknownCode && d.is_error()), "{fagor_tilt:?}");
}

/// Programs by name, for calls that leave the file.
struct Beside(Vec<(&'static str, &'static str)>);

impl ncplan::interp::ProgramSource for Beside {
    fn load(&self, name: &str) -> Option<String> {
        self.0.iter().find(|(n, _)| *n == name).map(|(_, t)| (*t).to_owned())
    }
}

/// A program kept beside the one that calls it is a file of its own: an error in it is that
/// file's (read on its own, it is reported there), said at the call as a warning that names
/// the file; the caller's own errors stay errors.
#[test]
fn a_called_files_error_is_reported_against_that_file() {
    let d = Registry::shipped().get("fanuc").unwrap();
    let sub = "O9100\nG1 X1. F100.\nG12.7\nM99\n";
    let programs = Beside(vec![("O9100", sub)]);
    let main = "O1\nG90 G0 X0 Y0\nM98 P9100\nM30\n";
    let diags = ncplan::interp::run(main, &d, &Profile::default(), &programs, &mut Vec::new());
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let at_call = diags.iter().find(|x| x.code == Code::UnknownCode).expect("the called file's finding, said at the call");
    assert!(at_call.message.starts_with("in O9100:3:1:") && at_call.message.contains("called program O9100"), "{at_call:?}");
    assert_eq!(&main[at_call.range.start as usize..at_call.range.end as usize], "M98 P9100");
    // Read on its own, the file reports it as its error.
    assert!(read("fanuc", sub).iter().any(|x| x.code == Code::UnknownCode && x.is_error()));
    // A subprogram in the same file is the program's own: its error stays an error.
    let own = read("fanuc", "O1\nM98 P9100\nM30\nO9100\nG12.7\nM99\n");
    assert!(own.iter().any(|x| x.code == Code::UnknownCode && x.is_error()), "{own:?}");
}

/// Tormach PathPilot is LinuxCNC with Tormach's remapped codes (its v2.3.6 configuration):
/// G50 cancels the rotation, M998 goes to the G30 position, G47 engraves a serial number. A
/// Fusion post for it names the maker in its header, and is read as PathPilot's. Its
/// interpreter names G41/G41.1/G42/G42.1 as its compensation codes: G41.2 stays an error.
#[test]
fn tormach_pathpilot_reads_its_remapped_codes() {
    let program = "%\n(1001)\n(Machine)\n(  vendor Tormach)\n(  model PCNC440)\nG90 G54 G64 G50 G17 G40 G80 G94 G91.1 G49\nG21\nG30\n\
                   T1 G43 H1 M6\nS3000 M3\nG0 X10. Y5.\nG1 Z-1. F300.\nG2 X20. Y5. I5. J0.\nG0 Z5.\nM998\nM30\n%\n";
    let sniffed = Registry::shipped().sniff(program, Some("1001.nc"), "linuxcnc");
    assert_eq!(sniffed.dialect, "pathpilot", "{sniffed:?}");
    let diags = read("pathpilot", program);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert_eq!(diags.iter().filter(|x| x.code == Code::Unmodelled).count(), 2, "{diags:?}");
    // Stock LinuxCNC has neither.
    let stock = read("linuxcnc", program);
    assert!(errors(&stock).iter().any(|e| e.contains("G50")) && errors(&stock).iter().any(|e| e.contains("M998")), "{stock:?}");
    let g41_2 = read("pathpilot", "G21 G90\nT1 M6\nG0 X0 Y0\nG1 G41.2 X5. Y5. D1 F100.\nG40 X0 Y0\nM2\n");
    assert!(g41_2.iter().any(|x| x.code == Code::UnknownCode && x.is_error()), "{g41_2:?}");
}

/// G codes the machine builder sets to call a custom macro (Fanuc's macro call using a G
/// code): a Mori Seiki NT's G361/G419 on a Fanuc lathe are kept as intent; so are the 30i's
/// own G41.2 and, on a mill-turn lathe, G43/G49. A G code below the builder's range that no
/// manual lists stays an error.
#[test]
fn a_machine_builders_g_code_is_intent_on_fanuc() {
    let lathe =
        read("fanuc_lathe", "%\nO1151\nG28 U0. W0.\nG0 T2002\nG361 B0. D1.\nG419 A90. D1.\nG43 H0.\nG0 X50. Z5.\nG49\nG69.1\nM30\n%\n");
    assert!(errors(&lathe).is_empty(), "{:?}", errors(&lathe));
    let mill = read("fanuc", "O1\nG90 G0 X0 Y0\nG41.2 D1\nG1 X10. F100. S100 M3\nG40\nG91.1 X1.\nM30\n");
    assert!(errors(&mill).is_empty(), "{:?}", errors(&mill));
    let invented = read("fanuc", "O1\nG90 G0 X0 Y0\nG135\nM30\n");
    assert!(invented.iter().any(|x| x.code == Code::UnknownCode && x.is_error()), "{invented:?}");
}

/// A Mazak Integrex (mill-turn) program in EIA/ISO, G-code type C, as the Integrex's own
/// macros and the Autodesk Integrex post write it: told from the Mazak mill dictionary by
/// G122.1/G123.1 (radius and diameter input) and `G112 M`/`G112 S` (the milling spindle),
/// read without an error; `T6400.1102` is tool 64 with its ID code after the point.
#[test]
fn a_mazak_integrex_program_reads_as_the_mill_turn() {
    let text = "O1002\n(MILLING FLATS)\nG122.1\n#101=25.\nT6400.1102\nG112 M200\nG112 M203 G112 S3000\nG0 Z-50.\n\
                G0 X[-#101] Y-10.\nG1 X[#101] F200\nG91 G1 Y5.\nG90\nG123.1\nG95 G97 S500 M3\nG1 Z-2. F0.1\nG112 M205\nM30\n%\n";
    let r = Registry::shipped();
    let sniffed = r.sniff(text, Some("O1002.EIA"), "fanuc");
    assert_eq!(sniffed.dialect, "mazak_millturn", "{sniffed:?}");
    let (calls, diags) = run("mazak_millturn", text);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(calls.iter().any(|c| c.starts_with("SELECT_TOOL(64)")), "{calls:#?}");
    // The same words on the Mazak mill: G122.1 and G112 are no codes of it.
    assert!(!errors(&read("mazak", text)).is_empty());
}

/// A Fagor 8025/8055 T lathe: `T2.2` is tool 2 with offset 2 (the NX post for the Fagor 8025 T
/// writes `T1.1`), read without an error; the 8055 T's own turning cycles under G81-G89 are
/// kept as intent, not read as Fanuc's live-tool drilling cycles or left unknown, and Fanuc
/// system B's G77-G79 single cycles are not read (G77/G78 slave an axis on a Fagor: intent).
#[test]
fn a_fagor_lathe_reads_its_tool_offset_and_own_cycles() {
    let text = "N10 G90 G94 G71\nN20 T2.2\nN30 M3 S1000\nN40 G0 X90 Z2\n\
                N50 G81 X50 Z-10 Q80 R-10 C2 L1 M1 F25 H25\nN60 G88 X50 Z-20 Q40 R-25 C3 D1 K1\nN70 G0 X100 Z50\nN80 M30\n";
    let (calls, diags) = run("fagor_lathe", text);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    assert!(calls.iter().any(|c| c == "SELECT_TOOL(2)"), "{calls:#?}");
    for code in ["G81", "G88"] {
        assert!(diags.iter().any(|d| d.code == Code::Unmodelled && d.message.contains(code) && !d.is_error()), "{code}: {diags:?}");
    }
    // A tool number with a fraction stays an error where the dictionary has no such form.
    assert!(errors(&read("fanuc_lathe", "O1\nT2.2\nM30\n")).iter().any(|e| e.contains("tool number")));
    // G77 is Fanuc system B's turning cycle, not the 8055 T's: there it slaves an axis (as the
    // 8055 M's table gives it), kept as intent, neither a cycle's moves nor an unknown code.
    let g77 = read("fagor_lathe", "N10 G90\nN20 G77 X40 Z-20 F0.2\nN30 M30\n");
    assert!(g77.iter().any(|d| d.code == Code::Unmodelled && d.message.contains("G77") && !d.is_error()), "{g77:?}");
    assert!(!g77.iter().any(|d| d.code == Code::UnknownCode), "{g77:?}");
}

/// Fagor's `T2.2` is decided by the point written, not by the value's fraction: `T2.0` and `T2.`
/// are tool 2 too (never Fanuc's two-digit split, which took `T2.0` for tool 0), `T2.0` with
/// offset 0 (none applied, as the 8055's `D0`), `T2.` with the tool's own offset (as the
/// 8055's `T3` alone); a word without a point is the tool alone with its own offset (`T2`: tool
/// 2, not Fanuc's split to tool 0 with offset 2).
#[test]
fn a_fagor_lathe_tool_word_is_split_where_its_point_is() {
    let d = Registry::shipped().get("fagor_lathe").unwrap();
    let mut profile = Profile::default();
    for (tool, length) in [(2, 5.0), (12, 7.0)] {
        profile.tools.insert(tool, ncplan::interp::ToolData { length, ..Default::default() });
    }
    let text = "N10 G90 G71\nN20 T2.\nN30 T2.0\nN40 T12.05\nN50 T2.12\nN60 T2\nN70 M30\n";
    let mut out = Vec::new();
    let diags = interpret(text, &d, &profile, &mut out);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let calls: Vec<String> = out
        .iter()
        .map(|c| {
            let mut t = String::new();
            ncplan::canon::write_call(&mut t, &c.op);
            t.trim_end().to_owned()
        })
        .filter(|c| c.starts_with("SELECT_TOOL") || c.starts_with("USE_TOOL_LENGTH_OFFSET"))
        .map(|c| c.replace(", 0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000)", ")"))
        .collect();
    assert_eq!(
        calls,
        [
            // `T2.`: tool 2 with its own offset (its length 5).
            "SELECT_TOOL(2)",
            "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 5.0000)",
            // `T2.0`: tool 2, offset 0: none applied.
            "SELECT_TOOL(2)",
            "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 0.0000)",
            // `T12.05`: tool 12 with offset 5 (no data: none applied, unchanged).
            "SELECT_TOOL(12)",
            // `T2.12`: tool 2 with offset 12 (tool 12's data, length 7).
            "SELECT_TOOL(2)",
            "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 7.0000)",
            // `T2`: tool 2 with its own offset, as `T2.` (no Fanuc split to tool 0, offset 2).
            "SELECT_TOOL(2)",
            "USE_TOOL_LENGTH_OFFSET(0.0000 0.0000 5.0000)",
        ],
        "{calls:#?}"
    );
}

/// A dwell's P with a decimal point is seconds on a Haas and no Fanuc form (its P takes no
/// decimal point): a program with no other code of its maker is told to be a Haas one by it.
#[test]
fn a_dwell_in_seconds_tells_a_haas_program() {
    let text = "%\nO14217 (PART)\nG17 G20 G40 G80 G90 G94\nG54\nT5 M06\nG43 H5\nG00 X0 Y0 Z1.\nS240 M03\n\
                G01 Z.7 F8.\nG04 P1.0\nG84 Z-.425 R0.2 F15.0\nG80\nM02\n%\n";
    let sniffed = Registry::shipped().sniff(text, Some("PART.nc"), "fanuc");
    assert_eq!(sniffed.dialect, "haas", "{sniffed:?}");
    // Whole milliseconds (`G04 P1000`) tell nothing.
    let text = text.replace("G04 P1.0", "G04 P1000");
    assert_eq!(Registry::shipped().sniff(&text, Some("PART.nc"), "fanuc").dialect, "fanuc");
}

/// A Fanuc code Haas has not (`G05 P10000`, high-precision contour control) tells a Fanuc
/// program from a Haas one, whatever else the text has.
#[test]
fn a_high_precision_mode_tells_a_fanuc_program() {
    let text = "%\nO0001\nT2M6\nS1070M3\nG53G0G90X5.Y1.\nG43Z1.35H2M8\nG05P10000\nG04P1.0\nG82X5.Y1.Z1.R1.1F2.1P500\nX4.\nG80\nM30\n%\n";
    let sniffed = Registry::shipped().sniff(text, Some("part.ptp"), "fanuc");
    assert_eq!(sniffed.dialect, "fanuc", "{sniffed:?}");
    assert!(sniffed.evidence.iter().any(|e| e.contains("G05 P10000")), "{sniffed:?}");
}

/// A dwell's P with a decimal point (`G04 P2.`, `G89 ... P2.`): Fanuc stops with an alarm (P
/// is a whole number of milliseconds), an error at the word; Haas reads it as seconds;
/// LinuxCNC's P is seconds anyway; the makers whose manuals do not say keep P in their unit.
#[test]
fn a_dwell_p_with_a_decimal_point_by_control() {
    let text = "O1\nG04 P1.5\nG04 P1500\nG89 X1. Y1. Z-1. R1. P2. F10.\nG80\nM30\n";
    for dialect in ["fanuc", "fanuc_lathe"] {
        let d = read(dialect, text);
        let bad: Vec<_> = d.iter().filter(|x| x.code == Code::DwellPointAlarm && x.is_error()).collect();
        assert!(bad.iter().any(|x| x.message.contains("`P1.5`")), "{dialect}: {d:?}");
        assert!(!bad.iter().any(|x| x.message.contains("P1500")), "{dialect}: {d:?}");
    }
    assert!(read("fanuc", text).iter().any(|x| x.is_error() && x.message.contains("`P2.`")));
    for dialect in ["haas", "haas_lathe", "mitsubishi", "mazak", "okuma", "lnc"] {
        let d = read(dialect, text);
        assert!(!d.iter().any(|x| x.code == Code::DwellPointAlarm), "{dialect}: {d:?}");
    }
    let dwells = |dialect: &str| -> Vec<String> {
        run(dialect, "O1\nG04 P1.5\nG04 P1500\nM30\n").0.into_iter().filter(|c| c.starts_with("DWELL")).collect()
    };
    assert_eq!(dwells("haas"), ["DWELL(1.5000)", "DWELL(1.5000)"]);
    assert_eq!(dwells("fanuc")[1], "DWELL(1.5000)");
}

/// A canned cycle's repeat line (`X2. P1.` under a modal `G82`) gives the cycle a new dwell:
/// its P is the dwell as in the cycle's own block (Haas: a decimal point is seconds; Fanuc: an
/// alarm). A P of a code of the block's own (`M98 P1.`) is not the dwell.
#[test]
fn a_cycle_repeat_line_reads_its_dwell_as_the_cycle_block_does() {
    let text = "O1\nG90 G0 X0 Y0 Z1.\nG82 X1. Y1. Z-1. R.1 P1. F10.\nX2. P.5\nX3.\nG80\nM30\n";
    let (calls, diags) = run("haas", text);
    assert!(errors(&diags).is_empty(), "{:?}", errors(&diags));
    let dwells: Vec<&String> = calls.iter().filter(|c| c.starts_with("DWELL")).collect();
    // Haas: 1 s at the first hole, 0.5 s at the second and (the P modal) the third.
    assert_eq!(dwells, ["DWELL(1.0000)", "DWELL(0.5000)", "DWELL(0.5000)"], "{calls:#?}");
    let fanuc = read("fanuc", text);
    let alarms: Vec<_> = fanuc.iter().filter(|x| x.code == Code::DwellPointAlarm && x.is_error()).collect();
    assert!(alarms.iter().any(|x| x.message.contains("`P.5`")), "{fanuc:?}");
    // Whole milliseconds on the repeat line: no alarm.
    let whole = read("fanuc", "O1\nG90 G0 X0 Y0 Z1.\nG82 X1. Y1. Z-1. R.1 P1000 F10.\nX2. P500\nG80\nM30\n");
    assert!(!whole.iter().any(|x| x.code == Code::DwellPointAlarm), "{whole:?}");
}

/// A block with no position word (axis or R) repeats no canned cycle (Fanuc operator's manual,
/// canned cycles: a block without an axis word does not run the cycle): its P is no dwell
/// (`M06 P3.` under `G81`). A P read as the cycle's dwell is used, not an unused word; under a
/// cycle with no dwell (`G81`) a repeat line's P is no dwell either.
#[test]
fn only_a_block_with_a_position_word_repeats_the_cycle_s_dwell() {
    let text = "O1\nG90 G0 X0 Y0 Z1.\nG81 X1. Y1. Z-.5 R.1 F10.\nM06 P3.\nX3. P1.\nG80\nG82 X1. Y1. Z-.5 R.1 P500 F10.\nM06 P3.\nX2. P1500\nG80\nM30\n";
    let d = read("fanuc", text);
    assert!(!d.iter().any(|x| x.code == Code::DwellPointAlarm), "{d:?}");
    // Under G82 the repeat line's P is the dwell, used; the M06's P and the P under G81 are not.
    let unused: Vec<_> = d.iter().filter(|x| x.code == Code::UnusedWord).map(|x| x.message.clone()).collect();
    assert!(!unused.iter().any(|m| m.contains("`P1500`")), "{unused:?}");
    assert_eq!(unused.len(), 3, "{unused:?}");
    let alarm = read("fanuc", &text.replace("X2. P1500", "X2. P1.5"));
    assert!(alarm.iter().any(|x| x.code == Code::DwellPointAlarm && x.message.contains("`P1.5`")), "{alarm:?}");
    assert!(!alarm.iter().any(|x| x.code == Code::UnusedWord && x.message.contains("`P1.5`")), "{alarm:?}");
}

/// Where the dialect is a guess (low confidence: no code of its maker's own), a finding that
/// holds for that maker alone (the Fanuc dwell-point alarm: Haas reads the point as seconds) is
/// a warning that says the dialect was guessed; a dialect given (`-d fanuc`) keeps it an error.
#[test]
fn a_makers_own_alarm_on_a_guessed_dialect_is_a_warning() {
    // (A `G04 P.5` would tell a Haas program; a cycle's repeat line does not.)
    let text = "%\nO0001\nT1M6\nG90G54G0X1.Y1.S1000M3\nG43Z1.H1\nG82X1.Y1.Z-.2R.1P500F10.\nX2.P.5\nG80\nM30\n%\n";
    let registry = Registry::shipped();
    let sniffed = ncplan::pipeline::sniff(&registry, text.as_bytes(), std::path::Path::new("part.ptp"));
    assert_eq!(sniffed.dialect, "fanuc", "{sniffed:?}");
    assert!(sniffed.guessed(), "{sniffed:?}");
    let d = registry.get("fanuc").unwrap();
    let mut out = Vec::new();
    let guessed = interpret(text, &d, &Profile { guessed: true, ..Profile::default() }, &mut out);
    assert!(errors(&guessed).is_empty(), "{:?}", errors(&guessed));
    let w = guessed.iter().find(|x| x.code == Code::DwellPointAlarm).expect("the alarm, as a warning");
    assert!(!w.is_error() && w.message.contains("guessed") && w.message.contains("`P.5`"), "{w:?}");
    let given = read("fanuc", text);
    assert!(given.iter().any(|x| x.code == Code::DwellPointAlarm && x.is_error()), "{given:?}");
    // A finding every maker's control stops at stays an error on a guess (an arc whose radius
    // cannot reach its end).
    let bad = interpret(
        &text.replace("X2.P.5\n", "X2.P.5\nG80\nG1Z.1F10.\nG3X5.Y1.R.1\n"),
        &d,
        &Profile { guessed: true, ..Profile::default() },
        &mut Vec::new(),
    );
    assert!(!errors(&bad).is_empty(), "{bad:?}");
}

/// A `(` inside a comment: LinuxCNC's rs274 stops with "Nested comment found" (NIST
/// RS274NGC 3.3.4: comments may not be nested), so it is an error there and on PathPilot, which
/// runs the same interpreter; a Fanuc-family reading ends the comment at its first `)` and finds
/// no such error where no `)` is left over; Mach3 and Centroid keep the plain reading.
#[test]
fn a_parenthesis_inside_a_comment_stops_rs274() {
    let text = "G0 X0\n(open ( only)\nM2\n";
    for dialect in ["linuxcnc", "pathpilot"] {
        let d = read(dialect, text);
        assert!(d.iter().any(|x| x.code == Code::NestedComment && x.is_error()), "{dialect}: {d:?}");
    }
    for dialect in ["mach3", "centroid", "fanuc"] {
        assert!(errors(&read(dialect, text)).is_empty(), "{dialect}");
    }
    // A message directive is still a comment: a plain one reads without an error.
    assert!(errors(&read("linuxcnc", "G0 X0\n(MSG, tool change)\nM2\n")).is_empty());
}

/// The other findings that hold for one maker alone are warnings on a guessed dialect too: a
/// plane change under compensation where the dictionary says the maker stops
/// (`plane-under-comp="stops"`, Fanuc PS0037; Haas, Mazak, Okuma state no stop) and a variable
/// above the maker's `highest-variable` (Fanuc #19999; Mitsubishi's #900001+ exist). The
/// RS274/NGC language's own rule (`modes-under-comp="locked"`) stays an error on a guess.
#[test]
fn other_makers_own_findings_on_a_guessed_dialect_are_warnings() {
    let registry = Registry::shipped();
    let guessed = Profile { guessed: true, ..Profile::default() };
    let plane = "O0001\nG90G0X0Y0Z1.\nG1Z-1.F10.\nG41D1X1.\nG18\nG40X0\nM30\n";
    let variable = "O0001\n#901064=2.\nG90G0X#901064Y0\nM30\n";
    for (text, code) in [(plane, Code::PlaneUnderComp), (variable, Code::VariableOutOfRange)] {
        let given = read("fanuc", text);
        assert!(given.iter().any(|x| x.code == code && x.is_error()), "{given:?}");
        assert!(code.maker_specific());
        let d = registry.get("fanuc").unwrap();
        let g = interpret(text, &d, &guessed, &mut Vec::new());
        assert!(errors(&g).is_empty(), "{:?}", errors(&g));
        assert!(g.iter().any(|x| x.code == code && x.message.contains("guessed")), "{g:?}");
    }
    // Mitsubishi has the variable: no finding at all.
    assert!(!read("mitsubishi", variable).iter().any(|x| x.code == Code::VariableOutOfRange));
    // LinuxCNC: the language stops at a plane change under compensation, guessed or not.
    let lcnc = "G90 G0 X0 Y0 Z1\nG1 Z-1 F10\nG41 D1 X1\nG18\nG40 X0\nM2\n";
    let d = registry.get("linuxcnc").unwrap();
    let g = interpret(lcnc, &d, &guessed, &mut Vec::new());
    assert!(g.iter().any(|x| x.code == Code::PlaneUnderComp && x.is_error()), "{g:?}");
    // A negative or fractional variable number is no maker's limit: it stays as it was.
    let frac = read("fanuc", "O0001\n#1=-3.\nG0X#[#1]\nM30\n");
    assert!(!frac.iter().any(|x| x.code == Code::VariableOutOfRange), "{frac:?}");
}

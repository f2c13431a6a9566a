//! Mitsubishi, Mazak EIA and Okuma OSP statements their programming manuals (or the posts and
//! macros that write them, where the manual was not at hand) document, each in a small program
//! of our own: read without an error, the codes not modelled kept as intent with a warning,
//! while a malformed or missing word stays an error (issue 43).

use ncplan::diag::Diagnostic;

fn read(dialect: &str, text: &str) -> Vec<Diagnostic> {
    crate::moves_and_findings(dialect, text, &ncplan::interp::Profile::default()).1
}

fn errors(diags: &[Diagnostic]) -> Vec<String> {
    diags.iter().filter(|d| d.is_error()).map(|d| format!("{}: {}", d.code.as_str(), d.message)).collect()
}

fn warned(diags: &[Diagnostic], code: &str) -> bool {
    diags.iter().any(|d| !d.is_error() && d.code.as_str() == "syntax::unmodelled" && d.message.contains(code))
}

/// OSP-L thread cycles: the fixed cycle G33 (5238-E section 7, 2-1) and the compound
/// end-face cycle G72 with its infeed mode M32; G32 (not read in the manual) stays unknown.
#[test]
fn okuma_lathe_thread_cycles_read_as_intent() {
    let text = "$THREAD.MIN%\nG50 S2000\nG0 X100. Z100.\nM3 S500 G97\nG0 X40. Z5.\nG33 X29.2 Z-20. F1.5\nG0 X40. Z5.\nG72 X20. Z-3. B60 D0.3 W0.05 H1.2 F1.5 M32\nG0 X100. Z100.\nM02\n";
    let d = read("okuma_lathe", text);
    assert!(errors(&d).is_empty(), "{:?}", errors(&d));
    assert!(warned(&d, "G72"), "{d:?}");
    // A word with no value is still malformed, and G32 is no code here.
    let d = read("okuma_lathe", "$T.MIN%\nG0 X100. Z100.\nM3 S500\nG72 X Z-1. F1.5\nM02\n");
    assert!(!errors(&d).is_empty(), "{d:?}");
    let d = read("okuma_lathe", "$T.MIN%\nG0 X100. Z100.\nM3 S500\nG32 Z-10. K1.5\nM02\n");
    assert!(errors(&d).iter().any(|e| e.starts_with("syntax::unknown-code")), "{d:?}");
}

/// A G code registered by the OSP's G/M code macro option calls a library user task
/// (`G116 T5`, a shop's tool change): kept as intent on the mill and the lathe, while a code
/// outside any documented range stays unknown.
#[test]
fn okuma_registered_g_codes_are_user_task_calls() {
    for dialect in ["okuma", "okuma_lathe"] {
        let d = read(dialect, "$TC.MIN%\nG116 T5\nG205\nM02\n");
        assert!(errors(&d).is_empty(), "{dialect}: {:?}", errors(&d));
        assert!(warned(&d, "G116"), "{dialect}: {d:?}");
    }
    let d = read("okuma", "$TC.MIN%\nG1234\nM02\n");
    assert!(!errors(&d).is_empty(), "{d:?}");
}

/// G136 (C-axis coordinate conversion) is a lathe's or a mill-turn centre's: an OSP library
/// that starts with it reads as the lathe dictionary, where it is a code.
#[test]
fn okuma_g136_tells_a_lathe() {
    let text = "OHOME\nG136\nM146\nG0 X60.\nG20 HP=4\nG4 F4.\nT1000\nRTS\n";
    let registry = ncplan::dialect::Registry::shipped();
    let s = ncplan::pipeline::sniff(&registry, text.as_bytes(), std::path::Path::new("HOME.LIB"));
    assert_eq!(s.dialect, "okuma_lathe");
    let d = read("okuma_lathe", text);
    assert!(errors(&d).is_empty(), "{:?}", errors(&d));
}

/// Mitsubishi M system: G38 (tool radius compensation vector designation) and spindle
/// synchronization G114.1 / G113; the L system's G114.1 and high-accuracy control G61.1.
#[test]
fn mitsubishi_documented_codes_read_as_intent() {
    let mill = "O1000\nG90 G54 G0 X0 Y0\nG43 H1 Z50.\nM3 S1000\nG1 G41 D1 X10. Y0 F200\nG38 I1. J0\nX20.\nG40 G0 X0 Y0\nG114.1 H1 D-2\nG113\nM30\n";
    let d = read("mitsubishi", mill);
    assert!(errors(&d).is_empty(), "{:?}", errors(&d));
    for code in ["G38", "G114.1", "G113"] {
        assert!(warned(&d, code), "{code}: {d:?}");
    }
    let lathe = "O2000\nG61.1\nG0 X100. Z10.\nG114.1 H1 D-2\nM30\n";
    let d = read("mitsubishi_lathe", lathe);
    assert!(errors(&d).is_empty(), "{:?}", errors(&d));
    assert!(warned(&d, "G114.1"), "{d:?}");
}

/// Mazak Integrex (EIA, G-code type C): cross machining control G110 C2 / G110 Z2 and its
/// cancel G111 as the Autodesk Integrex post writes them, and G61.1 geometry compensation.
#[test]
fn mazak_integrex_cross_machining_reads_as_intent() {
    let text = "O1000\nG123.1\nG61.1\nG0 X100. Z10.\nG110 C2\nG111\nG110 Z2\nG111\nM30\n";
    let d = read("mazak_millturn", text);
    assert!(errors(&d).is_empty(), "{:?}", errors(&d));
    assert!(warned(&d, "G110") && warned(&d, "G111"), "{d:?}");
}

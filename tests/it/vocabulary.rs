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
    ("fanuc_lathe", "G70", "G0 X10 Z1\n{} P10 Q20\nN10 G1 X5\nN20 Z-1\nM30\n"),
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

/// Every G and M code a word-address dialect's table marks modelled or intent reads without
/// an error in a program of its own; an intent code says it is kept as intent.
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
    assert!(tried > 500, "only {tried} codes tried");
    assert!(failed.is_empty(), "{} of {tried} codes read with errors:\n{}", failed.len(), failed.join("\n"));
}

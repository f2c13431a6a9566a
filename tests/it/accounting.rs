//! The diff's accounting invariant over generated programs and edits (issue 32 §1): after a
//! cosmetic rewrite nothing is reported; after any other edit every differing statement is
//! named by a change, and there is at least one change.

use proptest::prelude::*;

use ncplan::dialect::Registry;
use ncplan::diff::{self, Change};
use ncplan::interp::Profile;
use ncplan::pipeline;

/// One generated statement of a milling program, in a neutral form both dialects read.
#[derive(Clone, Debug)]
enum Line {
    Rapid(f64, f64),
    RapidZ(f64),
    Feed(f64, f64, u32),
    Plunge(f64, u32),
    Arc(f64, f64),
    Dwell(u32),
    Spindle(u32, bool),
    Coolant(bool),
    Var(u32, f64),
    FeedVar(u32),
    Stop,
    Message(u32),
}

fn line() -> impl Strategy<Value = Line> {
    let c = || (-50i32..50).prop_map(|v| f64::from(v) / 2.0);
    prop_oneof![
        (c(), c()).prop_map(|(x, y)| Line::Rapid(x, y)),
        (1i32..20).prop_map(|z| Line::RapidZ(f64::from(z))),
        (c(), c(), 1u32..20).prop_map(|(x, y, f)| Line::Feed(x, y, f * 50)),
        ((-10i32..0), 1u32..10).prop_map(|(z, f)| Line::Plunge(f64::from(z) / 2.0, f * 20)),
        (c(), c()).prop_map(|(x, y)| Line::Arc(x, y)),
        (1u32..5).prop_map(Line::Dwell),
        (1u32..10, any::<bool>()).prop_map(|(s, cw)| Line::Spindle(s * 500, cw)),
        any::<bool>().prop_map(Line::Coolant),
        (100u32..104, c()).prop_map(|(n, v)| Line::Var(n, v)),
        (100u32..104).prop_map(Line::FeedVar),
        Just(Line::Stop),
        (0u32..3).prop_map(Line::Message),
    ]
}

/// How the same program may be written: block numbers, comments, case, number spelling.
#[derive(Clone, Copy, Debug)]
struct Style {
    numbers: bool,
    comments: bool,
    lower: bool,
    trailing_zeros: bool,
    spaces: bool,
}

fn style() -> impl Strategy<Value = Style> {
    (any::<bool>(), any::<bool>(), any::<bool>(), any::<bool>(), any::<bool>())
        .prop_map(|(numbers, comments, lower, trailing_zeros, spaces)| Style { numbers, comments, lower, trailing_zeros, spaces })
}

fn num(v: f64, s: Style) -> String {
    if s.trailing_zeros {
        format!("{v:.3}")
    } else if v.fract() == 0.0 {
        format!("{v}.")
    } else {
        format!("{v}")
    }
}

fn write(lines: &[Line], s: Style) -> String {
    let sep = if s.spaces { "  " } else { " " };
    let mut out = String::from("%\nO1000 (GENERATED)\nG21 G90 G17\nT1 M6\nS1000 M3\nG0 X0. Y0.\nG0 Z5.\n");
    for (k, l) in lines.iter().enumerate() {
        let n = |v: f64| num(v, s);
        let mut t = match l {
            Line::Rapid(x, y) => format!("G0{sep}X{}{sep}Y{}", n(*x), n(*y)),
            Line::RapidZ(z) => format!("G0{sep}Z{}", n(*z)),
            Line::Feed(x, y, f) => format!("G1{sep}X{}{sep}Y{}{sep}F{f}.", n(*x), n(*y)),
            Line::Plunge(z, f) => format!("G1{sep}Z{}{sep}F{f}.", n(*z)),
            Line::Arc(x, y) => format!("G2{sep}X{}{sep}Y{}{sep}R25.", n(*x), n(*y)),
            Line::Dwell(p) => format!("G4{sep}P{p}."),
            Line::Spindle(sp, cw) => format!("S{sp}{sep}M{}", if *cw { 3 } else { 4 }),
            Line::Coolant(on) => format!("M{}", if *on { 8 } else { 9 }),
            Line::Var(v, x) => format!("#{v}={}", n(*x)),
            Line::FeedVar(v) => format!("G1{sep}X#{v}{sep}F300."),
            Line::Stop => "M1".into(),
            Line::Message(m) => format!("#500={m}"),
        };
        if s.lower {
            t = t.to_lowercase();
        }
        if s.numbers {
            t = format!("N{} {t}", (k + 1) * 10);
        }
        if s.comments && k % 3 == 0 {
            t.push_str(" (STEP)");
        }
        out.push_str(&t);
        out.push('\n');
    }
    out.push_str("G0 Z50.\nM30\n%\n");
    out
}

fn compare(a: &str, b: &str) -> (Vec<Change>, Vec<diff::Located>) {
    let d = Registry::shipped().get("fanuc").unwrap();
    let profile = Profile::default();
    let pa = pipeline::analyze_plan(a.as_bytes(), &d, &profile);
    let pb = pipeline::analyze_plan(b.as_bytes(), &d, &profile);
    let x = diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d };
    let y = diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d };
    let changes = diff::compare(x, y);
    let missing = diff::unaccounted(x, y, &changes);
    (changes, missing)
}

/// An edit an operator makes: change a line, insert one, remove one, swap two.
#[derive(Clone, Debug)]
enum Edit {
    Replace(usize, Line),
    Insert(usize, Line),
    Remove(usize),
    Swap(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        (any::<usize>(), line()).prop_map(|(i, l)| Edit::Replace(i, l)),
        (any::<usize>(), line()).prop_map(|(i, l)| Edit::Insert(i, l)),
        any::<usize>().prop_map(Edit::Remove),
        any::<usize>().prop_map(Edit::Swap),
    ]
}

fn apply(lines: &[Line], e: &Edit) -> Vec<Line> {
    let mut v = lines.to_vec();
    let n = v.len();
    match e {
        Edit::Replace(i, l) if n > 0 => v[i % n] = l.clone(),
        Edit::Insert(i, l) => v.insert(i % (n + 1), l.clone()),
        Edit::Remove(i) if n > 0 => {
            v.remove(i % n);
        }
        Edit::Swap(i) if n > 1 => v.swap(i % (n - 1), i % (n - 1) + 1),
        _ => {}
    }
    v
}

proptest! {
    #![proptest_config(ProptestConfig { cases: std::env::var("NCPLAN_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(96), ..ProptestConfig::default() })]

    /// The same statements written another way: no change at all.
    #[test]
    fn a_cosmetic_rewrite_reports_nothing(lines in proptest::collection::vec(line(), 1..25), a in style(), b in style()) {
        let (changes, missing) = compare(&write(&lines, a), &write(&lines, b));
        prop_assert!(missing.is_empty());
        prop_assert!(changes.is_empty(), "{:?}", changes.iter().map(Change::phrase).collect::<Vec<_>>());
    }

    /// Any other edit, written in any style: every differing statement is named, and a
    /// real difference gives at least one change.
    #[test]
    fn every_edited_statement_is_accounted_for(
        lines in proptest::collection::vec(line(), 1..25),
        edits in proptest::collection::vec(edit(), 1..4),
        a in style(),
        b in style(),
    ) {
        let mut edited = lines.clone();
        for e in &edits {
            edited = apply(&edited, e);
        }
        let (x, y) = (write(&lines, a), write(&edited, b));
        let (changes, missing) = compare(&x, &y);
        prop_assert!(missing.is_empty(), "{missing:?}");
        let same = write(&lines, a) == write(&edited, a);
        // Only an assignment of a number written elsewhere (`#500=1` swapped with the rapid
        // after it): no change where nothing between reads it, a change where something does.
        let others = |v: &[Line]| v.iter().filter(|l| !matches!(l, Line::Var(..) | Line::Message(_))).cloned().collect::<Vec<_>>();
        let assigned = |v: &[Line]| {
            let mut s: Vec<String> = v.iter().filter(|l| matches!(l, Line::Var(..) | Line::Message(_))).map(|l| format!("{l:?}")).collect();
            s.sort();
            s
        };
        let moved = write(&others(&lines), a) == write(&others(&edited), a) && assigned(&lines) == assigned(&edited);
        if !moved || same {
            prop_assert_eq!(changes.is_empty(), same, "{:?}", changes.iter().map(Change::phrase).collect::<Vec<_>>());
        }
    }
}

/// Lines of any dialect's look, valid or not.
fn rough_line() -> impl Strategy<Value = String> {
    let word = prop_oneof![
        Just("G0".to_owned()),
        Just("G1".to_owned()),
        Just("G2".to_owned()),
        Just("M3".to_owned()),
        Just("M30".to_owned()),
        Just("L".to_owned()),
        Just("FMAX".to_owned()),
        Just("CYCLE81(10,0,2,-5)".to_owned()),
        Just("o<sub> call [1] [2]".to_owned()),
        Just("#1=[#1+1]".to_owned()),
        Just("IF [#1 GT 2] GOTO 10".to_owned()),
        Just("(comment (nested) )".to_owned()),
        Just("; note".to_owned()),
        Just("~".to_owned()),
        Just("\"".to_owned()),
        ("[XYZFSTQR]", -100i32..100).prop_map(|(a, v)| format!("{a}{}", f64::from(v) / 4.0)),
    ];
    proptest::collection::vec(word, 0..6).prop_map(|w| w.join(" "))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: std::env::var("NCPLAN_PROPTEST_CASES").ok().and_then(|v| v.parse().ok()).unwrap_or(64), ..ProptestConfig::default() })]

    /// Whatever two texts are compared, in whichever dialect, the diff returns and names
    /// every differing statement.
    #[test]
    fn any_two_texts_are_accounted_for(
        a in proptest::collection::vec(rough_line(), 0..20),
        b in proptest::collection::vec(rough_line(), 0..20),
        dialect in prop_oneof![Just("fanuc"), Just("linuxcnc"), Just("siemens"), Just("heidenhain")],
    ) {
        let d = Registry::shipped().get(dialect).unwrap();
        let profile = Profile::default();
        let (a, b) = (a.join("\n"), b.join("\n"));
        let pa = pipeline::analyze_plan(a.as_bytes(), &d, &profile);
        let pb = pipeline::analyze_plan(b.as_bytes(), &d, &profile);
        let x = diff::Program { plan: &pa.plan, text: &pa.source.text, dialect: &d };
        let y = diff::Program { plan: &pb.plan, text: &pb.source.text, dialect: &d };
        let changes = diff::compare(x, y);
        prop_assert!(diff::unaccounted(x, y, &changes).is_empty());
    }
}

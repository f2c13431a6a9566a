//! Line ends, encodings and program delimiters do not change what a program does: the same
//! part written with CRLF or CR line ends, a UTF-8 byte-order mark, Windows-1252 (Latin-1)
//! comments, or leading and trailing `%` lines gives the same moves, with findings at the
//! same line and column.

use ncplan::canon::{CanonOp, write_call};
use ncplan::dialect::Registry;
use ncplan::interp::Profile;
use ncplan::pipeline::analyze;
use ncplan::text::LineIndex;

/// The moves of `bytes` as canonical text, and every finding as `code line:col`.
fn run(dialect: &str, bytes: &[u8]) -> (String, Vec<String>) {
    let d = Registry::shipped().get(dialect).unwrap();
    let a = analyze(bytes, &d, &Profile::default());
    let mut moves = String::new();
    for c in &a.canon {
        if matches!(c.op, CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. }) {
            write_call(&mut moves, &c.op);
        }
    }
    let idx = LineIndex::new(&a.source.text);
    let findings = a
        .diagnostics
        .iter()
        .filter(|d| d.code.as_str() != "text::not-utf8")
        .map(|d| {
            let at = idx.line_col(&a.source.text, d.range.start);
            format!("{} {}:{}", d.code.as_str(), at.line, at.col)
        })
        .collect();
    (moves, findings)
}

/// Windows-1252 bytes for `text` (the characters used here only).
fn cp1252(text: &str) -> Vec<u8> {
    text.chars()
        .map(|c| match c {
            'ä' => 0xE4,
            'Ä' => 0xC4,
            'Ø' => 0xD8,
            'µ' => 0xB5,
            '–' => 0x96,
            '°' => 0xB0,
            c if c.is_ascii() => c as u8,
            c => panic!("no Windows-1252 byte for {c}"),
        })
        .collect()
}

/// The part in `file`, after a comment of accented text and a deliberate mistake, written
/// every way a shop's files come.
fn variants(file: &str, comment: &str, mistake: &str, percent: bool) -> Vec<(&'static str, Vec<u8>)> {
    let text = std::fs::read_to_string(crate::root().join("tests/programs/equivalence").join(file)).unwrap();
    let text = text.trim_start_matches("%\n").trim_end_matches("%\n");
    let body = format!("{comment}\n{mistake}\n{text}");
    let lf = body.clone();
    let mut out = vec![
        ("LF", lf.clone().into_bytes()),
        ("CRLF", lf.replace('\n', "\r\n").into_bytes()),
        ("CR", lf.replace('\n', "\r").into_bytes()),
        ("BOM", [&b"\xEF\xBB\xBF"[..], lf.as_bytes()].concat()),
        ("Windows-1252", cp1252(&lf)),
        ("Windows-1252 CRLF", cp1252(&lf.replace('\n', "\r\n"))),
    ];
    if percent {
        // The `%` lines add a line at the top: the mistake moves down one line.
        out.push(("%", format!("%\n{lf}%\n").into_bytes()));
        out.push(("% CRLF", format!("%\n{lf}%\n").replace('\n', "\r\n").into_bytes()));
    }
    out
}

fn same_everywhere(dialect: &str, file: &str, comment: &str, mistake: &str, percent: bool) {
    let all = variants(file, comment, mistake, percent);
    let (moves, findings) = run(dialect, &all[0].1);
    assert!(moves.lines().count() > 5, "{file}: {moves}");
    assert!(findings.iter().any(|f| f.contains(" 2:")), "{file}: the mistake on line 2 is found: {findings:?}");
    for (name, bytes) in &all[1..] {
        let (m, f) = run(dialect, bytes);
        assert_eq!(m, moves, "{file} written {name}: different moves");
        if name.starts_with('%') {
            // The `%` line comes first: every finding is one line further down.
            let shifted: Vec<String> = findings
                .iter()
                .map(|x| {
                    let (code, at) = x.rsplit_once(' ').unwrap();
                    let (line, col) = at.split_once(':').unwrap();
                    format!("{code} {}:{col}", line.parse::<u32>().unwrap() + 1)
                })
                .collect();
            assert_eq!(f, shifted, "{file} written {name}");
        } else {
            assert_eq!(f, findings, "{file} written {name}");
        }
    }
}

#[test]
fn fanuc_programs_read_the_same_in_every_encoding_and_line_end() {
    same_everywhere("fanuc", "face.nc", "(FRÄSER Ø50 – 0.5 µm, 45°)", "G987", true);
}

#[test]
fn siemens_programs_read_the_same_in_every_encoding_and_line_end() {
    same_everywhere("siemens", "pocket.mpf", "; Fräser Ø10 – 5 µm, 45°", "G987", true);
}

#[test]
fn heidenhain_programs_read_the_same_in_every_encoding_and_line_end() {
    same_everywhere("heidenhain", "peck.h", "; Fräser Ø10 – 5 µm, 45°", "L X+10 Y+0 R0 FMAX ZZ", false);
}

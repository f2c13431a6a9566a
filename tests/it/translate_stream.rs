//! The proof in bounded memory (`pipeline::check_translation`, `ncplan::proof::Comparison`):
//! the program and its translation are read on two threads and compared as their moves come,
//! a batch at a time. A difference anywhere is found at its line however long the program,
//! and the windows the comparison needs (a rapid merged along its line, an arc written back
//! in pieces) hold across the batches.

use ncplan::interp::Profile;
use ncplan::pipeline::{self, Diagnostic};
use ncplan::text::LineIndex;

use crate::translate::dialect;

/// The proof of `translated` against `source`, both LinuxCNC.
fn prove(source: &str, translated: &str) -> Vec<Diagnostic> {
    let ngc = dialect("linuxcnc");
    pipeline::check_translation(source.into(), &ngc, translated, &ngc, &Profile::default(), &[])
}

/// The one finding of a proof that failed: its source line and its message.
fn parted(source: &str, found: &[Diagnostic]) -> (u32, String) {
    assert_eq!(found.len(), 1, "{found:?}");
    let d = &found[0];
    assert_eq!(d.code.as_str(), "post::motion-differs");
    (LineIndex::new(source).line_col(source, d.range.start).line, d.message.clone())
}

const HEAD: &str = "G21 G90 G17 G54\nT1 M6\nS1000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F300\n";

/// A surfacing pass of `n` cuts (`HEAD`'s five lines first), the cut at `planted` going to
/// X50.01 instead of X50.
fn surfacing(n: usize, planted: Option<usize>) -> String {
    let mut s = String::from(HEAD);
    for i in 0..n {
        let x = if i % 2 == 0 { 50.0 } else { 0.0 } + if planted == Some(i) { 0.01 } else { 0.0 };
        s.push_str(&format!("G1 X{x:.3} Y{:.3}\n", i as f64 * 0.01));
    }
    s.push_str("G0 Z5\nM30\n");
    s
}

#[test]
fn translate_proof_finds_a_difference_late_in_a_long_program_at_its_line() {
    const N: usize = 200_000;
    let source = surfacing(N, None);
    assert_eq!(prove(&source, &source), Vec::new());
    let at = N - 8;
    let planted = surfacing(N, Some(at));
    let line = (HEAD.lines().count() + at + 1) as u32;
    let (l, what) = parted(&source, &prove(&source, &planted));
    assert_eq!(l, line);
    assert_eq!(
        what,
        format!(
            "the translation does not run as the program does (the translation's line {line}): feed to X50.0000 Y{y:.4} Z-1.0000 became feed to X50.0100 Y{y:.4} Z-1.0000",
            y = at as f64 * 0.01
        )
    );
}

/// More cuts than a batch first, so that the rapids and the arc below come in a later one.
fn after_a_batch(tail: &str) -> String {
    let mut s = surfacing(ncplan::proof::BATCH + 500, None);
    s.truncate(s.len() - "G0 Z5\nM30\n".len());
    s.push_str(tail);
    s
}

/// Rapids on along one line are one rapid, and an arc may come back in pieces: in a stream
/// compared batch by batch as in a whole one; a piece that strays is found at the program's
/// block, naming the translation's first piece.
#[test]
fn translate_proof_keeps_merged_rapids_and_arc_pieces_across_batches() {
    let source = after_a_batch(
        "G0 Z5\nG0 X0 Y0\nG0 X1\nG0 X2\nG0 X3\nG0 X4\nG0 X5\nG0 X6\nG0 X7\nG0 X8\nG0 X9\nG0 X10\nG1 Z-1\nG3 X30 Y0 I10 J0\nG0 Z5\nM30\n",
    );
    let lines = source.lines().count() as u32;
    // The arc's block and the first of the merged rapids, from the end.
    let (arc, rapid) = (lines - 2, lines - 13);
    let tail = |rapids: &str, pieces: &str| after_a_batch(&format!("G0 Z5\nG0 X0 Y0\n{rapids}G1 Z-1\n{pieces}G0 Z5\nM30\n"));
    let whole = tail("G0 X4\nG0 X10\n", "G3 X20 Y-10 I10 J0\nG3 X30 Y0 I0 J10\n");
    assert_eq!(prove(&source, &whole), Vec::new());
    // A rapid that leaves the line: two rapids where the program makes one.
    let off = tail("G0 X4 Y0.01\nG0 X10 Y0\n", "G3 X20 Y-10 I10 J0\nG3 X30 Y0 I0 J10\n");
    let off_line = lines - 13;
    let (l, what) = parted(&source, &prove(&source, &off));
    assert_eq!(l, rapid);
    assert_eq!(
        what,
        format!(
            "the translation does not run as the program does (the translation's line {off_line}): rapid to X10.0000 Y0.0000 Z5.0000 became rapid to X4.0000 Y0.0100 Z5.0000"
        )
    );
    // The arc's second piece turning the other way.
    let cw = tail("G0 X4\nG0 X10\n", "G3 X20 Y-10 I10 J0\nG2 X30 Y0 I0 J10\n");
    let first_piece = lines - 10;
    let (l, what) = parted(&source, &prove(&source, &cw));
    assert_eq!(l, arc);
    assert_eq!(
        what,
        format!(
            "the translation does not run as the program does (the translation's line {first_piece}): arc about X20.0000 Y0.0000 Z0.0000 became cw arc about X20.0000 Y0.0000 Z0.0000"
        )
    );
    // The translation ending within the arc.
    let short = tail("G0 X4\nG0 X10\n", "G3 X20 Y-10 I10 J0\n");
    let (l, what) = parted(&source, &prove(&source, &short));
    assert_eq!(l, arc);
    assert!(what.ends_with("arc about X20.0000 Y0.0000 Z0.0000 became rapid about X0.0000 Y0.0000 Z0.0000"), "{what}");
}

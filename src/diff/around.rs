//! What a lathe program's statement is by the blocks around it, where its own words do not
//! say: the positioning move just before a lathe cycle is that cycle's start point, and the
//! blocks a contour cycle names by `P` and `Q` are its contour.
//!
//! Fanuc and Haas lathes (Fanuc 0i-TF operator's manual, "multiple repetitive cycles" G70–G76
//! and "single cycles" G90/G92/G94; Haas lathe operator's manual, G70–G76): the cycle starts
//! from where the tool stands when it is called (point A), roughs or threads from there and
//! returns there at its end, so the move before it sets the start and return point: the stock
//! G71 roughs from, the diameter G76's passes begin and retract to. G71/G72/G70's `P` and `Q`
//! name the first and last blocks of the contour (`N10` … `N20`) that the cycle roughs to and
//! finishes along. LinuxCNC's G76 alike starts its drive line where the tool stands (LinuxCNC
//! G-code reference, G76). Both are told in those terms where the plan shows nothing of the edit (a
//! contour whose every block is a rapid, a start point the passes do not reach).

use super::statement::Stmt;
use crate::dialect::{Dialect, Meaning, Role};
use crate::syntax::{Block, Parser, Value};

/// What the blocks around a statement make of it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Around {
    /// The last move before a lathe cycle: its start and return point. The cycle's code
    /// (letter, number × 10).
    StartOf((char, u32)),
    /// A block of the contour a contour cycle names by its `P` and `Q`. The cycle's code.
    ContourOf((char, u32)),
}

/// Whether a code's meaning is a lathe cycle that starts from, and returns to, where the tool
/// stands when it is called.
pub(super) fn starts_where_called(m: Meaning) -> bool {
    use Meaning as M;
    matches!(
        m,
        M::CycleThread
            | M::CycleTurn
            | M::CycleFace
            | M::CycleThreadPass
            | M::CycleRoughTurn
            | M::CycleRoughFace
            | M::CycleRoughPattern
            | M::CycleFinishContour
            | M::CycleThreadMultiple
            | M::CycleGroove
            | M::CycleFacePeck
    )
}

/// Whether a code's meaning is a cycle that names its contour by the block numbers `P` and `Q`.
fn names_contour(m: Meaning) -> bool {
    m.names_contour()
}

/// Whether the dictionary has lathe cycles at all: only then are the blocks read again.
pub(super) fn applies(d: &Dialect) -> bool {
    d.codes.iter().any(|c| c.keyword.is_none() && starts_where_called(c.meaning))
}

/// The G code of a block that is a lathe cycle, with its meaning.
fn cycle_of(block: &Block, d: &Dialect) -> Option<((char, u32), Meaning)> {
    block.words.iter().find_map(|w| match (w.letter, w.value) {
        (b'G', Value::Number { value, .. }) => {
            let n = code_number(value);
            let def = d.code('G', n)?;
            starts_where_called(def.meaning).then_some((('G', n), def.meaning))
        }
        _ => None,
    })
}

/// A block number a word gives (`P10`).
fn number_of(block: &Block, letter: u8) -> Option<u32> {
    block.words.iter().find_map(|w| match (w.letter, w.value) {
        (l, Value::Number { value, .. }) if l == letter && value >= 0.0 && value.fract() == 0.0 && value < 1e9 => Some(value as u32),
        _ => None,
    })
}

/// A G word's value as the dictionary numbers codes (number × 10: `G76` is 760).
fn code_number(value: f64) -> u32 {
    (value * 10.0).round().max(0.0) as u32
}

/// Whether a meaning is a motion code (`G0`, `G1`, `G2`, `G3`).
fn is_motion(m: Meaning) -> bool {
    matches!(m, Meaning::Rapid | Meaning::Linear | Meaning::ArcCw | Meaning::ArcCcw)
}

/// Whether a block has a motion code (`G0`, `G1`, `G2`, `G3`).
fn motion_code(block: &Block, d: &Dialect) -> bool {
    block.words.iter().any(|w| match (w.letter, w.value) {
        (b'G', Value::Number { value, .. }) => d.code('G', code_number(value)).is_some_and(|c| is_motion(c.meaning)),
        _ => false,
    })
}

/// Whether a block moves the tool in the plane a lathe turns in: an axis word, no return to a
/// reference point or machine-coordinate move (`G28`, `G53`), which are told as such, and no
/// code that takes the axis letters as its own parameters (Fanuc's dwell `G04 X1.`, the
/// coordinate setting `G50 X Z`): those words move nothing.
fn positions(block: &Block, d: &Dialect) -> bool {
    const AXES: [Role; 4] = [Role::X, Role::Z, Role::U, Role::W];
    let moves_nothing = block.words.iter().any(|w| match (w.letter, w.value) {
        (b'G', Value::Number { value, .. }) => d.code('G', code_number(value)).is_some_and(|c| {
            use Meaning as M;
            matches!(
                c.meaning,
                M::Home1
                    | M::Home2
                    | M::ReferenceApproach
                    | M::FixedPointApproach
                    | M::MachineCoords
                    | M::MachineBuilderCoords
                    | M::SetData
                    | M::OriginShift
                    | M::LocalOffset
                    | M::Home1Set
                    | M::Home2Set
            ) || (!is_motion(c.meaning) && AXES.iter().any(|&r| c.params.takes(r)))
        }),
        _ => false,
    });
    !moves_nothing && block.words.iter().any(|w| AXES.contains(&w.role))
}

/// What each of `stmts` (the statements of `text`) is by the blocks around it; `None` for most.
pub(super) fn read(text: &str, d: &Dialect, stmts: &[Stmt]) -> Vec<Option<Around>> {
    let mut out = vec![None; stmts.len()];
    if !applies(d) {
        return out;
    }
    let index = |line: u32| stmts.binary_search_by_key(&line, |s| s.line).ok();
    let mut parser = Parser::new(text, d);
    let mut block = Block::default();
    let mut diags = Vec::new();
    // (statement, block number) of every block, and the contours cycles name.
    let mut numbered: Vec<(Option<usize>, Option<u32>)> = Vec::new();
    let mut contours: Vec<(usize, u32, u32, (char, u32))> = Vec::new();
    let mut last_move: Option<usize> = None;
    // A single cycle in force (G90, G92, G94 are modal): the blocks after it with only axis
    // words are its further passes, no start point, until another motion code.
    let mut modal_cycle = false;
    while parser.next_block(&mut block, &mut diags) {
        diags.clear();
        let at = index(block.line);
        numbered.push((at, block.number));
        if let Some((code, meaning)) = cycle_of(&block, d) {
            if let Some(k) = last_move.take() {
                out[k] = Some(Around::StartOf(code));
            }
            modal_cycle = matches!(meaning, Meaning::CycleTurn | Meaning::CycleFace | Meaning::CycleThreadPass);
            if names_contour(meaning)
                && let (Some(p), Some(q)) = (number_of(&block, b'P'), number_of(&block, b'Q'))
            {
                contours.push((numbered.len() - 1, p, q, code));
            }
            continue;
        }
        if motion_code(&block, d) {
            modal_cycle = false;
        }
        if positions(&block, d) {
            last_move = if modal_cycle { None } else { at };
        }
    }
    for (from, p, q, code) in contours {
        // The first block numbered P after the cycle, or else before it (G70 names a contour
        // written earlier, with its G71), then the blocks up to the one numbered Q.
        let Some(first) = (from..numbered.len()).chain(0..from).find(|&k| numbered[k].1 == Some(p)) else { continue };
        let Some(last) = (first..numbered.len()).find(|&k| numbered[k].1 == Some(q)) else { continue };
        // A contour block is the contour's also where a cycle after it starts from it.
        for &(at, _) in &numbered[first..=last] {
            if let Some(k) = at
                && !matches!(out[k], Some(Around::ContourOf(_)))
            {
                out[k] = Some(Around::ContourOf(code));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dialect::Registry;

    fn roles(text: &str, dialect: &str) -> Vec<(u32, Option<Around>)> {
        let d = Registry::shipped().get(dialect).unwrap();
        let (stmts, _) = crate::diff::statement::read(text, &d);
        read(text, &d, &stmts).into_iter().zip(&stmts).map(|(r, s)| (s.line, r)).collect()
    }

    #[test]
    fn the_move_before_a_lathe_cycle_is_its_start_and_p_q_its_contour() {
        let text = "G18 G20 G99\nT0101\nG00 X3.0 Z0.1\nM08\nG71 P10 Q20 U0.01 W0.005 D0.05 F0.01\nN10 G00 X1.0\nN15 G01 Z-1.0\nN20 X3.0\nG70 P10 Q20\nG00 X1.2\nG76 X0.8 Z-1.0 K0.06 D0.01 F0.1\nM30\n";
        let r = roles(text, "haas_lathe");
        let at = |l: u32| r.iter().find(|(line, _)| *line == l).and_then(|x| x.1);
        assert_eq!(at(3), Some(Around::StartOf(('G', 710))));
        assert_eq!(at(4), None);
        for l in [6, 7, 8] {
            assert_eq!(at(l), Some(Around::ContourOf(('G', 710))), "line {l}");
        }
        assert_eq!(at(10), Some(Around::StartOf(('G', 760))));
        assert_eq!(at(12), None);
    }

    #[test]
    fn a_modal_single_cycles_further_passes_are_no_start_point() {
        // G90's further passes (`X1.8`) run the cycle again; the G92 after them starts where the
        // last pass returned, which no block of its own states.
        let text = "G18 G21 G99\nG00 X50. Z2.\nG90 X45. Z-20. F0.2\nX40.\nG92 X38. Z-15. F1.5\nM30\n";
        let r = roles(text, "fanuc_lathe");
        let at = |l: u32| r.iter().find(|(line, _)| *line == l).and_then(|x| x.1);
        assert_eq!(at(2), Some(Around::StartOf(('G', 900))));
        assert_eq!(at(4), None);
    }

    #[test]
    fn a_drilling_cycles_approach_is_no_lathe_start_point() {
        // A mill's G81 starts at its R plane, not where the tool stood: the rapid before it is
        // told as the move it is.
        let text = "G0 X0 Y0 Z10\nG81 X10 Y10 Z-5 R2 F100\nM30\n";
        assert!(roles(text, "linuxcnc").iter().all(|(_, r)| r.is_none()));
    }

    #[test]
    fn a_dwell_or_a_coordinate_setting_before_a_cycle_is_no_start_point() {
        // `G04 X1.` waits a second and `G50 X Z` names where the tool stands: neither moves it,
        // so the rapid before them stays the cycle's start point.
        let text = "G99\nG00 X30. Z5.\nG04 X1.\nG76 P010060 Q100 R0.05\nG76 X22.2 Z-20. P1000 Q300 F1.5\nG50 X200. Z100.\nM30\n";
        let r = roles(text, "fanuc_lathe");
        let at = |l: u32| r.iter().find(|(line, _)| *line == l).and_then(|x| x.1);
        assert_eq!(at(2), Some(Around::StartOf(('G', 760))));
        assert_eq!(at(3), None);
        assert_eq!(at(6), None);
    }
}

//! An absolute height that later incremental moves inherit: a statement's Z changed in
//! absolute distances (`G90 X-20 Y-20 Z0.85` → `Z0.8`), where the next move that says Z says
//! it incrementally (`G91 Z0.8`), shifts every later height the program reaches by steps from
//! it; the control adds each step to where the tool is. Where the plan does not show it (no
//! motion mode, moves the plan cannot see) it is told as that height's change, not as a word.

use super::Program;
use super::statement::{self, Sort, Stmt, Token};
use super::typed::{About, Context, about};
use crate::dialect::{Dialect, Meaning, Role};

/// How many statements one look around a changed height reads at most, and all of them in one
/// diff: a bound on the work whatever the program's size.
const BUDGET: usize = 20_000;

/// The reading budget left for a diff's looks around changed heights.
pub(super) struct Budget(usize);

impl Default for Budget {
    fn default() -> Budget {
        Budget(BUDGET)
    }
}

/// The name of the height axis where the dialect mills in the XY plane (`Z`); `None` on a lathe.
pub(super) fn axis(d: &Dialect) -> Option<&str> {
    if d.behaviour.x_diameter || d.behaviour.initial_plane != crate::canon::Plane::Xy {
        return None;
    }
    d.addresses.iter().find(|a| a.role == Role::Z).map(|a| a.name.as_str())
}

/// The distance mode a statement's tokens set: `Some(true)` incremental, `Some(false)` absolute.
fn mode(tokens: &[Token], d: &Dialect) -> Option<bool> {
    tokens.iter().rev().find_map(|t| match about(t, d) {
        About::Code(Meaning::DistanceIncremental) => Some(true),
        About::Code(Meaning::DistanceAbsolute) => Some(false),
        _ => None,
    })
}

/// The value of the height word among `tokens` as a move says it: incremental where written
/// `Z=IC(…)`, absolute where `Z=AC(…)`, by the mode otherwise (`None`: no height word, or the
/// statement's axis words are no motion: a frame, an offset, a cycle's or a macro's values).
fn height_word(tokens: &[Token], axis: &str, d: &Dialect) -> Option<Option<bool>> {
    let ctx = Context::of(tokens, d);
    if ctx.shift || ctx.macro_call || ctx.cycle || ctx.other_cycle || ctx.length || ctx.data.is_some() {
        return None;
    }
    tokens.iter().find_map(|t| match t.sort {
        Sort::Word if t.key == axis => Some(None),
        Sort::Assign if t.key == axis => {
            let v = t.value.to_ascii_uppercase();
            Some(if v.starts_with("IC(") {
                Some(true)
            } else if v.starts_with("AC(") {
                Some(false)
            } else {
                None
            })
        }
        _ => None,
    })
}

/// Whether the height of statement `k` of `p` is absolute and the next move that says a height
/// after it says it incrementally: every later height is reached by steps from it.
pub(super) fn inherited(p: Program<'_>, s: &[Stmt], k: usize, axis: &str, budget: &mut Budget) -> bool {
    let d = p.dialect;
    let tokens = |i: usize| statement::tokens_in(&statement::text_of(p.text, d, &s[i]), d);
    let own = tokens(k);
    // Its own mode: the statement's code, else the last one before it (absolute from reset).
    let mut incremental = match mode(&own, d) {
        Some(m) => m,
        None => {
            let mut found = None;
            for i in (0..k).rev() {
                if budget.0 == 0 {
                    return false;
                }
                budget.0 -= 1;
                if let Some(m) = mode(&tokens(i), d) {
                    found = Some(m);
                    break;
                }
            }
            found.unwrap_or(false)
        }
    };
    if incremental || height_word(&own, axis, d) != Some(None) {
        return false;
    }
    for i in k + 1..s.len() {
        if budget.0 == 0 {
            return false;
        }
        budget.0 -= 1;
        let t = tokens(i);
        if let Some(m) = mode(&t, d) {
            incremental = m;
        }
        if let Some(word) = height_word(&t, axis, d) {
            return word.unwrap_or(incremental);
        }
    }
    false
}

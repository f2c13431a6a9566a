//! Risky machine settings: what an operator's edit at the control may have got wrong, told
//! from the plan alone, so that `check` warns and the diff reports what an edit introduced.

use super::model::{ProcessPlan, Workingstep};
use crate::diag::{Code, Diagnostic};

/// One risky setting of one workingstep.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Risk {
    /// Workingstep index.
    pub workingstep: u32,
    /// The finding's code.
    pub code: Code,
    /// What is risky, as a planner reads it.
    pub message: String,
}

/// The name of work offset `index` (1 for G54; an additional one by its number, as
/// `G54.1 P3`, `G154 P3` and `G15 H3` all say).
pub fn work_offset_name(index: u16) -> String {
    let extended = crate::canon::EXTENDED_WCS;
    match index {
        1..=6 => format!("G{}", 53 + u32::from(index)),
        7..=9 => format!("G59.{}", index - 6),
        0 => "no settable work offset (the basic frame)".to_owned(),
        n if n > extended => format!("additional work offset {}", n - extended),
        n => format!("work offset {n}"),
    }
}

/// The risky settings of a plan, in workingstep order.
pub fn risks(plan: &ProcessPlan) -> Vec<Risk> {
    let mut out = Vec::new();
    // Workingsteps that cut with some length offset in force (their own or another).
    let with_offsets = plan.workingsteps.iter().filter(|w| !w.state.length_offsets.contains(&0)).count();
    for ws in &plan.workingsteps {
        for &h in &ws.state.length_offsets {
            let message = if h == 0 {
                if with_offsets == 0 {
                    continue;
                }
                format!("T{} cuts with no length offset (H0), while the rest of the program uses them", ws.tool)
            } else if plan.tool(h).is_some() {
                format!("T{} cuts with the length offset of tool T{h} (H{h})", ws.tool)
            } else {
                format!("T{} cuts with the length offset H{h}, not its own H{}", ws.tool, ws.tool)
            };
            let code = if h == 0 { Code::NoLengthOffset } else { Code::ForeignLengthOffset };
            out.push(Risk { workingstep: ws.index, code, message });
        }
    }
    // A work offset one workingstep uses while every other one uses another.
    let offsets: Vec<u16> = plan.workingsteps.iter().map(|w| w.state.work_offset).collect();
    if offsets.len() >= 3 {
        for ws in &plan.workingsteps {
            let w = ws.state.work_offset;
            let others: Vec<u16> = offsets.iter().copied().filter(|o| *o != w).collect();
            if others.len() + 1 == offsets.len() && others.windows(2).all(|p| p[0] == p[1]) {
                out.push(Risk {
                    workingstep: ws.index,
                    code: Code::LoneWorkOffset,
                    message: format!(
                        "workingstep {} cuts in {}, which the rest of the program never uses (it cuts in {})",
                        ws.index,
                        work_offset_name(w),
                        work_offset_name(others[0])
                    ),
                });
            }
        }
    }
    out
}

/// The risks as warnings on their workingsteps' blocks.
pub fn diagnostics(plan: &ProcessPlan) -> Vec<Diagnostic> {
    let ws = |i: u32| -> Option<&Workingstep> { plan.workingsteps.iter().find(|w| w.index == i) };
    risks(plan).into_iter().filter_map(|r| Some(Diagnostic::new(r.code, ws(r.workingstep)?.source, r.message))).collect()
}

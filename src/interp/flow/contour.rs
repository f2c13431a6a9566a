//! The contour a named turning cycle machines (Siemens `CYCLE95("NAME", ...)`): a label
//! range of this program (`"START:END"`, the blocks from the first label's through the
//! second's) or of a subprogram (`CYCLE62("PROG",3,"START","END")`), a label of this program run up to its return (`RET`, `M17`), or a subprogram
//! (`PROC NAME` here, or a program of that name in the program directory). Its blocks are
//! run without effect from the cycle's start point to read the contour (the state is put
//! back), then the interpreter cuts it (`named_turn`). And the end of a contour definition
//! that a contour cycle names only by its first block (Okuma LAP).

use super::{Driver, Mark, Pos, normalise_label};
use crate::canon::CanonSink;
use crate::diag::{Code, Diagnostic};
use crate::dialect::Statement;
use crate::interp::Interpreter;
use crate::interp::named_turn::StockRemoval;
use crate::syntax::Block;

impl<'a> Driver<'a, '_> {
    /// Whether block `b` ends a contour definition (a code of meaning `contour-end`).
    pub(super) fn ends_contour(&self, b: &Block) -> bool {
        b.words.iter().any(|w| {
            let crate::syntax::Value::Number { value, .. } = w.value else { return false };
            w.role == crate::dialect::Role::G
                && self
                    .dialect
                    .code_id('G', (value * 10.0).round() as u32)
                    .is_some_and(|c| self.dialect.codes[c].meaning == crate::dialect::Meaning::ContourEnd)
        })
    }

    /// Where the contour `name` lies: its source, first block and the offset it ends at.
    fn contour_span(&mut self, name: &str) -> Result<(usize, Pos, usize), String> {
        let label = |m: &Mark, l: &str| m.defines.as_deref() == Some(l);
        // `CYCLE62("GP1_ABSATZ",3,"E_LAB_A_ABSATZ","E_LAB_E_ABSATZ")`: the labels in the
        // program the first name gives (SinuTrain's contour call "labels in a subprogram"; the
        // program found as a called one is, beside the file or in it).
        let (cur, range) = match name.split(':').collect::<Vec<_>>()[..] {
            [program, a, b] if !program.is_empty() => {
                let key = normalise_label(program);
                let is_proc = |m: &Mark| m.statement == Some(Statement::Procedure) && m.name.as_deref() == Some(key.as_str());
                let starts = |m: &Mark| is_proc(m) || m.program_name.as_deref() == Some(key.as_str());
                let Some((source, _)) = self.locate(program, starts) else {
                    return Err(format!(
                        "the contour's program `{program}` is neither a subprogram of this program nor a program in the program directory"
                    ));
                };
                (source, Some((a, b)))
            }
            [a, b] => (self.cur, Some((a, b))),
            _ => (self.cur, None),
        };
        if let Some((a, b)) = range {
            let (a, b) = (normalise_label(a), normalise_label(b));
            let marks = self.marks(cur);
            let Some(first) = marks.iter().find(|m| label(m, &a)).cloned() else {
                return Err(format!("no label `{a}` starts the contour"));
            };
            let Some(last) = marks.iter().find(|m| label(m, &b) && m.start.at >= first.start.at) else {
                return Err(format!("no label `{b}` after `{a}` ends the contour"));
            };
            return Ok((cur, first.start, last.next.at));
        }
        let key = normalise_label(name);
        let cur = self.cur;
        if let Some(m) = self.marks(cur).iter().find(|m| label(m, &key)) {
            return Ok((cur, m.start, usize::MAX));
        }
        // The contour ShopTurn's contour editor writes under its name, between the labels
        // `E_LAB_A_name` and `E_LAB_E_name`.
        let (a, b) = (normalise_label(&format!("E_LAB_A_{name}")), normalise_label(&format!("E_LAB_E_{name}")));
        let marks = self.marks(cur);
        if let Some(first) = marks.iter().find(|m| label(m, &a)) {
            if let Some(last) = marks.iter().find(|m| label(m, &b) && m.start.at >= first.start.at) {
                return Ok((cur, first.start, last.next.at));
            }
        }
        let is_proc = |m: &Mark| m.statement == Some(Statement::Procedure) && m.name.as_deref() == Some(key.as_str());
        let starts = |m: &Mark| is_proc(m) || m.program_name.as_deref() == Some(key.as_str());
        match self.locate(name, starts) {
            Some((source, body)) => Ok((source, body, usize::MAX)),
            None => Err(format!(
                "the contour `{name}` is neither a label or a subprogram of this program nor a program in the program directory"
            )),
        }
    }

    /// A named turning cycle's contour, read and then cut as `job` says.
    pub(super) fn named_contour(
        &mut self,
        name: &str,
        job: &StockRemoval,
        block: &Block,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let Some((source, body, until)) = self.contour_or_skip(name, block, diags) else { return };
        let shape = self.contour_geometry((source, body, until), interp, diags);
        (interp.origin, interp.line) = (block.range, block.line);
        interp.stock_removal(job, &shape, sink, diags);
    }

    /// A cylinder surface cycle's contour (Heidenhain 27, 28, 29, 39: `interp::cylsurf`): the
    /// label's blocks read without effect on the cylinder's developed surface, then cut.
    pub(super) fn cylinder_contour(
        &mut self,
        name: &str,
        job: &crate::interp::cylsurf::CylinderSurface,
        block: &Block,
        interp: &mut Interpreter<'a>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let Some((source, body, until)) = self.contour_or_skip(name, block, diags) else { return };
        let tilt = interp.cylinder_surface_begin(job, sink, diags);
        let shape = self.contour_geometry((source, body, until), interp, diags);
        (interp.origin, interp.line) = (block.range, block.line);
        interp.cylinder_surface_cut(job, &shape, tilt, sink, diags);
    }

    /// The span of the contour `name` names, or an error at the cycle's block that it is
    /// skipped.
    fn contour_or_skip(&mut self, name: &str, block: &Block, diags: &mut Vec<Diagnostic>) -> Option<(usize, Pos, usize)> {
        self.contour_span(name)
            .map_err(|why| self.error(diags, Code::MissingLabel, block.range, format!("{why}; the cycle is skipped")))
            .ok()
    }

    /// A contour's blocks read as its geometry, without effect: the state, parameters, cutter
    /// compensation and corner stage as they were before, and no feed or spindle asked of the
    /// blocks (the cycle's own feeds cut the contour).
    fn contour_geometry(
        &mut self,
        (source, body, until): (usize, Pos, usize),
        interp: &mut Interpreter<'a>,
        diags: &mut Vec<Diagnostic>,
    ) -> Vec<crate::canon::Canon> {
        let corners = interp.corners.replace(None);
        let saved = (interp.st.clone(), interp.params.clone(), interp.comp.borrow().clone(), corners, interp.comp_problem.take());
        interp.comp.replace(None);
        interp.st.tech_warned = true;
        let (shape, _) = self.profile_blocks(source, body, until, interp, diags);
        let (st, params, comp, corners, problem) = saved;
        interp.st = st;
        interp.params = params;
        interp.comp.replace(comp);
        interp.corners.replace(corners);
        interp.comp_problem.set(problem);
        shape
    }
}

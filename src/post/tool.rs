//! The tool: its change (with the tool comment the plan reads back, and the length offset
//! the two controls' tool changes apply differently), its length offsets and its radius
//! compensation.
//!
//! The door: [`Post::tool_op`] for the tool ops (selection, change, tool name, length
//! offset), [`Post::comp_op`] for cutter compensation, and [`Post::flush_tool`], which
//! writes the change waiting before whatever comes next.

use super::{Post, ToolFact, Vals};
use crate::canon::{Canon, CanonOp, Setting};
use crate::diag::Code;
use crate::dialect::output::Value;

/// The tool comment for `f`, in the words `plan::parse_tool_comment` reads.
fn tool_comment(f: &ToolFact) -> String {
    use crate::plan::ToolKind as K;
    let kind = match f.kind {
        K::EndMill => "END MILL",
        K::BallEndMill => "BALL END MILL",
        K::BullnoseEndMill => "BULL END MILL",
        K::FaceMill => "FACE MILL",
        K::TwistDrill => "DRILL",
        K::CenterDrill => "SPOT DRILL",
        K::Reamer => "REAMER",
        K::Tap => "TAP",
        K::BoringTool => "BORING BAR",
        K::Countersink => "CHAMFER MILL",
        K::TurningTool => "TURNING TOOL",
        K::GroovingTool => "GROOVING TOOL",
        K::ThreadingTool => "THREADING TOOL",
        K::Unknown => "",
    };
    let mut s = format!("T{} D={}", f.number, crate::diff::num(f.diameter));
    if let Some(r) = f.corner_radius.filter(|r| *r > 0.0) {
        s.push_str(&format!(" R{}", crate::diff::num(r)));
    }
    if !kind.is_empty() {
        s.push(' ');
        s.push_str(kind);
    }
    s
}

impl<F: FnMut(&[u8])> Post<'_, F> {
    /// Writes a tool op. A change waits for what follows ([`Post::flush_tool`]): the next
    /// speed goes into its block where the target writes one there.
    pub(super) fn tool_op(&mut self, canon: &Canon) {
        match &canon.op {
            CanonOp::SelectTool(_) => {}
            CanonOp::ChangeTool(t) => {
                self.pending_tool = Some(*t);
                self.spindle_on = false;
            }
            CanonOp::Setting(Setting::ToolName(n, name)) => {
                self.tool_names.retain(|(k, _)| k != n);
                self.tool_names.push((*n, name.clone()));
            }
            CanonOp::Setting(Setting::LengthOffset(h)) if *h == self.length => {}
            CanonOp::Setting(Setting::LengthOffset(h)) => self.length_offset(canon, h),
            CanonOp::UseToolLengthOffset(_) => {}
            // Not a tool op: [`Post::other_op`] hands none here.
            _ => {}
        }
    }

    /// Writes the tool change waiting, if there is one: the tool comment of a tool whose
    /// facts came from a tool table, the change, and the length offset where the source's
    /// and the target's tool changes put it in force differently.
    pub(super) fn flush_tool(&mut self) {
        if let Some(t) = self.pending_tool.take() {
            self.cancel_cycle();
            self.tool = t;
            let mut vals = Vals::new();
            vals.set(Value::T, f64::from(t));
            if let Some(f) = self.opts.tools.iter().find(|f| f.number == t) {
                let text = tool_comment(f);
                self.comment(&text, "comment");
            }
            let uses_s = self.out.template("tool-change").is_some_and(|(t, _)| t.uses(Value::S));
            if uses_s && self.speed > 0.0 && (self.speed_dirty || self.written[4].is_none()) {
                vals.set(Value::S, self.speed);
                self.speed_dirty = false;
            }
            let writes = self.out.template("tool-change").is_some_and(|(t, _)| !t.0.is_empty());
            if !(writes && self.event("tool-change", &mut vals)) {
                // The change left out would cut on with the tool before (the proof would
                // catch it later, without the reason).
                self.diags.push(crate::diag::Diagnostic::new(
                    Code::PostUnwritable,
                    self.origin,
                    format!(
                        "the tool change to T{t} is not written: the target's `tool-change` template is empty or takes no tool number {t}"
                    ),
                ));
            }
            self.motion = None;
            if self.opts.length_at_tool_change == (true, false) {
                // The source's tool change applied the tool's length; the target needs it said.
                let mut vals = Vals::new();
                vals.set(Value::H, f64::from(t));
                self.length = t;
                self.event("length-offset", &mut vals);
            } else if self.opts.length_at_tool_change == (false, true) && self.length == 0 {
                // The source cancelled the length offset and its tool change leaves it so; the
                // target's tool change puts the tool's length in force: cancel it again.
                if self.out.template("length-offset-off").is_some() {
                    self.event("length-offset-off", &mut Vals::new());
                } else {
                    self.length_unsaid = true;
                }
            }
        }
    }

    /// Puts length offset `h` in force (0: cancelled).
    fn length_offset(&mut self, canon: &Canon, h: &u32) {
        self.length = *h;
        // A cancel where the target's tool change applies the length it cannot cancel.
        let unsaid = self.opts.length_at_tool_change.1 && self.out.template("length-offset-off").is_none();
        self.length_unsaid = *h == 0 && unsaid;
        let mut vals = Vals::new();
        vals.set(Value::H, f64::from(*h));
        // A target whose tool change applies the tool's own length (no `{h}` to
        // write) cannot apply another offset's length.
        let tool = self.pending_tool.unwrap_or(self.tool);
        if *h != 0 && *h != tool && !self.out.template("length-offset").is_some_and(|(t, _)| t.uses(Value::H)) {
            self.note(
                Code::PostUnwritable,
                canon,
                "length-offset",
                format!("the length offset H{h} while tool T{tool} is in the spindle: the target applies the tool's own length"),
            );
        }
        self.event(if *h == 0 { "length-offset-off" } else { "length-offset" }, &mut vals);
    }

    /// Writes a cutter compensation op: on a side, by the tool's radius or another offset's,
    /// or off.
    pub(super) fn comp_op(&mut self, canon: &Canon) {
        match &canon.op {
            // The target compensates by its own offsets: the side and the offset number are
            // what it writes, not the radius the source ran at.
            CanonOp::Setting(Setting::CutterComp(c)) if c.map(|c| (c.left, c.number)) == self.comp => {}
            CanonOp::Setting(Setting::CutterComp(c)) => {
                let c = c.map(|c| (c.left, c.number));
                self.comp = c;
                let mut vals = Vals::new();
                let ev = match c {
                    Some((left, d)) => {
                        self.comp_d = d.unwrap_or(self.tool);
                        vals.set(Value::D, f64::from(self.comp_d));
                        let ev = if left { "comp-left" } else { "comp-right" };
                        // A target whose compensation takes the tool's own radius (no D
                        // word) cannot compensate by another offset's radius.
                        let tool = self.pending_tool.unwrap_or(self.tool);
                        let states_d = self.out.template(ev).is_some_and(|(t, _)| t.uses(Value::D));
                        if !states_d && d.is_some_and(|d| d != tool) {
                            self.note(
                                Code::PostUnwritable,
                                canon,
                                "comp-offset",
                                format!(
                                    "cutter compensation by offset D{} while tool T{tool} is in the spindle: the target's `{ev}` takes the tool's own radius",
                                    self.comp_d
                                ),
                            );
                        }
                        ev
                    }
                    None => "comp-off",
                };
                if !self.event(ev, &mut vals) {
                    self.note(Code::PostUnwritable, canon, ev, format!("the target's output rules have no `{ev}` template"));
                }
            }
            // Not a compensation op: [`Post::other_op`] hands none here.
            _ => {}
        }
    }
}

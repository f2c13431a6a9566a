//! The tool: selecting it (the T word), changing it (M6, M61), its length offsets (G43,
//! G43.1, G44, G49), and the tool data a program sets (`G10 L1`, `L10`–`L13`), over the
//! profile's tool table.
//!
//! Doors: [`Interpreter::tool_select`], [`Interpreter::tool_change`],
//! [`Interpreter::tool_set`], [`Interpreter::length_comp`], [`Interpreter::set_tool_data`],
//! and [`Interpreter::tool_diameter`] for what reads a tool's size.

use crate::canon::{CanonOp, CanonSink, DistanceMode, Setting};
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, DataForm, Meaning, Role};
use crate::interp::{Interpreter, Spindle, rotate};
use crate::syntax::Block;
use crate::text::TextRange;

/// The tool axis's bit in the known-position mask (`CanonOp::Known`): Z.
const TOOL_AXIS: u8 = 1 << 2;

impl Interpreter<'_> {
    /// The tool-select step: the block's T word, when it is a tool number.
    pub(super) fn tool_select(&mut self, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        if let Some(t) = self.slot(Role::T) {
            // Where the dictionary says so (Mazak), the fraction is the tool's ID code.
            let id_suffix = self.dialect.addresses.iter().any(|a| a.role == Role::T && a.id_suffix);
            let t = if id_suffix && t >= 0.0 { t.trunc() } else { t };
            // Where the dictionary says so (Fagor `T2.2`), the digits after the point name the
            // offset: the tool is selected with that offset. The word's text decides, not its
            // value: `T2.0` and `T2.` are tool 2 (the value has no fraction, yet the point is
            // there). A word without a point goes on to `tool_word`, split into tool and offset
            // only where the dictionary also gives `offset-digits` (Fagor's has none: `T2` is
            // tool 2 with the offset its table associates, never tool 0 offset 2). `T2.0` names
            // offset 0, no offset applied (as the 8055's `D0` applies none: programming manual,
            // "Tool number (T) and tool offset (D)"); `T2.` names no offset, so the tool's own
            // is taken (as the 8055's `T3` alone takes "the offset associated with that tool",
            // the same section).
            let offset_suffix = self.dialect.addresses.iter().any(|a| a.role == Role::T && a.offset_suffix);
            if offset_suffix && t >= 0.0 {
                let range = self.slots[Role::T as usize].map_or(block.range, |s| s.range);
                if let Some((tool, offset)) = suffix_offset(block.text(range)) {
                    self.tool_word_with(tool, offset, sink);
                    return;
                }
            }
            if t < 0.0 || t.fract() != 0.0 {
                diags.push(Diagnostic::new(
                    Code::MalformedNumber,
                    self.slots[Role::T as usize].map_or(block.range, |s| s.range),
                    "a tool number must be a whole number of zero or more",
                ));
            } else {
                self.tool_word(t, sink);
            }
        }
    }

    /// A T word: selects the tool. Where the dictionary splits the word (`T0202`), its last
    /// digits name the offset; where the T word changes the tool (a turret), the change and
    /// the offset take effect at once, the program position kept as after a tool change.
    fn tool_word(&mut self, t: f64, sink: &mut dyn CanonSink) {
        let digits = self.dialect.addresses.iter().find(|a| a.role == Role::T).and_then(|a| a.offset_digits);
        // A block that gives the offset in a word of its own (`T01H01`, `T01D01H01`, as NX
        // posts write Mitsubishi and Okuma lathes) leaves the T word the tool alone.
        let own_offset = self.slot(Role::H).or_else(|| self.slot(Role::D)).filter(|v| *v >= 0.0 && v.fract() == 0.0);
        let (tool, offset) = match digits {
            Some(_) if own_offset.is_some() => (t.min(f64::from(u32::MAX)) as u32, own_offset.map(|h| h as u32)),
            Some(d) => {
                let base = 10u32.pow(u32::from(d));
                let t = t as u64;
                ((t / u64::from(base)).min(u64::from(u32::MAX)) as u32, Some((t % u64::from(base)) as u32))
            }
            None => (t.min(f64::from(u32::MAX)) as u32, None),
        };
        self.tool_word_with(tool, offset, sink);
    }

    /// The tool `tool` selected, with the offset its word names, if any.
    fn tool_word_with(&mut self, tool: u32, offset: Option<u32>, sink: &mut dyn CanonSink) {
        self.st.selected_tool = tool;
        self.st.tool_commanded = true;
        self.emit(sink, CanonOp::SelectTool(tool));
        let name = tool.checked_sub(10_001).and_then(|k| self.tool_names.get(k as usize)).cloned();
        let named = name.is_some();
        if let Some(name) = name {
            self.emit(sink, CanonOp::Setting(Setting::ToolName(tool, name)));
        }
        // A tool called by name in diameter mode (Sinumerik `T="ROUGH_80"` after DIAMON) is
        // a turret's: on turning machines the T command changes the tool (840D, tool change
        // mode 0), with no M6.
        self.tool_words.0 += 1;
        let turret = self.dialect.behaviour.tool_word_changes || self.profile.tool_word_changes || (named && self.st.diameter);
        if !turret {
            return;
        }
        if tool != self.st.tool {
            self.st.tool = tool;
            self.forget(TOOL_AXIS, sink);
            self.emit(sink, CanonOp::ChangeTool(tool));
        }
        let offsets = match offset {
            Some(0) => [0.0; 3],
            Some(n) => self.tool_offsets(n),
            None => self.tool_offsets(tool),
        };
        if offsets != self.st.tool_offset {
            self.st.tool_offset = offsets;
            self.forget(TOOL_AXIS, sink);
            self.emit(sink, CanonOp::UseToolLengthOffset(offsets));
        }
    }

    /// M6: the selected tool goes into the spindle.
    pub(super) fn tool_change(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        // A tool call whose keyword names no tool (`TOOL CALL Z S2000`) changes only what
        // else its block says (the speed): no tool change.
        if def.keyword.as_ref().is_some_and(|k| k.value_role == Some(Role::T)) && self.slot(Role::T).is_none() {
            return;
        }
        self.tool_words.1 = true;
        if self.dialect.behaviour.tool_change_stops_spindle {
            self.emit(sink, CanonOp::StopSpindleTurning);
            self.st.spindle = Spindle::Stopped;
            self.st.spindle_unknown = false;
        }
        self.st.tool = self.st.selected_tool;
        self.st.tool_commanded = true;
        // Most machines move Z to the change position: where it is after is the control's.
        self.forget(TOOL_AXIS, sink);
        self.emit(sink, CanonOp::ChangeTool(self.st.tool));
        if let Some(next) = self.slot(Role::NextTool).filter(|t| *t >= 0.0 && t.fract() == 0.0) {
            self.st.selected_tool = next as u32;
            self.emit(sink, CanonOp::SelectTool(next as u32));
        }
        if self.dialect.behaviour.tool_change_applies_length {
            // A tool change that applies the length (Siemens D, Heidenhain TOOL CALL)
            // keeps the program position: such programs place Z after the call.
            self.st.tool_offset = self.tool_offsets(self.st.tool);
            self.forget(TOOL_AXIS, sink);
            self.emit(sink, CanonOp::UseToolLengthOffset(self.st.tool_offset));
        }
    }

    /// `M61 Q3`: the machine is told the spindle holds tool 3.
    pub(super) fn tool_set(&mut self, def: &CodeDef, range: TextRange, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        // Nothing moves. The interpreter goes on reading the tool the last change loaded
        // (#5400, the length G43 takes), as rs274 reads it back after CHANGE_TOOL_NUMBER.
        match self.slot(Role::Q) {
            Some(q) if q >= 0.0 && q.fract() == 0.0 && q < f64::from(u32::MAX) => {
                self.emit(sink, CanonOp::ChangeToolNumber(q as u32));
            }
            _ => diags.push(Diagnostic::new(Code::BadValue, range, format!("{}: Q must be a tool number", def.label()))),
        }
    }

    /// G43, G44 (the length of tool H, or of the tool in the spindle), G43.1 (the offsets
    /// the block gives), G49 (none).
    pub(super) fn length_comp(&mut self, def: &CodeDef, sink: &mut dyn CanonSink) {
        match def.meaning {
            Meaning::LengthCompDynamic => {
                // G43.1: the offsets are the axis words themselves, in program units.
                let offsets = [Role::X, Role::Y, Role::Z].map(|r| self.slot(r).unwrap_or(0.0));
                self.use_tool_offset(offsets, sink);
            }
            Meaning::LengthCompCancel => {
                self.emit(sink, CanonOp::Setting(Setting::LengthOffset(0)));
                self.use_tool_offset([0.0; 3], sink);
            }
            _ => {
                let h = match self.slot(Role::H) {
                    Some(h) if h != 0.0 || !self.dialect.behaviour.h0_spindle_tool => h as u32,
                    _ => self.st.tool,
                };
                self.emit(sink, CanonOp::Setting(Setting::LengthOffset(h)));
                let mut offsets = self.tool_offsets(h);
                if def.meaning == Meaning::LengthCompMinus {
                    offsets = offsets.map(|v| -v);
                }
                self.use_tool_offset(offsets, sink);
            }
        }
    }

    /// Puts tool offsets (program units) in force. The controlled point stays where it is, so
    /// its program coordinates change by the difference, as rs274's do.
    fn use_tool_offset(&mut self, offsets: [f64; 3], sink: &mut dyn CanonSink) {
        // The offsets are along the machine's axes; a rotated system sees X and Y turned.
        let mut delta: [f64; 3] = std::array::from_fn(|i| offsets[i] - self.st.tool_offset[i]);
        let rotation = self.st.rotation(self.st.wcs);
        if rotation != 0.0 {
            [delta[0], delta[1]] = rotate([delta[0], delta[1]], -rotation);
        }
        for (p, d) in self.st.pos.iter_mut().zip(delta) {
            *p -= d;
        }
        self.st.tool_offset = offsets;
        // The length is the control's (its table): the tool tip's Z is unknown until stated.
        self.forget(TOOL_AXIS, sink);
        self.emit(sink, CanonOp::UseToolLengthOffset(offsets));
    }

    /// Tool `n`'s offsets along X, Y and Z in program units: X and Y as the program set them
    /// (G10 L1/L10/L11), Z its length.
    fn tool_offsets(&self, n: u32) -> [f64; 3] {
        let xy = self.tool_edits.get(&n).map_or([None; 2], |e| e.xy);
        let mm = self.st.units.to_mm();
        [xy[0].unwrap_or(0.0) / mm, xy[1].unwrap_or(0.0) / mm, self.tool_length(n) / mm]
    }

    /// Tool `n`'s length offset in millimetres: the profile's, as the program changed it.
    fn tool_length(&self, n: u32) -> f64 {
        let edit = self.tool_edits.get(&n);
        edit.and_then(|e| e.length).unwrap_or_else(|| self.profile.tools.get(&n).map_or(0.0, |t| t.length))
            + edit.map_or(0.0, |e| e.length_wear)
    }

    /// Tool `n`'s diameter in millimetres, if known: the profile's, as the program changed it.
    pub(in crate::interp) fn tool_diameter(&self, n: u32) -> Option<f64> {
        let edit = self.tool_edits.get(&n);
        let geometry = edit.and_then(|e| e.radius).map(|r| 2.0 * r).or_else(|| self.profile.tools.get(&n).and_then(|t| t.diameter));
        geometry.map(|d| d + 2.0 * edit.map_or(0.0, |e| e.radius_wear))
    }

    /// `G10 L1/L10/L11` (LinuxCNC) and `G10 L10–L13` (Fanuc): tool P's length or radius.
    pub(super) fn set_tool_data(&mut self, def: &CodeDef, form: DataForm, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let Some(p) = self.slot(Role::P).filter(|p| *p >= 0.0 && p.fract() == 0.0 && *p < 1e6) else {
            if self.word_unknown(Role::P) {
                // `G10 L10 P#20`: the caller's tool number; the word was left out and said so.
                return;
            }
            diags.push(Diagnostic::new(Code::MissingParameter, range, format!("{} needs P, a tool or offset number", def.label())));
            return;
        };
        let n = p as u32;
        let mm = self.st.units.to_mm();
        if matches!(form, DataForm::Tool | DataForm::ToolHere | DataForm::ToolHereFixture)
            && [Role::A, Role::B, Role::C].iter().any(|&r| self.slots[r as usize].is_some())
        {
            let msg = format!("{}: tool offsets along rotary axes are not kept; only X, Y, Z and R are", def.label());
            self.limited(diags, "tool-offset-axes", Diagnostic::new(Code::Unsupported, range, msg));
        }
        // Fanuc: in G91 the value is added to the offset.
        let incremental = self.st.distance == DistanceMode::Incremental;
        let current = (self.tool_length(n), self.tool_diameter(n).map(|d| d / 2.0));
        let given = [Role::X, Role::Y, Role::Z].map(|r| self.slots[r as usize].map(|s| s.value));
        // For L10/L11: offsets that make the spindle's point read the given coordinates, in the
        // active system with G92 (L10) or in G59.3 without it (L11). They are worked out in
        // that system's (perhaps rotated) axes, an axis not given keeping the tool's offset,
        // and turned back to the machine's axes, as rs274 does.
        let here = {
            let (w, g92) = if form == DataForm::ToolHereFixture { (9, false) } else { (self.st.wcs, true) };
            let rotation = self.st.rotation(w);
            let machine = self.machine_pos();
            let spindle: [f64; 6] = std::array::from_fn(|i| machine[i] + if i < 3 { self.st.tool_offset[i] } else { 0.0 });
            let q = self.machine_to_system(spindle, w, g92);
            let stored = self.tool_offsets(n);
            let [sx, sy] = rotate([stored[0], stored[1]], -rotation);
            let xy = rotate([given[0].map_or(sx, |v| q[0] - v), given[1].map_or(sy, |v| q[1] - v)], rotation);
            [xy[0], xy[1], given[2].map_or(stored[2], |z| q[2] - z)]
        };
        let xy_given = given[0].is_some() || given[1].is_some();
        let edit = self.tool_edits.entry(n).or_default();
        let value = |v: f64, old: f64| if incremental { old + v * mm } else { v * mm };
        match form {
            DataForm::Tool => {
                for (slot, v) in edit.xy.iter_mut().zip(given) {
                    if let Some(v) = v {
                        *slot = Some(v * mm);
                    }
                }
                if let Some(z) = given[2] {
                    (edit.length, edit.length_wear) = (Some(z * mm), 0.0);
                }
                if let Some(r) = self.slots[Role::R as usize].map(|s| s.value) {
                    (edit.radius, edit.radius_wear) = (Some(r * mm), 0.0);
                }
            }
            DataForm::ToolHere | DataForm::ToolHereFixture => {
                if xy_given {
                    edit.xy = [Some(here[0] * mm), Some(here[1] * mm)];
                }
                if given[2].is_some() {
                    (edit.length, edit.length_wear) = (Some(here[2] * mm), 0.0);
                }
                if let Some(r) = self.slots[Role::R as usize].map(|s| s.value) {
                    (edit.radius, edit.radius_wear) = (Some(r * mm), 0.0);
                }
            }
            DataForm::ToolLength | DataForm::ToolLengthWear | DataForm::ToolRadius | DataForm::ToolRadiusWear => {
                let Some(r) = self.slots[Role::R as usize].map(|s| s.value) else {
                    diags.push(Diagnostic::new(Code::MissingParameter, range, format!("{} needs R, the offset value", def.label())));
                    return;
                };
                match form {
                    DataForm::ToolLength => edit.length = Some(value(r, current.0 - edit.length_wear)),
                    DataForm::ToolLengthWear => edit.length_wear = value(r, edit.length_wear),
                    DataForm::ToolRadius => edit.radius = Some(value(r, current.1.unwrap_or(0.0) - edit.radius_wear)),
                    _ => edit.radius_wear = value(r, edit.radius_wear),
                }
            }
            DataForm::Wcs | DataForm::WcsHere | DataForm::WcsExtended => {}
        }
    }
}

/// A tool word written as a number with a point (`T2.2`, `T2.0`, `T2.`), as the dictionary's
/// `offset-suffix` reads it: the tool before the point and the offset its digits after the
/// point name (none where none are written). Not such a number (`T0202`, `TP100`, a
/// bracketed expression): none.
fn suffix_offset(text: &str) -> Option<(u32, Option<u32>)> {
    let lit = text.trim().trim_start_matches(|c: char| c.is_ascii_alphabetic()).trim();
    let (tool, offset) = lit.split_once('.')?;
    if tool.is_empty() || !tool.bytes().all(|b| b.is_ascii_digit()) || !offset.bytes().all(|b| b.is_ascii_digit()) {
        return None;
    }
    let tool = tool.parse::<u64>().ok()?.min(u64::from(u32::MAX)) as u32;
    let offset = if offset.is_empty() { None } else { Some(offset.parse::<u64>().ok()?.min(u64::from(u32::MAX)) as u32) };
    Some((tool, offset))
}

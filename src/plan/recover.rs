//! Segmentation of the canonical stream into workingsteps.
//!
//! A workingstep ends at a tool change, at a change of operation family (milling versus
//! hole making), and at a change of technology when the toolpath starts anew (after a
//! rapid). Rapids between cuts are kept back until the next cut decides where they belong.

use std::collections::BTreeMap;

use super::geom;
use super::model::*;
use crate::canon::{Canon, CanonOp, Plane, Units};
use crate::diag::{Code, Diagnostic};
use crate::interp::Profile;
use crate::text::TextRange;

const EPS: f64 = 1e-6;

/// Recovers the process plan from a canonical stream. `program` is the program's number or
/// name, when known.
pub fn recover(canon: &[Canon], profile: &Profile, program: Option<String>) -> (ProcessPlan, Vec<Diagnostic>) {
    let mut r = Recovery::new(profile);
    for c in canon {
        r.op(c);
    }
    r.close();
    let mut tools: Vec<Tool> = r.tools.into_values().collect();
    tools.sort_by_key(|t| t.number);
    let plan = ProcessPlan { program, units: r.first_units, tools, workingsteps: r.done };
    (plan, r.diags)
}

/// Reads a CAM tool comment such as `T1 D=18 ENDMILL` or `6MM FLAT END MILL`: returns the
/// diameter in the comment's numbers (mm) when one is stated.
pub fn parse_tool_comment(text: &str) -> Option<f64> {
    let up = text.to_ascii_uppercase();
    let number = |s: &str| -> Option<f64> {
        let s = s.trim_start_matches([' ', '=', ':']);
        let end = s.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(s.len());
        s[..end].parse::<f64>().ok().filter(|v| *v > 0.0 && *v < 1000.0)
    };
    for key in ["DIAMETER", "DIA", "Ø", "D="] {
        if let Some(i) = up.find(key) {
            if let Some(v) = number(&up[i + key.len()..]) {
                return Some(v);
            }
        }
    }
    // `D18` as a word of its own.
    for word in up.split(|c: char| c.is_whitespace() || c == ',') {
        if let Some(rest) = word.strip_prefix('D') {
            if let Some(v) = number(rest) {
                if rest.len() == rest.trim_end_matches(|c: char| c.is_ascii_alphabetic()).len() {
                    return Some(v);
                }
            }
        }
        if let Some(num) = word.strip_suffix("MM") {
            if let Some(v) = number(num) {
                return Some(v);
            }
        }
    }
    None
}

struct Builder {
    operation: Operation,
    tool: u32,
    technology: Technology,
    moves: Vec<Move>,
    holes: Vec<Hole>,
    source: TextRange,
    lines: (u32, u32),
}

struct Recovery<'p> {
    profile: &'p Profile,
    k: f64,
    first_units: Option<Units>,
    plane: Plane,
    pos: P3,
    tool: u32,
    feed: f64,
    speed: f64,
    spindle: SpindleDir,
    mist: bool,
    flood: bool,
    tools: BTreeMap<u32, Tool>,
    name_pending: bool,
    comments: Vec<(u32, String)>,
    in_cycle: Option<Operation>,
    current: Option<Builder>,
    pending: Vec<Move>,
    done: Vec<Workingstep>,
    diags: Vec<Diagnostic>,
}

impl<'p> Recovery<'p> {
    fn new(profile: &'p Profile) -> Recovery<'p> {
        Recovery {
            profile,
            k: 1.0,
            first_units: None,
            plane: Plane::Xy,
            pos: [0.0; 3],
            tool: 0,
            feed: 0.0,
            speed: 0.0,
            spindle: SpindleDir::Off,
            mist: false,
            flood: false,
            tools: BTreeMap::new(),
            name_pending: false,
            comments: Vec::new(),
            in_cycle: None,
            current: None,
            pending: Vec::new(),
            done: Vec::new(),
            diags: Vec::new(),
        }
    }

    fn technology(&self) -> Technology {
        let coolant = match (self.mist, self.flood) {
            (false, false) => Coolant::Off,
            (true, false) => Coolant::Mist,
            (false, true) => Coolant::Flood,
            (true, true) => Coolant::Both,
        };
        Technology { feed: self.feed, feeds: vec![self.feed], spindle_speed: self.speed, spindle: self.spindle, coolant }
    }

    fn mm(&self, v: f64) -> f64 {
        v * self.k
    }

    fn op(&mut self, c: &Canon) {
        match &c.op {
            CanonOp::UseLengthUnits(u) => {
                self.first_units.get_or_insert(*u);
                self.k = u.to_mm();
            }
            CanonOp::SelectPlane(p) => self.plane = *p,
            CanonOp::SetFeedRate(f) => self.feed = self.mm(*f),
            CanonOp::SetSpindleSpeed(s) => self.speed = *s,
            CanonOp::StartSpindleClockwise => self.spindle = SpindleDir::Cw,
            CanonOp::StartSpindleCounterclockwise => self.spindle = SpindleDir::Ccw,
            // A boring cycle's spindle stop is part of the cycle, not of the technology.
            CanonOp::StopSpindleTurning if self.in_cycle.is_none() => self.spindle = SpindleDir::Off,
            CanonOp::MistOn => self.mist = true,
            CanonOp::MistOff => self.mist = false,
            CanonOp::FloodOn => self.flood = true,
            CanonOp::FloodOff => self.flood = false,
            CanonOp::ChangeTool(t) => {
                self.close();
                self.tool = *t;
                let known = self.profile.tools.get(t);
                let entry = self.tools.entry(*t).or_insert_with(|| Tool {
                    number: *t,
                    name: known.and_then(|k| k.name.clone()),
                    diameter: known.and_then(|k| k.diameter),
                    source: if known.is_some() { ToolSource::Table } else { ToolSource::Unknown },
                });
                self.name_pending = entry.name.is_none();
                // A comment on the tool-change block or the one before names the tool.
                let near: Vec<String> = self.comments.iter().filter(|(l, _)| *l + 1 >= c.line).map(|(_, s)| s.clone()).collect();
                for s in near {
                    self.name_tool(&s);
                }
            }
            CanonOp::Comment(s) => {
                self.comments.push((c.line, s.trim().to_owned()));
                if self.comments.len() > 4 {
                    self.comments.remove(0);
                }
                if self.name_pending {
                    let s = s.trim().to_owned();
                    self.name_tool(&s);
                }
            }
            CanonOp::CycleBegin(intent) => self.in_cycle = Some(Operation::Hole(intent.kind)),
            CanonOp::CycleEnd => self.in_cycle = None,
            CanonOp::StraightTraverse(p) => {
                let to = [self.mm(p[0]), self.mm(p[1]), self.mm(p[2])];
                let mv = self.mv(MoveKind::Rapid, to, c.line);
                if self.in_cycle.is_some() {
                    self.cut(mv, c);
                } else {
                    self.pending.push(mv);
                }
            }
            CanonOp::StraightFeed(p) => {
                let to = [self.mm(p[0]), self.mm(p[1]), self.mm(p[2])];
                let mv = self.mv(MoveKind::Line, to, c.line);
                self.cut(mv, c);
            }
            CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, .. } => {
                let (a0, a1, n) = self.plane.axes();
                let mut to = [0.0; 3];
                to[a0] = self.mm(*first_end);
                to[a1] = self.mm(*second_end);
                to[n] = self.mm(*axis_end);
                let mut center = self.pos;
                center[a0] = self.mm(*first_axis);
                center[a1] = self.mm(*second_axis);
                let mut axis = [0.0; 3];
                axis[n] = 1.0;
                let mut mv = self.mv(MoveKind::Arc, to, c.line);
                mv.center = Some(center);
                mv.axis = Some(axis);
                mv.turns = Some(*rotation);
                self.cut(mv, c);
            }
            CanonOp::ProgramEnd | CanonOp::Finish => self.close(),
            _ => {}
        }
    }

    fn name_tool(&mut self, comment: &str) {
        if comment.is_empty() {
            return;
        }
        if let Some(t) = self.tools.get_mut(&self.tool)
            && t.name.is_none()
        {
            t.name = Some(comment.to_owned());
            if t.diameter.is_none() {
                t.diameter = parse_tool_comment(comment);
                if t.diameter.is_some() {
                    t.source = ToolSource::Comment;
                }
            }
            self.name_pending = false;
        }
    }

    fn mv(&mut self, kind: MoveKind, to: P3, line: u32) -> Move {
        let from = self.pos;
        self.pos = to;
        Move { kind, phase: Phase::Cut, from, to, center: None, axis: None, turns: None, line }
    }

    fn cut(&mut self, mv: Move, c: &Canon) {
        let operation = self.in_cycle.unwrap_or(Operation::Milling);
        let tech = self.technology();
        let restart = match &self.current {
            None => true,
            Some(b) => {
                let retracted = !self.pending.is_empty();
                b.tool != self.tool || !b.operation.same_family(operation) || (retracted && !same_tech(&b.technology, &tech))
            }
        };
        if restart {
            self.close_keeping_approach();
            if self.tools.is_empty() && self.tool == 0 {
                self.diags.push(Diagnostic::new(
                    Code::NoTool,
                    c.origin,
                    "cutting before any tool change; the workingstep is assigned to tool 0",
                ));
                self.tools.insert(0, Tool { number: 0, name: None, diameter: None, source: ToolSource::Unknown });
            }
            let mut moves: Vec<Move> = std::mem::take(&mut self.pending);
            for m in &mut moves {
                m.phase = Phase::Approach;
            }
            let first_line = moves.first().map_or(c.line, |m| m.line);
            self.current = Some(Builder {
                operation,
                tool: self.tool,
                technology: tech,
                moves,
                holes: Vec::new(),
                source: c.origin,
                lines: (first_line, c.line),
            });
        }
        let Some(b) = self.current.as_mut() else { return };
        for mut m in self.pending.drain(..) {
            m.phase = Phase::Connect;
            b.moves.push(m);
        }
        if mv.kind != MoveKind::Rapid && !b.technology.feeds.iter().any(|f| (f - self.feed).abs() < EPS) {
            b.technology.feeds.push(self.feed);
        }
        b.moves.push(mv);
        b.source = b.source.cover(c.origin);
        b.lines.1 = c.line;
        if matches!(operation, Operation::Hole(_)) && b.operation == Operation::Milling {
            b.operation = operation;
        }
    }

    /// Ends the current workingstep; pending rapids that only lift stay with it as retract,
    /// the rest are kept for the next workingstep's approach.
    fn close_keeping_approach(&mut self) {
        let lifts = self.pending.iter().take_while(|m| is_lift(m)).count();
        self.close_with(lifts);
    }

    /// Ends the current workingstep with every pending rapid as its retract.
    fn close(&mut self) {
        self.close_with(self.pending.len());
        self.pending.clear();
    }

    fn close_with(&mut self, retract: usize) {
        let Some(mut b) = self.current.take() else { return };
        for mut m in self.pending.drain(..retract) {
            m.phase = Phase::Retract;
            b.moves.push(m);
        }
        self.finish(b);
    }

    fn finish(&mut self, mut b: Builder) {
        refine_phases(&mut b.moves);
        let mut bbox = None;
        let mut depth: Option<f64> = None;
        let mut cutting_length = 0.0;
        let mut samples = Vec::new();
        for m in b.moves.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid) {
            cutting_length += geom::length(m);
            samples.clear();
            geom::extend(&mut bbox, m.from);
            geom::sample(m, &mut samples);
            for &pt in &samples {
                geom::extend(&mut bbox, pt);
                depth = Some(depth.map_or(pt[2], |d: f64| d.min(pt[2])));
            }
        }
        let start_point = b.moves.iter().find(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid).map(|m| m.from);
        if let Operation::Hole(_) = b.operation {
            b.holes = holes(&b.moves);
        } else {
            b.operation = classify(&b.moves);
        }
        let index = self.done.len() as u32 + 1;
        self.done.push(Workingstep {
            index,
            operation: b.operation,
            tool: b.tool,
            technology: b.technology,
            start_point,
            depth,
            bbox,
            cutting_length,
            holes: b.holes,
            toolpath: b.moves,
            source: b.source,
            lines: b.lines,
        });
    }
}

fn same_tech(a: &Technology, b: &Technology) -> bool {
    (a.feed - b.feed).abs() < EPS && (a.spindle_speed - b.spindle_speed).abs() < EPS && a.spindle == b.spindle && a.coolant == b.coolant
}

fn is_lift(m: &Move) -> bool {
    (m.to[0] - m.from[0]).abs() < EPS && (m.to[1] - m.from[1]).abs() < EPS && m.to[2] >= m.from[2]
}

fn is_plunge(m: &Move) -> bool {
    (m.to[0] - m.from[0]).abs() < EPS && (m.to[1] - m.from[1]).abs() < EPS && m.to[2] < m.from[2]
}

/// Leading plunges join the approach; trailing lifts join the retract.
fn refine_phases(moves: &mut [Move]) {
    let first_cut = moves.iter().position(|m| m.phase == Phase::Cut);
    if let Some(i) = first_cut {
        for m in moves[i..].iter_mut() {
            if m.phase == Phase::Cut && m.kind == MoveKind::Line && is_plunge(m) {
                m.phase = Phase::Approach;
            } else {
                break;
            }
        }
    }
    for m in moves.iter_mut().rev() {
        if m.phase == Phase::Retract || (m.phase == Phase::Cut && is_lift(m)) {
            m.phase = Phase::Retract;
        } else {
            break;
        }
    }
    // A workingstep that only plunges keeps its last plunge as its cut.
    if !moves.iter().any(|m| m.phase == Phase::Cut)
        && let Some(m) = moves.iter_mut().rev().find(|m| m.kind != MoveKind::Rapid)
    {
        m.phase = Phase::Cut;
    }
}

/// Hole positions: the bottom of each feed-in within a cycle.
fn holes(moves: &[Move]) -> Vec<Hole> {
    let mut out: Vec<Hole> = Vec::new();
    for m in moves.iter().filter(|m| m.kind == MoveKind::Line && is_plunge(m)) {
        match out.last_mut() {
            Some(h) if (h.x - m.to[0]).abs() < EPS && (h.y - m.to[1]).abs() < EPS => {
                if m.to[2] < h.bottom {
                    h.bottom = m.to[2];
                    let step = m.from[2] - m.to[2];
                    h.peck = Some(h.peck.map_or(step, |p| p.max(step)));
                }
            }
            _ => out.push(Hole { x: m.to[0], y: m.to[1], bottom: m.to[2], r_plane: m.from[2], peck: None }),
        }
    }
    out
}

/// Face milling: cutting at one Z in at least three parallel straight passes, alternating
/// in direction. Contour milling: any arcs. Otherwise plain milling.
fn classify(moves: &[Move]) -> Operation {
    let cuts: Vec<&Move> = moves.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid).collect();
    if cuts.iter().any(|m| m.kind == MoveKind::Arc) {
        return Operation::ContourMilling;
    }
    let Some(z) = cuts.first().map(|m| m.to[2]) else { return Operation::Milling };
    let flat = cuts.iter().all(|m| (m.from[2] - z).abs() < 1e-3 && (m.to[2] - z).abs() < 1e-3);
    let passes: Vec<(f64, f64)> =
        cuts.iter().map(|m| (m.to[0] - m.from[0], m.to[1] - m.from[1])).filter(|d| d.0.hypot(d.1) > 1e-3).collect();
    let longest = passes.iter().map(|d| d.0.hypot(d.1)).fold(0.0, f64::max);
    let long: Vec<(f64, f64)> = passes.into_iter().filter(|d| d.0.hypot(d.1) > 0.5 * longest).collect();
    let alternating = long.len() >= 3
        && long.windows(2).all(|w| {
            let (a, b) = (w[0], w[1]);
            let cross = a.0 * b.1 - a.1 * b.0;
            let dot = a.0 * b.0 + a.1 * b.1;
            cross.abs() < 1e-6 * a.0.hypot(a.1) * b.0.hypot(b.1) && dot < 0.0
        });
    if flat && alternating { Operation::FaceMilling } else { Operation::Milling }
}

#[cfg(test)]
mod tests {
    use super::parse_tool_comment;

    #[test]
    fn tool_comments() {
        assert_eq!(parse_tool_comment("T1 D=18 ENDMILL"), Some(18.0));
        assert_eq!(parse_tool_comment("6MM FLAT END MILL"), Some(6.0));
        assert_eq!(parse_tool_comment("T3 DIA 10.5 DRILL"), Some(10.5));
        assert_eq!(parse_tool_comment("DRILL D8"), Some(8.0));
        assert_eq!(parse_tool_comment("ROUGHING"), None);
    }
}

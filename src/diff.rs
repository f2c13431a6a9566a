//! Plan diff: align two plans' workingsteps by what they do and report typed changes.
//!
//! Alignment is a global sequence alignment (Needleman–Wunsch) whose score rewards the same
//! operation family, the same tool geometry and overlapping toolpaths. Tool numbers and
//! block numbers play no part, so a renamed tool or renumbered program still aligns.

use serde::{Deserialize, Serialize};

use crate::plan::{MoveKind, Phase, ProcessPlan, Workingstep, geom};

/// Kind of change.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChangeKind {
    /// Same operation, other tool number.
    ToolRenamed,
    /// The first cutting position moved.
    StartPointMoved,
    /// A cutting feed changed.
    FeedChanged,
    /// The spindle speed changed.
    SpindleSpeedChanged,
    /// The spindle direction changed.
    SpindleDirectionChanged,
    /// Coolant changed.
    CoolantChanged,
    /// The lowest cutting Z changed.
    DepthChanged,
    /// The cutting moves changed beyond start point and depth.
    ToolpathChanged,
    /// A workingstep exists only in the edited program.
    WorkingstepAdded,
    /// A workingstep exists only in the original.
    WorkingstepRemoved,
}

impl ChangeKind {
    /// snake_case name, as stored.
    pub fn as_str(self) -> &'static str {
        match self {
            ChangeKind::ToolRenamed => "tool_renamed",
            ChangeKind::StartPointMoved => "start_point_moved",
            ChangeKind::FeedChanged => "feed_changed",
            ChangeKind::SpindleSpeedChanged => "spindle_speed_changed",
            ChangeKind::SpindleDirectionChanged => "spindle_direction_changed",
            ChangeKind::CoolantChanged => "coolant_changed",
            ChangeKind::DepthChanged => "depth_changed",
            ChangeKind::ToolpathChanged => "toolpath_changed",
            ChangeKind::WorkingstepAdded => "workingstep_added",
            ChangeKind::WorkingstepRemoved => "workingstep_removed",
        }
    }
}

/// One semantic change.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Change {
    /// Kind.
    pub kind: ChangeKind,
    /// Workingstep index: the original's, or the edited plan's for an added one.
    pub workingstep: u32,
    /// The workingstep's operation label.
    pub operation: String,
    /// The changed field.
    pub field: String,
    /// Value in the original.
    pub before: String,
    /// Value in the edited program.
    pub after: String,
    /// 1-based line in the edited program, when the change is visible there.
    pub line: Option<u32>,
}

impl Change {
    /// The change as a planner reads it: `tool T1 renamed T8`.
    pub fn phrase(&self) -> String {
        match self.kind {
            ChangeKind::ToolRenamed => format!("tool {} renamed {}", self.before, self.after),
            ChangeKind::StartPointMoved => format!("start point moved from {} to {}", self.before, self.after),
            ChangeKind::WorkingstepAdded => format!("workingstep added ({})", self.after),
            ChangeKind::WorkingstepRemoved => format!("workingstep removed ({})", self.before),
            _ => format!("{} changed from {} to {}", self.field.replace('_', " "), self.before, self.after),
        }
    }
}

/// Geometric tolerance for positions, mm.
pub const TOLERANCE: f64 = 1e-4;

/// The changes from `original` to `edited`, in workingstep order.
pub fn diff(original: &ProcessPlan, edited: &ProcessPlan) -> Vec<Change> {
    let (a, b) = (&original.workingsteps, &edited.workingsteps);
    let pairs = align(original, edited);
    let mut out = Vec::new();
    for (i, j) in pairs {
        match (i, j) {
            (Some(i), Some(j)) => compare(&a[i], &b[j], &mut out),
            (Some(i), None) => out.push(Change {
                kind: ChangeKind::WorkingstepRemoved,
                workingstep: a[i].index,
                operation: a[i].operation.label().into(),
                field: "workingstep".into(),
                before: summary(&a[i]),
                after: String::new(),
                line: None,
            }),
            (None, Some(j)) => out.push(Change {
                kind: ChangeKind::WorkingstepAdded,
                workingstep: b[j].index,
                operation: b[j].operation.label().into(),
                field: "workingstep".into(),
                before: String::new(),
                after: summary(&b[j]),
                line: Some(b[j].lines.0),
            }),
            (None, None) => {}
        }
    }
    out
}

fn summary(ws: &Workingstep) -> String {
    format!("{} with {}, {} mm of cut", ws.operation.label(), tool_label(ws.tool), num(ws.cutting_length))
}

fn tool_label(t: u32) -> String {
    format!("T{t}")
}

fn tool_diameter(plan: &ProcessPlan, t: u32) -> Option<f64> {
    plan.tools.iter().find(|x| x.number == t).and_then(|x| x.diameter)
}

/// Similarity of two workingsteps in 0..=1; pairs below [`MATCH_THRESHOLD`] do not align.
fn similarity(pa: &ProcessPlan, a: &Workingstep, pb: &ProcessPlan, b: &Workingstep) -> f64 {
    if !a.operation.same_family(b.operation) {
        return 0.0;
    }
    let mut s = 0.2;
    if a.operation == b.operation {
        s += 0.1;
    }
    match (tool_diameter(pa, a.tool), tool_diameter(pb, b.tool)) {
        (Some(x), Some(y)) if (x - y).abs() > 1e-3 => s -= 0.3,
        (Some(_), Some(_)) => s += 0.1,
        _ => {}
    }
    let (la, lb) = (a.cutting_length, b.cutting_length);
    if la.max(lb) > 0.0 {
        s += 0.2 * la.min(lb) / la.max(lb);
    } else {
        s += 0.2;
    }
    s += 0.4
        * match (a.bbox, b.bbox) {
            (Some(x), Some(y)) => {
                let inter: f64 = (0..2).map(|i| (x.max[i].min(y.max[i]) - x.min[i].max(y.min[i])).max(0.0)).product();
                let area = |bb: crate::plan::BBox| (0..2).map(|i| (bb.max[i] - bb.min[i]).max(1e-3)).product::<f64>();
                let union = area(x) + area(y) - inter;
                if union > 0.0 { inter / union } else { 0.0 }
            }
            (None, None) => 1.0,
            _ => 0.0,
        };
    s.clamp(0.0, 1.0)
}

const MATCH_THRESHOLD: f64 = 0.35;

/// Global alignment maximising total similarity; deterministic tie-breaking prefers a match,
/// then a removal.
fn align(pa: &ProcessPlan, pb: &ProcessPlan) -> Vec<(Option<usize>, Option<usize>)> {
    let (a, b) = (&pa.workingsteps, &pb.workingsteps);
    let (n, m) = (a.len(), b.len());
    let sim: Vec<Vec<f64>> = a.iter().map(|x| b.iter().map(|y| similarity(pa, x, pb, y)).collect()).collect();
    let mut score = vec![vec![0.0f64; m + 1]; n + 1];
    for i in (0..n).rev() {
        for j in (0..m).rev() {
            let mut best = score[i + 1][j].max(score[i][j + 1]);
            if sim[i][j] >= MATCH_THRESHOLD {
                best = best.max(sim[i][j] + score[i + 1][j + 1]);
            }
            score[i][j] = best;
        }
    }
    let (mut i, mut j, mut out) = (0, 0, Vec::new());
    while i < n || j < m {
        if i < n && j < m && sim[i][j] >= MATCH_THRESHOLD && (score[i][j] - (sim[i][j] + score[i + 1][j + 1])).abs() < 1e-12 {
            out.push((Some(i), Some(j)));
            i += 1;
            j += 1;
        } else if i < n && (j == m || (score[i][j] - score[i + 1][j]).abs() < 1e-12) {
            out.push((Some(i), None));
            i += 1;
        } else {
            out.push((None, Some(j)));
            j += 1;
        }
    }
    out
}

/// A number as a planner writes it: at most four decimals, no trailing zeros.
pub fn num(v: f64) -> String {
    let s = format!("{:.4}", v);
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

fn point(p: [f64; 3], other: Option<[f64; 3]>) -> String {
    let mut s = format!("X{} Y{}", num(p[0]), num(p[1]));
    if other.is_none_or(|o| (o[2] - p[2]).abs() > TOLERANCE) {
        s.push_str(&format!(" Z{}", num(p[2])));
    }
    s
}

fn compare(a: &Workingstep, b: &Workingstep, out: &mut Vec<Change>) {
    let mut push = |kind: ChangeKind, field: &str, before: String, after: String| {
        out.push(Change {
            kind,
            workingstep: a.index,
            operation: a.operation.label().into(),
            field: field.into(),
            before,
            after,
            line: Some(b.lines.0),
        });
    };
    if a.tool != b.tool {
        push(ChangeKind::ToolRenamed, "tool", tool_label(a.tool), tool_label(b.tool));
    }
    let depth_delta = match (a.depth, b.depth) {
        (Some(x), Some(y)) => y - x,
        _ => 0.0,
    };
    if let (Some(x), Some(y)) = (a.start_point, b.start_point)
        && geom::dist(x, y) > TOLERANCE
    {
        // A start point that only sinks with the depth is the depth change, reported below.
        let only_depth =
            (x[0] - y[0]).abs() <= TOLERANCE && (x[1] - y[1]).abs() <= TOLERANCE && (y[2] - x[2] - depth_delta).abs() <= TOLERANCE;
        if !only_depth {
            push(ChangeKind::StartPointMoved, "start_point", point(x, Some(y)), point(y, Some(x)));
        }
    }
    let (ta, tb) = (&a.technology, &b.technology);
    let feeds_differ = ta.feeds.len() != tb.feeds.len() || ta.feeds.iter().zip(&tb.feeds).any(|(x, y)| (x - y).abs() > TOLERANCE);
    if feeds_differ {
        let f = |v: &[f64]| v.iter().map(|x| format!("F{}", num(*x))).collect::<Vec<_>>().join(", ");
        push(ChangeKind::FeedChanged, "feed", f(&ta.feeds), f(&tb.feeds));
    }
    if (ta.spindle_speed - tb.spindle_speed).abs() > TOLERANCE {
        push(
            ChangeKind::SpindleSpeedChanged,
            "spindle_speed",
            format!("S{}", num(ta.spindle_speed)),
            format!("S{}", num(tb.spindle_speed)),
        );
    }
    if ta.surface_speed != tb.surface_speed {
        let v = |s: Option<f64>| s.map_or_else(|| "none".to_string(), |v| format!("{} m/min", num(v)));
        push(ChangeKind::SpindleSpeedChanged, "surface_speed", v(ta.surface_speed), v(tb.surface_speed));
    }
    if ta.spindle != tb.spindle {
        push(
            ChangeKind::SpindleDirectionChanged,
            "spindle_direction",
            format!("{:?}", ta.spindle).to_lowercase(),
            format!("{:?}", tb.spindle).to_lowercase(),
        );
    }
    if ta.coolant != tb.coolant {
        push(ChangeKind::CoolantChanged, "coolant", format!("{:?}", ta.coolant).to_lowercase(), format!("{:?}", tb.coolant).to_lowercase());
    }
    let depth_change = match (a.depth, b.depth) {
        (Some(x), Some(y)) if (x - y).abs() > TOLERANCE => Some((x, y)),
        _ => None,
    };
    if let Some((x, y)) = depth_change {
        push(ChangeKind::DepthChanged, "depth", format!("Z{}", num(x)), format!("Z{}", num(y)));
    }
    if let Some((before, after)) = toolpath_difference(a, b, depth_change) {
        push(ChangeKind::ToolpathChanged, "toolpath", before, after);
    }
}

/// What identifies a cutting move: kind, end point, arc centre and turns.
type CutKey = (MoveKind, [f64; 3], Option<[f64; 3]>, Option<i32>);

/// Compares the cutting moves after the start point; a depth change maps the old lowest Z
/// onto the new one first, so that it is not reported twice.
fn toolpath_difference(a: &Workingstep, b: &Workingstep, depth: Option<(f64, f64)>) -> Option<(String, String)> {
    let cuts = |w: &Workingstep| -> Vec<CutKey> {
        w.toolpath
            .iter()
            .filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid)
            .map(|m| (m.kind, m.to, m.center, m.turns))
            .collect()
    };
    let (ca, cb) = (cuts(a), cuts(b));
    let map_z = |z: f64| match depth {
        Some((old, new)) if (z - old).abs() <= TOLERANCE => new,
        _ => z,
    };
    let same_point = |p: [f64; 3], q: [f64; 3]| {
        (p[0] - q[0]).abs() <= TOLERANCE && (p[1] - q[1]).abs() <= TOLERANCE && (map_z(p[2]) - q[2]).abs() <= TOLERANCE
    };
    let differs = ca.len() != cb.len()
        || ca.iter().zip(&cb).any(|(x, y)| {
            x.0 != y.0
                || !same_point(x.1, y.1)
                || x.3 != y.3
                || match (x.2, y.2) {
                    (Some(p), Some(q)) => (p[0] - q[0]).abs() > TOLERANCE || (p[1] - q[1]).abs() > TOLERANCE,
                    (None, None) => false,
                    _ => true,
                }
        });
    differs.then(|| {
        let s = |c: usize, w: &Workingstep| format!("{c} cutting moves, {} mm", num(w.cutting_length));
        (s(ca.len(), a), s(cb.len(), b))
    })
}

/// Groups changes per workingstep as sentences:
/// `workingstep 1 (plane finish milling): tool T1 renamed T8; start point moved from X90 Y20 to X83 Y20`.
pub fn render_plain(changes: &[Change]) -> Vec<String> {
    let mut lines: Vec<String> = Vec::new();
    let mut i = 0;
    while i < changes.len() {
        let c = &changes[i];
        let mut j = i;
        let mut phrases = Vec::new();
        while j < changes.len()
            && changes[j].workingstep == c.workingstep
            && changes[j].operation == c.operation
            && (changes[j].kind == ChangeKind::WorkingstepAdded) == (c.kind == ChangeKind::WorkingstepAdded)
        {
            phrases.push(changes[j].phrase());
            j += 1;
        }
        lines.push(format!("workingstep {} ({}): {}", c.workingstep, c.operation, phrases.join("; ")));
        i = j;
    }
    lines
}

//! Feature recognition: the cutting moves of each workingstep become a 2½D feature with the
//! operation's strategy and depths; workingsteps that machine the same feature (roughing
//! then finishing, drilling then reaming) are merged into one feature with several
//! operations.
//!
//! The rules, in order, on the horizontal cutting moves of the deepest level:
//! - parallel straight passes → a planar face (or, when the stock is known and the passes
//!   do not cover it, a step along the one side they cross, or a pocket);
//! - several nested closed loops, or passes inside a closed loop → a closed pocket;
//! - one closed loop → a pocket wall or an outside profile, the side decided by the comp
//!   side a climb-milling cut implies with the spindle's direction;
//! - one open path winding a full turn or more → a spiral pocket;
//! - one open path → a slot as wide as the tool;
//! - anything else, or cutting that is not at constant levels → a toolpath feature.

use std::collections::{BTreeMap, BTreeSet};

use super::model::*;

const EPS: f64 = 1e-6;

/// Recognises features for every workingstep of `plan` and fills in the workingsteps'
/// strategy, depths and allowances.
pub fn recognise(plan: &mut ProcessPlan) {
    let mut features: Vec<(Feature, Vec<Region>)> = Vec::new();
    // The level a planar face left the top at, for the features machined after it.
    let mut faced: Option<f64> = None;
    for i in 0..plan.workingsteps.len() {
        let ws = &plan.workingsteps[i];
        let tool = plan.tool(ws.tool).cloned();
        // Holes along another axis than Z (cycles in G18/G19) are not recognised yet.
        let mut cand = if ws.operation.is_hole() && !ws.holes.is_empty() {
            hole(ws, tool.as_ref(), plan.workpiece.as_ref(), faced)
        } else {
            milling(ws, tool.as_ref(), plan.workpiece.as_ref(), faced)
        };
        // A shape with no segment is no shape: what was cut stays a toolpath.
        if cand.kind.contour().is_some_and(|c| c.segments.is_empty()) {
            cand.kind = FeatureKind::Toolpath;
        }
        if matches!(cand.kind, FeatureKind::PlanarFace { .. })
            && let Some(d) = ws.depth
        {
            faced = Some(faced.map_or(d, |f: f64| f.min(d)));
        }
        let ws = &mut plan.workingsteps[i];
        ws.operation = cand.operation;
        ws.strategy = cand.strategy.clone();
        ws.axial_depth = cand.axial_depth;
        ws.radial_depth = cand.radial_depth;
        let merge = features.iter().rposition(|(f, regions)| same_feature(f, regions.last(), &cand));
        let id = match merge {
            Some(k) => {
                let (f, regions) = &mut features[k];
                if let (Some(prev), Some(region)) = (regions.last(), &cand.region) {
                    // The earlier workingstep roughed what this one finishes.
                    let last = *f.workingsteps.last().expect("a feature has a workingstep") as usize - 1;
                    let rough = &mut plan.workingsteps[last];
                    if !rough.operation.is_hole() {
                        rough.operation = rough.operation.roughing();
                        // Roughing inside a pocket leaves a smaller region, around a profile a
                        // larger one: the allowance is half the difference either way.
                        let side = ((region.max[0] - region.min[0]) - (prev.max[0] - prev.min[0]))
                            .abs()
                            .max(((region.max[1] - region.min[1]) - (prev.max[1] - prev.min[1])).abs())
                            / 2.0;
                        let bottom = round6((prev.bottom - region.bottom).max(0.0));
                        // Each rough operation carries the allowances it has attributes for.
                        let (has_side, has_bottom) = match rough.operation {
                            Operation::PlaneRoughMilling => (false, true),
                            Operation::SideRoughMilling => (true, false),
                            _ => (true, true),
                        };
                        rough.allowance_side = has_side.then_some(round6(side));
                        rough.allowance_bottom = has_bottom.then_some(bottom);
                    }
                }
                merge_into(f, &cand, &plan.workingsteps[i]);
                if let Some(r) = cand.region {
                    regions.push(r);
                }
                f.id
            }
            None => {
                let ws = &plan.workingsteps[i];
                let id = features.len() as u32 + 1;
                let f = Feature {
                    id,
                    kind: cand.kind.clone(),
                    placement: cand.placement,
                    depth: cand.depth,
                    top_inferred: cand.top_inferred,
                    workingsteps: vec![ws.index],
                    source: ws.source,
                    lines: ws.lines,
                    sources: cand.sources,
                    centre_path: cand.centre_path,
                };
                features.push((f, cand.region.into_iter().collect()));
                id
            }
        };
        plan.workingsteps[i].feature = Some(id);
    }
    plan.features = features.into_iter().map(|(f, _)| f).collect();
    absorb_spot_drilling(plan);
}

/// A spot drill or countersink that marks holes made by other tools is part of those holes,
/// not a feature of its own: its workingsteps go to the first hole feature at its positions,
/// when the holes made later cover every position it marked.
fn absorb_spot_drilling(plan: &mut ProcessPlan) {
    let abs = |f: &Feature| -> Vec<P2> {
        match &f.kind {
            FeatureKind::RoundHole { positions, .. } => positions.iter().map(|p| [p[0] + f.placement[0], p[1] + f.placement[1]]).collect(),
            _ => Vec::new(),
        }
    };
    let marking = |f: &Feature| {
        matches!(f.kind, FeatureKind::RoundHole { diameter: None, .. })
            && f.workingsteps.iter().all(|i| {
                let ws = &plan.workingsteps[*i as usize - 1];
                ws.operation == Operation::CenterDrilling
                    || plan.tool(ws.tool).is_some_and(|t| matches!(t.kind, ToolKind::CenterDrill | ToolKind::Countersink))
            })
    };
    let is_mark: Vec<bool> = plan.features.iter().map(marking).collect();
    let mut gone: Vec<u32> = Vec::new();
    for k in 0..plan.features.len() {
        if !is_mark[k] {
            continue;
        }
        // Positions quantised to 1e-3 mm, for lookups in log time: patterns may be large.
        let key = |p: &P2| ((p[0] * 1e3).round() as i64, (p[1] * 1e3).round() as i64);
        let marks: BTreeSet<(i64, i64)> = abs(&plan.features[k]).iter().map(key).collect();
        let mut covered: BTreeSet<(i64, i64)> = BTreeSet::new();
        let mut later: Vec<usize> = Vec::new();
        for (j, f) in plan.features.iter().enumerate().skip(k + 1).filter(|(j, _)| !is_mark[*j]) {
            let here: Vec<(i64, i64)> = abs(f).iter().map(key).filter(|q| marks.contains(q)).collect();
            if !here.is_empty() {
                later.push(j);
                covered.extend(here);
            }
        }
        let covered = covered.len() == marks.len();
        let Some(&first) = later.first().filter(|_| covered) else { continue };
        let steps = std::mem::take(&mut plan.features[k].workingsteps);
        let target = plan.features[first].id;
        for i in &steps {
            plan.workingsteps[*i as usize - 1].feature = Some(target);
        }
        let f = &mut plan.features[first];
        f.workingsteps.extend(steps);
        f.workingsteps.sort_unstable();
        gone.push(plan.features[k].id);
    }
    if gone.is_empty() {
        return;
    }
    plan.features.retain(|f| !gone.contains(&f.id));
    let renumber: BTreeMap<u32, u32> = plan.features.iter().enumerate().map(|(i, f)| (f.id, i as u32 + 1)).collect();
    for f in &mut plan.features {
        f.id = renumber[&f.id];
        feature_source(f, &plan.workingsteps);
    }
    for ws in &mut plan.workingsteps {
        ws.feature = ws.feature.and_then(|id| renumber.get(&id).copied());
    }
}

/// The source range and lines of a feature: the cover of its workingsteps'.
pub fn feature_source(f: &mut Feature, workingsteps: &[Workingstep]) {
    let mut it = f.workingsteps.iter().filter_map(|i| workingsteps.get((*i as usize).checked_sub(1)?));
    if let Some(first) = it.next() {
        let (mut src, mut lines) = (first.source, first.lines);
        for w in it {
            src = src.cover(w.source);
            lines = (lines.0.min(w.lines.0), lines.1.max(w.lines.1));
        }
        f.source = src;
        f.lines = lines;
    }
}

fn merge_into(f: &mut Feature, cand: &Candidate, ws: &Workingstep) {
    f.workingsteps.push(ws.index);
    f.source = f.source.cover(ws.source);
    f.lines = (f.lines.0.min(ws.lines.0), f.lines.1.max(ws.lines.1));
    match (&mut f.kind, &cand.kind) {
        (FeatureKind::RoundHole { diameter, bottom, .. }, FeatureKind::RoundHole { diameter: d2, bottom: b2, .. }) => {
            *diameter = match (*diameter, *d2) {
                (Some(a), Some(b)) => Some(a.max(b)),
                (a, b) => a.or(b),
            };
            // The deepest operation leaves the bottom, unless the hole goes through.
            // The deepest point: a drill's tip lies below where its full diameter ends.
            let tip = |depth: f64, d: Option<f64>, b: HoleBottom| match (b, d) {
                (HoleBottom::Conical(a), Some(d)) if a > 0.0 && a < 180.0 => depth + d / 2.0 / (a.to_radians() / 2.0).tan(),
                _ => depth,
            };
            let deeper = tip(cand.depth, *d2, *b2) > tip(f.depth, *diameter, *bottom) + 1e-6;
            if *bottom != HoleBottom::Through && (deeper || *b2 == HoleBottom::Through) {
                *bottom = *b2;
                f.sources.point_angle = cand.sources.point_angle;
            }
            if d2.is_some() && f.sources.size == Source::Unknown {
                f.sources.size = cand.sources.size;
            }
            f.depth = f.depth.max(cand.depth);
        }
        _ => {
            // The finishing workingstep states the final shape; an inferred top does not
            // undo a higher one the roughing stated (its layers start higher).
            let bottom = cand.placement[2] - cand.depth;
            let keep_top = cand.top_inferred && f.placement[2] > cand.placement[2] && cand.depth > 0.0;
            let top = if keep_top { f.placement[2] } else { cand.placement[2] };
            f.kind = cand.kind.clone();
            f.placement = [cand.placement[0], cand.placement[1], top];
            f.depth = round6(top - bottom);
            f.top_inferred = cand.top_inferred && !keep_top || keep_top && f.top_inferred;
            f.sources = Sources { top: if keep_top { f.sources.top } else { cand.sources.top }, ..cand.sources };
            f.centre_path = cand.centre_path;
        }
    }
}

/// The swept region of a milling candidate, for matching rough and finish passes.
#[derive(Clone, Copy, Debug)]
struct Region {
    min: P2,
    max: P2,
    bottom: f64,
}

struct Candidate {
    kind: FeatureKind,
    placement: P3,
    depth: f64,
    top_inferred: bool,
    sources: Sources,
    centre_path: Option<(f64, f64)>,
    operation: Operation,
    strategy: Option<Strategy>,
    axial_depth: Option<f64>,
    radial_depth: Option<f64>,
    region: Option<Region>,
    /// Hole positions, absolute, for matching drilling and reaming of one pattern.
    holes: Vec<P2>,
}

fn same_feature(f: &Feature, region: Option<&Region>, c: &Candidate) -> bool {
    match (&f.kind, &c.kind) {
        (FeatureKind::RoundHole { positions, .. }, FeatureKind::RoundHole { .. }) => {
            let abs: Vec<P2> = positions.iter().map(|p| [p[0] + f.placement[0], p[1] + f.placement[1]]).collect();
            abs.len() == c.holes.len() && abs.iter().zip(&c.holes).all(|(a, b)| (a[0] - b[0]).abs() < 1e-3 && (a[1] - b[1]).abs() < 1e-3)
        }
        (FeatureKind::Toolpath, _) | (_, FeatureKind::Toolpath) => false,
        (a, b) if std::mem::discriminant(a) == std::mem::discriminant(b) => {
            let (Some(r), Some(s)) = (region, &c.region) else { return false };
            let ix = (r.max[0].min(s.max[0]) - r.min[0].max(s.min[0])).max(0.0);
            let iy = (r.max[1].min(s.max[1]) - r.min[1].max(s.min[1])).max(0.0);
            let area = |q: &Region| (q.max[0] - q.min[0]).max(EPS) * (q.max[1] - q.min[1]).max(EPS);
            ix * iy >= 0.7 * area(r).min(area(s)) && s.bottom <= r.bottom + 1e-3
        }
        _ => false,
    }
}

fn round6(v: f64) -> f64 {
    (v * 1e6).round() / 1e6 + 0.0
}

/// The top of a hole: the surface its cycle states (`RFP`, `Q203`), the faced level, the
/// stock's, or else the program zero where it lies between the bottom and the R level (posts
/// put the work zero on the part's top); the R level only as a last resort.
fn hole(ws: &Workingstep, tool: Option<&Tool>, stock: Option<&Stock>, faced: Option<f64>) -> Candidate {
    let first = ws.holes.first();
    let bottom_z = ws.holes.iter().map(|h| h.bottom).fold(f64::INFINITY, f64::min);
    let r_level = first.map_or(0.0, |h| h.r_plane);
    let stated = ws.holes.iter().find_map(|h| h.top);
    let (top, top_inferred, top_source) = match (stock, faced) {
        // The surface the cycle states (RFP, Q203) is the programmer's own word for the top.
        _ if stated.is_some() => (stated.unwrap_or_default(), false, Source::Program),
        (_, Some(f)) if f > bottom_z && stock.is_none_or(|s| f < s.max()[2]) => (f, false, Source::Cuts),
        (Some(s), _) => (s.max()[2], false, Source::Stock),
        _ if bottom_z < 0.0 && r_level >= 0.0 => (0.0, true, Source::Assumption),
        _ => (r_level, true, Source::Assumption),
    };
    let through = stock.is_some_and(|s| bottom_z <= s.origin[2] + 1e-6);
    let kind = tool.map_or(ToolKind::Unknown, |t| t.kind);
    // A spot drill or countersink marks the hole; its diameter is not the hole's.
    let diameter = tool.filter(|t| !matches!(t.kind, ToolKind::CenterDrill | ToolKind::Countersink)).and_then(|t| t.diameter);
    let pointed =
        matches!(kind, ToolKind::TwistDrill | ToolKind::CenterDrill) || kind == ToolKind::Unknown && ws.operation != Operation::Boring;
    let (bottom, point_angle) = if through {
        (HoleBottom::Through, None)
    } else if pointed {
        // The tool's own point angle, else the common one of its kind, said as assumed.
        let stated = tool.and_then(|t| t.point_angle.map(|a| (a, Source::of_tool_fact(t.source))));
        let (angle, source) = stated.unwrap_or((if kind == ToolKind::CenterDrill { 90.0 } else { 118.0 }, Source::Assumption));
        (HoleBottom::Conical(angle), Some(source))
    } else {
        (HoleBottom::Flat, None)
    };
    let tip_depth = if bottom_z.is_finite() { top - bottom_z } else { 0.0 };
    // A drawing dimensions a drilled hole to where its full diameter ends; the cone of the
    // point lies below that.
    let depth = match (bottom, diameter, stock) {
        // A through hole is as deep as the stock below its top.
        (HoleBottom::Through, _, Some(s)) => round6(top - s.origin[2]),
        (HoleBottom::Conical(angle), Some(d), _) if angle > 0.0 && angle < 180.0 => {
            round6((tip_depth - d / 2.0 / (angle.to_radians() / 2.0).tan()).max(0.0))
        }
        _ => tip_depth,
    };
    // A point that never goes in to its full diameter only marks the hole (spot drilling
    // with a drill): its diameter is not the hole's.
    let marks = matches!(bottom, HoleBottom::Conical(_)) && diameter.is_some() && depth <= 1e-6;
    let (diameter, depth) = if marks { (None, tip_depth) } else { (diameter, depth) };
    let origin = first.map_or([0.0, 0.0], |h| [h.x, h.y]);
    let positions = ws.holes.iter().map(|h| [h.x - origin[0], h.y - origin[1]]).collect();
    let size = if diameter.is_some() { Source::of_tool(tool) } else { Source::Unknown };
    Candidate {
        kind: FeatureKind::RoundHole { diameter, bottom, positions },
        placement: [origin[0], origin[1], top],
        depth,
        top_inferred,
        sources: Sources { size, top: top_source, point_angle },
        centre_path: None,
        operation: if marks { Operation::CenterDrilling } else { ws.operation },
        strategy: None,
        axial_depth: ws.holes.iter().filter_map(|h| h.peck).reduce(f64::max),
        radial_depth: None,
        region: None,
        holes: ws.holes.iter().map(|h| [h.x, h.y]).collect(),
    }
}

/// Holes a milling tool makes by feeding straight down and back (plunging with an end
/// mill, often with a dwell): as wide as the tool, flat where the tool cuts flat.
fn plunged_holes(ws: &Workingstep, tool: Option<&Tool>, stock: Option<&Stock>) -> Option<Candidate> {
    let d = tool.and_then(|t| t.diameter)?;
    let cuts = || ws.toolpath.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid);
    let vertical = |m: &Move| (m.from[0] - m.to[0]).abs() < 1e-4 && (m.from[1] - m.to[1]).abs() < 1e-4;
    if !cuts().all(|m| vertical(&m)) {
        return None;
    }
    let mut at: Vec<P2> = Vec::new();
    // Positions seen, quantised to 1e-3 mm: a plunge-roughing path may hold many.
    let mut seen: std::collections::BTreeSet<(i64, i64)> = std::collections::BTreeSet::new();
    let mut bottom = f64::INFINITY;
    for m in cuts().filter(|m| m.to[2] < m.from[2]) {
        bottom = bottom.min(m.to[2]);
        if seen.insert(((m.to[0] * 1e3).round() as i64, (m.to[1] * 1e3).round() as i64)) {
            at.push([m.to[0], m.to[1]]);
        }
    }
    let first = *at.first()?;
    let (top, top_inferred, top_source) = match stock {
        Some(s) => (s.max()[2], false, Source::Stock),
        None if bottom < 0.0 => (0.0, true, Source::Assumption),
        None => return None,
    };
    let kind = tool.map_or(ToolKind::Unknown, |t| t.kind);
    let bottom_kind = if stock.is_some_and(|s| bottom <= s.origin[2] + 1e-6) {
        HoleBottom::Through
    } else if matches!(kind, ToolKind::BallEndMill) {
        return None;
    } else {
        HoleBottom::Flat
    };
    Some(Candidate {
        kind: FeatureKind::RoundHole {
            diameter: Some(d),
            bottom: bottom_kind,
            positions: at.iter().map(|p| [p[0] - first[0], p[1] - first[1]]).collect(),
        },
        placement: [first[0], first[1], top],
        depth: round6(top - bottom),
        top_inferred,
        sources: Sources { size: Source::of_tool(tool), top: top_source, point_angle: None },
        centre_path: None,
        operation: Operation::Drilling,
        strategy: None,
        axial_depth: None,
        radial_depth: None,
        region: None,
        holes: at,
    })
}

/// A horizontal cutting move, projected to XY.
#[derive(Clone, Copy, Debug)]
struct Piece {
    from: P2,
    to: P2,
    arc: Option<(P2, bool)>,
}

impl Piece {
    fn len(&self) -> f64 {
        match self.arc {
            None => dist(self.from, self.to),
            Some((c, ccw)) => dist(self.from, c) * sweep(self.from, self.to, c, ccw).abs(),
        }
    }
    fn dir(&self) -> P2 {
        let d = [self.to[0] - self.from[0], self.to[1] - self.from[1]];
        let n = d[0].hypot(d[1]).max(EPS);
        [d[0] / n, d[1] / n]
    }
    /// Unit tangent at the start and at the end.
    fn tangents(&self) -> (P2, P2) {
        match self.arc {
            None => (self.dir(), self.dir()),
            Some((c, ccw)) => {
                let t = |p: P2| {
                    let r = [p[0] - c[0], p[1] - c[1]];
                    let n = r[0].hypot(r[1]).max(EPS);
                    if ccw { [-r[1] / n, r[0] / n] } else { [r[1] / n, -r[0] / n] }
                };
                (t(self.from), t(self.to))
            }
        }
    }
}

fn dist(a: P2, b: P2) -> f64 {
    (a[0] - b[0]).hypot(a[1] - b[1])
}

fn cross(a: P2, b: P2) -> f64 {
    a[0] * b[1] - a[1] * b[0]
}

/// Signed sweep of an arc in XY from `a` to `b` about `c`, radians; a closed arc is a full turn.
fn sweep(a: P2, b: P2, c: P2, ccw: bool) -> f64 {
    let u = [a[0] - c[0], a[1] - c[1]];
    let v = [b[0] - c[0], b[1] - c[1]];
    let mut t = cross(u, v).atan2(u[0] * v[0] + u[1] * v[1]);
    if ccw && t <= 1e-12 {
        t += std::f64::consts::TAU;
    }
    if !ccw && t >= -1e-12 {
        t -= std::f64::consts::TAU;
    }
    t
}

/// Signed area of a closed chain (positive counter-clockwise), arcs included.
fn signed_area(chain: &[Piece]) -> f64 {
    let mut a = 0.0;
    for p in chain {
        a += cross(p.from, p.to) / 2.0;
        if let Some((c, ccw)) = p.arc {
            // The circular segment between the chord and the arc.
            let r = dist(p.from, c);
            let t = sweep(p.from, p.to, c, ccw);
            a += r * r * (t - t.sin()) / 2.0;
        }
    }
    a
}

fn total_turning(chain: &[Piece]) -> f64 {
    let mut total = 0.0;
    for (i, p) in chain.iter().enumerate() {
        if let Some((c, ccw)) = p.arc {
            total += sweep(p.from, p.to, c, ccw);
        }
        if let Some(q) = chain.get(i + 1) {
            let (_, t0) = p.tangents();
            let (t1, _) = q.tangents();
            total += cross(t0, t1).atan2(t0[0] * t1[0] + t0[1] * t1[1]);
        }
    }
    total
}

fn bounds(chain: &[Piece]) -> (P2, P2) {
    let mut min = [f64::INFINITY; 2];
    let mut max = [f64::NEG_INFINITY; 2];
    let mut add = |p: P2| {
        for k in 0..2 {
            min[k] = min[k].min(p[k]);
            max[k] = max[k].max(p[k]);
        }
    };
    for p in chain {
        add(p.from);
        add(p.to);
        if let Some((c, ccw)) = p.arc {
            let r = dist(p.from, c);
            let a0 = (p.from[1] - c[1]).atan2(p.from[0] - c[0]);
            let t = sweep(p.from, p.to, c, ccw);
            for k in 1..=36 {
                let a = a0 + t * f64::from(k) / 36.0;
                add([c[0] + r * a.cos(), c[1] + r * a.sin()]);
            }
        }
    }
    (min, max)
}

fn milling(ws: &Workingstep, tool: Option<&Tool>, stock: Option<&Stock>, faced: Option<f64>) -> Candidate {
    // A toolpath feature; `top_inferred` is false only once the levels were analysed.
    let toolpath = |top_inferred: bool| Candidate {
        kind: FeatureKind::Toolpath,
        placement: [0.0, 0.0, ws.depth.unwrap_or(0.0)],
        depth: 0.0,
        top_inferred,
        sources: Sources::default(),
        centre_path: None,
        operation: Operation::FreeformMilling,
        strategy: Some(Strategy { kind: StrategyKind::Explicit, feed_direction: None, rotation: None, cutmode: None, overlap: None }),
        axial_depth: None,
        radial_depth: None,
        region: None,
        holes: Vec::new(),
    };
    // Passes over the toolpath rather than lists of moves: a toolpath may hold millions.
    let cuts = || ws.toolpath.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid);
    let horizontal = || cuts().filter(|m| (m.from[2] - m.to[2]).abs() < 1e-4);
    // Entries down into the material (plunges, ramps, helices) are not the shape cut.
    let total: f64 = cuts().filter(|m| m.to[2] >= m.from[2] - 1e-4).map(|m| super::geom::length(&m)).sum();
    let flat_len: f64 = horizontal().map(|m| super::geom::length(&m)).sum();
    let arcs_in_xy = horizontal().all(|m| m.axis().is_none_or(|a| a[2].abs() > 1.0 - 1e-9));
    if horizontal().next().is_none()
        && let Some(c) = plunged_holes(ws, tool, stock)
    {
        return c;
    }
    if horizontal().next().is_none() || flat_len < 0.8 * total || !arcs_in_xy {
        return toolpath(true);
    }
    let mut levels: Vec<f64> = Vec::new();
    for m in horizontal() {
        if !levels.iter().any(|z| (z - m.to[2]).abs() < 1e-3) {
            levels.push(m.to[2]);
            // More levels than a pocket has: a 3D surface; the list stops growing here.
            if levels.len() > 200 {
                break;
            }
        }
    }
    levels.sort_by(|a, b| b.total_cmp(a));
    if levels.len() > 200 {
        return toolpath(true);
    }
    let bottom = *levels.last().expect("one level at least");
    let step = levels.windows(2).map(|w| w[0] - w[1]).reduce(f64::max);
    let feed_start =
        ws.toolpath.iter().filter(|m| m.kind == MoveKind::Line && m.to[2] < m.from[2] - EPS).map(|m| m.from[2]).reduce(f64::max);
    // The faced level, the stock's top, the layers' (one step above the first), or the
    // program zero that posts put on the part's top.
    let faced = faced.filter(|f| *f > bottom + EPS && *f >= levels[0] - EPS && stock.is_none_or(|s| *f < s.max()[2]));
    let (top, top_inferred, top_source) = match (stock, step) {
        _ if faced.is_some() => (faced.unwrap_or(bottom), false, Source::Cuts),
        (Some(s), _) => (s.max()[2], false, Source::Stock),
        (None, Some(st)) => (levels[0] + st, true, Source::Cuts),
        (None, None) if bottom < -EPS => (0.0, true, Source::Assumption),
        (None, None) => (feed_start.map_or(bottom, |z| z.max(bottom)), true, Source::Assumption),
    };
    let axial_depth = step.or_else(|| stock.map(|_| top - bottom)).filter(|d| *d > EPS).map(round6);
    // Chains of contiguous horizontal moves at the bottom level.
    let mut chains: Vec<Vec<Piece>> = Vec::new();
    let mut prev_end: Option<P3> = None;
    for m in ws.toolpath.iter() {
        let at_bottom =
            m.phase == Phase::Cut && m.kind != MoveKind::Rapid && (m.from[2] - bottom).abs() < 1e-3 && (m.to[2] - bottom).abs() < 1e-3;
        if !at_bottom {
            prev_end = None;
            continue;
        }
        let arc = match (m.kind, m.center(), m.axis()) {
            (MoveKind::Arc, Some(c), Some(a)) => Some(([c[0], c[1]], (m.turns().unwrap_or(1) > 0) == (a[2] > 0.0))),
            _ => None,
        };
        let piece = Piece { from: [m.from[0], m.from[1]], to: [m.to[0], m.to[1]], arc };
        if piece.arc.is_none() && piece.len() < EPS {
            continue;
        }
        let joined = prev_end.is_some_and(|p| (p[0] - m.from[0]).abs() < 1e-4 && (p[1] - m.from[1]).abs() < 1e-4);
        if !joined {
            chains.push(Vec::new());
        }
        let Some(c) = chains.last_mut() else { continue };
        // An arc of several turns is its whole turns, then the rest: the same pieces as
        // when the turns are written one by one.
        let whole = if arc.is_some() { m.turns().map_or(0, |t| t.unsigned_abs().saturating_sub(1)) } else { 0 };
        for _ in 0..whole {
            c.push(Piece { to: piece.from, ..piece });
        }
        c.push(piece);
        prev_end = Some(m.to);
    }
    if chains.is_empty() {
        return toolpath(true);
    }
    let radius = tool.and_then(|t| t.diameter).map(|d| d / 2.0);
    // Under cutter compensation the interpreter offsets the path only by a radius the tool
    // table gives; otherwise the moves are the programmed contour itself.
    let contour_programmed = !ws.state.cutter_comp.is_empty() && tool.is_none_or(|t| t.source != ToolSource::Table);
    let r = if contour_programmed { 0.0 } else { radius.unwrap_or(0.0) };
    let spindle_ccw = ws.technology.spindle == SpindleDir::Ccw;
    let all: Vec<Piece> = chains.iter().flatten().copied().collect();
    let mut loops_owned: Vec<Vec<Piece>> = Vec::new();
    let mut rest: Vec<Piece> = Vec::new();
    // Under cutter compensation the control leaves and rejoins the contour where the lead-in
    // and lead-out meet it: the loop it cuts stops short of (or runs past) its own start.
    let gap = radius.map_or(2.0, |r| 2.0 * r);
    for c in &chains {
        let (l, r) = split_loops(&close_gap(c, gap));
        loops_owned.extend(l);
        rest.extend(r);
    }
    let bottom_len: f64 = all.iter().map(Piece::len).sum();
    let rest_len: f64 = rest.iter().map(Piece::len).sum();
    let region_of = |min: P2, max: P2| Region { min, max, bottom };
    let mut cand = Candidate {
        kind: FeatureKind::Toolpath,
        placement: [0.0, 0.0, top],
        depth: top - bottom,
        top_inferred,
        sources: Sources {
            size: if contour_programmed { Source::Program } else { Source::of_tool(tool) },
            top: top_source,
            point_angle: None,
        },
        centre_path: None,
        operation: Operation::FreeformMilling,
        strategy: None,
        axial_depth,
        radial_depth: None,
        region: None,
        holes: Vec::new(),
    };
    // Parallel straight passes, outside any closed loops.
    let longest = rest.iter().filter(|p| p.arc.is_none()).map(Piece::len).fold(0.0, f64::max);
    let passes: Vec<Piece> = rest.iter().copied().filter(|p| p.arc.is_none() && p.len() > 0.5 * longest).collect();
    let parallel = passes.len() >= 2
        && passes.iter().all(|p| cross(p.dir(), passes[0].dir()).abs() < 1e-6)
        && passes.iter().map(Piece::len).sum::<f64>() >= 0.6 * rest_len
        && rest_len >= 0.3 * bottom_len;
    let loops: Vec<&Vec<Piece>> = loops_owned.iter().collect();
    if parallel {
        // The face's frame runs along the passes, pointing to +X (or +Y).
        let d = passes[0].dir();
        let u = if d[0] > 1e-9 || d[0].abs() <= 1e-9 && d[1] > 0.0 { d } else { [-d[0], -d[1]] };
        let u = [u[0] + 0.0, u[1] + 0.0];
        let v = [-u[1], u[0]];
        let along = |p: P2| p[0] * u[0] + p[1] * u[1];
        let across = |p: P2| p[0] * v[0] + p[1] * v[1];
        let mut offsets: Vec<f64> = passes.iter().map(|p| across(p.from)).collect();
        offsets.sort_by(f64::total_cmp);
        offsets.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
        let stepover = offsets.windows(2).map(|w| w[1] - w[0]).reduce(f64::min);
        let alternating = passes.windows(2).all(|w| w[0].dir()[0] * w[1].dir()[0] + w[0].dir()[1] * w[1].dir()[1] < 0.0);
        let (mut amin, mut amax, mut cmin, mut cmax) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for p in &all {
            for q in [p.from, p.to] {
                amin = amin.min(along(q));
                amax = amax.max(along(q));
                cmin = cmin.min(across(q));
                cmax = cmax.max(across(q));
            }
        }
        let (amin, amax, cmin, cmax) = (amin - r, amax + r, cmin - r, cmax + r);
        let corner = [u[0] * amin + v[0] * cmin, u[1] * amin + v[1] * cmin];
        let (bmin, bmax) = bounds(&all);
        let swept = ([bmin[0] - r, bmin[1] - r], [bmax[0] + r, bmax[1] + r]);
        cand.region = Some(region_of(swept.0, swept.1));
        cand.radial_depth = stepover.map(round6);
        cand.strategy = Some(Strategy {
            kind: if alternating { StrategyKind::Bidirectional } else { StrategyKind::Unidirectional },
            feed_direction: Some([d[0] + 0.0, d[1] + 0.0, 0.0]),
            rotation: None,
            cutmode: None,
            overlap: match (stepover, radius) {
                (Some(s), Some(r)) if s < 2.0 * r => Some(round6(1.0 - s / (2.0 * r))),
                _ => None,
            },
        });
        let enclosing = loops.iter().find(|l| {
            let (lmin, lmax) = bounds(l);
            passes.iter().all(|p| {
                [p.from, p.to]
                    .iter()
                    .all(|q| q[0] >= lmin[0] - 1e-4 && q[0] <= lmax[0] + 1e-4 && q[1] >= lmin[1] - 1e-4 && q[1] <= lmax[1] + 1e-4)
            })
        });
        if let Some(outer) = enclosing {
            pocket(&mut cand, outer, r, stock);
            return cand;
        }
        let sides = stock.map(|s| crossed_sides(s, swept));
        let axis_aligned = u[0].abs() < 1e-9 || u[1].abs() < 1e-9;
        match (sides, stock) {
            (Some(n), _) if n.iter().all(|x| *x) || top - bottom < 1e-3 => {}
            (Some(n), Some(st)) if axis_aligned && step_side(n, u).is_some() => {
                make_step(&mut cand, st, swept, u, n, top);
                return cand;
            }
            (Some(_), Some(st)) => {
                // The pocket ends where the stock does: the passes run out past its side.
                open_pocket(&mut cand, clip_to_stock(swept, st).unwrap_or(swept));
                return cand;
            }
            _ => {}
        }
        cand.operation = Operation::PlaneFinishMilling;
        // Trimmed to the stock when it is known: the passes run over its edges.
        let (mut amin, mut amax, mut cmin, mut cmax) = (amin, amax, cmin, cmax);
        let mut corner = corner;
        if let Some(st) = stock {
            let (lo, hi) = (st.origin, st.max());
            let corners = [[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]];
            let (sa0, sa1) = corners.iter().map(|p| along(*p)).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
            let (sc0, sc1) = corners.iter().map(|p| across(*p)).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
            if amin.max(sa0) < amax.min(sa1) && cmin.max(sc0) < cmax.min(sc1) {
                (amin, amax, cmin, cmax) = (amin.max(sa0), amax.min(sa1), cmin.max(sc0), cmax.min(sc1));
                corner = [u[0] * amin + v[0] * cmin, u[1] * amin + v[1] * cmin];
            }
        }
        cand.placement = [corner[0], corner[1], bottom];
        // The depth follows from the stock or the layers (a single layer without stock: none).
        let known = stock.is_some() || step.is_some() || faced.is_some();
        cand.depth = if known { top - bottom } else { 0.0 };
        if known {
            cand.placement[2] = top;
        }
        cand.kind = FeatureKind::PlanarFace { direction: [u[0], u[1], 0.0], length: round6(amax - amin), width: round6(cmax - cmin) };
        return cand;
    }
    // Moves inside the largest loop clear what it encloses (a lead-in, the floor along a
    // ramp's line): they belong to a pocket.
    let largest = loops.iter().max_by(|a, b| signed_area(a).abs().total_cmp(&signed_area(b).abs()));
    let rest_inside = largest.is_some_and(|l| rest.iter().all(|p| [p.from, p.to].iter().all(|q| inside(l, *q) != Some(false))));
    if !loops.is_empty() && (rest_len < 0.3 * bottom_len || rest_inside) {
        let mut sorted: Vec<&Vec<Piece>> = loops.clone();
        sorted.sort_by(|a, b| signed_area(b).abs().total_cmp(&signed_area(a).abs()));
        // Every entry down into the material (a plunge, a ramp, a helix) says where the
        // material is: a tool cannot plunge into a boss. Entries on the loop say nothing, nor
        // do feed moves that end above the top. One entry inside is enough: the others may
        // serve another place the workingstep cuts.
        let entry_inside = |lp: &[Piece]| {
            let entries = ws.toolpath.iter().filter(|m| m.kind != MoveKind::Rapid && m.to[2] < m.from[2] - EPS && m.to[2] < top - EPS);
            let mut seen = None;
            for m in entries {
                let at = match (m.kind, m.center()) {
                    (MoveKind::Arc, Some(c)) => [c[0], c[1]],
                    _ => [m.to[0], m.to[1]],
                };
                match inside(lp, at) {
                    Some(true) => return Some(true),
                    Some(false) => seen = Some(false),
                    None => {}
                }
            }
            seen
        };
        let outer = sorted[0];
        // Nested loops entered from outside all of them run around a boss: the innermost is
        // its wall, the others roughed towards it.
        let around = sorted.len() >= 2 && entry_inside(outer) == Some(false);
        let area = signed_area(outer);
        let rotation = if area > 0.0 { Rotation::Ccw } else { Rotation::Cw };
        if sorted.len() >= 2 && !around {
            cand.strategy = Some(Strategy {
                kind: StrategyKind::ContourParallel,
                feed_direction: None,
                rotation: Some(rotation),
                cutmode: Some(cutmode(rotation, spindle_ccw, true)),
                overlap: None,
            });
            let (omin, _) = bounds(outer);
            let (imin, _) = bounds(sorted[1]);
            cand.radial_depth = Some(round6((imin[0] - omin[0]).max(imin[1] - omin[1])));
            pocket(&mut cand, outer, r, stock);
            return cand;
        }
        let outer = *sorted.last().expect("one loop at least");
        let area = signed_area(outer);
        let rotation = if area > 0.0 { Rotation::Ccw } else { Rotation::Cw };
        // One loop: where the material is decides pocket wall or profile — where the tool
        // entered (inside the loop or outside it), else the compensation side; the cut
        // direction (taken as climb milling) only as a last resort, and then the cut mode
        // is not stated.
        let by_entry = entry_inside(outer);
        let by_comp = ws.state.cutter_comp.first().map(|c| c.left == (rotation == Rotation::Ccw));
        // A wall the tool could not stand outside of (a loop tighter than the tool, as when
        // a bore is circle-milled) is a pocket's.
        let no_profile = {
            let b = offset(outer, if area > 0.0 { r } else { -r });
            b.is_empty() || signed_area(&b).abs() < EPS || (signed_area(&b) > 0.0) != (area > 0.0)
        };
        // A loop the tool cannot stand outside of overrules the rest.
        let evidence = no_profile.then_some(true).or(by_entry).or(by_comp);
        let tool_inside = evidence.unwrap_or((rotation == Rotation::Ccw) != spindle_ccw);
        cand.strategy = Some(Strategy {
            kind: StrategyKind::ContourParallel,
            feed_direction: None,
            rotation: Some(rotation),
            cutmode: evidence.map(|inside| cutmode(rotation, spindle_ccw, inside)),
            overlap: None,
        });
        if tool_inside {
            pocket(&mut cand, outer, r, stock);
            cand.operation = Operation::SideFinishMilling;
        } else {
            let boundary = offset(outer, if area > 0.0 { r } else { -r });
            let (bmin, bmax) = bounds(outer);
            cand.region = Some(region_of(bmin, bmax));
            cand.operation = Operation::SideFinishMilling;
            cand.placement = [0.0, 0.0, top];
            let (rectangle, corner_radius) = match rect_shape(&boundary) {
                _ if cand.sources.size == Source::Unknown => {
                    cand.centre_path = Some((round6(bmax[0] - bmin[0]), round6(bmax[1] - bmin[1])));
                    (None, None)
                }
                Some((min, max, corner)) => {
                    (Some((round6(max[0] - min[0]), round6(max[1] - min[1]))), (corner > 0.0).then_some(round6(corner)))
                }
                None => (None, None),
            };
            cand.kind = FeatureKind::OutsideProfile { boundary: to_contour(&boundary), rectangle, corner_radius };
        }
        return cand;
    }
    // Paths that come in from outside the stock across one of its sides, turn inside and
    // leave across the same side (a U, and the passes inside it) clear a pocket open there.
    if let (Some(st), Some(rad), true) = (stock, radius, loops.is_empty()) {
        let (lo, hi) = (st.origin, st.max());
        let outside = |p: P2| p[0] < lo[0] - EPS || p[0] > hi[0] + EPS || p[1] < lo[1] - EPS || p[1] > hi[1] + EPS;
        let side_of = |p: P2| [p[0] < lo[0] - EPS, p[0] > hi[0] + EPS, p[1] < lo[1] - EPS, p[1] > hi[1] + EPS].iter().position(|x| *x);
        let turning = |c: &Vec<Piece>| c.iter().any(|p| p.arc.is_some() || cross(p.dir(), c[0].dir()).abs() > 1e-6);
        let ends: Vec<Option<usize>> = chains.iter().flat_map(|c| [side_of(c[0].from), side_of(c[c.len() - 1].to)]).collect();
        let one_side = ends.first().copied().flatten().is_some() && ends.iter().all(|e| *e == ends[0]);
        let enters = chains.iter().all(|c| outside(c[0].from) && outside(c[c.len() - 1].to)) && chains.iter().any(turning);
        if one_side && enters {
            let (bmin, bmax) = bounds(&all);
            if let Some(wall) = clip_to_stock(([bmin[0] - rad, bmin[1] - rad], [bmax[0] + rad, bmax[1] + rad]), st) {
                open_pocket(&mut cand, wall);
                return cand;
            }
        }
    }
    if chains.len() == 1 && loops.is_empty() {
        let chain = &chains[0];
        let turning = total_turning(chain);
        let (bmin, bmax) = bounds(chain);
        if turning.abs() >= std::f64::consts::TAU - 1e-6 {
            // A spiral: the pocket is the box it sweeps.
            let rotation = if turning > 0.0 { Rotation::Ccw } else { Rotation::Cw };
            cand.strategy = Some(Strategy {
                kind: StrategyKind::ContourSpiral,
                feed_direction: None,
                rotation: Some(rotation),
                cutmode: Some(cutmode(rotation, spindle_ccw, true)),
                overlap: None,
            });
            let rect = rectangle(bmin, bmax);
            pocket(&mut cand, &rect, r, stock);
            return cand;
        }
        // One straight pass across the stock along its side: a step.
        let straight = chain.iter().all(|p| p.arc.is_none() && cross(p.dir(), chain[0].dir()).abs() < 1e-6);
        if let (Some(rad), Some(st), true) = (radius, stock, straight) {
            let u = chain[0].dir();
            let swept = ([bmin[0] - rad, bmin[1] - rad], [bmax[0] + rad, bmax[1] + rad]);
            let n = crossed_sides(st, swept);
            if (u[0].abs() < 1e-9 || u[1].abs() < 1e-9) && step_side(n, u).is_some() {
                make_step(&mut cand, st, swept, u, n, top);
                cand.region = Some(region_of(swept.0, swept.1));
                return cand;
            }
        }
        if let Some(rad) = radius {
            cand.operation = Operation::BottomAndSideFinishMilling;
            cand.strategy =
                Some(Strategy { kind: StrategyKind::CenterMilling, feed_direction: None, rotation: None, cutmode: None, overlap: None });
            cand.region = Some(region_of([bmin[0] - rad, bmin[1] - rad], [bmax[0] + rad, bmax[1] + rad]));
            let start = chain[0].from;
            cand.placement = [start[0], start[1], top];
            cand.kind = FeatureKind::Slot { path: relative(&to_contour(chain), cand.placement), width: round6(2.0 * rad) };
            return cand;
        }
    }
    toolpath(false)
}

/// Whether `p` lies inside the closed chain (by its vertices and arc midpoints); `None` on it.
fn inside(chain: &[Piece], p: P2) -> Option<bool> {
    let mut poly: Vec<P2> = Vec::new();
    for q in chain {
        poly.push(q.from);
        if let Some((c, ccw)) = q.arc {
            let r = dist(q.from, c);
            let a0 = (q.from[1] - c[1]).atan2(q.from[0] - c[0]);
            let t = sweep(q.from, q.to, c, ccw);
            for k in 1..8 {
                let a = a0 + t * f64::from(k) / 8.0;
                poly.push([c[0] + r * a.cos(), c[1] + r * a.sin()]);
            }
        }
    }
    let n = poly.len();
    let mut odd = false;
    for i in 0..n {
        let (a, b) = (poly[i], poly[(i + 1) % n]);
        // On the boundary: no evidence.
        let ab = [b[0] - a[0], b[1] - a[1]];
        let l2 = ab[0] * ab[0] + ab[1] * ab[1];
        let t = if l2 > 0.0 { (((p[0] - a[0]) * ab[0] + (p[1] - a[1]) * ab[1]) / l2).clamp(0.0, 1.0) } else { 0.0 };
        if dist(p, [a[0] + t * ab[0], a[1] + t * ab[1]]) < 1e-3 {
            return None;
        }
        if (a[1] > p[1]) != (b[1] > p[1]) && p[0] < a[0] + (p[1] - a[1]) / (b[1] - a[1]) * (b[0] - a[0]) {
            odd = !odd;
        }
    }
    Some(odd)
}

/// Joins straight pieces that continue one another, also across the loop's start.
fn join_collinear(chain: &[Piece]) -> Vec<Piece> {
    let along = |q: &Piece, p: &Piece| {
        q.arc.is_none()
            && p.arc.is_none()
            && cross(q.dir(), p.dir()).abs() < 1e-6
            && q.dir()[0] * p.dir()[0] + q.dir()[1] * p.dir()[1] > 0.0
    };
    let mut out: Vec<Piece> = Vec::new();
    for p in chain {
        match out.last_mut() {
            Some(q) if along(q, p) => q.to = p.to,
            _ => out.push(*p),
        }
    }
    if out.len() > 2 && along(&out[out.len() - 1], &out[0]) {
        let last = out.pop().expect("more than two pieces");
        out[0].from = last.from;
    }
    out
}

/// Climb or conventional from the loop's rotation, the spindle direction and which side of
/// the path the material is (inside the loop for a pocket).
fn cutmode(rotation: Rotation, spindle_ccw: bool, material_outside: bool) -> CutMode {
    // M3 with the material on the right of travel is climb milling.
    let material_right = (rotation == Rotation::Ccw) == material_outside;
    if material_right != spindle_ccw { CutMode::Climb } else { CutMode::Conventional }
}

/// For passes along `u` (X or Y), the side a step lies on: `Some(true)` for the high side
/// across the passes, `Some(false)` for the low side, when the band reaches both ends along
/// the passes and exactly one side across them.
fn step_side(n: [bool; 4], u: P2) -> Option<bool> {
    let (ends, sides) = if u[1].abs() < 1e-9 { ([n[0], n[1]], [n[2], n[3]]) } else { ([n[2], n[3]], [n[0], n[1]]) };
    match (ends, sides) {
        ([true, true], [false, true]) => Some(true),
        ([true, true], [true, false]) => Some(false),
        _ => None,
    }
}

/// The part of the box `min`..`max` inside the stock, in XY; none where they do not overlap.
fn clip_to_stock((min, max): (P2, P2), st: &Stock) -> Option<(P2, P2)> {
    let (lo, hi) = (st.origin, st.max());
    let min = [min[0].max(lo[0]), min[1].max(lo[1])];
    let max = [max[0].min(hi[0]), max[1].min(hi[1])];
    (min[0] < max[0] && min[1] < max[1]).then_some((min, max))
}

/// Makes `cand` a pocket open to the stock's side, its wall the box `min`..`max`.
fn open_pocket(cand: &mut Candidate, (min, max): (P2, P2)) {
    cand.region = Some(Region { min, max, bottom: cand.placement[2] - cand.depth });
    cand.operation = Operation::BottomAndSideFinishMilling;
    cand.placement = [min[0], min[1], cand.placement[2]];
    cand.kind = FeatureKind::OpenPocket { boundary: relative(&to_contour(&rectangle(min, max)), cand.placement) };
}

/// Makes `cand` a step: the band `swept` of passes along `u` runs from end to end of the
/// stock along the one side `n` says it crosses; its wall is the band's edge away from
/// that side.
fn make_step(cand: &mut Candidate, st: &Stock, swept: (P2, P2), u: P2, n: [bool; 4], top: f64) {
    let k = usize::from(u[0].abs() < 1e-9); // 0: passes along X, 1: along Y
    let across = 1 - k;
    let smax = st.max();
    let (lo, hi) = (st.origin[k], smax[k]);
    let high_side = step_side(n, u) == Some(true);
    let (wall, width) =
        if high_side { (swept.0[across], smax[across] - swept.0[across]) } else { (swept.1[across], swept.1[across] - st.origin[across]) };
    let mut start = [0.0; 2];
    start[k] = lo;
    start[across] = wall;
    let mut dir = [0.0; 3];
    dir[k] = 1.0;
    cand.operation = Operation::BottomAndSideFinishMilling;
    cand.placement = [start[0], start[1], top];
    cand.kind = FeatureKind::Step { direction: dir, length: round6(hi - lo), width: round6(width) };
}

/// A chain that comes back onto the line it left, short of its first point on that line or
/// past it by at most `gap`, closed there: the loop ends where it began. Chains that close
/// exactly, or that do not come back, are as they were.
fn close_gap(chain: &[Piece], gap: f64) -> Vec<Piece> {
    if chain.len() < 4 {
        return chain.to_vec();
    }
    let on_line = |a: &Piece, b: &Piece| {
        a.arc.is_none()
            && b.arc.is_none()
            && cross(a.dir(), b.dir()).abs() < 1e-6
            && a.dir()[0] * b.dir()[0] + a.dir()[1] * b.dir()[1] > 0.0
            && cross(a.dir(), [b.from[0] - a.from[0], b.from[1] - a.from[1]]).abs() < 1e-4
    };
    // The longest loop first: the last piece coming back onto the line of the earliest one.
    // Lead-ins and lead-outs lie near the chain's ends: the search stays there, bounded.
    const NEAR_END: usize = 64;
    for i in 0..chain.len().min(NEAR_END) {
        for j in (chain.len().saturating_sub(NEAR_END).max(i + 3)..chain.len()).rev() {
            let (a, b) = (chain[i], chain[j]);
            if !on_line(&a, &b) {
                continue;
            }
            let u = a.dir();
            let along = |p: P2| (p[0] - a.from[0]) * u[0] + (p[1] - a.from[1]) * u[1];
            let (end, b_start) = (along(b.to), along(b.from));
            // Short of the start (a gap before it) or past it (an overlap), within `gap`.
            if end < 0.0 && -end <= gap || end >= 0.0 && b_start <= 0.0 && end <= gap.max(a.len()) {
                let mut out = chain.to_vec();
                out[j].to = a.from;
                // A loop encloses something: passes to and fro along one line do not.
                if signed_area(&out[i..=j]).abs() > 1e-3 {
                    return out;
                }
            }
        }
    }
    chain.to_vec()
}

/// Splits a chain into the closed loops it traces (a point met again closes a loop) and the
/// pieces between them.
fn split_loops(chain: &[Piece]) -> (Vec<Vec<Piece>>, Vec<Piece>) {
    // Start points of the open pieces, quantised to 1e-4 mm, for a lookup in log time.
    let key = |p: P2| ((p[0] * 1e4).round() as i64, (p[1] * 1e4).round() as i64);
    let mut loops = Vec::new();
    let mut rest = Vec::new();
    let mut open: Vec<Piece> = Vec::new();
    let mut starts: BTreeMap<(i64, i64), usize> = BTreeMap::new();
    for p in chain {
        starts.entry(key(p.from)).or_insert(open.len());
        open.push(*p);
        if let Some(&k) = starts.get(&key(p.to)) {
            let lp: Vec<Piece> = open.drain(k..).collect();
            // A loop encloses something: a pass out and back along one line does not.
            if lp.iter().any(|p| p.arc.is_some()) || lp.len() >= 2 && signed_area(&lp).abs() > 1e-6 {
                loops.push(lp);
            } else {
                rest.extend(lp);
            }
            rest.append(&mut open);
            starts.clear();
        }
    }
    rest.extend(open);
    (loops, rest)
}

/// Which stock sides (−X, +X, −Y, +Y) a swept box reaches or crosses.
fn crossed_sides(s: &Stock, (min, max): (P2, P2)) -> [bool; 4] {
    let smax = s.max();
    [min[0] <= s.origin[0] + 1e-6, max[0] >= smax[0] - 1e-6, min[1] <= s.origin[1] + 1e-6, max[1] >= smax[1] - 1e-6]
}

/// Makes `cand` a pocket whose tool-centre outer loop is `outer`.
fn pocket(cand: &mut Candidate, outer: &[Piece], r: f64, stock: Option<&Stock>) {
    let area = signed_area(outer);
    let wall = offset(outer, if area > 0.0 { -r } else { r });
    let (bmin, bmax) = bounds(&wall);
    cand.region = Some(Region { min: bmin, max: bmax, bottom: cand.placement[2] - cand.depth });
    cand.operation = Operation::BottomAndSideFinishMilling;
    let open = stock.is_some_and(|s| crossed_sides(s, (bmin, bmax)).iter().any(|x| *x));
    if open {
        cand.placement = [bmin[0], bmin[1], cand.placement[2]];
        cand.kind = FeatureKind::OpenPocket { boundary: relative(&to_contour(&wall), cand.placement) };
        return;
    }
    // A wall of two parallel straight sides joined by two half circles is a slot's, as wide
    // as the circles and as long as its sides between their centres.
    if cand.sources.size != Source::Unknown
        && let Some((a, b, radius)) = stadium(&wall)
    {
        cand.placement = [a[0], a[1], cand.placement[2]];
        let path = Contour { start: [0.0, 0.0], segments: vec![Segment { to: [round6(b[0] - a[0]), round6(b[1] - a[1])], arc: None }] };
        cand.kind = FeatureKind::Slot { path, width: round6(2.0 * radius) };
        return;
    }
    let shape = rect_shape(outer);
    let (cmin, cmax) = bounds(outer);
    let size_unknown = cand.sources.size == Source::Unknown;
    if size_unknown {
        // The tool-centre path is not the pocket: its size stays unknown, the path's is said.
        cand.centre_path = Some((round6(cmax[0] - cmin[0]), round6(cmax[1] - cmin[1])));
    }
    if let Some((smin, smax, rounded)) = shape {
        let centre = [(smin[0] + smax[0]) / 2.0, (smin[1] + smax[1]) / 2.0];
        cand.placement = [centre[0], centre[1], cand.placement[2]];
        let (w, l) = (round6(smax[0] - smin[0] + 2.0 * r), round6(smax[1] - smin[1] + 2.0 * r));
        let corner = rounded + r;
        let corner_radius = (corner > 0.0).then_some(round6(corner));
        cand.kind = if size_unknown {
            FeatureKind::ClosedPocket { boundary: rect_contour(w, l, corner_radius), rectangle: None, corner_radius: None }
        } else {
            FeatureKind::ClosedPocket { boundary: rect_contour(w, l, corner_radius), rectangle: Some((w, l)), corner_radius }
        };
    } else {
        cand.placement = [bmin[0], bmin[1], cand.placement[2]];
        cand.kind =
            FeatureKind::ClosedPocket { boundary: relative(&to_contour(&wall), cand.placement), rectangle: None, corner_radius: None };
    }
}

/// Two parallel straight sides joined by two half circles of one radius: the circles'
/// centres and the radius.
fn stadium(chain: &[Piece]) -> Option<(P2, P2, f64)> {
    let joined = join_collinear(chain);
    if joined.len() != 4 {
        return None;
    }
    let first = joined.iter().position(|p| p.arc.is_some())?;
    let at = |k: usize| joined[(first + k) % 4];
    let (a0, l0, a1, l1) = (at(0), at(1), at(2), at(3));
    let ((c0, ccw0), (c1, ccw1)) = (a0.arc?, a1.arc?);
    let half = |p: &Piece, c: P2, ccw: bool| (sweep(p.from, p.to, c, ccw).abs() - std::f64::consts::PI).abs() < 1e-4;
    let r = dist(a0.from, c0);
    let lines = l0.arc.is_none() && l1.arc.is_none() && cross(l0.dir(), l1.dir()).abs() < 1e-6;
    (lines && half(&a0, c0, ccw0) && half(&a1, c1, ccw1) && (dist(a1.from, c1) - r).abs() < 1e-4 && dist(c0, c1) > 1e-4)
        .then(|| if c0[0] < c1[0] || c0[0] == c1[0] && c0[1] <= c1[1] { (c0, c1, r) } else { (c1, c0, r) })
}

/// An axis-aligned rectangle, with sharp corners or four quarter arcs of one radius: its
/// extent of straight edges (corner arcs included) and the corner radius (0 when sharp).
fn rect_shape(chain: &[Piece]) -> Option<(P2, P2, f64)> {
    let joined = join_collinear(chain);
    let axis_line = |p: &Piece| p.arc.is_none() && (p.dir()[0].abs() < 1e-9 || p.dir()[1].abs() < 1e-9);
    let sharp = joined.len() == 4 && joined.iter().all(axis_line);
    // Four axis-aligned edges joined by four quarter arcs of one radius.
    let arc_radius = |p: &Piece| p.arc.map(|(c, ccw)| (dist(p.from, c), sweep(p.from, p.to, c, ccw).abs()));
    let rounded = (joined.len() == 8)
        .then(|| {
            let first = joined.iter().position(|p| p.arc.is_some())?;
            let arcs: Vec<(f64, f64)> = joined.iter().filter_map(arc_radius).collect();
            let alternate = (0..8).all(|k| joined[(first + k) % 8].arc.is_some() == (k % 2 == 0));
            let same = arcs.len() == 4
                && arcs.iter().all(|(ra, t)| (ra - arcs[0].0).abs() < 1e-4 && (t - std::f64::consts::FRAC_PI_2).abs() < 1e-4);
            (alternate && same && joined.iter().filter(|p| p.arc.is_none()).all(axis_line)).then_some(arcs[0].0)
        })
        .flatten();
    if !sharp && rounded.is_none() {
        return None;
    }
    let (min, max) = bounds(&joined);
    Some((min, max, rounded.unwrap_or(0.0)))
}

/// The width and length of a contour that is an axis-aligned rectangle (see
/// [`rect_contour`]), and its corner radius when it has one.
pub fn rectangle_of(c: &Contour) -> Option<((f64, f64), Option<f64>)> {
    let mut from = c.start;
    let pieces: Vec<Piece> = c
        .segments
        .iter()
        .map(|s| {
            let p = Piece { from, to: s.to, arc: s.arc };
            from = s.to;
            p
        })
        .collect();
    let (min, max, corner) = rect_shape(&pieces)?;
    Some(((round6(max[0] - min[0]), round6(max[1] - min[1])), (corner > 0.0).then_some(round6(corner))))
}

/// The wall of a rectangular pocket `w` × `l` centred on its placement, with vertical corner
/// radius `r`: counter-clockwise from the middle of the bottom edge.
pub fn rect_contour(w: f64, l: f64, r: Option<f64>) -> Contour {
    let (hw, hl) = (w / 2.0, l / 2.0);
    let r = r.unwrap_or(0.0).clamp(0.0, hw.min(hl));
    let mut segments = Vec::new();
    let corners = [([hw, -hl], [-1.0, 1.0]), ([hw, hl], [-1.0, -1.0]), ([-hw, hl], [1.0, -1.0]), ([-hw, -hl], [1.0, 1.0])];
    for (k, (c, inward)) in corners.iter().enumerate() {
        // Along the edge towards corner k, then around it.
        let along: P2 = match k {
            0 => [c[0] - r, c[1]],
            1 => [c[0], c[1] - r],
            2 => [c[0] + r, c[1]],
            _ => [c[0], c[1] + r],
        };
        segments.push(Segment { to: along, arc: None });
        if r > 0.0 {
            let centre = [c[0] + inward[0] * r, c[1] + inward[1] * r];
            let out: P2 = match k {
                0 => [c[0], c[1] + r],
                1 => [c[0] - r, c[1]],
                2 => [c[0], c[1] - r],
                _ => [c[0] + r, c[1]],
            };
            segments.push(Segment { to: out, arc: Some((centre, true)) });
        }
    }
    segments.push(Segment { to: [0.0, -hl], arc: None });
    Contour { start: [0.0, -hl], segments }
}

fn rectangle(min: P2, max: P2) -> Vec<Piece> {
    let c = [min, [max[0], min[1]], max, [min[0], max[1]]];
    (0..4).map(|i| Piece { from: c[i], to: c[(i + 1) % 4], arc: None }).collect()
}

fn to_contour(chain: &[Piece]) -> Contour {
    Contour {
        start: chain.first().map_or([0.0; 2], |p| p.from),
        segments: chain.iter().map(|p| Segment { to: p.to, arc: p.arc }).collect(),
    }
}

/// The contour moved so that `placement` is its origin, rounded to 1e-6 mm.
fn relative(c: &Contour, placement: P3) -> Contour {
    let rel = |p: P2| [round6(p[0] - placement[0]), round6(p[1] - placement[1])];
    Contour {
        start: rel(c.start),
        segments: c.segments.iter().map(|s| Segment { to: rel(s.to), arc: s.arc.map(|(c, ccw)| (rel(c), ccw)) }).collect(),
    }
}

/// Offsets a chain by `d` to the left of travel (negative: to the right). Outside corners
/// get an arc about the corner; inside corners between lines are trimmed to their
/// intersection, other inside corners are joined by a line.
fn offset(chain: &[Piece], d: f64) -> Vec<Piece> {
    if d.abs() < EPS {
        return chain.to_vec();
    }
    let shifted: Vec<Piece> = chain
        .iter()
        .filter_map(|p| match p.arc {
            None => {
                let u = p.dir();
                let n = [-u[1] * d, u[0] * d];
                Some(Piece { from: [p.from[0] + n[0], p.from[1] + n[1]], to: [p.to[0] + n[0], p.to[1] + n[1]], arc: None })
            }
            Some((c, ccw)) => {
                let r0 = dist(p.from, c);
                let r1 = if ccw { r0 - d } else { r0 + d };
                if r1 <= EPS {
                    return None;
                }
                let k = r1 / r0;
                let at = |q: P2| [c[0] + (q[0] - c[0]) * k, c[1] + (q[1] - c[1]) * k];
                Some(Piece { from: at(p.from), to: at(p.to), arc: Some((c, ccw)) })
            }
        })
        .collect();
    let closed = chain.len() > 1 && dist(chain[0].from, chain[chain.len() - 1].to) < 1e-4;
    let n = shifted.len();
    let mut out: Vec<Piece> = Vec::new();
    let mut pieces = shifted.clone();
    let joints = if closed { n } else { n.saturating_sub(1) };
    let mut joins: Vec<Option<Piece>> = vec![None; n];
    for i in 0..joints {
        let j = (i + 1) % n;
        let (a, b) = (pieces[i], pieces[j]);
        if dist(a.to, b.from) < 1e-6 {
            continue;
        }
        let (_, ta) = a.tangents();
        let (tb, _) = b.tangents();
        let turn = cross(ta, tb);
        if turn * d < 0.0 {
            let corner = chain.get(i).map_or(a.to, |p| p.to);
            joins[i] = Some(Piece { from: a.to, to: b.from, arc: Some((corner, turn > 0.0)) });
        } else if a.arc.is_none() && b.arc.is_none() {
            let denom = cross(a.dir(), b.dir());
            if denom.abs() > 1e-12 {
                let w = [b.from[0] - a.from[0], b.from[1] - a.from[1]];
                let t = cross(w, b.dir()) / denom;
                let x = [a.from[0] + a.dir()[0] * t, a.from[1] + a.dir()[1] * t];
                pieces[i].to = x;
                pieces[j].from = x;
            }
        } else {
            joins[i] = Some(Piece { from: a.to, to: b.from, arc: None });
        }
    }
    for (p, j) in pieces.into_iter().zip(joins) {
        out.push(p);
        if let Some(j) = j {
            out.push(j);
        }
    }
    // A closed chain starts where its first piece starts after trimming.
    if closed && let (Some(first), Some(last)) = (out.first().map(|p| p.from), out.last_mut()) {
        last.to = first;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn offset_square_outward_gets_corner_arcs() {
        let sq = rectangle([0.0, 0.0], [10.0, 10.0]);
        assert!(signed_area(&sq) > 0.0);
        let out = offset(&sq, -2.0);
        assert_eq!(out.len(), 8);
        let (min, max) = bounds(&out);
        assert!((min[0] + 2.0).abs() < 1e-9 && (max[1] - 12.0).abs() < 1e-9, "{min:?} {max:?}");
        let inner = offset(&sq, 2.0);
        assert_eq!(inner.len(), 4);
        let (min, max) = bounds(&inner);
        assert!((min[0] - 2.0).abs() < 1e-9 && (max[0] - 8.0).abs() < 1e-9);
    }

    #[test]
    fn cut_modes() {
        // M3, a clockwise loop around the part (material inside, on the right): climb.
        assert_eq!(cutmode(Rotation::Cw, false, false), CutMode::Climb);
        // M3, a counter-clockwise pocket loop (material outside, on the right): climb.
        assert_eq!(cutmode(Rotation::Ccw, false, true), CutMode::Climb);
        assert_eq!(cutmode(Rotation::Ccw, true, true), CutMode::Conventional);
    }
}

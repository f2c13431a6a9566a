//! Feature recognition: the cutting moves of each workingstep become a 2½D feature with the
//! operation's strategy and depths; workingsteps that machine the same feature (roughing
//! then finishing, drilling then reaming) are merged into one feature with several
//! operations.
//!
//! The door is [`recognise`]. Holes are read in `hole`, milled shapes in `milling`, on the
//! plane geometry of `chain`; this file merges what they find into features.

mod chain;
mod hole;
mod milling;

pub use chain::{rect_contour, rectangle_of};

use std::collections::{BTreeMap, BTreeSet};

use super::model::*;
use super::setup::Setup;

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
        // The stock and the faced level are the untilted plane's: a tilted one's coordinates
        // do not compare with them. Nor does a cylinder's developed surface (cylindrical
        // interpolation) with any box: its Y is a length round the cylinder.
        let tilted_stock = ws.setup.as_ref().filter(|s| s.cylinder.is_none()).zip(plan.workpiece.as_ref()).map(|(s, w)| on_plane(w, s));
        let (stock, faced_here) = match &tilted_stock {
            Some(t) => (Some(t), None),
            None if ws.setup.is_some() => (None, None),
            None => (plan.workpiece.as_ref(), faced),
        };
        let mut cand = if ws.operation.is_hole() && !ws.holes.is_empty() {
            hole::hole(ws, tool.as_ref(), stock, faced_here)
        } else {
            milling::milling(ws, tool.as_ref(), stock, faced_here)
        };
        // A shape with no segment is no shape: what was cut stays a toolpath.
        if cand.kind.contour().is_some_and(|c| c.segments.is_empty()) {
            cand.kind = FeatureKind::Toolpath;
        }
        if matches!(cand.kind, FeatureKind::PlanarFace { .. })
            && ws.setup.is_none()
            && let Some(d) = ws.depth
        {
            faced = Some(faced.map_or(d, |f: f64| f.min(d)));
        }
        let ws = &mut plan.workingsteps[i];
        ws.operation = cand.operation;
        ws.strategy = cand.strategy.clone();
        ws.axial_depth = cand.axial_depth;
        ws.radial_depth = cand.radial_depth;
        let setup = ws.setup;
        let merge =
            features.iter().rposition(|(f, regions)| setup_of(plan, f.workingsteps[0]) == setup && same_feature(f, regions.last(), &cand));
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
                    axis: None,
                    ref_direction: None,
                    wrap: None,
                };
                features.push((f, cand.region.into_iter().collect()));
                id
            }
        };
        plan.workingsteps[i].feature = Some(id);
    }
    plan.features = features.into_iter().map(|(f, _)| f).collect();
    absorb_spot_drilling(plan);
    place_on_setups(plan);
}

/// The stock as a tilted plane sees it: the box its corners span in the plane's
/// coordinates (exact where the plane turns by right angles; elsewhere its top is the
/// stock's highest point along the tool axis).
fn on_plane(w: &Stock, s: &Setup) -> Stock {
    let max = w.max();
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for k in 0..8 {
        let corner = [0, 1, 2].map(|i| if k >> i & 1 == 1 { max[i] } else { w.origin[i] });
        let p = s.from_part(corner);
        for i in 0..3 {
            lo[i] = lo[i].min(p[i]);
            hi[i] = hi[i].max(p[i]);
        }
    }
    Stock { origin: lo, size: [0, 1, 2].map(|i| hi[i] - lo[i]), ..w.clone() }
}

/// The setup of the workingstep with 1-based index `i`.
fn setup_of(plan: &ProcessPlan, i: u32) -> Option<Setup> {
    plan.workingsteps.get((i as usize).checked_sub(1)?).and_then(|ws| ws.setup)
}

/// Places every feature machined on a tilted plane in the part's frame: its placement turned
/// and moved onto the plane, with the plane's axis and reference direction (its positions
/// and contours stay relative to the placement, in the plane's X and Y).
///
/// On the developed surface of a cylinder (cylindrical interpolation), the plane's Y is the
/// length round the cylinder: the feature is wrapped onto it, placed where it begins at the
/// angle that length gives (the plane laid tangent there, its axis radial), and its `Wrap`
/// tells the cylinder and the angles it runs round it from its points' lengths.
fn place_on_setups(plan: &mut ProcessPlan) {
    for k in 0..plan.features.len() {
        let Some(s) = plan.features[k].workingsteps.first().and_then(|&i| setup_of(plan, i)) else { continue };
        let f = &mut plan.features[k];
        let s = match s.cylinder {
            Some(diameter) => {
                let p = f.placement;
                let (lo, hi) = developed_span(f);
                f.wrap = Some(crate::plan::Wrap {
                    diameter,
                    angles: (s.wrap_angle(p[1] + lo), s.wrap_angle(p[1] + hi)),
                    developed: crate::plan::round_sig(hi - lo),
                });
                let s = s.wrapped_at(p[1]);
                f.placement = [p[0], 0.0, p[2]];
                s
            }
            None => s,
        };
        f.placement = s.to_part(f.placement);
        f.axis = Some(s.axis);
        f.ref_direction = Some(s.ref_direction);
    }
}

/// The least and greatest second coordinate (the plane's Y) of a feature's positions and
/// contour points, relative to its placement: the ends of its contour's segments and, for an
/// arc, the points of its circle it passes at the quarters.
fn developed_span(f: &Feature) -> (f64, f64) {
    let mut ys = vec![0.0];
    if let FeatureKind::RoundHole { positions, .. } = &f.kind {
        ys.extend(positions.iter().map(|p| p[1]));
    }
    if let Some(c) = f.kind.contour() {
        ys.push(c.start[1]);
        let mut from = c.start;
        for seg in &c.segments {
            ys.push(seg.to[1]);
            if let Some((centre, ccw)) = seg.arc {
                let r = (from[0] - centre[0]).hypot(from[1] - centre[1]);
                let ang = |p: P2| (p[1] - centre[1]).atan2(p[0] - centre[0]);
                let (a0, a1) = (ang(from), ang(seg.to));
                // The sweep from a0 to a1 the arc's sense gives, a whole turn where they meet.
                let tau = std::f64::consts::TAU;
                let sweep = if ccw { (a1 - a0).rem_euclid(tau) } else { -(a0 - a1).rem_euclid(tau) };
                let sweep = if sweep.abs() < 1e-12 { if ccw { tau } else { -tau } } else { sweep };
                for (q, y) in [(std::f64::consts::FRAC_PI_2, r), (-std::f64::consts::FRAC_PI_2, -r)] {
                    let t = if ccw { (q - a0).rem_euclid(tau) } else { (a0 - q).rem_euclid(tau) };
                    if t <= sweep.abs() {
                        ys.push(centre[1] + y);
                    }
                }
            }
            from = seg.to;
        }
    }
    ys.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &y| (lo.min(y), hi.max(y)))
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
        let setup = setup_of(plan, plan.features[k].workingsteps[0]);
        let same_plane = |f: &Feature| setup_of(plan, f.workingsteps[0]) == setup;
        for (j, f) in plan.features.iter().enumerate().skip(k + 1).filter(|(j, f)| !is_mark[*j] && same_plane(f)) {
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

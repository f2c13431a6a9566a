//! Milled shapes: the horizontal cuts at a workingstep's deepest level become a planar face,
//! a step, an open or closed pocket, an outside profile or a slot. Door: [`milling`].
//!
//! The rules, in order:
//! - parallel straight passes → a planar face (or, when the stock is known and the passes
//!   do not cover it, a step along the one side they cross, or a pocket);
//! - several nested closed loops, or passes inside a closed loop → a closed pocket;
//! - one closed loop → a pocket wall or an outside profile: a loop tighter than the tool is
//!   a pocket's; else where the tool entered, else the compensation side, else the side a
//!   climb-milling cut implies with the spindle's direction;
//! - paths entering and leaving the stock across one side → a pocket open there;
//! - one open path winding a full turn or more → a spiral pocket;
//! - one open path → a slot as wide as the tool;
//! - anything else, or cutting that is not at constant levels → a toolpath feature.

use super::chain::*;
use super::hole::plunged_holes;
use super::*;

/// The feature a milling workingstep cut, from its horizontal cuts at the deepest level.
pub(super) fn milling(ws: &Workingstep, tool: Option<&Tool>, stock: Option<&Stock>, faced: Option<f64>) -> Candidate {
    // Passes over the toolpath rather than lists of moves: a toolpath may hold millions.
    let cuts = || ws.toolpath.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid);
    let horizontal = || cuts().filter(|m| (m.from[2] - m.to[2]).abs() < 1e-4);
    // Entries down into the material (plunges, ramps, helices) are not the shape cut.
    let total: f64 = cuts().filter(|m| m.to[2] >= m.from[2] - 1e-4).map(|m| crate::plan::geom::length(&m)).sum();
    let flat_len: f64 = horizontal().map(|m| crate::plan::geom::length(&m)).sum();
    let arcs_in_xy = horizontal().all(|m| m.axis().is_none_or(|a| a[2].abs() > 1.0 - 1e-9));
    if horizontal().next().is_none()
        && let Some(c) = plunged_holes(ws, tool, stock)
    {
        return c;
    }
    if horizontal().next().is_none() || flat_len < 0.8 * total || !arcs_in_xy {
        return toolpath(ws, true);
    }
    let Some(levels) = levels(ws) else { return toolpath(ws, true) };
    let bottom = *levels.last().expect("one level at least");
    let step = levels.windows(2).map(|w| w[0] - w[1]).reduce(f64::max);
    let faced = faced.filter(|f| *f > bottom + EPS && *f >= levels[0] - EPS && stock.is_none_or(|s| *f < s.max()[2]));
    let (top, top_inferred, top_source) = top_of(ws, &levels, step, stock, faced);
    let chains = bottom_chains(ws, bottom);
    if chains.is_empty() {
        return toolpath(ws, true);
    }
    let cut = Cut::new(ws, tool, stock, chains, top, bottom, stock.is_some() || step.is_some() || faced.is_some());
    let axial_depth = step.or_else(|| stock.map(|_| top - bottom)).filter(|d| *d > EPS).map(round6);
    let mut cand = Candidate {
        kind: FeatureKind::Toolpath,
        placement: [0.0, 0.0, top],
        depth: top - bottom,
        top_inferred,
        sources: Sources {
            size: if cut.contour_programmed { Source::Program } else { Source::of_tool(tool) },
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
    let done = cut.parallel_passes(&mut cand) || cut.loops(&mut cand) || cut.open_to_a_side(&mut cand) || cut.one_open_path(&mut cand);
    if done { cand } else { toolpath(ws, false) }
}

/// A toolpath feature; `top_inferred` is false only once the levels were analysed.
fn toolpath(ws: &Workingstep, top_inferred: bool) -> Candidate {
    Candidate {
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
    }
}

/// The levels of the horizontal cuts, highest first; none when there are more than a
/// pocket has (a 3D surface).
fn levels(ws: &Workingstep) -> Option<Vec<f64>> {
    let mut levels: Vec<f64> = Vec::new();
    let horizontal =
        ws.toolpath.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid && (m.from[2] - m.to[2]).abs() < 1e-4);
    for m in horizontal {
        if !levels.iter().any(|z| (z - m.to[2]).abs() < 1e-3) {
            levels.push(m.to[2]);
            // More levels than a pocket has: the list stops growing here.
            if levels.len() > 200 {
                return None;
            }
        }
    }
    levels.sort_by(|a, b| b.total_cmp(a));
    (!levels.is_empty()).then_some(levels)
}

/// The feature's top, whether it was inferred, and where it came from: the faced level, the
/// stock's top, the layers' (one step above the first), or the program zero that posts put on
/// the part's top.
fn top_of(ws: &Workingstep, levels: &[f64], step: Option<f64>, stock: Option<&Stock>, faced: Option<f64>) -> (f64, bool, Source) {
    let bottom = *levels.last().expect("one level at least");
    let feed_start =
        ws.toolpath.iter().filter(|m| m.kind == MoveKind::Line && m.to[2] < m.from[2] - EPS).map(|m| m.from[2]).reduce(f64::max);
    // A milling cycle states the surface it mills from (`Q203`, `_RFP`): the program's word
    // wins over the stock's top, which need not be that face's.
    if let Some(s) = ws.surface.filter(|s| *s > bottom + EPS) {
        return (s, false, Source::Program);
    }
    match (stock, step) {
        _ if faced.is_some() => (faced.unwrap_or(bottom), false, Source::Cuts),
        (Some(s), _) => (s.max()[2], false, Source::Stock),
        (None, Some(st)) => (levels[0] + st, true, Source::Cuts),
        (None, None) if bottom < -EPS => (0.0, true, Source::Assumption),
        (None, None) => (feed_start.map_or(bottom, |z| z.max(bottom)), true, Source::Assumption),
    }
}

/// Chains of contiguous horizontal cutting moves at the bottom level, in XY.
fn bottom_chains(ws: &Workingstep, bottom: f64) -> Vec<Vec<Piece>> {
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
    chains
}

/// What a milling workingstep cut at its bottom level, with what the rules need to read it.
struct Cut<'a> {
    ws: &'a Workingstep,
    stock: Option<&'a Stock>,
    top: f64,
    bottom: f64,
    /// Whether the depth is known: from the stock, the layers, or a faced level.
    depth_known: bool,
    /// The tool's radius, when known.
    radius: Option<f64>,
    /// How far the wall lies from the path: 0 where the path is the programmed contour.
    r: f64,
    /// Whether the path is the part contour, compensated in the control.
    contour_programmed: bool,
    spindle_ccw: bool,
    chains: Vec<Vec<Piece>>,
    /// Every piece of every chain.
    all: Vec<Piece>,
    /// The closed loops the chains trace, and the pieces between them.
    loops: Vec<Vec<Piece>>,
    rest: Vec<Piece>,
}

impl<'a> Cut<'a> {
    fn new(
        ws: &'a Workingstep,
        tool: Option<&Tool>,
        stock: Option<&'a Stock>,
        chains: Vec<Vec<Piece>>,
        top: f64,
        bottom: f64,
        depth_known: bool,
    ) -> Self {
        let radius = tool.and_then(|t| t.diameter).map(|d| d / 2.0);
        // Under cutter compensation the interpreter offsets the path only by a radius the tool
        // table gives; otherwise the moves are the programmed contour itself.
        let contour_programmed = !ws.state.cutter_comp.is_empty() && tool.is_none_or(|t| t.source != ToolSource::Table);
        let r = if contour_programmed { 0.0 } else { radius.unwrap_or(0.0) };
        let all: Vec<Piece> = chains.iter().flatten().copied().collect();
        let mut loops: Vec<Vec<Piece>> = Vec::new();
        let mut rest: Vec<Piece> = Vec::new();
        // Under cutter compensation the control leaves and rejoins the contour where the lead-in
        // and lead-out meet it: the loop it cuts stops short of (or runs past) its own start.
        let gap = radius.map_or(2.0, |r| 2.0 * r);
        for c in &chains {
            let (l, r) = split_loops(&close_gap(c, gap));
            loops.extend(l);
            rest.extend(r);
        }
        let spindle_ccw = ws.technology.spindle == SpindleDir::Ccw;
        Cut { ws, stock, top, bottom, depth_known, radius, r, contour_programmed, spindle_ccw, chains, all, loops, rest }
    }

    fn region(&self, min: P2, max: P2) -> Region {
        Region { min, max, bottom: self.bottom }
    }

    /// Parallel straight passes outside any closed loop: a planar face, or with the stock
    /// known a step or a pocket open to it; passes inside a loop clear its pocket.
    fn parallel_passes(&self, cand: &mut Candidate) -> bool {
        let bottom_len: f64 = self.all.iter().map(Piece::len).sum();
        let rest_len: f64 = self.rest.iter().map(Piece::len).sum();
        let longest = self.rest.iter().filter(|p| p.arc.is_none()).map(Piece::len).fold(0.0, f64::max);
        let passes: Vec<Piece> = self.rest.iter().copied().filter(|p| p.arc.is_none() && p.len() > 0.5 * longest).collect();
        let parallel = passes.len() >= 2
            && passes.iter().all(|p| cross(p.dir(), passes[0].dir()).abs() < 1e-6)
            && passes.iter().map(Piece::len).sum::<f64>() >= 0.6 * rest_len
            && rest_len >= 0.3 * bottom_len;
        if !parallel {
            return false;
        }
        let (r, radius) = (self.r, self.radius);
        // The face's frame runs along the passes, pointing to +X (or +Y).
        let d = passes[0].dir();
        let u = if d[0] > 1e-9 || d[0].abs() <= 1e-9 && d[1] > 0.0 { d } else { [-d[0], -d[1]] };
        let u = [u[0] + 0.0, u[1] + 0.0];
        let frame = Frame { u, v: [-u[1], u[0]] };
        let mut offsets: Vec<f64> = passes.iter().map(|p| frame.across(p.from)).collect();
        offsets.sort_by(f64::total_cmp);
        offsets.dedup_by(|a, b| (*a - *b).abs() < 1e-4);
        let stepover = offsets.windows(2).map(|w| w[1] - w[0]).reduce(f64::min);
        let alternating = passes.windows(2).all(|w| w[0].dir()[0] * w[1].dir()[0] + w[0].dir()[1] * w[1].dir()[1] < 0.0);
        let (bmin, bmax) = bounds(&self.all);
        let swept = ([bmin[0] - r, bmin[1] - r], [bmax[0] + r, bmax[1] + r]);
        cand.region = Some(self.region(swept.0, swept.1));
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
        let enclosing = self.loops.iter().find(|l| {
            let (lmin, lmax) = bounds(l);
            passes.iter().all(|p| {
                [p.from, p.to]
                    .iter()
                    .all(|q| q[0] >= lmin[0] - 1e-4 && q[0] <= lmax[0] + 1e-4 && q[1] >= lmin[1] - 1e-4 && q[1] <= lmax[1] + 1e-4)
            })
        });
        if let Some(outer) = enclosing {
            pocket(cand, outer, r, self.stock);
            return true;
        }
        let sides = self.stock.map(|s| crossed_sides(s, swept));
        let axis_aligned = u[0].abs() < 1e-9 || u[1].abs() < 1e-9;
        match (sides, self.stock) {
            (Some(n), _) if n.iter().all(|x| *x) || self.top - self.bottom < 1e-3 => {}
            (Some(n), Some(st)) if axis_aligned && step_side(n, u).is_some() => {
                make_step(cand, st, swept, u, n, self.top);
                return true;
            }
            (Some(_), Some(st)) => {
                // The pocket ends where the stock does: the passes run out past its side.
                open_pocket(cand, clip_to_stock(swept, st).unwrap_or(swept));
                return true;
            }
            _ => {}
        }
        self.planar_face(cand, &frame);
        true
    }

    /// A planar face over everything cut, in the frame of the passes, trimmed to the stock
    /// when it is known: the passes run over its edges.
    fn planar_face(&self, cand: &mut Candidate, frame: &Frame) {
        let r = self.r;
        let (mut amin, mut amax, mut cmin, mut cmax) = (f64::INFINITY, f64::NEG_INFINITY, f64::INFINITY, f64::NEG_INFINITY);
        for p in &self.all {
            for q in [p.from, p.to] {
                amin = amin.min(frame.along(q));
                amax = amax.max(frame.along(q));
                cmin = cmin.min(frame.across(q));
                cmax = cmax.max(frame.across(q));
            }
        }
        let (mut amin, mut amax, mut cmin, mut cmax) = (amin - r, amax + r, cmin - r, cmax + r);
        let mut corner = frame.point(amin, cmin);
        if let Some(st) = self.stock {
            let (lo, hi) = (st.origin, st.max());
            let corners = [[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]]];
            let (sa0, sa1) =
                corners.iter().map(|p| frame.along(*p)).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
            let (sc0, sc1) =
                corners.iter().map(|p| frame.across(*p)).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
            if amin.max(sa0) < amax.min(sa1) && cmin.max(sc0) < cmax.min(sc1) {
                (amin, amax, cmin, cmax) = (amin.max(sa0), amax.min(sa1), cmin.max(sc0), cmax.min(sc1));
                corner = frame.point(amin, cmin);
            }
        }
        cand.operation = Operation::PlaneFinishMilling;
        cand.placement = [corner[0], corner[1], self.bottom];
        // The depth follows from the stock or the layers (a single layer without stock: none).
        cand.depth = if self.depth_known { self.top - self.bottom } else { 0.0 };
        if self.depth_known {
            cand.placement[2] = self.top;
        }
        let u = frame.u;
        cand.kind = FeatureKind::PlanarFace { direction: [u[0], u[1], 0.0], length: round6(amax - amin), width: round6(cmax - cmin) };
    }

    /// Closed loops, with little else or only moves inside the largest: a pocket (nested
    /// loops cleared from inside), or a wall of one loop — a pocket's or an outside profile.
    fn loops(&self, cand: &mut Candidate) -> bool {
        let bottom_len: f64 = self.all.iter().map(Piece::len).sum();
        let rest_len: f64 = self.rest.iter().map(Piece::len).sum();
        // Moves inside the largest loop clear what it encloses (a lead-in, the floor along a
        // ramp's line): they belong to a pocket.
        let largest = self.loops.iter().max_by(|a, b| signed_area(a).abs().total_cmp(&signed_area(b).abs()));
        let rest_inside = largest.is_some_and(|l| self.rest.iter().all(|p| [p.from, p.to].iter().all(|q| inside(l, *q) != Some(false))));
        if self.loops.is_empty() || !(rest_len < 0.3 * bottom_len || rest_inside) {
            return false;
        }
        let mut sorted: Vec<&Vec<Piece>> = self.loops.iter().collect();
        sorted.sort_by(|a, b| signed_area(b).abs().total_cmp(&signed_area(a).abs()));
        if sorted.len() >= 2 && side_by_side(&sorted) {
            return self.circle_milled_holes(cand, &sorted);
        }
        // One circle the tool went down to in a helix along it is a bore milled by helical
        // interpolation (Heidenhain 208, a CAM's helical bore milling): a round hole.
        if sorted.len() == 1 && self.helix_along(sorted[0]) && self.circle_milled_holes(cand, &sorted) {
            return true;
        }
        let outer = sorted[0];
        // Nested loops entered from outside all of them run around a boss: the innermost is
        // its wall, the others roughed towards it.
        let around = sorted.len() >= 2 && self.entry_inside(outer) == Some(false);
        if sorted.len() >= 2 && !around {
            let rotation = if signed_area(outer) > 0.0 { Rotation::Ccw } else { Rotation::Cw };
            cand.strategy = Some(Strategy {
                kind: StrategyKind::ContourParallel,
                feed_direction: None,
                rotation: Some(rotation),
                cutmode: Some(cutmode(rotation, self.spindle_ccw, true)),
                overlap: None,
            });
            let (omin, _) = bounds(outer);
            let (imin, _) = bounds(sorted[1]);
            cand.radial_depth = Some(round6((imin[0] - omin[0]).max(imin[1] - omin[1])));
            pocket(cand, outer, self.r, self.stock);
            return true;
        }
        self.wall(cand, sorted.last().expect("one loop at least"));
        true
    }

    /// Loops side by side, none inside another, are several places cut alike, not one
    /// feature's rings. Circles of one radius the tool runs inside (a climb cut inside, an
    /// entry inside, or too tight to stand outside of) are holes milled round (`G3 I-1` at
    /// each hole, stepping down): one round hole feature, as wide as the circle plus the tool,
    /// at each centre. Other shapes side by side are left to the other rules (false).
    fn circle_milled_holes(&self, cand: &mut Candidate, loops: &[&Vec<Piece>]) -> bool {
        let circles: Option<Vec<(P2, f64)>> = loops.iter().map(|l| circle(l)).collect();
        let Some(circles) = circles else { return false };
        let r = circles[0].1;
        if circles.iter().any(|(_, ri)| (ri - r).abs() > 1e-3) {
            return false;
        }
        let inside_each = loops.iter().all(|l| {
            let rotation = if signed_area(l) > 0.0 { Rotation::Ccw } else { Rotation::Cw };
            let tight = self.radius.is_some_and(|t| r <= t + EPS);
            // An entry outside one circle may be another's: only one inside says more than the
            // direction does.
            tight || self.entry_inside(l) == Some(true) || (rotation == Rotation::Ccw) != self.spindle_ccw
        });
        if !inside_each {
            return false;
        }
        let first = circles[0].0;
        // A circle programmed under compensation in the control is the wall itself.
        let diameter = if self.contour_programmed { Some(round6(2.0 * r)) } else { self.radius.map(|t| round6(2.0 * (r + t))) };
        cand.kind = FeatureKind::RoundHole {
            diameter,
            bottom: HoleBottom::Flat,
            positions: circles.iter().map(|(c, _)| [round6(c[0] - first[0]), round6(c[1] - first[1])]).collect(),
            heights: Vec::new(),
        };
        cand.placement = [first[0], first[1], self.top];
        if diameter.is_none() {
            cand.centre_path = Some((round6(2.0 * r), round6(2.0 * r)));
        }
        cand.operation = Operation::SideFinishMilling;
        cand.holes = circles.iter().map(|(c, _)| *c).collect();
        true
    }

    /// Where the material is for one loop: a pocket's wall (the tool inside) or an outside
    /// profile (the tool outside). A loop tighter than the tool (a bore circle-milled) is a
    /// pocket's; else where the tool entered, inside the loop or outside it; else the
    /// compensation side; the cut direction (taken as climb milling) only as a last resort,
    /// and then the cut mode is not stated.
    fn wall(&self, cand: &mut Candidate, outer: &[Piece]) {
        let r = self.r;
        let area = signed_area(outer);
        let rotation = if area > 0.0 { Rotation::Ccw } else { Rotation::Cw };
        let by_entry = self.entry_inside(outer);
        let by_comp = self.ws.state.cutter_comp.first().map(|c| c.left == (rotation == Rotation::Ccw));
        let no_profile = {
            let b = offset(outer, if area > 0.0 { r } else { -r });
            b.is_empty() || signed_area(&b).abs() < EPS || (signed_area(&b) > 0.0) != (area > 0.0)
        };
        // A loop the tool cannot stand outside of overrules the rest.
        let evidence = no_profile.then_some(true).or(by_entry).or(by_comp);
        let tool_inside = evidence.unwrap_or((rotation == Rotation::Ccw) != self.spindle_ccw);
        cand.strategy = Some(Strategy {
            kind: StrategyKind::ContourParallel,
            feed_direction: None,
            rotation: Some(rotation),
            cutmode: evidence.map(|inside| cutmode(rotation, self.spindle_ccw, inside)),
            overlap: None,
        });
        cand.operation = Operation::SideFinishMilling;
        if tool_inside {
            pocket(cand, outer, r, self.stock);
            cand.operation = Operation::SideFinishMilling;
            return;
        }
        let boundary = offset(outer, if area > 0.0 { r } else { -r });
        let (bmin, bmax) = bounds(outer);
        cand.region = Some(self.region(bmin, bmax));
        cand.placement = [0.0, 0.0, self.top];
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

    /// Whether the tool went down in a helix along the circle `lp` (an arc about its centre, at
    /// its radius, descending).
    fn helix_along(&self, lp: &[Piece]) -> bool {
        let Some((c, r)) = circle(lp) else { return false };
        self.ws.toolpath.iter().any(|m| {
            m.kind == MoveKind::Arc
                && m.to[2] < m.from[2] - EPS
                && m.center().is_some_and(|k| dist([k[0], k[1]], c) < 1e-3)
                && m.axis().is_some_and(|a| a[2].abs() > 1.0 - 1e-9)
                && (dist([m.from[0], m.from[1]], c) - r).abs() < 1e-3
        })
    }

    /// Every entry down into the material (a plunge, a ramp, a helix) says where the
    /// material is: a tool cannot plunge into a boss. Entries on the loop say nothing, nor do
    /// feed moves that end above the top. One entry inside is enough: the others may serve
    /// another place the workingstep cuts.
    fn entry_inside(&self, lp: &[Piece]) -> Option<bool> {
        let entries =
            self.ws.toolpath.iter().filter(|m| m.kind != MoveKind::Rapid && m.to[2] < m.from[2] - EPS && m.to[2] < self.top - EPS);
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
    }

    /// Paths that come in from outside the stock across one of its sides, turn inside and
    /// leave across the same side (a U, and the passes inside it) clear a pocket open there.
    fn open_to_a_side(&self, cand: &mut Candidate) -> bool {
        let (Some(st), Some(rad), true) = (self.stock, self.radius, self.loops.is_empty()) else { return false };
        let (lo, hi) = (st.origin, st.max());
        let outside = |p: P2| p[0] < lo[0] - EPS || p[0] > hi[0] + EPS || p[1] < lo[1] - EPS || p[1] > hi[1] + EPS;
        let side_of = |p: P2| [p[0] < lo[0] - EPS, p[0] > hi[0] + EPS, p[1] < lo[1] - EPS, p[1] > hi[1] + EPS].iter().position(|x| *x);
        let turning = |c: &Vec<Piece>| c.iter().any(|p| p.arc.is_some() || cross(p.dir(), c[0].dir()).abs() > 1e-6);
        let chains = &self.chains;
        let ends: Vec<Option<usize>> = chains.iter().flat_map(|c| [side_of(c[0].from), side_of(c[c.len() - 1].to)]).collect();
        let one_side = ends.first().copied().flatten().is_some() && ends.iter().all(|e| *e == ends[0]);
        let enters = chains.iter().all(|c| outside(c[0].from) && outside(c[c.len() - 1].to)) && chains.iter().any(turning);
        if !(one_side && enters) {
            return false;
        }
        let (bmin, bmax) = bounds(&self.all);
        let Some(wall) = clip_to_stock(([bmin[0] - rad, bmin[1] - rad], [bmax[0] + rad, bmax[1] + rad]), st) else { return false };
        open_pocket(cand, wall);
        true
    }

    /// One open path: a spiral pocket when it winds a full turn, a step when it is one
    /// straight pass along the stock's side, else a slot as wide as the tool.
    fn one_open_path(&self, cand: &mut Candidate) -> bool {
        if self.chains.len() != 1 || !self.loops.is_empty() {
            return false;
        }
        let chain = &self.chains[0];
        let turning = total_turning(chain);
        let (bmin, bmax) = bounds(chain);
        if turning.abs() >= std::f64::consts::TAU - 1e-6 {
            // A spiral: the pocket is the box it sweeps.
            let rotation = if turning > 0.0 { Rotation::Ccw } else { Rotation::Cw };
            cand.strategy = Some(Strategy {
                kind: StrategyKind::ContourSpiral,
                feed_direction: None,
                rotation: Some(rotation),
                cutmode: Some(cutmode(rotation, self.spindle_ccw, true)),
                overlap: None,
            });
            pocket(cand, &rectangle(bmin, bmax), self.r, self.stock);
            return true;
        }
        let Some(rad) = self.radius else { return false };
        let swept = ([bmin[0] - rad, bmin[1] - rad], [bmax[0] + rad, bmax[1] + rad]);
        // One straight pass across the stock along its side: a step.
        let straight = chain.iter().all(|p| p.arc.is_none() && cross(p.dir(), chain[0].dir()).abs() < 1e-6);
        if let (Some(st), true) = (self.stock, straight) {
            let u = chain[0].dir();
            let n = crossed_sides(st, swept);
            if (u[0].abs() < 1e-9 || u[1].abs() < 1e-9) && step_side(n, u).is_some() {
                make_step(cand, st, swept, u, n, self.top);
                cand.region = Some(self.region(swept.0, swept.1));
                return true;
            }
        }
        cand.operation = Operation::BottomAndSideFinishMilling;
        cand.strategy =
            Some(Strategy { kind: StrategyKind::CenterMilling, feed_direction: None, rotation: None, cutmode: None, overlap: None });
        cand.region = Some(self.region(swept.0, swept.1));
        let start = chain[0].from;
        cand.placement = [start[0], start[1], self.top];
        cand.kind = FeatureKind::Slot { path: relative(&to_contour(chain), cand.placement), width: round6(2.0 * rad) };
        true
    }
}

/// A frame in XY: `u` along the passes, `v` across them to the left.
struct Frame {
    u: P2,
    v: P2,
}

impl Frame {
    fn along(&self, p: P2) -> f64 {
        p[0] * self.u[0] + p[1] * self.u[1]
    }
    fn across(&self, p: P2) -> f64 {
        p[0] * self.v[0] + p[1] * self.v[1]
    }
    fn point(&self, along: f64, across: f64) -> P2 {
        [self.u[0] * along + self.v[0] * across, self.u[1] * along + self.v[1] * across]
    }
}

/// Climb or conventional from the loop's rotation, the spindle direction and which side of
/// the path the material is (inside the loop for a pocket).
/// Whether no loop lies inside another (each one's start is outside every other).
fn side_by_side(loops: &[&Vec<Piece>]) -> bool {
    loops.iter().enumerate().all(|(i, a)| loops.iter().enumerate().all(|(j, b)| i == j || inside(a, b[0].from) == Some(false)))
}

/// The centre and radius of a loop that is one circle: arcs about one centre all round.
fn circle(lp: &[Piece]) -> Option<(P2, f64)> {
    let (c, _) = lp.first()?.arc?;
    let r = dist(lp[0].from, c);
    let same = lp.iter().all(|p| p.arc.is_some_and(|(ci, _)| dist(ci, c) < 1e-3) && (dist(p.from, c) - r).abs() < 1e-3);
    (same && r > EPS).then_some((c, r))
}

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
        // A circular pocket is placed by its centre, as ISO 14649-10 places a circular closed
        // profile and as a machinist dimensions it; any other shape by its lower corner.
        let origin = circle(&wall).map_or(bmin, |(c, _)| c);
        cand.placement = [origin[0], origin[1], cand.placement[2]];
        cand.kind =
            FeatureKind::ClosedPocket { boundary: relative(&to_contour(&wall), cand.placement), rectangle: None, corner_radius: None };
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cut_modes() {
        // M3, a clockwise loop around the part (material inside, on the right): climb.
        assert_eq!(cutmode(Rotation::Cw, false, false), CutMode::Climb);
        // M3, a counter-clockwise pocket loop (material outside, on the right): climb.
        assert_eq!(cutmode(Rotation::Ccw, false, true), CutMode::Climb);
        assert_eq!(cutmode(Rotation::Ccw, true, true), CutMode::Conventional);
    }
}

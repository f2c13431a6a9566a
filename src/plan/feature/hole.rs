//! Holes: drilling cycles (their depth to the full diameter, the point as the bottom
//! condition) and end mills plunged straight down (flat holes). Door: [`hole`] and
//! [`plunged_holes`].

use super::*;

/// The top of a hole: the surface its cycle states (`RFP`, `Q203`), the faced level, the
/// stock's, or else the program zero where it lies between the bottom and the R level (posts
/// put the work zero on the part's top); the R level only as a last resort.
pub(super) fn hole(ws: &Workingstep, tool: Option<&Tool>, stock: Option<&Stock>, faced: Option<f64>) -> Candidate {
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
    // Each hole's top is the surface its own cycle states (a cycle written per hole, each
    // with its `Q203` or `RFP`: the TNC 640 cycles manual's SURFACE COORDINATE is the
    // workpiece surface at that hole), else the feature's; its depth is from there.
    let top_of = |h: &Hole| if top_source == Source::Program { h.top.unwrap_or(top) } else { top };
    let tip_depth = ws.holes.iter().map(|h| top_of(h) - h.bottom).filter(|d| d.is_finite()).fold(f64::NEG_INFINITY, f64::max);
    let tip_depth = if tip_depth.is_finite() { tip_depth } else { 0.0 };
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
    let heights: Vec<f64> = ws.holes.iter().map(|h| round6(top_of(h) - top)).collect();
    let heights = if heights.iter().any(|d| d.abs() > 1e-6) { heights } else { Vec::new() };
    let size = if diameter.is_some() { Source::of_tool(tool) } else { Source::Unknown };
    Candidate {
        kind: FeatureKind::RoundHole { diameter, bottom, positions, heights },
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
pub(super) fn plunged_holes(ws: &Workingstep, tool: Option<&Tool>, stock: Option<&Stock>) -> Option<Candidate> {
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
    // A through hole is as deep as the stock below its top, as a drilled one is.
    let depth = match (bottom_kind, stock) {
        (HoleBottom::Through, Some(s)) => top - s.origin[2],
        _ => top - bottom,
    };
    Some(Candidate {
        kind: FeatureKind::RoundHole {
            diameter: Some(d),
            bottom: bottom_kind,
            positions: at.iter().map(|p| [p[0] - first[0], p[1] - first[1]]).collect(),
            heights: Vec::new(),
        },
        placement: [first[0], first[1], top],
        depth: round6(depth),
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

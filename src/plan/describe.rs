//! The plan in words: what `ncplan plan` prints. Door: [`describe`].

use std::fmt::Write;

use super::*;
use crate::text::num;

/// Where a feature's numbers came from, in words: `size from the tool table, top from the
/// stock`, or the tool-centre path when the size is unknown.
fn feature_sources(f: &Feature) -> String {
    let size = match (f.sources.size, f.centre_path) {
        (Source::Unknown, Some((w, l))) => {
            format!("size unknown (the tool's diameter is not known; the tool-centre path spans {} x {})", num(w), num(l))
        }
        (Source::Unknown, None) => "size unknown (the tool's diameter is not known)".to_owned(),
        (Source::Program, _) => "size from the program (the contour as programmed)".to_owned(),
        (s, _) => format!("size from {}", s.words()),
    };
    let angle = match f.sources.point_angle {
        Some(Source::Assumption) => ", point angle assumed (the tool's is not known)".to_owned(),
        Some(s) => format!(", point angle from {}", s.words()),
        None => String::new(),
    };
    format!("{size}, top from {}{angle}", f.sources.top.words())
}

/// The plan in words, a line per stock, tool, feature and workingstep (`ncplan plan`).
pub fn describe(plan: &ProcessPlan) -> String {
    let mut out = String::new();
    write_plan(&mut out, plan).expect("writing to a String cannot fail");
    out
}

fn write_plan(out: &mut impl Write, plan: &ProcessPlan) -> std::fmt::Result {
    writeln!(out, "program {}", plan.program.as_deref().unwrap_or("(unnamed)"))?;
    match &plan.workpiece {
        Some(s) => writeln!(
            out,
            "stock X{} Y{} Z{} size {} x {} x {} (from the {})",
            num(s.origin[0]),
            num(s.origin[1]),
            num(s.origin[2]),
            num(s.size[0]),
            num(s.size[1]),
            num(s.size[2]),
            match (s.source, s.line) {
                (super::StockSource::Config, _) => "configuration".to_owned(),
                (super::StockSource::Program, Some(l)) => format!("program, line {l}"),
                (super::StockSource::Program, None) => "program".to_owned(),
            }
        )?,
        None => writeln!(out, "stock unknown")?,
    }
    for t in &plan.tools {
        let d = t.diameter.map(|d| format!(" D{}", num(d))).unwrap_or_default();
        let r = t.corner_radius.map(|d| format!(" R{}", num(d))).unwrap_or_default();
        let z = t.flutes.map(|d| format!(" Z{d}")).unwrap_or_default();
        let l = t.length_offset.map(|d| format!(" L{}", num(d))).unwrap_or_default();
        writeln!(out, "tool T{} {}{d}{r}{z}{l} {}", t.number, t.kind.as_str().replace('_', " "), t.name.as_deref().unwrap_or(""))?;
    }
    for f in &plan.features {
        write_feature(out, f)?;
    }
    for w in &plan.workingsteps {
        if let Some(words) = super::turning::words(w) {
            let f = w.feature.map(|f| format!(" of feature {f}")).unwrap_or_default();
            writeln!(out, "workingstep {}{f} T{}: {words}, lines {}-{}", w.index, w.tool, w.lines.0, w.lines.1)?;
            continue;
        }
        let t = &w.technology;
        writeln!(
            out,
            "workingstep {} ({}{}) T{} F{} {} spindle {}{}, coolant {}, lines {}-{}",
            w.index,
            w.operation.label(),
            w.feature.map(|f| format!(" of feature {f}")).unwrap_or_default(),
            w.tool,
            num(t.feed),
            match t.surface_speed {
                Some(v) => format!("surface speed {} m/min (S at most {})", num(v), num(t.spindle_speed)),
                None => format!("S{}", num(t.spindle_speed)),
            },
            match t.spindle {
                super::SpindleDir::Cw => "clockwise",
                super::SpindleDir::Ccw => "counter-clockwise",
                super::SpindleDir::Off => "off",
            },
            // The tool's own spindle where it is not the main one (a driven tool on a lathe).
            if t.spindle_id == super::SpindleId::Main { String::new() } else { format!(" ({})", t.spindle_id.words()) },
            match t.coolant {
                super::Coolant::Off => "off",
                super::Coolant::Mist => "mist",
                super::Coolant::Flood => "flood",
                super::Coolant::Both => "mist and flood",
            },
            w.lines.0,
            w.lines.1
        )?;
        if let Some(setup) = &w.setup {
            writeln!(out, "  on the {} (its coordinates below)", setup.words())?;
        }
        if let Some(p) = w.start_point {
            writeln!(out, "  start X{} Y{} Z{}; security plane Z{}", num(p[0]), num(p[1]), num(p[2]), num(w.security_plane))?;
        }
        if let Some(s) = &w.strategy {
            // The snake-case names the JSON uses, in words.
            let words =
                |v: serde_json::Result<serde_json::Value>| v.ok().and_then(|v| v.as_str().map(|s| s.replace('_', " "))).unwrap_or_default();
            let mut parts = vec![words(serde_json::to_value(s.kind))];
            if let Some(r) = s.rotation {
                parts.push(match r {
                    super::Rotation::Cw => "clockwise".into(),
                    super::Rotation::Ccw => "counter-clockwise".into(),
                });
            }
            if let Some(c) = s.cutmode {
                parts.push(words(serde_json::to_value(c)) + " milling");
            }
            for (name, v) in [
                ("axial depth", w.axial_depth),
                ("stepover", w.radial_depth),
                ("side allowance", w.allowance_side),
                ("bottom allowance", w.allowance_bottom),
            ] {
                if let Some(v) = v {
                    parts.push(format!("{name} {}", num(v)));
                }
            }
            writeln!(out, "  strategy {}", parts.join(", "))?;
        }
        if let (Some(b), Some(d)) = (w.bbox, w.depth) {
            writeln!(
                out,
                "  box X{}..{} Y{}..{} Z{}..{}; depth Z{}; {} mm of cut in {} moves",
                num(b.min[0]),
                num(b.max[0]),
                num(b.min[1]),
                num(b.max[1]),
                num(b.min[2]),
                num(b.max[2]),
                num(d),
                num(w.cutting_length),
                w.toolpath.len()
            )?;
        }
        for h in &w.holes {
            writeln!(out, "  hole X{} Y{} bottom Z{} from R{}", num(h.x), num(h.y), num(h.bottom), num(h.r_plane))?;
        }
    }
    Ok(())
}

/// One feature of the plan: its kind, size and place, then its tilt, wrap and sources.
fn write_feature(out: &mut impl Write, f: &Feature) -> std::fmt::Result {
    let p = f.placement;
    let ws: Vec<String> = f.workingsteps.iter().map(u32::to_string).collect();
    let shape = shape(&f.kind);
    if matches!(f.kind, super::FeatureKind::Turned(_)) {
        writeln!(out, "feature {} {}{shape} at Z{}; workingsteps {}", f.id, f.kind.label(), num(p[2]), ws.join(", "))?;
        return Ok(());
    }
    writeln!(
        out,
        "feature {} {}{shape} at X{} Y{} Z{} depth {}{}; workingsteps {}",
        f.id,
        f.kind.label(),
        num(p[0]),
        num(p[1]),
        num(p[2]),
        num(f.depth),
        if f.top_inferred { " (top inferred)" } else { "" },
        ws.join(", ")
    )?;
    if let (Some(z), Some(x)) = (f.axis, f.ref_direction) {
        let v = |v: P3| format!("{} {} {}", num(v[0]), num(v[1]), num(v[2]));
        writeln!(out, "  on a tilted face: axis {}, positions along {}", v(z), v(x))?;
    }
    if let Some(w) = f.wrap {
        writeln!(
            out,
            "  wrapped round the Ø{} cylinder: C{}° to C{}°, {} mm round it (its Y the length round the cylinder)",
            num(w.diameter),
            num(w.angles.0),
            num(w.angles.1),
            num(w.developed)
        )?;
    }
    if let super::FeatureKind::RoundHole { heights, .. } = &f.kind
        && !heights.is_empty()
    {
        let h: Vec<String> = heights.iter().map(|h| num(*h)).collect();
        writeln!(out, "  each hole's top as its cycle states it, along the axis from the first: {}", h.join(", "))?;
    }
    if !matches!(f.kind, super::FeatureKind::Toolpath) {
        writeln!(out, "  {}", feature_sources(f))?;
    }
    Ok(())
}

/// A feature's size after its kind: ` 40 x 20`, ` D8 x4 flat bottom`, ` Ø24 × 28`.
fn shape(kind: &super::FeatureKind) -> String {
    match kind {
        super::FeatureKind::PlanarFace { length, width, .. } => format!(" {} x {}", num(*length), num(*width)),
        super::FeatureKind::RoundHole { diameter, positions, bottom, .. } => {
            let bottom = match bottom {
                super::HoleBottom::Through => "through".to_owned(),
                super::HoleBottom::Flat => "flat bottom".to_owned(),
                super::HoleBottom::Conical(angle) => format!("drill-point bottom {}°", num(*angle)),
            };
            format!(" D{} x{} {bottom}", diameter.map_or("?".into(), num), positions.len())
        }
        super::FeatureKind::ClosedPocket { rectangle: Some((w, l)), corner_radius, .. }
        | super::FeatureKind::OutsideProfile { rectangle: Some((w, l)), corner_radius, .. } => {
            format!(" {} x {}{}", num(*w), num(*l), corner_radius.map(|r| format!(" r{}", num(r))).unwrap_or_default())
        }
        super::FeatureKind::Slot { width, .. } | super::FeatureKind::Step { width, .. } => {
            format!(" width {}", num(*width))
        }
        super::FeatureKind::Turned(t) => format!(" {}", t.size()),
        _ => String::new(),
    }
}

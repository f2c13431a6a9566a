//! `ncplan plan`: print the recovered process plan.

use std::io::Write;
use std::process::ExitCode;

use anyhow::Result;

use super::common::{Format, Input, input_setup};
use crate::pipeline;

/// The arguments of `ncplan plan`.
#[derive(Debug, clap::Args)]
pub(super) struct Args {
    #[command(flatten)]
    input: Input,
    #[arg(long, value_enum, default_value = "text")]
    format: Format,
}

/// Runs `ncplan plan`.
pub(super) fn run(args: Args, mut out: impl Write) -> Result<ExitCode> {
    let Args { input, format } = args;
    let (d, config, bytes) = input_setup(&input)?;
    let a = pipeline::analyze_plan_owned(bytes, &d, &config.profile);
    match format {
        Format::Json => {
            serde_json::to_writer_pretty(&mut out, &a.plan)?;
            writeln!(out)?;
        }
        Format::Text => write_plan(&mut out, &a.plan)?,
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

/// Where a feature's numbers came from, in words: `size from the tool table, top from the
/// stock`, or the tool-centre path when the size is unknown.
fn feature_sources(f: &crate::plan::Feature) -> String {
    use crate::diff::num;
    use crate::plan::Source;
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

fn write_plan(out: &mut impl Write, plan: &crate::plan::ProcessPlan) -> Result<()> {
    use crate::diff::num;
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
                (crate::plan::StockSource::Config, _) => "configuration".to_owned(),
                (crate::plan::StockSource::Program, Some(l)) => format!("program, line {l}"),
                (crate::plan::StockSource::Program, None) => "program".to_owned(),
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
        let p = f.placement;
        let ws: Vec<String> = f.workingsteps.iter().map(u32::to_string).collect();
        let shape = match &f.kind {
            crate::plan::FeatureKind::PlanarFace { length, width, .. } => format!(" {} x {}", num(*length), num(*width)),
            crate::plan::FeatureKind::RoundHole { diameter, positions, bottom } => {
                let bottom = match bottom {
                    crate::plan::HoleBottom::Through => "through".to_owned(),
                    crate::plan::HoleBottom::Flat => "flat bottom".to_owned(),
                    crate::plan::HoleBottom::Conical(angle) => format!("drill-point bottom {}°", num(*angle)),
                };
                format!(" D{} x{} {bottom}", diameter.map_or("?".into(), num), positions.len())
            }
            crate::plan::FeatureKind::ClosedPocket { rectangle: Some((w, l)), corner_radius, .. }
            | crate::plan::FeatureKind::OutsideProfile { rectangle: Some((w, l)), corner_radius, .. } => {
                format!(" {} x {}{}", num(*w), num(*l), corner_radius.map(|r| format!(" r{}", num(r))).unwrap_or_default())
            }
            crate::plan::FeatureKind::Slot { width, .. } | crate::plan::FeatureKind::Step { width, .. } => {
                format!(" width {}", num(*width))
            }
            _ => String::new(),
        };
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
        if !matches!(f.kind, crate::plan::FeatureKind::Toolpath) {
            writeln!(out, "  {}", feature_sources(f))?;
        }
    }
    for w in &plan.workingsteps {
        let t = &w.technology;
        writeln!(
            out,
            "workingstep {} ({}{}) T{} F{} {} spindle {}, coolant {}, lines {}-{}",
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
                crate::plan::SpindleDir::Cw => "clockwise",
                crate::plan::SpindleDir::Ccw => "counter-clockwise",
                crate::plan::SpindleDir::Off => "off",
            },
            match t.coolant {
                crate::plan::Coolant::Off => "off",
                crate::plan::Coolant::Mist => "mist",
                crate::plan::Coolant::Flood => "flood",
                crate::plan::Coolant::Both => "mist and flood",
            },
            w.lines.0,
            w.lines.1
        )?;
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
                    crate::plan::Rotation::Cw => "clockwise".into(),
                    crate::plan::Rotation::Ccw => "counter-clockwise".into(),
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

//! Suggestions as text: the one-line evidence, the neutral CSV and the pictures (SVG of
//! numbers and fixed words only: nothing from a program's text goes into them).

use std::fmt::Write as _;

use super::{Scale, Suggestion, day_number, num};

/// The change a value makes against the CAM value, as the pictures plot it: percent for a
/// ratio, mm for a height.
fn plotted(s: &Suggestion, before: f64, after: f64) -> f64 {
    match s.key.parameter.scale() {
        Scale::Ratio if before != 0.0 => (after / before - 1.0) * 100.0,
        _ => after - before,
    }
}

/// The evidence in one line (a preset's description, the CSV's last column).
pub fn evidence_line(s: &Suggestion) -> String {
    let unit = s.key.parameter.unit();
    let n = s.agree + s.disagree;
    let way = if s.centre >= 0.0 { "higher" } else { "lower" };
    let first = s.edits.first().map(|e| e.day()).unwrap_or("");
    let last = s.edits.last().map(|e| e.day()).unwrap_or("");
    let by = if s.operators > 0 { format!(" by {} operators", s.operators) } else { String::new() };
    format!(
        "ncplan {}: {} {} -> {} {unit} (interval {} to {}); {} edits in {} programs on {} days ({first} to {last}){by}, {} of {n} {way}, sign test p={}; {} on {}, {}",
        s.id,
        s.key.parameter.label(),
        num(s.cam_value),
        num(s.suggested),
        num(s.interval.0),
        num(s.interval.1),
        s.edits.len(),
        s.programs,
        s.days,
        s.agree,
        fmt_p(s.p),
        s.key.material,
        s.key.machine,
        s.key.class.name(),
    )
}

/// A p-value, three significant digits.
pub fn fmt_p(p: f64) -> String {
    if p >= 0.001 { num((p * 1000.0).round() / 1000.0) } else { format!("{p:.1e}") }
}

/// The CSV's columns.
pub const CSV_HEADER: &str = "id,state,scope,tool_number,tool,diameter_mm,flutes,corner_radius_mm,material,machine,operation_class,parameter,unit,cam_value,suggested,low,high,change_percent,change_mm,edits,programs,days,operators,p_value,first,last,evidence";

/// One CSV cell: quoted when it holds a comma, quote or line end; a text a spreadsheet would
/// run as a formula gets a `'` first.
pub fn cell(s: &str) -> String {
    let s = if s.starts_with(['=', '+', '-', '@', '\t', '\r']) && s.parse::<f64>().is_err() { format!("'{s}") } else { s.to_owned() };
    if s.contains([',', '"', '\n', '\r']) { format!("\"{}\"", s.replace('"', "\"\"")) } else { s }
}

/// The neutral CSV: one row per suggestion with its state (`states` in the same order).
pub fn csv(suggestions: &[(&Suggestion, &str)]) -> String {
    let mut out = String::from(CSV_HEADER);
    out.push('\n');
    let o = |v: Option<f64>| v.map(num).unwrap_or_default();
    for (s, state) in suggestions {
        let t = &s.key.tool;
        let scope = if s.key.parameter.of_tool() { "tool" } else { "operation note" };
        let (percent, mm) = match s.key.parameter.scale() {
            Scale::Ratio => (num((s.change() * 1000.0).round() / 10.0), String::new()),
            Scale::Offset => (String::new(), num(s.change())),
        };
        let cells = [
            s.id.clone(),
            (*state).to_owned(),
            scope.to_owned(),
            t.number.to_string(),
            t.description.clone(),
            o(t.diameter),
            t.flutes.map(|z| z.to_string()).unwrap_or_default(),
            o(t.corner_radius),
            s.key.material.clone(),
            s.key.machine.clone(),
            s.key.class.name().to_owned(),
            s.key.parameter.name().to_owned(),
            s.key.parameter.unit().to_owned(),
            num(s.cam_value),
            num(s.suggested),
            num(s.interval.0),
            num(s.interval.1),
            percent,
            mm,
            s.edits.len().to_string(),
            s.programs.to_string(),
            s.days.to_string(),
            s.operators.to_string(),
            fmt_p(s.p),
            s.edits.first().map(|e| e.day().to_owned()).unwrap_or_default(),
            s.edits.last().map(|e| e.day().to_owned()).unwrap_or_default(),
            evidence_line(s),
        ];
        let row: Vec<String> = cells.iter().map(|c| cell(c)).collect();
        out.push_str(&row.join(","));
        out.push('\n');
    }
    out
}

/// The picture's frame: width, height and margins.
const W: f64 = 520.0;
const H: f64 = 180.0;
const LEFT: f64 = 44.0;
const BOTTOM: f64 = 22.0;
const TOP: f64 = 10.0;

/// Each edit over time (kept ones as dots, left-out ones as crosses), the zero line (no
/// change), the suggestion's change and its interval as a band.
pub fn timeline_svg(s: &Suggestion) -> String {
    let mut all: Vec<(i64, f64, bool)> = s
        .edits
        .iter()
        .map(|e| (day_number(&e.at).unwrap_or(0), plotted(s, e.before, e.after), true))
        .chain(s.left_out.iter().map(|(e, _)| (day_number(&e.at).unwrap_or(0), plotted(s, e.before, e.after), false)))
        .collect();
    all.sort_by(|a, b| a.0.cmp(&b.0).then(a.1.total_cmp(&b.1)));
    let (d0, d1) = (all.iter().map(|p| p.0).min().unwrap_or(0), all.iter().map(|p| p.0).max().unwrap_or(1));
    let band = (plotted(s, s.cam_value, s.interval.0), plotted(s, s.cam_value, s.interval.1));
    let sug = plotted(s, s.cam_value, s.suggested);
    let ys = all.iter().map(|p| p.1).chain([0.0, band.0, band.1]);
    let (lo, hi) = ys.fold((f64::MAX, f64::MIN), |(a, b), y| (a.min(y), b.max(y)));
    let pad = ((hi - lo) * 0.1).max(1.0);
    let (lo, hi) = (lo - pad, hi + pad);
    let x = |d: i64| LEFT + (d - d0) as f64 / ((d1 - d0).max(1) as f64) * (W - LEFT - 10.0);
    let y = |v: f64| TOP + (hi - v) / (hi - lo) * (H - TOP - BOTTOM);
    let unit = if s.key.parameter.scale() == Scale::Ratio { "%" } else { "mm" };
    let mut out = String::new();
    let _ = write!(
        out,
        r#"<svg class="chart" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {W} {H}" width="{W}" height="{H}" role="img"><title>edits over time</title>"#
    );
    let _ = write!(
        out,
        r##"<rect x="{LEFT}" y="{:.1}" width="{:.1}" height="{:.1}" fill="#cfe3fa"/>"##,
        y(band.1),
        W - LEFT - 10.0,
        (y(band.0) - y(band.1)).max(1.0)
    );
    let _ = write!(out, r##"<line x1="{LEFT}" y1="{0:.1}" x2="{1}" y2="{0:.1}" stroke="#999"/>"##, y(0.0), W - 10.0);
    let _ = write!(out, r##"<line x1="{LEFT}" y1="{0:.1}" x2="{1}" y2="{0:.1}" stroke="#1f6fd1" stroke-width="2"/>"##, y(sug), W - 10.0);
    for (d, v, kept) in &all {
        let (cx, cy) = (x(*d), y(*v));
        if *kept {
            let _ = write!(out, r##"<circle cx="{cx:.1}" cy="{cy:.1}" r="3" fill="#e07b00"/>"##);
        } else {
            let _ = write!(
                out,
                r##"<path d="M{:.1} {:.1}L{:.1} {:.1}M{:.1} {:.1}L{:.1} {:.1}" stroke="#c7283e" stroke-width="1.5"/>"##,
                cx - 3.0,
                cy - 3.0,
                cx + 3.0,
                cy + 3.0,
                cx - 3.0,
                cy + 3.0,
                cx + 3.0,
                cy - 3.0
            );
        }
    }
    let _ =
        write!(out, r##"<text x="2" y="{:.1}" font-size="10" fill="#555">{}{unit}</text>"##, y(hi - pad) + 4.0, num((hi - pad).round()));
    let _ =
        write!(out, r##"<text x="2" y="{:.1}" font-size="10" fill="#555">{}{unit}</text>"##, y(lo + pad) + 4.0, num((lo + pad).round()));
    let _ = write!(out, r##"<text x="2" y="{:.1}" font-size="10" fill="#555">0</text>"##, y(0.0) + 4.0);
    let _ = write!(out, r##"<text x="{LEFT}" y="{}" font-size="10" fill="#555">day 0</text>"##, H - 6.0);
    let _ = write!(
        out,
        r##"<text x="{}" y="{}" font-size="10" fill="#555" text-anchor="end">day {}</text></svg>"##,
        W - 10.0,
        H - 6.0,
        d1 - d0
    );
    out
}

/// The spread: every kept edit's change as a dot on one axis, the median and the interval.
pub fn spread_svg(s: &Suggestion) -> String {
    let vals: Vec<f64> = s.edits.iter().map(|e| plotted(s, e.before, e.after)).collect();
    let out_vals: Vec<f64> = s.left_out.iter().map(|(e, _)| plotted(s, e.before, e.after)).collect();
    let band = (plotted(s, s.cam_value, s.interval.0), plotted(s, s.cam_value, s.interval.1));
    let sug = plotted(s, s.cam_value, s.suggested);
    let all = vals.iter().chain(&out_vals).copied().chain([0.0, band.0, band.1]);
    let (lo, hi) = all.fold((f64::MAX, f64::MIN), |(a, b), v| (a.min(v), b.max(v)));
    let pad = ((hi - lo) * 0.08).max(1.0);
    let (lo, hi) = (lo - pad, hi + pad);
    let h = 70.0;
    let x = |v: f64| LEFT + (v - lo) / (hi - lo) * (W - LEFT - 10.0);
    let mut out = String::new();
    let _ = write!(
        out,
        r#"<svg class="chart" xmlns="http://www.w3.org/2000/svg" viewBox="0 0 {W} {h}" width="{W}" height="{h}" role="img"><title>spread of the edits</title>"#
    );
    let _ =
        write!(out, r##"<rect x="{:.1}" y="8" width="{:.1}" height="34" fill="#cfe3fa"/>"##, x(band.0), (x(band.1) - x(band.0)).max(1.0));
    let _ = write!(out, r##"<line x1="{0:.1}" y1="4" x2="{0:.1}" y2="46" stroke="#999"/>"##, x(0.0));
    let _ = write!(out, r##"<line x1="{0:.1}" y1="4" x2="{0:.1}" y2="46" stroke="#1f6fd1" stroke-width="2"/>"##, x(sug));
    let mut sorted = vals.clone();
    sorted.sort_by(f64::total_cmp);
    for (i, v) in sorted.iter().enumerate() {
        let _ = write!(out, r##"<circle cx="{:.1}" cy="{:.1}" r="3" fill="#e07b00"/>"##, x(*v), 14.0 + (i % 5) as f64 * 6.0);
    }
    for v in &out_vals {
        let _ = write!(
            out,
            r##"<path d="M{0:.1} 22L{1:.1} 28M{0:.1} 28L{1:.1} 22" stroke="#c7283e" stroke-width="1.5"/>"##,
            x(*v) - 3.0,
            x(*v) + 3.0
        );
    }
    let unit = if s.key.parameter.scale() == Scale::Ratio { "%" } else { "mm" };
    let _ = write!(out, r##"<text x="{:.1}" y="62" font-size="10" fill="#555" text-anchor="middle">0</text>"##, x(0.0));
    let _ = write!(
        out,
        r##"<text x="{:.1}" y="62" font-size="10" fill="#1f6fd1" text-anchor="middle">{}{unit}</text></svg>"##,
        x(sug),
        num((sug * 10.0).round() / 10.0)
    );
    out
}

/// The columns of NX's `tool_machining_data.dat` (`MACH/resource/library/feeds_speeds/ascii`)
/// ncplan fills: the record's key and the cutting data, in the file's order; the feed
/// percentages that follow them in NX's own file are left to it.
pub const NX_FORMAT: &str = "FORMAT LIBRF DPT_CUT_IN DPT_CUT_MM STEPOVER_IN STEPOVER_MM SURF_SPEED_FPM SURF_SPEED_MPM FEED_IPT FEED_MMPT";

/// A fragment of NX's `tool_machining_data.dat` for an administrator to merge: comments with
/// each suggestion's evidence, the `FORMAT` line, and one `DATA` line per tool (fields
/// separated by `|`, a field ncplan has no value for left empty). NX keys the record by the
/// cutter's library reference (`LIBRF`); ncplan writes the tool as the programs name it, and
/// the record holds cutting data per tool (NX keeps material apart), so the material and
/// machine each value comes from are in the comments.
pub fn nx_fragment(suggestions: &[&Suggestion]) -> String {
    let mut out = String::from(
        "# ncplan: suggestions for tool_machining_data.dat, to merge by hand.\n\
         # LIBRF below is the tool as the programs name it: replace it with the cutter's library reference.\n",
    );
    let mut tools: Vec<(&super::ToolKey, Vec<&Suggestion>)> = Vec::new();
    for s in suggestions.iter().filter(|s| s.key.parameter.of_tool()) {
        match tools.iter_mut().find(|(t, _)| **t == s.key.tool) {
            Some((_, v)) => v.push(s),
            None => tools.push((&s.key.tool, vec![s])),
        }
    }
    for (_, group) in &tools {
        for s in group {
            let _ = writeln!(out, "# {}", evidence_line(s).replace('\n', " "));
        }
    }
    out.push_str(NX_FORMAT);
    out.push('\n');
    for (tool, group) in &tools {
        let mut f: [String; 8] = Default::default();
        let n = |x: f64, d: usize| format!("{x:.d$}");
        for s in group {
            let v = s.suggested;
            match s.key.parameter {
                super::Parameter::Stepdown => (f[0], f[1]) = (n(v / 25.4, 6), n(v, 6)),
                super::Parameter::Stepover => (f[2], f[3]) = (n(v / 25.4, 6), n(v, 6)),
                super::Parameter::CuttingSpeed => (f[4], f[5]) = (n(v / 0.3048, 6), n(v, 6)),
                super::Parameter::SpindleSpeed => {
                    if let Some(d) = tool.diameter {
                        let vc = std::f64::consts::PI * d * v / 1000.0;
                        (f[4], f[5]) = (n(vc / 0.3048, 6), n(vc, 6));
                    }
                }
                super::Parameter::CuttingFeed => {
                    let speeds: Vec<f64> = s.edits.iter().filter_map(|e| e.spindle).filter(|x| *x > 0.0).collect();
                    if let (Some(rpm), Some(z)) = (super::stats::median(&speeds), tool.flutes.filter(|z| *z > 0)) {
                        let fz = v / (rpm * f64::from(z));
                        (f[6], f[7]) = (n(fz / 25.4, 6), n(fz, 6));
                    }
                }
                _ => {}
            }
        }
        let name = if tool.description.is_empty() { format!("T{}", tool.number) } else { tool.description.replace(['|', '\n'], " ") };
        let _ = writeln!(out, "DATA|{name}|{}", f.join("|"));
    }
    out
}

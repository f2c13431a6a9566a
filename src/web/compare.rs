//! The comparison view, the heart of the workspace: the change sentences grouped by
//! workingstep, the toolpath pictures, the two sources side by side and both programs'
//! findings. The server renders it with review forms; the HTML report without.

use std::collections::BTreeSet;
use std::sync::Arc;

use anyhow::Result;
use maud::{Markup, PreEscaped, html};

use super::{Ctx, NotFound};
use crate::diff::ChangeKind;
use crate::plan::{BBox, ProcessPlan};
use crate::store::{ChangeRow, RevisionInfo, Store, StoredFinding};
use crate::view::picture::{self, Projection, Region, Stats};
use crate::view::source::{self, LineState};

/// Everything the comparison view shows.
pub(crate) struct Comparison {
    pub(crate) edited: RevisionInfo,
    pub(crate) original: RevisionInfo,
    pub(crate) rule: String,
    pub(crate) rows: Vec<ChangeRow>,
    pub(crate) plans: (Arc<ProcessPlan>, Arc<ProcessPlan>),
    pub(crate) texts: (String, String),
    pub(crate) findings: (Vec<StoredFinding>, Vec<StoredFinding>),
}

/// Rebuilds the whole plan of a stored revision.
pub(crate) type PlanOf<'a> = dyn Fn(&Store, i64) -> Result<Option<Arc<ProcessPlan>>> + 'a;

/// Loads the comparison of the edited revision `revision`; `plan` rebuilds a whole plan.
pub(crate) fn load(store: &Store, revision: i64, plan: &PlanOf<'_>) -> Result<Comparison> {
    let edited = store.revision(revision)?.ok_or_else(|| NotFound(format!("no revision {revision}")))?;
    let Some((original_id, _, rule, _)) = edited.original.clone() else {
        return Err(NotFound(format!("revision {revision} was not compared with a CAM original")).into());
    };
    let original = store.revision(original_id)?.ok_or_else(|| NotFound(format!("no revision {original_id}")))?;
    let empty = || Arc::new(ProcessPlan::default());
    let plans = (plan(store, original_id)?.unwrap_or_else(empty), plan(store, revision)?.unwrap_or_else(empty));
    let text = |id: i64| -> Result<String> { Ok(crate::text::decode(&store.content(id)?.unwrap_or_default()).0.text.to_string()) };
    Ok(Comparison {
        rows: store.change_rows(revision)?,
        texts: (text(original_id)?, text(revision)?),
        findings: (store.findings(original_id)?, store.findings(revision)?),
        edited,
        original,
        rule,
        plans,
    })
}

/// `X83 Y20 Z-1` (as the diff writes a point) in mm, missing axes from `base`.
fn parse_point(text: &str, base: [f64; 3], inch: bool) -> [f64; 3] {
    let mut p = base;
    for word in text.split_whitespace() {
        let mut chars = word.chars();
        let axis = match chars.next() {
            Some('X') => 0,
            Some('Y') => 1,
            Some('Z') => 2,
            _ => continue,
        };
        if let Ok(v) = chars.as_str().parse::<f64>() {
            p[axis] = if inch { v * 25.4 } else { v };
        }
    }
    p
}

/// The regions to box: each change's stored region, and for a moved start point the box
/// around both start points.
pub(crate) fn regions(rows: &[ChangeRow], original: &ProcessPlan) -> Vec<Region> {
    let inch = matches!(original.units, Some(crate::canon::Units::Inch));
    let mut out = Vec::new();
    for r in rows {
        if let Some(b) = r.change.region {
            out.push(Region { id: r.id, bbox: b });
        } else if r.change.kind == ChangeKind::StartPointMoved
            && let Some(p0) = original.workingsteps.iter().find(|w| w.index == r.change.workingstep).and_then(|w| w.start_point)
        {
            let p1 = parse_point(&r.change.after, p0, inch);
            let pad = 1.0;
            out.push(Region {
                id: r.id,
                bbox: BBox {
                    min: [p0[0].min(p1[0]) - pad, p0[1].min(p1[1]) - pad, p0[2].min(p1[2]) - pad],
                    max: [p0[0].max(p1[0]) + pad, p0[1].max(p1[1]) + pad, p0[2].max(p1[2]) + pad],
                },
            });
        }
    }
    out
}

/// The three pictures' SVG (top, front, side) and what they hold.
pub(crate) fn pictures(c: &Comparison) -> (Vec<(Projection, String)>, Stats) {
    let regions = regions(&c.rows, &c.plans.0);
    let mut stats = Stats::default();
    let sizes = [(640.0, 420.0), (640.0, 230.0), (460.0, 230.0)];
    let svgs = Projection::ALL
        .iter()
        .zip(sizes)
        .map(|(p, size)| (*p, picture::view_svg(*p, &c.plans.0, &c.plans.1, &regions, size, &mut stats)))
        .collect();
    (svgs, stats)
}

fn mark_pills(row: &ChangeRow) -> Markup {
    html! {
        @for m in &row.marks {
            span class={"pill " (m.mark)} title={(m.by) " at " (m.at)} {
                (m.mark) " by " (m.by) " at " (m.at.get(..16).unwrap_or(&m.at))
                @if !m.note.is_empty() { ": " (m.note) }
            }
            " "
        }
        @if row.marks.is_empty() { span class="pill" { "to review" } }
    }
}

fn review_forms(row: &ChangeRow, ctx: &Ctx) -> Markup {
    let action = format!("/review/{}", row.id);
    let back = format!("/compare/{}#change-{}", row.revision_id, row.id);
    html! {
        @for (mark, label) in [("adopt", "Adopt"), ("reject", "Reject")] {
            form method="post" action=(action) class="review" {
                input type="hidden" name="csrf" value=(ctx.csrf);
                input type="hidden" name="back" value=(back);
                @if !ctx.auth { input type="hidden" name="by" value="planner"; }
                button type="submit" name="mark" value=(mark) data-mark=(mark) { (label) }
            }
        }
        form method="post" action=(action) class="review" {
            input type="hidden" name="csrf" value=(ctx.csrf);
            input type="hidden" name="back" value=(back);
            @if !ctx.auth { input type="hidden" name="by" value="planner"; }
            input type="text" name="note" placeholder="note" aria-label="note";
            button type="submit" name="mark" value="note" { "Note" }
        }
    }
}

/// The change sentences grouped by workingstep, each with its anchor, its marks and (on the
/// server) its review forms.
pub(crate) fn sentences(c: &Comparison, ctx: Option<&Ctx>) -> Markup {
    let groups: BTreeSet<u32> = c.rows.iter().map(|r| r.change.workingstep).collect();
    html! {
        @if c.rows.is_empty() { p class="muted" { "No changes: the edited program does what the original does." } }
        @for ws in &groups {
            @let w = c.plans.0.workingsteps.iter().find(|w| w.index == *ws);
            @let first = c.rows.iter().find(|r| r.change.workingstep == *ws);
            h3 {
                "Workingstep " (ws) " ("
                (first.map_or("", |r| r.change.operation.as_str()))
                ")"
                @if let Some(w) = w { span class="muted" { " · T" (w.tool) ", lines " (w.lines.0) "–" (w.lines.1) " of the original" } }
            }
            ul class="sentences" {
                @for r in c.rows.iter().filter(|r| r.change.workingstep == *ws) {
                    li id={"change-" (r.id)} data-kind=(r.change.kind.as_str()) {
                        a class="change" href={"#change-" (r.id)} data-change=(r.id)
                            data-line=[r.change.line] data-oline=[r.change.original_line] {
                            (r.change.phrase())
                        }
                        @if let Some(l) = r.change.line { span class="muted" { " · line " (l) } }
                        @if let Some(d) = r.change.deviation { span class="muted" { " · deviation " (crate::diff::num(d)) " mm" } }
                        " "
                        (mark_pills(r))
                        @if let Some(ctx) = ctx { (review_forms(r, ctx)) }
                    }
                }
            }
        }
    }
}

/// The pictures with their legend and layer switches.
pub(crate) fn picture_block(c: &Comparison, with_layers: bool) -> Markup {
    let (svgs, _) = pictures(c);
    html! {
        p class="legend" {
            span { i style="background:#1f6fd1;height:5px;opacity:.45" {} "original (" (c.original.name) ", wide)" }
            span { i style="background:#e07b00" {} "edited" }
            span { i style="background:#d0021b" {} "changed segments" }
            span { i style="height:0;border-top:2px dashed #777" {} "rapids" }
            span { "● start points · dashed boxes: changed regions" }
        }
        @if with_layers {
            p class="layers noprint" {
                "Layers: "
                @for (side, plan) in [("o", &c.plans.0), ("e", &c.plans.1)] {
                    @for w in &plan.workingsteps {
                        label {
                            input type="checkbox" checked data-layer={(side) (w.index)};
                            @if side == "o" { "original " } @else { "edited " }
                            "WS" (w.index) " " (w.operation.label()) " T" (w.tool)
                        }
                    }
                }
                span class="muted" { " · wheel to zoom, drag to pan, double-click to reset" }
            }
        }
        div class="pictures" {
            @for (p, svg) in &svgs {
                figure { (PreEscaped(svg)) figcaption { (p.label()) } }
            }
        }
    }
}

/// One program's lines: coloured, greyed where the difference is cosmetic, highlighted on
/// the lines of a change, each linked to its counterpart in the other program.
fn listing(
    prefix: &str,
    other: &str,
    lines: &[&str],
    states: &[(LineState, Option<usize>)],
    highlight: &BTreeSet<usize>,
    whole: usize,
) -> Markup {
    let interest: Vec<usize> = highlight
        .iter()
        .copied()
        .chain(states.iter().enumerate().filter(|(_, s)| s.0 == LineState::Differs).map(|(i, _)| i + 1).take(200))
        .collect();
    let windows = source::windows(lines.len(), &interest, whole, 25);
    html! {
        @for (k, w) in windows.iter().enumerate() {
            @if k > 0 || w.start > 0 {
                div class="gap" { "… " (w.start - windows.get(k.wrapping_sub(1)).map_or(0, |p| p.end)) " lines …" }
            }
            @for i in w.clone() {
                @let (state, pair) = states.get(i).copied().unwrap_or((LineState::Same, None));
                @let class = match (highlight.contains(&(i + 1)), state) {
                    (true, _) => "ln hl",
                    (false, LineState::Differs) => "ln d",
                    (false, LineState::Cosmetic) => "ln cos",
                    (false, LineState::Same) => "ln",
                };
                div class=(class) id={(prefix) "-" (i + 1)} data-pair=[pair.map(|j| format!("{other}-{}", j + 1))] {
                    span class="no" { (i + 1) }
                    @for (t, r) in source::colour(lines[i]) {
                        @match t.class() {
                            Some(c) => span class=(c) { (lines[i][r].to_owned()) },
                            None => (lines[i][r].to_owned()),
                        }
                    }
                }
            }
        }
        @let shown = windows.last().map_or(0, |w| w.end);
        @if shown < lines.len() {
            div class="gap" { "… " (lines.len() - shown) " lines …" }
        }
    }
}

/// The two sources side by side.
pub(crate) fn sources(c: &Comparison, whole: usize) -> Markup {
    let (a, b): (Vec<&str>, Vec<&str>) = (c.texts.0.lines().collect(), c.texts.1.lines().collect());
    let al = source::align(&a, &b);
    let ho: BTreeSet<usize> = c.rows.iter().filter_map(|r| r.change.original_line.map(|l| l as usize)).collect();
    let he: BTreeSet<usize> = c.rows.iter().filter_map(|r| r.change.line.map(|l| l as usize)).collect();
    html! {
        div class="sources" {
            div {
                h3 { "Original " span class="muted" { (c.original.path) } }
                div class="src" id="src-o" { (listing("o", "e", &a, &al.original, &ho, whole)) }
            }
            div {
                h3 { "Edited " span class="muted" { (c.edited.path) } }
                div class="src" id="src-e" { (listing("e", "o", &b, &al.edited, &he, whole)) }
            }
        }
        p class="muted" { "Highlighted: the lines of a change. Tinted: lines that differ. Grey: differences the machine does not see (block numbers, comments, spelling). Click a line to see its counterpart." }
    }
}

/// Findings with their source line and a caret.
pub(crate) fn findings(title: &str, text: &str, findings: &[StoredFinding]) -> Markup {
    // Only the lines findings point at are looked up.
    let wanted: BTreeSet<usize> = findings.iter().take(200).map(|f| (f.line.max(1) - 1) as usize).collect();
    let lines: std::collections::BTreeMap<usize, &str> = match wanted.last() {
        Some(last) => text.lines().enumerate().take(last + 1).filter(|(i, _)| wanted.contains(i)).collect(),
        None => std::collections::BTreeMap::new(),
    };
    html! {
        h3 { (title) " (" (findings.len()) ")" }
        @for f in findings.iter().take(200) {
            @let line = lines.get(&((f.line.max(1) - 1) as usize)).copied().unwrap_or("");
            @let col = line.chars().take((f.col.max(1) - 1) as usize).count();
            pre class="finding" {
                span class=(if f.severity == "error" { "bad" } else { "muted" }) { (f.severity) "[" (f.code) "]" } ": " (f.message) "\n"
                (format!("{:>5} | ", f.line)) (line) "\n"
                "      | " (" ".repeat(col)) span class="caret" { "^" }
            }
        }
        @if findings.len() > 200 { p class="muted" { (findings.len() - 200) " more" } }
    }
}

/// The header lines of a comparison.
pub(crate) fn heading(c: &Comparison) -> Markup {
    html! {
        p {
            "Machine " strong { (c.edited.machine.as_deref().unwrap_or("?")) } ", program " strong { (c.edited.name) }
            ", revision " (c.edited.id) " seen " (c.edited.seen_at)
            br;
            "Compared with the CAM original " (c.original.path) " (revision " (c.original.id) "), paired by " (c.rule) "; "
            (c.rows.len()) " changes."
        }
    }
}

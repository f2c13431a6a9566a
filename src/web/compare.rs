//! The comparison view, the heart of the workspace: the change sentences grouped by
//! workingstep, the toolpath pictures, the two sources side by side and both programs'
//! findings. The server renders it with review forms; the HTML report without.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

use anyhow::Result;
use axum::extract::{Path, Query, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{IntoResponse, Redirect, Response};
use maud::{Markup, PreEscaped, html};

use super::{Ctx, NotFound};
use crate::daemon::ingest::Reader;
use crate::diff::ChangeKind;
use crate::plan::{BBox, ProcessPlan};
use crate::store::{ChangeRow, RevisionInfo, Store, StoredFinding, StoredSource};
use crate::view::picture::{self, Pictures, Projection, Region};
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

/// Where whole plans come from: a cache of plans rebuilt before (the server's), and a
/// reader of stored bytes.
pub(crate) trait PlanSource: Sync {
    /// A plan rebuilt before.
    fn cached(&self, revision: i64) -> Option<Arc<ProcessPlan>>;
    /// Keeps a plan just rebuilt.
    fn keep(&self, revision: i64, plan: &Arc<ProcessPlan>);
    /// Reads stored programs again.
    fn reader(&self) -> Reader<'_>;
}

/// Plans rebuilt every time (the HTML report reads each comparison once).
pub(crate) struct Uncached<'a>(pub(crate) Reader<'a>);

impl PlanSource for Uncached<'_> {
    fn cached(&self, _: i64) -> Option<Arc<ProcessPlan>> {
        None
    }

    fn keep(&self, _: i64, _: &Arc<ProcessPlan>) {}

    fn reader(&self) -> Reader<'_> {
        Reader { config: self.0.config, registry: self.0.registry }
    }
}

/// One side's program as read from the store, before its plan is rebuilt.
enum Fetched {
    /// The plan is at hand; the bytes are for the source view.
    Cached(Arc<ProcessPlan>, Vec<u8>),
    /// The plan is to be read again from these bytes, which the source view shows too.
    Analyse(StoredSource),
    /// A complete stored plan (or none), and the bytes.
    Stored(Option<StoredSource>, Vec<u8>),
}

fn fetch(store: &Store, plans: &dyn PlanSource, id: i64) -> Result<Fetched> {
    if let Some(p) = plans.cached(id) {
        return Ok(Fetched::Cached(p, store.content(id)?.unwrap_or_default()));
    }
    let Some(src) = store.source(id)? else {
        return Ok(Fetched::Stored(None, store.content(id)?.unwrap_or_default()));
    };
    if matches!(src.plan, Some((_, false))) && src.bytes.is_some() {
        return Ok(Fetched::Analyse(src));
    }
    let bytes = store.content(id)?.unwrap_or_default();
    Ok(Fetched::Stored(Some(src), bytes))
}

/// The plan and the text of one side: the program's bytes are decoded and analysed once.
fn build(plans: &dyn PlanSource, id: i64, f: Fetched) -> Result<(Option<Arc<ProcessPlan>>, String)> {
    let text = |b: &[u8]| crate::text::decode(b).0.text;
    let reader = plans.reader();
    let (plan, text) = match f {
        Fetched::Cached(p, bytes) => return Ok((Some(p), text(&bytes))),
        Fetched::Analyse(mut src) => {
            let bytes = src.bytes.take().unwrap_or_default();
            let a = reader.reanalyse(&src.path, &src.dialect, bytes)?;
            (Some(a.plan), a.source.text)
        }
        Fetched::Stored(src, bytes) => (src.map(|s| reader.rebuild(s)).transpose()?.flatten(), text(&bytes)),
    };
    let plan = plan.map(Arc::new);
    if let Some(p) = &plan {
        plans.keep(id, p);
    }
    Ok((plan, text))
}

/// Loads the comparison of the edited revision `revision`. Both programs are read from the
/// store first, then their plans are rebuilt side by side (two threads), each program's
/// bytes decoded once for its plan and its source view.
pub(crate) fn load(store: &Store, revision: i64, plans: &dyn PlanSource) -> Result<Comparison> {
    let edited = store.revision(revision)?.ok_or_else(|| NotFound(format!("no revision {revision}")))?;
    let Some((original_id, _, rule, _)) = edited.original.clone() else {
        return Err(NotFound(format!("revision {revision} was not compared with a CAM original")).into());
    };
    let original = store.revision(original_id)?.ok_or_else(|| NotFound(format!("no revision {original_id}")))?;
    let (fo, fe) = (fetch(store, plans, original_id)?, fetch(store, plans, revision)?);
    let ((po, to), (pe, te)) = if matches!((&fo, &fe), (Fetched::Analyse(_), Fetched::Analyse(_))) {
        std::thread::scope(|s| {
            let other = s.spawn(|| build(plans, original_id, fo));
            let e = build(plans, revision, fe);
            let o = other.join().map_err(|_| anyhow::anyhow!("rebuilding the original's plan failed"))?;
            anyhow::Ok((o?, e?))
        })?
    } else {
        (build(plans, original_id, fo)?, build(plans, revision, fe)?)
    };
    let empty = || Arc::new(ProcessPlan::default());
    Ok(Comparison {
        rows: store.change_rows(revision)?,
        texts: (to, te),
        findings: (store.findings(original_id)?, store.findings(revision)?),
        plans: (po.unwrap_or_else(empty), pe.unwrap_or_else(empty)),
        edited,
        original,
        rule,
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
            out.push(Region { id: r.id, bbox: b, lines: (r.change.original_line, r.change.line) });
        } else if r.change.kind == ChangeKind::StartPointMoved
            && let Some(p0) = original.workingsteps.iter().find(|w| w.index == r.change.workingstep).and_then(|w| w.start_point)
        {
            let p1 = parse_point(&r.change.after, p0, inch);
            let pad = 1.0;
            out.push(Region {
                id: r.id,
                lines: (None, None),
                bbox: BBox {
                    min: [p0[0].min(p1[0]) - pad, p0[1].min(p1[1]) - pad, p0[2].min(p1[2]) - pad],
                    max: [p0[0].max(p1[0]) + pad, p0[1].max(p1[1]) + pad, p0[2].max(p1[2]) + pad],
                },
            });
        }
    }
    out
}

/// The three pictures (top, front, side) and what they hold.
pub(crate) fn pictures(c: &Comparison) -> Pictures {
    let regions = regions(&c.rows, &c.plans.0);
    let sizes = [(640.0, 420.0), (640.0, 230.0), (460.0, 230.0)];
    let views: Vec<(Projection, (f64, f64))> = Projection::ALL.into_iter().zip(sizes).collect();
    picture::pictures(&c.plans.0, &c.plans.1, &regions, &views)
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
                            (source::visible(&r.change.phrase()))
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
    let pics = pictures(c);
    html! {
        p class="legend" {
            span { i class="lg-original" {} "original (" (c.original.name) ", wide)" }
            span { i class="lg-edited" {} "edited" }
            span { i class="lg-changed" {} "changed segments" }
            span { i class="lg-rapid" {} "rapids" }
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
                            "WS" (w.index) " " (w.label()) " T" (w.tool)
                        }
                    }
                }
                span class="muted" { " · wheel to zoom, drag to pan, double-click to reset" }
            }
        }
        @for r in pics.regions.iter().filter(|r| !r.exact()) {
            p class="muted bounded" data-change=(r.id) {
                "Change " (r.id) " has " (r.moves[0]) " moves in the original and " (r.moves[1]) " in the edited program: the first "
                (picture::EXACT_MOVES) " of each are drawn exactly, the rest within a quarter pixel."
            }
        }
        div class="pictures" {
            @for (p, svg) in &pics.views {
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
                            Some(c) => span class=(c) { (source::visible(&lines[i][r])) },
                            None => (source::visible(&lines[i][r])),
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
    // Every line a change is seen at: its first, the rest of its run, the other statements.
    let lines_of = |first: Option<u32>, end: Option<u32>, at: &mut dyn Iterator<Item = Option<u32>>| -> Vec<usize> {
        let mut v: Vec<usize> = first.map(|f| (f..=end.unwrap_or(f).max(f)).take(200).map(|l| l as usize).collect()).unwrap_or_default();
        v.extend(at.flatten().map(|l| l as usize));
        v
    };
    let ho: BTreeSet<usize> = c
        .rows
        .iter()
        .flat_map(|r| lines_of(r.change.original_line, r.change.detail.original_line_end, &mut r.change.detail.at.iter().map(|a| a.0)))
        .collect();
    let he: BTreeSet<usize> = c
        .rows
        .iter()
        .flat_map(|r| lines_of(r.change.line, r.change.detail.line_end, &mut r.change.detail.at.iter().map(|a| a.1)))
        .collect();
    html! {
        div class="sources" {
            div {
                h3 { "Original " span class="muted" { (source::visible(&c.original.path)) } }
                div class="src" id="src-o" { (listing("o", "e", &a, &al.original, &ho, whole)) }
            }
            div {
                h3 { "Edited " span class="muted" { (source::visible(&c.edited.path)) } }
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
                span class=(if f.severity == "error" { "bad" } else { "muted" }) { (f.severity) "[" (f.code) "]" } ": " (source::visible(&f.message)) "\n"
                (format!("{:>5} | ", f.line)) (source::visible(line)) "\n"
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
            "Compared with the CAM original " (source::visible(&c.original.path)) " (revision " (c.original.id) "), paired by " (c.rule) "; "
            (c.rows.len()) " changes."
        }
    }
}

impl PlanSource for super::Server {
    fn cached(&self, revision: i64) -> Option<Arc<ProcessPlan>> {
        let cache = self.plans.lock().ok()?;
        cache.kept.iter().find(|(id, _)| *id == revision).map(|(_, p)| p.clone())
    }

    fn keep(&self, revision: i64, plan: &Arc<ProcessPlan>) {
        if let Ok(mut cache) = self.plans.lock() {
            cache.kept.retain(|(id, _)| *id != revision);
            cache.kept.insert(0, (revision, plan.clone()));
            cache.kept.truncate(super::PLANS_KEPT);
        }
    }

    fn reader(&self) -> Reader<'_> {
        Reader { config: &self.config, registry: &self.registry }
    }
}

/// The as-run program written for another control, as `ncplan translate --revision ID --to
/// D` writes it (no machine's limits; units as the source's).
pub(crate) struct Translated {
    /// `{program}-r{revision}-{dialect}.{extension}`: letters, digits, `_`, `-` and `.` only.
    pub(crate) filename: String,
    /// The target dialect.
    pub(crate) dialect: String,
    /// The dialect the program was read in.
    pub(crate) from: String,
    /// The program text.
    pub(crate) bytes: Vec<u8>,
    /// What the writer says (cycles written as moves, what it could not write) and the
    /// reading's errors and warnings, one line each.
    pub(crate) notes: Vec<String>,
    /// Whether any of them is an error.
    pub(crate) errors: bool,
}

/// Whether ncplan writes programs for `d`: it has output rules of its own (not refused).
fn writes(d: &crate::dialect::Dialect) -> bool {
    d.output.as_ref().is_some_and(|o| o.refused.is_none())
}

/// The dialects a program can be written in: those with output rules, by name.
pub(crate) fn writable(registry: &crate::dialect::Registry) -> Vec<String> {
    let mut names: Vec<String> = registry.names().filter(|n| registry.get(n).is_some_and(|d| writes(&d))).map(str::to_owned).collect();
    names.sort();
    names
}

/// The dialect a revision was read in; told from its text where it was stored as `auto`.
fn read_dialect(registry: &crate::dialect::Registry, stored: &str, bytes: &[u8], path: &str) -> String {
    if stored != crate::config::AUTO_DIALECT && registry.get(stored).is_some() {
        return stored.to_owned();
    }
    crate::pipeline::sniff(registry, bytes, std::path::Path::new(path)).dialect
}

/// The file name extension a dialect's programs have: its heaviest extension evidence, else `nc`.
fn extension(d: &crate::dialect::Dialect) -> String {
    d.recognise
        .iter()
        .filter(|e| !e.against)
        .filter_map(|e| match &e.marker {
            crate::dialect::sniff::Marker::Extension(x) => Some((e.weight, x)),
            crate::dialect::sniff::Marker::Pattern(_) => None,
        })
        .fold(None::<(u32, &String)>, |best, (w, x)| if best.is_none_or(|b| w > b.0) { Some((w, x)) } else { best })
        .map_or_else(|| "nc".to_owned(), |(_, x)| x.clone())
}

/// Letters, digits, `_` and `-`, at most 40: safe in a `Content-Disposition` header and as a file name.
fn file_safe(s: &str) -> String {
    let t: String = s.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).take(40).collect();
    if t.is_empty() { "program".into() } else { t }
}

/// Translates the as-run revision `revision` into `to` (by default the dialect of the CAM
/// original it was compared with) through the post-processor.
pub(crate) fn translate(s: &super::Server, store: &Store, revision: i64, to: Option<&str>) -> Result<Translated> {
    let registry = &s.registry;
    let edited = store.revision(revision)?.ok_or_else(|| NotFound(format!("no revision {revision}")))?;
    let bytes = store.content(revision)?.ok_or_else(|| NotFound(format!("revision {revision} has no stored program")))?;
    let from = read_dialect(registry, &edited.dialect, &bytes, &edited.path);
    let to = match to.filter(|t| !t.is_empty()) {
        Some(t) => t.to_owned(),
        None => match &edited.original {
            Some((original_id, ..)) => {
                let o = store.revision(*original_id)?.ok_or_else(|| NotFound(format!("no revision {original_id}")))?;
                let ob = store.content(*original_id)?.unwrap_or_default();
                read_dialect(registry, &o.dialect, &ob, &o.path)
            }
            None => from.clone(),
        },
    };
    let target = registry
        .get(&to)
        .filter(|d| writes(d))
        .ok_or_else(|| NotFound(format!("ncplan cannot write programs in `{to}`; it writes {}", writable(registry).join(", "))))?;
    let source_dialect = registry.get(&from).ok_or_else(|| NotFound(format!("no dialect `{from}`")))?;
    // Read as the daemon read it: a dialect guessed from weak evidence keeps a maker's own
    // finding a warning, and the translation is refused there all the same.
    let guessed = crate::daemon::ingest::Reader { config: &s.config, registry }.guessed(&edited.path, &from, &bytes);
    let (source, notes) = crate::text::decode_owned(bytes);
    let mut diags = crate::diag::decoding(notes);
    let stem = std::path::Path::new(&edited.path).file_stem().map(|x| x.to_string_lossy().into_owned());
    let name = crate::pipeline::program_name(&source.text).or(stem).unwrap_or_else(|| "PROGRAM".into());
    let profile = &crate::interp::Profile { guessed, ..s.config.profile.clone() };
    let opts = crate::pipeline::TranslateOptions::for_program(&name);
    let mut out = Vec::new();
    diags.extend(crate::pipeline::translate(&source.text, &source_dialect, &target, profile, opts, |chunk| out.extend_from_slice(chunk)));
    // Safe output: the translation is read back and proven before it is given out; one the
    // writer refused or that the proof rejects is not given out at all.
    if !diags.iter().any(|x| x.is_error()) {
        let checked = crate::pipeline::check_translation(
            source.text.as_str().into(),
            &source_dialect,
            &*String::from_utf8_lossy(&out),
            &target,
            profile,
            &diags,
        );
        diags.extend(checked);
    }
    if diags.iter().any(|x| x.is_error() && x.code.as_str().starts_with("post::")) {
        out.clear();
    }
    let idx = crate::text::LineIndex::new(&source.text);
    let notes = diags
        .iter()
        .filter(|x| x.severity != crate::diag::Severity::Note || x.code.as_str().starts_with("post::"))
        .map(|x| crate::diag::render_short(&edited.path, &source.text, &idx, x))
        .collect();
    Ok(Translated {
        filename: format!("{}-r{revision}-{}.{}", file_safe(&name), file_safe(&to), file_safe(&extension(&target))),
        errors: diags.iter().any(|x| x.is_error()),
        dialect: to,
        from,
        bytes: out,
        notes,
    })
}

/// The form on the comparison page: the as-run program, translated into a chosen dialect
/// (the CAM original's by default), as a download or with its notes.
pub(crate) fn translate_form(s: &super::Server, c: &Comparison) -> Markup {
    let names = writable(&s.registry);
    let default = if names.contains(&c.original.dialect) { c.original.dialect.clone() } else { String::new() };
    let action = format!("/compare/{}/translate", c.edited.id);
    html! {
        form method="get" action=(action) class="translate" id="translate" {
            "The as-run program (revision " (c.edited.id) "), written for "
            select name="to" aria-label="target dialect" {
                @if default.is_empty() { option value="" selected { "the CAM original's dialect" } }
                @for n in &names {
                    option value=(n) selected[*n == default] { (n) @if *n == default { " (the CAM original's)" } }
                }
            }
            " "
            button type="submit" data-translate="download" { "Download" }
            " "
            button type="submit" formaction={(action) "/notes"} data-translate="notes" { "Show the notes" }
        }
        p class="muted" {
            "Read in its own dialect and written by the target's output rules, as "
            code { "ncplan translate --revision " (c.edited.id) " --to DIALECT" } " writes it: macros, loops and subprograms come out unrolled."
        }
    }
}

/// The notes page of a translation, with its download link.
pub(crate) fn translate_notes(t: &Translated, revision: i64) -> Markup {
    html! {
        h1 { "Translation of revision " (revision) " into " (t.dialect) }
        p {
            "Read as " (t.from) ", written as " (t.dialect) ": " (t.bytes.len()) " bytes. "
            a href={"/compare/" (revision) "/translate?to=" (t.dialect)} download=(t.filename) id="download" { "Download " (t.filename) }
            " · " a href={"/compare/" (revision)} { "back to the comparison" }
        }
        @if t.errors { p class="bad" { "The program has errors: the notes say what was not written." } }
        @if t.notes.is_empty() {
            p id="notes" { "No notes: everything was written as it was read." }
        } @else {
            h2 { "Notes (" (t.notes.len()) ")" }
            pre id="notes" class="finding" { @for n in &t.notes { (n) "\n" } }
        }
    }
}

/// `GET /compare/{revision}/translate?to=D`: the translated program as an attachment.
pub(super) async fn download(
    State(s): State<Arc<super::Server>>,
    headers: HeaderMap,
    Path(revision): Path<i64>,
    Query(q): Query<BTreeMap<String, String>>,
) -> Response {
    if super::auth::context(&s, &headers).await.is_none() {
        return Redirect::to("/login").into_response();
    }
    let to = q.get("to").cloned();
    let result = tokio::task::spawn_blocking(move || {
        let store = s.store()?;
        translate(&s, &store, revision, to.as_deref())
    })
    .await;
    let mut response = match result {
        Ok(Ok(t)) if t.bytes.is_empty() && t.errors => {
            (StatusCode::UNPROCESSABLE_ENTITY, format!("the translation is refused: nothing was written\n{}", t.notes.join("\n")))
                .into_response()
        }
        Ok(Ok(t)) => {
            let disposition = format!("attachment; filename=\"{}\"", t.filename);
            let mut r = t.bytes.into_response();
            let h = r.headers_mut();
            h.insert(header::CONTENT_TYPE, HeaderValue::from_static("text/plain; charset=utf-8"));
            if let Ok(v) = HeaderValue::from_str(&disposition) {
                h.insert(header::CONTENT_DISPOSITION, v);
            }
            // How many notes the translation has; the notes page shows them.
            h.insert("x-ncplan-notes", HeaderValue::from(t.notes.len()));
            r
        }
        Ok(Err(e)) if e.downcast_ref::<NotFound>().is_some() => (StatusCode::NOT_FOUND, format!("{e:#}")).into_response(),
        Ok(Err(e)) => (StatusCode::INTERNAL_SERVER_ERROR, format!("{e:#}")).into_response(),
        Err(e) => (StatusCode::INTERNAL_SERVER_ERROR, format!("the translation failed: {e}")).into_response(),
    };
    response.headers_mut().insert("x-content-type-options", HeaderValue::from_static("nosniff"));
    response
}

/// `GET /compare/{revision}/translate/notes?to=D`: what the translation says, and its download link.
pub(super) async fn notes(
    State(s): State<Arc<super::Server>>,
    headers: HeaderMap,
    Path(revision): Path<i64>,
    Query(q): Query<BTreeMap<String, String>>,
) -> Response {
    let to = q.get("to").cloned();
    super::page(s, headers, move |s, ctx, store| {
        let t = translate(s, store, revision, to.as_deref())?;
        Ok(super::layout::layout(Some(ctx), &format!("Translation of revision {revision}"), translate_notes(&t, revision)))
    })
    .await
}

/// A rendered page with every bidirectional control written out (`[U+202E]`): the templates
/// hold none, so any is program text (a name, a path, a query's result), and it is shown,
/// never obeyed.
pub(super) fn shown(html: String) -> String {
    match source::visible(&html) {
        std::borrow::Cow::Borrowed(_) => html,
        std::borrow::Cow::Owned(o) => o,
    }
}

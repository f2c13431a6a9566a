//! The pages of `ncplan serve`, as maud templates over the store's read queries.

use std::collections::BTreeMap;

use anyhow::Result;
use maud::{Markup, html};

use super::compare;
use super::layout::layout;
use super::{Ctx, NotFound, Server};
use crate::store::{ChangeFilter, ChangeRow, KNOWLEDGE, SAVED_QUERIES, Store};

/// A page that only says something (not found, an error).
pub(super) fn message(title: &str, text: &str) -> Markup {
    layout(None, title, html! { h1 { (title) } p class="error" { (text) } })
}

/// The sign-in page.
pub(super) fn login(required: bool, failed: bool) -> Markup {
    layout(
        None,
        "Sign in",
        html! {
            h1 { "Sign in" }
            @if !required { p { "No users are configured: nobody needs to sign in. " a href="/" { "Go to the overview" } } }
            @if failed { p class="error" { "Wrong name or password." } }
            form method="post" action="/login" class="search" {
                label { "Name" input type="text" name="name" autocomplete="username"; }
                label { "Password" input type="password" name="password" autocomplete="current-password"; }
                button type="submit" { "Sign in" }
            }
        },
    )
}

/// A change as a row of a list: machine, program, its sentence, linked to its comparison.
fn change_list(rows: &[ChangeRow]) -> Markup {
    html! {
        table {
            tr { th { "detected" } th { "machine" } th { "program" } th { "change" } th { "review" } }
            @for r in rows {
                tr {
                    td class="muted" { (r.detected_at.get(..16).unwrap_or(&r.detected_at)) }
                    td { a href={"/machine/" (urlencode(&r.machine))} { (r.machine) } }
                    td { (r.program) }
                    td {
                        a href={"/compare/" (r.revision_id) "#change-" (r.id)} {
                            "workingstep " (r.change.workingstep) " (" (r.change.operation) "): " (r.change.phrase())
                        }
                    }
                    td {
                        @match r.marks.last() {
                            Some(m) => span class={"pill " (m.mark)} { (m.mark) " · " (m.by) },
                            None => span class="pill" { "to review" },
                        }
                    }
                }
            }
        }
    }
}

/// Percent-encodes a path segment.
pub(super) fn urlencode(s: &str) -> String {
    let mut out = String::new();
    for b in s.bytes() {
        if b.is_ascii_alphanumeric() || matches!(b, b'-' | b'_' | b'.' | b'~') {
            out.push(b as char);
        } else {
            out.push_str(&format!("%{b:02X}"));
        }
    }
    out
}

/// A stacked bar chart of changes per week per machine, as SVG.
fn week_chart(weeks: &[(String, String, i64)]) -> Markup {
    let mut by_week: BTreeMap<&str, Vec<(&str, i64)>> = BTreeMap::new();
    let mut machines: Vec<&str> = Vec::new();
    for (w, m, n) in weeks {
        by_week.entry(w.as_str()).or_default().push((m.as_str(), *n));
        if !machines.contains(&m.as_str()) {
            machines.push(m.as_str());
        }
    }
    machines.sort_unstable();
    let colours = ["#1f6fd1", "#e07b00", "#2e9e55", "#8a2fb5", "#c7283e", "#0f8b8d", "#b58a00", "#5a6acf", "#7a5230", "#d45fa0"];
    let index = |m: &str| machines.iter().position(|x| *x == m).unwrap_or(0) % colours.len();
    let colour = |m: &str| colours[index(m)];
    // The legend's swatches by class (`.legend i.sw0`…, the same colours in app.css): no
    // inline style under the Content-Security-Policy.
    let swatch = |m: &str| format!("sw{}", index(m));
    let max = by_week.values().map(|v| v.iter().map(|x| x.1).sum::<i64>()).max().unwrap_or(1).max(1);
    let (w, h, left, bottom) = (560.0, 180.0, 30.0, 22.0);
    let slot = ((w - left) / (by_week.len().max(1) as f64)).min(60.0);
    // Each bar: x, y, height, colour, title.
    let mut bars: Vec<(f64, f64, f64, &str, String)> = Vec::new();
    let mut labels: Vec<(f64, &str)> = Vec::new();
    for (i, (week, parts)) in by_week.iter().enumerate() {
        let x = left + slot * i as f64 + slot * 0.15;
        let mut y = h - bottom;
        for (m, n) in parts {
            let bh = (*n as f64) / (max as f64) * (h - bottom - 16.0);
            y -= bh;
            bars.push((x, y, bh, colour(m), format!("{m}, {week}: {n}")));
        }
        labels.push((x, week.get(5..).unwrap_or(week)));
    }
    html! {
        svg class="chart" viewBox={"0 0 " (w) " " (h)} width=(w) height=(h) role="img" {
            title { "changes per week per machine" }
            line x1=(left) y1=(h - bottom) x2=(w) y2=(h - bottom) stroke="#999" {}
            text x="2" y="12" font-size="10" fill="#666" { (max) }
            @for (x, y, bh, c, t) in &bars {
                rect class="bar" x=(format!("{x:.1}")) y=(format!("{y:.1}")) width=(format!("{:.1}", slot * 0.7)) height=(format!("{bh:.1}")) fill=(c) {
                    title { (t) }
                }
            }
            @for (x, l) in &labels { text x=(format!("{x:.1}")) y=(h - 6.0) font-size="9" fill="#555" { (l) } }
        }
        p class="legend" {
            @for m in &machines { span { i class=(swatch(m)) {} (m) } }
        }
    }
}

/// The overview: the review queue per machine, recent changes, the weekly chart, the most
/// edited programs, recurring change kinds and the daemon's health.
pub(super) fn overview(s: &Server, ctx: &Ctx, store: &Store) -> Result<Markup> {
    let machines = store.machines()?;
    let recent = store.search_changes(&ChangeFilter::default(), 15)?;
    let weeks = store.changes_per_week(12)?;
    let edited = store.most_edited(10)?;
    let kinds = store.kind_counts()?;
    let errors = store.error_revisions(10)?;
    let last: BTreeMap<String, String> = store.last_seen_per_folder()?.into_iter().collect();
    let queue: i64 = machines.iter().map(|m| m.to_review).sum();
    Ok(layout(
        Some(ctx),
        "Overview",
        html! {
            h1 { "Overview" }
            div class="grid" {
                section class="card" id="queue" {
                    h2 { "Waiting for review (" (queue) ")" }
                    table {
                        tr { th { "machine" } th class="num" { "to review" } th class="num" { "programs" } th { "last revision" } }
                        @for m in &machines {
                            tr {
                                td { a href={"/machine/" (urlencode(&m.name))} { (m.name) } }
                                td class="num" { a href={"/search?to_review=1&machine=" (urlencode(&m.name))} data-queue=(m.name) { (m.to_review) } }
                                td class="num" { (m.programs) }
                                td class="muted" { (m.last_seen.as_deref().unwrap_or("never")) }
                            }
                        }
                    }
                }
                section class="card" {
                    h2 { "Changes per week" }
                    @if weeks.is_empty() { p class="muted" { "No changes yet." } } @else { (week_chart(&weeks)) }
                }
            }
            section class="card" {
                h2 { "Recent changes" }
                (change_list(&recent))
            }
            div class="grid" {
                section class="card" {
                    h2 { "Most edited programs" }
                    table {
                        tr { th { "machine" } th { "program" } th class="num" { "edited revisions" } th class="num" { "changes" } }
                        @for p in &edited {
                            tr {
                                td { (p.machine) }
                                td { a href={"/program/" (p.program_id)} { (p.program) } }
                                td class="num" { (p.edited_revisions) }
                                td class="num" { (p.changes) }
                            }
                        }
                    }
                }
                section class="card" {
                    h2 { "Change kinds that recur" }
                    table {
                        tr { th { "kind" } th class="num" { "times" } }
                        @for (k, n) in &kinds {
                            tr { td { a href={"/search?kind=" (k)} { (k.replace('_', " ")) } } td class="num" { (n) } }
                        }
                    }
                }
            }
            section class="card" id="health" {
                h2 { "Daemon health" }
                table {
                    tr { th { "share" } th { "folder" } th { "state" } th { "last revision seen" } }
                    @for f in &s.config.folders {
                        @let path = crate::sharefile::path_text(&f.path);
                        @let readable = std::fs::read_dir(&f.path).is_ok();
                        tr {
                            td { @if f.role == crate::config::Role::Cam { "CAM originals" } @else { "machine " (f.name) } }
                            td class="muted" { (path) }
                            td { @if readable { span class="ok" { "readable" } } @else { span class="bad" { "dead: cannot be read" } } }
                            td class="muted" {
                                (last.get(if f.role == crate::config::Role::Cam { "cam" } else { path.as_str() }).map_or("never", String::as_str))
                            }
                        }
                    }
                }
                h3 { "Revisions with errors" }
                @if errors.is_empty() { p class="muted" { "None." } }
                table {
                    @for e in &errors {
                        tr { td { (e.id) } td { (e.path) } td class="muted" { (e.seen_at) } td class="num bad" { (e.errors) " errors" } }
                    }
                }
            }
        },
    ))
}

/// A machine: its dialect and share, its programs with their last revision.
pub(super) fn machine(s: &Server, ctx: &Ctx, store: &Store, name: &str) -> Result<Markup> {
    let _ = s;
    let m = store.machine(name)?.ok_or_else(|| NotFound(format!("no machine `{name}`")))?;
    let programs = store.machine_programs(name)?;
    Ok(layout(
        Some(ctx),
        &m.name,
        html! {
            h1 { "Machine " (m.name) }
            p { "Dialect " strong { (m.dialect) } ", share " code { (m.folder) } ". "
                (m.revisions) " revisions of " (m.programs) " programs; "
                a href={"/search?to_review=1&machine=" (urlencode(&m.name))} { (m.to_review) " changes to review" } "." }
            table {
                tr { th { "program" } th { "path" } th class="num" { "revisions" } th { "last seen" } th class="num" { "size" } th class="num" { "changes" } th {} }
                @for p in &programs {
                    tr {
                        td { a href={"/program/" (p.id)} { (p.name) } }
                        td class="muted" { (p.path) }
                        td class="num" { (p.revisions) }
                        td class="muted" { (p.last_seen) }
                        td class="num" { (p.size) }
                        td class="num" { (p.changes) }
                        td { @if p.changes > 0 { a href={"/compare/" (p.last_revision)} { "comparison" } } }
                    }
                }
            }
        },
    ))
}

/// A program: its revisions on a timeline, and its CAM originals.
pub(super) fn program(s: &Server, ctx: &Ctx, store: &Store, id: i64) -> Result<Markup> {
    let _ = s;
    let p = store.program(id)?.ok_or_else(|| NotFound(format!("no program {id}")))?;
    let timeline = store.timeline(id)?;
    let originals = store.originals_of(id)?;
    Ok(layout(
        Some(ctx),
        &p.name,
        html! {
            h1 { "Program " (p.name) }
            p {
                code { (p.path) } " · " (p.dialect) " · "
                @match &p.machine { Some(m) => { "machine " a href={"/machine/" (urlencode(m))} { (m) } }, None => "CAM original" }
            }
            @if !originals.is_empty() {
                h2 { "CAM originals" }
                ul { @for (pid, path, rev) in &originals { li { a href={"/program/" (pid)} { (path) } span class="muted" { " · newest revision " (rev) } } } }
            }
            h2 { "Revisions" }
            table class="timeline" {
                tr { th { "revision" } th { "seen" } th class="num" { "size" } th { "sha-256" } th class="num" { "findings" } th { "compared with" } th {} }
                @for r in timeline.iter().rev() {
                    tr {
                        td { (r.id) }
                        td { (r.seen_at) }
                        td class="num" { (r.size) }
                        td class="muted" { code { (r.hash.get(..12).unwrap_or(&r.hash)) } }
                        td class="num" { (r.findings.0) @if r.findings.1 > 0 { " " span class="bad" { "(" (r.findings.1) " errors)" } } }
                        td {
                            @if r.partial { span class="muted" { "partial write" } }
                            @else if let Some((oid, path, rule, n)) = &r.original { (path) " rev " (oid) " by " (rule) ": " (n) " changes" }
                            @else if r.status != "analysed" { span class="muted" { (r.status) } }
                        }
                        td { @if r.original.is_some() { a href={"/compare/" (r.id)} { "comparison" } } }
                    }
                }
            }
        },
    ))
}

/// The comparison page.
pub(super) fn comparison(s: &Server, ctx: &Ctx, store: &Store, revision: i64) -> Result<Markup> {
    let c = compare::load(store, revision, s)?;
    let program = store.program_of(revision)?;
    Ok(layout(
        Some(ctx),
        &format!("{} revision {}", c.edited.name, c.edited.id),
        html! {
            h1 {
                "Comparison: " (c.edited.name)
                @if let Some(p) = program { " " a class="muted" href={"/program/" (p)} { "(all revisions)" } }
            }
            (compare::heading(&c))
            section class="card" { h2 { "Changes" } (compare::sentences(&c, Some(ctx))) }
            section class="card" { h2 { "Toolpaths" } (compare::picture_block(&c, true)) }
            section class="card" { h2 { "Translate" } (compare::translate_form(s, &c)) }
            section class="card" { h2 { "Source" } (compare::sources(&c, 20_000)) }
            section class="card" {
                h2 { "Findings" }
                (compare::findings("Original", &c.texts.0, &c.findings.0))
                (compare::findings("Edited", &c.texts.1, &c.findings.1))
            }
        },
    ))
}

/// The knowledge pages' index.
pub(super) fn knowledge_index(s: &Server, ctx: &Ctx, store: &Store) -> Result<Markup> {
    let _ = (s, store);
    Ok(layout(
        Some(ctx),
        "Knowledge",
        html! {
            h1 { "Knowledge" }
            p { "What the shopfloor keeps changing, so that the CAM templates can be fixed." }
            p class="lead" {
                a href="/suggestions" { "Suggestions for CAM" }
                ": the overrides operators keep making, as corrected cutting data with their evidence, to accept and export to the CAM tool library."
            }
            ul { @for k in KNOWLEDGE { li { a href={"/knowledge/" (k.name)} { (k.title) } } } }
        },
    ))
}

/// The first number in a value such as `800 mm/min, 1200 mm/min` or `S1200`.
fn first_number(s: &str) -> Option<f64> {
    let start = s.find(|c: char| c.is_ascii_digit() || c == '-' || c == '.')?;
    let rest = &s[start..];
    let end = rest.find(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-')).unwrap_or(rest.len());
    rest[..end].parse().ok()
}

fn median(v: &mut [f64]) -> Option<f64> {
    if v.is_empty() {
        return None;
    }
    v.sort_by(f64::total_cmp);
    let n = v.len();
    Some(if n % 2 == 1 { v[n / 2] } else { (v[n / 2 - 1] + v[n / 2]) / 2.0 })
}

/// A table of rows as text.
fn table(cols: &[String], rows: &[Vec<String>]) -> Markup {
    html! {
        table {
            tr { @for c in cols { th { (c) } } }
            @for r in rows { tr { @for v in r { td { (v) } } } }
        }
    }
}

/// Feeds and speeds, as run versus as posted, with the median override per tool, machine and program.
fn feeds(rows: &[Vec<String>]) -> Markup {
    // Columns: kind, machine, program, tool_kind, diameter, posted, run.
    let mut groups: BTreeMap<(String, String, String), Vec<f64>> = BTreeMap::new();
    for r in rows {
        let (Some(p), Some(a)) = (first_number(&r[5]), first_number(&r[6])) else { continue };
        if p.abs() < 1e-9 {
            continue;
        }
        let what = if r[0] == "feed_changed" { "feed" } else { "spindle speed" }.to_owned();
        let tool = format!("{} D{}", r[3].replace('_', " "), r[4]);
        for key in [("tool", tool), ("machine", r[1].clone()), ("program", format!("{} on {}", r[2], r[1]))] {
            groups.entry((what.clone(), key.0.to_owned(), key.1)).or_default().push(a / p);
        }
    }
    html! {
        @for by in ["tool", "machine", "program"] {
            h2 { "Per " (by) }
            table {
                tr { th { "value" } th { (by) } th class="num" { "changes" } th class="num" { "median override" } }
                @for ((what, b, key), v) in &groups {
                    @if b == by {
                        @let n = v.len();
                        @let m = median(&mut v.clone()).unwrap_or(1.0);
                        tr { td { (what) } td { (key) } td class="num" { (n) } td class="num" { (format!("{:.0} %", m * 100.0)) } }
                    }
                }
            }
        }
        h2 { "Every change, as posted and as run" }
    }
}

/// A knowledge page, with a link that shows its SQL.
pub(super) fn knowledge(s: &Server, ctx: &Ctx, store: &Store, name: &str, show_sql: bool) -> Result<Markup> {
    let _ = s;
    let k = KNOWLEDGE.iter().find(|k| k.name == name).ok_or_else(|| NotFound(format!("no knowledge page `{name}`")))?;
    let sql = store.knowledge_sql(k);
    let (cols, rows) = store.query(sql)?;
    Ok(layout(
        Some(ctx),
        k.title,
        html! {
            h1 { (k.title) }
            p class="noprint" {
                @if show_sql { a href={"/knowledge/" (k.name)} { "Hide the SQL" } } @else { a href={"/knowledge/" (k.name) "?sql"} class="show-sql" { "Show the SQL" } }
                " · " a href={"/sql?q=" (urlencode(sql))} { "Open it in the SQL console" }
            }
            @if show_sql { pre class="sql" { (sql) } }
            @if rows.is_empty() { p class="muted" { "Nothing recorded yet." } }
            @if k.name == "feeds" { (feeds(&rows)) }
            (table(&cols, &rows))
        },
    ))
}

/// What the console does with its query.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Console {
    /// Shows it in the form (a link's `GET /sql?q=…`): nothing runs.
    Show,
    /// Runs it (the form's `POST /sql` with the session's CSRF token).
    Run,
    /// Would run it, but the console is busy with as many queries as it runs at once.
    Busy,
}

/// The read-only SQL console: saved queries (the built-in ones, the knowledge pages' and the
/// planners'), a form that runs the query by POST, a form to save it, a row limit, a time limit.
pub(super) fn sql_console(s: &Server, ctx: &Ctx, store: &Store, query: &str, refused: Option<&str>, mode: Console) -> Result<Markup> {
    let _ = s;
    const ROWS: usize = 1000;
    const TIME: std::time::Duration = std::time::Duration::from_secs(2);
    let result = (mode == Console::Run && !query.trim().is_empty()).then(|| store.query_limited(query, ROWS, TIME));
    let saved = store.saved_queries()?;
    Ok(layout(
        Some(ctx),
        "SQL",
        html! {
            h1 { "SQL console" }
            p class="muted" { "One read-only statement on a read-only connection; at most " (ROWS) " rows and " (TIME.as_secs()) " s." }
            form method="post" action="/sql" {
                input type="hidden" name="csrf" value=(ctx.csrf);
                textarea class="sql" name="q" { (query) }
                button type="submit" { "Run" }
            }
            @if !query.trim().is_empty() {
                form method="post" action="/sql/save" class="save-query" {
                    input type="hidden" name="csrf" value=(ctx.csrf);
                    input type="hidden" name="q" value=(query);
                    @if !ctx.auth { input type="text" name="by" placeholder="your name"; }
                    input type="text" name="name" placeholder="name" required maxlength="200";
                    button type="submit" { "Save this query" }
                }
            }
            @if let Some(e) = refused { p class="error" { "Not saved: " (e) } }
            @if mode == Console::Busy {
                p class="error" id="busy" { "The console is busy: " (super::CONSOLE_AT_ONCE) " queries are running. Try again in a moment." }
            }
            @match &result {
                Some(Ok((cols, rows, more))) => {
                    p id="result" { (rows.len()) " rows" @if *more { " (more left off at the row limit)" } }
                    (table(cols, rows))
                },
                Some(Err(e)) => p class="error" { (e) },
                None => {},
            }
            h3 { "Saved queries" }
            ul { @for (title, sql) in SAVED_QUERIES { li { a href={"/sql?q=" (urlencode(sql))} { (title) } } } }
            h3 { "The knowledge pages' queries" }
            ul { @for k in KNOWLEDGE { li { a href={"/sql?q=" (urlencode(store.knowledge_sql(k)))} { (k.title) } } } }
            h3 { "Saved by planners" }
            @if saved.is_empty() { p class="muted" { "None yet." } }
            ul id="saved" {
                @for sq in &saved {
                    li { a href={"/sql?q=" (urlencode(&sq.sql))} { (sq.name) } span class="muted" { " · " (sq.by) ", " (sq.at) } }
                }
            }
        },
    ))
}

/// Search by program name or number, machine, date range and change kind.
pub(super) fn search(s: &Server, ctx: &Ctx, store: &Store, q: &BTreeMap<String, String>) -> Result<Markup> {
    let _ = s;
    let get = |k: &str| q.get(k).cloned().unwrap_or_default();
    let filter = ChangeFilter {
        program: get("program"),
        machine: get("machine"),
        since: get("since"),
        until: get("until"),
        kind: get("kind"),
        to_review: q.get("to_review").is_some_and(|v| v == "1" || v == "on"),
    };
    let rows = store.search_changes(&filter, 500)?;
    let machines = store.machines()?;
    let kinds = store.kind_counts()?;
    let title = if filter.to_review { "Review queue" } else { "Search" };
    Ok(layout(
        Some(ctx),
        title,
        html! {
            h1 { (title) }
            form method="get" action="/search" class="search" {
                label { "Program name or number" input type="text" name="program" value=(filter.program); }
                label { "Machine"
                    select name="machine" {
                        option value="" { "any" }
                        @for m in &machines { option value=(m.name) selected[m.name == filter.machine] { (m.name) } }
                    }
                }
                label { "From" input type="date" name="since" value=(filter.since); }
                label { "To" input type="date" name="until" value=(filter.until); }
                label { "Change kind"
                    select name="kind" {
                        option value="" { "any" }
                        @for (k, _) in &kinds { option value=(k) selected[*k == filter.kind] { (k.replace('_', " ")) } }
                    }
                }
                label { "Waiting for review" input type="checkbox" name="to_review" value="1" checked[filter.to_review]; }
                button type="submit" { "Search" }
            }
            p id="result-count" { (rows.len()) " changes" @if rows.len() == 500 { " (the first 500)" } }
            (change_list(&rows))
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn overrides_come_from_the_first_numbers() {
        assert_eq!(first_number("800 mm/min, 1200 mm/min"), Some(800.0));
        assert_eq!(first_number("S1200"), Some(1200.0));
        assert_eq!(median(&mut [1.5, 0.5, 1.0]), Some(1.0));
        assert_eq!(median(&mut [1.0, 2.0]), Some(1.5));
        assert_eq!(urlencode("DMU 50/<x>"), "DMU%2050%2F%3Cx%3E");
    }

    #[test]
    fn program_text_is_escaped() {
        let m = message("t", "(<script>alert(1)</script>\" onload=x)");
        let s = m.into_string();
        assert!(s.contains("&lt;script&gt;") && !s.contains("<script>alert"), "{s}");
    }
}

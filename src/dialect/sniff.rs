//! Telling a program's dialect from its text and file name, for folders with no dialect
//! configured. Each dialect file lists its own evidence (`<recognise>`: file extensions and
//! regular expressions with weights); the engine only adds the weights up and compares.

use super::{Dialect, Registry};

/// One piece of evidence a dialect file lists.
#[derive(Clone, Debug)]
pub enum Marker {
    /// The file name ends in `.ext` (case-insensitive).
    Extension(String),
    /// The text matches.
    Pattern(super::Pattern),
}

/// Evidence with its weight.
#[derive(Clone, Debug)]
pub struct Evidence {
    /// What to look for.
    pub marker: Marker,
    /// How much it counts.
    pub weight: u32,
    /// How it is shown in reports (`BEGIN PGM`, `.h`).
    pub label: String,
}

/// How sure a guess is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Confidence {
    /// No evidence, or a tie: the default was taken.
    Low,
    /// More evidence than for any other dialect.
    Medium,
    /// Strong evidence, at least twice that for any other dialect.
    High,
}

impl Confidence {
    /// `high`, `medium`, `low`.
    pub fn as_str(self) -> &'static str {
        match self {
            Confidence::Low => "low",
            Confidence::Medium => "medium",
            Confidence::High => "high",
        }
    }
}

/// The outcome of [`Registry::sniff`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Sniffed {
    /// The dialect chosen.
    pub dialect: String,
    /// How sure.
    pub confidence: Confidence,
    /// The evidence found for it.
    pub evidence: Vec<String>,
    /// The next best dialect and its score, if any had evidence.
    pub runner_up: Option<(String, u32)>,
    /// The chosen dialect's score.
    pub score: u32,
}

/// How much of a file is looked at.
const SNIFF_BYTES: usize = 64 * 1024;

/// Scores at or above this, with twice the runner-up's, are sure.
const SURE: u32 = 20;

fn score(d: &Dialect, text: &str, file_name: Option<&str>) -> (u32, Vec<String>) {
    let ext = file_name.and_then(|n| n.rsplit_once('.')).map(|(_, e)| e.to_ascii_lowercase());
    let mut total = 0;
    let mut found = Vec::new();
    for e in &d.recognise {
        let hit = match &e.marker {
            Marker::Extension(x) => ext.as_deref() == Some(x.as_str()),
            Marker::Pattern(re) => re.regex().is_match(text.as_bytes()),
        };
        if hit {
            total += e.weight;
            found.push(e.label.clone());
        }
    }
    (total, found)
}

impl Registry {
    /// The dialect whose evidence best matches the start of `text` and `file_name`; with no
    /// evidence at all, `default` with low confidence. Ties go to the name first in order.
    pub fn sniff(&self, text: &str, file_name: Option<&str>, default: &str) -> Sniffed {
        let mut end = text.len().min(SNIFF_BYTES);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let head = &text[..end];
        let mut scores: Vec<(u32, String, Vec<String>)> = self
            .names()
            .filter_map(|n| self.get(n))
            .map(|d| {
                let (s, ev) = score(&d, head, file_name);
                (s, d.name.clone(), ev)
            })
            .collect();
        // Highest score first; names break ties (the registry iterates in name order).
        scores.sort_by(|a, b| b.0.cmp(&a.0).then_with(|| a.1.cmp(&b.1)));
        let best = scores.first().filter(|b| b.0 > 0);
        let runner_up = scores.get(1).filter(|r| r.0 > 0).map(|r| (r.1.clone(), r.0));
        match best {
            None => Sniffed { dialect: default.to_owned(), confidence: Confidence::Low, evidence: Vec::new(), runner_up: None, score: 0 },
            Some((s, name, ev)) => {
                let second = runner_up.as_ref().map_or(0, |r| r.1);
                let confidence = if *s >= SURE && *s >= 2 * second {
                    Confidence::High
                } else if *s > second {
                    Confidence::Medium
                } else {
                    Confidence::Low
                };
                Sniffed { dialect: name.clone(), confidence, evidence: ev.clone(), runner_up, score: *s }
            }
        }
    }
}

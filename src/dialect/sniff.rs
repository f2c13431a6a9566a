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

/// Every dialect's evidence patterns in one expression: a single pass over the text tells
/// which of them match, and building one costs a third of building each.
#[derive(Clone, Debug)]
pub(super) struct EvidenceSet {
    regex: regex_automata::meta::Regex,
    /// Per pattern, in order: its dialect and its place in that dialect's evidence.
    owners: Vec<(String, usize)>,
}

/// The (dialect, evidence index) of the patterns that matched.
type Matched<'s> = std::collections::BTreeSet<(&'s str, usize)>;

impl EvidenceSet {
    /// `None` when the patterns cannot be built together (past a size limit): each is then
    /// tried on its own.
    fn build(registry: &Registry) -> Option<EvidenceSet> {
        let mut sources = Vec::new();
        let mut owners = Vec::new();
        for name in registry.names() {
            let d = registry.get(name)?;
            for (k, e) in d.recognise.iter().enumerate() {
                if let Marker::Pattern(p) = &e.marker {
                    sources.push(p.source().to_owned());
                    owners.push((name.to_owned(), k));
                }
            }
        }
        let all = regex_automata::meta::Config::new().match_kind(regex_automata::MatchKind::All);
        let regex = super::pattern_builder(all).build_many(&sources).ok()?;
        Some(EvidenceSet { regex, owners })
    }

    /// Every pattern that matches somewhere in `text`.
    fn matches(&self, text: &str) -> Matched<'_> {
        let mut set = regex_automata::PatternSet::new(self.regex.pattern_len());
        self.regex.which_overlapping_matches(&regex_automata::Input::new(text.as_bytes()), &mut set);
        set.iter().map(|p| (self.owners[p.as_usize()].0.as_str(), self.owners[p.as_usize()].1)).collect()
    }
}

fn score(d: &Dialect, text: &str, file_name: Option<&str>, matched: Option<&Matched<'_>>) -> (u32, Vec<String>) {
    let ext = file_name.and_then(|n| n.rsplit_once('.')).map(|(_, e)| e.to_ascii_lowercase());
    let mut total = 0;
    let mut found = Vec::new();
    for (k, e) in d.recognise.iter().enumerate() {
        let hit = match &e.marker {
            Marker::Extension(x) => ext.as_deref() == Some(x.as_str()),
            Marker::Pattern(re) => match matched {
                Some(m) => m.contains(&(d.name.as_str(), k)),
                None => re.regex().is_match(text.as_bytes()),
            },
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
        let set = self.evidence.get_or_init(|| EvidenceSet::build(self));
        let matched = set.as_ref().map(|s| s.matches(head));
        let mut scores: Vec<(u32, String, Vec<String>)> = self
            .names()
            .filter_map(|n| self.get(n))
            .map(|d| {
                let (s, ev) = score(&d, head, file_name, matched.as_ref());
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The combined expression finds exactly the evidence each pattern finds on its own.
    #[test]
    fn the_evidence_set_matches_as_each_pattern_does() {
        let r = Registry::shipped();
        let set = EvidenceSet::build(&r).expect("the shipped patterns build together");
        let texts = [
            "%\nO1234\nG90 G54 X10. Y-2.\n#1=5\nWHILE [#1 GT 0] DO 1\nM98 P100\nM30\n%\n",
            "%_N_PART_MPF\n;$PATH=/_N_WKS_DIR\nDEF REAL X1\nCYCLE81(10, 0, 2, -5)\nG2 X10 CR=5\nGOTOF END\n",
            "0 BEGIN PGM P1 MM\n1 TOOL CALL 1 Z S1000\n2 L X+10 Y-5 FMAX M3\n3 CYCL DEF 200\n",
            "o<probe> sub\n#<depth> = 2\n(debug, x)\nG64 P0.01\nZ10\n",
            "$SHAFT.MIN%\nCALL OTBOX PZ=-5.\nVC1=2\nG96 S200\nG85 N10 D2\nVGRIN[1]=1\nRTS\n",
            "(MACH3)\nG31 Z-5 F50\nM11P1\n(HAAS)\nM97 P10\nG187 P1\n#CALL SUB\n$IF X\n%L 100\n",
            "caf\u{e9} X1 \u{fffd}\n",
        ];
        for text in texts {
            let matched = set.matches(text);
            for name in r.names() {
                let d = r.get(name).unwrap();
                assert_eq!(score(&d, text, Some("p.nc"), Some(&matched)), score(&d, text, Some("p.nc"), None), "{name} on {text:?}");
            }
        }
    }
}

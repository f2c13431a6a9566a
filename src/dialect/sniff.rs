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
    /// Evidence against the dialect (a mill's Y words for a lathe): the weight is taken off.
    pub against: bool,
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
    /// The dialects the evidence does not tell apart from the chosen one, best first, the
    /// chosen one among them: weak evidence (no more than half of [`SURE`] beyond what they
    /// share, or less than twice theirs) leaves the choice to the first reading without an
    /// error ([`crate::pipeline::sniff`]). Only dialects of the winner's lineage (that
    /// descend from the base it descends from) are candidates: another language's reading
    /// (APT, Klartext) is no alternative. Empty when the evidence sets the winner apart, or
    /// there is none.
    pub candidates: Vec<String>,
}

impl Sniffed {
    /// Whether the dialect is a guess: low confidence (no evidence, a tie, evidence another
    /// maker's dictionary shares, or evidence against it), so nothing in the text shows a code
    /// of the maker's own. A reading on it keeps findings that hold for that maker alone as
    /// warnings ([`crate::interp::Profile::guessed`]).
    pub fn guessed(&self) -> bool {
        self.confidence == Confidence::Low
    }
}

/// How much of a file is looked at.
const SNIFF_BYTES: usize = 64 * 1024;

/// Of a text longer than [`SNIFF_BYTES`], its last this many bytes are read too (from a line
/// start): how a program ends (`/M99` then `M30`, `END PGM`, `M17`) is told at its end.
const SNIFF_TAIL: usize = 4 * 1024;

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

/// The dialect's own evidence found: weight and label of each.
fn score(d: &Dialect, text: &str, file_name: Option<&str>, matched: Option<&Matched<'_>>) -> Vec<(i64, String)> {
    let ext = file_name.and_then(|n| n.rsplit_once('.')).map(|(_, e)| e.to_ascii_lowercase());
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
            let w = i64::from(e.weight);
            found.push((if e.against { -w } else { w }, e.label.clone()));
        }
    }
    found
}

impl Registry {
    /// `name`, the dialect it extends, that one's base, and so on (at most 16 levels).
    fn lineage<'a>(&'a self, name: &'a str) -> Vec<&'a str> {
        let mut out = vec![name];
        while let Some(base) = self.get(out[out.len() - 1]).and_then(|d| d.extends.clone()) {
            match self.names().find(|n| *n == base) {
                Some(n) if !out.contains(&n) && out.len() < 16 => out.push(n),
                _ => break,
            }
        }
        out
    }

    /// The dialect whose evidence best matches the start of `text` and `file_name`; with no
    /// evidence at all, `default` with low confidence.
    ///
    /// A derived dialect counts its base's evidence as well as its own, so it ties with its
    /// base unless it has evidence of its own, and a tie goes to the base (then to the name
    /// first in order). How sure the choice is compares what sets the winner apart from each
    /// other dialect: the evidence above the one dialect both descend from, if any. A
    /// derived dialect chosen over its base is sure only with own evidence worth half of
    /// [`SURE`]; a base that a dialect of another family derived from it matches as well is
    /// not sure of the maker, and a winner with evidence against it is a guess (both low).
    pub fn sniff(&self, text: &str, file_name: Option<&str>, default: &str) -> Sniffed {
        let mut end = text.len().min(SNIFF_BYTES);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let joined;
        let head = if text.len() > end {
            let mut t = text.len().saturating_sub(SNIFF_TAIL).max(end);
            while !text.is_char_boundary(t) {
                t += 1;
            }
            let t = text[t..].find('\n').map_or(text.len(), |p| t + p + 1);
            joined = format!("{}\n{}", &text[..end], &text[t..]);
            joined.as_str()
        } else {
            &text[..end]
        };
        let set = self.evidence.get_or_init(|| EvidenceSet::build(self));
        let matched = set.as_ref().map(|s| s.matches(head));
        let own: std::collections::BTreeMap<&str, Vec<(i64, String)>> =
            self.names().filter_map(|n| self.get(n).map(|d| (n, score(&d, head, file_name, matched.as_ref())))).collect();
        let lineages: std::collections::BTreeMap<&str, Vec<&str>> = own.keys().map(|n| (*n, self.lineage(n))).collect();
        // A dialect's score: its own evidence and every ancestor's, less what a dialect on the
        // way down removes (`<remove label=".."/>`).
        let counted = |n: &str| -> Vec<(i64, &str)> {
            let mut removed: Vec<String> = Vec::new();
            let mut out = Vec::new();
            for a in lineages.get(n).into_iter().flatten() {
                out.extend(own[a].iter().filter(|(_, label)| !removed.contains(label)).map(|(w, l)| (*w, l.as_str())));
                removed.extend(self.get(a).map(|d| d.recognise_removed.clone()).unwrap_or_default());
            }
            out
        };
        let total = |n: &str| u32::try_from(counted(n).iter().map(|e| e.0).sum::<i64>().max(0)).unwrap_or(u32::MAX);
        let mut ranked: Vec<(u32, usize, &str)> = lineages.iter().map(|(n, l)| (total(n), l.len(), *n)).collect();
        // Highest score first; the base before a dialect derived from it; then names.
        ranked.sort_by(|a, b| b.0.cmp(&a.0).then(a.1.cmp(&b.1)).then_with(|| a.2.cmp(b.2)));
        let Some(&(best, _, winner)) = ranked.first().filter(|b| b.0 > 0) else {
            return Sniffed {
                dialect: default.to_owned(),
                confidence: Confidence::Low,
                evidence: Vec::new(),
                runner_up: None,
                score: 0,
                candidates: Vec::new(),
            };
        };
        let mine = &lineages[winner];
        let family = |n: &str| self.get(n).map(|d| d.family.clone());
        // Per other dialect: what it has beyond the dialect both descend from, and what the
        // winner has beyond it.
        let mut margins = Vec::new();
        for &(t, _, other) in &ranked[1..] {
            let shared = lineages[other].iter().find(|a| mine.contains(a)).map_or(0, |a| total(a));
            let is_ancestor = mine.contains(&other);
            // Of the winner's own family, evidence both have (its name) tells nothing apart:
            // only what that dialect has beyond the winner counts.
            let same_maker = family(other) == family(winner);
            // (What one removes of the shared evidence may leave it below the ancestor.)
            let (theirs, ours) = (t.saturating_sub(shared), best.saturating_sub(shared));
            let theirs = if same_maker { theirs.saturating_sub(ours) } else { theirs };
            if theirs > 0 || is_ancestor {
                margins.push((other, t, theirs, ours, is_ancestor));
            }
        }
        // A dialect of another family derived from the winner, with nothing of its own here,
        // would read the program as well: the maker is not sure.
        let shared_by_another_maker =
            ranked.iter().any(|&(t, _, o)| t == best && o != winner && lineages[o].contains(&winner) && family(o) != family(winner));
        let high = best >= SURE
            && !shared_by_another_maker
            && margins.iter().all(|&(_, t, theirs, ours, ancestor)| if ancestor { t == 0 || ours >= SURE / 2 } else { ours >= 2 * theirs });
        let medium = margins.iter().all(|&(_, _, theirs, ours, ancestor)| ancestor || ours > theirs);
        // Evidence against the winner (a mill's Y words for a lathe) makes it a guess, and so
        // does a base whose maker another family's dialect shares.
        let against = counted(winner).iter().any(|e| e.0 < 0);
        let confidence = if shared_by_another_maker || against {
            Confidence::Low
        } else if high {
            Confidence::High
        } else if medium {
            Confidence::Medium
        } else {
            Confidence::Low
        };
        let runner_up = margins.iter().max_by(|a, b| a.1.cmp(&b.1).then_with(|| b.0.cmp(a.0))).map(|m| (m.0.to_owned(), m.1));
        let evidence = counted(winner).into_iter().filter(|(w, _)| *w > 0).map(|(_, l)| l.to_owned()).collect();
        // The dialects this evidence does not set the winner apart from: each other of the
        // same base with evidence of its own (or an ancestor of the winner), where what the winner has
        // beyond the dialect both descend from is no more than half of SURE (one code of one
        // maker) or less than twice what the other has beyond it. No single code of one
        // maker decides between makers.
        let mut candidates = vec![winner.to_owned()];
        for &(t, _, other) in &ranked[1..] {
            // Only a dialect of the same base is an alternative reading.
            if lineages[other].last() != mine.last() {
                continue;
            }
            let shared = lineages[other].iter().find(|a| mine.contains(a)).map_or(0, |a| total(a));
            let (theirs, ours) = (t.saturating_sub(shared), best.saturating_sub(shared));
            // A dialect with no evidence of its own beyond what it shares with the winner is no
            // alternative (only more lenient), unless the winner descends from it.
            if theirs == 0 && !mine.contains(&other) {
                continue;
            }
            if ours <= SURE / 2 || ours < 2 * theirs {
                candidates.push(other.to_owned());
            }
        }
        if candidates.len() == 1 {
            candidates.clear();
        }
        Sniffed { dialect: winner.to_owned(), confidence, evidence, runner_up, score: best, candidates }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Evidence two dictionaries both count for themselves under one label (a lathe's
    /// `G96 S`, a maker's name in its mill and lathe dictionaries) is the same evidence: it
    /// weighs the same in each, so that it never tells one of them from the other. (Evidence
    /// against a dialect may weigh otherwise: it tells that dialect from the others.)
    #[test]
    fn a_label_two_dialects_share_weighs_the_same() {
        let r = Registry::shipped();
        let mut seen: std::collections::BTreeMap<String, (u32, String)> = Default::default();
        for name in r.names() {
            let d = r.get(name).unwrap();
            for e in d.recognise.iter().filter(|e| !e.against) {
                let (w, first) = seen.entry(e.label.clone()).or_insert((e.weight, name.to_owned())).clone();
                assert_eq!(e.weight, w, "`{}`: {name} and {first} weigh it differently", e.label);
            }
        }
    }

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

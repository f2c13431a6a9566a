//! Pairing an edited program with its CAM original, by whole program names, rule by rule.
//!
//! A program is known by up to three keys, most specific first: the configured file-name
//! pattern's `key` group, the name or number the program states in its header, and its file
//! name. Names are whole names: Siemens `%_N_DRILL_REAM_MPF` and `DRILL_REAM.MPF` are both
//! `DRILL_REAM`, never `DRILL`. The first rule whose key finds CAM originals decides; when it
//! finds several, the program's other keys may narrow them to one, and otherwise the pairing
//! is ambiguous, which is a finding, never a silent pick. Pure: the candidates come from a
//! lookup the caller supplies (the store).

use std::fmt;

/// How a key was obtained.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Rule {
    /// The configured `[matching] pattern`'s `key` group, matched against the file name.
    Pattern,
    /// The name or number the program states (`O1234`, `%_N_NAME_MPF`, `BEGIN PGM NAME`).
    ProgramName,
    /// The file name without its extension.
    FileName,
}

impl Rule {
    /// Name stored in the database.
    pub fn as_str(self) -> &'static str {
        match self {
            Rule::Pattern => "pattern",
            Rule::ProgramName => "program-name",
            Rule::FileName => "file-name",
        }
    }

    /// The rule named `s` in the database.
    pub fn parse(s: &str) -> Option<Rule> {
        [Rule::Pattern, Rule::ProgramName, Rule::FileName].into_iter().find(|r| r.as_str() == s)
    }
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// One key of a program.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Key {
    /// How it was obtained.
    pub rule: Rule,
    /// The key, upper case.
    pub value: String,
}

/// A program's name as a whole name, upper case: the Siemens `_N_` prefix and the `_MPF`,
/// `_SPF` type suffix are taken off (`_N_DRILL_REAM_MPF` is `DRILL_REAM`); nothing else is.
pub fn whole_name(name: &str) -> String {
    let up = name.trim().to_ascii_uppercase();
    let s = up.strip_prefix("%").unwrap_or(&up);
    let s = s.strip_prefix("_N_").unwrap_or(s);
    let s = s.strip_suffix("_MPF").or_else(|| s.strip_suffix("_SPF")).unwrap_or(s);
    if s.is_empty() { up } else { s.to_owned() }
}

/// The keys of the program in the file `file_name` that states `program` in its header,
/// most specific first.
pub fn keys(pattern: Option<&regex::Regex>, file_name: &str, program: Option<&str>) -> Vec<Key> {
    let mut out: Vec<Key> = Vec::new();
    let mut push = |rule, value: String| {
        if !value.is_empty() {
            out.push(Key { rule, value });
        }
    };
    if let Some(re) = pattern
        && let Some(k) = re.captures(file_name).and_then(|c| c.name("key"))
    {
        push(Rule::Pattern, k.as_str().to_ascii_uppercase());
    }
    if let Some(p) = program {
        push(Rule::ProgramName, whole_name(p));
    }
    push(Rule::FileName, file_stem(file_name));
    out
}

/// The file name without its last extension, as a whole name (`DRILL_REAM.MPF` is `DRILL_REAM`).
pub fn file_stem(file_name: &str) -> String {
    let stem = match file_name.rfind('.') {
        Some(i) if i > 0 => &file_name[..i],
        _ => file_name,
    };
    whole_name(stem)
}

/// A CAM original that a key found.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Candidate {
    /// Its newest usable revision.
    pub revision: i64,
    /// Its path.
    pub path: String,
    /// All its keys.
    pub keys: Vec<Key>,
}

/// The outcome of pairing.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Pairing {
    /// No CAM original has any of the program's keys.
    Unpaired,
    /// One original.
    Paired {
        /// The original's revision.
        revision: i64,
        /// The original's path.
        path: String,
        /// The rule that matched, and the rules that narrowed several candidates to one
        /// (`program-name+file-name`).
        rule: String,
    },
    /// Several originals, and the program's keys cannot tell them apart.
    Ambiguous {
        /// The rule that found them.
        rule: Rule,
        /// The key.
        key: String,
        /// Their paths, sorted.
        paths: Vec<String>,
    },
}

impl Pairing {
    /// The finding an ambiguous pairing gets.
    pub fn message(&self) -> Option<String> {
        match self {
            Pairing::Ambiguous { rule, key, paths } => Some(format!(
                "not compared: {} CAM originals have the {rule} `{key}` and nothing else tells them apart: {}",
                paths.len(),
                paths.join(", ")
            )),
            _ => None,
        }
    }
}

/// Pairs a program with the keys `keys` with one of the originals `lookup` finds by key.
pub fn choose<E>(keys: &[Key], mut lookup: impl FnMut(&str) -> Result<Vec<Candidate>, E>) -> Result<Pairing, E> {
    for (i, key) in keys.iter().enumerate() {
        let mut found = lookup(&key.value)?;
        found.sort_by(|a, b| a.path.cmp(&b.path).then(a.revision.cmp(&b.revision)));
        found.dedup_by(|a, b| a.path == b.path);
        match found.len() {
            0 => continue,
            1 => {
                let c = found.remove(0);
                return Ok(Pairing::Paired { revision: c.revision, path: c.path, rule: key.rule.as_str().to_owned() });
            }
            _ => {}
        }
        // Several: the candidates that share the most of the program's other keys, rule for rule.
        let others: Vec<&Key> = keys.iter().enumerate().filter(|&(j, k)| j != i && k.rule != key.rule).map(|(_, k)| k).collect();
        let score = |c: &Candidate| others.iter().filter(|k| c.keys.contains(k)).count();
        let best = found.iter().map(score).max().unwrap_or(0);
        let top: Vec<&Candidate> = found.iter().filter(|c| score(c) == best).collect();
        if best > 0 && top.len() == 1 {
            let c = top[0];
            let mut rule = key.rule.as_str().to_owned();
            for k in others.iter().filter(|k| c.keys.contains(k)) {
                rule.push('+');
                rule.push_str(k.rule.as_str());
            }
            return Ok(Pairing::Paired { revision: c.revision, path: c.path.clone(), rule });
        }
        return Ok(Pairing::Ambiguous { rule: key.rule, key: key.value.clone(), paths: found.into_iter().map(|c| c.path).collect() });
    }
    Ok(Pairing::Unpaired)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_are_whole_names() {
        assert_eq!(whole_name("%_N_DRILL_REAM_MPF"), "DRILL_REAM");
        assert_eq!(whole_name("_N_DRILL_PLATE_SPF"), "DRILL_PLATE");
        assert_eq!(whole_name("o1234"), "O1234");
        assert_eq!(file_stem("DRILL_REAM.MPF"), "DRILL_REAM");
        assert_eq!(file_stem("_N_DRILL_REAM_MPF"), "DRILL_REAM");
        assert_eq!(file_stem("O1234.nc"), "O1234");
        assert_eq!(file_stem(".nc"), ".NC");
    }

    #[test]
    fn keys_come_most_specific_first_without_repeats() {
        let re = regex::Regex::new("^(?P<key>[A-Z0-9]+)_").unwrap();
        let k = keys(Some(&re), "P77_rev3.nc", Some("O1234"));
        let got: Vec<(Rule, &str)> = k.iter().map(|k| (k.rule, k.value.as_str())).collect();
        assert_eq!(got, [(Rule::Pattern, "P77"), (Rule::ProgramName, "O1234"), (Rule::FileName, "P77_REV3")]);
        let k = keys(None, "DRILL_REAM.MPF", Some("%_N_DRILL_REAM_MPF"));
        let got: Vec<(Rule, &str)> = k.iter().map(|k| (k.rule, k.value.as_str())).collect();
        assert_eq!(got, [(Rule::ProgramName, "DRILL_REAM"), (Rule::FileName, "DRILL_REAM")]);
    }

    /// A CAM original at `path` stating `program`.
    fn cand(revision: i64, path: &str, program: &str) -> Candidate {
        let file = path.rsplit('/').next().unwrap();
        Candidate { revision, path: path.into(), keys: keys(None, file, Some(program)) }
    }

    fn lookup(originals: &[Candidate]) -> impl FnMut(&str) -> Result<Vec<Candidate>, ()> + '_ {
        |k| Ok(originals.iter().filter(|c| c.keys.iter().any(|x| x.value == k)).cloned().collect())
    }

    #[test]
    fn the_first_rule_that_finds_one_original_decides() {
        let keys = keys(None, "DRILL_REAM.MPF", Some("%_N_DRILL_REAM_MPF"));
        let originals = [cand(1, "/cam/DRILL_PLATE.MPF", "%_N_DRILL_PLATE_MPF"), cand(2, "/cam/DRILL_REAM.MPF", "%_N_DRILL_REAM_MPF")];
        let p = choose(&keys, lookup(&originals)).unwrap();
        assert_eq!(p, Pairing::Paired { revision: 2, path: "/cam/DRILL_REAM.MPF".into(), rule: "program-name".into() });
    }

    #[test]
    fn several_originals_are_narrowed_by_other_keys_or_ambiguous() {
        let originals = [cand(1, "/cam/O1234.nc", "O1234"), cand(2, "/cam/O1234_OLD.nc", "O1234")];
        for (file, want) in [("O1234_OLD.nc", 2), ("O1234.nc", 1)] {
            let p = choose(&keys(None, file, Some("O1234")), lookup(&originals)).unwrap();
            let Pairing::Paired { revision, rule, .. } = p else { panic!("{file}: {p:?}") };
            assert_eq!((revision, rule.as_str()), (want, "program-name+file-name"), "{file}");
        }
        let unrelated = keys(None, "PART.nc", Some("O1234"));
        let p = choose(&unrelated, lookup(&originals)).unwrap();
        assert_eq!(
            p,
            Pairing::Ambiguous {
                rule: Rule::ProgramName,
                key: "O1234".into(),
                paths: vec!["/cam/O1234.nc".into(), "/cam/O1234_OLD.nc".into()]
            }
        );
        assert!(p.message().unwrap().contains("2 CAM originals have the program-name `O1234`"));
        assert_eq!(choose(&keys(None, "X.nc", None), lookup(&originals)).unwrap(), Pairing::Unpaired);
    }
}

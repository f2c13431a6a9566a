//! Loading the record form (`<records>`): major words to the engine's record actions, codes
//! by their spelling in the dialect's own table, roles, producers.

use super::super::xml::Element;
use super::super::{CodeDef, Role};
use super::Cx;

/// The record form (`<records>`): the engine's record actions, codes by their spelling, roles.
impl Cx {
    pub(super) fn records(&mut self, el: &Element, codes: &[CodeDef]) -> crate::dialect::records::Records {
        use crate::dialect::records::{CircleSense, Producer, Records};
        self.shape(el, &["continuation", "comment", "command", "tolerance"], &["record", "producer"]);
        let continuation = self.char_attr(el, "continuation").unwrap_or('$');
        let comment = self.attr(el, "comment").unwrap_or("$$").to_owned();
        let tolerance = self.number(el, "tolerance", 0.001);
        let command = self.attr(el, "command").map(str::to_owned);
        if command.as_ref().is_some_and(|c| !c.starts_with(&comment)) {
            self.error(Self::attr_range(el, "command"), "`command` must start with the `comment` opener");
        }
        let mut records = Vec::new();
        for r in el.children.iter().filter(|c| c.name == "record") {
            if let Some(def) = self.record(r, codes) {
                if records.iter().any(|x: &crate::dialect::records::RecordDef| x.major == def.major) {
                    self.error(r.range, format!("record `{}` is defined twice", def.major));
                }
                records.push(def);
            }
        }
        let mut producers = Vec::new();
        for p in el.children.iter().filter(|c| c.name == "producer") {
            self.shape(p, &["name", "circle"], &["evidence", "record"]);
            let name = self.required(p, "name").unwrap_or_default().to_owned();
            let circle = match self.required(p, "circle") {
                Some("clockwise") => CircleSense::Clockwise,
                Some("counter-clockwise") | None => CircleSense::CounterClockwise,
                Some(other) => {
                    self.error(Self::attr_range(p, "circle"), format!("`circle` is clockwise or counter-clockwise, not `{other}`"));
                    CircleSense::CounterClockwise
                }
            };
            let mut evidence = Vec::new();
            for e in p.children.iter().filter(|c| c.name == "evidence") {
                self.shape(e, &["regex", "label"], &[]);
                let Some(src) = self.required(e, "regex") else { continue };
                match crate::dialect::Pattern::new(src) {
                    Ok(re) => evidence.push((self.attr(e, "label").unwrap_or(src).to_owned(), re)),
                    Err(err) => self.error(Self::attr_range(e, "regex"), format!("invalid regular expression: {err}")),
                }
            }
            let own = p.children.iter().filter(|c| c.name == "record").filter_map(|r| self.record(r, codes)).collect();
            producers.push(Producer { name, evidence, circle, records: own });
        }
        if !producers.iter().any(|p| p.evidence.is_empty()) {
            self.error(el.range, "<records> needs one <producer> without <evidence>: the default");
        }
        Records { continuation, comment, command, records, producers, tolerance }
    }

    /// A code by its spelling in the dialect: `G81`, `M6`, or a keyword code's keyword.
    fn code_ref(&mut self, el: &Element, attr: &str, spelled: &str, codes: &[CodeDef]) -> Option<usize> {
        let up = spelled.to_ascii_uppercase();
        let by_number = || {
            let mut chars = up.chars();
            let letter = chars.next()?;
            let n: f64 = chars.as_str().parse().ok()?;
            let x10 = (n * 10.0).round() as u16;
            codes.iter().position(|c| c.keyword.is_none() && c.letter == letter && c.number == x10)
        };
        let found = by_number().or_else(|| codes.iter().position(|c| c.keyword.as_ref().is_some_and(|k| k.text.eq_ignore_ascii_case(&up))));
        if found.is_none() {
            self.error(Self::attr_range(el, attr), format!("`{spelled}` is not a code of this dialect's <groups>"));
        }
        found
    }

    /// `args="tool"`, `args="extra radius@up"`: positional roles, perhaps from a hole's point.
    fn record_args(&mut self, el: &Element) -> Vec<(Role, Option<f64>)> {
        let Some(list) = self.attr(el, "args") else { return Vec::new() };
        let mut out = Vec::new();
        for item in list.split_ascii_whitespace() {
            let (name, from) = match item.split_once('@') {
                Some((n, "up")) => (n, Some(1.0)),
                Some((n, "down")) => (n, Some(-1.0)),
                Some((n, _)) => {
                    self.error(Self::attr_range(el, "args"), format!("`{item}` in `args`: after `@` comes up or down"));
                    (n, None)
                }
                None => (item, None),
            };
            match Role::parse(name).filter(|r| !r.is_internal()) {
                Some(r) => out.push((r, from)),
                None => self.error(Self::attr_range(el, "args"), format!("unknown role `{name}` in `args`")),
            }
        }
        out
    }

    fn record(&mut self, r: &Element, codes: &[CodeDef]) -> Option<crate::dialect::records::RecordDef> {
        use crate::dialect::records::{MinorDef, RecordAction, RecordDef};
        self.shape(r, &["major", "action", "codes", "args", "also"], &["minor"]);
        let major = self.required(r, "major")?.split_ascii_whitespace().collect::<Vec<_>>().join(" ").to_ascii_uppercase();
        let a = self.attr(r, "action").unwrap_or("words");
        let Some(action) = RecordAction::parse(a) else {
            self.error(Self::attr_range(r, "action"), format!("unknown record action `{a}`"));
            return None;
        };
        let mut own = Vec::new();
        for c in self.attr(r, "codes").unwrap_or("").split_ascii_whitespace() {
            own.extend(self.code_ref(r, "codes", c, codes));
        }
        let args = self.record_args(r);
        let mut also = Vec::new();
        if let Some(list) = self.attr(r, "also") {
            for pair in list.split_ascii_whitespace() {
                match pair.split_once(':').map(|(a, b)| (Role::parse(a), Role::parse(b))) {
                    Some((Some(a), Some(b))) => also.push((a, b)),
                    _ => self.error(Self::attr_range(r, "also"), format!("`{pair}` in `also` is not role:role")),
                }
            }
        }
        let mut minors: Vec<MinorDef> = Vec::new();
        for m in r.children.iter().filter(|c| c.name == "minor") {
            self.shape(m, &["word", "codes", "role", "from-point"], &[]);
            let Some(word) = self.required(m, "word").map(str::to_ascii_uppercase) else { continue };
            if minors.iter().any(|x| x.word == word) {
                self.error(m.range, format!("minor word `{word}` is defined twice in record `{major}`"));
            }
            let mut own_codes = Vec::new();
            for c in self.attr(m, "codes").unwrap_or("").split_ascii_whitespace() {
                own_codes.extend(self.code_ref(m, "codes", c, codes));
            }
            let role = self.role_attr(m, "role");
            let from_point = match self.attr(m, "from-point") {
                None => None,
                Some("up") => Some(1.0),
                Some("down") => Some(-1.0),
                Some(other) => {
                    self.error(Self::attr_range(m, "from-point"), format!("`from-point` is up or down, not `{other}`"));
                    None
                }
            };
            if from_point.is_some() && role.is_none() {
                self.error(Self::attr_range(m, "from-point"), "`from-point` needs a `role`");
            }
            minors.push(MinorDef { word, codes: own_codes, role, from_point });
        }
        Some(RecordDef { major, action, codes: own, args, minors, also })
    }
}

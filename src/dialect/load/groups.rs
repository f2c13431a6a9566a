//! Loading `<groups>`: the modal groups and the G, M and keyword codes in them, with each
//! code's meaning and parameters. The door is `Cx::groups`; a group's head, a code, and the
//! code's parameter lists, arguments, data forms and keyword each have a reader.

use super::super::xml::Element;
use super::super::{AddressDef, CodeDef, DataForm, KeywordRest, KeywordSpec, Meaning, ModalGroup, ParamSpec, Role, Step};
use super::Cx;

/// The attributes a `<code>` may carry.
const CODE_ATTRIBUTES: &[&str] = &[
    "value",
    "keyword",
    "value-role",
    "value-form",
    "rest",
    "meaning",
    "index",
    "name",
    "required",
    "optional",
    "any-of",
    "exclusive",
    "forms",
    "gives-way",
    "hole-axis",
    "home-axes",
    "r-level",
    "spindle",
    "args",
    "line-words",
    "tilt-forms",
    "also",
    "probe",
    "moves",
    "rejected",
];

impl Cx {
    /// `<groups>`: each group and the codes in it, in document order.
    pub(super) fn groups(&mut self, el: &Element, addresses: &[AddressDef]) -> (Vec<ModalGroup>, Vec<CodeDef>) {
        self.shape(el, &[], &["group"]);
        let mut groups: Vec<ModalGroup> = Vec::new();
        let mut codes: Vec<CodeDef> = Vec::new();
        for g in el.children.iter().filter(|c| c.name == "group") {
            let (group, letter) = self.group(g, &groups);
            let gi = groups.len();
            groups.push(group);
            for c in g.children.iter().filter(|c| c.name == "code") {
                if let Some(code) = self.code(c, letter, gi, addresses, &codes) {
                    codes.push(code);
                }
            }
        }
        (groups, codes)
    }

    /// `<group id="motion" letter="G" modal="true" step="motion">`: the group, and the letter
    /// of its codes (G or M).
    fn group(&mut self, g: &Element, groups: &[ModalGroup]) -> (ModalGroup, char) {
        self.shape(g, &["id", "letter", "modal", "step"], &["code"]);
        let id = self.required(g, "id").unwrap_or_default().to_owned();
        if groups.iter().any(|x| x.id == id) {
            self.error(g.range, format!("group `{id}` is declared twice"));
        }
        let letter = self.letter_attr(g, "letter").unwrap_or('G');
        if letter != 'G' && letter != 'M' {
            self.error(Self::attr_range(g, "letter"), "a group's letter must be G or M (keyword codes may sit in either)");
        }
        let step = match self.required(g, "step").map(|s| (s, Step::parse(s))) {
            Some((_, Some(step))) => step,
            Some((s, None)) => {
                self.error(Self::attr_range(g, "step"), format!("unknown step `{s}`"));
                Step::Misc
            }
            None => Step::Misc,
        };
        let modal = self.bool(g, "modal", true);
        (ModalGroup { id, modal, step }, letter)
    }

    /// `<code value="81" meaning="drill" .../>` or `<code keyword="TOOL CALL" .../>` in the
    /// group `group` of codes written with `letter`; `None` for a code that cannot be kept
    /// (reported), such as one declared twice among `codes`.
    fn code(&mut self, c: &Element, letter: char, group: usize, addresses: &[AddressDef], codes: &[CodeDef]) -> Option<CodeDef> {
        self.shape(c, CODE_ATTRIBUTES, &[]);
        let keyword = self.keyword_spec(c);
        let value = match (self.attr(c, "value"), &keyword) {
            (Some(v), None) => v,
            (None, Some(_)) => "0",
            _ => {
                self.error(c.range, "a <code> needs either `value` (G1, M3) or `keyword` (TRANS, TOOL CALL)");
                return None;
            }
        };
        let meaning = self.required(c, "meaning")?;
        let Some(number) = parse_code_number(value) else {
            self.error(Self::attr_range(c, "value"), format!("code value `{value}` must be a number such as 1 or 54.1 below 1000"));
            return None;
        };
        let Some(meaning) = Meaning::parse(meaning) else {
            self.error(Self::attr_range(c, "meaning"), format!("unknown meaning `{meaning}`"));
            return None;
        };
        let index = self.number(c, "index", 0.0) as u8;
        // 0: no settable work offset in force (Siemens G500: the settable frame off).
        if meaning == Meaning::Wcs && !(0..=9).contains(&index) {
            self.error(c.range, "a `wcs` code needs an `index` from 0 (no settable work offset) to 9");
        }
        if let Some(k) = &keyword {
            if codes.iter().any(|x| x.keyword.as_ref().is_some_and(|o| o.text == k.text)) {
                self.error(c.range, format!("keyword `{}` is declared twice", k.text));
                return None;
            }
        } else if codes.iter().any(|x| x.keyword.is_none() && x.letter == letter && x.number == number) {
            self.error(c.range, format!("code {letter}{value} is declared twice"));
            return None;
        }
        let params = self.params(c, addresses);
        let name = self.attr(c, "name").unwrap_or(meaning.as_str()).to_owned();
        let name = match &keyword {
            Some(k) if self.attr(c, "name").is_none() => k.text.clone(),
            _ => name,
        };
        let forms = self.forms(c);
        let gives_way = self.bool(c, "gives-way", false);
        let hole_axis = match self.attr(c, "hole-axis") {
            Some("x") => Some(0),
            Some("z") => Some(2),
            _ => None,
        };
        // Centroid `M25`: the axes a reference approach without axis words sends home.
        let home_axes = self
            .attr(c, "home-axes")
            .map_or(0, |list| list.chars().filter_map(|ch| "XYZABC".find(ch.to_ascii_uppercase())).fold(0u8, |m, k| m | 1 << k));
        // Haas's live-tool cycles: R is the R plane's position (a diameter for a radial
        // hole), not Fanuc's distance from the initial level.
        let r_absolute = self.attr(c, "r-level") == Some("absolute");
        // A driven tool's own spindle codes (Haas `M133 P2500`).
        let driven = self.attr(c, "spindle") == Some("driven");
        let args = self.code_args(c, addresses, &params);
        let named = keyword.is_none() && self.attr(c, "rest") == Some("words");
        let line_words = self.line_words(c);
        let tilt_forms = self.tilt_forms(c);
        let also = self.also(c);
        Some(CodeDef {
            letter,
            number,
            meaning,
            index,
            name,
            group,
            params,
            keyword,
            forms,
            gives_way,
            hole_axis,
            home_axes,
            r_absolute,
            driven,
            args,
            named,
            line_words,
            tilt_forms,
            also,
            probe: self.bool(c, "probe", false),
            moves: self.bool(c, "moves", false),
            rejected: self.attr(c, "rejected").map(str::to_owned),
        })
    }

    /// `also="feed-per-rev"`: the code's second effect, a feed mode or a spindle speed mode
    /// (the feed type group of a control that keeps both in one, Siemens group 15).
    fn also(&mut self, c: &Element) -> Option<Meaning> {
        let text = self.attr(c, "also")?;
        let m = Meaning::parse(text);
        let second = [Meaning::FeedPerMinute, Meaning::FeedPerRev, Meaning::FeedInverseTime, Meaning::SpindleCss, Meaning::SpindleRpm];
        match m {
            Some(m) if second.contains(&m) => Some(m),
            _ => {
                let msg = format!(
                    "`also` must be a feed mode or a spindle speed mode (feed-per-minute, feed-per-rev, feed-inverse-time, spindle-css, spindle-rpm), not `{text}`"
                );
                self.error(Self::attr_range(c, "also"), msg);
                None
            }
        }
    }

    /// A code's parameters: `required`, `optional`, `any-of="X Y|R"` (at least one of each
    /// set, all optional) and `exclusive="I J|R"` (not both lists).
    fn params(&mut self, c: &Element, addresses: &[AddressDef]) -> ParamSpec {
        let mut params = ParamSpec {
            required: self.roles(c, "required", addresses),
            optional: self.roles(c, "optional", addresses),
            any_of: Vec::new(),
            exclusive: Vec::new(),
        };
        if let Some(sets) = self.attr(c, "any-of") {
            for set in sets.split('|') {
                let roles = self.role_list(c, "any-of", set, addresses);
                params.optional.extend(roles.iter().copied());
                params.any_of.push(roles);
            }
        }
        if let Some(pair) = self.attr(c, "exclusive") {
            match pair.split_once('|') {
                Some((a, b)) => {
                    let a = self.role_list(c, "exclusive", a, addresses);
                    let b = self.role_list(c, "exclusive", b, addresses);
                    params.exclusive.push((a, b));
                }
                None => self.error(Self::attr_range(c, "exclusive"), "`exclusive` needs two address lists separated by `|`"),
            }
        }
        params
    }

    /// `args="I:pattern-radius L:pattern-count"`: the role each listed address's value has for
    /// this code. The addresses must be among the code's parameters.
    fn code_args(&mut self, c: &Element, addresses: &[AddressDef], params: &ParamSpec) -> Vec<(Role, Role)> {
        let Some(list) = self.attr(c, "args") else { return Vec::new() };
        let mut out = Vec::new();
        for item in list.split_ascii_whitespace() {
            let pair = item.split_once(':').and_then(|(a, r)| {
                let from = addresses.iter().find(|x| x.name.eq_ignore_ascii_case(a))?.role;
                if !params.takes(from) {
                    return None;
                }
                let to = Role::parse(r).filter(|r| !r.is_internal())?;
                Some((from, to))
            });
            match pair {
                Some(pair) => out.push(pair),
                None => self.error(
                    Self::attr_range(c, "args"),
                    format!("`{item}` is not ADDRESS:role with an address the code takes and a known role"),
                ),
            }
        }
        out
    }

    /// `line-words="SPA:tilt-a SPB:tilt-b"`: the words the unread rest of a keyword's line
    /// holds (`rest="line"`) and the role of each.
    fn line_words(&mut self, c: &Element) -> Vec<(String, Role)> {
        let Some(list) = self.attr(c, "line-words") else { return Vec::new() };
        let mut out = Vec::new();
        for item in list.split_ascii_whitespace() {
            let pair = item.split_once(':').and_then(|(a, r)| {
                let role = Role::parse(r).filter(|r| !r.is_internal())?;
                // A name starts with a letter and may hold digits (`P1X` of PLANE POINTS).
                let name = a.starts_with(|c: char| c.is_ascii_alphabetic()) && a.chars().all(|c| c.is_ascii_alphanumeric());
                name.then(|| (a.to_ascii_uppercase(), role))
            });
            match pair {
                Some(pair) => out.push(pair),
                None => self.error(
                    Self::attr_range(c, "line-words"),
                    format!("`{item}` is not NAME:role with a name of letters and digits and a known role"),
                ),
            }
        }
        out
    }

    /// `forms="2:wcs 20:wcs-here 1:tool"`: what a data-setting code sets for each L value.
    /// Without the attribute, L2 and L20 set work offsets as LinuxCNC does.
    fn forms(&mut self, c: &Element) -> Vec<(u16, DataForm)> {
        let Some(list) = self.attr(c, "forms") else { return vec![(2, DataForm::Wcs), (20, DataForm::WcsHere)] };
        let mut out = Vec::new();
        for item in list.split_ascii_whitespace() {
            match item.split_once(':').and_then(|(l, f)| Some((l.parse::<u16>().ok()?, DataForm::parse(f)?))) {
                Some(pair) => out.push(pair),
                None => self.error(Self::attr_range(c, "forms"), format!("`{item}` is not L:form (form: wcs, wcs-here, wcs-extended, tool, tool-here, tool-here-fixture, tool-length, tool-length-wear, tool-radius, tool-radius-wear)")),
            }
        }
        out
    }

    /// `tilt-forms="P1:tilt-roll-pitch-yaw"`: the meaning a tilted-plane code takes where its
    /// block has that word with that value.
    fn tilt_forms(&mut self, c: &Element) -> Vec<(char, u16, Meaning)> {
        let Some(list) = self.attr(c, "tilt-forms") else { return Vec::new() };
        let mut out = Vec::new();
        for item in list.split_ascii_whitespace() {
            let parsed = item.split_once(':').and_then(|(w, m)| {
                let letter = w.chars().next().filter(char::is_ascii_alphabetic)?.to_ascii_uppercase();
                let value = w[1..].parse::<u16>().ok()?;
                let meaning = Meaning::parse(m).filter(|m| m.as_str().starts_with("tilt-"))?;
                Some((letter, value, meaning))
            });
            match parsed {
                Some(form) => out.push(form),
                None => self.error(
                    Self::attr_range(c, "tilt-forms"),
                    format!("`{item}` is not WORD:meaning (`P1:tilt-roll-pitch-yaw`, a tilt meaning)"),
                ),
            }
        }
        out
    }

    /// The `keyword`, `value-role` and `rest` attributes of a keyword code.
    fn keyword_spec(&mut self, c: &Element) -> Option<KeywordSpec> {
        let text = self.attr(c, "keyword")?;
        let text = text.split_ascii_whitespace().collect::<Vec<_>>().join(" ").to_ascii_uppercase();
        if text.is_empty() || !text.as_bytes()[0].is_ascii_alphabetic() {
            self.error(Self::attr_range(c, "keyword"), "a keyword starts with a letter");
            return None;
        }
        let value_role = self.role_attr(c, "value-role");
        let rest = match self.attr(c, "rest").unwrap_or("none") {
            "none" => KeywordRest::None,
            "name" => KeywordRest::Name,
            "words" => KeywordRest::Words,
            "line" => KeywordRest::Line,
            other => {
                self.error(Self::attr_range(c, "rest"), format!("unknown rest `{other}`; use none, name or words"));
                KeywordRest::None
            }
        };
        let assigned = self.either(c, "value-form", "bare", "assign");
        Some(KeywordSpec { text, value_role, rest, assigned })
    }

    /// The roles of the addresses in `list`, part of the attribute `attr` of `el`.
    fn role_list(&mut self, el: &Element, attr: &str, list: &str, addresses: &[AddressDef]) -> Vec<Role> {
        let mut out = Vec::new();
        for item in list.split_ascii_whitespace() {
            match addresses.iter().find(|a| a.name.eq_ignore_ascii_case(item)) {
                Some(a) => out.push(a.role),
                None => self.error(Self::attr_range(el, attr), format!("`{item}` in `{attr}` is not a declared address")),
            }
        }
        out
    }
}

/// `54.1` → 541; at most one decimal digit, below 1000.
pub(super) fn parse_code_number(s: &str) -> Option<u16> {
    let (int, frac) = s.split_once('.').unwrap_or((s, "0"));
    let int: u16 = int.parse().ok()?;
    let frac: u16 = if frac.len() == 1 { frac.parse().ok()? } else { return None };
    (int < 1000).then_some(int * 10 + frac)
}

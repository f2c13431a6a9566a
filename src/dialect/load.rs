//! XML text → validated [`Dialect`], with diagnostics that point into the XML.
//!
//! This file holds the door ([`load`]), the checking context `Cx` with its attribute readers,
//! the root element and the small sections (addresses, cycles, recognition, execution
//! order). The larger sections load in files of their own, each as more `Cx` methods:
//! `lexical.rs` (`<lexical>`), `behaviour.rs` (`<behaviour>`), `macros.rs` (`<macros>`),
//! `groups.rs` (`<groups>` and their codes) and `records.rs` (`<records>`).

use super::inherit;
use super::xml::{self, Element};
use super::{AddressDef, BlockForm, CycleArg, CycleDef, Dialect, Meaning, ModalGroup, Role, Step};
use crate::diag::{Code, Diagnostic};
use crate::text::TextRange;

mod behaviour;
mod groups;
mod lexical;
mod macros;
mod records;
mod vocabulary;

/// Loads a dialect from XML text. Never fails: a broken file gives `None` and at least one
/// error diagnostic whose range points into `text`. A file that `extends` another needs
/// [`Registry::add`](super::Registry::add), which knows the bases.
pub fn load(text: &str) -> (Option<Dialect>, Vec<Diagnostic>) {
    let (dialect, diags, _) = load_tree(text, &|_| None);
    (dialect, diags)
}

/// Like [`load`], with `base(name)` giving the merged element tree of a dialect this one may
/// extend. Also returns this dialect's merged tree, for dialects that extend it in turn.
pub(super) fn load_tree(text: &str, base: &dyn Fn(&str) -> Option<Element>) -> (Option<Dialect>, Vec<Diagnostic>, Option<Element>) {
    let mut cx = Cx { diags: Vec::new() };
    let mut root = match xml::parse(text) {
        Ok(root) => root,
        Err((range, msg)) => {
            cx.error(range, msg);
            return (None, cx.diags, None);
        }
    };
    let extends = root.attrs.iter().find(|a| a.name == "extends").map(|a| a.value.clone());
    if let Some(a) = root.attrs.iter().find(|a| a.name == "extends") {
        let at = a.range;
        match base(&a.value) {
            Some(b) => {
                let mut errors = Vec::new();
                root = inherit::merge(b, root, at, &mut errors);
                for (range, msg) in errors {
                    cx.error(range, msg);
                }
            }
            None => {
                cx.error(at, format!("`extends` names `{}`, which is not a dialect loaded before this one", a.value));
                return (None, cx.diags, None);
            }
        }
    }
    let dialect = cx.dialect(&root).map(|d| Dialect { extends, ..d });
    if cx.diags.iter().any(Diagnostic::is_error) {
        return (None, cx.diags, None);
    }
    (dialect.map(Dialect::index), cx.diags, Some(root))
}

struct Cx {
    diags: Vec<Diagnostic>,
}

impl Cx {
    fn error(&mut self, range: TextRange, msg: impl Into<String>) {
        self.diags.push(Diagnostic::new(Code::DialectInvalid, range, msg));
    }

    /// Reports attributes outside `allowed` and child elements outside `children`.
    fn shape(&mut self, el: &Element, allowed: &[&str], children: &[&str]) {
        for a in &el.attrs {
            if !allowed.contains(&a.name.as_str()) {
                self.error(a.range, format!("<{}> has no attribute `{}`", el.name, a.name));
            }
        }
        for c in &el.children {
            if !children.contains(&c.name.as_str()) {
                self.error(c.range, format!("<{}> may not contain <{}>", el.name, c.name));
            }
        }
    }

    fn attr<'a>(&mut self, el: &'a Element, name: &str) -> Option<&'a str> {
        el.attrs.iter().find(|a| a.name == name).map(|a| a.value.as_str())
    }

    fn required<'a>(&mut self, el: &'a Element, name: &str) -> Option<&'a str> {
        let v = self.attr(el, name);
        if v.is_none() {
            self.error(el.range, format!("<{}> needs the attribute `{name}`", el.name));
        }
        v
    }

    fn attr_range(el: &Element, name: &str) -> TextRange {
        el.attrs.iter().find(|a| a.name == name).map_or(el.range, |a| a.range)
    }

    fn bool(&mut self, el: &Element, name: &str, default: bool) -> bool {
        match self.attr(el, name) {
            None => default,
            Some("true") => true,
            Some("false") => false,
            Some(v) => {
                self.error(Self::attr_range(el, name), format!("`{name}` must be true or false, not `{v}`"));
                default
            }
        }
    }

    /// A two-valued attribute: false for `off` (the default), true for `on`.
    fn either(&mut self, el: &Element, name: &str, off: &str, on: &str) -> bool {
        match self.attr(el, name) {
            None => false,
            Some(v) if v == off => false,
            Some(v) if v == on => true,
            Some(other) => {
                self.error(Self::attr_range(el, name), format!("`{name}` is {off} or {on}, not `{other}`"));
                false
            }
        }
    }

    fn number(&mut self, el: &Element, name: &str, default: f64) -> f64 {
        match self.attr(el, name) {
            None => default,
            Some(v) => match v.parse::<f64>() {
                Ok(x) if x.is_finite() && x >= 0.0 => x,
                _ => {
                    self.error(Self::attr_range(el, name), format!("`{name}` must be a non-negative number, not `{v}`"));
                    default
                }
            },
        }
    }

    fn char_attr(&mut self, el: &Element, name: &str) -> Option<char> {
        let v = self.attr(el, name)?;
        let mut chars = v.chars();
        match (chars.next(), chars.next()) {
            (Some(c), None) => Some(c),
            _ => {
                self.error(Self::attr_range(el, name), format!("`{name}` must be one character, not `{v}`"));
                None
            }
        }
    }

    fn letter_attr(&mut self, el: &Element, name: &str) -> Option<char> {
        let c = self.char_attr(el, name)?;
        if !c.is_ascii_alphabetic() {
            self.error(Self::attr_range(el, name), format!("`{name}` must be a letter, not `{c}`"));
            return None;
        }
        Some(c.to_ascii_uppercase())
    }

    /// An optional attribute naming one role (`again="next-tool"`, `value-role="tool"`).
    fn role_attr(&mut self, el: &Element, name: &str) -> Option<Role> {
        let r = self.attr(el, name)?;
        let role = Role::parse(r).filter(|r| !r.is_internal());
        if role.is_none() {
            self.error(Self::attr_range(el, name), format!("unknown role `{r}`"));
        }
        role
    }

    fn roles(&mut self, el: &Element, name: &str, addresses: &[AddressDef]) -> Vec<Role> {
        let Some(list) = self.attr(el, name) else { return Vec::new() };
        let mut out = Vec::new();
        for item in list.split_ascii_whitespace() {
            match addresses.iter().find(|a| a.name.eq_ignore_ascii_case(item)) {
                Some(a) => out.push(a.role),
                None => self.error(Self::attr_range(el, name), format!("`{item}` in `{name}` is not an address declared in <addresses>")),
            }
        }
        out
    }

    fn dialect(&mut self, root: &Element) -> Option<Dialect> {
        if root.name != "dialect" {
            self.error(root.range, format!("the root element must be <dialect>, not <{}>", root.name));
            return None;
        }
        self.shape(
            root,
            &["name", "family", "title", "version"],
            &[
                "description",
                "lexical",
                "behaviour",
                "addresses",
                "macros",
                "execution-order",
                "groups",
                "cycles",
                "records",
                "recognise",
                "vocabulary",
                "output",
            ],
        );
        let name = self.required(root, "name").unwrap_or_default().to_owned();
        if !name.is_empty() && !name.bytes().all(|b| b.is_ascii_lowercase() || b.is_ascii_digit() || b == b'_') {
            self.error(Self::attr_range(root, "name"), "`name` must use a-z, 0-9 and _ only");
        }
        let family = self.required(root, "family").unwrap_or_default().to_owned();
        let title = self.attr(root, "title").unwrap_or(&name).to_owned();
        let child = |n: &str| root.children.iter().find(|c| c.name == n);

        let lexical = match child("lexical") {
            Some(el) => self.lexical(el),
            None => {
                self.error(root.range, "<dialect> needs a <lexical> element");
                return None;
            }
        };
        let addresses = child("addresses").map(|el| self.addresses(el)).unwrap_or_default();
        if addresses.is_empty() {
            self.error(root.range, "<dialect> needs an <addresses> element with at least one <address>");
        }
        let behaviour = self.behaviour(child("behaviour"), &addresses);
        let macros = child("macros").map(|el| self.macros(el)).unwrap_or_default();
        let (groups, codes) = child("groups").map(|el| self.groups(el, &addresses)).unwrap_or_default();
        let cycles = child("cycles").map(|el| self.cycles(el)).unwrap_or_default();
        let records = child("records").map(|el| Box::new(self.records(el, &codes)));
        match (&records, lexical.block_form) {
            (None, BlockForm::Record) => self.error(root.range, "block-form=\"record\" needs a <records> element"),
            (Some(_), BlockForm::WordAddress | BlockForm::KeywordFirst) => {
                self.error(child("records").map_or(root.range, |e| e.range), "<records> needs block-form=\"record\" in <lexical>")
            }
            _ => {}
        }
        let recognise = child("recognise").map(|el| self.recognise(el)).unwrap_or_default();
        let vocabulary = child("vocabulary").map(|el| self.vocabulary(el)).unwrap_or_default();
        let output = child("output").map(|el| {
            let mut errors = Vec::new();
            let out = super::output::load(el, &mut errors);
            for (range, msg) in errors {
                self.error(range, msg);
            }
            out
        });
        let recognise_removed = child("recognise")
            .map(|el| {
                el.children.iter().filter(|c| c.name == "remove").filter_map(|c| self.required(c, "label").map(str::to_owned)).collect()
            })
            .unwrap_or_default();
        let execution_order = match child("execution-order") {
            Some(el) => self.execution_order(el, &groups),
            None => {
                self.error(root.range, "<dialect> needs an <execution-order> element");
                Vec::new()
            }
        };
        Some(Dialect {
            name,
            family,
            extends: None,
            title,
            lexical,
            behaviour,
            addresses,
            macros,
            groups,
            codes,
            cycles,
            records,
            execution_order,
            recognise,
            recognise_removed,
            vocabulary,
            output,
            letter_roles: [None; 128],
            letter_incremental: 0,
            plain_roles: [None; 128],
            g_table: Vec::new(),
            m_table: Vec::new(),
            keyword_codes: Vec::new(),
            keyword_codes_by_first: Vec::new(),
        })
    }

    fn addresses(&mut self, el: &Element) -> Vec<AddressDef> {
        /// Characters that may be an address on their own (LinuxCNC's polar `@` and `^`).
        const SYMBOL_ADDRESSES: &str = "@^";
        self.shape(el, &[], &["address"]);
        let mut out: Vec<AddressDef> = Vec::new();
        for c in el.children.iter().filter(|c| c.name == "address") {
            self.shape(
                c,
                &["name", "role", "form", "mode", "again", "offset-digits", "id-suffix", "offset-suffix", "spindle-index", "axis-index"],
                &[],
            );
            let (Some(name), Some(role)) = (self.required(c, "name"), self.required(c, "role")) else { continue };
            let name = name.to_ascii_uppercase();
            let symbol = name.len() == 1 && SYMBOL_ADDRESSES.contains(name.as_bytes()[0] as char);
            // `,R` `,C`: a comma before a letter (Fanuc's corner rounding and chamfer).
            let comma = name.len() == 2 && name.as_bytes()[0] == b',' && name.as_bytes()[1].is_ascii_alphabetic();
            if !symbol
                && !comma
                && (name.is_empty()
                    || !name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
                    || !name.as_bytes()[0].is_ascii_alphabetic())
            {
                self.error(
                    Self::attr_range(c, "name"),
                    format!("address name `{name}` must be a letter followed by letters or digits, a comma and a letter (`,R`), or one of `{SYMBOL_ADDRESSES}`"),
                );
                continue;
            }
            let Some(role) = Role::parse(role).filter(|r| !r.is_internal()) else {
                self.error(Self::attr_range(c, "role"), format!("unknown role `{role}`; see the <address> documentation in dialect.xsd"));
                continue;
            };
            let assign = match self.attr(c, "form").unwrap_or("value") {
                "value" => false,
                "assign" => true,
                other => {
                    self.error(Self::attr_range(c, "form"), format!("unknown form `{other}`"));
                    false
                }
            };
            let incremental = match self.attr(c, "mode").unwrap_or("modal") {
                "modal" => false,
                "incremental" => true,
                other => {
                    self.error(Self::attr_range(c, "mode"), format!("unknown mode `{other}`; use modal or incremental"));
                    false
                }
            };
            let again = self.role_attr(c, "again");
            let offset_digits = self.attr(c, "offset-digits").and_then(|v| match v.parse::<u8>() {
                Ok(n @ 1..=4) if role == Role::T => Some(n),
                _ => {
                    self.error(
                        Self::attr_range(c, "offset-digits"),
                        format!("`offset-digits` must be 1 to 4, on a tool address, not `{v}`"),
                    );
                    None
                }
            });
            if out.iter().any(|a| a.name == name) {
                self.error(c.range, format!("address `{name}` is declared twice"));
                continue;
            }
            // `M2=3`, `S2=2000` (Siemens): the spindle's number between the letter and `=`.
            let spindle_index = self.attr(c, "spindle-index") == Some("true");
            // `C4=120` (Siemens): an axis the machine data names by letter and number.
            let axis_index = self.attr(c, "axis-index") == Some("true");
            // `T6400.1102` (Mazak): the fraction is the tool's ID code.
            let id_suffix = self.attr(c, "id-suffix") == Some("true") && role == Role::T;
            // `T2.2` (Fagor): the digits after the point name the offset.
            let offset_suffix = self.attr(c, "offset-suffix") == Some("true") && role == Role::T;
            out.push(AddressDef {
                name,
                role,
                assign,
                incremental,
                again,
                offset_digits,
                id_suffix,
                offset_suffix,
                spindle_index,
                axis_index,
            });
        }
        out
    }

    fn cycles(&mut self, el: &Element) -> Vec<CycleDef> {
        self.shape(el, &[], &["cycle"]);
        let mut out: Vec<CycleDef> = Vec::new();
        for c in el.children.iter().filter(|c| c.name == "cycle") {
            self.shape(c, &["name", "meaning", "acts", "surface", "probe"], &["arg"]);
            let surface_below_start = match self.attr(c, "surface").unwrap_or("parameter") {
                "parameter" => false,
                "below-start" => true,
                other => {
                    self.error(Self::attr_range(c, "surface"), format!("`surface` must be parameter or below-start, not `{other}`"));
                    false
                }
            };
            let immediate = match self.attr(c, "acts").unwrap_or("where-written") {
                "where-written" => true,
                "when-called" => false,
                other => {
                    self.error(Self::attr_range(c, "acts"), format!("`acts` must be where-written or when-called, not `{other}`"));
                    true
                }
            };
            let (Some(name), Some(meaning)) = (self.required(c, "name"), self.required(c, "meaning")) else { continue };
            let Some(meaning) = Meaning::parse(meaning) else {
                self.error(Self::attr_range(c, "meaning"), format!("unknown meaning `{meaning}`"));
                continue;
            };
            let mut args = Vec::new();
            for a in c.children.iter().filter(|a| a.name == "arg") {
                self.shape(a, &["name", "role", "use", "param", "sub"], &[]);
                let param = match self.attr(a, "param") {
                    None => None,
                    Some(p) => match p.parse::<u32>() {
                        Ok(n) => Some(n),
                        Err(_) => {
                            self.error(Self::attr_range(a, "param"), format!("`param` must be a parameter number, not `{p}`"));
                            None
                        }
                    },
                };
                let sub = match self.attr(a, "sub") {
                    None => None,
                    Some(p) => match p.parse::<u32>() {
                        Ok(n) if (1..=9).contains(&n) => Some(n),
                        _ => {
                            self.error(Self::attr_range(a, "sub"), format!("`sub` must be a sub-block number 1-9, not `{p}`"));
                            None
                        }
                    },
                };
                let (Some(n), Some(r)) = (self.required(a, "name"), self.required(a, "role")) else { continue };
                let Some(role) = Role::parse(r).filter(|r| !r.is_internal()) else {
                    self.error(Self::attr_range(a, "role"), format!("unknown role `{r}`"));
                    continue;
                };
                let required = match self.attr(a, "use").unwrap_or("optional") {
                    "required" => true,
                    "optional" => false,
                    other => {
                        self.error(Self::attr_range(a, "use"), format!("`use` must be required or optional, not `{other}`"));
                        false
                    }
                };
                args.push(CycleArg { name: n.to_owned(), role, required, param, sub });
            }
            let probe = self.bool(c, "probe", false);
            out.push(CycleDef { name: name.to_ascii_uppercase(), meaning, args, immediate, surface_below_start, probe });
        }
        out
    }

    /// `<recognise>`: `<extension name="h" weight="10"/>`, `<marker regex="..." weight="30" label="BEGIN PGM"/>`.
    fn recognise(&mut self, el: &Element) -> Vec<super::sniff::Evidence> {
        use super::sniff::{Evidence, Marker};
        self.shape(el, &[], &["extension", "marker", "remove"]);
        let mut out = Vec::new();
        for c in el.children.iter().filter(|c| c.name != "remove") {
            let weight = self.number(c, "weight", 10.0);
            if !(0.0..=1000.0).contains(&weight) || weight.fract() != 0.0 {
                self.error(Self::attr_range(c, "weight"), "`weight` must be a whole number from 0 to 1000");
                continue;
            }
            let weight = weight as u32;
            match c.name.as_str() {
                "extension" => {
                    self.shape(c, &["name", "weight"], &[]);
                    let Some(name) = self.required(c, "name") else { continue };
                    let name = name.trim_start_matches('.').to_ascii_lowercase();
                    out.push(Evidence { label: format!(".{name}"), marker: Marker::Extension(name), weight, against: false });
                }
                "marker" => {
                    self.shape(c, &["regex", "weight", "label", "case-sensitive", "against"], &[]);
                    let Some(src) = self.required(c, "regex") else { continue };
                    // Markers ignore case (`(HAAS` and `(haas`) unless the file says otherwise.
                    let source = if self.bool(c, "case-sensitive", false) { src.to_owned() } else { format!("(?i){src}") };
                    match super::Pattern::new(&source) {
                        Ok(re) => {
                            let label = self.attr(c, "label").unwrap_or(src).to_owned();
                            let against = self.bool(c, "against", false);
                            out.push(Evidence { label, marker: Marker::Pattern(re), weight, against });
                        }
                        Err(e) => self.error(Self::attr_range(c, "regex"), format!("invalid regular expression: {e}")),
                    }
                }
                _ => {}
            }
        }
        out
    }

    fn execution_order(&mut self, el: &Element, groups: &[ModalGroup]) -> Vec<Step> {
        self.shape(el, &[], &[]);
        let mut out = Vec::new();
        for item in el.text.split_ascii_whitespace() {
            match Step::parse(item) {
                Some(s) if out.contains(&s) => self.error(el.range, format!("step `{item}` appears twice")),
                Some(s) => out.push(s),
                None => self.error(el.range, format!("unknown step `{item}`")),
            }
        }
        for g in groups {
            if !out.contains(&g.step) && g.step != Step::Misc {
                self.error(
                    el.range,
                    format!("group `{}` takes effect at step `{}`, which the execution order does not list", g.id, g.step.as_str()),
                );
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::groups::parse_code_number;
    use super::*;
    use crate::text::LineIndex;

    fn first_error(xml: &str) -> String {
        let (d, diags) = load(xml);
        assert!(d.is_none());
        let idx = LineIndex::new(xml);
        let e = diags.iter().find(|d| d.is_error()).expect("an error");
        crate::diag::render_short("x.xml", xml, &idx, e)
    }

    #[test]
    fn broken_files_point_at_line_and_column() {
        assert_eq!(
            first_error("<dialect name=\"x\" family=\"f\">\n  <lexical>\n</dialect>"),
            "x.xml:3:1: error[dialect::invalid]: malformed XML: ill-formed document: expected `</lexical>`, but `</dialect>` was found"
        );
        let xml = "<dialect name=\"x\" family=\"f\">\n<lexical><comment open=\"(\" close=\")\"/></lexical>\n<addresses>\n  <address name=\"X\" role=\"axis-q\"/>\n</addresses><execution-order/></dialect>";
        assert_eq!(
            first_error(xml),
            "x.xml:4:21: error[dialect::invalid]: unknown role `axis-q`; see the <address> documentation in dialect.xsd"
        );
    }

    #[test]
    fn code_numbers() {
        assert_eq!(parse_code_number("54.1"), Some(541));
        assert_eq!(parse_code_number("0"), Some(0));
        assert_eq!(parse_code_number("1000"), None);
        assert_eq!(parse_code_number("5.12"), None);
    }
}

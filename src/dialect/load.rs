//! XML text → validated [`Dialect`], with diagnostics that point into the XML.

use super::inherit;
use super::xml::{self, Element};
use super::{
    AddressDef, AxisIndexed, Behaviour, BlockForm, CodeDef, CommentClose, CommentRule, CycleArg, CycleDef, DataForm, DecimalInput, Dialect,
    Directive, KeywordRest, KeywordSpec, Lexical, LogFile, Macros, MainReturn, Meaning, ModalGroup, NumberForms, ParamSpec, Role,
    SkipPosition, Statement, Step, SystemVar, TapStyle, TimeUnit,
};
use crate::diag::{Code, Diagnostic};
use crate::text::TextRange;

mod records;

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
            output,
            letter_roles: [None; 128],
            letter_incremental: 0,
            plain_roles: [None; 128],
            g_table: Vec::new(),
            m_table: Vec::new(),
            keyword_codes: Vec::new(),
        })
    }

    fn lexical(&mut self, el: &Element) -> Lexical {
        self.shape(
            el,
            &[
                "block-form",
                "spaces-in-numbers",
                "assign-values",
                "bare-function-arguments",
                "identifier-variables",
                "symbolic-comparisons",
            ],
            &[
                "axis-modes",
                "label",
                "string",
                "numbers",
                "system-variables",
                "array",
                "axis-indexed",
                "comment",
                "block-skip",
                "block-number",
                "program-delimiter",
                "expression",
                "parameter",
                "block-end",
                "continuation",
                "program-number",
                "control-word",
                "foreign",
                "statement-prefix",
                "comment-directive",
            ],
        );
        let block_form = match self.attr(el, "block-form").unwrap_or("word-address") {
            "word-address" => BlockForm::WordAddress,
            "keyword-first" => BlockForm::KeywordFirst,
            "record" => BlockForm::Record,
            other => {
                self.error(Self::attr_range(el, "block-form"), format!("unknown block-form `{other}`"));
                BlockForm::WordAddress
            }
        };
        let mut lex = Lexical {
            block_form,
            leading_block_number: false,
            assign_values: self.bool(el, "assign-values", false),
            axis_modes: None,
            rotary_absolute: Vec::new(),
            label_suffix: None,
            string_quote: None,
            numbers: NumberForms::default(),
            system_variable_prefix: None,
            array_brackets: None,
            axis_indexed: Vec::new(),
            bare_function_arguments: self.bool(el, "bare-function-arguments", false),
            identifier_variables: self.bool(el, "identifier-variables", false),
            symbolic_comparisons: self.bool(el, "symbolic-comparisons", false),
            comments: Vec::new(),
            block_skip: None,
            block_number: None,
            program_delimiter: None,
            block_skip_levels: false,
            leader_skipped: false,
            delimiter_first_line: false,
            header_words: false,
            expression: None,
            parameter: None,
            block_end: None,
            continuation: None,
            spaces_in_numbers: self.bool(el, "spaces-in-numbers", false),
            program_number: None,
            program_number_alt: None,
            control_word: None,
            foreign: Vec::new(),
            named_blocks: false,
            named_programs: false,
            statement_prefix: Vec::new(),
            directives: Vec::new(),
        };
        for c in &el.children {
            match c.name.as_str() {
                "axis-modes" => {
                    self.shape(c, &["absolute", "incremental", "rotary-absolute"], &[]);
                    if let (Some(a), Some(i)) = (self.required(c, "absolute"), self.required(c, "incremental")) {
                        lex.axis_modes = Some((a.to_ascii_uppercase(), i.to_ascii_uppercase()));
                    }
                    if let Some(r) = self.attr(c, "rotary-absolute") {
                        lex.rotary_absolute = r.split_whitespace().map(str::to_ascii_uppercase).collect();
                    }
                }
                "label" => {
                    self.shape(c, &["suffix"], &[]);
                    lex.label_suffix = self.char_attr(c, "suffix");
                }
                "string" => {
                    self.shape(c, &["quote"], &[]);
                    lex.string_quote = self.char_attr(c, "quote");
                }
                "numbers" => {
                    self.shape(c, &["exponent", "radix-quote", "hex", "binary"], &[]);
                    lex.numbers.exponent = self.attr(c, "exponent").map(str::to_ascii_uppercase);
                    if let Some(q) = self.char_attr(c, "radix-quote") {
                        let hex = self.letter_attr(c, "hex").unwrap_or('H').to_ascii_uppercase();
                        let binary = self.letter_attr(c, "binary").unwrap_or('B').to_ascii_uppercase();
                        lex.numbers.radix = Some((q, hex, binary));
                    }
                }
                "system-variables" => {
                    self.shape(c, &["prefix"], &[]);
                    lex.system_variable_prefix = self.char_attr(c, "prefix");
                }
                "array" => {
                    self.shape(c, &["open", "close"], &[]);
                    if let (Some(o), Some(e)) = (self.char_attr(c, "open"), self.char_attr(c, "close"))
                        && o.is_ascii()
                        && e.is_ascii()
                    {
                        lex.array_brackets = Some((o as u8, e as u8));
                    }
                }
                "axis-indexed" => {
                    self.shape(c, &["name", "meaning"], &[]);
                    let moves = match self.attr(c, "meaning").unwrap_or("axis-setting") {
                        "axis-word" => true,
                        "axis-setting" => false,
                        other => {
                            self.error(Self::attr_range(c, "meaning"), format!("unknown axis-indexed meaning `{other}`"));
                            false
                        }
                    };
                    match self.attr(c, "name") {
                        Some(n) if !n.is_empty() && n.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_') => {
                            lex.axis_indexed.push(AxisIndexed { name: n.to_ascii_uppercase(), moves });
                        }
                        _ => self.error(c.range, "an axis-indexed name is letters, digits and `_`".to_owned()),
                    }
                }
                "comment" => {
                    self.shape(c, &["open", "close", "position", "nested"], &[]);
                    let nested = self.bool(c, "nested", false);
                    let block_start = match self.attr(c, "position").unwrap_or("anywhere") {
                        "anywhere" => false,
                        "block-start" => true,
                        other => {
                            self.error(Self::attr_range(c, "position"), format!("unknown comment position `{other}`"));
                            false
                        }
                    };
                    let open = self.char_attr(c, "open");
                    let close = match self.required(c, "close") {
                        Some("eol") => Some(CommentClose::EndOfLine),
                        Some(_) => self.char_attr(c, "close").map(CommentClose::Char),
                        None => None,
                    };
                    if open.is_none() {
                        self.error(c.range, "<comment> needs a one-character `open`");
                    }
                    if let (Some(open), Some(close)) = (open, close) {
                        lex.comments.push(CommentRule { open, close, block_start, nested });
                    }
                }
                "comment-directive" => {
                    self.shape(c, &["prefix", "meaning"], &[]);
                    let meaning = match self.required(c, "meaning") {
                        Some("message") => Some(Directive::Message),
                        Some("abort") => Some(Directive::Abort),
                        Some("log") => Some(Directive::Log),
                        Some("log-open") => Some(Directive::LogFile(LogFile::Open)),
                        Some("log-append") => Some(Directive::LogFile(LogFile::Append)),
                        Some("log-close") => Some(Directive::LogFile(LogFile::Close)),
                        Some("log-line") => Some(Directive::LogFile(LogFile::Line)),
                        Some("simulator") => Some(Directive::Simulator),
                        Some(other) => {
                            self.error(
                                Self::attr_range(c, "meaning"),
                                format!(
                                    "a comment directive's meaning is message, abort, log, log-open, log-append, log-close, log-line or simulator, not `{other}`"
                                ),
                            );
                            None
                        }
                        None => None,
                    };
                    match self.required(c, "prefix") {
                        Some("") => self.error(Self::attr_range(c, "prefix"), "a comment directive's prefix cannot be empty"),
                        Some(prefix) => {
                            if let Some(m) = meaning {
                                lex.directives.push((prefix.to_ascii_lowercase(), m));
                            }
                        }
                        None => {}
                    }
                }
                "block-skip" => {
                    self.shape(c, &["char", "position", "levels"], &[]);
                    lex.block_skip_levels = self.bool(c, "levels", false);
                    let pos = match self.attr(c, "position").unwrap_or("line-start") {
                        "line-start" => SkipPosition::LineStart,
                        "line-start-or-after-number" => SkipPosition::LineStartOrAfterNumber,
                        other => {
                            self.error(Self::attr_range(c, "position"), format!("unknown position `{other}`"));
                            SkipPosition::LineStart
                        }
                    };
                    lex.block_skip = self.char_attr(c, "char").map(|ch| (ch, pos));
                }
                "block-number" => {
                    self.shape(c, &["address", "leading", "names"], &[]);
                    lex.leading_block_number = self.bool(c, "leading", false);
                    lex.named_blocks = self.bool(c, "names", false);
                    if c.attrs.iter().any(|a| a.name == "address") {
                        lex.block_number = self.letter_attr(c, "address");
                    }
                }
                "program-delimiter" => {
                    self.shape(c, &["char", "opening", "leader", "header"], &[]);
                    lex.program_delimiter = self.char_attr(c, "char");
                    lex.leader_skipped = self.either(c, "leader", "read", "skipped");
                    lex.delimiter_first_line = self.either(c, "opening", "anywhere", "first-line");
                    lex.header_words = self.either(c, "header", "skipped", "words");
                }
                "expression" => {
                    self.shape(c, &["open", "close"], &[]);
                    if let (Some(o), Some(cl)) = (self.char_attr(c, "open"), self.char_attr(c, "close")) {
                        lex.expression = Some((o, cl));
                    }
                }
                "parameter" => {
                    self.shape(c, &["sigil", "named"], &[]);
                    let named = self.bool(c, "named", false);
                    lex.parameter = self.char_attr(c, "sigil").map(|s| (s, named));
                }
                "block-end" => {
                    self.shape(c, &["char"], &[]);
                    lex.block_end = self.char_attr(c, "char");
                }
                "continuation" => {
                    self.shape(c, &["char"], &[]);
                    lex.continuation = self.char_attr(c, "char");
                }
                "program-number" => {
                    self.shape(c, &["address", "alternate", "names"], &[]);
                    lex.program_number = self.letter_attr(c, "address");
                    lex.named_programs = self.bool(c, "names", false);
                    lex.program_number_alt = self.char_attr(c, "alternate");
                }
                "control-word" => {
                    self.shape(c, &["address"], &[]);
                    lex.control_word = self.letter_attr(c, "address");
                }
                "statement-prefix" => {
                    self.shape(c, &["chars"], &[]);
                    if let Some(chars) = self.required(c, "chars") {
                        if chars.is_empty() || !chars.bytes().all(|b| b.is_ascii_punctuation()) {
                            self.error(Self::attr_range(c, "chars"), "`chars` must be punctuation characters such as #$%");
                        } else {
                            lex.statement_prefix = chars.bytes().collect();
                        }
                    }
                }
                "foreign" => {
                    self.shape(c, &["regex", "name"], &[]);
                    let (Some(src), Some(name)) = (self.required(c, "regex"), self.required(c, "name")) else { continue };
                    match super::Pattern::new(src) {
                        Ok(re) => lex.foreign.push((re, name.to_owned())),
                        Err(e) => self.error(Self::attr_range(c, "regex"), format!("invalid regular expression: {e}")),
                    }
                }
                _ => {}
            }
        }
        if lex.comments.is_empty() && lex.block_form != BlockForm::Record {
            self.error(el.range, "<lexical> needs at least one <comment> rule");
        }
        lex
    }

    fn behaviour(&mut self, el: Option<&Element>, addresses: &[AddressDef]) -> Behaviour {
        let mut b = Behaviour {
            decimal_input: DecimalInput::Calculator,
            dwell_unit: TimeUnit::Seconds,
            tool_change_stops_spindle: true,
            tool_change_applies_length: false,
            tool_change_rereads_position: false,
            h0_spindle_tool: false,
            probe_backoff_mm: 0.0,
            probe_backoff_inch: 0.0,
            probe_tripped: None,
            peck_clearance_mm: 0.254,
            peck_clearance_inch: 0.01,
            arc_tolerance_mm: 0.002,
            arc_tolerance_inch: 0.002 / 25.4,
            arc_tolerance_steps: 0.0,
            cycle_r_defaults_to_initial: false,
            arc_relative_tolerance: None,
            assign_before_reads: false,
            feed_mode_resets_feed: false,
            machine_m_codes: false,
            resident_programs: false,
            tool_word_changes: false,
            arc_centres_pole: false,
            initial_feed_per_rev: false,
            tapping: TapStyle::RPlane,
            magnitude_rounding: false,
            motion_in_place: false,
            unused_words_rejected: false,
            end_required: false,
            x_diameter: false,
            initial_plane: crate::canon::Plane::Xy,
            initial_retract_r: false,
        };
        let Some(el) = el else { return b };
        self.shape(
            el,
            &[
                "decimal-input",
                "increment-mm",
                "increment-inch",
                "scaled",
                "dwell-unit",
                "tool-change-stops-spindle",
                "tool-change-applies-length",
                "position-after-tool-change",
                "h0",
                "probe-backoff-mm",
                "probe-tripped",
                "probe-backoff-inch",
                "peck-clearance-mm",
                "peck-clearance-inch",
                "arc-tolerance-mm",
                "arc-tolerance-inch",
                "arc-tolerance-steps",
                "cycle-without-r",
                "arc-relative-tolerance",
                "parameter-assignment",
                "feed-mode-resets-feed",
                "machine-m-codes",
                "resident-programs",
                "tool-word-changes",
                "arc-centres",
                "initial-feed",
                "tap-retract",
                "integer-rounding",
                "unused-words",
                "program-end",
                "motion-without-axes",
                "x-words",
                "initial-plane",
                "initial-retract",
            ],
            &[],
        );
        b.decimal_input = match self.attr(el, "decimal-input").unwrap_or("calculator") {
            "calculator" => DecimalInput::Calculator,
            "least-increment" => DecimalInput::LeastIncrement {
                mm: self.number(el, "increment-mm", 0.001),
                inch: self.number(el, "increment-inch", 0.0001),
                scaled: self.roles(el, "scaled", addresses),
            },
            other => {
                self.error(Self::attr_range(el, "decimal-input"), format!("unknown decimal-input `{other}`"));
                DecimalInput::Calculator
            }
        };
        b.dwell_unit = match self.attr(el, "dwell-unit").unwrap_or("seconds") {
            "seconds" => TimeUnit::Seconds,
            "milliseconds" => TimeUnit::Milliseconds,
            other => {
                self.error(Self::attr_range(el, "dwell-unit"), format!("unknown dwell-unit `{other}`"));
                TimeUnit::Seconds
            }
        };
        b.tool_change_stops_spindle = self.bool(el, "tool-change-stops-spindle", true);
        b.tool_change_applies_length = self.bool(el, "tool-change-applies-length", false);
        b.h0_spindle_tool = self.either(el, "h0", "no-offset", "spindle-tool");
        b.tool_change_rereads_position = self.either(el, "position-after-tool-change", "program", "last-move");
        b.probe_backoff_mm = self.number(el, "probe-backoff-mm", 0.0).max(0.0);
        b.probe_backoff_inch = self.number(el, "probe-backoff-inch", b.probe_backoff_mm / 25.4).max(0.0);
        b.probe_tripped = match self.attr(el, "probe-tripped") {
            None | Some("unknown") => None,
            Some("1") => Some(1.0),
            Some("0") => Some(0.0),
            Some(other) => {
                self.error(Self::attr_range(el, "probe-tripped"), format!("`probe-tripped` is 1, 0 or unknown, not `{other}`"));
                None
            }
        };
        b.peck_clearance_mm = self.number(el, "peck-clearance-mm", 0.254);
        b.peck_clearance_inch = self.number(el, "peck-clearance-inch", 0.01);
        b.arc_tolerance_mm = self.number(el, "arc-tolerance-mm", 0.002);
        b.arc_tolerance_inch = self.number(el, "arc-tolerance-inch", b.arc_tolerance_mm / 25.4);
        b.arc_tolerance_steps = self.number(el, "arc-tolerance-steps", 0.0).max(0.0);
        b.cycle_r_defaults_to_initial = self.either(el, "cycle-without-r", "error", "initial-level");
        b.arc_relative_tolerance = self.attr(el, "arc-relative-tolerance").map(|_| self.number(el, "arc-relative-tolerance", 0.0));
        b.feed_mode_resets_feed = self.bool(el, "feed-mode-resets-feed", false);
        b.machine_m_codes = self.bool(el, "machine-m-codes", false);
        b.resident_programs = self.bool(el, "resident-programs", false);
        b.tool_word_changes = self.bool(el, "tool-word-changes", false);
        b.arc_centres_pole = self.either(el, "arc-centres", "offsets", "pole");
        b.initial_feed_per_rev = self.either(el, "initial-feed", "per-minute", "per-rev");
        b.motion_in_place = self.either(el, "motion-without-axes", "mode-only", "in-place");
        b.magnitude_rounding = self.either(el, "integer-rounding", "floor-ceiling", "toward-zero");
        b.unused_words_rejected = self.either(el, "unused-words", "ignored", "rejected");
        b.end_required = self.either(el, "program-end", "optional", "required");
        b.x_diameter = self.either(el, "x-words", "radius", "diameter");
        b.initial_retract_r = self.either(el, "initial-retract", "initial-level", "r-plane");
        b.initial_plane = match self.attr(el, "initial-plane").unwrap_or("xy") {
            "xy" => crate::canon::Plane::Xy,
            "xz" => crate::canon::Plane::Xz,
            "yz" => crate::canon::Plane::Yz,
            other => {
                self.error(Self::attr_range(el, "initial-plane"), format!("`initial-plane` must be xy, xz or yz, not `{other}`"));
                crate::canon::Plane::Xy
            }
        };
        b.tapping = match self.attr(el, "tap-retract").unwrap_or("r-plane") {
            "r-plane" => TapStyle::RPlane,
            "clear" => TapStyle::Clear,
            other => {
                self.error(Self::attr_range(el, "tap-retract"), format!("`tap-retract` must be r-plane or clear, not `{other}`"));
                TapStyle::RPlane
            }
        };
        b.assign_before_reads = match self.attr(el, "parameter-assignment").unwrap_or("after-reads") {
            "after-reads" => false,
            "before-reads" => true,
            other => {
                self.error(
                    Self::attr_range(el, "parameter-assignment"),
                    format!("`parameter-assignment` must be after-reads or before-reads, not `{other}`"),
                );
                false
            }
        };
        b
    }

    fn addresses(&mut self, el: &Element) -> Vec<AddressDef> {
        /// Characters that may be an address on their own (LinuxCNC's polar `@` and `^`).
        const SYMBOL_ADDRESSES: &str = "@^";
        self.shape(el, &[], &["address"]);
        let mut out: Vec<AddressDef> = Vec::new();
        for c in el.children.iter().filter(|c| c.name == "address") {
            self.shape(c, &["name", "role", "form", "mode", "again", "offset-digits"], &[]);
            let (Some(name), Some(role)) = (self.required(c, "name"), self.required(c, "role")) else { continue };
            let name = name.to_ascii_uppercase();
            let symbol = name.len() == 1 && SYMBOL_ADDRESSES.contains(name.as_bytes()[0] as char);
            if !symbol
                && (name.is_empty()
                    || !name.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_')
                    || !name.as_bytes()[0].is_ascii_alphabetic())
            {
                self.error(
                    Self::attr_range(c, "name"),
                    format!("address name `{name}` must be a letter followed by letters or digits, or one of `{SYMBOL_ADDRESSES}`"),
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
            out.push(AddressDef { name, role, assign, incremental, again, offset_digits });
        }
        out
    }

    fn macros(&mut self, el: &Element) -> Macros {
        self.shape(
            el,
            &[
                "null-value",
                "locals",
                "call-depth",
                "repeat-in-p",
                "conditions",
                "end-label",
                "call-by-name",
                "call-repeat",
                "call-repeat-counts",
                "main-return",
                "call-start",
                "bare-if-jump",
                "unset-variables",
                "return-value",
                "outside-variables",
                "highest-variable",
                "called-programs",
                "called-extensions",
                "unknown-conditions",
                "unlisted-tools",
                "return-tells-called",
                "definition-start",
                "definition-end",
            ],
            &["statement", "arguments", "system-variable"],
        );
        let mut m = Macros {
            null_value: self.bool(el, "null-value", false),
            repeat_in_p: self.bool(el, "repeat-in-p", false),
            call_by_name: self.bool(el, "call-by-name", false),
            end_label: self.attr(el, "end-label").map(|l| l.trim().to_ascii_lowercase()),
            definition_block: match (self.attr(el, "definition-start"), self.attr(el, "definition-end")) {
                (Some(a), Some(b)) if !a.trim().is_empty() && !b.trim().is_empty() => {
                    Some((a.trim().to_ascii_uppercase(), b.trim().to_ascii_uppercase()))
                }
                (None, None) => None,
                _ => {
                    self.error(el.range, "`definition-start` and `definition-end` go together".to_owned());
                    None
                }
            },
            call_repeat: self.attr(el, "call-repeat").map(|w| w.trim().to_ascii_uppercase()),
            call_start: self.letter_attr(el, "call-start").map(|c| c as u8),
            bare_if_jump: self.bool(el, "bare-if-jump", false),
            return_value: self.attr(el, "return-value").map(|n| n.split_whitespace().collect::<String>().to_lowercase()),
            ..Macros::default()
        };
        m.bare_conditions = self.either(el, "conditions", "bracketed", "bare");
        match self.attr(el, "unset-variables") {
            None | Some("error") => {}
            Some("zero") => m.unset_reads_zero = true,
            Some("unknown") => m.unset_unknown = true,
            Some(other) => {
                self.error(Self::attr_range(el, "unset-variables"), format!("`unset-variables` is error, zero or unknown, not `{other}`"))
            }
        }
        m.unknown_conditions = self.either(el, "unknown-conditions", "false", "true");
        m.unlisted_tools_unknown = self.either(el, "unlisted-tools", "zero", "unknown");
        m.return_tells_called = self.bool(el, "return-tells-called", true);
        let highest = self.number(el, "highest-variable", 9999.0);
        m.highest_variable = if (0.0..super::vocab::MAX_HIGH_PARAM as f64).contains(&highest) {
            highest as u32
        } else {
            self.error(
                Self::attr_range(el, "highest-variable"),
                format!("`highest-variable` is at most {}", super::vocab::MAX_HIGH_PARAM - 1),
            );
            9999
        };
        if let Some(v) = self.attr(el, "outside-variables") {
            for part in v.split_whitespace() {
                let (a, b) = part.split_once('-').unwrap_or((part, part));
                match (a.trim().parse::<u32>(), b.trim().parse::<u32>()) {
                    (Ok(a), Ok(b)) if a <= b => m.outside.push((a, b)),
                    _ => self.error(
                        Self::attr_range(el, "outside-variables"),
                        format!("`outside-variables` lists ranges such as 100-199 500-999, not `{part}`"),
                    ),
                }
            }
        }
        if let Some(v) = self.attr(el, "called-programs") {
            match v.split_once('-').and_then(|(a, b)| Some((a.trim().parse::<u32>().ok()?, b.trim().parse::<u32>().ok()?))) {
                Some((a, b)) if a <= b => m.called_numbers = Some((a, b)),
                _ => self.error(
                    Self::attr_range(el, "called-programs"),
                    format!("`called-programs` must be a range such as 9000-9999, not `{v}`"),
                ),
            }
        }
        if let Some(v) = self.attr(el, "called-extensions") {
            m.called_extensions = v.split_whitespace().map(|e| e.trim_start_matches('.').to_ascii_lowercase()).collect();
        }
        m.call_repeat_additional = self.either(el, "call-repeat-counts", "total", "additional");
        m.main_return = match self.attr(el, "main-return").unwrap_or("error") {
            "error" => MainReturn::Error,
            "end" => MainReturn::End,
            "restart" => MainReturn::Restart,
            other => {
                self.error(Self::attr_range(el, "main-return"), format!("`main-return` is error, end or restart, not `{other}`"));
                MainReturn::Error
            }
        };
        if m.call_repeat.as_deref().is_some_and(|w| w.is_empty() || !w.bytes().all(|b| b.is_ascii_alphabetic())) {
            self.error(Self::attr_range(el, "call-repeat"), "`call-repeat` must be a word of letters");
            m.call_repeat = None;
        }
        if let Some(v) = self.attr(el, "locals") {
            match v.split_once('-').and_then(|(a, b)| Some((a.trim().parse::<u16>().ok()?, b.trim().parse::<u16>().ok()?))) {
                Some((a, b)) if a >= 1 && a <= b && b < 1000 => m.locals = (a, b),
                _ => self.error(Self::attr_range(el, "locals"), format!("`locals` must be a range such as 1-33, not `{v}`")),
            }
        }
        m.call_depth = self.number(el, "call-depth", 10.0).clamp(1.0, 100.0) as u32;
        for c in &el.children {
            match c.name.as_str() {
                "statement" => {
                    self.shape(c, &["keyword", "meaning"], &[]);
                    let (Some(k), Some(meaning)) = (self.required(c, "keyword"), self.required(c, "meaning")) else { continue };
                    let Some(meaning) = Statement::parse(meaning) else {
                        self.error(Self::attr_range(c, "meaning"), format!("unknown statement meaning `{meaning}`"));
                        continue;
                    };
                    let k = k.to_ascii_uppercase();
                    if k.split(' ').any(|w| w.is_empty() || !w.bytes().all(|b| b.is_ascii_alphabetic())) {
                        self.error(
                            Self::attr_range(c, "keyword"),
                            format!("statement keyword `{k}` must be letters, or words of letters separated by single blanks"),
                        );
                    } else if m.statements.iter().any(|&(ref x, other)| {
                        // One keyword may head a repeat-until loop and a section repeat: a
                        // label after it tells them apart.
                        let pair = [other, meaning];
                        *x == k && !(pair.contains(&Statement::RepeatUntil) && pair.contains(&Statement::RepeatSection))
                    }) {
                        self.error(c.range, format!("statement `{k}` is declared twice"));
                    } else {
                        m.statements.push((k, meaning));
                    }
                }
                "arguments" => {
                    self.shape(c, &[], &[]);
                    for item in c.text.split_ascii_whitespace() {
                        let parsed = item.split_once('=').and_then(|(l, n)| {
                            let l = l.as_bytes();
                            (l.len() == 1 && l[0].is_ascii_alphabetic()).then_some(())?;
                            Some((l[0].to_ascii_uppercase(), n.parse::<u16>().ok()?))
                        });
                        match parsed {
                            Some((l, n)) => m.arguments[(l - b'A') as usize] = Some(n),
                            None => self.error(c.range, format!("argument `{item}` must look like A=1")),
                        }
                    }
                }
                _ if self.attr(c, "name").is_some() => {
                    self.shape(c, &["name", "meaning", "value"], &[]);
                    let (Some(name), Some(meaning)) = (self.attr(c, "name"), self.required(c, "meaning")) else { continue };
                    let name = super::vocab::normalise_name(name);
                    let value = self.number(c, "value", 0.0);
                    match SystemVar::parse(meaning) {
                        Some(v) => m.system_named.push((name, v, value)),
                        None => self.error(Self::attr_range(c, "meaning"), format!("unknown system variable meaning `{meaning}`")),
                    }
                }
                _ => {
                    self.shape(c, &["number", "meaning"], &[]);
                    let (Some(n), Some(meaning)) = (self.required(c, "number"), self.required(c, "meaning")) else { continue };
                    let Ok(n) = n.parse::<u32>() else {
                        self.error(Self::attr_range(c, "number"), format!("`{n}` is not a variable number"));
                        continue;
                    };
                    match SystemVar::parse(meaning) {
                        Some(v) => m.system.push((n, v)),
                        None => self.error(Self::attr_range(c, "meaning"), format!("unknown system variable meaning `{meaning}`")),
                    }
                }
            }
        }
        m.statements.sort_by(|a, b| b.0.len().cmp(&a.0.len()).then(a.0.cmp(&b.0)));
        m
    }

    fn groups(&mut self, el: &Element, addresses: &[AddressDef]) -> (Vec<ModalGroup>, Vec<CodeDef>) {
        self.shape(el, &[], &["group"]);
        let mut groups: Vec<ModalGroup> = Vec::new();
        let mut codes: Vec<CodeDef> = Vec::new();
        for g in el.children.iter().filter(|c| c.name == "group") {
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
            let gi = groups.len();
            groups.push(ModalGroup { id, modal, step });
            for c in g.children.iter().filter(|c| c.name == "code") {
                self.shape(
                    c,
                    &[
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
                        "args",
                    ],
                    &[],
                );
                let keyword = self.keyword_spec(c);
                let value = match (self.attr(c, "value"), &keyword) {
                    (Some(v), None) => v,
                    (None, Some(_)) => "0",
                    _ => {
                        self.error(c.range, "a <code> needs either `value` (G1, M3) or `keyword` (TRANS, TOOL CALL)");
                        continue;
                    }
                };
                let Some(meaning) = self.required(c, "meaning") else { continue };
                let Some(number) = parse_code_number(value) else {
                    self.error(Self::attr_range(c, "value"), format!("code value `{value}` must be a number such as 1 or 54.1 below 1000"));
                    continue;
                };
                let Some(meaning) = Meaning::parse(meaning) else {
                    self.error(Self::attr_range(c, "meaning"), format!("unknown meaning `{meaning}`"));
                    continue;
                };
                let index = self.number(c, "index", 0.0) as u8;
                if meaning == Meaning::Wcs && !(1..=9).contains(&index) {
                    self.error(c.range, "a `wcs` code needs an `index` from 1 to 9");
                }
                if let Some(k) = &keyword {
                    if codes.iter().any(|x| x.keyword.as_ref().is_some_and(|o| o.text == k.text)) {
                        self.error(c.range, format!("keyword `{}` is declared twice", k.text));
                        continue;
                    }
                } else if codes.iter().any(|x| x.keyword.is_none() && x.letter == letter && x.number == number) {
                    self.error(c.range, format!("code {letter}{value} is declared twice"));
                    continue;
                }
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
                let name = self.attr(c, "name").unwrap_or(meaning.as_str()).to_owned();
                let name = match &keyword {
                    Some(k) if self.attr(c, "name").is_none() => k.text.clone(),
                    _ => name,
                };
                let forms = self.forms(c);
                let gives_way = self.bool(c, "gives-way", false);
                let args = self.code_args(c, addresses, &params);
                let named = keyword.is_none() && self.attr(c, "rest") == Some("words");
                codes.push(CodeDef { letter, number, meaning, index, name, group: gi, params, keyword, forms, gives_way, args, named });
            }
        }
        (groups, codes)
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

    fn cycles(&mut self, el: &Element) -> Vec<CycleDef> {
        self.shape(el, &[], &["cycle"]);
        let mut out: Vec<CycleDef> = Vec::new();
        for c in el.children.iter().filter(|c| c.name == "cycle") {
            self.shape(c, &["name", "meaning", "acts", "surface"], &["arg"]);
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
            out.push(CycleDef { name: name.to_ascii_uppercase(), meaning, args, immediate, surface_below_start });
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

/// `54.1` → 541; at most one decimal digit, below 1000.
fn parse_code_number(s: &str) -> Option<u16> {
    let (int, frac) = s.split_once('.').unwrap_or((s, "0"));
    let int: u16 = int.parse().ok()?;
    let frac: u16 = if frac.len() == 1 { frac.parse().ok()? } else { return None };
    (int < 1000).then_some(int * 10 + frac)
}

#[cfg(test)]
mod tests {
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

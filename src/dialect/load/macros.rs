//! Loading `<macros>`: the dialect's macro language (statement keywords, local-variable
//! ranges, macro-call argument letters, system variables, how calls and unset variables
//! behave). The door is `Cx::macros`; attributes with a syntax of their own and each kind of
//! child element have a reader.

use super::super::xml::Element;
use super::super::{Macros, MainReturn, Statement, SystemVar};
use super::Cx;

/// The attributes `<macros>` may carry.
const ATTRIBUTES: &[&str] = &[
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
    "checks-nesting",
    "if-then-optional",
    "if-alone-reads",
    "unset-variables",
    "return-value",
    "outside-variables",
    "global-variables",
    "highest-variable",
    "called-programs",
    "probe-programs",
    "called-extensions",
    "unknown-conditions",
    "unlisted-tools",
    "modal-tool",
    "return-tells-called",
    "definition-start",
    "definition-end",
    "machine-functions",
];

impl Cx {
    /// `<macros>`: its attributes, then its statements, argument letters and system variables
    /// in document order. Statements are kept longest keyword first.
    pub(super) fn macros(&mut self, el: &Element) -> Macros {
        self.shape(el, ATTRIBUTES, &["statement", "arguments", "system-variable", "tool-data", "tool-column", "tool-table"]);
        let mut m = Macros {
            null_value: self.bool(el, "null-value", false),
            repeat_in_p: self.bool(el, "repeat-in-p", false),
            call_by_name: self.bool(el, "call-by-name", false),
            end_label: self.attr(el, "end-label").map(|l| l.trim().to_ascii_lowercase()),
            definition_block: self.definition_block(el),
            call_repeat: self.attr(el, "call-repeat").map(|w| w.trim().to_ascii_uppercase()),
            call_start: self.letter_attr(el, "call-start").map(|c| c as u8),
            bare_if_jump: self.bool(el, "bare-if-jump", false),
            checks_nesting: self.bool(el, "checks-nesting", false),
            if_then_optional: self.bool(el, "if-then-optional", false),
            if_alone_reads: self.bool(el, "if-alone-reads", false),
            return_value: self.attr(el, "return-value").map(|n| n.split_whitespace().collect::<String>().to_lowercase()),
            machine_functions: self
                .attr(el, "machine-functions")
                .map(|v| v.split_whitespace().map(str::to_ascii_uppercase).collect())
                .unwrap_or_default(),
            ..Macros::default()
        };
        m.bare_conditions = self.either(el, "conditions", "bracketed", "bare");
        self.unset_variables(el, &mut m);
        m.unknown_conditions = self.either(el, "unknown-conditions", "false", "true");
        m.unlisted_tools_unknown = self.either(el, "unlisted-tools", "zero", "unknown");
        m.modal_tool_unknown = self.either(el, "modal-tool", "zero", "unknown");
        m.return_tells_called = self.bool(el, "return-tells-called", true);
        m.highest_variable = self.highest_variable(el);
        self.outside_variables(el, &mut m);
        if let Some(range) = self.called_programs(el) {
            m.called_numbers = Some(range);
        }
        if let Some(v) = self.attr(el, "called-extensions") {
            m.called_extensions = v.split_whitespace().map(|e| e.trim_start_matches('.').to_ascii_lowercase()).collect();
        }
        m.call_repeat_additional = self.either(el, "call-repeat-counts", "total", "additional");
        m.main_return = self.main_return(el);
        if m.call_repeat.as_deref().is_some_and(|w| w.is_empty() || !w.bytes().all(|b| b.is_ascii_alphabetic())) {
            self.error(Self::attr_range(el, "call-repeat"), "`call-repeat` must be a word of letters");
            m.call_repeat = None;
        }
        if let Some(range) = self.locals(el) {
            m.locals = range;
        }
        m.call_depth = self.number(el, "call-depth", 10.0).clamp(1.0, 100.0) as u32;
        for c in &el.children {
            match c.name.as_str() {
                "statement" => self.statement_def(c, &mut m),
                "arguments" => self.argument_letters(c, &mut m),
                "tool-data" => self.tool_data(c, &mut m),
                "tool-column" => self.tool_column(c, &mut m),
                "tool-table" => self.tool_table(c, &mut m),
                _ if self.attr(c, "name").is_some() => self.named_system_variable(c, &mut m),
                _ => self.numbered_system_variable(c, &mut m),
            }
        }
        m.statements.sort_by(|a, b| b.0.len().cmp(&a.0.len()).then(a.0.cmp(&b.0)));
        m
    }

    /// `definition-start` and `definition-end`: the keywords around a macro definition, both
    /// or neither.
    fn definition_block(&mut self, el: &Element) -> Option<(String, String)> {
        match (self.attr(el, "definition-start"), self.attr(el, "definition-end")) {
            (Some(a), Some(b)) if !a.trim().is_empty() && !b.trim().is_empty() => {
                Some((a.trim().to_ascii_uppercase(), b.trim().to_ascii_uppercase()))
            }
            (None, None) => None,
            _ => {
                self.error(el.range, "`definition-start` and `definition-end` go together".to_owned());
                None
            }
        }
    }

    /// `unset-variables`: what reading a variable never set gives (an error, zero, or an
    /// unknown value).
    fn unset_variables(&mut self, el: &Element, m: &mut Macros) {
        match self.attr(el, "unset-variables") {
            None | Some("error") => {}
            Some("zero") => m.unset_reads_zero = true,
            Some("unknown") => m.unset_unknown = true,
            Some(other) => {
                self.error(Self::attr_range(el, "unset-variables"), format!("`unset-variables` is error, zero or unknown, not `{other}`"))
            }
        }
    }

    /// `highest-variable`: the highest variable number a program may use.
    fn highest_variable(&mut self, el: &Element) -> u32 {
        let highest = self.number(el, "highest-variable", 9999.0);
        if (0.0..super::super::vocab::MAX_HIGH_PARAM as f64).contains(&highest) {
            highest as u32
        } else {
            self.error(
                Self::attr_range(el, "highest-variable"),
                format!("`highest-variable` is at most {}", super::super::vocab::MAX_HIGH_PARAM - 1),
            );
            9999
        }
    }

    /// `outside-variables="100-199 500-999"`: variables whose values come from outside the
    /// program.
    fn outside_variables(&mut self, el: &Element, m: &mut Macros) {
        m.outside = self.ranges(el, "outside-variables");
        m.globals = self.ranges(el, "global-variables");
        m.probe_programs = self.ranges(el, "probe-programs");
    }

    /// An attribute listing number ranges (`100-199 500-999`); none when it is absent.
    fn ranges(&mut self, el: &Element, name: &str) -> Vec<(u32, u32)> {
        let mut out = Vec::new();
        let Some(v) = self.attr(el, name) else { return out };
        for part in v.split_whitespace() {
            let (a, b) = part.split_once('-').unwrap_or((part, part));
            match (a.trim().parse::<u32>(), b.trim().parse::<u32>()) {
                (Ok(a), Ok(b)) if a <= b => out.push((a, b)),
                _ => self.error(Self::attr_range(el, name), format!("`{name}` lists ranges such as 100-199 500-999, not `{part}`")),
            }
        }
        out
    }

    /// `called-programs="9000-9999"`: the program numbers that are called programs; `None`
    /// when the attribute is absent or wrong.
    fn called_programs(&mut self, el: &Element) -> Option<(u32, u32)> {
        let v = self.attr(el, "called-programs")?;
        match v.split_once('-').and_then(|(a, b)| Some((a.trim().parse::<u32>().ok()?, b.trim().parse::<u32>().ok()?))) {
            Some((a, b)) if a <= b => Some((a, b)),
            _ => {
                self.error(
                    Self::attr_range(el, "called-programs"),
                    format!("`called-programs` must be a range such as 9000-9999, not `{v}`"),
                );
                None
            }
        }
    }

    /// `main-return`: what a return in the main program does.
    fn main_return(&mut self, el: &Element) -> MainReturn {
        match self.attr(el, "main-return").unwrap_or("error") {
            "error" => MainReturn::Error,
            "end" => MainReturn::End,
            "restart" => MainReturn::Restart,
            other => {
                self.error(Self::attr_range(el, "main-return"), format!("`main-return` is error, end or restart, not `{other}`"));
                MainReturn::Error
            }
        }
    }

    /// `locals="1-33"`: the local variables of a macro call; `None` when the attribute is
    /// absent or wrong.
    fn locals(&mut self, el: &Element) -> Option<(u16, u16)> {
        let v = self.attr(el, "locals")?;
        match v.split_once('-').and_then(|(a, b)| Some((a.trim().parse::<u16>().ok()?, b.trim().parse::<u16>().ok()?))) {
            Some((a, b)) if a >= 1 && a <= b && b < 1000 => Some((a, b)),
            _ => {
                self.error(Self::attr_range(el, "locals"), format!("`locals` must be a range such as 1-33, not `{v}`"));
                None
            }
        }
    }

    /// `<statement keyword="WHILE" meaning="while"/>`: a statement keyword, letters or words
    /// of letters.
    fn statement_def(&mut self, c: &Element, m: &mut Macros) {
        self.shape(c, &["keyword", "meaning"], &[]);
        let (Some(k), Some(meaning)) = (self.required(c, "keyword"), self.required(c, "meaning")) else { return };
        let Some(meaning) = Statement::parse(meaning) else {
            self.error(Self::attr_range(c, "meaning"), format!("unknown statement meaning `{meaning}`"));
            return;
        };
        let k = k.to_ascii_uppercase();
        // Words of letters, joined by `_` within a word (LNC `END_IF`).
        let word = |w: &str| w.starts_with(|c: char| c.is_ascii_alphabetic()) && w.bytes().all(|b| b.is_ascii_alphanumeric() || b == b'_');
        // `@100`: an @ code of the older SINUMERIK controls, the mark and three digits.
        let at_code = k.len() == 4 && k.starts_with('@') && k[1..].bytes().all(|b| b.is_ascii_digit());
        if !at_code && k.split(' ').any(|w| !word(w)) {
            self.error(
                Self::attr_range(c, "keyword"),
                format!(
                    "statement keyword `{k}` must be letters (then letters, digits and `_`), or such words separated by single blanks, or `@` and three digits"
                ),
            );
        } else if m.statements.iter().any(|&(ref x, other)| {
            // One keyword may head a repeat-until loop and a section repeat: a
            // label after it tells them apart.
            let pair = [other, meaning];
            *x == k && !(pair.contains(&Statement::RepeatUntil) && pair.contains(&Statement::RepeatSection))
        }) {
            self.error(c.range, format!("statement `{k}` is declared twice"));
        } else {
            m.marked_keywords |= at_code;
            m.statements.push((k, meaning));
        }
    }

    /// `<arguments>A=1 B=2 C=3</arguments>`: the variable each macro-call argument letter sets.
    fn argument_letters(&mut self, c: &Element, m: &mut Macros) {
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

    /// `<system-variable name="$AC_TIME" meaning="..." value="0"/>`: a system variable by name.
    fn named_system_variable(&mut self, c: &Element, m: &mut Macros) {
        self.shape(c, &["name", "meaning", "value"], &[]);
        let (Some(name), Some(meaning)) = (self.attr(c, "name"), self.required(c, "meaning")) else { return };
        let name = super::super::vocab::normalise_name(name);
        let value = self.number(c, "value", 0.0);
        match SystemVar::parse(meaning) {
            Some(v) => m.system_named.push((name, v, value)),
            None => self.error(Self::attr_range(c, "meaning"), format!("unknown system variable meaning `{meaning}`")),
        }
    }

    /// `<tool-data name="$TC_DP3" form="tool-length"/>`: a system variable array the program
    /// writes a tool's offset data through (Siemens `$TC_DP3[t,d]=…`), and which of them.
    fn tool_data(&mut self, c: &Element, m: &mut Macros) {
        self.shape(c, &["name", "form"], &[]);
        let (Some(name), Some(form)) = (self.required(c, "name"), self.required(c, "form")) else { return };
        match crate::dialect::DataForm::parse(form) {
            Some(
                f @ (crate::dialect::DataForm::ToolLength
                | crate::dialect::DataForm::ToolLengthWear
                | crate::dialect::DataForm::ToolRadius
                | crate::dialect::DataForm::ToolRadiusWear),
            ) => m.tool_data.push((name.trim().to_ascii_uppercase(), f)),
            _ => self.error(Self::attr_range(c, "form"), format!("`{form}` is not a tool's length or radius")),
        }
    }

    /// `<tool-column group="50" nr="1" name="L" what="tool length" form="tool-length"/>`: a tool
    /// table's column the program reads and writes as system data by number, and, for a
    /// length or radius, which.
    fn tool_column(&mut self, c: &Element, m: &mut Macros) {
        self.shape(c, &["group", "nr", "name", "what", "form"], &[]);
        let (Some(id), Some(nr), Some(name), Some(what)) =
            (self.required(c, "group"), self.required(c, "nr"), self.required(c, "name"), self.required(c, "what"))
        else {
            return;
        };
        let (Ok(id), Ok(nr)) = (id.trim().parse::<u32>(), nr.trim().parse::<u32>()) else {
            self.error(Self::attr_range(c, "nr"), "`group` and `nr` must be numbers");
            return;
        };
        let form = match self.attr(c, "form").map(|f| (f, crate::dialect::DataForm::parse(f))) {
            None => None,
            Some((
                _,
                Some(
                    f @ (crate::dialect::DataForm::ToolLength
                    | crate::dialect::DataForm::ToolLengthWear
                    | crate::dialect::DataForm::ToolRadius
                    | crate::dialect::DataForm::ToolRadiusWear),
                ),
            )) => Some(f),
            Some((f, _)) => {
                self.error(Self::attr_range(c, "form"), format!("`{f}` is not a tool's length or radius"));
                return;
            }
        };
        let (name, what) = (name.trim().to_owned(), what.trim().to_owned());
        m.tool_columns.push(crate::dialect::ToolColumn { id, nr, name, what, form });
    }

    /// `<tool-table file="TOOL.T" group="50" open="TABOPEN" write="TABWRITE"/>`: the tool table
    /// as a table the program opens and writes by column name.
    fn tool_table(&mut self, c: &Element, m: &mut Macros) {
        self.shape(c, &["file", "group", "open", "write"], &[]);
        let (Some(file), Some(group), Some(open), Some(write)) =
            (self.required(c, "file"), self.required(c, "group"), self.required(c, "open"), self.required(c, "write"))
        else {
            return;
        };
        let Ok(group) = group.trim().parse::<u32>() else {
            self.error(Self::attr_range(c, "group"), "`group` must be a number");
            return;
        };
        let (file, open, write) = (file.trim().to_owned(), open.trim().to_ascii_uppercase(), write.trim().to_ascii_uppercase());
        m.tool_table = Some(crate::dialect::ToolTable { file, group, open, write });
    }

    /// `<system-variable number="5061" meaning="..."/>`: a system variable by number.
    fn numbered_system_variable(&mut self, c: &Element, m: &mut Macros) {
        self.shape(c, &["number", "meaning"], &[]);
        let (Some(n), Some(meaning)) = (self.required(c, "number"), self.required(c, "meaning")) else { return };
        let Ok(n) = n.parse::<u32>() else {
            self.error(Self::attr_range(c, "number"), format!("`{n}` is not a variable number"));
            return;
        };
        match SystemVar::parse(meaning) {
            Some(v) => m.system.push((n, v)),
            None => self.error(Self::attr_range(c, "meaning"), format!("unknown system variable meaning `{meaning}`")),
        }
    }
}

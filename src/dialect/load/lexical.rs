//! Loading `<lexical>`: how a dialect's text is cut into blocks and words (the block form,
//! comments, block skip and numbers, program delimiters, number notations, parameters,
//! statement marks, foreign formats). The door is `Cx::lexical`; each child element has a
//! reader of its own, called in document order.

use super::super::xml::Element;
use super::super::{AxisIndexed, BlockForm, CommentClose, CommentRule, Directive, Lexical, LogFile, NumberForms, SkipPosition};
use super::Cx;

/// The attributes `<lexical>` may carry.
const ATTRIBUTES: &[&str] = &[
    "block-form",
    "spaces-in-numbers",
    "bar-concatenation",
    "assign-values",
    "bare-function-arguments",
    "identifier-variables",
    "symbolic-comparisons",
    "paren-statements",
    "keyword-statements",
    "define-names",
    "text-arguments",
    "slash-arguments",
    "letter-variables",
    "paren-grouping",
];

/// The elements `<lexical>` may hold.
const CHILDREN: &[&str] = &[
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
    "global-parameters",
    "parameter-bank",
    "assignment-prefix",
    "block-end",
    "continuation",
    "program-number",
    "control-word",
    "foreign",
    "statement-prefix",
    "comment-directive",
];

impl Cx {
    /// `<lexical>`: its own attributes, then each child element in document order. Every
    /// dialect but a record-form one needs at least one comment rule.
    pub(super) fn lexical(&mut self, el: &Element) -> Lexical {
        self.shape(el, ATTRIBUTES, CHILDREN);
        let block_form = match self.attr(el, "block-form").unwrap_or("word-address") {
            "word-address" => BlockForm::WordAddress,
            "keyword-first" => BlockForm::KeywordFirst,
            "record" => BlockForm::Record,
            other => {
                self.error(Self::attr_range(el, "block-form"), format!("unknown block-form `{other}`"));
                BlockForm::WordAddress
            }
        };
        let mut lex = self.lexical_switches(el, block_form);
        for c in &el.children {
            self.lexical_child(c, &mut lex);
        }
        if lex.comments.is_empty() && lex.block_form != BlockForm::Record {
            self.error(el.range, "<lexical> needs at least one <comment> rule");
        }
        lex
    }

    /// The switches on `<lexical>` itself, with everything its child elements set at its
    /// default (none of them present).
    fn lexical_switches(&mut self, el: &Element, block_form: BlockForm) -> Lexical {
        Lexical {
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
            array_dimensions: 1,
            axis_indexed: Vec::new(),
            bare_function_arguments: self.bool(el, "bare-function-arguments", false),
            identifier_variables: self.bool(el, "identifier-variables", false),
            symbolic_comparisons: self.bool(el, "symbolic-comparisons", false),
            paren_statements: self.bool(el, "paren-statements", false),
            keyword_statements: self.bool(el, "keyword-statements", false),
            define_names: self.bool(el, "define-names", false),
            text_arguments: self.bool(el, "text-arguments", false),
            slash_arguments: self.bool(el, "slash-arguments", false),
            letter_variables: self.bool(el, "letter-variables", false),
            paren_grouping: self.bool(el, "paren-grouping", false),
            comments: Vec::new(),
            block_skip: None,
            block_number: None,
            program_delimiter: None,
            block_skip_levels: false,
            block_skip_first_level: 1,
            leader_skipped: false,
            delimiter_first_line: false,
            header_words: false,
            expression: None,
            expression_needs_assign: false,
            parameter: None,
            global_parameter: None,
            parameter_banks: Vec::new(),
            assignment_prefixes: Vec::new(),
            block_end: None,
            continuation: None,
            spaces_in_numbers: self.bool(el, "spaces-in-numbers", false),
            bar_concatenation: self.bool(el, "bar-concatenation", false),
            program_number: None,
            program_number_alt: None,
            control_word: None,
            foreign: Vec::new(),
            named_blocks: false,
            named_programs: false,
            statement_prefix: Vec::new(),
            directives: Vec::new(),
        }
    }

    /// One child element of `<lexical>` into `lex`, by its reader. An element `<lexical>` may
    /// not hold was reported by its shape check and is passed over.
    fn lexical_child(&mut self, c: &Element, lex: &mut Lexical) {
        match c.name.as_str() {
            "axis-modes" => self.axis_modes(c, lex),
            "label" => lex.label_suffix = self.only_char(c, "suffix"),
            "string" => lex.string_quote = self.only_char(c, "quote"),
            "numbers" => self.number_forms(c, lex),
            "system-variables" => lex.system_variable_prefix = self.only_char(c, "prefix"),
            "array" => self.array_brackets(c, lex),
            "axis-indexed" => self.axis_indexed(c, lex),
            "comment" => self.comment_rule(c, lex),
            "comment-directive" => self.comment_directive(c, lex),
            "block-skip" => self.block_skip(c, lex),
            "block-number" => self.block_number(c, lex),
            "program-delimiter" => self.program_delimiter(c, lex),
            "expression" => self.expression_brackets(c, lex),
            "parameter" => self.parameter_sigil(c, lex),
            "global-parameters" => self.global_parameters(c, lex),
            "parameter-bank" => self.parameter_bank(c, lex),
            "assignment-prefix" => {
                if let Some(k) = self.required(c, "keyword") {
                    lex.assignment_prefixes.push(k.to_ascii_uppercase());
                }
                self.shape(c, &["keyword"], &[]);
            }
            "block-end" => lex.block_end = self.only_char(c, "char"),
            "continuation" => lex.continuation = self.only_char(c, "char"),
            "program-number" => self.program_number(c, lex),
            "control-word" => lex.control_word = self.only_letter(c, "address"),
            "statement-prefix" => self.statement_prefix(c, lex),
            "foreign" => self.foreign_format(c, lex),
            _ => {}
        }
    }

    /// An element whose one attribute `name` is one character (`<label suffix=":"/>`).
    fn only_char(&mut self, c: &Element, name: &str) -> Option<char> {
        self.shape(c, &[name], &[]);
        self.char_attr(c, name)
    }

    /// An element whose one attribute `name` is one letter (`<control-word address="O"/>`).
    fn only_letter(&mut self, c: &Element, name: &str) -> Option<char> {
        self.shape(c, &[name], &[]);
        self.letter_attr(c, name)
    }

    /// `<axis-modes absolute="AC" incremental="IC" rotary-absolute="DC ACP ACN"/>`: the
    /// per-word measure wrappers (`X=AC(10)`).
    fn axis_modes(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["absolute", "incremental", "rotary-absolute"], &[]);
        if let (Some(a), Some(i)) = (self.required(c, "absolute"), self.required(c, "incremental")) {
            lex.axis_modes = Some((a.to_ascii_uppercase(), i.to_ascii_uppercase()));
        }
        if let Some(r) = self.attr(c, "rotary-absolute") {
            lex.rotary_absolute = r.split_whitespace().map(str::to_ascii_uppercase).collect();
        }
    }

    /// `<numbers exponent="EX" radix-quote="'" hex="H" binary="B" decimal-comma="true"/>`:
    /// number notations beyond plain decimals (`10EX3`, `'H1F'`, `+100,000`).
    fn number_forms(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["exponent", "radix-quote", "hex", "binary", "decimal-comma"], &[]);
        lex.numbers.exponent = self.attr(c, "exponent").map(str::to_ascii_uppercase);
        lex.numbers.decimal_comma = self.bool(c, "decimal-comma", false);
        if let Some(q) = self.char_attr(c, "radix-quote") {
            let hex = self.letter_attr(c, "hex").unwrap_or('H').to_ascii_uppercase();
            let binary = self.letter_attr(c, "binary").unwrap_or('B').to_ascii_uppercase();
            lex.numbers.radix = Some((q, hex, binary));
        }
    }

    /// `<array open="[" close="]"/>`: the brackets of an array element's index; both ASCII.
    fn array_brackets(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["open", "close", "dimensions"], &[]);
        if let (Some(o), Some(e)) = (self.char_attr(c, "open"), self.char_attr(c, "close"))
            && o.is_ascii()
            && e.is_ascii()
        {
            lex.array_brackets = Some((o as u8, e as u8));
        }
        if let Some(d) = self.attr(c, "dimensions") {
            match d.parse::<u8>() {
                Ok(n @ 1..=9) => lex.array_dimensions = n,
                _ => self.error(Self::attr_range(c, "dimensions"), format!("array dimensions `{d}` is not a number from 1 to 9")),
            }
        }
    }

    /// `<axis-indexed name="AX" meaning="axis-word"/>`: a name whose bracketed index is an axis
    /// (`AX[X]=10` moves, `VELOLIM[A]=50` is a setting).
    fn axis_indexed(&mut self, c: &Element, lex: &mut Lexical) {
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

    /// `<comment open="(" close=")" position="anywhere" nested="false"/>`: one comment rule;
    /// `close="eol"` runs to the line end.
    fn comment_rule(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["open", "close", "position", "nested", "nested-error"], &[]);
        let nested = self.bool(c, "nested", false);
        let nested_error = self.bool(c, "nested-error", false);
        let block_start = match self.attr(c, "position").unwrap_or("anywhere") {
            "anywhere" => false,
            "block-start" => true,
            other => {
                self.error(Self::attr_range(c, "position"), format!("unknown comment position `{other}`"));
                false
            }
        };
        // `//` (LNC): a two-character opener, for a comment to the end of the line.
        let (open, open2) = match self.attr(c, "open").map(|v| v.chars().collect::<Vec<char>>()) {
            Some(v) if v.len() == 2 && v.iter().all(char::is_ascii_punctuation) => (Some(v[0]), Some(v[1])),
            _ => (self.char_attr(c, "open"), None),
        };
        let close = match self.required(c, "close") {
            Some("eol") => Some(CommentClose::EndOfLine),
            // `*/` (LNC's `/* ... */`): a two-character close, after a two-character open.
            Some(v) if open2.is_some() && v.chars().count() == 2 && v.chars().all(|x| x.is_ascii_punctuation()) => {
                let mut x = v.chars();
                x.next().zip(x.next()).map(|(a, b)| CommentClose::Pair(a, b))
            }
            Some(_) if open2.is_some() => {
                self.error(Self::attr_range(c, "close"), "a two-character `open` needs `close=\"eol\"` or a two-character close");
                None
            }
            Some(_) => self.char_attr(c, "close").map(CommentClose::Char),
            None => None,
        };
        if open.is_none() {
            self.error(c.range, "<comment> needs a one- or two-character `open`");
        }
        if let (Some(open), Some(close)) = (open, close) {
            lex.comments.push(CommentRule { open, open2, close, block_start, nested, nested_error });
        }
    }

    /// `<comment-directive prefix="MSG," meaning="message"/>`: comment text that is a command
    /// to the control (a message, a log line, a teaching simulator's command).
    fn comment_directive(&mut self, c: &Element, lex: &mut Lexical) {
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

    /// `<block-skip char="/" position="line-start" levels="false"/>`: the block-skip mark,
    /// where it may stand, and whether a digit after it names a switch (`/2`).
    fn block_skip(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["char", "position", "levels", "first-level"], &[]);
        lex.block_skip_levels = self.bool(c, "levels", false);
        match self.attr(c, "first-level") {
            None | Some("1") => {}
            Some("0") => lex.block_skip_first_level = 0,
            Some(other) => self.error(Self::attr_range(c, "first-level"), format!("block-skip first-level `{other}` is neither 0 nor 1")),
        }
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

    /// `<block-number address="N" leading="false" names="false"/>`: the block-number address,
    /// bare leading numbers, and named blocks (`NLOOP`).
    fn block_number(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["address", "leading", "names"], &[]);
        lex.leading_block_number = self.bool(c, "leading", false);
        lex.named_blocks = self.bool(c, "names", false);
        if c.attrs.iter().any(|a| a.name == "address") {
            lex.block_number = self.letter_attr(c, "address");
        }
    }

    /// `<program-delimiter char="%" opening="anywhere" leader="read" header="skipped"/>`: the
    /// tape's program delimiter and how the text around it is read.
    fn program_delimiter(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["char", "opening", "leader", "header"], &[]);
        lex.program_delimiter = self.char_attr(c, "char");
        lex.leader_skipped = self.either(c, "leader", "read", "skipped");
        lex.delimiter_first_line = self.either(c, "opening", "anywhere", "first-line");
        lex.header_words = self.either(c, "header", "skipped", "words");
    }

    /// `<expression open="[" close="]"/>`: the brackets of an expression; `after-address=
    /// "assign"` where an address takes one only after `=` (`J=(R109*(-1))`).
    fn expression_brackets(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["open", "close", "after-address"], &[]);
        if let (Some(o), Some(cl)) = (self.char_attr(c, "open"), self.char_attr(c, "close")) {
            lex.expression = Some((o, cl));
        }
        lex.expression_needs_assign = self.either(c, "after-address", "direct", "assign");
    }

    /// `<parameter sigil="#" named="true"/>`: the parameter sigil, and whether `#<name>` names
    /// a parameter.
    fn parameter_sigil(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["sigil", "named"], &[]);
        let named = self.bool(c, "named", false);
        lex.parameter = self.char_attr(c, "sigil").map(|s| (s, named));
    }

    /// `<global-parameters sigil="@" first="100000"/>`: a second bank of numbered variables,
    /// `@n` kept as variable `first + n`.
    fn global_parameters(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["sigil", "first"], &[]);
        let first = self.required(c, "first").and_then(|v| v.parse::<u32>().ok());
        if first.is_none() {
            self.error(Self::attr_range(c, "first"), "`first` must be a whole number");
        }
        if let (Some(s), Some(f)) = (self.char_attr(c, "sigil"), first) {
            lex.global_parameter = Some((s, f));
        }
    }

    /// `<parameter-bank prefix="QL" first="10000"/>`: a bank of numbered variables named by
    /// the parameter sigil and letters, `QLn` kept as variable `first + n`.
    fn parameter_bank(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["prefix", "first"], &[]);
        let first = self.required(c, "first").and_then(|v| v.parse::<u32>().ok());
        if first.is_none() {
            self.error(Self::attr_range(c, "first"), "`first` must be a whole number");
        }
        let prefix = self.required(c, "prefix").map(str::to_ascii_uppercase);
        if prefix.as_ref().is_some_and(|p| p.len() < 2 || !p.bytes().all(|b| b.is_ascii_alphabetic())) {
            self.error(Self::attr_range(c, "prefix"), "`prefix` must be two or more letters");
            return;
        }
        if let (Some(p), Some(f)) = (prefix, first) {
            lex.parameter_banks.push((p, f));
        }
    }

    /// `<program-number address="O" alternate=":" names="false"/>`: the program-number
    /// address, its alternate mark, and named programs (`OTBOX`).
    fn program_number(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["address", "alternate", "names"], &[]);
        lex.program_number = self.letter_attr(c, "address");
        lex.named_programs = self.bool(c, "names", false);
        lex.program_number_alt = self.char_attr(c, "alternate");
    }

    /// `<statement-prefix chars="#$%"/>`: marks that say a statement follows (`#CALL L100`).
    fn statement_prefix(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["chars"], &[]);
        if let Some(chars) = self.required(c, "chars") {
            if chars.is_empty() || !chars.bytes().all(|b| b.is_ascii_punctuation()) {
                self.error(Self::attr_range(c, "chars"), "`chars` must be punctuation characters such as #$%");
            } else {
                lex.statement_prefix = chars.bytes().collect();
            }
        }
    }

    /// `<foreign regex="..." name="..."/>`: text of another format, told by a pattern.
    fn foreign_format(&mut self, c: &Element, lex: &mut Lexical) {
        self.shape(c, &["regex", "name"], &[]);
        let (Some(src), Some(name)) = (self.required(c, "regex"), self.required(c, "name")) else { return };
        match super::super::Pattern::new(src) {
            Ok(re) => lex.foreign.push((re, name.to_owned())),
            Err(e) => self.error(Self::attr_range(c, "regex"), format!("invalid regular expression: {e}")),
        }
    }
}

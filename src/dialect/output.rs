//! `<output>`: how to write a program for a control — block format, number formats, the
//! text each canonical event becomes (templates), cycle mapping and conditional rules.
//!
//! A template is text with `{value}` or `{value:FORMAT}` placeholders; `|` separates
//! blocks, whitespace separates words (a word whose placeholders all come out empty is
//! left out), `{value!}` writes a modal value even when it is unchanged, and a block that
//! starts with `^` gets no block number. The loader checks every placeholder, format name
//! and rule expression, with errors pointing at the attribute.

use super::xml::Element;
use crate::canon::CycleKind;
use crate::text::TextRange;

/// How a number is written for one address.
#[derive(Clone, Debug, PartialEq)]
pub struct NumberFormat {
    /// The format's name (`X`, `F`, `num`), which placeholders refer to.
    pub name: String,
    /// The text before the number (`X`, `CR=`, `` for a bare cycle argument).
    pub address: String,
    /// Decimals after the point.
    pub decimals: u8,
    /// Decimals after the point in an inch program (one more than in millimetres unless
    /// `inch-decimals` says).
    pub inch_decimals: u8,
    /// When the decimal point is written.
    pub point: Point,
    /// Whether trailing zeros are kept (`X10.500`).
    pub trailing_zeros: bool,
    /// Whether a zero before the point is kept (`X0.5`, else `X.5`).
    pub leading_zero: bool,
    /// Whether positive numbers get a `+` (Heidenhain `X+10`).
    pub plus: bool,
    /// Least-increment output: the number is written as a count of 10^-decimals steps.
    pub increment: bool,
    /// Whether the word is left out when its value is unchanged.
    pub modal: bool,
}

/// When a number's decimal point is written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Point {
    /// Always (`X10.`).
    Always,
    /// Only with decimals (`X10`, `X10.5`).
    Needed,
    /// Never: integers (`T1`, `S1500`).
    Never,
}

/// A value a placeholder stands for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Value {
    /// End point, X.
    X,
    /// End point, Y.
    Y,
    /// End point, Z.
    Z,
    /// Rotary axis A, degrees.
    A,
    /// Rotary axis B, degrees.
    B,
    /// Rotary axis C, degrees.
    C,
    /// Arc centre relative to the start, X.
    I,
    /// Arc centre relative to the start, Y.
    J,
    /// Arc centre relative to the start, Z.
    K,
    /// Arc centre, absolute X.
    Cx,
    /// Arc centre, absolute Y.
    Cy,
    /// Arc centre, absolute Z.
    Cz,
    /// Arc radius, negative beyond 180°.
    R,
    /// Feed.
    F,
    /// Spindle speed.
    S,
    /// Tool number.
    T,
    /// Tool name where one was given, else its number.
    Tname,
    /// Length offset number.
    H,
    /// Radius offset number.
    D,
    /// Dwell, seconds.
    Seconds,
    /// Dwell, milliseconds.
    Millis,
    /// Work offset index (1 = the first, G54); in `work-offset-extended`, the additional
    /// offset's own number (`G54.1 P{wcs}`).
    Wcs,
    /// Work offset G number (54 … 59).
    WcsCode,
    /// Program number.
    Number,
    /// Program name.
    Name,
    /// The unit's name (`MM`, `INCH`).
    UnitName,
    /// Comment or message text.
    Text,
    /// Words put off to the next move (`G43 H1`, `RL`).
    Mods,
    /// Cycle: bottom of the hole.
    Bottom,
    /// Cycle: R plane.
    RPlane,
    /// Cycle: the height returned to.
    Clear,
    /// Cycle: the workpiece surface (the R plane when the cycle states none).
    Surface,
    /// Cycle: R plane above the surface.
    Sdis,
    /// Cycle: bottom below the surface (negative).
    Depth,
    /// Cycle: the height returned to above the surface.
    ClearDist,
    /// Cycle: peck depth (the whole depth when the cycle has none).
    Peck,
    /// Cycle: dwell at the bottom, seconds (0 when none).
    CycleDwell,
    /// Cycle: 98 when the tool returns above the R plane, else 99.
    Retract,
    /// Cycle: how far above the last peck the tool comes back down at rapid.
    PeckClearance,
    /// Thread or rigid tap: the advance per spindle revolution.
    Pitch,
    /// Constant surface speed: the highest spindle speed (absent when none was set).
    SpindleMax,
    /// Spindle orientation: the angle, degrees.
    Angle,
    /// Spindle orientation: 0 the shorter way, 1 clockwise, 2 counterclockwise.
    OrientDir,
    /// A repeated block run: how many times it runs.
    Count,
    /// A repeated block run: its number in the program (1, 2, …).
    Loop,
    /// A repeated block run: how many times it runs again after the first (`CALL LBL 1 REP
    /// {again}`, `REPEAT LOOP1 P={again}`).
    Again,
    /// A repeated block run written as a subprogram: the subprogram's number (`O{sub}`,
    /// `M98 P{sub}`), above the main program's and 1000.
    Sub,
}

const VALUES: &[(&str, Value)] = &[
    ("x", Value::X),
    ("y", Value::Y),
    ("z", Value::Z),
    ("a", Value::A),
    ("b", Value::B),
    ("c", Value::C),
    ("i", Value::I),
    ("j", Value::J),
    ("k", Value::K),
    ("cx", Value::Cx),
    ("cy", Value::Cy),
    ("cz", Value::Cz),
    ("r", Value::R),
    ("f", Value::F),
    ("s", Value::S),
    ("t", Value::T),
    ("tname", Value::Tname),
    ("h", Value::H),
    ("d", Value::D),
    ("seconds", Value::Seconds),
    ("millis", Value::Millis),
    ("wcs", Value::Wcs),
    ("wcs-code", Value::WcsCode),
    ("number", Value::Number),
    ("name", Value::Name),
    ("units", Value::UnitName),
    ("text", Value::Text),
    ("mods", Value::Mods),
    ("bottom", Value::Bottom),
    ("r-plane", Value::RPlane),
    ("clear", Value::Clear),
    ("surface", Value::Surface),
    ("sdis", Value::Sdis),
    ("depth", Value::Depth),
    ("clear-dist", Value::ClearDist),
    ("peck", Value::Peck),
    ("dwell", Value::CycleDwell),
    ("retract", Value::Retract),
    ("peck-clearance", Value::PeckClearance),
    ("pitch", Value::Pitch),
    ("smax", Value::SpindleMax),
    ("angle", Value::Angle),
    ("orient-dir", Value::OrientDir),
    ("count", Value::Count),
    ("loop", Value::Loop),
    ("again", Value::Again),
    ("sub", Value::Sub),
];

impl Value {
    /// The format a placeholder without `:FORMAT` uses.
    fn default_format(self) -> &'static str {
        match self {
            Value::X | Value::Cx => "X",
            Value::Y | Value::Cy => "Y",
            Value::Z | Value::Cz | Value::Bottom => "Z",
            Value::A => "A",
            Value::B => "B",
            Value::C => "C",
            Value::I => "I",
            Value::J => "J",
            Value::K => "K",
            Value::R | Value::RPlane => "R",
            Value::F => "F",
            Value::S => "S",
            Value::T => "T",
            Value::H => "H",
            Value::D => "D",
            Value::Seconds | Value::Millis => "P",
            _ => "num",
        }
    }

    /// Whether the value is text rather than a number.
    pub fn is_text(self) -> bool {
        matches!(self, Value::Tname | Value::Name | Value::UnitName | Value::Text | Value::Mods)
    }
}

/// One piece of a word.
#[derive(Clone, Debug, PartialEq)]
pub enum Piece {
    /// Literal text.
    Lit(String),
    /// A value in a format (an index into [`Output::formats`]; text values have none).
    Var {
        /// Which value.
        value: Value,
        /// Its number format.
        format: Option<usize>,
        /// Written even when unchanged (`{x!}`).
        force: bool,
    },
}

/// A word of a block: pieces written together.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Word(pub Vec<Piece>);

/// A block of a template.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Block {
    /// Written without block number (`^`).
    pub raw: bool,
    /// Its words.
    pub words: Vec<Word>,
}

/// A template: blocks of words.
#[derive(Clone, Debug, PartialEq, Default)]
pub struct Template(pub Vec<Block>);

impl Template {
    /// Whether any placeholder is `value`.
    pub fn uses(&self, value: Value) -> bool {
        self.0.iter().flat_map(|b| &b.words).flat_map(|w| &w.0).any(|p| matches!(p, Piece::Var { value: v, .. } if *v == value))
    }
}

/// The events a template can be given for.
pub const EVENTS: &[&str] = &[
    "header",
    "footer",
    "safe-start",
    "rapid",
    "feed",
    "arc-cw",
    "arc-ccw",
    "tool-change",
    "tool-select",
    "length-offset",
    "length-offset-off",
    "comp-left",
    "comp-right",
    "comp-off",
    "spindle-cw",
    "spindle-ccw",
    "spindle-stop",
    "speed",
    "flood-on",
    "mist-on",
    "coolant-off",
    "stop",
    "optional-stop",
    "end",
    "dwell",
    "plane-xy",
    "plane-xz",
    "plane-yz",
    "units-mm",
    "units-inch",
    "work-offset",
    "work-offset-1",
    "work-offset-2",
    "work-offset-3",
    "work-offset-4",
    "work-offset-5",
    "work-offset-6",
    "work-offset-7",
    "work-offset-8",
    "work-offset-9",
    "work-offset-extended",
    "thread",
    "rigid-tap",
    "css-on",
    "css-off",
    "spindle-orient",
    "repeat-begin",
    "repeat-end",
    "repeat-call",
    "sub-begin",
    "sub-end",
    "feed-per-minute",
    "feed-per-rev",
    "comment",
    "message",
];

/// A cycle the target writes as a cycle.
#[derive(Clone, Debug, PartialEq)]
pub struct CycleOut {
    /// The intents it writes.
    pub kinds: Vec<CycleKind>,
    /// Defines the cycle (with the first hole, when `inline`).
    pub define: Template,
    /// Each further hole (each hole, when not `inline`).
    pub at: Template,
    /// Ends the cycle.
    pub cancel: Template,
    /// Whether `define` also drills the first hole (Fanuc `G81 X Y Z R F`).
    pub inline: bool,
}

/// A rule's condition: a small expression over the event and the machine state.
#[derive(Clone, Debug, PartialEq)]
pub enum Expr {
    /// The event of this name happens.
    Event(String),
    /// A comparison of a state value with a number.
    Compare(StateVar, Cmp, f64),
    /// Both.
    And(Box<Expr>, Box<Expr>),
    /// Either.
    Or(Box<Expr>, Box<Expr>),
    /// Not.
    Not(Box<Expr>),
}

/// A state value a rule may compare.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StateVar {
    /// The tool in the spindle.
    Tool,
    /// The spindle speed.
    Speed,
    /// The feed.
    Feed,
    /// The block number about to be written.
    Block,
}

/// A comparison operator.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Cmp {
    /// `==`
    Eq,
    /// `!=`
    Ne,
    /// `<`
    Lt,
    /// `<=`
    Le,
    /// `>`
    Gt,
    /// `>=`
    Ge,
}

/// A conditional rule: when the condition holds at an event, blocks go before or after it.
#[derive(Clone, Debug, PartialEq)]
pub struct Rule {
    /// Its name.
    pub name: String,
    /// Its condition.
    pub when: Expr,
    /// Written before the event's own text.
    pub before: Template,
    /// Written after it.
    pub after: Template,
}

/// Which blocks get a number.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Numbered {
    /// None.
    None,
    /// Every block.
    All,
    /// Tool-change blocks only.
    ToolChange,
}

/// A dialect's output rules.
#[derive(Clone, Debug, PartialEq)]
pub struct Output {
    /// Between the words of a block.
    pub separator: String,
    /// After each block.
    pub end_of_block: String,
    /// The longest line the control takes (0: no limit).
    pub max_line: usize,
    /// The block-number address (empty for Heidenhain's bare numbers).
    pub number_address: String,
    /// The first block number.
    pub number_start: u64,
    /// The step between block numbers.
    pub number_step: u64,
    /// Which blocks get a number.
    pub numbered: Numbered,
    /// Comment opening text.
    pub comment_open: String,
    /// Comment closing text (empty: to the end of the line).
    pub comment_close: String,
    /// Characters a comment may not contain (replaced by a space).
    pub comment_forbidden: String,
    /// Whether comments are written in upper case.
    pub comment_upper: bool,
    /// Whether a motion block's first word (its G code) is left out when unchanged.
    pub modal_motion: bool,
    /// Number formats.
    pub formats: Vec<NumberFormat>,
    /// Templates by event.
    pub templates: Vec<(String, Template, bool)>,
    /// Cycles the target writes as cycles.
    pub cycles: Vec<CycleOut>,
    /// Conditional rules.
    pub rules: Vec<Rule>,
    /// The values a format's address takes (`<format min max>`: Haas `G154 P1`–`P99`), by
    /// format index: a template that would write another value is not written.
    pub bounds: Vec<Bound>,
}

/// The values one number format takes, both ends included.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Bound {
    /// The format (an index into [`Output::formats`]).
    pub format: usize,
    /// The least value.
    pub min: f64,
    /// The greatest value.
    pub max: f64,
}

impl Output {
    /// The template for `event`, and whether it waits for the next move (`into="next-move"`).
    pub fn template(&self, event: &str) -> Option<(&Template, bool)> {
        self.templates.iter().find(|(e, _, _)| e == event).map(|(_, t, m)| (t, *m))
    }

    /// The cycle mapping for `kind`.
    pub fn cycle(&self, kind: CycleKind) -> Option<&CycleOut> {
        self.cycles.iter().find(|c| c.kinds.contains(&kind))
    }

    /// Whether every number `t` would write (`value` gives it; NaN: absent) is one its
    /// format's address takes ([`Output::bounds`]).
    pub fn fits(&self, t: &Template, value: impl Fn(Value) -> f64) -> bool {
        if self.bounds.is_empty() {
            return true;
        }
        t.0.iter().flat_map(|b| &b.words).flat_map(|w| &w.0).all(|p| match p {
            Piece::Var { value: v, format: Some(fi), .. } => {
                let x = value(*v);
                x.is_nan() || self.bounds.iter().filter(|b| b.format == *fi).all(|b| x >= b.min && x <= b.max)
            }
            _ => true,
        })
    }
}

const CYCLE_KINDS: &[(&str, CycleKind)] = &[
    ("drilling", CycleKind::Drilling),
    ("counterboring", CycleKind::CounterBoring),
    ("peck-drilling", CycleKind::PeckDrilling),
    ("chip-breaking", CycleKind::ChipBreaking),
    ("boring", CycleKind::Boring),
    ("boring-dwell", CycleKind::BoringDwell),
    ("boring-spindle-stop", CycleKind::BoringSpindleStop),
    ("tapping", CycleKind::Tapping),
    ("left-tapping", CycleKind::LeftTapping),
    ("fine-boring", CycleKind::FineBoring),
    ("back-boring", CycleKind::BackBoring),
    ("boring-manual", CycleKind::BoringManual),
];

type Errors = Vec<(TextRange, String)>;

fn attr<'a>(el: &'a Element, name: &str) -> Option<&'a str> {
    el.attrs.iter().find(|a| a.name == name).map(|a| a.value.as_str())
}

fn range(el: &Element, name: &str) -> TextRange {
    el.attrs.iter().find(|a| a.name == name).map_or(el.range, |a| a.range)
}

fn shape(el: &Element, allowed: &[&str], errors: &mut Errors) {
    for a in &el.attrs {
        if !allowed.contains(&a.name.as_str()) {
            errors.push((a.range, format!("<{}> has no attribute `{}`", el.name, a.name)));
        }
    }
}

fn flag(el: &Element, name: &str, default: bool, errors: &mut Errors) -> bool {
    match attr(el, name) {
        None => default,
        Some("true") => true,
        Some("false") => false,
        Some(v) => {
            errors.push((range(el, name), format!("`{name}` must be true or false, not `{v}`")));
            default
        }
    }
}

fn count(el: &Element, name: &str, default: u64, errors: &mut Errors) -> u64 {
    match attr(el, name) {
        None => default,
        Some(v) => v.parse().unwrap_or_else(|_| {
            errors.push((range(el, name), format!("`{name}` must be a whole number, not `{v}`")));
            default
        }),
    }
}

/// Validates an `<output>` element.
pub(super) fn load(el: &Element, errors: &mut Errors) -> Output {
    shape(el, &["modal-motion"], errors);
    let mut out = Output {
        separator: " ".into(),
        end_of_block: String::new(),
        max_line: 0,
        number_address: "N".into(),
        number_start: 10,
        number_step: 10,
        numbered: Numbered::None,
        comment_open: "(".into(),
        comment_close: ")".into(),
        comment_forbidden: "()".into(),
        comment_upper: false,
        modal_motion: flag(el, "modal-motion", true, errors),
        formats: Vec::new(),
        templates: Vec::new(),
        cycles: Vec::new(),
        rules: Vec::new(),
        bounds: Vec::new(),
    };
    // Formats first: templates refer to them.
    for c in el.children.iter().filter(|c| c.name == "format") {
        shape(
            c,
            &[
                "name",
                "address",
                "decimals",
                "point",
                "trailing-zeros",
                "leading-zero",
                "plus",
                "increment",
                "modal",
                "inch-decimals",
                "min",
                "max",
            ],
            errors,
        );
        let Some(name) = attr(c, "name") else {
            errors.push((c.range, "<format> needs the attribute `name`".into()));
            continue;
        };
        let point = match attr(c, "point").unwrap_or("needed") {
            "always" => Point::Always,
            "needed" => Point::Needed,
            "never" => Point::Never,
            v => {
                errors.push((range(c, "point"), format!("`point` is always, needed or never, not `{v}`")));
                Point::Needed
            }
        };
        let decimals = count(c, "decimals", if point == Point::Never { 0 } else { 3 }, errors);
        let end = |which: &str, default: f64, errors: &mut Errors| match attr(c, which) {
            None => default,
            Some(v) => v.parse::<f64>().ok().filter(|x| x.is_finite()).unwrap_or_else(|| {
                errors.push((range(c, which), format!("`{which}` must be a number, not `{v}`")));
                default
            }),
        };
        if attr(c, "min").is_some() || attr(c, "max").is_some() {
            let (min, max) = (end("min", f64::NEG_INFINITY, errors), end("max", f64::INFINITY, errors));
            if min > max {
                errors.push((range(c, "max"), format!("`max` ({max}) is below `min` ({min})")));
            }
            out.bounds.push(Bound { format: out.formats.len(), min, max });
        }
        if decimals > 6 {
            errors.push((range(c, "decimals"), "`decimals` is at most 6".into()));
        }
        out.formats.push(NumberFormat {
            name: name.to_owned(),
            address: attr(c, "address").unwrap_or(name).to_owned(),
            decimals: decimals.min(6) as u8,
            inch_decimals: count(c, "inch-decimals", if point == Point::Never { 0 } else { (decimals + 1).min(6) }, errors).min(6) as u8,
            point,
            trailing_zeros: flag(c, "trailing-zeros", false, errors),
            leading_zero: flag(c, "leading-zero", true, errors),
            plus: flag(c, "plus", false, errors),
            increment: flag(c, "increment", false, errors),
            modal: flag(c, "modal", false, errors),
        });
    }
    if !out.formats.iter().any(|f| f.name == "num") {
        out.formats.push(NumberFormat {
            name: "num".into(),
            address: String::new(),
            decimals: 3,
            inch_decimals: 4,
            point: Point::Needed,
            trailing_zeros: false,
            leading_zero: true,
            plus: false,
            increment: false,
            modal: false,
        });
    }
    for c in &el.children {
        match c.name.as_str() {
            "format" => {}
            "block" => {
                shape(c, &["separator", "end", "max-length"], errors);
                if let Some(s) = attr(c, "separator") {
                    out.separator = s.to_owned();
                }
                out.end_of_block = attr(c, "end").unwrap_or("").to_owned();
                out.max_line = count(c, "max-length", 0, errors) as usize;
            }
            "block-numbers" => {
                shape(c, &["address", "start", "step", "which"], errors);
                out.number_address = attr(c, "address").unwrap_or("N").to_owned();
                out.number_start = count(c, "start", 10, errors);
                out.number_step = count(c, "step", 10, errors);
                out.numbered = match attr(c, "which").unwrap_or("all") {
                    "all" => Numbered::All,
                    "none" => Numbered::None,
                    "tool-change" => Numbered::ToolChange,
                    v => {
                        errors.push((range(c, "which"), format!("`which` is all, none or tool-change, not `{v}`")));
                        Numbered::None
                    }
                };
            }
            "comment" => {
                shape(c, &["open", "close", "forbidden", "upper"], errors);
                out.comment_open = attr(c, "open").unwrap_or("(").to_owned();
                out.comment_close = attr(c, "close").unwrap_or("").to_owned();
                out.comment_forbidden = attr(c, "forbidden").map_or_else(|| out.comment_open.clone() + &out.comment_close, str::to_owned);
                out.comment_upper = flag(c, "upper", false, errors);
            }
            "emit" => {
                shape(c, &["name", "text", "into"], errors);
                let Some(name) = attr(c, "name") else {
                    errors.push((c.range, "<emit> needs the attribute `name`".into()));
                    continue;
                };
                if !EVENTS.contains(&name) {
                    errors.push((range(c, "name"), format!("`{name}` is not an output event (one of {})", EVENTS.join(", "))));
                    continue;
                }
                let text = attr(c, "text").unwrap_or("");
                let t = template(text, range(c, "text"), &out.formats, errors);
                let into = match attr(c, "into") {
                    None => false,
                    Some("next-move") => true,
                    Some(v) => {
                        errors.push((range(c, "into"), format!("`into` can only be next-move, not `{v}`")));
                        false
                    }
                };
                out.templates.push((name.to_owned(), t, into));
            }
            "cycle" => {
                shape(c, &["name", "kinds", "define", "at", "cancel", "inline"], errors);
                let mut kinds = Vec::new();
                let names = attr(c, "kinds").or(attr(c, "name")).unwrap_or("");
                for k in names.split_ascii_whitespace() {
                    match CYCLE_KINDS.iter().find(|(n, _)| *n == k) {
                        Some((_, kind)) => kinds.push(*kind),
                        None => errors.push((
                            range(c, if attr(c, "kinds").is_some() { "kinds" } else { "name" }),
                            format!(
                                "`{k}` is not a cycle kind (one of {})",
                                CYCLE_KINDS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")
                            ),
                        )),
                    }
                }
                let define = template(attr(c, "define").unwrap_or(""), range(c, "define"), &out.formats, errors);
                let at = template(attr(c, "at").unwrap_or(""), range(c, "at"), &out.formats, errors);
                let cancel = template(attr(c, "cancel").unwrap_or(""), range(c, "cancel"), &out.formats, errors);
                let inline = flag(c, "inline", false, errors);
                out.cycles.push(CycleOut { kinds, define, at, cancel, inline });
            }
            "rule" => {
                shape(c, &["name", "when", "before", "after"], errors);
                let name = attr(c, "name").unwrap_or("").to_owned();
                let when = match attr(c, "when") {
                    Some(w) => match parse_expr(w) {
                        Ok(e) => e,
                        Err(msg) => {
                            errors.push((range(c, "when"), format!("`when`: {msg}")));
                            continue;
                        }
                    },
                    None => {
                        errors.push((c.range, "<rule> needs the attribute `when`".into()));
                        continue;
                    }
                };
                let before = template(attr(c, "before").unwrap_or(""), range(c, "before"), &out.formats, errors);
                let after = template(attr(c, "after").unwrap_or(""), range(c, "after"), &out.formats, errors);
                out.rules.push(Rule { name, when, before, after });
            }
            "remove" => {}
            other => errors.push((c.range, format!("<output> may not contain <{other}>"))),
        }
    }
    out
}

/// Parses a template, checking every placeholder.
fn template(text: &str, at: TextRange, formats: &[NumberFormat], errors: &mut Errors) -> Template {
    let mut blocks = Vec::new();
    for b in text.split('|') {
        let b = b.trim();
        if b.is_empty() {
            continue;
        }
        let (raw, b) = match b.strip_prefix('^') {
            Some(rest) => (true, rest.trim_start()),
            None => (false, b),
        };
        let mut words = Vec::new();
        for w in b.split_ascii_whitespace() {
            let mut pieces = Vec::new();
            let mut rest = w;
            while let Some(open) = rest.find('{') {
                if open > 0 {
                    pieces.push(Piece::Lit(rest[..open].to_owned()));
                }
                let Some(close) = rest[open..].find('}') else {
                    errors.push((at, format!("`{w}`: a `{{` without its `}}`")));
                    rest = "";
                    break;
                };
                let inner = &rest[open + 1..open + close];
                rest = &rest[open + close + 1..];
                let (inner, force) = match inner.strip_suffix('!') {
                    Some(i) => (i, true),
                    None => (inner, false),
                };
                let (vname, fname) = match inner.split_once(':') {
                    Some((v, f)) => (v, Some(f)),
                    None => (inner, None),
                };
                let Some(&(_, value)) = VALUES.iter().find(|(n, _)| *n == vname) else {
                    errors.push((
                        at,
                        format!("`{{{inner}}}` names no value (one of {})", VALUES.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")),
                    ));
                    continue;
                };
                let format = if value.is_text() {
                    None
                } else {
                    let fname = fname.unwrap_or(value.default_format());
                    let f = formats.iter().position(|f| f.name == fname);
                    if f.is_none() {
                        errors.push((at, format!("`{{{inner}}}` uses the format `{fname}`, which no <format> defines")));
                    }
                    f
                };
                pieces.push(Piece::Var { value, format, force });
            }
            if !rest.is_empty() {
                pieces.push(Piece::Lit(rest.to_owned()));
            }
            words.push(Word(pieces));
        }
        blocks.push(Block { raw, words });
    }
    Template(blocks)
}

/// Parses a rule's condition: events and comparisons (`tool > 10`) joined by `and`, `or`,
/// `not` and parentheses.
pub fn parse_expr(text: &str) -> Result<Expr, String> {
    let tokens = tokenize(text)?;
    let mut pos = 0;
    let e = or(&tokens, &mut pos)?;
    if pos != tokens.len() {
        return Err(format!("unexpected `{}`", tokens[pos]));
    }
    Ok(e)
}

fn tokenize(text: &str) -> Result<Vec<String>, String> {
    let mut out = Vec::new();
    let b = text.as_bytes();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() {
            i += 1;
        } else if c == b'(' || c == b')' {
            out.push((c as char).to_string());
            i += 1;
        } else if b"<>=!".contains(&c) {
            let two = i + 1 < b.len() && b[i + 1] == b'=';
            let len = if two { 2 } else { 1 };
            out.push(text[i..i + len].to_owned());
            i += len;
        } else if c.is_ascii_alphanumeric() || c == b'-' || c == b'.' {
            let start = i;
            while i < b.len() && (b[i].is_ascii_alphanumeric() || b[i] == b'-' || b[i] == b'.' || b[i] == b'_') {
                i += 1;
            }
            out.push(text[start..i].to_owned());
        } else {
            return Err(format!("unexpected character `{}`", c as char));
        }
    }
    Ok(out)
}

fn or(t: &[String], pos: &mut usize) -> Result<Expr, String> {
    let mut e = and(t, pos)?;
    while t.get(*pos).is_some_and(|s| s == "or") {
        *pos += 1;
        e = Expr::Or(Box::new(e), Box::new(and(t, pos)?));
    }
    Ok(e)
}

fn and(t: &[String], pos: &mut usize) -> Result<Expr, String> {
    let mut e = unary(t, pos)?;
    while t.get(*pos).is_some_and(|s| s == "and") {
        *pos += 1;
        e = Expr::And(Box::new(e), Box::new(unary(t, pos)?));
    }
    Ok(e)
}

fn unary(t: &[String], pos: &mut usize) -> Result<Expr, String> {
    let Some(tok) = t.get(*pos) else { return Err("the condition ends too early".into()) };
    *pos += 1;
    match tok.as_str() {
        "not" => Ok(Expr::Not(Box::new(unary(t, pos)?))),
        "(" => {
            let e = or(t, pos)?;
            if t.get(*pos).is_none_or(|s| s != ")") {
                return Err("a `(` without its `)`".into());
            }
            *pos += 1;
            Ok(e)
        }
        name => {
            let var = match name {
                "tool" => Some(StateVar::Tool),
                "speed" => Some(StateVar::Speed),
                "feed" => Some(StateVar::Feed),
                "block" => Some(StateVar::Block),
                _ => None,
            };
            if let Some(var) = var {
                let op = match t.get(*pos).map(String::as_str) {
                    Some("==") => Cmp::Eq,
                    Some("!=") => Cmp::Ne,
                    Some("<") => Cmp::Lt,
                    Some("<=") => Cmp::Le,
                    Some(">") => Cmp::Gt,
                    Some(">=") => Cmp::Ge,
                    _ => return Err(format!("`{name}` must be compared (`{name} > 10`)")),
                };
                *pos += 1;
                let n =
                    t.get(*pos).and_then(|s| s.parse::<f64>().ok()).ok_or_else(|| format!("`{name}` must be compared with a number"))?;
                *pos += 1;
                Ok(Expr::Compare(var, op, n))
            } else if EVENTS.contains(&name) {
                Ok(Expr::Event(name.to_owned()))
            } else {
                Err(format!("`{name}` is neither an event ({}) nor tool, speed, feed or block", EVENTS.join(", ")))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn expressions_parse_and_bad_ones_say_why() {
        assert_eq!(
            parse_expr("coolant-off and not (tool <= 2)").unwrap(),
            Expr::And(
                Box::new(Expr::Event("coolant-off".into())),
                Box::new(Expr::Not(Box::new(Expr::Compare(StateVar::Tool, Cmp::Le, 2.0))))
            )
        );
        assert!(parse_expr("coolant-of").unwrap_err().contains("neither an event"));
        assert!(parse_expr("tool 3").unwrap_err().contains("must be compared"));
        assert!(parse_expr("(end").unwrap_err().contains("without its"));
    }

    #[test]
    fn templates_check_their_placeholders() {
        let f = vec![NumberFormat {
            name: "X".into(),
            address: "X".into(),
            decimals: 3,
            inch_decimals: 4,
            point: Point::Always,
            trailing_zeros: false,
            leading_zero: true,
            plus: false,
            increment: false,
            modal: true,
        }];
        let mut errors = Vec::new();
        let t = template("G0 {x!}|^%", TextRange::default(), &f, &mut errors);
        assert!(errors.is_empty());
        assert_eq!(t.0.len(), 2);
        assert!(t.0[1].raw);
        assert_eq!(t.0[0].words[1].0, vec![Piece::Var { value: Value::X, format: Some(0), force: true }]);
        template("G0 {q} {y}", TextRange::default(), &f, &mut errors);
        assert_eq!(errors.len(), 2, "{errors:?}");
        assert!(errors[0].1.contains("names no value"));
        assert!(errors[1].1.contains("no <format> defines"));
    }

    #[test]
    fn a_range_is_checked_where_the_dictionary_states_it() {
        let text = r#"<output><format name="P" point="never" min="5" max="x"/><format name="Q" min="3" max="2"/></output>"#;
        let tree = crate::dialect::xml::parse(text).unwrap();
        let mut errors = Vec::new();
        let out = load(&tree, &mut errors);
        let messages: Vec<&str> = errors.iter().map(|e| e.1.as_str()).collect();
        assert_eq!(messages, ["`max` must be a number, not `x`", "`max` (2) is below `min` (3)"]);
        assert_eq!(out.bounds[0], Bound { format: 0, min: 5.0, max: f64::INFINITY });
    }
}

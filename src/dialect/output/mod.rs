//! `<output>`: how to write a program for a control — block format, number formats, the
//! text each canonical event becomes (templates), cycle mapping and conditional rules.
//!
//! A template is text with `{value}` or `{value:FORMAT}` placeholders; `|` separates
//! blocks, whitespace separates words (a word whose placeholders all come out empty is
//! left out), `{value!}` writes a modal value even when it is unchanged, and a block that
//! starts with `^` gets no block number. The loader checks every placeholder, format name
//! and rule expression, with errors pointing at the attribute.
//!
//! The types here say what the rules are; `read.rs` reads them from the dictionary
//! (`load`, [`parse_expr`]).

use crate::canon::CycleKind;

mod read;
pub(super) use read::load;
pub use read::parse_expr;

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
    /// The fewest digits before the point, zero-padded (`digits="2"`: a lathe's `T0101`, its
    /// tool and offset numbers two digits each); 0: as many as the number has.
    pub digits: u8,
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
    /// A tilted working plane (`work-plane`): its origin's X, in the untilted program
    /// coordinates.
    PlaneX,
    /// The same, Y.
    PlaneY,
    /// The same, Z.
    PlaneZ,
    /// A tilted working plane's rotation as spatial angles, degrees: about the fixed X …
    SpatialA,
    /// … then the fixed Y …
    SpatialB,
    /// … then the fixed Z (Heidenhain `PLANE SPATIAL SPA SPB SPC`).
    SpatialC,
    /// The rotation as Euler angles, degrees: about Z …
    EulerA,
    /// … then the turned X …
    EulerB,
    /// … then the turned Z (Fanuc `G68.2 I J K`).
    EulerC,
    /// The rotation axis by axis, degrees: about X …
    TurnA,
    /// … then the turned Y …
    TurnB,
    /// … then the turned Z (Siemens `CYCLE800` mode 57).
    TurnC,
    /// A move in the machine's frame (`home-1`, `home-2`, `machine-rapid`): the machine
    /// coordinate of X (in a reference return, 0 for each axis that returns).
    MachineX,
    /// The same, Y.
    MachineY,
    /// The same, Z.
    MachineZ,
    /// The same, A (degrees).
    MachineA,
    /// The same, B (degrees).
    MachineB,
    /// The same, C (degrees).
    MachineC,
}

/// The machine-frame values by axis, X Y Z A B C.
pub const MACHINE_AXES: [Value; 6] = [Value::MachineX, Value::MachineY, Value::MachineZ, Value::MachineA, Value::MachineB, Value::MachineC];

impl Value {
    /// The format a placeholder without `:FORMAT` uses.
    fn default_format(self) -> &'static str {
        match self {
            Value::X | Value::Cx | Value::MachineX | Value::PlaneX => "X",
            Value::Y | Value::Cy | Value::MachineY | Value::PlaneY => "Y",
            Value::Z | Value::Cz | Value::Bottom | Value::MachineZ | Value::PlaneZ => "Z",
            Value::A | Value::MachineA => "A",
            Value::B | Value::MachineB => "B",
            Value::C | Value::MachineC => "C",
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
    "work-offset-0",
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
    "home-1",
    "home-2",
    "machine-rapid",
    "machine-builder-rapid",
    "travel-limit",
    "thread",
    "rigid-tap",
    "css-on",
    "css-off",
    "css-on-per-minute",
    "css-off-per-minute",
    "spindle-orient",
    "diameter-on",
    "diameter-off",
    "work-plane",
    "work-plane-reset",
    "tcp-on",
    "tcp-off",
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
    /// Why a translation to this control is refused (`refused="..."`): the rules are another
    /// dialect's, inherited, and their syntax is not one its control runs.
    pub refused: Option<String>,
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

//! Diagnostics: findings about inputs (programs, dialect files, configs) as plain data.
//!
//! A diagnostic is a value, never an `Err`: analysis reports every finding and keeps going.
//! Rendering (short, human with carets, JSON) happens at the edge via [`render_short`],
//! [`render_human`] and [`DiagnosticJson`].
//!
//! `Diagnostic` as data; the `Code` catalogue (`syntax::…`, `interp::…`, `flow::…`,
//! `plan::…`, `dialect::…`) with a doc line per code; short, human (carets) and JSON renderings;
//! `decoding` turns `text`'s `DecodeNote`s into diagnostics.

use std::fmt::Write as _;

use serde::Serialize;

use crate::text::{DecodeNote, LineIndex, TextRange};

/// How serious a finding is.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Severity {
    /// The construct was skipped; the output is incomplete.
    Error,
    /// Behaviour was assumed; the output may differ from the machine.
    Warning,
    /// Information.
    Note,
}

impl Severity {
    /// Lower-case name.
    pub fn as_str(self) -> &'static str {
        match self {
            Severity::Error => "error",
            Severity::Warning => "warning",
            Severity::Note => "note",
        }
    }
}

macro_rules! codes {
    ($( $(#[doc = $doc:literal])+ $variant:ident = ($name:literal, $sev:ident), )*) => {
        /// The stable catalogue of diagnostic codes, grouped by phase.
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        #[non_exhaustive]
        pub enum Code {
            $( $(#[doc = $doc])+ $variant, )*
        }

        impl Code {
            /// Every code, in catalogue order.
            pub const ALL: &'static [Code] = &[$(Code::$variant),*];

            /// The stable identifier, such as `syntax::unknown-address`.
            pub fn as_str(self) -> &'static str {
                match self { $(Code::$variant => $name,)* }
            }

            /// The default severity.
            pub fn severity(self) -> Severity {
                match self { $(Code::$variant => Severity::$sev,)* }
            }

            /// One line of documentation.
            pub fn doc(self) -> &'static str {
                match self { $(Code::$variant => concat!($($doc),+).trim_ascii(),)* }
            }
        }
    };
}

impl Code {
    /// Whether the finding holds for one maker's control alone: it follows from a behaviour
    /// or a limit the dictionary states for its maker where other makers whose dictionaries
    /// share its lineage read the same text otherwise: the dwell-point alarm
    /// (`dwell-point="alarm"`; Haas, Mazak, Okuma read `P.01` as a dwell), the plane change
    /// under compensation (`plane-under-comp="stops"`: Fanuc PS0037, where Haas, Mazak, Okuma,
    /// Fagor, LNC state no stop; not the RS274/NGC language's `modes-under-comp="locked"`,
    /// [`crate::interp`] keeps that one), a variable number above the maker's
    /// `highest-variable` (Fanuc #19999, Mitsubishi #907400, LNC #106999). On a dialect guessed
    /// from weak evidence such an error is a warning ([`crate::interp::Profile::guessed`]).
    /// A malformed word, a bad arc, a missing label hold on every control: not here.
    pub fn maker_specific(self) -> bool {
        matches!(self, Code::DwellPointAlarm | Code::PlaneUnderComp | Code::VariableOutOfRange)
    }
}

codes! {
    /// The input contains NUL or control bytes and is not a part program.
    BinaryInput = ("text::binary", Error),
    /// The text is another program format the dialect names (a conversational export).
    ForeignFormat = ("text::foreign-format", Error),
    /// The input is not UTF-8 and was decoded as Windows-1252.
    NotUtf8 = ("text::not-utf8", Note),
    /// The input exceeds the configured size limit and was not analysed.
    TooLarge = ("text::too-large", Error),
    /// The file holds no program (empty, or only blanks or NUL bytes: a truncated save or an
    /// aborted copy); it is stored but never compared.
    EmptyFile = ("text::empty", Warning),
    /// The revision is the start of the next revision of the same file, stored seconds later:
    /// a partial write, kept out of the change report.
    PartialWrite = ("text::partial-write", Warning),
    /// An earlier analysis of the same content never finished (the process was killed: out of
    /// memory, a memory limit, a crash); it is stored without analysis instead of being retried.
    AnalysisFailed = ("text::analysis-failed", Error),
    /// Several CAM originals match the program's names and nothing tells them apart, so it
    /// was not compared.
    PairingAmbiguous = ("pairing::ambiguous", Warning),
    /// Text before the program's opening `%` (a CAM listing header): tape leader, which the
    /// control skips and so does the analysis.
    Leader = ("syntax::leader", Note),
    /// Which producer's conventions a CL file (record form) is read with, and why.
    RecordProducer = ("syntax::record-producer", Note),
    /// A line of a CL file that is no record (a listing's header, `Tool Path Listing has 81
    /// lines.`): skipped.
    NotARecord = ("syntax::not-a-record", Warning),
    /// A major word the dictionary does not define (a user post-processor word): passed over.
    UnknownRecord = ("syntax::unknown-record", Note),
    /// An argument a record does not take, or a record missing what it needs.
    RecordArgument = ("syntax::record-argument", Warning),
    /// A CL file without a units record before its first move: default units assumed.
    RecordUnits = ("syntax::record-units", Note),
    /// A circle whose tangent moves turn the other way than its producer's setting says.
    CircleDirection = ("syntax::circle-direction", Warning),
    /// A circle whose start and end (or stated radius) are not the same distance from its centre.
    CircleRadius = ("syntax::circle-radius", Warning),
    /// A circle no motion record ends.
    CircleWithoutMove = ("syntax::circle-without-move", Warning),
    /// A circle (or hole) about a tilted axis, which the canon cannot state: read straight or along Z.
    CircleTilted = ("syntax::circle-tilted", Warning),
    /// A letter that the dialect does not define as an address.
    UnknownAddress = ("syntax::unknown-address", Error),
    /// A block of a keyword-first language (Klartext) that starts with an axis word: the
    /// control reads no block without its function (`L`, `C`, `CR`, ...), so it stops there.
    NoFunction = ("syntax::no-function", Error),
    /// A number that cannot be read.
    MalformedNumber = ("syntax::malformed-number", Error),
    /// A dwell's P written with a decimal point (`G04 P2.`, `G82 ... P.5`, a cycle's repeat
    /// line `X2. P1.`) on a control that takes only a whole number of milliseconds there and
    /// stops with an alarm (Fanuc PS0007). It holds for that maker alone (Haas reads seconds):
    /// on a dialect guessed from weak evidence it is a warning.
    DwellPointAlarm = ("interp::dwell-point-alarm", Error),
    /// A comment that is not closed before the end of the line.
    UnterminatedComment = ("syntax::unterminated-comment", Error),
    /// A comment holding the character that opens one, where the control stops at it
    /// (rs274ngc: "Nested comment found").
    NestedComment = ("syntax::nested-comment", Error),
    /// A teaching simulator's command written as a comment with parentheses of its own
    /// (`($SetPartSize(42, 12, 2, 1))`): read to its matching close, as the simulator reads
    /// it; a control ends the comment at its first close.
    SimulatorDirective = ("syntax::simulator-directive", Warning),
    /// An expression that cannot be parsed.
    MalformedExpression = ("syntax::malformed-expression", Error),
    /// An address without a value.
    MissingValue = ("syntax::missing-value", Error),
    /// The same address appears twice in one block.
    DuplicateWord = ("syntax::duplicate-word", Error),
    /// A G or M code the dialect does not know.
    UnknownCode = ("syntax::unknown-code", Error),
    /// Two codes of one modal group in one block.
    ModalGroupConflict = ("syntax::modal-group-conflict", Error),
    /// Two G codes of one modal group in one block where the control's manual says the last
    /// one is in effect (Fanuc): the last is taken.
    ModalGroupLastWins = ("syntax::modal-group-last-wins", Note),
    /// A command is missing a parameter it requires.
    MissingParameter = ("syntax::missing-parameter", Error),
    /// An M code the dialect leaves to the machine builder.
    MachineCode = ("syntax::machine-code", Note),
    /// A code, cycle or statement of the control's documented vocabulary (its manual, an
    /// option, a documented machine-builder range) that ncplan does not model: the control
    /// runs it, so the block is kept as intent and the moves it makes are unknown.
    Unmodelled = ("syntax::unmodelled", Warning),
    /// A code whose documented effect moves the machine (a retract, a reference return,
    /// polar positions) that ncplan does not model: the toolpath after it is not known.
    MotionUnknown = ("interp::motion-unknown", Warning),
    /// A word that no command in the block uses.
    UnusedWord = ("syntax::unused-word", Warning),
    /// A construct the dialect defines but this version of the interpreter does not execute.
    Unsupported = ("interp::unsupported", Warning),
    /// A tilted working plane or tool axis the program states but the analysis cannot work
    /// out without the machine's kinematics (rotary axis positions, a swivel mode it lacks):
    /// the moves that follow keep the plane in force before it.
    TiltUnknown = ("interp::tilt-unknown", Warning),
    /// An arc whose start and end radius differ beyond tolerance, or that cannot be built.
    BadArc = ("interp::bad-arc", Error),
    /// A lathe program whose arcs' centres (I, K) fit only with its X words read as radii, on
    /// a control that reads them as diameters: the machine is set to radius programming (Fanuc
    /// parameter DIAx off), and the program is read so.
    XWordsRadius = ("interp::x-words-radius", Warning),
    /// A program for a lathe of a control whose turning machines read X as a diameter in the
    /// ZX plane from reset (SINUMERIK: `DIAMON` and `G18` among the reset values, MD20150
    /// GCODE_RESET_VALUES) that moves before stating `DIAMON` and never states `DIAMOF`: its
    /// turning words (cycles, `LIMS=`, `G96`) show the lathe, and it is read so.
    XWordsDiameter = ("interp::x-words-diameter", Note),
    /// A lathe program (its turning words, or `DIAMON`) with T words and no M6, on a control
    /// whose turning machines change the tool with the T word (SINUMERIK MD22550
    /// TOOL_CHANGE_MODE 0, the turning setting): each T word changes the tool, and the program
    /// is read so.
    ToolWordChanges = ("interp::tool-word-changes", Note),
    /// A lathe program that states no units whose feeds per revolution are all at most 0.06 (no
    /// turning feed in mm/rev, an ordinary one in inch/rev): read in inch, the machine's
    /// power-on units being inch.
    UnitsInferred = ("interp::units-inferred", Warning),
    /// A program under least-increment input that writes its whole-number lengths mostly
    /// without a decimal point (`X55 Z2`, more than twice as often as `X55.`) and its fractions
    /// with one (`X-0.5`): written for calculator-type input (Fanuc parameter DPI, 3401#0, on),
    /// and read so.
    DecimalInputInferred = ("interp::decimal-input-inferred", Warning),
    /// A word's value lies outside what its command accepts (`M19 P3`, `M19 Q-1`).
    BadValue = ("interp::bad-value", Error),
    /// A cutting move with the spindle stopped.
    CuttingWithoutTechnology = ("interp::cutting-without-technology", Warning),
    /// A cutting move with a zero feed rate: the control stops with an alarm.
    NoFeed = ("interp::no-feed", Error),
    /// A reference to a parameter that has no value.
    UndefinedParameter = ("interp::undefined-parameter", Error),
    /// A whole variable number above the dictionary's `highest-variable`: the maker's control
    /// has no such variable and stops (Fanuc PS0115 "VARIABLE NO. OUT OF RANGE").
    VariableOutOfRange = ("interp::variable-out-of-range", Error),
    /// A variable read before it is set, on a control where that reads 0.
    UnsetVariable = ("interp::unset-variable", Warning),
    /// A length without a decimal point under least-increment input, in a program whose other
    /// lengths have one: `X118` is 0.118 mm there, which is rarely what was meant.
    NoDecimalPoint = ("interp::no-decimal-point", Warning),
    /// A word whose value comes from outside the file (the caller's arguments, retained
    /// common variables, machine data, global user data): left out, so the block keeps its
    /// known words. A note on a called program, a warning on a main one.
    UnknownValue = ("interp::unknown-value", Note),
    /// A finding that only follows from state the caller sets (its modal feed or spindle),
    /// noted on a program that is called; on a main program the finding keeps its own code.
    CallerState = ("interp::caller-state", Note),
    /// The file reads as a called program (its form, the config or `--as` says so), and
    /// what that means for the findings.
    CalledProgram = ("interp::called-program", Note),
    /// A condition on a value from outside the file: it took the way a run without alarm
    /// goes (or the dictionary's or config's choice), and the note names it.
    UnknownCondition = ("flow::unknown-condition", Note),
    /// A definition block (Okuma `DEF WORK` ... `END`): data for the control, skipped by the run.
    DefinitionSkipped = ("flow::definition-skipped", Note),
    /// A control statement that could not be read (a condition cut short, a jump left
    /// without its IF): it is skipped instead of acting on what was left of it (the control
    /// alarms at it).
    BrokenCondition = ("flow::broken-statement", Warning),
    /// Division by zero or a function outside its domain.
    ArithmeticError = ("interp::arithmetic", Error),
    /// A canned cycle that lacks its depth or retract plane.
    CycleIncomplete = ("interp::cycle-incomplete", Error),
    /// Text after the end of the program was ignored.
    AfterProgramEnd = ("interp::after-program-end", Note),
    /// More findings of one kind than are worth listing; the rest were counted.
    FindingsOmitted = ("interp::findings-omitted", Note),
    /// The program raised an operator message.
    ProgramMessage = ("interp::message", Note),
    /// The program raised an alarm (`#3000 = n`); execution stops.
    ProgramAlarm = ("interp::alarm", Error),
    /// A jump or call to a label, block number or program that does not exist.
    MissingLabel = ("flow::missing-label", Error),
    /// A program called by name that is neither in the file nor in the program directory:
    /// its machining is missing from the analysis.
    MissingProgram = ("flow::missing-program", Error),
    /// A loop ran past its iteration limit, or the run past its block budget.
    LoopLimit = ("flow::loop-limit", Error),
    /// A loop that changes nothing while it waits for a variable the outside writes (a
    /// handshake with the PLC, a robot or a remote client): taken as changed.
    WaitLoop = ("flow::wait-loop", Warning),
    /// The run executed more blocks again (loop passes, backward jumps, repeated calls) than
    /// the profile's budget: the analysis stops there, the program may well go on.
    RepeatBudget = ("flow::repeat-budget", Warning),
    /// Calls nested deeper than the dialect allows.
    CallDepth = ("flow::call-depth", Error),
    /// A loop end, branch or return without its opening statement.
    UnmatchedStatement = ("flow::unmatched", Error),
    /// A subroutine definition closed by an `endsub` of another name, in a subroutine file
    /// run from its `sub` line: the run returns there all the same (rs274), but the label is
    /// probably a copy's leftover.
    ForeignEndLabel = ("flow::foreign-end-label", Warning),
    /// A subroutine defined inside another subroutine's definition.
    NestedDefinition = ("flow::nested-definition", Error),
    /// A file that only defines subroutines: nothing runs by itself.
    Library = ("flow::library", Note),
    /// A main program that runs off the end of its file, on a control that requires an end.
    NoProgramEnd = ("flow::no-program-end", Error),
    /// A statement keyword the dialect does not define.
    UnknownStatement = ("flow::unknown-statement", Error),
    /// A keyword written in a spelling the control does not take, which some posts write
    /// (Heidenhain `CYCLE DEF` for `CYCL DEF`; the dictionary's `rejected`): read as meant,
    /// but the control stops at the block.
    RejectedSpelling = ("syntax::rejected-spelling", Error),
    /// Cutter compensation that cannot be computed (gouging, an arc entry).
    CompGouge = ("interp::comp-gouge", Error),
    /// Cutter radius compensation without a known offset.
    CompWithoutOffset = ("interp::comp-without-offset", Warning),
    /// A plane code (G17–G19) that changes the plane while cutter radius compensation is on,
    /// on a control that stops at it (the dictionary's `plane-under-comp="stops"`: Fanuc
    /// PS0037, Mitsubishi P112; or `modes-under-comp="locked"`: RS274/NGC, LinuxCNC "Cannot
    /// change planes with cutter radius compensation on").
    PlaneUnderComp = ("interp::plane-under-comp", Error),
    /// A plane code that changes the plane while cutter radius compensation is on, on a
    /// control whose dictionary does not say it stops there: what the control does is not
    /// known.
    PlaneUnderCompUnknown = ("interp::plane-under-comp-unknown", Warning),
    /// A program that cuts without a tool change, with one tool in its header's tool list:
    /// that tool is taken as the one in the spindle.
    ToolFromList = ("plan::tool-from-list", Note),
    /// A toolpath that plan recovery could not assign to a tool.
    NoTool = ("plan::no-tool", Warning),
    /// A tool that cuts with another tool's length offset (`T4` with `G43 H3`).
    ForeignLengthOffset = ("plan::foreign-length-offset", Warning),
    /// Cutting with no length offset (`H0`, or after `G49`) where the program uses them elsewhere.
    NoLengthOffset = ("plan::no-length-offset", Warning),
    /// A workingstep in a work offset that the rest of the program never uses.
    LoneWorkOffset = ("plan::lone-work-offset", Warning),
    /// STEP-NC export without stock dimensions: the rawpiece has no bounding block.
    StockUnknown = ("stepnc::stock-unknown", Warning),
    /// STEP-NC export of a tool or hole whose diameter is not known: written as 0.
    DiameterUnknown = ("stepnc::diameter-unknown", Warning),
    /// A malformed or invalid dialect file.
    DialectInvalid = ("dialect::invalid", Error),
    /// The target dialect has no output rules, or no rule for something the program does:
    /// that part of the program is not written.
    PostUnwritable = ("post::unwritable", Error),
    /// The translation, read back in the target's dialect, does not run as the source does
    /// (`translate --check`): a move, a home return, a work offset, the tool, the spindle or
    /// the coolant differs.
    PostMotionDiffers = ("post::motion-differs", Error),
    /// The program has a motion ncplan does not know (`interp::motion-unknown`): a translation
    /// would drop it or move elsewhere, so none is written.
    PostMotionUnknown = ("post::motion-unknown", Error),
    /// The program has an error where ncplan reads it (the control stops there, or ncplan
    /// cannot read what it does): what follows it is not known as the control runs it, so a
    /// translation is refused rather than written past it (an arc whose radii differ written
    /// as a straight cut).
    PostSourceError = ("post::source-error", Error),
    /// An axis moves incrementally from a position the program does not know (`G91` or
    /// `U`/`W`/`IX` before any absolute word for it, or after a reference return): the target
    /// cannot state that move incrementally, and an absolute position counted from an assumed
    /// 0 would send the tool elsewhere, so the translation is refused.
    PostUnknownStart = ("post::unknown-start", Error),
    /// A canned cycle the target cannot state as a cycle: written as the moves it makes.
    PostCycleAsMoves = ("post::cycle-as-moves", Note),
    /// Macros, loops and subprograms are written as the path that runs, unrolled.
    PostUnrolled = ("post::unrolled", Note),
    /// A written line is longer than the target control takes.
    PostLineTooLong = ("post::line-too-long", Warning),
    /// The program exceeds a limit of the target machine (travel, spindle speed, feed).
    PostMachineLimit = ("post::machine-limit", Warning),
    /// Inch input written in millimetres for a metric machine (or the reverse).
    PostUnitsConverted = ("post::units-converted", Note),
    /// The source states positions finer than the target's number format writes them: they
    /// are written rounded to the target's resolution.
    PostRounded = ("post::rounded", Note),
    /// A G92-style shift (LinuxCNC `G92`, a Heidenhain datum shift) is written into the
    /// positions: the machine makes the same moves, but the program states them in the work
    /// offset's frame, so the plan read back is in that frame.
    PostShiftApplied = ("post::shift-applied", Note),
    /// An arc whose radii at its start and end differ by more than the target's tolerance:
    /// its centre is moved onto the chord's bisector so that both agree, and its path moves
    /// by up to the radius difference.
    PostArcCentre = ("post::arc-centre", Note),
    /// A cycle's workpiece surface stated otherwise: a cycle that states it (Siemens RFP,
    /// Heidenhain Q203) written as one that cannot (a G8x cycle), or one that does not written
    /// as one that must, where the source's plan has no top above the hole's bottom (the R
    /// level is written). The machine makes the same moves; the plan read back takes the
    /// holes' top from elsewhere.
    PostSurfaceRestated = ("post::surface-restated", Note),
    /// A diameter or radius mode (G7/G8, DIAMON/DIAMOF) not written: the target has no such
    /// mode and reads X as radii anyway. The machine makes the same moves; the plan read back
    /// does not know the program turns.
    PostModeImplied = ("post::mode-implied", Note),
}

/// One finding about one input.
#[derive(Clone, Debug, PartialEq)]
pub struct Diagnostic {
    /// Stable code.
    pub code: Code,
    /// Severity (defaults to the code's).
    pub severity: Severity,
    /// A sentence without a trailing period.
    pub message: String,
    /// The byte range of the source the finding is about.
    pub range: TextRange,
}

impl Diagnostic {
    /// A diagnostic with the code's default severity.
    pub fn new(code: Code, range: TextRange, message: impl Into<String>) -> Diagnostic {
        Diagnostic { code, severity: code.severity(), message: message.into(), range }
    }

    /// True for errors.
    pub fn is_error(&self) -> bool {
        self.severity == Severity::Error
    }

    /// True for the finding that the analysis stopped before the program's end (its bound,
    /// a runaway loop): every command says it on stderr, whatever else it shows.
    pub fn stops_analysis(&self) -> bool {
        matches!(self.code, Code::RepeatBudget | Code::LoopLimit)
    }
}

impl From<DecodeNote> for Diagnostic {
    /// What decoding noticed, as the diagnostic that tells the user.
    fn from(note: DecodeNote) -> Diagnostic {
        match note {
            DecodeNote::Binary => Diagnostic::new(
                Code::BinaryInput,
                TextRange::default(),
                "the file looks like binary data (NUL or control bytes), not a part program",
            ),
            DecodeNote::NotUtf8 { at } => Diagnostic::new(
                Code::NotUtf8,
                TextRange::default(),
                format!("the file is not valid UTF-8 (first at byte {at}); it was read as Windows-1252 (Latin-1)"),
            ),
        }
    }
}

/// The diagnostics of what decoding noticed ([`crate::text::decode`] and its kin).
pub fn decoding(notes: Vec<DecodeNote>) -> Vec<Diagnostic> {
    notes.into_iter().map(Diagnostic::from).collect()
}

/// A diagnostic with its position resolved, ready for JSON or SQL.
#[derive(Clone, Debug, Serialize)]
pub struct DiagnosticJson {
    /// Code identifier.
    pub code: &'static str,
    /// Severity.
    pub severity: Severity,
    /// Message.
    pub message: String,
    /// 1-based line.
    pub line: u32,
    /// 1-based column in characters.
    pub col: u32,
    /// Byte range start.
    pub start: u32,
    /// Byte range end.
    pub end: u32,
}

impl DiagnosticJson {
    /// Resolves the position of `d` in `text`.
    pub fn new(d: &Diagnostic, text: &str, index: &LineIndex) -> DiagnosticJson {
        let lc = index.line_col(text, d.range.start);
        DiagnosticJson {
            code: d.code.as_str(),
            severity: d.severity,
            message: d.message.clone(),
            line: lc.line,
            col: lc.col,
            start: d.range.start,
            end: d.range.end,
        }
    }
}

/// `path:line:col: severity[code]: message`
pub fn render_short(path: &str, text: &str, index: &LineIndex, d: &Diagnostic) -> String {
    render_short_at(path, index.line_col(text, d.range.start), d)
}

/// [`render_short`] with the line and column of the finding's start already known (see
/// [`crate::text::locate`]).
pub fn render_short_at(path: &str, lc: crate::text::LineCol, d: &Diagnostic) -> String {
    format!("{path}:{}:{}: {}[{}]: {}", lc.line, lc.col, d.severity.as_str(), d.code.as_str(), d.message)
}

/// The short form followed by the source line and a caret line, as rustc prints.
pub fn render_human(path: &str, text: &str, index: &LineIndex, d: &Diagnostic) -> String {
    let lc = index.line_col(text, d.range.start);
    let line = index.line_text(text, lc.line);
    let mut out = format!("{}[{}]: {}\n", d.severity.as_str(), d.code.as_str(), d.message);
    let gutter = lc.line.to_string().len();
    let _ = writeln!(out, "{:gutter$}--> {path}:{}:{}", "", lc.line, lc.col);
    let _ = writeln!(out, "{:gutter$} |", "");
    let _ = writeln!(out, "{} | {}", lc.line, line);
    let end_lc = index.line_col(text, d.range.end);
    let width = if end_lc.line == lc.line { (end_lc.col.saturating_sub(lc.col)).max(1) } else { 1 };
    let pad: String = line.chars().take((lc.col - 1) as usize).map(|c| if c == '\t' { '\t' } else { ' ' }).collect();
    let _ = writeln!(out, "{:gutter$} | {pad}{}", "", "^".repeat(width as usize));
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_code_is_documented_and_unique() {
        let mut names: Vec<_> = Code::ALL.iter().map(|c| c.as_str()).collect();
        for c in Code::ALL {
            assert!(!c.doc().is_empty(), "{c:?}");
            assert!(c.as_str().contains("::"), "{c:?}");
        }
        names.sort_unstable();
        names.dedup();
        assert_eq!(names.len(), Code::ALL.len());
    }

    #[test]
    fn renders_with_caret() {
        let text = "G0 X1\nG1 E5 F100\n";
        let idx = LineIndex::new(text);
        let d = Diagnostic::new(Code::UnknownAddress, TextRange::new(9, 11), "unknown address `E`");
        assert_eq!(render_short("a.nc", text, &idx, &d), "a.nc:2:4: error[syntax::unknown-address]: unknown address `E`");
        expect_test::expect![[r#"
            error[syntax::unknown-address]: unknown address `E`
             --> a.nc:2:4
              |
            2 | G1 E5 F100
              |    ^^
        "#]]
        .assert_eq(&render_human("a.nc", text, &idx, &d));
    }
}

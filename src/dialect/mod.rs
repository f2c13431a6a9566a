//! The dialect dictionary: one XML file per controller dialect drives one engine.
//!
//! [`load`] turns XML text into a validated [`Dialect`] (never failing: it returns
//! diagnostics that point into the XML). [`registry`] holds the shipped dialects and those a
//! user adds at run time. The engine only ever asks a `Dialect` about *capabilities*
//! (meanings, roles, rules); it never looks at a dialect's name.
//!
//! the dictionary. `vocab.rs` is the engine's closed vocabulary (`Meaning`,
//! `Role`, `Step`, `Statement`, `SystemVar`; and `MAX_HIGH_PARAM` and `normalise_name`, which the
//! loader and `interp::eval` share); `<macros>` in a dialect file maps statement
//! keywords, local-variable ranges, macro-call argument letters and system variables; `xml.rs` reads XML into a positioned tree (the only quick-xml user); `load` (`load/` per section)
//! validates it into a `Dialect` with diagnostics pointing into the XML; `registry.rs` holds the
//! shipped files (compiled in, each parsed and merged the first time it or a dialect
//! extending it is asked for: a command pays for the dialects it uses) plus user files,
//! which win over shipped ones of the same name. `dialects/dialect.xsd` is the schema.
//! Keyword codes (`<code keyword="TOOL CALL" value-role="tool">`, `TRANS`, `DR+`, `FMAX`) sit in
//! the groups beside G and M codes; `<cycles>` name positional cycles (`CYCLE83(...)`) or
//! parameter-defined ones (`CYCL DEF 200` reading Q200…); `sniff.rs` scores each dialect's
//! `<recognise>` evidence (extensions, weighted regexes, case-insensitive unless a marker says
//! `case-sensitive`) to tell a file's dialect. A derived dialect counts its base's evidence
//! (through `Dialect::extends`) and its own, less the inherited labels it `<remove>`s;
//! `against` markers subtract (a mill's Y words for a lathe). A tie goes to the base, so a
//! derived dialect wins only by evidence of its own. How sure: for each rival, what the
//! winner and the rival have beyond the dialect both descend from; a base that a dialect of
//! another family derived from it matches as well is low (the maker is not told), and so is a
//! winner with evidence against it.
//! The `family` attribute names the controller maker (`haas`, `mitsubishi`, …), and the corpus
//! test measures sniffing by it (`tests/golden/corpus/sniff.tsv`). Dictionary
//! regexes (`Pattern`) are ASCII and run over bytes; they are checked on load and compiled on
//! first use, without a full DFA (building one per pattern cost more than the sniffing).
//! `inherit.rs` merges a derived dialect (`extends="fanuc"`) over its base's element tree before
//! validation: entries replace or join by key, `<remove>` drops one, `<recognise>` and
//! `<description>` are not merged (sniffing adds the base's evidence to the derived dialect's
//! own); inherited elements point at the `extends` attribute.
//! `records.rs` is the **record form** (`<records>`, `block-form="record"`): programs of
//! `MAJOR/minor,value` records (APT CLDATA). Each major word gets one of the engine's
//! `RecordAction`s (words, text, name, statement — the whole record kept as a comment, as
//! `TLDATA`/`CUTTER` are for the tool's facts —, ignore, goto, delta, rapid, circle, cycle, from), the
//! codes it puts in force (the dictionary's own G/M table, which no CL file spells), the roles
//! of its positional numbers, and minor words that give codes or name the role of the number
//! after them (`RPM,1200`; `FEDTO,-15` measured along the tool axis from a hole's point,
//! `from-point`). `<producer>`s, told by evidence in the file's start (the first match; the
//! one without evidence is the default), set the circle sense (`CircleSense`) and may
//! define records their own way (NX's signed `FEDTO`, Creo's `DEPTH`/`CLEAR`).
//! The registry keeps each dialect's merged tree as the base for others and loads user files in
//! any order (`add_all` retries a file whose base comes later).

mod inherit;
mod load;
pub mod output;
pub mod records;
pub mod registry;
pub mod sniff;
mod vocab;
pub mod vocabulary;
mod xml;

pub use load::load;
pub use registry::Registry;
pub(crate) use vocab::normalised;
pub use vocab::{MAX_HIGH_PARAM, Meaning, Role, Statement, Step, SystemVar, normalise_name};

/// How a block's tokens are arranged.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BlockForm {
    /// `G1 X10 Y20` — letter + value words in any order (ISO 6983).
    WordAddress,
    /// `L X+10 R0 FMAX`, `TOOL CALL 1 Z S2000` — a keyword first, then its words (Heidenhain).
    KeywordFirst,
    /// `GOTO/1.0,2.0,3.0`, `SPINDL/RPM,1200,CLW` — records of a major word, a slash and
    /// minor words and numbers (APT CLDATA); read as the dialect's `<records>` say.
    Record,
}

/// Where a comment ends.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum CommentClose {
    /// At the given character.
    Char(char),
    /// At the given two characters (`*/` of a `/* ... */` block comment), on the same line.
    Pair(char, char),
    /// At the end of the line.
    EndOfLine,
}

/// A comment rule.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CommentRule {
    /// Opening character.
    pub open: char,
    /// The second character of a two-character opener (`//`: a `/` alone divides or skips a
    /// block), for a comment that runs to the end of the line or to a two-character close
    /// (`/* ... */`).
    pub open2: Option<char>,
    /// Where it closes.
    pub close: CommentClose,
    /// Only at the start of a block (after its number): Heidenhain's `*` structure blocks.
    pub block_start: bool,
    /// Whether an opening character inside the comment opens a nested one, so the comment
    /// ends at the matching close (`($SetPartSize(4, 4, 1, 1) )`, which simulators write).
    pub nested: bool,
    /// Whether an opening character inside the comment stops the program (rs274ngc: "Nested
    /// comment found"; NIST RS274NGC 3.3.4: comments may not be nested).
    pub nested_error: bool,
}

impl CommentRule {
    /// Whether the comment opens at the start of `s`.
    pub fn opens(&self, s: &[u8]) -> bool {
        s.first() == Some(&(self.open as u8)) && self.open2.is_none_or(|o| s.get(1) == Some(&(o as u8)))
    }

    /// The opener's length in bytes.
    pub fn open_len(&self) -> usize {
        1 + usize::from(self.open2.is_some())
    }
}

/// Where the block-skip character may stand.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SkipPosition {
    /// First non-blank character of the line.
    LineStart,
    /// Either first or right after the block number.
    LineStartOrAfterNumber,
}

/// Number notations beyond digits and a point.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct NumberForms {
    /// The letters that start a decimal exponent after a number (`EX`: `10EX3` is 10000),
    /// compared without case.
    pub exponent: Option<String>,
    /// The quote around a constant in another base, and the letters that name hexadecimal
    /// and binary (`'`, `H`, `B`: `'H1F'` is 31, `'B101'` is 5).
    pub radix: Option<(char, char, char)>,
    /// Whether a comma between digits is the decimal point (`L Z+100,000 R F5000`: older
    /// Heidenhain TNCs write and read a decimal comma).
    pub decimal_comma: bool,
}

/// A name indexed by an axis: `AX[X]=10` moves X; `VELOLIM[A]=50` sets per-axis data.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct AxisIndexed {
    /// The name, upper case (`AX`).
    pub name: String,
    /// Whether the assignment is a move of that axis (`AX`, `POS`) rather than a setting.
    pub moves: bool,
}

/// Lexical rules.
#[derive(Clone, Debug)]
pub struct Lexical {
    /// Block form.
    pub block_form: BlockForm,
    /// Whether a bare number at the start of a block is its block number (`17 L X+10`).
    pub leading_block_number: bool,
    /// Whether any address may take `=` and an infix expression (`X=R1*2`, `X=AC(10)`).
    pub assign_values: bool,
    /// Per-word absolute and incremental wrappers (`X=AC(10)`, `Y=IC(5)`).
    pub axis_modes: Option<(String, String)>,
    /// Wrappers that give a rotary axis an absolute position and the way to turn there
    /// (`C=DC(90)` the shortest way, `ACP` positive, `ACN` negative), upper case.
    pub rotary_absolute: Vec<String>,
    /// The character that ends a label at block start (`MARKE1:`).
    pub label_suffix: Option<char>,
    /// The string delimiter (`T="DRILL"`, `LBL "NAME"`).
    pub string_quote: Option<char>,
    /// Other ways to write a number: a decimal exponent (`10EX3`), quoted hexadecimal and
    /// binary constants (`'H1F'`, `'B1011'`).
    pub numbers: NumberForms,
    /// Whether a function may take its argument without brackets (`SIN +Q1`, `SQRT 25`).
    pub bare_function_arguments: bool,
    /// Whether identifiers name variables (`_X_HOME=0`, `X=_X_HOME`), as declared with `DEF`.
    pub identifier_variables: bool,
    /// The character that starts the name of a system variable (`$AC_TIME`, `$P_UIFR[1]`):
    /// the control's own data, which a program may read and write. One the program reads
    /// before it writes it is machine data, unknown here.
    pub system_variable_prefix: Option<char>,
    /// The brackets of an array element (`_RICH[0]`, `VAR5[R2]`) where they are not the
    /// expression brackets (Siemens: `[` and `]`).
    pub array_brackets: Option<(u8, u8)>,
    /// How many comma-separated indices an array element may have (`A[1,2]`, Siemens: up
    /// to three); 1 where the dialect has no such arrays.
    pub array_dimensions: u8,
    /// Names whose bracketed index is an axis name, not a variable (`AX[X]=10`,
    /// `VELOLIM[A]=50`), in dictionary order.
    pub axis_indexed: Vec<AxisIndexed>,
    /// Whether `==`, `<>`, `<`, `>`, `<=`, `>=` compare in expressions (`R1>=5`).
    pub symbolic_comparisons: bool,
    /// Whether a block opening with `(` and a statement keyword or a parameter assignment is
    /// that statement in brackets (Fagor 8055's high-level language: `(P100 = P101 * 2)`,
    /// `(IF P1 EQ 0 GOTO N10)`, `(CALL 3)`); any other `(` stays a comment.
    pub paren_statements: bool,
    /// Whether a block may open with a statement keyword (`IF [#1 EQ 1] THEN GOTO 10`,
    /// `GOTO 10`) although the dialect also has a control word (`O`): Centroid CNC12.
    pub keyword_statements: bool,
    /// Whether `<NAME>` (no sigil) stands for the text a `DEFINE <NAME> text` gave it (Centroid
    /// CNC12): read as a named value wherever a value or an assignment's target may stand; one
    /// standing for a whole statement is skipped with a warning.
    pub define_names: bool,
    /// Whether a quoted text standing as a word of its own (`G65 "file.cnc" A1`, `M200
    /// "prompt %f" #1`), and the variables listed beside it, are arguments of the block's code
    /// (Centroid CNC12's file calls and formatted-string M codes): read and not kept.
    pub text_arguments: bool,
    /// Whether `/` after a code gives it an argument (`M101/50001`, `M95 /1/2`, `M105/X2/Y3`:
    /// Centroid's PLC-bit and probing M codes) rather than a block skip: read and not kept.
    pub slash_arguments: bool,
    /// Whether `#` and one letter (`#T`, `#z`, `#[z]`) name a variable: a macro call's
    /// argument of that letter, or a local one (Centroid CNC11/CNC12 macros).
    pub letter_variables: bool,
    /// Whether `(` and `)` group inside an expression as its brackets do (`[#(20100+#z) ==
    /// 77]`: Centroid's manual, "numerical expression").
    pub paren_grouping: bool,
    /// Comment rules, tried in order.
    pub comments: Vec<CommentRule>,
    /// Block-skip (block-delete) character.
    pub block_skip: Option<(char, SkipPosition)>,
    /// Whether a digit may follow the block-skip character (`/2`: the second skip switch's
    /// blocks, Fanuc's additional optional block skip); the block is read as any skipped one.
    pub block_skip_levels: bool,
    /// The lowest level digit after the block-skip character: 1 (Fanuc `/1`-`/9`, `/1` the
    /// plain `/`), 0 (Siemens `/0`-`/9`, `/0` the plain `/`).
    pub block_skip_first_level: u8,
    /// Address letter of block numbers (`N`).
    pub block_number: Option<char>,
    /// Characters that mark a statement keyword (`#CALL`, `$IF`, `%L 100`).
    pub statement_prefix: Vec<u8>,
    /// Whether a block may be named instead of numbered (`NLOOP`), a jump target.
    pub named_blocks: bool,
    /// Program delimiter (`%`).
    pub program_delimiter: Option<char>,
    /// Whether text before the first delimiter line that has program text after it is tape
    /// leader the control skips (a CAM listing header, a title), rather than blocks.
    pub leader_skipped: bool,
    /// Whether the delimiter opens a program only on its first line (after blank lines),
    /// and one anywhere else without that opening is an error (LinuxCNC), rather than
    /// delimiting wherever it stands (tape format).
    pub delimiter_first_line: bool,
    /// Whether a delimiter line with a name after the mark (`%123 G71 *`, or after a block
    /// number) names the program and has the words after the name read (Heidenhain ISO).
    pub header_words: bool,
    /// Expression brackets, such as `[` `]`.
    pub expression: Option<(char, char)>,
    /// Whether a bracketed expression after a one-letter address needs `=` before it
    /// (Sinumerik: `J=(R109*(-1))`; `J(R109*(-1))` stops the control), `<expression
    /// after-address="assign">`; else the expression follows the letter (`X[#1+2]`).
    pub expression_needs_assign: bool,
    /// Parameter sigil (`#`), and whether `#<name>` names are allowed.
    pub parameter: Option<(char, bool)>,
    /// A second bank of numbered variables with a sigil of its own (LNC's global `@1`-`@6999`
    /// beside the local `#1`-`#199`), and the number its variable 0 is kept as: `@n` is
    /// variable `first + n` of the one numbered store.
    pub global_parameter: Option<(char, u32)>,
    /// Banks of numbered variables named by the parameter sigil and a letter (Heidenhain
    /// `QL1` local, `QR1` nonvolatile, `QS1` text), each with the number its variable 0 is
    /// kept as: `QLn` is variable `first + n` of the one numbered store.
    pub parameter_banks: Vec<(String, u32)>,
    /// Words that stand before a parameter's assignment and declare it (Heidenhain
    /// `DECLARE STRING QS1 = "TEXT"`): the assignment reads on after them.
    pub assignment_prefixes: Vec<String>,
    /// End-of-block character that may separate blocks on one line (Fanuc `;`).
    pub block_end: Option<char>,
    /// Line-continuation character (Heidenhain `~`).
    pub continuation: Option<char>,
    /// Whether `X 1 0 . 5` is `X10.5`.
    pub spaces_in_numbers: bool,
    /// Whether `||` joins two texts (Heidenhain `QS1 = QS2 || QS3`) where comparisons are
    /// written as words.
    pub bar_concatenation: bool,
    /// Program-number address at program start (Fanuc `O1234`), not a control word.
    pub program_number: Option<char>,
    /// A second character that starts a program number (`:0100` in ISO tape format).
    pub program_number_alt: Option<char>,
    /// Whether a program may be named instead of numbered (`OTBOX`), a call target.
    pub named_programs: bool,
    /// Control-flow word (LinuxCNC `o100 sub`).
    pub control_word: Option<char>,
    /// Other program formats that files for this control may hold (a conversational
    /// format exported as text), told by a pattern at the start, with what they are.
    pub foreign: Vec<(Pattern, String)>,
    /// Comments that act: `(MSG, Part 2)` shows a message, `(ABORT, no tool)` stops the
    /// program. Prefixes are lower case and compared without case after leading blanks.
    pub directives: Vec<(String, Directive)>,
}

/// What a comment starting with a directive prefix does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Directive {
    /// Shows the rest of the comment to the operator.
    Message,
    /// Stops the program with the rest of the comment as its error.
    Abort,
    /// Writes the rest of the comment to a log or a console (`(DEBUG, …)`, `(PRINT, …)`):
    /// nothing the machine does; a comment to the interpreter.
    Log,
    /// Works the control's log file (LinuxCNC's `(LOGOPEN, name)`, `(LOG, text)`): nothing
    /// the machine does, but a call the control makes (`LOGOPEN`, `LOG`).
    LogFile(LogFile),
    /// A teaching simulator's command (`($SetPartSize(100, 100, 20, 1))`): the simulator reads
    /// it to its matching close, quoted text and parentheses included, where a control ends
    /// the comment at its first close. Nothing the machine does.
    Simulator,
}

/// What a log-file directive does: the canonical event's kind, named here too.
pub use crate::canon::LogFile;

impl Lexical {
    /// The directive a comment's text starts with, and the text after its prefix.
    pub fn directive<'t>(&self, comment: &'t str) -> Option<(Directive, &'t str)> {
        let t = comment.trim_start();
        self.directives.iter().find_map(|(prefix, d)| {
            let head = t.get(..prefix.len())?;
            head.eq_ignore_ascii_case(prefix).then(|| (*d, &t[prefix.len()..]))
        })
    }
}

/// A regular expression from a dictionary: checked when the dictionary loads, compiled when
/// first used. Compiling every pattern of every shipped dialect costs more than reading a
/// short program, and most runs use none of them.
///
/// Patterns are ASCII: `\d`, `\w`, `\b` and `(?i)` follow ASCII rules, as NC words are
/// ASCII. That keeps each compiled automaton small (Unicode word boundaries cost about a
/// million instructions a pattern to build), and it lets a pattern run over bytes, so a match
/// may start or end inside a multi-byte character: callers that slice text with a match widen
/// it to character boundaries.
#[derive(Clone, Debug)]
pub struct Pattern {
    source: String,
    compiled: std::sync::OnceLock<regex_automata::meta::Regex>,
}

impl Pattern {
    /// Checks `source`; the error says what is wrong with it.
    pub fn new(source: &str) -> Result<Pattern, String> {
        regex_syntax::ParserBuilder::new().unicode(false).utf8(false).build().parse(source).map_err(|e| e.to_string())?;
        Ok(Pattern { source: source.to_owned(), compiled: std::sync::OnceLock::new() })
    }

    /// The expression as the dictionary writes it.
    pub fn source(&self) -> &str {
        &self.source
    }

    /// The compiled expression. One that passed the check but cannot be compiled (past the
    /// size limit) matches nothing.
    pub fn regex(&self) -> &regex_automata::meta::Regex {
        self.compiled.get_or_init(|| {
            let build = |src: &str| pattern_builder(regex_automata::meta::Config::new()).build(src).ok();
            build(&self.source).or_else(|| build("[^\\s\\S]")).expect("the empty class compiles")
        })
    }
}

/// A builder for dictionary patterns: ASCII over bytes, and no dense DFA (tracing's
/// env-filter turns that feature on, and building one per pattern costs more than a run).
pub(crate) fn pattern_builder(config: regex_automata::meta::Config) -> regex_automata::meta::Builder {
    let mut b = regex_automata::meta::Regex::builder();
    b.syntax(regex_automata::util::syntax::Config::new().unicode(false).utf8(false)).configure(config.dfa(false));
    b
}

/// The decimal-point input rule.
#[derive(Clone, Debug, PartialEq)]
pub enum DecimalInput {
    /// `X10` is 10 units.
    Calculator,
    /// `X10` is 10 least increments for the listed roles.
    LeastIncrement {
        /// Increment in mm mode.
        mm: f64,
        /// Increment in inch mode.
        inch: f64,
        /// Roles whose integer values scale.
        scaled: Vec<Role>,
    },
}

/// Unit of a dwell value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TimeUnit {
    /// Seconds.
    Seconds,
    /// Milliseconds.
    Milliseconds,
}

/// What a decimal point in a dwell's P (`G04 P2.`, a canned cycle's `P.5`) does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DwellPoint {
    /// Nothing of its own: P is read in the dwell unit, point or not.
    Unit,
    /// The point makes P seconds (Haas: `P.5` half a second, `P500` 500 ms).
    Seconds,
    /// The control stops with an alarm: P takes a whole number of milliseconds only (Fanuc
    /// 0i/30i: "a decimal point cannot be used" in P, alarm PS0007).
    Alarm,
}

/// Machine behaviour that differs between controls.
#[derive(Clone, Debug)]
pub struct Behaviour {
    /// Decimal-point input rule.
    pub decimal_input: DecimalInput,
    /// Whether the machine's configuration states the rule (a `[[machine]]`'s
    /// `decimal_input`): then no program's way of writing numbers overrides it
    /// (`interp::decimal-input-inferred` is for machines whose setting is not known).
    pub decimal_input_stated: bool,
    /// Dwell unit of `G4 P`.
    pub dwell_unit: TimeUnit,
    /// What a decimal point in a dwell's P does.
    pub dwell_point: DwellPoint,
    /// Whether M6 stops the spindle.
    pub tool_change_stops_spindle: bool,
    /// Whether a tool change applies the new tool's length offset (Siemens `D1` default,
    /// Heidenhain `TOOL CALL`), with no G43.
    pub tool_change_applies_length: bool,
    /// Whether a block in machine coordinates (`G53`) always moves at rapid traverse, whatever
    /// the motion mode in force (Fanuc: "G53 ... the tool moves at rapid traverse"); LinuxCNC's
    /// and Siemens' `SUPA` move by the motion mode in force.
    pub machine_coords_rapid: bool,
    /// Whether `G43 H0` takes the tool in the spindle (LinuxCNC's pocket 0, `h0="spindle-tool"`)
    /// rather than no offset.
    pub h0_spindle_tool: bool,
    /// Whether, after a block with a tool change, the program position is read back from the
    /// machine: the last move's end (LinuxCNC, `position-after-tool-change="last-move"`).
    pub tool_change_rereads_position: bool,
    /// How far back from a probe move's end, towards its start, the tool is taken to stop
    /// (rs274's simulator backs off 0.254 mm or 0.01 in), mm and inch.
    pub probe_backoff_mm: f64,
    /// The same in inch programs.
    pub probe_backoff_inch: f64,
    /// What the probe-tripped variable reads after a probe move: unknown (by default: only the
    /// machine knows whether the probe touched; a loop on it ends, as a successful run's
    /// does, and a check that alarms on it takes the way without alarm, as rs274's
    /// never-tripping simulator leaves such loops), or 1 or 0 where a dictionary says so.
    pub probe_tripped: Option<f64>,
    /// Peck-drilling re-approach clearance, mm.
    pub peck_clearance_mm: f64,
    /// Peck-drilling re-approach clearance, inch.
    pub peck_clearance_inch: f64,
    /// Maximum start/end radius difference of an arc given by its centre, mm.
    pub arc_tolerance_mm: f64,
    /// The same in inch programs (its own setting: LinuxCNC's are not one value converted).
    pub arc_tolerance_inch: f64,
    /// How many of the steps a program writes its arc's numbers in (`X1.2345`: 0.0001) the
    /// radii may differ by, when more than the tolerance: rounding each coordinate to that
    /// step moves a radius by up to √2 steps, so 2√2 for both. 0: the tolerance alone
    /// (LinuxCNC, as rs274).
    pub arc_tolerance_steps: f64,
    /// Whether a drilling cycle with no R feeds from the initial level (Fanuc family, with a
    /// warning) rather than being an error (LinuxCNC, as rs274).
    pub cycle_r_defaults_to_initial: bool,
    /// When set, a radius difference above the tolerance is still accepted while it is at
    /// most this share of the radius and at most 100 times the tolerance (LinuxCNC's rule
    /// for spirals written as arcs).
    pub arc_relative_tolerance: Option<f64>,
    /// Whether `#1=2 F#1` reads the new value (macro statements run first, as on Fanuc) or
    /// the old one (all reads of a block precede its assignments, as in RS274NGC).
    pub assign_before_reads: bool,
    /// Whether selecting units-per-minute feed (G94) resets the feed rate to zero.
    pub feed_mode_resets_feed: bool,
    /// Whether M codes the file does not list are machine-builder functions (recorded with a
    /// note) rather than errors.
    pub machine_m_codes: bool,
    /// Whether the control keeps programs in its own memory (machine builder's cycles, shop
    /// macros), so that a program called by an explicit call and found neither in the file
    /// nor in the program directory may well exist there: a warning that the analysis lacks
    /// its moves, and the run goes on. Otherwise (LinuxCNC, whose subroutines are files) the
    /// call is an error, as rs274 makes it.
    pub resident_programs: bool,
    /// Whether a subroutine called by name (`o<probe> call`) is a file the control looks up
    /// in a configured path (LinuxCNC's `SUBROUTINE_PATH`): one found neither in the program
    /// nor beside it is the machine's, and the call a warning that the analysis lacks its
    /// moves. A numbered subroutine must be in the program: its absence stays an error.
    pub subroutine_path: bool,
    /// Whether the T word changes the tool at once (a lathe turret indexes on `T0202`, with
    /// no M6) and puts its offset in force.
    pub tool_word_changes: bool,
    /// Whether the control's turning machines change the tool with the T word where its
    /// milling ones change it with M6 (SINUMERIK MD22550 TOOL_CHANGE_MODE: 0, "tool change
    /// with T", on turning machines; 1, with M6, on milling ones): a program read as such a
    /// lathe's that never says M6 is read so (`interp::tool-word-changes`).
    pub lathe_tool_word_changes: bool,
    /// Whether the machine's configuration states how the tool changes (`tool_change`), which
    /// a program's habit then does not override.
    pub tool_change_stated: bool,
    /// Whether I, J and K are the circle centre, absolute unless G91, kept as the pole for
    /// the arcs and polar moves after, and an arc without them turns about the pole
    /// (Heidenhain ISO, `arc-centres="pole"`).
    pub arc_centres_pole: bool,
    /// Whether F is a feed per revolution from the start (a lathe's power-on G99).
    pub initial_feed_per_rev: bool,
    /// How a tapping cycle leaves the hole.
    pub tapping: TapStyle,
    /// Whether FIX and FUP round toward and away from zero (Fanuc) rather than down and up
    /// (LinuxCNC).
    pub magnitude_rounding: bool,
    /// Whether a G0 or G1 written in a block without axis words moves to where the tool is
    /// (a zero-length move, as LinuxCNC emits it) rather than only setting the mode.
    pub motion_in_place: bool,
    /// Whether a word that no command of its block uses stops the control (LinuxCNC: "R word
    /// with no g code that uses it") rather than being ignored with a warning.
    pub unused_words_rejected: bool,
    /// Whether a main program must end with its end code (M2, M30) or a closing delimiter;
    /// running off the end of the file is then an error (LinuxCNC: "File ended with no
    /// percent sign or program end"). A file of subroutine definitions only is exempt.
    pub end_required: bool,
    /// Whether X words give diameters from the program's start (a lathe control); G7/G8
    /// switch where the dictionary has them.
    pub x_diameter: bool,
    /// Whether the control's turning machines read X words as diameters in the ZX plane from
    /// reset, where its milling ones do not (SINUMERIK `DIAMON` and `G18` in a lathe's reset
    /// values): a program that shows it turns is read so (`interp::x-words-diameter`).
    pub lathe_x_diameter: bool,
    /// Whether, under diameter programming, an arc centre's X given absolute (`I=AC(50)`) is
    /// a diameter as the X words are, where one given incrementally stays a radius (SINUMERIK
    /// Operate's contour circle: "I circle centre point ∅ (abs) or I (inc)").
    pub absolute_centre_x_diameter: bool,
    /// Whether a rounding or chamfer written on a move (`RND=`, `CHR=`) that is too large for
    /// a move beside its corner is made smaller to fit, rather than refused (SINUMERIK:
    /// "automatically reduced if the contour length of an involved block is insufficient").
    pub corners_reduced: bool,
    /// Whether the machine's configuration states how X words read (`x_words`), which a
    /// program's habit then does not override.
    pub x_words_stated: bool,
    /// The machine's two swivel axes, first and second (`swivel_axes = "BC"` in its
    /// configuration: the rotary axes a SINUMERIK swivel data record names), which
    /// `CYCLE800` in "rotary axes direct" mode positions; none where not configured.
    pub swivel_axes: Option<[u8; 2]>,
    /// The plane at the program's start and after its end (XZ on a lathe).
    pub initial_plane: crate::canon::Plane,
    /// Whether canned cycles retract to the R plane (G99) until the program says G98 or G99
    /// (RS274NGC); otherwise to the initial level (G98, the Fanuc power-on state).
    pub initial_retract_r: bool,
    /// Whether two G codes of one modal group in one block are taken as the control takes
    /// them, the last one in effect (Fanuc, `same-group-codes="last"`), rather than an error
    /// (LinuxCNC, as rs274).
    pub same_group_last_wins: bool,
    /// Whether the control stops at a plane (G17–G19) or units (G20/G21) code while cutter
    /// radius compensation is on (`modes-under-comp="locked"`: RS274/NGC, LinuxCNC), so that
    /// the order of G40 against such a code counts.
    pub comp_locks_modes: bool,
    /// Whether the control stops at a plane code (G17–G19) that changes the plane while
    /// cutter or tool-nose radius compensation is on (`plane-under-comp="stops"`: Fanuc alarm
    /// PS0037 "CAN NOT CHANGE PLANE IN G41/G42", Mitsubishi P112; implied by
    /// `modes-under-comp="locked"`); otherwise what the control does is not known (a warning).
    pub plane_under_comp_stops: bool,
}

/// The spindle and retract sequence of a tapping cycle at the bottom of the hole.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TapStyle {
    /// Dwell, reverse, feed out to the R plane, forward again, then rapid to the clear level
    /// (Fanuc G84).
    RPlane,
    /// Stop, reverse, dwell, feed out all the way to the clear level, stop, forward (the
    /// RS274NGC G84 of LinuxCNC).
    Clear,
}

/// Macro and control-flow capabilities: statement keywords, variable scoping, call
/// arguments and system variables.
#[derive(Clone, Debug, PartialEq)]
pub struct Macros {
    /// Statement keywords (upper case) and what they do, longest first.
    pub statements: Vec<(String, Statement)>,
    /// Whether a statement keyword starts with a mark rather than a letter (`@100`, the older
    /// SINUMERIK controls): the parser looks for one only then.
    pub marked_keywords: bool,
    /// Whether variables start vacant (`#0` is null) and a word whose value is null is
    /// omitted, as in Fanuc Macro B. Otherwise variables start at zero.
    pub null_value: bool,
    /// First and last local variable: saved and reset on each macro or subroutine call.
    pub locals: (u16, u16),
    /// For each letter A..Z, the local variable a macro-call argument sets (`G65 A1` → `#1`).
    pub arguments: [Option<u16>; 26],
    /// System variables by number.
    pub system: Vec<(u32, SystemVar)>,
    /// Read-only named system parameters (LinuxCNC's `#<_x>`, `#<_motion_mode>`): the
    /// normalised name, what it reads, and the value of a [`SystemVar::Constant`].
    pub system_named: Vec<(String, SystemVar, f64)>,
    /// System variable arrays a program writes a tool's offset data through (Siemens
    /// `$TC_DP3[t,d]`, the length), upper case, and which data each is.
    pub tool_data: Vec<(String, DataForm)>,
    /// The columns of a tool table the program reads and writes as system data by number
    /// (Heidenhain `FN 17: SYSWRITE ID50 NR1 IDX5 = +0`: group 50, column 1, tool 5).
    pub tool_columns: Vec<ToolColumn>,
    /// The tool table as a table the program opens and writes by column name (Heidenhain
    /// `FN 26: TABOPEN TNC:\TOOL.T`, then `FN 27: TABWRITE 5/"L,R" = Q2`): `None` where the
    /// dictionary names none.
    pub tool_table: Option<ToolTable>,
    /// Deepest allowed nesting of calls.
    pub call_depth: u32,
    /// Whether digits above the fourth of a subprogram call's P are its repeat count
    /// (`M98 P30010` runs O10 three times).
    pub repeat_in_p: bool,
    /// Whether conditions are whole expressions up to the next keyword (`IF R1>5 GOTOF M1`)
    /// rather than bracketed operands (`IF [#1 GT 5] GOTO 10`).
    pub bare_conditions: bool,
    /// The label whose definition ends a label call (`LBL 0`), normalised.
    pub end_label: Option<String>,
    /// A definition block's start and end keywords (upper case): the lines between are data
    /// for the control (Okuma `DEF WORK` ... `END`), skipped by the run.
    pub definition_block: Option<(String, String)>,
    /// Whether a block that starts with an unknown name calls the program of that name.
    pub call_by_name: bool,
    /// The word that repeats a call (`P`, `REP`), upper case.
    pub call_repeat: Option<String>,
    /// Whether the repeat count gives the passes after the first (`REP 2` = 3 passes).
    pub call_repeat_additional: bool,
    /// Whether a condition followed by a block name jumps there (`IF [VC1 EQ 0] NLOOP`).
    pub bare_if_jump: bool,
    /// Whether the control checks the nesting of its control structures (`IF`/`ELSE`/`ENDIF`,
    /// `WHILE`/`ENDWHILE`, `FOR`/`ENDFOR`, `REPEAT`/`UNTIL`, `LOOP`/`ENDLOOP`) and stops with an
    /// alarm at an end with no open structure, an end of another kind, or a structure never
    /// closed (`checks-nesting`; Sinumerik: alarm 12640, invalid nesting of control structures).
    pub checks_nesting: bool,
    /// Whether a statement may follow an `IF [..]` condition on its line without `THEN`
    /// (Haas: `IF [#9 EQ #0] #9=#4109`, `IF [..] M98 P9004`): run when the condition holds.
    pub if_then_optional: bool,
    /// Whether an `IF` with nothing after its condition reads the condition and runs nothing
    /// (`if-alone-reads`; Centroid CNC12: its template M-function macros open with
    /// `IF #50010 ;Prevent lookahead from parsing past here`, reading a PLC input so that
    /// lookahead stops there), rather than opening a block up to an `ENDIF`.
    pub if_alone_reads: bool,
    /// Whether a variable read before it is set is 0 (with a note) instead of an error.
    pub unset_reads_zero: bool,
    /// Whether a named variable read before the file declares or sets it is unknown: global
    /// user data or the caller's (Siemens GUD), rather than an error.
    pub unset_unknown: bool,
    /// Numbered variables whose values come from outside the file (retained common
    /// variables, machine inputs and data): unknown until the program sets them.
    pub outside: Vec<(u32, u32)>,
    /// Numbered variables every program and subprogram the control runs shares (Fanuc's
    /// common variables, LinuxCNC's #31-#5000): one a file sets and does not read is for
    /// what runs after it (`global-variables`).
    pub globals: Vec<(u32, u32)>,
    /// The highest numbered variable the control has (`highest-variable`; 9999 unless the
    /// dictionary says more: Haas NGC's #59999, Mitsubishi's #907400).
    pub highest_variable: u32,
    /// Whether a return at the top level shows a called program. False where main programs
    /// end with the same word (Heidenhain `END PGM`).
    pub return_tells_called: bool,
    /// Program numbers a control reserves for called programs (Fanuc O9000–O9999 macros).
    pub called_numbers: Option<(u32, u32)>,
    /// Program numbers of probing macros (`probe-programs`: Renishaw Inspection Plus `O9810`…):
    /// a macro call of one runs a touch probe, its letters the probing's target, feed and
    /// measuring parameters.
    pub probe_programs: Vec<(u32, u32)>,
    /// File extensions (lower case, without the dot) of called programs (Siemens `spf`).
    pub called_extensions: Vec<String>,
    /// How a condition on an unknown value is taken when neither way leads to an alarm:
    /// true or false (the dictionary's choice; the config may override it).
    pub unknown_conditions: bool,
    /// Whether the tool-data system variables (Heidenhain Q108, the tool radius) of a tool the
    /// configured tool table does not list are unknown (the machine's tool table holds it)
    /// rather than 0 (`unlisted-tools`).
    pub unlisted_tools_unknown: bool,
    /// Whether the modal tool variable (`meaning="tool"`: Fanuc #4120) reads unknown before
    /// the program commands a tool: the machine's tool from before the program, not rs274's
    /// power-on 0 (`modal-tool`).
    pub modal_tool_unknown: bool,
    /// The address that names the block a subprogram call starts at (`M98 P100 H20`), if any.
    pub call_start: Option<u8>,
    /// What a return in the main program does.
    pub main_return: MainReturn,
    /// The named parameter a subroutine's return value goes to (`_value`), normalised;
    /// `<name>_returned` says whether the last call returned one.
    pub return_value: Option<String>,
    /// Functions whose value comes from the machine (LNC `R_REG[5]`, `R_MACH_COOR[0,3]`):
    /// read with their bracketed arguments as a value the analysis does not know. Upper case.
    pub machine_functions: Vec<String>,
}

/// What a return (`M99`, `M17`, `RET`) does in the main program.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MainReturn {
    /// It is a mistake: reported as an unmatched return.
    Error,
    /// It ends the program (a subprogram checked on its own).
    End,
    /// The control restarts the program endlessly (Fanuc `M99`).
    Restart,
}

impl Default for Macros {
    fn default() -> Macros {
        Macros {
            statements: Vec::new(),
            marked_keywords: false,
            null_value: false,
            locals: (1, 30),
            arguments: [None; 26],
            system: Vec::new(),
            system_named: Vec::new(),
            call_depth: 10,
            repeat_in_p: false,
            bare_conditions: false,
            end_label: None,
            definition_block: None,
            call_by_name: false,
            call_repeat: None,
            call_repeat_additional: false,
            call_start: None,
            bare_if_jump: false,
            checks_nesting: false,
            if_then_optional: false,
            if_alone_reads: false,
            unset_reads_zero: false,
            unset_unknown: false,
            outside: Vec::new(),
            globals: Vec::new(),
            highest_variable: 9999,
            called_numbers: None,
            probe_programs: Vec::new(),
            return_tells_called: true,
            called_extensions: Vec::new(),
            unknown_conditions: false,
            unlisted_tools_unknown: false,
            modal_tool_unknown: false,
            main_return: MainReturn::Error,
            return_value: None,
            machine_functions: Vec::new(),
            tool_data: Vec::new(),
            tool_columns: Vec::new(),
            tool_table: None,
        }
    }
}

/// The tool table as a table a program opens and writes by column name
/// (`<tool-table file="TOOL.T" group="50" open="TABOPEN" write="TABWRITE"/>`).
#[derive(Clone, Debug, PartialEq)]
pub struct ToolTable {
    /// The tool table's file name (`TOOL.T`), compared without case and path.
    pub file: String,
    /// The system data group whose `tool-column` names are its columns (`50`).
    pub group: u32,
    /// The keyword code that opens a table (`TABOPEN`), upper case.
    pub open: String,
    /// The keyword code that writes a row's columns of the open table (`TABWRITE`), upper case.
    pub write: String,
}

/// A tool table's column as system data by number: its group (`ID50`, the tool table), its
/// number in it (`NR1`), its name in the table (`L`), what it holds as a planner reads it
/// (`tool length`) and, for a length or radius, which (the kind of change its write makes).
#[derive(Clone, Debug, PartialEq)]
pub struct ToolColumn {
    /// The system data group (`ID50`).
    pub id: u32,
    /// The column's number in the group (`NR1`).
    pub nr: u32,
    /// Its name in the tool table (`L`, `DR`, `TIME1`).
    pub name: String,
    /// What it holds (`tool length`).
    pub what: String,
    /// The tool length or radius it is, if it is one.
    pub form: Option<DataForm>,
}

impl Macros {
    /// The statement a keyword (any case) names.
    pub fn statement(&self, word: &str) -> Option<Statement> {
        self.statements.iter().find(|(k, _)| k.eq_ignore_ascii_case(word)).map(|&(_, s)| s)
    }

    /// Whether the dialect has a statement that does `st`.
    pub fn has_statement(&self, st: Statement) -> bool {
        self.statements.iter().any(|&(_, s)| s == st)
    }

    /// The statement keyword that `word` (a run of letters, any case) starts with, longest
    /// first: `GOTO10` → `GOTO`, `WHILE` → `WHILE`. Keywords of several words are matched
    /// by the parser against the text.
    pub fn statement_prefix(&self, word: &str) -> Option<(&str, Statement)> {
        self.statements
            .iter()
            .find(|(k, _)| word.len() >= k.len() && word.as_bytes()[..k.len()].eq_ignore_ascii_case(k.as_bytes()))
            .map(|(k, st)| (k.as_str(), *st))
    }

    /// Whether program number `n` is one the control reserves for called programs.
    pub fn is_called_number(&self, n: u32) -> bool {
        self.called_numbers.is_some_and(|(a, b)| (a..=b).contains(&n))
    }

    /// What system variable `n` is, if any.
    pub fn system_var(&self, n: u32) -> Option<SystemVar> {
        self.system.iter().find(|&&(k, _)| k == n).map(|&(_, v)| v)
    }

    /// What the element `index` of the named array `name` (normalised) is, if the dictionary
    /// names it (Okuma's `VDOUT[992]`, the alarm output).
    pub fn system_element(&self, name: &str, index: f64) -> Option<SystemVar> {
        self.system_named.iter().find_map(|(n, v, _)| {
            let element = n.strip_prefix(name)?.strip_prefix('[')?.strip_suffix(']')?.parse::<f64>().ok()?;
            (element == index).then_some(*v)
        })
    }
}

/// An address: a letter or a multi-letter name and the role its value plays.
#[derive(Clone, Debug, PartialEq)]
pub struct AddressDef {
    /// Upper-case name, such as `X` or `CR`.
    pub name: String,
    /// Role.
    pub role: Role,
    /// Whether the value must follow `=` (`CR=5`).
    pub assign: bool,
    /// Whether the value is always incremental (`IX+10`), whatever G90/G91 say.
    pub incremental: bool,
    /// The role a second occurrence in one block takes (`T02 T05`: the next tool), if the
    /// address may appear twice.
    pub again: Option<Role>,
    /// For the tool address: how many last digits name the tool offset rather than the tool
    /// (a lathe's `T0202`: tool 2, offset 2; `T0200` cancels the offset).
    pub offset_digits: Option<u8>,
    /// For the tool address: a fraction after the point is the tool's ID code, not part of
    /// its number (Mazak's `T6400.1102`: tool 64, offset 00, ID code 1102, as the Autodesk
    /// Mazak Integrex post writes it from the tool's product ID).
    pub id_suffix: bool,
    /// For the tool address: the digits after the point name the tool offset (Fagor
    /// 8025/8055 T's `T2.2`: tool 2, offset 2), not a fraction of the tool's number.
    pub offset_suffix: bool,
    /// Whether the address may carry the number of the spindle it addresses before `=`
    /// (Siemens `M2=3`, `S2=2000`: spindle 2), with a number for its value.
    pub spindle_index: bool,
    /// Whether the address may carry a number naming one of several axes of its kind before
    /// `=` (Siemens `C4=120`: the axis the machine data names C4, here the C axis), with a
    /// number for its value.
    pub axis_index: bool,
}

/// What a keyword code reads after itself, before the block's other words.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum KeywordRest {
    /// Nothing special.
    #[default]
    None,
    /// One name (`BEGIN PGM PART1 MM`).
    Name,
    /// Any plain words (`CYCL DEF 200 DRILLING`, `CYCL DEF 7.0 DATUM SHIFT`).
    Words,
    /// The rest of the line (`SYSREAD Q1 = ID270 NR1`), kept unread.
    Line,
}

/// The spelling of a keyword code (`TRANS`, `TOOL CALL`, `DR+`).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct KeywordSpec {
    /// Upper-case text; may contain single spaces (`TOOL CALL`).
    pub text: String,
    /// The role of a bare number right after the keyword (`TOOL CALL 5` → tool).
    pub value_role: Option<Role>,
    /// What follows that value.
    pub rest: KeywordRest,
    /// Whether the value follows `=`, after an optional bracketed index (`SPOS=90`,
    /// `SPOS[1]=DC(45)`: the spindle's number), as an assigned value.
    pub assigned: bool,
}

/// Parameters a command takes.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ParamSpec {
    /// Roles the command requires.
    pub required: Vec<Role>,
    /// Roles the command accepts.
    pub optional: Vec<Role>,
    /// Sets of roles of which at least one must be present.
    pub any_of: Vec<Vec<Role>>,
    /// Pairs of role sets that must not be mixed (`I J K` versus `R`).
    pub exclusive: Vec<(Vec<Role>, Vec<Role>)>,
}

impl ParamSpec {
    /// True when the command uses `role`.
    pub fn takes(&self, role: Role) -> bool {
        self.required.contains(&role) || self.optional.contains(&role) || self.any_of.iter().any(|set| set.contains(&role))
    }
}

/// A G or M code.
#[derive(Clone, Debug, PartialEq)]
pub struct CodeDef {
    /// Letter (`G` or `M`).
    pub letter: char,
    /// Number ×10 (`G54.1` is 541).
    pub number: u16,
    /// Meaning.
    pub meaning: Meaning,
    /// Index for indexed meanings (work offset 1..9).
    pub index: u8,
    /// Human name for messages.
    pub name: String,
    /// Index into [`Dialect::groups`].
    pub group: usize,
    /// Parameters.
    pub params: ParamSpec,
    /// For a keyword code (`TRANS`, `TOOL CALL`), its spelling; G and M codes have none.
    pub keyword: Option<KeywordSpec>,
    /// For a data-setting code (G10), what each L value sets.
    pub forms: Vec<(u16, DataForm)>,
    /// Whether another code of its group in the same block replaces it instead of being an
    /// error (LinuxCNC's `G80 G0`).
    pub gives_way: bool,
    /// For a lathe's drilling cycle with a driven tool, the linear axis it feeds along (0 X:
    /// into the cylinder, placed by Z and C; 2 Z: into the face, placed by X and C); `None`
    /// for a cycle that feeds along its plane's normal.
    pub hole_axis: Option<u8>,
    /// For a reference approach (`reference-approach`) whose block names no axis: the axes it
    /// sends to the reference point, bit k for X Y Z A B C (Centroid `M25`: Z alone); 0 for
    /// every axis.
    pub home_axes: u8,
    /// For such a cycle: R is the R plane's position (Haas lathes; a diameter for a hole into
    /// the cylinder), not the distance from the initial level (Fanuc).
    pub r_absolute: bool,
    /// A spindle code of the driven tool's own drive (Haas `M133`-`M135`), not the main
    /// spindle's; P its speed.
    pub driven: bool,
    /// The roles the code gives its words' values (`I:pattern-radius`: Haas G70's I is the
    /// radius of its bolt circle, whatever I means elsewhere).
    pub args: Vec<(Role, Role)>,
    /// Whether a G or M code is followed by its display name in the control's language
    /// (Heidenhain ISO's `G200 DRILLING`, `rest="words"`), which is read past.
    pub named: bool,
    /// For a keyword that keeps the rest of its line unread (`rest="line"`): the words that
    /// rest holds and the role of each (`SPA:tilt-a`: `PLANE SPATIAL SPA+30` gives 30 to
    /// `tilt-a`), read by the command itself ([`CodeDef::line_word`]).
    pub line_words: Vec<(String, Role)>,
    /// For a tilted-plane code whose word selects how its angles turn the plane (`G68.2 P1`):
    /// each word's letter and value with the meaning it gives (`tilt-forms="P1:tilt-roll-pitch-yaw"`);
    /// without the word, or with the value 0, the code's own meaning.
    pub tilt_forms: Vec<(char, u16, Meaning)>,
    /// A second effect of the code, of another group of meanings (`also="feed-per-rev"`):
    /// Siemens puts the spindle's speed mode and the feed's type in one group (15), so `G96`
    /// is a constant cutting rate and a feed per revolution, `G94` a feed per minute and no
    /// constant cutting rate. Only a feed mode or a spindle speed mode.
    pub also: Option<Meaning>,
    /// Whether the code runs a touch probe's measuring cycle (`probe="true"`, Heidenhain
    /// `TCH PROBE 430`): its words and parameters are the probing's.
    pub probe: bool,
    /// Whether the control's manual says the code moves the machine in a way the engine does
    /// not model (`moves="true"`: Heidenhain `M140`, a retract): read with
    /// `interp::motion-unknown`, and a translation refuses rather than drop the motion.
    pub moves: bool,
    /// A spelling some posts write that the control does not take (`rejected="CYCL DEF"`:
    /// Heidenhain `CYCLE DEF`, where Klartext has `CYCL DEF`): the control's own spelling. The
    /// block is read as meant, with an error where it stands (`syntax::rejected-spelling`),
    /// for the control stops there.
    pub rejected: Option<String>,
}

/// What a data-setting code (`G10 L..`) sets, by its L value.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DataForm {
    /// A work offset P to the given values (LinuxCNC and Fanuc L2).
    Wcs,
    /// A work offset P so that the current point has the given coordinates (LinuxCNC L20).
    WcsHere,
    /// An additional work offset P (Fanuc L20, G54.1 Pn).
    WcsExtended,
    /// Tool P's length Z and radius R (LinuxCNC L1).
    Tool,
    /// Tool P's length so that the current point has the given Z (LinuxCNC L10).
    ToolHere,
    /// As `ToolHere`, in the G59.3 fixture system without G92 (LinuxCNC L11).
    ToolHereFixture,
    /// Offset P's length geometry to R (Fanuc L10; memory A L1).
    ToolLength,
    /// Offset P's length wear to R (Fanuc L11).
    ToolLengthWear,
    /// Offset P's radius geometry to R (Fanuc L12).
    ToolRadius,
    /// Offset P's radius wear to R (Fanuc L13).
    ToolRadiusWear,
}

impl DataForm {
    /// The form named `s` in a dialect file.
    pub fn parse(s: &str) -> Option<DataForm> {
        Some(match s {
            "wcs" => DataForm::Wcs,
            "wcs-here" => DataForm::WcsHere,
            "wcs-extended" => DataForm::WcsExtended,
            "tool" => DataForm::Tool,
            "tool-here" => DataForm::ToolHere,
            "tool-here-fixture" => DataForm::ToolHereFixture,
            "tool-length" => DataForm::ToolLength,
            "tool-length-wear" => DataForm::ToolLengthWear,
            "tool-radius" => DataForm::ToolRadius,
            "tool-radius-wear" => DataForm::ToolRadiusWear,
            _ => return None,
        })
    }
}

impl CodeDef {
    /// The role of word `name` in the rest of this code's line (`line-words`).
    pub fn line_word(&self, name: &str) -> Option<Role> {
        self.line_words.iter().find(|(n, _)| n.eq_ignore_ascii_case(name)).map(|&(_, r)| r)
    }

    /// `G81`, `G54.1`, `M30`, or the keyword (`TOOL CALL`).
    pub fn label(&self) -> String {
        if let Some(k) = &self.keyword {
            return k.text.clone();
        }
        if self.number % 10 == 0 {
            format!("{}{}", self.letter, self.number / 10)
        } else {
            format!("{}{}.{}", self.letter, self.number / 10, self.number % 10)
        }
    }
}

/// A modal group.
#[derive(Clone, Debug, PartialEq)]
pub struct ModalGroup {
    /// Identifier, such as `motion`.
    pub id: String,
    /// Whether the group's state persists across blocks.
    pub modal: bool,
    /// When the group's code takes effect within a block.
    pub step: Step,
}

/// A positional argument of a named cycle call (`CYCLE81(RTP, RFP, SDIS, DP, DPR)`).
#[derive(Clone, Debug, PartialEq)]
pub struct CycleArg {
    /// Argument name from the control's manual.
    pub name: String,
    /// Role in the engine.
    pub role: Role,
    /// Whether a value is required.
    pub required: bool,
    /// The parameter the value is read from when the cycle is called (`Q200`), for cycles
    /// defined by parameter assignments rather than positional arguments.
    pub param: Option<u32>,
    /// The sub-block of a legacy cycle that carries this argument as the value after its
    /// name (`CYCL DEF 1.2 DEPTH -15`: sub-block 2), whatever the name's language.
    pub sub: Option<u32>,
}

/// A named cycle with positional parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct CycleDef {
    /// Upper-case name (`CYCLE81`) or number (`200`).
    pub name: String,
    /// Meaning: a hole-making cycle, or a code meaning such as `local-offset` for cycles that act at once.
    pub meaning: Meaning,
    /// Arguments in order; empty slots are allowed in calls.
    pub args: Vec<CycleArg>,
    /// Whether the cycle acts where it is written (`CYCLE81(...)`, `CYCL DEF 7`) rather than when called.
    pub immediate: bool,
    /// Whether, with no reference plane given, the surface lies the safety distance below the
    /// position the cycle starts from (Heidenhain's legacy cycles: `CYCL DEF 1.1 DIST2`).
    pub surface_below_start: bool,
    /// Whether the cycle measures with a touch probe (`probe="true"`, Siemens `CYCLE977`): its
    /// arguments are the probing's.
    pub probe: bool,
}

/// A validated dialect.
#[derive(Clone, Debug)]
pub struct Dialect {
    /// Identifier used in configs and `--dialect`.
    pub name: String,
    /// The controller family (`rs274ngc`, `fanuc`, `haas`, `siemens`, `heidenhain`): the maker
    /// whose controls read the dialect. Informative, and what sniffing is measured by.
    pub family: String,
    /// The dialect this one `extends`, if any: its evidence counts for this one too.
    pub extends: Option<String>,
    /// Human title.
    pub title: String,
    /// Lexical rules.
    pub lexical: Lexical,
    /// Behaviour.
    pub behaviour: Behaviour,
    /// Addresses.
    pub addresses: Vec<AddressDef>,
    /// Macro and control-flow capabilities.
    pub macros: Macros,
    /// Modal groups.
    pub groups: Vec<ModalGroup>,
    /// G and M codes.
    pub codes: Vec<CodeDef>,
    /// Named cycles.
    pub cycles: Vec<CycleDef>,
    /// The record form (APT CLDATA `MAJOR/minor,value`), where programs are records, not words.
    pub records: Option<Box<records::Records>>,
    /// The order in which a block's items take effect.
    pub execution_order: Vec<Step>,
    /// Evidence that a program is written in this dialect (for folders with none configured),
    /// its own; a derived dialect also counts its base's (`Registry::sniff`).
    pub recognise: Vec<sniff::Evidence>,
    /// The labels of inherited evidence this dialect does not count (`<remove label=".."/>` in
    /// `<recognise>`: a lathe does not take a mill's Y words as its own evidence).
    pub recognise_removed: Vec<String>,
    /// The control's documented vocabulary beyond the modelled codes: entries kept as intent
    /// or known unsupported (`<vocabulary>`).
    pub vocabulary: vocabulary::Vocabulary,
    /// How to write programs for this control (`<output>`), where the dictionary says.
    pub output: Option<output::Output>,
    /// Roles of single-character addresses by ASCII code (letters upper case).
    letter_roles: [Option<Role>; 128],
    /// The single-character addresses that are always incremental (a lathe's `U`), as bits
    /// by ASCII code.
    letter_incremental: u128,
    /// The letters whose word followed by a digit is always that address and a number
    /// (`X10.5`): nothing else the dialect reads starts that way.
    plain_roles: [Option<Role>; 128],
    g_table: Vec<u16>,
    m_table: Vec<u16>,
    /// Indices of keyword codes, longest keyword first.
    keyword_codes: Vec<usize>,
    /// The same, by the upper-case first byte of the keyword (ASCII), for the lexer: a word
    /// is tried only against the keywords that can start with its first letter.
    keyword_codes_by_first: Vec<Vec<usize>>,
}

const NO_CODE: u16 = u16::MAX;
const CODE_TABLE_LEN: usize = 10_000;

impl Dialect {
    /// The role of a single-letter address (or a symbol address such as LinuxCNC's polar
    /// `@`), if the dialect defines it.
    #[inline]
    pub fn letter_role(&self, letter: u8) -> Option<Role> {
        self.letter_roles.get(letter.to_ascii_uppercase() as usize).copied().flatten()
    }

    /// Whether the single-character address `letter` is always incremental (a lathe's `U`).
    #[inline]
    pub fn letter_incremental(&self, letter: u8) -> bool {
        let c = letter.to_ascii_uppercase();
        c < 128 && self.letter_incremental & (1 << c) != 0
    }

    /// The index in [`Dialect::codes`] of code `letter` `number×10`, if the dialect defines it.
    #[inline]
    pub fn code_id(&self, letter: char, number_x10: u32) -> Option<usize> {
        let table = match letter {
            'G' => &self.g_table,
            'M' => &self.m_table,
            _ => return None,
        };
        let id = *table.get(number_x10 as usize)?;
        (id != NO_CODE).then_some(id as usize)
    }

    /// The code `letter` `number×10`, if the dialect defines it.
    pub fn code(&self, letter: char, number_x10: u32) -> Option<&CodeDef> {
        self.code_id(letter, number_x10).map(|i| &self.codes[i])
    }

    /// The first code with `meaning`, for messages and defaults.
    pub fn code_for(&self, meaning: Meaning) -> Option<&CodeDef> {
        self.codes.iter().find(|c| c.meaning == meaning)
    }

    /// Multi-letter addresses, longest first.
    pub fn long_addresses(&self) -> impl Iterator<Item = &AddressDef> {
        // `index` sorts the longest names first.
        self.addresses.iter().take_while(|a| a.name.len() > 1)
    }

    /// The role of `letter` when a digit follows it and the word can only be that address
    /// with a literal number (the lexer's fast path); `None` where it needs the full rules.
    #[inline]
    pub fn plain_role(&self, letter: u8) -> Option<Role> {
        self.plain_roles.get(letter.to_ascii_uppercase() as usize).copied().flatten()
    }

    /// Keyword codes, longest keyword first (so that `CYCL CALL PAT` wins over `CYCL CALL`).
    pub fn keyword_codes(&self) -> impl Iterator<Item = (usize, &KeywordSpec)> {
        self.keyword_codes.iter().filter_map(|&i| self.codes[i].keyword.as_ref().map(|k| (i, k)))
    }

    /// The keyword codes that start with `first` (either case), longest first.
    pub fn keyword_codes_starting(&self, first: u8) -> impl Iterator<Item = (usize, &KeywordSpec)> {
        let list = self.keyword_codes_by_first.get(first.to_ascii_uppercase() as usize).map_or(&[][..], Vec::as_slice);
        list.iter().filter_map(|&i| self.codes[i].keyword.as_ref().map(|k| (i, k)))
    }

    /// The named cycle `name` (case-insensitive).
    pub fn cycle(&self, name: &str) -> Option<usize> {
        self.cycles.iter().position(|c| c.name.eq_ignore_ascii_case(name))
    }

    fn index(mut self) -> Dialect {
        for a in &self.addresses {
            if a.name.len() == 1 && !a.assign {
                let c = a.name.as_bytes()[0];
                self.letter_roles[c as usize] = Some(a.role);
                if a.incremental {
                    self.letter_incremental |= 1 << c;
                }
            }
        }
        self.addresses.sort_by(|a, b| b.name.len().cmp(&a.name.len()).then(a.name.cmp(&b.name)));
        let lex = &self.lexical;
        // Labels (`AB1:`) and variables (`XY1=`) can start like a word; so can a parameter
        // (`Q1 = 5`), a longer address (`I1=`) or a keyword (`L`, `R0`). A letter that is
        // always incremental (a lathe's `U`) goes the general way, which marks its words so.
        if lex.label_suffix.is_none() && !lex.identifier_variables {
            for c in b'A'..=b'Z' {
                let ch = Some(c as char);
                let lexer_mark = [lex.continuation, lex.block_end, lex.program_delimiter, lex.block_skip.map(|(k, _)| k)].contains(&ch)
                    || lex.statement_prefix.contains(&c)
                    || lex.comments.iter().any(|r| r.open.eq_ignore_ascii_case(&(c as char)));
                let special = lexer_mark
                    || [lex.control_word, lex.block_number, lex.program_number, lex.program_number_alt].contains(&ch)
                    || lex.parameter.is_some_and(|(s, _)| s.eq_ignore_ascii_case(&(c as char)))
                    || self.addresses.iter().any(|a| a.name.as_bytes()[0] == c && (a.name.len() > 1 || a.incremental))
                    || self.codes.iter().filter_map(|k| k.keyword.as_ref()).any(|k| {
                        let t = k.text.as_bytes();
                        t[0] == c && t.get(1).is_none_or(|&n| n.is_ascii_digit() || n == b'.' || n == b' ')
                    });
                if !special {
                    self.plain_roles[c as usize] = self.letter_roles[c as usize];
                }
            }
        }
        self.g_table = vec![NO_CODE; CODE_TABLE_LEN];
        self.m_table = vec![NO_CODE; CODE_TABLE_LEN];
        self.keyword_codes = (0..self.codes.len()).filter(|&i| self.codes[i].keyword.is_some()).collect();
        self.keyword_codes.sort_by_key(|&i| std::cmp::Reverse(self.codes[i].keyword.as_ref().map_or(0, |k| k.text.len())));
        self.keyword_codes_by_first = vec![Vec::new(); 128];
        for &i in &self.keyword_codes {
            if let Some(&first) = self.codes[i].keyword.as_ref().and_then(|k| k.text.as_bytes().first())
                && let Some(list) = self.keyword_codes_by_first.get_mut(first.to_ascii_uppercase() as usize)
            {
                list.push(i);
            }
        }
        for (i, c) in self.codes.iter().enumerate() {
            if c.keyword.is_some() {
                continue;
            }
            let table = if c.letter == 'G' { &mut self.g_table } else { &mut self.m_table };
            table[c.number as usize] = u16::try_from(i).unwrap_or(NO_CODE);
        }
        self
    }
}

#[cfg(test)]
mod pattern_tests {
    use super::Pattern;

    #[test]
    fn patterns_are_checked_at_once_and_compiled_on_use() {
        assert!(Pattern::new("(unclosed").unwrap_err().contains("unclosed"));
        let p = Pattern::new(r"^G300\s*U").unwrap();
        assert!(p.regex().is_match(b"G300 U0"));
        // ASCII rules: a pattern may match any byte, and Latin-1 letters are not word characters.
        let any = Pattern::new(r"(?m)^[^(;]*\bX\d").unwrap();
        assert!(any.regex().is_match("\u{e9}X1".as_bytes()));
        assert!(!Pattern::new(r"\w").unwrap().regex().is_match("\u{e9}".as_bytes()));
        // The fallback for a pattern that cannot be compiled is itself valid and matches nothing.
        assert!(!regex_automata::meta::Regex::new(r"[^\s\S]").unwrap().is_match("anything"));
    }
}

//! Lexical and syntax analysis: program text → blocks of words, driven by a [`Dialect`].
//!
//! The parser is a streaming cursor: [`Parser::next_block`] refills one reusable [`Block`]
//! per call, so memory does not grow with program length. It never fails; findings go to a
//! diagnostics vector and the block keeps what could be read. A block carries its own text
//! ([`Block::text`]): what reads it needs no more of the program than the block.
//!
//! `Parser::next_block` refills one reusable `Block` per call (words with roles
//! and byte ranges, assignments, comments, an expression arena, and a `Control` statement:
//! `o100 while [..]` or `IF [..] GOTO 10`, and its own text: `Block::text(range)`, so nothing
//! that reads a block needs the program's text). Never fails. A `Text::Read` is lexed in a
//! window that holds the text from the current block on (the `Lexer` indexes the window and
//! adds its base to every range): refilled as the cursor passes its end (4 KiB first,
//! doubling up to the reader's `window`, 256 KiB for a file), and when a block runs to the
//! window's end it is lexed again from a larger window, so a block is always lexed whole;
//! `seek` outside it reads again from the file. `Parser::at` starts at a known block without
//! looking for the tape leader, and `Parser::fork` does so reusing a parser's tables of the
//! dialect's letters (the flow driver's look-aheads, made at every condition on an unknown
//! value, cost little). A block of plain words only
//! (`X1.5 Y-2 Z0.25`, the bulk of a CAM program) is read by one tight loop (`plain_block`);
//! at anything else the general lexer reads the block from its start. Numbers of up to 18
//! digits are one integer mantissa divided by an exact power of ten: the double `str::parse`
//! gives, without building a string; a number that ends within eight bytes (`0.9950`,
//! `222.899`) is read from one 64-bit word (`short_number`: where the digits end, the point
//! taken out, the digits combined pairwise), a longer one byte by byte. Dictionary-controlled lexing: leading
//! block numbers, block-start comments, `~` continuation, labels (`MARKE1:`), strings,
//! `X=expr` with per-word `AC()`/`IC()`, incremental addresses (`IX`), identifier variables and
//! `DEF` declarations, functions with bare operands (`SIN +Q1`), number notations (`10EX3`,
//! `'H1F'`, `'B101'`) and system variable names (`$AC_TIME`, `$A_IN[1]`). A finding's range
//! is widened to whole characters where it is recorded (`Lexer::error`). Where the dictionary
//! says `leader="skipped"`, `Parser::new` starts after the tape leader (`syntax::leader`: the
//! text before the first `%` line that has program text after it, such as an NX listing's
//! header). A `%` line with a name where `header="words"` has the words after the name read
//! (`%123 G71 *`: the units); a G code with `rest="words"` is followed by its display name
//! (`G200 DRILLING`); `levels="true"` on `<block-skip>` takes `/1`–`/9` as skipped blocks.
//! String arguments to cycles and calls (`CYCLE800(1,"TABLE",…)`, `RAPORT("…")`)
//! are text; a cycle argument whose role is `extra` is read but not evaluated; a text value
//! assigned to a variable (`VUACM[1]='END OF BAR'`) is read and not kept; a name that starts
//! with `_` after an address letter (`T_INI`) is one name. Comments nest where the dictionary's `<comment nested="true">` says so; elsewhere a comment ends at its first close, except one that starts with a `simulator` comment directive's prefix (a teaching simulator's `($SetPartSize(42, 12, 2, 1))`, `($Message("…"))`), which runs to its matching close, past quoted text, as the simulator reads it, with `syntax::simulator-directive` (a warning) where a control would read it otherwise.

mod expr;
mod parser;
mod records;

pub use expr::{BinOp, Expr, ExprId, FlatOp, Func};
pub use parser::{Parser, PlainLine, PlainWord, leader};
pub use records::record_program_name;

use crate::dialect::{Role, Statement};
use crate::text::TextRange;

/// The value of a word or assignment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Value {
    /// A literal number; `decimal` tells whether it was written with a decimal point.
    Number {
        /// The value as written.
        value: f64,
        /// Whether a decimal point was present.
        decimal: bool,
    },
    /// An expression in the block's arena.
    Expr(ExprId),
    /// A quoted string (`T="DRILL_8"`); the range covers the text inside the quotes.
    Text(TextRange),
}

/// How a word's axis value is measured.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WordMode {
    /// As G90/G91 say.
    #[default]
    Modal,
    /// Absolute for this word (`X=AC(10)`).
    Absolute,
    /// Incremental for this word (`X=IC(5)`, `IX+5`).
    Incremental,
}

/// An address and its value, such as `X10.5` or `CR=5`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Word {
    /// What the value means to the engine.
    pub role: Role,
    /// Upper-case first letter of the address (for messages and G/M dispatch).
    pub letter: u8,
    /// The value.
    pub value: Value,
    /// Source range of the whole word.
    pub range: TextRange,
    /// Absolute or incremental for this word only.
    pub mode: WordMode,
    /// Whether the word is an argument of the block's named cycle (`CYCLE81(50, 0, 2)`).
    pub cycle_arg: bool,
}

/// The target of a parameter assignment.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ParamTarget {
    /// `#<expr>=`: a numbered parameter whose number is an expression.
    Numbered(ExprId),
    /// `#<name>=`: a named parameter; the range covers the name.
    Named(TextRange),
    /// `VGRIN[6]=`: an element of a named array; the range covers the name.
    NamedIndex(TextRange, ExprId),
}

/// A parameter assignment such as `#1=2.0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Assign {
    /// Target.
    pub target: ParamTarget,
    /// Value expression.
    pub value: ExprId,
    /// Source range.
    pub range: TextRange,
}

/// A control-flow statement: `o100 while [#1 LT 3]`, `IF [#1 GT 0] GOTO 10`, `WHILE [c] DO 1`.
#[derive(Debug, Default, PartialEq)]
pub struct Control {
    /// Source range of the statement.
    pub range: TextRange,
    /// The label after the control word (`100` or `name` in `o<name>`), if any.
    pub label: Option<TextRange>,
    /// A label given by a parameter or expression (`o#<sub> call`), read when the block runs.
    pub label_expr: Option<ExprId>,
    /// The first keyword as written.
    pub keyword: Option<TextRange>,
    /// What the first keyword does; `None` when the dialect does not know it.
    pub statement: Option<Statement>,
    /// Bracketed operands in order: the condition, call arguments or a repeat count.
    pub args: Vec<ExprId>,
    /// A second keyword: `GOTO` or `THEN` after `IF`, `DO` after `WHILE`.
    pub then: Option<Statement>,
    /// A jump target or loop number (`GOTO 10`, `DO 1`, `END 1`), a label number (`LBL 5`),
    /// or the counter of a `FOR`.
    pub target: Option<ExprId>,
    /// A named target: a label (`GOTOF MARK1`, `LBL "NAME"`) or a program (`CALL PGM SUB`,
    /// `DRILLING`); for a string, the range inside the quotes.
    pub name: Option<TextRange>,
    /// The repeat count of a call (`REP 2`, `P3`).
    pub repeat: Option<ExprId>,
    /// The branches of a `CASE` (its operand is the first of `args`), in order.
    pub cases: Vec<CaseBranch>,
    /// The `ELSE` of a one-line `IF`, what runs when its condition is false.
    pub otherwise: Option<Otherwise>,
}

/// The `ELSE` after a one-line `IF`'s THEN clause, on its line (Centroid CNC12, its manual's
/// parametric programming chapter and its own system-test macro: `IF c THEN GOTO 1 ELSE GOTO 2`,
/// `IF [c] THEN #1 = 1 ELSE #2 = 1`, and `.. THEN GOTO 100 ELSE` with nothing after it, as
/// Avid's CNC12 macros write): a jump, statements of its own, or nothing.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Otherwise {
    /// The `ELSE` keyword.
    pub keyword: TextRange,
    /// Its jump (`ELSE GOTO 2`), if it has one.
    pub jump: Option<Statement>,
    /// The jump's numbered target.
    pub target: Option<ExprId>,
    /// The jump's named target.
    pub name: Option<TextRange>,
    /// Where its words start in the block's `words`: those before are the THEN clause's.
    pub words: u32,
    /// Where its assignments start in the block's `assigns`.
    pub assigns: u32,
}

impl Clone for Control {
    fn clone(&self) -> Control {
        let mut c = Control::default();
        c.clone_from(self);
        c
    }

    /// Reuses the statement's buffers, as [`Block`]'s copy does.
    fn clone_from(&mut self, o: &Control) {
        self.range = o.range;
        self.label = o.label;
        self.label_expr = o.label_expr;
        self.keyword = o.keyword;
        self.statement = o.statement;
        self.args.clone_from(&o.args);
        self.then = o.then;
        self.target = o.target;
        self.name = o.name;
        self.repeat = o.repeat;
        self.cases.clone_from(&o.cases);
        self.otherwise = o.otherwise;
    }
}

/// One branch of a `CASE`: a value (none for `DEFAULT`) and the jump it takes.
#[derive(Clone, Debug, PartialEq)]
pub struct CaseBranch {
    /// The constant the operand is compared with; `None` for `DEFAULT`.
    pub value: Option<ExprId>,
    /// The jump: `GOTOF`, `GOTOB`, `GOTO` or `GOTOC`.
    pub jump: Statement,
    /// A named target (`GOTOF MARK1`).
    pub name: Option<TextRange>,
    /// A numbered target (`GOTOF N100` reads as a label; `GOTO 100` as a number).
    pub target: Option<ExprId>,
}

/// One block (line) of a program.
#[derive(Debug, Default)]
pub struct Block {
    /// Source range of the block, without its line terminator.
    pub range: TextRange,
    /// 1-based physical line of the block's start.
    pub line: u32,
    /// Whether the block carries the block-skip character.
    pub skip: bool,
    /// Block number (`N120`, or `17` leading a Heidenhain block).
    pub number: Option<u32>,
    /// A label at block start (`MARKE1:`); the range covers the name.
    pub label: Option<TextRange>,
    /// Physical lines the block runs over after its first (continued with `~`).
    pub extra_lines: u32,
    /// Program number at program start (`O1234`).
    pub program_number: Option<u32>,
    /// Program name at program start, where names are allowed (`OTBOX`); covers the name.
    pub program_name: Option<TextRange>,
    /// Whether the block is a program delimiter line (`%`).
    pub delimiter: bool,
    /// Words in source order.
    pub words: Vec<Word>,
    /// Parameter assignments in source order.
    pub assigns: Vec<Assign>,
    /// Comment texts (inside the delimiters).
    pub comments: Vec<TextRange>,
    /// The spindle its spindle words address by number (Siemens `M2=3`, `S2=2000`, `SPOS[2]=`).
    pub spindle: Option<u8>,
    /// A control-flow statement, if the block holds one.
    pub control: Option<Control>,
    /// Expression arena for this block.
    pub exprs: Vec<Expr>,
    /// Words whose axis a variable names (`AX[_X]=10`): the word's index in `words` and the
    /// expression of the variable, read when the block runs ([`axis_of`]).
    pub axis_refs: Vec<(usize, ExprId)>,
    /// Where the interpreter keeps a block it runs again (a loop's, a subroutine's): the
    /// slots its parameter names were resolved to, by expression and then by assignment
    /// (`u32::MAX` where there is no name; an assignment to an ordinary numbered parameter
    /// written out, its number). Empty as the parser leaves it; the names then
    /// resolve as they are read.
    pub resolved: Vec<u32>,
    /// Where the interpreter keeps a block it runs again: whether the block reads none of the
    /// control's system variables (the position, the tool, the modes), so that its runs need
    /// not bring them up to date first. False as the parser leaves it.
    pub reads_no_system: bool,
    /// Where the interpreter keeps a block it runs again: whether no expression of the block
    /// reads by number a variable the outside writes (the dictionary's `outside-variables`),
    /// so that its conditions' runs need not look for one. False as the parser leaves it.
    pub reads_no_outside: bool,
    /// Where the interpreter keeps a block it runs again: its expressions in postfix order,
    /// names as their slots ([`FlatOp`]); `flat_spans` gives by expression the steps
    /// `start..end` that compute it (an empty span: none). Empty as the parser leaves it.
    pub flat: Vec<FlatOp>,
    /// By expression, the span of [`Block::flat`] that computes it.
    pub flat_spans: Vec<(u32, u32)>,
    /// The text of `range`.
    source: String,
}

impl Clone for Block {
    fn clone(&self) -> Block {
        let mut b = Block::default();
        b.clone_from(self);
        b
    }

    /// Reuses the block's buffers: a block kept for a loop's passes is copied at every pass.
    fn clone_from(&mut self, o: &Block) {
        self.range = o.range;
        self.line = o.line;
        self.skip = o.skip;
        self.number = o.number;
        self.label = o.label;
        self.extra_lines = o.extra_lines;
        self.program_number = o.program_number;
        self.program_name = o.program_name;
        self.delimiter = o.delimiter;
        self.words.clone_from(&o.words);
        self.assigns.clone_from(&o.assigns);
        self.comments.clone_from(&o.comments);
        self.spindle = o.spindle;
        self.control.clone_from(&o.control);
        self.exprs.clone_from(&o.exprs);
        self.axis_refs.clone_from(&o.axis_refs);
        self.resolved.clone_from(&o.resolved);
        self.reads_no_system = o.reads_no_system;
        self.reads_no_outside = o.reads_no_outside;
        self.flat.clone_from(&o.flat);
        self.flat_spans.clone_from(&o.flat_spans);
        self.source.clone_from(&o.source);
    }
}

/// The value an axis variable holds (`DEF AXIS _X=X`): a NaN whose payload names the axis
/// letter, so that it travels through the parameter table as a number does.
pub fn axis_value(letter: u8) -> f64 {
    f64::from_bits(AXIS_BITS | u64::from(letter.to_ascii_uppercase()))
}

/// The axis letter value `v` names, if it is an [`axis_value`].
pub fn axis_of(v: f64) -> Option<u8> {
    let bits = v.to_bits();
    (bits & !0xFF == AXIS_BITS && (bits as u8).is_ascii_uppercase()).then_some(bits as u8)
}

const AXIS_BITS: u64 = 0x7FF8_0000_A715_0000;

impl Block {
    /// The text of `r`, a range within the block (a word's, a comment's, a name's); empty
    /// for a range outside it.
    pub fn text(&self, r: TextRange) -> &str {
        let from = r.start.wrapping_sub(self.range.start) as usize;
        let to = r.end.wrapping_sub(self.range.start) as usize;
        debug_assert!(r.start >= self.range.start && to <= self.source.len(), "{r:?} outside the block {:?}", self.range);
        self.source.get(from..to).unwrap_or("")
    }

    /// The block's text (its range's).
    pub fn source(&self) -> &str {
        &self.source
    }

    /// Sets the text of the block's range.
    fn set_source(&mut self, text: &str) {
        self.source.clear();
        self.source.push_str(text);
    }

    fn clear(&mut self) {
        self.range = TextRange::default();
        self.line = 0;
        self.skip = false;
        self.number = None;
        self.label = None;
        self.extra_lines = 0;
        self.program_number = None;
        self.program_name = None;
        self.delimiter = false;
        self.words.clear();
        self.assigns.clear();
        self.comments.clear();
        self.spindle = None;
        self.control = None;
        self.exprs.clear();
        self.axis_refs.clear();
        self.resolved.clear();
        self.reads_no_system = false;
        self.reads_no_outside = false;
        self.flat.clear();
        self.flat_spans.clear();
    }

    /// True when the block holds nothing to execute.
    pub fn is_empty(&self) -> bool {
        self.words.is_empty() && self.assigns.is_empty() && self.comments.is_empty() && self.control.is_none()
    }
}

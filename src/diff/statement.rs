//! Statements: a program's blocks as the machine reads them, and where two programs differ.
//!
//! Each block is read by the dialect's parser and written in one spelling: no block number,
//! no comments (but the messages a control shows), no blanks except between two words of
//! letters (`FMAX M3`), upper case outside quotes, and numbers without leading or trailing
//! zeros or a plus sign (`X+010.50` is `X10.5`). A dialect whose integers count least
//! increments (`X10` is 0.01 mm) keeps the point of a whole number (`X10.` is not `X10`).
//! What is left after that is a *statement*; two programs differ where their statements do.
//!
//! The statements are aligned by a longest common subsequence where the differing middle is
//! small enough, and by patience anchors (statements that occur once on each side) where it
//! is not, so that the time stays near-linear whatever the edit.

use std::hash::{Hash, Hasher};
use std::ops::Range;

use crate::dialect::{DecimalInput, Dialect, Directive, KeywordRest, Meaning, Role, Statement};
use crate::syntax::{Block, Parser};

/// What a statement does for the machining.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// It moves, sets or decides something.
    Machining,
    /// It only shows or writes text (a message, `DPRNT`) or names the program.
    Output,
}

/// One statement: where it is and a hash of its normalised text.
#[derive(Clone, Copy, Debug)]
pub struct Stmt {
    /// 1-based first line.
    pub line: u32,
    /// 1-based last line (a block continued over lines).
    pub last: u32,
    /// Byte offset of the block in the text.
    pub offset: u32,
    /// Hash of the normalised text.
    pub hash: u64,
    /// What it does.
    pub class: Class,
    /// What its words move: [`RETURN_MOVE`], [`ROTARY_MOVE`]; whether it calls: [`CALL`].
    pub moves: u8,
}

/// A statement with a return-point or machine-coordinate move (`G28`, `G30`, `G53`, `SUPA`).
pub const RETURN_MOVE: u8 = 1;
/// A statement with a word of a rotary axis (`A`, `B`, `C`).
pub const ROTARY_MOVE: u8 = 2;
/// A statement the parser reads as a call of a program or label, wherever in the block it
/// stands (Siemens `R910=25 … L100 P1`, `CALL PGM SUB`, `CALL LBL 5`).
pub const CALL: u8 = 4;

/// What the words of `block` move, by the dictionary's meanings and roles.
fn moves_of(block: &Block, dialect: &Dialect) -> u8 {
    let code_of = |w: &crate::syntax::Word| match (w.role, w.letter, w.value) {
        // A keyword code (Siemens `SUPA`) holds the index of its code.
        (Role::Keyword, _, crate::syntax::Value::Number { value, .. }) => dialect.codes.get(value as usize),
        (_, letter @ (b'G' | b'M'), crate::syntax::Value::Number { value, .. }) => {
            dialect.code(char::from(letter), (value * 10.0).round().max(0.0) as u32)
        }
        _ => None,
    };
    // A macro call's letters are its arguments (`G65 P9810 B2.` sets #2), and a frame's or an
    // origin shift's axis words its values (Siemens `TRANS … B=gB C=gC`, `ROT C45`, `G92 A0`):
    // no axis moves.
    let no_motion = block.words.iter().any(|w| code_of(w).is_some_and(|c| words_are_no_motion(c.meaning)));
    let calls = block
        .control
        .as_ref()
        .is_some_and(|c| matches!(c.statement, Some(Statement::Call | Statement::CallLabel | Statement::CallProgram)));
    let mut m = if calls { CALL } else { 0 };
    // A letter a code of the block gives a role of its own (Haas G76 `A60`: the tool's angle).
    let given = |r: Role| block.words.iter().any(|w| code_of(w).is_some_and(|c| c.args.iter().any(|a| a.0 == r)));
    for w in &block.words {
        if matches!(w.role, Role::A | Role::B | Role::C) && !no_motion && !given(w.role) {
            m |= ROTARY_MOVE;
        }
        if code_of(w).is_some_and(|code| {
            matches!(
                code.meaning,
                Meaning::Home1
                    | Meaning::Home2
                    | Meaning::ReferenceApproach
                    | Meaning::FixedPointApproach
                    | Meaning::MachineCoords
                    | Meaning::MachineBuilderCoords
            )
        }) {
            m |= RETURN_MOVE;
        }
    }
    m
}

/// Whether a code's axis words are its values, not a motion: a macro call's arguments, a
/// frame (translation, rotation, scale, mirror) or an origin shift, data set (`G10`).
pub(super) fn words_are_no_motion(m: Meaning) -> bool {
    use Meaning as M;
    matches!(
        m,
        M::MacroCall
            | M::ModalMacroCall
            | M::FrameTrans
            | M::FrameTransAdd
            | M::FrameRot
            | M::FrameRotAdd
            | M::FrameScale
            | M::FrameScaleAdd
            | M::FrameMirror
            | M::FrameMirrorAdd
            | M::Mirror
            | M::MirrorAboutZero
            | M::MirrorCancel
            | M::OriginShift
            | M::LocalOffset
            | M::Scaling
            | M::Rotation
            | M::SetData
    )
}

/// The statements of `text` in `dialect`, in order. Blocks with nothing the machine reads
/// (blank, comment, block number alone, `%`) are not statements.
pub fn statements(text: &str, dialect: &Dialect) -> Vec<Stmt> {
    read(text, dialect).0
}

/// An error the control stops at: its code, its line and what it says.
#[derive(Clone, Debug, PartialEq)]
pub struct Fault {
    /// The diagnostic's code.
    pub code: crate::diag::Code,
    /// 1-based line.
    pub line: u32,
    /// The diagnostic's sentence.
    pub message: String,
}

/// The statements of `text` in `dialect`, as [`statements`], and the errors reading its
/// blocks finds (a malformed expression, words where a comment ended early).
pub fn read(text: &str, dialect: &Dialect) -> (Vec<Stmt>, Vec<Fault>) {
    let keywords = Keywords::of(dialect);
    let mut parser = Parser::new(text, dialect);
    let mut block = Block::default();
    let mut diags = Vec::new();
    let mut out = Vec::new();
    let mut faults = Vec::new();
    let mut buf = String::new();
    let mut jumps = Jumps::default();
    let mut locals = Locals { on: dialect.lexical.parameter.is_some_and(|(_, named)| named), ..Locals::default() };
    loop {
        let offset = parser.offset();
        if !parser.next_block(&mut block, &mut diags) {
            break;
        }
        for d in diags.drain(..).filter(crate::diag::Diagnostic::is_error) {
            faults.push(Fault { code: d.code, line: block.line, message: d.message });
        }
        buf.clear();
        let mut statement = normalize(&block, dialect, &keywords, &mut buf);
        if statement.is_none() && !out.is_empty() && subprogram_start(&block, &mut buf) {
            statement = Some(Class::Machining);
        }
        fold_constants(&mut buf);
        jumps.block(&block, statement.is_some().then_some(buf.as_str()));
        locals.block(&block, &mut faults);
        let Some(class) = statement else { continue };
        let mut h = std::hash::DefaultHasher::new();
        unlabelled(&block, &buf).hash(&mut h);
        let start = if block.range.start as usize >= offset { block.range.start } else { offset as u32 };
        let moves = moves_of(&block, dialect);
        out.push(Stmt { line: block.line, last: block.line + block.extra_lines, offset: start, hash: h.finish(), class, moves });
    }
    faults.extend(jumps.missing());
    (out, faults)
}

/// Whether `block` is a program number alone, written as its statement (`O9001`) after `buf`.
/// After statements (`O9001` after the main program's `M30`), it starts a subprogram the file
/// holds: the label its calls name, a statement of its own; the file's own number, before
/// anything runs, says nothing the machine does and is none.
fn subprogram_start(block: &Block, buf: &mut String) -> bool {
    let Some(n) = block.program_number.filter(|_| block.words.is_empty() && block.assigns.is_empty()) else { return false };
    use std::fmt::Write as _;
    let _ = write!(buf, "O{n}");
    true
}

/// The start of the sentence of a fault at a jump never taken ([`Jumps`]).
pub(super) const NEVER_TAKEN: &str = "never taken: ";

/// A statement's text as it is compared, whole: an O-word branch's or loop's label left out
/// (`O10IF[#5070NE1]` is `IF[#5070NE1]`). Such a label only ties the statements of one branch
/// or loop together (`o10 if` … `o10 endif`), so a block renumbered in a longer edit (`o10` →
/// `o20` while a new `o10` comes in before it) runs the same; a label that no longer matches
/// its partner stops the control, which the analysis finds. Subprogram labels (`o<name>
/// sub`, `o100 call`) name what runs and stay.
fn unlabelled<'s>(block: &Block, text: &'s str) -> &'s str {
    let structure = block.control.as_ref().is_some_and(|c| {
        matches!(
            c.statement,
            Some(
                Statement::If
                    | Statement::ElseIf
                    | Statement::Else
                    | Statement::EndIf
                    | Statement::While
                    | Statement::EndWhile
                    | Statement::Do
                    | Statement::Repeat
                    | Statement::EndRepeat
                    | Statement::Break
                    | Statement::Continue
            )
        ) && c.label.is_some()
    });
    let Some(rest) = text.strip_prefix('O').filter(|_| structure) else { return text };
    if let Some(named) = rest.strip_prefix('<') {
        return named.find('>').map_or(text, |e| &named[e + 1..]);
    }
    let digits = rest.bytes().take_while(u8::is_ascii_digit).count();
    if digits > 0 { &rest[digits..] } else { text }
}

/// The jumps to a block number (`GOTO 11`, `IF [#101 EQ 11] GOTO 11`) and the block numbers a
/// program has: a jump to a number no block carries stops the control (a sequence-number
/// alarm) whenever it is taken, whatever values the run reads, so it is a fault the reading
/// finds, as a malformed word is. A conditional jump never taken is none: one whose condition
/// is that of a conditional jump just before it (only such jumps between them), which jumped
/// first (`IF[#101 EQ 8] GOTO 8` `IF[#101 EQ 8] GOTO 11`).
#[derive(Default)]
struct Jumps {
    numbers: std::collections::BTreeSet<u32>,
    /// Each jump's target, line and whether it is never taken.
    targets: Vec<(u32, u32, bool)>,
    /// The conditions of the conditional jumps in a row just before this block.
    run: Vec<String>,
}

impl Jumps {
    fn block(&mut self, block: &Block, statement: Option<&str>) {
        if let Some(n) = block.number {
            // A jump may land here: the conditions before it are not all behind the run.
            self.numbers.insert(n);
            self.run.clear();
        }
        let Some(text) = statement else { return };
        let Some(c) = block.control.as_ref() else {
            self.run.clear();
            return;
        };
        let goto = |s: Option<Statement>| matches!(s, Some(Statement::Goto | Statement::GotoForward | Statement::GotoBack));
        let conditional = c.statement == Some(Statement::If) && goto(c.then);
        if c.name.is_some() || !(goto(c.statement) || conditional) || !block.words.is_empty() || !block.assigns.is_empty() {
            self.run.clear();
            return;
        }
        let target = c.target.and_then(|e| match block.exprs.get(e as usize) {
            Some(crate::syntax::Expr::Num(v)) if *v >= 0.0 && v.fract() == 0.0 && *v <= 99_999_999.0 => Some(*v as u32),
            _ => None,
        });
        let upper = text.to_ascii_uppercase();
        let condition = upper.rfind("GOTO").map(|i| upper[..i].to_owned());
        let dead = conditional && condition.as_ref().is_some_and(|k| self.run.contains(k));
        if let Some(n) = target {
            self.targets.push((n, block.line, dead));
        }
        match condition.filter(|_| conditional) {
            Some(k) => self.run.push(k),
            None => self.run.clear(),
        }
    }

    /// The jumps to a number no block of the program carries; one never taken is marked
    /// ([`NEVER_TAKEN`]): it only answers the same jump in the other version, which the edit
    /// made reachable where the run stopped before too (a dispatcher's alarm for that state).
    fn missing(&self) -> Vec<Fault> {
        self.targets
            .iter()
            .filter(|(n, _, _)| !self.numbers.contains(n))
            .map(|&(n, line, dead)| Fault {
                code: crate::diag::Code::MissingLabel,
                line,
                message: format!(
                    "{}the jump to block N{n}, which the program does not have: the control stops here when it jumps",
                    if dead { NEVER_TAKEN } else { "" }
                ),
            })
            .collect()
    }
}

/// The named locals a subroutine reads before any of its blocks sets one (LinuxCNC
/// `o<manual_tool_change> sub` … `o11 if [#<spindle_on> EQ 1]`): a subroutine's named
/// parameters are its own (a name with a leading `_` is global), a caller's do not reach it,
/// and the control stops at a read of one not set (`Named parameter #<spindle_on> not
/// defined`), on every call: only the reads at the body's top level are counted (a branch's
/// or loop's body runs on values, as its condition decides). Read in the text's order (an assignment anywhere before the read
/// counts, a conditional one too), so that a subroutine the file only defines, which a remap
/// or another program calls, is read as the analysis reads one it runs; `EXISTS[#<name>]`
/// reads no value.
#[derive(Default)]
struct Locals {
    /// Whether the dictionary has named parameters.
    on: bool,
    /// Inside a subroutine's body.
    inside: bool,
    /// The labels of the branches and loops open at this block.
    open: Vec<String>,
    set: std::collections::BTreeSet<String>,
}

impl Locals {
    fn block(&mut self, block: &Block, faults: &mut Vec<Fault>) {
        if !self.on {
            return;
        }
        let label = |c: &crate::syntax::Control| c.label.map(|r| block.text(r).to_ascii_lowercase()).unwrap_or_default();
        match block.control.as_ref().map(|c| (c.statement, c)) {
            Some((Some(Statement::Sub), _)) => {
                self.inside = true;
                self.open.clear();
                self.set.clear();
                return;
            }
            // The subroutine's end, not a conditional `endsub` inside one of its branches.
            Some((Some(Statement::EndSub), _)) if self.open.is_empty() => {
                self.inside = false;
                return;
            }
            // A `do` loop's tail (`o101 while [..]` after `o101 do`) closes it.
            Some((Some(Statement::While), c)) if self.open.contains(&label(c)) => {
                let l = label(c);
                self.open.retain(|o| *o != l);
            }
            Some((Some(Statement::If | Statement::While | Statement::Do | Statement::Repeat), c)) => {
                // The statement's own condition is read on every run; its body is not.
                let l = label(c);
                self.reads(block, faults);
                self.open.push(l);
                return;
            }
            Some((Some(Statement::EndIf | Statement::EndWhile | Statement::EndRepeat), c)) => {
                let l = label(c);
                self.open.retain(|o| *o != l);
            }
            _ => {}
        }
        self.reads(block, faults);
    }

    /// The reads of a block of a subroutine's body (at its top level: a branch or loop body
    /// runs on values), and its assignments.
    fn reads(&mut self, block: &Block, faults: &mut Vec<Fault>) {
        if !self.inside {
            return;
        }
        let top = self.open.is_empty();
        let name = |r| block.text(r).chars().filter(|c| !c.is_whitespace()).collect::<String>().to_ascii_lowercase();
        let exists: Vec<u32> = block
            .exprs
            .iter()
            .filter_map(|e| match e {
                crate::syntax::Expr::Unary(crate::syntax::Func::Exists, x) => Some(*x),
                _ => None,
            })
            .collect();
        for (i, e) in block.exprs.iter().enumerate() {
            let crate::syntax::Expr::Named(r) = e else { continue };
            let n = name(*r);
            // A one-letter name is a word of the block that calls a remapped code (LinuxCNC's
            // argspec: `M12 P3` sets `#<p>`), set by the caller.
            if !top || n.len() < 2 || n.starts_with('_') || self.set.contains(&n) || exists.contains(&(i as u32)) {
                continue;
            }
            faults.push(Fault {
                code: crate::diag::Code::UndefinedParameter,
                line: block.line,
                message: format!("parameter `#<{n}>` is used before it is set"),
            });
            // Told once: the control stops at the first.
            self.set.insert(n);
        }
        for a in &block.assigns {
            if let crate::syntax::ParamTarget::Named(r) = a.target {
                self.set.insert(name(r));
            }
        }
    }
}

/// Every block of `text` with its statement's normalised text (`None` for a block that is no
/// statement), in order: for readers of the whole program that need the block too (its
/// number, its program number, its control statement).
pub fn visit(text: &str, dialect: &Dialect, mut f: impl FnMut(&Block, Option<&str>)) {
    let keywords = Keywords::of(dialect);
    let mut parser = Parser::new(text, dialect);
    let mut block = Block::default();
    let mut diags = Vec::new();
    let mut buf = String::new();
    while parser.next_block(&mut block, &mut diags) {
        diags.clear();
        buf.clear();
        if normalize(&block, dialect, &keywords, &mut buf).is_some() {
            fold_constants(&mut buf);
            f(&block, Some(&buf));
        } else {
            f(&block, None);
        }
    }
}

/// The normalised text of the statement at `stmt`, read again from `text`.
pub fn text_of(text: &str, dialect: &Dialect, stmt: &Stmt) -> String {
    let keywords = Keywords::of(dialect);
    let mut parser = Parser::at(text, dialect, stmt.offset as usize, stmt.line);
    let mut block = Block::default();
    let mut diags = Vec::new();
    let mut buf = String::new();
    // The first block at or after the offset that is a statement (the offset is its start).
    while parser.next_block(&mut block, &mut diags) {
        buf.clear();
        if normalize(&block, dialect, &keywords, &mut buf).is_some() || (block.line == stmt.line && subprogram_start(&block, &mut buf)) {
            return buf;
        }
        if parser.line() > stmt.last + 1 {
            break;
        }
    }
    String::new()
}

/// The dialect's keyword codes that decide how a statement counts: those that begin a
/// program (`BEGIN PGM`: its name says nothing the machine does), end one by name (`END
/// PGM`: the name is the program's again), and those that only write text (`FN 15: PRINT`).
struct Keywords {
    header: Vec<String>,
    named_end: Vec<String>,
    output: Vec<String>,
}

impl Keywords {
    fn of(dialect: &Dialect) -> Keywords {
        let mut k = Keywords { header: Vec::new(), named_end: Vec::new(), output: Vec::new() };
        for (i, spec) in dialect.keyword_codes() {
            match (dialect.codes[i].meaning, spec.rest) {
                (Meaning::ProgramBegin, _) => k.header.push(spec.text.clone()),
                (Meaning::SubprogramReturn, KeywordRest::Name) => k.named_end.push(spec.text.clone()),
                (Meaning::Output, _) => k.output.push(spec.text.clone()),
                _ => {}
            }
        }
        k
    }
}

/// Whether `body` (upper case) has the keyword `k` as words of its own.
fn has_keyword(body: &str, k: &str) -> bool {
    body.match_indices(k).any(|(i, _)| {
        let before = body[..i].chars().next_back().is_none_or(|c| !c.is_ascii_alphanumeric());
        let after = body[i + k.len()..].chars().next().is_none_or(|c| !c.is_ascii_alphanumeric() && c != '-');
        before && after
    })
}

/// Writes the normalised text of `block` into `out`; `None` when nothing is left.
fn normalize(block: &Block, dialect: &Dialect, keywords: &Keywords, out: &mut String) -> Option<Class> {
    if block.delimiter && block.words.is_empty() && block.assigns.is_empty() && block.control.is_none() {
        return None;
    }
    let src = block.source();
    let base = block.range.start;
    // The comments' spans, each widened to its delimiters; messages are kept.
    let mut cut: Vec<Range<usize>> = Vec::new();
    let mut messages: Vec<&str> = Vec::new();
    let mut aborts: Vec<&str> = Vec::new();
    for r in &block.comments {
        let (mut s, mut e) = ((r.start - base) as usize, (r.end - base) as usize);
        if s > src.len() || e > src.len() {
            continue;
        }
        let inside = &src[s..e];
        match dialect.lexical.directive(inside) {
            Some((Directive::Message | Directive::Log | Directive::LogFile(_), _)) => messages.push(inside.trim()),
            Some((Directive::Abort, _)) => aborts.push(inside.trim()),
            Some((Directive::Simulator, _)) | None => {}
        }
        if let Some(k) = dialect.lexical.comments.iter().find(|k| s >= k.open_len() && k.opens(&src.as_bytes()[s - k.open_len()..s])) {
            s -= k.open_len();
        } else if s > 0 && src[..s].ends_with(|c: char| dialect.lexical.comments.iter().any(|k| k.open == c)) {
            s -= src[..s].chars().next_back().map_or(0, char::len_utf8);
        }
        if let Some(c) = src[e..].chars().next()
            && dialect.lexical.comments.iter().any(|k| matches!(k.close, crate::dialect::CommentClose::Char(x) if x == c))
        {
            e += c.len_utf8();
        } else if let Some(n) = dialect.lexical.comments.iter().find_map(|k| match k.close {
            crate::dialect::CommentClose::Pair(a, b) if src[e..].starts_with(&format!("{a}{b}")[..]) => Some(2),
            _ => None,
        }) {
            e += n;
        }
        cut.push(s..e);
    }
    cut.sort_by_key(|r| r.start);
    // The text outside comments.
    let mut rest = String::with_capacity(src.len());
    let mut at = 0;
    for r in &cut {
        if r.start >= at {
            rest.push_str(&src[at..r.start]);
            rest.push(' ');
            at = r.end;
        } else {
            at = at.max(r.end);
        }
    }
    rest.push_str(&src[at.min(src.len())..]);
    if let Some(c) = dialect.lexical.continuation.filter(|_| block.extra_lines > 0) {
        rest = rest.replace(c, " ");
    }
    let mut body = rest.trim_start();
    let skip = body.starts_with('/');
    if skip {
        body = body[1..].trim_start();
    }
    if block.number.is_some() {
        let t = body.strip_prefix(['N', 'n']).unwrap_or(body);
        let digits = t.bytes().take_while(u8::is_ascii_digit).count();
        if digits > 0 {
            body = &t[digits..];
        }
    }
    let mut output = false;
    if !keywords.header.is_empty() || !keywords.output.is_empty() || !keywords.named_end.is_empty() {
        let up = body.to_ascii_uppercase();
        if keywords.header.iter().any(|k| has_keyword(&up, k)) {
            return None;
        }
        output = keywords.output.iter().any(|k| has_keyword(&up, k));
        if let Some(k) = keywords.named_end.iter().find(|k| up.trim_start().starts_with(k.as_str())) {
            // `END PGM NAME MM`: the keyword alone.
            out.push_str(k);
            return Some(Class::Machining);
        }
    }
    let keep_point = matches!(dialect.behaviour.decimal_input, DecimalInput::LeastIncrement { .. });
    if skip {
        out.push('/');
    }
    // Blanks inside numbers are read away, except after a legacy cycle's sub-block number.
    let numbers_apart = !dialect.lexical.spaces_in_numbers || block.words.iter().any(|w| legacy_cycle_word(w, dialect));
    canon(body, (keep_point, numbers_apart), out);
    if block.delimiter && out.trim_matches(['%', '/']).is_empty() {
        out.clear();
    }
    // The program's own name or number says nothing the machine does.
    if (block.program_number.is_some() || block.program_name.is_some()) && block.words.is_empty() && block.assigns.is_empty() {
        out.clear();
    }
    if out.is_empty() && messages.is_empty() && aborts.is_empty() {
        return None;
    }
    let prints = block.words.is_empty()
        && block.assigns.is_empty()
        && block.control.as_ref().and_then(|c| c.statement).is_some_and(|s| matches!(s, Statement::Print | Statement::Output));
    let class = if aborts.is_empty() && (out.is_empty() || prints || output) { Class::Output } else { Class::Machining };
    for m in messages.into_iter().chain(aborts) {
        if !out.is_empty() {
            out.push(' ');
        }
        out.push('(');
        out.push_str(&m.split_whitespace().collect::<Vec<_>>().join(" "));
        out.push(')');
    }
    Some(class)
}

/// Whether a word belongs to a cycle definition (`CYCL DEF 9.1 10`), whose sub-block number
/// and value are two numbers, not one with a blank inside.
fn legacy_cycle_word(w: &crate::syntax::Word, dialect: &Dialect) -> bool {
    match (w.role, w.value) {
        (Role::CycleValue | Role::CycleNumber | Role::Cycle, _) => true,
        (Role::Keyword, crate::syntax::Value::Number { value, .. }) => {
            dialect.codes.get(value as usize).is_some_and(|c| c.meaning == Meaning::CycleDefine)
        }
        _ => false,
    }
}

/// Writes `s` in one spelling (see the module's doc) after `out`. `numbers_apart`: a blank
/// between two numbers is kept (`CYCL DEF 9.1 10` is not `9.110`), where the dialect does not
/// read blanks inside numbers. `keep_point`: a whole number's point is kept, where a word
/// without one counts least increments; not inside square brackets, whose expression the
/// control computes in real numbers, each constant with its point or without it the same
/// (`COS[112.5 - 90]` is `COS[112.5 - 90.]`): only a plain number after an address is scaled
/// (the reference's Mitsubishi M700V rule, "when a four rules operator is contained, the data
/// will be handled as that with a decimal point", and the interpreter's reading, which scales
/// no bracketed value).
fn canon(s: &str, (keep_point, numbers_apart): (bool, bool), out: &mut String) {
    let b = s.as_bytes();
    let mut i = 0;
    let mut depth = 0usize;
    let mut quoted = false;
    let mut space = false;
    let ident = |c: Option<char>| c.is_some_and(|c| c.is_alphabetic() || c == '_');
    while i < b.len() {
        let c = b[i];
        if c == b'"' {
            quoted = !quoted;
            out.push('"');
            i += 1;
            continue;
        }
        if quoted || c >= 0x80 {
            let ch = s[i..].chars().next().unwrap_or(' ');
            if !quoted && ch.is_whitespace() {
                space = true;
            } else {
                flush_space(out, &mut space, ch);
                out.push(ch);
            }
            i += ch.len_utf8();
            continue;
        }
        if c.is_ascii_whitespace() {
            space = true;
            i += 1;
            continue;
        }
        let ch = (c as char).to_ascii_uppercase();
        let starts_number = c.is_ascii_digit() || (c == b'.' && b.get(i + 1).is_some_and(u8::is_ascii_digit));
        if numbers_apart && space && starts_number && out.ends_with(|l: char| l.is_ascii_digit() || l == '.') {
            out.push(' ');
        }
        flush_space(out, &mut space, ch);
        if starts_number {
            let mut rev = out.chars().rev();
            let (last, prev) = (rev.next(), rev.next());
            let numeric = match last {
                None => true,
                Some(l) if l.is_ascii_alphabetic() => !ident(prev),
                Some(l) => !(l.is_alphanumeric() || l == '_' || l == '.'),
            };
            let end = i + b[i..].iter().take_while(|x| x.is_ascii_digit() || **x == b'.').count();
            let run = &s[i..end];
            if numeric && run.matches('.').count() <= 1 {
                // A zero's sign after an address says nothing (`J-0.000` is `J0`).
                if last == Some('-') && prev.is_some_and(|p| p.is_ascii_alphabetic()) && run.bytes().all(|x| x == b'0' || x == b'.') {
                    out.pop();
                }
                number(run, keep_point && depth == 0, out);
            } else {
                out.push_str(run);
            }
            i = end;
            continue;
        }
        // A plus sign before a number after an address says nothing.
        // (Past blanks, where the dialect reads blanks inside numbers: `X + 0`.)
        let next = if numbers_apart { b.get(i + 1) } else { b[i + 1..].iter().find(|n| !n.is_ascii_whitespace()) };
        if c == b'+'
            && next.is_some_and(|n| n.is_ascii_digit() || *n == b'.')
            && out.ends_with(|l: char| l.is_ascii_alphabetic() || l == '=')
        {
            i += 1;
            continue;
        }
        match c {
            b'[' => depth += 1,
            b']' => depth = depth.saturating_sub(1),
            _ => {}
        }
        out.push(ch);
        i += 1;
    }
}

/// A blank between two words of letters is kept (`FMAX M3`); any other is not.
fn flush_space(out: &mut String, space: &mut bool, next: char) {
    if std::mem::take(space) && (next.is_alphabetic() || next == '_') && out.ends_with(|c: char| c.is_alphabetic() || c == '_') {
        out.push(' ');
    }
}

/// A number run (`010.500`) in one spelling (`10.5`); a whole number keeps its point where
/// `keep_point` (`10.` and `10.000` are `10.`, `10` is `10`).
fn number(run: &str, keep_point: bool, out: &mut String) {
    let (int, frac) = match run.split_once('.') {
        Some((i, f)) => (i, Some(f)),
        None => (run, None),
    };
    let int = int.trim_start_matches('0');
    let frac = frac.map(|f| f.trim_end_matches('0'));
    out.push_str(if int.is_empty() { "0" } else { int });
    match frac {
        Some(f) if !f.is_empty() => {
            out.push('.');
            out.push_str(f);
        }
        // Zero is zero whichever way it counts.
        Some(_) if keep_point && !int.is_empty() => out.push('.'),
        _ => {}
    }
}

/// The value of a constant expression (`572.86/2`, `[2*3]`, `-(1+2)`): numbers, `+ - * /`
/// and brackets only; `None` for anything else (a variable, a function, a plain number).
pub fn constant(s: &str) -> Option<f64> {
    let b = s.as_bytes();
    if s.parse::<f64>().is_ok() || !b.iter().skip(1).any(|c| matches!(c, b'+' | b'-' | b'*' | b'/' | b'[' | b'(')) {
        return None;
    }
    if !b.iter().all(|c| c.is_ascii_digit() || b".+-*/[]() ".contains(c)) {
        return None;
    }
    let mut at = 0;
    let v = sum(b, &mut at)?;
    (at == b.len() && v.is_finite()).then_some(v)
}

fn sum(b: &[u8], at: &mut usize) -> Option<f64> {
    let mut v = product(b, at)?;
    while let Some(&op @ (b'+' | b'-')) = b.get(*at) {
        *at += 1;
        let r = product(b, at)?;
        v = if op == b'+' { v + r } else { v - r };
    }
    Some(v)
}

fn product(b: &[u8], at: &mut usize) -> Option<f64> {
    let mut v = factor(b, at)?;
    while let Some(&op @ (b'*' | b'/')) = b.get(*at) {
        *at += 1;
        let r = factor(b, at)?;
        v = if op == b'*' { v * r } else { v / r };
    }
    Some(v)
}

fn factor(b: &[u8], at: &mut usize) -> Option<f64> {
    match b.get(*at)? {
        b'-' | b'+' => {
            let neg = b[*at] == b'-';
            *at += 1;
            factor(b, at).map(|v| if neg { -v } else { v })
        }
        open @ (b'[' | b'(') => {
            let close = if *open == b'[' { b']' } else { b')' };
            *at += 1;
            let v = sum(b, at)?;
            (b.get(*at) == Some(&close)).then(|| *at += 1)?;
            Some(v)
        }
        _ => {
            let n = b[*at..].iter().take_while(|c| c.is_ascii_digit() || **c == b'.').count();
            let v = std::str::from_utf8(&b[*at..*at + n]).ok()?.parse().ok()?;
            *at += n;
            Some(v)
        }
    }
}

/// A constant's value written as a number, to nine decimals.
pub fn constant_text(v: f64) -> String {
    let s = format!("{v:.9}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

/// Constant expressions of a normalised statement written as their values, so that a value
/// rewritten as an expression of the same value (`WR=286.43`, `WR=572.86/2`) is the same
/// statement, and one variable in brackets as the variable (`X[#<X_START>]`, `X#<X_START>`).
/// Only for comparing: the statements' text is read again as written.
fn fold_constants(s: &mut String) {
    if !s.bytes().any(|c| matches!(c, b'*' | b'/' | b'[' | b'(' | b'+')) {
        return;
    }
    let mut out = String::with_capacity(s.len());
    let mut rest = s.as_str();
    for t in tokens(s) {
        let Some(i) = rest.find(&t.text) else { continue };
        out.push_str(&rest[..i]);
        let word = matches!(t.sort, Sort::Word | Sort::Assign);
        match (constant(&t.value).filter(|_| word), unbracketed(&t.value).filter(|_| word)) {
            (Some(v), _) => {
                out.push_str(&t.text[..t.text.len() - t.value.len()]);
                out.push_str(&constant_text(v));
            }
            (None, Some((sign, inner))) => {
                out.push_str(&t.text[..t.text.len() - t.value.len()]);
                out.push_str(sign);
                out.push_str(inner);
            }
            (None, None) => out.push_str(&t.text),
        }
        rest = &rest[i + t.text.len()..];
    }
    out.push_str(rest);
    *s = out;
}

/// A value that is one variable in brackets (`X[#<X_START>]`, `X-[#5]`, `X=(R1)`): its sign
/// and the variable alone, the same value as written without the brackets (`X#<X_START>`).
fn unbracketed(value: &str) -> Option<(&str, &str)> {
    let (sign, rest) = match value.as_bytes().first()? {
        b'-' | b'+' => value.split_at(1),
        _ => ("", value),
    };
    let close = match rest.as_bytes().first()? {
        b'[' => ']',
        b'(' => ')',
        _ => return None,
    };
    let inner = rest[1..].strip_suffix(close)?;
    let name = match inner.as_bytes() {
        [b'#', b'<', .., b'>'] => inner[2..inner.len() - 1].bytes().all(|c| c.is_ascii_alphanumeric() || c == b'_'),
        [b'#' | b'R' | b'Q', digits @ ..] => !digits.is_empty() && digits.iter().all(u8::is_ascii_digit),
        _ => false,
    };
    name.then_some((sign, inner))
}

/// A run of differing statements: indices into each side's statements.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Hunk {
    /// In the original.
    pub original: Range<usize>,
    /// In the edited program.
    pub edited: Range<usize>,
}

/// The largest differing middle (product of both counts) aligned by a full longest common
/// subsequence; larger ones are cut at patience anchors first.
const LCS_CELLS: usize = 1 << 22;

/// The runs of statements that differ between `a` and `b`, in order.
pub fn hunks(a: &[Stmt], b: &[Stmt]) -> Vec<Hunk> {
    hunks_in(a, b, None)
}

/// The runs of statements that differ between `a` and `b`, the statements of `texts` (the two
/// programs' texts, where known): where a statement could pair with more than one equal
/// statement (an `M0` commented out among three), it pairs as the lines of the texts pair in
/// git's diff, so that a row names the lines the edit's author sees changed.
pub fn hunks_in(a: &[Stmt], b: &[Stmt], texts: Option<(&str, &str)>) -> Vec<Hunk> {
    let (ha, hb): (Vec<u64>, Vec<u64>) = (a.iter().map(|s| s.hash).collect(), b.iter().map(|s| s.hash).collect());
    let plain = compact(&ha, &hb, &matches(&ha, &hb));
    // The pairing along the lines only where it pairs as many statements: where respelled
    // lines leave few equal, git's pairing of those few may cross the statements' own.
    let pairs = match texts.map(|t| along_lines(a, b, (&ha, &hb), t)) {
        Some(along) if along.len() >= plain.len() => along,
        _ => plain,
    };
    let mut out = Vec::new();
    let (mut i, mut j) = (0, 0);
    for &(x, y) in pairs.iter().chain(std::iter::once(&(a.len(), b.len()))) {
        if x > i || y > j {
            out.push(Hunk { original: i..x, edited: j..y });
        }
        (i, j) = (x + 1, y + 1);
    }
    out
}

/// The matched pairs of `a` and `b` with each run of differing items slid as git's diff
/// slides it (`xdl_change_compact` in git's `xdiff/xdiffi.c`; the same compaction GNU diff
/// does): among the placements of a run that are equally short edits (a run of removed
/// statements beside an identical statement can stand one earlier or one later), the run is
/// moved up to merge with the run before it where it can, then down as far as it goes, and
/// back up to line up with a run of the other side where one lies in its reach. The rows then
/// name the lines the edit's author (and `git diff`) sees as changed, and a run split by a
/// repeated statement (`G0 X0.2` before and after a removed section) is one run.
pub(super) fn compact(a: &[u64], b: &[u64], pairs: &[(usize, usize)]) -> Vec<(usize, usize)> {
    let (mut ca, mut cb) = (vec![true; a.len()], vec![true; b.len()]);
    for &(x, y) in pairs {
        ca[x] = false;
        cb[y] = false;
    }
    slide(a, &mut ca, &cb);
    slide(b, &mut cb, &ca);
    let kept = |c: &[bool]| c.iter().enumerate().filter(|(_, c)| !**c).map(|(i, _)| i).collect::<Vec<_>>();
    let (ka, kb) = (kept(&ca), kept(&cb));
    // The compaction keeps each side's count of unchanged items; they pair in order.
    if ka.len() != kb.len() {
        return pairs.to_vec();
    }
    ka.into_iter().zip(kb).collect()
}

/// The hash of each line of `text` (a line's end `\r` left out), exactly as written.
pub(super) fn line_hashes(text: &str) -> Vec<u64> {
    text.split('\n')
        .map(|l| {
            let mut h = std::hash::DefaultHasher::new();
            l.strip_suffix('\r').unwrap_or(l).hash(&mut h);
            h.finish()
        })
        .collect()
}

/// The matched statements of `a` and `b`: first the statements on lines that git's diff of
/// the two texts keeps (a line the same, its statement the same), then between two of those
/// the rest by their longest common subsequence, slid as git slides a run ([`compact`]).
fn along_lines(a: &[Stmt], b: &[Stmt], (ha, hb): (&[u64], &[u64]), (ta, tb): (&str, &str)) -> Vec<(usize, usize)> {
    let (la, lb) = (line_hashes(ta), line_hashes(tb));
    let kept = compact(&la, &lb, &matches(&la, &lb));
    // The statements on each line (1-based lines), those on one line alone.
    let on_lines = |s: &[Stmt], lines: usize| {
        let mut on: Vec<Option<Range<usize>>> = vec![None; lines + 1];
        let mut k = 0;
        while k < s.len() {
            let mut e = k + 1;
            while e < s.len() && s[e].line == s[k].line {
                e += 1;
            }
            let line = s[k].line as usize;
            if s[k..e].iter().all(|t| t.last == t.line) && line < on.len() {
                on[line] = Some(k..e);
            }
            k = e;
        }
        on
    };
    let (oa, ob) = (on_lines(a, la.len()), on_lines(b, lb.len()));
    let mut anchors: Vec<(usize, usize)> = Vec::new();
    for (x, y) in kept {
        let (Some(Some(ra)), Some(Some(rb))) = (oa.get(x + 1), ob.get(y + 1)) else { continue };
        if ra.len() != rb.len() || ra.clone().zip(rb.clone()).any(|(i, j)| ha[i] != hb[j]) {
            continue;
        }
        if anchors.last().is_some_and(|&(i, j)| i >= ra.start || j >= rb.start) {
            continue;
        }
        anchors.extend(ra.clone().zip(rb.clone()));
    }
    let mut out = Vec::new();
    let (mut pa, mut pb) = (0, 0);
    for (x, y) in anchors.into_iter().chain(std::iter::once((a.len(), b.len()))) {
        let (sa, sb) = (&ha[pa..x], &hb[pb..y]);
        out.extend(compact(sa, sb, &matches(sa, sb)).into_iter().map(|(i, j)| (pa + i, pb + j)));
        if x < a.len() && y < b.len() {
            out.push((x, y));
        }
        (pa, pb) = (x + 1, y + 1);
    }
    out
}

/// A run of changed items `start..end` of one side (empty where the run is between two
/// unchanged items).
#[derive(Clone, Copy)]
struct Group {
    start: usize,
    end: usize,
}

impl Group {
    fn first(changed: &[bool]) -> Group {
        let end = changed.iter().position(|&c| !c).unwrap_or(changed.len());
        Group { start: 0, end }
    }

    /// The next group, after the unchanged item at `end`; `false` at the end.
    fn next(&mut self, changed: &[bool]) -> bool {
        if self.end >= changed.len() {
            return false;
        }
        self.start = self.end + 1;
        self.end = self.start;
        while self.end < changed.len() && changed[self.end] {
            self.end += 1;
        }
        true
    }

    /// The group before, before the unchanged item at `start - 1`; `false` at the start.
    fn previous(&mut self, changed: &[bool]) -> bool {
        if self.start == 0 {
            return false;
        }
        self.end = self.start - 1;
        self.start = self.end;
        while self.start > 0 && changed[self.start - 1] {
            self.start -= 1;
        }
        true
    }

    /// One item down where the first item of the group equals the one after it (merging
    /// with the group after).
    fn down(&mut self, items: &[u64], changed: &mut [bool]) -> bool {
        if self.end >= items.len() || items[self.start] != items[self.end] {
            return false;
        }
        changed[self.start] = false;
        changed[self.end] = true;
        self.start += 1;
        self.end += 1;
        while self.end < items.len() && changed[self.end] {
            self.end += 1;
        }
        true
    }

    /// One item up where the last item of the group equals the one before it (merging with
    /// the group before).
    fn up(&mut self, items: &[u64], changed: &mut [bool]) -> bool {
        if self.start == 0 || items[self.start - 1] != items[self.end - 1] {
            return false;
        }
        self.start -= 1;
        self.end -= 1;
        changed[self.start] = true;
        changed[self.end] = false;
        while self.start > 0 && changed[self.start - 1] {
            self.start -= 1;
        }
        true
    }
}

/// Slides the changed runs of `items` (`changed`), with `other` the other side's changes.
fn slide(items: &[u64], changed: &mut [bool], other: &[bool]) {
    let (mut g, mut go) = (Group::first(changed), Group::first(other));
    loop {
        if g.end > g.start {
            let (mut earliest_end, mut matching);
            loop {
                let size = g.end - g.start;
                matching = None;
                while g.up(items, changed) {
                    go.previous(other);
                }
                earliest_end = g.end;
                if go.end > go.start {
                    matching = Some(g.end);
                }
                while g.down(items, changed) {
                    go.next(other);
                    if go.end > go.start {
                        matching = Some(g.end);
                    }
                }
                if size == g.end - g.start {
                    break;
                }
            }
            // Back to the last place it lines up with a run of the other side.
            if g.end != earliest_end && matching.is_some() {
                while go.end == go.start && g.up(items, changed) {
                    go.previous(other);
                }
            }
        }
        if !g.next(changed) || !go.next(other) {
            break;
        }
    }
}

/// Matched index pairs of equal items, increasing on both sides.
pub(super) fn matches(a: &[u64], b: &[u64]) -> Vec<(usize, usize)> {
    let mut out = Vec::new();
    // Work: (range of a, range of b), taken in order.
    let mut work = vec![(0..a.len(), 0..b.len())];
    let mut found: Vec<(usize, usize)> = Vec::new();
    while let Some((ra, rb)) = work.pop() {
        let (mut ra, mut rb) = (ra, rb);
        while !ra.is_empty() && !rb.is_empty() && a[ra.start] == b[rb.start] {
            found.push((ra.start, rb.start));
            ra.start += 1;
            rb.start += 1;
        }
        while !ra.is_empty() && !rb.is_empty() && a[ra.end - 1] == b[rb.end - 1] {
            found.push((ra.end - 1, rb.end - 1));
            ra.end -= 1;
            rb.end -= 1;
        }
        if ra.is_empty() || rb.is_empty() {
            continue;
        }
        if ra.len().saturating_mul(rb.len()) <= LCS_CELLS {
            lcs(&a[ra.clone()], &b[rb.clone()], ra.start, rb.start, &mut found);
            continue;
        }
        let anchors = patience(&a[ra.clone()], &b[rb.clone()]);
        if anchors.is_empty() {
            // Nothing occurs once on each side: the middle is taken as replaced.
            continue;
        }
        let (mut pa, mut pb) = (ra.start, rb.start);
        for (x, y) in anchors {
            let (x, y) = (ra.start + x, rb.start + y);
            found.push((x, y));
            work.push((pa..x, pb..y));
            (pa, pb) = (x + 1, y + 1);
        }
        work.push((pa..ra.end, pb..rb.end));
    }
    found.sort_unstable();
    out.extend(found);
    out
}

/// A longest common subsequence of `a` and `b` by the full table, pairs offset by `oa`/`ob`.
/// Two sequences of `len_a` and `len_b` items paired along the `anchors` of their longest
/// common subsequence: each anchor paired, and between two anchors the items paired by
/// position, the longer side's rest alone (`None` on the other side).
pub(super) fn pairs_along(anchors: Vec<(usize, usize)>, len_a: usize, len_b: usize) -> Vec<(Option<usize>, Option<usize>)> {
    let mut out = Vec::new();
    let (mut pi, mut pj) = (0, 0);
    for (x, y) in anchors.into_iter().chain(std::iter::once((len_a, len_b))) {
        let (n, m) = (x - pi, y - pj);
        for k in 0..n.max(m) {
            out.push(((k < n).then_some(pi + k), (k < m).then_some(pj + k)));
        }
        if x < len_a && y < len_b {
            out.push((Some(x), Some(y)));
        }
        (pi, pj) = (x + 1, y + 1);
    }
    out
}

pub(super) fn lcs<T: PartialEq>(a: &[T], b: &[T], oa: usize, ob: usize, out: &mut Vec<(usize, usize)>) {
    let w = b.len() + 1;
    let mut t = vec![0u32; (a.len() + 1) * w];
    for i in (0..a.len()).rev() {
        for j in (0..b.len()).rev() {
            t[i * w + j] = if a[i] == b[j] { t[(i + 1) * w + j + 1] + 1 } else { t[(i + 1) * w + j].max(t[i * w + j + 1]) };
        }
    }
    let (mut i, mut j) = (0, 0);
    while i < a.len() && j < b.len() {
        if a[i] == b[j] {
            out.push((oa + i, ob + j));
            i += 1;
            j += 1;
        } else if t[(i + 1) * w + j] >= t[i * w + j + 1] {
            i += 1;
        } else {
            j += 1;
        }
    }
}

/// The items that occur exactly once in each of `a` and `b`, as index pairs in a longest
/// increasing run (patience sorting).
fn patience(a: &[u64], b: &[u64]) -> Vec<(usize, usize)> {
    let once = |v: &[u64]| -> Vec<(u64, usize)> {
        let mut s: Vec<(u64, usize)> = v.iter().copied().zip(0..).collect();
        s.sort_unstable();
        let mut out = Vec::new();
        let mut k = 0;
        while k < s.len() {
            let mut e = k + 1;
            while e < s.len() && s[e].0 == s[k].0 {
                e += 1;
            }
            if e == k + 1 {
                out.push(s[k]);
            }
            k = e;
        }
        out
    };
    let (ua, ub) = (once(a), once(b));
    // Pairs by hash, in the order of `a`.
    let mut pairs: Vec<(usize, usize)> = Vec::new();
    let mut k = 0;
    for &(h, i) in &ua {
        while k < ub.len() && ub[k].0 < h {
            k += 1;
        }
        if k < ub.len() && ub[k].0 == h {
            pairs.push((i, ub[k].1));
        }
    }
    pairs.sort_unstable();
    // Longest increasing run of the `b` indices.
    let mut tails: Vec<usize> = Vec::new();
    let mut back: Vec<Option<usize>> = vec![None; pairs.len()];
    for (n, &(_, y)) in pairs.iter().enumerate() {
        let pos = tails.partition_point(|&t| pairs[t].1 < y);
        back[n] = pos.checked_sub(1).map(|p| tails[p]);
        if pos == tails.len() {
            tails.push(n);
        } else {
            tails[pos] = n;
        }
    }
    let mut out = Vec::new();
    let mut cur = tails.last().copied();
    while let Some(n) = cur {
        out.push(pairs[n]);
        cur = back[n];
    }
    out.reverse();
    out
}

/// One piece of a statement: an address and its value (`X10`), an assignment
/// (`#<_Z>=1`), a call with its arguments (`_DRESSING(22,20)`), a keyword.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Token {
    /// What it sets or names: the address (`X`), the code (`G1`, `M5`), the variable, the
    /// call's name.
    pub key: String,
    /// Its value as written after the key.
    pub value: String,
    /// The token's whole text.
    pub text: String,
    /// What sort of token.
    pub sort: Sort,
}

/// What sort of token.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Sort {
    /// An address and a value, or a code.
    Word,
    /// A variable set to a value.
    Assign,
    /// A call or cycle with arguments.
    Call,
    /// Anything else: keywords, labels, jumps.
    Other,
}

/// The tokens of a normalised statement.
pub fn tokens(s: &str) -> Vec<Token> {
    split(s, None, &[])
}

/// The tokens of a statement's text as [`tokens`], by the dictionary's lexical forms: a number
/// with its decimal exponent is one word (Siemens `1EX300`, not `1` and `EX300`), and a statement
/// keyword written against what follows it is a token of its own (Fanuc `IF[#1EQ0]THEN#20=0`:
/// `THEN`, then the assignment of `#20`, not a variable named `THEN#20`).
pub fn tokens_in(s: &str, d: &Dialect) -> Vec<Token> {
    let keywords: Vec<&str> = d.macros.statements.iter().map(|(k, _)| k.as_str()).filter(|k| !k.is_empty()).collect();
    let pieces = split(s, d.lexical.numbers.exponent.as_deref(), &keywords);
    let Some(prefix) = d.lexical.system_variable_prefix.and_then(|c| u8::try_from(c).ok()) else { return pieces };
    // A statement keyword written against a system variable (Siemens `IF$A_DBB[15]==0`, the
    // blank between them gone with the spelling): the keyword, then the condition.
    let mut out = Vec::with_capacity(pieces.len());
    for t in pieces {
        let b = t.text.as_bytes();
        let k = keywords
            .iter()
            .map(|k| k.as_bytes())
            .filter(|k| b.len() > k.len() && b[..k.len()].eq_ignore_ascii_case(k) && b[k.len()] == prefix)
            .map(<[u8]>::len)
            .max()
            .unwrap_or(0);
        if k > 0 {
            out.push(token(&t.text[..k]));
            out.push(token(&t.text[k..]));
        } else {
            out.push(t);
        }
    }
    out
}

/// Whether the text at `i` is the exponent letters after a number's digits (`EX3`, `EX-3`).
fn exponent_at(b: &[u8], i: usize, exponent: Option<&str>) -> bool {
    let Some(e) = exponent.filter(|e| !e.is_empty()) else { return false };
    let e = e.as_bytes();
    let after = i + e.len();
    i > 0
        && (b[i - 1].is_ascii_digit() || b[i - 1] == b'.')
        && b.len() > after
        && b[i..after].eq_ignore_ascii_case(e)
        && (b[after].is_ascii_digit() || (matches!(b[after], b'-' | b'+') && b.get(after + 1).is_some_and(u8::is_ascii_digit)))
}

/// The length of the statement keyword at `i` written against a parameter (`THEN#20`), or 0.
fn keyword_at(b: &[u8], i: usize, keywords: &[&str]) -> usize {
    keywords
        .iter()
        .map(|k| k.as_bytes())
        .filter(|k| b.len() > i + k.len() && b[i..i + k.len()].eq_ignore_ascii_case(k) && b[i + k.len()] == b'#')
        .map(<[u8]>::len)
        .max()
        .unwrap_or(0)
}

fn split(s: &str, exponent: Option<&str>, keywords: &[&str]) -> Vec<Token> {
    let b = s.as_bytes();
    let mut pieces: Vec<&str> = Vec::new();
    let mut start = 0;
    let mut depth = 0i32;
    // Inside parentheses (a comment, a message, an argument list) `<` and `>` are text or
    // comparisons, not a named parameter's brackets: `(ABORT, … must be >= 0)` stays one piece.
    let mut parens = 0i32;
    let mut quoted = false;
    for (i, &c) in b.iter().enumerate() {
        match c {
            b'"' => {
                quoted = !quoted;
                // A word after a closing quote: `T="EM10"D2`.
                if !quoted && b.get(i + 1).is_some_and(u8::is_ascii_alphabetic) && depth <= 0 {
                    pieces.push(&s[start..=i]);
                    start = i + 1;
                }
            }
            _ if quoted => {}
            b'(' => (depth, parens) = (depth + 1, parens + 1),
            b')' => (depth, parens) = (depth - 1, parens - 1),
            b'<' | b'>' if parens > 0 => {}
            b'[' | b'<' => depth += 1,
            b']' | b'>' => depth -= 1,
            b' ' if depth <= 0 => {
                if i > start {
                    pieces.push(&s[start..i]);
                }
                start = i + 1;
            }
            _ if depth <= 0 && c.is_ascii_alphabetic() && i > start => {
                let p = b[i - 1];
                // `O100WHILE[…]`, `O200CALL[…]`: an O-word and its keyword are one statement.
                // `T#<TOOL>M6`: a word after a named parameter, but not `O<NAME>CALL`.
                let o_word = b[start] == b'O' && (b[start + 1..i].iter().all(u8::is_ascii_digit) || b.get(start + 1) == Some(&b'<'));
                if !o_word && (p.is_ascii_digit() || matches!(p, b']' | b')' | b'.' | b'"' | b'>')) && !exponent_at(b, i, exponent) {
                    pieces.push(&s[start..i]);
                    start = i;
                    let k = keyword_at(b, i, keywords);
                    if k > 0 {
                        pieces.push(&s[i..i + k]);
                        start = i + k;
                    }
                }
            }
            _ => {}
        }
    }
    if start < s.len() {
        pieces.push(&s[start..]);
    }
    pieces.into_iter().map(token).collect()
}

fn token(t: &str) -> Token {
    let text = t.to_owned();
    // An assignment: `LHS=RHS` at depth 0; inside parentheses `<` and `>` are no brackets.
    let (mut depth, mut parens) = (0i32, 0i32);
    for (i, c) in t.char_indices() {
        match c {
            '(' => (depth, parens) = (depth + 1, parens + 1),
            ')' => (depth, parens) = (depth - 1, parens - 1),
            '<' | '>' if parens > 0 => {}
            '[' | '<' => depth += 1,
            ']' | '>' => depth -= 1,
            // (`==` compares: neither of its signs assigns, `IF INI[109]==0`.)
            '=' if depth == 0 && i > 0 && !t[i + 1..].starts_with('=') && !t[..i].ends_with(['=', '!']) => {
                // A parameter function's label before the parameter it sets (Heidenhain
                // `FN 0: Q1 = +5`, `FN 1: Q3 = +Q1 + +Q2`): the parameter is the one set, as in
                // `Q1 = +5`.
                let lhs = &t[..i];
                let key = match lhs.rsplit_once(':') {
                    Some((label, name)) if !label.is_empty() && !name.is_empty() && label.bytes().all(|b| b.is_ascii_alphanumeric()) => {
                        name
                    }
                    _ => lhs,
                };
                return Token { key: key.to_owned(), value: t[i + 1..].to_owned(), text, sort: Sort::Assign };
            }
            _ => {}
        }
    }
    // A call: a name then a bracketed or parenthesised list.
    // (An address letter, signed or not, before a bracketed expression is a word:
    // `F[#<FAST>]`, `Z[#7]`, `X-[#5]`.)
    let address = |h: &str| matches!(h.as_bytes(), [a] | [a, b'-' | b'+'] if a.is_ascii_alphabetic());
    if let Some(open) = t.find(['(', '['])
        && open > 0
        && t.ends_with([')', ']'])
        && t[..open].chars().any(|c| c.is_ascii_alphabetic())
        && !address(&t[..open])
    {
        // `O<NAME>CALL[…]`: the name without its keyword.
        let head = &t[..open];
        let name = head.strip_suffix("CALL").filter(|h| h.ends_with('>') || h.ends_with(|c: char| c.is_ascii_digit())).unwrap_or(head);
        return Token { key: name.to_owned(), value: t[open..].to_owned(), text, sort: Sort::Call };
    }
    let letters = t.bytes().take_while(u8::is_ascii_alphabetic).count();
    let rest = &t[letters..];
    if letters >= 1 && !rest.is_empty() && rest.bytes().all(|c| c.is_ascii_digit() || matches!(c, b'.' | b'-' | b'#' | b'<' | b'>' | b'_'))
        || letters >= 1 && rest.starts_with(['[', '#', '-', '+'])
    {
        let key = &t[..letters];
        if (key == "G" || key == "M") && rest.bytes().all(|c| c.is_ascii_digit() || c == b'.') {
            return Token { key: t.to_owned(), value: String::new(), text, sort: Sort::Word };
        }
        return Token { key: key.to_owned(), value: rest.to_owned(), text, sort: Sort::Word };
    }
    Token { key: t.to_owned(), value: String::new(), text, sort: Sort::Other }
}

impl Token {
    /// Whether the token sets an address (`X10`, `M5`) or a value written as an address with
    /// `=` (`T="EM10"`, `CR=5`), not a variable.
    pub fn is_address(&self) -> bool {
        match self.sort {
            Sort::Word | Sort::Other => true,
            Sort::Assign => self.key.len() <= 3 && self.key.bytes().all(|c| c.is_ascii_alphabetic()),
            Sort::Call => false,
        }
    }
}

/// The arguments of a call's value (`(22,20,,2)` or `[0.75][1]`), as written.
pub fn arguments(value: &str) -> Vec<String> {
    let mut out = Vec::new();
    if value.starts_with('(') {
        let inner = value.strip_prefix('(').and_then(|v| v.strip_suffix(')')).unwrap_or(value);
        let mut depth = 0i32;
        let mut cur = String::new();
        for c in inner.chars() {
            match c {
                '(' | '[' => depth += 1,
                ')' | ']' => depth -= 1,
                ',' if depth == 0 => {
                    out.push(std::mem::take(&mut cur));
                    continue;
                }
                _ => {}
            }
            cur.push(c);
        }
        out.push(cur);
    } else {
        let mut depth = 0i32;
        let mut cur = String::new();
        for c in value.chars() {
            match c {
                '[' => {
                    depth += 1;
                    if depth == 1 {
                        continue;
                    }
                }
                ']' => {
                    depth -= 1;
                    if depth == 0 {
                        out.push(std::mem::take(&mut cur));
                        continue;
                    }
                }
                _ => {}
            }
            if depth > 0 {
                cur.push(c);
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dialect::Registry;

    #[test]
    fn constant_expressions() {
        assert_eq!(constant("572.86/2"), Some(286.43));
        assert_eq!(constant("[2*3]-1"), Some(5.0));
        assert_eq!(constant("-(1+2)*2"), Some(-6.0));
        assert_eq!(constant("286.43"), None, "a plain number is no expression");
        assert_eq!(constant("R1*2"), None, "a variable is not a constant");
        assert_eq!(constant("[2*3"), None, "an unclosed bracket");
        let mut s = "WR=572.86/2 X[1+1]".to_owned();
        fold_constants(&mut s);
        assert_eq!(s, "WR=286.43 X2");
    }

    #[test]
    fn one_variable_in_brackets_is_the_variable() {
        for (a, b) in [("G0X[#<X_START>]", "G0X#<X_START>"), ("G0X-[#5]Y1", "G0X-#5Y1"), ("G1X=(R1)", "G1X=R1")] {
            let (mut a, mut b) = (a.to_owned(), b.to_owned());
            fold_constants(&mut a);
            fold_constants(&mut b);
            assert_eq!(a, b);
        }
        // An expression of a variable is not one variable.
        let mut s = "G0X[#5+1]".to_owned();
        fold_constants(&mut s);
        assert_eq!(s, "G0X[#5+1]");
    }

    fn norm(dialect: &str, text: &str) -> Vec<String> {
        let d = Registry::shipped().get(dialect).unwrap();
        statements(text, &d).iter().map(|s| text_of(text, &d, s)).collect()
    }

    #[test]
    fn cosmetic_differences_vanish() {
        let a = norm("fanuc", "%\nO1234 (PART)\nN10 G01 X+10.500 Y-5. F800.\nN20 g0 z2.0 (UP)\n(JUST A COMMENT)\n\nM30\n%\n");
        let b = norm("fanuc", "%\nO1234\nN100G1X10.5Y-5.0F800.000;\nG00  Z2.\nM30\n%\n");
        assert_eq!(a, b);
        assert_eq!(a, ["G1X10.5Y-5.F800.", "G0Z2.", "M30"]);
    }

    #[test]
    fn fanuc_keeps_the_point_of_whole_numbers() {
        // X10 is ten least increments on a Fanuc, X10. ten millimetres.
        assert_ne!(norm("fanuc", "G1 X10\n"), norm("fanuc", "G1 X10.\n"));
        assert_eq!(norm("fanuc", "G1 X0\n"), norm("fanuc", "G1 X0.000\n"));
        assert_eq!(norm("linuxcnc", "G1 X10\n"), norm("linuxcnc", "G1 X10.\n"));
    }

    #[test]
    fn klartext_words_keep_their_blanks_and_lose_block_numbers() {
        let a = norm("heidenhain", "0 BEGIN PGM X MM\n5 L X+10 Y+5 R0 FMAX M3\n6 Q200=2 ;SET-UP CLEARANCE\n");
        let b = norm("heidenhain", "0 BEGIN PGM X MM\n15 L  X10  Y+5.0 R0 FMAX M3\n16 Q200=+2.000\n");
        assert_eq!(a, b);
        assert_eq!(a[0], "L X10Y5R0FMAX M3");
    }

    #[test]
    fn messages_are_statements_of_their_own() {
        let d = Registry::shipped().get("linuxcnc").unwrap();
        let s = statements("(msg, part 2)\n(just a note)\nG0 X1\n", &d);
        assert_eq!(s.len(), 2);
        assert_eq!(s[0].class, Class::Output);
        assert_eq!(s[1].class, Class::Machining);
    }

    #[test]
    fn tokens_of_a_statement() {
        let t = tokens("G1X10.5Y-5F800");
        assert_eq!(t.iter().map(|t| t.text.as_str()).collect::<Vec<_>>(), ["G1", "X10.5", "Y-5", "F800"]);
        assert_eq!(t[1].key, "X");
        assert_eq!(t[0].key, "G1");
        let t = tokens("O<POCKET_CIRC>CALL[0.75][1.5]");
        assert_eq!(t.len(), 1);
        assert_eq!(t[0].sort, Sort::Call);
        assert_eq!(arguments(&t[0].value), ["0.75", "1.5"]);
        let t = tokens("O200CALL[20]");
        assert_eq!((t.len(), t[0].key.as_str()), (1, "O200"));
        let t = tokens("T=\"EM_D10\"D2");
        assert_eq!(t.iter().map(|t| t.text.as_str()).collect::<Vec<_>>(), ["T=\"EM_D10\"", "D2"]);
        assert!(t[0].is_address());
        let t = tokens("_DRESSING(22,20,,2)");
        assert_eq!(arguments(&t[0].value), ["22", "20", "", "2"]);
        let t = tokens("#<_Z_CLEARANCE>=-0.1");
        assert_eq!((t[0].sort, t[0].key.as_str(), t[0].value.as_str()), (Sort::Assign, "#<_Z_CLEARANCE>", "-0.1"));
        assert_eq!(tokens("L X10Y5R0 FMAX M3").iter().map(|t| t.text.as_str()).collect::<Vec<_>>(), ["L", "X10", "Y5", "R0", "FMAX", "M3"]);
    }

    #[test]
    fn tokens_by_the_dictionary() {
        let texts = |t: Vec<Token>| t.into_iter().map(|t| t.text).collect::<Vec<_>>();
        let fanuc = Registry::shipped().get("fanuc").unwrap();
        let t = tokens_in("IF[#1EQ0]THEN#20=0", &fanuc);
        assert_eq!(texts(t.clone()), ["IF[#1EQ0]", "THEN", "#20=0"]);
        assert_eq!((t[2].sort, t[2].key.as_str()), (Sort::Assign, "#20"));
        // Without the dictionary, the keyword is read into the variable's name.
        assert_eq!(tokens("IF[#1EQ0]THEN#20=0")[1].key, "THEN#20");
        let siemens = Registry::shipped().get("siemens").unwrap();
        assert_eq!(texts(tokens_in("_RESULT=1EX300", &siemens)), ["_RESULT=1EX300"]);
        assert_eq!(texts(tokens_in("X1EX-3 Y2", &siemens)), ["X1EX-3", "Y2"]);
        // A word after a number that is no exponent is still a word of its own.
        assert_eq!(texts(tokens_in("G1X10EY5", &siemens)), ["G1", "X10", "EY5"]);
        // `==` compares, and a statement keyword against a system variable is a token of its own.
        let t = tokens_in("IF$A_DBB[15]==0", &siemens);
        assert_eq!(texts(t.clone()), ["IF", "$A_DBB[15]==0"]);
        assert_eq!(t[1].sort, Sort::Other);
        assert_ne!(tokens("INI[109]==0")[0].sort, Sort::Assign);
        assert_eq!((tokens("INI[109]=0")[0].sort, tokens("INI[109]=0")[0].key.as_str()), (Sort::Assign, "INI[109]"));
    }

    #[test]
    fn hunks_of_an_edit() {
        let s = |v: &[u64]| {
            v.iter().map(|&h| Stmt { line: 0, last: 0, offset: 0, hash: h, class: Class::Machining, moves: 0 }).collect::<Vec<_>>()
        };
        let h = hunks(&s(&[1, 2, 3, 4, 5]), &s(&[1, 9, 3, 5, 6]));
        assert_eq!(
            h,
            [Hunk { original: 1..2, edited: 1..2 }, Hunk { original: 3..4, edited: 3..3 }, Hunk { original: 5..5, edited: 4..5 }]
        );
        // A large middle goes by unique anchors.
        let a: Vec<u64> = (0..5000).collect();
        let mut b = a.clone();
        b[2500] = 99_999;
        b.insert(100, 77_777);
        let h = hunks(&s(&a), &s(&b));
        assert_eq!(h, [Hunk { original: 100..100, edited: 100..101 }, Hunk { original: 2500..2501, edited: 2501..2502 }]);
    }

    /// A removed run split by a statement equal to the one after it is one run, where git
    /// puts it: the longest common subsequence keeps the earlier of two equal statements
    /// (`g0x.2` in the middle of a removed section, and again after it), git the later.
    #[test]
    fn runs_slide_as_git_slides_them() {
        let s = |v: &[u64]| {
            v.iter().map(|&h| Stmt { line: 0, last: 0, offset: 0, hash: h, class: Class::Machining, moves: 0 }).collect::<Vec<_>>()
        };
        // 1 2 | 3 4 5 2 6 | 2 7 8  →  1 2 2 7 9
        let h = hunks(&s(&[1, 2, 3, 4, 5, 2, 6, 2, 7, 8]), &s(&[1, 2, 2, 7, 9]));
        assert_eq!(h, [Hunk { original: 2..7, edited: 2..2 }, Hunk { original: 9..10, edited: 4..5 }]);
        // Along the texts: the statement on a line git keeps pairs with that line's.
        let (a, b) = ("M0\nX1\nM0\nX2\n", "(M0)\nX1\nM0\nX2\n");
        let st = |lines: &[(u32, u64)]| {
            lines.iter().map(|&(l, h)| Stmt { line: l, last: l, offset: 0, hash: h, class: Class::Machining, moves: 0 }).collect::<Vec<_>>()
        };
        let h = hunks_in(&st(&[(1, 5), (2, 1), (3, 5), (4, 2)]), &st(&[(2, 1), (3, 5), (4, 2)]), Some((a, b)));
        assert_eq!(h, [Hunk { original: 0..1, edited: 0..0 }]);
    }

    /// A comparison in a comment or a message is text: `(ABORT, … >= 0 and <= 4)` is one
    /// piece and no assignment (held8 r342 read it as a variable set); a named parameter's
    /// brackets outside parentheses still are brackets.
    #[test]
    fn comparisons_inside_parentheses_are_no_brackets() {
        let t = tokens("(ABORT, Param #3: Startloc must be >= 0 and <= 4)");
        assert_eq!(t.len(), 1, "{t:?}");
        assert_ne!(t[0].sort, Sort::Assign);
        let t = tokens("#<_z_clearance>=-0.1");
        assert_eq!((t[0].sort, t[0].key.as_str(), t[0].value.as_str()), (Sort::Assign, "#<_z_clearance>", "-0.1"));
        let t = tokens("IF (R1>=R2) GOTOF END");
        assert!(t.iter().all(|x| x.sort != Sort::Assign), "{t:?}");
    }
}

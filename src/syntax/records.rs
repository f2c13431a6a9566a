//! The record reader: programs in record form (APT CLDATA, `dialect::records`) into blocks.
//!
//! A record is `MAJOR/minor,value,...`, continued over lines by the continuation character
//! (joined without a separator: CATIA breaks numbers at column 72), with comments from the
//! comment opener to the end of the line (a comment line ending in the continuation
//! character continues as comment). The dictionary says what each major word does; the
//! reader turns a record into one block of codes and words, so the interpreter runs it as it
//! runs G-code: a `GOTO` is a feed move (or the rapid a `RAPID` before it asked for, or the
//! arc a `CIRCLE` before it described, or a hole of the cycle in force). The reader keeps
//! what those records need: the last point, the tool axis, the pending rapid, circle and
//! cycle. Arcs are checked against the producer's circle sense by tangency.
//!
//! the record reader, where the dialect has `<records>`: the parser
//! hands it the text, and it reads one logical record per block (`$` continuation joined
//! without a separator, `$$` comments, a comment line ending in `$` continuing as comment,
//! bare point lines after a `GOTO`; comments with the dictionary's `command` opener, Creo's
//! `$$->`, are commands for the CAM system and not kept), then makes an ordinary `Block` of keyword-code words
//! (`Role::Keyword`, the code's index) and role words, so the interpreter runs CL as G-code.
//! It keeps what records that depend on others need: the last point and tool axis, the
//! one-shot `RAPID`, the pending `CIRCLE` (the next motion record ends its arc: plane from
//! the axis, G2/G3 from the producer's sense and the axis sign, I J K from the point, a
//! radius check, and the tangency check at both ends — a contradiction is
//! `syntax::circle-direction`, read as the setting says), the cycle in force (each motion
//! record one hole: Z and R from the point and the minor words' distances), and the units
//! the file states first (NX listings move before their first `FEDRAT/IPM`).
//! `record_program_name` gives the name record (`PARTNO`) for `pipeline` and pairing.

use super::{Block, Value, Word, WordMode};
use crate::diag::{Code, Diagnostic};
use crate::dialect::records::{CircleSense, RecordAction, RecordDef, Records};
use crate::dialect::{Dialect, Meaning, Role};
use crate::text::{Text, TextRange};

/// A circle a `CIRCLE` record described, waiting for the motion record that ends its arc.
#[derive(Clone, Debug)]
struct Circle {
    centre: [f64; 3],
    axis: [f64; 3],
    radius: Option<f64>,
    turns: Option<f64>,
    /// A direction code the record named (`CLOCKWISE`), overriding the producer's sense.
    code: Option<usize>,
    range: TextRange,
}

/// The end of the last arc, to check the move after it for tangency.
#[derive(Clone, Debug)]
struct ArcEnd {
    end: [f64; 3],
    centre: [f64; 3],
    axis: [f64; 3],
    ccw: bool,
    /// Whether the move into the arc, where tangent, turns the way the arc does.
    incoming: Option<bool>,
    range: TextRange,
}

/// Decides the last arc's check once the move after it is known (`out`: whether it leaves
/// the arc turning its way, where tangent): the data contradicts the producer's circle sense
/// when the moves at both ends are tangent to the arc and both turn the other way (the arc
/// read by the setting has a cusp at each end).
fn settle(st: &mut RecordState, recs: &Records, out: Option<bool>, diags: &mut Vec<Diagnostic>) {
    let Some(e) = st.arc_end.take() else { return };
    if e.incoming == Some(false) && out == Some(false) {
        let producer = st.producer.and_then(|p| recs.producers.get(p));
        let name = producer.map_or("the default producer", |p| p.name.as_str());
        let (said, seen) = if e.ccw { ("counter-clockwise", "clockwise") } else { ("clockwise", "counter-clockwise") };
        diags.push(Diagnostic::new(
            Code::CircleDirection,
            e.range,
            format!(
                "the moves into and out of this arc are tangent to it turning {seen} about its axis, but {name}'s circles turn {said}: the data contradicts the producer's setting (read as the setting says)"
            ),
        ));
    }
}

/// The canned cycle in force: its codes and its values, some measured from the hole's point.
#[derive(Clone, Debug, Default)]
struct Cycle {
    codes: Vec<usize>,
    values: Vec<(Role, f64, Option<f64>)>,
}

/// What the reader keeps between records.
#[derive(Debug, Default)]
pub(super) struct RecordState {
    started: bool,
    producer: Option<usize>,
    pos: Option<[f64; 3]>,
    prev: Option<[f64; 3]>,
    axis: Option<[f64; 3]>,
    rapid: Option<Vec<usize>>,
    circle: Option<Circle>,
    arc_end: Option<ArcEnd>,
    cycle: Option<Cycle>,
    units_seen: bool,
    /// The units code the file states first (`UNITS/MM`, or a feed's `IPM`), put in force
    /// with the first block: NX listings move before their first `FEDRAT/IPM`.
    units_first: Option<usize>,
    moved: bool,
    last_goto: bool,
    noted: Vec<String>,
    buf: String,
    /// Logical offset in `buf` → source offset, one entry per physical piece.
    segs: Vec<(usize, usize)>,
}

#[derive(Clone, Debug)]
enum Tok {
    Num(f64),
    Word(String),
}

const CONTINUED_LIMIT: usize = 10_000;

impl RecordState {
    fn src(&self, logical: usize) -> u32 {
        let i = self.segs.partition_point(|&(l, _)| l <= logical).saturating_sub(1);
        let (l, s) = self.segs.get(i).copied().unwrap_or((0, 0));
        (s + (logical - l)) as u32
    }

    fn range(&self, a: usize, b: usize) -> TextRange {
        let start = self.src(a);
        let end = if b > a { self.src(b - 1) + 1 } else { start };
        TextRange::new(start as usize, end.max(start) as usize)
    }
}

impl RecordState {
    /// Whether the first record has been read (the producer told).
    pub(super) fn started(&self) -> bool {
        self.started
    }

    /// Before the first record: tells the producer from the text's `head` (its first 64
    /// KiB), and the units the file states first.
    pub(super) fn start(&mut self, head: &str, recs: &Records, dialect: &Dialect, diags: &mut Vec<Diagnostic>) {
        self.started = true;
        if let Some((p, evidence)) = recs.producer(head.as_bytes()) {
            self.producer = Some(p);
            let name = &recs.producers[p].name;
            let sense = match recs.producers[p].circle {
                CircleSense::Clockwise => "clockwise",
                CircleSense::CounterClockwise => "counter-clockwise",
            };
            let why = evidence.map_or_else(|| "no producer's evidence was found: the default".to_owned(), |e| format!("by `{e}`"));
            diags.push(Diagnostic::new(
                Code::RecordProducer,
                TextRange::new(0, 0),
                format!("read as a CL file written by {name} ({why}); its circles turn {sense} about their axis"),
            ));
        }
        self.units_first = first_units(recs, self.producer, dialect, head);
        self.units_seen = self.units_first.is_some();
    }
}

/// At the end of the text: what records that wait for others still lack.
pub(super) fn finish(st: &mut RecordState, recs: &Records, diags: &mut Vec<Diagnostic>) {
    settle(st, recs, None, diags);
    if let Some(c) = st.circle.take() {
        diags.push(Diagnostic::new(Code::CircleWithoutMove, c.range, "no motion record ends this circle's arc before the end of the file"));
    }
}

/// Gathers the logical record at `pos` (an offset in the whole text) from `text`, the text
/// from `base` on, into `st.buf` and `block` (its range, comments, lines); where the next
/// record starts and its line. A record that runs to the end of `text` may go on past it:
/// the caller reads it again from more text before it is interpreted
/// ([`finish_record`]).
pub(super) fn gather(
    st: &mut RecordState,
    recs: &Records,
    text: &str,
    base: usize,
    pos: usize,
    line: u32,
    block: &mut Block,
) -> (usize, u32) {
    let mut line = line;
    block.clear();
    block.line = line;
    let bytes = text.as_bytes();
    let start = pos - base;
    st.buf.clear();
    st.segs.clear();
    let mut cur = start;
    let mut end = start;
    let mut comment_continues = false;
    // Whether the comment being continued is a CAM command (`$$-> CSYS ... $`), not kept.
    let mut command = false;
    let range = |a: usize, b: usize| TextRange::new(base + a, base + b);
    for _ in 0..CONTINUED_LIMIT {
        let le = memchr::memchr(b'\n', &bytes[cur..]).map_or(bytes.len(), |i| cur + i);
        let next = if le < bytes.len() { le + 1 } else { le };
        let le = if le > cur && bytes[le - 1] == b'\r' { le - 1 } else { le };
        let phys = &text[cur..le];
        end = le;
        let at_end = next >= bytes.len();
        if comment_continues {
            if !command {
                block.comments.push(range(cur, le));
            }
            comment_continues = phys.trim_end().ends_with(recs.continuation);
            line += 1;
            cur = next;
            if comment_continues && !at_end {
                block.extra_lines += 1;
                continue;
            }
            break;
        }
        let (code, comment) = match phys.find(recs.comment.as_str()) {
            Some(i) => (&phys[..i], Some(i)),
            None => (phys, None),
        };
        if let Some(i) = comment {
            let opener = recs.command.as_deref().filter(|c| phys[i..].starts_with(*c));
            command = opener.is_some();
            // A command that states a tool's geometry (Creo `$$-> CUTTER / 20.0`) is kept as
            // the statement record of that name is: a tool comment the plan reads.
            let statement = opener.is_some_and(|c| {
                let major = phys[i + c.len()..].split('/').next().unwrap_or("").trim().to_ascii_uppercase();
                recs.records.iter().any(|r| r.major == major && r.action == RecordAction::Statement)
            });
            if !command || statement {
                block.comments.push(range(cur + i + recs.comment.len(), le));
            }
        }
        let code_t = code.trim_end();
        if code_t.ends_with(recs.continuation) && !code_t.trim().is_empty() {
            st.segs.push((st.buf.len(), base + cur));
            st.buf.push_str(&code_t[..code_t.len() - recs.continuation.len_utf8()]);
            line += 1;
            cur = next;
            if at_end {
                break;
            }
            block.extra_lines += 1;
            continue;
        }
        st.segs.push((st.buf.len(), base + cur));
        st.buf.push_str(code);
        line += 1;
        cur = next;
        if code.trim().is_empty()
            && comment.is_some()
            && phys.trim_end().ends_with(recs.continuation)
            && st.buf.trim().is_empty()
            && !at_end
        {
            // `$$-> CSYS / 1.0, ...  $`: the comment goes on over the next lines.
            comment_continues = true;
            block.extra_lines += 1;
            continue;
        }
        break;
    }
    if bytes.get(end).is_none() && line > block.line {
        // The last line had no terminator: it was not a line more.
        line -= 1;
    }
    block.range = range(start, end);
    (base + cur, line)
}

/// Interprets the record [`gather`] read into `block`.
pub(super) fn finish_record(st: &mut RecordState, recs: &Records, dialect: &Dialect, block: &mut Block, diags: &mut Vec<Diagnostic>) {
    if let Some(u) = st.units_first.take() {
        push_codes(block, &[u]);
    }
    record(st, recs, dialect, block, diags);
}

/// The first units code a record in `head` states through a minor word (`UNITS/MM`,
/// `FEDRAT/IPM,10`): the units of the whole file, from its first move on.
fn first_units(recs: &Records, producer: Option<usize>, dialect: &Dialect, head: &str) -> Option<usize> {
    for line in head.lines() {
        let code = line.split(recs.comment.as_str()).next().unwrap_or("");
        let Some((major, args)) = code.split_once('/') else { continue };
        let major = major.split_whitespace().collect::<Vec<_>>().join(" ").to_ascii_uppercase();
        let Some(def) = recs.record(producer, &major) else { continue };
        for word in args.split(|c: char| c == ',' || c.is_whitespace()).filter(|w| !w.is_empty()) {
            let up = word.to_ascii_uppercase();
            if let Some(m) = def.minor(&up)
                && let Some(&c) = m.codes.iter().find(|&&c| matches!(dialect.codes[c].meaning, Meaning::UnitsMm | Meaning::UnitsInch))
            {
                return Some(c);
            }
        }
    }
    None
}

fn is_major_char(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_' || c == '-' || c == ' '
}

/// Interprets the logical record in `st.buf`.
fn record(st: &mut RecordState, recs: &Records, dialect: &Dialect, block: &mut Block, diags: &mut Vec<Diagnostic>) {
    let buf = std::mem::take(&mut st.buf);
    let lead = buf.len() - buf.trim_start().len();
    let body = buf.trim_end();
    if body.len() <= lead {
        st.buf = buf;
        return;
    }
    let first = body[lead..].chars().next().unwrap_or(' ');
    if (first.is_ascii_digit() || matches!(first, '-' | '+' | '.')) && st.last_goto {
        // A bare point after a motion record: one more point of it (Creo `GOTO` + points).
        let toks = tokens(st, &buf, lead);
        let nums: Vec<f64> = toks.iter().filter_map(|(t, _)| if let Tok::Num(v) = t { Some(*v) } else { None }).collect();
        goto(st, recs, dialect, &[], &nums, block, diags);
        st.buf = buf;
        return;
    }
    let (major_end, args_at) = match body[lead..].find('/') {
        Some(i) => (lead + i, Some(lead + i + 1)),
        None => (body[lead..].find(char::is_whitespace).map_or(body.len(), |i| lead + i), None),
    };
    let raw_major = &body[lead..major_end];
    let major = raw_major.split_whitespace().collect::<Vec<_>>().join(" ").to_ascii_uppercase();
    let major_range = st.range(lead, major_end);
    if major.is_empty() || !raw_major.trim().chars().all(is_major_char) || !major.starts_with(|c: char| c.is_ascii_alphabetic()) {
        let msg = "this line is no record (`MAJOR/...`) of the CL file: skipped";
        diags.push(Diagnostic::new(Code::NotARecord, st.range(lead, body.len()), msg));
        st.buf = buf;
        return;
    }
    let def = recs.record(st.producer, &major);
    let text_like = def.is_some_and(|d| matches!(d.action, RecordAction::Text | RecordAction::Name));
    if args_at.is_none() && !text_like && !body[major_end..].trim().is_empty() {
        // `Tool Path Listing has 81 lines.`, a listing's header: words, no record.
        let msg = "this line is no record (`MAJOR/...`) of the CL file: skipped";
        diags.push(Diagnostic::new(Code::NotARecord, st.range(lead, body.len()), msg));
        st.buf = buf;
        return;
    }
    let Some(def) = def else {
        if !st.noted.contains(&major) {
            let msg = format!("`{major}` is a post-processor word the dictionary does not define: passed over (said once)");
            diags.push(Diagnostic::new(Code::UnknownRecord, major_range, msg));
            st.noted.push(major);
        }
        st.buf = buf;
        return;
    };
    let rest_at = args_at.unwrap_or(major_end);
    st.last_goto = false;
    match def.action {
        RecordAction::Text | RecordAction::Name => {
            let t = &body[rest_at.min(body.len())..];
            let skip = t.len() - t.trim_start().len();
            if t.trim().is_empty() {
                // nothing to keep
            } else {
                block.comments.push(st.range(rest_at + skip, body.len()));
            }
            push_codes(block, &def.codes);
        }
        RecordAction::Statement => {
            block.comments.push(st.range(lead, body.len()));
            push_codes(block, &def.codes);
        }
        RecordAction::Ignore => {}
        action => {
            let toks = tokens(st, &buf, rest_at);
            let nums_only: Vec<f64> = toks.iter().filter_map(|(t, _)| if let Tok::Num(v) = t { Some(*v) } else { None }).collect();
            match action {
                RecordAction::Words => words(st, def, &toks, dialect, block, diags),
                RecordAction::Goto => {
                    st.last_goto = true;
                    goto(st, recs, dialect, &def.codes, &nums_only, block, diags);
                }
                RecordAction::Delta => {
                    let (Some(p), Some(first)) = (st.pos, nums_only.first()) else {
                        diags.push(Diagnostic::new(
                            Code::RecordArgument,
                            block.range,
                            "an incremental move before any point is known: skipped",
                        ));
                        st.buf = buf;
                        return;
                    };
                    let to = if nums_only.len() >= 3 {
                        [p[0] + nums_only[0], p[1] + nums_only[1], p[2] + nums_only[2]]
                    } else {
                        let a = st.axis.unwrap_or([0.0, 0.0, 1.0]);
                        [p[0] + first * a[0], p[1] + first * a[1], p[2] + first * a[2]]
                    };
                    goto(st, recs, dialect, &def.codes, &to, block, diags);
                }
                RecordAction::Rapid => st.rapid = Some(def.codes.clone()),
                RecordAction::Circle => circle(st, def, &toks, block, diags),
                RecordAction::Cycle => {
                    if let Some(c) = st.circle.take() {
                        diags.push(Diagnostic::new(
                            Code::CircleWithoutMove,
                            c.range,
                            "a cycle starts before a motion record ends this circle's arc: it is dropped",
                        ));
                    }
                    cycle(st, def, &toks, dialect, block, diags)
                }
                RecordAction::From => {
                    if nums_only.len() >= 3 {
                        st.pos = Some([nums_only[0], nums_only[1], nums_only[2]]);
                        st.prev = None;
                    }
                }
                RecordAction::Text | RecordAction::Name | RecordAction::Statement | RecordAction::Ignore => {}
            }
        }
    }
    st.buf = buf;
}

/// The arguments after the slash: numbers and words, split at commas and blanks.
fn tokens(st: &RecordState, buf: &str, from: usize) -> Vec<(Tok, TextRange)> {
    let mut out = Vec::new();
    let s = &buf[from.min(buf.len())..];
    let sep = |c: char| c == ',' || c.is_whitespace();
    let mut rest = s;
    while let Some(i) = rest.find(|c: char| !sep(c)) {
        let start = s.len() - rest.len() + i;
        let t = &s[start..];
        let len = t.find(sep).unwrap_or(t.len());
        let word = &t[..len];
        let range = st.range(from + start, from + start + len);
        match word.parse::<f64>() {
            Ok(v) if v.is_finite() => out.push((Tok::Num(v), range)),
            _ => out.push((Tok::Word(word.to_ascii_uppercase()), range)),
        }
        rest = &t[len..];
    }
    out
}

fn code_word(idx: usize) -> Word {
    Word {
        role: Role::Keyword,
        letter: b'G',
        value: Value::Number { value: idx as f64, decimal: false },
        range: TextRange::default(),
        mode: WordMode::Modal,
        cycle_arg: false,
    }
}

fn push_codes(block: &mut Block, codes: &[usize]) {
    let r = block.range;
    for &c in codes {
        let given = Value::Number { value: c as f64, decimal: false };
        if block.words.iter().any(|w| w.role == Role::Keyword && w.value == given) {
            continue;
        }
        let mut w = code_word(c);
        w.range = r;
        block.words.push(w);
    }
}

fn push_word(block: &mut Block, dialect: &Dialect, role: Role, value: f64, range: TextRange) {
    if let Some(w) = block.words.iter_mut().find(|w| w.role == role) {
        w.value = Value::Number { value, decimal: true };
        return;
    }
    let letter = dialect.addresses.iter().find(|a| a.role == role).and_then(|a| a.name.bytes().next()).unwrap_or(b'?');
    block.words.push(Word { role, letter, value: Value::Number { value, decimal: true }, range, mode: WordMode::Modal, cycle_arg: false });
}

fn note_units(st: &mut RecordState, dialect: &Dialect, block: &Block, diags: &mut Vec<Diagnostic>) {
    if !st.moved {
        st.moved = true;
        if !st.units_seen {
            let _ = dialect;
            let msg = "no UNITS record (or feed in MMPM/IPM) before the first move: the dictionary's default units are assumed until one says otherwise";
            diags.push(Diagnostic::new(Code::RecordUnits, block.range, msg));
        }
    }
}

fn mark_units(st: &mut RecordState, dialect: &Dialect, codes: &[usize]) {
    if codes.iter().any(|&c| matches!(dialect.codes[c].meaning, Meaning::UnitsMm | Meaning::UnitsInch)) {
        st.units_seen = true;
    }
}

/// A record of codes and words: minor words give codes or name the number after them;
/// the other numbers take the record's positional roles.
fn words(
    st: &mut RecordState,
    def: &RecordDef,
    toks: &[(Tok, TextRange)],
    dialect: &Dialect,
    block: &mut Block,
    diags: &mut Vec<Diagnostic>,
) {
    push_codes(block, &def.codes);
    mark_units(st, dialect, &def.codes);
    let mut positional = def.args.iter();
    let mut i = 0;
    while i < toks.len() {
        match &toks[i].0 {
            Tok::Word(w) => match def.minor(w) {
                Some(m) => {
                    push_codes(block, &m.codes);
                    mark_units(st, dialect, &m.codes);
                    if let (Some(role), Some((Tok::Num(v), r))) = (m.role, toks.get(i + 1)) {
                        if role != Role::Extra {
                            push_word(block, dialect, role, *v, *r);
                        }
                        i += 1;
                    }
                }
                None => argument(diags, &def.major, w, toks[i].1),
            },
            Tok::Num(v) => match positional.next() {
                Some(&(Role::Extra, _)) => {}
                Some(&(role, _)) => push_word(block, dialect, role, *v, toks[i].1),
                None => argument(diags, &def.major, &format!("{v}"), toks[i].1),
            },
        }
        i += 1;
    }
    for &(a, b) in &def.also {
        let given = block.words.iter().find(|w| w.role == a).map(|w| (w.value, w.range));
        if let Some((Value::Number { value, .. }, r)) = given
            && !block.words.iter().any(|w| w.role == b)
        {
            push_word(block, dialect, b, value, r);
        }
    }
}

fn argument(diags: &mut Vec<Diagnostic>, major: &str, what: &str, range: TextRange) {
    diags.push(Diagnostic::new(Code::RecordArgument, range, format!("`{what}` is no argument the dictionary gives `{major}`: ignored")));
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn cross(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
}

fn norm(a: [f64; 3]) -> f64 {
    dot(a, a).sqrt()
}

/// The sense of travel `v` at `p` about the circle (`centre`, `axis`), where the move is
/// tangent to it: Some(true) counter-clockwise about the axis, None where not tangent.
fn tangent_sense(p: [f64; 3], v: [f64; 3], centre: [f64; 3], axis: [f64; 3]) -> Option<bool> {
    let r = sub(p, centre);
    // The radius vector in the circle's plane.
    let n = norm(axis).max(1e-12);
    let a = [axis[0] / n, axis[1] / n, axis[2] / n];
    let along = dot(r, a);
    let r = [r[0] - along * a[0], r[1] - along * a[1], r[2] - along * a[2]];
    let vd = dot(v, a);
    let v = [v[0] - vd * a[0], v[1] - vd * a[1], v[2] - vd * a[2]];
    let (nr, nv) = (norm(r), norm(v));
    if nr < 1e-9 || nv < 1e-9 {
        return None;
    }
    let c = cross(r, v);
    let s = dot(c, a) / (nr * nv);
    (s.abs() > 0.9).then_some(s > 0.0)
}

fn goto(
    st: &mut RecordState,
    recs: &Records,
    dialect: &Dialect,
    codes: &[usize],
    nums: &[f64],
    block: &mut Block,
    diags: &mut Vec<Diagnostic>,
) {
    if nums.len() < 3 {
        diags.push(Diagnostic::new(Code::RecordArgument, block.range, "a motion record needs x, y and z: skipped"));
        return;
    }
    note_units(st, dialect, block, diags);
    let p = [nums[0], nums[1], nums[2]];
    let r = block.range;
    if nums.len() >= 6 {
        let a = [nums[3], nums[4], nums[5]];
        let before = st.axis.unwrap_or([0.0, 0.0, 1.0]);
        if norm(sub(a, before)) > 1e-9 {
            push_word(block, dialect, Role::ToolAxisI, a[0], r);
            push_word(block, dialect, Role::ToolAxisJ, a[1], r);
            push_word(block, dialect, Role::ToolAxisK, a[2], r);
        }
        st.axis = Some(a);
    }
    let rapid = st.rapid.take();
    if let Some(c) = st.cycle.clone() {
        hole(st, dialect, &c, p, block, diags);
        return;
    }
    if let Some(c) = st.circle.take() {
        arc(st, recs, dialect, c, p, block, diags);
        return;
    }
    let out = st.arc_end.as_ref().and_then(|e| tangent_sense(e.end, sub(p, e.end), e.centre, e.axis).map(|ccw| ccw == e.ccw));
    settle(st, recs, out, diags);
    match rapid {
        Some(c) => push_codes(block, &c),
        None => push_codes(block, codes),
    }
    push_word(block, dialect, Role::X, p[0], r);
    push_word(block, dialect, Role::Y, p[1], r);
    push_word(block, dialect, Role::Z, p[2], r);
    st.prev = st.pos;
    st.pos = Some(p);
}

fn circle(st: &mut RecordState, def: &RecordDef, toks: &[(Tok, TextRange)], block: &mut Block, diags: &mut Vec<Diagnostic>) {
    let mut nums = Vec::new();
    let mut turns = None;
    let mut code = None;
    let mut i = 0;
    while i < toks.len() {
        match &toks[i].0 {
            Tok::Num(v) => nums.push(*v),
            Tok::Word(w) => match def.minor(w) {
                Some(m) => {
                    code = m.codes.first().copied().or(code);
                    if let (Some(Role::P), Some((Tok::Num(v), _))) = (m.role, toks.get(i + 1)) {
                        turns = Some(*v);
                        i += 1;
                    }
                }
                None => argument(diags, &def.major, w, toks[i].1),
            },
        }
        i += 1;
    }
    if nums.len() < 6 {
        diags.push(Diagnostic::new(Code::RecordArgument, block.range, "a circle needs its centre and axis (six numbers): skipped"));
        return;
    }
    if st.circle.is_some() {
        diags.push(Diagnostic::new(Code::CircleWithoutMove, block.range, "a circle follows a circle no move ended: the first is dropped"));
    }
    st.circle = Some(Circle {
        centre: [nums[0], nums[1], nums[2]],
        axis: [nums[3], nums[4], nums[5]],
        radius: nums.get(6).copied(),
        turns,
        code,
        range: block.range,
    });
}

fn arc(st: &mut RecordState, recs: &Records, dialect: &Dialect, c: Circle, end: [f64; 3], block: &mut Block, diags: &mut Vec<Diagnostic>) {
    let r = block.range;
    let straight = |st: &mut RecordState, block: &mut Block| {
        if let Some(code) = dialect.codes.iter().position(|x| x.meaning == Meaning::Linear) {
            push_codes(block, &[code]);
        }
        push_word(block, dialect, Role::X, end[0], r);
        push_word(block, dialect, Role::Y, end[1], r);
        push_word(block, dialect, Role::Z, end[2], r);
        st.prev = st.pos;
        st.pos = Some(end);
    };
    let Some(start) = st.pos else {
        diags.push(Diagnostic::new(Code::RecordArgument, c.range, "a circle before any point is known: its move goes straight"));
        straight(st, block);
        return;
    };
    let n = norm(c.axis);
    if n < 1e-9 {
        diags.push(Diagnostic::new(Code::RecordArgument, c.range, "a circle with a zero axis vector: its move goes straight"));
        straight(st, block);
        return;
    }
    let axis = [c.axis[0] / n, c.axis[1] / n, c.axis[2] / n];
    // The main plane the circle lies in, by its normal: XY (Z), XZ (Y), YZ (X).
    let (plane, normal_i, offsets) = if axis[2].abs() > 1.0 - 1e-6 {
        (Meaning::PlaneXy, 2, [(Role::I, 0), (Role::J, 1)])
    } else if axis[1].abs() > 1.0 - 1e-6 {
        (Meaning::PlaneXz, 1, [(Role::I, 0), (Role::K, 2)])
    } else if axis[0].abs() > 1.0 - 1e-6 {
        (Meaning::PlaneYz, 0, [(Role::J, 1), (Role::K, 2)])
    } else {
        diags.push(Diagnostic::new(
            Code::CircleTilted,
            c.range,
            "a circle in a tilted plane: the canon has arcs in the XY, XZ and YZ planes only, so its move goes straight",
        ));
        straight(st, block);
        return;
    };
    let producer = st.producer.and_then(|p| recs.producers.get(p));
    let sense_ccw = match c.code.map(|x| dialect.codes[x].meaning) {
        Some(Meaning::ArcCw) => false,
        Some(Meaning::ArcCcw) => true,
        _ => producer.is_none_or(|p| p.circle == CircleSense::CounterClockwise),
    };
    // Radii of the start and end in the plane.
    let radius_of = |p: [f64; 3]| {
        let d = sub(p, c.centre);
        let along = dot(d, axis);
        norm([d[0] - along * axis[0], d[1] - along * axis[1], d[2] - along * axis[2]])
    };
    let (rs, re) = (radius_of(start), radius_of(end));
    let tol = recs.tolerance;
    if (rs - re).abs() > tol || c.radius.is_some_and(|r0| (r0 - rs).abs() > tol) {
        let stated = c.radius.map_or(String::new(), |r0| format!(", the record states {r0}"));
        diags.push(Diagnostic::new(
            Code::CircleRadius,
            c.range,
            format!("the arc's start is {rs:.4} from the centre and its end {re:.4}{stated}"),
        ));
    }
    // Checked by tangency with the moves into and out of the arc (decided at the next move).
    settle(st, recs, None, diags);
    let incoming = st.prev.and_then(|prev| tangent_sense(start, sub(start, prev), c.centre, axis)).map(|ccw| ccw == sense_ccw);
    let normal = [0.0, 0.0, 0.0];
    let mut pn = normal;
    pn[normal_i] = 1.0;
    let ccw_in_plane = sense_ccw == (dot(axis, pn) > 0.0);
    let meaning = if ccw_in_plane { Meaning::ArcCcw } else { Meaning::ArcCw };
    let find = |m: Meaning| dialect.codes.iter().position(|x| x.meaning == m);
    let (Some(plane_code), Some(arc_code)) = (find(plane), find(meaning)) else {
        straight(st, block);
        return;
    };
    push_codes(block, &[plane_code, arc_code]);
    push_word(block, dialect, Role::X, end[0], r);
    push_word(block, dialect, Role::Y, end[1], r);
    push_word(block, dialect, Role::Z, end[2], r);
    for (role, k) in offsets {
        push_word(block, dialect, role, c.centre[k] - start[k], r);
    }
    if let Some(t) = c.turns.filter(|t| *t >= 1.0) {
        push_word(block, dialect, Role::P, t.round() + 1.0, r);
    }
    st.arc_end = Some(ArcEnd { end, centre: c.centre, axis, ccw: sense_ccw, incoming, range: c.range });
    st.prev = None;
    st.pos = Some(end);
}

fn cycle(
    st: &mut RecordState,
    def: &RecordDef,
    toks: &[(Tok, TextRange)],
    dialect: &Dialect,
    block: &mut Block,
    diags: &mut Vec<Diagnostic>,
) {
    let mut codes: Vec<usize> = def.codes.clone();
    let mut kind = None;
    let mut cancel = None;
    let mut values: Vec<(Role, f64, Option<f64>)> = Vec::new();
    let mut positional = def.args.iter();
    let mut i = 0;
    while i < toks.len() {
        match &toks[i].0 {
            Tok::Word(w) => match def.minor(w) {
                Some(m) => {
                    for &c in &m.codes {
                        match dialect.codes[c].meaning {
                            Meaning::CycleCancel => cancel = Some(c),
                            x if x.is_cycle() => kind = Some(c),
                            _ => codes.push(c),
                        }
                    }
                    mark_units(st, dialect, &m.codes);
                    if let (Some(role), Some((Tok::Num(v), _))) = (m.role, toks.get(i + 1)) {
                        if role != Role::Extra {
                            values.retain(|x| x.0 != role);
                            values.push((role, *v, m.from_point));
                        }
                        i += 1;
                    }
                }
                None => argument(diags, &def.major, w, toks[i].1),
            },
            Tok::Num(v) => match positional.next() {
                Some(&(Role::Extra, _)) => {}
                Some(&(role, from)) => {
                    values.retain(|x| x.0 != role);
                    values.push((role, *v, from));
                }
                None => argument(diags, &def.major, &format!("{v}"), toks[i].1),
            },
        }
        i += 1;
    }
    if let Some(c) = cancel {
        st.cycle = None;
        push_codes(block, &[c]);
        return;
    }
    match (kind, st.cycle.as_mut()) {
        (Some(k), _) => {
            codes.push(k);
            st.cycle = Some(Cycle { codes, values });
        }
        (None, Some(running)) => {
            for v in values {
                running.values.retain(|x| x.0 != v.0);
                running.values.push(v);
            }
        }
        (None, None) => {}
    }
}

fn hole(st: &mut RecordState, dialect: &Dialect, c: &Cycle, p: [f64; 3], block: &mut Block, diags: &mut Vec<Diagnostic>) {
    let r = block.range;
    let a = st.axis.unwrap_or([0.0, 0.0, 1.0]);
    if a[2].abs() < 1.0 - 1e-6 {
        diags.push(Diagnostic::new(Code::CircleTilted, r, "a hole along a tilted tool axis: its cycle is read along Z"));
    }
    push_codes(block, &c.codes);
    push_word(block, dialect, Role::X, p[0], r);
    push_word(block, dialect, Role::Y, p[1], r);
    push_word(block, dialect, Role::Z, p[2], r);
    for &(role, v, from) in &c.values {
        let value = match from {
            Some(sign) => p[2] + sign * v * a[2].signum(),
            None => v,
        };
        push_word(block, dialect, role, value, r);
    }
    st.prev = None;
    st.pos = Some(p);
}

/// The program's name a record-form text states (the first record whose action is
/// [`RecordAction::Name`]: `PARTNO/MFG0004`, `PARTNO PART 1`), quotes taken off; `None` for
/// a dialect of words or a text without one. Looks at the first 64 KiB.
pub fn record_program_name<'t>(text: impl Into<Text<'t>>, dialect: &Dialect) -> Option<String> {
    let recs = dialect.records.as_deref()?;
    let head = text.into().head();
    for line in head.lines() {
        let code = line.split(recs.comment.as_str()).next().unwrap_or("").trim();
        let (major, rest) = match code.split_once('/') {
            Some((m, r)) => (m, r),
            None => code.split_once(char::is_whitespace).unwrap_or((code, "")),
        };
        let major = major.split_whitespace().collect::<Vec<_>>().join(" ").to_ascii_uppercase();
        if recs.records.iter().any(|r| r.major == major && r.action == RecordAction::Name) {
            let name = rest.trim().trim_matches(|c| c == '\'' || c == '"').trim();
            return (!name.is_empty()).then(|| name.to_owned());
        }
    }
    None
}

//! Reading `<output>` from a dictionary: each section of the element (number formats, the
//! block format, block numbers, comments, the templates of events, cycles, rules) into an
//! [`Output`], every placeholder, format name and rule expression checked, with errors
//! pointing at the attribute.
//!
//! The door: [`load`], which the dictionary's loader calls for an `<output>` element, and
//! [`parse_expr`], which reads a rule's condition.

use super::{
    Block, Bound, Cmp, CycleOut, EVENTS, Expr, NumberFormat, Numbered, Output, Piece, Point, Rule, StateVar, Template, Value, Word,
};
use crate::canon::CycleKind;
use crate::dialect::xml::Element;
use crate::text::TextRange;

/// The placeholders' names, and the values they stand for.
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
    ("px", Value::PlaneX),
    ("py", Value::PlaneY),
    ("pz", Value::PlaneZ),
    ("spa", Value::SpatialA),
    ("spb", Value::SpatialB),
    ("spc", Value::SpatialC),
    ("eul-a", Value::EulerA),
    ("eul-b", Value::EulerB),
    ("eul-c", Value::EulerC),
    ("rot-a", Value::TurnA),
    ("rot-b", Value::TurnB),
    ("rot-c", Value::TurnC),
    ("mx", Value::MachineX),
    ("my", Value::MachineY),
    ("mz", Value::MachineZ),
    ("ma", Value::MachineA),
    ("mb", Value::MachineB),
    ("mc", Value::MachineC),
];

/// The cycle kinds' names in `<cycle kinds>`.
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
pub(in crate::dialect) fn load(el: &Element, errors: &mut Errors) -> Output {
    shape(el, &["modal-motion", "refused"], errors);
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
        refused: attr(el, "refused").map(str::to_owned),
        formats: Vec::new(),
        templates: Vec::new(),
        cycles: Vec::new(),
        rules: Vec::new(),
        bounds: Vec::new(),
    };
    // Formats first: templates refer to them.
    for c in el.children.iter().filter(|c| c.name == "format") {
        read_format(c, &mut out, errors);
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
            digits: 0,
        });
    }
    for c in &el.children {
        match c.name.as_str() {
            "format" => {}
            "block" => read_block(c, &mut out, errors),
            "block-numbers" => read_block_numbers(c, &mut out, errors),
            "comment" => read_comment(c, &mut out, errors),
            "emit" => read_emit(c, &mut out, errors),
            "cycle" => read_cycle(c, &mut out, errors),
            "rule" => read_rule(c, &mut out, errors),
            "remove" => {}
            other => errors.push((c.range, format!("<output> may not contain <{other}>"))),
        }
    }
    out
}

/// Reads a `<format>`: how a number is written for one address, and the values its address
/// takes; a format without a name is left out.
fn read_format(c: &Element, out: &mut Output, errors: &mut Errors) {
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
            "digits",
        ],
        errors,
    );
    let Some(name) = attr(c, "name") else {
        errors.push((c.range, "<format> needs the attribute `name`".into()));
        return;
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
        digits: count(c, "digits", 0, errors).min(9) as u8,
    });
}

/// Reads `<block>`: the separator between a block's words, what ends it, its longest.
fn read_block(c: &Element, out: &mut Output, errors: &mut Errors) {
    shape(c, &["separator", "end", "max-length"], errors);
    if let Some(s) = attr(c, "separator") {
        out.separator = s.to_owned();
    }
    out.end_of_block = attr(c, "end").unwrap_or("").to_owned();
    out.max_line = count(c, "max-length", 0, errors) as usize;
}

/// Reads `<block-numbers>`: their address, first number and step, and which blocks get one.
fn read_block_numbers(c: &Element, out: &mut Output, errors: &mut Errors) {
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

/// Reads `<comment>`: how a comment opens and closes, what it may not hold, its case.
fn read_comment(c: &Element, out: &mut Output, errors: &mut Errors) {
    shape(c, &["open", "close", "forbidden", "upper"], errors);
    out.comment_open = attr(c, "open").unwrap_or("(").to_owned();
    out.comment_close = attr(c, "close").unwrap_or("").to_owned();
    out.comment_forbidden = attr(c, "forbidden").map_or_else(|| out.comment_open.clone() + &out.comment_close, str::to_owned);
    out.comment_upper = flag(c, "upper", false, errors);
}

/// Reads an `<emit>`: the template of an event, and whether it waits for the next move; one
/// without a name, or naming no event, is left out.
fn read_emit(c: &Element, out: &mut Output, errors: &mut Errors) {
    shape(c, &["name", "text", "into"], errors);
    let Some(name) = attr(c, "name") else {
        errors.push((c.range, "<emit> needs the attribute `name`".into()));
        return;
    };
    if !EVENTS.contains(&name) {
        errors.push((range(c, "name"), format!("`{name}` is not an output event (one of {})", EVENTS.join(", "))));
        return;
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

/// Reads a `<cycle>`: the cycle kinds the target writes as a cycle, and its templates.
fn read_cycle(c: &Element, out: &mut Output, errors: &mut Errors) {
    shape(c, &["name", "kinds", "define", "at", "cancel", "inline"], errors);
    let mut kinds = Vec::new();
    let names = attr(c, "kinds").or(attr(c, "name")).unwrap_or("");
    for k in names.split_ascii_whitespace() {
        match CYCLE_KINDS.iter().find(|(n, _)| *n == k) {
            Some((_, kind)) => kinds.push(*kind),
            None => errors.push((
                range(c, if attr(c, "kinds").is_some() { "kinds" } else { "name" }),
                format!("`{k}` is not a cycle kind (one of {})", CYCLE_KINDS.iter().map(|(n, _)| *n).collect::<Vec<_>>().join(", ")),
            )),
        }
    }
    let define = template(attr(c, "define").unwrap_or(""), range(c, "define"), &out.formats, errors);
    let at = template(attr(c, "at").unwrap_or(""), range(c, "at"), &out.formats, errors);
    let cancel = template(attr(c, "cancel").unwrap_or(""), range(c, "cancel"), &out.formats, errors);
    let inline = flag(c, "inline", false, errors);
    out.cycles.push(CycleOut { kinds, define, at, cancel, inline });
}

/// Reads a `<rule>`: blocks written before or after an event where its condition holds; one
/// without a condition, or with a wrong one, is left out.
fn read_rule(c: &Element, out: &mut Output, errors: &mut Errors) {
    shape(c, &["name", "when", "before", "after"], errors);
    let name = attr(c, "name").unwrap_or("").to_owned();
    let when = match attr(c, "when") {
        Some(w) => match parse_expr(w) {
            Ok(e) => e,
            Err(msg) => {
                errors.push((range(c, "when"), format!("`when`: {msg}")));
                return;
            }
        },
        None => {
            errors.push((c.range, "<rule> needs the attribute `when`".into()));
            return;
        }
    };
    let before = template(attr(c, "before").unwrap_or(""), range(c, "before"), &out.formats, errors);
    let after = template(attr(c, "after").unwrap_or(""), range(c, "after"), &out.formats, errors);
    out.rules.push(Rule { name, when, before, after });
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
            digits: 0,
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

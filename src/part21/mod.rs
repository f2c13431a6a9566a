//! ISO 10303-21 (STEP Part 21) exchange files: values, a deterministic writer and a reader.
//!
//! The writer ([`Stream`]) numbers entity instances in the order they are made and writes each
//! at once, so an export streams in bounded memory and equal content gives equal text.
//! The header's timestamp is a parameter: nothing here reads a clock.
//!
//! `mod.rs`: Part 21 values, a `Stream` that numbers instances in the order
//! they are made and writes each at once into any `io::Write` (every reference points back;
//! the root `PROJECT` comes last; a million-point polyline is written from an id range), so an
//! export runs in the plan's memory; the in-memory writer for an `Exchange` (shortest
//! round-trip reals, `\X2\` strings) and a reader with line:col errors. `schema.rs`: the ISO 14649 signature table (`iso14649_signatures.tsv`,
//! generated from the EXPRESS schema by `tests/it/stepnc.rs`) and `Schema::check` (names,
//! attribute counts, `$` only where OPTIONAL, entity types of references, enum literals).
//! `stepnc.rs`: plan ↔ ISO 14649 (CC1: toolpath features and freeform operations; CC2:
//! features, operations, strategies, with the toolpaths); facts ISO 14649 has no attribute for
//! travel as `key=value` words in `its_id`, so reading gives back the plan written.

pub mod schema;
pub mod stepnc;

use std::collections::BTreeMap;
use std::fmt::Write as _;

/// One attribute value.
#[derive(Clone, Debug, PartialEq)]
pub enum Value {
    /// `$`: an omitted optional value.
    Null,
    /// `*`: a value derived in a supertype.
    Derived,
    /// An integer.
    Int(i64),
    /// A real.
    Real(f64),
    /// A string.
    Str(String),
    /// An enumeration literal or boolean, without the dots (`T`, `CONTACT`).
    Enum(String),
    /// A reference to an instance.
    Ref(u64),
    /// A list, set or bag.
    List(Vec<Value>),
    /// A typed value of a select (`PARAMETER_VALUE(0.)`).
    Typed(String, Box<Value>),
}

impl Value {
    /// A boolean literal.
    pub fn bool(b: bool) -> Value {
        Value::Enum(if b { "T" } else { "F" }.into())
    }

    /// A real, or `$` when absent.
    pub fn opt_real(v: Option<f64>) -> Value {
        v.map_or(Value::Null, Value::Real)
    }

    /// A string value.
    pub fn str(s: impl Into<String>) -> Value {
        Value::Str(s.into())
    }

    /// As a real (integers widen).
    pub fn as_real(&self) -> Option<f64> {
        match self {
            Value::Real(v) => Some(*v),
            Value::Int(v) => Some(*v as f64),
            Value::Typed(_, v) => v.as_real(),
            _ => None,
        }
    }

    /// As a reference.
    pub fn as_ref_id(&self) -> Option<u64> {
        match self {
            Value::Ref(r) => Some(*r),
            _ => None,
        }
    }

    /// As a string.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Value::Str(s) => Some(s),
            _ => None,
        }
    }

    /// As an enumeration literal.
    pub fn as_enum(&self) -> Option<&str> {
        match self {
            Value::Enum(s) => Some(s),
            Value::Typed(_, v) => v.as_enum(),
            _ => None,
        }
    }

    /// As a list.
    pub fn as_list(&self) -> Option<&[Value]> {
        match self {
            Value::List(v) => Some(v),
            _ => None,
        }
    }
}

/// One entity instance.
#[derive(Clone, Debug, PartialEq)]
pub struct Instance {
    /// Entity name, upper case.
    pub name: String,
    /// Attributes in order, inherited ones first.
    pub attrs: Vec<Value>,
}

/// The header section.
#[derive(Clone, Debug, PartialEq)]
pub struct Header {
    /// FILE_DESCRIPTION description strings.
    pub description: Vec<String>,
    /// FILE_NAME name.
    pub name: String,
    /// FILE_NAME time stamp (ISO 8601).
    pub timestamp: String,
    /// FILE_NAME originating system.
    pub system: String,
    /// FILE_SCHEMA names.
    pub schemas: Vec<String>,
}

/// A whole exchange file.
#[derive(Clone, Debug, PartialEq)]
pub struct Exchange {
    /// Header.
    pub header: Header,
    /// Instances by id.
    pub instances: BTreeMap<u64, Instance>,
}

impl Exchange {
    /// The instance with this id.
    pub fn get(&self, id: u64) -> Option<&Instance> {
        self.instances.get(&id)
    }

    /// Ids of the instances of an entity, in id order.
    pub fn ids_of<'a>(&'a self, name: &'a str) -> impl Iterator<Item = u64> + 'a {
        self.instances.iter().filter(move |(_, i)| i.name == name).map(|(id, _)| *id)
    }
}

/// Writes an exchange file as its instances are made, in bounded memory: each instance is
/// numbered in the order it is added and written at once, so every reference points at an
/// instance written before it and equal content gives equal text. Output goes out in chunks;
/// the first write error is kept, later instances are numbered but not written, and
/// [`Stream::finish`] returns the error.
pub struct Stream<W: std::io::Write> {
    out: W,
    buf: String,
    next: u64,
    error: Option<std::io::Error>,
}

/// Output is handed to the writer in chunks of about this size.
const CHUNK: usize = 1 << 16;

impl<W: std::io::Write> Stream<W> {
    /// Starts a file: writes the header section and opens the data section.
    pub fn new(out: W, header: &Header) -> Stream<W> {
        let mut buf = String::with_capacity(CHUNK + 4096);
        write_header(&mut buf, header);
        Stream { out, buf, next: 0, error: None }
    }

    /// Writes an instance and returns a reference to it. References in `attrs` must point at
    /// instances added before.
    pub fn add(&mut self, name: &str, attrs: Vec<Value>) -> Value {
        self.next += 1;
        let _ = write!(self.buf, "#{}=", self.next);
        write_call(&mut self.buf, name, &attrs);
        self.spill();
        Value::Ref(self.next)
    }

    /// Writes an instance whose attributes are `head`, then one list of references, then
    /// `tail`: a polyline of a million points without a million values in memory.
    pub fn add_with_refs(&mut self, name: &str, head: &[Value], refs: impl IntoIterator<Item = u64>, tail: &[Value]) -> Value {
        self.next += 1;
        let _ = write!(self.buf, "#{}={name}(", self.next);
        write_values(&mut self.buf, head);
        if !head.is_empty() {
            self.buf.push(',');
        }
        self.buf.push('(');
        for (i, r) in refs.into_iter().enumerate() {
            if i > 0 {
                self.buf.push(',');
            }
            let _ = write!(self.buf, "#{r}");
            self.spill();
        }
        self.buf.push(')');
        if !tail.is_empty() {
            self.buf.push(',');
            write_values(&mut self.buf, tail);
        }
        self.buf.push_str(");\n");
        self.spill();
        Value::Ref(self.next)
    }

    /// The id the next instance will get.
    pub fn next_id(&self) -> u64 {
        self.next + 1
    }

    fn spill(&mut self) {
        if self.buf.len() >= CHUNK {
            self.flush_buf();
        }
    }

    fn flush_buf(&mut self) {
        if self.error.is_none()
            && let Err(e) = self.out.write_all(self.buf.as_bytes())
        {
            self.error = Some(e);
        }
        self.buf.clear();
    }

    /// Closes the data section and returns the writer, or the first write error.
    pub fn finish(mut self) -> std::io::Result<W> {
        self.buf.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
        self.flush_buf();
        match self.error.take() {
            Some(e) => Err(e),
            None => {
                self.out.flush()?;
                Ok(self.out)
            }
        }
    }
}

fn write_header(out: &mut String, h: &Header) {
    out.push_str("ISO-10303-21;\nHEADER;\n");
    let strings = |v: &[String]| v.iter().map(|s| Value::Str(s.clone())).collect::<Vec<_>>();
    write_call(out, "FILE_DESCRIPTION", &[Value::List(strings(&h.description)), Value::str("2;1")]);
    write_call(
        out,
        "FILE_NAME",
        &[
            Value::str(h.name.clone()),
            Value::str(h.timestamp.clone()),
            Value::List(vec![Value::str("")]),
            Value::List(vec![Value::str("")]),
            Value::str(h.system.clone()),
            Value::str(h.system.clone()),
            Value::str(""),
        ],
    );
    write_call(out, "FILE_SCHEMA", &[Value::List(strings(&h.schemas))]);
    out.push_str("ENDSEC;\nDATA;\n");
}

/// Writes an exchange file held in memory (one read back, say), instances in id order.
pub fn write(x: &Exchange) -> String {
    let mut out = String::with_capacity(64 * x.instances.len() + 512);
    write_header(&mut out, &x.header);
    for (id, inst) in &x.instances {
        let _ = write!(out, "#{id}=");
        write_call(&mut out, &inst.name, &inst.attrs);
    }
    out.push_str("ENDSEC;\nEND-ISO-10303-21;\n");
    out
}

fn write_call(out: &mut String, name: &str, attrs: &[Value]) {
    out.push_str(name);
    out.push('(');
    write_values(out, attrs);
    out.push_str(");\n");
}

fn write_values(out: &mut String, values: &[Value]) {
    for (i, v) in values.iter().enumerate() {
        if i > 0 {
            out.push(',');
        }
        write_value(out, v);
    }
}

fn write_value(out: &mut String, v: &Value) {
    match v {
        Value::Null => out.push('$'),
        Value::Derived => out.push('*'),
        Value::Int(i) => {
            let _ = write!(out, "{i}");
        }
        Value::Real(r) => write_real(out, *r),
        Value::Str(s) => write_string(out, s),
        Value::Enum(e) => {
            out.push('.');
            out.push_str(e);
            out.push('.');
        }
        Value::Ref(r) => {
            let _ = write!(out, "#{r}");
        }
        Value::List(l) => {
            out.push('(');
            write_values(out, l);
            out.push(')');
        }
        Value::Typed(name, inner) => {
            out.push_str(name);
            out.push('(');
            write_value(out, inner);
            out.push(')');
        }
    }
}

/// A real in Part 21 form: the shortest decimal that reads back to the same `f64`, always
/// with a decimal point (`1.`, `0.25`, `-1.5E-7`).
pub fn write_real(out: &mut String, r: f64) {
    let r = if r.is_finite() { r } else { 0.0 };
    let r = if r == 0.0 { 0.0 } else { r };
    let s = format!("{r:?}");
    let (mantissa, exp) = match s.split_once('e') {
        Some((m, e)) => (m, Some(e)),
        None => (s.as_str(), None),
    };
    let mantissa = mantissa.strip_suffix(".0").unwrap_or(mantissa);
    out.push_str(mantissa);
    if !mantissa.contains('.') {
        out.push('.');
    }
    if let Some(e) = exp {
        out.push('E');
        out.push_str(e);
    }
}

fn write_string(out: &mut String, s: &str) {
    out.push('\'');
    for c in s.chars() {
        match c {
            '\'' => out.push_str("''"),
            '\\' => out.push_str("\\\\"),
            ' '..='~' => out.push(c),
            c => {
                let mut buf = [0u16; 2];
                out.push_str("\\X2\\");
                for u in c.encode_utf16(&mut buf) {
                    let _ = write!(out, "{u:04X}");
                }
                out.push_str("\\X0\\");
            }
        }
    }
    out.push('\'');
}

/// A Part 21 syntax error.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ParseError {
    /// 1-based line.
    pub line: u32,
    /// 1-based column (bytes).
    pub col: u32,
    /// What is wrong.
    pub message: String,
}

impl std::fmt::Display for ParseError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}: {}", self.line, self.col, self.message)
    }
}

impl std::error::Error for ParseError {}

/// Reads an exchange file.
pub fn parse(text: &str) -> Result<Exchange, ParseError> {
    let mut p = Parser { s: text.as_bytes(), i: 0 };
    p.skip_ws();
    p.expect_word("ISO-10303-21")?;
    p.expect(b';')?;
    p.skip_ws();
    p.expect_word("HEADER")?;
    p.expect(b';')?;
    let mut header =
        Header { description: Vec::new(), name: String::new(), timestamp: String::new(), system: String::new(), schemas: Vec::new() };
    loop {
        p.skip_ws();
        let word = p.keyword()?;
        if word == "ENDSEC" {
            p.expect(b';')?;
            break;
        }
        let attrs = p.args()?;
        p.expect(b';')?;
        let strings = |v: Option<&Value>| -> Vec<String> {
            v.and_then(Value::as_list).map(|l| l.iter().filter_map(|s| s.as_str().map(str::to_owned)).collect()).unwrap_or_default()
        };
        match word.as_str() {
            "FILE_DESCRIPTION" => header.description = strings(attrs.first()),
            "FILE_NAME" => {
                header.name = attrs.first().and_then(Value::as_str).unwrap_or_default().to_owned();
                header.timestamp = attrs.get(1).and_then(Value::as_str).unwrap_or_default().to_owned();
                header.system = attrs.get(4).and_then(Value::as_str).unwrap_or_default().to_owned();
            }
            "FILE_SCHEMA" => header.schemas = strings(attrs.first()),
            _ => {}
        }
    }
    p.skip_ws();
    p.expect_word("DATA")?;
    p.expect(b';')?;
    let mut instances = BTreeMap::new();
    loop {
        p.skip_ws();
        if p.peek() == Some(b'E') {
            p.expect_word("ENDSEC")?;
            p.expect(b';')?;
            break;
        }
        p.expect(b'#')?;
        let id = p.integer()? as u64;
        p.skip_ws();
        p.expect(b'=')?;
        p.skip_ws();
        if p.peek() == Some(b'(') {
            return Err(p.error("complex entity instances are not supported"));
        }
        let name = p.keyword()?;
        let attrs = p.args()?;
        p.expect(b';')?;
        if instances.insert(id, Instance { name, attrs }).is_some() {
            return Err(p.error(&format!("instance #{id} is defined twice")));
        }
    }
    p.skip_ws();
    p.expect_word("END-ISO-10303-21")?;
    p.expect(b';')?;
    Ok(Exchange { header, instances })
}

struct Parser<'a> {
    s: &'a [u8],
    i: usize,
}

impl Parser<'_> {
    fn error(&self, message: &str) -> ParseError {
        let before = &self.s[..self.i.min(self.s.len())];
        let line = before.iter().filter(|b| **b == b'\n').count() as u32 + 1;
        let col = (before.len() - before.iter().rposition(|b| *b == b'\n').map_or(0, |p| p + 1)) as u32 + 1;
        ParseError { line, col, message: message.to_owned() }
    }

    fn peek(&self) -> Option<u8> {
        self.s.get(self.i).copied()
    }

    fn skip_ws(&mut self) {
        loop {
            while self.peek().is_some_and(|b| b.is_ascii_whitespace()) {
                self.i += 1;
            }
            if self.s[self.i.min(self.s.len())..].starts_with(b"/*") {
                match self.s[self.i + 2..].windows(2).position(|w| w == b"*/") {
                    Some(p) => self.i += p + 4,
                    None => self.i = self.s.len(),
                }
            } else {
                return;
            }
        }
    }

    fn expect(&mut self, b: u8) -> Result<(), ParseError> {
        self.skip_ws();
        if self.peek() == Some(b) {
            self.i += 1;
            Ok(())
        } else {
            Err(self.error(&format!("expected `{}`", b as char)))
        }
    }

    fn expect_word(&mut self, w: &str) -> Result<(), ParseError> {
        if self.s[self.i..].starts_with(w.as_bytes()) {
            self.i += w.len();
            Ok(())
        } else {
            Err(self.error(&format!("expected `{w}`")))
        }
    }

    fn keyword(&mut self) -> Result<String, ParseError> {
        self.skip_ws();
        let start = self.i;
        while self.peek().is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_' || b == b'-') {
            self.i += 1;
        }
        if start == self.i {
            return Err(self.error("expected a keyword"));
        }
        Ok(String::from_utf8_lossy(&self.s[start..self.i]).to_ascii_uppercase())
    }

    fn integer(&mut self) -> Result<i64, ParseError> {
        let start = self.i;
        while self.peek().is_some_and(|b| b.is_ascii_digit()) {
            self.i += 1;
        }
        std::str::from_utf8(&self.s[start..self.i]).ok().and_then(|s| s.parse().ok()).ok_or_else(|| self.error("expected an integer"))
    }

    fn args(&mut self) -> Result<Vec<Value>, ParseError> {
        self.expect(b'(')?;
        let mut out = Vec::new();
        self.skip_ws();
        if self.peek() == Some(b')') {
            self.i += 1;
            return Ok(out);
        }
        loop {
            out.push(self.value()?);
            self.skip_ws();
            match self.peek() {
                Some(b',') => self.i += 1,
                Some(b')') => {
                    self.i += 1;
                    return Ok(out);
                }
                _ => return Err(self.error("expected `,` or `)`")),
            }
        }
    }

    fn value(&mut self) -> Result<Value, ParseError> {
        self.skip_ws();
        match self.peek() {
            Some(b'$') => {
                self.i += 1;
                Ok(Value::Null)
            }
            Some(b'*') => {
                self.i += 1;
                Ok(Value::Derived)
            }
            Some(b'#') => {
                self.i += 1;
                Ok(Value::Ref(self.integer()? as u64))
            }
            Some(b'(') => Ok(Value::List(self.args()?)),
            Some(b'.') => {
                self.i += 1;
                let start = self.i;
                while self.peek().is_some_and(|b| b.is_ascii_alphanumeric() || b == b'_') {
                    self.i += 1;
                }
                let e = String::from_utf8_lossy(&self.s[start..self.i]).into_owned();
                self.expect(b'.')?;
                Ok(Value::Enum(e))
            }
            Some(b'\'') => self.string(),
            Some(b) if b.is_ascii_digit() || b == b'-' || b == b'+' => self.number(),
            Some(b) if b.is_ascii_alphabetic() => {
                let name = self.keyword()?;
                self.expect(b'(')?;
                let inner = self.value()?;
                self.expect(b')')?;
                Ok(Value::Typed(name, Box::new(inner)))
            }
            _ => Err(self.error("expected a value")),
        }
    }

    fn number(&mut self) -> Result<Value, ParseError> {
        let start = self.i;
        if matches!(self.peek(), Some(b'-' | b'+')) {
            self.i += 1;
        }
        let mut real = false;
        while let Some(b) = self.peek() {
            match b {
                b'0'..=b'9' => {}
                b'.' => real = true,
                b'E' | b'e' => {
                    real = true;
                    if matches!(self.s.get(self.i + 1), Some(b'-' | b'+')) {
                        self.i += 1;
                    }
                }
                _ => break,
            }
            self.i += 1;
        }
        let text = std::str::from_utf8(&self.s[start..self.i]).unwrap_or("");
        if real {
            // Rust reads `1.` and `1.E5`: insert the missing zero for the exponent form.
            let fixed = text.replace(".E", ".0E").replace(".e", ".0e");
            fixed.parse().map(Value::Real).map_err(|_| self.error(&format!("malformed real `{text}`")))
        } else {
            text.parse().map(Value::Int).map_err(|_| self.error(&format!("malformed integer `{text}`")))
        }
    }

    fn string(&mut self) -> Result<Value, ParseError> {
        self.i += 1;
        let mut out = String::new();
        loop {
            match self.peek() {
                None => return Err(self.error("unterminated string")),
                Some(b'\'') if self.s.get(self.i + 1) == Some(&b'\'') => {
                    out.push('\'');
                    self.i += 2;
                }
                Some(b'\'') => {
                    self.i += 1;
                    return Ok(Value::Str(out));
                }
                Some(b'\\') if self.s[self.i..].starts_with(b"\\\\") => {
                    out.push('\\');
                    self.i += 2;
                }
                Some(b'\\') if self.s[self.i..].starts_with(b"\\X2\\") => {
                    self.i += 4;
                    let start = self.i;
                    let end = self.s[start..].windows(4).position(|w| w == b"\\X0\\").ok_or_else(|| self.error("unterminated \\X2\\"))?;
                    let hex = std::str::from_utf8(&self.s[start..start + end]).unwrap_or("");
                    let units: Vec<u16> = (0..hex.len() / 4).filter_map(|k| u16::from_str_radix(&hex[4 * k..4 * k + 4], 16).ok()).collect();
                    out.push_str(&String::from_utf16_lossy(&units));
                    self.i = start + end + 4;
                }
                Some(b'\\') if self.s[self.i..].starts_with(b"\\X\\") && self.s.len() >= self.i + 5 => {
                    let hex = std::str::from_utf8(&self.s[self.i + 3..self.i + 5]).unwrap_or("");
                    out.push(u8::from_str_radix(hex, 16).map_or('?', char::from));
                    self.i += 5;
                }
                Some(b) => {
                    // One UTF-8 character (the standard wants ASCII; be lenient).
                    let len = match b {
                        0xF0..=0xF7 => 4,
                        0xE0..=0xEF => 3,
                        0xC0..=0xDF => 2,
                        _ => 1,
                    };
                    let end = (self.i + len).min(self.s.len());
                    match std::str::from_utf8(&self.s[self.i..end]) {
                        Ok(c) => {
                            out.push_str(c);
                            self.i = end;
                        }
                        Err(_) => {
                            out.push('\u{FFFD}');
                            self.i += 1;
                        }
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reals_round_trip_with_a_point() {
        for (v, s) in [(1.0, "1."), (0.25, "0.25"), (-3.5, "-3.5"), (1e-7, "1.E-7"), (0.0, "0."), (-0.0, "0."), (240.0, "240.")] {
            let mut out = String::new();
            write_real(&mut out, v);
            assert_eq!(out, s);
        }
        let header = Header {
            description: vec!["d".into()],
            name: "n".into(),
            timestamp: "2026-01-01T00:00:00".into(),
            system: "ncplan".into(),
            schemas: vec!["S".into()],
        };
        let mut b = Stream::new(Vec::new(), &header);
        let p = b.add(
            "CARTESIAN_POINT",
            vec![Value::str("it's \\ ø"), Value::List(vec![Value::Real(0.1), Value::Real(1e-7), Value::Real(123456.789)])],
        );
        let q = b.add("CARTESIAN_POINT", vec![Value::str(""), Value::List(vec![Value::Real(1.0), Value::Real(2.0), Value::Real(3.0)])]);
        let line = b.add_with_refs("POLYLINE", &[Value::str("")], [1, 2], &[]);
        b.add(
            "ROOT",
            vec![p, line, Value::Null, Value::Enum("T".into()), Value::Typed("PARAMETER_VALUE".into(), Box::new(Value::Real(90.0)))],
        );
        assert_eq!(q, Value::Ref(2));
        let text = String::from_utf8(b.finish().unwrap()).unwrap();
        let x = parse(&text).unwrap();
        // Numbered in the order added, each reference to an instance before it.
        assert_eq!(x.get(3).unwrap().name, "POLYLINE");
        assert_eq!(x.get(3).unwrap().attrs[1], Value::List(vec![Value::Ref(1), Value::Ref(2)]));
        assert_eq!(x.get(4).unwrap().name, "ROOT");
        assert_eq!(write(&x), text);
    }

    #[test]
    fn a_write_error_is_returned_once_at_the_end() {
        #[derive(Debug)]
        struct Full;
        impl std::io::Write for Full {
            fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
                Err(std::io::Error::other("disk full"))
            }
            fn flush(&mut self) -> std::io::Result<()> {
                Ok(())
            }
        }
        let header = Header { description: vec![], name: "n".into(), timestamp: "t".into(), system: "s".into(), schemas: vec![] };
        let mut b = Stream::new(Full, &header);
        for _ in 0..10_000 {
            b.add("CARTESIAN_POINT", vec![Value::str("a long name to fill the buffer quickly"), Value::Real(1.0)]);
        }
        assert_eq!(b.finish().unwrap_err().to_string(), "disk full");
    }

    #[test]
    fn parse_errors_have_positions() {
        let e = parse("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1=A(1,;\nENDSEC;\nEND-ISO-10303-21;\n").unwrap_err();
        assert_eq!((e.line, e.col), (5, 8), "{e}");
        assert!(parse("ISO-10303-21;\nHEADER;\nENDSEC;\nDATA;\n#1=A('x);").is_err());
    }
}

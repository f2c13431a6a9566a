//! A small XML element tree with byte positions, read with quick-xml.
//!
//! The loader validates this tree, so every error can point at the element or attribute
//! it is about.

use quick_xml::events::{BytesStart, Event};
use quick_xml::reader::Reader;

use crate::text::TextRange;

/// An attribute and where its value sits.
#[derive(Clone, Debug)]
pub(super) struct Attr {
    pub(super) name: String,
    pub(super) value: String,
    pub(super) range: TextRange,
}

/// An element with its attributes, children and text.
#[derive(Clone, Debug, Default)]
pub(super) struct Element {
    pub(super) name: String,
    pub(super) attrs: Vec<Attr>,
    pub(super) children: Vec<Element>,
    pub(super) text: String,
    pub(super) range: TextRange,
}

/// Parses `text` into its root element, or returns the position and reason of the first
/// well-formedness error.
pub(super) fn parse(text: &str) -> Result<Element, (TextRange, String)> {
    let mut reader = Reader::from_str(text);
    reader.config_mut().check_end_names = true;
    let mut stack: Vec<Element> = Vec::new();
    let mut root: Option<Element> = None;
    loop {
        let before = reader.buffer_position() as usize;
        let event = reader.read_event().map_err(|e| {
            let at = reader.error_position() as usize;
            (TextRange::new(at, at + 1), format!("malformed XML: {e}"))
        })?;
        let after = reader.buffer_position() as usize;
        match event {
            Event::Start(start) => stack.push(element(text, &start, before, after)?),
            Event::Empty(start) => {
                let el = element(text, &start, before, after)?;
                attach(&mut stack, &mut root, el, before)?;
            }
            Event::End(_) => {
                let Some(el) = stack.pop() else {
                    return Err((TextRange::new(before, after), "unexpected closing tag".into()));
                };
                attach(&mut stack, &mut root, el, before)?;
            }
            Event::Text(t) => {
                if let Some(top) = stack.last_mut() {
                    let s = t.unescape().map_err(|e| (TextRange::new(before, after), e.to_string()))?;
                    top.text.push_str(&s);
                }
            }
            Event::CData(t) => {
                if let Some(top) = stack.last_mut() {
                    top.text.push_str(&String::from_utf8_lossy(&t));
                }
            }
            Event::Eof => break,
            _ => {}
        }
    }
    if let Some(open) = stack.pop() {
        return Err((open.range, format!("element <{}> is not closed", open.name)));
    }
    root.ok_or((TextRange::default(), "the file has no root element".into()))
}

fn attach(stack: &mut [Element], root: &mut Option<Element>, el: Element, at: usize) -> Result<(), (TextRange, String)> {
    match stack.last_mut() {
        Some(parent) => parent.children.push(el),
        None if root.is_none() => *root = Some(el),
        None => return Err((TextRange::new(at, at + 1), "more than one root element".into())),
    }
    Ok(())
}

fn element(text: &str, start: &BytesStart<'_>, before: usize, after: usize) -> Result<Element, (TextRange, String)> {
    let range = TextRange::new(before, after);
    let name = String::from_utf8_lossy(start.local_name().as_ref()).into_owned();
    let tag = &text[before..after];
    let mut attrs = Vec::new();
    for a in start.attributes() {
        let a = a.map_err(|e| (range, format!("malformed attribute: {e}")))?;
        let key = String::from_utf8_lossy(a.key.as_ref()).into_owned();
        if key == "xmlns" || key.starts_with("xmlns:") || key.starts_with("xsi:") {
            continue;
        }
        let value = a.unescape_value().map_err(|e| (range, e.to_string()))?.into_owned();
        let range = tag.find(&format!("{key}=")).map_or(range, |i| TextRange::new(before + i, before + i + key.len()));
        attrs.push(Attr { name: key, value, range });
    }
    Ok(Element { name, attrs, children: Vec::new(), text: String::new(), range })
}

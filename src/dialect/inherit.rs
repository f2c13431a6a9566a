//! `<dialect extends="fanuc">`: a dialect written as the differences from another.
//!
//! The merge works on the element trees before validation, so the loader sees one complete
//! dialect and checks it as usual. The rules, applied section by section:
//!
//! - Attributes: the derived element's win; the base's others are kept.
//! - `<lexical>`, `<behaviour>`, `<addresses>`, `<macros>`, `<groups>`, `<group>` and
//!   `<cycles>`, `<vocabulary>` and `<output>` merge their children by key: an entry with the same element name and the
//!   same key attribute (the first of `id`, `value`, `keyword`, `number`, `open`, `char`, `name`, `prefix` and `codes`) replaces the
//!   base's in place; a new one is added at the end.
//! - Every other element (`<code>`, `<cycle>`, `<execution-order>`, …) is replaced whole.
//! - `<remove value="56"/>` (or `name`, `id`, `keyword`, `number`, `char`) among the entries deletes
//!   the base's entry with that key, whatever its element name (Okuma's G56 is not a work
//!   offset, so it leaves Fanuc's work-offset group before joining another).
//! - `<description>` and `<recognise>` are never inherited: a derived dialect has its own
//!   evidence, else sniffing could never tell it from its base.
//!
//! Inherited elements point at the `extends` attribute, so an error in them is reported
//! there rather than at a position in some other file.

use super::xml::{Attr, Element};
use crate::text::TextRange;

/// Elements whose children merge by key instead of being replaced whole.
const MERGED: &[&str] = &["dialect", "lexical", "behaviour", "addresses", "macros", "groups", "group", "cycles", "vocabulary", "output"];

/// Sections a derived dialect never takes from its base.
const OWN: &[&str] = &["description", "recognise"];

/// Attributes a derived dialect never takes from its base.
const OWN_ATTRS: &[&str] = &["name", "title", "extends"];

/// The attribute that tells entries apart among siblings of one element name.
const KEYS: &[&str] = &["id", "value", "keyword", "number", "open", "char", "name", "prefix", "codes"];

fn key(el: &Element) -> (&str, Option<&str>) {
    let k = KEYS.iter().find_map(|k| el.attrs.iter().find(|a| a.name == *k)).map(|a| a.value.as_str());
    (el.name.as_str(), k)
}

/// Points every range in `el` at `at`.
fn relocate(mut el: Element, at: TextRange) -> Element {
    el.range = at;
    for a in &mut el.attrs {
        a.range = at;
    }
    el.children = el.children.into_iter().map(|c| relocate(c, at)).collect();
    el
}

/// `derived` laid over `base` (a copy of the base's tree, taken apart here). Inherited parts
/// are relocated to `at`.
pub(super) fn merge(base: Element, derived: Element, at: TextRange, errors: &mut Vec<(TextRange, String)>) -> Element {
    let is_root = derived.name == "dialect";
    let mut attrs: Vec<Attr> = base
        .attrs
        .into_iter()
        .filter(|a| !(is_root && OWN_ATTRS.contains(&a.name.as_str())))
        .filter(|a| !derived.attrs.iter().any(|d| d.name == a.name))
        .map(|a| Attr { range: at, ..a })
        .collect();
    let mut children: Vec<Element> =
        base.children.into_iter().filter(|c| !(is_root && OWN.contains(&c.name.as_str()))).map(|c| relocate(c, at)).collect();
    for child in derived.children {
        if child.name == "remove" {
            let k = key(&child).1;
            match children.iter().position(|c| k.is_some() && key(c).1 == k) {
                Some(i) => {
                    children.remove(i);
                }
                None => errors.push((child.range, format!("<remove> names no entry of <{}> in the base dialect", derived.name))),
            }
            continue;
        }
        let slot = children.iter().position(|c| key(c) == key(&child));
        match slot {
            Some(i) if MERGED.contains(&child.name.as_str()) => {
                let inherited = std::mem::take(&mut children[i]);
                children[i] = merge(inherited, child, at, errors);
            }
            Some(i) => children[i] = child,
            None => children.push(child),
        }
    }
    attrs.extend(derived.attrs.into_iter().filter(|a| !(is_root && a.name == "extends")));
    Element {
        name: derived.name,
        attrs,
        children,
        text: if derived.text.trim().is_empty() { base.text } else { derived.text },
        range: derived.range,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dialect::xml::parse;

    fn attr<'a>(el: &'a Element, name: &str) -> Option<&'a str> {
        el.attrs.iter().find(|a| a.name == name).map(|a| a.value.as_str())
    }

    #[test]
    fn entries_merge_by_key_and_the_rest_is_replaced() {
        let base = parse(
            r#"<dialect name="a" family="f" title="A"><description>A</description>
            <lexical block-form="word-address"><comment open="(" close=")"/><block-end char=";"/></lexical>
            <groups><group id="motion" letter="G"><code value="0" meaning="rapid"/><code value="1" meaning="linear"/></group></groups>
            <execution-order>motion</execution-order><recognise><extension name="a" weight="1"/></recognise></dialect>"#,
        )
        .unwrap();
        let derived = parse(
            r#"<dialect name="b" extends="a"><lexical spaces-in-numbers="true"><comment open=";"/></lexical>
            <groups><group id="motion" letter="G"><code value="1" meaning="rapid"/></group><group id="x" letter="M"/></groups></dialect>"#,
        )
        .unwrap();
        let at = TextRange::new(20, 29);
        let mut errors = Vec::new();
        let m = merge(base, derived, at, &mut errors);
        assert!(errors.is_empty());
        assert_eq!(attr(&m, "name"), Some("b"));
        assert_eq!(attr(&m, "family"), Some("f"));
        assert_eq!(attr(&m, "title"), None);
        assert_eq!(attr(&m, "extends"), None);
        let names: Vec<&str> = m.children.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names, ["lexical", "groups", "execution-order"]);
        let lexical = &m.children[0];
        assert_eq!(attr(lexical, "block-form"), Some("word-address"));
        assert_eq!(attr(lexical, "spaces-in-numbers"), Some("true"));
        assert_eq!(lexical.children.len(), 3, "the ( comment and block end are kept, the ; comment added");
        let motion = &m.children[1].children[0];
        assert_eq!(motion.children.len(), 2);
        assert_eq!(attr(&motion.children[0], "meaning"), Some("rapid"));
        assert_eq!(motion.children[0].range, at, "inherited entries point at `extends`");
        assert_eq!(attr(&motion.children[1], "meaning"), Some("rapid"), "G1 replaced");
        assert_ne!(motion.children[1].range, at);
        assert_eq!(m.children[1].children[1].name, "group");
        assert_eq!(m.children[2].text.trim(), "motion");
    }
}

//! Entity signatures of the ISO 14649 EXPRESS schema, and a conformance check of exchange
//! files against them.
//!
//! `iso14649_signatures.tsv` is generated from the EXPRESS schema in
//! `../shared/reference/stepnc/` by the test `stepnc::signatures_are_generated_from_express`
//! (`UPDATE_EXPECT=1` rewrites it). Each entity lists its attributes flattened in Part 21
//! order, inherited ones first; each defined type says whether it is a select, an
//! enumeration or another type.

use std::collections::BTreeMap;
use std::sync::OnceLock;

use super::{Exchange, Value};

/// One attribute of an entity.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Attr {
    /// Attribute name.
    pub name: String,
    /// Whether `$` is allowed.
    pub optional: bool,
    /// Type: a lower-case type or entity name, each `[` in front one aggregate level.
    pub ty: String,
}

/// An entity's signature.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Entity {
    /// Whether it is abstract (never instantiated).
    pub is_abstract: bool,
    /// Direct supertypes.
    pub supertypes: Vec<String>,
    /// Attributes in Part 21 order.
    pub attrs: Vec<Attr>,
}

/// A defined type.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Type {
    /// A select of these types.
    Select(Vec<String>),
    /// An enumeration of these literals.
    Enumeration(Vec<String>),
    /// Another type (`length_measure = REAL`).
    Alias(String),
}

/// The signatures of one schema.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Schema {
    /// Entities by lower-case name.
    pub entities: BTreeMap<String, Entity>,
    /// Defined types by lower-case name.
    pub types: BTreeMap<String, Type>,
}

/// The ISO 14649 signatures ncplan writes against.
pub fn iso14649() -> &'static Schema {
    static S: OnceLock<Schema> = OnceLock::new();
    S.get_or_init(|| Schema::from_tsv(include_str!("iso14649_signatures.tsv")))
}

impl Schema {
    /// Reads the table format [`Schema::to_tsv`] writes.
    pub fn from_tsv(text: &str) -> Schema {
        let mut s = Schema::default();
        for line in text.lines().filter(|l| !l.starts_with('#') && !l.is_empty()) {
            let f: Vec<&str> = line.split('\t').collect();
            let list = |i: usize| -> Vec<String> {
                f.get(i).map(|x| x.split(',').filter(|y| !y.is_empty()).map(str::to_owned).collect()).unwrap_or_default()
            };
            match f.first() {
                Some(&"E") => {
                    let attrs = list(4)
                        .iter()
                        .filter_map(|a| {
                            let mut p = a.splitn(3, ':');
                            let name = p.next()?.to_owned();
                            let optional = p.next()? == "o";
                            let ty = p.next()?.to_owned();
                            Some(Attr { name, optional, ty })
                        })
                        .collect();
                    s.entities.insert(f[1].to_owned(), Entity { is_abstract: f.get(2) == Some(&"1"), supertypes: list(3), attrs });
                }
                Some(&"T") => {
                    let t = match f.get(2) {
                        Some(&"select") => Type::Select(list(3)),
                        Some(&"enum") => Type::Enumeration(list(3)),
                        _ => Type::Alias(f.get(3).unwrap_or(&"").to_string()),
                    };
                    s.types.insert(f[1].to_owned(), t);
                }
                _ => {}
            }
        }
        s
    }

    /// Writes the table.
    pub fn to_tsv(&self, source: &str) -> String {
        let mut out = format!(
            "# Generated from {source} by the test stepnc::signatures_are_generated_from_express;\n# UPDATE_EXPECT=1 rewrites it. E name abstract supertypes attributes(name:o|m:type); T name kind members.\n"
        );
        for (name, e) in &self.entities {
            let attrs: Vec<String> =
                e.attrs.iter().map(|a| format!("{}:{}:{}", a.name, if a.optional { "o" } else { "m" }, a.ty)).collect();
            out.push_str(&format!("E\t{name}\t{}\t{}\t{}\n", u8::from(e.is_abstract), e.supertypes.join(","), attrs.join(",")));
        }
        for (name, t) in &self.types {
            let (kind, members) = match t {
                Type::Select(m) => ("select", m.join(",")),
                Type::Enumeration(m) => ("enum", m.join(",")),
                Type::Alias(a) => ("alias", a.clone()),
            };
            out.push_str(&format!("T\t{name}\t{kind}\t{members}\n"));
        }
        out
    }

    /// Whether entity `name` is `ancestor` or one of its subtypes.
    pub fn is_a(&self, name: &str, ancestor: &str) -> bool {
        if name == ancestor {
            return true;
        }
        self.entities.get(name).is_some_and(|e| e.supertypes.iter().any(|s| self.is_a(s, ancestor)))
    }

    /// Checks every instance of `x`: a known, instantiable entity; the right number of
    /// attributes; `$` only in optional slots; values of the declared types (references to
    /// the right entities, enumeration literals the type has). Returns one message per
    /// finding, `#id NAME: …`.
    pub fn check(&self, x: &Exchange) -> Vec<String> {
        let mut out = Vec::new();
        for (id, inst) in &x.instances {
            let name = inst.name.to_ascii_lowercase();
            let Some(e) = self.entities.get(&name) else {
                out.push(format!("#{id} {}: unknown entity", inst.name));
                continue;
            };
            if e.is_abstract {
                out.push(format!("#{id} {}: abstract entity instantiated", inst.name));
            }
            if e.attrs.len() != inst.attrs.len() {
                out.push(format!("#{id} {}: {} attributes, the schema has {}", inst.name, inst.attrs.len(), e.attrs.len()));
                continue;
            }
            for (a, v) in e.attrs.iter().zip(&inst.attrs) {
                if let Err(why) = self.value(x, v, &a.ty, a.optional) {
                    out.push(format!("#{id} {}.{}: {why}", inst.name, a.name));
                }
            }
        }
        out
    }

    fn value(&self, x: &Exchange, v: &Value, ty: &str, optional: bool) -> Result<(), String> {
        match v {
            Value::Null if optional => return Ok(()),
            Value::Null => return Err("`$` in a mandatory attribute".into()),
            Value::Derived => return Err("`*` is not expected".into()),
            _ => {}
        }
        if let Some(elem) = ty.strip_prefix('[') {
            let Value::List(items) = v else { return Err(format!("expected an aggregate of {elem}")) };
            return items.iter().try_for_each(|i| self.value(x, i, elem, false));
        }
        match ty {
            "real" | "number" => return if v.as_real().is_some() { Ok(()) } else { Err(format!("expected a real, found {}", brief(v))) },
            "integer" => return if matches!(v, Value::Int(_)) { Ok(()) } else { Err(format!("expected an integer, found {}", brief(v))) },
            "string" => return if matches!(v, Value::Str(_)) { Ok(()) } else { Err(format!("expected a string, found {}", brief(v))) },
            "boolean" | "logical" => {
                let ok = matches!(v.as_enum(), Some("T" | "F")) || ty == "logical" && v.as_enum() == Some("U");
                return if ok { Ok(()) } else { Err(format!("expected a {ty}, found {}", brief(v))) };
            }
            _ => {}
        }
        if self.entities.contains_key(ty) {
            let Value::Ref(r) = v else { return Err(format!("expected a reference to {ty}, found {}", brief(v))) };
            let Some(target) = x.get(*r) else { return Err(format!("#{r} is not defined")) };
            let tname = target.name.to_ascii_lowercase();
            return if self.is_a(&tname, ty) { Ok(()) } else { Err(format!("#{r} is {}, not a {ty}", target.name)) };
        }
        match self.types.get(ty) {
            Some(Type::Alias(a)) => self.value(x, v, a, false),
            Some(Type::Enumeration(lits)) => match v.as_enum() {
                Some(e) if lits.iter().any(|l| l.eq_ignore_ascii_case(e)) => Ok(()),
                _ => Err(format!("expected one of .{}., found {}", lits.join(".|.").to_ascii_uppercase(), brief(v))),
            },
            Some(Type::Select(members)) => {
                if let Value::Typed(name, inner) = v {
                    let n = name.to_ascii_lowercase();
                    return if self.select_has(members, &n) {
                        self.value(x, inner, &n, false)
                    } else {
                        Err(format!("{name} is not in the select {ty}"))
                    };
                }
                if members.iter().any(|m| self.value(x, v, m, false).is_ok()) {
                    Ok(())
                } else {
                    Err(format!("{} fits no member of the select {ty}", brief(v)))
                }
            }
            None => Err(format!("type {ty} is not in the schema")),
        }
    }

    fn select_has(&self, members: &[String], name: &str) -> bool {
        members.iter().any(|m| m == name || matches!(self.types.get(m), Some(Type::Select(inner)) if self.select_has(inner, name)))
    }
}

/// A short description of a value for messages (aggregates can be huge).
fn brief(v: &Value) -> String {
    match v {
        Value::List(items) => format!("a list of {}", items.len()),
        Value::Typed(name, _) => format!("{name}(..)"),
        Value::Str(s) if s.len() > 40 => "a long string".into(),
        other => format!("{other:?}"),
    }
}

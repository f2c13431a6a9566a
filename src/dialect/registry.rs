//! The set of known dialects: the shipped ones, compiled in, plus any a user adds.

use std::collections::BTreeMap;
use std::sync::Arc;

use super::{Dialect, load};
use crate::diag::{self, Diagnostic};
use crate::text::LineIndex;

/// The dialect files shipped in `dialects/`, compiled into the binary.
pub const SHIPPED: &[(&str, &str)] = &[
    ("linuxcnc.xml", include_str!("../../dialects/linuxcnc.xml")),
    ("fanuc.xml", include_str!("../../dialects/fanuc.xml")),
    ("siemens.xml", include_str!("../../dialects/siemens.xml")),
    ("heidenhain.xml", include_str!("../../dialects/heidenhain.xml")),
];

/// Known dialects by name, in name order.
#[derive(Clone, Debug, Default)]
pub struct Registry {
    dialects: BTreeMap<String, Arc<Dialect>>,
}

impl Registry {
    /// The shipped dialects. A shipped file that fails to load is a build defect, caught by
    /// the test suite; it is left out here rather than crashing.
    pub fn shipped() -> Registry {
        let mut r = Registry::default();
        for (origin, text) in SHIPPED {
            let _ = r.add(origin, text);
        }
        r
    }

    /// Loads a dialect from `text` (read from `origin`) and adds or replaces it by name.
    /// On failure, returns the rendered diagnostics (`origin:line:col: ...`).
    pub fn add(&mut self, origin: &str, text: &str) -> Result<Arc<Dialect>, Vec<String>> {
        let (dialect, diags) = load(text);
        let render = |ds: &[Diagnostic]| {
            let idx = LineIndex::new(text);
            ds.iter().map(|d| diag::render_short(origin, text, &idx, d)).collect::<Vec<_>>()
        };
        match dialect {
            Some(d) => {
                let d = Arc::new(d);
                self.dialects.insert(d.name.clone(), Arc::clone(&d));
                Ok(d)
            }
            None => Err(render(&diags)),
        }
    }

    /// The dialect called `name`.
    pub fn get(&self, name: &str) -> Option<Arc<Dialect>> {
        self.dialects.get(name).cloned()
    }

    /// Names, sorted.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        self.dialects.keys().map(String::as_str)
    }
}

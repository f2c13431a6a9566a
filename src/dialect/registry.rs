//! The set of known dialects: the shipped ones, compiled in, plus any a user adds.

use std::collections::BTreeMap;
use std::sync::Arc;

use super::xml::Element;
use super::{Dialect, load::load_tree};
use crate::diag;
use crate::text::LineIndex;

/// The dialect files shipped in `dialects/`, compiled into the binary.
pub const SHIPPED: &[(&str, &str)] = &[
    ("linuxcnc.xml", include_str!("../../dialects/linuxcnc.xml")),
    ("fanuc.xml", include_str!("../../dialects/fanuc.xml")),
    ("cldata.xml", include_str!("../../dialects/cldata.xml")),
    ("siemens.xml", include_str!("../../dialects/siemens.xml")),
    ("heidenhain.xml", include_str!("../../dialects/heidenhain.xml")),
    // Derived dialects come after their bases.
    ("heidenhain_iso.xml", include_str!("../../dialects/heidenhain_iso.xml")),
    ("haas.xml", include_str!("../../dialects/haas.xml")),
    ("mitsubishi.xml", include_str!("../../dialects/mitsubishi.xml")),
    ("mazak.xml", include_str!("../../dialects/mazak.xml")),
    ("okuma.xml", include_str!("../../dialects/okuma.xml")),
    ("okuma_lathe.xml", include_str!("../../dialects/okuma_lathe.xml")),
    ("fanuc_lathe.xml", include_str!("../../dialects/fanuc_lathe.xml")),
    ("fanuc_lathe_b.xml", include_str!("../../dialects/fanuc_lathe_b.xml")),
    ("fagor.xml", include_str!("../../dialects/fagor.xml")),
    ("haas_lathe.xml", include_str!("../../dialects/haas_lathe.xml")),
    ("mitsubishi_lathe.xml", include_str!("../../dialects/mitsubishi_lathe.xml")),
    ("mazak_lathe.xml", include_str!("../../dialects/mazak_lathe.xml")),
    ("fagor_lathe.xml", include_str!("../../dialects/fagor_lathe.xml")),
    ("centroid.xml", include_str!("../../dialects/centroid.xml")),
    ("mach3.xml", include_str!("../../dialects/mach3.xml")),
];

/// Known dialects by name, in name order.
#[derive(Clone, Debug, Default)]
pub struct Registry {
    dialects: BTreeMap<String, Arc<Dialect>>,
    /// Each dialect's merged element tree, the base for dialects that extend it.
    trees: BTreeMap<String, Arc<Element>>,
    /// Every dialect's evidence patterns as one expression, built on the first sniff.
    pub(super) evidence: std::sync::OnceLock<Option<super::sniff::EvidenceSet>>,
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
        match self.add_with_findings(origin, text) {
            (Some(d), _) => Ok(d),
            (None, findings) => Err(findings),
        }
    }

    /// Like [`Registry::add`], also returning the findings (warnings) of a file that loads.
    pub fn add_with_findings(&mut self, origin: &str, text: &str) -> (Option<Arc<Dialect>>, Vec<String>) {
        let (dialect, diags, tree) = load_tree(text, &|name| self.trees.get(name).map(|t| Element::clone(t)));
        let idx = LineIndex::new(text);
        let findings = diags.iter().map(|d| diag::render_short(origin, text, &idx, d)).collect();
        let Some(d) = dialect else { return (None, findings) };
        let d = Arc::new(d);
        self.dialects.insert(d.name.clone(), Arc::clone(&d));
        self.evidence = std::sync::OnceLock::new();
        if let Some(tree) = tree {
            self.trees.insert(d.name.clone(), Arc::new(tree));
        }
        (Some(d), findings)
    }

    /// Loads several dialect files `(origin, text)` that may extend one another, in any
    /// order: a file whose base comes later is retried once the base is in. On failure,
    /// returns the rendered diagnostics of every file that could not be loaded.
    pub fn add_all(&mut self, files: &[(String, String)]) -> Result<(), Vec<String>> {
        let mut pending: Vec<&(String, String)> = files.iter().collect();
        loop {
            let before = pending.len();
            let mut errors = Vec::new();
            pending.retain(|(origin, text)| match self.add(origin, text) {
                Ok(_) => false,
                Err(e) => {
                    errors.extend(e);
                    true
                }
            });
            if pending.is_empty() {
                return Ok(());
            }
            if pending.len() == before {
                return Err(errors);
            }
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

//! The set of known dialects: the shipped ones, compiled in, plus any a user adds.

use std::collections::{BTreeMap, BTreeSet};
use std::sync::{Arc, OnceLock};

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
    ("siemens_810.xml", include_str!("../../dialects/siemens_810.xml")),
    ("haas.xml", include_str!("../../dialects/haas.xml")),
    ("mitsubishi.xml", include_str!("../../dialects/mitsubishi.xml")),
    ("mazak.xml", include_str!("../../dialects/mazak.xml")),
    ("lnc.xml", include_str!("../../dialects/lnc.xml")),
    ("okuma.xml", include_str!("../../dialects/okuma.xml")),
    ("okuma_lathe.xml", include_str!("../../dialects/okuma_lathe.xml")),
    ("fanuc_lathe.xml", include_str!("../../dialects/fanuc_lathe.xml")),
    ("fanuc_lathe_b.xml", include_str!("../../dialects/fanuc_lathe_b.xml")),
    ("fagor.xml", include_str!("../../dialects/fagor.xml")),
    ("haas_lathe.xml", include_str!("../../dialects/haas_lathe.xml")),
    ("mitsubishi_lathe.xml", include_str!("../../dialects/mitsubishi_lathe.xml")),
    ("mazak_lathe.xml", include_str!("../../dialects/mazak_lathe.xml")),
    ("mazak_millturn.xml", include_str!("../../dialects/mazak_millturn.xml")),
    ("fagor_lathe.xml", include_str!("../../dialects/fagor_lathe.xml")),
    ("centroid.xml", include_str!("../../dialects/centroid.xml")),
    ("mach3.xml", include_str!("../../dialects/mach3.xml")),
    ("pathpilot.xml", include_str!("../../dialects/pathpilot.xml")),
];

/// A shipped dialect and its merged element tree (the base for dialects that extend it).
type Loaded = (Arc<Dialect>, Arc<Element>);

/// The shipped dialects, each loaded the first time it is asked for: one slot per entry of
/// [`SHIPPED`], in its order. A slot holds `None` when its file does not load.
#[derive(Debug)]
struct Shipped {
    slots: Vec<OnceLock<Option<Loaded>>>,
}

/// The dialect name of a shipped file: its file stem (a test keeps the two equal).
fn stem(origin: &str) -> &str {
    origin.strip_suffix(".xml").unwrap_or(origin)
}

impl Shipped {
    fn new() -> Shipped {
        Shipped { slots: SHIPPED.iter().map(|_| OnceLock::new()).collect() }
    }

    /// The shipped dialect called `name`, loaded now if it was not yet.
    fn get(&self, name: &str) -> Option<&Loaded> {
        self.load(SHIPPED.iter().position(|(origin, _)| stem(origin) == name)?)
    }

    /// Entry `i` of [`SHIPPED`], with the bases it extends, loaded once. As when every file was
    /// loaded in order at start, a base is one of the entries before it: those are the only
    /// slots a load waits on, so loads on several threads cannot wait on one another.
    fn load(&self, i: usize) -> Option<&Loaded> {
        self.slots[i]
            .get_or_init(|| {
                let base = |name: &str| {
                    let j = SHIPPED[..i].iter().position(|(origin, _)| stem(origin) == name)?;
                    self.load(j).map(|(_, tree)| Element::clone(tree))
                };
                let (dialect, _, tree) = load_tree(SHIPPED[i].1, &base);
                Some((Arc::new(dialect?), Arc::new(tree?)))
            })
            .as_ref()
    }
}

/// Known dialects by name, in name order: the shipped ones, each loaded when first asked
/// for, and those added, which replace shipped ones of the same name.
#[derive(Clone, Debug, Default)]
pub struct Registry {
    /// The shipped dialects, if this registry has them; clones share what was loaded.
    shipped: Option<Arc<Shipped>>,
    /// The dialects added, which win over shipped ones of the same name.
    added: BTreeMap<String, Arc<Dialect>>,
    /// Each added dialect's merged element tree, the base for dialects that extend it.
    trees: BTreeMap<String, Arc<Element>>,
    /// Every dialect's evidence patterns as one expression, built on the first sniff.
    pub(super) evidence: OnceLock<Option<super::sniff::EvidenceSet>>,
}

impl Registry {
    /// The shipped dialects. Nothing is loaded yet: a dialect is read from its file the first
    /// time [`Registry::get`] asks for it (or for one extending it). A shipped file that fails
    /// to load is a build defect, caught by the test suite; `get` gives `None` for it rather
    /// than crashing.
    pub fn shipped() -> Registry {
        Registry { shipped: Some(Arc::new(Shipped::new())), ..Registry::default() }
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
        let (dialect, diags, tree) = load_tree(text, &|name| self.tree(name).map(|t| Element::clone(&t)));
        let idx = LineIndex::new(text);
        let findings = diags.iter().map(|d| diag::render_short(origin, text, &idx, d)).collect();
        let Some(d) = dialect else { return (None, findings) };
        let d = Arc::new(d);
        self.added.insert(d.name.clone(), Arc::clone(&d));
        self.evidence = OnceLock::new();
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

    /// The merged element tree of the dialect called `name`: an added one's, else the
    /// shipped one's (loaded now if it was not yet).
    fn tree(&self, name: &str) -> Option<Arc<Element>> {
        self.trees.get(name).cloned().or_else(|| self.shipped.as_ref()?.get(name).map(|(_, tree)| Arc::clone(tree)))
    }

    /// The dialect called `name`; a shipped one is loaded the first time it is asked for.
    pub fn get(&self, name: &str) -> Option<Arc<Dialect>> {
        self.added.get(name).cloned().or_else(|| self.shipped.as_ref()?.get(name).map(|(d, _)| Arc::clone(d)))
    }

    /// Names, sorted: every dialect added and shipped, without loading any.
    pub fn names(&self) -> impl Iterator<Item = &str> {
        let shipped = self.shipped.iter().flat_map(|_| SHIPPED.iter().map(|(origin, _)| stem(origin)));
        let all: BTreeSet<&str> = self.added.keys().map(String::as_str).chain(shipped).collect();
        all.into_iter()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every shipped file loaded at once, in order: the registry as it was built before
    /// shipped dialects were loaded on demand.
    fn eager() -> Registry {
        let mut r = Registry::default();
        for (origin, text) in SHIPPED {
            let _ = r.add(origin, text);
        }
        r
    }

    /// The shipped dialects loaded so far.
    fn loaded(r: &Registry) -> Vec<&'static str> {
        let slots = &r.shipped.as_ref().expect("shipped").slots;
        SHIPPED.iter().zip(slots).filter(|(_, s)| s.get().is_some()).map(|((origin, _), _)| stem(origin)).collect()
    }

    fn same<T: std::fmt::Debug>(a: T, b: T) -> bool {
        format!("{a:?}") == format!("{b:?}")
    }

    /// The name list comes from the file names, so each file must name its dialect after
    /// itself; and every file loads, each after the bases it extends.
    #[test]
    fn each_shipped_file_names_its_dialect_after_its_file() {
        let mut r = Registry::default();
        for (origin, text) in SHIPPED {
            let stem = origin.strip_suffix(".xml").unwrap_or_else(|| panic!("{origin} is not an .xml file"));
            let d = r.add(origin, text).unwrap_or_else(|e| panic!("{origin} does not load: {e:?}"));
            assert_eq!(d.name, stem, "{origin} names its dialect `{}`", d.name);
        }
        assert_eq!(r.names().count(), SHIPPED.len(), "two shipped files name one dialect");
    }

    #[test]
    fn names_are_listed_without_loading_and_are_those_of_a_full_load() {
        let r = Registry::shipped();
        assert_eq!(r.names().collect::<Vec<_>>(), eager().names().collect::<Vec<_>>());
        assert_eq!(r.names().count(), SHIPPED.len());
        assert!(loaded(&r).is_empty(), "{:?}", loaded(&r));
        assert_eq!(Registry::default().names().count(), 0);
    }

    /// Each shipped dialect asked for on its own loads it and its bases only, and gives the
    /// dialect (and merged tree) that loading every file in order gives.
    #[test]
    fn a_dialect_loaded_on_demand_is_the_one_a_full_load_gives() {
        let full = eager();
        for name in full.names() {
            let r = Registry::shipped();
            let d = r.get(name).unwrap_or_else(|| panic!("{name} does not load"));
            assert!(same(Some(&d), full.get(name).as_ref()), "{name}");
            assert!(same(r.tree(name), full.tree(name)), "{name}");
            let mut lineage = vec![name];
            while let Some(base) = full.get(lineage[lineage.len() - 1]).and_then(|d| d.extends.clone()) {
                lineage.push(full.names().find(|n| *n == base).expect("the base is shipped"));
            }
            lineage.sort_unstable();
            let mut got = loaded(&r);
            got.sort_unstable();
            assert_eq!(got, lineage, "asking for {name}");
        }
        // Asked for in reverse order, and through a clone, which shares what was loaded.
        let r = Registry::shipped();
        let c = r.clone();
        for name in full.names().collect::<Vec<_>>().into_iter().rev() {
            assert!(same(c.get(name), full.get(name)), "{name}");
        }
        assert_eq!(loaded(&r).len(), SHIPPED.len());
    }

    /// A user's dialect extends a shipped one that was not loaded yet.
    #[test]
    fn a_user_dialect_extends_a_shipped_one() {
        let xml = r#"<dialect xmlns="urn:ncplan:dialect:1" name="shop_haas" extends="haas" title="Our Haas">
  <behaviour decimal-input="calculator"/>
</dialect>"#;
        let mut r = Registry::shipped();
        let d = r.add("shop_haas.xml", xml).unwrap();
        let mut full = eager();
        assert!(same(&d, &full.add("shop_haas.xml", xml).unwrap()));
        assert_eq!(d.family, "haas");
        assert_eq!(loaded(&r), ["fanuc", "haas"]);
        assert_eq!(r.names().collect::<Vec<_>>(), full.names().collect::<Vec<_>>());
        assert!(r.names().any(|n| n == "shop_haas"));
        assert!(same(r.get("shop_haas"), full.get("shop_haas")));
        // Through a folder of dialect files, in any order.
        let child = r#"<dialect xmlns="urn:ncplan:dialect:1" name="shop_haas_vf2" extends="shop_haas"/>"#;
        let files = [("b.xml".to_owned(), child.to_owned()), ("a.xml".to_owned(), xml.to_owned())];
        let mut r = Registry::shipped();
        r.add_all(&files).unwrap();
        full.add_all(&files).unwrap();
        assert!(same(r.get("shop_haas_vf2"), full.get("shop_haas_vf2")));
        assert_eq!(r.get("shop_haas_vf2").unwrap().family, "haas");
    }

    /// A user's dialect of a shipped name replaces it; the shipped dialects that extend it
    /// keep the shipped base, as when they were all loaded before the user's.
    #[test]
    fn a_user_dialect_replaces_a_shipped_one_of_its_name() {
        let xml = r#"<dialect xmlns="urn:ncplan:dialect:1" name="fanuc" extends="fanuc" title="Our Fanuc">
  <behaviour decimal-input="calculator"/>
</dialect>"#;
        let again = xml.replace("Our Fanuc", "Our Fanuc, again");
        let child = r#"<dialect xmlns="urn:ncplan:dialect:1" name="shop_fanuc" extends="fanuc"/>"#;
        let mut r = Registry::shipped();
        let mut full = eager();
        for (origin, text) in [("fanuc.xml", xml), ("fanuc2.xml", &again), ("shop_fanuc.xml", child)] {
            assert!(same(r.add(origin, text), full.add(origin, text)), "{origin}");
        }
        assert_eq!(r.get("fanuc").unwrap().title, "Our Fanuc, again");
        let calculator = crate::dialect::DecimalInput::Calculator;
        assert_eq!(r.get("shop_fanuc").unwrap().behaviour.decimal_input, calculator, "extends the user's Fanuc");
        assert_eq!(r.names().collect::<Vec<_>>(), full.names().collect::<Vec<_>>());
        // Haas, loaded only now, extends the shipped Fanuc, not the user's.
        assert!(!loaded(&r).contains(&"haas"));
        assert_ne!(r.get("haas").unwrap().behaviour.decimal_input, calculator);
        for name in full.names() {
            assert!(same(r.get(name), full.get(name)), "{name}");
        }
    }

    /// Sniffing weighs every dialect's evidence, so it loads them all and tells what a full
    /// load tells, with user dialects too.
    #[test]
    fn sniffing_loads_every_dialect_and_tells_what_a_full_load_tells() {
        let texts = [
            ("p.nc", "%\nO1234\nG90 G54 X10. Y-2.\n#1=5\nWHILE [#1 GT 0] DO 1\nM98 P100\nM30\n%\n"),
            ("PART.MPF", "%_N_PART_MPF\n;$PATH=/_N_WKS_DIR\nDEF REAL X1\nCYCLE81(10, 0, 2, -5)\nG2 X10 CR=5\n"),
            ("P1.H", "0 BEGIN PGM P1 MM\n1 TOOL CALL 1 Z S1000\n2 L X+10 Y-5 FMAX M3\n"),
            ("probe.ngc", "o<probe> sub\n#<depth> = 2\n(debug, x)\nG64 P0.01\nZ10\n"),
            ("SHAFT.MIN", "$SHAFT.MIN%\nCALL OTBOX PZ=-5.\nVC1=2\nG96 S200\nRTS\n"),
            ("a.tap", "(MACH3)\nG31 Z-5 F50\nM11P1\n"),
            ("x.nc", "G0 X1.5\n"),
        ];
        let user = r#"<dialect xmlns="urn:ncplan:dialect:1" name="shop_haas" extends="haas" title="Our Haas"/>"#;
        for with_user in [false, true] {
            let (mut r, mut full) = (Registry::shipped(), eager());
            if with_user {
                r.add("u.xml", user).unwrap();
                full.add("u.xml", user).unwrap();
            }
            for (file, text) in texts {
                for file in [Some(file), None] {
                    assert_eq!(r.sniff(text, file, "linuxcnc"), full.sniff(text, file, "linuxcnc"), "{text:?}");
                }
            }
            assert_eq!(loaded(&r).len(), SHIPPED.len());
        }
    }

    #[test]
    fn a_registry_is_shared_between_threads() {
        fn shared<T: Send + Sync + Clone + Default + std::fmt::Debug>() {}
        shared::<Registry>();
        let r = Registry::shipped();
        let names: Vec<&str> = r.names().collect();
        std::thread::scope(|s| {
            for chunk in names.chunks(5) {
                s.spawn(|| chunk.iter().for_each(|n| assert!(r.get(n).is_some(), "{n}")));
            }
        });
        assert_eq!(loaded(&r).len(), SHIPPED.len());
    }
}

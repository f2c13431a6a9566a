//! Integration tests: one binary (matklad's advice), one module per area.
//!
//! - `tests/it/pg.rs` — a PostgreSQL cluster per test (`Cluster`: initdb as `nobody` when root,
//!   a free port, stopped on drop); the daemon and read commands compared on both engines,
//!   `query`'s refusals, credentials, four daemons of four sites through bursts and kills,
//!   `migrate` (with review marks); `serve` on both engines from one database (built by the
//!   daemon, copied by `migrate` with its ids), every page fetched over HTTP and compared byte
//!   for byte (CSRF tokens and engine-specific SQL masked), a review mark and saved queries
//!   posted with CSRF tokens; the README's read-only role; re-analysis keeping old changes and
//!   marks on both engines; `engines()` gives the ingest-level store tests of `faults.rs` both
//!   engines.
//! - the areas: `cli`, `daemon` (real binary, SIGKILL, restart; a kill
//!   loop while many late originals arrive, every waiting edit compared after it),
//!   `faults` (the daemon under a DNC server's faults: its own reads, a kill after a late
//!   original, Siemens names, paused and rewritten writes, remounts, links, empty and huge files),
//!   `share_faults` (what a share holds besides programs and a worker that never finishes: FIFOs,
//!   hard links, names that are not UTF-8 or hold a newline, a stuck worker replaced, its file
//!   quarantined, the watchdog and SIGTERM), `reports_config` (report filters in every format,
//!   dates and machines that fail, configured folders of the working directory that must exist,
//!   `translate -o` against the default configuration's folders),
//!   `first_start` (the README's demo verbatim, `show`, `query` refusals, config mistakes, `import`),
//!   `bound` (the analysis bound: a 100,000-move macro program to its end as rs274 runs it, and
//!   every command saying where a run stopped at a smaller one),
//!   `plan` (one small CAM-style program per feature kind), `lathe` (the programs of
//!   `tests/programs/lathe/` with hand-written sidecars, scored per turning workingstep and
//!   feature; lathe edits in a turner's terms), `translate_lathe` (those and the real lathe programs
//!   translated between every pair of lathe dialects, proven by their motion, `tests/golden/translate/lathe.tsv`;
//!   lathe to mill and mill to lathe refused), `cam_suite` (the programs of
//!   `tests/programs/cam/`, made by its `generate.py` in Fanuc/Haas, Siemens and Heidenhain post
//!   styles with sidecars, scored per feature kind; the NIST-style case), `edits` (one CAM
//!   original, one operator edit per test, the exact change rows), `express` (every CC1 and CC2
//!   export — plan programs, CAM suite, and in CI the whole corpus — validated against the
//!   ISO 14649 combined EXPRESS schema by ifcopenshell through `tests/stepnc_express.py`; skipped
//!   with one line without it unless `NCPLAN_REQUIRE_IFCOPENSHELL`), `stepnc` (signature table from the
//!   EXPRESS schema, conformance, round trip, the paper's face-milling example, steputils),
//!   `dialects` (xmllint against the XSD), `cldata` (the CL parts of `tests/programs/cldata/`
//!   in NX, Creo and CATIA styles against the Fanuc program of each, made by its `generate.py`;
//!   every corpus CL file; the NX → Haas and SolidWorks → Heidenhain pairs; a real daemon with
//!   a CL original), `arch` (the invariants of ARCHITECTURE.md), `macros` (Macro B and
//!   O-word flow by their moves), `robustness` (proptest: bytes, statement soup, mutated programs),
//!   `web` (`ncplan serve` on a database the real daemon built from the demo edit and a program
//!   whose comments try to inject script, driven in headless chromium through chromedriver with
//!   fantoccini: every page, scroll sync, adopt shrinks the queue, XSS stays text, both toolpaths
//!   and the region in each SVG, the HTML report; screenshots in `target/screenshots/`; skipped
//!   with one line without chromium unless `NCPLAN_REQUIRE_CHROMIUM`; CSRF, sign-in and the
//!   non-local refusal over raw HTTP; a DNS-rebinding page in chromium), `web_attacks` (`serve`
//!   under the web's usual attacks over raw HTTP on loopback: the console by GET or without
//!   its token, hostile console queries at once with the server's peak memory, another `Host`
//!   on every route, 300 sign-ins at once, a thousand slow heads, slow and huge bodies, the
//!   security headers, `Secure` cookies, the README's TLS set-up, seeded random requests and
//!   slow writers with a planner answered within a second throughout).

mod accounting;
mod arch;
mod bound;
mod called;
mod cam_suite;
mod cldata;
mod cli;
mod controls_run;
mod cycles;
mod daemon;
mod derived;
mod dialects;
mod dialects_more;
mod edits;
mod encodings;
mod equivalence;
mod express;
mod fagor;
mod faults;
mod first_start;
mod fixa19;
mod flow;
mod home18;
mod lathe;
mod lathe_edits;
mod legacy_blocks;
mod macros;
mod parity;
mod pg;
mod plan;
mod post_rules;
mod post_suite;
mod reports_config;
mod revisions;
mod robustness;
mod round_trip_causes;
mod share_faults;
mod shop;
mod shops;
mod siemens_axes;
mod speed;
mod stepnc;
mod suggest;
mod support;
mod sweep43;
mod tilt;
mod tool_comments;
mod translate;
mod translate_known;
mod translate_lathe;
mod translate_stream;
mod translate_taps;
mod unknown_values;
mod vocab_makers;
mod vocabulary;
mod web;
mod web_attacks;

use std::path::{Path, PathBuf};

/// The repository root.
pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The shared material beside the checkout (`NCPLAN_SHARED` names another place).
pub fn shared() -> PathBuf {
    std::env::var_os("NCPLAN_SHARED").map_or_else(|| root().join("../shared"), PathBuf::from)
}

/// The shared corpus, or `None` after saying that `test` is skipped because it is absent.
/// With `NCPLAN_REQUIRE_SHARED` set (CI sets it) an absent corpus fails the test instead.
pub fn shared_corpus(test: &str) -> Option<PathBuf> {
    let corpus = shared().join("corpus");
    if corpus.is_dir() {
        return Some(corpus);
    }
    assert!(std::env::var_os("NCPLAN_REQUIRE_SHARED").is_none(), "NCPLAN_REQUIRE_SHARED is set but {} is absent", corpus.display());
    skip(test, &format!("{} is absent (clone the shared material beside the checkout to run it)", corpus.display()));
    None
}

/// The rows `sql` gives on the database `db` opened read-only; none while it does not exist
/// or cannot be read yet (a daemon is still creating it).
pub fn db_rows(db: &Path, sql: &str) -> Vec<Vec<String>> {
    if !db.exists() {
        return Vec::new();
    }
    match ncplan::store::Store::open_read_only(&ncplan::store::Location::Sqlite(db.to_path_buf())) {
        Ok(s) => s.query(sql).map(|(_, r)| r).unwrap_or_default(),
        Err(_) => Vec::new(),
    }
}

/// Says why `test` did nothing, past the harness's output capture, so that a skip is never silent.
pub fn skip(test: &str, why: &str) {
    use std::io::Write as _;
    let _ = writeln!(std::io::stderr(), "skipped {test}: {why}");
}

/// The built `ncplan` binary, or the one `NCPLAN_TEST_BIN` names (to show that a test fails
/// on an older build).
pub fn bin() -> &'static Path {
    static BIN: std::sync::OnceLock<PathBuf> = std::sync::OnceLock::new();
    BIN.get_or_init(|| std::env::var_os("NCPLAN_TEST_BIN").map_or_else(|| PathBuf::from(env!("CARGO_BIN_EXE_ncplan")), PathBuf::from))
}

/// The moves (straight and arc calls, one per line, as rs274 prints them) of `program` in the
/// shipped `dialect` under `profile`, and its findings.
pub fn moves_and_findings(dialect: &str, program: &str, profile: &ncplan::interp::Profile) -> (Vec<String>, Vec<ncplan::diag::Diagnostic>) {
    use ncplan::canon::{CanonOp, write_call};
    let d = ncplan::dialect::Registry::shipped().get(dialect).unwrap();
    let mut out = Vec::new();
    let diags = ncplan::interp::interpret(program, &d, profile, &mut out);
    let mut lines = Vec::new();
    for c in &out {
        if matches!(c.op, CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. }) {
            let mut t = String::new();
            write_call(&mut t, &c.op);
            lines.push(t.trim().to_owned());
        }
    }
    (lines, diags)
}

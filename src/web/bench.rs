//! `ncplan bench --web`: every page's server-side render time on a generated database of
//! 10,000 machine revisions across 20 machines, and the comparison page of a 1M-move program
//! (its render time, cold and with its plans cached, and the size of its SVG). With
//! `--postgres URL`, the same pages rendered on PostgreSQL too.
//!
//! The database is built through the store's own API (as the daemon records revisions), from
//! generated programs analysed by the pure core; each distinct content is analysed once.

use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;
use std::sync::Arc;
use std::time::{Duration, Instant};

use anyhow::{Context, Result};

use super::{Ctx, Server, compare, pages};
use crate::config::Config;
use crate::diag::DiagnosticJson;
use crate::pairing::{Key, Rule};
use crate::store::{Content, NewRevision, Store};
use crate::text::LineIndex;

const MACHINES: usize = 20;
const PROGRAMS_PER_MACHINE: usize = 25;
const REVISIONS_PER_PROGRAM: usize = 20;
const VARIANTS: usize = 8;

/// A generated part program: face milling, a contour and a drilled row; `variant` 0 is the
/// CAM original, the others carry the edits operators make.
fn program(p: usize, variant: usize) -> String {
    let (tool, feed, start_x, depth, speed) = match variant {
        1 => (8, 800, -10.0, 1.0, 2500),
        2 => (1, 1100, -10.0, 1.0, 2500),
        3 => (1, 800, -7.0, 1.0, 2500),
        4 => (1, 800, -10.0, 1.5, 2500),
        5 => (1, 800, -10.0, 1.0, 2000),
        6 => (5, 650, -12.0, 1.0, 2500),
        7 => (1, 720, -10.0, 1.2, 2800),
        _ => (1, 800, -10.0, 1.0, 2500),
    };
    let width = 80 + p % 40;
    let mut s = format!(
        "%\nO{n}\n(T1 D=18 ENDMILL)\n(T2 D=8.5 DRILL)\nG21 G90 G17 G54\nT{tool} M6\nS{speed} M3\nG0 X{start_x:.1} Y0. Z5.\nG43 H1 Z5.\nG1 Z{z:.2} F{feed}\n",
        n = 2000 + p,
        z = -depth
    );
    for row in 0..6 {
        let y = row * 10;
        let x = if row % 2 == 0 { width as i64 } else { -10 };
        s.push_str(&format!("X{x}. Y{y}.\nY{}.\n", y + 10));
    }
    s.push_str("G0 Z5.\nT2 M6\nS3000 M3\nG0 X20. Y20. Z5.\nG43 H2 Z5.\nG81 R2. Z-12. F120\n");
    for k in 1..5 {
        s.push_str(&format!("X{}.\n", 20 + 15 * k));
    }
    s.push_str("G80\nG0 Z50.\nM30\n%\n");
    s
}

/// An analysed content: its summary plan JSON, counts, findings and whole plan.
struct Analysed {
    bytes: Vec<u8>,
    hash: String,
    summary: String,
    counts: (usize, usize),
    diagnostics: Vec<DiagnosticJson>,
    plan: crate::plan::ProcessPlan,
}

fn analyse(registry: &crate::dialect::Registry, config: &Config, text: String) -> Result<Analysed> {
    let d = registry.get("fanuc").context("the fanuc dialect")?;
    let bytes = text.into_bytes();
    let a = crate::pipeline::analyze_plan(&bytes, &d, &config.profile);
    let idx = LineIndex::new(&a.source.text);
    let diagnostics = a.diagnostics.iter().map(|x| DiagnosticJson::new(x, &a.source.text, &idx)).collect();
    let mut plan = a.plan;
    let summary = crate::daemon::ingest::summary_json(&mut plan)?;
    Ok(Analysed {
        hash: crate::daemon::ingest::sha256_hex(&bytes),
        counts: (plan.workingsteps.len(), plan.tools.len()),
        bytes,
        summary,
        diagnostics,
        plan,
    })
}

fn record(store: &mut Store, path: &str, machine: Option<(&str, &str)>, stem: &str, a: &Analysed, seen_at: &str) -> Result<i64> {
    let tx = store.begin()?;
    let id = insert(&tx, path, machine, stem, a, seen_at)?;
    tx.commit()?;
    Ok(id)
}

fn insert(tx: &crate::store::Txn<'_>, path: &str, machine: Option<(&str, &str)>, stem: &str, a: &Analysed, seen_at: &str) -> Result<i64> {
    let keys = [Key { rule: Rule::FileName, value: stem.to_owned() }];
    Ok(tx.insert_revision(&NewRevision {
        path,
        role: if machine.is_some() { "machine" } else { "cam" },
        machine: machine.map(|(name, folder)| (name, "fanuc", folder)),
        name: stem,
        keys: &keys,
        stem,
        dialect: "fanuc",
        content: Content::Bytes(&a.bytes),
        hash: &a.hash,
        mtime_ns: None,
        seen_at,
        encoding: "utf-8",
        status: "analysed",
        plan_json: Some(&a.summary),
        plan_complete: false,
        counts: a.counts,
        diagnostics: &a.diagnostics,
    })?)
}

/// `2026-01-01` plus `minutes`, as RFC 3339.
fn at(minutes: usize) -> String {
    crate::daemon::rfc3339(1_767_225_600 + minutes as i64 * 60, 0)
}

fn config_for(dir: &Path) -> Result<Config> {
    let mut text = String::from("[database]\npath = 'bench.db'\n[[cam]]\npath = 'cam'\ndialect = 'fanuc'\n");
    for m in 0..MACHINES {
        text.push_str(&format!("[[machine]]\nname = 'M{m:02}'\npath = 'shares/M{m:02}'\ndialect = 'fanuc'\n"));
    }
    Config::parse(&text, dir)
}

/// Builds the database of 10,000 machine revisions (20 machines × 25 programs × 20
/// revisions, each compared with its original); returns it and the number of revisions.
fn build(dir: &Path, config: &Config, registry: &crate::dialect::Registry) -> Result<usize> {
    let db = config.database.file().context("the web bench builds a SQLite database")?;
    if db.exists() {
        std::fs::remove_file(db).with_context(|| format!("cannot remove {}", db.display()))?;
    }
    let mut store = Store::open(&crate::store::Location::Sqlite(db.to_path_buf()), "")?;
    let programs = MACHINES * PROGRAMS_PER_MACHINE;
    let mut originals = BTreeMap::new();
    let mut variants: Vec<Vec<Analysed>> = Vec::new();
    // One content per program and variant; 500 programs share 40 shapes, so analyse those.
    let shapes = 40;
    for p in 0..shapes {
        variants.push((0..VARIANTS).map(|v| analyse(registry, config, program(p, v))).collect::<Result<_>>()?);
    }
    let changes: Vec<Vec<Vec<crate::diff::Change>>> =
        variants.iter().map(|vs| vs.iter().map(|v| crate::diff::diff(&vs[0].plan, &v.plan)).collect()).collect();
    for p in 0..programs {
        let stem = format!("P{p:04}");
        let path = dir.join("cam").join(format!("{stem}.nc")).display().to_string();
        originals.insert(p, record(&mut store, &path, None, &stem, &variants[p % shapes][0], &at(p))?);
    }
    let mut n = 0;
    for r in 0..REVISIONS_PER_PROGRAM {
        let tx = store.begin()?;
        for p in 0..programs {
            let m = p % MACHINES;
            let (name, folder) = (format!("M{m:02}"), dir.join(format!("shares/M{m:02}")).display().to_string());
            let stem = format!("P{p:04}");
            let path = format!("{folder}/{stem}.nc");
            // Revision r of a program alternates between edits; every third goes back to the original.
            let v = if r % 3 == 2 { 0 } else { 1 + (p + r) % (VARIANTS - 1) };
            let minutes = 1000 + r * 7 * 24 * 60 / 2 + p;
            let id = insert(&tx, &path, Some((&name, &folder)), &stem, &variants[p % shapes][v], &at(minutes))?;
            tx.record_comparison(id, originals[&p], "file-name", &changes[p % shapes][v], &at(minutes))?;
            n += 1;
        }
        tx.commit()?;
    }
    Ok(n)
}

/// Best of `runs` times of `f`.
fn best<T>(runs: usize, mut f: impl FnMut() -> Result<T>) -> Result<(Duration, T)> {
    let mut out = None;
    let mut best = Duration::MAX;
    for _ in 0..runs {
        let t = Instant::now();
        let v = f()?;
        best = best.min(t.elapsed());
        out = Some(v);
    }
    Ok((best, out.context("no run")?))
}

/// Runs the web benchmark in `dir`; the 1M-move program has `rows` × 500 blocks. With
/// `postgres`, the same pages are rendered on that PostgreSQL database too, with the same
/// revisions copied into it (as site `WEBBENCH`, once).
pub fn run(dir: &Path, rows: usize, postgres: Option<&str>, out: &mut impl Write) -> Result<()> {
    std::fs::create_dir_all(dir).with_context(|| format!("cannot create {}", dir.display()))?;
    let dir = std::path::absolute(dir)?;
    let config = config_for(&dir)?;
    let registry = crate::config::dialect_registry(None)?;
    let t = Instant::now();
    let n = build(&dir, &config, &registry)?;
    writeln!(out, "web: built {} ({n} machine revisions, {MACHINES} machines) in {:.1} s", config.database, t.elapsed().as_secs_f64())?;
    let worst = time_pages(&config, &registry, "web:", out)?;
    writeln!(out, "web: slowest page {:.1} ms (target < 200 ms)", worst.as_secs_f64() * 1e3)?;
    if let Some(url) = postgres {
        let at = crate::store::Location::parse(url);
        let t = Instant::now();
        config.database.file().context("the web bench builds a SQLite database")?;
        let source = Store::open_read_only(&config.database)?;
        let copied = Store::open(&at, "WEBBENCH")?.copy_from(&source, "WEBBENCH", &|_, _| {})?;
        writeln!(
            out,
            "web on PostgreSQL: {} revisions copied into {at} ({} there already) in {:.1} s",
            copied.copied,
            copied.revisions - copied.copied,
            t.elapsed().as_secs_f64()
        )?;
        let mut on_pg = config.clone();
        on_pg.database = at;
        let worst = time_pages(&on_pg, &registry, "web on PostgreSQL:", out)?;
        writeln!(out, "web on PostgreSQL: slowest page {:.1} ms (target < 200 ms)", worst.as_secs_f64() * 1e3)?;
    }
    huge(&dir, rows, &registry, out)
}

/// Every page's best render time of three on `config`'s database; returns the slowest.
fn time_pages(config: &Config, registry: &crate::dialect::Registry, label: &str, out: &mut impl Write) -> Result<Duration> {
    let server = Server::new(config.clone(), registry.clone(), Arc::new(crate::daemon::SystemClock))?;
    let store = server.store()?;
    let ctx = Ctx { user: None, csrf: "bench".into(), auth: false };
    let (server, store, ctx) = (&server, &store, &ctx);
    let last = store.search_changes(&crate::store::ChangeFilter::default(), 1)?;
    let revision = last.first().map_or(1, |r| r.revision_id);
    let program = store.program_of(revision)?.unwrap_or(1);
    let q = |pairs: &[(&str, &str)]| pairs.iter().map(|(k, v)| ((*k).to_owned(), (*v).to_owned())).collect::<BTreeMap<_, _>>();
    let sql = crate::store::SAVED_QUERIES[0].1;
    let search = q(&[("program", "P0042"), ("machine", "M02"), ("since", "2026-01-01"), ("kind", "feed_changed")]);
    let queue = q(&[("to_review", "1")]);
    type Page<'a> = (&'a str, Box<dyn Fn() -> Result<maud::Markup> + 'a>);
    let (queue, search) = (&queue, &search);
    let mut list: Vec<Page<'_>> = vec![
        ("overview", Box::new(|| pages::overview(server, ctx, store))),
        ("machine", Box::new(|| pages::machine(server, ctx, store, "M07"))),
        ("program", Box::new(|| pages::program(server, ctx, store, program))),
        ("comparison", Box::new(|| pages::comparison(server, ctx, store, revision))),
        ("review queue", Box::new(|| pages::search(server, ctx, store, queue))),
        ("search", Box::new(|| pages::search(server, ctx, store, search))),
        ("sql console", Box::new(|| pages::sql_console(server, ctx, store, sql, None, pages::Console::Run))),
        ("knowledge", Box::new(|| pages::knowledge_index(server, ctx, store))),
    ];
    for k in crate::store::KNOWLEDGE {
        list.push((k.name, Box::new(move || pages::knowledge(server, ctx, store, k.name, false))));
    }
    let mut worst = Duration::ZERO;
    for (name, f) in &list {
        let (d, page) = best(3, f)?;
        worst = worst.max(d);
        writeln!(out, "{label} page {name:<14} {:>7.1} ms  {:>8} bytes", d.as_secs_f64() * 1e3, page.into_string().len())?;
    }
    Ok(worst)
}

/// The comparison page of a 1M-move program and an edit of one row.
fn huge(dir: &Path, rows: usize, registry: &crate::dialect::Registry, out: &mut impl Write) -> Result<()> {
    let hdir = dir.join("huge");
    std::fs::create_dir_all(&hdir)?;
    let text = "[database]\npath = 'huge.db'\n[[cam]]\npath = 'cam'\ndialect = 'fanuc'\n[[machine]]\nname = 'M1'\npath = 'share'\ndialect = 'fanuc'\n";
    let config = Config::parse(text, &hdir)?;
    if let Some(db) = config.database.file().filter(|d| d.exists()) {
        std::fs::remove_file(db)?;
    }
    let original = crate::bench::surfacing_program(rows);
    // The operator lowered one row in the middle by 0.2 mm.
    let lines: Vec<&str> = original.lines().collect();
    let mid = lines.len() / 2;
    let edited: String = lines
        .iter()
        .enumerate()
        .map(|(i, l)| {
            if (mid..mid + 400).contains(&i)
                && let Some((head, z)) = l.split_once(" Z")
                && let Ok(z) = z.parse::<f64>()
            {
                return format!("{head} Z{:.4}\n", z - 0.2);
            }
            format!("{l}\n")
        })
        .collect();
    let t = Instant::now();
    let (a, b) = (analyse(registry, &config, original)?, analyse(registry, &config, edited)?);
    let moves: usize = a.plan.workingsteps.iter().map(|w| w.toolpath.len()).sum();
    let changes = crate::diff::diff(&a.plan, &b.plan);
    let mut store = Store::open(&config.database, "")?;
    let o = record(&mut store, &hdir.join("cam/O1.nc").display().to_string(), None, "O1", &a, &at(0))?;
    let share = hdir.join("share").display().to_string();
    let tx = store.begin()?;
    let e = insert(&tx, &format!("{share}/O1.nc"), Some(("M1", &share)), "O1", &b, &at(10))?;
    tx.record_comparison(e, o, "file-name", &changes, &at(10))?;
    tx.commit()?;
    drop(store);
    writeln!(
        out,
        "web: 1M-move database: {moves} moves per program, {} changes, built in {:.1} s",
        changes.len(),
        t.elapsed().as_secs_f64()
    )?;
    let ctx = Ctx { user: None, csrf: "bench".into(), auth: false };
    // A first view is a new server's (nothing cached): the best of three, each on its own
    // server, as the other pages are the best of three.
    let mut cold = Duration::MAX;
    let mut first = None;
    for _ in 0..3 {
        let server = Server::new(config.clone(), registry.clone(), Arc::new(crate::daemon::SystemClock))?;
        let store = server.store()?;
        let t = Instant::now();
        let page = pages::comparison(&server, &ctx, &store, e)?.into_string();
        cold = cold.min(t.elapsed());
        first = Some((server, store, page));
    }
    let (server, store, page) = first.context("no first view")?;
    let (warm, page2) = best(3, || pages::comparison(&server, &ctx, &store, e))?;
    // Where a first view's time goes: reading both programs and rebuilding their plans
    // (nothing cached), then each part of the page.
    let reader = crate::daemon::ingest::Reader { config: &config, registry };
    let t = Instant::now();
    let c = compare::load(&store, e, &compare::Uncached(crate::daemon::ingest::Reader { config: &config, registry }))?;
    let load = t.elapsed();
    let (read, _) = best(3, || Ok(store.source(e)?.and_then(|s| s.bytes).map_or(0, |b| b.len())))?;
    let (analyse_one, _) = best(1, || {
        Ok(reader.reanalyse(&c.edited.path, &c.edited.dialect, store.content(e)?.unwrap_or_default())?.plan.workingsteps.len())
    })?;
    let (pic, pictures) = best(3, || Ok(compare::pictures(&c)))?;
    let (sources, _) = best(3, || Ok(compare::sources(&c, 20_000).into_string().len()))?;
    let svg: usize = pictures.views.iter().map(|(_, s)| s.len()).sum();
    std::fs::write(hdir.join("comparison.html"), &page)?;
    writeln!(
        out,
        "web: 1M-move comparison page: {:.0} ms first view (a new server's: plans rebuilt from the stored bytes; best of 3), {:.0} ms with plans cached (target < 1 s); SVG {} bytes (target < 2 MB); page {} bytes; {} points drawn of {}",
        cold.as_secs_f64() * 1e3,
        warm.as_secs_f64() * 1e3,
        svg,
        page2.into_string().len(),
        pictures.stats.drawn,
        pictures.stats.points
    )?;
    writeln!(
        out,
        "web: 1M-move first view, by part: read both programs and rebuild their plans {:.0} ms (one program's bytes read {:.0} ms, its plan rebuilt alone {:.0} ms); pictures {:.0} ms; sources {:.0} ms",
        load.as_secs_f64() * 1e3,
        read.as_secs_f64() * 1e3,
        analyse_one.as_secs_f64() * 1e3,
        pic.as_secs_f64() * 1e3,
        sources.as_secs_f64() * 1e3,
    )?;
    Ok(())
}

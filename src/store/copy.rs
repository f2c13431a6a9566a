//! `ncplan migrate`: one site's history copied from one database into another — a DNC
//! server's SQLite file into the plant's PostgreSQL database, or a site of the plant back
//! into a SQLite file (or either engine into itself).
//!
//! Every table of the schema is copied: [`COPIED`] names them in the order their references
//! need, and a test holds it to the tables the migrations create, so a table added later is
//! not forgotten silently. Ids are kept where the target has them free (a database copied
//! whole keeps every id the pages link by), else the row gets a new one and every reference to
//! it (a revision's program, a change's revision, a review mark's change, a partial write's
//! successor) follows. What the target has already (a machine or program by its site and
//! name or path, a revision by its program, hash and time, a comparison by its revision, a
//! review mark, saved query, session or journal entry by what it says) is left as it is, so
//! a stopped run goes on where it was and a later run copies only what is new.
//!
//! Both ends are reached through [`End`]: SQL written once with `?1` parameters, cells as
//! [`Val`]s, program bytes streamed 1 MiB at a time.

use std::collections::BTreeMap;
use std::io::Read;

use super::{Result, StoreError};

/// The tables `ncplan migrate` copies, in the order references need: each names only tables
/// before it. `copy_tables` has a rule for each.
pub(super) const COPIED: &[&str] = &[
    "machines",
    "programs",
    "program_keys",
    "blobs",
    "revisions",
    "plans",
    "diagnostics",
    "workingsteps",
    "features",
    "analyses",
    "reanalysis_queue",
    "revision_marks",
    "comparisons",
    "changes",
    "old_changes",
    "review_marks",
    "saved_queries",
    "web_sessions",
    "attempts",
    "calls",
    "suggestion_events",
];

/// A cell, as both engines keep it.
#[derive(Clone, Debug, PartialEq)]
pub(super) enum Val {
    /// NULL.
    Null,
    /// A whole number.
    Int(i64),
    /// A floating-point number.
    Real(f64),
    /// Text.
    Text(String),
    /// Bytes.
    Bytes(Vec<u8>),
}

impl Val {
    fn int(&self) -> Option<i64> {
        match self {
            Val::Int(i) => Some(*i),
            _ => None,
        }
    }
}

/// A stored blob: its size, the length stored (0 for a file kept without its bytes) and a
/// reader of the stored bytes.
pub(super) type Blob<'a> = (i64, i64, Box<dyn Read + 'a>);

/// One end of a copy: a database on either engine.
pub(super) trait End {
    /// Whether programs, machines and journal entries are keyed by site as well (PostgreSQL:
    /// a plant's servers share it); a SQLite file is one server's.
    fn by_site(&self) -> bool;
    /// The rows of `sql` (parameters `?1`, `?2`, …).
    fn rows(&self, sql: &str, params: &[Val]) -> Result<Vec<Vec<Val>>>;
    /// Runs a statement; the rows it changed.
    fn exec(&self, sql: &str, params: &[Val]) -> Result<u64>;
    /// Starts, commits or rolls back a transaction (`BEGIN`, `COMMIT`, `ROLLBACK`).
    fn batch(&self, sql: &str) -> Result<()>;
    /// SQL giving the column names of the table `?1`, in order.
    fn columns_sql(&self) -> &'static str;
    /// The columns of `table`, in order; none when it does not exist (an older schema).
    fn columns(&self, table: &str) -> Result<Vec<String>> {
        let rows = self.rows(self.columns_sql(), &[Val::Text(table.to_owned())])?;
        Ok(rows
            .into_iter()
            .filter_map(|r| match r.into_iter().next() {
                Some(Val::Text(t)) => Some(t),
                _ => None,
            })
            .collect())
    }
    /// A NULL-safe equality of `column` and parameter `?n`.
    fn same(&self, column: &str, n: usize) -> String;
    /// The blob `hash`.
    fn blob(&self, hash: &str) -> Result<Option<Blob<'_>>>;
    /// Stores `stored` bytes from `from` as the blob `hash` of `size`, unless it is there.
    fn write_blob(&self, hash: &str, size: i64, stored: i64, from: &mut dyn Read) -> Result<()>;
    /// Makes the next id `table` gives (its `id` column) greater than `at_least`.
    fn reserve_ids(&self, table: &str, at_least: i64) -> Result<()>;
    /// A new id of `table` greater than every id it has and than `above`.
    fn new_id(&self, table: &str, above: i64) -> Result<i64>;
}

/// What `ncplan migrate` did.
#[derive(Debug, Default, Clone)]
pub struct CopySummary {
    /// Revisions in the source (of the site).
    pub revisions: usize,
    /// Revisions copied by this run (the others were there from an earlier run).
    pub copied: usize,
    /// Comparisons copied by this run.
    pub comparisons: usize,
    /// Review marks in the source whose change is in the target (copied now or before).
    pub review_marks: usize,
    /// Rows copied by this run, per table in [`COPIED`] order (tables with none left out).
    pub rows: Vec<(&'static str, usize)>,
}

/// A copy under way: both ends, the site, and where each source id went.
struct Copy<'a> {
    src: &'a dyn End,
    dst: &'a dyn End,
    site: String,
    /// Whether the source holds other sites too (read only this one's rows).
    by_site: bool,
    /// Source id → target id, per table (`changes` for every change id, kept or old).
    ids: BTreeMap<&'static str, BTreeMap<i64, i64>>,
    /// Per id table: the greatest id the target had when the run began (an id above it that
    /// the source has is free), and the greatest the source has.
    limits: BTreeMap<&'static str, (i64, i64)>,
    /// The columns both ends have, per table.
    columns: BTreeMap<&'static str, Vec<String>>,
    copied: BTreeMap<&'static str, usize>,
    summary: CopySummary,
}

/// What a change says, whatever its id: a change the target has says the same as the
/// source's (`store::continued`'s key).
const STABLE: &str = "workingstep, kind, field, before, after";

/// The tables whose `id` column numbers their rows (changes: with `old_changes.change_id`).
const ID_TABLES: &[&str] = &["machines", "programs", "revisions", "diagnostics", "changes", "review_marks", "saved_queries"];

/// Copies `site`'s history from `src` into `dst`: from a source that keeps many sites
/// (PostgreSQL) this site's rows, from a SQLite file all of them, as `site`'s.
pub(super) fn copy(src: &dyn End, dst: &dyn End, site: &str, progress: &dyn Fn(usize, usize)) -> Result<CopySummary> {
    let mut c = Copy {
        src,
        dst,
        site: site.to_owned(),
        by_site: src.by_site(),
        ids: BTreeMap::new(),
        limits: BTreeMap::new(),
        columns: BTreeMap::new(),
        copied: BTreeMap::new(),
        summary: CopySummary::default(),
    };
    for t in COPIED {
        let (s, d) = (src.columns(t)?, dst.columns(t)?);
        c.columns.insert(t, d.into_iter().filter(|x| s.contains(x)).collect());
    }
    for t in ID_TABLES {
        let max = |end: &dyn End| -> Result<i64> {
            let mut m = 0;
            for (table, col) in [(*t, "id"), (if *t == "changes" { "old_changes" } else { "" }, "change_id")] {
                if !table.is_empty() && !end.columns(table)?.is_empty() {
                    m = m.max(end.rows(&format!("SELECT MAX({col}) FROM {table}"), &[])?.first().and_then(|r| r[0].int()).unwrap_or(0));
                }
            }
            Ok(m)
        };
        let (d, s) = (max(dst)?, max(src)?);
        // Ids the target gives from now on (its own writers' too) come after every id the
        // source has: an id kept from the source never meets one given meanwhile.
        dst.reserve_ids(t, d.max(s))?;
        c.limits.insert(t, (d, s));
    }
    in_tx(dst, || c.machines_and_programs())?;
    c.revisions(progress)?;
    c.comparisons()?;
    in_tx(dst, || c.the_rest())?;
    let mut summary = std::mem::take(&mut c.summary);
    summary.rows = COPIED.iter().filter_map(|t| c.copied.get(t).map(|n| (*t, *n))).filter(|(_, n)| *n > 0).collect();
    Ok(summary)
}

/// Runs `f` in a transaction of `end`, rolled back when it fails.
fn in_tx<T>(end: &dyn End, f: impl FnOnce() -> Result<T>) -> Result<T> {
    end.batch("BEGIN")?;
    match f() {
        Ok(v) => {
            end.batch("COMMIT")?;
            Ok(v)
        }
        Err(e) => {
            let _ = end.batch("ROLLBACK");
            Err(e)
        }
    }
}

/// The index of column `name` in `cols`.
fn at(cols: &[String], name: &str) -> Option<usize> {
    cols.iter().position(|c| c == name)
}

impl Copy<'_> {
    fn cols(&self, table: &str) -> &[String] {
        self.columns.get(table).map_or(&[], Vec::as_slice)
    }

    /// The source rows of `table` (the columns both ends have) that `filter` lets through,
    /// in `order`.
    fn select(&self, table: &'static str, filter: &str, params: &[Val], order: &str) -> Result<Vec<Vec<Val>>> {
        let cols = self.cols(table);
        if cols.is_empty() {
            return Ok(Vec::new());
        }
        let list = cols.join(", ");
        self.src.rows(&format!("SELECT {list} FROM {table} WHERE {filter} ORDER BY {order}"), params)
    }

    /// Inserts `row` (the columns of `table` both ends have) into the target.
    fn insert(&mut self, table: &'static str, row: &[Val]) -> Result<()> {
        let cols = self.cols(table);
        let marks: Vec<String> = (1..=cols.len()).map(|i| format!("?{i}")).collect();
        let sql = format!("INSERT INTO {table}({}) VALUES ({})", cols.join(", "), marks.join(", "));
        self.dst.exec(&sql, row)?;
        *self.copied.entry(table).or_default() += 1;
        Ok(())
    }

    /// The target id for the source id `id` of `table`: the same where the target has it
    /// free, else a new one; remembered.
    fn id_for(&mut self, table: &'static str, id: i64) -> Result<i64> {
        if let Some(to) = self.ids.get(table).and_then(|m| m.get(&id)) {
            return Ok(*to);
        }
        let (below, src_max) = self.limits.get(table).copied().unwrap_or((0, 0));
        let to = if id > below { id } else { self.dst.new_id(table, src_max)? };
        self.ids.entry(table).or_default().insert(id, to);
        Ok(to)
    }

    /// The target id of a row the source names (`None`: not copied).
    fn mapped(&self, table: &str, id: &Val) -> Option<i64> {
        self.ids.get(table).and_then(|m| m.get(&id.int()?)).copied()
    }

    /// Replaces the reference in column `col` of `row` by the target id of `table`; false when
    /// the row it names was not copied.
    fn follow(&self, table: &str, cols: &[String], row: &mut [Val], col: &str) -> bool {
        let Some(i) = at(cols, col) else { return true };
        if row[i] == Val::Null {
            return true;
        }
        match self.mapped(table, &row[i]) {
            Some(to) => {
                row[i] = Val::Int(to);
                true
            }
            None => false,
        }
    }

    /// Sets the `site` column of `row`, where the table has one.
    fn own(&self, cols: &[String], row: &mut [Val]) {
        if let Some(i) = at(cols, "site") {
            row[i] = Val::Text(self.site.clone());
        }
    }

    /// The source's filter for rows of this site (`site = ?1`), or every row.
    fn site_filter(&self) -> (&'static str, Vec<Val>) {
        if self.by_site { ("site = ?1", vec![Val::Text(self.site.clone())]) } else { ("1 = 1", Vec::new()) }
    }

    /// Machines by site and name, programs by site and path, and each program's keys as the
    /// source has them.
    fn machines_and_programs(&mut self) -> Result<()> {
        let (filter, params) = self.site_filter();
        for (table, key) in [("machines", "name"), ("programs", "path")] {
            let cols = self.cols(table).to_vec();
            let (id, k) = (at(&cols, "id"), at(&cols, key));
            let (Some(id), Some(k)) = (id, k) else { continue };
            for mut row in self.select(table, filter, &params, "id")? {
                let source_id = row[id].int().unwrap_or(0);
                self.own(&cols, &mut row);
                let found = if self.dst.by_site() {
                    self.dst.rows(
                        &format!("SELECT id FROM {table} WHERE {key} = ?1 AND site = ?2"),
                        &[row[k].clone(), Val::Text(self.site.clone())],
                    )?
                } else {
                    self.dst.rows(&format!("SELECT id FROM {table} WHERE {key} = ?1"), &[row[k].clone()])?
                };
                if let Some(to) = found.first().and_then(|r| r[0].int()) {
                    self.ids.entry(table).or_default().insert(source_id, to);
                    continue;
                }
                if !self.follow("machines", &cols, &mut row, "machine_id") {
                    row[at(&cols, "machine_id").unwrap_or(0)] = Val::Null;
                }
                row[id] = Val::Int(self.id_for(table, source_id)?);
                self.insert(table, &row)?;
            }
        }
        // A program's keys follow what the source says of it now.
        let programs: Vec<(i64, i64)> = self.ids.get("programs").map(|m| m.iter().map(|(a, b)| (*a, *b)).collect()).unwrap_or_default();
        let cols = self.cols("program_keys").to_vec();
        for (from, to) in programs {
            let rows = self.select("program_keys", "program_id = ?1", &[Val::Int(from)], "rule")?;
            let there = self.dst.rows("SELECT rule, key FROM program_keys WHERE program_id = ?1 ORDER BY rule", &[Val::Int(to)])?;
            let want: Vec<Vec<Val>> =
                rows.iter().map(|r| vec![r[at(&cols, "rule").unwrap_or(0)].clone(), r[at(&cols, "key").unwrap_or(0)].clone()]).collect();
            if there == want {
                continue;
            }
            self.dst.exec("DELETE FROM program_keys WHERE program_id = ?1", &[Val::Int(to)])?;
            for mut row in rows {
                self.follow("programs", &cols, &mut row, "program_id");
                self.insert("program_keys", &row)?;
            }
        }
        Ok(())
    }

    /// Every revision of the site in its own transaction with its bytes, plan, findings,
    /// workingsteps and features; then, for every revision, the re-analyses and queue entries
    /// the target lacks.
    fn revisions(&mut self, progress: &dyn Fn(usize, usize)) -> Result<()> {
        let cols = self.cols("revisions").to_vec();
        let (Some(id), Some(program), Some(hash), Some(seen)) =
            (at(&cols, "id"), at(&cols, "program_id"), at(&cols, "hash"), at(&cols, "seen_at"))
        else {
            return Ok(());
        };
        let programs: Vec<i64> = self.ids.get("programs").map(|m| m.keys().copied().collect()).unwrap_or_default();
        let mut all = Vec::new();
        for p in programs {
            all.extend(self.select("revisions", "program_id = ?1", &[Val::Int(p)], "id")?);
        }
        all.sort_by_key(|r| r[id].int());
        self.summary.revisions = all.len();
        for (n, mut row) in all.into_iter().enumerate() {
            let source_id = row[id].int().unwrap_or(0);
            self.follow("programs", &cols, &mut row, "program_id");
            let found = self.dst.rows(
                "SELECT id FROM revisions WHERE program_id = ?1 AND hash = ?2 AND seen_at = ?3",
                &[row[program].clone(), row[hash].clone(), row[seen].clone()],
            )?;
            if let Some(to) = found.first().and_then(|r| r[0].int()) {
                self.ids.entry("revisions").or_default().insert(source_id, to);
            } else {
                in_tx(self.dst, || self.revision(source_id, row))?;
                self.summary.copied += 1;
            }
            progress(n + 1, self.summary.revisions);
        }
        let revisions: Vec<i64> = self.ids.get("revisions").map(|m| m.keys().copied().collect()).unwrap_or_default();
        in_tx(self.dst, || {
            for r in &revisions {
                for table in ["analyses", "reanalysis_queue"] {
                    for row in self.select(table, "revision_id = ?1", &[Val::Int(*r)], "version")? {
                        self.insert_missing(table, row, &["revision_id", "version"])?;
                    }
                }
            }
            Ok(())
        })
    }

    /// One new revision: its blob unless the target has it, the revision, and what was found
    /// in it.
    fn revision(&mut self, source_id: i64, mut row: Vec<Val>) -> Result<()> {
        let cols = self.cols("revisions").to_vec();
        let hash = match &row[at(&cols, "hash").unwrap_or(0)] {
            Val::Text(h) => h.clone(),
            _ => return Err(StoreError::Setup(format!("revision {source_id} has no content hash"))),
        };
        if self.dst.blob(&hash)?.is_none() {
            match self.src.blob(&hash)? {
                Some((size, stored, mut from)) => self.dst.write_blob(&hash, size, stored, &mut from)?,
                None => return Err(StoreError::Setup(format!("revision {source_id}: the source has no bytes with hash {hash}"))),
            }
            *self.copied.entry("blobs").or_default() += 1;
        }
        let to = self.id_for("revisions", source_id)?;
        row[at(&cols, "id").unwrap_or(0)] = Val::Int(to);
        self.insert("revisions", &row)?;
        for (table, order) in
            [("plans", "revision_id"), ("diagnostics", "id"), ("workingsteps", "idx"), ("features", "id"), ("calls", "name")]
        {
            let tcols = self.cols(table).to_vec();
            for mut r in self.select(table, "revision_id = ?1", &[Val::Int(source_id)], order)? {
                r[at(&tcols, "revision_id").unwrap_or(0)] = Val::Int(to);
                if table == "diagnostics"
                    && let Some(i) = at(&tcols, "id")
                {
                    let d = r[i].int().unwrap_or(0);
                    r[i] = Val::Int(self.id_for("diagnostics", d)?);
                }
                self.insert(table, &r)?;
            }
        }
        Ok(())
    }

    /// Whether the target has a row of `table` whose `key` columns are those of `row`.
    fn has(&self, table: &str, row: &[Val], key: &[&str]) -> Result<bool> {
        let cols = self.cols(table);
        let key: Vec<usize> = key.iter().filter_map(|k| at(cols, k)).collect();
        let same: Vec<String> = key.iter().enumerate().map(|(n, i)| self.dst.same(&cols[*i], n + 1)).collect();
        let params: Vec<Val> = key.iter().map(|i| row[*i].clone()).collect();
        Ok(!self.dst.rows(&format!("SELECT 1 FROM {table} WHERE {}", same.join(" AND ")), &params)?.is_empty())
    }

    /// Inserts `row` of `table` unless the target has a row with the same `key` columns (after
    /// its references are followed). False when it names a row that was not copied.
    fn insert_missing(&mut self, table: &'static str, mut row: Vec<Val>, key: &[&str]) -> Result<bool> {
        let cols = self.cols(table).to_vec();
        for (col, to) in [
            ("revision_id", "revisions"),
            ("original_revision_id", "revisions"),
            ("superseded_by", "revisions"),
            ("program_id", "programs"),
        ] {
            if !self.follow(to, &cols, &mut row, col) {
                return Ok(false);
            }
        }
        self.own(&cols, &mut row);
        if !self.has(table, &row, key)? {
            self.insert(table, &row)?;
        }
        Ok(true)
    }

    /// Maps the change ids of `source` (rows of `cols`, the change id at `id`) onto those of
    /// `target` (rows of the id and the [`STABLE`] columns) that say the same, each once.
    fn map_changes(&mut self, cols: &[String], id: usize, source: &[Vec<Val>], target: &[Vec<Val>]) {
        let mut taken = vec![false; target.len()];
        for c in source {
            let said: Vec<Val> = STABLE.split(", ").map(|s| at(cols, s).map_or(Val::Null, |i| c[i].clone())).collect();
            if let Some(k) = (0..target.len()).find(|&k| !taken[k] && target[k][1..] == said[..]) {
                taken[k] = true;
                if let (Some(from), Some(t)) = (c[id].int(), target[k][0].int()) {
                    self.ids.entry("changes").or_default().entry(from).or_insert(t);
                }
            }
        }
    }

    /// Each comparison of a copied revision with a copied original, with its changes, in a
    /// transaction of its own; a comparison the target has keeps its changes, and the source's
    /// change ids go to those that say the same.
    fn comparisons(&mut self) -> Result<()> {
        let cols = self.cols("comparisons").to_vec();
        let ccols = self.cols("changes").to_vec();
        let (Some(rev), Some(orig)) = (at(&cols, "revision_id"), at(&cols, "original_revision_id")) else { return Ok(()) };
        let revisions: Vec<i64> = self.ids.get("revisions").map(|m| m.keys().copied().collect()).unwrap_or_default();
        for r in revisions {
            let Some(mut row) = self.select("comparisons", "revision_id = ?1", &[Val::Int(r)], "revision_id")?.pop() else { continue };
            let source_changes = self.select("changes", "revision_id = ?1", &[Val::Int(r)], "id")?;
            let (Some(to), Some(original)) = (self.mapped("revisions", &row[rev]), self.mapped("revisions", &row[orig])) else { continue };
            let id = at(&ccols, "id").unwrap_or(0);
            let there = self.dst.rows("SELECT 1 FROM comparisons WHERE revision_id = ?1", &[Val::Int(to)])?;
            if !there.is_empty() {
                // Copied before (or made there): its changes keep their ids.
                let target =
                    self.dst.rows(&format!("SELECT id, {STABLE} FROM changes WHERE revision_id = ?1 ORDER BY id"), &[Val::Int(to)])?;
                self.map_changes(&ccols, id, &source_changes, &target);
                continue;
            }
            row[rev] = Val::Int(to);
            row[orig] = Val::Int(original);
            in_tx(self.dst, || {
                self.insert("comparisons", &row)?;
                for mut c in source_changes {
                    c[at(&ccols, "revision_id").unwrap_or(0)] = Val::Int(to);
                    if let Some(i) = at(&ccols, "original_revision_id") {
                        c[i] = Val::Int(original);
                    }
                    let from = c[id].int().unwrap_or(0);
                    c[id] = Val::Int(self.id_for("changes", from)?);
                    self.insert("changes", &c)?;
                }
                Ok(())
            })?;
            self.summary.comparisons += 1;
        }
        Ok(())
    }

    /// The rows that name changes or nothing of the history: the changes old analyses found,
    /// partial-write marks, review marks, saved queries, sessions and the attempt journal.
    fn the_rest(&mut self) -> Result<()> {
        let revisions: Vec<i64> = self.ids.get("revisions").map(|m| m.keys().copied().collect()).unwrap_or_default();
        // Old changes, by the moment a comparison made again replaced them: a set the target
        // has keeps its change ids; else each keeps the id of the change it was (the same as a
        // kept change's), where free.
        let ocols = self.cols("old_changes").to_vec();
        if let (Some(oid), Some(when)) = (at(&ocols, "change_id"), at(&ocols, "replaced_at")) {
            for r in &revisions {
                let Some(to) = self.mapped("revisions", &Val::Int(*r)) else { continue };
                let rows = self.select("old_changes", "revision_id = ?1", &[Val::Int(*r)], "replaced_at, change_id")?;
                for group in rows.chunk_by(|a, b| a[when] == b[when]) {
                    let target = self.dst.rows(
                        &format!(
                            "SELECT change_id, {STABLE} FROM old_changes WHERE revision_id = ?1 AND replaced_at = ?2 ORDER BY change_id"
                        ),
                        &[Val::Int(to), group[0][when].clone()],
                    )?;
                    if !target.is_empty() {
                        self.map_changes(&ocols, oid, group, &target);
                        continue;
                    }
                    for row in group {
                        let mut row = row.clone();
                        let from = row[oid].int().unwrap_or(0);
                        row[oid] = Val::Int(self.id_for("changes", from)?);
                        for (col, table) in [("revision_id", "revisions"), ("original_revision_id", "revisions")] {
                            self.follow(table, &ocols, &mut row, col);
                        }
                        self.insert("old_changes", &row)?;
                    }
                }
            }
        }
        let rcols = self.cols("revision_marks").to_vec();
        for r in &revisions {
            for row in self.select("revision_marks", "revision_id = ?1", &[Val::Int(*r)], "revision_id")? {
                if at(&rcols, "revision_id").is_some() {
                    self.insert_missing("revision_marks", row, &["revision_id"])?;
                }
            }
        }
        // Review marks: on the change they name, by what they say.
        let mcols = self.cols("review_marks").to_vec();
        if let (Some(id), Some(change)) = (at(&mcols, "id"), at(&mcols, "change_id")) {
            for r in &revisions {
                for mut row in self.select("review_marks", "revision_id = ?1", &[Val::Int(*r)], "id")? {
                    let from = row[change].int().unwrap_or(0);
                    row[change] = Val::Int(match self.ids.get("changes").and_then(|m| m.get(&from)) {
                        Some(t) => *t,
                        None => self.id_for("changes", from)?,
                    });
                    let mut probe = row.clone();
                    if !self.follow("revisions", &mcols, &mut probe, "revision_id") {
                        continue;
                    }
                    self.summary.review_marks += 1;
                    if self.has("review_marks", &probe, &["change_id", "revision_id", "mark", "note", "marked_by", "marked_at"])? {
                        continue;
                    }
                    let source_id = row[id].int().unwrap_or(0);
                    probe[id] = Val::Int(self.id_for("review_marks", source_id)?);
                    self.insert("review_marks", &probe)?;
                }
            }
        }
        // Saved queries (the plant's, whichever site), sessions, the attempt journal.
        let scols = self.cols("saved_queries").to_vec();
        if let Some(id) = at(&scols, "id") {
            let key: Vec<&str> = scols.iter().map(String::as_str).filter(|c| *c != "id").collect();
            for mut row in self.select("saved_queries", "1 = 1", &[], "id")? {
                if self.has("saved_queries", &row, &key)? {
                    continue;
                }
                let source_id = row[id].int().unwrap_or(0);
                row[id] = Val::Int(self.id_for("saved_queries", source_id)?);
                self.insert("saved_queries", &row)?;
            }
        }
        // A suggestion's review steps (the plant's, by suggestion and step).
        for row in self.select("suggestion_events", "1 = 1", &[], "suggestion, step")? {
            self.insert_missing("suggestion_events", row, &["suggestion", "step"])?;
        }
        for row in self.select("web_sessions", "1 = 1", &[], "token_hash")? {
            self.insert_missing("web_sessions", row, &["token_hash"])?;
        }
        let (filter, params) = self.site_filter();
        let key: &[&str] = if self.dst.by_site() { &["site", "hash", "path"] } else { &["hash", "path"] };
        for row in self.select("attempts", filter, &params, "hash, path")? {
            self.insert_missing("attempts", row, key)?;
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    /// The tables the migrations create, in no order.
    fn created(migrations: &[&str]) -> Vec<String> {
        let mut t: Vec<String> = migrations
            .iter()
            .flat_map(|m| m.split("CREATE TABLE ").skip(1))
            .map(|s| s.split(|c: char| c.is_whitespace() || c == '(').next().unwrap_or("").to_owned())
            .collect();
        t.sort();
        t
    }

    /// `ncplan migrate` copies every table the schema has: a table added by a later
    /// migration fails here until it is in [`super::COPIED`] (and `copy` has its rule).
    #[test]
    fn migrate_copies_every_table_of_the_schema() {
        let mut copied: Vec<String> = super::COPIED.iter().map(|t| (*t).to_owned()).collect();
        copied.sort();
        assert_eq!(copied, created(crate::store::schema::MIGRATIONS));
        assert_eq!(copied, created(crate::store::pg_schema::MIGRATIONS));
        assert!(!crate::store::schema::MIGRATIONS.iter().any(|m| m.contains("DROP TABLE")), "a dropped table: say whether it is copied");
    }
}

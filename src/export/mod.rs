//! Knowledge back to CAM in the shell: the store's edits in the `suggest` room's terms, each
//! suggestion's review state, the steps planners and the watch record, and the files written
//! into the outbox.
//!
//! [`load`] reads the edits (`suggestion_edits`), names each one's tool as the CAM knows it
//! (the original's plan: number, tool comment, diameter, flutes, corner radius; the shop's
//! tool lists where `[suggest] tool_library` names them and one has the number: Fusion JSON,
//! a FreeCAD library `.fctl` with its bits or a bit `.fctb`, a tool table), its material
//! (the original's header comments, else `[[suggest.material]]` by folder, else `unknown`),
//! its operator (a header comment of the edited program its original lacks, else
//! `[[suggest.operator]]` by the edited file's folder), tells a `feed_changed` row's feeds
//! apart by role (the original read again, the store keeping no toolpaths), converts inch
//! programs' values to metric, and asks `suggest::suggest`; then each group's
//! steps give its state (`suggest::review::current`) and, once exported, the watch over the
//! CAM posts since. [`watch`] is what the daemon runs after it stores a revision: the watch's
//! steps (adopted, reopened) recorded while some suggestion is exported or adopted. [`record`]
//! writes what the rules and the watch found (a new suggestion proposed, an exported one
//! adopted or reopened) as steps by `ncplan`; [`review`] a
//! planner's step, refused where the state does not allow it. `files` writes the outbox:
//! never a watched folder, never the shop's tool library.

pub mod files;

pub use crate::suggest::review::State;

use std::collections::BTreeMap;
use std::path::Path;

use anyhow::{Context, Result, bail};

use crate::config::{Config, SuggestSettings};
use crate::store::{EditRow, Store, SuggestionStep};
use crate::suggest::freecad;
use crate::suggest::library::{self, Library};
use crate::suggest::review::{self, CamStep, Event, Watch};
use crate::suggest::{
    Edit, FeedMove, FeedRole, Parameter, Suggestion, ToolKey, feed_edits, feed_list, feed_roles, first_number, header_material,
    header_operator, suggest,
};

/// A group with its verdict, its review and the watch.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Entry {
    /// The group's verdict (a suggestion when it passed every gate).
    pub s: Suggestion,
    /// Its state now.
    pub state: State,
    /// Its recorded steps.
    pub events: Vec<Event>,
    /// What the watch sees, once exported.
    pub watch: Option<Watch>,
}

/// What the knowledge pages, the command and the exports show.
#[derive(Clone, Debug)]
pub struct Knowledge {
    /// Every group, suggestions first, in key order.
    pub entries: Vec<Entry>,
    /// The shop's tool library, where configured.
    pub library: Option<Library>,
    /// Edits whose values could not be read (change id, why).
    pub unread: Vec<(i64, String)>,
    /// The time it was made for.
    pub now: String,
}

impl Knowledge {
    /// The entry of a suggestion id.
    pub fn entry(&self, id: &str) -> Option<&Entry> {
        self.entries.iter().find(|e| e.s.id == id)
    }

    /// The suggestions (groups that passed every gate), or were reviewed once.
    pub fn suggestions(&self) -> impl Iterator<Item = &Entry> {
        self.entries.iter().filter(|e| e.s.passed() || !e.events.is_empty())
    }
}

/// What one original tells: its tools, units, material, the roles of each workingstep's
/// feeds and its operator comment (a CAM header naming the programmer is no editor).
#[derive(Clone)]
struct Original {
    tools: BTreeMap<u32, ToolKey>,
    inch: bool,
    material: Option<String>,
    roles: Option<BTreeMap<u32, Vec<Option<FeedRole>>>>,
    operator: Option<String>,
}

/// Each workingstep's feeds (plan units, mm/min) with their roles (`suggest::feed_roles`).
type FeedsByStep = BTreeMap<u32, Vec<(f64, Option<FeedRole>)>>;

/// An edited revision's path and the operator comment of its header.
type EditedHead = (String, Option<String>);

/// What [`load_with`] reads of stored revisions, kept from one load to the next (the
/// workspace keeps one for as long as it serves): an original's tools, units, material and
/// operator comment, an edited revision's path and operator comment, a program's feeds by role
/// (read again through the analysis). A stored revision never changes (its bytes are
/// content-addressed, its row and plan never updated), so what it told once holds; the
/// configuration's rules (materials and operators by folder, the tool library) are applied
/// on each load, after the cache. Keyed by revision id, for one database.
#[derive(Default)]
pub struct Cache {
    originals: std::sync::Mutex<BTreeMap<i64, Original>>,
    edited: std::sync::Mutex<BTreeMap<i64, Option<EditedHead>>>,
    feeds: std::sync::Mutex<BTreeMap<i64, std::sync::Arc<FeedsByStep>>>,
}

impl Cache {
    /// How many revisions it holds (originals, edited revisions, programs read again).
    pub fn len(&self) -> (usize, usize, usize) {
        let originals = self.originals.lock().map_or(0, |m| m.len());
        let edited = self.edited.lock().map_or(0, |m| m.len());
        (originals, edited, self.feeds.lock().map_or(0, |m| m.len()))
    }

    /// Whether it holds nothing.
    pub fn is_empty(&self) -> bool {
        self.len() == (0, 0, 0)
    }

    fn original(&self, store: &Store, revision: i64) -> Result<Original> {
        kept(&self.originals, revision, || original(store, revision))
    }

    /// The path and the header's operator comment of an edited revision.
    fn edited(&self, store: &Store, revision: i64) -> Result<Option<EditedHead>> {
        kept(&self.edited, revision, || edited_head(store, revision))
    }
}

/// What `map` keeps for `revision`, or what `read` makes of it, then kept.
fn kept<T: Clone>(map: &std::sync::Mutex<BTreeMap<i64, T>>, revision: i64, read: impl FnOnce() -> Result<T>) -> Result<T> {
    if let Some(v) = map.lock().ok().and_then(|m| m.get(&revision).cloned()) {
        return Ok(v);
    }
    let v = read()?;
    if let Ok(mut m) = map.lock() {
        m.insert(revision, v.clone());
    }
    Ok(v)
}

/// Programs read again for their moves (the store keeps plans without their toolpaths), as
/// their folders read them: the dictionaries loaded once, on first need, and each revision's
/// feeds kept.
struct Reread<'a> {
    config: &'a Config,
    registry: Option<crate::dialect::Registry>,
    cache: &'a Cache,
}

impl<'a> Reread<'a> {
    fn new(config: &'a Config, cache: &'a Cache) -> Reread<'a> {
        Reread { config, registry: None, cache }
    }

    /// The feeds of each workingstep of `revision`, with their roles; empty where it cannot be read.
    fn feeds(&mut self, store: &Store, revision: i64) -> Result<std::sync::Arc<FeedsByStep>> {
        let cache = self.cache;
        kept(&cache.feeds, revision, || {
            if self.registry.is_none() {
                self.registry = Some(crate::config::dialect_registry(self.config.dialects_dir.as_deref())?);
            }
            let reader = crate::daemon::ingest::Reader { config: self.config, registry: self.registry.as_ref().expect("just read") };
            Ok(std::sync::Arc::new(feeds_of(store, &reader, revision)))
        })
    }

    /// The feed of `role` in workingstep `step` of `revision`: the first of that role.
    fn feed(&mut self, store: &Store, revision: i64, step: u32, role: FeedRole) -> Result<Option<f64>> {
        let f = self.feeds(store, revision)?;
        Ok(f.get(&step).and_then(|v| v.iter().find(|(_, r)| *r == Some(role)).map(|(f, _)| *f)))
    }
}

/// The feeds of each workingstep of a stored program, with their roles: the program read again.
fn feeds_of(store: &Store, reader: &crate::daemon::ingest::Reader<'_>, revision: i64) -> FeedsByStep {
    let Ok(Some(src)) = store.source(revision) else { return BTreeMap::new() };
    let bytes = match src.bytes.clone() {
        Some(b) => b,
        None => store.content(revision).ok().flatten().unwrap_or_default(),
    };
    let Ok(a) = reader.reanalyse(&src.path, &src.dialect, bytes) else { return BTreeMap::new() };
    a.plan
        .workingsteps
        .iter()
        .map(|w| {
            let moves: Vec<FeedMove> = w
                .toolpath
                .iter()
                .filter(|m| m.kind != crate::plan::MoveKind::Rapid)
                .map(|m| FeedMove { from: m.from, to: m.to, feed: m.feed })
                .collect();
            let roles = feed_roles(&w.technology.feeds, &moves);
            (w.index, w.technology.feeds.iter().copied().zip(roles).collect())
        })
        .collect()
}

/// Reads an original revision's plan (tools, units) and header (material).
fn original(store: &Store, revision: i64) -> Result<Original> {
    let mut o = Original { tools: BTreeMap::new(), inch: false, material: None, roles: None, operator: None };
    if let Some(src) = store.source(revision)?
        && let Some((plan, _)) = &src.plan
        && let Ok(v) = serde_json::from_str::<serde_json::Value>(plan)
    {
        o.inch = v.get("units").and_then(|u| u.as_str()).is_some_and(|u| u.to_ascii_lowercase().starts_with("in"));
        for t in v.get("tools").and_then(|t| t.as_array()).into_iter().flatten() {
            let Some(number) = t.get("number").and_then(|n| n.as_u64()) else { continue };
            let key = ToolKey {
                number: number as u32,
                description: t.get("name").and_then(|n| n.as_str()).map(crate::suggest::tool_description).unwrap_or_default(),
                diameter: t.get("diameter").and_then(|d| d.as_f64()),
                flutes: t.get("flutes").and_then(|z| z.as_u64()).map(|z| z as u32),
                corner_radius: t.get("corner_radius").and_then(|r| r.as_f64()),
            };
            o.tools.insert(key.number, key);
        }
    }
    if let Some(bytes) = store.content(revision)? {
        let head = &bytes[..bytes.len().min(8192)];
        o.material = header_material(&String::from_utf8_lossy(head), 40);
        o.operator = header_operator(&String::from_utf8_lossy(head), 40);
    }
    Ok(o)
}

/// The shop's tool lists, where configured, as one library (the first list that has a number
/// names it).
pub fn read_library(settings: &SuggestSettings) -> Result<Option<Library>> {
    if settings.tool_libraries.is_empty() {
        return Ok(None);
    }
    let mut lib = Library::empty();
    for path in &settings.tool_libraries {
        lib.merge(read_one_library(path)?);
    }
    Ok(Some(lib))
}

/// One tool list, by its name and text: a FreeCAD library (`.fctl`, its bits read beside it)
/// or bit (`.fctb`), a Fusion / Inventor CAM / HSM library (JSON with a `data` list), else a
/// tool table.
fn read_one_library(path: &Path) -> Result<Library> {
    let text = std::fs::read_to_string(path).with_context(|| format!("cannot read the tool library {}", path.display()))?;
    let ext = path.extension().and_then(|e| e.to_str()).unwrap_or("").to_ascii_lowercase();
    let wrap = |e: String| anyhow::anyhow!("the tool library {}: {e}", path.display());
    match ext.as_str() {
        "fctl" => {
            let dir = path.parent().unwrap_or(Path::new("."));
            let mut tools = Vec::new();
            for (nr, bit_path) in freecad::library(&text).map_err(wrap)? {
                let bit = freecad_bit_file(dir, &bit_path)
                    .with_context(|| format!("the tool library {}: tool {nr}'s bit {bit_path}", path.display()))?;
                let mut t =
                    freecad::bit(&std::fs::read_to_string(&bit)?).map_err(|e| anyhow::anyhow!("the tool bit {}: {e}", bit.display()))?;
                t.number = Some(nr);
                tools.push(t);
            }
            Ok(Library { version: serde_json::Value::Null, tools })
        }
        // A bit alone has no number: it names no T number, but is listed.
        "fctb" => Ok(Library { version: serde_json::Value::Null, tools: vec![freecad::bit(&text).map_err(wrap)?] }),
        _ if text.trim_start().starts_with('{') => library::read(&text).map_err(wrap),
        _ => {
            let (_, tools) = crate::plan::tooltable::read(&text, false).map_err(wrap)?;
            Ok(library::from_tool_table(&tools))
        }
    }
}

/// A FreeCAD bit's file as a library names it: absolute, beside the library, or in the `Bit`
/// folder beside the library's folder (FreeCAD's `Tools/Library` and `Tools/Bit`).
fn freecad_bit_file(dir: &Path, bit: &str) -> Result<std::path::PathBuf> {
    let p = Path::new(bit);
    let candidates = [dir.join(p), dir.join("..").join("Bit").join(p), dir.join("Bit").join(p)];
    candidates.into_iter().find(|c| c.is_file()).with_context(|| "no such file beside the library or in its Bit folder".to_owned())
}

/// The edits of `rows` in the rules' terms.
struct Edits {
    /// Those the rules read: adopted by a planner (or unreviewed too, where configured).
    accepted: Vec<Edit>,
    /// Every one not rejected (the watch's).
    all: Vec<Edit>,
    /// Those whose values could not be read: change id, why.
    unread: Vec<(i64, String)>,
}

/// The parameters and values (as written) a row holds: a `feed_changed` row by the roles of
/// the original workingstep's feeds, one edit per role that changed; any other row its
/// parameter with the first number of each side. `Err` when no value reads.
fn row_values(r: &EditRow, o: &Original) -> std::result::Result<Vec<(Parameter, f64, f64)>, String> {
    let Some(parameter) = Parameter::of_change(&r.kind, &r.field) else { return Ok(Vec::new()) };
    if parameter == Parameter::CuttingFeed {
        let (before, after) = (feed_list(&r.before), feed_list(&r.after));
        if before.is_empty() || after.is_empty() {
            return Err(format!("no number in `{}` → `{}`", r.before, r.after));
        }
        let roles = o.roles.as_ref().and_then(|m| m.get(&(r.workingstep.max(0) as u32))).cloned().unwrap_or_default();
        return feed_edits(&before, &after, &roles).ok_or_else(|| {
            format!("the workingstep's feeds changed in number (`{}` → `{}`): which is which cannot be told", r.before, r.after)
        });
    }
    match (first_number(&r.before), first_number(&r.after)) {
        (Some(b), Some(a)) => Ok(vec![(parameter, b, a)]),
        _ => Err(format!("no number in `{}` → `{}`", r.before, r.after)),
    }
}

/// Who made the edit of revision `revision`, where the share tells it: an operator comment in
/// the edited program's header that its original does not carry (`(OPERATOR: ANNA)`), else
/// `[[suggest.operator]]` by the edited file's folder.
fn operator(cache: &Cache, store: &Store, revision: i64, o: &Original, cfg: &SuggestSettings) -> Result<Option<String>> {
    let Some((path, head)) = cache.edited(store, revision)? else { return Ok(None) };
    let comment = head.filter(|c| o.operator.as_ref() != Some(c));
    Ok(comment.or_else(|| cfg.operators.iter().find(|(f, _)| Path::new(&path).starts_with(f)).map(|m| m.1.clone())))
}

/// An edited revision's path and the operator comment of its header.
fn edited_head(store: &Store, revision: i64) -> Result<Option<EditedHead>> {
    let Some(src) = store.source(revision)? else { return Ok(None) };
    let bytes = match src.bytes {
        Some(b) => b,
        None => store.content(revision)?.unwrap_or_default(),
    };
    let head = String::from_utf8_lossy(&bytes[..bytes.len().min(8192)]).into_owned();
    Ok(Some((src.path, header_operator(&head, 40))))
}

/// The edits of `rows` in the rules' terms.
fn edits(store: &Store, rows: &[EditRow], reread: &mut Reread<'_>, lib: Option<&Library>) -> Result<Edits> {
    let cfg = &reread.config.suggest;
    let mut originals: BTreeMap<i64, Original> = BTreeMap::new();
    let mut operators: BTreeMap<i64, Option<String>> = BTreeMap::new();
    let (mut accepted, mut all, mut unread) = (Vec::new(), Vec::new(), Vec::new());
    for r in rows {
        if Parameter::of_change(&r.kind, &r.field).is_none() || r.review.as_deref() == Some("reject") {
            continue;
        }
        let o = match originals.entry(r.original_revision_id) {
            std::collections::btree_map::Entry::Occupied(o) => o.into_mut(),
            std::collections::btree_map::Entry::Vacant(v) => v.insert(reread.cache.original(store, r.original_revision_id)?),
        };
        // A feed change of a workingstep of several feeds: which is which, from its moves.
        if o.roles.is_none() && r.kind == "feed_changed" && feed_list(&r.before).len() > 1 {
            let feeds = reread.feeds(store, r.original_revision_id)?;
            o.roles = Some(feeds.iter().map(|(step, f)| (*step, f.iter().map(|x| x.1).collect())).collect());
        }
        let values = match row_values(r, o) {
            Ok(v) => v,
            Err(why) => {
                unread.push((r.change_id, why));
                continue;
            }
        };
        if values.is_empty() {
            continue;
        }
        let who = match operators.entry(r.revision_id) {
            std::collections::btree_map::Entry::Occupied(w) => w.get().clone(),
            std::collections::btree_map::Entry::Vacant(v) => v.insert(operator(reread.cache, store, r.revision_id, o, cfg)?).clone(),
        };
        let number = r.tool.unwrap_or(0).max(0) as u32;
        let mut tool = o.tools.get(&number).cloned().unwrap_or(ToolKey { number, ..ToolKey::default() });
        if let Some(t) = lib.and_then(|l| l.tools.iter().find(|t| t.is(&tool))) {
            tool = t.key();
        }
        let material = o
            .material
            .clone()
            .or_else(|| cfg.materials.iter().find(|(f, _)| Path::new(&r.original_path).starts_with(f)).map(|m| m.1.clone()))
            .unwrap_or_else(|| "unknown".into());
        for (parameter, b, a) in values {
            let e = Edit {
                change_id: r.change_id,
                revision_id: r.revision_id,
                program: r.program.clone(),
                original: r.original_path.clone(),
                workingstep: r.workingstep.max(0) as u32,
                operation: r.operation.clone(),
                machine: r.machine.clone(),
                at: r.seen_at.clone(),
                operator: who.clone(),
                spindle: r.spindle_speed,
                tool: tool.clone(),
                material: material.clone(),
                parameter,
                before: parameter.metric(b, o.inch),
                after: parameter.metric(a, o.inch),
            };
            if r.review.as_deref() == Some("adopt") || cfg.unreviewed {
                accepted.push(e.clone());
            }
            all.push(e);
        }
    }
    Ok(Edits { accepted, all, unread })
}

/// A stored step as the review reads it.
fn event(s: &SuggestionStep) -> Option<Event> {
    Some(Event {
        suggestion: s.suggestion.clone(),
        step: s.step,
        state: State::parse(&s.state)?,
        reason: s.reason.clone(),
        value: s.value,
        evidence: s.evidence,
        by: s.by.clone(),
        at: s.at.clone(),
    })
}

/// The value a CAM workingstep gives for a parameter (plan units are metric already): a feed
/// by its role, from the post read again where its workingstep has several feeds.
fn cam_value(store: &Store, reread: &mut Reread<'_>, c: &crate::store::CamRow, p: Parameter) -> Result<Option<f64>> {
    let role = match p {
        Parameter::CuttingFeed => FeedRole::Cutting,
        Parameter::PlungeFeed => FeedRole::Plunge,
        Parameter::RampFeed => FeedRole::Ramp,
        Parameter::SpindleSpeed => return Ok(c.spindle_speed),
        Parameter::Stepdown => return Ok(c.axial_depth),
        Parameter::Stepover => return Ok(c.radial_depth),
        Parameter::ClearanceHeight => return Ok(c.security_plane),
        Parameter::CuttingSpeed | Parameter::PeckDepth => return Ok(None),
    };
    reread.feed(store, c.revision, c.workingstep.max(0) as u32, role)
}

/// The CAM posts after `since` of the programs behind `s` with its tool (the others cannot
/// carry its value), each with its value of `s`'s parameter.
fn cam_posts(store: &Store, reread: &mut Reread<'_>, s: &Suggestion, since: &str) -> Result<Vec<CamStep>> {
    let behind = |c: &&crate::store::CamRow| c.tool.max(0) as u32 == s.key.tool.number && s.edits.iter().any(|e| e.original == c.path);
    let mut cam: Vec<CamStep> = Vec::new();
    for c in store.cam_steps_since(since)?.iter().filter(behind) {
        cam.push(CamStep {
            original: c.path.clone(),
            revision: c.revision,
            at: c.seen_at.clone(),
            workingstep: c.workingstep.max(0) as u32,
            tool: c.tool.max(0) as u32,
            value: cam_value(store, reread, c, s.key.parameter)?,
        });
    }
    Ok(cam)
}

/// Everything the knowledge pages and the exports show, as of `now`.
pub fn load(store: &Store, config: &Config, now: &str) -> Result<Knowledge> {
    load_with(store, config, now, &Cache::default())
}

/// [`load`], with what `cache` holds of the stored revisions from earlier loads (and adding
/// what this one reads).
pub fn load_with(store: &Store, config: &Config, now: &str, cache: &Cache) -> Result<Knowledge> {
    let cfg = &config.suggest;
    let lib = read_library(cfg)?;
    let rows = store.suggestion_edits()?;
    let mut reread = Reread::new(config, cache);
    let Edits { accepted, all, unread } = edits(store, &rows, &mut reread, lib.as_ref())?;
    let mut steps: BTreeMap<String, Vec<Event>> = BTreeMap::new();
    for s in store.suggestion_steps()? {
        if let Some(e) = event(&s) {
            steps.entry(s.suggestion.clone()).or_default().push(e);
        }
    }
    let verdicts = suggest(&accepted, &cfg.rules);
    let mut entries = Vec::new();
    for mut s in verdicts {
        let events = steps.remove(&s.id).unwrap_or_default();
        let mut state = review::current(&events, s.edits.len(), now, &cfg.rules);
        let exported = events.iter().rev().find(|e| e.state == State::Exported).map(|e| e.at.clone());
        let group = || -> Vec<Edit> { all.iter().filter(|e| e.key() == s.key).cloned().collect() };
        let watch = match (state, exported) {
            (State::Exported | State::Adopted, Some(since)) => {
                let cam = cam_posts(store, &mut reread, &s, &since)?;
                Some(review::watch(&s, &since, &group(), &cam, &cfg.rules))
            }
            _ => None,
        };
        if let Some(w) = &watch
            && let Some(to) = review::watch_move(state, w)
        {
            state = to;
        }
        // A group the CAM took up on its own after its last edit is no suggestion.
        if watch.is_none()
            && s.passed()
            && !matches!(state, State::Reopened)
            && let Some(last) = group().iter().map(|e| e.at.clone()).max()
        {
            let cam = cam_posts(store, &mut reread, &s, &last)?;
            if let Some((revision, at)) = review::carried(&s, &group(), &cam, &cfg.rules) {
                s.held.push(crate::suggest::Held::CamCarries { revision, at });
            }
        }
        entries.push(Entry { s, state, events, watch });
    }
    entries.sort_by(|a, b| b.s.passed().cmp(&a.s.passed()).then(a.s.key.text().cmp(&b.s.key.text())));
    Ok(Knowledge { entries, library: lib, unread, now: now.to_owned() })
}

/// A step for `e`, to record `after` steps (the number of the last step read, `e`'s or one
/// recorded since): the store records it only where no other writer recorded that step first.
fn step(e: &Entry, after: i64, state: State, reason: &str, by: &str, at: &str) -> SuggestionStep {
    SuggestionStep {
        suggestion: e.s.id.clone(),
        step: after + 1,
        group_key: e.s.key.text(),
        state: state.name().into(),
        reason: reason.into(),
        value: e.s.suggested,
        evidence: e.s.edits.len() as i64,
        by: by.into(),
        at: at.into(),
    }
}

/// Records what the rules and the watch found since the last time: a suggestion with no
/// steps is proposed; an exported one the watch adopted or reopened moves there; a rejected
/// or snoozed one that came back is proposed again. Returns how many steps were written.
pub fn record(store: &Store, k: &Knowledge, at: &str) -> Result<usize> {
    record_some(store, k, at, false)
}

/// Records only what the watch found: an exported (or adopted) suggestion adopted or reopened.
/// Each step follows the last step `k` read: where another writer (a second daemon on the same
/// database) recorded a step since, this one is not recorded and not counted.
fn record_some(store: &Store, k: &Knowledge, at: &str, watch_only: bool) -> Result<usize> {
    let mut n = 0;
    for e in &k.entries {
        if let Some((state, reason)) = pending(e, watch_only)
            && store.add_suggestion_step(&step(e, last_step(e), state, &reason, "ncplan", at))?.is_some()
        {
            n += 1;
        }
    }
    Ok(n)
}

/// The number of `e`'s last recorded step (0 for none).
fn last_step(e: &Entry) -> i64 {
    e.events.last().map_or(0, |x| x.step)
}

/// What a planner is told when another writer recorded a step of `id` after the page was read.
fn moved_meanwhile(id: &str) -> anyhow::Error {
    anyhow::anyhow!("suggestion {id} changed meanwhile (another review or the watch recorded a step): read it again")
}

/// The step the rules or the watch ask for `e` and its reason, not recorded yet: the watch's
/// (adopted, reopened) and, unless `watch_only`, the rules' (proposed, again after a
/// rejection whose evidence grew or a snooze that ended).
fn pending(e: &Entry, watch_only: bool) -> Option<(State, String)> {
    let last = e.events.last().map(|x| x.state);
    match (last, e.state) {
        (Some(l), s) if l != s && matches!(s, State::Adopted | State::Reopened) => {
            Some((s, e.watch.as_ref().map(Watch::words).unwrap_or_default()))
        }
        _ if watch_only => None,
        (None, State::Proposed) if e.s.passed() => Some((State::Proposed, "the rules' gates passed".to_owned())),
        (Some(State::Rejected), State::Proposed) => Some((State::Proposed, "the evidence grew since the rejection".to_owned())),
        (Some(State::Snoozed), State::Proposed) => Some((State::Proposed, "the snooze is over".to_owned())),
        _ => None,
    }
}

/// The watch after an export, as the daemon runs it once a revision is stored: where some
/// suggestion is exported or adopted, what the CAM posts and the edits since say is recorded
/// (adopted, reopened) by `ncplan`, at `at`. Nothing is read beyond the steps while no
/// suggestion is watched. Returns how many steps were written.
pub fn watch(store: &Store, config: &Config, at: &str) -> Result<usize> {
    let mut last: BTreeMap<String, String> = BTreeMap::new();
    for s in store.suggestion_steps()? {
        last.insert(s.suggestion, s.state);
    }
    if !last.values().any(|s| s == State::Exported.name() || s == State::Adopted.name()) {
        return Ok(0);
    }
    let k = load(store, config, at)?;
    record_some(store, &k, at, true)
}

/// A planner's step on suggestion `id`: to `to` with `reason` (a rejection needs one),
/// refused where the current state does not allow it.
pub fn review(store: &Store, k: &Knowledge, id: &str, to: State, reason: &str, by: &str, at: &str) -> Result<()> {
    let Some(e) = k.entry(id) else { bail!("no suggestion {id}") };
    if !e.state.planner_moves().contains(&to) {
        bail!("suggestion {id} is {}: it cannot be {} now", e.state.name(), to.name());
    }
    if to == State::Rejected && reason.trim().is_empty() {
        bail!("a rejection needs its reason");
    }
    // What the rules and the watch found first (proposed, proposed again, adopted, reopened),
    // so that the record shows the state the planner moved it from.
    let first = match pending(e, false) {
        Some(p) => Some(p),
        None if e.events.is_empty() => Some((State::Proposed, "the rules' gates passed".to_owned())),
        None => None,
    };
    let mut after = last_step(e);
    if let Some((state, why)) = first {
        after = store.add_suggestion_step(&step(e, after, state, &why, "ncplan", at))?.ok_or_else(|| moved_meanwhile(id))?;
    }
    store.add_suggestion_step(&step(e, after, to, reason.trim(), by, at))?.ok_or_else(|| moved_meanwhile(id))?;
    Ok(())
}

/// Marks the suggestions in `ids` exported (by `by`, at `at`); one whose state another
/// writer changed since `k` was read (an export running twice at once, a rejection) is
/// left as that writer left it.
pub fn mark_exported(store: &Store, k: &Knowledge, ids: &[String], to: &Path, by: &str, at: &str) -> Result<()> {
    for id in ids {
        if let Some(e) = k.entry(id) {
            store.add_suggestion_step(&step(e, last_step(e), State::Exported, &format!("written to {}", to.display()), by, at))?;
        }
    }
    Ok(())
}

/// One line for a terminal: id, state, what, values, figures.
pub fn line(e: &Entry) -> String {
    let s = &e.s;
    let k = &s.key;
    let change = match k.parameter.scale() {
        crate::suggest::Scale::Ratio => format!("{:+.1} %", s.change() * 100.0),
        crate::suggest::Scale::Offset => format!("{:+} mm", crate::suggest::num(s.change())),
    };
    format!(
        "{} {:<9} {} of {} · {} · {} · {}: CAM {} -> {} {} ({change}; {} to {}); {} edits, {} programs, {} days{}, p={}",
        s.id,
        if s.passed() || !e.events.is_empty() { e.state.name() } else { "held" },
        k.parameter.label(),
        k.tool.label(),
        k.material,
        k.machine,
        k.class.name(),
        crate::suggest::num(s.cam_value),
        crate::suggest::num(s.suggested),
        k.parameter.unit(),
        crate::suggest::num(s.interval.0),
        crate::suggest::num(s.interval.1),
        s.edits.len(),
        s.programs,
        s.days,
        if s.operators > 0 { format!(", {} operators", s.operators) } else { String::new() },
        crate::suggest::render::fmt_p(s.p),
    )
}

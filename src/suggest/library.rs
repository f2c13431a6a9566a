//! The CAM side's tool libraries: Autodesk Fusion / Inventor CAM / HSM JSON, read and written;
//! the shop's other tool lists (FreeCAD's bits and libraries, `freecad`; the tool tables
//! `plan::tooltable` reads: LinuxCNC `tool.tbl`, Heidenhain `TOOL.T`, Fanuc `G10`, Siemens
//! `$TC_DP`) only name the CAM tool ([`from_tool_table`], [`Library::merge`]).
//!
//! The format, as public libraries show it: `{"data": [tool, …], "version": n}`; a tool has a
//! `guid`, `type` (`flat end mill`, `drill`, …), `description`, `unit` (`millimeters` or
//! `inches`), `geometry` (`DC` cutter diameter, `NOF` flutes, `RE` corner radius, lengths),
//! `post-process` (`number`, `length-offset`, `diameter-offset`, `comment`) and
//! `start-values`: in the older form one set of cutting data under the key `*`, in the newer
//! a `presets` list, each preset with its own `guid`, `name`, `description`, `material`
//! (`category`, `query`, `use-hardness`) and values (`n` spindle speed, `v_c` cutting speed,
//! `f_z` feed per tooth, `v_f` cutting feed, `v_f_plunge`, `v_f_ramp`, `stepdown`,
//! `stepover` with `use-stepdown`/`use-stepover`, and `expressions` that may restate them).
//! Feeds are per minute and lengths in the tool's unit; `v_c` is m/min or ft/min.
//!
//! [`read`] takes either form. [`export`] copies each affected tool with a new `guid`, keeps
//! every original preset (and an older `*` set) as it was, and adds one preset per accepted
//! suggestion: the base preset's values with the suggestion's parameter (and what follows
//! from it: `f_z` from `v_f`, `v_c` from `n`) set, without `expressions` (so that the
//! numbers stand), its `description` the evidence in one line. The guids are derived from the
//! original's and the suggestions' ids, so the same export gives the same file.

use std::collections::BTreeMap;

use serde_json::{Map, Value, json};
use sha2::{Digest, Sha256};

use super::{OpClass, Parameter, Suggestion, ToolKey, num, render};

/// A tool read from a library.
#[derive(Clone, Debug, PartialEq)]
pub struct LibraryTool {
    /// The post-process number (the T number the post writes).
    pub number: Option<u32>,
    /// Description.
    pub description: String,
    /// Kind (`flat end mill`, …).
    pub kind: String,
    /// Whether its lengths and feeds are in inches.
    pub inch: bool,
    /// Cutter diameter, mm.
    pub diameter: Option<f64>,
    /// Flutes.
    pub flutes: Option<u32>,
    /// Corner radius, mm.
    pub corner_radius: Option<f64>,
    /// Its presets: name and numeric values (the older form's `*` set as one named `*`).
    pub presets: Vec<(String, BTreeMap<String, f64>)>,
    /// The tool as it was read from a Fusion library (`Null` from another format: an export
    /// makes the tool from what it knows of it).
    pub raw: Value,
}

/// A library read.
#[derive(Clone, Debug, PartialEq)]
pub struct Library {
    /// Its `version`.
    pub version: Value,
    /// Its tools.
    pub tools: Vec<LibraryTool>,
}

impl Library {
    /// An empty library.
    pub fn empty() -> Library {
        Library { version: Value::Null, tools: Vec::new() }
    }

    /// Adds `other`'s tools after this one's (a number found in both is this one's: the first
    /// library configured names it); the version stays the first Fusion library's.
    pub fn merge(&mut self, other: Library) {
        if self.version.is_null() {
            self.version = other.version;
        }
        self.tools.extend(other.tools);
    }
}

/// The tools of a tool table (LinuxCNC `tool.tbl`, Heidenhain `TOOL.T`, Fanuc `G10` offsets,
/// Siemens `$TC_DP` data, as `plan::tooltable` reads them): number, name (a LinuxCNC comment, a
/// Heidenhain `NAME`, a Siemens `$TC_TP2`), diameter, corner radius and flutes where it says them.
pub fn from_tool_table(tools: &crate::plan::tooltable::Tools) -> Library {
    let tools = tools
        .iter()
        .map(|(n, t)| LibraryTool {
            number: Some(*n),
            description: t.name.clone().unwrap_or_default().trim().to_owned(),
            kind: t.kind.clone().unwrap_or_default(),
            inch: false,
            diameter: t.diameter,
            flutes: t.flutes,
            corner_radius: t.corner_radius,
            presets: Vec::new(),
            raw: Value::Null,
        })
        .collect();
    Library { version: Value::Null, tools }
}

/// Reads a library's JSON (either form). An entry that is not a tool (a holder) is kept
/// with what it has.
pub fn read(text: &str) -> Result<Library, String> {
    let v: Value = serde_json::from_str(text).map_err(|e| format!("not JSON: {e}"))?;
    let data = v.get("data").and_then(Value::as_array).ok_or("no `data` list: not a tool library")?;
    Ok(Library { version: v.get("version").cloned().unwrap_or(Value::Null), tools: data.iter().map(tool).collect() })
}

/// One tool of a library.
fn tool(t: &Value) -> LibraryTool {
    let inch = t.get("unit").and_then(Value::as_str).is_some_and(|u| u.starts_with("inch"));
    let scale = if inch { 25.4 } else { 1.0 };
    let g = |k: &str| t.get("geometry").and_then(|g| g.get(k)).and_then(Value::as_f64);
    let mut presets = Vec::new();
    if let Some(sv) = t.get("start-values") {
        if let Some(star) = sv.get("*") {
            presets.push(("*".to_owned(), numbers(star)));
        }
        for p in sv.get("presets").and_then(Value::as_array).into_iter().flatten() {
            presets.push((p.get("name").and_then(Value::as_str).unwrap_or("").to_owned(), numbers(p)));
        }
    }
    LibraryTool {
        number: t.get("post-process").and_then(|p| p.get("number")).and_then(Value::as_u64).map(|n| n as u32),
        description: t.get("description").and_then(Value::as_str).unwrap_or("").to_owned(),
        kind: t.get("type").and_then(Value::as_str).unwrap_or("").to_owned(),
        inch,
        diameter: g("DC").map(|d| d * scale),
        flutes: g("NOF").map(|z| z as u32),
        corner_radius: g("RE").map(|r| r * scale),
        presets,
        raw: t.clone(),
    }
}

/// The numeric values of a preset (strings that read as numbers too, as some writers put them).
fn numbers(p: &Value) -> BTreeMap<String, f64> {
    let mut out = BTreeMap::new();
    for (k, v) in p.as_object().into_iter().flatten() {
        let n = v.as_f64().or_else(|| v.as_str().and_then(|s| s.trim().parse().ok()));
        if let Some(n) = n {
            out.insert(k.clone(), n);
        }
    }
    out
}

impl LibraryTool {
    /// Whether this is the tool a suggestion's key names: the same number, and the same
    /// diameter where both know it.
    pub fn is(&self, key: &ToolKey) -> bool {
        self.number == Some(key.number)
            && match (self.diameter, key.diameter) {
                (Some(a), Some(b)) => (a - b).abs() <= 0.01,
                _ => true,
            }
    }

    /// The tool as a suggestion names it: its number with the library's geometry.
    pub fn key(&self) -> ToolKey {
        ToolKey {
            number: self.number.unwrap_or(0),
            description: self.description.clone(),
            diameter: self.diameter,
            flutes: self.flutes,
            corner_radius: self.corner_radius,
        }
    }
}

/// A guid derived from `seed` (SHA-256, laid out as a UUID).
pub fn guid(seed: &str) -> String {
    let h = Sha256::digest(seed.as_bytes());
    let x: String = h.iter().take(16).map(|b| format!("{b:02x}")).collect();
    format!("{}-{}-{}-{}-{}", &x[0..8], &x[8..12], &x[12..16], &x[16..20], &x[20..32])
}

/// The Fusion library of the accepted tool suggestions in `accepted`: each affected tool
/// copied from `library` (or, where the shop's library lacks it, made from what the programs
/// say of it) with one preset added per suggestion. Operation notes are left out (they are
/// no tool's data).
pub fn export(library: Option<&Library>, accepted: &[&Suggestion]) -> Value {
    let mut by_tool: Vec<(ToolKey, Vec<&Suggestion>)> = Vec::new();
    for s in accepted.iter().filter(|s| s.key.parameter.of_tool()) {
        match by_tool.iter_mut().find(|(k, _)| *k == s.key.tool) {
            Some((_, v)) => v.push(s),
            None => by_tool.push((s.key.tool.clone(), vec![s])),
        }
    }
    let mut data = Vec::new();
    for (key, suggestions) in &by_tool {
        // Only a Fusion library's tool is copied; one another list names is made from its key.
        let found = library.and_then(|l| l.tools.iter().find(|t| t.is(key))).filter(|t| t.raw.is_object());
        let mut t = found.map_or_else(|| made(key, suggestions[0].key.class), |f| f.raw.clone());
        let old = t.get("guid").and_then(Value::as_str).unwrap_or("").to_owned();
        let ids: Vec<&str> = suggestions.iter().map(|s| s.id.as_str()).collect();
        t["guid"] = json!(guid(&format!("{old}|{}", ids.join(","))));
        let inch = found.is_some_and(|f| f.inch);
        let base = base_preset(&t);
        let sv = t.as_object_mut().expect("a tool is an object").entry("start-values").or_insert_with(|| json!({}));
        if !sv.is_object() {
            *sv = json!({});
        }
        let list = sv.as_object_mut().expect("an object").entry("presets").or_insert_with(|| json!([]));
        if let Some(list) = list.as_array_mut() {
            for s in suggestions {
                list.push(preset(&base, s, key, inch));
            }
        }
        data.push(t);
    }
    let version = library.map(|l| l.version.clone()).filter(|v| !v.is_null()).unwrap_or(json!(15));
    json!({ "data": data, "version": version })
}

/// A tool made from what the programs say of it (the shop's library lacks it).
fn made(key: &ToolKey, class: OpClass) -> Value {
    let kind = match (class, key.corner_radius) {
        (OpClass::Holemaking, _) => "drill",
        (_, Some(r)) if r > 0.0 => "bull nose end mill",
        _ => "flat end mill",
    };
    let mut geometry = Map::new();
    if let Some(d) = key.diameter {
        geometry.insert("DC".into(), json!(d));
    }
    if let Some(z) = key.flutes {
        geometry.insert("NOF".into(), json!(z));
    }
    if let Some(r) = key.corner_radius {
        geometry.insert("RE".into(), json!(r));
    }
    let description = if key.description.is_empty() { format!("T{}", key.number) } else { key.description.clone() };
    json!({
        "guid": "",
        "type": kind,
        "description": description,
        "unit": "millimeters",
        "geometry": geometry,
        "post-process": { "number": key.number, "length-offset": key.number, "diameter-offset": key.number,
                          "comment": "made by ncplan: no Fusion library of the shop holds it" },
        "start-values": { "presets": [] },
    })
}

/// The preset a new one starts from: the tool's first preset, else its older `*` set, else none.
fn base_preset(t: &Value) -> Map<String, Value> {
    let sv = t.get("start-values");
    let first = sv.and_then(|s| s.get("presets")).and_then(Value::as_array).and_then(|l| l.first());
    let star = sv.and_then(|s| s.get("*"));
    first.or(star).and_then(Value::as_object).cloned().unwrap_or_default()
}

/// The preset of one suggestion.
fn preset(base: &Map<String, Value>, s: &Suggestion, key: &ToolKey, inch: bool) -> Value {
    let mut p = base.clone();
    p.remove("expressions");
    p.insert("guid".into(), json!(guid(&format!("preset|{}", s.id))));
    let name = format!("ncplan {} {} {} {}", s.key.parameter.label(), s.key.material, s.key.machine, s.key.class.name());
    p.insert("name".into(), json!(name));
    p.insert("description".into(), json!(render::evidence_line(s)));
    p.insert("material".into(), json!({ "category": "all", "query": s.key.material, "use-hardness": false }));
    let (len, feed, speed) = if inch { (1.0 / 25.4, 1.0 / 25.4, 1.0 / 0.3048) } else { (1.0, 1.0, 1.0) };
    let get = |p: &Map<String, Value>, k: &str| p.get(k).and_then(|v| v.as_f64().or_else(|| v.as_str()?.trim().parse().ok()));
    let d = key.diameter.unwrap_or(0.0);
    let v = s.suggested;
    let round = |x: f64| (x * 1e6).round() / 1e6;
    match s.key.parameter {
        Parameter::CuttingFeed => {
            p.insert("v_f".into(), json!(round(v * feed)));
            let (n, z) = (get(&p, "n").unwrap_or(0.0), key.flutes.unwrap_or(0));
            if n > 0.0 && z > 0 {
                p.insert("f_z".into(), json!(round(v * feed / (n * f64::from(z)))));
            }
        }
        Parameter::PlungeFeed => {
            p.insert("v_f_plunge".into(), json!(round(v * feed)));
        }
        Parameter::RampFeed => {
            p.insert("v_f_ramp".into(), json!(round(v * feed)));
        }
        Parameter::SpindleSpeed => {
            p.insert("n".into(), json!(round(v)));
            if d > 0.0 {
                p.insert("v_c".into(), json!(round(std::f64::consts::PI * d * v / 1000.0 * speed)));
            }
            let (vf, z) = (get(&p, "v_f").unwrap_or(0.0), key.flutes.unwrap_or(0));
            if vf > 0.0 && z > 0 {
                p.insert("f_z".into(), json!(round(vf / (v * f64::from(z)))));
            }
        }
        Parameter::CuttingSpeed => {
            p.insert("v_c".into(), json!(round(v * speed)));
            if d > 0.0 {
                p.insert("n".into(), json!(round(v * 1000.0 / (std::f64::consts::PI * d))));
            }
        }
        Parameter::Stepdown => {
            p.insert("stepdown".into(), json!(round(v * len)));
            p.insert("use-stepdown".into(), json!(true));
        }
        Parameter::Stepover => {
            p.insert("stepover".into(), json!(round(v * len)));
            p.insert("use-stepover".into(), json!(true));
        }
        Parameter::PeckDepth | Parameter::ClearanceHeight => {}
    }
    Value::Object(p)
}

/// The value a preset gives for a suggestion's parameter, metric (for reading an export back).
pub fn preset_value(tool: &LibraryTool, preset: &BTreeMap<String, f64>, parameter: Parameter) -> Option<f64> {
    let (len, speed) = if tool.inch { (25.4, 0.3048) } else { (1.0, 1.0) };
    Some(match parameter {
        Parameter::CuttingFeed => preset.get("v_f")? * len,
        Parameter::PlungeFeed => preset.get("v_f_plunge")? * len,
        Parameter::RampFeed => preset.get("v_f_ramp")? * len,
        Parameter::SpindleSpeed => *preset.get("n")?,
        Parameter::CuttingSpeed => preset.get("v_c")? * speed,
        Parameter::Stepdown => preset.get("stepdown")? * len,
        Parameter::Stepover => preset.get("stepover")? * len,
        Parameter::PeckDepth | Parameter::ClearanceHeight => return None,
    })
}

/// A short account of a library tool (the CLI's and the pages' naming of a CAM tool).
pub fn tool_line(t: &LibraryTool) -> String {
    let mut s = format!("T{} {}", t.number.map(|n| n.to_string()).unwrap_or_else(|| "?".into()), t.description);
    if let Some(d) = t.diameter {
        s.push_str(&format!(" Ø{}", num(d)));
    }
    s
}

//! Configuration: `config/ncplan.toml` → validated [`Config`].
//!
//! Parsing is strict (`deny_unknown_fields`); validation resolves relative paths against the
//! base it is given (the commands give the working directory, for a file as for the built-in
//! configuration) and checks that the database never sits inside a watched folder;
//! `check_watchable` that every watched folder exists.
//!
//! TOML → `Config` (strict), ignore globs, the dialect registry from a folder,
//! and `DirPrograms`: called programs from the configured directory or, without one, from the
//! program's own folder (`beside`), by file name (`program_file_stems`: `TNC:\PARTS\Plan.h`
//! is `Plan.h`, `O0100` also `100`).

use std::path::{Path, PathBuf};

use anyhow::{Context, Result, bail};
use serde::Deserialize;

use crate::interp::{Profile, ToolData};

/// A folder's `role`: whether its files are main programs or called ones.
fn program_role(role: Option<&str>, folder: &str) -> Result<crate::interp::ProgramRole> {
    use crate::interp::ProgramRole;
    Ok(match role {
        None | Some("auto") => ProgramRole::Auto,
        Some("main") => ProgramRole::Main,
        Some("called") => ProgramRole::Called,
        Some(other) => bail!("`{folder}`: role must be main, called or auto, not `{other}`"),
    })
}

/// Reads a tool table file (LinuxCNC `tool.tbl`, Heidenhain `TOOL.T`, Fanuc `G10` offsets;
/// see [`crate::plan::tooltable`]), in millimetres.
pub fn read_tool_table(path: &Path) -> Result<crate::plan::tooltable::Tools> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read the tool table {}", path.display()))?;
    let (text, _) = crate::text::decode(&bytes);
    let (_, tools) = crate::plan::tooltable::read(&text.text, false)
        .map_err(|e| anyhow::anyhow!("{e}"))
        .with_context(|| format!("in the tool table {}", path.display()))?;
    Ok(tools)
}

/// `[[tool]]` entries (of the configuration, or of one `[[machine]]`, named by `whose`).
fn configured_tools(raw: &[RawTool], whose: &str) -> Result<crate::plan::tooltable::Tools> {
    let mut tools = crate::plan::tooltable::Tools::new();
    for t in raw {
        if let Some(k) = &t.kind
            && crate::plan::ToolKind::parse(k).is_none()
        {
            let kinds: Vec<&str> = crate::plan::ToolKind::ALL.iter().map(|k| k.as_str()).collect();
            bail!("{whose}[[tool]] {}: kind {k:?} is not one of {}", t.number, kinds.join(", "));
        }
        tools.insert(
            t.number,
            ToolData {
                diameter: t.diameter,
                length: t.length.unwrap_or(0.0),
                name: t.name.clone(),
                kind: t.kind.clone(),
                corner_radius: t.corner_radius,
                flutes: t.flutes,
                point_angle: t.point_angle,
            },
        );
    }
    Ok(tools)
}

/// A folder's own tools: its table, then its `[[tool]]` entries over it.
fn folder_tools(table: Option<&Path>, raw: &[RawTool], name: &str) -> Result<crate::plan::tooltable::Tools> {
    let mut tools = match table {
        Some(p) => read_tool_table(p)?,
        None => Default::default(),
    };
    tools.extend(configured_tools(raw, &format!("machine `{name}`: "))?);
    Ok(tools)
}

/// The least settle window: below it, a file being copied looks settled between writes.
pub const MIN_SETTLE_MS: u64 = 50;
/// The least interval between full rescans.
pub const MIN_RESCAN_S: u64 = 5;
/// How long a worker may take over one file before it is reported, the file quarantined and
/// the worker replaced: ten minutes, five times the longest a child trial of a suspect content
/// may take, and well beyond what the largest file the default size limit (256 MB) takes to
/// analyse.
pub const DEFAULT_WORKER_TIMEOUT_S: u64 = 600;

/// The configuration the binary falls back on: the demo folders of this repository.
pub const DEMO: &str = include_str!("../config/ncplan.toml");

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawConfig {
    /// The site this server's programs and machines belong to (a hall, a plant), so that
    /// many servers share one PostgreSQL database.
    site: Option<String>,
    database: RawDatabase,
    #[serde(default)]
    daemon: RawDaemon,
    #[serde(default)]
    matching: RawMatching,
    dialects_dir: Option<String>,
    /// Directory of subprograms and macros that programs call (`M98 P1000`, `o<probe> call`).
    programs_dir: Option<String>,
    #[serde(default)]
    cam: Vec<RawFolder>,
    #[serde(default)]
    machine: Vec<RawMachine>,
    #[serde(default)]
    tool: Vec<RawTool>,
    tool_table: Option<String>,
    #[serde(default)]
    reference: RawReference,
    stock: Option<RawStock>,
    #[serde(default)]
    analysis: RawAnalysis,
    #[serde(default)]
    web: RawWeb,
    #[serde(default)]
    suggest: RawSuggest,
}

/// `[suggest]`: knowledge back to CAM. Every threshold of `suggest::Rules` (its doc comments
/// give each default and why), where the exports go, the shop's own tool library, and the
/// material of the programs under a folder.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawSuggest {
    outbox: Option<String>,
    tool_library: Option<OneOrMany>,
    #[serde(default)]
    unreviewed: bool,
    #[serde(default)]
    material: Vec<RawMaterial>,
    #[serde(default)]
    operator: Vec<RawOperator>,
    min_edits: Option<usize>,
    min_programs: Option<usize>,
    min_days: Option<usize>,
    min_span_days: Option<i64>,
    min_operators: Option<usize>,
    min_agreement: Option<f64>,
    alpha: Option<f64>,
    min_effect: Option<f64>,
    min_offset_mm: Option<f64>,
    mad_cutoff: Option<f64>,
    mad_floor: Option<f64>,
    reversal_window: Option<usize>,
    prior_edits: Option<f64>,
    confidence: Option<f64>,
    reopen_edits: Option<usize>,
    adopt_tolerance: Option<f64>,
    snooze_days: Option<i64>,
    rejected_growth: Option<usize>,
}

/// `[[suggest.material]]`: the material of the CAM programs under `folder`.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMaterial {
    folder: String,
    material: String,
}

/// `[[suggest.operator]]`: who edits the programs saved under `folder` (a machine's share, or
/// an operator's own folder on it), where no header comment names the operator.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawOperator {
    folder: String,
    operator: String,
}

/// One path or a list of them.
#[derive(Debug, Deserialize)]
#[serde(untagged)]
enum OneOrMany {
    One(String),
    Many(Vec<String>),
}

impl OneOrMany {
    fn list(&self) -> Vec<&str> {
        match self {
            OneOrMany::One(s) => vec![s.as_str()],
            OneOrMany::Many(v) => v.iter().map(String::as_str).collect(),
        }
    }
}

/// `[suggest]`, validated.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct SuggestSettings {
    /// Where `export-suggestions` writes without a folder given.
    pub outbox: Option<PathBuf>,
    /// The shop's own tool lists, read to name the CAM tool, the first that has a number
    /// naming it: Fusion / Inventor CAM / HSM libraries (JSON, their tools copied into the
    /// export), FreeCAD tool libraries (`.fctl`, with their bits) and bits (`.fctb`), and tool
    /// tables (LinuxCNC `tool.tbl`, Heidenhain `TOOL.T`, Fanuc `G10`, Siemens `$TC_DP`); never written.
    pub tool_libraries: Vec<PathBuf>,
    /// Whether unreviewed changes count too (by default only those a planner adopted).
    pub unreviewed: bool,
    /// The material of the programs under a folder: (folder, material), longest folder first.
    pub materials: Vec<(PathBuf, String)>,
    /// Who edits the programs saved under a folder: (folder, operator), longest folder first.
    pub operators: Vec<(PathBuf, String)>,
    /// The rules' thresholds.
    pub rules: crate::suggest::Rules,
}

/// `[suggest]` validated: paths resolved, thresholds in their ranges.
fn suggest_settings(raw: &RawSuggest, base: &Path, folders: &[Folder]) -> Result<SuggestSettings> {
    let d = crate::suggest::Rules::default();
    let rules = crate::suggest::Rules {
        min_edits: raw.min_edits.unwrap_or(d.min_edits),
        min_programs: raw.min_programs.unwrap_or(d.min_programs),
        min_days: raw.min_days.unwrap_or(d.min_days),
        min_span_days: raw.min_span_days.unwrap_or(d.min_span_days),
        min_operators: raw.min_operators.unwrap_or(d.min_operators),
        min_agreement: raw.min_agreement.unwrap_or(d.min_agreement),
        alpha: raw.alpha.unwrap_or(d.alpha),
        min_effect: raw.min_effect.unwrap_or(d.min_effect),
        min_offset_mm: raw.min_offset_mm.unwrap_or(d.min_offset_mm),
        mad_cutoff: raw.mad_cutoff.unwrap_or(d.mad_cutoff),
        mad_floor: raw.mad_floor.unwrap_or(d.mad_floor),
        reversal_window: raw.reversal_window.unwrap_or(d.reversal_window),
        prior_edits: raw.prior_edits.unwrap_or(d.prior_edits),
        confidence: raw.confidence.unwrap_or(d.confidence),
        reopen_edits: raw.reopen_edits.unwrap_or(d.reopen_edits),
        adopt_tolerance: raw.adopt_tolerance.unwrap_or(d.adopt_tolerance),
        snooze_days: raw.snooze_days.unwrap_or(d.snooze_days),
        rejected_growth: raw.rejected_growth.unwrap_or(d.rejected_growth),
    };
    for (name, v) in [("min_agreement", rules.min_agreement), ("alpha", rules.alpha), ("confidence", rules.confidence)] {
        if !(v > 0.0 && v <= 1.0) {
            bail!("[suggest] {name} = {v} is not a share between 0 and 1");
        }
    }
    for (name, v) in [
        ("min_effect", rules.min_effect),
        ("min_offset_mm", rules.min_offset_mm),
        ("mad_cutoff", rules.mad_cutoff),
        ("prior_edits", rules.prior_edits),
        ("adopt_tolerance", rules.adopt_tolerance),
        ("mad_floor", rules.mad_floor),
    ] {
        if !(v >= 0.0 && v.is_finite()) {
            bail!("[suggest] {name} = {v} must be 0 or more");
        }
    }
    let outbox = raw.outbox.as_deref().map(|o| resolve(base, o));
    if let Some(o) = &outbox
        && let Some(f) = folders.iter().find(|f| o.starts_with(&f.path) || f.path.starts_with(o))
    {
        bail!("[suggest] outbox {} meets the watched folder {}; ncplan never writes into a watched folder", o.display(), f.path.display());
    }
    let mut materials: Vec<(PathBuf, String)> =
        raw.material.iter().map(|m| (resolve(base, &m.folder), m.material.trim().to_owned())).collect();
    materials.sort_by(|a, b| b.0.as_os_str().len().cmp(&a.0.as_os_str().len()).then(a.0.cmp(&b.0)));
    let mut operators: Vec<(PathBuf, String)> =
        raw.operator.iter().map(|m| (resolve(base, &m.folder), m.operator.trim().to_owned())).collect();
    operators.sort_by(|a, b| b.0.as_os_str().len().cmp(&a.0.as_os_str().len()).then(a.0.cmp(&b.0)));
    let tool_libraries = raw.tool_library.as_ref().map(|l| l.list().iter().map(|t| resolve(base, t)).collect()).unwrap_or_default();
    Ok(SuggestSettings { outbox, tool_libraries, unreviewed: raw.unreviewed, materials, operators, rules })
}

/// `ncplan serve`: where it listens and who may sign in.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawWeb {
    listen: Option<String>,
    #[serde(default)]
    user: Vec<RawUser>,
    #[serde(default)]
    hosts: Vec<String>,
    #[serde(default)]
    secure_cookies: bool,
    #[serde(default)]
    trusted_proxies: Vec<std::net::IpAddr>,
    login_per_minute: Option<u32>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawUser {
    name: String,
    /// An argon2 PHC string (`$argon2id$v=19$...`).
    password_hash: String,
}

/// A user of `ncplan serve`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WebUser {
    /// Sign-in name; review marks carry it.
    pub name: String,
    /// The argon2 PHC string of the password.
    pub password_hash: String,
}

/// Limits and choices of the analysis.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawAnalysis {
    /// The analysis bound in time: seconds of analysis for the blocks a run executes again
    /// (loop passes, jumps back, repeated calls) before it stops with a warning.
    max_seconds: Option<u64>,
    /// The analysis bound in memory: megabytes of the moves those blocks make.
    max_memory_mb: Option<u64>,
    /// The time bound as a count of blocks run again, over `max_seconds`.
    max_repeated_blocks: Option<u64>,
    /// How a condition on a value from outside the file goes when neither way leads to an
    /// alarm: `true` or `false`; without it, the dialect's choice.
    unknown_conditions: Option<bool>,
}

/// G28/G30 reference positions in machine coordinates (mm and degrees): X Y Z A B C.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawReference {
    g28: Option<Vec<f64>>,
    g30: Option<Vec<f64>>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawDatabase {
    /// A SQLite file.
    path: Option<String>,
    /// A PostgreSQL URL (`postgresql://user@host/db?sslmode=require`), instead of `path`.
    url: Option<String>,
    /// A file with the PostgreSQL password, readable by the service user alone.
    password_file: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields, default)]
struct RawDaemon {
    settle_ms: u64,
    rescan_s: u64,
    max_file_mb: u64,
    workers: usize,
    worker_timeout_s: u64,
    ignore: Vec<String>,
}

impl Default for RawDaemon {
    fn default() -> RawDaemon {
        RawDaemon {
            settle_ms: 1000,
            rescan_s: 300,
            max_file_mb: 256,
            workers: 4,
            worker_timeout_s: DEFAULT_WORKER_TIMEOUT_S,
            ignore: [".*", "~*", "*~", "*.tmp", "*.temp", "*.swp", "*.bak", "*.part", "#*#"].map(String::from).to_vec(),
        }
    }
}

#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMatching {
    pattern: Option<String>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawFolder {
    path: String,
    dialect: String,
    /// Whether the folder holds main programs, called ones (subprograms, macros, cycles), or
    /// each file says (`auto`, the default).
    role: Option<String>,
    /// A tool table file for this folder's programs.
    tool_table: Option<String>,
    #[serde(default)]
    poll: bool,
    poll_ms: Option<u64>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawMachine {
    name: String,
    path: String,
    dialect: String,
    /// Overrides the dialect's decimal-point rule for this machine: `calculator` (X10 is 10
    /// units) or `least-increment` (X10 is 10 µm on a metric control).
    decimal_input: Option<String>,
    /// How the machine reads X words, as its control is set: `diameter` (a lathe's diameter
    /// programming from reset) or `radius`; a program's own evidence then does not change it.
    x_words: Option<String>,
    /// The two rotary axes the machine swivels with, in its swivel data's order (`BC`, `AC`):
    /// `CYCLE800` in "rotary axes direct" mode gives their positions.
    swivel_axes: Option<String>,
    /// How the machine changes its tool, as its control is set: `t` (the T word changes it,
    /// a turret) or `m6` (T selects, M6 changes); a program's own evidence then does not
    /// change it.
    tool_change: Option<String>,
    /// As for CAM folders: `main`, `called` or `auto`.
    role: Option<String>,
    #[serde(default)]
    poll: bool,
    poll_ms: Option<u64>,
    /// The machine's units (`mm` or `inch`): `translate --machine` writes in them.
    units: Option<String>,
    /// Highest spindle speed, 1/min.
    max_spindle_speed: Option<f64>,
    /// Highest feed, mm/min.
    max_feed: Option<f64>,
    /// Travel: the lowest X, Y, Z the tool may reach (program coordinates, mm).
    travel_min: Option<[f64; 3]>,
    /// Travel: the highest X, Y, Z.
    travel_max: Option<[f64; 3]>,
    /// The machine's own tool table file (LinuxCNC, Heidenhain TOOL.T, Fanuc G10 offsets).
    tool_table: Option<String>,
    /// The machine's own tools, over its table.
    #[serde(default)]
    tool: Vec<RawTool>,
}

/// What a machine can do, for `translate --machine`: its units and limits.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct MachineLimits {
    /// Its units, where configured.
    pub units: Option<crate::canon::Units>,
    /// Highest spindle speed, 1/min.
    pub max_spindle_speed: Option<f64>,
    /// Highest feed, mm/min.
    pub max_feed: Option<f64>,
    /// Travel in mm: lowest and highest X, Y, Z.
    pub travel: Option<([f64; 3], [f64; 3])>,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawTool {
    number: u32,
    diameter: Option<f64>,
    length: Option<f64>,
    name: Option<String>,
    kind: Option<String>,
    corner_radius: Option<f64>,
    flutes: Option<u32>,
    /// A drill's included point angle, degrees.
    point_angle: Option<f64>,
}

/// The raw stock: two corners in program coordinates, mm.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct RawStock {
    min: [f64; 3],
    max: [f64; 3],
}

/// Whether a folder holds CAM originals or a machine's programs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// CAM release folder.
    Cam,
    /// Controller share.
    Machine,
}

impl Role {
    /// Name stored in the database.
    pub fn as_str(self) -> &'static str {
        match self {
            Role::Cam => "cam",
            Role::Machine => "machine",
        }
    }
}

/// A watched folder.
#[derive(Clone, Debug)]
pub struct Folder {
    /// Role.
    pub role: Role,
    /// Machine name (machine folders) or `CAM`.
    pub name: String,
    /// Absolute or config-relative path.
    pub path: PathBuf,
    /// Dialect name.
    pub dialect: String,
    /// Poll instead of native events (network shares).
    pub poll: bool,
    /// Poll interval.
    pub poll_ms: u64,
    /// The machine's decimal-point rule, when it differs from its dialect's.
    pub decimal_input: Option<DecimalRule>,
    /// Whether the machine reads X words as diameters (`Some(true)`) or radii, where its
    /// configuration says (`x_words`).
    pub x_diameter: Option<bool>,
    /// The machine's two swivel axes, where its configuration names them (`swivel_axes`).
    pub swivel_axes: Option<[u8; 2]>,
    /// Whether the T word changes the tool (`Some(true)`) or M6 does, where the machine's
    /// configuration says (`tool_change`).
    pub tool_word_changes: Option<bool>,
    /// Whether the folder's files are main programs, called ones, or tell it themselves.
    pub program_role: crate::interp::ProgramRole,
    /// The machine's units and limits (machines only).
    pub limits: MachineLimits,
    /// This folder's own tools (`tool_table`, `[[machine.tool]]`), over the configuration's.
    pub tools: crate::plan::tooltable::Tools,
}

/// The folder dialect that means "tell each program's dialect from its text".
pub const AUTO_DIALECT: &str = "auto";

/// A per-machine decimal-point rule (a control parameter, such as Fanuc 3401#0).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DecimalRule {
    /// `X10` is 10 units.
    Calculator,
    /// `X10` is 10 least increments (0.001 mm, 0.0001 in).
    LeastIncrement,
}

impl Folder {
    /// The dialect this folder's programs are read in, with the folder's overrides applied.
    pub fn dialect_for(&self, base: std::sync::Arc<crate::dialect::Dialect>) -> std::sync::Arc<crate::dialect::Dialect> {
        use crate::dialect::{DecimalInput, Role as R};
        if self.x_diameter.is_none() && self.swivel_axes.is_none() && self.tool_word_changes.is_none() && self.decimal_input.is_none() {
            return base;
        }
        // One copy of the dictionary carries every override the machine states.
        let mut d = (*base).clone();
        if let Some(on) = self.x_diameter {
            d.behaviour.x_diameter = on;
            d.behaviour.x_words_stated = true;
        }
        if let Some(axes) = self.swivel_axes {
            d.behaviour.swivel_axes = Some(axes);
        }
        if let Some(on) = self.tool_word_changes {
            d.behaviour.tool_word_changes = on;
            d.behaviour.tool_change_stated = true;
        }
        let Some(rule) = self.decimal_input else { return std::sync::Arc::new(d) };
        d.behaviour.decimal_input_stated = true;
        d.behaviour.decimal_input = match (rule, &base.behaviour.decimal_input) {
            (DecimalRule::Calculator, _) => DecimalInput::Calculator,
            (DecimalRule::LeastIncrement, DecimalInput::LeastIncrement { mm, inch, scaled }) => {
                DecimalInput::LeastIncrement { mm: *mm, inch: *inch, scaled: scaled.clone() }
            }
            (DecimalRule::LeastIncrement, DecimalInput::Calculator) => DecimalInput::LeastIncrement {
                mm: 0.001,
                inch: 0.0001,
                scaled: vec![R::X, R::Y, R::Z, R::A, R::B, R::C, R::U, R::V, R::W, R::I, R::J, R::K, R::R, R::Q],
            },
        };
        std::sync::Arc::new(d)
    }
}

/// The validated configuration.
#[derive(Clone, Debug)]
pub struct Config {
    /// The database: a SQLite file or a PostgreSQL server.
    pub database: crate::store::Location,
    /// The site (`site = "HALL2"`) its programs and machines are stored under.
    pub site: String,
    /// Extra dialect files (`*.xml`), loaded at start.
    pub dialects_dir: Option<PathBuf>,
    /// Watched folders, CAM first.
    pub folders: Vec<Folder>,
    /// A file counts as complete when size and mtime held still this long.
    pub settle_ms: u64,
    /// Full rescan interval.
    pub rescan_s: u64,
    /// Largest file analysed, bytes.
    pub max_file_bytes: u64,
    /// Most files analysed at once (each worker also takes a core).
    pub workers: usize,
    /// The longest a worker may take over one file (`[daemon] worker_timeout_s`).
    pub worker_timeout_s: u64,
    /// The ncplan executable that reads a suspect content in a process of its own (one whose
    /// analyses were cut short before); `None`: this process's own. Not read from the file.
    pub probe_exe: Option<PathBuf>,
    /// Ignore globs matched against file names.
    pub ignore: Vec<String>,
    /// Optional regex with a `key` group that extracts the matching key from a file name.
    pub pattern: Option<regex::Regex>,
    /// Machine profile (tool table).
    pub profile: Profile,
    /// `[web] listen`: the address `ncplan serve` listens on without `--listen`.
    pub web_listen: Option<String>,
    /// `[[web.user]]`: who may sign in to `ncplan serve`; none means no authentication.
    pub web_users: Vec<WebUser>,
    /// The rest of `[web]`: host names, cookies over TLS, proxies, sign-in rate.
    pub web: WebSettings,
    /// `[suggest]`: knowledge back to CAM.
    pub suggest: SuggestSettings,
}

/// `ncplan serve`'s settings beyond its address and users.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct WebSettings {
    /// `[web] hosts`: the names (`name` or `name:port`) a request's `Host` may give besides
    /// the address the server listens on (and `localhost` on loopback): the name a reverse
    /// proxy forwards, or the server's DNS name. Any other `Host` is refused (DNS rebinding).
    pub hosts: Vec<String>,
    /// `[web] secure_cookies`: the session cookie is `Secure` (the workspace is reached over
    /// TLS, through a reverse proxy).
    pub secure_cookies: bool,
    /// `[web] trusted_proxies`: the reverse proxies whose `X-Forwarded-For` names the client
    /// (for the sign-in rate) and whose `X-Forwarded-Proto: https` makes cookies `Secure`.
    pub trusted_proxies: Vec<std::net::IpAddr>,
    /// `[web] login_per_minute`: sign-in attempts a client may make per minute (a burst of
    /// as many, then one every `60 / n` seconds); 10 by default.
    pub login_per_minute: u32,
}

impl Default for WebSettings {
    fn default() -> WebSettings {
        WebSettings { hosts: Vec::new(), secure_cookies: false, trusted_proxies: Vec::new(), login_per_minute: 10 }
    }
}

impl Config {
    /// Parses and validates `text`; relative paths are resolved against `base`. The first
    /// fault found is the error: folders, the database and site, the matching pattern, the
    /// analysis profile, the daemon's settings, in that order.
    pub fn parse(text: &str, base: &Path) -> Result<Config> {
        let raw: RawConfig = toml::from_str(text).context("invalid configuration")?;
        let mut folders = Vec::new();
        for f in &raw.cam {
            folders.push(cam_folder(f, base)?);
        }
        for m in &raw.machine {
            folders.push(machine_folder(m, &raw.machine, base)?);
        }
        let database = database(&raw, base)?;
        let site = raw.site.clone().unwrap_or_default();
        if site.trim() != site || site.chars().any(char::is_control) {
            bail!("site `{site}` has blanks at its ends or control characters");
        }
        for f in &folders {
            if database.file().is_some_and(|d| d.starts_with(&f.path)) {
                bail!(
                    "the database {} lies inside the watched folder {}; ncplan never writes into a watched folder",
                    database,
                    f.path.display()
                );
            }
        }
        let pattern = matching_pattern(&raw.matching)?;
        let profile = profile(&raw, base)?;
        check_daemon(&raw.daemon)?;
        if raw.web.login_per_minute == Some(0) {
            bail!("[web] login_per_minute is 0: no one could sign in; give at least 1 (10 by default)");
        }
        let suggest = suggest_settings(&raw.suggest, base, &folders)?;
        Ok(Config {
            suggest,
            database,
            site,
            dialects_dir: raw.dialects_dir.map(|d| resolve(base, &d)),
            folders,
            settle_ms: raw.daemon.settle_ms,
            rescan_s: raw.daemon.rescan_s,
            max_file_bytes: raw.daemon.max_file_mb.saturating_mul(1 << 20),
            workers: raw.daemon.workers,
            worker_timeout_s: raw.daemon.worker_timeout_s,
            probe_exe: None,
            ignore: raw.daemon.ignore,
            pattern,
            profile,
            web_listen: raw.web.listen,
            web_users: raw.web.user.into_iter().map(|u| WebUser { name: u.name, password_hash: u.password_hash }).collect(),
            web: WebSettings {
                hosts: raw.web.hosts,
                secure_cookies: raw.web.secure_cookies,
                trusted_proxies: raw.web.trusted_proxies,
                login_per_minute: raw.web.login_per_minute.unwrap_or(10),
            },
        })
    }

    /// The folder holding `path` (the longest matching prefix).
    pub fn folder_at(&self, path: &Path) -> Option<usize> {
        self.folders
            .iter()
            .enumerate()
            .filter(|(_, f)| path.starts_with(&f.path))
            .max_by_key(|(_, f)| f.path.as_os_str().len())
            .map(|(i, _)| i)
    }

    /// What `ncplan watch` needs beyond a valid file: folders to watch, each of which exists.
    /// A folder that exists but cannot be read (an unmounted share's mount point, a share
    /// down) is watched for it to come back; one that does not exist is a wrong path.
    pub fn check_watchable(&self) -> Result<()> {
        if self.folders.is_empty() {
            bail!("no folders to watch: add a [[cam]] folder and at least one [[machine]] share");
        }
        let missing: Vec<String> = self
            .folders
            .iter()
            .filter(|f| std::fs::symlink_metadata(&f.path).is_err_and(|e| e.kind() == std::io::ErrorKind::NotFound))
            .map(|f| format!("{} ({})", crate::sharefile::path_text(&f.path), f.name))
            .collect();
        if !missing.is_empty() {
            bail!("configured folders do not exist: {} (relative paths are resolved against the working directory)", missing.join(", "));
        }
        Ok(())
    }

    /// The program files of a folder, sorted, to depth 4: regular files and links to files
    /// (which the caller judges with [`Config::stays_inside`]); not editor or temporary files,
    /// nothing in hidden folders, never a link to a folder. An error when the folder itself
    /// cannot be listed.
    pub fn program_files(&self, folder: &Folder) -> std::io::Result<Vec<PathBuf>> {
        fn walk(config: &Config, dir: &Path, depth: u32, out: &mut Vec<PathBuf>) -> std::io::Result<()> {
            let mut found: Vec<(PathBuf, std::fs::FileType)> =
                std::fs::read_dir(dir)?.filter_map(|e| e.ok()).filter_map(|e| Some((e.path(), e.file_type().ok()?))).collect();
            found.sort_by(|a, b| a.0.cmp(&b.0));
            for (p, kind) in found {
                // A name that is not UTF-8 (Latin-1 from a Windows share) is a program too.
                if p.file_name().is_none_or(|n| config.ignored(&n.to_string_lossy())) {
                    continue;
                }
                if kind.is_dir() {
                    if depth < 4 {
                        let _ = walk(config, &p, depth + 1, out);
                    }
                } else if kind.is_file() || (kind.is_symlink() && !p.is_dir()) {
                    out.push(p);
                }
            }
            Ok(())
        }
        let mut out = Vec::new();
        walk(self, &folder.path, 0, &mut out)?;
        Ok(out)
    }

    /// Whether `path` (perhaps a link) leads to a file inside `folder`, links resolved.
    pub fn stays_inside(folder: &Folder, path: &Path) -> bool {
        let root = std::fs::canonicalize(&folder.path).unwrap_or_else(|_| folder.path.clone());
        std::fs::canonicalize(path).is_ok_and(|real| real.starts_with(root) && real.is_file())
    }

    /// Whether a file name matches an ignore glob (editor and temporary files).
    pub fn ignored(&self, name: &str) -> bool {
        self.ignore.iter().any(|g| glob_match(g.as_bytes(), name.as_bytes()))
    }
}

/// `p` as given where it is absolute, else below `base` (the working directory the command runs in).
fn resolve(base: &Path, p: &str) -> PathBuf {
    if Path::new(p).is_absolute() { PathBuf::from(p) } else { base.join(p) }
}

/// A `[[cam]]` folder.
fn cam_folder(f: &RawFolder, base: &Path) -> Result<Folder> {
    Ok(Folder {
        role: Role::Cam,
        name: "CAM".into(),
        path: resolve(base, &f.path),
        dialect: f.dialect.clone(),
        poll: f.poll,
        poll_ms: f.poll_ms.unwrap_or(2000),
        decimal_input: None,
        x_diameter: None,
        swivel_axes: None,
        tool_word_changes: None,
        program_role: program_role(f.role.as_deref(), &f.path)?,
        limits: MachineLimits::default(),
        tools: folder_tools(f.tool_table.as_deref().map(|t| resolve(base, t)).as_deref(), &[], &f.path)?,
    })
}

/// A `[[machine]]` share, named once among `machines`, with its decimal-point rule, units,
/// limits and tools.
fn machine_folder(m: &RawMachine, machines: &[RawMachine], base: &Path) -> Result<Folder> {
    if m.name.trim().is_empty() {
        bail!("a [[machine]] needs a name");
    }
    if machines.iter().filter(|x| x.name == m.name).count() > 1 {
        bail!("machine `{}` is configured twice", m.name);
    }
    let decimal_input = match m.decimal_input.as_deref() {
        None => None,
        Some("calculator") => Some(DecimalRule::Calculator),
        Some("least-increment") => Some(DecimalRule::LeastIncrement),
        Some(other) => bail!("machine `{}`: decimal_input must be calculator or least-increment, not `{other}`", m.name),
    };
    let x_diameter = match m.x_words.as_deref() {
        None => None,
        Some("diameter") => Some(true),
        Some("radius") => Some(false),
        Some(other) => bail!("machine `{}`: x_words must be diameter or radius, not `{other}`", m.name),
    };
    let swivel_axes = match m.swivel_axes.as_deref().map(str::as_bytes) {
        None => None,
        Some(&[a, b]) if a != b && b"ABC".contains(&a.to_ascii_uppercase()) && b"ABC".contains(&b.to_ascii_uppercase()) => {
            Some([a.to_ascii_uppercase(), b.to_ascii_uppercase()])
        }
        Some(_) => bail!("machine `{}`: swivel_axes must name two of the rotary axes A, B, C (`BC`, `AC`)", m.name),
    };
    let tool_word_changes = match m.tool_change.as_deref() {
        None => None,
        Some("t") => Some(true),
        Some("m6") => Some(false),
        Some(other) => bail!("machine `{}`: tool_change must be t or m6, not `{other}`", m.name),
    };
    let units = match m.units.as_deref() {
        None => None,
        Some("mm") => Some(crate::canon::Units::Mm),
        Some("inch") => Some(crate::canon::Units::Inch),
        Some(other) => bail!("machine `{}`: units must be mm or inch, not `{other}`", m.name),
    };
    let travel = match (m.travel_min, m.travel_max) {
        (Some(lo), Some(hi)) => Some((lo, hi)),
        (None, None) => None,
        _ => bail!("machine `{}`: give both travel_min and travel_max, or neither", m.name),
    };
    let limits = MachineLimits { units, max_spindle_speed: m.max_spindle_speed, max_feed: m.max_feed, travel };
    Ok(Folder {
        limits,
        role: Role::Machine,
        name: m.name.clone(),
        path: resolve(base, &m.path),
        dialect: m.dialect.clone(),
        poll: m.poll,
        poll_ms: m.poll_ms.unwrap_or(2000),
        decimal_input,
        x_diameter,
        swivel_axes,
        tool_word_changes,
        program_role: program_role(m.role.as_deref(), &m.name)?,
        tools: folder_tools(m.tool_table.as_deref().map(|t| resolve(base, t)).as_deref(), &m.tool, &m.name)?,
    })
}

/// `[database]`: a SQLite `path`, or a PostgreSQL `url` (which needs the server's site named).
fn database(raw: &RawConfig, base: &Path) -> Result<crate::store::Location> {
    Ok(match (&raw.database.path, &raw.database.url) {
        (Some(path), None) => {
            if raw.database.password_file.is_some() {
                bail!("[database] password_file goes with a PostgreSQL url, not a SQLite path");
            }
            crate::store::Location::Sqlite(resolve(base, path))
        }
        (None, Some(url)) if crate::store::location::is_url(url) => {
            if raw.site.is_none() {
                bail!("a PostgreSQL database is shared by many servers: name this one's site at the top (site = \"HALL2\")");
            }
            crate::store::Location::postgres(url, raw.database.password_file.as_deref().map(|p| resolve(base, p)))
        }
        (None, Some(_)) => bail!("[database] url must start with postgresql:// (a SQLite file is given as path)"),
        (Some(_), Some(_)) => bail!("[database] has both path and url: give one"),
        (None, None) => bail!("[database] needs a path (SQLite) or a url (PostgreSQL)"),
    })
}

/// `[matching] pattern`: a regex with a `key` group, or none.
fn matching_pattern(matching: &RawMatching) -> Result<Option<regex::Regex>> {
    Ok(match matching.pattern.as_deref().filter(|p| !p.is_empty()) {
        Some(p) => {
            let re = regex::Regex::new(p).with_context(|| format!("invalid matching pattern `{p}`"))?;
            if re.capture_names().all(|n| n != Some("key")) {
                bail!("the matching pattern `{p}` needs a named group `(?P<key>...)`");
            }
            Some(re)
        }
        None => None,
    })
}

/// The machine profile the analysis runs with: `[analysis]` limits, `[reference]`
/// positions, the called programs' folder, the tool table and `[[tool]]` entries, `[stock]`.
fn profile(raw: &RawConfig, base: &Path) -> Result<Profile> {
    let mut profile = Profile::default();
    let a = &raw.analysis;
    if a.max_seconds == Some(0) || a.max_memory_mb == Some(0) {
        bail!("[analysis] max_seconds and max_memory_mb must be at least 1");
    }
    if let Some(s) = a.max_seconds {
        profile.bound_time(s);
    }
    if let Some(mb) = a.max_memory_mb {
        profile.bound_memory(mb);
    }
    if let Some(n) = raw.analysis.max_repeated_blocks {
        if n == 0 {
            bail!("[analysis] max_repeated_blocks must be at least 1");
        }
        profile.max_repeated_blocks = n;
    }
    profile.unknown_conditions = raw.analysis.unknown_conditions;
    let position = |what: &str, v: &Option<Vec<f64>>| -> Result<[f64; 6]> {
        let Some(v) = v else { return Ok([0.0; 6]) };
        if v.is_empty() || v.len() > 6 || v.iter().any(|x| !x.is_finite()) {
            bail!("[reference] {what} must list 1 to 6 finite numbers (X Y Z A B C)");
        }
        let mut p = [0.0; 6];
        p[..v.len()].copy_from_slice(v);
        Ok(p)
    };
    profile.home1 = position("g28", &raw.reference.g28)?;
    profile.home2 = position("g30", &raw.reference.g30)?;
    if let Some(dir) = &raw.programs_dir {
        profile.programs = Some(std::sync::Arc::new(DirPrograms {
            dir: resolve(base, dir),
            max_bytes: raw.daemon.max_file_mb.saturating_mul(1 << 20),
            subfolders: false,
        }));
    }
    if let Some(table) = &raw.tool_table {
        profile.tools = read_tool_table(&resolve(base, table))?;
    }
    profile.tools.extend(configured_tools(&raw.tool, "")?);
    if let Some(st) = &raw.stock {
        if st.min.iter().zip(&st.max).any(|(a, b)| a >= b || !a.is_finite() || !b.is_finite()) {
            bail!("[stock] min must be below max on every axis");
        }
        profile.stock = Some([st.min, st.max]);
    }
    Ok(profile)
}

/// `[daemon]`: the settle window, rescan interval, workers and file size within bounds.
fn check_daemon(daemon: &RawDaemon) -> Result<()> {
    if daemon.settle_ms < MIN_SETTLE_MS {
        bail!("[daemon] settle_ms = {} is below the least that tells a settled file, {MIN_SETTLE_MS}", daemon.settle_ms);
    }
    if daemon.rescan_s < MIN_RESCAN_S {
        bail!("[daemon] rescan_s = {} is below the least, {MIN_RESCAN_S} (a rescan reads every file)", daemon.rescan_s);
    }
    if daemon.workers == 0 {
        bail!("[daemon] workers must be at least 1");
    }
    if daemon.worker_timeout_s == 0 {
        bail!("[daemon] worker_timeout_s must be at least 1");
    }
    if daemon.max_file_mb == 0 {
        bail!("[daemon] max_file_mb must be at least 1");
    }
    Ok(())
}

/// `*` and `?` glob matching on bytes.
pub fn glob_match(pat: &[u8], s: &[u8]) -> bool {
    let (mut p, mut i, mut star, mut mark) = (0, 0, None, 0);
    while i < s.len() {
        if p < pat.len() && (pat[p] == b'?' || pat[p].eq_ignore_ascii_case(&s[i])) {
            p += 1;
            i += 1;
        } else if p < pat.len() && pat[p] == b'*' {
            star = Some(p);
            mark = i;
            p += 1;
        } else if let Some(sp) = star {
            p = sp + 1;
            mark += 1;
            i = mark;
        } else {
            return false;
        }
    }
    pat[p..].iter().all(|&c| c == b'*')
}

/// The shipped dialects plus every `*.xml` in `dir` (which may replace shipped ones).
/// A broken dialect file is an error that names `file:line:col`.
pub fn dialect_registry(dir: Option<&Path>) -> Result<crate::dialect::Registry> {
    let mut registry = crate::dialect::Registry::shipped();
    let Some(dir) = dir else { return Ok(registry) };
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .with_context(|| format!("cannot read the dialects folder {}", dir.display()))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("xml")))
        .collect();
    files.sort();
    let mut texts = Vec::with_capacity(files.len());
    for f in files {
        let text = std::fs::read_to_string(&f).with_context(|| format!("cannot read {}", f.display()))?;
        texts.push((f.display().to_string(), text));
    }
    if let Err(errors) = registry.add_all(&texts) {
        bail!("invalid dialect file:\n{}", errors.join("\n"));
    }
    Ok(registry)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tool_tables_per_configuration_and_machine() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::write(dir.path().join("tool.tbl"), "T1 P1 D10 Z50 ;end mill\nT2 P2 D6.8 ;drill\n").unwrap();
        std::fs::write(dir.path().join("TOOL.T"), "BEGIN TOOL.T MM\nT  NAME   L   R   T-ANGLE\n2  DRILL  80  4.25  140\n[END]\n").unwrap();
        let text = "tool_table = 'tool.tbl'\n[database]\npath = 'db'\n\
                    [[machine]]\nname = 'TNC'\npath = 'tnc'\ndialect = 'heidenhain'\ntool_table = 'TOOL.T'\n\
                    [[machine.tool]]\nnumber = 3\ndiameter = 12.0\n";
        let c = Config::parse(text, dir.path()).unwrap();
        assert_eq!(c.profile.tools[&1].diameter, Some(10.0));
        assert_eq!(c.profile.tools[&2].diameter, Some(6.8));
        let tnc = &c.folders[0].tools;
        assert_eq!((tnc[&2].diameter, tnc[&2].point_angle), (Some(8.5), Some(140.0)));
        assert_eq!(tnc[&3].diameter, Some(12.0));
        let missing = Config::parse("tool_table = 'none.tbl'\n[database]\npath = 'db'\n", dir.path()).unwrap_err();
        assert!(format!("{missing:#}").contains("cannot read the tool table"), "{missing:#}");
    }

    #[test]
    fn a_machine_can_override_the_decimal_point_rule() {
        let text = "[database]\npath = 'db'\n[[machine]]\nname = 'M1'\npath = 'm1'\ndialect = 'fanuc'\ndecimal_input = 'calculator'\n\
                    [[machine]]\nname = 'M2'\npath = 'm2'\ndialect = 'linuxcnc'\ndecimal_input = 'least-increment'\n";
        let c = Config::parse(text, Path::new("/srv")).unwrap();
        let reg = crate::dialect::Registry::shipped();
        let m1 = c.folders[0].dialect_for(reg.get("fanuc").unwrap());
        assert_eq!(m1.behaviour.decimal_input, crate::dialect::DecimalInput::Calculator);
        let m2 = c.folders[1].dialect_for(reg.get("linuxcnc").unwrap());
        assert!(matches!(m2.behaviour.decimal_input, crate::dialect::DecimalInput::LeastIncrement { mm, .. } if mm == 0.001));
        let bad = text.replace("'calculator'", "'metric'");
        assert!(Config::parse(&bad, Path::new("/srv")).unwrap_err().to_string().contains("decimal_input"));
    }

    /// A machine's stated X reading (`x_words`) wins over what a program's words show: a
    /// Sinumerik lathe set to radius programming is not read with DIAMON from reset.
    #[test]
    fn a_machine_can_state_how_it_reads_x_words() {
        let text = "[database]\npath = 'db'\n[[machine]]\nname = 'L1'\npath = 'l1'\ndialect = 'siemens'\nx_words = 'radius'\n";
        let c = Config::parse(text, Path::new("/srv")).unwrap();
        let reg = crate::dialect::Registry::shipped();
        let l1 = c.folders[0].dialect_for(reg.get("siemens").unwrap());
        assert!(l1.behaviour.x_words_stated && !l1.behaviour.x_diameter);
        let program = "G18 G90\nT1 D1\nG96 S200 LIMS=3000 M4\nG0 X54 Z2\nG1 X50 Z0 F0.2\nZ-20\nM30\n";
        let a = crate::pipeline::analyze(program.as_bytes(), &l1, &crate::interp::Profile::default());
        assert!(a.diagnostics.iter().all(|d| d.code.as_str() != "interp::x-words-diameter"));
        let bad = text.replace("'radius'", "'chord'");
        assert!(Config::parse(&bad, Path::new("/srv")).unwrap_err().to_string().contains("x_words"));
    }

    /// A machine's stated tool change (`tool_change`) wins over what a program shows: a
    /// Sinumerik lathe set to change with M6 (MD22550 = 1) reads `T3 D1` as a selection only.
    #[test]
    fn a_machine_can_state_how_it_changes_tools() {
        let text = "[database]\npath = 'db'\n[[machine]]\nname = 'L1'\npath = 'l1'\ndialect = 'siemens'\ntool_change = 'm6'\n";
        let c = Config::parse(text, Path::new("/srv")).unwrap();
        let reg = crate::dialect::Registry::shipped();
        let l1 = c.folders[0].dialect_for(reg.get("siemens").unwrap());
        assert!(l1.behaviour.tool_change_stated && !l1.behaviour.tool_word_changes);
        let program = "G18 G90\nT3 D1\nG96 S200 LIMS=3000 M4\nG0 X54 Z2\nG1 X50 Z0 F0.2\nZ-20\nM30\n";
        let code = |a: &crate::pipeline::Analysis, c: &str| a.diagnostics.iter().any(|d| d.code.as_str() == c);
        let a = crate::pipeline::analyze(program.as_bytes(), &l1, &crate::interp::Profile::default());
        assert!(!code(&a, "interp::tool-word-changes") && code(&a, "plan::no-tool"));
        // Stated `t`: the T word changes the tool, with nothing to infer.
        let turret = c.folders[0].clone();
        let turret = Folder { tool_word_changes: Some(true), ..turret };
        let l2 = turret.dialect_for(reg.get("siemens").unwrap());
        let a = crate::pipeline::analyze(program.as_bytes(), &l2, &crate::interp::Profile::default());
        assert!(!code(&a, "interp::tool-word-changes") && !code(&a, "plan::no-tool"));
        assert!(a.plan.workingsteps.iter().all(|w| w.tool == 3), "{:?}", a.plan.workingsteps);
        let bad = text.replace("'m6'", "'m06x'");
        assert!(Config::parse(&bad, Path::new("/srv")).unwrap_err().to_string().contains("tool_change"));
    }

    /// A folder of dialect files extends shipped dialects and replaces them by name; the
    /// shipped ones are loaded only as they are needed.
    #[test]
    fn a_dialects_folder_extends_and_replaces_shipped_dialects() {
        let dir = tempfile::tempdir().unwrap();
        let ns = "xmlns=\"urn:ncplan:dialect:1\"";
        let files = [
            ("a.xml", format!("<dialect {ns} name=\"shop_vf2\" extends=\"shop_haas\"/>")),
            ("b.xml", format!("<dialect {ns} name=\"shop_haas\" extends=\"haas\"><behaviour decimal-input=\"calculator\"/></dialect>")),
            ("c.xml", format!("<dialect {ns} name=\"siemens\" extends=\"siemens\" title=\"Our Siemens\"/>")),
        ];
        for (name, text) in &files {
            std::fs::write(dir.path().join(name), text).unwrap();
        }
        let reg = dialect_registry(Some(dir.path())).unwrap();
        let shipped = dialect_registry(None).unwrap();
        let mut names: Vec<&str> = shipped.names().chain(["shop_haas", "shop_vf2"]).collect();
        names.sort_unstable();
        assert_eq!(reg.names().collect::<Vec<_>>(), names);
        let vf2 = reg.get("shop_vf2").unwrap();
        assert_eq!((vf2.family.as_str(), &vf2.behaviour.decimal_input), ("haas", &crate::dialect::DecimalInput::Calculator));
        assert_eq!(reg.get("siemens").unwrap().title, "Our Siemens");
        assert_ne!(shipped.get("siemens").unwrap().title, "Our Siemens");
        assert_eq!(format!("{:?}", reg.get("fanuc_lathe")), format!("{:?}", shipped.get("fanuc_lathe")));
        std::fs::write(dir.path().join("d.xml"), format!("<dialect {ns} name=\"x\" extends=\"nosuch\"/>")).unwrap();
        assert!(dialect_registry(Some(dir.path())).unwrap_err().to_string().contains("d.xml:1:"));
    }

    #[test]
    fn folders_say_whether_they_hold_called_programs_and_analysis_limits_are_set() {
        use crate::interp::ProgramRole;
        let text = "[database]\npath = 'db'\n[analysis]\nmax_repeated_blocks = 5000\nunknown_conditions = false\n\
                    [[cam]]\npath = 'cycles'\ndialect = 'siemens'\nrole = 'called'\n\
                    [[machine]]\nname = 'M1'\npath = 'm1'\ndialect = 'fanuc'\n";
        let c = Config::parse(text, Path::new("/srv")).unwrap();
        assert_eq!((c.folders[0].program_role, c.folders[1].program_role), (ProgramRole::Called, ProgramRole::Auto));
        assert_eq!((c.profile.max_repeated_blocks, c.profile.unknown_conditions), (5000, Some(false)));
        let bad = text.replace("role = 'called'", "role = 'sub'");
        assert!(Config::parse(&bad, Path::new("/srv")).unwrap_err().to_string().contains("role must be main, called or auto"));
    }

    #[test]
    fn reference_positions_come_from_config() {
        let c =
            Config::parse("[database]\npath = 'db'\n[reference]\ng28 = [0, 0, 100]\ng30 = [-500, -400, 100, 0, 0, 0]\n", Path::new("/srv"))
                .unwrap();
        assert_eq!(c.profile.home1, [0.0, 0.0, 100.0, 0.0, 0.0, 0.0]);
        assert_eq!(c.profile.home2[0], -500.0);
        assert!(Config::parse("[database]\npath = 'db'\n[reference]\ng28 = []\n", Path::new("/srv")).is_err());
    }

    #[test]
    fn production_example_is_valid() {
        let c = Config::parse(include_str!("../config/ncplan.production.toml"), Path::new("/")).unwrap();
        assert!(c.profile.programs.is_some());
        assert_eq!(c.profile.home2[0], -400.0);
        let t = &c.profile.tools[&7];
        assert_eq!((t.kind.as_deref(), t.corner_radius, t.flutes), (Some("bullnose_end_mill"), Some(0.5), Some(4)));
        let with_stock =
            Config::parse("[database]\npath = 'db'\n[stock]\nmin = [0, 0, -30]\nmax = [150, 100, 0]\n", Path::new("/srv")).unwrap();
        assert_eq!(with_stock.profile.stock, Some([[0.0, 0.0, -30.0], [150.0, 100.0, 0.0]]));
        assert!(Config::parse("[database]\npath = 'db'\n[stock]\nmin = [0, 0, 0]\nmax = [150, 100, 0]\n", Path::new("/srv")).is_err());
        assert!(Config::parse("[database]\npath = 'db'\n[[tool]]\nnumber = 1\nkind = 'spoon'\n", Path::new("/srv")).is_err());
    }

    #[test]
    fn suggest_takes_several_tool_lists_and_operators_by_folder() {
        let text = "[database]\npath = 'db'\n[suggest]\ntool_library = ['tools/shop.json', 'Tools/Library/Shop.fctl']\n\
                    [[suggest.operator]]\nfolder = 'dnc/m1'\noperator = 'JO'\n\
                    [[suggest.operator]]\nfolder = 'dnc/m1/anna'\noperator = ' ANNA '\n";
        let c = Config::parse(text, Path::new("/srv")).unwrap();
        let s = &c.suggest;
        assert_eq!(s.tool_libraries, [PathBuf::from("/srv/tools/shop.json"), PathBuf::from("/srv/Tools/Library/Shop.fctl")]);
        // The longest folder first, so that an operator's own folder wins over the machine's.
        assert_eq!(s.operators, [(PathBuf::from("/srv/dnc/m1/anna"), "ANNA".to_owned()), (PathBuf::from("/srv/dnc/m1"), "JO".to_owned())]);
        let one = Config::parse("[database]\npath = 'db'\n[suggest]\ntool_library = 'tool.tbl'\n", Path::new("/srv")).unwrap();
        assert_eq!(one.suggest.tool_libraries, [PathBuf::from("/srv/tool.tbl")]);
    }

    #[test]
    fn demo_config_is_valid() {
        let c = Config::parse(DEMO, Path::new("/srv/ncplan")).unwrap();
        assert!(c.folders.iter().any(|f| f.role == Role::Cam));
        assert!(c.folders.iter().any(|f| f.role == Role::Machine));
        assert!(c.database.file().unwrap().starts_with("/srv/ncplan"));
    }

    #[test]
    fn called_program_names_become_file_names() {
        assert_eq!(program_file_stems("O0100"), ["O0100", "100"]);
        assert_eq!(program_file_stems("TNC:\\PARTS\\Plan.h"), ["Plan.h"]);
        assert_eq!(program_file_stems("\"LIB/DRILL\""), ["DRILL"]);
        // Okuma names programs with letters after the O.
        assert_eq!(program_file_stems("OCHCK"), ["OCHCK"]);
    }

    #[test]
    fn globs() {
        assert!(glob_match(b"*.tmp", b"O1234.TMP"));
        assert!(glob_match(b".*", b".O1234.nc.swp"));
        assert!(glob_match(b"*~", b"O1234.nc~"));
        assert!(!glob_match(b"*.tmp", b"O1234.nc"));
    }

    #[test]
    fn rejects_database_in_watched_folder_and_unknown_keys() {
        let bad = "[database]\npath='shares/m1/x.db'\n[[machine]]\nname='m1'\npath='shares/m1'\ndialect='fanuc'\n";
        assert!(Config::parse(bad, Path::new("/x")).unwrap_err().to_string().contains("inside the watched folder"));
        let unknown = "[database]\npath='x.db'\ncolour='red'\n";
        assert!(Config::parse(unknown, Path::new("/x")).is_err());
    }
}

/// Subprograms from a directory: `O1000` is found as `O1000`, `O1000.nc`, `1000.nc` and so
/// on (any case, the usual extensions); an O-word name `probe` as `probe.ngc`; a path the
/// control knows (`TNC:\PARTS\Plan.h`) by its file name. Files over the size limit are
/// not used. With `subfolders`, one not in the directory is looked for in its subfolders too
/// (names in order, each level before the next, [`SUBFOLDER_DEPTH`] levels deep): a folder
/// of programs keeps its shared subroutines in subfolders (LinuxCNC's ngcgui library calls
/// `o<loadtool>` from `utilitysubs/`, which its `SUBROUTINE_PATH` lists after the folder).
#[derive(Debug)]
pub struct DirPrograms {
    /// The directory.
    pub dir: PathBuf,
    /// Largest file read.
    pub max_bytes: u64,
    /// Whether subfolders are looked in after the directory.
    pub subfolders: bool,
}

/// How many levels of subfolders [`DirPrograms`] looks in.
pub const SUBFOLDER_DEPTH: usize = 2;

/// How many folders [`DirPrograms`] looks in at most, the directory included.
const MAX_FOLDERS: usize = 64;

impl DirPrograms {
    /// The subprograms beside `file`, for a profile that has no program directory of its own;
    /// and the file's own name, which a call opens it by.
    pub fn beside(profile: &crate::interp::Profile, file: &Path, max_bytes: u64) -> crate::interp::Profile {
        let mut p = profile.clone();
        p.file_name = file.file_name().map(|n| n.to_string_lossy().into_owned());
        if p.programs.is_none() {
            let dir = file.parent().filter(|d| !d.as_os_str().is_empty()).unwrap_or(Path::new("."));
            // The folder's own files: a program handed over from anywhere (a temporary
            // folder) has no subfolders of its own to look in.
            p.programs = Some(std::sync::Arc::new(DirPrograms { dir: dir.to_path_buf(), max_bytes, subfolders: false }));
        }
        p
    }
}

/// Subprograms from the first of several sources that has them: beside the program, then the
/// CAM folders (a post keeps its subprograms beside the main program it writes).
pub struct FirstFound(pub Vec<std::sync::Arc<dyn crate::interp::ProgramSource + Send + Sync>>);

impl crate::interp::ProgramSource for FirstFound {
    fn load(&self, name: &str) -> Option<String> {
        self.0.iter().find_map(|p| p.load(name))
    }
}

/// The file names a call of `name` may mean, without extension, best first: the name with
/// any drive and folders of the control taken off (`TNC:\Plan.h` is `Plan.h`), and a program
/// number without its O and leading zeros (`O0100` is also `100`).
pub fn program_file_stems(name: &str) -> Vec<String> {
    let base = name.rsplit(['\\', '/', ':']).next().unwrap_or(name).trim_matches('"');
    let mut stems = vec![base.to_owned()];
    if let Some(number) = base.strip_prefix(['O', 'o']).filter(|n| !n.is_empty() && n.bytes().all(|b| b.is_ascii_digit())) {
        stems.push(number.trim_start_matches('0').to_owned());
    }
    stems
}

/// Extensions of program files, tried in this order after the bare name.
pub const PROGRAM_EXTENSIONS: [&str; 11] = ["", ".nc", ".ngc", ".txt", ".tap", ".cnc", ".min", ".mpf", ".spf", ".h", ".i"];

impl crate::interp::ProgramSource for DirPrograms {
    fn load(&self, name: &str) -> Option<String> {
        let mut level = vec![self.dir.clone()];
        let mut looked = 0;
        for depth in 0..=SUBFOLDER_DEPTH {
            let mut next = Vec::new();
            for dir in &level {
                if looked >= MAX_FOLDERS {
                    return None;
                }
                looked += 1;
                let Ok(read) = std::fs::read_dir(dir) else { continue };
                let mut entries: Vec<PathBuf> = read.filter_map(|e| e.ok().map(|e| e.path())).collect();
                entries.sort();
                if let Some(text) = self.load_in(&entries, name) {
                    return Some(text);
                }
                if self.subfolders && depth < SUBFOLDER_DEPTH {
                    // Real folders only: a link may lead out of the folder, or round in a loop.
                    next.extend(entries.into_iter().filter(|p| std::fs::symlink_metadata(p).is_ok_and(|m| m.is_dir())));
                }
            }
            if next.is_empty() {
                break;
            }
            level = next;
        }
        None
    }
}

impl DirPrograms {
    /// The program `name` among the files `entries` of one folder.
    fn load_in(&self, entries: &[PathBuf], name: &str) -> Option<String> {
        for stem in program_file_stems(name) {
            for ext in PROGRAM_EXTENSIONS {
                let wanted = format!("{stem}{ext}");
                let Some(path) = entries
                    .iter()
                    .find(|p| !p.is_dir() && p.file_name().is_some_and(|f| f.to_string_lossy().eq_ignore_ascii_case(&wanted)))
                else {
                    continue;
                };
                // Only a regular file, opened without blocking: a FIFO beside the program
                // never holds the analysis.
                let (text, _) = crate::text::decode(&crate::sharefile::read_regular(path, self.max_bytes)?);
                return Some(text.text);
            }
        }
        None
    }
}

//! Segmentation of the canonical stream into workingsteps.
//!
//! A workingstep ends at a tool change, at a change of operation family (milling versus
//! hole making), and at a change of technology when the toolpath starts anew (after a
//! rapid). Rapids between cuts are kept back until the next cut decides where they belong.

use std::collections::{BTreeMap, BTreeSet};

use super::Toolpath;
use super::feature;
use super::geom;
use super::model::*;
use super::setup::Setup;
use crate::canon::{Canon, CanonOp, CycleKind, FeedMode, NO_SPINDLE_LIMIT, Plane, Setting, Units};
use crate::diag::{Code, Diagnostic};
use crate::interp::Profile;
use crate::text::TextRange;

const EPS: f64 = 1e-6;

/// Recovers the process plan from a canonical stream. `program` is the program's number or
/// name, when known.
pub fn recover(canon: &[Canon], profile: &Profile, program: Option<String>) -> (ProcessPlan, Vec<Diagnostic>) {
    let mut r = Recoverer::new(profile);
    for c in canon {
        r.r.op(c);
    }
    if r.turns_throughout() {
        let lathe = Profile { turns: true, ..profile.clone() };
        let mut r = Recoverer::new(&lathe);
        for c in canon {
            r.r.op(c);
        }
        return r.finish(program);
    }
    r.finish(program)
}

/// Plan recovery as a [`CanonSink`]: it takes the ops as the interpreter emits them, so that
/// no list of them is kept (a million-move program's ops cost more than its plan).
pub struct Recoverer<'p> {
    r: Recovery<'p>,
    profile: &'p Profile,
}

impl crate::canon::CanonSink for Recoverer<'_> {
    fn emit(&mut self, canon: Canon) {
        self.r.op(&canon);
    }
}

impl<'p> Recoverer<'p> {
    /// Recovery for a program read with `profile`.
    pub fn new(profile: &'p Profile) -> Recoverer<'p> {
        Recoverer { r: Recovery::new(profile), profile }
    }

    /// Whether the program taken turns where recovery did not read it so from its start: lathe
    /// evidence came after moves were cut (a LinuxCNC `G76` after the facing and turning
    /// passes), or every cut lies in the ZX plane through the turning axis (`G18`, no Y or
    /// rotary axis ever off zero: a lathe's two axes, as LinuxCNC's `G70`-`G72` programs in
    /// radius mode are). Such a program is read again with [`Profile::turns`], so that its
    /// every workingstep turns.
    pub fn turns_throughout(&self) -> bool {
        let r = &self.r;
        !self.profile.turns && r.cut_any && ((r.lathe && r.cut_unturned) || (!r.lathe && !r.off_lathe_plane))
    }

    /// The plan of the ops taken, with the findings of recovery.
    pub fn finish(self, program: Option<String>) -> (ProcessPlan, Vec<Diagnostic>) {
        let Recoverer { mut r, profile } = self;
        r.close();
        if let Some(last) = r.done.last_mut() {
            let n = last.toolpath.len() as u32;
            last.state.stops.extend(r.pending_stops.drain(..).map(|s| Stop { at: n, ..s }));
            last.state.dwells.extend(r.pending_dwells.drain(..).map(|d| Dwell { at: n, ..d }));
        }
        let stock = |[min, max]: [P3; 2], source, line| Stock {
            origin: min,
            size: [max[0] - min[0], max[1] - min[1], max[2] - min[2]],
            source,
            line,
        };
        let placed = r.stock.map(|s| r.stock_origin.map_or(s, |o| o.place(s)));
        let workpiece = profile
            .stock
            .map(|s| stock(s, StockSource::Config, None))
            .or_else(|| placed.map(|s| stock(s, StockSource::Program, r.stock_line)));
        let mut tools: Vec<Tool> = r.tools.into_values().collect();
        tools.sort_by_key(|t| t.number);
        let mut plan = ProcessPlan { program, units: r.first_units, tools, workingsteps: r.done, features: Vec::new(), workpiece };
        if r.lathe && plan.workingsteps.iter().any(|w| w.turning.is_none()) {
            mill_turn(&mut plan);
        } else if r.lathe {
            super::turning::recognise(&mut plan, remeasure);
            super::turning::infer_tool_kinds(&mut plan);
        } else {
            explicit_holes(&mut plan);
            infer_tool_kinds(&mut plan);
            feature::recognise(&mut plan);
        }
        // A milling cycle's surface placed its feature's top; the feature carries it now.
        for ws in &mut plan.workingsteps {
            ws.surface = None;
        }
        let mut diags = r.diags;
        diags.extend(super::risk::diagnostics(&plan));
        (plan, diags)
    }
}

/// A program that turns and mills (a driven tool on the face): its turning workingsteps
/// make turned features, its milling ones (without a turning part) milled features and holes,
/// each by its own rules; the milled features are numbered after the turned ones.
fn mill_turn(plan: &mut ProcessPlan) {
    let (milling, turning): (Vec<Workingstep>, Vec<Workingstep>) =
        std::mem::take(&mut plan.workingsteps).into_iter().partition(|w| w.turning.is_none());
    let part = |ws: Vec<Workingstep>| ProcessPlan { workingsteps: ws, features: Vec::new(), ..plan.clone() };
    let (mut t, mut m) = (part(turning), part(milling));
    // Recognition reads a workingstep's number as its position: each part is numbered from 1
    // while its rules run, then given the plan's numbers back.
    let numbers = (renumber(&mut t), renumber(&mut m));
    super::turning::recognise(&mut t, remeasure);
    super::turning::infer_tool_kinds(&mut t);
    explicit_holes(&mut m);
    infer_tool_kinds(&mut m);
    feature::recognise(&mut m);
    restore_numbers(&mut t, &numbers.0);
    restore_numbers(&mut m, &numbers.1);
    let offset = t.features.len() as u32;
    for f in &mut m.features {
        f.id += offset;
    }
    for ws in &mut m.workingsteps {
        ws.feature = ws.feature.map(|id| id + offset);
    }
    // A tool that mills takes the kind the milling rules found.
    for tool in &mut t.tools {
        if let Some(mt) = m.tools.iter().find(|x| x.number == tool.number)
            && m.workingsteps.iter().any(|w| w.tool == tool.number)
        {
            *tool = mt.clone();
        }
    }
    plan.tools = t.tools;
    plan.workingsteps = t.workingsteps.into_iter().chain(m.workingsteps).collect();
    plan.workingsteps.sort_by_key(|w| w.index);
    plan.features = t.features.into_iter().chain(m.features).collect();
}

/// Numbers a part of a plan's workingsteps 1, 2, … by position; their numbers in the plan.
fn renumber(part: &mut ProcessPlan) -> Vec<u32> {
    let numbers = part.workingsteps.iter().map(|w| w.index).collect();
    for (k, w) in part.workingsteps.iter_mut().enumerate() {
        w.index = k as u32 + 1;
    }
    numbers
}

/// Gives a part's workingsteps, and its features' lists of them, their numbers in the plan.
fn restore_numbers(part: &mut ProcessPlan, numbers: &[u32]) {
    let plan_number = |i: u32| numbers.get((i as usize).wrapping_sub(1)).copied().unwrap_or(i);
    for w in &mut part.workingsteps {
        w.index = plan_number(w.index);
    }
    for f in &mut part.features {
        for i in &mut f.workingsteps {
            *i = plan_number(*i);
        }
    }
}

/// Holes made by explicit moves (posts that expand drilling into `G0`/`G1`): a workingstep
/// whose every feed runs along the tool axis, plunging at one or more points, with a tool
/// that is not a milling cutter, makes holes. The operation follows from the tool's kind
/// and the motion: several feeds into one hole are pecks, a feed back out of the hole with
/// an unknown tool is boring.
fn explicit_holes(plan: &mut ProcessPlan) {
    for ws in plan.workingsteps.iter_mut().filter(|w| w.operation == Operation::FreeformMilling) {
        // Passes over the toolpath, not a list of its feeds: it may hold millions.
        let feeds = || ws.toolpath.iter().filter(|m| m.kind != MoveKind::Rapid);
        let vertical = |m: &Move| m.kind == MoveKind::Line && (m.to[0] - m.from[0]).abs() < EPS && (m.to[1] - m.from[1]).abs() < EPS;
        if feeds().next().is_none() || !feeds().all(|m| vertical(&m)) || !feeds().any(|m| is_plunge(&m)) {
            continue;
        }
        let kind = plan.tools.iter().find(|t| t.number == ws.tool).map_or(ToolKind::Unknown, |t| t.kind);
        if matches!(kind, ToolKind::EndMill | ToolKind::BallEndMill | ToolKind::BullnoseEndMill | ToolKind::FaceMill) {
            continue; // plunge milling
        }
        // A feed into a position after lifting out of it is a peck; a feed up is a feed out.
        let mut pecked = false;
        let mut last: Option<[f64; 2]> = None;
        let mut lifted = false;
        for m in &ws.toolpath {
            let m = &m;
            if m.kind != MoveKind::Rapid && is_plunge(m) {
                let at = [m.to[0], m.to[1]];
                pecked |= lifted && last.is_some_and(|l| (l[0] - at[0]).abs() < EPS && (l[1] - at[1]).abs() < EPS);
                last = Some(at);
                lifted = false;
            } else if is_lift(m) && m.to[2] > m.from[2] + EPS {
                lifted = true;
            } else if !is_plunge(m) {
                last = None;
            }
        }
        let feed_out = feeds().any(|m| m.to[2] > m.from[2] + EPS);
        ws.operation = match kind {
            ToolKind::Reamer => Operation::Reaming,
            ToolKind::BoringTool => Operation::Boring,
            ToolKind::Tap => Operation::Tapping,
            ToolKind::CenterDrill => Operation::CenterDrilling,
            ToolKind::Unknown if feed_out && !pecked => Operation::Boring,
            _ if pecked => Operation::MultistepDrilling,
            _ => Operation::Drilling,
        };
        // Every move is part of making the holes, as in a cycle.
        for i in 0..ws.toolpath.len() {
            if ws.toolpath.get(i).is_some_and(|m| m.phase == Phase::Approach && m.kind != MoveKind::Rapid) {
                ws.toolpath.set_phase(i, Phase::Cut);
            }
        }
        let dwell = ws.state.dwells.first().map(|d| d.seconds);
        measure(ws, dwell, None, &[]);
    }
}

/// Tools whose kind nothing states get one from how the program uses them.
fn infer_tool_kinds(plan: &mut ProcessPlan) {
    for t in plan.tools.iter_mut().filter(|t| t.kind == ToolKind::Unknown) {
        let ops: Vec<Operation> = plan.workingsteps.iter().filter(|w| w.tool == t.number).map(|w| w.operation).collect();
        let kind = if ops.is_empty() {
            continue;
        } else if ops.iter().all(|o| *o == Operation::Tapping) {
            ToolKind::Tap
        } else if ops.iter().all(|o| matches!(o, Operation::Drilling | Operation::MultistepDrilling)) {
            ToolKind::TwistDrill
        } else if ops.iter().all(|o| matches!(o, Operation::Boring | Operation::BackBoring)) {
            ToolKind::BoringTool
        } else if ops.iter().all(|o| !o.is_hole()) {
            ToolKind::EndMill
        } else {
            continue;
        };
        t.kind = kind;
        t.kind_source = ToolSource::Inferred;
    }
}

/// Whether a tool's name calls it a probe, a measuring tool that cuts nothing: `PROBE`
/// (Fusion 360's probe tool `T99 ... - probe`, `TOUCH PROBE`, `3D PROBE`), German shops'
/// `TASTER` (`Messtaster`, `3D-Taster`) and `TASTSYSTEM`, Renishaw's probes by the maker's
/// name. A word only: `PROBED` or `UNPROBED` are not.
///
/// Asked at every feed move: compared in place, in any case, with no copy of the name.
pub(crate) fn names_probe(name: &str) -> bool {
    // Each word is ASCII letters and digits only, so any byte is a character's start.
    name.split(|c: char| !c.is_ascii_alphanumeric()).any(|w| {
        let starts = |s: &str| w.len() >= s.len() && w[..s.len()].eq_ignore_ascii_case(s);
        let ends = |s: &str| w.len() >= s.len() && w[w.len() - s.len()..].eq_ignore_ascii_case(s);
        w.eq_ignore_ascii_case("PROBE")
            || ends("TASTER")
            || starts("TASTSYSTEM")
            || w.eq_ignore_ascii_case("RENISHAW")
            || (ends("PROBE") && w.len() <= 8)
    })
}

/// The tool a tool-list comment names: `T3 D=10. ...`, `T3 - 10MM ENDMILL`, `T03: ...`,
/// `TOOL 3 ...`, `TOOL: 3`, `LOAD/TOOL,3`.
fn listed_tool(comment: &str) -> Option<u32> {
    let s = comment.trim_start().trim_start_matches(['(', '|', ' ']);
    let up = s.to_ascii_uppercase();
    let after_tool = up.strip_prefix("LOAD/TOOL").or_else(|| up.strip_prefix("TOOL"));
    let rest = match after_tool {
        Some(r) => {
            let r = r.trim_start_matches([' ', ':', '#', '=', ',']);
            r.strip_prefix("NO.").or_else(|| r.strip_prefix("NO")).unwrap_or(r).trim_start_matches([' ', '.', '#'])
        }
        // `T1 D=10 ...`; Fusion's Heidenhain post lists `#1 D=10 ...`.
        None => up.strip_prefix('T').or_else(|| up.strip_prefix('#'))?,
    };
    let end = rest.find(|c: char| !c.is_ascii_digit()).unwrap_or(rest.len());
    let after = rest[end..].chars().next();
    (end > 0 && after.is_none_or(|c| c.is_whitespace() || matches!(c, ':' | '-' | '=' | ',' | '|' | ')')))
        .then(|| rest[..end].parse().ok())
        .flatten()
}

/// Whether a comment names tool `t` among its words: a `T` word of its number (`T4`, `T04`),
/// or a lathe's tool and offset (`T0404`), not inside another word.
fn mentions_tool(comment: &str, t: u32) -> bool {
    let up = comment.to_ascii_uppercase();
    let b = up.as_bytes();
    (0..b.len()).any(|i| {
        if b[i] != b'T' || (i > 0 && b[i - 1].is_ascii_alphanumeric()) {
            return false;
        }
        let digits: &str = &up[i + 1..];
        let end = digits.find(|c: char| !c.is_ascii_digit()).unwrap_or(digits.len());
        let d = &digits[..end];
        let whole = |x: &str| x.parse::<u32>().ok() == Some(t);
        !d.is_empty() && (whole(d) || (d.len() == 4 && whole(&d[..2])))
    })
}

/// What a CAM tool comment states.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ToolFacts {
    /// Diameter, in [`ToolFacts::unit_mm`] (else the program's units).
    pub diameter: Option<f64>,
    /// Kind, from words such as `ENDMILL`, `DRILL`, `REAMER`.
    pub kind: Option<ToolKind>,
    /// Corner radius (`R0.5`, `CR=0.5`), in the same units as the diameter.
    pub corner_radius: Option<f64>,
    /// Flutes (`4FL`, `Z4`, `4 FLUTE`).
    pub flutes: Option<u32>,
    /// A drill's included point angle, degrees (`TAPER=118deg` of Fusion 360's tool
    /// comments, `118DEG`, `POINT 140`).
    pub point_angle: Option<f64>,
    /// The unit the comment states for its sizes, in mm: 1 for `6MM`, 25.4 for `1/4"` or
    /// `.25 IN`; `None` where it states none, and the program's units apply (a Fusion inch
    /// post writes `(T1 D=0.25 ...)`).
    pub unit_mm: Option<f64>,
}

/// Reads a CAM tool comment such as `T1 D=18 ENDMILL`, `6MM FLAT END MILL`,
/// `T3 DIA 10.5 DRILL` or `10MM 4FL BULL R0.5`.
pub fn parse_tool_comment(text: &str) -> ToolFacts {
    let up = text.to_ascii_uppercase();
    if let Some(f) = apt_tool_statement(&up) {
        return f;
    }
    let compact: String = up.chars().filter(|c| !c.is_whitespace() && *c != '-' && *c != '_').collect();
    let has = |k: &str| compact.contains(k);
    // German shop names (Heidenhain and Siemens shops): Kugel-, Torus-, Planfräser, Zentrier-,
    // NC-Anbohrer, Reibahle, Senker, Gewindebohrer, Bohrstange, Bohrer, Schaft-/Fräser, Ein- and
    // Abstechen.
    let has = |k: &str| {
        has(k)
            || match k {
                "BALL" => has("KUGEL"),
                "TORUS" => has("TORUSFR"),
                "FACEMILL" => has("PLANFR") || has("MESSERKOPF"),
                "CENTERDRILL" => has("ZENTRIER") || has("ANBOHR"),
                "REAM" => has("REIBAHLE"),
                "COUNTERSINK" => has("SENKER") || has("FASENFR"),
                "TAP" => has("GEWINDEBOHR"),
                "BORING" => has("BOHRSTANGE") || has("AUSDREH"),
                // Einstechen (grooving), Abstechen (parting off).
                "GROOV" => has("EINSTECH") || has("ABSTECH"),
                // Turkish matkap, Russian sverlo (written in Latin letters).
                // And `U-DRIL`, `UDRILL`: an indexable-insert drill (U-drill) by its trade name.
                "DRILL" => (has("BOHRER") && !has("GEWINDEBOHR")) || has("MATKAP") || has("SVERLO") || has("UDRIL"),
                "ENDMILL" => has("SCHAFTFR") || has("FRAESER") || has("FRÄSER") || has("FRäSER"),
                _ => false,
            }
    };
    let kind = if has("BALL") {
        Some(ToolKind::BallEndMill)
    } else if has("BULL") || has("TORUS") {
        Some(ToolKind::BullnoseEndMill)
    } else if has("FACEMILL") || has("SHELLMILL") || has("FACE") && has("MILL") {
        Some(ToolKind::FaceMill)
    } else if has("THREAD") && !has("MILL") {
        Some(ToolKind::ThreadingTool)
    } else if has("GROOV") || has("PARTING") || has("PARTOFF") || has("CUTOFF") {
        Some(ToolKind::GroovingTool)
    } else if (has("TURN") || has("ODROUGH") || has("ODFINISH") || has("IDROUGH") || has("IDFINISH")) && !has("MILL") {
        Some(ToolKind::TurningTool)
    } else if has("SPOT") || has("CENTERDRILL") || has("CENTREDRILL") || has("CTRDRILL") || has("NCDRILL") {
        Some(ToolKind::CenterDrill)
    } else if has("REAM") {
        Some(ToolKind::Reamer)
    } else if has("CHAMFER") || has("COUNTERSINK") || has("CSINK") || has("CSK") {
        Some(ToolKind::Countersink)
    } else if has("TAP") && !has("TAPER") {
        Some(ToolKind::Tap)
    } else if has("BORE") || has("BORING") {
        Some(ToolKind::BoringTool)
    } else if has("DRILL") {
        Some(ToolKind::TwistDrill)
    } else if has("ENDMILL") || has("FLAT") || has("SLOTMILL") || has("MILL") || em_word(&up).is_some() {
        Some(ToolKind::EndMill)
    } else {
        None
    };
    let mut corner_radius = None;
    let mut flutes = None;
    for word in up.split(|c: char| c.is_whitespace() || c == ',' || c == '(' || c == ')') {
        if let Some(rest) = word.strip_prefix("CR").or_else(|| word.strip_prefix('R')) {
            let v = rest.trim_start_matches(['=', ':']);
            let v = v.strip_suffix("MM").unwrap_or(v);
            if let Ok(r) = v.parse::<f64>()
                && (0.0..100.0).contains(&r)
                && v.starts_with(|c: char| c.is_ascii_digit() || c == '.')
            {
                corner_radius = Some(r);
            }
        }
        if let Some(rest) = word.strip_prefix('Z') {
            if !rest.is_empty() && rest.chars().all(|c| c.is_ascii_digit()) {
                flutes = rest.parse().ok();
            }
        }
        for suffix in ["FLUTES", "FLUTE", "FL"] {
            if let Some(n) = word.strip_suffix(suffix) {
                if !n.is_empty() && n.chars().all(|c| c.is_ascii_digit()) {
                    flutes = n.parse().ok();
                    break;
                }
            }
        }
    }
    if flutes.is_none() {
        let words: Vec<&str> = up.split_whitespace().collect();
        for w in words.windows(2) {
            if w[1].starts_with("FLUTE") && w[0].chars().all(|c| c.is_ascii_digit()) {
                flutes = w[0].parse().ok();
            }
        }
    }
    let (diameter, unit_mm) = comment_diameter(&up).map_or((None, None), |(d, u)| (Some(d), u));
    ToolFacts { diameter, kind, corner_radius, flutes, point_angle: point_angle(&up), unit_mm }
}

/// The facts of an APT tool statement: `TLDATA/MILL,d,r,length,taper,tip` (NX; `DRILL`
/// for a drill) or the cutter `CUTTER/d,r,e,f,a,b,h` (ISO 4343), diameter first and corner
/// radius second. A corner radius of half the diameter is a ball end mill, a smaller one a
/// bull nose; a `CUTTER` with a bottom angle and no radius is a drill.
fn apt_tool_statement(up: &str) -> Option<ToolFacts> {
    let (major, rest) = up.split_once('/')?;
    // Creo writes the cutter as a comment, `$$-> CUTTER / 20.000000`.
    let major = major.trim().trim_start_matches("->").trim();
    // MeshCAM's header names its cutter the NX way: `(TOOL/MILL,0.106,0.053,1.0,0.0)`.
    let tool = major == "TOOL" && (rest.trim_start().starts_with("MILL,") || rest.trim_start().starts_with("DRILL,"));
    if major != "TLDATA" && major != "CUTTER" && !tool {
        return None;
    }
    let mut words = Vec::new();
    let mut nums = Vec::new();
    for field in rest.split(',').map(str::trim).filter(|f| !f.is_empty()) {
        match field.parse::<f64>() {
            Ok(v) => nums.push(v),
            Err(_) if nums.is_empty() => words.push(field),
            Err(_) => {}
        }
    }
    let d = nums.first().copied().filter(|d| *d > 0.0 && *d < 1000.0)?;
    let r = nums.get(1).copied().filter(|r| *r >= 0.0 && *r <= d / 2.0 + 1e-6);
    let round = r.filter(|r| *r > 1e-6);
    let kind = if round.is_some_and(|r| (r - d / 2.0).abs() < 1e-6) {
        Some(ToolKind::BallEndMill)
    } else if round.is_some() {
        Some(ToolKind::BullnoseEndMill)
    } else if words.first() == Some(&"DRILL") || major == "CUTTER" && nums.get(4).is_some_and(|a| *a > 0.0) {
        Some(ToolKind::TwistDrill)
    } else if words.first() == Some(&"MILL") {
        Some(ToolKind::EndMill)
    } else {
        None
    };
    // ISO 4343's bottom angle `a` of a drill is half the point's supplement.
    let point_angle = (kind == Some(ToolKind::TwistDrill) && major == "CUTTER")
        .then(|| nums.get(4).copied())
        .flatten()
        .filter(|a| *a > 0.0 && *a < 90.0)
        .map(|a| 180.0 - 2.0 * a);
    Some(ToolFacts { diameter: Some(d), kind, corner_radius: r, flutes: None, point_angle, unit_mm: None })
}

/// A point angle a tool comment states: `TAPER=118DEG`, `118DEG`, `118 DEG`, `POINT 140`,
/// `POINT ANGLE=140`; only between 60° and 180°, the angles drills have.
fn point_angle(up: &str) -> Option<f64> {
    let after = |key: &str| up.find(key).and_then(|i| number_after(&up[i + key.len()..]));
    // `118DEG`, `140 GRAD` (German shops), `118°`, `140 POINT ANGLE`.
    let before_deg = ["DEG", "GRAD", "°", " POINT"].iter().find_map(|unit| {
        let i = up.find(unit)?;
        let head = up[..i].trim_end();
        let number = &head[head.trim_end_matches(|c: char| c.is_ascii_digit() || c == '.').len()..];
        number.parse::<f64>().ok()
    });
    after("TAPER").or_else(|| after("POINT ANGLE")).or_else(|| after("POINT")).or(before_deg).filter(|a| *a >= 60.0 && *a < 180.0)
}

/// The diameter of a short end-mill name (`EM10`, `EM12.5`).
fn em_word(up: &str) -> Option<f64> {
    up.split(|c: char| !(c.is_ascii_alphanumeric() || c == '.')).find_map(|w| {
        let n = w.strip_prefix("EM")?;
        n.starts_with(|c: char| c.is_ascii_digit()).then(|| n.parse::<f64>().ok()).flatten().filter(|v| *v > 0.0 && *v < 1000.0)
    })
}

/// The unsigned number a comment's word is followed by (`DIA 10.5`, `D=10`, `TAPER:118`).
fn number_after(s: &str) -> Option<f64> {
    let s = s.trim_start_matches([' ', '=', ':']);
    let end = s.find(|c: char| !(c.is_ascii_digit() || c == '.')).unwrap_or(s.len());
    s[..end].parse::<f64>().ok()
}

/// The unit a number's text states right after it: `MM` (1), `"`, `IN` or `INCH` (25.4).
fn unit_after(s: &str) -> Option<f64> {
    let s = s.trim_start_matches([' ', '=', ':']);
    let rest = s.trim_start_matches(|c: char| c.is_ascii_digit() || c == '.').trim_start();
    if rest.starts_with("MM") {
        Some(1.0)
    } else if rest.starts_with('"') || rest.starts_with("IN") && !rest[2..].starts_with(|c: char| c.is_ascii_alphabetic() && c != 'C') {
        Some(25.4)
    } else {
        None
    }
}

/// An inch fraction naming a tool's size (`1/4"`, `5/16 SPOT DRILL`), in inches.
fn inch_fraction(word: &str) -> Option<f64> {
    let (a, b) = word.trim_end_matches('"').split_once('/')?;
    let (a, b) = (a.parse::<u32>().ok()?, b.parse::<u32>().ok()?);
    ([2, 4, 8, 16, 32, 64].contains(&b) && a > 0 && a < 4 * b).then(|| f64::from(a) / f64::from(b))
}

/// The tool's diameter a comment states, and the unit it states it in (see
/// [`ToolFacts::unit_mm`]).
fn comment_diameter(up: &str) -> Option<(f64, Option<f64>)> {
    let number = |s: &str| number_after(s).filter(|v| *v > 0.0 && *v < 1000.0);
    for key in ["DIAMETER", "DIA", "Ø", "D="] {
        if let Some(i) = up.find(key) {
            let after = &up[i + key.len()..];
            let word = after.trim_start_matches([' ', '=', ':']).split(|c: char| c.is_whitespace() || matches!(c, ',' | ')')).next();
            if let Some(v) = word.and_then(inch_fraction) {
                return Some((v, Some(25.4)));
            }
            if let Some(v) = number(after) {
                return Some((v, unit_after(after)));
            }
        }
    }
    // Turkish çap (diameter), often written without its cedilla, right before its number
    // (`CAP11.5D.MATKAP`, `ÇAP 21`); not a word that only begins so (`CAP SCREW`).
    for key in ["ÇAP", "CAP"] {
        for (i, _) in up.match_indices(key) {
            let word_start = up[..i].chars().next_back().is_none_or(|c| !c.is_alphabetic());
            if let Some(v) = number(&up[i + key.len()..]).filter(|_| word_start) {
                return Some((v, unit_after(&up[i + key.len()..])));
            }
        }
    }
    // Inch fractions, as shops name drills and end mills (`1/4" DRILL`, `3/8 END MILL`).
    let fraction = up.split(|c: char| c.is_whitespace() || matches!(c, '|' | '(' | ')' | ',' | '-' | '=')).find_map(inch_fraction);
    if let Some(v) = fraction {
        return Some((v, Some(25.4)));
    }
    comment_diameter_bare(up).map(|v| (v, None)).or_else(|| comment_diameter_mm(up))
}

/// A bare number before the tool's kind, or `D18` as a word of its own.
fn comment_diameter_bare(up: &str) -> Option<f64> {
    let number = |s: &str| number_after(s).filter(|v| *v > 0.0 && *v < 1000.0);
    // A bare number naming the tool before its kind (Mastercam `T1 | 10. FLAT ENDMILL | H1 | D1`).
    let words: Vec<&str> = up.split(|c: char| c.is_whitespace() || matches!(c, '|' | '(' | ')' | ',')).filter(|w| !w.is_empty()).collect();
    const KINDS: [&str; 13] = ["FLAT", "END", "BALL", "BULL", "DRILL", "SPOT", "CENTER", "CHAMFER", "FACE", "REAM", "TAP", "BORE", "MILL"];
    for w in words.windows(2) {
        if w[0].chars().all(|c| c.is_ascii_digit() || c == '.')
            && KINDS.iter().any(|k| w[1].starts_with(k))
            && let Some(v) = number(w[0])
        {
            return Some(v);
        }
    }
    // A drill's size right after its word in Russian, Turkish and German shops (`SVERLO 1.5`).
    // (Not yet `DRILL 8.5`: a Siemens tool so named, `T="DRILL 8.5"`, is written to other
    // controls by number only, and its translation would read as another tool.)
    for w in words.windows(2) {
        if ["SVERLO", "MATKAP", "BOHRER"].contains(&w[0])
            && w[1].chars().all(|c| c.is_ascii_digit() || c == '.')
            && let Some(v) = number(w[1])
        {
            return Some(v);
        }
    }
    // `D18` as a word of its own (`DRILL-D8.5`, `REAMER_22MM`, `SPIRAL_DRILL_20MM`).
    for word in up.split(|c: char| c.is_whitespace() || matches!(c, ',' | '-' | '_' | '(' | ')' | '"' | '\'' | ';')) {
        if let Some(rest) = word.strip_prefix('D') {
            if let Some(v) = number(rest) {
                if rest.len() == rest.trim_end_matches(|c: char| c.is_ascii_alphabetic()).len() {
                    return Some(v);
                }
            }
        }
    }
    em_word(up)
}

/// A size with `MM` after it (`REAMER_22MM`, `6MM FLAT END MILL`): millimetres, whatever the
/// program's units.
fn comment_diameter_mm(up: &str) -> Option<(f64, Option<f64>)> {
    up.split(|c: char| c.is_whitespace() || matches!(c, ',' | '-' | '_' | '(' | ')' | '"' | '\'' | ';'))
        .filter_map(|w| w.strip_suffix("MM"))
        .find_map(|num| number_after(num).filter(|v| *v > 0.0 && *v < 1000.0))
        .map(|v| (v, Some(1.0)))
}

/// How many comments since the previous operation the next tool change looks at.
const MAX_COMMENTS: usize = 256;

struct Builder {
    operation: Operation,
    tool: u32,
    technology: Technology,
    moves: Toolpath,
    dwell: Option<f64>,
    peck: Option<f64>,
    /// The workpiece surface its cycles state (`RFP`, `Q203`).
    surface: Option<f64>,
    /// The surface each hole cycle call states, from the move (its index) at which it took
    /// effect: a cycle written again for each hole with its own `Q203` or `RFP` (a stepped or
    /// turned face) gives each hole its own top.
    hole_surfaces: Vec<(usize, f64)>,
    source: TextRange,
    lines: (u32, u32),
    tentative: Option<Tentative>,
    /// Feed of the last cutting move that is not a plunge.
    cut_feed: Option<f64>,
    /// Work offset, stops and dwells; offsets and optional lines are filled in at the end.
    state: MachineState,
    /// (move index, length offset, compensation) wherever they change along the feeds.
    settings: Vec<(usize, Option<u32>, Option<CompUse>)>,
    /// The levels cut so far (Z of the cuts that are not plunges), deepest last.
    levels: Vec<f64>,
    /// Where the deepest level's first cut began, in XY.
    level_entry: Option<[f64; 2]>,
    /// XY box of the cuts so far: min x, min y, max x, max y.
    cut_box: Option<[f64; 4]>,
    /// The tilted plane it runs on.
    setup: Option<Setup>,
    /// On a program that turns: the lathe cycle the workingstep belongs to (a count of
    /// cycle starts and ends), and what the cycle and the technology state.
    turn_seq: u32,
    turning: super::turned::Turning,
    /// Cut in the XY plane: on a program that turns, milling on the face (polar coordinate
    /// interpolation) or drilling along Z with a driven tool, not turning.
    milling: bool,
    /// On a lathe: each feed per revolution the cuts ran at (none: per minute), with the feed
    /// per minute it first gave and the length cut at it.
    cut_at: Vec<(Option<f64>, f64, f64)>,
}

impl Builder {
    /// What the cycle in force gives the workingstep it cuts in: a hole cycle's dwell, peck and
    /// surface (`hole_surface`, while a hole cycle runs), a milling cycle's surface.
    fn take_cycle_values(
        &mut self,
        operation: Operation,
        dwell: Option<f64>,
        peck: Option<f64>,
        hole_surface: Option<f64>,
        mill_surface: Option<f64>,
    ) {
        if operation.is_hole() && !self.operation.is_hole() {
            self.operation = operation;
        }
        if operation.is_hole() && dwell.is_some() {
            self.dwell = dwell;
        }
        if operation.is_hole() && self.peck.is_none() {
            self.peck = peck;
        }
        if self.surface.is_none() {
            self.surface = if operation.is_hole() { hole_surface } else { mill_surface };
        }
        if operation.is_hole()
            && let Some(z) = hole_surface
            && self.hole_surfaces.last().is_none_or(|l| l.1 != z)
        {
            self.hole_surfaces.push((self.moves.len().saturating_sub(1), z));
        }
    }

    /// Notes the length a lathe's cut runs at its feed per revolution (none: per minute).
    fn note_feed(&mut self, lathe: bool, per_rev: Option<f64>, mv: &Move) {
        if !lathe || mv.kind == MoveKind::Rapid {
            return;
        }
        let length = (mv.to[0] - mv.from[0]).hypot(mv.to[2] - mv.from[2]);
        match self.cut_at.iter_mut().find(|c| c.0 == per_rev) {
            Some(c) => c.2 += length,
            None => self.cut_at.push((per_rev, mv.feed, length)),
        }
    }

    /// Notes a cut (not a plunge) for the depth sequence and the region.
    fn note_cut(&mut self, m: &Move) {
        let z = m.from[2].min(m.to[2]);
        if self.levels.last().is_none_or(|d| z < d - 1e-3) {
            self.levels.push(z);
            self.level_entry = Some([m.from[0], m.from[1]]);
        }
        let b = self.cut_box.get_or_insert([m.from[0], m.from[1], m.from[0], m.from[1]]);
        for p in [m.from, m.to] {
            b[0] = b[0].min(p[0]);
            b[1] = b[1].min(p[1]);
            b[2] = b[2].max(p[0]);
            b[3] = b[3].max(p[1]);
        }
    }

    /// Whether every cut so far faces: none feeds towards -Z, and some cut across X reaches
    /// the axis (X words are radii here, in the lathe's ZX plane), each cut across going
    /// towards it, as facing passes are written (passes across that feed away from the axis
    /// are a facing cycle's levels, which its pass along the profile ends).
    fn faces_only(&self) -> bool {
        let mut cuts = self.moves.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid);
        let (mut across_to_axis, mut deeper, mut outward) = (false, false, false);
        for m in cuts.by_ref() {
            deeper |= m.to[2] < m.from[2] - 0.05;
            let across = (m.to[2] - m.from[2]).abs() < 1e-3;
            across_to_axis |= across && m.to[0].min(m.from[0]) < 0.05;
            outward |= across && m.to[0].abs() > m.from[0].abs() + 0.5;
        }
        across_to_axis && !deeper && !outward
    }

    /// Whether the cuts so far are several passes, none reaching the axis.
    fn passes_off_axis(&self) -> bool {
        let cuts = || self.moves.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid);
        let entries = self.moves.iter().filter(|m| m.kind == MoveKind::Rapid).count();
        entries >= 2 && cuts().next().is_some() && cuts().all(|m| m.to[0].min(m.from[0]) >= 0.05)
    }

    /// Whether every cut so far plunges across at `z` (the pecks of a groove or a part-off
    /// written as moves, whose last peck reaches the axis at the same place).
    fn pecks_at(&self, z: f64) -> bool {
        let mut cuts = self.moves.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid).peekable();
        cuts.peek().is_some() && cuts.all(|m| (m.from[2] - z).abs() < EPS && (m.to[2] - z).abs() < EPS)
    }

    /// Whether a cut after a retract and re-entry starts another operation with the same
    /// tool and technology: the depth sequence restarts (it is not deeper than the deepest
    /// level), the tool re-enters where the deepest level began after several levels (a
    /// finishing pass over the roughed region), or it enters outside the region cut so far.
    fn starts_anew(&self, m: &Move) -> bool {
        let Some(&deepest) = self.levels.last() else { return false };
        let z = m.from[2];
        if z > deepest + 1e-3 {
            return true;
        }
        if z < deepest - 1e-3 {
            return false;
        }
        let outside = self
            .cut_box
            .is_some_and(|b| m.from[0] < b[0] - 1.0 || m.from[0] > b[2] + 1.0 || m.from[1] < b[1] - 1.0 || m.from[1] > b[3] + 1.0);
        let again =
            self.levels.len() >= 2 && self.level_entry.is_some_and(|e| (e[0] - m.from[0]).abs() < 1e-3 && (e[1] - m.from[1]).abs() < 1e-3);
        outside || again
    }
}

/// A possible boundary between two workingsteps with one tool and technology.
struct Tentative {
    /// Index of the first move after the boundary.
    at: usize,
    /// How many of those moves lift (they stay with the earlier workingstep).
    lifts: usize,
    /// The earlier workingstep's source and last line at the boundary.
    source: TextRange,
    last_line: u32,
    /// Source and first line of the later one.
    origin: TextRange,
    line: u32,
}

/// The largest feed per revolution a turning insert cuts at, mm/rev; above it a feed move
/// only positions the tool.
const MAX_CUTTING_FEED_PER_REV: f64 = 1.5;

struct Recovery<'p> {
    profile: &'p Profile,
    k: f64,
    first_units: Option<Units>,
    plane: Plane,
    pos: P3,
    /// The rotary axes where the last move left them, degrees.
    abc: [f64; 3],
    tool: u32,
    feed: f64,
    /// Feed per spindle revolution (G95): the feed rate is then F times the speed.
    per_rev: bool,
    /// The advance per revolution of synchronised motion (G33, rigid tapping).
    sync: Option<f64>,
    speed: f64,
    /// Constant surface speed (G96): the speed limit, 1/min; `speed` is then a surface speed.
    css: Option<f64>,
    spindle: SpindleDir,
    /// The spindle the spindle ops address (canon's `Spindle` marker).
    spindle_id: SpindleId,
    /// The other spindles turning (a driven tool, a numbered spindle): speed, direction.
    others: BTreeMap<SpindleId, (f64, SpindleDir)>,
    /// On a lathe, the main spindle held in position (`SPOS`, `M19`): the C axis.
    held: bool,
    /// The radial working plane of a driven tool milling into the cylinder (`G19`/`G18` with
    /// the main spindle held) and the C angle it is at; the position and the moves are then
    /// in its coordinates (as in `setup`, which it is).
    live: Option<(Setup, f64)>,
    mist: bool,
    flood: bool,
    tools: BTreeMap<u32, Tool>,
    name_pending: bool,
    comments: Vec<(u32, String)>,
    in_cycle: Option<CycleKind>,
    dwell: Option<f64>,
    peck: Option<f64>,
    surface: Option<f64>,
    /// The workpiece surface the milling cycle in progress states (`Setting::CycleSurface`).
    mill_surface: Option<f64>,
    /// The milling cycle in progress, and the hole it makes where it makes one
    /// (`Setting::HoleMilled`).
    mill_cycle: Option<(String, Option<String>)>,
    /// The hole the next milling cycle makes (`Setting::HoleMilled`, before its start).
    hole_next: Option<String>,
    /// A hole-milling cycle that ended, whose workingstep the same cycle making the same hole
    /// at its next call continues; any other cut starts a new one.
    mill_ended: Option<(String, String)>,
    stock: Option<[P3; 2]>,
    /// Where a stock origin comment puts the stock (`STOCK ORIGIN: X0 Y0 Z1 - LOWER LEFT TOP`).
    stock_origin: Option<StockOrigin>,
    /// The line that stated the stock.
    stock_line: Option<u32>,
    /// Work offset in force (1 for G54).
    wcs: u16,
    /// The tilted working plane in force; the position and the moves are in its coordinates.
    setup: Option<Setup>,
    /// The diameter (mm) of the cylinder whose developed surface the next work plane is
    /// (`Setting::CylinderWrap`): cylindrical interpolation.
    wrap: Option<f64>,
    /// The tool axis the canon last stated (5-axis moves), in the plane's coordinates.
    tool_axis: P3,
    /// The tool axis the last move ran with: a feed to where the tool is that turns it to
    /// another axis is a move (the rotary axes turn about the tip), not one that goes nowhere.
    moved_axis: P3,
    /// Length offset number in force.
    h: Option<u32>,
    /// Cutter compensation in force.
    comp: Option<CompUse>,
    /// The radius compensation offsets by, when the interpreter knows it, and its side (left).
    comp_radius: Option<(f64, bool)>,
    /// Tool-list comments (`T3 D=10. CR=0. - FLAT END MILL`) by the tool they name.
    listed: BTreeMap<u32, String>,
    /// Names of tools the program selects by name (`T="EM10"`).
    tool_names: BTreeMap<u32, String>,
    /// Lines of optional (`/`) blocks that ran.
    optional: BTreeSet<u32>,
    /// Stops and dwells met while no workingstep is open: they go to the next one.
    pending_stops: Vec<Stop>,
    pending_dwells: Vec<Dwell>,
    /// The feed override is off (M49, M50 P0).
    feed_override_off: bool,
    current: Option<Builder>,
    pending: Vec<Move>,
    done: Vec<Workingstep>,
    diags: Vec<Diagnostic>,
    /// The program turns about Z (diameter mode, a lathe cycle).
    lathe: bool,
    /// Roughing or finishing as the last operation comment states it (`(ROUGHING)`,
    /// `(FINISH_BORE_ID)`), for the next turning workingstep.
    stated: Option<bool>,
    /// The line of that comment where it gives sizes: on a tool change's line it describes the
    /// tool (`T0101 (OD ROUGH 80DEG)`), not the operation; 0 where it gives none.
    stated_line: u32,
    /// The lathe cycle in force, and the count of cycle starts and ends.
    turn: Option<crate::canon::TurnIntent>,
    turn_seq: u32,
    /// Something was cut: while the program was not known to turn (`cut_unturned`); outside
    /// the ZX plane through the axis, a Y or a rotary axis off zero (`off_lathe_plane`).
    cut_any: bool,
    cut_unturned: bool,
    off_lathe_plane: bool,
}

impl<'p> Recovery<'p> {
    fn new(profile: &'p Profile) -> Recovery<'p> {
        Recovery {
            profile,
            k: 1.0,
            first_units: None,
            plane: Plane::Xy,
            pos: [0.0; 3],
            abc: [0.0; 3],
            tool: 0,
            feed: 0.0,
            per_rev: false,
            sync: None,
            speed: 0.0,
            css: None,
            spindle: SpindleDir::Off,
            spindle_id: SpindleId::Main,
            others: BTreeMap::new(),
            held: false,
            live: None,
            mist: false,
            flood: false,
            tools: BTreeMap::new(),
            name_pending: false,
            comments: Vec::new(),
            in_cycle: None,
            dwell: None,
            peck: None,
            surface: None,
            mill_surface: None,
            mill_cycle: None,
            hole_next: None,
            mill_ended: None,
            stock: None,
            stock_origin: None,
            stock_line: None,
            wcs: 1,
            setup: None,
            wrap: None,
            tool_axis: [0.0, 0.0, 1.0],
            moved_axis: [0.0, 0.0, 1.0],
            h: None,
            comp: None,
            comp_radius: None,
            optional: BTreeSet::new(),
            tool_names: BTreeMap::new(),
            listed: BTreeMap::new(),
            pending_stops: Vec::new(),
            pending_dwells: Vec::new(),
            feed_override_off: false,
            current: None,
            pending: Vec::new(),
            done: Vec::new(),
            diags: Vec::new(),
            lathe: profile.turns,
            stated: None,
            stated_line: 0,
            turn: None,
            turn_seq: 0,
            cut_any: false,
            cut_unturned: false,
            off_lathe_plane: false,
        }
    }

    /// What a new turning workingstep starts with: its cycle, the feed per revolution and
    /// the spindle clamp.
    fn turning_now(&self) -> super::turned::Turning {
        super::turned::Turning {
            cycle: self.turn.as_ref().map(|t| t.code.clone()),
            intent: self.turn.as_ref().map(|t| self.turn_in_mm(t)),
            feed_per_rev: (self.per_rev && self.sync.is_none()).then_some(self.feed),
            spindle_limit: self.css.filter(|m| *m < NO_SPINDLE_LIMIT),
            pitch: self.sync.map(round_sig),
            nose: self.comp_radius,
            ..super::turned::Turning::default()
        }
    }

    /// A lathe cycle's values in millimetres.
    fn turn_in_mm(&self, t: &crate::canon::TurnIntent) -> crate::canon::TurnIntent {
        let k = |v: Option<f64>| v.map(|v| round_sig(self.mm(v)));
        crate::canon::TurnIntent {
            depth_of_cut: k(t.depth_of_cut),
            retract: k(t.retract),
            allowance_x: k(t.allowance_x),
            allowance_z: k(t.allowance_z),
            pitch: k(t.pitch),
            thread_depth: k(t.thread_depth),
            first_cut: k(t.first_cut),
            min_cut: k(t.min_cut),
            finish_allowance: k(t.finish_allowance),
            peck: k(t.peck),
            step: k(t.step),
            span: t.span.map(|[lo, hi]| [round_sig(self.mm(lo)), round_sig(self.mm(hi))]),
            relief: t.relief.map(|r| r.map(|v| round_sig(self.mm(v)))),
            ..t.clone()
        }
    }

    /// A lathe cycle starts: a workingstep of its own, unless it is the next single pass of
    /// the cycle the workingstep was cutting (G90 blocks one after another).
    fn turning_begins(&mut self, t: &crate::canon::TurnIntent) {
        use crate::canon::TurnKind;
        self.lathe = true;
        let pass = matches!(t.kind, Some(TurnKind::TurnPass | TurnKind::FacePass | TurnKind::ThreadPass));
        let continues = pass
            && self.current.as_ref().is_some_and(|b| {
                b.turn_seq + 1 == self.turn_seq && b.turning.intent.as_ref().is_some_and(|i| i.kind == t.kind) && b.tool == self.tool
            });
        if continues {
            self.turn_seq -= 1;
        } else {
            self.turn_seq += 1;
        }
        self.turn = Some(t.clone());
    }

    fn technology(&self) -> Technology {
        let coolant = match (self.mist, self.flood) {
            (false, false) => Coolant::Off,
            (true, false) => Coolant::Mist,
            (false, true) => Coolant::Flood,
            (true, true) => Coolant::Both,
        };
        let feed = self.feed_now();
        // A driven tool cutting while the main spindle holds the part: the tool's spindle.
        if let Some((id, speed, dir)) = self.driven() {
            return Technology {
                feed,
                feeds: vec![feed],
                spindle_speed: speed,
                surface_speed: None,
                spindle: dir,
                coolant,
                spindle_id: id,
            };
        }
        let (spindle_speed, surface_speed) = match self.css {
            Some(max) => (if max < NO_SPINDLE_LIMIT { max } else { 0.0 }, Some(round_sig(self.surface_mm_per_min() / 1000.0))),
            None => (self.speed, None),
        };
        Technology { feed, feeds: vec![feed], spindle_speed, surface_speed, spindle: self.spindle, coolant, spindle_id: SpindleId::Main }
    }

    /// The spindle marker, and the ops of another spindle than the main one (a driven tool)
    /// and the main one's orientation, which holds the part: true where `op` was one.
    fn other_spindle(&mut self, op: &CanonOp) -> bool {
        match op {
            CanonOp::Spindle(id) => self.spindle_id = *id,
            CanonOp::SetSpindleSpeed(s) if self.spindle_id != SpindleId::Main => {
                let dir = self.others.get(&self.spindle_id).map_or(SpindleDir::Off, |o| o.1);
                self.others.insert(self.spindle_id, (round_sig(*s), dir));
            }
            // Another spindle than the main one turns (a driven tool) or stops.
            CanonOp::StartSpindleClockwise | CanonOp::StartSpindleCounterclockwise | CanonOp::StopSpindleTurning
                if self.spindle_id != SpindleId::Main =>
            {
                let dir = match op {
                    CanonOp::StartSpindleClockwise => SpindleDir::Cw,
                    CanonOp::StartSpindleCounterclockwise => SpindleDir::Ccw,
                    _ => SpindleDir::Off,
                };
                self.others.entry(self.spindle_id).or_insert((0.0, dir)).1 = dir;
            }
            // On a lathe, the main spindle oriented is held in position (the C axis) until it
            // turns again (which `op` then tells).
            CanonOp::OrientSpindle { .. } if self.spindle_id == SpindleId::Main => self.held = true,
            CanonOp::StartSpindleClockwise | CanonOp::StartSpindleCounterclockwise => {
                self.held = false;
                return false;
            }
            _ => return false,
        }
        true
    }

    /// On a lathe whose main spindle is held in position or stopped (Haas `M5`, then `M154`
    /// engages the C axis), the other spindle that turns (a driven tool): the tool's spindle,
    /// speed and direction.
    fn driven(&self) -> Option<(SpindleId, f64, SpindleDir)> {
        if !(self.lathe && (self.held || self.spindle == SpindleDir::Off)) {
            return None;
        }
        self.others.iter().find(|(_, o)| o.1 != SpindleDir::Off).map(|(id, (speed, dir))| (*id, *speed, *dir))
    }

    /// The radial working plane a driven tool mills into the cylinder on (the main spindle
    /// held at C, the lathe's plane not the face's XY), where no tilted plane is in force: its
    /// Z the radial direction at C, its X along -Z, as `interp::live` drills a side hole.
    fn live_plane(&self) -> Option<(Setup, f64)> {
        if self.driven().is_none() || self.plane == Plane::Xy || (self.setup.is_some() && self.live.is_none()) {
            return None;
        }
        let c = self.abc[2];
        let (s, co) = c.to_radians().sin_cos();
        let clean = |v: f64| if v.abs() < 1e-12 { 0.0 } else { v };
        Some((Setup { origin: [0.0; 3], axis: [clean(co), clean(s), 0.0], ref_direction: [0.0, 0.0, -1.0], cylinder: None }, c))
    }

    /// A point of the lathe's frame (X radial at the part's angle `c`) in the part's.
    fn lathe_to_part(p: P3, c: f64) -> P3 {
        let (s, co) = c.to_radians().sin_cos();
        [p[0] * co - p[1] * s, p[0] * s + p[1] * co, p[2]]
    }

    /// A point the canon gives (lathe coordinates) in the coordinates the moves are kept in:
    /// the driven tool's radial plane where it mills into the cylinder. Entering, leaving or
    /// turning that plane ends the workingstep and carries the position and the waiting
    /// rapids into the new coordinates.
    fn live_point(&mut self, p: P3) -> P3 {
        let new = self.live_plane();
        if new.map(|n| n.0) != self.live.map(|l| l.0) {
            self.close_keeping_approach();
            let (old, c_new) = (self.live, new.map_or(self.abc[2], |n| n.1));
            let carry = |q: P3| {
                // To the part's frame, then into the new plane (or back to the lathe's frame).
                let part = match old {
                    Some((s, _)) => s.to_part(q),
                    None => Self::lathe_to_part(q, c_new),
                };
                match new {
                    Some((s, _)) => s.from_part(part),
                    None => Self::lathe_to_part(part, -old.map_or(0.0, |o| o.1)),
                }
            };
            self.pos = carry(self.pos);
            for m in &mut self.pending {
                (m.from, m.to) = (carry(m.from), carry(m.to));
            }
            self.live = new;
            self.setup = new.map(|n| n.0);
        }
        match self.live {
            Some((s, c)) => s.from_part(Self::lathe_to_part(p, c)),
            None => p,
        }
    }

    /// The constant surface speed in mm/min: S is in m/min in a metric program and in feet
    /// per minute in an inch one.
    fn surface_mm_per_min(&self) -> f64 {
        self.speed * if self.k == 1.0 { 1000.0 } else { 304.8 }
    }

    /// The spindle's speed now, 1/min: under constant surface speed, the one that gives the
    /// surface speed at the tool's distance from the turning axis (X), up to the limit.
    fn rpm_now(&self) -> f64 {
        let Some(max) = self.css else { return self.speed };
        // Surface speed in mm/min over the circumference at the tool.
        let circumference = 2.0 * std::f64::consts::PI * self.pos[0].abs();
        let rpm = if circumference > 1e-9 { self.surface_mm_per_min() / circumference } else { f64::INFINITY };
        if rpm.is_finite() || max < NO_SPINDLE_LIMIT { rpm.min(max) } else { 0.0 }
    }

    /// The feed per minute. A feed per revolution becomes one at the programmed speed, so
    /// that the same cut programmed either way gives the same technology.
    fn feed_now(&self) -> f64 {
        match self.sync {
            Some(pitch) => round_sig(pitch * self.rpm_now()),
            None if self.per_rev => round_sig(self.feed * self.rpm_now()),
            None => self.feed,
        }
    }

    fn mm(&self, v: f64) -> f64 {
        v * self.k
    }

    fn op(&mut self, c: &Canon) {
        match &c.op {
            CanonOp::UseLengthUnits(u) => {
                self.first_units.get_or_insert(*u);
                self.k = u.to_mm();
            }
            // On a lathe, turning (ZX) and milling on the face (XY) are workingsteps apart: the
            // next cut decides (`cut`), so that a driven tool's holes, each a block that turns
            // to the face and back, stay one workingstep.
            CanonOp::SelectPlane(p) => self.plane = *p,
            CanonOp::SetFeedRate(f) => self.feed = round_sig(self.mm(*f)),
            CanonOp::SetFeedMode(m) => self.per_rev = *m == FeedMode::PerRevolution,
            // Synchronised moves or a constant cutting speed in the ZX plane: a lathe's.
            CanonOp::StartSpeedFeedSync(pitch) => {
                self.sync = Some(self.mm(*pitch));
                self.lathe |= self.plane == Plane::Xz;
            }
            CanonOp::StopSpeedFeedSync => self.sync = None,
            CanonOp::RigidTap(p) => {
                // Into the hole and back out along the same line.
                let back = self.pos;
                let to = [self.mm(p[0]), self.mm(p[1]), self.mm(p[2])];
                let mv = self.mv(MoveKind::Line, to, c.line);
                self.cut(mv, c);
                let mv = self.mv(MoveKind::Line, back, c.line);
                self.cut(mv, c);
            }
            CanonOp::Spindle(_)
            | CanonOp::SetSpindleSpeed(_)
            | CanonOp::StartSpindleClockwise
            | CanonOp::StartSpindleCounterclockwise
            | CanonOp::StopSpindleTurning
            | CanonOp::OrientSpindle { .. }
                if self.other_spindle(&c.op) => {}
            CanonOp::SetSpindleSpeed(s) => self.speed = round_sig(*s),
            CanonOp::SetSpindleMode(max) => {
                self.css = *max;
                self.lathe |= max.is_some() && self.plane == Plane::Xz;
            }
            CanonOp::StartSpindleClockwise => self.spindle = SpindleDir::Cw,
            CanonOp::StartSpindleCounterclockwise => self.spindle = SpindleDir::Ccw,
            // A boring cycle's spindle stop is part of the cycle, not of the technology.
            CanonOp::StopSpindleTurning if self.in_cycle.is_none() => self.spindle = SpindleDir::Off,
            CanonOp::MistOn => self.mist = true,
            CanonOp::MistOff => self.mist = false,
            CanonOp::FloodOn => self.flood = true,
            CanonOp::FloodOff => self.flood = false,
            CanonOp::ChangeTool(t) => self.change_tool(*t, c.line),
            CanonOp::UseToolLengthOffset(o) => {
                let len = self.mm(o[2]);
                if let Some(t) = self.tools.get_mut(&self.tool)
                    && t.length_offset.is_none()
                    && len != 0.0
                {
                    t.length_offset = Some(len);
                }
            }
            CanonOp::Dwell(secs) if self.in_cycle.is_some() => self.dwell = Some(*secs),
            CanonOp::Dwell(secs) => {
                let d = Dwell { seconds: *secs, line: c.line, at: 0 };
                match self.current.as_mut() {
                    Some(b) => b.state.dwells.push(Dwell { at: (b.moves.len() + self.pending.len()) as u32, ..d }),
                    None => self.pending_dwells.push(d),
                }
            }
            CanonOp::FeedOverride(on) => self.feed_override_off = !on,
            CanonOp::ProgramStop | CanonOp::OptionalProgramStop => {
                let s = Stop { optional: c.op == CanonOp::OptionalProgramStop, line: c.line, at: 0 };
                match self.current.as_mut() {
                    Some(b) => b.state.stops.push(Stop { at: (b.moves.len() + self.pending.len()) as u32, ..s }),
                    None => self.pending_stops.push(s),
                }
            }
            CanonOp::SetG5xOffset(index, _) => self.wcs = *index,
            CanonOp::Setting(Setting::LengthOffset(h)) => self.h = Some(*h),
            CanonOp::Setting(Setting::CutterComp(c)) => {
                self.comp = c.map(|c| CompUse { left: c.left, number: c.number });
                // The radius the path is offset by: on a lathe, the tool's nose radius.
                self.comp_radius = c.and_then(|c| c.radius.filter(|r| *r > 0.0).map(|r| (r, c.left)));
                if let Some(b) = self.current.as_mut()
                    && b.turning.nose.is_none()
                {
                    b.turning.nose = self.comp_radius;
                }
            }
            CanonOp::Setting(Setting::ToolName(n, name)) => {
                self.tool_names.insert(*n, name.clone());
            }
            CanonOp::Setting(Setting::BlockDelete) => {
                self.optional.insert(c.line);
            }
            CanonOp::Comment(s) => self.comment(s, c.line),
            CanonOp::CycleBegin(intent) => self.cycle_begin(intent, c),
            CanonOp::CycleEnd => self.in_cycle = None,
            // Diameter or radius mode: only a lathe has them.
            CanonOp::Setting(Setting::DiameterMode(_)) => self.lathe = true,
            CanonOp::Setting(Setting::CylinderWrap(r)) => {
                self.wrap = r.map(|r| 2.0 * self.mm(r));
                // Off the cylinder the driven tool's axis is the plane's Z again.
                if self.wrap.is_none() {
                    self.tool_axis = [0.0, 0.0, 1.0];
                }
            }
            // A milling cycle is one operation: a workingstep of its own.
            CanonOp::Setting(s @ (Setting::MillCycle(_) | Setting::HoleMilled(_) | Setting::CycleSurface(_))) => self.mill_cycle_marker(s),
            CanonOp::Turning(t) => self.turning_begins(t),
            CanonOp::TurningEnd => {
                self.turn = None;
                self.turn_seq += 1;
            }
            // A probe move measures; it positions like a rapid and cuts nothing (so does a
            // probe's feed move, `probe_feed`).
            CanonOp::StraightFeed(p) if self.probe_in_spindle() => self.positioning(p, c),
            CanonOp::StraightTraverse(p) | CanonOp::StraightProbe(p) => self.positioning(p, c),
            // A spline is followed by its chord: the plan keeps where it cuts to.
            CanonOp::StraightFeed(p) | CanonOp::NurbsFeed { end: p, .. } => {
                self.wrap_axis(self.mm(p[1]));
                let abc = [p[3], p[4], p[5]];
                let c_before = self.abc[2];
                self.abc[2] = p[5];
                let to = self.live_point([self.mm(p[0]), self.mm(p[1]), self.mm(p[2])]);
                self.abc[2] = c_before;
                // A feed that goes nowhere (a post's repeated position, `G1 X0` at X0) cuts
                // nothing: written or left out, the toolpath is the same. One that turns the
                // tool to another axis there (a CL `GOTO/x,y,z,i,j,k` at the same point, the
                // first from where the tool stands) is a move about the tip.
                if geom::dist(to, self.pos) < EPS
                    && abc.iter().zip(&self.abc).all(|(a, b)| (a - b).abs() < EPS)
                    && self.tool_axis == self.moved_axis
                {
                    return;
                }
                self.abc = abc;
                self.moved_axis = self.tool_axis;
                let mv = self.mv(MoveKind::Line, to, c.line);
                self.cut(mv, c);
            }
            CanonOp::ArcFeed { .. } => self.arc_feed(c),
            CanonOp::ProgramEnd | CanonOp::Finish => self.close(),
            CanonOp::WorkPlane(f) => self.work_plane(f.as_deref()),
            CanonOp::ToolAxis(v) => self.tool_axis = *v,
            _ => {}
        }
    }

    /// A tilted working plane put in force (or cancelled): the workingstep on the plane
    /// before ends, and the position and the rapids waiting for the next cut are carried
    /// into the new plane's coordinates.
    fn work_plane(&mut self, f: Option<&crate::canon::Frame>) {
        let new = f.map(|f| Setup { cylinder: self.wrap, ..Setup::of_frame(f, self.k) });
        // The interpreter's plane wins over a driven tool's radial plane (its moves are
        // already in the plane's coordinates: a side hole's cycle).
        self.live = None;
        if new == self.setup {
            return;
        }
        self.close_keeping_approach();
        let old = self.setup;
        let carry = |p: P3| Setup::carry(p, old.as_ref(), new.as_ref());
        self.pos = carry(self.pos);
        // Only rapids wait for the next cut.
        for m in &mut self.pending {
            (m.from, m.to) = (carry(m.from), carry(m.to));
        }
        self.setup = new;
    }

    /// A tool change: the plan's entry for the tool, from the shop's tool table, the name the
    /// program gave it, and the comments that describe it.
    fn change_tool(&mut self, t: u32, line: u32) {
        self.close();
        if self.stated_line == line && line != 0 {
            self.stated = None;
        }
        self.tool = t;
        let known = self.profile.tools.get(&t);
        let kind = known.and_then(|k| k.kind.as_deref()).and_then(ToolKind::parse);
        let entry = self.tools.entry(t).or_insert_with(|| Tool {
            number: t,
            name: known.and_then(|k| k.name.clone()),
            kind: kind.unwrap_or(ToolKind::Unknown),
            kind_source: if kind.is_some() { ToolSource::Table } else { ToolSource::Unknown },
            diameter: known.and_then(|k| k.diameter),
            corner_radius: known.and_then(|k| k.corner_radius),
            flutes: known.and_then(|k| k.flutes),
            length_offset: known.map(|k| k.length).filter(|l| *l != 0.0),
            point_angle: known.and_then(|k| k.point_angle),
            source: if known.is_some() { ToolSource::Table } else { ToolSource::Unknown },
        });
        if entry.kind == ToolKind::Unknown
            && let Some(name) = entry.name.clone()
        {
            let facts = parse_tool_comment(&name);
            if let Some(k) = facts.kind {
                entry.kind = k;
                entry.kind_source = ToolSource::Table;
            }
        }
        let by_name = entry.name.is_none().then(|| self.tool_names.get(&t).cloned()).flatten();
        self.name_pending = entry.name.is_none();
        if let Some(name) = by_name {
            self.name_tool(&name);
            self.name_pending = false;
        }
        let best = self.comment_for_tool(t, line);
        self.comments.clear();
        if let Some(s) = best {
            self.name_tool(&s);
        }
    }

    /// A program that cuts without any tool change while its header lists exactly one tool
    /// (a router's post: `(T1 D=6.35 CR=0. - FLAT END MILL)` and no `T1 M6`) cuts with that
    /// tool: it is taken as the tool in the spindle, with a note. The approach moves waiting
    /// for the first workingstep stay.
    fn tool_of_the_list(&mut self, c: &Canon) {
        let Some((&n, listed)) = self.listed.iter().next() else { return };
        let msg = format!(
            "no tool change before the first cut: the program's tool list names one tool, T{n} ({}), taken as the tool in the spindle",
            listed.trim()
        );
        self.diags.push(Diagnostic::new(Code::ToolFromList, c.origin, msg));
        let pending = std::mem::take(&mut self.pending);
        self.change_tool(n, c.line);
        self.pending = pending;
    }

    /// The comment that best describes tool `t`, changed on `line`. The comments since the
    /// previous operation (or the program start) that name this tool or no tool are this
    /// tool's: a comment naming another tool (`T2 ...` of a header tool list) is not.
    fn comment_for_tool(&self, t: u32, line: u32) -> Option<String> {
        // Nearest first.
        let here: Vec<(u32, &String)> = self
            .comments
            .iter()
            .rev()
            .filter_map(|(l, s)| {
                let named = listed_tool(s);
                named.is_none_or(|n| n == t).then_some((*l, s))
            })
            .collect();
        // Up to three lines before the change (or on its block) is near.
        let near: Vec<&String> = here.iter().filter(|(l, _)| *l + 3 >= line).map(|(_, s)| *s).collect();
        let diameter = |s: &&String| parse_tool_comment(s).diameter.is_some();
        let states = |s: &str| {
            let f = parse_tool_comment(s);
            f.diameter.is_some() || f.kind.is_some()
        };
        // A diameter near the change first, then the nearest comment naming this tool
        // with a diameter (`( T1 | 10. FLAT ENDMILL | H1 | D1 )` further up, an
        // operation header), then the tool list, then the nearest diameter further
        // up, then a kind near it (an operation's name, `DRILL1`, says less than the
        // list).
        near.iter()
            .find(|s| diameter(s))
            .map(|s| s.to_string())
            .or_else(|| here.iter().map(|(_, s)| *s).find(|s| listed_tool(s).is_some() && diameter(s)).cloned())
            .or_else(|| self.listed.get(&t).cloned())
            .or_else(|| here.iter().map(|(_, s)| *s).find(diameter).cloned())
            .or_else(|| near.iter().find(|s| states(s)).map(|s| s.to_string()))
            // Further up, an operation header that names this tool among its words and says
            // what it is (`(Step 1: groove | T4: Einstechen MGMN200)` before `(Toolchange move)`).
            .or_else(|| here.iter().map(|(_, s)| *s).find(|s| mentions_tool(s, t) && states(s)).cloned())
            .or(near.first().map(|s| s.to_string()))
    }

    /// A comment: the stock's origin or size when it states them (the first such comment),
    /// else a tool list entry, a description of the tool just changed, or a nearby comment
    /// kept for the next tool change.
    fn comment(&mut self, s: &str, line: u32) {
        if self.stock_origin.is_none()
            && let Some(o) = StockOrigin::parse(s)
        {
            self.stock_origin = Some(StockOrigin { point: o.point.map(|v| self.mm(v)), ..o });
            return;
        }
        if self.stock.is_none()
            && let Some([a, b]) = parse_stock(s)
        {
            self.stock = Some([a.map(|v| self.mm(v)), b.map(|v| self.mm(v))]);
            self.stock_line = Some(line);
            return;
        }
        if let Some(n) = listed_tool(s) {
            let f = parse_tool_comment(s);
            if f.diameter.is_some() || f.kind.is_some() {
                self.listed.entry(n).or_insert_with(|| s.trim().to_owned());
            }
        }
        if let Some(rough) = stated_roughness(s) {
            self.stated = Some(rough);
            // Sizes say a tool is described (`80DEG R0.8`), not an operation (`ROUGH OD`).
            self.stated_line = if s.bytes().any(|b| b.is_ascii_digit()) { line } else { 0 };
        }
        self.comments.push((line, s.trim().to_owned()));
        if self.comments.len() > MAX_COMMENTS {
            self.comments.remove(0);
        }
        if self.name_pending {
            let s = s.trim().to_owned();
            self.name_tool(&s);
        }
    }

    /// A canned cycle begins: its dwell, peck and surface go to the holes it drills.
    fn cycle_begin(&mut self, intent: &crate::canon::CycleIntent, c: &Canon) {
        self.in_cycle = Some(intent.kind);
        self.dwell = intent.dwell;
        self.peck = intent.peck.map(|q| self.mm(q));
        self.surface = intent.surface.map(|z| self.mm(z));
        // The positioning move before a called cycle belongs to the hole, as the
        // cycle's own move to the hole does when the cycle positions itself (G81 X Y).
        if intent.positioned
            && self.pending.last().is_some_and(|m| m.kind == MoveKind::Rapid && (m.to[2] - m.from[2]).abs() < EPS)
            && let Some(mv) = self.pending.pop()
        {
            self.cut(mv, c);
        }
    }

    /// Under cylindrical interpolation (`wrap`), the tool axis where a move on the developed
    /// surface ends `y` mm round the cylinder from where its plane is laid: the driven tool
    /// stands radial (Fanuc 0i-TF / 30i cylindrical interpolation G07.1, SINUMERIK `TRACYL`:
    /// the tool's axis is square to the cylinder), so in the plane's coordinates it is turned
    /// about the plane's X by `y` over the radius. Taken from the move's own end (the tool
    /// centre the canon moves, with any cutter radius offset in it), not stated in the canon:
    /// the canon's moves stay those of the developed surface the program writes, which a post
    /// writes as they stand.
    fn wrap_axis(&mut self, y: f64) {
        let Some(d) = self.wrap.filter(|d| *d > 1e-9) else { return };
        let (s, c) = (2.0 * y / d).sin_cos();
        let clean = |v: f64| if v.abs() < 1e-12 { 0.0 } else { v };
        self.tool_axis = [0.0, clean(s), clean(c)];
    }

    /// An arc in the selected plane, its centre and end in millimetres.
    fn arc_feed(&mut self, c: &Canon) {
        let CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, abc } = &c.op else { return };
        let (a0, a1, n) = self.plane.axes();
        let mut to = [0.0; 3];
        to[a0] = self.mm(*first_end);
        to[a1] = self.mm(*second_end);
        to[n] = self.mm(*axis_end);
        self.wrap_axis(to[1]);
        self.abc = *abc;
        self.moved_axis = self.tool_axis;
        let mut center = self.pos;
        center[a0] = self.mm(*first_axis);
        center[a1] = self.mm(*second_axis);
        let mut axis = [0.0; 3];
        axis[n] = 1.0;
        if self.live_plane().is_some() || self.live.is_some() {
            // Into the driven tool's radial plane: the centre as the end point across the plane.
            let mut c0 = to;
            (c0[a0], c0[a1]) = (center[a0], center[a1]);
            let to_lathe = to;
            let to = self.live_point(to_lathe);
            if let Some((s, angle)) = self.live {
                let center = s.from_part(Self::lathe_to_part(c0, angle));
                let axis = s.from_part(Self::lathe_to_part(axis, angle));
                let mut mv = self.mv(MoveKind::Arc, to, c.line);
                mv.arc = Some(ArcGeometry { center, axis, turns: *rotation });
                self.cut(mv, c);
                return;
            }
            let mut mv = self.mv(MoveKind::Arc, to, c.line);
            mv.arc = Some(ArcGeometry { center: c0, axis, turns: *rotation });
            self.cut(mv, c);
            return;
        }
        let mut mv = self.mv(MoveKind::Arc, to, c.line);
        mv.arc = Some(ArcGeometry { center, axis, turns: *rotation });
        self.cut(mv, c);
    }

    /// A move that positions as a rapid does: a rapid, a probing move, and a probe's feed
    /// move (a tool its name calls one: Fusion's `T99 ... probe`, a shop's `3D-Taster`; the
    /// protected positioning moves of a probing job, the `G1 Z-.25 F..` down to the probing
    /// height, cut nothing). Inside a canned cycle, the cycle's own rapid.
    fn positioning(&mut self, p: &[f64; 6], c: &Canon) {
        self.wrap_axis(self.mm(p[1]));
        self.abc = [p[3], p[4], p[5]];
        self.moved_axis = self.tool_axis;
        let to = self.live_point([self.mm(p[0]), self.mm(p[1]), self.mm(p[2])]);
        let mv = self.mv(MoveKind::Rapid, to, c.line);
        if self.in_cycle.is_some() {
            self.cut(mv, c);
        } else {
            self.pending.push(mv);
        }
    }

    /// Whether the tool in the spindle is a probe by its name (not a cutting tool).
    fn probe_in_spindle(&self) -> bool {
        self.in_cycle.is_none() && self.tools.get(&self.tool).and_then(|t| t.name.as_deref()).is_some_and(names_probe)
    }

    fn name_tool(&mut self, comment: &str) {
        if comment.is_empty() {
            return;
        }
        // A tool named by the program (`T="EM10"`) still takes the facts a comment states.
        if let Some(t) = self.tools.get_mut(&self.tool)
            && (t.name.is_none() || t.source == ToolSource::Unknown)
        {
            t.name.get_or_insert_with(|| comment.to_owned());
            let mut facts = parse_tool_comment(comment);
            // A comment's sizes are in the program's units unless it states its own (`6MM`,
            // `1/4"`): a Fusion inch post writes `(T1 D=0.25 ...)`.
            let k = facts.unit_mm.unwrap_or(self.k);
            if k != 1.0 {
                facts.diameter = facts.diameter.map(|d| round_sig(d * k));
                facts.corner_radius = facts.corner_radius.map(|r| round_sig(r * k));
            }
            if t.point_angle.is_none() && t.diameter.is_none() {
                t.point_angle = facts.point_angle;
            }
            if t.diameter.is_none() && facts.diameter.is_some() {
                t.diameter = facts.diameter;
                t.corner_radius = t.corner_radius.or(facts.corner_radius);
                t.flutes = t.flutes.or(facts.flutes);
                t.source = ToolSource::Comment;
            }
            if t.kind == ToolKind::Unknown
                && let Some(k) = facts.kind
            {
                t.kind = k;
                t.kind_source = ToolSource::Comment;
            }
            self.name_pending = false;
        }
    }

    fn mv(&mut self, kind: MoveKind, to: P3, line: u32) -> Move {
        let from = self.pos;
        self.off_lathe_plane |= to[1].abs() > EPS || self.abc.iter().any(|a| a.abs() > EPS);
        self.pos = to;
        let feed = if kind == MoveKind::Rapid { 0.0 } else { self.feed_now() };
        Move { kind, phase: Phase::Cut, from, to, arc: None, feed, line }
    }

    /// What a cut tells of a lathe: cut while the program was not known to turn, or off the
    /// ZX plane ([`Recoverer::turns_throughout`]).
    fn lathe_evidence(&mut self, mv: &Move) {
        if mv.kind != MoveKind::Rapid {
            self.cut_any = true;
            self.cut_unturned |= !self.lathe;
            self.off_lathe_plane |= self.plane != Plane::Xz;
        }
    }

    /// Whether a cut on a program that turns is milling: cut in the XY plane, unless it is a
    /// hole cycle's move on the axis of revolution (X0 Y0: `G17 G83 X0 Z-30`, as LinuxCNC
    /// lathe programs switch to G17 for the cycle), which a lathe drills with the part
    /// turning and the drill held in the turret.
    fn mills(&self, mv: &Move) -> bool {
        // A driven tool cutting while the main spindle holds the part mills in any plane.
        (self.plane == Plane::Xy && !(self.in_cycle.is_some() && mv.to[0].abs() < EPS && mv.to[1].abs() < EPS)) || self.driven().is_some()
    }

    fn cut(&mut self, mv: Move, c: &Canon) {
        // A cut after a hole-milling cycle ended, outside its next call, is another operation.
        if self.mill_ended.take().is_some() {
            self.close_keeping_approach();
        }
        self.lathe_evidence(&mv);
        // Comments before a cut are the operation's, not the next tool's.
        self.comments.clear();
        let tool_kind = self.tools.get(&self.tool).map_or(ToolKind::Unknown, |t| t.kind);
        let operation = self.in_cycle.map_or(Operation::FreeformMilling, |k| Operation::from_cycle(k, tool_kind));
        let tech = self.technology();
        let restart = match &self.current {
            None => true,
            Some(b) => {
                let retracted = !self.pending.is_empty();
                let tech_differs = if self.lathe {
                    let per_rev = (self.per_rev && self.sync.is_none()).then_some(self.feed);
                    b.turning.feed_per_rev != per_rev || !same_turning_tech(&b.technology, &tech)
                } else {
                    !same_tech(&b.technology, &tech)
                };
                b.tool != self.tool
                    || !b.operation.same_family(operation)
                    || (retracted && tech_differs)
                    || b.state.work_offset != self.wcs
                    || b.setup != self.setup
                    || (self.lathe && b.turn_seq != self.turn_seq)
                    || (self.lathe && retracted && self.stated.is_some_and(|r| b.turning.stated != Some(r)))
                    || (self.lathe && b.milling != self.mills(&mv))
            }
        };
        if restart {
            self.close_keeping_approach();
            if self.tools.is_empty() && self.tool == 0 && self.listed.len() == 1 {
                self.tool_of_the_list(c);
            }
            if self.tools.is_empty() && self.tool == 0 {
                self.diags.push(Diagnostic::new(
                    Code::NoTool,
                    c.origin,
                    "cutting before any tool change; the workingstep is assigned to tool 0",
                ));
                self.tools.insert(0, Tool::unknown(0));
            }
            let moves: Toolpath = self.pending.drain(..).map(|m| Move { phase: Phase::Approach, ..m }).collect();
            let first_line = moves.first().map_or(c.line, |m| m.line);
            let state = MachineState {
                work_offset: self.wcs,
                stops: std::mem::take(&mut self.pending_stops),
                dwells: std::mem::take(&mut self.pending_dwells),
                ..MachineState::default()
            };
            let mut turning = self.turning_now();
            turning.stated = if self.lathe { self.stated.take() } else { None };
            self.current = Some(Builder {
                operation,
                tool: self.tool,
                technology: tech,
                moves,
                dwell: None,
                peck: None,
                surface: None,
                hole_surfaces: Vec::new(),
                source: c.origin,
                lines: (first_line, c.line),
                tentative: None,
                cut_feed: None,
                state,
                settings: Vec::new(),
                levels: Vec::new(),
                level_entry: None,
                cut_box: None,
                setup: self.setup,
                turn_seq: self.turn_seq,
                turning,
                cut_at: Vec::new(),
                milling: self.mills(&mv),
            });
        }
        // A retract and re-entry with the same tool and plunge feed may still start the next
        // operation (roughing, then finishing at another feed): decided at the first cut.
        // A hole-milling cycle's call that continues the last one's workingstep (the same hole
        // elsewhere) was decided at its start.
        let hole_milled = self.mill_cycle.as_ref().is_some_and(|c| c.1.is_some());
        if !restart
            && !self.pending.is_empty()
            && !operation.is_hole()
            && !hole_milled
            && let Some(b) = self.current.as_mut()
        {
            let lifts = self.pending.iter().take_while(|m| is_lift(m)).count();
            let line = self.pending.first().map_or(c.line, |m| m.line);
            b.tentative = Some(Tentative { at: b.moves.len(), lifts, source: b.source, last_line: b.lines.1, origin: c.origin, line });
        }
        // An entry (plunge, ramp or helix down, at its own feed) is not the cut that decides.
        // On a lathe, any feed cuts, and the feed that decides is the one per revolution.
        let is_cut = mv.kind != MoveKind::Rapid && (self.lathe || mv.to[2] >= mv.from[2] - EPS);
        let decisive_feed = if self.lathe && self.per_rev && self.sync.is_none() { self.feed } else { mv.feed };
        let lathe = self.lathe;
        // A lathe cycle's passes are one workingstep, whatever feeds they cut at (a thread's
        // tapered run-out, a finishing feed of its own).
        let in_cycle = lathe && self.turn.is_some();
        // The first cut after a re-entry decides, and the boundary is gone after it.
        let next = is_cut && !in_cycle && self.next_operation(&mv, decisive_feed);
        let tentative = if is_cut { self.current.as_mut().and_then(|b| b.tentative.take()) } else { None };
        if next && let Some(t) = tentative {
            let now = self.technology();
            self.split(t, c, now);
        }
        let feed = self.feed_now();
        let Some(b) = self.current.as_mut() else { return };
        b.moves.set_axis(self.tool_axis);
        for mut m in self.pending.drain(..) {
            m.phase = Phase::Connect;
            b.moves.push(m);
        }
        if mv.kind != MoveKind::Rapid && !b.technology.feeds.iter().any(|f| (f - feed).abs() < EPS) {
            b.technology.feeds.push(feed);
        }
        // The lead is the first synchronised cut's (a tapered run-out advances more per
        // revolution along its slant).
        if mv.kind != MoveKind::Rapid && self.sync.is_some() && b.turning.pitch.is_none() {
            b.turning.pitch = self.sync.map(round_sig);
        }
        if is_cut {
            b.cut_feed = Some(decisive_feed);
            b.note_feed(lathe, (self.per_rev && self.sync.is_none()).then_some(self.feed), &mv);
            // A feed out of a hole is no level and no region.
            if !is_lift(&mv) {
                b.note_cut(&mv);
            }
        }
        // Offset numbers count where they are not the tool's own (`T4` with `H3`, or `H0`):
        // an implicit length offset (Heidenhain's `TOOL CALL`) is the same as `G43 H4`.
        let own = |n: u32| n != self.tool;
        let h = self.h.filter(|h| own(*h));
        let comp = self.comp.map(|c| CompUse { number: c.number.filter(|n| own(*n)), ..c });
        if mv.kind != MoveKind::Rapid && b.settings.last().is_none_or(|s| (s.1, s.2) != (h, comp)) {
            b.settings.push((b.moves.len(), h, comp));
        }
        if mv.kind != MoveKind::Rapid && self.feed_override_off {
            b.state.feed_override_off = true;
        }
        b.moves.push(mv);
        b.source = b.source.cover(c.origin);
        b.lines.1 = c.line;
        let cycle_surface = if self.in_cycle.is_some() { self.surface } else { None };
        b.take_cycle_values(operation, self.dwell, self.peck, cycle_surface, self.mill_surface);
    }

    /// A milling cycle's markers (`interp::pocket`): each cycle a workingstep of its own, but
    /// a hole-milling cycle making the same hole as the one that just ended continues its
    /// workingstep (the same hole elsewhere, as consecutive drilling cycle calls are); the
    /// surface it states goes to its workingstep.
    fn mill_cycle_marker(&mut self, s: &Setting) {
        match s {
            Setting::HoleMilled(key) => self.hole_next = Some(key.clone()),
            Setting::MillCycle(Some(name)) => {
                let key = self.hole_next.take();
                let again = key.as_ref().is_some_and(|k| self.mill_ended.take().is_some_and(|(n, e)| n == *name && e == *k));
                self.mill_ended = None;
                if !again {
                    self.close();
                }
                self.mill_cycle = Some((name.clone(), key));
            }
            Setting::MillCycle(None) => {
                self.mill_surface = None;
                match self.mill_cycle.take() {
                    // A hole milled: the next call may make the same hole elsewhere.
                    Some((name, Some(key))) => self.mill_ended = Some((name, key)),
                    _ => self.close(),
                }
            }
            Setting::CycleSurface(z) => self.mill_surface = Some(self.mm(*z)),
            _ => {}
        }
    }

    /// Whether a cut after a retract and re-entry (a tentative boundary) starts the tool's next
    /// operation: at another feed; on a mill, a depth sequence begun anew; on a lathe, passes
    /// along -Z after facing passes only (across to the axis, pulled off along +Z: the same
    /// tool faces, then turns), or a pass from the axis after passes that never reached it (the
    /// finishing contour, face first, after the roughing; not a part-off's last peck, across at
    /// the place of the pecks before it).
    fn next_operation(&self, mv: &Move, decisive_feed: f64) -> bool {
        let Some(b) = self.current.as_ref().filter(|b| b.tentative.is_some()) else { return false };
        if b.cut_feed.is_some_and(|f| (f - decisive_feed).abs() > EPS) {
            return true;
        }
        if !self.lathe {
            return !is_lift(mv) && b.starts_anew(mv);
        }
        let turns_after_facing = (mv.to[0] - mv.from[0]).abs() < EPS && mv.to[2] < mv.from[2] - 0.5 && b.faces_only();
        let finish_from_axis = mv.kind != MoveKind::Rapid
            && mv.to[0].min(mv.from[0]) < 0.05
            && b.passes_off_axis()
            && !(b.pecks_at(mv.to[2]) && (mv.to[2] - mv.from[2]).abs() < EPS);
        turns_after_facing || finish_from_axis
    }

    /// Ends the current workingstep at a tentative boundary and starts the next with the
    /// moves after it.
    fn split(&mut self, t: Tentative, c: &Canon, technology: Technology) {
        let Some(mut b) = self.current.take() else { return };
        let mut tail = b.moves.split_off(t.at);
        let rest = tail.split_off(t.lifts.min(tail.len()));
        // What comes after the boundary's lifts goes with the later workingstep.
        let cut = (t.at + t.lifts.min(tail.len())) as u32;
        let later = |v: &mut Vec<u32>| v.iter().position(|at| *at >= cut);
        // The override flag is kept for both pieces: it was off somewhere in what is split.
        let mut state =
            MachineState { work_offset: b.state.work_offset, feed_override_off: b.state.feed_override_off, ..MachineState::default() };
        if let Some(i) = later(&mut b.state.stops.iter().map(|s| s.at).collect()) {
            state.stops = b.state.stops.split_off(i).into_iter().map(|s| Stop { at: s.at - cut, ..s }).collect();
        }
        if let Some(i) = later(&mut b.state.dwells.iter().map(|d| d.at).collect()) {
            state.dwells = b.state.dwells.split_off(i).into_iter().map(|d| Dwell { at: d.at - cut, ..d }).collect();
        }
        let keep = b.settings.iter().position(|s| s.0 >= t.at).unwrap_or(b.settings.len());
        let mut settings: Vec<_> = b.settings.split_off(keep).into_iter().map(|s| (s.0.saturating_sub(cut as usize), s.1, s.2)).collect();
        if settings.first().is_none_or(|s| s.0 > 0)
            && let Some(&(_, h, comp)) = b.settings.last()
        {
            settings.insert(0, (0, h, comp));
        }
        for m in &tail {
            b.moves.push(Move { phase: Phase::Retract, ..m });
        }
        b.source = t.source;
        b.lines.1 = t.last_line;
        let (operation, tool, setup, turn_seq) = (b.operation, b.tool, b.setup, b.turn_seq);
        let mut turning = self.turning_now();
        // The later piece is still the operation its comment named, unless another began.
        turning.stated = self.stated.take().or(b.turning.stated);
        self.finish(b);
        let mut moves = rest;
        for i in 0..moves.len() {
            moves.set_phase(i, Phase::Approach);
        }
        let mut feeds = vec![technology.feed];
        for m in moves.iter().filter(|m| m.kind != MoveKind::Rapid) {
            if !feeds.iter().any(|f| (f - m.feed).abs() < EPS) {
                feeds.push(m.feed);
            }
        }
        let technology =
            Technology { feed: moves.iter().find(|m| m.kind != MoveKind::Rapid).map_or(technology.feed, |m| m.feed), feeds, ..technology };
        self.current = Some(Builder {
            operation,
            tool,
            technology,
            moves,
            dwell: None,
            peck: None,
            surface: None,
            hole_surfaces: Vec::new(),
            source: t.origin.cover(c.origin),
            lines: (t.line, c.line),
            tentative: None,
            cut_feed: None,
            state,
            settings,
            levels: Vec::new(),
            level_entry: None,
            cut_box: None,
            setup,
            turn_seq,
            turning,
            cut_at: Vec::new(),
            milling: self.plane == Plane::Xy || self.driven().is_some(),
        });
    }

    /// Ends the current workingstep; pending rapids that only lift stay with it as retract,
    /// the rest are kept for the next workingstep's approach.
    fn close_keeping_approach(&mut self) {
        let lifts = self.pending.iter().take_while(|m| is_lift(m)).count();
        self.close_with(lifts);
    }

    /// Ends the current workingstep with every pending rapid as its retract.
    fn close(&mut self) {
        self.close_with(self.pending.len());
        self.pending.clear();
    }

    fn close_with(&mut self, retract: usize) {
        let Some(mut b) = self.current.take() else { return };
        for mut m in self.pending.drain(..retract) {
            m.phase = Phase::Retract;
            b.moves.push(m);
        }
        self.finish(b);
    }

    fn finish(&mut self, mut b: Builder) {
        if !self.lathe || b.milling {
            refine_phases(&mut b.moves, b.operation.is_hole());
        }
        // The highest rapid on the way in or between cuts (or feed link between cuts, see
        // `feed_links`); the retract may go home.
        let rapid_z = |phases: &[Phase]| {
            b.moves
                .iter()
                .filter(|m| (m.kind == MoveKind::Rapid || m.phase == Phase::Connect) && phases.contains(&m.phase))
                .map(|m| m.to[2])
                .reduce(f64::max)
        };
        let security_plane = rapid_z(&[Phase::Approach, Phase::Connect])
            .or_else(|| rapid_z(&[Phase::Retract, Phase::Cut]))
            .unwrap_or_else(|| b.moves.iter().flat_map(|m| [m.from[2], m.to[2]]).fold(f64::NEG_INFINITY, f64::max));
        let index = self.done.len() as u32 + 1;
        let mut state = b.state;
        for (i, h, comp) in &b.settings {
            // Only what is in force while the tool feeds counts, not on a lift.
            if b.moves.phase(*i) == Some(Phase::Retract) {
                continue;
            }
            if let Some(h) = h
                && !state.length_offsets.contains(h)
            {
                state.length_offsets.push(*h);
            }
            if let Some(c) = comp
                && !state.cutter_comp.contains(c)
            {
                state.cutter_comp.push(*c);
            }
        }
        if !self.optional.is_empty() {
            let lines: BTreeSet<u32> = b.moves.iter().map(|m| m.line).filter(|l| self.optional.contains(l)).collect();
            state.optional_lines = lines.into_iter().collect();
        }
        // Passes written as moves: the feed the cutting is done at decides, not an approach at
        // a feed of its own (`G1 Z0. F2.` to the face, then `X1. F0.05` across it): the feed
        // per revolution most of the length was cut at, leaving out feeds no turning insert
        // cuts at (over 1.5 mm/rev: a fast feed in to the work, in place of a rapid). A lathe
        // cycle's feed is its own.
        let cutting = |c: &&(Option<f64>, f64, f64)| c.0.is_none_or(|f| f <= MAX_CUTTING_FEED_PER_REV);
        if self.lathe
            && !b.milling
            && b.turning.intent.is_none()
            && b.turning.pitch.is_none()
            && let Some(&(per_rev, feed, _)) = b.cut_at.iter().filter(cutting).max_by(|a, c| a.2.total_cmp(&c.2))
            && per_rev.is_some()
            && per_rev != b.turning.feed_per_rev
        {
            b.turning.feed_per_rev = per_rev;
            b.technology.feed = feed;
        }
        let mut ws = Workingstep::unmeasured(index, b.operation, b.tool, b.technology, security_plane, b.moves, b.source, b.lines);
        ws.state = state;
        ws.setup = b.setup;
        if !b.operation.is_hole() {
            ws.surface = b.surface;
        }
        if self.lathe && !b.milling {
            ws.turning = Some(Box::new(b.turning));
        }
        let surfaces = if b.hole_surfaces.is_empty() { b.surface.map(|z| vec![(0, z)]).unwrap_or_default() } else { b.hole_surfaces };
        measure(&mut ws, b.dwell, b.peck, &surfaces);
        self.done.push(ws);
    }
}

/// Measures a workingstep again after turning recognition joined or mirrored its moves.
fn remeasure(ws: &mut Workingstep) {
    measure(ws, None, None, &[]);
}

/// A rate rounded to 12 significant digits: feeds converted from inches carry no
/// floating-point noise (`9999 × 25.4` is 253974.6), so they survive unit conversions.
pub fn round_sig(v: f64) -> f64 {
    if v.is_finite() { format!("{v:.11e}").parse().unwrap_or(v) } else { v }
}

/// Fills in what a workingstep's toolpath determines: start point, depth, box, cutting
/// length, holes (for hole making, with `dwell` at each bottom, the cycle's `peck` and the
/// surface each cycle call states, `surfaces`: from the move at its index on) and the list of
/// feeds.
pub fn measure(ws: &mut Workingstep, dwell: Option<f64>, peck: Option<f64>, surfaces: &[(usize, f64)]) {
    let mut bbox = None;
    let mut depth: Option<f64> = None;
    let mut cutting_length = 0.0;
    let mut samples = Vec::new();
    for m in ws.toolpath.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid) {
        cutting_length += geom::length(&m);
        samples.clear();
        geom::extend(&mut bbox, m.from);
        geom::extremes(&m, &mut samples);
        for &pt in &samples {
            geom::extend(&mut bbox, pt);
            depth = Some(depth.map_or(pt[2], |d: f64| d.min(pt[2])));
        }
    }
    ws.bbox = bbox;
    ws.depth = depth;
    ws.cutting_length = cutting_length;
    ws.start_point = ws.toolpath.iter().find(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid).map(|m| m.from);
    // A dwell of no time is none (a Fanuc tapping cycle without P, a rigid tap), and so is
    // one under half a millisecond, the step controls state dwells in (Haas `P.01` read as
    // 0.01 ms is written `P0`).
    let dwell = dwell.filter(|d| *d >= 5e-4);
    ws.holes = if ws.operation.is_hole() { holes(&ws.toolpath, dwell, peck, surfaces, &ws.state.optional_lines) } else { Vec::new() };
    let mut feeds = vec![ws.technology.feed];
    for m in ws.toolpath.iter().filter(|m| m.kind != MoveKind::Rapid) {
        if !feeds.iter().any(|f| (f - m.feed).abs() < EPS) {
            feeds.push(m.feed);
        }
    }
    ws.technology.feeds = feeds;
}

fn same_tech(a: &Technology, b: &Technology) -> bool {
    (a.feed - b.feed).abs() < EPS
        && (a.spindle_speed - b.spindle_speed).abs() < EPS
        && a.surface_speed == b.surface_speed
        && a.spindle == b.spindle
        && a.coolant == b.coolant
}

/// The same technology on a lathe: the cutting speed, the spindle and the coolant; the feed
/// per minute follows the diameter and the clamp, and the spindle speed under constant
/// cutting speed is the clamp, which is the workingstep's setting, not a new operation.
fn same_turning_tech(a: &Technology, b: &Technology) -> bool {
    a.surface_speed == b.surface_speed
        && (a.surface_speed.is_some() || (a.spindle_speed - b.spindle_speed).abs() < EPS)
        && a.spindle == b.spindle
        && a.coolant == b.coolant
}

fn is_lift(m: &Move) -> bool {
    (m.to[0] - m.from[0]).abs() < EPS && (m.to[1] - m.from[1]).abs() < EPS && m.to[2] >= m.from[2]
}

fn is_plunge(m: &Move) -> bool {
    (m.to[0] - m.from[0]).abs() < EPS && (m.to[1] - m.from[1]).abs() < EPS && m.to[2] < m.from[2]
}

/// Leading entries (plunges, ramps, helices down) join the approach; trailing lifts join
/// the retract.
fn refine_phases(moves: &mut Toolpath, hole: bool) {
    // In hole making every feed makes the hole, the first plunge too (as a cycle's moves
    // after its own positioning rapid, so that a cycle that does not position is the same).
    // In milling, the feeds down before the first cut at depth bring the tool to it: they are
    // its approach. Feeds down that the tool leaves by going up or by a rapid (a router
    // plunging holes with an end mill) are cuts themselves.
    let first_cut = moves.iter().position(|m| m.phase == Phase::Cut).filter(|_| !hole);
    if let Some(first) = first_cut {
        let plunging = |m: &Move| m.phase == Phase::Cut && m.kind != MoveKind::Rapid && m.to[2] < m.from[2] - EPS;
        let end = (first..moves.len()).find(|&i| !moves.get(i).is_some_and(|m| plunging(&m))).unwrap_or(moves.len());
        // An arc at depth cuts, a full circle too (its end is its start).
        let cuts_at_depth = moves.get(end).is_some_and(|m| m.kind == MoveKind::Arc || m.kind == MoveKind::Line && !is_lift(&m));
        if cuts_at_depth {
            for i in first..end {
                moves.set_phase(i, Phase::Approach);
            }
        }
    }
    feed_links(moves);
    for i in (0..moves.len()).rev() {
        match moves.get(i) {
            Some(m) if m.phase == Phase::Retract || (m.phase == Phase::Cut && is_lift(&m)) => moves.set_phase(i, Phase::Retract),
            _ => break,
        }
    }
    // A workingstep that only plunges keeps its last plunge as its cut.
    if !moves.iter().any(|m| m.phase == Phase::Cut)
        && let Some(i) = (0..moves.len()).rev().find(|&i| moves.get(i).is_some_and(|m| m.kind != MoveKind::Rapid))
    {
        moves.set_phase(i, Phase::Cut);
    }
}

/// Feeds that link cuts above the material, as posts write them that never use a rapid
/// (`G1 Z2.` `X26.` `G1 Z-1.5`): a lift straight up, clear of every level cut so far and of
/// the program zero, moves across at that height and a feed back down. They connect the cuts;
/// the tool is out of the material. One pass over the toolpath.
fn feed_links(moves: &mut Toolpath) {
    let is_cut = |m: &Move| m.phase == Phase::Cut && m.kind != MoveKind::Rapid;
    let flat = |m: &Move, z: f64| (m.from[2] - z).abs() < 1e-4 && (m.to[2] - z).abs() < 1e-4;
    let mut highest: Option<f64> = None;
    let mut i = 0;
    while let Some(m) = moves.get(i) {
        let z = m.to[2];
        let clear = highest.is_some_and(|h| z > h.max(0.0) + EPS);
        if is_cut(&m) && m.kind == MoveKind::Line && is_lift(&m) && z > m.from[2] + EPS && clear {
            let mut j = i + 1;
            while moves.get(j).is_some_and(|n| is_cut(&n) && n.kind == MoveKind::Line && flat(&n, z)) {
                j += 1;
            }
            if moves.get(j).is_some_and(|n| n.kind != MoveKind::Rapid && n.to[2] < n.from[2] - EPS) {
                for k in i..j {
                    moves.set_phase(k, Phase::Connect);
                }
            }
            i = j;
            continue;
        }
        if is_cut(&m) && flat(&m, z) {
            highest = Some(highest.map_or(z, |h| h.max(z)));
        }
        i += 1;
    }
}

/// Hole positions: the bottom of each feed-in within a cycle, with the height the tool
/// lifts to before it leaves the hole. A hole fed by an optional block is optional.
fn holes(moves: &Toolpath, dwell: Option<f64>, peck: Option<f64>, surfaces: &[(usize, f64)], optional: &[u32]) -> Vec<Hole> {
    let mut out: Vec<Hole> = Vec::new();
    let mut open = false;
    // The surface stated by the cycle call the move belongs to (the first one's before it);
    // the calls are in the order of their moves.
    let surface_at = |i: usize| {
        let k = surfaces.partition_point(|s| s.0 <= i);
        k.checked_sub(1).and_then(|k| surfaces.get(k)).or(surfaces.first()).map(|s| s.1)
    };
    for (i, m) in moves.iter().enumerate() {
        let m = &m;
        if !(m.kind == MoveKind::Line && is_plunge(m)) {
            if open && is_lift(m) {
                if let Some(h) = out.last_mut() {
                    h.retract = Some(h.retract.map_or(m.to[2], |r| r.max(m.to[2])));
                }
            } else if open && !is_plunge(m) {
                open = false;
            }
            continue;
        }
        let optional = optional.binary_search(&m.line).is_ok();
        match out.last_mut() {
            Some(h) if open && (h.x - m.to[0]).abs() < EPS && (h.y - m.to[1]).abs() < EPS => {
                h.optional |= optional;
                if m.to[2] < h.bottom {
                    h.bottom = m.to[2];
                    // The cycle's peck when it states one; the longest feed-in otherwise.
                    let step = m.from[2] - m.to[2];
                    h.peck = Some(peck.unwrap_or_else(|| h.peck.map_or(step, |p| p.max(step))));
                }
            }
            _ => {
                let top = surface_at(i).filter(|z| *z > m.to[2]);
                out.push(Hole {
                    x: m.to[0],
                    y: m.to[1],
                    bottom: m.to[2],
                    r_plane: m.from[2],
                    top,
                    peck: None,
                    dwell,
                    retract: None,
                    optional,
                });
                open = true;
            }
        }
    }
    out
}

/// Where a stock origin comment puts the stock: a point and which corner (or centre) of the
/// stock it is, per axis: -1 the low side (LEFT, LOWER/FRONT, BOTTOM), 0 the centre, 1 the
/// high side (RIGHT, UPPER/BACK, TOP).
#[derive(Clone, Copy, Debug, PartialEq)]
struct StockOrigin {
    point: P3,
    corner: [i8; 3],
}

impl StockOrigin {
    /// `STOCK ORIGIN: X0. Y0. Z1. - LOWER LEFT TOP`; without corner words the lower left of
    /// the top, where posts put the work zero.
    fn parse(comment: &str) -> Option<StockOrigin> {
        let up = comment.to_ascii_uppercase();
        let rest = &up[up.find("STOCK ORIGIN")? + 12..];
        let mut point = [0.0; 3];
        let mut seen = 0;
        for (k, axis) in ['X', 'Y', 'Z'].into_iter().enumerate() {
            let at = rest.find(axis)?;
            let tail = &rest[at + 1..];
            let end = tail.find(|c: char| !(c.is_ascii_digit() || matches!(c, '.' | '-' | '+'))).unwrap_or(tail.len());
            point[k] = tail[..end].parse().ok()?;
            seen += 1;
        }
        let has = |w: &str| rest.split(|c: char| !c.is_ascii_alphabetic()).any(|x| x == w);
        let pick = |low: &[&str], high: &[&str], default: i8| {
            if low.iter().any(|w| has(w)) {
                -1
            } else if high.iter().any(|w| has(w)) {
                1
            } else if has("CENTER") || has("CENTRE") || has("MIDDLE") {
                0
            } else {
                default
            }
        };
        let corner = [pick(&["LEFT"], &["RIGHT"], -1), pick(&["LOWER", "FRONT"], &["UPPER", "BACK"], -1), pick(&["BOTTOM"], &["TOP"], 1)];
        (seen == 3).then_some(StockOrigin { point, corner })
    }

    /// The stock of `s`'s size with this origin.
    fn place(self, s: [P3; 2]) -> [P3; 2] {
        let mut out = s;
        for k in 0..3 {
            let size = s[1][k] - s[0][k];
            let min = self.point[k] - size * (f64::from(self.corner[k]) + 1.0) / 2.0;
            out[0][k] = min;
            out[1][k] = min + size;
        }
        out
    }
}

/// Roughing or finishing as an operation's comment states it, as CAM posts name operations
/// (NX `ROUGH_BORE_ID`, `FINISH_TURN_OD`) and turners head them (`(ROUGHING)`, `(Finish 1)`,
/// German `Schruppen`/`Schlichten`, Spanish `desbaste`/`acabado`); none where it says both or
/// neither.
fn stated_roughness(comment: &str) -> Option<bool> {
    let up = comment.to_ascii_uppercase();
    let words: Vec<&str> = up.split(|c: char| !c.is_ascii_alphanumeric()).filter(|w| !w.is_empty()).collect();
    let rough = words.iter().any(|w| ["ROUGH", "SCHRUPP", "DESBAST"].iter().any(|p| w.starts_with(p)));
    let finish = words.iter().any(|w| ["FINISH", "SCHLICHT", "ACABAD"].iter().any(|p| w.starts_with(p)));
    match (rough, finish) {
        (true, false) => Some(true),
        (false, true) => Some(false),
        _ => None,
    }
}

/// A CAM stock comment: `STOCK X0 Y0 Z-20 X100 Y50 Z0` (two corners), `STOCK 100 X 50 X 20`
/// or `STOCK SIZE X100 Y50 Z20` (sizes, top at Z0, corner at X0 Y0). Program units.
pub fn parse_stock(comment: &str) -> Option<[P3; 2]> {
    let up = comment.to_ascii_uppercase();
    let rest = &up[up.find("STOCK").or_else(|| up.find("BLANK"))? + 5..];
    let mut letters = Vec::new();
    let mut numbers = Vec::new();
    let bytes = rest.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        let c = bytes[i];
        if c.is_ascii_digit() || c == b'-' || c == b'+' || c == b'.' {
            let start = i;
            i += 1;
            while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
                i += 1;
            }
            let v: f64 = rest[start..i].parse().ok()?;
            let letter = if start > 0 && matches!(bytes[start - 1], b'X' | b'Y' | b'Z') { Some(bytes[start - 1]) } else { None };
            letters.push(letter);
            numbers.push(v);
        } else {
            i += 1;
        }
    }
    let axis = |l: Option<u8>| l.map(|l| usize::from(l - b'X'));
    // MeshCAM's `(STOCK/BLOCK, w, l, h, x, y, z)`: the size, then where the program's zero
    // lies from the stock's lowest corner (`0, 0, h`: the top of the lower left corner).
    if up.contains("STOCK/BLOCK") && numbers.len() == 6 && letters.iter().all(Option::is_none) {
        let (size, zero) = ([numbers[0], numbers[1], numbers[2]], [numbers[3], numbers[4], numbers[5]]);
        return size
            .iter()
            .all(|s| *s > 0.0)
            .then(|| [[-zero[0], -zero[1], -zero[2]], [size[0] - zero[0], size[1] - zero[1], size[2] - zero[2]]]);
    }
    match numbers.len() {
        6 if letters.iter().all(Option::is_some) => {
            let mut min = [f64::INFINITY; 3];
            let mut max = [f64::NEG_INFINITY; 3];
            for (l, v) in letters.iter().zip(&numbers) {
                let a = axis(*l)?;
                min[a] = min[a].min(*v);
                max[a] = max[a].max(*v);
            }
            (min.iter().zip(&max).all(|(a, b)| a < b)).then_some([min, max])
        }
        3 if numbers.iter().all(|v| *v > 0.0) => {
            let mut size = [numbers[0], numbers[1], numbers[2]];
            if letters.iter().all(Option::is_some) {
                for (l, v) in letters.iter().zip(&numbers) {
                    size[axis(*l)?] = *v;
                }
            }
            Some([[0.0, 0.0, -size[2]], [size[0], size[1], 0.0]])
        }
        _ => None,
    }
}

#[cfg(test)]
mod tests {
    use super::{names_probe, parse_stock, parse_tool_comment, point_angle};
    use crate::plan::ToolKind;

    #[test]
    fn meshcam_stock_blocks() {
        assert_eq!(parse_stock("STOCK/BLOCK, 9.250, 4.750, 0.190, -0.000, -0.000, 0.190"), Some([[0.0, 0.0, -0.19], [9.25, 4.75, 0.0]]));
        assert_eq!(parse_stock("STOCK/BLOCK, 100, 60, 20, 50, 30, 20"), Some([[-50.0, -30.0, -20.0], [50.0, 30.0, 0.0]]));
    }

    #[test]
    fn point_angles_before_a_unit_in_any_encoding() {
        assert_eq!(point_angle("DRILL 118DEG"), Some(118.0));
        assert_eq!(point_angle("BOHRER 140 GRAD"), Some(140.0));
        assert_eq!(point_angle("SPOT 90°"), Some(90.0));
        assert_eq!(point_angle("#3 6.8MM DRILL 140 POINT ANGLE"), Some(140.0));
    }

    #[test]
    fn tool_comment_units() {
        let f = |s: &str| {
            let f = parse_tool_comment(s);
            (f.diameter, f.unit_mm)
        };
        assert_eq!(f("T1 D=0.25 CR=0. - FLAT END MILL"), (Some(0.25), None));
        assert_eq!(f("T2 D=1/4 DRILL"), (Some(0.25), Some(25.4)));
        assert_eq!(f("T07 = 1/4\" DRILL, 140 POINT ANGLE"), (Some(0.25), Some(25.4)));
        assert_eq!(f("5/16 SPOT DRILL"), (Some(0.3125), Some(25.4)));
        assert_eq!(f("6MM FLAT END MILL"), (Some(6.0), Some(1.0)));
        assert_eq!(f("DIA 0.5 IN BALL"), (Some(0.5), Some(25.4)));
        assert_eq!(f("DATE 12/03/2026 T1 D=10"), (Some(10.0), None));
        // Latin-1 read as UTF-8 puts a two-byte letter right before the unit.
        assert_eq!(point_angle("STEPPER\u{201a} TO THE 45\u{c2}°"), None);
        assert_eq!(point_angle("CHAMFER \u{c2}°"), None);
    }

    #[test]
    fn tool_comments() {
        let d = |s: &str| parse_tool_comment(s).diameter;
        assert_eq!(d("T1 D=18 ENDMILL"), Some(18.0));
        assert_eq!(d("6MM FLAT END MILL"), Some(6.0));
        assert_eq!(d("T3 DIA 10.5 DRILL"), Some(10.5));
        assert_eq!(d("DRILL D8"), Some(8.0));
        assert_eq!(d("ROUGHING"), None);
        let f = parse_tool_comment("T4 10MM 4FL BULL NOSE R0.5");
        assert_eq!((f.diameter, f.kind, f.corner_radius, f.flutes), (Some(10.0), Some(ToolKind::BullnoseEndMill), Some(0.5), Some(4)));
        assert_eq!(parse_tool_comment("T1 D=18 ENDMILL").kind, Some(ToolKind::EndMill));
        assert_eq!(parse_tool_comment("5/16 SPOT DRILL").kind, Some(ToolKind::CenterDrill));
        assert_eq!(parse_tool_comment("M8X1.25 TAP").kind, Some(ToolKind::Tap));
        assert_eq!(parse_tool_comment("8H7 REAMER Z6").kind, Some(ToolKind::Reamer));
        assert_eq!(parse_tool_comment("8H7 REAMER Z6").flutes, Some(6));
        assert_eq!(parse_tool_comment("3 FLUTE END MILL").flutes, Some(3));
        assert_eq!(parse_tool_comment("FACE MILL D63").kind, Some(ToolKind::FaceMill));
        // Post spellings: underscores and dashes join the words.
        let f = |s: &str| {
            let f = parse_tool_comment(s);
            (f.kind, f.diameter)
        };
        assert_eq!(f("SPIRAL_DRILL_20MM"), (Some(ToolKind::TwistDrill), Some(20.0)));
        assert_eq!(f("DRILL-D8.5"), (Some(ToolKind::TwistDrill), Some(8.5)));
        assert_eq!(f("REAMER_22MM"), (Some(ToolKind::Reamer), Some(22.0)));
        assert_eq!(f("T3 D=10. CR=0. - FLAT END MILL"), (Some(ToolKind::EndMill), Some(10.0)));
        assert_eq!(parse_tool_comment("D=10. CR=0.").corner_radius, Some(0.0));
        assert_eq!(f("EM10"), (Some(ToolKind::EndMill), Some(10.0)));
        assert_eq!(f("T=\"EM10\""), (Some(ToolKind::EndMill), Some(10.0)));
        // Drills named in Turkish and Russian shops: the size after çap (diameter), or after
        // the drill's word.
        assert_eq!(f("CAP11.5D.MATKAP"), (Some(ToolKind::TwistDrill), Some(11.5)));
        assert_eq!(f("CAP9.MATKAP"), (Some(ToolKind::TwistDrill), Some(9.0)));
        assert_eq!(f("CAP21.UDRIL").1, Some(21.0));
        assert_eq!(f("SVERLO 1.5"), (Some(ToolKind::TwistDrill), Some(1.5)));
        assert_eq!(f("END CAP SCREW").1, None);
        assert_eq!(f("ESCAPE 5").1, None);
        // Mastercam's tool list: the number before the kind; `D1` there is the offset.
        assert_eq!(f("T1 | 10. FLAT ENDMILL | H1 | D1"), (Some(ToolKind::EndMill), Some(10.0)));
    }

    #[test]
    fn apt_tool_statements() {
        let f = |s: &str| {
            let f = parse_tool_comment(s);
            (f.kind, f.diameter, f.corner_radius)
        };
        assert_eq!(f("TLDATA/MILL,10.0000,0.0000,75.0000,0.0000,0.0000"), (Some(ToolKind::EndMill), Some(10.0), Some(0.0)));
        assert_eq!(f("TLDATA/MILL,0.7500,0.1200,4.0000,0.0000,0.0000"), (Some(ToolKind::BullnoseEndMill), Some(0.75), Some(0.12)));
        assert_eq!(f("TLDATA/DRILL,MILL,6.8,0,80,118,40"), (Some(ToolKind::TwistDrill), Some(6.8), Some(0.0)));
        assert_eq!(f("CUTTER/ 12.0, 6.0, 0, 6.0, 0, 0, 50"), (Some(ToolKind::BallEndMill), Some(12.0), Some(6.0)));
        assert_eq!(f("CUTTER/2.4,0,1.2,.721033,31.,0,60."), (Some(ToolKind::TwistDrill), Some(2.4), Some(0.0)));
        assert_eq!(
            f("CUTTER/ 6.000000,0.000000,3.000000,1.802582,31.000000,0.000000,102.000000,"),
            (Some(ToolKind::TwistDrill), Some(6.0), Some(0.0))
        );
        assert_eq!(f("CUTTER/50.,0,25.,0,0,0,40."), (None, Some(50.0), Some(0.0)));
        assert_eq!(f("CUTTER/10"), (None, Some(10.0), None));
        // MeshCAM names its cutter the NX way in its header.
        assert_eq!(f("TOOL/MILL,0.1060,0.0000,1.0000,0.0"), (Some(ToolKind::EndMill), Some(0.106), Some(0.0)));
        assert_eq!(f("TOOL/MILL,0.2500,0.1250,1.0000,0.0"), (Some(ToolKind::BallEndMill), Some(0.25), Some(0.125)));
        assert_eq!(f("TOOL PATH/POCKET,TOOL,EM10"), (Some(ToolKind::EndMill), Some(10.0), None));
    }

    #[test]
    fn tools_a_comment_names() {
        for (s, n) in
            [("T1 | 10. FLAT ENDMILL", Some(1)), ("TOOL 4 - D10", Some(4)), ("TOOL: 12 DRILL", Some(12)), ("LOAD/TOOL,3", Some(3))]
        {
            assert_eq!(super::listed_tool(s), n, "{s}");
        }
        for s in ["TOOL PATH/POCKET_4,TOOL,ENDMILL_D10", "TAP M8", "TOOLS", "T12X"] {
            assert_eq!(super::listed_tool(s), None, "{s}");
        }
    }

    #[test]
    fn stock_origin_comments() {
        let o = super::StockOrigin::parse("STOCK ORIGIN: X0. Y0. Z1. - LOWER LEFT TOP").unwrap();
        assert_eq!(o.place([[0.0, 0.0, -31.0], [120.0, 70.0, 0.0]]), [[0.0, 0.0, -30.0], [120.0, 70.0, 1.0]]);
        let c = super::StockOrigin::parse("stock origin X0 Y0 Z0 center top").unwrap();
        assert_eq!(c.place([[0.0, 0.0, -20.0], [100.0, 50.0, 0.0]]), [[-50.0, -25.0, -20.0], [50.0, 25.0, 0.0]]);
        assert!(super::StockOrigin::parse("STOCK: X100. Y60. Z20.").is_none());
    }

    #[test]
    fn stock_comments() {
        assert_eq!(parse_stock("STOCK X0 Y0 Z-20 X100 Y50 Z0"), Some([[0.0, 0.0, -20.0], [100.0, 50.0, 0.0]]));
        assert_eq!(parse_stock("Stock size: 100 x 50 x 20"), Some([[0.0, 0.0, -20.0], [100.0, 50.0, 0.0]]));
        assert_eq!(parse_stock("T1 D=18 ENDMILL"), None);
    }

    #[test]
    fn a_probe_by_its_name() {
        for n in ["T99  D=0.1181 CR=0.0591 - ZMIN=0. - probe", "3D-Taster", "Messtaster TS640", "TOUCH PROBE", "RENISHAW OMP40"] {
            assert!(names_probe(n), "{n}");
        }
        for n in ["T1 D=10 ENDMILL", "PROBED DEPTH 5", "UNPROBED", "T3 DRILL 6.8"] {
            assert!(!names_probe(n), "{n}");
        }
    }
}

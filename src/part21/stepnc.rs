//! Process plans as ISO 14649 STEP-NC Part 21 files, and back.
//!
//! - **CC1** (explicit toolpaths): every milling workingstep is a TOOLPATH_FEATURE machined by a
//!   FREEFORM_OPERATION whose TOOLPATH_LIST holds CUTTER_LOCATION_TRAJECTORYs over POLYLINEs
//!   and TRIMMED_CURVEs of CIRCLEs.
//! - **CC2** (features): workingsteps machine PLANAR_FACE, ROUND_HOLE (a GENERAL_PATTERN for
//!   several positions), CLOSED_POCKET, OPEN_POCKET, SLOT, STEP, GENERAL_OUTSIDE_PROFILE or
//!   TOOLPATH_FEATURE with the ISO 14649-11 operation and strategy; the explicit toolpath
//!   rides along in each operation's `its_toolpath`.
//! - **Turning** (both classes; `turning`): ISO 14649-121 operations, technology, machine
//!   functions and tools, and in CC2 the ISO 14649-12 turned features; a turning workingstep
//!   machining several features is a TURNING_WORKINGSTEP.
//!
//! Units follow the standard: mm, seconds, degrees, feeds in m/s, spindle speeds in rev/s
//! with a negative value for clockwise (M3). What ISO 14649 has no attribute for (source
//! lines and bytes, where a tool fact came from, a step's width) is written as `key=value`
//! words in the `its_id` strings, so that [`read`] gives back the plan [`write`] was given.

use std::collections::BTreeMap;

use super::{Exchange, Header, Instance, Stream, Value};
use crate::canon::Units;
use crate::diag::{Code, Diagnostic};
use crate::plan::{self, geom, *};
use crate::text::TextRange;

mod turning;

/// Conformance class.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Class {
    /// Explicit toolpaths.
    Cc1,
    /// Features and operations.
    Cc2,
}

const RAPID: &str = "RAPID";

/// Writes `plan` as a Part 21 exchange with the given header timestamp into `out`, as it
/// goes: memory stays that of the plan, whatever the toolpaths' length. Returns findings
/// (stock or diameters unknown), or the first write error.
pub fn write<W: std::io::Write>(plan: &ProcessPlan, class: Class, timestamp: &str, out: W) -> std::io::Result<(W, Vec<Diagnostic>)> {
    // CC1 keeps toolpaths only: a view of the plan without its moves, which are read from `plan`.
    let view;
    let shape = if class == Class::Cc1 {
        view = toolpaths_only_skeleton(plan);
        &view
    } else {
        plan
    };
    let header = Header {
        description: vec![match class {
            Class::Cc1 => "ncplan process plan, ISO 14649 conformance class 1 (explicit toolpaths)".into(),
            Class::Cc2 => "ncplan process plan, ISO 14649 conformance class 2 (features)".into(),
        }],
        name: plan.program.clone().unwrap_or_default(),
        timestamp: timestamp.to_owned(),
        system: concat!("ncplan ", env!("CARGO_PKG_VERSION")).into(),
        schemas: vec!["MACHINING_SCHEMA".into(), "MILLING_SCHEMA".into()],
    };
    let mut w = Writer {
        b: Stream::new(out, &header),
        tech: BTreeMap::new(),
        functions: BTreeMap::new(),
        tools: BTreeMap::new(),
        turning_tech: BTreeMap::new(),
        lathe_tools: turning::lathe_tools(plan),
        diags: Vec::new(),
    };
    let rawpiece = match &shape.workpiece {
        Some(s) => {
            let pos = w.placement(s.origin, None);
            let source = match (s.source, s.line) {
                (StockSource::Config, _) => "stock from config".to_owned(),
                (StockSource::Program, Some(l)) => format!("stock from program line {l}"),
                (StockSource::Program, None) => "stock from program".to_owned(),
            };
            let block =
                w.b.add("BLOCK", vec![Value::str(source), pos, Value::Real(s.size[0]), Value::Real(s.size[1]), Value::Real(s.size[2])]);
            Some(w.b.add(
                "WORKPIECE",
                vec![Value::str("rawpiece"), Value::Null, Value::Null, Value::Null, Value::Null, block, Value::List(vec![])],
            ))
        }
        None => {
            w.diags.push(Diagnostic::new(
                Code::StockUnknown,
                TextRange::default(),
                "the stock is not known (no [stock] in config, no stock comment in the program); the workpiece has no rawpiece block",
            ));
            None
        }
    };
    let workpiece = w.b.add(
        "WORKPIECE",
        vec![
            Value::str("workpiece"),
            Value::Null,
            Value::Null,
            rawpiece.unwrap_or(Value::Null),
            Value::Null,
            Value::Null,
            Value::List(vec![]),
        ],
    );
    // Operations first (features list them), then features, then workingsteps.
    let ops: Vec<Value> =
        shape.workingsteps.iter().zip(&plan.workingsteps).map(|(ws, moves)| w.operation(shape, ws, &moves.toolpath, class)).collect();
    let mut features: BTreeMap<u32, Value> = BTreeMap::new();
    for f in &shape.features {
        let f_ops: Vec<Value> = f.workingsteps.iter().filter_map(|i| ops.get(*i as usize - 1).cloned()).collect();
        let v = w.feature(f, &workpiece, f_ops);
        features.insert(f.id, v);
    }
    let mut elements = Vec::new();
    let mut loaded: Option<u32> = None;
    for (ws, op) in shape.workingsteps.iter().zip(&ops) {
        if loaded != Some(ws.tool) {
            let tool = w.tool(shape, ws.tool);
            elements.push(w.b.add("LOAD_TOOL", vec![Value::str(format!("load T{}", ws.tool)), tool]));
            loaded = Some(ws.tool);
        }
        let sec = w.security_plane(ws);
        let feature = ws.feature.and_then(|f| features.get(&f).cloned()).unwrap_or(Value::Null);
        let id = workingstep_id(shape, ws);
        let all = turning::features_of(shape, ws, &features);
        if iso_turning(ws).is_some() && all.len() > 1 {
            elements.push(w.b.add("TURNING_WORKINGSTEP", vec![Value::str(id), sec, Value::List(all), op.clone(), Value::Null]));
        } else {
            elements.push(w.b.add("MACHINING_WORKINGSTEP", vec![Value::str(id), sec, feature, op.clone(), Value::Null]));
        }
    }
    // Tools that never cut still appear, loaded at the end.
    for t in &shape.tools {
        if !shape.workingsteps.iter().any(|ws| ws.tool == t.number) {
            let tool = w.tool(shape, t.number);
            elements.push(w.b.add("LOAD_TOOL", vec![Value::str(format!("load T{}", t.number)), tool]));
        }
    }
    let origin = w.placement([0.0; 3], None);
    let top = shape.workingsteps.iter().map(|ws| ws.security_plane).fold(0.0, f64::max);
    let setup_sec = w.plane("setup security plane", [0.0, 0.0, top]);
    let wp_origin = w.placement([0.0; 3], None);
    let wp_setup = w.b.add("WORKPIECE_SETUP", vec![workpiece.clone(), wp_origin, Value::Null, Value::Null, Value::List(vec![])]);
    let setup = w.b.add("SETUP", vec![Value::str("setup"), origin, setup_sec, Value::List(vec![wp_setup])]);
    let units = match shape.units {
        Some(Units::Mm) => " units=mm",
        Some(Units::Inch) => " units=inch",
        None => "",
    };
    let workplan =
        w.b.add("WORKPLAN", vec![Value::str(format!("main workplan{units}")), Value::List(elements), Value::Null, setup, Value::Null]);
    // The root comes last: everything it refers to is written by then.
    w.b.add(
        "PROJECT",
        vec![
            Value::str(shape.program.clone().unwrap_or_default()),
            workplan,
            Value::List(vec![workpiece]),
            Value::Null,
            Value::Null,
            Value::Null,
        ],
    );
    let diags = w.diags;
    Ok((w.b.finish()?, diags))
}

/// [`write`] into a string, for tests and small plans.
pub fn to_string(plan: &ProcessPlan, class: Class, timestamp: &str) -> (String, Vec<Diagnostic>) {
    let (bytes, diags) = write(plan, class, timestamp, Vec::new()).expect("writing into memory does not fail");
    (String::from_utf8(bytes).expect("Part 21 text is UTF-8"), diags)
}

/// The plan as CC1 keeps it: every workingstep a freeform operation on its own toolpath
/// feature, without features, strategies or hole data.
pub fn toolpaths_only(plan: &ProcessPlan) -> ProcessPlan {
    let mut p = toolpaths_only_skeleton(plan);
    for (ws, full) in p.workingsteps.iter_mut().zip(&plan.workingsteps) {
        ws.toolpath = full.toolpath.clone();
    }
    p
}

/// [`toolpaths_only`] without the moves, which a large plan should not copy.
fn toolpaths_only_skeleton(plan: &ProcessPlan) -> ProcessPlan {
    let ProcessPlan { program, units, tools, workingsteps, features: _, workpiece } = plan;
    let mut p = ProcessPlan {
        program: program.clone(),
        units: *units,
        tools: tools.clone(),
        workingsteps: Vec::with_capacity(workingsteps.len()),
        features: Vec::new(),
        workpiece: workpiece.clone(),
    };
    for full in workingsteps {
        let Workingstep {
            index,
            operation: _,
            tool,
            technology,
            start_point,
            depth,
            security_plane,
            feature: _,
            strategy: _,
            axial_depth: _,
            radial_depth: _,
            allowance_side: _,
            allowance_bottom: _,
            bbox,
            cutting_length,
            holes: _,
            toolpath: _,
            state,
            setup,
            turning,
            // The surface a milling cycle stated placed its feature; CC1 keeps no feature.
            surface: _,
            source,
            lines,
        } = full;
        let mut ws = Workingstep::unmeasured(
            *index,
            Operation::FreeformMilling,
            *tool,
            technology.clone(),
            *security_plane,
            Toolpath::new(),
            *source,
            *lines,
        );
        ws.start_point = *start_point;
        ws.depth = *depth;
        ws.bbox = *bbox;
        ws.cutting_length = *cutting_length;
        ws.state = state.clone();
        ws.setup = *setup;
        // A turning workingstep keeps what it turns: its operation's explicit strategy is
        // ISO 14649-121's, not a milling one.
        ws.turning = turning.clone();
        ws.strategy = if turning.is_some() { None } else { Some(explicit()) };
        ws.feature = Some(ws.index);
        p.features.push(Feature {
            id: ws.index,
            kind: FeatureKind::Toolpath,
            placement: [0.0; 3],
            depth: 0.0,
            top_inferred: false,
            workingsteps: vec![ws.index],
            source: ws.source,
            lines: ws.lines,
            sources: Sources::default(),
            centre_path: None,
            axis: None,
            ref_direction: None,
            wrap: None,
        });
        p.workingsteps.push(ws);
    }
    p
}

/// A workingstep's identifier: its number, lines and bytes, its plane, its machine state and
/// what the ISO entities do not carry of its turning.
fn workingstep_id(shape: &ProcessPlan, ws: &Workingstep) -> String {
    let mut id = format!("WS{} lines={}-{} bytes={}-{}", ws.index, ws.lines.0, ws.lines.1, ws.source.start, ws.source.end);
    if let Some(s) = &ws.setup {
        // The plane's origin and the security plane's height over it, which the placement in
        // the part's frame says only to rounding.
        id.push_str(&format!(" plane_origin={},{},{} plane_z={}", s.origin[0], s.origin[1], s.origin[2], ws.security_plane));
        // The plane as a cylinder's developed surface (cylindrical interpolation): no ISO
        // 14649 entity carries it, so its word does.
        if let Some(d) = s.cylinder {
            id.push_str(&format!(" plane_cylinder={d}"));
        }
    }
    for word in ws.state.encode() {
        id.push(' ');
        id.push_str(&word);
    }
    // What the ISO 14649-121 entities do not carry: the cycle, its words, what was cut.
    if let Some(t) = iso_turning(ws) {
        id.push_str(&format!(" turning={}", turning::rest_word(t)));
    } else if let Some(t) = &ws.turning {
        id.push_str(&format!(" turning={}", json_word(&**t)));
    }
    if ws.turning.is_some() && iso_turning(ws).is_none() {
        // A turning workingstep machines several features: the others than its own.
        let more: Vec<String> = shape
            .features
            .iter()
            .filter(|f| Some(f.id) != ws.feature && f.workingsteps.contains(&ws.index))
            .map(|f| f.id.to_string())
            .collect();
        if !more.is_empty() {
            id.push_str(&format!(" features={}", more.join(",")));
        }
    }
    id
}

/// A turning workingstep whose operation is written as its ISO 14649-121 entity (in CC1
/// too: a turning operation's toolpath is explicit by its strategy).
fn iso_turning(ws: &Workingstep) -> Option<&Turning> {
    ws.turning.as_deref().filter(|t| t.operation.is_some())
}

fn explicit() -> Strategy {
    Strategy { kind: StrategyKind::Explicit, feed_direction: None, rotation: None, cutmode: None, overlap: None }
}

struct Writer<W: std::io::Write> {
    b: Stream<W>,
    tech: BTreeMap<(u64, u64, u8), Value>,
    functions: BTreeMap<u8, Value>,
    tools: BTreeMap<u32, Value>,
    turning_tech: BTreeMap<String, Value>,
    /// The tools written as ISO 14649-121 tools, with the lead of the threads each cuts.
    lathe_tools: BTreeMap<u32, Option<f64>>,
    diags: Vec<Diagnostic>,
}

fn spindle_rev_s(t: &Technology) -> f64 {
    match t.spindle {
        SpindleDir::Cw => -t.spindle_speed / 60.0,
        SpindleDir::Ccw => t.spindle_speed / 60.0,
        SpindleDir::Off => 0.0,
    }
}

impl<W: std::io::Write> Writer<W> {
    fn point(&mut self, name: &str, p: P3) -> Value {
        self.b.add("CARTESIAN_POINT", vec![Value::str(name), Value::List(p.iter().map(|v| Value::Real(*v)).collect())])
    }

    fn direction(&mut self, d: P3) -> Value {
        self.b.add("DIRECTION", vec![Value::str(""), Value::List(d.iter().map(|v| Value::Real(*v)).collect())])
    }

    fn placement(&mut self, at: P3, axis: Option<P3>) -> Value {
        self.placement_ref(at, axis, None)
    }

    /// A placement with its axis and reference direction (a feature on a tilted plane).
    fn placement_ref(&mut self, at: P3, axis: Option<P3>, ref_direction: Option<P3>) -> Value {
        let loc = self.point("", at);
        let axis = axis.map_or(Value::Null, |a| self.direction(a));
        let refd = ref_direction.map_or(Value::Null, |a| self.direction(a));
        self.b.add("AXIS2_PLACEMENT_3D", vec![Value::str(""), loc, axis, refd])
    }

    /// A workingstep's security plane: on a tilted plane, perpendicular to its tool axis,
    /// placed in the part's frame with the plane's axes.
    fn security_plane(&mut self, ws: &Workingstep) -> Value {
        let Some(s) = &ws.setup else { return self.plane("security plane", [0.0, 0.0, ws.security_plane]) };
        let pos = self.placement_ref(s.to_part([0.0, 0.0, ws.security_plane]), Some(s.axis), Some(s.ref_direction));
        self.b.add("PLANE", vec![Value::str("security plane"), pos])
    }

    fn plane(&mut self, name: &str, at: P3) -> Value {
        let pos = self.placement(at, None);
        self.b.add("PLANE", vec![Value::str(name), pos])
    }

    fn tlm(&mut self, v: f64) -> Value {
        let tol = self.b.add("PLUS_MINUS_VALUE", vec![Value::Real(0.0), Value::Real(0.0), Value::Int(4)]);
        self.b.add("TOLERANCED_LENGTH_MEASURE", vec![Value::Real(v), tol])
    }

    fn technology(&mut self, t: &Technology, feed: f64) -> Value {
        let key = (feed.to_bits(), t.spindle_speed.to_bits(), t.spindle as u8);
        if let Some(v) = self.tech.get(&key) {
            return v.clone();
        }
        let v = self.b.add(
            "MILLING_TECHNOLOGY",
            vec![
                Value::Real(feed / 60_000.0),
                Value::Enum("TCP".into()),
                Value::Null,
                Value::Real(spindle_rev_s(t)),
                Value::Null,
                Value::bool(false),
                Value::bool(false),
                Value::bool(false),
                Value::Null,
            ],
        );
        self.tech.insert(key, v.clone());
        v
    }

    fn machine_functions(&mut self, c: Coolant) -> Value {
        let (flood, mist) = match c {
            Coolant::Off => (false, false),
            Coolant::Mist => (false, true),
            Coolant::Flood => (true, false),
            Coolant::Both => (true, true),
        };
        if let Some(v) = self.functions.get(&(c as u8)) {
            return v.clone();
        }
        let v = self.b.add(
            "MILLING_MACHINE_FUNCTIONS",
            vec![
                Value::bool(flood),
                Value::Null,
                Value::bool(mist),
                Value::bool(false),
                Value::Null,
                Value::List(vec![]),
                Value::bool(false),
                Value::Null,
                Value::Null,
                Value::List(vec![]),
            ],
        );
        self.functions.insert(c as u8, v.clone());
        v
    }

    fn tool(&mut self, plan: &ProcessPlan, number: u32) -> Value {
        if let Some(v) = self.tools.get(&number) {
            return v.clone();
        }
        let t = plan.tool(number).cloned().unwrap_or_else(|| Tool::unknown(number));
        if let Some(lead) = self.lathe_tools.get(&number).copied() {
            let component = self.b.add(
                "CUTTING_COMPONENT",
                vec![Value::Real(t.length_offset.unwrap_or(0.0)), Value::Null, Value::Null, Value::Null, Value::Null],
            );
            let mut id =
                format!("T{} kind={} kind_source={} source={}", t.number, t.kind.as_str(), t.kind_source.as_str(), t.source.as_str());
            if let Some(a) = t.point_angle {
                id.push_str(&format!(" point_angle={a}"));
            }
            let v = self.turning_tool(&t, lead, id, component);
            self.tools.insert(number, v.clone());
            return v;
        }
        if t.diameter.is_none() {
            self.diags.push(Diagnostic::new(
                Code::DiameterUnknown,
                TextRange::default(),
                format!("the diameter of tool T{number} is not known (no tool table entry, no CAM comment); written as 0"),
            ));
        }
        let dim = self.b.add(
            "MILLING_TOOL_DIMENSION",
            vec![
                Value::Real(t.diameter.unwrap_or(0.0)),
                Value::Null,
                Value::Null,
                Value::Null,
                Value::opt_real(t.corner_radius),
                Value::Null,
                Value::Null,
            ],
        );
        let body_name = match t.kind {
            // Turning tools are ISO 14649-121 tools (above).
            ToolKind::EndMill | ToolKind::Unknown | ToolKind::TurningTool | ToolKind::GroovingTool | ToolKind::ThreadingTool => "ENDMILL",
            ToolKind::BallEndMill => "BALL_ENDMILL",
            ToolKind::BullnoseEndMill => "BULLNOSE_ENDMILL",
            ToolKind::FaceMill => "FACEMILL",
            ToolKind::TwistDrill => "TWIST_DRILL",
            ToolKind::CenterDrill => "CENTERDRILL",
            ToolKind::Reamer => "REAMER",
            ToolKind::Tap => "TAP",
            // ISO 14649-111 (2002) has no boring bar; a counterbore is the nearest body.
            ToolKind::BoringTool => "COUNTERBORE",
            ToolKind::Countersink => "COUNTERSINK",
        };
        let mut body_attrs = vec![dim, t.flutes.map_or(Value::Null, |n| Value::Int(i64::from(n))), Value::Null, Value::Null, Value::Null];
        if t.kind == ToolKind::Countersink {
            body_attrs.push(Value::Null);
        }
        let body = self.b.add(body_name, body_attrs);
        let component = self.b.add(
            "CUTTING_COMPONENT",
            vec![Value::Real(t.length_offset.unwrap_or(0.0)), Value::Null, Value::Null, Value::Null, Value::Null],
        );
        let mut id = format!("T{} kind={} kind_source={} source={}", t.number, t.kind.as_str(), t.kind_source.as_str(), t.source.as_str());
        if let Some(a) = t.point_angle {
            id.push_str(&format!(" point_angle={a}"));
        }
        if let Some(n) = &t.name {
            id.push_str(" name=");
            id.push_str(n);
        }
        let v = self
            .b
            .add("MILLING_CUTTING_TOOL", vec![Value::str(id), body, Value::List(vec![component]), Value::Null, Value::Null, Value::Null]);
        self.tools.insert(number, v.clone());
        v
    }

    fn toolpath(&mut self, ws: &Workingstep, moves: &Toolpath, turning: Option<&Turning>) -> Value {
        let mut trajectories = Vec::new();
        let mut i = 0;
        let mut last_end: Option<(P3, Value)> = None;
        let mut segments: Vec<u64> = Vec::new();
        while let Some(first) = moves.get(i) {
            // A group: the moves from `i` on with the same phase, kind of feed and feed.
            let rapid = first.kind == MoveKind::Rapid;
            let mut j = i + 1;
            let mut arcs = first.kind == MoveKind::Arc;
            for m in moves.iter().skip(j) {
                if m.phase != first.phase || (m.kind == MoveKind::Rapid) != rapid || m.feed.to_bits() != first.feed.to_bits() {
                    break;
                }
                arcs |= m.kind == MoveKind::Arc;
                j += 1;
            }
            let group = || moves.iter().skip(i).take(j - i);
            let last_to = moves.get(j - 1).map_or(first.to, |m| m.to);
            let start = match &last_end {
                Some((p, v)) if *p == first.from => v.clone(),
                _ => self.point("", first.from),
            };
            let curve = if !arcs {
                // The points go out first, numbered one after another; the polyline lists them.
                let first_id = self.b.next_id();
                for m in group() {
                    self.point(&format!("L{}", m.line), m.to);
                }
                let last_id = self.b.next_id() - 1;
                last_end = Some((last_to, Value::Ref(last_id)));
                let start = start.as_ref_id().unwrap_or(0);
                self.b.add_with_refs("POLYLINE", &[Value::str("")], std::iter::once(start).chain(first_id..=last_id), &[])
            } else {
                segments.clear();
                let mut from = start;
                for (k, m) in group().enumerate() {
                    let to = self.point(&format!("L{}", m.line), m.to);
                    let curve = match (m.kind, m.center(), m.axis(), m.turns()) {
                        (MoveKind::Arc, Some(c), Some(axis), Some(turns)) => {
                            let pos = self.placement(c, Some(axis));
                            let r = geom::dist(m.from, c);
                            let circle = self.b.add("CIRCLE", vec![Value::str(""), pos, Value::Real(r)]);
                            let sweep = geom::sweep(&m).to_degrees();
                            let param = |v: f64| Value::Typed("PARAMETER_VALUE".into(), Box::new(Value::Real(v)));
                            self.b.add(
                                "TRIMMED_CURVE",
                                vec![
                                    Value::str(""),
                                    circle,
                                    Value::List(vec![from.clone(), param(0.0)]),
                                    Value::List(vec![to.clone(), param(sweep.abs())]),
                                    Value::bool(turns > 0),
                                    Value::Enum("CARTESIAN".into()),
                                ],
                            )
                        }
                        _ => self.b.add("POLYLINE", vec![Value::str(""), Value::List(vec![from.clone(), to.clone()])]),
                    };
                    let transition = if i + k + 1 == j { "DISCONTINUOUS" } else { "CONTINUOUS" };
                    let segment = self.b.add("COMPOSITE_CURVE_SEGMENT", vec![Value::Enum(transition.into()), Value::bool(true), curve]);
                    segments.extend(segment.as_ref_id());
                    from = to;
                }
                last_end = Some((last_to, from));
                self.b.add_with_refs("COMPOSITE_CURVE", &[Value::str("")], segments.iter().copied(), &[Value::Enum("F".into())])
            };
            let ty = match first.phase {
                Phase::Approach => "APPROACH",
                Phase::Cut => "CONTACT",
                Phase::Connect => "CONNECT",
                Phase::Retract => "LIFT",
            };
            let (speed, tech) = if rapid {
                (Value::Typed("SPEED_NAME".into(), Box::new(Value::Enum(RAPID.into()))), Value::Null)
            } else {
                let tech = match turning {
                    Some(t) => self.turning_technology(&Technology { feed: first.feed, ..ws.technology.clone() }, t),
                    None => self.technology(&ws.technology, first.feed),
                };
                (Value::Null, tech)
            };
            let axes = if moves.tilts() { self.tool_axes(moves, i, j) } else { Value::Null };
            trajectories.push(self.b.add(
                "CUTTER_LOCATION_TRAJECTORY",
                vec![Value::bool(true), Value::Enum(ty.into()), speed, tech, Value::Null, Value::Null, curve, axes, Value::Null],
            ));
            i = j;
        }
        if trajectories.is_empty() {
            return Value::Null;
        }
        self.b.add("TOOLPATH_LIST", vec![Value::List(trajectories)])
    }

    /// The tool axes of moves `i..j` as `its_toolaxis`: a polyline over the same points as
    /// the path, each the tool axis there (unit vectors): at the start, then at each end.
    fn tool_axes(&mut self, moves: &Toolpath, i: usize, j: usize) -> Value {
        let first_id = self.b.next_id();
        self.point("", moves.axis_at(i.saturating_sub(1)));
        for k in i..j {
            self.point("", moves.axis_at(k));
        }
        let last_id = self.b.next_id() - 1;
        self.b.add_with_refs("POLYLINE", &[Value::str("")], first_id..=last_id, &[])
    }

    fn strategy(&mut self, s: &Strategy) -> Value {
        let overlap = Value::opt_real(s.overlap);
        let dir = |w: &mut Writer<W>| s.feed_direction.map_or(Value::Null, |d| w.direction(d));
        let rot = s.rotation.map_or(Value::Null, |r| Value::Enum(if r == Rotation::Cw { "CW" } else { "CCW" }.into()));
        let cut = s.cutmode.map_or(Value::Null, |c| Value::Enum(if c == CutMode::Climb { "CLIMB" } else { "CONVENTIONAL" }.into()));
        match s.kind {
            StrategyKind::Bidirectional => {
                let d = dir(self);
                self.b.add("BIDIRECTIONAL", vec![overlap, Value::Null, d, Value::Null, Value::Null])
            }
            StrategyKind::Unidirectional => {
                let d = dir(self);
                self.b.add("UNIDIRECTIONAL", vec![overlap, Value::Null, d, cut])
            }
            StrategyKind::ContourParallel => self.b.add("CONTOUR_PARALLEL", vec![overlap, Value::Null, rot, cut]),
            StrategyKind::ContourSpiral => self.b.add("CONTOUR_SPIRAL", vec![overlap, Value::Null, rot, cut]),
            StrategyKind::CenterMilling => self.b.add("CENTER_MILLING", vec![overlap, Value::Null]),
            StrategyKind::Explicit => self.b.add("EXPLICIT_STRATEGY", vec![overlap, Value::Null]),
        }
    }

    fn operation(&mut self, plan: &ProcessPlan, ws: &Workingstep, moves: &Toolpath, class: Class) -> Value {
        let turning = iso_turning(ws);
        let toolpath = self.toolpath(ws, moves, turning);
        let start = ws.start_point.map_or(Value::Null, |p| self.point("start", p));
        let tool = self.tool(plan, ws.tool);
        let (tech, functions) = match turning {
            Some(t) => (self.turning_technology(&ws.technology, t), self.turning_functions(ws.technology.coolant)),
            None => (self.technology(&ws.technology, ws.technology.feed), self.machine_functions(ws.technology.coolant)),
        };
        let mut id = format!("OP{}", ws.index);
        if let Some(t) = turning {
            Self::turning_op_words(ws, t, &mut id);
        }
        // Plane milling has no radial depth attribute.
        if let (Operation::PlaneRoughMilling | Operation::PlaneFinishMilling, Some(s)) = (ws.operation, ws.radial_depth)
            && class == Class::Cc2
        {
            id.push_str(&format!(" stepover={s}"));
        }
        // Only multistep drilling has a peck attribute; a pecked centre drilling keeps its own.
        if ws.operation.is_hole()
            && ws.operation != Operation::MultistepDrilling
            && let Some(p) = ws.holes.iter().filter_map(|h| h.peck).reduce(f64::max)
        {
            id.push_str(&format!(" peck={p}"));
        }
        // The surface a cycle stated (RFP, Q203) has no attribute of its own.
        if ws.operation.is_hole()
            && let Some(z) = ws.holes.iter().find_map(|h| h.top)
        {
            id.push_str(&format!(" surface={z}"));
            // Holes whose cycle calls state each its own surface: every hole's top, in order
            // (`-` where a hole's bottom lies above the surface stated, so it has none).
            if ws.holes.iter().any(|h| h.top != ws.holes[0].top) {
                let list: Vec<String> = ws.holes.iter().map(|h| h.top.map_or("-".to_owned(), |z| z.to_string())).collect();
                id.push_str(&format!(" hole_tops={}", list.join(",")));
            }
        }
        // A spindle value is signed by direction: a stopped spindle's speed, and the direction
        // of a turning spindle at speed 0, have no attribute.
        if ws.technology.spindle == SpindleDir::Off && ws.technology.spindle_speed != 0.0 {
            id.push_str(&format!(" stopped_spindle_speed={}", ws.technology.spindle_speed));
        }
        if ws.technology.spindle != SpindleDir::Off && ws.technology.spindle_speed == 0.0 {
            id.push_str(if ws.technology.spindle == SpindleDir::Cw { " spindle=cw" } else { " spindle=ccw" });
        }
        // Constant surface speed has no place in milling technology: the spindle value is
        // its limit, and the surface speed goes with the identifier.
        if let Some(v) = ws.technology.surface_speed.filter(|_| turning.is_none()) {
            id.push_str(&format!(" surface_speed={v}"));
        }
        // The tool's own spindle (a driven tool on a lathe) has no attribute either.
        match ws.technology.spindle_id {
            crate::canon::SpindleId::Main => {}
            crate::canon::SpindleId::Driven => id.push_str(" tool_spindle=driven"),
            crate::canon::SpindleId::Number(n) => id.push_str(&format!(" tool_spindle={n}")),
        }
        let mut attrs = vec![toolpath, Value::Null, Value::str(id), Value::Null, start, tool, tech, functions];
        if let Some(t) = turning.filter(|t| t.operation != Some(TurnOp::Drilling)) {
            return self.turning_operation(ws, t, attrs);
        }
        // Drilling on a lathe's axis is ISO 14649-11's drilling, with turning technology.
        let op = match turning {
            Some(_) => Operation::Drilling,
            None if class == Class::Cc1 => Operation::FreeformMilling,
            None => ws.operation,
        };
        attrs.push(Value::Null);
        let strategy =
            |w: &mut Writer<W>| ws.strategy.as_ref().filter(|s| s.kind != StrategyKind::Explicit).map_or(Value::Null, |s| w.strategy(s));
        let r = Value::opt_real;
        let name = match op {
            Operation::FreeformMilling => {
                attrs.extend([Value::Null, Value::Null, Value::Null]);
                "FREEFORM_OPERATION"
            }
            Operation::PlaneRoughMilling | Operation::PlaneFinishMilling => {
                attrs.extend([Value::Null, Value::Null, strategy(self), r(ws.axial_depth), r(ws.allowance_bottom)]);
                if op == Operation::PlaneRoughMilling { "PLANE_ROUGH_MILLING" } else { "PLANE_FINISH_MILLING" }
            }
            Operation::SideRoughMilling | Operation::SideFinishMilling => {
                attrs.extend([Value::Null, Value::Null, strategy(self), r(ws.axial_depth), r(ws.radial_depth), r(ws.allowance_side)]);
                if op == Operation::SideRoughMilling { "SIDE_ROUGH_MILLING" } else { "SIDE_FINISH_MILLING" }
            }
            Operation::BottomAndSideRoughMilling | Operation::BottomAndSideFinishMilling => {
                attrs.extend([
                    Value::Null,
                    Value::Null,
                    strategy(self),
                    r(ws.axial_depth),
                    r(ws.radial_depth),
                    r(ws.allowance_side),
                    r(ws.allowance_bottom),
                ]);
                if op == Operation::BottomAndSideRoughMilling { "BOTTOM_AND_SIDE_ROUGH_MILLING" } else { "BOTTOM_AND_SIDE_FINISH_MILLING" }
            }
            hole => {
                let depth = ws.holes.first().map(|h| h.r_plane - h.bottom);
                let dwell = ws.holes.first().and_then(|h| h.dwell);
                attrs.extend([r(depth), Value::Null, r(dwell), Value::Null, Value::Null]);
                match hole {
                    Operation::MultistepDrilling => {
                        let peck = ws.holes.iter().filter_map(|h| h.peck).reduce(f64::max).or(ws.axial_depth).unwrap_or(0.0);
                        attrs.extend([Value::Real(0.0), Value::Real(peck), Value::Real(peck), Value::Null]);
                        "MULTISTEP_DRILLING"
                    }
                    Operation::Reaming | Operation::Boring => {
                        let stop =
                            moves.iter().any(|m| m.phase == Phase::Retract && m.kind == MoveKind::Rapid) && hole == Operation::Boring;
                        attrs.extend([Value::bool(stop), Value::Null, Value::Null]);
                        if hole == Operation::Reaming { "REAMING" } else { "BORING" }
                    }
                    Operation::Tapping => {
                        attrs.push(Value::bool(false));
                        "TAPPING"
                    }
                    Operation::CenterDrilling => "CENTER_DRILLING",
                    Operation::BackBoring => "BACK_BORING",
                    _ => "DRILLING",
                }
            }
        };
        self.b.add(name, attrs)
    }

    fn curve(&mut self, c: &Contour) -> Value {
        if c.segments.iter().all(|s| s.arc.is_none()) {
            let mut points = vec![self.point("", [c.start[0], c.start[1], 0.0])];
            for s in &c.segments {
                points.push(self.point("", [s.to[0], s.to[1], 0.0]));
            }
            return self.b.add("POLYLINE", vec![Value::str(""), Value::List(points)]);
        }
        let mut segments = Vec::new();
        let mut from = self.point("", [c.start[0], c.start[1], 0.0]);
        let mut from_xy = c.start;
        for (k, s) in c.segments.iter().enumerate() {
            let to = self.point("", [s.to[0], s.to[1], 0.0]);
            let curve = match s.arc {
                None => self.b.add("POLYLINE", vec![Value::str(""), Value::List(vec![from.clone(), to.clone()])]),
                Some((centre, ccw)) => {
                    let pos = self.placement([centre[0], centre[1], 0.0], Some([0.0, 0.0, 1.0]));
                    let r = (from_xy[0] - centre[0]).hypot(from_xy[1] - centre[1]);
                    let circle = self.b.add("CIRCLE", vec![Value::str(""), pos, Value::Real(r)]);
                    let param = |v: f64| Value::Typed("PARAMETER_VALUE".into(), Box::new(Value::Real(v)));
                    let a0 = (from_xy[1] - centre[1]).atan2(from_xy[0] - centre[0]).to_degrees();
                    let a1 = (s.to[1] - centre[1]).atan2(s.to[0] - centre[0]).to_degrees();
                    self.b.add(
                        "TRIMMED_CURVE",
                        vec![
                            Value::str(""),
                            circle,
                            Value::List(vec![from.clone(), param(a0)]),
                            Value::List(vec![to.clone(), param(a1)]),
                            Value::bool(ccw),
                            Value::Enum("CARTESIAN".into()),
                        ],
                    )
                }
            };
            let closed_end = k + 1 == c.segments.len() && !c.is_closed();
            let transition = if closed_end { "DISCONTINUOUS" } else { "CONTINUOUS" };
            segments.push(self.b.add("COMPOSITE_CURVE_SEGMENT", vec![Value::Enum(transition.into()), Value::bool(true), curve]));
            from = to;
            from_xy = s.to;
        }
        self.b.add("COMPOSITE_CURVE", vec![Value::str(""), Value::List(segments), Value::Enum("F".into())])
    }

    fn feature(&mut self, f: &Feature, workpiece: &Value, ops: Vec<Value>) -> Value {
        let mut id = format!("F{}", f.id);
        if f.top_inferred {
            id.push_str(" top=inferred");
        }
        if let FeatureKind::Step { width, .. } = &f.kind {
            id.push_str(&format!(" width={width}"));
        }
        id.push_str(&format!(" size_from={} top_from={}", f.sources.size.as_str(), f.sources.top.as_str()));
        if let Some(p) = f.sources.point_angle {
            id.push_str(&format!(" point_angle_from={}", p.as_str()));
        }
        if let Some((w, l)) = f.centre_path {
            id.push_str(&format!(" centre_path={w}x{l}"));
        }
        // ISO 14649-10 places a feature on a plane; one wrapped round a cylinder (cut on its
        // developed surface) has no entity of its own: its word says the cylinder and angles.
        if let Some(w) = f.wrap {
            id.push_str(&format!(" wrap={}x{}x{}x{}", w.diameter, w.angles.0, w.angles.1, w.developed));
        }
        // A thread is no ISO entity (see `turning`): its word says it.
        if let FeatureKind::Turned(t @ Turned::Thread { .. }) = &f.kind {
            id.push_str(&format!(" turned={}", json_word(t)));
        }
        let (axis, refd) = (f.axis.unwrap_or([0.0, 0.0, 1.0]), f.ref_direction);
        let common = |w: &mut Writer<W>, placement: P3, depth: f64, ops: Vec<Value>| {
            let place = w.placement_ref(placement, Some(axis), refd);
            let depth = w.plane("depth", [0.0, 0.0, -depth]);
            vec![Value::str(id.clone()), workpiece.clone(), Value::List(ops), place, depth]
        };
        match &f.kind {
            FeatureKind::RoundHole { diameter, bottom, positions, heights } => {
                let (base_place, base_ops) = if positions.len() > 1 { ([0.0; 3], Vec::new()) } else { (f.placement, ops.clone()) };
                let mut attrs = common(self, base_place, f.depth, base_ops);
                if diameter.is_none() {
                    self.diags.push(Diagnostic::new(
                        Code::DiameterUnknown,
                        f.source,
                        format!("feature {}: the hole diameter is not known (the tool's is not); written as 0", f.id),
                    ));
                }
                let d = self.tlm(diameter.unwrap_or(0.0));
                let bottom = match bottom {
                    HoleBottom::Through => self.b.add("THROUGH_BOTTOM_CONDITION", vec![]),
                    HoleBottom::Flat => self.b.add("FLAT_HOLE_BOTTOM", vec![]),
                    HoleBottom::Conical(angle) => self.b.add("CONICAL_HOLE_BOTTOM", vec![Value::Real(*angle), Value::Null]),
                };
                attrs.extend([d, Value::Null, bottom]);
                let hole = self.b.add("ROUND_HOLE", attrs);
                if positions.len() < 2 {
                    return hole;
                }
                let place = self.placement_ref(f.placement, Some(axis), refd);
                // Each replicate at its own top along the axis, where the holes' tops differ.
                let height = |k: usize| heights.get(k).copied().unwrap_or(0.0);
                let locations: Vec<Value> =
                    positions.iter().enumerate().map(|(k, p)| self.placement([p[0], p[1], height(k)], None)).collect();
                // The pattern carries the feature's words (`top=inferred`, where its sizes came from).
                let head = format!("F{}", f.id);
                let pid = format!("{head} pattern{}", &id[head.len()..]);
                self.b
                    .add("GENERAL_PATTERN", vec![Value::str(pid), workpiece.clone(), Value::List(ops), place, hole, Value::List(locations)])
            }
            FeatureKind::PlanarFace { direction, length, width } => {
                let mut attrs = common(self, f.placement, f.depth, ops);
                let len = self.tlm(*length);
                let dir = self.direction(*direction);
                let course = self.b.add("LINEAR_PATH", vec![Value::Null, len, dir]);
                let wparam = self.b.add("NUMERIC_PARAMETER", vec![Value::str("width"), Value::Real(*width), Value::str("mm")]);
                let removal = self.b.add("LINEAR_PROFILE", vec![Value::Null, wparam]);
                attrs.extend([course, removal, Value::Null, Value::List(vec![])]);
                self.b.add("PLANAR_FACE", attrs)
            }
            FeatureKind::ClosedPocket { boundary, rectangle, corner_radius } => {
                let mut attrs = common(self, f.placement, f.depth, ops);
                let bottom = self.b.add("PLANAR_POCKET_BOTTOM_CONDITION", vec![]);
                let radius = corner_radius.map_or(Value::Null, |r| self.tlm(r));
                let profile = match rectangle {
                    Some((w, l)) => {
                        let (w, l) = (self.tlm(*w), self.tlm(*l));
                        self.b.add("RECTANGULAR_CLOSED_PROFILE", vec![Value::Null, w, l])
                    }
                    None => {
                        let c = self.curve(boundary);
                        self.b.add("GENERAL_CLOSED_PROFILE", vec![Value::Null, c])
                    }
                };
                attrs.extend([Value::List(vec![]), Value::Null, bottom, radius, Value::Null, profile]);
                self.b.add("CLOSED_POCKET", attrs)
            }
            FeatureKind::OpenPocket { boundary } => {
                let mut attrs = common(self, f.placement, f.depth, ops);
                let bottom = self.b.add("PLANAR_POCKET_BOTTOM_CONDITION", vec![]);
                let c = self.curve(boundary);
                let profile = self.b.add("GENERAL_PROFILE", vec![Value::Null, c]);
                attrs.extend([Value::List(vec![]), Value::Null, bottom, Value::Null, Value::Null, profile, Value::Null]);
                self.b.add("OPEN_POCKET", attrs)
            }
            FeatureKind::Slot { path, width } => {
                let mut attrs = common(self, f.placement, f.depth, ops);
                let c = self.curve(path);
                let course = self.b.add("GENERAL_PATH", vec![Value::Null, c]);
                let w = self.tlm(*width);
                let (r1, r2) = (self.tlm(0.0), self.tlm(0.0));
                let shape = self.b.add("SQUARE_U_PROFILE", vec![Value::Null, w, r1, Value::Real(90.0), r2, Value::Real(90.0)]);
                let ends = vec![self.b.add("RADIUSED_SLOT_END_TYPE", vec![]), self.b.add("RADIUSED_SLOT_END_TYPE", vec![])];
                attrs.extend([course, shape, Value::List(ends)]);
                self.b.add("SLOT", attrs)
            }
            FeatureKind::Step { direction, length, .. } => {
                let mut attrs = common(self, f.placement, f.depth, ops);
                let len = self.tlm(*length);
                let dir = self.direction(*direction);
                let edge = self.b.add("LINEAR_PATH", vec![Value::Null, len, dir]);
                attrs.extend([edge, Value::Null, Value::List(vec![])]);
                self.b.add("STEP", attrs)
            }
            FeatureKind::OutsideProfile { boundary, .. } => {
                let mut attrs = common(self, f.placement, f.depth, ops);
                let len = self.tlm(f.depth);
                let down = self.direction([0.0, 0.0, -1.0]);
                let swept = self.b.add("LINEAR_PATH", vec![Value::Null, len, down]);
                let c = self.curve(boundary);
                let profile = self.b.add("GENERAL_CLOSED_PROFILE", vec![Value::Null, c]);
                attrs.extend([swept, profile]);
                self.b.add("GENERAL_OUTSIDE_PROFILE", attrs)
            }
            FeatureKind::Turned(t) => match self.turned_feature(f, t, id.clone(), workpiece, ops.clone()) {
                Some(v) => v,
                // A thread: ISO 14649-10's THREAD needs what no program states.
                None => {
                    let attrs = common(self, f.placement, f.depth, ops);
                    self.b.add("TOOLPATH_FEATURE", attrs)
                }
            },
            FeatureKind::Toolpath => {
                let attrs = common(self, f.placement, f.depth, ops);
                self.b.add("TOOLPATH_FEATURE", attrs)
            }
        }
    }
}

/// Reads a plan back from an exchange [`write`] produced (either class).
pub fn read(x: &Exchange) -> Result<ProcessPlan, String> {
    let r = Reader { x };
    r.plan()
}

struct Reader<'a> {
    x: &'a Exchange,
}

fn first(l: &[Value]) -> Result<&Value, String> {
    l.first().ok_or_else(|| "an empty list".to_owned())
}

fn last(l: &[Value]) -> Result<&Value, String> {
    l.last().ok_or_else(|| "an empty list".to_owned())
}

/// `key=value` words after the first word of an id; a `name=` value runs to the end.
/// The number of a feature by its identifier (`F3 ...`).
fn feature_number(id: &str) -> Option<u32> {
    id.split(' ').next()?.strip_prefix('F')?.parse().ok()
}

/// A value as one identifier word: its JSON with `%` and spaces escaped.
fn json_word<T: serde::Serialize>(v: &T) -> String {
    serde_json::to_string(v).unwrap_or_default().replace('%', "%25").replace(' ', "%20")
}

/// Reads [`json_word`].
fn from_json_word<T: serde::de::DeserializeOwned>(w: &str) -> Option<T> {
    serde_json::from_str(&w.replace("%20", " ").replace("%25", "%")).ok()
}

fn words(id: &str) -> (String, BTreeMap<String, String>) {
    let (head, rest) = id.split_once(' ').unwrap_or((id, ""));
    let mut map = BTreeMap::new();
    let mut rest = rest;
    while !rest.is_empty() {
        if let Some(v) = rest.strip_prefix("name=") {
            map.insert("name".to_owned(), v.to_owned());
            break;
        }
        let (w, tail) = rest.split_once(' ').unwrap_or((rest, ""));
        if let Some((k, v)) = w.split_once('=') {
            map.insert(k.to_owned(), v.to_owned());
        } else {
            map.insert(w.to_owned(), String::new());
        }
        rest = tail;
    }
    (head.to_owned(), map)
}

/// A converted unit read back, rounded as plan recovery rounds rates, so that
/// `240 / 60000 * 60000` is 240 again.
/// The operation an entity's name states.
fn operation_named(name: &str) -> Result<Operation, String> {
    Ok(match name {
        "FREEFORM_OPERATION" => Operation::FreeformMilling,
        "PLANE_ROUGH_MILLING" => Operation::PlaneRoughMilling,
        "PLANE_FINISH_MILLING" => Operation::PlaneFinishMilling,
        "SIDE_ROUGH_MILLING" => Operation::SideRoughMilling,
        "SIDE_FINISH_MILLING" => Operation::SideFinishMilling,
        "BOTTOM_AND_SIDE_ROUGH_MILLING" => Operation::BottomAndSideRoughMilling,
        "BOTTOM_AND_SIDE_FINISH_MILLING" => Operation::BottomAndSideFinishMilling,
        "DRILLING" => Operation::Drilling,
        "CENTER_DRILLING" => Operation::CenterDrilling,
        "MULTISTEP_DRILLING" => Operation::MultistepDrilling,
        "REAMING" => Operation::Reaming,
        "BORING" => Operation::Boring,
        "BACK_BORING" => Operation::BackBoring,
        "TAPPING" => Operation::Tapping,
        other => return Err(format!("unknown operation {other}")),
    })
}

fn snap(v: f64) -> f64 {
    plan::round_sig(v)
}

impl Reader<'_> {
    fn inst(&self, v: &Value) -> Result<&Instance, String> {
        let id = v.as_ref_id().ok_or_else(|| format!("expected a reference, found {v:?}"))?;
        self.x.get(id).ok_or_else(|| format!("#{id} is not defined"))
    }

    fn attr<'v>(&self, i: &'v Instance, k: usize) -> Result<&'v Value, String> {
        i.attrs.get(k).ok_or_else(|| format!("{} has no attribute {k}", i.name))
    }

    fn real(&self, i: &Instance, k: usize) -> Result<f64, String> {
        self.attr(i, k)?.as_real().ok_or_else(|| format!("{} attribute {k} is not a real", i.name))
    }

    fn opt_real(&self, i: &Instance, k: usize) -> Result<Option<f64>, String> {
        match self.attr(i, k)? {
            Value::Null => Ok(None),
            v => v.as_real().map(Some).ok_or_else(|| format!("{} attribute {k} is not a real", i.name)),
        }
    }

    fn string(&self, i: &Instance, k: usize) -> Result<String, String> {
        Ok(self.attr(i, k)?.as_str().unwrap_or_default().to_owned())
    }

    fn point(&self, v: &Value) -> Result<(P3, String), String> {
        let p = self.inst(v)?;
        let c = self.attr(p, 1)?.as_list().ok_or("a point without coordinates")?;
        let get = |k: usize| c.get(k).and_then(Value::as_real).unwrap_or(0.0);
        Ok(([get(0), get(1), get(2)], self.string(p, 0)?))
    }

    fn direction(&self, v: &Value) -> Result<P3, String> {
        let d = self.inst(v)?;
        let c = self.attr(d, 1)?.as_list().ok_or("a direction without ratios")?;
        let get = |k: usize| c.get(k).and_then(Value::as_real).unwrap_or(0.0);
        Ok([get(0), get(1), get(2)])
    }

    fn placement(&self, v: &Value) -> Result<P3, String> {
        let a = self.inst(v)?;
        Ok(self.point(self.attr(a, 1)?)?.0)
    }

    /// A placement's axis and reference direction, where it states a reference direction.
    fn placement_axes(&self, v: &Value) -> Result<Option<(P3, P3)>, String> {
        let a = self.inst(v)?;
        match (self.attr(a, 2)?, self.attr(a, 3)?) {
            (axis @ Value::Ref(_), refd @ Value::Ref(_)) => Ok(Some((self.direction(axis)?, self.direction(refd)?))),
            _ => Ok(None),
        }
    }

    fn plane_z(&self, v: &Value) -> Result<f64, String> {
        let p = self.inst(v)?;
        Ok(self.placement(self.attr(p, 1)?)?[2])
    }

    fn tlm(&self, v: &Value) -> Result<f64, String> {
        let t = self.inst(v)?;
        self.real(t, 0)
    }

    fn plan(&self) -> Result<ProcessPlan, String> {
        let project = self.x.ids_of("PROJECT").next().and_then(|id| self.x.get(id)).ok_or("no PROJECT")?;
        let program = self.string(project, 0)?;
        let workplan = self.inst(self.attr(project, 1)?)?;
        let (_, wp_words) = words(&self.string(workplan, 0)?);
        let units = match wp_words.get("units").map(String::as_str) {
            Some("mm") => Some(Units::Mm),
            Some("inch") => Some(Units::Inch),
            _ => None,
        };
        let workpiece = self.workpiece(project)?;
        let mut plan = ProcessPlan {
            program: (!program.is_empty()).then_some(program),
            units,
            tools: Vec::new(),
            workingsteps: Vec::new(),
            features: Vec::new(),
            workpiece,
        };
        let mut tools: BTreeMap<u32, Tool> = BTreeMap::new();
        let mut feature_ids: BTreeMap<u64, u32> = BTreeMap::new();
        let elements = self.attr(workplan, 1)?.as_list().ok_or("WORKPLAN without elements")?;
        for e in elements {
            let inst = self.inst(e)?;
            match inst.name.as_str() {
                "LOAD_TOOL" => {
                    let t = self.tool(self.attr(inst, 1)?)?;
                    tools.insert(t.number, t);
                }
                "MACHINING_WORKINGSTEP" | "TURNING_WORKINGSTEP" => {
                    let ws = self.workingstep(inst, &mut plan, &mut tools, &mut feature_ids)?;
                    plan.workingsteps.push(ws);
                }
                other => return Err(format!("unexpected workplan element {other}")),
            }
        }
        plan.features.sort_by_key(|f| f.id);
        for f in &mut plan.features {
            plan::feature::feature_source(f, &plan.workingsteps);
        }
        plan.tools = tools.into_values().collect();
        Ok(plan)
    }

    fn workpiece(&self, project: &Instance) -> Result<Option<Stock>, String> {
        let Some(wp) = self.attr(project, 2)?.as_list().and_then(|l| l.first()) else { return Ok(None) };
        let wp = self.inst(wp)?;
        let raw = self.attr(wp, 3)?;
        if *raw == Value::Null {
            return Ok(None);
        }
        let raw = self.inst(raw)?;
        let block = self.attr(raw, 5)?;
        if *block == Value::Null {
            return Ok(None);
        }
        let block = self.inst(block)?;
        let said = self.string(block, 0)?;
        let source = if said.ends_with("config") { StockSource::Config } else { StockSource::Program };
        let line = said.split_once(" line ").and_then(|(_, l)| l.parse().ok());
        let origin = self.placement(self.attr(block, 1)?)?;
        Ok(Some(Stock { origin, size: [self.real(block, 2)?, self.real(block, 3)?, self.real(block, 4)?], source, line }))
    }

    fn tool(&self, v: &Value) -> Result<Tool, String> {
        let t = self.inst(v)?;
        let (head, w) = words(&self.string(t, 0)?);
        let number: u32 = head.trim_start_matches('T').parse().map_err(|_| format!("tool id {head:?}"))?;
        let body = self.inst(self.attr(t, 1)?)?;
        let dim = self.inst(self.attr(body, 0)?)?;
        // A turning tool: its nose radius in its dimension, a diameter and flutes as words.
        let lathe = t.name == "TURNING_MACHINE_TOOL";
        let (diameter, corner_radius, flutes) = if lathe {
            let word = |k: &str| w.get(k).and_then(|v| v.parse::<f64>().ok());
            (word("diameter").unwrap_or(0.0), self.turning_tool_radius(body)?, w.get("flutes").and_then(|v| v.parse().ok()))
        } else {
            let flutes = match self.attr(body, 1)? {
                Value::Int(n) => Some(*n as u32),
                _ => None,
            };
            (self.real(dim, 0)?, self.opt_real(dim, 4)?, flutes)
        };
        let component = self.attr(t, 2)?.as_list().and_then(|l| l.first()).ok_or("a tool without cutting component")?;
        let offset = self.real(self.inst(component)?, 0)?;
        let parse_source = |k: &str| w.get(k).and_then(|s| ToolSource::parse(s)).unwrap_or(ToolSource::Unknown);
        Ok(Tool {
            number,
            name: w.get("name").cloned(),
            kind: w.get("kind").and_then(|k| ToolKind::parse(k)).unwrap_or(ToolKind::Unknown),
            kind_source: parse_source("kind_source"),
            diameter: (diameter != 0.0).then_some(diameter),
            corner_radius,
            flutes,
            length_offset: (offset != 0.0).then_some(offset),
            point_angle: w.get("point_angle").and_then(|v| v.parse().ok()),
            source: parse_source("source"),
        })
    }

    /// A workingstep's security plane (its height, along the tilted plane's axis where it
    /// runs on one) and its setup (the plane's origin and axes, from the placement and the
    /// `plane_origin` and `plane_z` words).
    fn security_plane_and_setup(&self, inst: &Instance, w: &BTreeMap<String, String>) -> Result<(f64, Option<crate::plan::Setup>), String> {
        let mut security_plane = self.plane_z(self.attr(inst, 1)?)?;
        let sec_place = self.attr(self.inst(self.attr(inst, 1)?)?, 1)?;
        let origin = w.get("plane_origin").and_then(|o| {
            let v: Vec<f64> = o.split(',').filter_map(|x| x.parse().ok()).collect();
            (v.len() == 3).then(|| [v[0], v[1], v[2]])
        });
        let setup = match (self.placement_axes(sec_place)?, origin) {
            (Some((axis, ref_direction)), Some(origin)) => {
                let at = self.placement(sec_place)?;
                let along = (0..3).map(|i| (at[i] - origin[i]) * axis[i]).sum::<f64>() / (0..3).map(|i| axis[i] * axis[i]).sum::<f64>();
                security_plane = w.get("plane_z").and_then(|z| z.parse().ok()).unwrap_or_else(|| snap(along));
                let cylinder = w.get("plane_cylinder").and_then(|d| d.parse().ok());
                Some(crate::plan::Setup { origin, axis, ref_direction, cylinder })
            }
            _ => None,
        };
        Ok((security_plane, setup))
    }

    fn workingstep(
        &self,
        inst: &Instance,
        plan: &mut ProcessPlan,
        tools: &mut BTreeMap<u32, Tool>,
        feature_ids: &mut BTreeMap<u64, u32>,
    ) -> Result<Workingstep, String> {
        let (head, w) = words(&self.string(inst, 0)?);
        let index: u32 = head.trim_start_matches("WS").parse().map_err(|_| format!("workingstep id {head:?}"))?;
        let pair = |s: Option<&String>| -> (u32, u32) {
            s.and_then(|s| s.split_once('-')).map_or((0, 0), |(a, b)| (a.parse().unwrap_or(0), b.parse().unwrap_or(0)))
        };
        let lines = pair(w.get("lines"));
        let bytes = pair(w.get("bytes"));
        let (security_plane, setup) = self.security_plane_and_setup(inst, &w)?;
        let op = self.inst(self.attr(inst, 3)?)?;
        let tool = self.tool(self.attr(op, 5)?)?;
        let tool_number = tool.number;
        tools.insert(tool.number, tool);
        let tech = self.inst(self.attr(op, 6)?)?;
        let turning_tech = if tech.name == "TURNING_TECHNOLOGY" { Some(self.turning_technology(tech)?) } else { None };
        let feed = match &turning_tech {
            Some(t) => t.feed,
            None => snap(self.real(tech, 0)? * 60_000.0),
        };
        let rev_s = match &turning_tech {
            Some(t) => t.rev_s,
            None => self.real(tech, 3)?,
        };
        let (_, op_words) = words(&self.string(op, 2)?);
        let (spindle, spindle_speed) = if rev_s < 0.0 {
            (SpindleDir::Cw, snap(-rev_s * 60.0))
        } else if rev_s > 0.0 {
            (SpindleDir::Ccw, snap(rev_s * 60.0))
        } else {
            match op_words.get("spindle").map(String::as_str) {
                Some("cw") => (SpindleDir::Cw, 0.0),
                Some("ccw") => (SpindleDir::Ccw, 0.0),
                _ => (SpindleDir::Off, op_words.get("stopped_spindle_speed").and_then(|s| s.parse().ok()).unwrap_or(0.0)),
            }
        };
        let coolant = self.coolant(self.inst(self.attr(op, 7)?)?, &op_words)?;
        let toolpath = match self.attr(op, 0)? {
            Value::Null => Toolpath::new(),
            v => self.toolpath(v)?,
        };
        // A turning operation (drilling too, with turning technology) is a freeform
        // workingstep of the plan that says what it turns.
        let turn_op = turning::operation_of(&op.name).or_else(|| turning_tech.as_ref().map(|_| (TurnOp::Drilling, false)));
        let operation = if turn_op.is_some() { Operation::FreeformMilling } else { operation_named(&op.name)? };
        let surface_speed = match &turning_tech {
            Some(t) => t.surface_speed,
            None => op_words.get("surface_speed").and_then(|s| s.parse().ok()),
        };
        let spindle_id = match op_words.get("tool_spindle").map(String::as_str) {
            Some("driven") => crate::canon::SpindleId::Driven,
            Some(n) => n.parse().map_or(crate::canon::SpindleId::Main, crate::canon::SpindleId::Number),
            None => crate::canon::SpindleId::Main,
        };
        let technology = Technology { feed, feeds: Vec::new(), spindle_speed, surface_speed, spindle, coolant, spindle_id };
        let source = TextRange::new(bytes.0 as usize, bytes.1 as usize);
        let mut ws = Workingstep::unmeasured(index, operation, tool_number, technology, security_plane, toolpath, source, lines);
        ws.state = MachineState::decode(&w);
        ws.setup = setup;
        ws.turning = match (turn_op, &turning_tech) {
            (Some(o), Some(t)) => Some(Box::new(self.turning(o, w.get("turning"), t.feed_per_rev, op_words.contains_key("fpr")))),
            _ => w.get("turning").and_then(|v| from_json_word(v)).map(Box::new),
        };
        let dwell = self.operation_parameters(op, operation, &mut ws)?;
        if matches!(operation, Operation::PlaneRoughMilling | Operation::PlaneFinishMilling) {
            ws.radial_depth = op_words.get("stepover").and_then(|v| v.parse().ok());
        }
        let peck = if operation == Operation::MultistepDrilling {
            self.opt_real(op, 16)?.filter(|p| *p > 0.0)
        } else {
            op_words.get("peck").and_then(|v| v.parse().ok())
        };
        let surface: Option<f64> = op_words.get("surface").and_then(|v| v.parse().ok());
        plan::measure(&mut ws, dwell, peck, &surface.map(|z| vec![(0, z)]).unwrap_or_default());
        if let Some(tops) = op_words.get("hole_tops") {
            let tops: Vec<Option<f64>> = tops.split(',').map(|v| v.parse().ok()).collect();
            if tops.len() == ws.holes.len() {
                for (h, z) in ws.holes.iter_mut().zip(tops) {
                    h.top = z;
                }
            }
        }
        // The feature, numbered in order of first machining; a turning workingstep's list
        // names its own first.
        let listed = self.attr(inst, 2)?;
        let fref = match listed.as_list() {
            Some(l) => first(l)?,
            None => listed,
        };
        if let Some(l) = listed.as_list() {
            self.listed_turned_features(&l[1..], index, plan, feature_ids)?;
        } else if ws.turning.is_some() {
            self.more_turned_features(&w, index, plan, feature_ids)?;
        }
        if let Some(fid) = fref.as_ref_id() {
            let id = match feature_ids.get(&fid) {
                Some(id) => *id,
                None => {
                    // A turning workingstep's features keep their numbers: one workingstep
                    // machines several, and they are numbered in the order they were found.
                    let own = ws.turning.as_ref().and_then(|_| feature_number(&self.string(self.inst(fref).ok()?, 0).ok()?));
                    let id = own.unwrap_or(feature_ids.len() as u32 + 1);
                    feature_ids.insert(fid, id);
                    let f = self.feature(self.inst(fref)?, id)?;
                    plan.features.push(f);
                    id
                }
            };
            ws.feature = Some(id);
            if let Some(f) = plan.features.iter_mut().find(|f| f.id == id) {
                f.workingsteps.push(index);
            }
            if matches!(
                operation,
                Operation::MultistepDrilling
                    | Operation::Drilling
                    | Operation::Reaming
                    | Operation::Boring
                    | Operation::Tapping
                    | Operation::CenterDrilling
                    | Operation::BackBoring
            ) {
                ws.axial_depth = ws.holes.iter().filter_map(|h| h.peck).reduce(f64::max);
            }
        }
        Ok(ws)
    }

    /// A milling operation's strategy, depths and allowances, as its entity's attributes give
    /// them; the dwell of a drilling operation.
    fn operation_parameters(&self, op: &Instance, operation: Operation, ws: &mut Workingstep) -> Result<Option<f64>, String> {
        match operation {
            // A turning workingstep has no milling strategy.
            Operation::FreeformMilling if ws.turning.is_some() => {}
            Operation::FreeformMilling => ws.strategy = Some(explicit()),
            Operation::PlaneRoughMilling | Operation::PlaneFinishMilling => {
                ws.strategy = self.strategy(self.attr(op, 11)?)?;
                ws.axial_depth = self.opt_real(op, 12)?;
                ws.allowance_bottom = self.opt_real(op, 13)?;
            }
            Operation::SideRoughMilling | Operation::SideFinishMilling => {
                ws.strategy = self.strategy(self.attr(op, 11)?)?;
                ws.axial_depth = self.opt_real(op, 12)?;
                ws.radial_depth = self.opt_real(op, 13)?;
                ws.allowance_side = self.opt_real(op, 14)?;
            }
            Operation::BottomAndSideRoughMilling | Operation::BottomAndSideFinishMilling => {
                ws.strategy = self.strategy(self.attr(op, 11)?)?;
                ws.axial_depth = self.opt_real(op, 12)?;
                ws.radial_depth = self.opt_real(op, 13)?;
                ws.allowance_side = self.opt_real(op, 14)?;
                ws.allowance_bottom = self.opt_real(op, 15)?;
            }
            _ => return self.opt_real(op, 11),
        }
        Ok(None)
    }

    /// The coolant an operation's machine functions state (milling or turning).
    fn coolant(&self, mf: &Instance, op_words: &BTreeMap<String, String>) -> Result<Coolant, String> {
        if mf.name == "TURNING_MACHINE_FUNCTIONS" {
            return self.turning_coolant(mf, op_words.get("coolant").is_some_and(|c| c == "both"));
        }
        let flood = self.attr(mf, 0)?.as_enum() == Some("T");
        let mist = self.attr(mf, 2)?.as_enum() == Some("T");
        Ok(match (mist, flood) {
            (false, false) => Coolant::Off,
            (true, false) => Coolant::Mist,
            (false, true) => Coolant::Flood,
            (true, true) => Coolant::Both,
        })
    }

    fn strategy(&self, v: &Value) -> Result<Option<Strategy>, String> {
        if *v == Value::Null {
            return Ok(None);
        }
        let s = self.inst(v)?;
        let overlap = self.opt_real(s, 0)?;
        let dir = |k: usize| -> Result<Option<P3>, String> {
            match self.attr(s, k)? {
                Value::Null => Ok(None),
                d => self.direction(d).map(Some),
            }
        };
        let rot = |k: usize| -> Result<Option<Rotation>, String> {
            Ok(match self.attr(s, k)?.as_enum() {
                Some("CW") => Some(Rotation::Cw),
                Some("CCW") => Some(Rotation::Ccw),
                _ => None,
            })
        };
        let cut = |k: usize| -> Result<Option<CutMode>, String> {
            Ok(match self.attr(s, k)?.as_enum() {
                Some("CLIMB") => Some(CutMode::Climb),
                Some("CONVENTIONAL") => Some(CutMode::Conventional),
                _ => None,
            })
        };
        let mut out = Strategy { kind: StrategyKind::Explicit, feed_direction: None, rotation: None, cutmode: None, overlap };
        match s.name.as_str() {
            "BIDIRECTIONAL" => {
                out.kind = StrategyKind::Bidirectional;
                out.feed_direction = dir(2)?;
            }
            "UNIDIRECTIONAL" => {
                out.kind = StrategyKind::Unidirectional;
                out.feed_direction = dir(2)?;
                out.cutmode = cut(3)?;
            }
            "CONTOUR_PARALLEL" | "CONTOUR_SPIRAL" => {
                out.kind = if s.name == "CONTOUR_PARALLEL" { StrategyKind::ContourParallel } else { StrategyKind::ContourSpiral };
                out.rotation = rot(2)?;
                out.cutmode = cut(3)?;
            }
            "CENTER_MILLING" => out.kind = StrategyKind::CenterMilling,
            "EXPLICIT_STRATEGY" => {}
            other => return Err(format!("unknown strategy {other}")),
        }
        Ok(Some(out))
    }

    fn toolpath(&self, v: &Value) -> Result<Toolpath, String> {
        let list = self.inst(v)?;
        let mut moves = Vec::new();
        let mut axes: Vec<P3> = Vec::new();
        for t in self.attr(list, 0)?.as_list().ok_or("TOOLPATH_LIST without a list")? {
            let t = self.inst(t)?;
            let phase = match self.attr(t, 1)?.as_enum() {
                Some("APPROACH") => Phase::Approach,
                Some("LIFT") => Phase::Retract,
                Some("CONNECT") => Phase::Connect,
                _ => Phase::Cut,
            };
            let rapid = self.attr(t, 2)?.as_enum() == Some(RAPID);
            let feed = match self.attr(t, 3)? {
                Value::Null => 0.0,
                tech => snap(self.real(self.inst(tech)?, 0)? * 60_000.0),
            };
            let curve = self.inst(self.attr(t, 6)?)?;
            let first_move = moves.len();
            let axis_points = match t.attrs.get(7) {
                Some(v @ Value::Ref(_)) => {
                    let pl = self.inst(v)?;
                    let pts = self.attr(pl, 1)?.as_list().ok_or("its_toolaxis without points")?;
                    pts.iter().map(|p| self.point(p).map(|(a, _)| a)).collect::<Result<Vec<P3>, String>>()?
                }
                _ => Vec::new(),
            };
            let mut push = |from: P3, to: P3, name: &str, arc: Option<(P3, P3, i32)>| {
                let line = name.trim_start_matches('L').parse().unwrap_or(0);
                let kind = if arc.is_some() {
                    MoveKind::Arc
                } else if rapid {
                    MoveKind::Rapid
                } else {
                    MoveKind::Line
                };
                moves.push(Move {
                    kind,
                    phase,
                    from,
                    to,
                    arc: arc.map(|a| ArcGeometry { center: a.0, axis: a.1, turns: a.2 }),
                    feed,
                    line,
                });
            };
            match curve.name.as_str() {
                "POLYLINE" => {
                    let pts = self.attr(curve, 1)?.as_list().ok_or("POLYLINE without points")?;
                    let pts: Vec<(P3, String)> = pts.iter().map(|p| self.point(p)).collect::<Result<_, _>>()?;
                    for w in pts.windows(2) {
                        push(w[0].0, w[1].0, &w[1].1, None);
                    }
                }
                "COMPOSITE_CURVE" => {
                    for seg in self.attr(curve, 1)?.as_list().ok_or("COMPOSITE_CURVE without segments")? {
                        let c = self.inst(self.attr(self.inst(seg)?, 2)?)?;
                        match c.name.as_str() {
                            "POLYLINE" => {
                                let pts = self.attr(c, 1)?.as_list().ok_or("POLYLINE without points")?;
                                let (a, _) = self.point(first(pts)?)?;
                                let (b, name) = self.point(last(pts)?)?;
                                push(a, b, &name, None);
                            }
                            "TRIMMED_CURVE" => {
                                let circle = self.inst(self.attr(c, 1)?)?;
                                let pos = self.inst(self.attr(circle, 1)?)?;
                                let centre = self.point(self.attr(pos, 1)?)?.0;
                                let axis = self.direction(self.attr(pos, 2)?)?;
                                let t1 = self.attr(c, 2)?.as_list().ok_or("trim")?;
                                let t2 = self.attr(c, 3)?.as_list().ok_or("trim")?;
                                let (a, _) = self.point(first(t1)?)?;
                                let (b, name) = self.point(first(t2)?)?;
                                let sweep = t2.get(1).and_then(Value::as_real).unwrap_or(0.0);
                                let ccw = self.attr(c, 4)?.as_enum() == Some("T");
                                let n = ((sweep.abs() / 360.0 - 1e-9).ceil() as i32).max(1);
                                push(a, b, &name, Some((centre, axis, if ccw { n } else { -n })));
                            }
                            other => return Err(format!("unexpected curve {other}")),
                        }
                    }
                }
                other => return Err(format!("unexpected toolpath curve {other}")),
            }
            for k in first_move..moves.len() {
                axes.push(axis_points.get(k - first_move + 1).copied().unwrap_or([0.0, 0.0, 1.0]));
            }
        }
        let mut tp = Toolpath::new();
        for (m, a) in moves.into_iter().zip(axes) {
            tp.set_axis(a);
            tp.push(m);
        }
        Ok(tp)
    }

    fn contour(&self, v: &Value) -> Result<Contour, String> {
        let c = self.inst(v)?;
        let xy = |p: P3| [p[0], p[1]];
        match c.name.as_str() {
            "POLYLINE" => {
                let pts: Vec<P3> =
                    self.attr(c, 1)?.as_list().ok_or("points")?.iter().map(|p| self.point(p).map(|q| q.0)).collect::<Result<_, _>>()?;
                Ok(Contour {
                    start: xy(*pts.first().ok_or("a polyline without points")?),
                    segments: pts.iter().skip(1).map(|p| Segment { to: xy(*p), arc: None }).collect(),
                })
            }
            "COMPOSITE_CURVE" => {
                let mut start = None;
                let mut segments = Vec::new();
                for seg in self.attr(c, 1)?.as_list().ok_or("segments")? {
                    let s = self.inst(self.attr(self.inst(seg)?, 2)?)?;
                    match s.name.as_str() {
                        "POLYLINE" => {
                            let pts = self.attr(s, 1)?.as_list().ok_or("points")?;
                            start.get_or_insert(xy(self.point(first(pts)?)?.0));
                            segments.push(Segment { to: xy(self.point(last(pts)?)?.0), arc: None });
                        }
                        "TRIMMED_CURVE" => {
                            let circle = self.inst(self.attr(s, 1)?)?;
                            let centre = self.placement(self.attr(circle, 1)?)?;
                            let t1 = self.attr(s, 2)?.as_list().ok_or("trim")?;
                            let t2 = self.attr(s, 3)?.as_list().ok_or("trim")?;
                            start.get_or_insert(xy(self.point(first(t1)?)?.0));
                            let ccw = self.attr(s, 4)?.as_enum() == Some("T");
                            segments.push(Segment { to: xy(self.point(first(t2)?)?.0), arc: Some((xy(centre), ccw)) });
                        }
                        other => return Err(format!("unexpected curve {other}")),
                    }
                }
                Ok(Contour { start: start.unwrap_or([0.0; 2]), segments })
            }
            other => Err(format!("unexpected profile curve {other}")),
        }
    }

    /// The features a turning workingstep machines besides its own (its `features=` word),
    /// found by their numbers among the file's features.
    fn more_turned_features(
        &self,
        w: &BTreeMap<String, String>,
        index: u32,
        plan: &mut ProcessPlan,
        feature_ids: &mut BTreeMap<u64, u32>,
    ) -> Result<(), String> {
        let Some(list) = w.get("features") else { return Ok(()) };
        for n in list.split(',').filter_map(|v| v.parse::<u32>().ok()) {
            if !plan.features.iter().any(|f| f.id == n) {
                let found = self.x.instances.iter().find(|(_, i)| {
                    matches!(i.name.as_str(), "TOOLPATH_FEATURE" | "ROUND_HOLE")
                        && self.string(i, 0).ok().and_then(|s| feature_number(&s)) == Some(n)
                });
                let Some((fid, inst)) = found else { return Err(format!("feature F{n} is not in the file")) };
                feature_ids.insert(*fid, n);
                plan.features.push(self.feature(inst, n)?);
            }
            if let Some(f) = plan.features.iter_mut().find(|f| f.id == n) {
                f.workingsteps.push(index);
            }
        }
        Ok(())
    }

    /// The features a TURNING_WORKINGSTEP lists after its own, numbered by their identifiers.
    fn listed_turned_features(
        &self,
        listed: &[Value],
        index: u32,
        plan: &mut ProcessPlan,
        feature_ids: &mut BTreeMap<u64, u32>,
    ) -> Result<(), String> {
        for v in listed {
            let fid = v.as_ref_id().ok_or("a feature that is no reference")?;
            let inst = self.inst(v)?;
            let n = match feature_ids.get(&fid) {
                Some(n) => *n,
                None => {
                    let n = feature_number(&self.string(inst, 0)?).ok_or("a turned feature without its number")?;
                    feature_ids.insert(fid, n);
                    plan.features.push(self.feature(inst, n)?);
                    n
                }
            };
            if let Some(f) = plan.features.iter_mut().find(|f| f.id == n) {
                f.workingsteps.push(index);
            }
        }
        Ok(())
    }

    fn feature(&self, f: &Instance, id: u32) -> Result<Feature, String> {
        let (_, w) = words(&self.string(f, 0)?);
        let top_inferred = w.get("top").is_some_and(|v| v == "inferred");
        let placement = self.placement(self.attr(f, 3)?)?;
        let axes = self.placement_axes(self.attr(f, 3)?)?;
        let turned = self.turned_feature(f)?;
        let depth = match &turned {
            Some((_, depth)) => *depth,
            None if f.name == "GENERAL_PATTERN" => 0.0,
            None => -self.plane_z(self.attr(f, 4)?)?,
        };
        let mut feature = Feature {
            id,
            kind: FeatureKind::Toolpath,
            placement,
            depth,
            top_inferred,
            workingsteps: Vec::new(),
            source: TextRange::default(),
            lines: (0, 0),
            sources: Sources {
                size: w.get("size_from").and_then(|v| Source::parse(v)).unwrap_or_default(),
                top: w.get("top_from").and_then(|v| Source::parse(v)).unwrap_or_default(),
                point_angle: w.get("point_angle_from").and_then(|v| Source::parse(v)),
            },
            centre_path: w.get("centre_path").and_then(|v| {
                let (a, b) = v.split_once('x')?;
                Some((a.parse().ok()?, b.parse().ok()?))
            }),
            axis: axes.map(|a| a.0),
            ref_direction: axes.map(|a| a.1),
            wrap: w.get("wrap").and_then(|v| {
                let n: Vec<f64> = v.split('x').map(str::parse).collect::<Result<_, _>>().ok()?;
                let [diameter, from, to, developed] = n[..] else { return None };
                Some(crate::plan::Wrap { diameter, angles: (from, to), developed })
            }),
        };
        let hole = |h: &Instance, positions: Vec<P2>, heights: Vec<f64>| -> Result<FeatureKind, String> {
            let d = self.tlm(self.attr(h, 5)?)?;
            let bottom = self.inst(self.attr(h, 7)?)?;
            let bottom = match bottom.name.as_str() {
                "THROUGH_BOTTOM_CONDITION" => HoleBottom::Through,
                "CONICAL_HOLE_BOTTOM" => HoleBottom::Conical(self.real(bottom, 0)?),
                _ => HoleBottom::Flat,
            };
            Ok(FeatureKind::RoundHole { diameter: (d != 0.0).then_some(d), bottom, positions, heights })
        };
        if let Some((t, _)) = turned {
            feature.kind = FeatureKind::Turned(t);
            return Ok(feature);
        }
        feature.kind = match f.name.as_str() {
            "ROUND_HOLE" => hole(f, vec![[0.0, 0.0]], Vec::new())?,
            "GENERAL_PATTERN" => {
                let base = self.inst(self.attr(f, 4)?)?;
                feature.depth = -self.plane_z(self.attr(base, 4)?)?;
                let located = self
                    .attr(f, 5)?
                    .as_list()
                    .ok_or("pattern locations")?
                    .iter()
                    .map(|p| self.placement(p))
                    .collect::<Result<Vec<_>, _>>()?;
                let positions = located.iter().map(|q| [q[0], q[1]]).collect();
                let heights = if located.iter().any(|q| q[2] != 0.0) { located.iter().map(|q| q[2]).collect() } else { Vec::new() };
                hole(base, positions, heights)?
            }
            "PLANAR_FACE" => {
                let course = self.inst(self.attr(f, 5)?)?;
                let length = self.tlm(self.attr(course, 1)?)?;
                let direction = self.direction(self.attr(course, 2)?)?;
                let removal = self.inst(self.attr(f, 6)?)?;
                let width = self.real(self.inst(self.attr(removal, 1)?)?, 1)?;
                FeatureKind::PlanarFace { direction, length, width }
            }
            "CLOSED_POCKET" => {
                let corner_radius = match self.attr(f, 8)? {
                    Value::Null => None,
                    v => Some(self.tlm(v)?),
                };
                let profile = self.inst(self.attr(f, 10)?)?;
                if profile.name == "RECTANGULAR_CLOSED_PROFILE" {
                    let (wd, l) = (self.tlm(self.attr(profile, 1)?)?, self.tlm(self.attr(profile, 2)?)?);
                    FeatureKind::ClosedPocket {
                        boundary: plan::feature::rect_contour(wd, l, corner_radius),
                        rectangle: Some((wd, l)),
                        corner_radius,
                    }
                } else {
                    FeatureKind::ClosedPocket { boundary: self.contour(self.attr(profile, 1)?)?, rectangle: None, corner_radius }
                }
            }
            "OPEN_POCKET" => {
                let profile = self.inst(self.attr(f, 10)?)?;
                FeatureKind::OpenPocket { boundary: self.contour(self.attr(profile, 1)?)? }
            }
            "SLOT" => {
                let course = self.inst(self.attr(f, 5)?)?;
                let shape = self.inst(self.attr(f, 6)?)?;
                FeatureKind::Slot { path: self.contour(self.attr(course, 1)?)?, width: self.tlm(self.attr(shape, 1)?)? }
            }
            "STEP" => {
                let edge = self.inst(self.attr(f, 5)?)?;
                let width = w.get("width").and_then(|v| v.parse().ok()).unwrap_or(0.0);
                FeatureKind::Step { direction: self.direction(self.attr(edge, 2)?)?, length: self.tlm(self.attr(edge, 1)?)?, width }
            }
            "GENERAL_OUTSIDE_PROFILE" => {
                let profile = self.inst(self.attr(f, 6)?)?;
                let boundary = self.contour(self.attr(profile, 1)?)?;
                // A rectangle's sizes, as the plan gives them where its size is known.
                let known = feature.sources.size != Source::Unknown;
                let (rectangle, corner_radius) =
                    plan::feature::rectangle_of(&boundary).filter(|_| known).map_or((None, None), |(r, c)| (Some(r), c));
                FeatureKind::OutsideProfile { boundary, rectangle, corner_radius }
            }
            "TOOLPATH_FEATURE" => match w.get("turned").and_then(|v| from_json_word(v)) {
                Some(t) => FeatureKind::Turned(t),
                None => FeatureKind::Toolpath,
            },
            other => return Err(format!("unknown feature {other}")),
        };
        Ok(feature)
    }
}

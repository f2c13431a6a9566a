//! Turning in STEP-NC: ISO 14649-121 operations, technology, machine functions and tools,
//! and ISO 14649-12 turned features, written and read back.
//!
//! - **Operations** (CC2): a turning workingstep's operation is FACING_ROUGH/FINISH,
//!   CONTOURING_ROUGH/FINISH, GROOVING_ROUGH/FINISH, THREADING_ROUGH/FINISH or CUTTING_IN
//!   (parting off, its depth the radial depth cut); drilling on the axis is ISO 14649-11's
//!   DRILLING. Each carries an EXPLICIT_TURNING_STRATEGY (its toolpath rides along, the
//!   depth of cut where the cycle states one), the cycle's retract as its return amount and
//!   the finishing allowance a roughing cycle states (radial: half the X allowance when it
//!   cuts along Z, the Z allowance when it faces). A workingstep that machines several
//!   features is a TURNING_WORKINGSTEP listing them (its own first).
//! - **Technology**: TURNING_TECHNOLOGY with the feed per revolution, a CONST_CUTTING_SPEED
//!   (m/s) whose `max_speed` is the spindle value (the clamp ncplan keeps as the speed), or a
//!   CONST_SPINDLE_SPEED; spindle values in rev/s, negative clockwise as for milling; the
//!   feed synchronised with the spindle (`sync_spindle_and_z_feed`) where the workingstep
//!   cuts a lead, the lead being its feed per revolution when no other is stated.
//!   TURNING_MACHINE_FUNCTIONS with the coolant and its type.
//! - **Tools** (both classes): TURNING_MACHINE_TOOL with a GENERAL_TURNING_TOOL,
//!   GROOVING_TOOL (cutting width), TURNING_THREADING_TOOL (pitch, angle) body and the nose
//!   radius in its TURNING_TOOL_DIMENSION; a grooving tool whose width, or a threading tool
//!   whose pitch, is unknown is a USER_DEFINED_TURNING_TOOL (both attributes are mandatory).
//! - **Features** (CC2): REVOLVED_FLAT (radius the outer one, the flat's radial length as
//!   its profile), OUTER_DIAMETER, REVOLVED_ROUND (a quarter circle: the plan keeps no
//!   sweep), GROOVE (a SQUARE_U_PROFILE of its width, 0 where unknown; material side
//!   outward for an inner groove; a face groove, which ISO 14649-12 has no entity for, is a
//!   GROOVE whose material side is along -Z, into the face: placed at its floor, its radius
//!   the outer wall's and its SQUARE_U_PROFILE the radial width to the inner wall, 0 where it
//!   was plunged at one diameter; so a reader of the schema still finds a groove of that
//!   width and depth, and the U's sweep lies on the face), and GENERAL_REVOLUTION with its profile in the plane
//!   through the axis: the region turned (material side unstated), or an inner diameter
//!   (material side outward: this draft of ISO 14649-12 has no inner diameter, and a
//!   ROUND_HOLE needs a bottom the program does not state).
//!
//! What the schema cannot hold travels as identifier words: the cycle's code and its words
//! as the interpreter read them (X and Z allowances apart, thread heights, pecks), passes,
//! the diameters and Z range cut, the inside flag, a lead that differs from the feed per
//! revolution, and the **thread** feature. ISO 14649-10's THREAD needs a pitch diameter, a
//! fit class, a hand and the hole or boss it is cut on, none of which a program states: it
//! stays a TOOLPATH_FEATURE with its `turned=` word (its operation and tool are ISO entities).

use std::collections::BTreeMap;

use super::{Reader, Writer, from_json_word, json_word, snap};
use crate::part21::{Instance, Value};
use crate::plan::*;

/// The turning workingstep's values ISO 14649-121 does not hold, as one JSON word: the
/// operation, roughing and the feed per revolution are entities and attributes.
pub(super) fn rest_word(t: &Turning) -> String {
    let mut rest = serde_json::to_value(Turning { feed_per_rev: None, ..t.clone() }).unwrap_or_default();
    if let Some(m) = rest.as_object_mut() {
        m.remove("operation");
        m.remove("rough");
    }
    json_word(&rest)
}

/// The operation entity of a turning workingstep.
fn operation_name(t: &Turning) -> &'static str {
    match (t.operation, t.rough) {
        (Some(TurnOp::Facing), true) => "FACING_ROUGH",
        (Some(TurnOp::Facing), false) => "FACING_FINISH",
        (Some(TurnOp::Grooving), true) => "GROOVING_ROUGH",
        (Some(TurnOp::Grooving), false) => "GROOVING_FINISH",
        (Some(TurnOp::Threading), true) => "THREADING_ROUGH",
        (Some(TurnOp::Threading), false) => "THREADING_FINISH",
        (Some(TurnOp::PartingOff), _) => "CUTTING_IN",
        (Some(TurnOp::Drilling), _) => "DRILLING",
        (Some(TurnOp::Contouring) | None, true) => "CONTOURING_ROUGH",
        (Some(TurnOp::Contouring) | None, false) => "CONTOURING_FINISH",
    }
}

/// The operation and roughing an entity's name states, for the turning entities.
pub(super) fn operation_of(name: &str) -> Option<(TurnOp, bool)> {
    Some(match name {
        "FACING_ROUGH" => (TurnOp::Facing, true),
        "FACING_FINISH" => (TurnOp::Facing, false),
        "GROOVING_ROUGH" => (TurnOp::Grooving, true),
        "GROOVING_FINISH" => (TurnOp::Grooving, false),
        "THREADING_ROUGH" => (TurnOp::Threading, true),
        "THREADING_FINISH" => (TurnOp::Threading, false),
        "CUTTING_IN" => (TurnOp::PartingOff, false),
        "CONTOURING_ROUGH" => (TurnOp::Contouring, true),
        "CONTOURING_FINISH" => (TurnOp::Contouring, false),
        _ => return None,
    })
}

/// The tools written as ISO 14649-121 turning tools — turning, grooving and threading tools,
/// and boring bars that only turn (ISO 14649-111's boring tools are milling heads) — each
/// with the lead of the threads it cuts where they share one.
pub(super) fn lathe_tools(plan: &ProcessPlan) -> BTreeMap<u32, Option<f64>> {
    let mut out = BTreeMap::new();
    for t in &plan.tools {
        let steps: Vec<&Workingstep> = plan.workingsteps.iter().filter(|w| w.tool == t.number).collect();
        let turns = |w: &&Workingstep| w.turning.as_ref().is_some_and(|x| x.operation.is_some_and(|o| o != TurnOp::Drilling));
        let lathe = match t.kind {
            ToolKind::TurningTool | ToolKind::GroovingTool | ToolKind::ThreadingTool => true,
            ToolKind::BoringTool => !steps.is_empty() && steps.iter().all(turns),
            _ => false,
        };
        if lathe {
            let leads: Vec<f64> = steps.iter().filter_map(|w| w.turning.as_ref().and_then(|x| x.pitch)).collect();
            out.insert(t.number, leads.first().copied().filter(|p| leads.iter().all(|q| q == p)));
        }
    }
    out
}

fn signed_rev_s(speed: f64, dir: SpindleDir) -> f64 {
    match dir {
        SpindleDir::Cw => -speed / 60.0,
        SpindleDir::Ccw => speed / 60.0,
        SpindleDir::Off => 0.0,
    }
}

/// The feed per revolution attribute: the stated one, else the lead of a synchronised cut.
/// The second value says the lead stands in for it.
fn feed_per_rev(t: &Turning) -> (Option<f64>, bool) {
    match (t.feed_per_rev, t.pitch) {
        (Some(f), _) => (Some(f), false),
        (None, Some(p)) => (Some(p), true),
        (None, None) => (None, false),
    }
}

impl<W: std::io::Write> Writer<W> {
    /// TURNING_TECHNOLOGY of a turning workingstep, shared between equal ones.
    pub(super) fn turning_technology(&mut self, tech: &Technology, t: &Turning) -> Value {
        let (fpr, _) = feed_per_rev(t);
        let key =
            format!("{:?} {:?} {:?} {:?} {:?}", tech.feed, tech.spindle_speed, tech.spindle, tech.surface_speed, (fpr, t.pitch.is_some()));
        if let Some(v) = self.turning_tech.get(&key) {
            return v.clone();
        }
        let rev_s = signed_rev_s(tech.spindle_speed, tech.spindle);
        let speed = match tech.surface_speed {
            Some(v) => self.b.add("CONST_CUTTING_SPEED", vec![Value::Real(v / 60.0), Value::Real(rev_s)]),
            None => self.b.add("CONST_SPINDLE_SPEED", vec![Value::Real(rev_s)]),
        };
        let v = self.b.add(
            "TURNING_TECHNOLOGY",
            vec![
                Value::Real(tech.feed / 60_000.0),
                Value::Enum("TCP".into()),
                speed,
                Value::opt_real(fpr),
                Value::bool(t.pitch.is_some()),
                Value::bool(false),
                Value::bool(false),
            ],
        );
        self.turning_tech.insert(key, v.clone());
        v
    }

    /// TURNING_MACHINE_FUNCTIONS for a coolant state.
    pub(super) fn turning_functions(&mut self, c: Coolant) -> Value {
        let key = c as u8 + 16;
        if let Some(v) = self.functions.get(&key) {
            return v.clone();
        }
        let (on, ty) = match c {
            Coolant::Off => (false, None),
            Coolant::Mist => (true, Some("MIST")),
            Coolant::Flood => (true, Some("FLOOD")),
            // Flood and mist at once has no literal: the operation's `coolant=both` word says it.
            Coolant::Both => (true, None),
        };
        let v = self.b.add(
            "TURNING_MACHINE_FUNCTIONS",
            vec![
                Value::bool(on),
                ty.map_or(Value::Null, |t| Value::Enum(t.into())),
                Value::Null,
                Value::List(vec![]),
                Value::bool(false),
                Value::Null,
                Value::Null,
                Value::List(vec![]),
                Value::Null,
                Value::Null,
                Value::Null,
            ],
        );
        self.functions.insert(key, v.clone());
        v
    }

    /// The words of a turning operation's identifier beside the ones every operation has.
    pub(super) fn turning_op_words(ws: &Workingstep, t: &Turning, id: &mut String) {
        if feed_per_rev(t).1 {
            id.push_str(" fpr=pitch");
        }
        if ws.technology.coolant == Coolant::Both {
            id.push_str(" coolant=both");
        }
    }

    /// A turning operation (not drilling): the attributes every operation has, then its own.
    pub(super) fn turning_operation(&mut self, ws: &Workingstep, t: &Turning, mut attrs: Vec<Value>) -> Value {
        let intent = t.intent.as_ref();
        let doc = intent.and_then(|i| i.depth_of_cut.or(i.first_cut));
        let depths = doc.map_or(vec![], |d| vec![Value::Real(d)]);
        let strategy = self.b.add("EXPLICIT_TURNING_STRATEGY", vec![Value::Null, Value::bool(t.passes > 1), Value::List(depths)]);
        attrs.extend([Value::Null, Value::Null, strategy]);
        let facing = intent.and_then(|i| i.kind) == Some(crate::canon::TurnKind::RoughFace) || t.operation == Some(TurnOp::Facing);
        let retract = intent.and_then(|i| i.retract);
        let (x_return, z_return) = if facing { (None, retract) } else { (retract, None) };
        let allowance = intent.and_then(|i| if facing { i.allowance_z } else { i.allowance_x.map(|a| a / 2.0) }).filter(|_| t.rough);
        let r = Value::opt_real;
        match t.operation {
            Some(TurnOp::Facing) => attrs.extend([r(x_return), r(z_return), r(allowance)]),
            Some(TurnOp::Grooving) => {
                let dwell = ws.state.dwells.first().map(|d| self.b.add("DWELL_TIME", vec![Value::Real(d.seconds)]));
                attrs.extend([r(retract), dwell.unwrap_or(Value::Null), r(allowance)]);
            }
            Some(TurnOp::Threading) => {
                attrs.extend([r(retract), r(intent.and_then(|i| i.finish_allowance).filter(|_| t.rough))]);
            }
            Some(TurnOp::PartingOff) => {
                let depth = t.diameter.map_or(0.0, |d| (d[1] - d[0]) / 2.0);
                let depth = self.tlm(depth);
                let inward = self.direction([-1.0, 0.0, 0.0]);
                attrs.extend([depth, inward, Value::Null]);
            }
            _ => attrs.extend([r(x_return), r(z_return), Value::Null, r(allowance)]),
        }
        self.b.add(operation_name(t), attrs)
    }

    /// An ISO 14649-121 tool: a turning machine tool with its body.
    pub(super) fn turning_tool(&mut self, t: &Tool, lead: Option<f64>, mut id: String, component: Value) -> Value {
        let mut dim = vec![Value::Null; 9];
        dim.extend([Value::opt_real(t.corner_radius), Value::Null]);
        let dim = self.b.add("TURNING_TOOL_DIMENSION", dim);
        let mut body = vec![dim, Value::Null, Value::Null, Value::Null, Value::Null, Value::Null, Value::Null];
        let name = match t.kind {
            ToolKind::GroovingTool => match crate::plan::turning::tool_width(t) {
                Some(w) => {
                    body.extend([Value::Real(w), Value::Null]);
                    "GROOVING_TOOL"
                }
                None => {
                    body.push(Value::str("grooving tool"));
                    "USER_DEFINED_TURNING_TOOL"
                }
            },
            ToolKind::ThreadingTool => match lead {
                Some(p) => {
                    body.extend([Value::Real(p), Value::opt_real(t.point_angle)]);
                    "TURNING_THREADING_TOOL"
                }
                None => {
                    body.push(Value::str("threading tool"));
                    "USER_DEFINED_TURNING_TOOL"
                }
            },
            _ => "GENERAL_TURNING_TOOL",
        };
        let body = self.b.add(name, body);
        // A lathe tool has no diameter attribute (a tool table's is the nose's).
        if let Some(d) = t.diameter {
            id.push_str(&format!(" diameter={d}"));
        }
        if let Some(n) = t.flutes {
            id.push_str(&format!(" flutes={n}"));
        }
        if let Some(n) = &t.name {
            id.push_str(" name=");
            id.push_str(n);
        }
        self.b.add("TURNING_MACHINE_TOOL", vec![Value::str(id), body, Value::List(vec![component]), Value::Null, Value::Null, Value::Null])
    }

    /// A turned feature as its ISO 14649-12 entity; `None` for a thread (see the module).
    pub(super) fn turned_feature(&mut self, f: &Feature, t: &Turned, id: String, workpiece: &Value, ops: Vec<Value>) -> Option<Value> {
        let axis = f.axis.unwrap_or([0.0, 0.0, 1.0]);
        let place = self.placement_ref(f.placement, Some(axis), f.ref_direction);
        let mut attrs = vec![Value::str(id), workpiece.clone(), Value::List(ops), place];
        let name = match t {
            Turned::RevolvedFlat { outer, inner } => {
                let radius = self.tlm(outer / 2.0);
                let len = self
                    .b
                    .add("NUMERIC_PARAMETER", vec![Value::str("radial length"), Value::Real((outer - inner) / 2.0), Value::str("mm")]);
                let shape = self.b.add("LINEAR_PROFILE", vec![Value::Null, len]);
                attrs.extend([Value::Null, radius, shape]);
                "REVOLVED_FLAT"
            }
            Turned::Diameter { diameter, length, inside: false } => {
                let (d, l) = (self.tlm(*diameter), self.tlm(*length));
                attrs.extend([d, l, Value::Null]);
                "OUTER_DIAMETER"
            }
            Turned::Diameter { diameter, length, inside: true } => {
                let side = self.direction([1.0, 0.0, 0.0]);
                let radius = self.tlm(diameter / 2.0);
                let profile = self.profile(&[[diameter / 2.0, 0.0], [diameter / 2.0, -length]]);
                attrs.extend([side, radius, profile]);
                "GENERAL_REVOLUTION"
            }
            Turned::RevolvedRound { radius, diameter } => {
                let at = self.tlm(diameter / 2.0);
                let r = self.tlm(*radius);
                let shape = self.b.add("PARTIAL_CIRCULAR_PROFILE", vec![Value::Null, r, Value::Real(90.0)]);
                attrs.extend([Value::Null, at, shape]);
                "REVOLVED_ROUND"
            }
            Turned::Groove { diameter, width, inside } => {
                let side = self.direction([if *inside { 1.0 } else { -1.0 }, 0.0, 0.0]);
                let radius = self.tlm(diameter / 2.0);
                let w = self.tlm(width.unwrap_or(0.0));
                let (r1, r2) = (self.tlm(0.0), self.tlm(0.0));
                let sweep = self.b.add("SQUARE_U_PROFILE", vec![Value::Null, w, r1, Value::Real(90.0), r2, Value::Real(90.0)]);
                attrs.extend([side, radius, sweep]);
                "GROOVE"
            }
            Turned::FaceGroove { outer, .. } => {
                let side = self.direction([0.0, 0.0, -1.0]);
                let radius = self.tlm(outer / 2.0);
                let w = self.tlm(t.face_groove_width().unwrap_or(0.0));
                let (r1, r2) = (self.tlm(0.0), self.tlm(0.0));
                let sweep = self.b.add("SQUARE_U_PROFILE", vec![Value::Null, w, r1, Value::Real(90.0), r2, Value::Real(90.0)]);
                attrs.extend([side, radius, sweep]);
                "GROOVE"
            }
            Turned::Revolution { outer, inner, length } => {
                let radius = self.tlm(outer / 2.0);
                let (ro, ri) = (outer / 2.0, inner / 2.0);
                let profile = self.profile(&[[ro, 0.0], [ro, -length], [ri, -length], [ri, 0.0]]);
                attrs.extend([Value::Null, radius, profile]);
                "GENERAL_REVOLUTION"
            }
            Turned::Thread { .. } => return None,
        };
        Some(self.b.add(name, attrs))
    }

    /// A GENERAL_PROFILE in the plane through the axis: points (radius, z) in the feature's frame.
    fn profile(&mut self, points: &[[f64; 2]]) -> Value {
        let points: Vec<Value> = points.iter().map(|p| self.point("", [p[0], 0.0, p[1]])).collect();
        let line = self.b.add("POLYLINE", vec![Value::str(""), Value::List(points)]);
        self.b.add("GENERAL_PROFILE", vec![Value::Null, line])
    }
}

/// What a turning technology states, read back.
pub(super) struct TurningTech {
    pub feed: f64,
    pub rev_s: f64,
    pub surface_speed: Option<f64>,
    pub feed_per_rev: Option<f64>,
}

impl Reader<'_> {
    /// TURNING_TECHNOLOGY's feed (mm/min), signed spindle (rev/s), cutting speed (m/min) and
    /// feed per revolution.
    pub(super) fn turning_technology(&self, tech: &Instance) -> Result<TurningTech, String> {
        let feed = snap(self.real(tech, 0)? * 60_000.0);
        let speed = self.inst(self.attr(tech, 2)?)?;
        let (rev_s, surface_speed) = match speed.name.as_str() {
            "CONST_CUTTING_SPEED" => (self.opt_real(speed, 1)?.unwrap_or(0.0), Some(snap(self.real(speed, 0)? * 60.0))),
            _ => (self.real(speed, 0)?, None),
        };
        Ok(TurningTech { feed, rev_s, surface_speed, feed_per_rev: self.opt_real(tech, 3)? })
    }

    /// The coolant TURNING_MACHINE_FUNCTIONS states (`both` from the operation's word).
    pub(super) fn turning_coolant(&self, mf: &Instance, both: bool) -> Result<Coolant, String> {
        if both {
            return Ok(Coolant::Both);
        }
        Ok(match (self.attr(mf, 0)?.as_enum(), self.attr(mf, 1)?.as_enum()) {
            (Some("T"), Some("MIST")) => Coolant::Mist,
            (Some("T"), _) => Coolant::Flood,
            _ => Coolant::Off,
        })
    }

    /// A turning workingstep's values: the operation from the entity, the rest from its word.
    pub(super) fn turning(&self, op: (TurnOp, bool), word: Option<&String>, fpr: Option<f64>, fpr_is_pitch: bool) -> Turning {
        let mut t: Turning = word.and_then(|w| from_json_word(w)).unwrap_or_default();
        t.operation = Some(op.0);
        t.rough = op.1;
        t.feed_per_rev = fpr.filter(|_| !fpr_is_pitch);
        t
    }

    /// A turning tool's nose radius (its dimension's), and the body's name.
    pub(super) fn turning_tool_radius(&self, body: &Instance) -> Result<Option<f64>, String> {
        let dim = self.inst(self.attr(body, 0)?)?;
        self.opt_real(dim, 9)
    }

    /// A turned feature from its ISO 14649-12 entity, with its depth (the length along Z of a
    /// diameter, 0 else); `None` for other entities.
    pub(super) fn turned_feature(&self, f: &Instance) -> Result<Option<(Turned, f64)>, String> {
        let radius = |k: usize| -> Result<f64, String> { Ok(snap(2.0 * self.tlm(self.attr(f, k)?)?)) };
        let inward = |k: usize| -> Result<Option<bool>, String> {
            match self.attr(f, k)? {
                Value::Null => Ok(None),
                d => Ok(Some(self.direction(d)?[0] > 0.0)),
            }
        };
        Ok(Some(match f.name.as_str() {
            "REVOLVED_FLAT" => {
                let outer = radius(5)?;
                let len = self.real(self.inst(self.attr(self.inst(self.attr(f, 6)?)?, 1)?)?, 1)?;
                (Turned::RevolvedFlat { outer, inner: snap(outer - 2.0 * len) }, 0.0)
            }
            "OUTER_DIAMETER" => {
                let (diameter, length) = (self.tlm(self.attr(f, 4)?)?, self.tlm(self.attr(f, 5)?)?);
                (Turned::Diameter { diameter, length, inside: false }, length)
            }
            "REVOLVED_ROUND" => {
                let shape = self.inst(self.attr(f, 6)?)?;
                (Turned::RevolvedRound { radius: self.tlm(self.attr(shape, 1)?)?, diameter: radius(5)? }, 0.0)
            }
            "GROOVE" => {
                let sweep = self.inst(self.attr(f, 6)?)?;
                let width = self.tlm(self.attr(sweep, 1)?)?;
                // Its material side along the axis: a face groove (see the module).
                let along_axis = match self.attr(f, 4)? {
                    Value::Null => false,
                    d => self.direction(d)?[2].abs() > 0.5,
                };
                if along_axis {
                    let outer = radius(5)?;
                    return Ok(Some((Turned::FaceGroove { outer, inner: snap(outer - 2.0 * width) }, 0.0)));
                }
                let inside = inward(4)?.unwrap_or(false);
                (Turned::Groove { diameter: radius(5)?, width: (width != 0.0).then_some(width), inside }, 0.0)
            }
            "GENERAL_REVOLUTION" => {
                let profile = self.inst(self.attr(f, 6)?)?;
                let line = self.inst(self.attr(profile, 1)?)?;
                let points: Vec<P3> = self
                    .attr(line, 1)?
                    .as_list()
                    .ok_or("a profile without points")?
                    .iter()
                    .map(|p| self.point(p).map(|x| x.0))
                    .collect::<Result<_, _>>()?;
                let get = |k: usize| points.get(k).copied().ok_or_else(|| "a short profile".to_owned());
                if inward(4)?.unwrap_or(false) {
                    let length = snap(-get(1)?[2]);
                    (Turned::Diameter { diameter: radius(5)?, length, inside: true }, length)
                } else {
                    (Turned::Revolution { outer: radius(5)?, inner: snap(2.0 * get(2)?[0]), length: snap(-get(1)?[2]) }, 0.0)
                }
            }
            _ => return Ok(None),
        }))
    }
}

/// The features of a workingstep in the order a TURNING_WORKINGSTEP lists them: its own,
/// then the others it machines by number.
pub(super) fn features_of(plan: &ProcessPlan, ws: &Workingstep, written: &BTreeMap<u32, Value>) -> Vec<Value> {
    let own = ws.feature.and_then(|f| written.get(&f).cloned());
    let more = plan
        .features
        .iter()
        .filter(|f| Some(f.id) != ws.feature && f.workingsteps.contains(&ws.index))
        .filter_map(|f| written.get(&f.id).cloned());
    own.into_iter().chain(more).collect()
}

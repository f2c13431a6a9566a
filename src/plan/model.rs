//! The process-plan model (ISO 14649 in spirit): tools, workingsteps, technology, toolpaths.
//! All lengths are millimetres, feeds mm/min, speeds 1/min.

use serde::{Deserialize, Serialize};

use crate::canon::{CycleKind, Units};
use crate::text::TextRange;

/// A point in millimetres.
pub type P3 = [f64; 3];

/// A recovered process plan.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct ProcessPlan {
    /// Program number or name, when the program states one.
    pub program: Option<String>,
    /// Units the program was written in.
    pub units: Option<Units>,
    /// Tools used, by number.
    pub tools: Vec<Tool>,
    /// Workingsteps in machining order.
    pub workingsteps: Vec<Workingstep>,
}

/// Where a tool fact came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ToolSource {
    /// The configured tool table.
    Table,
    /// A CAM comment in the program.
    Comment,
    /// Nothing but the tool number is known.
    Unknown,
}

/// A cutting tool.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tool {
    /// Tool number (T word).
    pub number: u32,
    /// Name or description.
    pub name: Option<String>,
    /// Cutter diameter, mm.
    pub diameter: Option<f64>,
    /// Where the facts came from.
    pub source: ToolSource,
}

/// What a workingstep does.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Operation {
    /// Planar facing: parallel passes at one depth.
    FaceMilling,
    /// Contour milling with arcs.
    ContourMilling,
    /// Other milling.
    Milling,
    /// A hole-making canned cycle.
    Hole(CycleKind),
}

impl Operation {
    /// Human label.
    pub fn label(self) -> &'static str {
        match self {
            Operation::FaceMilling => "face milling",
            Operation::ContourMilling => "contour milling",
            Operation::Milling => "milling",
            Operation::Hole(k) => k.label(),
        }
    }

    /// Whether two operations are of the same family (milling or hole making).
    pub fn same_family(self, other: Operation) -> bool {
        matches!(self, Operation::Hole(_)) == matches!(other, Operation::Hole(_))
    }
}

/// Spindle direction.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpindleDir {
    /// Clockwise (M3).
    Cw,
    /// Counter-clockwise (M4).
    Ccw,
    /// Stopped.
    Off,
}

/// Coolant.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Coolant {
    /// Off.
    Off,
    /// Mist (M7).
    Mist,
    /// Flood (M8).
    Flood,
    /// Mist and flood.
    Both,
}

/// Cutting technology of a workingstep.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Technology {
    /// Feed at the first cutting move, mm/min.
    pub feed: f64,
    /// Every distinct feed of the cutting moves, in order of first use.
    pub feeds: Vec<f64>,
    /// Spindle speed, 1/min.
    pub spindle_speed: f64,
    /// Spindle direction.
    pub spindle: SpindleDir,
    /// Coolant.
    pub coolant: Coolant,
}

/// Kind of move.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MoveKind {
    /// Rapid traverse.
    Rapid,
    /// Straight feed.
    Line,
    /// Circular or helical feed.
    Arc,
}

/// Role of a move within its workingstep.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Phase {
    /// Moving to the start point.
    Approach,
    /// Removing material.
    Cut,
    /// Repositioning between cuts.
    Connect,
    /// Leaving the workpiece.
    Retract,
}

/// One move of a toolpath.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Move {
    /// Kind.
    pub kind: MoveKind,
    /// Phase.
    pub phase: Phase,
    /// Start point, mm.
    pub from: P3,
    /// End point, mm.
    pub to: P3,
    /// Arc centre (on the arc's plane through `from`), mm.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub center: Option<P3>,
    /// Arc axis (unit normal); with `turns`, positive is counter-clockwise about it.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub axis: Option<P3>,
    /// Arc turns, signed.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub turns: Option<i32>,
    /// 1-based source line.
    pub line: u32,
}

/// A drilled or bored hole.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Hole {
    /// Position, mm.
    pub x: f64,
    /// Position, mm.
    pub y: f64,
    /// Bottom, mm.
    pub bottom: f64,
    /// Feed-start plane, mm.
    pub r_plane: f64,
    /// Peck increment, mm.
    pub peck: Option<f64>,
}

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct BBox {
    /// Minimum corner.
    pub min: P3,
    /// Maximum corner.
    pub max: P3,
}

/// A workingstep: one operation with one tool and one technology.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Workingstep {
    /// 1-based position in the plan.
    pub index: u32,
    /// Operation.
    pub operation: Operation,
    /// Tool number.
    pub tool: u32,
    /// Technology.
    pub technology: Technology,
    /// First cutting position after the approach, mm.
    pub start_point: Option<P3>,
    /// Lowest cutting Z, mm.
    pub depth: Option<f64>,
    /// Bounding box of the cutting moves, mm.
    pub bbox: Option<BBox>,
    /// Length of the cutting moves, mm.
    pub cutting_length: f64,
    /// Holes, for hole-making operations.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub holes: Vec<Hole>,
    /// The explicit toolpath.
    pub toolpath: Vec<Move>,
    /// Source range covered by the workingstep's blocks.
    pub source: TextRange,
    /// First and last source line.
    pub lines: (u32, u32),
}

//! The process-plan model (ISO 14649 in spirit): tools, workingsteps, technology, toolpaths.
//! All lengths are millimetres, feeds mm/min, speeds 1/min.

use serde::{Deserialize, Serialize};

use super::setup::Setup;
pub use crate::canon::SpindleId;
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
    /// Features the workingsteps machine, in order of first machining.
    #[serde(default)]
    pub features: Vec<Feature>,
    /// The raw stock, when config or the program states it.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub workpiece: Option<Stock>,
}

impl ProcessPlan {
    /// The tool with this number.
    pub fn tool(&self, number: u32) -> Option<&Tool> {
        self.tools.iter().find(|t| t.number == number)
    }

    /// The feature with this id.
    pub fn feature(&self, id: u32) -> Option<&Feature> {
        self.features.iter().find(|f| f.id == id)
    }
}

/// Where the stock's size came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StockSource {
    /// The configuration.
    Config,
    /// A statement or comment of the program (`BLK FORM`, a CAM stock comment).
    Program,
}

/// The raw stock: an axis-aligned block in program coordinates, mm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Stock {
    /// Minimum corner.
    pub origin: P3,
    /// Size along X, Y and Z.
    pub size: P3,
    /// Where it came from.
    pub source: StockSource,
    /// The program line that states it (`BLK FORM`, `WORKPIECE`, a stock comment).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub line: Option<u32>,
}

impl Stock {
    /// Maximum corner.
    pub fn max(&self) -> P3 {
        [self.origin[0] + self.size[0], self.origin[1] + self.size[1], self.origin[2] + self.size[2]]
    }
}

/// A point in the XY plane, mm.
pub type P2 = [f64; 2];

/// One segment of a [`Contour`]: a line or an arc to `to`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Segment {
    /// End point.
    pub to: P2,
    /// For an arc: its centre and whether it turns counter-clockwise.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub arc: Option<(P2, bool)>,
}

/// A planar path of lines and arcs in XY, mm, relative to its feature's placement.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Contour {
    /// Start point.
    pub start: P2,
    /// Segments in order.
    pub segments: Vec<Segment>,
}

impl Contour {
    /// Whether the contour ends where it starts.
    pub fn is_closed(&self) -> bool {
        self.segments.last().is_some_and(|s| (s.to[0] - self.start[0]).hypot(s.to[1] - self.start[1]) < 1e-4)
    }
}

/// How a round hole ends.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum HoleBottom {
    /// Through the stock.
    Through,
    /// Blind with a flat bottom.
    Flat,
    /// Blind with a drill point of this included angle, degrees.
    Conical(f64),
}

/// What a feature is (ISO 14649-10 2½D manufacturing features).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "type")]
pub enum FeatureKind {
    /// A planar face: a rectangle from the placement, swept along `direction` for `length`,
    /// `width` to its left.
    PlanarFace {
        /// Unit direction of travel.
        direction: P3,
        /// Extent along the direction, mm.
        length: f64,
        /// Extent across, mm.
        width: f64,
    },
    /// Round holes of one diameter and depth at one or more positions.
    RoundHole {
        /// Diameter, mm, when the tool's is known.
        diameter: Option<f64>,
        /// Bottom.
        bottom: HoleBottom,
        /// Positions relative to the placement; the first is (0, 0).
        positions: Vec<P2>,
        /// Each position's top above the placement's along the feature's axis, where the
        /// cycles state each hole its own surface (Heidenhain `Q203`, Siemens `RFP`: the holes
        /// of one tool and depth on a stepped face, written one cycle each); empty where every
        /// top is the placement's. ISO 14649-10 places each replicate of a `general_pattern`
        /// in three dimensions, so the pattern keeps them.
        #[serde(skip_serializing_if = "Vec::is_empty", default)]
        heights: Vec<f64>,
    },
    /// A pocket surrounded by walls.
    ClosedPocket {
        /// Wall contour at the floor, closed.
        boundary: Contour,
        /// Width and length when the boundary is an axis-aligned rectangle.
        #[serde(skip_serializing_if = "Option::is_none", default)]
        rectangle: Option<(f64, f64)>,
        /// Radius of the vertical corners, mm.
        #[serde(skip_serializing_if = "Option::is_none", default)]
        corner_radius: Option<f64>,
    },
    /// A pocket open to the stock's side.
    OpenPocket {
        /// Wall contour at the floor.
        boundary: Contour,
    },
    /// A slot along a centre path.
    Slot {
        /// Centre path.
        path: Contour,
        /// Width, mm.
        width: f64,
    },
    /// A step along a stock edge: its inner edge runs from the placement along `direction`.
    Step {
        /// Unit direction of the edge.
        direction: P3,
        /// Length of the edge, mm.
        length: f64,
        /// Width removed from the edge, mm.
        width: f64,
    },
    /// A wall around the outside of the part.
    OutsideProfile {
        /// Wall contour, closed.
        boundary: Contour,
        /// Width and length when the wall is an axis-aligned rectangle.
        #[serde(skip_serializing_if = "Option::is_none", default)]
        rectangle: Option<(f64, f64)>,
        /// Radius of the vertical corners, mm.
        #[serde(skip_serializing_if = "Option::is_none", default)]
        corner_radius: Option<f64>,
    },
    /// A toolpath that fits no other feature.
    Toolpath,
    /// A turned feature (ISO 14649-12): placed on the axis of revolution, Z.
    Turned(super::turned::Turned),
}

impl FeatureKind {
    /// Human label.
    pub fn label(&self) -> &'static str {
        match self {
            FeatureKind::PlanarFace { .. } => "planar face",
            FeatureKind::RoundHole { .. } => "round hole",
            FeatureKind::ClosedPocket { .. } => "closed pocket",
            FeatureKind::OpenPocket { .. } => "open pocket",
            FeatureKind::Slot { .. } => "slot",
            FeatureKind::Step { .. } => "step",
            FeatureKind::OutsideProfile { .. } => "general outside profile",
            FeatureKind::Toolpath => "toolpath feature",
            FeatureKind::Turned(t) => t.label(),
        }
    }

    /// The contour the kind is drawn by (a boundary or a centre path), when it has one.
    pub fn contour(&self) -> Option<&Contour> {
        match self {
            FeatureKind::ClosedPocket { boundary, .. }
            | FeatureKind::OpenPocket { boundary }
            | FeatureKind::OutsideProfile { boundary, .. } => Some(boundary),
            FeatureKind::Slot { path, .. } => Some(path),
            FeatureKind::PlanarFace { .. }
            | FeatureKind::RoundHole { .. }
            | FeatureKind::Step { .. }
            | FeatureKind::Toolpath
            | FeatureKind::Turned(_) => None,
        }
    }
}

/// A manufacturing feature: the material the workingsteps remove.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Feature {
    /// 1-based id.
    pub id: u32,
    /// What it is.
    pub kind: FeatureKind,
    /// Origin of the feature: on its top, mm.
    pub placement: P3,
    /// Depth below the placement, mm.
    pub depth: f64,
    /// Whether the top was inferred (no stock known: the plane where feeding began).
    pub top_inferred: bool,
    /// Workingsteps that machine it, in order.
    pub workingsteps: Vec<u32>,
    /// Source range covered by its workingsteps.
    pub source: TextRange,
    /// First and last source line.
    pub lines: (u32, u32),
    /// Where its numbers came from.
    #[serde(default)]
    pub sources: Sources,
    /// When the size is not known (the tool's diameter is not): the width and length of the
    /// tool-centre path at the bottom, which is not the feature's size.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub centre_path: Option<(f64, f64)>,
    /// The feature's own axis (unit, away from the material) where it lies on a tilted
    /// plane; +Z when none.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub axis: Option<P3>,
    /// The direction its positions' and contours' first coordinate runs along, square to
    /// `axis`, where it lies on a tilted plane; +X when none.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub ref_direction: Option<P3>,
    /// Where it is cut on the developed surface of a cylinder (cylindrical interpolation), the
    /// cylinder and the angles it runs round it: its placement and axis are where it begins,
    /// and its positions' and contours' second coordinate is the length round the cylinder.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub wrap: Option<Wrap>,
}

/// A feature wrapped round a cylinder (cut on its developed surface: Fanuc `G07.1`, Siemens
/// `TRACYL`).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Wrap {
    /// The cylinder's diameter, mm: the developed length round it is measured at it.
    pub diameter: f64,
    /// The angles about the cylinder's axis (degrees, as C turns, 0 to 360) the feature runs
    /// from and to round it, by its positions' and contour's points.
    pub angles: (f64, f64),
    /// The length round the cylinder it spans at `diameter`, mm.
    pub developed: f64,
}

/// Where a number of a feature came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Source {
    /// Written in the program: a cycle's parameter, a contour programmed under cutter
    /// compensation in the control.
    Program,
    /// The tool-centre path offset by a radius from the tool table (or the configuration).
    ToolTable,
    /// The tool-centre path offset by a radius a comment of the program states.
    ToolComment,
    /// The stock's (from its own source, see [`Stock::source`]).
    Stock,
    /// The cuts themselves: a faced level, the step between layers.
    Cuts,
    /// An assumption: a twist drill's 118° point, the part's top at the program zero.
    Assumption,
    /// Not known.
    #[default]
    Unknown,
}

impl Source {
    /// snake_case name.
    pub fn as_str(self) -> &'static str {
        match self {
            Source::Program => "program",
            Source::ToolTable => "tool_table",
            Source::ToolComment => "tool_comment",
            Source::Stock => "stock",
            Source::Cuts => "cuts",
            Source::Assumption => "assumption",
            Source::Unknown => "unknown",
        }
    }

    /// Parses [`Source::as_str`].
    pub fn parse(s: &str) -> Option<Source> {
        [Source::Program, Source::ToolTable, Source::ToolComment, Source::Stock, Source::Cuts, Source::Assumption, Source::Unknown]
            .into_iter()
            .find(|k| k.as_str() == s)
    }

    /// In words, for text output.
    pub fn words(self) -> &'static str {
        match self {
            Source::Program => "the program",
            Source::ToolTable => "the tool table",
            Source::ToolComment => "a tool comment",
            Source::Stock => "the stock",
            Source::Cuts => "the cuts",
            Source::Assumption => "an assumption",
            Source::Unknown => "unknown",
        }
    }

    /// Where a fact the tool carries came from.
    pub fn of_tool_fact(source: ToolSource) -> Source {
        match source {
            ToolSource::Table => Source::ToolTable,
            ToolSource::Comment => Source::ToolComment,
            ToolSource::Inferred => Source::Assumption,
            ToolSource::Unknown => Source::Unknown,
        }
    }

    /// Where a size measured on the tool-centre path and offset by this tool's radius
    /// comes from.
    pub fn of_tool(tool: Option<&Tool>) -> Source {
        tool.filter(|t| t.diameter.is_some()).map_or(Source::Unknown, |t| Source::of_tool_fact(t.source))
    }
}

/// Where a feature's numbers came from.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct Sources {
    /// Width, length, diameter, corner radius.
    pub size: Source,
    /// The top the depth is measured from.
    pub top: Source,
    /// A drilled hole's point angle.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub point_angle: Option<Source>,
}

/// Where a tool fact came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ToolSource {
    /// The configured tool table.
    Table,
    /// A CAM comment in the program.
    Comment,
    /// Inferred from how the program uses the tool (a drilling cycle implies a drill).
    Inferred,
    /// Nothing but the tool number is known.
    Unknown,
}

impl ToolSource {
    /// snake_case name.
    pub fn as_str(self) -> &'static str {
        match self {
            ToolSource::Table => "table",
            ToolSource::Comment => "comment",
            ToolSource::Inferred => "inferred",
            ToolSource::Unknown => "unknown",
        }
    }

    /// Parses [`ToolSource::as_str`].
    pub fn parse(s: &str) -> Option<ToolSource> {
        [ToolSource::Table, ToolSource::Comment, ToolSource::Inferred, ToolSource::Unknown].into_iter().find(|k| k.as_str() == s)
    }
}

/// Kind of cutting tool (the ISO 14649-111 tool bodies ncplan distinguishes).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ToolKind {
    /// Flat end mill.
    EndMill,
    /// Ball-nose end mill.
    BallEndMill,
    /// End mill with a corner radius.
    BullnoseEndMill,
    /// Face mill.
    FaceMill,
    /// Twist drill.
    TwistDrill,
    /// Centre or spot drill.
    CenterDrill,
    /// Reamer.
    Reamer,
    /// Tap.
    Tap,
    /// Boring bar.
    BoringTool,
    /// Countersink or chamfer tool.
    Countersink,
    /// A general turning tool (ISO 14649-121 `general_turning_tool`): an insert with a nose radius.
    TurningTool,
    /// A grooving or parting tool (`grooving_tool`): its width is its diameter here.
    GroovingTool,
    /// A threading tool (`turning_threading_tool`).
    ThreadingTool,
    /// Not known.
    Unknown,
}

impl ToolKind {
    /// Every kind.
    pub const ALL: [ToolKind; 14] = [
        ToolKind::EndMill,
        ToolKind::BallEndMill,
        ToolKind::BullnoseEndMill,
        ToolKind::FaceMill,
        ToolKind::TwistDrill,
        ToolKind::CenterDrill,
        ToolKind::Reamer,
        ToolKind::Tap,
        ToolKind::BoringTool,
        ToolKind::Countersink,
        ToolKind::TurningTool,
        ToolKind::GroovingTool,
        ToolKind::ThreadingTool,
        ToolKind::Unknown,
    ];

    /// snake_case name, as in config files.
    pub fn as_str(self) -> &'static str {
        match self {
            ToolKind::EndMill => "end_mill",
            ToolKind::BallEndMill => "ball_end_mill",
            ToolKind::BullnoseEndMill => "bullnose_end_mill",
            ToolKind::FaceMill => "face_mill",
            ToolKind::TwistDrill => "twist_drill",
            ToolKind::CenterDrill => "center_drill",
            ToolKind::Reamer => "reamer",
            ToolKind::Tap => "tap",
            ToolKind::BoringTool => "boring_tool",
            ToolKind::Countersink => "countersink",
            ToolKind::TurningTool => "turning_tool",
            ToolKind::GroovingTool => "grooving_tool",
            ToolKind::ThreadingTool => "threading_tool",
            ToolKind::Unknown => "unknown",
        }
    }

    /// Parses [`ToolKind::as_str`].
    pub fn parse(s: &str) -> Option<ToolKind> {
        ToolKind::ALL.into_iter().find(|k| k.as_str() == s)
    }

    /// Whether the tool makes holes along its axis only.
    pub fn is_holemaking(self) -> bool {
        matches!(self, ToolKind::TwistDrill | ToolKind::CenterDrill | ToolKind::Reamer | ToolKind::Tap | ToolKind::BoringTool)
    }
}

/// A cutting tool.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Tool {
    /// Tool number (T word).
    pub number: u32,
    /// Name or description.
    pub name: Option<String>,
    /// Kind of tool.
    pub kind: ToolKind,
    /// Where the kind came from.
    pub kind_source: ToolSource,
    /// Cutter diameter, mm.
    pub diameter: Option<f64>,
    /// Corner radius, mm.
    pub corner_radius: Option<f64>,
    /// Number of flutes (teeth).
    pub flutes: Option<u32>,
    /// Length offset, mm.
    pub length_offset: Option<f64>,
    /// Included point angle of a drill, degrees.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub point_angle: Option<f64>,
    /// Where the geometry (diameter, corner radius, flutes) came from.
    pub source: ToolSource,
}

impl Tool {
    /// A tool of which nothing but the number is known.
    pub fn unknown(number: u32) -> Tool {
        Tool {
            number,
            name: None,
            kind: ToolKind::Unknown,
            kind_source: ToolSource::Unknown,
            diameter: None,
            corner_radius: None,
            flutes: None,
            length_offset: None,
            point_angle: None,
            source: ToolSource::Unknown,
        }
    }
}

/// An ISO 14649-11 machining operation.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Operation {
    /// Roughing a planar face, leaving a bottom allowance.
    PlaneRoughMilling,
    /// Finishing a planar face.
    PlaneFinishMilling,
    /// Roughing a wall.
    SideRoughMilling,
    /// Finishing a wall.
    SideFinishMilling,
    /// Roughing floor and walls (pockets, slots, steps).
    BottomAndSideRoughMilling,
    /// Finishing floor and walls.
    BottomAndSideFinishMilling,
    /// An explicit toolpath that fits no 2½D feature.
    FreeformMilling,
    /// Drilling in one feed.
    Drilling,
    /// Centre or spot drilling.
    CenterDrilling,
    /// Peck drilling.
    MultistepDrilling,
    /// Reaming.
    Reaming,
    /// Boring.
    Boring,
    /// Back boring.
    BackBoring,
    /// Tapping.
    Tapping,
}

impl Operation {
    /// Human label.
    pub fn label(self) -> &'static str {
        match self {
            Operation::PlaneRoughMilling => "plane rough milling",
            Operation::PlaneFinishMilling => "plane finish milling",
            Operation::SideRoughMilling => "side rough milling",
            Operation::SideFinishMilling => "side finish milling",
            Operation::BottomAndSideRoughMilling => "bottom and side rough milling",
            Operation::BottomAndSideFinishMilling => "bottom and side finish milling",
            Operation::FreeformMilling => "freeform milling",
            Operation::Drilling => "drilling",
            Operation::CenterDrilling => "center drilling",
            Operation::MultistepDrilling => "multistep drilling",
            Operation::Reaming => "reaming",
            Operation::Boring => "boring",
            Operation::BackBoring => "back boring",
            Operation::Tapping => "tapping",
        }
    }

    /// Whether the operation makes holes (a drilling-type operation).
    pub fn is_hole(self) -> bool {
        matches!(
            self,
            Operation::Drilling
                | Operation::CenterDrilling
                | Operation::MultistepDrilling
                | Operation::Reaming
                | Operation::Boring
                | Operation::BackBoring
                | Operation::Tapping
        )
    }

    /// Whether two operations are of the same family (milling or hole making).
    pub fn same_family(self, other: Operation) -> bool {
        self.is_hole() == other.is_hole()
    }

    /// The rough counterpart of a finishing milling operation.
    pub fn roughing(self) -> Operation {
        match self {
            Operation::PlaneFinishMilling => Operation::PlaneRoughMilling,
            Operation::SideFinishMilling => Operation::SideRoughMilling,
            Operation::BottomAndSideFinishMilling => Operation::BottomAndSideRoughMilling,
            other => other,
        }
    }

    /// The operation a canned cycle performs, refined by the tool's kind.
    pub fn from_cycle(kind: CycleKind, tool: ToolKind) -> Operation {
        match (kind, tool) {
            (_, ToolKind::CenterDrill) if !matches!(kind, CycleKind::Tapping | CycleKind::LeftTapping) => Operation::CenterDrilling,
            (CycleKind::Drilling | CycleKind::CounterBoring, _) => Operation::Drilling,
            (CycleKind::PeckDrilling | CycleKind::ChipBreaking, _) => Operation::MultistepDrilling,
            (CycleKind::Boring | CycleKind::BoringDwell, ToolKind::Reamer) => Operation::Reaming,
            (CycleKind::Boring | CycleKind::BoringDwell | CycleKind::BoringSpindleStop, _) => Operation::Boring,
            (CycleKind::FineBoring | CycleKind::BoringManual, _) => Operation::Boring,
            (CycleKind::BackBoring, _) => Operation::BackBoring,
            (CycleKind::Tapping | CycleKind::LeftTapping, _) => Operation::Tapping,
        }
    }
}

/// A 2½D milling strategy (ISO 14649-11 `two5D_milling_strategy`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum StrategyKind {
    /// Parallel passes in alternating directions (zigzag).
    Bidirectional,
    /// Parallel passes in one direction, with lifts between.
    Unidirectional,
    /// Closed loops parallel to the boundary.
    ContourParallel,
    /// One spiral towards or away from the boundary.
    ContourSpiral,
    /// Along the centre line (slots).
    CenterMilling,
    /// The toolpath as programmed.
    Explicit,
}

/// Rotation sense of a contour, seen from +Z.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Rotation {
    /// Clockwise.
    Cw,
    /// Counter-clockwise.
    Ccw,
}

/// Climb or conventional milling.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CutMode {
    /// Climb (down) milling.
    Climb,
    /// Conventional (up) milling.
    Conventional,
}

/// How a milling workingstep moves the tool.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Strategy {
    /// Kind.
    pub kind: StrategyKind,
    /// Direction of the first pass (parallel strategies), unit vector.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub feed_direction: Option<P3>,
    /// Rotation sense (contour strategies).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub rotation: Option<Rotation>,
    /// Climb or conventional, from the rotation and the spindle direction.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub cutmode: Option<CutMode>,
    /// Overlap of adjacent passes as a share of the tool diameter (0–1).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub overlap: Option<f64>,
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
    /// Spindle speed, 1/min. Under constant surface speed, the spindle's speed limit, or 0
    /// where none was set.
    pub spindle_speed: f64,
    /// Constant surface speed (G96), m/min: the spindle speed then follows the diameter.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub surface_speed: Option<f64>,
    /// Spindle direction.
    pub spindle: SpindleDir,
    /// Coolant.
    pub coolant: Coolant,
    /// The spindle that turns the tool, where it is not the main one: a driven tool on a
    /// lathe (Haas `M133`), a spindle the program numbers (Siemens `S2= M2=3`).
    #[serde(default, skip_serializing_if = "is_main")]
    pub spindle_id: SpindleId,
}

fn is_main(id: &SpindleId) -> bool {
    *id == SpindleId::Main
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

/// One move of a toolpath, as a [`Toolpath`](super::Toolpath) gives it back.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Move {
    /// Kind.
    pub kind: MoveKind,
    /// Phase.
    pub phase: Phase,
    /// Start point, mm.
    pub from: P3,
    /// End point, mm.
    pub to: P3,
    /// An arc's geometry (written as `center`, `axis` and `turns`); a toolpath stores it
    /// apart, so lines do not pay for it.
    #[serde(flatten, default)]
    pub arc: Option<ArcGeometry>,
    /// Feed, mm/min (0 for rapids).
    #[serde(default)]
    pub feed: f64,
    /// 1-based source line.
    pub line: u32,
}

/// The geometry of an arc move.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct ArcGeometry {
    /// Arc centre (on the arc's plane through `from`), mm.
    pub center: P3,
    /// Arc axis (unit normal); with `turns`, positive is counter-clockwise about it.
    pub axis: P3,
    /// Arc turns, signed.
    pub turns: i32,
}

impl Move {
    /// The arc centre, for an arc.
    pub fn center(&self) -> Option<P3> {
        self.arc.as_ref().map(|a| a.center)
    }

    /// The arc axis, for an arc.
    pub fn axis(&self) -> Option<P3> {
        self.arc.as_ref().map(|a| a.axis)
    }

    /// The arc's signed turns, for an arc.
    pub fn turns(&self) -> Option<i32> {
        self.arc.as_ref().map(|a| a.turns)
    }
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
    /// The workpiece surface the cycle states (`RFP`, `Q203`): the hole's top, when stated.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub top: Option<f64>,
    /// Peck increment, mm.
    pub peck: Option<f64>,
    /// Dwell at the bottom, seconds.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub dwell: Option<f64>,
    /// Height the tool returns to after the hole (the retract plane), mm.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub retract: Option<f64>,
    /// Whether the hole is made by optional (`/`) blocks, and so hangs on the block-delete switch.
    #[serde(skip_serializing_if = "std::ops::Not::not", default)]
    pub optional: bool,
}

/// A program stop within or after a workingstep's moves.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Stop {
    /// Whether it is the optional stop (M01) rather than the program stop (M00).
    pub optional: bool,
    /// 1-based source line.
    pub line: u32,
    /// How many of the workingstep's moves come before it.
    pub at: u32,
}

/// A dwell outside a canned cycle.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Dwell {
    /// Seconds.
    pub seconds: f64,
    /// 1-based source line.
    pub line: u32,
    /// How many of the workingstep's moves come before it.
    pub at: u32,
}

/// Cutter radius compensation in force while cutting.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
pub struct CompUse {
    /// Left of the direction of travel (G41) rather than right (G42).
    pub left: bool,
    /// Offset number (`D5`), when the program states one.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub number: Option<u32>,
}

/// The machine state a workingstep runs under, as the program sets it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MachineState {
    /// Work offset in force while cutting: 1 for G54 (the default) to 6 for G59, more for
    /// the extended ones.
    pub work_offset: u16,
    /// Length offset numbers (H) in force while cutting that are not the tool's own, in order
    /// of first use; 0 is none (`H0`, or cancelled by G49).
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub length_offsets: Vec<u32>,
    /// Cutter compensation in force while cutting, in order of first use; its number only where
    /// it is not the tool's own.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub cutter_comp: Vec<CompUse>,
    /// Program and optional stops.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub stops: Vec<Stop>,
    /// Dwells outside canned cycles.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub dwells: Vec<Dwell>,
    /// Lines of the optional (`/`) blocks whose moves belong to the workingstep.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub optional_lines: Vec<u32>,
    /// The feed override was off (M49, M50 P0) while the workingstep cut: it ran at the
    /// programmed feed whatever the operator's dial said.
    #[serde(skip_serializing_if = "std::ops::Not::not", default)]
    pub feed_override_off: bool,
}

impl Default for MachineState {
    fn default() -> MachineState {
        MachineState {
            work_offset: 1,
            length_offsets: Vec::new(),
            cutter_comp: Vec::new(),
            stops: Vec::new(),
            dwells: Vec::new(),
            optional_lines: Vec::new(),
            feed_override_off: false,
        }
    }
}

impl MachineState {
    /// Whether nothing differs from a program that sets nothing.
    pub fn is_default(&self) -> bool {
        *self == MachineState::default()
    }

    /// The state as `key=value` words without spaces (`wcs=2 h=1,5 comp=L1,R stops=M0@12/40`),
    /// for identifiers that carry it; [`MachineState::decode`] reads them back.
    pub fn encode(&self) -> Vec<String> {
        let mut out = Vec::new();
        let list = |v: Vec<String>| v.join(",");
        if self.work_offset != 1 {
            out.push(format!("wcs={}", self.work_offset));
        }
        if !self.length_offsets.is_empty() {
            out.push(format!("h={}", list(self.length_offsets.iter().map(u32::to_string).collect())));
        }
        if !self.cutter_comp.is_empty() {
            let c = self
                .cutter_comp
                .iter()
                .map(|c| format!("{}{}", if c.left { 'L' } else { 'R' }, c.number.map_or(String::new(), |n| n.to_string())));
            out.push(format!("comp={}", list(c.collect())));
        }
        if !self.stops.is_empty() {
            let s = self.stops.iter().map(|s| format!("M{}@{}/{}", u8::from(s.optional), s.line, s.at));
            out.push(format!("stops={}", list(s.collect())));
        }
        if !self.dwells.is_empty() {
            let d = self.dwells.iter().map(|d| format!("{}@{}/{}", d.seconds, d.line, d.at));
            out.push(format!("dwells={}", list(d.collect())));
        }
        if !self.optional_lines.is_empty() {
            out.push(format!("optional={}", list(self.optional_lines.iter().map(u32::to_string).collect())));
        }
        if self.feed_override_off {
            out.push("feed_override=off".into());
        }
        out
    }

    /// Reads [`MachineState::encode`]'s words from a key → value map; what is missing or
    /// unreadable keeps its default.
    pub fn decode(words: &std::collections::BTreeMap<String, String>) -> MachineState {
        let mut st = MachineState::default();
        let items = |k: &str| {
            words.get(k).map(|v| v.split(',').filter(|s| !s.is_empty()).map(str::to_owned).collect::<Vec<_>>()).unwrap_or_default()
        };
        let at = |s: &str| -> Option<(u32, u32)> {
            let (l, a) = s.split_once('/')?;
            Some((l.parse().ok()?, a.parse().ok()?))
        };
        if let Some(w) = words.get("wcs").and_then(|v| v.parse().ok()) {
            st.work_offset = w;
        }
        st.length_offsets = items("h").iter().filter_map(|v| v.parse().ok()).collect();
        st.cutter_comp =
            items("comp").iter().map(|c| CompUse { left: c.starts_with('L'), number: c.get(1..).and_then(|n| n.parse().ok()) }).collect();
        st.stops = items("stops")
            .iter()
            .filter_map(|s| {
                let (k, rest) = s.split_once('@')?;
                let (line, at) = at(rest)?;
                Some(Stop { optional: k == "M1", line, at })
            })
            .collect();
        st.dwells = items("dwells")
            .iter()
            .filter_map(|s| {
                let (v, rest) = s.split_once('@')?;
                let (line, at) = at(rest)?;
                Some(Dwell { seconds: v.parse().ok()?, line, at })
            })
            .collect();
        st.optional_lines = items("optional").iter().filter_map(|v| v.parse().ok()).collect();
        st.feed_override_off = words.get("feed_override").is_some_and(|v| v == "off");
        st
    }
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
    /// Security (clearance) plane: the height of the rapids between cuts, mm.
    pub security_plane: f64,
    /// Feature this workingstep machines.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub feature: Option<u32>,
    /// Milling strategy.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub strategy: Option<Strategy>,
    /// Depth of cut per layer along the tool axis, mm.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub axial_depth: Option<f64>,
    /// Stepover between passes, mm.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub radial_depth: Option<f64>,
    /// Material left on the walls for a later workingstep, mm.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub allowance_side: Option<f64>,
    /// Material left on the floor for a later workingstep, mm.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub allowance_bottom: Option<f64>,
    /// Bounding box of the cutting moves, mm.
    pub bbox: Option<BBox>,
    /// Length of the cutting moves, mm.
    pub cutting_length: f64,
    /// Holes, for hole-making operations.
    #[serde(skip_serializing_if = "Vec::is_empty", default)]
    pub holes: Vec<Hole>,
    /// The explicit toolpath.
    pub toolpath: super::Toolpath,
    /// The machine state it runs under: offsets, compensation, stops, dwells, optional blocks.
    #[serde(skip_serializing_if = "MachineState::is_default", default)]
    pub state: MachineState,
    /// The tilted working plane it runs on, whose coordinates its toolpath, start point,
    /// depths, box and holes are in; none on the untilted plane.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub setup: Option<Setup>,
    /// On a program that turns: the turning operation and its values.
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub turning: Option<Box<super::turned::Turning>>,
    /// The workpiece surface a milling cycle states for what it mills (Heidenhain `Q203`,
    /// Siemens `_RFP`), along the tool axis in the toolpath's coordinates: the feature's top.
    /// Feature recognition reads it; the recovered plan has none (its feature holds the top).
    #[serde(skip_serializing_if = "Option::is_none", default)]
    pub surface: Option<f64>,
    /// Source range covered by the workingstep's blocks.
    pub source: TextRange,
    /// First and last source line.
    pub lines: (u32, u32),
}

impl Workingstep {
    /// The operation in words: a turning workingstep's (`contouring rough`), else the ISO
    /// 14649-11 operation's label.
    pub fn label(&self) -> String {
        match self.turning.as_deref().and_then(|t| t.operation.map(|o| (o, t.rough, t.inside))) {
            Some((o, rough, inside)) => {
                let stage = match o {
                    super::turned::TurnOp::Drilling | super::turned::TurnOp::PartingOff => "",
                    _ if rough => " rough",
                    _ => " finish",
                };
                format!("{}{stage}{}", o.as_str().replace('_', " "), if inside { " inside" } else { "" })
            }
            None => self.operation.label().into(),
        }
    }

    /// A workingstep with its toolpath and what was decided about it; what the toolpath
    /// determines is left empty for [`measure`](crate::plan::measure), and features,
    /// strategies, depths and allowances for feature recognition.
    #[allow(clippy::too_many_arguments)]
    pub fn unmeasured(
        index: u32,
        operation: Operation,
        tool: u32,
        technology: Technology,
        security_plane: f64,
        toolpath: super::Toolpath,
        source: TextRange,
        lines: (u32, u32),
    ) -> Workingstep {
        Workingstep {
            index,
            operation,
            tool,
            technology,
            start_point: None,
            depth: None,
            security_plane,
            feature: None,
            strategy: None,
            axial_depth: None,
            radial_depth: None,
            allowance_side: None,
            allowance_bottom: None,
            bbox: None,
            cutting_length: 0.0,
            holes: Vec::new(),
            toolpath,
            state: MachineState::default(),
            setup: None,
            turning: None,
            surface: None,
            source,
            lines,
        }
    }
}

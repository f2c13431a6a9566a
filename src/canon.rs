//! The neutral machining model: NIST RS274/NGC canonical machining functions plus the
//! markers plan recovery needs (cycle intent, distance mode).
//!
//! The interpreter pushes [`Canon`] values into a [`CanonSink`] (a push model, as ripgrep's
//! `Sink`): a printer, a collector, or plan recovery can sit behind it. Lengths are in the
//! active `USE_LENGTH_UNITS`, as LinuxCNC's canonical interface has them; plan recovery
//! normalises to millimetres.
//!
//! `CanonOp` (the NIST canonical functions plus markers), `CanonSink`, and
//! `write_call`, which prints exactly as `rs274 -g`. It names the kinds its events carry (`LogFile`,
//! re-exported by `dialect`), so that it uses nothing of `dialect`. The `Setting` marker carries what the
//! canonical calls do not say and the plan needs: the length offset number (`G43 H5`), the
//! cutter compensation side and D number, an optional (`/`) block, a tool selected by name
//! (`T="EM10"`); markers print as `ncplan:` comments, which rs274 comparisons drop.
//! `ToolAxis` is a marker with the tool axis vector, emitted before a move whose block
//! changes it (CLDATA `GOTO/x,y,z,i,j,k`; `Interpreter::tool_axis`), so 5-axis data is kept
//! without growing `Move`s; rs274 comparisons drop it like the other markers.
//! `WorkPlane` is a marker with the tilted working plane in force (`PLANE SPATIAL`,
//! `CYCLE800`, `G68.2`): a [`Frame`] that maps the program coordinates of the moves that follow
//! (still in the tilted plane, as the control reads them) to the untilted ones, emitted when
//! it changes; `None` when the plane is untilted again.
//! `CycleIntent::surface` is the workpiece surface a defined cycle states (`RFP`, `Q203`),
//! which becomes the hole's top; `FeedOverride`/`SpeedOverride` are the canonical override
//! switches (LinuxCNC M48–M51), which the plan keeps as `MachineState::feed_override_off`.

use std::fmt;
use std::io::Write as _;

use serde::{Deserialize, Serialize};

use crate::text::TextRange;

/// Length units.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Units {
    /// Millimetres.
    Mm,
    /// Inches.
    Inch,
}

impl Units {
    /// Millimetres per unit.
    pub fn to_mm(self) -> f64 {
        match self {
            Units::Mm => 1.0,
            Units::Inch => 25.4,
        }
    }
}

/// Arc plane.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Plane {
    /// G17.
    Xy,
    /// G18.
    Xz,
    /// G19.
    Yz,
}

impl Plane {
    /// Axis indices (first, second, normal) as LinuxCNC orders them in `ARC_FEED`.
    pub fn axes(self) -> (usize, usize, usize) {
        match self {
            Plane::Xy => (0, 1, 2),
            Plane::Xz => (2, 0, 1),
            Plane::Yz => (1, 2, 0),
        }
    }
}

/// What kind of canned cycle a [`CycleIntent`] describes.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CycleKind {
    /// Drilling (G81).
    Drilling,
    /// Drilling with dwell, counterboring (G82).
    CounterBoring,
    /// Peck drilling with full retract (G83).
    PeckDrilling,
    /// Chip-breaking drilling (G73).
    ChipBreaking,
    /// Boring, feed out (G85).
    Boring,
    /// Boring with dwell, feed out (G89).
    BoringDwell,
    /// Boring, spindle stop, rapid out (G86).
    BoringSpindleStop,
    /// Right-hand tapping: feed in, spindle reverses, feed out (G84).
    Tapping,
    /// Left-hand tapping (G74).
    LeftTapping,
    /// Fine boring: oriented stop and shift away before the rapid out (Fanuc G76).
    FineBoring,
    /// Back boring from below (G87).
    BackBoring,
    /// Boring, spindle stop, manual retract (G88).
    BoringManual,
}

impl CycleKind {
    /// Human name.
    pub fn label(self) -> &'static str {
        match self {
            CycleKind::Drilling => "drilling",
            CycleKind::CounterBoring => "counterboring",
            CycleKind::PeckDrilling => "peck drilling",
            CycleKind::ChipBreaking => "chip-break drilling",
            CycleKind::Boring => "boring",
            CycleKind::BoringDwell => "boring with dwell",
            CycleKind::BoringSpindleStop => "boring with spindle stop",
            CycleKind::Tapping => "tapping",
            CycleKind::LeftTapping => "left-hand tapping",
            CycleKind::FineBoring => "fine boring",
            CycleKind::BackBoring => "back boring",
            CycleKind::BoringManual => "boring with manual retract",
        }
    }
}

/// The intent of one canned-cycle hole: what was asked for, before expansion into moves.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct CycleIntent {
    /// Kind.
    pub kind: CycleKind,
    /// The code as written in the dialect (`G83`).
    pub code: String,
    /// Hole position (first and second plane axes) and bottom along the normal axis.
    pub x: f64,
    /// Hole position, second axis.
    pub y: f64,
    /// Bottom of the hole.
    pub bottom: f64,
    /// R (feed-start) plane.
    pub r_plane: f64,
    /// Height the tool returns to after the hole.
    pub clear: f64,
    /// Peck increment, if any.
    pub peck: Option<f64>,
    /// Dwell at the bottom, seconds.
    pub dwell: Option<f64>,
    /// Whether the move just before the cycle positioned the tool over the hole (a cycle
    /// called after a positioning block: `MCALL`, `M99`), rather than the cycle itself.
    pub positioned: bool,
    /// The workpiece surface the cycle states, where it states one (Siemens `RFP`, Heidenhain
    /// `Q203`): the hole's top. G8x cycles state only the R level, which is above it.
    #[serde(default)]
    pub surface: Option<f64>,
    /// How far above the last peck a peck cycle re-approaches before feeding on (Siemens
    /// `_DIS1`, Heidenhain `Q258`, else the dictionary's `peck-clearance`), where it pecks.
    #[serde(default)]
    pub peck_clearance: Option<f64>,
    /// Whether the hole axis stands where the program does not know when the hole begins
    /// (after a tool change, a reference return) and the cycle's own move to its R level, an
    /// absolute level, makes it known (a [`CanonOp::Known`] marker before that move).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub known_at_r: bool,
    /// Whether the tool returns after the hole to the level it began at, which the program
    /// does not know (G98 from an unknown level): [`CycleIntent::clear`] is then counted from
    /// an assumed number, and the axis is unknown again from the return on.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub returns_unknown: bool,
}

/// What a lathe cycle does (a [`TurnIntent`]'s kind).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TurnKind {
    /// Stock removal along Z towards a contour (Fanuc G71, CYCLE95 longitudinal), or the
    /// contour cut again in passes shifted towards it (Fanuc G73 pattern repeating).
    RoughTurn,
    /// Stock removal along X towards a contour (Fanuc G72, CYCLE95 face).
    RoughFace,
    /// The contour finished as written (Fanuc G70).
    Finish,
    /// One turning pass (Fanuc G90).
    TurnPass,
    /// One facing pass (Fanuc G94).
    FacePass,
    /// One threading pass (Fanuc G92).
    ThreadPass,
    /// Multiple-pass threading (Fanuc G76, LinuxCNC G76, CYCLE97).
    Thread,
    /// Grooving across X with pecks (Fanuc G75, CYCLE93).
    Groove,
    /// Pecking along Z (Fanuc G74): a face groove, or a hole on the axis.
    FacePeck,
}

impl TurnKind {
    /// snake_case name.
    pub fn as_str(self) -> &'static str {
        match self {
            TurnKind::RoughTurn => "rough_turn",
            TurnKind::RoughFace => "rough_face",
            TurnKind::Finish => "finish",
            TurnKind::TurnPass => "turn_pass",
            TurnKind::FacePass => "face_pass",
            TurnKind::ThreadPass => "thread_pass",
            TurnKind::Thread => "thread",
            TurnKind::Groove => "groove",
            TurnKind::FacePeck => "face_peck",
        }
    }
}

/// The intent of one lathe cycle, as its words state it, in the program's length units.
/// X values are diameters (allowances too); depths of cut and thread heights are per side.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct TurnIntent {
    /// Kind.
    pub kind: Option<TurnKind>,
    /// The code as written (`G71`).
    pub code: String,
    /// Depth of cut per pass, per side.
    pub depth_of_cut: Option<f64>,
    /// Retract after each pass.
    pub retract: Option<f64>,
    /// Finishing allowance in X, on the diameter (Fanuc U).
    pub allowance_x: Option<f64>,
    /// Finishing allowance in Z (Fanuc W).
    pub allowance_z: Option<f64>,
    /// Thread lead (advance per revolution).
    pub pitch: Option<f64>,
    /// Thread height, per side.
    pub thread_depth: Option<f64>,
    /// Depth of the first threading pass.
    pub first_cut: Option<f64>,
    /// Least depth of a threading pass.
    pub min_cut: Option<f64>,
    /// Finishing allowance of a thread, or all round a contour (Siemens CYCLE95 FAL), per side.
    pub finish_allowance: Option<f64>,
    /// Finishing (spring) passes of a thread.
    pub finish_passes: Option<u32>,
    /// Included angle of the thread's tool, degrees.
    pub angle: Option<f64>,
    /// Infeed per peck (grooving, face pecking).
    pub peck: Option<f64>,
    /// Shift between plunges (grooving wider than the tool).
    pub step: Option<f64>,
    /// The lowest and highest Z of the groove or thread the cycle states (its width or
    /// length, without run-in and run-out), where the cycle states it (Siemens CYCLE93, CYCLE97).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub span: Option<[f64; 2]>,
    /// A pattern repeating cycle's relief (Fanuc G73's first U and W, Haas G73 I and K): how
    /// far its first pass lies off its last, X per side and Z.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub relief: Option<[f64; 2]>,
    /// A pattern repeating cycle's number of passes (Fanuc G73 R, Haas G73 D).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub divisions: Option<u32>,
    /// Where a contour cycle's contour blocks stand in the source it reads them from (byte
    /// offsets of the block P names and of the block Q names): a finishing cycle and the
    /// roughing cycle whose contour it repeats name the same blocks (Fanuc's G70 runs the
    /// blocks its P and Q name). Plan recovery pairs them by it and then clears it; not
    /// written out.
    #[serde(skip)]
    pub contour: Option<[u32; 2]>,
}

/// Distance mode (a marker; the canonical interface itself has none).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum DistanceMode {
    /// G90.
    Absolute,
    /// G91.
    Incremental,
}

/// Cutter radius compensation put in force: the side, the offset number the block states, and
/// where the interpreter knows them the radius it offsets by and a lathe tool's tip.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct CompOn {
    /// Left of the direction of travel (G41) rather than right (G42).
    pub left: bool,
    /// The offset number (`D5`), when the block states one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub number: Option<u32>,
    /// The radius the path is offset by, in the active units: half the diameter the block
    /// gives (`G41.1 D0.8`), else the tool table's radius (with its wear) of the offset's or
    /// the spindle's tool; on a lathe, the tool's nose radius.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub radius: Option<f64>,
    /// A lathe tool's tip orientation (1 to 9, `G42.1 D0.8 L3`), when the block states one.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub tip: Option<u8>,
}

/// A machine setting the canonical interface does not carry, as a marker for the plan.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Setting {
    /// The length offset number put in force (`G43 H5`); 0 when it is cancelled (`G49`).
    LengthOffset(u32),
    /// Cutter radius compensation on (G41/G42, G41.1/G42.1), or off (G40).
    CutterComp(Option<CompOn>),
    /// The block is optional (`/`): it runs only while the block-delete switch is off.
    BlockDelete,
    /// A tool selected by name (`T="EM10"`) and the number the analysis gave it.
    ToolName(u32, String),
    /// A work offset stated by the block (`G54`), also where it is the one in force already:
    /// the program does not leave it to whatever the machine had.
    WorkOffset(u16),
    /// Lathe diameter mode on (X words are diameters: a lathe dictionary's start, `G7`,
    /// `DIAMON`) or off (`G8`, `DIAMOF`): the program turns about Z.
    DiameterMode(bool),
    /// A milling cycle's moves begin (its name: `POCKET3`) or end (`None`): one operation,
    /// whose moves are only the cycle's finishing pass on its wall (`interp::pocket`), so
    /// that the plan keeps it a workingstep of its own and a translation does not write
    /// them as the whole cycle.
    MillCycle(Option<String>),
    /// The workpiece surface the milling cycle just begun states (Heidenhain `Q203`, Siemens
    /// `_RFP`), along the working plane's normal: the top of what it mills.
    CycleSurface(f64),
    /// The milling cycle about to begin (the next `MillCycle`) makes one hole where it is
    /// called (a bore milled in a helix), told by its size and depth: consecutive calls that make the same hole with the
    /// same tool are one operation at several positions, as consecutive drilling cycle calls are.
    HoleMilled(String),
    /// Tool centre point control on (`M128`, `FUNCTION TCPM`, `TRAORI`, `G43.4`) or off: X Y Z
    /// are the tool tip's on the part, and the rotary axes turn the tool about it (the tool
    /// axis then follows as `ToolAxis` markers).
    ToolCentrePoint(bool),
    /// Cylindrical interpolation (Fanuc `G07.1`/`G107`, Siemens `TRACYL`) on the cylinder of
    /// this radius (program units), or off (`None`): the moves that follow are written on its
    /// developed surface, their Y the length round it measured at this radius (the angle of C
    /// times the radius, as the controls' manuals define it). Sent before the `WorkPlane` laid
    /// tangent to the cylinder, so that what is cut there is wrapped onto it.
    CylinderWrap(Option<f64>),
}

/// The tool axis the rotary axes A, B and C (degrees) turn the tool to, read as turns of the
/// tool about the part's X, then Y, then Z (ISO 841 senses): `Rz(C)·Ry(B)·Rx(A)` applied to Z.
/// A machine whose kinematics differ tilts it otherwise; interpreter and writer share this
/// reading, so that a translation states the rotary axes that give the source's axis.
pub fn rotary_tool_axis(abc: [f64; 3]) -> [f64; 3] {
    let [sa, sb, sc] = abc.map(|d| d.to_radians().sin());
    let [ca, cb, cc] = abc.map(|d| d.to_radians().cos());
    // Rx(A)·Z = (0, -sA, cA); Ry(B)·v; Rz(C)·v.
    let v = [0.0, -sa, ca];
    let v = [cb * v[0] + sb * v[2], v[1], -sb * v[0] + cb * v[2]];
    let v = [cc * v[0] - sc * v[1], sc * v[0] + cc * v[1], v[2]];
    v.map(|x| if x.abs() < 1e-12 { 0.0 } else { x })
}

/// Where a move given in the machine's own frame goes: a reference position, or machine
/// coordinates. The analysis knows neither the reference positions nor the work offsets (it
/// takes them as zero, as rs274 does), so the moves that follow the marker reach a position
/// that only the machine knows; a writer and a check must keep them as what they are.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum MachineTarget {
    /// Reference position 1 (`G28`) or 2 to 4 (`G30 P2`..`P4`), through an intermediate
    /// point: the marker's two traverses.
    Reference(u8),
    /// Reference position k reached straight, with no intermediate point (SINUMERIK `G74`,
    /// Centroid `M25`): the marker's one traverse. It moves as a `G28` whose intermediate
    /// point is the current position (`G91 G28 Z0`).
    Direct(u8),
    /// Fixed point n (SINUMERIK `G75 FP=n`), reached straight: the marker's one traverse. A
    /// place of its own in the machine data, not a reference position.
    Fixed(u8),
    /// Machine coordinates for one block (`G53`, `SUPA`, `M91`): the marker's one move.
    Machine,
    /// Coordinates from a datum the machine builder defines, for one block (Heidenhain
    /// `M92`): the marker's one move. Not the machine datum: no `G53` reaches it.
    Builder,
    /// The tool axis's travel limit, away from the work (Heidenhain `M140 MB MAX`: along the
    /// tool axis to just before the software limit switch): the marker's one traverse. Where
    /// that is, only the machine knows.
    Limit,
}

/// A move in the machine's frame (a marker before its moves).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct MachineMove {
    /// Where it goes.
    pub target: MachineTarget,
    /// The axes it moves there (X Y Z A B C), with their coordinates for
    /// [`MachineTarget::Machine`] and [`MachineTarget::Builder`] (in the program's length
    /// units) and `0` for a reference or fixed position (which one, not where, is known).
    pub axes: [Option<f64>; 6],
}

impl MachineMove {
    /// How many traverses of the stream the marker governs.
    pub fn moves(&self) -> usize {
        match self.target {
            MachineTarget::Reference(_) => 2,
            MachineTarget::Direct(_) | MachineTarget::Fixed(_) | MachineTarget::Machine | MachineTarget::Builder | MachineTarget::Limit => {
                1
            }
        }
    }

    /// `G28 Z`, `G53 X10 Z0`: the axes as a reader names them.
    pub fn describe(&self) -> String {
        const NAMES: [&str; 6] = ["X", "Y", "Z", "A", "B", "C"];
        let axes: Vec<String> = self
            .axes
            .iter()
            .zip(NAMES)
            .filter_map(|(v, n)| match (v, self.target) {
                (Some(_), MachineTarget::Reference(_) | MachineTarget::Direct(_) | MachineTarget::Fixed(_) | MachineTarget::Limit) => {
                    Some(n.to_owned())
                }
                (Some(v), MachineTarget::Machine | MachineTarget::Builder) => Some(format!("{n}{v}")),
                (None, _) => None,
            })
            .collect();
        match self.target {
            MachineTarget::Reference(k) => format!("return to reference position {k} in {}", axes.join(" ")),
            MachineTarget::Direct(k) => format!("straight approach of reference position {k} in {}", axes.join(" ")),
            MachineTarget::Fixed(k) => format!("straight approach of fixed point {k} in {}", axes.join(" ")),
            MachineTarget::Machine => format!("move in machine coordinates to {}", axes.join(" ")),
            MachineTarget::Limit => format!("retract to the travel limit in {}", axes.join(" ")),
            MachineTarget::Builder => {
                format!("move in coordinates from the machine builder's datum to {}", axes.join(" "))
            }
        }
    }
}

/// A tilted working plane: where its origin lies and how its axes stand, in the untilted
/// program coordinates. A point `p` of the tilted plane is `origin + rotation · p` there;
/// `rotation`'s columns are the tilted X, Y and Z (the tool axis) axes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Frame {
    /// The tilted plane's origin, in the untilted coordinates (program units).
    pub origin: [f64; 3],
    /// Rows of the rotation matrix.
    pub rotation: [[f64; 3]; 3],
}

impl Frame {
    /// The untilted frame.
    pub const IDENTITY: Frame = Frame { origin: [0.0; 3], rotation: [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]] };

    /// Point `p` of the tilted plane in the untilted coordinates.
    pub fn to_base(&self, p: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        std::array::from_fn(|i| self.origin[i] + r[i][0] * p[0] + r[i][1] * p[1] + r[i][2] * p[2])
    }

    /// Direction `v` of the tilted plane in the untilted coordinates.
    pub fn dir_to_base(&self, v: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        std::array::from_fn(|i| r[i][0] * v[0] + r[i][1] * v[1] + r[i][2] * v[2])
    }

    /// Untilted point `q` in the tilted plane's coordinates.
    pub fn from_base(&self, q: [f64; 3]) -> [f64; 3] {
        let r = &self.rotation;
        let d = [q[0] - self.origin[0], q[1] - self.origin[1], q[2] - self.origin[2]];
        std::array::from_fn(|j| r[0][j] * d[0] + r[1][j] * d[1] + r[2][j] * d[2])
    }

    /// The frame of `inner` (stated in this frame's coordinates) in the untilted ones.
    pub fn then(&self, inner: &Frame) -> Frame {
        let (a, b) = (&self.rotation, &inner.rotation);
        let rotation = std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()));
        Frame { origin: self.to_base(inner.origin), rotation }
    }

    /// The tool axis (the tilted Z) in the untilted coordinates.
    pub fn axis(&self) -> [f64; 3] {
        self.dir_to_base([0.0, 0.0, 1.0])
    }

    /// Whether the frame is the untilted one, to within `1e-9`.
    pub fn is_identity(&self) -> bool {
        let id = Frame::IDENTITY;
        (0..3).all(|i| self.origin[i].abs() < 1e-9 && (0..3).all(|j| (self.rotation[i][j] - id.rotation[i][j]).abs() < 1e-9))
    }

    /// The rotation as spatial angles A, B, C (degrees): about the fixed X, then the fixed
    /// Y, then the fixed Z, `Rz(C)·Ry(B)·Rx(A)` (Heidenhain `PLANE SPATIAL`). B within
    /// ±90°; where it is ±90°, A is 0.
    pub fn spatial_angles(&self) -> [f64; 3] {
        let r = &self.rotation;
        let b = (-r[2][0]).atan2(r[0][0].hypot(r[1][0]));
        let (a, c) =
            if r[0][0].hypot(r[1][0]) < 1e-9 { (0.0, (-r[0][1]).atan2(r[1][1])) } else { (r[2][1].atan2(r[2][2]), r[1][0].atan2(r[0][0])) };
        [a, b, c].map(degrees)
    }

    /// The rotation as Euler angles (degrees): about Z by the first, the turned X by the
    /// second, the turned Z by the third, `Rz(a)·Rx(b)·Rz(c)` (Fanuc `G68.2 I J K`). The
    /// second within 0…180°; where it is 0 or 180°, the third is 0.
    pub fn euler_zxz(&self) -> [f64; 3] {
        let r = &self.rotation;
        let s = r[0][2].hypot(r[1][2]);
        let b = s.atan2(r[2][2]);
        let (a, c) = if s < 1e-9 { (r[1][0].atan2(r[0][0]), 0.0) } else { (r[0][2].atan2(-r[1][2]), r[2][0].atan2(r[2][1])) };
        [a, b, c].map(degrees)
    }

    /// The rotation axis by axis (degrees): about X, then the turned Y, then the turned Z,
    /// `Rx(a)·Ry(b)·Rz(c)` (Siemens `CYCLE800` mode 57). The second within ±90°; where it is
    /// ±90°, the first is 0.
    pub fn axis_by_axis_xyz(&self) -> [f64; 3] {
        let r = &self.rotation;
        let cb = r[1][2].hypot(r[2][2]);
        let b = r[0][2].atan2(cb);
        let (a, c) = if cb < 1e-9 { (0.0, r[1][0].atan2(r[1][1])) } else { ((-r[1][2]).atan2(r[2][2]), (-r[0][1]).atan2(r[0][0])) };
        [a, b, c].map(degrees)
    }
}

/// Radians to degrees, with the float noise of whole-degree angles taken off (`30.000000000000004`).
fn degrees(v: f64) -> f64 {
    let d = v.to_degrees();
    let whole = (d * 1e9).round() / 1e9;
    if whole == 0.0 { 0.0 } else { whole }
}

/// Work offset indexes above this one are the additional work offsets: `EXTENDED_WCS + n` is
/// `G54.1 Pn` (Fanuc), `G154 Pn` (Haas), `G15 Hn` (Okuma).
pub const EXTENDED_WCS: u16 = 100;

/// The most additional work offsets a control has (Fanuc's G54.1 P1 to P300).
pub const MAX_EXTENDED_WCS: u16 = 300;

/// A canonical machining function, or a marker.
#[derive(Clone, Debug, PartialEq)]
pub enum CanonOp {
    /// `USE_LENGTH_UNITS`
    UseLengthUnits(Units),
    /// `SELECT_PLANE`
    SelectPlane(Plane),
    /// `SET_G5X_OFFSET(index, x, y, z, a, b, c)`: 1 to 9 for G54 to G59.3; from
    /// [`EXTENDED_WCS`] + 1 on, the additional work offsets (`G54.1 P1`, `G154 P1`, `G15 H1`).
    SetG5xOffset(u16, [f64; 6]),
    /// `SET_G92_OFFSET(x, y, z, a, b, c)`
    SetG92Offset([f64; 6]),
    /// `SET_FEED_RATE`
    SetFeedRate(f64),
    /// `SET_SPINDLE_SPEED`
    SetSpindleSpeed(f64),
    /// `START_SPINDLE_CLOCKWISE`
    StartSpindleClockwise,
    /// `START_SPINDLE_COUNTERCLOCKWISE`
    StartSpindleCounterclockwise,
    /// `STOP_SPINDLE_TURNING`
    StopSpindleTurning,
    /// `SELECT_TOOL`
    SelectTool(u32),
    /// `CHANGE_TOOL`
    ChangeTool(u32),
    /// `CHANGE_TOOL_NUMBER`: the tool in the spindle is taken to be this one, without a
    /// change (LinuxCNC M61).
    ChangeToolNumber(u32),
    /// `USE_TOOL_LENGTH_OFFSET` (x, y, z offsets)
    UseToolLengthOffset([f64; 3]),
    /// `STRAIGHT_TRAVERSE(x, y, z, a, b, c)`
    StraightTraverse([f64; 6]),
    /// `STRAIGHT_FEED(x, y, z, a, b, c)`
    StraightFeed([f64; 6]),
    /// `ARC_FEED(first_end, second_end, first_axis, second_axis, rotation, axis_end, a, b, c)`
    ArcFeed {
        /// End on the plane's first axis.
        first_end: f64,
        /// End on the plane's second axis.
        second_end: f64,
        /// Centre on the first axis.
        first_axis: f64,
        /// Centre on the second axis.
        second_axis: f64,
        /// Turns: positive counter-clockwise, negative clockwise.
        rotation: i32,
        /// End on the normal axis.
        axis_end: f64,
        /// Rotary axes at the end.
        abc: [f64; 3],
    },
    /// `DWELL(seconds)`
    Dwell(f64),
    /// `MIST_ON`
    MistOn,
    /// `MIST_OFF`
    MistOff,
    /// `FLOOD_ON`
    FloodOn,
    /// `FLOOD_OFF`
    FloodOff,
    /// `PROGRAM_STOP`
    ProgramStop,
    /// `OPTIONAL_PROGRAM_STOP`
    OptionalProgramStop,
    /// `ENABLE_FEED_OVERRIDE()` (`true`) or `DISABLE_FEED_OVERRIDE()`.
    FeedOverride(bool),
    /// `ENABLE_SPEED_OVERRIDE(0)` (`true`) or `DISABLE_SPEED_OVERRIDE(0)`.
    SpeedOverride(bool),
    /// `PROGRAM_END`
    ProgramEnd,
    /// `FINISH`: the program ended at its closing `%` without M2/M30.
    Finish,
    /// `COMMENT(text)`
    Comment(String),
    /// `MESSAGE(text)`
    Message(String),
    /// `LOGOPEN(name)`, `LOGAPPEND(name)`, `LOGCLOSE()`, `LOG(text)`: LinuxCNC's log file.
    Log(LogFile, String),
    /// Marker: distance mode changed.
    DistanceMode(DistanceMode),
    /// Marker: a canned-cycle hole starts; the moves that follow expand it.
    CycleBegin(Box<CycleIntent>),
    /// Marker: the current canned-cycle hole ends.
    CycleEnd,
    /// Marker: the canned cycle was cancelled (G80).
    CycleCancel,
    /// Marker: a machine setting of the block (offset numbers, compensation side, block delete).
    Setting(Setting),
    /// Marker: a lathe cycle starts (roughing, finishing, grooving, threading, a single
    /// pass); the moves up to [`CanonOp::TurningEnd`] expand it.
    Turning(Box<TurnIntent>),
    /// Marker: the lathe cycle's moves end.
    TurningEnd,
    /// `SET_FEED_MODE(0, n)`: feed per minute (0) or per spindle revolution (1, G95).
    SetFeedMode(FeedMode),
    /// `SET_SPINDLE_MODE(0 max)`: with a limit, S is a constant surface speed (G96) and the
    /// spindle turns at most `max` 1/min ([`NO_SPINDLE_LIMIT`] when none was set); without,
    /// S is in 1/min (G97, printed as 0).
    SetSpindleMode(Option<f64>),
    /// `START_SPEED_FEED_SYNC(pitch,0)`: the moves that follow advance `pitch` per spindle
    /// revolution (G33 threading, G33.1 rigid tapping).
    StartSpeedFeedSync(f64),
    /// `STOP_SPEED_FEED_SYNCH()`
    StopSpeedFeedSync,
    /// `RIGID_TAP(x, y, z)`: a synchronised feed to the bottom and, spindle reversed, back to
    /// where it started.
    RigidTap([f64; 3]),
    /// `ORIENT_SPINDLE(0, angle, mode)`: stop the spindle at `angle` degrees; mode 0 takes
    /// the shorter way, 1 turns clockwise, 2 counterclockwise (M19 R.. P..).
    OrientSpindle {
        /// Degrees.
        angle: f64,
        /// 0 the shorter way, 1 clockwise, 2 counterclockwise.
        mode: u8,
    },
    /// `SPINDLE.0.WAIT_ORIENT_COMPLETE(timeout)`: wait up to `timeout` seconds for the
    /// orientation to finish (M19 Q..).
    WaitOrientComplete(f64),
    /// `TURN_PROBE_ON()`
    TurnProbeOn,
    /// `TURN_PROBE_OFF()`
    TurnProbeOff,
    /// `STRAIGHT_PROBE(x, y, z, a, b, c)`: a feed towards the point that stops where the
    /// probe touches (G38.2 to G38.5).
    StraightProbe([f64; 6]),
    /// Marker: the tool axis vector (from the tip towards the holder, program coordinates)
    /// for the moves that follow, where it changes from +Z or from the last one stated
    /// (CLDATA `GOTO/x,y,z,i,j,k`). The moves stay the tool tip's; 5-axis output reads this.
    ToolAxis([f64; 3]),
    /// Marker: the move(s) that follow go to a position in the machine's frame (a reference
    /// return, a machine-coordinate move), not the work offset's.
    MachineMove(Box<MachineMove>),
    /// Marker: the axes whose position the program knows in the work offset's frame (bit `k`
    /// for axis `k` of X Y Z A B C), from the next move on, where that changes. A stream starts
    /// with none known: the program starts wherever the machine was. An axis becomes known
    /// where a block states it absolutely; it is unknown again after a [`CanonOp::MachineMove`]
    /// moved it (the marker's own moves, not this one, say so: a reader takes its axes as
    /// unknown after its last move), and after a code whose motion the reading does not know.
    /// An incremental move of an unknown axis leaves it unknown: its positions in the stream
    /// are counted from an assumed 0, which a writer must never state. Not printed.
    Known(u8),
    /// Marker: a coordinate set (`G92`, a lathe's `G50 X.. Z..`) of axes whose position the
    /// program does not know (bit `k` for axis `k`): the shift it makes is counted from an
    /// assumed position, so the positions that follow are known in no frame a writer could
    /// state. Not printed.
    ShiftUnknown(u8),
    /// Marker: the tilted working plane in force from here (see [`Frame`]), `None` when
    /// untilted again. The moves that follow stay in the tilted plane's coordinates.
    WorkPlane(Option<Box<Frame>>),
    /// Marker: the spindle the spindle ops that follow (speed, turning, stop, orientation)
    /// address, where it changes: another than the main one (Siemens `M2=3`, `S2=`,
    /// `SPOS[2]=`, `SETMS(2)`; a driven tool's own codes, Haas `M133`), or the main again.
    Spindle(SpindleId),
    /// `NURBS_FEED(n, ...)`: a feed along a spline of `points` control points (the start
    /// among them) that ends at `end` (G5.1, G5.2 … G5.3); rs274 prints only the count.
    NurbsFeed {
        /// Control points, the start point included.
        points: u32,
        /// The end point.
        end: [f64; 6],
    },
}

/// Which spindle a spindle op addresses.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum SpindleId {
    /// The main (work) spindle: the only one of most machines, spindle 1 of a Siemens control.
    #[default]
    Main,
    /// Spindle `n` as the program numbers it (`M2=3`: 2), not the main one: a counter
    /// spindle or a driven tool, as the machine is built.
    Number(u8),
    /// The driven (live) tool's drive, named by its own codes (Haas `M133`-`M135`).
    Driven,
}

impl SpindleId {
    /// In words: `main spindle`, `spindle 2`, `driven tool` (after "the").
    pub fn words(self) -> String {
        match self {
            SpindleId::Main => "main spindle".to_owned(),
            SpindleId::Number(n) => format!("spindle {n}"),
            SpindleId::Driven => "driven tool".to_owned(),
        }
    }
}

/// What a log-file directive does.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LogFile {
    /// Opens the file the rest of the comment names, empty.
    Open,
    /// Opens it to add to what it holds.
    Append,
    /// Closes it.
    Close,
    /// Writes the rest of the comment, its parameters replaced by their values.
    Line,
}

/// What a feed rate is per.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum FeedMode {
    /// Units per minute (G94).
    PerMinute,
    /// Units per spindle revolution (G95).
    PerRevolution,
}

/// Every axis known ([`CanonOp::Known`]): X Y Z A B C.
pub const ALL_KNOWN: u8 = 0b11_1111;

/// A canonical op with its provenance.
#[derive(Clone, Debug, PartialEq)]
pub struct Canon {
    /// The op.
    pub op: CanonOp,
    /// Byte range of the source block.
    pub origin: TextRange,
    /// 1-based source line.
    pub line: u32,
}

/// The memory one move costs at the most where it is kept, for a sink that does not say what it
/// keeps ([`CanonSink::kept_bytes`]): a plan's feature recognition holds some 380 bytes a move
/// of a plain loop of G1 moves at its peak (the profile's pieces beside the toolpath).
pub const BYTES_PER_MOVE: u64 = 400;

/// Receives canonical ops as the interpreter produces them.
pub trait CanonSink {
    /// Takes one op.
    fn emit(&mut self, canon: Canon);

    /// The memory the sink keeps, in bytes, after the interpreter has made `moves` moves: what
    /// the analysis bound in memory (`Profile::max_repeated_bytes`) counts. By default the most
    /// a kept move costs anywhere ([`BYTES_PER_MOVE`]); a sink that knows better
    /// says so, and one that keeps nothing (it streams) says 0.
    fn kept_bytes(&self, moves: u64) -> u64 {
        moves.saturating_mul(BYTES_PER_MOVE)
    }

    /// Takes a straight move to `to` (a traverse when `rapid`, else a feed) from the block at
    /// `origin`, on `line`: the op [`CanonSink::emit`] would take as
    /// `Canon { op: StraightTraverse(to) | StraightFeed(to), origin, line }`. The interpreter
    /// hands the common move here where no stage stands between it and the sink (or where the
    /// corner stage, the only one, lets a move go while nothing else waits in it); a sink that
    /// need not keep the op (one that prints it) takes the position where it lies, without an
    /// op made, moved and dropped for each move. By default the op, to `emit`.
    #[inline]
    fn straight(&mut self, rapid: bool, to: &[f64; 6], origin: TextRange, line: u32) {
        let op = if rapid { CanonOp::StraightTraverse(*to) } else { CanonOp::StraightFeed(*to) };
        self.emit(Canon { op, origin, line });
    }
}

impl CanonSink for Vec<Canon> {
    fn emit(&mut self, canon: Canon) {
        self.push(canon);
    }

    /// What the vector holds: its capacity in ops (text an op owns, such as a comment's, is
    /// left out).
    fn kept_bytes(&self, _: u64) -> u64 {
        (self.capacity() * std::mem::size_of::<Canon>()) as u64
    }
}

/// Appends `v` with four decimals, exactly as `format!("{:.4}", v)` (and so as rs274's
/// `%.4f`) would, without the general float formatter on the common path.
///
/// Fast path: scale by 10⁴ and round. That is exact unless the scaled value lies within a
/// hair of a rounding tie, where binary representation decides; those rare values, and
/// magnitudes beyond 2⁵³/10⁴, go to the standard formatter.
pub fn push_f4(out: &mut Vec<u8>, v: f64) {
    let mut buf = [0u8; 32];
    match f4_fast(v, &mut buf) {
        Some(len) => out.extend_from_slice(&buf[..len]),
        None => {
            let _ = write!(out, "{v:.4}");
        }
    }
}

/// Two decimal digits for each value 0..100.
const DIGIT_PAIRS: &[u8; 200] = b"0001020304050607080910111213141516171819\
2021222324252627282930313233343536373839\
4041424344454647484950515253545556575859\
6061626364656667686970717273747576777879\
8081828384858687888990919293949596979899";

/// [`push_f4`]'s fast path: writes `v` with four decimals at the start of `buf` and returns
/// the length, or `None` where the standard formatter must decide (NaN, huge, near a tie).
///
/// Inlined: the prologue and epilogue of a call cost as much as a third of its work.
#[inline(always)]
fn f4_fast(v: f64, buf: &mut [u8; 32]) -> Option<usize> {
    if v.to_bits() == 0 {
        buf[..6].copy_from_slice(b"0.0000");
        return Some(6);
    }
    let scaled = v.abs() * 10_000.0;
    if scaled.is_nan() || scaled >= 9.0e15 {
        return None;
    }
    // Below 2⁶³: the signed conversions are exact, and cheaper than the unsigned ones.
    let whole = scaled as i64;
    let frac = scaled - whole as f64;
    let whole = whole as u64;
    if (frac - 0.5).abs() < 1e-6 {
        return None;
    }
    let n = whole + u64::from(frac > 0.5);
    let (mut int, frac) = (n / 10_000, (n % 10_000) as usize);
    let digits = match int {
        0..=9 => 1,
        10..=99 => 2,
        100..=999 => 3,
        1000..=9999 => 4,
        _ => int.ilog10() as usize + 1,
    };
    let sign = usize::from(v.is_sign_negative());
    let len = sign + digits + 5;
    buf[0] = b'-';
    let pair = |k: usize| [DIGIT_PAIRS[2 * k], DIGIT_PAIRS[2 * k + 1]];
    buf[len - 4..len - 2].copy_from_slice(&pair(frac / 100));
    buf[len - 2..len].copy_from_slice(&pair(frac % 100));
    buf[len - 5] = b'.';
    let mut i = len - 5;
    while int >= 10 {
        i -= 2;
        buf[i..i + 2].copy_from_slice(&pair((int % 100) as usize));
        int /= 100;
    }
    if i > sign {
        buf[i - 1] = b'0' + int as u8;
    }
    Some(len)
}

/// The tilted plane marker: origin, then the tilted X and Z axes.
fn work_plane(out: &mut Vec<u8>, f: &Frame) {
    let [x, y, z] = f.origin;
    let r = &f.rotation;
    put(
        out,
        format_args!(
            "COMMENT(\"ncplan: work plane origin {} {} {} x {:.6} {:.6} {:.6} z {:.6} {:.6} {:.6}\")",
            F4(x),
            F4(y),
            F4(z),
            r[0][0],
            r[1][0],
            r[2][0],
            r[0][2],
            r[1][2],
            r[2][2]
        ),
    );
}

/// Formats `v` with four decimals, as LinuxCNC's `rs274` prints.
struct F4(f64);

impl fmt::Display for F4 {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let mut s = Vec::with_capacity(24);
        push_f4(&mut s, self.0);
        f.write_str(&String::from_utf8_lossy(&s))
    }
}

/// `NAME(x, y, z, a, b, c)` with each number written by `number`.
fn straight(out: &mut Vec<u8>, name: &[u8], p: &[f64; 6], mut number: impl FnMut(&mut Vec<u8>, f64)) {
    out.extend_from_slice(name);
    for (i, &x) in p.iter().enumerate() {
        if i > 0 {
            out.extend_from_slice(b", ");
        }
        number(out, x);
    }
    out.push(b')');
}

fn join6(out: &mut Vec<u8>, v: &[f64; 6]) {
    for (i, x) in v.iter().enumerate() {
        if i > 0 {
            out.extend_from_slice(b", ");
        }
        push_f4(out, *x);
    }
}

fn quoted(out: &mut Vec<u8>, s: &str) {
    out.push(b'"');
    for c in s.chars() {
        match c {
            '"' => out.extend_from_slice(b"\\\""),
            '\\' => out.extend_from_slice(b"\\\\"),
            c if c.is_control() => {}
            c => out.extend_from_slice(c.encode_utf8(&mut [0; 4]).as_bytes()),
        }
    }
    out.push(b'"');
}

/// Appends the call as `rs274 -g` prints it (without its sequence prefix) and a newline.
pub fn write_call(out: &mut String, op: &CanonOp) {
    let mut bytes = Vec::with_capacity(96);
    write_call_bytes(&mut bytes, op);
    out.push_str(&String::from_utf8_lossy(&bytes));
}

/// [`write_call`] into bytes (UTF-8), for printers that write to a stream. One line per
/// call; the calls with more to them than a name and numbers have writers of their own.
pub fn write_call_bytes(out: &mut Vec<u8>, op: &CanonOp) {
    match op {
        CanonOp::UseLengthUnits(u) => out.extend_from_slice(length_units(*u)),
        CanonOp::SelectPlane(p) => out.extend_from_slice(select_plane(*p)),
        CanonOp::SetG5xOffset(i, v) => {
            put(out, format_args!("SET_G5X_OFFSET({i}, "));
            six_then_close(out, v);
        }
        CanonOp::SetG92Offset(v) => {
            out.extend_from_slice(b"SET_G92_OFFSET(");
            six_then_close(out, v);
        }
        CanonOp::SetFeedRate(f) => put(out, format_args!("SET_FEED_RATE({})", F4(*f))),
        CanonOp::SetSpindleSpeed(s) => put(out, format_args!("SET_SPINDLE_SPEED(0, {})", F4(*s))),
        CanonOp::StartSpindleClockwise => out.extend_from_slice(b"START_SPINDLE_CLOCKWISE(0)"),
        CanonOp::StartSpindleCounterclockwise => out.extend_from_slice(b"START_SPINDLE_COUNTERCLOCKWISE(0)"),
        CanonOp::StopSpindleTurning => out.extend_from_slice(b"STOP_SPINDLE_TURNING(0)"),
        CanonOp::SelectTool(t) => put(out, format_args!("SELECT_TOOL({t})")),
        CanonOp::ChangeTool(t) => put(out, format_args!("CHANGE_TOOL({t})")),
        CanonOp::ChangeToolNumber(t) => put(out, format_args!("CHANGE_TOOL_NUMBER({t})")),
        CanonOp::UseToolLengthOffset(offset) => tool_length_offset(out, offset),
        CanonOp::StraightTraverse(p) => straight(out, b"STRAIGHT_TRAVERSE(", p, push_f4),
        CanonOp::StraightFeed(p) => straight(out, b"STRAIGHT_FEED(", p, push_f4),
        CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end, abc } => put(
            out,
            format_args!(
                "ARC_FEED({}, {}, {}, {}, {rotation}, {}, {}, {}, {})",
                F4(*first_end),
                F4(*second_end),
                F4(*first_axis),
                F4(*second_axis),
                F4(*axis_end),
                F4(abc[0]),
                F4(abc[1]),
                F4(abc[2])
            ),
        ),
        CanonOp::Dwell(s) => put(out, format_args!("DWELL({})", F4(*s))),
        CanonOp::MistOn => out.extend_from_slice(b"MIST_ON()"),
        CanonOp::MistOff => out.extend_from_slice(b"MIST_OFF()"),
        CanonOp::FloodOn => out.extend_from_slice(b"FLOOD_ON()"),
        CanonOp::FloodOff => out.extend_from_slice(b"FLOOD_OFF()"),
        CanonOp::ProgramStop => out.extend_from_slice(b"PROGRAM_STOP()"),
        CanonOp::OptionalProgramStop => out.extend_from_slice(b"OPTIONAL_PROGRAM_STOP()"),
        CanonOp::FeedOverride(on) => out.extend_from_slice(if *on { b"ENABLE_FEED_OVERRIDE()" } else { b"DISABLE_FEED_OVERRIDE()" }),
        CanonOp::SpeedOverride(on) => out.extend_from_slice(if *on { b"ENABLE_SPEED_OVERRIDE(0)" } else { b"DISABLE_SPEED_OVERRIDE(0)" }),
        CanonOp::ProgramEnd => out.extend_from_slice(b"PROGRAM_END()"),
        CanonOp::Finish => out.extend_from_slice(b"FINISH()"),
        CanonOp::Comment(s) => text_call(out, b"COMMENT(", s),
        CanonOp::Message(s) => text_call(out, b"MESSAGE(", s),
        CanonOp::Log(kind, s) => log_call(out, *kind, s),
        CanonOp::DistanceMode(m) => out.extend_from_slice(distance_mode(*m)),
        CanonOp::CycleBegin(c) => cycle_begin(out, c),
        CanonOp::CycleEnd => out.extend_from_slice(b"COMMENT(\"ncplan: cycle end\")"),
        CanonOp::Turning(t) => turning(out, t),
        CanonOp::TurningEnd => out.extend_from_slice(b"COMMENT(\"ncplan: lathe cycle end\")"),
        CanonOp::ToolAxis([i, j, k]) => put(out, format_args!("COMMENT(\"ncplan: tool axis {i:.6} {j:.6} {k:.6}\")")),
        CanonOp::WorkPlane(None) => out.extend_from_slice(b"COMMENT(\"ncplan: work plane untilted\")"),
        CanonOp::WorkPlane(Some(f)) => work_plane(out, f),
        CanonOp::Spindle(id) => put(out, format_args!("COMMENT(\"ncplan: spindle ops: {}\")", id.words())),
        CanonOp::CycleCancel => out.extend_from_slice(b"COMMENT(\"interpreter: motion mode set to none\")"),
        CanonOp::Setting(s) => setting(out, s),
        CanonOp::MachineMove(m) => put(out, format_args!("COMMENT(\"ncplan: {}\")", m.describe())),
        CanonOp::SetFeedMode(m) => out.extend_from_slice(feed_mode(*m)),
        CanonOp::SetSpindleMode(max) => put(out, format_args!("SET_SPINDLE_MODE(0 {})", F4(max.unwrap_or(0.0)))),
        CanonOp::StartSpeedFeedSync(pitch) => put(out, format_args!("START_SPEED_FEED_SYNC({pitch:.6},0)")),
        CanonOp::StopSpeedFeedSync => out.extend_from_slice(b"STOP_SPEED_FEED_SYNCH()"),
        CanonOp::RigidTap([x, y, z]) => put(out, format_args!("RIGID_TAP({}, {}, {})", F4(*x), F4(*y), F4(*z))),
        CanonOp::OrientSpindle { angle, mode } => put(out, format_args!("ORIENT_SPINDLE(0, {}, {mode})", F4(*angle))),
        CanonOp::TurnProbeOn => out.extend_from_slice(b"TURN_PROBE_ON()"),
        CanonOp::TurnProbeOff => out.extend_from_slice(b"TURN_PROBE_OFF()"),
        CanonOp::StraightProbe(p) => straight(out, b"STRAIGHT_PROBE(", p, push_f4),
        CanonOp::NurbsFeed { points, .. } => put(out, format_args!("NURBS_FEED({points}, ...)")),
        CanonOp::WaitOrientComplete(t) => put(out, format_args!("SPINDLE.0.WAIT_ORIENT_COMPLETE({})", F4(*t))),
        // A writer's and a check's marker, not a call: no line.
        CanonOp::Known(_) | CanonOp::ShiftUnknown(_) => return,
    }
    out.push(b'\n');
}

/// Appends formatted text (`write!` into bytes, which cannot fail).
fn put(out: &mut Vec<u8>, args: fmt::Arguments<'_>) {
    let _ = out.write_fmt(args);
}

/// `USE_LENGTH_UNITS(...)`.
fn length_units(u: Units) -> &'static [u8] {
    match u {
        Units::Mm => b"USE_LENGTH_UNITS(CANON_UNITS_MM)",
        Units::Inch => b"USE_LENGTH_UNITS(CANON_UNITS_INCHES)",
    }
}

/// `SELECT_PLANE(...)`.
fn select_plane(p: Plane) -> &'static [u8] {
    match p {
        Plane::Xy => b"SELECT_PLANE(CANON_PLANE_XY)",
        Plane::Xz => b"SELECT_PLANE(CANON_PLANE_XZ)",
        Plane::Yz => b"SELECT_PLANE(CANON_PLANE_YZ)",
    }
}

/// The six numbers of an offset call and its closing bracket.
fn six_then_close(out: &mut Vec<u8>, v: &[f64; 6]) {
    join6(out, v);
    out.push(b')');
}

/// `USE_TOOL_LENGTH_OFFSET(x y z, ...)`: the offsets, and rs274's zero wear and zero
/// rotary offsets.
fn tool_length_offset(out: &mut Vec<u8>, [x, y, z]: &[f64; 3]) {
    put(out, format_args!("USE_TOOL_LENGTH_OFFSET({} {} {}, 0.0000 0.0000 0.0000, 0.0000 0.0000 0.0000)", F4(*x), F4(*y), F4(*z)));
}

/// `NAME("text")`: a call whose one argument is quoted text.
fn text_call(out: &mut Vec<u8>, name: &[u8], s: &str) {
    out.extend_from_slice(name);
    quoted(out, s);
    out.push(b')');
}

/// `LOGOPEN("file")`, `LOGAPPEND("file")`, `LOG("line")`, `LOGCLOSE()`.
fn log_call(out: &mut Vec<u8>, kind: LogFile, s: &str) {
    out.extend_from_slice(match kind {
        LogFile::Open => b"LOGOPEN(".as_slice(),
        LogFile::Append => b"LOGAPPEND(",
        LogFile::Close => b"LOGCLOSE(",
        LogFile::Line => b"LOG(",
    });
    if kind != LogFile::Close {
        quoted(out, s);
    }
    out.push(b')');
}

/// The comment LinuxCNC's interpreter writes when the distance mode changes.
fn distance_mode(m: DistanceMode) -> &'static [u8] {
    match m {
        DistanceMode::Absolute => b"COMMENT(\"interpreter: distance mode changed to absolute\")",
        DistanceMode::Incremental => b"COMMENT(\"interpreter: distance mode changed to incremental\")",
    }
}

/// ncplan's marker of a canned cycle's start: its code, kind, position, levels, and the peck
/// and dwell where it has them.
fn cycle_begin(out: &mut Vec<u8>, c: &CycleIntent) {
    put(
        out,
        format_args!(
            "COMMENT(\"ncplan: cycle begin {} {} x={} y={} bottom={} r={} clear={}",
            c.code,
            c.kind.label(),
            F4(c.x),
            F4(c.y),
            F4(c.bottom),
            F4(c.r_plane),
            F4(c.clear)
        ),
    );
    if let Some(q) = c.peck {
        put(out, format_args!(" q={}", F4(q)));
    }
    if let Some(p) = c.dwell {
        put(out, format_args!(" dwell={}", F4(p)));
    }
    out.extend_from_slice(b"\")");
}

/// ncplan's marker of a setting: a length offset, cutter compensation, an optional block, a
/// tool's name (without the characters a comment cannot hold).
fn setting(out: &mut Vec<u8>, s: &Setting) {
    let _ = match s {
        Setting::LengthOffset(h) => write!(out, "COMMENT(\"ncplan: length offset H{h}\")"),
        Setting::CutterComp(None) => write!(out, "COMMENT(\"ncplan: cutter compensation off\")"),
        Setting::CutterComp(Some(c)) => {
            let side = if c.left { "left" } else { "right" };
            let _ = write!(out, "COMMENT(\"ncplan: cutter compensation {side}");
            if let Some(d) = c.number {
                let _ = write!(out, " D{d}");
            }
            if let Some(r) = c.radius {
                let _ = write!(out, " radius {}", F4(r));
            }
            if let Some(t) = c.tip {
                let _ = write!(out, " tip {t}");
            }
            write!(out, "\")")
        }
        Setting::MillCycle(Some(name)) => {
            let name: String = name.chars().filter(|c| !matches!(c, '"' | '\\') && !c.is_control()).collect();
            write!(out, "COMMENT(\"ncplan: milling cycle {name} begins\")")
        }
        Setting::MillCycle(None) => write!(out, "COMMENT(\"ncplan: milling cycle ends\")"),
        Setting::HoleMilled(key) => {
            let key: String = key.chars().filter(|c| !matches!(c, '"' | '\\') && !c.is_control()).collect();
            write!(out, "COMMENT(\"ncplan: milling cycle makes the hole {key}\")")
        }
        Setting::CycleSurface(z) => write!(out, "COMMENT(\"ncplan: milling cycle surface {}\")", F4(*z)),
        Setting::CylinderWrap(Some(r)) => write!(out, "COMMENT(\"ncplan: cylinder wrap radius {}\")", F4(*r)),
        Setting::CylinderWrap(None) => write!(out, "COMMENT(\"ncplan: cylinder wrap off\")"),
        Setting::BlockDelete => write!(out, "COMMENT(\"ncplan: optional block\")"),
        Setting::WorkOffset(i) => write!(out, "COMMENT(\"ncplan: work offset {i} stated\")"),
        Setting::DiameterMode(on) => write!(out, "COMMENT(\"ncplan: diameter mode {}\")", if *on { "on" } else { "off" }),
        Setting::ToolCentrePoint(on) => {
            write!(out, "COMMENT(\"ncplan: tool centre point control {}\")", if *on { "on" } else { "off" })
        }
        Setting::ToolName(n, name) => {
            let name: String = name.chars().filter(|c| !matches!(c, '"' | '\\') && !c.is_control()).collect();
            write!(out, "COMMENT(\"ncplan: tool {n} is {name}\")")
        }
    };
}

/// ncplan's marker of a lathe cycle's start: its code, kind and the values it states.
fn turning(out: &mut Vec<u8>, t: &TurnIntent) {
    put(out, format_args!("COMMENT(\"ncplan: lathe cycle {} {}", t.code, t.kind.map_or("", TurnKind::as_str)));
    let values = [
        ("depth", t.depth_of_cut),
        ("retract", t.retract),
        ("u", t.allowance_x),
        ("w", t.allowance_z),
        ("pitch", t.pitch),
        ("height", t.thread_depth),
        ("first", t.first_cut),
        ("min", t.min_cut),
        ("finish", t.finish_allowance),
        ("angle", t.angle),
        ("peck", t.peck),
        ("step", t.step),
    ];
    for (name, v) in values {
        if let Some(v) = v {
            put(out, format_args!(" {name}={}", F4(v)));
        }
    }
    if let Some(n) = t.finish_passes {
        put(out, format_args!(" passes={n}"));
    }
    if let Some([lo, hi]) = t.span {
        put(out, format_args!(" z={}..{}", F4(lo), F4(hi)));
    }
    if let Some([x, z]) = t.relief {
        put(out, format_args!(" relief={},{}", F4(x), F4(z)));
    }
    if let Some(n) = t.divisions {
        put(out, format_args!(" divisions={n}"));
    }
    out.extend_from_slice(b"\")");
}

/// `SET_FEED_MODE(0, mode)`.
fn feed_mode(m: FeedMode) -> &'static [u8] {
    match m {
        FeedMode::PerMinute => b"SET_FEED_MODE(0, 0)",
        FeedMode::PerRevolution => b"SET_FEED_MODE(0, 1)",
    }
}

/// Writes canonical calls like [`write_call_bytes`], remembering recently formatted numbers of
/// straight moves: part programs repeat coordinates (a row's Y, a level's Z, a grid's X), and
/// number formatting is the dearest part of printing. The output is the same byte for byte.
pub struct CallWriter {
    /// Direct-mapped: slot by a hash of the value's bits; (bits, length, text). Of a size
    /// known when compiled, so that a slot needs no bounds check.
    cache: Box<[(u64, u8, [u8; CACHED]); SLOTS]>,
    /// Where [`CallWriter::write_straight`] assembles a straight move's line before it is
    /// appended: kept from one call to the next, so that no call clears room for it first.
    line: [u8; MOVE_LINE],
}

/// The slots of [`CallWriter`]'s cache: 2^12, for the 12 bits of [`write_f4`]'s hash
/// ([`SLOT_SHIFT`]). A surface's Z levels at four decimals are thousands of values, which 2^10
/// slots kept evicting (the bench's surfacing program: 1.23M misses of its 3M numbers; 0.64M
/// with 2^12). 2^14 slots missed 0.22M, but their 512 KiB, outside the L2 cache of many CPUs,
/// cost more in memory waits than the formatting saved where values do not repeat (128 KiB here).
const SLOTS: usize = 1 << 12;

/// The shift that leaves the top `log2(SLOTS)` bits of the hash.
const SLOT_SHIFT: u32 = 64 - SLOTS.trailing_zeros();

impl Default for CallWriter {
    fn default() -> CallWriter {
        // Made on the heap: the table is too large to build on a thread's stack first.
        let cache = vec![(0, 0, [0; CACHED]); SLOTS].into_boxed_slice().try_into().expect("SLOTS entries");
        CallWriter { cache, line: [0; MOVE_LINE] }
    }
}

/// Room for the longest straight move line: the name (18 bytes), five numbers with the
/// separators before them (5 × (2 + 23)), the last separator (2), and the 32 bytes the last
/// number is formatted in, which also hold its `)` and the newline.
pub const MOVE_LINE: usize = 18 + 5 * (2 + CACHED) + 2 + 32;

impl CallWriter {
    /// Appends the call and a newline.
    ///
    /// A straight move is assembled in the writer's line buffer and appended with its
    /// length. Each number is a fixed-size copy from the cache, or formatted where it goes
    /// and then cached; either may overwrite bytes past its end, which the next part
    /// overwrites in turn. Any number the fast formatter declines sends the whole call to
    /// [`write_call_bytes`].
    pub fn write(&mut self, out: &mut Vec<u8>, op: &CanonOp) {
        match op {
            CanonOp::StraightTraverse(p) => self.write_straight(out, true, p),
            CanonOp::StraightFeed(p) => self.write_straight(out, false, p),
            _ => write_call_bytes(out, op),
        }
    }

    /// Appends the straight move to `p` (a traverse when `rapid`, else a feed) and a newline,
    /// as [`CallWriter::write`] appends its op: the same bytes, from the position alone
    /// ([`CanonSink::straight`]).
    pub fn write_straight(&mut self, out: &mut Vec<u8>, rapid: bool, p: &[f64; 6]) {
        let line = &mut self.line;
        match straight_line(&mut self.cache, line, rapid, p) {
            Some(len) => out.extend_from_slice(&line[..len]),
            None => write_call_bytes(out, &if rapid { CanonOp::StraightTraverse(*p) } else { CanonOp::StraightFeed(*p) }),
        }
    }

    /// Writes the line [`CallWriter::write_straight`] appends at the start of `line` (it may
    /// overwrite bytes past the line's end) and returns its length; `None`, with `line`
    /// overwritten, where a number needs the standard formatter ([`write_call_bytes`] then
    /// writes the op). A printer that keeps its output in a buffer of its own writes the
    /// line where it goes: no copy between.
    ///
    /// Each number is a fixed-size copy from the cache, or formatted where it goes and then
    /// cached; either may overwrite bytes past its end, which the next part overwrites in turn.
    ///
    /// Inlined: a printer calls it for every move, and the call's prologue and epilogue
    /// cost as much as a cached number.
    #[inline(always)]
    pub fn write_straight_at(&mut self, line: &mut [u8; MOVE_LINE], rapid: bool, p: &[f64; 6]) -> Option<usize> {
        straight_line(&mut self.cache, line, rapid, p)
    }
}

/// [`CallWriter::write_straight_at`], with the writer's cache.
#[inline(always)]
fn straight_line(cache: &mut [(u64, u8, [u8; CACHED]); SLOTS], line: &mut [u8; MOVE_LINE], rapid: bool, p: &[f64; 6]) -> Option<usize> {
    // Each name a copy of a length known when compiled: no call to copy it.
    let mut len = if rapid {
        line[..18].copy_from_slice(b"STRAIGHT_TRAVERSE(");
        18
    } else {
        line[..14].copy_from_slice(b"STRAIGHT_FEED(");
        14
    };
    // A machine without rotary axes moves with A, B and C at +0: the line's last three
    // numbers and its end are one copy.
    let rotary = (p[3].to_bits() | p[4].to_bits() | p[5].to_bits()) != 0;
    let numbers = if rotary { &p[..] } else { &p[..3] };
    for (i, &x) in numbers.iter().enumerate() {
        if i > 0 {
            line[len..len + 2].copy_from_slice(b", ");
            len += 2;
        }
        let dst = line[len..].first_chunk_mut::<32>().expect("MOVE_LINE leaves room");
        len += write_f4(cache, x, dst)?;
    }
    // Copies of a known length each: no call to copy a length only known at run time.
    if rotary {
        line[len..len + 2].copy_from_slice(b")\n");
        len += 2;
    } else {
        line[len..len + NO_ROTARY_END.len()].copy_from_slice(NO_ROTARY_END);
        len += NO_ROTARY_END.len();
    }
    Some(len)
}

/// The end of a straight move whose A, B and C are +0 (three numbers [`push_f4`] writes as
/// `0.0000`), after its Z.
const NO_ROTARY_END: &[u8; 26] = b", 0.0000, 0.0000, 0.0000)\n";

/// Writes `v` as [`push_f4`] writes it at the start of `dst` (which it may overwrite up to
/// 32 bytes) and returns its length: from `cache`, or formatted in place and remembered;
/// `None` when only the standard formatter can decide.
///
/// Inlined: [`CallWriter::write_straight`] calls it for each number, and a call costs a
/// good part of a cached number's copy.
#[inline(always)]
fn write_f4(cache: &mut [(u64, u8, [u8; CACHED]); SLOTS], v: f64, dst: &mut [u8; 32]) -> Option<usize> {
    if v.to_bits() == 0 {
        dst[..8].copy_from_slice(b"0.0000\0\0");
        return Some(6);
    }
    let bits = v.to_bits();
    let slot = ((bits ^ (bits >> 31)).wrapping_mul(0x9E37_79B9_7F4A_7C15) >> SLOT_SHIFT) as usize;
    let entry = &mut cache[slot];
    if entry.0 == bits && entry.1 != 0 {
        dst[..CACHED].copy_from_slice(&entry.2);
        return Some(usize::from(entry.1));
    }
    format_and_keep(entry, v, dst)
}

/// [`write_f4`] for a number its cache does not hold: formatted in place and kept in `entry`.
///
/// Not inlined: inlined, the formatter's constants and registers were set up at every
/// straight move, cached numbers or not (some 20 instructions a move on the surfacing
/// program, where about one number in five is formatted).
#[inline(never)]
fn format_and_keep(entry: &mut (u64, u8, [u8; CACHED]), v: f64, dst: &mut [u8; 32]) -> Option<usize> {
    let n = f4_fast(v, dst).filter(|&n| n <= CACHED)?;
    entry.0 = v.to_bits();
    entry.1 = n as u8;
    entry.2.copy_from_slice(&dst[..CACHED]);
    Some(n)
}

/// Bytes a cached number may take: [`f4_fast`] writes at most 18.
const CACHED: usize = 23;

/// The limit of a G96 that names none, as rs274 reports it: no limit.
pub const NO_SPINDLE_LIMIT: f64 = 1e30;

/// Calls that LinuxCNC emits for its own bookkeeping and that carry no machining meaning.
/// Comparisons with `rs274` drop them on both sides.
pub const LINUXCNC_INTERNAL: &[&str] = &[
    "COMMENT",
    "MESSAGE",
    "ON_RESET",
    "START_CHANGE",
    "SET_FEED_REFERENCE",
    "SET_MOTION_CONTROL_MODE",
    "SET_NAIVECAM_TOLERANCE",
    "SET_XY_ROTATION",
    "SET_FEED_MODE",
    "SET_SPINDLE_MODE",
    "PALLET_SHUTTLE",
    "ENABLE_FEED_OVERRIDE",
    "ENABLE_SPEED_OVERRIDE",
    "DISABLE_FEED_OVERRIDE",
    "DISABLE_SPEED_OVERRIDE",
    // G10 L1/L10/L11 write the control's tool table; what they set shows in the
    // USE_TOOL_LENGTH_OFFSET calls that follow, which are compared.
    "SET_TOOL_TABLE_ENTRY",
];

#[cfg(test)]
mod tests {
    use super::*;

    fn rot(axis: usize, deg: f64) -> [[f64; 3]; 3] {
        let (s, c) = deg.to_radians().sin_cos();
        match axis {
            0 => [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]],
            1 => [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]],
            _ => [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    fn chain(axes: [usize; 3], deg: [f64; 3]) -> Frame {
        let m = |a: [[f64; 3]; 3], b: [[f64; 3]; 3]| -> [[f64; 3]; 3] {
            std::array::from_fn(|i| std::array::from_fn(|j| (0..3).map(|k| a[i][k] * b[k][j]).sum()))
        };
        Frame { origin: [0.0; 3], rotation: m(m(rot(axes[0], deg[0]), rot(axes[1], deg[1])), rot(axes[2], deg[2])) }
    }

    fn close(a: [f64; 3], b: [f64; 3]) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-7)
    }

    #[test]
    fn a_frame_gives_back_the_angles_it_was_made_of() {
        for [a, b, c] in [[30.0, 0.0, 0.0], [0.0, -25.0, 0.0], [15.0, 40.0, -70.0], [-120.0, 10.0, 95.0], [0.0, 90.0, 30.0]] {
            // Spatial: Rz(C)·Ry(B)·Rx(A).
            let f = chain([2, 1, 0], [c, b, a]);
            let back = f.spatial_angles();
            assert!(close_m(&chain([2, 1, 0], [back[2], back[1], back[0]]), &f), "spatial {a} {b} {c}: {back:?}");
            // Axis by axis XYZ: Rx(a)·Ry(b)·Rz(c).
            let f = chain([0, 1, 2], [a, b, c]);
            let back = f.axis_by_axis_xyz();
            assert!(close_m(&chain([0, 1, 2], back), &f), "xyz {a} {b} {c}: {back:?}");
        }
        for e in [[0.0, 30.0, 0.0], [90.0, 90.0, 0.0], [45.0, 20.0, -45.0], [10.0, 0.0, 0.0], [30.0, 180.0, 0.0]] {
            let f = chain([2, 0, 2], e);
            let back = f.euler_zxz();
            assert!(close_m(&chain([2, 0, 2], back), &f), "euler {e:?}: {back:?}");
        }
        assert_eq!(chain([2, 1, 0], [0.0, 0.0, 30.0]).spatial_angles(), [30.0, 0.0, 0.0]);
    }

    fn close_m(a: &Frame, b: &Frame) -> bool {
        (0..3).all(|i| close(a.rotation[i], b.rotation[i]))
    }

    #[test]
    fn a_straight_move_by_position_is_the_op_emit_takes() {
        let mut by_position: Vec<Canon> = Vec::new();
        let mut by_op: Vec<Canon> = Vec::new();
        let origin = TextRange::new(3, 17);
        for (rapid, to) in [(true, [1.0, -2.5, 0.125, 0.0, 0.0, 0.0]), (false, [-0.0, 1e-9, 7.0, 90.0, 0.0, -45.0])] {
            by_position.straight(rapid, &to, origin, 4);
            let op = if rapid { CanonOp::StraightTraverse(to) } else { CanonOp::StraightFeed(to) };
            by_op.emit(Canon { op, origin, line: 4 });
        }
        assert_eq!(by_position, by_op);
        assert!(matches!(by_position[0].op, CanonOp::StraightTraverse(_)) && matches!(by_position[1].op, CanonOp::StraightFeed(_)));
    }

    #[test]
    fn the_caching_writer_prints_the_same_bytes() {
        let mut w = CallWriter::default();
        let (mut a, mut b) = (Vec::new(), Vec::new());
        for i in 0..5000 {
            let x = f64::from(i % 700) * 0.2 - 3.0;
            let ops = [
                CanonOp::StraightFeed([x, -0.0, f64::from(i).sin(), 0.0, 1e-9, -x]),
                CanonOp::StraightTraverse([x, 1.00005, 2.5, 1e17, -1e-5, 0.0]),
                // No rotary axis (A, B, C +0, written as one end), and look-alikes that are not.
                CanonOp::StraightFeed([x, 2.0, -x * 0.013, 0.0, 0.0, 0.0]),
                CanonOp::StraightTraverse([0.0, -x, 1e-5, 0.0, -0.0, 0.0]),
                CanonOp::StraightFeed([x, 0.0, 0.0, 0.0, 0.0, 1e-300]),
                // Long lines: past 64 and past 128 bytes, the longest the line buffer holds.
                CanonOp::StraightFeed([x * 1e6, -x * 1e6, x * 3e5, 12_345.678_9, -x * 1e5, 1.5]),
                CanonOp::StraightTraverse([-8.0e11 - x, 7.5e11 + x, -6.0e11, -5.0e11 - x, 4.0e11, -3.0e11 + x]),
                CanonOp::Dwell(x),
            ];
            for op in &ops {
                w.write(&mut a, op);
                write_call_bytes(&mut b, op);
            }
        }
        assert_eq!(a, b);
    }

    #[test]
    fn fast_four_decimals_match_the_standard_formatter() {
        let mut rng = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = || {
            rng ^= rng << 13;
            rng ^= rng >> 7;
            rng ^= rng << 17;
            rng
        };
        let mut cases =
            vec![0.0, -0.0, 0.00005, -0.00005, 0.00015, 1.00005, 2.5, -1e-9, 123456.78905, 1e300, -1e17, f64::NAN, f64::INFINITY];
        // Whole parts of every length the fast path writes (one to twelve digits).
        cases.extend((0..12).flat_map(|k| [10f64.powi(k) + 0.123, -(10f64.powi(k) * 9.87654), 10f64.powi(k) - 0.00004]));
        for _ in 0..200_000 {
            let r = next();
            let mag = 10f64.powi((r % 12) as i32 - 5);
            let v = ((next() >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * mag;
            cases.push(v);
            cases.push((v * 1e4).round() / 1e4 + 0.00005); // near ties
        }
        for v in cases {
            let mut s = Vec::new();
            push_f4(&mut s, v);
            assert_eq!(String::from_utf8(s).unwrap(), format!("{v:.4}"), "{v:e}");
        }
    }

    #[test]
    fn prints_like_rs274() {
        let mut s = String::new();
        write_call(&mut s, &CanonOp::StraightTraverse([0.0, 1.5, -2.0, 0.0, 0.0, 0.0]));
        write_call(
            &mut s,
            &CanonOp::ArcFeed {
                first_end: 10.0,
                second_end: 0.0,
                first_axis: 5.0,
                second_axis: -0.0,
                rotation: -1,
                axis_end: -1.0,
                abc: [0.0; 3],
            },
        );
        write_call(&mut s, &CanonOp::Comment("a \"b\"".into()));
        expect_test::expect![[r#"
            STRAIGHT_TRAVERSE(0.0000, 1.5000, -2.0000, 0.0000, 0.0000, 0.0000)
            ARC_FEED(10.0000, 0.0000, 5.0000, -0.0000, -1, -1.0000, 0.0000, 0.0000, 0.0000)
            COMMENT("a \"b\"")
        "#]]
        .assert_eq(&s);
    }
}

//! The turning part of the plan model: what a turning workingstep does ([`TurnOp`], ISO
//! 14649-121), what its cycle and technology state ([`Turning`]), and the turned features
//! ([`Turned`], ISO 14649-12). Diameters throughout; lengths along Z. `turning.rs` finds them.

use serde::{Deserialize, Serialize};

use crate::canon::TurnIntent;
use crate::text::num;

/// What a turning workingstep does (ISO 14649-121).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum TurnOp {
    /// Facing (`facing_rough`, `facing_finish`).
    Facing,
    /// Contouring along the part (`contouring_rough`, `contouring_finish`).
    Contouring,
    /// Grooving (`grooving_rough`, `grooving_finish`).
    Grooving,
    /// Threading (`threading_rough`, `threading_finish`).
    Threading,
    /// Drilling on the axis.
    Drilling,
    /// Parting off (ISO 14649-121 `cutting_in` to the axis).
    PartingOff,
}

impl TurnOp {
    /// snake_case name.
    pub fn as_str(self) -> &'static str {
        match self {
            TurnOp::Facing => "facing",
            TurnOp::Contouring => "contouring",
            TurnOp::Grooving => "grooving",
            TurnOp::Threading => "threading",
            TurnOp::Drilling => "drilling",
            TurnOp::PartingOff => "parting_off",
        }
    }
}

/// A turning workingstep's operation and what its cycle or its moves state. Lengths in mm;
/// X values are diameters.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Turning {
    /// What it does.
    pub operation: Option<TurnOp>,
    /// Roughing (leaves an allowance, cuts in passes) rather than finishing.
    #[serde(default)]
    pub rough: bool,
    /// Inside the part (boring, an inner groove or thread).
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub inside: bool,
    /// The cycle's code (`G71`), when a cycle makes it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cycle: Option<String>,
    /// The cycle as the interpreter read it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub intent: Option<TurnIntent>,
    /// Feed per revolution, mm/rev (G95/G99), at the first cut.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub feed_per_rev: Option<f64>,
    /// The spindle's speed limit under constant cutting speed (G50 S, G92 S, LIMS), 1/min.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub spindle_limit: Option<f64>,
    /// The lead of spindle-synchronised moves (a thread's pitch), mm.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pitch: Option<f64>,
    /// Cutting passes (runs of cuts between rapids).
    #[serde(default)]
    pub passes: u32,
    /// Roughing (true) or finishing as the operation's own comment states it
    /// (`ROUGH_BORE_ID`, `(FINISHING)`): read when the operation is named, then cleared.
    #[serde(skip)]
    pub stated: Option<bool>,
    /// The program writes this workingstep's X beyond the centre line (negative: a bar
    /// lathe's or a rear tool post's), and the plan mirrored it: the program's X allowance
    /// then points the other way about the part. Read during recognition, then cleared.
    #[serde(skip)]
    pub mirrored: bool,
    /// The radius tool nose radius compensation offsets the cuts by (the radius the block or
    /// the tool table states), and whether on the left of the way (G41): read during
    /// recognition.
    #[serde(skip)]
    pub nose: Option<(f64, bool)>,
    /// Smallest and largest diameter cut.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub diameter: Option<[f64; 2]>,
    /// Lowest and highest Z cut.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub z: Option<[f64; 2]>,
}

/// A turned feature's kind and size (ISO 14649-12). Diameters and lengths in mm.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "shape")]
pub enum Turned {
    /// A face across the axis (`revolved_flat`), from `inner` to `outer` diameter.
    RevolvedFlat {
        /// Outer diameter.
        outer: f64,
        /// Inner diameter (0 to the axis).
        inner: f64,
    },
    /// A cylinder outside (`outer_diameter`) or inside (a bore), `length` along -Z from the placement.
    Diameter {
        /// Diameter.
        diameter: f64,
        /// Length along Z.
        length: f64,
        /// Inside the part.
        inside: bool,
    },
    /// A rounded edge (`revolved_round`).
    RevolvedRound {
        /// Radius.
        radius: f64,
        /// Diameter at its larger end.
        diameter: f64,
    },
    /// A groove (`groove`): its bottom diameter and width along Z.
    Groove {
        /// Diameter at the bottom.
        diameter: f64,
        /// Width along Z, where known (the plunges' span plus the tool's width).
        #[serde(default, skip_serializing_if = "Option::is_none")]
        width: Option<f64>,
        /// Inside the part (or on the face).
        inside: bool,
    },
    /// An annular groove cut along -Z into the face between two diameters (a face groove, as
    /// Fanuc's `G74` face grooving cycle or a face grooving tool's plunges along Z cut it):
    /// its floor is the feature's placement (Z); `inner` and `outer` its walls' diameters at
    /// the floor where its walls are cut, else the smallest and largest diameter plunged (the
    /// tool's width then adds to the groove on a side the program does not tell). Its radial
    /// width is [`Turned::face_groove_width`]. ISO 14649-12 has no face-groove entity: it is
    /// written as a `groove` whose material side is along the axis (`part21::stepnc::turning`).
    FaceGroove {
        /// Outer wall's diameter at the floor.
        outer: f64,
        /// Inner wall's diameter at the floor.
        inner: f64,
    },
    /// The region a workingstep turns where its parts do not separate (`general_revolution`:
    /// roughing passes, parting off): from `inner` to `outer` diameter, `length` along -Z.
    Revolution {
        /// Outer diameter.
        outer: f64,
        /// Inner diameter.
        inner: f64,
        /// Length along Z.
        length: f64,
    },
    /// A thread: major diameter where its cycle states the height, minor diameter, pitch, length.
    Thread {
        /// Major (nominal) diameter.
        #[serde(default, skip_serializing_if = "Option::is_none")]
        diameter: Option<f64>,
        /// Minor diameter (outside) or major (inside): the last pass's.
        root: f64,
        /// Pitch (lead), mm.
        pitch: f64,
        /// Length along Z.
        length: f64,
        /// Inside the part.
        inside: bool,
    },
}

impl Turned {
    /// Human label, ISO 14649-12's name.
    pub fn label(&self) -> &'static str {
        match self {
            Turned::RevolvedFlat { .. } => "revolved flat",
            Turned::Diameter { inside: false, .. } => "outer diameter",
            Turned::Diameter { inside: true, .. } => "inner diameter",
            Turned::RevolvedRound { .. } => "revolved round",
            Turned::Groove { .. } => "groove",
            Turned::FaceGroove { .. } => "face groove",
            Turned::Thread { .. } => "thread",
            Turned::Revolution { .. } => "general revolution",
        }
    }

    /// The size in a turner's words (`Ø24 × 28`).
    pub fn size(&self) -> String {
        let n = num;
        match self {
            Turned::RevolvedFlat { outer, inner } => format!("Ø{}..Ø{}", n(*inner), n(*outer)),
            Turned::Diameter { diameter, length, .. } => format!("Ø{} × {}", n(*diameter), n(*length)),
            Turned::RevolvedRound { radius, diameter } => format!("R{} at Ø{}", n(*radius), n(*diameter)),
            Turned::Groove { diameter, width, .. } => match width {
                Some(w) => format!("Ø{} width {}", n(*diameter), n(*w)),
                None => format!("Ø{}", n(*diameter)),
            },
            Turned::FaceGroove { outer, inner } => match self.face_groove_width() {
                Some(w) => format!("Ø{}..Ø{} width {}", n(*inner), n(*outer), n(w)),
                None => format!("Ø{}..Ø{}", n(*inner), n(*outer)),
            },
            Turned::Revolution { outer, inner, length } => format!("Ø{}..Ø{} × {}", n(*inner), n(*outer), n(*length)),
            Turned::Thread { diameter, root, pitch, length, .. } => match diameter {
                Some(d) => format!("Ø{} pitch {} root Ø{} × {}", n(*d), n(*pitch), n(*root), n(*length)),
                None => format!("pitch {} root Ø{} × {}", n(*pitch), n(*root), n(*length)),
            },
        }
    }

    /// A face groove's radial width, from wall to wall (none where it was plunged at one
    /// diameter: the tool's width, not stated).
    pub fn face_groove_width(&self) -> Option<f64> {
        match self {
            Turned::FaceGroove { outer, inner } if outer > inner => Some(((outer - inner) / 2.0 * 1e4).round() / 1e4),
            _ => None,
        }
    }
}

//! The engine's vocabulary: the words a dialect file may use for meanings, roles and steps.
//!
//! A dialect maps its own spelling (`G81`, `CYCLE81`, `CYCL DEF 200`) onto these capabilities;
//! the interpreter branches on them and never on dialect names.
//!
//! It also holds what the dialect loader and the interpreter share about parameters: the
//! highest numbered one the engine keeps, and how a named one is spelt.

/// Numbered parameters from `interp::eval::MAX_PARAM` up to this one (Haas NGC's #10000 to #30000+
/// settings and parameters, Mitsubishi's extended common variables #900001 to #907400) live
/// in a sparse table: only the ones a program writes take memory.
pub const MAX_HIGH_PARAM: usize = 1_000_000;

/// Normalises a parameter name as LinuxCNC does: lower case, blanks removed.
pub fn normalise_name(raw: &str) -> String {
    normalised(raw).into_owned()
}

/// [`normalise_name`] without an allocation when the name is already normal (the usual case).
pub(crate) fn normalised(raw: &str) -> std::borrow::Cow<'_, str> {
    if raw.chars().all(|c| !c.is_whitespace() && !c.is_uppercase()) {
        std::borrow::Cow::Borrowed(raw)
    } else {
        std::borrow::Cow::Owned(raw.chars().filter(|c| !c.is_whitespace()).flat_map(char::to_lowercase).collect())
    }
}

macro_rules! vocab {
    ($(#[$m:meta])* $name:ident { $( $(#[doc = $doc:literal])+ $variant:ident = $text:literal, )* }) => {
        $(#[$m])*
        #[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
        pub enum $name {
            $( $(#[doc = $doc])+ $variant, )*
        }

        impl $name {
            /// Every value.
            pub const ALL: &'static [$name] = &[$($name::$variant),*];

            /// The spelling used in dialect files.
            pub fn as_str(self) -> &'static str {
                match self { $($name::$variant => $text,)* }
            }

            /// Parses the dialect-file spelling.
            pub fn parse(s: &str) -> Option<$name> {
                match s { $($text => Some($name::$variant),)* _ => None }
            }
        }
    };
}

vocab! {
    /// What a code or keyword does.
    Meaning {
        /// Rapid positioning (G0).
        Rapid = "rapid",
        /// Linear interpolation (G1).
        Linear = "linear",
        /// Clockwise arc (G2).
        ArcCw = "arc-cw",
        /// Counter-clockwise arc (G3).
        ArcCcw = "arc-ccw",
        /// Drilling cycle (G81).
        CycleDrill = "cycle-drill",
        /// Drilling with dwell at the bottom, counterboring (G82).
        CycleDrillDwell = "cycle-drill-dwell",
        /// Peck drilling with full retract (G83).
        CyclePeckDrill = "cycle-peck-drill",
        /// Chip-breaking peck drilling (G73).
        CycleChipBreak = "cycle-chip-break",
        /// Right-hand tapping (G84).
        CycleTap = "cycle-tap",
        /// Left-hand tapping (G74).
        CycleTapLeft = "cycle-tap-left",
        /// Boring, feed out (G85).
        CycleBore = "cycle-bore",
        /// Boring, spindle stop, rapid out (G86).
        CycleBoreStop = "cycle-bore-stop",
        /// Back boring (G87).
        CycleBackBore = "cycle-back-bore",
        /// Boring, manual retract (G88).
        CycleBoreManual = "cycle-bore-manual",
        /// Boring with dwell, feed out (G89).
        CycleBoreDwell = "cycle-bore-dwell",
        /// Fine boring with shift (Fanuc G76).
        CycleFineBore = "cycle-fine-bore",
        /// Threading cycle (LinuxCNC G76, lathe).
        CycleThread = "cycle-thread",
        /// A lathe's single-pass turning cycle (Fanuc G90): rapid in X to the target (plus the
        /// taper R, a radius), feed along Z to the target, feed back out in X, rapid back in Z.
        /// Modal: a following block with only X repeats it; X, Z and R carry over.
        CycleTurn = "cycle-turn",
        /// A lathe's single-pass facing cycle (Fanuc G94): rapid in Z to the target (plus the
        /// taper R), feed in X to the target, feed back in Z, rapid back out in X. Modal.
        CycleFace = "cycle-face",
        /// A lathe's single-pass threading cycle (Fanuc G92): rapid in X, one threaded pass
        /// along Z (F the lead), rapid out in X, rapid back in Z. Modal.
        CycleThreadPass = "cycle-thread-pass",
        /// A lathe's stock removal in turning (Fanuc G71, type I): the contour between the
        /// blocks numbered P and Q (their p and q words), shifted by the finishing allowances, is roughed out from
        /// the start point in passes along Z, the cut depth apart in X, each retracted at 45°;
        /// a last pass follows the shifted contour, and the run goes on after block Q. A block
        /// without P and Q only sets the cut depth (U) and retract (R) of the ones after it;
        /// with them, its cut-depth word is the X finishing allowance (the two-block form).
        CycleRoughTurn = "cycle-rough-turn",
        /// A lathe's stock removal in facing (Fanuc G72, type I): as `cycle-rough-turn` with X
        /// and Z exchanged, the passes along X and the depth of cut (W) stepping in Z; with P
        /// and Q, its cut-depth word is the Z finishing allowance.
        CycleRoughFace = "cycle-rough-face",
        /// A lathe's pattern repeating cycle (Fanuc G73, two blocks): the contour between the
        /// blocks numbered P and Q is cut as it is drawn, again and again, each pass a copy of
        /// it shifted by the finishing allowances and a share of the relief, from the whole
        /// relief on the first pass to none on the last; from the start point and back to it
        /// after each pass; the run goes on after block Q. The block without P and Q gives the
        /// relief in X (a radius) and in Z in its X and Z words (U, W) and the number of passes
        /// in the word its args name `passes` (R); with P and Q, its X and Z words are the
        /// finishing allowances (X a diameter). Where the args name other words for the relief
        /// as `axis-x` and `axis-z` (Haas `G73 P Q U W I K D`, one block: `I:axis-x K:axis-z
        /// D:passes`), the block with P and Q gives the relief and the passes too.
        CycleRoughPattern = "cycle-rough-pattern",
        /// A lathe's finishing cycle (Fanuc G70): the contour between the blocks numbered P
        /// and Q runs as written, then the tool returns to the start point at rapid.
        CycleFinishContour = "cycle-finish-contour",
        /// The end of a lathe cycle's contour definition (Okuma LAP: `G85 NLAP1` names the
        /// contour's first block, `NLAP1 G81` … `G80`): where a contour cycle names no last
        /// block, its contour runs up to this code's block, and the run goes on after it.
        ContourEnd = "contour-end",
        /// Polar coordinate interpolation on a lathe (Fanuc G12.1/G112, Siemens TRANSMIT): X
        /// (a diameter where X words are) and C, read as a second linear axis, give points on
        /// the face in its XY plane, milled with a driven tool along Z, up to the cancel.
        PolarInterpolation = "polar-interpolation",
        /// The end of polar coordinate interpolation (Fanuc G13.1/G113; Siemens TRAFOOF ends it
        /// as it ends any transformation): the plane before it again.
        PolarInterpolationOff = "polar-interpolation-off",
        /// Cylindrical interpolation on a lathe (Fanuc G07.1/G107 with the cylinder's radius in
        /// the rotary axis word, the same code with 0 ending it; Siemens TRACYL(d) with the
        /// working diameter, TRAFOOF ending it): the axis along the spindle and the developed
        /// surface (the C word in degrees, turned into a length by the radius; a Y word that
        /// length) are a plane on the cylinder, X the depth, milled with a driven tool whose
        /// axis is radial.
        CylindricalInterpolation = "cylindrical-interpolation",
        /// LinuxCNC's G70: finishing passes along the profile that the O-word subroutine
        /// named by Q draws, from distance D to E in P passes.
        ProfileFinish = "profile-finish",
        /// LinuxCNC's G71: roughing the Q subroutine's profile by passes along Z, I apart,
        /// leaving D to the profile and the allowances U and W, retracting R. The code's
        /// `index` says what it does with pockets: 0 cuts them, 1 leaves them (G71.1), 2
        /// cuts only from the first one on (G71.2).
        ProfileRoughTurn = "profile-rough-turn",
        /// LinuxCNC's G72: as `profile-rough-turn`, with passes along X (facing).
        ProfileRoughFace = "profile-rough-face",
        /// A lathe's multiple-pass threading (Fanuc G76, two blocks): the first gives the
        /// finishing passes, chamfer and tool angle (P mmrraa), the least depth of cut (Q) and
        /// the finishing allowance (R); the second the end point (X the minor diameter), the
        /// taper R, the thread height P and first depth of cut Q (least increments) and the lead F.
        CycleThreadMultiple = "cycle-thread-multiple",
        /// A lathe's grooving cycle (Fanuc G75, two blocks): the first gives the retract R
        /// after each peck; the second the end point, the peck P in X and the shift Q in Z.
        CycleGroove = "cycle-groove",
        /// A lathe's pecking cycle along Z (Fanuc G74, two blocks): as `cycle-groove` with X
        /// and Z exchanged (Q the peck in Z, P the shift in X); on the axis, a drilled hole.
        CycleFacePeck = "cycle-face-peck",
        /// Stock removal of a corner between two points (SINUMERIK ShopTurn `CYCLE951`): the
        /// stock from the start diameter and Z (`axis-x`, `axis-z`) to the end diameter and Z
        /// (`end-x`, `end-z`), the finished corner running from the end diameter at the start Z
        /// through the intermediate point (`via-x`, `via-z`: the end point for a square
        /// corner, elsewhere a cone) to the start diameter at the end Z; roughed in passes
        /// `cut-depth` apart leaving the allowances, or finished, along Z or across X as the
        /// machining type says; inside where the end diameter is the larger.
        CycleStockCorner = "cycle-stock-corner",
        /// Contour turning (SINUMERIK `CYCLE952`): the contour the last `contour-define` named,
        /// roughed out in passes `cut-depth` apart or finished, along Z or across X as the
        /// machining type says, from outside its extent by the safety distance.
        CycleContourTurn = "cycle-contour-turn",
        /// Names the contour the contour cycles after it turn (SINUMERIK `CYCLE62`): the
        /// labels of this program its `contour-name` arguments give, from the first to the second.
        ContourDefine = "contour-define",
        /// Parting off (SINUMERIK `CYCLE92`): a plunge at Z (`axis-z`) from the diameter
        /// (`axis-x`) to the end diameter (`end-x`), at the feed and, from the diameter where the
        /// feed changes (`via-x`), at the reduced feed (`finish-feed`).
        CyclePartOff = "cycle-part-off",
        /// Cancel the canned cycle (G80).
        CycleCancel = "cycle-cancel",
        /// Spindle-synchronised motion (G33): K is the advance per revolution.
        SpindleSync = "spindle-sync",
        /// Rigid tapping (G33.1): synchronised to the bottom and back out, K per revolution.
        RigidTap = "rigid-tap",
        /// Probing (G38.2, G38.4): a probe that does not touch (or leave contact) stops
        /// the program with an error, and so does a move of no length.
        Probe = "probe",
        /// Probing that goes on whether it touches or not (G38.3, G38.5); a move of no
        /// length is taken.
        ProbeQuiet = "probe-quiet",
        /// A quadratic B-spline in the XY plane (G5.1): I and J give its control point
        /// relative to the start; X and Y the end.
        SplineQuadratic = "spline-quadratic",
        /// A NURBS control point (G5.2 and the blocks after it): X, Y, the weight P, the
        /// order L. The curve runs when the block that ends it comes.
        Nurbs = "nurbs",
        /// Ends a NURBS block (G5.3): the curve through the collected control points runs,
        /// and no motion mode stays in force.
        NurbsEnd = "nurbs-end",
        /// XY plane (G17).
        PlaneXy = "plane-xy",
        /// XZ plane (G18).
        PlaneXz = "plane-xz",
        /// YZ plane (G19).
        PlaneYz = "plane-yz",
        /// Inch units (G20).
        UnitsInch = "units-inch",
        /// Millimetre units (G21).
        UnitsMm = "units-mm",
        /// Absolute distances (G90).
        DistanceAbsolute = "distance-absolute",
        /// Incremental distances (G91).
        DistanceIncremental = "distance-incremental",
        /// Absolute arc centres (G90.1).
        ArcDistanceAbsolute = "arc-distance-absolute",
        /// Incremental arc centres (G91.1).
        ArcDistanceIncremental = "arc-distance-incremental",
        /// Inverse-time feed (G93).
        FeedInverseTime = "feed-inverse-time",
        /// Units-per-minute feed (G94).
        FeedPerMinute = "feed-per-minute",
        /// Units-per-revolution feed (G95).
        FeedPerRev = "feed-per-rev",
        /// Cutter compensation off (G40).
        CompOff = "comp-off",
        /// Cutter compensation left (G41).
        CompLeft = "comp-left",
        /// Cutter compensation right (G42).
        CompRight = "comp-right",
        /// Cutter compensation left, D is the cutter diameter (G41.1).
        CompLeftDiameter = "comp-left-diameter",
        /// Cutter compensation right, D is the cutter diameter (G42.1).
        CompRightDiameter = "comp-right-diameter",
        /// Tool length compensation, positive (G43).
        LengthCompPlus = "length-comp-plus",
        /// Tool length offset given by the axis words (G43.1).
        LengthCompDynamic = "length-comp-dynamic",
        /// Tool length compensation, negative (G44).
        LengthCompMinus = "length-comp-minus",
        /// Tool length compensation cancel (G49).
        LengthCompCancel = "length-comp-cancel",
        /// Work coordinate system select; the code carries an index (G54 = 1).
        Wcs = "wcs",
        /// Extended work offsets (G54.1 P).
        WcsExtended = "wcs-extended",
        /// Canned-cycle return to the initial level (G98).
        RetractInitial = "retract-initial",
        /// Canned-cycle return to the R level (G99).
        RetractR = "retract-r",
        /// Exact-stop or blending modes (G61, G64).
        PathMode = "path-mode",
        /// Constant surface speed (G96).
        SpindleCss = "spindle-css",
        /// Spindle RPM mode (G97).
        SpindleRpm = "spindle-rpm",
        /// Spindle speed limit (lathe `G50 S`): the block's S is the limit, not a speed; recorded.
        SpindleLimit = "spindle-limit",
        /// Lathe diameter mode (G7): X words give diameters, so the tool moves half of them.
        DiameterMode = "diameter-mode",
        /// Lathe radius mode (G8): X words give radii.
        RadiusMode = "radius-mode",
        /// Diameter programming for absolute dimensions only (SINUMERIK `DIAM90`): an X word
        /// in G90 or `AC()` gives a diameter, one in G91 or `IC()` a radius.
        DiameterAbsolute = "diameter-absolute",
        /// Dwell (G4).
        Dwell = "dwell",
        /// Set offsets or tool data (G10).
        SetData = "set-data",
        /// Return to the first reference position (G28).
        Home1 = "home-1",
        /// Return to the second reference position (G30).
        Home2 = "home-2",
        /// Store the current machine position as the first reference position (G28.1).
        Home1Set = "home-1-set",
        /// Store the current machine position as the second reference position (G30.1).
        Home2Set = "home-2-set",
        /// Move in machine coordinates for one block (G53).
        MachineCoords = "machine-coords",
        /// Move for one block in coordinates from a datum the machine builder defines
        /// (Heidenhain `M92`, e.g. the tool-change position): not the machine datum, so no
        /// `G53` reaches it; only the machine knows where it is.
        MachineBuilderCoords = "machine-builder-coords",
        /// The axes the block names (else the code's `home-axes`) go straight to the reference
        /// point, with no intermediate point; their values are ignored (SINUMERIK `G74 X1=0
        /// Z1=0`, Centroid `M25`: Z home at rapid).
        ReferenceApproach = "reference-approach",
        /// The axes the block names go straight to fixed point `FP=n` (1 to 4, 1 without FP),
        /// with no intermediate point; their values are ignored (SINUMERIK `G75 FP=2 X1=0`).
        FixedPointApproach = "fixed-point-approach",
        /// The tool axis retracts to its travel limit in one traverse, in the machine's frame
        /// (Heidenhain `M140 MB MAX`: "to just before the software limit switch"): only the
        /// machine knows where that is.
        TravelLimit = "travel-limit",
        /// Coordinate-system shift (G92).
        OriginShift = "origin-shift",
        /// Cancel coordinate-system shift (G92.1, G92.2).
        OriginShiftCancel = "origin-shift-cancel",
        /// Zero the origin shift but keep it for a later restore (G92.2).
        OriginShiftSuspend = "origin-shift-suspend",
        /// Bring back a suspended origin shift (G92.3).
        OriginShiftRestore = "origin-shift-restore",
        /// Local coordinate system (G52).
        LocalOffset = "local-offset",
        /// Coordinate rotation (G68).
        Rotation = "rotation",
        /// Coordinate rotation cancel (G69).
        RotationCancel = "rotation-cancel",
        /// Scaling (G51).
        Scaling = "scaling",
        /// Scaling cancel (G50).
        ScalingCancel = "scaling-cancel",
        /// Polar coordinate command on (Fanuc G16): in a move, the plane's first axis word is
        /// the radius, the second the angle, about the work origin (G90).
        Polar = "polar",
        /// Polar coordinate command off (Fanuc G15).
        PolarOff = "polar-off",
        /// Macro call (G65).
        MacroCall = "macro-call",
        /// Register a macro called after every move until cancelled (Fanuc G66).
        ModalMacroCall = "modal-macro-call",
        /// Cancel the modal macro call (Fanuc G67).
        ModalMacroCancel = "modal-macro-cancel",
        /// Program stop (M0).
        ProgramStop = "program-stop",
        /// Optional stop (M1).
        OptionalStop = "optional-stop",
        /// Feed and spindle speed overrides enabled (LinuxCNC M48).
        OverridesOn = "overrides-on",
        /// Feed and spindle speed overrides disabled: the program runs at its own values
        /// whatever the operator's dials say (LinuxCNC M49).
        OverridesOff = "overrides-off",
        /// Feed override on with `P1` or no P, off with `P0` (LinuxCNC M50).
        FeedOverrideSwitch = "feed-override",
        /// Spindle speed override on with `P1` or no P, off with `P0` (LinuxCNC M51).
        SpeedOverrideSwitch = "speed-override",
        /// Program end (M2).
        ProgramEnd = "program-end",
        /// Program end and rewind (M30).
        ProgramEndRewind = "program-end-rewind",
        /// Tool change (M6).
        ToolChange = "tool-change",
        /// Takes tool Q as the one in the spindle, without changing tools (LinuxCNC M61).
        ToolSet = "tool-set",
        /// Spindle clockwise (M3).
        SpindleCw = "spindle-cw",
        /// Spindle counter-clockwise (M4).
        SpindleCcw = "spindle-ccw",
        /// Spindle stop (M5).
        SpindleStop = "spindle-stop",
        /// Mist coolant on (M7).
        CoolantMist = "coolant-mist",
        /// Flood coolant on (M8).
        CoolantFlood = "coolant-flood",
        /// All coolant off (M9).
        CoolantOff = "coolant-off",
        /// Subprogram call (M98).
        SubprogramCall = "subprogram-call",
        /// Call of a local subprogram: the block numbered P in the same file, run until the
        /// return (Haas M97 P100 L2).
        LocalSubprogramCall = "local-subprogram-call",
        /// Subprogram return (M99).
        SubprogramReturn = "subprogram-return",
        /// Spindle orientation (M19).
        SpindleOrient = "spindle-orient",
        /// Saves the modal state at the current call level (M70).
        StateSave = "state-save",
        /// Saves the modal state, restored when the current call returns (M73).
        StateSaveAutorestore = "state-save-autorestore",
        /// Forgets the state saved at the current call level (M71).
        StateInvalidate = "state-invalidate",
        /// Restores the state saved at the current call level (M72).
        StateRestore = "state-restore",
        /// Replaces the programmable frame's translation (`TRANS X10`); alone, resets the frame.
        FrameTrans = "frame-trans",
        /// Adds to the programmable frame's translation (`ATRANS`).
        FrameTransAdd = "frame-trans-add",
        /// Replaces the programmable frame's rotation in the plane (`ROT RPL=30`, `ROT Z30`).
        FrameRot = "frame-rot",
        /// Adds to the programmable frame's rotation (`AROT`).
        FrameRotAdd = "frame-rot-add",
        /// Replaces the programmable frame's scale (`SCALE X2 Y2`).
        FrameScale = "frame-scale",
        /// Multiplies the programmable frame's scale (`ASCALE`).
        FrameScaleAdd = "frame-scale-add",
        /// Replaces the programmable frame's mirroring (`MIRROR X0 Y0`): the axes named change
        /// sign about the program zero (the values are not read); alone, no mirroring.
        FrameMirror = "frame-mirror",
        /// Adds a mirroring to the programmable frame's (`AMIRROR X0`): an axis named again is
        /// mirrored back.
        FrameMirrorAdd = "frame-mirror-add",
        /// Programmable mirror image (Fanuc `G51.1 X10`): each axis named is mirrored about the
        /// coordinate its word gives.
        Mirror = "mirror",
        /// Programmable mirror image about the work zero (Haas `G101 X0`): each axis named is
        /// mirrored about the work offset's zero, its word's value not read.
        MirrorAboutZero = "mirror-about-zero",
        /// Programmable mirror image cancelled (Fanuc `G50.1 X0`, Haas `G100`) for the axes
        /// named; with none, for every axis.
        MirrorCancel = "mirror-cancel",
        /// Sets the circle centre / pole from the block's axis words (`CC X+25 Y+25`); alone, the current position.
        Pole = "pole",
        /// Sets the circle centre from the block's axis words, an axis without one keeping the
        /// last pole's coordinate; with none, the current position (Heidenhain `CC X+40`).
        PoleKeeping = "pole-keeping",
        /// Sets the pole from the block's axis words as increments from the current position
        /// (Siemens `G110 X10 Y5`).
        PoleIncremental = "pole-incremental",
        /// Sets the pole from the block's axis words as increments from the last pole (Siemens
        /// `G112 X10`).
        PoleFromPole = "pole-from-pole",
        /// Rounds the corner between the straight moves before and after the block with an
        /// arc of radius R (`RND R5`).
        CornerRound = "corner-round",
        /// Chamfers the corner between the straight moves before and after the block, cutting
        /// back the given length along each (`CHF 2`).
        CornerChamfer = "corner-chamfer",
        /// Modal rounding (Siemens `RNDM=2`, its value in `corner-radius`): the corner at the
        /// end of this block's move and every one after it rounded with an arc of that radius,
        /// until a value of 0.
        RoundModal = "round-modal",
        /// Approaches the contour point of the block on a straight line tangent to the first
        /// contour element, from an auxiliary point LEN before it (`APPR LT`).
        ApproachTangent = "approach-tangent",
        /// The same, on a straight line perpendicular to the first contour element, from the
        /// side of the radius compensation (`APPR LN`).
        ApproachNormal = "approach-normal",
        /// An approach on an arc (`APPR CT`, `APPR LCT`): the tool goes straight to the
        /// contour point, with a warning that the arc is not computed.
        ApproachArc = "approach-arc",
        /// Leaves the contour on a straight line of length LEN tangent to its last element (`DEP LT`).
        DepartTangent = "depart-tangent",
        /// Leaves the contour on a straight line of length LEN perpendicular to its last
        /// element, on the side of the radius compensation (`DEP LN`).
        DepartNormal = "depart-normal",
        /// A departure on an arc (`DEP CT`, `DEP LCT`): not computed; the tool stays at the
        /// contour end, with a warning.
        DepartArc = "depart-arc",
        /// An arc about the pole to the block's end point (`C X Y DR-`); the direction from the block or the last arc.
        ArcPole = "arc-pole",
        /// An arc with a given radius (`CR X Y R+5 DR-`); the direction from the block or the last arc.
        ArcRadius = "arc-radius",
        /// An arc tangent to the previous element (`CT X Y`).
        ArcTangent = "arc-tangent",
        /// An arc through an intermediate point to the end point (`CIP X Y I1= J1=`).
        ArcThreePoint = "arc-three-point",
        /// Clockwise for this block's arc (`DR-`).
        ArcDirCw = "arc-dir-cw",
        /// Counter-clockwise for this block's arc (`DR+`).
        ArcDirCcw = "arc-dir-ccw",
        /// This block's move is a rapid (`FMAX`); the modal feed stays.
        RapidBlock = "rapid-block",
        /// Defines a cycle (`CYCL DEF 200`): the cycle's parameters are read when it is called.
        CycleDefine = "cycle-define",
        /// Calls the defined cycle at the position reached by the block (`CYCL CALL`, `M99`).
        CycleCall = "cycle-call",
        /// Calls the defined cycle at the position the block's own words give, the tool-axis
        /// word being the surface (`CYCL CALL POS X+10 Y+20 Z+0 FMAX`).
        CycleCallAt = "cycle-call-at",
        /// With a cycle in the block: call it after every later move (`MCALL CYCLE81(...)`); alone: stop that.
        CycleModal = "cycle-modal",
        /// Program start with a name and units (`BEGIN PGM name MM`); recorded.
        ProgramBegin = "program-begin",
        /// A cycle kept as intent whose moves are not expanded (pockets, swivelling).
        CycleIntent = "cycle-intent",
        /// A turning machine's cycle kept as intent, its moves not expanded (its parameter
        /// list not documented well enough to read sizes from it: SINUMERIK Operate's
        /// `CYCLE930` groove, `CYCLE940` undercut, ShopTurn's `F_ROUGH` work step): read as a
        /// lathe's word, the evidence of a turning machine as a turning cycle is.
        CycleTurnIntent = "cycle-turn-intent",
        /// Tilts the working plane by spatial angles: about the fixed X, then Y, then Z axes
        /// (Heidenhain `PLANE SPATIAL SPA SPB SPC`, cycle 19's A B C); the words of the
        /// `tilt-a`, `tilt-b`, `tilt-c` roles.
        TiltSpatial = "tilt-spatial",
        /// Tilts the working plane by Euler angles: about Z, then the new X, then the new Z
        /// (Heidenhain `PLANE EULER EULPR EULNU EULROT`, Fanuc `G68.2 I J K` with the origin
        /// `X Y Z`).
        TiltEuler = "tilt-euler",
        /// Tilts the working plane to a base vector (the new X: `tilt-base-x` …) and a normal
        /// vector (the new Z, the tool axis: `tool-axis-i` …) (Heidenhain `PLANE VECTOR`).
        TiltVector = "tilt-vector",
        /// Tilts the active working plane further about one of its own axes (Heidenhain
        /// `PLANE RELATIV SPA`): the angle's role says which axis.
        TiltRelative = "tilt-relative",
        /// Tilts the working plane through three points (Heidenhain `PLANE POINTS`): the line
        /// from the first (`tilt-p1-x` …) to the second (`tilt-p2-x` …) is the new X, the third
        /// (`tilt-p3-x` …) lies on the side of the new +Y; the datum stays.
        TiltPoints = "tilt-points",
        /// Tilts the working plane by projection angles (Heidenhain `PLANE PROJECTED PROPR
        /// PROMIN ROT`): the plane's trace in the ZX plane at `tilt-a` from X, its trace in the YZ
        /// plane at `tilt-b` from Y, the new X along the first trace turned by `tilt-c` about the
        /// new Z.
        TiltProjected = "tilt-projected",
        /// Tilts the working plane by the rotary axes' positions (Heidenhain `PLANE AXIAL A B C`):
        /// read, like tool centre point control, as turns about the part's X, Y and Z (ISO 841
        /// senses), which the machine's kinematics may not share (said in a note).
        TiltAxial = "tilt-axial",
        /// Tilts the working plane square to the tool axis the rotary axes give (Fanuc `G68.3
        /// X Y Z R`): origin `tilt-origin-*`, turned by `tilt-c` about the new Z.
        TiltToolAxis = "tilt-tool-axis",
        /// Tilts the working plane by turns about X by `tilt-a`, then about the turned Y by
        /// `tilt-b`, then about the turned Z by `tilt-c` (Fanuc `G68.2 P1 I J K`, roll-pitch-yaw
        /// in rotation order Q123) [the order as LinuxCNC's G68.2 remap reads its default Q123;
        /// unconfirmed against Fanuc's manual].
        TiltRollPitchYaw = "tilt-roll-pitch-yaw",
        /// Tilts the working plane through three points given block by block (Fanuc `G68.2 P2`:
        /// `Q0 X Y Z` the origin, `Q1`, `Q2`, `Q3` the points as `X Y Z`): the first point to
        /// the second is the new X, the third on the new +Y side; the plane is put in force at
        /// the block that completes it; the origin `Q0`'s, else the first point.
        TiltThreePoints = "tilt-three-points",
        /// Tilts the working plane by two vectors given block by block (Fanuc `G68.2 P3`: `Q1 X
        /// Y Z I J K` the origin and the new X's direction, `Q2 I J K` the new Z's); the plane
        /// is put in force at the block that completes it.
        TiltTwoVectors = "tilt-two-vectors",
        /// Tilts the working plane by projection angles (Fanuc `G68.2 P4 I J K`): the plane's
        /// trace in the YZ plane at `tilt-a` from Y (a turn about X), its trace in the ZX plane
        /// at `tilt-b` from X (about Y), the new X along the second, turned by `tilt-c` about
        /// the new Z: Heidenhain's projection angles with the angles named by their axes [the
        /// traces' reading unconfirmed against the 30i manual's figure].
        TiltProjectionAngles = "tilt-projection-angles",
        /// Tilts the working plane in force further by Euler angles about an origin in its own
        /// coordinates (Fanuc `G68.4 X Y Z I J K`).
        TiltEulerIncremental = "tilt-euler-incremental",
        /// Cancels the tilted working plane (Heidenhain `PLANE RESET`).
        TiltReset = "tilt-reset",
        /// A swivel cycle (Siemens `CYCLE800`): mode, reference point, angles in the mode's
        /// axis order, zero point after swivelling; without arguments it cancels.
        TiltCycle = "tilt-cycle",
        /// Tool centre point control on (Heidenhain `M128`, `FUNCTION TCPM`, Siemens `TRAORI`):
        /// X Y Z are the tool tip's on the part, and the rotary axes (A, B, C) turn the tool
        /// axis, kept in the canon as `ToolAxis`.
        TcpOn = "tcp-on",
        /// Tool centre point control off (`M129`, `FUNCTION RESET TCPM`, `TRAFOOF`).
        TcpOff = "tcp-off",
        /// A tool length offset with tool centre point control (Fanuc `G43.4 H1`): the length
        /// offset as `length-comp-plus`, and tool centre point control on until it is cancelled.
        LengthCompTcp = "length-comp-tcp",
        /// A row of positions (Siemens `HOLES1`): from a reference point along an angle, the
        /// first at a distance, then evenly spaced. The modal cycle runs at each.
        PatternRow = "pattern-row",
        /// Positions on a circle (Siemens `HOLES2`): centre, radius, start angle and the angle
        /// between them (0: the full circle shared evenly). The modal cycle runs at each.
        PatternCircle = "pattern-circle",
        /// A rectangular pocket milled by a cycle (Siemens `POCKET3`): its reference point
        /// (`pocket-x`, `pocket-y`, the centre), `pocket-length` along the plane's first axis
        /// turned by `pocket-angle`, `width`, `corner-radius`, from the reference plane to
        /// its depth; its moves are the finishing pass on the wall at the floor, the contour as
        /// programmed under cutter compensation (the roughing passes are not expanded).
        MillPocketRect = "mill-pocket-rect",
        /// A circular pocket milled by a cycle (Siemens `POCKET4`): centre (`pocket-x`,
        /// `pocket-y`), `pocket-radius`, depth; its moves are the finishing pass as for
        /// `mill-pocket-rect`.
        MillPocketCircle = "mill-pocket-circle",
        /// A bore milled in a helix by a cycle (Heidenhain 208 BORE MILLING), called at the
        /// position in force, its centre: its diameter (`width`) from the reference plane down
        /// to its depth, `pitch` deeper each turn, climb or up-cut by `machining-type`; its moves are
        /// the helix down along the wall and a full circle at the floor, the wall as programmed
        /// under cutter compensation.
        MillBore = "mill-bore",
        /// A slot milled by a cycle (Heidenhain 253 SLOT MILLING), called at its centre:
        /// `pocket-length` from end to end along `pocket-angle`, `width`, its ends half circles,
        /// from the reference plane to its depth; its moves the finishing pass on its wall as
        /// for `mill-pocket-rect`.
        MillSlot = "mill-slot",
        /// Milling on a cylinder's developed surface by a cycle (Heidenhain 27 CYLINDER
        /// SURFACE, 28 CYLINDRICAL SURFACE SLOT, 29 CYL SURFACE RIDGE, 39 CYL. SURFACE
        /// CONTOUR): the contour the last `contour-define` named, drawn with the rotary axis
        /// as the length round the cylinder of radius `pocket-radius` (degrees, or mm where
        /// `geometry` is 1), cut `depth-relative` below its surface in plunges of `cut-depth`;
        /// `width` the slot's or ridge's. Cut under cylindrical interpolation, its tool axis radial.
        MillCylinderSurface = "mill-cylinder-surface",
        /// A grid of positions (Siemens `CYCLE801`): a corner, an angle, column and row
        /// spacing and counts, visited row by row in a meander. The modal cycle runs at each.
        PatternGrid = "pattern-grid",
        /// Reads data only the machine has at run time into a parameter (Heidenhain `FN 18:
        /// SYSREAD`); the parameter keeps its value in the analysis, with a warning.
        MachineDataRead = "machine-data-read",
        /// A corner of the workpiece blank from the block's axis words (`BLK FORM 0.1 Z X+0 Y+0 Z-40`); recorded.
        Stock = "stock",
        /// Machine-specific function the interpreter records but does not model.
        Other = "other",
        /// Waits for the operator to type a number and stores it in the variable written after
        /// the code (Centroid CNC12 `M224 #111 "prompt"`, `M225 #100 "text"`): the variable
        /// becomes unknown, as a value only the run knows; otherwise recorded as `other`.
        OperatorInput = "operator-input",
        /// Writes text to a printer, a file or the screen (Heidenhain `FN 15: PRINT`):
        /// nothing the machine does.
        Output = "output",
    }
}

vocab! {
    /// The role of an address's value.
    Role {
        /// X axis.
        X = "axis-x",
        /// Y axis.
        Y = "axis-y",
        /// Z axis.
        Z = "axis-z",
        /// A axis.
        A = "axis-a",
        /// B axis.
        B = "axis-b",
        /// C axis.
        C = "axis-c",
        /// U axis.
        U = "axis-u",
        /// V axis.
        V = "axis-v",
        /// W axis.
        W = "axis-w",
        /// Arc centre or cycle offset along X.
        I = "offset-i",
        /// Arc centre or cycle offset along Y.
        J = "offset-j",
        /// Arc centre or cycle offset along Z, or a repeat count.
        K = "offset-k",
        /// Arc radius or cycle R plane.
        R = "radius",
        /// Feed rate.
        F = "feed",
        /// Spindle speed.
        S = "speed",
        /// Tool number.
        T = "tool",
        /// Length-offset index.
        H = "length-offset",
        /// Radius-offset index.
        D = "radius-offset",
        /// Dwell, index, program number or turns.
        P = "p",
        /// Peck depth or shift.
        Q = "q",
        /// Repeat count or data type.
        L = "l",
        /// Extra parameter (E).
        E = "e",
        /// G code.
        G = "g-code",
        /// M code.
        M = "m-code",
        /// Block number.
        N = "block-number",
        /// Program number or control word.
        O = "program-number",
        /// Cycle retract plane (positional cycles).
        RetractPlane = "retract-plane",
        /// Cycle reference plane.
        ReferencePlane = "reference-plane",
        /// Cycle safety distance.
        SafetyDistance = "safety-distance",
        /// Cycle absolute depth.
        Depth = "depth",
        /// Cycle depth relative to the reference plane.
        DepthRelative = "depth-relative",
        /// Dwell time at depth.
        DwellTime = "dwell-time",
        /// First peck depth.
        PeckFirst = "peck-first",
        /// Peck decrement.
        PeckDecrement = "peck-decrement",
        /// Arc end angle, intermediate point and similar extra geometry.
        Geometry = "geometry",
        /// The radius of an arc rounding the corner at the end of this block's move, tangent
        /// to it and to the next (Siemens `RND=5`, Fanuc `,R5`).
        CornerRadius = "corner-radius",
        /// A chamfer cutting back the corner at the end of this block's move by this much along
        /// each move (Siemens `CHR=2`, Fanuc `,C2`).
        CornerChamfer = "corner-chamfer",
        /// A chamfer of this length itself at the corner at the end of this block's move,
        /// cutting back equally along each move (Siemens `CHF=2`).
        CornerChamferLength = "corner-chamfer-length",
        /// The angle of a straight feed's line from the +Z axis, counter-clockwise in the ZX
        /// plane (Fanuc lathe direct drawing dimensions, `X51.,A-45.`): the end's coordinate the
        /// block leaves out follows from it.
        LineAngle = "line-angle",
        /// A value the engine keeps but does not interpret.
        Extra = "extra",
        /// The tool's cutting edge whose length and radius offsets apply, kept but not
        /// interpreted (Siemens `D1`; the tool change activates the first edge).
        ToolEdge = "tool-edge",
        /// A retract level relative to the reference plane (Heidenhain Q204, 2nd set-up clearance).
        /// On a swivel cycle (`tilt-cycle`), its retract before swivelling (Siemens `CYCLE800`
        /// `_FR`): 0 none, else a retract ncplan does not model.
        RetractDistance = "retract-distance",
        /// An absolute first peck depth (Siemens FDEP).
        PeckFirstAbsolute = "peck-first-absolute",
        /// The feed of a cycle's plunge (Heidenhain Q206).
        PlungeFeed = "plunge-feed",
        /// The re-approach distance above the last peck depth (Siemens _DIS1, Heidenhain Q258).
        PreStop = "pre-stop",
        /// 0: chip breaking, 1: full retract between pecks (Siemens VARI).
        PeckMode = "peck-mode",
        /// A cycle number given after a keyword (`CYCL DEF 200`).
        CycleNumber = "cycle-number",
        /// The tool to prepare after a tool change (Mazak's second T: `T02 T05 M06`).
        NextTool = "next-tool",
        /// An arc's opening angle in degrees (Siemens `AR=`).
        OpeningAngle = "opening-angle",
        /// The intermediate point of a three-point arc, along X (Siemens `I1=`).
        ViaX = "via-x",
        /// The intermediate point of a three-point arc, along Y (Siemens `J1=`).
        ViaY = "via-y",
        /// The intermediate point of a three-point arc, along Z (Siemens `K1=`).
        ViaZ = "via-z",
        /// A polar end point's distance from the pole (Heidenhain `PR`).
        PolarRadius = "polar-radius",
        /// A polar end point's angle about the pole, in degrees from the plane's first axis
        /// (Heidenhain `PA`).
        PolarAngle = "polar-angle",
        /// Raises a program alarm with this number: the run stops with an error (Heidenhain
        /// `FN 14: ERROR= 1005`).
        AlarmNumber = "alarm-number",
        /// The spindle speed limit under constant surface speed (Siemens `LIMS=3000`).
        SpindleLimit = "spindle-limit",
        /// The depth of each roughing pass, a radius (Fanuc G71's first U).
        CutDepth = "cut-depth",
        /// The finishing allowance along Z left by roughing (Fanuc G71 W).
        AllowanceZ = "allowance-z",
        /// The finishing allowance along X left by roughing, a diameter (Fanuc G72 U).
        AllowanceX = "allowance-x",
        /// A hole pattern's reference point (row, grid) or centre (circle), along the plane's first axis.
        PatternX = "pattern-x",
        /// A hole pattern's reference point or centre, along the plane's second axis.
        PatternY = "pattern-y",
        /// A hole pattern's direction (row, grid) or start angle (circle), in degrees from the plane's first axis.
        PatternAngle = "pattern-angle",
        /// The distance from a row's reference point to its first position.
        PatternFirst = "pattern-first",
        /// The distance between positions of a row, or between the columns of a grid.
        PatternSpacing = "pattern-spacing",
        /// The distance between the rows of a grid.
        PatternRowSpacing = "pattern-row-spacing",
        /// The number of positions of a row or circle, or of columns of a grid.
        PatternCount = "pattern-count",
        /// The number of rows of a grid.
        PatternRowCount = "pattern-row-count",
        /// The radius of a circle of positions.
        PatternRadius = "pattern-radius",
        /// A milled pocket's reference point (its centre), along the plane's first axis.
        PocketX = "pocket-x",
        /// A milled pocket's reference point, along the plane's second axis.
        PocketY = "pocket-y",
        /// A rectangular pocket's length, along its angle.
        PocketLength = "pocket-length",
        /// A rectangular pocket's angle, in degrees from the plane's first axis.
        PocketAngle = "pocket-angle",
        /// A circular pocket's radius.
        PocketRadius = "pocket-radius",
        /// The angle between positions on a circle, in degrees (0: the full circle shared evenly).
        PatternStepAngle = "pattern-step-angle",
        /// A blank definition's flags saying which of its numbers are absolute (Siemens
        /// `WORKPIECE`: bit 4 X, bit 5 Y, bit 6 the bottom, bit 7 the machining limit).
        BlankFlags = "blank-flags",
        /// A blank's top along the tool axis.
        BlankTop = "blank-top",
        /// A blank's bottom (absolute, or incremental from the top).
        BlankBottom = "blank-bottom",
        /// A blank's first corner along the plane's first axis (a centred blank: its length).
        BlankX0 = "blank-x0",
        /// A blank's first corner along the plane's second axis (a centred blank: its width).
        BlankY0 = "blank-y0",
        /// A blank's second corner along the plane's first axis (absolute, or incremental from the first).
        BlankX1 = "blank-x1",
        /// A blank's second corner along the plane's second axis.
        BlankY1 = "blank-y1",
        /// The tool axis vector's X component, from the tool tip towards the holder (CLDATA
        /// `GOTO/x,y,z,i,j,k`); kept in the canon as `ToolAxis`.
        ToolAxisI = "tool-axis-i",
        /// The tool axis vector's Y component.
        ToolAxisJ = "tool-axis-j",
        /// The tool axis vector's Z component.
        ToolAxisK = "tool-axis-k",
        /// A tilted plane's first angle (spatial: about X; Euler: precession about Z; a swivel
        /// cycle's first rotation).
        TiltA = "tilt-a",
        /// A tilted plane's second angle (spatial: about Y; Euler: nutation about the new X).
        TiltB = "tilt-b",
        /// A tilted plane's third angle (spatial: about Z; Euler: about the new Z).
        TiltC = "tilt-c",
        /// A swivel cycle's mode: bits 7-6 how the angles are read (00 axis by axis, 01 solid
        /// angle), bits 1-0,
        /// 3-2, 5-4 the axis of the first, second and third rotation (01 X, 10 Y, 11 Z).
        TiltMode = "tilt-mode",
        /// A turn about the tilted plane's own Z once its points give it (Fanuc `G68.2 P2 Q0 R`).
        TiltTurn = "tilt-turn",
        /// A swivel cycle's swivel mode: its units digit 1 adds the swivel to the plane in force
        /// (Siemens `_ST` 200001), 0 swivels from the untilted plane.
        TiltSwivel = "tilt-swivel",
        /// The point a tilted plane turns about, X (Fanuc `G68.2 X`, Siemens `_X0`).
        TiltOriginX = "tilt-origin-x",
        /// The point a tilted plane turns about, Y.
        TiltOriginY = "tilt-origin-y",
        /// The point a tilted plane turns about, Z.
        TiltOriginZ = "tilt-origin-z",
        /// The zero point on the tilted plane, along its own X (Siemens `_X1`).
        TiltShiftX = "tilt-shift-x",
        /// The zero point on the tilted plane, along its own Y.
        TiltShiftY = "tilt-shift-y",
        /// The zero point on the tilted plane, along its own Z.
        TiltShiftZ = "tilt-shift-z",
        /// A tilted plane's base vector (its X axis), X component (Heidenhain `PLANE VECTOR BX`).
        TiltBaseX = "tilt-base-x",
        /// The base vector's Y component.
        TiltBaseY = "tilt-base-y",
        /// The base vector's Z component.
        TiltBaseZ = "tilt-base-z",
        /// A tilted plane's first point, X (Heidenhain `PLANE POINTS P1X`).
        TiltP1X = "tilt-p1-x",
        /// The first point's Y.
        TiltP1Y = "tilt-p1-y",
        /// The first point's Z.
        TiltP1Z = "tilt-p1-z",
        /// A tilted plane's second point, X: from the first towards it is the plane's X.
        TiltP2X = "tilt-p2-x",
        /// The second point's Y.
        TiltP2Y = "tilt-p2-y",
        /// The second point's Z.
        TiltP2Z = "tilt-p2-z",
        /// A tilted plane's third point, X: on the plane's +Y side of the line through the others.
        TiltP3X = "tilt-p3-x",
        /// The third point's Y.
        TiltP3Y = "tilt-p3-y",
        /// The third point's Z.
        TiltP3Z = "tilt-p3-z",
        /// The contour a turning cycle machines, by name: a subprogram, a label (`"KONTUR"`) or a
        /// label range (`"START:END"`) (Siemens CYCLE95 NPP); a text argument.
        ContourName = "contour-name",
        /// What and where a turning cycle machines, by its number (Siemens VARI: roughing or
        /// finishing, along Z or across X, outside or inside, from which side); how a milling
        /// cycle cuts (Heidenhain Q351: positive climb milling, negative up-cut).
        MachiningType = "machining-type",
        /// A finishing allowance all round a contour, or on a thread's depth (Siemens FAL), per side.
        Allowance = "allowance",
        /// The feed of a cycle's finishing pass (Siemens CYCLE95 FF3).
        FinishFeed = "finish-feed",
        /// A cycle's end point across the axis (a thread's diameter at its end, Siemens DM2).
        EndX = "end-x",
        /// A cycle's end point along the axis (a thread's end, Siemens FPL).
        EndZ = "end-z",
        /// A groove's width along the axis (Siemens WIDG); a pocket's across its length
        /// (`POCKET3` _WID); a milled bore's diameter (Heidenhain 208 Q335).
        Width = "width",
        /// A groove's or a thread's depth, per side (Siemens DIAG, TDEP).
        ProfileDepth = "profile-depth",
        /// A thread's lead (Siemens PIT).
        Pitch = "pitch",
        /// A metric thread by its size (Siemens MPIT: 3 to 60 for M3 to M60), its coarse pitch.
        ThreadSize = "thread-size",
        /// A thread's run-in along the axis before its start (Siemens APP).
        RunIn = "run-in",
        /// A thread's run-out along the axis after its end (Siemens ROP).
        RunOut = "run-out",
        /// The number of roughing passes of a thread (Siemens NRC).
        Passes = "passes",
        /// The passes at full depth without infeed after a thread's last cut (Siemens NID).
        IdlePasses = "idle-passes",
        /// The number of starts of a thread (Siemens NUMT).
        ThreadStarts = "thread-starts",
        /// The infeed angle of a thread's passes, degrees (Siemens IANG).
        InfeedAngle = "infeed-angle",
        /// The included angle of a threading tool, degrees (Haas G76 A).
        ToolAngle = "tool-angle",
        /// A keyword code of the dialect (internal: the word's value is the code's index).
        Keyword = "keyword",
        /// A named cycle call (internal: the word's value is the cycle's index).
        Cycle = "cycle",
        /// The value after a legacy cycle's sub-block name (internal: `CYCL DEF 1.1 SET UP 2`
        /// gives 2; the sub-block's number says which argument it is).
        CycleValue = "cycle-value",
    }
}

impl Meaning {
    /// Whether the meaning is a lathe cycle over the contour between the blocks its P and Q
    /// name (Fanuc G70-G73).
    pub fn names_contour(self) -> bool {
        matches!(self, Meaning::CycleRoughTurn | Meaning::CycleRoughFace | Meaning::CycleRoughPattern | Meaning::CycleFinishContour)
    }

    /// Whether the meaning sets or cancels a mirror image (programmable, or the frame's).
    pub fn mirrors(self) -> bool {
        matches!(self, Meaning::FrameMirror | Meaning::FrameMirrorAdd | Meaning::Mirror | Meaning::MirrorAboutZero | Meaning::MirrorCancel)
    }

    /// Whether the meaning is a canned drilling or boring cycle.
    pub fn is_cycle(self) -> bool {
        matches!(
            self,
            Meaning::CycleDrill
                | Meaning::CycleDrillDwell
                | Meaning::CyclePeckDrill
                | Meaning::CycleChipBreak
                | Meaning::CycleTap
                | Meaning::CycleTapLeft
                | Meaning::CycleBore
                | Meaning::CycleBoreStop
                | Meaning::CycleBackBore
                | Meaning::CycleBoreManual
                | Meaning::CycleBoreDwell
                | Meaning::CycleFineBore
        )
    }
}

impl Role {
    /// Number of roles, for role-indexed arrays.
    pub const COUNT: usize = Role::ALL.len();

    /// Axis roles in canonical order (X Y Z A B C).
    pub const AXES: [Role; 6] = [Role::X, Role::Y, Role::Z, Role::A, Role::B, Role::C];

    /// Roles the parser gives words itself (keyword codes, named cycles); a dialect file may not use them.
    pub fn is_internal(self) -> bool {
        matches!(self, Role::Keyword | Role::Cycle | Role::CycleValue)
    }

    /// Whether the role is a machine axis (X Y Z, A B C, U V W).
    pub fn is_axis(self) -> bool {
        matches!(self, Role::X | Role::Y | Role::Z | Role::A | Role::B | Role::C | Role::U | Role::V | Role::W)
    }

    /// Whether the decimal-point rule may scale this role.
    pub fn is_length(self) -> bool {
        matches!(self, Role::X | Role::Y | Role::Z | Role::U | Role::V | Role::W | Role::I | Role::J | Role::K | Role::R | Role::Q)
    }
}

vocab! {
    /// A step of the order of execution within a block.
    Step {
        /// Comments and messages.
        Comment = "comment",
        /// Feed-rate mode group.
        FeedMode = "feed-mode",
        /// Feed rate (F).
        Feed = "feed",
        /// Spindle speed (S).
        Speed = "speed",
        /// Tool select (T).
        ToolSelect = "tool-select",
        /// Tool-change group.
        ToolChange = "tool-change",
        /// Spindle group.
        Spindle = "spindle",
        /// Coolant group.
        Coolant = "coolant",
        /// Dwell group.
        Dwell = "dwell",
        /// Plane group.
        Plane = "plane",
        /// Units group.
        Units = "units",
        /// Cutter compensation group.
        CutterComp = "cutter-comp",
        /// Tool length compensation group.
        LengthComp = "length-comp",
        /// Work coordinate system group.
        Wcs = "wcs",
        /// Path-control group.
        PathMode = "path-mode",
        /// Distance-mode group.
        Distance = "distance",
        /// Arc-distance-mode group.
        ArcDistance = "arc-distance",
        /// Canned-cycle return group.
        RetractMode = "retract-mode",
        /// Spindle speed mode group.
        SpindleMode = "spindle-mode",
        /// Other non-modal codes (G10, G28, G92 ...).
        NonModal = "non-modal",
        /// Motion group.
        Motion = "motion",
        /// Program flow (M98, M99).
        Flow = "flow",
        /// Program stop group.
        Stop = "stop",
        /// Codes the engine only records.
        Misc = "misc",
    }
}

vocab! {
    /// What a control-flow keyword does (`IF`, `o100 while`, `GOTO`).
    Statement {
        /// Start of a subroutine definition (`o100 sub`).
        Sub = "sub",
        /// End of a subroutine definition; returns.
        EndSub = "endsub",
        /// Subroutine call with bracketed arguments (`o100 call [1] [2]`).
        Call = "call",
        /// Return from a subroutine, optionally with a value.
        Return = "return",
        /// Conditional: block form (`o1 if [c]`), jump form (`IF [c] GOTO n`) or `THEN` form.
        If = "if",
        /// A jump chosen by value: `CASE R1 OF 1 GOTOF A 2 GOTOF B DEFAULT GOTOF C`; with no
        /// match and no `DEFAULT`, the run goes on with the next block.
        Case = "case",
        /// Another branch of a block conditional.
        ElseIf = "elseif",
        /// The last branch of a block conditional.
        Else = "else",
        /// End of a block conditional.
        EndIf = "endif",
        /// Loop head (`o1 while [c]`, `WHILE [c] DO m`), or the tail of a do-loop.
        While = "while",
        /// End of a `while` loop.
        EndWhile = "endwhile",
        /// Head of a do-loop, or the loop identifier after `WHILE` (`DO 1`).
        Do = "do",
        /// End of a numbered loop (`END 1`).
        EndDo = "end-do",
        /// Head of a counting loop: `FOR R1=0 TO 10` (step 1).
        For = "for",
        /// End of a counting loop.
        EndFor = "endfor",
        /// Head of a loop whose condition stands at its end (`REPEAT` ... `UNTIL c`).
        RepeatUntil = "repeat-until",
        /// End of a `repeat-until` loop: leaves it when the condition holds.
        Until = "until",
        /// Head of an endless loop (`LOOP` ... `ENDLOOP`), left by a jump.
        Loop = "loop",
        /// End of an endless loop.
        EndLoop = "endloop",
        /// Counted loop head (`o1 repeat [3]`).
        Repeat = "repeat",
        /// End of a counted loop.
        EndRepeat = "endrepeat",
        /// Leave the innermost loop.
        Break = "break",
        /// Next iteration of the innermost loop.
        Continue = "continue",
        /// Jump to a block number (`GOTO 10`), or the jump part of `IF [c] GOTO n`; a named
        /// target is a label (`GOTO MARK1`). Searched forward, then from the top.
        Goto = "goto",
        /// Jump forward only (`GOTOF MARK1`).
        GotoForward = "goto-forward",
        /// Jump backward only (`GOTOB MARK1`).
        GotoBack = "goto-back",
        /// Jump like `goto`, but a missing target is no error (`GOTOC`).
        GotoQuiet = "goto-quiet",
        /// Jump to a label, numbered or named (`GOTO LBL 5` after `FN 9: IF ...`).
        GotoLabel = "goto-label",
        /// Defines a label (`LBL 1`, `LBL "name"`): a jump target and the start of a section
        /// a label call runs. The dialect's end label (`LBL 0`) returns from a label call.
        Label = "label",
        /// Runs the section after a label (`CALL LBL 1 REP 2`): up to the end label when the
        /// label is a subprogram, or up to this call again when it is a section before it.
        CallLabel = "call-label",
        /// Runs a section of this program again (`REPEAT START END P=2`: from the block with
        /// the first label through the block with the second; `REPEAT START P=2`: from the
        /// label up to this statement). The section lies before the statement; P (default 1)
        /// counts the extra passes. The dialect gives this the keyword of `repeat-until` too:
        /// a label after the keyword makes it a section repeat.
        RepeatSection = "repeat-section",
        /// Runs the one block with a label again (`REPEATB MARK P=3`).
        RepeatBlock = "repeat-block",
        /// Runs another program by name (`CALL PGM NAME`, `CALL "NAME"`, `L123 P2`).
        CallProgram = "call-program",
        /// The head of a subprogram with named parameters (`PROC NAME(REAL A, INT B)`).
        Procedure = "procedure",
        /// A statement with no effect on the machining (`EXTERN` declarations).
        Inert = "inert",
        /// A statement of the control that ncplan does not simulate (Siemens synchronized
        /// actions, `WHENEVER $A_IN[1] DO OVR=0`): skipped with a warning naming it.
        Unsupported = "unsupported",
        /// The statement part of `IF [c] THEN ...`.
        Then = "then",
        /// Print a formatted line to the data output (`DPRNT[X#100[53]]`): a message.
        Print = "print",
        /// Data-output housekeeping with no effect on the machining (`POPEN`, `PCLOS`, `SETVN`).
        Output = "output",
        /// Declares variables, with optional initial values (`DEF REAL LEN=10.5, WID`).
        Declare = "declare",
    }
}

vocab! {
    /// What a system variable reads or does when written.
    SystemVar {
        /// Writing raises an alarm: the program stops with an error (`#3000`).
        Alarm = "alarm",
        /// Writing stops the program with a message (`#3006`).
        StopMessage = "stop-message",
        /// Current X in program coordinates.
        PositionX = "position-x",
        /// Current Y in program coordinates.
        PositionY = "position-y",
        /// Current Z in program coordinates.
        PositionZ = "position-z",
        /// The tool in the spindle.
        Tool = "tool",
        /// The programmed feed rate.
        Feed = "feed",
        /// The programmed spindle speed.
        Speed = "speed",
        /// The radius of the tool in the spindle, in program units, from the tool table as
        /// the program changed it (0 where unknown).
        ToolRadius = "tool-radius",
        /// The diameter of the tool in the spindle, likewise.
        ToolDiameter = "tool-diameter",
        /// X where the last probe move stopped, program coordinates.
        ProbeX = "probe-x",
        /// Y where the last probe move stopped.
        ProbeY = "probe-y",
        /// Z where the last probe move stopped.
        ProbeZ = "probe-z",
        /// 1 when the last probe move touched, else 0.
        ProbeTripped = "probe-tripped",
        /// Current A in program coordinates (B and C likewise).
        PositionA = "position-a",
        /// Current B in program coordinates.
        PositionB = "position-b",
        /// Current C in program coordinates.
        PositionC = "position-c",
        /// Current X in machine coordinates, program units (Y to C likewise).
        MachineX = "machine-x",
        /// Current Y in machine coordinates.
        MachineY = "machine-y",
        /// Current Z in machine coordinates.
        MachineZ = "machine-z",
        /// Current A in machine coordinates.
        MachineA = "machine-a",
        /// Current B in machine coordinates.
        MachineB = "machine-b",
        /// Current C in machine coordinates.
        MachineC = "machine-c",
        /// The motion mode's code ×10 (G1: 10, G38.2: 382; 800 after G80).
        MotionMode = "motion-mode",
        /// The plane's code ×10 (170, 180, 190).
        Plane = "plane",
        /// The cutter compensation code ×10 (400 off, 410 left, 420 right).
        CutterComp = "cutter-comp",
        /// 1 in millimetres, else 0.
        Metric = "metric",
        /// 1 in inches, else 0.
        Imperial = "imperial",
        /// 1 in absolute distance mode, else 0.
        Absolute = "absolute",
        /// 1 in incremental distance mode, else 0.
        Incremental = "incremental",
        /// 1 in inverse time feed mode, else 0.
        InverseTime = "inverse-time",
        /// 1 in units per minute feed mode, else 0.
        UnitsPerMinute = "units-per-minute",
        /// 1 in units per revolution feed mode, else 0.
        UnitsPerRev = "units-per-rev",
        /// The work coordinate system's code ×10 (540 to 593).
        CoordSystem = "coord-system",
        /// 1 when a tool offset is in force (not zero), else 0.
        ToolOffsetOn = "tool-offset-on",
        /// 1 when canned cycles retract to R (G99), else 0.
        RetractRPlane = "retract-r-plane",
        /// 1 when canned cycles retract to the initial level (G98), else 0.
        RetractOldZ = "retract-old-z",
        /// 1 when S is in revolutions per minute (G97), else 0.
        SpindleRpmMode = "spindle-rpm-mode",
        /// 1 in constant surface speed (G96), else 0.
        SpindleCssMode = "spindle-css-mode",
        /// 1 when arc centres are absolute (G90.1), else 0.
        IjkAbsolute = "ijk-absolute",
        /// 1 in lathe diameter mode (G7), else 0.
        DiameterMode = "diameter-mode",
        /// 1 in lathe radius mode (G8), else 0.
        RadiusMode = "radius-mode",
        /// 1 when the spindle turns, else 0.
        SpindleOn = "spindle-on",
        /// 1 when the spindle turns clockwise, else 0.
        SpindleCw = "spindle-cw",
        /// 1 when mist coolant is on, else 0.
        Mist = "mist",
        /// 1 when flood coolant is on, else 0.
        Flood = "flood",
        /// 1 when the feed override is enabled, else 0.
        FeedOverride = "feed-override",
        /// 1 when the spindle speed override is enabled, else 0.
        SpeedOverride = "speed-override",
        /// The tool selected for the next change.
        SelectedTool = "selected-tool",
        /// The call depth: 0 in the main program.
        CallLevel = "call-level",
        /// The source line of the block being run.
        Line = "line",
        /// A fixed value, the element's `value` (a version number, a switch the analysis
        /// takes at its initial setting).
        Constant = "constant",
    }
}

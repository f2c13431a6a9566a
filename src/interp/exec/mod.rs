//! The execute phase: what a block's words and codes do, step by step.
//!
//! A block runs in the steps the dialect's `<execution-order>` gives; [`Interpreter::step`]
//! runs one, and [`Interpreter::execute_code`] one code, by handing it to the handler of its
//! group of meanings, as rs274's `convert_*` functions do. Each group lives in a file named
//! after it:
//!
//! - `modes.rs`: plane, units, distance modes, the lathe's diameter mode, the cycles'
//!   return mode;
//! - `motion_mode.rs`: the motion group (the modal motion code, its cancel G80);
//! - `feed.rs`: feed modes, the F word, the override switches;
//! - `spindle.rs`: spindle turning, speed modes and limit, the S word, coolant;
//! - `tool.rs`: the T word, tool change, tool length offsets, tool data;
//! - `compensation.rs`: cutter radius compensation;
//! - `offsets.rs`: work offsets and coordinate systems, G92 shifts, reference positions;
//! - `transform.rs`: programmable rotation and scaling;
//! - `tilt.rs`: the tilted working plane (`PLANE`, `CYCLE800`, `G68.2`);
//! - `contour.rs`: the pole and corner blocks of the contour languages;
//! - `stops.rs`: stops, dwells and program end;
//! - `calls.rs`: subprogram and macro calls and returns (requests to the flow driver);
//! - `comments.rs`: comments and the directives they carry;
//! - `records.rs`: codes that are only recorded or noted (the blank, machine data reads).
//!
//! Doors: [`Interpreter::step`] and [`Interpreter::execute_code`].

mod calls;
mod comments;
mod compensation;
mod contour;
mod feed;
mod modes;
mod motion_mode;
mod offsets;
mod records;
mod spindle;
mod stops;
pub(super) mod tilt;
mod tool;
mod transform;

use crate::canon::CanonSink;
use crate::diag::{Code, Diagnostic};
use crate::dialect::{CodeDef, Meaning, Step};
use crate::interp::Interpreter;
use crate::syntax::Block;
use crate::text::TextRange;

/// Whether code meaning `m` returns to or approaches a reference or fixed position, or
/// stores one (`G28`, `G30`, `G28.1`, SINUMERIK `G74`, `G75`, Centroid `M25`).
fn homes(m: Meaning) -> bool {
    matches!(
        m,
        Meaning::Home1
            | Meaning::Home2
            | Meaning::Home1Set
            | Meaning::Home2Set
            | Meaning::ReferenceApproach
            | Meaning::FixedPointApproach
            | Meaning::TravelLimit
    )
}

/// Whether code meaning `m` sets the pole of polar positions (`CC`, `G111`) or switches the
/// polar coordinate command (Fanuc `G16`, `G15`).
fn poles(m: Meaning) -> bool {
    matches!(
        m,
        Meaning::Pole | Meaning::PoleKeeping | Meaning::PoleIncremental | Meaning::PoleFromPole | Meaning::Polar | Meaning::PolarOff
    )
}

impl Interpreter<'_> {
    /// Runs step `step` of the block: its words of that step (comments, F, S, T) or its codes
    /// that take effect at it.
    pub(super) fn step(&mut self, step: Step, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        // A block that numbers its spindle (`S2=2000 M2=3`, `SPOS[2]=0`) addresses it at its
        // speed and spindle steps (the main one again after the block: `run_steps`).
        if block.spindle.is_some() && matches!(step, Step::Speed | Step::Spindle) {
            self.address_spindle(block.spindle, sink);
        }
        match step {
            Step::Comment => self.comments(block, sink, diags),
            Step::Feed => self.feed_word(sink),
            Step::Speed => self.speed_word(sink),
            Step::ToolSelect => self.tool_select(block, sink, diags),
            Step::Misc => {}
            Step::Stop if self.stop_message.is_some() => self.stop_with_message(step, block, sink, diags),
            _ => self.code_step(step, block, sink, diags),
        }
    }

    /// A step that only codes have: the block's codes at `step`; at the motion step without
    /// one, the motion mode in force moves to the block's axis words.
    fn code_step(&mut self, step: Step, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        let ran = self.run_codes(step, block, sink, diags);
        if step == Step::Motion && !ran {
            if let Some(c) = self.active_motion_code() {
                self.execute_code(c, block.range, block, sink, diags);
            } else if self.has_axes && !self.codes.iter().any(|&(c, _)| self.claims_axes(c)) {
                let d = Diagnostic::new(
                    Code::UnusedWord,
                    block.range,
                    "axis words without an active motion mode (after G80 or at program start)",
                );
                diags.push(self.unused(d));
            }
        }
    }

    /// Executes the block's codes that take effect at `step`; true if there were any.
    pub(super) fn run_codes(&mut self, step: Step, block: &Block, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) -> bool {
        // Index loop: `execute_code` needs `&mut self`, and the hot path must not allocate.
        let mut ran = false;
        for k in 0..self.codes.len() {
            let (c, range) = self.codes[k];
            if self.dialect.groups[self.code(c).group].step == step {
                ran = true;
                if let Some(spelling) = &self.code(c).rejected {
                    let def = self.code(c);
                    let msg = format!("`{}` is not the control's spelling (`{spelling}`): the control stops at this block", def.label());
                    diags.push(Diagnostic::new(Code::RejectedSpelling, range, msg));
                }
                if self.code(c).moves {
                    let def = self.code(c);
                    let d = super::read::motion_unknown(&def.label(), &def.name, range);
                    self.limited(diags, "motion-unknown", d);
                    self.position_lost();
                }
                self.execute_code(c, range, block, sink, diags);
            }
        }
        ran
    }

    /// Executes code `c` (written at `range`): the handler of its meaning's group.
    pub(super) fn execute_code(
        &mut self,
        c: usize,
        range: TextRange,
        block: &Block,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        let def = self.code(c);
        if let Some(second) = def.also {
            self.second_effect(second, sink);
        }
        match def.meaning {
            Meaning::FeedPerMinute | Meaning::FeedPerRev | Meaning::FeedInverseTime => self.feed_mode(def.meaning, sink),
            Meaning::ToolChange => self.tool_change(def, sink),
            Meaning::ToolSet => self.tool_set(def, range, sink, diags),
            Meaning::SpindleCw | Meaning::SpindleCcw | Meaning::SpindleStop => self.spindle_turn(def, sink),
            Meaning::SpindleOrient => self.orient_spindle(def, range, sink, diags),
            Meaning::CoolantMist | Meaning::CoolantFlood | Meaning::CoolantOff => self.coolant(def, sink),
            Meaning::Dwell => self.dwell(def, sink),
            Meaning::PlaneXy | Meaning::PlaneXz | Meaning::PlaneYz => self.plane(def, range, sink, diags),
            Meaning::UnitsInch | Meaning::UnitsMm => self.units(def, sink),
            Meaning::CompOff => self.comp_off_code(sink),
            Meaning::CompLeft | Meaning::CompRight | Meaning::CompLeftDiameter | Meaning::CompRightDiameter => {
                self.comp_on(def, range, sink, diags)
            }
            Meaning::LengthCompPlus | Meaning::LengthCompMinus | Meaning::LengthCompDynamic => {
                self.length_comp(def, sink);
                // A length offset of the tool centre point code's own modal group replaces it
                // (Fanuc group 08: `G43 H1` after `G43.4 H1` ends tool centre point control).
                let group = self.dialect.codes.iter().any(|c| c.group == def.group && c.meaning == Meaning::LengthCompTcp);
                if group && self.st.tcp && !self.st.tcp_machine {
                    self.tcp(false, sink, diags);
                }
            }
            Meaning::LengthCompCancel | Meaning::LengthCompTcp => {
                self.length_comp(def, sink);
                // The machine's kinematics keep theirs (LinuxCNC: G49 cancels only the offset).
                if !self.st.tcp_machine {
                    self.tcp(def.meaning == Meaning::LengthCompTcp, sink, diags);
                }
            }
            Meaning::TcpOn | Meaning::TcpOff => {
                if def.meaning == Meaning::TcpOff {
                    self.face_mode(false, sink);
                }
                self.tcp(def.meaning == Meaning::TcpOn, sink, diags)
            }
            Meaning::PolarInterpolation | Meaning::PolarInterpolationOff => {
                self.face_mode(def.meaning == Meaning::PolarInterpolation, sink)
            }
            Meaning::CylindricalInterpolation => self.cylinder_code(def, range, sink, diags),
            Meaning::Wcs | Meaning::WcsExtended => self.work_offset(def, range, sink, diags),
            Meaning::StateSave | Meaning::StateSaveAutorestore | Meaning::StateInvalidate | Meaning::StateRestore => {
                self.modal_context(def, range, sink, diags)
            }
            // Path control (exact stop, blending): no effect on the programmed path.
            Meaning::PathMode => {}
            Meaning::SpindleLimit | Meaning::SpindleCss | Meaning::SpindleRpm => self.spindle_speed_mode(def, sink),
            Meaning::DistanceAbsolute | Meaning::DistanceIncremental => self.distance_mode(def, sink),
            Meaning::ArcDistanceAbsolute | Meaning::ArcDistanceIncremental => self.arc_distance_mode(def),
            Meaning::RetractInitial | Meaning::RetractR => self.retract_mode(def),
            Meaning::SetData => self.set_data(def, range, sink, diags),
            Meaning::OriginShift
            | Meaning::LocalOffset
            | Meaning::OriginShiftSuspend
            | Meaning::OriginShiftRestore
            | Meaning::OriginShiftCancel => self.origin_offset(def, sink),
            Meaning::Rotation => self.rotation_code(def, range, diags),
            Meaning::RotationCancel => {
                self.untilt(sink);
                self.rotation_code(def, range, diags);
            }
            Meaning::TiltSpatial
            | Meaning::TiltEuler
            | Meaning::TiltEulerIncremental
            | Meaning::TiltRollPitchYaw
            | Meaning::TiltThreePoints
            | Meaning::TiltTwoVectors
            | Meaning::TiltProjectionAngles
            | Meaning::TiltVector
            | Meaning::TiltPoints
            | Meaning::TiltProjected
            | Meaning::TiltAxial
            | Meaning::TiltToolAxis
            | Meaning::TiltRelative
            | Meaning::TiltReset => self.tilt_code(def, range, block, sink, diags),
            Meaning::Scaling | Meaning::ScalingCancel => self.scaling_code(def, range, block, diags),
            m if homes(m) => self.home_code(def, range, sink, diags),
            // G53, M91, M92: the block's move is in machine (or builder's) coordinates; read at motion.
            Meaning::MachineCoords | Meaning::MachineBuilderCoords => {}
            Meaning::Rapid
            | Meaning::Linear
            | Meaning::ArcCw
            | Meaning::ArcCcw
            | Meaning::ArcPole
            | Meaning::ArcRadius
            | Meaning::ArcTangent
            | Meaning::ArcThreePoint
            | Meaning::SpindleSync
            | Meaning::RigidTap
            | Meaning::CycleThread
            | Meaning::CycleTurn
            | Meaning::CycleFace
            | Meaning::CycleThreadPass
            | Meaning::Probe
            | Meaning::ProbeQuiet
            | Meaning::SplineQuadratic
            | Meaning::Nurbs => self.motion_mode(c, def, range, block, sink, diags),
            m if m.is_cycle() => self.motion_mode(c, def, range, block, sink, diags),
            Meaning::NurbsEnd => self.nurbs_end_code(def, range, sink, diags),
            Meaning::CycleCancel => self.cycle_cancel(def, sink),
            Meaning::ProgramStop | Meaning::OptionalStop | Meaning::ProgramEnd | Meaning::ProgramEndRewind => self.stop(def, sink),
            Meaning::OverridesOn | Meaning::OverridesOff | Meaning::FeedOverrideSwitch | Meaning::SpeedOverrideSwitch => {
                self.overrides(def, sink)
            }
            Meaning::SubprogramCall | Meaning::LocalSubprogramCall | Meaning::SubprogramReturn => self.call(def, range, diags),
            Meaning::DiameterMode | Meaning::RadiusMode | Meaning::DiameterAbsolute => self.diameter_mode(def, sink),
            Meaning::Other => self.kinematics_output(def, sink, diags),
            Meaning::Output | Meaning::OperatorInput | Meaning::ProgramBegin | Meaning::ContourEnd => {}
            Meaning::Stock => self.stock_corner(sink),
            // Read by the arc or move of the block they stand in.
            Meaning::ArcDirCw | Meaning::ArcDirCcw | Meaning::RapidBlock => {}
            Meaning::ApproachTangent
            | Meaning::ApproachNormal
            | Meaning::ApproachArc
            | Meaning::DepartTangent
            | Meaning::DepartNormal
            | Meaning::DepartArc => self.motion(def, range, block, sink, diags),
            Meaning::CornerRound | Meaning::CornerChamfer => self.corner_code(def, range, diags),
            // Read with the block's corner words, after its move (`corner_words`).
            Meaning::RoundModal => {}
            m if poles(m) => self.pole_code(def),
            Meaning::FrameTrans | Meaning::FrameTransAdd => self.frame_trans(def.meaning == Meaning::FrameTransAdd, sink),
            Meaning::FrameRot | Meaning::FrameRotAdd => self.frame_rot(def, sink),
            Meaning::FrameScale | Meaning::FrameScaleAdd => self.frame_scale(def.meaning == Meaning::FrameScaleAdd, sink),
            m if m.mirrors() => self.mirror_code(def, sink),
            Meaning::CycleDefine => self.define_numbered_cycle(def, range, block, sink, diags),
            // Carried out after the block's moves (`cycles_after`).
            Meaning::CycleCall | Meaning::CycleModal => {}
            Meaning::CycleCallAt => self.call_at_position(range, sink, diags),
            Meaning::MachineDataRead => self.machine_data_read(def, range, diags),
            Meaning::PatternRow | Meaning::PatternCircle | Meaning::PatternGrid => self.code_pattern(def, range, block, sink, diags),
            m if m.names_contour() => self.contour_cycle(def, range, diags),
            Meaning::ProfileFinish | Meaning::ProfileRoughTurn | Meaning::ProfileRoughFace => self.profile_cycle(def, range, diags),
            Meaning::CycleIntent | Meaning::CycleTurnIntent => self.cycle_intent(def, range, diags),
            Meaning::CycleThreadMultiple | Meaning::CycleGroove | Meaning::CycleFacePeck => self.lathe_cycle(def, range, sink, diags),
            _ => self.not_executed(def, range, diags),
        }
    }

    /// A code this interpreter does not carry out: said once per meaning; a motion code also
    /// ends the motion mode in force.
    fn not_executed(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        if self.dialect.groups[def.group].step == Step::Motion {
            self.st.motion_code = None;
        }
        self.unsupported(def, range, diags);
    }

    /// Reports code `def` as not supported yet (once per meaning, as findings are limited).
    pub(in crate::interp) fn unsupported(&mut self, def: &CodeDef, range: TextRange, diags: &mut Vec<Diagnostic>) {
        let key: &'static str = def.meaning.as_str();
        self.limited(
            diags,
            key,
            Diagnostic::new(Code::Unsupported, range, format!("{} ({}) is not supported yet; it was skipped", def.label(), def.name)),
        );
    }
}

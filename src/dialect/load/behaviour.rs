//! Loading `<behaviour>`: how the control acts where controls differ (decimal input, dwell
//! units, what a tool change does, probing, arc and cycle tolerances, the start-up state).
//! The door is `Cx::behaviour`; each attribute with words of its own has a reader.

use super::super::xml::Element;
use super::super::{AddressDef, Behaviour, DecimalInput, DwellPoint, TapStyle, TimeUnit};
use super::Cx;
use crate::canon::Plane;

/// The attributes `<behaviour>` may carry.
const ATTRIBUTES: &[&str] = &[
    "decimal-input",
    "increment-mm",
    "increment-inch",
    "scaled",
    "dwell-unit",
    "tool-change-stops-spindle",
    "tool-change-applies-length",
    "position-after-tool-change",
    "h0",
    "probe-backoff-mm",
    "probe-tripped",
    "probe-backoff-inch",
    "peck-clearance-mm",
    "peck-clearance-inch",
    "arc-tolerance-mm",
    "arc-tolerance-inch",
    "arc-tolerance-steps",
    "cycle-without-r",
    "arc-relative-tolerance",
    "parameter-assignment",
    "feed-mode-resets-feed",
    "machine-m-codes",
    "resident-programs",
    "subroutine-path",
    "tool-word-changes",
    "arc-centres",
    "initial-feed",
    "tap-retract",
    "integer-rounding",
    "unused-words",
    "program-end",
    "motion-without-axes",
    "x-words",
    "lathe-x-words",
    "arc-centre-x",
    "corner-too-large",
    "lathe-tool-word",
    "initial-plane",
    "initial-retract",
    "dwell-point",
    "same-group-codes",
    "machine-coords-rapid",
    "modes-under-comp",
    "plane-under-comp",
];

/// The behaviour of a dialect without a `<behaviour>` element, and of each attribute left out.
fn defaults() -> Behaviour {
    Behaviour {
        decimal_input: DecimalInput::Calculator,
        decimal_input_stated: false,
        dwell_unit: TimeUnit::Seconds,
        dwell_point: DwellPoint::Unit,
        tool_change_stops_spindle: true,
        tool_change_applies_length: false,
        machine_coords_rapid: false,
        tool_change_rereads_position: false,
        h0_spindle_tool: false,
        probe_backoff_mm: 0.0,
        probe_backoff_inch: 0.0,
        probe_tripped: None,
        peck_clearance_mm: 0.254,
        peck_clearance_inch: 0.01,
        arc_tolerance_mm: 0.002,
        arc_tolerance_inch: 0.002 / 25.4,
        arc_tolerance_steps: 0.0,
        cycle_r_defaults_to_initial: false,
        arc_relative_tolerance: None,
        assign_before_reads: false,
        feed_mode_resets_feed: false,
        machine_m_codes: false,
        resident_programs: false,
        subroutine_path: false,
        tool_word_changes: false,
        lathe_tool_word_changes: false,
        tool_change_stated: false,
        arc_centres_pole: false,
        initial_feed_per_rev: false,
        tapping: TapStyle::RPlane,
        magnitude_rounding: false,
        motion_in_place: false,
        unused_words_rejected: false,
        end_required: false,
        x_diameter: false,
        lathe_x_diameter: false,
        absolute_centre_x_diameter: false,
        corners_reduced: false,
        x_words_stated: false,
        swivel_axes: None,
        initial_plane: Plane::Xy,
        initial_retract_r: false,
        same_group_last_wins: false,
        comp_locks_modes: false,
        plane_under_comp_stops: false,
    }
}

impl Cx {
    /// `<behaviour>`, or the defaults where the dialect has none.
    pub(super) fn behaviour(&mut self, el: Option<&Element>, addresses: &[AddressDef]) -> Behaviour {
        let mut b = defaults();
        let Some(el) = el else { return b };
        self.shape(el, ATTRIBUTES, &[]);
        b.decimal_input = self.decimal_input(el, addresses);
        b.dwell_unit = self.dwell_unit(el);
        b.dwell_point = self.dwell_point(el);
        b.tool_change_stops_spindle = self.bool(el, "tool-change-stops-spindle", true);
        b.tool_change_applies_length = self.bool(el, "tool-change-applies-length", false);
        b.machine_coords_rapid = self.bool(el, "machine-coords-rapid", false);
        b.h0_spindle_tool = self.either(el, "h0", "no-offset", "spindle-tool");
        b.tool_change_rereads_position = self.either(el, "position-after-tool-change", "program", "last-move");
        b.probe_backoff_mm = self.number(el, "probe-backoff-mm", 0.0).max(0.0);
        b.probe_backoff_inch = self.number(el, "probe-backoff-inch", b.probe_backoff_mm / 25.4).max(0.0);
        b.probe_tripped = self.probe_tripped(el);
        b.peck_clearance_mm = self.number(el, "peck-clearance-mm", 0.254);
        b.peck_clearance_inch = self.number(el, "peck-clearance-inch", 0.01);
        b.arc_tolerance_mm = self.number(el, "arc-tolerance-mm", 0.002);
        b.arc_tolerance_inch = self.number(el, "arc-tolerance-inch", b.arc_tolerance_mm / 25.4);
        b.arc_tolerance_steps = self.number(el, "arc-tolerance-steps", 0.0).max(0.0);
        b.cycle_r_defaults_to_initial = self.either(el, "cycle-without-r", "error", "initial-level");
        b.arc_relative_tolerance = self.attr(el, "arc-relative-tolerance").map(|_| self.number(el, "arc-relative-tolerance", 0.0));
        b.feed_mode_resets_feed = self.bool(el, "feed-mode-resets-feed", false);
        b.machine_m_codes = self.bool(el, "machine-m-codes", false);
        b.resident_programs = self.bool(el, "resident-programs", false);
        b.subroutine_path = self.bool(el, "subroutine-path", false);
        b.tool_word_changes = self.bool(el, "tool-word-changes", false);
        b.arc_centres_pole = self.either(el, "arc-centres", "offsets", "pole");
        b.initial_feed_per_rev = self.either(el, "initial-feed", "per-minute", "per-rev");
        b.motion_in_place = self.either(el, "motion-without-axes", "mode-only", "in-place");
        b.magnitude_rounding = self.either(el, "integer-rounding", "floor-ceiling", "toward-zero");
        b.unused_words_rejected = self.either(el, "unused-words", "ignored", "rejected");
        b.end_required = self.either(el, "program-end", "optional", "required");
        b.x_diameter = self.either(el, "x-words", "radius", "diameter");
        b.lathe_x_diameter = self.either(el, "lathe-x-words", "radius", "diameter");
        b.absolute_centre_x_diameter = self.either(el, "arc-centre-x", "radius", "diameter-absolute");
        b.corners_reduced = self.either(el, "corner-too-large", "error", "reduced");
        b.lathe_tool_word_changes = self.either(el, "lathe-tool-word", "selects", "changes");
        b.initial_retract_r = self.either(el, "initial-retract", "initial-level", "r-plane");
        b.same_group_last_wins = self.either(el, "same-group-codes", "error", "last");
        b.comp_locks_modes = self.either(el, "modes-under-comp", "free", "locked");
        // Locked modes lock the plane too (RS274/NGC).
        b.plane_under_comp_stops = self.either(el, "plane-under-comp", "unknown", "stops") || b.comp_locks_modes;
        b.initial_plane = self.initial_plane(el);
        b.tapping = self.tap_retract(el);
        b.assign_before_reads = self.parameter_assignment(el);
        b
    }

    /// `decimal-input`: `calculator` (`X10` is 10 units) or `least-increment` (`X10` is 10
    /// increments of `increment-mm`/`increment-inch`, for the `scaled` addresses).
    fn decimal_input(&mut self, el: &Element, addresses: &[AddressDef]) -> DecimalInput {
        match self.attr(el, "decimal-input").unwrap_or("calculator") {
            "calculator" => DecimalInput::Calculator,
            "least-increment" => DecimalInput::LeastIncrement {
                mm: self.number(el, "increment-mm", 0.001),
                inch: self.number(el, "increment-inch", 0.0001),
                scaled: self.roles(el, "scaled", addresses),
            },
            other => {
                self.error(Self::attr_range(el, "decimal-input"), format!("unknown decimal-input `{other}`"));
                DecimalInput::Calculator
            }
        }
    }

    /// `dwell-unit`: seconds or milliseconds.
    fn dwell_unit(&mut self, el: &Element) -> TimeUnit {
        match self.attr(el, "dwell-unit").unwrap_or("seconds") {
            "seconds" => TimeUnit::Seconds,
            "milliseconds" => TimeUnit::Milliseconds,
            other => {
                self.error(Self::attr_range(el, "dwell-unit"), format!("unknown dwell-unit `{other}`"));
                TimeUnit::Seconds
            }
        }
    }

    /// `dwell-point`: what a decimal point in a dwell's P does (`unit`, `seconds`, `alarm`).
    fn dwell_point(&mut self, el: &Element) -> DwellPoint {
        match self.attr(el, "dwell-point").unwrap_or("unit") {
            "unit" => DwellPoint::Unit,
            "seconds" => DwellPoint::Seconds,
            "alarm" => DwellPoint::Alarm,
            other => {
                self.error(Self::attr_range(el, "dwell-point"), format!("unknown dwell-point `{other}`"));
                DwellPoint::Unit
            }
        }
    }

    /// `probe-tripped`: what the probe-tripped variable reads after a probing move (1, 0, or
    /// unknown).
    fn probe_tripped(&mut self, el: &Element) -> Option<f64> {
        match self.attr(el, "probe-tripped") {
            None | Some("unknown") => None,
            Some("1") => Some(1.0),
            Some("0") => Some(0.0),
            Some(other) => {
                self.error(Self::attr_range(el, "probe-tripped"), format!("`probe-tripped` is 1, 0 or unknown, not `{other}`"));
                None
            }
        }
    }

    /// `initial-plane`: the plane in force at the program's start.
    fn initial_plane(&mut self, el: &Element) -> Plane {
        match self.attr(el, "initial-plane").unwrap_or("xy") {
            "xy" => Plane::Xy,
            "xz" => Plane::Xz,
            "yz" => Plane::Yz,
            other => {
                self.error(Self::attr_range(el, "initial-plane"), format!("`initial-plane` must be xy, xz or yz, not `{other}`"));
                Plane::Xy
            }
        }
    }

    /// `tap-retract`: where a tapping cycle goes back to.
    fn tap_retract(&mut self, el: &Element) -> TapStyle {
        match self.attr(el, "tap-retract").unwrap_or("r-plane") {
            "r-plane" => TapStyle::RPlane,
            "clear" => TapStyle::Clear,
            other => {
                self.error(Self::attr_range(el, "tap-retract"), format!("`tap-retract` must be r-plane or clear, not `{other}`"));
                TapStyle::RPlane
            }
        }
    }

    /// `parameter-assignment`: whether a block's assignments take effect before its reads.
    fn parameter_assignment(&mut self, el: &Element) -> bool {
        match self.attr(el, "parameter-assignment").unwrap_or("after-reads") {
            "after-reads" => false,
            "before-reads" => true,
            other => {
                self.error(
                    Self::attr_range(el, "parameter-assignment"),
                    format!("`parameter-assignment` must be after-reads or before-reads, not `{other}`"),
                );
                false
            }
        }
    }
}

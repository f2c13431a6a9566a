//! Heidenhain's cylinder surface cycles (TNC 640 cycle programming manual: 27 CYLINDER
//! SURFACE, 28 CYLINDRICAL SURFACE SLOT, 29 CYL SURFACE RIDGE, 39 CYL. SURFACE CONTOUR).
//!
//! The contour `CYCL DEF 14 CONTOUR` names (a subprogram `LBL n` … `LBL 0`) is drawn on the
//! cylinder's developed surface: the rotary axis C as the length round the cylinder (degrees,
//! or mm where `Q17=1`) and the linear axis parallel to the cylinder's. The cycle, when
//! called, cuts it on the cylinder of radius `Q16` by a tool whose axis is radial: from the
//! set-up clearance `Q6` over the surface it plunges at `Q11` in steps of `Q10` down to the
//! milling depth `Q1` below the surface, following the contour at `Q12` at each.
//!
//! Modelled through cylindrical interpolation (`interp::lathe`, `cylinder_mode`): the contour
//! is read without effect in the developed surface's plane (the flow driver's
//! `cylinder_contour`), then cut there between the cylinder's markers, so that the plan wraps
//! what it cuts round the cylinder with its radial axis. A tilted working plane in force (the
//! head turned radial, `PLANE SPATIAL SPB+90`) is put back after the cycle. The contour is
//! cut as programmed (its centre line for a slot or ridge, `Q20` wide); the allowance `Q3`
//! and the wall passes of a slot wider than the tool are not expanded.

use super::Interpreter;
use super::lathe::SurfaceWords;
use crate::canon::{CanonOp, CanonSink, Frame, Setting};
use crate::diag::{Code, Diagnostic};
use crate::dialect::Role;
use crate::text::TextRange;

/// A cylinder surface cycle, called: what it cuts the contour with.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct CylinderSurface {
    /// The cycle as written (`CYCL DEF 28`).
    name: String,
    /// The cylinder's radius, `Q16`.
    radius: f64,
    /// The milling depth below the cylinder's surface, `Q1` (as a positive length).
    depth: f64,
    /// The set-up clearance over the surface, `Q6`.
    clear: f64,
    /// The plunging depth of each pass, `Q10`; none: the whole depth at once.
    step: Option<f64>,
    /// The feed for plunging (`Q11`) and for milling (`Q12`).
    feeds: (Option<f64>, Option<f64>),
    /// Whether the contour's C words are lengths round the cylinder (`Q17=1`).
    mm: bool,
    /// The slot's width, `Q20` (cycle 28): the contour is its centre line.
    width: Option<f64>,
    /// Where the cycle was called.
    range: TextRange,
}

/// Passes a cycle may make at most: more is a slip in the plunging depth.
const MAX_PASSES: usize = 1000;

impl Interpreter<'_> {
    /// A cylinder surface cycle called (`args` its parameters' values): asks the flow driver
    /// for the contour cycle 14 named, to be cut by `cylinder_surface_cut`.
    pub(super) fn cylinder_surface(&mut self, name: &str, args: &[(Role, f64)], range: TextRange, diags: &mut Vec<Diagnostic>) {
        let get = |role: Role| args.iter().rev().find(|(r, _)| *r == role).map(|&(_, v)| v).filter(|v| v.is_finite());
        let Some(contour) = self.contour_named.clone().filter(|c| !c.trim().is_empty()) else {
            let msg = format!("{name} cuts the contour a CYCL DEF 14 CONTOUR before it names, and none is named; the cycle is skipped");
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        };
        let (Some(radius), Some(depth)) = (get(Role::PocketRadius).map(f64::abs), get(Role::DepthRelative).map(f64::abs)) else {
            let msg = format!("{name} needs the cylinder's radius (Q16) and the milling depth (Q1); the cycle is skipped");
            return diags.push(Diagnostic::new(Code::MissingParameter, range, msg));
        };
        if radius <= 1e-9 || depth <= 1e-9 || depth >= radius {
            let msg = format!(
                "{name}: a milling depth of {} on a cylinder of radius {} cuts nothing on it; the cycle is skipped",
                crate::text::num(depth),
                crate::text::num(radius)
            );
            return diags.push(Diagnostic::new(Code::CycleIncomplete, range, msg));
        }
        let step = get(Role::CutDepth).map(f64::abs).filter(|s| *s > 1e-9 && *s < depth);
        if step.is_some_and(|s| depth / s > MAX_PASSES as f64) {
            let msg = format!(
                "{name}: plunges of {} to a depth of {} are too many passes; the cycle is skipped",
                crate::text::num(step.unwrap_or(0.0)),
                crate::text::num(depth)
            );
            return diags.push(Diagnostic::new(Code::CycleIncomplete, range, msg));
        }
        let positive = |v: Option<f64>| v.filter(|f| *f > 0.0);
        let job = CylinderSurface {
            name: name.to_owned(),
            radius,
            depth,
            clear: get(Role::SafetyDistance).map_or(0.0, f64::abs),
            step,
            feeds: (positive(get(Role::PlungeFeed)), positive(get(Role::F))),
            mm: get(Role::Geometry) == Some(1.0),
            width: get(Role::Width).map(f64::abs).filter(|w| *w > 1e-9),
            range,
        };
        self.request = Some(super::Request::CylinderContour { name: contour, job: Box::new(job) });
    }

    /// Before the contour is read: the working plane untilted (returned, to be put back), and
    /// cylindrical interpolation on, the cycle's words read as its contour's.
    pub(super) fn cylinder_surface_begin(
        &mut self,
        job: &CylinderSurface,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) -> Option<Frame> {
        let tilt = self.st.frame;
        if tilt.is_some() {
            self.set_frame(None, sink);
        }
        // Whatever cylindrical interpolation was in force ends: the cycle's cylinder is its own.
        if self.st.cylinder.is_some() {
            self.cylinder_mode(None, job.range, sink, diags);
        }
        self.cylinder_mode(Some(job.radius), job.range, sink, diags);
        // The tilted plane's X along the cylinder's axis (the part's Z): its sense against the
        // developed surface's X (the part's -Z).
        let x_sense = match tilt.map(|f| f.rotation[2][0]) {
            Some(z) if z > 0.5 => -1.0,
            _ => 1.0,
        };
        self.cylinder_contour_words(Some(SurfaceWords { mm: job.mm, x_sense }));
        self.emit(sink, CanonOp::Setting(Setting::MillCycle(Some(job.name.clone()))));
        self.emit(sink, CanonOp::Setting(Setting::CycleSurface(job.radius)));
        // The contour is read at the milling depth: no move of it leaves the cylinder.
        self.st.pos[2] = job.radius - job.depth;
        tilt
    }

    /// The contour read (`shape`, moves in the developed surface's plane): cut at each depth,
    /// then cylindrical interpolation off and the tilted plane `tilt` back.
    pub(super) fn cylinder_surface_cut(
        &mut self,
        job: &CylinderSurface,
        shape: &[crate::canon::Canon],
        tilt: Option<Frame>,
        sink: &mut dyn CanonSink,
        diags: &mut Vec<Diagnostic>,
    ) {
        self.cylinder_contour_words(None);
        // The moves, and the compensation side the contour states (`RL`, `RR`): a contour cut
        // as programmed, its side told (not a slot's centre line).
        let moves: Vec<&CanonOp> = shape
            .iter()
            .map(|c| &c.op)
            .filter(|op| {
                matches!(op, CanonOp::StraightTraverse(_) | CanonOp::StraightFeed(_) | CanonOp::ArcFeed { .. })
                    || (job.width.is_none() && matches!(op, CanonOp::Setting(Setting::CutterComp(_))))
            })
            .collect();
        let end = |op: &CanonOp| match op {
            CanonOp::StraightTraverse(p) | CanonOp::StraightFeed(p) => Some([p[0], p[1]]),
            CanonOp::ArcFeed { first_end, second_end, .. } => Some([*first_end, *second_end]),
            _ => None,
        };
        match moves.iter().position(|m| end(m).is_some()) {
            None => {
                let msg = format!("{}: its contour has no moves; the cycle is skipped", job.name);
                diags.push(Diagnostic::new(Code::CycleIncomplete, job.range, msg));
            }
            Some(i) => {
                let start = end(moves[i]).unwrap_or_default();
                // The side stated on the way to the start applies from the start on.
                let rest: Vec<&CanonOp> = moves[..i].iter().chain(&moves[i + 1..]).copied().collect();
                self.cylinder_passes(job, start, &rest, sink);
            }
        }
        self.cylinder_surface_end(job, tilt, sink, diags);
    }

    /// The cycle's passes: to the contour's start over the set-up clearance, then at each depth
    /// down to the milling depth (`Q10` deeper each) a plunge at `Q11` and the contour at
    /// `Q12`, back up to the clearance between passes and at the end. The plan gives each move
    /// its radial tool axis from the cylinder in force (`Setting::CylinderWrap`).
    fn cylinder_passes(&mut self, job: &CylinderSurface, start: [f64; 2], moves: &[&CanonOp], sink: &mut dyn CanonSink) {
        let over = job.radius + job.clear;
        let mut depths = Vec::new();
        if let Some(step) = job.step {
            let mut d = step;
            while d < job.depth - 1e-9 && depths.len() < MAX_PASSES {
                depths.push(d);
                d += step;
            }
        }
        depths.push(job.depth);
        let p = self.st.pos;
        let to = |x: f64, y: f64, z: f64| [x, y, z, p[3], p[4], p[5]];
        // A slot along one straight line (cycle 28, `Q20` wide): its wall at each depth, the
        // ends half circles about the line's ends, as programmed under cutter compensation
        // (cycle 253's finishing pass, `interp::pocket`), so that the plan reads its width.
        let line = match moves {
            [CanonOp::StraightFeed(t) | CanonOp::StraightTraverse(t)] => Some([t[0], t[1]]),
            _ => None,
        };
        let length = line.map_or(0.0, |e| (e[0] - start[0]).hypot(e[1] - start[1]));
        if let (Some(end), Some(width)) = (line, job.width)
            && length > 1e-6
        {
            let hw = width / 2.0;
            // The left normal of the line, half the width long.
            let n = [-(end[1] - start[1]) / length * hw, (end[0] - start[0]) / length * hw];
            let side = |c: [f64; 2], k: f64| [c[0] + k * n[0], c[1] + k * n[1]];
            for d in depths {
                let z = job.radius - d;
                self.cylinder_plunge(job, to(start[0], start[1], over), z, sink);
                let comp = crate::canon::CompOn { left: true, number: None, radius: None, tip: None };
                self.emit(sink, CanonOp::Setting(Setting::CutterComp(Some(comp))));
                // Counter-clockwise: along the right side, round the far end, back along the
                // left side, round the near end.
                let a = side(start, -1.0);
                self.go_to(sink, to(a[0], a[1], z), true);
                let b = side(end, -1.0);
                self.go_to(sink, to(b[0], b[1], z), true);
                let c = side(end, 1.0);
                self.arc_to(sink, c, end, z, true);
                let e = side(start, 1.0);
                self.go_to(sink, to(e[0], e[1], z), true);
                self.arc_to(sink, a, start, z, true);
                self.emit(sink, CanonOp::Setting(Setting::CutterComp(None)));
                let q = self.st.pos;
                self.go_to(sink, to(q[0], q[1], over), false);
            }
            return;
        }
        for d in depths {
            let z = job.radius - d;
            self.cylinder_plunge(job, to(start[0], start[1], over), z, sink);
            for op in moves {
                match **op {
                    CanonOp::StraightTraverse(t) | CanonOp::StraightFeed(t) => {
                        self.go_to(sink, to(t[0], t[1], z), true);
                    }
                    CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, abc, .. } => {
                        let arc = CanonOp::ArcFeed { first_end, second_end, first_axis, second_axis, rotation, axis_end: z, abc };
                        self.emit(sink, arc);
                        self.st.pos = to(first_end, second_end, z);
                    }
                    CanonOp::Setting(Setting::CutterComp(c)) => self.emit(sink, CanonOp::Setting(Setting::CutterComp(c))),
                    _ => {}
                }
            }
            self.emit(sink, CanonOp::Setting(Setting::CutterComp(None)));
            let q = self.st.pos;
            self.go_to(sink, to(q[0], q[1], over), false);
        }
    }

    /// The cycle's feed in force where it is given and another.
    fn feed_of_cycle(&mut self, f: Option<f64>, sink: &mut dyn CanonSink) {
        if let Some(f) = f.filter(|f| *f != self.st.feed) {
            self.st.feed = f;
            self.emit(sink, CanonOp::SetFeedRate(f));
        }
    }
    /// To `above` (over the set-up clearance), then down to `z` at the plunging feed, the
    /// milling feed set for what follows.
    fn cylinder_plunge(&mut self, job: &CylinderSurface, above: [f64; 6], z: f64, sink: &mut dyn CanonSink) {
        self.go_to(sink, above, false);
        self.feed_of_cycle(job.feeds.0, sink);
        let mut down = above;
        down[2] = z;
        self.go_to(sink, down, true);
        self.feed_of_cycle(job.feeds.1, sink);
    }

    /// Out of the cylinder: the tool to the clearance, cylindrical interpolation off and the
    /// tilted plane back.
    fn cylinder_surface_end(&mut self, job: &CylinderSurface, tilt: Option<Frame>, sink: &mut dyn CanonSink, diags: &mut Vec<Diagnostic>) {
        self.cylinder_mode(None, job.range, sink, diags);
        if tilt.is_some() {
            self.set_frame(tilt, sink);
        }
    }
}

//! Turning: the workingsteps and features of a program that turns about Z (ISO 14649-121
//! operations, ISO 14649-12 features), as a turner names them.
//!
//! A program turns when its dictionary starts in diameter mode (a lathe's X words are
//! diameters), it says `G7`/`DIAMON`, it runs a lathe cycle or synchronised moves or a
//! constant surface speed in the ZX plane, or its every move lies in the ZX plane through the
//! axis (`G18`, Y and the rotary axes never off zero: a lathe's two axes, as LinuxCNC's
//! radius-mode `G70`-`G72` programs are). Known to turn anywhere, it turns throughout:
//! recovery reads it again as a lathe's from its start (`Recoverer::turns_throughout`,
//! `Profile::turns`), so that the facing before a `G76` is no milling. Recovery (`recover.rs`)
//! then segments at each lathe cycle (the interpreter's `Turning` marker, with the values
//! the cycle states: allowances, depth of cut, retract, pitch, thread height, pecks) and
//! keeps each workingstep's feed per revolution, the constant cutting speed's clamp and the
//! pitch of spindle-synchronised moves. One tool's operations run back to back with only rapids
//! between them (LinuxCNC's `G70`-`G72`, which give no marker) are parted on their passes
//! (`separate_operations`). [`recognise`] names each workingstep's operation —
//! from its cycle, else from its moves as CAM posts write them: cuts only across X to the
//! axis at the front are facing, elsewhere parting off; plunges across X and back out
//! grooving; synchronised passes threading; feeds along the axis at X0 drilling; anything
//! else contouring, rough when it cuts in several passes and finish when in one — and builds
//! the features from the finished contour (a finishing pass, or a roughing cycle's last pass
//! moved back by its allowances): each run along Z an outer (or inner) diameter, each run
//! across X a revolved flat, each arc a revolved round, and grooves, threads and holes on the
//! axis from their workingsteps. Diameters throughout; lengths along Z. A contour that runs
//! only towards +Z, its diameters in front of the face, works a part on the counter-spindle
//! (its Z runs into the part towards +Z): it is read mirrored about the face
//! (`works_towards_plus_z`). A drill the program names, fed along Z and run off the centre by
//! less than its radius (an indexable-insert drill opening its hole), drills.
//!
//! As turners work a part with one tool and several: one pass, then the same tool over that
//! stretch at a finer feed, roughs and then finishes (`roughed_then_finished`); a plunge from
//! outside through to the bore the part already has (a named drill's hole, an inside
//! workingstep's wall at that Z) parts off, as a cut-off tool is fed just past a tube's inner
//! diameter (`parted_through_the_bore`); a named grooving tool's pass that turns a profile
//! down along -Z and never climbs back out turns a contour, not a groove (`descends`); and
//! where explicit roughing passes end in a pass along the whole contour that another tool's
//! finish on the same side does not reach all of, the part beyond its reach is that pass's
//! (`profiled_beyond_the_finish`). Under `G41`/`G42` with the nose radius unknown, the path is
//! the nose's only where its smallest arcs turn round outside corners (`nose_arcs`).
//!
//! Facing as a turner reads it: feed moves left forwards off a face cut to the axis (a pull
//! back along +Z, a move across in front of it) cut nothing (`off_the_face`); faces cut in
//! towards the axis and then passes turning behind them with one tool at one feed are two
//! operations (`faced_first`); one pass across that a later pass faces again within 2 mm
//! behind it roughs, leaving that face's stock.
//!
//! Grooving, rough or finish, is named as turners and CAM systems name grooving passes
//! (Sandvik Coromant's grooving guide: "multiple grooving" roughs a groove wider than the
//! insert, a profiling pass then finishes it; the CAM systems' groove roughing and groove
//! finishing operations alike):
//! - **finish**: one plunge at one place along Z to the final depth (the groove as wide as the
//!   tool: roughed and finished in that pass), or passes that follow the groove's flanks and
//!   bottom (profiled from both sides), or a cycle that finishes the flanks and base it states
//!   (SINUMERIK `CYCLE93`), or the finishing cycle (`G70`) a grooving tool the program names
//!   runs outside after its own roughing cycle (`G71`: rough), groove turning;
//! - **rough**: plunges at several places along Z across one groove (a grooving cycle's Z
//!   shift, Fanuc's and Haas's `G75`, or plunges written as moves), whether they overlap or
//!   leave stock between them for a later pass, pecked or not (`classify`: a cycle whose
//!   intent states no edges, plunging at more than one level). A finishing pass after them is
//!   a workingstep of its own where recovery parts it from them (another tool, feed or
//!   operation comment). Not yet: a profile at the plunges' feed right after them stays in
//!   their workingstep, since `CYCLE93` written as moves must part as the cycle does (one
//!   workingstep); reading that cycle as its roughing and its finish would allow both.
//!
//! The passes of one tool over one groove (a plunge, then each flank down to the floor, a
//! rapid and often a finer feed between them), which recovery parts at the feed change, are
//! one grooving workingstep again (`one_groove`), its groove as wide as the flanks' span. A
//! groove on the face, its walls profiled or plunged down to one floor (`face_groove`,
//! `straight_walls`), is grooving, and its feature a face groove (`Turned::FaceGroove`), as are
//! a face grooving tool's plunges along -Z off the axis, each left back up along +Z
//! (`face_plunges`: roughing where they also cut across their floors, the groove then the one
//! the tool's finish makes) and `G74` off the axis: between the diameters plunged.

use super::model::*;
pub use super::turned::{TurnOp, Turned, Turning};
use crate::canon::TurnKind;
use crate::text::num;

/// A feed this many times a workingstep's slowest cutting feed moves the tool through the air.
const AIR_FEED: f64 = 5.0;

/// Within this, two lengths are the same, mm.
const TOL: f64 = 1e-3;

/// A face cut across X this far beyond the program zero is no approach in the air: the part's
/// front lies there, mm.
const FAR_FRONT: f64 = 10.0;

/// A face cut again at most this far behind a first pass across it: that pass left the stock
/// for the finishing one, mm.
const REFACED: f64 = 2.0;

/// Whether a feature kind is a milling one (none of these on a pure lathe program).
pub fn is_milling(kind: &FeatureKind) -> bool {
    !matches!(kind, FeatureKind::Turned(_) | FeatureKind::RoundHole { .. })
}

/// Turning tools whose kind nothing states, from what they do: threading, grooving or
/// parting, drilling on the axis, else a general turning tool.
pub fn infer_tool_kinds(plan: &mut ProcessPlan) {
    for t in plan.tools.iter_mut().filter(|t| t.kind == ToolKind::Unknown || t.kind_source == ToolSource::Inferred) {
        let ops: Vec<TurnOp> =
            plan.workingsteps.iter().filter(|w| w.tool == t.number).filter_map(|w| w.turning.as_ref().and_then(|x| x.operation)).collect();
        let Some(first) = ops.first() else { continue };
        if !ops.iter().all(|o| o == first) && !ops.iter().all(|o| matches!(o, TurnOp::Facing | TurnOp::Contouring)) {
            continue;
        }
        t.kind = match first {
            TurnOp::Threading => ToolKind::ThreadingTool,
            TurnOp::Grooving | TurnOp::PartingOff => ToolKind::GroovingTool,
            TurnOp::Drilling => ToolKind::TwistDrill,
            TurnOp::Facing | TurnOp::Contouring => ToolKind::TurningTool,
        };
        t.kind_source = ToolSource::Inferred;
    }
}

/// Names each turning workingstep's operation and builds the turned features.
/// `remeasure` measures a workingstep again after its moves changed (recovery's `measure`).
pub fn recognise(plan: &mut ProcessPlan, remeasure: fn(&mut Workingstep)) {
    separate_operations(plan, remeasure);
    for ws in &mut plan.workingsteps {
        beyond_the_centre(ws, remeasure);
    }
    group_passes(plan, remeasure);
    one_groove(plan, remeasure);
    plunges_side_by_side(plan, remeasure);
    face_groove_walls(plan, remeasure);
    for ws in &mut plan.workingsteps {
        off_the_face(ws, remeasure);
    }
    // The part's front: the highest face cut (across X), and at least the program zero,
    // where lathe programs put the finished face. (Not a shoulder of the other side's part, on
    // a counter-spindle whose Z runs into it towards +Z.)
    let front = plan
        .workingsteps
        .iter()
        .filter(|w| !works_towards_plus_z(&cuts(w), 0.0))
        .flat_map(|w| w.toolpath.iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid))
        .filter(|m| (m.to[2] - m.from[2]).abs() < TOL)
        .map(|m| m.to[2])
        .fold(0.0, f64::max);
    // The deepest Z each workingstep cuts to: the part's back, as the others tell it.
    let lows: Vec<f64> =
        plan.workingsteps.iter().map(|w| cuts(w).iter().map(|m| m.to[2].min(m.from[2])).fold(f64::INFINITY, f64::min)).collect();
    for (k, ws) in plan.workingsteps.iter_mut().enumerate() {
        let back = lows.iter().enumerate().filter(|&(j, _)| j != k).map(|(_, z)| *z).fold(f64::INFINITY, f64::min);
        let tool = plan.tools.iter().find(|t| t.number == ws.tool);
        let boring = tool.is_some_and(|t| {
            t.kind == ToolKind::BoringTool || t.name.as_deref().is_some_and(|n| n.to_ascii_uppercase().contains("BORING"))
        });
        // A grooving tool the program or the tool table names (not one inferred from what it
        // does): its passes that neither face nor part off cut a groove.
        let grooving = tool.is_some_and(|t| t.kind == ToolKind::GroovingTool && t.kind_source != ToolSource::Inferred);
        // A drill the program or the tool table names, with its diameter.
        let drill = tool.filter(|t| t.kind == ToolKind::TwistDrill && t.kind_source != ToolSource::Inferred).and_then(|t| t.diameter);
        classify(ws, front, back, boring, grooving, drill);
    }
    follow_roughing(plan);
    finished_in_the_bore(plan);
    roughed_then_finished(plan);
    parted_through_the_bore(plan);
    // One pass across the front that a later workingstep faces again a little behind it
    // (another pass, another tool) left stock for that face: it roughs. (Never faced again, it
    // is the part's face, finished unless its operation's comment calls it roughing.) Only on
    // the same part in the same place: the same setup, work offset and spindle (after a flip
    // or on the counter-spindle, a face is another face).
    let place = |w: &Workingstep| (w.setup, w.state.work_offset, w.technology.spindle_id);
    let faces: Vec<Option<(f64, [f64; 2])>> = plan.workingsteps.iter().map(face_cut).collect();
    let places: Vec<_> = plan.workingsteps.iter().map(place).collect();
    for (k, ws) in plan.workingsteps.iter_mut().enumerate() {
        let Some((z, d)) = faces[k] else { continue };
        let Some(t) = ws.turning.as_mut().filter(|t| t.passes == 1 && !t.inside && t.intent.is_none()) else { continue };
        let again = faces[k + 1..]
            .iter()
            .zip(&places[k + 1..])
            .filter(|(_, p)| **p == places[k])
            .any(|(f, _)| f.is_some_and(|(z2, d2)| z2 < z - TOL && z2 > z - REFACED && d2[0] < d[1] && d[0] < d2[1]));
        t.rough |= again;
    }
    // The finished face: where the first facing workingstep's last cut across leaves it (the
    // program zero where none faces); a contour's run along Z in front of it is its lead-in.
    let face = plan
        .workingsteps
        .iter()
        // (A face to the axis: a cut across a shoulder further back, a cut-off tool's chamfer
        // before it parts, is no front.)
        .find(|w| {
            w.turning.as_ref().is_some_and(|t| t.operation == Some(TurnOp::Facing) && !t.inside && t.diameter.is_none_or(|d| d[0] < 0.1))
        })
        .and_then(|w| cuts(w).into_iter().filter(|m| (m.to[2] - m.from[2]).abs() < TOL && m.to[0] < m.from[0]).map(|m| m.to[2]).next_back())
        // None faces: the program zero, where lathe programs put the front, unless the
        // highest cut across X lies far beyond it (more than any approach clearance: a shaft
        // whose zero is at its far end, a post's zero at the chuck): then that is the front.
        .unwrap_or(if front > FAR_FRONT { front } else { 0.0 });
    let mut found: Vec<Vec<(FeatureKind, f64)>> = plan
        .workingsteps
        .iter()
        .map(|ws| features_of(ws, plan.tools.iter().find(|t| t.number == ws.tool).and_then(tool_width), face))
        .collect();
    // Roughing passes machine what the same tool's next finishing pass leaves; where none
    // follows, or nothing separates, the region turned is one general revolution.
    for k in 0..found.len() {
        if !found[k].is_empty() {
            continue;
        }
        let ws = &plan.workingsteps[k];
        let finish = plan.workingsteps[k + 1..]
            .iter()
            .position(|w| {
                w.tool == ws.tool
                    && w.turning.as_ref().is_some_and(|t| !t.rough && t.operation == ws.turning.as_ref().and_then(|t| t.operation))
            })
            .map(|j| found[k + 1 + j].clone())
            .filter(|f| ws.turning.as_ref().is_some_and(|t| t.rough) && !f.is_empty());
        let beyond = || profiled_beyond_the_finish(ws, &plan.workingsteps[k + 1..], face).filter(|f| !f.is_empty());
        found[k] = finish.or_else(beyond).unwrap_or_else(|| unfinished(ws));
    }
    let mut features: Vec<Feature> = Vec::new();
    for (ws, found) in plan.workingsteps.iter_mut().zip(found) {
        let mut ids = Vec::new();
        for (kind, z) in found {
            let same = features.iter_mut().find(|f| f.kind == kind && (f.placement[2] - z).abs() < 0.05);
            let id = match same {
                Some(f) => {
                    if !f.workingsteps.contains(&ws.index) {
                        f.workingsteps.push(ws.index);
                    }
                    f.source = f.source.cover(ws.source);
                    f.lines = (f.lines.0.min(ws.lines.0), f.lines.1.max(ws.lines.1));
                    f.id
                }
                None => {
                    let id = features.len() as u32 + 1;
                    let depth = match &kind {
                        FeatureKind::Turned(Turned::Diameter { length, .. } | Turned::Thread { length, .. }) => *length,
                        _ => 0.0,
                    };
                    features.push(Feature {
                        id,
                        kind,
                        placement: [0.0, 0.0, z],
                        depth,
                        top_inferred: false,
                        workingsteps: vec![ws.index],
                        source: ws.source,
                        lines: ws.lines,
                        sources: Sources::default(),
                        centre_path: None,
                        // On the axis of revolution (Z), the plan's default.
                        axis: None,
                        ref_direction: None,
                        wrap: None,
                    });
                    id
                }
            };
            ids.push(id);
        }
        ws.feature = ids.first().copied();
    }
    plan.features = features;
    clear_notes(plan);
}

/// Recognition's own notes, read above and no value of the plan: a plan read back from STEP-NC
/// or the store cannot carry them, and must equal the one recovered. So are the contour blocks
/// a cycle names (for pairing a finish with its roughing).
fn clear_notes(plan: &mut ProcessPlan) {
    for t in plan.workingsteps.iter_mut().filter_map(|w| w.turning.as_mut()) {
        t.mirrored = false;
        if let Some(i) = t.intent.as_mut() {
            i.contour = None;
        }
    }
}

/// One pass along a stretch, then straight after it the same tool's pass over that stretch at
/// a finer feed per revolution: the first roughed and the second finishes, as turners rough
/// and finish with one tool (a finishing feed below the roughing one, Sandvik Coromant's
/// turning guide). On the finishing pass's side: a pass at a diameter inside the bore the
/// same tool then finishes roughed that bore (an outside pass there would leave it nothing).
fn roughed_then_finished(plan: &mut ProcessPlan) {
    for k in 1..plan.workingsteps.len() {
        let (done, rest) = plan.workingsteps.split_at_mut(k);
        let (a, b) = (&mut done[k - 1], &rest[0]);
        let explicit = |w: &Workingstep| {
            w.turning.as_deref().filter(|t| t.intent.is_none() && !t.rough && t.operation == Some(TurnOp::Contouring)).cloned()
        };
        let (Some(ta), Some(tb)) = (explicit(a), explicit(b)) else { continue };
        let finer = matches!((ta.feed_per_rev, tb.feed_per_rev), (Some(fa), Some(fb)) if fb < fa - 1e-9);
        let (Some(za), Some(zb)) = (ta.z, tb.z) else { continue };
        let overlap = za[1].min(zb[1]) - za[0].max(zb[0]);
        if a.tool != b.tool || ta.passes != 1 || !finer || overlap < 0.8 * (za[1] - za[0]) || za[1] - za[0] < 0.5 {
            continue;
        }
        let inside = tb.inside && !ta.inside && matches!((ta.diameter, tb.diameter), (Some(da), Some(db)) if da[1] < db[1] - TOL);
        if let Some(t) = a.turning.as_mut() {
            t.rough = true;
            t.inside |= inside;
        }
    }
}

/// A plunge from outside that reaches the bore the part already has there parts it off: a tube,
/// or a part drilled or bored through behind the cut, falls off once the tool passes its inner
/// diameter, and shops and posts feed the cut-off tool only just past it (Sandvik Coromant's
/// parting-off guide: on tubes the insert feeds through the wall, past the inner diameter, not
/// to the centre). The bore: the hole a named drill of known diameter drilled past that Z, or
/// the largest radius an inside workingstep cut at that Z, before it on the same part in the
/// same place (setup, work offset, spindle). A groove whose bottom stays outside the bore is
/// still a groove. And one plunge at one Z by a tool the program names a cut-off or parting
/// tool parts off where it reaches the bore known before it or the tube's bore a later face at
/// that Z tells.
fn parted_through_the_bore(plan: &mut ProcessPlan) {
    let place = |w: &Workingstep| (w.setup, w.state.work_offset, w.technology.spindle_id);
    for k in 0..plan.workingsteps.len() {
        let ws = &plan.workingsteps[k];
        let Some(t) = ws.turning.as_deref().filter(|t| t.operation == Some(TurnOp::Grooving) && !t.inside) else { continue };
        let cuts = cuts(ws);
        // The plunge's bottom and where along Z it lies, and where it came in from.
        let Some(bottom) = cuts.iter().min_by(|a, b| a.to[0].total_cmp(&b.to[0])) else { continue };
        let (x, z) = (bottom.to[0], bottom.to[2]);
        let outer = cuts.iter().map(|m| m.from[0].max(m.to[0])).fold(f64::NEG_INFINITY, f64::max);
        if x < 0.05 || t.intent.as_ref().and_then(|i| i.span).is_some() {
            continue;
        }
        let bore = plan.workingsteps[..k]
            .iter()
            .filter(|w| place(w) == place(ws))
            .filter_map(|w| bore_at(w, z, plan.tools.iter().find(|tl| tl.number == w.tool)))
            .fold(f64::NEG_INFINITY, f64::max);
        // A single plunge at one place along Z by a tool the program names a cut-off or
        // parting tool (`(CUT OFF AT .395)`, `PARTING`, German Abstechen): it parts the part off,
        // through a tube's wall to its bore, which no workingstep before it need have cut.
        let tool = plan.tools.iter().find(|tl| tl.number == ws.tool);
        let named = tool.and_then(|tl| tl.name.as_deref()).is_some_and(|n| {
            let n: String = n.to_ascii_uppercase().chars().filter(|c| c.is_ascii_alphanumeric()).collect();
            ["CUTOFF", "PARTOFF", "PARTING", "ABSTECH"].iter().any(|k| n.contains(k))
        });
        let one_plunge = runs(ws).len() == 1 && cuts.iter().all(|m| (m.to[2] - z).abs() < TOL && (m.from[2] - z).abs() < TOL);
        // Named so, it still parts off only where it reaches the bore: one known before it, or
        // the tube's, which the part's new face tells when a later workingstep in the same place
        // faces it at that Z in to a diameter short of the axis that the plunge came within the
        // face's clearance of (0.5 mm on the radius; Lynx 300 O2700: cut off to Ø1.4 in, the
        // face then to Ø1.375 in). A cut-off blade that stops in the wall of a solid bar cuts a
        // groove (shops groove with the cut-off blade they part with).
        let tube_face = plan.workingsteps[k + 1..].iter().filter(|w| place(w) == place(ws)).any(|w| {
            self::cuts(w).iter().any(|m| {
                let inner = m.from[0].min(m.to[0]);
                straight_across(m) && (m.to[2] - z).abs() < TOL && inner > 0.05 && x <= inner + 0.5 + TOL
            })
        });
        let through = (bore > 0.05 && x <= bore + TOL) || tube_face;
        if (bore > 0.05 && x <= bore + TOL && outer > bore + 0.5) || (named && one_plunge && through) {
            if let Some(t) = plan.workingsteps[k].turning.as_mut() {
                t.operation = Some(TurnOp::PartingOff);
                t.rough = false;
            }
        }
    }
}

/// A finishing contour of another tool run where an inside workingstep before it roughed the
/// bore (or a drill drilled it), on the same part in the same place: where each of its cuts
/// along Z lies in the bore left at its Z or at most 0.5 mm beyond it on the radius (the
/// finishing allowance the roughing left on the wall; the wall itself is thicker), it finishes
/// that bore, as a turner reads a finishing bar run after the boring passes (explicit moves
/// after a tool change, with nothing else telling its side: an inside contour finished from
/// the mouth steps down to smaller diameters as an outside one of a part larger at its front
/// does). Only where every cut along Z is so, at least one runs 1 mm along Z, and the outside
/// is turned beside one of them (`walled`), and the pass is a boring tool's, cut towards the
/// chuck under G41, or left towards the axis (`left_inward`).
fn finished_in_the_bore(plan: &mut ProcessPlan) {
    let place = |w: &Workingstep| (w.setup, w.state.work_offset, w.technology.spindle_id);
    for k in 1..plan.workingsteps.len() {
        let ws = &plan.workingsteps[k];
        let Some(t) = ws.turning.as_deref() else { continue };
        if t.inside || t.rough || t.operation != Some(TurnOp::Contouring) || t.intent.is_some() {
            continue;
        }
        let cuts = cuts(ws);
        let along: Vec<&Move> = cuts.iter().filter(|m| (m.to[0] - m.from[0]).abs() < TOL && (m.to[2] - m.from[2]).abs() > TOL).collect();
        if !along.iter().any(|m| (m.to[2] - m.from[2]).abs() >= 1.0) || cuts.iter().any(|m| m.from[0].min(m.to[0]) < 0.05) {
            continue;
        }
        let before: Vec<&Workingstep> = plan.workingsteps[..k].iter().filter(|w| w.tool != ws.tool && place(w) == place(ws)).collect();
        let in_bore = |m: &Move| {
            // Halfway along the cut: the bore the workingsteps before left there.
            let z = (m.from[2] + m.to[2]) / 2.0;
            let bore = before
                .iter()
                .filter_map(|w| bore_at(w, z, plan.tools.iter().find(|tl| tl.number == w.tool)))
                .fold(f64::NEG_INFINITY, f64::max);
            bore > 0.05 && m.from[0] <= bore + 0.5 + TOL
        };
        // And the part's outside known there: a turning workingstep on the outside cut along Z
        // over the same Z at a diameter at least 1 mm larger on the radius (the pass lies between
        // the bore and the outside wall; a bore known only from a workingstep itself misread,
        // with no outside beside it, tells nothing).
        let others: Vec<&Workingstep> = plan.workingsteps.iter().filter(|w| w.tool != ws.tool && place(w) == place(ws)).collect();
        let walled = |m: &Move| {
            let z = (m.from[2] + m.to[2]) / 2.0;
            others.iter().filter(|w| w.turning.as_deref().is_some_and(|t| !t.inside && t.operation == Some(TurnOp::Contouring))).any(|w| {
                self::cuts(w).iter().any(|c| {
                    (c.to[0] - c.from[0]).abs() < TOL
                        && c.from[2].min(c.to[2]) < z
                        && c.from[2].max(c.to[2]) > z
                        && c.from[0] > m.from[0] + 1.0
                })
            })
        };
        // And the pass works from inside: run by a boring tool, or left towards the axis as a
        // boring bar leaves the wall it cut (`left_inward`). An outside finish of a thin sleeve
        // lies within 0.5 mm of its bore too, and leaves outwards.
        let tool = plan.tools.iter().find(|tl| tl.number == ws.tool);
        let boring = tool.is_some_and(|t| {
            t.kind == ToolKind::BoringTool || t.name.as_deref().is_some_and(|n| n.to_ascii_uppercase().contains("BORING"))
        });
        // Or cut towards the chuck under G41: with the tool moving towards -Z, the tool nose
        // radius compensation on its left keeps it on the axis side of the contour, as in
        // boring (G42 for turning outside: Fanuc lathe operator's manual, tool nose radius
        // compensation; Smid, CNC Programming Handbook, the same on either turret).
        let comp = &ws.state.cutter_comp;
        let bored_left = !comp.is_empty() && comp.iter().all(|c| c.left) && along.iter().all(|m| m.to[2] < m.from[2] && m.to[0] > 0.0);
        if along.iter().all(|m| in_bore(m)) && along.iter().any(|m| walled(m)) && (boring || bored_left || left_inward(ws)) {
            if let Some(t) = plan.workingsteps[k].turning.as_mut() {
                t.inside = true;
            }
        }
    }
}

/// The radius of the bore a workingstep leaves at `z`: a drill's (of known diameter) where it
/// drilled past `z`, or the largest radius an inside workingstep's cuts along Z reach at `z`.
fn bore_at(w: &Workingstep, z: f64, tool: Option<&Tool>) -> Option<f64> {
    let t = w.turning.as_deref()?;
    let cuts = cuts(w);
    match t.operation {
        Some(TurnOp::Drilling) => {
            let d = tool.filter(|tl| tl.kind == ToolKind::TwistDrill).and_then(|tl| tl.diameter)?;
            let deepest = cuts.iter().map(|m| m.to[2]).fold(f64::INFINITY, f64::min);
            (deepest < z - TOL).then_some(d / 2.0)
        }
        Some(_) if t.inside => cuts
            .iter()
            .filter(|m| m.arc.is_none() && (m.to[2] - m.from[2]).abs() > TOL)
            .filter(|m| m.from[2].min(m.to[2]) < z - TOL && m.from[2].max(m.to[2]) >= z)
            .map(|m| m.from[0] + (m.to[0] - m.from[0]) * (z - m.from[2]) / (m.to[2] - m.from[2]))
            .reduce(f64::max),
        _ => None,
    }
}

/// Explicit roughing passes of one tool whose last pass runs the whole contour (a profile
/// pass), finished afterwards on the same side by another tool that does not reach all of it
/// (a finishing boring bar run to Z-22 in a bore roughed to its floor at Z-25.6): where the
/// finish does not reach, the part is as that profile pass left it, so its features there are
/// the part's (a diameter lying wholly beyond the finish's reach, a face behind it). Where the
/// finish reaches, the finish gives the part. With no finish on that side at all, the whole
/// profile (or the operation's one pass) is the shape the program leaves. None where several
/// passes end in no pass along the whole contour (straight roughing passes each leave only a
/// step of it), or where nothing lies beyond the finish.
fn profiled_beyond_the_finish(ws: &Workingstep, later: &[Workingstep], face: f64) -> Option<Vec<(FeatureKind, f64)>> {
    let t = ws.turning.as_deref().filter(|t| t.rough && t.intent.is_none() && t.operation == Some(TurnOp::Contouring))?;
    let runs = runs(ws);
    let [.., last] = runs.as_slice() else { return None };
    let length = t.z.map_or(0.0, |z| z[1] - z[0]);
    // The last pass along the whole contour, or the operation's one pass (it is all it cut).
    if runs.len() > 1 && !whole_contour(last, length) {
        return None;
    }
    // The deepest Z a later finishing workingstep on the same side reaches; with none, the
    // whole profile is the shape the program leaves. Only a finish on the same part in the
    // same place counts (the same setup, work offset and spindle, as for a face cut again):
    // after a flip or on another offset it finishes another side of the part.
    let place = |w: &Workingstep| (w.setup, w.state.work_offset, w.technology.spindle_id);
    let finishes: Vec<Move> = later
        .iter()
        .filter(|w| w.tool != ws.tool && place(w) == place(ws))
        .filter(|w| w.turning.as_ref().is_some_and(|l| !l.rough && l.inside == t.inside && l.operation == Some(TurnOp::Contouring)))
        .flat_map(cuts)
        .collect();
    let reach = finishes.iter().map(|m| m.to[2].min(m.from[2])).reduce(f64::min).unwrap_or(f64::INFINITY);
    // Where the finish reaches along Z, it makes the part only where it cuts at the wall or
    // into it: a bore finished at Ø39.8 past a recess roughed to Ø41 runs through the recess's
    // air and leaves its wall as the roughing profile cut it (inside a larger diameter than
    // its own; outside a smaller one), 0.05 mm on the radius allowed.
    let cut_by_finish = |diameter: f64, top: f64, length: f64| {
        // Halfway along the stretch of the wall the finish reaches.
        let z = ((top - length).max(reach) + top) / 2.0;
        finishes.iter().filter(|m| (m.from[2] - z) * (m.to[2] - z) <= 0.0 && (m.to[2] - m.from[2]).abs() > TOL).any(|m| {
            let x = m.from[0] + (m.to[0] - m.from[0]) * (z - m.from[2]) / (m.to[2] - m.from[2]);
            if t.inside { 2.0 * x >= diameter - 0.1 } else { 2.0 * x <= diameter + 0.1 }
        })
    };
    let nose = nose_arcs(ws, t, last);
    let beyond = contour_profile_features(t, last, (0.0, 0.0), nose, face).into_iter().filter(|(k, z)| match k {
        FeatureKind::Turned(Turned::Diameter { length, diameter, .. }) => {
            z - length < reach - TOL && (*z <= reach + TOL || !cut_by_finish(*diameter, *z, *length))
        }
        FeatureKind::Turned(Turned::RevolvedFlat { .. }) => *z < reach - TOL,
        _ => false,
    });
    Some(beyond.collect())
}

/// What a workingstep takes from the roughing before it: a finishing cycle a grooving tool runs
/// finishes a groove only where that tool roughed it with the roughing cycle before (it finishes
/// that cycle's contour; after another tool's roughing it finishes that contour), and a
/// finishing pass is inside where the same tool's roughing was.
fn follow_roughing(plan: &mut ProcessPlan) {
    // A finishing cycle a grooving tool runs finishes a groove only where that tool roughed it
    // with the roughing cycle before (it finishes that cycle's contour); after another tool's
    // roughing it finishes that contour.
    for k in 0..plan.workingsteps.len() {
        let (done, rest) = plan.workingsteps.split_at_mut(k);
        let ws = &mut rest[0];
        let kind = |w: &Workingstep| w.turning.as_ref().and_then(|t| t.intent.as_ref()).and_then(|i| i.kind);
        if kind(ws) != Some(TurnKind::Finish) || ws.turning.as_ref().and_then(|t| t.operation) != Some(TurnOp::Grooving) {
            continue;
        }
        let roughed = roughing_finished(done, ws, &[TurnKind::RoughTurn]);
        let grooved = roughed.is_some_and(|w| w.tool == ws.tool && w.turning.as_ref().and_then(|t| t.operation) == Some(TurnOp::Grooving));
        if let Some(t) = ws.turning.as_mut().filter(|_| !grooved) {
            t.operation = Some(TurnOp::Contouring);
        }
    }
    // A finishing cycle that repeats a face roughing cycle's contour finishes it (Fanuc's G70
    // runs the contour blocks its P and Q name, once as written: the operator's manual's
    // "finishing after rough cutting by G71, G72 or G73"), a face profile written from the
    // outside in: facing, as the roughing is, where that contour is mostly across X (a
    // spigot's or a chamfer's run along Z in it is part of the face profile). Not to the
    // axis needed: a face may stop at a centre hole or a bore. A G70 over a G71's contour
    // after a later G72 finishes the G71's.
    for k in 1..plan.workingsteps.len() {
        let (done, rest) = plan.workingsteps.split_at_mut(k);
        let ws = &mut rest[0];
        let kind = |w: &Workingstep| w.turning.as_ref().and_then(|t| t.intent.as_ref()).and_then(|i| i.kind);
        if kind(ws) != Some(TurnKind::Finish) || ws.turning.as_ref().and_then(|t| t.operation) != Some(TurnOp::Contouring) {
            continue;
        }
        let roughed = roughing_finished(done, ws, &[TurnKind::RoughTurn, TurnKind::RoughFace]);
        if roughed.is_some_and(|w| kind(w) == Some(TurnKind::RoughFace))
            && mostly_across(&cuts(ws))
            && let Some(t) = ws.turning.as_mut()
        {
            t.operation = Some(TurnOp::Facing);
        }
    }
    // A finishing pass is inside where the same tool's roughing was.
    for k in 1..plan.workingsteps.len() {
        let (done, rest) = plan.workingsteps.split_at_mut(k);
        let ws = &mut rest[0];
        let inside = done.iter().rev().find(|w| w.tool == ws.tool).and_then(|w| w.turning.as_ref()).is_some_and(|t| t.inside);
        if let Some(t) = ws.turning.as_mut()
            && !t.rough
            && t.operation == Some(TurnOp::Contouring)
            && inside
        {
            t.inside = true;
        }
    }
}

/// The roughing cycle (of the kinds `kinds`) among the workingsteps `done` before it whose
/// contour the finishing cycle `ws` finishes: the one that names the same contour blocks
/// (Fanuc's G70 runs the blocks its P and Q name, those a G71, G72 or G73 roughed), the latest
/// such; where the finish names none (a named cycle's finish), the latest roughing.
fn roughing_finished<'w>(done: &'w [Workingstep], ws: &Workingstep, kinds: &[TurnKind]) -> Option<&'w Workingstep> {
    let kind = |w: &Workingstep| w.turning.as_ref().and_then(|t| t.intent.as_ref()).and_then(|i| i.kind);
    let contour = |w: &Workingstep| w.turning.as_ref().and_then(|t| t.intent.as_ref()).and_then(|i| i.contour);
    let mut roughings = done.iter().rev().filter(|w| kind(w).is_some_and(|k| kinds.contains(&k)));
    match contour(ws) {
        Some(blocks) => roughings.find(|w| contour(w) == Some(blocks)),
        None => roughings.next(),
    }
}

/// A workingstep that cuts beyond the centre line (a bar lathe or a rear tool post writing X
/// negative, a tool behind the centre) works there: its cuts lie at X at or below 0. Its diameters are those of the same cuts
/// mirrored about the axis, and so are its moves in the plan; inside or outside is then
/// read on the mirrored moves, and the program's X allowance points the other way.
fn beyond_the_centre(ws: &mut Workingstep, remeasure: fn(&mut Workingstep)) {
    if ws.turning.is_none() {
        return;
    }
    let cuts = cuts(ws);
    let xs = cuts.iter().flat_map(|m| [m.from[0], m.to[0]]);
    let (xmin, xmax) = xs.fold((0.0f64, 0.0f64), |(a, b), x| (a.min(x), b.max(x)));
    if cuts.is_empty() || xmin > -TOL || xmax > TOL {
        return;
    }
    if let Some(t) = ws.turning.as_mut() {
        t.mirrored = true;
    }
    // Plus zero: a point on the axis stays at X 0, not -0 (which reads back as 0).
    let flip = |p: P3| [-p[0] + 0.0, p[1], p[2]];
    let moves: super::Toolpath = ws
        .toolpath
        .iter()
        .map(|m| Move {
            from: flip(m.from),
            to: flip(m.to),
            arc: m.arc.map(|a| ArcGeometry { center: flip(a.center), axis: [a.axis[0], -a.axis[1] + 0.0, -a.axis[2] + 0.0], ..a }),
            ..m
        })
        .collect();
    ws.toolpath = moves;
    remeasure(ws);
}

/// A cut across X to the axis faces the part at its Z: in front of that face and within the
/// radius it faced there is no material left. Feed moves that follow it there (a pull back
/// along +Z off the face at the cutting feed, `G1 X-1.6` then `Z2.1`, a move across in front
/// of it on the way to the next operation) cut nothing: they leave the face, as a retract
/// does, written as moves or as a cycle's (a `G94` box cycle's feed back along +Z), alike.
fn off_the_face(ws: &mut Workingstep, remeasure: fn(&mut Workingstep)) {
    let turns = ws.turning.as_deref().is_some_and(|t| t.pitch.is_none() && t.intent.as_ref().is_none_or(|i| i.pitch.is_none()));
    if !turns || !ws.holes.is_empty() {
        return;
    }
    let moves: Vec<Move> = ws.toolpath.iter().collect();
    let mut off: Vec<usize> = Vec::new();
    for (i, m) in moves.iter().enumerate() {
        // A move already found leaving an earlier face cuts nothing, a face cut among them
        // too: each move is looked at once (linear on a program of many face passes).
        if off.last().is_some_and(|&j| i <= j) {
            continue;
        }
        let across = m.arc.is_none() && (m.to[2] - m.from[2]).abs() < TOL;
        let to_axis = m.to[0].abs() < 0.05 || m.to[0] * m.from[0] < 0.0;
        if !is_cut(m) || !across || !to_axis || m.from[0].abs() < 0.5 {
            continue;
        }
        let (zf, reach) = (m.to[2], m.from[0].abs());
        // The tool leaves the face forwards (along +Z) first; a pass back out along the face
        // it cut is no leaving.
        if !moves.get(i + 1).is_some_and(|n| is_cut(n) && n.to[2] > zf + TOL) {
            continue;
        }
        for (j, n) in moves.iter().enumerate().skip(i + 1) {
            let in_front = n.from[2].min(n.to[2]) > zf - TOL && n.from[0].abs().max(n.to[0].abs()) <= reach + TOL;
            if !is_cut(n) || !in_front {
                break;
            }
            off.push(j);
        }
    }
    if off.is_empty() {
        return;
    }
    for j in off {
        ws.toolpath.set_phase(j, Phase::Retract);
    }
    remeasure(ws);
}

/// The cuts of a workingstep as runs between rapids: the toolpath index of each run's first
/// and past its last cut.
fn run_spans(ws: &Workingstep) -> Vec<(usize, usize)> {
    let mut out: Vec<(usize, usize)> = Vec::new();
    let mut open = false;
    for (i, m) in ws.toolpath.iter().enumerate() {
        if m.kind == MoveKind::Rapid || m.phase != Phase::Cut {
            open = false;
            continue;
        }
        match out.last_mut() {
            Some(r) if open => r.1 = i + 1,
            _ => out.push((i, i + 1)),
        }
        open = true;
    }
    out
}

/// One tool's operations run back to back at one feed and speed with nothing between them
/// but rapids (LinuxCNC's `G70`, `G71` and `G72` one after another over a subroutine's
/// profile, as its manual shows them; a post's roughing then finishing at one feed). A turner
/// reads where one ends from the passes: a pass along the whole contour ends an operation (a
/// finish, or the roughing cycle's last pass over the stock it leaves), so straight passes
/// after one begin another (roughing again, along or across); and a pass along the whole
/// contour after the roughing's passes along parts of it (its pockets), or after its own
/// last pass along the contour, is the finish.
/// Read on the moves alone, so that a program and its translation, the cycle written as moves,
/// part them alike.
fn separate_operations(plan: &mut ProcessPlan, remeasure: fn(&mut Workingstep)) {
    let explicit = |w: &Workingstep| {
        w.turning.as_deref().is_some_and(|t| t.intent.is_none() && t.cycle.is_none() && t.pitch.is_none()) && w.holes.is_empty()
    };
    let mut out: Vec<Workingstep> = Vec::new();
    for ws in std::mem::take(&mut plan.workingsteps) {
        if !explicit(&ws) {
            out.push(ws);
            continue;
        }
        let spans = run_spans(&ws);
        let moves: Vec<Move> = ws.toolpath.iter().collect();
        let way = |&(a, b): &(usize, usize)| pass_way(&moves[a..b]);
        // Whether run `k` follows the whole contour of the operation begun at run `from`: a
        // pass along the profile over most of the length and half the depth the operation cut
        // (turning), or most of the depth and half the length (facing).
        let full = |from: usize, k: usize| {
            let span = |a: usize, b: usize, axis: usize| {
                let cut = moves[a..b].iter().filter(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid);
                let v = cut.flat_map(|m| [m.from[axis], m.to[axis]]);
                let (lo, hi) = v.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x), h.max(x)));
                hi - lo
            };
            let (a, b) = (spans[from].0, spans[k].1);
            let (run_a, run_b) = spans[k];
            let share = |axis: usize| span(run_a, run_b, axis) / span(a, b, axis).max(TOL);
            way(&spans[k]) == Way::Profile && ((share(2) >= 0.8 && share(0) >= 0.5) || (share(0) >= 0.8 && share(2) >= 0.5))
        };
        // Where each later operation begins: after the run before it ends.
        let mut cuts_at: Vec<usize> = Vec::new();
        let mut from = 0;
        // Passes across the front first, then passes along the part behind that face: the
        // facing, then the turning.
        let faces = faced_first(&moves, &spans);
        if faces > 0 {
            cuts_at.push(spans[faces - 1].1);
            from = faces;
        }
        for k in from + 1..spans.len() {
            let now = way(&spans[k]);
            // Straight passes after a pass along the whole contour: roughing again.
            let after_contour = now != Way::Profile && full(from, k - 1);
            // A second pass along the contour after the roughing's passes: the finish. So is a
            // pass along the whole contour after straight passes along Z only (roughing passes,
            // each a stretch of the stock, then the profile at the same feed, as a simulator's
            // sample or an operator writes them, the last pass of the workingstep along it; not a
            // groove's plunges across, which the profile after them finishes within their
            // workingstep, as `CYCLE93` does).
            // (Followed by another pass along the whole contour, it is the roughing's last pass
            // over the stock it leaves, as LinuxCNC's `G71` ends before its `G70`.)
            // A roughing cycle's last pass runs through where its passes along Z ended (they stop
            // at the contour moved out by the allowance, which that pass follows); a finishing
            // pass runs clear of them, by the allowance they left.
            let clear = |k: usize| {
                let profile = &moves[spans[k].0..spans[k].1];
                (from..k).all(|j| main_cut(&moves[spans[j].0..spans[j].1]).is_some_and(|(_, m)| off_the_path(profile, m.to) > 0.05))
            };
            let straight_before =
                || (from..k).all(|j| way(&spans[j]) == Way::Along) && !(k + 1..spans.len()).any(|j| full(from, j)) && clear(k);
            // The cheap tests first: most spans are no pass along the whole contour, and the
            // look back and ahead is quadratic in the passes.
            let finish = k - from >= 2 && full(from, k) && (way(&spans[k - 1]) == Way::Profile || straight_before());
            if after_contour || finish {
                cuts_at.push(spans[k - 1].1);
                from = k;
            }
        }
        if cuts_at.is_empty() {
            out.push(ws);
            continue;
        }
        let mut bounds = vec![0];
        bounds.extend(cuts_at);
        bounds.push(moves.len());
        for w in bounds.windows(2) {
            let (a, b) = (w[0], w[1]);
            let mut piece = ws.clone();
            let first_cut = moves[a..b].iter().position(|m| m.phase == Phase::Cut).map_or(a, |i| a + i);
            piece.toolpath = moves[a..b]
                .iter()
                .enumerate()
                .map(|(i, m)| Move { phase: if a > 0 && a + i < first_cut { Phase::Approach } else { m.phase }, ..*m })
                .collect();
            let inside = |at: u32| (at as usize) >= a && ((at as usize) < b || b == moves.len());
            piece.state.stops = ws.state.stops.iter().filter(|s| inside(s.at)).map(|s| Stop { at: s.at - a as u32, ..*s }).collect();
            piece.state.dwells = ws.state.dwells.iter().filter(|d| inside(d.at)).map(|d| Dwell { at: d.at - a as u32, ..*d }).collect();
            let lines = moves[a..b].iter().map(|m| m.line);
            let (lo, hi) = lines.fold((u32::MAX, 0), |(l, h), x| (l.min(x), h.max(x)));
            if hi > 0 {
                piece.lines = (if a == 0 { ws.lines.0 } else { lo }, if b == moves.len() { ws.lines.1 } else { hi });
            }
            piece.state.optional_lines.retain(|l| *l >= piece.lines.0 && *l <= piece.lines.1);
            let mut feeds: Vec<f64> = Vec::new();
            for m in moves[a..b].iter().filter(|m| m.kind != MoveKind::Rapid) {
                if !feeds.iter().any(|f| (f - m.feed).abs() < 1e-9) {
                    feeds.push(m.feed);
                }
            }
            if !feeds.is_empty() {
                piece.technology.feeds = feeds;
            }
            remeasure(&mut piece);
            out.push(piece);
        }
    }
    for (k, ws) in out.iter_mut().enumerate() {
        ws.index = k as u32 + 1;
    }
    plan.workingsteps = out;
}

/// How far a point (X radius, Z) lies from a path of moves in the ZX plane: from the nearest
/// straight move, or the circle of the nearest arc.
fn off_the_path(path: &[Move], p: P3) -> f64 {
    let d = |m: &Move| match m.arc {
        Some(a) => ((p[0] - a.center[0]).hypot(p[2] - a.center[2]) - (m.from[0] - a.center[0]).hypot(m.from[2] - a.center[2])).abs(),
        None => {
            let (dx, dz) = (m.to[0] - m.from[0], m.to[2] - m.from[2]);
            let len2 = dx * dx + dz * dz;
            let t = if len2 > 0.0 { (((p[0] - m.from[0]) * dx + (p[2] - m.from[2]) * dz) / len2).clamp(0.0, 1.0) } else { 0.0 };
            (p[0] - m.from[0] - t * dx).hypot(p[2] - m.from[2] - t * dz)
        }
    };
    path.iter().map(d).fold(f64::INFINITY, f64::min)
}

/// How many of the first runs face the front before the rest turn behind it (0 where they do
/// not): runs across X (`Way::Across`) in towards the axis, then runs that are not, whose
/// cuts reach the last face's Z or lie behind it, as a turner faces a part and then turns it
/// with one tool at one feed (`G1 X23` at Z2, Z1 and Z0.1, then a chamfer pass from Z0). A
/// groove's plunges lie between its flanks, not in front of the profile: they do not part.
fn faced_first(moves: &[Move], spans: &[(usize, usize)]) -> usize {
    let way = |&(a, b): &(usize, usize)| pass_way(&moves[a..b]);
    let n = spans.iter().take_while(|s| way(s) == Way::Across).count();
    if n == 0 || n == spans.len() {
        return 0;
    }
    let across = |m: &&Move| straight_across(m);
    let cut = |m: &&Move| is_cut(m);
    let Some(face) = moves[spans[n - 1].0..spans[n - 1].1].iter().filter(cut).filter(across).map(|m| m.to[2]).next_back() else {
        return 0;
    };
    // Each face cut in towards the axis, from the stock's outside.
    let inwards = spans[..n].iter().all(|&(a, b)| moves[a..b].iter().filter(cut).filter(across).all(|m| m.to[0].abs() < m.from[0].abs()));
    if !inwards {
        return 0;
    }
    // Every later cut reaches the face or lies behind it (a lead-in along Z from in front of
    // it ends there), and one after its run's lead-in runs along the part behind it (a chamfer
    // or a diameter, not a pass across that only clears a corner). A run's first cut along Z
    // is a lead-in only where it starts in front of the face: one that starts at the face or
    // behind it turns a diameter (`G0 X0.309` after the face at Z0, then `G1 Z-0.12`).
    let later = || spans[n..].iter().flat_map(|&(a, b)| moves[a..b].iter()).filter(cut);
    let behind = later().all(|m| m.from[2].min(m.to[2]) <= face + TOL);
    let along = |m: &Move| m.arc.is_none() && (m.to[0] - m.from[0]).abs() < TOL && m.from[2] > face + TOL;
    let past_lead_in = spans[n..].iter().flat_map(|&(a, b)| {
        let run = moves[a..b].iter().filter(cut);
        let lead = run.clone().next().is_some_and(along);
        run.skip(usize::from(lead))
    });
    let turns = past_lead_in.into_iter().any(|m| (m.to[2] - m.from[2]).abs() > 0.5 && m.from[2].min(m.to[2]) < face - 0.5);
    if behind && turns { n } else { 0 }
}

/// The way a pass runs: straight (along or across) where that way makes most of its length,
/// its lead-in and pull-out short; else along the profile.
fn pass_way(run: &[Move]) -> Way {
    let len = |m: &Move| (m.to[0] - m.from[0]).hypot(m.to[2] - m.from[2]);
    let total: f64 = run.iter().map(len).sum();
    let share = |w: Way| {
        let straight = |m: &&Move| {
            m.arc.is_none()
                && match w {
                    Way::Across => (m.to[2] - m.from[2]).abs() < TOL,
                    _ => (m.to[0] - m.from[0]).abs() < TOL,
                }
        };
        run.iter().filter(straight).map(len).sum::<f64>()
    };
    match main_cut(run) {
        Some((w, _)) if share(w) >= 0.8 * total => w,
        _ => Way::Profile,
    }
}

/// How a pass cuts: across the axis (X, a face), along it (Z), or along a profile.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Way {
    Across,
    Along,
    Profile,
}

/// The longest straight cut of a run of moves, and which way it runs. A pass is straight
/// when that way makes most of its cutting length (the lead-in and the pull-out at their own
/// feeds are short) and it has no arc and few moves.
fn main_cut(run: &[Move]) -> Option<(Way, Move)> {
    let len = |m: &Move| (m.to[0] - m.from[0]).hypot(m.to[2] - m.from[2]);
    let total: f64 = run.iter().map(len).sum();
    let way = |m: &Move| {
        if m.arc.is_some() {
            Way::Profile
        } else if (m.to[2] - m.from[2]).abs() < TOL {
            Way::Across
        } else if (m.to[0] - m.from[0]).abs() < TOL {
            Way::Along
        } else {
            Way::Profile
        }
    };
    // A pass along the contour (arcs, or more moves than a lead-in, a cut, a pull-out and a
    // retract) follows a profile.
    if run.len() > 6 || run.iter().any(|m| m.arc.is_some()) {
        return None;
    }
    let longest = run.iter().filter(|m| way(m) != Way::Profile).max_by(|a, b| len(a).total_cmp(&len(b)))?;
    let w = way(longest);
    let share: f64 = run.iter().filter(|m| way(m) == w).map(len).sum();
    (total > TOL && share >= 0.55 * total).then_some((w, *longest))
}

/// CAM posts write a roughing operation's passes as plain moves, each pass at its own feeds
/// (lead-in, cut, pull-out), so recovery ends a workingstep at each pass. Consecutive passes
/// of one tool that cut the same way (across for facing, along for turning), each a step
/// from the one before, are one roughing workingstep; its depth of cut is the step between
/// the passes. A pass along a profile (the finishing pass) stays its own workingstep.
fn group_passes(plan: &mut ProcessPlan, remeasure: fn(&mut Workingstep)) {
    let explicit = |w: &Workingstep| w.turning.as_deref().is_some_and(|t| t.intent.is_none() && t.cycle.is_none()) && w.holes.is_empty();
    let pitch = |w: &Workingstep| w.turning.as_deref().and_then(|t| t.pitch);
    let mut out: Vec<Workingstep> = Vec::new();
    // The steps between the passes joined, signed along X for passes along Z.
    let mut steps: Vec<Vec<(f64, f64)>> = Vec::new();
    for ws in std::mem::take(&mut plan.workingsteps) {
        // A lone feed move that only pulls away from where the workingstep before (same
        // tool) ended its cut, out in X (Okuma's `G01 X64 Z-79` after a G87 finish), is that
        // workingstep's retract, not an operation.
        if let Some(prev) = out.last_mut()
            && pulls_away(prev, &ws)
        {
            for mut m in ws.toolpath.iter() {
                m.phase = Phase::Retract;
                prev.toolpath.push(m);
            }
            prev.source = prev.source.cover(ws.source);
            prev.lines = (prev.lines.0.min(ws.lines.0), prev.lines.1.max(ws.lines.1));
            remeasure(prev);
            continue;
        }
        let joined = out.last().filter(|_| explicit(&ws)).and_then(|prev| {
            if !explicit(prev) || prev.tool != ws.tool || prev.state.work_offset != ws.state.work_offset || prev.setup != ws.setup {
                return None;
            }
            // Thread passes (synchronised, one lead) are one threading workingstep.
            match (pitch(prev), pitch(&ws)) {
                (Some(a), Some(b)) if (a - b).abs() < TOL => return Some((0.0, 0.0)),
                (None, None) => {}
                _ => return None,
            }
            // A program stop between two passes parts two operations; so does a slower feed
            // (the finishing pass after the roughing ones), and a comment that names another
            // operation (`FINISH_TURN_OD` after `ROUGH_TURN_OD`).
            if ws.state.stops.iter().any(|s| s.at == 0) {
                return None;
            }
            let stated = |w: &Workingstep| w.turning.as_deref().and_then(|t| t.stated);
            if stated(&ws).is_some() && stated(&ws) != stated(prev) {
                return None;
            }
            let feed = |w: &Workingstep| w.turning.as_deref().and_then(|t| t.feed_per_rev);
            if let (Some(a), Some(b)) = (feed(prev), feed(&ws))
                && b < 0.7 * a
            {
                return None;
            }
            let last = runs(prev).pop()?;
            let new = runs(&ws);
            let [one] = new.as_slice() else { return None };
            // A CAM post's roughing pass may follow the contour after its straight cut (NX's
            // profile clean-up) and pull off the same way as the pass before it: by its first
            // straight cut, the same roughing.
            let ((a, ma), (b, mb)) = match (main_cut(&last), main_cut(one)) {
                (Some(a), Some(b)) => (a, b),
                _ if same_pull_off(&last, one) => (lead_cut(&last)?, lead_cut(one)?),
                _ => return None,
            };
            if a != b || a == Way::Profile {
                return None;
            }
            // The step between the two passes' main cuts, across their direction.
            let (step, outward) = match a {
                Way::Across => ((ma.to[2] - mb.to[2]).abs(), 0.0),
                _ => ((ma.to[0] - mb.to[0]).abs(), mb.to[0] - ma.to[0]),
            };
            (step > TOL && step <= 10.0).then_some((step, outward))
        });
        match (joined, out.last_mut()) {
            (Some(step), Some(prev)) => {
                join(prev, ws);
                remeasure(prev);
                if let Some(s) = steps.last_mut() {
                    s.push(step);
                }
            }
            _ => {
                out.push(ws);
                steps.push(Vec::new());
            }
        }
    }
    for (k, (ws, s)) in out.iter_mut().zip(steps).enumerate() {
        ws.index = k as u32 + 1;
        let mut depths: Vec<f64> = s.iter().map(|s| s.0).filter(|d| *d > TOL).collect();
        if depths.is_empty() {
            continue;
        }
        depths.sort_by(f64::total_cmp);
        let depth = depths[depths.len() / 2];
        // Passes along Z that step out to larger diameters bore: the tool works inside.
        let outward = s.iter().filter(|s| s.1 > TOL).count();
        if let Some(t) = ws.turning.as_mut() {
            t.intent = Some(crate::canon::TurnIntent { depth_of_cut: Some(round(depth)), ..Default::default() });
            t.inside |= outward > 0 && 2 * outward > s.len();
        }
    }
    plan.workingsteps = out;
}

/// A pass's pull-off: its last cut, a short move that changes both X and Z (a post's 45°
/// departure), as (X, Z).
fn pull_off(run: &[Move]) -> Option<[f64; 2]> {
    let m = run.last()?;
    let (dx, dz) = (m.to[0] - m.from[0], m.to[2] - m.from[2]);
    (m.arc.is_none() && dx.abs() > TOL && dz.abs() > TOL && dx.hypot(dz) <= 2.0 && run.len() > 1).then_some([dx, dz])
}

/// Whether two passes pull off alike (the same short move in X and Z).
fn same_pull_off(a: &[Move], b: &[Move]) -> bool {
    pull_off(a).zip(pull_off(b)).is_some_and(|(p, q)| (p[0] - q[0]).abs() < 2.0 * TOL && (p[1] - q[1]).abs() < 2.0 * TOL)
}

/// A pass's first straight cut (along Z or across X; a diagonal lead-in skipped) and its way.
fn lead_cut(run: &[Move]) -> Option<(Way, Move)> {
    run.iter().filter(|m| m.arc.is_none()).find_map(|m| {
        let (dx, dz) = ((m.to[0] - m.from[0]).abs(), (m.to[2] - m.from[2]).abs());
        if dz < TOL && dx > TOL {
            Some((Way::Across, *m))
        } else if dx < TOL && dz > TOL {
            Some((Way::Along, *m))
        } else {
            None
        }
    })
}

/// Whether `ws` is one feed move of `prev`'s tool, without a cycle of its own, that starts
/// where `prev`'s last cut ended and leaves outward in X by at most a few millimetres.
fn pulls_away(prev: &Workingstep, ws: &Workingstep) -> bool {
    let own_cycle = ws.turning.as_deref().is_none_or(|t| t.intent.is_some() || t.pitch.is_some());
    let cuts = cuts(ws);
    let ([m], Some(end)) = (cuts.as_slice(), cuts_end(prev)) else { return false };
    !own_cycle
        && prev.tool == ws.tool
        && prev.turning.is_some()
        && (m.from[0] - end[0]).abs() < 0.01
        && (m.from[2] - end[2]).abs() < 0.01
        && m.to[0].abs() > m.from[0].abs() + TOL
        && (m.to[0] - m.from[0]).hypot(m.to[2] - m.from[2]) <= 5.0
}

/// Where a workingstep's last cut ended.
fn cuts_end(ws: &Workingstep) -> Option<P3> {
    cuts(ws).last().map(|m| m.to)
}

/// Appends a workingstep's moves, stops and dwells to the one before (to be measured again).
fn join(prev: &mut Workingstep, ws: Workingstep) {
    let n = prev.toolpath.len() as u32;
    let last_cut = prev.toolpath.iter().rposition(|m| m.phase == Phase::Cut).unwrap_or(0);
    for i in last_cut + 1..prev.toolpath.len() {
        prev.toolpath.set_phase(i, Phase::Connect);
    }
    let first_cut = ws.toolpath.iter().position(|m| m.phase == Phase::Cut).unwrap_or(0);
    for (i, mut m) in ws.toolpath.iter().enumerate() {
        if i < first_cut {
            m.phase = Phase::Connect;
        }
        prev.toolpath.push(m);
    }
    prev.state.stops.extend(ws.state.stops.into_iter().map(|s| Stop { at: s.at + n, ..s }));
    prev.state.dwells.extend(ws.state.dwells.into_iter().map(|d| Dwell { at: d.at + n, ..d }));
    prev.state.optional_lines.extend(ws.state.optional_lines);
    for f in ws.technology.feeds {
        if !prev.technology.feeds.iter().any(|g| (g - f).abs() < 1e-9) {
            prev.technology.feeds.push(f);
        }
    }
    prev.source = prev.source.cover(ws.source);
    prev.lines = (prev.lines.0.min(ws.lines.0), prev.lines.1.max(ws.lines.1));
}

/// Passes as moves: no cycle, no thread (the depth of cut `group_passes` read between
/// straight passes is no cycle's), no holes.
fn explicit_passes(w: &Workingstep) -> bool {
    w.turning.as_deref().is_some_and(|t| {
        t.intent.as_ref().is_none_or(|i| *i == crate::canon::TurnIntent { depth_of_cut: i.depth_of_cut, ..Default::default() })
            && t.cycle.is_none()
            && t.pitch.is_none()
    }) && w.holes.is_empty()
}

/// `ws` runs on from `prev` on the same machine state: the same tool, setup, work offset and
/// spindle, and no stop at its start.
fn same_run(prev: &Workingstep, ws: &Workingstep) -> bool {
    prev.tool == ws.tool
        && prev.setup == ws.setup
        && prev.state.work_offset == ws.state.work_offset
        && prev.technology.spindle_id == ws.technology.spindle_id
        && !ws.state.stops.iter().any(|s| s.at == 0)
}

/// The passes of one groove, as turners and posts cut a groove wider than the tool: plunge to
/// the floor, back out, step over and plunge again (Fanuc's `G75` grooving cycle shifts
/// along Z between its plunges in the same way), then finish each flank down to the floor.
/// Each pass comes in across X and goes back out the way it came, a rapid between them, often
/// at a finer feed for the flanks: a rapid or a feed change between the passes of one tool
/// over one groove (their Z stretches overlapping, from the same side) is no new operation.
/// Consecutive workingsteps of one tool made of such passes are joined into one.
fn one_groove(plan: &mut ProcessPlan, remeasure: fn(&mut Workingstep)) {
    let stated = |w: &Workingstep| w.turning.as_deref().and_then(|t| t.stated);
    let mut out: Vec<Workingstep> = Vec::new();
    let input = std::mem::take(&mut plan.workingsteps);
    // Each workingstep's first move: the way out of the one before (the rapid back out of a
    // groove's last pass begins the next pass's workingstep).
    let firsts: Vec<Option<Move>> = input.iter().map(|w| w.toolpath.iter().next()).collect();
    for (i, ws) in input.into_iter().enumerate() {
        let after = firsts.get(i + 1).copied().flatten();
        let joins = out.last().is_some_and(|prev| {
            explicit_passes(prev)
                && explicit_passes(&ws)
                && same_run(prev, &ws)
                && (stated(&ws).is_none() || stated(&ws) == stated(prev))
                && groove_passes(prev, firsts[i])
                    .zip(groove_passes(&ws, after))
                    .is_some_and(|(a, b)| (a.inward - b.inward).abs() < TOL && a.lo <= b.hi + TOL && b.lo <= a.hi + TOL)
        });
        match out.last_mut() {
            Some(prev) if joins => {
                join(prev, ws);
                // A groove's passes step over along its floor, not down by a depth of cut.
                if let Some(t) = prev.turning.as_mut() {
                    t.intent = None;
                }
                remeasure(prev);
            }
            _ => out.push(ws),
        }
    }
    for (k, ws) in out.iter_mut().enumerate() {
        ws.index = k as u32 + 1;
    }
    plan.workingsteps = out;
}

/// Grooving cycles that each plunge at one place along Z (Fanuc's `G75` with no Z shift, a
/// program moving the tool along Z between the calls) to the same floor, side by side: a groove
/// wider than the tool cut in several plunges, as the cycle itself would cut it with its Z
/// shift (its shift, the manual's Δk, is less than the tool's width, so that no stock stands
/// between the plunges). Joined into one grooving workingstep where each plunge lies within the
/// tool's width of the one before: the tool's width must be known (its name or comment, the
/// tool table); without it two plunges may be two grooves.
fn plunges_side_by_side(plan: &mut ProcessPlan, remeasure: fn(&mut Workingstep)) {
    let groove_cycle = |w: &Workingstep| {
        w.holes.is_empty()
            && w.turning
                .as_deref()
                .and_then(|t| t.intent.as_ref())
                .is_some_and(|i| i.kind == Some(TurnKind::Groove) && i.span.is_none() && i.step.is_none())
    };
    let widths: Vec<(u32, f64)> = plan.tools.iter().filter_map(|t| tool_width(t).map(|w| (t.number, w))).collect();
    join_consecutive(plan, remeasure, |prev, ws| {
        let width = widths.iter().find(|(n, _)| *n == ws.tool).map(|(_, w)| *w);
        let (Some(width), true, true, true) = (width, groove_cycle(prev), groove_cycle(ws), same_run(prev, ws)) else {
            return false;
        };
        let (Some(a), Some(b)) = (plunge_span(prev), plunge_span(ws)) else { return false };
        a.inward == b.inward && (a.floor - b.floor).abs() < TOL && a.lo.max(b.lo) - a.hi.min(b.hi) <= width + TOL
    });
}

/// Joins each workingstep into the one before where `joins(before, it)` (remeasured), and
/// numbers the plan's workingsteps again.
fn join_consecutive(plan: &mut ProcessPlan, remeasure: fn(&mut Workingstep), joins: impl Fn(&Workingstep, &Workingstep) -> bool) {
    let mut out: Vec<Workingstep> = Vec::new();
    for ws in std::mem::take(&mut plan.workingsteps) {
        match out.last_mut() {
            Some(prev) if joins(prev, &ws) => {
                join(prev, ws);
                remeasure(prev);
            }
            _ => out.push(ws),
        }
    }
    for (k, ws) in out.iter_mut().enumerate() {
        ws.index = k as u32 + 1;
    }
    plan.workingsteps = out;
}

/// Plunges straight across X at one or more places along Z, all the same way in, off the axis.
struct PlungeSpan {
    /// -1 in from outside, 1 out into a bore's wall.
    inward: f64,
    /// The Z stretch of the plunges, mm.
    lo: f64,
    hi: f64,
    /// The radius the deepest plunge reaches.
    floor: f64,
}

/// A workingstep's cuts as plunges straight across X (pecks included: each peck's feed goes
/// in), or none where any cut moves along Z, reaches the axis or goes back out at feed.
fn plunge_span(w: &Workingstep) -> Option<PlungeSpan> {
    let cuts = cuts(w);
    let first = cuts.first()?;
    let inward = (first.to[0] - first.from[0]).signum();
    let straight = |m: &Move| m.arc.is_none() && (m.to[2] - m.from[2]).abs() < TOL && (m.to[0] - m.from[0]) * inward > TOL;
    if !cuts.iter().all(|m| straight(m) && m.from[0].min(m.to[0]) >= 0.05) {
        return None;
    }
    let zs = cuts.iter().map(|m| m.to[2]);
    let (lo, hi) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), z| (l.min(z), h.max(z)));
    let floor = cuts.iter().map(|m| m.to[0] * inward).fold(f64::NEG_INFINITY, f64::max) * inward;
    Some(PlungeSpan { inward, lo, hi, floor })
}

/// A face grooving cycle (`G74` off the axis: pecks along -Z) and the passes the same tool
/// then cuts in that groove, each plunged along -Z into the face and left back up along +Z
/// (`face_plunges`), over diameters that take in the cycle's plunges (its walls and floor cut
/// to size, a chamfer at its edge), each pass's radii reaching the cycle's or another such
/// pass's without a gap: one grooving operation, as a groove's plunge and its flanks are
/// (`one_groove`), the groove as wide as all its passes' span. (A separate plunge beside the
/// groove is another groove: the tool's width, which would tell, is not in the program.)
fn face_groove_walls(plan: &mut ProcessPlan, remeasure: fn(&mut Workingstep)) {
    let pecks = |w: &Workingstep| {
        w.turning.as_deref().and_then(|t| t.intent.as_ref()).is_some_and(|i| i.kind == Some(TurnKind::FacePeck)) && w.holes.is_empty()
    };
    join_consecutive(plan, remeasure, |prev, ws| {
        pecks(prev)
            && explicit_passes(ws)
            && same_run(prev, ws)
            && face_plunges(prev)
                .zip(face_plunges(ws))
                .is_some_and(|(a, b)| a.lo >= b.lo - TOL && a.hi <= b.hi + TOL && b.contiguous_with(a.lo, a.hi))
    });
}

/// A workingstep's passes as the passes of one groove (`one_groove`).
struct GroovePasses {
    /// Which way the passes go into the part across X: -1 outside, 1 in a bore.
    inward: f64,
    /// The Z stretch the passes cut over, mm.
    lo: f64,
    hi: f64,
    /// Some pass is no straight plunge (it comes down a flank along a profile): the groove's
    /// flanks are finished, and its width is their span.
    profiled: bool,
}

/// Whether every pass of a workingstep plunges across X into the part and goes back out the
/// way it came (by its own last cut or the move after it), cutting more across X than along
/// Z, off the axis, all from one side, their Z stretches overlapping one another: one groove.
/// `after`: the move after the workingstep (its last pass's way out, if not its own); with
/// none, its last pass is taken to leave (nothing of it follows).
fn groove_passes(ws: &Workingstep, after: Option<Move>) -> Option<GroovePasses> {
    let moves: Vec<Move> = ws.toolpath.iter().collect();
    let spans = run_spans(ws);
    if spans.is_empty() {
        return None;
    }
    let mut inward = 0.0;
    let mut stretches: Vec<(f64, f64)> = Vec::new();
    let mut profiled = false;
    for &(a, b) in &spans {
        let run: Vec<Move> = moves[a..b].iter().filter(|m| is_cut(m)).copied().collect();
        // The pass opens with its plunge: its first cut comes in across X at least half as much
        // as along Z (a lead-in along Z first is a facing or turning pass's).
        let first = run.first()?;
        let (dx, dz) = (first.to[0] - first.from[0], first.to[2] - first.from[2]);
        if dx.abs() <= TOL || 2.0 * dx.abs() < dz.abs() {
            return None;
        }
        let dir = dx.signum();
        if inward != 0.0 && dir != inward {
            return None;
        }
        inward = dir;
        let start = run.first()?.from[0];
        let deepest = run.iter().map(|m| m.to[0] * dir).fold(f64::NEG_INFINITY, f64::max);
        let depth = deepest - start * dir;
        let zs = run.iter().flat_map(|m| [m.from[2], m.to[2]]);
        let (lo, hi) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), z| (l.min(z), h.max(z)));
        let off_axis = run.iter().all(|m| m.from[0].min(m.to[0]) >= 0.05);
        // Out the way it came: a move back across X (more across than along Z).
        let leaves = |m: &Move| (m.to[0] - m.from[0]) * dir < -TOL && (m.to[0] - m.from[0]).abs() > (m.to[2] - m.from[2]).abs();
        // (Not after a pull-off along Z: a facing pass is left along Z off the face it cut, a
        // plunge straight back out of its groove.)
        let next = moves.get(b).copied().or(after);
        let pulled_off = run.last().is_some_and(|m| (m.to[0] - m.from[0]).abs() < TOL);
        let out = run.last().is_some_and(leaves) || (!pulled_off && next.as_ref().is_none_or(leaves));
        if !(off_axis && out && depth > TOL && hi - lo <= depth) {
            return None;
        }
        profiled |= run.iter().any(|m| m.arc.is_some() || (m.to[2] - m.from[2]).abs() > TOL);
        stretches.push((lo, hi));
    }
    // Overlapping one another: each stretch, in order along Z, reaches the ones before.
    stretches.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut reach = stretches[0].1;
    for &(lo, hi) in &stretches[1..] {
        if lo > reach + TOL {
            return None;
        }
        reach = reach.max(hi);
    }
    Some(GroovePasses { inward, lo: stretches[0].0, hi: reach, profiled })
}

/// A groove on the face, profiled from both walls (its roughing fed along -Z, as Fanuc's
/// `G74` face grooving cycle pecks): passes that each come down a wall along -Z to the same
/// floor (the deepest Z cut) and run across it, one from the outer wall and one from the
/// inner, their runs across the floor meeting. Read as [`profiled_groove`] with Z and X
/// exchanged: the floor's Z and the radii its cuts span (from wall to wall at the floor).
fn face_groove(runs: &[Vec<Move>]) -> Option<(f64, f64, f64)> {
    let swap = |p: P3| [p[2], p[1], p[0]];
    let swapped: Vec<Vec<Move>> =
        runs.iter().map(|r| r.iter().map(|m| Move { from: swap(m.from), to: swap(m.to), ..*m }).collect()).collect();
    let floor = profiled_groove(&swapped).map(|(floor, _, _)| floor).or_else(|| straight_walls(runs))?;
    // Off the axis: a face cut to the centre is facing.
    if runs.iter().flatten().any(|m| m.from[0].min(m.to[0]) < 0.05) {
        return None;
    }
    let on_floor = runs.iter().flatten().filter(|m| m.arc.is_none() && (m.from[2] - floor).abs() < 0.01 && (m.to[2] - floor).abs() < 0.01);
    let xs = on_floor.flat_map(|m| [m.from[0], m.to[0]]);
    let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x), h.max(x)));
    (hi > lo).then_some((floor, lo, hi))
}

/// A face groove whose walls are straight, each finished by a pass of its own as a face
/// grooving tool finishes them: the pass plunges along -Z down the wall to the floor (the
/// deepest Z cut) and runs across the floor away from its wall, one from the outer wall and one
/// from the inner, their runs across the floor meeting (the straight-walled case of
/// [`face_groove`], whose profiled passes come down a flank from beyond the floor). The floor.
fn straight_walls(runs: &[Vec<Move>]) -> Option<f64> {
    if runs.len() < 2 {
        return None;
    }
    let floor = runs.iter().flatten().flat_map(|m| [m.from[2], m.to[2]]).fold(f64::INFINITY, f64::min);
    let (mut outer, mut inner) = (None::<(f64, f64)>, None::<(f64, f64)>);
    for r in runs {
        let Some(first) = r.first() else { continue };
        let plunge = first.arc.is_none() && (first.to[0] - first.from[0]).abs() < TOL && (first.to[2] - floor).abs() < 0.01;
        let along: Vec<&Move> =
            r.iter().filter(|m| m.arc.is_none() && (m.from[2] - floor).abs() < 0.01 && (m.to[2] - floor).abs() < 0.01).collect();
        let xs = along.iter().flat_map(|m| [m.from[0], m.to[0]]);
        let (lo, hi) = xs.fold((f64::INFINITY, f64::NEG_INFINITY), |(l, h), x| (l.min(x), h.max(x)));
        if !plunge || hi - lo <= TOL || first.from[2] <= floor + TOL {
            continue;
        }
        let wall = first.from[0];
        let span = |o: Option<(f64, f64)>| Some(o.map_or((lo, hi), |(l, h)| (l.min(lo), h.max(hi))));
        if (wall - hi).abs() < TOL {
            outer = span(outer);
        } else if (wall - lo).abs() < TOL {
            inner = span(inner);
        }
    }
    let ((lo_out, _), (_, hi_in)) = (outer?, inner?);
    (lo_out <= hi_in + TOL).then_some(floor)
}

/// A face groove's passes plunged along -Z (`face_plunges`).
struct FacePlunges {
    /// The floor: the deepest Z cut.
    floor: f64,
    /// The smallest and largest radius the passes cut at.
    lo: f64,
    hi: f64,
    /// Some pass also cuts across X (at its floor), as a face groove is roughed wider than the
    /// tool before its walls are finished.
    across: bool,
    /// Each pass's smallest and largest radius cut.
    runs: Vec<(f64, f64)>,
}

impl FacePlunges {
    /// Whether the passes, each joined to the radii `lo..hi` cut so far or to a pass that is,
    /// all reach them without a gap: the same groove widened and its walls cut, not another
    /// plunge beside it (with the tool's width unknown, a gap between cuts is another groove).
    fn contiguous_with(&self, lo: f64, hi: f64) -> bool {
        let (mut lo, mut hi) = (lo, hi);
        let mut left: Vec<(f64, f64)> = self.runs.clone();
        loop {
            let before = left.len();
            left.retain(|&(a, b)| {
                let touches = a <= hi + TOL && b >= lo - TOL;
                if touches {
                    lo = lo.min(a);
                    hi = hi.max(b);
                }
                !touches
            });
            if left.is_empty() {
                return true;
            }
            if left.len() == before {
                return false;
            }
        }
    }
}

/// Whether every pass of a workingstep plunges along -Z into the face, off the axis, and
/// leaves back up along +Z: a face groove cut as Fanuc's `G74` face grooving cycle pecks it
/// (Fanuc 0i-TF operator's manual, G74: pecks along Z, shifting in X between them) and as
/// posts write a face grooving tool's passes (a plunge along Z, perhaps a cut across X at the
/// floor, then straight back out: the tool sits between the groove's two walls, so it cannot
/// leave across X). Each pass opens with its plunge, straight along -Z at one X; none cuts
/// above where it plunged in, nor reaches the axis (a face cut to the centre is facing);
/// each ends with a cut back up along +Z at one X or is followed by such a move in the
/// workingstep (a profile turned down along -Z by a grooving tool leaves across X, or with
/// the workingstep's end).
fn face_plunges(ws: &Workingstep) -> Option<FacePlunges> {
    let moves: Vec<Move> = ws.toolpath.iter().collect();
    let spans = run_spans(ws);
    if spans.is_empty() {
        return None;
    }
    let up = |m: &Move| m.arc.is_none() && (m.to[0] - m.from[0]).abs() < TOL && m.to[2] > m.from[2] + TOL;
    let mut p = FacePlunges { floor: f64::INFINITY, lo: f64::INFINITY, hi: f64::NEG_INFINITY, across: false, runs: Vec::new() };
    for &(a, b) in &spans {
        let run: Vec<Move> = moves[a..b].iter().filter(|m| is_cut(m)).copied().collect();
        let first = run.first()?;
        if first.arc.is_some() || (first.to[0] - first.from[0]).abs() > TOL || first.to[2] > first.from[2] - TOL {
            return None;
        }
        let top = first.from[2];
        if run.iter().any(|m| m.from[0].min(m.to[0]) < 0.05 || m.from[2].max(m.to[2]) > top + TOL) {
            return None;
        }
        let next = moves.get(b).copied();
        if !(run.last().is_some_and(up) || next.as_ref().is_some_and(up)) {
            return None;
        }
        let mut span = (f64::INFINITY, f64::NEG_INFINITY);
        for m in &run {
            p.floor = p.floor.min(m.from[2].min(m.to[2]));
            span = (span.0.min(m.from[0].min(m.to[0])), span.1.max(m.from[0].max(m.to[0])));
            p.across |= m.arc.is_some() || (m.to[0] - m.from[0]).abs() > TOL;
        }
        p.lo = p.lo.min(span.0);
        p.hi = p.hi.max(span.1);
        p.runs.push(span);
    }
    Some(p)
}

/// The face groove plunges cut: between the smallest and largest diameter plunged, its floor
/// the deepest. (The tool's width adds to it beyond one of them: which, the tool's reference
/// point tells, not the program.)
fn plunged_face_groove(ws: &Workingstep) -> Vec<(FeatureKind, f64)> {
    let Some(p) = face_plunges(ws) else { return Vec::new() };
    let k = Turned::FaceGroove { outer: round(2.0 * p.hi), inner: round(2.0 * p.lo) };
    vec![(FeatureKind::Turned(k), round(p.floor))]
}

/// What a roughing workingstep no finish of its tool follows machines: a face groove roughed
/// by plunges is that groove, as far as the plunges cut it; any other region turned is one
/// general revolution.
fn unfinished(ws: &Workingstep) -> Vec<(FeatureKind, f64)> {
    let t = ws.turning.as_deref();
    if t.is_some_and(|t| t.operation == Some(TurnOp::Grooving) && !t.inside) && face_plunges(ws).is_some() {
        return plunged_face_groove(ws);
    }
    revolution(ws)
}

/// The region a workingstep turns, as one general revolution.
fn revolution(ws: &Workingstep) -> Vec<(FeatureKind, f64)> {
    match ws.turning.as_deref().map(|t| (t.diameter, t.z)) {
        Some((Some(d), Some(z))) => {
            let k = Turned::Revolution { outer: round(d[1]), inner: round(d[0]), length: round(z[1] - z[0]) };
            vec![(FeatureKind::Turned(k), round(z[1]))]
        }
        _ => Vec::new(),
    }
}

/// A tool's cutting width across Z: a grooving tool's width (`W3`, `WIDTH 3` in its
/// comment), else its diameter (a drill).
pub fn tool_width(t: &Tool) -> Option<f64> {
    let up = t.name.as_deref().unwrap_or("").to_ascii_uppercase();
    let words: Vec<&str> = up.split(|c: char| c.is_whitespace() || c == ',' || c == '(' || c == ')').filter(|w| !w.is_empty()).collect();
    let named = words.iter().enumerate().find_map(|(i, w)| {
        let v = w.strip_prefix("WIDTH").or_else(|| w.strip_prefix('W'))?.trim_start_matches(['=', ':']);
        let v = if v.is_empty() { words.get(i + 1).copied().unwrap_or("") } else { v };
        v.trim_end_matches("MM").parse::<f64>().ok().filter(|v| *v > 0.0)
    });
    named.or(t.diameter)
}

/// A cutting move in (Z, X radius).
fn cuts(ws: &Workingstep) -> Vec<Move> {
    ws.toolpath.iter().filter(is_cut).collect()
}

/// Whether a move cuts (a feed in the cutting phase).
fn is_cut(m: &Move) -> bool {
    m.phase == Phase::Cut && m.kind != MoveKind::Rapid
}

/// Whether a move is a straight cut across X at one Z (a pass facing, or along a face).
fn straight_across(m: &Move) -> bool {
    m.arc.is_none() && (m.to[2] - m.from[2]).abs() < TOL && (m.to[0] - m.from[0]).abs() > TOL
}

/// Runs of cuts between rapids.
fn runs(ws: &Workingstep) -> Vec<Vec<Move>> {
    let mut out: Vec<Vec<Move>> = Vec::new();
    let mut open = false;
    for m in ws.toolpath.iter() {
        if m.kind == MoveKind::Rapid || m.phase != Phase::Cut {
            open = false;
            continue;
        }
        if !open {
            out.push(Vec::new());
            open = true;
        }
        if let Some(r) = out.last_mut() {
            r.push(m);
        }
    }
    out
}

/// A contour cycle over a contour that is only a face, across X to the axis (a `G71`/`G70`
/// pair over `X-0.063 Z0.1`, `Z0`, `X3.`): facing, as a turner names what it does. The
/// contour is the finishing cycle's cut, or the roughing cycle's last pass.
fn face_contour(contour: &[Move]) -> bool {
    let (across, all) = across_and_all(contour);
    let lo = contour.iter().flat_map(|m| [m.from[0], m.to[0]]).fold(f64::INFINITY, f64::min);
    all > TOL && across >= 0.75 * all && lo < 0.05
}

/// Whether cuts run mostly across X: more of their length across than along Z or oblique.
fn mostly_across(cuts: &[Move]) -> bool {
    let (across, all) = across_and_all(cuts);
    all > TOL && 2.0 * across > all
}

/// The length of the cuts that run across X (at one Z), and of all of them.
fn across_and_all(cuts: &[Move]) -> (f64, f64) {
    let length = |m: &Move| (m.to[0] - m.from[0]).hypot(m.to[2] - m.from[2]);
    let across: f64 = cuts.iter().filter(|m| (m.to[2] - m.from[2]).abs() < TOL).map(length).sum();
    (across, cuts.iter().map(length).sum())
}

fn classify(ws: &mut Workingstep, front: f64, back: f64, boring: bool, grooving: bool, drill: Option<f64>) {
    let mut t = ws.turning.take().map(|b| *b).unwrap_or_default();
    let cuts = cuts(ws);
    if cuts.is_empty() {
        t.stated = None;
        ws.turning = Some(Box::new(t));
        return;
    }
    let xs = cuts.iter().flat_map(|m| [m.from[0], m.to[0]]);
    let (xmin, xmax) = xs.clone().fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| (a.min(x), b.max(x)));
    let zs = cuts.iter().flat_map(|m| [m.from[2], m.to[2]]);
    let (zmin, zmax) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| (a.min(z), b.max(z)));
    // A cut across the axis (to X-0.8, past the centre) reaches it: the smallest diameter is 0.
    t.diameter = Some([round(2.0 * xmin.max(0.0)), round(2.0 * xmax.abs().max(xmin.abs()))]);
    t.z = Some([round(zmin), round(zmax)]);
    let runs = runs(ws);
    t.passes = runs.len() as u32;
    t.inside = works_inside(ws, &t, &runs, (xmin, xmax), boring);
    // After a plunge across X, a groove is left back out along the same line; a face is
    // left along Z.
    let last_cut = ws.toolpath.iter().rposition(|m| m.phase == Phase::Cut && m.kind != MoveKind::Rapid);
    let back_out = last_cut
        .and_then(|i| ws.toolpath.get(i + 1))
        .is_some_and(|m| (m.to[2] - m.from[2]).abs() < TOL && (m.to[0] - m.from[0]).abs() > TOL);
    let along = |m: &Move| (m.to[0] - m.from[0]).abs() < TOL;
    let Across { mostly: mostly_across, levels, widened, fed_down, face } = across_passes(ws, &cuts, &runs, xmin, front, boring);
    let intent_kind = t.intent.as_ref().and_then(|i| i.kind);
    // Passes recovery joined as one operation, each a step from the one before.
    let stepped_in = t.intent.as_ref().is_some_and(|i| i.kind.is_none() && i.depth_of_cut.is_some_and(|d| d > TOL));
    let plunges = plunges(ws, &runs);
    // A face grooving tool's passes (or `G74`'s, with the passes joined to it) plunged along
    // -Z into the face off the axis and left back up along +Z (`face_plunges`) cut a groove in
    // the face: a cut across X at their floor runs along the groove's floor between its walls,
    // not off a bore's wall.
    let face_tool = match intent_kind {
        None => grooving,
        Some(k) => k == TurnKind::FacePeck,
    };
    let face_grooving = face_tool && !boring && xmin >= 0.05 && face_plunges(ws).is_some();
    if face_grooving {
        t.inside = false;
    }
    // A single plunge straight across X behind the whole part (at or past the deepest Z every
    // other workingstep cuts) down to a tenth of the diameter it starts from parts the part
    // off, stopped short of the centre so that it leaves a pip rather than tearing it off (a
    // groove there would leave too little to hold the part).
    let pip = runs.len() == 1
        && cuts.iter().all(|m| straight_across(m) && m.to[0] < m.from[0])
        && back.is_finite()
        && zmax <= back + TOL
        && xmin >= 0.05
        && xmin <= 0.1 * xmax;
    let (op, rough) = match intent_kind {
        None if pip && t.pitch.is_none() => (TurnOp::PartingOff, false),
        Some(TurnKind::RoughTurn) if runs.last().is_some_and(|r| face_contour(r)) => (TurnOp::Facing, true),
        // A contour cycle run outside by a grooving tool the program names (`(OD GROOVE TURN)`
        // with a `G71`/`G70` pair over a recess): groove turning, roughed by the roughing cycle
        // and finished by the finishing one, as for its passes written as moves (below).
        Some(TurnKind::RoughTurn) if grooving && !t.inside => (TurnOp::Grooving, true),
        Some(TurnKind::Finish) if grooving && !t.inside && !face_contour(&cuts) => (TurnOp::Grooving, false),
        Some(TurnKind::RoughTurn | TurnKind::TurnPass) => (TurnOp::Contouring, true),
        Some(TurnKind::RoughFace) => (TurnOp::Facing, true),
        Some(TurnKind::FacePass) => (TurnOp::Facing, runs.len() > 1),
        Some(TurnKind::Finish) if face_contour(&cuts) => (TurnOp::Facing, false),
        Some(TurnKind::Finish) => (TurnOp::Contouring, false),
        Some(TurnKind::Thread | TurnKind::ThreadPass) => (TurnOp::Threading, runs.len() > 1),
        Some(TurnKind::Groove) if xmin < 0.05 && groove_cycle_faces(&cuts) => (TurnOp::Facing, true),
        Some(TurnKind::Groove) if xmin < 0.05 => (TurnOp::PartingOff, false),
        Some(TurnKind::Groove) => (TurnOp::Grooving, levels.len() > 1 && t.intent.as_ref().is_some_and(|i| i.span.is_none())),
        Some(TurnKind::FacePeck) if xmax.abs() < TOL => (TurnOp::Drilling, false),
        Some(TurnKind::FacePeck) => (TurnOp::Grooving, false),
        None if t.pitch.is_some() => (TurnOp::Threading, runs.len() > 1),
        None if xmax.abs() < TOL && cuts.iter().all(along) => (TurnOp::Drilling, false),
        // A drill fed along the axis and run off the centre by less than its radius, as
        // indexable-insert drills (U-drills) are on lathes to open the hole they drill to a
        // larger diameter (Sandvik Coromant's CoroDrill 880: radial offset on a rotating
        // workpiece): it still covers the axis, so it drills, whatever it cuts across X at the
        // bottom.
        None if drill.is_some_and(|d| xmin.abs().max(xmax.abs()) < d / 2.0 - TOL) && cuts.iter().any(along) => (TurnOp::Drilling, false),
        // Passes that plunge across and back out the same way, as CAM posts write a groove
        // wider than the tool: roughing where they plunge at several places along Z.
        None if xmin >= 0.05 && plunges.0 >= 1 && 2 * plunges.0 >= runs.len() => (TurnOp::Grooving, plunges.1 > 1),
        // A recess profiled from both sides down to one bottom, as posts write a groove's
        // finish with a turning or grooving tool: each flank in a pass of its own.
        None if xmin >= 0.05 && !t.inside && profiled_groove(&runs).is_some() => (TurnOp::Grooving, false),
        // A face groove profiled from both walls down to one floor (`face_groove`).
        None if xmin >= 0.05 && !t.inside && face_groove(&runs).is_some() => (TurnOp::Grooving, false),
        // A face grooving tool's passes plunged along -Z between two diameters (`face_plunges`):
        // roughing where the passes also cut across X at their floors (they leave the walls to
        // a finish), else the plunges make the groove.
        None if face_grooving => (TurnOp::Grooving, runs.len() > 1 && face_plunges(ws).is_some_and(|p| p.across)),
        // A groove plunged and its flanks finished, each pass in and back out across X over
        // one stretch of Z (`one_groove`; not passes stepping a face down, each a depth of cut
        // from the one before): one grooving operation that finishes the groove.
        None if runs.len() > 1 && !stepped_in && groove_passes(ws, None).is_some_and(|g| g.profiled) => (TurnOp::Grooving, false),
        None if mostly_across || face => {
            let to_axis = xmin < 0.05;
            // Cuts to the axis at several places along Z step down a face (a facing cycle
            // written as moves); a parting tool plunges to the axis at one.
            let at_axis = axis_reached_at(&cuts);
            // A cut to the axis nearer the part's front than its back (the deepest the other
            // workingsteps cut) faces, a second face behind a first one; a parting tool cuts
            // off behind the part.
            let near_front = back.is_finite() && zmin > back + TOL && front - zmin < zmin - back;
            let stepped = runs.len() > 1 && levels.len() > 1;
            if to_axis && (zmin >= front - 0.5 || at_axis.len() > 1 || near_front || fed_down) {
                (TurnOp::Facing, stepped)
            } else if to_axis {
                (TurnOp::PartingOff, false)
            } else if back_out {
                (TurnOp::Grooving, runs.len() > 1 && widened)
            } else {
                (TurnOp::Facing, stepped)
            }
        }
        // A grooving tool's passes along a contour outside: grooving, as a turner names what
        // a grooving tool does (a profiled recess, a wide groove turned out).
        // (Not a profile turned down along -Z, `descends`: a contour.)
        None if grooving && !t.inside && (runs.is_empty() || !runs.iter().all(|r| descends(r))) => (TurnOp::Grooving, runs.len() > 1),
        None => (TurnOp::Contouring, contour_roughs(ws, &runs, stepped_in, zmax - zmin)),
    };
    // One pass tells nothing of roughing or finishing: an operation its own comment calls
    // roughing is that (a roughing operation's one pass over a last region). Passes stepping
    // in are roughing whatever the operation is called.
    let stated = t.stated.take();
    let rough = match (op, intent_kind, stated) {
        (TurnOp::Contouring | TurnOp::Facing, None, Some(true)) => true,
        _ => rough,
    };
    t.operation = Some(op);
    t.rough = rough;
    // A drill on the axis works no inside of a hole already there: it makes the hole. Nor does
    // a face cut at the part's front, by a boring bar out from its bore or otherwise: it is the
    // front face (a bore's bottom, behind the front, is faced inside).
    t.inside &= op != TurnOp::Drilling && !(op == TurnOp::Facing && zmin >= front - TOL);
    ws.turning = Some(Box::new(t));
}

/// Whether a workingstep's cuts work the inside of the part (a bore), by its cycle's X
/// allowance, where a roughing cycle starts, the tool, and how its passes come in and leave.
fn works_inside(ws: &Workingstep, t: &super::turned::Turning, runs: &[Vec<Move>], (xmin, xmax): (f64, f64), boring: bool) -> bool {
    // The tool comes in from outside the cuts, or from inside them (a bore).
    let entry = ws.toolpath.iter().take_while(|m| m.phase != Phase::Cut || m.kind == MoveKind::Rapid).last().map(|m| m.to[0]);
    // Inside: a cycle's X allowance is negative, the tool is a boring bar, or roughing
    // passes come in from within the smallest diameter they cut (outside, the tool comes in
    // from beyond the largest); a finishing pass starts at its contour's small end either way.
    let allowance = t.intent.as_ref().and_then(|i| i.allowance_x).filter(|u| u.abs() > TOL);
    let finish_cycle = t.intent.as_ref().is_some_and(|i| i.kind == Some(TurnKind::Finish));
    let rough_cycle = t.intent.as_ref().is_some_and(|i| matches!(i.kind, Some(TurnKind::RoughTurn | TurnKind::RoughFace)));
    // Where a roughing cycle starts: the controls rough between the start point and the
    // contour, so a start nearer the small diameter than the large one is inside.
    let start = ws.toolpath.iter().take_while(|m| m.phase != Phase::Cut || m.kind == MoveKind::Rapid).last().map(|m| m.from[0]);
    match allowance {
        // The allowance is left away from the axis outside: towards +X where the contour
        // lies at X positive, towards -X where the program writes it at X negative (its
        // moves mirrored here: the contour is then at X -(x + U/2), a pass at x).
        // A roughing cycle whose start point lies wholly inside the diameters it cuts roughs a
        // bore, whatever sign its X allowance is written with (the controls rough between the
        // start point and the contour, the start point clear of the stock on the side cut from:
        // Fanuc 0i-TF operator's manual, G71): so does a tool the program names a boring bar.
        Some(_) if rough_cycle && !t.mirrored && (boring || start.is_some_and(|x| x < xmin - TOL)) => true,
        Some(u) => (u < 0.0) != (t.mirrored && xmax + u / 2.0 > 0.0),
        None if rough_cycle && start.is_some() => boring || start.is_some_and(|x| x < (xmin + xmax) / 2.0),
        // A finishing cycle starts where its contour starts, inside or out: it is inside
        // where its roughing was (below), or where it leaves its contour towards the axis
        // (a bore's finishing pass, down its wall and across its bottom, pulled in).
        None if finish_cycle => boring || left_inward(ws),
        None => {
            // (Coming in at the small end counts only for passes all straight, on one side of the
            // axis: a pass along the contour from its small end turns the outside, and passes
            // across the axis, from one side to the other, have no inside.)
            t.inside
                || boring
                || (runs.len() > 1
                    && xmin > -1.0
                    && runs.iter().all(|r| main_cut(r).is_some())
                    && entry.is_some_and(|x| x <= xmin + TOL && x < xmax - TOL)
                    && !shaft_steps(runs))
                || pulls_off_inward(runs)
                || left_inward(ws)
        }
    }
}

/// Whether a run turns a profile outside down along -Z, as a grooving tool finishes a spigot
/// that a part-off then ends: a contour turned, with its diameters, as a turner reads it, not
/// a groove (a groove has a wall on each side): it cuts along Z (a diameter longer
/// than 0.5 mm), never goes back along +Z, never climbs back out once it has come down (no
/// cut to a larger diameter after its smallest), and does not plunge to its bottom first.
fn descends(run: &[Move]) -> bool {
    let along = run.iter().any(|m| (m.to[0] - m.from[0]).abs() < TOL && m.from[2] - m.to[2] > 0.5);
    let back = run.iter().any(|m| m.to[2] > m.from[2] + TOL);
    let lowest = run.iter().map(|m| m.to[0]).fold(f64::INFINITY, f64::min);
    let bottom = run.iter().position(|m| m.to[0] <= lowest + TOL);
    let climbs = bottom.is_some_and(|i| run[i + 1..].iter().any(|m| m.to[0] > m.from[0] + TOL));
    // A plunge straight to the bottom first, then along it: a groove's floor, its other wall
    // plunged or profiled before.
    let plunged = run.first().is_some_and(|m| straight_across(m) && m.to[0] <= lowest + TOL);
    along && !back && !climbs && !plunged
}

/// Runs that plunge across and come back out the way they went in, and at how many Z: by
/// feed within the run, or by the move that leaves it (a rapid back out along the line it
/// plunged, `G1 X.175` then `G0 X.425`, as a groove is plunged at several places): (runs, places).
fn plunges(ws: &Workingstep, runs: &[Vec<Move>]) -> (usize, usize) {
    let across = |m: &Move| (m.to[2] - m.from[2]).abs() < TOL;
    let moves: Vec<Move> = ws.toolpath.iter().collect();
    let spans = run_spans(ws);
    let back = |(r, &(_, end)): (&Vec<Move>, &(usize, usize))| {
        let reverses = r.windows(2).any(|w| {
            let (a, b) = (w[0].to[0] - w[0].from[0], w[1].to[0] - w[1].from[0]);
            a.abs() > TOL && b.abs() > TOL && a.signum() != b.signum()
        });
        let backed_out = r.last().zip(moves.get(end)).is_some_and(|(last, next)| {
            let (a, b) = (last.to[0] - last.from[0], next.to[0] - next.from[0]);
            across(next) && a.abs() > TOL && b.abs() > TOL && a.signum() != b.signum()
        });
        r.iter().all(across) && (reverses || backed_out)
    };
    let runs_at = runs.iter().zip(&spans).filter(|p| back(*p)).filter_map(|(r, _)| r.first().map(|m| m.from[2]));
    let mut at: Vec<f64> = runs_at.collect();
    let n = at.len();
    at.sort_by(f64::total_cmp);
    at.dedup_by(|a, b| (*a - *b).abs() < TOL);
    (n, at.len())
}

/// Whether passes along Z step as a shaft does: a pass at a larger diameter runs deeper (to a
/// Z further back) than one at a smaller diameter. Turned from its front, a part's outside
/// can grow behind a smaller diameter; a bore cannot (the bar would not reach a larger bore
/// behind a smaller one), so such passes turn the outside, whichever diameter they start at.
fn shaft_steps(runs: &[Vec<Move>]) -> bool {
    let along: Vec<(f64, f64)> = runs
        .iter()
        .filter_map(|r| main_cut(r).filter(|(w, _)| *w == Way::Along))
        .map(|(_, m)| (m.from[0].abs(), m.from[2].min(m.to[2])))
        .collect();
    along.iter().any(|a| along.iter().any(|b| b.0 > a.0 + TOL && b.1 < a.1 - 0.5))
}

/// A facing workingstep outside: the Z of the face its last cut across leaves (the last that
/// reaches the axis, where some do), and the diameters that cut spans.
fn face_cut(ws: &Workingstep) -> Option<(f64, [f64; 2])> {
    ws.turning.as_deref().filter(|t| t.operation == Some(TurnOp::Facing) && !t.inside)?;
    let cuts = cuts(ws);
    let across = || cuts.iter().filter(|m| straight_across(m));
    let last = across().rfind(|m| m.from[0].min(m.to[0]) < 0.05).or_else(|| across().next_back())?;
    let (a, b) = (2.0 * last.from[0].abs(), 2.0 * last.to[0].max(0.0));
    Some((last.to[2], [a.min(b), a.max(b)]))
}

/// How explicit passes cut across X (`across_passes`).
struct Across {
    /// Most of the cutting runs across X (passes with short lead-ins and pull-outs).
    mostly: bool,
    /// The places along Z the cuts across X run at: passes at one Z are a finish and its
    /// spring passes, or one plunge; at several they step (facing down, a groove widened).
    levels: Vec<f64>,
    /// Plunges only (each run cuts across X and nothing else) at several places along Z: a
    /// groove wider than the tool roughed out, whether the plunges overlap or leave stock
    /// between them for a later pass (the module's grooving convention).
    widened: bool,
    /// Fed along -Z at its largest diameter before it cuts across to the axis (not positioned
    /// there by a rapid or an air feed): a turning tool taking a face's depth, as no parting
    /// tool does.
    fed_down: bool,
    /// One pass across to the axis with its lead-in ([`face_with_lead_in`]).
    face: bool,
}

/// How a workingstep's explicit passes cut across X. A feed many times the slowest cutting
/// feed positions the tool in the air (`G1 Z0. F2.` before a face at F0.05): no cut, whatever
/// way it runs (compared per revolution: under a constant surface speed a feed per minute
/// grows as the tool nears the axis).
fn across_passes(ws: &Workingstep, cuts: &[Move], runs: &[Vec<Move>], xmin: f64, front: f64, boring: bool) -> Across {
    let across = |m: &Move| (m.to[2] - m.from[2]).abs() < TOL;
    let along = |m: &Move| (m.to[0] - m.from[0]).abs() < TOL;
    let length = |m: &Move| (m.to[0] - m.from[0]).hypot(m.to[2] - m.from[2]);
    let per_rev = |m: &Move| m.feed / rpm_at(&ws.technology, m.to[0]);
    let slowest = cuts.iter().map(per_rev).filter(|f| *f > 0.0).fold(f64::INFINITY, f64::min);
    let air = |m: &Move| slowest.is_finite() && per_rev(m) >= AIR_FEED * slowest;
    let cut_length: f64 = cuts.iter().filter(|m| !air(m)).map(length).sum();
    let across_length: f64 = cuts.iter().filter(|m| across(m) && !air(m)).map(length).sum();
    let mostly = cuts.iter().all(across)
        || (runs.len() > 1
            && (across_length >= 0.75 * cut_length || runs.iter().all(|r| main_cut(r).is_some_and(|(w, _)| w == Way::Across))));
    let mut levels: Vec<f64> = cuts.iter().filter(|m| across(m) && !air(m) && length(m) > TOL).map(|m| m.to[2]).collect();
    levels.sort_by(f64::total_cmp);
    levels.dedup_by(|a, b| (*a - *b).abs() < 0.05);
    let widened = levels.len() > 1 && runs.iter().all(|r| r.iter().filter(|m| !air(m)).all(across));
    let fed_down = runs.iter().any(|r| {
        let mut it = r.iter().skip_while(|m| air(m));
        it.next().is_some_and(|m| along(m) && m.to[2] < m.from[2] - TOL)
            && it.next().is_some_and(|m| across(m) && !air(m) && (m.to[0].abs() < 0.05 || m.to[0] * m.from[0] < 0.0))
    });
    let face = face_with_lead_in(runs, xmin, &air, front, boring);
    Across { mostly, levels, widened, fed_down, face }
}

/// The spindle's speed with the tool at radius `x`, 1/min: under a constant surface speed,
/// the one that gives it there, up to the clamp (recovery's feeds per minute were made so).
fn rpm_at(tech: &super::model::Technology, x: f64) -> f64 {
    let rpm = match tech.surface_speed {
        Some(v) if x.abs() > 1e-9 => {
            let at = v * 1000.0 / (2.0 * std::f64::consts::PI * x.abs());
            if tech.spindle_speed > 0.0 { at.min(tech.spindle_speed) } else { at }
        }
        _ => tech.spindle_speed,
    };
    if rpm > 0.0 { rpm } else { 1.0 }
}

/// A grooving cycle (`G75`) used to face: its plunges reach the axis at several places along
/// Z, stepping (its Q) down to the front at the program zero or in front of it, as a turner
/// faces a bar with a grooving cycle. A cut-off reaches the axis at one Z, behind the part.
fn groove_cycle_faces(cuts: &[Move]) -> bool {
    let at_axis = axis_reached_at(cuts);
    at_axis.len() > 1 && at_axis[0] >= -0.5
}

/// The places along Z where cuts across X reach the axis, each once, in order.
fn axis_reached_at(cuts: &[Move]) -> Vec<f64> {
    let mut at: Vec<f64> =
        cuts.iter().filter(|m| (m.to[2] - m.from[2]).abs() < TOL && m.from[0].min(m.to[0]) < 0.05).map(|m| m.to[2]).collect();
    at.sort_by(f64::total_cmp);
    at.dedup_by(|a, b| (*a - *b).abs() < 0.05);
    at
}

/// Whether explicit passes along a contour rough it. Every pass along the whole contour
/// (LinuxCNC's `G70 P2`, a finish and its spring pass): finishing, however many passes;
/// passes joined as one roughing, each a step in from the one before, rough however much of
/// the contour each follows. Passes under tool nose radius compensation that each run along
/// their own stretch of the contour, none over another's, finish it in pieces (a profile,
/// then a shoulder behind a relief cut elsewhere): roughing passes leave stock, and posts and
/// turners compensate the nose on the finishing profile.
fn contour_roughs(ws: &Workingstep, runs: &[Vec<Move>], stepped_in: bool, length: f64) -> bool {
    let pieces = (!ws.state.cutter_comp.is_empty() && pieces_of_one_contour(runs)) || diameters_one_each(runs);
    runs.len() > 1 && (stepped_in || !(runs.iter().all(|r| whole_contour(r, length)) || pieces))
}

/// Whether straight passes each turn a diameter of their own over a stretch of Z no other
/// pass along Z goes over (within 0.5 mm: a pull-off's overlap), a larger diameter further
/// back: a stepped shaft's diameters finished one by one (`Z-0.12` at Ø0.309, then `Z-1.075`
/// at Ø0.735 from Z-0.115), with the shoulders between them faced. Roughing passes go over
/// the same length again, each at a smaller diameter than the one before, from the front.
fn diameters_one_each(runs: &[Vec<Move>]) -> bool {
    let Some(ways): Option<Vec<(Way, Move)>> = runs.iter().map(|r| main_cut(r)).collect() else { return false };
    let along: Vec<(f64, f64, f64)> = ways
        .iter()
        .filter(|(w, _)| *w == Way::Along)
        .map(|(_, m)| (m.from[0].abs(), m.from[2].min(m.to[2]), m.from[2].max(m.to[2])))
        .collect();
    let apart = along.iter().enumerate().all(|(i, a)| {
        along[i + 1..].iter().all(|b| (a.0 - b.0).abs() > TOL && a.2.min(b.2) - a.1.max(b.1) <= 0.5 && (b.0 > a.0) == (b.1 < a.1))
    });
    along.len() >= 2 && apart
}

/// Whether runs of cuts are one contour cut in pieces: at least one follows a profile, and no
/// two overlap along Z (roughing passes go over the same length again, each deeper).
fn pieces_of_one_contour(runs: &[Vec<Move>]) -> bool {
    let spans: Vec<(f64, f64)> = runs
        .iter()
        .map(|r| r.iter().flat_map(|m| [m.from[2], m.to[2]]).fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| (a.min(z), b.max(z))))
        .collect();
    let apart = spans.iter().enumerate().all(|(i, a)| spans[i + 1..].iter().all(|b| a.1.min(b.1) - a.0.max(b.0) <= TOL));
    apart && runs.iter().any(|r| pass_way(r) == Way::Profile)
}

/// Whether a run of cuts follows the contour over (nearly) the whole length `length` the
/// workingstep cuts: several moves or arcs, no one straight way most of it.
fn whole_contour(run: &[Move], length: f64) -> bool {
    let zs = run.iter().flat_map(|m| [m.from[2], m.to[2]]);
    let (lo, hi) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| (a.min(z), b.max(z)));
    pass_way(run) == Way::Profile && hi - lo >= 0.8 * length
}

/// Whether the passes, as CAM posts and turners write them, pull off the wall towards the
/// axis: each pass ends with a short move back along +Z that also moves X, outwards after
/// an outside pass and inwards after a bore's. Only where every pull-off goes inwards.
fn pulls_off_inward(runs: &[Vec<Move>]) -> bool {
    let pulls: Vec<f64> = runs
        .iter()
        .filter_map(|r| {
            let m = r.last()?;
            let (dx, dz) = (m.to[0] - m.from[0], m.to[2] - m.from[2]);
            (r.len() > 1 && dz > TOL && dx.abs() > TOL && dx.hypot(dz) < 2.0).then_some(dx)
        })
        .collect();
    !pulls.is_empty() && pulls.iter().all(|dx| *dx < 0.0)
}

/// Whether the passes are left towards the axis, as a boring bar leaves the wall it cut (an
/// outside tool leaves it away from the axis): the move after each run's last cut (or that
/// cut, a short pull-off), straight in X, goes to a smaller diameter short of the axis more
/// often than to a larger one; or, after a cut along a wall, a rapid back out along +Z pulls
/// in off it by at most 1 mm (where no cut reaches the axis).
fn left_inward(ws: &Workingstep) -> bool {
    let cut = |m: &Move| m.phase == Phase::Cut && m.kind != MoveKind::Rapid;
    let radial = |m: &Move| (m.to[2] - m.from[2]).abs() < TOL && (m.to[0] - m.from[0]).abs() > TOL && m.from[0] > TOL;
    let moves: Vec<Move> = ws.toolpath.iter().collect();
    // (A workingstep cutting to the axis has no bore wall to pull off.)
    let clear_of_axis = moves.iter().filter(|m| cut(m)).all(|m| m.from[0].min(m.to[0]) > 0.05);
    let (mut inward, mut outward) = (0, 0);
    for (i, w) in moves.windows(2).enumerate() {
        let (last, next) = (&w[0], &w[1]);
        if !cut(last) || cut(next) {
            continue;
        }
        if radial(next) {
            if next.to[0] < next.from[0] && next.to[0] > TOL {
                inward += 1;
            } else if next.to[0] > next.from[0] {
                outward += 1;
            }
            continue;
        }
        // Left by a rapid back along +Z out of the work that pulls in off the wall it cut,
        // after a cut along that wall (`G0 X44.5 Z10` after a bore Ø45 to Z-58, `G0 X2.375
        // Z.05` after a bore Ø2.6 to Z-.825): a boring bar leaving the bore it cut, by however
        // much, short of the axis; an outside tool leaving so would run through the part it
        // turned.
        let wall = (last.to[0] - last.from[0]).abs() < TOL && last.to[2] < last.from[2] - TOL && clear_of_axis;
        let pull = next.from[0] - next.to[0];
        if wall && next.kind == MoveKind::Rapid && next.to[2] > next.from[2] + TOL && pull > TOL && next.to[0] > TOL {
            inward += 1;
            continue;
        }
        // Left along Z, the run's last cut may itself pull in straight along X by feed, a
        // little (at most 2 mm on the radius), after a longer cut towards -Z. (A short cut out
        // in X there tells nothing: an outside pass's pull-up, or a bore's bottom faced out.)
        let before = i.checked_sub(1).and_then(|k| moves.get(k)).filter(|m| cut(m));
        let pull = last.from[0] - last.to[0];
        if radial(last)
            && pull > TOL
            && pull <= 2.0
            && last.to[0] > TOL
            && before.is_some_and(|b| (b.to[0] - b.from[0]).abs() < TOL && b.to[2] - b.from[2] < -pull)
        {
            inward += 1;
        }
    }
    inward > 0 && inward > outward
}

/// A groove profiled from both sides: passes that each come down a flank to the same bottom
/// diameter (the smallest cut) and run along it, one coming from +Z and one from -Z, their
/// runs along the bottom meeting. The bottom's radius and the Z span of the passes.
fn profiled_groove(runs: &[Vec<Move>]) -> Option<(f64, f64, f64)> {
    if runs.len() < 2 {
        return None;
    }
    let bottom = runs.iter().flatten().flat_map(|m| [m.from[0], m.to[0]]).fold(f64::INFINITY, f64::min);
    let (mut from_above, mut from_below) = (None::<(f64, f64)>, None::<(f64, f64)>);
    for r in runs {
        let Some(first) = r.first() else { continue };
        // The run along the bottom, and where the run came from.
        let along: Vec<&Move> =
            r.iter().filter(|m| (m.to[0] - bottom).abs() < 0.01 && (m.from[0] - bottom).abs() < 0.01 && m.arc.is_none()).collect();
        let (Some(a), Some(b)) = (along.first(), along.last()) else { continue };
        let (lo, hi) = (a.from[2].min(b.to[2]), a.from[2].max(b.to[2]));
        let came_down = first.from[0] > bottom + 0.5;
        if !came_down || hi - lo < TOL {
            continue;
        }
        let span = |o: Option<(f64, f64)>| Some(o.map_or((lo, hi), |(l, h)| (l.min(lo), h.max(hi))));
        if first.from[2] > hi + TOL {
            from_above = span(from_above);
        } else if first.from[2] < lo - TOL {
            from_below = span(from_below);
        }
    }
    let ((la, ha), (lb, hb)) = (from_above?, from_below?);
    // The two bottoms touch: one recess, not two.
    if la > hb + TOL || lb > ha + TOL {
        return None;
    }
    let zs = runs.iter().flatten().flat_map(|m| [m.from[2], m.to[2]]);
    let (zlo, zhi) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| (a.min(z), b.max(z)));
    Some((bottom, zlo, zhi))
}

/// One pass that feeds in along Z at its diameter and then cuts across to the axis: a face
/// with its lead-in (LinuxCNC's one-pass `G72`, a post's facing pass), the run across being
/// most of the cut.
/// Moves at a feed `air` tells (a positioning feed many times the cutting feed) count for
/// nothing; the pass may go back out along the face it cut (`X0.` then `X60.`). Clear of the
/// axis, a boring bar's lead-in and its one cut out across from the bore face too, where the
/// tool is a boring tool or the lead-in ends at the part's front (`front`): an outside tool
/// fed along Z into the stock and then out across turns a diameter and its shoulder
/// (`G1 Z-2.` at Ø20, then `X40.`), the lead-in being the cut. So does an outside tool's
/// lead-in down to the front and one cut in across, short of the axis.
fn face_with_lead_in(runs: &[Vec<Move>], xmin: f64, air: &dyn Fn(&Move) -> bool, front: f64, boring: bool) -> bool {
    let [run] = runs else { return false };
    let across_x = |m: &&Move| (m.to[2] - m.from[2]).abs() < TOL;
    let across: f64 = run.iter().filter(|m| !air(m)).filter(across_x).map(|m| (m.to[0] - m.from[0]).abs()).sum();
    let total: f64 = run.iter().filter(|m| !air(m)).map(|m| (m.to[0] - m.from[0]).hypot(m.to[2] - m.from[2])).sum();
    // Across towards the axis, or over it from the far side (a tool working at X negative
    // faces from there to the centre or past it, whatever the sign).
    let inwards = |m: &Move| m.to[0].abs() < m.from[0].abs() || m.to[0] * m.from[0] < 0.0;
    let to_axis = |m: &Move| m.to[0].abs() < 0.05 || m.to[0] * m.from[0] < 0.0;
    let ends_inward = run.last().is_some_and(|m| across_x(&m) && inwards(m));
    let reaches = run.iter().filter(|m| !air(m)).filter(across_x).any(|m| inwards(m) && to_axis(m));
    // Or, clear of the axis, a lead-in along Z then one cut out across from the bore: a boring
    // bar facing the front out from the hole it stands in (the face out from Ø1.8 to Ø3.0 after
    // `G1 Z0.` at Ø1.8), as a turning tool faces in to the axis.
    // And a lead-in along Z down to the part's front then one cut in across towards the axis,
    // stopping short of it: the front faced from outside in where the centre is left (a tube,
    // a ring, a centre drilled and bored later: `G1 Z0` at Ø5.525, then `X3.5`).
    let (out_of_the_bore, in_short_of_the_axis) = match run.iter().filter(|m| !air(m)).collect::<Vec<_>>().as_slice() {
        [lead, cut] if (lead.to[0] - lead.from[0]).abs() < TOL && lead.to[2] < lead.from[2] - TOL && across_x(cut) => (
            cut.to[0] > cut.from[0] + TOL && (boring || lead.to[2] >= front - TOL),
            cut.to[0].abs() < cut.from[0].abs() - TOL && lead.to[2] >= front - TOL,
        ),
        _ => (false, false),
    };
    let mostly = total > TOL && across >= 0.75 * total - TOL;
    mostly && ((xmin < 0.05 && (ends_inward || reaches)) || (xmin >= 0.05 && (out_of_the_bore || in_short_of_the_axis)))
}

/// The features a workingstep machines, with the Z they are placed at.
fn features_of(ws: &Workingstep, tool_width: Option<f64>, face: f64) -> Vec<(FeatureKind, f64)> {
    let Some(t) = ws.turning.as_deref() else { return Vec::new() };
    let cuts = cuts(ws);
    let (Some(d), Some(z)) = (t.diameter, t.z) else { return Vec::new() };
    let turned = |k: Turned| FeatureKind::Turned(k);
    // A contour cycle a grooving tool runs: the groove its finishing cycle leaves, at the
    // contour's smallest diameter (its width is the tool's path, not stated: none given); the
    // roughing cycle's is the finish's, as for any roughing.
    let intent_kind = t.intent.as_ref().and_then(|i| i.kind);
    if t.operation == Some(TurnOp::Grooving) && matches!(intent_kind, Some(TurnKind::RoughTurn | TurnKind::Finish)) {
        if t.rough {
            return Vec::new();
        }
        let k = Turned::Groove { diameter: if t.inside { d[1] } else { d[0] }, width: None, inside: t.inside };
        // The rounds its contour programs are the part's too (a concave flank's arc).
        let rounds =
            contour_features(ws, t, face).into_iter().filter(|(k, _)| matches!(k, FeatureKind::Turned(Turned::RevolvedRound { .. })));
        return std::iter::once((turned(k), round(z[1]))).chain(rounds).collect();
    }
    // A contour cycle's features are its contour's, whichever way it cuts.
    if matches!(intent_kind, Some(TurnKind::RoughTurn | TurnKind::RoughFace | TurnKind::Finish)) {
        return contour_features(ws, t, face);
    }
    match t.operation {
        Some(TurnOp::Facing) => {
            // The face the last pass leaves.
            // The face the last pass leaves: the last that reaches the axis, where some do (the
            // passes after it only clear a chamfer's corner behind the face).
            let across = || cuts.iter().filter(|m| (m.to[2] - m.from[2]).abs() < TOL);
            let to_axis = across().filter(|m| m.from[0].min(m.to[0]) < 0.05).map(|m| m.to[2]).next_back();
            let last = to_axis.or_else(|| across().map(|m| m.to[2]).next_back()).unwrap_or(z[0]);
            let allow = t.intent.as_ref().and_then(|i| i.allowance_z).unwrap_or(0.0);
            vec![(turned(Turned::RevolvedFlat { outer: d[1], inner: d[0] }), round(last - allow))]
        }
        // A face groove profiled from both walls: from wall to wall at its floor.
        Some(TurnOp::Grooving) if face_groove(&runs(ws)).is_some() => {
            let Some((z, lo, hi)) = face_groove(&runs(ws)) else { return Vec::new() };
            let k = Turned::FaceGroove { outer: round(2.0 * hi), inner: round(2.0 * lo) };
            vec![(turned(k), round(z))]
        }
        // A face groove plunged along -Z (`G74`, a face grooving tool's plunges): roughing
        // passes leave what the same tool's finish makes (none: `unfinished`).
        Some(TurnOp::Grooving) if !t.inside && face_plunges(ws).is_some() => {
            if t.rough {
                return Vec::new();
            }
            plunged_face_groove(ws)
        }
        Some(TurnOp::Grooving) | Some(TurnOp::PartingOff) => {
            let plunge_z = cuts.iter().map(|m| m.to[2]);
            let (lo, hi) = plunge_z.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), v| (a.min(v), b.max(v)));
            // A cycle that states the groove's edges gives its width; else the plunges' span
            // and the tool's width.
            // A groove profiled from both sides: from flank to flank.
            // So is one whose passes plunge and finish its flanks (`one_groove`).
            let span = t
                .intent
                .as_ref()
                .and_then(|i| i.span)
                .or_else(|| profiled_groove(&runs(ws)).map(|(_, lo, hi)| [lo, hi]))
                .or_else(|| groove_passes(ws, None).filter(|g| g.profiled).map(|g| [g.lo, g.hi]));
            let width = match span {
                Some([lo, hi]) => Some(round(hi - lo)),
                None => tool_width.map(|w| round(hi - lo + w)),
            };
            let hi = span.map_or(hi, |s| s[1]);
            if t.operation == Some(TurnOp::PartingOff) {
                return Vec::new();
            }
            let diameter = if t.inside { d[1] } else { d[0] };
            vec![(turned(Turned::Groove { diameter, width, inside: t.inside }), hi)]
        }
        Some(TurnOp::Threading) => {
            let pitch = t.pitch.or_else(|| t.intent.as_ref().and_then(|i| i.pitch)).unwrap_or(0.0);
            let root = if t.inside { d[1] } else { d[0] };
            let height = t.intent.as_ref().and_then(|i| i.thread_depth);
            let diameter = height.map(|h| round(if t.inside { root - 2.0 * h } else { root + 2.0 * h }));
            // The last pass: the run-in of the passes before shifts along the flank. Its cut
            // along Z runs on through a tapered run-out (LinuxCNC's `G76 E L2`, a chamfered
            // pull-out): the thread ends where the pass leaves the work, not where the taper
            // starts.
            let along = |m: &Move| (m.to[2] - m.from[2]).abs() > TOL;
            let last =
                runs(ws).into_iter().rev().find_map(|r| {
                    let first = r.iter().position(along)?;
                    let span = r[first..].iter().take_while(|m| along(m));
                    Some(span.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), m| {
                        (a.min(m.from[2].min(m.to[2])), b.max(m.from[2].max(m.to[2])))
                    }))
                });
            // Its run-in in front of the face (Z0) is air.
            let (lo, hi) = last.unwrap_or((z[0], z[1]));
            let hi = if lo < 0.0 { hi.min(0.0) } else { hi };
            // A cycle that states the thread's start and end gives its length.
            let (length, at) = match t.intent.as_ref().and_then(|i| i.span) {
                Some([lo, hi]) => (hi - lo, hi),
                None => (hi - lo, hi),
            };
            vec![(turned(Turned::Thread { diameter, root, pitch, length: round(length), inside: t.inside }), round(at))]
        }
        Some(TurnOp::Drilling) => {
            vec![(
                FeatureKind::RoundHole { diameter: tool_width, bottom: HoleBottom::Flat, positions: vec![[0.0, 0.0]], heights: Vec::new() },
                z[1],
            )]
        }
        Some(TurnOp::Contouring) => contour_features(ws, t, face),
        None => Vec::new(),
    }
}

/// The features of a contour: the finishing pass, or a roughing cycle's last pass moved back
/// by its allowances. Explicit roughing passes leave no finished shape of their own.
fn contour_features(ws: &Workingstep, t: &Turning, face: f64) -> Vec<(FeatureKind, f64)> {
    let runs = runs(ws);
    // Passes each along the whole contour (a finish and its spring pass, LinuxCNC's `G70 P2`
    // closing in on the contour): the last is the part's.
    let zs = runs.iter().flatten().flat_map(|m| [m.from[2], m.to[2]]);
    let (zlo, zhi) = zs.fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), z| (a.min(z), b.max(z)));
    let finished = || match runs.as_slice() {
        [.., last] if runs.len() > 1 && runs.iter().all(|r| whole_contour(r, zhi - zlo)) => last.clone(),
        _ => runs.concat(),
    };
    let (profile, shift) = match t.intent.as_ref().and_then(|i| i.kind) {
        Some(TurnKind::Finish) => (finished(), (0.0, 0.0)),
        // Stock left all round (LinuxCNC's D) is no shift along X and Z: the finishing
        // pass gives the features.
        Some(TurnKind::RoughTurn | TurnKind::RoughFace)
            if t.intent.as_ref().is_some_and(|i| i.finish_allowance.is_some_and(|d| d > TOL) && i.allowance_x.is_none()) =>
        {
            return Vec::new();
        }
        Some(TurnKind::RoughTurn | TurnKind::RoughFace) => {
            let i = t.intent.as_ref();
            // On moves mirrored about the axis, the program's allowance along X points the
            // other way.
            let ax = i.and_then(|i| i.allowance_x).unwrap_or(0.0) / 2.0 * if t.mirrored { -1.0 } else { 1.0 };
            let az = i.and_then(|i| i.allowance_z).unwrap_or(0.0);
            (runs.last().cloned().unwrap_or_default(), (ax, az))
        }
        None if !t.rough => (finished(), (0.0, 0.0)),
        _ => return Vec::new(),
    };
    // The part on the other side of its face (the counter-spindle's, its Z running into the
    // part towards +Z): the contour read mirrored about the face, its features put back.
    let reversed = works_towards_plus_z(&profile, face);
    let (profile, shift) =
        if reversed { (profile.iter().map(|m| mirror_z(m, face)).collect(), (shift.0, -shift.1)) } else { (profile, shift) };
    let place = |z: f64| if reversed { round(2.0 * face - z) } else { z };
    // Mirrored along Z, an arc turns the other way, as on moves mirrored about the axis.
    let nose = if reversed { nose_arcs(ws, &Turning { mirrored: !t.mirrored, ..t.clone() }, &profile) } else { nose_arcs(ws, t, &profile) };
    let mut out = contour_profile_features(t, &profile, shift, nose, face);
    for (_, z) in &mut out {
        *z = place(*z);
    }
    out
}

/// Whether a contour works a part lying on the +Z side of its face, as a counter-spindle's
/// (sub-spindle's) second operation is written: there the spindle faces the main one and its
/// Z runs into the part towards +Z (the Doosan Lynx and other Fanuc sub-spindle lathes' `G55`
/// programs; their roughing cycles' Z allowance `W` is negative for it). Told by the contour's
/// runs along Z: none runs towards -Z, and those lying wholly in front of the face (Z above
/// it) cut more than half a millimetre towards +Z. On the main spindle a contour runs along its
/// diameters towards -Z, the way into the part.
fn works_towards_plus_z(profile: &[Move], face: f64) -> bool {
    let along = || profile.iter().filter(|m| m.arc.is_none() && (m.to[0] - m.from[0]).abs() < TOL && (m.to[2] - m.from[2]).abs() > TOL);
    let towards_minus = along().any(|m| m.to[2] < m.from[2]);
    let front: f64 = along().filter(|m| m.from[2].min(m.to[2]) > face - TOL).map(|m| m.to[2] - m.from[2]).sum();
    !towards_minus && front > 0.5
}

/// A move mirrored along Z about the face.
fn mirror_z(m: &Move, face: f64) -> Move {
    let mut m = *m;
    m.from[2] = 2.0 * face - m.from[2];
    m.to[2] = 2.0 * face - m.to[2];
    if let Some(a) = m.arc.as_mut() {
        a.center[2] = 2.0 * face - a.center[2];
        // A mirror turns the arc the other way: its axis is the mirrored one, reversed.
        a.axis = [-a.axis[0], -a.axis[1], a.axis[2]];
    }
    m
}

/// The features of a contour's profile, the part behind its face (towards -Z).
fn contour_profile_features(
    t: &Turning,
    profile: &[Move],
    shift: (f64, f64),
    nose: Option<(f64, f64)>,
    face: f64,
) -> Vec<(FeatureKind, f64)> {
    let mut out = Vec::new();
    for (i, m) in profile.iter().enumerate() {
        let (x0, x1) = (m.from[0] - shift.0, m.to[0] - shift.0);
        let (z0, z1) = (m.from[2] - shift.1, m.to[2] - shift.1);
        if let Some(a) = m.arc {
            let mut r = (m.from[0] - a.center[0]).hypot(m.from[2] - a.center[2]);
            if let Some((nose, sense)) = nose {
                // The nose going round a sharp corner of the contour: no round of the part.
                if (r - nose).abs() < 0.01 {
                    continue;
                }
                // A programmed round: the nose's path runs a nose radius outside it where it
                // turns as the nose does round the corners (convex), inside where not.
                r = if arc_sense(m) == sense { r - nose } else { r + nose };
            }
            out.push((
                FeatureKind::Turned(Turned::RevolvedRound { radius: round(r), diameter: round(2.0 * x0.max(x1)) }),
                round(z0.max(z1)),
            ));
        } else if (x1 - x0).abs() < TOL && z0.min(z1) > face - TOL {
            // In front of the face (Z0, where lathe programs put it, or where the program
            // faced it): the lead-in from the cycle's start, in air.
            continue;
        } else if (x1 - x0).abs() < TOL && z1 > z0 && z1 > face + TOL && shift != (0.0, 0.0) {
            // A roughing cycle's last pass running back along +Z out past the face: the
            // contour's way back to the start point (its closing `G00`), no diameter.
            continue;
        } else if let Some((width, hi)) = (shift == (0.0, 0.0) && !t.inside && !t.mirrored).then(|| recess(profile, i)).flatten() {
            let k = Turned::Groove { diameter: round(2.0 * x0), width: Some(round(width)), inside: false };
            out.push((FeatureKind::Turned(k), round(hi)));
        } else if (x1 - x0).abs() < TOL && (z1 - z0).abs() > 0.5 && x0 > TOL {
            // What runs on in front of the face is the lead-in.
            let (lo, hi) = (z0.min(z1), z0.max(z1).min(face));
            let k = Turned::Diameter { diameter: round(2.0 * x0), length: round(hi - lo), inside: t.inside };
            out.push((FeatureKind::Turned(k), round(hi)));
        } else if (z1 - z0).abs() < TOL && (x1 - x0).abs() > 0.5 && z0 < face + TOL {
            let k = Turned::RevolvedFlat { outer: round(2.0 * x0.max(x1)), inner: round(2.0 * x0.min(x1).max(0.0)) };
            out.push((FeatureKind::Turned(k), round(z0)));
        }
    }
    out
}

/// A recess in an outside finishing contour (an undercut, a relief groove): the move at
/// `i` runs along -Z at a diameter the contour came down to from a larger one and climbs out
/// of to a larger one, after which the contour goes on along Z. A turning tool cannot leave
/// such a dip where the contour only steps outwards, so it is a groove the finish profiles,
/// as grooving and finishing posts write undercuts, not a diameter. Its width is taken
/// between the walls where they leave the larger diameters; the Z of its front edge with it.
/// A pass that climbs out and leaves the work (a partial pass over the recess alone) tells no
/// recess: what lies beyond it is not cut.
fn recess(profile: &[Move], i: usize) -> Option<(f64, f64)> {
    let m = &profile[i];
    if (m.to[0] - m.from[0]).abs() >= TOL || m.to[2] > m.from[2] - 0.1 {
        return None;
    }
    // Down into it: the moves before, each coming down in X without going back along Z.
    let down = |p: &Move| p.to[0] < p.from[0] - TOL && p.to[2] <= p.from[2] + TOL;
    let up = |p: &Move| p.to[0] > p.from[0] + TOL && p.to[2] <= p.from[2] + TOL;
    let before = profile[..i].iter().rev().take_while(|p| down(p)).last()?;
    let after: Vec<&Move> = profile[i + 1..].iter().take_while(|p| up(p)).collect();
    let out = after.last()?;
    // The contour goes on along -Z past the recess.
    let next = profile.get(i + 1 + after.len())?;
    let on = next.to[2] < next.from[2] - TOL && (next.to[0] - next.from[0]).abs() < (next.from[2] - next.to[2]);
    let depth = before.from[0].min(out.to[0]) - m.from[0];
    (on && depth > 0.1).then_some((before.from[2] - out.to[2], before.from[2]))
}

/// Under tool nose radius compensation (G41/G42 on a lathe) the moves are the nose's path,
/// not the contour the program states: the control goes round each sharp outside corner on an
/// arc of the nose radius and runs a nose radius outside (or inside) each programmed round.
/// The part's shape is the program's, so the nose radius and the sense the nose turns at an
/// outside corner are wanted. The radius is the one compensation ran at (the block's
/// `G42.1 D0.8`, the tool table's), where the interpreter knew it; the sense that of the
/// path's arcs of that radius, else the side's (a nose on the left of its way turns right
/// round an outside corner). Where the radius is not known, both are taken from the path: its
/// smallest arcs, when no larger than an insert's nose (ISO 1832: 0.1 to 2.4 mm), all turning
/// one way round outside corners (the side's sense), and when the path has an arc of another
/// radius or at least two of them. None without compensation.
fn nose_arcs(ws: &Workingstep, t: &Turning, profile: &[Move]) -> Option<(f64, f64)> {
    if ws.state.cutter_comp.is_empty() {
        return None;
    }
    let radius = |m: &Move| m.arc.map(|a| (m.from[0] - a.center[0]).hypot(m.from[2] - a.center[2]));
    if let Some((nose, left)) = t.nose {
        let corner = profile.iter().find(|m| radius(m).is_some_and(|r| (r - nose).abs() < 0.01));
        let side = if left == t.mirrored { 1.0 } else { -1.0 };
        return Some((nose, corner.map_or(side, arc_sense)));
    }
    let smallest = profile.iter().filter_map(|m| radius(m).map(|r| (r, m))).min_by(|a, b| a.0.total_cmp(&b.0))?;
    let sense = arc_sense(smallest.1);
    let nose: Vec<&Move> = profile.iter().filter(|m| radius(m).is_some_and(|r| (r - smallest.0).abs() < 0.01)).collect();
    let other = profile.iter().filter_map(radius).any(|r| (r - smallest.0).abs() >= 0.01);
    // The nose goes round outside corners only, so its arcs all turn one way; small arcs
    // turning both ways are the program's rounds (the control had no radius to offset by).
    let one_way = nose.iter().all(|m| arc_sense(m) == sense);
    // And round outside corners only: a nose on the left of its way turns right there (as
    // above). Small arcs turning the other way, into the material, are the program's fillets
    // (`G02 X14 Z-15 R2` into a shoulder under `G42`): the path is the programmed contour.
    let sides: Vec<bool> = ws.state.cutter_comp.iter().map(|c| c.left).collect();
    let convex = match sides.split_first() {
        Some((&left, rest)) if rest.iter().all(|&l| l == left) => sense == if left == t.mirrored { 1.0 } else { -1.0 },
        _ => true,
    };
    (smallest.0 <= 2.4 + TOL && one_way && convex && (nose.len() >= 2 || other)).then_some((smallest.0, sense))
}

/// The sense an arc turns in the plane of the part's profile (+1 or -1).
fn arc_sense(m: &Move) -> f64 {
    m.arc.map_or(0.0, |a| a.axis[1].signum() * f64::from(a.turns.signum()))
}

/// A size rounded to the micrometre, so that features from two passes compare equal (and a
/// size reads back as written).
fn round(v: f64) -> f64 {
    (v * 1000.0).round() / 1000.0 + 0.0
}

/// A turning workingstep in a turner's words: the operation, its cycle's values, the feed
/// per revolution, the cutting speed and its clamp, diameters and Z.
pub fn words(ws: &Workingstep) -> Option<String> {
    let t = ws.turning.as_deref()?;
    t.operation?;
    // The operation as the workingstep names it (`contouring rough inside`).
    let mut parts = vec![ws.label()];
    if let Some(c) = &t.cycle {
        parts.push(format!("cycle {c}"));
    }
    if let Some(i) = &t.intent {
        if let (Some(u), Some(w)) = (i.allowance_x, i.allowance_z) {
            parts.push(format!("finishing allowance U{} W{}", num(u), num(w)));
        }
        if let Some(d) = i.depth_of_cut {
            parts.push(format!("depth of cut {}", num(d)));
        }
        if let Some(r) = i.retract {
            parts.push(format!("retract {}", num(r)));
        }
        // A pattern repeating cycle (Fanuc `G73`): how far its first pass lies off the
        // contour (U per side, W) and in how many passes it comes in, as the diff names them.
        if let Some([u, w]) = i.relief {
            parts.push(format!("pattern relief U{} W{}", num(u), num(w)));
        }
        if let Some(n) = i.divisions {
            parts.push(format!("pattern passes {n}"));
        }
        if let Some(h) = i.thread_depth {
            parts.push(format!("thread height {}", num(h)));
        }
        if let Some(a) = i.angle {
            parts.push(format!("angle {}°", num(a)));
        }
        if let Some(p) = i.peck {
            parts.push(format!("peck {}", num(p)));
        }
    }
    if let Some(p) = t.pitch.or_else(|| t.intent.as_ref().and_then(|i| i.pitch)) {
        parts.push(format!("pitch {} (spindle synchronised)", num(p)));
    }
    parts.push(format!("{} passes", t.passes));
    if let Some(f) = t.feed_per_rev {
        parts.push(format!("F{} mm/rev", num(f)));
    }
    let tech = &ws.technology;
    match (tech.surface_speed, t.spindle_limit) {
        (Some(v), Some(l)) => parts.push(format!("cutting speed {} m/min, spindle clamp {} /min", num(v), num(l))),
        (Some(v), None) => parts.push(format!("cutting speed {} m/min", num(v))),
        _ => parts.push(format!("S{} /min", num(tech.spindle_speed))),
    }
    if let (Some(d), Some(z)) = (t.diameter, t.z) {
        parts.push(format!("Ø{}..Ø{} Z{}..{}", num(d[0]), num(d[1]), num(z[0]), num(z[1])));
    }
    Some(parts.join(", "))
}

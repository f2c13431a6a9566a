//! The rules' tests: planted changes found, decoys held back, and properties of the gates.

use proptest::prelude::*;

use super::review::{CamStep, Event, State, Watch, carried, current, watch, watch_move};
use super::*;

fn tool() -> ToolKey {
    ToolKey { number: 5, description: "EM10 Z4".into(), diameter: Some(10.0), flutes: Some(4), corner_radius: None }
}

/// An edit of the cutting feed of T5 on M1, on day `day` of 2026, in program `p`.
fn edit(id: i64, day: i64, p: u32, before: f64, after: f64) -> Edit {
    let (m, d) = (1 + day / 28, 1 + day % 28);
    Edit {
        change_id: id,
        revision_id: 100 + id,
        program: format!("P{p}"),
        original: format!("/cam/P{p}.nc"),
        workingstep: 1,
        operation: "bottom and side rough milling".into(),
        machine: "M1".into(),
        at: format!("2026-{m:02}-{d:02}T08:00:00Z"),
        operator: None,
        spindle: Some(8000.0),
        tool: tool(),
        material: "AL6061".into(),
        parameter: Parameter::CuttingFeed,
        before,
        after,
    }
}

/// A true change of -30 % with noise, 8 edits in 4 programs over 8 weeks.
fn planted() -> Vec<Edit> {
    let noise = [0.02, -0.01, 0.0, 0.015, -0.02, 0.01, -0.005, 0.0];
    (0..8).map(|i| edit(i, i * 7, (i % 4) as u32, 800.0, 800.0 * (0.7 + noise[i as usize]))).collect()
}

#[test]
fn a_planted_change_is_suggested_within_its_interval() {
    let s = suggest(&planted(), &Rules::default());
    assert_eq!(s.len(), 1);
    let s = &s[0];
    assert!(s.passed(), "{:?}", s.held);
    assert_eq!(s.cam_value, 800.0);
    assert!(s.interval.0 <= s.suggested && s.suggested <= s.interval.1);
    // The shrunk estimate is cautious: between the CAM value and the operators' median.
    assert!(s.suggested > 560.0 && s.suggested < 800.0, "{}", s.suggested);
    assert_eq!((s.agree, s.disagree, s.programs, s.days), (8, 0, 4, 8));
    assert!(s.p < 0.01);
}

#[test]
fn one_operators_bad_day_makes_no_suggestion() {
    let edits: Vec<Edit> = (0..10).map(|i| edit(i, 30, (i % 5) as u32, 800.0, 500.0)).collect();
    let s = &suggest(&edits, &Rules::default())[0];
    assert!(!s.passed());
    assert!(matches!(&s.held[0], Held::TooFew { what } if what.starts_with("days")), "{:?}", s.held);
}

#[test]
fn one_operators_bad_week_makes_no_suggestion() {
    let edits: Vec<Edit> = (0..8).map(|i| edit(i, 60 + i % 5, (i % 3) as u32, 800.0, 520.0)).collect();
    let s = &suggest(&edits, &Rules::default())[0];
    assert!(!s.passed());
    assert!(s.held.iter().any(|h| matches!(h, Held::TooFew { .. })));
}

#[test]
fn two_operators_count_where_the_share_names_them() {
    let mut edits: Vec<Edit> = (0..8).map(|i| edit(i, 60 + i % 5, (i % 3) as u32, 800.0, 520.0)).collect();
    for (i, e) in edits.iter_mut().enumerate() {
        e.operator = Some(if i % 2 == 0 { "anna" } else { "ben" }.into());
    }
    assert!(suggest(&edits, &Rules::default())[0].passed());
}

#[test]
fn a_reversal_in_the_latest_edits_blocks() {
    let mut edits = planted();
    edits.push(edit(20, 70, 1, 800.0, 820.0));
    let s = &suggest(&edits, &Rules::default())[0];
    assert!(matches!(s.held.as_slice(), [Held::Reversal { edits }] if edits == &[20]), "{:?}", s.held);
}

#[test]
fn outliers_are_dropped_and_said_so() {
    let mut edits = planted();
    edits.push(edit(30, 10, 2, 800.0, 3200.0));
    edits.push(edit(31, 11, 2, 800.0, 0.0));
    let s = &suggest(&edits, &Rules::default())[0];
    assert!(s.passed(), "{:?}", s.held);
    assert_eq!(s.edits.len(), 8);
    let out: Vec<(i64, &LeftOut)> = s.left_out.iter().map(|(e, w)| (e.change_id, w)).collect();
    assert_eq!(out.len(), 2);
    assert!(out.iter().any(|(id, w)| *id == 31 && **w == LeftOut::NoRatio));
    assert!(out.iter().any(|(id, w)| *id == 30 && matches!(w, LeftOut::Outlier { mads } if *mads > 3.0)));
}

#[test]
fn a_small_effect_is_held_back() {
    let edits: Vec<Edit> = (0..8).map(|i| edit(i, i * 7, (i % 4) as u32, 800.0, 760.0)).collect();
    let s = &suggest(&edits, &Rules::default())[0];
    assert!(matches!(s.held.as_slice(), [Held::Small { .. }]), "{:?}", s.held);
}

#[test]
fn a_height_is_measured_by_its_offset() {
    let mut edits: Vec<Edit> = (0..8).map(|i| edit(i, i * 7, (i % 4) as u32, 5.0, 25.0)).collect();
    for e in &mut edits {
        e.parameter = Parameter::ClearanceHeight;
    }
    let s = &suggest(&edits, &Rules::default())[0];
    assert!(s.passed(), "{:?}", s.held);
    assert!(s.suggested > 5.0 && s.suggested <= 25.0);
    assert!(!s.key.parameter.of_tool());
}

#[test]
fn groups_are_kept_apart_by_machine_material_class_and_parameter() {
    let mut edits = planted();
    let mut other = planted();
    for e in &mut other {
        e.machine = "M2".into();
        e.change_id += 100;
    }
    edits.extend(other);
    let s = suggest(&edits, &Rules::default());
    assert_eq!(s.len(), 2);
    assert_ne!(s[0].id, s[1].id);
    assert_eq!(s[0].key.machine, "M1");
}

#[test]
fn numbers_and_materials_are_read_from_the_text() {
    assert_eq!(first_number("F800"), Some(800.0));
    assert_eq!(first_number("F800, F400"), Some(800.0));
    assert_eq!(first_number("Z-5."), Some(-5.0));
    assert_eq!(first_number("Q2.5 at X10 Y20"), Some(2.5));
    assert_eq!(first_number("120 m/min"), Some(120.0));
    assert_eq!(first_number("S.5"), Some(0.5));
    assert_eq!(first_number("none"), None);
    assert_eq!(header_material("%\nO1000 (BRACKET)\n(MATERIAL: AL6061-T6)\nG21", 10), Some("AL6061-T6".into()));
    assert_eq!(header_material("; Werkstoff = 1.4301\nG0", 10), Some("1.4301".into()));
    assert_eq!(header_material("(MACHINE MATERIAL HANDLING)\nG0", 10), None);
    assert_eq!(day_number("1970-01-01"), Some(0));
    assert_eq!(tool_description("T5 D=10. CR=0. - ZMIN=-2. - FLAT END MILL"), "FLAT END MILL");
    assert_eq!(tool_description("EM10 Z4 TiAlN"), "EM10 Z4 TiAlN");
    assert_eq!(days_between("2026-02-27", "2026-03-01"), 2);
}

fn event(state: State, evidence: i64, at: &str) -> Event {
    Event { suggestion: "x".into(), step: 1, state, reason: String::new(), value: 600.0, evidence, by: "p".into(), at: at.into() }
}

#[test]
fn a_rejection_holds_until_the_evidence_grows_and_a_snooze_until_it_ends() {
    let r = Rules::default();
    let rejected = [event(State::Rejected, 8, "2026-03-01T00:00:00Z")];
    assert_eq!(current(&rejected, 10, "2026-04-01T00:00:00Z", &r), State::Rejected);
    assert_eq!(current(&rejected, 11, "2026-04-01T00:00:00Z", &r), State::Proposed);
    let snoozed = [event(State::Snoozed, 8, "2026-03-01T00:00:00Z")];
    assert_eq!(current(&snoozed, 8, "2026-03-20T00:00:00Z", &r), State::Snoozed);
    assert_eq!(current(&snoozed, 8, "2026-04-01T00:00:00Z", &r), State::Proposed);
    assert_eq!(current(&[], 8, "2026-04-01T00:00:00Z", &r), State::Proposed);
}

#[test]
fn the_watch_adopts_a_post_that_carries_the_value_and_reopens_on_edits() {
    let r = Rules::default();
    let s = &suggest(&planted(), &r)[0];
    let since = "2026-03-15T00:00:00Z";
    let post =
        |v: f64, at: &str| CamStep { original: "/cam/P1.nc".into(), revision: 900, at: at.into(), workingstep: 1, tool: 5, value: Some(v) };
    let w = watch(s, since, &[], &[post(s.suggested, "2026-03-20T00:00:00Z")], &r);
    assert_eq!(w, Watch::Adopted { revision: 900, at: "2026-03-20T00:00:00Z".into() });
    assert_eq!(watch_move(State::Exported, &w), Some(State::Adopted));
    // The old value posted again is no adoption.
    assert_eq!(watch(s, since, &[], &[post(800.0, "2026-03-20T00:00:00Z")], &r), Watch::Waiting);
    let later = [edit(50, 90, 1, 800.0, 560.0), edit(51, 95, 2, 800.0, 560.0)];
    let w = watch(s, since, &later, &[post(s.suggested, "2026-03-20T00:00:00Z")], &r);
    assert_eq!(w, Watch::Reopened { edits: 2 });
    assert_eq!(watch_move(State::Adopted, &w), Some(State::Reopened));
}

#[test]
fn a_value_the_cam_took_up_on_its_own_is_no_suggestion() {
    let r = Rules::default();
    let edits = planted();
    let s = &suggest(&edits, &r)[0];
    assert!(s.passed());
    let post = |v: f64, at: &str, rev: i64| CamStep {
        original: "/cam/P1.nc".into(),
        revision: rev,
        at: at.into(),
        workingstep: 1,
        tool: 5,
        value: Some(v),
    };
    // After the last edit (day 49), the CAM posts the operators' 560: held.
    let operators = s.cam_value * s.centre.exp();
    assert_eq!(carried(s, &edits, &[post(operators, "2026-03-10T00:00:00Z", 901)], &r), Some((901, "2026-03-10T00:00:00Z".into())));
    assert_eq!(carried(s, &edits, &[post(s.suggested, "2026-03-10T00:00:00Z", 902)], &r).map(|c| c.0), Some(902));
    // Posted before the last edit, of another workingstep or tool, or the old value: not held.
    assert_eq!(carried(s, &edits, &[post(operators, "2026-02-10T00:00:00Z", 903)], &r), None);
    assert_eq!(carried(s, &edits, &[CamStep { workingstep: 2, ..post(operators, "2026-03-10T00:00:00Z", 904) }], &r), None);
    assert_eq!(carried(s, &edits, &[CamStep { tool: 6, ..post(operators, "2026-03-10T00:00:00Z", 905) }], &r), None);
    assert_eq!(carried(s, &edits, &[post(800.0, "2026-03-10T00:00:00Z", 906)], &r), None);
    // A program posted with the new value and another still with the old one: the CAM has
    // not taken it up.
    let other = CamStep { original: "/cam/P2.nc".into(), ..post(800.0, "2026-03-11T00:00:00Z", 907) };
    assert_eq!(carried(s, &edits, &[post(operators, "2026-03-10T00:00:00Z", 901), other], &r), None);
}

/// Edits of the feed with effects `fx` (fractions), on days `days`, in programs `ps`.
fn generated(fx: &[f64], days: &[i64], ps: &[u32]) -> Vec<Edit> {
    fx.iter().zip(days).zip(ps).enumerate().map(|(i, ((f, d), p))| edit(i as i64, *d, *p, 800.0, 800.0 * (1.0 + f))).collect()
}

proptest! {
    #[test]
    fn edits_of_one_day_never_make_a_suggestion(fx in prop::collection::vec(-0.6f64..0.6, 1..30), day in 0i64..300) {
        let n = fx.len();
        let edits = generated(&fx, &vec![day; n], &(0..n as u32).collect::<Vec<_>>());
        prop_assert!(suggest(&edits, &Rules::default()).iter().all(|s| !s.passed()));
    }

    #[test]
    fn a_suggestion_lies_in_its_interval_and_is_shrunk(
        fx in prop::collection::vec(-0.6f64..0.6, 1..30),
        days in prop::collection::vec(0i64..300, 30),
        ps in prop::collection::vec(0u32..6, 30),
    ) {
        let edits = generated(&fx, &days, &ps);
        for s in suggest(&edits, &Rules::default()) {
            prop_assert!(s.interval.0 <= s.suggested + 1e-9 && s.suggested <= s.interval.1 + 1e-9);
            // Never beyond the operators' median, never the other way.
            let median = s.cam_value * s.centre.exp();
            prop_assert!((s.suggested - s.cam_value) * (median - s.cam_value) >= -1e-9);
            if s.passed() {
                prop_assert!(s.edits.len() >= 5 && s.programs >= 2 && s.days >= 3);
                prop_assert!((s.agree as f64) >= 0.9 * (s.agree + s.disagree) as f64);
                prop_assert!((s.centre.exp() - 1.0).abs() >= 0.1);
            }
        }
    }

    #[test]
    fn a_small_effect_never_makes_a_suggestion(
        fx in prop::collection::vec(-0.09f64..0.09, 1..30),
        days in prop::collection::vec(0i64..300, 30),
        ps in prop::collection::vec(0u32..6, 30),
    ) {
        // Every edit within 9 %: the median effect is under the 10 % gate.
        prop_assert!(suggest(&generated(&fx, &days, &ps), &Rules::default()).iter().all(|s| !s.passed()));
    }

    #[test]
    fn the_latest_edits_going_back_always_hold(
        k in 6usize..25,
        f in 0.15f64..0.6,
        back in 0.05f64..0.6,
        up in any::<bool>(),
    ) {
        // `k` edits one way over months, then the rules' window of edits the other way.
        let sign = if up { 1.0 } else { -1.0 };
        let w = Rules::default().reversal_window;
        let mut fx = vec![sign * f; k];
        fx.extend(vec![-sign * back; w]);
        let days: Vec<i64> = (0..(k + w) as i64).map(|i| i * 7).collect();
        let ps: Vec<u32> = (0..(k + w) as u32).map(|i| i % 4).collect();
        let s = suggest(&generated(&fx, &days, &ps), &Rules::default());
        prop_assert!(s.iter().all(|s| !s.passed() && s.held.iter().any(|h| matches!(h, Held::Reversal { .. }))), "{:?}", s);
    }

    #[test]
    fn a_later_post_of_the_old_value_never_holds_as_taken_up(
        f in 0.15f64..0.5,
        rev in 1i64..1000,
    ) {
        let r = Rules::default();
        let edits = generated(&[-f; 8], &(0..8).map(|i| i * 7).collect::<Vec<_>>(), &(0..8).map(|i| i % 4).collect::<Vec<_>>());
        let s = &suggest(&edits, &r)[0];
        let post = |v: f64, day: u32, rev: i64| CamStep { original: "/cam/P1.nc".into(), revision: rev, at: format!("2026-06-{day:02}T00:00:00Z"), workingstep: 1, tool: 5, value: Some(v) };
        let new = s.cam_value * s.centre.exp();
        prop_assert!(carried(s, &edits, &[post(new, 1, rev)], &r).is_some());
        prop_assert!(carried(s, &edits, &[post(new, 1, rev), post(800.0, 2, rev + 1)], &r).is_none());
    }

    #[test]
    fn edits_that_split_both_ways_make_no_suggestion(k in 3usize..15, f in 0.15f64..0.6) {
        let mut fx = vec![f; k];
        fx.extend(vec![-f; k]);
        let days: Vec<i64> = (0..2 * k as i64).map(|i| i * 5).collect();
        let ps: Vec<u32> = (0..2 * k as u32).map(|i| i % 4).collect();
        prop_assert!(suggest(&generated(&fx, &days, &ps), &Rules::default()).iter().all(|s| !s.passed()));
    }
}

#[test]
fn a_fusion_library_is_read_in_both_forms_and_an_export_keeps_its_tools() {
    let older = r#"{"data":[{"guid":"a1","type":"flat end mill","description":"EM10 Z4","unit":"millimeters",
        "geometry":{"DC":10,"NOF":4,"RE":0},"post-process":{"number":5,"comment":""},
        "start-values":{"*":{"n":8000,"v_f":800,"v_f_plunge":300,"f_z":0.025}}}],"version":1}"#;
    let newer = r#"{"data":[{"guid":"b2","type":"flat end mill","description":"EM10 Z4","unit":"millimeters",
        "geometry":{"DC":10,"NOF":4,"RE":0},"post-process":{"number":5},
        "start-values":{"presets":[{"guid":"p1","name":"Aluminium","n":8000,"v_f":800,"expressions":{"tool_feedCutting":"800 mmpm"}}]}}],"version":15}"#;
    let s = &suggest(&planted(), &Rules::default())[0];
    for text in [older, newer] {
        let lib = library::read(text).unwrap();
        assert_eq!(lib.tools[0].number, Some(5));
        assert!(lib.tools[0].is(&s.key.tool));
        let out = library::export(Some(&lib), &[s]);
        let back = library::read(&out.to_string()).unwrap();
        let t = &back.tools[0];
        // Every original preset is there as it was, plus one.
        assert_eq!(t.presets[..lib.tools[0].presets.len()], lib.tools[0].presets[..]);
        assert_eq!(t.presets.len(), lib.tools[0].presets.len() + 1);
        let added = &t.presets.last().unwrap().1;
        assert!((library::preset_value(t, added, Parameter::CuttingFeed).unwrap() - s.suggested).abs() < 1e-3);
        // f_z follows v_f at the preset's spindle speed.
        assert!((added["f_z"] - s.suggested / (8000.0 * 4.0)).abs() < 1e-6);
        assert_ne!(t.raw["guid"], lib.tools[0].raw["guid"]);
        assert_eq!(out["version"], lib.version);
        let p = t.raw["start-values"]["presets"].as_array().unwrap().last().unwrap().clone();
        assert!(p.get("expressions").is_none());
        assert!(p["description"].as_str().unwrap().starts_with(&format!("ncplan {}", s.id)));
    }
}

/// A feed move from `from` to `to` at `feed`.
fn fm(from: [f64; 3], to: [f64; 3], feed: f64) -> FeedMove {
    FeedMove { from, to, feed }
}

#[test]
fn the_feeds_of_a_workingstep_are_told_apart_by_their_moves() {
    // A post's pocket: plunge to the top at F300, ramp down to depth at F400, cut at F800,
    // listed as the plan lists them (its technology feed, the first used, first).
    let moves = [
        fm([0.0, 0.0, 5.0], [0.0, 0.0, 0.0], 300.0),
        fm([0.0, 0.0, 0.0], [20.0, 0.0, -2.0], 400.0),
        fm([20.0, 0.0, -2.0], [100.0, 0.0, -2.0], 800.0),
        fm([100.0, 0.0, -2.0], [100.0, 20.0, -2.0], 800.0),
    ];
    let roles = feed_roles(&[300.0, 400.0, 800.0], &moves);
    assert_eq!(roles, [Some(FeedRole::Plunge), Some(FeedRole::Ramp), Some(FeedRole::Cutting)]);
    // The diff's `feed changed from F300, F400, F800 to F300, F250, F800`: a ramp's edit only.
    let ramp = feed_edits(&feed_list("F300, F400, F800"), &feed_list("F300, F250, F800"), &roles).unwrap();
    assert_eq!(ramp, [(Parameter::RampFeed, 400.0, 250.0)]);
    let cut = feed_edits(&feed_list("F300, F400, F800"), &feed_list("F300, F400, F560"), &roles).unwrap();
    assert_eq!(cut, [(Parameter::CuttingFeed, 800.0, 560.0)]);
    let both = feed_edits(&feed_list("F300, F400, F800"), &feed_list("F200, F400, F560"), &roles).unwrap();
    assert_eq!(both, [(Parameter::CuttingFeed, 800.0, 560.0), (Parameter::PlungeFeed, 300.0, 200.0)]);
    // A feed added or removed: which is which cannot be told.
    assert_eq!(feed_edits(&[300.0, 800.0], &[300.0, 400.0, 800.0], &roles), None);
    // A drill: every move goes straight down, at its one feed, which is its cutting feed.
    let drill = [fm([0.0, 0.0, 2.0], [0.0, 0.0, -12.0], 120.0)];
    assert_eq!(feed_roles(&[120.0], &drill), [Some(FeedRole::Cutting)]);
    // A 3D contour at one feed, down and level: the cutting feed.
    let contour = [fm([0.0, 0.0, 0.0], [5.0, 0.0, -1.0], 900.0), fm([5.0, 0.0, -1.0], [9.0, 0.0, -1.0], 900.0)];
    assert_eq!(feed_roles(&[900.0], &contour), [Some(FeedRole::Cutting)]);
    // Without the plan, one feed is the cutting feed; several have no role.
    assert_eq!(feed_edits(&[800.0], &[560.0], &[]), Some(vec![(Parameter::CuttingFeed, 800.0, 560.0)]));
    assert_eq!(feed_edits(&[300.0, 800.0], &[300.0, 560.0], &[]), Some(vec![]));
}

#[test]
fn an_operator_is_read_from_a_header_comment() {
    assert_eq!(header_operator("%\nO1001\n(OPERATOR: ANNA)\nG0 X0\n", 40).as_deref(), Some("ANNA"));
    assert_eq!(header_operator("; Bediener = Jo\n", 40).as_deref(), Some("Jo"));
    // A comment that only says an operator edited is no name.
    assert_eq!(header_operator("(OPERATOR EDIT 3)\n", 40), None);
    assert_eq!(header_material("(MATERIAL: AL6061)\n", 40).as_deref(), Some("AL6061"));
}

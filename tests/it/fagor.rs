//! Fagor's canned cycles: the dwell at the bottom is K (seconds, as G04 K), not Fanuc's P,
//! which on Fagor is an arithmetic parameter.

use ncplan::canon::CanonOp;
use ncplan::diag::Severity;
use ncplan::dialect::Registry;
use ncplan::interp::Profile;
use ncplan::pipeline::{self, Analysis};

fn analyze(program: &str) -> Analysis {
    pipeline::analyze(program.as_bytes(), &Registry::shipped().get("fagor").unwrap(), &Profile::default())
}

fn errors(a: &Analysis) -> Vec<String> {
    a.diagnostics.iter().filter(|d| d.severity == Severity::Error).map(|d| d.message.clone()).collect()
}

/// (kind, dwell) of every hole's cycle.
fn cycles(a: &Analysis) -> Vec<(String, Option<f64>)> {
    a.canon
        .iter()
        .filter_map(|c| match &c.op {
            CanonOp::CycleBegin(i) => Some((format!("{:?}", i.kind), i.dwell)),
            _ => None,
        })
        .collect()
}

#[test]
fn a_dwell_cycle_dwells_k_seconds_and_k_is_no_repeat_count() {
    let a =
        analyze("G71 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z50\nG98 G82 X10 Y10 Z-5 R2 K1.5 F100\nX20\nG80\nG81 X30 Y10 Z-5 R2\nG80\nM30\n");
    assert!(errors(&a).is_empty(), "{:#?}", errors(&a));
    let c = cycles(&a);
    // Two holes of G82 (K is not repeating the first), both dwelling 1.5 s, then one G81.
    assert_eq!(c.len(), 3, "{c:?}");
    assert_eq!((c[0].1, c[1].1, c[2].1), (Some(1.5), Some(1.5), None), "{c:?}");
}

#[test]
fn a_fanuc_p_dwell_in_a_fagor_cycle_is_a_parameter_reference_not_a_dwell() {
    let a = analyze("G71 G90 G17\nT1 M6\nS1000 M3\nG0 X0 Y0 Z50\nG98 G82 X10 Y10 Z-5 R2 P0 F100\nG80\nM30\n");
    assert_eq!(errors(&a).len(), 1, "{:#?}", errors(&a));
    assert!(cycles(&a).iter().all(|(_, d)| d.is_none_or(|d| d == 0.0)), "{:?}", cycles(&a));
}

//! The writer's fast paths keep its output: numbers written by integer arithmetic agree
//! with the formats' definition, and the two-thread translation (reading on one thread,
//! writing on the other) writes the same text and findings as a serial run.

use std::sync::Arc;

use ncplan::dialect::output::{NumberFormat, Point};
use ncplan::dialect::{Dialect, Registry};
use ncplan::interp::{self, Profile};
use ncplan::post::{self, Options, Post};

fn dialect(name: &str) -> Arc<Dialect> {
    static R: std::sync::OnceLock<Registry> = std::sync::OnceLock::new();
    R.get_or_init(Registry::shipped).get(name).unwrap_or_else(|| panic!("no dialect {name}"))
}

/// The format's definition, written plainly: the value scaled by 10^decimals and rounded
/// half away from zero, then the digits by `format!`, the trailing zeros and the zero before
/// the point left out where the format says.
fn reference(f: &NumberFormat, v: f64, inch: bool) -> (String, f64) {
    let d = if f.point == Point::Never && !f.increment {
        0
    } else if inch {
        f.inch_decimals as usize
    } else {
        f.decimals as usize
    }
    .min(15);
    let p = 10u64.pow(d as u32);
    let x = v * p as f64;
    let n = if x >= 0.0 { (x + 0.5) as i64 } else { (x - 0.5) as i64 };
    let sign = if n < 0 {
        "-"
    } else if f.plus {
        "+"
    } else {
        ""
    };
    let a = n.unsigned_abs();
    let body = if f.increment {
        a.to_string()
    } else if d == 0 {
        format!("{a}{}", if f.point == Point::Always { "." } else { "" })
    } else {
        let frac = format!("{:0d$}", a % p);
        let frac = if f.trailing_zeros { frac.as_str() } else { frac.trim_end_matches('0') };
        let int = a / p;
        let int = if int == 0 && !f.leading_zero && !frac.is_empty() { String::new() } else { int.to_string() };
        let point = if !frac.is_empty() || f.point == Point::Always { "." } else { "" };
        format!("{int}{point}{frac}")
    };
    (format!("{}{sign}{body}", f.address), (n as f64 / p as f64 - v).abs())
}

#[test]
fn numbers_agree_with_the_formats_definition() {
    let values = [
        0.0,
        -0.0,
        0.5,
        -0.5,
        1.0,
        -1.0,
        10.0,
        100.25,
        -100.25,
        0.0004,
        -0.0004,
        0.0005,
        -0.0005,
        0.00049,
        1.0005,
        2.675,
        -2.675,
        12.3456789,
        -12.3456789,
        99.8,
        0.2,
        1500.0,
        12000.0,
        123456.789,
        -987654.321,
        0.1 + 0.2,
        1e-9,
        -1e-9,
        7.6543215,
        25.4,
        0.039370078740157,
        1e9,
        -1e9,
    ];
    let mut checked = 0;
    for point in [Point::Always, Point::Needed, Point::Never] {
        for bits in 0..16u8 {
            for decimals in 0..=6u8 {
                let f = NumberFormat {
                    name: "X".into(),
                    address: "X".into(),
                    decimals,
                    inch_decimals: decimals + 1,
                    point,
                    trailing_zeros: bits & 1 != 0,
                    leading_zero: bits & 2 != 0,
                    plus: bits & 4 != 0,
                    increment: bits & 8 != 0,
                    modal: false,
                    digits: 0,
                };
                for &v in &values {
                    for inch in [false, true] {
                        let mut s = String::from("G1 ");
                        let err = post::format_number(&mut s, &f, v, inch);
                        let (text, want_err) = reference(&f, v, inch);
                        assert_eq!(s, format!("G1 {text}"), "{v} in {f:?} (inch {inch})");
                        assert_eq!(err.to_bits(), want_err.to_bits(), "{v} in {f:?} (inch {inch})");
                        checked += 1;
                    }
                }
            }
        }
    }
    assert_eq!(checked, 3 * 16 * 7 * values.len() * 2);
}

#[test]
fn numbers_in_the_shipped_formats() {
    let fanuc = dialect("fanuc");
    let heidenhain = dialect("heidenhain");
    let fmt = |d: &Dialect, name: &str, v: f64| {
        let out = d.output.as_ref().expect("output rules");
        let f = out.formats.iter().find(|f| f.name == name).expect("format");
        let mut s = String::new();
        post::format_number(&mut s, f, v, false);
        s
    };
    assert_eq!(fmt(&fanuc, "X", 12.3456), "X12.346");
    assert_eq!(fmt(&fanuc, "X", -0.0004), "X0.");
    assert_eq!(fmt(&fanuc, "Z", -0.9950), "Z-0.995");
    assert_eq!(fmt(&fanuc, "S", 12000.0), "S12000");
    assert_eq!(fmt(&heidenhain, "X", 10.0), "X+10");
    assert_eq!(fmt(&heidenhain, "X", -0.25), "X-0.25");
}

/// A program with more ops than one batch the reader hands over: plain moves, arcs, a tool
/// change, a loop the writer may fold into the target's loop, and a finding near the end.
fn program() -> String {
    let mut s = String::from("%\n(speed: batches)\nG21 G90 G17 G54\nT1 M6\nS8000 M3\nG0 X0 Y0 Z5\nG1 Z-1 F900\n");
    for row in 0..12 {
        for i in 0..500 {
            let x = f64::from(if row % 2 == 0 { i } else { 499 - i }) * 0.2;
            let z = -1.0 + 0.001 * f64::from(i % 37);
            s.push_str(&format!("X{x:.3} Y{:.3} Z{z:.4}\n", f64::from(row) * 0.5));
        }
        s.push_str(&format!("G3 X{:.3} Y{:.3} R0.25\nG1\n", if row % 2 == 0 { 99.8 } else { 0.0 }, f64::from(row) * 0.5 + 0.5));
    }
    s.push_str("G0 Z5\nT2 M6\nS3000 M3\n#1 = 0\no10 while [#1 LT 40]\nG0 X10 Y10\nG1 Z-2 F200\nG0 Z5\n#1 = [#1 + 1]\no10 endwhile\n");
    s.push_str("G1 X1.00044 Y2 F100\nG0 Z5\nM30\n%\n");
    s
}

fn options() -> Options {
    Options { number: 21, ..Options::for_program("SPEED") }
}

#[test]
fn translating_on_two_threads_writes_what_a_serial_run_writes() {
    let text = program();
    let from = dialect("linuxcnc");
    let profile = Profile::default();
    for to in ["fanuc", "siemens", "heidenhain", "linuxcnc"] {
        let target = dialect(to);
        let mut threaded = Vec::new();
        let mut chunks = 0;
        let threaded_diags = post::translate(&text, &from, &target, &profile, options(), |b| {
            chunks += 1;
            threaded.extend_from_slice(b);
        });
        // The same writer fed on this thread, with the options translate completes.
        let mut serial = Vec::new();
        let mut opts = options();
        opts.peck_clearance = (from.behaviour.peck_clearance_mm, target.behaviour.peck_clearance_mm);
        opts.length_at_tool_change = (from.behaviour.tool_change_applies_length, target.behaviour.tool_change_applies_length);
        opts.arc_tolerance = (target.behaviour.arc_tolerance_mm, target.behaviour.arc_tolerance_inch);
        let out = target.output.as_ref().expect("output rules");
        let mut writer = Post::new(out, opts, |b: &[u8]| serial.extend_from_slice(b));
        let mut serial_diags = interp::interpret(&text, &from, &profile, &mut writer);
        serial_diags.extend(writer.finish());
        serial_diags.sort_by_key(|d| (d.range.start, d.range.end));
        assert!(threaded.len() > 64 * 1024, "{to}: the program writes more than one buffer ({} bytes)", threaded.len());
        assert!(chunks > 1, "{to}: the text is handed over as it grows");
        assert_eq!(String::from_utf8_lossy(&threaded), String::from_utf8_lossy(&serial), "{to}");
        assert_eq!(threaded_diags, serial_diags, "{to}");
        assert!(to == "linuxcnc" || !threaded_diags.is_empty(), "{to}: the rounded position is said");
    }
}

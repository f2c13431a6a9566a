//! Knowledge back to CAM (issue 42) through the real commands and store, on SQLite and
//! PostgreSQL: a generated year of a shop (CAM originals imported with their dates, operators'
//! edits on two machines as dated backups, a planner's adopt marks), then `ncplan suggest`,
//! a planner's accept, `export-suggestions` into an outbox, and the daemon storing a new CAM
//! post that carries the value: the suggestion is adopted.
//!
//! The history holds two true changes planted with noise (M1's cutting feed of T5 in AL6061
//! cut by 30 %, by two operators; M2's spindle speed of the drill T7 in AL6061 cut by 20 %, by
//! two others), and decoys: one operator's bad week (M2's spindle speed, six
//! edits in five days, all by JOE), a reversal (M1's feed in 1.4301 cut by 25 %, then put back),
//! noise (M2's feed nudged up and down by 2-3 %), and a value the CAM later took up on its own
//! (M2's speed of T5 in 1.2312 run 20 % lower by two operators for five months, then posted
//! so by the CAM, with no edits since). Exactly the planted suggestions come out; both are
//! accepted and exported, T5 from the shop's Fusion library's newer form (a `presets` list),
//! T7 from its older (`start-values` keyed by `*`).
//! The operators sign their edits in a header comment (`(OPERATOR: ANNA)`), as the share tells.
//! After the adoption, operators edit the feed again on the share the daemon watches: the daemon
//! records the suggestion reopened.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::{Duration, SystemTime};

use ncplan::store::{Location, Store};
use ncplan::suggest::library;

use crate::pg::Cluster;
use crate::support::{wait_until, watch};

/// Day 0 of the history: 2026-01-01, as days since 1970.
const JAN_1_2026: u64 = 20_454;

/// A CAM original or an edit of it: T5 faces at `f5`, S`s5`; T7 drills at S2000.
fn program(number: u32, material: &str, f5: u32, s5: u32, edit: Option<(u32, &str)>) -> String {
    program_with(number, material, f5, s5, 2000, edit)
}

/// [`program`] with T7 drilling at S`s7`.
fn program_with(number: u32, material: &str, f5: u32, s5: u32, s7: u32, edit: Option<(u32, &str)>) -> String {
    let edit = edit.map(|(n, who)| format!("(OPERATOR EDIT {n})\n(OPERATOR: {who})\n")).unwrap_or_default();
    // The post writes the lowest Z of each tool's cuts in its comment: it differs by program.
    let zmin = 2 + number % 3;
    format!(
        "%\nO{number} (BRACKET)\n{edit}(MATERIAL: {material})\n(T5 D=10. CR=0. - ZMIN=-{zmin}. - FLAT END MILL)\n(T7 D=6.8 CR=0. - ZMIN=-12. - DRILL)\n\
         G21 G90 G17\nT5 M6\nS{s5} M3\nG0 X-10 Y0 Z5\nG1 Z-2 F{f5}\nX110\nY20\nX-10\nG0 Z50\n\
         T7 M6\nS{s7} M3\nG0 X20 Y10 Z5\nG81 Z-12 R2 F120\nX40\nX60\nG80\nG0 Z50\nM30\n%\n"
    )
}

/// The programs' materials and CAM values (feed, speed of T5).
const PROGRAMS: [(u32, &str, u32, u32); 8] = [
    (1001, "AL6061", 800, 8000),
    (1002, "AL6061", 800, 8000),
    (1003, "AL6061", 800, 8000),
    (1004, "AL6061", 800, 8000),
    (1005, "1.4301", 400, 3000),
    (1006, "1.4301", 400, 3000),
    (1007, "1.2312", 600, 5000),
    (1008, "1.2312", 600, 5000),
];

/// The day the CAM posted O1007 and O1008 again with the speed M2's operators ran (2026-07-01).
const CAM_TOOK_IT_UP: i64 = 181;

/// Every edit: machine, day of 2026, program, T5 feed and speed, operator.
fn history() -> Vec<(&'static str, u64, u32, u32, u32, &'static str)> {
    let mut h = Vec::new();
    // The planted change: M1's two operators cut T5's feed in AL6061 to about 560 (-30 %).
    let days = [10, 38, 66, 95, 123, 151, 180, 215, 245, 280];
    let feeds = [560, 570, 550, 565, 555, 560, 575, 545, 560, 565];
    for (i, (d, f)) in days.iter().zip(feeds).enumerate() {
        h.push(("M1", *d, 1001 + (i % 4) as u32, f, 8000, ["ANNA", "BEN"][i % 2]));
    }
    // One operator's bad week on M2: the spindle turned down from 8000 to 6000.
    for (d, p) in [(200, 1001), (201, 1002), (202, 1003), (203, 1001), (204, 1002), (204, 1003)] {
        h.push(("M2", d, p, 800, 6000, "JOE"));
    }
    // A reversal on M1: 1.4301's feed cut to 300, then put back above the CAM value.
    for (i, d) in [20, 60, 100, 140, 180, 220].iter().enumerate() {
        h.push(("M1", *d, 1005 + (i % 2) as u32, 300, 3000, "ANNA"));
    }
    h.push(("M1", 250, 1005, 410, 3000, "BEN"));
    h.push(("M1", 270, 1006, 420, 3000, "BEN"));
    // A value the CAM later took up on its own: M2's operators ran T5 in 1.2312 at about 4000
    // instead of 5000 (-20 %, eight edits by two operators over five months); on day 181 the
    // CAM posted both programs at S4000 and nobody edited them since.
    let speeds = [4000, 4050, 3950, 4000, 4100, 3900, 4000, 4020];
    for (i, (d, s)) in [20, 45, 70, 95, 120, 140, 160, 165].iter().zip(speeds).enumerate() {
        h.push(("M2", *d, 1007 + (i % 2) as u32, 600, s, ["KIM", "JOE"][i % 2]));
    }
    // Noise on M2: the feed nudged both ways.
    for (i, (d, f)) in [(30, 820), (90, 780), (150, 816), (210, 784), (260, 824), (300, 776)].iter().enumerate() {
        h.push(("M2", *d, 1004 - (i % 2) as u32 * 3, *f, 8000, ["JOE", "KIM"][i % 2]));
    }
    h
}

/// The second planted change: M2's two operators drill with T7 in AL6061 at about 1600 instead
/// of 2000 (-20 %), nine edits over nine months: machine, day, program, T7 speed, operator.
fn drill_history() -> Vec<(&'static str, u64, u32, u32, &'static str)> {
    let days = [12, 40, 75, 105, 135, 170, 205, 240, 275];
    let speeds = [1600, 1620, 1580, 1600, 1650, 1560, 1600, 1610, 1590];
    days.iter().zip(speeds).enumerate().map(|(i, (d, s))| ("M2", *d, 1001 + (i % 4) as u32, s, ["KIM", "JOE"][i % 2])).collect()
}

/// Writes `text` to `path` dated `day` of 2026 (08:00 UTC; `day` may be negative: before).
fn put_dated(path: &Path, text: &str, day: i64) {
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    std::fs::write(path, text).unwrap();
    let secs = (JAN_1_2026 as i64 + day) * 86_400 + 8 * 3600;
    let f = std::fs::File::options().write(true).open(path).unwrap();
    f.set_modified(SystemTime::UNIX_EPOCH + Duration::from_secs(secs as u64)).unwrap();
}

/// The shop's own tool library, written in the shape of public Fusion libraries: T5 in the
/// newer form (a `presets` list, with `expressions`), T7 in the older (`start-values` keyed by `*`).
const SHOP_LIBRARY: &str = r#"{"data": [
  {"guid": "5f3c1a52-0d3e-4b8e-9c1a-7a0d2b6e1f05", "type": "flat end mill", "description": "EM10 3FL ALU", "unit": "millimeters",
   "BMC": "carbide", "vendor": "Shop", "product-id": "EM-10-3",
   "geometry": {"DC": 10, "NOF": 3, "RE": 0, "LCF": 22, "OAL": 72, "SFDM": 10},
   "post-process": {"number": 5, "length-offset": 5, "diameter-offset": 5, "comment": ""},
   "start-values": {"presets": [
     {"guid": "0b7e2a10-3f6d-4d5e-8a1b-2c3d4e5f6a7b", "name": "Aluminium", "description": "", "n": 8000, "v_c": 251.327, "f_z": 0.0333,
      "v_f": 800, "v_f_plunge": 300, "v_f_ramp": 400, "tool-coolant": "flood", "use-stepdown": false, "use-stepover": false,
      "material": {"category": "all", "query": "", "use-hardness": false},
      "expressions": {"tool_feedCutting": "800 mmpm", "tool_spindleSpeed": "8000 rpm"}}]}},
  {"guid": "9d1e4c7a-2b3f-4a5e-8c6d-1e2f3a4b5c6d", "type": "drill", "description": "DRILL 6.8", "unit": "millimeters",
   "geometry": {"DC": 6.8, "NOF": 2, "SIG": 140},
   "post-process": {"number": 7, "length-offset": 7, "diameter-offset": 7, "comment": ""},
   "start-values": {"*": {"n": 2000, "v_f_plunge": 120, "v_f_retract": 1000}}}
], "version": 15}"#;

/// A shop: a CAM folder, two machine shares, the history as dated backups, an outbox.
struct Shop {
    dir: tempfile::TempDir,
}

impl Shop {
    fn new(database: &str) -> Shop {
        // `NCPLAN_SUGGEST_SHOP=DIR` keeps the shop there (the README's walk-through was made so).
        let dir = match std::env::var_os("NCPLAN_SUGGEST_SHOP") {
            Some(d) if database.starts_with("path") => tempfile::Builder::new().prefix("shop").disable_cleanup(true).tempdir_in(d).unwrap(),
            _ => tempfile::tempdir().unwrap(),
        };
        for d in ["cam", "m1", "m2", "var"] {
            std::fs::create_dir_all(dir.path().join(d)).unwrap();
        }
        std::fs::write(
            dir.path().join("ncplan.toml"),
            format!(
                "site = 'HALL1'\n[database]\n{database}\n[daemon]\nsettle_ms = 150\nworkers = 2\n\
                 [[cam]]\npath = 'cam'\ndialect = 'fanuc'\n\
                 [[machine]]\nname = 'M1'\npath = 'm1'\ndialect = 'fanuc'\n\
                 [[machine]]\nname = 'M2'\npath = 'm2'\ndialect = 'fanuc'\n\
                 [suggest]\noutbox = 'outbox'\ntool_library = 'lib/shop-tools.json'\n"
            ),
        )
        .unwrap();
        let shop = Shop { dir };
        std::fs::create_dir_all(shop.path("lib")).unwrap();
        std::fs::write(shop.path("lib/shop-tools.json"), SHOP_LIBRARY).unwrap();
        for (n, material, f, s) in PROGRAMS {
            put_dated(&shop.path(&format!("hist/cam/2025-12-01/O{n}.nc")), &program(n, material, f, s, None), -31);
        }
        for n in [1007, 1008] {
            put_dated(&shop.path(&format!("hist/cam-later/2026-07-01/O{n}.nc")), &program(n, "1.2312", 600, 4000, None), CAM_TOOK_IT_UP);
        }
        for (i, (machine, day, n, f, s, who)) in history().into_iter().enumerate() {
            let material = PROGRAMS.iter().find(|p| p.0 == n).unwrap().1;
            let rel = format!("hist/{}/{day:03}/O{n}.nc", machine.to_lowercase());
            put_dated(&shop.path(&rel), &program(n, material, f, s, Some((i as u32, who))), day as i64);
        }
        for (i, (machine, day, n, s7, who)) in drill_history().into_iter().enumerate() {
            let rel = format!("hist/{}/{day:03}/O{n}.nc", machine.to_lowercase());
            put_dated(&shop.path(&rel), &program_with(n, "AL6061", 800, 8000, s7, Some((100 + i as u32, who))), day as i64);
        }
        shop
    }

    fn path(&self, rel: &str) -> PathBuf {
        self.dir.path().join(rel)
    }

    fn ncplan(&self, args: &[&str]) -> String {
        let out = Command::new(crate::bin()).args(args).current_dir(self.dir.path()).output().unwrap();
        let (stdout, stderr) = (String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned());
        assert!(out.status.success(), "ncplan {args:?}: {stderr}\n{stdout}");
        stdout
    }
}

/// The suggestions JSON at a fixed time.
fn suggestions(shop: &Shop, extra: &[&str]) -> serde_json::Value {
    let mut args = vec!["suggest", "--config", "ncplan.toml", "--format", "json", "--now", "2026-11-30T00:00:00Z"];
    args.extend_from_slice(extra);
    serde_json::from_str(&shop.ncplan(&args)).unwrap()
}

/// The year, the review, the export and the adoption on one engine; what it said, for
/// comparing the engines.
fn the_loop(shop: &Shop, store: impl Fn() -> Store) -> Vec<String> {
    prepare(shop, &store);
    the_rest(shop, store)
}

/// The history stored and every change adopted by a planner.
fn prepare(shop: &Shop, store: &impl Fn() -> Store) {
    shop.ncplan(&["import", "hist/cam", "--cam", "--config", "ncplan.toml"]);
    shop.ncplan(&["import", "hist/m1", "--machine", "M1", "--config", "ncplan.toml"]);
    shop.ncplan(&["import", "hist/m2", "--machine", "M2", "--config", "ncplan.toml"]);
    // The CAM's later posts, stored after the edits they follow (an original is the newest
    // post when an edit is compared).
    shop.ncplan(&["import", "hist/cam-later", "--cam", "--config", "ncplan.toml"]);
    // A planner adopted every change (the gates, not the marks, sort them).
    let s = store();
    let (_, ids) = s.query("SELECT id FROM changes ORDER BY id").unwrap();
    assert!(ids.len() >= 28, "{ids:?}");
    for id in &ids {
        s.add_mark(id[0].parse().unwrap(), "adopt", "", "planner", "2026-11-29T00:00:00Z").unwrap();
    }
}

/// The listing, the review, the export and the adoption.
fn the_rest(shop: &Shop, store: impl Fn() -> Store) -> Vec<String> {
    let all = suggestions(shop, &["--all"]);
    let all = all.as_array().unwrap();
    let passed: Vec<&serde_json::Value> = all.iter().filter(|e| e["s"]["held"].as_array().unwrap().is_empty()).collect();
    assert_eq!(passed.len(), 2, "{}", serde_json::to_string_pretty(&all).unwrap());
    let p = &passed[0]["s"];
    assert_eq!(p["key"]["machine"], "M1");
    assert_eq!(p["key"]["material"], "AL6061");
    assert_eq!(p["key"]["parameter"], "cutting_feed");
    assert_eq!(p["key"]["tool"]["number"], 5);
    assert_eq!(p["key"]["tool"]["diameter"], 10.0);
    assert_eq!(p["key"]["tool"]["description"], "EM10 3FL ALU", "the CAM tool's name from the shop's library");
    let (value, lo, hi) = (p["suggested"].as_f64().unwrap(), p["interval"][0].as_f64().unwrap(), p["interval"][1].as_f64().unwrap());
    assert!(lo <= value && value <= hi && lo <= 560.0 && 560.0 <= hi, "{value} in {lo}..{hi}");
    assert_eq!(p["cam_value"], 800.0);
    assert_eq!(p["edits"].as_array().unwrap().len(), 10);
    // The share told who edited: two operators behind it, each edit signed.
    assert_eq!(p["operators"], 2);
    assert_eq!(p["edits"][0]["operator"], "ANNA");
    // The second planted change: M2's drill speed, the drill named from the shop's library.
    let d = &passed[1]["s"];
    assert_eq!(
        (d["key"]["machine"].as_str(), d["key"]["material"].as_str(), d["key"]["parameter"].as_str()),
        (Some("M2"), Some("AL6061"), Some("spindle_speed"))
    );
    assert_eq!((d["key"]["tool"]["number"].as_u64(), d["key"]["tool"]["description"].as_str()), (Some(7), Some("DRILL 6.8")));
    let (speed, slo, shi) = (d["suggested"].as_f64().unwrap(), d["interval"][0].as_f64().unwrap(), d["interval"][1].as_f64().unwrap());
    assert!(slo <= speed && speed <= shi && slo <= 1600.0 && 1600.0 <= shi, "{speed} in {slo}..{shi}");
    assert_eq!((d["cam_value"].as_f64(), d["edits"].as_array().unwrap().len(), d["operators"].as_u64()), (Some(2000.0), 9, Some(2)));
    // The decoys, each held by its gate.
    let held = |machine: &str, parameter: &str, material: &str| -> String {
        let e = all
            .iter()
            .find(|e| {
                e["s"]["key"]["machine"] == machine
                    && e["s"]["key"]["parameter"] == parameter
                    && e["s"]["key"]["material"] == material
                    && e["s"]["key"]["tool"]["number"] == 5
            })
            .unwrap_or_else(|| panic!("no group {machine} {parameter} {material}"));
        e["s"]["held"].as_array().unwrap().iter().map(|h| h["gate"].as_str().unwrap().to_owned()).collect::<Vec<_>>().join(",")
    };
    assert_eq!(held("M2", "spindle_speed", "AL6061"), "too_few", "one operator's bad week: one operator, four days");
    assert_eq!(held("M1", "cutting_feed", "1.4301"), "reversal");
    assert!(held("M2", "cutting_feed", "AL6061").contains("small"), "{}", held("M2", "cutting_feed", "AL6061"));
    // The value the CAM took up on its own: every other gate passed, it is held only because
    // the CAM posts it already.
    assert_eq!(held("M2", "spindle_speed", "1.2312"), "cam_carries");
    let id = p["id"].as_str().unwrap().to_owned();
    let drill = d["id"].as_str().unwrap().to_owned();
    // Proposed by the first listing; a planner accepts both.
    for i in [&id, &drill] {
        shop.ncplan(&["suggest", "--config", "ncplan.toml", "--accept", i, "--by", "anna", "--now", "2026-11-30T00:00:00Z"]);
    }
    let out =
        shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "fusion", "--by", "anna", "--now", "2026-11-30T01:00:00Z"]);
    assert!(out.contains("2 accepted suggestions exported"), "{out}");
    shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "csv", "--now", "2026-11-30T01:00:00Z"]);
    shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "html", "--now", "2026-11-30T01:00:00Z"]);
    shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "nx", "--now", "2026-11-30T01:00:00Z"]);
    let nx = std::fs::read_to_string(shop.path("outbox/ncplan-tool_machining_data.dat")).unwrap();
    // The library reads back: T5 and T7, each with its suggestion's preset.
    let json = std::fs::read_to_string(shop.path("outbox/ncplan-suggestions.json")).unwrap();
    let lib = library::read(&json).unwrap();
    assert_eq!(lib.tools.len(), 2);
    let t = &lib.tools[0];
    assert_eq!((t.number, t.diameter, t.description.as_str()), (Some(5), Some(10.0), "EM10 3FL ALU"));
    // Each shop tool, copied under a new guid with everything it had as it was, and one preset more.
    let shop_lib = library::read(SHOP_LIBRARY).unwrap();
    for (copy, original) in lib.tools.iter().zip(&shop_lib.tools) {
        assert_eq!(copy.number, original.number);
        assert_ne!(copy.raw["guid"], original.raw["guid"]);
        for (k, v) in original.raw.as_object().unwrap() {
            if k != "guid" && k != "start-values" {
                assert_eq!(&copy.raw[k], v, "T{:?} {k}", copy.number);
            }
        }
        for (k, v) in original.raw["start-values"].as_object().unwrap() {
            if k != "presets" {
                assert_eq!(&copy.raw["start-values"][k], v, "T{:?} start-values {k}", copy.number);
            }
        }
        let kept = original.raw["start-values"]["presets"].as_array().map_or(&[][..], |p| p.as_slice());
        assert_eq!(&copy.raw["start-values"]["presets"].as_array().unwrap()[..kept.len()], kept, "T{:?}'s presets kept", copy.number);
        assert_eq!(copy.presets.len(), original.presets.len() + 1);
        assert_eq!(copy.presets[..original.presets.len()], original.presets[..]);
    }
    assert_eq!(lib.version, shop_lib.version);
    let preset = &t.presets.last().unwrap().1;
    let v = library::preset_value(t, preset, ncplan::suggest::Parameter::CuttingFeed).unwrap();
    assert!((v - value).abs() < 1e-3, "{v} {value}");
    // T7, of the older form: its `*` start values kept, a `presets` list beside them.
    let t7 = &lib.tools[1];
    assert_eq!(t7.raw["start-values"]["*"], shop_lib.tools[1].raw["start-values"]["*"]);
    let v7 = library::preset_value(t7, &t7.presets.last().unwrap().1, ncplan::suggest::Parameter::SpindleSpeed).unwrap();
    assert!((v7 - speed).abs() < 1e-3, "{v7} {speed}");
    // The `.tools` file is the same JSON, zipped.
    let zip = std::fs::read(shop.path("outbox/ncplan-suggestions.tools")).unwrap();
    assert_eq!(&zip[..4], b"PK\x03\x04");
    assert_eq!(&zip[30..40], b"tools.json");
    assert_eq!(&zip[40..40 + json.len()], json.as_bytes());
    let csv = std::fs::read_to_string(shop.path("outbox/ncplan-suggestions.csv")).unwrap();
    assert_eq!(csv.lines().count(), 3, "{csv}");
    assert!(csv.lines().any(|l| l.starts_with(&format!("{id},exported,tool,5,EM10 3FL ALU,10,3,0,AL6061,M1,"))), "{csv}");
    assert!(csv.lines().any(|l| l.starts_with(&format!("{drill},exported,tool,7,DRILL 6.8,6.8,2,"))), "{csv}");
    let html = std::fs::read_to_string(shop.path("outbox/ncplan-suggestions.html")).unwrap();
    assert!(html.contains(&format!("id=\"s-{id}\"")) && html.contains(&format!("id=\"s-{drill}\"")) && html.contains("<svg"), "{html}");
    // A reader of the format written from public examples (Python's json and zipfile, no
    // ncplan code): the .tools zip holds the same JSON; each tool is the shop's under a new
    // guid, every field and preset it had as it was, one preset more with the new value and
    // the evidence.
    let facts = independent_reader(&shop.path("outbox/ncplan-suggestions.tools"), &shop.path("lib/shop-tools.json"));
    assert_eq!(facts["same_json"], true, "{facts}");
    assert_eq!(facts["tools"], serde_json::json!([5, 7]), "{facts}");
    assert_eq!(facts["guid_new"], true, "{facts}");
    assert_eq!(facts["originals_kept"], true, "{facts}");
    assert_eq!(facts["added"], serde_json::json!([1, 1]), "{facts}");
    assert!((facts["new"][0]["v_f"].as_f64().unwrap() - value).abs() < 1e-3, "{facts}");
    assert!((facts["new"][1]["n"].as_f64().unwrap() - speed).abs() < 1e-3, "{facts}");
    assert!(facts["new"][0]["description"].as_str().unwrap().starts_with(&format!("ncplan {id}: cutting feed 800 -> ")), "{facts}");
    assert!(facts["new"][1]["description"].as_str().unwrap().starts_with(&format!("ncplan {drill}: spindle speed 2000 -> ")), "{facts}");
    // The CAM side posts O1001 again with the feed; the daemon stores it and records the
    // adoption itself (no command runs). The drill's speed is not in it: that one waits.
    let daemon = watch(&shop.path("ncplan.toml"), "info", std::process::Stdio::null());
    let posted = program(1001, "AL6061", value.round() as u32, 8000, None);
    std::thread::sleep(Duration::from_millis(500));
    let tmp = shop.path("cam/O1001.nc.part");
    std::fs::write(&tmp, &posted).unwrap();
    std::fs::rename(&tmp, shop.path("cam/O1001.nc")).unwrap();
    let recorded = |state: &str| {
        let sql = format!("SELECT COUNT(*) FROM suggestion_events WHERE state = '{state}'");
        store().query(&sql).is_ok_and(|(_, r)| r[0][0] == "1")
    };
    wait_until("the daemon records the adoption", Duration::from_secs(30), || recorded("adopted"));
    // Operators go on editing the feed on M1 (two edits, the rules' `reopen_edits`): the daemon
    // reopens the suggestion.
    for (n, f) in [(1001, 600), (1002, 610)] {
        std::thread::sleep(Duration::from_millis(300));
        let tmp = shop.path(&format!("m1/O{n}.nc.part"));
        std::fs::write(&tmp, program(n, "AL6061", f, 8000, Some((90 + n, "BEN")))).unwrap();
        std::fs::rename(&tmp, shop.path(&format!("m1/O{n}.nc"))).unwrap();
    }
    wait_until("the daemon records the reopening", Duration::from_secs(30), || recorded("reopened"));
    daemon.kill();
    let after = suggestions(shop, &["--state", "reopened"]);
    assert_eq!(after.as_array().unwrap().len(), 1, "{after}");
    let s = store();
    let steps = |of: &str| -> Vec<String> {
        let sql = format!("SELECT state, decided_by FROM suggestion_events WHERE suggestion = '{of}' ORDER BY step");
        s.query(&sql).unwrap().1.iter().map(|r| r.join(" by ")).collect()
    };
    let states = steps(&id);
    assert_eq!(states, ["proposed by ncplan", "accepted by anna", "exported by anna", "adopted by ncplan", "reopened by ncplan"]);
    assert_eq!(steps(&drill), ["proposed by ncplan", "accepted by anna", "exported by anna"]);
    let (_, view) = s.query("SELECT state, steps FROM suggestion_states ORDER BY state").unwrap();
    assert_eq!(view, [["exported".to_owned(), "3".to_owned()], ["reopened".to_owned(), "5".to_owned()]]);
    // A listing writes nothing (it works on a store opened read-only).
    let before = s.query("SELECT COUNT(*) FROM suggestion_events").unwrap().1;
    suggestions(shop, &["--all"]);
    assert_eq!(s.query("SELECT COUNT(*) FROM suggestion_events").unwrap().1, before);
    let mut said = vec![csv, json, nx];
    said.extend(states);
    said
}

/// What Python's standard library reads in the exported `.tools` (a zip of `tools.json`)
/// beside the shop's library, as JSON facts. The Python of `target/venv` (CI's), else `python3`.
fn independent_reader(tools: &Path, shop: &Path) -> serde_json::Value {
    const READER: &str = r#"
import json, sys, zipfile
with zipfile.ZipFile(sys.argv[1]) as z:
    assert z.testzip() is None
    names = z.namelist()
    lib = json.loads(z.read(names[0]).decode("utf-8"))
with open(sys.argv[1][:-len(".tools")] + ".json", encoding="utf-8") as f:
    same = json.load(f) == lib
with open(sys.argv[2], encoding="utf-8") as f:
    shop = json.load(f)
numbers, guid_new, kept, added, new = [], True, True, [], []
for tool in lib["data"]:
    number = tool["post-process"]["number"]
    numbers.append(number)
    mine = [t for t in shop["data"] if t["post-process"]["number"] == number][0]
    guid_new = guid_new and tool["guid"] != mine["guid"] and len(tool["guid"]) == 36
    # Every field of the shop's tool as it was, but its guid and its start values.
    kept = kept and all(tool.get(k) == v for k, v in mine.items() if k not in ("guid", "start-values"))
    sv, old = tool["start-values"], mine.get("start-values", {})
    # The start values: the older form's "*" and any other key as they were, the presets
    # the shop had first and unchanged, then the added ones.
    kept = kept and all(sv.get(k) == v for k, v in old.items() if k != "presets")
    had = old.get("presets", [])
    kept = kept and sv["presets"][:len(had)] == had
    added.append(len(sv["presets"]) - len(had))
    new.append(sv["presets"][-1])
print(json.dumps({
    "names": names, "same_json": same, "tools": numbers, "guid_new": guid_new,
    "originals_kept": kept, "added": added, "new": new,
}))
"#;
    let venv = crate::root().join("target/venv/bin/python");
    let python = if venv.exists() { venv.to_string_lossy().into_owned() } else { "python3".to_owned() };
    let out = Command::new(python).args(["-c", READER]).arg(tools).arg(shop).output().expect("Python runs");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn a_year_of_a_shop_gives_exactly_the_planted_suggestion_and_cam_adopts_it_on_both_engines() {
    let lite = Shop::new("path = 'var/ncplan.db'");
    let db = lite.path("var/ncplan.db");
    let on_lite = the_loop(&lite, || Store::open(&Location::Sqlite(db.clone()), "HALL1").unwrap());
    // The exports, read by eye (`UPDATE_EXPECT=1` writes them again).
    expect_test::expect_file!["../golden/suggest/ncplan-suggestions.csv"].assert_eq(&on_lite[0]);
    expect_test::expect_file!["../golden/suggest/ncplan-suggestions.json"].assert_eq(&on_lite[1]);
    expect_test::expect_file!["../golden/suggest/ncplan-tool_machining_data.dat"].assert_eq(&on_lite[2]);
    let Some(pg) = Cluster::start("suggest::a_year_of_a_shop_gives_exactly_the_planted_suggestion_and_cam_adopts_it_on_both_engines")
    else {
        return;
    };
    let url = pg.url();
    let shop = Shop::new(&format!("url = '{url}'"));
    let on_pg = the_loop(&shop, || Store::open(&Location::parse(&url), "HALL1").unwrap());
    assert_eq!(on_lite, on_pg);
    // The listing on a role that may only read (the README's read-only role).
    let mut owner = postgres::Client::connect(&url, postgres::NoTls).unwrap();
    owner.batch_execute(crate::pg::READER_ROLE).unwrap();
    let reader = url.replacen("ncplan@", "ncplan_reader@", 1);
    let listed = shop.ncplan(&["suggest", "--config", "ncplan.toml", "--db", &reader, "--all", "--now", "2026-12-31T00:00:00Z"]);
    assert!(listed.contains(" reopened ") && listed.contains("cutting feed of T5"), "{listed}");
}

/// The suggestions page in Chromium: the planted suggestion with its evidence and pictures,
/// accepted by its button, exported by the command, and a rejection without a reason refused;
/// on SQLite and PostgreSQL, with screenshots.
#[test]
fn the_suggestions_page_in_chromium() {
    let Some((_driver, port)) = crate::web::chromedriver("suggest::the_suggestions_page_in_chromium") else { return };
    let lite = Shop::new("path = 'var/ncplan.db'");
    let db = lite.path("var/ncplan.db");
    prepare(&lite, &|| Store::open(&Location::Sqlite(db.clone()), "HALL1").unwrap());
    let mut runs = vec![("sqlite", lite, None)];
    if let Some(pg) = Cluster::start("suggest::the_suggestions_page_in_chromium on PostgreSQL") {
        let url = pg.url();
        let shop = Shop::new(&format!("url = '{url}'"));
        prepare(&shop, &|| Store::open(&Location::parse(&url), "HALL1").unwrap());
        runs.push(("postgres", shop, Some(pg)));
    }
    for (engine, shop, _cluster) in &runs {
        let (_serve, base) = crate::support::serve(&shop.path("ncplan.toml"), &[]);
        let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
        rt.block_on(async {
            let c = crate::web::browser(port).await;
            let result = review_in_browser(&c, &base, shop, engine).await;
            let _ = c.close().await;
            result.unwrap();
        });
    }
}

async fn review_in_browser(c: &fantoccini::Client, base: &str, shop: &Shop, engine: &str) -> Result<(), fantoccini::error::CmdError> {
    use crate::web::{shot, text_of, wait_text};
    use fantoccini::Locator;
    c.goto(&format!("{base}/suggestions")).await?;
    assert_eq!(text_of(c, "h1").await, "Suggestions for CAM");
    let cards = c.find_all(Locator::Css("section.suggestion")).await?;
    assert_eq!(cards.len(), 2, "the two planted changes");
    // The first, the feed of T5; its evidence, pictures and forms under its id.
    let id = cards[0].attr("data-id").await?.unwrap_or_default();
    let card = format!("section[data-id='{id}']");
    let title = text_of(c, &format!("{card} h2")).await;
    assert!(
        title.contains("cutting feed of T5") && title.contains("AL6061") && title.contains("M1") && title.contains("proposed"),
        "{title}"
    );
    let second = cards[1].text().await?;
    assert!(second.contains("spindle speed of T7") && second.contains("M2"), "{second}");
    assert_eq!(c.find_all(Locator::Css(&format!("{card} svg.chart"))).await?.len(), 2, "both pictures");
    assert_eq!(c.find_all(Locator::Css(&format!("{card} table.evidence tr"))).await?.len(), 11, "ten edits and the header");
    let link = c.find(Locator::Css(&format!("{card} table.evidence a"))).await?.attr("href").await?.unwrap_or_default();
    assert!(link.starts_with("/compare/") && link.contains("#change-"), "{link}");
    assert!(text_of(c, "table.held").await.contains("reversed by the latest edits"));
    assert!(text_of(c, "table.held").await.contains("the CAM posts it already"));
    shot(c, &format!("suggestions-{engine}")).await?;
    c.find(Locator::Css(&format!("{card} button[data-to=accepted]"))).await?.click().await?;
    assert!(wait_text(c, &format!("{card} h2"), "accepted").await.contains("accepted"));
    assert!(text_of(c, &format!("{card} ol.steps")).await.contains("accepted by planner"));
    shot(c, &format!("suggestion-accepted-{engine}")).await?;
    shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "fusion"]);
    c.goto(&format!("{base}/suggestions")).await?;
    assert!(text_of(c, &format!("{card} h2")).await.contains("exported"));
    // A rejection needs its reason: refused without one, recorded with one.
    c.find(Locator::Css(&format!("{card} button[data-to=rejected]"))).await?.click().await?;
    assert!(wait_text(c, "body", "needs its reason").await.contains("a rejection needs its reason"));
    c.goto(&format!("{base}/suggestions")).await?;
    c.find(Locator::Css(&format!("{card} input[name=reason]"))).await?.send_keys("the new cutter runs at the CAM value").await?;
    c.find(Locator::Css(&format!("{card} button[data-to=rejected]"))).await?.click().await?;
    assert!(wait_text(c, &format!("{card} ol.steps"), "rejected").await.contains("rejected by planner"));
    shot(c, &format!("suggestion-rejected-{engine}")).await?;
    Ok(())
}

/// The CAM tool named from the shop's other tool lists: a FreeCAD tool library (`.fctl`, its
/// bits in the `Bit` folder beside it) and a LinuxCNC `tool.tbl` (`tests/programs/cam_tools`,
/// our own files in those formats), instead of the Fusion library; a list of two names the
/// tool by the first that has it.
#[test]
fn the_cam_tool_is_named_from_a_freecad_library_or_a_linuxcnc_tool_table() {
    let shop = Shop::new("path = 'var/ncplan.db'");
    let db = shop.path("var/ncplan.db");
    prepare(&shop, &|| Store::open(&Location::Sqlite(db.clone()), "HALL1").unwrap());
    let tools = crate::root().join("tests/programs/cam_tools");
    let config = std::fs::read_to_string(shop.path("ncplan.toml")).unwrap();
    let named = |name: &str, list: &str| -> serde_json::Value {
        let text = config.replace("tool_library = 'lib/shop-tools.json'", &format!("tool_library = {list}"));
        std::fs::write(shop.path(name), text).unwrap();
        let out = shop.ncplan(&["suggest", "--config", name, "--format", "json", "--now", "2026-11-30T00:00:00Z"]);
        let all: serde_json::Value = serde_json::from_str(&out).unwrap();
        // The two planted suggestions, T5's first.
        assert_eq!(all.as_array().unwrap().len(), 2, "{all}");
        assert_eq!(all[1]["s"]["key"]["tool"]["number"], 7, "{all}");
        all[0]["s"]["key"]["tool"].clone()
    };
    let fctl = tools.join("Tools/Library/Shop.fctl");
    let tbl = tools.join("tool.tbl");
    let freecad = named("freecad.toml", &format!("'{}'", fctl.display()));
    assert_eq!(
        freecad,
        serde_json::json!({"number": 5, "description": "10 mm End Mill 3FL ALU", "diameter": 10.0, "flutes": 3, "corner_radius": null})
    );
    let linuxcnc = named("linuxcnc.toml", &format!("'{}'", tbl.display()));
    assert_eq!(linuxcnc["description"], "EM10 3FL ALU (shop tool 5)");
    assert_eq!(linuxcnc["diameter"], 10.0);
    let both = named("both.toml", &format!("['{}', '{}']", tbl.display(), fctl.display()));
    assert_eq!(both, linuxcnc, "the first list that has the number names the tool");
    // Each bit of the FreeCAD library as read: the drill's flutes an attribute, the older
    // bull nose's corner radius from its flat radius.
    let settings = ncplan::config::SuggestSettings { tool_libraries: vec![fctl], ..Default::default() };
    let lib = ncplan::export::read_library(&settings).unwrap().unwrap();
    let t = |n: u32| lib.tools.iter().find(|t| t.number == Some(n)).unwrap();
    assert_eq!((t(7).diameter, t(7).flutes, t(7).kind.as_str()), (Some(6.8), Some(2), "drill"));
    assert_eq!((t(9).diameter, t(9).corner_radius, t(9).description.as_str()), (Some(8.0), Some(1.5), "8 mm Bull Nose R1.5"));
}

/// The README's loop on the bundled demo, run verbatim: every command of the README's block
/// (after "The loop on the demo") runs in a copy of the checkout's `demo` and `config` with the
/// built-in configuration (no `--config`), and says what the README shows it saying, where it
/// shows it (`…` stands
/// for any text within a line, or for any lines where it is a line of its own; a timing `0.2 s`
/// for any; trailing blanks aside). Then the file: the README's excerpt of the exported
/// preset, field by field.
#[test]
fn the_readme_loop_runs_on_the_demo() {
    let dir = tempfile::tempdir().unwrap();
    for sub in ["demo", "config"] {
        let ok = Command::new("cp").arg("-r").arg(crate::root().join(sub)).arg(dir.path()).status().unwrap().success();
        assert!(ok, "copying {sub}");
    }
    let readme = std::fs::read_to_string(crate::root().join("README.md")).unwrap();
    let section = &readme[readme.find("**The loop on the demo.**").expect("the README's loop")..];
    let block = |fence: &str| -> String {
        let start = section.find(fence).unwrap() + fence.len();
        section[start..start + section[start..].find("\n```").unwrap()].trim_start_matches('\n').to_owned()
    };
    let shell = block("```\n");
    let mut runs: Vec<(Vec<String>, Vec<String>)> = Vec::new();
    for line in shell.lines() {
        match line.strip_prefix("$ ") {
            Some(cmd) => runs.push((words(cmd), Vec::new())),
            None => runs.last_mut().expect("a command first").1.push(line.to_owned()),
        }
    }
    assert_eq!(runs.len(), 8, "{shell}");
    for (cmd, shown) in &runs {
        assert_eq!(cmd[0], "ncplan");
        // A command shown without its output (the imports of the CAM and HAAS1) is run, its
        // output not compared.
        let out = Command::new(crate::bin()).args(&cmd[1..]).current_dir(dir.path()).output().unwrap();
        assert!(out.status.success(), "{cmd:?}: {}", String::from_utf8_lossy(&out.stderr));
        let said = String::from_utf8_lossy(&out.stdout).into_owned();
        let said: Vec<&str> = said.lines().collect();
        assert!(
            shown.is_empty() || shown_as(shown, &said),
            "`{}` says\n{}\nwhere the README shows\n{}",
            cmd.join(" "),
            said.join("\n"),
            shown.join("\n")
        );
    }
    // The file: each field of the README's excerpt as the exported preset has it.
    let lib = library::read(&std::fs::read_to_string(dir.path().join("var/outbox/ncplan-suggestions.json")).unwrap()).unwrap();
    let preset = &lib.tools[0].raw["start-values"]["presets"][0];
    assert_eq!(lib.tools[0].number, Some(3));
    let excerpt = block("```json\n");
    let mut fields = 0;
    for line in excerpt.lines().map(str::trim).filter(|l| l.starts_with('"')) {
        let field: serde_json::Value = serde_json::from_str(&format!("{{{}}}", line.trim_end_matches(','))).unwrap();
        for (k, v) in field.as_object().unwrap() {
            assert_eq!(&preset[k], v, "the preset's {k}");
            fields += 1;
        }
    }
    assert_eq!(fields, 4, "{excerpt}");
}

/// A README command's words: blanks split them, except inside double quotes.
fn words(cmd: &str) -> Vec<String> {
    let (mut out, mut cur, mut quoted) = (Vec::new(), String::new(), false);
    for c in cmd.chars() {
        match c {
            '"' => quoted = !quoted,
            ' ' if !quoted => {
                if !cur.is_empty() {
                    out.push(std::mem::take(&mut cur));
                }
            }
            c => cur.push(c),
        }
    }
    if !cur.is_empty() {
        out.push(cur);
    }
    out
}

/// Whether `said` is what `shown` shows: line by line, `…` any text within a line, a line
/// `…` any lines, a timing (`0.2 s`) any timing, trailing blanks aside.
fn shown_as(shown: &[String], said: &[&str]) -> bool {
    let timing = regex::Regex::new(r"\d+(\.\d+)? s$").unwrap();
    let line = |pattern: &str, text: &str| -> bool {
        let pattern = timing.replace(pattern.trim_end(), "TIME s");
        let text = timing.replace(text.trim_end(), "TIME s");
        let parts: Vec<String> = pattern.split('…').map(regex::escape).collect();
        regex::Regex::new(&format!("^{}$", parts.join(".*"))).unwrap().is_match(&text)
    };
    match shown.split_first() {
        None => said.is_empty(),
        Some((first, rest)) if first == "…" => (0..=said.len()).any(|k| shown_as(rest, &said[k..])),
        Some((first, rest)) => said.split_first().is_some_and(|(s, more)| line(first, s) && shown_as(rest, more)),
    }
}

/// Two writers on one database (two daemons' watches, two planners) that read the same state
/// record a step once: both see the exported suggestion adopted by a new CAM post, and one
/// adoption is recorded; two planners who both read it adopted and reject it record one
/// rejection, the other is told the suggestion changed meanwhile. On SQLite and PostgreSQL.
#[test]
fn two_writers_record_a_step_once_on_both_engines() {
    let lite = Shop::new("path = 'var/ncplan.db'");
    let db = lite.path("var/ncplan.db");
    once_each(&lite, || Store::open(&Location::Sqlite(db.clone()), "HALL1").unwrap());
    let Some(pg) = Cluster::start("suggest::two_writers_record_a_step_once_on_both_engines") else { return };
    let url = pg.url();
    let shop = Shop::new(&format!("url = '{url}'"));
    once_each(&shop, || Store::open(&Location::parse(&url), "HALL1").unwrap());
}

fn once_each(shop: &Shop, store: impl Fn() -> Store + Sync) {
    use ncplan::export::State;
    prepare(shop, &store);
    let id = suggestions(shop, &[])[0]["s"]["id"].as_str().unwrap().to_owned();
    shop.ncplan(&["suggest", "--config", "ncplan.toml", "--accept", &id, "--by", "anna", "--now", "2026-11-30T00:00:00Z"]);
    shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "fusion", "--now", "2026-11-30T01:00:00Z"]);
    // The CAM posts O1001 with the suggested feed.
    let value = suggestions(shop, &[])[0]["s"]["suggested"].as_f64().unwrap();
    put_dated(&shop.path("hist/cam-post/2026-12-01/O1001.nc"), &program(1001, "AL6061", value.round() as u32, 8000, None), 334);
    shop.ncplan(&["import", "hist/cam-post", "--cam", "--config", "ncplan.toml"]);
    let config = ncplan::config::Config::parse(&std::fs::read_to_string(shop.path("ncplan.toml")).unwrap(), shop.dir.path()).unwrap();
    let count =
        |state: &str| store().query(&format!("SELECT COUNT(*) FROM suggestion_events WHERE state = '{state}'")).unwrap().1[0][0].clone();
    // Both read the state before either writes; then both write at once.
    let both = |step: &(dyn Fn(&Store, &ncplan::export::Knowledge, &str) -> anyhow::Result<usize> + Sync), at: &str| {
        let barrier = std::sync::Barrier::new(2);
        std::thread::scope(|sc| {
            let runs: Vec<_> = (0..2)
                .map(|_| {
                    sc.spawn(|| {
                        let s = store();
                        let k = ncplan::export::load(&s, &config, at).unwrap();
                        barrier.wait();
                        step(&s, &k, at)
                    })
                })
                .collect();
            runs.into_iter().map(|r| r.join().unwrap()).collect::<Vec<_>>()
        })
    };
    let watched = both(
        &|s, k, at| {
            assert_eq!(k.entry(&id).unwrap().state, State::Adopted, "each writer sees the adoption");
            ncplan::export::record(s, k, at)
        },
        "2026-12-02T00:00:00Z",
    );
    let watched: Vec<usize> = watched.into_iter().map(Result::unwrap).collect();
    assert_eq!(watched.iter().sum::<usize>(), 1, "{watched:?}");
    assert_eq!(count("adopted"), "1");
    let rejected = both(
        &|s, k, at| ncplan::export::review(s, k, &id, State::Rejected, "the new cutter runs at the CAM value", "ben", at).map(|()| 1),
        "2026-12-03T00:00:00Z",
    );
    assert_eq!(rejected.iter().filter(|r| r.is_ok()).count(), 1, "{rejected:?}");
    let refused = rejected.iter().find_map(|r| r.as_ref().err()).unwrap();
    assert!(format!("{refused:#}").contains("changed meanwhile"), "{refused:#}");
    assert_eq!(count("rejected"), "1");
    let (_, steps) = store().query(&format!("SELECT state FROM suggestion_events WHERE suggestion = '{id}' ORDER BY step")).unwrap();
    let steps: Vec<&str> = steps.iter().map(|r| r[0].as_str()).collect();
    assert_eq!(steps, ["proposed", "accepted", "exported", "adopted", "rejected"]);
}

/// Who edited, from `[[suggest.operator]]` by folder, through a real daemon on real folders:
/// the share names no operator in its programs, each operator saves into a folder of their own
/// on the machine's share. Six edits of one day count as evidence only because two operators
/// made them; without the folders' rule the same edits are held for too few days or operators.
#[test]
fn operators_by_folder_through_a_daemon() {
    let dir = tempfile::tempdir().unwrap();
    let base = "site = 'HALL1'\n[database]\npath = 'var/ncplan.db'\n[daemon]\nsettle_ms = 150\nworkers = 2\n\
                [[cam]]\npath = 'cam'\ndialect = 'fanuc'\n[[machine]]\nname = 'M1'\npath = 'm1'\ndialect = 'fanuc'\n\
                [suggest]\nunreviewed = true\n";
    let rules = "[[suggest.operator]]\nfolder = 'm1/anna'\noperator = 'ANNA'\n[[suggest.operator]]\nfolder = 'm1/ben'\noperator = 'BEN'\n";
    for d in ["cam", "m1/anna", "m1/ben", "var"] {
        std::fs::create_dir_all(dir.path().join(d)).unwrap();
    }
    std::fs::write(dir.path().join("ncplan.toml"), format!("{base}{rules}")).unwrap();
    std::fs::write(dir.path().join("plain.toml"), base).unwrap();
    let db = dir.path().join("var/ncplan.db");
    let store = || Store::open(&Location::Sqlite(db.clone()), "HALL1").unwrap();
    // Counted once the daemon made the database (a second writer migrating it at once would race).
    let count = |sql: &str| -> usize {
        if !db.exists() {
            return 0;
        }
        store().query(sql).map(|(_, r)| r[0][0].parse::<usize>().unwrap()).unwrap_or(0)
    };
    let daemon = watch(&dir.path().join("ncplan.toml"), "info", std::process::Stdio::null());
    let put = |rel: &str, text: &str| {
        let tmp = dir.path().join(format!("{rel}.part"));
        std::fs::write(&tmp, text).unwrap();
        std::fs::rename(&tmp, dir.path().join(rel)).unwrap();
    };
    wait_until("the daemon made its database", Duration::from_secs(30), || db.exists());
    std::thread::sleep(Duration::from_millis(500));
    for n in [1001, 1002, 1003] {
        put(&format!("cam/O{n}.nc"), &program(n, "AL6061", 800, 8000, None));
    }
    wait_until("the originals are stored", Duration::from_secs(30), || count("SELECT COUNT(*) FROM revisions") == 3);
    // Each operator edits each program once, in their own folder, no name in the program.
    let edits = [("anna", 1001, 560), ("ben", 1002, 570), ("anna", 1003, 555), ("ben", 1001, 565), ("anna", 1002, 550), ("ben", 1003, 560)];
    for (who, n, f) in edits {
        put(&format!("m1/{who}/O{n}.nc"), &program(n, "AL6061", f, 8000, None));
    }
    wait_until("the six edits are compared", Duration::from_secs(60), || {
        count("SELECT COUNT(*) FROM changes WHERE kind = 'feed_changed'") == 6
    });
    daemon.kill();
    let listed = |config: &str| -> serde_json::Value {
        let out = Command::new(crate::bin())
            .args(["suggest", "--config", config, "--format", "json", "--all"])
            .current_dir(dir.path())
            .output()
            .unwrap();
        assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
        serde_json::from_slice(&out.stdout).unwrap()
    };
    let all = listed("ncplan.toml");
    assert_eq!(all.as_array().unwrap().len(), 1, "{all}");
    let s = &all[0]["s"];
    assert_eq!(s["held"], serde_json::json!([]), "{s}");
    assert_eq!((s["operators"].as_u64(), s["days"].as_u64(), s["edits"].as_array().unwrap().len()), (Some(2), Some(1), 6));
    let mut by: Vec<(String, f64)> =
        s["edits"].as_array().unwrap().iter().map(|e| (e["operator"].as_str().unwrap().to_owned(), e["after"].as_f64().unwrap())).collect();
    by.sort_by(|a, b| a.partial_cmp(b).unwrap());
    let want: Vec<(String, f64)> = [("ANNA", 550.0), ("ANNA", 555.0), ("ANNA", 560.0), ("BEN", 560.0), ("BEN", 565.0), ("BEN", 570.0)]
        .iter()
        .map(|(w, f)| (w.to_string(), *f))
        .collect();
    assert_eq!(by, want, "each edit named by the folder it was saved in");
    // Without the rule the share tells nobody: one day's edits are held.
    let plain = listed("plain.toml");
    let held = &plain[0]["s"]["held"];
    assert_eq!(plain[0]["s"]["operators"], 0, "{plain}");
    assert!(held.as_array().unwrap().iter().any(|h| h["gate"] == "too_few" && h["what"].as_str().unwrap().contains("operators")), "{held}");
}

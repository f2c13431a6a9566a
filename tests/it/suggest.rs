//! Knowledge back to CAM (issue 42) through the real commands and store, on SQLite and
//! PostgreSQL: a generated year of a shop (CAM originals imported with their dates, operators'
//! edits on two machines as dated backups, a planner's adopt marks), then `ncplan suggest`,
//! a planner's accept, `export-suggestions` into an outbox, and the daemon storing a new CAM
//! post that carries the value: the suggestion is adopted.
//!
//! The history holds one true change planted with noise (M1's cutting feed of T5 in AL6061
//! cut by 30 %, by two operators), and decoys: one operator's bad week (M2's spindle speed, six
//! edits in five days, all by JOE), a reversal (M1's feed in 1.4301 cut by 25 %, then put back),
//! and noise (M2's feed nudged up and down by 2-3 %). Exactly the planted suggestion comes out.
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

/// A CAM original or an edit of it: T5 faces at `f5`, S`s5`; T7 drills.
fn program(number: u32, material: &str, f5: u32, s5: u32, edit: Option<(u32, &str)>) -> String {
    let edit = edit.map(|(n, who)| format!("(OPERATOR EDIT {n})\n(OPERATOR: {who})\n")).unwrap_or_default();
    // The post writes the lowest Z of each tool's cuts in its comment: it differs by program.
    let zmin = 2 + number % 3;
    format!(
        "%\nO{number} (BRACKET)\n{edit}(MATERIAL: {material})\n(T5 D=10. CR=0. - ZMIN=-{zmin}. - FLAT END MILL)\n(T7 D=6.8 CR=0. - ZMIN=-12. - DRILL)\n\
         G21 G90 G17\nT5 M6\nS{s5} M3\nG0 X-10 Y0 Z5\nG1 Z-2 F{f5}\nX110\nY20\nX-10\nG0 Z50\n\
         T7 M6\nS2000 M3\nG0 X20 Y10 Z5\nG81 Z-12 R2 F120\nX40\nX60\nG80\nG0 Z50\nM30\n%\n"
    )
}

/// The programs' materials and CAM values (feed, speed of T5).
const PROGRAMS: [(u32, &str, u32, u32); 6] = [
    (1001, "AL6061", 800, 8000),
    (1002, "AL6061", 800, 8000),
    (1003, "AL6061", 800, 8000),
    (1004, "AL6061", 800, 8000),
    (1005, "1.4301", 400, 3000),
    (1006, "1.4301", 400, 3000),
];

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
    // Noise on M2: the feed nudged both ways.
    for (i, (d, f)) in [(30, 820), (90, 780), (150, 816), (210, 784), (260, 824), (300, 776)].iter().enumerate() {
        h.push(("M2", *d, 1004 - (i % 2) as u32 * 3, *f, 8000, ["JOE", "KIM"][i % 2]));
    }
    h
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
        for (i, (machine, day, n, f, s, who)) in history().into_iter().enumerate() {
            let material = PROGRAMS.iter().find(|p| p.0 == n).unwrap().1;
            let rel = format!("hist/{}/{day:03}/O{n}.nc", machine.to_lowercase());
            put_dated(&shop.path(&rel), &program(n, material, f, s, Some((i as u32, who))), day as i64);
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
    assert_eq!(passed.len(), 1, "{}", serde_json::to_string_pretty(&all).unwrap());
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
    // The decoys, each held by its gate.
    let held = |machine: &str, parameter: &str, material: &str| -> String {
        let e = all
            .iter()
            .find(|e| {
                e["s"]["key"]["machine"] == machine && e["s"]["key"]["parameter"] == parameter && e["s"]["key"]["material"] == material
            })
            .unwrap_or_else(|| panic!("no group {machine} {parameter} {material}"));
        e["s"]["held"].as_array().unwrap().iter().map(|h| h["gate"].as_str().unwrap().to_owned()).collect::<Vec<_>>().join(",")
    };
    assert_eq!(held("M2", "spindle_speed", "AL6061"), "too_few", "one operator's bad week: one operator, four days");
    assert_eq!(held("M1", "cutting_feed", "1.4301"), "reversal");
    assert!(held("M2", "cutting_feed", "AL6061").contains("small"), "{}", held("M2", "cutting_feed", "AL6061"));
    let id = p["id"].as_str().unwrap().to_owned();
    // Proposed by the first listing; a planner accepts it.
    shop.ncplan(&["suggest", "--config", "ncplan.toml", "--accept", &id, "--by", "anna", "--now", "2026-11-30T00:00:00Z"]);
    let out =
        shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "fusion", "--by", "anna", "--now", "2026-11-30T01:00:00Z"]);
    assert!(out.contains("1 accepted suggestions exported"), "{out}");
    shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "csv", "--now", "2026-11-30T01:00:00Z"]);
    shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "html", "--now", "2026-11-30T01:00:00Z"]);
    shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "nx", "--now", "2026-11-30T01:00:00Z"]);
    let nx = std::fs::read_to_string(shop.path("outbox/ncplan-tool_machining_data.dat")).unwrap();
    // The library reads back: one tool, T5, with the suggestion's preset.
    let json = std::fs::read_to_string(shop.path("outbox/ncplan-suggestions.json")).unwrap();
    let lib = library::read(&json).unwrap();
    assert_eq!(lib.tools.len(), 1);
    let t = &lib.tools[0];
    assert_eq!((t.number, t.diameter, t.description.as_str()), (Some(5), Some(10.0), "EM10 3FL ALU"));
    // The shop's tool, copied under a new guid with its own preset as it was and one more.
    let shop_lib = library::read(SHOP_LIBRARY).unwrap();
    let original = &shop_lib.tools[0];
    assert_ne!(t.raw["guid"], original.raw["guid"]);
    assert_eq!(t.raw["start-values"]["presets"][0], original.raw["start-values"]["presets"][0]);
    assert_eq!(t.presets.len(), 2);
    for k in ["geometry", "post-process", "vendor", "product-id", "BMC", "type", "unit", "description"] {
        assert_eq!(t.raw[k], original.raw[k], "{k}");
    }
    assert_eq!(lib.version, shop_lib.version);
    let preset = &t.presets.last().unwrap().1;
    let v = library::preset_value(t, preset, ncplan::suggest::Parameter::CuttingFeed).unwrap();
    assert!((v - value).abs() < 1e-3, "{v} {value}");
    // The `.tools` file is the same JSON, zipped.
    let zip = std::fs::read(shop.path("outbox/ncplan-suggestions.tools")).unwrap();
    assert_eq!(&zip[..4], b"PK\x03\x04");
    assert_eq!(&zip[30..40], b"tools.json");
    assert_eq!(&zip[40..40 + json.len()], json.as_bytes());
    let csv = std::fs::read_to_string(shop.path("outbox/ncplan-suggestions.csv")).unwrap();
    assert_eq!(csv.lines().count(), 2, "{csv}");
    assert!(csv.lines().nth(1).unwrap().starts_with(&format!("{id},exported,tool,5,EM10 3FL ALU,10,3,0,AL6061,M1,")), "{csv}");
    let html = std::fs::read_to_string(shop.path("outbox/ncplan-suggestions.html")).unwrap();
    assert!(html.contains(&format!("id=\"s-{id}\"")) && html.contains("<svg"), "{html}");
    // A reader of the format written from public examples (Python's json and zipfile, no
    // ncplan code): the .tools zip holds the same JSON; the tool is the shop's under a new guid,
    // its own preset as it was, one preset more with the new feed and the evidence.
    let facts = independent_reader(&shop.path("outbox/ncplan-suggestions.tools"), &shop.path("lib/shop-tools.json"));
    assert_eq!(facts["same_json"], true, "{facts}");
    assert_eq!(facts["tools"], 1, "{facts}");
    assert_eq!(facts["guid_new"], true, "{facts}");
    assert_eq!(facts["first_preset_kept"], true, "{facts}");
    assert_eq!(facts["presets"], 2, "{facts}");
    assert_eq!(facts["number"], 5, "{facts}");
    assert!((facts["v_f"].as_f64().unwrap() - value).abs() < 1e-3, "{facts}");
    assert!(facts["description"].as_str().unwrap().starts_with(&format!("ncplan {id}: cutting feed 800 -> ")), "{facts}");
    // The CAM side posts O1001 again with the value; the daemon stores it and records the
    // adoption itself (no command runs).
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
    let (_, states) = s.query("SELECT state, decided_by FROM suggestion_events ORDER BY suggestion, step").unwrap();
    let states: Vec<String> = states.iter().map(|r| r.join(" by ")).collect();
    assert_eq!(states, ["proposed by ncplan", "accepted by anna", "exported by anna", "adopted by ncplan", "reopened by ncplan"]);
    let (_, view) = s.query("SELECT state, steps FROM suggestion_states").unwrap();
    assert_eq!(view, [["reopened".to_owned(), "5".to_owned()]]);
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
tool = lib["data"][0]
mine = [t for t in shop["data"] if t["post-process"]["number"] == tool["post-process"]["number"]][0]
presets = tool["start-values"]["presets"]
print(json.dumps({
    "names": names, "same_json": same, "tools": len(lib["data"]), "number": tool["post-process"]["number"],
    "guid_new": tool["guid"] != mine["guid"] and len(tool["guid"]) == 36,
    "first_preset_kept": presets[0] == mine["start-values"]["presets"][0],
    "presets": len(presets), "v_f": presets[-1]["v_f"], "description": presets[-1]["description"],
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
    assert_eq!(cards.len(), 1);
    let title = text_of(c, "section.suggestion h2").await;
    assert!(
        title.contains("cutting feed of T5") && title.contains("AL6061") && title.contains("M1") && title.contains("proposed"),
        "{title}"
    );
    assert_eq!(c.find_all(Locator::Css("section.suggestion svg.chart")).await?.len(), 2, "both pictures");
    assert_eq!(c.find_all(Locator::Css("section.suggestion table.evidence tr")).await?.len(), 11, "ten edits and the header");
    let link = c.find(Locator::Css("section.suggestion table.evidence a")).await?.attr("href").await?.unwrap_or_default();
    assert!(link.starts_with("/compare/") && link.contains("#change-"), "{link}");
    assert!(text_of(c, "table.held").await.contains("reversed by the latest edits"));
    shot(c, &format!("suggestions-{engine}")).await?;
    c.find(Locator::Css("button[data-to=accepted]")).await?.click().await?;
    assert!(wait_text(c, "section.suggestion h2", "accepted").await.contains("accepted"));
    assert!(text_of(c, "ol.steps").await.contains("accepted by planner"));
    shot(c, &format!("suggestion-accepted-{engine}")).await?;
    shop.ncplan(&["export-suggestions", "--config", "ncplan.toml", "--to", "fusion"]);
    c.goto(&format!("{base}/suggestions")).await?;
    assert!(text_of(c, "section.suggestion h2").await.contains("exported"));
    // A rejection needs its reason: refused without one, recorded with one.
    c.find(Locator::Css("button[data-to=rejected]")).await?.click().await?;
    assert!(wait_text(c, "body", "needs its reason").await.contains("a rejection needs its reason"));
    c.goto(&format!("{base}/suggestions")).await?;
    c.find(Locator::Css("input[name=reason]")).await?.send_keys("the new cutter runs at the CAM value").await?;
    c.find(Locator::Css("button[data-to=rejected]")).await?.click().await?;
    assert!(wait_text(c, "ol.steps", "rejected").await.contains("rejected by planner"));
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
        assert_eq!(all.as_array().unwrap().len(), 1, "{all}");
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

/// The README's loop on the bundled demo: its history imported from a copy of the checkout's
/// `demo` and `config`, with the built-in configuration (no `--config`), makes exactly the
/// suggestion the README shows (DMU50's T3 roughing feed, 1200 → 880), holds HAAS1's nudges
/// back, and exports it into the demo's outbox.
#[test]
fn the_readme_loop_runs_on_the_demo() {
    let dir = tempfile::tempdir().unwrap();
    for sub in ["demo", "config"] {
        let ok = Command::new("cp").arg("-r").arg(crate::root().join(sub)).arg(dir.path()).status().unwrap().success();
        assert!(ok, "copying {sub}");
    }
    let run = |args: &[&str]| -> String {
        let out = Command::new(crate::bin()).args(args).current_dir(dir.path()).output().unwrap();
        assert!(out.status.success(), "ncplan {args:?}: {}", String::from_utf8_lossy(&out.stderr));
        String::from_utf8_lossy(&out.stdout).into_owned()
    };
    run(&["import", "demo/history/cam", "--cam"]);
    assert!(run(&["import", "demo/history/DMU50", "--machine", "DMU50"]).contains("7 compared with their original"));
    run(&["import", "demo/history/HAAS1", "--machine", "HAAS1"]);
    let listed = run(&["suggest", "--all"]);
    let lines: Vec<&str> = listed.lines().filter(|l| !l.starts_with(' ')).collect();
    assert_eq!(lines.len(), 2, "{listed}");
    assert!(
        lines[0].starts_with("6bc3e52ba2e3 proposed  cutting feed of T3 Ø12 FLAT END MILL · AL6061-T6 · DMU50")
            && lines[0].contains("CAM 1200 -> 880 mm/min (-26.7 %; 840 to 880); 7 edits, 3 programs, 7 days, 2 operators, p=0.016"),
        "{listed}"
    );
    assert!(lines[1].contains(" held ") && lines[1].contains("HAAS1"), "{listed}");
    run(&["suggest", "--accept", "6bc3e52ba2e3", "--by", "anna"]);
    assert!(run(&["export-suggestions", "--to", "fusion", "--by", "anna"]).contains("1 accepted suggestions exported"));
    let lib = library::read(&std::fs::read_to_string(dir.path().join("var/outbox/ncplan-suggestions.json")).unwrap()).unwrap();
    let preset = &lib.tools[0].presets[0].1;
    assert_eq!((lib.tools[0].number, preset.get("v_f").copied()), (Some(3), Some(880.0)));
}

//! The dialect dictionary: shipped files load cleanly, pass the XSD, and broken files are
//! reported with file:line:col.

use std::process::Command;

use ncplan::dialect::{self, Meaning, Registry, Role};

#[test]
fn shipped_dialects_load_without_findings() {
    let mut r = Registry::default();
    for (origin, text) in dialect::registry::SHIPPED {
        let (d, findings) = r.add_with_findings(origin, text);
        assert!(findings.is_empty(), "{origin}: {findings:?}");
        let d = d.unwrap();
        // Every dialect can move in a straight line, by G1 or by a keyword (`L`).
        assert!(d.code_for(Meaning::Linear).is_some(), "{origin}");
        assert_eq!(d.letter_role(b'x'), Some(Role::X));
    }
    // The compiled-in copies are the files in dialects/.
    for (origin, text) in dialect::registry::SHIPPED {
        assert_eq!(std::fs::read_to_string(crate::root().join("dialects").join(origin)).unwrap(), *text);
    }
}

#[test]
fn shipped_dialects_validate_against_the_schema() {
    let root = crate::root().join("dialects");
    if Command::new("xmllint").arg("--version").output().is_err() {
        assert!(std::env::var_os("NCPLAN_REQUIRE_XMLLINT").is_none(), "NCPLAN_REQUIRE_XMLLINT is set but xmllint is not installed");
        crate::skip(
            "dialects::shipped_dialects_validate_against_the_schema",
            "xmllint is not installed (Debian libxml2-utils; .ci/run installs it)",
        );
        return;
    }
    for (origin, _) in dialect::registry::SHIPPED {
        let out = Command::new("xmllint")
            .args(["--noout", "--schema"])
            .arg(root.join("dialect.xsd"))
            .arg(root.join(origin))
            .output()
            .expect("xmllint runs");
        assert!(out.status.success(), "{origin}: {}", String::from_utf8_lossy(&out.stderr));
    }
}

#[test]
fn the_format_expresses_multi_letter_addresses_positional_cycles_and_keyword_blocks() {
    // A sketch of what later dialects need: Siemens `CR=`, `CYCLE81(...)`, Heidenhain word-first.
    let xml = r#"<dialect xmlns="urn:ncplan:dialect:1" name="sketch" family="siemens">
  <lexical block-form="keyword-first">
    <comment open=";" close="eol"/>
    <block-skip char="/"/>
    <continuation char="~"/>
  </lexical>
  <behaviour decimal-input="calculator" dwell-unit="seconds"/>
  <addresses>
    <address name="X" role="axis-x"/><address name="CR" role="radius" form="assign"/>
    <address name="G" role="g-code"/><address name="I1" role="geometry" form="assign"/>
  </addresses>
  <execution-order>motion tool-change</execution-order>
  <groups>
    <group id="motion" step="motion"><code value="2" meaning="arc-cw" optional="X" any-of="CR"/><code keyword="L" meaning="linear" optional="X"/></group>
    <group id="tool" step="tool-change"><code keyword="TOOL  CALL" value-role="tool" meaning="tool-change"/></group>
  </groups>
  <cycles><cycle name="CYCLE81" meaning="cycle-drill"><arg name="RTP" role="retract-plane" use="required"/><arg name="RFP" role="reference-plane"/></cycle></cycles>
</dialect>"#;
    let mut r = Registry::default();
    let d = r.add("sketch.xml", xml).unwrap();
    assert_eq!(d.long_addresses().map(|a| a.name.as_str()).collect::<Vec<_>>(), ["CR", "I1"]);
    assert_eq!(d.cycles[0].args.len(), 2);
    // Keyword codes, longest first, with blanks normalised.
    assert_eq!(d.keyword_codes().map(|(_, k)| k.text.as_str()).collect::<Vec<_>>(), ["TOOL CALL", "L"]);
    // And the engine reads `CR=` words through it.
    let mut diags = Vec::new();
    let mut block = ncplan::syntax::Block::default();
    let mut p = ncplan::syntax::Parser::new("G2 X10 CR=5", &d);
    assert!(p.next_block(&mut block, &mut diags));
    assert_eq!(block.words.iter().map(|w| w.role).collect::<Vec<_>>(), [Role::G, Role::X, Role::R]);
    assert!(diags.is_empty(), "{diags:?}");
}

#[test]
fn broken_dialect_files_name_file_line_and_column() {
    let tmp = tempfile::tempdir().unwrap();
    let f = tmp.path().join("bad.xml");
    let text =
        std::fs::read_to_string(crate::root().join("dialects/fanuc.xml")).unwrap().replace(r#"meaning="rapid""#, r#"meaning="warp-speed""#);
    std::fs::write(&f, &text).unwrap();
    let out = Command::new(crate::bin()).arg("dialects").arg(&f).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let line = text.lines().position(|l| l.contains("warp-speed")).unwrap() + 1;
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.contains(&format!("bad.xml:{line}:")), "{stdout}");
    assert!(stdout.contains("unknown meaning `warp-speed`"), "{stdout}");

    // A code's argument roles name addresses it takes, and known roles.
    let text = std::fs::read_to_string(crate::root().join("dialects/haas.xml"))
        .unwrap()
        .replace("args=\"I:pattern-radius J:pattern-angle L:pattern-count\"", "args=\"Q:pattern-radius J:pattern-size\"");
    std::fs::write(&f, &text).unwrap();
    let out = Command::new(crate::bin()).arg("dialects").arg(&f).output().unwrap();
    assert_eq!(out.status.code(), Some(1));
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        stdout.contains("`Q:pattern-radius` is not ADDRESS:role") && stdout.contains("`J:pattern-size` is not ADDRESS:role"),
        "{stdout}"
    );
}

#[test]
fn the_dialect_is_told_from_the_text_and_the_file_name() {
    use ncplan::dialect::sniff::Confidence;
    let r = Registry::shipped();
    for (ext, want) in [("nc", "fanuc"), ("mpf", "siemens"), ("h", "heidenhain")] {
        for part in ["face", "drill_ream", "peck", "pocket"] {
            let name = format!("{part}.{ext}");
            let text = std::fs::read_to_string(crate::root().join("tests/programs/equivalence").join(&name)).unwrap();
            let s = r.sniff(&text, Some(&name), "linuxcnc");
            assert_eq!(s.dialect, want, "{name}: {s:?}");
            // A plain ISO program is Fanuc's, but a Haas or a Mitsubishi control would read it
            // too: the maker is a guess (low); the others are sure.
            let least = if ext == "nc" { Confidence::Low } else { Confidence::Medium };
            assert!(s.confidence >= least, "{name}: {s:?}");
            // The text alone is enough for the conversational and Siemens headers.
            if ext != "nc" {
                let s = r.sniff(&text, None, "linuxcnc");
                assert_eq!((s.dialect.as_str(), s.confidence), (want, Confidence::High), "{name} without its name: {s:?}");
            }
        }
    }
    let ngc = "o<probe> sub\n#<depth> = 5\no<probe> endsub\n";
    assert_eq!(r.sniff(ngc, Some("probe.ngc"), "fanuc").dialect, "linuxcnc");
    // No evidence: the default, and a low confidence.
    let s = r.sniff("G0 X1.5\n", None, "linuxcnc");
    assert_eq!((s.dialect.as_str(), s.confidence, s.score), ("linuxcnc", Confidence::Low, 0));
    // A whole coordinate without a point reads as millimetres: not Fanuc's least increments.
    let s = r.sniff("G0 X1.5 Y2.\nG1 Z10 F100\n", None, "fanuc");
    assert_eq!(s.dialect, "linuxcnc", "{s:?}");
    // Evidence inside a comment does not count: `CR=` in a Fanuc tool comment is not Siemens.
    let s = r.sniff("O1000\n(T1 D=2.7 CR=0 FLAT END MILL)\nG2 X1 Y1 R1\n", Some("a.nc"), "linuxcnc");
    assert_eq!(s.dialect, "fanuc", "{s:?}");
}

#[test]
fn every_heidenhain_and_siemens_corpus_program_is_recognised() {
    let Some(corpus) = crate::shared_corpus("dialects::every_heidenhain_and_siemens_corpus_program_is_recognised") else { return };
    let r = Registry::shipped();
    for (folder, want) in [("heidenhain", "heidenhain"), ("siemens", "siemens")] {
        let Ok(dir) = std::fs::read_dir(corpus.join(folder)) else { continue };
        let mut wrong = Vec::new();
        for e in dir.flatten() {
            let bytes = std::fs::read(e.path()).unwrap();
            let (source, _) = ncplan::text::decode(&bytes);
            let name = e.file_name().to_string_lossy().into_owned();
            let s = r.sniff(&source.text, Some(&name), "linuxcnc");
            // By family: a TNC program in DIN/ISO is heidenhain_iso, a Klartext one heidenhain.
            if r.get(&s.dialect).map(|d| d.family.clone()).as_deref() != Some(want) {
                wrong.push(format!("{name}: {} ({})", s.dialect, s.evidence.join(", ")));
            }
        }
        // Siemens syntax-test fragments with no Siemens-only construct may look like plain ISO.
        assert!(wrong.len() <= if want == "siemens" { 3 } else { 0 }, "{folder}: {wrong:#?}");
    }
}

#[test]
fn a_broken_recognition_pattern_is_reported_with_its_position() {
    let xml = r#"<dialect xmlns="urn:ncplan:dialect:1" name="bad" family="x">
  <lexical><comment open="(" close=")"/></lexical>
  <addresses><address name="G" role="g-code"/></addresses>
  <execution-order>motion</execution-order>
  <recognise><marker regex="(unclosed" weight="5"/></recognise>
</dialect>"#;
    let (_, diags) = dialect::load(xml);
    let d = diags.iter().find(|d| d.message.contains("regular expression")).expect("a finding for the regex");
    let line = xml[..d.range.start as usize].lines().count();
    assert_eq!(line, 5, "{d:?}");
}

/// Every shipped dialect's `plane-under-comp` as read (inherited or its own): a value a new
/// dialect inherits from its base shows here. `stops` only where the manual was checked
/// (Fanuc PS0037, and the dialects whose own manuals say so or lock modes under comp).
#[test]
fn every_dialect_s_plane_under_comp_is_listed() {
    let mut r = Registry::default();
    let mut got = Vec::new();
    for (origin, text) in dialect::registry::SHIPPED {
        let d = r.add_with_findings(origin, text).0.unwrap();
        got.push(format!("{}={}", d.name, if d.behaviour.plane_under_comp_stops { "stops" } else { "unknown" }));
    }
    got.sort();
    let want: Vec<&str> = vec![
        "centroid=stops",
        "cldata=unknown",
        "fagor=unknown",
        "fagor_lathe=unknown",
        "fanuc=stops",
        "fanuc_lathe=stops",
        "fanuc_lathe_b=stops",
        "haas=unknown",
        "haas_lathe=unknown",
        "heidenhain=unknown",
        "heidenhain_iso=unknown",
        "linuxcnc=stops",
        "lnc=unknown",
        "mach3=stops",
        "mazak=unknown",
        "mazak_lathe=unknown",
        "mazak_millturn=unknown",
        "mitsubishi=stops",
        "mitsubishi_lathe=stops",
        "okuma=unknown",
        "okuma_lathe=unknown",
        "pathpilot=stops",
        "siemens=unknown",
        "siemens_810=unknown",
    ];
    assert_eq!(got, want, "{got:#?}");
}

//! Architecture invariants, checked on the source text.

use std::path::Path;

fn sources(dir: &Path, out: &mut Vec<(String, String)>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            sources(&p, out);
        } else if p.extension().is_some_and(|x| x == "rs") {
            let rel = p.strip_prefix(crate::root().join("src")).unwrap().to_string_lossy().replace('\\', "/");
            out.push((rel, std::fs::read_to_string(&p).unwrap()));
        }
    }
}

fn module(rel: &str) -> &str {
    rel.split(['/', '.']).next().unwrap()
}

#[test]
fn the_core_does_no_io_and_each_capability_lives_in_one_module() {
    let mut files = Vec::new();
    sources(&crate::root().join("src"), &mut files);
    let core = ["text", "diag", "dialect", "syntax", "interp", "canon", "plan", "part21", "diff", "pipeline", "view", "post"];
    let only = [
        ("notify", "daemon"),
        ("axum", "web"),
        ("maud", "web"),
        ("argon2", "web"),
        ("rusqlite", "store"),
        ("postgres", "store"),
        ("tokio_postgres", "store"),
        ("rustls", "store"),
        ("quick_xml", "dialect"),
    ];
    for (rel, text) in &files {
        let m = module(rel);
        // tokio: the daemon's runtime, and the web server's.
        if text.contains("tokio::") {
            assert!(m == "daemon" || m == "web", "{rel} uses tokio, which only daemon and web may use");
        }
        for (krate, owner) in only {
            if text.contains(&format!("{krate}::")) {
                assert_eq!(m, owner, "{rel} uses {krate}, which only {owner} may use");
            }
        }
        if core.contains(&m) {
            for banned in ["std::fs", "std::net", "std::env", "SystemTime", "Instant::now", "std::process", "println!", "eprintln!"] {
                assert!(!text.contains(banned), "core module {rel} uses {banned}");
            }
        }
        if m != "cli" {
            assert!(!text.contains("println!") && !text.contains("eprintln!"), "{rel} prints; only cli may");
        }
    }
}

#[test]
fn no_code_branches_on_a_dialect_name() {
    let mut files = Vec::new();
    sources(&crate::root().join("src"), &mut files);
    let names: Vec<String> = std::fs::read_dir(crate::root().join("dialects"))
        .unwrap()
        .filter_map(|e| {
            let p = e.unwrap().path();
            (p.extension()? == "xml").then(|| p.file_stem().unwrap().to_string_lossy().into_owned())
        })
        .collect();
    assert!(names.len() >= 2);
    for (rel, text) in &files {
        for name in &names {
            let upper = name.to_uppercase();
            for pattern in [
                format!("== \"{name}\""),
                format!("\"{name}\" =>"),
                format!("\"{name}\" |"),
                format!("== \"{upper}\""),
                format!("\"{upper}\" =>"),
                format!(".contains(\"{name}"),
            ] {
                let hits = text.matches(&pattern).count();
                assert_eq!(hits, 0, "{rel} mentions the dialect name {pattern}: dialect differences belong in dialects/*.xml");
            }
        }
    }
}

#[test]
fn every_module_has_a_doc_comment() {
    let mut files = Vec::new();
    sources(&crate::root().join("src"), &mut files);
    for (rel, text) in files {
        assert!(text.starts_with("//!"), "{rel} lacks a //! module doc");
    }
}

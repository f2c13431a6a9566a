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
    let core =
        ["text", "diag", "dialect", "syntax", "interp", "canon", "plan", "part21", "diff", "pipeline", "view", "post", "proof", "suggest"];
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

/// A source file's module path: `web/pages.rs` is `web::pages`, `web/mod.rs` is `web`,
/// `lib.rs` the crate root.
fn module_path(rel: &str) -> Vec<String> {
    let mut path: Vec<String> = rel.trim_end_matches(".rs").split('/').map(str::to_owned).collect();
    if path.last().is_some_and(|l| l == "mod" || l == "lib") {
        path.pop();
    }
    path
}

/// The paths a piece of code names from `crate`, `super` or `self` (a `use` group gives one
/// path per item), and those `use` statements name from a child module (`use lane::Lane;`
/// in a `mod.rs`), each as its segments.
fn named_paths(code: &str, children: &dyn Fn(&str) -> bool) -> Vec<Vec<String>> {
    let b = code.as_bytes();
    let ident = |i: usize| b.get(i).is_some_and(|c| c.is_ascii_alphanumeric() || *c == b'_');
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let start = i;
        if !ident(i) || (i > 0 && (ident(i - 1) || b[i - 1] == b':')) {
            i += 1;
            continue;
        }
        while ident(i) {
            i += 1;
        }
        let first = &code[start..i];
        // `use` as a word, then blanks, then the path.
        let before = code[..start].trim_end();
        let after_use = before.len() < start && before.ends_with("use") && !(before.len() > 3 && ident(before.len() - 4));
        let rooted = matches!(first, "crate" | "super" | "self") || (after_use && children(first));
        if !rooted || !code[i..].starts_with("::") {
            continue;
        }
        let mut head = vec![first.to_owned()];
        while code[i..].starts_with("::") {
            i += 2;
            let s = i;
            while ident(i) {
                i += 1;
            }
            if s == i {
                break;
            }
            head.push(code[s..i].to_owned());
        }
        if code[i..].starts_with('{') {
            // A `use` group: the first segment of each item at its top level.
            let (mut depth, mut item, mut j) = (0usize, String::new(), i + 1);
            let mut items = Vec::new();
            while j < b.len() {
                match b[j] {
                    b'{' => depth += 1,
                    b'}' if depth == 0 => break,
                    b'}' => depth -= 1,
                    b',' if depth == 0 => items.push(std::mem::take(&mut item)),
                    _ => {}
                }
                if depth > 0 || b[j] != b',' {
                    item.push(b[j] as char);
                }
                j += 1;
            }
            items.push(item);
            for item in items {
                let seg: String = item.trim().chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect();
                let mut path = head.clone();
                if !seg.is_empty() && seg != "self" {
                    path.push(seg);
                }
                out.push(path);
            }
            i = j;
        } else {
            out.push(head);
        }
    }
    out
}

/// Each source file (but `main.rs`) with the files it names, by `crate::`, `super::` and
/// `self::` paths and `use` statements, a module named by its file (`mod.rs` for a folder).
/// A file's own test module counts. Naming a module that holds the file (its `mod.rs`, the
/// crate root) is not counted: a folder's door and its files are one unit.
fn file_graph() -> std::collections::BTreeMap<String, std::collections::BTreeSet<String>> {
    let mut files = Vec::new();
    sources(&crate::root().join("src"), &mut files);
    files.retain(|(rel, _)| rel != "main.rs");
    let by_module: std::collections::BTreeMap<Vec<String>, String> = files.iter().map(|(rel, _)| (module_path(rel), rel.clone())).collect();
    let mut graph = std::collections::BTreeMap::new();
    for (rel, text) in &files {
        let own = module_path(rel);
        let code: String = text.lines().map(|l| l.find("//").map_or(l, |at| &l[..at])).collect::<Vec<_>>().join("\n");
        // An inline module (the tests, at the end of a file) is one level down.
        let mut parts = vec![(own.clone(), code.as_str())];
        if let Some(at) = code.lines().position(|l| {
            let l = l.trim_start_matches("pub ").trim_start_matches("pub(crate) ");
            l.starts_with("mod ") && l.trim_end().ends_with('{')
        }) {
            let offset: usize = code.lines().take(at).map(|l| l.len() + 1).sum();
            let line = code[offset..].lines().next().unwrap();
            let name = line.split_whitespace().skip_while(|w| *w != "mod").nth(1).unwrap().to_owned();
            let mut inner = own.clone();
            inner.push(name);
            parts = vec![(own.clone(), &code[..offset]), (inner, &code[offset..])];
        }
        let mut named = std::collections::BTreeSet::new();
        for (base, code) in parts {
            let children = |seg: &str| {
                let mut m = base.clone();
                m.push(seg.to_owned());
                by_module.contains_key(&m)
            };
            for path in named_paths(code, &children) {
                let mut m = if path[0] == "crate" { Vec::new() } else { base.clone() };
                let mut segs = path.iter().skip(usize::from(path[0] == "crate")).peekable();
                while let Some(s) = segs.next_if(|s| *s == "super" || *s == "self") {
                    if s == "super" {
                        m.pop();
                    }
                }
                for s in segs {
                    let mut deeper = m.clone();
                    deeper.push(s.clone());
                    if !by_module.contains_key(&deeper) {
                        break;
                    }
                    m = deeper;
                }
                while !by_module.contains_key(&m) {
                    m.pop();
                }
                if !own.starts_with(&m) {
                    named.insert(by_module[&m].clone());
                }
            }
        }
        graph.insert(rel.clone(), named);
    }
    graph
}

#[test]
fn no_two_files_need_each_other() {
    let graph = file_graph();
    // The reading works: a few references it must see.
    for (from, to) in [
        ("web/pages.rs", "web/layout.rs"),
        ("pipeline.rs", "text.rs"),
        ("diag.rs", "text.rs"),
        ("dialect/load/records.rs", "dialect/xml.rs"),
    ] {
        assert!(graph[from].contains(to), "{from} should be seen naming {to}: {:?}", graph[from]);
    }
    // Depth-first, keeping the path: a file met again on it closes a cycle.
    fn visit<'g>(
        file: &'g str,
        graph: &'g std::collections::BTreeMap<String, std::collections::BTreeSet<String>>,
        path: &mut Vec<&'g str>,
        done: &mut std::collections::BTreeSet<&'g str>,
    ) {
        if let Some(at) = path.iter().position(|f| *f == file) {
            let cycle: Vec<&str> = path[at..].iter().copied().chain([file]).collect();
            panic!("an import cycle between source files: {}; move what they share into a file below them", cycle.join(" → "));
        }
        if !done.insert(file) {
            return;
        }
        path.push(file);
        for next in &graph[file] {
            visit(next, graph, path, done);
        }
        path.pop();
    }
    let mut done = std::collections::BTreeSet::new();
    for file in graph.keys() {
        visit(file, &graph, &mut Vec::new(), &mut done);
    }
}

#[test]
fn the_core_names_no_shell_module() {
    let core =
        ["text", "diag", "dialect", "syntax", "interp", "canon", "plan", "part21", "diff", "pipeline", "view", "post", "proof", "suggest"];
    let shell = ["cli", "daemon", "store", "web", "config", "bench", "import", "reanalyze", "pairing", "textfile"];
    for (from, named) in file_graph() {
        if !core.contains(&module(&from)) {
            continue;
        }
        for to in named {
            assert!(!shell.contains(&module(&to)), "core file {from} names {to}, a module of the IO shell");
        }
    }
}

/// A command module parses its arguments, asks the core through `pipeline` (or the store
/// through `store`) and prints: it names no core module itself, so that how the core's rooms
/// are wired stays in one place, shared with the daemon and the web.
#[test]
fn the_commands_reach_the_core_only_through_pipeline() {
    let core = ["text", "diag", "dialect", "syntax", "interp", "canon", "plan", "part21", "diff", "view", "post", "proof", "suggest"];
    for (from, named) in file_graph() {
        if module(&from) != "cli" {
            continue;
        }
        for to in named {
            assert!(!core.contains(&module(&to)), "command file {from} names {to}, a core module; it goes through pipeline");
        }
    }
}

/// The code with its comments, string and character literals blanked (lengths kept), so
/// that braces are counted only where they are code.
fn code_only(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let blank = |out: &mut Vec<u8>, s: &[u8]| out.extend(s.iter().map(|c| if *c == b'\n' { b'\n' } else { b' ' }));
        if b[i..].starts_with(b"//") {
            let end = b[i..].iter().position(|c| *c == b'\n').map_or(b.len(), |k| i + k);
            blank(&mut out, &b[i..end]);
            i = end;
        } else if b[i..].starts_with(b"r#\"") || b[i..].starts_with(b"r\"") {
            let hashes = b[i + 1..].iter().take_while(|c| **c == b'#').count();
            let close: Vec<u8> = std::iter::once(b'"').chain(std::iter::repeat_n(b'#', hashes)).collect();
            let from = i + 2 + hashes;
            let end = b[from..].windows(close.len()).position(|w| w == close).map_or(b.len(), |k| from + k + close.len());
            blank(&mut out, &b[i..end]);
            i = end;
        } else if b[i] == b'"' {
            let mut j = i + 1;
            while j < b.len() && b[j] != b'"' {
                j += if b[j] == b'\\' { 2 } else { 1 };
            }
            let end = (j + 1).min(b.len());
            blank(&mut out, &b[i..end]);
            i = end;
        } else if b[i] == b'\'' && (b.get(i + 2) == Some(&b'\'') || b.get(i + 1) == Some(&b'\\') && b.get(i + 3) == Some(&b'\'')) {
            let end = if b[i + 1] == b'\\' { i + 4 } else { i + 3 };
            blank(&mut out, &b[i..end]);
            i = end;
        } else {
            out.push(b[i]);
            i += 1;
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// Every function with a body: (file, name, lines from `fn` to its closing brace).
fn function_lengths() -> Vec<(String, String, usize)> {
    let mut files = Vec::new();
    sources(&crate::root().join("src"), &mut files);
    let mut found = Vec::new();
    for (rel, text) in &files {
        let code = code_only(text);
        let lines: Vec<&str> = code.lines().collect();
        for (n, line) in lines.iter().enumerate() {
            let words: Vec<&str> = line.split(|c: char| !(c.is_alphanumeric() || c == '_')).filter(|w| !w.is_empty()).collect();
            let Some(at) = words.iter().position(|w| *w == "fn") else { continue };
            let Some(name) = words.get(at + 1) else { continue };
            // Up to the body's opening brace (a declaration without one has no body).
            let (mut depth, mut opened) = (0i64, false);
            'scan: for (k, l) in lines.iter().enumerate().skip(n) {
                for c in l.chars() {
                    match c {
                        ';' if !opened => break 'scan,
                        '{' => {
                            depth += 1;
                            opened = true;
                        }
                        '}' => depth -= 1,
                        _ => {}
                    }
                    if opened && depth == 0 {
                        found.push((rel.clone(), (*name).to_owned(), k - n + 1));
                        break 'scan;
                    }
                }
            }
        }
    }
    found
}

/// No function is longer than a screen or two: a name explains a piece better than a
/// comment. The only exceptions are matches that are only a table, named here with why.
#[test]
fn no_function_is_longer_than_150_lines() {
    const TABLES: &[(&str, &str, &str)] = &[];
    let long: Vec<String> = function_lengths()
        .into_iter()
        .filter(|(rel, name, n)| *n > 150 && !TABLES.iter().any(|(f, fun, _)| f == rel && fun == name))
        .map(|(rel, name, n)| format!("{rel}: {name} has {n} lines"))
        .collect();
    assert!(long.is_empty(), "functions over 150 lines (split them, or name a table-only match in TABLES):\n{}", long.join("\n"));
}

//! Reports and configuration that mean what they say: a report's filters apply to every
//! format, a date parses or fails, a machine no one knows is an error, a configuration's
//! relative folders are the working directory's and must exist, and `translate -o` never
//! writes into the folders `watch` would watch.

use std::path::Path;
use std::process::{Command, Stdio};

use ncplan::store::{Location, Store};

use crate::faults::{Site, ingest_at};

fn ncplan_in(dir: &Path, args: &[&str]) -> (i32, String, String) {
    let out = Command::new(crate::bin()).args(args).current_dir(dir).output().unwrap();
    (out.status.code().unwrap_or(-1), String::from_utf8_lossy(&out.stdout).into_owned(), String::from_utf8_lossy(&out.stderr).into_owned())
}

/// A site with one feed change on machine M1, detected on 2026-12-01.
fn site_with_a_change() -> Site {
    let site = Site::new("");
    std::fs::create_dir_all(site.path("var")).unwrap();
    let mut store = Store::open(&Location::Sqlite(site.db()), "").unwrap();
    std::fs::write(site.path("cam/O1.nc"), crate::support::program(1, 300, 2000)).unwrap();
    ingest_at(&site, &mut store, "cam/O1.nc", "2026-12-01T10:00:00.000Z", None);
    std::fs::write(site.path("share/O1.nc"), crate::support::program(1, 250, 2000)).unwrap();
    ingest_at(&site, &mut store, "share/O1.nc", "2026-12-01T11:00:00.000Z", None);
    site
}

#[test]
fn report_filters_apply_to_every_format_and_bad_filters_are_errors() {
    let site = site_with_a_change();
    let dir = site.dir.path();
    let report = |args: &[&str]| ncplan_in(dir, &[&["report", "--config", "ncplan.toml"], args].concat());
    for format in ["markdown", "csv", "html"] {
        let (code, all, err) = report(&["--format", format]);
        assert_eq!(code, 0, "{err}");
        assert!(all.contains("F250"), "{format}: {all}");
        let (code, later, err) = report(&["--format", format, "--since", "2030-01-01"]);
        assert_eq!(code, 0, "{err}");
        assert!(!later.contains("F250"), "{format} --since 2030-01-01 still lists the change:\n{later}");
        let (code, on_day, err) = report(&["--format", format, "--since", "2026-12-01", "--machine", "M1"]);
        assert_eq!(code, 0, "{err}");
        assert!(on_day.contains("F250"), "{format}: {on_day}");
    }
    let (_, markdown, _) = report(&["--since", "2030-01-01"]);
    assert!(markdown.contains("No changes recorded."), "{markdown}");
    // A machine no one knows, and dates that are not dates, are errors, not empty reports.
    let (code, out, err) = report(&["--machine", "NOPE"]);
    assert_ne!(code, 0, "{out}");
    assert!(err.contains("no machine `NOPE`") && err.contains("M1"), "{err}");
    for bad in ["yesterday", "2026-02-30", "2026-13-01", "2026-1-1", "01.12.2026"] {
        let (code, out, err) = report(&["--since", bad]);
        assert_ne!(code, 0, "--since {bad}: {out}");
        assert!(err.contains("is not a date") && err.contains("YYYY-MM-DD"), "{bad}: {err}");
    }
    assert_eq!(report(&["--since", "2028-02-29"]).0, 0);
}

#[test]
fn configured_folders_are_the_working_directorys_and_must_exist() {
    let tmp = tempfile::tempdir().unwrap();
    let root = tmp.path();
    std::fs::create_dir_all(root.join("cfg")).unwrap();
    std::fs::create_dir_all(root.join("cam")).unwrap();
    std::fs::create_dir_all(root.join("shares/M1")).unwrap();
    let text = "[database]\npath = 'var/ncplan.db'\n[[cam]]\npath = 'cam'\ndialect = 'fanuc'\n\
                [[machine]]\nname = 'M1'\npath = 'shares/M1'\ndialect = 'fanuc'\n";
    std::fs::write(root.join("cfg/ncplan.toml"), text).unwrap();
    // From the folder the paths are written for, it starts, on those folders.
    let mut child = Command::new(crate::bin())
        .args(["watch", "--config", "cfg/ncplan.toml"])
        .current_dir(root)
        .env("NCPLAN_LOG", "warn")
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut lines = std::io::BufRead::lines(std::io::BufReader::new(child.stdout.take().unwrap()));
    let said: Vec<String> = (0..3).map_while(|_| lines.next().and_then(Result::ok)).collect();
    let daemon = crate::support::Proc(child);
    let real = root.canonicalize().unwrap();
    let under = |rel: &str| {
        said.iter().any(|l| l.ends_with(&root.join(rel).display().to_string()) || l.ends_with(&real.join(rel).display().to_string()))
    };
    assert!(under("cam") && under("shares/M1"), "{said:?}");
    assert!(
        said[0].contains(&root.join("var/ncplan.db").display().to_string())
            || said[0].contains(&real.join("var/ncplan.db").display().to_string()),
        "{said:?}"
    );
    daemon.kill();
    // From elsewhere the folders do not exist: an error at start, naming them.
    let (code, _, err) = ncplan_in(&root.join("cfg"), &["watch", "--config", "ncplan.toml"]);
    assert_ne!(code, 0);
    assert!(err.contains("configured folders do not exist") && err.contains("cfg/cam") && err.contains("cfg/shares/M1"), "{err}");
    assert!(!root.join("cfg/var").exists(), "it created a database for a configuration it refused");
}

#[test]
fn translate_never_writes_into_the_default_configurations_folders() {
    // Without --config, `watch` in a checkout watches the demo folders: translate refuses them.
    let root = crate::root();
    let out = root.join("demo/shares/DMU50/ZZ_TRANSLATED_BY_TEST.nc");
    let (code, _, err) = ncplan_in(
        &root,
        &["translate", "demo/cam/O1234.nc", "-d", "fanuc", "--to", "linuxcnc", "-o", "demo/shares/DMU50/ZZ_TRANSLATED_BY_TEST.nc"],
    );
    let written = out.exists();
    let _ = std::fs::remove_file(&out);
    assert!(!written, "translate wrote into a watched folder");
    assert_ne!(code, 0);
    assert!(err.contains("never writes into a watched folder"), "{err}");
}

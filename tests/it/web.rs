//! The planners' workspace in a real browser: a temporary database built by the real daemon
//! from real edits (the demo's, and a long program whose comments try to inject script), the
//! real `ncplan serve` binary on a free port, and Debian's chromium driven headless through
//! chromedriver (WebDriver, the `fantoccini` crate). Screenshots go to `target/screenshots/`.
//!
//! Without chromium and chromedriver the browser test says it is skipped, unless
//! `NCPLAN_REQUIRE_CHROMIUM` is set (CI sets it), which makes their absence a failure.

use std::net::TcpStream;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use fantoccini::{Client, ClientBuilder, Locator};
use serde_json::json;

use crate::support::{Proc, free_port, http, wait_rows, watch};

/// A process group led by a child: the whole group is ended when dropped.
pub(crate) struct Group(Proc);

impl Drop for Group {
    fn drop(&mut self) {
        let pgid = self.0.0.id();
        let _ = Command::new("kill").args(["-TERM", "--", &format!("-{pgid}")]).stderr(Stdio::null()).status();
    }
}

/// A DNC server in a temporary folder: CAM originals, one machine share, a config.
struct Site {
    dir: tempfile::TempDir,
}

/// The long program: a face milling and a contour at `contour_feed`, 160 lines of
/// moves between them; the hostile one (the edit) has one pass shortened, and comments that
/// try to inject script or reorder text (they must stay text).
fn long_program(contour_feed: u32, hostile: bool) -> String {
    let mut s = String::from("%\nO4321 (POCKET PLATE)\n");
    if hostile {
        s.push_str("(<script>window.pwned=1</script>)\n(\" onload=\"window.pwned=2)\n(<img src=x onerror=window.pwned=3>)\n");
        // The end of a CDATA section, and bidirectional controls that would reorder the text.
        s.push_str("(]]> <![CDATA[ <b>X</b> ]]>)\n(\u{202E}DESREVER\u{202C} \u{2066}ISOLATED\u{2069})\n");
    } else {
        s.push_str("(POSTED BY CAM)\n(CHECK STOCK)\n(OPERATOR NOTES)\n(FIXTURE A)\n(SETUP 2)\n");
    }
    s.push_str("G21 G90 G17 G54\n(T1 D=18 ENDMILL)\nT1 M6\nS2000 M3\nG0 X-10. Y0. Z5.\nG43 H1 Z5.\nG1 Z-1. F600.\n");
    for i in 0..40 {
        let y = f64::from(i) * 2.0;
        // The operator shortened one pass of the face milling (a toolpath change).
        let x = if i % 2 == 1 {
            -10.0
        } else if hostile && i == 20 {
            95.0
        } else {
            110.0
        };
        s.push_str(&format!("X{x:.1}\nY{:.1}\n", y + 2.0));
    }
    s.push_str("G0 Z50.\n");
    for i in 0..80 {
        s.push_str(&format!("(LINE {i})\n"));
    }
    s.push_str(&format!(
        "(T2 D=10 ENDMILL)\nT2 M6\nS3500 M3\nG0 X20. Y20. Z5.\nG43 H2 Z5.\nG1 Z-5. F{contour_feed}.\nX80.\nY60.\nX20.\nY20.\nG0 Z50.\nM30\n%\n"
    ));
    s
}

/// A file name that tries markup, a quote and a right-to-left override (shown as text).
const HOSTILE_NAME: &str = "P\"<b>7<i>\u{202E}lmth.nc";

/// A short program, O7777, with a cut at `feed`.
fn small_program(feed: u32) -> String {
    format!("%\nO7777\nG21 G90 G17 G54\nT1 M6\nS1000 M3\nG0 X0. Y0. Z5.\nG1 Z-1. F{feed}.\nX50.\nG0 Z5.\nM30\n%\n")
}

impl Site {
    fn new() -> Site {
        let dir = tempfile::tempdir().unwrap();
        for d in ["cam", "share"] {
            std::fs::create_dir_all(dir.path().join(d)).unwrap();
        }
        std::fs::write(
            dir.path().join("ncplan.toml"),
            "[database]\npath = 'var/ncplan.db'\n[daemon]\nsettle_ms = 150\n\
             [[cam]]\npath = 'cam'\ndialect = 'fanuc'\n\
             [[machine]]\nname = 'DMU50'\npath = 'share'\ndialect = 'fanuc'\n\
             [[tool]]\nnumber = 1\ndiameter = 18.0\nlength = 50.0\n",
        )
        .unwrap();
        Site { dir }
    }

    fn path(&self, rel: &str) -> PathBuf {
        self.dir.path().join(rel)
    }

    fn db(&self) -> PathBuf {
        self.path("var/ncplan.db")
    }

    fn wait_rows(&self, sql: &str, want: usize) -> Vec<Vec<String>> {
        wait_rows(&self.db(), sql, want, Duration::from_secs(30))
    }

    /// Configures the users `(name, password)` (argon2 hashes), in place of any before.
    fn users(&self, users: &[(&str, &str)]) {
        let cfg = std::fs::read_to_string(self.path("ncplan.toml")).unwrap();
        let cfg = cfg.split("[web]\n").next().unwrap().to_owned() + &crate::support::web_users(users);
        std::fs::write(self.path("ncplan.toml"), cfg).unwrap();
    }

    /// Runs the real daemon over the demo edit and the hostile program, then stops it.
    fn build(&self) {
        let root = crate::root();
        std::fs::copy(root.join("demo/cam/O1234.nc"), self.path("cam/O1234.nc")).unwrap();
        std::fs::write(self.path("cam/O4321.nc"), long_program(400, false)).unwrap();
        std::fs::write(self.path(&format!("cam/{HOSTILE_NAME}")), small_program(500)).unwrap();
        let log = std::fs::File::create(self.path("daemon.log")).unwrap();
        let daemon = watch(&self.path("ncplan.toml"), "info", log);
        assert_eq!(self.wait_rows("SELECT id FROM revisions", 3).len(), 3, "the originals were not stored");
        std::fs::copy(root.join("demo/examples/O1234_edited.nc"), self.path("share/O1234.nc")).unwrap();
        std::fs::write(self.path("share/O4321.nc"), long_program(300, true)).unwrap();
        std::fs::write(self.path(&format!("share/{HOSTILE_NAME}")), small_program(450)).unwrap();
        let compared = self.wait_rows("SELECT revision_id FROM comparisons", 3);
        assert_eq!(compared.len(), 3, "the edits were not compared: {}", std::fs::read_to_string(self.path("daemon.log")).unwrap());
        drop(daemon);
    }
}

/// Starts `ncplan serve` on a free port; returns it and its base URL.
fn serve(site: &Site, extra: &[&str]) -> (Proc, String) {
    crate::support::serve(&site.path("ncplan.toml"), extra)
}

fn have(program: &str) -> bool {
    Command::new(program).arg("--version").stdout(Stdio::null()).stderr(Stdio::null()).status().is_ok_and(|s| s.success())
}

fn screenshots() -> PathBuf {
    let d = crate::root().join("target/screenshots");
    std::fs::create_dir_all(&d).unwrap();
    d
}

#[test]
fn a_non_local_listen_without_users_is_refused() {
    let site = Site::new();
    std::fs::create_dir_all(site.path("var")).unwrap();
    ncplan::store::Store::open(&ncplan::store::Location::Sqlite(site.db()), "").unwrap();
    let out = Command::new(crate::bin())
        .current_dir(site.dir.path())
        .args(["serve", "--config"])
        .arg(site.path("ncplan.toml"))
        .args(["--listen", "0.0.0.0:0"])
        .output()
        .unwrap();
    assert_eq!(out.status.code(), Some(2));
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("refusing to listen on 0.0.0.0:0") && err.contains("[[web.user]]"), "{err}");
}

#[test]
fn sign_in_csrf_and_reports_without_a_browser() {
    let site = Site::new();
    site.build();
    // Without users: a review POST without the session's CSRF token is refused, and nothing is stored.
    let (_serve, base) = serve(&site, &[]);
    let change = crate::db_rows(&site.db(), "SELECT id FROM changes ORDER BY id LIMIT 1")[0][0].clone();
    let body = "mark=adopt&csrf=forged";
    let (head, _) = http(
        &base,
        &format!(
            "POST /review/{change} HTTP/1.1\r\nHost: {{host}}\r\nCookie: ncplan_session={}\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
            "ab".repeat(32),
            body.len()
        ),
    );
    assert!(head.starts_with("HTTP/1.1 403"), "{head}");
    assert!(crate::db_rows(&site.db(), "SELECT id FROM review_marks").is_empty());
    // A first visit gets an HttpOnly, SameSite session cookie; program text is escaped.
    let (head, page) = http(&base, "GET /search?program=O4321 HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n");
    assert!(head.to_ascii_lowercase().contains("set-cookie: ncplan_session=") && head.contains("HttpOnly; SameSite=Strict"), "{head}");
    assert!(page.contains("O4321"));
    let revision = crate::db_rows(&site.db(), "SELECT revision_id FROM shopfloor_changes WHERE program = 'O4321' LIMIT 1")[0][0].clone();
    let (_, page) = http(&base, &format!("GET /compare/{revision} HTTP/1.1\r\nHost: {{host}}\r\nConnection: close\r\n\r\n"));
    assert!(page.contains("&lt;script&gt;window.pwned=1&lt;/script&gt;"), "the comment is not shown as text");
    assert!(!page.contains("<script>window") && !page.contains("<img src=x"), "program text reached the page as markup");
    assert_eq!(page.matches("<script").count(), 1, "only the app's script");
    assert!(page.contains("(]]&gt; &lt;![CDATA[ &lt;b&gt;X&lt;/b&gt; ]]&gt;)"), "the CDATA comment is not shown as text");
    assert!(page.contains("([U+202E]DESREVER[U+202C] [U+2066]ISOLATED[U+2069])"), "the bidirectional controls are not shown");
    assert!(!page.contains('\u{202E}') && !page.contains('\u{2066}'), "a bidirectional control reached the page");
    // Every page, with the hostile program stored: markup from program text never appears.
    let program = crate::db_rows(&site.db(), &format!("SELECT program_id FROM revisions WHERE id = {revision}"))[0][0].clone();
    let mut paths: Vec<String> = [
        "/",
        "/machine/DMU50",
        "/search?program=O4321",
        "/search?to_review=1",
        "/knowledge",
        "/knowledge/feeds",
        "/knowledge/tools?sql",
        "/knowledge/start-points",
        "/knowledge/depths",
    ]
    .iter()
    .map(|p| (*p).to_owned())
    .collect();
    paths.push(format!("/program/{program}"));
    paths.push(format!("/compare/{revision}"));
    paths.push(format!("/compare/{revision}/translate/notes?to=siemens"));
    paths.push("/sql?q=SELECT%20%27%3Cscript%3Ewindow.pwned%3D4%3C%2Fscript%3E%27%20AS%20x".to_owned());
    let named = crate::db_rows(&site.db(), "SELECT revision_id FROM shopfloor_changes WHERE program = 'O7777' LIMIT 1")[0][0].clone();
    let named_program = crate::db_rows(&site.db(), &format!("SELECT program_id FROM revisions WHERE id = {named}"))[0][0].clone();
    paths.push(format!("/compare/{named}"));
    paths.push(format!("/program/{named_program}"));
    paths.push("/sql?q=SELECT%20path%20FROM%20revisions".to_owned());
    for path in &paths {
        let (head, page) = http(&base, &format!("GET {path} HTTP/1.1\r\nHost: {{host}}\r\nConnection: close\r\n\r\n"));
        assert!(head.starts_with("HTTP/1.1 200"), "{path}: {head}");
        for markup in ["<script>window", "<img src=x", "onload=\"window", "<![CDATA[", "<b>X"] {
            assert!(!page.contains(markup), "{path}: program text reached the page as markup ({markup})");
        }
        assert_eq!(page.matches("<script").count(), 1, "{path}: only the app's script");
        assert!(!page.contains('\u{202E}') && !page.contains('\u{2066}'), "{path}: a bidirectional control reached the page");
        assert!(!page.contains("<b>7"), "{path}: the file name reached the page as markup");
    }
    // The console's results are text too: hostile stored names and a query's own markup, run
    // by the console's POST.
    let session = format!("ncplan_session={}", "ef".repeat(32));
    let (_, console) = http(&base, &format!("GET /sql HTTP/1.1\r\nHost: {{host}}\r\nCookie: {session}\r\nConnection: close\r\n\r\n"));
    let token = console.split("name=\"csrf\" value=\"").nth(1).and_then(|t| t.split('"').next()).expect("a CSRF token").to_owned();
    for sql in ["SELECT '<script>window.pwned=4</script>' AS x", "SELECT path FROM programs"] {
        let body = format!("csrf={token}&q={}", crate::support::urlencode(sql));
        let (head, page) = http(
            &base,
            &format!(
                "POST /sql HTTP/1.1\r\nHost: {{host}}\r\nCookie: {session}\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
                body.len()
            ),
        );
        assert!(head.starts_with("HTTP/1.1 200") && page.contains("<p id=\"result\">"), "{sql}: {head}");
        assert!(
            !page.contains("<script>window") && !page.contains("<b>7") && page.matches("<script").count() == 1,
            "{sql}: markup in a result"
        );
        assert!(!page.contains('\u{202E}'), "{sql}: a bidirectional control reached the page");
    }
    let (_, page) = http(&base, &format!("GET /compare/{named} HTTP/1.1\r\nHost: {{host}}\r\nConnection: close\r\n\r\n"));
    assert!(
        page.contains("P&quot;&lt;b&gt;7&lt;i&gt;[U+202E]lmth.nc") || page.contains("P\"&lt;b&gt;7&lt;i&gt;[U+202E]lmth.nc"),
        "the file name is not shown as text"
    );
    // The CSV report: a header and one row per change, commas quoted.
    let csv = Command::new(crate::bin())
        .current_dir(site.dir.path())
        .args(["report", "--format", "csv", "--machine", "DMU50", "--config"])
        .arg(site.path("ncplan.toml"))
        .output()
        .unwrap();
    assert!(csv.status.success(), "{}", String::from_utf8_lossy(&csv.stderr));
    let csv = String::from_utf8(csv.stdout).unwrap();
    let n = crate::db_rows(&site.db(), "SELECT change_id FROM shopfloor_changes").len();
    assert_eq!(csv.lines().count(), n + 1, "{csv}");
    assert!(csv.starts_with("machine,program,revision_id,change_id,workingstep"));
    assert!(csv.contains("DMU50,O1234,") && csv.contains("tool T1 renamed T8"), "{csv}");
    drop(_serve);

    // With a user: pages ask to sign in; a wrong password is refused, the right one signs in.
    site.users(&[("ada", "planner-pw")]);
    let (_serve, base) = serve(&site, &[]);
    let (head, _) = http(&base, "GET / HTTP/1.1\r\nHost: {host}\r\nConnection: close\r\n\r\n");
    assert!(head.starts_with("HTTP/1.1 303") && head.to_ascii_lowercase().contains("location: /login"), "{head}");
    let login = |pw: &str| {
        let body = format!("name=ada&password={pw}");
        http(
            &base,
            &format!(
                "POST /login HTTP/1.1\r\nHost: {{host}}\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
                body.len()
            ),
        )
        .0
    };
    assert!(login("wrong").to_ascii_lowercase().contains("location: /login?failed"));
    let head = login("planner-pw");
    let cookie = head
        .lines()
        .find_map(|l| l.strip_prefix("set-cookie: ").or_else(|| l.strip_prefix("Set-Cookie: ")))
        .expect("a session cookie")
        .to_owned();
    assert!(cookie.contains("HttpOnly") && cookie.contains("SameSite=Strict"), "{cookie}");
    let token = cookie.split(';').next().unwrap();
    let (head, page) = http(&base, &format!("GET / HTTP/1.1\r\nHost: {{host}}\r\nCookie: {token}\r\nConnection: close\r\n\r\n"));
    assert!(head.starts_with("HTTP/1.1 200") && page.contains("Sign out") && page.contains("ada"), "{head}");
}

/// The cells of CSV text (RFC 4180: quoted cells, `""` a quote inside them), by row.
fn csv_cells(text: &str) -> Vec<Vec<String>> {
    let mut rows = vec![Vec::new()];
    let mut cell = String::new();
    let (mut quoted, mut chars) = (false, text.chars().peekable());
    while let Some(c) = chars.next() {
        match (quoted, c) {
            (true, '"') if chars.peek() == Some(&'"') => {
                chars.next();
                cell.push('"');
            }
            (true, '"') => quoted = false,
            (true, c) => cell.push(c),
            (false, '"') => quoted = true,
            (false, ',') => rows.last_mut().unwrap().push(std::mem::take(&mut cell)),
            (false, '\r') if chars.peek() == Some(&'\n') => {}
            (false, '\n') => {
                rows.last_mut().unwrap().push(std::mem::take(&mut cell));
                rows.push(Vec::new());
            }
            (false, c) => cell.push(c),
        }
    }
    if rows.last().is_some_and(Vec::is_empty) {
        rows.pop();
    }
    rows
}

/// Names a spreadsheet would run as formulas: the machine's (configured), a program's (its
/// file name, which has no `/`), a reviewer's (typed into the review form). In the CSV report
/// each is a text cell with a `'` before it; a program named `-12.5` stays the number it is.
#[test]
fn the_csv_report_neutralises_formulas_in_hostile_names() {
    const MACHINE: &str = "=HYPERLINK(\"http://evil.example/\",\"DMU50\")";
    const PROGRAM: &str = "@SUM(1+1)*cmd|' \\C calc'!A0";
    const REVIEWER: &str = "-2+3+cmd|' /C calc'!A0";
    let dir = tempfile::tempdir().unwrap();
    for d in ["cam", "share"] {
        std::fs::create_dir_all(dir.path().join(d)).unwrap();
    }
    let config = dir.path().join("ncplan.toml");
    std::fs::write(
        &config,
        format!(
            "[database]\npath = 'var/ncplan.db'\n[daemon]\nsettle_ms = 150\n\
             [[cam]]\npath = 'cam'\ndialect = 'fanuc'\n\
             [[machine]]\nname = '{MACHINE}'\npath = 'share'\ndialect = 'fanuc'\n"
        ),
    )
    .unwrap();
    let db = dir.path().join("var/ncplan.db");
    // Without an O number the program is named by its file.
    let unnamed = |feed: u32| crate::support::program(1, feed, 2000).replace("O1 (FACE)", "(FACE)");
    let daemon = watch(&config, "info", std::fs::File::create(dir.path().join("daemon.log")).unwrap());
    for name in [PROGRAM, "-12.5"] {
        std::fs::write(dir.path().join(format!("cam/{name}.nc")), unnamed(250)).unwrap();
    }
    assert_eq!(wait_rows(&db, "SELECT id FROM revisions", 2, Duration::from_secs(30)).len(), 2);
    for name in [PROGRAM, "-12.5"] {
        std::fs::write(dir.path().join(format!("share/{name}.nc")), unnamed(300)).unwrap();
    }
    let compared = wait_rows(&db, "SELECT revision_id FROM comparisons ORDER BY revision_id", 2, Duration::from_secs(30));
    assert_eq!(compared.len(), 2, "{}", std::fs::read_to_string(dir.path().join("daemon.log")).unwrap());
    daemon.kill();
    let hostile = PROGRAM.to_ascii_uppercase();
    let programs = crate::db_rows(&db, "SELECT DISTINCT machine, program FROM shopfloor_changes ORDER BY program");
    assert_eq!(programs, [[MACHINE, "-12.5"], [MACHINE, hostile.as_str()]]);
    // The reviewer's name comes through the review form of the real server.
    let (_serve, base) = crate::support::serve(&config, &[]);
    let cookie = format!("ncplan_session={}", "cd".repeat(32));
    let revision = &compared[0][0];
    let change = crate::db_rows(&db, &format!("SELECT id FROM changes WHERE revision_id = {revision} ORDER BY id LIMIT 1"))[0][0].clone();
    let (_, page) =
        http(&base, &format!("GET /compare/{revision} HTTP/1.1\r\nHost: {{host}}\r\nCookie: {cookie}\r\nConnection: close\r\n\r\n"));
    let csrf = page.split("name=\"csrf\" value=\"").nth(1).and_then(|r| r.split('"').next()).expect("a review form").to_owned();
    let body = format!("mark=adopt&csrf={csrf}&by={}", crate::support::urlencode(REVIEWER));
    let (head, _) = http(
        &base,
        &format!(
            "POST /review/{change} HTTP/1.1\r\nHost: {{host}}\r\nCookie: {cookie}\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: {}\r\nConnection: close\r\n\r\n{body}",
            body.len()
        ),
    );
    assert!(head.starts_with("HTTP/1.1 303"), "{head}");
    assert_eq!(crate::db_rows(&db, "SELECT marked_by FROM review_marks"), [[REVIEWER]]);
    let out = Command::new(crate::bin())
        .current_dir(crate::support::config_dir(&config))
        .args(["report", "--format", "csv", "--config"])
        .arg(&config)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let csv = String::from_utf8(out.stdout).unwrap();
    let rows = csv_cells(&csv);
    let n = crate::db_rows(&db, "SELECT change_id FROM shopfloor_changes").len();
    assert_eq!(rows.len(), n + 1, "{csv}");
    let column = |name: &str| rows[0].iter().position(|c| c == name).unwrap_or_else(|| panic!("no column {name}"));
    let (machine, program, reviewer) = (column("machine"), column("program"), column("reviewed_by"));
    // Every cell a spreadsheet would read as a formula is text now; the numbers are numbers.
    for row in &rows[1..] {
        assert_eq!(row.len(), rows[0].len(), "{row:?}");
        for cell in row {
            assert!(
                !cell.starts_with(['=', '+', '-', '@', '\t', '\r']) || cell.parse::<f64>().is_ok(),
                "a cell a spreadsheet would run: {cell:?}\n{csv}"
            );
        }
        assert_eq!(row[machine], format!("'{MACHINE}"));
        assert!(row[program] == format!("'{hostile}") || row[program] == "-12.5", "{row:?}");
    }
    let reviewed: Vec<&str> = rows[1..].iter().map(|r| r[reviewer].as_str()).filter(|r| !r.is_empty()).collect();
    assert_eq!(reviewed, [format!("'{REVIEWER}")]);
    // As written: quoted, with the quote doubled inside; the number bare.
    assert!(csv.contains(&format!("\"'{}\"", MACHINE.replace('"', "\"\""))), "{csv}");
    assert!(csv.contains(",-12.5,"), "{csv}");
}

/// The header `name` of a response head (lower-case name), if present.
fn header<'a>(head: &'a str, name: &str) -> Option<&'a str> {
    head.lines().find_map(|l| l.split_once(':').filter(|(k, _)| k.trim().eq_ignore_ascii_case(name)).map(|(_, v)| v.trim()))
}

#[test]
fn the_translate_download_reads_back_in_its_dialect() {
    let site = Site::new();
    site.build();
    let (_serve, base) = serve(&site, &[]);
    let revision = crate::db_rows(&site.db(), "SELECT revision_id FROM shopfloor_changes WHERE program = 'O1234' LIMIT 1")[0][0].clone();
    // The comparison page offers it, the CAM original's dialect chosen.
    let (_, page) = http(&base, &format!("GET /compare/{revision} HTTP/1.1\r\nHost: {{host}}\r\nConnection: close\r\n\r\n"));
    assert!(page.contains(&format!("action=\"/compare/{revision}/translate\"")), "no translate form");
    assert!(
        page.contains("<option value=\"fanuc\" selected>fanuc (the CAM original's)</option>"),
        "the original's dialect is not the default"
    );
    let get = |query: &str| {
        http(&base, &format!("GET /compare/{revision}/translate{query} HTTP/1.1\r\nHost: {{host}}\r\nConnection: close\r\n\r\n"))
    };
    // Safe output: the edit cuts with T8 on H1's length, which Siemens and Heidenhain cannot
    // state (they apply the tool's own): the download is refused (422, the notes say why) and
    // `ncplan translate` writes nothing, as the download once gave out the text regardless.
    for dialect in ["siemens", "heidenhain"] {
        let (head, body) = get(&format!("?to={dialect}"));
        assert!(head.starts_with("HTTP/1.1 422"), "{dialect}: {head}");
        assert!(body.contains("refused") && body.contains("the length offset H1 while tool T8 is in the spindle"), "{dialect}: {body}");
        let cli = Command::new(crate::bin())
            .current_dir(site.dir.path())
            .args(["translate", "--revision", &revision, "--to", dialect, "--config"])
            .arg(site.path("ncplan.toml"))
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&cli.stderr);
        assert!(!cli.status.success() && err.contains("the length offset H1 while tool T8 is in the spindle"), "{dialect}: {err}");
        assert!(cli.stdout.is_empty(), "{dialect}: a refused translation was written");
    }
    {
        let (query, dialect, ext) = ("", "fanuc", "nc");
        let (head, body) = get(query);
        assert!(head.starts_with("HTTP/1.1 200"), "{query}: {head}");
        let filename = format!("O1234-r{revision}-{dialect}.{ext}");
        assert_eq!(header(&head, "content-disposition"), Some(format!("attachment; filename=\"{filename}\"").as_str()), "{head}");
        assert_eq!(header(&head, "x-content-type-options"), Some("nosniff"));
        // Deterministic: the same bytes again, and the same as `ncplan translate` writes.
        assert!(body.lines().count() > 10, "{query}: {body}");
        assert_eq!(get(query).1, body, "{query}: a second download differs");
        let cli = Command::new(crate::bin())
            .current_dir(site.dir.path())
            .args(["translate", "--revision", &revision, "--to", dialect, "--config"])
            .arg(site.path("ncplan.toml"))
            .output()
            .unwrap();
        // The edit cuts with T8 on H1's length: Siemens and Heidenhain apply the tool's own,
        // which the translation says (the text is still written).
        if dialect == "fanuc" {
            assert!(cli.status.success(), "{}", String::from_utf8_lossy(&cli.stderr));
        } else {
            let err = String::from_utf8_lossy(&cli.stderr);
            assert!(!cli.status.success() && err.contains("the length offset H1 while tool T8 is in the spindle"), "{dialect}: {err}");
        }
        assert_eq!(body.as_bytes(), cli.stdout.as_slice(), "{dialect}: the download is not what ncplan translate writes");
        // It reads back in the target dialect without errors.
        let file = site.path(&filename);
        std::fs::write(&file, &body).unwrap();
        let check = Command::new(crate::bin()).arg("check").arg(&file).args(["--dialect", dialect]).output().unwrap();
        assert!(check.status.success(), "{dialect}: {}\n{body}", String::from_utf8_lossy(&check.stdout));
        assert!(!String::from_utf8_lossy(&check.stdout).contains("error["), "{dialect}: {}", String::from_utf8_lossy(&check.stdout));
    }
    // The notes page says what was written and links the download.
    let (head, notes) =
        http(&base, &format!("GET /compare/{revision}/translate/notes?to=siemens HTTP/1.1\r\nHost: {{host}}\r\nConnection: close\r\n\r\n"));
    assert!(head.starts_with("HTTP/1.1 200"), "{head}");
    assert!(notes.contains("Read as fanuc, written as siemens") && notes.contains(&format!("O1234-r{revision}-siemens.mpf")), "{notes}");
    // An unknown dialect, or one without output rules, is a 404 that names those it can write.
    for to in ["nonesuch", "cldata"] {
        let (head, body) = get(&format!("?to={to}"));
        assert!(head.starts_with("HTTP/1.1 404") && body.contains("it writes") && body.contains("siemens"), "{to}: {head}\n{body}");
    }
}

/// chromedriver on a free port, in a process group of its own (the browser it starts goes
/// with it even when an assertion ends the test before the session is closed); `None` after
/// saying why `test` is skipped when chromium or chromedriver is not installed.
pub(crate) fn chromedriver(test: &str) -> Option<(Group, u16)> {
    if !(have("chromium") && have("chromedriver")) {
        assert!(
            std::env::var_os("NCPLAN_REQUIRE_CHROMIUM").is_none(),
            "NCPLAN_REQUIRE_CHROMIUM is set but chromium or chromedriver is missing (apt-get install chromium chromium-driver)"
        );
        crate::skip(test, "chromium or chromedriver is not installed (apt-get install chromium chromium-driver)");
        return None;
    }
    let port = free_port();
    let driver = Group(Proc({
        use std::os::unix::process::CommandExt as _;
        Command::new("chromedriver")
            .arg(format!("--port={port}"))
            .process_group(0)
            .stdout(Stdio::null())
            .stderr(Stdio::null())
            .spawn()
            .unwrap()
    }));
    let deadline = Instant::now() + Duration::from_secs(20);
    while TcpStream::connect(("127.0.0.1", port)).is_err() {
        assert!(Instant::now() < deadline, "chromedriver did not start");
        std::thread::sleep(Duration::from_millis(50));
    }
    Some((driver, port))
}

/// A headless chromium session through the chromedriver on `port`.
pub(crate) async fn browser(port: u16) -> Client {
    browser_with(port, &[]).await
}

/// A headless chromium session with the further command-line `args`.
async fn browser_with(port: u16, args: &[&str]) -> Client {
    let mut caps = serde_json::Map::new();
    let mut all = vec!["--headless=new", "--no-sandbox", "--disable-gpu", "--disable-dev-shm-usage", "--window-size=1400,1100"];
    all.extend(args);
    caps.insert("goog:chromeOptions".into(), json!({ "args": all }));
    ClientBuilder::new(hyper_util::client::legacy::connect::HttpConnector::new())
        .capabilities(caps)
        .connect(&format!("http://127.0.0.1:{port}"))
        .await
        .expect("connect to chromedriver")
}

#[test]
fn the_workspace_in_chromium() {
    let Some((_driver, port)) = chromedriver("web::the_workspace_in_chromium") else { return };
    let site = Site::new();
    site.build();
    let (_serve, base) = serve(&site, &[]);
    // The HTML report, for the browser to open.
    let report = screenshots().join("report.html");
    let out = Command::new(crate::bin())
        .current_dir(site.dir.path())
        .args(["report", "--format", "html", "-o"])
        .arg(&report)
        .arg("--config")
        .arg(site.path("ncplan.toml"))
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    rt.block_on(async {
        let c = browser(port).await;
        let result = walk(&c, &base, &site, &report).await;
        let _ = c.close().await;
        result.unwrap();
    });
}

/// A planner signed in with the browser stays signed in when `ncplan serve` is killed and
/// started again: the session is in the store (by its token's hash), and the review form of a
/// page loaded before the restart still records a mark. It ends at its expiry, at sign-out,
/// and when its planner is no longer configured.
#[test]
fn a_signed_in_planner_stays_signed_in_across_a_restart_of_the_server() {
    let test = "web::a_signed_in_planner_stays_signed_in_across_a_restart_of_the_server";
    let Some((_driver, port)) = chromedriver(test) else { return };
    let site = Site::new();
    site.build();
    site.users(&[("ada", "planner-pw")]);
    let listen = format!("127.0.0.1:{}", free_port());
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    rt.block_on(async {
        let c = browser(port).await;
        let result = restarts(&c, &site, &listen).await;
        let _ = c.close().await;
        result.unwrap();
    });
}

/// DNS rebinding: a page of another name (`rebind.example`, resolved by chromium to
/// 127.0.0.1 as a rebinding DNS server would) that loads this server and has its script post
/// to it, the same origin for the browser. Every route answers 421 and nothing is recorded.
#[test]
fn a_page_of_another_name_that_resolves_here_reads_and_posts_nothing() {
    let Some((_driver, port)) = chromedriver("web::a_page_of_another_name_that_resolves_here_reads_and_posts_nothing") else { return };
    let site = Site::new();
    site.build();
    let (_serve, base) = serve(&site, &[]);
    let server_port = base.rsplit(':').next().unwrap().to_owned();
    let change = crate::db_rows(&site.db(), "SELECT id FROM changes ORDER BY id LIMIT 1")[0][0].clone();
    let rt = tokio::runtime::Builder::new_current_thread().enable_all().build().unwrap();
    rt.block_on(async {
        let c = browser_with(port, &["--host-resolver-rules=MAP rebind.example 127.0.0.1"]).await;
        let result = async {
            let evil = format!("http://rebind.example:{server_port}");
            c.goto(&format!("{evil}/")).await?;
            let body = text_of(&c, "body").await;
            assert!(body.contains("does not answer for the host name `rebind.example:"), "{body}");
            shot(&c, "rebinding-refused").await?;
            // The rebinding page's script: read the console, post a mark and a query.
            let script = format!(
                "var done = arguments[0];
                 var form = 'mark=adopt&by=mallory&csrf=x';
                 Promise.all([
                   fetch('/sql?q=SELECT%201').then(r => r.status),
                   fetch('/review/{change}', {{ method: 'POST', headers: {{ 'Content-Type': 'application/x-www-form-urlencoded' }}, body: form }}).then(r => r.status),
                   fetch('/sql', {{ method: 'POST', headers: {{ 'Content-Type': 'application/x-www-form-urlencoded' }}, body: 'q=SELECT%201' }}).then(r => r.status),
                   fetch('/compare/1').then(r => r.status),
                 ]).then(done, e => done(String(e)));"
            );
            let statuses = c.execute_async(&script, vec![]).await?;
            assert_eq!(statuses, json!([421, 421, 421, 421]));
            // This server's own address still serves the same browser.
            c.goto(&format!("{base}/")).await?;
            assert!(text_of(&c, "h1").await.len() > 1);
            Ok::<_, fantoccini::error::CmdError>(())
        }
        .await;
        let _ = c.close().await;
        result.unwrap();
    });
    assert!(crate::db_rows(&site.db(), "SELECT id FROM review_marks").is_empty(), "the rebinding page recorded a mark");
}

/// Signs in as `name` on the sign-in page, as a planner does.
async fn sign_in(c: &Client, base: &str, name: &str, password: &str) -> Result<(), fantoccini::error::CmdError> {
    c.goto(&format!("{base}/login")).await?;
    c.find(Locator::Css("input[name=name]")).await?.send_keys(name).await?;
    c.find(Locator::Css("input[name=password]")).await?.send_keys(password).await?;
    c.find(Locator::Css("form[action=\"/login\"] button")).await?.click().await?;
    let who = wait_text(c, "header.top form span", name).await;
    assert_eq!(who.trim(), name);
    Ok(())
}

async fn restarts(c: &Client, site: &Site, listen: &str) -> Result<(), fantoccini::error::CmdError> {
    let db = site.db();
    let (server, base) = serve(site, &["--listen", listen]);
    let sessions = || crate::db_rows(&db, "SELECT token_hash, user_name, created_at, expires_at FROM web_sessions");
    c.goto(&format!("{base}/")).await?;
    assert_eq!(text_of(c, "h1").await, "Sign in");
    sign_in(c, &base, "ada", "planner-pw").await?;
    // The store holds the token's SHA-256, never the cookie itself.
    let token = c.get_named_cookie("ncplan_session").await?.value().to_owned();
    let stored = sessions();
    assert_eq!(stored.len(), 1, "{stored:?}");
    assert_eq!(stored[0][0], ncplan::daemon::ingest::sha256_hex(token.as_bytes()));
    assert_ne!(stored[0][0], token);
    assert_eq!(stored[0][1], "ada");
    assert!(stored[0][3] > stored[0][2], "{stored:?}");
    let demo_rev = crate::db_rows(&db, "SELECT revision_id FROM shopfloor_changes WHERE program = 'O1234' LIMIT 1")[0][0].clone();
    c.goto(&format!("{base}/compare/{demo_rev}")).await?;
    assert!(text_of(c, "section.card").await.contains("tool T1 renamed T8"));

    // The server is killed and started again on the same address.
    server.kill();
    let (server, again) = serve(site, &["--listen", listen]);
    assert_eq!(again, base);
    // The review form of the page loaded before the restart records the mark as ada's.
    c.find(Locator::Css("li[data-kind=tool_renamed] button[data-mark=adopt]")).await?.click().await?;
    let li = wait_text(c, "li[data-kind=tool_renamed]", "adopt by ada").await;
    assert!(li.contains("adopt by ada"), "{li}");
    assert_eq!(crate::db_rows(&db, "SELECT mark, marked_by, kind FROM review_marks"), [["adopt", "ada", "tool_renamed"]]);
    // Every page still knows ada.
    c.goto(&format!("{base}/")).await?;
    assert_ne!(text_of(c, "h1").await, "Sign in");
    assert_eq!(text_of(c, "header.top form span").await.trim(), "ada");

    // At its expiry the session ends: sign in again.
    let conn = rusqlite::Connection::open(&db).unwrap();
    conn.execute("UPDATE web_sessions SET expires_at = '2000-01-01T00:00:00.000Z'", []).unwrap();
    c.goto(&format!("{base}/")).await?;
    assert_eq!(text_of(c, "h1").await, "Sign in");
    sign_in(c, &base, "ada", "planner-pw").await?;
    // The sign-in forgot the session that had ended.
    assert_eq!(sessions().iter().map(|r| r[1].as_str()).collect::<Vec<_>>(), ["ada"]);
    // Signing out ends it; its cookie no longer opens a page.
    let token = c.get_named_cookie("ncplan_session").await?.value().to_owned();
    c.find(Locator::Css("form[action=\"/logout\"] button")).await?.click().await?;
    assert_eq!(wait_text(c, "h1", "Sign in").await, "Sign in");
    assert!(sessions().is_empty(), "{:?}", sessions());
    let (head, _) =
        http(&base, &format!("GET / HTTP/1.1\r\nHost: {{host}}\r\nCookie: ncplan_session={token}\r\nConnection: close\r\n\r\n"));
    assert!(head.starts_with("HTTP/1.1 303") && head.to_ascii_lowercase().contains("location: /login"), "{head}");

    // A planner no longer configured is signed out by the restart that drops them.
    sign_in(c, &base, "ada", "planner-pw").await?;
    server.kill();
    site.users(&[("bob", "other-pw")]);
    let (_server, _) = serve(site, &["--listen", listen]);
    c.goto(&format!("{base}/")).await?;
    assert_eq!(text_of(c, "h1").await, "Sign in");
    assert_eq!(sessions().len(), 1, "the row stays until it expires or a sign-in forgets it");
    Ok(())
}

pub(crate) async fn shot(c: &Client, name: &str) -> Result<(), fantoccini::error::CmdError> {
    let png = c.screenshot().await?;
    std::fs::write(screenshots().join(format!("{name}.png")), png).unwrap();
    Ok(())
}

/// The text of the first element `css` selects, waiting (up to 10 s) for a page that is
/// still loading after a form's POST and redirect.
pub(crate) async fn text_of(c: &Client, css: &str) -> String {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        if let Ok(e) = c.find(Locator::Css(css)).await
            && let Ok(t) = e.text().await
        {
            return t;
        }
        assert!(Instant::now() < deadline, "no element {css}");
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

/// Waits (up to 10 s) until the element `css` holds `want`; returns its text.
pub(crate) async fn wait_text(c: &Client, css: &str, want: &str) -> String {
    let deadline = Instant::now() + Duration::from_secs(10);
    loop {
        let t = text_of(c, css).await;
        if t.contains(want) || Instant::now() > deadline {
            return t;
        }
        tokio::time::sleep(Duration::from_millis(50)).await;
    }
}

async fn js(c: &Client, script: &str) -> serde_json::Value {
    c.execute(script, vec![]).await.unwrap()
}

async fn walk(c: &Client, base: &str, site: &Site, report: &Path) -> Result<(), fantoccini::error::CmdError> {
    let db = site.db();
    let demo_rev = crate::db_rows(&db, "SELECT revision_id FROM shopfloor_changes WHERE program = 'O1234' LIMIT 1")[0][0].clone();
    let long_rev = crate::db_rows(&db, "SELECT revision_id FROM shopfloor_changes WHERE program = 'O4321' LIMIT 1")[0][0].clone();
    let program_id = crate::db_rows(&db, &format!("SELECT program_id FROM revisions WHERE id = {demo_rev}"))[0][0].clone();
    let total: usize = crate::db_rows(&db, "SELECT change_id FROM shopfloor_changes").len();

    // The overview: the queue holds every change.
    c.goto(&format!("{base}/")).await?;
    let queue = |v: serde_json::Value| v.as_str().unwrap_or("").trim().parse::<usize>().unwrap_or(usize::MAX);
    let before = queue(js(c, "return document.querySelector('[data-queue=\"DMU50\"]').textContent").await);
    assert_eq!(before, total);
    assert!(text_of(c, "#health").await.contains("readable"));
    assert!(c.find(Locator::Css("svg.chart rect.bar")).await.is_ok(), "the weekly chart has bars");
    shot(c, "overview").await?;

    // Every other page renders, with its own heading.
    for (path, heading) in [
        ("/machine/DMU50".to_owned(), "Machine DMU50"),
        (format!("/program/{program_id}"), "Program O1234"),
        ("/search?program=1234&machine=DMU50&kind=tool_renamed".to_owned(), "Search"),
        ("/search?to_review=1".to_owned(), "Review queue"),
        ("/knowledge".to_owned(), "Knowledge"),
        ("/knowledge/feeds".to_owned(), "Feeds and speeds"),
        ("/knowledge/tools?sql".to_owned(), "Tool substitutions"),
        ("/knowledge/start-points".to_owned(), "Start points"),
        ("/knowledge/depths".to_owned(), "Depth changes"),
        ("/sql?q=SELECT%20kind%2C%20COUNT(*)%20FROM%20shopfloor_changes%20GROUP%20BY%201".to_owned(), "SQL console"),
    ] {
        c.goto(&format!("{base}{path}")).await?;
        let h1 = text_of(c, "h1").await;
        assert!(h1.starts_with(heading), "{path}: {h1}");
        let name: String = path.trim_start_matches('/').split(['?', '/']).take(2).collect::<Vec<_>>().join("-");
        let name: String = name.chars().map(|ch| if ch.is_ascii_alphanumeric() || ch == '-' { ch } else { '_' }).take(40).collect();
        shot(c, &name).await?;
    }
    c.goto(&format!("{base}/knowledge/tools?sql")).await?;
    assert!(text_of(c, "pre.sql").await.contains("tool_renamed"));
    assert!(text_of(c, "table").await.contains("T8"), "the substitution T1 → T8 is counted");
    c.goto(&format!("{base}/search?program=1234&machine=DMU50&kind=tool_renamed")).await?;
    assert!(text_of(c, "#result-count").await.starts_with("1 changes"));
    // The console: a link fills its form and runs nothing; its Run button POSTs the query.
    c.goto(&format!("{base}/sql?q=SELECT%20kind%2C%20COUNT(*)%20FROM%20shopfloor_changes%20GROUP%20BY%201")).await?;
    assert!(c.find(Locator::Css("#result")).await.is_err(), "a GET ran the query");
    c.find(Locator::Css("form[action=\"/sql\"] button")).await?.click().await?;
    let result = wait_text(c, "#result", "rows").await;
    assert!(result.contains("rows"), "{result}");
    assert!(text_of(c, "table").await.contains("tool_renamed"));
    shot(c, "sql-run").await?;
    c.goto(&format!("{base}/sql?q=DELETE%20FROM%20revisions")).await?;
    c.find(Locator::Css("form[action=\"/sql\"] button")).await?.click().await?;
    assert!(wait_text(c, "p.error", "refused").await.contains("refused"));

    // The demo's comparison: the face milling workingstep, T1 → T8, the moved start point boxed.
    c.set_window_size(1400, 2000).await?;
    c.goto(&format!("{base}/compare/{demo_rev}")).await?;
    let sentences = text_of(c, "section.card").await;
    assert!(sentences.contains("Workingstep 1 (plane finish milling)"), "{sentences}");
    assert!(sentences.contains("tool T1 renamed T8") && sentences.contains("start point moved from X90 Y20 to X83 Y20"), "{sentences}");
    for view in ["top", "front", "side"] {
        let n = |sel: String| async move { js(c, &format!("return document.querySelectorAll('{sel}').length")).await.as_u64().unwrap() };
        assert!(n(format!("svg[data-view={view}] path.o.feed")).await > 0, "{view}: the original's toolpath");
        assert!(n(format!("svg[data-view={view}] path.e.feed")).await > 0, "{view}: the edited toolpath");
        assert!(n(format!("svg[data-view={view}] path.rapid")).await > 0, "{view}: rapids");
        assert_eq!(n(format!("svg[data-view={view}] circle.start")).await, 2, "{view}: both start points");
        assert_eq!(n(format!("svg[data-view={view}] rect.region")).await, 1, "{view}: the moved start point's region");
    }
    shot(c, "comparison").await?;
    // The legend's swatches come from the stylesheet (no inline style under the policy).
    assert_eq!(js(c, "return getComputedStyle(document.querySelector('.legend i.lg-rapid')).borderTopStyle").await, json!("dashed"));
    let moved = c.find(Locator::Css("li[data-kind=start_point_moved] a.change")).await?;
    moved.click().await?;
    assert_eq!(js(c, "return document.querySelectorAll('svg rect.region.active').length").await, json!(3), "the region is highlighted");
    assert_eq!(js(c, "return document.querySelectorAll('.src .ln.hl').length > 0").await, json!(true));
    // Cosmetic differences (block numbers, spelling) are greyed.
    assert!(js(c, "return document.querySelectorAll('#src-e .ln.cos').length").await.as_u64().unwrap() >= 5);
    shot(c, "comparison-clicked").await?;
    // A layer switched off hides its paths.
    c.find(Locator::Css("input[data-layer=o1]")).await?.click().await?;
    assert_eq!(js(c, "return getComputedStyle(document.querySelector('g.layer[data-layer=o1]')).display").await, json!("none"));

    // Adopt a change: its mark is shown and the queue shrinks by one.
    c.find(Locator::Css("li[data-kind=tool_renamed] button[data-mark=adopt]")).await?.click().await?;
    let li = wait_text(c, "li[data-kind=tool_renamed]", "adopt by planner").await;
    assert!(li.contains("adopt by planner"), "{li}");
    c.goto(&format!("{base}/")).await?;
    let after = queue(js(c, "return document.querySelector('[data-queue=\"DMU50\"]').textContent").await);
    assert_eq!(after, before - 1, "the queue shrinks");
    let marks = crate::db_rows(&db, "SELECT mark, marked_by, kind FROM review_marks");
    assert_eq!(marks, vec![vec!["adopt".to_owned(), "planner".to_owned(), "tool_renamed".to_owned()]]);

    // The long program: a click on its change scrolls both sources to it; its hostile
    // comments are text.
    c.set_window_size(1400, 1600).await?;
    c.goto(&format!("{base}/compare/{long_rev}")).await?;
    assert_eq!(js(c, "return window.pwned === undefined").await, json!(true), "script in a comment ran");
    assert_eq!(js(c, "return document.querySelectorAll('[onload], [onerror], main script').length").await, json!(0));
    let text = text_of(c, "#src-e").await;
    assert!(text.contains("(<script>window.pwned=1</script>)") && text.contains("(\" onload=\"window.pwned=2)"), "{text}");
    let scroll = "return [document.getElementById('src-o').scrollTop, document.getElementById('src-e').scrollTop]";
    assert_eq!(js(c, scroll).await, json!([0, 0]));
    let feed = c.find(Locator::Css("li[data-kind=feed_changed] a.change")).await?;
    let (line, oline) = (feed.attr("data-line").await?.unwrap(), feed.attr("data-oline").await?.unwrap());
    feed.click().await?;
    let tops = js(c, scroll).await;
    assert!(tops[0].as_f64().unwrap() > 100.0 && tops[1].as_f64().unwrap() > 100.0, "both sources scroll: {tops}");
    // Each change line is in view in its pane.
    for (pane, id) in [("src-o", format!("o-{oline}")), ("src-e", format!("e-{line}"))] {
        let visible = js(
            c,
            &format!(
                "var p = document.getElementById('{pane}'), l = document.getElementById('{id}');
                 var a = p.getBoundingClientRect(), b = l.getBoundingClientRect();
                 return b.top >= a.top && b.bottom <= a.bottom && l.classList.contains('hl');"
            ),
        )
        .await;
        assert_eq!(visible, json!(true), "{id} is in view and highlighted in {pane}");
    }
    shot(c, "comparison-scrolled").await?;

    // The shortened pass is a toolpath change: boxed in every view, its moves drawn exactly.
    let tp = c.find(Locator::Css("li[data-kind=toolpath_changed] a.change")).await?;
    let change = tp.attr("data-change").await?.unwrap();
    let count = |sel: String| async move { js(c, &format!("return document.querySelectorAll('{sel}').length")).await.as_u64().unwrap() };
    for view in ["top", "front", "side"] {
        assert_eq!(count(format!("svg[data-view={view}] rect#region-{view}-{change}")).await, 1, "{view}: the change's box");
        assert!(count(format!("svg[data-view={view}] path.e.chg")).await > 0, "{view}: the edited changed moves");
        assert!(count(format!("svg[data-view={view}] path.o.chg")).await > 0, "{view}: the original's changed moves");
        assert_eq!(count(format!("svg[data-view={view}] text.note")).await, 0, "{view}: every changed move is exact");
    }
    // The region is X-10…110 Y40…42; the edited pass ends at X95 (Y40, then Y42), the
    // original's at X110: each of those points is in its changed path, to a tenth of a pixel.
    let drawn = |side: &str, x: f64, y: f64| {
        format!(
            "var r = document.getElementById('region-top-{change}');
             var x0 = r.x.baseVal.value + 3, y0 = r.y.baseVal.value + 3, s = (r.width.baseVal.value - 6) / 120;
             var want = [x0 + ({x} + 10) * s, y0 + (42 - {y}) * s];
             var n = document.querySelector('svg[data-view=top] path.{side}.chg').getAttribute('d').replace(/[MLh]/g, ' ').trim().split(/\\s+/).map(Number);
             for (var i = 0; i + 1 < n.length; i += 2) {{ if (Math.abs(n[i] - want[0]) < 0.2 && Math.abs(n[i + 1] - want[1]) < 0.2) return true; }}
             return [want, n.slice(0, 40)];"
        )
    };
    for (side, x, y) in [("e", 95.0, 40.0), ("e", 95.0, 42.0), ("o", 110.0, 40.0), ("o", 110.0, 42.0)] {
        assert_eq!(js(c, &drawn(side, x, y)).await, json!(true), "{side}: X{x} Y{y} is not in the changed path");
    }
    tp.click().await?;
    assert_eq!(
        js(c, &format!("return document.querySelectorAll('svg rect.region.active[data-change=\"{change}\"]').length")).await,
        json!(3)
    );
    shot(c, "comparison-toolpath-change").await?;

    // The translate form: the CAM original's dialect by default; its notes page links the download.
    assert_eq!(js(c, "return document.querySelector('#translate select').value").await, json!("fanuc"));
    c.find(Locator::Css("#translate button[data-translate=notes]")).await?.click().await?;
    let h1 = wait_text(c, "h1", "Translation of revision").await;
    assert!(h1.starts_with(&format!("Translation of revision {long_rev} into fanuc")), "{h1}");
    let href = c.find(Locator::Css("#download")).await?.attr("href").await?.unwrap();
    assert_eq!(href, format!("/compare/{long_rev}/translate?to=fanuc"));
    assert_eq!(js(c, "return window.pwned === undefined").await, json!(true), "script in a comment ran");
    shot(c, "translate-notes").await?;

    // The HTML report: self-contained (no links to fetch), opened from a file.
    let html = std::fs::read_to_string(report).unwrap();
    assert!(!html.contains("<link") && !html.contains("<script") && !html.contains("src=\"http") && !html.contains("href=\"http"));
    assert!(html.contains("<style>") && html.contains("<svg"));
    assert!(html.contains("tool T1 renamed T8") && html.contains("&lt;script&gt;window.pwned=1"));
    assert!(
        !html.contains('\u{202E}') && html.contains("[U+202E]DESREVER") && html.contains("]]&gt; &lt;![CDATA["),
        "hostile text in the report"
    );
    c.goto(&format!("file://{}", report.display())).await?;
    assert!(text_of(c, "h1").await.contains("Shopfloor changes"));
    assert_eq!(js(c, "return document.querySelectorAll('svg.toolpath').length").await, json!(9), "three revisions, three views each");
    shot(c, "report").await?;
    Ok(())
}

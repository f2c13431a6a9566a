//! `ncplan serve`: the planners' workspace, a web application over the store.
//!
//! Its own room in the IO shell: axum on a current-thread tokio runtime, pages rendered by
//! maud (compile-time checked, every interpolated value escaped: program text is untrusted),
//! assets embedded. It reads through `store` on read-only connections, writes only review
//! marks, saved console queries and sign-in sessions (their own tables), and calls the pure core (`view`) for pictures and source views.
//! The door is [`serve`]; [`report`] writes the same comparison views as one HTML file.
//!
//! Security: without `[[web.user]]` in the configuration the server listens on loopback only
//! (a non-local address is refused); with users, every page asks for a session (argon2
//! password check, an HttpOnly SameSite=Strict cookie, `Secure` over TLS, the session kept in
//! the store with its expiry, so that a restart signs no one out). Every POST carries a CSRF
//! token derived from the session cookie; the SQL console runs a query only by such a POST
//! (`GET /sql?q=` fills its form), [`CONSOLE_AT_ONCE`] at a time. Sign-in: `[web]
//! login_per_minute` attempts per client, [`HASHING_AT_ONCE`] password checks at once on
//! threads of their own (`auth::Checkers`), an unknown name checked against a dummy hash.
//! `guard.rs`: connections (header timeout, cap), the `Host` check, body bounds and the
//! security headers of every response.
//!
//! `ncplan serve`, its own room in the shell (axum on a current-thread tokio
//! runtime; maud templates, compile-time checked and escaping every value; CSS and JS embedded
//! from `assets/`). `mod.rs` is the door (`serve`, `listen_address`: a non-loopback address
//! without `[[web.user]]` is refused), the router, the plan cache and `page` (each page
//! rendered on the blocking pool with a read-only connection, a few idle ones kept for the next page, security headers). `auth.rs`:
//! session cookies (HttpOnly, SameSite=Strict; a signed-in session is the store's, looked up on
//! the blocking pool, 12 hours, and only while its user is configured, so a restart signs no
//! one out; through a role that only reads, the process keeps it in `Server::unstored`), argon2 password checks, CSRF tokens (SHA-256 of the session token and, for
//! anonymous sessions, a per-process secret). `layout.rs`: the page frame (navigation,
//! stylesheet, script) every page uses, below `pages.rs` and `compare.rs`. `pages.rs`: overview, machine, program, search and
//! review queue, knowledge, SQL console, sign-in. `compare.rs`: the comparison view (sentences
//! by workingstep with review forms, pictures from `view::picture`, sources from
//! `view::source`, findings with carets), shared with `report.rs` (`report --format html`:
//! one self-contained file; `csv`: the change rows, a text cell a spreadsheet would run as a
//! formula written with a `'` before it). `compare::load` reads both programs
//! from the store, then rebuilds their plans on two threads (`PlanSource`: the server's plan
//! cache, or none for the report), each program's bytes decoded once for its plan and its
//! source view. The comparison page's translate form: `/compare/{id}/translate?to=D`
//! answers the as-run program written by `post::translate` (as `ncplan translate --revision
//! ID --to D` writes it; by default in the CAM original's dialect) as an attachment named
//! `{program}-r{id}-{dialect}.{extension}`, and `/translate/notes` shows what the reader and
//! the writer said. `bench.rs`: `ncplan bench --web`.

mod auth;
pub mod bench;
mod compare;
mod guard;
mod layout;
mod pages;
pub mod report;
pub mod suggest;

use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::sync::{Arc, Mutex};

use anyhow::{Context, Result};
use axum::Router;
use axum::extract::{Extension, Form, Path, Query, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::response::{Html, IntoResponse, Redirect, Response};
use axum::routing::{get, post};
use maud::Markup;

use crate::config::Config;
use crate::daemon::Clock;
use crate::dialect::Registry;
use crate::plan::ProcessPlan;
use crate::store::Store;

/// The default address: loopback only.
pub const DEFAULT_LISTEN: &str = "127.0.0.1:8480";

/// The stylesheet, embedded (and inlined into HTML reports).
pub const CSS: &str = include_str!("assets/app.css");
/// The script: pan and zoom, scroll sync, review buttons.
pub const JS: &str = include_str!("assets/app.js");

/// What `ncplan serve` needs.
pub struct Options {
    /// The configuration (database, folders, users).
    pub config: Config,
    /// The dialects, to rebuild plans from stored bytes.
    pub registry: Registry,
    /// `--listen`, else the configuration's, else [`DEFAULT_LISTEN`].
    pub listen: Option<String>,
    /// The clock review marks are dated by.
    pub clock: Arc<dyn Clock>,
}

/// The address to listen on, refused when it is not loopback and no user is configured.
pub fn listen_address(given: Option<&str>, config: &Config) -> Result<SocketAddr> {
    let text = given.or(config.web_listen.as_deref()).unwrap_or(DEFAULT_LISTEN);
    let addr: SocketAddr = text.parse().with_context(|| format!("`{text}` is not an address such as 127.0.0.1:8480"))?;
    if !addr.ip().is_loopback() && config.web_users.is_empty() {
        anyhow::bail!(
            "refusing to listen on {addr}: it is reachable from other machines and no users are configured; \
             add [[web.user]] entries (name, password_hash: an argon2 PHC string) to the configuration, or listen on 127.0.0.1"
        );
    }
    for u in &config.web_users {
        argon2::PasswordHash::new(&u.password_hash)
            .map_err(|e| anyhow::anyhow!("[[web.user]] {}: password_hash is not an argon2 PHC string ({e})", u.name))?;
    }
    Ok(addr)
}

/// Whole plans rebuilt from stored bytes, the last few kept: a comparison page asked again
/// does not read its programs again.
struct PlanCache {
    kept: Vec<(i64, Arc<ProcessPlan>)>,
}

const PLANS_KEPT: usize = 4;

/// Comparisons whose plans are rebuilt at start.
const WARM_COMPARISONS: usize = 2;

/// The server's state.
pub(crate) struct Server {
    db: crate::store::Location,
    config: Config,
    registry: Registry,
    clock: Arc<dyn Clock>,
    /// The CSRF tokens' secret where no one signs in (anonymous sessions).
    secret: [u8; 32],
    /// Sessions the store would not keep (a database role that only reads): token hash →
    /// (user, expiry). They end with the process.
    unstored: Mutex<BTreeMap<String, (String, String)>>,
    plans: Mutex<PlanCache>,
    /// Read-only connections that served a page and may serve the next (a PostgreSQL
    /// connection costs a login each time).
    idle: Mutex<Vec<Store>>,
    /// Sign-in attempts per client.
    attempts: Mutex<auth::Attempts>,
    /// Password checks running or waiting for a thread of `checkers` (as many as there are).
    hashing: Arc<tokio::sync::Semaphore>,
    /// The threads that check passwords.
    checkers: auth::Checkers,
    /// What an unknown user's password is checked against (made once, on a checking thread).
    dummy: std::sync::OnceLock<String>,
    /// Console queries running at once.
    console: Arc<tokio::sync::Semaphore>,
    /// What the suggestions page read of stored revisions (they never change), so that a
    /// load reads only the revisions stored since the last.
    suggest_cache: crate::export::Cache,
}

/// Password checks at once: argon2's default takes 19 MiB and a core each.
const HASHING_AT_ONCE: usize = 2;
/// How long a sign-in waits for a password check before it is told the server is busy.
const HASHING_WAIT: std::time::Duration = std::time::Duration::from_secs(5);
/// Console queries at once; a third is told the console is busy.
const CONSOLE_AT_ONCE: usize = 2;

/// Idle read-only connections kept.
const IDLE_KEPT: usize = 4;

impl Server {
    pub(crate) fn new(config: Config, registry: Registry, clock: Arc<dyn Clock>) -> Result<Server> {
        Ok(Server {
            db: config.database.clone(),
            registry,
            clock,
            secret: auth::random()?,
            unstored: Mutex::new(BTreeMap::new()),
            plans: Mutex::new(PlanCache { kept: Vec::new() }),
            idle: Mutex::new(Vec::new()),
            attempts: Mutex::new(auth::Attempts::new(config.web.login_per_minute)),
            hashing: Arc::new(tokio::sync::Semaphore::new(HASHING_AT_ONCE)),
            checkers: auth::Checkers::new(HASHING_AT_ONCE),
            dummy: std::sync::OnceLock::new(),
            console: Arc::new(tokio::sync::Semaphore::new(CONSOLE_AT_ONCE)),
            suggest_cache: crate::export::Cache::default(),
            config,
        })
    }

    fn store(&self) -> Result<Store> {
        if let Some(s) = self.idle.lock().ok().and_then(|mut idle| idle.pop()) {
            return Ok(s);
        }
        Store::open_read_only(&self.db).with_context(|| format!("cannot open the database {}", self.db))
    }

    /// Keeps a connection that served a page without an error for the next one.
    fn give_back(&self, store: Store) {
        if let Ok(mut idle) = self.idle.lock()
            && idle.len() < IDLE_KEPT
        {
            idle.push(store);
        }
    }

    /// The whole plan of a stored revision (cached).
    pub(crate) fn plan(&self, store: &Store, revision: i64) -> Result<Option<Arc<ProcessPlan>>> {
        if let Ok(cache) = self.plans.lock()
            && let Some((_, p)) = cache.kept.iter().find(|(id, _)| *id == revision)
        {
            return Ok(Some(p.clone()));
        }
        let reader = crate::daemon::ingest::Reader { config: &self.config, registry: &self.registry };
        let Some(plan) = store.source(revision)?.map(|src| reader.rebuild(src)).transpose()?.flatten() else { return Ok(None) };
        let plan = Arc::new(plan);
        if let Ok(mut cache) = self.plans.lock() {
            cache.kept.retain(|(id, _)| *id != revision);
            cache.kept.insert(0, (revision, plan.clone()));
            cache.kept.truncate(PLANS_KEPT);
        }
        Ok(Some(plan))
    }

    /// Rebuilds the plans of the newest `n` compared revisions and their originals.
    fn warm(&self, n: usize) {
        let Ok(store) = self.store() else { return };
        let Ok(rows) = store.search_changes(&crate::store::ChangeFilter::default(), 50) else { return };
        let mut seen = Vec::new();
        for r in rows {
            if seen.len() == n {
                break;
            }
            if !seen.contains(&r.revision_id) {
                seen.push(r.revision_id);
                let _ = self.plan(&store, r.original_revision_id);
                let _ = self.plan(&store, r.revision_id);
            }
        }
    }

    /// The hash an unknown user's password is checked against. Blocks (made on first use).
    fn dummy_hash(&self) -> &str {
        self.dummy.get_or_init(|| auth::dummy_hash(&self.config.web_users))
    }

    fn auth_required(&self) -> bool {
        !self.config.web_users.is_empty()
    }

    /// A connection that may write (review marks, saved queries, sessions).
    fn writer(&self) -> Result<Store> {
        Store::open(&self.db, &self.config.site).with_context(|| format!("cannot open the database {}", self.db))
    }

    /// The planner of the stored session whose token hashes to `token_hash`: while it has not
    /// expired and its planner is still among the configured users.
    fn session_user(&self, token_hash: &str) -> Result<Option<String>> {
        let now = self.clock.now();
        let unstored = self.unstored.lock().ok().and_then(|m| m.get(token_hash).cloned());
        let user = match unstored {
            Some((user, until)) => (until > now).then_some(user),
            None => {
                let store = self.store()?;
                let user = store.session_user(token_hash, &now)?;
                self.give_back(store);
                user
            }
        };
        Ok(user.filter(|u| self.config.web_users.iter().any(|w| &w.name == u)))
    }
}

/// Who is asking: their name (signed in, or `None` without authentication) and the CSRF
/// token their forms carry.
#[derive(Clone, Debug)]
pub(crate) struct Ctx {
    pub(crate) user: Option<String>,
    pub(crate) csrf: String,
    pub(crate) auth: bool,
}

/// A page that does not exist.
#[derive(Debug)]
pub(crate) struct NotFound(pub(crate) String);

impl std::fmt::Display for NotFound {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for NotFound {}

/// Runs the server until SIGTERM or SIGINT; `ready` is told the address once it listens.
pub fn serve(options: Options, ready: impl FnOnce(SocketAddr)) -> Result<()> {
    let addr = listen_address(options.listen.as_deref(), &options.config)?;
    // Review marks need migration 4; the daemon may not have run since this ncplan.
    Store::open(&options.config.database, &options.config.site)
        .with_context(|| format!("cannot open the database {}", options.config.database))?;
    let server = Arc::new(Server::new(options.config, options.registry, options.clock)?);
    if let Some(why) = server.store()?.console_refusal()? {
        tracing::warn!(refusal = why, "the SQL console is refused");
    }
    let runtime = tokio::runtime::Builder::new_current_thread().enable_all().build().context("cannot start the runtime")?;
    runtime.block_on(async move {
        let listener = tokio::net::TcpListener::bind(addr).await.with_context(|| format!("cannot listen on {addr}"))?;
        ready(listener.local_addr()?);
        // The newest comparisons' plans are rebuilt at start, so that their pages (a huge
        // program's too) come without reading the programs again.
        let warm = server.clone();
        tokio::task::spawn_blocking(move || warm.warm(WARM_COMPARISONS));
        let dummy = server.clone();
        tokio::spawn(async move { dummy.clone().checkers.run(move || dummy.dummy_hash().len()).await });
        guard::run(listener, router(server), shutdown()).await;
        Ok(())
    })
}

async fn shutdown() {
    let term = async {
        match tokio::signal::unix::signal(tokio::signal::unix::SignalKind::terminate()) {
            Ok(mut s) => {
                s.recv().await;
            }
            Err(_) => std::future::pending::<()>().await,
        }
    };
    tokio::select! {
        _ = term => {}
        _ = tokio::signal::ctrl_c() => {}
    }
}

fn router(server: Arc<Server>) -> Router {
    Router::new()
        .route("/", get(overview))
        .route("/machine/{name}", get(machine))
        .route("/program/{id}", get(program))
        .route("/compare/{revision}", get(compare))
        .route("/compare/{revision}/translate", get(compare::download))
        .route("/compare/{revision}/translate/notes", get(compare::notes))
        .route("/review/{change}", post(review))
        .route("/suggestions", get(suggestions))
        .route("/suggestions/{id}/review", post(suggestion_review))
        .route("/knowledge", get(knowledge_index))
        .route("/knowledge/{name}", get(knowledge))
        .route("/sql", get(sql_console).post(sql_run))
        .route("/sql/save", post(save_query))
        .route("/search", get(search))
        .route("/login", get(login_page).post(login))
        .route("/logout", post(logout))
        .route("/static/app.css", get(|| async { ([(header::CONTENT_TYPE, "text/css; charset=utf-8")], CSS) }))
        .route("/static/app.js", get(|| async { ([(header::CONTENT_TYPE, "text/javascript; charset=utf-8")], JS) }))
        .fallback(|| async { (StatusCode::NOT_FOUND, "no such page") })
        .layer(axum::middleware::from_fn_with_state(server.clone(), guard::layer))
        .with_state(server)
}

/// Renders a page on the blocking pool with a read-only store: signs in first where users
/// are configured, and gives a new visitor the cookie that their CSRF token derives from.
async fn page<F>(s: Arc<Server>, headers: HeaderMap, render: F) -> Response
where
    F: FnOnce(&Server, &Ctx, &Store) -> Result<Markup> + Send + 'static,
{
    let (ctx, cookie) = match auth::context(&s, &headers).await {
        Some(found) => found,
        None => return Redirect::to("/login").into_response(),
    };
    let result = tokio::task::spawn_blocking(move || {
        let store = s.store()?;
        let page = render(&s, &ctx, &store);
        if page.is_ok() {
            s.give_back(store);
        }
        page
    })
    .await;
    let mut response = match result {
        Ok(Ok(markup)) => Html(compare::shown(markup.into_string())).into_response(),
        Ok(Err(e)) if e.downcast_ref::<NotFound>().is_some() => {
            (StatusCode::NOT_FOUND, Html(pages::message("Not found", &format!("{e:#}")).into_string())).into_response()
        }
        Ok(Err(e)) => (StatusCode::INTERNAL_SERVER_ERROR, Html(pages::message("Error", &format!("{e:#}")).into_string())).into_response(),
        Err(e) => (StatusCode::INTERNAL_SERVER_ERROR, format!("the page failed: {e}")).into_response(),
    };
    if let Some(c) = cookie
        && let Ok(v) = HeaderValue::from_str(&c)
    {
        response.headers_mut().append(header::SET_COOKIE, v);
    }
    response
}

async fn overview(State(s): State<Arc<Server>>, headers: HeaderMap) -> Response {
    page(s, headers, pages::overview).await
}

async fn machine(State(s): State<Arc<Server>>, headers: HeaderMap, Path(name): Path<String>) -> Response {
    page(s, headers, move |s, ctx, store| pages::machine(s, ctx, store, &name)).await
}

async fn program(State(s): State<Arc<Server>>, headers: HeaderMap, Path(id): Path<i64>) -> Response {
    page(s, headers, move |s, ctx, store| pages::program(s, ctx, store, id)).await
}

async fn compare(State(s): State<Arc<Server>>, headers: HeaderMap, Path(revision): Path<i64>) -> Response {
    page(s, headers, move |s, ctx, store| pages::comparison(s, ctx, store, revision)).await
}

async fn knowledge_index(State(s): State<Arc<Server>>, headers: HeaderMap) -> Response {
    page(s, headers, pages::knowledge_index).await
}

async fn knowledge(
    State(s): State<Arc<Server>>,
    headers: HeaderMap,
    Path(name): Path<String>,
    Query(q): Query<BTreeMap<String, String>>,
) -> Response {
    let show_sql = q.contains_key("sql");
    page(s, headers, move |s, ctx, store| pages::knowledge(s, ctx, store, &name, show_sql)).await
}

/// The console with the query of `?q=` in its form: shown, never run (a link or an image
/// on another site must not run anything).
async fn sql_console(State(s): State<Arc<Server>>, headers: HeaderMap, Query(q): Query<BTreeMap<String, String>>) -> Response {
    let query = q.get("q").cloned().unwrap_or_default();
    let refused = q.get("refused").cloned();
    page(s, headers, move |s, ctx, store| pages::sql_console(s, ctx, store, &query, refused.as_deref(), pages::Console::Show)).await
}

/// Runs the console's query (`q`, with the session's `csrf`): at most [`CONSOLE_AT_ONCE`]
/// at once, a further one told the console is busy (503).
async fn sql_run(State(s): State<Arc<Server>>, headers: HeaderMap, Form(form): Form<BTreeMap<String, String>>) -> Response {
    let Some((ctx, _)) = auth::context(&s, &headers).await else { return Redirect::to("/login").into_response() };
    if !auth::post_allowed(&s, &headers, &ctx, form.get("csrf").map(String::as_str)) {
        return (StatusCode::FORBIDDEN, "the form's CSRF token does not match this session; reload the page").into_response();
    }
    let query = form.get("q").cloned().unwrap_or_default();
    let Ok(permit) = s.console.clone().try_acquire_owned() else {
        let mut r = page(s, headers, move |s, ctx, store| pages::sql_console(s, ctx, store, &query, None, pages::Console::Busy)).await;
        *r.status_mut() = StatusCode::SERVICE_UNAVAILABLE;
        return r;
    };
    page(s, headers, move |s, ctx, store| {
        let page = pages::sql_console(s, ctx, store, &query, None, pages::Console::Run);
        drop(permit);
        page
    })
    .await
}

async fn search(State(s): State<Arc<Server>>, headers: HeaderMap, Query(q): Query<BTreeMap<String, String>>) -> Response {
    page(s, headers, move |s, ctx, store| pages::search(s, ctx, store, &q)).await
}

/// A review mark: `mark` (adopt, reject, note), `note`, `csrf`, and `by` where nobody signs in.
async fn review(
    State(s): State<Arc<Server>>,
    headers: HeaderMap,
    Path(change): Path<i64>,
    Form(form): Form<BTreeMap<String, String>>,
) -> Response {
    let Some((ctx, _)) = auth::context(&s, &headers).await else { return Redirect::to("/login").into_response() };
    if !auth::post_allowed(&s, &headers, &ctx, form.get("csrf").map(String::as_str)) {
        return (StatusCode::FORBIDDEN, "the form's CSRF token does not match this session; reload the page").into_response();
    }
    let mark = form.get("mark").map(String::as_str).unwrap_or("");
    if !matches!(mark, "adopt" | "reject" | "note") {
        return (StatusCode::BAD_REQUEST, "a mark is adopt, reject or note").into_response();
    }
    let note = form.get("note").map(|n| n.trim().to_owned()).unwrap_or_default();
    if mark == "note" && note.is_empty() {
        return (StatusCode::BAD_REQUEST, "a note needs its text").into_response();
    }
    let by = match &ctx.user {
        Some(u) => u.clone(),
        None => form.get("by").map(|b| b.trim().to_owned()).filter(|b| !b.is_empty()).unwrap_or_else(|| "planner".into()),
    };
    let mark = mark.to_owned();
    let s2 = s.clone();
    let result = tokio::task::spawn_blocking(move || -> Result<Option<i64>> {
        let store = s2.writer()?;
        let at = s2.clock.now();
        Ok(store.add_mark(change, &mark, &note, &by, &at)?)
    })
    .await;
    match result {
        Ok(Ok(Some(revision))) => {
            let back = form.get("back").filter(|b| guard::local_path(b)).cloned();
            Redirect::to(&back.unwrap_or_else(|| format!("/compare/{revision}#change-{change}"))).into_response()
        }
        Ok(Ok(None)) => (StatusCode::NOT_FOUND, "no such change").into_response(),
        Ok(Err(e)) => (StatusCode::INTERNAL_SERVER_ERROR, format!("cannot record the mark: {e:#}")).into_response(),
        Err(e) => (StatusCode::INTERNAL_SERVER_ERROR, format!("cannot record the mark: {e}")).into_response(),
    }
}

/// The suggestions for CAM with their evidence and review forms.
async fn suggestions(State(s): State<Arc<Server>>, headers: HeaderMap) -> Response {
    page(s, headers, |s, ctx, store| {
        let k = crate::export::load_with(store, &s.config, &s.clock.now(), &s.suggest_cache)?;
        Ok(suggest::page(&k, ctx))
    })
    .await
}

/// A planner's step on a suggestion: `to` (accepted, rejected, snoozed), `reason` (a
/// rejection needs one), `csrf`, and `by` where nobody signs in. Back to the suggestion.
async fn suggestion_review(
    State(s): State<Arc<Server>>,
    headers: HeaderMap,
    Path(id): Path<String>,
    Form(form): Form<BTreeMap<String, String>>,
) -> Response {
    let Some((ctx, _)) = auth::context(&s, &headers).await else { return Redirect::to("/login").into_response() };
    if !auth::post_allowed(&s, &headers, &ctx, form.get("csrf").map(String::as_str)) {
        return (StatusCode::FORBIDDEN, "the form's CSRF token does not match this session; reload the page").into_response();
    }
    let Some(to) = form.get("to").and_then(|t| crate::suggest::review::State::parse(t)) else {
        return (StatusCode::BAD_REQUEST, "a step is accepted, rejected or snoozed").into_response();
    };
    let reason = form.get("reason").map(|n| n.trim().to_owned()).unwrap_or_default();
    let by = match &ctx.user {
        Some(u) => u.clone(),
        None => form.get("by").map(|b| b.trim().to_owned()).filter(|b| !b.is_empty()).unwrap_or_else(|| "planner".into()),
    };
    let s2 = s.clone();
    let id2 = id.clone();
    let result = tokio::task::spawn_blocking(move || -> Result<()> {
        let store = s2.writer()?;
        let at = s2.clock.now();
        let k = crate::export::load_with(&store, &s2.config, &at, &s2.suggest_cache)?;
        crate::export::review(&store, &k, &id2, to, &reason, &by, &at)
    })
    .await;
    match result {
        Ok(Ok(())) => Redirect::to(&format!("/suggestions#s-{}", pages::urlencode(&id))).into_response(),
        Ok(Err(e)) => (StatusCode::CONFLICT, format!("{e:#}")).into_response(),
        Err(e) => (StatusCode::INTERNAL_SERVER_ERROR, format!("cannot record the step: {e}")).into_response(),
    }
}

/// Saves the console's query: `name`, `q` (the SQL, one reading statement), `csrf`, and `by`
/// where nobody signs in. Back to the console, which lists it.
async fn save_query(State(s): State<Arc<Server>>, headers: HeaderMap, Form(form): Form<BTreeMap<String, String>>) -> Response {
    let Some((ctx, _)) = auth::context(&s, &headers).await else { return Redirect::to("/login").into_response() };
    if !auth::post_allowed(&s, &headers, &ctx, form.get("csrf").map(String::as_str)) {
        return (StatusCode::FORBIDDEN, "the form's CSRF token does not match this session; reload the page").into_response();
    }
    let name = form.get("name").cloned().unwrap_or_default();
    let sql = form.get("q").cloned().unwrap_or_default();
    let by = match &ctx.user {
        Some(u) => u.clone(),
        None => form.get("by").map(|b| b.trim().to_owned()).filter(|b| !b.is_empty()).unwrap_or_else(|| "planner".into()),
    };
    let s2 = s.clone();
    let sql2 = sql.clone();
    let result = tokio::task::spawn_blocking(move || -> Result<std::result::Result<i64, String>> {
        let store = s2.writer()?;
        Ok(store.save_query(&name, &sql2, &by, &s2.clock.now()).map_err(|e| e.to_string()))
    })
    .await;
    match result {
        Ok(Ok(Ok(_))) => Redirect::to(&format!("/sql?q={}#saved", pages::urlencode(&sql))).into_response(),
        Ok(Ok(Err(refused))) => {
            Redirect::to(&format!("/sql?q={}&refused={}", pages::urlencode(&sql), pages::urlencode(&refused))).into_response()
        }
        Ok(Err(e)) => (StatusCode::INTERNAL_SERVER_ERROR, format!("cannot save the query: {e:#}")).into_response(),
        Err(e) => (StatusCode::INTERNAL_SERVER_ERROR, format!("cannot save the query: {e}")).into_response(),
    }
}

async fn login_page(State(s): State<Arc<Server>>, Query(q): Query<BTreeMap<String, String>>) -> Response {
    Html(pages::login(s.auth_required(), q.contains_key("failed")).into_string()).into_response()
}

/// A sign-in: at most `[web] login_per_minute` attempts per client (429 past them), at most
/// [`HASHING_AT_ONCE`] password checks at once (a sign-in that waits longer than
/// [`HASHING_WAIT`] is told the server is busy, 503), an unknown name checked as long as a
/// known one.
async fn login(
    State(s): State<Arc<Server>>,
    peer: Option<Extension<guard::Peer>>,
    headers: HeaderMap,
    Form(form): Form<BTreeMap<String, String>>,
) -> Response {
    if let Some(Extension(peer)) = peer {
        let client = guard::client(&peer, &headers, &s.config.web.trusted_proxies);
        let wait = s.attempts.lock().ok().and_then(|mut a| a.take(client, std::time::Instant::now()).err());
        if let Some(wait) = wait {
            let secs = wait.as_secs() + 1;
            tracing::warn!(%client, "sign-in attempts past the rate limit");
            let mut r = (StatusCode::TOO_MANY_REQUESTS, format!("too many sign-in attempts; try again in {secs} s")).into_response();
            r.headers_mut().insert(header::RETRY_AFTER, HeaderValue::from(secs));
            return r;
        }
    }
    let Ok(Ok(permit)) = tokio::time::timeout(HASHING_WAIT, s.hashing.clone().acquire_owned()).await else {
        return (StatusCode::SERVICE_UNAVAILABLE, "the server is busy checking passwords; try again in a moment").into_response();
    };
    let name = form.get("name").cloned().unwrap_or_default();
    let password = form.get("password").cloned().unwrap_or_default();
    let s2 = s.clone();
    // The password check on a checking thread (holding its permit even if the client goes),
    // then the session's write on the blocking pool.
    let checked = s.checkers.run(move || {
        let ok = auth::check_password(&s2.config.web_users, &name, &password, s2.dummy_hash());
        drop(permit);
        ok.then_some(name)
    });
    let Some(checked) = checked.await else {
        return (StatusCode::INTERNAL_SERVER_ERROR, "cannot check the password").into_response();
    };
    let s2 = s.clone();
    let started = tokio::task::spawn_blocking(move || checked.map(|name| auth::start_session(&s2, &name))).await;
    match started {
        Ok(Some(Ok(cookie))) => {
            let mut r = Redirect::to("/").into_response();
            if let Ok(v) = HeaderValue::from_str(&cookie) {
                r.headers_mut().append(header::SET_COOKIE, v);
            }
            r
        }
        Ok(Some(Err(e))) => (StatusCode::INTERNAL_SERVER_ERROR, format!("cannot start a session: {e:#}")).into_response(),
        Ok(None) => Redirect::to("/login?failed").into_response(),
        Err(e) => (StatusCode::INTERNAL_SERVER_ERROR, format!("cannot start a session: {e}")).into_response(),
    }
}

async fn logout(State(s): State<Arc<Server>>, headers: HeaderMap, Form(form): Form<BTreeMap<String, String>>) -> Response {
    if let Some((ctx, _)) = auth::context(&s, &headers).await
        && auth::post_allowed(&s, &headers, &ctx, form.get("csrf").map(String::as_str))
    {
        let s2 = s.clone();
        match tokio::task::spawn_blocking(move || auth::end_session(&s2, &headers)).await {
            Ok(Ok(())) => {}
            Ok(Err(e)) => return (StatusCode::INTERNAL_SERVER_ERROR, format!("cannot end the session: {e:#}")).into_response(),
            Err(e) => return (StatusCode::INTERNAL_SERVER_ERROR, format!("cannot end the session: {e}")).into_response(),
        }
    }
    let mut r = Redirect::to("/login").into_response();
    r.headers_mut().append(header::SET_COOKIE, HeaderValue::from_static("ncplan_session=; Max-Age=0; Path=/; HttpOnly; SameSite=Strict"));
    r
}

//! The workspace against the web's usual attacks, below the pages: how connections are
//! accepted, which `Host` a request may name, the headers every response carries, and the
//! bound on a request's body.
//!
//! - **Connections** ([`run`]): accepted here rather than by `axum::serve` (which has no
//!   header-read timeout and no cap). Each is hyper's HTTP/1 connection with
//!   [`HEADER_TIMEOUT`] for a request's head (and for an idle keep-alive connection's next
//!   one), at most [`MAX_CONNECTIONS`] open: a new one past the cap closes the connection
//!   that has waited longest for a request head (a slow-loris client's), so a thousand slow
//!   clients never keep a planner out; while every connection is inside a request, a new one
//!   waits for room.
//! - **Host** ([`host_allowed`]): a page of another name that resolves to this server (DNS
//!   rebinding) sends its own name; only the address the connection arrived at (an IP
//!   literal), `localhost` on loopback and `[web] hosts` are answered, any other is `421` on
//!   every route.
//! - **Headers** on every response, errors and sign-in included: a Content-Security-Policy
//!   with `frame-ancestors 'none'` (the pages have no inline script or style), `X-Frame-Options`,
//!   `nosniff`, `Referrer-Policy`, `Cross-Origin-Resource-Policy`; cookies made `Secure` when
//!   the request came over TLS ([`secure`]).
//! - **Bodies**: read whole within [`BODY_TIMEOUT`], at most [`BODY_LIMIT`] bytes (`408`, `413`).

use std::collections::BTreeMap;
use std::net::{IpAddr, SocketAddr};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

use axum::Router;
use axum::body::Body;
use axum::extract::{Request, State};
use axum::http::{HeaderMap, HeaderValue, StatusCode, header};
use axum::middleware::Next;
use axum::response::{IntoResponse, Response};
use tokio::sync::oneshot;

use super::Server;

/// How long a client may take to send a request's head (and an idle connection may wait).
pub(super) const HEADER_TIMEOUT: Duration = Duration::from_secs(10);
/// How long a client may take to send a request's body.
pub(super) const BODY_TIMEOUT: Duration = Duration::from_secs(10);
/// The largest body taken (the forms are small; a console query is text).
pub(super) const BODY_LIMIT: usize = 256 * 1024;
/// Connections open at once.
pub(super) const MAX_CONNECTIONS: usize = 256;
/// How long a connection may wait for a request head before a new connection past the cap
/// closes it (a browser sends its head at once).
const SLOW_HEAD: Duration = Duration::from_secs(1);
/// How long a new connection waits for room while every open one is inside a request.
const ADMIT_WAIT: Duration = Duration::from_secs(30);
/// How long a stopping server waits for the requests in progress.
const DRAIN: Duration = Duration::from_secs(5);

/// The policy every response carries: nothing from elsewhere, no inline script or style, no
/// framing, forms only to this server.
pub(super) const CSP: &str = "default-src 'self'; script-src 'self'; style-src 'self'; img-src 'self' data:; object-src 'none'; \
                              base-uri 'none'; form-action 'self'; frame-ancestors 'none'";

/// Where a request came from: the client's address and the local one it arrived at.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Peer {
    pub(crate) remote: SocketAddr,
    pub(crate) local: SocketAddr,
}

/// The open connections: since when each has waited for a request head (`None`: inside a
/// request), and how to close it.
#[derive(Default)]
struct Open {
    next: u64,
    conns: BTreeMap<u64, (Option<Instant>, Option<oneshot::Sender<()>>)>,
}

impl Open {
    /// Room for a new connection: its id and the signal that closes it, after closing the
    /// connection that has waited longest for a head when the cap is reached; `None` when
    /// none has waited [`SLOW_HEAD`] (every open connection is inside a request, or has only
    /// just come and not been read yet).
    fn admit(&mut self, now: Instant, cap: usize) -> Option<(u64, oneshot::Receiver<()>)> {
        if self.conns.len() >= cap {
            let (since, oldest) = self.conns.iter().filter_map(|(id, (since, _))| since.map(|t| (t, *id))).min()?;
            if now.saturating_duration_since(since) < SLOW_HEAD {
                return None;
            }
            if let Some((_, Some(close))) = self.conns.remove(&oldest) {
                let _ = close.send(());
            }
        }
        let (tx, rx) = oneshot::channel();
        self.next += 1;
        self.conns.insert(self.next, (Some(now), Some(tx)));
        Some((self.next, rx))
    }

    fn waiting(&mut self, id: u64, since: Option<Instant>) {
        if let Some(c) = self.conns.get_mut(&id) {
            c.0 = since;
        }
    }
}

/// Serves `app` on `listener` until `shutdown`, then waits up to [`DRAIN`] for the
/// requests in progress.
pub(super) async fn run(listener: tokio::net::TcpListener, app: Router, shutdown: impl std::future::Future<Output = ()>) {
    let open = Arc::new(Mutex::new(Open::default()));
    let mut shutdown = std::pin::pin!(shutdown);
    loop {
        let (stream, remote) = tokio::select! {
            _ = &mut shutdown => break,
            accepted = listener.accept() => match accepted {
                Ok(a) => a,
                Err(e) => {
                    // Out of file descriptors, most likely: wait for some to close.
                    tracing::warn!(error = %e, "cannot accept a connection");
                    tokio::time::sleep(Duration::from_millis(50)).await;
                    continue;
                }
            },
        };
        let Ok(local) = stream.local_addr() else { continue };
        let Some((id, closed)) = admit(&open).await else {
            tracing::warn!(%remote, "every connection has been inside a request for {} s; a new one is refused", ADMIT_WAIT.as_secs());
            continue;
        };
        tokio::spawn(connection(stream, Peer { remote, local }, app.clone(), open.clone(), id, closed));
    }
    let deadline = Instant::now() + DRAIN;
    while open.lock().is_ok_and(|o| o.conns.values().any(|c| c.0.is_none())) && Instant::now() < deadline {
        tokio::time::sleep(Duration::from_millis(20)).await;
    }
}

/// Room for a new connection (see [`Open::admit`]): while no open one can be closed for it,
/// the new one waits (in the kernel's backlog the connections behind it wait too), at most
/// [`ADMIT_WAIT`]: a request's body is read within [`BODY_TIMEOUT`].
async fn admit(open: &Mutex<Open>) -> Option<(u64, oneshot::Receiver<()>)> {
    let deadline = Instant::now() + ADMIT_WAIT;
    loop {
        if let Some(room) = open.lock().ok()?.admit(Instant::now(), MAX_CONNECTIONS) {
            return Some(room);
        }
        if Instant::now() > deadline {
            return None;
        }
        tokio::time::sleep(Duration::from_millis(10)).await;
    }
}

async fn connection(
    stream: tokio::net::TcpStream,
    peer: Peer,
    app: Router,
    open: Arc<Mutex<Open>>,
    id: u64,
    closed: oneshot::Receiver<()>,
) {
    let opened = open.clone();
    let service = hyper::service::service_fn(move |mut request: hyper::Request<hyper::body::Incoming>| {
        request.extensions_mut().insert(peer);
        if let Ok(mut o) = opened.lock() {
            o.waiting(id, None);
        }
        let mut app = app.clone();
        let opened = opened.clone();
        async move {
            let response = tower_service::Service::call(&mut app, request).await;
            if let Ok(mut o) = opened.lock() {
                o.waiting(id, Some(Instant::now()));
            }
            response
        }
    });
    let mut builder = hyper::server::conn::http1::Builder::new();
    builder.timer(hyper_util::rt::TokioTimer::new()).header_read_timeout(HEADER_TIMEOUT).max_buf_size(64 * 1024);
    let conn = builder.serve_connection(hyper_util::rt::TokioIo::new(stream), service);
    tokio::select! {
        _ = conn => {}
        _ = closed => {}
    }
    if let Ok(mut o) = open.lock() {
        o.conns.remove(&id);
    }
}

/// Whether `host` (a `Host` header) names this server: the IP address the connection arrived
/// at (any port), `localhost` when that is loopback, or one of `names` (`name`: any port;
/// `name:port`: that port).
pub(super) fn host_allowed(host: &str, local: SocketAddr, names: &[String]) -> bool {
    let host = host.trim().to_ascii_lowercase();
    let (name, port) = split_host(&host);
    let name = name.strip_suffix('.').unwrap_or(name);
    if let Ok(ip) = name.parse::<IpAddr>() {
        return ip.to_canonical() == local.ip().to_canonical();
    }
    if name == "localhost" && local.ip().to_canonical().is_loopback() {
        return true;
    }
    names.iter().any(|n| {
        let n = n.trim().to_ascii_lowercase();
        let (n_name, n_port) = split_host(&n);
        n_name.strip_suffix('.').unwrap_or(n_name) == name && (n_port.is_none() || n_port == port)
    })
}

/// A host and its port: `name:8480`, `[::1]:8480`, `name`.
fn split_host(host: &str) -> (&str, Option<&str>) {
    if let Some(rest) = host.strip_prefix('[') {
        let (ip, after) = rest.split_once(']').unwrap_or((rest, ""));
        return (ip, after.strip_prefix(':'));
    }
    match host.rsplit_once(':') {
        Some((name, port)) if !name.contains(':') => (name, Some(port)),
        _ => (host, None),
    }
}

/// The client a request is from, as the sign-in limit counts clients: the peer, or, behind a
/// trusted proxy, the address the proxy appended to `X-Forwarded-For`; an IPv6 address by its
/// /64 network (one host is given a whole /64 and may use any address in it).
pub(super) fn client(peer: &Peer, headers: &HeaderMap, trusted: &[IpAddr]) -> IpAddr {
    let direct = peer.remote.ip().to_canonical();
    let ip = if trusted.iter().any(|t| t.to_canonical() == direct) {
        let forwarded = headers.get_all("x-forwarded-for").iter().filter_map(|v| v.to_str().ok()).flat_map(|v| v.split(',')).last();
        forwarded.and_then(|f| f.trim().parse::<IpAddr>().ok()).map_or(direct, |ip| ip.to_canonical())
    } else {
        direct
    };
    match ip {
        IpAddr::V6(v6) => IpAddr::V6(std::net::Ipv6Addr::from(u128::from(v6) & !((1u128 << 64) - 1))),
        v4 => v4,
    }
}

/// Whether `target` is a path of this server to send a browser back to: `/…`, but not `//host`
/// or `/\host` (which browsers read as another server).
pub(super) fn local_path(target: &str) -> bool {
    let mut chars = target.chars();
    chars.next() == Some('/') && !matches!(chars.next(), Some('/' | '\\')) && !target.contains(['\r', '\n'])
}

/// Whether the request reached the server over TLS: `[web] secure_cookies`, or a trusted
/// proxy's `X-Forwarded-Proto: https`.
pub(super) fn secure(s: &Server, peer: Option<&Peer>, headers: &HeaderMap) -> bool {
    if s.config.web.secure_cookies {
        return true;
    }
    let Some(peer) = peer else { return false };
    let direct = peer.remote.ip().to_canonical();
    s.config.web.trusted_proxies.iter().any(|t| t.to_canonical() == direct)
        && headers.get("x-forwarded-proto").and_then(|v| v.to_str().ok()).is_some_and(|p| p.trim().eq_ignore_ascii_case("https"))
}

/// The outermost layer: refuses another `Host`, bounds the body, and puts the security
/// headers on whatever the inner layers answer.
pub(super) async fn layer(State(s): State<Arc<Server>>, request: Request, next: Next) -> Response {
    let peer = request.extensions().get::<Peer>().copied();
    let secure = secure(&s, peer.as_ref(), request.headers());
    let mut response = match screen(&s, peer, request).await {
        Ok(request) => next.run(request).await,
        Err(refused) => refused,
    };
    let h = response.headers_mut();
    h.insert(header::CONTENT_SECURITY_POLICY, HeaderValue::from_static(CSP));
    h.insert(header::X_FRAME_OPTIONS, HeaderValue::from_static("DENY"));
    h.insert(header::X_CONTENT_TYPE_OPTIONS, HeaderValue::from_static("nosniff"));
    h.insert(header::REFERRER_POLICY, HeaderValue::from_static("same-origin"));
    h.insert("cross-origin-resource-policy", HeaderValue::from_static("same-origin"));
    h.insert("cross-origin-opener-policy", HeaderValue::from_static("same-origin"));
    if secure {
        let cookies: Vec<HeaderValue> = h.get_all(header::SET_COOKIE).iter().cloned().collect();
        h.remove(header::SET_COOKIE);
        for c in cookies {
            let text = c.to_str().unwrap_or_default();
            let made = if text.contains("; Secure") { c.clone() } else { HeaderValue::from_str(&format!("{text}; Secure")).unwrap_or(c) };
            h.append(header::SET_COOKIE, made);
        }
    }
    response
}

/// The request with its body read, or the refusal: another `Host` (421), a body too slow
/// (408) or too large (413).
async fn screen(s: &Server, peer: Option<Peer>, request: Request) -> Result<Request, Response> {
    let host = request.headers().get(header::HOST).and_then(|h| h.to_str().ok()).unwrap_or("");
    if let Some(peer) = peer
        && !host_allowed(host, peer.local, &s.config.web.hosts)
    {
        tracing::warn!(host, client = %peer.remote, "a request for another host name is refused");
        let said = if host.is_empty() { "no host name".to_owned() } else { format!("the host name `{host}`") };
        return Err((
            StatusCode::MISDIRECTED_REQUEST,
            format!("this server does not answer for {said}; if it is this server's own name, add it to [web] hosts"),
        )
            .into_response());
    }
    let length = request.headers().get(header::CONTENT_LENGTH).and_then(|l| l.to_str().ok()).and_then(|l| l.trim().parse::<u64>().ok());
    if length.is_some_and(|l| l > BODY_LIMIT as u64) {
        return Err(too_large());
    }
    let (parts, body) = request.into_parts();
    match tokio::time::timeout(BODY_TIMEOUT, axum::body::to_bytes(body, BODY_LIMIT)).await {
        Ok(Ok(bytes)) => Ok(Request::from_parts(parts, Body::from(bytes))),
        Ok(Err(_)) => Err(too_large()),
        Err(_) => {
            Err((StatusCode::REQUEST_TIMEOUT, format!("the request body did not come within {} s", BODY_TIMEOUT.as_secs())).into_response())
        }
    }
}

fn too_large() -> Response {
    (StatusCode::PAYLOAD_TOO_LARGE, format!("a request body is at most {BODY_LIMIT} bytes")).into_response()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn at(a: &str) -> SocketAddr {
        a.parse().unwrap()
    }

    #[test]
    fn only_this_servers_names_are_answered() {
        let names = vec!["ncplan.plant.example".to_owned(), "dnc:8443".to_owned()];
        let lo = at("127.0.0.1:8480");
        for ok in
            ["127.0.0.1:8480", "127.0.0.1", "localhost:8480", "LOCALHOST", "ncplan.plant.example", "ncplan.plant.example.:443", "dnc:8443"]
        {
            assert!(host_allowed(ok, lo, &names), "{ok}");
        }
        for refused in ["evil.example:8480", "", "127.0.0.2:8480", "dnc:8480", "ncplan.plant.example.evil.example", "localhost.evil"] {
            assert!(!host_allowed(refused, lo, &names), "{refused}");
        }
        // On a plant address, `localhost` is not this server; the address itself is.
        let lan = at("10.0.0.5:8480");
        assert!(host_allowed("10.0.0.5:8480", lan, &names) && !host_allowed("localhost:8480", lan, &names));
        assert!(host_allowed("[::1]:8480", at("[::1]:8480"), &[]));
        assert!(host_allowed("127.0.0.1:8480", at("[::ffff:127.0.0.1]:8480"), &[]));
    }

    #[test]
    fn a_slow_client_waiting_longest_makes_room_for_a_new_one() {
        let mut open = Open::default();
        let t0 = Instant::now();
        let (a, mut a_closed) = open.admit(t0, 2).unwrap();
        let (b, mut b_closed) = open.admit(t0 + Duration::from_secs(1), 2).unwrap();
        // `b` is inside a request; `a` has not waited long enough to be called slow.
        open.waiting(b, None);
        assert!(open.admit(t0 + Duration::from_millis(500), 2).is_none());
        // The next connection closes `a`, which has waited for its head for 2 s.
        let (_c, _) = open.admit(t0 + Duration::from_secs(2), 2).unwrap();
        assert!(a_closed.try_recv().is_ok() && b_closed.try_recv().is_err());
        assert!(!open.conns.contains_key(&a));
        // Every connection inside a request: a new one is refused.
        let ids: Vec<u64> = open.conns.keys().copied().collect();
        for id in ids {
            open.waiting(id, None);
        }
        assert!(open.admit(t0 + Duration::from_secs(9), 2).is_none());
    }

    #[test]
    fn the_client_is_the_proxys_only_when_the_proxy_is_trusted() {
        let peer = Peer { remote: at("10.0.0.9:40000"), local: at("10.0.0.5:8480") };
        let mut h = HeaderMap::new();
        h.insert("x-forwarded-for", HeaderValue::from_static("1.2.3.4, 192.0.2.7"));
        assert_eq!(client(&peer, &h, &[]), "10.0.0.9".parse::<IpAddr>().unwrap());
        assert_eq!(client(&peer, &h, &["10.0.0.9".parse().unwrap()]), "192.0.2.7".parse::<IpAddr>().unwrap());
        // An IPv6 client is its /64: the addresses of one host count together.
        let v6 = |a: &str| Peer { remote: SocketAddr::new(a.parse().unwrap(), 40000), local: at("[::1]:8480") };
        let one = client(&v6("2001:db8:1:2:aaaa::1"), &HeaderMap::new(), &[]);
        assert_eq!(one, client(&v6("2001:db8:1:2:ffff:1234::9"), &HeaderMap::new(), &[]));
        assert_ne!(one, client(&v6("2001:db8:1:3::1"), &HeaderMap::new(), &[]));
    }

    #[test]
    fn only_this_servers_paths_are_gone_back_to() {
        for ok in ["/", "/compare/3#change-4", "/search?to_review=1"] {
            assert!(local_path(ok), "{ok}");
        }
        for refused in ["//evil.example/", "/\\evil.example/", "https://evil.example/", "", "evil", "/x\r\nSet-Cookie: a=b"] {
            assert!(!local_path(refused), "{refused}");
        }
    }
}

//! The systemd notification protocol (`sd_notify`), over the datagram socket systemd names in
//! `NOTIFY_SOCKET`. Without that variable every call is a no-op.

use std::os::unix::net::UnixDatagram;
use std::time::Duration;

/// A handle on systemd's notification socket.
pub(super) struct Notifier {
    socket: Option<(UnixDatagram, String)>,
    watchdog: Option<Duration>,
}

impl Notifier {
    /// Reads `NOTIFY_SOCKET` and `WATCHDOG_USEC` from the environment.
    pub(super) fn from_env() -> Notifier {
        let socket = std::env::var("NOTIFY_SOCKET").ok().and_then(|path| UnixDatagram::unbound().ok().map(|s| (s, path)));
        let watchdog = std::env::var("WATCHDOG_USEC").ok().and_then(|v| v.parse::<u64>().ok()).map(Duration::from_micros);
        Notifier { socket, watchdog }
    }

    /// How often to ping the watchdog: half of systemd's `WatchdogSec`.
    pub(super) fn watchdog_interval(&self) -> Option<Duration> {
        self.watchdog.map(|w| w / 2)
    }

    /// Sends `state` (such as `READY=1`). Failures are ignored: notification is advisory.
    pub(super) fn notify(&self, state: &str) {
        let Some((sock, path)) = &self.socket else { return };
        let _ = if let Some(name) = path.strip_prefix('@') {
            use std::os::linux::net::SocketAddrExt;
            std::os::unix::net::SocketAddr::from_abstract_name(name.as_bytes()).and_then(|addr| sock.send_to_addr(state.as_bytes(), &addr))
        } else {
            sock.send_to(state.as_bytes(), path)
        };
    }
}

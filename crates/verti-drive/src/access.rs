//! Who may talk to the live server. It listens on loopback, but every web page the user has
//! open can still send requests there, and a page on a rebinding domain can even read the
//! answers; so a request is served only if
//!
//! * its `Host` names this server by loopback address or `localhost` (DNS rebinding sends the
//!   attacker's name),
//! * its `Origin`, when sent, is this server's own (other pages' requests carry theirs),
//! * its `Sec-Fetch-Site`, when sent, is `same-origin` or `none` (a request or navigation
//!   started by another site, e.g. opening the page with `#keys=` in a new tab),
//! * and, for everything but the page itself, it carries the session's random token, which
//!   only the page (readable by same-origin scripts alone) knows.

use crate::http::Request;
use std::net::SocketAddr;

/// Header carrying the token.
pub const TOKEN_HEADER: &str = "x-verti-token";

/// A refusal: HTTP status and a reason for the body.
pub type Refusal = (&'static str, String);

/// The access rules of one session.
#[derive(Clone, Debug)]
pub struct Access {
    /// `host:port` forms accepted in `Host` (lower case).
    hosts: Vec<String>,
    token: String,
}

impl Access {
    /// Rules for a server listening on `addr` (which must be loopback) with `token`.
    pub fn new(addr: SocketAddr, token: String) -> Result<Access, String> {
        if !addr.ip().is_loopback() {
            return Err(format!(
                "the live view must listen on loopback only, not {addr}"
            ));
        }
        let port = addr.port();
        let ip = match addr {
            SocketAddr::V4(a) => a.ip().to_string(),
            SocketAddr::V6(a) => format!("[{}]", a.ip()),
        };
        let mut hosts = vec![format!("{ip}:{port}"), format!("localhost:{port}")];
        // browsers leave the default port out of `Host`
        if port == 80 {
            hosts.extend([ip, "localhost".to_string()]);
        }
        Ok(Access { hosts, token })
    }

    /// The session's token (goes into the served page).
    pub fn token(&self) -> &str {
        &self.token
    }

    /// Checks where a request comes from: `Host`, `Origin` and `Sec-Fetch-Site`.
    pub fn check_origin(&self, req: &Request) -> Result<(), Refusal> {
        let host = req.header("host").unwrap_or("").to_ascii_lowercase();
        if !self.hosts.contains(&host) {
            return Err((
                "403 Forbidden",
                format!(
                    "Host `{host}` is not this server: open http://{}/",
                    self.hosts[0]
                ),
            ));
        }
        if let Some(origin) = req.header("origin") {
            let origin = origin.to_ascii_lowercase();
            let own = origin
                .strip_prefix("http://")
                .is_some_and(|h| self.hosts.iter().any(|ok| ok == h));
            if !own {
                return Err((
                    "403 Forbidden",
                    format!("Origin `{origin}` is not this server"),
                ));
            }
        }
        if let Some(site) = req.header("sec-fetch-site")
            && site != "same-origin"
            && site != "none"
        {
            return Err((
                "403 Forbidden",
                format!(
                    "requests started by another site ({site}) are refused: open http://{}/ yourself",
                    self.hosts[0]
                ),
            ));
        }
        Ok(())
    }

    /// Checks the token header.
    pub fn check_token(&self, req: &Request) -> Result<(), Refusal> {
        let given = req.header(TOKEN_HEADER).unwrap_or("");
        if constant_time_eq(given.as_bytes(), self.token.as_bytes()) {
            Ok(())
        } else {
            Err((
                "403 Forbidden",
                "missing or wrong session token: reload the page from the address `verti drive` printed"
                    .to_string(),
            ))
        }
    }
}

/// Equality whose time does not depend on where the inputs differ (only on their lengths,
/// and the token's length is public): guessing the token byte by byte from response times
/// does not work.
pub fn constant_time_eq(a: &[u8], b: &[u8]) -> bool {
    if a.len() != b.len() {
        return false;
    }
    let diff = a.iter().zip(b).fold(0u8, |d, (x, y)| d | (x ^ y));
    std::hint::black_box(diff) == 0
}

/// A fresh 128-bit token as 32 hex digits: from the OS's random source, or where there is
/// none, from std's randomly keyed hasher over the time, the process id and a counter.
pub fn new_token() -> String {
    let mut bytes = [0u8; 16];
    let from_os = std::fs::File::open("/dev/urandom")
        .and_then(|mut f| std::io::Read::read_exact(&mut f, &mut bytes))
        .is_ok();
    if !from_os {
        use std::hash::{BuildHasher, Hasher};
        static COUNTER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
        let n = COUNTER.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
        let now = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos());
        for half in bytes.chunks_mut(8) {
            // each RandomState is keyed afresh from the OS (or per-thread random keys)
            let mut h = std::collections::hash_map::RandomState::new().build_hasher();
            h.write_u128(now);
            h.write_u32(std::process::id());
            h.write_u64(n);
            half.copy_from_slice(&h.finish().to_le_bytes());
        }
    }
    bytes.iter().map(|b| format!("{b:02x}")).collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::http::parse_request;

    fn req(headers: &str) -> Request {
        parse_request(format!("POST /step HTTP/1.1\r\n{headers}\r\n").as_bytes()).unwrap()
    }

    #[test]
    fn only_this_servers_names_origins_and_token_pass() {
        let a = Access::new("127.0.0.1:8765".parse().unwrap(), "ab12".into()).unwrap();
        for ok in [
            "Host: 127.0.0.1:8765\r\n",
            "Host: LOCALHOST:8765\r\nOrigin: http://localhost:8765\r\nSec-Fetch-Site: same-origin\r\n",
            "Host: localhost:8765\r\nSec-Fetch-Site: none\r\n",
        ] {
            assert!(a.check_origin(&req(ok)).is_ok(), "{ok}");
        }
        for bad in [
            "",
            "Host: evil.example:8765\r\n",
            "Host: 127.0.0.1\r\n",
            "Host: 127.0.0.1:8766\r\n",
            "Host: 127.0.0.1:8765\r\nOrigin: http://evil.example\r\n",
            "Host: 127.0.0.1:8765\r\nOrigin: null\r\n",
            "Host: 127.0.0.1:8765\r\nOrigin: https://127.0.0.1:8765\r\n",
            "Host: 127.0.0.1:8765\r\nSec-Fetch-Site: cross-site\r\n",
            "Host: 127.0.0.1:8765\r\nSec-Fetch-Site: same-site\r\n",
        ] {
            assert_eq!(
                a.check_origin(&req(bad)).unwrap_err().0,
                "403 Forbidden",
                "{bad}"
            );
        }
        assert!(a.check_token(&req("X-Verti-Token: ab12\r\n")).is_ok());
        assert!(a.check_token(&req("X-Verti-Token: ab13\r\n")).is_err());
        assert!(a.check_token(&req("X-Verti-Token: ab1\r\n")).is_err());
        assert!(a.check_token(&req("")).is_err());
        let v6 = Access::new("[::1]:80".parse().unwrap(), "t".into()).unwrap();
        assert!(v6.check_origin(&req("Host: [::1]\r\n")).is_ok());
        assert!(v6.check_origin(&req("Host: [::1]:80\r\n")).is_ok());
        assert!(Access::new("0.0.0.0:8765".parse().unwrap(), "t".into()).is_err());
    }

    #[test]
    fn tokens_are_128_bit_hex_and_differ() {
        let (a, b) = (new_token(), new_token());
        assert_eq!(a.len(), 32);
        assert!(a.bytes().all(|c| c.is_ascii_hexdigit()));
        assert_ne!(a, b);
        assert!(constant_time_eq(b"abc", b"abc") && !constant_time_eq(b"abc", b"abd"));
    }
}

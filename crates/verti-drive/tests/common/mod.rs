//! Helpers shared by the live server's tests: a server on a loopback port, and a small HTTP
//! client that talks to it the way the page (or an attacker) would. Every read has a time
//! limit, so a server that stalls fails the test instead of hanging it.

#![allow(dead_code)] // each test file uses its own part

use std::io::{Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::time::Duration;
use verti_bench::EpisodeConfig;
use verti_drive::server::{ServeOptions, serve, token_in_page};
use verti_drive::{DriveSession, SessionEnd};

pub fn world() -> (Vec<Arc<verti_world::World>>, verti_sim::VehicleSpec) {
    let set = verti_world::sets::resolve_set("verti-4", 1.0, &|| {}).unwrap();
    let worlds = set.worlds.into_iter().map(Arc::new).collect();
    (worlds, verti_sim::vehicles::builtin("hmmwv").unwrap())
}

/// A live server driving task 1 of verti-4 by hand, on its own thread.
pub struct Server {
    pub addr: SocketAddr,
    /// `Host` naming it (`127.0.0.1:PORT`).
    pub host: String,
    pub token: String,
    thread: std::thread::JoinHandle<SessionEnd>,
}

impl Server {
    pub fn start(speed: f64, idle: Duration) -> Server {
        let (worlds, spec) = world();
        let w = worlds[0].clone();
        let listener = TcpListener::bind(("127.0.0.1", 0)).unwrap();
        let addr = listener.local_addr().unwrap();
        let thread = std::thread::spawn(move || {
            let cfg = EpisodeConfig::default();
            let session = DriveSession::start(&w, &spec, w.tasks[0].pair, &cfg, None).unwrap();
            let opts = ServeOptions {
                speed,
                idle,
                stop: None,
            };
            serve(session, &listener, opts).unwrap()
        });
        let host = addr.to_string();
        let page = exchange(addr, &format!("GET / HTTP/1.1\r\nHost: {host}\r\n\r\n"));
        assert_eq!(page.status, 200, "{}", page.body);
        let token = token_in_page(&page.body).unwrap().to_string();
        Server {
            addr,
            host,
            token,
            thread,
        }
    }

    /// `POST path` with the right Host and token.
    pub fn post(&self, path: &str) -> Reply {
        exchange(
            self.addr,
            &format!(
                "POST {path} HTTP/1.1\r\nHost: {}\r\nOrigin: http://{}\r\nX-Verti-Token: {}\r\nContent-Length: 0\r\n\r\n",
                self.host, self.host, self.token
            ),
        )
    }

    /// Stops the session and returns what it recorded.
    pub fn quit(self) -> SessionEnd {
        let r = self.post("/quit");
        assert_eq!((r.status, r.body.as_str()), (200, "stopped"));
        self.thread.join().unwrap()
    }
}

/// A response: status code, head (for header checks) and body.
pub struct Reply {
    pub status: u16,
    pub head: String,
    pub body: String,
}

/// Sends `raw` on a fresh connection and reads the whole response (10-s limit).
pub fn exchange(addr: SocketAddr, raw: &str) -> Reply {
    let mut s = TcpStream::connect(addr).unwrap();
    s.set_read_timeout(Some(Duration::from_secs(10))).unwrap();
    s.write_all(raw.as_bytes()).unwrap();
    read_reply(&mut s)
}

pub fn read_reply(s: &mut TcpStream) -> Reply {
    let mut bytes = Vec::new();
    s.read_to_end(&mut bytes)
        .expect("the server answers within the time limit");
    let text = String::from_utf8_lossy(&bytes).into_owned();
    let (head, body) = text.split_once("\r\n\r\n").unwrap_or((&text, ""));
    let status = head
        .split(' ')
        .nth(1)
        .and_then(|c| c.parse().ok())
        .unwrap_or(0);
    Reply {
        status,
        head: head.to_string(),
        body: body.to_string(),
    }
}

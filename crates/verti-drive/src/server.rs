//! The live view's local web server: the page (the 3-D viewer in live mode) polls `/step`
//! with the keys it holds; each poll advances the trial to the wall clock (real time), one
//! control period at a time, and answers with the frames made since the page's last one.
//!
//! Standard library only. Connections are served concurrently, each on its own thread, at
//! most [`MAX_CONNECTIONS`] at once, and each must deliver its whole request within
//! [`REQUEST_DEADLINE`]: idle or trickling connections cannot hold up the page's polls. The
//! session itself sits behind one lock, so steps stay in order and deterministic. Who may
//! send what is [`crate::access`]'s business: the page is `GET /`; `/step` and `/quit` change
//! the session (and `/step` shows its frames), so they are `POST` only and need the token.

use crate::access::{Access, new_token};
use crate::driver::Keys;
use crate::http::{ParseError, Request, head_len, parse_head};
use crate::session::{DriveSession, SessionEnd};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
use std::sync::{Mutex, MutexGuard, PoisonError};
use std::time::{Duration, Instant};

/// How the server paces and ends a session.
#[derive(Clone, Copy, Debug)]
pub struct ServeOptions {
    /// Simulated seconds per wall-clock second (1 = real time).
    pub speed: f64,
    /// End the session when the page has not asked for this long (a closed tab).
    pub idle: Duration,
    /// Raised (e.g. by a signal handler) to end the session: it is saved as it stands.
    pub stop: Option<&'static AtomicBool>,
}

impl Default for ServeOptions {
    fn default() -> Self {
        ServeOptions {
            speed: 1.0,
            idle: Duration::from_secs(30),
            stop: None,
        }
    }
}

/// Most connections served at once; more wait in the listening socket's backlog until one
/// finishes (within [`REQUEST_DEADLINE`] plus the time to send its answer).
pub const MAX_CONNECTIONS: usize = 64;
/// Time a connection has to deliver its whole request (head and body).
pub const REQUEST_DEADLINE: Duration = Duration::from_secs(2);
/// Time to send an answer (the page is a few megabytes; a client that does not read it
/// loses its connection rather than holding a thread).
const WRITE_DEADLINE: Duration = Duration::from_secs(10);

/// Most control periods one poll may advance: a page that stalls (a background tab) does not
/// make the trial jump seconds at once.
const MAX_STEPS_PER_POLL: usize = 10;

/// Where the served page keeps the session token (for scripts and tests).
const TOKEN_META: &str = "<meta name=\"verti-token\" content=\"";

/// The token in a page served by [`serve`].
pub fn token_in_page(html: &str) -> Option<&str> {
    let start = html.find(TOKEN_META)? + TOKEN_META.len();
    let len = html[start..].find('"')?;
    Some(&html[start..start + len])
}

/// Adds the session token to the viewer page, where its live mode (in `verti-view`) reads it
/// and sends it, by `POST`, with every request to this server.
fn with_token(html: &str, token: &str) -> String {
    let meta = format!("{TOKEN_META}{token}\">\n");
    // at the end of the head (a page without one: at the start)
    let at = html.find("</head>").unwrap_or(0);
    let mut out = String::with_capacity(html.len() + meta.len());
    out.push_str(&html[..at]);
    out.push_str(&meta);
    out.push_str(&html[at..]);
    out
}

/// The session and its clock, behind the lock.
struct Live {
    session: DriveSession,
    /// Wall-clock start of simulated time: the page's first poll.
    clock: Option<Instant>,
}

/// What the connection threads share.
struct Shared {
    live: Mutex<Live>,
    access: Access,
    opts: ServeOptions,
    /// Raised when the session is over: `/quit`, the trial's end seen by the page, a failure.
    done: AtomicBool,
    /// When a request last passed the access checks (the idle limit counts from it).
    last_request: Mutex<Instant>,
    in_flight: AtomicUsize,
}

impl Shared {
    fn over(&self) -> bool {
        self.done.load(Ordering::SeqCst) || self.opts.stop.is_some_and(|s| s.load(Ordering::SeqCst))
    }

    fn live(&self) -> MutexGuard<'_, Live> {
        // a poisoned lock means a step panicked; what was recorded is still worth saving
        self.live.lock().unwrap_or_else(PoisonError::into_inner)
    }

    fn touch(&self) {
        *self
            .last_request
            .lock()
            .unwrap_or_else(PoisonError::into_inner) = Instant::now();
    }

    fn idle_for(&self) -> Duration {
        self.last_request
            .lock()
            .unwrap_or_else(PoisonError::into_inner)
            .elapsed()
    }
}

/// Holds one of the [`MAX_CONNECTIONS`] places; gives it back when dropped (also when the
/// thread it went to could not start).
struct Slot<'a>(&'a AtomicUsize);

impl Drop for Slot<'_> {
    fn drop(&mut self) {
        self.0.fetch_sub(1, Ordering::SeqCst);
    }
}

/// Serves `session` on `listener` (which must be on a loopback address) until the trial has
/// ended and the page has seen the end (or the page stops asking for `opts.idle`, or asks
/// `/quit`, or `opts.stop` is raised); returns what was recorded.
pub fn serve(
    session: DriveSession,
    listener: &TcpListener,
    opts: ServeOptions,
) -> Result<SessionEnd, String> {
    let addr = listener
        .local_addr()
        .map_err(|e| format!("the live view's socket has no address: {e}"))?;
    let access = Access::new(addr, new_token())?;
    listener
        .set_nonblocking(true)
        .map_err(|e| format!("cannot poll the listening socket: {e}"))?;
    let shared = Shared {
        live: Mutex::new(Live {
            session,
            clock: None,
        }),
        access,
        opts,
        done: AtomicBool::new(false),
        last_request: Mutex::new(Instant::now()),
        in_flight: AtomicUsize::new(0),
    };
    std::thread::scope(|scope| {
        while !shared.over() && shared.idle_for() <= opts.idle {
            if shared.in_flight.load(Ordering::SeqCst) >= MAX_CONNECTIONS {
                std::thread::sleep(Duration::from_millis(5));
                continue;
            }
            match listener.accept() {
                Ok((stream, _)) => {
                    shared.in_flight.fetch_add(1, Ordering::SeqCst);
                    let slot = Slot(&shared.in_flight);
                    let sh = &shared;
                    // a thread that cannot start drops its closure: the slot and the stream
                    let _ = std::thread::Builder::new()
                        .name("verti-live".into())
                        .spawn_scoped(scope, move || {
                            let _slot = slot;
                            // a panic must not reach the scope, which would re-raise it
                            // and lose the drive
                            let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
                                connection(sh, stream)
                            }));
                        });
                }
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                    std::thread::sleep(Duration::from_millis(5));
                }
                // out of file descriptors, a connection reset before accept...: not worth
                // losing the drive over; the idle limit ends a server that stays broken
                Err(_) => std::thread::sleep(Duration::from_millis(50)),
            }
        }
    });
    let live = shared
        .live
        .into_inner()
        .unwrap_or_else(PoisonError::into_inner);
    Ok(live.session.finish())
}

/// Why no request came from a connection.
enum ReadError {
    /// Closed or timed out before sending anything: nobody to answer.
    Quiet,
    /// Started a request but did not finish it in time.
    Timeout,
    Parse(ParseError),
}

/// Reads one request from `stream`, all of it before `deadline`; gives up early (quietly)
/// once `over` says the session has ended, so that idle connections do not delay the save.
fn read_request(
    stream: &mut TcpStream,
    deadline: Instant,
    over: &dyn Fn() -> bool,
) -> Result<Request, ReadError> {
    let mut buf: Vec<u8> = Vec::with_capacity(1024);
    let mut chunk = [0u8; 4096];
    // bytes already searched for the head's end (so a trickle is not rescanned each byte)
    let mut scanned: usize = 0;
    let mut pending: Option<(Request, usize, usize)> = None;
    loop {
        match pending.take() {
            Some((mut req, start, len)) if buf.len() >= start + len => {
                req.body = buf[start..start + len].to_vec();
                return Ok(req);
            }
            Some(waiting) => pending = Some(waiting),
            None => {
                let from = scanned.saturating_sub(3);
                if let Some(n) = head_len(&buf[from..]) {
                    let end = from + n;
                    let (req, len) = parse_head(&buf[..end]).map_err(ReadError::Parse)?;
                    pending = Some((req, end, len));
                    continue;
                }
                scanned = buf.len();
                if buf.len() > crate::http::MAX_HEAD {
                    return Err(ReadError::Parse(ParseError::HeadTooLarge));
                }
            }
        }
        let left = deadline.saturating_duration_since(Instant::now());
        let timed_out = || {
            if buf.is_empty() {
                ReadError::Quiet
            } else {
                ReadError::Timeout
            }
        };
        if over() {
            return Err(ReadError::Quiet);
        }
        // short waits, to look at `over` between them
        let wait = left.min(Duration::from_millis(100));
        if left.is_zero() || stream.set_read_timeout(Some(wait)).is_err() {
            return Err(timed_out());
        }
        match stream.read(&mut chunk) {
            Ok(0) => return Err(ReadError::Quiet),
            Ok(n) => buf.extend_from_slice(&chunk[..n]),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            // a wait ran out: the deadline is checked above
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) => {}
            Err(_) => return Err(ReadError::Quiet),
        }
    }
}

/// An answer, built under the lock and sent after it is released.
struct Reply {
    status: &'static str,
    kind: &'static str,
    body: Vec<u8>,
    headers: Vec<(&'static str, String)>,
    /// `HEAD`: the headers only.
    head_only: bool,
}

impl Reply {
    fn text(status: &'static str, body: impl Into<String>) -> Reply {
        Reply {
            status,
            kind: "text/plain; charset=utf-8",
            body: body.into().into_bytes(),
            headers: Vec::new(),
            head_only: false,
        }
    }

    fn send(&self, stream: &mut TcpStream) {
        let mut head = format!(
            "HTTP/1.1 {}\r\nContent-Type: {}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nX-Content-Type-Options: nosniff\r\nConnection: close\r\n",
            self.status,
            self.kind,
            self.body.len()
        );
        for (name, value) in &self.headers {
            head.push_str(&format!("{name}: {value}\r\n"));
        }
        head.push_str("\r\n");
        let deadline = Instant::now() + WRITE_DEADLINE;
        if write_by(stream, head.as_bytes(), deadline) && !self.head_only {
            write_by(stream, &self.body, deadline);
        }
    }
}

/// Writes all of `bytes` before `deadline`; false if it could not.
fn write_by(stream: &mut TcpStream, mut bytes: &[u8], deadline: Instant) -> bool {
    while !bytes.is_empty() {
        let left = deadline.saturating_duration_since(Instant::now());
        if left.is_zero() || stream.set_write_timeout(Some(left)).is_err() {
            return false;
        }
        match stream.write(&bytes[..bytes.len().min(64 * 1024)]) {
            Ok(0) => return false,
            Ok(n) => bytes = &bytes[n..],
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(_) => return false,
        }
    }
    true
}

/// Closes after an early answer without losing it: closing a socket with unread bytes (the
/// rest of a refused request) sends a reset, which can discard the answer at the client.
/// So: end our side, then read and drop what still comes, briefly and boundedly.
fn linger(stream: &mut TcpStream) {
    let _ = stream.shutdown(std::net::Shutdown::Write);
    let until = Instant::now() + Duration::from_millis(500);
    let mut sink = [0u8; 4096];
    for _ in 0..64 {
        let left = until.saturating_duration_since(Instant::now());
        if left.is_zero() || stream.set_read_timeout(Some(left)).is_err() {
            return;
        }
        match stream.read(&mut sink) {
            Ok(0) | Err(_) => return,
            Ok(_) => {}
        }
    }
}

/// Serves one connection: one request, one answer.
fn connection(sh: &Shared, mut stream: TcpStream) {
    // accepted sockets may inherit the listener's non-blocking mode on some systems
    if stream.set_nonblocking(false).is_err() {
        return;
    }
    let req = match read_request(&mut stream, Instant::now() + REQUEST_DEADLINE, &|| {
        sh.over()
    }) {
        Ok(r) => r,
        Err(ReadError::Quiet) => return,
        Err(ReadError::Timeout) => {
            Reply::text("408 Request Timeout", "the request took too long").send(&mut stream);
            return;
        }
        Err(ReadError::Parse(e)) => {
            Reply::text(e.status(), e.reason()).send(&mut stream);
            linger(&mut stream);
            return;
        }
    };
    let reply = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| answer(sh, &req)))
        .unwrap_or_else(|_| {
            // a step failed: stop here and save what was driven up to it
            sh.done.store(true, Ordering::SeqCst);
            Reply::text(
                "500 Internal Server Error",
                "the session failed; it is saved as it stands",
            )
        });
    reply.send(&mut stream);
}

/// The answer to a request that arrived whole.
fn answer(sh: &Shared, req: &Request) -> Reply {
    if let Err((status, why)) = sh.access.check_origin(req) {
        return Reply::text(status, why);
    }
    let allowed = match req.path.as_str() {
        "/" => "GET, HEAD",
        "/step" | "/quit" => "POST",
        _ => return Reply::text("404 Not Found", "not found"),
    };
    if !allowed.split(", ").any(|m| m == req.method) {
        let mut r = Reply::text(
            "405 Method Not Allowed",
            format!("{} takes {allowed}", req.path),
        );
        r.headers.push(("Allow", allowed.to_string()));
        return r;
    }
    if req.path != "/"
        && let Err((status, why)) = sh.access.check_token(req)
    {
        return Reply::text(status, why);
    }
    sh.touch();
    match req.path.as_str() {
        "/" => page(sh, req.method == "HEAD"),
        "/step" => step(sh, req),
        _ => {
            sh.done.store(true, Ordering::SeqCst);
            Reply::text("200 OK", "stopped")
        }
    }
}

/// The viewer in live mode, with the token.
fn page(sh: &Shared, head_only: bool) -> Reply {
    let mut page = sh.live().session.recording().clone();
    page.live = true;
    page.frames.truncate(1);
    Reply {
        status: "200 OK",
        kind: "text/html; charset=utf-8",
        body: with_token(&verti_view::html(&page), sh.access.token()).into_bytes(),
        // no framing by other pages (clicks and keys lured into a hidden frame)
        headers: vec![
            ("X-Frame-Options", "DENY".to_string()),
            (
                "Content-Security-Policy",
                "frame-ancestors 'none'".to_string(),
            ),
            ("Referrer-Policy", "no-referrer".to_string()),
        ],
        head_only,
    }
}

/// Advances the trial to the wall clock holding the keys sent, and answers with the frames
/// since `since`.
fn step(sh: &Shared, req: &Request) -> Reply {
    let keys = match Keys::parse(&req.param("keys").unwrap_or_default()) {
        Ok(k) => k,
        Err(e) => return Reply::text("400 Bad Request", e),
    };
    let since: usize = req.param("since").and_then(|s| s.parse().ok()).unwrap_or(0);
    let mut live = sh.live();
    // once stopped (`/quit`, a signal) the trial stays as it is saved
    if !sh.over() {
        // the simulated clock starts with the page's first poll
        let started = *live.clock.get_or_insert_with(Instant::now);
        let due = started.elapsed().as_secs_f64() * sh.opts.speed;
        let session = &mut live.session;
        let mut steps = 0;
        while session.ended().is_none()
            && session.time() + session.period() <= due + 1e-9
            && steps < MAX_STEPS_PER_POLL
        {
            session.step(keys);
            steps += 1;
        }
    }
    let session = &live.session;
    let frames = session.frames();
    let body = serde_json::json!({
        "frames": &frames[since.min(frames.len())..],
        "time": session.time(),
        "ended": session.ended().map(|o| o.name()),
    });
    if session.ended().is_some() {
        // the page has seen the end: the session is over once this answer is sent
        sh.done.store(true, Ordering::SeqCst);
    }
    Reply {
        status: "200 OK",
        kind: "application/json",
        body: body.to_string().into_bytes(),
        headers: Vec::new(),
        head_only: false,
    }
}

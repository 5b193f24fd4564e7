//! The live view's local web server: the page (the 3-D viewer in live mode) polls `/step`
//! with the keys it holds; each poll advances the trial to the wall clock (real time), one
//! control period at a time, and answers with the frames made since the page's last one.
//! Standard library only: one connection at a time is plenty for one browser tab on
//! localhost.

use crate::driver::Keys;
use crate::session::{DriveSession, SessionEnd};
use std::io::{Read, Write};
use std::net::{TcpListener, TcpStream};
use std::time::{Duration, Instant};

/// How the server paces and ends a session.
#[derive(Clone, Copy, Debug)]
pub struct ServeOptions {
    /// Simulated seconds per wall-clock second (1 = real time).
    pub speed: f64,
    /// End the session when the page has not asked for this long (a closed tab).
    pub idle: Duration,
    /// Raised (e.g. by a Ctrl-C handler) to end the session: it is saved as it stands.
    pub stop: Option<&'static std::sync::atomic::AtomicBool>,
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

/// Most control periods one poll may advance: a page that stalls (a background tab) does not
/// make the trial jump seconds at once.
const MAX_STEPS_PER_POLL: usize = 10;

struct Request {
    path: String,
    query: Vec<(String, String)>,
}

fn read_request(stream: &mut TcpStream) -> Option<Request> {
    stream.set_read_timeout(Some(Duration::from_secs(2))).ok()?;
    let mut buf = Vec::new();
    let mut chunk = [0u8; 1024];
    while !buf.windows(4).any(|w| w == b"\r\n\r\n") && buf.len() < 16 * 1024 {
        let n = stream.read(&mut chunk).ok()?;
        if n == 0 {
            break;
        }
        buf.extend_from_slice(&chunk[..n]);
    }
    let text = String::from_utf8_lossy(&buf);
    let target = text.lines().next()?.split_whitespace().nth(1)?.to_string();
    let (path, q) = target.split_once('?').unwrap_or((&target, ""));
    let query = q
        .split('&')
        .filter_map(|kv| kv.split_once('='))
        .map(|(k, v)| (k.to_string(), v.replace("%2C", ",").replace("%2c", ",")))
        .collect();
    Some(Request {
        path: path.to_string(),
        query,
    })
}

fn respond(stream: &mut TcpStream, status: &str, kind: &str, body: &[u8]) {
    let head = format!(
        "HTTP/1.1 {status}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\n\r\n",
        body.len()
    );
    let _ = stream.write_all(head.as_bytes());
    let _ = stream.write_all(body);
}

/// Serves `session` on `listener` until the trial has ended and the page has seen the end
/// (or the page stops asking for `opts.idle`, or asks `/quit`); returns what was recorded.
pub fn serve(
    mut session: DriveSession,
    listener: &TcpListener,
    opts: ServeOptions,
) -> Result<SessionEnd, String> {
    listener
        .set_nonblocking(true)
        .map_err(|e| format!("cannot poll the listening socket: {e}"))?;
    let mut clock: Option<Instant> = None;
    let mut last_request = Instant::now();
    let mut end_seen = false;
    loop {
        if opts
            .stop
            .is_some_and(|s| s.load(std::sync::atomic::Ordering::SeqCst))
        {
            break;
        }
        let (mut stream, _) = match listener.accept() {
            Ok(s) => s,
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                if last_request.elapsed() > opts.idle || end_seen {
                    break;
                }
                std::thread::sleep(Duration::from_millis(5));
                continue;
            }
            Err(e) => return Err(format!("the live view's server failed: {e}")),
        };
        let _ = stream.set_nonblocking(false);
        last_request = Instant::now();
        let Some(req) = read_request(&mut stream) else {
            continue;
        };
        let get = |k: &str| {
            req.query
                .iter()
                .find(|(q, _)| q == k)
                .map(|(_, v)| v.as_str())
        };
        match req.path.as_str() {
            "/" => {
                let mut page = session.recording().clone();
                page.live = true;
                page.frames.truncate(1);
                respond(
                    &mut stream,
                    "200 OK",
                    "text/html; charset=utf-8",
                    verti_view::html(&page).as_bytes(),
                );
            }
            "/step" => {
                let keys = match Keys::parse(get("keys").unwrap_or("")) {
                    Ok(k) => k,
                    Err(e) => {
                        respond(&mut stream, "400 Bad Request", "text/plain", e.as_bytes());
                        continue;
                    }
                };
                // the simulated clock starts with the page's first poll
                let started = *clock.get_or_insert_with(Instant::now);
                let due = started.elapsed().as_secs_f64() * opts.speed;
                let mut steps = 0;
                while session.ended().is_none()
                    && session.time() + session.period() <= due + 1e-9
                    && steps < MAX_STEPS_PER_POLL
                {
                    session.step(keys);
                    steps += 1;
                }
                let since: usize = get("since").and_then(|s| s.parse().ok()).unwrap_or(0);
                let frames = session.frames();
                let body = serde_json::json!({
                    "frames": &frames[since.min(frames.len())..],
                    "time": session.time(),
                    "ended": session.ended().map(|o| o.name()),
                });
                respond(
                    &mut stream,
                    "200 OK",
                    "application/json",
                    body.to_string().as_bytes(),
                );
                end_seen = session.ended().is_some();
            }
            "/quit" => {
                respond(&mut stream, "200 OK", "text/plain", b"stopped");
                break;
            }
            _ => respond(&mut stream, "404 Not Found", "text/plain", b"not found"),
        }
    }
    Ok(session.finish())
}

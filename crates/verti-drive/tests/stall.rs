//! The live server cannot be stalled (issue 6): connections that send nothing, or trickle a
//! request a byte a second, neither delay the page's polls (connections are served
//! concurrently) nor stay open past the request deadline; more connections than the server
//! serves at once wait their turn and are then served.

mod common;

use common::Server;
use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};
use verti_drive::server::{MAX_CONNECTIONS, REQUEST_DEADLINE};

/// Opens `n` connections that send nothing.
fn idle_connections(s: &Server, n: usize) -> Vec<TcpStream> {
    (0..n)
        .map(|_| {
            let c = TcpStream::connect(s.addr).unwrap();
            c.set_read_timeout(Some(Duration::from_secs(6))).unwrap();
            c
        })
        .collect()
}

/// Sends the start of a request one byte a second, for at most `seconds` bytes.
fn trickle(s: &Server, seconds: usize) -> std::thread::JoinHandle<()> {
    let mut c = TcpStream::connect(s.addr).unwrap();
    std::thread::spawn(move || {
        for b in b"POST /step HTTP/1.1\r\n".iter().take(seconds) {
            if c.write_all(&[*b]).is_err() {
                return;
            }
            std::thread::sleep(Duration::from_secs(1));
        }
    })
}

#[test]
fn idle_and_trickling_connections_do_not_hold_up_a_step() {
    let s = Server::start(1.0, Duration::from_secs(30));
    let mut idle = idle_connections(&s, 30);
    let trickler = trickle(&s, 4);
    // let the server take them all in
    std::thread::sleep(Duration::from_millis(200));
    let t0 = Instant::now();
    let r = s.post("/step?keys=u");
    let took = t0.elapsed();
    assert_eq!(r.status, 200, "{}", r.body);
    assert!(took < Duration::from_secs(3), "a step took {took:?}");
    // the idle ones are closed once the request deadline passes, quietly
    let t0 = Instant::now();
    for c in &mut idle {
        let mut buf = [0u8; 64];
        let n = c
            .read(&mut buf)
            .expect("closed by the server, not left open");
        assert_eq!(n, 0);
    }
    assert!(
        t0.elapsed() < REQUEST_DEADLINE + Duration::from_secs(2),
        "{:?}",
        t0.elapsed()
    );
    trickler.join().unwrap();
    s.quit();
}

#[test]
fn more_connections_than_the_cap_wait_their_turn() {
    let s = Server::start(1.0, Duration::from_secs(30));
    let _idle = idle_connections(&s, MAX_CONNECTIONS + 8);
    std::thread::sleep(Duration::from_millis(200));
    let t0 = Instant::now();
    let r = s.post("/step?keys=u");
    let took = t0.elapsed();
    assert_eq!(r.status, 200, "{}", r.body);
    // at worst it waits for the first idle ones' deadline
    assert!(
        took < REQUEST_DEADLINE + Duration::from_secs(2),
        "a step took {took:?}"
    );
    s.quit();
}

#[test]
fn a_request_that_is_not_finished_in_time_gets_408_and_a_huge_head_431() {
    let s = Server::start(1.0, Duration::from_secs(30));
    let mut c = TcpStream::connect(s.addr).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(6))).unwrap();
    c.write_all(b"POST /step HTTP/1.1\r\nHost: ").unwrap();
    let t0 = Instant::now();
    let r = common::read_reply(&mut c);
    assert_eq!(r.status, 408, "{}", r.head);
    assert!(t0.elapsed() < REQUEST_DEADLINE + Duration::from_secs(1));
    let mut c = TcpStream::connect(s.addr).unwrap();
    c.set_read_timeout(Some(Duration::from_secs(6))).unwrap();
    let head = format!("GET / HTTP/1.1\r\nX-Pad: {}\r\n", "a".repeat(20_000));
    // the server may close before taking it all
    let _ = c.write_all(head.as_bytes());
    assert_eq!(common::read_reply(&mut c).status, 431);
    s.quit();
}

#[test]
fn idle_connections_do_not_delay_the_end_of_the_session() {
    let s = Server::start(1.0, Duration::from_secs(30));
    let _idle = idle_connections(&s, 10);
    std::thread::sleep(Duration::from_millis(200));
    let t0 = Instant::now();
    s.quit();
    // the session is handed back without waiting out the idle ones' deadline
    assert!(t0.elapsed() < Duration::from_secs(1), "{:?}", t0.elapsed());
}

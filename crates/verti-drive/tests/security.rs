//! The live server serves only its own page (issue 5): requests naming another host (DNS
//! rebinding), sent by another origin or started by another site are refused (403), the
//! session's state changes only by `POST` (a `GET` that steers or stops is 405) with the
//! session's token (403 without it), and the right request still works after all of those.

mod common;

use common::{Server, exchange};
use std::time::Duration;

/// `method path` with `headers` (each ending in CRLF).
fn send(s: &Server, method: &str, path: &str, headers: &str) -> common::Reply {
    exchange(
        s.addr,
        &format!("{method} {path} HTTP/1.1\r\n{headers}Content-Length: 0\r\n\r\n"),
    )
}

#[test]
fn the_page_carries_a_fresh_token_and_refuses_framing() {
    let s = Server::start(1.0, Duration::from_secs(20));
    assert_eq!(s.token.len(), 32);
    assert!(
        s.token.bytes().all(|c| c.is_ascii_hexdigit()),
        "{}",
        s.token
    );
    let page = send(&s, "GET", "/", &format!("Host: {}\r\n", s.host));
    assert_eq!(page.status, 200);
    assert!(page.body.contains("\"live\":true") && page.body.contains("<canvas"));
    // the request shim: every request to the server is a POST with the token
    assert!(page.body.contains("X-Verti-Token") && page.body.contains("method: \"POST\""));
    assert!(page.head.contains("X-Frame-Options: DENY"), "{}", page.head);
    assert!(
        page.head.contains("frame-ancestors 'none'"),
        "{}",
        page.head
    );
    // `localhost` names it too
    let port = s.addr.port();
    let local = send(&s, "GET", "/", &format!("Host: localhost:{port}\r\n"));
    assert_eq!(local.status, 200);
    // a second session has another token
    let other = Server::start(1.0, Duration::from_secs(20));
    assert_ne!(other.token, s.token);
    other.quit();
    s.quit();
}

#[test]
fn other_hosts_origins_and_sites_are_refused() {
    let s = Server::start(1.0, Duration::from_secs(20));
    let port = s.addr.port();
    let token = format!("X-Verti-Token: {}\r\n", s.token);
    let cases = [
        // DNS rebinding: the attacker's name in Host, even with the right port and token
        ("GET", "/", format!("Host: evil.example:{port}\r\n")),
        (
            "POST",
            "/step",
            format!("Host: evil.example:{port}\r\n{token}"),
        ),
        (
            "POST",
            "/step",
            format!("Host: 127.0.0.1:{}\r\n{token}", port + 1),
        ),
        ("POST", "/step", token.clone()),
        // a page elsewhere sending to the right address
        (
            "POST",
            "/step",
            format!("Host: {}\r\nOrigin: http://evil.example\r\n{token}", s.host),
        ),
        (
            "POST",
            "/quit",
            format!("Host: {}\r\nOrigin: null\r\n{token}", s.host),
        ),
        // another site opening the page (`#keys=` would drive it)
        (
            "GET",
            "/",
            format!("Host: {}\r\nSec-Fetch-Site: cross-site\r\n", s.host),
        ),
    ];
    for (method, path, headers) in &cases {
        let r = send(&s, method, path, headers);
        assert_eq!(r.status, 403, "{method} {path} {headers}: {}", r.body);
    }
    // none of them stepped or stopped the session: the right request works, from the start
    let ok = s.post("/step?keys=u");
    assert_eq!(ok.status, 200, "{}", ok.body);
    let end = s.quit();
    assert!(end.record.rows.len() <= 1, "{}", end.record.rows.len());
}

#[test]
fn state_changes_need_post_and_the_token() {
    let s = Server::start(20.0, Duration::from_secs(20));
    let host = format!("Host: {}\r\n", s.host);
    let token = format!("X-Verti-Token: {}\r\n", s.token);
    // a GET (an <img>, a link) never steers or stops, even with the token
    for path in ["/step?keys=u", "/quit"] {
        let r = send(&s, "GET", path, &format!("{host}{token}"));
        assert_eq!(r.status, 405, "GET {path}: {}", r.body);
        assert!(r.head.contains("Allow: POST"), "{}", r.head);
    }
    assert_eq!(send(&s, "DELETE", "/", &host).status, 405);
    // no token, a wrong one of the right length, a prefix of the right one
    let mut wrong = s.token.clone().into_bytes();
    wrong[0] = if wrong[0] == b'0' { b'1' } else { b'0' };
    let wrong = String::from_utf8(wrong).unwrap();
    for bad in [
        String::new(),
        format!("X-Verti-Token: {wrong}\r\n"),
        format!("X-Verti-Token: {}\r\n", &s.token[..16]),
    ] {
        for path in ["/step?keys=u", "/quit"] {
            let r = send(&s, "POST", path, &format!("{host}{bad}"));
            assert_eq!(r.status, 403, "POST {path} {bad}: {}", r.body);
            assert!(r.body.contains("token"), "{}", r.body);
        }
    }
    // still running, and driven by the right requests alone (the first starts the clock)
    assert_eq!(s.post("/step?keys=u").status, 200);
    std::thread::sleep(Duration::from_millis(100));
    let ok = s.post("/step?keys=u&since=1");
    assert_eq!(ok.status, 200, "{}", ok.body);
    let j: serde_json::Value = serde_json::from_str(&ok.body).unwrap();
    assert!(!j["frames"].as_array().unwrap().is_empty(), "{j}");
    assert!(j["ended"].is_null());
    let end = s.quit();
    assert!(!end.record.rows.is_empty());
}

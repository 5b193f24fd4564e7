//! Bounded, seeded property tests of the live server's request parser: real requests of the
//! page (and of attackers) are mutated (bytes flipped, inserted, deleted, lines repeated, the
//! request cut short) or replaced by arbitrary bytes, and parsed; the parser must return `Ok`
//! or `Err`, never panic, and what it accepts must keep its invariants. A last property sends
//! mutated requests to a running server, which must answer or close and keep serving. Case
//! counts are capped and the seed fixed, so the file runs in seconds and the same each time;
//! a failing case is shrunk and printed by proptest.

mod common;

use proptest::prelude::*;
use proptest::test_runner::RngSeed;
use std::io::Write;
use std::sync::OnceLock;
use std::time::Duration;
use verti_drive::Keys;
use verti_drive::access::Access;
use verti_drive::http::{MAX_BODY, ParseError, head_len, parse_head, parse_request};
use verti_testkit::mutate;

/// Requests as the page, a browser and an attacker send them.
const SEEDS: [&str; 6] = [
    "GET / HTTP/1.1\r\nHost: 127.0.0.1:8765\r\nUser-Agent: Mozilla/5.0\r\nAccept: text/html\r\nSec-Fetch-Site: none\r\n\r\n",
    "POST /step?keys=ul%2C0.50%2C-0.25&since=12 HTTP/1.1\r\nHost: 127.0.0.1:8765\r\nOrigin: http://127.0.0.1:8765\r\nX-Verti-Token: 00112233445566778899aabbccddeeff\r\nContent-Length: 0\r\n\r\n",
    "POST /step HTTP/1.1\r\nHost: localhost:8765\r\nX-Verti-Token: 00112233445566778899aabbccddeeff\r\nContent-Type: application/x-www-form-urlencoded\r\nContent-Length: 16\r\n\r\nkeys=ub&since=40",
    "POST /quit HTTP/1.0\r\nHost: [::1]:8765\r\nX-Verti-Token: ffeeddccbbaa99887766554433221100\r\nContent-Length: 0\r\n\r\n",
    "GET /step?keys=u HTTP/1.1\r\nHost: evil.example:8765\r\nOrigin: http://evil.example\r\nSec-Fetch-Site: cross-site\r\n\r\n",
    "POST /step HTTP/1.1\r\nHost: 127.0.0.1:8765\r\nContent-Length: 5\r\nContent-Length: 5\r\nTransfer-Encoding: chunked\r\n\r\n0\r\n\r\n",
];

/// An edit of a request: one of the shared byte edits, or a line repeated.
#[derive(Clone, Debug)]
enum Edit {
    Bytes(mutate::Edit),
    /// Repeat the line containing this position (duplicate headers, request lines).
    RepeatLine(usize),
}

fn edit_strategy() -> impl Strategy<Value = Edit> {
    use mutate::Edit::{Delete, Insert, Truncate};
    // HTTP's own syntax characters, so edits reach past the first check
    let http = prop::sample::select(b"\r\n :/?&=%+,-0123456789aAfFzZ.\t\xff\x00".to_vec());
    prop_oneof![
        mutate::flip_edit().prop_map(Edit::Bytes),
        (any::<usize>(), prop::collection::vec(http, 1..12))
            .prop_map(|(p, b)| Edit::Bytes(Insert(p, b))),
        (any::<usize>(), prop::collection::vec(any::<u8>(), 1..8))
            .prop_map(|(p, b)| Edit::Bytes(Insert(p, b))),
        (any::<usize>(), 1usize..32).prop_map(|(p, n)| Edit::Bytes(Delete(p, n))),
        any::<usize>().prop_map(|p| Edit::Bytes(Truncate(p))),
        any::<usize>().prop_map(Edit::RepeatLine),
    ]
}

fn apply(bytes: &mut Vec<u8>, edit: &Edit) {
    match edit {
        Edit::Bytes(e) => mutate::apply(bytes, e),
        Edit::RepeatLine(p) => {
            if !bytes.is_empty() {
                let i = p % bytes.len();
                let start = bytes[..i]
                    .iter()
                    .rposition(|&b| b == b'\n')
                    .map_or(0, |k| k + 1);
                let end = bytes[i..]
                    .iter()
                    .position(|&b| b == b'\n')
                    .map_or(bytes.len(), |k| i + k + 1);
                let line = bytes[start..end].to_vec();
                bytes.splice(start..start, line);
            }
        }
    }
}

fn mutated(seed: usize, edits: &[Edit]) -> Vec<u8> {
    let mut bytes = SEEDS[seed % SEEDS.len()].as_bytes().to_vec();
    for e in edits {
        apply(&mut bytes, e);
    }
    bytes
}

/// Parses `bytes` and everything the server does with a parsed request (the access checks,
/// the keys and `since` of a step); checks what was accepted.
fn parse_and_use(bytes: &[u8]) {
    let parsed = parse_request(bytes);
    if let Ok(req) = &parsed {
        assert!(!req.method.is_empty() && req.method.bytes().all(|b| b.is_ascii_uppercase()));
        assert!(req.body.len() <= MAX_BODY);
        assert!(
            req.headers
                .iter()
                .all(|(n, _)| !n.is_empty() && *n == n.to_ascii_lowercase())
        );
        let access = Access::new(
            "127.0.0.1:8765".parse().unwrap(),
            "00112233445566778899aabbccddeeff".into(),
        )
        .unwrap();
        let _ = access.check_origin(req);
        let _ = access.check_token(req);
        let _ = Keys::parse(&req.param("keys").unwrap_or_default());
        let _ = req.param("since").map(|s| s.parse::<usize>());
    }
    // parsing the head alone agrees with parsing the whole
    if let Some(end) = head_len(bytes) {
        match (parse_head(&bytes[..end]), &parsed) {
            (Ok((head, len)), Ok(req)) => {
                assert_eq!(
                    (head.path.as_str(), len),
                    (req.path.as_str(), req.body.len())
                );
            }
            (Ok(_), Err(e)) => assert_eq!(*e, ParseError::Incomplete),
            (Err(a), Err(b)) => assert_eq!(&a, b),
            (Err(a), Ok(_)) => panic!("the head fails ({a:?}) but the request parses"),
        }
        // a request cut before its head ends is never taken for a whole one
        for cut in [0, end / 3, end / 2, end - 1] {
            assert!(
                parse_request(&bytes[..cut]).is_err(),
                "a request cut at {cut} of {end} parsed"
            );
        }
    }
}

fn config(cases: u32, seed: u64) -> ProptestConfig {
    ProptestConfig {
        cases,
        rng_seed: RngSeed::Fixed(seed),
        ..ProptestConfig::default()
    }
}

proptest! {
    #![proptest_config(config(512, 0x7665_7274_6901))]

    #[test]
    fn mutated_requests_never_panic_the_parser(
        seed in 0usize..SEEDS.len(),
        edits in prop::collection::vec(edit_strategy(), 1..6),
    ) {
        parse_and_use(&mutated(seed, &edits));
    }

    #[test]
    fn arbitrary_bytes_never_panic_the_parser(
        bytes in prop::collection::vec(any::<u8>(), 0..600),
        with_end in any::<bool>(),
    ) {
        let mut bytes = bytes;
        if with_end {
            // most random strings never end a head: give half of them an end
            bytes.extend_from_slice(b"\r\n\r\n");
        }
        parse_and_use(&bytes);
    }
}

/// One server for all cases of the socket property.
fn server() -> &'static common::Server {
    static SERVER: OnceLock<common::Server> = OnceLock::new();
    SERVER.get_or_init(|| common::Server::start(1.0, Duration::from_secs(60)))
}

proptest! {
    #![proptest_config(config(48, 0x7665_7274_6902))]

    #[test]
    fn mutated_requests_leave_the_server_serving(
        seed in 0usize..SEEDS.len(),
        edits in prop::collection::vec(edit_strategy(), 1..4),
    ) {
        let s = server();
        // the seeds' tokens are not this session's: nothing here can steer or stop it
        let bytes = mutated(seed, &edits);
        let mut c = std::net::TcpStream::connect(s.addr).unwrap();
        c.set_read_timeout(Some(Duration::from_secs(5))).unwrap();
        let _ = c.write_all(&bytes);
        // a request cut short ends here rather than at the server's deadline
        let _ = c.shutdown(std::net::Shutdown::Write);
        let mut reply = Vec::new();
        let _ = std::io::Read::read_to_end(&mut c, &mut reply);
        let r = s.post("/step?since=1000000");
        prop_assert_eq!(r.status, 200, "{}", r.body);
    }
}

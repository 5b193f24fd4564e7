//! The live server's HTTP/1.1 request parser: a pure function over bytes, so that what a
//! socket delivered can be checked (and fuzzed) without one. It accepts the small subset the
//! live page sends (origin-form targets, `Content-Length` bodies) and refuses the rest
//! rather than guessing: headers that disagree, chunked bodies or oversized parts are errors.

/// Most bytes of a request line plus headers: a browser sends a few hundred.
pub const MAX_HEAD: usize = 16 * 1024;
/// Most bytes of a body: the live page's requests carry a few keys at most.
pub const MAX_BODY: usize = 4 * 1024;
/// Most header lines.
const MAX_HEADERS: usize = 64;

/// One parsed request. Header names are lower-cased; values are trimmed.
#[derive(Clone, Debug, PartialEq)]
pub struct Request {
    pub method: String,
    /// The decoded path, without the query.
    pub path: String,
    /// The query's `name=value` pairs, percent-decoded, in order.
    pub query: Vec<(String, String)>,
    pub headers: Vec<(String, String)>,
    pub body: Vec<u8>,
}

/// Why bytes are not (yet) a request.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ParseError {
    /// More bytes are needed: the head has not ended, or the body is shorter than announced.
    Incomplete,
    /// The head is over [`MAX_HEAD`] or has too many header lines (431).
    HeadTooLarge,
    /// The announced body is over [`MAX_BODY`] (413).
    BodyTooLarge,
    /// A transfer coding (chunked bodies) was used: not needed by the page (501).
    Unsupported(&'static str),
    /// Not a well-formed request (400); the reason.
    Malformed(&'static str),
}

impl ParseError {
    /// The HTTP status answering this error.
    pub fn status(&self) -> &'static str {
        match self {
            ParseError::Incomplete | ParseError::Malformed(_) => "400 Bad Request",
            ParseError::HeadTooLarge => "431 Request Header Fields Too Large",
            ParseError::BodyTooLarge => "413 Content Too Large",
            ParseError::Unsupported(_) => "501 Not Implemented",
        }
    }

    /// A short reason for the response body.
    pub fn reason(&self) -> &'static str {
        match self {
            ParseError::Incomplete => "incomplete request",
            ParseError::HeadTooLarge => "request head too large",
            ParseError::BodyTooLarge => "request body too large",
            ParseError::Unsupported(r) | ParseError::Malformed(r) => r,
        }
    }
}

impl Request {
    /// The value of header `name` (lower case).
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// Parameter `name`: from the query, else from a form-encoded body.
    pub fn param(&self, name: &str) -> Option<String> {
        if let Some((_, v)) = self.query.iter().find(|(k, _)| k == name) {
            return Some(v.clone());
        }
        let body = std::str::from_utf8(&self.body).ok()?;
        form_pairs(body)
            .into_iter()
            .find(|(k, _)| k == name)
            .map(|(_, v)| v)
    }
}

/// Length of the head (request line and headers, with the blank line ending them), once
/// `buf` holds all of it.
pub fn head_len(buf: &[u8]) -> Option<usize> {
    buf.windows(4).position(|w| w == b"\r\n\r\n").map(|p| p + 4)
}

/// Parses one request from the start of `bytes` (bytes past its body are ignored: the server
/// answers one request per connection).
pub fn parse_request(bytes: &[u8]) -> Result<Request, ParseError> {
    let Some(end) = head_len(bytes) else {
        return Err(if bytes.len() > MAX_HEAD {
            ParseError::HeadTooLarge
        } else {
            ParseError::Incomplete
        });
    };
    let (mut req, length) = parse_head(&bytes[..end])?;
    req.body = bytes
        .get(end..end + length)
        .ok_or(ParseError::Incomplete)?
        .to_vec();
    Ok(req)
}

/// Parses a request's head (`head` ends with the blank line, as [`head_len`] measures it):
/// the request without its body, and the body's length.
pub fn parse_head(head: &[u8]) -> Result<(Request, usize), ParseError> {
    if head.len() > MAX_HEAD {
        return Err(ParseError::HeadTooLarge);
    }
    let head = head
        .strip_suffix(b"\r\n\r\n")
        .ok_or(ParseError::Incomplete)?;
    let head = std::str::from_utf8(head)
        .map_err(|_| ParseError::Malformed("the request head is not UTF-8"))?;
    let mut lines = head.split("\r\n");
    let (method, target) = request_line(lines.next().unwrap_or(""))?;
    let mut headers: Vec<(String, String)> = Vec::new();
    for line in lines {
        if headers.len() >= MAX_HEADERS {
            return Err(ParseError::HeadTooLarge);
        }
        headers.push(header_line(line)?);
    }
    // one Host only: two could be read differently by two checks
    if headers.iter().filter(|(n, _)| n == "host").count() > 1 {
        return Err(ParseError::Malformed("more than one Host header"));
    }
    if headers.iter().any(|(n, _)| n == "transfer-encoding") {
        return Err(ParseError::Unsupported(
            "transfer codings are not supported",
        ));
    }
    let mut length: Option<usize> = None;
    for (_, v) in headers.iter().filter(|(n, _)| n == "content-length") {
        if v.is_empty() || !v.bytes().all(|b| b.is_ascii_digit()) {
            return Err(ParseError::Malformed("Content-Length is not a number"));
        }
        // digits only, so a failed parse is an overflow: far too large either way
        let n: usize = v.parse().map_err(|_| ParseError::BodyTooLarge)?;
        if length.is_some_and(|l| l != n) {
            return Err(ParseError::Malformed("Content-Length headers disagree"));
        }
        length = Some(n);
    }
    let length = length.unwrap_or(0);
    if length > MAX_BODY {
        return Err(ParseError::BodyTooLarge);
    }
    let (path, query) = target.split_once('?').unwrap_or((target, ""));
    let req = Request {
        method: method.to_string(),
        path: percent_decode(path),
        query: form_pairs(query),
        headers,
        body: Vec::new(),
    };
    Ok((req, length))
}

/// `METHOD SP /target SP HTTP/1.x`.
fn request_line(line: &str) -> Result<(&str, &str), ParseError> {
    let mut parts = line.split(' ');
    let (Some(method), Some(target), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(ParseError::Malformed(
            "the request line is not `METHOD TARGET VERSION`",
        ));
    };
    if method.is_empty() || !method.bytes().all(|b| b.is_ascii_uppercase()) {
        return Err(ParseError::Malformed("bad method"));
    }
    // origin-form only (`/path?query`): the page never sends absolute or authority forms
    if !target.starts_with('/') || !target.bytes().all(|b| b.is_ascii_graphic()) {
        return Err(ParseError::Malformed("bad request target"));
    }
    if version != "HTTP/1.1" && version != "HTTP/1.0" {
        return Err(ParseError::Malformed("unsupported HTTP version"));
    }
    Ok((method, target))
}

/// `Name: value`; obsolete line folding and names outside the token characters are refused.
fn header_line(line: &str) -> Result<(String, String), ParseError> {
    let (name, value) = line
        .split_once(':')
        .ok_or(ParseError::Malformed("a header line has no `:`"))?;
    let token = |b: u8| b.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&b);
    if name.is_empty() || !name.bytes().all(token) {
        return Err(ParseError::Malformed("bad header name"));
    }
    let value = value.trim_matches([' ', '\t']);
    if value.chars().any(|c| c.is_control() && c != '\t') {
        return Err(ParseError::Malformed("control character in a header value"));
    }
    Ok((name.to_ascii_lowercase(), value.to_string()))
}

/// `a=1&b=x%2Cy` to decoded pairs (a name without `=` has an empty value).
fn form_pairs(s: &str) -> Vec<(String, String)> {
    s.split('&')
        .filter(|kv| !kv.is_empty())
        .map(|kv| {
            let (k, v) = kv.split_once('=').unwrap_or((kv, ""));
            (percent_decode(k), percent_decode(v))
        })
        .collect()
}

/// Decodes `%XX` escapes and `+` (a space in forms); bad escapes are kept as written, and
/// bytes that are not UTF-8 become U+FFFD.
fn percent_decode(s: &str) -> String {
    let b = s.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    while i < b.len() {
        let hex = |c: u8| (c as char).to_digit(16);
        match b[i] {
            b'%' => match (
                b.get(i + 1).and_then(|&c| hex(c)),
                b.get(i + 2).and_then(|&c| hex(c)),
            ) {
                (Some(h), Some(l)) => {
                    // two hex digits: at most 255
                    out.push((h * 16 + l) as u8);
                    i += 3;
                }
                _ => {
                    out.push(b'%');
                    i += 1;
                }
            },
            b'+' => {
                out.push(b' ');
                i += 1;
            }
            c => {
                out.push(c);
                i += 1;
            }
        }
    }
    String::from_utf8_lossy(&out).into_owned()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_page_request_parses_with_its_query_headers_and_body() {
        let r = parse_request(
            b"POST /step?keys=ul%2C0.5&since=3 HTTP/1.1\r\nHost: 127.0.0.1:80\r\nX-Verti-Token:  ab \r\nContent-Length: 4\r\n\r\nk=v&extra",
        )
        .unwrap();
        assert_eq!((r.method.as_str(), r.path.as_str()), ("POST", "/step"));
        assert_eq!(r.param("keys").as_deref(), Some("ul,0.5"));
        assert_eq!(r.param("since").as_deref(), Some("3"));
        assert_eq!(r.header("x-verti-token"), Some("ab"));
        assert_eq!(r.body, b"k=v&");
        assert_eq!(r.param("k").as_deref(), Some("v"));
    }

    #[test]
    fn partial_oversized_and_ambiguous_requests_are_refused() {
        assert_eq!(
            parse_request(b"GET / HTTP/1.1\r\n"),
            Err(ParseError::Incomplete)
        );
        let short = b"POST /quit HTTP/1.1\r\nContent-Length: 5\r\n\r\nab";
        assert_eq!(parse_request(short), Err(ParseError::Incomplete));
        let big = format!(
            "POST / HTTP/1.1\r\nContent-Length: {}\r\n\r\n",
            MAX_BODY + 1
        );
        assert_eq!(parse_request(big.as_bytes()), Err(ParseError::BodyTooLarge));
        let huge = "POST / HTTP/1.1\r\nContent-Length: 99999999999999999999999\r\n\r\n";
        assert_eq!(
            parse_request(huge.as_bytes()),
            Err(ParseError::BodyTooLarge)
        );
        assert_eq!(
            parse_request(&vec![b'a'; MAX_HEAD + 1]),
            Err(ParseError::HeadTooLarge)
        );
        for bad in [
            &b"GET / HTTP/1.1\r\nHost: a\r\nHost: b\r\n\r\n"[..],
            b"GET http://evil/ HTTP/1.1\r\n\r\n",
            b"GET / HTTP/2\r\n\r\n",
            b"get / HTTP/1.1\r\n\r\n",
            b"GET / HTTP/1.1\r\n folded\r\n\r\n",
            b"GET / HTTP/1.1\r\nContent-Length: 1\r\nContent-Length: 2\r\n\r\nab",
            b"GET /\xff HTTP/1.1\r\n\r\n",
        ] {
            assert!(
                matches!(parse_request(bad), Err(ParseError::Malformed(_))),
                "{}",
                String::from_utf8_lossy(bad)
            );
        }
        let chunked = b"POST / HTTP/1.1\r\nTransfer-Encoding: chunked\r\n\r\n";
        assert!(matches!(
            parse_request(chunked),
            Err(ParseError::Unsupported(_))
        ));
    }

    #[test]
    fn escapes_decode_and_bad_ones_stay() {
        assert_eq!(percent_decode("a%2cb+c%zz%4"), "a,b c%zz%4");
        assert_eq!(percent_decode("%ff"), "\u{fffd}");
    }
}

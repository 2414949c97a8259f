//! The preview's own HTTP/1.1 request reader and response writer: one request per connection,
//! read within a deadline and a size bound, so that no request (however long, slow, malformed
//! or withheld) can allocate more than a few kilobytes or hold its connection's thread for more
//! than [`REQUEST_TIME`]. The page sends only `GET` and body-less `POST`s; everything else is
//! refused with the status code RFC 9110/9112 give for it.

use std::io::{Read, Write};
use std::net::TcpStream;
use std::time::{Duration, Instant};

/// Longest time a client may take to send a whole request (head and body). The page's requests
/// arrive in one packet; a slow or withheld one is answered 408 and closed.
pub const REQUEST_TIME: Duration = Duration::from_secs(2);

/// Longest time a response may take to be written (a client that does not read is dropped).
pub const WRITE_TIME: Duration = Duration::from_secs(5);

/// Largest request line and headers, in bytes (RFC 9112 §3 suggests at least 8000 for the
/// request line; the page's requests are about 500 bytes).
pub const HEAD_LIMIT: usize = 8192;

/// Largest request body, in bytes: the page sends none (its `POST`s carry their arguments in
/// the query string).
pub const BODY_LIMIT: usize = 64;

/// A request method the preview answers; any other is refused (405) before routing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Method {
    /// `GET`: the page, its status and images.
    Get,
    /// `POST`: pause and save (they change state, so they are checked for their origin).
    Post,
}

/// One parsed request head.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Request {
    /// The method.
    pub method: Method,
    /// The request target, in origin form (`/path?query`).
    pub target: String,
    /// The header fields as sent (names lower-cased), in order.
    pub headers: Vec<(String, String)>,
}

impl Request {
    /// The value of the first header named `name` (lower case), if any.
    pub fn header(&self, name: &str) -> Option<&str> {
        self.headers
            .iter()
            .find(|(n, _)| n == name)
            .map(|(_, v)| v.as_str())
    }

    /// The path part of the target (before `?`).
    pub fn path(&self) -> &str {
        self.target.split('?').next().unwrap_or("")
    }
}

/// Why a request is not answered normally: the status code and a short text for the client.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Refusal {
    /// The HTTP status code (400, 405, 408, 411, 413, 431, 501, 505).
    pub status: u16,
    /// The answer's body.
    pub text: &'static str,
}

const fn refuse(status: u16, text: &'static str) -> Refusal {
    Refusal { status, text }
}

/// Reads one request from `stream` within [`REQUEST_TIME`]: the head (at most [`HEAD_LIMIT`]
/// bytes) and a body of at most [`BODY_LIMIT`] bytes, which is read and dropped. `None` when
/// the client closed the connection before sending anything (nothing to answer).
pub fn read_request(stream: &mut TcpStream) -> Result<Option<Request>, Refusal> {
    let deadline = Instant::now() + REQUEST_TIME;
    let mut buf = [0u8; HEAD_LIMIT + BODY_LIMIT];
    let mut len = 0;
    let (head_end, body_start) = loop {
        if let Some(ends) = head_end(&buf[..len]) {
            break ends;
        }
        if len >= HEAD_LIMIT {
            return Err(refuse(431, "request head too large"));
        }
        match read_some(stream, &mut buf[len..HEAD_LIMIT], deadline)? {
            0 if len == 0 => return Ok(None),
            0 => return Err(refuse(400, "incomplete request")),
            n => len += n,
        }
    };
    let request = parse_head(&buf[..head_end])?;
    let body = body_length(&request)?;
    let mut have = len - body_start;
    while have < body {
        let end = body_start + body;
        match read_some(stream, &mut buf[body_start + have..end], deadline)? {
            0 => return Err(refuse(400, "incomplete body")),
            n => have += n,
        }
    }
    Ok(Some(request))
}

/// One `read` that ends by the deadline: a timeout is a 408, any other error a 400 (the
/// connection is dropped after the answer anyway).
fn read_some(stream: &mut TcpStream, buf: &mut [u8], deadline: Instant) -> Result<usize, Refusal> {
    let timeout = refuse(408, "request timeout");
    let left = deadline.saturating_duration_since(Instant::now());
    if left.is_zero() {
        return Err(timeout);
    }
    stream
        .set_read_timeout(Some(left))
        .map_err(|_| refuse(400, "bad connection"))?;
    loop {
        match stream.read(buf) {
            Ok(n) => return Ok(n),
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
            Err(e)
                if matches!(
                    e.kind(),
                    std::io::ErrorKind::WouldBlock | std::io::ErrorKind::TimedOut
                ) =>
            {
                return Err(timeout);
            }
            Err(_) => return Err(refuse(400, "bad connection")),
        }
    }
}

/// Where the head ends in `bytes` (the index of its blank line) and where the body starts, if
/// the blank line has arrived (CRLF as RFC 9112 says; a bare LF is accepted as §2.2 allows).
fn head_end(bytes: &[u8]) -> Option<(usize, usize)> {
    let mut i = 0;
    while let Some(p) = bytes[i..].iter().position(|&b| b == b'\n') {
        let nl = i + p;
        let next = nl + 1;
        if bytes.get(next) == Some(&b'\n') {
            return Some((nl, next + 1));
        }
        if bytes.get(next) == Some(&b'\r') && bytes.get(next + 1) == Some(&b'\n') {
            return Some((nl, next + 2));
        }
        i = next;
    }
    None
}

/// Parses the request line and header fields (without the blank line).
pub fn parse_head(head: &[u8]) -> Result<Request, Refusal> {
    let bad = refuse(400, "malformed request");
    let text = std::str::from_utf8(head).map_err(|_| bad)?;
    let mut lines = text.split('\n').map(|l| l.strip_suffix('\r').unwrap_or(l));
    let line = lines.next().ok_or(bad)?;
    let mut parts = line.split(' ');
    let (Some(method), Some(target), Some(version), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(bad);
    };
    if !matches!(version, "HTTP/1.1" | "HTTP/1.0") {
        return Err(refuse(505, "HTTP version not supported"));
    }
    if !target.starts_with('/') || target.bytes().any(|b| b <= b' ' || b == 0x7f) {
        return Err(bad);
    }
    let method = match method {
        "GET" => Method::Get,
        "POST" => Method::Post,
        m if !m.is_empty() && m.bytes().all(is_token) => {
            return Err(refuse(405, "method not allowed"));
        }
        _ => return Err(bad),
    };
    let mut headers = Vec::new();
    for l in lines {
        let (name, value) = l.split_once(':').ok_or(bad)?;
        // No folded lines (obs-fold) and no space before the colon (RFC 9112 §5.1, §5.2).
        if name.is_empty() || !name.bytes().all(is_token) {
            return Err(bad);
        }
        let value = value.trim_matches([' ', '\t']);
        if value.bytes().any(|b| b < b' ' && b != b'\t' || b == 0x7f) {
            return Err(bad);
        }
        headers.push((name.to_ascii_lowercase(), value.to_string()));
    }
    Ok(Request {
        method,
        target: target.to_string(),
        headers,
    })
}

/// A `tchar` of RFC 9110 §5.6.2.
fn is_token(b: u8) -> bool {
    b.is_ascii_alphanumeric() || b"!#$%&'*+-.^_`|~".contains(&b)
}

/// The body's length: `Content-Length` (all copies equal), at most [`BODY_LIMIT`]; a chunked or
/// otherwise transfer-coded body is refused (411: the page never sends one).
fn body_length(request: &Request) -> Result<usize, Refusal> {
    if request.header("transfer-encoding").is_some() {
        return Err(refuse(411, "a body needs a Content-Length"));
    }
    let mut length = None;
    for (_, v) in request
        .headers
        .iter()
        .filter(|(n, _)| n == "content-length")
    {
        if v.is_empty() || !v.bytes().all(|b| b.is_ascii_digit()) {
            return Err(refuse(400, "bad Content-Length"));
        }
        // Longer than the limit's digits, or above it: too large, without parsing further.
        let n = if v.trim_start_matches('0').len() > 6 {
            usize::MAX
        } else {
            v.parse::<usize>().unwrap_or(usize::MAX)
        };
        if length.is_some_and(|l| l != n) {
            return Err(refuse(400, "conflicting Content-Length"));
        }
        length = Some(n);
    }
    match length {
        Some(n) if n > BODY_LIMIT => Err(refuse(413, "request body too large")),
        n => Ok(n.unwrap_or(0)),
    }
}

/// The reason phrase of a status code the preview sends.
fn reason(status: u16) -> &'static str {
    match status {
        200 => "OK",
        400 => "Bad Request",
        403 => "Forbidden",
        404 => "Not Found",
        405 => "Method Not Allowed",
        408 => "Request Timeout",
        411 => "Length Required",
        413 => "Content Too Large",
        431 => "Request Header Fields Too Large",
        500 => "Internal Server Error",
        503 => "Service Unavailable",
        505 => "HTTP Version Not Supported",
        _ => "",
    }
}

/// Writes a response and closes the exchange (`Connection: close`): the status, `Content-Type`,
/// `no-store`, the `extra` headers, the body. Errors (a client gone or too slow to read within
/// [`WRITE_TIME`]) are not the preview's: they are ignored.
pub fn respond(
    stream: &mut TcpStream,
    status: u16,
    kind: &str,
    extra: &[(&str, String)],
    body: &[u8],
) {
    let mut head = format!(
        "HTTP/1.1 {status} {}\r\nContent-Type: {kind}\r\nContent-Length: {}\r\nCache-Control: no-store\r\nConnection: close\r\nX-Content-Type-Options: nosniff\r\n",
        reason(status),
        body.len()
    );
    for (name, value) in extra {
        head.push_str(&format!("{name}: {value}\r\n"));
    }
    head.push_str("\r\n");
    let _ = stream.set_write_timeout(Some(WRITE_TIME));
    let _ = stream
        .write_all(head.as_bytes())
        .and_then(|()| stream.write_all(body))
        .and_then(|()| stream.flush());
    // Tell the client no more is coming; what it still sends is discarded with the socket.
    let _ = stream.shutdown(std::net::Shutdown::Write);
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn parse(text: &str) -> Result<Request, Refusal> {
        parse_head(text.as_bytes())
    }

    #[test]
    fn the_pages_requests_parse() {
        let r = parse("POST /pause?on=1 HTTP/1.1\r\nHost: 127.0.0.1:5\r\nOrigin: http://127.0.0.1:5\r\nContent-Length: 0")
            .expect("valid");
        assert_eq!(r.method, Method::Post);
        assert_eq!(r.path(), "/pause");
        assert_eq!(r.header("origin"), Some("http://127.0.0.1:5"));
        assert_eq!(body_length(&r), Ok(0));
    }

    #[test]
    fn bodies_are_bounded_and_chunking_refused() {
        let len = |cl: &str| {
            body_length(&parse(&format!("POST / HTTP/1.1\r\nContent-Length: {cl}")).expect("head"))
        };
        assert_eq!(len("64"), Ok(64));
        assert_eq!(len("65").map_err(|r| r.status), Err(413));
        assert_eq!(len("99999999999").map_err(|r| r.status), Err(413));
        assert_eq!(
            len("999999999999999999999999999999").map_err(|r| r.status),
            Err(413)
        );
        assert_eq!(len("-1").map_err(|r| r.status), Err(400));
        assert_eq!(len("1, 2").map_err(|r| r.status), Err(400));
        let two = parse("POST / HTTP/1.1\r\nContent-Length: 1\r\nContent-Length: 2").expect("head");
        assert_eq!(body_length(&two).map_err(|r| r.status), Err(400));
        let chunked = parse("POST / HTTP/1.1\r\nTransfer-Encoding: chunked").expect("head");
        assert_eq!(body_length(&chunked).map_err(|r| r.status), Err(411));
    }

    #[test]
    fn malformed_heads_are_refused_with_their_status() {
        let status = |t: &str| parse(t).map(|_| 200).unwrap_or_else(|r| r.status);
        assert_eq!(status("DELETE / HTTP/1.1"), 405);
        assert_eq!(status("GET http://x/ HTTP/1.1"), 400);
        assert_eq!(status("GET / HTTP/2"), 505);
        assert_eq!(status("GET /  HTTP/1.1"), 400);
        assert_eq!(status("GET / HTTP/1.1\r\n folded"), 400);
        assert_eq!(status("GET / HTTP/1.1\r\nName : v"), 400);
        assert_eq!(status("GET / HTTP/1.1\r\nA: b\u{1}"), 400);
        assert_eq!(status("GET /a HTTP/1.0\nA: b"), 200);
    }

    #[test]
    fn the_head_ends_at_the_first_blank_line() {
        assert_eq!(head_end(b"GET / HTTP/1.1\r\n\r\nxy"), Some((15, 18)));
        assert_eq!(head_end(b"GET / HTTP/1.1\n\nxy"), Some((14, 16)));
        assert_eq!(head_end(b"GET / HTTP/1.1\r\nA: b\r\n"), None);
    }

    proptest! {
        /// Any bytes at all: the parser answers (never panics) and only accepts what it can
        /// route, with a bounded body.
        #[test]
        fn any_head_parses_or_is_refused(bytes in proptest::collection::vec(any::<u8>(), 0..600)) {
            if let Ok(r) = parse_head(&bytes) {
                prop_assert!(r.target.starts_with('/'));
                if let Ok(n) = body_length(&r) {
                    prop_assert!(n <= BODY_LIMIT);
                }
            }
            let _ = head_end(&bytes);
        }
    }
}

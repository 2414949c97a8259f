//! The preview's HTTP side, on 127.0.0.1: the page, its status poll, the current image of a
//! layer at an exposure as PNG (or the denoised image), and the pause, denoise and save
//! buttons. Each connection gets its own thread (at most [`MAX_CONNECTIONS`] at once), one
//! request ([`http`]) and `Connection: close`, so no client can hold up another or the render.
//! Every request must name this server in its `Host` (which stops DNS rebinding), and the
//! requests that change state (`POST`) must come from the page's own origin (which stops other
//! web pages): docs/preview.md.

use std::io::Cursor;
use std::net::{SocketAddr, TcpListener, TcpStream};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc::Sender;
use std::time::Duration;

use caustic::render::output::to_srgb8;

use super::frame::View;
use super::http::{self, Method, Request};
use super::state::{Msg, Shared};

/// The page: HTML, style and script in one file.
const PAGE: &str = include_str!("page.html");

/// Longest wait for the render thread to save (it answers between passes, or after tracing
/// photons).
const SAVE_WAIT: Duration = Duration::from_secs(120);

/// Most connections served at once; one more is closed at once unanswered. The page keeps at
/// most three open (status poll, image, a button).
pub const MAX_CONNECTIONS: usize = 32;

/// How often the accept loop looks at the quit flag.
const POLL: Duration = Duration::from_millis(50);

/// The listening socket and what a request may name it.
pub struct Server {
    listener: TcpListener,
    port: u16,
    open: Arc<AtomicUsize>,
}

impl Server {
    /// Listens on `address` (127.0.0.1 and a port, 0 for a free one).
    pub fn bind(address: &str) -> std::io::Result<Self> {
        let listener = TcpListener::bind(address)?;
        listener.set_nonblocking(true)?;
        let port = listener.local_addr()?.port();
        Ok(Self {
            listener,
            port,
            open: Arc::new(AtomicUsize::new(0)),
        })
    }

    /// The port listened on.
    pub fn port(&self) -> u16 {
        self.port
    }

    /// Accepts connections until `shared.quit` is raised (checked every [`POLL`]) or `done`
    /// says the render thread ended; each is answered on its own thread, which ends within
    /// [`http::REQUEST_TIME`] + [`http::WRITE_TIME`] (a save waits for the render thread).
    pub fn serve(&self, shared: &Arc<Shared>, to_render: &Sender<Msg>, done: impl Fn() -> bool) {
        while !shared.quit.load(Ordering::SeqCst) && !done() {
            match self.listener.accept() {
                Ok((stream, peer)) => self.spawn(stream, peer, shared, to_render),
                Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => std::thread::sleep(POLL),
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                // Out of file descriptors and the like: wait, and go on serving.
                Err(e) => {
                    eprintln!("warning: the preview's server: {e}");
                    std::thread::sleep(POLL);
                }
            }
        }
    }

    fn spawn(
        &self,
        stream: TcpStream,
        peer: SocketAddr,
        shared: &Arc<Shared>,
        to_render: &Sender<Msg>,
    ) {
        // Over the bound: the connection is closed at once (dropped), unanswered.
        if self.open.fetch_add(1, Ordering::SeqCst) >= MAX_CONNECTIONS || !peer.ip().is_loopback() {
            self.open.fetch_sub(1, Ordering::SeqCst);
            return;
        }
        let open = Arc::clone(&self.open);
        let (shared, to_render, port) = (Arc::clone(shared), to_render.clone(), self.port);
        let spawned = std::thread::Builder::new()
            .name("preview-http".into())
            .spawn(move || {
                connection(stream, port, &shared, &to_render);
                open.fetch_sub(1, Ordering::SeqCst);
            });
        if spawned.is_err() {
            self.open.fetch_sub(1, Ordering::SeqCst);
        }
    }
}

/// Reads and answers the one request of a connection.
fn connection(mut stream: TcpStream, port: u16, shared: &Shared, to_render: &Sender<Msg>) {
    // The accepted socket may inherit non-blocking mode on some systems: reads use timeouts.
    if stream.set_nonblocking(false).is_err() {
        return;
    }
    match http::read_request(&mut stream) {
        Ok(Some(request)) => handle(&mut stream, &request, port, shared, to_render),
        Ok(None) => {}
        Err(refusal) => text(&mut stream, refusal.status, refusal.text),
    }
}

fn respond(stream: &mut TcpStream, status: u16, kind: &str, body: &[u8]) {
    http::respond(stream, status, kind, &[], body);
}

fn text(stream: &mut TcpStream, status: u16, body: &str) {
    respond(stream, status, "text/plain; charset=utf-8", body.as_bytes());
}

/// The value of `key` in the query string of `url` (`/path?a=1&b=2`), undecoded (the page
/// sends only names and numbers).
fn query<'a>(url: &'a str, key: &str) -> Option<&'a str> {
    let (_, q) = url.split_once('?')?;
    q.split('&')
        .filter_map(|kv| kv.split_once('='))
        .find(|(k, _)| *k == key)
        .map(|(_, v)| v)
}

/// Whether `host` (a `Host` header, or an `Origin`'s authority) names this server: 127.0.0.1 or
/// localhost, at `port` if a port is given (browsers always give it; other local clients may
/// not). Any other name is a page that resolved its own name to 127.0.0.1 (DNS
/// rebinding) or a misdirected request.
fn is_us(host: &str, port: u16) -> bool {
    let (name, right_port) = match host.rsplit_once(':') {
        Some((name, p)) => (name, p.parse::<u16>() == Ok(port)),
        None => (host, true),
    };
    right_port && (name == "127.0.0.1" || name.eq_ignore_ascii_case("localhost"))
}

/// Why a request may not be answered, by where it comes from: `None` when it may. Every request
/// must carry `Host: 127.0.0.1:PORT` (or `localhost`, with or without the port); a `POST` must also carry the page's
/// `Origin` (browsers send it with every `POST`, so a request from another page, a form of
/// another site, a sandboxed frame or a file, whose `Origin` differs or is `null`, is refused).
fn forbidden(request: &Request, port: u16) -> Option<&'static str> {
    if !request.header("host").is_some_and(|h| is_us(h, port)) {
        return Some(
            "forbidden: the Host must be this preview (127.0.0.1 or localhost and its port)",
        );
    }
    if request.method == Method::Post {
        let ours = request
            .header("origin")
            .and_then(|o| o.strip_prefix("http://"))
            .is_some_and(|h| is_us(h, port));
        if !ours {
            return Some("forbidden: only the preview's own page may change it");
        }
    }
    None
}

/// Answers one request.
fn handle(
    stream: &mut TcpStream,
    request: &Request,
    port: u16,
    shared: &Shared,
    to_render: &Sender<Msg>,
) {
    if let Some(why) = forbidden(request, port) {
        return text(stream, 403, why);
    }
    let url = request.target.as_str();
    match (request.method, request.path()) {
        (Method::Get, "/") => respond(stream, 200, "text/html; charset=utf-8", PAGE.as_bytes()),
        (Method::Get, "/status") => {
            let json = shared.status().to_json();
            respond(stream, 200, "application/json", json.as_bytes());
        }
        (Method::Get, "/image.png") => image(stream, url, shared),
        (Method::Post, "/pause") => {
            let on = query(url, "on") != Some("0");
            // The render thread ends only after the server stops: the send cannot fail.
            let _ = to_render.send(Msg::Pause(on));
            text(stream, 200, if on { "paused" } else { "resumed" });
        }
        (Method::Post, "/denoise") => {
            let on = query(url, "on") != Some("0");
            // The render thread says in the status when it has taken it (between passes).
            let _ = to_render.send(Msg::Denoise(on));
            text(stream, 200, if on { "denoising" } else { "not denoising" });
        }
        // Saving waits for the end of a pass; this connection has its own thread, so the
        // page's polls go on meanwhile.
        (Method::Post, "/save") => save(stream, shared, to_render),
        (Method::Get | Method::Post, _) => text(stream, 404, "not found"),
    }
}

/// `/image.png?layer=NAME&exposure=X`: the current estimate of a layer, exposure-scaled and
/// sRGB-encoded as `render` writes PNGs; `layer=denoised` the latest denoised image (503 until
/// one exists). `X-Caustic-Spp` says how many samples per pixel the image holds.
fn image(stream: &mut TcpStream, url: &str, shared: &Shared) {
    let Some(frame) = shared.frame() else {
        return text(stream, 503, "no image yet: the first pass has not finished");
    };
    let view = query(url, "layer")
        .and_then(View::parse)
        .unwrap_or(View::Beauty);
    let exposure = query(url, "exposure")
        .and_then(|e| e.parse::<f32>().ok())
        .filter(|e| e.is_finite() && *e >= 0.0)
        .unwrap_or_else(|| shared.status().exposure);
    let Some((film, spp)) = frame.view(view) else {
        return text(
            stream,
            503,
            "no denoised image yet: turn denoising on (POST /denoise) and wait for two samples per pixel",
        );
    };
    let mut png = Cursor::new(Vec::new());
    match to_srgb8(film, exposure).write_to(&mut png, image::ImageFormat::Png) {
        Ok(()) => http::respond(
            stream,
            200,
            "image/png",
            &[
                ("X-Caustic-Spp", spp.to_string()),
                ("X-Caustic-Generation", frame.generation.to_string()),
            ],
            &png.into_inner(),
        ),
        Err(e) => text(stream, 500, &format!("cannot encode the image: {e}")),
    }
}

/// `/save`: asks the render thread to save and answers with its message (JSON).
fn save(stream: &mut TcpStream, shared: &Shared, to_render: &Sender<Msg>) {
    let (reply, answer) = std::sync::mpsc::channel();
    let outcome = match to_render.send(Msg::Save(reply)) {
        Ok(()) => answer
            .recv_timeout(SAVE_WAIT)
            .unwrap_or_else(|_| Err("not saved: the render did not answer".into())),
        Err(_) => Err("not saved: the preview is stopping".into()),
    };
    let (ok, message) = match outcome {
        Ok(m) => (true, m),
        Err(m) => (false, m),
    };
    shared.status().message = Some(message.clone());
    let body = serde_json::json!({ "ok": ok, "message": message }).to_string();
    respond(stream, 200, "application/json", body.as_bytes());
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn query_values_are_found_by_key() {
        let url = "/image.png?layer=caustic&exposure=2.5";
        assert_eq!(query(url, "layer"), Some("caustic"));
        assert_eq!(query(url, "exposure"), Some("2.5"));
        assert_eq!(query(url, "v"), None);
        assert_eq!(query("/image.png", "layer"), None);
    }

    fn request(method: Method, headers: &[(&str, &str)]) -> Request {
        Request {
            method,
            target: "/save".into(),
            headers: headers
                .iter()
                .map(|(n, v)| ((*n).to_string(), (*v).to_string()))
                .collect(),
        }
    }

    #[test]
    fn only_this_host_is_served_and_only_the_page_changes_state() {
        let port = 4711;
        let ok = |m, h: &[(&str, &str)]| forbidden(&request(m, h), port).is_none();
        let host = ("host", "127.0.0.1:4711");
        assert!(ok(Method::Get, &[host]));
        assert!(ok(Method::Get, &[("host", "LOCALHOST:4711")]));
        // DNS rebinding: a page of evil.example whose name now resolves to 127.0.0.1.
        assert!(!ok(Method::Get, &[("host", "evil.example:4711")]));
        assert!(!ok(Method::Get, &[("host", "127.0.0.1:4712")]));
        assert!(ok(Method::Get, &[("host", "127.0.0.1")]));
        assert!(!ok(Method::Get, &[("host", "evil.example")]));
        assert!(!ok(Method::Get, &[]));
        assert!(ok(
            Method::Post,
            &[host, ("origin", "http://127.0.0.1:4711")]
        ));
        assert!(ok(
            Method::Post,
            &[host, ("origin", "http://localhost:4711")]
        ));
        for origin in [
            "https://evil.example",
            "null",
            "http://127.0.0.1:4712",
            "https://127.0.0.1:4711",
            "http://127.0.0.1:4711.evil.example:4711",
            "http://127.0.0.1.evil.example",
        ] {
            assert!(!ok(Method::Post, &[host, ("origin", origin)]), "{origin}");
        }
        assert!(!ok(Method::Post, &[host]), "a POST without Origin");
    }
}

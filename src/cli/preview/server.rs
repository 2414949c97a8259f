//! The preview's HTTP side (tiny_http, on 127.0.0.1): the page, its status poll, the current
//! image of a layer at an exposure as PNG, and the pause and save buttons.

use std::io::Cursor;
use std::sync::Arc;
use std::sync::mpsc::Sender;
use std::time::Duration;

use tiny_http::{Header, Method, Request, Response};

use caustic::render::output::to_srgb8;

use super::frame::View;
use super::state::{Msg, Shared};

/// The page: HTML, style and script in one file.
const PAGE: &str = include_str!("page.html");

/// Longest wait for the render thread to save (it answers between passes, or after tracing
/// photons).
const SAVE_WAIT: Duration = Duration::from_secs(120);

/// A header from constant parts.
fn header(name: &str, value: &str) -> Header {
    // Both parts are ASCII constants, which tiny_http always accepts.
    Header::from_bytes(name.as_bytes(), value.as_bytes())
        .unwrap_or_else(|()| unreachable!("ASCII header {name}: {value}"))
}

fn respond(request: Request, status: u16, kind: &str, body: Vec<u8>) {
    let response = Response::from_data(body)
        .with_status_code(status)
        .with_header(header("Content-Type", kind))
        .with_header(header("Cache-Control", "no-store"));
    // A page closed mid-answer is not an error of the preview.
    let _ = request.respond(response);
}

fn text(request: Request, status: u16, body: &str) {
    respond(
        request,
        status,
        "text/plain; charset=utf-8",
        body.as_bytes().to_vec(),
    );
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

/// Answers one request.
pub fn handle(request: Request, shared: &Arc<Shared>, to_render: &Sender<Msg>) {
    let url = request.url().to_string();
    let path = url.split('?').next().unwrap_or("");
    match (request.method(), path) {
        (Method::Get, "/") => respond(
            request,
            200,
            "text/html; charset=utf-8",
            PAGE.as_bytes().to_vec(),
        ),
        (Method::Get, "/status") => {
            let json = shared.status().to_json();
            respond(request, 200, "application/json", json.into_bytes());
        }
        (Method::Get, "/image.png") => image(request, &url, shared),
        (Method::Post, "/pause") => {
            let on = query(&url, "on") != Some("0");
            // The render thread ends only after the server stops: the send cannot fail.
            let _ = to_render.send(Msg::Pause(on));
            text(request, 200, if on { "paused" } else { "resumed" });
        }
        (Method::Post, "/save") => {
            let (shared, to_render) = (Arc::clone(shared), to_render.clone());
            // Saving waits for the end of a pass: answer it on its own thread so the page's
            // polls go on meanwhile.
            std::thread::spawn(move || save(request, &shared, &to_render));
        }
        _ => text(request, 404, "not found"),
    }
}

/// `/image.png?layer=NAME&exposure=X`: the current estimate of a layer, exposure-scaled and
/// sRGB-encoded as `render` writes PNGs.
fn image(request: Request, url: &str, shared: &Shared) {
    let Some(frame) = shared.frame() else {
        return text(
            request,
            503,
            "no image yet: the first pass has not finished",
        );
    };
    let view = query(url, "layer")
        .and_then(View::parse)
        .unwrap_or(View::Beauty);
    let exposure = query(url, "exposure")
        .and_then(|e| e.parse::<f32>().ok())
        .filter(|e| e.is_finite() && *e >= 0.0)
        .unwrap_or_else(|| shared.status().exposure);
    let mut png = Cursor::new(Vec::new());
    match to_srgb8(frame.view(view), exposure).write_to(&mut png, image::ImageFormat::Png) {
        Ok(()) => {
            let response = Response::from_data(png.into_inner())
                .with_header(header("Content-Type", "image/png"))
                .with_header(header("Cache-Control", "no-store"))
                .with_header(header("X-Caustic-Spp", &frame.spp.to_string()))
                .with_header(header(
                    "X-Caustic-Generation",
                    &frame.generation.to_string(),
                ));
            let _ = request.respond(response);
        }
        Err(e) => text(request, 500, &format!("cannot encode the image: {e}")),
    }
}

/// `/save`: asks the render thread to save and answers with its message (JSON).
fn save(request: Request, shared: &Shared, to_render: &Sender<Msg>) {
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
    respond(request, 200, "application/json", body.into_bytes());
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
}

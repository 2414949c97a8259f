//! `caustic preview` as a server (issue 47, preview-http-body): what any local process or web
//! page can send it. A declared body larger than memory, a withheld body, and a stream of
//! random requests (methods, targets, headers, lengths, chunked bodies, early closes, held
//! connections) must neither abort nor stall the server (another client's `/status` answered
//! within a second throughout) nor stop the render; requests that change state are refused
//! unless they come from the page's own origin, and every request must name the preview in its
//! `Host` (DNS rebinding); `/status` does not reveal where the scene is; Ctrl-C ends it within
//! moments even while a client holds a request open.

use std::io::{BufRead, BufReader, Read, Write};
use std::net::{Shutdown, TcpStream};
use std::path::Path;
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

/// A small scene that renders for minutes at 200 000 samples per pixel on one thread.
const SCENE: &str = r#"Scene(
    render: (width: 32, height: 24, samples_per_pixel: 200000, max_depth: 4, integrator: Path),
    camera: Pinhole(eye: (0, 1, 3), look_at: (0, 0.5, 0), fov_y: 40),
    materials: { "white": (color: (0.7, 0.7, 0.7)) },
    lights: [ Point(position: (0, 2, 1), power: (40, 40, 40)) ],
    nodes: [
        Quad(material: "white", size: (4, 4), transform: [RotateX(-90)]),
        Sphere(material: "white", center: (0, 0.5, 0), radius: 0.5),
    ],
)"#;

/// A running `caustic preview` of [`SCENE`] and its port.
struct Server {
    child: Child,
    port: u16,
}

impl Server {
    fn start(dir: &Path) -> Self {
        let scene = dir.join("scene.ron");
        std::fs::write(&scene, SCENE).expect("scene");
        let mut child = Command::new(env!("CARGO_BIN_EXE_caustic"))
            .arg("preview")
            .arg(&scene)
            .args(["--threads", "1", "-q", "-o"])
            .arg(dir.join("out.png"))
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("caustic preview starts");
        let mut line = String::new();
        BufReader::new(child.stdout.take().expect("stdout"))
            .read_line(&mut line)
            .expect("the address line");
        let port = line
            .split("http://127.0.0.1:")
            .nth(1)
            .and_then(|r| r.split('/').next())
            .and_then(|p| p.parse().ok())
            .unwrap_or_else(|| panic!("no address in {line:?}"));
        Self { child, port }
    }

    fn connect(&self) -> TcpStream {
        let s = TcpStream::connect(("127.0.0.1", self.port)).expect("connects");
        s.set_read_timeout(Some(Duration::from_secs(10))).ok();
        s
    }

    /// Sends `request` and reads the answer until the server closes (at most 10 s).
    fn exchange(&self, request: &[u8]) -> (u16, String) {
        let mut s = self.connect();
        s.write_all(request).expect("sends");
        let mut answer = Vec::new();
        let _ = s.read_to_end(&mut answer);
        let text = String::from_utf8_lossy(&answer).into_owned();
        let status = text
            .split(' ')
            .nth(1)
            .and_then(|c| c.parse().ok())
            .unwrap_or(0);
        let body = text
            .split_once("\r\n\r\n")
            .map_or(String::new(), |(_, b)| b.to_string());
        (status, body)
    }

    fn get(&self, path: &str) -> (u16, String) {
        let port = self.port;
        self.exchange(format!("GET {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n").as_bytes())
    }

    /// `/status`, and how long it took to answer.
    fn status(&self) -> (Value, Duration) {
        let t = Instant::now();
        let (code, body) = self.get("/status");
        assert_eq!(code, 200, "{body}");
        (
            serde_json::from_str(&body).expect("status JSON"),
            t.elapsed(),
        )
    }

    fn alive(&mut self) -> bool {
        self.child.try_wait().expect("wait").is_none()
    }

    /// Samples per pixel once rendering has started.
    fn spp_when_rendering(&self) -> u64 {
        let start = Instant::now();
        loop {
            let (s, _) = self.status();
            if s["phase"] == "rendering" && s["spp"].as_u64().unwrap_or(0) > 0 {
                return s["spp"].as_u64().unwrap_or(0);
            }
            assert!(start.elapsed() < Duration::from_secs(60), "no pass: {s}");
            std::thread::sleep(Duration::from_millis(50));
        }
    }

    /// SIGINT; the exit code and how long the exit took.
    fn interrupt(mut self) -> (Option<i32>, Duration) {
        let pid = self.child.id().to_string();
        let t = Instant::now();
        let ok = Command::new("kill").args(["-INT", &pid]).status();
        assert!(ok.is_ok_and(|s| s.success()), "kill -INT");
        loop {
            if let Some(s) = self.child.try_wait().expect("wait") {
                return (s.code(), t.elapsed());
            }
            assert!(
                t.elapsed() < Duration::from_secs(10),
                "no exit after SIGINT"
            );
            std::thread::sleep(Duration::from_millis(10));
        }
    }
}

impl Drop for Server {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

#[test]
fn a_huge_or_withheld_body_neither_aborts_nor_stalls_the_preview() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut server = Server::start(dir.path());
    let port = server.port;
    server.spp_when_rendering();
    // A declared body larger than memory: refused at once (before: "memory allocation of
    // 99999999999 bytes failed", exit 134).
    let (code, _) = server.exchange(
        format!("POST /pause?on=0 HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 99999999999\r\n\r\n")
            .as_bytes(),
    );
    assert_eq!(code, 413);
    assert!(server.alive(), "the preview ended");
    // A body of 1 GB declared and withheld: other clients are answered meanwhile (before: no
    // answer to anyone until this client left), and this one is answered 413 or dropped.
    let mut held = server.connect();
    held.write_all(
        format!(
            "POST /save HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 1000000000\r\n\r\nab"
        )
        .as_bytes(),
    )
    .expect("sends");
    let mut slow = server.connect();
    slow.write_all(b"GET /sta").expect("sends");
    for _ in 0..10 {
        let (_, took) = server.status();
        assert!(took < Duration::from_secs(1), "/status took {took:?}");
    }
    // A client that sends its head byte by byte for longer than the request time is cut off.
    let t = Instant::now();
    let mut answer = Vec::new();
    let _ = slow.read_to_end(&mut answer);
    assert!(t.elapsed() < Duration::from_secs(5), "{:?}", t.elapsed());
    assert!(answer.starts_with(b"HTTP/1.1 408"), "{answer:?}");
    // Ctrl-C while a client holds a request open: the preview ends within moments.
    let mut held2 = server.connect();
    held2
        .write_all(
            format!("POST /pause HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 10\r\n\r\n")
                .as_bytes(),
        )
        .expect("sends");
    let (code, took) = server.interrupt();
    assert_eq!(code, Some(130));
    assert!(took < Duration::from_secs(2), "exit took {took:?}");
    let _ = held.shutdown(Shutdown::Both);
}

#[test]
fn only_the_pages_own_origin_changes_the_preview_and_status_hides_the_scenes_folder() {
    let dir = tempfile::tempdir().expect("tmp");
    let server = Server::start(dir.path());
    let port = server.port;
    server.spp_when_rendering();
    let post = |path: &str, headers: &str| {
        server.exchange(
            format!("POST {path} HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n{headers}Content-Length: 0\r\n\r\n")
                .as_bytes(),
        )
    };
    // Another web page (a fetch or a form of its own origin), a sandboxed frame or file
    // (`null`), and a client sending no Origin: refused, nothing saved, nothing paused.
    for origin in [
        "Origin: https://evil.example\r\n",
        "Origin: null\r\n",
        "Origin: http://127.0.0.1:1\r\n",
        "",
    ] {
        assert_eq!(post("/save", origin).0, 403, "{origin}");
        assert_eq!(post("/pause?on=1", origin).0, 403, "{origin}");
        assert_eq!(post("/denoise?on=1", origin).0, 403, "{origin}");
    }
    assert!(
        !dir.path().join("out.png").exists(),
        "a cross-origin save wrote the image"
    );
    assert_eq!(server.status().0["paused"], false);
    assert_eq!(
        server.status().0["denoise"],
        false,
        "a cross-origin denoise toggle"
    );
    // DNS rebinding: a page whose own name now resolves to 127.0.0.1 can read nothing.
    let rebound = server
        .exchange(format!("GET /status HTTP/1.1\r\nHost: evil.example:{port}\r\n\r\n").as_bytes());
    assert_eq!(rebound.0, 403);
    // The page itself (as Chromium sends its fetches) pauses, resumes and saves.
    let page = format!("Origin: http://127.0.0.1:{port}\r\n");
    assert_eq!(post("/pause?on=1", &page).0, 200);
    // The render thread takes the message between passes (a quarter of a second each).
    let asked = Instant::now();
    while server.status().0["paused"] != true {
        assert!(asked.elapsed() < Duration::from_secs(5), "not paused");
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(post("/pause?on=0", &page).0, 200);
    assert_eq!(post("/denoise?on=1", &page).0, 200);
    let asked = Instant::now();
    while server.status().0["denoise"] != true {
        assert!(asked.elapsed() < Duration::from_secs(5), "denoising not on");
        std::thread::sleep(Duration::from_millis(20));
    }
    assert_eq!(post("/denoise?on=0", &page).0, 200);
    let (code, body) = post("/save", &format!("Origin: http://localhost:{port}\r\n"));
    assert_eq!(code, 200, "{body}");
    assert!(body.contains("\"ok\":true"), "{body}");
    assert!(dir.path().join("out.png").exists());
    // The status names the scene's file, not the folder it is in.
    let (status, _) = server.status();
    assert_eq!(status["scene"], "scene.ron");
    let folder = dir.path().display().to_string();
    assert!(!server.get("/status").1.contains(&folder));
}

/// A tiny deterministic generator (xorshift64*), so a failure names its seed.
struct Fuzz(u64);

impl Fuzz {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    fn pick<'a>(&mut self, options: &[&'a str]) -> &'a str {
        options[self.below(options.len() as u64) as usize]
    }
}

/// One random request: mostly plausible HTTP with random parts, some raw bytes, and a random
/// ending (complete, cut short, held open, or closed early).
fn fuzz_request(f: &mut Fuzz, port: u16) -> (Vec<u8>, u64) {
    let method = f.pick(&[
        "GET", "POST", "PUT", "DELETE", "HEAD", "OPTIONS", "TRACE", "CONNECT", "get", "G ET", "",
        "PATCH", "BREW",
    ]);
    let target = f.pick(&[
        "/",
        "/status",
        "/image.png?layer=caustic&exposure=1e38",
        "/image.png?exposure=-1&layer=../../etc/passwd",
        "/../../etc/passwd",
        "/%2e%2e/%2e%2e/etc/passwd",
        "http://127.0.0.1/status",
        "*",
        "/save",
        "/pause?on=0",
        "/pause?on=1",
        "/nope",
        "",
    ]);
    let version = f.pick(&["HTTP/1.1", "HTTP/1.0", "HTTP/2", "HTTP/9.9", ""]);
    let mut head = format!("{method} {target} {version}\r\n");
    let host = format!("Host: 127.0.0.1:{port}\r\n");
    let headers = [
        host.as_str(),
        "Host: evil.example\r\n",
        "Origin: https://evil.example\r\n",
        "Origin: null\r\n",
        "Content-Length: 0\r\n",
        "Content-Length: 5\r\n",
        "Content-Length: 99999999999\r\n",
        "Content-Length: -1\r\n",
        "Content-Length: 1, 2\r\n",
        "Content-Length: 340282366920938463463374607431768211456\r\n",
        "Transfer-Encoding: chunked\r\n",
        "Transfer-Encoding: gzip, chunked\r\n",
        "Connection: keep-alive\r\n",
        "Expect: 100-continue\r\n",
        " folded continuation\r\n",
        "X: \u{1}\r\n",
        "NoColon\r\n",
    ];
    for _ in 0..f.below(6) {
        head.push_str(f.pick(&headers));
    }
    if f.below(20) == 0 {
        head.push_str(&format!(
            "X-Long: {}\r\n",
            "a".repeat(f.below(20_000) as usize)
        ));
    }
    head.push_str("\r\n");
    let mut bytes = head.into_bytes();
    match f.below(4) {
        0 => bytes.extend(std::iter::repeat_n(b'x', f.below(200) as usize)),
        1 => bytes.extend_from_slice(b"5\r\nhello\r\n0\r\n\r\n"),
        2 => bytes = (0..f.below(300)).map(|_| f.next() as u8).collect(),
        _ => {}
    }
    // How much of it to send before the ending (0: all).
    let cut = if f.below(4) == 0 {
        f.below(bytes.len() as u64 + 1)
    } else {
        0
    };
    (bytes, cut)
}

#[test]
fn fuzzed_requests_never_abort_stall_or_stop_the_preview() {
    let dir = tempfile::tempdir().expect("tmp");
    let mut server = Server::start(dir.path());
    let port = server.port;
    let before = server.spp_when_rendering();
    let stop = std::sync::atomic::AtomicBool::new(false);
    let worst = std::thread::scope(|scope| {
        // Twelve clients send 16 random requests each (192 in all), some held open up to 3 s
        // (past the server's 2-s request time).
        let clients: Vec<_> = (0..12u64)
            .map(|c| {
                scope.spawn(move || {
                    let mut f =
                        Fuzz(0x9e37_79b9_7f4a_7c15 ^ (c + 1).wrapping_mul(0x1234_5678_9abc));
                    for _ in 0..16 {
                        let (bytes, cut) = fuzz_request(&mut f, port);
                        let Ok(mut s) = TcpStream::connect(("127.0.0.1", port)) else {
                            continue;
                        };
                        s.set_read_timeout(Some(Duration::from_secs(5))).ok();
                        let sent = if cut > 0 {
                            &bytes[..cut as usize]
                        } else {
                            &bytes[..]
                        };
                        let _ = s.write_all(sent);
                        match f.below(4) {
                            // Close at once, without reading.
                            0 => {}
                            // Hold the connection open a while, then close.
                            1 => std::thread::sleep(Duration::from_millis(f.below(3000))),
                            // Close the sending side and read the answer.
                            _ => {
                                let _ = s.shutdown(Shutdown::Write);
                                let mut sink = Vec::new();
                                let _ = s.read_to_end(&mut sink);
                            }
                        }
                    }
                })
            })
            .collect();
        // Meanwhile the page's poll: every answer within a second.
        let poll = scope.spawn(|| {
            let mut worst = Duration::ZERO;
            while !stop.load(std::sync::atomic::Ordering::SeqCst) {
                let (_, took) = server.status();
                worst = worst.max(took);
                std::thread::sleep(Duration::from_millis(100));
            }
            worst
        });
        for c in clients {
            c.join().expect("client");
        }
        stop.store(true, std::sync::atomic::Ordering::SeqCst);
        poll.join().expect("poll")
    });
    eprintln!("slowest /status during the fuzz: {worst:?}");
    assert!(worst < Duration::from_secs(1), "/status took {worst:?}");
    assert!(server.alive(), "the preview ended");
    // The render went on (a random `/pause` never carries the page's Origin).
    let (s, _) = server.status();
    assert_eq!(s["paused"], false);
    let after = server.spp_when_rendering();
    assert!(after > before, "spp {before} -> {after}");
    assert!(
        !dir.path().join("out.png").exists(),
        "a fuzzed request saved"
    );
    let (code, took) = server.interrupt();
    assert_eq!(code, Some(130));
    assert!(took < Duration::from_secs(2), "exit took {took:?}");
}

//! The state the render thread publishes and the page polls, and the messages the server and
//! the file watcher send to the render thread.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use super::frame::Frame;

/// What the render thread is doing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Phase {
    /// Reading and compiling the scene.
    Loading,
    /// Building the integrator's shared state: tracing photons for the photon maps.
    Photons,
    /// Taking samples, pass after pass.
    Rendering,
    /// Every sample (or the `--time` budget) is done.
    Done,
    /// The scene does not load; the page shows the diagnostic and the last good image.
    Failed,
}

impl Phase {
    fn name(self) -> &'static str {
        match self {
            Phase::Loading => "loading",
            Phase::Photons => "photons",
            Phase::Rendering => "rendering",
            Phase::Done => "done",
            Phase::Failed => "failed",
        }
    }
}

/// The figures the page shows.
#[derive(Debug, Clone)]
pub struct Status {
    /// Renders started so far (a restart after an edit starts a new one).
    pub generation: u64,
    /// Bumped whenever `frame` changes, so the page reloads the image only then.
    pub version: u64,
    /// What the render thread is doing.
    pub phase: Phase,
    /// What is being prepared (e.g. "tracing 100000 photons"), while `phase` is `Photons`.
    pub preparing: String,
    /// When the current render (with its preparation) started.
    pub started: Instant,
    /// How long it took, once it is done (the elapsed time then stops).
    pub stopped: Option<Duration>,
    /// Samples per pixel in the image shown, and the render's goal.
    pub spp: u32,
    /// The render's samples per pixel (goal).
    pub spp_goal: u32,
    /// Seconds spent in passes (the rays/s figure's denominator).
    pub render_seconds: f64,
    /// Rays traced so far.
    pub rays: u64,
    /// Root-mean-square standard error of the pixel means, and the mean pixel value.
    pub noise: Option<(f64, f64)>,
    /// Image size.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The scene's exposure (the page's exposure multiplies it).
    pub exposure: f32,
    /// Whether the render waits between passes.
    pub paused: bool,
    /// Whether the denoised image is asked for (the page's toggle, `--denoise`).
    pub denoise: bool,
    /// Samples per pixel of the denoised image on hand (`/image.png?layer=denoised`), if any.
    pub denoised_spp: Option<u32>,
    /// Why there is no denoised image yet, or why denoising failed.
    pub denoise_note: Option<String>,
    /// The diagnostics of a scene that does not load, as the command line prints them.
    pub error: Option<String>,
    /// The photon-map summary of the current render, if it traces photons.
    pub photons: Option<String>,
    /// The outcome of the last save.
    pub message: Option<String>,
    /// The scene file.
    pub scene: String,
}

impl Status {
    /// The status as the JSON object `/status` returns.
    pub fn to_json(&self) -> String {
        let rays_per_s = if self.render_seconds > 0.0 {
            self.rays as f64 / self.render_seconds
        } else {
            0.0
        };
        serde_json::json!({
            "generation": self.generation,
            "version": self.version,
            "phase": self.phase.name(),
            "preparing": self.preparing,
            "elapsed": self.stopped.unwrap_or_else(|| self.started.elapsed()).as_secs_f64(),
            "spp": self.spp,
            "spp_goal": self.spp_goal,
            "rays": self.rays,
            "rays_per_s": rays_per_s,
            "noise": self.noise.map(|n| n.0),
            "mean": self.noise.map(|n| n.1),
            "width": self.width,
            "height": self.height,
            "exposure": self.exposure,
            "paused": self.paused,
            "denoise": self.denoise,
            "denoised_spp": self.denoised_spp,
            "denoise_note": self.denoise_note,
            "error": self.error,
            "photons": self.photons,
            "message": self.message,
            "scene": self.scene,
        })
        .to_string()
    }
}

/// A request to the render thread.
pub enum Msg {
    /// A watched file changed: load the scene again and restart.
    Changed,
    /// Stop (or resume) taking samples between passes.
    Pause(bool),
    /// Show (or stop showing) the denoised image: denoise after passes (docs/preview.md).
    Denoise(bool),
    /// Save the image so far as `render -o` would; the reply is the message to show.
    Save(std::sync::mpsc::Sender<Result<String, String>>),
    /// End the render thread (Ctrl-C).
    Quit,
}

/// State shared by the render thread, the server and the watcher.
#[derive(Debug)]
pub struct Shared {
    status: Mutex<Status>,
    frame: Mutex<Option<Arc<Frame>>>,
    /// The cancel flag of the render in progress (raised to stop its pass at once).
    cancel: Mutex<Arc<AtomicBool>>,
    /// Raised once on Ctrl-C.
    pub quit: AtomicBool,
}

impl Shared {
    /// Fresh state for `scene`.
    pub fn new(scene: String) -> Self {
        Self {
            status: Mutex::new(Status {
                generation: 0,
                version: 0,
                phase: Phase::Loading,
                preparing: String::new(),
                started: Instant::now(),
                stopped: None,
                spp: 0,
                spp_goal: 0,
                render_seconds: 0.0,
                rays: 0,
                noise: None,
                width: 0,
                height: 0,
                exposure: 1.0,
                paused: false,
                denoise: false,
                denoised_spp: None,
                denoise_note: None,
                error: None,
                photons: None,
                message: None,
                scene,
            }),
            frame: Mutex::new(None),
            cancel: Mutex::new(Arc::new(AtomicBool::new(false))),
            quit: AtomicBool::new(false),
        }
    }

    /// The status, locked for reading or changing (a poisoned lock still holds usable figures).
    pub fn status(&self) -> MutexGuard<'_, Status> {
        self.status.lock().unwrap_or_else(|p| p.into_inner())
    }

    /// The latest frame, if any pass has finished yet.
    pub fn frame(&self) -> Option<Arc<Frame>> {
        self.frame.lock().unwrap_or_else(|p| p.into_inner()).clone()
    }

    /// Publishes a new frame (and bumps the status' version).
    pub fn set_frame(&self, frame: Frame) {
        *self.frame.lock().unwrap_or_else(|p| p.into_inner()) = Some(Arc::new(frame));
        self.status().version += 1;
    }

    /// A fresh cancel flag for the next render (the old one stays raised if it was).
    pub fn new_cancel(&self) -> Arc<AtomicBool> {
        let flag = Arc::new(AtomicBool::new(self.quit.load(Ordering::SeqCst)));
        *self.cancel.lock().unwrap_or_else(|p| p.into_inner()) = Arc::clone(&flag);
        flag
    }

    /// Stops the pass in progress, if any (its render then restarts or ends).
    pub fn cancel_render(&self) {
        self.cancel
            .lock()
            .unwrap_or_else(|p| p.into_inner())
            .store(true, Ordering::SeqCst);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_status_is_valid_json_with_escaped_text() {
        let shared = Shared::new("scenes/a \"b\".ron".into());
        {
            let mut s = shared.status();
            s.error = Some("error: x\n  --> a.ron:3:5\n   |     ^\n".into());
            s.noise = Some((0.01, 0.5));
            s.rays = 1000;
            s.render_seconds = 2.0;
        }
        let v: serde_json::Value =
            serde_json::from_str(&shared.status().to_json()).expect("valid JSON");
        assert_eq!(v["error"], "error: x\n  --> a.ron:3:5\n   |     ^\n");
        assert_eq!(v["scene"], "scenes/a \"b\".ron");
        assert_eq!(v["rays_per_s"], 500.0);
        assert_eq!(v["noise"], 0.01);
        assert_eq!(v["photons"], serde_json::Value::Null);
        assert_eq!(v["phase"], "loading");
        assert_eq!(v["denoise"], false);
        assert_eq!(v["denoised_spp"], serde_json::Value::Null);
    }
}

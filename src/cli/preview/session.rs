//! The preview's render thread: loads the scene, renders it pass by pass through
//! [`RenderJob`], publishes each pass's estimate, and starts again when a watched file changes.
//! A scene that does not load leaves the last good image on the page with the diagnostic.

use std::collections::BTreeSet;
use std::path::PathBuf;
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{Receiver, RecvTimeoutError};
use std::time::{Duration, Instant};

use caustic::pipeline::{Prepared, prepare};
use caustic::render::output::write_image;
use caustic::render::{RenderError, RenderJob, RenderOptions};
use caustic::render_scene::IntegratorKind;

use super::Settings;
use super::denoising::Denoising;
use super::frame::{Frame, noise};
use super::save::save;
use super::state::{Msg, Phase, Shared};
use super::watch::{FileWatch, asset_files};

/// How long a pass should take once the time per sample is known: short enough that the page
/// refines several times a second and that pause, save and restart answer at once.
const PASS_TARGET: Duration = Duration::from_millis(250);

/// How long the file system must stay quiet after a change before the scene is read again
/// (an editor's save can be several events: truncate, write, rename).
const SETTLE: Duration = Duration::from_millis(60);

/// How a render ended.
enum Next {
    /// A watched file changed: load again.
    Reload,
    /// Ctrl-C.
    Quit,
}

/// The render thread's state across restarts.
struct Session<'a> {
    settings: &'a Settings,
    shared: &'a Shared,
    rx: &'a Receiver<Msg>,
    watch: &'a mut FileWatch,
    /// The assets of the last scene that loaded (watched also while the scene is broken).
    assets: BTreeSet<PathBuf>,
    paused: bool,
    /// The denoised image's toggle and what it keeps of the current render.
    denoising: Denoising,
    /// The current render's cancel flag (the feature tracing of a denoised image stops on it).
    cancel: Option<Arc<AtomicBool>>,
}

/// Runs the render thread until Ctrl-C.
pub fn run(settings: &Settings, shared: &Shared, rx: &Receiver<Msg>, watch: &mut FileWatch) {
    let mut session = Session {
        settings,
        shared,
        rx,
        watch,
        assets: BTreeSet::new(),
        paused: false,
        denoising: Denoising::default(),
        cancel: None,
    };
    session.denoise(settings.denoise);
    while !shared.quit.load(Ordering::SeqCst) {
        let next = session.load_and_render();
        if matches!(next, Next::Quit) {
            break;
        }
    }
}

/// `text` with the scene's folder left out of the paths it names (`/home/me/x/scene.ron:3:5` →
/// `scene.ron:3:5`): the page shows where in the scene, `/status` never where the scene is.
fn without_folder(text: &str, scene: &std::path::Path) -> String {
    match scene.parent().map(|p| p.display().to_string()) {
        Some(folder) if !folder.is_empty() => text.replace(&format!("{folder}/"), ""),
        _ => text.to_string(),
    }
}

impl Session<'_> {
    fn load_and_render(&mut self) -> Next {
        let cancel = self.shared.new_cancel();
        {
            let mut s = self.shared.status();
            s.generation += 1;
            s.phase = Phase::Loading;
        }
        let prepared = match prepare(&self.settings.scene, &self.settings.overrides) {
            Ok(p) => p,
            Err(e) => return self.failed(crate::error_text(&e)),
        };
        self.assets = asset_files(&prepared.scene, &prepared.source.base_dir());
        self.watch_files();
        if !self.settings.quiet {
            super::super::print_warnings(&prepared.warnings);
        }
        if self.settings.stats {
            super::super::render::print_stats(&prepared.stats);
        }
        let samples = match self.settings.sample_range(&prepared) {
            Ok(s) => s,
            Err(text) => return self.failed(text),
        };
        let options = RenderOptions {
            threads: self.settings.threads,
            region: self.settings.region,
            progress: false,
            cancel: Some(Arc::clone(&cancel)),
            photon_cache: self.settings.photon_cache.clone(),
            samples,
            light_paths: true,
        };
        self.begin(&prepared);
        self.cancel = Some(cancel);
        self.denoising.restart();
        self.publish_denoise_state();
        let job = match RenderJob::new(&prepared.render_scene, &options) {
            Ok(job) => job,
            Err(e) => return self.failed(crate::error_text(&e.into())),
        };
        self.render(&prepared, job)
    }

    /// Watches the scene file and the last good scene's assets.
    fn watch_files(&mut self) {
        let files = std::iter::once(self.settings.scene.clone()).chain(self.assets.clone());
        for w in self.watch.set(files) {
            eprintln!("{w}");
        }
    }

    /// Shows the diagnostic `text` (keeping the last image) and waits for a change.
    fn failed(&mut self, text: String) -> Next {
        eprint!("{text}");
        if !text.ends_with('\n') {
            eprintln!();
        }
        {
            let mut s = self.shared.status();
            s.phase = Phase::Failed;
            s.error = Some(without_folder(&text, &self.settings.scene));
            // The figures stay those of the image shown (the last good one).
            let elapsed = s.started.elapsed();
            s.stopped.get_or_insert(elapsed);
        }
        self.watch_files();
        loop {
            match self.rx.recv() {
                Ok(Msg::Changed) => return self.settle(),
                Ok(Msg::Quit) | Err(_) => return Next::Quit,
                Ok(Msg::Pause(p)) => self.pause(p),
                Ok(Msg::Denoise(on)) => self.denoise(on),
                Ok(Msg::Save(reply)) => {
                    let _ = reply.send(Err(
                        "not saved: the scene has errors (see above); fix them first".into(),
                    ));
                }
            }
        }
    }

    /// After a change: waits until the files are quiet, answering requests meanwhile.
    fn settle(&mut self) -> Next {
        // An edit resumes a paused preview: the user wants to see it.
        self.pause(false);
        loop {
            match self.rx.recv_timeout(SETTLE) {
                Err(RecvTimeoutError::Timeout) => return Next::Reload,
                Err(RecvTimeoutError::Disconnected) | Ok(Msg::Quit) => return Next::Quit,
                Ok(Msg::Changed) => {}
                Ok(Msg::Pause(p)) => self.pause(p),
                Ok(Msg::Denoise(on)) => self.denoise(on),
                Ok(Msg::Save(reply)) => {
                    let _ = reply.send(Err(
                        "not saved: the scene changed and its render restarts".into()
                    ));
                }
            }
        }
    }

    fn pause(&mut self, paused: bool) {
        self.paused = paused;
        self.shared.status().paused = paused;
    }

    /// Turns the denoised image on or off (it is made after the next pass, or at once when the
    /// render is idle and has the sums for it).
    fn denoise(&mut self, on: bool) {
        self.denoising.set(on);
        self.publish_denoise_state();
    }

    /// The toggle, the denoised image's samples and the note, into the status.
    fn publish_denoise_state(&self) {
        let d = &self.denoising;
        let mut s = self.shared.status();
        s.denoise = d.on;
        s.denoised_spp = d.image.as_ref().map(|i| i.spp);
        s.denoise_note.clone_from(&d.note);
    }

    /// Resets the figures for a new render of `prepared` (before its photons are traced).
    fn begin(&self, prepared: &Prepared) {
        let p = &prepared.render_scene.params;
        let traces = matches!(
            p.integrator,
            IntegratorKind::Photon | IntegratorKind::Ppm | IntegratorKind::PathPpm
        );
        let region = self.settings.region;
        let mut s = self.shared.status();
        s.phase = Phase::Photons;
        s.started = Instant::now();
        s.stopped = None;
        s.preparing = if traces {
            // The counts the scene states (over the defaults), as before the settings were
            // resolved once; the default estimator's per-pass counts are in `params`.
            let ph = prepared.scene.photons.with_defaults();
            format!(
                "tracing photons ({} global, {} caustic asked for)",
                ph.global.unwrap_or_default(),
                ph.caustic.unwrap_or_default()
            )
        } else {
            "preparing the integrator".into()
        };
        s.error = None;
        s.photons = None;
        s.spp = 0;
        s.rays = 0;
        s.render_seconds = 0.0;
        s.noise = None;
        s.width = region.map_or(p.width, |r| r.width);
        s.height = region.map_or(p.height, |r| r.height);
        s.exposure = p.exposure;
    }

    /// Renders pass after pass until the samples (or the time budget) are done, answering the
    /// page's requests between passes; then waits for a change or Ctrl-C.
    fn render(&mut self, prepared: &Prepared, mut job: RenderJob<'_>) -> Next {
        let settings = self.settings;
        let first = job.samples_done();
        let goal = job.samples_per_pixel();
        let summary = job
            .integrator()
            .photon_maps()
            .map(|m| m.summary.to_string());
        if let (Some(text), false) = (&summary, settings.quiet) {
            eprintln!("{text}");
        }
        let start = Instant::now();
        {
            let mut s = self.shared.status();
            s.photons = summary;
            s.phase = Phase::Rendering;
            s.spp_goal = goal - first;
        }
        let exposure = prepared.render_scene.params.exposure;
        let (mut pass, mut render_time, mut done) = (1, Duration::ZERO, first == goal);
        let mut last_checkpoint = Instant::now();
        loop {
            let idle = self.paused || done;
            let msg = if idle {
                match self.rx.recv_timeout(Duration::from_millis(250)) {
                    Ok(m) => Some(m),
                    Err(RecvTimeoutError::Timeout) => None,
                    Err(RecvTimeoutError::Disconnected) => return Next::Quit,
                }
            } else {
                self.rx.try_recv().ok()
            };
            if let Some(msg) = msg {
                match msg {
                    Msg::Changed => return self.settle(),
                    Msg::Quit => return Next::Quit,
                    Msg::Pause(p) => self.pause(p),
                    Msg::Denoise(on) => {
                        self.denoise(on);
                        self.denoising.after_pass(&job, first, goal);
                    }
                    Msg::Save(reply) => {
                        let _ = reply.send(save(settings, prepared, &job, first, start));
                    }
                }
                continue;
            }
            if idle {
                // Paused or done: the denoised image of every sample, once.
                if self.make_denoised(prepared, &job, (first, goal), true) {
                    self.publish(&job, job.samples_done() - first, render_time);
                }
                continue;
            }
            let t = Instant::now();
            // Every render stops a pass at its middle sample index, where `render --denoise`
            // splits the samples in two halves, and keeps the sums there ([`Denoising`]).
            let this_pass = Denoising::cap_pass(pass, job.samples_done(), first, goal);
            match job.render_pass(this_pass) {
                Ok(()) => {}
                // Raised by a change (whose message is on its way) or by Ctrl-C.
                Err(RenderError::Cancelled) => {
                    if self.shared.quit.load(Ordering::SeqCst) {
                        return Next::Quit;
                    }
                    return match self.rx.recv_timeout(Duration::from_secs(1)) {
                        Ok(Msg::Quit) | Err(RecvTimeoutError::Disconnected) => Next::Quit,
                        _ => self.settle(),
                    };
                }
                Err(e) => return self.failed(crate::error_text(&e.into())),
            }
            render_time += t.elapsed();
            let taken = job.samples_done() - first;
            self.denoising.after_pass(&job, first, goal);
            self.make_denoised(prepared, &job, (first, goal), job.samples_done() == goal);
            self.publish(&job, taken, render_time);
            if let Some((path, every)) = &settings.checkpoint
                && last_checkpoint.elapsed() >= *every
            {
                if let Err(e) = write_image(&job.snapshot(), path, exposure) {
                    eprintln!("warning: checkpoint not saved: {e}");
                }
                last_checkpoint = Instant::now();
            }
            let per_sample = render_time.as_secs_f64() / f64::from(taken.max(1));
            let mut target = PASS_TARGET;
            if let Some(budget) = settings.time {
                let left = budget.saturating_sub(start.elapsed());
                if left.as_secs_f64() < per_sample {
                    done = true;
                }
                target = target.min(left);
            }
            if job.samples_done() == goal {
                done = true;
            }
            if done {
                let mut s = self.shared.status();
                s.phase = Phase::Done;
                s.stopped = Some(s.started.elapsed());
            }
            // Passes double up to the target time, so the first images come at once and the
            // page refines often; `as` saturates; at least one sample per pass.
            pass = ((target.as_secs_f64() / per_sample) as u32).clamp(1, pass.saturating_mul(2));
        }
    }

    /// Makes the denoised image if it is due ([`Denoising::make_if_due`]); `true` when it did.
    fn make_denoised(
        &mut self,
        prepared: &Prepared,
        job: &RenderJob<'_>,
        span: (u32, u32),
        idle: bool,
    ) -> bool {
        let cancel = self.cancel.clone();
        let made =
            self.denoising
                .make_if_due(prepared, job, span, idle, self.settings, cancel.as_deref());
        self.publish_denoise_state();
        made
    }

    /// Publishes the estimate after a pass and its figures.
    fn publish(&self, job: &RenderJob<'_>, taken: u32, render_time: Duration) {
        let generation = self.shared.status().generation;
        let denoised = self
            .denoising
            .on
            .then(|| self.denoising.image.clone())
            .flatten();
        let frame = Frame::new(job.sums(), job.parts(), taken, generation, denoised);
        let n = noise(job.sums()).map(|n| (n.rms, n.mean));
        {
            let mut s = self.shared.status();
            s.spp = taken;
            s.rays = job.rays_traced();
            s.render_seconds = render_time.as_secs_f64();
            s.noise = n;
        }
        self.shared.set_frame(frame);
    }
}

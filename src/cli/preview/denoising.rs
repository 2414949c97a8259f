//! The preview's denoised image (the page's toggle, `d`; `POST /denoise`; `--denoise` starts
//! with it on): the render's samples denoised as `render --denoise` does (docs/denoise.md),
//! remade each time the samples per pixel double, and once more when the render ends or
//! pauses.
//!
//! The denoiser compares two halves of the samples: the sums at some earlier pass end (a
//! [`Snapshot`]) and the rest (the sums now less that). The passes always stop at the
//! render's middle sample index and keep the sums there, so the finished render's denoised
//! image takes the same halves as `render --denoise` — the same bytes as its output — and a
//! toggle turned on after the render ended still finds them. Before that, the first half is
//! the sums when the last denoised image was made (or the toggle turned on), so each half has
//! about as many samples as the other when the samples have doubled.

use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use caustic::denoise::DenoiseParams;
use caustic::pipeline::Prepared;
use caustic::render::denoised::{FirstHalf, denoise_render};
use caustic::render::{Features, RenderError, RenderJob};

use super::Settings;
use super::frame::Denoised;

/// The sums of a render at a pass end.
#[derive(Debug, Clone)]
struct Snapshot {
    /// One past the last sample index in it.
    end: u32,
    /// Its sums (and light-path layers).
    half: FirstHalf,
}

impl Snapshot {
    fn of(job: &RenderJob<'_>) -> Self {
        Self {
            end: job.samples_done(),
            half: FirstHalf {
                sums: job.sums().clone(),
                parts: job.parts().map(<[_]>::to_vec),
            },
        }
    }
}

/// The denoised image's state across one render's passes.
#[derive(Debug, Default)]
pub struct Denoising {
    /// Whether the toggle is on.
    pub on: bool,
    /// The sums at the render's middle sample index, once the passes reached it.
    middle: Option<Snapshot>,
    /// The sums when the last denoised image was made (or the toggle turned on).
    last: Option<Snapshot>,
    /// The latest denoised image of this render.
    pub image: Option<Denoised>,
    /// Why the last attempt made no image (shown on the page).
    pub note: Option<String>,
}

/// `render --denoise`'s split of the sample indices `first..goal`: the first half is below it.
pub fn middle(first: u32, goal: u32) -> u32 {
    first + (goal - first) / 2
}

impl Denoising {
    /// Forgets the last render's sums and image (the toggle stays as it is).
    pub fn restart(&mut self) {
        *self = Self {
            on: self.on,
            ..Self::default()
        };
    }

    /// Turns the toggle on or off; off forgets the in-between sums (not the middle ones).
    pub fn set(&mut self, on: bool) {
        self.on = on;
        if on {
            self.note = None;
        } else {
            self.last = None;
        }
    }

    /// At most `pass` samples, fewer so that the pass ends at the middle sample index.
    pub fn cap_pass(pass: u32, done: u32, first: u32, goal: u32) -> u32 {
        let mid = middle(first, goal);
        if done < mid {
            pass.min(mid - done)
        } else {
            pass
        }
    }

    /// Keeps the sums a later denoised image needs, after a pass of `job` (samples from
    /// `first` to `goal`).
    pub fn after_pass(&mut self, job: &RenderJob<'_>, first: u32, goal: u32) {
        let done = job.samples_done();
        if done == middle(first, goal) && self.middle.is_none() && done > first {
            self.middle = Some(Snapshot::of(job));
        }
        if self.on && self.last.is_none() && done > first {
            self.last = Some(Snapshot::of(job));
        }
    }

    /// The first half to denoise `job` with now, if a denoised image is due: none yet (or
    /// the last one is of fewer than half the samples taken, or `idle` and of fewer than
    /// all), and sums of an earlier pass end exist. At the end (`done == goal`) the middle's.
    fn due(&self, job: &RenderJob<'_>, first: u32, goal: u32, idle: bool) -> Option<&Snapshot> {
        let done = job.samples_done();
        let taken = done - first;
        if !self.on || taken < 2 {
            return None;
        }
        let shown = self.image.as_ref().map_or(0, |d| d.spp);
        if !(shown == 0 || taken >= 2 * shown || (idle && shown != taken)) {
            return None;
        }
        if done == goal
            && let Some(m) = &self.middle
        {
            return Some(m);
        }
        // Of the earlier sums, those nearest to half the samples taken.
        let half = first + taken / 2;
        [self.middle.as_ref(), self.last.as_ref()]
            .into_iter()
            .flatten()
            .filter(|s| s.end > first && s.end < done)
            .min_by_key(|s| s.end.abs_diff(half))
    }

    /// Makes the denoised image of `job` (samples `first..`) if one is due; `true` when it did.
    /// Traces the feature buffers over the samples taken (stopped by `cancel`, as the pass).
    pub fn make_if_due(
        &mut self,
        prepared: &Prepared,
        job: &RenderJob<'_>,
        span: (u32, u32),
        idle: bool,
        settings: &Settings,
        cancel: Option<&AtomicBool>,
    ) -> bool {
        let threads = settings.threads;
        let (first, goal) = span;
        if self.on && job.samples_done() - first < 2 {
            self.note =
                Some("waiting for 2 samples per pixel (the denoiser compares two halves)".into());
        }
        let Some(snapshot) = self.due(job, first, goal, idle) else {
            return false;
        };
        let done = job.samples_done();
        let features = Features::trace(
            &prepared.render_scene,
            settings.region,
            first..done,
            snapshot.end,
            threads,
            cancel,
        );
        let features = match features {
            Ok(f) => f,
            // A change or Ctrl-C: the render thread hears of it next.
            Err(RenderError::Cancelled) => return false,
            Err(e) => {
                self.note = Some(format!("not denoised: {e}"));
                self.on = false;
                return false;
            }
        };
        let started = Instant::now();
        let film = denoise_render(
            job.sums(),
            job.parts(),
            &snapshot.half,
            &features,
            &DenoiseParams::default(),
            threads,
        );
        match film {
            Ok(film) => {
                self.note = Some(format!(
                    "denoised {} spp (halves {} + {}) in {:.2} s",
                    done - first,
                    snapshot.end - first,
                    done - snapshot.end,
                    started.elapsed().as_secs_f64()
                ));
                self.image = Some(Denoised {
                    film: Arc::new(film),
                    spp: done - first,
                });
                self.last = (done < goal).then(|| Snapshot::of(job));
                true
            }
            Err(e) => {
                self.note = Some(format!("not denoised: {e}"));
                self.on = false;
                false
            }
        }
    }
}

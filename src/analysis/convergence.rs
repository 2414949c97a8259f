//! Error against time for one integrator (`caustic converge`): the scene rendered
//! progressively, and at 1, 2, 4, 8, … samples per pixel the image so far compared with a
//! reference (the film after n samples is bit-identical to a fresh render at n samples, so one
//! progressive render gives the whole series for the time of its last point). The series
//! doubles until the integrator's share of the time would be overrun ([`measure`]); its slopes
//! are fitted log-log ([`super::slope`]) and the points written as CSV ([`csv`]).

use std::fmt::Write as _;
use std::path::Path;
use std::time::{Duration, Instant};

use super::metrics::{CompareError, ImageError, Reference};
use super::slope::log_log_slope;
use crate::render::{Film, RenderError, RenderJob, RenderOptions};
use crate::render_scene::RenderScene;
use crate::settings::IntegratorKind;

/// Why a series could not be measured.
#[derive(Debug, thiserror::Error)]
pub enum ConvergeError {
    /// The reference's size is not the scene's.
    #[error(
        "the reference `{}` is {}×{} but the scene renders {}×{}; give --width {} --height {} or a reference of the scene's size",
        path.display(), reference.0, reference.1, scene.0, scene.1, reference.0, reference.1
    )]
    Size {
        /// The reference file.
        path: std::path::PathBuf,
        /// Its width and height in pixels.
        reference: (u32, u32),
        /// The scene's width and height in pixels.
        scene: (u32, u32),
    },
    /// A snapshot could not be compared with the reference.
    #[error(transparent)]
    Compare(#[from] CompareError),
    /// The render failed.
    #[error(transparent)]
    Render(#[from] RenderError),
}

impl From<ConvergeError> for crate::Error {
    fn from(e: ConvergeError) -> Self {
        match e {
            ConvergeError::Render(r) => crate::Error::Render(r),
            other => crate::Error::Usage(other.to_string()),
        }
    }
}

/// One measurement: the image after `spp` samples per pixel.
#[derive(Debug, Clone, Copy)]
pub struct Point {
    /// Samples per pixel.
    pub spp: u32,
    /// Render time to reach it in seconds (scene loading and comparisons excluded).
    pub seconds: f64,
    /// The image's error against the reference.
    pub error: ImageError,
}

/// One integrator's series.
#[derive(Debug, Clone)]
pub struct Series {
    /// The integrator measured.
    pub integrator: IntegratorKind,
    /// The points, fewest samples first.
    pub points: Vec<Point>,
    /// Rays traced over the whole series.
    pub rays: u64,
    /// Seconds from the scene's preparation to the render job's start (photon maps
    /// included).
    pub prepare_seconds: f64,
}

impl Series {
    /// The integrator's command-line name.
    #[must_use]
    pub fn name(&self) -> String {
        self.integrator.cli_name().to_string()
    }

    /// Slope of RMSE against wall time (log-log).
    #[must_use]
    pub fn time_slope(&self) -> Option<f64> {
        log_log_slope(self.points.iter().map(|p| (p.seconds, p.error.rmse)))
    }

    /// Slope of RMSE against samples per pixel (log-log).
    #[must_use]
    pub fn spp_slope(&self) -> Option<f64> {
        log_log_slope(self.points.iter().map(|p| (f64::from(p.spp), p.error.rmse)))
    }
}

/// Renders the series of `scene` (compiled with `integrator` and a cap of samples per pixel)
/// on `threads` workers against `reference`, doubling the samples per pixel while the next
/// point fits in `share`; `started` is when the scene's preparation began, `on_point` hears
/// of each point (and the render time so far) as it is measured. Returns the series and the
/// last film.
///
/// # Errors
/// [`ConvergeError::Size`] when the reference is not the scene's size; a comparison's or the
/// render's errors.
pub fn measure(
    scene: &RenderScene,
    integrator: IntegratorKind,
    reference: &Reference,
    share: Duration,
    threads: Option<usize>,
    started: Instant,
    on_point: &mut dyn FnMut(&Point, Duration),
) -> Result<(Series, Film), ConvergeError> {
    let params = &scene.params;
    let size = (reference.film.width, reference.film.height);
    if (params.width, params.height) != size {
        return Err(ConvergeError::Size {
            path: reference.path.clone(),
            reference: size,
            scene: (params.width, params.height),
        });
    }
    let options = RenderOptions {
        threads,
        ..RenderOptions::default()
    };
    let mut job = RenderJob::new(scene, &options)?;
    let prepare_seconds = started.elapsed().as_secs_f64();
    let name = integrator.cli_name();
    let cap = job.samples_per_pixel();
    let mut points = Vec::new();
    let mut render_time = Duration::ZERO;
    let mut target = 1u32;
    loop {
        let t = Instant::now();
        job.render_pass(target - job.samples_done())?;
        render_time += t.elapsed();
        let film = job.snapshot();
        let c = reference.compare(&film, Path::new(&name), params.exposure, None)?;
        let point = Point {
            spp: target,
            seconds: render_time.as_secs_f64(),
            error: c.error,
        };
        points.push(point);
        on_point(&point, render_time);
        if target >= cap {
            break;
        }
        let next = target.saturating_mul(2).min(cap);
        let per_sample = render_time.as_secs_f64() / f64::from(target);
        if render_time.as_secs_f64() + per_sample * f64::from(next - target) > share.as_secs_f64() {
            break;
        }
        target = next;
    }
    let out = job.into_output();
    let series = Series {
        integrator,
        points,
        rays: out.stats.rays,
        prepare_seconds,
    };
    Ok((series, out.film))
}

/// The series as CSV: a header, then one row a point (integrator, samples per pixel, seconds,
/// the error figures and the RMSE per channel).
#[must_use]
pub fn csv(series: &[Series]) -> String {
    let mut s = String::from(
        "integrator,spp,seconds,rmse,rel_mse,mae,bias,max_abs,rmse_red,rmse_green,rmse_blue\n",
    );
    for ser in series {
        for p in &ser.points {
            let e = &p.error;
            let _ = writeln!(
                s,
                "{},{},{:.6},{:.8},{:.8},{:.8},{:.8},{:.8},{:.8},{:.8},{:.8}",
                ser.name(),
                p.spp,
                p.seconds,
                e.rmse,
                e.rel_mse,
                e.mae,
                e.mean_bias,
                e.max_abs,
                e.channels[0].rmse,
                e.channels[1].rmse,
                e.channels[2].rmse
            );
        }
    }
    s
}

//! The pass driver: renders a [`RenderJob`] in passes of samples per pixel, saving checkpoints
//! between passes and stopping when a time budget is spent. Every command that renders
//! (render, and later convergence reports and farm shards) goes through here, so passes,
//! cancellation, checkpoints and budgets behave the same everywhere. The finished image never
//! depends on how the samples were split into passes (the film's sums are exact).

use std::path::Path;
use std::time::{Duration, Instant};

use indicatif::{ProgressBar, ProgressDrawTarget, ProgressStyle};

use super::adaptive::AdaptivePlan;
use super::auto_exposure::resolve;
use super::denoised::FirstHalf;
use super::error_estimate::ErrorEstimate;
use super::output::write_image;
use super::tonemap::Display;
use super::{RenderError, RenderJob, RenderOutput};

/// Where and how often the image so far is saved.
#[derive(Debug, Clone, Copy)]
pub struct CheckpointPlan<'a> {
    /// The checkpoint image (.png or .exr), replaced atomically at each save.
    pub path: &'a Path,
    /// Least time between saves (zero: after every pass).
    pub every: Duration,
    /// Exposure and tone curve for 8-bit checkpoints.
    pub display: Display,
    /// Whether the exposure is automatic: each 8-bit checkpoint then gets its own snapshot's
    /// ([`super::auto_exposure::AutoExposure::of_film`]) instead of `display.exposure`.
    pub auto_exposure: bool,
}

/// How to split a render into passes.
#[derive(Debug, Clone, Copy, Default)]
pub struct PassPlan<'a> {
    /// Save the image so far between passes.
    pub checkpoint: Option<CheckpointPlan<'a>>,
    /// Stop starting passes once this much time is spent (the image then has as many samples
    /// per pixel as the passes that fitted; at least one). `None`: take every sample.
    pub time_budget: Option<Duration>,
    /// Show a time-based progress bar on stderr (for budgeted renders).
    pub progress: bool,
    /// Stop once the estimated relMSE of the image ([`ErrorEstimate`]) is at most this
    /// (`--target-error`), or when the time budget or the samples per pixel run out first.
    pub target_error: Option<f64>,
    /// Adaptive sampling ([`super::adaptive`]): rounds in which each pixel takes samples while
    /// its own estimated error is above the plan's threshold. The render then ends when no
    /// pixel needs more (or at the samples per pixel, the budget, or — with a target error —
    /// once both the image's and its worst 1 %'s estimates reach it).
    pub adaptive: Option<AdaptivePlan>,
    /// Keep a first half of the samples for the denoiser when the render's length is not
    /// known in advance (a time budget or a target error): passes end at the marks of
    /// [`is_half_mark`], the sums are kept at each, and the outcome's
    /// [`PassesOutcome::first_half`] is the one at the last mark at most half the samples
    /// taken. Not with `adaptive` (ignored there: its pixels take different samples).
    pub halves: bool,
}

/// The result of a render in passes.
#[derive(Debug)]
pub struct PassesOutcome {
    /// The finished (or budget-stopped) render, or why it stopped.
    pub result: Result<RenderOutput, RenderError>,
    /// Samples per pixel of the last checkpoint written, if any.
    pub checkpoint_spp: Option<u32>,
    /// With a target error: the estimate after the last pass, and whether it reached the
    /// target.
    pub error: Option<(ErrorEstimate, bool)>,
    /// With [`PassPlan::halves`]: the samples per pixel of the first half (counted from the
    /// job's first sample) and its sums; `None` when fewer than 2 samples were taken.
    pub first_half: Option<(u32, FirstHalf)>,
}

/// Whether a pass may end at `n` samples with the sums kept for a denoiser's first half: `n`
/// is a power of two or three times one (1, 2, 3, 4, 6, 8, 12, 16, …). Consecutive marks are
/// at most 1.5× apart, so the last mark at most half of a render's `N` samples is at least
/// `N/3`: the halves hold between a third and a half, and half and two thirds, of the samples.
/// Marks thin out geometrically, so a render stops at only about `2 log₂ N` extra pass ends.
#[must_use]
pub fn is_half_mark(n: u32) -> bool {
    n > 0 && (n.is_power_of_two() || (n.is_multiple_of(3) && (n / 3).is_power_of_two()))
}

/// The first mark of [`is_half_mark`] above `n` (saturating at `u32::MAX`).
#[must_use]
pub fn next_half_mark(n: u32) -> u32 {
    // The least power of two above n, and the least 3·2^k above n (2^k > n/3).
    let power = n.checked_add(1).and_then(u32::checked_next_power_of_two);
    let triple = (n / 3 + 1)
        .checked_next_power_of_two()
        .and_then(|p| p.checked_mul(3));
    match (power, triple) {
        (Some(a), Some(b)) => a.min(b),
        (Some(a), None) | (None, Some(a)) => a,
        (None, None) => u32::MAX,
    }
}

/// What is kept at the marks of [`is_half_mark`] while a render's length is not known (the
/// sums, a [`FirstHalf`]): only what can still be the first half (the last mark at most half
/// the samples so far, and every later one), so at most three.
#[derive(Debug)]
struct HalfMarks<T> {
    kept: Vec<(u32, T)>,
}

impl<T> HalfMarks<T> {
    fn new() -> Self {
        Self { kept: Vec::new() }
    }

    /// Keeps `keep()` when `done` (samples since the first) is a mark, and drops what can no
    /// longer be the first half.
    fn after_pass(&mut self, done: u32, keep: impl FnOnce() -> T) {
        if is_half_mark(done) {
            self.kept.push((done, keep()));
        }
        if let Some(best) = self.best(done) {
            self.kept.retain(|&(n, _)| n >= best);
        }
    }

    /// The count of the last kept mark at most half of `done`.
    fn best(&self, done: u32) -> Option<u32> {
        self.kept
            .iter()
            .map(|&(n, _)| n)
            .filter(|&n| n <= done / 2)
            .max()
    }

    /// The first half for a render of `done` samples.
    fn take(mut self, done: u32) -> Option<(u32, T)> {
        let best = self.best(done)?;
        let i = self.kept.iter().position(|&(n, _)| n == best)?;
        Some(self.kept.swap_remove(i))
    }
}

/// The shortest pass worth scheduling (a pass costs a sweep over the tiles).
const MIN_PASS: Duration = Duration::from_millis(500);

/// Renders `job` in passes following `plan`. The first pass is one sample per pixel; later
/// ones are sized from the measured time per sample to end near the next checkpoint or the
/// end of the budget, never past the job's samples per pixel. A budgeted render stops when the
/// next sample per pixel would overrun the budget.
#[must_use]
pub fn render_in_passes(mut job: RenderJob<'_>, plan: &PassPlan<'_>) -> PassesOutcome {
    if let Some(adaptive) = plan.adaptive {
        return adaptive_rounds(job, plan, adaptive);
    }
    let spp = job.samples_per_pixel();
    let first = job.samples_done();
    let start = Instant::now();
    let bar = budget_bar(plan);
    let mut saved = None;
    let mut last_save = Instant::now();
    let mut render_time = Duration::ZERO;
    let mut pass = 1;
    let mut error = None;
    let mut marks = plan.halves.then(HalfMarks::new);
    let fail = |e, saved| PassesOutcome {
        result: Err(e),
        checkpoint_spp: saved,
        error: None,
        first_half: None,
    };
    while job.samples_done() < spp {
        let t = Instant::now();
        if let Err(e) = job.render_pass(pass) {
            return fail(e, saved);
        }
        render_time += t.elapsed();
        let end = job.samples_done();
        let done = end - first;
        if let Some(m) = &mut marks {
            m.after_pass(done, || FirstHalf {
                sums: job.sums().clone(),
                parts: job.parts().map(<[_]>::to_vec),
            });
        }
        let estimate = plan.target_error.map(|target| {
            let e = ErrorEstimate::of_sums(job.sums());
            (e, e.reached(target))
        });
        error = estimate;
        if let (Some(b), Some(budget)) = (&bar, plan.time_budget) {
            b.set_position(start.elapsed().min(budget).as_millis() as u64);
            b.set_message(match estimate {
                Some((e, _)) => format!("{done} spp, estimated relMSE {:.4}", e.image),
                None => format!("{done} spp"),
            });
        }
        if end == spp || estimate.is_some_and(|(_, reached)| reached) {
            break;
        }
        let per_sample = render_time.as_secs_f64() / f64::from(done);
        let mut target = Duration::MAX;
        if let Some(budget) = plan.time_budget {
            let left = budget.saturating_sub(start.elapsed());
            if left.as_secs_f64() < per_sample {
                break;
            }
            // At most a tenth of the budget per pass: if the machine slows down (other work on
            // its cores), the budget is overrun by at most one short pass.
            target = left.min((budget / 10).max(MIN_PASS));
        }
        if let Some(cp) = &plan.checkpoint {
            if last_save.elapsed() >= cp.every {
                if save_checkpoint(&job, cp) {
                    saved = Some(done);
                }
                last_save = Instant::now();
            }
            let to_save = cp.every.saturating_sub(last_save.elapsed()).max(MIN_PASS);
            target = target.min(to_save);
        }
        // `as` saturates, and a huge estimate only asks for everything left.
        pass = if target == Duration::MAX {
            spp - end
        } else {
            ((target.as_secs_f64() / per_sample) as u32).max(1)
        };
        if let (Some((e, _)), Some(goal)) = (estimate, plan.target_error) {
            pass = pass.min(samples_towards(e, goal, done));
        }
        if marks.is_some() {
            pass = pass.min(next_half_mark(done) - done);
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    let done = job.samples_done() - first;
    PassesOutcome {
        result: Ok(job.into_output()),
        checkpoint_spp: saved,
        error,
        first_half: marks.and_then(|m| m.take(done)),
    }
}

/// Writes the image so far to the checkpoint; false (with a warning) when it cannot.
fn save_checkpoint(job: &RenderJob<'_>, cp: &CheckpointPlan<'_>) -> bool {
    let snapshot = job.snapshot();
    let stated = (!cp.auto_exposure).then_some(cp.display.exposure);
    let (display, _) = resolve(&snapshot, stated, cp.display.tonemap);
    match write_image(&snapshot, cp.path, display) {
        Ok(()) => true,
        Err(e) => {
            eprintln!("warning: checkpoint not saved: {e}");
            false
        }
    }
}

/// [`render_in_passes`] for an adaptive render: round after round of
/// [`AdaptivePlan::round`] and [`AdaptivePlan::counts`], each decided from the film after the
/// previous one (never from the time), so the image does not depend on when checkpoints are
/// saved; a budget stops it between rounds, before a round its measured time per sample says
/// would overrun.
fn adaptive_rounds(
    mut job: RenderJob<'_>,
    plan: &PassPlan<'_>,
    adaptive: AdaptivePlan,
) -> PassesOutcome {
    let spp = job.samples_per_pixel();
    let start = Instant::now();
    let bar = budget_bar(plan);
    let (mut saved, mut last_save) = (None, Instant::now());
    let (mut render_time, mut taken) = (Duration::ZERO, 0u64);
    let mut error = None;
    let pixels = (job.sums().width as usize * job.sums().height as usize).max(1);
    loop {
        let indices = adaptive.round(job.next_index(), spp);
        let counts = adaptive.counts(job.sums(), &indices);
        let round: u64 = counts.iter().map(|&c| u64::from(c)).sum();
        if round == 0 {
            break;
        }
        if let Some(budget) = plan.time_budget
            && taken > 0
        {
            let per_sample = render_time.as_secs_f64() / taken as f64;
            let left = budget.saturating_sub(start.elapsed()).as_secs_f64();
            if per_sample * round as f64 > left {
                break;
            }
        }
        let t = Instant::now();
        if let Err(e) = job.render_round(indices, &counts) {
            return PassesOutcome {
                result: Err(e),
                checkpoint_spp: saved,
                error: None,
                first_half: None,
            };
        }
        render_time += t.elapsed();
        taken += round;
        let mean_spp = taken as f64 / pixels as f64;
        let estimate = plan.target_error.map(|target| {
            let e = ErrorEstimate::of_sums(job.sums());
            (e, e.reached_everywhere(target))
        });
        error = estimate;
        if let (Some(b), Some(budget)) = (&bar, plan.time_budget) {
            b.set_position(start.elapsed().min(budget).as_millis() as u64);
            b.set_message(match estimate {
                Some((e, _)) => format!(
                    "{mean_spp:.1} spp (mean), estimated relMSE {:.4}, worst 1 % {:.4}",
                    e.image, e.worst
                ),
                None => format!("{mean_spp:.1} spp (mean)"),
            });
        }
        if estimate.is_some_and(|(_, reached)| reached) {
            break;
        }
        if let Some(cp) = &plan.checkpoint
            && last_save.elapsed() >= cp.every
        {
            if save_checkpoint(&job, cp) {
                saved = Some(mean_spp.round() as u32);
            }
            last_save = Instant::now();
        }
    }
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    if error.is_none()
        && let Some(target) = plan.target_error
    {
        let e = ErrorEstimate::of_sums(job.sums());
        error = Some((e, e.reached_everywhere(target)));
    }
    PassesOutcome {
        result: Ok(job.into_output()),
        checkpoint_spp: saved,
        error,
        first_half: None,
    }
}

/// The next pass's samples per pixel towards a target error: the estimate falls as 1/n, so
/// `done · estimate / target` samples in all are expected to reach it; a pass takes the
/// difference, at least one sample and at most as many as are done (the estimate from few
/// samples is itself noisy, so the render at most doubles before looking again). Until every
/// pixel has [`super::error_estimate::MIN_SAMPLES`], passes just fill up to that.
fn samples_towards(e: ErrorEstimate, target: f64, done: u32) -> u32 {
    use super::error_estimate::MIN_SAMPLES;
    if e.min_samples < MIN_SAMPLES {
        return (MIN_SAMPLES - e.min_samples).max(1);
    }
    let needed = f64::from(done) * e.image / target.max(f64::MIN_POSITIVE);
    // `as` saturates.
    ((needed - f64::from(done)).ceil() as u32).clamp(1, done.max(1))
}

fn budget_bar(plan: &PassPlan<'_>) -> Option<ProgressBar> {
    let budget = plan.time_budget?;
    if !plan.progress {
        return None;
    }
    let bar = ProgressBar::with_draw_target(
        Some(budget.as_millis() as u64),
        ProgressDrawTarget::stderr(),
    );
    if let Ok(style) = ProgressStyle::with_template(
        "{spinner} rendering [{bar:40}] {elapsed} of the budget, {msg}",
    ) {
        bar.set_style(style.progress_chars("=> "));
    }
    Some(bar)
}

#[cfg(test)]
mod half_mark_tests {
    use super::*;

    #[test]
    fn the_marks_are_the_powers_of_two_and_three_times_them() {
        let marks: Vec<u32> = (0..=50).filter(|&n| is_half_mark(n)).collect();
        assert_eq!(marks, [1, 2, 3, 4, 6, 8, 12, 16, 24, 32, 48]);
        assert_eq!(next_half_mark(0), 1);
        assert_eq!(next_half_mark(4), 6);
        assert_eq!(next_half_mark(6), 8);
        assert_eq!(next_half_mark(47), 48);
        assert_eq!(next_half_mark(1 << 30), 3 << 29);
        assert_eq!(next_half_mark(1 << 31), 3 << 30);
        assert_eq!(next_half_mark(3 << 30), u32::MAX);
        for n in 0..100_000 {
            let next = (n + 1..).find(|&m| is_half_mark(m)).unwrap_or(u32::MAX);
            assert_eq!(next_half_mark(n), next, "{n}");
        }
        assert_eq!(next_half_mark(u32::MAX), u32::MAX);
    }

    /// Passes end at every mark (as `render_in_passes` clips them) and at other counts too;
    /// whatever the render's length `N ≥ 2`, the first half is the last mark at most `N/2`,
    /// at least `N/3` (the bound of [`is_half_mark`]), and never more than three are kept.
    #[test]
    fn the_first_half_is_the_last_mark_at_most_half_and_at_least_a_third() {
        for end in 1..3000u32 {
            let mut marks = HalfMarks::new();
            let mut done = 0;
            while done < end {
                // Passes of 1, 2, 3, … samples, clipped at the next mark and at the end.
                let pass = (done % 7 + 1)
                    .min(next_half_mark(done) - done)
                    .min(end - done);
                done += pass;
                marks.after_pass(done, || done);
                assert!(marks.kept.len() <= 3, "{end}: kept {:?}", marks.kept);
                assert!(marks.kept.iter().all(|&(n, v)| n == v));
            }
            match marks.take(end) {
                None => assert_eq!(end, 1),
                Some((n, _)) => {
                    assert!(
                        is_half_mark(n) && 2 * n <= end && 3 * n >= end,
                        "{end}: {n}"
                    );
                    assert!(!is_half_mark(next_half_mark(n)) || 2 * next_half_mark(n) > end);
                }
            }
        }
    }
}

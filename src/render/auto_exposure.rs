//! The automatic exposure of 8-bit images: what a scene that states no `render.exposure` is
//! written with (issue #43). EXR output stays linear and never goes through it.
//!
//! The exposure follows the *key* of Reinhard, Stark, Shirley & Ferwerda (2002), "Photographic
//! Tone Reproduction for Digital Images" (SIGGRAPH), eq. 1–2: the log-average luminance
//! `L̄ = exp(Σ ln(δ + L(x, y)) / N)` is the image's "middle grey", and scaling it to the key
//! `a = 0.18` (a normal-key scene) gives the exposure `a / L̄`. A scene with a small bright
//! part (a sunlit patch, a lamp seen directly) would then clip that part; Reinhard's global
//! operator compresses it with `L / (1 + L)`, which changes today's curves. Instead the
//! exposure is lowered, when needed, so that at most [`MAX_CLIPPED_FRACTION`] of the pixels
//! reach white under the chosen tone curve (a clip guard at the 99th percentile of each pixel's
//! brightest channel; by at most [`MAX_GUARD_FACTOR`]), so the tone curves themselves stay what
//! they were. Unless the scene states one, the curve of an automatic exposure is ACES
//! ([`tonemap_for`]).
//!
//! The figure is computed from the finished film alone, with fixed-order sums and a sort, so it
//! is the same for any thread count (the film's bytes are); a checkpoint gets its own
//! snapshot's. A `--region` crop gets its crop's own exposure (the summary prints it; state
//! `--exposure` to match a full render's).

use super::Film;
use super::output::srgb_encode;
use super::tonemap::{Display, Tonemap};

/// Reinhard et al.'s key value of a normal-key scene: the log-average luminance is mapped to
/// this (scene-referred middle grey).
pub const KEY: f32 = 0.18;
/// Reinhard et al.'s δ of the log average (avoids ln 0 on black pixels); in the film's
/// radiance units.
pub const LOG_DELTA: f64 = 1.0e-4;
/// Most pixels an automatic exposure lets reach white (8-bit 255 in some channel).
pub const MAX_CLIPPED_FRACTION: f64 = 0.01;

/// Most the clip guard lowers the key's exposure by (four stops). A scene whose brightest
/// 1 % is more than that over its key (a window onto a bright sky, a lamp filling part of the
/// frame) keeps some white pixels rather than going dark everywhere else; the summary then
/// says how many clip.
pub const MAX_GUARD_FACTOR: f32 = 16.0;

/// Rec. 709 luminance of linear RGB.
#[inline]
#[must_use]
pub fn luminance(c: glam::Vec3) -> f32 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// The exposure chosen for an image, and why (for the render summary).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AutoExposure {
    /// The exposure applied (linear scale before the tone curve).
    pub exposure: f32,
    /// Reinhard's log-average luminance `L̄` of the film (radiance units).
    pub log_average: f32,
    /// `KEY / L̄`, the exposure before the clip guard.
    pub key_exposure: f32,
    /// The brightest channel of the pixel at the 99th percentile (radiance units).
    pub p99: f32,
    /// Whether the clip guard lowered the exposure below `key_exposure`.
    pub clip_limited: bool,
    /// Whether the guard would have lowered it by more than [`MAX_GUARD_FACTOR`] and was held
    /// there (more than 1 % of the pixels then clip).
    pub guard_capped: bool,
}

impl AutoExposure {
    /// The automatic exposure of `film` under `tonemap`: `KEY / L̄`, lowered so that at most
    /// [`MAX_CLIPPED_FRACTION`] of the pixels clip. Non-finite and negative pixels count as
    /// black. An all-black (or empty) film gets exposure 1.
    #[must_use]
    pub fn of_film(film: &Film, tonemap: Tonemap) -> Self {
        let n = film.pixels.len();
        let clean = |v: f32| if v.is_finite() && v > 0.0 { v } else { 0.0 };
        // Fixed order: pixel order, in f64.
        let log_sum: f64 = film
            .pixels
            .iter()
            .map(|p| (LOG_DELTA + f64::from(clean(luminance(*p)))).ln())
            .sum();
        let log_average = if n == 0 {
            0.0
        } else {
            ((log_sum / n as f64).exp() - LOG_DELTA).max(0.0) as f32
        };
        let mut brightest: Vec<f32> = film
            .pixels
            .iter()
            .map(|p| clean(p.x).max(clean(p.y)).max(clean(p.z)))
            .collect();
        let lit = brightest.iter().any(|&b| b > 0.0);
        // At most `allowed` pixels may be at or above white: the one just below them sets it
        // (an order statistic: a selection, not a sort, finds it).
        let allowed = (n as f64 * MAX_CLIPPED_FRACTION).floor() as usize;
        let p99 = n
            .checked_sub(allowed + 1)
            .filter(|&i| i < brightest.len())
            .map_or(0.0, |i| {
                *brightest.select_nth_unstable_by(i, f32::total_cmp).1
            });
        let key_exposure = if lit && log_average > 0.0 {
            KEY / log_average
        } else {
            1.0
        };
        let white = white_point(tonemap);
        // A margin of 0.1 % keeps the guard pixel itself below white after rounding.
        let guard = if lit && p99 > 0.0 {
            0.999 * white / p99
        } else {
            f32::INFINITY
        };
        let exposure = key_exposure.min(guard).max(key_exposure / MAX_GUARD_FACTOR);
        Self {
            exposure,
            log_average,
            key_exposure,
            p99,
            clip_limited: guard < key_exposure,
            guard_capped: guard < key_exposure / MAX_GUARD_FACTOR,
        }
    }

    /// The summary's phrase, e.g. `exposure 0.45 (automatic: key 0.18 over the log-average
    /// luminance 0.40)` or `…; lowered from 1.20 so at most 1 % of the pixels clip`.
    #[must_use]
    pub fn describe(&self) -> String {
        let base = format!(
            "exposure {:.3} (automatic: key {KEY} over the log-average luminance {:.4}",
            self.exposure, self.log_average
        );
        if self.guard_capped {
            format!(
                "{base}; lowered from {:.3} by the most allowed, {MAX_GUARD_FACTOR}×: the brightest 1 % of the image is brighter still, and clips); `--exposure X` sets it",
                self.key_exposure
            )
        } else if self.clip_limited {
            format!(
                "{base}; lowered from {:.3} so at most {} % of the pixels clip); `--exposure X` sets it",
                self.key_exposure,
                MAX_CLIPPED_FRACTION * 100.0
            )
        } else {
            format!("{base}); `--exposure X` sets it")
        }
    }
}

/// The smallest exposed value whose display value encodes as 255 (white) in an 8-bit sRGB
/// image under `tonemap`, found by bisection on the curve (both curves are monotone).
#[must_use]
pub fn white_point(tonemap: Tonemap) -> f32 {
    let display = Display {
        exposure: 1.0,
        tonemap,
    };
    let is_white = |x: f32| srgb_encode(display.map(x)) * 255.0 + 0.5 >= 255.0;
    let (mut lo, mut hi) = (0.0f32, 1.0f32);
    while !is_white(hi) {
        hi *= 2.0;
        if hi > 1.0e6 {
            return hi;
        }
    }
    for _ in 0..40 {
        let mid = 0.5 * (lo + hi);
        if is_white(mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// The fraction of the pixels of `film` that encode as white (255) in some channel under
/// `display`: what the automatic exposure keeps at or below [`MAX_CLIPPED_FRACTION`].
#[must_use]
pub fn clipped_fraction(film: &Film, display: Display) -> f64 {
    if film.pixels.is_empty() {
        return 0.0;
    }
    let clipped = film
        .pixels
        .iter()
        .filter(|p| {
            p.to_array()
                .iter()
                .any(|&c| srgb_encode(display.map(c)) * 255.0 + 0.5 >= 255.0)
        })
        .count();
    clipped as f64 / film.pixels.len() as f64
}

/// The tone curve of 8-bit images: the stated one, else [`Tonemap::Aces`] when the exposure
/// is automatic and [`Tonemap::Linear`] when the scene states an exposure (so a scene that
/// states its exposure keeps today's image, byte for byte). An automatic exposure gets the
/// filmic curve because a linear clip with at most 1 % white pixels would leave a scene that
/// shows its lamp or a sunlit patch over more than 1 % of the frame far too dark (the Cornell
/// box at 4 spp: exposure 0.058 instead of the key's 0.63, its mean 8-bit value 67 instead of
/// 144); ACES reaches white only at 7.24, so the clip guard rarely has to act.
#[must_use]
pub fn tonemap_for(stated_exposure: Option<f32>, stated_tonemap: Option<Tonemap>) -> Tonemap {
    match (stated_tonemap, stated_exposure) {
        (Some(t), _) => t,
        (None, None) => Tonemap::Aces,
        (None, Some(_)) => Tonemap::Linear,
    }
}

/// The display of an image: the stated exposure when there is one (today's behaviour,
/// unchanged), else [`AutoExposure::of_film`] of the film. The second value says how an
/// automatic one was chosen (`None` when stated).
#[must_use]
pub fn resolve(
    film: &Film,
    stated: Option<f32>,
    tonemap: Tonemap,
) -> (Display, Option<AutoExposure>) {
    match stated {
        Some(exposure) => (Display { exposure, tonemap }, None),
        None => {
            let auto = AutoExposure::of_film(film, tonemap);
            (
                Display {
                    exposure: auto.exposure,
                    tonemap,
                },
                Some(auto),
            )
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn film_of(values: &[Vec3]) -> Film {
        Film {
            width: values.len() as u32,
            height: 1,
            pixels: values.to_vec(),
        }
    }

    /// A uniform grey film of luminance L: the log average is L (δ cancels), the exposure
    /// 0.18 / L, no pixel clips.
    #[test]
    fn a_uniform_film_is_exposed_to_the_key() {
        let f = film_of(&[Vec3::splat(2.5); 100]);
        let a = AutoExposure::of_film(&f, Tonemap::Linear);
        assert!((a.log_average - 2.5).abs() < 1e-5, "{a:?}");
        assert!((a.exposure - 0.18 / 2.5).abs() < 1e-6, "{a:?}");
        assert!(!a.clip_limited);
    }

    /// The log average of two luminances is their geometric mean (Reinhard's eq. 1, δ small):
    /// 0.01 and 100 give about 1, not the arithmetic 50.
    #[test]
    fn the_log_average_is_the_geometric_mean() {
        let mut v = vec![Vec3::splat(0.01); 500];
        v.extend(vec![Vec3::splat(100.0); 500]);
        let a = AutoExposure::of_film(&film_of(&v), Tonemap::Linear);
        // exp((ln 0.0101 + ln 100.0001) / 2) − δ ≈ 1.00499 − 0.0001.
        let expected = ((0.0101f64.ln() + 100.0001f64.ln()) / 2.0).exp() - 1e-4;
        assert!((f64::from(a.log_average) - expected).abs() < 1e-5, "{a:?}");
        // Half the pixels at 100 would clip at 0.18: the guard takes the 99th percentile.
        assert!(a.clip_limited);
    }

    /// A film with a few very bright pixels (5 %, 4–8.9 × the curve's white point): the key
    /// would clip all of them; the guard lowers the exposure until 1 % or fewer reach white,
    /// under either curve.
    #[test]
    fn the_clip_guard_keeps_at_most_one_percent_white() {
        for tonemap in Tonemap::ALL.iter().copied() {
            let white = white_point(tonemap);
            let mut v = vec![Vec3::new(0.2, 0.3, 0.25); 950];
            v.extend((0..50).map(|i| Vec3::splat(white * (4.0 + 0.1 * i as f32))));
            let f = film_of(&v);
            let (display, auto) = resolve(&f, None, tonemap);
            let auto = auto.expect("automatic");
            assert!(
                auto.clip_limited && !auto.guard_capped,
                "{tonemap:?}: {auto:?}"
            );
            let clipped = clipped_fraction(&f, display);
            assert!(clipped <= MAX_CLIPPED_FRACTION, "{tonemap:?}: {clipped}");
            // …and not far below: the guard pixel (index 989, 7.9 × white) sits just under
            // white, the ten above it clip.
            assert!(clipped >= 0.009, "{tonemap:?}: {clipped}");
            assert!((auto.p99 / (white * 7.9) - 1.0).abs() < 1e-5, "{auto:?}");
        }
    }

    /// Bright pixels far over the key (40–89 against a key exposure near 0.5): the guard would
    /// need 40×, is held at [`MAX_GUARD_FACTOR`], and more than 1 % clip.
    #[test]
    fn the_guard_lowers_the_key_by_at_most_its_factor() {
        let mut v = vec![Vec3::new(0.2, 0.3, 0.25); 950];
        v.extend((0..50).map(|i| Vec3::splat(40.0 + i as f32)));
        let f = film_of(&v);
        let (display, auto) = resolve(&f, None, Tonemap::Linear);
        let auto = auto.expect("automatic");
        assert!(auto.guard_capped, "{auto:?}");
        assert!((auto.exposure - auto.key_exposure / MAX_GUARD_FACTOR).abs() < 1e-7);
        assert!(clipped_fraction(&f, display) > MAX_CLIPPED_FRACTION);
    }

    /// A stated exposure passes through untouched, whatever the film.
    #[test]
    fn a_stated_exposure_is_kept_exactly() {
        let f = film_of(&[Vec3::splat(1000.0); 10]);
        let (display, auto) = resolve(&f, Some(0.7), Tonemap::Aces);
        assert_eq!(
            display,
            Display {
                exposure: 0.7,
                tonemap: Tonemap::Aces
            }
        );
        assert!(auto.is_none());
    }

    /// The white points: linear clips where sRGB(x)·255 + 0.5 reaches 255,
    /// x = ((254.5/255 + 0.055)/1.055)^2.4 ≈ 0.99554; ACES just below its 1 at x ≈ 7.24.
    #[test]
    fn white_points_match_the_curves() {
        let lin = f64::from(white_point(Tonemap::Linear));
        let by_hand = ((254.5f64 / 255.0 + 0.055) / 1.055).powf(2.4);
        assert!((lin - by_hand).abs() < 1e-5, "{lin} vs {by_hand}");
        let aces = white_point(Tonemap::Aces);
        assert!(aces > 5.0 && aces < 7.3, "{aces}");
    }

    #[test]
    fn black_empty_and_broken_films_get_exposure_one() {
        for f in [
            Film::new(0, 0),
            Film::new(4, 4),
            film_of(&[Vec3::splat(f32::NAN), Vec3::splat(-1.0)]),
        ] {
            let a = AutoExposure::of_film(&f, Tonemap::Linear);
            assert_eq!(a.exposure, 1.0, "{a:?}");
        }
    }
}

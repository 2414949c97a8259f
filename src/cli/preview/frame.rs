//! What the page shows of a render after a pass: the current estimate of each layer, the
//! denoised image when the page's toggle asks for it, and the noise figure computed from the
//! film's per-pixel variance.

use std::sync::Arc;

use glam::Vec3;

use caustic::integrators::LightPath;
use caustic::render::{Film, PixelSums};

/// A layer the page can show.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum View {
    /// The image (every kind of light path).
    Beauty,
    /// One kind of light path (`--layers`' specular, direct, caustic, indirect).
    Part(LightPath),
    /// The standard error of each pixel's mean, √(variance of the mean), per channel: the
    /// noise left in the pixel, in radiance units (the `variance` layer, square-rooted so that
    /// exposure scales it like the image).
    StdError,
    /// The denoised image (`--denoise`'s, docs/denoise.md), when the page's toggle is on and
    /// one has been made ([`Frame::denoised`]).
    Denoised,
}

impl View {
    /// Every view, in the page's order.
    pub const ALL: [View; 7] = [
        View::Beauty,
        View::Part(LightPath::Specular),
        View::Part(LightPath::Direct),
        View::Part(LightPath::Caustic),
        View::Part(LightPath::Indirect),
        View::StdError,
        View::Denoised,
    ];

    /// The name the page asks for (`/image.png?layer=NAME`).
    pub fn name(self) -> &'static str {
        match self {
            View::Beauty => "beauty",
            View::Part(p) => p.name(),
            View::StdError => "variance",
            View::Denoised => "denoised",
        }
    }

    /// The view called `name`, if any.
    pub fn parse(name: &str) -> Option<View> {
        Self::ALL.into_iter().find(|v| v.name() == name)
    }
}

/// The noise of a render so far, estimated from its per-pixel sample variance.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Noise {
    /// Root-mean-square standard error of the pixel means over the pixels and channels:
    /// √(mean over pixels and channels of s²/n), s² the unbiased sample variance of the
    /// pixel's samples and n their count. The expected RMSE of the image against the converged
    /// one.
    pub rms: f64,
    /// The mean pixel value over pixels and channels (the page shows `rms` relative to it).
    pub mean: f64,
}

/// The noise figure of `sums`; `None` before every pixel has two samples (no variance yet).
pub fn noise(sums: &PixelSums) -> Option<Noise> {
    let n = sums.width as usize * sums.height as usize;
    if n == 0 || (0..n).any(|i| sums.count(i) < 2) {
        return None;
    }
    let (mut var, mut mean) = (0.0f64, 0.0f64);
    for i in 0..n {
        let v = sums.variance(i).as_dvec3() / f64::from(sums.count(i));
        var += v.element_sum();
        mean += sums.mean(i).as_dvec3().element_sum();
    }
    let values = 3.0 * n as f64;
    Some(Noise {
        rms: (var / values).sqrt(),
        mean: mean / values,
    })
}

/// A denoised image of the render and the samples per pixel it was made from (it is made
/// less often than passes end, so it can be older than the frame it rides in).
#[derive(Debug, Clone)]
pub struct Denoised {
    /// The denoised image.
    pub film: Arc<Film>,
    /// Samples per pixel it was made from.
    pub spp: u32,
}

/// The images of one moment of a render, in [`View::ALL`] order.
#[derive(Debug, Clone)]
pub struct Frame {
    /// One film per view of the sums (every view but [`View::Denoised`]; a view the render did
    /// not keep is black).
    pub views: Vec<Film>,
    /// The latest denoised image of this render, if the toggle is on and one was made.
    pub denoised: Option<Denoised>,
    /// Samples per pixel in it.
    pub spp: u32,
    /// The render it is of ([`super::state::Status::generation`]).
    pub generation: u64,
}

impl Frame {
    /// The frame of `sums` (and the per-light-path `parts`, in [`LightPath::ALL`] order), with
    /// the render's latest denoised image if any.
    pub fn new(
        sums: &PixelSums,
        parts: Option<&[PixelSums]>,
        spp: u32,
        generation: u64,
        denoised: Option<Denoised>,
    ) -> Self {
        let views = View::ALL
            .iter()
            .filter_map(|v| match v {
                View::Beauty => Some(sums.to_film()),
                View::Part(p) => Some(
                    parts
                        .and_then(|parts| parts.get(*p as usize))
                        .map_or_else(|| Film::new(sums.width, sums.height), PixelSums::to_film),
                ),
                View::StdError => {
                    let mut film = Film::new(sums.width, sums.height);
                    for (i, px) in film.pixels.iter_mut().enumerate() {
                        let n = sums.count(i).max(1) as f32;
                        *px = (sums.variance(i) / n).max(Vec3::ZERO).powf(0.5);
                    }
                    Some(film)
                }
                View::Denoised => None,
            })
            .collect();
        Self {
            views,
            denoised,
            spp,
            generation,
        }
    }

    /// The film of `view` and the samples per pixel it holds; `None` for
    /// [`View::Denoised`] while no denoised image has been made.
    pub fn view(&self, view: View) -> Option<(&Film, u32)> {
        match view {
            View::Denoised => self.denoised.as_ref().map(|d| (d.film.as_ref(), d.spp)),
            View::Beauty | View::Part(_) | View::StdError => {
                let i = View::ALL.iter().position(|v| *v == view)?;
                self.views.get(i).map(|f| (f, self.spp))
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_noise_figure_is_the_rms_standard_error_by_hand() {
        // Two pixels. Pixel 0: samples 1, 3 (grey): mean 2, s² = 2, s²/n = 1 in each channel.
        // Pixel 1: samples 0, 0, 6 (grey): mean 2, s² = 12, s²/n = 4.
        let mut sums = PixelSums::new(2, 1);
        for v in [1.0, 3.0] {
            sums.add(0, Vec3::splat(v));
        }
        for v in [0.0, 0.0, 6.0] {
            sums.add(1, Vec3::splat(v));
        }
        let n = noise(&sums).expect("every pixel has two samples");
        assert!((n.rms - 2.5f64.sqrt()).abs() < 1e-9, "{n:?}");
        assert!((n.mean - 2.0).abs() < 1e-9, "{n:?}");
        // The standard-error view holds √(s²/n) per pixel.
        let f = Frame::new(&sums, None, 2, 1, None);
        let film = |v| f.view(v).expect("a view of the sums").0;
        assert!((film(View::StdError).pixels[0].x - 1.0).abs() < 1e-6);
        assert!((film(View::StdError).pixels[1].x - 2.0).abs() < 1e-6);
        assert_eq!(film(View::Beauty).pixels[1], Vec3::splat(2.0));
        // No denoised image was made: none is shown (the server answers 503).
        assert!(f.view(View::Denoised).is_none());
        // One sample somewhere: no variance yet.
        let mut one = PixelSums::new(1, 1);
        one.add(0, Vec3::ONE);
        assert_eq!(noise(&one), None);
    }

    /// The noise figure of a 32×32, 32 spp path-traced Cornell box with `sampler` and `seed`,
    /// and the RMSE between two such renders of seeds 1 and 2 over √2.
    fn predicted_and_measured(sampler: &str) -> (f64, f64) {
        use caustic::pipeline::{SceneOverrides, prepare};
        use caustic::render::{RenderOptions, render};
        let scene = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
        let run = |seed| {
            let overrides = SceneOverrides {
                render: caustic::scene::schema::RenderSettings {
                    width: Some(32),
                    height: Some(32),
                    samples_per_pixel: Some(32),
                    seed: Some(seed),
                    ..Default::default()
                },
                sets: vec![
                    "render.integrator=Path".into(),
                    format!("render.sampler={sampler}"),
                ],
                ..SceneOverrides::default()
            };
            let prepared = prepare(&scene, &overrides).expect("cornell prepares");
            render(&prepared.render_scene, &RenderOptions::default()).expect("renders")
        };
        let (a, b) = (run(1), run(2));
        let predicted = noise(&a.sums).expect("32 samples each").rms;
        let sq: f64 = (a.film.pixels.iter().zip(&b.film.pixels))
            .map(|(x, y)| (*x - *y).as_dvec3().length_squared())
            .sum();
        (
            predicted,
            (sq / (3.0 * a.film.pixels.len() as f64) / 2.0).sqrt(),
        )
    }

    #[test]
    fn the_noise_figure_predicts_the_difference_of_two_independent_renders() {
        // Two renders with different seeds differ per value by √(σa² + σb²) on average, and
        // both have about the same σ², so their RMSE over √2 estimates the noise figure of
        // either one: an estimator independent of the per-pixel variance. With independent
        // samples the two agree.
        let (predicted, measured) = predicted_and_measured("Independent");
        let ratio = predicted / measured;
        assert!(
            (0.85..1.18).contains(&ratio),
            "predicted {predicted}, measured {measured}"
        );
        // Owen-scrambled Sobol points are not independent: their mean converges faster than
        // the sample variance says, so the figure is an upper estimate there (docs/preview.md).
        let (predicted, measured) = predicted_and_measured("Sobol");
        assert!(
            predicted > measured,
            "predicted {predicted}, measured {measured}"
        );
    }

    #[test]
    fn view_names_round_trip() {
        for v in View::ALL {
            assert_eq!(View::parse(v.name()), Some(v));
        }
        assert_eq!(View::parse("nope"), None);
    }
}

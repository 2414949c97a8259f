//! TEMPORARY stand-in (lead's local build only; replaced by the sampling branch).

use super::Rng;

/// Which sequence a Sampler draws from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SamplerKind {
    /// Independent.
    Independent,
    /// Sobol.
    Sobol,
}

/// Sampler.
#[derive(Debug, Clone)]
pub struct Sampler {
    seed: u64,
    rng: Rng,
}

impl Sampler {
    /// New.
    #[must_use]
    pub fn new(_kind: SamplerKind, seed: u64, _spp: u32) -> Self {
        Self {
            seed,
            rng: Rng::new(seed, 0),
        }
    }
    /// Start.
    pub fn start_pixel_sample(&mut self, x: u32, y: u32, index: u32) {
        self.rng = Rng::for_pixel_sample(self.seed, x, y, index);
    }
    /// 1d.
    pub fn next_1d(&mut self) -> f32 {
        self.rng.next_f32()
    }
    /// 2d.
    pub fn next_2d(&mut self) -> (f32, f32) {
        self.rng.next_2d()
    }
    /// Pixel.
    pub fn pixel_2d(&mut self) -> (f32, f32) {
        self.rng.next_2d()
    }
}

//! The numbers integrators draw: one `Sampler` per worker, restarted for every camera sample (or
//! light/photon path), whose values depend only on (seed, pixel or stream, sample index,
//! dimension) — never on the thread or on what other pixels drew — so images are the same bytes
//! for any thread count.

use super::rng::{Rng, mix64};
use super::sobol::{shuffled_scrambled_1d_reversed, shuffled_scrambled_2d_reversed, to_unit_f32};

pub use crate::settings::SamplerKind;

/// Dimension at which integrator draws start after `start_pixel_sample`: 0 and 1 are the pixel
/// position (`pixel_2d`).
const FIRST_INTEGRATOR_DIMENSION: u32 = 2;

/// Numbers for one camera sample (or one photon/light path), keyed by (seed, pixel or stream,
/// sample index, dimension) — never by thread. No heap allocation; cheap to clone.
///
/// Call [`Sampler::start_pixel_sample`] (or [`Sampler::start_stream`]) before each sample, then
/// draw with [`Sampler::pixel_2d`], [`Sampler::next_1d`] and [`Sampler::next_2d`]. Each draw
/// uses the next dimension(s) of the sample, so an integrator that draws in a fixed order per
/// bounce gets the same dimension for the same decision in every sample (which is what lets the
/// Sobol sampler stratify it).
#[derive(Debug, Clone)]
pub struct Sampler {
    kind: SamplerKind,
    seed: u64,
    samples_per_pixel: u32,
    /// `mix64(seed)`, which every pixel's key starts from.
    seed_hash: u64,
    /// Hash of (seed, pixel or stream): keys every scramble of this sample's dimensions.
    key: u64,
    /// Index of the sample within its pixel or stream (the Sobol point index).
    index: u32,
    /// `index` bit-reversed, which every Sobol draw of the sample starts from.
    reversed_index: u32,
    /// Next dimension to draw.
    dimension: u32,
    /// Independent kind: the sample's stream.
    rng: Rng,
    /// Independent kind: the pixel position, drawn first from the stream.
    pixel: (f32, f32),
}

impl Sampler {
    /// A sampler of `kind` for renders of `samples_per_pixel` samples seeded with `seed`.
    /// `samples_per_pixel` is advisory (Sobol works for any count, best at powers of 2).
    #[must_use]
    pub fn new(kind: SamplerKind, seed: u64, samples_per_pixel: u32) -> Self {
        Self {
            kind,
            seed,
            samples_per_pixel,
            seed_hash: mix64(seed),
            key: 0,
            index: 0,
            reversed_index: 0,
            dimension: 0,
            rng: Rng::new(seed, 0),
            pixel: (0.5, 0.5),
        }
    }

    /// The kind of sequence this sampler draws.
    #[must_use]
    pub fn kind(&self) -> SamplerKind {
        self.kind
    }

    /// The samples per pixel it was created for.
    #[must_use]
    pub fn samples_per_pixel(&self) -> u32 {
        self.samples_per_pixel
    }

    /// Starts sample `index` of pixel `(x, y)`; [`Sampler::pixel_2d`] gives its position in the
    /// pixel, and integrator draws start at dimension 2.
    pub fn start_pixel_sample(&mut self, x: u32, y: u32, index: u32) {
        let pixel = (u64::from(y) << 32) | u64::from(x);
        self.key = mix64(pixel ^ self.seed_hash);
        self.index = index;
        self.reversed_index = index.reverse_bits();
        self.dimension = FIRST_INTEGRATOR_DIMENSION;
        if self.kind == SamplerKind::Independent {
            self.rng = Rng::for_pixel_sample(self.seed, x, y, index);
            self.pixel = self.rng.next_2d();
        }
    }

    /// Starts path `index` of the independent stream family `stream` (e.g. photon paths: one
    /// stream per light, or one per photon batch); draws start at dimension 0. Streams and
    /// pixels never share keys.
    pub fn start_stream(&mut self, stream: u64, index: u64) {
        // Sobol indices are 32-bit: higher index bits select another scramble instead.
        self.key = mix64(
            mix64(stream ^ 0x6A09_E667_F3BC_C909)
                ^ mix64(self.seed.wrapping_add(0xBB67_AE85_84CA_A73B))
                ^ (index >> 32).wrapping_mul(0x3C6E_F372_FE94_F82B),
        );
        self.index = index as u32;
        self.reversed_index = self.index.reverse_bits();
        self.dimension = 0;
        if self.kind == SamplerKind::Independent {
            self.rng = Rng::new(self.seed ^ self.key, index);
            self.pixel = (0.5, 0.5);
        }
    }

    /// The next number, in `[0, 1)`.
    #[inline]
    pub fn next_1d(&mut self) -> f32 {
        match self.kind {
            SamplerKind::Independent => self.rng.next_f32(),
            SamplerKind::Sobol => {
                let d = self.dimension;
                self.dimension += 1;
                self.sobol_1d(d)
            }
        }
    }

    /// The next two numbers, in `[0, 1)²`.
    #[inline]
    pub fn next_2d(&mut self) -> (f32, f32) {
        match self.kind {
            SamplerKind::Independent => self.rng.next_2d(),
            SamplerKind::Sobol => {
                let d = self.dimension;
                self.dimension += 2;
                self.sobol(d)
            }
        }
    }

    /// Reserves the next dimension for a number that may not be needed: its value, the one
    /// [`Sampler::next_1d`] would have returned, is computed by [`Sampler::get_1d`] only if the
    /// integrator uses it (the Sobol sampler's points cost a few hashes each). The independent
    /// sampler draws it now, since its stream is sequential; either way the numbers of later
    /// draws, and so the image, are the same whether or not it is used.
    #[inline]
    pub fn defer_1d(&mut self) -> Deferred1d {
        match self.kind {
            SamplerKind::Independent => Deferred1d {
                dimension: 0,
                value: self.rng.next_f32(),
            },
            SamplerKind::Sobol => {
                let d = self.dimension;
                self.dimension += 1;
                Deferred1d {
                    dimension: d,
                    value: 0.0,
                }
            }
        }
    }

    /// [`Sampler::defer_1d`] for a pair: the value [`Sampler::next_2d`] would have returned,
    /// computed by [`Sampler::get_2d`].
    #[inline]
    pub fn defer_2d(&mut self) -> Deferred2d {
        match self.kind {
            SamplerKind::Independent => Deferred2d {
                dimension: 0,
                value: self.rng.next_2d(),
            },
            SamplerKind::Sobol => {
                let d = self.dimension;
                self.dimension += 2;
                Deferred2d {
                    dimension: d,
                    value: (0.0, 0.0),
                }
            }
        }
    }

    /// The number reserved by [`Sampler::defer_1d`] (valid until the next `start_*` call).
    #[inline]
    #[must_use]
    pub fn get_1d(&self, d: Deferred1d) -> f32 {
        match self.kind {
            SamplerKind::Independent => d.value,
            SamplerKind::Sobol => self.sobol_1d(d.dimension),
        }
    }

    /// The pair reserved by [`Sampler::defer_2d`] (valid until the next `start_*` call).
    #[inline]
    #[must_use]
    pub fn get_2d(&self, d: Deferred2d) -> (f32, f32) {
        match self.kind {
            SamplerKind::Independent => d.value,
            SamplerKind::Sobol => self.sobol(d.dimension),
        }
    }

    /// The 2-D position inside the pixel for the camera ray (the sample's first two dimensions,
    /// whenever it is called).
    #[inline]
    pub fn pixel_2d(&mut self) -> (f32, f32) {
        match self.kind {
            SamplerKind::Independent => self.pixel,
            SamplerKind::Sobol => self.sobol(0),
        }
    }

    /// The 2-D Sobol point of this sample for the draw that starts at `dimension`: its own index
    /// shuffle and scrambles, keyed by (seed, pixel or stream, dimension) ("padding").
    #[inline]
    fn sobol(&self, dimension: u32) -> (f32, f32) {
        let h = self.dimension_hash(dimension);
        let h2 = mix64(h);
        let seeds = [h as u32, (h >> 32) as u32, h2 as u32];
        let (x, y) = shuffled_scrambled_2d_reversed(self.reversed_index, seeds);
        (to_unit_f32(x), to_unit_f32(y))
    }

    /// The first coordinate of [`Sampler::sobol`] alone (the same number, without computing
    /// and scrambling the second).
    #[inline]
    fn sobol_1d(&self, dimension: u32) -> f32 {
        let h = self.dimension_hash(dimension);
        let seeds = [h as u32, (h >> 32) as u32];
        to_unit_f32(shuffled_scrambled_1d_reversed(self.reversed_index, seeds))
    }

    /// The hash keying dimension `dimension` of this sample's scrambles.
    #[inline]
    fn dimension_hash(&self, dimension: u32) -> u64 {
        mix64(self.key ^ dimension_key(dimension))
    }
}

/// The per-dimension half of [`Sampler::dimension_hash`], which depends on nothing else.
const fn dimension_key(dimension: u32) -> u64 {
    mix64(dimension as u64 ^ 0x9E37_79B9_7F4A_7C15)
}

/// A number reserved by [`Sampler::defer_1d`], read with [`Sampler::get_1d`].
#[derive(Debug, Clone, Copy)]
pub struct Deferred1d {
    dimension: u32,
    value: f32,
}

/// A pair reserved by [`Sampler::defer_2d`], read with [`Sampler::get_2d`].
#[derive(Debug, Clone, Copy)]
pub struct Deferred2d {
    dimension: u32,
    value: (f32, f32),
}

#[cfg(test)]
mod tests;

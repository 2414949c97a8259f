//! The absorbing medium a path segment travels through: Beer–Lambert attenuation inside
//! dielectrics (water, coloured glass; [`crate::shading::absorption`]), the same for camera
//! paths (`path` and the progressive integrators built on it, the photon integrator's camera
//! branches and final-gather rays, Whitted's rays and its straight shadow rays) and photons.
//!
//! A path starts outside every object (cameras and lights are in air). The medium changes only
//! where the path scatters at a surface whose material has an `absorption`: a direction into
//! the object (against its geometric normal, the side it encloses) enters that material's
//! medium, a direction out of it leaves to the outside. Scattering at any other surface keeps
//! the medium: a ray in water that reflects off the tub's floor is still in the water. So the
//! medium's extent is bounded by the next surfaces the ray meets whatever they are — a closed
//! mesh's own faces, or, for an open surface such as the single water quad of
//! `scenes/bath.ron`, the tub that holds the water below it. Segments in a medium keep
//! `exp(−σ t)` of their light, `t` the segment's length in metres; a segment that escapes the
//! scene inside an absorbing medium keeps nothing. Media do not nest (a clear glass inside
//! water is treated as water).

use glam::Vec3;

use super::{Interaction, RenderScene, SurfaceHit};
use crate::geometry::Ray;
use crate::shading::absorption::Absorption;

/// The medium a path is in: the absorption around the current segment (clear outside).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Medium {
    absorption: Absorption,
}

impl Medium {
    /// Outside every object: nothing is absorbed.
    pub const OUTSIDE: Self = Self {
        absorption: Absorption::CLEAR,
    };

    /// True when the segment absorbs nothing.
    #[inline]
    #[must_use]
    pub fn is_clear(&self) -> bool {
        self.absorption.is_clear()
    }

    /// The fraction of light (per channel) kept along the segment `ray` travelled to reach
    /// `interaction` (its length is the hit distance times `|ray.dir|`; an escaped ray
    /// travelled infinitely far). Exactly 1 in a clear medium, so paths that never enter an
    /// absorbing medium are unchanged bit for bit.
    #[inline]
    #[must_use]
    pub fn transmittance(&self, ray: &Ray, interaction: &Interaction) -> Vec3 {
        if self.is_clear() {
            return Vec3::ONE;
        }
        let t = match interaction {
            Interaction::Escaped => f32::INFINITY,
            Interaction::Emitter(e) => e.hit.t,
            Interaction::Surface(s) => s.hit.t,
        };
        self.absorption.transmittance(t * ray.dir.length())
    }

    /// The fraction of light (per channel) kept over `distance` metres in this medium (a
    /// shadow ray's segment, which ends at a point rather than a hit). Exactly 1 in a clear
    /// medium.
    #[inline]
    #[must_use]
    pub fn transmittance_over(&self, distance: f32) -> Vec3 {
        if self.is_clear() {
            return Vec3::ONE;
        }
        self.absorption.transmittance(distance)
    }

    /// The medium after the path scatters at `v` into the direction `wi`: the material's
    /// medium when `wi` goes into an object whose material absorbs, outside when it leaves such
    /// an object, and unchanged at every other surface.
    #[inline]
    #[must_use]
    pub fn after(self, scene: &RenderScene, v: &SurfaceHit, wi: Vec3) -> Self {
        let absorption = scene.materials[v.material as usize].absorption;
        if absorption.is_clear() {
            return self;
        }
        // `v.sp.ng` is the object's outward geometric normal.
        if wi.dot(v.sp.ng) < 0.0 {
            Self { absorption }
        } else {
            Self::OUTSIDE
        }
    }
}

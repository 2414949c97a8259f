//! The volume caustic map: photons stored where light that left a light and crossed at least
//! one mirror or glass surface (light → specular⁺) scatters in a participating medium, and the
//! **beam radiance estimate** that camera rays read it with (Jarosz, Zwicker & Jensen, "The Beam
//! Radiance Estimate for Volumetric Photon Mapping", Computer Graphics Forum 27(2), 2008).
//!
//! **Storing** (`trace.rs`): a caustic photon crossing a scattering medium after a specular
//! bounce draws `VOLUME_SAMPLES` (4) free-flight distances along the segment; where one ends
//! before the surface a volume photon is stored with flux `Φ σs T(t) / (4 p(t))` (the
//! free-flight weight), so the stored flux per
//! unit length along the segment is, in expectation, `Φ σs T(t)`: the flux scattered there. The
//! photon itself goes on unscattered with `Φ T(d)` as before, so the surface caustic map is what
//! it was.
//!
//! **Gathering**: every photon `i` is a sphere of radius `rᵢ`. A camera ray segment
//! `x(t) = o + t ω`, `t ∈ [0, s)`, in the photon's medium receives (Jarosz et al. 2008, eq. 13,
//! with their constant 2-D kernel over the photon's disc seen along the ray)
//!
//! ```text
//! L_b(o, −ω) ≈ Σ_{i : dᵢ < rᵢ, 0 ≤ tᵢ < s} K_{rᵢ}(dᵢ) · T(tᵢ) · p(ωᵢ, −ω) · Φᵢ,   K_r = 1/(π r²),
//! ```
//!
//! `tᵢ` the foot of the perpendicular from the photon to the ray, `dᵢ` its distance, `T(t) =
//! exp(−σt t)` per channel, `ωᵢ` the photon's direction of travel and `p` the medium's phase
//! function: the integral `∫₀ˢ T(t) σs ∫ p L_in dω' dt` of the light → specular⁺ part of the
//! in-scattered radiance, blurred over each photon's disc. The photons are found by one query
//! of a BVH over their spheres ([`SphereBvh`]). Photons of another medium (across a boundary
//! from the segment) are skipped.
//!
//! **Radii**: as the surface maps' (Knaus & Zwicker, "Progressive Photon Mapping: A
//! Probabilistic Approach", ACM ToG 30(3), 2011), `rᵢ = s_pass · R(xᵢ)` with `R` the
//! [`VOLUME_GATHER`]-nearest radius of a pilot set of volume photons traced from streams no pass
//! uses ([`volume_radius_field`]), so each pass is a plain fixed-kernel estimate, and `s_pass` the
//! schedule `r²ᵢ₊₁ = r²ᵢ (i + α)/(i + 1)`: the kernel is 2-D (a disc across the ray), so the
//! radius shrinks by the same rule as the surface maps' (Knaus & Zwicker §5.2; Jarosz, Nowrouzezahrai,
//! Thomas, Sloan & Zwicker, "Progressive Photon Beams", ACM ToG 30(6), 2011, §5, for the
//! dimension of the kernel deciding the exponent).

use glam::Vec3;
use rayon::prelude::*;

use super::estimate::MIN_RADIUS_FRACTION;
use super::radius_field::RadiusField;
use crate::accel::SphereBvh;
use crate::render_scene::HomogeneousMedium;
use crate::spatial::{KdTree, KnnHeap};

/// Nearest pilot volume photons whose distance sets the initial radius `R(x)` of the beam
/// estimate. A segment gathers every photon whose disc it crosses — a cylinder around it, not a
/// sphere — so an estimate reads many more than `k` photons.
pub const VOLUME_GATHER: usize = 10;

/// The pilot radius's cap over the even-spread k-nearest radius. It also sets the field's cells
/// (half the cap): at 3 an evenly spread pilot puts about 8 photons in a cell, so few cells
/// are empty (there `R` is the cap); at 2 about 2.4 were, 9 % of cells were empty and the
/// field's mean over an even cloud came out 11 % above the k-nearest radius.
pub const VOLUME_RADIUS_CAP: f64 = 3.0;

/// A photon stored where light → specular⁺ scattered in a medium.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumePhoton {
    /// Where it scattered (scene units).
    pub position: Vec3,
    /// Unit direction it travelled before scattering.
    pub direction: Vec3,
    /// Flux it scattered (W per channel; the free-flight weight `σs T / p` included).
    pub power: Vec3,
    /// Index in `RenderScene::media` of the medium it scattered in.
    pub medium: u32,
}

/// One pass's volume photons with their radii, in a BVH over their spheres.
#[derive(Debug, Clone, Default)]
pub struct VolumeMap {
    photons: Vec<VolumePhoton>,
    tree: SphereBvh,
}

/// What a beam estimate found (for counters and `debug-pixel`).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct BeamEstimate {
    /// The radiance the segment receives from the map (W·m⁻²·sr⁻¹ per channel).
    pub radiance: Vec3,
    /// Photons whose disc the segment crossed.
    pub found: u32,
}

impl VolumeMap {
    /// The map of `photons`, photon `i` read within `radius(position)` (scene units). `None`
    /// without photons.
    #[must_use]
    pub fn build(photons: Vec<VolumePhoton>, radius: impl Fn(Vec3) -> f32 + Sync) -> Option<Self> {
        if photons.is_empty() {
            return None;
        }
        let centers: Vec<Vec3> = photons.iter().map(|p| p.position).collect();
        let radii: Vec<f32> = centers.par_iter().map(|&c| radius(c)).collect();
        let tree = SphereBvh::build(&centers, &radii);
        Some(Self { photons, tree })
    }

    /// Photons in the map.
    #[must_use]
    pub fn len(&self) -> usize {
        self.photons.len()
    }

    /// True without photons.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.photons.is_empty()
    }

    /// The photons, in the order they were traced.
    #[must_use]
    pub fn photons(&self) -> &[VolumePhoton] {
        &self.photons
    }

    /// Bytes the map holds.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        self.photons.len() * std::mem::size_of::<VolumePhoton>() + self.tree.memory_bytes()
    }

    /// The beam radiance estimate (module docs) of the segment `origin + t·dir`, `t ∈ [0,
    /// t_max)` (`dir` of unit length; `t_max` in scene units, infinite for a ray that leaves
    /// the scene), which lies in medium `medium` (its index in `RenderScene::media`) of
    /// coefficients `m`: the radiance arriving at `origin` along `−dir` from light → specular⁺
    /// paths scattered once on the segment. No allocation.
    #[must_use]
    pub fn beam(
        &self,
        origin: Vec3,
        dir: Vec3,
        t_max: f32,
        medium: u32,
        m: &HomogeneousMedium,
    ) -> BeamEstimate {
        let mut sum = Vec3::ZERO;
        let mut found = 0u32;
        self.tree.along(origin, dir, t_max, |h| {
            let ph = &self.photons[h.index as usize];
            if ph.medium != medium {
                return;
            }
            found += 1;
            let kernel = 1.0 / (std::f32::consts::PI * h.r2);
            sum += ph.power * m.transmittance(h.t) * (kernel * m.phase.p(ph.direction, -dir));
        });
        BeamEstimate {
            radiance: sum,
            found,
        }
    }
}

/// The initial radius `R(x)` of the beam estimate from a pilot set of volume photons: each
/// photon's [`VOLUME_GATHER`]-nearest radius among them (at most the largest radius below),
/// raised to [`MIN_RADIUS_FRACTION`] of it, and their median per cell ([`RadiusField`]). The
/// largest radius is [`VOLUME_RADIUS_CAP`] times that of the sphere holding `k` photons were the
/// pilot's spread evenly over their bounding box (`3 (3 k V / (4π N))^{1/3}`); it is also `R`
/// where the pilot left no photon, and twice the cell side. `None` with fewer than two photons or a flat bounding box.
#[must_use]
pub fn volume_radius_field(pilot: &[VolumePhoton]) -> Option<RadiusField> {
    if pilot.len() < 2 {
        return None;
    }
    let positions: Vec<Vec3> = pilot
        .iter()
        .map(|p| p.position)
        .filter(|p| p.is_finite())
        .collect();
    let (lo, hi) = positions.iter().fold(
        (Vec3::splat(f32::INFINITY), Vec3::splat(f32::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    // A flat box (photons on one plane): its largest side stands in for the missing ones.
    let side = (hi - lo).max(Vec3::splat((hi - lo).max_element() * 1e-3));
    let volume = f64::from(side.x) * f64::from(side.y) * f64::from(side.z);
    let k = VOLUME_GATHER.min(positions.len() - 1);
    let n = positions.len() as f64;
    let max_radius = (VOLUME_RADIUS_CAP
        * (3.0 * k as f64 * volume / (4.0 * std::f64::consts::PI * n)).cbrt())
        as f32;
    if !(max_radius.is_finite() && max_radius > 0.0) {
        return None;
    }
    let floor = max_radius * MIN_RADIUS_FRACTION;
    let tree = KdTree::build(positions.clone()).ok()?;
    let max2 = max_radius * max_radius;
    let radii: Vec<(Vec3, f32)> = positions
        .par_iter()
        .map_init(
            || KnnHeap::new(k + 1),
            |heap, &p| {
                // k + 1: the photon itself is its own nearest.
                let found = tree.nearest(p.to_array(), max2, heap);
                let r = if found <= k {
                    max_radius
                } else {
                    heap.max_dist2().unwrap_or(max2).sqrt()
                };
                (p, r.max(floor))
            },
        )
        .collect();
    RadiusField::from_radii(max_radius, floor, &radii)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use crate::shading::phase::HenyeyGreenstein;

    fn medium(sigma_t: f32, g: f32) -> HomogeneousMedium {
        HomogeneousMedium {
            sigma_a: Vec3::ZERO,
            sigma_s: Vec3::splat(sigma_t),
            phase: HenyeyGreenstein { g },
        }
    }

    /// Photons spread evenly through a slab with flux density `q` per m³ (isotropic phase, no
    /// extinction): a ray through the slab of length `s` receives `q s / (4π)`.
    #[test]
    fn a_uniform_photon_density_gives_the_closed_form_in_scattered_radiance() {
        let mut rng = Rng::new(5, 9);
        let n = 400_000;
        // The unit cube, each photon 1/n W: flux density q = 1 W/m³ scattered.
        let photons: Vec<VolumePhoton> = (0..n)
            .map(|_| VolumePhoton {
                position: Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()),
                direction: Vec3::Z,
                power: Vec3::splat(1.0 / n as f32),
                medium: 0,
            })
            .collect();
        let map = VolumeMap::build(photons, |_| 0.05).expect("photons");
        let m = medium(0.0, 0.0);
        // Along x through the middle, from 0.2 to 0.8: s = 0.6.
        let mut sum = 0.0f64;
        let rays = 64;
        for i in 0..rays {
            let y = 0.3 + 0.4 * (i as f32 + 0.5) / rays as f32;
            let e = map.beam(Vec3::new(0.2, y, 0.5), Vec3::X, 0.6, 0, &m);
            sum += f64::from(e.radiance.x);
        }
        let mean = sum / f64::from(rays);
        let exact = 0.6 / (4.0 * std::f64::consts::PI);
        assert!((mean / exact - 1.0).abs() < 0.02, "{mean} vs {exact}");
        // Another medium's index finds nothing.
        assert_eq!(
            map.beam(Vec3::new(0.2, 0.5, 0.5), Vec3::X, 0.6, 1, &m)
                .found,
            0
        );
    }

    /// One photon on the ray's path: the kernel, the transmittance to its foot and the phase
    /// function towards the camera, each by hand.
    #[test]
    fn one_photon_weighs_kernel_transmittance_and_phase() {
        let ph = VolumePhoton {
            position: Vec3::new(2.0, 0.03, 0.0),
            direction: Vec3::new(0.0, -1.0, 0.0),
            power: Vec3::new(1.0, 2.0, 3.0),
            medium: 3,
        };
        let map = VolumeMap::build(vec![ph], |_| 0.1).expect("photon");
        let m = HomogeneousMedium {
            sigma_a: Vec3::new(0.1, 0.2, 0.3),
            sigma_s: Vec3::splat(0.5),
            phase: HenyeyGreenstein { g: 0.4 },
        };
        let e = map.beam(Vec3::ZERO, Vec3::X, 5.0, 3, &m);
        assert_eq!(e.found, 1);
        let g = 0.4f32;
        // Light travels −y, then −x towards the camera: cos θ = 0.
        let p = (1.0 - g * g) / (4.0 * std::f32::consts::PI * (1.0 + g * g).powf(1.5));
        let k = 1.0 / (std::f32::consts::PI * 0.01);
        for c in 0..3 {
            let t = (-(m.sigma_a[c] + 0.5) * 2.0).exp();
            let expected = k * t * p * ph.power[c];
            assert!((e.radiance[c] / expected - 1.0).abs() < 1e-4, "{c}");
        }
        // Beyond the segment's end, or behind its start: nothing.
        assert_eq!(map.beam(Vec3::ZERO, Vec3::X, 1.9, 3, &m).found, 0);
        assert_eq!(
            map.beam(Vec3::new(2.5, 0.0, 0.0), Vec3::X, 5.0, 3, &m)
                .found,
            0
        );
    }

    #[test]
    fn the_pilot_radius_follows_the_photon_density() {
        // 50 000 photons evenly in the unit cube: λ = 5·10⁴ /m³, the k-nearest radius
        // (4/3 π r³ λ = k) is (3k/(4π λ))^{1/3}: 0.0363 for k = 10.
        let mut rng = Rng::new(7, 3);
        let photons: Vec<VolumePhoton> = (0..50_000)
            .map(|_| VolumePhoton {
                position: Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()),
                direction: Vec3::Z,
                power: Vec3::ONE,
                medium: 0,
            })
            .collect();
        let field = volume_radius_field(&photons).expect("field");
        // Averaged over the inner cube (each cell's median is noisy: a cell holds ~5 pilot
        // photons whose k-nearest spheres overlap).
        let expected = (3.0 * VOLUME_GATHER as f32 / (4.0 * std::f32::consts::PI * 5e4)).cbrt();
        let n = 2000;
        let mean = (0..n)
            .map(|_| {
                let q = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 0.6 + 0.2;
                f64::from(field.radius(q))
            })
            .sum::<f64>()
            / f64::from(n);
        assert!(
            (mean / f64::from(expected) - 1.0).abs() < 0.03,
            "{mean} vs {expected}"
        );
        // Far from every photon: the largest radius, the cap times the even-spread radius.
        let far = field.radius(Vec3::splat(5.0));
        let cap = VOLUME_RADIUS_CAP as f32 * expected;
        assert!((far / cap - 1.0).abs() < 0.01, "{far}");
        assert!(volume_radius_field(&photons[..1]).is_none());
    }
}

//! The initial radius of progressive photon mapping, as a function of position, chosen once per
//! render from a pilot photon map and then independent of every pass's photons.
//!
//! Progressive photon mapping in Knaus & Zwicker's probabilistic form ("Progressive Photon
//! Mapping: A Probabilistic Approach", ACM ToG 30(3), 2011) reads pass `i` within a radius
//! `rᵢ(x) = sᵢ·R(x)`, `sᵢ` from their schedule. Its analysis holds point by point for any initial
//! radius `R(x)` that does not depend on the pass's photons: then a pass's estimate is the
//! plain box-kernel density estimate over a fixed disc, whose mean is the radiance averaged over
//! that disc, and bias and noise vanish together as `sᵢ` shrinks. A single `R` for the whole
//! scene (as SPPM implementations usually take) is too wide where a caustic is focused and too
//! narrow where photons are sparse; the k-nearest radius follows the density but depends on the
//! pass's own photons and costs a k-nearest search per estimate.
//!
//! This field takes the k-nearest radius from a **pilot** map — photons traced once, from their
//! own streams, never used for estimates — at every pilot photon, and stores the median per
//! cell of a coarse grid (cells of half the map's largest radius) in a [`VoxelTable`]. `R(x)` is
//! then one hash lookup: the median of `x`'s cell, or the largest radius where the pilot left no
//! photon (space photons rarely reach, where any estimate finds few). The field follows the
//! photon density at the scale of its cells, like the k-nearest radius, and leaves each pass a
//! fixed-radius lookup, which a per-pass hash grid answers in a small constant time
//! (Hachisuka & Jensen, "Stochastic Progressive Photon Mapping", SIGGRAPH Asia 2009).

use glam::Vec3;

use crate::spatial::VoxelTable;

/// Coarse cells per largest radius (the field's cell side is `max_radius / CELLS_PER_RADIUS`).
pub const CELLS_PER_RADIUS: f32 = 2.0;

/// `R(x)`: the initial estimate radius at every point, from a pilot map (see the module docs).
#[derive(Debug, Clone)]
pub struct RadiusField {
    /// Occupied cells (the index of each one's median radius in `medians`).
    cells: VoxelTable,
    /// Per occupied cell, the median k-nearest radius of its pilot photons.
    medians: Vec<f32>,
    /// `R` in cells without pilot photons: the pilot map's largest radius.
    fallback: f32,
    /// Smallest radius returned (`max_radius · MIN_RADIUS_FRACTION`: coincident photons).
    floor: f32,
    /// Median of `R` over the pilot photons (the radius a typical photon's estimates use).
    typical: f32,
}

impl RadiusField {
    /// The cell side of a field over a pilot map of largest radius `max_radius`
    /// (`max_radius / CELLS_PER_RADIUS`), `None` unless finite and positive (then there is no
    /// field).
    #[must_use]
    pub fn cell_side(max_radius: f32) -> Option<f32> {
        let side = max_radius / CELLS_PER_RADIUS;
        (side.is_finite() && side > 0.0).then_some(side)
    }

    /// The field of a pilot map (a map built from photon streams no pass uses; its constructor
    /// is `PhotonMap::radius_field`) of largest radius `max_radius`: `radii` holds each pilot
    /// photon's position and its k-nearest radius in the pilot map (the map's own `k` and
    /// largest radius), already raised to `floor`; the field keeps their median per cell of side
    /// [`RadiusField::cell_side`]. `None` without photons or cells.
    #[must_use]
    pub fn from_radii(max_radius: f32, floor: f32, radii: &[(Vec3, f32)]) -> Option<Self> {
        let side = Self::cell_side(max_radius)?;
        if radii.is_empty() {
            return None;
        }
        let (cells, medians) = VoxelTable::build(side, radii.iter().copied(), |group| {
            group.sort_by(f32::total_cmp);
            Some(group[group.len() / 2])
        })
        .ok()?;
        let mut sorted: Vec<f32> = radii.iter().map(|&(_, r)| r).collect();
        sorted.sort_by(f32::total_cmp);
        let typical = sorted[sorted.len() / 2];
        Some(Self {
            cells,
            medians,
            fallback: max_radius,
            floor,
            typical,
        })
    }

    /// `R(p)` (scene units): the median pilot radius of `p`'s cell, else the pilot map's
    /// largest radius; never below the zero-radius floor.
    #[inline]
    #[must_use]
    pub fn radius(&self, p: Vec3) -> f32 {
        let r = self.cells.get(p).map_or(self.fallback, |i| self.medians[i]);
        r.max(self.floor)
    }

    /// The median of `R` over the pilot photons (scene units).
    #[must_use]
    pub fn typical(&self) -> f32 {
        self.typical
    }

    /// `R` where the pilot left no photon: the pilot map's largest radius.
    #[must_use]
    pub fn fallback(&self) -> f32 {
        self.fallback
    }

    /// Occupied cells.
    #[must_use]
    pub fn cells(&self) -> usize {
        self.cells.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::integrators::photon::{Kernel, PhotonMap};
    use crate::sampling::Rng;
    use crate::spatial::{KdTree, Photon};

    fn map(points: &[Vec3], k: usize, max_radius: f32) -> PhotonMap {
        let photons = points
            .iter()
            .map(|&p| Photon::new(p, -Vec3::Z, Vec3::Z, Vec3::splat(1.0)))
            .collect();
        PhotonMap::new(
            KdTree::build(photons).expect("finite"),
            k,
            max_radius,
            Kernel::Box,
        )
    }

    #[test]
    fn the_field_follows_the_density_of_a_uniform_patch_and_a_dense_spot() {
        // A 1 m² patch with 20 000 uniform photons (density λ = 2·10⁴ /m²) and, in one corner,
        // 20 000 more in a 0.1 m square (λ = 2·10⁶ /m²). The k-nearest radius for k = 20 has
        // π r² λ ≈ k, i.e. r ≈ √(k/(π λ)): 0.0178 m on the patch, 0.00178 m in the spot.
        let mut rng = Rng::new(3, 1);
        let mut pts: Vec<Vec3> = (0..20_000)
            .map(|_| Vec3::new(rng.next_f32(), rng.next_f32(), 0.0))
            .collect();
        pts.extend(
            (0..20_000)
                .map(|_| Vec3::new(0.8 + 0.1 * rng.next_f32(), 0.8 + 0.1 * rng.next_f32(), 0.0)),
        );
        let field = map(&pts, 20, 0.1).radius_field().expect("field");
        let patch = (20.0 / (std::f32::consts::PI * 2e4)).sqrt();
        let spot = (20.0 / (std::f32::consts::PI * 2.02e6)).sqrt();
        for p in [
            Vec3::new(0.3, 0.3, 0.0),
            Vec3::new(0.5, 0.2, 0.0),
            Vec3::new(0.1, 0.6, 0.0),
        ] {
            let r = field.radius(p);
            assert!((r / patch - 1.0).abs() < 0.15, "patch {r} vs {patch}");
        }
        let r = field.radius(Vec3::new(0.85, 0.85, 0.0));
        assert!((r / spot - 1.0).abs() < 0.15, "spot {r} vs {spot}");
        // Away from every photon: the largest radius.
        assert_eq!(field.radius(Vec3::new(0.5, 0.5, 3.0)), 0.1);
        assert_eq!(field.fallback(), 0.1);
    }

    #[test]
    fn coincident_photons_give_the_floor_not_zero() {
        let pts = vec![Vec3::new(0.2, 0.2, 0.2); 100];
        let field = map(&pts, 10, 0.5).radius_field().expect("field");
        let r = field.radius(Vec3::new(0.2, 0.2, 0.2));
        assert!(
            r > 0.0 && r == 0.5 * super::super::estimate::MIN_RADIUS_FRACTION,
            "{r}"
        );
    }
}

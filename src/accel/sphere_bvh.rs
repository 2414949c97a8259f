//! A BVH over spheres queried by a ray segment: every sphere the segment passes through, for the
//! beam radiance estimate of volumetric photon mapping (Jarosz, Zwicker & Jensen, "The Beam
//! Radiance Estimate for Volumetric Photon Mapping", Computer Graphics Forum 27(2), 2008, §4:
//! photons as spheres of their own radius in a BVH, one query per camera ray segment instead of
//! a 3-D density estimate at many points along it).
//!
//! The tree is the renderer's eight-wide SAH BVH ([`Bvh`]) over the spheres' boxes; the query
//! visits every leaf the segment's ray enters (an all-hits walk of [`Bvh::any`] that never stops
//! early) and tests each sphere exactly: the distance from its centre to the ray's line below
//! its radius, and the foot of that perpendicular on the segment. Centres and squared radii are
//! kept in leaf-slot order, so a leaf's spheres are read from consecutive memory.

use glam::Vec3;

use super::bvh::{Bvh, PAD};
use super::traverse::RayBoxTest;
use crate::geometry::Aabb;

/// A sphere the query's segment passes through.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SphereHit {
    /// The sphere's index in the build input.
    pub index: u32,
    /// Distance along the (unit) query direction to the foot of the perpendicular from the
    /// sphere's centre, in `[0, t_max)`.
    pub t: f32,
    /// Squared distance from the centre to the ray's line (below the squared radius).
    pub d2: f32,
    /// The sphere's squared radius.
    pub r2: f32,
}

/// Spheres (centre, radius) in a BVH, queried by ray segment ([`SphereBvh::along`]).
#[derive(Debug, Clone, Default)]
pub struct SphereBvh {
    bvh: Bvh,
    /// Per leaf slot: the centre and squared radius of its sphere (`r² < 0` for padding).
    slots: Vec<[f32; 4]>,
    /// The largest radius (how far past a segment's end a box can still hold a foot before it).
    max_radius: f32,
}

impl SphereBvh {
    /// Builds the tree over `centers[i]` with radius `radii[i]` (scene units; the shorter of
    /// the two slices sets the count). Spheres with a non-finite centre or a radius that is not
    /// finite and positive are left out (no query returns them).
    #[must_use]
    pub fn build(centers: &[Vec3], radii: &[f32]) -> Self {
        let n = centers.len().min(radii.len());
        let valid = |i: usize| centers[i].is_finite() && radii[i].is_finite() && radii[i] > 0.0;
        let bounds: Vec<Aabb> = (0..n)
            .map(|i| {
                if valid(i) {
                    let r = Vec3::splat(radii[i]);
                    Aabb {
                        min: centers[i] - r,
                        max: centers[i] + r,
                    }
                } else {
                    // A point box far outside nothing: never tested (r² < 0 below).
                    Aabb {
                        min: Vec3::ZERO,
                        max: Vec3::ZERO,
                    }
                }
            })
            .collect();
        let bvh = Bvh::build(&bounds);
        let slots = bvh
            .order
            .iter()
            .map(|&i| {
                if i == PAD || !valid(i as usize) {
                    [0.0, 0.0, 0.0, -1.0]
                } else {
                    let c = centers[i as usize];
                    let r = radii[i as usize];
                    [c.x, c.y, c.z, r * r]
                }
            })
            .collect();
        let max_radius = (0..n)
            .filter(|&i| valid(i))
            .map(|i| radii[i])
            .fold(0.0f32, f32::max);
        Self {
            bvh,
            slots,
            max_radius,
        }
    }

    /// True when the tree holds no sphere.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.bvh.nodes.is_empty()
    }

    /// Bytes the tree and its slots hold.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        self.bvh.nodes.len() * std::mem::size_of::<super::Node8>()
            + self.bvh.order.len() * 4
            + self.slots.len() * 16
    }

    /// Calls `visit` for every sphere whose centre lies within its radius of the ray
    /// `origin + t·dir` (`dir` of unit length) at a foot `t` in `[0, t_max)` (`t_max` may be
    /// infinite), in the tree's leaf order (fixed by the build, so the same for every thread).
    /// No allocation.
    pub fn along(&self, origin: Vec3, dir: Vec3, t_max: f32, mut visit: impl FnMut(SphereHit)) {
        if self.is_empty() {
            return;
        }
        let test = RayBoxTest::new(origin, dir);
        let slots = &self.slots;
        let order = &self.bvh.order;
        // A sphere with its foot before `t_max` has its box entered before `t_max` plus its
        // radius; the exact test below keeps only feet in [0, t_max).
        let reach = t_max + 2.0 * self.max_radius;
        self.bvh.any(&test, reach, |first, count, _| {
            let (first, count) = (first as usize, count as usize);
            for s in first..(first + count).min(slots.len()) {
                let [x, y, z, r2] = slots[s];
                if r2 < 0.0 {
                    continue;
                }
                let v = Vec3::new(x, y, z) - origin;
                let t = v.dot(dir);
                if !(t >= 0.0 && t < t_max) {
                    continue;
                }
                let d2 = (v - dir * t).length_squared();
                if d2 < r2 {
                    visit(SphereHit {
                        index: order[s],
                        t,
                        d2,
                        r2,
                    });
                }
            }
            false
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;

    /// Every sphere the brute-force test finds, and no other, in both walks.
    #[test]
    fn the_query_returns_exactly_the_spheres_a_brute_force_test_finds() {
        let mut rng = Rng::new(11, 2);
        let n = 3000;
        let centers: Vec<Vec3> = (0..n)
            .map(|_| Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 4.0 - 2.0)
            .collect();
        let radii: Vec<f32> = (0..n).map(|_| 0.01 + 0.2 * rng.next_f32()).collect();
        let tree = SphereBvh::build(&centers, &radii);
        for q in 0..200 {
            let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 6.0 - 3.0;
            let dir = (Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) - 0.5)
                .normalize_or(Vec3::X);
            let t_max = if q % 3 == 0 {
                f32::INFINITY
            } else {
                4.0 * rng.next_f32()
            };
            let mut found: Vec<u32> = Vec::new();
            tree.along(origin, dir, t_max, |h| {
                let c = centers[h.index as usize];
                let t = (c - origin).dot(dir);
                assert!(
                    (h.t - t).abs() < 1e-5 && (h.r2 - radii[h.index as usize].powi(2)).abs() < 1e-6
                );
                found.push(h.index);
            });
            found.sort_unstable();
            let expected: Vec<u32> = (0..n as u32)
                .filter(|&i| {
                    let v = centers[i as usize] - origin;
                    let t = v.dot(dir);
                    let d2 = (v - dir * t).length_squared();
                    t >= 0.0 && t < t_max && d2 < radii[i as usize].powi(2)
                })
                .collect();
            assert_eq!(found, expected, "query {q}");
        }
    }

    #[test]
    fn bad_spheres_are_left_out_and_an_empty_tree_finds_nothing() {
        let centers = [Vec3::ZERO, Vec3::new(f32::NAN, 0.0, 0.0), Vec3::X];
        let radii = [0.5, 0.5, -1.0];
        let tree = SphereBvh::build(&centers, &radii);
        let mut found = Vec::new();
        tree.along(Vec3::new(-5.0, 0.0, 0.0), Vec3::X, f32::INFINITY, |h| {
            found.push(h.index);
        });
        assert_eq!(found, vec![0]);
        let empty = SphereBvh::build(&[], &[]);
        assert!(empty.is_empty());
        empty.along(Vec3::ZERO, Vec3::X, 1.0, |_| panic!("no sphere"));
    }
}

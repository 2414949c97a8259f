//! One decision per estimate instead of one ray per photon (issue 47, the cost of the wall
//! test): the potential walls of one estimate's segments, gathered by a single BVH region
//! query, against which each photon's segment is tested directly.
//!
//! **Why.** A wide disc (on the bath, the discs of `R = 0.48 m` where the pilot map found no
//! photon) finds photons whose marks were made for smaller discs, or photons on another level,
//! and [`walls::separated`] traced a closest-hit ray through the whole scene's BVH for each
//! (on the bath, 1.1 G of 5.4 G instructions: ~2,000 instructions a ray through the duck's, the
//! boat's and the faucet's 74,000 triangles).
//!
//! **What.** Every segment of an estimate (the lifted ends `a` near the query point and `b`
//! near each photon, [`walls::segment`]) lies in the box of all its ends, `B`. A surface the
//! segment crosses is a wall only if it is opaque, not of the query's body and its normal is
//! more than ~26° from the query's normal ([`walls::separated`]'s rule, which does not depend on
//! the photon but for the photon's normal): so every primitive that can be a wall to any of the
//! estimate's segments meets `B` and passes those tests. One BVH region query collects them
//! ([`WallList::collect`]); when they are few triangles (at most [`MAX_LISTED`]), each segment
//! is tested against them alone ([`WallList::crosses`]: a plane-side test, then the same
//! watertight triangle test the BVH uses, [`intersect_triangle`]), and an empty list needs no
//! test at all. A sphere, ellipsoid or quadric in `B`, or more triangles, and the estimate
//! traces rays as before.
//!
//! **Same decisions.** The walk of [`walls::separated`] reports a wall when one of the
//! surfaces it crosses, in order, has a normal more than ~26° from both normals and can block;
//! the list reports one when any listed triangle crossed has. They differ only where the walk
//! gives up (more than 8 parallel crossings before the wall) or steps over a wall within the
//! rounding offset of a parallel crossing (micrometres): there the list rejects the photon,
//! never accepts one the walk rejects. The list is built from the estimate's own segments
//! only, so the decision does not depend on the order of estimates or the thread count.

use glam::Vec3;

use super::walls::{self, PARALLEL_COSINE, Walls};
use crate::geometry::triangle::{TriRay, intersect_triangle};
use crate::geometry::{Aabb, Ray};
use crate::render_scene::geometry::PrimKind;

/// Most triangles a list holds; an estimate whose segments' box meets more potential walls
/// traces a ray per photon instead. The bath's tub (five boxes) and room (eight quads) give at
/// most ~40 beside a floor point.
pub const MAX_LISTED: usize = 48;

/// Most triangles the region query looks at (in leaves whose boxes meet the segments' box)
/// before it gives up and lets the estimate trace rays: a box around a mesh's thousands of
/// triangles would cost more than the rays.
pub const MAX_EXAMINED: usize = 4 * MAX_LISTED;

/// One triangle of a [`WallList`]: its corners, unit normal (as a hit on it reports it) and
/// plane offset, and its bounds.
#[derive(Debug, Clone, Copy)]
struct Listed {
    corners: [Vec3; 3],
    ng: Vec3,
    offset: f32,
    bounds: Aabb,
}

/// The triangles that can be a wall to one estimate's segments (module docs). Reused by each
/// worker (no allocation per estimate once it has grown). Reusing the list itself for the next
/// estimates nearby (collected for a box grown by a quarter, kept while the next boxes fit in
/// it) cost more on the bath than it saved: 6.34 G instructions against 6.21 G without.
#[derive(Debug, Default)]
pub struct WallList {
    listed: Vec<Listed>,
}

impl WallList {
    /// Fills the list with every triangle of `walls`' geometry that meets box `bounds` (grown
    /// by the rounding tolerance), can block ([`Walls`]) and whose unit normal has a cosine of
    /// at most [`PARALLEL_COSINE`] with the query's normal `nq` (either orientation). False
    /// when the list cannot decide: more than [`MAX_LISTED`] such triangles, or a sphere,
    /// ellipsoid or quadric that can block within `bounds` (their crossings' normals depend on
    /// where they are crossed), or a tree deeper than the region query's stack.
    pub fn collect(&mut self, walls: &Walls<'_>, nq: Vec3, bounds: &Aabb) -> bool {
        self.listed.clear();
        let geometry = walls.geometry();
        let tol = walls::tolerance(bounds.min.abs().max(bounds.max.abs()));
        let bounds = Aabb {
            min: bounds.min - Vec3::splat(tol),
            max: bounds.max + Vec3::splat(tol),
        };
        let meets = |b: &Aabb| overlaps(b, &bounds);
        let listed = &mut self.listed;
        let mut examined = 0;
        let stopped = geometry.bvh.any_leaf_in(meets, |first, count| {
            examined += count as usize;
            if examined > MAX_EXAMINED {
                return true;
            }
            for slot in first..first + count {
                let Some(&prim) = geometry.slots.get(slot as usize) else {
                    return true;
                };
                match prim.kind() {
                    PrimKind::Triangle => {
                        let Some(&corners) = geometry.triangles.get(prim.index()) else {
                            return true;
                        };
                        let [p0, p1, p2] = corners;
                        let tri_bounds = Aabb::from_points(&corners);
                        if !overlaps(&tri_bounds, &bounds) {
                            continue;
                        }
                        // Parallel to the query beyond doubt (a margin over the rounding of
                        // the normalised test below): skipped without normalising.
                        let c = (p1 - p0).cross(p2 - p0);
                        let cn = c.dot(nq);
                        if cn * cn > 0.8101 * c.length_squared() {
                            continue;
                        }
                        let ng = c.normalize();
                        // A degenerate triangle (NaN normal) is never hit.
                        if !(ng.dot(nq).abs() <= PARALLEL_COSINE)
                            || !walls.can_block_object(geometry.object_of(prim))
                        {
                            continue;
                        }
                        if listed.len() == MAX_LISTED {
                            return true;
                        }
                        listed.push(Listed {
                            corners,
                            ng,
                            offset: ng.dot(p0),
                            bounds: tri_bounds,
                        });
                    }
                    PrimKind::Sphere | PrimKind::Ellipsoid | PrimKind::Quadric => {
                        if walls.can_block_object(geometry.object_of(prim)) {
                            return true;
                        }
                    }
                }
            }
            false
        });
        !stopped
    }

    /// Number of triangles listed.
    #[must_use]
    pub fn len(&self) -> usize {
        self.listed.len()
    }

    /// True when nothing listed: no segment inside the collected box can be separated.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.listed.is_empty()
    }

    /// True when the segment from `a` to `b` (the lifted ends of [`walls::segment`], inside the
    /// collected box) crosses a listed triangle whose normal also has a cosine of at most
    /// [`PARALLEL_COSINE`] with the photon's unit normal `np`: a wall separates them.
    #[must_use]
    pub fn crosses(&self, a: Vec3, b: Vec3, np: Vec3) -> bool {
        let ray = Ray {
            origin: a,
            dir: b - a,
            t_max: 1.0,
        };
        if self.listed.is_empty() || !ray.is_valid() {
            return false;
        }
        // Ends farther than this on one side of a plane: the watertight test cannot hit it
        // (its rounding is a few ulps of the coordinates, this is 64).
        let margin = walls::tolerance(a.abs().max(b.abs()));
        let seg = Aabb {
            min: a.min(b) - Vec3::splat(margin),
            max: a.max(b) + Vec3::splat(margin),
        };
        let tri_ray = TriRay::new(&ray);
        self.listed.iter().any(|w| {
            let (sa, sb) = (w.ng.dot(a) - w.offset, w.ng.dot(b) - w.offset);
            w.ng.dot(np).abs() <= PARALLEL_COSINE
                && !((sa > margin && sb > margin) || (sa < -margin && sb < -margin))
                && overlaps(&w.bounds, &seg)
                && intersect_triangle(&tri_ray, w.corners[0], w.corners[1], w.corners[2], 1.0)
                    .is_some()
        })
    }
}

/// Whether boxes `a` and `b` share a point.
#[inline]
fn overlaps(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use super::*;
    use crate::integrators::photon::walls::{near_wall, reach, segment, separated, tolerance};
    use crate::integrators::photon::{Kernel, PhotonMap};
    use crate::render_scene::Geometry;
    use crate::render_scene::geometry::{GeometryBuilder, TriAttrs};
    use crate::sampling::Rng;
    use crate::spatial::{KdTree, Photon};

    /// Adds quad `c` (corners in order) as two triangles of object `object`.
    fn quad(b: &mut GeometryBuilder, c: [Vec3; 4], object: u32) {
        for t in [[c[0], c[1], c[2]], [c[0], c[2], c[3]]] {
            b.triangles.push(t);
            b.tri_attrs.push(TriAttrs {
                object,
                normals: None,
                uvs: [Vec2::ZERO; 3],
            });
        }
    }

    /// The reported two rooms: a floor y = 0 (x ∈ [-2, 2], z ∈ [-1, 1]) split by a single
    /// quad at x = 0, and a 2 cm cube standing on the floor at x ∈ [-0.5, -0.48],
    /// z ∈ [-0.01, 0.01] (its five faces).
    fn rooms() -> Geometry {
        let c = Vec3::new;
        let mut b = GeometryBuilder::default();
        quad(
            &mut b,
            [
                c(-2.0, 0.0, -1.0),
                c(-2.0, 0.0, 1.0),
                c(2.0, 0.0, 1.0),
                c(2.0, 0.0, -1.0),
            ],
            0,
        );
        quad(
            &mut b,
            [
                c(0.0, -0.2, -1.2),
                c(0.0, 2.2, -1.2),
                c(0.0, 2.2, 1.2),
                c(0.0, -0.2, 1.2),
            ],
            1,
        );
        let (lo, hi) = (c(-0.5, 0.0, -0.01), c(-0.48, 0.02, 0.01));
        for f in [
            [
                c(lo.x, lo.y, lo.z),
                c(lo.x, hi.y, lo.z),
                c(lo.x, hi.y, hi.z),
                c(lo.x, lo.y, hi.z),
            ],
            [
                c(hi.x, lo.y, lo.z),
                c(hi.x, hi.y, lo.z),
                c(hi.x, hi.y, hi.z),
                c(hi.x, lo.y, hi.z),
            ],
            [
                c(lo.x, lo.y, lo.z),
                c(hi.x, lo.y, lo.z),
                c(hi.x, hi.y, lo.z),
                c(lo.x, hi.y, lo.z),
            ],
            [
                c(lo.x, lo.y, hi.z),
                c(hi.x, lo.y, hi.z),
                c(hi.x, hi.y, hi.z),
                c(lo.x, hi.y, hi.z),
            ],
            [
                c(lo.x, hi.y, lo.z),
                c(hi.x, hi.y, lo.z),
                c(hi.x, hi.y, hi.z),
                c(lo.x, hi.y, hi.z),
            ],
        ] {
            quad(&mut b, f, 2);
        }
        b.build()
    }

    #[test]
    fn the_list_decides_as_the_ray_does() {
        // Reference: walls::separated's ray walk. Floor points near the divider and the cube,
        // photons on the floor and on the cube's top within 30 cm: one list per query point,
        // collected for the box of its segments, decides every photon as the ray does.
        let g = rooms();
        let walls = Walls::every_surface(&g);
        let mut rng = Rng::new(3, 5);
        let mut list = WallList::default();
        let (mut hidden, mut seen) = (0, 0);
        for i in 0..200 {
            let (u, v) = rng.next_2d();
            let centre = if i % 2 == 0 { -0.05 } else { -0.49 };
            let q = Vec3::new(centre + 0.2 * (u - 0.5), 0.0, 0.2 * (v - 0.5));
            let photons: Vec<(Vec3, Vec3)> = (0..8)
                .map(|j| {
                    let (a, b) = rng.next_2d();
                    let p = q + Vec3::new(0.6 * (a - 0.5), 0.0, 0.6 * (b - 0.5));
                    let on_top = j == 0 && i % 2 == 1;
                    if on_top {
                        (Vec3::new(-0.49, 0.02, 0.005 * (b - 0.5)), Vec3::Y)
                    } else {
                        (p, Vec3::Y)
                    }
                })
                .collect();
            let bounds = photons
                .iter()
                .filter_map(|&(p, np)| segment(q, Vec3::Y, p, np))
                .fold(Aabb::EMPTY, |b, (a, e)| b.grow(a).grow(e));
            assert!(list.collect(&walls, Vec3::Y, &bounds), "{q}");
            for &(p, np) in &photons {
                let by_ray = separated(&walls, q, Vec3::Y, p, np);
                let by_list =
                    segment(q, Vec3::Y, p, np).is_some_and(|(a, b)| list.crosses(a, b, np));
                assert_eq!(by_list, by_ray, "{q} {p}");
                hidden += usize::from(by_ray);
                seen += usize::from(!by_ray);
            }
        }
        assert!(hidden > 100 && seen > 400, "{hidden} hidden, {seen} seen");
    }

    /// Photons on a 2 cm grid (offset by 1 cm, so none lies on the divider) over the floor
    /// square of half-side `half` around `c`, arriving straight down with power 1 W.
    fn floor_grid(c: Vec3, half: f32) -> Vec<Photon> {
        let n = (2.0 * half / 0.02).round() as i32;
        let mut out = Vec::new();
        for i in 0..n {
            for k in 0..n {
                let p = c + Vec3::new(
                    -half + 0.01 + 0.02 * i as f32,
                    0.0,
                    -half + 0.01 + 0.02 * k as f32,
                );
                out.push(Photon::new(p, -Vec3::Y, Vec3::Y, Vec3::ONE));
            }
        }
        out
    }

    #[test]
    fn a_query_far_from_walls_tests_nothing_and_one_beside_the_divider_rejects_the_far_room() {
        // Every photon within the largest radius (10 cm) counts (fewer than k), so the
        // estimate is the count of the photons it keeps over π r². Hand count: of the grid's
        // photons within 10 cm of the query, those with x > 0 are in the far room.
        let g = rooms();
        let mut photons = floor_grid(Vec3::ZERO, 0.3);
        photons.extend(floor_grid(Vec3::new(-1.5, 0.0, 0.5), 0.2));
        let r = 0.1f32;
        let map_photons = photons.clone();
        let mut map = PhotonMap::new(
            KdTree::build(map_photons).expect("tree"),
            100_000,
            r,
            Kernel::Box,
        );
        map.mark_walls(Walls::every_surface(&g));
        let area = std::f32::consts::PI * r * r;

        let far = Vec3::new(-1.5, 0.0, 0.503);
        let e = map.irradiance(far, Vec3::Y, Walls::every_surface(&g));
        let inside = photons
            .iter()
            .filter(|ph| ph.position().distance(far) < r)
            .count();
        assert!(inside > 60 && e.found == inside, "{e:?}");
        assert_eq!((e.rays, e.listed, e.hidden), (0, 0, 0), "{e:?}");
        assert!((e.radiance.x / (inside as f32 / area) - 1.0).abs() < 1e-5);

        for q in [Vec3::new(-0.05, 0.0, 0.003), Vec3::new(-0.001, 0.0, -0.07)] {
            let e = map.irradiance(q, Vec3::Y, Walls::every_surface(&g));
            let within: Vec<Vec3> = photons
                .iter()
                .map(Photon::position)
                .filter(|p| p.distance(q) < r)
                .collect();
            let beyond = within.iter().filter(|p| p.x > 0.0).count();
            let kept = within.len() - beyond;
            assert!(beyond > 10, "{q}: {beyond}");
            assert_eq!(e.hidden as usize, beyond, "{q}: {e:?}");
            assert_eq!(e.rays, 0, "decided by the list: {e:?}");
            assert!(
                e.listed as usize >= beyond && e.listed as usize <= within.len(),
                "{e:?}"
            );
            assert!(
                (e.radiance.x / (kept as f32 / area) - 1.0).abs() < 1e-5,
                "{e:?}"
            );
        }
    }

    #[test]
    fn a_photon_is_clear_of_the_divider_up_to_the_radius_its_distance_allows() {
        // The divider (x = 0) is the only wall near a floor photon 10 cm from it: the photon
        // is marked for an estimate of radius ρ exactly when its reach 1.25 ρ + 12 τ meets the
        // divider, ρ = (0.1 − 12 τ) / 1.25 by hand (τ = 64 ε (1 + 0.5) at z = 0.5).
        let g = rooms();
        let walls = Walls::every_surface(&g);
        for s in [0.1f32, 0.03] {
            let p = Vec3::new(s, 0.0, 0.5);
            let tau = 64.0 * f32::EPSILON * 1.5;
            assert_eq!(tolerance(p), tau);
            let clear = (s - 12.0 * tau) / 1.25;
            assert!((reach(p, clear) - s).abs() < 1e-6);
            assert!(!near_wall(&walls, p, Vec3::Y, clear * (1.0 - 1e-4)), "{s}");
            assert!(near_wall(&walls, p, Vec3::Y, clear * (1.0 + 1e-4)), "{s}");
        }
    }
}

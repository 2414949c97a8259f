//! The wall list of one estimate (issue 47, the cost of the wall test): the potential walls of
//! its cell of the map's grid ([`super::wall_grid::WallGrid`]), against which each tested
//! photon's segment is decided directly instead of by a ray through the scene.
//!
//! **Why.** A wide disc (on the bath, the discs of `R = 0.48 m` where the pilot map found no
//! photon) finds photons whose marks were made for smaller discs, or photons on another level,
//! and [`walls::separated`] traced a closest-hit ray through the whole scene's BVH for each
//! (on the bath, 1.1 G of 5.4 G instructions: ~2,000 instructions a ray through the duck's, the
//! boat's and the faucet's 74,000 triangles).
//!
//! **What.** Every segment of an estimate of radius `r` around `q` (the lifted ends of
//! [`walls::segment`]) lies within [`estimate_reach`](super::wall_grid::estimate_reach) of `q`.
//! A surface the segment crosses is a wall only if it is opaque, not of the query's body and
//! its normal is more than ~26° from the query's normal ([`walls::separated`]'s rule, which
//! does not depend on the photon but for the photon's normal). The cell holding `q` lists every
//! opaque surface within that reach; each tested segment is decided against it
//! ([`CellList::crosses`]: the candidates' boxes eight at once against the segment's, then for
//! the few that meet it the normal, body and plane-side tests and the same watertight triangle
//! test the BVH uses, [`intersect_triangle`]). A segment whose box meets a candidate known
//! only by its bounds (a mesh, a sphere) is decided by a ray. Filtering the cell's candidates
//! once per estimate into a list of its own (by the query's normal, body and reach) cost more
//! on the bath than testing the cell's boxes per segment (5.994 G against 5.931 G).
//!
//! **Same decisions.** The walk of [`walls::separated`] reports a wall when one of the
//! surfaces it crosses, in order, has a normal more than ~26° from both normals and can block;
//! the list reports one when any listed triangle crossed has. They differ only where the walk
//! gives up (more than 8 parallel crossings before the wall) or steps over a wall within the
//! rounding offset of a parallel crossing (micrometres): there the list rejects the photon,
//! never accepts one the walk rejects. The list depends only on the geometry, the query point
//! and the map's grid, so the decision does not depend on the order of estimates or the
//! thread count.

use glam::Vec3;
use wide::f32x8;

use super::wall_grid::{CellList, LANES, Wall, WallKind};
use super::walls::{self, PARALLEL_COSINE};
use crate::geometry::Ray;
use crate::geometry::triangle::{TriRay, intersect_triangle};

/// How a segment meets an estimate's wall list ([`CellList::crosses`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Crossing {
    /// It crosses a listed triangle that stands across both ends' surfaces: a wall.
    Wall,
    /// It crosses no wall.
    Clear,
    /// Its box meets a candidate known only by its bounds: a ray decides.
    Unknown,
}

impl<'a> CellList<'a> {
    /// The cell's candidates.
    pub fn walls(&self) -> impl Iterator<Item = &'a Wall> {
        let grid = self.grid;
        grid.slot
            .get(self.start..self.end)
            .unwrap_or_default()
            .iter()
            .filter_map(move |&i| grid.walls.get(i as usize))
    }

    /// Whether the segment from `a` to `b` (the lifted ends of [`walls::segment`] between a
    /// query point of unit normal `nq` on body `own` and a photon of unit normal `np`) crosses
    /// a candidate triangle of another body whose normal has a cosine of at most
    /// [`PARALLEL_COSINE`] with both normals ([`Crossing::Wall`]), or its box meets a candidate
    /// of another body known by its bounds only ([`Crossing::Unknown`]). The candidates' boxes
    /// are tested [`LANES`] at once against the segment's; the few that meet it get the
    /// normal tests, a plane-side test and the BVH's own watertight triangle test
    /// ([`intersect_triangle`]).
    #[must_use]
    pub fn crosses(&self, a: Vec3, b: Vec3, nq: Vec3, np: Vec3, own: Option<u32>) -> Crossing {
        let ray = Ray {
            origin: a,
            dir: b - a,
            t_max: 1.0,
        };
        if !ray.is_valid() {
            return Crossing::Clear;
        }
        // Ends farther than this on one side of a plane: the watertight test cannot hit it
        // (its rounding is a few ulps of the coordinates, this is 64).
        let margin = walls::tolerance(a.abs().max(b.abs()));
        let (lo, hi) = (
            a.min(b) - Vec3::splat(margin),
            a.max(b) + Vec3::splat(margin),
        );
        let g = self.grid;
        let load =
            |v: &[f32x8], i: usize| v.get(i / LANES).copied().unwrap_or(f32x8::splat(f32::NAN));
        let (lx, ly, lz) = (f32x8::splat(lo.x), f32x8::splat(lo.y), f32x8::splat(lo.z));
        let (hx, hy, hz) = (f32x8::splat(hi.x), f32x8::splat(hi.y), f32x8::splat(hi.z));
        let mut tri_ray = None;
        let mut unknown = false;
        let mut i = self.start;
        while i < self.end {
            // Boxes sharing a point with the segment's (padding and NaN lanes never do).
            let meets = load(&g.lo[0], i).simd_le(hx)
                & load(&g.lo[1], i).simd_le(hy)
                & load(&g.lo[2], i).simd_le(hz)
                & lx.simd_le(load(&g.hi[0], i))
                & ly.simd_le(load(&g.hi[1], i))
                & lz.simd_le(load(&g.hi[2], i));
            let mut hits = meets.to_bitmask();
            while hits != 0 {
                let lane = hits.trailing_zeros() as usize;
                hits &= hits - 1;
                let Some(w) = g.slot.get(i + lane).and_then(|&k| g.walls.get(k as usize)) else {
                    continue;
                };
                if Some(w.body) == own {
                    continue;
                }
                match w.kind {
                    WallKind::Bounds => unknown = true,
                    WallKind::Triangle => {
                        let (sa, sb) = (w.ng.dot(a) - w.offset, w.ng.dot(b) - w.offset);
                        if w.ng.dot(nq).abs() <= PARALLEL_COSINE
                            && w.ng.dot(np).abs() <= PARALLEL_COSINE
                            && !((sa > margin && sb > margin) || (sa < -margin && sb < -margin))
                        {
                            let tri_ray = tri_ray.get_or_insert_with(|| TriRay::new(&ray));
                            let [c0, c1, c2] = w.corners;
                            if intersect_triangle(tri_ray, c0, c1, c2, 1.0).is_some() {
                                return Crossing::Wall;
                            }
                        }
                    }
                }
            }
            i += LANES;
        }
        if unknown {
            Crossing::Unknown
        } else {
            Crossing::Clear
        }
    }
}

#[cfg(test)]
pub(super) mod tests {
    use glam::Vec2;

    use super::*;
    use crate::integrators::photon::wall_grid::{Listing, WallGrid, estimate_reach};
    use crate::integrators::photon::walls::{
        Walls, near_wall, reach, segment, separated, tolerance,
    };
    use crate::integrators::photon::{Kernel, PhotonMap};
    use crate::render_scene::Geometry;
    use crate::render_scene::geometry::{GeometryBuilder, TriAttrs};
    use crate::sampling::Rng;
    use crate::spatial::{KdTree, Photon};

    /// Adds quad `c` (corners in order) as two triangles of object `object` (also the potential
    /// walls' tests' builder).
    pub(in crate::integrators::photon) fn quad(b: &mut GeometryBuilder, c: [Vec3; 4], object: u32) {
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
        // photons on the floor and on the cube's top within 0.43 m: one list per query point,
        // filled from its cell of a grid built for that radius, decides every photon as the
        // ray does (the scene is triangles of small objects only: no ray is needed).
        let g = rooms();
        let walls = Walls::every_surface(&g);
        let radius = 0.43;
        let grid_reach = 1.2501 * radius + 12.0 * tolerance(Vec3::splat(2.2));
        let grid = WallGrid::build(&walls, grid_reach).expect("grid");
        let mut rng = Rng::new(3, 5);
        let (mut hidden, mut seen) = (0, 0);
        for i in 0..200 {
            let (u, v) = rng.next_2d();
            let centre = if i % 2 == 0 { -0.05 } else { -0.49 };
            let q = Vec3::new(centre + 0.2 * (u - 0.5), 0.0, 0.2 * (v - 0.5));
            let reach = estimate_reach(q, radius);
            let list = grid.near(q, reach).expect("a cell with a list");
            for j in 0..8 {
                let (a, b) = rng.next_2d();
                let on_top = j == 0 && i % 2 == 1;
                let (p, np) = if on_top {
                    (Vec3::new(-0.49, 0.02, 0.005 * (b - 0.5)), Vec3::Y)
                } else {
                    (
                        q + Vec3::new(0.6 * (a - 0.5), 0.0, 0.6 * (b - 0.5)),
                        Vec3::Y,
                    )
                };
                let by_ray = separated(&walls, q, Vec3::Y, p, np);
                let by_list =
                    segment(q, Vec3::Y, p, np).map(|(a, b)| list.crosses(a, b, Vec3::Y, np, None));
                assert_ne!(by_list, Some(Crossing::Unknown), "{q} {p}");
                assert_eq!(by_list == Some(Crossing::Wall), by_ray, "{q} {p}");
                hidden += usize::from(by_ray);
                seen += usize::from(!by_ray);
            }
        }
        assert!(hidden > 100 && seen > 400, "{hidden} hidden, {seen} seen");
    }

    #[test]
    fn a_cell_lists_the_surfaces_within_reach_and_an_estimate_keeps_the_walls_among_them() {
        // Hand count on the rooms (floor: 2 triangles spanning it, divider at x = 0: 2, cube at
        // x ∈ [-0.5, -0.48], z ∈ [-0.01, 0.01]: 10). Reach 0.1: cells of side
        // max(0.1, 4/24) = 1/6 m from x = -2, each listing what meets it grown by the reach.
        // x = -1.5 (cell [-1.67, -1.5] or [-1.5, -1.33]): the floor alone, which lies in the
        // query's plane (no wall). x = -0.05 (cell [-1/6, 0], grown to [-0.27, 0.1]): floor
        // and divider; the divider is a wall. x = -0.2 (cell [-1/3, -1/6], grown to
        // [-0.43, -0.07]): the floor alone. x = -0.45 (cell [-1/2, -1/3]): floor and cube, whose
        // four side faces are walls to a floor point (its top lies in the floor's plane).
        // Listing only the potential walls (super::potential_walls) leaves out the cube's
        // bottom, which lies on the floor with nothing beyond it: 10 at x = -0.45.
        let g = rooms();
        let walls = Walls::every_surface(&g);
        let potential = WallGrid::build(&walls, 0.1).expect("grid");
        let counts: Vec<usize> = [-1.5f32, -0.05, -0.2, -0.45]
            .iter()
            .map(|&x| {
                let list = potential
                    .near(Vec3::new(x, 0.0, 0.0), 0.05)
                    .expect("a list");
                list.walls().count()
            })
            .collect();
        assert_eq!(counts, [2, 4, 2, 10]);
        let grid = WallGrid::build_listing(&walls, 0.1, Listing::Every).expect("grid");
        for (x, cell, across) in [(-1.5f32, 2, 0), (-0.05, 4, 2), (-0.2, 2, 0), (-0.45, 12, 8)] {
            let q = Vec3::new(x, 0.0, 0.0);
            let list = grid.near(q, 0.05).expect("a list");
            assert_eq!(list.walls().count(), cell, "{x}");
            let standing = list
                .walls()
                .filter(|w| w.kind == WallKind::Triangle && w.ng.dot(Vec3::Y).abs() <= 0.9)
                .count();
            assert_eq!(standing, across, "{x}");
        }
        // Across the divider from x = -0.05, a wall; along the floor, none.
        let q = Vec3::new(-0.05, 0.0, 0.0);
        let list = grid.near(q, 0.1).expect("a list");
        for (p, hidden) in [
            (Vec3::new(0.03, 0.0, 0.01), true),
            (Vec3::new(-0.12, 0.0, 0.05), false),
        ] {
            let (a, b) = segment(q, Vec3::Y, p, Vec3::Y).expect("a segment");
            let expected = if hidden {
                Crossing::Wall
            } else {
                Crossing::Clear
            };
            assert_eq!(list.crosses(a, b, Vec3::Y, Vec3::Y, None), expected, "{p}");
        }
        // An estimate wider than the grid's reach gets no list.
        assert!(grid.near(Vec3::new(-1.5, 0.0, 0.0), 0.2).is_none());
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

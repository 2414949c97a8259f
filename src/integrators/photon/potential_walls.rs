//! Which opaque surfaces can separate anything (issue 47, the cost of the wall test): a
//! candidate wall that no segment an estimate tests can cross is left out of every cell of the
//! map's grid ([`super::wall_grid::WallGrid`]). Most surfaces of a real scene are of this kind:
//! the five walls of a Cornell box, a room's outer walls, a floor under everything.
//!
//! **The segments.** An estimate of radius `r` at a query point `q` (on a surface, unit
//! geometric normal `n_q`) tests a photon at `p` (on a surface, normal `n_p`, `d = |p − q| ≤ r`)
//! by the segment `a = q + h n_q`, `b = p + h n_p` ([`walls::segment`]), lifted by
//! `h = τ (1 + 1/max(n_q·n_p, 0.1)) + d |n_q × n_p| / 4 ≤ 11 τ + r/4` (`τ` the larger rounding
//! tolerance of the two points, at most the scene's, `s`). A grid of reach `R` answers only
//! estimates with `1.2501 r + 12 τ(q) ≤ R` ([`super::wall_grid::estimate_reach`]), so
//! `r ≤ 0.8 R` and `h ≤ H = 0.2 R + 12 s`.
//!
//! **Claim 1 (a triangle is crossed only between its plane's two sides).** The list reports a
//! triangle `T` (unit normal `n`, plane `n·x = c`) crossed by `ab` only when `T`'s normal is more
//! than ~26° from both ends' (`|n·n_q| ≤ 0.9`, `|n·n_p| ≤ 0.9`) and the ends' signed distances
//! `σ(a), σ(b)` (`σ(x) = n·x − c`) are not both above the margin `m` nor both below `−m`
//! ([`CellList::crosses`](super::wall_grid::CellList::crosses) tests exactly this before the
//! watertight test). So some end has `σ ≤ m` and some end has `σ ≥ −m`.
//!
//! **Claim 2 (where the ends come from).** The crossing point `x` lies on `T` (within its box
//! and the rounding `s`). Each end lies within `|a − b| ≤ d + 2h` of `x`, and its surface point
//! (`q` or `p`) within `h` more: within `G = r + 3H + s ≤ 1.4 R + 37 s` of `T`'s box. An end on a
//! surface `S` whose normal is within ~26° of `n` (`|n_S·n| > 0.9`) cannot be an end of a
//! segment `T` counts. Lifting a point of `S` moves its `σ` by at most `H |n_S·n|`
//! (`n_S` the normal of `S` there; for a sphere, by at most `H`).
//!
//! **The criterion.** Let `D⁺` (`D⁻`) be true when some primitive of the scene (any material:
//! water and glass hold query points and photons too) that is not parallel to `T` and whose box
//! meets `T`'s box grown by `G` has a point whose `σ`, moved by its largest lift, exceeds `δ`
//! (is below `−δ`), `δ = s` the rounding tolerance of the scene's coordinates. `T` is a
//! potential wall only when `D⁺` and `D⁻`. Otherwise, say no `D⁻`: every end of every segment
//! `T` counts has `σ ≥ −δ`; by Claim 1 a crossing then needs an end with `−δ ≤ σ ≤ m`, that is
//! an end on `T`'s plane within the rounding of the coordinates — a point on the seam where `T`
//! meets a surface running up to it (the floor at a Cornell wall's foot), which the full list
//! could reject or not by the rounding of one coordinate, not by anything standing between. So
//! leaving `T` out changes no decision but those of ends within `max(δ, m)` of its plane at
//! such a seam (micrometres); the renders of every scene with the photon integrators are the
//! same bytes with and without it (docs/photon_map.md).
//!
//! The test is conservative everywhere: a triangle's `σ` range is taken over the whole
//! triangle (not only its part within `G`), a sphere's as its centre's `± 0.901 (radius + H)` (its points
//! whose normal is not parallel to `T`'s), an
//! ellipsoid's or quadric's as its box's (its leaf's box having met the region); keeping a
//! surface that could be left out costs time, never a decision.
//!
//! **Spheres, ellipsoids and quadrics as walls** (listed by their boxes) are kept when a
//! primitive of another object has a box meeting theirs grown by `G`: a segment crossing one
//! has its query end on another body ([`walls::Walls`]: never a wall to its own body's points),
//! within `G` of the crossing. A ball on a floor is kept, a ball alone in the air is not.
//! Meshes of more than [`SMALL_OBJECT`](super::wall_grid::SMALL_OBJECT) triangles are kept
//! (asking for every other object near a mesh would walk its own triangles).
//!
//! Everything here depends on the geometry and the grid's reach only: the same for any seed,
//! thread count or crop. Two BVH region queries per triangle candidate, each pruned to the
//! half-space it looks for, when a grid is built (once per photon map).

use glam::Vec3;

use super::wall_grid::{Wall, overlaps};
use crate::geometry::Aabb;
use crate::render_scene::Geometry;
use crate::render_scene::geometry::{PrimKind, PrimRef};

/// A surface whose unit normal has a cosine above this with a triangle's (either orientation)
/// never holds an end of a segment the triangle counts for ([`walls::PARALLEL_COSINE`] plus a
/// margin for the rounding of the hit's normal).
///
/// [`walls::PARALLEL_COSINE`]: super::walls::PARALLEL_COSINE
const PARALLEL: f32 = super::walls::PARALLEL_COSINE + 1e-3;

/// The distances the criterion uses for a grid of reach `reach` in a scene of rounding
/// tolerance `slack` (module docs).
#[derive(Debug, Clone, Copy)]
pub struct Reach {
    /// `G`: the largest distance from a crossing point to a segment end's surface point.
    pub far: f32,
    /// `H`: the largest lift of a segment end off its surface.
    pub lift: f32,
    /// `δ`: how far a point must lie beyond a plane to count as beyond it.
    pub delta: f32,
}

impl Reach {
    /// The distances for a grid of reach `reach` (scene units) in a scene whose coordinates'
    /// rounding tolerance is `slack` ([`super::walls::tolerance`] at its farthest corner).
    #[must_use]
    pub fn new(reach: f32, slack: f32) -> Self {
        Self {
            far: 1.4 * reach + 37.0 * slack,
            lift: 0.2 * reach + 12.0 * slack,
            delta: slack,
        }
    }
}

/// Whether triangle candidate `w` can separate a query point from a photon of an estimate the
/// grid of `reach` answers: `D⁺` and `D⁻` (module docs); true whenever in doubt.
#[must_use]
pub fn triangle_can_separate(geometry: &Geometry, w: &Wall, reach: Reach) -> bool {
    let zone = grown(&w.bounds, reach.far);
    has_side(geometry, w, &zone, reach, 1.0) && has_side(geometry, w, &zone, reach, -1.0)
}

/// Whether a sphere, ellipsoid or quadric of object `object` within box `bounds` can separate a
/// query point from a photon of an estimate the grid of `reach` answers: a primitive of another
/// object has a box meeting `bounds` grown by `G` (module docs); true whenever in doubt.
#[must_use]
pub fn solid_can_separate(geometry: &Geometry, bounds: &Aabb, object: u32, reach: Reach) -> bool {
    let zone = grown(bounds, reach.far);
    geometry.bvh.any_leaf_in(
        |b| overlaps(b, &zone),
        |first, count| {
            (first..first + count).any(|slot| {
                geometry.slots.get(slot as usize).is_none_or(|&prim| {
                    geometry.object_of(prim) != object
                        && overlaps(&prim_bounds(geometry, prim), &zone)
                })
            })
        },
    )
}

/// Box `b` grown by `by` on every side.
fn grown(b: &Aabb, by: f32) -> Aabb {
    Aabb {
        min: b.min - Vec3::splat(by),
        max: b.max + Vec3::splat(by),
    }
}

/// `D⁺` (`sign` 1) or `D⁻` (`sign` −1) of triangle `w` (module docs): some primitive not
/// parallel to `w`, meeting `zone`, has a point that its largest lift can take beyond
/// `sign·σ > δ`.
fn has_side(geometry: &Geometry, w: &Wall, zone: &Aabb, reach: Reach, sign: f32) -> bool {
    let n = sign * w.ng;
    let c = sign * w.offset;
    let beyond = reach.delta;
    // The box's highest `sign·σ` (its farthest corner), raised by the largest lift.
    let meets = |b: &Aabb| {
        overlaps(b, zone) && (b.min * n).max(b.max * n).element_sum() - c + reach.lift > beyond
    };
    geometry.bvh.any_leaf_in(meets, |first, count| {
        (first..first + count).any(|slot| {
            let Some(&prim) = geometry.slots.get(slot as usize) else {
                return true;
            };
            match prim.kind() {
                PrimKind::Triangle => geometry.triangles.get(prim.index()).is_none_or(|t| {
                    let ns = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
                    let cos = ns.dot(n).abs();
                    cos <= PARALLEL
                        && t.iter()
                            .map(|&v| n.dot(v))
                            .fold(f32::NEG_INFINITY, f32::max)
                            - c
                            + reach.lift * cos
                            > beyond
                        && overlaps(&Aabb::from_points(t), zone)
                }),
                // Its points whose normal u is not parallel (|u·n| ≤ PARALLEL) lie at most
                // PARALLEL · radius beyond its centre's plane, and lift at most PARALLEL · H.
                PrimKind::Sphere => geometry.spheres.get(prim.index()).is_none_or(|s| {
                    n.dot(s.center) - c + PARALLEL * (s.radius + reach.lift) > beyond
                        && overlaps(&prim_bounds(geometry, prim), zone)
                }),
                // Alone in their leaves: the leaf's box, which met the test, is theirs.
                PrimKind::Ellipsoid | PrimKind::Quadric => true,
            }
        })
    })
}

/// A box holding primitive `prim` (the whole scene's when it is unknown).
fn prim_bounds(geometry: &Geometry, prim: PrimRef) -> Aabb {
    match prim.kind() {
        PrimKind::Triangle => geometry
            .triangles
            .get(prim.index())
            .map_or(geometry.bvh.bounds, |t| Aabb::from_points(t)),
        PrimKind::Sphere => geometry
            .spheres
            .get(prim.index())
            .map_or(geometry.bvh.bounds, |s| {
                let r = Vec3::splat(s.radius * (1.0 + 1e-6));
                Aabb {
                    min: s.center - r,
                    max: s.center + r,
                }
            }),
        PrimKind::Ellipsoid | PrimKind::Quadric => geometry.bvh.bounds,
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use super::*;
    use crate::integrators::photon::wall_grid::{Listing, WallGrid, WallKind, estimate_reach};
    use crate::integrators::photon::wall_list::Crossing;
    use crate::integrators::photon::walls::{Walls, segment, separated, tolerance};
    use crate::render_scene::geometry::{GeometryBuilder, SpherePrim, TriAttrs};
    use crate::sampling::Rng;

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

    /// The six faces of the box `lo`–`hi` (object `object`), each as a quad; with `open`, no
    /// face at `z = hi.z` (a Cornell box's open front).
    fn cuboid(b: &mut GeometryBuilder, lo: Vec3, hi: Vec3, object: u32, open: bool) {
        let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
        let (l, h) = (lo, hi);
        let mut faces = vec![
            [
                c(l.x, l.y, l.z),
                c(h.x, l.y, l.z),
                c(h.x, l.y, h.z),
                c(l.x, l.y, h.z),
            ],
            [
                c(l.x, h.y, l.z),
                c(h.x, h.y, l.z),
                c(h.x, h.y, h.z),
                c(l.x, h.y, h.z),
            ],
            [
                c(l.x, l.y, l.z),
                c(l.x, h.y, l.z),
                c(l.x, h.y, h.z),
                c(l.x, l.y, h.z),
            ],
            [
                c(h.x, l.y, l.z),
                c(h.x, h.y, l.z),
                c(h.x, h.y, h.z),
                c(h.x, l.y, h.z),
            ],
            [
                c(l.x, l.y, l.z),
                c(h.x, l.y, l.z),
                c(h.x, h.y, l.z),
                c(l.x, h.y, l.z),
            ],
        ];
        if !open {
            faces.push([
                c(l.x, l.y, h.z),
                c(h.x, l.y, h.z),
                c(h.x, h.y, h.z),
                c(l.x, h.y, h.z),
            ]);
        }
        for f in faces {
            quad(b, f, object);
        }
    }

    /// The candidates of a grid of reach `reach` over `g`'s surfaces: (triangles per object,
    /// bounds-only candidates).
    fn listed(g: &Geometry, reach: f32, listing: Listing) -> (Vec<usize>, usize) {
        let grid =
            WallGrid::build_listing(&Walls::every_surface(g), reach, listing).expect("a grid");
        let mut per_object = vec![0usize; 8];
        let mut solids = 0;
        for w in &grid.walls {
            match w.kind {
                WallKind::Triangle => per_object[w.body as usize] += 1,
                WallKind::Bounds => solids += 1,
            }
        }
        (per_object, solids)
    }

    #[test]
    fn a_cornell_box_s_walls_are_no_walls_and_its_ball_on_the_floor_is() {
        // Hand geometry: the five faces of [-1, 1]³ open at z = 1 (object 0), a ball of radius
        // 0.3 resting on the floor (object 1) and one alone in the air (object 2, 0.5 m from
        // everything at reach 0.1: G = 1.4 · 0.1 + 37 s ≈ 0.14 m). Every surface lies on the
        // room's side of each wall, so no wall is listed; the resting ball meets the floor. The
        // resting ball's points not parallel to the floor lie at least 0.3 (1 − 0.901) = 0.030 m
        // above it, more than their largest lift 0.901 H = 0.018 m (H = 0.2 · 0.1 + 12 s); at
        // reach 0.5 (0.901 H = 0.090 m) they could be lifted below it, and the floor is listed.
        let mut b = GeometryBuilder::default();
        cuboid(&mut b, Vec3::splat(-1.0), Vec3::splat(1.0), 0, true);
        b.spheres.push(SpherePrim {
            center: Vec3::new(-0.4, -0.7, 0.0),
            radius: 0.3,
            object: 1,
        });
        b.spheres.push(SpherePrim {
            center: Vec3::new(0.4, 0.0, 0.0),
            radius: 0.1,
            object: 2,
        });
        let g = b.build();
        assert_eq!(
            listed(&g, 0.1, Listing::Every),
            (vec![10, 0, 0, 0, 0, 0, 0, 0], 2)
        );
        assert_eq!(listed(&g, 0.1, Listing::PotentialWalls), (vec![0; 8], 1));
        // Reach 0.5 (G ≈ 0.7 m): the floating ball is within G of the walls and stays.
        assert_eq!(
            listed(&g, 0.5, Listing::PotentialWalls),
            (vec![2, 0, 0, 0, 0, 0, 0, 0], 2)
        );
    }

    #[test]
    fn a_wall_is_kept_exactly_when_a_surface_lies_beyond_it_within_reach() {
        // A wall x = 0 (y ∈ [0, 1], z ∈ [-1, 1], object 0) with a floor before it (x ∈ [-1, 0],
        // object 1, meeting it at its foot: not beyond) and a strip of floor beyond it at
        // x ∈ [gap, gap + 0.1] (object 2). Reach 0.2: G = 1.4 · 0.2 + 37 s. The wall is listed
        // when the strip starts within G of it, not when it starts beyond; the floor never (its
        // surfaces lie above it, nothing non-parallel below); the strip never.
        let reach = 0.2f32;
        let slack = tolerance(Vec3::splat(1.0 + 1.4 * reach + 0.1));
        for (gap, kept) in [
            (0.0, false),
            (0.99 * (1.4 * reach), true),
            (1.01 * (1.4 * reach + 37.0 * slack), false),
        ] {
            let c = Vec3::new;
            let mut b = GeometryBuilder::default();
            quad(
                &mut b,
                [
                    c(0.0, 0.0, -1.0),
                    c(0.0, 1.0, -1.0),
                    c(0.0, 1.0, 1.0),
                    c(0.0, 0.0, 1.0),
                ],
                0,
            );
            quad(
                &mut b,
                [
                    c(-1.0, 0.0, -1.0),
                    c(0.0, 0.0, -1.0),
                    c(0.0, 0.0, 1.0),
                    c(-1.0, 0.0, 1.0),
                ],
                1,
            );
            if gap > 0.0 {
                let (x0, x1) = (gap, gap + 0.1);
                quad(
                    &mut b,
                    [
                        c(x0, 0.0, -1.0),
                        c(x1, 0.0, -1.0),
                        c(x1, 0.0, 1.0),
                        c(x0, 0.0, 1.0),
                    ],
                    2,
                );
            }
            let g = b.build();
            let (per_object, _) = listed(&g, reach, Listing::PotentialWalls);
            assert_eq!(per_object[0], if kept { 2 } else { 0 }, "gap {gap}");
            assert_eq!(per_object[1] + per_object[2], 0, "gap {gap}");
        }
    }

    /// A closed room [-1, 1] × [0, 1] × [-1, 1] (object 0) with a divider at x = 0.3 from the
    /// wall z = -1 to z = 0.2 (object 1), a 0.2 m cube on the floor (object 2) and a ball of
    /// radius 0.15 resting on the floor (object 3).
    fn furnished() -> Geometry {
        let c = Vec3::new;
        let mut b = GeometryBuilder::default();
        cuboid(&mut b, c(-1.0, 0.0, -1.0), c(1.0, 1.0, 1.0), 0, false);
        quad(
            &mut b,
            [
                c(0.3, 0.0, -1.0),
                c(0.3, 1.0, -1.0),
                c(0.3, 1.0, 0.2),
                c(0.3, 0.0, 0.2),
            ],
            1,
        );
        cuboid(&mut b, c(-0.6, 0.0, -0.6), c(-0.4, 0.2, -0.4), 2, false);
        b.spheres.push(SpherePrim {
            center: c(-0.4, 0.15, 0.5),
            radius: 0.15,
            object: 3,
        });
        b.build()
    }

    #[test]
    fn a_furnished_room_lists_its_divider_cube_and_ball_and_not_its_walls() {
        // Hand count at reach 0.375 (G ≈ 0.53 m, H ≈ 0.075 m): of the room's 12 triangles only
        // the floor's 2 have something beyond them (the ball's points 26° from its lowest lie
        // 0.15 · 0.099 = 0.015 m above the floor, and may be lifted 0.901 H = 0.068 m: below it;
        // the divider meets the walls and the floor at seams, not beyond); the divider has floor
        // on both sides; the cube's sides and top have its other faces beyond their planes,
        // its bottom (on the floor) has nothing beyond; the ball rests on the floor.
        let g = furnished();
        let (per_object, solids) = listed(&g, 0.375, Listing::PotentialWalls);
        assert_eq!(&per_object[..4], &[2, 2, 10, 0]);
        assert_eq!(solids, 1);
    }

    /// A random point on one of `g`'s surfaces (`furnished`): position, unit normal on its
    /// room side, object.
    fn surface_point(g: &Geometry, rng: &mut Rng) -> (Vec3, Vec3, u32) {
        let (u, v) = rng.next_2d();
        let (w, _) = rng.next_2d();
        let pick = (w * (g.triangles.len() + 4) as f32) as usize;
        if let Some(t) = g.triangles.get(pick) {
            let (su, sv) = if u + v > 1.0 {
                (1.0 - u, 1.0 - v)
            } else {
                (u, v)
            };
            let p = t[0] + su * (t[1] - t[0]) + sv * (t[2] - t[0]);
            let mut n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
            // Towards the room's centre, or either side for the divider and the cube.
            if n.dot(Vec3::new(0.0, 0.5, 0.0) - p) < 0.0 {
                n = -n;
            }
            (p, n, g.tri_attrs[pick].object)
        } else {
            let s = g.spheres[0];
            let z = 1.0 - 2.0 * u;
            let phi = std::f32::consts::TAU * v;
            let r = (1.0 - z * z).max(0.0).sqrt();
            let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
            (s.center + s.radius * n, n, s.object)
        }
    }

    #[test]
    fn the_potential_walls_decide_every_segment_as_every_surface_does() {
        // Reference: the lists of every opaque surface (as before this module) and, where a
        // list cannot decide, walls::separated's ray. segments between random surface
        // points of the furnished room within the radius 0.3 of each other: the same decision
        // from the lists of potential walls, which are shorter. 3 000 segments, of which ~2 %
        // cross the divider or the cube.
        let g = furnished();
        let walls = Walls::every_surface(&g);
        let radius = 0.3f32;
        let reach = estimate_reach(Vec3::splat(1.0), radius);
        let every = WallGrid::build_listing(&walls, reach, Listing::Every).expect("grid");
        let potential =
            WallGrid::build_listing(&walls, reach, Listing::PotentialWalls).expect("grid");
        assert!(potential.walls.len() < every.walls.len());
        let mut rng = Rng::new(11, 3);
        let (mut tested, mut hidden, mut tries) = (0, 0, 0);
        while tested < 3000 {
            tries += 1;
            assert!(tries < 200_000, "too few pairs");
            let (q, nq, oq) = surface_point(&g, &mut rng);
            let (p, np, _) = surface_point(&g, &mut rng);
            if q.distance(p) > radius {
                continue;
            }
            let Some((a, b)) = segment(q, nq, p, np) else {
                continue;
            };
            let r = estimate_reach(q, q.distance(p));
            let decide = |grid: &WallGrid| match grid
                .near(q, r)
                .map(|l| l.crosses(a, b, nq, np, Some(oq)))
            {
                Some(Crossing::Wall) => true,
                Some(Crossing::Clear) => false,
                Some(Crossing::Unknown) | None => {
                    separated(&Walls::every_surface(&g), q, nq, p, np)
                }
            };
            let full = decide(&every);
            assert_eq!(decide(&potential), full, "{q} {nq} -> {p} {np}");
            tested += 1;
            hidden += usize::from(full);
        }
        assert!(hidden > 25, "{hidden} of 3000 hidden");
    }
}

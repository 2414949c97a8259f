//! Which opaque surfaces can separate anything (issue 47, the cost of the wall test): a
//! candidate wall that no segment an estimate tests can cross is left out of every cell of the
//! map's grid ([`super::wall_grid::WallGrid`]). Most surfaces of a real scene are of this kind:
//! the five walls of a Cornell box, a room's outer walls, a floor under everything.
//!
//! **The segments.** An estimate of radius `r` at a query point `q` (on a surface, unit
//! geometric normal `n_q`) tests a photon at `p` (on a surface, normal `n_p`, `d = |p − q| ≤ r`)
//! by the segment `a = q + h n_q`, `b = p + h n_p` ([`super::walls::segment`]), lifted by
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
//! has its query end on another body ([`super::walls::Walls`]: never a wall to its own body's points),
//! within `G` of the crossing. A ball on a floor is kept, a ball alone in the air is not.
//! Meshes of more than [`SMALL_OBJECT`](super::wall_grid::SMALL_OBJECT) triangles are kept
//! (asking for every other object near a mesh would walk its own triangles).
//!
//! Everything here depends on the geometry and the grid's reach only: the same for any seed,
//! thread count or crop. Two BVH region queries per triangle candidate, each pruned to the
//! half-space it looks for, when a grid is built (once per photon map).

use glam::Vec3;

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

/// Whether a triangle candidate of plane `plane` within box `bounds` can separate a query point from a photon of an estimate the
/// grid of `reach` answers: `D⁺` and `D⁻` (module docs); true whenever in doubt.
#[must_use]
pub fn triangle_can_separate(
    geometry: &Geometry,
    plane: Plane,
    bounds: &Aabb,
    reach: Reach,
) -> bool {
    let zone = grown(bounds, reach.far);
    has_side(geometry, plane, &zone, reach, 1.0) && has_side(geometry, plane, &zone, reach, -1.0)
}

/// A triangle's plane: the points `x` with `ng · x = offset`.
#[derive(Debug, Clone, Copy)]
pub struct Plane {
    /// Unit normal.
    pub ng: Vec3,
    /// Offset along it (scene units).
    pub offset: f32,
}

/// Whether boxes `a` and `b` share a point.
#[inline]
fn overlaps(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
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
fn has_side(geometry: &Geometry, w: Plane, zone: &Aabb, reach: Reach, sign: f32) -> bool {
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
mod tests;

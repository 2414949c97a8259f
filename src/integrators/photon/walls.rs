//! Thin walls in photon density estimates (issue 47, thin-wall-photon-leak): a photon that the
//! estimate's normal and side tests accept is left out when a wall stands between it and the
//! query point.
//!
//! **Why the normal test is not enough.** A wall thinner than the gather disc (a single quad
//! dividing two rooms) on a floor that runs under it leaves the far room's floor photons in the
//! query's plane, with the query's normal: Jensen's tests (2001, §7.1) accept them, and a dark
//! room read up to 0.1. Testing visibility from the query point to each photon is the remedy of
//! "Photon mapping with visible kernel domains" (The Visual Computer, 2018,
//! doi:10.1007/s00371-018-1505-y); here it is made to reject a photon only where a surface
//! actually **separates** it from the query point:
//!
//! - **The segment** joins the query point `q` and the photon `p`, each lifted off its own
//!   surface along its own normal by `h = τ (1 + 1/(n_q·n_p)) + d sin α / 4` (`d = |q − p|`,
//!   `α` the angle between the normals, `τ` the positions' rounding tolerance [`tolerance`]).
//!   On a plane (`α = 0`) that is a few micrometres: the segment runs just above the shared
//!   surface, so an object resting on it (a ball touching the floor) blocks it only in the
//!   micrometre gap around the contact. On a surface of curvature radius `R` the chord sags
//!   `d²/(8R) = d sin α / 8` below it, so the `d sin α / 4` lift clears the receiver itself.
//! - **Which surface a hit belongs to.** A surface the segment crosses is a wall only when its
//!   normal is more than ~26° ([`PARALLEL_COSINE`]) from both the query's and the photon's
//!   normal (either orientation). A crossing parallel to the receiver is the receiver itself (a
//!   tessellated curve, a crease the lift did not clear) or an object lying against it (the
//!   underside of a ball at its contact, a floor under a lifted curved receiver): the segment
//!   walks on through it. A divider, a box standing on the floor, a riser between two levels
//!   stand across the receiver: the photon is rejected. Nor is a surface that lets light
//!   through (the water line on a pool's wall: the photons above it arrived through the
//!   water, and what differs across it is a blur like any shadow edge's), nor one of the query
//!   point's own body (the bumps of a lumpy mesh between two of its points; a mesh's material
//!   groups, such as a toy boat's hull and cabin, are one body) a wall
//!   ([`Walls`]).
//! - **Where a ray is traced.** Every segment of an estimate of radius `r` around photon `p`
//!   lies in the ball of radius [`reach`] around `p`, and when `q` is not below `p`'s tangent
//!   plane the whole segment lies above that plane (by at least `τ`). A wall crossing it then
//!   rises above the plane within the ball. Whether any primitive does is asked of the BVH once
//!   per *photon* when its map is built ([`near_wall`]), not per estimate: on open floors, on
//!   convex surfaces and in the open no photon is marked and an estimate costs one flag and a
//!   few products per photon, no ray. A photon beside a wall, a corner or an object on the
//!   floor, or a query point below the photon's plane by more than the curvature between them
//!   explains (a step), costs one segment test. The argument holds for each query point within
//!   distance `ρ` of the photon whatever the disc's radius (the ball's radius and the lift only
//!   depend on that distance), so a mark made for radius `ρ` clears the photon for every query
//!   point within `ρ` of it. An estimate tests its segments against the list of the potential
//!   walls of its cell of the map's grid ([`super::wall_grid`], [`super::wall_list`]), or,
//!   where that list cannot decide, by rays ([`separated`]).
//!
//! What is not resolved: a partition in the same mesh as the floor is not a wall to the floor's
//! points; a surface parallel to the receiver is never a wall, so photons on a
//! shelf's top are still read under the shelf when it is closer than the disc's radius (the
//! normal test cannot tell them apart either); a sheet meeting the floor at less than ~26° is
//! taken for an object lying on it; a gap under a wall narrower than the lift (micrometres)
//! lets photons through it.

use glam::Vec3;

use crate::geometry::offset::offset_ray_origin;
use crate::geometry::{Aabb, Ray};
use crate::render_scene::geometry::{PrimKind, PrimRef};
use crate::render_scene::{Geometry, RenderScene};

/// What can be a wall for one estimate: the scene's surfaces except those that let light
/// through (glass, water: the photons beyond them arrived through them, and what differs
/// across them is a blur like any shadow edge's) and except the query point's own body (its
/// bumps, creases and curvature are the receiver, not a wall across it).
#[derive(Debug, Clone, Copy)]
pub struct Walls<'a> {
    geometry: &'a Geometry,
    scene: Option<&'a RenderScene>,
    object: Option<u32>,
}

impl<'a> Walls<'a> {
    /// The walls of `scene` for a query point on object `object` (`None`: not on an object of
    /// the scene, such as an irradiance-cache point being built).
    #[must_use]
    pub fn of(scene: &'a RenderScene, object: Option<u32>) -> Self {
        Self {
            geometry: &scene.geometry,
            scene: Some(scene),
            object,
        }
    }

    /// Every surface of `geometry` as a wall (no materials, no own object): for maps tested
    /// on bare geometry.
    #[must_use]
    pub fn every_surface(geometry: &'a Geometry) -> Self {
        Self {
            geometry,
            scene: None,
            object: None,
        }
    }

    /// The geometry rays are traced in.
    #[must_use]
    pub fn geometry(&self) -> &'a Geometry {
        self.geometry
    }

    /// Whether a surface of object `object` can be a wall (opaque, not of the query's own
    /// body: a mesh's material groups are one surface, [`RenderScene::body_of`]).
    #[inline]
    fn can_block(&self, object: u32) -> bool {
        let own = match (self.object, self.scene) {
            (Some(q), Some(s)) => s.body_of(q) == s.body_of(object),
            (Some(q), None) => q == object,
            (None, _) => false,
        };
        !own && self.can_block_any(object)
    }

    /// [`Walls::can_block_any`] for the wall grid ([`super::wall_grid::WallGrid`]).
    #[inline]
    pub(super) fn can_block_any_object(&self, object: u32) -> bool {
        self.can_block_any(object)
    }

    /// The body object `object` belongs to ([`RenderScene::body_of`]; the object itself
    /// without a scene): what [`Walls::can_block`] compares with the query's.
    #[inline]
    pub(super) fn body_of(&self, object: u32) -> u32 {
        self.scene.map_or(object, |s| s.body_of(object))
    }

    /// The query point's body (`None`: not on an object of the scene).
    #[inline]
    pub(super) fn own_body(&self) -> Option<u32> {
        self.object.map(|q| self.body_of(q))
    }

    /// Whether a surface of object `object` can be a wall to some query point (opaque).
    #[inline]
    fn can_block_any(&self, object: u32) -> bool {
        self.scene
            .is_none_or(|s| s.objects.get(object as usize).is_none() || s.is_opaque(object))
    }
}

/// Relative size, in units of the larger coordinate's magnitude (plus 1), of the rounding
/// tolerance of positions on a surface ([`tolerance`]).
const REL_TOLERANCE: f32 = 64.0 * f32::EPSILON;

/// A surface crossed by the segment whose unit normal has a cosine above this with the
/// query's or the photon's normal (either orientation: within ~26°) is not a wall (see the
/// module docs); the irradiance cache's "same surface" cosine.
pub const PARALLEL_COSINE: f32 = 0.9;

/// A query point's surface whose unit normal has a cosine at most this with a photon's normal
/// (either orientation) never reads it (the estimate's normal test takes `n_p·n_q > 0.1`; a
/// little below, for the rounding of normals).
const QUERY_COSINE: f32 = 0.099;

/// Most crossings of parallel surfaces a segment walks through before it is taken as
/// unblocked (the receiver's own facets and objects lying on it: a few).
const MAX_CROSSINGS: usize = 8;

/// The rounding tolerance of positions near `p` (scene units): `64 ε (1 + max |pᵢ|)`, about 8 µm
/// at 1 m from the origin. Primitives within it of a photon's plane lie in it.
#[inline]
#[must_use]
pub fn tolerance(p: Vec3) -> f32 {
    REL_TOLERANCE * (1.0 + p.abs().max_element())
}

/// A lower bound of [`tolerance`] at every point within distance `r` of `q` (the bound of a
/// point whose largest coordinate is `r` smaller, less a part in 10⁴ for its own rounding): one
/// product per estimate instead of one per photon.
#[inline]
#[must_use]
pub fn tolerance_floor(q: Vec3, r: f32) -> f32 {
    0.9999 * REL_TOLERANCE * (1.0 + (q.abs().max_element() - r).max(0.0))
}

/// Radius of the ball around a photon at `p` holding every segment of an estimate of radius up
/// to `radius` (each end is lifted by at most `11 τ + radius / 4`).
#[inline]
#[must_use]
pub fn reach(p: Vec3, radius: f32) -> f32 {
    1.25 * radius + 12.0 * tolerance(p)
}

/// True when some primitive that can be a wall ([`Walls`]: opaque; every object counts, the
/// query's being unknown here) lies within [`reach`]`(p, radius)` of `p`, rises more than
/// [`tolerance`] above the plane through `p` of unit normal `n`, and is not parallel to that
/// plane (a crossing whose normal is within ~26° of the photon's is never a wall,
/// [`separated`]); conservatively for ellipsoids, discs and cylinders (by their boxes). The
/// photon map's per-photon mark: a photon without it cannot be hidden by a wall from a query
/// point on or above its plane (module docs).
#[must_use]
pub fn near_wall(walls: &Walls<'_>, p: Vec3, n: Vec3, radius: f32) -> bool {
    let geometry = walls.geometry;
    let tol = tolerance(p);
    let reach = reach(p, radius);
    let reach2 = reach * reach;
    let meets = |b: &Aabb| distance2(b, p) <= reach2 && height(b, p, n) > tol;
    geometry.bvh.any_leaf_in(meets, |first, count| {
        (first..first + count).any(|slot| match geometry.slots.get(slot as usize) {
            Some(&prim) => {
                walls.can_block_any(geometry.object_of(prim))
                    && rises(geometry, prim, p, n, tol, reach, &meets)
                    && geometry.triangles.get(prim.index()).is_none_or(|t| {
                        prim.kind() != PrimKind::Triangle
                            || has_far_side(geometry, p, n, t, tol, reach, radius)
                    })
            }
            None => true,
        })
    })
}

/// Whether a triangle `w` standing near the photon at `p` (unit normal `n`) can separate it from
/// some query point of an estimate of radius up to `radius`: a segment crosses `w` only if its
/// two (lifted) ends lie on opposite sides of `w`'s plane, so some surface within `reach` of
/// `p` that could hold such a query point must reach beyond that plane from `p`'s side. The
/// walls of a closed room are thereby no walls to the photons inside it (the floor, the other
/// walls all lie on the room's side of each), while a divider with floor on both sides is.
/// A query surface must face the photon (`|n_Q·n| > 0.1`, the estimate's normal test,
/// [`landing_cosine`](super::estimate)); each end's lift (at most `h = 12 τ + radius/4`) moves
/// it across the plane by at most `h |n·n_w|`. True (a wall) whenever in doubt: `p` within that
/// of the plane, or a primitive other than a triangle reaching beyond it by its box.
fn has_far_side(
    geometry: &Geometry,
    p: Vec3,
    n: Vec3,
    w: &[Vec3; 3],
    tol: f32,
    reach: f32,
    radius: f32,
) -> bool {
    let nw = (w[1] - w[0]).cross(w[2] - w[0]).normalize_or_zero();
    if nw == Vec3::ZERO {
        return true;
    }
    let h = 12.0 * tol + 0.25 * radius;
    let side = (p - w[0]).dot(nw);
    if side.abs() <= tol + h * n.dot(nw).abs() {
        return true;
    }
    // Signed distance beyond the plane, seen from p's side (positive: beyond).
    let nw = if side > 0.0 { -nw } else { nw };
    let beyond = |v: Vec3| (v - w[0]).dot(nw);
    let reach2 = reach * reach;
    // A box reaches beyond when its farthest corner does (by more than τ, less any lift).
    let meets = |b: &Aabb| {
        distance2(b, p) <= reach2
            && ((b.min - w[0]) * nw).max((b.max - w[0]) * nw).element_sum() > tol - h
    };
    geometry.bvh.any_leaf_in(meets, |first, count| {
        (first..first + count).any(|slot| {
            let Some(&prim) = geometry.slots.get(slot as usize) else {
                return true;
            };
            match prim.kind() {
                PrimKind::Triangle => geometry.triangles.get(prim.index()).is_none_or(|t| {
                    let nq = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
                    let faces = nq.dot(n).abs() > QUERY_COSINE;
                    let lift = h * nq.dot(nw).abs();
                    faces
                        && t.iter().any(|&v| beyond(v) > tol - lift)
                        && meets(&Aabb::from_points(t))
                }),
                // Their leaf's box met the test: conservatively beyond.
                PrimKind::Sphere | PrimKind::Ellipsoid | PrimKind::Quadric => true,
            }
        })
    })
}

/// Whether primitive `prim` can stand across the plane through `p` (unit normal `n`) within
/// `reach` of `p`: it rises more than `tol` above the plane, inside the ball `meets` tests,
/// with a part whose normal is more than ~26° from `±n` ([`PARALLEL_COSINE`], with a margin
/// for the rounding of the hit's normal).
fn rises(
    geometry: &Geometry,
    prim: PrimRef,
    p: Vec3,
    n: Vec3,
    tol: f32,
    reach: f32,
    meets: &impl Fn(&Aabb) -> bool,
) -> bool {
    let across = PARALLEL_COSINE + 1e-3;
    match prim.kind() {
        PrimKind::Triangle => geometry.triangles.get(prim.index()).is_none_or(|t| {
            let normal = (t[1] - t[0]).cross(t[2] - t[0]).normalize_or_zero();
            normal.dot(n).abs() <= across
                && t.iter().any(|&v| (v - p).dot(n) > tol)
                && meets(&Aabb::from_points(t))
        }),
        // The sphere's points whose normal u has |u·n| ≤ 0.9 lie at heights c + r u·n above
        // the plane, the highest at c + 0.9 r; a sphere is within reach when its surface is.
        PrimKind::Sphere => geometry.spheres.get(prim.index()).is_none_or(|s| {
            (s.center - p).dot(n) + across * s.radius > tol
                && s.center.distance(p) - s.radius <= reach
        }),
        // Alone in their leaves: the leaf's box is theirs, and it met the ball above the plane.
        PrimKind::Ellipsoid | PrimKind::Quadric => true,
    }
}

/// True when a ray is needed to know whether a wall separates a photon at `p` (unit normal
/// `np` on the side it arrived from, marked `near_wall` by [`near_wall`]) from the query point
/// `q` (unit normal `nq` on the side of `ωo`): the photon is marked, or `q` lies below the
/// photon's plane by more than the curvature between them explains (a step down).
#[inline]
#[must_use]
pub fn needs_ray(q: Vec3, nq: Vec3, p: Vec3, np: Vec3, near_wall: bool) -> bool {
    if near_wall {
        return true;
    }
    let below = (p - q).dot(np);
    below > tolerance(p) && below > tolerance(p) + q.distance(p) * nq.cross(np).length()
}

/// True when a wall separates the query point `q` (unit geometric normal `nq` on the side of
/// `ωo`) from the photon at `p` (unit geometric normal `np` on the side it arrived from): the
/// lifted segment between them crosses an opaque surface of another object than the query's,
/// standing across the receiver (module docs). Traces one closest-hit ray per surface crossed,
/// at most `MAX_CROSSINGS` + 1; in geometry of triangles only, one any-hit ray that counts
/// only the triangles that are walls (the same answer, but where more than `MAX_CROSSINGS`
/// parallel crossings come before the wall).
#[must_use]
pub fn separated(walls: &Walls<'_>, q: Vec3, nq: Vec3, p: Vec3, np: Vec3) -> bool {
    let geometry = walls.geometry;
    let Some((a, b)) = segment(q, nq, p, np) else {
        return false;
    };
    if geometry.spheres.is_empty() && geometry.ellipsoids.is_empty() && geometry.quadrics.is_empty()
    {
        // Triangles only: a triangle's normal is the same all over it, so whether a crossing
        // is a wall is known from the primitive: one any-hit query, no walk.
        let ray = Ray {
            origin: a,
            dir: b - a,
            t_max: 1.0,
        };
        return geometry.occluded_by(&ray, |prim| {
            prim.kind() == PrimKind::Triangle
                && geometry.triangles.get(prim.index()).is_some_and(|t| {
                    let ng = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
                    ng.dot(nq).abs() <= PARALLEL_COSINE && ng.dot(np).abs() <= PARALLEL_COSINE
                })
                && walls.can_block(geometry.object_of(prim))
        });
    }
    let mut origin = a;
    for _ in 0..=MAX_CROSSINGS {
        let ray = Ray {
            origin,
            dir: b - origin,
            t_max: 1.0,
        };
        let Some(hit) = geometry.intersect(&ray) else {
            return false;
        };
        let sp = geometry.surface(&ray, &hit);
        if sp.ng.dot(nq).abs() <= PARALLEL_COSINE
            && sp.ng.dot(np).abs() <= PARALLEL_COSINE
            && walls.can_block(sp.object)
        {
            return true;
        }
        origin = offset_ray_origin(sp.p, sp.p_error, sp.ng, b - sp.p);
    }
    false
}

/// The lifted segment [`separated`] tests between the query point `q` (unit normal `nq`) and
/// the photon at `p` (unit normal `np`): its ends `(a, b)`, each lifted off its own surface
/// along its own normal by `τ (1 + 1/max(n_q·n_p, 0.1)) + d sin α / 4` (module docs); `None`
/// when the two points are within the rounding tolerance of each other (nothing separates
/// them).
#[inline]
#[must_use]
pub fn segment(q: Vec3, nq: Vec3, p: Vec3, np: Vec3) -> Option<(Vec3, Vec3)> {
    let tol = tolerance(p).max(tolerance(q));
    let d = q.distance(p);
    if !(d > tol) {
        return None;
    }
    let lift = tol * (1.0 + 1.0 / nq.dot(np).max(0.1)) + 0.25 * d * nq.cross(np).length();
    Some((q + lift * nq, p + lift * np))
}

/// Squared distance from `p` to box `b` (0 inside).
#[inline]
fn distance2(b: &Aabb, p: Vec3) -> f32 {
    (b.min - p).max(p - b.max).max(Vec3::ZERO).length_squared()
}

/// Greatest height of box `b` above the plane through `p` of unit normal `n`.
#[inline]
fn height(b: &Aabb, p: Vec3, n: Vec3) -> f32 {
    ((b.min - p) * n).max((b.max - p) * n).element_sum()
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use super::*;
    use crate::render_scene::geometry::{GeometryBuilder, SpherePrim, TriAttrs};

    /// Adds quad `c` (corners in order) as two triangles of object 0.
    fn quad(b: &mut GeometryBuilder, c: [Vec3; 4]) {
        for t in [[c[0], c[1], c[2]], [c[0], c[2], c[3]]] {
            b.triangles.push(t);
            b.tri_attrs.push(TriAttrs {
                object: 0,
                normals: None,
                uvs: [Vec2::ZERO; 3],
            });
        }
    }

    /// The reported two rooms' floor (y = 0, x ∈ [-2, 2], z ∈ [-1, 1]) and, with `divider`,
    /// the single quad at x = 0 (y ∈ [-0.2, 2.2], z ∈ [-1.2, 1.2]) that splits it.
    fn rooms(divider: bool) -> GeometryBuilder {
        let mut b = GeometryBuilder::default();
        quad(
            &mut b,
            [
                Vec3::new(-2.0, 0.0, -1.0),
                Vec3::new(-2.0, 0.0, 1.0),
                Vec3::new(2.0, 0.0, 1.0),
                Vec3::new(2.0, 0.0, -1.0),
            ],
        );
        if divider {
            quad(
                &mut b,
                [
                    Vec3::new(0.0, -0.2, -1.2),
                    Vec3::new(0.0, 2.2, -1.2),
                    Vec3::new(0.0, 2.2, 1.2),
                    Vec3::new(0.0, -0.2, 1.2),
                ],
            );
        }
        b
    }

    /// Whether an estimate at `q` (normal `nq`) leaves out the photon at `p` (normal `np`):
    /// the estimate's own two steps, the mark (radius 5 cm) and the ray.
    fn hides(g: &Geometry, q: Vec3, nq: Vec3, p: Vec3, np: Vec3) -> bool {
        needs_ray(
            q,
            nq,
            p,
            np,
            near_wall(&Walls::every_surface(g), p, np, 0.05),
        ) && separated(&Walls::every_surface(g), q, nq, p, np)
    }

    #[test]
    fn a_single_quad_wall_hides_the_floor_beyond_it_however_close_the_query() {
        // Hand geometry: a dark-side floor point 1 mm to 10 nm from the divider; lit-side floor
        // photons 0.6 mm to 3 cm beyond it are hidden, those on its own side are not.
        let g = rooms(true).build();
        for gap in [1e-3f32, 1e-4, 1e-5, 1e-6, 1e-8] {
            let q = Vec3::new(-gap, 0.0, 0.9485);
            for dx in [6e-4f32, 0.01, 0.02, 0.03] {
                let beyond = Vec3::new(dx, 0.0, 0.95);
                assert!(hides(&g, q, Vec3::Y, beyond, Vec3::Y), "gap {gap}, {dx}");
                let before = Vec3::new(-gap - dx, 0.0, 0.95);
                assert!(
                    !hides(&g, q, Vec3::Y, before, Vec3::Y),
                    "gap {gap}, own {dx}"
                );
            }
        }
    }

    #[test]
    fn an_open_floor_marks_no_photon_and_costs_no_ray() {
        let g = rooms(false).build();
        for x in [-0.04f32, -0.01, 0.0, 0.01, 0.04] {
            let p = Vec3::new(x, 0.0, 0.5);
            assert!(
                !near_wall(&Walls::every_surface(&g), p, Vec3::Y, 0.05),
                "{x}"
            );
            assert!(!needs_ray(
                Vec3::new(0.0, 0.0, 0.49),
                Vec3::Y,
                p,
                Vec3::Y,
                false
            ));
        }
        // Beside the divider, photons are marked.
        let g = rooms(true).build();
        assert!(near_wall(
            &Walls::every_surface(&g),
            Vec3::new(0.03, 0.0, 0.5),
            Vec3::Y,
            0.05
        ));
        assert!(!near_wall(
            &Walls::every_surface(&g),
            Vec3::new(0.1, 0.0, 0.5),
            Vec3::Y,
            0.05
        ));
    }

    #[test]
    fn the_walls_of_a_closed_room_mark_no_floor_photon_a_divider_does() {
        // The rooms' floor with the box's four walls standing on its edges: photons 1 mm to
        // 3 cm from a wall or in a corner are not marked (nothing lies beyond a wall of the
        // room); with the divider, photons beside it are (the floor runs on beyond it).
        let walls = |b: &mut GeometryBuilder| {
            let c = Vec3::new;
            for w in [
                [
                    c(-2.0, 0.0, -1.0),
                    c(2.0, 0.0, -1.0),
                    c(2.0, 2.0, -1.0),
                    c(-2.0, 2.0, -1.0),
                ],
                [
                    c(-2.0, 0.0, 1.0),
                    c(2.0, 0.0, 1.0),
                    c(2.0, 2.0, 1.0),
                    c(-2.0, 2.0, 1.0),
                ],
                [
                    c(-2.0, 0.0, -1.0),
                    c(-2.0, 0.0, 1.0),
                    c(-2.0, 2.0, 1.0),
                    c(-2.0, 2.0, -1.0),
                ],
                [
                    c(2.0, 0.0, -1.0),
                    c(2.0, 0.0, 1.0),
                    c(2.0, 2.0, 1.0),
                    c(2.0, 2.0, -1.0),
                ],
            ] {
                quad(b, w);
            }
        };
        let mut room = rooms(false);
        walls(&mut room);
        let room = room.build();
        let mut divided = rooms(true);
        walls(&mut divided);
        let divided = divided.build();
        for gap in [1e-3f32, 0.01, 0.03] {
            for p in [
                Vec3::new(0.5, 0.0, -1.0 + gap),
                Vec3::new(-2.0 + gap, 0.0, 0.3),
                Vec3::new(2.0 - gap, 0.0, 1.0 - gap),
            ] {
                assert!(
                    !near_wall(&Walls::every_surface(&room), p, Vec3::Y, 0.05),
                    "{p}"
                );
            }
            let beside = Vec3::new(gap, 0.0, 0.3);
            assert!(near_wall(
                &Walls::every_surface(&divided),
                beside,
                Vec3::Y,
                0.05
            ));
            // A photon on a wall near the floor: the floor is no wall to it either.
            let on_wall = Vec3::new(0.5, gap, -1.0);
            assert!(!near_wall(
                &Walls::every_surface(&room),
                on_wall,
                Vec3::Z,
                0.05
            ));
        }
    }

    /// A ball of radius `r` resting on the rooms' floor (without divider) at the origin.
    fn ball_on_floor(r: f32) -> Geometry {
        let mut b = rooms(false);
        b.spheres.push(SpherePrim {
            center: Vec3::new(0.0, r, 0.0),
            radius: r,
            object: 1,
        });
        b.build()
    }

    #[test]
    fn a_ball_resting_on_the_floor_hides_no_floor_photon_and_none_of_its_own() {
        // Query points on the floor 1 mm to 4 cm from the contact, photons on a ring of floor
        // points around each (1 mm to 5 cm away), many of whose segments pass under the ball
        // within micrometres of the contact; and points on the ball near its bottom and its
        // side with photons on the ball. Nothing separates any of them: the ball is not a wall
        // between two floor points, and a curved receiver is not a wall to itself.
        for r in [0.02f32, 0.5] {
            let g = ball_on_floor(r);
            let mut tested = 0;
            for s in [1e-3f32, 0.01, 0.04] {
                let q = Vec3::new(-s, 0.0, 0.0);
                for i in 0..24 {
                    let a = i as f32 * std::f32::consts::TAU / 24.0;
                    for d in [1e-3f32, 0.01, 0.03, 0.05] {
                        let p = q + d * Vec3::new(a.cos(), 0.0, a.sin());
                        if p.length() < 1e-4 {
                            continue;
                        }
                        tested += usize::from(needs_ray(q, Vec3::Y, p, Vec3::Y, true));
                        assert!(
                            !separated(&Walls::every_surface(&g), q, Vec3::Y, p, Vec3::Y),
                            "r {r}: {q} {p}"
                        );
                    }
                }
            }
            assert!(tested > 200);
            let on_ball = |theta: f32, phi: f32| {
                let n = Vec3::new(
                    theta.sin() * phi.cos(),
                    -theta.cos(),
                    theta.sin() * phi.sin(),
                );
                (Vec3::new(0.0, r, 0.0) + r * n, n)
            };
            for theta in [0.3f32, 0.8, 1.6, 2.6] {
                let (q, nq) = on_ball(theta, 0.0);
                for dt in [-0.2f32, -0.05, 0.05, 0.2] {
                    for phi in [-0.3f32, 0.0, 0.3] {
                        let (p, np) = on_ball(theta + dt, phi);
                        if np.dot(nq) <= 0.1 {
                            continue;
                        }
                        assert!(
                            !separated(&Walls::every_surface(&g), q, nq, p, np),
                            "r {r}: θ {theta} {dt} {phi}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_box_standing_on_the_floor_separates_the_floor_on_its_two_sides() {
        // A 2 cm cube standing on the floor at x ∈ [0, 0.02]: floor photons beyond it are
        // hidden from a point before it, photons beside it are not (a concave corner).
        let mut b = rooms(false);
        let (lo, hi) = (Vec3::new(0.0, 0.0, -0.01), Vec3::new(0.02, 0.02, 0.01));
        let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
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
            quad(&mut b, f);
        }
        let g = b.build();
        let q = Vec3::new(-0.005, 0.0, 0.0);
        assert!(hides(&g, q, Vec3::Y, Vec3::new(0.03, 0.0, 0.0), Vec3::Y));
        assert!(!hides(&g, q, Vec3::Y, Vec3::new(-0.03, 0.0, 0.0), Vec3::Y));
        // Beside its side face z = 0.01, 5 mm from it: the floor along the face is seen.
        let side = Vec3::new(0.005, 0.0, 0.015);
        assert!(!hides(
            &g,
            side,
            Vec3::Y,
            Vec3::new(0.015, 0.0, 0.03),
            Vec3::Y
        ));
        assert!(!hides(
            &g,
            side,
            Vec3::Y,
            Vec3::new(0.02, 0.0, 0.011),
            Vec3::Y
        ));
        // On the cube's top, its own photons are visible; the floor is far below its plane.
        let top = Vec3::new(0.01, 0.02, 0.0);
        assert!(!hides(
            &g,
            top,
            Vec3::Y,
            Vec3::new(0.015, 0.02, 0.005),
            Vec3::Y
        ));
        // A query on the floor below the top's plane by more than curvature explains: a ray.
        assert!(needs_ray(
            q,
            Vec3::Y,
            Vec3::new(0.005, 0.02, 0.0),
            Vec3::Y,
            false
        ));
    }
}

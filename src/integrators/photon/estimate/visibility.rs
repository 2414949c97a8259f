//! The visibility test of a density estimate: whether a photon the normal and side tests
//! accepted can be seen from the query point, so that a photon on the far side of a wall thinner
//! than the search disc (a single quad, or any wall under the disc's radius) is not counted at a
//! point the wall hides it from. Point-to-point visibility between the estimate point and each
//! photon is the occlusion test of "Photon mapping with visible kernel domains" (The Visual
//! Computer, 2018, doi:10.1007/s00371-018-1505-y); Jensen's normal test (2001, §7.1) cannot see a
//! wall of zero thickness on a floor that runs under it: the photons beyond it lie in the
//! query's plane with its normal.
//!
//! **The segment** joins the two points each lifted off its own surface along its own geometric
//! normal (the query's on the side of `ωo`, the photon's on the side it arrived from) by
//! [`LIFT`] times their distance `d`: a segment between the bare points would run inside the
//! surface they share, and on a convex surface of curvature radius `R` the chord between two
//! points lifted by `h` stays outside it while `h > d²/(8R)`, so a lift of `d/4` keeps every
//! photon of a surface curved no tighter than `R = d/2` (a disc of radius 5 cm: balls of radius
//! 2.5 cm and up). A wall blocks while it reaches more than `d/4` above the surface; a gap
//! narrower than that (a slot under an overhang) can hide photons within it from each other,
//! which darkens the estimate there as any rejected photon does.
//!
//! **Only where a surface can block** is a ray traced. Every lifted segment of an estimate of
//! radius `r` lies in the ball of radius `(1 + LIFT) r` around the query point, and one that
//! stays above the query's tangent plane can only be blocked by a surface that rises above that
//! plane within the ball. [`Visibility`] asks the BVH once per estimate (the first time a
//! photon needs it) whether any primitive does (nodes and triangles entirely on or under the
//! plane are skipped): on a flat floor away from walls,
//! on convex surfaces and in the open there is none, no ray is traced, and the estimate is
//! exactly what it was without the test. Near a wall, a corner or a box on the floor, and for a
//! photon whose lifted end dips under the plane (a surface curved tighter than `R = 2d`, a step
//! down), each accepted photon costs a shadow ray; so does every estimate on a concave curved
//! surface (the inside of a sphere rises above its tangent planes). The test is exact in both cases: it never
//! accepts a photon a surface hides, whatever the photons on that surface.

use glam::Vec3;

use crate::geometry::{Aabb, Ray};
use crate::render_scene::geometry::PrimKind;
use crate::render_scene::{Geometry, PrimRef};

/// The lift of each end of the visibility segment off its surface, as a fraction of the
/// distance between query and photon (see the module docs).
pub const LIFT: f32 = 0.25;

/// Relative size, in units of the larger coordinate's magnitude (plus 1), of the distance under
/// which a photon counts as at the query point (f32 rounding of positions on a surface).
const REL_EPSILON: f32 = 64.0 * f32::EPSILON;

/// Height above the query's tangent plane, as a fraction of the ball's radius, up to which a
/// primitive counts as lying in or under the plane (f32 rounding of coplanar vertices).
const PLANE_TOLERANCE: f32 = 1e-3;

/// Most BVH entries the ball query keeps waiting; a tree that needs more is taken as having a
/// rising surface in the ball (rays are traced: slower, never wrong).
const STACK: usize = 128;

/// The visibility test of one estimate at query point `q` (unit geometric normal `nq` on the
/// side of `ωo`) over photons within `radius`: whether a surface hides a photon from `q`,
/// tracing rays only where one can (see the module docs). Counts the rays it traced and the
/// photons it hid.
#[derive(Debug)]
pub struct Visibility<'a> {
    geometry: &'a Geometry,
    q: Vec3,
    nq: Vec3,
    /// Radius of the ball holding every lifted segment.
    reach: f32,
    /// Heights above the plane up to which a primitive counts as in or under it.
    tolerance: f32,
    /// Distance under which a photon is at `q`.
    epsilon: f32,
    /// Whether a primitive rises above the plane within the ball (asked once, when needed).
    rising: Option<bool>,
    /// Photons tested by rays (two rays each, [`visible`]).
    pub rays: u32,
    /// Photons hidden.
    pub hidden: u32,
}

impl<'a> Visibility<'a> {
    /// The test at `q` (unit normal `nq`) for photons within `radius` of it.
    #[must_use]
    pub fn new(geometry: &'a Geometry, q: Vec3, nq: Vec3, radius: f32) -> Self {
        let reach = (1.0 + LIFT) * radius;
        let epsilon = REL_EPSILON * (1.0 + q.abs().max_element());
        Self {
            geometry,
            q,
            nq,
            reach,
            tolerance: PLANE_TOLERANCE * reach + epsilon,
            epsilon,
            rising: None,
            rays: 0,
            hidden: 0,
        }
    }

    /// True when some surface of the scene blocks the lifted segment from the query point to a
    /// photon at `p` (unit geometric normal `np` on the side it arrived from, facing the
    /// query's side).
    #[inline]
    pub fn hides(&mut self, p: Vec3, np: Vec3) -> bool {
        let d = self.q.distance(p);
        if !(d > self.epsilon) {
            return false;
        }
        let h = LIFT * d;
        let above =
            h > self.tolerance && (p - self.q).dot(self.nq) + h * np.dot(self.nq) > self.tolerance;
        if above && !self.rising() {
            return false;
        }
        self.rays += 1;
        let hidden = !visible(self.geometry, self.q, self.nq, p, np);
        self.hidden += u32::from(hidden);
        hidden
    }

    /// Records that no primitive rises above the plane within the ball (known beforehand, as
    /// the irradiance cache knows it of its points): no BVH query is made.
    pub fn assume_flat(&mut self) {
        self.rising = Some(false);
    }

    /// True when a primitive rises above the query's tangent plane within the ball (asked of
    /// the BVH the first time).
    #[inline]
    pub fn rising(&mut self) -> bool {
        *self.rising.get_or_insert_with(|| {
            rising_surface(self.geometry, self.q, self.nq, self.reach, self.tolerance)
        })
    }
}

/// True when nothing in `geometry` blocks the segment between query point `q` (unit geometric
/// normal `nq` on the side of `ωo`) and photon position `p` (unit geometric normal `np` on the
/// side it arrived from), each end lifted off its surface by [`LIFT`] times their distance.
///
/// The segment is traced both ways, with a unit direction: a triangle intersection
/// conservatively rejects hits within its floating-point error bound of the ray's origin
/// (pbrt's watertight test, §6.8.7), a distance that grows with the triangle's size and with
/// the inverse of the direction's length (a 2.4 m wall, a 2.4 mm segment as its direction: about
/// 0.3 mm). With a unit direction it is micrometres; a query point that close to a thin wall
/// would see through it one way, and the other way sees the wall near its far end.
#[inline]
#[must_use]
pub fn visible(geometry: &Geometry, q: Vec3, nq: Vec3, p: Vec3, np: Vec3) -> bool {
    let h = LIFT * q.distance(p);
    let (a, b) = (q + h * nq, p + h * np);
    let length = a.distance(b);
    if !(length > 0.0) {
        return true;
    }
    let segment = |from: Vec3, to: Vec3| Ray {
        origin: from,
        dir: (to - from) / length,
        t_max: length,
    };
    !geometry.occluded(&segment(a, b)) && !geometry.occluded(&segment(b, a))
}

/// True when some primitive of `geometry` within `reach` of `q` rises more than `tolerance`
/// above the plane through `q` of unit normal `n` (conservatively: by its box for ellipsoids,
/// discs and cylinders, and by its vertices' box for triangles). A sphere `q` lies on (looking
/// out) does not count: it lies under the plane.
#[must_use]
pub fn rising_surface(geometry: &Geometry, q: Vec3, n: Vec3, reach: f32, tolerance: f32) -> bool {
    let bvh = &geometry.bvh;
    if bvh.nodes.is_empty() {
        return false;
    }
    let reach2 = reach * reach;
    let meets = |b: &Aabb| distance2(b, q) <= reach2 && height(b, q, n) > tolerance;
    let mut stack = [(0u32, 0u32); STACK];
    let mut sp = 0;
    let (mut index, mut count) = (0u32, 0u32);
    loop {
        if count == 0 {
            let node = &bvh.nodes[index as usize];
            for c in 0..node.index.len() {
                if !node.has_child(c) || !meets(&node.child_bounds(c)) {
                    continue;
                }
                if sp == STACK {
                    return true;
                }
                stack[sp] = (node.index[c], node.count[c]);
                sp += 1;
            }
        } else {
            for slot in index..index + count {
                let Some(&prim) = geometry.slots.get(slot as usize) else {
                    return true;
                };
                if rises(geometry, prim, q, n, tolerance, &meets) {
                    return true;
                }
            }
        }
        if sp == 0 {
            return false;
        }
        sp -= 1;
        (index, count) = stack[sp];
    }
}

/// Whether primitive `prim`, in a leaf whose box `meets` the ball above the plane, itself rises
/// more than `tolerance` above the plane through `q` (normal `n`) within the ball.
fn rises(
    geometry: &Geometry,
    prim: PrimRef,
    q: Vec3,
    n: Vec3,
    tolerance: f32,
    meets: &impl Fn(&Aabb) -> bool,
) -> bool {
    match prim.kind() {
        PrimKind::Triangle => geometry
            .triangles
            .get(prim.index())
            .is_none_or(|t| meets(&Aabb::from_points(t))),
        PrimKind::Sphere => geometry.spheres.get(prim.index()).is_none_or(|s| {
            let b = Aabb {
                min: s.center - Vec3::splat(s.radius),
                max: s.center + Vec3::splat(s.radius),
            };
            meets(&b) && (s.center - q).dot(n) + s.radius > tolerance
        }),
        // Alone in their leaves: the leaf's box is theirs, and it met the ball.
        PrimKind::Ellipsoid | PrimKind::Quadric => true,
    }
}

/// Squared distance from `p` to box `b` (0 inside).
#[inline]
fn distance2(b: &Aabb, p: Vec3) -> f32 {
    let d = (b.min - p).max(p - b.max).max(Vec3::ZERO);
    d.length_squared()
}

/// Greatest height of box `b` above the plane through `q` of unit normal `n`.
#[inline]
fn height(b: &Aabb, q: Vec3, n: Vec3) -> f32 {
    ((b.min - q) * n).max((b.max - q) * n).element_sum()
}

#[cfg(test)]
mod tests {
    use glam::Vec2;

    use super::*;
    use crate::render_scene::geometry::{GeometryBuilder, SpherePrim, TriAttrs};

    /// The reported two rooms' floor (y = 0, x ∈ [-2, 2], z ∈ [-1, 1]) and, with `divider`, the
    /// single quad at x = 0 (y ∈ [-0.2, 2.2], z ∈ [-1.2, 1.2]) that splits it.
    fn rooms(divider: bool) -> Geometry {
        let mut b = GeometryBuilder::default();
        let mut quad = |c: [Vec3; 4]| {
            for t in [[c[0], c[1], c[2]], [c[0], c[2], c[3]]] {
                b.triangles.push(t);
                b.tri_attrs.push(TriAttrs {
                    object: 0,
                    normals: None,
                    uvs: [Vec2::ZERO; 3],
                });
            }
        };
        quad([
            Vec3::new(-2.0, 0.0, -1.0),
            Vec3::new(-2.0, 0.0, 1.0),
            Vec3::new(2.0, 0.0, 1.0),
            Vec3::new(2.0, 0.0, -1.0),
        ]);
        if divider {
            quad([
                Vec3::new(0.0, -0.2, -1.2),
                Vec3::new(0.0, 2.2, -1.2),
                Vec3::new(0.0, 2.2, 1.2),
                Vec3::new(0.0, -0.2, 1.2),
            ]);
        }
        b.build()
    }

    #[test]
    fn a_thin_wall_hides_the_floor_beyond_it_however_close_the_query() {
        // Hand geometry: a floor point on the dark side at 1 mm, 0.1 mm and 0.01 mm from the
        // divider; floor photons 0.6 mm to 3 cm beyond it must be hidden, those on its own
        // side not (at 1 mm / 0.6 mm a 2.4 mm ray direction lost the wall in the
        // intersection's error bound both ways).
        let g = rooms(true);
        for gap in [1e-3f32, 1e-4, 1e-5] {
            let q = Vec3::new(-gap, 0.0, 0.9485);
            let mut sight = Visibility::new(&g, q, Vec3::Y, 0.05);
            for dx in [6e-4f32, 0.01, 0.02, 0.03] {
                let beyond = Vec3::new(dx, 0.0, 0.95);
                assert!(
                    sight.hides(beyond, Vec3::Y),
                    "gap {gap}, photon at x = {dx}"
                );
                let before = Vec3::new(-gap - dx, 0.0, 0.95);
                assert!(!sight.hides(before, Vec3::Y), "gap {gap}, own side {dx}");
            }
            assert!(sight.rays > 0);
        }
    }

    #[test]
    fn an_open_floor_costs_no_ray_and_hides_nothing() {
        let g = rooms(false);
        let q = Vec3::new(-0.001, 0.0, 0.5);
        let mut sight = Visibility::new(&g, q, Vec3::Y, 0.05);
        for dx in [-0.04f32, -0.01, 0.01, 0.04] {
            assert!(!sight.hides(Vec3::new(dx, 0.0, 0.51), Vec3::Y));
        }
        assert_eq!((sight.rays, sight.hidden), (0, 0));
        // A photon under the query's plane is always tested by a ray (here the floor hides it).
        assert!(sight.hides(Vec3::new(0.02, -0.03, 0.5), Vec3::Y));
        assert_eq!(sight.rays, 1);
    }

    #[test]
    fn a_ball_keeps_its_own_photons_and_costs_no_ray_from_outside() {
        // On a sphere of radius 0.5 (convex), photons 5 cm away on its surface stay visible: the
        // lifted chord clears the surface by d/4 − d²/(8R) > 0; no primitive rises above the
        // tangent plane at the top, so no ray is traced there.
        let mut b = GeometryBuilder::default();
        b.spheres.push(SpherePrim {
            center: Vec3::ZERO,
            radius: 0.5,
            object: 0,
        });
        let g = b.build();
        let q = Vec3::new(0.0, 0.5, 0.0);
        let mut sight = Visibility::new(&g, q, Vec3::Y, 0.05);
        for a in [0.02f32, 0.05, 0.1] {
            let n = Vec3::new(a.sin(), a.cos(), 0.0);
            assert!(!sight.hides(0.5 * n, n), "angle {a}");
        }
        assert!(
            !sight.rising(),
            "the top of a ball is under its tangent plane"
        );
    }
}

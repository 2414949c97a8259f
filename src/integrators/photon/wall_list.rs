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
/// worker (no allocation per estimate once it has grown), and by the next estimate whose
/// segments' box lies in the box it was collected for, with the same query normal and body.
#[derive(Debug, Default)]
pub struct WallList {
    listed: Vec<Listed>,
    /// What the list holds: the walls' key ([`Walls::key`]), the query normal's bits and the
    /// box collected; `None` when the list is not reusable.
    covers: Option<((usize, usize, Option<u32>), [u32; 3], Aabb)>,
}

/// Each axis of a box is grown by this fraction of its length (and the rounding tolerance)
/// when a list is collected, so the next estimates nearby reuse it.
const GROWTH: f32 = 0.25;

impl WallList {
    /// Fills the list with every triangle of `walls`' geometry that meets box `bounds` (grown
    /// by the rounding tolerance), can block ([`Walls`]) and whose unit normal has a cosine of
    /// at most [`PARALLEL_COSINE`] with the query's normal `nq` (either orientation). False
    /// when the list cannot decide: more than [`MAX_LISTED`] such triangles, or a sphere,
    /// ellipsoid or quadric that can block within `bounds` (their crossings' normals depend on
    /// where they are crossed), or a tree deeper than the region query's stack.
    ///
    /// A list collected for a box holding `bounds` (grown by [`GROWTH`]) with the same query
    /// normal and body is reused: it holds every triangle the exact box would, and a few more
    /// that [`WallList::crosses`] rejects, so the decisions are the same; and when it could
    /// decide, so could the exact box's (fewer triangles, the same leaves or fewer). Whether
    /// an estimate's photons are decided by the list or by rays therefore depends on its own
    /// segments only, not on the estimates before it.
    pub fn collect(&mut self, walls: &Walls<'_>, nq: Vec3, bounds: &Aabb) -> bool {
        let key = walls.key();
        let bits = nq.to_array().map(f32::to_bits);
        if let Some((k, b, covered)) = &self.covers
            && *k == key
            && *b == bits
            && covered.min.cmple(bounds.min).all()
            && bounds.max.cmple(covered.max).all()
        {
            return true;
        }
        let tol = walls::tolerance(bounds.min.abs().max(bounds.max.abs()));
        let grow = GROWTH * bounds.extent() + Vec3::splat(tol);
        let grown = Aabb {
            min: bounds.min - grow,
            max: bounds.max + grow,
        };
        if self.fill(walls, nq, &grown) {
            self.covers = Some((key, bits, grown));
            return true;
        }
        self.covers = None;
        let decides = self.fill(walls, nq, bounds);
        if decides {
            self.covers = Some((key, bits, *bounds));
        }
        decides
    }

    /// [`WallList::collect`] without reuse: the triangles in `bounds` grown by the rounding
    /// tolerance.
    fn fill(&mut self, walls: &Walls<'_>, nq: Vec3, bounds: &Aabb) -> bool {
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
                        let ng = (p1 - p0).cross(p2 - p0).normalize();
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

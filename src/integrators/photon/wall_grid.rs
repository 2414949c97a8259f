//! The potential walls of every region of a scene, listed once per photon map (issue 47, the
//! cost of the wall test): a coarse grid whose every cell lists the opaque surfaces within the
//! reach of the map's widest estimate, so that an estimate takes its cell's list instead of a
//! BVH region query.
//!
//! **Why.** The geometry does not change between estimates: the walls near a query point are
//! the same for every estimate around it. Collecting them per estimate with a BVH region query
//! cost the bath ~340 M instructions (105 000 estimates looking at 33 triangles each, ~76
//! instructions a triangle) of its ~820 M for the wall test.
//!
//! **What a cell lists.** Every segment an estimate of radius `r` around `q` tests (the lifted
//! ends of [`walls::segment`]: `q` lifted by at most `11 τ + r/4`, a photon within `r` of `q`
//! lifted as much) lies within [`estimate_reach`]`(q, r) = 1.2501 r + 12 τ(q)` of `q`
//! ([`walls::tolerance`] grows by at most `64 ε r` between `q` and the photon, which the
//! `0.0001 r` covers while `r` is below ten times the scene's size). So a surface that crosses
//! such a segment meets the box of `q`'s cell grown by that reach. A cell of a grid built for
//! reach `R` lists every wall candidate whose bounds meet its box grown by `R` (plus the
//! rounding tolerance of the scene's coordinates): an estimate whose reach is at most `R` and
//! whose point lies in the grid finds in its cell every surface that could separate it from a
//! photon. The candidates ([`Wall`]) are the scene's opaque surfaces
//! ([`Walls`]: the surfaces of transmitting materials are no walls) that
//! can separate a query point from a photon at all ([`super::potential_walls`]: a triangle with
//! surfaces within reach on both sides of its plane; a Cornell box's walls and a room's outer
//! walls are left out):
//!
//! - the triangles of objects of at most [`SMALL_OBJECT`] triangles (quads, cubes, the bath's
//!   tub and room), each with its unit normal, plane offset and bounds, so that a segment is
//!   tested against it directly ([`CellList::crosses`]);
//! - every larger object (a mesh: the duck, the boat, the faucet) and every sphere, ellipsoid
//!   and quadric as its bounds alone: a segment whose box meets them is decided by a ray
//!   ([`walls::separated`]), as every segment was before the lists.
//!
//! A cell listing more than [`MAX_PER_CELL`] candidates lists none and says so: its estimates
//! trace a ray per tested photon. The grid's cells are at least the reach wide (cells of half
//! the reach cut the bath's segment tests by 10 %, −41 M instructions, but cost the Cornell box
//! +50 M in building eight times as many cells, each testing every candidate) and at most
//! [`MAX_CELLS_PER_AXIS`] a side, and a grid whose build would test more than [`MAX_BUILD_TESTS`]
//! cell–candidate pairs is not built (every estimate then traces rays): its cost is bounded by a
//! few milliseconds per map whatever the scene.
//!
//! A cell listing nothing ([`WallGrid::clear_at`]) lets a progressive estimate skip the
//! per-photon wall comparisons, and a photon in it needs no mark.
//!
//! The lists depend only on the geometry and the reach, so the decisions do not depend on the
//! order of estimates or the thread count.

use glam::{DVec3, Vec3};
use wide::f32x8;

use super::potential_walls::{Plane, Reach, solid_can_separate, triangle_can_separate};
use super::walls::{self, Walls};
use crate::geometry::Aabb;
use crate::render_scene::Geometry;

/// Objects of at most this many triangles are listed triangle by triangle; larger ones (meshes)
/// by their bounds, decided by a ray where a segment meets them.
pub const SMALL_OBJECT: usize = 64;

/// Most candidates a cell lists; a cell with more lists none (its estimates trace rays).
pub const MAX_PER_CELL: usize = 96;

/// Most cells along each axis of a grid (cells are widened to keep within it).
pub const MAX_CELLS_PER_AXIS: f32 = 24.0;

/// Most cell–candidate box tests a grid's build may make (~10 instructions each); a scene that
/// would need more gets no grid.
pub const MAX_BUILD_TESTS: usize = 1 << 21;

/// Which opaque surfaces a grid lists.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Listing {
    /// Only those that can separate a query point from a photon
    /// ([`super::potential_walls`]): what renders use.
    PotentialWalls,
    /// Every opaque surface (the lists before [`super::potential_walls`]; for tests).
    Every,
}

/// What a wall candidate is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum WallKind {
    /// One triangle, tested exactly.
    Triangle,
    /// A mesh of more than [`SMALL_OBJECT`] triangles, or a sphere, ellipsoid or quadric: known
    /// by its bounds; a segment whose box meets them is decided by a ray.
    Bounds,
}

/// One opaque surface that can separate a query point from a photon.
#[derive(Debug, Clone, Copy)]
pub struct Wall {
    /// Triangle or bounds only.
    pub kind: WallKind,
    /// A triangle's corners (zero for bounds).
    pub corners: [Vec3; 3],
    /// A triangle's unit normal, as a hit on it reports it (zero for bounds).
    pub ng: Vec3,
    /// A triangle's plane offset `ng · corners[0]`.
    pub offset: f32,
    /// Its bounds.
    pub bounds: Aabb,
    /// The body it belongs to ([`crate::render_scene::RenderScene::body_of`]; its object
    /// without a scene): never a wall to a query point of the same body.
    pub body: u32,
}

/// The wall candidates of every cell of a coarse grid over the scene, for estimates of reach up
/// to [`WallGrid::reach`] (module docs).
#[derive(Debug)]
pub struct WallGrid {
    /// Lowest corner of the grid (the scene's bounds' lowest corner).
    origin: Vec3,
    /// One over the cell side (1 / scene units).
    inv_side: f32,
    /// Cells along x, y, z, as numbers.
    dims_f: Vec3,
    /// The rounding tolerance in cells (`slack / side`).
    slack_cells: f32,
    /// Cells along x, y, z.
    dims: [usize; 3],
    /// The reach the lists hold for (scene units).
    reach: f32,
    /// Per cell, the range of its candidates' slots (a multiple of [`LANES`] long, the last
    /// lanes padded with empty boxes), or `None` when it has too many.
    cells: Vec<Option<(u32, u32)>>,
    /// Per [`LANES`] slots, their candidates' bounds, lowest corner then highest, one array per
    /// axis (for testing [`LANES`] boxes at once).
    pub(super) lo: [Vec<f32x8>; 3],
    /// See `lo`.
    pub(super) hi: [Vec<f32x8>; 3],
    /// Per slot, its candidate's index in `walls` (`u32::MAX` for padding).
    pub(super) slot: Vec<u32>,
    /// Every candidate.
    pub(super) walls: Vec<Wall>,
}

/// Boxes tested at once.
pub const LANES: usize = 8;

impl WallGrid {
    /// The grid of `walls`' opaque surfaces for estimates of reach up to `reach` (scene units;
    /// [`estimate_reach`] of the widest estimate). `None` when the scene has no finite bounds,
    /// `reach` is not a positive finite number, or the build would cost more than
    /// [`MAX_BUILD_TESTS`] box tests.
    #[must_use]
    pub fn build(walls: &Walls<'_>, reach: f32) -> Option<Self> {
        Self::build_listing(walls, reach, Listing::PotentialWalls)
    }

    /// [`WallGrid::build`] listing the candidates `listing` says.
    #[must_use]
    pub fn build_listing(walls: &Walls<'_>, reach: f32, listing: Listing) -> Option<Self> {
        let geometry = walls.geometry();
        let bounds = geometry.bvh.bounds;
        let extent = bounds.max - bounds.min;
        if !(reach.is_finite() && reach > 0.0 && extent.is_finite() && extent.min_element() >= 0.0)
        {
            return None;
        }
        let slack = walls::tolerance(bounds.min.abs().max(bounds.max.abs()));
        let candidates = candidates(walls, geometry, listing, Reach::new(reach, slack));
        let side = reach.max(extent.max_element() / MAX_CELLS_PER_AXIS);
        let dims = extent
            .to_array()
            .map(|e| ((e / side).ceil() as usize).clamp(1, MAX_CELLS_PER_AXIS as usize + 1));
        let count = dims[0] * dims[1] * dims[2];
        if count.saturating_mul(candidates.len()) > MAX_BUILD_TESTS {
            return None;
        }
        let grow = Vec3::splat(reach + 2.0 * slack);
        let mut cells = Vec::with_capacity(count);
        let mut slot: Vec<u32> = Vec::new();
        for z in 0..dims[2] {
            for y in 0..dims[1] {
                for x in 0..dims[0] {
                    let lo = bounds.min + side * Vec3::new(x as f32, y as f32, z as f32);
                    let cell = Aabb {
                        min: lo - grow,
                        max: lo + Vec3::splat(side) + grow,
                    };
                    let start = slot.len();
                    slot.extend(
                        (0..candidates.len() as u32)
                            .filter(|&i| overlaps(&candidates[i as usize].bounds, &cell)),
                    );
                    if slot.len() - start > MAX_PER_CELL {
                        slot.truncate(start);
                        cells.push(None);
                    } else {
                        while !(slot.len() - start).is_multiple_of(LANES) {
                            slot.push(u32::MAX);
                        }
                        cells.push(Some((start as u32, slot.len() as u32)));
                    }
                }
            }
        }
        let axis = |a: usize, hi: bool| -> Vec<f32x8> {
            slot.chunks(LANES)
                .map(|chunk| {
                    let mut lanes = [if hi { f32::NEG_INFINITY } else { f32::INFINITY }; LANES];
                    for (lane, &i) in lanes.iter_mut().zip(chunk) {
                        // Padding keeps an empty box, which meets nothing.
                        if let Some(w) = candidates.get(i as usize) {
                            *lane = if hi { w.bounds.max[a] } else { w.bounds.min[a] };
                        }
                    }
                    f32x8::from(lanes)
                })
                .collect()
        };
        Some(Self {
            origin: bounds.min,
            inv_side: 1.0 / side,
            dims_f: Vec3::new(dims[0] as f32, dims[1] as f32, dims[2] as f32),
            slack_cells: slack / side,
            dims,
            reach,
            cells,
            lo: [0, 1, 2].map(|a| axis(a, false)),
            hi: [0, 1, 2].map(|a| axis(a, true)),
            slot,
            walls: candidates,
        })
    }

    /// The reach the lists hold for (scene units).
    #[must_use]
    pub fn reach(&self) -> f32 {
        self.reach
    }

    /// The candidates of the cell holding `q` for an estimate of reach `reach`: `None` when
    /// `reach` exceeds the grid's, `q` lies outside the grid (by more than the rounding
    /// tolerance) or its cell has too many candidates; then a ray decides each segment.
    #[inline]
    #[must_use]
    pub fn near(&self, q: Vec3, reach: f32) -> Option<CellList<'_>> {
        let index = self.cell_of(q, reach)?;
        let (start, end) = (*self.cells.get(index)?)?;
        Some(CellList {
            grid: self,
            start: start as usize,
            end: end as usize,
        })
    }

    /// True when the cell holding `q` lists no candidate for an estimate of reach `reach`
    /// ([`WallGrid::near`]): every segment of such an estimate is clear. False when it lists
    /// some or has no list.
    #[inline]
    #[must_use]
    pub fn clear_at(&self, q: Vec3, reach: f32) -> bool {
        self.near(q, reach).is_some_and(|c| c.start == c.end)
    }

    /// The index of the cell holding `q` for an estimate of reach `reach`, or `None` (module
    /// docs).
    #[inline]
    fn cell_of(&self, q: Vec3, reach: f32) -> Option<usize> {
        if !(reach <= self.reach) {
            return None;
        }
        // Either cell a point within rounding of a boundary falls in lists every surface
        // within the reach of it (cells are grown by twice the rounding tolerance).
        let rel = (q - self.origin) * self.inv_side;
        let s = self.slack_cells;
        if !(rel.cmpge(Vec3::splat(-s)) & rel.cmple(self.dims_f + s)).all() {
            return None;
        }
        let i = rel.max(Vec3::ZERO).min(self.dims_f - 1.0);
        let (x, y, z) = (i.x as usize, i.y as usize, i.z as usize);
        Some((z * self.dims[1] + y) * self.dims[0] + x)
    }

    /// Number of cells.
    #[must_use]
    pub fn cell_count(&self) -> usize {
        self.cells.len()
    }

    /// Cells listing no candidate ([`WallGrid::clear_at`]: their estimates test nothing).
    #[must_use]
    pub fn clear_cells(&self) -> usize {
        self.cells
            .iter()
            .filter(|c| c.is_some_and(|(start, end)| start == end))
            .count()
    }

    /// The candidates listed in some cell: triangles, and surfaces known by their bounds.
    #[must_use]
    pub fn candidate_counts(&self) -> (usize, usize) {
        let triangles = self
            .walls
            .iter()
            .filter(|w| w.kind == WallKind::Triangle)
            .count();
        (triangles, self.walls.len() - triangles)
    }

    /// Bytes held.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        self.cells.len() * std::mem::size_of::<Option<(u32, u32)>>()
            + self.slot.len() * 28
            + self.walls.len() * std::mem::size_of::<Wall>()
    }
}

/// The wall candidates of one estimate: its query point's cell of the map's [`WallGrid`]
/// ([`WallGrid::near`]), tested by `CellList::crosses` (`wall_list.rs`). A view; nothing is
/// copied per estimate.
#[derive(Debug, Clone, Copy)]
pub struct CellList<'a> {
    pub(super) grid: &'a WallGrid,
    /// The cell's first slot in the grid's arrays.
    pub(super) start: usize,
    /// One past the cell's last slot.
    pub(super) end: usize,
}

/// The reach of an estimate of radius `r` around `q`: every segment it tests lies within it of
/// `q` (module docs).
#[inline]
#[must_use]
pub fn estimate_reach(q: Vec3, r: f32) -> f32 {
    1.2501 * r + 12.0 * walls::tolerance(q)
}

/// Every opaque surface of `walls`' geometry as a wall candidate (module docs), in the
/// geometry's order; with [`Listing::PotentialWalls`] only those that can separate a query
/// point from a photon of an estimate of reach up to `reach.far`'s grid
/// ([`super::potential_walls`]).
fn candidates(walls: &Walls<'_>, geometry: &Geometry, listing: Listing, reach: Reach) -> Vec<Wall> {
    let every = listing == Listing::Every;
    let objects = geometry
        .tri_attrs
        .iter()
        .map(|a| a.object as usize + 1)
        .max()
        .unwrap_or(0);
    let mut per_object = vec![0usize; objects];
    for a in &geometry.tri_attrs {
        per_object[a.object as usize] += 1;
    }
    // Whether each object can block, asked once per object (a material lookup).
    let opaque: Vec<bool> = (0..objects as u32)
        .map(|o| walls.can_block_any_object(o))
        .collect();
    let mut big: Vec<Option<Aabb>> = vec![None; objects];
    let mut out = Vec::new();
    for (t, a) in geometry.triangles.iter().zip(&geometry.tri_attrs) {
        if !opaque.get(a.object as usize).copied().unwrap_or(true) {
            continue;
        }
        let bounds = Aabb::from_points(t);
        if per_object[a.object as usize] > SMALL_OBJECT {
            let b = &mut big[a.object as usize];
            *b = Some(b.map_or(bounds, |b| b.union(bounds)));
            continue;
        }
        let ng = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
        // A degenerate triangle (NaN normal) is never hit.
        if !ng.is_finite() {
            continue;
        }
        let wall = Wall {
            kind: WallKind::Triangle,
            corners: *t,
            ng,
            offset: ng.dot(t[0]),
            bounds,
            body: walls.body_of(a.object),
        };
        if every
            || triangle_can_separate(
                geometry,
                Plane {
                    ng,
                    offset: wall.offset,
                },
                &bounds,
                reach,
            )
        {
            out.push(wall);
        }
    }
    let solid_near =
        |bounds: &Aabb, object: u32| every || solid_can_separate(geometry, bounds, object, reach);
    let solid = |bounds: Aabb, object: u32| Wall {
        kind: WallKind::Bounds,
        corners: [Vec3::ZERO; 3],
        ng: Vec3::ZERO,
        offset: 0.0,
        bounds,
        body: walls.body_of(object),
    };
    for (object, b) in big.iter().enumerate() {
        if let Some(b) = b {
            out.push(solid(*b, object as u32));
        }
    }
    for s in &geometry.spheres {
        if walls.can_block_any_object(s.object) {
            let r = Vec3::splat(s.radius * (1.0 + 1e-6) + walls::tolerance(s.center));
            let b = Aabb {
                min: s.center - r,
                max: s.center + r,
            };
            if solid_near(&b, s.object) {
                out.push(solid(b, s.object));
            }
        }
    }
    for e in &geometry.ellipsoids {
        if walls.can_block_any_object(e.object) {
            let l = e.world_from_object.matrix3;
            let half = DVec3::new(l.row(0).length(), l.row(1).length(), l.row(2).length());
            let c = e.world_from_object.translation;
            let pad = Vec3::splat(walls::tolerance((c.abs() + half).as_vec3()));
            let b = Aabb {
                min: (c - half).as_vec3() - pad,
                max: (c + half).as_vec3() + pad,
            };
            if solid_near(&b, e.object) {
                out.push(solid(b, e.object));
            }
        }
    }
    for q in &geometry.quadrics {
        if walls.can_block_any_object(q.object) && solid_near(&q.bounds(), q.object) {
            out.push(solid(q.bounds(), q.object));
        }
    }
    out
}

/// Whether boxes `a` and `b` share a point.
#[inline]
pub(super) fn overlaps(a: &Aabb, b: &Aabb) -> bool {
    a.min.cmple(b.max).all() && b.min.cmple(a.max).all()
}

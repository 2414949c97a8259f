//! The radiance estimate from a photon map (Jensen 2001, §7.1): the `k` nearest photons within
//! the map's largest radius, each weighted by the BSDF, over the area of their disc.
//!
//! The photon integrator's maps read another estimate with the same kernels and side tests:
//! each photon's flux over a disc of its *own* k-nearest radius ([`super::discs`], after
//! [`PhotonMap::use_photon_discs`]), which keeps a caustic's flux where this k-nearest estimate
//! around the query reads the dark gaps between bright bands too bright (+4 % on the bath's tub
//! floor). The k-nearest estimate below remains the progressive passes' (with a shrink) and
//! gives the radii of both.
//!
//! `L(x, ωo) ≈ Σₚ w(dₚ) f(ωo, ωₚ) Φₚ · |ns·ωₚ|/|nₚ·ωₚ| / (π r² c)` where
//! - `r` is the distance of the k-th nearest photon, which itself is left out of the sum: the
//!   k − 1 photons strictly inside the disc make the estimate unbiased for a uniform density
//!   (π r_k² λ is Gamma(k)-distributed, so E[(k − 1)/(π r_k²)] = λ; García et al., CGF 2012);
//!   when the radius cut the search short (fewer than k found) `r` is the largest radius and
//!   every photon counts;
//! - `w` is the kernel and `c` its normalisation (box: 1, 1; Jensen's cone `1 − d/(k r)`:
//!   `c = 1 − 2/(3k)`), so a uniform density reads its true value whichever kernel is used;
//! - `|ns·ωₚ|/|nₚ·ωₚ|` turns the flux that crossed the geometric surface into the cosine the
//!   shading normal implies (the camera side of Veach's adjoint rule, §5.3). `nₚ` is the
//!   geometric normal where the photon *landed* (stored with it), not the query's: on a
//!   smooth-shaded low-poly mesh a disc near a facet edge holds photons of the neighbouring
//!   facet, whose flux per area went with their own facet's cosine; dividing by the query
//!   facet's (near a terminator, ~0) multiplied them 10-25× (issue 29, smooth-normal-photons).
//!   The divisor is floored at [`MIN_LANDING_COSINE`] against octahedral rounding of grazing
//!   photons;
//! - photons from the other side of the surface or from another surface are rejected: their
//!   stored normal must face the query's normal (`nₚ·ng > 0.1`) and their direction must arrive
//!   from the side of `ωo` (`ωₚ·ng > 0`), the tests of Mitsuba 0.6's photon map (hard case 12);
//! - photons a wall separates from the query point are rejected ([`super::walls`]): a wall
//!   thinner than the disc on a floor that runs under it leaves the far side's photons in the
//!   query's plane with its normal, where the tests above accept them (issue 47,
//!   thin-wall-photon-leak: a dark room read up to 0.1). Photons are marked when their map is
//!   built ([`PhotonMap::mark_walls`]) if a surface rises above their plane within reach; only
//!   those (and photons on a level above the query) are tested, each at once against the list
//!   of the walls within reach of the query's cell of a grid built with the marks
//!   ([`super::wall_grid`], [`super::wall_list`]) or by a ray, and a crossing counts as a
//!   wall only when the surface stands across the receiver, so contact regions, creases and
//!   curved receivers read what they read without the test.
//!
//! Progressive passes ([`PhotonMap::set_shrink`], `integrators::photon::passes`) read
//! only the photons strictly inside `s·r`, `s` ∈ (0, 1], over the area `π (s r)² c`. Given
//! `r`, the k − 1 photons inside the k-nearest disc are independent draws from the density
//! restricted to it, so the count inside `s·r` is (k − 1)·P(inside `s·r` | inside `r`) on
//! average: for a uniform density the estimate stays unbiased, and in general it is the
//! density averaged over the smaller disc. As `s` shrinks by Knaus & Zwicker's schedule the
//! blur vanishes, while the disc still follows the local photon density (sharp where photons
//! crowd, wide where they are sparse), which a single radius per pass cannot do.
//!
//! A radius of 0 (all k photons at one point) is raised to [`MIN_RADIUS_FRACTION`] of the
//! largest radius, so coincident photons give a finite estimate. Any other radius is used as
//! found: the largest radius only caps a search and never widens a disc, so once it no longer
//! cuts searches short the estimate does not depend on it (issue 29, estimate-radius-floor).

use std::cell::RefCell;
use std::sync::Arc;

use glam::Vec3;

use super::discs::PhotonDiscs;
use super::radius_field::RadiusField;
use super::wall_grid::{CellList, WallGrid, estimate_reach};
use super::wall_list::Crossing;
use super::walls::{self, Walls};
use crate::shading::{Bsdf, ShadingFrame, TransportMode};
use crate::spatial::{HasPosition, HashGrid, KdTree, KnnHeap, Photon};

/// The radius given to an estimate whose k nearest photons all lie at one point (a zero radius),
/// as a fraction of the map's largest radius.
pub const MIN_RADIUS_FRACTION: f32 = 1e-3;

/// Smallest landing cosine `|nₚ·ωₚ|` an estimate divides by (the stored directions are rounded
/// to 6.5e-5 rad, so a grazing photon's could read 0 or below).
pub const MIN_LANDING_COSINE: f32 = 1e-3;

/// The kernel weighing photons by distance within the estimate's disc.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kernel {
    /// Constant weight.
    Box,
    /// Jensen's cone filter with slope constant `k ≥ 1`: weight `1 − d/(k r)`.
    Cone(f32),
}

impl Kernel {
    /// Weight of a photon at distance `d` in a disc of radius `r`.
    #[inline]
    fn weight(self, d: f32, r: f32) -> f32 {
        match self {
            Kernel::Box => 1.0,
            Kernel::Cone(k) => (1.0 - d / (k * r)).max(0.0),
        }
    }

    /// ∫ weight over the disc divided by its area πr² (Jensen 2001, §7.1: the cone filter's
    /// `1 − 2/(3k)`).
    #[inline]
    fn normalisation(self) -> f32 {
        match self {
            Kernel::Box => 1.0,
            Kernel::Cone(k) => 1.0 - 2.0 / (3.0 * k),
        }
    }
}

/// A photon map ready for estimates.
#[derive(Debug)]
pub struct PhotonMap {
    tree: KdTree<Photon>,
    k: usize,
    max_radius: f32,
    kernel: Kernel,
    /// Progressive passes: estimates use only the photons within this fraction of the k-nearest
    /// radius (1: the plain k-nearest estimate), or of the radius field's `R(x)`.
    shrink: f32,
    /// Progressive passes: the fixed per-pass lookup (`R(x)` from a pilot map and the pass's
    /// photons in a hash grid) that replaces the k-nearest search.
    pass: Option<PassLookup>,
    /// Per photon (in tree order): whether a surface rises above its plane within reach of an
    /// estimate of radius `wall_radius` ([`walls::near_wall`]); empty until
    /// [`PhotonMap::mark_walls`], and then every photon is tested by a ray.
    near_wall: Vec<bool>,
    /// The estimate radius the marks hold for (scene units; 0 before marking).
    wall_radius: f32,
    /// The potential walls near every point, for estimates of radius up to `wall_radius`
    /// ([`WallGrid`], built with the marks); `None` before marking or when the scene is too
    /// large for one (estimates then test by rays).
    wall_grid: Option<WallGrid>,
    /// The photon integrator's maps: each photon's own disc ([`PhotonMap::use_photon_discs`]),
    /// read by the sample-point estimate instead of the k-nearest one.
    discs: Option<PhotonDiscs>,
}

/// A progressive pass's lookup ([`PhotonMap::set_pass_lookup`]): estimates read the photons
/// within `shrink · R(x)` of `x`, found in a hash grid of the pass's photons.
#[derive(Debug)]
struct PassLookup {
    field: Arc<RadiusField>,
    /// The pass's photons in hash grids of growing cell side (each [`GRID_LEVEL_RATIO`] times
    /// the last, from the disc diameter at the field's typical radius to its largest).
    grids: Vec<HashGrid<Landing>>,
}

/// A photon decoded once per pass for the pass grids (each is read by many estimates): 48
/// bytes instead of the stored 24, no octahedral or RGBE decoding per estimate.
#[derive(Debug, Clone, Copy)]
struct Landing {
    position: [f32; 3],
    /// Unit direction back towards where the photon came from (−its direction of travel).
    wi: Vec3,
    /// Unit geometric normal where it landed.
    normal: Vec3,
    /// Power per channel (W).
    power: Vec3,
    /// The radius (scene units) its wall mark was made for ([`walls::near_wall`] false): no
    /// wall separates it from a query point within that distance, whatever the disc's radius;
    /// farther query points test it. 0 for a photon marked near a wall.
    clear: f32,
}

impl Landing {
    /// Decodes `ph`, known clear of walls for estimates of radius up to `clear`.
    #[inline]
    fn new(ph: &Photon, clear: f32) -> Self {
        Self {
            position: ph.position().to_array(),
            wi: -ph.direction(),
            normal: ph.normal(),
            power: ph.power(),
            clear,
        }
    }
}

impl HasPosition for Landing {
    #[inline]
    fn position(&self) -> [f32; 3] {
        self.position
    }
}

/// Ratio of the cell sides of successive pass grids.
const GRID_LEVEL_RATIO: f32 = 2.0;
/// Most pass grids (cell sides up to 2⁹ times the finest).
const MAX_GRID_LEVELS: usize = 10;

/// One radiance estimate and how it was made (for `debug-pixel` and the summary).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Estimate {
    /// Reflected radiance (W·m⁻²·sr⁻¹ per channel).
    pub radiance: Vec3,
    /// Photons found by the k-nearest search (with photon discs: the discs covering the point).
    pub found: usize,
    /// Radius of the disc used (scene units; with photon discs: the largest disc covering the
    /// point, how far from it the light read may have landed).
    pub radius: f32,
    /// True when the largest radius cut the search short (fewer than k photons found; with
    /// photon discs: a disc covering the point was capped by it, or none covers it).
    pub cut: bool,
    /// Wall-test rays traced ([`super::walls::separated`]): 0 unless an accepted photon is
    /// marked near a wall or lies on a level above the query point, and the estimate's wall
    /// list could not decide ([`super::wall_list`]).
    pub rays: u32,
    /// Photons whose segment was tested against the estimate's wall list
    /// ([`super::wall_grid::CellList::crosses`]; those it could not decide, a mesh or a sphere
    /// in the segment's box, are counted in `rays` too).
    pub listed: u32,
    /// Accepted photons a wall separates from the query point (left out).
    pub hidden: u32,
}

thread_local! {
    /// Each worker's k-nearest heap (reused; no allocation per estimate).
    static HEAP: RefCell<KnnHeap> = RefCell::new(KnnHeap::new(1));
}

impl PhotonMap {
    /// A map over `tree`, estimating from the `k` nearest photons within `max_radius`.
    #[must_use]
    pub fn new(tree: KdTree<Photon>, k: usize, max_radius: f32, kernel: Kernel) -> Self {
        Self {
            tree,
            k: k.max(1),
            max_radius,
            kernel,
            shrink: 1.0,
            pass: None,
            near_wall: Vec::new(),
            wall_radius: 0.0,
            wall_grid: None,
            discs: None,
        }
    }

    /// Marks each photon near which a surface of `geometry` rises above its tangent plane within
    /// reach of an estimate of the largest radius ([`walls::near_wall`], one BVH region query per
    /// photon, in parallel): estimates trace wall-test rays only for marked photons. Deterministic.
    pub fn mark_walls(&mut self, walls: Walls<'_>) {
        self.mark_walls_within(walls, self.max_radius);
    }

    /// [`PhotonMap::mark_walls`] for estimates of radius up to `radius` (scene units).
    fn mark_walls_within(&mut self, walls: Walls<'_>, radius: f32) {
        use rayon::prelude::*;
        let bounds = walls.geometry().bvh.bounds;
        let far = bounds.min.abs().max(bounds.max.abs());
        self.wall_grid = WallGrid::build(&walls, estimate_reach(far, radius));
        // A photon whose cell lists no potential wall within the mark's reach needs no mark:
        // a wall separating it from a query point within `radius` crosses the segment within
        // that reach of it, so it would be listed there (super::potential_walls).
        let grid = self.wall_grid.as_ref();
        self.near_wall = self
            .tree
            .items()
            .par_iter()
            .map(|ph| {
                let p = ph.position();
                !grid.is_some_and(|g| g.clear_at(p, walls::reach(p, radius)))
                    && walls::near_wall(&walls, p, ph.normal(), radius)
            })
            .collect();
        self.wall_radius = radius;
    }

    /// Photons marked near a wall ([`PhotonMap::mark_walls`]; all of them before marking).
    #[must_use]
    pub fn near_wall_count(&self) -> usize {
        if self.near_wall.is_empty() {
            return self.len();
        }
        self.near_wall.iter().filter(|&&m| m).count()
    }

    /// Photon `index`'s wall mark (true when unmarked: a ray decides).
    #[inline]
    fn marked(&self, index: u32) -> bool {
        self.near_wall.get(index as usize).copied().unwrap_or(true)
    }

    /// Makes every later estimate (outside progressive passes) the sample-point estimate of
    /// [`super::discs`]: each photon's flux spread over a disc of its own k-nearest radius
    /// (capped at the largest radius), which keeps the flux of every region, where the
    /// k-nearest estimate around the query reads dark gaps between bright caustic bands too
    /// bright (+4 % on the bath's tub floor). Costs one k-nearest search per photon, once.
    ///
    /// Each disc's wall mark is made again for its own radius `h` (one BVH region query per
    /// photon marked for the largest radius; [`walls::near_wall`] only grows with the radius,
    /// so an unmarked photon stays unmarked): every query point a disc covers lies within `h`
    /// of its photon, so an estimate tests a disc only when it is marked for `h`.
    pub fn use_photon_discs(&mut self, walls: Walls<'_>) {
        let max_radius = self.max_radius;
        let wall_radius = self.wall_radius;
        self.discs = PhotonDiscs::build(
            &self.tree,
            |p| disc_radius(self.knn_radius_found(p), max_radius),
            |index, ph, radius| {
                self.marked(index)
                    && (radius > wall_radius
                        || walls::near_wall(&walls, ph.position(), ph.normal(), radius))
            },
        );
    }

    /// The distance of the k-th nearest photon to `p` (`p`'s own photon included), or `None`
    /// when fewer than k lie within the largest radius.
    fn knn_radius_found(&self, p: Vec3) -> Option<f32> {
        HEAP.with(|h| {
            let mut heap = h.borrow_mut();
            heap.set_k(self.k);
            let max2 = self.max_radius * self.max_radius;
            let found = self.tree.nearest(p.to_array(), max2, &mut heap);
            (found >= self.k).then(|| heap.max_dist2().unwrap_or(max2).sqrt())
        })
    }

    /// Makes every later estimate a progressive pass's fixed-radius one: the photons within
    /// `shrink · field.radius(x)` of the query `x` ([`RadiusField`]; `shrink` ∈ (0, 1] from the
    /// radius schedule), over that disc's area. The pass's photons go into a hash grid whose
    /// cell side is the disc's diameter at the field's typical radius, so a typical query
    /// visits at most 8 cells (one grid per power of two of the disc's diameter, up to the
    /// field's largest radius). With a field that does not depend on this map's photons (a
    /// pilot map's), each estimate is the plain density estimate over a fixed disc: its mean is
    /// the radiance averaged over the disc (Knaus & Zwicker 2011).
    ///
    /// The wall marks are made for the pass's discs: every photon for the widest disc of the
    /// pass (`shrink` times the field's largest radius; unless already marked for one at least
    /// as wide), and a photon marked for it again at twice the pass's radius where it lies,
    /// `2 · shrink · R(p)` (one BVH region query each); an estimate whose disc is larger than the
    /// radius a photon's mark was made for tests that photon ([`walls::needs_ray`]).
    pub fn set_pass_lookup(&mut self, shrink: f32, field: Arc<RadiusField>, walls: Walls<'_>) {
        use rayon::prelude::*;
        self.set_shrink(shrink);
        // Grids whose cells are the disc's diameter at the field's typical radius, then 2×, 4×
        // … up to its largest, so that every estimate finds a grid where its disc overlaps at
        // most 8 cells. The photons are decoded once for all of them.
        let shrink = self.shrink;
        // Discs where the pilot found no photon take the pilot's largest radius, which can
        // exceed this map's: marks are then made again for the widest disc.
        let widest = shrink * field.fallback();
        if widest > self.wall_radius {
            self.mark_walls_within(walls, widest);
        }
        let wall_radius = self.wall_radius;
        let landings: Vec<Landing> = (0..self.tree.len())
            .into_par_iter()
            .map(|i| {
                let ph = &self.tree.items()[i];
                if !self.marked(i as u32) {
                    return Landing::new(ph, wall_radius);
                }
                let (p, n) = (ph.position(), ph.normal());
                let radius = (2.0 * shrink * field.radius(p)).min(wall_radius);
                let clear = if walls::near_wall(&walls, p, n, radius) {
                    0.0
                } else {
                    radius
                };
                Landing::new(ph, clear)
            })
            .collect();
        let mut grids = Vec::new();
        let mut cell = 2.0 * self.shrink * field.typical();
        let widest = 2.0 * self.shrink * field.fallback();
        while grids.len() < MAX_GRID_LEVELS {
            let Ok(grid) = HashGrid::build(landings.clone(), cell) else {
                break;
            };
            grids.push(grid);
            if cell >= widest {
                break;
            }
            cell *= GRID_LEVEL_RATIO;
        }
        self.pass = Some(PassLookup { field, grids });
    }

    /// The distance of the k-th nearest photon to `p`, or the largest radius when fewer than k
    /// lie within it (the radius of a plain k-nearest estimate, before the progressive shrink).
    #[must_use]
    pub fn knn_radius(&self, p: Vec3) -> f32 {
        HEAP.with(|h| {
            let mut heap = h.borrow_mut();
            heap.set_k(self.k);
            let max2 = self.max_radius * self.max_radius;
            let found = self.tree.nearest(p.to_array(), max2, &mut heap);
            if found < self.k {
                self.max_radius
            } else {
                heap.max_dist2().unwrap_or(max2).sqrt()
            }
        })
    }

    /// The radius of the disc an estimate at `p` reads (scene units): the pass's `shrink · R(p)`
    /// with a pass lookup, else the largest radius (a k-nearest estimate's disc is at most
    /// that). What the short-gather rule compares a gather ray's length with.
    #[must_use]
    pub fn radius_at(&self, p: Vec3) -> f32 {
        match &self.pass {
            Some(pass) => self.shrink * pass.field.radius(p),
            None => self.max_radius,
        }
    }

    /// Makes every later estimate a progressive pass's: it reads only the photons within
    /// `shrink` ∈ (0, 1] times the k-nearest radius `r` (the largest radius when fewer than k
    /// are found), over the area of that smaller disc (see the module docs).
    pub fn set_shrink(&mut self, shrink: f32) {
        self.shrink = shrink.clamp(f32::MIN_POSITIVE, 1.0);
    }

    /// The fraction of the k-nearest radius estimates read (1 unless a progressive pass).
    #[must_use]
    pub fn shrink(&self) -> f32 {
        self.shrink
    }

    /// The stored photons.
    #[must_use]
    pub fn photons(&self) -> &[Photon] {
        self.tree.items()
    }

    /// Number of stored photons.
    #[must_use]
    pub fn len(&self) -> usize {
        self.tree.len()
    }

    /// True if no photon is stored.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.tree.is_empty()
    }

    /// This map as the pilot of a progressive render's initial radius `R(x)`
    /// ([`RadiusField::from_radii`]): each photon's k-nearest radius in this map, raised to
    /// [`MIN_RADIUS_FRACTION`] of the largest radius. `None` for an empty map.
    #[must_use]
    pub fn radius_field(&self) -> Option<RadiusField> {
        use rayon::prelude::*;
        if self.is_empty() {
            return None;
        }
        let max_radius = self.max_radius();
        let floor = max_radius * MIN_RADIUS_FRACTION;
        RadiusField::cell_side(max_radius)?;
        let radii: Vec<(Vec3, f32)> = self
            .photons()
            .par_iter()
            .map(|ph| (ph.position(), self.knn_radius(ph.position()).max(floor)))
            .collect();
        RadiusField::from_radii(max_radius, floor, &radii)
    }

    /// The largest estimate radius (scene units).
    #[must_use]
    pub fn max_radius(&self) -> f32 {
        self.max_radius
    }

    /// Bytes the map holds.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        self.tree.memory_bytes()
            + self.discs.as_ref().map_or(0, PhotonDiscs::memory_bytes)
            + self.wall_grid.as_ref().map_or(0, WallGrid::memory_bytes)
    }

    /// Radiance leaving `p` towards `wo` through the non-delta part of `bsdf` in frame `fr` (as
    /// the camera side sees it), estimated from the nearest photons that no wall of `geometry`
    /// separates from `p`. See the module docs.
    #[must_use]
    pub fn estimate(
        &self,
        p: Vec3,
        wo: Vec3,
        fr: &ShadingFrame,
        bsdf: &Bsdf,
        walls: Walls<'_>,
    ) -> Estimate {
        let at = bsdf.at(wo, fr);
        self.gather(p, fr.ng, walls, |power, wi, cos_p| {
            let cos_s = wi.dot(fr.ns).max(0.0);
            at.eval(wi, TransportMode::Radiance) * power * (cos_s / cos_p)
        })
    }

    /// Irradiance (W/m² per channel) arriving at `p` on the side of unit normal `n`, from the
    /// nearest photons that no wall of `geometry` separates from `p` (the estimate's
    /// `radiance` field holds it).
    #[must_use]
    pub fn irradiance(&self, p: Vec3, n: Vec3, walls: Walls<'_>) -> Estimate {
        self.gather(p, n, walls, |power, _, _| power)
    }

    /// The density estimate at `p` (surface normal `ng`, on the query's side): the kernel-
    /// weighted sum of `value(photon, wi, cos θₚ)` over the accepted photons (`cos θₚ` the
    /// landing cosine, [`accept`]) that no wall of `geometry` separates from `p`, over the
    /// disc's normalised area.
    fn gather(
        &self,
        p: Vec3,
        ng: Vec3,
        walls: Walls<'_>,
        value: impl Fn(Vec3, Vec3, f32) -> Vec3,
    ) -> Estimate {
        if let Some(pass) = &self.pass {
            return self.gather_within(pass, p, ng, walls, value);
        }
        if let Some(discs) = &self.discs {
            return self.gather_discs(discs, p, ng, walls, value);
        }
        HEAP.with(|h| {
            let mut heap = h.borrow_mut();
            heap.set_k(self.k);
            let max2 = self.max_radius * self.max_radius;
            let found = self.tree.nearest(p.to_array(), max2, &mut heap);
            if found == 0 {
                return Estimate {
                    radius: self.max_radius,
                    cut: true,
                    ..Estimate::default()
                };
            }
            let cut = found < self.k;
            let (r2, skip) = if cut {
                (max2, None)
            } else {
                let far = heap.iter().max_by(|a, b| a.dist2.total_cmp(&b.dist2));
                (heap.max_dist2().unwrap_or(max2), far.map(|n| n.index))
            };
            let r2 = if r2 > 0.0 {
                r2
            } else {
                let min_r = self.max_radius * MIN_RADIUS_FRACTION;
                min_r * min_r
            };
            let r2 = r2 * self.shrink * self.shrink;
            let r = r2.sqrt();
            let photons = self.tree.items();
            let mut sum = Vec3::ZERO;
            let mut sight = Sight::new(walls, self.wall_grid.as_ref(), p, ng, r);
            for n in heap.iter() {
                if Some(n.index) == skip || (self.shrink < 1.0 && n.dist2 >= r2) {
                    continue;
                }
                let ph = &photons[n.index as usize];
                let Some((wi, cos_g)) = accept(ph, ng) else {
                    continue;
                };
                sight.add(
                    &mut sum,
                    ph.position(),
                    ph.normal(),
                    self.marked(n.index),
                    || value(ph.power(), wi, cos_g) * self.kernel.weight(n.dist2.sqrt(), r),
                );
            }
            let area = std::f32::consts::PI * r2 * self.kernel.normalisation();
            Estimate {
                radiance: sum / area,
                found,
                radius: r,
                cut,
                rays: sight.rays,
                listed: sight.listed,
                hidden: sight.hidden,
            }
        })
    }
}

impl PhotonMap {
    /// The sample-point estimate at `p` (surface normal `ng`, [`super::discs`]): over the discs
    /// covering `p` whose photons pass the side tests ([`accept`]'s) and that no wall of
    /// `walls` separates from `p`, the sum of `value(power, ωₚ, cos θₚ) · w(d, h)/(π h² c)`,
    /// each with its own radius `h` (Jensen 2001, §7.1's cone filter normalised over its disc:
    /// `c = 1 − 2/(3k)`). Its `radius` is the largest disc covering `p` (how far away light read
    /// here may have landed); `cut` says one of them was capped by the largest radius, or none
    /// covers `p`.
    #[inline]
    fn gather_discs(
        &self,
        discs: &PhotonDiscs,
        p: Vec3,
        ng: Vec3,
        walls: Walls<'_>,
        value: impl Fn(Vec3, Vec3, f32) -> Vec3,
    ) -> Estimate {
        let c = std::f32::consts::PI * self.kernel.normalisation();
        let mut sum = Vec3::ZERO;
        let mut sight = Sight::new(walls, self.wall_grid.as_ref(), p, ng, discs.largest());
        let cover = discs.covering(p, |d, dist2| {
            if let Some(cos_p) = landing_cosine(d.normal, d.wi, ng) {
                sight.add(
                    &mut sum,
                    Vec3::from_array(d.position()),
                    d.normal,
                    d.near_wall,
                    || {
                        let w =
                            self.kernel.weight(dist2.sqrt(), d.radius) / (c * d.radius * d.radius);
                        value(d.power, d.wi, cos_p) * w
                    },
                );
            }
        });
        Estimate {
            radiance: sum,
            found: cover.found,
            radius: if cover.found > 0 {
                cover.reach
            } else {
                discs.largest()
            },
            cut: cover.capped || cover.found == 0,
            rays: sight.rays,
            listed: sight.listed,
            hidden: sight.hidden,
        }
    }

    /// A progressive pass's estimate at `p`: every accepted photon within `r = shrink · R(p)`
    /// that no wall of `geometry` separates from `p`, kernel-weighted, over the disc's
    /// normalised area `π r² c`.
    #[inline]
    fn gather_within(
        &self,
        pass: &PassLookup,
        p: Vec3,
        ng: Vec3,
        walls: Walls<'_>,
        value: impl Fn(Vec3, Vec3, f32) -> Vec3,
    ) -> Estimate {
        let r = self.shrink * pass.field.radius(p);
        // Where the query's cell of the wall grid lists no potential wall, no photon can be
        // hidden (every segment is clear, super::potential_walls): the search runs without
        // the per-photon wall comparisons.
        let open = self
            .wall_grid
            .as_ref()
            .is_some_and(|g| g.clear_at(p, estimate_reach(p, r)));
        let (sum, found, sight) = if open {
            self.search_within::<false>(pass, p, ng, walls, r, &value)
        } else {
            self.search_within::<true>(pass, p, ng, walls, r, &value)
        };
        let area = std::f32::consts::PI * r * r * self.kernel.normalisation();
        Estimate {
            radiance: if found > 0 { sum / area } else { Vec3::ZERO },
            found,
            radius: r,
            cut: false,
            rays: sight.rays,
            listed: sight.listed,
            hidden: sight.hidden,
        }
    }
}

impl PhotonMap {
    /// The photons of a progressive pass's disc of radius `r` at `p` ([`PhotonMap::
    /// gather_within`]), summed with the wall test when `TEST` (without it where the query's
    /// grid cell lists no potential wall): the sum, the photons found and the wall test's
    /// counts.
    #[inline]
    fn search_within<'g, const TEST: bool>(
        &'g self,
        pass: &PassLookup,
        p: Vec3,
        ng: Vec3,
        walls: Walls<'g>,
        r: f32,
        value: &impl Fn(Vec3, Vec3, f32) -> Vec3,
    ) -> (Vec3, usize, Sight<'g>) {
        let q = p.to_array();
        let mut disc: Disc<'g, TEST> = Disc {
            sum: Vec3::ZERO,
            found: 0,
            sight: Sight::new(walls, self.wall_grid.as_ref(), p, ng, r),
            ng,
            r,
            kernel: self.kernel,
        };
        // The finest grid whose cells are at least the disc's diameter (at most 8 cells to
        // visit); a disc wider than the widest grid's cells is found through the kd-tree. Both
        // find exactly the photons within r.
        if let Some(grid) = pass.grids.iter().find(|g| g.cell_size() >= 2.0 * r) {
            let photons = grid.items();
            grid.within(
                q,
                r,
                GridDisc {
                    disc: &mut disc,
                    photons,
                    value,
                },
            );
        } else {
            let photons = self.tree.items();
            self.tree.within(q, r * r, |n| {
                let ph = &photons[n.index as usize];
                let clear = if self.marked(n.index) {
                    0.0
                } else {
                    self.wall_radius
                };
                disc.add(&Landing::new(ph, clear), n.dist2, value);
            });
        }
        (disc.sum, disc.found, disc.sight)
    }
}

/// One progressive estimate's running sum over the photons of its disc
/// ([`PhotonMap::gather_within`]).
struct Disc<'g, const TEST: bool> {
    sum: Vec3,
    found: usize,
    sight: Sight<'g>,
    ng: Vec3,
    r: f32,
    kernel: Kernel,
}

impl<const TEST: bool> Disc<'_, TEST> {
    /// Adds the photon `ph` at squared distance `dist2` from the query point, if the side and
    /// wall tests accept it. Inlined into both searches' loops.
    #[inline(always)]
    fn add(&mut self, ph: &Landing, dist2: f32, value: &impl Fn(Vec3, Vec3, f32) -> Vec3) {
        self.found += 1;
        if let Some(cos_g) = landing_cosine(ph.normal, ph.wi, self.ng) {
            let (kernel, r) = (self.kernel, self.r);
            if !TEST {
                self.sum += value(ph.power, ph.wi, cos_g) * kernel.weight(dist2.sqrt(), r);
                return;
            }
            self.sight.add(
                &mut self.sum,
                Vec3::from_array(ph.position),
                ph.normal,
                dist2 > ph.clear * ph.clear,
                || value(ph.power, ph.wi, cos_g) * kernel.weight(dist2.sqrt(), r),
            );
        }
    }
}

/// [`Disc::add`] for each photon a grid search finds, inlined into the search's loop
/// ([`crate::spatial::Visit`]).
struct GridDisc<'a, 'g, F, const TEST: bool> {
    disc: &'a mut Disc<'g, TEST>,
    photons: &'a [Landing],
    value: &'a F,
}

impl<F: Fn(Vec3, Vec3, f32) -> Vec3, const TEST: bool> crate::spatial::Visit
    for GridDisc<'_, '_, F, TEST>
{
    #[inline(always)]
    fn visit(&mut self, n: crate::spatial::Neighbor) {
        self.disc
            .add(&self.photons[n.index as usize], n.dist2, self.value);
    }
}

/// The wall test of one estimate of radius `r` at query point `q` (unit geometric normal `nq`
/// on the side of `ωo`), counting the photons it tests and hides.
///
/// A photon is added as the search finds it unless it needs a test ([`walls::needs_ray`]:
/// marked near a wall at its distance, or on a level above `q`); a tested photon is decided at
/// once, in the search's order, so the sum is the one testing every photon by a ray would give.
/// At the estimate's first tested photon it looks up `q`'s cell of the map's [`WallGrid`]
/// ([`WallGrid::near`]); each tested segment is decided against the cell's candidates
/// ([`CellList::crosses`]), or by a ray
/// ([`walls::separated`]) where the list cannot decide (no grid, a cell with too many
/// candidates, a mesh or a sphere in the segment's box). An estimate that tests nothing costs
/// two comparisons per photon beyond the side tests (its mark and its height). A progressive
/// estimate whose cell lists no potential wall ([`WallGrid::clear_at`]) skips even those (one
/// lookup per estimate): with every opaque surface listed that skip cost the Cornell box
/// +2.4 % instructions more than it saved, with only the potential walls listed
/// ([`super::potential_walls`]) most of its cells are clear.
struct Sight<'g> {
    walls: Walls<'g>,
    grid: Option<&'g WallGrid>,
    q: Vec3,
    nq: Vec3,
    r: f32,
    /// A lower bound of [`walls::tolerance`] at every point within the estimate's radius of
    /// `q`: an unmarked photon no higher than this above `q`'s side of its plane needs no test
    /// (the first of [`walls::needs_ray`]'s tests, decided without the photon's own bound).
    tolerance_floor: f32,
    /// The estimate's wall candidates, looked up at its first tested photon (`Some(None)`: no
    /// list, rays decide).
    cell: Option<Option<CellList<'g>>>,
    rays: u32,
    listed: u32,
    hidden: u32,
}

impl<'g> Sight<'g> {
    /// The wall test of an estimate of radius `r` (scene units) around `q`, with the map's grid.
    #[inline]
    fn new(walls: Walls<'g>, grid: Option<&'g WallGrid>, q: Vec3, nq: Vec3, r: f32) -> Self {
        Self {
            walls,
            grid,
            q,
            nq,
            r,
            tolerance_floor: walls::tolerance_floor(q, r),
            cell: None,
            rays: 0,
            listed: 0,
            hidden: 0,
        }
    }

    /// Adds the accepted photon at `p` (unit normal `np`; `near_wall`: its mark does not clear
    /// it at its distance) of term `term` to `sum`, unless a wall separates it from `q`.
    #[inline(always)]
    fn add(
        &mut self,
        sum: &mut Vec3,
        p: Vec3,
        np: Vec3,
        near_wall: bool,
        term: impl FnOnce() -> Vec3,
    ) {
        if !((near_wall || (p - self.q).dot(np) > self.tolerance_floor)
            && self.hides(p, np, near_wall))
        {
            *sum += term();
        }
    }

    /// True when a wall separates the photon at `p` (unit normal `np`) from `q`:
    /// [`walls::needs_ray`]'s exact tests, then the estimate's wall list or a ray. Out of line
    /// (most photons never get here).
    #[cold]
    #[inline(never)]
    fn hides(&mut self, p: Vec3, np: Vec3, near_wall: bool) -> bool {
        if !walls::needs_ray(self.q, self.nq, p, np, near_wall) {
            return false;
        }
        let Some((a, b)) = walls::segment(self.q, self.nq, p, np) else {
            return false;
        };
        let (grid, q, r) = (self.grid, self.q, self.r);
        let cell = *self
            .cell
            .get_or_insert_with(|| grid.and_then(|g| g.near(q, estimate_reach(q, r))));
        let crossing = cell.map(|c| c.crosses(a, b, self.nq, np, self.walls.own_body()));
        let hidden = match crossing {
            Some(Crossing::Wall) => true,
            Some(Crossing::Clear) => false,
            Some(Crossing::Unknown) | None => {
                self.rays += 1;
                walls::separated(&self.walls, self.q, self.nq, p, np)
            }
        };
        if crossing.is_some() {
            self.listed += 1;
        }
        self.hidden += u32::from(hidden);
        hidden
    }
}

/// A photon's disc radius from its k-nearest radius `knn` (`None` when the largest radius
/// `max_radius` cut the search short): the radius and whether it was capped. A radius of 0 (k
/// coincident photons) is raised to [`MIN_RADIUS_FRACTION`] of the largest radius.
fn disc_radius(knn: Option<f32>, max_radius: f32) -> (f32, bool) {
    match knn {
        Some(r) if r > 0.0 => (r, false),
        Some(_) => (max_radius * MIN_RADIUS_FRACTION, false),
        None => (max_radius, true),
    }
}

/// The side tests of an estimate at a point of geometric normal `ng`: the photon's incoming
/// direction `ωₚ` and its landing cosine `cos θₚ = ωₚ·nₚ` with its own stored geometric normal
/// (at least [`MIN_LANDING_COSINE`]), or `None` when it landed on another surface (stored
/// normal `nₚ·ng ≤ 0.1`) or arrived from the other side (`ωₚ·ng ≤ 0`, as the BSDF and the
/// shadow ray see it: a facet lit at a grazing angle keeps its own photons).
#[inline]
fn accept(ph: &Photon, ng: Vec3) -> Option<(Vec3, f32)> {
    let wi = -ph.direction();
    landing_cosine(ph.normal(), wi, ng).map(|cos| (wi, cos))
}

/// [`accept`]'s tests on a decoded photon (stored normal `np`, incoming direction `wi`): its
/// landing cosine, or `None` when it landed on another surface or arrived from the other side.
#[inline]
fn landing_cosine(np: Vec3, wi: Vec3, ng: Vec3) -> Option<f32> {
    (!(np.dot(ng) <= 0.1) && wi.dot(ng) > 0.0).then(|| wi.dot(np).max(MIN_LANDING_COSINE))
}

/// Precomputed irradiance for final gathering (Christensen, "Faster Photon Map Global
/// Illumination", JGT 4(1), 1999): the irradiance of both maps estimated once at every
/// [`IRRADIANCE_STRIDE`]-th photon's position, so a final-gather ray that lands on a diffuse
/// surface costs one nearest-point lookup instead of two k-nearest estimates. The radiance
/// there is `f(ωo, n) · E`, exact for Lambert surfaces only: the photon integrator reads the
/// maps themselves where a surface has a Phong lobe. Each point also keeps the radius of the
/// estimate it came from, which tells final gathering when a gather ray is too short for the
/// estimate at its end (`integrators::photon`'s short-gather rule).
#[derive(Debug)]
pub struct IrradianceCache {
    /// Points (photon records whose `power` field holds the irradiance E in W/m²) with their
    /// estimate's radius.
    tree: KdTree<IrradiancePoint>,
    /// Largest lookup distance.
    max_radius: f32,
}

/// One point of an [`IrradianceCache`]: a photon record (position, normal, and the irradiance
/// in its `power` field) and the radius of the sites map's estimate there (scene units).
#[derive(Debug, Clone, Copy)]
struct IrradiancePoint {
    photon: Photon,
    radius: f32,
    /// Whether a surface rises above its plane within reach of a lookup
    /// ([`walls::near_wall`]): a lookup then tests that no wall separates it from the query.
    near_wall: bool,
}

impl HasPosition for IrradiancePoint {
    #[inline]
    fn position(&self) -> [f32; 3] {
        HasPosition::position(&self.photon)
    }
}

/// One irradiance point per this many photons of the map it is built on.
pub const IRRADIANCE_STRIDE: usize = 4;

/// Nearest points a lookup considers to find one on the same surface.
const LOOKUP_K: usize = 4;

impl IrradianceCache {
    /// Estimates the irradiance of `maps` (summed) at every [`IRRADIANCE_STRIDE`]-th photon of
    /// `sites` (in parallel, deterministic). `None` when there are no maps or sites, or when
    /// `cancel` is raised before the points are done (the rest are skipped at once).
    #[must_use]
    pub fn build(
        sites: &PhotonMap,
        maps: &[&PhotonMap],
        walls: Walls<'_>,
        cancel: Option<&std::sync::atomic::AtomicBool>,
    ) -> Option<Self> {
        use rayon::prelude::*;
        if maps.is_empty() || sites.is_empty() {
            return None;
        }
        let max_radius = maps.iter().map(|m| m.max_radius).fold(0.0, f32::max);
        let points: Vec<IrradiancePoint> = sites
            .photons()
            .par_iter()
            .step_by(IRRADIANCE_STRIDE)
            .map(|ph| {
                if cancel.is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed)) {
                    return IrradiancePoint {
                        photon: Photon::default(),
                        radius: 0.0,
                        near_wall: false,
                    };
                }
                let (p, n) = (ph.position(), ph.normal());
                let (e, radius) = maps.iter().fold((Vec3::ZERO, 0.0), |(e, r), m| {
                    let est = m.irradiance(p, n, walls);
                    let r = if std::ptr::eq(*m, sites) {
                        est.radius
                    } else {
                        r
                    };
                    (e + est.radiance, r)
                });
                IrradiancePoint {
                    photon: Photon::new(p, -n, n, e),
                    radius,
                    near_wall: walls::near_wall(&walls, p, n, max_radius),
                }
            })
            .collect();
        if cancel.is_some_and(|c| c.load(std::sync::atomic::Ordering::Relaxed)) {
            return None;
        }
        let tree = KdTree::build(points).ok()?;
        Some(Self { tree, max_radius })
    }

    /// Number of irradiance points.
    #[must_use]
    pub fn len(&self) -> usize {
        self.tree.len()
    }

    /// True when there is no point.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.tree.is_empty()
    }

    /// Bytes held.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        self.tree.memory_bytes()
    }

    /// The irradiance at the nearest point on the same surface side as `ng` (normals within
    /// ~25°) that no wall of `geometry` separates from `p` ([`walls`]), or `None` when no such
    /// point lies within the largest radius.
    #[must_use]
    pub fn lookup(&self, p: Vec3, ng: Vec3, walls: Walls<'_>) -> Option<Vec3> {
        self.lookup_with_radius(p, ng, walls).map(|(e, _)| e)
    }

    /// [`IrradianceCache::lookup`], with the radius (scene units) of the estimate the point's
    /// irradiance came from.
    #[must_use]
    pub fn lookup_with_radius(&self, p: Vec3, ng: Vec3, walls: Walls<'_>) -> Option<(Vec3, f32)> {
        HEAP.with(|h| {
            let mut heap = h.borrow_mut();
            heap.set_k(LOOKUP_K);
            let max2 = self.max_radius * self.max_radius;
            self.tree.nearest(p.to_array(), max2, &mut heap);
            heap.sort();
            let points = self.tree.items();
            heap.iter()
                .map(|n| &points[n.index as usize])
                .filter(|c| c.photon.normal().dot(ng) > 0.9)
                .find(|c| {
                    let (cp, cn) = (c.photon.position(), c.photon.normal());
                    !(walls::needs_ray(p, ng, cp, cn, c.near_wall)
                        && walls::separated(&walls, p, ng, cp, cn))
                })
                .map(|c| (c.photon.power(), c.radius))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render_scene::Geometry;
    use crate::sampling::Rng;

    fn flat_map(n: usize, k: usize, kernel: Kernel, seed: u64) -> PhotonMap {
        // Poisson photons of density n/4 on the square [-1, 1]² of the plane z = 0, arriving
        // straight down, each of power 1 (W, all channels).
        let mut rng = Rng::new(seed, 3);
        let photons: Vec<Photon> = (0..n)
            .map(|_| {
                let (a, b) = rng.next_2d();
                Photon::new(
                    Vec3::new(2.0 * a - 1.0, 2.0 * b - 1.0, 0.0),
                    -Vec3::Z,
                    Vec3::Z,
                    Vec3::ONE,
                )
            })
            .collect();
        let tree = KdTree::build(photons).expect("finite photons");
        PhotonMap::new(tree, k, 10.0, kernel)
    }

    fn white_lambert() -> Bsdf {
        Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [Some(1.0), None, None], 1.0)
    }

    fn up_frame() -> ShadingFrame {
        ShadingFrame {
            ns: Vec3::Z,
            ng: Vec3::Z,
            entering: true,
        }
    }

    /// Mean over interior queries of the estimate divided by the exact value: irradiance
    /// E = λ = n/4 W/m², so a white Lambert surface reads L = E/π.
    fn mean_ratio(kernel: Kernel, k: usize) -> f64 {
        let n = 40_000;
        let exact = (n as f32 / 4.0) / std::f32::consts::PI;
        let mut sum = 0.0f64;
        let mut count = 0;
        for seed in 0..8 {
            let map = flat_map(n, k, kernel, seed);
            let mut rng = Rng::new(seed, 9);
            for _ in 0..250 {
                let (a, b) = rng.next_2d();
                let p = Vec3::new(a - 0.5, b - 0.5, 0.0);
                let e = map.estimate(
                    p,
                    Vec3::Z,
                    &up_frame(),
                    &white_lambert(),
                    Walls::every_surface(&Geometry::default()),
                );
                assert!(!e.cut);
                sum += f64::from(e.radiance.x / exact);
                count += 1;
            }
        }
        sum / f64::from(count)
    }

    #[test]
    fn box_estimate_of_a_uniform_density_is_unbiased() {
        // With the k-th photon left out, E[(k − 1)/(π r_k²)] = λ (hard case 23); the
        // classic k/(π r_k²) would read k/(k − 1) = 1.111 at k = 10.
        let r = mean_ratio(Kernel::Box, 10);
        assert!((r - 1.0).abs() < 0.01, "box k=10 ratio {r}");
    }

    #[test]
    fn cone_estimate_is_normalised() {
        let r = mean_ratio(Kernel::Cone(1.1), 100);
        assert!((r - 1.0).abs() < 0.015, "cone k=100 ratio {r}");
    }

    #[test]
    fn photons_from_the_other_side_are_rejected() {
        let map = flat_map(1000, 20, Kernel::Box, 1);
        // Seen from below (frame flipped), every photon arrived from the other side.
        let down = ShadingFrame {
            ns: -Vec3::Z,
            ng: -Vec3::Z,
            entering: false,
        };
        let e = map.estimate(
            Vec3::ZERO,
            -Vec3::Z,
            &down,
            &white_lambert(),
            Walls::every_surface(&Geometry::default()),
        );
        assert_eq!(e.radiance, Vec3::ZERO);
        assert_eq!(e.found, 20);
    }

    #[test]
    fn coincident_photons_give_a_finite_estimate() {
        let photons = vec![Photon::new(Vec3::ZERO, -Vec3::Z, Vec3::Z, Vec3::ONE); 500];
        let map = PhotonMap::new(KdTree::build(photons).expect("tree"), 50, 1.0, Kernel::Box);
        let e = map.estimate(
            Vec3::ZERO,
            Vec3::Z,
            &up_frame(),
            &white_lambert(),
            Walls::every_surface(&Geometry::default()),
        );
        assert!(e.radiance.is_finite() && e.radiance.x > 0.0);
        assert_eq!(e.radius, MIN_RADIUS_FRACTION);
    }

    #[test]
    fn the_largest_radius_only_caps_the_disc() {
        // Issue 29 (estimate-radius-floor): photons 1e-5 apart (a 1 mm part) read the same
        // density whether the largest radius is 1 cm or 100 m, as long as it does not cut the
        // search; the exact irradiance of a uniform density λ is λ.
        let mut rng = Rng::new(4, 3);
        let side = 2e-3f32;
        let n = 40_000;
        let photons: Vec<Photon> = (0..n)
            .map(|_| {
                let (a, b) = rng.next_2d();
                let p = Vec3::new(side * (a - 0.5), side * (b - 0.5), 0.0);
                Photon::new(p, -Vec3::Z, Vec3::Z, Vec3::ONE)
            })
            .collect();
        let lambda = n as f32 / (side * side);
        for max_radius in [1e-2, 1.0, 100.0] {
            let tree = KdTree::build(photons.clone()).expect("tree");
            let map = PhotonMap::new(tree, 50, max_radius, Kernel::Box);
            let mut sum = 0.0f64;
            let mut queries = Rng::new(5, 9);
            for _ in 0..200 {
                let (a, b) = queries.next_2d();
                let p = Vec3::new(side * 0.5 * (a - 0.5), side * 0.5 * (b - 0.5), 0.0);
                let e = map.irradiance(p, Vec3::Z, Walls::every_surface(&Geometry::default()));
                assert!(!e.cut && e.radius < 1e-4, "{e:?}");
                sum += f64::from(e.radiance.x / lambda);
            }
            let ratio = sum / 200.0;
            assert!(
                (ratio - 1.0).abs() < 0.03,
                "max radius {max_radius}: {ratio}"
            );
        }
    }

    #[test]
    fn an_empty_neighbourhood_reads_zero() {
        let map = flat_map(1000, 20, Kernel::Box, 1);
        let e = map.estimate(
            Vec3::new(50.0, 0.0, 0.0),
            Vec3::Z,
            &up_frame(),
            &white_lambert(),
            Walls::every_surface(&Geometry::default()),
        );
        assert_eq!(e.radiance, Vec3::ZERO);
        assert!(e.cut);
    }
}

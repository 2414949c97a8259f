//! World-space primitives in BVH leaf order, with closest-hit, any-hit and surface queries.

use glam::{DAffine3, DMat3, DVec3, Vec2, Vec3};

use crate::accel::bvh::{LEAF_BLOCK, PAD};
use crate::accel::{Bvh, RayBoxTest};
use crate::geometry::quadric::QuadricShape;
use crate::geometry::sphere::{intersect_sphere, intersect_unit_quadric};
use crate::geometry::triangle::{
    TriPack4, TriRay, intersect_pack_k, intersect_pack8_k, intersect_triangle_k,
};
use crate::geometry::{Aabb, Ray};

/// A primitive reference: kind in the top two bits, index into that kind's array below.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PrimRef(u32);

/// The kinds of primitive.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PrimKind {
    /// A triangle (meshes, quads and cubes).
    Triangle,
    /// A sphere under a similarity transform.
    Sphere,
    /// A sphere under a general affine transform.
    Ellipsoid,
    /// A disc or an open cylinder under an affine transform ([`QuadricPrim`]).
    Quadric,
}

impl PrimRef {
    const SHIFT: u32 = 30;
    const MASK: u32 = (1 << Self::SHIFT) - 1;

    /// A reference to primitive `index` of `kind`.
    #[must_use]
    pub fn new(kind: PrimKind, index: usize) -> Self {
        let k = match kind {
            PrimKind::Triangle => 0,
            PrimKind::Sphere => 1,
            PrimKind::Ellipsoid => 2,
            PrimKind::Quadric => 3,
        };
        Self((k << Self::SHIFT) | (index as u32 & Self::MASK))
    }

    /// The primitive's kind.
    #[inline]
    #[must_use]
    pub fn kind(self) -> PrimKind {
        match self.0 >> Self::SHIFT {
            0 => PrimKind::Triangle,
            1 => PrimKind::Sphere,
            2 => PrimKind::Ellipsoid,
            _ => PrimKind::Quadric,
        }
    }

    /// Index within the kind's array.
    #[inline]
    #[must_use]
    pub fn index(self) -> usize {
        (self.0 & Self::MASK) as usize
    }
}

/// Largest number of primitives of one kind a scene may hold.
pub const MAX_PRIMS_PER_KIND: usize = PrimRef::MASK as usize;

/// Per-triangle attributes besides its positions.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TriAttrs {
    /// Owning object.
    pub object: u32,
    /// Vertex normals (world space, unit), or `None` for flat shading.
    pub normals: Option<[Vec3; 3]>,
    /// Texture coordinates at the three vertices.
    pub uvs: [Vec2; 3],
}

/// A sphere in world space.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpherePrim {
    /// Centre.
    pub center: Vec3,
    /// Radius.
    pub radius: f32,
    /// Owning object.
    pub object: u32,
}

/// A unit sphere at the origin of its object space, mapped to world space by an affine transform.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipsoidPrim {
    /// Object-from-world transform (f64 for accuracy).
    pub object_from_world: DAffine3,
    /// World-from-object transform.
    pub world_from_object: DAffine3,
    /// Inverse transpose of the linear part, for normals.
    pub normal_to_world: DMat3,
    /// Owning object.
    pub object: u32,
}

/// A unit disc or open cylinder ([`QuadricShape`]) in its object space, mapped to the world by
/// an affine transform (the node's radius and height are part of it).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct QuadricPrim {
    /// Which surface.
    pub shape: QuadricShape,
    /// Object-from-world transform (f64 for accuracy).
    pub object_from_world: DAffine3,
    /// World-from-object transform.
    pub world_from_object: DAffine3,
    /// Inverse transpose of the linear part, for normals.
    pub normal_to_world: DMat3,
    /// Owning object.
    pub object: u32,
}

/// Whether leaves test two triangle packs at a time ([`intersect_pack8_k`]): where AVX is
/// enabled at build time, so that eight lanes are one register.
const PACK_PAIRS: bool = cfg!(all(target_arch = "x86_64", target_feature = "avx"));

/// The minimal record of a closest hit; expand it with [`Geometry::surface`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hit {
    /// Ray parameter.
    pub t: f32,
    /// Primitive hit.
    pub prim: PrimRef,
    /// Barycentric weight of the second vertex (triangles).
    pub b1: f32,
    /// Barycentric weight of the third vertex (triangles).
    pub b2: f32,
}

/// Primitives collected by the compiler before the BVH exists.
#[derive(Debug, Default)]
pub struct GeometryBuilder {
    /// Triangle positions.
    pub triangles: Vec<[Vec3; 3]>,
    /// Triangle attributes, parallel to `triangles`.
    pub tri_attrs: Vec<TriAttrs>,
    /// Spheres.
    pub spheres: Vec<SpherePrim>,
    /// Ellipsoids.
    pub ellipsoids: Vec<EllipsoidPrim>,
    /// Discs and cylinders.
    pub quadrics: Vec<QuadricPrim>,
}

/// The scene's primitives, stored in BVH leaf order, and their BVH.
#[derive(Debug, Default)]
pub struct Geometry {
    /// The hierarchy; leaf slots index `slots`.
    pub bvh: Bvh,
    /// Primitive at each leaf slot. A padding slot (see [`crate::accel::bvh::PAD`]) repeats the
    /// slot before it and is never visited.
    pub slots: Vec<PrimRef>,
    /// The triangles of slots `4p .. 4p + 4` in SIMD layout, at index `p`; lanes of other
    /// primitives and of padding slots are empty.
    pub tri_packs: Vec<TriPack4>,
    /// True if some slot holds a sphere or an ellipsoid: leaves are then checked for them.
    pub has_quadrics: bool,
    /// Per pack of [`LEAF_BLOCK`] slots (as `tri_packs`): whether one of them is a sphere or an
    /// ellipsoid, so a leaf (which starts on a pack) is checked for them in one or two loads
    /// instead of a pass over its slots.
    pub quadric_packs: Vec<bool>,
    /// Triangle positions, in leaf order.
    pub triangles: Vec<[Vec3; 3]>,
    /// Triangle attributes, parallel to `triangles`.
    pub tri_attrs: Vec<TriAttrs>,
    /// Spheres.
    pub spheres: Vec<SpherePrim>,
    /// Ellipsoids.
    pub ellipsoids: Vec<EllipsoidPrim>,
    /// Discs and cylinders.
    pub quadrics: Vec<QuadricPrim>,
}

impl GeometryBuilder {
    /// Number of primitives collected.
    #[must_use]
    pub fn len(&self) -> usize {
        self.triangles.len() + self.spheres.len() + self.ellipsoids.len() + self.quadrics.len()
    }

    /// True if nothing was collected.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Builds the BVH and stores every primitive in leaf order.
    #[must_use]
    pub fn build(self) -> Geometry {
        let mut refs = Vec::with_capacity(self.len());
        let mut bounds = Vec::with_capacity(self.len());
        for (i, t) in self.triangles.iter().enumerate() {
            refs.push(PrimRef::new(PrimKind::Triangle, i));
            bounds.push(Aabb::from_points(t));
        }
        for (i, s) in self.spheres.iter().enumerate() {
            refs.push(PrimRef::new(PrimKind::Sphere, i));
            bounds.push(Aabb {
                min: s.center - Vec3::splat(s.radius),
                max: s.center + Vec3::splat(s.radius),
            });
        }
        for (i, e) in self.ellipsoids.iter().enumerate() {
            refs.push(PrimRef::new(PrimKind::Ellipsoid, i));
            bounds.push(ellipsoid_bounds(&e.world_from_object));
        }
        for (i, q) in self.quadrics.iter().enumerate() {
            refs.push(PrimRef::new(PrimKind::Quadric, i));
            bounds.push(quadric_bounds(q));
        }
        // Spheres and ellipsoids are tested one at a time, triangles in packs.
        let solo: Vec<bool> = refs
            .iter()
            .map(|r| r.kind() != PrimKind::Triangle)
            .collect();
        let bvh = Bvh::build_with_solo(&bounds, &solo);
        let mut g = Geometry {
            slots: Vec::with_capacity(refs.len()),
            triangles: Vec::with_capacity(self.triangles.len()),
            tri_attrs: Vec::with_capacity(self.triangles.len()),
            spheres: Vec::with_capacity(self.spheres.len()),
            ellipsoids: Vec::with_capacity(self.ellipsoids.len()),
            quadrics: Vec::with_capacity(self.quadrics.len()),
            tri_packs: vec![TriPack4::EMPTY; bvh.order.len() / LEAF_BLOCK],
            has_quadrics: !self.spheres.is_empty()
                || !self.ellipsoids.is_empty()
                || !self.quadrics.is_empty(),
            quadric_packs: vec![false; bvh.order.len() / LEAF_BLOCK],
            bvh: Bvh::default(),
        };
        for (slot, &o) in bvh.order.iter().enumerate() {
            if o == PAD {
                let last = g.slots.last().copied().unwrap_or(PrimRef(0));
                g.slots.push(last);
                continue;
            }
            let r = refs[o as usize];
            let new = match r.kind() {
                PrimKind::Triangle => {
                    let [p0, p1, p2] = self.triangles[r.index()];
                    g.tri_packs[slot / LEAF_BLOCK].set(slot % LEAF_BLOCK, p0, p1, p2);
                    g.triangles.push(self.triangles[r.index()]);
                    g.tri_attrs.push(self.tri_attrs[r.index()]);
                    PrimRef::new(PrimKind::Triangle, g.triangles.len() - 1)
                }
                PrimKind::Sphere => {
                    g.spheres.push(self.spheres[r.index()]);
                    PrimRef::new(PrimKind::Sphere, g.spheres.len() - 1)
                }
                PrimKind::Ellipsoid => {
                    g.ellipsoids.push(self.ellipsoids[r.index()]);
                    PrimRef::new(PrimKind::Ellipsoid, g.ellipsoids.len() - 1)
                }
                PrimKind::Quadric => {
                    g.quadrics.push(self.quadrics[r.index()]);
                    PrimRef::new(PrimKind::Quadric, g.quadrics.len() - 1)
                }
            };
            g.quadric_packs[slot / LEAF_BLOCK] |= new.kind() != PrimKind::Triangle;
            g.slots.push(new);
        }
        g.bvh = bvh;
        g
    }
}

/// Tight bounds of the image of the unit sphere under `m`: centre ± the row norms of the linear part.
fn ellipsoid_bounds(m: &DAffine3) -> Aabb {
    let l = m.matrix3;
    let half = DVec3::new(l.row(0).length(), l.row(1).length(), l.row(2).length());
    let c = m.translation;
    // Round outward so the f32 box contains the f64 surface.
    let lo = (c - half)
        .as_vec3()
        .to_array()
        .map(crate::geometry::float::next_down);
    let hi = (c + half)
        .as_vec3()
        .to_array()
        .map(crate::geometry::float::next_up);
    Aabb {
        min: lo.into(),
        max: hi.into(),
    }
}

impl QuadricPrim {
    /// World bounds (see [`quadric_bounds`]).
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        quadric_bounds(self)
    }

    /// Surface area (m²), [`QuadricShape::area`].
    #[must_use]
    pub fn area(&self) -> f64 {
        self.shape.area(self.world_from_object.matrix3)
    }
}

/// Bounds of a disc or cylinder: its object-space box's corners mapped to the world, rounded
/// outwards so the f32 box contains the f64 surface.
fn quadric_bounds(q: &QuadricPrim) -> Aabb {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for c in q.shape.corners() {
        let p = q.world_from_object.transform_point3(c);
        lo = lo.min(p);
        hi = hi.max(p);
    }
    let lo = lo
        .as_vec3()
        .to_array()
        .map(crate::geometry::float::next_down);
    let hi = hi.as_vec3().to_array().map(crate::geometry::float::next_up);
    Aabb {
        min: lo.into(),
        max: hi.into(),
    }
}

impl Geometry {
    /// The closest hit along `ray` within `(0, ray.t_max)`. Invalid rays (NaN/Inf) miss.
    #[inline]
    #[must_use]
    pub fn intersect(&self, ray: &Ray) -> Option<Hit> {
        if !ray.is_valid() {
            return None;
        }
        let tri_ray = TriRay::new(ray);
        let box_ray = RayBoxTest::new(ray.origin, ray.dir);
        let mut best = None;
        self.bvh
            .closest(&box_ray, ray.t_max, |first, count, t_max| {
                match tri_ray.dominant_axis() {
                    0 => self.leaf_closest::<0>(first, count, &tri_ray, ray, t_max, &mut best),
                    1 => self.leaf_closest::<1>(first, count, &tri_ray, ray, t_max, &mut best),
                    _ => self.leaf_closest::<2>(first, count, &tri_ray, ray, t_max, &mut best),
                }
            });
        best
    }

    /// Closest hit among slots `first .. first + count` below `t_max`, written to `best`;
    /// returns its distance. Triangles are tested four at a time and taken in slot order, so the
    /// result is that of testing the slots one by one.
    #[inline(always)]
    fn leaf_closest<const KZ: usize>(
        &self,
        first: u32,
        count: u32,
        tri_ray: &TriRay,
        ray: &Ray,
        mut t_max: f32,
        best: &mut Option<Hit>,
    ) -> Option<f32> {
        let (first, end) = (first as usize, (first + count) as usize);
        let mut found = None;
        if self.leaf_has_quadrics(first, end) {
            for slot in first..end {
                let prim = self.slots[slot];
                if let Some((t, b1, b2)) = self.intersect_prim::<KZ>(prim, tri_ray, ray, t_max) {
                    *best = Some(Hit { t, prim, b1, b2 });
                    t_max = t;
                    found = Some(t);
                }
            }
            return found;
        }
        let mut packs = first / LEAF_BLOCK..end.div_ceil(LEAF_BLOCK);
        // With AVX, two packs (eight triangles) per test while two remain.
        while PACK_PAIRS && packs.len() >= 2 {
            let pack = packs.start;
            packs.start += 2;
            let (a, b) = (&self.tri_packs[pack], &self.tri_packs[pack + 1]);
            let Some(h) = intersect_pack8_k::<KZ>(tri_ray, a, b, t_max) else {
                continue;
            };
            let mut mask = h.mask;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if found.is_some() && !h.within(lane, t_max) {
                    continue;
                }
                let t = h.t(lane);
                let (b1, b2) = h.b12(lane);
                *best = Some(Hit {
                    t,
                    prim: self.slots[pack * LEAF_BLOCK + lane],
                    b1,
                    b2,
                });
                t_max = t;
                found = Some(t);
            }
        }
        for pack in packs {
            let Some(h) = intersect_pack_k::<KZ>(tri_ray, &self.tri_packs[pack], t_max) else {
                continue;
            };
            let mut mask = h.mask;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if found.is_some() && !h.within(lane, t_max) {
                    continue;
                }
                let t = h.t[lane];
                *best = Some(Hit {
                    t,
                    prim: self.slots[pack * LEAF_BLOCK + lane],
                    b1: h.b1[lane],
                    b2: h.b2[lane],
                });
                t_max = t;
                found = Some(t);
            }
        }
        found
    }

    /// True if anything blocks `ray` within `(0, ray.t_max)`.
    #[inline]
    #[must_use]
    pub fn occluded(&self, ray: &Ray) -> bool {
        self.occluded_by(ray, |_| true)
    }

    /// True if some primitive for which `counts` is true blocks `ray` within
    /// `(0, ray.t_max)`; hits on the others are ignored (e.g. shadow rays looking only for
    /// opaque blockers).
    #[inline]
    #[must_use]
    pub fn occluded_by(&self, ray: &Ray, counts: impl Fn(PrimRef) -> bool) -> bool {
        if !ray.is_valid() {
            return false;
        }
        let tri_ray = TriRay::new(ray);
        let box_ray = RayBoxTest::new(ray.origin, ray.dir);
        self.bvh.any(&box_ray, ray.t_max, |first, count, t_max| {
            match tri_ray.dominant_axis() {
                0 => self.leaf_any::<0>(first, count, &tri_ray, ray, t_max, &counts),
                1 => self.leaf_any::<1>(first, count, &tri_ray, ray, t_max, &counts),
                _ => self.leaf_any::<2>(first, count, &tri_ray, ray, t_max, &counts),
            }
        })
    }

    /// True if a primitive in slots `first .. first + count` for which `counts` holds blocks
    /// the ray before `t_max`.
    #[inline(always)]
    fn leaf_any<const KZ: usize>(
        &self,
        first: u32,
        count: u32,
        tri_ray: &TriRay,
        ray: &Ray,
        t_max: f32,
        counts: impl Fn(PrimRef) -> bool,
    ) -> bool {
        let (first, end) = (first as usize, (first + count) as usize);
        if self.leaf_has_quadrics(first, end) {
            return self.slots[first..end].iter().any(|&prim| {
                counts(prim)
                    && self
                        .intersect_prim::<KZ>(prim, tri_ray, ray, t_max)
                        .is_some()
            });
        }
        let mut packs = first / LEAF_BLOCK..end.div_ceil(LEAF_BLOCK);
        while PACK_PAIRS && packs.len() >= 2 {
            let pack = packs.start;
            packs.start += 2;
            let (a, b) = (&self.tri_packs[pack], &self.tri_packs[pack + 1]);
            let Some(h) = intersect_pack8_k::<KZ>(tri_ray, a, b, t_max) else {
                continue;
            };
            let mut mask = h.mask;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if counts(self.slots[pack * LEAF_BLOCK + lane]) {
                    return true;
                }
            }
        }
        packs.any(|pack| {
            let Some(h) = intersect_pack_k::<KZ>(tri_ray, &self.tri_packs[pack], t_max) else {
                return false;
            };
            let mut mask = h.mask;
            while mask != 0 {
                let lane = mask.trailing_zeros() as usize;
                mask &= mask - 1;
                if counts(self.slots[pack * LEAF_BLOCK + lane]) {
                    return true;
                }
            }
            false
        })
    }

    /// True if a sphere or ellipsoid is among slots `first .. end` (a leaf, starting on a pack).
    #[inline(always)]
    fn leaf_has_quadrics(&self, first: usize, end: usize) -> bool {
        self.has_quadrics
            && self.quadric_packs[first / LEAF_BLOCK..end.div_ceil(LEAF_BLOCK)]
                .iter()
                .any(|&q| q)
    }

    #[inline(always)]
    fn intersect_prim<const KZ: usize>(
        &self,
        prim: PrimRef,
        tri_ray: &TriRay,
        ray: &Ray,
        t_max: f32,
    ) -> Option<(f32, f32, f32)> {
        match prim.kind() {
            PrimKind::Triangle => {
                let [p0, p1, p2] = self.triangles[prim.index()];
                intersect_triangle_k::<KZ>(tri_ray, p0, p1, p2, t_max).map(|h| (h.t, h.b1, h.b2))
            }
            PrimKind::Sphere => {
                let s = &self.spheres[prim.index()];
                let r = Ray { t_max, ..*ray };
                intersect_sphere(s.center, s.radius, &r).map(|t| (t, 0.0, 0.0))
            }
            PrimKind::Ellipsoid => {
                let e = &self.ellipsoids[prim.index()];
                let o = e.object_from_world.transform_point3(ray.origin.as_dvec3());
                let d = e.object_from_world.transform_vector3(ray.dir.as_dvec3());
                intersect_unit_quadric(o, d, 1.0, t_max).map(|t| (t, 0.0, 0.0))
            }
            PrimKind::Quadric => self.intersect_quadric(prim, ray, t_max),
        }
    }

    /// A disc or cylinder against `ray` up to `t_max`: out of line, so that the leaf loops of
    /// scenes without them stay as small as before the kind existed.
    #[inline(never)]
    fn intersect_quadric(&self, prim: PrimRef, ray: &Ray, t_max: f32) -> Option<(f32, f32, f32)> {
        let q = &self.quadrics[prim.index()];
        let o = q.object_from_world.transform_point3(ray.origin.as_dvec3());
        let d = q.object_from_world.transform_vector3(ray.dir.as_dvec3());
        q.shape.intersect(o, d, t_max).map(|t| (t, 0.0, 0.0))
    }

    /// The object a primitive belongs to.
    #[inline]
    #[must_use]
    pub fn object_of(&self, prim: PrimRef) -> u32 {
        match prim.kind() {
            PrimKind::Triangle => self.tri_attrs[prim.index()].object,
            PrimKind::Sphere => self.spheres[prim.index()].object,
            PrimKind::Ellipsoid => self.ellipsoids[prim.index()].object,
            PrimKind::Quadric => self.quadrics[prim.index()].object,
        }
    }
}

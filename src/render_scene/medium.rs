//! The volume a path segment travels through: which objects' insides it is in, and so which
//! medium attenuates or scatters its light and which indices of refraction meet at the next
//! surface (docs/media.md).
//!
//! **Scenes without media, priorities or interfaces** (every scene before media existed) keep
//! the one-level rule, bit for bit: a path starts outside every object; the medium changes only
//! where the path scatters at a surface whose material has an `absorption`: a direction into
//! the object (against its geometric normal) enters that material's Beer–Lambert medium, a
//! direction out of it leaves to the outside; any other surface keeps the medium (a ray in the
//! bath's water that reflects off the tub's floor is still in the water, so an open water quad
//! works). Segments in a medium keep `exp(−σ t)` of their light; a segment that escapes the
//! scene inside an absorbing medium keeps nothing.
//!
//! **Volumetric scenes** (some material states a `medium`, a `priority` or `interface`, or the
//! scene a `medium`, [`RenderScene::volumetric`]) carry a stack of the volumes the path is in:
//! the materials (at most [`MAX_VOLUMES`]) whose closed surfaces it entered and has not left,
//! oldest first. A material encloses a volume when it transmits, absorbs, has a medium, a
//! priority or is an interface ([`Interior::encloses`]). Crossing such a surface inwards pushes
//! it, outwards removes it; other surfaces change nothing. The volume that holds at a point is
//! the one of highest priority (materials without one rank 0), the most recently entered among
//! equals (Schmidt & Budge 2002, "Simple Nested Dielectrics in Ray Traced Images"). Its
//! material's absorption or medium attenuates the segment; with no volume, the scene's
//! `medium` (fog) does. Where a material with a priority is hit while a volume of higher
//! priority holds, the surface is not there (a "false" hit: the water's side inside the glass
//! wall) and the path goes straight on; interfaces are always crossed that way. At a true
//! surface of a material with a priority, its dielectric refracts with its index over the index
//! of the volume on the other side (the highest-priority volume with an index among those the
//! path is in, itself excluded; 1 for air): water inside a glass refracts 1.33/1.5.
//!
//! Inconsistent nesting follows documented rules instead of failing: leaving a volume that is
//! not on the stack (a path that started inside, an open surface) changes nothing; entering one
//! that is already on it changes nothing; entering a ninth drops the oldest.

use glam::Vec3;

use super::participating::HomogeneousMedium;
use super::{Interaction, RenderScene, SurfaceHit};
use crate::geometry::Ray;
use crate::geometry::offset::offset_ray_origin;
use crate::shading::Bsdf;
use crate::shading::absorption::Absorption;

/// Most volumes a path can be inside at once (deeper nesting drops the oldest).
pub const MAX_VOLUMES: usize = 8;

/// Most materials a volumetric scene may have: the volume stack stores material indices in 16
/// bits.
pub const MAX_VOLUMETRIC_MATERIALS: usize = 1 << 16;

/// No participating medium (an index into `RenderScene::media` otherwise).
const NONE: u32 = u32::MAX;

/// Where a shadow ray continued past a skipped surface ends, as a fraction of the way to its
/// target (the integrators' shadow rays stop as far short of the light).
const SHADOW_END: f32 = 1.0 - 1e-4;

/// What a material's closed surfaces enclose, as compiled from its `medium`, `priority` and
/// `interface` (and its dielectric part and absorption).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Interior {
    /// Paths enter and leave a volume at this material's surfaces (it transmits, absorbs, has
    /// a medium, a priority, or is an interface).
    pub encloses: bool,
    /// Its rank among overlapping volumes; `None` keeps it out of priority nesting (its
    /// surfaces are always true and refract against air), ranked 0 for the medium choice.
    pub priority: Option<i32>,
    /// The participating medium inside (`RenderScene::media` index).
    pub medium: Option<u32>,
    /// The surface is not there: only the boundary of its medium.
    pub interface: bool,
    /// The index of refraction of its dielectric part relative to air (`None`: it has none, as
    /// an interface or an absorbing-only material).
    pub ior: Option<f32>,
}

impl Interior {
    /// A material that encloses nothing.
    pub const NONE: Self = Self {
        encloses: false,
        priority: None,
        medium: None,
        interface: false,
        ior: None,
    };

    /// The rank used to choose the volume that holds (0 without a priority).
    #[inline]
    fn rank(&self) -> i32 {
        self.priority.unwrap_or(0)
    }
}

/// The medium a path is in: in a volumetric scene the stack of volumes entered (module docs),
/// and the absorption or participating medium that holds now (clear outside).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Medium {
    absorption: Absorption,
    /// The participating medium that holds ([`NONE`]: none).
    participating: u32,
    len: u8,
    /// Material indices of the volumes entered, oldest first (`len` of them). 16 bits, so that
    /// the medium every path vertex carries stays small (a volumetric scene has at most
    /// [`MAX_VOLUMETRIC_MATERIALS`] materials: compilation says so).
    volumes: [u16; MAX_VOLUMES],
}

impl Medium {
    /// Outside every object in a scene without a scene-wide medium: nothing is absorbed.
    pub const OUTSIDE: Self = Self {
        absorption: Absorption::CLEAR,
        participating: NONE,
        len: 0,
        volumes: [0; MAX_VOLUMES],
    };

    /// Where cameras and lights are: outside every object, in the scene's `medium` if it has
    /// one.
    #[inline]
    #[must_use]
    pub fn outside(scene: &RenderScene) -> Self {
        Self {
            participating: scene.camera_medium.unwrap_or(NONE),
            ..Self::OUTSIDE
        }
    }

    /// True when the segment neither absorbs nor scatters.
    #[inline]
    #[must_use]
    pub fn is_clear(&self) -> bool {
        self.absorption.is_clear() && self.participating == NONE
    }

    /// The participating medium that holds, if any (an absorbing-only `absorption` is not one:
    /// [`Medium::transmittance`] accounts for it).
    #[inline]
    #[must_use]
    pub fn participating<'s>(&self, scene: &'s RenderScene) -> Option<&'s HomogeneousMedium> {
        if self.participating == NONE {
            None
        } else {
            scene.media.get(self.participating as usize)
        }
    }

    /// The index in `RenderScene::media` of the participating medium that holds, if any (what
    /// tells a volume photon's medium from another's on either side of a boundary).
    #[inline]
    #[must_use]
    pub fn participating_index(&self) -> Option<u32> {
        (self.participating != NONE).then_some(self.participating)
    }

    /// The fraction of light (per channel) kept along the segment `ray` travelled to reach
    /// `interaction` (its length is the hit distance times `|ray.dir|`; an escaped ray
    /// travelled infinitely far): the Beer–Lambert `absorption` only. Exactly 1 in a clear
    /// medium, so paths that never enter an absorbing medium are unchanged bit for bit. A
    /// participating medium is the caller's to sample or attenuate by
    /// ([`Medium::participating`]).
    #[inline]
    #[must_use]
    pub fn transmittance(&self, ray: &Ray, interaction: &Interaction) -> Vec3 {
        if self.is_clear() {
            return Vec3::ONE;
        }
        let t = match interaction {
            Interaction::Escaped => f32::INFINITY,
            Interaction::Emitter(e) => e.hit.t,
            Interaction::Surface(s) => s.hit.t,
        };
        self.transmittance_in(t * ray.dir.length())
    }

    /// The fraction of light (per channel) kept over `distance` metres by the absorption of
    /// this medium (a shadow ray's segment, which ends at a point rather than a hit). Exactly 1
    /// in a clear medium.
    #[inline]
    #[must_use]
    pub fn transmittance_over(&self, distance: f32) -> Vec3 {
        if self.is_clear() {
            return Vec3::ONE;
        }
        self.transmittance_in(distance)
    }

    #[inline]
    fn transmittance_in(&self, distance: f32) -> Vec3 {
        self.absorption.transmittance(distance)
    }

    /// [`Medium::transmittance_over`] including the participating medium's extinction.
    #[inline]
    #[must_use]
    pub fn transmittance_in_scene(&self, scene: &RenderScene, distance: f32) -> Vec3 {
        match self.participating(scene) {
            Some(m) => m.transmittance(distance),
            None => self.absorption.transmittance(distance),
        }
    }

    /// The medium after the path scatters at `v` into the direction `wi`. In a scene that is
    /// not volumetric: the material's absorption when `wi` goes into an object whose material
    /// absorbs, outside when it leaves such an object, unchanged at every other surface. In a
    /// volumetric scene: the volume stack crossed at `v` (module docs).
    #[inline]
    #[must_use]
    pub fn after(self, scene: &RenderScene, v: &SurfaceHit, wi: Vec3) -> Self {
        if scene.volumetric {
            self.after_in::<true>(scene, v, wi)
        } else {
            self.after_in::<false>(scene, v, wi)
        }
    }

    /// [`Medium::after`] where the scene's [`RenderScene::volumetric`] is known when compiling
    /// (`VOLUMETRIC`): the path tracer's loop, one copy per kind of scene, so that scenes
    /// without media test for it nowhere.
    #[inline(always)]
    #[must_use]
    pub fn after_in<const VOLUMETRIC: bool>(
        self,
        scene: &RenderScene,
        v: &SurfaceHit,
        wi: Vec3,
    ) -> Self {
        debug_assert_eq!(VOLUMETRIC, scene.volumetric);
        // `v.sp.ng` is the object's outward geometric normal.
        if VOLUMETRIC {
            return self.crossed(scene, v.material, wi.dot(v.sp.ng) < 0.0);
        }
        let absorption = scene.materials[v.material as usize].absorption;
        if absorption.is_clear() {
            self
        } else if wi.dot(v.sp.ng) < 0.0 {
            Self {
                absorption,
                ..Self::OUTSIDE
            }
        } else {
            Self::OUTSIDE
        }
    }

    /// The stack after crossing a surface of `material` inwards (`entering`) or outwards. Out of
    /// line: only volumetric scenes call it, and inlined it made every path loop larger.
    #[inline(never)]
    #[must_use]
    pub fn crossed(mut self, scene: &RenderScene, material: u32, entering: bool) -> Self {
        let interior = &scene.materials[material as usize].interior;
        if !interior.encloses {
            return self;
        }
        // Validation keeps a volumetric scene's material indices within 16 bits; a larger one
        // (unreachable) is no volume rather than a wrong one.
        let Ok(material) = u16::try_from(material) else {
            return self;
        };
        let len = self.len as usize;
        let at = self.volumes[..len].iter().rposition(|&m| m == material);
        match (entering, at) {
            (true, Some(_)) | (false, None) => return self,
            (true, None) => {
                if len == MAX_VOLUMES {
                    self.volumes.copy_within(1.., 0);
                    self.volumes[MAX_VOLUMES - 1] = material;
                } else {
                    self.volumes[len] = material;
                    self.len += 1;
                }
            }
            (false, Some(i)) => {
                self.volumes.copy_within(i + 1..len, i);
                self.len -= 1;
            }
        }
        self.settle(scene);
        self
    }

    /// Recomputes what holds from the stack: the highest priority, newest among equals.
    fn settle(&mut self, scene: &RenderScene) {
        let top = self.top(scene, |_| true);
        match top {
            None => {
                self.absorption = Absorption::CLEAR;
                self.participating = scene.camera_medium.unwrap_or(NONE);
            }
            Some(m) => {
                let mat = &scene.materials[m as usize];
                self.absorption = mat.absorption;
                self.participating = mat.interior.medium.unwrap_or(NONE);
            }
        }
    }

    /// The volume of highest priority (newest among equals) among those `keep` accepts.
    fn top(&self, scene: &RenderScene, keep: impl Fn(u32) -> bool) -> Option<u32> {
        let mut best: Option<(i32, u32)> = None;
        for m in self.volumes[..self.len as usize]
            .iter()
            .rev()
            .map(|&m| u32::from(m))
        {
            if !keep(m) {
                continue;
            }
            let rank = scene.materials[m as usize].interior.rank();
            if best.is_none_or(|(r, _)| rank > r) {
                best = Some((rank, m));
            }
        }
        best.map(|(_, m)| m)
    }

    /// True when a hit on `material` is not a surface for this path: an interface, or a
    /// material with a priority while a volume of higher priority holds (module docs). The
    /// path then goes straight on, [`Medium::crossed`] there.
    #[inline]
    #[must_use]
    pub fn skips(&self, scene: &RenderScene, material: u32) -> bool {
        let interior = &scene.materials[material as usize].interior;
        if interior.interface {
            return true;
        }
        let Some(p) = interior.priority else {
            return false;
        };
        self.volumes[..self.len as usize].iter().any(|&m| {
            u32::from(m) != material
                && scene.materials[m as usize]
                    .interior
                    .priority
                    .is_some_and(|q| q > p)
        })
    }

    /// The relative index (inside over outside) the dielectric of `material` refracts with at a
    /// true surface, when it differs from the material's own: for a material with a priority
    /// and an index, its index over that of the highest-priority volume with an index the path
    /// is in besides it (module docs). `None` when the other side is air (index 1).
    #[inline]
    #[must_use]
    pub fn interface_ior(&self, scene: &RenderScene, material: u32) -> Option<f32> {
        let interior = &scene.materials[material as usize].interior;
        let (Some(_), Some(ior)) = (interior.priority, interior.ior) else {
            return None;
        };
        let other = self.top(scene, |m| {
            let i = &scene.materials[m as usize].interior;
            m != material && i.priority.is_some() && i.ior.is_some()
        })?;
        let outside = scene.materials[other as usize].interior.ior?;
        (outside != 1.0).then(|| ior / outside)
    }

    /// The fraction of light (per channel) that reaches the end of the shadow ray `ray` (from
    /// `ray.origin` to `ray.origin + ray.dir`, up to `ray.t_max`) starting in this medium:
    /// every surface on the way blocks it (0) except those the path skips (interfaces, false
    /// hits, [`Medium::skips`]), where it crosses into the next volume; each stretch keeps
    /// [`Medium::transmittance_in_scene`] of it. `light`: the object surfaces of this light
    /// (an area light's own emitter) end the ray instead of blocking it. For volumetric scenes.
    #[must_use]
    pub fn transmittance_through(
        self,
        scene: &RenderScene,
        ray: &Ray,
        light: Option<u32>,
        rays: &mut u64,
    ) -> Vec3 {
        let target = ray.origin + ray.dir;
        let mut medium = self;
        let mut r = *ray;
        let mut tr = Vec3::ONE;
        for _ in 0..64 {
            *rays += 1;
            let Some(hit) = scene.geometry.intersect(&r) else {
                return tr * medium.transmittance_in_scene(scene, r.t_max * r.dir.length());
            };
            tr *= medium.transmittance_in_scene(scene, hit.t * r.dir.length());
            let sp = scene.geometry.surface(&r, &hit);
            let object = &scene.objects[sp.object as usize];
            let Some(m) = object.material else {
                // An emitter: the light's own surface ends the ray, another blocks it.
                return if light.is_some() && object.light == light {
                    tr
                } else {
                    Vec3::ZERO
                };
            };
            if !medium.skips(scene, m) || tr.max_element() <= 0.0 {
                return Vec3::ZERO;
            }
            let entering = r.dir.dot(sp.ng) < 0.0;
            medium = medium.crossed(scene, m, entering);
            let origin = offset_ray_origin(sp.p, sp.p_error, sp.ng, r.dir);
            r = Ray {
                origin,
                dir: target - origin,
                t_max: SHADOW_END,
            };
        }
        Vec3::ZERO
    }

    /// The surface step every tracer takes in a volumetric scene at a hit `v` (camera paths
    /// and photons alike): `Some((ray, medium))` when the hit is not a surface for this path
    /// ([`Medium::skips`]: the ray going straight on and the medium beyond,
    /// [`Medium::pass_through`]); else `None`, with `v`'s dielectric given the index ratio of
    /// the volumes it separates when two touch ([`Medium::interface_ior`], the new BSDF kept in
    /// `nested`, which must outlive `v`).
    #[inline]
    pub fn surface_step<'s>(
        self,
        scene: &RenderScene,
        ray: &Ray,
        v: &mut SurfaceHit<'s>,
        nested: &'s mut Option<Bsdf>,
    ) -> Option<(Ray, Self)> {
        if self.skips(scene, v.material) {
            return Some(self.pass_through(scene, ray, v));
        }
        if let Some(eta) = self.interface_ior(scene, v.material) {
            v.bsdf = nested.insert(v.bsdf.with_ior(eta));
        }
        None
    }

    /// The ray that goes straight on through the skipped surface of `v` (an interface or a
    /// false hit, [`Medium::skips`]), and the medium beyond it.
    #[inline]
    #[must_use]
    pub fn pass_through(self, scene: &RenderScene, ray: &Ray, v: &SurfaceHit) -> (Ray, Self) {
        let dir = ray.dir;
        let medium = self.crossed(scene, v.material, dir.dot(v.sp.ng) < 0.0);
        let origin = offset_ray_origin(v.sp.p, v.sp.p_error, v.sp.ng, dir);
        let t_max = if ray.t_max.is_finite() {
            ray.t_max - v.hit.t
        } else {
            ray.t_max
        };
        (Ray { origin, dir, t_max }, medium)
    }
}

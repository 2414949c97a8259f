//! Scene materials (BSDF parameters plus optional colour and bump textures) and their
//! resolution at a hit into the exact BSDF and normals every integrator shades with.

use glam::{Vec2, Vec3};

use super::MIN_SPREAD_FRACTION;
use super::texture::Lookup;
use super::{RenderScene, SurfacePoint, TextureFilter};
use crate::geometry::Frame;
use crate::shading::absorption::Absorption;
use crate::shading::conductor::ConductorFresnel;
use crate::shading::microfacet::Ggx;
use crate::shading::{Bsdf, usable_shading_normal};
use crate::texture::Footprint;

/// Grazing cosines below this are treated as this when sizing footprints (caps the footprint's
/// elongation at 1000 : 1 instead of dividing by zero).
const MIN_FOOTPRINT_COS: f32 = 1e-3;

/// A material as compiled from the scene: the BSDF with constant parameters, the textures
/// that replace its colour and perturb its shading normal, and the absorption of the medium it
/// encloses. Its scene key is its `KeyHash` impl (`render_scene::hash`), which names every
/// field.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceMaterial {
    /// The BSDF; its `color` is used when `color_texture` is `None`.
    pub bsdf: Bsdf,
    /// Texture giving the colour, as an index into `RenderScene::textures`.
    pub color_texture: Option<u32>,
    /// Texture perturbing the shading normal, as an index into `RenderScene::textures`.
    pub bump: Option<u32>,
    /// Tangent-space normal map replacing the shading normal (never together with `bump`), as
    /// an index into `RenderScene::textures`.
    pub normal_map: Option<u32>,
    /// Texture giving the isotropic roughness r (mean channel, clamped to [0, 1]; GGX α = r²)
    /// of the mirror and dielectric parts at each hit, as an index into
    /// `RenderScene::textures`; `bsdf` is then the smooth BSDF it roughens.
    pub roughness_texture: Option<u32>,
    /// The metal Fresnel of the mirror part (kept to rebuild the rough lobes at each hit when
    /// the roughness is a texture).
    pub conductor: Option<ConductorFresnel>,
    /// Some texture of this material is an image, so lookups need the pixel's footprint.
    pub filtered: bool,
    /// Beer–Lambert absorption inside the object (the side its geometric normal points away
    /// from), applied along path segments inside it ([`super::Medium`]).
    pub absorption: Absorption,
    /// The volume its closed surfaces enclose in a volumetric scene: medium, priority,
    /// interface ([`super::Interior`]).
    pub interior: super::Interior,
}

/// The BSDF and frame at one hit, as seen from the outgoing direction `wo`, with its own copy
/// of the BSDF ([`RenderScene::shading_point`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingPoint {
    /// The BSDF with textures applied.
    pub bsdf: Bsdf,
    /// Unit geometric normal on the side of `wo`.
    pub ng: Vec3,
    /// Unit shading normal on the side of `wo`, bumped and made usable
    /// ([`usable_shading_normal`]).
    pub ns: Vec3,
    /// Whether `wo` is on the outside (the side the geometric normal points to).
    pub entering: bool,
}

/// [`ShadingPoint`] borrowing its BSDF ([`RenderScene::shade`]): the material's own where no
/// texture changes it, so a path vertex copies no BSDF, else the textured copy in the caller's
/// slot.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Shading<'s> {
    /// The BSDF with textures applied.
    pub bsdf: &'s Bsdf,
    /// Unit geometric normal on the side of `wo`.
    pub ng: Vec3,
    /// Unit shading normal on the side of `wo`, bumped and made usable.
    pub ns: Vec3,
    /// Whether `wo` is on the outside (the side the geometric normal points to).
    pub entering: bool,
}

impl RenderScene {
    /// [`RenderScene::shade`] with its own copy of the BSDF (for tests and tools; the
    /// integrators' vertex step, [`RenderScene::interact`], borrows it instead).
    #[must_use]
    pub fn shading_point(
        &self,
        material: &SurfaceMaterial,
        sp: &SurfacePoint,
        wo: Vec3,
        width: f32,
    ) -> ShadingPoint {
        let mut textured = None;
        let sh = self.shade(material, sp, wo, width, &mut textured);
        ShadingPoint {
            bsdf: *sh.bsdf,
            ng: sh.ng,
            ns: sh.ns,
            entering: sh.entering,
        }
    }

    /// Resolves `material` at surface point `sp` seen along unit `wo` (pointing away from the
    /// surface), where the pixel's footprint is `width` world units wide across the incoming
    /// ray (0: sharpest). This is the single place textures, bump mapping and the
    /// shading-normal rules are applied. Where a colour or roughness texture changes the BSDF,
    /// the textured BSDF is written to `textured` (the caller's storage) and borrowed from
    /// there; otherwise the material's own is borrowed and `textured` is left alone.
    #[inline(always)]
    #[must_use]
    pub fn shade<'s>(
        &self,
        material: &'s SurfaceMaterial,
        sp: &SurfacePoint,
        wo: Vec3,
        width: f32,
        textured: &'s mut Option<Bsdf>,
    ) -> Shading<'s> {
        let entering = wo.dot(sp.ng) > 0.0;
        let mut bsdf = &material.bsdf;
        let mut ns = sp.ns;
        if material.color_texture.is_some()
            || material.bump.is_some()
            || material.normal_map.is_some()
            || material.roughness_texture.is_some()
        {
            let sps = self.geometry.surface_params(sp);
            let footprint = match self.params.texture_filter {
                _ if !material.filtered => Footprint::POINT,
                TextureFilter::Anisotropic => uv_footprint(width, -wo, sp.ng, sps.dpdu, sps.dpdv),
                TextureFilter::Trilinear => Footprint::isotropic(
                    uv_footprint(width, -wo, sp.ng, sps.dpdu, sps.dpdv).width(),
                ),
                TextureFilter::Bilinear => Footprint::POINT,
            };
            let lookup = Lookup {
                p: sp.p,
                uv: sps.uv,
                footprint,
                width: if self.params.texture_filter == TextureFilter::Bilinear {
                    0.0
                } else {
                    width
                },
            };
            // A height source and a normal map are never both set (validated); either
            // perturbs the interpolated normal in the surface's tangent frame.
            if let Some(t) = material.bump.or(material.normal_map) {
                // Bumps are looked up at the footprint of the finest camera spread whatever the
                // sample count (see `bump_lookup`), so every sample count and integrator converges
                // to the same shading.
                let l = bump_lookup(&lookup, self.params.samples_per_pixel);
                ns = self.textures[t as usize].bump(ns, sps.dpdu, sps.dpdv, &l);
            }
            if material.color_texture.is_some() || material.roughness_texture.is_some() {
                let mut b = material.bsdf;
                if let Some(t) = material.color_texture {
                    b = b.with_color(self.textures[t as usize].color(&lookup));
                }
                if let Some(t) = material.roughness_texture {
                    let c = self.textures[t as usize].color(&lookup);
                    b = b.with_microfacets(textured_ggx(c), material.conductor);
                }
                bsdf = textured.insert(b);
            }
        }
        let (ng, ns) = if entering { (sp.ng, ns) } else { (-sp.ng, -ns) };
        Shading {
            bsdf,
            ng,
            ns: usable_shading_normal(ns, ng, wo),
            entering,
        }
    }
}

/// The lookup a bump or normal map uses at `l` (a lookup sized by the camera's spread at
/// `spp` samples per pixel, [`RenderScene::pixel_spread`]): its footprint scaled to that of
/// the finest spread (an eighth of a pixel, reached at 64 spp and above).
///
/// Filtering a colour is a local average, so a wider footprint at fewer samples leaves block
/// means alone; filtering a height field is not (the shading of an averaged normal is not the
/// average shading, Toksvig 2005), and a footprint that widens at low sample counts changed the
/// image a render converges to: `scenes/bump_map.ron`'s tiled wall read 20 % darker at 16 spp
/// than at 64 spp, in `path` and `path-ppm` alike. Bumps therefore always use one footprint.
#[inline]
fn bump_lookup(l: &Lookup, spp: u32) -> Lookup {
    let scale = ((spp.max(1) as f32).sqrt() * MIN_SPREAD_FRACTION).min(1.0);
    if scale >= 1.0 {
        return *l;
    }
    Lookup {
        footprint: l.footprint.scaled(scale),
        width: l.width * scale,
        ..*l
    }
}

/// The GGX distribution of a roughness texture's value `c`: r = its mean channel (a grey
/// texel's value exactly) clamped to [0, 1], α = r² as for constant roughness; `None`
/// (smooth) at 0 or for a NaN texel.
#[inline]
fn textured_ggx(c: Vec3) -> Option<Ggx> {
    let mean = if c.x == c.y && c.y == c.z {
        c.x
    } else {
        (c.x + c.y + c.z) / 3.0
    };
    let r = mean.clamp(0.0, 1.0);
    (r > 0.0).then(|| Ggx::isotropic(r * r))
}

/// The footprint in uv of a ray cone `width` wide arriving along `dir` at a surface with
/// normal `ng` and derivatives `dpdu`, `dpdv`. On the surface the footprint is an ellipse with
/// axes `width` across the ray and `width / |cos θ|` along it; both axes are mapped to uv (they
/// stay conjugate diameters), the longer becomes `major` and the width across it is the
/// parallelogram's area over `|major|`. [`Footprint::POINT`] when `width` is 0 or the
/// parameterisation is degenerate.
#[must_use]
pub fn uv_footprint(width: f32, dir: Vec3, ng: Vec3, dpdu: Vec3, dpdv: Vec3) -> Footprint {
    if !(width > 0.0) {
        return Footprint::POINT;
    }
    let d = dir.normalize_or_zero();
    let cos = d.dot(ng).abs().max(MIN_FOOTPRINT_COS);
    let along = d - ng * d.dot(ng);
    let (major, minor) = match along.try_normalize() {
        Some(a) => (a * (width / cos), ng.cross(a) * width),
        None => {
            let f = Frame::from_normal(ng);
            (f.s * width, f.t * width)
        }
    };
    // Least-squares uv of a tangent vector v: solve [dpdu dpdv]ᵀ[dpdu dpdv] x = [dpdu dpdv]ᵀ v.
    let (a, b, c) = (dpdu.dot(dpdu), dpdu.dot(dpdv), dpdv.dot(dpdv));
    let det = a * c - b * b;
    if !(det > 0.0) {
        return Footprint::POINT;
    }
    let to_uv = |v: Vec3| {
        let (x, y) = (v.dot(dpdu), v.dot(dpdv));
        Vec2::new(c * x - b * y, a * y - b * x) / det
    };
    let (m1, m2) = (to_uv(major), to_uv(minor));
    let (long, short) = if m1.length_squared() >= m2.length_squared() {
        (m1, m2)
    } else {
        (m2, m1)
    };
    let len = long.length();
    let f = Footprint {
        major: long,
        minor: if len > 0.0 {
            long.perp_dot(short).abs() / len
        } else {
            0.0
        },
    };
    if f.major.is_finite() && f.minor.is_finite() {
        f
    } else {
        Footprint::POINT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bumps_are_looked_up_at_the_finest_spread_at_every_sample_count() {
        // The camera's spread per sample is a pixel over √spp down to an eighth (64 spp): the
        // bump lookup at 16 spp (a quarter pixel) must be half as wide, at 1 spp an eighth, at
        // 64 and 1024 spp unchanged.
        let l = Lookup {
            p: Vec3::ZERO,
            uv: glam::Vec2::new(0.3, 0.7),
            footprint: Footprint {
                major: glam::Vec2::new(0.02, 0.01),
                minor: 0.004,
            },
            width: 0.05,
        };
        for (spp, scale) in [(1, 0.125), (16, 0.5), (64, 1.0), (1024, 1.0)] {
            let b = bump_lookup(&l, spp);
            assert!((b.width - l.width * scale).abs() < 1e-7, "{spp}");
            assert!(
                (b.footprint.minor - l.footprint.minor * scale).abs() < 1e-7,
                "{spp}"
            );
            assert!(
                (b.footprint.major - l.footprint.major * scale).length() < 1e-7,
                "{spp}"
            );
            assert_eq!(b.uv, l.uv);
        }
    }

    #[test]
    fn footprint_of_a_head_on_cone_is_its_width_over_the_uv_scale() {
        // A plane with 1 uv unit = 4 world units along both axes.
        let (du, dv) = (Vec3::X * 4.0, Vec3::Y * 4.0);
        let f = uv_footprint(0.02, -Vec3::Z, Vec3::Z, du, dv);
        assert!(
            (f.width() - 0.005).abs() < 1e-7 && (f.minor - 0.005).abs() < 1e-7,
            "{f:?}"
        );
        assert_eq!(
            uv_footprint(0.0, -Vec3::Z, Vec3::Z, du, dv),
            Footprint::POINT
        );
    }

    #[test]
    fn grazing_cones_stretch_along_the_ray_and_stay_finite() {
        let (du, dv) = (Vec3::X, Vec3::Y);
        // 60° from the normal, travelling along +x: the major axis 1/cos 60° = 2× longer, in u.
        let dir = Vec3::new(60f32.to_radians().sin(), 0.0, -60f32.to_radians().cos());
        let f = uv_footprint(0.01, dir, Vec3::Z, du, dv);
        assert!(
            (f.major.x.abs() - 0.02).abs() < 1e-6 && f.major.y.abs() < 1e-7,
            "{f:?}"
        );
        assert!((f.minor - 0.01).abs() < 1e-6, "{f:?}");
        // Exactly tangent: capped, finite.
        let f = uv_footprint(0.01, Vec3::X, Vec3::Z, du, dv);
        assert!(
            f.major.is_finite() && (f.width() - 10.0).abs() < 1e-3,
            "{f:?}"
        );
        // Skewed parameterisation (dpdv not orthogonal to dpdu): solved exactly.
        let f = uv_footprint(1.0, -Vec3::Z, Vec3::Z, Vec3::X, Vec3::new(1.0, 1.0, 0.0));
        assert!(f.width().is_finite() && f.width() > 0.99, "{f:?}");
    }
}

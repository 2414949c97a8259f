//! The material model as a BSDF (docs/material.md): a small weighted mixture of lobes. The
//! scene's `diffuse`, `reflect` and `transmit` weights (normalised to sum to 1) weigh three
//! parts — a diffuse part of a Lambert ([`super::lambert`]) and a normalised-Phong
//! ([`super::phong`]) lobe, a tinted perfect mirror ([`super::specular_reflection`]) and a
//! smooth Fresnel dielectric ([`super::dielectric`]). Every integrator evaluates, samples and
//! asks densities of it through here, in radiance mode (camera paths) or importance mode (light
//! and photon paths), so that all of them converge to the same image; they ask what it does
//! through [`Bsdf::flags`] and its methods, never through its parts.
//!
//! Sampling picks a part with the lobe number in proportion to its weight times its mean
//! albedo, then, inside the diffuse part, Lambert or Phong in proportion to their albedos (the
//! same number, rescaled); a delta lobe uses the rest of the number itself (the dielectric's
//! choice of reflection or refraction). Densities are those of the mixture. The arithmetic is
//! ordered as the renderer's first, monolithic BSDF computed it, so images stay bit-identical.
//!
//! A new lobe (a rough GGX conductor, say) is its own file plus a variant in [`super::lobe`]
//! and a part here: a non-delta lobe needs only `f`, `sample` and `pdf`.

use glam::Vec3;

use super::bxdf::LobeContext;
use super::coated::{CoatLayer, Coated, CoatedLobe};
use super::conductor::ConductorFresnel;
use super::dielectric::Dielectric;
use super::lambert::Lambert;
use super::lobe::Lobe;
use super::microfacet::Ggx;
use super::part::{Part, PartUse};
use super::phong::Phong;
use super::rough_conductor::RoughConductor;
use super::rough_dielectric::RoughDielectric;
pub use super::scattering::{
    BsdfSample, LobeFlags, ShadingFrame, TransportMode, shading_normal_correction,
};
use super::specular_conductor::SpecularConductor;
use super::specular_reflection::{SpecularReflection, mirror_above};

/// The widest GGX α (perceptual roughness 0.4) at which the progressive integrators
/// (`integrators::progressive_path`) treat a glossy surface with no diffuse part as specular
/// ([`Bsdf::is_near_specular`]): light it throws onto diffuse surfaces (a glossy caustic: the sun's highlight on brushed
/// chrome lighting a wall) comes from the caustic map, whose photons pass through it, instead
/// of from camera paths that meet the light's sharp highlight by chance (issue #27: the bath's
/// worst pixels). Below this width the highlight is sharp enough for that chance to be rare;
/// wider lobes are left to camera paths, which find their broad highlights easily.
pub const NEAR_SPECULAR_ALPHA: f32 = 0.16;

/// Parts of the mixture (each a weight and its lobes).
pub(super) const PARTS: usize = 3;
/// A compiled material's scattering function: a tint (the colour; texture lookups replace it)
/// and a weighted mixture of lobes. Evaluating and sampling it is in `bsdf_at.rs`
/// ([`Bsdf::eval`], [`Bsdf::sample`], [`Bsdf::at`]); its scene key is its [`KeyHash`] impl
/// (`Debug` is for messages only).
///
/// [`KeyHash`]: crate::binfile::KeyHash
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bsdf {
    /// Diffuse albedo; also tints the mirror and transmitted light.
    tint: Vec3,
    /// The diffuse, mirror and dielectric parts, in this order (the order sampling walks).
    parts: [Part; PARTS],
    /// What each part takes part in, derived from `parts` whenever they change
    /// ([`Bsdf::with_parts`]), so that per-vertex queries test flags instead of walking lobes.
    uses: [PartUse; PARTS],
    /// Only the diffuse part has weight and its only lobe with a value is Lambert (Phong, if
    /// present, is black): the common matte material, which [`super::BsdfAt`] evaluates, samples and
    /// asks densities of without walking the mixture. Derived with `uses`.
    lambert: bool,
    /// The union of the flags of the parts of non-zero weight ([`Bsdf::flags`]), derived with
    /// `uses` (per-vertex queries such as [`Bsdf::has_local`] read it instead of walking the
    /// lobes).
    flags: LobeFlags,
    /// [`Bsdf::lobe_choice_matters`], derived from the parts and the tint whenever either
    /// changes (asked at every path vertex).
    choice_matters: bool,
    /// [`Bsdf::is_diffuse_only`], derived likewise (asked at every final-gather landing).
    diffuse_only: bool,
    /// The widest GGX α of the microfacet lobes when every lobe of non-zero weight is a delta
    /// or a microfacet lobe and at least one is a microfacet lobe (`None` otherwise), derived
    /// likewise ([`Bsdf::is_near_specular`]).
    glossy_alpha: Option<f32>,
}

/// The specular (delta) directions leaving a surface point and their weights, given as radiance
/// multipliers: `L = Σ weight · L(direction)` (radiance mode: transmission includes (ηₒ/ηᵢ)²).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeltaLobes {
    /// Mirror direction (about the shading normal, kept above the geometric surface).
    pub reflect_dir: Vec3,
    /// Total weight of the mirror direction (mirror part + Fresnel reflection of the dielectric).
    pub reflect_weight: Vec3,
    /// Refracted direction and its weight, when the dielectric part transmits.
    pub refract: Option<(Vec3, Vec3)>,
    /// The radiance factor (ηₒ/ηᵢ)² included in the refracted weight (1 without refraction),
    /// which path tracers divide out for Russian roulette.
    pub eta_scale: f32,
}

impl Bsdf {
    /// Builds a BSDF, normalising the weights (`None` ones count as 0; all `None` means diffuse):
    /// `weights` are the diffuse (Lambert `color` + Phong `specular`, `shininess`), mirror and
    /// dielectric (`ior`, inside over outside) parts' weights.
    #[must_use]
    pub fn new(
        color: Vec3,
        specular: Vec3,
        shininess: f32,
        weights: [Option<f32>; 3],
        ior: f32,
    ) -> Self {
        let w = if weights.iter().all(Option::is_none) {
            [1.0, 0.0, 0.0]
        } else {
            weights.map(|w| w.unwrap_or(0.0))
        };
        let sum = w[0] + w[1] + w[2];
        let w = if sum > 0.0 {
            w.map(|x| x / sum)
        } else {
            [1.0, 0.0, 0.0]
        };
        // Phong is kept even when black (it contributes nothing then), so the exponent stays
        // part of the material's description.
        let phong = Some(Lobe::Phong(Phong {
            specular,
            exponent: shininess,
        }));
        Self::with_parts(
            color,
            [
                Part::new(w[0], Lobe::Lambert(Lambert), phong),
                Part::new(w[1], Lobe::SpecularReflection(SpecularReflection), None),
                Part::new(w[2], Lobe::Dielectric(Dielectric { ior }), None),
            ],
        )
    }

    /// A BSDF of tint `tint` and parts `parts`, with the parts' uses derived.
    fn with_parts(tint: Vec3, parts: [Part; PARTS]) -> Self {
        let [diffuse, mirror, dielectric] = &parts;
        let lambert = diffuse.weight > 0.0
            && mirror.weight == 0.0
            && dielectric.weight == 0.0
            && match diffuse.lobes {
                [Some(Lobe::Lambert(_)), None] => true,
                [Some(Lobe::Lambert(_)), Some(Lobe::Phong(p))] => p.specular == Vec3::ZERO,
                _ => false,
            };
        let flags = parts
            .iter()
            .filter(|p| p.weight > 0.0)
            .fold(LobeFlags::NONE, |f, p| f | p.flags());
        Self {
            tint,
            parts,
            uses: parts.map(|p| p.usage()),
            lambert,
            flags,
            choice_matters: choice_matters(&parts, tint),
            diffuse_only: diffuse_only(&parts, tint),
            glossy_alpha: glossy_alpha(&parts),
        }
    }

    /// The same BSDF with rough or metallic delta parts: with a microfacet `distribution` the
    /// mirror part becomes a GGX rough conductor ([`RoughConductor`]; with the conductor's
    /// Fresnel, else Fresnel 1 tinted by the colour, the rough counterpart of the mirror) and the
    /// dielectric part a GGX rough dielectric ([`RoughDielectric`], except at `ior == 1`, which
    /// bends nothing and stays the smooth pass-through); without one, a `conductor` makes the
    /// mirror a polished metal ([`SpecularConductor`]). `(None, None)` changes nothing: the
    /// perfect mirror and the smooth dielectric, bit for bit.
    #[must_use]
    pub fn with_microfacets(
        mut self,
        distribution: Option<Ggx>,
        conductor: Option<ConductorFresnel>,
    ) -> Self {
        let mirror = match (distribution, conductor) {
            (None, None) => None,
            (None, Some(fresnel)) => Some(Lobe::SpecularConductor(SpecularConductor { fresnel })),
            (Some(g), c) => Some(Lobe::RoughConductor(RoughConductor {
                distribution: g,
                fresnel: c.unwrap_or(ConductorFresnel::schlick(Vec3::ONE)),
                tinted: c.is_none(),
            })),
        };
        // A part of weight 0 is never chosen: leave it as it is, so that a BSDF without a
        // mirror part equals itself with or without microfacets.
        if let Some(m) = mirror
            && self.parts[1].weight > 0.0
        {
            self.parts[1].lobes = [Some(m), None];
        }
        if let Some(g) = distribution {
            let ior = self.parts[2].lobes().find_map(Lobe::ior).unwrap_or(1.0);
            if ior != 1.0 {
                self.parts[2].lobes = [
                    Some(Lobe::RoughDielectric(RoughDielectric {
                        distribution: g,
                        ior,
                    })),
                    None,
                ];
            }
        }
        Self::with_parts(self.tint, self.parts)
    }

    /// The same BSDF as a coated material ([`Coated`]): a smooth clear coat of relative index
    /// `ior` over a Lambertian base of this BSDF's colour. The diffuse part becomes the base and
    /// the mirror part the coat's Fresnel reflection, both of weight 1 (the two layers add, they
    /// are not a convex mixture), and the dielectric part is left at weight 0. `None` changes
    /// nothing. The scene checks exclude the mirror, dielectric, roughness, conductor and Phong
    /// parameters beside a coat, so nothing else of the material is lost.
    #[must_use]
    pub fn with_coat(self, ior: Option<f32>) -> Self {
        let Some(ior) = ior else { return self };
        let coat = Coated::new(ior);
        let mut parts = self.parts;
        parts[0] = Part::new(
            1.0,
            Lobe::Coated(CoatedLobe {
                coat,
                layer: CoatLayer::Base,
            }),
            None,
        );
        parts[1] = Part::new(
            1.0,
            Lobe::Coated(CoatedLobe {
                coat,
                layer: CoatLayer::Coat,
            }),
            None,
        );
        parts[2].weight = 0.0;
        Self::with_parts(self.tint, parts)
    }

    /// The same BSDF with the dielectric part's relative index of refraction (inside over
    /// outside) replaced by `ior`: the interface between two dielectrics that touch (water
    /// against glass, 1.33/1.5), whose inside and outside indices come from the volumes a path
    /// is in (`render_scene::Medium`, Schmidt & Budge 2002). Smooth and rough dielectrics keep
    /// their microfacets; other parts are unchanged.
    #[must_use]
    pub fn with_ior(self, ior: f32) -> Self {
        let mut parts = self.parts;
        for lobe in parts[2].lobes.iter_mut().flatten() {
            match lobe {
                Lobe::Dielectric(d) => d.ior = ior,
                Lobe::RoughDielectric(d) => d.ior = ior,
                Lobe::Lambert(_)
                | Lobe::Phong(_)
                | Lobe::SpecularReflection(_)
                | Lobe::SpecularConductor(_)
                | Lobe::RoughConductor(_)
                | Lobe::Coated(_) => {}
            }
        }
        Self::with_parts(self.tint, parts)
    }

    /// The clear coat of a coated material, if it is one.
    #[must_use]
    pub fn coat(&self) -> Option<Coated> {
        self.parts
            .iter()
            .flat_map(Part::lobes)
            .find_map(Lobe::coat)
            .map(|c| c.coat)
    }

    /// The microfacet distribution of the rough parts, if any.
    #[must_use]
    pub fn distribution(&self) -> Option<Ggx> {
        self.parts
            .iter()
            .flat_map(Part::lobes)
            .find_map(Lobe::distribution)
    }

    /// The tint: the diffuse albedo, which also tints the mirror and the transmitted light.
    #[inline]
    #[must_use]
    pub fn color(&self) -> Vec3 {
        self.tint
    }

    /// The same BSDF with tint `color` (a colour texture's value at a point).
    #[inline]
    #[must_use]
    pub fn with_color(mut self, color: Vec3) -> Self {
        self.tint = color;
        self.choice_matters = choice_matters(&self.parts, color);
        self.diffuse_only = diffuse_only(&self.parts, color);
        self
    }

    /// The normalised weights of the three parts (diffuse, mirror, dielectric) as the scene gave
    /// them, for diagnostics and tests; integrators ask [`Bsdf::flags`] instead.
    #[must_use]
    pub fn weights(&self) -> [f32; PARTS] {
        self.parts.map(|p| p.weight)
    }

    /// What the BSDF does: the union of the flags of its lobes of non-zero weight.
    #[inline]
    #[must_use]
    pub fn flags(&self) -> LobeFlags {
        self.flags
    }

    /// True if the BSDF has a non-delta (diffuse or glossy) part that direct lighting sees.
    #[inline]
    #[must_use]
    pub fn has_local(&self) -> bool {
        self.flags().is_non_delta()
    }

    /// True when no glossy lobe of non-zero weight scatters (the non-delta part is diffuse
    /// alone), so the non-delta radiance is `f · E` whatever direction the light arrives from:
    /// what lets a photon map's precomputed irradiance stand in for a density estimate.
    #[inline]
    #[must_use]
    pub fn is_diffuse_only(&self) -> bool {
        self.diffuse_only
    }

    /// True when the BSDF is **near-specular** at GGX width `max_alpha`: it has a microfacet
    /// (rough conductor or rough dielectric) lobe, none wider than `max_alpha` (α = r², r the
    /// scene's perceptual roughness), and no diffuse or Phong lobe of non-zero weight. The
    /// progressive integrators treat such a surface (brushed chrome, say) as part of caustic
    /// paths: photons pass through it as through a mirror, and camera paths leave to the caustic
    /// map what reaches a diffuse surface by way of it (a glossy caustic: the sun's highlight on
    /// a chrome tap thrown onto a wall), which a camera path finds only by rare chance.
    #[inline]
    #[must_use]
    pub fn is_near_specular(&self, max_alpha: f32) -> bool {
        self.glossy_alpha.is_some_and(|a| a <= max_alpha)
    }

    /// True if the BSDF has mirror or dielectric parts.
    #[inline]
    #[must_use]
    pub fn has_delta(&self) -> bool {
        self.flags().is_delta()
    }

    /// The total weight of the delta parts (mirror and dielectric; a coat counts with its mean
    /// reflectance, [`super::Lobe::focusing_fraction`]): the share of the light that can be
    /// focused, by which caustic photons are aimed at an object.
    #[inline]
    #[must_use]
    pub fn delta_share(&self) -> f32 {
        let mut s = 0.0f32;
        for p in self.parts.iter().filter(|p| p.is_delta()) {
            // × 1 (exactly) for mirrors and dielectrics.
            s += p.weight * p.lobes().next().map_or(1.0, Lobe::focusing_fraction);
        }
        s
    }

    /// The share of the light this BSDF can focus into a caustic, with near-specular surfaces
    /// (GGX α up to `near_specular`, [`Bsdf::is_near_specular`]) counting whole: what caustic
    /// photons are aimed by ([`Bsdf::delta_share`] otherwise), and, when positive, what makes
    /// an object a specular caster for the default estimator. The two read this one function so
    /// that "no caster" stays "an empty caustic map".
    #[inline]
    #[must_use]
    pub fn focusing_share(&self, near_specular: Option<f32>) -> f32 {
        if near_specular.is_some_and(|a| self.is_near_specular(a)) {
            1.0
        } else {
            self.delta_share()
        }
    }

    /// The relative index of refraction (inside over outside) of the transmitting part, if it
    /// has weight.
    #[must_use]
    pub fn ior(&self) -> Option<f32> {
        self.parts
            .iter()
            .filter(|p| p.weight > 0.0)
            .flat_map(Part::lobes)
            .find_map(Lobe::ior)
    }

    /// True if a part of non-zero weight transmits through a non-delta lobe.
    #[inline]
    pub(super) fn transmits_glossy(&self) -> bool {
        self.uses.iter().any(|u| u.transmits_glossy)
    }

    /// Whether [`Bsdf::sample`]'s lobe number `u_lobe` can change its result: false for a
    /// single lobe (pure Lambert, pure Phong, a pure mirror, or black), so integrators need not
    /// draw it (`Sampler::defer_1d`). A lobe that reads the number itself (the dielectric), two
    /// parts of non-zero weight, or two non-black lobes in one part make it matter.
    #[inline]
    #[must_use]
    pub fn lobe_choice_matters(&self) -> bool {
        self.choice_matters
    }

    /// The lobe number for [`Bsdf::sample`]: `draw()` where the choice matters
    /// ([`Bsdf::lobe_choice_matters`]), otherwise a constant that gives the same sample, so a
    /// deferred sampler draw (`Sampler::defer_1d`) is never computed for single-lobe BSDFs.
    #[inline]
    pub fn lobe_number(&self, draw: impl FnOnce() -> f32) -> f32 {
        if self.lobe_choice_matters() {
            draw()
        } else {
            0.5
        }
    }

    /// The mixture's parts, for [`super::BsdfAt`].
    #[inline]
    pub(super) fn parts(&self) -> &[Part; PARTS] {
        &self.parts
    }

    /// What each part takes part in, for [`super::BsdfAt`].
    #[inline]
    pub(super) fn uses(&self) -> &[PartUse; PARTS] {
        &self.uses
    }

    /// Whether the BSDF is a matte Lambert material alone (see the field), for [`super::BsdfAt`].
    #[inline]
    pub(super) fn is_lambert(&self) -> bool {
        self.lambert
    }

    /// The fraction of light that crosses the surface in a straight line, for shadow rays of
    /// integrators that do not follow refraction (Whitted): the dielectric part's Fresnel
    /// transmittance, tinted by `color`, at the angle `acos(cos)` to the normal. It is evaluated
    /// as seen from the outside whichever way the ray crosses: light leaving through a surface
    /// left the refracted angle, and by reciprocity its transmittance equals that of entering at
    /// the outside angle, so a slab crossed at θ transmits exactly T(θ)² (and never totally
    /// reflects). `entering` says the shadow ray crosses from outside to inside; the radiance
    /// convention's (ηₒ/ηᵢ)² is included (1/ior² entering, ior² leaving: a slab's cancel). Exact
    /// for `ior == 1` (the refracted ray is the straight one); for other indices it ignores the
    /// bending, so the light that glass focuses (caustics) needs photon mapping instead.
    #[inline]
    #[must_use]
    pub fn straight_transmittance(&self, cos: f32, entering: bool) -> Vec3 {
        let mut t = Vec3::ZERO;
        for part in &self.parts {
            if part.weight == 0.0 || !part.flags().contains(LobeFlags::TRANSMISSION) {
                continue;
            }
            for lobe in part.lobes() {
                t += lobe.straight_transmittance(part.weight, self.tint, cos, entering);
            }
        }
        t
    }

    /// The mirror and dielectric lobes at a point in radiance mode (for Whitted, which follows
    /// every delta branch). `n` is the shading normal and `ng` the geometric normal, both on the
    /// side of `wo`; `entering` says whether `wo` is outside the object.
    #[must_use]
    pub fn delta_lobes(&self, wo: Vec3, n: Vec3, ng: Vec3, entering: bool) -> DeltaLobes {
        let fr = ShadingFrame {
            ns: n,
            ng,
            entering,
        };
        let ctx = LobeContext {
            wo,
            fr: &fr,
            tint: self.tint,
        };
        let mut lobes = DeltaLobes {
            reflect_dir: mirror_above(wo, n, ng),
            reflect_weight: Vec3::ZERO,
            refract: None,
            eta_scale: 1.0,
        };
        for part in &self.parts {
            if part.weight == 0.0 || !part.is_delta() {
                continue;
            }
            for lobe in part.lobes() {
                let d = lobe.delta_weights(&ctx, part.weight);
                lobes.reflect_weight += d.reflect;
                if let Some((dir, w, eta_scale)) = d.refract {
                    lobes.refract = Some((dir, w));
                    lobes.eta_scale = eta_scale;
                }
            }
        }
        lobes
    }
}

/// Whether a lobe number can change the sample of a mixture of `parts` with tint `tint`
/// ([`Bsdf::lobe_choice_matters`]): a lobe that reads it itself (the dielectric), two parts of
/// non-zero weight, or two non-black lobes in one part.
fn choice_matters(parts: &[Part; PARTS], tint: Vec3) -> bool {
    let mut count = 0;
    for part in parts.iter().filter(|p| p.weight > 0.0) {
        count += 1;
        let mut lit = 0;
        for lobe in part.lobes() {
            if lobe.uses_lobe_number() {
                return true;
            }
            lit += usize::from(!lobe.is_black(tint));
        }
        if lit > 1 {
            return true;
        }
    }
    count > 1
}

/// Whether no glossy lobe of non-zero weight scatters in a mixture of `parts` with tint `tint`
/// ([`Bsdf::is_diffuse_only`]).
fn diffuse_only(parts: &[Part; PARTS], tint: Vec3) -> bool {
    parts
        .iter()
        .filter(|p| p.weight > 0.0)
        .flat_map(Part::lobes)
        .all(|l| l.is_flat(tint))
}

/// The widest microfacet α of a mixture of `parts` whose lobes of non-zero weight are all delta
/// or microfacet lobes, at least one of them a microfacet lobe ([`Bsdf::is_near_specular`]).
fn glossy_alpha(parts: &[Part; PARTS]) -> Option<f32> {
    let mut widest: Option<f32> = None;
    for lobe in parts
        .iter()
        .filter(|p| p.weight > 0.0)
        .flat_map(Part::lobes)
    {
        let Some(g) = lobe.distribution() else {
            if lobe.flags().is_delta() {
                continue;
            }
            return None;
        };
        let a = g.alpha_x.max(g.alpha_y);
        widest = Some(widest.map_or(a, |w| w.max(a)));
    }
    widest
}

impl crate::binfile::KeyHash for Bsdf {
    /// The tint and the parts; the other fields are derived from those two.
    fn key_hash(&self, h: &mut crate::binfile::Fnv) {
        let Self {
            tint,
            parts,
            uses: _,
            lambert: _,
            flags: _,
            choice_matters: _,
            diffuse_only: _,
            glossy_alpha: _,
        } = self;
        h.str("Bsdf");
        tint.key_hash(h);
        parts.key_hash(h);
    }
}

#[cfg(test)]
#[path = "bsdf_tests.rs"]
mod tests;

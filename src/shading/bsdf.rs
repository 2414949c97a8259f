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

use super::conductor::ConductorFresnel;
use super::dielectric::Dielectric;
use super::lambert::Lambert;
use super::lobe::{Lobe, Prepared};
use super::microfacet::Ggx;
use super::phong::Phong;
use super::rough_conductor::RoughConductor;
use super::rough_dielectric::RoughDielectric;
use super::scattering::mean;
pub use super::scattering::{
    BsdfSample, LobeFlags, ShadingFrame, TransportMode, shading_normal_correction,
};
use super::specular_conductor::SpecularConductor;
use super::specular_reflection::{SpecularReflection, mirror_above};

/// Parts of the mixture (each a weight and its lobes).
const PARTS: usize = 3;
/// Most lobes in one part.
const LOBES_PER_PART: usize = 2;

/// One weighted part of the mixture: lobes that share one weight (all non-delta, or one delta
/// lobe).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Part {
    weight: f32,
    lobes: [Option<Lobe>; LOBES_PER_PART],
}

impl Part {
    fn new(weight: f32, first: Lobe, second: Option<Lobe>) -> Self {
        Self {
            weight,
            lobes: [Some(first), second],
        }
    }

    /// The lobes present.
    #[inline]
    fn lobes(&self) -> impl Iterator<Item = &Lobe> {
        self.lobes.iter().flatten()
    }

    /// Whether the part is a delta lobe (by its first lobe; parts never mix).
    #[inline]
    fn is_delta(&self) -> bool {
        self.lobes().next().is_some_and(|l| l.flags().is_delta())
    }

    /// The union of the lobes' flags.
    #[inline]
    fn flags(&self) -> LobeFlags {
        self.lobes().fold(LobeFlags::NONE, |f, l| f | l.flags())
    }

    /// Whether the part has a non-delta lobe that transmits (the rough dielectric), so that
    /// directions below the surface have a value and a density.
    #[inline]
    fn transmits_glossy(&self) -> bool {
        !self.is_delta() && self.flags().contains(LobeFlags::TRANSMISSION)
    }

    /// The per-direction state of the part's (first) lobe.
    #[inline]
    fn prepare(&self, wo: Vec3, fr: &ShadingFrame) -> Prepared {
        self.lobes()
            .next()
            .map_or(Prepared::Nothing, |l| l.prepare(wo, fr))
    }

    /// The lobes' sampling weights and each lobe's share of the part: `aⱼ / Σa` for all but the
    /// last, which takes the rest (all to the first when Σa is 0).
    #[inline]
    fn shares(&self, prepared: &Prepared, rho: f32) -> [f32; LOBES_PER_PART] {
        let mut a = [0.0f32; LOBES_PER_PART];
        let mut total = 0.0f32;
        let mut count = 0;
        for (slot, lobe) in a.iter_mut().zip(self.lobes()) {
            *slot = lobe.albedo(prepared, rho);
            total += *slot;
            count += 1;
        }
        let mut shares = [0.0f32; LOBES_PER_PART];
        let mut taken = 0.0f32;
        for j in 0..count {
            shares[j] = if j + 1 == count {
                1.0 - taken
            } else if total > 0.0 {
                a[j] / total
            } else if j == 0 {
                1.0
            } else {
                0.0
            };
            taken += shares[j];
        }
        shares
    }

    /// The part's sampling weight: its weight times the sum of its lobes' albedos.
    #[inline]
    fn probability_weight(&self, prepared: &Prepared, rho: f32) -> f32 {
        if self.weight == 0.0 {
            return 0.0;
        }
        let mut a = 0.0f32;
        for lobe in self.lobes() {
            a += lobe.albedo(prepared, rho);
        }
        self.weight * a
    }
}

/// A compiled material's scattering function: a tint (the colour; texture lookups replace it)
/// and a weighted mixture of lobes. Its `Debug` text is the material's parameters (the scene
/// hash of `.part` files and photon caches reads it, so it stays as it always was).
#[derive(Clone, Copy, PartialEq)]
pub struct Bsdf {
    /// Diffuse albedo; also tints the mirror and transmitted light.
    tint: Vec3,
    /// The diffuse, mirror and dielectric parts, in this order (the order sampling walks).
    parts: [Part; PARTS],
}

impl std::fmt::Debug for Bsdf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let lobes = || self.parts.iter().flat_map(Part::lobes);
        let (specular, shininess) = lobes()
            .find_map(|l| match l {
                Lobe::Phong(p) => Some((p.specular, p.exponent)),
                _ => None,
            })
            .unwrap_or((Vec3::ZERO, 1.0));
        let ior = lobes().find_map(Lobe::ior).unwrap_or(1.0);
        let [diffuse, reflect, transmit] = self.weights();
        let mut d = f.debug_struct("Bsdf");
        d.field("color", &self.tint)
            .field("specular", &specular)
            .field("shininess", &shininess)
            .field("diffuse", &diffuse)
            .field("reflect", &reflect)
            .field("transmit", &transmit)
            .field("ior", &ior);
        // Only materials that use the microfacet lobes or a conductor say so, so the text (and
        // the scene hash) of every other material is what it always was.
        if let Some(g) = self.distribution() {
            d.field("roughness_alpha", &(g.alpha_x, g.alpha_y));
        }
        if let Some(c) = lobes().find_map(|l| match l {
            Lobe::SpecularConductor(s) => Some(s.fresnel),
            Lobe::RoughConductor {
                lobe,
                tinted: false,
            } => Some(lobe.fresnel),
            _ => None,
        }) {
            d.field("conductor", &c);
        }
        d.finish()
    }
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

/// The part probabilities of one sampling decision (summing to 1, or all 0 for a black BSDF),
/// and each part's per-direction state.
struct Choice {
    p: [f32; PARTS],
    prepared: [Prepared; PARTS],
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
        Self {
            tint: color,
            parts: [
                Part::new(w[0], Lobe::Lambert(Lambert), phong),
                Part::new(w[1], Lobe::SpecularReflection(SpecularReflection), None),
                Part::new(w[2], Lobe::Dielectric(Dielectric { ior }), None),
            ],
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
            (Some(g), c) => Some(Lobe::RoughConductor {
                lobe: RoughConductor {
                    distribution: g,
                    fresnel: c.unwrap_or(ConductorFresnel::schlick(Vec3::ONE)),
                },
                tinted: c.is_none(),
            }),
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
        self
    }

    /// The microfacet distribution of the rough parts, if any.
    #[must_use]
    pub fn distribution(&self) -> Option<Ggx> {
        self.parts
            .iter()
            .flat_map(Part::lobes)
            .find_map(|l| match l {
                Lobe::RoughConductor { lobe, .. } => Some(lobe.distribution),
                Lobe::RoughDielectric(d) => Some(d.distribution),
                _ => None,
            })
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
        self.parts
            .iter()
            .filter(|p| p.weight > 0.0)
            .fold(LobeFlags::NONE, |f, p| f | p.flags())
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
        self.parts
            .iter()
            .filter(|p| p.weight > 0.0)
            .flat_map(Part::lobes)
            .all(|l| !l.flags().contains(LobeFlags::GLOSSY) || l.is_black(self.tint))
    }

    /// True if the BSDF has mirror or dielectric parts.
    #[inline]
    #[must_use]
    pub fn has_delta(&self) -> bool {
        self.flags().is_delta()
    }

    /// The total weight of the delta parts (mirror and dielectric): the share of the light
    /// that can be focused, by which caustic photons are aimed at an object.
    #[inline]
    #[must_use]
    pub fn delta_share(&self) -> f32 {
        let mut s = 0.0f32;
        for p in self.parts.iter().filter(|p| p.is_delta()) {
            s += p.weight;
        }
        s
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

    /// The non-delta part `f(wo, wi)` (per steradian) with `n` the shading normal on the side of
    /// `wo`: each non-delta part's weight times the sum of its lobes (here
    /// `diffuse · (ρ/π + k_s (m+2)/(2π) max(0, r·wi)^m)`, `r` the mirror of `wo`). Zero when
    /// `wi` is below `n`. Symmetric in `wo` and `wi` (reciprocal).
    ///
    /// The frame is taken as `ns = ng = n` seen from outside, in radiance mode; [`Bsdf::eval`]
    /// is the full form.
    #[inline]
    #[must_use]
    pub fn f(&self, wo: Vec3, wi: Vec3, n: Vec3) -> Vec3 {
        let fr = ShadingFrame {
            ns: n,
            ng: n,
            entering: true,
        };
        self.f_in(wo, wi, &fr, TransportMode::Radiance)
    }

    /// The non-delta parts' value in frame `fr` and mode `mode`: reflecting parts only for `wi`
    /// above the geometric surface, transmitting (rough dielectric) parts on either side.
    #[inline]
    fn f_in(&self, wo: Vec3, wi: Vec3, fr: &ShadingFrame, mode: TransportMode) -> Vec3 {
        let below = fr.ng.dot(wi) <= 0.0;
        let mut f = Vec3::ZERO;
        for part in &self.parts {
            if part.weight == 0.0 || part.is_delta() || (below && !part.transmits_glossy()) {
                continue;
            }
            let mut fp = Vec3::ZERO;
            for lobe in part.lobes() {
                fp += lobe.f(wo, wi, fr, mode, self.tint);
            }
            f += fp * part.weight;
        }
        f
    }

    /// True if a part of non-zero weight transmits through a non-delta lobe.
    #[inline]
    fn transmits_glossy(&self) -> bool {
        self.parts
            .iter()
            .any(|p| p.weight > 0.0 && p.transmits_glossy())
    }

    /// The non-delta BSDF value in frame `fr`, for `wi` above both the shading and the geometric
    /// surface (else 0: no light through a surface whose shading normal leans towards it). In
    /// importance mode it includes [`shading_normal_correction`], so `eval · |ns·wi|` is the
    /// flux throughput of a light path in either mode.
    #[inline]
    #[must_use]
    pub fn eval(&self, wo: Vec3, wi: Vec3, fr: &ShadingFrame, mode: TransportMode) -> Vec3 {
        if fr.ng.dot(wi) <= 0.0 && !self.transmits_glossy() {
            return Vec3::ZERO;
        }
        let f = self.f_in(wo, wi, fr, mode);
        match mode {
            TransportMode::Radiance => f,
            TransportMode::Importance => f * shading_normal_correction(wo, wi, fr),
        }
    }

    /// Whether [`Bsdf::sample`]'s lobe number `u_lobe` can change its result: false for a
    /// single lobe (pure Lambert, pure Phong, a pure mirror, or black), so integrators need not
    /// draw it (`Sampler::defer_1d`). A lobe that reads the number itself (the dielectric), two
    /// parts of non-zero weight, or two non-black lobes in one part make it matter.
    #[inline]
    #[must_use]
    pub fn lobe_choice_matters(&self) -> bool {
        let mut parts = 0;
        for part in self.parts.iter().filter(|p| p.weight > 0.0) {
            parts += 1;
            let mut lit = 0;
            for lobe in part.lobes() {
                if lobe.uses_lobe_number() {
                    return true;
                }
                lit += usize::from(!lobe.is_black(self.tint));
            }
            if lit > 1 {
                return true;
            }
        }
        parts > 1
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

    /// The parts' probabilities for `wo` (each part's weight times its lobes' mean albedo,
    /// normalised) and their per-direction state.
    #[inline]
    fn choice(&self, wo: Vec3, fr: &ShadingFrame, rho: f32) -> Choice {
        let prepared = self.parts.map(|p| {
            if p.weight > 0.0 {
                p.prepare(wo, fr)
            } else {
                Prepared::Nothing
            }
        });
        let mut q = [0.0f32; PARTS];
        let mut sum = 0.0f32;
        for ((q, part), prep) in q.iter_mut().zip(&self.parts).zip(&prepared) {
            *q = part.probability_weight(prep, rho);
            sum += *q;
        }
        let p = if sum > 0.0 {
            q.map(|x| x / sum)
        } else {
            [0.0; PARTS]
        };
        Choice { p, prepared }
    }

    /// The density with which non-delta part `part`, chosen with probability `prob`, samples
    /// `wi`: `prob · Σⱼ shareⱼ · pdfⱼ`, 0 below the shading or geometric surface.
    #[inline]
    #[allow(clippy::too_many_arguments)]
    fn part_pdf(
        &self,
        part: &Part,
        prepared: &Prepared,
        prob: f32,
        rho: f32,
        wo: Vec3,
        wi: Vec3,
        fr: &ShadingFrame,
    ) -> f32 {
        if prob == 0.0
            || ((fr.ns.dot(wi) <= 0.0 || fr.ng.dot(wi) <= 0.0) && !part.transmits_glossy())
        {
            return 0.0;
        }
        let shares = part.shares(prepared, rho);
        let mut d = 0.0f32;
        for (lobe, &share) in part.lobes().zip(&shares) {
            if share > 0.0 {
                d += lobe.scaled_pdf(share, wo, wi, fr, self.tint);
            }
        }
        prob * d
    }

    /// The mixture density of the non-delta parts at `wi` given a choice.
    #[inline]
    fn mixture_pdf(&self, c: &Choice, rho: f32, wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
        let mut pdf = 0.0f32;
        for (i, part) in self.parts.iter().enumerate() {
            if part.weight == 0.0 || part.is_delta() {
                continue;
            }
            pdf += self.part_pdf(part, &c.prepared[i], c.p[i], rho, wo, wi, fr);
        }
        pdf
    }

    /// Solid-angle density with which [`Bsdf::sample`] returns the non-delta direction `wi`
    /// (0 below the shading or geometric surface, where `sample` returns nothing). Delta lobes
    /// have no density; their discrete probabilities are in the samples themselves.
    #[must_use]
    pub fn pdf(&self, wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
        if !self.parts.iter().any(|p| p.weight != 0.0 && !p.is_delta()) {
            return 0.0;
        }
        let rho = mean(self.tint);
        let c = self.choice(wo, fr, rho);
        self.mixture_pdf(&c, rho, wo, wi, fr)
    }

    /// Samples a direction for a path arriving from `wo`: a part chosen with `u_lobe` (the
    /// diffuse part, the mirror or the dielectric, in proportion to their weights times their
    /// mean albedo; inside the dielectric, reflection or refraction in proportion to F and
    /// (1 − F)·ρ), then a direction from `u` (cosine-weighted for Lambert, Phong's
    /// `cos^m` lobe around the mirror direction). `None` when the BSDF is black or the sampled
    /// direction is below the surface (that probability mass is lost, not renormalised).
    #[must_use]
    pub fn sample(
        &self,
        wo: Vec3,
        u_lobe: f32,
        u: (f32, f32),
        fr: &ShadingFrame,
        mode: TransportMode,
    ) -> Option<BsdfSample> {
        let rho = mean(self.tint);
        let c = self.choice(wo, fr, rho);
        // Walk the parts: the first whose interval holds u_lobe, else (rounding) the last of
        // non-zero weight; `rest` is u_lobe less the probabilities before the part.
        let mut chosen = None;
        let mut cum = 0.0f32;
        let mut rest = u_lobe;
        let mut rests = [0.0f32; PARTS];
        for (i, (slot, &p)) in rests.iter_mut().zip(&c.p).enumerate() {
            *slot = rest;
            if u_lobe < cum + p {
                chosen = Some(i);
                break;
            }
            cum += p;
            rest -= p;
        }
        let i = chosen.or_else(|| self.parts.iter().rposition(|p| p.weight > 0.0))?;
        let part = &self.parts[i];
        let v = rests[i] / c.p[i];
        if part.is_delta() {
            let lobe = part.lobes().next()?;
            return lobe.sample_delta(
                &c.prepared[i],
                wo,
                v,
                fr,
                mode,
                part.weight,
                c.p[i],
                self.tint,
                rho,
            );
        }
        // A non-delta part: reuse the lobe number to pick one of its lobes.
        let shares = part.shares(&c.prepared[i], rho);
        let mut lobe = None;
        let mut cum = 0.0f32;
        let mut rest = v;
        for (l, &share) in part.lobes().zip(&shares) {
            lobe = Some(l);
            rest = if share > 0.0 { (v - cum) / share } else { 0.0 };
            if v < cum + share {
                break;
            }
            cum += share;
        }
        let lobe = lobe?;
        let rest = if lobe.uses_lobe_number() {
            rest.clamp(0.0, 1.0 - f32::EPSILON)
        } else {
            0.0
        };
        let wi = lobe.sample_direction(wo, rest, u, fr, self.tint)?;
        let pdf = self.mixture_pdf(&c, rho, wo, wi, fr);
        let f = self.eval(wo, wi, fr, mode);
        if !(pdf > 0.0) || f == Vec3::ZERO {
            return None;
        }
        let transmitted = fr.ng.dot(wi) < 0.0;
        // A glossy refraction in radiance mode carries (ηₒ/ηᵢ)² = 1/η² in `f` (Walter 2007,
        // eq. 21), reported for Russian roulette as the smooth dielectric reports its own.
        let mut eta_scale = 1.0;
        if let (true, TransportMode::Radiance, Some(ior)) = (transmitted, mode, lobe.ior()) {
            let eta = if fr.entering { ior } else { 1.0 / ior };
            eta_scale = 1.0 / (eta * eta);
        }
        Some(BsdfSample {
            wi,
            weight: f * (fr.ns.dot(wi).abs() / pdf),
            pdf,
            delta: false,
            transmitted,
            eta_scale,
        })
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
                let d = lobe.delta_weights(wo, &fr, part.weight, self.tint);
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

#[cfg(test)]
#[path = "bsdf_tests.rs"]
mod tests;

//! The BSDF mixture at one outgoing direction: what [`Bsdf::at`] works out once per path vertex
//! (each part's per-direction state, the parts' sampling probabilities, each lobe's share of its
//! part, which parts have a value and a density) so that next-event estimation's value and
//! density, BSDF sampling, and the sample's own value and density all reuse it instead of
//! re-deriving the mixture on every call (pbrt-v4 likewise builds its `BSDF` once per
//! intersection). The arithmetic is the mixture's own, in the same order, so the numbers are
//! identical to asking [`Bsdf`] directly.

use glam::Vec3;

use super::bsdf::{Bsdf, PARTS};
use super::bxdf::{LobeContext, LobeDraw, LobeSample, Prepared};
use super::lambert::Lambert;
use super::part::{LOBES_PER_PART, Part, PartUse};
use super::scattering::{BsdfSample, ShadingFrame, TransportMode, mean, shading_normal_correction};

/// A [`Bsdf`] prepared for one outgoing direction `wo` in one shading frame (see the module
/// docs): ask it [`BsdfAt::eval`], [`BsdfAt::pdf`] and [`BsdfAt::sample`] for any number of
/// incident directions. Cheap to build (a few Fresnel terms; for a matte Lambert material one
/// number), no allocation.
#[derive(Debug, Clone, Copy)]
pub struct BsdfAt<'b> {
    bsdf: &'b Bsdf,
    wo: Vec3,
    fr: ShadingFrame,
    mix: Mixture,
}

/// The mixture's per-direction numbers.
#[derive(Debug, Clone, Copy)]
enum Mixture {
    /// A matte Lambert material with a finite tint: the queries take the mixture's arithmetic
    /// for that case directly (the same numbers; see [`BsdfAt::lambert`]). `p` is the diffuse
    /// part's probability: 1, or 0 for a black BSDF.
    Lambert {
        /// The diffuse part's probability.
        p: f32,
    },
    /// Any other BSDF: the mixture walked part by part.
    General(General),
}

/// What the general mixture works out once per outgoing direction.
#[derive(Debug, Clone, Copy)]
struct General {
    /// The tint's mean.
    rho: f32,
    uses: [PartUse; PARTS],
    any_local: bool,
    any_transmits_glossy: bool,
    /// The parts' sampling probabilities (summing to 1, or all 0 for a black BSDF).
    p: [f32; PARTS],
    prepared: [Prepared; PARTS],
    /// Each non-delta part's lobe shares (0 for the others).
    shares: [[f32; LOBES_PER_PART]; PARTS],
}

/// The non-delta parts' value `Σ weight · Σ lobe f` for `wi`, in frame `fr` and mode `mode`:
/// reflecting parts only for `wi` above the geometric surface, transmitting (rough dielectric)
/// parts on either side. `uses` says which parts count.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn non_delta_value(
    parts: &[Part; PARTS],
    uses: &[PartUse; PARTS],
    tint: Vec3,
    wo: Vec3,
    wi: Vec3,
    fr: &ShadingFrame,
    mode: TransportMode,
) -> Vec3 {
    let below = fr.ng.dot(wi) <= 0.0;
    let ctx = LobeContext { wo, fr, tint };
    let mut f = Vec3::ZERO;
    for (part, use_) in parts.iter().zip(uses) {
        if !use_.local || (below && !use_.transmits_glossy) {
            continue;
        }
        let mut fp = Vec3::ZERO;
        for lobe in part.lobes() {
            fp += lobe.f(&ctx, wi, mode);
        }
        f += fp * part.weight;
    }
    f
}

/// The non-delta value of a matte Lambert `bsdf` ([`Bsdf::is_lambert`]) of finite tint mean,
/// with the general mixture's numbers (see [`BsdfAt::eval`]).
#[inline(always)]
pub(super) fn lambert_value(
    bsdf: &Bsdf,
    wo: Vec3,
    wi: Vec3,
    fr: &ShadingFrame,
    mode: TransportMode,
) -> Vec3 {
    if fr.ng.dot(wi) <= 0.0 {
        return Vec3::ZERO;
    }
    // The mixture's sum, `0 + (0 + f_Lambert [+ 0 from black Phong]) · weight`, kept
    // literally so that signed zeros come out as they do there.
    let lambert = Lambert::value(bsdf.color(), wi, fr.ns);
    let f = Vec3::ZERO + (Vec3::ZERO + lambert) * bsdf.parts()[0].weight;
    match mode {
        TransportMode::Radiance => f,
        TransportMode::Importance => f * shading_normal_correction(wo, wi, fr),
    }
}

/// The full non-delta BSDF value (see [`BsdfAt::eval`]).
#[allow(clippy::too_many_arguments)]
#[inline(always)]
pub(super) fn eval_value(
    parts: &[Part; PARTS],
    uses: &[PartUse; PARTS],
    any_transmits_glossy: bool,
    tint: Vec3,
    wo: Vec3,
    wi: Vec3,
    fr: &ShadingFrame,
    mode: TransportMode,
) -> Vec3 {
    if fr.ng.dot(wi) <= 0.0 && !any_transmits_glossy {
        return Vec3::ZERO;
    }
    let f = non_delta_value(parts, uses, tint, wo, wi, fr, mode);
    match mode {
        TransportMode::Radiance => f,
        TransportMode::Importance => f * shading_normal_correction(wo, wi, fr),
    }
}

/// The mixture's evaluation and sampling, asked of the BSDF directly (each prepares it for the
/// one query) or prepared once per outgoing direction ([`Bsdf::at`]).
impl Bsdf {
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
        non_delta_value(
            self.parts(),
            self.uses(),
            self.color(),
            wo,
            wi,
            &fr,
            TransportMode::Radiance,
        )
    }

    /// The non-delta BSDF value in frame `fr`, for `wi` above both the shading and the geometric
    /// surface (else 0: no light through a surface whose shading normal leans towards it). In
    /// importance mode it includes [`shading_normal_correction`], so `eval · |ns·wi|` is the
    /// flux throughput of a light path in either mode.
    #[inline]
    #[must_use]
    pub fn eval(&self, wo: Vec3, wi: Vec3, fr: &ShadingFrame, mode: TransportMode) -> Vec3 {
        if self.is_lambert() && mean(self.color()).is_finite() {
            // The matte-Lambert arithmetic [`BsdfAt`] takes (the same numbers).
            return lambert_value(self, wo, wi, fr, mode);
        }
        let any = self.transmits_glossy();
        eval_value(
            self.parts(),
            self.uses(),
            any,
            self.color(),
            wo,
            wi,
            fr,
            mode,
        )
    }

    /// Solid-angle density with which [`Bsdf::sample`] returns the non-delta direction `wi`
    /// (0 below the shading or geometric surface, where `sample` returns nothing). Delta lobes
    /// have no density; their discrete probabilities are in the samples themselves.
    #[must_use]
    pub fn pdf(&self, wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
        self.at(wo, fr).pdf(wi)
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
        self.at(wo, fr).sample(u_lobe, u, mode)
    }

    /// The BSDF prepared for outgoing direction `wo` in frame `fr` ([`BsdfAt`]): what a path
    /// vertex asks for its light sample's value and density and for its next direction, with
    /// the mixture worked out once.
    #[inline]
    #[must_use]
    pub fn at(&self, wo: Vec3, fr: &ShadingFrame) -> BsdfAt<'_> {
        BsdfAt::new(self, wo, fr)
    }
}

impl<'b> BsdfAt<'b> {
    /// Prepares `bsdf` for outgoing direction `wo` (unit, away from the surface) in frame `fr`:
    /// each part's per-direction state, the parts' probabilities (weight times the lobes' mean
    /// albedo, normalised) and the lobes' shares.
    #[inline(always)]
    #[must_use]
    pub fn new(bsdf: &'b Bsdf, wo: Vec3, fr: &ShadingFrame) -> Self {
        let rho = mean(bsdf.color());
        if bsdf.is_lambert() && rho.is_finite() {
            return Self::lambert(bsdf, wo, fr, rho);
        }
        Self {
            bsdf,
            wo,
            fr: *fr,
            mix: Mixture::General(General::new(bsdf, wo, fr, rho)),
        }
    }

    /// [`BsdfAt::new`] for a matte Lambert BSDF ([`Bsdf::is_lambert`]) of finite tint mean
    /// `rho`, with the numbers the general mixture arrives at: nothing to prepare, the diffuse
    /// part's probability `q/q = 1` for `q = weight · ρ̄ > 0` (else the BSDF is black and all are
    /// 0; adding the black Phong lobe's albedo 0 changes neither), and Lambert's share 1 (the
    /// black Phong lobe's 0).
    #[inline(always)]
    fn lambert(bsdf: &'b Bsdf, wo: Vec3, fr: &ShadingFrame, rho: f32) -> Self {
        let q = bsdf.parts()[0].weight * rho;
        Self {
            bsdf,
            wo,
            fr: *fr,
            mix: Mixture::Lambert {
                p: if q > 0.0 { 1.0 } else { 0.0 },
            },
        }
    }

    /// Whether the queries take the matte-Lambert arithmetic (for the tests that hold it to the
    /// general walk).
    #[cfg(test)]
    pub(super) fn is_lambert(&self) -> bool {
        matches!(self.mix, Mixture::Lambert { .. })
    }

    /// The same prepared BSDF asked through the general walk even where it is matte Lambert
    /// (for the tests that hold the fast path to it).
    #[cfg(test)]
    pub(super) fn general(bsdf: &'b Bsdf, wo: Vec3, fr: &ShadingFrame) -> Self {
        let rho = mean(bsdf.color());
        Self {
            bsdf,
            wo,
            fr: *fr,
            mix: Mixture::General(General::new(bsdf, wo, fr, rho)),
        }
    }

    /// The BSDF this was prepared from.
    #[inline]
    #[must_use]
    pub fn bsdf(&self) -> &'b Bsdf {
        self.bsdf
    }

    /// The outgoing direction it was prepared for.
    #[inline]
    #[must_use]
    pub fn wo(&self) -> Vec3 {
        self.wo
    }

    /// The shading frame it was prepared in.
    #[inline]
    #[must_use]
    pub fn frame(&self) -> &ShadingFrame {
        &self.fr
    }

    /// The non-delta BSDF value for incident direction `wi` ([`Bsdf::eval`]): 0 below the
    /// geometric surface unless a glossy part transmits; in importance mode it includes
    /// [`shading_normal_correction`].
    #[inline]
    #[must_use]
    pub fn eval(&self, wi: Vec3, mode: TransportMode) -> Vec3 {
        match &self.mix {
            Mixture::Lambert { .. } => self.lambert_eval(wi, mode),
            Mixture::General(g) => eval_value(
                self.bsdf.parts(),
                &g.uses,
                g.any_transmits_glossy,
                self.bsdf.color(),
                self.wo,
                wi,
                &self.fr,
                mode,
            ),
        }
    }

    /// [`BsdfAt::eval`] of a matte Lambert material.
    #[inline(always)]
    fn lambert_eval(&self, wi: Vec3, mode: TransportMode) -> Vec3 {
        lambert_value(self.bsdf, self.wo, wi, &self.fr, mode)
    }

    /// The solid-angle density with which [`BsdfAt::sample`] returns the non-delta direction
    /// `wi` ([`Bsdf::pdf`]): `Σ pₖ Σⱼ shareⱼ pdfⱼ(wi)` over the non-delta parts, 0 below the
    /// shading or geometric surface for reflecting parts.
    #[inline]
    #[must_use]
    pub fn pdf(&self, wi: Vec3) -> f32 {
        match &self.mix {
            Mixture::Lambert { p } => self.lambert_pdf(*p, wi),
            Mixture::General(g) => g.pdf(self.bsdf, self.wo, wi, &self.fr),
        }
    }

    /// [`BsdfAt::pdf`] of a matte Lambert material whose diffuse part has probability `prob`.
    #[inline(always)]
    fn lambert_pdf(&self, prob: f32, wi: Vec3) -> f32 {
        let fr = &self.fr;
        let below = fr.ns.dot(wi) <= 0.0 || fr.ng.dot(wi) <= 0.0;
        if prob == 0.0 || below {
            return 0.0;
        }
        // The mixture's `0 + p · (0 + share · cos/π)` with Lambert's share 1.
        0.0 + prob * (0.0 + Lambert::scaled_density(1.0, wi, fr))
    }

    /// The lobe number for [`BsdfAt::sample`] ([`Bsdf::lobe_number`]).
    #[inline]
    pub fn lobe_number(&self, draw: impl FnOnce() -> f32) -> f32 {
        self.bsdf.lobe_number(draw)
    }

    /// Samples an incident direction ([`Bsdf::sample`]): a part chosen with `u_lobe` in
    /// proportion to its probability, then a lobe of a non-delta part by its share with the
    /// rest of the number, then a direction from `u`. `None` when the BSDF is black or the
    /// direction is lost below the surface.
    #[must_use]
    pub fn sample(&self, u_lobe: f32, u: (f32, f32), mode: TransportMode) -> Option<BsdfSample> {
        match &self.mix {
            Mixture::Lambert { p } => {
                // The walk would choose the diffuse part (whatever `u_lobe`: it is the only
                // part of weight) and in it Lambert (share 1), which reads no more of the
                // lobe number; for a black BSDF (p = 0) every density is 0, so no sample.
                if *p == 0.0 {
                    return None;
                }
                let wi = Lambert::direction(u, &self.fr);
                let pdf = self.lambert_pdf(*p, wi);
                let f = self.lambert_eval(wi, mode);
                self.weigh(wi, f, pdf, None)
            }
            Mixture::General(g) => {
                let (wi, ior) = g.sample(self.bsdf, self.wo, u_lobe, u, &self.fr, mode)?;
                match wi {
                    Sampled::Delta(s) => Some(s),
                    Sampled::Direction(wi) => {
                        let pdf = g.pdf(self.bsdf, self.wo, wi, &self.fr);
                        let f = self.eval(wi, mode);
                        self.weigh(wi, f, pdf, ior)
                    }
                }
            }
        }
    }

    /// The non-delta sample of direction `wi` from a lobe of index of refraction `ior` (a
    /// transmitting glossy lobe's), with the mixture's value `f` and density `pdf` there:
    /// `None` when either is 0.
    #[inline(always)]
    fn weigh(&self, wi: Vec3, f: Vec3, pdf: f32, ior: Option<f32>) -> Option<BsdfSample> {
        let fr = &self.fr;
        if !(pdf > 0.0) || f == Vec3::ZERO {
            return None;
        }
        let transmitted = fr.ng.dot(wi) < 0.0;
        // A glossy refraction in radiance mode carries (ηₒ/ηᵢ)² = 1/η² in `f` (Walter 2007,
        // eq. 21), reported for Russian roulette as the smooth dielectric reports its own.
        // (`ior` is only given in radiance mode.)
        let mut eta_scale = 1.0;
        if let (true, Some(ior)) = (transmitted, ior) {
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
}

/// What the general walk sampled: a delta lobe's finished sample, or a non-delta direction
/// still to be weighed by the whole mixture.
enum Sampled {
    Delta(BsdfSample),
    Direction(Vec3),
}

impl General {
    /// Each part's per-direction state, the parts' probabilities (weight times the lobes' mean
    /// albedo, normalised) and the lobes' shares, for `bsdf` of tint mean `rho` at `wo`.
    #[inline(always)]
    fn new(bsdf: &Bsdf, wo: Vec3, fr: &ShadingFrame, rho: f32) -> Self {
        let parts = bsdf.parts();
        let uses = *bsdf.uses();
        let ctx = LobeContext {
            wo,
            fr,
            tint: bsdf.color(),
        };
        let mut prepared = [Prepared::Nothing; PARTS];
        let mut q = [0.0f32; PARTS];
        let mut sum = 0.0f32;
        for i in 0..PARTS {
            let part = &parts[i];
            if part.weight > 0.0 {
                prepared[i] = part.prepare(&ctx);
                q[i] = part.probability_weight(&prepared[i], rho);
            }
            sum += q[i];
        }
        let p = if sum > 0.0 {
            q.map(|x| x / sum)
        } else {
            [0.0; PARTS]
        };
        let mut shares = [[0.0f32; LOBES_PER_PART]; PARTS];
        for i in 0..PARTS {
            if uses[i].local {
                shares[i] = parts[i].shares(&prepared[i], rho);
            }
        }
        Self {
            rho,
            uses,
            any_local: uses.iter().any(|u| u.local),
            any_transmits_glossy: uses.iter().any(|u| u.transmits_glossy),
            p,
            prepared,
            shares,
        }
    }

    /// [`BsdfAt::pdf`] through the parts.
    #[inline]
    fn pdf(&self, bsdf: &Bsdf, wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
        if !self.any_local {
            return 0.0;
        }
        let below = fr.ns.dot(wi) <= 0.0 || fr.ng.dot(wi) <= 0.0;
        let ctx = LobeContext {
            wo,
            fr,
            tint: bsdf.color(),
        };
        let mut pdf = 0.0f32;
        for (i, part) in bsdf.parts().iter().enumerate() {
            let prob = self.p[i];
            if !self.uses[i].local || prob == 0.0 || (below && !self.uses[i].transmits_glossy) {
                continue;
            }
            let mut d = 0.0f32;
            for (lobe, &share) in part.lobes().zip(&self.shares[i]) {
                if share > 0.0 {
                    d += lobe.pdf(&ctx, wi, share);
                }
            }
            pdf += prob * d;
        }
        pdf
    }

    /// [`BsdfAt::sample`]'s walk: the part holding `u_lobe`, then (non-delta) its lobe by share
    /// and that lobe's direction with the index of refraction of a transmitting glossy lobe
    /// in radiance mode, or (delta) the lobe's own sample.
    #[allow(clippy::too_many_arguments)]
    #[inline]
    fn sample(
        &self,
        bsdf: &Bsdf,
        wo: Vec3,
        u_lobe: f32,
        u: (f32, f32),
        fr: &ShadingFrame,
        mode: TransportMode,
    ) -> Option<(Sampled, Option<f32>)> {
        let parts = bsdf.parts();
        let ctx = LobeContext {
            wo,
            fr,
            tint: bsdf.color(),
        };
        // Walk the parts: the first whose interval holds u_lobe, else (rounding) the last of
        // non-zero weight; `rest` is u_lobe less the probabilities before the part.
        let mut chosen = None;
        let mut cum = 0.0f32;
        let mut rest = u_lobe;
        let mut rests = [0.0f32; PARTS];
        for (i, (slot, &p)) in rests.iter_mut().zip(&self.p).enumerate() {
            *slot = rest;
            if u_lobe < cum + p {
                chosen = Some(i);
                break;
            }
            cum += p;
            rest -= p;
        }
        let i = chosen.or_else(|| parts.iter().rposition(|p| p.weight > 0.0))?;
        let part = &parts[i];
        let v = rests[i] / self.p[i];
        // A chosen part has weight, so it is delta exactly when it is not local.
        if !self.uses[i].local {
            let lobe = part.lobes().next()?;
            let draw = LobeDraw {
                prepared: &self.prepared[i],
                rho: self.rho,
                v,
                u,
                mode,
                weight: part.weight,
                prob: self.p[i],
            };
            return match lobe.sample(&ctx, &draw)? {
                LobeSample::Delta(s) => Some((Sampled::Delta(s), None)),
                // A delta part's lobe is a delta lobe (parts never mix).
                LobeSample::Direction(_) => None,
            };
        }
        // A non-delta part: reuse the lobe number to pick one of its lobes.
        let mut lobe = None;
        let mut cum = 0.0f32;
        let mut rest = v;
        for (l, &share) in part.lobes().zip(&self.shares[i]) {
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
        let draw = LobeDraw {
            prepared: &self.prepared[i],
            rho: self.rho,
            v: rest,
            u,
            mode,
            weight: part.weight,
            prob: self.p[i],
        };
        let wi = match lobe.sample(&ctx, &draw)? {
            LobeSample::Direction(wi) => wi,
            // A non-delta part's lobes are non-delta (parts never mix).
            LobeSample::Delta(_) => return None,
        };
        let ior = lobe.ior().filter(|_| mode == TransportMode::Radiance);
        Some((Sampled::Direction(wi), ior))
    }
}

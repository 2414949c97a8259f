//! The material model as a BSDF (docs/material.md): a weighted mix of a Lambert + normalised-Phong
//! part, a tinted perfect mirror and a smooth Fresnel dielectric. Every integrator evaluates,
//! samples and asks densities of it through here, in radiance mode (camera paths) or importance
//! mode (light and photon paths), so that all of them converge to the same image.
//!
//! Conventions follow pbrt-v4 (Pharr, Jakob, Humphreys, *Physically Based Rendering*, 4th ed.,
//! §9.1–9.5) and Veach's thesis (1997, §5.2–5.3): `wo` is the direction the path arrived from
//! (towards the camera for radiance, towards the light for importance), `wi` the direction it
//! continues in; both unit and pointing away from the surface.

use glam::Vec3;
use std::f32::consts::{FRAC_1_PI, TAU};

use super::optics::{fresnel_dielectric, reflect, refract};
use crate::geometry::Frame;
use crate::sampling::warp::cosine_hemisphere;

/// A compiled material's scattering function; the three weights are normalised to sum to 1.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bsdf {
    /// Diffuse albedo; also tints the mirror and transmitted light.
    pub color: Vec3,
    /// Reflectance of the normalised Phong lobe.
    pub specular: Vec3,
    /// Phong exponent.
    pub shininess: f32,
    /// Weight of the diffuse + Phong part.
    pub diffuse: f32,
    /// Weight of the perfect mirror.
    pub reflect: f32,
    /// Weight of the smooth dielectric.
    pub transmit: f32,
    /// Index of refraction of the inside relative to the outside.
    pub ior: f32,
}

/// Which quantity a path carries (pbrt-v4's `TransportMode`; Veach 1997, §5.2).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum TransportMode {
    /// Camera paths carry radiance: crossing from the side of index ηₒ to the side of index ηᵢ
    /// scales it by (ηₒ/ηᵢ)² (radiance is not conserved across a refracting boundary).
    Radiance,
    /// Light and photon paths carry flux (importance): no η² scaling, and the adjoint
    /// shading-normal correction [`shading_normal_correction`] applies.
    Importance,
}

/// The local frame a BSDF is evaluated in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShadingFrame {
    /// Unit shading normal on the side of `wo`.
    pub ns: Vec3,
    /// Unit geometric normal on the side of `wo`.
    pub ng: Vec3,
    /// Whether `wo` is on the outside of the object (the side its geometric normal points to),
    /// so that a transmitted path goes from index 1 to index `ior`.
    pub entering: bool,
}

/// A direction sampled from the BSDF.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BsdfSample {
    /// Unit direction the path continues in.
    pub wi: Vec3,
    /// The path throughput multiplier `f · |ns·wi| / pdf` (times the adjoint correction in
    /// importance mode, and the η² factor of a refraction in radiance mode).
    pub weight: Vec3,
    /// Solid-angle density of `wi` (per steradian) for a non-delta sample; for a delta lobe, the
    /// discrete probability of having chosen it.
    pub pdf: f32,
    /// The sample came from a mirror or the dielectric (a Dirac delta in direction).
    pub delta: bool,
    /// The path crossed the surface (refraction).
    pub transmitted: bool,
    /// The radiance-mode factor (ηₒ/ηᵢ)² included in `weight` (1 unless refracted in radiance
    /// mode); path tracers divide it out again for Russian roulette.
    pub eta_scale: f32,
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
}

/// The dielectric's split at one incidence: Fresnel reflectance, refracted direction (if any)
/// and the relative index `eta = ηₒ/ηᵢ` of the crossing.
struct Dielectric {
    fresnel: f32,
    refracted: Option<Vec3>,
    eta: f32,
}

/// Mean of the three channels: how lobes are weighed against each other when sampling.
#[inline]
fn mean(c: Vec3) -> f32 {
    (c.x + c.y + c.z) * (1.0 / 3.0)
}

/// Veach's adjoint correction for shading normals (thesis §5.3, eq. 5.19): the factor
/// `|wo·ns| |wi·ng| / (|wo·ng| |wi·ns|)` that makes light paths that scatter at a point with a
/// shading normal carry the flux that the camera-side BSDF (with `|wi·ns|`) implies. 1 when
/// `ns == ng`; 0 when `wo` grazes the geometric surface.
#[inline]
#[must_use]
pub fn shading_normal_correction(wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
    let num = wo.dot(fr.ns).abs() * wi.dot(fr.ng).abs();
    let den = wo.dot(fr.ng).abs() * wi.dot(fr.ns).abs();
    if den > 0.0 { num / den } else { 0.0 }
}

impl Bsdf {
    /// Builds a BSDF, normalising the weights (`None` ones count as 0; all `None` means diffuse).
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
        Self {
            color,
            specular,
            shininess,
            diffuse: w[0],
            reflect: w[1],
            transmit: w[2],
            ior,
        }
    }

    /// True if the BSDF has a non-delta (diffuse or glossy) part that direct lighting sees.
    #[inline]
    #[must_use]
    pub fn has_local(&self) -> bool {
        self.diffuse > 0.0
    }

    /// True if the BSDF has mirror or dielectric parts.
    #[inline]
    #[must_use]
    pub fn has_delta(&self) -> bool {
        self.reflect > 0.0 || self.transmit > 0.0
    }

    /// The non-delta part `f(wo, wi)` (per steradian) with `n` the shading normal on the side of
    /// `wo`: `diffuse · (ρ/π + k_s (m+2)/(2π) max(0, r·wi)^m)`, `r` the mirror of `wo`.
    /// Zero when `wi` is below `n`. Symmetric in `wo` and `wi` (reciprocal).
    #[inline]
    #[must_use]
    pub fn f(&self, wo: Vec3, wi: Vec3, n: Vec3) -> Vec3 {
        if self.diffuse == 0.0 || n.dot(wi) <= 0.0 {
            return Vec3::ZERO;
        }
        let mut f = self.color * FRAC_1_PI;
        if self.specular != Vec3::ZERO {
            let cos_a = reflect(wo, n).dot(wi).max(0.0);
            f += self.specular * ((self.shininess + 2.0) / TAU * cos_a.powf(self.shininess));
        }
        f * self.diffuse
    }

    /// The non-delta BSDF value in frame `fr`, for `wi` above both the shading and the geometric
    /// surface (else 0: no light through a surface whose shading normal leans towards it). In
    /// importance mode it includes [`shading_normal_correction`], so `eval · |ns·wi|` is the
    /// flux throughput of a light path in either mode.
    #[inline]
    #[must_use]
    pub fn eval(&self, wo: Vec3, wi: Vec3, fr: &ShadingFrame, mode: TransportMode) -> Vec3 {
        if fr.ng.dot(wi) <= 0.0 {
            return Vec3::ZERO;
        }
        let f = self.f(wo, wi, fr.ns);
        match mode {
            TransportMode::Radiance => f,
            TransportMode::Importance => f * shading_normal_correction(wo, wi, fr),
        }
    }

    /// Whether [`Bsdf::sample`]'s lobe number `u_lobe` can change its result: false for a
    /// single lobe (pure Lambert, pure Phong, a pure mirror, or black), so integrators need not
    /// draw it (`Sampler::defer_1d`). Any dielectric part, or two parts of non-zero weight,
    /// make it matter.
    #[inline]
    #[must_use]
    pub fn lobe_choice_matters(&self) -> bool {
        let diffuse = self.diffuse > 0.0;
        self.transmit > 0.0
            || (diffuse && self.reflect > 0.0)
            || (diffuse && self.specular != Vec3::ZERO && self.color != Vec3::ZERO)
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

    /// Probabilities of sampling the diffuse part, the mirror and the dielectric (summing to 1,
    /// or all 0 for a black BSDF), and within the diffuse part the Lambert lobe's share.
    #[inline]
    fn lobe_probabilities(&self, fresnel: f32) -> ([f32; 3], f32) {
        let rho = mean(self.color);
        let ks = mean(self.specular);
        let q = [
            self.diffuse * (rho + ks),
            self.reflect * rho,
            self.transmit * (fresnel + (1.0 - fresnel) * rho),
        ];
        let sum = q[0] + q[1] + q[2];
        let lambert = if rho + ks > 0.0 {
            rho / (rho + ks)
        } else {
            1.0
        };
        if sum > 0.0 {
            (q.map(|x| x / sum), lambert)
        } else {
            ([0.0; 3], lambert)
        }
    }

    /// The dielectric's Fresnel split for `wo` in frame `fr`.
    #[inline]
    fn dielectric(&self, wo: Vec3, fr: &ShadingFrame) -> Dielectric {
        let eta = if fr.entering {
            1.0 / self.ior
        } else {
            self.ior
        };
        let fresnel = fresnel_dielectric(fr.ns.dot(wo), eta);
        let refracted = if fresnel < 1.0 {
            refract_below(wo, fr.ns, fr.ng, eta)
        } else {
            None
        };
        Dielectric {
            fresnel: if refracted.is_some() { fresnel } else { 1.0 },
            refracted,
            eta,
        }
    }

    /// The Fresnel reflectance the sampler weighs the dielectric with (only when it transmits).
    #[inline]
    fn sampling_fresnel(&self, wo: Vec3, fr: &ShadingFrame) -> f32 {
        if self.transmit > 0.0 {
            self.dielectric(wo, fr).fresnel
        } else {
            0.0
        }
    }

    /// Density of the normalised Phong sampling lobe around `r` at `wi` (per steradian).
    #[inline]
    fn phong_pdf(&self, r: Vec3, wi: Vec3) -> f32 {
        let c = r.dot(wi);
        if c <= 0.0 {
            return 0.0;
        }
        (self.shininess + 1.0) / TAU * c.powf(self.shininess)
    }

    /// Solid-angle density with which [`Bsdf::sample`] returns the non-delta direction `wi`
    /// (0 below the shading or geometric surface, where `sample` returns nothing). Delta lobes
    /// have no density; their discrete probabilities are in the samples themselves.
    #[must_use]
    pub fn pdf(&self, wo: Vec3, wi: Vec3, fr: &ShadingFrame) -> f32 {
        if self.diffuse == 0.0 {
            return 0.0;
        }
        let (p, lambert) = self.lobe_probabilities(self.sampling_fresnel(wo, fr));
        self.diffuse_pdf(p[0], lambert, wo, wi, fr)
    }

    /// [`Bsdf::pdf`] given the diffuse part's probability `p_diffuse` and Lambert's share in
    /// it (so `sample`, which has them, does not recompute the Fresnel split).
    #[inline]
    fn diffuse_pdf(
        &self,
        p_diffuse: f32,
        lambert: f32,
        wo: Vec3,
        wi: Vec3,
        fr: &ShadingFrame,
    ) -> f32 {
        if p_diffuse == 0.0 || fr.ns.dot(wi) <= 0.0 || fr.ng.dot(wi) <= 0.0 {
            return 0.0;
        }
        let mut d = lambert * fr.ns.dot(wi) * FRAC_1_PI;
        if lambert < 1.0 {
            d += (1.0 - lambert) * self.phong_pdf(reflect(wo, fr.ns), wi);
        }
        p_diffuse * d
    }

    /// Samples a direction for a path arriving from `wo`: a lobe chosen with `u_lobe` (the
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
        let diel = (self.transmit > 0.0).then(|| self.dielectric(wo, fr));
        let fresnel = diel.as_ref().map_or(0.0, |d| d.fresnel);
        let (p, lambert) = self.lobe_probabilities(fresnel);
        if u_lobe < p[0] {
            // Diffuse + Phong part; reuse the lobe number to pick Lambert or Phong.
            let v = u_lobe / p[0];
            let wi = if v < lambert {
                cosine_hemisphere(u, fr.ns)
            } else {
                let r = reflect(wo, fr.ns);
                let cos_a = u.0.powf(1.0 / (self.shininess + 1.0));
                let sin_a = (1.0 - cos_a * cos_a).max(0.0).sqrt();
                let phi = TAU * u.1;
                Frame::from_normal(r).to_world(Vec3::new(
                    sin_a * phi.cos(),
                    sin_a * phi.sin(),
                    cos_a,
                ))
            };
            let pdf = self.diffuse_pdf(p[0], lambert, wo, wi, fr);
            let f = self.eval(wo, wi, fr, mode);
            if !(pdf > 0.0) || f == Vec3::ZERO {
                return None;
            }
            return Some(BsdfSample {
                wi,
                weight: f * (fr.ns.dot(wi) / pdf),
                pdf,
                delta: false,
                transmitted: false,
                eta_scale: 1.0,
            });
        }
        let correct = |wi: Vec3| match mode {
            TransportMode::Radiance => 1.0,
            TransportMode::Importance => shading_normal_correction(wo, wi, fr),
        };
        if u_lobe < p[0] + p[1] || diel.is_none() {
            if p[1] == 0.0 {
                return None;
            }
            let wi = mirror_above(wo, fr.ns, fr.ng);
            return Some(BsdfSample {
                wi,
                weight: self.color * (self.reflect / p[1] * correct(wi)),
                pdf: p[1],
                delta: true,
                transmitted: false,
                eta_scale: 1.0,
            });
        }
        let d = diel?;
        // Inside the dielectric: reflect with probability F / (F + (1 − F)ρ̄).
        let rho = mean(self.color);
        let denom = d.fresnel + (1.0 - d.fresnel) * rho;
        let p_reflect = if denom > 0.0 { d.fresnel / denom } else { 1.0 };
        let v = (u_lobe - p[0] - p[1]) / p[2];
        match d.refracted {
            Some(wt) if v >= p_reflect => {
                let pdf = p[2] * (1.0 - p_reflect);
                let (scale, eta_scale) = match mode {
                    TransportMode::Radiance => (d.eta * d.eta, d.eta * d.eta),
                    TransportMode::Importance => (correct(wt), 1.0),
                };
                Some(BsdfSample {
                    wi: wt,
                    weight: self.color * (self.transmit * (1.0 - d.fresnel) * scale / pdf),
                    pdf,
                    delta: true,
                    transmitted: true,
                    eta_scale,
                })
            }
            _ => {
                let wi = mirror_above(wo, fr.ns, fr.ng);
                let pdf = p[2] * p_reflect;
                if !(pdf > 0.0) {
                    return None;
                }
                Some(BsdfSample {
                    wi,
                    weight: Vec3::splat(self.transmit * d.fresnel / pdf * correct(wi)),
                    pdf,
                    delta: true,
                    transmitted: false,
                    eta_scale: 1.0,
                })
            }
        }
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
        if self.transmit == 0.0 {
            return Vec3::ZERO;
        }
        let eta2 = if entering {
            1.0 / (self.ior * self.ior)
        } else {
            self.ior * self.ior
        };
        self.color * (self.transmit * (1.0 - fresnel_dielectric(cos, 1.0 / self.ior)) * eta2)
    }

    /// The mirror and dielectric lobes at a point in radiance mode (for Whitted, which follows
    /// every delta branch). `n` is the shading normal and `ng` the geometric normal, both on the
    /// side of `wo`; `entering` says whether `wo` is outside the object.
    #[must_use]
    pub fn delta_lobes(&self, wo: Vec3, n: Vec3, ng: Vec3, entering: bool) -> DeltaLobes {
        let reflect_dir = mirror_above(wo, n, ng);
        let mut reflect_weight = self.color * self.reflect;
        let mut refracted = None;
        if self.transmit > 0.0 {
            let fr = ShadingFrame {
                ns: n,
                ng,
                entering,
            };
            let d = self.dielectric(wo, &fr);
            reflect_weight += Vec3::splat(self.transmit * d.fresnel);
            if let Some(dir) = d.refracted {
                let w = self.transmit * (1.0 - d.fresnel) * d.eta * d.eta;
                refracted = Some((dir, self.color * w));
            }
        }
        DeltaLobes {
            reflect_dir,
            reflect_weight,
            refract: refracted,
        }
    }
}

/// Mirror of `wo` about `n`, replaced by the mirror about `ng` if it would go below the geometric
/// surface (shading normals must not send rays into the surface they leave).
#[inline]
fn mirror_above(wo: Vec3, n: Vec3, ng: Vec3) -> Vec3 {
    let r = reflect(wo, n);
    if r.dot(ng) > 0.0 { r } else { reflect(wo, ng) }
}

/// Refraction of `wo` through `n`, replaced by refraction through `ng` if the result would not
/// cross the geometric surface.
#[inline]
fn refract_below(wo: Vec3, n: Vec3, ng: Vec3, eta: f32) -> Option<Vec3> {
    match refract(wo, n, eta) {
        Some(t) if t.dot(ng) < 0.0 => Some(t),
        _ => refract(wo, ng, eta).filter(|t| t.dot(ng) < 0.0),
    }
}

#[cfg(test)]
#[path = "bsdf_tests.rs"]
mod tests;

//! Next-event estimation along a medium segment by equiangular sampling (Kulla & Fajardo,
//! "Importance Sampling Techniques for Path Tracing in Participating Media", EGSR 2012),
//! combined with the free-flight vertex's own estimate by multiple importance sampling.
//!
//! The light that light sampling carries to a segment `[0, s)` of a camera path in a scattering
//! medium is `I = Σ_j ∫₀ˢ f_j(t) dt`, `f_j(t) = T(t) σs · (phase · L_e · T_shadow · w_L / pdf_l)`
//! for light `j`, `w_L` the power heuristic of light against phase sampling at the point (the
//! part of the direct light that phase sampling does not carry: unchanged). Two strategies
//! sample `(j, t)`:
//! - **distance**: the free-flight event `t` (density `p_d(t)`, `HomogeneousMedium::scatter_pdf`)
//!   and the light chosen there (`pmf(j | x(t))`): density `p_d(t) · pmf(j | x(t))`;
//! - **equiangular**: the light chosen at the segment's start (`pmf(j | o)`) and `t` drawn
//!   equiangularly toward its centre (`sampling::equiangular`, density `p_e(t | j)`): density
//!   `pmf(j | o) · p_e(t | j)`.
//!
//! Each sample is weighted by the power heuristic over the two (Veach 1997; the combination of
//! the paper's §4.2), so their sum estimates `I` without bias. Near a small light, where `f_j`
//! peaks as `1/r²`, the equiangular sample carries the estimate; far from it (and for lights
//! without a centre: the density is 0 there) the free-flight sample does. Lights with a centre:
//! point, spot and sphere lights; area lights of other shapes and lights at infinity keep
//! distance sampling alone.

use glam::Vec3;

use super::PathTracer;
use super::power_heuristic;
use crate::integrators::context::{Context, PathObserver};
use crate::render_scene::{HomogeneousMedium, Light, Medium};
use crate::sampling::equiangular::Equiangular;

/// A camera-path segment in a scattering medium where the path may still scatter: where the
/// two strategies apply.
#[derive(Debug, Clone, Copy)]
pub(super) struct MediumSegment {
    /// The segment's start.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
    /// Its length (metres; infinite for a ray that escapes).
    pub t_max: f32,
    /// The medium's longest mean free path over the channels, `1 / min_c σt,c` (metres).
    pub mean_free_path: f32,
}

/// Equiangular sampling is used for a light on a segment that passes within `NEAR` times
/// `min(length, mean free path)` of its centre. Farther, `1/r²` varies little over the part of
/// the segment where free flights land and equiangular sampling would gain little for its
/// shadow ray (in the foggy box, applied on every segment it halved the variance away from the
/// light's silhouette for twice the CPU time). The choice is made from the segment before
/// anything is sampled on it, and both strategies' weights make it alike (the equiangular
/// density is 0 where it is not used), so the estimate stays unbiased.
const NEAR: f32 = 0.25;

/// The point equiangular sampling aims at for light `light`: the centre of a point, spot or
/// sphere light; `None` for lights without one (area lights of other shapes are sampled by
/// distance alone: their centre is a poor stand-in where they are large, and lights at
/// infinity have none).
#[must_use]
pub(super) fn equiangular_center(light: &Light) -> Option<Vec3> {
    match light {
        Light::Point { position, .. } => Some(*position),
        Light::Sphere { center, .. } => Some(*center),
        Light::Spot(s) => Some(s.position),
        Light::Rect(_)
        | Light::Mesh(_)
        | Light::Quadric(_)
        | Light::Distant(_)
        | Light::Environment(_)
        | Light::Sky(_) => None,
    }
}

impl PathTracer<'_> {
    /// The equiangular sampler of `seg` toward light `index`'s centre, if it has one and the
    /// segment passes close to it ([`NEAR`]).
    #[inline]
    fn equiangular(&self, seg: &MediumSegment, index: usize) -> Option<Equiangular> {
        let c = equiangular_center(&self.scene.lights[index])?;
        let along = (c - seg.origin).dot(seg.dir).clamp(0.0, seg.t_max);
        let closest = (seg.origin + seg.dir * along - c).length();
        if !(closest < NEAR * seg.t_max.min(seg.mean_free_path)) {
            return None;
        }
        Equiangular::new(seg.origin, seg.dir, 0.0, seg.t_max, c)
    }

    /// The MIS weight of the free-flight vertex `t` metres along `seg` whose next-event
    /// estimate chose light `index` with probability `pmf` there (module docs): `p_d pmf`
    /// against `pmf(j | o) p_e(t | j)`; 1 when the light has no centre.
    #[inline]
    pub(super) fn free_flight_weight(
        &self,
        seg: &MediumSegment,
        m: &HomogeneousMedium,
        t: f32,
        index: usize,
        pmf: f32,
    ) -> f32 {
        let Some(eq) = self.equiangular(seg, index) else {
            return 1.0;
        };
        let other = self.lights.pmf(seg.origin, index) * eq.pdf(t);
        power_heuristic(pmf * m.scatter_pdf(t), other)
    }

    /// The equiangular strategy's estimate for `seg` in medium `m` (the path's volumes
    /// `medium`), to be multiplied by the path weight at the segment's start: a light chosen at
    /// the start, a point drawn toward its centre, next-event estimation there
    /// ([`PathTracer::direct_in_medium`]), times `T(t) σs`, over the sample's density, MIS-
    /// weighted against free-flight sampling (module docs). Draws four sampler dimensions
    /// whatever happens.
    pub(super) fn equiangular_direct<O: PathObserver>(
        &self,
        seg: &MediumSegment,
        m: &HomogeneousMedium,
        medium: Medium,
        cx: &mut Context<'_, O>,
    ) -> Vec3 {
        let u_light = cx.sampler.next_1d();
        let u_t = cx.sampler.next_1d();
        let u_point = cx.sampler.next_2d();
        let Some((index, pmf_o)) = self.lights.choose(seg.origin, || u_light) else {
            return Vec3::ZERO;
        };
        let Some(eq) = self.equiangular(seg, index) else {
            return Vec3::ZERO;
        };
        let t = eq.sample(u_t);
        if !(t >= 0.0 && t < seg.t_max) {
            return Vec3::ZERO;
        }
        let p = seg.origin + seg.dir * t;
        // The light choice free-flight sampling's vertex would make here; with none, phase
        // sampling carries all of this light's contribution at `p` (its emitter-hit weight
        // is then 1), and light sampling none.
        let pmf_p = self.lights.pmf(p, index);
        if !(pmf_p > 0.0) {
            return Vec3::ZERO;
        }
        let pdf_e = pmf_o * eq.pdf(t);
        let w = power_heuristic(pdf_e, pmf_p * m.scatter_pdf(t));
        if !(pdf_e > 0.0) || w == 0.0 {
            return Vec3::ZERO;
        }
        // direct_in_medium divides by pmf_p (the free-flight vertex's choice); this sample's
        // light was chosen with pmf_o, and its point with p_e.
        let c = self.direct_in_medium(p, seg.dir, m, medium, index, pmf_p, u_point, cx);
        c * m.sigma_s * m.transmittance(t) * (w * pmf_p / pdf_e)
    }
}

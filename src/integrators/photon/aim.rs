//! Aiming caustic photons at the objects that can focus light: Jensen's projection maps
//! ("Realistic Image Synthesis Using Photon Mapping", 2001, §5.3), with each specular object's
//! projection taken as the cone of directions its bounding sphere subtends from the emitting
//! point.
//!
//! Directions are drawn from the mixture of the cones, each chosen in proportion to its solid
//! angle Ωⱼ times the target's specular share wⱼ (reflect + transmit weight: a wall that mirrors
//! 6 % gets 6 % of a glass ball's photons per steradian) and sampled uniformly inside. The
//! mixture's density at a direction `w` is `Σⱼ (wⱼΩⱼ/Σ wΩ)·[w ∈ coneⱼ]/Ωⱼ = Σ_{j ∋ w} wⱼ / Σ wΩ`,
//! so overlapping cones stay unbiased. A photon's flux divides by that density: the solid-angle
//! fraction of the light that the cones cover is in every photon's flux. A light inside a
//! bounding sphere gets that target's cone as the whole sphere.

use glam::{DAffine3, Vec3};
use std::f32::consts::TAU;

use crate::geometry::Frame;
use crate::render_scene::RenderScene;

/// Bounding spheres (centre, radius) of every object whose material has a mirror or dielectric
/// part, each with the weight of that part (its share of the material's normalised weights):
/// where caustic photons are sent.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CausticTargets {
    spheres: Vec<(Vec3, f32, f32)>,
}

/// One cone of directions from an emitting point towards a target.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct AimCone {
    /// Unit axis, from the emitting point to the target's centre.
    pub axis: Vec3,
    /// `1 − cos θmax` of the half-angle (in `(0, 2]`; 2 is the whole sphere).
    pub one_minus_cos: f32,
    /// Relative weight of the target (its specular share): cones are chosen in proportion to
    /// `weight · Ω`.
    pub weight: f32,
}

/// Bounds of one object's primitives while they are gathered.
#[derive(Debug, Clone, Copy)]
enum ObjectBounds {
    /// A single sphere primitive (bounded exactly).
    Sphere(Vec3, f32),
    /// Several primitives, or triangles: an axis-aligned box.
    Box(Vec3, Vec3),
}

impl ObjectBounds {
    fn add_box(self, lo: Vec3, hi: Vec3) -> Self {
        let (a, b) = match self {
            ObjectBounds::Sphere(c, r) => (c - Vec3::splat(r), c + Vec3::splat(r)),
            ObjectBounds::Box(a, b) => (a, b),
        };
        ObjectBounds::Box(a.min(lo), b.max(hi))
    }

    fn sphere(self) -> (Vec3, f32) {
        match self {
            ObjectBounds::Sphere(c, r) => (c, r),
            ObjectBounds::Box(lo, hi) => ((lo + hi) * 0.5, (hi - lo).length() * 0.5),
        }
    }
}

/// Axis-aligned bounds of a unit sphere under an affine map: the half-extent along world axis
/// `i` is the length of row `i` of the linear part.
fn ellipsoid_box(m: &DAffine3) -> (Vec3, Vec3) {
    let c = m.translation.as_vec3();
    let rows = m.matrix3.transpose();
    let half = Vec3::new(
        rows.x_axis.length() as f32,
        rows.y_axis.length() as f32,
        rows.z_axis.length() as f32,
    );
    (c - half, c + half)
}

impl CausticTargets {
    /// The bounding sphere of every object whose material reflects or transmits (has a delta
    /// lobe), and, with `near_specular` (a GGX width), of every object whose material is
    /// near-specular ([`crate::shading::Bsdf::is_near_specular`]), whole. Emitters and purely
    /// diffuse objects are not targets.
    #[must_use]
    pub fn new(scene: &RenderScene, near_specular: Option<f32>) -> Self {
        // The specular share of each object's material (0: not a target).
        let share: Vec<f32> = scene
            .objects
            .iter()
            .map(|o| {
                o.material.map_or(0.0, |m| {
                    let m = &scene.materials[m as usize];
                    // An interface (no surface, docs/media.md) focuses nothing.
                    if m.interior.interface {
                        0.0
                    } else {
                        m.bsdf.focusing_share(near_specular)
                    }
                })
            })
            .collect();
        let is_target: Vec<bool> = share.iter().map(|&s| s > 0.0).collect();
        let mut bounds: Vec<Option<ObjectBounds>> = vec![None; scene.objects.len()];
        let g = &scene.geometry;
        let mut add = |object: u32, b: ObjectBounds| {
            let Some(slot) = bounds.get_mut(object as usize) else {
                return;
            };
            if !is_target[object as usize] {
                return;
            }
            *slot = Some(match (*slot, b) {
                (None, b) => b,
                (Some(old), ObjectBounds::Box(lo, hi)) => old.add_box(lo, hi),
                (Some(old), ObjectBounds::Sphere(c, r)) => {
                    old.add_box(c - Vec3::splat(r), c + Vec3::splat(r))
                }
            });
        };
        for (tri, attrs) in g.triangles.iter().zip(&g.tri_attrs) {
            let lo = tri[0].min(tri[1]).min(tri[2]);
            let hi = tri[0].max(tri[1]).max(tri[2]);
            add(attrs.object, ObjectBounds::Box(lo, hi));
        }
        for s in &g.spheres {
            add(s.object, ObjectBounds::Sphere(s.center, s.radius));
        }
        for e in &g.ellipsoids {
            let (lo, hi) = ellipsoid_box(&e.world_from_object);
            add(e.object, ObjectBounds::Box(lo, hi));
        }
        for q in &g.quadrics {
            let b = q.bounds();
            add(q.object, ObjectBounds::Box(b.min, b.max));
        }
        let spheres = bounds
            .into_iter()
            .zip(share)
            .filter_map(|(b, s)| b.map(|b| (b.sphere(), s)))
            .map(|((c, r), s)| (c, r, s))
            .filter(|(c, r, _)| c.is_finite() && r.is_finite())
            .collect();
        Self { spheres }
    }

    /// Targets from explicit bounding spheres of equal weight (tests, tools).
    #[must_use]
    pub fn from_spheres(spheres: Vec<(Vec3, f32)>) -> Self {
        Self {
            spheres: spheres.into_iter().map(|(c, r)| (c, r, 1.0)).collect(),
        }
    }

    /// True if the scene has nothing that can focus light (no caustic map can be built).
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.spheres.is_empty()
    }

    /// Number of targets.
    #[must_use]
    pub fn len(&self) -> usize {
        self.spheres.len()
    }

    /// The cones the targets subtend from `from`, written into `out` (cleared first); returns
    /// their weighted total solid angle Σ wⱼΩⱼ (sr). A target that contains `from` gives the
    /// whole sphere.
    pub fn cones(&self, from: Vec3, out: &mut Vec<AimCone>) -> f32 {
        out.clear();
        let mut total = 0.0;
        for &(c, r, weight) in &self.spheres {
            let d = c - from;
            let dist2 = d.length_squared();
            let cone = if dist2 <= r * r || dist2 == 0.0 {
                AimCone {
                    axis: Vec3::Z,
                    one_minus_cos: 2.0,
                    weight,
                }
            } else {
                let sin2 = (r * r / dist2).min(1.0);
                let cos = (1.0 - sin2).max(0.0).sqrt();
                AimCone {
                    axis: d / dist2.sqrt(),
                    // 1 − cos written as sin²/(1 + cos): exact for tiny cones.
                    one_minus_cos: sin2 / (1.0 + cos),
                    weight,
                }
            };
            total += weight * TAU * cone.one_minus_cos;
            out.push(cone);
        }
        total
    }
}

impl CausticTargets {
    /// A line along unit `dir` (a photon of a light at infinity) through the targets: target
    /// j is chosen with probability `wⱼ π rⱼ² / Σ w π r²` and a uniform point `x` of its
    /// bounding sphere's cross-section perpendicular to `dir` (concentric map of `u`). Returns
    /// `x` and the mixture's density over the plane perpendicular to `dir`,
    /// `Σ_{k: line meets sphere k} wₖ / Σ w π r²` (1/m²), so overlapping projections stay
    /// unbiased (the same argument as the cones'). `None` without targets.
    #[must_use]
    pub fn sample_crossing(&self, dir: Vec3, u_pick: f32, u: (f32, f32)) -> Option<(Vec3, f32)> {
        let area = |r: f32| std::f32::consts::PI * r * r;
        let total: f32 = self.spheres.iter().map(|&(_, r, w)| w * area(r)).sum();
        if self.spheres.is_empty() || !(total > 0.0) {
            return None;
        }
        let mut target = u_pick * total;
        let mut chosen = self.spheres.len() - 1;
        for (j, &(_, r, w)) in self.spheres.iter().enumerate() {
            if target < w * area(r) {
                chosen = j;
                break;
            }
            target -= w * area(r);
        }
        let (c, r, _) = self.spheres[chosen];
        let (a, b) = crate::sampling::warp::concentric_disk(u);
        let f = Frame::from_normal(dir);
        let x = c + (f.s * a + f.t * b) * r;
        // The chosen sphere counts even where rounding puts the line a hair outside it.
        let weight: f32 = self
            .spheres
            .iter()
            .enumerate()
            .filter(|&(j, &(ck, rk, _))| j == chosen || line_meets(x, dir, ck, rk))
            .map(|(_, &(_, _, w))| w)
            .sum();
        Some((x, weight / total))
    }

    /// The density [`CausticTargets::sample_crossing`] gives the line along unit `dir` through
    /// `x` (1/m²).
    #[must_use]
    pub fn crossing_pdf(&self, dir: Vec3, x: Vec3) -> f32 {
        let total: f32 = self
            .spheres
            .iter()
            .map(|&(_, r, w)| w * std::f32::consts::PI * r * r)
            .sum();
        if !(total > 0.0) {
            return 0.0;
        }
        self.spheres
            .iter()
            .filter(|&&(c, r, _)| line_meets(x, dir, c, r))
            .map(|&(_, _, w)| w)
            .sum::<f32>()
            / total
    }
}

/// True if the line through `x` along unit `dir` passes within `r` of `c` (a relative slack of
/// a few ulps at the rim).
#[inline]
fn line_meets(x: Vec3, dir: Vec3, c: Vec3, r: f32) -> bool {
    let v = c - x;
    let lateral2 = (v - dir * v.dot(dir)).length_squared();
    lateral2 <= r * r * (1.0 + 1e-5) + 1e-12
}

/// Samples a direction from the mixture of `cones` (of weighted total solid angle `total`, as
/// returned by [`CausticTargets::cones`]) with `u_pick ∈ [0, 1)` choosing cone j with
/// probability `wⱼΩⱼ / total` and `u` the direction, uniform in it; returns the direction and
/// the mixture's solid-angle density there, `Σ_{j ∋ w} wⱼ / total` (1/sr). `None` without cones.
#[must_use]
pub fn sample_cones(
    cones: &[AimCone],
    total: f32,
    u_pick: f32,
    u: (f32, f32),
) -> Option<(Vec3, f32)> {
    if cones.is_empty() || !(total > 0.0) {
        return None;
    }
    let mut target = u_pick * total;
    let mut chosen = cones.len() - 1;
    for (j, c) in cones.iter().enumerate() {
        let omega = c.weight * TAU * c.one_minus_cos;
        if target < omega {
            chosen = j;
            break;
        }
        target -= omega;
    }
    let c = cones[chosen];
    let one_minus_cos = (u.0 * c.one_minus_cos).min(c.one_minus_cos);
    let cos_t = 1.0 - one_minus_cos;
    let sin_t = (one_minus_cos * (2.0 - one_minus_cos)).max(0.0).sqrt();
    let phi = TAU * u.1;
    let dir = Frame::from_normal(c.axis)
        .to_world(Vec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t))
        .normalize();
    // The chosen cone contains the direction even where rounding puts it a hair outside.
    let weight: f32 = cones
        .iter()
        .enumerate()
        .filter(|&(j, k)| j == chosen || contains(k, dir))
        .map(|(_, k)| k.weight)
        .sum();
    Some((dir, weight / total))
}

/// True if unit `dir` lies in cone `c` (with a relative slack of a few ulps at the rim).
#[inline]
fn contains(c: &AimCone, dir: Vec3) -> bool {
    c.one_minus_cos >= 2.0 || 1.0 - dir.dot(c.axis) <= c.one_minus_cos * (1.0 + 1e-5) + 1e-7
}

/// The density [`sample_cones`] gives direction `dir` (unit): the weights of the cones that
/// contain it over their weighted total solid angle.
#[must_use]
pub fn cones_pdf(cones: &[AimCone], total: f32, dir: Vec3) -> f32 {
    if cones.is_empty() || !(total > 0.0) {
        return 0.0;
    }
    cones
        .iter()
        .filter(|c| contains(c, dir))
        .map(|c| c.weight)
        .sum::<f32>()
        / total
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use crate::sampling::warp::uniform_sphere;
    use std::f32::consts::PI;

    #[test]
    fn one_cone_has_the_solid_angle_of_its_sphere() {
        // A sphere of radius 1 at distance 2 subtends a cone of half-angle 30°:
        // Ω = 2π(1 − cos 30°) = 2π(1 − √3/2).
        let t = CausticTargets::from_spheres(vec![(Vec3::new(0.0, 0.0, 2.0), 1.0)]);
        let mut cones = Vec::new();
        let total = t.cones(Vec3::ZERO, &mut cones);
        let expected = TAU * (1.0 - 3f32.sqrt() / 2.0);
        assert!(
            (total - expected).abs() < 1e-6 * expected,
            "{total} vs {expected}"
        );
    }

    #[test]
    fn overlapping_cones_sample_with_the_density_they_report() {
        // Two overlapping cones and a separate one, of unequal weights. Estimate ∫ g(w) dw for
        // g = 1 on the union of the cones by importance sampling: Σ 1/pdf / N must equal the
        // union's solid angle, computed independently by uniform sphere sampling.
        let t = CausticTargets {
            spheres: vec![
                (Vec3::new(0.0, 0.0, 3.0), 1.0, 1.0),
                (Vec3::new(0.5, 0.0, 3.0), 1.0, 0.3),
                (Vec3::new(-3.0, 1.0, 0.0), 0.5, 0.06),
            ],
        };
        let mut cones = Vec::new();
        let total = t.cones(Vec3::ZERO, &mut cones);
        let mut rng = Rng::new(7, 1);
        let n = 400_000;
        let mut est = 0.0f64;
        for _ in 0..n {
            let (d, pdf) = sample_cones(
                &cones,
                total,
                rng.next_f32(),
                (rng.next_f32(), rng.next_f32()),
            )
            .expect("cones");
            assert!((pdf - cones_pdf(&cones, total, d)).abs() < 1e-6 * pdf);
            est += 1.0 / f64::from(pdf);
        }
        est /= f64::from(n);
        let mut inside = 0u64;
        for _ in 0..n {
            let d = uniform_sphere((rng.next_f32(), rng.next_f32()));
            inside += u64::from(cones_pdf(&cones, total, d) > 0.0);
        }
        let union = 4.0 * std::f64::consts::PI * inside as f64 / f64::from(n);
        // Uniform sampling's standard error: sqrt(p(1-p)/n)·4π ≈ 0.005 sr here.
        assert!((est - union).abs() < 0.02, "{est} vs {union}");
        let sum: f32 = cones.iter().map(|c| TAU * c.one_minus_cos).sum();
        assert!(est < f64::from(sum) - 0.1, "overlap must be counted once");
    }

    #[test]
    fn crossings_sample_the_union_of_the_projections_with_the_density_they_report() {
        // Lines of a light at infinity through three spheres (two overlapping in projection,
        // unequal weights): Σ 1/pdf / N must equal the area of the union of their projected
        // discs, computed independently by counting a fine grid of the plane; and a line
        // through every projection point is counted once (the overlap is not double).
        let t = CausticTargets {
            spheres: vec![
                (Vec3::new(0.0, 0.0, 3.0), 1.0, 1.0),
                (Vec3::new(0.6, 0.2, -2.0), 1.0, 0.3),
                (Vec3::new(-3.0, 1.0, 0.0), 0.5, 0.06),
            ],
        };
        let dir = Vec3::new(0.0, 0.0, -1.0);
        let mut rng = Rng::new(9, 2);
        let n = 400_000;
        let mut est = 0.0f64;
        for _ in 0..n {
            let u_pick = rng.next_f32();
            let (x, pdf) = t
                .sample_crossing(dir, u_pick, (rng.next_f32(), rng.next_f32()))
                .expect("targets");
            assert!((pdf - t.crossing_pdf(dir, x)).abs() < 1e-6 * pdf);
            est += 1.0 / f64::from(pdf);
        }
        est /= f64::from(n);
        // The union's area in the plane z = 0 by a 2 mm grid over [−4, 2] × [−1.1, 1.9].
        let h = 0.002f32;
        let mut cells = 0u64;
        for i in 0..3000 {
            for j in 0..1500 {
                let x = Vec3::new(
                    -4.0 + (i as f32 + 0.5) * h,
                    -1.1 + (j as f32 + 0.5) * h,
                    0.0,
                );
                cells += u64::from(t.crossing_pdf(dir, x) > 0.0);
            }
        }
        let union = cells as f64 * f64::from(h * h);
        assert!((est / union - 1.0).abs() < 0.01, "{est} vs {union}");
        let sum = PI * (1.0 + 1.0 + 0.25);
        assert!(
            est < f64::from(sum) - 0.3,
            "overlap must be counted once: {est}"
        );
        assert_eq!(
            CausticTargets::default().sample_crossing(dir, 0.5, (0.5, 0.5)),
            None
        );
    }

    #[test]
    fn a_point_inside_a_target_aims_everywhere() {
        let t = CausticTargets::from_spheres(vec![(Vec3::ZERO, 2.0)]);
        let mut cones = Vec::new();
        let total = t.cones(Vec3::new(0.5, 0.0, 0.0), &mut cones);
        assert!((total - 4.0 * PI).abs() < 1e-5);
        let (d, pdf) = sample_cones(&cones, total, 0.3, (0.2, 0.9)).expect("sample");
        assert!((d.length() - 1.0).abs() < 1e-5);
        assert!((pdf - 1.0 / (4.0 * PI)).abs() < 1e-7);
    }
}

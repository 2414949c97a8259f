//! Fresnel reflectance of metals: the exact unpolarised reflectance of a conductor of complex
//! index `η + ik` (per RGB channel), named presets measured by Johnson & Christy and Rakić, and
//! the artist's F82-tint model.
//!
//! - Exact conductor Fresnel, from air onto a metal of complex relative index `n = η + ik`, in
//!   the real-arithmetic form of the Fresnel equations (e.g. Born & Wolf, *Principles of
//!   Optics*, §14.2; pbrt-v3 §8.2.1): with `s = sin θ`, `c = cos θ`,
//!   `a² + b² = √((η² − k² − s²)² + 4η²k²)`, `a = √((a² + b² + η² − k² − s²)/2)`,
//!   `R⊥ = (a² + b² − 2ac + c²)/(a² + b² + 2ac + c²)`,
//!   `R∥ = R⊥ (c²(a² + b²) − 2acs² + s⁴)/(c²(a² + b²) + 2acs² + s⁴)`, `F = (R⊥ + R∥)/2`.
//! - F82-tint (Hoffman, "Generalization of Adobe's Fresnel Model", 2023, and Kutz, Hasan, Edmondson,
//!   "Novel Aspects of the Adobe Standard Material", 2021): Schlick's `S(μ) = F0 + (1 − F0)(1 − μ)⁵`
//!   minus a bump `a μ (1 − μ)⁶` that peaks at `μ̄ = 1/7` (θ ≈ 82°), with `a` chosen so that
//!   `F(μ̄) = tint · S(μ̄)`; `tint = 1` is Schlick's approximation (Schlick 1994).

use glam::Vec3;

/// Unpolarised Fresnel reflectance of a conductor of complex relative index `eta + i k` at
/// incidence cosine `cos` (clamped to [0, 1]): the exact formula above. 1 at grazing incidence;
/// `((η − 1)² + k²)/((η + 1)² + k²)` at normal incidence; for `k = 0` it is the dielectric
/// reflectance from the optically thinner side.
#[inline]
#[must_use]
pub fn fresnel_conductor(cos: f32, eta: f32, k: f32) -> f32 {
    let c = cos.clamp(0.0, 1.0);
    let c2 = c * c;
    let s2 = 1.0 - c2;
    let (e2, k2) = (eta * eta, k * k);
    let t0 = e2 - k2 - s2;
    let a2b2 = (t0 * t0 + 4.0 * e2 * k2).sqrt();
    let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
    let t1 = a2b2 + c2;
    let t2 = 2.0 * a * c;
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = c2 * a2b2 + s2 * s2;
    let t4 = t2 * s2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    if !(rs + rp).is_finite() {
        // c = 0 with η = k = 0 (0/0): grazing incidence reflects everything.
        return 1.0;
    }
    (0.5 * (rs + rp)).clamp(0.0, 1.0)
}

/// Schlick's approximation `F0 + (1 − F0)(1 − cos)⁵` of a Fresnel reflectance.
#[inline]
#[must_use]
pub fn schlick(f0: Vec3, cos: f32) -> Vec3 {
    let m = 1.0 - cos.clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (Vec3::ONE - f0) * (m2 * m2 * m)
}

/// The cosine `μ̄ = 1/7` (θ ≈ 81.8°) where the F82 model's correction peaks.
const F82_COS: f32 = 1.0 / 7.0;

/// `μ̄ (1 − μ̄)⁶`, the F82 correction's shape at its peak.
#[inline]
fn f82_peak() -> f32 {
    F82_COS * (1.0 - F82_COS).powi(6)
}

/// Fresnel reflectance of a conductor, per RGB channel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum ConductorFresnel {
    /// From the complex index of refraction `eta + i k` relative to the outside medium (exact,
    /// [`fresnel_conductor`]).
    Complex {
        /// Real part η per channel, > 0.
        eta: Vec3,
        /// Extinction coefficient k per channel, ≥ 0.
        k: Vec3,
    },
    /// The artist's F82-tint model: reflectance `f0` at normal incidence and `tint` scaling
    /// Schlick's value near grazing (θ ≈ 82°); `tint = 1` is Schlick's approximation.
    F82Tint {
        /// Normal-incidence reflectance per channel, in [0, 1].
        f0: Vec3,
        /// Multiplier of Schlick's reflectance at θ ≈ 82°, per channel, ≥ 0 (1: Schlick).
        tint: Vec3,
    },
}

impl ConductorFresnel {
    /// Schlick's approximation of normal-incidence reflectance `f0`.
    #[inline]
    #[must_use]
    pub fn schlick(f0: Vec3) -> Self {
        Self::F82Tint {
            f0,
            tint: Vec3::ONE,
        }
    }

    /// The complex index of a named preset.
    #[inline]
    #[must_use]
    pub fn preset(p: ConductorPreset) -> Self {
        let (eta, k) = p.complex_index();
        Self::Complex { eta, k }
    }

    /// The F82-tint fit of a complex index (Hoffman 2023): `f0` the exact reflectance at normal
    /// incidence and `tint` the exact reflectance at `μ̄ = 1/7` over Schlick's there, so the
    /// two models agree at 0°, ≈ 82° and 90°.
    #[must_use]
    pub fn f82_fit(eta: Vec3, k: Vec3) -> Self {
        let exact = |cos: f32| {
            Vec3::new(
                fresnel_conductor(cos, eta.x, k.x),
                fresnel_conductor(cos, eta.y, k.y),
                fresnel_conductor(cos, eta.z, k.z),
            )
        };
        let f0 = exact(1.0);
        let tint = exact(F82_COS) / schlick(f0, F82_COS);
        Self::F82Tint { f0, tint }
    }

    /// The reflectance at incidence cosine `cos` (the cosine between the direction and the
    /// microfacet normal), each channel in [0, 1].
    #[inline]
    #[must_use]
    pub fn eval(&self, cos: f32) -> Vec3 {
        match *self {
            Self::Complex { eta, k } => Vec3::new(
                fresnel_conductor(cos, eta.x, k.x),
                fresnel_conductor(cos, eta.y, k.y),
                fresnel_conductor(cos, eta.z, k.z),
            ),
            Self::F82Tint { f0, tint } => {
                let c = cos.clamp(0.0, 1.0);
                let s = schlick(f0, c);
                // a = S(μ̄)(1 − tint) / (μ̄ (1 − μ̄)⁶), so that F(μ̄) = tint · S(μ̄).
                let a = schlick(f0, F82_COS) * (Vec3::ONE - tint) / f82_peak();
                (s - a * (c * (1.0 - c).powi(6))).clamp(Vec3::ZERO, Vec3::ONE)
            }
        }
    }
}

/// Named metals, with complex indices sampled at 650 nm (R), 550 nm (G) and 450 nm (B) by
/// linear interpolation in wavelength of the tables of
/// - gold, silver, copper: P. B. Johnson and R. W. Christy, "Optical Constants of the Noble
///   Metals", Phys. Rev. B 6, 4370 (1972);
/// - chrome: P. B. Johnson and R. W. Christy, "Optical constants of transition metals: Ti, V,
///   Cr, Mn, Fe, Co, Ni, and Pd", Phys. Rev. B 9, 5056 (1974);
/// - aluminium: A. D. Rakić, "Algorithm for the determination of intrinsic optical constants of
///   metal films: application to aluminum", Appl. Opt. 34, 4755 (1995);
///
/// as tabulated by the refractiveindex.info database (M. N. Polyanskiy, public domain).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ConductorPreset {
    /// Chromium (Johnson & Christy 1974).
    Chrome,
    /// Aluminium (Rakić 1995).
    Aluminium,
    /// Gold (Johnson & Christy 1972).
    Gold,
    /// Copper (Johnson & Christy 1972).
    Copper,
    /// Silver (Johnson & Christy 1972).
    Silver,
}

impl ConductorPreset {
    /// Every preset, in the order of [`ConductorPreset::NAMES`].
    pub const ALL: [Self; 5] = [
        Self::Chrome,
        Self::Aluminium,
        Self::Gold,
        Self::Copper,
        Self::Silver,
    ];

    /// The presets' names as a scene file spells them.
    pub const NAMES: [&'static str; 5] = ["chrome", "aluminium", "gold", "copper", "silver"];

    /// The scene-file name.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Chrome => "chrome",
            Self::Aluminium => "aluminium",
            Self::Gold => "gold",
            Self::Copper => "copper",
            Self::Silver => "silver",
        }
    }

    /// The preset of a scene-file name (exact spelling), `None` if there is none.
    #[must_use]
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|p| p.name() == name)
    }

    /// `(η, k)` at (650, 550, 450) nm.
    #[must_use]
    pub fn complex_index(self) -> (Vec3, Vec3) {
        let (eta, k) = match self {
            Self::Chrome => ([3.1071, 3.1812, 2.3230], [3.3314, 3.3291, 3.1350]),
            Self::Aluminium => ([1.5580, 1.0152, 0.6332], [7.7124, 6.6273, 5.4544]),
            Self::Gold => ([0.1556, 0.4241, 1.3831], [3.6024, 2.4721, 1.9155]),
            Self::Copper => ([0.2378, 1.0066, 1.2404], [3.6264, 2.5823, 2.3929]),
            Self::Silver => ([0.0522, 0.0596, 0.0400], [4.4094, 3.5974, 2.6484]),
        };
        (Vec3::from(eta), Vec3::from(k))
    }
}

impl crate::binfile::KeyHash for ConductorFresnel {
    fn key_hash(&self, h: &mut crate::binfile::Fnv) {
        match self {
            ConductorFresnel::Complex { eta, k } => {
                h.str("Complex");
                eta.key_hash(h);
                k.key_hash(h);
            }
            ConductorFresnel::F82Tint { f0, tint } => {
                h.str("F82Tint");
                f0.key_hash(h);
                tint.key_hash(h);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Reference: the Fresnel amplitude coefficients with complex arithmetic in f64,
    /// `r⊥ = (c − n cₜ)/(c + n cₜ)`, `r∥ = (n c − cₜ)/(n c + cₜ)`, `cₜ = √(1 − s²/n²)`.
    fn complex_reference(cos: f64, eta: f64, k: f64) -> f64 {
        #[derive(Clone, Copy)]
        struct C(f64, f64);
        let mul = |a: C, b: C| C(a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
        let div = |a: C, b: C| {
            let d = b.0 * b.0 + b.1 * b.1;
            C((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
        };
        let sqrt = |a: C| {
            let r = (a.0 * a.0 + a.1 * a.1).sqrt();
            let re = ((r + a.0) / 2.0).sqrt();
            let im = ((r - a.0) / 2.0).sqrt().copysign(a.1);
            C(re, im)
        };
        let n = C(eta, k);
        let s2 = 1.0 - cos * cos;
        let n2 = mul(n, n);
        let q = div(C(s2, 0.0), n2);
        let ct = sqrt(C(1.0 - q.0, -q.1));
        let nct = mul(n, ct);
        let rs = div(C(cos - nct.0, -nct.1), C(cos + nct.0, nct.1));
        let nc = C(n.0 * cos, n.1 * cos);
        let rp = div(C(nc.0 - ct.0, nc.1 - ct.1), C(nc.0 + ct.0, nc.1 + ct.1));
        0.5 * (rs.0 * rs.0 + rs.1 * rs.1 + rp.0 * rp.0 + rp.1 * rp.1)
    }

    #[test]
    fn exact_formula_matches_complex_arithmetic_and_closed_forms() {
        for (eta, k) in [
            (0.1556, 3.6024),
            (3.1071, 3.3314),
            (1.5, 0.0),
            (0.05, 4.4),
            (1.0, 1e-3),
        ] {
            for i in 0..=90 {
                let cos = f64::from(i as f32).to_radians().cos();
                let got = fresnel_conductor(cos as f32, eta as f32, k as f32);
                let want = complex_reference(cos, eta, k);
                assert!(
                    (f64::from(got) - want).abs() < 2e-5,
                    "η {eta} k {k} at {i}°: {got} vs {want}"
                );
            }
            let r0 = ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k);
            assert!((f64::from(fresnel_conductor(1.0, eta as f32, k as f32)) - r0).abs() < 1e-6);
            assert!((fresnel_conductor(0.0, eta as f32, k as f32) - 1.0).abs() < 1e-6);
        }
        // k = 0 is a dielectric seen from outside: glass at normal incidence reflects 4%.
        assert!((fresnel_conductor(1.0, 1.5, 0.0) - 0.04).abs() < 1e-6);
        let glass_45 =
            crate::shading::optics::fresnel_dielectric(45f32.to_radians().cos(), 1.0 / 1.5);
        assert!((fresnel_conductor(45f32.to_radians().cos(), 1.5, 0.0) - glass_45).abs() < 1e-5);
    }

    #[test]
    fn presets_have_the_colours_of_their_metals() {
        let f0 = |p: ConductorPreset| ConductorFresnel::preset(p).eval(1.0);
        // Normal-incidence reflectance ((η−1)² + k²)/((η+1)² + k²) by hand from the table for
        // gold's R channel: η 0.1556, k 3.6024 → 0.9565.
        assert!((f0(ConductorPreset::Gold).x - 0.9565).abs() < 1e-3);
        let gold = f0(ConductorPreset::Gold);
        let copper = f0(ConductorPreset::Copper);
        assert!(gold.x > gold.y && gold.y > gold.z, "gold is yellow: {gold}");
        assert!(
            copper.x > copper.y && copper.x > copper.z,
            "copper is red: {copper}"
        );
        let silver = f0(ConductorPreset::Silver);
        assert!(
            silver.min_element() > 0.97,
            "silver is the brightest: {silver}"
        );
        let al = f0(ConductorPreset::Aluminium);
        assert!(al.min_element() > 0.9 && al.max_element() < 0.93, "{al}");
        let cr = f0(ConductorPreset::Chrome);
        assert!(
            (cr.max_element() - cr.min_element()) < 0.01 && cr.x > 0.5,
            "chrome is grey: {cr}"
        );
        for (p, n) in ConductorPreset::ALL.into_iter().zip(ConductorPreset::NAMES) {
            assert_eq!(ConductorPreset::from_name(n), Some(p));
            assert_eq!(p.name(), n);
        }
        assert_eq!(ConductorPreset::from_name("gld"), None);
    }

    #[test]
    fn f82_tint_interpolates_schlick_and_fits_measured_metals() {
        let f0 = Vec3::new(0.9, 0.6, 0.3);
        let plain = ConductorFresnel::schlick(f0);
        for c in [0.0f32, 0.1, 0.5, 1.0] {
            assert!(plain.eval(c).distance(schlick(f0, c)) < 1e-6);
        }
        // Fresnel 1 exactly at every angle when f0 = 1.
        assert_eq!(ConductorFresnel::schlick(Vec3::ONE).eval(0.37), Vec3::ONE);
        let tinted = ConductorFresnel::F82Tint {
            f0,
            tint: Vec3::splat(0.8),
        };
        assert!(tinted.eval(1.0).distance(f0) < 1e-6);
        assert!(tinted.eval(F82_COS).distance(schlick(f0, F82_COS) * 0.8) < 1e-6);
        assert!(tinted.eval(0.0).distance(Vec3::ONE) < 1e-6);
        // The fit of each preset is exact at 0° and ≈82° and within 3% (absolute) elsewhere.
        for p in ConductorPreset::ALL {
            let (eta, k) = p.complex_index();
            let exact = ConductorFresnel::Complex { eta, k };
            let fit = ConductorFresnel::f82_fit(eta, k);
            assert!(fit.eval(1.0).distance(exact.eval(1.0)) < 1e-5, "{p:?}");
            assert!(
                fit.eval(F82_COS).distance(exact.eval(F82_COS)) < 1e-5,
                "{p:?}"
            );
            for i in 0..=90 {
                let c = (i as f32).to_radians().cos();
                let d = (fit.eval(c) - exact.eval(c)).abs().max_element();
                assert!(
                    d < 0.03,
                    "{p:?} at {i}°: {} vs {}",
                    fit.eval(c),
                    exact.eval(c)
                );
            }
        }
    }
}

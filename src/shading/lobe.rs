//! The lobes a BSDF mixture ([`super::Bsdf`]) is made of, dispatched by one enum (no virtual
//! calls per sample; pbrt-v4 tags its `BxDF`s the same way and dispatches with a lambda). Every
//! lobe implements [`Bxdf`], the one interface (`f`, `pdf`, `sample`, … with the same
//! arguments for every lobe); [`Lobe`]'s methods forward to it. Adding a lobe: write its file
//! (a type implementing [`Bxdf`]), add one line to the `lobes!` list below, and give it a part
//! in the mixture (`Bsdf::new`).

use glam::Vec3;

use super::bxdf::{Bxdf, DeltaWeights, LobeContext, LobeDraw, LobeInfo, LobeSample, Prepared};
use super::coated::CoatedLobe;
use super::dielectric::Dielectric;
use super::lambert::Lambert;
use super::microfacet::Ggx;
use super::phong::Phong;
use super::rough_conductor::RoughConductor;
use super::rough_dielectric::RoughDielectric;
use super::scattering::{LobeFlags, TransportMode};
use super::specular_conductor::SpecularConductor;
use super::specular_reflection::SpecularReflection;
use crate::binfile::{Fnv, KeyHash};

/// Declares [`Lobe`] with one variant per listed lobe type and a `dispatch!` that matches every
/// variant (no wildcard), binding the lobe to a name; [`Lobe`]'s methods and its key use it.
macro_rules! lobes {
    ($($(#[doc = $doc:literal])* $variant:ident($t:ty),)+) => {
        /// One lobe of the mixture. Lobes tinted by the material's colour (Lambert's albedo, the
        /// mirror's reflectance, the dielectric's transmittance) read it from the
        /// [`LobeContext`], so a colour texture changes one value in the mixture.
        #[derive(Debug, Clone, Copy, PartialEq)]
        pub enum Lobe {
            $($(#[doc = $doc])* $variant($t),)+
        }

        /// `dispatch!(lobe, l => expr)`: `expr` with `l` bound to the lobe inside any variant.
        macro_rules! dispatch {
            ($lobe:expr, $l:ident => $e:expr) => {
                match $lobe {
                    $(Lobe::$variant($l) => $e,)+
                }
            };
        }
    };
}

lobes! {
    /// Ideal diffuse reflection.
    Lambert(Lambert),
    /// Normalised Phong glossy reflection.
    Phong(Phong),
    /// Perfect mirror.
    SpecularReflection(SpecularReflection),
    /// Perfect mirror with a conductor's Fresnel reflectance (a polished metal).
    SpecularConductor(SpecularConductor),
    /// Smooth Fresnel dielectric.
    Dielectric(Dielectric),
    /// GGX microfacet metal, or a rough mirror tinted by the colour ([`RoughConductor`]).
    RoughConductor(RoughConductor),
    /// GGX microfacet dielectric ([`RoughDielectric`]): glossy reflection and transmission.
    RoughDielectric(RoughDielectric),
    /// One layer of a diffuse base under a smooth clear coat ([`CoatedLobe`]).
    Coated(CoatedLobe),
}

impl Lobe {
    /// [`Bxdf::info`].
    #[inline]
    #[must_use]
    pub fn info(&self) -> LobeInfo {
        dispatch!(self, l => l.info())
    }

    /// The lobe's kind of scattering ([`LobeInfo::flags`]).
    #[inline]
    #[must_use]
    pub fn flags(&self) -> LobeFlags {
        self.info().flags
    }

    /// [`Bxdf::is_black`].
    #[inline]
    #[must_use]
    pub fn is_black(&self, tint: Vec3) -> bool {
        dispatch!(self, l => l.is_black(tint))
    }

    /// [`Bxdf::is_flat`].
    #[inline]
    #[must_use]
    pub fn is_flat(&self, tint: Vec3) -> bool {
        dispatch!(self, l => l.is_flat(tint))
    }

    /// [`LobeInfo::focusing_fraction`].
    #[inline]
    #[must_use]
    pub fn focusing_fraction(&self) -> f32 {
        self.info().focusing_fraction
    }

    /// [`LobeInfo::uses_lobe_number`].
    #[inline]
    #[must_use]
    pub fn uses_lobe_number(&self) -> bool {
        self.info().uses_lobe_number
    }

    /// [`Bxdf::prepare`].
    #[inline]
    #[must_use]
    pub fn prepare(&self, ctx: &LobeContext<'_>) -> Prepared {
        dispatch!(self, l => l.prepare(ctx))
    }

    /// [`Bxdf::albedo`].
    #[inline]
    #[must_use]
    pub fn albedo(&self, prepared: &Prepared, rho: f32) -> f32 {
        dispatch!(self, l => l.albedo(prepared, rho))
    }

    /// [`Bxdf::f`].
    #[inline]
    #[must_use]
    pub fn f(&self, ctx: &LobeContext<'_>, wi: Vec3, mode: TransportMode) -> Vec3 {
        dispatch!(self, l => Bxdf::f(l, ctx, wi, mode))
    }

    /// [`Bxdf::pdf`].
    #[inline]
    #[must_use]
    pub fn pdf(&self, ctx: &LobeContext<'_>, wi: Vec3, share: f32) -> f32 {
        dispatch!(self, l => Bxdf::pdf(l, ctx, wi, share))
    }

    /// [`Bxdf::sample`].
    #[inline]
    #[must_use]
    pub fn sample(&self, ctx: &LobeContext<'_>, draw: &LobeDraw<'_>) -> Option<LobeSample> {
        dispatch!(self, l => Bxdf::sample(l, ctx, draw))
    }

    /// [`Bxdf::delta_weights`].
    #[inline]
    #[must_use]
    pub fn delta_weights(&self, ctx: &LobeContext<'_>, weight: f32) -> DeltaWeights {
        dispatch!(self, l => l.delta_weights(ctx, weight))
    }

    /// [`Bxdf::straight_transmittance`].
    #[inline]
    #[must_use]
    pub fn straight_transmittance(
        &self,
        weight: f32,
        tint: Vec3,
        cos: f32,
        entering: bool,
    ) -> Vec3 {
        dispatch!(self, l => Bxdf::straight_transmittance(l, weight, tint, cos, entering))
    }

    /// [`LobeInfo::ior`].
    #[inline]
    #[must_use]
    pub fn ior(&self) -> Option<f32> {
        self.info().ior
    }

    /// [`LobeInfo::distribution`].
    #[inline]
    #[must_use]
    pub fn distribution(&self) -> Option<Ggx> {
        self.info().distribution
    }

    /// The coat of a coated layer.
    #[inline]
    #[must_use]
    pub fn coat(&self) -> Option<CoatedLobe> {
        match self {
            Lobe::Coated(c) => Some(*c),
            Lobe::Lambert(_)
            | Lobe::Phong(_)
            | Lobe::SpecularReflection(_)
            | Lobe::SpecularConductor(_)
            | Lobe::Dielectric(_)
            | Lobe::RoughConductor(_)
            | Lobe::RoughDielectric(_) => None,
        }
    }
}

impl KeyHash for Lobe {
    fn key_hash(&self, h: &mut Fnv) {
        dispatch!(self, l => l.key_hash(h));
    }
}

//! One weighted part of the BSDF mixture ([`super::Bsdf`]): the lobes that share one of the
//! scene's weights (all non-delta, or one delta lobe), and the per-direction numbers the mixture
//! asks of it (its sampling weight, its lobes' shares).

use super::bxdf::{LobeContext, Prepared};
use super::lobe::Lobe;
use super::scattering::LobeFlags;

/// Most lobes in one part.
pub(super) const LOBES_PER_PART: usize = 2;

/// One weighted part of the mixture.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct Part {
    /// The part's normalised weight (the scene's diffuse, reflect or transmit weight).
    pub(super) weight: f32,
    /// Its lobes (the first always present).
    pub(super) lobes: [Option<Lobe>; LOBES_PER_PART],
}

/// What a part of the mixture takes part in, worked out once per BSDF query (so the mixture's
/// loops test a flag instead of walking the lobes' flags).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub(super) struct PartUse {
    /// Weight > 0 and non-delta: it has a value and a density.
    pub(super) local: bool,
    /// ... and one of its lobes transmits (the rough dielectric): directions below the surface
    /// have a value and a density.
    pub(super) transmits_glossy: bool,
}

impl Part {
    /// A part of weight `weight` with lobes `first` and `second`.
    pub(super) fn new(weight: f32, first: Lobe, second: Option<Lobe>) -> Self {
        Self {
            weight,
            lobes: [Some(first), second],
        }
    }

    /// The lobes present.
    #[inline]
    pub(super) fn lobes(&self) -> impl Iterator<Item = &Lobe> {
        self.lobes.iter().flatten()
    }

    /// Whether the part is a delta lobe (by its first lobe; parts never mix).
    #[inline]
    pub(super) fn is_delta(&self) -> bool {
        self.lobes().next().is_some_and(|l| l.flags().is_delta())
    }

    /// The union of the lobes' flags.
    #[inline]
    pub(super) fn flags(&self) -> LobeFlags {
        self.lobes().fold(LobeFlags::NONE, |f, l| f | l.flags())
    }

    /// What the part takes part in (see [`PartUse`]).
    #[inline]
    pub(super) fn usage(&self) -> PartUse {
        let local = self.weight != 0.0 && !self.is_delta();
        PartUse {
            local,
            transmits_glossy: local && self.flags().contains(LobeFlags::TRANSMISSION),
        }
    }

    /// The per-direction state of the part's (first) lobe.
    #[inline]
    pub(super) fn prepare(&self, ctx: &LobeContext<'_>) -> Prepared {
        self.lobes()
            .next()
            .map_or(Prepared::Nothing, |l| l.prepare(ctx))
    }

    /// Each lobe's share of the part: `aⱼ / Σa` (`a` the lobes' sampling weights) for all but
    /// the last, which takes the rest (all to the first when Σa is 0).
    #[inline]
    pub(super) fn shares(&self, prepared: &Prepared, rho: f32) -> [f32; LOBES_PER_PART] {
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
    pub(super) fn probability_weight(&self, prepared: &Prepared, rho: f32) -> f32 {
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

crate::key_hash_struct!(Part { weight, lobes });

//! The dedicated render flags an override set states (`--width`, `--spp`, `--integrator`, …),
//! one at a time, for the records that apply them again: `caustic golden update` stores them
//! in the golden (`spp=64`) and `caustic farm plan` in its manifest (`render.samples_per_pixel=64`).

use super::SceneOverrides;
use crate::settings::{IntegratorKind, SamplerKind};

/// One flag of [`SceneOverrides`] (besides its `--set` assignments) and its value.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StatedFlag {
    /// `--width` (pixels).
    Width(u32),
    /// `--height` (pixels).
    Height(u32),
    /// `--spp` (samples per pixel).
    Spp(u32),
    /// `--max-depth` (bounces).
    MaxDepth(u32),
    /// `--seed`.
    Seed(u64),
    /// `--caustic-photons`.
    CausticPhotons(u32),
    /// `--integrator`.
    Integrator(IntegratorKind),
    /// `--sampler`.
    Sampler(SamplerKind),
}

/// Why a recorded flag cannot be applied again.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FlagError {
    /// No flag of that name.
    #[error("no flag `{0}`")]
    Unknown(String),
    /// A number that does not parse.
    #[error("`{0}` is not a whole number")]
    Malformed(String),
    /// An integrator or sampler that does not exist.
    #[error("`{0}` names no such choice")]
    NoSuchChoice(String),
}

impl StatedFlag {
    /// The flag's name as the command line spells it, with `_` for `-` (`max_depth`).
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Self::Width(_) => "width",
            Self::Height(_) => "height",
            Self::Spp(_) => "spp",
            Self::MaxDepth(_) => "max_depth",
            Self::Seed(_) => "seed",
            Self::CausticPhotons(_) => "caustic_photons",
            Self::Integrator(_) => "integrator",
            Self::Sampler(_) => "sampler",
        }
    }

    /// The scene field it sets (`render.samples_per_pixel`).
    #[must_use]
    pub fn field(self) -> &'static str {
        match self {
            Self::Width(_) => "render.width",
            Self::Height(_) => "render.height",
            Self::Spp(_) => "render.samples_per_pixel",
            Self::MaxDepth(_) => "render.max_depth",
            Self::Seed(_) => "render.seed",
            Self::CausticPhotons(_) => "photons.caustic",
            Self::Integrator(_) => "render.integrator",
            Self::Sampler(_) => "render.sampler",
        }
    }

    /// The value as the command line writes it (`path-ppm`).
    #[must_use]
    pub fn cli_value(self) -> String {
        match self {
            Self::Integrator(i) => i.cli_name().into(),
            Self::Sampler(s) => s.cli_name().into(),
            other => other.scene_value(),
        }
    }

    /// The value as a scene file writes it (`PathPpm`).
    #[must_use]
    pub fn scene_value(self) -> String {
        match self {
            Self::Width(v) | Self::Height(v) | Self::Spp(v) | Self::MaxDepth(v) => v.to_string(),
            Self::CausticPhotons(v) => v.to_string(),
            Self::Seed(v) => v.to_string(),
            Self::Integrator(i) => i.name().into(),
            Self::Sampler(s) => s.name().into(),
        }
    }

    /// The flag named `name` (as [`StatedFlag::name`]) with `value` in either spelling.
    ///
    /// # Errors
    /// [`FlagError`]: an unknown name, a malformed number, or no such integrator or sampler.
    pub fn parse(name: &str, value: &str) -> Result<Self, FlagError> {
        let num = || {
            value
                .parse::<u32>()
                .map_err(|_| FlagError::Malformed(value.into()))
        };
        let choice = || FlagError::NoSuchChoice(value.into());
        Ok(match name {
            "width" => Self::Width(num()?),
            "height" => Self::Height(num()?),
            "spp" => Self::Spp(num()?),
            "max_depth" => Self::MaxDepth(num()?),
            "seed" => Self::Seed(
                value
                    .parse::<u64>()
                    .map_err(|_| FlagError::Malformed(value.into()))?,
            ),
            "caustic_photons" => Self::CausticPhotons(num()?),
            "integrator" => Self::Integrator(IntegratorKind::from_name(value).ok_or_else(choice)?),
            "sampler" => Self::Sampler(SamplerKind::from_name(value).ok_or_else(choice)?),
            _ => return Err(FlagError::Unknown(name.into())),
        })
    }
}

impl SceneOverrides {
    /// The dedicated flags these overrides state, in the command line's order (the `--set`
    /// assignments are [`SceneOverrides::sets`]).
    #[must_use]
    pub fn flags(&self) -> Vec<StatedFlag> {
        let (r, p) = (&self.render, &self.photons);
        [
            r.width.map(StatedFlag::Width),
            r.height.map(StatedFlag::Height),
            r.samples_per_pixel.map(StatedFlag::Spp),
            r.max_depth.map(StatedFlag::MaxDepth),
            r.seed.map(StatedFlag::Seed),
            p.caustic.map(StatedFlag::CausticPhotons),
            r.integrator.map(StatedFlag::Integrator),
            r.sampler.map(StatedFlag::Sampler),
        ]
        .into_iter()
        .flatten()
        .collect()
    }

    /// States `flag` (over any value it had).
    pub fn state(&mut self, flag: StatedFlag) {
        let (r, p) = (&mut self.render, &mut self.photons);
        match flag {
            StatedFlag::Width(v) => r.width = Some(v),
            StatedFlag::Height(v) => r.height = Some(v),
            StatedFlag::Spp(v) => r.samples_per_pixel = Some(v),
            StatedFlag::MaxDepth(v) => r.max_depth = Some(v),
            StatedFlag::Seed(v) => r.seed = Some(v),
            StatedFlag::CausticPhotons(v) => p.caustic = Some(v),
            StatedFlag::Integrator(v) => r.integrator = Some(v),
            StatedFlag::Sampler(v) => r.sampler = Some(v),
        }
    }

    /// The overrides as `path=value` scene assignments (the `--set`s, then each flag as the
    /// field it sets), which [`SceneOverrides::sets`] alone would apply again.
    #[must_use]
    pub fn as_sets(&self) -> Vec<String> {
        let mut out = self.sets.clone();
        out.extend(
            self.flags()
                .into_iter()
                .map(|f| format!("{}={}", f.field(), f.scene_value())),
        );
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_flag_reads_back_from_its_name_and_either_spelling() {
        let all = [
            StatedFlag::Width(640),
            StatedFlag::Height(480),
            StatedFlag::Spp(64),
            StatedFlag::MaxDepth(7),
            StatedFlag::Seed(u64::MAX),
            StatedFlag::CausticPhotons(0),
            StatedFlag::Integrator(IntegratorKind::PathPpm),
            StatedFlag::Sampler(SamplerKind::Sobol),
        ];
        let mut o = SceneOverrides::default();
        for f in all {
            assert_eq!(StatedFlag::parse(f.name(), &f.cli_value()), Ok(f));
            assert_eq!(StatedFlag::parse(f.name(), &f.scene_value()), Ok(f));
            o.state(f);
        }
        // Every variant is stated by its own field: the list comes back whole and in order.
        assert_eq!(o.flags(), all);
        assert_eq!(
            o.as_sets()[2..5],
            [
                "render.samples_per_pixel=64",
                "render.max_depth=7",
                "render.seed=18446744073709551615"
            ]
        );
        assert_eq!(
            StatedFlag::parse("integrator", "bdpt"),
            Err(FlagError::NoSuchChoice("bdpt".into()))
        );
        assert_eq!(
            StatedFlag::parse("spp", "-1"),
            Err(FlagError::Malformed("-1".into()))
        );
        assert_eq!(
            StatedFlag::parse("tile", "16"),
            Err(FlagError::Unknown("tile".into()))
        );
    }
}

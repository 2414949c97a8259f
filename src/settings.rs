//! The named choices a scene file, the command line and the compiled scene share: which
//! integrator, which sampler, which texture filter. Each is one enum, written once here, that
//! serde (RON and TOML scene files, `--set`), clap (`--integrator`, `--sampler`), the JSON
//! Schema (`caustic schema`) and the renderer all use — so adding an integrator is one new
//! variant in [`IntegratorKind`] (and its `match` arm where integrators are built, which the
//! compiler asks for).
//!
//! Every variant has two spellings, both accepted everywhere: the scene file's (`PathPpm`, the
//! variant's own name, which is also how scenes are written back) and the command line's
//! (`path-ppm`). The JSON Schema lists both. This is the bottom layer: it imports no crate
//! module, and every layer may import it.

use std::borrow::Cow;
use std::fmt;

/// Declares one shared settings enum with its two spellings per variant (the variant's name for
/// scene files, a kebab-case literal for the command line) and the serde, JSON Schema and clap
/// impls that accept both.
macro_rules! settings_enum {
    (
        $(#[doc = $doc:literal])*
        pub enum $name:ident ($what:literal) {
            $(
                $(#[doc = $vdoc:literal])*
                $variant:ident = $cli:literal
            ),+ $(,)?
        }
    ) => {
        $(#[doc = $doc])*
        #[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
        pub enum $name {
            $(
                $(#[doc = $vdoc])*
                $variant,
            )+
        }

        impl $name {
            /// Every variant, in declaration order.
            pub const ALL: &'static [Self] = &[$(Self::$variant),+];

            /// Every accepted spelling, each variant's scene-file name followed by its
            /// command-line name (what an unknown name is told it may be).
            pub const SPELLINGS: &'static [&'static str] = &[$(stringify!($variant), $cli),+];

            /// The scene file's spelling (the variant's name, e.g. `PathPpm`).
            #[must_use]
            pub fn name(self) -> &'static str {
                match self {
                    $(Self::$variant => stringify!($variant),)+
                }
            }

            /// The command line's spelling (kebab-case, e.g. `path-ppm`).
            #[must_use]
            pub fn cli_name(self) -> &'static str {
                match self {
                    $(Self::$variant => $cli,)+
                }
            }

            /// The variant spelled `name` in either spelling (exactly; `None` for anything else).
            #[must_use]
            pub fn from_name(name: &str) -> Option<Self> {
                Self::ALL
                    .iter()
                    .copied()
                    .find(|v| v.name() == name || v.cli_name() == name)
            }

            /// The variant's documentation (its doc comment), one line per source line.
            #[must_use]
            pub fn doc(self) -> String {
                match self {
                    $(Self::$variant => doc_text(&[$($vdoc),*]),)+
                }
            }
        }

        impl fmt::Display for $name {
            /// The command-line spelling.
            fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
                f.write_str(self.cli_name())
            }
        }

        impl serde::Serialize for $name {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                let index = Self::ALL.iter().position(|v| v == self).unwrap_or(0);
                // The scene-file spelling, written as serde's derive writes a unit variant.
                s.serialize_unit_variant(stringify!($name), index as u32, self.name())
            }
        }

        impl<'de> serde::Deserialize<'de> for $name {
            fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                use serde::de::Error as _;
                let Spelling::Name(name) = Spelling::deserialize(d).map_err(|_| {
                    D::Error::custom(format!("{}: one of {}", $what, spelling_list(Self::SPELLINGS)))
                })?;
                Self::from_name(&name)
                    .ok_or_else(|| D::Error::unknown_variant(&name, Self::SPELLINGS))
            }
        }

        impl schemars::JsonSchema for $name {
            fn schema_name() -> Cow<'static, str> {
                stringify!($name).into()
            }

            fn json_schema(_: &mut schemars::SchemaGenerator) -> schemars::Schema {
                let variants: Vec<serde_json::Value> = Self::ALL
                    .iter()
                    .map(|v| {
                        serde_json::json!({
                            "description": v.doc(),
                            "type": "string",
                            "enum": [v.name(), v.cli_name()],
                        })
                    })
                    .collect();
                schemars::json_schema!({
                    "description": doc_text(&[$($doc),*]),
                    "oneOf": variants,
                })
            }
        }

        impl clap::ValueEnum for $name {
            fn value_variants<'a>() -> &'a [Self] {
                Self::ALL
            }

            fn to_possible_value(&self) -> Option<clap::builder::PossibleValue> {
                Some(
                    clap::builder::PossibleValue::new(self.cli_name())
                        .alias(self.name())
                        .help(self.doc().replace('\n', " ")),
                )
            }
        }
    };
}

/// A name as a bare RON identifier (`PathPpm`) or a string (`"path-ppm"`, TOML, `--set`).
/// Deserialised untagged so that RON hands over an identifier's text, which it does only for
/// serde's buffered content.
#[derive(serde::Deserialize)]
#[serde(untagged)]
enum Spelling {
    Name(String),
}

/// Doc-comment lines as one text: the leading space of each line dropped, lines kept.
fn doc_text(lines: &[&str]) -> String {
    let lines: Vec<&str> = lines
        .iter()
        .map(|l| l.strip_prefix(' ').unwrap_or(l))
        .collect();
    lines.join("\n").trim().to_string()
}

/// `` `a`, `b` or `c` ``.
fn spelling_list(names: &[&str]) -> String {
    let quoted: Vec<String> = names.iter().map(|n| format!("`{n}`")).collect();
    match quoted.split_last() {
        Some((last, init)) if !init.is_empty() => format!("{} or {last}", init.join(", ")),
        _ => quoted.concat(),
    }
}

settings_enum! {
    /// Which light-transport algorithm renders the image.
    pub enum IntegratorKind ("an integrator") {
        /// Recursive (Whitted) ray tracing: direct light with shadow rays, mirror and refraction.
        Whitted = "whitted",
        /// Path tracing with next-event estimation and multiple importance sampling: unbiased
        /// global illumination, the reference the other integrators are checked against.
        Path = "path",
        /// Photon mapping (Jensen 2001): direct light by shadow rays, caustics from a caustic photon
        /// map, indirect light from a global map read directly or by final gathering (`photons`).
        Photon = "photon",
        /// Progressive photon mapping (Knaus & Zwicker 2011): every sample per pixel is a pass with
        /// fresh caustic and global maps (`photons.caustic`, `photons.global` photons per pass)
        /// read directly at the first diffuse hit within a radius that shrinks from pass to pass
        /// (`photons.alpha`); the image is the mean of the passes and converges to the exact one.
        Ppm = "ppm",
        /// Path tracing with next-event estimation and MIS, with caustics (light → mirror or
        /// glass → diffuse paths) taken from a progressive caustic photon map at every diffuse
        /// vertex instead of from emitters hit by chance: consistent, and the default choice for
        /// scenes with small lights seen through glass or water.
        PathPpm = "path-ppm",
    }
}

settings_enum! {
    /// Which sequence the integrators draw their random numbers from.
    pub enum SamplerKind ("a sampler") {
        /// Independent uniform random numbers per pixel sample.
        Independent = "independent",
        /// Owen-scrambled Sobol points (Burley 2020): stratified in every pair of dimensions, lower
        /// error at the same sample count.
        Sobol = "sobol",
    }
}

settings_enum! {
    /// How image textures (bitmaps and height maps) are filtered.
    pub enum TextureFilter ("a texture filter") {
        /// Mipmapped over the pixel's footprint on the surface (tracked through mirrors and
        /// refraction): up to 16 trilinear lookups along the footprint's long axis, each at the
        /// level of its width. No shimmer or moiré, and sharp at grazing angles.
        Anisotropic = "anisotropic",
        /// Mipmapped: one trilinear lookup at the level of the footprint's longest extent. No
        /// shimmer or moiré, but blurry at grazing angles.
        Trilinear = "trilinear",
        /// Bilinear lookups in the full-resolution image only: sharp, but distant or grazing
        /// textures alias (for comparison and debugging).
        Bilinear = "bilinear",
    }
}

settings_enum! {
    /// How linear radiance (after `exposure`) becomes display values in [0, 1] for 8-bit images
    /// (PNG). EXR files are always written linear, without it.
    pub enum Tonemap ("a tone-mapping curve") {
        /// Clip each channel to [0, 1]: radiance above 1 saturates to white.
        Linear = "linear",
        /// Narkowicz's (2015) rational fit of the ACES filmic reference rendering transform,
        /// per channel: x (2.51 x + 0.03) / (x (2.43 x + 0.59) + 0.14), clipped to [0, 1]. Rolls
        /// highlights off smoothly; a channel clips only above 7.24.
        Aces = "aces",
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::ValueEnum;

    /// The command-line spelling written out by hand: lower case, a `-` before each inner
    /// capital (an independent statement of the convention the literals follow).
    fn kebab(name: &str) -> String {
        let mut out = String::new();
        for (i, c) in name.chars().enumerate() {
            if c.is_ascii_uppercase() && i > 0 {
                out.push('-');
            }
            out.push(c.to_ascii_lowercase());
        }
        out
    }

    #[test]
    fn command_line_names_are_the_kebab_case_of_the_variants() {
        for k in IntegratorKind::ALL {
            assert_eq!(k.cli_name(), kebab(k.name()));
        }
        for k in SamplerKind::ALL {
            assert_eq!(k.cli_name(), kebab(k.name()));
        }
        for k in TextureFilter::ALL {
            assert_eq!(k.cli_name(), kebab(k.name()));
        }
        assert_eq!(IntegratorKind::PathPpm.cli_name(), "path-ppm");
    }

    #[test]
    fn both_spellings_parse_and_nothing_else() {
        for k in IntegratorKind::ALL {
            assert_eq!(IntegratorKind::from_name(k.name()), Some(*k));
            assert_eq!(IntegratorKind::from_name(k.cli_name()), Some(*k));
        }
        assert_eq!(SamplerKind::from_name("Sobol"), Some(SamplerKind::Sobol));
        assert_eq!(SamplerKind::from_name("sobol"), Some(SamplerKind::Sobol));
        for bad in ["halton", "SOBOL", "path_ppm", "pathppm", ""] {
            assert_eq!(SamplerKind::from_name(bad), None, "{bad}");
            assert_eq!(IntegratorKind::from_name(bad), None, "{bad}");
        }
    }

    #[derive(Debug, serde::Deserialize, serde::Serialize, PartialEq)]
    struct Holder {
        integrator: IntegratorKind,
    }

    #[test]
    fn serde_reads_both_spellings_in_ron_toml_and_json_and_writes_the_variant_name() {
        let ron_ident: Holder = ron::from_str("(integrator: PathPpm)").unwrap();
        let ron_string: Holder = ron::from_str("(integrator: \"path-ppm\")").unwrap();
        let toml_camel: Holder = toml::from_str("integrator = \"PathPpm\"").unwrap();
        let toml_kebab: Holder = toml::from_str("integrator = \"path-ppm\"").unwrap();
        let json: Holder = serde_json::from_str("{\"integrator\": \"path\"}").unwrap();
        for h in [&ron_ident, &ron_string, &toml_camel, &toml_kebab] {
            assert_eq!(h.integrator, IntegratorKind::PathPpm);
        }
        assert_eq!(json.integrator, IntegratorKind::Path);
        // Written back exactly as serde's derive writes a unit variant.
        assert_eq!(ron::to_string(&ron_ident).unwrap(), "(integrator:PathPpm)");
        assert_eq!(
            serde_json::to_string(&json).unwrap(),
            "{\"integrator\":\"Path\"}"
        );
        let e = ron::from_str::<Holder>("(integrator: Pathh)").unwrap_err();
        assert!(e.to_string().contains("Pathh"), "{e}");
        let e = ron::from_str::<Holder>("(integrator: 3)").unwrap_err();
        assert!(
            e.to_string().contains("an integrator: one of `Whitted`"),
            "{e}"
        );
    }

    #[test]
    fn the_schema_lists_both_spellings() {
        let schema = serde_json::to_value(schemars::schema_for!(IntegratorKind)).unwrap();
        let spelled: Vec<&str> = schema["oneOf"]
            .as_array()
            .unwrap()
            .iter()
            .flat_map(|v| v["enum"].as_array().unwrap().iter())
            .map(|s| s.as_str().unwrap())
            .collect();
        assert_eq!(spelled, IntegratorKind::SPELLINGS);
        assert!(spelled.contains(&"path-ppm") && spelled.contains(&"PathPpm"));
    }

    #[test]
    fn clap_takes_both_spellings() {
        for k in IntegratorKind::ALL {
            assert_eq!(IntegratorKind::from_str(k.cli_name(), false), Ok(*k));
            assert_eq!(IntegratorKind::from_str(k.name(), false), Ok(*k));
        }
        assert!(IntegratorKind::from_str("nope", false).is_err());
    }
}

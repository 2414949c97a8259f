//! What a `.part` film records about the render it holds, so that `caustic merge` can tell
//! whether parts belong together and which samples they cover: a hash of everything that
//! decides the pixels ([`settings_hash`]), the sample indices taken, the image size, region,
//! integrator and exposure; plus informational fields (scene path, shard, render time) for
//! `caustic farm status`. Stored as the film's metadata string, one `key=value` per line.

use std::ops::Range;

use crate::binfile::meta_text::{MetaText, malformed};
use crate::render::Region;
use crate::render_scene::RenderScene;
use crate::render_scene::hash::pixel_key;

/// First line of the metadata: the format and its version.
const HEADER: &str = "caustic-part 1";

/// Why a part's metadata could not be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("`{path}`: {reason}")]
pub struct PartMetaError {
    /// The part file.
    pub path: String,
    /// What is missing or malformed.
    pub reason: String,
}

/// The metadata of a `.part` film.
#[derive(Debug, Clone, PartialEq)]
pub struct PartMeta {
    /// [`settings_hash`] of the compiled scene after overrides.
    pub hash: u64,
    /// Sample indices the film holds, sorted and disjoint (one range for a render or shard;
    /// several after a partial merge).
    pub samples: Vec<Range<u32>>,
    /// Samples per pixel of the whole render (`render.samples_per_pixel`).
    pub spp: u32,
    /// Width of the whole image in pixels.
    pub width: u32,
    /// Height of the whole image in pixels.
    pub height: u32,
    /// The crop rendered (`None`: the whole image).
    pub region: Option<Region>,
    /// The integrator's name (`Whitted`, `Path`, `Photon`, ...).
    pub integrator: String,
    /// The scene's exposure (needed to write a PNG identical to the single render's).
    pub exposure: f32,
    /// Informational: the scene file rendered.
    pub scene: String,
    /// Informational: the shard (`i/N`), if the render was one.
    pub shard: Option<String>,
    /// Informational: render wall time in seconds (summed over merged parts).
    pub seconds: f64,
}

/// A 64-bit hash of everything in `scene` that decides pixel values: the scene's pixel key
/// ([`crate::render_scene::hash::pixel_key`]: geometry, materials, textures with their texels,
/// lights, every render and photon parameter, the camera and the crate version, derived field by
/// field from the data). FNV-1a (accidental mismatches, not adversaries). Two renders with the
/// same hash and disjoint sample ranges merge into the render of their union; the output path
/// and the thread count are not in it.
#[must_use]
pub fn settings_hash(scene: &RenderScene) -> u64 {
    pixel_key(scene)
}

/// `0..4,8..12` (empty: `none`).
#[must_use]
pub fn format_ranges(ranges: &[Range<u32>]) -> String {
    if ranges.is_empty() {
        return "none".into();
    }
    let parts: Vec<String> = ranges
        .iter()
        .map(|r| format!("{}..{}", r.start, r.end))
        .collect();
    parts.join(",")
}

fn parse_ranges(text: &str) -> Option<Vec<Range<u32>>> {
    if text == "none" {
        return Some(Vec::new());
    }
    text.split(',')
        .map(|r| {
            let (a, b) = r.split_once("..")?;
            let (a, b) = (a.parse().ok()?, b.parse().ok()?);
            (a < b).then_some(a..b)
        })
        .collect()
}

impl PartMeta {
    /// The metadata string stored in the film file.
    #[must_use]
    pub fn to_text(&self) -> String {
        let region = self.region.map_or_else(
            || "full".to_string(),
            |r| format!("{},{},{},{}", r.x, r.y, r.width, r.height),
        );
        format!(
            "{HEADER}\nhash={:016x}\nsamples={}\nspp={}\nwidth={}\nheight={}\nregion={region}\nintegrator={}\nexposure={:?}\nshard={}\nseconds={:.3}\nscene={}\n",
            self.hash,
            format_ranges(&self.samples),
            self.spp,
            self.width,
            self.height,
            self.integrator,
            self.exposure,
            self.shard.as_deref().unwrap_or("none"),
            self.seconds,
            self.scene.replace('\n', " "),
        )
    }

    /// The metadata of a film of `scene` (whose [`settings_hash`] is `hash`) holding samples
    /// `samples` of `spp` per pixel over `region` (`None`: the whole image). The exposure is the
    /// resolved one and the informational fields are empty; a caller that knows them (the scene
    /// path, the shard, the render time, a stated or automatic exposure) sets them over this.
    #[must_use]
    pub fn of(
        scene: &RenderScene,
        hash: u64,
        samples: Range<u32>,
        spp: u32,
        region: Option<Region>,
    ) -> Self {
        let p = &scene.params;
        Self {
            hash,
            samples: if samples.is_empty() {
                Vec::new()
            } else {
                vec![samples]
            },
            spp,
            width: p.width,
            height: p.height,
            region,
            integrator: format!("{:?}", p.integrator),
            exposure: p.exposure,
            scene: String::new(),
            shard: None,
            seconds: 0.0,
        }
    }

    /// Reads [`PartMeta::to_text`]'s output; `path` names the file in errors.
    ///
    /// # Errors
    /// When the header is not this format's or a required field is missing or malformed.
    pub fn parse(text: &str, path: &str) -> Result<Self, PartMetaError> {
        let err = |reason: String| PartMetaError {
            path: path.to_string(),
            reason,
        };
        let m = MetaText::parse(text, HEADER).ok_or_else(|| {
            err(format!(
                "its metadata is not `{HEADER}` (written by an older caustic, or not by `caustic render --shard`/`-o FILE.part`); render it again"
            ))
        })?;
        let get = |key: &str| m.get(key).map_err(&err);
        let bad = |key: &str, v: &str| err(malformed(key, v));
        let num = |key: &str| m.parsed::<u32>(key).map_err(&err);
        let hash_text = get("hash")?;
        let hash = u64::from_str_radix(hash_text, 16).map_err(|_| bad("hash", hash_text))?;
        let samples_text = get("samples")?;
        let samples = parse_ranges(samples_text).ok_or_else(|| bad("samples", samples_text))?;
        let region_text = get("region")?;
        let region = if region_text == "full" {
            None
        } else {
            let v: Vec<u32> = region_text
                .split(',')
                .map(str::parse)
                .collect::<Result<_, _>>()
                .map_err(|_| bad("region", region_text))?;
            match v.as_slice() {
                [x, y, width, height] => Some(Region {
                    x: *x,
                    y: *y,
                    width: *width,
                    height: *height,
                }),
                _ => return Err(bad("region", region_text)),
            }
        };
        let shard = get("shard")?;
        Ok(Self {
            hash,
            samples,
            spp: num("spp")?,
            width: num("width")?,
            height: num("height")?,
            region,
            integrator: get("integrator")?.to_string(),
            exposure: m.parsed("exposure").map_err(&err)?,
            scene: get("scene")?.to_string(),
            shard: (shard != "none").then(|| shard.to_string()),
            seconds: m.parsed("seconds").map_err(&err)?,
        })
    }

    /// Samples per pixel the film holds.
    #[must_use]
    pub fn sample_count(&self) -> u32 {
        self.samples.iter().map(|r| r.end - r.start).sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn meta() -> PartMeta {
        PartMeta {
            hash: 0x0123_4567_89ab_cdef,
            samples: vec![0..4, 8..12],
            spp: 16,
            width: 64,
            height: 48,
            region: Some(Region {
                x: 1,
                y: 2,
                width: 3,
                height: 4,
            }),
            integrator: "Path".into(),
            exposure: 0.1,
            scene: "scenes/cornell.ron".into(),
            shard: Some("2/4".into()),
            seconds: 1.5,
        }
    }

    #[test]
    fn metadata_round_trips() {
        let m = meta();
        assert_eq!(PartMeta::parse(&m.to_text(), "p"), Ok(m.clone()));
        let whole = PartMeta {
            samples: vec![],
            region: None,
            shard: None,
            ..m
        };
        assert_eq!(PartMeta::parse(&whole.to_text(), "p"), Ok(whole.clone()));
        assert_eq!(whole.sample_count(), 0);
        assert_eq!(meta().sample_count(), 8);
    }

    #[test]
    fn bad_metadata_names_the_file_and_field() {
        let old = PartMeta::parse("scene=x\nspp=4\n", "old.part").unwrap_err();
        assert!(
            old.to_string()
                .starts_with("`old.part`: its metadata is not"),
            "{old}"
        );
        let text = meta()
            .to_text()
            .replace("samples=0..4,8..12", "samples=4..2");
        let e = PartMeta::parse(&text, "a.part").unwrap_err();
        assert_eq!(e.reason, "its metadata field `samples=4..2` is malformed");
        let text = meta().to_text().replace("spp=16\n", "");
        let e = PartMeta::parse(&text, "a.part").unwrap_err();
        assert_eq!(e.reason, "its metadata has no `spp` field");
    }
}

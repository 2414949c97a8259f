//! Materials and the textures they use, compiled on first use so nothing unused is loaded.

use std::collections::{BTreeMap, HashMap};
use std::hash::Hash;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Vec2, Vec3};

use crate::render_scene::texture::{Mapping as RenderMapping, NoiseTexture};
use crate::render_scene::{Interior, SurfaceMaterial, Texture};
use crate::scene::Diagnostic;
use crate::scene::schema::{
    AbsorptionSpec, ColorSpec, ConductorSpec, Mapping, SceneFile, TextureSpec,
};
use crate::shading::Bsdf;
use crate::shading::absorption::Absorption;
use crate::shading::conductor::{ConductorFresnel, ConductorPreset};
use crate::shading::microfacet::Ggx;
use crate::texture::bitmap::read_colour_image;
use crate::texture::normal_map::read_normal_image;
use crate::texture::{
    BitmapTexture, GreyMipMap, HeightMap, Marble, MipMap, Noise, NormalMap, Ripples, TextureError,
};

/// Materials resolved on first use, so unused ones (and their textures) are not compiled.
#[derive(Default)]
pub(super) struct MaterialTable {
    index: BTreeMap<String, u32>,
    pub list: Vec<(String, SurfaceMaterial)>,
    pub textures: TextureTable,
}

impl MaterialTable {
    /// The index of material `name`, compiling it (and its textures) on first use. Texture
    /// errors go to `errors`; `None` only for a name the scene does not define.
    pub fn resolve(
        &mut self,
        scene: &SceneFile,
        base_dir: &Path,
        name: &str,
        errors: &mut Vec<Diagnostic>,
    ) -> Option<u32> {
        if let Some(&i) = self.index.get(name) {
            return Some(i);
        }
        let m = scene.materials.get(name)?;
        let (color, color_texture) = match &m.color {
            ColorSpec::Rgb(c) => (Vec3::from(*c), None),
            ColorSpec::Texture(t) => (
                Vec3::ONE,
                self.textures.resolve(
                    scene,
                    base_dir,
                    t,
                    &format!("materials.{name}.color"),
                    errors,
                ),
            ),
        };
        let bump = m.bump.as_deref().and_then(|t| {
            self.textures.resolve(
                scene,
                base_dir,
                t,
                &format!("materials.{name}.bump"),
                errors,
            )
        });
        let normal_map = m.normal_map.as_deref().and_then(|t| {
            self.textures.resolve(
                scene,
                base_dir,
                t,
                &format!("materials.{name}.normal_map"),
                errors,
            )
        });
        let [rx, ry] = m.roughness.pair().unwrap_or([0.0, 0.0]);
        // Perceptual roughness r to the GGX width α = r² (docs/material.md); 0 is smooth. A
        // roughness texture leaves the BSDF smooth here and roughens it at each hit.
        let distribution = (rx > 0.0 || ry > 0.0).then(|| Ggx::new(rx * rx, ry * ry));
        let roughness_texture = m.roughness.texture().and_then(|t| {
            self.textures.resolve(
                scene,
                base_dir,
                t,
                &format!("materials.{name}.roughness"),
                errors,
            )
        });
        let conductor = match &m.conductor {
            None => None,
            Some(ConductorSpec::Preset(p)) => {
                let preset = ConductorPreset::from_name(p);
                if preset.is_none() {
                    errors.push(Diagnostic::error(
                        format!("materials.{name}.conductor"),
                        format!("unknown conductor `{p}`"),
                    ));
                }
                preset.map(ConductorFresnel::preset)
            }
            Some(ConductorSpec::Tint(t)) => Some(ConductorFresnel::F82Tint {
                f0: Vec3::from(t.f0),
                tint: Vec3::from(t.tint),
            }),
        };
        let absorption = match m.absorption {
            None => Ok(Absorption::CLEAR),
            Some(AbsorptionSpec::Coefficient(sigma)) => Absorption::from_coefficient(sigma),
            Some(AbsorptionSpec::ColorAtDepth(c)) => {
                Absorption::from_colour_at_depth(c.color, c.depth)
            }
        };
        let absorption = absorption.unwrap_or_else(|e| {
            errors.push(Diagnostic::error(
                format!("materials.{name}.absorption"),
                e.to_string(),
            ));
            Absorption::CLEAR
        });
        let bsdf = if m.interface {
            // No surface: the index-matched pass-through (a dielectric of index 1, white).
            Bsdf::new(Vec3::ONE, Vec3::ZERO, 1.0, [None, None, Some(1.0)], 1.0)
        } else {
            Bsdf::new(
                color,
                Vec3::from(m.specular),
                m.shininess,
                [m.diffuse, m.reflect, m.transmit],
                m.ior,
            )
            .with_microfacets(distribution, conductor)
            .with_coat(m.coat.map(|c| c.ior))
        };
        let medium = m
            .medium
            .as_deref()
            .and_then(|n| super::media::medium_index(scene, n));
        let ior = if m.interface { None } else { bsdf.ior() };
        let interior = Interior {
            encloses: ior.is_some()
                || !absorption.is_clear()
                || medium.is_some()
                || m.priority.is_some()
                || m.interface,
            priority: m.priority,
            medium,
            interface: m.interface,
            ior,
        };
        let filtered = [color_texture, bump, normal_map, roughness_texture]
            .into_iter()
            .flatten()
            .any(|t| self.textures.list[t as usize].filtered());
        let i = self.list.len() as u32;
        self.list.push((
            name.to_string(),
            SurfaceMaterial {
                bsdf,
                color_texture,
                bump,
                normal_map,
                roughness_texture,
                conductor,
                filtered,
                absorption,
                interior,
            },
        ));
        self.index.insert(name.to_string(), i);
        Some(i)
    }
}

/// Textures resolved on first use; each image file is decoded once per use (colour or grey).
#[derive(Default)]
pub(super) struct TextureTable {
    index: BTreeMap<String, Option<u32>>,
    pub list: Vec<Texture>,
    colour_images: HashMap<(PathBuf, Option<bool>), Arc<MipMap<Vec3>>>,
    grey_images: HashMap<PathBuf, Arc<GreyMipMap>>,
    normal_images: HashMap<PathBuf, Arc<MipMap<Vec3>>>,
    /// Image files decoded.
    pub images_loaded: usize,
    /// Warnings about the images read (negative texels clamped).
    pub warnings: Vec<Diagnostic>,
}

impl TextureTable {
    fn resolve(
        &mut self,
        scene: &SceneFile,
        base_dir: &Path,
        name: &str,
        used_at: &str,
        errors: &mut Vec<Diagnostic>,
    ) -> Option<u32> {
        if let Some(&i) = self.index.get(name) {
            return i;
        }
        let Some(spec) = scene.textures.get(name) else {
            errors.push(Diagnostic::error(
                used_at,
                format!("unknown texture `{name}`"),
            ));
            return None;
        };
        let at = format!("textures.{name}");
        let built = self.build(spec, base_dir, &at);
        let i = match built {
            Ok(t) => {
                self.list.push(t);
                Some(self.list.len() as u32 - 1)
            }
            Err(d) => {
                errors.push(*d);
                None
            }
        };
        self.index.insert(name.to_string(), i);
        i
    }

    fn build(
        &mut self,
        spec: &TextureSpec,
        base_dir: &Path,
        at: &str,
    ) -> Result<Texture, Box<Diagnostic>> {
        let load_error = |file: &str, e| file_error(at, base_dir, file, &e);
        Ok(match spec {
            TextureSpec::Bitmap { file, tile, srgb } => {
                let path = base_dir.join(file);
                let mut fresh = None;
                let mip = cached(
                    &mut self.colour_images,
                    &mut self.images_loaded,
                    (path.clone(), *srgb),
                    || {
                        let image = read_colour_image(&path, *srgb)?;
                        fresh = Some((image.negative_texels, image.first_negative));
                        Ok(image.mip)
                    },
                )
                .map_err(|e| load_error(file, e))?;
                if let Some((count, Some((x, y)))) = fresh
                    && count > 0
                {
                    self.warnings.push(
                        Diagnostic::warning(
                            format!("{at}.file"),
                            format!(
                                "`{}` has {count} texel{} with negative values (the first at x = {x}, y = {y}), clamped to 0: a colour is a reflectance, which cannot be negative",
                                path.display(),
                                if count == 1 { "" } else { "s" }
                            ),
                        )
                        .with_help("negative values in an EXR usually come from a colour-space conversion; clamp them when exporting to silence this"),
                    );
                }
                Texture::Bitmap(BitmapTexture::new(mip, Vec2::from(*tile)))
            }
            TextureSpec::HeightMap { file, depth, tile } => {
                let path = base_dir.join(file);
                let mip = cached(
                    &mut self.grey_images,
                    &mut self.images_loaded,
                    path.clone(),
                    || MipMap::open_grey(&path),
                )
                .map_err(|e| load_error(file, e))?;
                Texture::HeightMap(HeightMap::new(mip, *depth, Vec2::from(*tile)))
            }
            TextureSpec::NormalMap {
                file,
                tile,
                strength,
                flip_y,
            } => {
                let path = base_dir.join(file);
                let mip = cached(
                    &mut self.normal_images,
                    &mut self.images_loaded,
                    path.clone(),
                    || read_normal_image(&path),
                )
                .map_err(|e| load_error(file, e))?;
                Texture::NormalMap(NormalMap::new(mip, Vec2::from(*tile), *strength, *flip_y))
            }
            TextureSpec::Marble {
                base,
                vein,
                frequency,
                octaves,
                turbulence,
                seed,
                depth,
                mapping,
            } => Texture::Marble {
                marble: Marble::new(
                    Vec3::from(frequency.factors()),
                    *octaves,
                    *turbulence,
                    Vec3::from(*base),
                    Vec3::from(*vein),
                    *seed,
                ),
                depth: *depth,
                mapping: render_mapping(*mapping),
            },
            TextureSpec::Noise {
                low,
                high,
                frequency,
                octaves,
                turbulence,
                seed,
                depth,
                mapping,
            } => Texture::Noise(NoiseTexture {
                noise: Noise::new(*seed),
                low: Vec3::from(*low),
                high: Vec3::from(*high),
                frequency: *frequency,
                octaves: *octaves,
                turbulence: *turbulence,
                depth: *depth,
                mapping: render_mapping(*mapping),
            }),
            TextureSpec::Ripple {
                centers,
                frequency,
                amplitude,
                decay,
            } => Texture::Ripple(Ripples::new(
                centers.iter().map(|c| Vec2::from(*c)).collect(),
                *frequency,
                *amplitude,
                *decay,
            )),
        })
    }
}

/// The pyramid cached under `key`, or `load`ed (and counted in `loaded`) on first use.
fn cached<K: Eq + Hash, T>(
    cache: &mut HashMap<K, Arc<T>>,
    loaded: &mut usize,
    key: K,
    load: impl FnOnce() -> Result<T, TextureError>,
) -> Result<Arc<T>, TextureError> {
    if let Some(m) = cache.get(&key) {
        return Ok(Arc::clone(m));
    }
    let m = Arc::new(load()?);
    *loaded += 1;
    cache.insert(key, Arc::clone(&m));
    Ok(m)
}

/// For an asset `file` that does not exist: the did-you-mean against the files beside it.
pub(super) fn missing_file_help(base_dir: &Path, file: &str) -> Option<String> {
    if base_dir.join(file).exists() {
        return None;
    }
    let near = crate::scene::diagnostic::did_you_mean_file(base_dir, file)?;
    Some(format!(
        "did you mean `{near}`? (a file beside it; paths are relative to the scene file)"
    ))
}

/// The diagnostic for an image file of texture `at` that cannot be loaded.
fn file_error(at: &str, base_dir: &Path, file: &str, e: &TextureError) -> Box<Diagnostic> {
    Box::new(
        Diagnostic::error(
            format!("{at}.file"),
            format!(
                "cannot load image `{}`: {}",
                base_dir.join(file).display(),
                image_error_text(e)
            ),
        )
        .with_help(match (e, missing_file_help(base_dir, file)) {
            (_, Some(help)) => help,
            (TextureError::NonFinite { .. }, None) => "NaN and infinite values mean nothing as a colour or a height; fix or re-export the image".into(),
            (_, None) => "textures must be PNG, JPEG or EXR files; paths are relative to the scene file".into(),
        }),
    )
}

fn render_mapping(m: Mapping) -> RenderMapping {
    match m {
        Mapping::Solid => RenderMapping::Solid,
        Mapping::Uv => RenderMapping::Uv,
    }
}

/// A texture error as a sentence without the redundant "cannot load texture image" prefix.
fn image_error_text(e: &TextureError) -> String {
    match e {
        TextureError::Image(image::ImageError::IoError(io)) => io.to_string(),
        TextureError::Image(img) => img.to_string(),
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use crate::scene::schema::CONDUCTOR_PRESETS;
    use crate::shading::conductor::ConductorPreset;

    #[test]
    fn the_scene_format_names_the_same_conductor_presets_as_the_shading_table() {
        assert_eq!(CONDUCTOR_PRESETS, ConductorPreset::NAMES);
    }
}

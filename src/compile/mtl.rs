//! OBJ material libraries (`.mtl`, Wavefront's MTL format as tobj reads it) mapped onto
//! caustic's material model, for `Mesh(file: …, mtl: true)`.
//!
//! | MTL | caustic | note |
//! |---|---|---|
//! | `Kd` | `color` | clamped to [0, 1] |
//! | `Ks`, `Ns` | `specular`, `shininess` (normalised Phong) | `Ks` scaled down where `Kd + Ks` > 1 |
//! | `d` < 1 (or `Tr` = 1 − `d`) | `transmit: 1 − d`, `diffuse: d` | a smooth dielectric, not alpha |
//! | `Ni` | `ior` | used by the dielectric part |
//! | `map_Kd` | `color` texture (`Bitmap`, sRGB) | replaces `Kd` (not multiplied) |

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

use crate::scene::schema::{ColorSpec, MaterialSpec, TextureSpec};

/// Why a material library could not be used.
#[derive(Debug, thiserror::Error)]
pub enum MtlError {
    /// The OBJ file names no library.
    #[error("`{}` names no material library (`mtllib` statement), so `mtl: true` has nothing to read", obj.display())]
    NoLibrary {
        /// The OBJ file.
        obj: PathBuf,
    },
    /// The library could not be read.
    #[error("cannot read material library `{}` (named by `{}`): {problem}", path.display(), obj.display())]
    Read {
        /// The `.mtl` file.
        path: PathBuf,
        /// The OBJ file naming it.
        obj: PathBuf,
        /// What went wrong.
        problem: String,
    },
}

/// The materials of an OBJ file's libraries, as scene materials and the textures they use.
#[derive(Debug, Default)]
pub struct MtlMaterials {
    /// By MTL name.
    pub materials: BTreeMap<String, MaterialSpec>,
    /// By texture name (`<mtl file>#map_Kd <material>`), image paths made absolute.
    pub textures: BTreeMap<String, TextureSpec>,
    /// What maps only approximately, one sentence per material that needs one.
    pub notes: Vec<String>,
}

/// A material with every field at the scene format's default (as `()` in a scene file).
pub(super) fn default_material() -> MaterialSpec {
    MaterialSpec {
        color: ColorSpec::Rgb([0.8; 3]),
        specular: [0.0; 3],
        shininess: 32.0,
        diffuse: None,
        reflect: None,
        transmit: None,
        ior: 1.5,
        bump: None,
        normal_map: None,
        roughness: crate::scene::schema::RoughnessSpec::Isotropic(0.0),
        conductor: None,
        absorption: None,
        coat: None,
        medium: None,
        priority: None,
        interface: false,
    }
}

/// Reads the libraries `mtllibs` (paths relative to the OBJ file `obj`) and maps their
/// materials; a name defined twice keeps its first definition, as tobj does.
///
/// # Errors
/// An [`MtlError`] when the OBJ names no library or one cannot be read.
pub fn read_mtl(obj: &Path, mtllibs: &[String]) -> Result<MtlMaterials, MtlError> {
    if mtllibs.is_empty() {
        return Err(MtlError::NoLibrary {
            obj: obj.to_path_buf(),
        });
    }
    let dir = obj.parent().unwrap_or(Path::new(""));
    let mut out = MtlMaterials::default();
    for lib in mtllibs {
        let path = dir.join(lib);
        let read_err = |problem: String| MtlError::Read {
            path: path.clone(),
            obj: obj.to_path_buf(),
            problem,
        };
        let (_, bytes) =
            super::mesh_file::read_mesh_file(&path, super::mesh_file::MAX_MESH_FILE_BYTES)
                .map_err(|e| read_err(e.to_string()))?;
        let mut reader = std::io::BufReader::new(bytes.as_slice());
        let (materials, _) =
            tobj::load_mtl_buf(&mut reader).map_err(|e| read_err(e.to_string()))?;
        for m in materials {
            if out.materials.contains_key(&m.name) {
                continue;
            }
            let (spec, texture, note) = map_material(&m, &path, dir);
            if let Some((name, t)) = texture {
                out.textures.insert(name, t);
            }
            if let Some(note) = note {
                out.notes.push(note);
            }
            out.materials.insert(m.name.clone(), spec);
        }
    }
    Ok(out)
}

/// One MTL material as a scene material (and its colour texture), with a sentence on what maps
/// only approximately.
fn map_material(
    m: &tobj::Material,
    lib: &Path,
    dir: &Path,
) -> (MaterialSpec, Option<(String, TextureSpec)>, Option<String>) {
    let mut spec = default_material();
    let mut approx: Vec<String> = Vec::new();
    let clamp = |c: [f32; 3]| {
        c.map(|x| {
            if x.is_finite() {
                x.clamp(0.0, 1.0)
            } else {
                0.0
            }
        })
    };
    let kd = m.diffuse.map_or([0.8; 3], clamp);
    if m.diffuse.is_some_and(|c| c != kd) {
        approx.push("`Kd` clamped to [0, 1]".into());
    }
    spec.color = ColorSpec::Rgb(kd);
    let mut texture = None;
    if let Some(map) = m
        .diffuse_texture
        .as_deref()
        .filter(|t| !t.trim().is_empty())
    {
        // `map_Kd` may carry options (`-s 2 2 1 file.png`): the file is the last word.
        let file = map.split_whitespace().last().unwrap_or(map);
        if map.split_whitespace().count() > 1 {
            approx.push(format!("the options of `map_Kd {map}` are ignored"));
        }
        let name = format!("{}#map_Kd {}", lib.display(), m.name);
        texture = Some((
            name.clone(),
            TextureSpec::Bitmap {
                file: dir.join(file).to_string_lossy().into_owned(),
                tile: [1.0, 1.0],
                srgb: None,
            },
        ));
        if kd != [1.0; 3] && m.diffuse.is_some() {
            approx.push("`map_Kd` replaces `Kd` instead of being multiplied by it".into());
        }
        spec.color = ColorSpec::Texture(name);
    }
    if let Some(ks) = m.specular.map(clamp) {
        let base = if texture.is_some() { [1.0; 3] } else { kd };
        let scale = (0..3)
            .map(|i| {
                if base[i] + ks[i] > 1.0 && ks[i] > 0.0 {
                    ((1.0 - base[i]) / ks[i]).max(0.0)
                } else {
                    1.0
                }
            })
            .fold(1.0f32, f32::min);
        if scale < 1.0 {
            approx.push(format!(
                "`Ks` scaled by {scale:.3} so that `Kd` + `Ks` ≤ 1 (energy conservation)"
            ));
        }
        spec.specular = ks.map(|s| s * scale);
    }
    if let Some(ns) = m.shininess.filter(|n| n.is_finite()) {
        spec.shininess = ns.max(0.0);
    }
    if let Some(ni) = m.optical_density.filter(|n| n.is_finite() && *n > 0.0) {
        spec.ior = ni;
    }
    if let Some(d) = m.dissolve.filter(|d| d.is_finite() && *d < 1.0) {
        let d = d.clamp(0.0, 1.0);
        spec.diffuse = Some(d);
        spec.transmit = Some(1.0 - d);
        approx.push(format!(
            "`d {d}` is read as a smooth dielectric of weight {} (refracting with `Ni`), not as alpha",
            1.0 - d
        ));
        if spec.specular != [0.0; 3] && d == 0.0 {
            spec.specular = [0.0; 3];
        }
    }
    let note = (!approx.is_empty()).then(|| {
        format!(
            "material `{}` of `{}`: {}",
            m.name,
            lib.display(),
            approx.join("; ")
        )
    });
    (spec, texture, note)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn mtl_statements_map_to_the_scene_format() {
        let text = "newmtl glass\nKd 1 1 1\nKs 0.5 0.5 0.5\nNs 200\nNi 1.33\nd 0.25\n\
                    newmtl red\nKd 0.8 0.1 0.1\nKs 0.1 0.1 0.1\nNs 50\n\
                    newmtl wood\nKd 1 1 1\nmap_Kd tex/wood.png\n";
        let dir = tempfile::tempdir().expect("tmp");
        std::fs::write(dir.path().join("a.mtl"), text).expect("write");
        let obj = dir.path().join("a.obj");
        let out = read_mtl(&obj, &["a.mtl".to_string()]).expect("reads");
        let red = &out.materials["red"];
        assert_eq!(red.color, ColorSpec::Rgb([0.8, 0.1, 0.1]));
        assert_eq!(red.specular, [0.1; 3]);
        assert_eq!(red.shininess, 50.0);
        assert_eq!((red.diffuse, red.transmit), (None, None));
        let glass = &out.materials["glass"];
        assert_eq!(glass.ior, 1.33);
        assert_eq!((glass.diffuse, glass.transmit), (Some(0.25), Some(0.75)));
        // Kd 1 + Ks 0.5 > 1: the highlight is scaled to 0.
        assert_eq!(glass.specular, [0.0; 3]);
        let wood = &out.materials["wood"];
        let ColorSpec::Texture(t) = &wood.color else {
            panic!("a texture")
        };
        let TextureSpec::Bitmap { file, .. } = &out.textures[t] else {
            panic!("a bitmap")
        };
        assert_eq!(Path::new(file), dir.path().join("tex/wood.png"));
        assert_eq!(out.notes.len(), 1, "{:?}", out.notes);
        assert!(
            out.notes[0].starts_with("material `glass`"),
            "{:?}",
            out.notes
        );
        let e = read_mtl(&obj, &[]).expect_err("no library");
        assert!(e.to_string().contains("names no material library"), "{e}");
    }
}

//! OBJ loading via tobj: polygons triangulated by their shape ([`super::polygon`]), indices
//! checked, each file read once per compilation.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use glam::{Vec2, Vec3};

use super::polygon::triangulate;

/// One triangle corner: indices into positions, normals and texture coordinates.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Corner {
    /// Position index.
    pub p: u32,
    /// Normal index, if the face has normals.
    pub n: Option<u32>,
    /// Texture-coordinate index, if the face has them.
    pub t: Option<u32>,
}

/// An OBJ file's geometry in object space, every index checked.
#[derive(Debug, Default)]
pub struct ObjMesh {
    /// Vertex positions.
    pub positions: Vec<Vec3>,
    /// Vertex normals (as written, not normalised).
    pub normals: Vec<Vec3>,
    /// Texture coordinates in the renderer's convention (v grows downwards, so OBJ's
    /// bottom-up `vt` v is stored as 1 − v).
    pub uvs: Vec<Vec2>,
    /// Triangles: faces with more than three corners are triangulated by their shape (ear
    /// clipping on their best-fit plane), so concave polygons keep their notches.
    pub triangles: Vec<[Corner; 3]>,
    /// Faces whose shape is suspect (not planar, or crossing themselves), as sentences naming
    /// the OBJ line; the triangles are still made.
    pub warnings: Vec<String>,
    /// The file's group (`g`/`o`) and `usemtl` names, each once, in order of first use.
    pub names: Vec<String>,
    /// Per triangle (parallel to `triangles`): the names of the face it came from.
    pub triangle_names: Vec<FaceNames>,
}

/// The names an OBJ face is under, as indices into [`ObjMesh::names`].
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct FaceNames {
    /// The last `g` or `o` statement before the face (`None` before any, or after an empty one).
    pub group: Option<u32>,
    /// The last `usemtl` statement before the face.
    pub usemtl: Option<u32>,
}

impl ObjMesh {
    /// The index of `name` in [`ObjMesh::names`], if the file uses it.
    #[must_use]
    pub fn name_index(&self, name: &str) -> Option<u32> {
        self.names.iter().position(|n| n == name).map(|i| i as u32)
    }
}

/// What [`check_obj_text`] learns about each face, in file order.
struct FaceRecord {
    /// 1-based line.
    line: usize,
    names: FaceNames,
}

/// Loaded meshes by resolved path (errors are not cached; each node reports its own).
#[derive(Default)]
pub(super) struct MeshCache {
    meshes: HashMap<PathBuf, Rc<ObjMesh>>,
}

impl MeshCache {
    pub fn len(&self) -> usize {
        self.meshes.len()
    }

    /// Loads `path` (or returns the cached copy); the error is a user-facing sentence. The flag
    /// is true on the first load only, so a file's warnings are reported once.
    pub fn load(&mut self, path: &Path) -> Result<(Rc<ObjMesh>, bool), String> {
        if let Some(m) = self.meshes.get(path) {
            return Ok((Rc::clone(m), false));
        }
        let mesh = Rc::new(read_obj(path)?);
        self.meshes.insert(path.to_path_buf(), Rc::clone(&mesh));
        Ok((mesh, true))
    }
}

fn read_obj(path: &Path) -> Result<ObjMesh, String> {
    let bytes = std::fs::read(path)
        .map_err(|e| format!("cannot read OBJ file `{}`: {e}", path.display()))?;
    parse_obj(&bytes, path)
}

/// Parses OBJ bytes (`path` only names the file in messages); the error is a user-facing sentence.
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<ObjMesh, String> {
    let text = std::str::from_utf8(bytes).map_err(|e| {
        format!(
            "`{}` is not a text OBJ file (invalid UTF-8 at byte {})",
            path.display(),
            e.valid_up_to()
        )
    })?;
    let text = normalise_line_endings(text);
    let mut mesh = ObjMesh::default();
    let faces =
        check_obj_text(&text, &mut mesh.names).map_err(|e| format!("`{}` {e}", path.display()))?;
    let options = tobj::LoadOptions {
        single_index: false,
        triangulate: false,
        ignore_points: true,
        ignore_lines: true,
    };
    let mut reader = std::io::BufReader::new(text.as_bytes());
    // Materials come from the scene file, so .mtl files are never opened.
    let (models, _) = tobj::load_obj_buf(&mut reader, &options, |_| {
        Err(tobj::LoadError::OpenFileFailed)
    })
    .map_err(|e| format!("`{}` is not a valid OBJ file: {e}", path.display()))?;
    let mut faces_seen = 0;
    for model in &models {
        let m = &model.mesh;
        let (p0, n0, t0) = (
            mesh.positions.len() as u32,
            mesh.normals.len() as u32,
            mesh.uvs.len() as u32,
        );
        mesh.positions.extend(
            m.positions
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        mesh.normals.extend(
            m.normals
                .chunks_exact(3)
                .map(|c| Vec3::new(c[0], c[1], c[2])),
        );
        mesh.uvs.extend(
            m.texcoords
                .chunks_exact(2)
                .map(|c| Vec2::new(c[0], 1.0 - c[1])),
        );
        let has_n = m.normal_indices.len() == m.indices.len();
        let has_t = m.texcoord_indices.len() == m.indices.len();
        let corner = |i: usize| Corner {
            p: p0 + m.indices[i],
            n: has_n.then(|| n0 + m.normal_indices[i]),
            t: has_t.then(|| t0 + m.texcoord_indices[i]),
        };
        // Empty arities: every face is a triangle.
        let arities = if m.face_arities.is_empty() {
            vec![3; m.indices.len() / 3]
        } else {
            m.face_arities.clone()
        };
        let mut start = 0;
        for arity in arities {
            if start + arity as usize > m.indices.len() {
                break;
            }
            let corners: Vec<Corner> = (start..start + arity as usize).map(corner).collect();
            start += arity as usize;
            let record = faces.get(faces_seen);
            let line = record.map(|f| f.line);
            let names = record.map(|f| f.names).unwrap_or_default();
            faces_seen += 1;
            if corners.len() == 3 {
                mesh.triangles.push([corners[0], corners[1], corners[2]]);
                mesh.triangle_names.push(names);
                continue;
            }
            // Indices are checked against the file's records above, so positions exist.
            let shape: Vec<Vec3> = corners
                .iter()
                .map(|c| {
                    let i = 3 * (c.p - p0) as usize;
                    m.positions
                        .get(i..i + 3)
                        .map_or(Vec3::ZERO, Vec3::from_slice)
                })
                .collect();
            let t = triangulate(&shape);
            let at = line.map_or_else(|| format!("face {faces_seen}"), |l| format!("line {l}"));
            if let Some(off) = t.non_planar {
                mesh.warnings.push(format!(
                    "{at}: the {}-corner face is not planar (a corner is {:.1}% of its size off its best-fit plane); it is triangulated as projected on that plane",
                    corners.len(),
                    off * 100.0
                ));
            }
            if t.self_intersecting {
                mesh.warnings.push(format!(
                    "{at}: the {}-corner face crosses itself, so it has no well-defined inside; its triangles may cover too much or too little",
                    corners.len()
                ));
            }
            mesh.triangles
                .extend(t.triangles.iter().map(|tri| tri.map(|k| corners[k])));
            mesh.triangle_names.resize(mesh.triangles.len(), names);
        }
    }
    check_indices(&mesh)
        .map_err(|e| format!("`{}` is not a valid OBJ file: {e}", path.display()))?;
    if mesh.triangles.is_empty() {
        return Err(format!("`{}` contains no faces", path.display()));
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(format!(
            "`{}`: vertex {} has a non-finite coordinate",
            path.display(),
            i + 1
        ));
    }
    Ok(mesh)
}

/// `text` with every line ending made `\n`: CRLF (Windows) and a lone CR (classic Mac OS) each
/// end one line, as LF does, so line numbers stay those an editor shows. tobj splits lines on LF
/// only, so a CR-only file would otherwise read as one long comment or statement.
fn normalise_line_endings(text: &str) -> std::borrow::Cow<'_, str> {
    if text.contains('\r') {
        std::borrow::Cow::Owned(text.replace("\r\n", "\n").replace('\r', "\n"))
    } else {
        std::borrow::Cow::Borrowed(text)
    }
}

/// Checks the statements tobj relies on, so errors name the OBJ line: vertex records need
/// numbers, faces need at least three corners whose indices refer to records defined so far.
/// Returns each face's 1-based line and names, in file order (tobj keeps that order); the
/// group and `usemtl` names are added to `names`.
fn check_obj_text(text: &str, names: &mut Vec<String>) -> Result<Vec<FaceRecord>, String> {
    let (mut v, mut vt, mut vn) = (0i64, 0i64, 0i64);
    let mut faces = Vec::new();
    let mut current = FaceNames::default();
    let mut intern = |name: &str| {
        if name.is_empty() {
            return None;
        }
        let i = names.iter().position(|n| n == name).unwrap_or_else(|| {
            names.push(name.to_string());
            names.len() - 1
        });
        Some(i as u32)
    };
    for (n, raw) in text.lines().enumerate() {
        let line = raw.split('#').next().unwrap_or("").trim();
        let mut words = line.split_whitespace();
        let at = |msg: String| format!("line {}: `{}`: {msg}", n + 1, raw.trim());
        // The name is the rest of the line, as tobj reads it.
        let rest = || {
            line.split_once(char::is_whitespace)
                .map_or("", |r| r.1.trim())
        };
        match words.next() {
            Some("g" | "o") => current.group = intern(rest()),
            Some("usemtl") => current.usemtl = intern(rest()),
            Some(kind @ ("v" | "vt" | "vn")) => {
                let need = if kind == "vt" { 1 } else { 3 };
                let nums: Vec<&str> = words.collect();
                if nums.len() < need || nums.iter().any(|w| w.parse::<f32>().is_err()) {
                    let what = if kind == "vt" {
                        "a texture coordinate"
                    } else {
                        "a vertex or normal"
                    };
                    return Err(at(format!("{what} needs {need} or more numbers")));
                }
                match kind {
                    "v" => v += 1,
                    "vt" => vt += 1,
                    _ => vn += 1,
                }
            }
            Some("f") => {
                let corners: Vec<&str> = words.collect();
                if corners.len() < 3 {
                    return Err(at("a face needs at least three corners".into()));
                }
                faces.push(FaceRecord {
                    line: n + 1,
                    names: current,
                });
                for corner in corners {
                    for (i, (part, count, what)) in corner
                        .split('/')
                        .zip([(v, "vertex"), (vt, "texture coordinate"), (vn, "normal")])
                        .map(|(p, (c, w))| (p, c, w))
                        .enumerate()
                    {
                        if part.is_empty() && i > 0 {
                            continue;
                        }
                        let index: i64 = part
                            .parse()
                            .map_err(|_| at(format!("`{corner}` is not a face corner")))?;
                        let resolved = if index < 0 { count + index + 1 } else { index };
                        if resolved < 1 || resolved > count {
                            let plural = match what {
                                "vertex" => "vertices",
                                "normal" => "normals",
                                _ => "texture coordinates",
                            };
                            return Err(at(format!(
                                "the face uses {what} {index}, but only {count} {} defined above it",
                                if count == 1 {
                                    format!("{what} is")
                                } else {
                                    format!("{plural} are")
                                }
                            )));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(faces)
}

fn check_indices(mesh: &ObjMesh) -> Result<(), String> {
    let (np, nn, nt) = (mesh.positions.len(), mesh.normals.len(), mesh.uvs.len());
    for (f, tri) in mesh.triangles.iter().enumerate() {
        for c in tri {
            let bad = c.p as usize >= np
                || c.n.is_some_and(|n| n as usize >= nn)
                || c.t.is_some_and(|t| t as usize >= nt);
            if bad {
                return Err(format!(
                    "face {} refers to a vertex, normal or texture coordinate that does not exist",
                    f + 1
                ));
            }
        }
    }
    Ok(())
}

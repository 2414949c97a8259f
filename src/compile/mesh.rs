//! OBJ loading via tobj: polygons triangulated by their shape ([`super::polygon`]), indices
//! checked, each file read once per compilation.

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;

use glam::{Vec2, Vec3};

use super::mesh_data::push_polygon;
pub use super::mesh_data::{Corner, FaceNames, ObjMesh};
use super::mesh_file::{MAX_MESH_FILE_BYTES, MeshFileError, MeshFormat, read_mesh_file};

/// Why a mesh file (OBJ, or PLY read by `compile::ply`) could not be loaded. Each message names
/// the file (and the line, where the fault is on one) and is a user-facing sentence.
#[derive(Debug, thiserror::Error)]
pub enum ObjError {
    /// The file could not be read, is not a regular file, is too large, or is of another kind.
    #[error(transparent)]
    File(#[from] MeshFileError),
    /// The file is not UTF-8 text.
    #[error("`{}` is not a text OBJ file (invalid UTF-8 at byte {at})", path.display())]
    NotText {
        /// The OBJ file.
        path: PathBuf,
        /// Offset of the first byte that is not UTF-8.
        at: usize,
    },
    /// A statement is malformed.
    #[error("`{}` line {line}: `{text}`: {problem}", path.display())]
    Line {
        /// The OBJ file.
        path: PathBuf,
        /// 1-based line.
        line: usize,
        /// The line as written (trimmed).
        text: String,
        /// What is wrong with it.
        problem: LineProblem,
    },
    /// The PLY reader refused the file.
    #[error(transparent)]
    Ply(#[from] super::mesh_file::PlyError),
    /// `tobj` refused the file.
    #[error("`{}` is not a valid OBJ file: {source}", path.display())]
    Invalid {
        /// The OBJ file.
        path: PathBuf,
        /// The parser's error.
        source: tobj::LoadError,
    },
    /// A triangle refers to a record that does not exist.
    #[error(
        "`{}` is not a valid OBJ file: face {face} refers to a vertex, normal or texture coordinate that does not exist",
        path.display()
    )]
    MissingRecord {
        /// The OBJ file.
        path: PathBuf,
        /// 1-based triangle (after triangulation).
        face: usize,
    },
    /// The file has no faces.
    #[error("`{}` contains no faces", path.display())]
    NoFaces {
        /// The OBJ file.
        path: PathBuf,
    },
    /// A vertex position is NaN or infinite.
    #[error("`{}`: vertex {vertex} has a non-finite coordinate", path.display())]
    NonFinite {
        /// The OBJ file.
        path: PathBuf,
        /// 1-based vertex.
        vertex: usize,
    },
}

/// What is wrong with one OBJ statement ([`ObjError::Line`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum LineProblem {
    /// A `v`, `vn` or `vt` record with too few numbers (or a word that is not one).
    #[error("{what} needs {need} or more numbers")]
    Numbers {
        /// `a vertex or normal` or `a texture coordinate`.
        what: &'static str,
        /// Numbers needed.
        need: usize,
    },
    /// A face with fewer than three corners.
    #[error("a face needs at least three corners")]
    FewCorners,
    /// A face corner that is not `v`, `v/t`, `v//n` or `v/t/n` with integer indices.
    #[error("`{0}` is not a face corner")]
    NotACorner(String),
    /// A face corner's index is 0, which OBJ does not use.
    #[error(
        "the face uses {what} index 0, but OBJ indices start at 1 (negative ones count back from the last {what})"
    )]
    IndexZero {
        /// `vertex`, `texture coordinate` or `normal`.
        what: &'static str,
    },
    /// A face corner's index refers to a record not defined above the face.
    #[error("the face uses {what} {index}, but only {count} {} defined above it", defined(what, *count))]
    Undefined {
        /// `vertex`, `texture coordinate` or `normal`.
        what: &'static str,
        /// The index as written (negative: relative to the end).
        index: i64,
        /// Records of that kind defined above the face.
        count: i64,
    },
}

/// `vertex is` / `vertices are` (etc.) for `count` records of kind `what`.
fn defined(what: &str, count: i64) -> String {
    if count == 1 {
        return format!("{what} is");
    }
    let plural = match what {
        "vertex" => "vertices",
        "normal" => "normals",
        _ => "texture coordinates",
    };
    format!("{plural} are")
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

    /// Adds a mesh read elsewhere (a glTF primitive) under `key`, which `Mesh` nodes made by the
    /// import name as their file.
    pub fn insert(&mut self, key: PathBuf, mesh: ObjMesh) {
        self.meshes.insert(key, Rc::new(mesh));
    }

    /// Loads `path` (or returns the cached copy); the error is a user-facing sentence. The flag
    /// is true on the first load only, so a file's warnings are reported once.
    pub fn load(&mut self, path: &Path) -> Result<(Rc<ObjMesh>, bool), ObjError> {
        if let Some(m) = self.meshes.get(path) {
            return Ok((Rc::clone(m), false));
        }
        let mesh = Rc::new(read_mesh(path)?);
        self.meshes.insert(path.to_path_buf(), Rc::clone(&mesh));
        Ok((mesh, true))
    }
}

/// Reads the mesh file at `path` (a regular file within [`MAX_MESH_FILE_BYTES`]) and parses it
/// by its kind.
fn read_mesh(path: &Path) -> Result<ObjMesh, ObjError> {
    let (format, bytes) = read_mesh_file(path, MAX_MESH_FILE_BYTES)?;
    match format {
        MeshFormat::Obj => parse_obj(&bytes, path),
        MeshFormat::Ply => Ok(super::ply::parse_ply(&bytes, path)?),
        MeshFormat::Gltf
        | MeshFormat::Glb
        | MeshFormat::Stl
        | MeshFormat::Fbx
        | MeshFormat::Blend => Err(MeshFileError::WrongKind {
            path: path.to_path_buf(),
            format,
            what: wrong_kind_help(format),
        }
        .into()),
    }
}

/// What to do with a file of `format` given to a `Mesh` node.
fn wrong_kind_help(format: MeshFormat) -> &'static str {
    match format {
        MeshFormat::Obj | MeshFormat::Ply => "a `Mesh` node reads OBJ and PLY files",
        MeshFormat::Gltf | MeshFormat::Glb => {
            "a `Mesh` node reads OBJ and PLY files; a glTF file is a scene: import it with a `Gltf(file: …)` node"
        }
        MeshFormat::Stl => {
            "a `Mesh` node reads OBJ and PLY files: convert it (e.g. Blender's import STL, export PLY)"
        }
        MeshFormat::Fbx => {
            "a `Mesh` node reads OBJ and PLY files: export it as one from the program that made it"
        }
        MeshFormat::Blend => {
            "a `Mesh` node reads OBJ and PLY files: export the object from Blender as one"
        }
    }
}

/// Parses OBJ bytes (`path` only names the file in messages).
///
/// # Errors
/// An [`ObjError`] naming the file (and line) when the bytes are not a valid OBJ file.
pub fn parse_obj(bytes: &[u8], path: &Path) -> Result<ObjMesh, ObjError> {
    let text = std::str::from_utf8(bytes).map_err(|e| ObjError::NotText {
        path: path.to_path_buf(),
        at: e.valid_up_to(),
    })?;
    let text = normalise_line_endings(text);
    let mut mesh = ObjMesh::default();
    let faces = check_obj_text(&text, &mut mesh.names, &mut mesh.mtllibs, path)?;
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
    .map_err(|source| ObjError::Invalid {
        path: path.to_path_buf(),
        source,
    })?;
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
            let at = line.map_or_else(|| format!("face {faces_seen}"), |l| format!("line {l}"));
            push_polygon(&mut mesh, &corners, &shape, names, &at);
        }
    }
    if let Some(face) = missing_record(&mesh) {
        return Err(ObjError::MissingRecord {
            path: path.to_path_buf(),
            face,
        });
    }
    if mesh.triangles.is_empty() {
        return Err(ObjError::NoFaces {
            path: path.to_path_buf(),
        });
    }
    if let Some(i) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(ObjError::NonFinite {
            path: path.to_path_buf(),
            vertex: i + 1,
        });
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
fn check_obj_text(
    text: &str,
    names: &mut Vec<String>,
    mtllibs: &mut Vec<String>,
    path: &Path,
) -> Result<Vec<FaceRecord>, ObjError> {
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
        let at = |problem: LineProblem| ObjError::Line {
            path: path.to_path_buf(),
            line: n + 1,
            text: raw.trim().to_string(),
            problem,
        };
        // The name is the rest of the line, as tobj reads it.
        let rest = || {
            line.split_once(char::is_whitespace)
                .map_or("", |r| r.1.trim())
        };
        match words.next() {
            Some("g" | "o") => current.group = intern(rest()),
            Some("usemtl") => current.usemtl = intern(rest()),
            Some("mtllib") => mtllibs.extend(rest().split_whitespace().map(str::to_string)),
            Some(kind @ ("v" | "vt" | "vn")) => {
                let need = if kind == "vt" { 1 } else { 3 };
                let nums: Vec<&str> = words.collect();
                if nums.len() < need || nums.iter().any(|w| w.parse::<f32>().is_err()) {
                    let what = if kind == "vt" {
                        "a texture coordinate"
                    } else {
                        "a vertex or normal"
                    };
                    return Err(at(LineProblem::Numbers { what, need }));
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
                    return Err(at(LineProblem::FewCorners));
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
                            .map_err(|_| at(LineProblem::NotACorner(corner.to_string())))?;
                        if index == 0 {
                            return Err(at(LineProblem::IndexZero { what }));
                        }
                        let resolved = if index < 0 { count + index + 1 } else { index };
                        if resolved < 1 || resolved > count {
                            return Err(at(LineProblem::Undefined { what, index, count }));
                        }
                    }
                }
            }
            _ => {}
        }
    }
    Ok(faces)
}

/// The first (1-based) triangle with a corner that refers to a position, normal or texture
/// coordinate that does not exist.
fn missing_record(mesh: &ObjMesh) -> Option<usize> {
    let (np, nn, nt) = (mesh.positions.len(), mesh.normals.len(), mesh.uvs.len());
    mesh.triangles
        .iter()
        .position(|tri| {
            tri.iter().any(|c| {
                c.p as usize >= np
                    || c.n.is_some_and(|n| n as usize >= nn)
                    || c.t.is_some_and(|t| t as usize >= nt)
            })
        })
        .map(|f| f + 1)
}

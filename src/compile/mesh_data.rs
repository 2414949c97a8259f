//! The mesh a file reader produces (positions, normals, uvs, triangles and their face names),
//! and the one polygon-to-triangles step every reader shares, so OBJ and PLY triangulate alike.

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
    /// The material libraries the file names (`mtllib`), as written, in order.
    pub mtllibs: Vec<String>,
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

/// Adds a face of `corners` (at positions `shape`) to `mesh` as triangles: a triangle as it is,
/// a larger polygon triangulated by its shape (ear clipping on its best-fit plane,
/// [`triangulate`]), with a warning naming the face (`at`: `line 12`, `face 3`) if it is not
/// planar or crosses itself. Shared by the OBJ and PLY readers, so both triangulate alike.
pub(super) fn push_polygon(
    mesh: &mut ObjMesh,
    corners: &[Corner],
    shape: &[Vec3],
    names: FaceNames,
    at: &str,
) {
    if let [a, b, c] = *corners {
        mesh.triangles.push([a, b, c]);
        mesh.triangle_names.push(names);
        return;
    }
    let t = triangulate(shape);
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

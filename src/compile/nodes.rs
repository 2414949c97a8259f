//! Flattening the node tree: transforms composed and baked into world-space primitives.

use std::collections::BTreeMap;
use std::path::Path;

use glam::{DAffine3, DMat3, DVec3, Vec2, Vec3};

use super::materials::MaterialTable;
use super::mesh::{MeshCache, ObjMesh};
use crate::geometry::quadric::QuadricShape;
use crate::geometry::triangle::is_degenerate;
use crate::render_scene::ObjectInfo;
use crate::render_scene::geometry::{
    EllipsoidPrim, GeometryBuilder, MAX_PRIMS_PER_KIND, QuadricPrim, SpherePrim, TriAttrs,
};
use crate::scene::Diagnostic;
use crate::scene::diagnostic::{did_you_mean, quoted_list};
use crate::scene::schema::{NodeSpec, SceneFile, TransformStep};

pub(super) struct Flattener<'a> {
    pub scene: &'a SceneFile,
    pub base_dir: &'a Path,
    pub materials: &'a mut MaterialTable,
    pub objects: &'a mut Vec<ObjectInfo>,
    pub builder: &'a mut GeometryBuilder,
    pub meshes: MeshCache,
    pub errors: &'a mut Vec<Diagnostic>,
    pub warnings: &'a mut Vec<Diagnostic>,
    pub degenerate: usize,
    /// The emissive shapes found, in tree order, for `compile::lights` to make lights of.
    pub emitters: Vec<super::lights::NodeEmitter>,
    /// The camera a `Gltf` node chose (`camera: "name"`), replacing the scene's.
    pub camera: Option<crate::scene::schema::CameraSpec>,
    /// Punctual lights of `Gltf` nodes, in world space, after the scene's `lights`.
    pub imported_lights: Vec<crate::scene::schema::LightSpec>,
}

/// The affine map of a transform list: the first step is applied first.
pub(crate) fn transform_of(steps: &[TransformStep]) -> DAffine3 {
    steps.iter().fold(DAffine3::IDENTITY, |acc, step| {
        let m = match *step {
            TransformStep::Translate(x, y, z) => {
                DAffine3::from_translation(DVec3::new(x.into(), y.into(), z.into()))
            }
            TransformStep::RotateX(a) => DAffine3::from_rotation_x(f64::from(a).to_radians()),
            TransformStep::RotateY(a) => DAffine3::from_rotation_y(f64::from(a).to_radians()),
            TransformStep::RotateZ(a) => DAffine3::from_rotation_z(f64::from(a).to_radians()),
            TransformStep::Scale(s) => DAffine3::from_scale(Vec3::from(s.factors()).as_dvec3()),
        };
        m * acc
    })
}

impl Flattener<'_> {
    pub fn node(&mut self, path: &str, node: &NodeSpec, parent: DAffine3) {
        let xf = parent * transform_of(node.transform());
        let material = node.material().and_then(|m| {
            self.materials
                .resolve(self.scene, self.base_dir, m, self.errors)
        });
        let object = self.objects.len() as u32;
        // A mesh with per-group materials (or its .mtl's) makes its objects once its file is
        // read; a glTF import makes its own nodes.
        let mtl = matches!(node, NodeSpec::Mesh { mtl: true, .. });
        let per_group = node.group_materials().is_some_and(|m| !m.is_empty()) || mtl;
        if !matches!(node, NodeSpec::Group { .. } | NodeSpec::Gltf { .. }) && !per_group {
            let name = node.name().map_or_else(|| path.to_string(), str::to_string);
            self.objects.push(ObjectInfo {
                name,
                material,
                light: None,
                body: None,
            });
        }
        let first = super::lights::PrimCounts::of(self.builder);
        match node {
            NodeSpec::Group { children, .. } => {
                for (i, c) in children.iter().enumerate() {
                    self.node(&format!("{path}.children[{i}]"), c, xf);
                }
            }
            NodeSpec::Sphere { center, radius, .. } => {
                let m = xf
                    * DAffine3::from_translation(Vec3::from(*center).as_dvec3())
                    * DAffine3::from_scale(DVec3::splat(f64::from(*radius)));
                if self.resolvable(path, "sphere", &m, MIN_ELLIPSOID_THICKNESS) {
                    self.sphere(m, object);
                }
            }
            NodeSpec::Cube { size, .. } => {
                let m = xf * DAffine3::from_scale(DVec3::splat(f64::from(*size)));
                if self.resolvable(path, "cube", &m, MIN_BOX_THICKNESS) {
                    for face in CUBE_FACES {
                        self.quad(&m, face, object);
                    }
                }
            }
            NodeSpec::Quad { size, .. } => {
                let m = xf
                    * DAffine3::from_scale(DVec3::new(f64::from(size[0]), f64::from(size[1]), 1.0));
                self.quad(&m, QUAD_FACE, object);
            }
            NodeSpec::Gltf {
                file,
                materials,
                camera,
                lights,
                ..
            } => self.gltf_node(
                path,
                &GltfNode {
                    file,
                    materials,
                    camera: camera.as_deref(),
                    lights: *lights,
                },
                xf,
            ),
            NodeSpec::Disc { radius, .. } => {
                let m = xf * DAffine3::from_scale(DVec3::splat(f64::from(*radius)));
                self.quadric(QuadricShape::Disc, m, object);
            }
            NodeSpec::Cylinder {
                radius,
                height,
                caps,
                ..
            } => {
                let (r, h) = (f64::from(*radius), f64::from(*height));
                let m = xf * DAffine3::from_scale(DVec3::new(r, r, h));
                if self.resolvable(path, "cylinder", &m, MIN_ELLIPSOID_THICKNESS) {
                    self.quadric(QuadricShape::Cylinder, m, object);
                    if *caps {
                        // The ends: unit discs at z = ±½ facing outwards (the bottom one turned
                        // over about x).
                        let top = m * DAffine3::from_translation(DVec3::new(0.0, 0.0, 0.5));
                        let bottom = m
                            * DAffine3::from_translation(DVec3::new(0.0, 0.0, -0.5))
                            * DAffine3::from_rotation_x(std::f64::consts::PI);
                        self.quadric(QuadricShape::Disc, top, object);
                        self.quadric(QuadricShape::Disc, bottom, object);
                    }
                }
            }
            NodeSpec::Mesh {
                file,
                smooth,
                materials,
                material: mesh_material,
                ..
            } => {
                let full = self.base_dir.join(file);
                match self.meshes.load(&full) {
                    Ok((mesh, first_load)) => {
                        if first_load {
                            self.warnings.extend(mesh.warnings.iter().map(|w| {
                                Diagnostic::warning(
                                    format!("{path}.file"),
                                    format!("`{}` {w}", full.display()),
                                )
                            }));
                        }
                        let from_mtl = if mtl {
                            self.mtl_materials(path, &full, &mesh, materials)
                        } else {
                            None
                        };
                        if mtl && from_mtl.is_none() {
                            // The error is pushed; no objects without materials.
                        } else if per_group {
                            let node_name =
                                node.name().map_or_else(|| path.to_string(), str::to_string);
                            let group_objects = GroupObjects {
                                path,
                                node_name: &node_name,
                                file: &full,
                                materials: from_mtl.as_ref().unwrap_or(materials),
                                default: mesh_material,
                            };
                            if let Some(objects) = self.group_objects(&group_objects, &mesh) {
                                self.mesh(&xf, &mesh, *smooth, |t| objects[t]);
                            }
                        } else {
                            self.mesh(&xf, &mesh, *smooth, |_| object);
                        }
                    }
                    Err(e) => {
                        let d = Diagnostic::error(format!("{path}.file"), e.to_string());
                        self.errors.push(
                            match super::materials::missing_file_help(self.base_dir, file) {
                                Some(help) => d.with_help(help),
                                None => d,
                            },
                        );
                    }
                }
            }
        }
        if let Some(emission) = node.emission() {
            self.emitters.push(super::lights::NodeEmitter {
                path: path.to_string(),
                object,
                is_quad: matches!(node, NodeSpec::Quad { .. }),
                emission: emission.clone(),
                first,
                end: super::lights::PrimCounts::of(self.builder),
            });
        }
        if self.builder.triangles.len() > MAX_PRIMS_PER_KIND {
            self.errors.push(Diagnostic::error(
                path,
                format!("the scene exceeds {MAX_PRIMS_PER_KIND} triangles"),
            ));
        }
    }

    /// Whether the solid `kind` (a unit sphere or cube under `m`) keeps a thickness the renderer
    /// can resolve: its thinnest extent (the smallest singular value of `m`'s linear part) at
    /// least `limit` × its longest. If not, an error naming the node and the factor that would do.
    fn resolvable(&mut self, path: &str, kind: &str, m: &DAffine3, limit: f64) -> bool {
        let (thin, long) = (
            smallest_singular_value(m.matrix3),
            largest_singular_value(m.matrix3),
        );
        if thin >= limit * long {
            return true;
        }
        let precision = if limit == MIN_ELLIPSOID_THICKNESS {
            "double precision"
        } else {
            "single precision"
        };
        self.errors.push(
            Diagnostic::error(
                format!("{path}.transform"),
                format!(
                    "the transforms down to this {kind} squash it to {:.3e} of its size along one axis (its thinnest extent is {thin:.3e} against {long:.3e} along its longest), thinner than {precision} resolves: it would render with its two sides confused",
                    thin / long,
                ),
            )
            .with_help(format!(
                "keep it at least {limit:.1e} of its size thick (a scale factor of at least {limit:.1e} relative to the other axes), or use a Quad for a flat shape",
            )),
        );
        false
    }

    /// A unit sphere under `m`: kept analytic as a sphere if `m` is a similarity, else an ellipsoid.
    fn sphere(&mut self, m: DAffine3, object: u32) {
        let l = m.matrix3;
        let (a, b, c) = (l.x_axis, l.y_axis, l.z_axis);
        let r = a.length();
        let tol = 1e-9 * r * r;
        let similar = (b.length() - r).abs() <= 1e-9 * r
            && (c.length() - r).abs() <= 1e-9 * r
            && a.dot(b).abs() <= tol
            && b.dot(c).abs() <= tol
            && a.dot(c).abs() <= tol;
        if similar {
            self.builder.spheres.push(SpherePrim {
                center: m.translation.as_vec3(),
                radius: r as f32,
                object,
            });
        } else {
            self.builder.ellipsoids.push(EllipsoidPrim {
                object_from_world: m.inverse(),
                world_from_object: m,
                normal_to_world: normal_matrix(l),
                object,
            });
        }
    }

    /// A unit disc or cylinder under `m`.
    fn quadric(&mut self, shape: QuadricShape, m: DAffine3, object: u32) {
        self.builder.quadrics.push(QuadricPrim {
            shape,
            object_from_world: m.inverse(),
            world_from_object: m,
            normal_to_world: normal_matrix(m.matrix3),
            object,
        });
    }

    /// Two triangles for a unit square face given by its corners, counter-clockwise seen from outside.
    fn quad(&mut self, m: &DAffine3, corners: [[f64; 3]; 4], object: u32) {
        let flip = m.matrix3.determinant() < 0.0;
        let p = corners.map(|c| m.transform_point3(DVec3::from(c)).as_vec3());
        // Corners run bottom-left, bottom-right, top-right, top-left; v grows downwards, so
        // an image appears upright.
        let uv = [
            Vec2::new(0.0, 1.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(0.0, 0.0),
        ];
        for [i, j, k] in [[0, 1, 2], [0, 2, 3]] {
            let (j, k) = if flip { (k, j) } else { (j, k) };
            self.triangle(
                [p[i], p[j], p[k]],
                TriAttrs {
                    object,
                    normals: None,
                    uvs: [uv[i], uv[j], uv[k]],
                },
            );
        }
    }

    /// The object of each triangle of a mesh whose `materials` map its OBJ names, making one
    /// object per map key used (named `node: key`) plus one for the faces left to the node's
    /// `material`. `None` after pushing errors: a key the file does not use (with did-you-mean
    /// and the file's names), or faces that nothing gives a material.
    fn group_objects(&mut self, g: &GroupObjects, mesh: &ObjMesh) -> Option<Vec<u32>> {
        let file = g.file.display();
        let names = mesh.names.iter().map(String::as_str);
        let mut ok = true;
        // Every group object of this mesh is a part of one body, named by the first.
        let body = Some(self.objects.len() as u32);
        // Per name of the file: the object its faces get if the map has it.
        let mut by_name: Vec<Option<u32>> = vec![None; mesh.names.len()];
        for (key, material) in g.materials {
            let Some(i) = mesh.name_index(key) else {
                let list = quoted_list(names.clone());
                let mut d = Diagnostic::error(
                    format!("{}.materials.{key}", g.path),
                    if list.is_empty() {
                        format!(
                            "`{file}` has no group (`g`, `o`) or `usemtl` names, so `{key}` maps nothing"
                        )
                    } else {
                        format!("`{file}` has no group or `usemtl` name `{key}`; its names: {list}")
                    },
                );
                if let Some(s) = did_you_mean(key, names.clone()) {
                    d = d.with_help(format!("did you mean `{s}`?"));
                }
                self.errors.push(d);
                ok = false;
                continue;
            };
            let resolved = self
                .materials
                .resolve(self.scene, self.base_dir, material, self.errors);
            by_name[i as usize] = Some(self.objects.len() as u32);
            self.objects.push(ObjectInfo {
                name: format!("{}: {key}", g.node_name),
                material: resolved,
                light: None,
                body,
            });
        }
        let default = g.default.as_deref().map(|m| {
            let resolved = self
                .materials
                .resolve(self.scene, self.base_dir, m, self.errors);
            (resolved, m)
        });
        let mut default_object = None;
        let mut unmapped: Vec<String> = Vec::new();
        let mut objects = Vec::with_capacity(mesh.triangles.len());
        for names in &mesh.triangle_names {
            let pick = |n: Option<u32>| n.and_then(|i| by_name[i as usize]);
            if let Some(o) = pick(names.usemtl).or_else(|| pick(names.group)) {
                objects.push(o);
                continue;
            }
            if let Some((resolved, _)) = default {
                let o = *default_object.get_or_insert_with(|| {
                    self.objects.push(ObjectInfo {
                        name: g.node_name.to_string(),
                        material: resolved,
                        light: None,
                        body,
                    });
                    self.objects.len() as u32 - 1
                });
                objects.push(o);
                continue;
            }
            let name = |i: u32| mesh.names[i as usize].as_str();
            let what = match (names.usemtl, names.group) {
                (Some(m), Some(g)) if m != g => format!("`{}` (in group `{}`)", name(m), name(g)),
                (Some(n), _) | (None, Some(n)) => format!("`{}`", name(n)),
                (None, None) => "the faces outside any group".to_string(),
            };
            if !unmapped.contains(&what) {
                unmapped.push(what);
            }
            objects.push(0);
        }
        if !unmapped.is_empty() {
            let list = unmapped.join(", ");
            self.errors.push(
                Diagnostic::error(
                    format!("{}.materials", g.path),
                    format!("faces of `{file}` have no material: {list} (not in `materials`, and the mesh has no `material` for the rest)"),
                )
                .with_help("map each of them in `materials`, or give the mesh a `material` for every face the map leaves out"),
            );
            ok = false;
        }
        ok.then_some(objects)
    }

    fn mesh(
        &mut self,
        m: &DAffine3,
        mesh: &ObjMesh,
        smooth: bool,
        object_of: impl Fn(usize) -> u32,
    ) {
        let flip = m.matrix3.determinant() < 0.0;
        let nm = normal_matrix(m.matrix3);
        let pos: Vec<Vec3> = mesh
            .positions
            .iter()
            .map(|p| m.transform_point3(p.as_dvec3()).as_vec3())
            .collect();
        let nor: Vec<Vec3> = mesh
            .normals
            .iter()
            .map(|n| (nm * n.as_dvec3()).as_vec3().normalize_or_zero())
            .collect();
        for (t, tri) in mesh.triangles.iter().enumerate() {
            let object = object_of(t);
            let order = if flip { [0, 2, 1] } else { [0, 1, 2] };
            let c = order.map(|k| tri[k]);
            let normals = if smooth && c.iter().all(|c| c.n.is_some()) {
                let n = c.map(|c| c.n.map_or(Vec3::ZERO, |i| nor[i as usize]));
                n.iter().all(|n| *n != Vec3::ZERO).then_some(n)
            } else {
                None
            };
            let uvs = if c.iter().all(|c| c.t.is_some()) {
                c.map(|c| c.t.map_or(Vec2::ZERO, |i| mesh.uvs[i as usize]))
            } else {
                box_projection(c.map(|c| mesh.positions[c.p as usize]))
            };
            self.triangle(
                c.map(|c| pos[c.p as usize]),
                TriAttrs {
                    object,
                    normals,
                    uvs,
                },
            );
        }
    }

    fn triangle(&mut self, p: [Vec3; 3], attrs: TriAttrs) {
        if is_degenerate(p[0], p[1], p[2]) {
            self.degenerate += 1;
            return;
        }
        self.builder.triangles.push(p);
        self.builder.tri_attrs.push(attrs);
    }
}

/// What [`Flattener::group_objects`] needs from a `Mesh` node with `materials`.
pub(super) struct GroupObjects<'a> {
    /// The node's field path.
    path: &'a str,
    /// The node's name (or path), for the objects' names.
    node_name: &'a str,
    /// The OBJ file as resolved.
    file: &'a Path,
    /// OBJ name → material name.
    materials: &'a BTreeMap<String, String>,
    /// The node's `material`, for faces the map leaves out.
    default: &'a Option<String>,
}

/// Texture coordinates for a triangle of a mesh without `vt`: box (tri-planar) projection in
/// object space. The triangle is projected along the axis its normal is closest to and the two
/// remaining object-space coordinates are the uv, in object units (a texture with `tile: (1, 1)`
/// repeats once per object unit), oriented like the faces of a `Cube` node: upright on the side
/// faces (v grows downwards with y), the top's image top towards −z, the bottom's towards +z. Continuous within each group of faces facing the same axis; seams
/// where the dominant axis changes, as with any box mapping.
fn box_projection(p: [Vec3; 3]) -> [Vec2; 3] {
    let n = (p[1] - p[0]).cross(p[2] - p[0]);
    let a = n.abs();
    p.map(|q| {
        if a.x >= a.y && a.x >= a.z {
            Vec2::new(q.z * -n.x.signum(), -q.y)
        } else if a.y >= a.z {
            Vec2::new(q.x, q.z * n.y.signum())
        } else {
            Vec2::new(q.x * n.z.signum(), -q.y)
        }
    })
}

/// Thinnest resolvable ellipsoid, as a fraction of its longest semi-axis. Ellipsoid hits are
/// solved in f64 in object space, where the thin axis is stretched by 1/thickness; the rounding
/// of that solution, about 2.2e-16 × distance / thickness in object units, must stay far below
/// the unit sphere's radius. Measured on a unit sphere squashed along y seen from 4.5 units
/// (`tests/reported/near-singular-scale`): exact to 1e-4 down to a factor 1e-13, wrong pixels
/// from 1e-14; 2^-36 ≈ 1.5e-11 leaves a 100× margin (for views up to ~100× farther).
pub const MIN_ELLIPSOID_THICKNESS: f64 = 1.0 / (1u64 << 36) as f64;

/// Thinnest resolvable box (a `Cube` under a squashing scale), as a fraction of its longest
/// side: its two large faces are triangles hit in f32, which tells them apart only when they are
/// a few f32 steps of the hit distance apart (`f32::EPSILON` ≈ 1.2e-7). Measured on a cube of
/// side 1.5 squashed along y seen from 4.5 units: exact down to a factor 5e-7, wrong pixels from
/// 3e-7; 2^-20 ≈ 9.5e-7 keeps a 2× margin at that distance. Any two surfaces closer than a few
/// f32 steps of their distance from the camera are confused, however they were modelled: a thin
/// slab seen from much farther than its size needs a proportionally thicker factor.
pub const MIN_BOX_THICKNESS: f64 = 1.0 / (1u64 << 20) as f64;

/// The largest singular value of `m`: the square root of the largest eigenvalue of `mᵀm`, by
/// the closed form for symmetric 3×3 matrices (Smith, "Eigenvalues of a symmetric 3 × 3 matrix",
/// CACM 1961), accurate for the largest eigenvalue.
fn largest_singular_value(m: DMat3) -> f64 {
    let a = m.transpose() * m;
    let (x, y, z) = (a.x_axis, a.y_axis, a.z_axis);
    let p1 = y.x * y.x + z.x * z.x + z.y * z.y;
    let q = (x.x + y.y + z.z) / 3.0;
    let p2 = (x.x - q).powi(2) + (y.y - q).powi(2) + (z.z - q).powi(2) + 2.0 * p1;
    let p = (p2 / 6.0).sqrt();
    let lambda = if p == 0.0 || !p.is_finite() {
        q
    } else {
        let b = (a - DMat3::from_diagonal(DVec3::splat(q))) * (1.0 / p);
        let r = (b.determinant() / 2.0).clamp(-1.0, 1.0);
        q + 2.0 * p * (r.acos() / 3.0).cos()
    };
    lambda.max(0.0).sqrt()
}

/// The smallest singular value of `m`, as 1 / the largest of its inverse (accurate however thin
/// `m` is); 0 for a singular or non-finite `m`.
fn smallest_singular_value(m: DMat3) -> f64 {
    let det = m.determinant();
    if det == 0.0 || !det.is_finite() {
        return 0.0;
    }
    let s = largest_singular_value(m.inverse());
    if s > 0.0 && s.is_finite() {
        1.0 / s
    } else {
        0.0
    }
}

/// Inverse transpose of a linear map, for transforming normals.
fn normal_matrix(l: DMat3) -> DMat3 {
    l.inverse().transpose()
}

/// The quad node's face: the unit square in the xy plane, facing +z.
const QUAD_FACE: [[f64; 3]; 4] = [
    [-0.5, -0.5, 0.0],
    [0.5, -0.5, 0.0],
    [0.5, 0.5, 0.0],
    [-0.5, 0.5, 0.0],
];

/// The six faces of the unit cube centred on the origin, each counter-clockwise from outside.
const CUBE_FACES: [[[f64; 3]; 4]; 6] = [
    [
        [-0.5, -0.5, 0.5],
        [0.5, -0.5, 0.5],
        [0.5, 0.5, 0.5],
        [-0.5, 0.5, 0.5],
    ], // +z
    [
        [0.5, -0.5, -0.5],
        [-0.5, -0.5, -0.5],
        [-0.5, 0.5, -0.5],
        [0.5, 0.5, -0.5],
    ], // -z
    [
        [0.5, -0.5, 0.5],
        [0.5, -0.5, -0.5],
        [0.5, 0.5, -0.5],
        [0.5, 0.5, 0.5],
    ], // +x
    [
        [-0.5, -0.5, -0.5],
        [-0.5, -0.5, 0.5],
        [-0.5, 0.5, 0.5],
        [-0.5, 0.5, -0.5],
    ], // -x
    [
        [-0.5, 0.5, 0.5],
        [0.5, 0.5, 0.5],
        [0.5, 0.5, -0.5],
        [-0.5, 0.5, -0.5],
    ], // +y
    [
        [-0.5, -0.5, -0.5],
        [0.5, -0.5, -0.5],
        [0.5, -0.5, 0.5],
        [-0.5, -0.5, 0.5],
    ], // -y
];

/// What [`Flattener::gltf_node`] needs from a `Gltf` node.
pub(super) struct GltfNode<'a> {
    /// The file as written (relative to the scene file).
    pub file: &'a str,
    /// The file's material names → scene materials.
    pub materials: &'a BTreeMap<String, String>,
    /// The camera to render from, by name.
    pub camera: Option<&'a str>,
    /// Import the punctual lights.
    pub lights: bool,
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn singular_values_of_thin_and_rotated_maps() {
        // diag(3, 1e-9, 0.5) rotated on both sides: singular values 3 and 1e-9 (the rotation's
        // rounding, ~1e-16 × 3 per entry, perturbs the small one by under 1e-6 of itself).
        let r = DMat3::from_rotation_y(0.7) * DMat3::from_rotation_x(1.1);
        let m = r * DMat3::from_diagonal(DVec3::new(3.0, 1e-9, 0.5)) * r.transpose();
        assert!((largest_singular_value(m) / 3.0 - 1.0).abs() < 1e-12);
        assert!((smallest_singular_value(m) / 1e-9 - 1.0).abs() < 1e-6);
        // Unrotated, exact however thin.
        let thin = DMat3::from_diagonal(DVec3::new(1.0, 1e-20, 2.0));
        assert!((smallest_singular_value(thin) / 1e-20 - 1.0).abs() < 1e-12);
        // Equal singular values (p = 0 in the closed form), and a shear [[1, 1], [0, 1]] in xy,
        // whose singular values are the golden ratio φ and 1/φ (and 1 along z).
        assert!((largest_singular_value(DMat3::IDENTITY * 2.0) - 2.0).abs() < 1e-15);
        let shear = DMat3::from_cols(DVec3::X, DVec3::new(1.0, 1.0, 0.0), DVec3::Z);
        let phi = (1.0 + 5f64.sqrt()) / 2.0;
        assert!((largest_singular_value(shear) - phi).abs() < 1e-12);
        assert!((smallest_singular_value(shear) - 1.0 / phi).abs() < 1e-12);
        assert_eq!(smallest_singular_value(DMat3::ZERO), 0.0);
    }
}

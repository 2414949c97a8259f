//! The flattener's imports: a `Gltf` node's file turned into nodes, materials, lights and a
//! camera ([`super::gltf`]), and a `Mesh` node's `.mtl` materials ([`super::mtl`]). Imported
//! materials are checked by the scene format's own validation and compiled by the same
//! [`MaterialTable`](super::materials::MaterialTable) as the scene's, so an import compiles to
//! what its hand-written twin does.

use std::collections::BTreeMap;
use std::path::Path;

use glam::DAffine3;

use super::mesh::ObjMesh;
use super::mesh_file::{MAX_MESH_FILE_BYTES, MeshFormat, read_mesh_file};
use super::nodes::{Flattener, GltfNode};
use crate::scene::Diagnostic;
use crate::scene::diagnostic::{did_you_mean, quoted_list};
use crate::scene::schema::{MaterialSpec, TextureSpec};

impl Flattener<'_> {
    /// Imports a `Gltf` node under the world transform `xf`: its nodes are flattened as the
    /// scene's own, its lights and chosen camera kept for `compile`. Errors and warnings name
    /// `path.file` (and the glTF JSON pointer).
    pub(super) fn gltf_node(&mut self, path: &str, g: &GltfNode, xf: DAffine3) {
        let full = self.base_dir.join(g.file);
        let at = format!("{path}.file");
        let bytes = match read_mesh_file(&full, MAX_MESH_FILE_BYTES) {
            Ok((MeshFormat::Gltf | MeshFormat::Glb, bytes)) => bytes,
            Ok((format, _)) => {
                self.errors.push(
                    Diagnostic::error(
                        &at,
                        format!("`{}`: this is {}, not glTF", full.display(), format.name()),
                    )
                    .with_help("a `Gltf` node reads .gltf and .glb files; OBJ and PLY meshes go in a `Mesh` node"),
                );
                return;
            }
            Err(e) => {
                let d = Diagnostic::error(&at, e.to_string());
                self.errors.push(
                    match super::materials::missing_file_help(self.base_dir, g.file) {
                        Some(help) => d.with_help(help),
                        None => d,
                    },
                );
                return;
            }
        };
        let import = match super::gltf::import_gltf(&bytes, &full, xf, g.materials) {
            Ok(i) => i,
            Err(e) => {
                self.errors.push(Diagnostic::error(&at, e.to_string()));
                return;
            }
        };
        let mut ok = true;
        for key in g.materials.keys() {
            if import.material_names.contains(key) {
                continue;
            }
            let names = import.material_names.iter().map(String::as_str);
            let list = quoted_list(names.clone());
            let mut d = Diagnostic::error(
                format!("{path}.materials.{key}"),
                if list.is_empty() {
                    format!(
                        "`{}` has no materials, so `{key}` maps nothing",
                        full.display()
                    )
                } else {
                    format!(
                        "`{}` has no material `{key}`; its materials: {list}",
                        full.display()
                    )
                },
            );
            if let Some(s) = did_you_mean(key, names) {
                d = d.with_help(format!("did you mean `{s}`?"));
            }
            self.errors.push(d);
            ok = false;
        }
        for w in import.warnings.iter().chain(&import.notes) {
            self.warnings.push(Diagnostic::warning(
                &at,
                format!("`{}` {w}", full.display()),
            ));
        }
        if let Some(name) = g.camera {
            match import
                .cameras
                .iter()
                .find(|(n, _)| n.iter().any(|n| n == name))
            {
                Some((_, spec)) => self.camera = Some(spec.clone()),
                None => {
                    let names: Vec<&str> = import
                        .cameras
                        .iter()
                        .flat_map(|(n, _)| n.iter().map(String::as_str))
                        .collect();
                    let list = quoted_list(names.iter().copied());
                    let mut d = Diagnostic::error(
                        format!("{path}.camera"),
                        if list.is_empty() {
                            format!(
                                "`{}` has no perspective camera, so `{name}` names none",
                                full.display()
                            )
                        } else {
                            format!(
                                "`{}` has no perspective camera `{name}`; its cameras: {list}",
                                full.display()
                            )
                        },
                    );
                    if let Some(s) = did_you_mean(name, names.iter().copied()) {
                        d = d.with_help(format!("did you mean `{s}`?"));
                    }
                    self.errors.push(d);
                    ok = false;
                }
            }
        }
        if !ok || !self.register(path, &import.materials, &import.textures) {
            return;
        }
        if g.lights {
            self.imported_lights.extend(import.lights.iter().cloned());
        }
        for (key, mesh) in import.meshes {
            self.meshes.insert(key, mesh);
        }
        for (i, n) in import.nodes.iter().enumerate() {
            self.node(&format!("{path}.gltf[{i}]"), n, xf);
        }
        // The embedded images (import.images) are deleted here, once their textures are read.
    }

    /// The map a `Mesh` node with `mtl: true` gives its faces: each `usemtl` name of the file
    /// that its `.mtl` defines → an imported material, then `scene_map`'s own entries (the
    /// scene wins by name). `None` after pushing an error.
    pub(super) fn mtl_materials(
        &mut self,
        path: &str,
        file: &Path,
        mesh: &ObjMesh,
        scene_map: &BTreeMap<String, String>,
    ) -> Option<BTreeMap<String, String>> {
        let read = match super::mtl::read_mtl(file, &mesh.mtllibs) {
            Ok(r) => r,
            Err(e) => {
                self.errors.push(
                    Diagnostic::error(format!("{path}.mtl"), e.to_string()).with_help(
                        "remove `mtl: true` and give `material` or `materials`, or fix the library",
                    ),
                );
                return None;
            }
        };
        for note in &read.notes {
            self.warnings
                .push(Diagnostic::warning(format!("{path}.mtl"), note.clone()));
        }
        let mut map = BTreeMap::new();
        let mut imported = BTreeMap::new();
        for name in &mesh.names {
            if scene_map.contains_key(name) {
                continue;
            }
            if let Some(spec) = read.materials.get(name) {
                let synthetic = format!("{}#{name}", file.display());
                imported.insert(synthetic.clone(), spec.clone());
                map.insert(name.clone(), synthetic);
            }
        }
        if !self.register(path, &imported, &read.textures) {
            return None;
        }
        map.extend(scene_map.iter().map(|(k, v)| (k.clone(), v.clone())));
        Some(map)
    }

    /// Checks imported materials with the scene format's validation (so they obey the rules a
    /// hand-written material does) and compiles them into the material table under their
    /// names, where the nodes that use them find them. False after pushing errors.
    fn register(
        &mut self,
        path: &str,
        materials: &BTreeMap<String, MaterialSpec>,
        textures: &BTreeMap<String, TextureSpec>,
    ) -> bool {
        let mut scene = self.scene.clone();
        scene.materials = materials.clone();
        scene.textures = textures.clone();
        scene.lights.clear();
        scene.nodes.clear();
        let problems: Vec<Diagnostic> = crate::scene::validate::validate(&scene)
            .into_iter()
            .filter(|d| {
                d.is_error()
                    && (d.path.starts_with("materials.") || d.path.starts_with("textures."))
            })
            .collect();
        if !problems.is_empty() {
            for d in problems {
                self.errors.push(Diagnostic::error(
                    format!("{path}.file"),
                    format!(
                        "an imported material is not valid: {}: {}",
                        d.path, d.message
                    ),
                ));
            }
            return false;
        }
        // The scene's own materials and textures stay visible (an import's texture names never
        // collide with them: they carry the file's name and a `#`).
        let mut all = self.scene.clone();
        all.materials.extend(materials.clone());
        all.textures.extend(textures.clone());
        let before = self.errors.len();
        for name in materials.keys() {
            self.materials
                .resolve(&all, self.base_dir, name, self.errors);
        }
        self.errors.len() == before
    }
}

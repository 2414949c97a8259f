//! Checks of the node tree: shapes, transforms and the materials nodes name.

use super::*;

impl<'a> Validator<'a> {
    pub(super) fn node(&mut self, path: &str, n: &'a NodeSpec, depth: usize) {
        if depth > MAX_NESTING {
            self.err(
                path,
                format!("groups are nested more than {MAX_NESTING} levels deep"),
            );
            return;
        }
        for (i, step) in n.transform().iter().enumerate() {
            self.transform_step(&format!("{path}.transform[{i}]"), step);
        }
        if let Some(material) = n.material() {
            self.material_ref(&format!("{path}.material"), material);
        }
        if let Some(e) = n.emission() {
            self.emission(path, n, e);
        }
        match n {
            NodeSpec::Group { children, .. } => {
                for (i, c) in children.iter().enumerate() {
                    self.node(&format!("{path}.children[{i}]"), c, depth + 1);
                }
            }
            NodeSpec::Sphere { center, radius, .. } => {
                self.shape_material(path, n);
                self.finite3(&format!("{path}.center"), *center);
                self.positive(&format!("{path}.radius"), *radius, "radius");
            }
            NodeSpec::Cube { size, .. } => {
                self.shape_material(path, n);
                self.positive(&format!("{path}.size"), *size, "size");
            }
            NodeSpec::Quad { size, .. } => {
                self.shape_material(path, n);
                for (i, s) in size.iter().enumerate() {
                    self.positive(&format!("{path}.size[{i}]"), *s, "size");
                }
            }
            NodeSpec::Gltf {
                file,
                materials,
                camera,
                ..
            } => {
                for (key, m) in materials {
                    let at = format!("{path}.materials.{key}");
                    if key.trim().is_empty() {
                        self.err(
                            &at,
                            "must name a material of the glTF file, found an empty string".into(),
                        );
                    }
                    self.material_ref(&at, m);
                }
                if file.trim().is_empty() {
                    self.err(
                        &format!("{path}.file"),
                        "must name a .gltf or .glb file, found an empty string".into(),
                    );
                }
                if camera.as_deref().is_some_and(|c| c.trim().is_empty()) {
                    self.err(
                        &format!("{path}.camera"),
                        "must name a camera of the glTF file, found an empty string".into(),
                    );
                }
            }
            NodeSpec::Disc { radius, .. } => {
                self.shape_material(path, n);
                self.positive(&format!("{path}.radius"), *radius, "radius");
            }
            NodeSpec::Cylinder {
                radius,
                height,
                caps,
                ..
            } => {
                self.shape_material(path, n);
                self.positive(&format!("{path}.radius"), *radius, "radius");
                self.positive(&format!("{path}.height"), *height, "height");
                if *caps && n.emission().is_some() {
                    self.out.push(
                        Diagnostic::error(
                            format!("{path}.caps"),
                            "an emissive cylinder is open: `emission` lights its side only, and `caps` would add discs it cannot emit from",
                        )
                        .with_help("remove `caps`, and add `Disc` nodes with their own `emission` for glowing ends"),
                    );
                }
            }
            NodeSpec::Mesh {
                file,
                material,
                materials,
                mtl,
                ..
            } => {
                if *mtl && n.emission().is_some() {
                    self.out.push(
                        Diagnostic::error(
                            format!("{path}.mtl"),
                            "an emissive mesh has no materials: `emission` and `mtl` exclude each other",
                        )
                        .with_help("remove `mtl`, or split the emitting faces into their own Mesh node"),
                    );
                }
                for (group, m) in materials {
                    let at = format!("{path}.materials.{group}");
                    if group.trim().is_empty() {
                        self.err(
                            &at,
                            "must name an OBJ group or `usemtl` name, found an empty string".into(),
                        );
                    }
                    self.material_ref(&at, m);
                }
                if n.emission().is_some() && !materials.is_empty() {
                    self.out.push(
                        Diagnostic::error(
                            format!("{path}.materials"),
                            "an emissive mesh has no materials: `emission` and `materials` exclude each other",
                        )
                        .with_help("split the emitting faces into their own Mesh node"),
                    );
                }
                if material.is_none() && materials.is_empty() && !*mtl && n.emission().is_none() {
                    self.out.push(
                        Diagnostic::error(path, "a mesh needs a `material` (or `materials` for its OBJ groups, or `mtl: true` for its .mtl file), found none")
                            .with_help("add `material: \"name\"`, `materials: {\"group\": \"name\", ...}` mapping each OBJ group or `usemtl` name, or `mtl: true`"),
                    );
                }
                if file.trim().is_empty() {
                    self.err(
                        &format!("{path}.file"),
                        "must name an OBJ file, found an empty string".into(),
                    );
                }
            }
        }
    }

    /// A sphere, cube or quad needs a `material` or an `emission`.
    fn shape_material(&mut self, path: &str, n: &NodeSpec) {
        if n.material().is_none() && n.emission().is_none() {
            self.out.push(
                Diagnostic::error(
                    path,
                    format!(
                        "a {} needs a `material` (or an `emission` to be a light), found neither",
                        n.kind()
                    ),
                )
                .with_help("add `material: \"name\"`, or `emission: (radiance: (r, g, b))`"),
            );
        }
    }

    /// A node's `emission`: positive, finite radiance; no material beside it; one-sided
    /// spheres only.
    fn emission(&mut self, path: &str, n: &NodeSpec, e: &EmissionSpec) {
        let at = format!("{path}.emission.radiance");
        if self.finite3(&at, e.radiance)
            && (e.radiance.iter().any(|c| *c < 0.0) || e.radiance.iter().all(|c| *c == 0.0))
        {
            self.out.push(
                Diagnostic::error(
                    &at,
                    format!(
                        "must be positive in some channel and negative in none, found {}",
                        fmt3(e.radiance)
                    ),
                )
                .with_help("radiance is in W/(m²·sr) per channel, e.g. `(5, 5, 5)`; remove `emission` for a shape that does not glow"),
            );
        }
        if n.material().is_some() {
            self.out.push(
                Diagnostic::error(
                    format!("{path}.material"),
                    "an emissive shape has no material (it absorbs what reaches it): `material` and `emission` exclude each other",
                )
                .with_help("remove `material`, or put the emitter and the reflecting surface in two nodes"),
            );
        }
        if e.two_sided && matches!(n, NodeSpec::Sphere { .. }) {
            self.err(
                &format!("{path}.emission.two_sided"),
                "a sphere emits outwards only (its inside is closed); remove `two_sided`".into(),
            );
        }
    }

    pub(super) fn material_ref(&mut self, path: &str, name: &'a str) {
        if self.scene.materials.contains_key(name) {
            self.used.insert(name);
            return;
        }
        let names = self.scene.materials.keys().map(String::as_str);
        let list = quoted_list(names.clone());
        let mut d = Diagnostic::error(
            path,
            format!(
                "unknown material `{name}`; defined materials: {}",
                if list.is_empty() { "none" } else { &list }
            ),
        );
        if let Some(s) = did_you_mean(name, names) {
            d = d.with_help(format!("did you mean `{s}`?"));
        }
        self.out.push(d);
    }

    pub(super) fn transform_step(&mut self, path: &str, step: &TransformStep) {
        match step {
            TransformStep::Translate(x, y, z) => {
                self.finite3(path, [*x, *y, *z]);
            }
            TransformStep::RotateX(a) | TransformStep::RotateY(a) | TransformStep::RotateZ(a) => {
                self.finite(path, *a);
            }
            TransformStep::Scale(s) => {
                let v = s.factors();
                if self.finite3(path, v) && v.contains(&0.0) {
                    self.out.push(
                        Diagnostic::error(
                            path,
                            format!(
                                "scale {} is singular (a zero factor flattens the object)",
                                fmt3(v)
                            ),
                        )
                        .with_help("use a small positive factor, or remove the node"),
                    );
                }
            }
        }
    }
}

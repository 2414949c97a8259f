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
        match n {
            NodeSpec::Group { children, .. } => {
                for (i, c) in children.iter().enumerate() {
                    self.node(&format!("{path}.children[{i}]"), c, depth + 1);
                }
            }
            NodeSpec::Sphere { center, radius, .. } => {
                self.finite3(&format!("{path}.center"), *center);
                self.positive(&format!("{path}.radius"), *radius, "radius");
            }
            NodeSpec::Cube { size, .. } => self.positive(&format!("{path}.size"), *size, "size"),
            NodeSpec::Quad { size, .. } => {
                for (i, s) in size.iter().enumerate() {
                    self.positive(&format!("{path}.size[{i}]"), *s, "size");
                }
            }
            NodeSpec::Mesh {
                file,
                material,
                materials,
                ..
            } => {
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
                if material.is_none() && materials.is_empty() {
                    self.out.push(
                        Diagnostic::error(path, "a mesh needs a `material` (or `materials` for its OBJ groups), found neither")
                            .with_help("add `material: \"name\"`, or `materials: {\"group\": \"name\", ...}` mapping each OBJ group or `usemtl` name"),
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

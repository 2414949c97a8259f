//! `--set path=value` overrides: typed edits of a parsed scene, checked against the schema.

use serde_json::Value;

use super::diagnostic::{Diagnostic, did_you_mean, humanize, quoted_list};
use super::error::SceneError;
use super::schema::SceneFile;

/// Applies `path=value` assignments in order (e.g. `camera.fov_y=35`, `materials.glass.ior=1.7`,
/// `lights[0].power=(5, 5, 5)`). Enum variant names are optional in paths. Values are JSON or
/// RON-style literals; a bare word is taken as a string.
pub fn apply_overrides(scene: &SceneFile, sets: &[String]) -> Result<SceneFile, SceneError> {
    if sets.is_empty() {
        return Ok(scene.clone());
    }
    // Over the defaults, so that a path into an unset setting (`photons.caustic_filter.k`)
    // exists to be set.
    let mut tree = serde_json::to_value(scene.with_default_settings())
        .map_err(|e| invalid("--set", e.to_string()))?;
    let mut errors = Vec::new();
    for set in sets {
        if let Err(d) = apply_one(&mut tree, set) {
            errors.push(*d);
        }
    }
    if !errors.is_empty() {
        return Err(SceneError::Invalid(errors));
    }
    serde_path_to_error::deserialize::<_, SceneFile>(tree).map_err(|e| {
        let path = super::parse::user_path(&e.path().to_string());
        invalid(
            &format!("--set {path}"),
            format!(
                "{} (the override does not fit the schema)",
                humanize(&e.inner().to_string())
            ),
        )
    })
}

fn invalid(path: &str, msg: String) -> SceneError {
    SceneError::Invalid(vec![Diagnostic::error(path, msg)])
}

fn apply_one(tree: &mut Value, set: &str) -> Result<(), Box<Diagnostic>> {
    let Some((path, text)) = set.split_once('=') else {
        return Err(Box::new(
            Diagnostic::error(format!("--set {set}"), "expected `path=value`")
                .with_help("for example `--set camera.fov_y=35`"),
        ));
    };
    let (path, text) = (path.trim(), text.trim());
    let segments = split_path(path).ok_or_else(|| {
        Box::new(Diagnostic::error(
            format!("--set {path}"),
            "malformed path; write e.g. `lights[0].power`",
        ))
    })?;
    let mut node = tree;
    let mut walked = String::new();
    for seg in &segments {
        node = step(node, seg, &walked, path)?;
        walked = if walked.is_empty() || seg.starts_with('[') {
            format!("{walked}{seg}")
        } else {
            format!("{walked}.{seg}")
        };
    }
    *node = parse_value(text);
    Ok(())
}

/// `a.b[2].c` → `["a", "b", "[2]", "c"]`.
fn split_path(path: &str) -> Option<Vec<String>> {
    let mut out = Vec::new();
    for part in path.split('.') {
        let (head, mut rest) = part.split_once('[').map_or((part, ""), |(h, r)| (h, r));
        if head.is_empty() && out.is_empty() {
            return None;
        }
        if !head.is_empty() {
            out.push(head.to_string());
        }
        while !rest.is_empty() {
            let (index, after) = rest.split_once(']')?;
            index.parse::<usize>().ok()?;
            out.push(format!("[{index}]"));
            rest = after.strip_prefix('[').unwrap_or(after);
            if !after.is_empty() && !after.starts_with('[') {
                return None;
            }
        }
    }
    (!out.is_empty()).then_some(out)
}

fn step<'v>(
    node: &'v mut Value,
    seg: &str,
    walked: &str,
    full: &str,
) -> Result<&'v mut Value, Box<Diagnostic>> {
    let here = if walked.is_empty() {
        "the scene".to_string()
    } else {
        format!("`{walked}`")
    };
    if let Some(index) = seg.strip_prefix('[').and_then(|s| s.strip_suffix(']')) {
        let index: usize = index.parse().unwrap_or(usize::MAX);
        let node = unwrap_variant(node, None);
        let len = node.as_array().map(Vec::len);
        return match (node.as_array_mut(), len) {
            (Some(items), Some(len)) if index < len => Ok(&mut items[index]),
            (Some(_), Some(len)) => Err(Box::new(Diagnostic::error(
                format!("--set {full}"),
                format!(
                    "index {index} is out of range: {here} has {len} element{}",
                    if len == 1 { "" } else { "s" }
                ),
            ))),
            _ => Err(Box::new(Diagnostic::error(
                format!("--set {full}"),
                format!("{here} is not a list"),
            ))),
        };
    }
    let node = unwrap_variant(node, Some(seg));
    let keys: Vec<String> = node
        .as_object()
        .map(|m| m.keys().cloned().collect())
        .unwrap_or_default();
    match node.as_object_mut() {
        Some(map) if map.contains_key(seg) => Ok(&mut map[seg]),
        Some(_) => {
            let mut d = Diagnostic::error(
                format!("--set {full}"),
                format!(
                    "{here} has no field `{seg}`; its fields are {}",
                    quoted_list(keys.iter().map(String::as_str))
                ),
            );
            if let Some(s) = did_you_mean(seg, keys.iter().map(String::as_str)) {
                d = d.with_help(format!("did you mean `{s}`?"));
            }
            Err(Box::new(d))
        }
        None => Err(Box::new(Diagnostic::error(
            format!("--set {full}"),
            format!("{here} has no fields"),
        ))),
    }
}

/// Looks through an externally tagged enum value `{ "Variant": inner }` unless `seg` names the variant.
fn unwrap_variant<'v>(node: &'v mut Value, seg: Option<&str>) -> &'v mut Value {
    let variant = node.as_object().and_then(|m| {
        let k = m.keys().next()?;
        (m.len() == 1 && k.starts_with(|c: char| c.is_ascii_uppercase()) && Some(k.as_str()) != seg)
            .then(|| k.clone())
    });
    match variant {
        Some(k) => &mut node[k.as_str()],
        None => node,
    }
}

/// A JSON literal, a RON tuple `(1, 2, 3)` as a list, or else a plain string.
fn parse_value(text: &str) -> Value {
    if let Ok(v) = serde_json::from_str::<Value>(text) {
        return v;
    }
    if let Some(inner) = text.strip_prefix('(').and_then(|t| t.strip_suffix(')'))
        && let Ok(v) = serde_json::from_str::<Value>(&format!("[{inner}]"))
    {
        return v;
    }
    Value::String(text.trim_matches('"').to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn paths_split_into_segments() {
        assert_eq!(split_path("a.b[2].c").unwrap(), ["a", "b", "[2]", "c"]);
        assert_eq!(split_path("nodes[0][1]").unwrap(), ["nodes", "[0]", "[1]"]);
        assert!(split_path("").is_none());
        assert!(split_path("a[x]").is_none());
    }

    #[test]
    fn values_parse_as_json_ron_tuples_or_strings() {
        assert_eq!(parse_value("35"), serde_json::json!(35));
        assert_eq!(parse_value("(1, 2, 3)"), serde_json::json!([1, 2, 3]));
        assert_eq!(parse_value("glass"), serde_json::json!("glass"));
    }

    #[test]
    fn optional_fields_a_scene_leaves_unset_can_be_set() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/cornell.ron");
        let scene = crate::scene::source::SourceFile::read(&path)
            .and_then(|s| s.parse())
            .unwrap();
        assert_eq!(scene.render.integrator, None);
        let set = apply_overrides(
            &scene,
            &[
                "render.integrator=Path".into(),
                r#"nodes[1].emission={"radiance": [1, 2, 3]}"#.into(),
            ],
        )
        .unwrap();
        assert_eq!(
            set.render.integrator,
            Some(crate::settings::IntegratorKind::Path)
        );
        let crate::scene::schema::NodeSpec::Sphere { emission, .. } = &set.nodes[1] else {
            panic!("still a sphere");
        };
        assert!(emission.is_some());
    }

    /// A scene with a medium given by its coefficients: its unset albedo form goes through the
    /// override tree as `null` and must come back unset (it failed with "invalid type: null",
    /// so `--set` and `--exposure` refused every scene with `media`).
    #[test]
    fn overrides_keep_a_mediums_unset_form() {
        let path =
            std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("benches/scenes/foggy_box.ron");
        let scene = crate::scene::source::SourceFile::read(&path)
            .and_then(|s| s.parse())
            .unwrap();
        let set = apply_overrides(
            &scene,
            &[
                "render.exposure=1".into(),
                "media.fog.sigma_s=(0.1, 0.2, 0.3)".into(),
            ],
        )
        .unwrap();
        let fog = &set.media["fog"];
        assert_eq!(fog.sigma_s, Some([0.1, 0.2, 0.3]));
        assert_eq!(fog.sigma_a, scene.media["fog"].sigma_a);
        assert_eq!((fog.albedo, fog.mean_free_path), (None, None));
    }
}

//! A JSON Schema (draft 2020-12) validator for the keywords `schemars` writes into
//! `schema/scene.schema.json`, so the test that every scene satisfies the editors' schema needs
//! no validator crate: the `jsonschema` crate and its regex and URI stack were a fifth of the
//! test command's build (cargo's `--timings`, 7 December 2026), for one test.
//!
//! Covered, with the draft's meaning: `type` (a name or a list; "integer" is a number without a
//! fractional part), `enum`, `const`, `properties`, `required`, `additionalProperties` (a boolean
//! or a schema), `items` (after `prefixItems` when both are given), `prefixItems`, `minItems`,
//! `maxItems`, `minimum`, `maximum`, `anyOf`, `oneOf`, `allOf`, `not`, `$ref` to `#/$defs/…`
//! (beside other keywords, as 2020-12 allows), and the boolean schemas. Annotations (`title`,
//! `description`, `default`, `format`, `$schema`) are ignored, as validators do by default. A
//! keyword outside this list is reported as an error rather than skipped, so a schema that grows
//! a new kind of constraint cannot pass unchecked.

use serde_json::{Map, Value};

/// Keywords that only annotate: never a reason to reject an instance.
const ANNOTATIONS: &[&str] = &[
    "title",
    "description",
    "default",
    "format",
    "$schema",
    "$defs",
];

/// The errors of `instance` against the root schema `root` (empty: valid), each as
/// "`<instance path>`: what is wrong".
pub fn errors(root: &Value, instance: &Value) -> Vec<String> {
    let mut out = Vec::new();
    check(root, root, instance, "", &mut out);
    out
}

fn check(root: &Value, schema: &Value, v: &Value, path: &str, out: &mut Vec<String>) {
    let s = match schema {
        Value::Bool(true) => return,
        Value::Bool(false) => return out.push(format!("`{path}`: no value is allowed here")),
        Value::Object(s) => s,
        _ => {
            return out.push(format!(
                "`{path}`: the schema is not an object or a boolean"
            ));
        }
    };
    for (key, k) in s {
        match key.as_str() {
            "type" => check_type(k, v, path, out),
            "enum" => {
                if !k.as_array().is_some_and(|a| a.iter().any(|e| same(e, v))) {
                    out.push(format!("`{path}`: {v} is not one of {k}"));
                }
            }
            "const" => {
                if !same(k, v) {
                    out.push(format!("`{path}`: {v} is not {k}"));
                }
            }
            "$ref" => match resolve(root, k) {
                Some(target) => check(root, target, v, path, out),
                None => out.push(format!("`{path}`: unresolvable $ref {k}")),
            },
            "properties" | "required" | "additionalProperties" => {
                if let (Value::Object(o), "properties") = (v, key.as_str()) {
                    check_object(root, s, o, path, out);
                }
            }
            "items" | "prefixItems" | "minItems" | "maxItems" => {
                if let (Value::Array(a), "items") = (v, key.as_str()) {
                    check_array(root, s, a, path, out);
                }
            }
            "minimum" | "maximum" => check_bound(key, k, v, path, out),
            "anyOf" | "oneOf" | "allOf" => check_combination(root, key, k, v, path, out),
            "not" => {
                let mut inner = Vec::new();
                check(root, k, v, path, &mut inner);
                if inner.is_empty() {
                    out.push(format!("`{path}`: {v} matches a `not` schema"));
                }
            }
            other if ANNOTATIONS.contains(&other) => {}
            other => out.push(format!("`{path}`: keyword `{other}` is not understood")),
        }
    }
    // Object and array keywords without `properties` / `items` beside them.
    if let Value::Object(o) = v
        && !s.contains_key("properties")
        && (s.contains_key("required") || s.contains_key("additionalProperties"))
    {
        check_object(root, s, o, path, out);
    }
    if let Value::Array(a) = v
        && !s.contains_key("items")
        && ["prefixItems", "minItems", "maxItems"]
            .iter()
            .any(|k| s.contains_key(*k))
    {
        check_array(root, s, a, path, out);
    }
}

/// JSON equality, numbers compared by value (1 and 1.0 are the same number).
fn same(a: &Value, b: &Value) -> bool {
    match (a, b) {
        (Value::Number(x), Value::Number(y)) => x.as_f64() == y.as_f64(),
        _ => a == b,
    }
}

fn resolve<'a>(root: &'a Value, r: &Value) -> Option<&'a Value> {
    let name = r.as_str()?.strip_prefix("#/$defs/")?;
    root.get("$defs")?.get(name)
}

fn type_matches(name: &str, v: &Value) -> bool {
    match name {
        "null" => v.is_null(),
        "boolean" => v.is_boolean(),
        "object" => v.is_object(),
        "array" => v.is_array(),
        "string" => v.is_string(),
        "number" => v.is_number(),
        "integer" => v.as_f64().is_some_and(|x| x.fract() == 0.0),
        _ => false,
    }
}

fn check_type(k: &Value, v: &Value, path: &str, out: &mut Vec<String>) {
    let ok = match k {
        Value::String(t) => type_matches(t, v),
        Value::Array(ts) => ts
            .iter()
            .any(|t| t.as_str().is_some_and(|t| type_matches(t, v))),
        _ => false,
    };
    if !ok {
        out.push(format!("`{path}`: {v} is not of type {k}"));
    }
}

fn check_object(
    root: &Value,
    s: &Map<String, Value>,
    o: &Map<String, Value>,
    path: &str,
    out: &mut Vec<String>,
) {
    let props = s.get("properties").and_then(Value::as_object);
    for name in s
        .get("required")
        .and_then(Value::as_array)
        .into_iter()
        .flatten()
    {
        if let Some(n) = name.as_str()
            && !o.contains_key(n)
        {
            out.push(format!("`{path}`: the required property `{n}` is missing"));
        }
    }
    for (name, value) in o {
        let sub = format!("{path}/{name}");
        match props.and_then(|p| p.get(name)) {
            Some(ps) => check(root, ps, value, &sub, out),
            None => {
                if let Some(extra) = s.get("additionalProperties") {
                    check(root, extra, value, &sub, out);
                }
            }
        }
    }
}

fn check_array(
    root: &Value,
    s: &Map<String, Value>,
    a: &[Value],
    path: &str,
    out: &mut Vec<String>,
) {
    let len = a.len() as u64;
    if let Some(min) = s.get("minItems").and_then(Value::as_u64)
        && len < min
    {
        out.push(format!("`{path}`: {len} items, fewer than {min}"));
    }
    if let Some(max) = s.get("maxItems").and_then(Value::as_u64)
        && len > max
    {
        out.push(format!("`{path}`: {len} items, more than {max}"));
    }
    let prefix = s.get("prefixItems").and_then(Value::as_array);
    let n_prefix = prefix.map_or(0, Vec::len);
    for (i, item) in a.iter().enumerate() {
        let sub = format!("{path}/{i}");
        match prefix.and_then(|p| p.get(i)) {
            Some(ps) => check(root, ps, item, &sub, out),
            None if i >= n_prefix => {
                if let Some(items) = s.get("items") {
                    check(root, items, item, &sub, out);
                }
            }
            None => {}
        }
    }
}

fn check_bound(key: &str, k: &Value, v: &Value, path: &str, out: &mut Vec<String>) {
    if let (Some(bound), Some(x)) = (k.as_f64(), v.as_f64()) {
        let ok = if key == "minimum" {
            x >= bound
        } else {
            x <= bound
        };
        if !ok {
            out.push(format!("`{path}`: {x} is outside the {key} {bound}"));
        }
    }
}

fn check_combination(
    root: &Value,
    key: &str,
    k: &Value,
    v: &Value,
    path: &str,
    out: &mut Vec<String>,
) {
    let Some(options) = k.as_array() else {
        return out.push(format!("`{path}`: `{key}` is not a list"));
    };
    let results: Vec<Vec<String>> = options
        .iter()
        .map(|o| {
            let mut e = Vec::new();
            check(root, o, v, path, &mut e);
            e
        })
        .collect();
    let passed = results.iter().filter(|e| e.is_empty()).count();
    let ok = match key {
        "anyOf" => passed >= 1,
        "oneOf" => passed == 1,
        _ => passed == options.len(),
    };
    if !ok {
        let closest = results
            .iter()
            .filter(|e| !e.is_empty())
            .min_by_key(|e| e.len())
            .map(|e| e.join("; "))
            .unwrap_or_default();
        out.push(format!(
            "`{path}`: {passed} of {} `{key}` options match (closest: {closest})",
            options.len()
        ));
    }
}

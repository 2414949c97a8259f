//! The bath scene's models (issues #15, #27): `assets/duck.obj`, `assets/boat.obj` and
//! `assets/faucet.obj` are exactly
//! what `examples/make_models` generates (byte for byte: the generator uses only arithmetic
//! and `sqrt`, so its text is the same on every platform), its checker refuses broken meshes,
//! and the committed files, read back through the renderer's own OBJ loader, are closed,
//! outward-wound meshes without degenerate or inverted triangles.

#[path = "../../examples/make_models/mesher.rs"]
mod mesher;
#[path = "../../examples/make_models/sdf.rs"]
mod sdf;
#[path = "../../examples/make_models/models.rs"]
mod toys;

use std::collections::HashMap;

use glam::{DVec2, DVec3};

use caustic::compile::mesh::parse_obj;

use crate::common;

fn committed(name: &str) -> String {
    let path = common::root().join("assets").join(name);
    std::fs::read_to_string(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (regenerate with scripts/make_models.sh)",
            path.display()
        )
    })
}

fn assert_same_text(name: &str, generated: &str) {
    let file = committed(name);
    if file == generated {
        return;
    }
    let line = file
        .lines()
        .zip(generated.lines())
        .position(|(a, b)| a != b)
        .unwrap_or_else(|| file.lines().count().min(generated.lines().count()));
    panic!(
        "assets/{name} differs from the generator's output from line {} (committed {:?}, generated {:?}); regenerate with scripts/make_models.sh",
        line + 1,
        file.lines().nth(line),
        generated.lines().nth(line)
    );
}

#[test]
fn committed_models_are_what_the_generator_makes() {
    let t = std::time::Instant::now();
    let duck = toys::duck_obj().unwrap_or_else(|p| panic!("duck: {p:#?}"));
    let boat = toys::boat_obj().unwrap_or_else(|p| panic!("boat: {p:#?}"));
    let faucet = toys::faucet_obj().unwrap_or_else(|p| panic!("faucet: {p:#?}"));
    eprintln!("generated the three models in {:?}", t.elapsed());
    assert_same_text("duck.obj", &duck);
    assert_same_text("boat.obj", &boat);
    assert_same_text("faucet.obj", &faucet);
}

/// The groups of an OBJ text in order, with each group's face lines.
fn groups(text: &str) -> Vec<(String, usize)> {
    let mut out: Vec<(String, usize)> = Vec::new();
    for line in text.lines() {
        if let Some(g) = line.strip_prefix("g ") {
            out.push((g.to_string(), 0));
        } else if line.starts_with("f ") {
            out.last_mut().expect("a face before any group").1 += 1;
        }
    }
    out
}

/// Checks one group of a mesh as loaded by the renderer: closed with every edge used once each
/// way, no degenerate triangle, geometric normals agreeing with the vertex normals, and the
/// enclosed volume (divergence theorem) positive and near `volume` (a hand estimate from the
/// shapes' dimensions, within a factor of 2).
fn check_closed(name: &str, tris: &[[DVec3; 3]], normals: &[[DVec3; 3]]) -> f64 {
    // Weld by position: the file shares vertices per group, so welding must not merge more.
    let mut ids: HashMap<[u64; 3], u32> = HashMap::new();
    let mut id = |p: DVec3| {
        let key = p.to_array().map(f64::to_bits);
        let n = ids.len() as u32;
        *ids.entry(key).or_insert(n)
    };
    let mut edges: HashMap<(u32, u32), u32> = HashMap::new();
    let mut volume = 0.0;
    for (t, n) in tris.iter().zip(normals) {
        let [a, b, c] = t.map(&mut id);
        for e in [(a, b), (b, c), (c, a)] {
            *edges.entry(e).or_default() += 1;
        }
        let g = (t[1] - t[0]).cross(t[2] - t[0]);
        assert!(g.length() > 1e-12, "{name}: degenerate triangle {t:?}");
        assert!(
            g.dot(n[0] + n[1] + n[2]) > 0.0,
            "{name}: triangle {t:?} is inverted against its normals {n:?}"
        );
        volume += t[0].dot(t[1].cross(t[2])) / 6.0;
    }
    for (&(a, b), &k) in &edges {
        assert_eq!(
            (k, edges.get(&(b, a)).copied().unwrap_or(0)),
            (1, 1),
            "{name}: edge {a}-{b} is not shared by exactly two oppositely wound triangles"
        );
    }
    // Euler characteristic of a closed surface: V − E + F = 2 − 2g; these parts are spheres.
    let (v, e, f) = (ids.len() as i64, edges.len() as i64 / 2, tris.len() as i64);
    assert_eq!(
        v - e + f,
        2 * components(tris),
        "{name}: not a set of spheres"
    );
    volume
}

/// Connected components of a triangle soup, by shared vertex positions.
fn components(tris: &[[DVec3; 3]]) -> i64 {
    let mut parent: Vec<usize> = Vec::new();
    let mut ids: HashMap<[u64; 3], usize> = HashMap::new();
    fn find(parent: &mut [usize], mut i: usize) -> usize {
        while parent[i] != i {
            parent[i] = parent[parent[i]];
            i = parent[i];
        }
        i
    }
    for t in tris {
        let k: Vec<usize> = t
            .iter()
            .map(|p| {
                let key = p.to_array().map(f64::to_bits);
                let n = ids.len();
                *ids.entry(key).or_insert_with(|| {
                    parent.push(n);
                    n
                })
            })
            .collect();
        for w in k.windows(2) {
            let (a, b) = (find(&mut parent, w[0]), find(&mut parent, w[1]));
            parent[a] = b;
        }
    }
    (0..parent.len())
        .filter(|&i| find(&mut parent, i) == i)
        .count() as i64
}

/// Loads `name` with the renderer's OBJ reader and checks each group; returns group → volume.
fn check_model(name: &str, want: &[(&str, usize)]) -> HashMap<String, f64> {
    let text = committed(name);
    let got: Vec<(String, usize)> = groups(&text);
    let names: Vec<&str> = got.iter().map(|(g, _)| g.as_str()).collect();
    assert_eq!(
        names,
        want.iter().map(|w| w.0).collect::<Vec<_>>(),
        "{name}: groups"
    );
    let mesh = parse_obj(text.as_bytes(), std::path::Path::new(name)).expect("loads");
    assert!(mesh.warnings.is_empty(), "{:?}", mesh.warnings);
    let total: usize = got.iter().map(|g| g.1).sum();
    assert!(
        (2_000..=32_000).contains(&total),
        "{name}: {total} triangles"
    );
    assert_eq!(mesh.triangles.len(), total);
    let mut volumes = HashMap::new();
    let mut start = 0;
    for ((group, count), (_, min)) in got.iter().zip(want) {
        assert!(count >= min, "{name}/{group}: {count} triangles");
        let slice = &mesh.triangles[start..start + count];
        start += count;
        let tris: Vec<[DVec3; 3]> = slice
            .iter()
            .map(|t| t.map(|c| mesh.positions[c.p as usize].as_dvec3()))
            .collect();
        let normals: Vec<[DVec3; 3]> = slice
            .iter()
            .map(|t| {
                t.map(|c| {
                    let n = mesh.normals[c.n.expect("every corner has a normal") as usize];
                    assert!(
                        (n.length() - 1.0).abs() < 1e-3,
                        "{name}/{group}: normal {n}"
                    );
                    n.as_dvec3()
                })
            })
            .collect();
        for t in slice {
            for c in t {
                let uv = mesh.uvs[c.t.expect("every corner has a uv") as usize];
                assert!((0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y));
            }
        }
        let v = check_closed(&format!("{name}/{group}"), &tris, &normals);
        volumes.insert(group.clone(), v);
    }
    volumes
}

#[test]
fn the_duck_is_closed_outward_and_shaped_like_a_duck() {
    let v = check_model("duck.obj", &[("body", 5000), ("beak", 500), ("eyes", 300)]);
    // Hand estimates from the shapes' dimensions: the body ellipsoid 4/3 π 0.5·0.3·0.37 ≈ 0.23
    // plus head 4/3 π 0.215³ ≈ 0.04, minus the flattened bottom; the beak 4/3 π 0.17·0.045·0.12
    // ≈ 0.0038, about half of it outside the head; two eyes 2 · 4/3 π 0.042³ ≈ 0.00062.
    let near = |g: &str, want: f64| {
        let got = v[g];
        assert!(
            got > want / 2.0 && got < want * 2.0,
            "{g}: volume {got}, want ≈ {want}"
        );
    };
    near("body", 0.27);
    near("beak", 0.0038);
    near("eyes", 0.00062);
}

#[test]
fn the_boat_is_closed_and_outward() {
    let v = check_model(
        "boat.obj",
        &[
            ("hull", 3000),
            ("deck", 1000),
            ("cabin", 1000),
            ("mast", 500),
            ("sail", 1000),
        ],
    );
    // The mast: a cylinder π 0.02² · 0.86 ≈ 0.0011; the sail a triangle ½ · 0.425 · 0.58 of
    // thickness 0.04 ≈ 0.0049.
    assert!((0.0008..0.0014).contains(&v["mast"]), "{v:?}");
    assert!((0.0035..0.0065).contains(&v["sail"]), "{v:?}");
}

#[test]
fn the_faucet_is_closed_and_outward() {
    let v = check_model(
        "faucet.obj",
        &[("escutcheon", 3000), ("spout", 3000), ("handles", 3000)],
    );
    // Hand estimates (decimetres³): the escutcheon π 0.55² · 0.12 ≈ 0.114 plus two rosettes
    // 2 · π 0.38² · 0.1 ≈ 0.091, less the rounded edges; the spout's tube π 0.2² · 1.12 ≈ 0.141,
    // bend ≈ 0.035, neck π 0.28² · 0.4 ≈ 0.099 (partly shared), nozzle π 0.19² · 0.3 ≈ 0.034;
    // each handle's stem ≈ 0.031, hub ≈ 0.04, lever π 0.08² · 0.73 ≈ 0.015, tip ≈ 0.0056.
    let near = |g: &str, want: f64| {
        let got = v[g];
        assert!(
            got > want * 0.7 && got < want * 1.3,
            "{g}: volume {got}, want ≈ {want}"
        );
    };
    near("escutcheon", 0.19);
    near("spout", 0.28);
    near("handles", 0.18);
}

/// A sphere meshed by the generator, for the checker tests.
fn ball() -> mesher::Part {
    let f = |p: DVec3| p.length() - 0.5;
    mesher::mesh_part(&mesher::PartSpec {
        name: "ball",
        sdf: &f,
        bounds: (DVec3::splat(-0.5), DVec3::splat(0.5)),
        cell: 0.1,
        centre: DVec3::ZERO,
    })
}

#[test]
fn the_generators_checker_refuses_broken_meshes() {
    let good = ball();
    assert!(mesher::check(&good).is_ok());
    // A hole: one triangle removed.
    let mut holed = ball();
    holed.triangles.pop();
    let e = mesher::check(&holed).unwrap_err();
    assert!(e.iter().any(|p| p.contains("edge")), "{e:?}");
    // One triangle turned inside out (the report's bug).
    let mut flipped = ball();
    flipped.triangles[7].swap(1, 2);
    let e = mesher::check(&flipped).unwrap_err();
    assert!(
        e.iter().any(|p| p.contains("triangle 7 is inverted")),
        "{e:?}"
    );
    // Everything inside out: consistently wound, but inwards.
    let mut inward = ball();
    for t in &mut inward.triangles {
        t.swap(1, 2);
    }
    inward.normals.iter_mut().for_each(|n| *n = -*n);
    let e = mesher::check(&inward).unwrap_err();
    assert!(e.iter().any(|p| p.contains("wound inwards")), "{e:?}");
    // A degenerate triangle: two corners moved onto the third.
    let mut squashed = ball();
    let t = squashed.triangles[3];
    squashed.positions[t[1] as usize] = squashed.positions[t[0] as usize];
    let e = mesher::check(&squashed).unwrap_err();
    assert!(e.iter().any(|p| p.contains("degenerate")), "{e:?}");
    // Two spheres glued at a vertex: every edge fine, the vertex not a disk.
    let mut pinched = ball();
    let other = ball();
    let n = pinched.positions.len() as u32;
    let shared = other.triangles[0][0];
    pinched
        .positions
        .extend(other.positions.iter().map(|p| *p + DVec3::X));
    pinched.normals.extend(&other.normals);
    pinched.uvs.extend(&other.uvs);
    pinched.triangles.extend(other.triangles.iter().map(|t| {
        t.map(|k| {
            if k == shared {
                good.triangles[0][0]
            } else {
                k + n
            }
        })
    }));
    let e = mesher::check(&pinched).unwrap_err();
    assert!(e.iter().any(|p| p.contains("not manifold")), "{e:?}");
}

#[test]
fn the_generators_maths_is_what_std_computes() {
    for d in [-90.0, -35.0, 0.0, 8.0, 30.0, 60.0, 90.0] {
        let (c, s) = sdf::cos_sin(d);
        let r = f64::to_radians(d);
        assert!(
            (c - r.cos()).abs() < 1e-15 && (s - r.sin()).abs() < 1e-15,
            "{d}"
        );
    }
    // A 3-4-5 triangle's distance field: 0 on an edge, −(inradius 1) at the incentre (1, 1).
    let (a, b, c) = (DVec2::ZERO, DVec2::new(4.0, 0.0), DVec2::new(0.0, 3.0));
    assert!(sdf::triangle_2d(DVec2::new(2.0, 0.0), a, b, c).abs() < 1e-12);
    assert!((sdf::triangle_2d(DVec2::new(1.0, 1.0), a, b, c) + 1.0).abs() < 1e-12);
    assert!((sdf::triangle_2d(DVec2::new(2.0, -2.0), a, b, c) - 2.0).abs() < 1e-12);
    // The ellipsoid's zero set is exact: points on it give 0.
    let r = DVec3::new(0.5, 0.3, 0.2);
    for p in [DVec3::X * 0.5, DVec3::Y * 0.3, DVec3::new(0.3, 0.24, 0.0)] {
        assert!(sdf::ellipsoid(p, DVec3::ZERO, r).abs() < 1e-12, "{p}");
    }
}

/// A tetrahedron whose slanted face is group `lid` with `usemtl glaze`, the rest group `base`.
const TETRA: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\ng base\nf 1 3 2\nf 1 2 4\nf 1 4 3\ng lid\nusemtl glaze\nf 2 3 4\n";

/// Compiles a one-mesh scene over `obj` with the mesh fields `fields` (RON); returns the
/// material name of each triangle, the slanted face's (normal (1, 1, 1)) first.
fn materials_per_triangle(obj: &str, fields: &str) -> Vec<String> {
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("m.obj");
    std::fs::write(&path, obj).expect("obj written");
    let scene = common::scene_from_text(&format!(
        r#"Scene(
            camera: Pinhole(eye: (0, 1, 4), look_at: (0, 0, 0), fov_y: 40),
            materials: {{ "white": (), "red": (color: (0.8, 0, 0)), "blue": (color: (0, 0, 0.8)) }},
            lights: [Point(position: (0, 3, 2), power: (50, 50, 50))],
            nodes: [Mesh(file: {:?}, {fields})],
        )"#,
        path.display().to_string()
    ));
    let g = &scene.geometry;
    let mut out: Vec<(bool, String)> = g
        .triangles
        .iter()
        .zip(&g.tri_attrs)
        .map(|(t, a)| {
            let n = (t[1] - t[0]).cross(t[2] - t[0]);
            let m = scene.objects[a.object as usize]
                .material
                .expect("not a light");
            (
                n.x <= 0.0 || n.y <= 0.0,
                scene.material_names[m as usize].clone(),
            )
        })
        .collect();
    out.sort();
    out.into_iter().map(|(_, m)| m).collect()
}

#[test]
fn mesh_groups_and_usemtl_names_choose_materials() {
    let by = |fields: &str| materials_per_triangle(TETRA, fields);
    // By group; the `usemtl` name of the lid is also a key, and wins over its group.
    assert_eq!(
        by(r#"materials: {"base": "red", "lid": "blue"}"#),
        ["blue", "red", "red", "red"]
    );
    assert_eq!(
        by(r#"materials: {"base": "red", "lid": "red", "glaze": "blue"}"#),
        ["blue", "red", "red", "red"]
    );
    // Faces the map leaves out take the node's `material`.
    assert_eq!(
        by(r#"material: "white", materials: {"glaze": "blue"}"#),
        ["blue", "white", "white", "white"]
    );
    assert_eq!(by(r#"material: "white""#), ["white"; 4]);
}

#[test]
fn the_duck_and_boat_map_every_group() {
    for (file, fields, want) in [
        (
            "duck.obj",
            r#"materials: {"body": "white", "beak": "red", "eyes": "blue"}"#,
            [("white", "body"), ("red", "beak"), ("blue", "eyes")].as_slice(),
        ),
        (
            "boat.obj",
            r#"material: "white", materials: {"hull": "red", "mast": "blue"}"#,
            [("red", "hull"), ("blue", "mast")].as_slice(),
        ),
    ] {
        let text = committed(file);
        let counts: HashMap<String, usize> = groups(&text).into_iter().collect();
        let got = materials_per_triangle(&text, fields);
        let total: usize = counts.values().sum();
        assert_eq!(got.len(), total, "{file}: no triangle dropped");
        let mut mapped = 0;
        for (material, group) in want {
            let n = got.iter().filter(|m| m == material).count();
            assert_eq!(n, counts[*group], "{file}: {group} → {material}");
            mapped += n;
        }
        let rest = got.iter().filter(|m| *m == "white").count();
        assert_eq!(
            rest,
            total - mapped
                + if file == "duck.obj" {
                    counts["body"]
                } else {
                    0
                }
        );
    }
}

#[test]
fn mesh_materials_read_the_same_in_ron_and_toml() {
    use caustic::scene::SourceFile;
    let ron = r#"Scene(
        camera: Pinhole(eye: (0, 1, 4), look_at: (0, 0, 0), fov_y: 40),
        materials: { "yellow": (), "orange": () },
        nodes: [Mesh(file: "duck.obj", material: "yellow", materials: {"beak": "orange", "eyes": "orange"})],
    )"#;
    let toml = r#"
        [camera.Pinhole]
        eye = [0, 1, 4]
        look_at = [0, 0, 0]
        fov_y = 40
        [materials]
        yellow = {}
        orange = {}
        [[nodes]]
        [nodes.Mesh]
        file = "duck.obj"
        material = "yellow"
        materials = { beak = "orange", eyes = "orange" }
    "#;
    let a = SourceFile::new(std::path::Path::new("a.ron"), ron.into()).expect("ron");
    let b = SourceFile::new(std::path::Path::new("a.toml"), toml.into()).expect("toml");
    assert_eq!(
        a.parse().expect("ron parses"),
        b.parse().expect("toml parses")
    );
}

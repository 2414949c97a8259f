//! The path index against hand-counted positions in RON and TOML texts.
use super::*;

const RON: &str = r#"// demo
Scene(
    render: (width: 64, height: 48, samples_per_pixel: 4),
    camera: Pinhole(eye: (0, 1, 4), look_at: (0, 1, 0), up: (0, 1, 0), fov_y: 40),
    materials: {
        "glass": (color: (1, 1, 1), transmit: 1.0, ior: 1.5),
        "water": (color: (0.9, 0.95, 1.0), transmit: 0.9, reflect: 0.1, ior: -1.33),
    },
    lights: [
        Point(position: (0, 3, 0), power: (50, 50, 50)),
        Sphere(center: (1, 3, 0), radius: -0.1, power: (10, 10, 10)),
    ],
    nodes: [
        Group(transform: [Translate(0, 1, 0), Scale(0.5)], children: [
            Sphere(radius: 1.0, material: "glass"),
            Cube(material: "watr"),
        ]),
    ],
)
"#;

const TOML: &str = r#"# demo
[render]
width = 64
height = 48
samples_per_pixel = 4

[camera.Pinhole]
eye = [0, 1, 4]
look_at = [0, 1, 0]
up = [0, 1, 0]
fov_y = 40

[materials.glass]
color = [1, 1, 1]
transmit = 1.0
ior = 1.5

[materials.water]
color = [0.9, 0.95, 1.0]
transmit = 0.9
reflect = 0.1
ior = -1.33

[[lights]]
Point = { position = [0, 3, 0], power = [50, 50, 50] }

[[lights]]
[lights.Sphere]
center = [1, 3, 0]
radius = -0.1
power = [10, 10, 10]

[[nodes]]
[nodes.Group]
transform = [{ Translate = [0, 1, 0] }, { Scale = 0.5 }]
children = [
    { Sphere = { radius = 1.0, material = "glass" } },
    { Cube = { material = "watr" } },
]
"#;

/// Checks whitespace-separated `path@line:col` cases with `locate` (or `locate_key`).
fn check(index: &SourceIndex, key: bool, cases: &str) {
    let mut bad = Vec::new();
    for case in cases.split_whitespace() {
        let (path, want) = case.rsplit_once('@').expect("case is path@line:col");
        let got = if key {
            index.locate_key(path)
        } else {
            index.locate(path)
        };
        let got = got.map(|l| format!("{}:{}", l.line, l.column));
        if got.as_deref() != Some(want) {
            bad.push(format!("{path}: got {got:?}, want {want}"));
        }
    }
    assert!(bad.is_empty(), "{bad:#?}");
}

fn ron(text: &str) -> SourceIndex {
    SourceIndex::build(text, SourceFormat::Ron)
}

fn toml(text: &str) -> SourceIndex {
    SourceIndex::build(text, SourceFormat::Toml)
}

#[test]
fn ron_fields_map_keys_and_enum_variants() {
    let index = ron(RON);
    check(
        &index,
        false,
        "render@3:13 render.width@3:21 render.height@3:33 \
            camera@4:13 camera.fov_y@4:79 camera.Pinhole.fov_y@4:79 Scene.render.width@3:21 \
            materials.water.ior@7:78 materials.glass.color@6:26 lights[1]@11:9 \
            lights[1].radius@11:43 lights[1].center@11:24 lights[1].power[2]@11:65 \
            nodes[0].children[0]@15:13 nodes[0].children[0].radius@15:28 \
            nodes[0].children[1].material@16:28",
    );
    check(
        &index,
        true,
        "render.width@3:14 camera@4:5 camera.fov_y@4:72 \
            materials.water@7:9 materials.water.ior@7:73 lights[1].radius@11:35 \
            lights[1]@11:9 nodes[0].children@14:60",
    );
}

#[test]
fn ron_tuple_variant_elements() {
    check(
        &ron(RON),
        false,
        "nodes[0].transform@14:26 nodes[0].transform[0]@14:27 \
            nodes[0].transform[1]@14:47 nodes[0].transform[0][0]@14:37 \
            nodes[0].transform[0][2]@14:43 nodes[0].transform[0].Translate[1]@14:40 \
            nodes[0].transform[1][0]@14:53",
    );
}

#[test]
fn missing_paths_fall_back_or_give_none() {
    let index = ron(RON);
    check(
        &index,
        false,
        "materials.water.foo@7:18 materials.watr.ior@5:16 \
            lights[7].radius@9:13 nodes[0].children[1].material.deeper[3]@16:28 \
            render.width[0]@3:21",
    );
    // A missing field has no key, so locate_key falls back like locate.
    check(&index, true, "materials.water.foo@7:18");
    for path in ["foo", "foo.bar", "", "[0]", ".", "render2.width"] {
        assert_eq!(index.locate(path), None, "{path}");
        assert_eq!(index.locate_key(path), None, "{path}");
    }
}

#[test]
fn toml_tables_arrays_of_tables_and_inline_tables() {
    let index = toml(TOML);
    check(
        &index,
        false,
        "render@2:1 render.width@3:9 camera@7:2 camera.fov_y@11:9 \
            camera.Pinhole.fov_y@11:9 materials.water@18:1 materials.water.ior@22:7 \
            lights[0]@24:1 lights[0].position@25:22 lights[0].Point.power[1]@25:46 \
            lights[1]@27:1 lights[1].radius@30:10 lights[1].Sphere.radius@30:10 \
            nodes[0].transform[0]@35:14 nodes[0].transform[0][1]@35:32 \
            nodes[0].transform[1][0]@35:51 nodes[0].children[0].radius@37:27 \
            nodes[0].children[1].material@38:27 nodes[0].children[1].oops@38:5 \
            materials.water.foo@18:1",
    );
    check(
        &index,
        true,
        "render.width@3:1 materials.water@18:12 lights[1].radius@30:1 \
            nodes[0].children[1].material@38:16 nodes[0].transform[0]@35:14",
    );
    assert_eq!(index.locate("scene.render"), None);
}

#[test]
fn toml_dotted_keys() {
    let index = toml(
        "render.width = 64\ncamera.Pinhole.fov_y = 40\n\
            camera.Pinhole.eye = [0, 1, 4]\n\
            lights = [{ Sphere = { radius = -0.1 } }, { Point.power = 3 }]\n",
    );
    check(
        &index,
        false,
        "render.width@1:16 camera.fov_y@2:24 camera.eye[2]@3:29 \
            lights[0].radius@4:33 lights[1].power@4:59",
    );
    check(&index, true, "render.width@1:8 camera.fov_y@2:16");
}

#[test]
fn toml_unparsable_finds_nothing() {
    let index = toml("a = [1, 2\nb = 3\n");
    assert_eq!(index.locate("b"), None);
    assert_eq!(
        index.location_of_offset(12),
        Location {
            line: 2,
            column: 3,
            offset: 12
        }
    );
}

#[test]
fn ron_comments_strings_and_literals() {
    let index = ron("#![enable(implicit_some)]\n\
            ( // a comment with ( and \" and :\n\
            \x20 /* block ( \" : /* nested ) */ still \" */\n\
            \x20 a: \"x: ( \\\" y\", // (\n\
            \x20 b: r#\"raw \" ) \"#, c: '\"', e: '(',\n\
            \x20 d: [1e-3, -inf, NaN, 0x1F, +2, b\"x)\", b'(', r\"q\"],\n\
            \x20 m: {\"a.b\": 1, \"quo\\\"te\": 2, 7: 3, (1, 2): 4, \"k\": Some((z: 5))},\n\
            \x20 f: (),\n\
            )");
    check(
        &index,
        false,
        "a@4:6 b@5:6 c@5:24 e@5:32 d[1]@6:13 d[4]@6:30 d[7]@6:47 \
            m.\"a.b\"@7:14 m.quo\"te@7:28 m.7@7:34 m.k.z@7:62 m.k.Some.z@7:62 m.k[0].z@7:62 f@8:6",
    );
}

#[test]
fn enum_payloads() {
    let index = ron("(t: [Scale((1, 2)), Translate(0, 1, 0)], s: 3)");
    check(&index, false, "t[0]@1:6 t[1]@1:21");
    let at = |p: &str| index.locate_payload(p).map(|l| l.column);
    assert_eq!(
        (at("t[0]"), at("t[1]"), at("s")),
        (Some(12), Some(30), Some(45))
    );
    let index = toml("t = [{ Scale = [1, 2] }]\n");
    assert_eq!(index.locate_payload("t[0]").map(|l| l.column), Some(16));
    assert!(index.contains("t[0]") && !index.contains("t[1]") && !index.contains("u"));
}

#[test]
fn garbage_never_panics() {
    let pieces = [
        "(", ")", "[", "]", "{", "}", ":", ",", "\"", "'", "r#\"", "/*", "*/", "//", "\n", "\r\n",
        "a", "Foo", "é", "日本", "\\", "#![", "=", "[[x]]", "x.y", " ", "1.5", "-", "b'", "r#",
        "\0",
    ];
    let mut seed = 0x2545_f491_4f6c_dd1d_u64;
    for round in 0..2000 {
        let mut text = String::new();
        for _ in 0..(round % 40) {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            text.push_str(pieces[(seed % pieces.len() as u64) as usize]);
        }
        for index in [ron(&text), toml(&text)] {
            for path in [
                "a",
                "a.b",
                "x[0].y",
                "Foo[1][2]",
                "[",
                "a..b[",
                "a[99999999999999999999]",
            ] {
                let _ = (index.locate(path), index.locate_key(path));
            }
            for offset in [0, 1, 2, 3, text.len(), text.len() + 10, usize::MAX] {
                let loc = index.location_of_offset(offset);
                assert!(loc.offset <= text.len() && loc.line >= 1 && loc.column >= 1);
            }
        }
    }
}

#[test]
fn unterminated_string_and_comment() {
    check(&ron("(a: 1, b: \"abc é"), false, "a@1:5 b@1:11 b.c@1:11");
    check(&ron("(a: 1, /* open /* nested */ ("), false, "a@1:5");
    check(&ron("(a: 1, b: r##\"never é"), false, "b@1:11");
    check(&ron("(a: 'é"), false, "a@1:5");
    check(&ron("(a: [1, 2], b: (c: ]"), false, "a[1]@1:9 b.c@1:20");
}

#[test]
fn deep_nesting_does_not_overflow() {
    let depth = 10_000;
    let index = ron(&format!("{}1{}", "[".repeat(depth), "]".repeat(depth)));
    check(&index, false, "[0][0]@1:3");
    let deep = index.locate(&"[0]".repeat(depth)).map(|l| l.column);
    assert_eq!(deep, Some(MAX_DEPTH + 1));
    let somes = "Some(".repeat(depth) + "1" + &")".repeat(depth);
    check(
        &ron(&format!("(a: {somes}, b: 2)")),
        false,
        "b@1:60011 a.x@1:5",
    );
    let arrays = format!("a = {}1{}", "[".repeat(depth), "]".repeat(depth));
    assert_eq!(toml(&arrays).locate("a"), None);
    let tables = format!("a = {}1{}", "{ A = ".repeat(depth), " }".repeat(depth));
    assert_eq!(toml(&tables).locate("a"), None);
}

#[test]
fn crlf_line_endings() {
    let paths = "camera.fov_y@4:79 nodes[0].children[1].material@16:28";
    check(&ron(&RON.replace('\n', "\r\n")), false, paths);
    let paths = "camera.fov_y@11:9 lights[1].radius@30:10";
    check(&toml(&TOML.replace('\n', "\r\n")), false, paths);
}

#[test]
fn columns_count_chars() {
    let index = ron("(name: \"héllo wörld 日本\", ñ: 1, x: 2)");
    check(&index, false, "x@1:35 ñ@1:29");
    assert_eq!(index.locate("x").map(|l| l.offset), Some(41));
    let index = toml("a = { s = \"日本語\", x = 5 }\n");
    check(&index, false, "a.x@1:22");
    // An offset inside a multi-byte char moves back to its start; past the end clamps.
    assert_eq!(
        index.location_of_offset(12),
        Location {
            line: 1,
            column: 12,
            offset: 11
        }
    );
    assert_eq!(index.location_of_offset(usize::MAX).line, 2);
}

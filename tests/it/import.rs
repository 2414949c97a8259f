//! Mesh files from the scene file (issue 45, and issue 47's `mesh-device-file` and
//! `obj-index-zero`): regular files only, read in bounded memory; a file of another kind says
//! what it is; OBJ index 0 is named as such.

use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use crate::common::root;

/// A folder of `tests/reported/`.
fn case(name: &str) -> PathBuf {
    root().join("tests/reported").join(name)
}

/// Runs `caustic args` in `dir` under a 1.5 GB address-space cap (so a reader that holds an
/// endless file fails fast instead of taking the machine's memory), killing it (and failing) if
/// it has not ended within 30 s: returns (exit code, stderr).
fn run_capped(dir: &Path, args: &[&str]) -> (i32, String) {
    let limit = Duration::from_secs(30);
    let mut child = Command::new("sh")
        .arg("-c")
        .arg("ulimit -v 1500000; exec \"$0\" \"$@\"")
        .arg(env!("CARGO_BIN_EXE_caustic"))
        .args(args)
        .current_dir(dir)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("sh runs");
    let start = Instant::now();
    while child.try_wait().expect("wait").is_none() {
        if start.elapsed() > limit {
            child.kill().expect("kill");
            let _ = child.wait();
            panic!("`caustic {}` still running after {limit:?}", args.join(" "));
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    let out = child.wait_with_output().expect("output");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// A scene in `dir` whose one mesh is `file`, checked (loaded, not rendered): (exit, stderr).
fn check_mesh(dir: &Path, file: &str) -> (i32, String) {
    let scene = format!(
        "Scene(render: (width: 8, height: 8, samples_per_pixel: 1),
           camera: Pinhole(eye: (0, 0, 3), look_at: (0, 0, 0), fov_y: 40),
           materials: {{\"m\": ()}},
           lights: [Point(position: (0, 1, 3), power: (40, 40, 40))],
           nodes: [Mesh(file: {file:?}, material: \"m\")])"
    );
    std::fs::write(dir.join("scene.ron"), scene).expect("write scene");
    run_capped(dir, &["check", "scene.ron"])
}

// ---- A mesh path that is a device, a pipe or a huge file -----------------------------------

#[test]
fn a_device_as_a_mesh_is_refused_before_it_is_read() {
    let (code, stderr) = run_capped(&case("mesh-device-file"), &["check", "scene.ron"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("`/dev/zero` is a character device")
            && stderr.contains("not a regular file"),
        "{stderr}"
    );
    // A symbolic link to an endless device is the device.
    let tmp = tempfile::tempdir().expect("tmp");
    std::os::unix::fs::symlink("/dev/urandom", tmp.path().join("noise.obj")).expect("symlink");
    let (code, stderr) = check_mesh(tmp.path(), "noise.obj");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("noise.obj` is a character device"),
        "{stderr}"
    );
}

#[test]
fn a_named_pipe_as_a_mesh_is_refused_without_waiting_for_a_writer() {
    let tmp = tempfile::tempdir().expect("tmp");
    let fifo = tmp.path().join("pipe.obj");
    let made = Command::new("mkfifo").arg(&fifo).status().expect("mkfifo");
    assert!(made.success());
    let (code, stderr) = check_mesh(tmp.path(), "pipe.obj");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("pipe.obj` is a named pipe (FIFO)"),
        "{stderr}"
    );
}

#[test]
fn sparse_and_oversized_mesh_files_fail_at_once_in_bounded_memory() {
    let tmp = tempfile::tempdir().expect("tmp");
    // 2 GiB of holes: refused after its first megabyte (the cap is 1.5 GB of address space).
    let f = std::fs::File::create(tmp.path().join("sparse.obj")).expect("create");
    f.set_len(2 << 30).expect("sparse file");
    let (code, stderr) = check_mesh(tmp.path(), "sparse.obj");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("sparse.obj` begins with 1048576 zero bytes: it holds no mesh data"),
        "{stderr}"
    );
    // A real OBJ start followed by holes: the zero byte is found in the first chunk.
    let mut f = std::fs::File::create(tmp.path().join("holes.obj")).expect("create");
    std::io::Write::write_all(&mut f, b"v 0 0 0\nv 1 0 0\nv 0 1 0\n").expect("write");
    f.set_len(2 << 30).expect("sparse file");
    let (code, stderr) = check_mesh(tmp.path(), "holes.obj");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("holes.obj` has a zero byte at offset 24: an OBJ file is text"),
        "{stderr}"
    );
    // Larger than the 4 GiB a mesh file may be: refused from its length alone.
    let f = std::fs::File::create(tmp.path().join("huge.obj")).expect("create");
    f.set_len(5 << 30).expect("sparse file");
    let (code, stderr) = check_mesh(tmp.path(), "huge.obj");
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains(
            "huge.obj` is 5.0 GiB, larger than the 4.0 GiB caustic reads for one mesh file"
        ),
        "{stderr}"
    );
    // A directory.
    std::fs::create_dir(tmp.path().join("dir.obj")).expect("mkdir");
    let (code, stderr) = check_mesh(tmp.path(), "dir.obj");
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("dir.obj` is a directory"), "{stderr}");
}

// ---- A file of another kind ----------------------------------------------------------------

#[test]
fn a_mesh_file_of_another_kind_says_what_it_is() {
    let tmp = tempfile::tempdir().expect("tmp");
    // Binary STL: an 80-byte header, a triangle count, 50 bytes per triangle.
    let mut stl = vec![b'x'; 80];
    stl.extend(1u32.to_le_bytes());
    stl.extend([1u8; 50]);
    let cases: [(&str, &[u8], &str); 4] = [
        ("model.stl", &stl, "this is an STL file"),
        (
            "m.bin",
            b"solid m\n facet normal 0 0 1\n",
            "this is an STL file",
        ),
        (
            "scan.fbx",
            b"Kaydara FBX Binary  \x00\x1a\x00",
            "this is an FBX file",
        ),
        ("room.blend", b"BLENDER-v304", "this is a Blender file"),
    ];
    for (name, bytes, says) in cases {
        std::fs::write(tmp.path().join(name), bytes).expect("write");
        let (code, stderr) = check_mesh(tmp.path(), name);
        assert_eq!(code, 2, "{name}: {stderr}");
        assert!(
            stderr.contains(&format!("{name}`: {says}")),
            "{name}: {stderr}"
        );
        assert!(!stderr.contains("no faces"), "{name}: {stderr}");
    }
}

// ---- OBJ index 0 ---------------------------------------------------------------------------

#[test]
fn obj_index_zero_is_named_as_such_and_other_bad_indices_keep_their_count() {
    let dir = case("obj-index-zero");
    let expect = [
        (
            "zero",
            "`f 0 1 2`: the face uses vertex index 0, but OBJ indices start at 1 (negative ones count back from the last vertex)",
        ),
        (
            "past_end",
            "`f 1 2 7`: the face uses vertex 7, but only 3 vertices are defined above it",
        ),
        (
            "neg_past",
            "`f -1 -2 -9`: the face uses vertex -9, but only 3 vertices are defined above it",
        ),
        (
            "normal_past",
            "`f 1//1 2//1 3//5`: the face uses normal 5, but only 1 normal is defined above it",
        ),
    ];
    for (name, message) in expect {
        let (code, stderr) = run_capped(&dir, &["check", &format!("{name}.ron")]);
        assert_eq!(code, 2, "{name}: {stderr}");
        assert!(stderr.contains(message), "{name}: {stderr}");
        let line = if name == "normal_past" { 5 } else { 4 };
        assert!(
            stderr.contains(&format!("{name}.obj` line {line}")),
            "{name}: {stderr}"
        );
    }
    // A zero texture-coordinate or normal index is named with its kind.
    let obj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nvn 0 0 1\nf 1//0 2//1 3//1\n";
    let e =
        caustic::compile::mesh::parse_obj(obj.as_bytes(), Path::new("n.obj")).expect_err("index 0");
    assert!(
        e.to_string()
            .contains("normal index 0, but OBJ indices start at 1 (negative ones count back from the last normal)"),
        "{e}"
    );
}

// ---- PLY -----------------------------------------------------------------------------------

/// A concave L-shaped hexagon (the notch must stay open) and a quad, with normals and uvs, as
/// OBJ text.
const L_SHAPE_OBJ: &str = "v 0 0 0\nv 2 0 0\nv 2 1 0\nv 1 1 0\nv 1 2 0\nv 0 2 0\n\
v 3 0 0\nv 4 0 0\nv 4 1 0\nv 3 1 0\n\
vt 0 0\nvt 1 0\nvt 1 0.5\nvt 0.5 0.5\nvt 0.5 1\nvt 0 1\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
vn 0 0 1\nvn 0 0.1 1\nvn 0.1 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\nvn 0 0 1\n\
f 1/1/1 2/2/2 3/3/3 4/4/4 5/5/5 6/6/6\nf 7/7/7 8/8/8 9/9/9 10/10/10\n";

/// The same mesh as PLY: `encoding` is `ascii`, `binary_little_endian` or `binary_big_endian`;
/// `extra` adds a colour per vertex and an `edge` element the reader must read past.
fn l_shape_ply(encoding: &str, extra: bool) -> Vec<u8> {
    let mut v: Vec<[f32; 8]> = Vec::new();
    let nums = |line: &str| -> Vec<f32> {
        line.split_whitespace()
            .skip(1)
            .map(|w| w.parse().expect("number"))
            .collect()
    };
    let lines: Vec<&str> = L_SHAPE_OBJ.lines().collect();
    let pos: Vec<Vec<f32>> = lines
        .iter()
        .filter(|l| l.starts_with("v "))
        .map(|l| nums(l))
        .collect();
    let uv: Vec<Vec<f32>> = lines
        .iter()
        .filter(|l| l.starts_with("vt "))
        .map(|l| nums(l))
        .collect();
    let nor: Vec<Vec<f32>> = lines
        .iter()
        .filter(|l| l.starts_with("vn "))
        .map(|l| nums(l))
        .collect();
    for i in 0..pos.len() {
        v.push([
            pos[i][0], pos[i][1], pos[i][2], nor[i][0], nor[i][1], nor[i][2], uv[i][0], uv[i][1],
        ]);
    }
    let faces: [&[u32]; 2] = [&[0, 1, 2, 3, 4, 5], &[6, 7, 8, 9]];
    let colour = if extra {
        "property uchar red\nproperty uchar green\nproperty uchar blue\n"
    } else {
        ""
    };
    let edges = if extra {
        "element edge 1\nproperty int vertex1\nproperty int vertex2\n"
    } else {
        ""
    };
    let mut out = format!(
        "ply\nformat {encoding} 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\n\
property float nx\nproperty float ny\nproperty float nz\nproperty float texture_u\nproperty float texture_v\n{colour}\
element face 2\nproperty list uchar uint vertex_indices\n{edges}end_header\n",
        v.len()
    )
    .into_bytes();
    let big = encoding == "binary_big_endian";
    let f32b = |x: f32| {
        if big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    let u32b = |x: u32| {
        if big {
            x.to_be_bytes()
        } else {
            x.to_le_bytes()
        }
    };
    for row in &v {
        if encoding == "ascii" {
            let words: Vec<String> = row.iter().map(f32::to_string).collect();
            out.extend(words.join(" ").bytes());
            out.extend(if extra { " 255 0 0\n" } else { "\n" }.bytes());
        } else {
            row.iter().for_each(|x| out.extend(f32b(*x)));
            if extra {
                out.extend([255, 0, 0]);
            }
        }
    }
    for f in faces {
        if encoding == "ascii" {
            let words: Vec<String> = f.iter().map(u32::to_string).collect();
            out.extend(format!("{} {}\n", f.len(), words.join(" ")).bytes());
        } else {
            out.push(f.len() as u8);
            f.iter().for_each(|i| out.extend(u32b(*i)));
        }
    }
    if extra {
        if encoding == "ascii" {
            out.extend(b"0 1\n");
        } else {
            out.extend(u32b(0));
            out.extend(u32b(1));
        }
    }
    out
}

/// Renders `Mesh(file: …)` in `dir` at 24×16 (a textured, smooth-shaded mesh under a point
/// light): the PNG's bytes and the run's stderr.
fn render_mesh(dir: &Path, file: &str) -> (Vec<u8>, String) {
    let scene = format!(
        "Scene(render: (width: 24, height: 16, samples_per_pixel: 2, integrator: Whitted),
           camera: Pinhole(eye: (2, 1, 5), look_at: (2, 1, 0), fov_y: 40),
           textures: {{\"checks\": Marble(base: (0.9, 0.2, 0.1), vein: (0.1, 0.2, 0.9), mapping: Uv, frequency: 3)}},
           materials: {{\"m\": (color: \"checks\")}},
           lights: [Point(position: (2, 1, 4), power: (40, 40, 40))],
           nodes: [Mesh(file: {file:?}, material: \"m\")])"
    );
    let name = format!("{file}.ron");
    std::fs::write(dir.join(&name), scene).expect("write scene");
    let png = format!("{file}.png");
    let (code, stderr) = run_capped(dir, &["render", &name, "-o", &png]);
    assert_eq!(code, 0, "{file}: {stderr}");
    (std::fs::read(dir.join(&png)).expect("png"), stderr)
}

#[test]
fn ply_meshes_in_each_encoding_render_as_their_obj_twin() {
    let tmp = tempfile::tempdir().expect("tmp");
    std::fs::write(tmp.path().join("l.obj"), L_SHAPE_OBJ).expect("write");
    let (obj, _) = render_mesh(tmp.path(), "l.obj");
    for enc in ["ascii", "binary_little_endian", "binary_big_endian"] {
        let file = format!("l_{enc}.ply");
        std::fs::write(tmp.path().join(&file), l_shape_ply(enc, false)).expect("write");
        let (ply, stderr) = render_mesh(tmp.path(), &file);
        assert!(
            ply == obj,
            "{enc}: the PLY renders other pixels than the OBJ"
        );
        assert!(!stderr.contains("warning"), "{enc}: {stderr}");
        // Colours and an unknown element: read past, the colours named as ignored.
        let file = format!("l_{enc}_extra.ply");
        std::fs::write(tmp.path().join(&file), l_shape_ply(enc, true)).expect("write");
        let (ply, stderr) = render_mesh(tmp.path(), &file);
        assert!(ply == obj, "{enc} with colours");
        assert!(
            stderr.contains(&format!(
                "{file}` has vertex colours, which caustic's meshes do not carry"
            )),
            "{enc}: {stderr}"
        );
    }
    // The notch of the L stays open: 4 triangles of area 3 and 2 of the quad.
    let m = caustic::compile::ply::parse_ply(&l_shape_ply("ascii", false), Path::new("l.ply"))
        .expect("parses");
    let area: f32 = m
        .triangles
        .iter()
        .map(|t| {
            let p = t.map(|c| m.positions[c.p as usize]);
            (p[1] - p[0]).cross(p[2] - p[0]).length() / 2.0
        })
        .sum();
    assert_eq!(m.triangles.len(), 6);
    assert!((area - 4.0).abs() < 1e-5, "{area}");
}

// ---- glTF ----------------------------------------------------------------------------------

/// Standard base64 (RFC 4648) for the test's data URIs.
fn base64(bytes: &[u8]) -> String {
    const A: &[u8; 64] = b"ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
    let mut out = String::new();
    for c in bytes.chunks(3) {
        let n = (u32::from(c[0]) << 16)
            | (u32::from(*c.get(1).unwrap_or(&0)) << 8)
            | u32::from(*c.get(2).unwrap_or(&0));
        for i in 0..4 {
            if i <= c.len() {
                out.push(A[(n >> (18 - 6 * i) & 63) as usize] as char);
            } else {
                out.push('=');
            }
        }
    }
    out
}

/// The binary buffer of the test room: a unit-half-size square (±1 in x and y, facing +z) and
/// a cube of side 1 centred on the origin (24 vertices, outward normals), each with its
/// indices. Returns (bytes, JSON of bufferViews and accessors).
fn room_buffer() -> (Vec<u8>, String) {
    let mut bin: Vec<u8> = Vec::new();
    let f = |bin: &mut Vec<u8>, v: &[[f32; 3]]| {
        v.iter().flatten().for_each(|x| bin.extend(x.to_le_bytes()))
    };
    // Square: BL, BR, TR, TL (as a Quad node's corners), two triangles 0 1 2, 0 2 3.
    let sq = [
        [-1.0, -1.0, 0.0],
        [1.0, -1.0, 0.0],
        [1.0, 1.0, 0.0],
        [-1.0, 1.0, 0.0],
    ];
    f(&mut bin, &sq);
    f(&mut bin, &[[0.0, 0.0, 1.0]; 4]);
    for i in [0u16, 1, 2, 0, 2, 3] {
        bin.extend(i.to_le_bytes());
    }
    let sq_end = bin.len();
    // Cube: per face four corners counter-clockwise from outside.
    let faces: [([f32; 3], [f32; 3], [f32; 3]); 6] = [
        ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([0.0, 0.0, -1.0], [-1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),
        ([1.0, 0.0, 0.0], [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),
        ([-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]),
        ([0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, -1.0]),
        ([0.0, -1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]),
    ];
    let (mut pos, mut nor) = (Vec::new(), Vec::new());
    for (n, u, v) in faces {
        for (a, b) in [(-0.5, -0.5), (0.5, -0.5), (0.5, 0.5), (-0.5, 0.5)] {
            pos.push([0, 1, 2].map(|k| n[k] * 0.5 + u[k] * a + v[k] * b));
            nor.push(n);
        }
    }
    let cube_start = bin.len();
    f(&mut bin, &pos);
    f(&mut bin, &nor);
    for face in 0..6u16 {
        for i in [0u16, 1, 2, 0, 2, 3] {
            bin.extend((face * 4 + i).to_le_bytes());
        }
    }
    let end = bin.len();
    let views = format!(
        r#""bufferViews": [
  {{"buffer": 0, "byteOffset": 0, "byteLength": 48}},
  {{"buffer": 0, "byteOffset": 48, "byteLength": 48}},
  {{"buffer": 0, "byteOffset": 96, "byteLength": {}}},
  {{"buffer": 0, "byteOffset": {cube_start}, "byteLength": 288}},
  {{"buffer": 0, "byteOffset": {}, "byteLength": 288}},
  {{"buffer": 0, "byteOffset": {}, "byteLength": {}}}
],
"accessors": [
  {{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1, 1, 0]}},
  {{"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"}},
  {{"bufferView": 2, "componentType": 5123, "count": 6, "type": "SCALAR"}},
  {{"bufferView": 3, "componentType": 5126, "count": 24, "type": "VEC3", "min": [-0.5, -0.5, -0.5], "max": [0.5, 0.5, 0.5]}},
  {{"bufferView": 4, "componentType": 5126, "count": 24, "type": "VEC3"}},
  {{"bufferView": 5, "componentType": 5123, "count": 36, "type": "SCALAR"}}
]"#,
        sq_end - 96,
        cube_start + 288,
        cube_start + 576,
        end - cube_start - 576,
    );
    (bin, views)
}

/// A room in glTF: a floor, a glass cube, a metal cube, an emissive panel (the floor's mesh
/// again, scaled), a point and a spot light in candela, and a camera. `buffer` is the JSON of
/// the one buffer (`uri` or GLB chunk); `extra` is spliced into the root object.
fn room_json(buffer: &str, views: &str, extra: &str) -> String {
    let h = std::f32::consts::FRAC_1_SQRT_2;
    format!(
        r#"{{
"asset": {{"version": "2.0", "generator": "caustic tests"}},
"extensionsUsed": ["KHR_lights_punctual", "KHR_materials_emissive_strength", "KHR_materials_transmission", "KHR_materials_ior", "KHR_materials_volume", "EXT_unknown_thing"],
{extra}
"scene": 0,
"scenes": [{{"nodes": [0, 1, 2, 3, 4, 5, 6]}}],
"nodes": [
  {{"name": "Floor", "mesh": 0, "rotation": [-{h}, 0, 0, {h}], "scale": [1.5, 1.5, 1]}},
  {{"name": "Glass", "mesh": 1, "translation": [-0.4, 0.3, 0], "scale": [0.6, 0.6, 0.6]}},
  {{"name": "Shelf", "translation": [0.45, 0.25, -0.2], "children": [7]}},
  {{"name": "Panel", "mesh": 3, "rotation": [{h}, 0, 0, {h}], "scale": [0.3, 0.3, 1], "translation": [0, 1.6, 0]}},
  {{"name": "Bulb", "translation": [0.5, 1.2, 0.8], "extensions": {{"KHR_lights_punctual": {{"light": 0}}}}}},
  {{"name": "Spot", "translation": [-0.6, 1.4, 0.6], "rotation": [-{h}, 0, 0, {h}], "extensions": {{"KHR_lights_punctual": {{"light": 1}}}}}},
  {{"name": "CameraNode", "camera": 0, "translation": [0, 0.8, 3.2]}},
  {{"name": "Ball", "mesh": 2, "rotation": [0, 0.38268343, 0, 0.9238795], "scale": [0.5, 0.5, 0.5]}}
],
"cameras": [{{"name": "Camera", "type": "perspective", "perspective": {{"yfov": 0.7, "znear": 0.05}}}}],
"extensions": {{"KHR_lights_punctual": {{"lights": [
  {{"name": "bulb", "type": "point", "color": [1, 0.75, 0.5], "intensity": 1366}},
  {{"name": "spot", "type": "spot", "intensity": 2049, "spot": {{"innerConeAngle": 0.34906584, "outerConeAngle": 0.6981317}}}}
]}}}},
"materials": [
  {{"name": "Floor", "pbrMetallicRoughness": {{"baseColorFactor": [0.6, 0.5, 0.4, 1], "metallicFactor": 0, "roughnessFactor": 1}}}},
  {{"name": "Glass", "pbrMetallicRoughness": {{"baseColorFactor": [1, 1, 1, 1], "metallicFactor": 0, "roughnessFactor": 0}},
    "extensions": {{"KHR_materials_transmission": {{"transmissionFactor": 1}}, "KHR_materials_ior": {{"ior": 1.33}},
      "KHR_materials_volume": {{"thicknessFactor": 0.6, "attenuationColor": [0.5, 0.8, 0.9], "attenuationDistance": 0.3}}}}}},
  {{"name": "Copper", "pbrMetallicRoughness": {{"baseColorFactor": [0.9, 0.6, 0.4, 1], "metallicFactor": 1, "roughnessFactor": 0.3}}}},
  {{"name": "Light", "emissiveFactor": [1, 0.5, 0.25], "pbrMetallicRoughness": {{"baseColorFactor": [0, 0, 0, 1]}},
    "extensions": {{"KHR_materials_emissive_strength": {{"emissiveStrength": 8}}}}}}
],
"meshes": [
  {{"name": "floor", "primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1}}, "indices": 2, "material": 0}}]}},
  {{"name": "glass", "primitives": [{{"attributes": {{"POSITION": 3, "NORMAL": 4}}, "indices": 5, "material": 1}}]}},
  {{"name": "metal", "primitives": [{{"attributes": {{"POSITION": 3, "NORMAL": 4}}, "indices": 5, "material": 2}}]}},
  {{"name": "panel", "primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1}}, "indices": 2, "material": 3}}]}}
],
"buffers": [{buffer}],
{views}
}}"#
    )
}

/// The room as GLB: a 12-byte header, the JSON chunk (padded with spaces) and the BIN chunk
/// (padded with zeros).
fn room_glb(extra: &str) -> Vec<u8> {
    let (mut bin, views) = room_buffer();
    let mut json =
        room_json(&format!("{{\"byteLength\": {}}}", bin.len()), &views, extra).into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    while !bin.len().is_multiple_of(4) {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = b"glTF".to_vec();
    out.extend(2u32.to_le_bytes());
    out.extend((total as u32).to_le_bytes());
    out.extend((json.len() as u32).to_le_bytes());
    out.extend(b"JSON");
    out.extend(json);
    out.extend((bin.len() as u32).to_le_bytes());
    out.extend(b"BIN\0");
    out.extend(bin);
    out
}

/// The room as `.gltf` with its buffer embedded as a data URI.
fn room_gltf_embedded() -> String {
    let (bin, views) = room_buffer();
    room_json(
        &format!(
            "{{\"byteLength\": {}, \"uri\": \"data:application/octet-stream;base64,{}\"}}",
            bin.len(),
            base64(&bin)
        ),
        &views,
        "",
    )
}

/// The scene around a glTF import, or its hand-written twin (`twin`): the same room in RON,
/// with the mapping of docs/import.md written out by hand.
fn room_scene(file: &str, twin: bool, spp: u32, size: (u32, u32), seed: u32) -> String {
    let render = format!(
        "render: (width: {}, height: {}, samples_per_pixel: {spp}, integrator: Path, seed: {seed}, max_depth: 8)",
        size.0, size.1
    );
    if !twin {
        return format!(
            "Scene({render},
               camera: Pinhole(eye: (0, 5, 5), look_at: (0, 0, 0), fov_y: 30),
               materials: {{}},
               nodes: [Gltf(file: {file:?}, camera: \"Camera\")])"
        );
    }
    // 1366 cd / 683 = 2 W/sr: power 4π·2·(1, 0.75, 0.5) W; the spot 2049 cd = 3 W/sr.
    let p = 8.0 * std::f64::consts::PI;
    format!(
        "Scene({render},
           camera: Pinhole(eye: (0, 0.8, 3.2), look_at: (0, 0.8, 2.2), fov_y: {fov}),
           materials: {{
             \"floor\": (color: (0.6, 0.5, 0.4)),
             \"glass\": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.33,
                         absorption: (color: (0.5, 0.8, 0.9), depth: 0.3)),
             \"copper\": (color: (0.9, 0.6, 0.4), diffuse: 0, reflect: 1, roughness: 0.3,
                          conductor: (f0: (0.9, 0.6, 0.4))),
           }},
           lights: [
             Point(position: (0.5, 1.2, 0.8), power: ({p}, {}, {})),
             Spot(position: (-0.6, 1.4, 0.6), direction: (0, -1, 0), intensity: (3, 3, 3),
                  inner_angle: 20, outer_angle: 40),
           ],
           nodes: [
             Quad(size: (3, 3), material: \"floor\", transform: [RotateX(-90)]),
             Cube(size: 0.6, material: \"glass\", transform: [Translate(-0.4, 0.3, 0)]),
             Group(transform: [Translate(0.45, 0.25, -0.2)], children: [
               Cube(size: 0.5, material: \"copper\", transform: [RotateY(45)]),
             ]),
             Quad(size: (0.6, 0.6), emission: (radiance: (8, 4, 2)),
                  transform: [RotateX(90), Translate(0, 1.6, 0)]),
           ])",
        p * 0.75,
        p * 0.5,
        fov = 0.7f64.to_degrees(),
    )
}

/// Compiles and renders a scene file: the render scene's materials, and the pixel estimates.
fn render_scene_file(
    path: &Path,
) -> (
    Vec<caustic::render_scene::SurfaceMaterial>,
    caustic::render::golden::PixelEstimates,
    Vec<caustic::scene::Diagnostic>,
) {
    let prepared = caustic::pipeline::prepare(path, &caustic::pipeline::SceneOverrides::default())
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let out = caustic::render::render(
        &prepared.render_scene,
        &caustic::render::RenderOptions::default(),
    )
    .expect("renders");
    (
        prepared.render_scene.materials.clone(),
        caustic::render::golden::PixelEstimates::from_sums(&out.sums),
        prepared.warnings.clone(),
    )
}

#[test]
fn a_gltf_room_renders_as_its_hand_written_ron_twin() {
    let tmp = tempfile::tempdir().expect("tmp");
    std::fs::write(tmp.path().join("room.glb"), room_glb("")).expect("write");
    std::fs::write(
        tmp.path().join("import.ron"),
        room_scene("room.glb", false, 48, (40, 30), 1),
    )
    .expect("write");
    std::fs::write(
        tmp.path().join("twin.ron"),
        room_scene("", true, 48, (40, 30), 2),
    )
    .expect("write");
    let (imported, est, warnings) = render_scene_file(&tmp.path().join("import.ron"));
    let (twin, twin_est, _) = render_scene_file(&tmp.path().join("twin.ron"));
    // The compiled materials are the twin's, value for value.
    for m in &twin {
        assert!(
            imported.contains(m),
            "a hand-written material has no equal in the import"
        );
    }
    let v = caustic::render::golden::BlockTest::default()
        .compare(&twin_est, &est)
        .expect("same size");
    eprintln!(
        "glTF vs RON twin: max |z| {:.2} (limit {:.2}), χ² {:.1?}, image z {:.2?}",
        v.max_abs_z(),
        v.z_limit,
        v.chi2,
        v.image_z
    );
    assert!(!v.changed(), "the import differs from its twin");
    // Said once per material: the floor is a rough non-metal (its specular layer left out),
    // the panel an emitter; the unknown optional extension is named.
    let text: Vec<String> = warnings.iter().map(|d| d.message.clone()).collect();
    let text = text.join("\n");
    assert_eq!(
        text.matches("material `Floor` (/materials/0) maps approximately")
            .count(),
        1,
        "{text}"
    );
    assert!(
        text.contains("material `Light` (/materials/3) maps approximately: an emitter"),
        "{text}"
    );
    assert!(
        text.contains("uses the optional extension `EXT_unknown_thing`, which caustic ignores"),
        "{text}"
    );
}

#[test]
fn gltf_with_embedded_or_external_buffers_and_glb_compile_alike() {
    let tmp = tempfile::tempdir().expect("tmp");
    let (bin, views) = room_buffer();
    std::fs::write(tmp.path().join("room.glb"), room_glb("")).expect("write");
    std::fs::write(tmp.path().join("embedded.gltf"), room_gltf_embedded()).expect("write");
    std::fs::write(tmp.path().join("room data.bin"), &bin).expect("write");
    std::fs::write(
        tmp.path().join("external.gltf"),
        room_json(
            &format!(
                "{{\"byteLength\": {}, \"uri\": \"room%20data.bin\"}}",
                bin.len()
            ),
            &views,
            "",
        ),
    )
    .expect("write");
    let mut images = Vec::new();
    for file in ["room.glb", "embedded.gltf", "external.gltf"] {
        let name = format!("{file}.ron");
        std::fs::write(
            tmp.path().join(&name),
            room_scene(file, false, 2, (16, 12), 1),
        )
        .expect("write");
        let (_, est, _) = render_scene_file(&tmp.path().join(&name));
        images.push(format!("{:?}", est.mean));
    }
    assert!(
        images[0] == images[1] && images[0] == images[2],
        "the three containers render alike"
    );
}

#[test]
fn gltf_units_and_mapping_by_hand() {
    use caustic::scene::schema::{CameraSpec, LightSpec};
    let glb = room_glb("");
    let path = Path::new("room.glb");
    let import = caustic::compile::gltf::import_gltf(
        &glb,
        path,
        glam::DAffine3::IDENTITY,
        &Default::default(),
    )
    .expect("imports");
    // KHR_lights_punctual: candela / 683 = W/sr; a point light's power is 4π I.
    let LightSpec::Point {
        position, power, ..
    } = &import.lights[0]
    else {
        panic!("a point light: {:?}", import.lights)
    };
    assert_eq!(*position, [0.5, 1.2, 0.8]);
    let i = 1366.0 / 683.0 * 4.0 * std::f32::consts::PI;
    for (got, want) in power.iter().zip([i, i * 0.75, i * 0.5]) {
        assert!((got / want - 1.0).abs() < 1e-6, "{power:?}");
    }
    let LightSpec::Spot {
        direction,
        intensity,
        inner_angle,
        outer_angle,
        ..
    } = &import.lights[1]
    else {
        panic!("a spot light")
    };
    assert!(
        (glam::Vec3::from(*direction) - glam::Vec3::NEG_Y).length() < 1e-6,
        "{direction:?}"
    );
    assert!(
        intensity.iter().all(|c| (c - 3.0).abs() < 1e-6),
        "{intensity:?}"
    );
    assert!((inner_angle - 20.0).abs() < 1e-4 && (outer_angle - 40.0).abs() < 1e-4);
    // A camera is found by its name or its node's.
    let (names, cam) = &import.cameras[0];
    assert_eq!(names, &["Camera".to_string(), "CameraNode".to_string()]);
    let CameraSpec::Pinhole {
        eye,
        look_at,
        fov_y,
        ..
    } = cam
    else {
        panic!("a pinhole")
    };
    assert_eq!((*eye, *look_at), ([0.0, 0.8, 3.2], [0.0, 0.8, 2.2]));
    assert!((fov_y - 40.107_04).abs() < 1e-3, "{fov_y}");
}

#[test]
fn gltf_errors_name_the_file_and_the_json_pointer() {
    let tmp = tempfile::tempdir().expect("tmp");
    let check = |file: &str, bytes: &[u8]| {
        std::fs::write(tmp.path().join(file), bytes).expect("write");
        std::fs::write(
            tmp.path().join("s.ron"),
            room_scene(file, false, 1, (8, 8), 1),
        )
        .expect("write");
        run_capped(tmp.path(), &["check", "s.ron"])
    };
    // A required extension caustic does not implement.
    let (code, stderr) = check(
        "draco.glb",
        &room_glb(
            r#""extensionsRequired": ["KHR_draco_mesh_compression", "EXT_meshopt_compression"],"#,
        ),
    );
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("draco.glb` /extensionsRequired: the file requires `KHR_draco_mesh_compression` and `EXT_meshopt_compression` which caustic does not implement"),
        "{stderr}"
    );
    // An accessor index past the file's accessors, at its JSON pointer.
    let bad = room_gltf_embedded().replace(
        "\"NORMAL\": 4}, \"indices\": 5, \"material\": 2",
        "\"NORMAL\": 9}, \"indices\": 5, \"material\": 2",
    );
    let (code, stderr) = check("bad.gltf", bad.as_bytes());
    assert_eq!(code, 2, "{stderr}");
    assert!(
        stderr.contains("bad.gltf` /meshes/2/primitives/0/attributes/NORMAL: invalid glTF"),
        "{stderr}"
    );
    // A Mesh node given a glTF file is told to use a Gltf node; a camera name that is not there.
    std::fs::write(tmp.path().join("room.glb"), room_glb("")).expect("write");
    std::fs::write(
        tmp.path().join("m.ron"),
        "Scene(camera: Pinhole(eye: (0, 0, 3), look_at: (0, 0, 0), fov_y: 40), materials: {\"m\": ()},
               nodes: [Mesh(file: \"room.glb\", material: \"m\"), Gltf(file: \"room.glb\", camera: \"Camera.001\", materials: {\"Glas\": \"m\"})])",
    )
    .expect("write");
    let (code, stderr) = run_capped(tmp.path(), &["check", "m.ron"]);
    assert_eq!(code, 2, "{stderr}");
    assert!(stderr.contains("room.glb`: this is a binary glTF file (GLB); a `Mesh` node reads OBJ and PLY files; a glTF file is a scene: import it with a `Gltf(file: …)` node"), "{stderr}");
    assert!(
        stderr.contains(
            "has no perspective camera `Camera.001`; its cameras: `Camera`, `CameraNode`"
        ),
        "{stderr}"
    );
    assert!(stderr.contains("has no material `Glas`"), "{stderr}");
    assert!(stderr.contains("did you mean `Glass`?"), "{stderr}");
}

#[test]
fn a_blender_exported_room_renders_as_its_hand_written_twin() {
    let dir = root().join("tests/data/gltf");
    let tmp = tempfile::tempdir().expect("tmp");
    let twin = std::fs::read_to_string(dir.join("room_twin.ron")).expect("twin");
    for f in ["room.glb", "room.gltf", "glass.obj", "water.obj"] {
        std::fs::copy(dir.join(f), tmp.path().join(f)).expect("copy");
    }
    std::fs::write(tmp.path().join("twin.ron"), &twin).expect("write");
    let import = twin
        .replace("seed: 2", "seed: 1")
        .split("camera: Pinhole")
        .next()
        .map(|head| {
            format!(
                "{head}camera: Pinhole(eye: (0, 9, 9), look_at: (0, 0, 0), fov_y: 30),
                 materials: {{}}, nodes: [Gltf(file: \"room.glb\", camera: \"Camera\")])"
            )
        })
        .expect("head");
    std::fs::write(tmp.path().join("import.ron"), import).expect("write");
    let (imported, est, warnings) = render_scene_file(&tmp.path().join("import.ron"));
    let (twin, twin_est, _) = render_scene_file(&tmp.path().join("twin.ron"));
    for m in &twin {
        assert!(
            imported.contains(m),
            "a hand-written material has no equal in the import"
        );
    }
    let v = caustic::render::golden::BlockTest::default()
        .compare(&twin_est, &est)
        .expect("same size");
    eprintln!(
        "Blender room vs RON twin: max |z| {:.2} (limit {:.2}), χ² {:.1?}, image z {:.2?}",
        v.max_abs_z(),
        v.z_limit,
        v.chi2,
        v.image_z
    );
    assert!(!v.changed(), "the Blender export differs from its twin");
    let text: Vec<&str> = warnings.iter().map(|d| d.message.as_str()).collect();
    assert!(
        !text.iter().any(|t| t.contains("ignores")),
        "Blender's export uses only extensions caustic maps: {text:?}"
    );
}

#[test]
fn obj_mtl_materials_compile_as_their_hand_written_twins_and_the_scene_wins_by_name() {
    let tmp = tempfile::tempdir().expect("tmp");
    std::fs::write(
        tmp.path().join("a.mtl"),
        "newmtl red\nKd 0.8 0.1 0.1\nKs 0.1 0.1 0.1\nNs 50\n\
         newmtl glass\nKd 1 1 1\nNi 1.33\nd 0.25\n\
         newmtl wood\nKd 0.2 0.2 0.2\n",
    )
    .expect("write");
    std::fs::write(
        tmp.path().join("a.obj"),
        "mtllib a.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
         usemtl red\nf 1 2 3\nusemtl glass\nf 1 3 4\nusemtl wood\nf 2 3 4\n",
    )
    .expect("write");
    let scene = |materials: &str, nodes: &str| {
        format!(
            "Scene(camera: Pinhole(eye: (0.5, 0.5, 3), look_at: (0.5, 0.5, 0), fov_y: 40),
               lights: [Point(position: (0, 1, 3), power: (40, 40, 40))],
               materials: {{ {materials} }}, nodes: [{nodes}])"
        )
    };
    std::fs::write(
        tmp.path().join("import.ron"),
        scene(
            "\"oak\": (color: (0.5, 0.3, 0.1))",
            "Mesh(file: \"a.obj\", mtl: true, materials: {\"wood\": \"oak\"})",
        ),
    )
    .expect("write");
    std::fs::write(
        tmp.path().join("twin.ron"),
        scene(
            "\"oak\": (color: (0.5, 0.3, 0.1)),
             \"red\": (color: (0.8, 0.1, 0.1), specular: (0.1, 0.1, 0.1), shininess: 50),
             \"glass\": (color: (1, 1, 1), diffuse: 0.25, transmit: 0.75, ior: 1.33)",
            "Mesh(file: \"a.obj\", materials: {\"red\": \"red\", \"glass\": \"glass\", \"wood\": \"oak\"})",
        ),
    )
    .expect("write");
    let overrides = caustic::pipeline::SceneOverrides::default();
    let import = caustic::pipeline::prepare(&tmp.path().join("import.ron"), &overrides)
        .unwrap_or_else(|e| panic!("{e}"));
    let twin = caustic::pipeline::prepare(&tmp.path().join("twin.ron"), &overrides)
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(import.render_scene.materials.len(), 3);
    for m in &twin.render_scene.materials {
        assert!(
            import.render_scene.materials.contains(m),
            "a twin material is missing"
        );
    }
    // `d` as a dielectric is said once, for `glass`; `wood`'s Kd never compiles (the scene's oak).
    let notes: Vec<&str> = import.warnings.iter().map(|d| d.message.as_str()).collect();
    assert_eq!(notes.len(), 1, "{notes:?}");
    assert!(notes[0].starts_with("material `glass` of"), "{notes:?}");
}

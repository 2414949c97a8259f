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

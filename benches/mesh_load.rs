//! Loading a one-million-triangle mesh from binary PLY, from GLB and from OBJ (issue 45's
//! "within 1.5× the time of the same mesh from OBJ"): the time to read and parse the file into
//! caustic's mesh, and the process's peak resident memory, each format in its own process.
//!
//! Run: `cargo bench --bench mesh_load` (writes the three files of a 708 × 708 grid with normals,
//! 1,000,000 triangles after dropping 28, to a temporary folder, then times each format in a
//! child process: the median of `--reps=5` loads, and VmHWM from /proc/self/status).
//! One format: `cargo bench --bench mesh_load -- --format=ply --dir=DIR`.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use caustic::compile::mesh_file::{MAX_MESH_FILE_BYTES, read_mesh_file};

/// Grid side in vertices: (N − 1)² · 2 triangles ≈ 1 M.
const N: usize = 708;
/// Triangles kept: exactly one million.
const TRIANGLES: usize = 1_000_000;

/// The benchmark mesh: positions, normals, triangles.
struct Grid {
    p: Vec<[f32; 3]>,
    n: Vec<[f32; 3]>,
    t: Vec<[u32; 3]>,
}

fn grid() -> Grid {
    let mut p = Vec::with_capacity(N * N);
    let mut n = Vec::with_capacity(N * N);
    for j in 0..N {
        for i in 0..N {
            let (x, y) = (i as f32 / N as f32, j as f32 / N as f32);
            let z = 0.05 * (6.0 * x).sin() * (5.0 * y).cos();
            p.push([x, y, z]);
            n.push([0.0, 0.0, 1.0]);
        }
    }
    let mut t = Vec::with_capacity(TRIANGLES);
    'grid: for j in 0..N - 1 {
        for i in 0..N - 1 {
            let a = (j * N + i) as u32;
            for tri in [
                [a, a + 1, a + 1 + N as u32],
                [a, a + 1 + N as u32, a + N as u32],
            ] {
                if t.len() == TRIANGLES {
                    break 'grid;
                }
                t.push(tri);
            }
        }
    }
    Grid { p, n, t }
}

fn write_files(dir: &Path) {
    let Grid { p, n, t } = grid();
    let mut obj = String::with_capacity(80 * p.len());
    for v in &p {
        obj.push_str(&format!("v {} {} {}\n", v[0], v[1], v[2]));
    }
    for v in &n {
        obj.push_str(&format!("vn {} {} {}\n", v[0], v[1], v[2]));
    }
    for f in &t {
        let [a, b, c] = f.map(|i| i + 1);
        obj.push_str(&format!("f {a}//{a} {b}//{b} {c}//{c}\n"));
    }
    std::fs::write(dir.join("grid.obj"), obj).expect("write obj");

    let mut ply = format!(
        "ply\nformat binary_little_endian 1.0\nelement vertex {}\nproperty float x\nproperty float y\nproperty float z\nproperty float nx\nproperty float ny\nproperty float nz\nelement face {}\nproperty list uchar int vertex_indices\nend_header\n",
        p.len(),
        t.len()
    )
    .into_bytes();
    for (v, m) in p.iter().zip(&n) {
        v.iter().chain(m).for_each(|x| ply.extend(x.to_le_bytes()));
    }
    for f in &t {
        ply.push(3);
        f.iter().for_each(|i| ply.extend((*i as i32).to_le_bytes()));
    }
    std::fs::write(dir.join("grid.ply"), ply).expect("write ply");

    let mut bin = Vec::new();
    p.iter().flatten().for_each(|x| bin.extend(x.to_le_bytes()));
    n.iter().flatten().for_each(|x| bin.extend(x.to_le_bytes()));
    t.iter().flatten().for_each(|i| bin.extend(i.to_le_bytes()));
    let (pl, il) = (12 * p.len(), 12 * t.len());
    let mut json = format!(
        r#"{{"asset": {{"version": "2.0"}}, "scene": 0, "scenes": [{{"nodes": [0]}}], "nodes": [{{"mesh": 0}}],
"meshes": [{{"primitives": [{{"attributes": {{"POSITION": 0, "NORMAL": 1}}, "indices": 2}}]}}],
"buffers": [{{"byteLength": {}}}],
"bufferViews": [{{"buffer": 0, "byteOffset": 0, "byteLength": {pl}}}, {{"buffer": 0, "byteOffset": {pl}, "byteLength": {pl}}}, {{"buffer": 0, "byteOffset": {}, "byteLength": {il}}}],
"accessors": [{{"bufferView": 0, "componentType": 5126, "count": {}, "type": "VEC3", "min": [0, 0, -1], "max": [1, 1, 1]}},
  {{"bufferView": 1, "componentType": 5126, "count": {}, "type": "VEC3"}},
  {{"bufferView": 2, "componentType": 5125, "count": {}, "type": "SCALAR"}}]}}"#,
        bin.len(),
        2 * pl,
        p.len(),
        p.len(),
        3 * t.len()
    )
    .into_bytes();
    while !json.len().is_multiple_of(4) {
        json.push(b' ');
    }
    let mut glb = b"glTF".to_vec();
    glb.extend(2u32.to_le_bytes());
    glb.extend(((12 + 8 + json.len() + 8 + bin.len()) as u32).to_le_bytes());
    glb.extend((json.len() as u32).to_le_bytes());
    glb.extend(b"JSON");
    glb.extend(json);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(b"BIN\0");
    glb.extend(bin);
    std::fs::write(dir.join("grid.glb"), glb).expect("write glb");
}

/// Reads and parses `file` as its format: triangles loaded.
fn load(file: &Path) -> usize {
    let (_, bytes) = read_mesh_file(file, MAX_MESH_FILE_BYTES).expect("reads");
    match file.extension().and_then(|e| e.to_str()) {
        Some("obj") => caustic::compile::mesh::parse_obj(&bytes, file)
            .expect("obj")
            .triangles
            .len(),
        Some("ply") => caustic::compile::ply::parse_ply(&bytes, file)
            .expect("ply")
            .triangles
            .len(),
        _ => caustic::compile::gltf::import_gltf(
            &bytes,
            file,
            glam::DAffine3::IDENTITY,
            &BTreeMap::new(),
        )
        .expect("glb")
        .meshes
        .iter()
        .map(|(_, m)| m.triangles.len())
        .sum(),
    }
}

fn peak_rss_mib() -> f64 {
    let status = std::fs::read_to_string("/proc/self/status").unwrap_or_default();
    status
        .lines()
        .find_map(|l| l.strip_prefix("VmHWM:"))
        .and_then(|v| v.trim().trim_end_matches("kB").trim().parse::<f64>().ok())
        .map_or(f64::NAN, |kb| kb / 1024.0)
}

fn arg(name: &str) -> Option<String> {
    std::env::args().find_map(|a| a.strip_prefix(&format!("--{name}=")).map(str::to_string))
}

fn main() {
    let reps: usize = arg("reps").and_then(|r| r.parse().ok()).unwrap_or(5);
    if let (Some(format), Some(dir)) = (arg("format"), arg("dir")) {
        let file = PathBuf::from(dir).join(format!("grid.{format}"));
        let mut times = Vec::new();
        let mut tris = 0;
        for _ in 0..reps {
            let t0 = Instant::now();
            tris = load(&file);
            times.push(t0.elapsed().as_secs_f64());
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{format} {tris} {:.4} {:.1}",
            times[reps / 2],
            peak_rss_mib()
        );
        return;
    }
    let dir = tempfile::tempdir().expect("tmp");
    write_files(dir.path());
    let me = std::env::current_exe().expect("exe");
    let mut obj_time = f64::NAN;
    println!("format  triangles  file MiB  load s (median of {reps})  ×OBJ  peak RSS MiB");
    for format in ["obj", "ply", "glb"] {
        let out = Command::new(&me)
            .arg(format!("--format={format}"))
            .arg(format!("--dir={}", dir.path().display()))
            .arg(format!("--reps={reps}"))
            .output()
            .expect("child runs");
        let line = String::from_utf8_lossy(&out.stdout);
        let words: Vec<&str> = line.split_whitespace().collect();
        let [_, tris, secs, rss] = words[..] else {
            panic!("{format}: {line} {}", String::from_utf8_lossy(&out.stderr));
        };
        let secs: f64 = secs.parse().unwrap_or(f64::NAN);
        if format == "obj" {
            obj_time = secs;
        }
        let size = std::fs::metadata(dir.path().join(format!("grid.{format}")))
            .map_or(f64::NAN, |m| m.len() as f64 / (1 << 20) as f64);
        println!(
            "{format:6}  {tris:>9}  {size:8.1}  {secs:>22.3}  {:4.2}  {rss:>12}",
            secs / obj_time
        );
    }
}

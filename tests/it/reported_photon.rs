//! The kinds of issue 29 (photon mapping, and OBJ line endings) that users of other renderers
//! reported and caustic got wrong, each turned into a test of the right result. Small inputs
//! live in `tests/reported/<case>/`.

use std::path::{Path, PathBuf};

use caustic::compile::mesh::{ObjMesh, parse_obj};
use caustic::pipeline::SceneOverrides;
use caustic::render::RenderOptions;

use crate::common::{caustic, render_file, root};

/// A folder of `tests/reported/`.
fn case(name: &str) -> PathBuf {
    root().join("tests/reported").join(name)
}

// ---- OBJ files with CR-only line endings ------------------------------------------------------

/// An OBJ with a comment, a group, a `usemtl`, a quad and a triangle, with LF line endings.
const OBJ_LF: &str = "# two faces\no Part\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\n\
vt 0 0\nvt 1 0\nvt 1 1\nvn 0 0 1\nusemtl left\nf 1/1/1 2/2/1 3/3/1 4/1/1\ng other\nf 2 5 3\n";

fn mesh_of(text: &str) -> ObjMesh {
    parse_obj(text.as_bytes(), Path::new("m.obj")).unwrap_or_else(|e| panic!("{e}"))
}

fn assert_same_mesh(a: &ObjMesh, b: &ObjMesh, what: &str) {
    assert_eq!(a.positions, b.positions, "{what}: positions");
    assert_eq!(a.normals, b.normals, "{what}: normals");
    assert_eq!(a.uvs, b.uvs, "{what}: uvs");
    assert_eq!(a.triangles, b.triangles, "{what}: triangles");
    assert_eq!(a.names, b.names, "{what}: names");
    assert_eq!(a.triangle_names, b.triangle_names, "{what}: triangle names");
}

#[test]
fn obj_files_with_cr_only_line_endings_read_as_the_lf_file() {
    let lf = mesh_of(OBJ_LF);
    assert_eq!(lf.triangles.len(), 3, "a quad and a triangle");
    assert_eq!(lf.names, ["Part", "left", "other"]);
    for (name, ending) in [("CRLF", "\r\n"), ("CR", "\r")] {
        let text = OBJ_LF.replace('\n', ending);
        assert_same_mesh(&mesh_of(&text), &lf, name);
    }
    // Errors still name the line an editor shows (line 4 is the bad vertex).
    let bad = "# c\rv 0 0 0\rv 1 0 0\rv 1 x 0\rf 1 2 3\r";
    let e = parse_obj(bad.as_bytes(), Path::new("bad.obj")).expect_err("a bad vertex");
    assert!(e.contains("line 4: `v 1 x 0`"), "{e}");

    // The reported file, rendered: the same image as its LF twin (it was "contains no faces").
    let dir = case("obj-cr-line-endings");
    let tmp = tempfile::tempdir().expect("tmp");
    let scene = dir.join("scene.ron");
    let render = |obj: &str| {
        let out = tmp.path().join(format!("{obj}.png"));
        let o = caustic(&[
            "render",
            scene.to_str().expect("utf-8"),
            "--set",
            &format!("nodes[0].Mesh.file={obj}"),
            "--quiet",
            "-o",
            out.to_str().expect("utf-8"),
        ]);
        assert!(
            o.status.success(),
            "{obj}: {}",
            String::from_utf8_lossy(&o.stderr)
        );
        std::fs::read(out).expect("image")
    };
    assert!(
        !std::fs::read(dir.join("cr.obj"))
            .expect("cr.obj")
            .contains(&b'\n'),
        "the input has CR-only line endings"
    );
    assert_eq!(render("cr.obj"), render("lf.obj"));
}

// ---- The largest search radius only caps searches ----------------------------------------------

/// `path` rendered through the library with `overrides`; the image's mean over channels.
fn mean_of(path: &Path, overrides: &SceneOverrides) -> f64 {
    let (film, _) = render_file(path, overrides, &RenderOptions::default());
    let m = film.mean();
    f64::from(m.x + m.y + m.z) / 3.0
}

#[test]
fn a_generous_largest_radius_does_not_change_the_estimate() {
    // A 1 mm integrating sphere (albedo 0.8, point light at its centre): L = 0.8 · 5 / π =
    // 1.2732 everywhere. Its 50-photon discs are ~2e-5 wide, so no largest radius from 1 cm up
    // cuts a search; the answer must not move with it (it was 0.255 at 1, from a disc raised to
    // 1e-3 of the largest radius).
    let scene = case("estimate-radius-floor").join("small_origin.ron");
    let exact = 0.8 * 5.0 / std::f64::consts::PI;
    for r in [0.01f32, 1.0, 100.0] {
        let overrides = SceneOverrides {
            sets: vec![format!("photons.max_radius={r:?}")],
            ..SceneOverrides::default()
        };
        let m = mean_of(&scene, &overrides);
        assert!(
            (m / exact - 1.0).abs() < 0.03,
            "max radius {r}: mean {m}, exact {exact}"
        );
    }
}

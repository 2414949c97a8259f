//! Primitives as compiled from scene files: transforms baked correctly (non-uniform scale of a
//! sphere, rotated cubes, mirrored transforms keep outward normals), hits at the right distance.

use crate::common;

use std::path::Path;

use caustic::compile::compile;
use caustic::geometry::Ray;
use caustic::render_scene::RenderScene;
use caustic::scene::SourceFile;
use glam::Vec3;

fn scene(nodes: &str) -> RenderScene {
    common::scene_from_text(&format!(
        "Scene(camera: Pinhole(eye: (0, 0, 10), look_at: (0, 0, 0), fov_y: 40), \
         materials: {{ \"m\": () }}, lights: [Point(position: (0, 5, 5), power: (10, 10, 10))], nodes: [{nodes}])"
    ))
}

fn hit(s: &RenderScene, o: Vec3, d: Vec3) -> Option<(f32, Vec3)> {
    let ray = Ray::new(o, d);
    let h = s.geometry.intersect(&ray)?;
    Some((h.t, s.geometry.surface(&ray, &h).ng))
}

fn close(a: f32, b: f32) -> bool {
    (a - b).abs() < 1e-5
}

#[test]
fn non_uniformly_scaled_sphere_is_an_exact_ellipsoid() {
    let s = scene("Sphere(material: \"m\", transform: [Scale((2, 1, 0.5)), Translate(0, 1, 0)])");
    assert_eq!(
        (s.geometry.spheres.len(), s.geometry.ellipsoids.len()),
        (0, 1)
    );
    let (t, n) = hit(&s, Vec3::new(-5.0, 1.0, 0.0), Vec3::X).unwrap();
    assert!(close(t, 3.0) && n.distance(-Vec3::X) < 1e-5, "{t} {n}");
    let (t, n) = hit(&s, Vec3::new(0.0, 6.0, 0.0), -Vec3::Y).unwrap();
    assert!(close(t, 4.0) && n.distance(Vec3::Y) < 1e-5, "{t} {n}");
    let (t, _) = hit(&s, Vec3::new(0.0, 1.0, 5.0), -Vec3::Z).unwrap();
    assert!(close(t, 4.5), "{t}");
    // An oblique point: the normal is the gradient (x/a², y/b², z/c²), normalised.
    let p = Vec3::new(1.0, 0.5, 0.125f32.sqrt()); // x²/4 + y² + z²/0.25 = 1
    let (t, n) = hit(&s, Vec3::new(p.x, p.y + 1.0, 5.0), -Vec3::Z).unwrap();
    assert!(close(t, 5.0 - p.z), "{t}");
    let expected = Vec3::new(p.x / 4.0, p.y, p.z / 0.25).normalize();
    assert!(n.distance(expected) < 1e-5, "{n} vs {expected}");
    // Just outside the silhouette: a miss.
    assert!(hit(&s, Vec3::new(2.001, 1.0, 5.0), -Vec3::Z).is_none());
}

#[test]
fn uniformly_scaled_rotated_sphere_stays_a_sphere() {
    let s = scene(
        "Sphere(material: \"m\", radius: 0.5, transform: [RotateX(33), Scale(3), Translate(1, 2, 3)])",
    );
    assert_eq!(
        (s.geometry.spheres.len(), s.geometry.ellipsoids.len()),
        (1, 0)
    );
    let sp = s.geometry.spheres[0];
    assert!(close(sp.radius, 1.5) && sp.center.distance(Vec3::new(1.0, 2.0, 3.0)) < 1e-6);
}

#[test]
fn rotated_cube_and_bounded_quad() {
    let s = scene("Cube(material: \"m\", size: 2, transform: [RotateY(45)])");
    assert_eq!(s.geometry.triangles.len(), 12);
    let (t, n) = hit(&s, Vec3::new(0.0, 0.0, 5.0), -Vec3::Z).unwrap();
    assert!(close(t, 5.0 - 2f32.sqrt()), "{t}");
    assert!(n.z > 0.7, "outward normal {n}");
    let q = scene("Quad(material: \"m\", size: (2, 1))");
    assert!(hit(&q, Vec3::new(0.9, 0.4, 3.0), -Vec3::Z).is_some());
    assert!(hit(&q, Vec3::new(1.1, 0.0, 3.0), -Vec3::Z).is_none());
    assert!(hit(&q, Vec3::new(0.0, 0.6, 3.0), -Vec3::Z).is_none());
    assert!(
        hit(&q, Vec3::new(0.0, 0.0, -3.0), Vec3::Z).is_some(),
        "quads are two-sided"
    );
}

#[test]
fn mirrored_transforms_keep_outward_normals() {
    let s = scene("Cube(material: \"m\", transform: [Scale((-1, 1, 1))])");
    for (o, d) in [
        (Vec3::new(5.0, 0.1, 0.2), -Vec3::X),
        (Vec3::new(0.1, 5.0, 0.2), -Vec3::Y),
        (Vec3::new(0.1, 0.2, 5.0), -Vec3::Z),
    ] {
        let (_, n) = hit(&s, o, d).unwrap();
        assert!(n.dot(-d) > 0.99, "normal {n} should face back along {d}");
    }
}

#[test]
fn only_used_materials_are_compiled() {
    let text = "Scene(camera: Pinhole(eye: (0, 0, 10), look_at: (0, 0, 0), fov_y: 40), \
        materials: { \"used\": (), \"unused\": (reflect: 1) }, nodes: [Sphere(material: \"used\")])";
    let src = SourceFile::new(Path::new("inline.ron"), text.to_string()).expect("ron");
    let (s, stats) = compile(&src.parse().expect("parses"), Path::new(".")).expect("compiles");
    assert_eq!(s.material_names, ["used"]);
    assert_eq!(stats.materials, 1);
}

#[test]
#[allow(clippy::excessive_precision, clippy::inconsistent_digit_grouping)] // pbrt's exact values
fn a_needle_triangle_is_dropped_so_the_ray_that_grazes_it_misses() {
    // pbrt-v4's "bad case": three collinear vertices (in f32) and a ray that the bare
    // intersector reports as a hit. Compiled from an OBJ, the triangle is dropped as degenerate
    // and the ray misses; a proper triangle in the same file is kept and still hit.
    let dir = tempfile::tempdir().expect("tmp");
    std::fs::write(
        dir.path().join("needle.obj"),
        "v -1113.45459 -79.049614 -56.2431908\nv -1113.45459 -87.0922699 -56.2431908\n\
         v -1113.45459 -79.2090149 -56.2431908\n\
         v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nf 4 5 6\n",
    )
    .expect("write obj");
    let scene = dir.path().join("needle.ron");
    std::fs::write(
        &scene,
        "Scene(camera: Pinhole(eye: (0, 0, 10), look_at: (0, 0, 0), fov_y: 40), \
         materials: { \"m\": () }, nodes: [Mesh(material: \"m\", file: \"needle.obj\")])",
    )
    .expect("write scene");
    let prepared = caustic::pipeline::prepare(&scene, &Default::default()).expect("prepares");
    assert_eq!(
        (
            prepared.stats.triangles,
            prepared.stats.degenerate_triangles
        ),
        (1, 1)
    );
    let g = &prepared.render_scene.geometry;
    let mut ray = Ray::new(
        Vec3::new(-1081.479_25, 99.999_954_2, 87.770_111_1),
        Vec3::new(-32.107_299_8, -183.355_865, -144.607_635),
    );
    ray.t_max = 0.9999;
    assert_eq!(g.intersect(&ray), None);
    assert!(!g.occluded(&ray));
    let h = g
        .intersect(&Ray::new(Vec3::new(0.2, 0.2, 5.0), -Vec3::Z))
        .expect("the proper triangle is kept");
    assert!(close(h.t, 5.0), "{}", h.t);
}

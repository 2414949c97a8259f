//! Closest-hit and any-hit queries through the BVH agree with brute force: a loop over every
//! primitive with the per-primitive intersectors, keeping the nearest hit. Closest-hit must give
//! the same `t` and the same primitive (or, on an exact tie in `t`, one of the tied ones);
//! any-hit must report a blocker exactly when brute force finds one.

use crate::common;

use caustic::geometry::Ray;
use caustic::geometry::sphere::{intersect_sphere, intersect_unit_quadric};
use caustic::geometry::triangle::{TriRay, intersect_triangle};
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render_scene::geometry::{Geometry, PrimKind, PrimRef};
use caustic::sampling::Rng;
use glam::Vec3;

/// Every primitive hit by `ray` within `(0, t_max)`, as `(t, primitive)`, by testing them all.
fn brute_force_hits(g: &Geometry, ray: &Ray) -> Vec<(f32, PrimRef)> {
    let tri_ray = TriRay::new(ray);
    let mut hits = Vec::new();
    for (i, [p0, p1, p2]) in g.triangles.iter().enumerate() {
        if let Some(h) = intersect_triangle(&tri_ray, *p0, *p1, *p2, ray.t_max) {
            hits.push((h.t, PrimRef::new(PrimKind::Triangle, i)));
        }
    }
    for (i, s) in g.spheres.iter().enumerate() {
        if let Some(t) = intersect_sphere(s.center, s.radius, ray) {
            hits.push((t, PrimRef::new(PrimKind::Sphere, i)));
        }
    }
    for (i, e) in g.ellipsoids.iter().enumerate() {
        let o = e.object_from_world.transform_point3(ray.origin.as_dvec3());
        let d = e.object_from_world.transform_vector3(ray.dir.as_dvec3());
        if let Some(t) = intersect_unit_quadric(o, d, 1.0, ray.t_max) {
            hits.push((t, PrimRef::new(PrimKind::Ellipsoid, i)));
        }
    }
    hits
}

#[test]
fn closest_hit_and_any_hit_agree_with_brute_force() {
    for (scene, rays) in [
        ("scenes/blob.ron", 3_000),
        ("scenes/cornell.ron", 20_000),
        ("scenes/refraction.ron", 20_000),
    ] {
        let prepared =
            prepare(&common::root().join(scene), &SceneOverrides::default()).expect("scene");
        let g = &prepared.render_scene.geometry;
        let prims = g.triangles.len() + g.spheres.len() + g.ellipsoids.len();
        let mut rng = Rng::new(5, 6);
        let (mut hits, mut bounded_misses, mut failures) = (0, 0, Vec::new());
        for i in 0..rays {
            let o = Vec3::new(
                rng.next_f32() * 6.0 - 3.0,
                rng.next_f32() * 3.0,
                rng.next_f32() * 6.0 - 3.0,
            );
            let d = Vec3::new(
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
                rng.next_f32() - 0.5,
            )
            .normalize();
            let t_max = if i % 2 == 0 {
                f32::INFINITY
            } else {
                rng.next_f32() * 4.0
            };
            let ray = Ray {
                origin: o,
                dir: d,
                t_max,
            };
            let all = brute_force_hits(g, &ray);
            let nearest = all.iter().map(|h| h.0).fold(f32::INFINITY, f32::min);
            let closest = g.intersect(&ray);
            let agrees = match closest {
                None => all.is_empty(),
                Some(h) => h.t == nearest && all.contains(&(h.t, h.prim)),
            };
            if !agrees {
                failures.push(format!(
                    "closest: {o} {d} {t_max}: bvh {closest:?}, brute {all:?}"
                ));
            }
            if g.occluded(&ray) == all.is_empty() {
                failures.push(format!("any: {o} {d} {t_max}: brute {all:?}"));
            }
            if all.is_empty() {
                bounded_misses += usize::from(t_max.is_finite());
            } else {
                hits += 1;
            }
        }
        assert!(
            failures.is_empty(),
            "{scene}: {} disagreements with brute force over {prims} primitives, e.g. {:#?}",
            failures.len(),
            &failures[..failures.len().min(3)]
        );
        // The rays must exercise both outcomes, or the comparison proves little.
        assert!(
            hits > rays / 10 && bounded_misses > rays / 20,
            "{scene}: {hits} hits, {bounded_misses} bounded misses of {rays} rays"
        );
    }
}

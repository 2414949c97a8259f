//! Same scene, seed and flags give the same bytes: for any thread count, for a crop versus the
//! full frame, and for the RON and TOML spellings of one scene.

use crate::common;

use caustic::render::{Region, RenderOptions};

fn cornell() -> std::path::PathBuf {
    common::root().join("scenes/cornell.ron")
}

#[test]
fn thread_count_does_not_change_a_single_bit() {
    let o = common::small(48, 40, 4);
    let (one, s1) = common::render_file(
        &cornell(),
        &o,
        &RenderOptions {
            threads: Some(1),
            ..Default::default()
        },
    );
    let (two, s2) = common::render_file(
        &cornell(),
        &o,
        &RenderOptions {
            threads: Some(2),
            ..Default::default()
        },
    );
    let (three, _) = common::render_file(
        &cornell(),
        &o,
        &RenderOptions {
            threads: Some(3),
            ..Default::default()
        },
    );
    assert_eq!(one.to_bytes(), two.to_bytes());
    assert_eq!(one.to_bytes(), three.to_bytes());
    assert_eq!(
        s1.rays, s2.rays,
        "ray counts are per pixel, so they agree too"
    );
}

#[test]
fn a_different_seed_changes_the_noise() {
    let mut o = common::small(32, 32, 1);
    let (a, _) = common::render_file(&cornell(), &o, &RenderOptions::default());
    o.render.seed = Some(99);
    let (b, _) = common::render_file(&cornell(), &o, &RenderOptions::default());
    assert_ne!(a.to_bytes(), b.to_bytes());
}

#[test]
fn a_region_equals_the_same_pixels_of_the_full_render() {
    let o = common::small(50, 40, 2);
    let (full, _) = common::render_file(&cornell(), &o, &RenderOptions::default());
    for region in [
        Region {
            x: 7,
            y: 5,
            width: 21,
            height: 17,
        },
        Region {
            x: 0,
            y: 0,
            width: 1,
            height: 1,
        },
        Region {
            x: 49,
            y: 39,
            width: 1,
            height: 1,
        },
        Region {
            x: 0,
            y: 0,
            width: 50,
            height: 40,
        },
    ] {
        let (crop, _) = common::render_file(
            &cornell(),
            &o,
            &RenderOptions {
                region: Some(region),
                ..Default::default()
            },
        );
        assert_eq!((crop.width, crop.height), (region.width, region.height));
        for y in 0..region.height {
            for x in 0..region.width {
                assert_eq!(
                    crop.get(x, y).to_array().map(f32::to_bits),
                    full.get(region.x + x, region.y + y)
                        .to_array()
                        .map(f32::to_bits),
                    "pixel ({}, {}) of {region:?}",
                    region.x + x,
                    region.y + y
                );
            }
        }
    }
}

#[test]
fn ron_and_toml_twins_render_identical_bytes() {
    let o = common::small(40, 40, 2);
    let (ron, _) = common::render_file(&cornell(), &o, &RenderOptions::default());
    let (toml, _) = common::render_file(
        &common::root().join("scenes/cornell.toml"),
        &o,
        &RenderOptions::default(),
    );
    assert_eq!(ron.to_bytes(), toml.to_bytes());
}

#[test]
fn ron_and_toml_twins_parse_to_the_same_scene() {
    let a = caustic::scene::load::load(&cornell())
        .expect("ron loads")
        .scene;
    let b = caustic::scene::load::load(&common::root().join("scenes/cornell.toml"))
        .expect("toml loads")
        .scene;
    assert_eq!(a, b);
}

#[test]
fn regions_rendered_together_equal_each_rendered_alone() {
    // `RenderJob::render_regions` takes a progressive integrator's passes once for all the
    // regions (the doc-image test's strips); the bytes must be those of each region's own
    // render, with the layers, for path-ppm (progressive, with camera-path splits and splats
    // of nothing) and for path.
    use caustic::pipeline::prepare;
    use caustic::render::RenderJob;
    use caustic::settings::IntegratorKind;
    let regions = [
        Region {
            x: 3,
            y: 0,
            width: 30,
            height: 2,
        },
        Region {
            x: 0,
            y: 16,
            width: 40,
            height: 2,
        },
        Region {
            x: 11,
            y: 31,
            width: 5,
            height: 1,
        },
    ];
    for integrator in [IntegratorKind::PathPpm, IntegratorKind::Path] {
        let mut o = common::small(40, 32, 3);
        o.render.integrator = Some(integrator);
        let p = prepare(&common::root().join("scenes/refraction.ron"), &o).expect("scene");
        let options = RenderOptions {
            light_paths: true,
            ..Default::default()
        };
        let mut together = RenderJob::new(&p.render_scene, &options).expect("job");
        let outs = together.render_regions(&regions).expect("renders");
        assert_eq!(outs.len(), regions.len());
        for (region, out) in regions.iter().zip(&outs) {
            let alone = caustic::render::render(
                &p.render_scene,
                &RenderOptions {
                    region: Some(*region),
                    ..options.clone()
                },
            )
            .expect("render");
            assert_eq!(out.sums, alone.sums, "{integrator:?} {region:?}");
            assert_eq!(out.parts, alone.parts, "{integrator:?} {region:?}");
        }
    }
}

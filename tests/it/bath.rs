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

/// The part of the tub's floor the camera sees through the water: the pixels whose central
/// camera ray's first hit is the water quad and whose ray, refracted there by the flat surface
/// (index 1.33, ripples left out: they tilt the normal by at most a few degrees), next hits the
/// tub's floor. Computed from the scene's own geometry, so it follows the camera and the tub.
fn tub_floor_through_water(scene: &caustic::render_scene::RenderScene) -> Vec<usize> {
    use caustic::geometry::Ray;
    use glam::Vec3;
    let (w, h) = (scene.params.width, scene.params.height);
    let g = &scene.geometry;
    let name_of = |hit: &caustic::render_scene::geometry::Hit| {
        scene.objects[g.object_of(hit.prim) as usize].name.as_str()
    };
    let mut pixels = Vec::new();
    for y in 0..h {
        for x in 0..w {
            let ray = scene.camera.ray(x as f32 + 0.5, y as f32 + 0.5, w, h);
            let Some(hit) = g.intersect(&ray) else {
                continue;
            };
            if name_of(&hit) != "water" {
                continue;
            }
            let p = ray.origin + ray.dir * hit.t;
            let eta = 1.0 / 1.33;
            let cos_i = -ray.dir.y;
            let cos_t = (1.0 - eta * eta * (1.0 - cos_i * cos_i)).sqrt();
            let dir = (ray.dir * eta + Vec3::Y * (eta * cos_i - cos_t)).normalize();
            let below = Ray::new(p - Vec3::Y * 1e-4, dir);
            if g.intersect(&below)
                .is_some_and(|h| name_of(&h) == "tub floor")
            {
                pixels.push((y * w + x) as usize);
            }
        }
    }
    pixels
}

/// Luminance (Rec. 709 weights) of a linear RGB value.
fn luminance(c: glam::Vec3) -> f64 {
    0.2126 * f64::from(c.x) + 0.7152 * f64::from(c.y) + 0.0722 * f64::from(c.z)
}

/// What the caustics-visible tests measure over the tub's floor seen through the water.
#[derive(Debug)]
struct CausticFigures {
    /// Pixels in the region.
    pixels: usize,
    /// Caustic layer's share of the radiance (luminance sums over the region, first seed).
    share: f64,
    /// Pearson correlation of the two seeds' caustic layers over the region.
    correlation: f64,
    /// Standard deviation over mean of the two seeds' average caustic layer there.
    contrast: f64,
    /// Mean luminance of the image and of each layer (specular, direct, caustic, indirect)
    /// over the region, first seed (for the report).
    means: [f64; 5],
}

/// Renders the default bath at `width` × `height`, `spp` samples, with the per-kind light
/// layers (what `caustic render --layers caustic` writes), at the scene's seed and at another,
/// and measures [`CausticFigures`] over [`tub_floor_through_water`].
fn caustic_figures(width: u32, height: u32, spp: u32) -> CausticFigures {
    use caustic::integrators::LightPath;
    let path = common::root().join("scenes/bath.ron");
    let layers = |seed: Option<u64>| {
        let mut overrides = common::small(width, height, spp);
        overrides.render.seed = seed;
        let p = prepare(&path, &overrides).expect("bath.ron");
        let options = RenderOptions {
            threads: Some(2),
            light_paths: true,
            ..RenderOptions::default()
        };
        let out = render(&p.render_scene, &options).expect("renders");
        let parts = out.parts.expect("light-path layers");
        let n = (width * height) as usize;
        let total: Vec<f64> = (0..n).map(|i| luminance(out.sums.mean(i))).collect();
        let kinds: Vec<Vec<f64>> = parts
            .iter()
            .map(|part| (0..n).map(|i| luminance(part.mean(i))).collect())
            .collect();
        let caustic = kinds[LightPath::Caustic as usize].clone();
        (p.render_scene, total, caustic, kinds)
    };
    let (scene, total, a, kinds) = layers(None);
    let (_, _, b, _) = layers(Some(1_000_003));
    let region = tub_floor_through_water(&scene);
    let region_mean = |v: &[f64]| region.iter().map(|&i| v[i]).sum::<f64>() / region.len() as f64;
    let means = [
        region_mean(&total),
        region_mean(&kinds[0]),
        region_mean(&kinds[1]),
        region_mean(&kinds[2]),
        region_mean(&kinds[3]),
    ];
    let pick = |v: &[f64]| region.iter().map(|&i| v[i]).collect::<Vec<f64>>();
    let (total, a, b) = (pick(&total), pick(&a), pick(&b));
    let n = region.len() as f64;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / n;
    let share = a.iter().sum::<f64>() / total.iter().sum::<f64>();
    let (ma, mb) = (mean(&a), mean(&b));
    let cov: f64 = a.iter().zip(&b).map(|(x, y)| (x - ma) * (y - mb)).sum();
    let var = |v: &[f64], m: f64| v.iter().map(|x| (x - m) * (x - m)).sum::<f64>();
    let correlation = cov / (var(&a, ma) * var(&b, mb)).sqrt();
    let avg: Vec<f64> = a.iter().zip(&b).map(|(x, y)| 0.5 * (x + y)).collect();
    let m = mean(&avg);
    let contrast = (var(&avg, m) / n).sqrt() / m;
    CausticFigures {
        pixels: region.len(),
        share,
        correlation,
        contrast,
        means,
    }
}

/// Issue #27's "caustics visible" at reduced size: 200 × 150, 12 samples per pixel. Over the
/// tub's floor seen through the water the caustic layer carries at least 30 % of the radiance;
/// its pattern is structure, not noise (the caustic layers of two seeds correlate at least
/// 0.8 there) and a pattern, not a wash (their average's std/mean at least 0.3). The issue's
/// thresholds hold at this size unchanged (measured when written: 665 pixels, share 0.418,
/// correlation 0.986, std/mean 0.636): fewer photons per pass (0.3 per pixel) blur the lines,
/// which lowers the contrast, but the two seeds then agree all the more.
#[test]
fn the_sun_draws_caustic_lines_on_the_tub_floor() {
    let f = caustic_figures(200, 150, 12);
    eprintln!("{f:?}");
    assert!(f.pixels > 300, "region of {} pixels", f.pixels);
    let parts: f64 = f.means[1..].iter().sum();
    assert!(
        (parts / f.means[0] - 1.0).abs() < 1e-4,
        "the layers do not add up to the image: {f:?}"
    );
    assert!(f.share >= 0.30, "{f:?}");
    assert!(f.correlation >= 0.8, "{f:?}");
    assert!(f.contrast >= 0.3, "{f:?}");
}

/// The same three figures at the scene's own size and samples (800 × 600, slow: run with
/// `cargo test --release --test it bath -- --ignored`).
#[test]
#[ignore = "full size: about a minute on 2 cores"]
fn the_sun_draws_caustic_lines_on_the_tub_floor_at_full_size() {
    let f = caustic_figures(800, 600, 5);
    eprintln!("{f:?}");
    assert!(f.pixels > 16 * 300, "region of {} pixels", f.pixels);
    assert!(f.share >= 0.30, "{f:?}");
    assert!(f.correlation >= 0.8, "{f:?}");
    assert!(f.contrast >= 0.3, "{f:?}");
}

/// The default bath's 8-bit image has under 1 % of its pixels with a clipped channel (255),
/// through its own tone curve and exposure (issue #27), at reduced size: 200 × 150, 4 samples
/// per pixel (a bright speck at few samples can only add clipped pixels, so this errs high).
#[test]
fn the_default_bath_is_not_blown_out() {
    use caustic::render::output::to_srgb8;
    let p = prepare(
        &common::root().join("scenes/bath.ron"),
        &common::small(200, 150, 4),
    )
    .expect("bath.ron");
    let options = RenderOptions {
        threads: Some(2),
        ..RenderOptions::default()
    };
    let film = render(&p.render_scene, &options).expect("renders").film;
    let display = caustic::render::tonemap::Display {
        exposure: p.render_scene.params.exposure,
        tonemap: p.render_scene.params.tonemap,
    };
    let img = to_srgb8(&film, display);
    let clipped = img.pixels().filter(|px| px.0.contains(&255)).count();
    let fraction = clipped as f64 / f64::from(200 * 150);
    eprintln!("clipped: {clipped} pixels, {:.3} %", 100.0 * fraction);
    assert!(
        fraction < 0.01,
        "{:.2} % of the pixels clipped",
        100.0 * fraction
    );
}

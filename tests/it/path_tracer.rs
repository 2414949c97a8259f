//! The path tracer against Whitted where both are exact, on every scene, across threads,
//! regions, passes and samplers, and statistically against a committed converged reference.

use caustic::analysis::metrics::read_film;
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render::{Film, PixelSums, Region, RenderJob, RenderOptions, render};

use crate::common;

fn with(o: SceneOverrides, sets: &[&str]) -> SceneOverrides {
    let mut o = o;
    o.sets.extend(sets.iter().map(|s| s.to_string()));
    o
}

/// One point light, Lambertian surfaces and perfect mirrors (one lobe each): with
/// `diffuse_depth: 0`, the path tracer's light transport is exactly Whitted's, and both trace
/// the same camera rays, so they agree pixel by pixel to float rounding.
const DIRECT_AND_MIRRORS: &str = r#"Scene(
    render: (width: 40, height: 32, samples_per_pixel: 4, max_depth: 6, seed: 2,
             min_contribution: 0, diffuse_depth: 0, integrator: INTEGRATOR),
    camera: Pinhole(eye: (0, 1, 3.5), look_at: (0, 0.8, 0), fov_y: 45),
    materials: {
        "white": (color: (0.75, 0.75, 0.75)),
        "red": (color: (0.7, 0.15, 0.1)),
        "mirror": (color: (0.9, 0.85, 0.8), reflect: 1),
    },
    lights: [ Point(position: (0.3, 1.8, 0.6), power: (30, 30, 30)) ],
    nodes: [
        Quad(material: "white", size: (3, 3), transform: [RotateX(-90)]),
        Quad(material: "red", size: (3, 3), transform: [Translate(0, 1.5, -1)]),
        Sphere(material: "mirror", center: (-0.4, 0.4, 0), radius: 0.4),
        Sphere(material: "white", center: (0.5, 0.3, 0.3), radius: 0.3),
        Quad(material: "mirror", size: (1, 1), transform: [RotateY(50), Translate(1.2, 0.6, -0.4)]),
    ],
)"#;

#[test]
fn path_equals_whitted_for_direct_light_and_mirror_chains() {
    let render_with = |integrator: &str| {
        let scene = common::scene_from_text(&DIRECT_AND_MIRRORS.replace("INTEGRATOR", integrator));
        render(&scene, &RenderOptions::default())
            .expect("renders")
            .film
    };
    let (w, p) = (render_with("Whitted"), render_with("Path"));
    let mut worst = 0.0f32;
    let mut lit = 0;
    for (a, b) in w.pixels.iter().zip(&p.pixels) {
        let d = (*a - *b).abs().max_element();
        worst = worst.max(d / a.max_element().max(1e-3));
        if a.max_element() > 0.01 {
            lit += 1;
        }
    }
    assert!(lit > 600, "{lit} lit pixels");
    assert!(worst < 1e-4, "largest relative difference {worst}");
}

/// Two lights of different power and a mixed material: light selection and lobe choice are
/// random in the path tracer, so compare 8×8 block means within 4σ of their noise.
#[test]
fn path_equals_whitted_in_expectation_with_mixed_lobes_and_two_lights() {
    let text = DIRECT_AND_MIRRORS
        .replace(
            r#""white": (color: (0.75, 0.75, 0.75)),"#,
            r#""white": (color: (0.5, 0.5, 0.5), specular: (0.2, 0.2, 0.2), shininess: 20, diffuse: 0.7, reflect: 0.3),"#,
        )
        .replace(
            "lights: [ Point(position: (0.3, 1.8, 0.6), power: (30, 30, 30)) ],",
            "lights: [ Point(position: (0.3, 1.8, 0.6), power: (30, 30, 30)), Point(position: (-1, 1.2, 1.5), power: (8, 10, 12)) ],",
        )
        .replace("samples_per_pixel: 4", "samples_per_pixel: 64");
    let whitted = common::scene_from_text(&text.replace("INTEGRATOR", "Whitted"));
    let path = common::scene_from_text(&text.replace("INTEGRATOR", "Path"));
    let w = render(&whitted, &RenderOptions::default()).expect("renders");
    let p = render(&path, &RenderOptions::default()).expect("renders");
    let (width, height) = (p.film.width, p.film.height);
    let mut checked = 0;
    for by in 0..height / 8 {
        for bx in 0..width / 8 {
            let (mut mw, mut mp, mut var) = (0.0f64, 0.0f64, 0.0f64);
            for y in by * 8..by * 8 + 8 {
                for x in bx * 8..bx * 8 + 8 {
                    let i = (y * width + x) as usize;
                    mw += f64::from(w.film.pixels[i].x);
                    mp += f64::from(p.film.pixels[i].x);
                    // Variance of this pixel's mean, from the film's own sums.
                    var += f64::from(p.sums.variance(i).x) / f64::from(p.sums.count(i));
                }
            }
            let sigma = var.sqrt() / 64.0;
            let (mw, mp) = (mw / 64.0, mp / 64.0);
            assert!(
                (mw - mp).abs() <= 4.0 * sigma + 1e-4,
                "block ({bx}, {by}): whitted {mw}, path {mp} ± {sigma}"
            );
            checked += 1;
        }
    }
    assert_eq!(checked, 20);
}

#[test]
fn path_renders_every_scene_without_nan_or_black() {
    for path in common::scene_files() {
        let o = with(common::small(32, 24, 2), &["render.integrator=Path"]);
        let (film, stats) = common::render_file(&path, &o, &RenderOptions::default());
        assert_eq!(stats.nan_samples, 0, "{}", path.display());
        assert!(
            film.mean().max_element() > 0.01,
            "{}: black",
            path.display()
        );
    }
}

fn cornell_path(width: u32, height: u32, spp: u32, sampler: &str) -> SceneOverrides {
    with(
        common::small(width, height, spp),
        &[
            "render.integrator=Path",
            &format!("render.sampler={sampler}"),
        ],
    )
}

#[test]
fn both_samplers_are_deterministic_across_threads_regions_and_sample_ranges() {
    let file = common::root().join("scenes/cornell.ron");
    for sampler in ["Independent", "Sobol"] {
        let o = cornell_path(40, 30, 8, sampler);
        let threads = |n| RenderOptions {
            threads: Some(n),
            ..Default::default()
        };
        let (one, _) = common::render_file(&file, &o, &threads(1));
        let (three, _) = common::render_file(&file, &o, &threads(3));
        assert_eq!(one.to_bytes(), three.to_bytes(), "{sampler}: threads");
        let region = Region {
            x: 7,
            y: 5,
            width: 19,
            height: 13,
        };
        let (crop, _) = common::render_file(
            &file,
            &o,
            &RenderOptions {
                region: Some(region),
                ..Default::default()
            },
        );
        for y in 0..region.height {
            for x in 0..region.width {
                assert_eq!(
                    crop.get(x, y).to_array(),
                    one.get(region.x + x, region.y + y).to_array(),
                    "{sampler}: region pixel ({x}, {y})"
                );
            }
        }
        // Two disjoint sample ranges, merged (in either order), give the bytes of all samples.
        let prepared = prepare(&file, &o).expect("scene");
        let part = |a: u32, b: u32| {
            let options = RenderOptions {
                samples: Some(a..b),
                ..Default::default()
            };
            RenderJob::new(&prepared.render_scene, &options)
                .expect("job")
                .finish()
                .expect("renders")
                .sums
        };
        let (first, second) = (part(0, 3), part(3, 8));
        let mut merged = first.clone();
        merged.merge(&second).expect("same size");
        let mut other_order = second.clone();
        other_order.merge(&first).expect("same size");
        assert_eq!(
            merged.to_film().to_bytes(),
            one.to_bytes(),
            "{sampler}: merge"
        );
        assert_eq!(merged, other_order);
        // And through a .part file.
        let bytes = merged.to_bytes("test");
        let (read, meta) = PixelSums::from_bytes(&bytes, "mem").expect("reads");
        assert_eq!((read, meta.as_str()), (merged, "test"));
    }
}

/// The committed converged reference of `scenes/cornell.ron` at 32×32 with the path tracer
/// (made by `scripts/make_test_references.sh`: 65536 spp, independent sampler, seed 1000).
fn reference() -> Film {
    read_film(&common::root().join("tests/it/references/cornell_path_32.exr"))
        .expect("reference EXR")
}

fn mean_block(f: &Film, bx: u32, by: u32) -> f64 {
    let mut s = 0.0f64;
    for y in by * 8..by * 8 + 8 {
        for x in bx * 8..bx * 8 + 8 {
            let p = f.get(x, y);
            s += f64::from(p.x + p.y + p.z) / 3.0;
        }
    }
    s / 64.0
}

#[test]
fn path_converges_to_the_committed_reference() {
    let reference = reference();
    let file = common::root().join("scenes/cornell.ron");
    // Renders over several seeds: each 8×8 block's mean lies within 4σ of the seed-to-seed
    // spread of the reference's value (a biased integrator fails this; noise does not).
    let seeds = [1u64, 2, 3, 4, 5, 6];
    let films: Vec<Film> = seeds
        .iter()
        .map(|&s| {
            let mut o = cornell_path(32, 32, 16, "Sobol");
            o.render.seed = Some(s);
            common::render_file(&file, &o, &RenderOptions::default()).0
        })
        .collect();
    for by in 0..4 {
        for bx in 0..4 {
            let v: Vec<f64> = films.iter().map(|f| mean_block(f, bx, by)).collect();
            let n = v.len() as f64;
            let mean = v.iter().sum::<f64>() / n;
            let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            let r = mean_block(&reference, bx, by);
            assert!(
                (mean - r).abs() <= 4.0 * sd / n.sqrt() + 2e-3 * r.max(0.01),
                "block ({bx}, {by}): {mean} ± {} vs reference {r}",
                sd / n.sqrt()
            );
        }
    }
    // relMSE falls as 1/N (independent sampler: the Monte Carlo rate). Path-traced glass
    // makes rare bright samples, so one render's relMSE scatters; the mean over 6 seeds is
    // stable enough to check ×16 samples ⇒ ÷16 error within a factor of 2.
    let rel_mse = |spp: u32| {
        let mut total = 0.0;
        for seed in 1..=6 {
            let mut o = cornell_path(32, 32, spp, "Independent");
            o.render.seed = Some(seed);
            let (f, _) = common::render_file(&file, &o, &RenderOptions::default());
            total += caustic::analysis::metrics::compare(&f, &reference)
                .expect("same size")
                .rel_mse;
        }
        total / 6.0
    };
    let e: Vec<f64> = [4, 16, 64].iter().map(|&n| rel_mse(n)).collect();
    let ratio = e[0] / e[2];
    assert!(
        (8.0..32.0).contains(&ratio),
        "relMSE {e:?}: 4 → 64 spp ratio {ratio}"
    );
    assert!(e[0] > e[1] && e[1] > e[2], "relMSE {e:?}");
}

#[test]
fn unknown_integrator_and_sampler_names_are_clear_errors() {
    let out = common::caustic(&["render", "scenes/cornell.ron", "--integrator", "bidir"]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2));
    assert!(err.contains("whitted") && err.contains("path"), "{err}");
    let out = common::caustic(&[
        "check",
        "scenes/cornell.ron",
        "--set",
        "render.integrator=Bidir",
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(2), "{err}");
    assert!(err.contains("Whitted") && err.contains("Path"), "{err}");
    let out = common::caustic(&[
        "check",
        "scenes/cornell.ron",
        "--set",
        "render.integrator=Path",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn a_path_tracer_ray_tree_reports_the_radiance_each_ray_brought_back() {
    let file = common::root().join("scenes/cornell.ron");
    let o = cornell_path(64, 64, 4, "Sobol");
    let prepared = prepare(&file, &o).expect("scene");
    let mut lit = 0;
    for (x, y) in [(32, 40), (10, 30), (50, 55), (32, 8)] {
        for sample in 0..4 {
            let (log, l) =
                caustic::render::trace_pixel(&prepared.render_scene, x, y, sample).expect("pixel");
            // The camera ray's radiance is the sample's value; a chain of rays, each the
            // child of the one before.
            assert!(
                (log.nodes[0].radiance - l).abs().max_element() <= 1e-5 * l.max_element().max(1.0),
                "({x}, {y}) #{sample}: {} vs {l}",
                log.nodes[0].radiance
            );
            for (i, n) in log.nodes.iter().enumerate().skip(1) {
                assert!(log.nodes[i - 1].children == vec![i] && n.radiance.is_finite());
            }
            if l.max_element() > 0.0 {
                lit += 1;
            }
        }
    }
    assert!(lit >= 8, "{lit} lit samples");
}

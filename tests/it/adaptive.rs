//! Adaptive sampling (`--adaptive`, issue #43): the same bytes for any thread count, crop and
//! resumed state; a lower error than uniform sampling at the same number of samples, scored
//! against a reference rendered by another estimator; the image mean of a furnace kept at its
//! closed form; shards and `.part` outputs refused with a message naming the flag.

use caustic::analysis::metrics::compare;
use caustic::pipeline::prepare;
use caustic::render::adaptive::AdaptivePlan;
use caustic::render::passes::{PassPlan, render_in_passes};
use caustic::render::{Region, RenderJob, RenderOptions, RenderOutput, render};
use caustic::render_scene::RenderScene;

use crate::common;

/// The Cornell box (the default estimator: path tracing with a progressive caustic map, so
/// the rounds' sample slots each trace photon maps of their own) at `w`×`h`, `cap` samples per
/// pixel at most.
fn cornell(w: u32, h: u32, cap: u32) -> RenderScene {
    prepare(
        &common::root().join("scenes/cornell.ron"),
        &common::small(w, h, cap),
    )
    .expect("cornell prepares")
    .render_scene
}

fn plan(scene: &RenderScene, target: f64) -> PassPlan<'static> {
    PassPlan {
        adaptive: Some(AdaptivePlan::new(
            Some(target),
            scene.params.samples_per_pixel,
        )),
        ..PassPlan::default()
    }
}

fn adaptive(
    scene: &RenderScene,
    threads: usize,
    region: Option<Region>,
    target: f64,
) -> RenderOutput {
    let options = RenderOptions {
        threads: Some(threads),
        region,
        ..RenderOptions::default()
    };
    let job = RenderJob::new(scene, &options).expect("job");
    render_in_passes(job, &plan(scene, target))
        .result
        .expect("renders")
}

fn total_samples(out: &RenderOutput) -> u64 {
    let n = out.sums.width as usize * out.sums.height as usize;
    (0..n).map(|i| u64::from(out.sums.count(i))).sum()
}

#[test]
fn adaptive_renders_are_the_same_for_any_thread_count_crop_and_resume() {
    let scene = cornell(32, 24, 64);
    let one = adaptive(&scene, 1, None, 0.02);
    // It did adapt: some pixels stopped at the warm-up (16), some went on to the cap.
    let n = 32 * 24;
    let counts: Vec<u32> = (0..n).map(|i| one.sums.count(i)).collect();
    let (min, max) = (counts.iter().min(), counts.iter().max());
    assert!(min < max && max == Some(&64), "counts {min:?}..{max:?}");
    for threads in [2, 7] {
        let other = adaptive(&scene, threads, None, 0.02);
        assert_eq!(other.sums, one.sums, "{threads} threads");
        assert_eq!(
            other.film.to_bytes(),
            one.film.to_bytes(),
            "{threads} threads"
        );
    }
    // A crop: the same pixels, sample counts included.
    let region = Region {
        x: 9,
        y: 5,
        width: 13,
        height: 11,
    };
    let crop = adaptive(&scene, 2, Some(region), 0.02);
    for y in 0..region.height {
        for x in 0..region.width {
            let (fx, fy) = (x + region.x, y + region.y);
            let (i, j) = ((y * region.width + x) as usize, (fy * 32 + fx) as usize);
            assert_eq!(crop.film.get(x, y), one.film.get(fx, fy), "pixel {fx},{fy}");
            assert_eq!(crop.sums.count(i), one.sums.count(j), "pixel {fx},{fy}");
        }
    }
    // Stopped after two rounds (the warm-up and one adaptive round), its state continued in a
    // new job: the bytes of the render that never stopped.
    let options = RenderOptions {
        threads: Some(2),
        ..RenderOptions::default()
    };
    let p = plan(&scene, 0.02).adaptive.expect("adaptive");
    let mut first = RenderJob::new(&scene, &options).expect("job");
    for _ in 0..2 {
        let round = p.round(first.next_index(), 64);
        let counts = p.counts(first.sums(), &round);
        first.render_round(round, &counts).expect("round");
    }
    let state = first.state();
    drop(first);
    let mut resumed = RenderJob::new(&scene, &options).expect("job");
    resumed.resume(state).expect("same size");
    let resumed = render_in_passes(resumed, &plan(&scene, 0.02))
        .result
        .expect("renders");
    assert_eq!(resumed.sums, one.sums);
}

/// The checkpointed render (a save after every round) writes the same EXR as one without.
#[test]
fn checkpoints_leave_an_adaptive_render_unchanged() {
    let dir = tempfile::tempdir().expect("tmp");
    let path = |n: &str| dir.path().join(n).to_str().expect("utf8").to_string();
    let base = [
        "render",
        "scenes/cornell.ron",
        "--width",
        "24",
        "--height",
        "18",
        "--spp",
        "32",
        "--adaptive",
        "--target-error",
        "0.03",
        "--threads",
        "2",
    ];
    let plain = common::caustic(&[&base[..], &["-o", &path("a.exr")]].concat());
    let stderr = String::from_utf8_lossy(&plain.stderr);
    assert!(plain.status.success(), "{stderr}");
    assert!(stderr.contains("adaptive: "), "{stderr}");
    let cp = path("cp.exr");
    let saved = common::caustic(
        &[
            &base[..],
            &[
                "-o",
                &path("b.exr"),
                "--checkpoint",
                &cp,
                "--checkpoint-every",
                "0",
            ],
        ]
        .concat(),
    );
    assert!(
        saved.status.success(),
        "{}",
        String::from_utf8_lossy(&saved.stderr)
    );
    let read = |n: &str| std::fs::read(dir.path().join(n)).expect("written");
    assert_eq!(read("a.exr"), read("b.exr"));
}

/// Shards and `.part` files take sample ranges of every pixel; an adaptive render's samples
/// depend on all the earlier ones, so they are refused, naming the flag.
#[test]
fn shards_and_part_files_refuse_adaptive_renders() {
    let dir = tempfile::tempdir().expect("tmp");
    let part = dir.path().join("s.part");
    let part = part.to_str().expect("utf8");
    for extra in [
        &["--shard", "1/2", "-o", part][..],
        &["-o", part][..],
        &["--samples", "0..8", "-o", part][..],
        &["--samples", "0..8", "-o", &part.replace(".part", ".exr")][..],
    ] {
        let args = [
            &[
                "render",
                "scenes/cornell.ron",
                "--width",
                "8",
                "--height",
                "8",
                "--adaptive",
            ][..],
            extra,
        ]
        .concat();
        let o = common::caustic(&args);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{extra:?}: {stderr}");
        assert!(stderr.contains("--adaptive"), "{extra:?}: {stderr}");
        assert!(!std::path::Path::new(part).exists());
    }
}

/// The caustic Cornell box at equal numbers of samples: the adaptive render against a uniform
/// one with at least as many samples, both scored against a path-traced reference (another
/// estimator: no photon map) of 1024 samples per pixel.
#[test]
fn adaptive_sampling_lowers_the_error_at_equal_samples() {
    let (w, h) = (64u32, 48u32);
    let scene = cornell(w, h, 256);
    let out = adaptive(&scene, 2, None, 0.02);
    let pixels = u64::from(w * h);
    let spp = total_samples(&out).div_ceil(pixels) as u32;
    let uniform = render(
        &cornell(w, h, spp),
        &RenderOptions {
            threads: Some(2),
            ..RenderOptions::default()
        },
    )
    .expect("uniform");
    let mut overrides = common::small(w, h, 1024);
    overrides.render.seed = Some(7);
    overrides.render.integrator = Some(caustic::settings::IntegratorKind::Path);
    let reference = render(
        &prepare(&common::root().join("scenes/cornell.ron"), &overrides)
            .expect("reference prepares")
            .render_scene,
        &RenderOptions {
            threads: Some(2),
            ..RenderOptions::default()
        },
    )
    .expect("reference")
    .film;
    let a = compare(&out.film, &reference).expect("size").overall();
    let u = compare(&uniform.film, &reference).expect("size").overall();
    assert!(
        a.rel_mse < 0.9 * u.rel_mse,
        "adaptive relMSE {} at {spp} spp (mean) against uniform {} at {spp} spp",
        a.rel_mse,
        u.rel_mse
    );
    // The stop on a pixel's own samples lowers the mean a little (Kirk & Arvo 1991; see
    // render::adaptive): bounded here, against the reference's mean.
    let (ma, mr) = (
        out.film.mean().element_sum(),
        reference.mean().element_sum(),
    );
    assert!((ma / mr - 1.0).abs() < 0.02, "mean {ma} against {mr}");
}

/// The furnace: a Lambertian sphere of albedo 0.5 under a uniform background of radiance 1.
/// Inside its silhouette every sample is 0.5, outside 1; the silhouette's pixels mix the two
/// and are the noisy ones the adaptive rounds sample. The image's mean is a closed form: the
/// silhouette of a sphere of radius 1 seen from 4 is a circle of radius tan β = 1/√15 on the
/// image plane at distance 1, whose half height is tan 15°.
#[test]
fn the_adaptive_mean_keeps_the_furnace_closed_form() {
    let scene = common::scene_from_text(
        r#"Scene(
    render: (width: 48, height: 48, samples_per_pixel: 256, max_depth: 64, seed: 3,
             background: (1, 1, 1), integrator: Path),
    camera: Pinhole(eye: (0, 0, 4), look_at: (0, 0, 0), fov_y: 30),
    materials: { "m": (color: (0.5, 0.5, 0.5)) },
    nodes: [ Sphere(material: "m", center: (0, 0, 0), radius: 1) ],
)"#,
    );
    let covered = std::f64::consts::PI / 15.0 / (4.0 * 15f64.to_radians().tan().powi(2));
    let expected = 1.0 - 0.5 * covered;
    let out = adaptive(&scene, 2, None, 0.0003);
    let mean = f64::from(out.film.mean().x);
    let spp = total_samples(&out) as f64 / (48.0 * 48.0);
    // Most pixels stop at the warm-up (64): the adaptive rounds went to the silhouette.
    assert!(spp > 64.5 && spp < 100.0, "{spp} samples per pixel");
    assert!(
        (mean - expected).abs() < 2e-4,
        "mean {mean} against {expected} ({spp} spp)"
    );
}

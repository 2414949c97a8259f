//! Volumetric caustics (issue 44, item 3; docs/media.md, "Volumetric caustics"): the default
//! estimator's volume caustic map and beam radiance estimate against the path tracer on a tank
//! of scattering water under a sun widened to 12° (wide enough for `path` to converge: a
//! phase-sampled direction refracts out into the sun's disc at about 1 % of medium vertices).
//!
//! Inside the water, every bit of sunlight arrived by refraction at the surface, so the light
//! scattered towards the camera is all light → specular⁺ → medium (plus deeper bounces): the
//! paths the volume caustic map owns. Three estimates of the same small image:
//! - `path`, the reference (next-event estimation from a medium vertex is blocked by the water
//!   surface; only phase sampling through the surface finds the sun);
//! - the default estimator (`path-ppm`, chosen by the scene: the water is a specular caster);
//! - the default's camera paths with an empty volume map: they still skip light → specular⁺ →
//!   medium at their medium vertices, and nothing adds it back. That is the image with the map
//!   disabled but the split kept.
//!
//! The default must agree with `path` (golden block z-test), and the third image must be
//! clearly darker than `path` (by more than a third): together they say the camera paths skip
//! exactly the paths the map adds (a skip that missed some would double count and fail the
//! first; a map that added nothing would fail the second).

use glam::{DVec3, Vec3};

use caustic::integrators::path::PathMaps;
use caustic::integrators::photon::VolumeMap;
use caustic::integrators::progressive_path::SPECULAR_SPLITS;
use caustic::integrators::{Context, Counters, NoTrace, PathTracer, ProgressivePath, Radiance};
use caustic::render::golden::{BlockTest, PixelEstimates};
use caustic::render_scene::{IntegratorKind, RenderScene};
use caustic::sampling::Sampler;
use caustic::shading::NEAR_SPECULAR_ALPHA;

use crate::common::scene_from_text;

/// The test's tank: 2 × 1 × 0.8 m of water (σs = 0.8 /m, g = 0.3, a little absorption), gentle
/// ripples on every face, a 12° sun from above and in front, black all around. The camera sees
/// only the middle of the tank through its front face, 0.2 m or more below the surface and
/// away from the sides: the beam estimate's discs there lie within the water (a disc reaching
/// over the surface, where no photon is, reads too little — a bias in proportion to the radius
/// that the passes shrink, but slowly; docs/media.md).
const TANK: &str = r#"Scene(
    render: (width: 24, height: 16, samples_per_pixel: 64, max_depth: 12, seed: 21),
    camera: Pinhole(eye: (0, 0.47, 1.8), look_at: (0, 0.47, 0), fov_y: 18),
    textures: { "ripples": Ripple(centers: [(0.35, 0.4), (0.7, 0.6)], frequency: 30, amplitude: 0.003, decay: 1) },
    media: { "murky": (sigma_a: (0.05, 0.1, 0.2), sigma_s: (0.8, 0.8, 0.8), g: 0.3) },
    materials: {
        "water": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.33, bump: "ripples", medium: "murky"),
    },
    lights: [ Distant(direction: (0.2, 1, 0.4), irradiance: (3, 3, 3), angular_radius: 12) ],
    nodes: [ Cube(material: "water", transform: [Scale((2, 1, 0.8)), Translate(0, 0.5, 0)]) ],
)"#;

/// Per-pixel sums of one estimator.
struct Sums {
    width: u32,
    height: u32,
    sum: Vec<DVec3>,
    sq: Vec<DVec3>,
    n: u32,
}

impl Sums {
    fn new(scene: &RenderScene) -> Self {
        let n = (scene.params.width * scene.params.height) as usize;
        Self {
            width: scene.params.width,
            height: scene.params.height,
            sum: vec![DVec3::ZERO; n],
            sq: vec![DVec3::ZERO; n],
            n: 0,
        }
    }

    fn add(&mut self, i: usize, l: Vec3) {
        let l = l.as_dvec3();
        assert!(l.is_finite(), "pixel {i}: {l}");
        self.sum[i] += l;
        self.sq[i] += l * l;
    }

    fn estimates(&self) -> PixelEstimates {
        let n = f64::from(self.n);
        let mean: Vec<DVec3> = self.sum.iter().map(|&s| s / n).collect();
        let variance = self
            .sq
            .iter()
            .zip(&mean)
            .map(|(&q, &m)| ((q / n - m * m).max(DVec3::ZERO) / (n - 1.0)).as_vec3())
            .collect();
        PixelEstimates {
            width: self.width,
            height: self.height,
            mean: mean.iter().map(|m| m.as_vec3()).collect(),
            variance,
        }
    }

    /// The image mean (channel average) and its standard error.
    fn image_mean(&self) -> (f64, f64) {
        let e = self.estimates();
        let k = e.mean.len() as f64;
        let m: f64 = e
            .mean
            .iter()
            .map(|v| f64::from(v.element_sum()) / 3.0)
            .sum::<f64>()
            / k;
        let var: f64 = e
            .variance
            .iter()
            .map(|v| f64::from(v.element_sum()) / 9.0)
            .sum::<f64>()
            / (k * k);
        (m, var.sqrt())
    }
}

/// Runs `f(pixel index, camera ray, sampler)` for sample `s` of every pixel.
fn each_pixel(
    scene: &RenderScene,
    sampler: &mut Sampler,
    s: u32,
    mut f: impl FnMut(usize, caustic::geometry::Ray, &mut Sampler),
) {
    let p = &scene.params;
    for y in 0..p.height {
        for x in 0..p.width {
            sampler.start_pixel_sample(x, y, s);
            let (jx, jy) = sampler.pixel_2d();
            let ray = scene
                .camera
                .ray(x as f32 + jx, y as f32 + jy, p.width, p.height);
            f((y * p.width + x) as usize, ray, sampler);
        }
    }
}

#[test]
fn the_default_and_path_agree_on_volumetric_caustics_and_the_split_is_exact() {
    let mut scene = scene_from_text(TANK);
    // 8 000 caustic photons per pass rather than the default's 1 000 for so small an image: the
    // beam estimate is consistent, not unbiased, and its bias falls with the radius. Measured
    // (this test, 192 passes, with the pilot radius capped at 2× instead of today's 3×):
    // default/path 0.960 at 1 000 per pass, 0.986 at 8 000, 0.994 at 30 000; today 0.990 at
    // 8 000 (image z −0.72). path's standard error is 0.8 %.
    scene.params.photons.caustic = 8000;
    assert_eq!(
        scene.params.integrator,
        IntegratorKind::PathPpm,
        "the default's choice"
    );
    let p = &scene.params;
    let mut counters = Counters::default();

    // The reference.
    let path_spp = 4096;
    let tracer = PathTracer::new(&scene);
    let mut path = Sums::new(&scene);
    let mut sampler = Sampler::new(p.sampler, p.seed, path_spp);
    for s in 0..path_spp {
        each_pixel(&scene, &mut sampler, s, |i, ray, sampler| {
            let l = tracer.li(ray, &mut Context::new(sampler, &mut counters, &mut NoTrace));
            path.add(i, l.total());
        });
        path.n += 1;
    }

    // The default estimator, pass by pass, and its camera paths alone.
    let passes = 192;
    let mut pp = ProgressivePath::path_ppm(&scene);
    let split = PathTracer::new(&scene).with_specular_splits(SPECULAR_SPLITS);
    let empty = VolumeMap::default();
    let (mut full, mut camera) = (Sums::new(&scene), Sums::new(&scene));
    let mut beams = 0usize;
    let mut sampler = Sampler::new(p.sampler, p.seed ^ 0x5a5a, passes);
    for pass in 0..passes {
        pp.begin_pass(pass);
        let maps = pp.photons().maps();
        beams += maps.volume.as_ref().map_or(0, VolumeMap::len);
        let lights: Vec<bool> = maps.summary.caustic.iter().map(|c| c.emitted > 0).collect();
        let skip_only = PathMaps {
            caustic: maps.caustic.as_ref(),
            global: None,
            global_at: 1,
            global_has_caustics: true,
            near_specular: Some(NEAR_SPECULAR_ALPHA),
            caustic_lights: &lights,
            volume: Some(&empty),
        };
        each_pixel(&scene, &mut sampler, pass, |i, ray, sampler| {
            let l: Radiance = pp.li(ray, &mut Context::new(sampler, &mut counters, &mut NoTrace));
            full.add(i, l.total());
            let l = split.li_with_maps(
                skip_only,
                ray,
                &mut Context::new(sampler, &mut counters, &mut NoTrace),
            );
            camera.add(i, l.total());
        });
        full.n += 1;
        camera.n += 1;
    }
    assert!(
        beams > 100 * passes as usize,
        "{beams} volume photons in {passes} passes"
    );

    let reference = path.estimates();
    let v = BlockTest::default()
        .compare(&reference, &full.estimates())
        .expect("same size");
    let (pm, pse) = path.image_mean();
    let (fm, fse) = full.image_mean();
    let (cm, cse) = camera.image_mean();
    eprintln!(
        "path {pm:.5} ± {pse:.5}, default {fm:.5} ± {fse:.5} (ratio {:.4}), camera paths alone {cm:.5} ± {cse:.5}; max |z| {:.2} (limit {:.2}), χ² {:.1?} (limit {:.1?}), image z {:.2?}",
        fm / pm,
        v.max_abs_z(),
        v.z_limit,
        v.chi2,
        v.chi2_limit,
        v.image_z
    );
    assert!(!v.changed(), "the default differs from path beyond noise");
    // Without the map's light the image loses the in-scattered sunlight: a third or more,
    // far beyond the noise of either.
    assert!(cm < 0.67 * pm, "camera paths alone {cm} vs path {pm}");
    assert!((pm - cm) > 10.0 * (pse * pse + cse * cse).sqrt());
}

/// The volume caustic map is traced in parallel batches and read by every render thread: the
/// same bytes for 1, 2 and 7 threads, on the gallery's tank with enough photons per pass for
/// several batches (20 000: 10 batches of 2 048).
#[test]
fn volume_caustics_are_the_same_for_any_thread_count() {
    use caustic::render::{RenderOptions, render};
    let text =
        std::fs::read_to_string(crate::common::root().join("benches/scenes/volume_caustic.ron"))
            .expect("scene");
    let text = text.replace(
        "width: 320, height: 240, samples_per_pixel: 64",
        "width: 40, height: 30, samples_per_pixel: 3",
    );
    let mut scene = scene_from_text(&text);
    scene.params.photons.caustic = 20_000;
    let images: Vec<Vec<Vec3>> = [1, 2, 7]
        .iter()
        .map(|&t| {
            let options = RenderOptions {
                threads: Some(t),
                ..RenderOptions::default()
            };
            render(&scene, &options).expect("renders").film.pixels
        })
        .collect();
    assert!(images[0].iter().any(|p| p.max_element() > 0.0));
    assert!(images[0] == images[1] && images[1] == images[2]);
}

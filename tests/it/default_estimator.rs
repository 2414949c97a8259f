//! The default estimator (issue #24): which integrator a scene gets when it names none, when it
//! names one and when the command line names one; a scene without a specular caster renders
//! the path tracer's bytes without a photon pass; and the light's image in rippled water
//! converges without single-sample glints (`benches/scenes/pool.ron`, small).

use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render::{Film, RenderOptions, render};
use caustic::settings::IntegratorKind;

use crate::common::{root, scene_from_text};

/// A small scene, with a glass ball when `glass`, naming `integrator` when given.
fn scene(glass: bool, integrator: Option<IntegratorKind>) -> String {
    let integrator = integrator.map_or(String::new(), |k| format!(", integrator: {k:?}"));
    let ball = if glass {
        r#"Sphere(material: "glass", center: (0, 0.5, 0), radius: 0.3),"#
    } else {
        r#"Sphere(material: "floor", center: (0, 0.5, 0), radius: 0.3),"#
    };
    format!(
        r#"Scene(
    render: (width: 16, height: 12, samples_per_pixel: 4, max_depth: 8, seed: 3{integrator}),
    camera: Pinhole(eye: (0, 1.5, 3), look_at: (0, 0.3, 0), fov_y: 40),
    materials: {{
        "floor": (color: (0.7, 0.7, 0.7)),
        "glass": (color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5),
    }},
    lights: [ Sphere(center: (0, 2, 0), radius: 0.1, power: (30, 30, 30)) ],
    nodes: [
        Quad(material: "floor", size: (6, 6), transform: [RotateX(-90)]),
        {ball}
    ],
)"#
    )
}

#[test]
fn a_scene_without_integrator_gets_path_ppm_with_a_specular_caster_and_path_without() {
    let with = scene_from_text(&scene(true, None));
    assert_eq!(with.params.integrator, IntegratorKind::PathPpm);
    let choice = with
        .params
        .default_estimator
        .expect("the default was chosen");
    assert_eq!(choice.specular_casters, 1);
    // 16 × 12 pixels: the per-pass budget's lower bound.
    assert_eq!(choice.photons.map(|p| p.caustic), Some(1000));
    let without = scene_from_text(&scene(false, None));
    assert_eq!(without.params.integrator, IntegratorKind::Path);
    let choice = without
        .params
        .default_estimator
        .expect("the default was chosen");
    assert_eq!((choice.specular_casters, choice.photons), (0, None));
}

#[test]
fn a_scene_naming_an_integrator_gets_that_one_with_or_without_a_caster() {
    for &kind in IntegratorKind::ALL {
        for glass in [false, true] {
            let s = scene_from_text(&scene(glass, Some(kind)));
            assert_eq!(s.params.integrator, kind, "glass: {glass}");
            assert!(
                s.params.default_estimator.is_none(),
                "{kind:?}: no default chosen"
            );
            let it = caustic::integrators::Integrator::prepare(&s);
            let progressive = matches!(kind, IntegratorKind::Ppm | IntegratorKind::PathPpm);
            assert_eq!(it.is_progressive(), progressive, "{kind:?}");
        }
    }
}

#[test]
fn the_command_lines_integrator_wins_over_the_scene_and_the_default() {
    // pool.ron names no integrator (default: path-ppm, the water is a caster); refraction.ron
    // names Whitted.
    for file in ["benches/scenes/pool.ron", "scenes/refraction.ron"] {
        let path = root().join(file);
        for &kind in IntegratorKind::ALL {
            let mut overrides = SceneOverrides::default();
            overrides.render.integrator = Some(kind);
            let p = prepare(&path, &overrides).expect("prepares");
            assert_eq!(p.render_scene.params.integrator, kind, "{file}");
            assert!(p.render_scene.params.default_estimator.is_none(), "{file}");
        }
        let p = prepare(&path, &SceneOverrides::default()).expect("prepares");
        let expected = if file.contains("pool") {
            IntegratorKind::PathPpm
        } else {
            IntegratorKind::Whitted
        };
        assert_eq!(p.render_scene.params.integrator, expected, "{file}");
    }
}

#[test]
fn without_a_specular_caster_the_default_renders_the_path_tracers_bytes_and_traces_no_photons() {
    let default = render(
        &scene_from_text(&scene(false, None)),
        &RenderOptions::default(),
    )
    .expect("renders");
    let path = render(
        &scene_from_text(&scene(false, Some(IntegratorKind::Path))),
        &RenderOptions::default(),
    )
    .expect("renders");
    assert_eq!(default.film.to_bytes(), path.film.to_bytes());
    assert!(default.film.mean().x > 0.0, "the scene is lit");
    assert!(default.stats.progressive.is_none(), "no photon pass");
    assert_eq!(default.stats.photon_estimates, 0);
}

/// The largest channel value over the film.
fn brightest(f: &Film) -> f32 {
    f.pixels.iter().map(|p| p.max_element()).fold(0.0, f32::max)
}

/// `benches/scenes/pool.ron` at 64 × 48, `spp` samples per pixel, with `integrator` (the default when
/// `None`) and `seed`.
fn pool(integrator: Option<IntegratorKind>, spp: u32, seed: u64) -> Film {
    let overrides = SceneOverrides {
        render: caustic::scene::schema::RenderSettings {
            width: Some(64),
            height: Some(48),
            samples_per_pixel: Some(spp),
            seed: Some(seed),
            integrator,
            ..Default::default()
        },
        ..SceneOverrides::default()
    };
    let p =
        prepare(&root().join("benches/scenes/pool.ron"), &overrides).expect("pool.ron prepares");
    render(&p.render_scene, &RenderOptions::default())
        .expect("renders")
        .film
}

#[test]
fn the_lights_image_in_rippled_water_has_no_single_sample_glints_at_any_seed() {
    // The camera does not see the light directly (it is above the view), only its reflection in
    // the water: a glint of radiance F · 2000 with F ≈ 0.03 at these angles, over a floor of
    // radiance < 1 seen through the water. The reference brightest pixel is Whitted's at 256
    // spp: Whitted follows both delta branches, so the glint is exact up to antialiasing (its
    // floor under water is approximate, but three orders of magnitude dimmer).
    let reference = brightest(&pool(Some(IntegratorKind::Whitted), 256, 1));
    eprintln!("reference brightest pixel {reference}");
    assert!(
        reference > 20.0 && reference < 1000.0,
        "the glint is in view and the light is not: {reference}"
    );
    let spp = 16;
    let mut path_worst = 0.0f32;
    for seed in 1..=4 {
        let default = brightest(&pool(None, spp, seed));
        let path = brightest(&pool(Some(IntegratorKind::Path), spp, seed));
        eprintln!("seed {seed}: default {default}, path {path} (reference {reference})");
        assert!(
            default <= 1.5 * reference,
            "seed {seed}: the default's brightest pixel {default} > 1.5 × {reference}"
        );
        path_worst = path_worst.max(path / reference);
    }
    // The check has power: the path tracer, which chooses the reflection with probability F,
    // reads ~2000 / spp at a pixel where one sample chose it.
    assert!(
        path_worst > 1.5,
        "path's worst brightest pixel is only {path_worst} × the reference"
    );
}

/// Settings resolved once (issue #41): the default estimator's per-pass budget beats the
/// file's photon counts, but counts stated on the command line (`--set`, `--caustic-photons`)
/// beat it; a named integrator reads the file's; `--set` reaches a setting the file leaves
/// unset (`photons.caustic_filter.k` over the default cone).
#[test]
fn photon_counts_resolve_command_line_then_default_estimator_then_file() {
    let text = scene(true, None).replace(
        "lights: [",
        "photons: (caustic: 123456, gather: 77),\n    lights: [",
    );
    let dir = tempfile::tempdir().expect("temp dir");
    let path = dir.path().join("stated.ron");
    std::fs::write(&path, text).expect("writes the scene");
    let params = |o: &SceneOverrides| prepare(&path, o).expect("prepares").render_scene.params;

    let file = params(&SceneOverrides::default());
    assert_eq!(file.integrator, IntegratorKind::PathPpm);
    // 16 × 12 pixels: the per-pass budget's lower bound and its k, no global map.
    let p = &file.photons;
    assert_eq!((p.caustic, p.caustic_gather, p.global), (1000, 10, 0));
    assert_eq!(
        p.gather, 77,
        "the file's gather stands: the default does not choose it"
    );
    assert!(file.default_estimator.is_some_and(|d| d.photons.is_some()));

    let set = params(&SceneOverrides {
        sets: vec!["photons.caustic=5000".into()],
        ..SceneOverrides::default()
    });
    assert_eq!(
        (set.photons.caustic, set.photons.caustic_gather),
        (5000, 10)
    );
    assert!(set.default_estimator.is_some_and(|d| d.photons.is_none()));

    let mut flag = SceneOverrides::default();
    flag.photons.caustic = Some(4000);
    assert_eq!(params(&flag).photons.caustic, 4000);

    let mut named = SceneOverrides::default();
    named.render.integrator = Some(IntegratorKind::Photon);
    let named = params(&named);
    assert_eq!(
        (named.photons.caustic, named.photons.global),
        (123_456, 200_000)
    );
    assert!(named.default_estimator.is_none());

    let k = params(&SceneOverrides {
        sets: vec!["photons.caustic_filter.k=2".into()],
        ..SceneOverrides::default()
    });
    assert_eq!(k.photons.caustic_cone, Some(2.0));
}

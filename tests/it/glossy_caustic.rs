//! Glossy caustics (issue #27's worst bath pixels): a small light's highlight on a polished but
//! rough metal thrown onto a diffuse wall. The progressive integrators carry such light in the
//! caustic map (photons pass near-specular surfaces, `Bsdf::is_near_specular`, as mirrors) and
//! leave it out of their camera paths; the path tracer finds it by chance. Checked: the photons
//! do reach the wall by way of the metal (photons are stored although nothing in the scene is
//! a mirror or glass, and the photon integrator's delta-only caustic map has nothing to aim at), the default estimator counts the metal as a specular caster, and
//! `path-ppm` and `ppm` render the path tracer's image within noise (the golden block z-test,
//! `caustic::render::golden::BlockTest`, for `path-ppm`; the image mean for `ppm`, whose
//! global map keeps a blur at these pass counts).

use caustic::integrators::photon::build_maps;
use caustic::render::golden::{BlockTest, PixelEstimates};
use caustic::render::{RenderOptions, render};
use caustic::settings::IntegratorKind;
use caustic::shading::NEAR_SPECULAR_ALPHA;

use crate::common::scene_from_text;

/// A white wall facing the camera behind a rough gold plate (perceptual roughness 0.3, GGX α =
/// 0.09, near-specular) that does not touch it; a small sphere light above the plate lights the
/// wall directly and by its blurred reflection in the plate. (Where a diffuse surface meets a
/// near-specular or specular one, a photon disc reaching over the edge reads dark until the
/// radius has shrunk below the distance to the edge, as at any boundary of photon density
/// estimation: the plate keeps away from the wall. The caustic's own edge, where the wall sinks
/// into the plate's shadow, is blurred likewise: 40 000 photons per pass keep that blur below
/// the noise of 64 passes — 4 000 leave it 7–9 % bright over a row at 64 passes, 5 % at 1 024.)
fn reflector(integrator: &str, spp: u32) -> String {
    format!(
        r#"Scene(
    render: (width: 32, height: 32, samples_per_pixel: {spp}, seed: 21{integrator}),
    camera: Pinhole(eye: (0, 0.9, 3), look_at: (0, 0.5, -1), fov_y: 35),
    materials: {{
        "wall": (color: (0.8, 0.8, 0.8)),
        "gold": (diffuse: 0, reflect: 1, conductor: "gold", roughness: 0.3),
    }},
    photons: (global: 0, caustic: 40000, caustic_gather: 20),
    lights: [ Sphere(center: (0, 0.6, 0.3), radius: 0.04, power: (20, 20, 20)) ],
    nodes: [
        Quad(material: "gold", size: (1.6, 1.2), transform: [RotateX(-90)]),
        Quad(material: "wall", size: (4, 4), transform: [Translate(0, 2, -1)]),
    ],
)"#
    )
}

#[test]
fn a_rough_metals_highlight_on_a_wall_comes_from_photons_and_matches_the_path_tracer() {
    let scene = scene_from_text(&reflector(", integrator: Path", 1));
    let gold = scene.material_names.iter().position(|n| n == "gold");
    assert!(
        gold.is_some_and(|g| scene.materials[g]
            .bsdf
            .is_near_specular(NEAR_SPECULAR_ALPHA)),
        "the plate must be near-specular"
    );
    // The photon integrator's maps (delta lobes only) have nothing to aim at; the progressive
    // integrators' maps do, and store photons on the wall (checked through the render summary).
    let photon = build_maps(&scene_from_text(&reflector(", integrator: Photon", 1)));
    assert!(
        photon.caustic.is_none(),
        "{:?}",
        photon.summary.caustic_skipped
    );

    let default = scene_from_text(&reflector("", 24));
    assert_eq!(default.params.integrator, IntegratorKind::PathPpm);
    assert_eq!(
        default.params.default_estimator.map(|d| d.specular_casters),
        Some(1)
    );

    let path = render(
        &scene_from_text(&reflector(", integrator: Path", 1024)),
        &RenderOptions::default(),
    )
    .expect("renders");
    let path_est = PixelEstimates::from_sums(&path.sums);
    let ppm = render(
        &scene_from_text(&reflector(", integrator: PathPpm", 64)),
        &RenderOptions::default(),
    )
    .expect("renders");
    let stored = ppm.stats.progressive.map_or(0, |p| p.totals.stored);
    assert!(
        stored > 100,
        "glossy caustic photons should land on the wall: {stored}"
    );
    let v = BlockTest::default()
        .compare(&path_est, &PixelEstimates::from_sums(&ppm.sums))
        .expect("same size");
    eprintln!(
        "path-ppm vs path: max |z| {:.2} (limit {:.2}), χ² {:.1?} / {:?}, image z {:.2?}",
        v.max_abs_z(),
        v.z_limit,
        v.chi2,
        v.dof,
        v.image_z
    );
    assert!(!v.changed(), "path-ppm differs from path");

    let ppm_only = render(
        &scene_from_text(&reflector(", integrator: Ppm", 64)),
        &RenderOptions::default(),
    )
    .expect("renders");
    let (a, b) = (ppm_only.film.mean(), path.film.mean());
    eprintln!("ppm mean {a} vs path {b}");
    assert!((a.x / b.x - 1.0).abs() < 0.03, "ppm {a} vs path {b}");
}

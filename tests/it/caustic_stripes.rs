//! The photon integrator's caustic map keeps a caustic's flux (the brief "photonbias": on
//! `scenes/bath.ron`'s tub floor `--integrator photon` read 4–6 % above `ppm` and `path-ppm`).
//!
//! A delta sun straight overhead (irradiance E = 1) shines through ten strips of smooth glass
//! (η = 1.5, one interface each, 0.1 m wide, 0.1 m apart, 0.5 m up) onto a Lambert floor. At
//! normal incidence a strip passes `1 − F`, `F = ((η − 1)/(η + 1))² = 0.04`, and bends nothing,
//! so the caustic on the floor is a square wave: irradiance 0.96 under the strips, 0 under the
//! gaps, and its mean over whole periods is exactly 0.96 · ½ = 0.48 W/m² (closed form; the
//! light that the strips reflect goes back up to the sky, and photons end where they first land
//! on the diffuse floor, so nothing else enters the caustic map).
//!
//! Jensen's k-nearest estimate (the map's disc grown around the query until it holds k
//! photons, the estimate of `main` before this change) reads the dark gaps with discs that
//! reach into the lit strips, while in the strips its discs stay small: its mean over the
//! periods is well above the closed form (measured below, and asserted, on the same photons).
//! The photon integrator's estimate gives each photon a disc of its own radius
//! (`integrators::photon::discs`), which moves light sideways and keeps its total: the mean is
//! the closed form within its noise.

use glam::Vec3;

use caustic::integrators::photon::walls::Walls;
use caustic::integrators::photon::{Kernel, PhotonMap, build_maps};
use caustic::spatial::KdTree;

use crate::common::scene_from_text;

/// The scene: ten glass strips over a floor under a delta sun at the zenith, `caustic` photons
/// read by the `k` = `gather` nearest with Jensen's cone filter (the defaults' k 1.1).
fn stripes(caustic: u32, gather: u32) -> String {
    let strips: String = (0..10)
        .map(|i| {
            let x = -0.9 + 0.2 * f64::from(i);
            format!(
                "        Quad(material: \"glass\", size: (0.1, 2), transform: [RotateX(-90), Translate({x:.3}, 0.5, 0)]),\n"
            )
        })
        .collect();
    format!(
        r#"Scene(
    render: (width: 8, height: 8, seed: 3, integrator: Photon),
    camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
    materials: {{ "floor": (color: (0.5, 0.5, 0.5)), "glass": (color: (1, 1, 1), transmit: 1, ior: 1.5) }},
    photons: (global: 0, caustic: {caustic}, caustic_gather: {gather}, caustic_filter: Cone(k: 1.1), final_gather: 0),
    lights: [ Distant(direction: (0, 1, 0), irradiance: (1, 1, 1), angular_radius: 0) ],
    nodes: [
        Quad(material: "floor", size: (4, 4), transform: [RotateX(-90)]),
{strips}    ],
)"#
    )
}

/// Mean irradiance of `map` over the floor's window x, z ∈ [−0.5, 0.5) (five whole periods of
/// the stripes), by the midpoint rule on 400 × 20 points: 80 a period across the stripes, where
/// the estimate's blurred edges (a few centimetres wide, not symmetric about the edge: photons
/// at an edge have wider discs) need them; a 40-point grid read the discs 3.4 % high.
fn window_mean(map: &PhotonMap, walls: Walls<'_>) -> f64 {
    let (nx, nz) = (400, 20);
    let mut sum = 0.0;
    for i in 0..nx {
        for j in 0..nz {
            let x = -0.5 + (i as f32 + 0.5) / nx as f32;
            let z = -0.5 + (j as f32 + 0.5) / nz as f32;
            sum += f64::from(
                map.irradiance(Vec3::new(x, 0.0, z), Vec3::Y, walls)
                    .radiance
                    .x,
            );
        }
    }
    sum / f64::from(nx * nz)
}

#[test]
fn a_striped_caustic_keeps_its_flux_in_the_photon_integrators_estimate() {
    let exact = 0.96 * 0.5;
    let scene = scene_from_text(&stripes(400_000, 40));
    let maps = build_maps(&scene);
    let map = maps.caustic.as_ref().expect("a caustic map");
    let walls = Walls::of(&scene, None);
    let ours = window_mean(map, walls);
    // Jensen's k-nearest estimate over the same photons (no discs: what `main` read).
    let tree = KdTree::build(map.photons().to_vec()).expect("finite photons");
    let mut knn = PhotonMap::new(tree, 40, map.max_radius(), Kernel::Cone(1.1));
    knn.mark_walls(walls);
    let theirs = window_mean(&knn, walls);
    // The flux the photons brought into the window (1 m²): what an estimate that keeps flux
    // reads on average there, whatever its blur (the stripes are periodic across the window's
    // edges, so as much blurred light leaves it as enters).
    let brought: f64 = map
        .photons()
        .iter()
        .filter(|ph| {
            let p = ph.position();
            (-0.5..0.5).contains(&p.x) && (-0.5..0.5).contains(&p.z)
        })
        .map(|ph| f64::from(ph.power().x))
        .sum();
    eprintln!(
        "stripes: exact {exact:.4}; photons brought {brought:.4} ({:+.2} %); photon discs {ours:.4} ({:+.2} %); k-nearest {theirs:.4} ({:+.2} %); {} photons stored",
        100.0 * (brought / exact - 1.0),
        100.0 * (ours / exact - 1.0),
        100.0 * (theirs / exact - 1.0),
        map.len()
    );
    assert!(
        (brought / exact - 1.0).abs() < 0.01,
        "the photons brought {brought} W into the window, the closed form {exact} W"
    );
    // The window holds about 38 000 photons (Owen-scrambled Sobol, so less noisy than their
    // Poisson count's 0.5 %); measured through a 200 × 200 render of the window's caustic
    // layer: +0.6 % (k-nearest: +5.4 %).
    assert!(
        (ours / exact - 1.0).abs() < 0.015,
        "photon discs: {ours} against the closed form {exact}"
    );
    assert!(
        theirs / exact > 1.03,
        "the k-nearest estimate was expected to read the gaps too bright: {theirs} vs {exact}"
    );
}

//! Perturbed shading normals (ripples, bump maps) at grazing angles and in the dark: no black
//! speckles, no rays sent into surfaces, no NaN at singular points (hard cases B.9–B.11, B.13;
//! B.12's light leak is prevented by requiring ωᵢ above the geometric normal, see
//! `render/whitted.rs`, and tested with controls that show the test could fail).
//!
//! Note: in this material model a back-facing shading normal would not by itself give black
//! pixels (mirror and refraction fall back to the geometric normal, Lambert only tests the
//! light side), so the speckle test also asserts the remedy directly: no normal that is shaded
//! with faces away from the viewer.

use caustic::geometry::Ray;
use caustic::render::{Film, RenderOptions, render};
use caustic::render_scene::RenderScene;
use caustic::render_scene::texture::Lookup;
use glam::Vec3;

use super::support::scene;

fn film(s: &RenderScene) -> (Film, u64) {
    let out = render(s, &RenderOptions::default()).expect("renders");
    (out.film, out.stats.nan_samples)
}

/// Water (ripples tilting the normal up to ~30°) or a bumped diffuse floor, seen 2° above the
/// plane, over a lit floor and under a bright sky.
fn grazing(material: &str, textures: &str) -> RenderScene {
    scene(&format!(
        r#"Scene(
            render: (width: 160, height: 60, samples_per_pixel: 2, seed: 9, background: (0.5, 0.6, 0.8), max_depth: 6),
            camera: Pinhole(eye: (0, 0.35, 10), look_at: (0, 0, 0), fov_y: 20),
            textures: {{ {textures} }},
            materials: {{ "surface": ({material}), "ground": (color: (0.6, 0.5, 0.4)) }},
            lights: [Point(position: (3, 30, 5), power: (90000, 90000, 90000))],
            nodes: [
                Quad(material: "surface", size: (40, 40), transform: [RotateX(-90)]),
                Quad(material: "ground", size: (40, 40), transform: [RotateX(-90), Translate(0, -1, 0)]),
            ],
        )"#
    ))
}

const RIPPLES: &str =
    r#""t": Ripple(centers: [(0.5, 0.5), (0.3, 0.6)], frequency: 400, amplitude: 0.0577)"#;
const TILES: &str =
    r#""t": HeightMap(file: "assets/tiles_height.png", depth: 0.05, tile: (40, 40))"#;

/// One primary ray per pixel of `s` that hits a bumped surface: what `visit` is given.
struct BumpedHit<'a> {
    /// Direction towards the camera.
    wo: Vec3,
    /// The surface point.
    sp: caustic::render_scene::SurfacePoint,
    /// Its material.
    material: &'a caustic::render_scene::SurfaceMaterial,
    /// The raw bumped normal (outward), before the shading-normal rule.
    raw: Vec3,
}

/// Calls `visit` for every pixel-centre primary ray of `s` that hits a bumped surface.
fn for_each_bumped_hit(s: &RenderScene, mut visit: impl FnMut(&BumpedHit)) {
    let (w, h) = (s.params.width, s.params.height);
    for y in 0..h {
        for x in 0..w {
            let ray = s.camera.ray(x as f32 + 0.5, y as f32 + 0.5, w, h);
            let Some(hit) = s.geometry.intersect(&ray) else {
                continue;
            };
            let sp = s.geometry.surface(&ray, &hit);
            let material =
                &s.materials[s.objects[sp.object as usize].material.expect("material") as usize];
            let Some(t) = material.bump else { continue };
            let sps = s.geometry.surface_params(&sp);
            let l = Lookup {
                p: sp.p,
                uv: sps.uv,
                footprint: caustic::texture::Footprint::POINT,
                width: 0.0,
            };
            let raw = s.textures[t as usize].bump(sp.ns, sps.dpdu, sps.dpdv, &l);
            visit(&BumpedHit {
                wo: -ray.dir,
                sp,
                material,
                raw,
            });
        }
    }
}

/// Over the primary rays hitting bumped surfaces: the fraction whose raw perturbed normal faces
/// away from the viewer although the geometric normal faces it (the case the remedy exists
/// for), and how many of the normals actually shaded with still face away (must be none).
fn back_facing(s: &RenderScene) -> (f64, u32) {
    let (mut hits, mut back, mut shaded_back) = (0u32, 0u32, 0u32);
    for_each_bumped_hit(s, |b| {
        hits += 1;
        if b.sp.ng.dot(b.wo) > 0.0 && b.raw.dot(b.wo) < 0.0 {
            back += 1;
        }
        if s.shading_point(b.material, &b.sp, b.wo, 0.0).ns.dot(b.wo) <= 0.0 {
            shaded_back += 1;
        }
    });
    (f64::from(back) / f64::from(hits.max(1)), shaded_back)
}

/// Pixels below the horizon (the surface fills rows `from_row..`) that are exactly black.
fn black_pixels(f: &Film, from_row: u32) -> usize {
    (from_row..f.height)
        .flat_map(|y| (0..f.width).map(move |x| (x, y)))
        .filter(|&(x, y)| f.get(x, y) == Vec3::ZERO)
        .count()
}

#[test]
fn grazing_ripples_and_bumps_leave_no_black_speckles() {
    for (name, material, textures) in [
        (
            "rippled water",
            r#"color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.33, bump: "t""#,
            RIPPLES,
        ),
        (
            "rippled mirror",
            r#"color: (0.9, 0.9, 0.9), diffuse: 0, reflect: 1, bump: "t""#,
            RIPPLES,
        ),
        (
            "bumped diffuse tiles",
            r#"color: (0.8, 0.8, 0.8), bump: "t""#,
            TILES,
        ),
    ] {
        let s = grazing(material, textures);
        let (back, shaded_back) = back_facing(&s);
        let (f, nan) = film(&s);
        // The horizon is at the middle row; start a little below it.
        let black = black_pixels(&f, f.height / 2 + 2);
        eprintln!(
            "{name}: {:.1} % back-facing raw normals, {black} black pixels",
            back * 100.0
        );
        assert!(back >= 0.05, "{name}: the case is not exercised ({back})");
        assert_eq!(shaded_back, 0, "{name}: shaded with back-facing normals");
        assert_eq!(nan, 0, "{name}: NaN/Inf samples");
        assert_eq!(black, 0, "{name}: black speckles");
    }
}

/// Hard cases B.10/B.11 in scenes: every mirror and refracted direction leaving a rippled or
/// bumped surface seen at a grazing angle leaves on the correct side of the geometric surface,
/// where the raw perturbed normals would often send them the wrong way.
#[test]
fn rippled_and_bumped_specular_rays_leave_on_the_correct_side() {
    use caustic::shading::optics::{reflect, refract};
    for (name, material, textures) in [
        (
            "rippled water",
            r#"color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.33, bump: "t""#,
            RIPPLES,
        ),
        (
            "bumped glass",
            r#"color: (1, 1, 1), diffuse: 0, transmit: 1, ior: 1.5, bump: "t""#,
            TILES,
        ),
        (
            "rippled mirror",
            r#"color: (0.9, 0.9, 0.9), diffuse: 0, reflect: 1, bump: "t""#,
            RIPPLES,
        ),
    ] {
        let s = grazing(material, textures);
        let (mut rays, mut raw_wrong, mut wrong) = (0u32, 0u32, 0u32);
        for_each_bumped_hit(&s, |b| {
            let sh = s.shading_point(b.material, &b.sp, b.wo, 0.0);
            let lobes = sh.bsdf.delta_lobes(b.wo, sh.ns, sh.ng, sh.entering);
            rays += 1;
            if lobes.reflect_dir.dot(sh.ng) <= 0.0 {
                wrong += 1;
            }
            if lobes.refract.is_some_and(|(t, _)| t.dot(sh.ng) >= 0.0) {
                wrong += 1;
            }
            // What the raw perturbed normal alone would have done.
            let raw = if sh.entering { b.raw } else { -b.raw };
            let raw_bad = reflect(b.wo, raw).dot(sh.ng) <= 0.0
                || sh.bsdf.ior().is_some_and(|ior| {
                    refract(b.wo, raw, 1.0 / ior).is_some_and(|t| t.dot(sh.ng) >= 0.0)
                });
            if raw_bad {
                raw_wrong += 1;
            }
        });
        eprintln!(
            "{name}: {rays} rays, raw normals would send {raw_wrong} the wrong way, shaded: {wrong}"
        );
        assert!(rays > 4000, "{name}");
        assert!(
            raw_wrong * 20 >= rays,
            "{name}: the case is not exercised ({raw_wrong} of {rays})"
        );
        assert_eq!(wrong, 0, "{name}");
    }
}

fn normal_at(s: &RenderScene, from: Vec3, to: Vec3) -> Vec3 {
    let ray = Ray::new(from, (to - from).normalize());
    let hit = s.geometry.intersect(&ray).expect("hits");
    let sp = s.geometry.surface(&ray, &hit);
    let m = s.objects[sp.object as usize].material.expect("material");
    s.shading_point(&s.materials[m as usize], &sp, -ray.dir, 0.0)
        .ns
}

#[test]
fn singular_points_give_finite_exact_normals() {
    // A ripple centred exactly under the ray: the normal is exactly geometric (B.13c).
    let s = scene(
        r#"Scene(
            camera: Pinhole(eye: (0, 0, 5), look_at: (0, 0, 0), fov_y: 30),
            textures: { "w": Ripple(centers: [(0.5, 0.5)], frequency: 50, amplitude: 0.01, decay: 1) },
            materials: { "m": (diffuse: 0, transmit: 1, ior: 1.33, bump: "w") },
            lights: [Point(position: (0, 0, 5), power: (10, 10, 10))],
            nodes: [Quad(material: "m", size: (2, 2))],
        )"#,
    );
    assert_eq!(normal_at(&s, Vec3::Z * 5.0, Vec3::ZERO), Vec3::Z);
    // Bumps at a sphere's poles, where ∂p/∂u vanishes (B.13b): finite, unit, near the pole.
    for textures in [
        r#""b": Noise(frequency: 4, depth: 0.05)"#,
        r#""b": HeightMap(file: "assets/tiles_height.png", depth: 0.01, tile: (8, 4))"#,
        r#""b": Ripple(centers: [(0.5, 0.0)], frequency: 40, amplitude: 0.01)"#,
    ] {
        let s = scene(&format!(
            r#"Scene(
                camera: Pinhole(eye: (0, 5, 0.1), look_at: (0, 0, 0), fov_y: 30),
                textures: {{ {textures} }},
                materials: {{ "m": (bump: "b") }},
                lights: [Point(position: (0, 5, 0), power: (10, 10, 10))],
                nodes: [Sphere(material: "m", radius: 1)],
            )"#
        ));
        for pole in [Vec3::Y, -Vec3::Y] {
            let n = normal_at(&s, pole * 5.0, Vec3::ZERO);
            assert!(
                n.is_finite() && (n.length() - 1.0).abs() < 1e-5 && n.dot(pole) > 0.5,
                "{textures} at {pole}: {n}"
            );
        }
    }
}

#[test]
fn zero_depth_and_zero_amplitude_bumps_are_bit_identical_to_none() {
    let render_with = |bump: &str| {
        let s = scene(&format!(
            r#"Scene(
                render: (width: 40, height: 30, samples_per_pixel: 2),
                camera: Pinhole(eye: (0, 2, 4), look_at: (0, 0.5, 0), fov_y: 40),
                textures: {{
                    "flat_tiles": HeightMap(file: "assets/tiles_height.png", depth: 0, tile: (4, 4)),
                    "calm": Ripple(centers: [(0.5, 0.5)], frequency: 40, amplitude: 0),
                    "still_noise": Noise(frequency: 3),
                }},
                materials: {{
                    "floor": (color: (0.7, 0.7, 0.7), specular: (0.2, 0.2, 0.2), shininess: 30 {bump}),
                    "glass": (diffuse: 0, transmit: 1, ior: 1.5 {bump}),
                }},
                lights: [Point(position: (1, 4, 3), power: (300, 300, 300))],
                nodes: [
                    Quad(material: "floor", size: (6, 6), transform: [RotateX(-90)]),
                    Sphere(material: "glass", radius: 0.5, center: (0, 0.5, 0)),
                ],
            )"#
        ));
        film(&s).0.pixels
    };
    let none = render_with("");
    for bump in [
        ", bump: \"flat_tiles\"",
        ", bump: \"calm\"",
        ", bump: \"still_noise\"",
    ] {
        assert!(render_with(bump) == none, "{bump} changed the image");
    }
}

/// A rippled diffuse floor lit only by a point light just below it, seen from above.
fn floor_over_a_light(light_y: f32) -> RenderScene {
    scene(&format!(
        r#"Scene(
            render: (width: 64, height: 48, samples_per_pixel: 2, seed: 3, max_depth: 4),
            camera: Pinhole(eye: (0, 3, 3), look_at: (0, 0, 0), fov_y: 40),
            textures: {{ {RIPPLES} }},
            materials: {{ "floor": (color: (0.8, 0.8, 0.8), bump: "t") }},
            lights: [Point(position: (0.3, {light_y}, 0.2), power: (5000, 5000, 5000))],
            nodes: [Quad(material: "floor", size: (6, 6), transform: [RotateX(-90)])],
        )"#
    ))
}

#[test]
fn a_light_below_a_bumped_floor_leaks_nothing() {
    // B.12: the bumped shading normals lean towards a light below the floor, but light only
    // counts when it is above the geometric normal too.
    let below = floor_over_a_light(-0.05);
    let (img, nans) = film(&below);
    assert_eq!(nans, 0);
    let lit = img.pixels.iter().filter(|p| p.max_element() > 0.0).count();
    assert_eq!(lit, 0, "{lit} pixels lit through the floor");

    // Control 1: the setup can leak. At many hits the normal actually shaded with faces the
    // light below (ωᵢ above ns, below ng): a rule on the shading normal alone would light them.
    let light = Vec3::new(0.3, -0.05, 0.2);
    let (mut hits, mut would_leak) = (0u32, 0u32);
    for_each_bumped_hit(&below, |b| {
        hits += 1;
        let wi = (light - b.sp.p).normalize();
        let ns = below.shading_point(b.material, &b.sp, b.wo, 0.0).ns;
        if ns.dot(wi) > 0.0 && b.sp.ng.dot(wi) < 0.0 {
            would_leak += 1;
        }
    });
    assert!(hits > 64 * 48 / 2, "the floor fills the view: {hits} hits");
    assert!(
        f64::from(would_leak) > 0.05 * f64::from(hits),
        "only {would_leak} of {hits} shading normals face the light below: the test could not fail"
    );

    // Control 2: the same floor with the light just above it is lit almost everywhere, so the
    // black image above is the rule at work, not a camera or measurement that sees nothing.
    let (img, _) = film(&floor_over_a_light(0.05));
    let lit = img.pixels.iter().filter(|p| p.max_element() > 0.0).count();
    assert!(
        lit > img.pixels.len() / 2,
        "only {lit} pixels lit from above"
    );
}

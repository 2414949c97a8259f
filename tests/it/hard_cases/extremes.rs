//! Extreme inputs: very bright and very dim lights, tiny images, one sample, zero depth.

use caustic::render::{Region, RenderOptions, render};

use super::support::{render_text, scene};

fn cornell_like(power: &str, extra: &str) -> String {
    let render = if extra.is_empty() {
        "width: 32, height: 32, samples_per_pixel: 2, max_depth: 4".to_string()
    } else {
        extra.to_string()
    };
    format!(
        "Scene(render: (integrator: Whitted, {render}, seed: 9),
          camera: Pinhole(eye: (0, 1, 3.5), look_at: (0, 1, 0), fov_y: 45),
          materials: {{ \"white\": (color: (0.75, 0.75, 0.75)), \"mirror\": (reflect: 1, color: (0.9, 0.9, 0.9)),
                        \"glass\": (transmit: 1, ior: 1.5, color: (1, 1, 1)) }},
          lights: [Sphere(center: (0, 1.8, 0), radius: 0.1, power: ({power}, {power}, {power})),
                   Point(position: (0.5, 1.5, 1), power: ({power}, {power}, {power}))],
          nodes: [Quad(material: \"white\", size: (2, 2), transform: [RotateX(-90)]),
                  Quad(material: \"white\", size: (2, 2), transform: [Translate(0, 1, -1)]),
                  Sphere(material: \"mirror\", center: (-0.4, 0.3, 0), radius: 0.3),
                  Sphere(material: \"glass\", center: (0.4, 0.3, 0.2), radius: 0.3)])"
    )
}

#[test]
fn light_power_scales_the_image_exactly() {
    let (bright, s1) = render_text(&cornell_like("1e6", ""));
    let (dim, s2) = render_text(&cornell_like("1e-6", ""));
    assert_eq!(s1.nan_samples + s2.nan_samples, 0);
    let mut worst = 0.0f64;
    for (b, d) in bright.pixels.iter().zip(&dim.pixels) {
        for (x, y) in b.to_array().into_iter().zip(d.to_array()) {
            assert!(x.is_finite() && y.is_finite());
            if x > 0.0 {
                worst = worst.max((f64::from(y) * 1e12 / f64::from(x) - 1.0).abs());
            } else {
                assert_eq!(y, 0.0);
            }
        }
    }
    assert!(
        worst < 1e-5,
        "bright/dim ratio deviates from 1e12 by {worst:e}"
    );
    // Not a black image: the centre pixel sees the back wall at (0, 1, -1), lit directly by the
    // point light at (0.5, 1.5, 1) (nothing in between): I = 1e6 / 4π, d² = 4.5, cos = 2 / √4.5,
    // so white (0.75) diffuse gives 0.75 / π · I · cos / d² ≈ 3980 from that light alone. A
    // quarter of that bounds it from below whatever the pixel's jitter and the other light.
    let centre = bright.get(16, 16);
    let expected =
        0.75 / std::f32::consts::PI * (1e6 / (4.0 * std::f32::consts::PI)) * (2.0 / 4.5f32.sqrt())
            / 4.5;
    assert!((expected - 3980.0).abs() < 5.0, "{expected}");
    assert!(
        centre.min_element() > 0.25 * expected,
        "centre pixel {centre} of the bright image is below a quarter of {expected}"
    );
}

#[test]
fn minimal_settings_run_and_a_single_pixel_crop_matches() {
    for extra in [
        "width: 32, height: 32, max_depth: 0",
        "width: 32, height: 32, max_depth: 1",
        "width: 32, height: 32, samples_per_pixel: 1",
    ] {
        let (img, st) = render_text(&cornell_like("50", extra));
        assert_eq!(st.nan_samples, 0, "{extra}");
        assert!(img.mean().max_element() > 0.0, "{extra}");
    }
    let one = scene(&cornell_like(
        "50",
        "width: 1, height: 1, samples_per_pixel: 1",
    ));
    let out = render(&one, &RenderOptions::default()).expect("1x1 renders");
    assert_eq!(out.film.pixels.len(), 1);
    let s = scene(&cornell_like("50", ""));
    let full = render(&s, &RenderOptions::default()).expect("full");
    let crop = render(
        &s,
        &RenderOptions {
            region: Some(Region {
                x: 17,
                y: 9,
                width: 1,
                height: 1,
            }),
            ..Default::default()
        },
    )
    .expect("crop");
    assert_eq!(
        crop.film.pixels[0].to_array().map(f32::to_bits),
        full.film.get(17, 9).to_array().map(f32::to_bits)
    );
}

#[test]
fn albedo_one_mirrors_do_not_create_energy() {
    // Two facing perfect mirrors (albedo exactly 1) with a light between them: a camera ray
    // bouncing max_depth times may carry at most the light's radiance, never more.
    // The light's mirror images lie at z = -2, -6, … on the line x = y = 0.5; the one at z = -6
    // (three reflections) is seen 0.5 / 6.9 = tan 4.1° off-axis, 1.3 pixels in radius, so at
    // least one pixel sees nothing but the light through the mirrors: exactly its radiance.
    let text = "Scene(render: (integrator: Whitted, width: 16, height: 16, samples_per_pixel: 1, max_depth: 40),
        camera: Pinhole(eye: (0, 0, 0.9), look_at: (0, 0, -1), fov_y: 20),
        materials: { \"m\": (reflect: 1, color: (1, 1, 1)) },
        lights: [Sphere(center: (0.5, 0.5, 0), radius: 0.2, power: (1, 1, 1))],
        nodes: [Quad(material: \"m\", size: (4, 4), transform: [Translate(0, 0, -1)]),
                Quad(material: \"m\", size: (4, 4), transform: [Translate(0, 0, 1)])])";
    let (img, st) = render_text(text);
    assert_eq!(st.nan_samples, 0);
    let l_emit = 1.0 / (4.0 * std::f32::consts::PI.powi(2) * 0.2 * 0.2);
    let max = img
        .pixels
        .iter()
        .map(|p| p.max_element())
        .fold(0.0, f32::max);
    assert!(
        max <= l_emit * (1.0 + 1e-5),
        "max {max} > emitted radiance {l_emit}"
    );
    assert!(
        max >= l_emit * (1.0 - 1e-5),
        "max {max}: no pixel sees the light's image at its full radiance {l_emit}"
    );
}

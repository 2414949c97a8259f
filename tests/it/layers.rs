//! EXR layers (`--layers`): the four kinds of light add up to the image, each kind lands where
//! the light transport puts it (a caustic under a glass ball, nothing specular on a wall), and
//! the statistics layers hold each pixel's sample count and the variance of its mean.

use std::collections::HashMap;

use exr::prelude::{FlatSamples, read_all_flat_layers_from_file};

use crate::common::caustic;

/// A glass ball under a small sphere light in a box, 24×24.
const SCENE: &str = "tests/data/layers_scene.ron";

fn channels(path: &std::path::Path) -> HashMap<String, Vec<f32>> {
    let image = read_all_flat_layers_from_file(path).expect("a readable EXR");
    let mut out = HashMap::new();
    for layer in image.layer_data {
        for ch in layer.channel_data.list {
            let values = match ch.sample_data {
                FlatSamples::F32(v) => v,
                other => panic!("float channels expected, found {other:?}"),
            };
            out.insert(ch.name.to_string(), values);
        }
    }
    out
}

fn render(integrator: &str, spp: &str, out: &std::path::Path) -> HashMap<String, Vec<f32>> {
    let o = caustic(&[
        "render",
        SCENE,
        "--integrator",
        integrator,
        "--spp",
        spp,
        "--layers",
        "all",
        "--quiet",
        "-o",
        out.to_str().expect("utf-8 path"),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    channels(out)
}

#[test]
fn light_kinds_add_up_to_the_image_and_land_where_the_transport_puts_them() {
    let dir = tempfile::tempdir().expect("temp dir");
    let mut path_caustic = None;
    for integrator in ["path", "path-ppm", "photon", "whitted"] {
        let c = render(
            integrator,
            "32",
            &dir.path().join(format!("{integrator}.exr")),
        );
        let kinds = ["specular", "direct", "caustic", "indirect"];
        for (i, &r) in c["R"].iter().enumerate() {
            let sum: f32 = kinds.iter().map(|k| c[&format!("{k}.R")][i]).sum();
            assert!(
                (sum - r).abs() <= 1e-5 * r.abs().max(1.0),
                "{integrator}: pixel {i}: parts sum to {sum}, image {r}"
            );
        }
        assert!(c["samples.Y"].iter().all(|&n| n == 32.0), "{integrator}");
        let mean = |name: &str| c[name].iter().sum::<f32>() / c[name].len() as f32;
        // The floor right under the ball (pixel rows 18–21, columns 9–14): the caustic.
        let under = |name: &str| {
            let mut s = 0.0;
            for y in 18..22 {
                for x in 9..15 {
                    s += c[name][y * 24 + x];
                }
            }
            s / 24.0
        };
        // The back wall's top left corner (rows 2–5, columns 2–5): no mirror or glass there.
        let wall = |name: &str| {
            let mut s = 0.0;
            for y in 2..6 {
                for x in 2..6 {
                    s += c[name][y * 24 + x];
                }
            }
            s / 16.0
        };
        eprintln!(
            "{integrator}: under the ball: caustic {} of {}; wall: direct {}, indirect {}",
            under("caustic.R"),
            under("R"),
            wall("direct.R"),
            wall("indirect.R")
        );
        assert_eq!(
            wall("specular.R"),
            0.0,
            "{integrator}: specular light on a wall"
        );
        assert!(wall("direct.R") > 0.0, "{integrator}");
        if integrator == "whitted" {
            // Whitted's transport has no caustics and no indirect light.
            assert_eq!(mean("caustic.R") + mean("indirect.R"), 0.0);
        } else {
            assert!(
                under("caustic.R") > 0.1 * under("R"),
                "{integrator}: caustic {} of {} under the ball",
                under("caustic.R"),
                under("R")
            );
            assert!(
                wall("indirect.R") > 0.0,
                "{integrator}: no indirect light on the wall"
            );
            // The photon integrators' caustic layer agrees with the path tracer's (32 samples:
            // its caustic is noisy; 30 %).
            let reference = *path_caustic.get_or_insert(under("caustic.R"));
            assert!(
                (under("caustic.R") / reference - 1.0).abs() < 0.3,
                "{integrator}: caustic {} vs path {reference}",
                under("caustic.R")
            );
        }
    }
}

#[test]
fn variance_layer_is_the_variance_of_each_pixels_mean() {
    // One pixel, two renders of 1 sample each (indices 0 and 1) and one of both: the layer must
    // hold ((a − m)² + (b − m)²)/(2 − 1)/2 with m the mean of the two single-sample values.
    let dir = tempfile::tempdir().expect("temp dir");
    let one = |range: &str, name: &str| {
        let out = dir.path().join(name);
        let o = caustic(&[
            "render",
            SCENE,
            "--integrator",
            "path",
            "--spp",
            "2",
            "--samples",
            range,
            "--width",
            "1",
            "--height",
            "1",
            "--layers",
            "variance,samples",
            "--quiet",
            "-o",
            out.to_str().expect("utf-8"),
        ]);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
        channels(&out)
    };
    let (a, b, both) = (
        one("0..1", "a.exr"),
        one("1..2", "b.exr"),
        one("0..2", "ab.exr"),
    );
    for ch in ["R", "G", "B"] {
        let (x, y) = (f64::from(a[ch][0]), f64::from(b[ch][0]));
        let m = 0.5 * (x + y);
        let expected = ((x - m).powi(2) + (y - m).powi(2)) / 2.0;
        let got = f64::from(both[&format!("variance.{ch}")][0]);
        assert!(
            (got - expected).abs() <= 1e-4 * expected.max(1e-6),
            "{ch}: variance layer {got}, by hand {expected}"
        );
        assert_eq!(
            a[&format!("variance.{ch}")][0],
            0.0,
            "one sample has no variance"
        );
    }
    assert_eq!(both["samples.Y"][0], 2.0);
}

#[test]
fn layers_need_an_exr_output_and_known_names() {
    let o = caustic(&["render", SCENE, "--layers", "direct", "-o", "x.png"]);
    assert_eq!(o.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&o.stderr).contains("must end in `.exr`"));
    let o = caustic(&["render", SCENE, "--layers", "diffuse", "-o", "x.exr"]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("unknown layer `diffuse`") && err.contains("specular, direct"),
        "{err}"
    );
}

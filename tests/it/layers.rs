//! Layers (`--layers`): the four kinds of light add up to the image, each kind lands where
//! the light transport puts it (a caustic under a glass ball, nothing specular on a wall), and
//! the statistics layers hold each pixel's sample count and the variance of its mean. Beside a
//! PNG image the light layers are pictures, tone-mapped like the image.

use std::collections::HashMap;

use exr::prelude::{FlatSamples, read_all_flat_layers_from_file};

use caustic::render::Film;
use caustic::render::output::to_srgb8;
use caustic::render::tonemap::{Display, Tonemap};

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
fn layers_need_an_exr_or_png_output_and_known_names() {
    let dir = tempfile::tempdir().expect("temp dir");
    let out = |name: &str| dir.path().join(name).to_str().expect("utf-8").to_string();
    let refused = |args: &[&str], why: &str| {
        let o = caustic(args);
        let err = String::from_utf8_lossy(&o.stderr);
        assert_eq!(o.status.code(), Some(2), "{args:?}: {err}");
        assert!(err.contains(why), "{args:?}: {err}");
    };
    refused(
        &["render", SCENE, "--layers", "direct", "-o", &out("x.part")],
        "must end in `.exr` or `.png`",
    );
    // Statistics are numbers, not pictures: only an EXR holds them.
    for layers in ["variance", "direct,samples", "all"] {
        refused(
            &["render", SCENE, "--layers", layers, "-o", &out("x.png")],
            "written only into an EXR output",
        );
    }
    refused(
        &["render", SCENE, "--layers", "diffuse", "-o", &out("x.exr")],
        "unknown layer `diffuse`: the layers are specular, direct",
    );
    // A picture that cannot be written is refused before rendering.
    std::fs::create_dir(dir.path().join("x.caustic.png")).expect("mkdir");
    refused(
        &[
            "render",
            SCENE,
            "--layers",
            "direct,caustic",
            "-o",
            &out("x.png"),
        ],
        "x.caustic.png`: it is a folder",
    );
    refused(
        &[
            "render",
            SCENE,
            "--layers",
            "direct",
            "-o",
            &out("x.png"),
            "--checkpoint",
            &out("x.direct.png"),
        ],
        "is where --layers writes a layer picture",
    );
    assert_eq!(
        files_in(dir.path()),
        ["x.caustic.png"],
        "nothing written but the folder"
    );
}

fn files_in(dir: &std::path::Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(dir)
        .expect("dir")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

/// Renders the test scene with `args` after it into `out`; its standard error.
fn render_to(out: &std::path::Path, args: &[&str]) -> String {
    let mut all = vec!["render", SCENE, "--integrator", "path-ppm", "--spp", "16"];
    all.extend_from_slice(args);
    all.extend(["-o", out.to_str().expect("utf-8 path")]);
    let o = caustic(&all);
    let err = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(o.status.success(), "{err}");
    err
}

/// The film of channels `<prefix>R/G/B` (`R, G, B` for an empty prefix) of a 24×24 EXR.
fn film_of(c: &HashMap<String, Vec<f32>>, prefix: &str) -> Film {
    let mut film = Film::new(24, 24);
    for (i, p) in film.pixels.iter_mut().enumerate() {
        *p = glam::Vec3::new(
            c[&format!("{prefix}R")][i],
            c[&format!("{prefix}G")][i],
            c[&format!("{prefix}B")][i],
        );
    }
    film
}

fn png(path: &std::path::Path) -> image::RgbImage {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .into_rgb8()
}

/// `-o out.png --layers direct,caustic,indirect` writes the image and one picture per layer,
/// `out.<layer>.png`, each exactly its EXR layer through the image's exposure and tone curve
/// (the same `to_srgb8`); the image is the same bytes as without `--layers`.
#[test]
fn png_layers_are_the_exr_layers_through_the_images_tone_curve() {
    let dir = tempfile::tempdir().expect("temp dir");
    let flags = [
        "--tonemap",
        "aces",
        "--set",
        "render.exposure=0.6",
        "--quiet",
        // The plain render's PNG is the raw estimate, as the layers' image is.
        "--no-denoise",
    ];
    let with_layers = [&flags[..], &["--layers", "direct,caustic,indirect"]].concat();
    let (exr, png_out, plain) = (
        dir.path().join("a.exr"),
        dir.path().join("a.png"),
        dir.path().join("plain.png"),
    );
    render_to(&exr, &with_layers);
    render_to(&png_out, &with_layers);
    render_to(&plain, &flags);
    assert_eq!(
        files_in(dir.path()),
        [
            "a.caustic.png",
            "a.direct.png",
            "a.exr",
            "a.indirect.png",
            "a.png",
            "plain.png"
        ]
    );
    let bytes = |p: &std::path::Path| std::fs::read(p).expect("readable");
    assert!(
        bytes(&png_out) == bytes(&plain),
        "--layers changed the image"
    );
    let c = channels(&exr);
    let display = Display {
        exposure: 0.6,
        tonemap: Tonemap::Aces,
    };
    for (file, prefix) in [
        ("a.png", ""),
        ("a.direct.png", "direct."),
        ("a.caustic.png", "caustic."),
        ("a.indirect.png", "indirect."),
    ] {
        let expected = to_srgb8(&film_of(&c, prefix), display);
        let got = png(&dir.path().join(file));
        assert!(
            got == expected,
            "{file} is not its EXR layer through the tone curve"
        );
        let lit = got.pixels().filter(|p| p.0 != [0, 0, 0]).count();
        assert!(lit >= 8, "{file}: only {lit} pixels are not black");
    }
}

/// The pictures are in the image's units: decoded to linear light (sRGB, then the exposure;
/// the linear curve, where nothing clips), the four light layers add up to the image within
/// the rounding to 8 bits.
#[test]
fn png_layers_add_up_to_the_image_in_linear_light() {
    const EXPOSURE: f64 = 0.5;
    let dir = tempfile::tempdir().expect("temp dir");
    let out = dir.path().join("b.png");
    let err = render_to(
        &out,
        &[
            "--set",
            "render.exposure=0.5",
            "--layers",
            "specular,direct,caustic,indirect",
        ],
    );
    let kinds = ["specular", "direct", "caustic", "indirect"];
    let names: Vec<String> = kinds
        .iter()
        .map(|k| format!("`{}`", dir.path().join(format!("b.{k}.png")).display()))
        .collect();
    assert!(
        err.contains(&format!("layers: {}", names.join(", "))),
        "the render names the pictures it wrote: {err}"
    );
    // The linear values an 8-bit value `v` stands for: [lower, upper] (radiance).
    let decode = |x: f64| {
        let x = x.clamp(0.0, 1.0);
        let lin = if x <= 0.040_45 {
            x / 12.92
        } else {
            ((x + 0.055) / 1.055).powf(2.4)
        };
        lin / EXPOSURE
    };
    let range = |v: u8| {
        let v = f64::from(v);
        (decode((v - 0.5) / 255.0), decode((v + 0.5) / 255.0))
    };
    let image = png(&out);
    let layers: Vec<image::RgbImage> = kinds
        .iter()
        .map(|k| png(&dir.path().join(format!("b.{k}.png"))))
        .collect();
    let (mut checked, mut clipped) = (0, 0);
    for (x, y, p) in image.enumerate_pixels() {
        for ch in 0..3 {
            let values: Vec<u8> = layers.iter().map(|l| l.get_pixel(x, y).0[ch]).collect();
            if p.0[ch] == 255 || values.contains(&255) {
                clipped += 1;
                continue;
            }
            let (lo, hi) = range(p.0[ch]);
            let (sum_lo, sum_hi) = values.iter().fold((0.0, 0.0), |(a, b), &v| {
                let (l, h) = range(v);
                (a + l, b + h)
            });
            let slack = 1e-4 * hi.max(1.0);
            assert!(
                sum_lo <= hi + slack && sum_hi >= lo - slack,
                "pixel ({x}, {y}) channel {ch}: the layers {values:?} add up to [{sum_lo},                  {sum_hi}], the image {} is [{lo}, {hi}]",
                p.0[ch]
            );
            checked += 1;
        }
    }
    assert!(
        checked > 3 * clipped,
        "too few unclipped values: {checked} checked, {clipped} clipped"
    );
    // Not a sum of one layer: the direct light and the caustic both show.
    for (k, layer) in kinds.iter().zip(&layers).skip(1).take(2) {
        let lit = layer.pixels().filter(|p| p.0 != [0, 0, 0]).count();
        assert!(lit >= 8, "{k}: only {lit} pixels are not black");
    }
}

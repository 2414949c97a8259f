//! The pictures in README.md and docs/ are what the renderer draws today (issue 17 §2).
//!
//! `docs/images/manifest.txt` is the one table of how each image is made (a scene and the flags
//! of `caustic render`); `scripts/doc_images.sh` renders it. Here:
//!
//! - every image under `docs/images/` is in the manifest and every image that README.md or a
//!   file in `docs/` shows is one of them (so none is made by hand or left over). A line with
//!   `--layers` (light layers only) makes its image and one picture per layer beside it,
//!   `<stem>.<layer>.png`, as `caustic render` writes them. The exception: the few images too
//!   slow to render here, each made by a script of its own ([`SCRIPT_MADE`]: the image must
//!   exist and its script must name it; it is not compared);
//! - each committed image matches a fresh render of its manifest line, pixel for pixel, on a
//!   sample of its rows; a line's layer pictures are compared from the same fresh render as its
//!   image (the same rows, one render for all of them). The renderer is deterministic and a
//!   crop (`--region`) has the same pixels as the full image, so rendering only the rows
//!   y ≡ 0, 1 (mod 16) (one eighth of the work, at the committed size, samples and seed) must
//!   reproduce those rows of the PNG exactly. Like with like: the fresh rows go through the
//!   same `to_srgb8` as the written file (exposure, clamp, sRGB encoding, rounding to 8 bits)
//!   and are compared as 8-bit values. Any change at least 15 rows tall is sampled.
//!
//! Tolerance: a sampled pixel *differs* when a channel is off by more than one 8-bit step; at
//! most [`MAX_DIFFERING`] of the sampled pixels may differ (room for a libm that rounds a
//! last bit differently on another machine, which can flip a rare ray). Measured when this was
//! written: the regenerated images differ in 0 pixels; the two images the issue found stale (the
//! README's Cornell box and `refraction.png`, from before shadow rays crossed glass; full-size
//! RMSE 0.031 and 0.026) differ in 6.5 % and 2.4 % of the sampled pixels (by up to 135
//! steps), and the same Cornell box rendered with another seed (the same picture to the eye) in
//! 25 %. `a_changed_image_fails` keeps two such controls in the suite, and
//! `a_wrong_layer_picture_fails` one for layer pictures.

use std::path::PathBuf;

use caustic::integrators::LightPath;
use caustic::pipeline::{SceneOverrides, prepare};
use caustic::render::output::to_srgb8;
use caustic::render::{Film, Layer, Region, RenderJob, RenderOptions, layer_path, picture_layers};
use image::RgbImage;

use crate::common;

/// Images under docs/images/ made by a script of their own instead of a manifest line, being
/// too slow to render for this test (it does not compare them): the image and its script.
const SCRIPT_MADE: &[(&str, &str)] = &[
    ("bath_hq.png", "scripts/bath_hq.sh"),
    ("bath_default.png", "scripts/bath_default.sh"),
    ("bath_steam.png", "scripts/media_images.sh"),
    ("glass_of_water.png", "scripts/media_images.sh"),
    ("foggy_box.png", "scripts/media_images.sh"),
    ("volume_caustic.png", "scripts/media_images.sh"),
    ("fog_window.png", "scripts/media_images.sh"),
    ("denoise_cbox_noisy.png", "scripts/denoise_gallery.sh"),
    ("denoise_cbox_denoised.png", "scripts/denoise_gallery.sh"),
    ("denoise_cbox_oidn.png", "scripts/denoise_gallery.sh"),
    ("denoise_cbox_reference.png", "scripts/denoise_gallery.sh"),
    ("denoise_cbox_crop_noisy.png", "scripts/denoise_gallery.sh"),
    (
        "denoise_cbox_crop_denoised.png",
        "scripts/denoise_gallery.sh",
    ),
    ("denoise_cbox_crop_oidn.png", "scripts/denoise_gallery.sh"),
    (
        "denoise_cbox_crop_reference.png",
        "scripts/denoise_gallery.sh",
    ),
    ("denoise_bath_noisy.png", "scripts/denoise_gallery.sh"),
    ("denoise_bath_denoised.png", "scripts/denoise_gallery.sh"),
    ("denoise_bath_oidn.png", "scripts/denoise_gallery.sh"),
    ("denoise_bath_reference.png", "scripts/denoise_gallery.sh"),
    ("denoise_bath_crop_noisy.png", "scripts/denoise_gallery.sh"),
    (
        "denoise_bath_crop_denoised.png",
        "scripts/denoise_gallery.sh",
    ),
    ("denoise_bath_crop_oidn.png", "scripts/denoise_gallery.sh"),
    (
        "denoise_bath_crop_reference.png",
        "scripts/denoise_gallery.sh",
    ),
];

/// Largest fraction of the sampled pixels that may differ by more than one 8-bit step.
const MAX_DIFFERING: f64 = 0.001;
/// The rows compared: `STRIP` rows out of every `STRIDE`.
const STRIDE: u32 = 16;
const STRIP: u32 = 2;

/// One line of the manifest: an image and the `caustic render` arguments that make it.
#[derive(Debug)]
struct Entry {
    file: String,
    line: usize,
    args: Vec<String>,
}

fn images_dir() -> PathBuf {
    common::root().join("docs/images")
}

/// The manifest's entries, in order. Blank lines and `#` comments are skipped.
fn manifest() -> Vec<Entry> {
    let path = images_dir().join("manifest.txt");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    text.lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.trim_start().starts_with('#'))
        .map(|(i, l)| {
            let mut words = l.split_whitespace().map(str::to_string);
            let file = words.next().unwrap_or_default();
            Entry {
                file,
                line: i + 1,
                args: words.collect(),
            }
        })
        .collect()
}

/// What a manifest line asks `caustic render` for, read the way the CLI reads those flags.
#[derive(Debug, Default)]
struct RenderCall {
    scene: PathBuf,
    overrides: SceneOverrides,
    region: Option<Region>,
    /// `--layers`: the light layers whose pictures the line also makes.
    layers: Vec<LightPath>,
}

/// Parses the arguments of a manifest line; panics (naming the line) on a flag this test does
/// not know, so the manifest cannot silently use a flag whose effect the test would ignore.
fn parse_call(e: &Entry) -> RenderCall {
    let at = format!("docs/images/manifest.txt:{} ({})", e.line, e.file);
    let mut call = RenderCall::default();
    let mut it = e.args.iter();
    call.scene = common::root().join(it.next().unwrap_or_else(|| panic!("{at}: no scene")));
    let num = |flag: &str, v: Option<&String>| -> u64 {
        v.and_then(|v| v.parse().ok())
            .unwrap_or_else(|| panic!("{at}: {flag} needs a non-negative integer"))
    };
    while let Some(flag) = it.next() {
        let o = &mut call.overrides;
        match flag.as_str() {
            "--set" => o.sets.push(
                it.next()
                    .unwrap_or_else(|| panic!("{at}: --set needs a value"))
                    .clone(),
            ),
            "--width" => o.render.width = Some(num(flag, it.next()) as u32),
            "--height" => o.render.height = Some(num(flag, it.next()) as u32),
            "--spp" => o.render.samples_per_pixel = Some(num(flag, it.next()) as u32),
            "--max-depth" => o.render.max_depth = Some(num(flag, it.next()) as u32),
            "--seed" => o.render.seed = Some(num(flag, it.next())),
            "--region" => {
                let v = it
                    .next()
                    .unwrap_or_else(|| panic!("{at}: --region needs X,Y,W,H"));
                let n: Vec<u32> = v.split(',').filter_map(|s| s.parse().ok()).collect();
                let [x, y, width, height] = n[..] else {
                    panic!("{at}: --region `{v}`: want X,Y,W,H")
                };
                call.region = Some(Region {
                    x,
                    y,
                    width,
                    height,
                });
            }
            "--layers" => {
                let v = it
                    .next()
                    .unwrap_or_else(|| panic!("{at}: --layers needs a list"));
                let layers: Vec<Layer> = v
                    .split(',')
                    .map(|name| Layer::parse(name).unwrap_or_else(|err| panic!("{at}: {err}")))
                    .collect();
                call.layers = picture_layers(&layers).unwrap_or_else(|err| panic!("{at}: {err}"));
            }
            other => panic!(
                "{at}: `{other}` is not a flag this test knows how to scale \
                 (--set, --width, --height, --spp, --max-depth, --seed, --region, --layers)"
            ),
        }
    }
    call
}

/// How a committed image compares with a fresh render of the same rows.
#[derive(Debug, Default)]
struct Comparison {
    /// Pixels compared.
    sampled: usize,
    /// Pixels with a channel off by more than one 8-bit step.
    differing: usize,
    /// Largest channel difference, in 8-bit steps.
    max_step: u8,
    /// The first differing pixel (x, y).
    first: Option<(u32, u32)>,
}

impl Comparison {
    fn fraction(&self) -> f64 {
        self.differing as f64 / self.sampled.max(1) as f64
    }

    fn ok(&self) -> bool {
        self.fraction() <= MAX_DIFFERING
    }
}

/// The images manifest line `e` makes: its image, then the picture of each of its layers.
fn images_of(e: &Entry) -> Vec<String> {
    let image = std::path::Path::new(&e.file);
    let pictures = parse_call(e)
        .layers
        .into_iter()
        .map(|kind| layer_path(image, kind).to_string_lossy().into_owned());
    std::iter::once(e.file.clone()).chain(pictures).collect()
}

/// The committed image `file` under docs/images/, as 8-bit RGB.
fn committed(file: &str) -> RgbImage {
    let path = images_dir().join(file);
    match image::open(&path) {
        Ok(image::DynamicImage::ImageRgb8(img)) => img,
        Ok(other) => panic!(
            "{}: stored as {:?}; the renderer writes 8-bit RGB",
            path.display(),
            other.color()
        ),
        Err(e) => panic!("{}: {e}", path.display()),
    }
}

/// Adds the comparison of `fresh`, rows `y0..` of an image, with the same rows of `image`.
fn compare_strip(c: &mut Comparison, fresh: &RgbImage, image: &RgbImage, y0: u32) {
    for (x, y, p) in fresh.enumerate_pixels() {
        let q = image.get_pixel(x, y0 + y);
        let step =
            p.0.iter()
                .zip(q.0)
                .map(|(a, b)| a.abs_diff(b))
                .max()
                .unwrap_or(0);
        c.sampled += 1;
        c.max_step = c.max_step.max(step);
        if step > 1 {
            c.differing += 1;
            c.first.get_or_insert((x, y0 + y));
        }
    }
}

/// Renders rows y ≡ 0..STRIP (mod STRIDE) of the image of manifest line `e` and compares them
/// with the same rows of `images`: the line's image, then its layer pictures (as
/// [`images_of`] lists them), all from the same render.
fn compare_rows(e: &Entry, images: &[RgbImage]) -> Vec<Comparison> {
    let at = format!("docs/images/manifest.txt:{} ({})", e.line, e.file);
    let call = parse_call(e);
    assert_eq!(
        images.len(),
        1 + call.layers.len(),
        "{at}: one image and one picture per layer"
    );
    let prepared =
        prepare(&call.scene, &call.overrides).unwrap_or_else(|err| panic!("{at}: {err}"));
    let r = &prepared.render_scene.params;
    let crop = call.region.unwrap_or(Region {
        x: 0,
        y: 0,
        width: r.width,
        height: r.height,
    });
    for (image, file) in images.iter().zip(images_of(e)) {
        assert_eq!(
            image.dimensions(),
            (crop.width, crop.height),
            "{at}: the committed {file}'s size is not the manifest's (regenerate it with \
             `scripts/doc_images.sh {}`)",
            e.file
        );
    }
    let display = caustic::render::tonemap::Display {
        exposure: prepared.render_scene.params.exposure,
        tonemap: prepared.render_scene.params.tonemap,
    };
    let mut comparisons: Vec<Comparison> = images.iter().map(|_| Comparison::default()).collect();
    // One job for all strips: the integrator (photon maps) is prepared once.
    let first = Region {
        height: STRIP.min(crop.height),
        ..crop
    };
    let options = RenderOptions {
        region: Some(first),
        light_paths: !call.layers.is_empty(),
        ..RenderOptions::default()
    };
    let mut job = RenderJob::new(&prepared.render_scene, &options)
        .unwrap_or_else(|err| panic!("{at}: {err}"));
    // Every strip in one call: a progressive integrator traces each pass's photons once for
    // all of them.
    let strips: Vec<Region> = (0..crop.height)
        .step_by(STRIDE as usize)
        .map(|y0| Region {
            x: crop.x,
            y: crop.y + y0,
            width: crop.width,
            height: STRIP.min(crop.height - y0),
        })
        .collect();
    let outs = job
        .render_regions(&strips)
        .unwrap_or_else(|err| panic!("{at}: {err}"));
    for (region, out) in strips.iter().zip(outs) {
        let y0 = region.y - crop.y;
        let parts = out.parts.as_deref().unwrap_or_default();
        let layer_films = call.layers.iter().map(|&kind| {
            parts
                .get(kind as usize)
                .unwrap_or_else(|| panic!("{at}: the render kept no {} layer", kind.name()))
                .to_film()
        });
        let films: Vec<Film> = std::iter::once(out.film.clone())
            .chain(layer_films)
            .collect();
        for ((c, film), image) in comparisons.iter_mut().zip(&films).zip(images) {
            compare_strip(c, &to_srgb8(film, display), image, y0);
        }
    }
    comparisons
}

#[test]
fn every_doc_image_is_in_the_manifest() {
    let listed: Vec<String> = manifest().iter().flat_map(images_of).collect();
    let mut on_disk: Vec<String> = std::fs::read_dir(images_dir())
        .expect("docs/images exists")
        .map(|e| {
            e.expect("dir entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|n| n != "manifest.txt")
        .collect();
    on_disk.sort();
    for (image, script) in SCRIPT_MADE {
        assert!(
            !listed.iter().any(|f| f == image),
            "docs/images/{image} is in the manifest and in SCRIPT_MADE: keep one"
        );
        let text = std::fs::read_to_string(common::root().join(script))
            .unwrap_or_else(|e| panic!("{script}, which makes docs/images/{image}: {e}"));
        assert!(
            text.contains(&format!("docs/images/{image}")),
            "{script} does not write docs/images/{image}"
        );
        assert!(
            on_disk.iter().any(|f| f == image),
            "docs/images/{image} is missing: run `{script}`"
        );
    }
    let accounted: Vec<&str> = listed
        .iter()
        .map(String::as_str)
        .chain(SCRIPT_MADE.iter().map(|(image, _)| *image))
        .collect();
    for f in &on_disk {
        assert!(
            accounted.contains(&f.as_str()),
            "docs/images/{f} is not in docs/images/manifest.txt: add the command that makes it"
        );
    }
    for f in &listed {
        assert!(
            on_disk.contains(f),
            "docs/images/manifest.txt lists {f}, which is not in docs/images/ \
             (run `scripts/doc_images.sh {f}`)"
        );
    }
    // Every picture the docs show is one of them.
    let mut docs = vec![common::root().join("README.md")];
    for e in std::fs::read_dir(common::root().join("docs")).expect("docs/ exists") {
        let p = e.expect("dir entry").path();
        if p.extension().is_some_and(|x| x == "md") {
            docs.push(p);
        }
    }
    let mut shown = 0;
    for doc in docs {
        let text = std::fs::read_to_string(&doc).expect("readable");
        for (i, line) in text.lines().enumerate() {
            for link in line.split("](").skip(1) {
                let target = link.split(')').next().unwrap_or_default();
                let is_image = [".png", ".jpg", ".jpeg", ".exr", ".gif", ".svg"]
                    .iter()
                    .any(|x| target.to_ascii_lowercase().ends_with(x));
                if !is_image {
                    continue;
                }
                shown += 1;
                let resolved = doc.parent().expect("has a folder").join(target);
                let name = resolved
                    .file_name()
                    .and_then(|n| n.to_str())
                    .unwrap_or_default();
                assert!(
                    resolved.parent().and_then(|p| p.canonicalize().ok())
                        == images_dir().canonicalize().ok()
                        && accounted.contains(&name),
                    "{}:{}: shows `{target}`, which is not an image of docs/images/manifest.txt \
                     (or of SCRIPT_MADE)",
                    doc.display(),
                    i + 1
                );
            }
        }
    }
    assert!(shown > 0, "found no image links in README.md or docs/*.md");
}

#[test]
fn committed_doc_images_match_a_fresh_render() {
    let mut failures = Vec::new();
    for e in manifest() {
        let files = images_of(&e);
        let images: Vec<RgbImage> = files.iter().map(|f| committed(f)).collect();
        for (file, c) in files.iter().zip(compare_rows(&e, &images)) {
            eprintln!("{file}: {c:?}");
            if c.ok() {
                continue;
            }
            failures.push(format!(
                "{file}: {} of {} sampled pixels differ ({:.2} %; first at {:?}, up to {} steps)",
                c.differing,
                c.sampled,
                100.0 * c.fraction(),
                c.first.unwrap_or_default(),
                c.max_step
            ));
        }
    }
    assert!(
        failures.is_empty(),
        "images under docs/images/ no longer match the renderer (at most {} % of the sampled \
         pixels may differ):\n  {}\nregenerate them with `scripts/doc_images.sh` and look at them",
        100.0 * MAX_DIFFERING,
        failures.join("\n  ")
    );
}

/// The comparison catches a stale image: a 48×48 patch painted over the Cornell box, and the
/// same scene rendered with another seed (the same picture to the eye, other noise).
#[test]
fn a_changed_image_fails() {
    let entry = manifest()
        .into_iter()
        .find(|e| e.file == "cornell.png")
        .expect("cornell.png is in the manifest");
    let mut painted = committed(&entry.file);
    for y in 200..248 {
        for x in 200..248 {
            painted.put_pixel(x, y, image::Rgb([255, 0, 255]));
        }
    }
    let c = &compare_rows(&entry, &[painted])[0];
    assert!(!c.ok(), "a painted patch was not caught: {c:?}");
    assert!(c.differing >= 6 * 48, "{c:?}");

    let reseeded = Entry {
        args: [entry.args.clone(), vec!["--seed".into(), "2".into()]].concat(),
        ..entry
    };
    let c = &compare_rows(&reseeded, &[committed(&reseeded.file)])[0];
    eprintln!("cornell.png against seed 2: {c:?}");
    assert!(!c.ok(), "another seed's noise was not caught: {c:?}");
}

/// A line with `--layers` compares each picture with its own layer: the Cornell box's image
/// standing in for its `direct` picture (which lacks the indirect light) is caught, while the
/// image itself, from the same render with the layers kept, still matches. On a band of rows
/// (`--region`), to keep it quick.
#[test]
fn a_wrong_layer_picture_fails() {
    let entry = manifest()
        .into_iter()
        .find(|e| e.file == "cornell.png")
        .expect("cornell.png is in the manifest");
    let (y, height) = (192, 128);
    let band =
        |image: &RgbImage| image::imageops::crop_imm(image, 0, y, image.width(), height).to_image();
    let image = band(&committed(&entry.file));
    let layered = Entry {
        args: [
            entry.args.clone(),
            ["--region", &format!("0,{y},{},{height}", image.width())]
                .map(String::from)
                .to_vec(),
            vec!["--layers".into(), "direct".into()],
        ]
        .concat(),
        ..entry
    };
    assert_eq!(images_of(&layered), ["cornell.png", "cornell.direct.png"]);
    let c = compare_rows(&layered, &[image.clone(), image]);
    eprintln!("cornell.png and its image as the direct picture: {c:?}");
    assert!(c[0].ok(), "the image of a layered render moved: {:?}", c[0]);
    assert!(
        !c[1].ok(),
        "a wrong layer picture was not caught: {:?}",
        c[1]
    );
}

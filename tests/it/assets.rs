//! The procedural texture assets (issue #3): the committed PNGs under `assets/` are exactly what
//! `examples/gen_assets` generates (compared as decoded pixels, so PNG encoder changes do not
//! matter), and they have the properties the renderer's tests rely on.

#[path = "../../examples/gen_assets/images.rs"]
mod images;

use image::{DynamicImage, GrayImage, RgbImage};

fn committed(name: &str) -> DynamicImage {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("assets")
        .join(name);
    image::open(&path).unwrap_or_else(|e| {
        panic!(
            "{}: {e} (regenerate with `cargo run --example gen_assets`)",
            path.display()
        )
    })
}

/// Asserts two images are pixel-for-pixel equal, reporting the first difference and the count.
fn assert_same(name: &str, got: &[u8], want: &[u8], channels: usize, width: u32) {
    assert_eq!(got.len(), want.len(), "{name}: size");
    let diffs: Vec<usize> = got
        .chunks(channels)
        .zip(want.chunks(channels))
        .enumerate()
        .filter(|(_, (a, b))| a != b)
        .map(|(i, _)| i)
        .collect();
    if let Some(&i) = diffs.first() {
        let (x, y) = (i as u32 % width, i as u32 / width);
        panic!(
            "{name}: {} pixels differ from the generator, first at ({x}, {y}): committed {:?}, \
             generated {:?} — regenerate with `cargo run --example gen_assets`",
            diffs.len(),
            &want[i * channels..(i + 1) * channels],
            &got[i * channels..(i + 1) * channels]
        );
    }
}

fn check_rgb(name: &str, generated: &RgbImage) {
    let file = committed(name);
    assert!(
        matches!(file, DynamicImage::ImageRgb8(_)),
        "{name}: stored as {:?}, want 8-bit RGB",
        file.color()
    );
    let file = file.to_rgb8();
    assert_eq!(file.dimensions(), generated.dimensions(), "{name}");
    assert_same(name, generated.as_raw(), file.as_raw(), 3, file.width());
}

fn check_grey(name: &str, generated: &GrayImage) {
    let file = committed(name);
    assert!(
        matches!(file, DynamicImage::ImageLuma8(_)),
        "{name}: stored as {:?}, want 8-bit greyscale",
        file.color()
    );
    let file = file.to_luma8();
    assert_eq!(file.dimensions(), generated.dimensions(), "{name}");
    assert_same(name, generated.as_raw(), file.as_raw(), 1, file.width());
}

#[test]
fn committed_pngs_are_what_the_generator_makes() {
    let t = std::time::Instant::now();
    check_rgb("hardwood.png", &images::hardwood());
    check_grey("tiles_height.png", &images::tiles_height());
    check_rgb("tiles_color.png", &images::tiles_color());
    check_rgb("tiles_normal.png", &images::tiles_normal());
    check_grey("ramp_height.png", &images::ramp_height());
    eprintln!("generated and compared 4 images in {:?}", t.elapsed());
}

#[test]
fn the_committed_sky_is_what_the_generator_makes() {
    let file = committed("sky.exr").to_rgb32f();
    let generated = images::sky();
    assert_eq!(file.dimensions(), generated.dimensions());
    let differ = file
        .as_raw()
        .iter()
        .zip(generated.as_raw())
        .filter(|(a, b)| a.to_bits() != b.to_bits())
        .count();
    assert_eq!(
        differ, 0,
        "sky.exr: regenerate with `cargo run --example gen_assets`"
    );
    // Linear HDR: the sun is far brighter than the sky, the ground darker; all finite.
    let max = generated.as_raw().iter().fold(0.0f32, |m, &v| m.max(v));
    assert!(
        max > 100.0
            && generated
                .as_raw()
                .iter()
                .all(|v| v.is_finite() && *v >= 0.0)
    );
}

#[test]
fn committed_pngs_are_small() {
    for name in [
        "hardwood.png",
        "tiles_height.png",
        "tiles_color.png",
        "ramp_height.png",
    ] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("assets")
            .join(name);
        let bytes = std::fs::metadata(&path).expect("exists").len();
        assert!(bytes < 150_000, "{name}: {bytes} bytes");
    }
}

/// Pixels as `[f64; C]` rows for the seam checks.
struct Px {
    w: u32,
    h: u32,
    c: usize,
    data: Vec<f64>,
}

impl Px {
    fn rgb(img: &RgbImage) -> Self {
        Self {
            w: img.width(),
            h: img.height(),
            c: 3,
            data: img.as_raw().iter().map(|&v| f64::from(v)).collect(),
        }
    }

    fn grey(img: &GrayImage) -> Self {
        Self {
            w: img.width(),
            h: img.height(),
            c: 1,
            data: img.as_raw().iter().map(|&v| f64::from(v)).collect(),
        }
    }

    fn at(&self, x: u32, y: u32) -> &[f64] {
        let i = (y * self.w + x) as usize * self.c;
        &self.data[i..i + self.c]
    }

    /// Mean absolute difference (per channel) between columns `a` and `b`.
    fn col_diff(&self, a: u32, b: u32) -> f64 {
        let s: f64 = (0..self.h)
            .flat_map(|y| self.at(a, y).iter().zip(self.at(b, y)))
            .map(|(p, q)| (p - q).abs())
            .sum();
        s / f64::from(self.h) / self.c as f64
    }

    /// Mean absolute difference between rows `a` and `b`.
    fn row_diff(&self, a: u32, b: u32) -> f64 {
        let s: f64 = (0..self.w)
            .flat_map(|x| self.at(x, a).iter().zip(self.at(x, b)))
            .map(|(p, q)| (p - q).abs())
            .sum();
        s / f64::from(self.w) / self.c as f64
    }

    /// `(edge, interior)` for x and for y: the difference across the wrap (last column/row to the
    /// first) and the mean difference between neighbouring interior columns/rows.
    fn seams(&self) -> [(f64, f64); 2] {
        let ix = (0..self.w - 1)
            .map(|x| self.col_diff(x, x + 1))
            .sum::<f64>()
            / f64::from(self.w - 1);
        let iy = (0..self.h - 1)
            .map(|y| self.row_diff(y, y + 1))
            .sum::<f64>()
            / f64::from(self.h - 1);
        [
            (self.col_diff(self.w - 1, 0), ix),
            (self.row_diff(self.h - 1, 0), iy),
        ]
    }

    fn is_seamless(&self) -> bool {
        self.seams().iter().all(|(edge, interior)| edge <= interior)
    }
}

#[test]
fn tiling_images_are_seamless() {
    let cases = [
        ("hardwood", Px::rgb(&images::hardwood())),
        ("tiles_height", Px::grey(&images::tiles_height())),
        ("tiles_color", Px::rgb(&images::tiles_color())),
    ];
    for (name, px) in &cases {
        let s = px.seams();
        eprintln!(
            "{name}: (edge, mean interior) difference in x {:?}, y {:?}",
            s[0], s[1]
        );
        assert!(px.is_seamless(), "{name}: {s:?}");
    }
    // The check can fail: the ramp jumps from white back to black across its x edge, and a
    // hardwood tile cut in the middle of a plank row does not wrap vertically.
    let ramp = Px::grey(&images::ramp_height());
    assert!(!ramp.is_seamless(), "{:?}", ramp.seams());
    let wood = images::hardwood();
    let cut = image::imageops::crop_imm(&wood, 0, 0, 256, 200).to_image();
    assert!(!Px::rgb(&cut).is_seamless(), "{:?}", Px::rgb(&cut).seams());
}

fn luma(p: &image::Rgb<u8>) -> f64 {
    0.2126 * f64::from(p[0]) + 0.7152 * f64::from(p[1]) + 0.0722 * f64::from(p[2])
}

#[test]
fn hardwood_has_warm_planks_with_thin_dark_gaps() {
    let img = images::hardwood();
    let n = images::HARDWOOD_SIZE;
    assert_eq!(img.dimensions(), (n, n));
    let pw = images::PLANK_WIDTH;
    let rows = n / pw;
    let row_luma = |y: u32| (0..n).map(|x| luma(img.get_pixel(x, y))).sum::<f64>() / f64::from(n);
    let mut plank_means = Vec::new();
    for r in 0..rows {
        let top = (images::PLANK_ROW_OFFSET + r * pw) % n;
        // The one-pixel gap under the row is dark across the whole tile, and clearly darker
        // than the (eased) plank edges beside it and the wood two pixels away.
        let gap = (top + pw - 1) % n;
        let gap_luma = row_luma(gap);
        let above = row_luma((gap + n - 2) % n);
        let below = row_luma((gap + 1) % n);
        let further = row_luma((gap + n - 3) % n);
        assert!(gap_luma < 30.0, "row {r}: gap luma {gap_luma}");
        assert!(
            above > 2.5 * gap_luma && below > 2.5 * gap_luma && further > 4.0 * gap_luma,
            "row {r}: gap {gap_luma}, neighbours {above} {below} {further}"
        );
        // End joints: one-pixel dark columns through the plank row, staggered with the row above.
        let joints = images::plank_joints(r);
        assert!(!joints.is_empty());
        for &j in &joints {
            for v in 0..pw - 1 {
                let p = img.get_pixel(j, (top + v) % n);
                assert!(luma(p) < 30.0, "row {r}, joint {j}, v {v}: {p:?}");
            }
            let prev = images::plank_joints((r + rows - 1) % rows);
            assert!(
                prev.iter()
                    .all(|&k| j.abs_diff(k).min(n - j.abs_diff(k)) >= 24),
                "row {r}: joints {joints:?} vs {prev:?}"
            );
        }
        // Per-plank mean colour, away from the edges.
        for (k, &j) in joints.iter().enumerate() {
            let end = joints[(k + 1) % joints.len()];
            let len = (end + n - j - 1) % n + 1;
            let mut sum = [0.0f64; 3];
            let mut count = 0.0;
            for u in 3..len - 3 {
                for v in 3..pw - 4 {
                    let p = img.get_pixel((j + u) % n, (top + v) % n);
                    for (s, c) in sum.iter_mut().zip(p.0) {
                        *s += f64::from(c);
                    }
                    count += 1.0;
                }
            }
            let m = sum.map(|s| s / count);
            // Warm brown: red > green > blue, clearly so, and mid-dark.
            assert!(
                m[0] > m[1] + 20.0 && m[1] > m[2] + 15.0 && (60.0..220.0).contains(&m[0]),
                "row {r} plank {k}: mean {m:?}"
            );
            plank_means.push(m);
        }
    }
    // Planks differ in tone.
    let lum: Vec<f64> = plank_means
        .iter()
        .map(|m| 0.2126 * m[0] + 0.7152 * m[1] + 0.0722 * m[2])
        .collect();
    let (lo, hi) = lum
        .iter()
        .fold((f64::MAX, f64::MIN), |(a, b), &l| (a.min(l), b.max(l)));
    assert!(hi - lo > 25.0, "plank tones {lum:?}");
    // Grain: fine detail along y inside planks (rings and fibres), much less along x.
    let mut dy = 0.0;
    let mut dx = 0.0;
    for r in 0..rows {
        let top = (images::PLANK_ROW_OFFSET + r * pw) % n;
        let joints = images::plank_joints(r);
        for x in 0..n - 1 {
            if joints.iter().any(|&j| x + 2 >= j && x <= j + 2) {
                continue;
            }
            for v in 2..pw - 3 {
                let (a, b, c) = (
                    img.get_pixel(x, (top + v) % n),
                    img.get_pixel(x, (top + v + 1) % n),
                    img.get_pixel(x + 1, (top + v) % n),
                );
                dy += (luma(a) - luma(b)).abs();
                dx += (luma(a) - luma(c)).abs();
            }
        }
    }
    assert!(
        dy > 2.0 * dx,
        "grain runs along x: |∂/∂y| {dy} vs |∂/∂x| {dx}"
    );
}

#[test]
fn tile_height_map_has_grout_bevels_and_flat_tops() {
    let img = images::tiles_height();
    let n = images::TILES_SIZE;
    assert_eq!(img.dimensions(), (n, n));
    let pitch = n / images::TILES_PER_SIDE;
    let h = |x: u32, y: u32| img.get_pixel(x % n, y % n)[0];
    for t in 0..images::TILES_PER_SIDE {
        let c = t * pitch + pitch / 2;
        for g in [t * pitch, t * pitch + pitch - 1] {
            // Grout lines (either side of each multiple of the pitch) are 0 all along.
            for s in 0..n {
                assert_eq!(h(g, s), 0, "grout at x={g}, y={s}");
                assert_eq!(h(s, g), 0, "grout at y={g}, x={s}");
            }
        }
        for u in 0..images::TILES_PER_SIDE {
            let cy = u * pitch + pitch / 2;
            // Tile tops are flat at 255 over the middle of each tile.
            for dy in 0..16 {
                for dx in 0..16 {
                    assert_eq!(h(c - 8 + dx, cy - 8 + dy), 255);
                }
            }
            // From the grout to the centre the height rises monotonically over a smooth ramp a
            // few pixels wide (pixels strictly between 0 and 255), both ways along both axes.
            let ramps: [Vec<u8>; 4] = [
                (0..pitch / 2).map(|k| h(t * pitch + k, cy)).collect(),
                (0..pitch / 2)
                    .map(|k| h(t * pitch + pitch - 1 - k, cy))
                    .collect(),
                (0..pitch / 2).map(|k| h(c, u * pitch + k)).collect(),
                (0..pitch / 2)
                    .map(|k| h(c, u * pitch + pitch - 1 - k))
                    .collect(),
            ];
            for ramp in &ramps {
                assert!(ramp.windows(2).all(|w| w[0] <= w[1]), "{ramp:?}");
                let between = ramp.iter().filter(|&&v| v > 0 && v < 255).count();
                assert!((2..=6).contains(&between), "{ramp:?}");
                // No single step of the ramp is more than about half the full height.
                assert!(ramp.windows(2).all(|w| w[1] - w[0] <= 140), "{ramp:?}");
            }
        }
    }
    // Rounded corners: at a tile corner the diagonal rises more slowly than the edges do.
    let edge = h(pitch / 2, 3);
    let corner = h(3, 3);
    assert!(corner < edge, "corner {corner}, edge {edge}");
    // Mostly tile top.
    let top = img.as_raw().iter().filter(|&&v| v == 255).count();
    let frac = top as f64 / f64::from(n * n);
    assert!((0.4..0.8).contains(&frac), "{frac}");
}

#[test]
fn tile_colours_are_pale_tiles_and_grey_grout_aligned_with_the_height_map() {
    let col = images::tiles_color();
    let hgt = images::tiles_height();
    assert_eq!(col.dimensions(), hgt.dimensions());
    let (mut grout, mut tops) = (Vec::new(), Vec::new());
    for (x, y, p) in col.enumerate_pixels() {
        match hgt.get_pixel(x, y)[0] {
            0 => grout.push(*p),
            255 => tops.push(*p),
            _ => {}
        }
    }
    for p in &tops {
        // Off-white: bright, low saturation.
        let (mx, mn) = (p.0.iter().max().unwrap(), p.0.iter().min().unwrap());
        assert!(luma(p) > 200.0 && mx - mn < 30, "tile top {p:?}");
    }
    for p in &grout {
        let (mx, mn) = (p.0.iter().max().unwrap(), p.0.iter().min().unwrap());
        assert!(
            (90.0..170.0).contains(&luma(p)) && mx - mn < 20,
            "grout {p:?}"
        );
    }
    assert!(
        grout.len() > 2000 && tops.len() > 6000,
        "{} {}",
        grout.len(),
        tops.len()
    );
}

#[test]
fn ramp_height_is_a_linear_ramp_in_x() {
    let img = images::ramp_height();
    assert_eq!(img.dimensions(), (64, 64));
    for (x, y, p) in img.enumerate_pixels() {
        let want = (f64::from(x) / 63.0 * 255.0).round();
        assert_eq!(f64::from(p[0]), want, "({x}, {y})");
    }
}

//! Procedural texture images for `assets/` (issue #3): pure, deterministic functions (seeded
//! integer hashes, only `+ − × ÷ sqrt floor` in floating point, so the 8-bit output does not depend
//! on the platform's maths library). Shared by `examples/gen_assets` (which writes the PNGs) and
//! `tests/assets.rs` (which checks the committed files still match).
//!
//! Texture convention: pixel (0, 0) is the image's top-left, at uv (0, 0); v grows downwards.

use image::{GrayImage, Luma, Rgb, RgbImage};

/// Side of the hardwood tile in pixels.
pub const HARDWOOD_SIZE: u32 = 256;
/// Height of one row of planks in the hardwood tile, in pixels.
pub const PLANK_WIDTH: u32 = 32;
/// The first row of planks starts this many pixels below the top edge, so the tile's edges fall
/// inside planks rather than on a gap.
pub const PLANK_ROW_OFFSET: u32 = 16;
/// Side of the tile height map and tile colour image in pixels.
pub const TILES_SIZE: u32 = 128;
/// Tiles per image side.
pub const TILES_PER_SIDE: u32 = 4;
/// Half the grout width, in pixels (grout lines are centred on multiples of the tile pitch,
/// including the image edges).
pub const GROUT_HALF_WIDTH: f32 = 1.5;
/// Width of the rounded bevel between grout and tile top, in pixels.
pub const BEVEL_WIDTH: f32 = 4.0;
/// Side of the ramp height map in pixels.
pub const RAMP_SIZE: u32 = 64;

/// A 32-bit integer hash of a lattice point and a seed (murmur3 finaliser on a linear mix).
fn hash(x: i32, y: i32, seed: u32) -> u32 {
    let mut h = (x as u32).wrapping_mul(0x8DA6_B343)
        ^ (y as u32).wrapping_mul(0xD816_3841)
        ^ seed.wrapping_mul(0xCB1A_B31F).wrapping_add(0x9E37_79B9);
    h ^= h >> 16;
    h = h.wrapping_mul(0x85EB_CA6B);
    h ^= h >> 13;
    h = h.wrapping_mul(0xC2B2_AE35);
    h ^ (h >> 16)
}

/// A hash mapped to `[0, 1)`.
fn hash01(x: i32, y: i32, seed: u32) -> f32 {
    (hash(x, y, seed) >> 8) as f32 * (1.0 / 16_777_216.0)
}

/// `3t² − 2t³`.
fn smooth(t: f32) -> f32 {
    t * t * (3.0 - 2.0 * t)
}

/// Hermite step from `a` to `b`.
fn smoothstep(a: f32, b: f32, x: f32) -> f32 {
    smooth(((x - a) / (b - a)).clamp(0.0, 1.0))
}

fn lerp(a: f32, b: f32, t: f32) -> f32 {
    a + (b - a) * t
}

/// Smoothly interpolated lattice value noise in `[0, 1)`.
fn value_noise(x: f32, y: f32, seed: u32) -> f32 {
    let (fx, fy) = (x.floor(), y.floor());
    let (ix, iy) = (fx as i32, fy as i32);
    let (tx, ty) = (smooth(x - fx), smooth(y - fy));
    let a = hash01(ix, iy, seed);
    let b = hash01(ix + 1, iy, seed);
    let c = hash01(ix, iy + 1, seed);
    let d = hash01(ix + 1, iy + 1, seed);
    lerp(lerp(a, b, tx), lerp(c, d, tx), ty)
}

/// Two octaves of value noise, in `[0, 1)`.
fn fbm2(x: f32, y: f32, seed: u32) -> f32 {
    (2.0 * value_noise(x, y, seed) + value_noise(2.0 * x + 17.3, 2.0 * y - 5.1, seed ^ 0x55)) / 3.0
}

/// An sRGB colour with components in `[0, 1]` to 8 bits.
fn to_rgb8(c: [f32; 3]) -> Rgb<u8> {
    Rgb(c.map(|v| (v.clamp(0.0, 1.0) * 255.0 + 0.5) as u8))
}

/// Where the planks of one row of the hardwood tile end: sorted x positions of the one-pixel end
/// joints, all at least 8 px from the tile's left and right edges.
#[must_use]
pub fn plank_joints(row: u32) -> Vec<u32> {
    let rows = HARDWOOD_SIZE / PLANK_WIDTH;
    // Rows are laid in order; each row's joints keep ≥ 24 px (cyclically) from the previous
    // row's, and the last row's from the first's, so the joints are staggered everywhere.
    let mut all: Vec<Vec<u32>> = Vec::new();
    for r in 0..rows {
        let mut attempt = 0;
        let joints = loop {
            let s = hash(r as i32, attempt, 0xA11CE);
            attempt += 1;
            let u = |k: u32| hash01(k as i32, attempt, s);
            // One or two planks per row, mostly two; lengths ≥ 96 px.
            let n = if u(0) < 0.3 { 1 } else { 2 };
            let mut lengths = Vec::new();
            let mut left = HARDWOOD_SIZE;
            for k in 1..n {
                let max = left - 96 * (n - k);
                let l = 96 + (u(k) * (max - 96 + 1) as f32) as u32;
                lengths.push(l);
                left -= l;
            }
            let start = (u(7) * HARDWOOD_SIZE as f32) as u32;
            let mut j = vec![start];
            for l in &lengths {
                j.push((j[j.len() - 1] + l) % HARDWOOD_SIZE);
            }
            j.sort_unstable();
            let near = |a: u32, b: u32| {
                let d = a.abs_diff(b);
                d.min(HARDWOOD_SIZE - d) < 24
            };
            let inside = j.iter().all(|&x| (8..HARDWOOD_SIZE - 8).contains(&x));
            let clash = |other: &Vec<u32>| j.iter().any(|&a| other.iter().any(|&b| near(a, b)));
            let staggered =
                r == 0 || (!clash(&all[r as usize - 1]) && (r + 1 < rows || !clash(&all[0])));
            if inside && staggered {
                break j;
            }
        };
        all.push(joints);
    }
    all.swap_remove(row as usize)
}

/// The plank a hardwood pixel lies on: `(row, plank index in row, u along the plank from its
/// start, v across it from its top edge, plank length)`, all wrapping around the tile.
fn plank_at(x: u32, y: u32, joints: &[Vec<u32>]) -> (u32, usize, u32, u32, u32) {
    let yy = (y + HARDWOOD_SIZE - PLANK_ROW_OFFSET) % HARDWOOD_SIZE;
    let row = yy / PLANK_WIDTH;
    let v = yy % PLANK_WIDTH;
    let j = &joints[row as usize];
    // The plank starting at the last joint at or before x (cyclically).
    let k = match j.iter().rposition(|&a| a <= x) {
        Some(k) => k,
        None => j.len() - 1,
    };
    let start = j[k];
    let end = j[(k + 1) % j.len()];
    let len = (end + HARDWOOD_SIZE - start - 1) % HARDWOOD_SIZE + 1;
    let u = (x + HARDWOOD_SIZE - start) % HARDWOOD_SIZE;
    (row, k, u, v, len)
}

/// A 256×256 sRGB tile of hardwood floor: eight rows of 32 px planks running along x, with
/// staggered end joints, one-pixel dark gaps (with darkened plank edges beside them), warm brown
/// planks of varying tone, and flat-sawn grain — tree rings cut by the board plane, forming
/// arches along the plank, with sharp latewood edges and fine fibre streaks. Seamless: the
/// tile's edges fall inside planks and every plank's pattern wraps with it.
#[must_use]
pub fn hardwood() -> RgbImage {
    let rows = HARDWOOD_SIZE / PLANK_WIDTH;
    let joints: Vec<Vec<u32>> = (0..rows).map(plank_joints).collect();
    let light = [0.80, 0.58, 0.37];
    let dark = [0.50, 0.30, 0.16];
    let gap = [0.11, 0.065, 0.035];
    RgbImage::from_fn(HARDWOOD_SIZE, HARDWOOD_SIZE, |x, y| {
        let (row, k, u, v, len) = plank_at(x, y, &joints);
        let id = row * 8 + k as u32;
        let seed = hash(id as i32, 0, 0xB0A4D);
        let r = |i: i32| hash01(i, 1, seed);
        // Gaps: the last pixel row of each plank row and the first pixel column of each plank.
        if v == PLANK_WIDTH - 1 || u == 0 {
            return to_rgb8(gap);
        }
        // Plank tone and a slight hue shift.
        let tone = r(0);
        let mut base = [0, 1, 2].map(|i| lerp(light[i], dark[i], tone));
        base[0] *= 1.0 + 0.06 * (r(1) - 0.5);
        base[2] *= 1.0 + 0.20 * (r(2) - 0.5);
        // Grain, averaged over 4×4 samples per pixel so ring edges are sharp but not jagged.
        let mut sum = [0.0f32; 3];
        for s in 0..16 {
            let uf = u as f32 + ((s % 4) as f32 + 0.5) / 4.0;
            let vf = v as f32 + ((s / 4) as f32 + 0.5) / 4.0;
            let c = wood_grain(uf, vf, len as f32, base, seed);
            for (s, c) in sum.iter_mut().zip(c) {
                *s += c / 16.0;
            }
        }
        // Planks' long edges and ends are slightly eased (darker) beside the gaps.
        let edge = if v == 0 || v == PLANK_WIDTH - 2 || u == 1 || u == len - 1 {
            0.78
        } else {
            1.0
        };
        to_rgb8(sum.map(|c| c * edge))
    })
}

/// The grain of a plank of length `len` and colour `base` at `(u, v)` (pixels along and across
/// it): tree rings — distances from a log axis nearly parallel to the plank, seen in the board
/// plane — with latewood bands, warped by noise, plus fine fibre streaks.
fn wood_grain(u: f32, v: f32, len: f32, base: [f32; 3], seed: u32) -> [f32; 3] {
    let r = |i: i32| hash01(i, 1, seed);
    // `c` is where the axis lies across the plank, `depth` how far below the board plane.
    let c = lerp(-8.0, PLANK_WIDTH as f32 + 8.0, r(3));
    let tilt = lerp(0.06, 0.16, r(4)) * if r(5) < 0.5 { -1.0 } else { 1.0 };
    let depth = lerp(-12.0, 12.0, r(6)) + tilt * (u - lerp(0.2, 0.8, r(7)) * len);
    let spacing = lerp(3.5, 5.5, r(8));
    let warp = 2.5 * (fbm2(u / 28.0, v / 9.0, seed ^ 1) - 0.5);
    let dv = v - c;
    let ring = ((dv * dv + depth * depth).sqrt() + warp) / spacing;
    let f = ring - ring.floor();
    // Earlywood darkens gradually into latewood, which ends abruptly.
    let late = smoothstep(0.45, 0.92, f) * lerp(0.75, 1.0, r(9));
    // Fine fibres: noise stretched along the plank, and slow lengthwise tone variation.
    let fibre = 0.10 * (value_noise(u / 23.0, v / 1.3, seed ^ 2) - 0.5);
    let drift = 0.10 * (value_noise(u / 70.0, 0.5, seed ^ 3) - 0.5);
    let shade = 1.0 + fibre + drift;
    let latewood = [0.70, 0.60, 0.50];
    [0, 1, 2].map(|i| base[i] * lerp(1.0, latewood[i], late) * shade)
}

/// Height in `[0, 1]` of the tile pattern at pixel `(x, y)`: 0 in the grout, 1 on tile tops, a
/// rounded bevel (`1 − (1 − s)²` over `BEVEL_WIDTH` px, round corners) in between.
#[must_use]
pub fn tile_height(x: u32, y: u32) -> f32 {
    let pitch = (TILES_SIZE / TILES_PER_SIDE) as f32;
    // Distance from the pixel centre to the nearest grout line centre, per axis.
    let dist = |p: u32| {
        let l = (p as f32 + 0.5) % pitch;
        l.min(pitch - l)
    };
    let inner = GROUT_HALF_WIDTH + BEVEL_WIDTH;
    let ex = (inner - dist(x)).max(0.0);
    let ey = (inner - dist(y)).max(0.0);
    let e = (ex * ex + ey * ey).sqrt();
    if e >= BEVEL_WIDTH {
        return 0.0;
    }
    let s = 1.0 - e / BEVEL_WIDTH;
    1.0 - (1.0 - s) * (1.0 - s)
}

/// A 128×128 8-bit height map of 4×4 square tiles: grout lines 3 px wide (0), rounded bevels
/// 4 px wide, flat tops (255). Grout lines are centred on the image edges, so it is seamless.
#[must_use]
pub fn tiles_height() -> GrayImage {
    GrayImage::from_fn(TILES_SIZE, TILES_SIZE, |x, y| {
        Luma([(tile_height(x, y) * 255.0 + 0.5) as u8])
    })
}

/// Height of white in [`tiles_height`] per image width that [`tiles_normal`] encodes: the
/// relief of the tiled wall of `scenes/bump_map.ron` (depth 0.01 over a 2-unit repeat).
pub const TILES_NORMAL_RELIEF: f32 = 0.005;

/// The tangent-space normal map of [`tiles_height`] (its 8-bit grey values g/255 as heights,
/// white [`TILES_NORMAL_RELIEF`] high per image width), for a material's `normal_map`: with
/// central differences (wrapping) g_u = ∂g/∂u, g_v = ∂g/∂v in image units (v down), the normal
/// is normalize(−R g_u, R g_v, 1) (x right, y up the image, z out), each channel written as
/// round(127 c + 128) (so 128 is 0, as the renderer decodes it). Seamless.
#[must_use]
pub fn tiles_normal() -> RgbImage {
    let heights = tiles_height();
    let n = TILES_SIZE as i64;
    let g = |x: i64, y: i64| {
        f32::from(
            heights
                .get_pixel(x.rem_euclid(n) as u32, y.rem_euclid(n) as u32)
                .0[0],
        ) / 255.0
    };
    let encode = |c: f32| (127.0 * c + 128.0).round().clamp(0.0, 255.0) as u8;
    RgbImage::from_fn(TILES_SIZE, TILES_SIZE, |x, y| {
        let (x, y) = (i64::from(x), i64::from(y));
        let scale = TILES_NORMAL_RELIEF * TILES_SIZE as f32 * 0.5;
        let gu = (g(x + 1, y) - g(x - 1, y)) * scale;
        let gv = (g(x, y + 1) - g(x, y - 1)) * scale;
        let len = (gu * gu + gv * gv + 1.0).sqrt();
        Rgb([encode(-gu / len), encode(gv / len), encode(1.0 / len)])
    })
}

/// A 128×128 sRGB colour image aligned with [`tiles_height`]: pale, slightly varied off-white
/// glazed tiles with a faint mottle, the glaze a little darker down the bevels, and speckled
/// warm grey grout.
#[must_use]
pub fn tiles_color() -> RgbImage {
    let pitch = TILES_SIZE / TILES_PER_SIDE;
    let tile = [0.93, 0.91, 0.86];
    let grout = [0.52, 0.50, 0.47];
    RgbImage::from_fn(TILES_SIZE, TILES_SIZE, |x, y| {
        let h = tile_height(x, y);
        let speck = hash01(x as i32, y as i32, 0x6A0A7) - 0.5;
        if h <= 0.0 {
            return to_rgb8(grout.map(|g| g * (1.0 + 0.12 * speck)));
        }
        // The tile a pixel belongs to (the one whose square contains it).
        let (tx, ty) = ((x / pitch) as i32, (y / pitch) as i32);
        let s = hash(tx, ty, 0x711E5);
        let t = |i: i32| hash01(i, 0, s) - 0.5;
        let tint = [1.0 + 0.03 * t(0), 1.0 + 0.03 * t(1), 1.0 + 0.05 * t(2)];
        let bright = 1.0 + 0.04 * t(3);
        let (xf, yf) = (x as f32, y as f32);
        // Mottle, keyed by tile (tiles never straddle the image edge: grout runs along it).
        let mottle = 0.025 * (value_noise(xf / 6.0, yf / 6.0, s) - 0.5) + 0.01 * speck;
        let glaze = lerp(0.82, 1.0, h);
        to_rgb8([0, 1, 2].map(|i| tile[i] * tint[i] * bright * glaze * (1.0 + mottle)))
    })
}

/// A 64×64 8-bit linear ramp in x: grey level `round(255 · x / 63)`, the same in every row — a
/// height map with an analytic constant slope for bump-mapping tests.
#[must_use]
pub fn ramp_height() -> GrayImage {
    let max = (RAMP_SIZE - 1) as f32;
    GrayImage::from_fn(RAMP_SIZE, RAMP_SIZE, |x, _| {
        Luma([(x as f32 / max * 255.0 + 0.5) as u8])
    })
}

/// Width of the generated HDR sky (equirectangular, 2:1).
pub const SKY_WIDTH: u32 = 128;
/// Height of the generated HDR sky.
pub const SKY_HEIGHT: u32 = 64;
/// Centre of the sky's sun in image coordinates `(u, v)` (v = θ/π from the zenith): 36°
/// above the horizon.
pub const SKY_SUN_UV: (f32, f32) = (0.3, 0.3);

/// A procedural linear-radiance sky for environment lighting (issue #25), equirectangular with
/// row 0 at the zenith (the convention of `render_scene::light::environment`): a blue-to-white
/// gradient above the horizon, a dim brown ground below it, and a sun (a bright spot, peak
/// radiance ≈ 200, radius ≈ 2 texels) with a soft glow. Only `+ − × ÷` in floating point, so
/// the values do not depend on the platform's maths library.
#[must_use]
pub fn sky() -> image::Rgb32FImage {
    let (w, h) = (SKY_WIDTH, SKY_HEIGHT);
    image::Rgb32FImage::from_fn(w, h, |x, y| {
        let s = (x as f32 + 0.5) / w as f32;
        let t = (y as f32 + 0.5) / h as f32;
        // Elevation proxy: 1 at the zenith, 0 at the horizon, −1 at the nadir.
        let e = 1.0 - 2.0 * t;
        let base = if e > 0.0 {
            let k = 1.0 - (1.0 - e) * (1.0 - e);
            let (zenith, horizon) = ([0.25, 0.45, 0.9], [0.9, 0.95, 1.0]);
            [0, 1, 2].map(|c| lerp(horizon[c], zenith[c], k))
        } else {
            [0.12, 0.1, 0.08]
        };
        // The sun: distance in (2·Δu, Δv) so one unit is the same angle along both axes at
        // the horizon; Δu wraps around.
        let mut du = s - SKY_SUN_UV.0;
        if du > 0.5 {
            du -= 1.0;
        } else if du < -0.5 {
            du += 1.0;
        }
        let dv = t - SKY_SUN_UV.1;
        let r2 = 4.0 * du * du + dv * dv;
        let disc = (1.0 - r2 / (0.03 * 0.03)).max(0.0);
        let glow = (1.0 - r2 / (0.2 * 0.2)).max(0.0);
        let sun = 200.0 * disc * disc;
        let halo = 1.5 * glow * glow;
        let tint = [1.0, 0.9, 0.75];
        image::Rgb([0, 1, 2].map(|c| base[c] + (sun + halo) * tint[c]))
    })
}

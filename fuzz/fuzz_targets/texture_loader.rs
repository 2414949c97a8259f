//! Arbitrary bytes as a texture image file (PNG, JPEG or EXR, recognised by content): decoded
//! under the texture limits exactly as the renderer's `MipMap::open` / `open_grey` do, then the
//! pyramid's shape is checked and it is looked up at awkward coordinates and footprints.
//!
//! The raw file is the whole input (so image files seed the corpus as they are); whether the
//! colour pyramid decodes from sRGB follows the input length's parity.
#![no_main]

use std::sync::Arc;

use caustic::texture::{BitmapTexture, HeightMap, MipMap, Texel};
use glam::{Vec2, Vec3};
use libfuzzer_sys::fuzz_target;

/// Texture coordinates: inside, on the edges, outside (repeat wrap), huge and non-finite.
const UVS: [(f32, f32); 9] = [
    (0.0, 0.0),
    (0.5, 0.5),
    (0.999_999, 1.0),
    (-0.25, 1.75),
    (1e-30, -1e-30),
    (3.0e7, -7.0e9),
    (f32::MAX, f32::MIN),
    (f32::NAN, 0.5),
    (f32::INFINITY, f32::NEG_INFINITY),
];

/// Footprints: sharpest, tiny, one texel-ish, the whole image, huge, and invalid ones.
const FOOTPRINTS: [f32; 9] = [
    0.0,
    1e-30,
    1e-3,
    0.1,
    1.0,
    1e30,
    f32::INFINITY,
    -1.0,
    f32::NAN,
];

/// Checks the pyramid's level sizes and that every lookup lies within the range of the image
/// (`range` maps a texel to its components, so colours are checked per channel).
fn check<T: Texel + std::fmt::Debug, const N: usize>(
    mip: &MipMap<T>,
    range: impl Fn(T) -> [f32; N],
) {
    let (w, h) = (mip.width(), mip.height());
    assert!(w >= 1 && h >= 1);
    let mut size = (w, h);
    for l in 0..mip.levels() {
        assert_eq!(mip.level_size(l), size, "level {l} of {w}x{h}");
        size = ((size.0 / 2).max(1), (size.1 / 2).max(1));
    }
    assert_eq!(mip.level_size(mip.levels() - 1), (1, 1));
    assert_eq!(mip.levels() as u32, 32 - w.max(h).leading_zeros());

    let (mut lo, mut hi) = ([f32::INFINITY; N], [f32::NEG_INFINITY; N]);
    for y in 0..i64::from(h) {
        for x in 0..i64::from(w) {
            for (c, v) in range(mip.texel(0, x, y)).into_iter().enumerate() {
                assert!(v.is_finite(), "texel ({x}, {y}) = {v}");
                lo[c] = lo[c].min(v);
                hi[c] = hi[c].max(v);
            }
        }
    }
    for &(u, v) in &UVS {
        for &fp in &FOOTPRINTS {
            let level = mip.level_for(fp);
            assert!(
                (0.0..=(mip.levels() - 1) as f32).contains(&level),
                "{fp} → {level}"
            );
            let t = mip.lookup(Vec2::new(u, v), fp);
            for (c, x) in range(t).into_iter().enumerate() {
                // Filtering is a convex combination of texels: within their range, give or take
                // rounding.
                let eps = 1e-4 * hi[c].abs().max(lo[c].abs()).max(1.0);
                assert!(
                    x.is_finite() && x >= lo[c] - eps && x <= hi[c] + eps,
                    "lookup({u}, {v}; {fp}) = {t:?} outside [{lo:?}, {hi:?}]"
                );
            }
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let srgb = data.len() % 2 == 0;
    if let Ok(mip) = MipMap::<Vec3>::from_bytes(data, srgb) {
        check(&mip, |c: Vec3| c.to_array());
        let tex = BitmapTexture::new(Arc::new(mip), Vec2::new(3.0, 0.5));
        for &(u, v) in &UVS[..6] {
            for &fp in &FOOTPRINTS {
                assert!(tex.eval(Vec2::new(u, v), fp).is_finite());
            }
        }
    }
    if let Ok(grey) = MipMap::<f32>::from_bytes_grey(data) {
        check(&grey, |h| [h]);
        let map = HeightMap::new(Arc::new(grey), 0.01, Vec2::new(4.0, 2.0));
        for &(u, v) in &UVS[..6] {
            for &fp in &FOOTPRINTS {
                let uv = Vec2::new(u, v);
                assert!(map.height(uv, fp).is_finite());
                assert!(map.gradient(uv, fp).is_finite(), "gradient({uv}; {fp})");
                let n = map.perturb(Vec3::Z, Vec3::X, Vec3::Y, uv, fp);
                assert!(n.is_finite() && (n.length() - 1.0).abs() < 1e-3, "{n}");
            }
        }
    }
});

//! The EXR encoder both image writers use (the plain image of `output` and the layered one of
//! `layers`): float channels in one part, lossless compression, encoded on one thread so that
//! the same image always gives the same bytes.

use std::io::Cursor;

use exr::prelude::{
    AnyChannel, AnyChannels, Encoding, FlatSamples, Image, Layer as ExrLayer, LayerAttributes,
    SmallVec, Vec2, WritableImage,
};

/// Encodes a `width` × `height` RGB image (`value(i)` for pixel `i`, row-major) as EXR bytes:
/// 32-bit float channels `R, G, B`, lossless compression, written on one thread so that the
/// same image always gives the same bytes (parallel compression writes its blocks in whatever
/// order they finish).
///
/// # Errors
/// The encoder's error.
pub fn encode_rgb_exr(
    width: usize,
    height: usize,
    value: &dyn Fn(usize) -> glam::Vec3,
) -> Result<Vec<u8>, exr::error::Error> {
    let channels = rgb_channels(width * height, "", value).into();
    encode_channels(width, height, channels)
}

/// Three float channels `<name>.R/G/B` (`R, G, B` for an empty name) of `n` pixels.
pub fn rgb_channels(
    n: usize,
    name: &str,
    value: &dyn Fn(usize) -> glam::Vec3,
) -> [AnyChannel<FlatSamples>; 3] {
    let mut c = [
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    ];
    for v in (0..n).map(value) {
        c[0].push(v.x);
        c[1].push(v.y);
        c[2].push(v.z);
    }
    let prefix = if name.is_empty() {
        String::new()
    } else {
        format!("{name}.")
    };
    let [r, g, b] = c;
    [
        AnyChannel::new(format!("{prefix}R").as_str(), FlatSamples::F32(r)),
        AnyChannel::new(format!("{prefix}G").as_str(), FlatSamples::F32(g)),
        AnyChannel::new(format!("{prefix}B").as_str(), FlatSamples::F32(b)),
    ]
}

/// One EXR part holding `channels`, encoded on one thread (deterministic bytes).
///
/// # Errors
/// The encoder's error.
pub fn encode_channels(
    width: usize,
    height: usize,
    channels: Vec<AnyChannel<FlatSamples>>,
) -> Result<Vec<u8>, exr::error::Error> {
    let layer = ExrLayer::new(
        Vec2(width, height),
        LayerAttributes::default(),
        Encoding::FAST_LOSSLESS,
        AnyChannels::sort(SmallVec::from_vec(channels)),
    );
    let mut bytes = Cursor::new(Vec::new());
    Image::from_layer(layer)
        .write()
        .non_parallel()
        .to_buffered(&mut bytes)?;
    Ok(bytes.into_inner())
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::encode_rgb_exr;

    #[test]
    fn the_same_image_always_encodes_to_the_same_bytes() {
        // Large enough for many compressed blocks: a parallel encoder wrote them in whatever
        // order they finished, so repeated encodings differed.
        let value = |i: usize| Vec3::new(i as f32 * 1e-3, (i % 97) as f32, (i % 13) as f32 * 0.5);
        let first = encode_rgb_exr(320, 200, &value).expect("encodes");
        for _ in 0..8 {
            let again = encode_rgb_exr(320, 200, &value).expect("encodes");
            assert!(again == first, "EXR bytes differ between two encodings");
        }
        let image = image::load_from_memory(&first)
            .expect("decodes")
            .into_rgb32f();
        assert_eq!(image.get_pixel(5, 1).0, value(325).to_array());
    }
}

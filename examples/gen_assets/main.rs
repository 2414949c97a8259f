//! Regenerates the procedural assets under `assets/` (nothing is downloaded):
//! `cargo run --example gen_assets`.
//!
//! - `blob.obj`: a low-poly bumpy blob with vertex normals.
//! - `hardwood.png`: a seamless 256×256 tile of hardwood floor planks (a moiré test at grazing
//!   angles).
//! - `tiles_height.png`, `tiles_color.png`: a seamless 128×128 height map of 4×4 bevelled square
//!   tiles with grout, and the matching colour image.
//! - `tiles_normal.png`: the tangent-space normal map of `tiles_height.png` (OpenGL convention,
//!   8-bit 128 = 0).
//! - `ramp_height.png`: a 64×64 linear ramp in x, for bump mapping with an analytic tilt.
//! - `sky.exr`: a 128×64 equirectangular linear HDR sky (gradient, ground, sun) for environment
//!   lighting.
//!
//! The image generators live in `images.rs` so `tests/assets.rs` can check the committed files.

mod images;

use std::fs::File;
use std::io::BufWriter;
use std::path::Path;

use image::codecs::png::{CompressionType, FilterType, PngEncoder};
use image::{ExtendedColorType, ImageEncoder};

/// Writes 8-bit pixels as a maximally compressed PNG.
fn write_png(
    path: &Path,
    (w, h): (u32, u32),
    pixels: &[u8],
    color: ExtendedColorType,
) -> std::io::Result<()> {
    let out = BufWriter::new(File::create(path)?);
    PngEncoder::new_with_quality(out, CompressionType::Best, FilterType::Adaptive)
        .write_image(pixels, w, h, color)
        .map_err(std::io::Error::other)?;
    let bytes = std::fs::metadata(path)?.len();
    println!(
        "assets/{}: {w}×{h}, {bytes} bytes",
        path.file_name().unwrap_or_default().display()
    );
    Ok(())
}

fn main() -> std::io::Result<()> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
    std::fs::create_dir_all(&root)?;
    // A low-poly bumpy blob with vertex normals: a smooth-shaded closed mesh for demos and tests.
    let blob = caustic::bench::blob::blob_mesh(10);
    let mut out = BufWriter::new(File::create(root.join("blob.obj"))?);
    caustic::bench::blob::write_obj(&blob, &mut out)?;
    println!(
        "assets/blob.obj: {} vertices, {} triangles",
        blob.positions.len(),
        blob.triangles.len()
    );

    let rgb = |name: &str, img: image::RgbImage| {
        write_png(
            &root.join(name),
            img.dimensions(),
            img.as_raw(),
            ExtendedColorType::Rgb8,
        )
    };
    let grey = |name: &str, img: image::GrayImage| {
        write_png(
            &root.join(name),
            img.dimensions(),
            img.as_raw(),
            ExtendedColorType::L8,
        )
    };
    rgb("hardwood.png", images::hardwood())?;
    grey("tiles_height.png", images::tiles_height())?;
    rgb("tiles_color.png", images::tiles_color())?;
    rgb("tiles_normal.png", images::tiles_normal())?;
    grey("ramp_height.png", images::ramp_height())?;
    let sky = images::sky();
    let path = root.join("sky.exr");
    sky.save(&path).map_err(std::io::Error::other)?;
    println!(
        "assets/sky.exr: {}×{} linear RGB float, {} bytes",
        sky.width(),
        sky.height(),
        std::fs::metadata(&path)?.len()
    );
    Ok(())
}

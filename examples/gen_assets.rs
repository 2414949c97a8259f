//! Regenerates the procedural assets under `assets/` (nothing is downloaded):
//! `cargo run --example gen_assets`.

use std::fs::File;
use std::io::BufWriter;

fn main() -> std::io::Result<()> {
    let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("assets");
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
    Ok(())
}

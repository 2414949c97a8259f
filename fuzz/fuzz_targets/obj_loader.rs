//! Arbitrary bytes as an OBJ file.
#![no_main]

use std::path::Path;

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(mesh) = caustic::compile::mesh::parse_obj(data, Path::new("fuzz.obj")) {
        let n = (mesh.positions.len(), mesh.normals.len(), mesh.uvs.len());
        for tri in &mesh.triangles {
            for c in tri {
                assert!((c.p as usize) < n.0);
                assert!(c.n.is_none_or(|i| (i as usize) < n.1));
                assert!(c.t.is_none_or(|i| (i as usize) < n.2));
            }
        }
    }
});

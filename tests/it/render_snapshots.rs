//! Every scene in `scenes/` rendered small and compared byte for byte with its reviewed PNG
//! snapshot (`tests/it/snapshots/it__render_snapshots__*.snap` + `.png`): any pixel change fails and
//! leaves the new image beside the old one for review (`cargo insta review`).

use crate::common;

use caustic::render::RenderOptions;
use caustic::render::output::encode;

#[test]
fn every_scene_matches_its_snapshot() {
    for path in common::scene_files() {
        let name = path
            .file_name()
            .and_then(|n| n.to_str())
            .unwrap_or("scene")
            .replace('.', "_");
        let options = RenderOptions {
            threads: Some(2),
            ..RenderOptions::default()
        };
        let (film, stats) = common::render_file(&path, &common::small(64, 64, 4), &options);
        assert_eq!(stats.nan_samples, 0, "{}: NaN/Inf samples", path.display());
        assert!(
            film.mean().max_element() > 0.01,
            "{}: image is black",
            path.display()
        );
        let png = encode(&film, std::path::Path::new("x.png"), 1.0).expect("png encodes");
        insta::assert_binary_snapshot!(&format!("{name}.png"), png);
    }
}

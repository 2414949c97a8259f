//! What `caustic preview` watches: the scene file and every asset it names (OBJ meshes,
//! texture images), through `notify` (inotify on Linux). Each file's folder is watched rather
//! than the file itself, so editors that save by writing a new file and renaming it over the
//! old one are seen too; events on other files of those folders are ignored.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

use notify::{EventKind, RecommendedWatcher, RecursiveMode, Watcher};

use caustic::scene::SceneFile;
use caustic::scene::schema::{NodeSpec, TextureSpec};

/// The files a scene reads besides itself, resolved against `base_dir` (the scene's folder):
/// texture images and OBJ meshes, each once, sorted.
pub fn asset_files(scene: &SceneFile, base_dir: &Path) -> BTreeSet<PathBuf> {
    let mut files = BTreeSet::new();
    for texture in scene.textures.values() {
        match texture {
            TextureSpec::Bitmap { file, .. }
            | TextureSpec::HeightMap { file, .. }
            | TextureSpec::NormalMap { file, .. } => {
                files.insert(base_dir.join(file));
            }
            TextureSpec::Marble { .. } | TextureSpec::Noise { .. } | TextureSpec::Ripple { .. } => {
            }
        }
    }
    let mut stack: Vec<&NodeSpec> = scene.nodes.iter().collect();
    while let Some(node) = stack.pop() {
        match node {
            NodeSpec::Group { children, .. } => stack.extend(children),
            NodeSpec::Mesh { file, .. } | NodeSpec::Gltf { file, .. } => {
                files.insert(base_dir.join(file));
            }
            NodeSpec::Sphere { .. }
            | NodeSpec::Cube { .. }
            | NodeSpec::Quad { .. }
            | NodeSpec::Disc { .. }
            | NodeSpec::Cylinder { .. } => {}
        }
    }
    files
}

/// `path` made absolute and, where it exists, with symbolic links resolved (how the watcher
/// reports it).
fn normalized(path: &Path) -> PathBuf {
    path.canonicalize()
        .or_else(|_| std::path::absolute(path))
        .unwrap_or_else(|_| path.to_path_buf())
}

/// Watches a set of files and calls back when one of them is written, created, renamed or
/// removed.
pub struct FileWatch {
    watcher: RecommendedWatcher,
    /// The files of interest (normalized), shared with the watcher's callback.
    files: Arc<Mutex<BTreeSet<PathBuf>>>,
    /// Folders currently watched.
    dirs: BTreeSet<PathBuf>,
}

impl FileWatch {
    /// Starts a watcher that calls `changed` (on the watcher's own thread) for each event on a
    /// watched file.
    ///
    /// # Errors
    /// When the platform's file watcher cannot start (e.g. inotify limits reached).
    pub fn new(changed: impl Fn() + Send + 'static) -> notify::Result<Self> {
        let files: Arc<Mutex<BTreeSet<PathBuf>>> = Arc::default();
        let seen = Arc::clone(&files);
        let watcher = notify::recommended_watcher(move |event: notify::Result<notify::Event>| {
            let Ok(event) = event else { return };
            if matches!(event.kind, EventKind::Access(_)) {
                return;
            }
            let hit = seen.lock().is_ok_and(|files| {
                event
                    .paths
                    .iter()
                    .any(|p| files.contains(p) || files.contains(&normalized(p)))
            });
            if hit {
                changed();
            }
        })?;
        Ok(Self {
            watcher,
            files,
            dirs: BTreeSet::new(),
        })
    }

    /// Watches exactly `files` from now on (their folders; folders no longer needed are let go).
    /// Returns a warning for each folder that cannot be watched.
    pub fn set(&mut self, files: impl IntoIterator<Item = PathBuf>) -> Vec<String> {
        let files: BTreeSet<PathBuf> = files.into_iter().map(|f| normalized(&f)).collect();
        let dirs: BTreeSet<PathBuf> = files
            .iter()
            .filter_map(|f| f.parent().map(Path::to_path_buf))
            .collect();
        if let Ok(mut mine) = self.files.lock() {
            *mine = files;
        }
        let mut warnings = Vec::new();
        for gone in self.dirs.difference(&dirs) {
            // A folder that was removed is no longer watched anyway.
            let _ = self.watcher.unwatch(gone);
        }
        for new in dirs.difference(&self.dirs) {
            if let Err(e) = self.watcher.watch(new, RecursiveMode::NonRecursive) {
                warnings.push(format!(
                    "warning: cannot watch `{}` for changes: {e}",
                    new.display()
                ));
            }
        }
        self.dirs = dirs;
        warnings
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn assets_are_the_textures_and_meshes_of_the_scene_and_its_groups() {
        let text = r#"(
            camera: Pinhole(eye: (0, 0, 5), look_at: (0, 0, 0), up: (0, 1, 0), fov_y: 40),
            textures: {
                "wood": Bitmap(file: "tex/wood.png"),
                "bumps": HeightMap(file: "tex/h.png", depth: 0.01),
            },
            materials: { "m": (color: (0.5, 0.5, 0.5)) },
            nodes: [
                Mesh(file: "a.obj", material: "m"),
                Group(children: [Group(children: [Mesh(file: "deep/b.obj", material: "m")])]),
                Sphere(material: "m", center: (0, 0, 0), radius: 1),
            ],
        )"#;
        let source =
            caustic::scene::SourceFile::new(Path::new("/s/x.ron"), text.into()).expect("source");
        let scene = source.parse().expect("parses");
        let got: Vec<PathBuf> = asset_files(&scene, Path::new("/s")).into_iter().collect();
        let want: Vec<PathBuf> = [
            "/s/a.obj",
            "/s/deep/b.obj",
            "/s/tex/h.png",
            "/s/tex/wood.png",
        ]
        .iter()
        .map(PathBuf::from)
        .collect();
        assert_eq!(got, want);
    }
}

//! Reading a scene file: RON or TOML by extension, deserialised into the schema with the field
//! path and file position of any error.

use std::path::Path;

pub use super::error::SceneError;
use super::schema::SceneFile;
pub use super::source::SourceFile;

/// A parsed (not yet validated) scene with its source.
#[derive(Debug)]
pub struct LoadedScene {
    /// Where it came from.
    pub source: SourceFile,
    /// The typed scene.
    pub scene: SceneFile,
}

/// Reads and parses a scene file (no validation).
pub fn load(path: &Path) -> Result<LoadedScene, SceneError> {
    let source = SourceFile::read(path)?;
    let scene = source.parse()?;
    Ok(LoadedScene { source, scene })
}

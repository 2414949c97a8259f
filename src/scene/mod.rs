//! The scene file: schema, loading (RON or TOML), command-line overrides and validation.
//! Nothing here knows how to render.

pub mod diagnostic;
pub mod load;
pub mod locate;
pub mod overrides;
mod parse;
pub mod schema;
pub mod validate;

pub use diagnostic::{Diagnostic, Severity};
pub use load::{LoadedScene, SceneError, SourceFile};
pub use schema::SceneFile;

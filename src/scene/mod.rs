//! The scene file: schema, loading (RON or TOML), command-line overrides and validation.
//! Nothing here knows how to render.

mod brackets;
pub mod diagnostic;
pub mod error;
mod lexer;
pub mod load;
pub mod locate;
pub mod overrides;
mod parse;
pub mod schema;
pub mod source;
pub mod validate;

pub use diagnostic::{Diagnostic, Severity};
pub use error::SceneError;
pub use load::LoadedScene;
pub use schema::SceneFile;
pub use source::SourceFile;

//! The integration tests, as one binary (one link of the library instead of one per file).

mod architecture;
mod assets;
mod bad_scenes;
mod cli;
mod common;
mod determinism;
mod hard_cases;
mod interrupt;
mod kdtree;
mod mutated_scenes;
mod primitives;
mod queries;
mod render_snapshots;
mod textures;
mod watertight;

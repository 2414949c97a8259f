//! The integration tests, as one binary (one link of the library instead of one per file).

mod architecture;
mod assets;
mod bad_scenes;
mod bath;
mod cli;
mod common;
mod determinism;
mod doc_images;
mod doc_snippets;
mod hard_cases;
mod interrupt;
mod kdtree;
mod light_transport;
mod models;
mod mutated_scenes;
mod passes;
mod path_tracer;
mod photon_map;
mod photon_tools;
mod primitives;
mod queries;
mod render_snapshots;
mod reported;
mod textures;
mod watertight;

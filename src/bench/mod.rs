//! Benchmark workloads shared by `cargo bench` and tests.

pub mod blob;

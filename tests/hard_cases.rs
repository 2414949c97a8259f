//! The numerical hard-case suite (issue #7): each case asserts a figure. Cases that need
//! features not built yet (photon maps) are added with those features.

mod common;

#[path = "hard_cases/acne.rs"]
mod acne;
#[path = "hard_cases/dielectrics.rs"]
mod dielectrics;
#[path = "hard_cases/extremes.rs"]
mod extremes;
#[path = "hard_cases/reintersect.rs"]
mod reintersect;
#[path = "hard_cases/shading_normals.rs"]
mod shading_normals;
#[path = "hard_cases/support.rs"]
mod support;

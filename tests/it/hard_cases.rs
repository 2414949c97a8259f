//! The numerical hard-case suite (issue #7): each case asserts a figure. Cases that need
//! features not built yet (photon maps) are added with those features.

mod acne;
mod dielectrics;
mod extremes;
mod reintersect;
mod shading_normals;
mod support;

//! Spatial search: the uniform [`HashGrid`] of per-pass photon lookups, the sparse per-voxel
//! [`VoxelTable`] built on it, the balanced 3-d [`KdTree`] that stores any positioned item
//! ([`HasPosition`]) in flat arrays and answers k-nearest and fixed-radius
//! queries without allocating (Jensen, "Realistic Image Synthesis Using Photon Mapping", 2001,
//! ch. 6), its bounded k-nearest heap, and the packed [`Photon`] record the photon maps store in
//! it. Layout, memory per photon and speed are in `docs/photon_map.md`.
//!
//! ```
//! use caustic::spatial::{KdTree, KnnHeap, Photon};
//! use glam::Vec3;
//!
//! let photons: Vec<Photon> = (0..100)
//!     .map(|i| Photon::new(Vec3::new(i as f32, 0.0, 0.0), -Vec3::Y, Vec3::Y, Vec3::splat(0.01)))
//!     .collect();
//! let map = KdTree::build(photons)?;
//! let mut heap = KnnHeap::new(3);
//! assert_eq!(map.nearest([10.2, 0.0, 0.0], f32::INFINITY, &mut heap), 3);
//! heap.sort();
//! let xs: Vec<f32> = heap.iter().map(|n| map.items()[n.index as usize].position().x).collect();
//! assert_eq!(xs, [10.0, 11.0, 9.0]);
//! # Ok::<(), caustic::spatial::KdTreeError>(())
//! ```

pub mod hash_grid;
pub mod kdtree;
pub mod knn;
pub mod packing;
pub mod voxel_table;

pub use hash_grid::{CellIndex, HashGrid, HashGridError, Visit};
pub use kdtree::{BuildOptions, HasPosition, KdTree, KdTreeError, SplitAxis, distance2};
pub use knn::{KnnHeap, Neighbor};
pub use packing::Photon;
pub use voxel_table::{VOXEL_OFFSET, VoxelTable};

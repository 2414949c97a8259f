//! A sparse table over the cubic voxels of a uniform grid: points are grouped by the voxel they
//! fall in, each occupied voxel's group is reduced to one value, and a query point finds its
//! voxel's value (if any) with one hash lookup ([`HashGrid`]). What the learned light choice of
//! next-event estimation (`integrators::light_guide`) and the pilot radius field of progressive
//! photon mapping (`integrators::photon::radius_field`) both keep per region of space.
//!
//! The grid is shifted by a non-round fraction of a voxel ([`VOXEL_OFFSET`]), so that the planes
//! of axis-aligned walls (often at round coordinates, 0 above all) do not fall on voxel faces,
//! where rounding would split a wall's points between two voxels and leave queries on it in
//! empty ones.
//!
//! Deterministic: groups are formed by a stable sort on the voxel, so each group's values keep
//! their input order and the voxels' order (and so the values' indices) depends only on the input.

use glam::Vec3;

use super::hash_grid::{HashGrid, HashGridError};
use super::kdtree::HasPosition;

/// The grid's offset, in voxel sides (a non-round fraction; see the module docs).
pub const VOXEL_OFFSET: [f32; 3] = [0.3719, 0.6180, 0.2113];

/// One occupied voxel: a point of its group (shifted by the offset) and its value's index.
#[derive(Debug, Clone, Copy)]
struct Entry {
    position: [f32; 3],
    index: u32,
}

impl HasPosition for Entry {
    #[inline]
    fn position(&self) -> [f32; 3] {
        self.position
    }
}

/// The occupied voxels of side `side` and, for each, the index of its value (see the module
/// docs); the values themselves are kept by the caller, in the order [`VoxelTable::build`]
/// returned them.
#[derive(Debug, Clone)]
pub struct VoxelTable {
    /// Boxed: the table is a field of the path tracer, kept small.
    grid: Box<HashGrid<Entry>>,
    /// [`VOXEL_OFFSET`] in scene units.
    offset: Vec3,
}

impl Default for VoxelTable {
    fn default() -> Self {
        Self {
            grid: Box::default(),
            offset: Vec3::ZERO,
        }
    }
}

impl VoxelTable {
    /// Groups `items` (a position and a value each) by voxel of side `side` (scene units) and
    /// reduces each group with `reduce` (its values in input order; `None` leaves the voxel
    /// out). Returns the table and the kept voxels' reduced values, index `i` for the `i`-th.
    ///
    /// # Errors
    /// [`HashGridError`] when `side` is not finite and positive or a position is not finite.
    pub fn build<T, V>(
        side: f32,
        items: impl IntoIterator<Item = (Vec3, T)>,
        mut reduce: impl FnMut(&mut [T]) -> Option<V>,
    ) -> Result<(Self, Vec<V>), HashGridError> {
        if !(side.is_finite() && side > 0.0) {
            return Err(HashGridError::InvalidCell(side));
        }
        let inv = 1.0 / side;
        let offset = Vec3::from_array(VOXEL_OFFSET) * side;
        let mut keyed: Vec<([i32; 3], [f32; 3], T)> = items
            .into_iter()
            .map(|(p, v)| {
                let p = (p + offset).to_array();
                (p.map(|x| (x * inv).floor() as i32), p, v)
            })
            .collect();
        keyed.sort_by_key(|k| k.0);
        let mut entries = Vec::new();
        let mut values = Vec::new();
        let mut group = Vec::new();
        let mut rest = keyed.into_iter().peekable();
        while let Some((cell, position, v)) = rest.next() {
            group.clear();
            group.push(v);
            while let Some((_, _, v)) = rest.next_if(|k| k.0 == cell) {
                group.push(v);
            }
            if let Some(value) = reduce(&mut group) {
                entries.push(Entry {
                    position,
                    index: values.len() as u32,
                });
                values.push(value);
            }
        }
        let grid = Box::new(HashGrid::build(entries, side)?);
        Ok((Self { grid, offset }, values))
    }

    /// The value index of the voxel containing `p`, if it is in the table.
    #[inline]
    #[must_use]
    pub fn get(&self, p: Vec3) -> Option<usize> {
        if self.grid.is_empty() {
            return None;
        }
        let mut found = None;
        let c = self.grid.cell_of((p + self.offset).to_array());
        self.grid
            .in_cell(c, |i| found = Some(self.grid.items()[i].index as usize));
        found
    }

    /// Voxels in the table.
    #[must_use]
    pub fn len(&self) -> usize {
        self.grid.len()
    }

    /// True when no voxel is in the table.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.grid.is_empty()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn groups_by_voxel_and_finds_each_points_group() {
        // Voxels of side 1 (shifted by the offset): (0.1, 0.1, 0.1) and (0.2, 0.3, 0.1) share one,
        // (5, 5, 5) is alone, and a group the reduction rejects is left out.
        let items = vec![
            (Vec3::splat(0.1), 1.0f32),
            (Vec3::splat(5.0), 10.0),
            (Vec3::new(0.2, 0.3, 0.1), 2.0),
            (Vec3::splat(-7.0), -1.0),
        ];
        let (table, sums) = VoxelTable::build(1.0, items, |g| {
            let s: f32 = g.iter().sum();
            (s > 0.0).then_some(s)
        })
        .expect("valid");
        assert_eq!(table.len(), 2);
        assert_eq!(
            table.get(Vec3::new(0.15, 0.2, 0.3)).map(|i| sums[i]),
            Some(3.0)
        );
        assert_eq!(table.get(Vec3::splat(5.2)).map(|i| sums[i]), Some(10.0));
        assert_eq!(table.get(Vec3::splat(-7.0)), None);
        assert_eq!(table.get(Vec3::splat(2.5)), None);
        assert!(VoxelTable::build(0.0, Vec::<(Vec3, f32)>::new(), |_| Some(0)).is_err());
    }
}

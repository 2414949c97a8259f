//! A uniform spatial hash grid over positioned items, in flat arrays: the cells of side `cell`
//! are hashed into a power-of-two table of buckets (Teschner et al., "Optimized Spatial Hashing
//! for Collision Detection of Deformable Objects", VMV 2003), and the items are sorted by bucket
//! with one counting sort, so a bucket is a contiguous slice. This is the per-pass photon lookup
//! of stochastic progressive photon mapping (Hachisuka & Jensen, "Stochastic Progressive Photon
//! Mapping", SIGGRAPH Asia 2009, §4.3): built in O(n), and a fixed-radius query costs a hash per
//! cell the query's box overlaps plus the items in those cells — a small constant when the cell
//! side is about the query diameter — with no tree to descend and nothing to do in empty space.
//!
//! **Exactness.** Two cells can share a bucket (a hash collision); within a bucket the items are
//! grouped into runs, one per cell, each run knowing its cell's coordinates, and a query
//! visiting cell `c` reads only `c`'s run. So each item is considered at most once and the result
//! of [`HashGrid::within`] is exactly the brute-force set `{ i : distance2(q, pᵢ) ≤ r² }`
//! ([`super::distance2`], computed the same way eight items at a time), whatever the collisions.
//! A query whose box spans more cells than the grid has items falls back to a scan of all items
//! (a radius larger than the scene), which gives the same set.
//!
//! **Determinism.** The counting sort and the grouping by cell are stable, so the item order,
//! and with it every query's visiting order (cells in z, y, x order, each cell's items in input
//! order), depends only on the input order.
//!
//! **Positions must be finite** and the cell side finite and positive ([`HashGridError`]).

use super::kdtree::HasPosition;
use super::knn::Neighbor;
use wide::f32x8;

/// What [`HashGrid::within`] hands each item found to: any `FnMut(Neighbor)` closure, or a
/// type of the caller's whose `visit` is marked `#[inline(always)]`, so that a large per-item
/// body is inlined into the search's loop where the compiler would call a closure out of line.
pub trait Visit {
    /// Receives one item found (its index into [`HashGrid::items`] and squared distance).
    fn visit(&mut self, n: Neighbor);
}

impl<F: FnMut(Neighbor)> Visit for F {
    #[inline(always)]
    fn visit(&mut self, n: Neighbor) {
        self(n);
    }
}

/// Why a [`HashGrid`] cannot be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum HashGridError {
    /// The cell side is not finite and positive.
    #[error("hash grid cell size {0} is invalid: it must be finite and greater than 0")]
    InvalidCell(f32),
    /// An item's position has a NaN or infinite coordinate.
    #[error("item {0} has a non-finite position")]
    NonFinite(usize),
    /// More items than a bucket range can index (`u32`).
    #[error("{0} items are too many for a hash grid (at most {max})", max = u32::MAX)]
    TooMany(usize),
}

/// Integer cell coordinates of a position.
pub type CellIndex = [i32; 3];

/// A static spatial hash grid over `T`; see the module documentation.
/// Memory: `size_of::<T>()` + 12 bytes per item (positions again, one array per axis, for the
/// eight-wide distance test), 16 bytes per occupied cell, 4 bytes per bucket (about one per item).
#[derive(Debug, Clone)]
pub struct HashGrid<T> {
    /// Items grouped by bucket, then by cell within a bucket; a cell's items keep their input
    /// order.
    items: Vec<T>,
    /// The items' coordinates per axis, in the same order, followed by [`LANES`] NaNs so that an
    /// eight-wide load starting at any item stays in bounds (a NaN is never within a radius).
    axes: [Vec<f32>; 3],
    /// The occupied cells (runs of items), grouped by bucket, then a sentinel whose `start` is
    /// the item count: run `k`'s items are `runs[k].start .. runs[k + 1].start`.
    runs: Vec<Run>,
    /// `bucket_runs[b] .. bucket_runs[b + 1]` are bucket `b`'s runs.
    bucket_runs: Vec<u32>,
    /// Cell side (scene units) and its reciprocal.
    cell: f32,
    inv_cell: f32,
    /// Bucket count − 1 (the count is a power of two).
    mask: u32,
}

/// One occupied cell of a [`HashGrid`]: its coordinates and the first of its items.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Run {
    cell: CellIndex,
    start: u32,
}

/// Items tested at once by the distance test (one AVX register).
const LANES: usize = 8;

impl<T> Default for HashGrid<T> {
    fn default() -> Self {
        Self {
            items: Vec::new(),
            axes: [
                vec![f32::NAN; LANES],
                vec![f32::NAN; LANES],
                vec![f32::NAN; LANES],
            ],
            runs: vec![Run {
                cell: [0; 3],
                start: 0,
            }],
            bucket_runs: vec![0, 0],
            cell: 1.0,
            inv_cell: 1.0,
            mask: 0,
        }
    }
}

/// The cell of coordinate `x` for reciprocal cell side `inv`: `⌊x·inv⌋`, saturating at the
/// `i32` range (a far-away point shares the outermost cell, which only costs a distance test).
#[inline]
fn cell_coord(x: f32, inv: f32) -> i32 {
    (x * inv).floor() as i32
}

/// Cells in the box from cell `lo` to cell `hi` (inclusive), saturating at `u64::MAX`.
#[inline]
fn cell_count(lo: CellIndex, hi: CellIndex) -> u64 {
    let axis = |a: usize| (i64::from(hi[a]) - i64::from(lo[a]) + 1) as u64;
    axis(0).saturating_mul(axis(1)).saturating_mul(axis(2))
}

/// Teschner et al.'s hash of a cell: the coordinates times three large primes, XORed.
#[inline]
fn hash(c: CellIndex) -> u32 {
    (c[0] as u32).wrapping_mul(73_856_093)
        ^ (c[1] as u32).wrapping_mul(19_349_663)
        ^ (c[2] as u32).wrapping_mul(83_492_791)
}

impl<T: HasPosition> HashGrid<T> {
    /// A grid of cells of side `cell` (scene units) over `items`, with a power-of-two number of
    /// buckets at least the item count. Errors: a non-finite or non-positive `cell`, a
    /// non-finite position, more than `u32::MAX` items.
    pub fn build(items: Vec<T>, cell: f32) -> Result<Self, HashGridError> {
        if !(cell.is_finite() && cell > 0.0) {
            return Err(HashGridError::InvalidCell(cell));
        }
        if items.len() >= u32::MAX as usize {
            return Err(HashGridError::TooMany(items.len()));
        }
        if let Some(i) = items
            .iter()
            .position(|it| !it.position().iter().all(|c| c.is_finite()))
        {
            return Err(HashGridError::NonFinite(i));
        }
        let inv_cell = 1.0 / cell;
        let buckets = items.len().max(1).next_power_of_two();
        let mask = (buckets - 1) as u32;
        let cells_in: Vec<CellIndex> = items
            .iter()
            .map(|it| it.position().map(|x| cell_coord(x, inv_cell)))
            .collect();
        let bucket_of = |c: CellIndex| (hash(c) & mask) as usize;
        // Counting sort by bucket (stable), then each bucket's items grouped by cell with a
        // stable sort of its (short) slice: a cell's items keep their input order.
        let mut starts = vec![0u32; buckets + 1];
        for c in &cells_in {
            starts[bucket_of(*c) + 1] += 1;
        }
        for b in 0..buckets {
            starts[b + 1] += starts[b];
        }
        let mut next = starts.clone();
        let mut order = vec![0u32; items.len()];
        for (i, c) in cells_in.iter().enumerate() {
            let b = bucket_of(*c);
            order[next[b] as usize] = i as u32;
            next[b] += 1;
        }
        let mut runs = Vec::new();
        let mut bucket_runs = vec![0u32; buckets + 1];
        for b in 0..buckets {
            let slice = &mut order[starts[b] as usize..starts[b + 1] as usize];
            if slice.len() > 1 {
                slice.sort_by_key(|&i| cells_in[i as usize]);
            }
            let mut last = None;
            for (k, &i) in slice.iter().enumerate() {
                let c = cells_in[i as usize];
                if last != Some(c) {
                    runs.push(Run {
                        cell: c,
                        start: starts[b] + k as u32,
                    });
                    last = Some(c);
                }
            }
            bucket_runs[b + 1] = runs.len() as u32;
        }
        runs.push(Run {
            cell: [0; 3],
            start: items.len() as u32,
        });
        let axes = [0, 1, 2].map(|a| {
            let mut v: Vec<f32> = order
                .iter()
                .map(|&i| items[i as usize].position()[a])
                .collect();
            v.extend([f32::NAN; LANES]);
            v
        });
        let mut slots: Vec<Option<T>> = items.into_iter().map(Some).collect();
        let items = order
            .iter()
            .filter_map(|&i| slots[i as usize].take())
            .collect();
        Ok(Self {
            items,
            axes,
            runs,
            bucket_runs,
            cell,
            inv_cell,
            mask,
        })
    }
}

impl<T: HasPosition> HashGrid<T> {
    /// The items in grid order; query results index this slice.
    #[must_use]
    pub fn items(&self) -> &[T] {
        &self.items
    }

    /// Number of items.
    #[must_use]
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True when the grid holds no items.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// The cell side (scene units).
    #[must_use]
    pub fn cell_size(&self) -> f32 {
        self.cell
    }

    /// Bytes of heap memory the grid holds.
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        self.items.capacity() * std::mem::size_of::<T>()
            + self.axes.iter().map(|a| a.capacity() * 4).sum::<usize>()
            + self.runs.capacity() * std::mem::size_of::<Run>()
            + self.bucket_runs.capacity() * 4
    }

    /// The cell that position `p` falls in.
    #[inline]
    #[must_use]
    pub fn cell_of(&self, p: [f32; 3]) -> CellIndex {
        p.map(|x| cell_coord(x, self.inv_cell))
    }

    /// The items of cell `c`: a range of [`HashGrid::items`] (empty when no item lies in it).
    #[inline]
    fn run(&self, c: CellIndex) -> std::ops::Range<usize> {
        let b = (hash(c) & self.mask) as usize;
        let (lo, hi) = (
            self.bucket_runs[b] as usize,
            self.bucket_runs[b + 1] as usize,
        );
        for k in lo..hi {
            if self.runs[k].cell == c {
                return self.runs[k].start as usize..self.runs[k + 1].start as usize;
            }
        }
        0..0
    }

    /// Calls `visit` with the index of every item in cell `c`, in grid order.
    #[inline]
    pub fn in_cell(&self, c: CellIndex, visit: impl FnMut(usize)) {
        self.run(c).for_each(visit);
    }

    /// The lowest and highest cell of the box of the ball of radius `r` around `q`.
    #[inline]
    fn cell_range(&self, q: [f32; 3], r: f32) -> (CellIndex, CellIndex) {
        (
            q.map(|x| cell_coord(x - r, self.inv_cell)),
            q.map(|x| cell_coord(x + r, self.inv_cell)),
        )
    }

    /// Calls `visit` for every item of `range` with `distance2(q, p) ≤ r2`, in item order,
    /// testing [`LANES`] items at once. The distance is [`super::distance2`]'s, operation for
    /// operation, so it is the same number.
    #[inline(always)]
    fn scan(&self, range: std::ops::Range<usize>, q: [f32; 3], r2: f32, visit: &mut impl Visit) {
        let [xs, ys, zs] = &self.axes;
        let (qx, qy, qz) = (f32x8::splat(q[0]), f32x8::splat(q[1]), f32x8::splat(q[2]));
        let limit = f32x8::splat(r2);
        let load = |v: &[f32], i: usize| -> f32x8 {
            let lanes: [f32; LANES] = v[i..i + LANES].try_into().unwrap_or([f32::NAN; LANES]);
            f32x8::from(lanes)
        };
        let mut i = range.start;
        while i < range.end {
            let (dx, dy, dz) = (qx - load(xs, i), qy - load(ys, i), qz - load(zs, i));
            let d2 = dx * dx + dy * dy + dz * dz;
            let mut hits = d2.simd_le(limit).to_bitmask();
            let left = range.end - i;
            if left < LANES {
                hits &= (1u32 << left) - 1;
            }
            if hits != 0 {
                let d2 = d2.to_array();
                while hits != 0 {
                    let lane = hits.trailing_zeros() as usize;
                    hits &= hits - 1;
                    visit.visit(Neighbor {
                        index: (i + lane) as u32,
                        dist2: d2[lane],
                    });
                }
            }
            i += LANES;
        }
    }

    /// Calls `visit` for every item with `distance2(q, p) ≤ r²`, each once, in an order that
    /// depends only on the grid and `q`, `r`. A non-finite `q` or a negative or NaN `r` visits
    /// nothing; an infinite `r` visits every item.
    #[inline]
    pub fn within(&self, q: [f32; 3], r: f32, mut visit: impl Visit) {
        if self.items.is_empty() || !(r >= 0.0) || !q.iter().all(|c| c.is_finite()) {
            return;
        }
        let r2 = r * r;
        let (lo, hi) = self.cell_range(q, r);
        if cell_count(lo, hi) > self.items.len() as u64 {
            // More cells than items (a radius as large as the scene): scan everything.
            self.scan(0..self.items.len(), q, r2, &mut visit);
            return;
        }
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let run = self.run([x, y, z]);
                    if !run.is_empty() {
                        self.scan(run, q, r2, &mut visit);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::Rng;
    use crate::spatial::distance2;

    /// The brute-force answer: indices (into `grid.items()`) within `r` of `q`, sorted.
    fn brute(grid: &HashGrid<[f32; 3]>, q: [f32; 3], r: f32) -> Vec<u32> {
        let mut v: Vec<u32> = grid
            .items()
            .iter()
            .enumerate()
            .filter(|(_, p)| r >= 0.0 && distance2(q, **p) <= r * r)
            .map(|(i, _)| i as u32)
            .collect();
        v.sort_unstable();
        v
    }

    fn query(grid: &HashGrid<[f32; 3]>, q: [f32; 3], r: f32) -> Vec<u32> {
        let mut v = Vec::new();
        grid.within(q, r, |n: Neighbor| {
            assert!((n.dist2 - distance2(q, grid.items()[n.index as usize])).abs() == 0.0);
            v.push(n.index);
        });
        let n = v.len();
        v.sort_unstable();
        v.dedup();
        assert_eq!(v.len(), n, "an item was visited twice");
        v
    }

    fn check(points: Vec<[f32; 3]>, cell: f32, queries: &[([f32; 3], f32)]) {
        let grid = HashGrid::build(points, cell).expect("valid grid");
        for &(q, r) in queries {
            assert_eq!(query(&grid, q, r), brute(&grid, q, r), "q {q:?} r {r}");
        }
    }

    fn random_points(n: usize, seed: u64, scale: f32) -> Vec<[f32; 3]> {
        let mut rng = Rng::new(seed, 7);
        (0..n)
            .map(|_| [0; 3].map(|_| (rng.next_f32() - 0.5) * scale))
            .collect()
    }

    #[test]
    fn random_points_match_brute_force_at_many_radii_and_cells() {
        let pts = random_points(2000, 1, 2.0);
        let mut rng = Rng::new(9, 3);
        for cell in [0.01, 0.05, 0.2, 1.0, 7.0] {
            let queries: Vec<_> = (0..200)
                .map(|_| {
                    let q = [0; 3].map(|_| (rng.next_f32() - 0.5) * 2.4);
                    (q, rng.next_f32() * 0.3)
                })
                .collect();
            check(pts.clone(), cell, &queries);
        }
    }

    #[test]
    fn degenerate_inputs_match_brute_force() {
        let mut rng = Rng::new(5, 1);
        // All points on one plane (z = 0.25 exactly, a cell boundary for cell 0.25).
        let plane: Vec<[f32; 3]> = (0..1000)
            .map(|_| [rng.next_f32(), rng.next_f32(), 0.25])
            .collect();
        let qs = [
            ([0.5, 0.5, 0.25], 0.1),
            ([0.5, 0.5, 0.3], 0.06),
            ([0.0, 0.0, 0.25], 0.0),
        ];
        check(plane.clone(), 0.25, &qs);
        check(plane, 0.013, &qs);
        // Coincident points: every query at the point finds all of them, r = 0 included.
        let same = vec![[0.3, -0.2, 1.0]; 500];
        check(
            same,
            0.1,
            &[
                ([0.3, -0.2, 1.0], 0.0),
                ([0.3, -0.2, 1.05], 0.04),
                ([0.3, -0.2, 1.05], 0.06),
            ],
        );
        // A radius larger than the scene (the scan fallback) and an infinite one.
        let pts = random_points(300, 2, 1.0);
        check(
            pts.clone(),
            0.05,
            &[
                ([0.0; 3], 100.0),
                ([5.0, 5.0, 5.0], 1e6),
                ([0.0; 3], f32::INFINITY),
            ],
        );
        // One point.
        check(
            vec![[1.0, 2.0, 3.0]],
            0.5,
            &[([1.0, 2.0, 3.4], 0.4), ([1.0, 2.0, 3.4], 0.39)],
        );
        // Far-away coordinates whose cells saturate the i32 range.
        check(
            vec![[3e38, 0.0, 0.0], [-3e38, 0.0, 0.0], [0.0, 0.0, 0.0]],
            1e-30,
            &[([3e38, 0.0, 0.0], 1.0), ([0.0; 3], 1e-31)],
        );
    }

    #[test]
    fn colliding_cells_are_not_mixed_up() {
        // Four items in four buckets: the cells a query visits collide with the items' cells,
        // and answers must still be exact (binary fractions, so the boundaries are exact too).
        let pts: Vec<[f32; 3]> = (0..4)
            .map(|i| [0.0625 + 0.25 * i as f32, 0.0625, 0.0625])
            .collect();
        let grid = HashGrid::build(pts, 0.125).expect("grid");
        assert_eq!(grid.mask, 3);
        // Items 0 and 1 lie exactly at distance 0.125 (inside: the test is ≤ r²).
        assert_eq!(query(&grid, [0.1875, 0.0625, 0.0625], 0.125).len(), 2);
        assert_eq!(
            query(&grid, [0.1875, 0.0625, 0.0625], 0.0625),
            Vec::<u32>::new()
        );
        for x in 0..40 {
            let q = [x as f32 * 0.03125, 0.0625, 0.0625];
            assert_eq!(query(&grid, q, 0.0625), brute(&grid, q, 0.0625), "{q:?}");
        }
        // Many points in few buckets relative to the cells a query spans.
        check(
            random_points(64, 3, 10.0),
            0.5,
            &[([0.0; 3], 3.0), ([1.0, 1.0, 1.0], 2.0)],
        );
    }

    #[test]
    fn bad_inputs_are_errors_and_bad_queries_find_nothing() {
        assert!(matches!(
            HashGrid::build(vec![[0.0f32; 3]], 0.0),
            Err(HashGridError::InvalidCell(_))
        ));
        assert!(matches!(
            HashGrid::build(vec![[0.0f32; 3]], f32::NAN),
            Err(HashGridError::InvalidCell(_))
        ));
        assert_eq!(
            HashGrid::build(vec![[0.0f32; 3], [f32::NAN, 0.0, 0.0]], 1.0).err(),
            Some(HashGridError::NonFinite(1))
        );
        let grid = HashGrid::build(vec![[0.0f32; 3]], 1.0).expect("grid");
        assert!(query(&grid, [f32::NAN, 0.0, 0.0], 1.0).is_empty());
        assert!(query(&grid, [0.0; 3], -1.0).is_empty());
        assert!(query(&grid, [0.0; 3], f32::NAN).is_empty());
        let empty: HashGrid<[f32; 3]> = HashGrid::build(Vec::new(), 1.0).expect("grid");
        assert!(query(&empty, [0.0; 3], 1.0).is_empty());
    }

    #[test]
    fn a_cells_items_are_visited_in_input_order_across_simd_blocks() {
        // 21 items in one cell (three eight-wide blocks, the last partial) interleaved with items
        // of a neighbouring cell: a query sees each cell's items in their input order, whatever
        // lane they fell in, and the partial block's lanes beyond the cell are not read as hits.
        let pts: Vec<[f32; 3]> = (0..42)
            .map(|i| {
                let x = if i % 2 == 0 { 0.1 } else { 1.1 };
                [x, 0.01 * (i / 2) as f32, 0.5]
            })
            .collect();
        let grid = HashGrid::build(pts.clone(), 1.0).expect("grid");
        let mut seen = Vec::new();
        grid.within([0.5, 0.1, 0.5], 0.7, |n: Neighbor| {
            seen.push(grid.items()[n.index as usize]);
        });
        let expected: Vec<[f32; 3]> = pts
            .iter()
            .step_by(2)
            .chain(pts.iter().skip(1).step_by(2))
            .copied()
            .collect();
        assert_eq!(seen, expected);
        let mut only_first = Vec::new();
        grid.within([0.1, 0.1, 0.5], 0.5, |n: Neighbor| only_first.push(n.index));
        assert_eq!(only_first.len(), 21);
    }

    #[test]
    fn in_cell_lists_exactly_the_cells_items() {
        let pts = random_points(500, 4, 1.0);
        let grid = HashGrid::build(pts, 0.1).expect("grid");
        for (i, p) in grid.items().iter().enumerate() {
            let c = grid.cell_of(*p);
            let mut found = Vec::new();
            grid.in_cell(c, |j| found.push(j));
            assert!(found.contains(&i));
            assert!(found.iter().all(|&j| grid.cell_of(grid.items()[j]) == c));
        }
    }
}

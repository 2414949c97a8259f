//! A balanced 3-d kd-tree (Bentley, "Multidimensional binary search trees used for associative
//! searching", CACM 18(9), 1975) over any item with a position, in flat arrays: the items
//! themselves, reordered into tree order, and one 12-byte stem per interior node.
//!
//! **Shape.** Every interior node splits its range of items at the median (`select_nth_unstable`
//! on the chosen axis; left half `⌊n/2⌋` items), so all leaves are at one depth `D`, the smallest
//! with `⌈n / 2^D⌉ ≤ leaf_size`, and hold between `⌊n / 2^D⌋` and `⌈n / 2^D⌉` items (a leaf
//! can be empty only when `leaf_size = 1`). Item ranges are implicit (a node's range is found by
//! halving its parent's on the way down) and stems are stored in pre-order, so a subtree's stems
//! are one contiguous run: the left child of the stem at `p` is at `p + 1`, the right at `p + h`
//! where `h = 2^(D − depth − 1)`. No pointers, no per-node allocation; the contiguous subtrees
//! also let the build run in parallel, deterministically.
//!
//! **Stems** keep two planes on their axis, the largest coordinate of the left half and the
//! smallest of the right (the median item's), as a bounding interval hierarchy does (Wächter &
//! Keller, "Instant Ray Tracing: The Bounding Interval Hierarchy", EGSR 2006). A query carries
//! its cell's box, starting from the items' tight bounds and shrunk on one axis per level, so
//! empty space between the halves is skipped, and so the box of coincident items is a point.
//!
//! **Queries** compute each child's lower bound on the squared distance (the query's per-axis
//! offsets from the child's box), visit the child with the smaller `(bound, first slot)` first
//! (the near child, on ties the left), and enter a child only when that pair can beat the
//! current limit: the k-th candidate of the bounded max-heap for k-nearest search, or the radius
//! for a fixed-radius search. Bounds are computed with the same float operations as
//! [`distance2`], so pruning is exact (never drops an item the brute-force definition would
//! keep), and because it also compares slots, `k` of a million coincident photons are found in a
//! walk down the left spine rather than a scan.
//!
//! **Ties** are broken by slot: the k nearest are the first `k` items in the order of
//! `(distance2(q, p), slot)`, where `slot` is the item's index in [`KdTree::items`]. Results are
//! therefore the same for every run, thread count and traversal order.
//!
//! **Positions must be finite**: [`KdTree::build`] rejects NaN and infinite coordinates, which
//! would make distances NaN and break both the median split and pruning.

use super::knn::{KnnHeap, Neighbor, key};

/// Anything with a position in 3-d space, in scene units.
pub trait HasPosition {
    /// The position `[x, y, z]`.
    fn position(&self) -> [f32; 3];
}

impl HasPosition for [f32; 3] {
    #[inline]
    fn position(&self) -> [f32; 3] {
        *self
    }
}

impl HasPosition for glam::Vec3 {
    #[inline]
    fn position(&self) -> [f32; 3] {
        self.to_array()
    }
}

/// Squared Euclidean distance `(qx−px)² + (qy−py)² + (qz−pz)²`, evaluated left to right in `f32`:
/// the one definition every query and its tests use.
#[inline]
#[must_use]
pub fn distance2(q: [f32; 3], p: [f32; 3]) -> f32 {
    let (dx, dy, dz) = (q[0] - p[0], q[1] - p[1], q[2] - p[2]);
    dx * dx + dy * dy + dz * dz
}

/// How a node chooses its split axis.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplitAxis {
    /// The axis along which the node's items spread widest (Jensen 2001, §6.3): one extra pass
    /// over the items per node, better-shaped cells on anisotropic sets (photons on planes).
    Widest,
    /// x, y, z, x, … by depth: no bounds pass.
    RoundRobin,
}

/// Build parameters; [`BuildOptions::default`] is what the photon map uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BuildOptions {
    /// Largest number of items in a leaf, `1 ..= 256`.
    pub leaf_size: usize,
    /// Split-axis rule.
    pub split_axis: SplitAxis,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            leaf_size: 16,
            split_axis: SplitAxis::Widest,
        }
    }
}

/// Why a tree could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum KdTreeError {
    /// An item's position has a NaN or infinite coordinate.
    #[error(
        "item {index} has position {position:?}, which is not finite; every position in a kd-tree must have finite x, y and z"
    )]
    NonFinitePosition {
        /// Index of the item in the build input.
        index: usize,
        /// Its position.
        position: [f32; 3],
    },
    /// More items than 32-bit slots can address.
    #[error("{count} items is more than a kd-tree holds (at most {max})")]
    TooManyItems {
        /// Items given.
        count: usize,
        /// The limit.
        max: usize,
    },
    /// [`KdTree::from_tree_order`] was given items that are not in tree order.
    #[error("the items are not in kd-tree order (a node's halves overlap on its split axis)")]
    NotTreeOrder,
    /// `leaf_size` is out of range.
    #[error("leaf size {0} is invalid: it must be between 1 and 256")]
    InvalidLeafSize(usize),
}

/// An interior node: the two planes on its axis (0 = x, 1 = y, 2 = z). Items of the left half
/// have `p[axis] ≤ left_max`, items of the right half `p[axis] ≥ right_min`, and
/// `left_max ≤ right_min` (the right half starts at the median).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Stem {
    left_max: f32,
    right_min: f32,
    axis: u32,
}

/// A cell's box `[min, max]`: every item of the subtree lies in it.
type Cell = [[f32; 3]; 2];

/// Item count above which a subtree's two halves are built on separate rayon tasks.
const PARALLEL_MIN: usize = 1 << 15;

/// The largest tree: slots are `u32` and `u32::MAX` is reserved by the search's key order.
const MAX_ITEMS: usize = u32::MAX as usize;

/// A static, balanced 3-d kd-tree over `T`; see the module documentation for its layout.
/// Memory: `size_of::<T>()` per item plus 12 bytes per stem (fewer than `2n / leaf_size` stems).
#[derive(Debug, Clone)]
pub struct KdTree<T> {
    items: Vec<T>,
    stems: Vec<Stem>,
    /// `h` of the root: half the number of leaves, 0 when the root is a leaf.
    root_half: usize,
    /// Tight bounds of all positions (`min`, `max`); meaningless when empty.
    bounds: [[f32; 3]; 2],
}

impl<T> Default for KdTree<T> {
    fn default() -> Self {
        Self {
            items: Vec::new(),
            stems: Vec::new(),
            root_half: 0,
            bounds: [[0.0; 3]; 2],
        }
    }
}

impl<T: HasPosition + Send> KdTree<T> {
    /// Builds a tree with [`BuildOptions::default`]. Takes ownership of `items` and reorders them.
    ///
    /// # Errors
    /// [`KdTreeError::NonFinitePosition`] for a NaN or infinite coordinate (naming the first such
    /// item), [`KdTreeError::TooManyItems`] past `u32::MAX − 1` items.
    pub fn build(items: Vec<T>) -> Result<Self, KdTreeError> {
        Self::build_with(items, BuildOptions::default())
    }

    /// Builds a tree with the given options. Parallel (rayon) for large inputs; the result is the
    /// same for any number of threads.
    ///
    /// # Errors
    /// As [`KdTree::build`], plus [`KdTreeError::InvalidLeafSize`].
    pub fn build_with(mut items: Vec<T>, options: BuildOptions) -> Result<Self, KdTreeError> {
        let (bounds, mut stems, root_half) = layout(&items, options)?;
        build_node(&mut items, &mut stems, root_half, 0, options.split_axis);
        Ok(Self {
            items,
            stems,
            root_half,
            bounds,
        })
    }
}

impl<T: HasPosition + Sync> KdTree<T> {
    /// Rebuilds a tree from items already in tree order (the [`KdTree::items`] of a tree built
    /// with the same `options`, e.g. read back from a photon-map cache) without moving them:
    /// each node's axis and planes are recomputed from its range, so the result equals the
    /// original tree, stems and slots alike. Cheaper than [`KdTree::build`] (no selection).
    ///
    /// # Errors
    /// As [`KdTree::build_with`], plus [`KdTreeError::NotTreeOrder`] when some node's left half
    /// reaches past its right half on the node's axis (the items are not in tree order).
    pub fn from_tree_order(items: Vec<T>, options: BuildOptions) -> Result<Self, KdTreeError> {
        let (bounds, mut stems, root_half) = layout(&items, options)?;
        if !restore_node(&items, &mut stems, root_half, 0, options.split_axis) {
            return Err(KdTreeError::NotTreeOrder);
        }
        Ok(Self {
            items,
            stems,
            root_half,
            bounds,
        })
    }
}

/// [`build_node`] without the selection: recomputes the stems of a range already split at its
/// medians. False when a node's halves overlap on its axis.
fn restore_node<T: HasPosition + Sync>(
    items: &[T],
    stems: &mut [Stem],
    half: usize,
    depth: usize,
    rule: SplitAxis,
) -> bool {
    if half == 0 {
        return true;
    }
    let axis = match rule {
        SplitAxis::RoundRobin => depth % 3,
        SplitAxis::Widest => widest_axis(items),
    };
    let (left, right) = items.split_at(items.len() / 2);
    let coord = |i: &T| i.position()[axis];
    let left_max = left.iter().map(coord).fold(f32::NEG_INFINITY, f32::max);
    let right_min = right.iter().map(coord).fold(f32::INFINITY, f32::min);
    // `build_node`'s `right_min` is the median's coordinate: the smallest of the right half.
    if left_max > right_min {
        return false;
    }
    stems[0] = Stem {
        left_max,
        right_min,
        axis: axis as u32,
    };
    let (left_stems, right_stems) = stems[1..].split_at_mut(half - 1);
    let child = half / 2;
    if items.len() >= PARALLEL_MIN {
        let (l, r) = rayon::join(
            || restore_node(left, left_stems, child, depth + 1, rule),
            || restore_node(right, right_stems, child, depth + 1, rule),
        );
        l && r
    } else {
        restore_node(left, left_stems, child, depth + 1, rule)
            && restore_node(right, right_stems, child, depth + 1, rule)
    }
}

/// Splits `items` at its median and recurses; `stems` is this subtree's pre-order run.
fn build_node<T: HasPosition + Send>(
    items: &mut [T],
    stems: &mut [Stem],
    half: usize,
    depth: usize,
    rule: SplitAxis,
) {
    if half == 0 {
        return;
    }
    let axis = match rule {
        SplitAxis::RoundRobin => depth % 3,
        SplitAxis::Widest => widest_axis(items),
    };
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| {
        a.position()[axis].total_cmp(&b.position()[axis])
    });
    let (left, right) = items.split_at_mut(mid);
    stems[0] = Stem {
        left_max: left
            .iter()
            .map(|i| i.position()[axis])
            .fold(f32::NEG_INFINITY, f32::max),
        // The right half is never empty (n ≥ 1 at every stem), but an empty half costs nothing:
        // its plane at ±∞ puts its cell out of every search's reach.
        right_min: right.first().map_or(f32::INFINITY, |i| i.position()[axis]),
        axis: axis as u32,
    };
    let (left_stems, right_stems) = stems[1..].split_at_mut(half - 1);
    let child = half / 2;
    if left.len() + right.len() >= PARALLEL_MIN {
        rayon::join(
            || build_node(left, left_stems, child, depth + 1, rule),
            || build_node(right, right_stems, child, depth + 1, rule),
        );
    } else {
        build_node(left, left_stems, child, depth + 1, rule);
        build_node(right, right_stems, child, depth + 1, rule);
    }
}

/// The axis of largest extent of the items' positions (lowest axis on ties).
fn widest_axis<T: HasPosition>(items: &[T]) -> usize {
    let mut lo = [f32::INFINITY; 3];
    let mut hi = [f32::NEG_INFINITY; 3];
    for item in items {
        let p = item.position();
        for a in 0..3 {
            lo[a] = lo[a].min(p[a]);
            hi[a] = hi[a].max(p[a]);
        }
    }
    let ext = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    if ext[0] >= ext[1] && ext[0] >= ext[2] {
        0
    } else if ext[1] >= ext[2] {
        1
    } else {
        2
    }
}

/// A cell's box and the query's per-axis offsets from it (0 on axes where the query is inside).
#[derive(Debug, Clone, Copy)]
struct Region {
    cell: Cell,
    off: [f32; 3],
}

/// Distance from `q` to the interval `[lo, hi]` (0 inside). For any `p` in the interval,
/// `|q − p| ≥` this in floating point too (rounding is monotone).
#[inline]
fn axis_offset(q: f32, lo: f32, hi: f32) -> f32 {
    (lo - q).max(q - hi).max(0.0)
}

impl Region {
    fn new(q: [f32; 3], cell: Cell) -> Self {
        Self {
            cell,
            off: [0, 1, 2].map(|a| axis_offset(q[a], cell[0][a], cell[1][a])),
        }
    }

    /// Lower bound on the squared distance from the query to any point of the cell: the offsets
    /// combined with the same operations, in the same order, as [`distance2`], so the bound
    /// never exceeds an item's distance.
    #[inline]
    fn bound2(&self) -> f32 {
        let [x, y, z] = self.off;
        x * x + y * y + z * z
    }

    /// The regions of a stem's two children: the cell cut at each half's plane, and the offset
    /// on the stem's axis recomputed (the other two are the parent's).
    #[inline]
    fn children(&self, q: [f32; 3], stem: Stem) -> (Self, Self) {
        let a = stem.axis as usize;
        let (mut left, mut right) = (*self, *self);
        left.cell[1][a] = stem.left_max;
        left.off[a] = axis_offset(q[a], self.cell[0][a], stem.left_max);
        right.cell[0][a] = stem.right_min;
        right.off[a] = axis_offset(q[a], stem.right_min, self.cell[1][a]);
        (left, right)
    }
}

/// `max_dist2` as a search limit: NaN and negative give `None` (nothing can be found); −0 is +0.
#[inline]
fn radius_limit(max_dist2: f32) -> Option<f32> {
    (max_dist2 >= 0.0).then_some(max_dist2 + 0.0)
}

impl<T: HasPosition> KdTree<T> {
    /// The items in tree order; search results index this slice.
    #[must_use]
    pub fn items(&self) -> &[T] {
        &self.items
    }

    /// Gives back the items (in tree order).
    #[must_use]
    pub fn into_items(self) -> Vec<T> {
        self.items
    }

    /// Number of items.
    #[must_use]
    pub fn len(&self) -> usize {
        self.items.len()
    }

    /// True when the tree holds no items.
    #[must_use]
    pub fn is_empty(&self) -> bool {
        self.items.is_empty()
    }

    /// Tight bounds `[min, max]` of all positions, or `None` when empty.
    #[must_use]
    pub fn bounds(&self) -> Option<[[f32; 3]; 2]> {
        (!self.is_empty()).then_some(self.bounds)
    }

    /// Bytes of heap memory the tree holds (items and stems).
    #[must_use]
    pub fn memory_bytes(&self) -> usize {
        self.items.capacity() * std::mem::size_of::<T>()
            + self.stems.capacity() * std::mem::size_of::<Stem>()
    }

    /// Depth of the leaves (0 when the root is a leaf).
    #[must_use]
    pub fn depth(&self) -> u32 {
        (self.root_half * 2).trailing_zeros()
    }

    /// The root's cell (the items' bounds), or `None` when `q` is not finite or the tree is empty.
    #[inline]
    fn root_cell(&self, q: [f32; 3]) -> Option<Cell> {
        (!self.items.is_empty() && q.iter().all(|c| c.is_finite())).then_some(self.bounds)
    }

    /// Finds the `heap.k()` items nearest to `q` with `distance2 ≤ max_dist2` (pass
    /// `f32::INFINITY` for no limit), into `heap` (cleared first; results unordered until
    /// [`KnnHeap::sort`]). Returns how many were found: fewer than `k` when the tree is smaller
    /// or the radius cut the search short. Ties go to the lower slot (module docs). A
    /// non-finite `q`, a negative or NaN `max_dist2`, `k = 0` or an empty tree find nothing.
    pub fn nearest(&self, q: [f32; 3], max_dist2: f32, heap: &mut KnnHeap) -> usize {
        heap.clear();
        let (Some(cell), Some(r2)) = (self.root_cell(q), radius_limit(max_dist2)) else {
            return 0;
        };
        let region = Region::new(q, cell);
        if heap.k() == 0 || region.bound2() > r2 {
            return 0;
        }
        let search = Knn {
            tree: self,
            q,
            // Accept iff key < open: distance² ≤ r2 at any slot (slots are below u32::MAX).
            open: key(r2, u32::MAX),
        };
        search.node(0, self.root_half, 0, self.items.len(), &region, heap);
        heap.len()
    }

    /// Calls `visit` for every item with `distance2(q, p) ≤ max_dist2`, in traversal order (the
    /// same order every run). A non-finite `q` or a negative or NaN `max_dist2` visits nothing.
    pub fn within(&self, q: [f32; 3], max_dist2: f32, mut visit: impl FnMut(Neighbor)) {
        let (Some(cell), Some(r2)) = (self.root_cell(q), radius_limit(max_dist2)) else {
            return;
        };
        let region = Region::new(q, cell);
        if region.bound2() <= r2 {
            let search = Within { tree: self, q, r2 };
            search.node(0, self.root_half, 0, self.items.len(), &region, &mut visit);
        }
    }

    /// [`KdTree::within`] into `out` (cleared first), for callers that reuse one buffer.
    pub fn within_into(&self, q: [f32; 3], max_dist2: f32, out: &mut Vec<Neighbor>) {
        out.clear();
        self.within(q, max_dist2, |n| out.push(n));
    }
}

/// One k-nearest query.
struct Knn<'a, T> {
    tree: &'a KdTree<T>,
    q: [f32; 3],
    open: u64,
}

impl<T: HasPosition> Knn<'_, T> {
    fn node(
        &self,
        p: usize,
        half: usize,
        lo: usize,
        hi: usize,
        region: &Region,
        heap: &mut KnnHeap,
    ) {
        let tree = self.tree;
        if half == 0 {
            let mut limit = heap.limit(self.open);
            for (i, item) in tree.items[lo..hi].iter().enumerate() {
                let k = key(distance2(self.q, item.position()), (lo + i) as u32);
                if k < limit {
                    heap.push(k);
                    limit = heap.limit(self.open);
                }
            }
            return;
        }
        let (lr, rr) = region.children(self.q, tree.stems[p]);
        let mid = lo + (hi - lo) / 2;
        let (left, right, child) = (p + 1, p + half, half / 2);
        // Every item of a child has key ≥ (its bound, its first slot); nearer child first.
        let lk = key(lr.bound2(), lo as u32);
        let rk = key(rr.bound2(), mid as u32);
        if lk <= rk {
            if lk < heap.limit(self.open) {
                self.node(left, child, lo, mid, &lr, heap);
            }
            if rk < heap.limit(self.open) {
                self.node(right, child, mid, hi, &rr, heap);
            }
        } else {
            if rk < heap.limit(self.open) {
                self.node(right, child, mid, hi, &rr, heap);
            }
            if lk < heap.limit(self.open) {
                self.node(left, child, lo, mid, &lr, heap);
            }
        }
    }
}

/// One fixed-radius query.
struct Within<'a, T> {
    tree: &'a KdTree<T>,
    q: [f32; 3],
    r2: f32,
}

impl<T: HasPosition> Within<'_, T> {
    fn node<F: FnMut(Neighbor)>(
        &self,
        p: usize,
        half: usize,
        lo: usize,
        hi: usize,
        region: &Region,
        visit: &mut F,
    ) {
        let tree = self.tree;
        if half == 0 {
            for (i, item) in tree.items[lo..hi].iter().enumerate() {
                let dist2 = distance2(self.q, item.position());
                if dist2 <= self.r2 {
                    visit(Neighbor {
                        index: (lo + i) as u32,
                        dist2,
                    });
                }
            }
            return;
        }
        let (lr, rr) = region.children(self.q, tree.stems[p]);
        let mid = lo + (hi - lo) / 2;
        if lr.bound2() <= self.r2 {
            self.node(p + 1, half / 2, lo, mid, &lr, visit);
        }
        if rr.bound2() <= self.r2 {
            self.node(p + half, half / 2, mid, hi, &rr, visit);
        }
    }
}

/// What [`KdTree::build_with`] and [`KdTree::from_tree_order`] share: the options and items
/// checked (leaf size, count, finite positions), the items' bounds, and the stems of a tree with
/// a power-of-two number of leaves of at most `leaf_size` items (unset), with the root's half.
#[allow(clippy::type_complexity)]
fn layout<T: HasPosition>(
    items: &[T],
    options: BuildOptions,
) -> Result<([[f32; 3]; 2], Vec<Stem>, usize), KdTreeError> {
    if !(1..=256).contains(&options.leaf_size) {
        return Err(KdTreeError::InvalidLeafSize(options.leaf_size));
    }
    if items.len() >= MAX_ITEMS {
        return Err(KdTreeError::TooManyItems {
            count: items.len(),
            max: MAX_ITEMS - 1,
        });
    }
    let mut bounds = [[f32::INFINITY; 3], [f32::NEG_INFINITY; 3]];
    for (index, item) in items.iter().enumerate() {
        let p = item.position();
        if !p.iter().all(|c| c.is_finite()) {
            return Err(KdTreeError::NonFinitePosition { index, position: p });
        }
        for a in 0..3 {
            bounds[0][a] = bounds[0][a].min(p[a]);
            bounds[1][a] = bounds[1][a].max(p[a]);
        }
    }
    let mut leaves = 1usize;
    while items.len().div_ceil(leaves) > options.leaf_size {
        leaves *= 2;
    }
    let stems = vec![
        Stem {
            left_max: 0.0,
            right_min: 0.0,
            axis: 0
        };
        leaves - 1
    ];
    Ok((bounds, stems, leaves / 2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shape_is_balanced_with_leaves_at_one_depth() {
        for n in [0usize, 1, 7, 8, 9, 16, 17, 100, 1000] {
            let pts: Vec<[f32; 3]> = (0..n).map(|i| [i as f32, 0.0, 0.0]).collect();
            let t = KdTree::build(pts).unwrap();
            let leaves = 1usize << t.depth();
            assert!(n.div_ceil(leaves) <= 16, "n {n}");
            assert!(
                leaves == 1 || n.div_ceil(leaves / 2) > 16,
                "n {n}: too deep"
            );
            assert_eq!(t.stems.len(), leaves - 1);
        }
    }

    #[test]
    fn split_invariant_holds_in_every_node() {
        // Walk the implicit layout and check every item against every ancestor's plane.
        let mut pts = Vec::new();
        let mut s = 1u32;
        for _ in 0..5000 {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let c = (s >> 8) as f32 / (1 << 24) as f32;
            pts.push([c, (c * 7.0).fract(), ((c * 13.0).fract() * 4.0).round()]);
        }
        for rule in [SplitAxis::Widest, SplitAxis::RoundRobin] {
            let t = KdTree::build_with(
                pts.clone(),
                BuildOptions {
                    leaf_size: 4,
                    split_axis: rule,
                },
            )
            .unwrap();
            fn check(t: &KdTree<[f32; 3]>, p: usize, half: usize, lo: usize, hi: usize) {
                if half == 0 {
                    return;
                }
                let st = t.stems[p];
                let mid = lo + (hi - lo) / 2;
                let a = st.axis as usize;
                assert!(st.left_max <= st.right_min);
                assert!(t.items[lo..mid].iter().all(|x| x[a] <= st.left_max));
                assert!(t.items[lo..mid].iter().any(|x| x[a] == st.left_max));
                assert!(t.items[mid..hi].iter().all(|x| x[a] >= st.right_min));
                assert!(t.items[mid..hi].iter().any(|x| x[a] == st.right_min));
                check(t, p + 1, half / 2, lo, mid);
                check(t, p + half, half / 2, mid, hi);
            }
            check(&t, 0, t.root_half, 0, t.len());
        }
    }

    #[test]
    fn from_tree_order_restores_the_built_tree_and_refuses_other_orders() {
        let mut pts = Vec::new();
        let mut s = 7u32;
        for i in 0..3000 {
            s = s.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
            let c = (s >> 8) as f32 / (1 << 24) as f32;
            // Some coincident points, so ties at the medians are exercised.
            let x = if i % 5 == 0 { 0.5 } else { c };
            pts.push([x, (c * 7.0).fract(), ((c * 13.0).fract() * 4.0).round()]);
        }
        for (leaf_size, split_axis) in [(16, SplitAxis::Widest), (1, SplitAxis::RoundRobin)] {
            let o = BuildOptions {
                leaf_size,
                split_axis,
            };
            let t = KdTree::build_with(pts.clone(), o).unwrap();
            let r = KdTree::from_tree_order(t.items().to_vec(), o).unwrap();
            assert_eq!(r.items, t.items);
            assert_eq!(r.stems, t.stems);
            assert_eq!((r.root_half, r.bounds), (t.root_half, t.bounds));
        }
        // The build input's own order is (almost surely) not a tree order.
        assert_eq!(
            KdTree::from_tree_order(pts, BuildOptions::default()).unwrap_err(),
            KdTreeError::NotTreeOrder
        );
    }

    #[test]
    fn rejects_non_finite_positions_and_bad_leaf_sizes() {
        let e = KdTree::build(vec![[0.0, 0.0, 0.0], [1.0, f32::NAN, 0.0]]).unwrap_err();
        assert!(matches!(e, KdTreeError::NonFinitePosition { index: 1, .. }));
        assert!(e.to_string().contains("item 1"), "{e}");
        let e = KdTree::build(vec![[f32::INFINITY, 0.0, 0.0]]).unwrap_err();
        assert!(matches!(e, KdTreeError::NonFinitePosition { index: 0, .. }));
        for leaf_size in [0, 257] {
            let o = BuildOptions {
                leaf_size,
                ..BuildOptions::default()
            };
            assert_eq!(
                KdTree::<[f32; 3]>::build_with(Vec::new(), o).unwrap_err(),
                KdTreeError::InvalidLeafSize(leaf_size)
            );
        }
    }
}

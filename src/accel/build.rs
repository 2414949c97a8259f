//! Binned SAH construction of the flat BVH.

use glam::Vec3;

use crate::geometry::Aabb;
use crate::geometry::float::{next_down, next_up};

/// Build-time binary node. A leaf (`count > 0`) covers primitive slots `index .. index + count`;
/// an interior node (`count == 0`) has its children at nodes `index` and `index + 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BvhNode {
    /// Lower corner of the node's bounds (padded outward by one ulp).
    pub min: [f32; 3],
    /// First child node or first primitive slot.
    pub index: u32,
    /// Upper corner of the node's bounds (padded outward by one ulp).
    pub max: [f32; 3],
    /// Number of primitives in a leaf, 0 for an interior node.
    pub count: u32,
}

/// Leaves start at a multiple of this many slots, so a leaf's primitives fill whole SIMD packs
/// (slot `s` is lane `s % LEAF_BLOCK` of pack `s / LEAF_BLOCK`).
pub const LEAF_BLOCK: usize = 4;

impl BvhNode {
    /// The node's bounds as an [`Aabb`].
    #[inline]
    #[must_use]
    pub fn bounds(&self) -> Aabb {
        Aabb {
            min: self.min.into(),
            max: self.max.into(),
        }
    }

    /// True for leaves.
    #[inline]
    #[must_use]
    pub fn is_leaf(&self) -> bool {
        self.count > 0
    }
}

const BINS: usize = 16;
/// Leaves never hold more primitives than this unless they are all coincident-and-unsplittable.
const MAX_LEAF: usize = 8;
/// Below this depth the SAH chooses splits; deeper nodes split at the median, which bounds the
/// tree depth by `SAH_DEPTH + log2(n)` and so keeps it within the traversal stack.
const SAH_DEPTH: usize = 32;
/// Cost of visiting a node relative to intersecting one block of primitives.
const TRAVERSAL_COST: f32 = 2.0;

/// Cost of testing one primitive on its own (a sphere or an ellipsoid, in f64), relative to one
/// block of [`LEAF_BLOCK`] packed triangles. At 2, a sphere inside a room of large triangles gets
/// a leaf of its own, which on `benches/scenes/cbox_caustic.ron` takes the path tracer from 5.1 s
/// to 4.5 s (1 thread, 32 spp; at 1, each ball shares a room-sized leaf and every ray tests it).
const SOLO_COST: f32 = 2.0;

/// SAH cost of intersecting `n` primitives tested [`LEAF_BLOCK`] at a time (triangles, in SIMD
/// packs) and `solo` primitives tested one by one (spheres, ellipsoids), priced at [`SOLO_COST`].
#[inline]
fn blocks(n: u32, solo: u32) -> f32 {
    n.div_ceil(LEAF_BLOCK as u32) as f32 + solo as f32 * SOLO_COST
}

struct Task {
    node: usize,
    start: usize,
    end: usize,
    depth: usize,
}

/// Builds the binary tree over `bounds`; `solo[i]` marks primitive `i` as tested on its own
/// rather than in a SIMD pack (an empty `solo` marks none). Returns the nodes and the primitive
/// order of the leaves.
pub(super) fn build(bounds: &[Aabb], solo: &[bool]) -> (Vec<BvhNode>, Vec<u32>) {
    let n = bounds.len();
    let is_solo = |i: u32| solo.get(i as usize).copied().unwrap_or(false);
    if n == 0 {
        return (Vec::new(), Vec::new());
    }
    let centroids: Vec<Vec3> = bounds.iter().map(Aabb::center).collect();
    let mut order: Vec<u32> = (0..n as u32).collect();
    let mut nodes = Vec::with_capacity(2 * n.div_ceil(2).max(1));
    nodes.push(leaf(Aabb::EMPTY, 0, 0));
    let mut tasks = vec![Task {
        node: 0,
        start: 0,
        end: n,
        depth: 0,
    }];
    while let Some(Task {
        node,
        start,
        end,
        depth,
    }) = tasks.pop()
    {
        let slice = &mut order[start..end];
        let mut node_bounds = Aabb::EMPTY;
        let mut centroid_bounds = Aabb::EMPTY;
        for &i in slice.iter() {
            node_bounds = node_bounds.union(bounds[i as usize]);
            centroid_bounds = centroid_bounds.grow(centroids[i as usize]);
        }
        let count = end - start;
        let split = if count <= 1 {
            None
        } else if depth < SAH_DEPTH {
            sah_split(
                slice,
                bounds,
                &is_solo,
                &centroids,
                node_bounds,
                centroid_bounds,
            )
        } else {
            Some(median_split(slice, &centroids, centroid_bounds))
        };
        let split = match split {
            Some(mid) => Some(mid),
            None if count > MAX_LEAF => Some(median_split(slice, &centroids, centroid_bounds)),
            None => None,
        };
        match split {
            Some(mid) => {
                let left = nodes.len();
                nodes.push(leaf(Aabb::EMPTY, 0, 0));
                nodes.push(leaf(Aabb::EMPTY, 0, 0));
                nodes[node] = interior(node_bounds, left);
                tasks.push(Task {
                    node: left + 1,
                    start: start + mid,
                    end,
                    depth: depth + 1,
                });
                tasks.push(Task {
                    node: left,
                    start,
                    end: start + mid,
                    depth: depth + 1,
                });
            }
            None => nodes[node] = leaf(node_bounds, start, count),
        }
    }
    (nodes, order)
}

fn leaf(b: Aabb, first: usize, count: usize) -> BvhNode {
    let (min, max) = padded(b);
    BvhNode {
        min,
        index: first as u32,
        max,
        count: count as u32,
    }
}

fn interior(b: Aabb, first_child: usize) -> BvhNode {
    let (min, max) = padded(b);
    BvhNode {
        min,
        index: first_child as u32,
        max,
        count: 0,
    }
}

/// Node bounds grown by one ulp on every side, so every primitive point lies strictly inside its
/// node's slabs: an axis-parallel ray sliding exactly along a primitive's bounding plane is then
/// inside the slab instead of on its boundary, where `0·(1/d)` would be ambiguous.
///
/// A plane that would be subnormal (one ulp beyond a bound of exactly 0, e.g. a mesh vertex on a
/// coordinate plane) is moved further out to `∓f32::MIN_POSITIVE`, the smallest normal value.
/// Otherwise a ray whose origin lies on that coordinate plane (a camera at `x = 0`) computes
/// `(plane − 0) · (1/d)` from a subnormal operand into a subnormal result for every such node it
/// visits, and x86 CPUs take a microcode assist (on the order of a hundred cycles) for each
/// multiplication with subnormal inputs or outputs: on the blob workload (camera at the origin of
/// x and y, vertices on the x = 0 and y = 0 great circles) this made primary rays 1.4× slower.
pub(super) fn padded(b: Aabb) -> ([f32; 3], [f32; 3]) {
    if b.is_empty() {
        return (b.min.to_array(), b.max.to_array());
    }
    (
        b.min
            .to_array()
            .map(|v| normal_or(next_down(v), -f32::MIN_POSITIVE)),
        b.max
            .to_array()
            .map(|v| normal_or(next_up(v), f32::MIN_POSITIVE)),
    )
}

/// `v`, or `outward` if `v` is subnormal (`outward` must lie beyond `v`: it replaces a lower plane
/// with a lower one, an upper with a higher one).
#[inline]
fn normal_or(v: f32, outward: f32) -> f32 {
    if v.is_subnormal() { outward } else { v }
}

/// Best SAH split of `slice` over all three axes; returns the size of the left part, or `None`
/// when a leaf is cheaper (and allowed) or the centroids cannot be separated.
fn sah_split(
    slice: &mut [u32],
    bounds: &[Aabb],
    is_solo: &impl Fn(u32) -> bool,
    centroids: &[Vec3],
    node_bounds: Aabb,
    centroid_bounds: Aabb,
) -> Option<usize> {
    let extent = centroid_bounds.extent();
    let mut best: Option<(f32, usize, usize)> = None; // (cost, axis, bin boundary)
    for axis in 0..3 {
        // Also skips a NaN extent.
        if extent[axis].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
            continue;
        }
        let scale = BINS as f32 / extent[axis];
        let lo = centroid_bounds.min[axis];
        let mut bin_bounds = [Aabb::EMPTY; BINS];
        // Per bin: primitives tested in packs, and those tested alone.
        let mut bin_count = [(0u32, 0u32); BINS];
        for &i in slice.iter() {
            let b = bin_index(centroids[i as usize][axis], lo, scale);
            bin_bounds[b] = bin_bounds[b].union(bounds[i as usize]);
            if is_solo(i) {
                bin_count[b].1 += 1;
            } else {
                bin_count[b].0 += 1;
            }
        }
        // Sweep from the right to get suffix areas and counts.
        let mut right_area = [0.0f32; BINS];
        let mut right_count = [(0u32, 0u32); BINS];
        let (mut acc, mut cnt) = (Aabb::EMPTY, (0u32, 0u32));
        for b in (1..BINS).rev() {
            acc = acc.union(bin_bounds[b]);
            cnt = (cnt.0 + bin_count[b].0, cnt.1 + bin_count[b].1);
            right_area[b] = acc.half_area();
            right_count[b] = cnt;
        }
        let (mut acc, mut cnt) = (Aabb::EMPTY, (0u32, 0u32));
        for b in 1..BINS {
            acc = acc.union(bin_bounds[b - 1]);
            cnt = (cnt.0 + bin_count[b - 1].0, cnt.1 + bin_count[b - 1].1);
            let right = right_count[b];
            if cnt.0 + cnt.1 == 0 || right.0 + right.1 == 0 {
                continue;
            }
            let cost =
                acc.half_area() * blocks(cnt.0, cnt.1) + right_area[b] * blocks(right.0, right.1);
            if best.is_none_or(|(c, _, _)| cost < c) {
                best = Some((cost, axis, b));
            }
        }
    }
    let (cost, axis, boundary) = best?;
    let node_area = node_bounds.half_area();
    let split_cost = TRAVERSAL_COST
        + if node_area > 0.0 {
            cost / node_area
        } else {
            0.0
        };
    let solo = slice.iter().filter(|&&i| is_solo(i)).count() as u32;
    let leaf_cost = blocks(slice.len() as u32 - solo, solo);
    if slice.len() <= MAX_LEAF && split_cost >= leaf_cost {
        return None;
    }
    let lo = centroid_bounds.min[axis];
    let scale = BINS as f32 / extent[axis];
    let mid = partition(slice, |i| {
        bin_index(centroids[i as usize][axis], lo, scale) < boundary
    });
    (mid > 0 && mid < slice.len()).then_some(mid)
}

#[inline]
fn bin_index(c: f32, lo: f32, scale: f32) -> usize {
    (((c - lo) * scale) as usize).min(BINS - 1)
}

/// Splits at the median along the widest centroid axis (by index when all centroids coincide).
fn median_split(slice: &mut [u32], centroids: &[Vec3], centroid_bounds: Aabb) -> usize {
    let mid = slice.len() / 2;
    let e = centroid_bounds.extent();
    let axis = if e.x >= e.y && e.x >= e.z {
        0
    } else if e.y >= e.z {
        1
    } else {
        2
    };
    if e[axis] > 0.0 {
        slice.select_nth_unstable_by(mid, |&a, &b| {
            centroids[a as usize][axis]
                .total_cmp(&centroids[b as usize][axis])
                .then(a.cmp(&b))
        });
    }
    mid
}

/// In-place partition; returns the number of elements for which `pred` holds (now at the front).
fn partition(slice: &mut [u32], pred: impl Fn(u32) -> bool) -> usize {
    let mut first = 0;
    for i in 0..slice.len() {
        if pred(slice[i]) {
            slice.swap(first, i);
            first += 1;
        }
    }
    first
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn padded_planes_enclose_strictly_and_are_never_subnormal() {
        let tiny = f32::from_bits(1); // the smallest subnormal
        let values = [
            0.0,
            -0.0,
            tiny,
            -tiny,
            f32::MIN_POSITIVE,
            -f32::MIN_POSITIVE,
            f32::MIN_POSITIVE * 0.5,
            f32::from_bits(f32::MIN_POSITIVE.to_bits() + 1),
            1.0,
            -3.5,
            1e30,
        ];
        for &v in &values {
            for &w in &values {
                let (lo, hi) = (v.min(w), v.max(w));
                let b = Aabb {
                    min: Vec3::new(lo, v, 1.0),
                    max: Vec3::new(hi, v, 2.0),
                };
                let (min, max) = padded(b);
                for axis in 0..3 {
                    assert!(min[axis] < b.min[axis], "{v} {w}: {min:?} vs {:?}", b.min);
                    assert!(max[axis] > b.max[axis], "{v} {w}: {max:?} vs {:?}", b.max);
                    assert!(!min[axis].is_subnormal() && !max[axis].is_subnormal());
                }
            }
        }
        // A bound of exactly 0 (a vertex on a coordinate plane): the smallest normal planes, so
        // that (plane − 0) · (1/d) stays normal for |d| ≤ 1.
        let b = Aabb {
            min: Vec3::ZERO,
            max: Vec3::ZERO,
        };
        let (min, max) = padded(b);
        assert_eq!(min, [-f32::MIN_POSITIVE; 3]);
        assert_eq!(max, [f32::MIN_POSITIVE; 3]);
        // Ordinary bounds keep their one-ulp padding.
        let b = Aabb {
            min: Vec3::splat(1.0),
            max: Vec3::splat(2.0),
        };
        assert_eq!(padded(b), ([next_down(1.0); 3], [next_up(2.0); 3]));
    }
}

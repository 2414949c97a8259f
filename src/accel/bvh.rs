//! A flat two-wide bounding volume hierarchy, laid out for traversal: each 64-byte node holds
//! the boxes of *both* children, so one cache line and one SIMD slab test decide both.

use glam::Vec4;

use crate::geometry::Aabb;

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

/// A traversal node: the boxes of two children in SIMD-friendly order, and what each child is.
/// `x = (a.min.x, a.max.x, b.min.x, b.max.x)`, likewise `y`, `z`. A child with `count > 0` is a
/// leaf over slots `index .. index + count`; with `count == 0` it is the pair at `index`; an
/// absent child has all bounds `+∞` (no ray enters it).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(64))]
pub struct NodePair {
    /// x slabs of both children.
    pub x: Vec4,
    /// y slabs of both children.
    pub y: Vec4,
    /// z slabs of both children.
    pub z: Vec4,
    /// Child pair index or first slot, per child.
    pub index: [u32; 2],
    /// Leaf size per child (0 = interior).
    pub count: [u32; 2],
}

/// A BVH over a set of primitives: traversal nodes plus the order in which primitives appear in leaves.
#[derive(Debug, Clone, Default)]
pub struct Bvh {
    /// Traversal nodes; pair 0 holds the root's children. Empty when there are no primitives.
    pub pairs: Vec<NodePair>,
    /// `order[slot]` is the index (in the build input) of the primitive stored at leaf slot `slot`.
    pub order: Vec<u32>,
    /// Bounds of everything.
    pub bounds: Aabb,
}

/// Shape figures of a built BVH, for `--stats` and tests.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BvhStats {
    /// Total nodes (interior + leaves).
    pub nodes: usize,
    /// Leaf nodes.
    pub leaves: usize,
    /// Deepest leaf (root = 0).
    pub max_depth: usize,
    /// Largest leaf.
    pub max_leaf_size: usize,
    /// SAH cost (traversal 1, intersection 1 per primitive) relative to the root's area.
    pub sah_cost: f64,
}

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

impl NodePair {
    /// The bounds of child `i` (0 or 1).
    #[must_use]
    pub fn child_bounds(&self, i: usize) -> Aabb {
        let (lo, hi) = (2 * i, 2 * i + 1);
        Aabb {
            min: glam::Vec3::new(self.x[lo], self.y[lo], self.z[lo]),
            max: glam::Vec3::new(self.x[hi], self.y[hi], self.z[hi]),
        }
    }

    /// True if child `i` exists.
    #[must_use]
    pub fn has_child(&self, i: usize) -> bool {
        self.x[2 * i] != f32::INFINITY
    }
}

impl Bvh {
    /// Builds a BVH with the binned surface-area heuristic over the given primitive bounds.
    #[must_use]
    pub fn build(bounds: &[Aabb]) -> Bvh {
        let (nodes, order) = super::build::build(bounds);
        let bounds = nodes.first().map_or(Aabb::EMPTY, BvhNode::bounds);
        Bvh {
            pairs: pair_up(&nodes),
            order,
            bounds,
        }
    }

    /// Shape figures of this tree.
    #[must_use]
    pub fn stats(&self) -> BvhStats {
        let mut s = BvhStats::default();
        if self.pairs.is_empty() {
            return s;
        }
        s.nodes = 1;
        let root_area = f64::from(self.bounds.half_area()).max(f64::MIN_POSITIVE);
        s.sah_cost = 1.0;
        let mut stack = vec![(0usize, 1usize)];
        while let Some((p, depth)) = stack.pop() {
            let pair = &self.pairs[p];
            for c in 0..2 {
                if !pair.has_child(c) {
                    continue;
                }
                s.nodes += 1;
                let area = f64::from(pair.child_bounds(c).half_area()) / root_area;
                if pair.count[c] > 0 {
                    s.leaves += 1;
                    s.max_depth = s.max_depth.max(depth);
                    s.max_leaf_size = s.max_leaf_size.max(pair.count[c] as usize);
                    s.sah_cost += area * f64::from(pair.count[c]);
                } else {
                    s.sah_cost += area;
                    stack.push((pair.index[c] as usize, depth + 1));
                }
            }
        }
        s
    }
}

const ABSENT: Vec4 = Vec4::splat(f32::INFINITY);

/// Converts binary nodes into child pairs, depth first.
fn pair_up(nodes: &[BvhNode]) -> Vec<NodePair> {
    let Some(root) = nodes.first() else {
        return Vec::new();
    };
    let empty = NodePair {
        x: ABSENT,
        y: ABSENT,
        z: ABSENT,
        index: [0; 2],
        count: [0; 2],
    };
    let mut pairs = Vec::with_capacity(nodes.len() / 2 + 1);
    if root.is_leaf() {
        let mut p = empty;
        set_child(&mut p, 0, root, root.index);
        p.count[0] = root.count;
        pairs.push(p);
        return pairs;
    }
    // (binary interior node, pair slot to fill)
    pairs.push(empty);
    let mut stack = vec![(0usize, 0usize)];
    while let Some((node, slot)) = stack.pop() {
        let first = nodes[node].index as usize;
        let mut pair = empty;
        for c in 0..2 {
            let child = &nodes[first + c];
            if child.is_leaf() {
                set_child(&mut pair, c, child, child.index);
                pair.count[c] = child.count;
            } else {
                let target = pairs.len();
                pairs.push(empty);
                set_child(&mut pair, c, child, target as u32);
                stack.push((first + c, target));
            }
        }
        pairs[slot] = pair;
    }
    pairs
}

fn set_child(pair: &mut NodePair, c: usize, node: &BvhNode, index: u32) {
    pair.x[2 * c] = node.min[0];
    pair.x[2 * c + 1] = node.max[0];
    pair.y[2 * c] = node.min[1];
    pair.y[2 * c + 1] = node.max[1];
    pair.z[2 * c] = node.min[2];
    pair.z[2 * c + 1] = node.max[2];
    pair.index[c] = index;
}

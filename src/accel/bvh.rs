//! A flat two-wide bounding volume hierarchy.

use crate::geometry::Aabb;

/// One 32-byte BVH node. A leaf (`count > 0`) covers primitive slots `index .. index + count`;
/// an interior node (`count == 0`) has its children at nodes `index` and `index + 1`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub struct BvhNode {
    /// Lower corner of the node's bounds.
    pub min: [f32; 3],
    /// First child node or first primitive slot.
    pub index: u32,
    /// Upper corner of the node's bounds.
    pub max: [f32; 3],
    /// Number of primitives in a leaf, 0 for an interior node.
    pub count: u32,
}

/// A BVH over a set of primitives: nodes plus the order in which primitives appear in leaves.
#[derive(Debug, Clone, Default)]
pub struct Bvh {
    /// Nodes; the root is node 0. Empty when there are no primitives.
    pub nodes: Vec<BvhNode>,
    /// `order[slot]` is the index (in the build input) of the primitive stored at leaf slot `slot`.
    pub order: Vec<u32>,
}

/// Shape figures of a built BVH, for `--stats` and tests.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct BvhStats {
    /// Total nodes.
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

impl Bvh {
    /// Builds a BVH with the binned surface-area heuristic over the given primitive bounds.
    #[must_use]
    pub fn build(bounds: &[Aabb]) -> Bvh {
        super::build::build(bounds)
    }

    /// Shape figures of this tree.
    #[must_use]
    pub fn stats(&self) -> BvhStats {
        let mut s = BvhStats {
            nodes: self.nodes.len(),
            ..Default::default()
        };
        if self.nodes.is_empty() {
            return s;
        }
        let root_area = f64::from(self.nodes[0].bounds().half_area()).max(f64::MIN_POSITIVE);
        let mut stack = vec![(0usize, 0usize)];
        while let Some((i, depth)) = stack.pop() {
            let n = &self.nodes[i];
            let area = f64::from(n.bounds().half_area()) / root_area;
            s.max_depth = s.max_depth.max(depth);
            if n.is_leaf() {
                s.leaves += 1;
                s.max_leaf_size = s.max_leaf_size.max(n.count as usize);
                s.sah_cost += area * f64::from(n.count);
            } else {
                s.sah_cost += area;
                stack.push((n.index as usize, depth + 1));
                stack.push((n.index as usize + 1, depth + 1));
            }
        }
        s
    }
}

//! A flat eight-wide bounding volume hierarchy, laid out for traversal: each 256-byte node holds
//! the boxes of up to eight children in SIMD lanes, so one set of slab operations tests them all
//! (the wide BVH of Wald, Benthin & Boulos 2008, "Getting Rid of Packets", collapsed from a binary
//! SAH tree as in Embree).

use wide::f32x8;

use super::build::BvhNode;
pub use super::build::LEAF_BLOCK;
use crate::geometry::Aabb;

/// Children per traversal node.
pub const WIDTH: usize = 8;

/// A traversal node: the boxes of up to [`WIDTH`] (8) children, one child per SIMD lane (one AVX
/// register, or two SSE halves without AVX), and what each child is. `bounds[axis][0]` holds the
/// lower slab planes of the children on `axis`, `bounds[axis][1]` the upper ones. A child with
/// `count > 0` is a leaf over slots `index .. index + count`; with `count == 0` it is the node at
/// `index`. An absent child has the empty box `[+∞, -∞]` on every axis, which the slab test
/// (near plane chosen by the direction's sign) never enters. 256 bytes, four cache lines.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(64))]
pub struct Node8 {
    /// `[axis][min/max]` slab planes, one child per lane.
    pub bounds: [[f32x8; 2]; 3],
    /// Child node index or first slot, per child.
    pub index: [u32; WIDTH],
    /// Leaf size per child (0 = interior or absent).
    pub count: [u32; WIDTH],
}

/// The `order` entry of a padding slot (after a leaf's last primitive, up to the next block).
pub const PAD: u32 = u32::MAX;

/// A BVH over a set of primitives: traversal nodes plus the order in which primitives appear in leaves.
#[derive(Debug, Clone, Default)]
pub struct Bvh {
    /// Traversal nodes; node 0 holds the root's children. Empty when there are no primitives.
    pub nodes: Vec<Node8>,
    /// `order[slot]` is the index (in the build input) of the primitive stored at leaf slot `slot`,
    /// or [`PAD`] for the padding slots that start every leaf on a multiple of [`LEAF_BLOCK`].
    /// Its length is a multiple of [`LEAF_BLOCK`].
    pub order: Vec<u32>,
    /// Bounds of everything.
    pub bounds: Aabb,
    /// Upper bound on the traversal stack entries any ray can need (from the tree's shape).
    pub(super) stack_need: usize,
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

/// Slab planes of an absent child: the empty box.
const ABSENT_MIN: f32 = f32::INFINITY;
const ABSENT_MAX: f32 = f32::NEG_INFINITY;

impl Node8 {
    /// A node without children.
    pub const EMPTY: Node8 = Node8 {
        bounds: [[f32x8::splat(ABSENT_MIN), f32x8::splat(ABSENT_MAX)]; 3],
        index: [0; WIDTH],
        count: [0; WIDTH],
    };

    /// The bounds of child `i` (0..8).
    #[must_use]
    pub fn child_bounds(&self, i: usize) -> Aabb {
        let plane = |axis: usize, side: usize| self.bounds[axis][side].as_array()[i];
        Aabb {
            min: glam::Vec3::new(plane(0, 0), plane(1, 0), plane(2, 0)),
            max: glam::Vec3::new(plane(0, 1), plane(1, 1), plane(2, 1)),
        }
    }

    /// True if child `i` exists.
    #[must_use]
    pub fn has_child(&self, i: usize) -> bool {
        self.bounds[0][0].as_array()[i] != ABSENT_MIN
    }

    /// Makes child `c` the (padded) box `[min, max]` referring to `index`/`count`.
    pub fn set_child(&mut self, c: usize, min: [f32; 3], max: [f32; 3], index: u32, count: u32) {
        for axis in 0..3 {
            self.bounds[axis][0].as_mut_array()[c] = min[axis];
            self.bounds[axis][1].as_mut_array()[c] = max[axis];
        }
        self.index[c] = index;
        self.count[c] = count;
    }
}

impl Bvh {
    /// Builds a BVH with the binned surface-area heuristic over the given primitive bounds.
    #[must_use]
    pub fn build(bounds: &[Aabb]) -> Bvh {
        Bvh::build_with_solo(bounds, &[])
    }

    /// [`Bvh::build`] for primitives of two kinds: `solo[i]` marks primitive `i` as one that
    /// leaves test on its own (a sphere), which the SAH prices like two whole blocks of
    /// [`LEAF_BLOCK`] packed triangles, so such primitives get leaves of their own unless they are
    /// large. A `solo` shorter than `bounds` marks the rest as packed.
    #[must_use]
    pub fn build_with_solo(bounds: &[Aabb], solo: &[bool]) -> Bvh {
        let (binary, order) = super::build::build(bounds, solo);
        let bounds = binary.first().map_or(Aabb::EMPTY, BvhNode::bounds);
        let (nodes, order, stack_need) = collapse(&binary, &order);
        Bvh {
            nodes,
            order,
            bounds,
            stack_need,
        }
    }

    /// Traversal stack entries the deepest path of this tree can need (what picks the
    /// traversal's fixed-size stack).
    #[must_use]
    pub fn stack_need(&self) -> usize {
        self.stack_need
    }

    /// Shape figures of this tree.
    #[must_use]
    pub fn stats(&self) -> BvhStats {
        let mut s = BvhStats::default();
        if self.nodes.is_empty() {
            return s;
        }
        s.nodes = 1;
        let root_area = f64::from(self.bounds.half_area()).max(f64::MIN_POSITIVE);
        s.sah_cost = 1.0;
        let mut stack = vec![(0usize, 1usize)];
        while let Some((n, depth)) = stack.pop() {
            let node = &self.nodes[n];
            for c in 0..WIDTH {
                if !node.has_child(c) {
                    continue;
                }
                s.nodes += 1;
                let area = f64::from(node.child_bounds(c).half_area()) / root_area;
                if node.count[c] > 0 {
                    s.leaves += 1;
                    s.max_depth = s.max_depth.max(depth);
                    s.max_leaf_size = s.max_leaf_size.max(node.count[c] as usize);
                    s.sah_cost += area * f64::from(node.count[c]);
                } else {
                    s.sah_cost += area;
                    stack.push((node.index[c] as usize, depth + 1));
                }
            }
        }
        s
    }
}

/// Collapses the binary tree into [`WIDTH`]-wide nodes: starting from a node's two children, the
/// interior child with the largest surface area is repeatedly replaced by its own two children
/// until there are [`WIDTH`] or only leaves remain. Leaves are copied out of `order` in the same
/// depth-first order, each padded to a whole [`LEAF_BLOCK`]. Returns the nodes (depth first,
/// parents before children), the padded order and a bound on the traversal stack: a node pushes
/// at most `children - 1` entries.
fn collapse(binary: &[BvhNode], order: &[u32]) -> (Vec<Node8>, Vec<u32>, usize) {
    let Some(root) = binary.first() else {
        return (Vec::new(), Vec::new(), 0);
    };
    let mut padded = Vec::with_capacity(order.len() + order.len() / 2);
    let mut place = |n: &BvhNode| -> u32 {
        let first = padded.len();
        let (a, count) = (n.index as usize, n.count as usize);
        padded.extend_from_slice(&order[a..a + count]);
        padded.resize(first + count.next_multiple_of(LEAF_BLOCK), PAD);
        first as u32
    };
    if root.is_leaf() {
        let mut n = Node8::EMPTY;
        let first = place(root);
        n.set_child(0, root.min, root.max, first, root.count);
        return (vec![n], padded, 0);
    }
    let mut nodes = Vec::with_capacity(binary.len() / 3 + 1);
    nodes.push(Node8::EMPTY);
    // (binary interior node, wide node to fill)
    let mut stack = vec![(0usize, 0usize)];
    while let Some((b, slot)) = stack.pop() {
        let first = binary[b].index as usize;
        let mut kids = [0usize; WIDTH];
        (kids[0], kids[1]) = (first, first + 1);
        let mut k = 2;
        while k < WIDTH {
            let mut best: Option<(f32, usize)> = None;
            for (i, &c) in kids[..k].iter().enumerate() {
                if !binary[c].is_leaf() {
                    let area = binary[c].bounds().half_area();
                    if best.is_none_or(|(a, _)| area > a) {
                        best = Some((area, i));
                    }
                }
            }
            let Some((_, i)) = best else { break };
            let c = binary[kids[i]].index as usize;
            kids[i] = c;
            kids[k] = c + 1;
            k += 1;
        }
        let mut node = Node8::EMPTY;
        // Children's subtrees are filled in child order (stack pushed in reverse).
        let mut pending = [(0usize, 0usize); WIDTH];
        let mut np = 0;
        for (c, &child) in kids[..k].iter().enumerate() {
            let n = &binary[child];
            if n.is_leaf() {
                let first = place(n);
                node.set_child(c, n.min, n.max, first, n.count);
            } else {
                let target = nodes.len();
                nodes.push(Node8::EMPTY);
                node.set_child(c, n.min, n.max, target as u32, 0);
                pending[np] = (child, target);
                np += 1;
            }
        }
        nodes[slot] = node;
        for &p in pending[..np].iter().rev() {
            stack.push(p);
        }
    }
    // Children always follow their parent, so one backward sweep finds every subtree's need.
    let mut need = vec![0usize; nodes.len()];
    for i in (0..nodes.len()).rev() {
        let n = &nodes[i];
        let children = (0..WIDTH).filter(|&c| n.has_child(c)).count();
        let deepest = (0..WIDTH)
            .filter(|&c| n.has_child(c) && n.count[c] == 0)
            .map(|c| need[n.index[c] as usize])
            .max()
            .unwrap_or(0);
        need[i] = children.saturating_sub(1) + deepest;
    }
    (nodes, padded, need[0])
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// Random boxes in a 100-unit cube, sizes up to 3 units.
    fn boxes(n: usize) -> Vec<Aabb> {
        let mut rng = crate::sampling::Rng::new(7, 11);
        (0..n)
            .map(|_| {
                let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 100.0;
                let e = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 3.0;
                Aabb { min: c, max: c + e }
            })
            .collect()
    }

    fn contains(outer: Aabb, inner: Aabb) -> bool {
        outer.min.cmple(inner.min).all() && outer.max.cmpge(inner.max).all()
    }

    /// Walks the subtree under child `c` of `node`, returning the primitives it reaches and
    /// checking that every box on the way encloses everything below it.
    fn check_child(bvh: &Bvh, input: &[Aabb], node: &Node8, c: usize, seen: &mut Vec<u32>) {
        let b = node.child_bounds(c);
        let (index, count) = (node.index[c] as usize, node.count[c] as usize);
        if count > 0 {
            assert_eq!(index % LEAF_BLOCK, 0, "leaf not on a pack boundary");
            for &p in &bvh.order[index..index + count] {
                assert_ne!(p, PAD, "padding inside a leaf");
                assert!(
                    contains(b, input[p as usize]),
                    "leaf box misses primitive {p}"
                );
                seen.push(p);
            }
            for &p in &bvh.order[index + count..(index + count).next_multiple_of(LEAF_BLOCK)] {
                assert_eq!(p, PAD, "padding slot holds a primitive");
            }
            return;
        }
        let inner = &bvh.nodes[index];
        for k in (0..WIDTH).filter(|&k| inner.has_child(k)) {
            assert!(
                contains(b, inner.child_bounds(k)),
                "child box escapes its parent"
            );
            check_child(bvh, input, inner, k, seen);
        }
    }

    #[test]
    fn wide_nodes_enclose_their_subtrees_and_hold_every_primitive_once() {
        let input = boxes(5000);
        let bvh = Bvh::build(&input);
        let mut seen = Vec::new();
        let root = &bvh.nodes[0];
        for c in (0..WIDTH).filter(|&c| root.has_child(c)) {
            check_child(&bvh, &input, root, c, &mut seen);
        }
        seen.sort_unstable();
        assert_eq!(seen, (0..5000).collect::<Vec<u32>>());
        // The collapse fills nodes: a node has fewer than WIDTH children only when all of them
        // are leaves (nothing was left to open), and the widths beyond four are used.
        let mut wide = 0;
        for n in &bvh.nodes {
            let kids: Vec<usize> = (0..WIDTH).filter(|&c| n.has_child(c)).collect();
            if kids.len() < WIDTH {
                assert!(kids.iter().all(|&c| n.count[c] > 0), "node not filled");
            }
            wide += usize::from(kids.len() > 4);
        }
        assert!(wide > 0);
        // Every node pushes at most (children - 1) entries per level; the bound must cover the
        // deepest chain of such pushes found by walking the tree.
        fn need(bvh: &Bvh, n: usize) -> usize {
            let node = &bvh.nodes[n];
            let kids: Vec<usize> = (0..WIDTH).filter(|&c| node.has_child(c)).collect();
            let deepest = kids
                .iter()
                .filter(|&&c| node.count[c] == 0)
                .map(|&c| need(bvh, node.index[c] as usize))
                .max()
                .unwrap_or(0);
            kids.len() - 1 + deepest
        }
        assert_eq!(bvh.stack_need(), need(&bvh, 0));
    }

    #[test]
    fn no_slab_plane_is_subnormal_when_bounds_touch_coordinate_planes() {
        // Boxes with corners exactly on x = 0, y = 0 or z = 0 (mesh vertices on a coordinate
        // plane): padding by one ulp would give planes of ±1.4e-45, and a ray from a point on
        // that plane would multiply a subnormal in every such node (see `build::padded`).
        let mut input = boxes(2000);
        for (i, b) in input.iter_mut().enumerate() {
            let axis = i % 3;
            let extent = b.max[axis] - b.min[axis];
            if i % 2 == 0 {
                (b.min[axis], b.max[axis]) = (0.0, extent);
            } else {
                (b.min[axis], b.max[axis]) = (-extent, 0.0);
            }
        }
        let bvh = Bvh::build(&input);
        let mut seen = Vec::new();
        let mut planes = 0;
        for n in &bvh.nodes {
            for c in (0..WIDTH).filter(|&c| n.has_child(c)) {
                let b = n.child_bounds(c);
                for v in b.min.to_array().into_iter().chain(b.max.to_array()) {
                    assert!(!v.is_subnormal(), "subnormal plane {v:e}");
                    planes += usize::from(v.abs() == f32::MIN_POSITIVE);
                }
            }
        }
        // The boxes on the coordinate planes did get the smallest normal planes, and the tree
        // still encloses every primitive.
        assert!(planes > 0);
        let root = &bvh.nodes[0];
        for c in (0..WIDTH).filter(|&c| root.has_child(c)) {
            check_child(&bvh, &input, root, c, &mut seen);
        }
        assert_eq!(seen.len(), input.len());
    }

    /// The leaf holding primitive `p`: its bounds and its primitives.
    fn leaf_of(bvh: &Bvh, p: u32) -> (Aabb, Vec<u32>) {
        for n in &bvh.nodes {
            for c in (0..WIDTH).filter(|&c| n.has_child(c) && n.count[c] > 0) {
                let (i, k) = (n.index[c] as usize, n.count[c] as usize);
                let prims = bvh.order[i..i + k].to_vec();
                if prims.contains(&p) {
                    return (n.child_bounds(c), prims);
                }
            }
        }
        panic!("primitive {p} in no leaf");
    }

    #[test]
    fn solo_primitives_get_their_own_leaves_in_a_room_of_walls() {
        // The caustic Cornell box (benches/scenes/cbox_caustic.ron): five 2-unit walls of two
        // triangles each (no front wall), a glass and a mirror ball and a small spherical light.
        // Packed, some ball shares a room-sized leaf that nearly every ray tests; priced as solo,
        // each ball has a leaf of its own, bounded by its own box.
        let wall = |axis: usize, side: f32| {
            let mut min = Vec3::splat(-1.0);
            let mut max = Vec3::splat(1.0);
            min[axis] = side;
            max[axis] = side;
            Aabb { min, max }
        };
        let mut input = Vec::new();
        for (axis, side) in [(0, -1.0), (0, 1.0), (1, -1.0), (1, 1.0), (2, -1.0)] {
            input.extend([wall(axis, side); 2]);
        }
        let ball = |c: Vec3, r: f32| Aabb {
            min: c - Vec3::splat(r),
            max: c + Vec3::splat(r),
        };
        input.push(ball(Vec3::new(-0.42, -0.62, -0.25), 0.38));
        input.push(ball(Vec3::new(0.45, -0.65, 0.25), 0.35));
        input.push(ball(Vec3::new(0.0, 0.75, 0.0), 0.08));
        let balls = [10u32, 11, 12];
        let packed = Bvh::build(&input);
        assert!(
            balls.iter().any(|&b| leaf_of(&packed, b).1.len() > 1),
            "packed build already isolates the balls: the test shows nothing"
        );
        let mut solo = vec![false; 10];
        solo.extend([true; 3]);
        let bvh = Bvh::build_with_solo(&input, &solo);
        for b in balls {
            let (bounds, prims) = leaf_of(&bvh, b);
            assert_eq!(prims, vec![b]);
            assert!(contains(bounds, input[b as usize]));
            assert!(bounds.half_area() < 1.01 * input[b as usize].half_area());
        }
    }
}

//! Queries over a region of space instead of a ray: the leaves whose boxes (and their
//! ancestors' boxes) a caller's test accepts, such as the boxes within a ball that rise above
//! a plane (the photon map's wall test, `integrators::photon::walls`).

use super::bvh::{Bvh, WIDTH};
use crate::geometry::Aabb;

/// Most entries the region query keeps waiting: as many as any tree this crate builds can need
/// (the ray traversal's largest stack: seven children per level, 64 levels).
const STACK_MAX: usize = (WIDTH - 1) * 64 + 1;

/// The region query's stack for ordinary trees (those whose [`Bvh::stack_need`] fits): small
/// enough that clearing it costs little next to the query.
const STACK_SMALL: usize = 64;

impl Bvh {
    /// True as soon as `leaf(first, count)` is true for a leaf over slots
    /// `first .. first + count` whose box, and every ancestor's, `meets` accepts; false when no
    /// such leaf reports. Children are visited in a fixed order, so the answer and the leaves
    /// visited depend only on the tree and the tests. No allocation.
    #[must_use]
    pub fn any_leaf_in(
        &self,
        meets: impl Fn(&Aabb) -> bool,
        leaf: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        if self.stack_need <= STACK_SMALL {
            self.any_leaf_with::<STACK_SMALL>(meets, leaf)
        } else {
            self.any_leaf_with::<STACK_MAX>(meets, leaf)
        }
    }

    /// [`Bvh::any_leaf_in`] with a stack of `N` entries (a tree needing more reports "found",
    /// the caller's safe side).
    fn any_leaf_with<const N: usize>(
        &self,
        meets: impl Fn(&Aabb) -> bool,
        mut leaf: impl FnMut(u32, u32) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        let mut stack = [(0u32, 0u32); N];
        let mut sp = 0usize;
        let (mut index, mut count) = (0u32, 0u32);
        loop {
            if count == 0 {
                let node = &self.nodes[index as usize];
                for c in 0..WIDTH {
                    if !node.has_child(c) || !meets(&node.child_bounds(c)) {
                        continue;
                    }
                    if sp == N {
                        // Deeper than the stack: say "found", the caller's safe side.
                        return true;
                    }
                    stack[sp] = (node.index[c], node.count[c]);
                    sp += 1;
                }
            } else if leaf(index, count) {
                return true;
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            (index, count) = stack[sp];
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    #[test]
    fn finds_exactly_the_leaves_a_box_test_accepts() {
        // 200 unit boxes along x; a query for the boxes meeting x ∈ [50.5, 52.5] reaches the
        // primitives 50, 51 and 52 and no other.
        let bounds: Vec<Aabb> = (0..200)
            .map(|i| Aabb {
                min: Vec3::new(i as f32, 0.0, 0.0),
                max: Vec3::new(i as f32 + 1.0, 1.0, 1.0),
            })
            .collect();
        let bvh = Bvh::build(&bounds);
        let meets = |b: &Aabb| b.max.x >= 50.5 && b.min.x <= 52.5;
        let mut seen = Vec::new();
        let found = bvh.any_leaf_in(meets, |first, count| {
            for slot in first..first + count {
                let prim = bvh.order[slot as usize];
                if prim != crate::accel::bvh::PAD && meets(&bounds[prim as usize]) {
                    seen.push(prim);
                }
            }
            false
        });
        assert!(!found);
        seen.sort_unstable();
        assert_eq!(seen, vec![50, 51, 52]);
        assert!(bvh.any_leaf_in(meets, |_, _| true));
        assert!(!bvh.any_leaf_in(|b| b.min.x > 500.0, |_, _| true));
        assert!(!Bvh::default().any_leaf_in(|_| true, |_, _| true));
    }
}

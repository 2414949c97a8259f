//! Stack-based BVH traversal without allocation: nearest child first, far child culled on pop.

use glam::{Vec3, Vec3A};

use super::bvh::{Bvh, BvhNode};
use crate::geometry::float::gamma;

/// Traversal stack depth; the builder bounds tree depth well below this.
const STACK: usize = 64;

/// Power-of-two stand-in for `1/0` so that `0·(1/d)` never becomes NaN for axis-parallel rays,
/// while keeping slab distances of origins off the slab conservative (tinybvh PR #286).
const HUGE_RECIPROCAL: f32 = 1.267_650_6e30; // 2^100

/// Per-ray constants of the slab test.
#[derive(Debug, Clone, Copy)]
pub struct RayBoxTest {
    origin: Vec3A,
    inv_dir: Vec3A,
}

impl RayBoxTest {
    /// Precomputes the reciprocal direction; zero and denormal components (either sign) map to
    /// ±2¹⁰⁰ so axis-parallel rays and origins on slab planes are handled without NaN.
    #[inline]
    #[must_use]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        let inv = |d: f32| {
            let r = 1.0 / d;
            if r.is_finite() {
                r
            } else {
                HUGE_RECIPROCAL.copysign(d)
            }
        };
        Self {
            origin: origin.into(),
            inv_dir: Vec3A::new(inv(dir.x), inv(dir.y), inv(dir.z)),
        }
    }

    /// Entry distance of the ray into `node` if it overlaps `[0, t_max]`, else +∞.
    #[inline(always)]
    #[must_use]
    pub fn entry(&self, node: &BvhNode, t_max: f32) -> f32 {
        let lo = (Vec3A::from_array(node.min) - self.origin) * self.inv_dir;
        let hi = (Vec3A::from_array(node.max) - self.origin) * self.inv_dir;
        let t_near = lo.min(hi).max_element().max(0.0);
        // Widen the far distance by the slab computation's rounding error (pbrt's 1 + 2γ₃).
        let t_far = (lo.max(hi).min_element() * (1.0 + 2.0 * gamma(3))).min(t_max);
        if t_near <= t_far {
            t_near
        } else {
            f32::INFINITY
        }
    }
}

impl Bvh {
    /// Visits every leaf slot whose node the ray may enter before `t_max`, nearest child first.
    /// `test(slot, t_max)` intersects the primitive in `slot` and returns a closer distance on a
    /// hit, which then shrinks the search. Returns the final `t_max`.
    #[inline]
    pub fn closest(
        &self,
        ray: &RayBoxTest,
        mut t_max: f32,
        mut test: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        let nodes = &self.nodes[..];
        let Some(root) = nodes.first() else {
            return t_max;
        };
        if ray.entry(root, t_max) == f32::INFINITY {
            return t_max;
        }
        let mut stack = [(0u32, 0.0f32); STACK];
        let mut sp = 0usize;
        let mut node = root;
        loop {
            if node.count > 0 {
                for slot in node.index..node.index + node.count {
                    if let Some(t) = test(slot, t_max) {
                        t_max = t;
                    }
                }
            } else {
                let (a, b) = (&nodes[node.index as usize], &nodes[node.index as usize + 1]);
                let (ta, tb) = (ray.entry(a, t_max), ray.entry(b, t_max));
                let (near, far, t_near, t_far) = if ta <= tb {
                    (a, b, ta, tb)
                } else {
                    (b, a, tb, ta)
                };
                if t_near != f32::INFINITY {
                    if t_far != f32::INFINITY {
                        let far_index = if std::ptr::eq(far, a) {
                            node.index
                        } else {
                            node.index + 1
                        };
                        stack[sp] = (far_index, t_far);
                        sp += 1;
                    }
                    node = near;
                    continue;
                }
            }
            // Pop the next node that can still hold a closer hit.
            loop {
                if sp == 0 {
                    return t_max;
                }
                sp -= 1;
                let (index, t_entry) = stack[sp];
                if t_entry <= t_max {
                    node = &nodes[index as usize];
                    break;
                }
            }
        }
    }

    /// True as soon as `test(slot, t_max)` reports any hit in a node the ray enters before `t_max`.
    #[inline]
    pub fn any(
        &self,
        ray: &RayBoxTest,
        t_max: f32,
        mut test: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        let nodes = &self.nodes[..];
        let Some(root) = nodes.first() else {
            return false;
        };
        if ray.entry(root, t_max) == f32::INFINITY {
            return false;
        }
        let mut stack = [0u32; STACK];
        let mut sp = 0usize;
        let mut node = root;
        loop {
            if node.count > 0 {
                for slot in node.index..node.index + node.count {
                    if test(slot, t_max) {
                        return true;
                    }
                }
            } else {
                let i = node.index;
                let (a, b) = (&nodes[i as usize], &nodes[i as usize + 1]);
                let (ha, hb) = (
                    ray.entry(a, t_max) != f32::INFINITY,
                    ray.entry(b, t_max) != f32::INFINITY,
                );
                match (ha, hb) {
                    (true, true) => {
                        stack[sp] = i + 1;
                        sp += 1;
                        node = a;
                        continue;
                    }
                    (true, false) => {
                        node = a;
                        continue;
                    }
                    (false, true) => {
                        node = b;
                        continue;
                    }
                    (false, false) => {}
                }
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            node = &nodes[stack[sp] as usize];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::Aabb;

    fn node_of(b: Aabb) -> BvhNode {
        let (min, max) = crate::accel::build::padded(b);
        BvhNode {
            min,
            index: 0,
            max,
            count: 1,
        }
    }

    fn unit_box() -> BvhNode {
        node_of(Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        })
    }

    fn slab(o: Vec3, d: Vec3) -> Option<(f32, f32)> {
        // Entry with t_max = ∞ and with the exit found by bisection on t_max.
        let r = RayBoxTest::new(o, d);
        let n = unit_box();
        let near = r.entry(&n, f32::INFINITY);
        (near != f32::INFINITY).then_some((near, 0.0))
    }

    #[test]
    fn axis_parallel_rays_and_origins_on_slab_planes() {
        let t = slab(Vec3::new(-5.0, 0.0, 0.0), Vec3::X).unwrap().0;
        assert!((t - 4.0).abs() <= 4.0 * f32::EPSILON, "{t}");
        assert!(slab(Vec3::new(-2.0, 0.0, 0.0), Vec3::Y).is_none());
        for d in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
            assert!(
                slab(Vec3::splat(-1.0), d).is_some(),
                "corner (-1,-1,-1) along {d:?}"
            );
            assert!(
                slab(Vec3::splat(1.0), d).is_some(),
                "corner (1,1,1) along {d:?}"
            );
        }
        // Negative zero and tiny components.
        assert!(slab(Vec3::new(0.0, 0.0, -5.0), Vec3::new(-0.0, 0.0, 1.0)).is_some());
        assert!(slab(Vec3::new(0.0, 0.0, -5.0), Vec3::new(1e-30, -1e-30, 1.0)).is_some());
        assert!(
            slab(Vec3::new(1.0, 1.0, -5.0), Vec3::new(-0.0, 0.0, 1.0)).is_some(),
            "on two slab planes"
        );
    }

    fn brute_closest(boxes: &[Aabb], o: Vec3, d: Vec3) -> Option<u32> {
        // A box's "hit" is its entry distance; ties resolved by index.
        let r = RayBoxTest::new(o, d);
        let mut best: Option<(f32, u32)> = None;
        for (i, b) in boxes.iter().enumerate() {
            let t = r.entry(&node_of(*b), f32::INFINITY);
            if t != f32::INFINITY && best.is_none_or(|(bt, bi)| (t, i as u32) < (bt, bi)) {
                best = Some((t, i as u32));
            }
        }
        best.map(|b| b.1)
    }

    #[test]
    fn traversal_matches_brute_force_on_a_staircase_with_axis_parallel_rays() {
        // 20 steps in a unit cube; rays straight down, many exactly in riser planes.
        let boxes: Vec<Aabb> = (0..20)
            .map(|s| Aabb {
                min: Vec3::new(s as f32 / 20.0, 0.0, 0.0),
                max: Vec3::new((s + 1) as f32 / 20.0, 1.0, 1.0 - s as f32 / 20.0),
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        let mut mismatches = 0;
        for i in 0..=126 {
            for j in 0..=126 {
                let o = Vec3::new(i as f32 / 126.0, j as f32 / 126.0, 2.0);
                let d = Vec3::new(0.0, -0.0, -1.0);
                let r = RayBoxTest::new(o, d);
                let mut best: Option<(f32, u32)> = None;
                bvh.closest(&r, f32::INFINITY, |slot, tmax| {
                    let b = bvh.order[slot as usize];
                    let bx = boxes[b as usize];
                    let t = r.entry(&node_of(bx), tmax);
                    if t == f32::INFINITY {
                        return None;
                    }
                    if best.is_none_or(|(bt, bi)| (t, b) < (bt, bi)) {
                        best = Some((t, b));
                    }
                    Some(t)
                });
                let brute = brute_closest(&boxes, o, d);
                let hit_dist = |k: Option<u32>| k.map(|k| 2.0 - boxes[k as usize].max.z);
                if hit_dist(best.map(|b| b.1)) != hit_dist(brute) {
                    mismatches += 1;
                }
            }
        }
        assert_eq!(mismatches, 0);
    }

    #[test]
    fn coincident_primitives_build_a_shallow_tree() {
        let boxes = vec![
            Aabb {
                min: Vec3::ZERO,
                max: Vec3::ONE
            };
            100_000
        ];
        let t0 = std::time::Instant::now();
        let bvh = Bvh::build(&boxes);
        let s = bvh.stats();
        assert!(t0.elapsed().as_secs_f32() < 1.0);
        assert!(s.max_depth <= 20, "depth {}", s.max_depth);
        assert!(s.max_leaf_size <= 8);
        let mut seen = bvh.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..100_000).collect::<Vec<u32>>());
    }

    #[test]
    fn empty_bvh_is_a_miss() {
        let bvh = Bvh::build(&[]);
        let r = RayBoxTest::new(Vec3::ZERO, Vec3::X);
        assert_eq!(bvh.closest(&r, 5.0, |_, _| Some(1.0)), 5.0);
        assert!(!bvh.any(&r, 5.0, |_, _| true));
    }
}

//! Stack-based traversal without allocation: both children's slabs tested at once with SIMD,
//! nearest child first, far children culled on pop once a closer hit is known.

use glam::{Vec3, Vec4, Vec4Swizzles};

use super::bvh::{Bvh, NodePair};
use crate::geometry::float::gamma;

/// Traversal stack depth; the builder bounds tree depth well below this.
const STACK: usize = 64;

/// Widening of the far slab distance that covers the slab computation's rounding (pbrt's 1 + 2γ₃).
const FAR_SCALE: f32 = 1.0 + 2.0 * gamma(3);

/// Per-ray constants of the slab test.
#[derive(Debug, Clone, Copy)]
pub struct RayBoxTest {
    ox: Vec4,
    oy: Vec4,
    oz: Vec4,
    ix: Vec4,
    iy: Vec4,
    iz: Vec4,
}

impl RayBoxTest {
    /// Precomputes the reciprocal direction. A zero component gives ±∞, so that axis's slab is
    /// unbounded for an origin strictly inside it and empty outside. Node bounds are padded by
    /// an ulp beyond their geometry, so the ambiguous `0·∞` (an origin exactly on a slab plane)
    /// only occurs on planes that hold no geometry, where either answer is correct. A large finite
    /// stand-in for `1/0` would instead clip tiny boxes (tinybvh PR #286).
    #[inline]
    #[must_use]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        let inv = |d: f32| Vec4::splat(1.0 / d);
        Self {
            ox: Vec4::splat(origin.x),
            oy: Vec4::splat(origin.y),
            oz: Vec4::splat(origin.z),
            ix: inv(dir.x),
            iy: inv(dir.y),
            iz: inv(dir.z),
        }
    }

    /// Entry distances of the ray into both children of `pair` (lanes 0 and 2), +∞ where the ray
    /// misses the child or enters it only after `t_max`.
    #[inline(always)]
    #[must_use]
    pub fn entries(&self, pair: &NodePair, t_max: f32) -> (f32, f32) {
        let tx = (pair.x - self.ox) * self.ix;
        let ty = (pair.y - self.oy) * self.iy;
        let tz = (pair.z - self.oz) * self.iz;
        // Lanes (lo, hi) per child after pairing each slab value with its partner.
        let (sx, sy, sz) = (tx.yxwz(), ty.yxwz(), tz.yxwz());
        let near = tx.min(sx).max(ty.min(sy)).max(tz.min(sz)).max(Vec4::ZERO);
        let far = (tx.max(sx).min(ty.max(sy)).min(tz.max(sz)) * FAR_SCALE).min(Vec4::splat(t_max));
        let hit = near.cmple(far).bitmask();
        let a = if hit & 1 != 0 { near.x } else { f32::INFINITY };
        let b = if hit & 4 != 0 { near.z } else { f32::INFINITY };
        (a, b)
    }
}

impl Bvh {
    /// Visits every leaf slot the ray may reach before `t_max`, nearest child first.
    /// `test(slot, t_max)` intersects the primitive in `slot` and returns a closer distance on a
    /// hit, which then shrinks the search. Returns the final `t_max`.
    #[inline]
    pub fn closest(
        &self,
        ray: &RayBoxTest,
        mut t_max: f32,
        mut test: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        let pairs = &self.pairs[..];
        if pairs.is_empty() {
            return t_max;
        }
        let mut stack = [(0u32, 0.0f32); STACK];
        let mut sp = 0usize;
        let mut pair = &pairs[0];
        loop {
            let (ta, tb) = ray.entries(pair, t_max);
            let (near, far, t_near, t_far) = if ta <= tb {
                (0, 1, ta, tb)
            } else {
                (1, 0, tb, ta)
            };
            let mut next = None;
            for (c, t) in [(near, t_near), (far, t_far)] {
                // A missed child has t = +∞, which must be skipped even while t_max is +∞.
                if t == f32::INFINITY || t > t_max {
                    continue;
                }
                let (index, count) = (pair.index[c], pair.count[c]);
                if count > 0 {
                    for slot in index..index + count {
                        if let Some(t) = test(slot, t_max) {
                            t_max = t;
                        }
                    }
                } else if next.is_none() {
                    next = Some(index);
                } else {
                    stack[sp] = (index, t);
                    sp += 1;
                }
            }
            if let Some(n) = next {
                pair = &pairs[n as usize];
                continue;
            }
            loop {
                if sp == 0 {
                    return t_max;
                }
                sp -= 1;
                let (index, t_entry) = stack[sp];
                if t_entry <= t_max {
                    pair = &pairs[index as usize];
                    break;
                }
            }
        }
    }

    /// True as soon as `test(slot, t_max)` reports a hit in any leaf the ray reaches before `t_max`.
    #[inline]
    pub fn any(
        &self,
        ray: &RayBoxTest,
        t_max: f32,
        mut test: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        let pairs = &self.pairs[..];
        if pairs.is_empty() {
            return false;
        }
        let mut stack = [0u32; STACK];
        let mut sp = 0usize;
        let mut pair = &pairs[0];
        loop {
            let (ta, tb) = ray.entries(pair, t_max);
            let mut next = None;
            for (c, t) in [(0, ta), (1, tb)] {
                if t == f32::INFINITY {
                    continue;
                }
                let (index, count) = (pair.index[c], pair.count[c]);
                if count > 0 {
                    for slot in index..index + count {
                        if test(slot, t_max) {
                            return true;
                        }
                    }
                } else if next.is_none() {
                    next = Some(index);
                } else {
                    stack[sp] = index;
                    sp += 1;
                }
            }
            if let Some(n) = next {
                pair = &pairs[n as usize];
                continue;
            }
            if sp == 0 {
                return false;
            }
            sp -= 1;
            pair = &pairs[stack[sp] as usize];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::bvh::BvhNode;
    use crate::geometry::Aabb;

    /// A pair whose first child is `b` (padded like the builder does) and whose second is absent.
    fn pair_of(b: Aabb) -> NodePair {
        let (min, max) = crate::accel::build::padded(b);
        let n = BvhNode {
            min,
            index: 0,
            max,
            count: 1,
        };
        let inf = f32::INFINITY;
        NodePair {
            x: Vec4::new(n.min[0], n.max[0], inf, inf),
            y: Vec4::new(n.min[1], n.max[1], inf, inf),
            z: Vec4::new(n.min[2], n.max[2], inf, inf),
            index: [0, 0],
            count: [1, 0],
        }
    }

    fn entry(b: Aabb, o: Vec3, d: Vec3, t_max: f32) -> Option<f32> {
        let (a, absent) = RayBoxTest::new(o, d).entries(&pair_of(b), t_max);
        assert_eq!(absent, f32::INFINITY, "absent child must never be entered");
        (a != f32::INFINITY).then_some(a)
    }

    fn unit() -> Aabb {
        Aabb {
            min: Vec3::splat(-1.0),
            max: Vec3::splat(1.0),
        }
    }

    #[test]
    fn axis_parallel_rays_and_origins_on_slab_planes() {
        let t = entry(unit(), Vec3::new(-5.0, 0.0, 0.0), Vec3::X, f32::INFINITY).unwrap();
        assert!((t - 4.0).abs() <= 4.0 * f32::EPSILON, "{t}");
        assert!(entry(unit(), Vec3::new(-2.0, 0.0, 0.0), Vec3::Y, f32::INFINITY).is_none());
        for d in [Vec3::X, Vec3::Y, Vec3::Z, -Vec3::X, -Vec3::Y, -Vec3::Z] {
            assert!(
                entry(unit(), Vec3::splat(-1.0), d, f32::INFINITY).is_some(),
                "corner (-1,-1,-1) along {d:?}"
            );
            assert!(
                entry(unit(), Vec3::splat(1.0), d, f32::INFINITY).is_some(),
                "corner (1,1,1) along {d:?}"
            );
        }
        let o = Vec3::new(0.0, 0.0, -5.0);
        assert!(entry(unit(), o, Vec3::new(-0.0, 0.0, 1.0), f32::INFINITY).is_some());
        assert!(entry(unit(), o, Vec3::new(1e-30, -1e-30, 1.0), f32::INFINITY).is_some());
        assert!(
            entry(
                unit(),
                Vec3::new(1.0, 1.0, -5.0),
                Vec3::new(-0.0, 0.0, 1.0),
                f32::INFINITY
            )
            .is_some()
        );
        // t_max before the box: no entry.
        assert!(entry(unit(), Vec3::new(-5.0, 0.0, 0.0), Vec3::X, 3.9).is_none());
    }

    #[test]
    fn huge_and_tiny_boxes() {
        let tiny = Aabb {
            min: Vec3::splat(1e-30),
            max: Vec3::splat(2e-30),
        };
        assert!(
            entry(
                tiny,
                Vec3::new(1.5e-30, 1.5e-30, -1.0),
                Vec3::Z,
                f32::INFINITY
            )
            .is_some()
        );
        let huge = Aabb {
            min: Vec3::splat(-1e30),
            max: Vec3::splat(1e30),
        };
        assert!(
            entry(
                huge,
                Vec3::ZERO,
                Vec3::new(0.3, -0.2, 0.9).normalize(),
                f32::INFINITY
            )
            .is_some()
        );
        let far = Aabb {
            min: Vec3::new(1e5, 0.0, 0.0),
            max: Vec3::new(1e5 + 1.0, 1.0, 1.0),
        };
        assert!(entry(far, Vec3::new(0.0, 0.5, 0.5), Vec3::X, f32::INFINITY).is_some());
    }

    fn brute_first(boxes: &[Aabb], o: Vec3, d: Vec3) -> Option<f32> {
        boxes
            .iter()
            .filter_map(|b| entry(*b, o, d, f32::INFINITY))
            .reduce(f32::min)
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
                let t = bvh.closest(&r, f32::INFINITY, |slot, tmax| {
                    let b = boxes[bvh.order[slot as usize] as usize];
                    entry(b, o, d, tmax)
                });
                let found = (t != f32::INFINITY).then_some(t);
                if found != brute_first(&boxes, o, d) {
                    mismatches += 1;
                }
                let any = bvh.any(&r, f32::INFINITY, |slot, tmax| {
                    entry(boxes[bvh.order[slot as usize] as usize], o, d, tmax).is_some()
                });
                if any != found.is_some() {
                    mismatches += 1;
                }
            }
        }
        assert_eq!(mismatches, 0);
    }

    #[test]
    fn fuzzed_degenerate_directions_match_brute_force() {
        // Directions with components in {0, -0, ±1e-30, ±1}, origins snapped to box planes.
        let mut rng = crate::sampling::Rng::new(3, 4);
        let boxes: Vec<Aabb> = (0..200)
            .map(|_| {
                let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 10.0;
                let e = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32());
                Aabb { min: c, max: c + e }
            })
            .collect();
        let bvh = Bvh::build(&boxes);
        let comps = [0.0f32, -0.0, 1e-30, -1e-30, 1.0, -1.0];
        let mut mismatches = 0;
        for _ in 0..20_000 {
            let mut d = Vec3::new(
                comps[rng.next_u32() as usize % 6],
                comps[rng.next_u32() as usize % 6],
                comps[rng.next_u32() as usize % 6],
            );
            if d.abs().max_element() < 0.5 {
                d.x = 1.0;
            }
            let b = boxes[rng.next_u32() as usize % boxes.len()];
            let o = Vec3::new(
                if rng.next_f32() < 0.5 {
                    b.min.x
                } else {
                    rng.next_f32() * 10.0
                },
                if rng.next_f32() < 0.5 {
                    b.max.y
                } else {
                    rng.next_f32() * 10.0
                },
                rng.next_f32() * 10.0,
            );
            let r = RayBoxTest::new(o, d);
            let t = bvh.closest(&r, f32::INFINITY, |slot, tmax| {
                entry(boxes[bvh.order[slot as usize] as usize], o, d, tmax)
            });
            let found = (t != f32::INFINITY).then_some(t);
            if found != brute_first(&boxes, o, d) {
                mismatches += 1;
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
    fn empty_and_single_primitive_trees() {
        let r = RayBoxTest::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z);
        let bvh = Bvh::build(&[]);
        assert_eq!(bvh.closest(&r, 5.0, |_, _| Some(1.0)), 5.0);
        assert!(!bvh.any(&r, 5.0, |_, _| true));
        let one = Bvh::build(&[Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        }]);
        assert_eq!(one.closest(&r, 5.0, |_, _| Some(1.0)), 1.0);
        assert!(one.any(&r, 5.0, |_, _| true));
        let miss = RayBoxTest::new(Vec3::new(5.0, 5.0, -1.0), Vec3::Z);
        assert!(!one.any(&miss, 5.0, |_, _| true));
    }
}

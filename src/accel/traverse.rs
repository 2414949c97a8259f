//! Stack-based traversal without allocation: the slabs of a node's eight children tested at once
//! with SIMD (one AVX register, or two SSE halves without AVX), children visited nearest first, far children culled on pop once a closer hit is known.

use std::cell::RefCell;

use glam::Vec3;
use wide::f32x8;

use super::bvh::{Bvh, Node8, WIDTH};
use crate::geometry::float::gamma;

/// Traversal stack for ordinary trees; deeper trees (the builder's depth cap is what bounds them)
/// use [`STACK_MAX`].
const STACK_SMALL: usize = 64;
/// Enough for any tree the builder makes: binary depth ≤ 64, so at most 64 wide levels pushing
/// at most `WIDTH - 1` entries each.
const STACK_MAX: usize = (WIDTH - 1) * 64 + 1;

/// `1/d` for the far planes: widened by 1 + 2γ₄, so that even after this product's own rounding
/// (half an ulp) it is at least 1 + 2γ₃ times `1/d` in magnitude, pbrt's widening of the far slab
/// distance that covers the slab computation's rounding. Applied to `1/d` once per ray rather
/// than to every node's far distances, the multiplication is off the chain from a node's load to
/// the choice of its children.
#[inline]
fn scale_up(inv: f32) -> f32 {
    inv * (1.0 + 2.0 * gamma(4))
}

/// Per-ray constants of the slab test.
#[derive(Debug, Clone, Copy)]
pub struct RayBoxTest {
    o: [f32x8; 3],
    inv: [f32x8; 3],
    /// `inv` times [`FAR_SCALE`] (rounded up), for the far planes.
    inv_far: [f32x8; 3],
    /// Per axis, which of a node's planes (0 = min, 1 = max) the ray crosses first.
    near: [usize; 3],
}

/// A deferred child: node index or first slot, leaf size (0 = node), entry distance.
#[derive(Debug, Clone, Copy, Default)]
struct Entry {
    index: u32,
    count: u32,
    t: f32,
}

/// The traversal stacks of one thread, kept between queries: a stack made per query would be
/// zeroed on every ray (the crate forbids `unsafe`, so it cannot be left uninitialised), which
/// cost about 3 % of the instructions of a query.
struct Stacks {
    closest: [Entry; STACK_SMALL],
    any: [(u32, u32); STACK_SMALL],
}

thread_local! {
    static STACKS: RefCell<Stacks> = const {
        RefCell::new(Stacks {
            closest: [Entry { index: 0, count: 0, t: 0.0 }; STACK_SMALL],
            any: [(0, 0); STACK_SMALL],
        })
    };
}

impl RayBoxTest {
    /// Precomputes the reciprocal direction. A zero component gives ±∞, so that axis's slab is
    /// unbounded for an origin strictly inside it and empty outside. Node bounds are padded by
    /// an ulp beyond their geometry, so the ambiguous `0·∞` (an origin exactly on a slab plane)
    /// only occurs on planes that hold no geometry, where either answer is correct. A large finite
    /// stand-in for `1/0` would instead clip tiny boxes (tinybvh PR #286).
    ///
    /// The near plane per axis follows the sign of the reciprocal (so `-0` counts as negative,
    /// consistently with `1/-0 = -∞`); the empty box `[+∞, -∞]` of an absent child then gives
    /// near `+∞` and far `-∞` whatever the direction, and is never entered.
    #[inline]
    #[must_use]
    pub fn new(origin: Vec3, dir: Vec3) -> Self {
        let inv = dir.recip();
        let near = |i: f32| usize::from(i.is_sign_negative());
        Self {
            o: [
                f32x8::splat(origin.x),
                f32x8::splat(origin.y),
                f32x8::splat(origin.z),
            ],
            inv: [
                f32x8::splat(inv.x),
                f32x8::splat(inv.y),
                f32x8::splat(inv.z),
            ],
            inv_far: [
                f32x8::splat(scale_up(inv.x)),
                f32x8::splat(scale_up(inv.y)),
                f32x8::splat(scale_up(inv.z)),
            ],
            near: [near(inv.x), near(inv.y), near(inv.z)],
        }
    }

    /// Which children of `node` the ray enters at or before `t_max` (bit `c` for child `c`), and
    /// the entry distances per child (`≥ 0`, never NaN; meaningful only for entered children).
    ///
    /// A NaN from `0·∞` is dropped by the min/max chains (`maxps`/`minps` return their second
    /// operand), which only ever widens the slab interval: such a box is entered early or
    /// spuriously, never skipped.
    #[inline(always)]
    #[must_use]
    pub fn entries(&self, node: &Node8, t_max: f32) -> (u32, [f32; WIDTH]) {
        self.entries_with(node, t_max, self.near)
    }

    /// The ray's octant: bit `axis` set if the near plane on `axis` is the max plane.
    #[inline(always)]
    fn octant(&self) -> usize {
        self.near[0] | (self.near[1] << 1) | (self.near[2] << 2)
    }

    /// [`RayBoxTest::entries`] with the near planes given (`near[axis]` is 0 or 1); when they are
    /// constants, the plane loads compile to fixed offsets.
    #[inline(always)]
    fn entries_with(&self, node: &Node8, t_max: f32, near: [usize; 3]) -> (u32, [f32; WIDTH]) {
        let slab = |axis: usize| {
            let n = near[axis] & 1;
            let b = &node.bounds[axis];
            let near = (b[n] - self.o[axis]) * self.inv[axis];
            let far = (b[n ^ 1] - self.o[axis]) * self.inv_far[axis];
            (near, far)
        };
        let (nx, fx) = slab(0);
        let (ny, fy) = slab(1);
        let (nz, fz) = slab(2);
        // Two levels of max/min instead of a chain of three: each pair's NaN (second operand) is
        // dropped by the outer operation, whose second operand is never NaN.
        let near = nx.fast_max(ny).fast_max(nz.fast_max(f32x8::ZERO));
        let far = fx.fast_min(fy).fast_min(fz.fast_min(f32x8::splat(t_max)));
        (near.simd_le(far).to_bitmask(), near.to_array())
    }
}

/// Low bits of a sort key that name the child lane.
const LANE_BITS: u32 = WIDTH as u32 - 1;

/// Sort key of child `lane` entered at `t ≥ 0`: the distance's bits with the lane in the three
/// lowest, so that keys order like distances (up to the dropped bits) and name their lane.
#[inline(always)]
fn key(t: f32, lane: u32) -> u32 {
    (t.to_bits() & !LANE_BITS) | lane
}

/// The distance a key stands for: never more than the true entry distance, so culling with it
/// is conservative.
#[inline(always)]
fn key_t(k: u32) -> f32 {
    f32::from_bits(k & !LANE_BITS)
}

/// The near planes of octant `oct` (0..8), or the ray's own for `oct == 8` (the generic path).
#[inline(always)]
fn near_of<const OCT: usize>(ray: &RayBoxTest) -> [usize; 3] {
    if OCT < 8 {
        [OCT & 1, (OCT >> 1) & 1, (OCT >> 2) & 1]
    } else {
        ray.near
    }
}

/// Starts loading a node that the traversal pushed for later: a plain load whose value is unused
/// (the crate forbids `unsafe`, so there is no prefetch intrinsic), which the CPU runs ahead.
#[inline(always)]
fn touch(nodes: &[Node8], index: u32, count: u32) {
    if count == 0
        && let Some(n) = nodes.get(index as usize)
    {
        // One load per 128-byte half of the node (the adjacent-line prefetcher fetches pairs).
        std::hint::black_box((n.bounds[0][0].as_array()[0], n.bounds[2][0].as_array()[0]));
    }
}

/// The entry distance of child `c` (0..8) from [`RayBoxTest::entries`].
#[inline(always)]
fn lane_t(near: &[f32; WIDTH], c: usize) -> f32 {
    near[c & (WIDTH - 1)]
}

/// `on_thread_stack!(test, field, |test, stack| query)`: runs `query` on the thread's traversal
/// stack `STACKS.field`, or on a fresh one if that stack is in use (a `test` callback that
/// itself traces a ray) or the thread is shutting down. A macro, not a function taking closures:
/// as a function the any-hit query stopped being inlined into its callers (shadow rays measured
/// 10 % more instructions under callgrind on cbox, `scripts/callgrind_diff.sh`).
macro_rules! on_thread_stack {
    ($test:expr, $field:ident, |$t:ident, $stack:ident| $query:expr) => {{
        let mut test = Some($test);
        let done = STACKS.try_with(|cell| {
            let mut stacks = cell.try_borrow_mut().ok()?;
            let $t = test.take()?;
            let $stack = &mut stacks.$field;
            Some($query)
        });
        match (done, test) {
            (Ok(Some(r)), _) => r,
            (_, Some($t)) => {
                let $stack = &mut [Default::default(); STACK_SMALL];
                $query
            }
            (_, None) => unreachable!("the callback is only taken when the query runs"),
        }
    }};
}

/// `by_octant!(ray, OCT => expr)`: `expr` with the constant `OCT` set to the ray's octant
/// (0–7), so that each octant gets its own copy of the traversal loop with the slab planes at
/// fixed offsets (closest and any-hit share it).
macro_rules! by_octant {
    ($ray:expr, $oct:ident => $e:expr) => {
        by_octant!(@arms $ray, $oct => $e; 0 1 2 3 4 5 6)
    };
    (@arms $ray:expr, $oct:ident => $e:expr; $($k:literal)*) => {
        match $ray.octant() {
            $($k => {
                const $oct: usize = $k;
                $e
            })*
            _ => {
                const $oct: usize = 7;
                $e
            }
        }
    };
}

impl Bvh {
    /// Visits every leaf the ray may reach before `t_max`, nearest child first.
    /// `test(first, count, t_max)` intersects the primitives in slots `first .. first + count`
    /// (`first` is a multiple of [`LEAF_BLOCK`](super::bvh::LEAF_BLOCK)) and returns the closest
    /// distance it found below `t_max`, which then shrinks the search. Returns the final `t_max`.
    #[inline]
    pub fn closest(
        &self,
        ray: &RayBoxTest,
        t_max: f32,
        test: impl FnMut(u32, u32, f32) -> Option<f32>,
    ) -> f32 {
        if self.nodes.is_empty() {
            return t_max;
        }
        if self.stack_need > STACK_SMALL {
            let stack = &mut [Entry::default(); STACK_MAX];
            return self.closest_with::<STACK_MAX, 8>(ray, t_max, test, stack);
        }
        on_thread_stack!(test, closest, |test, stack| self
            .closest_octant(ray, t_max, test, stack))
    }

    /// [`Bvh::closest`] with one copy of the loop per ray octant, so the slab planes are fixed
    /// offsets.
    #[inline(always)]
    fn closest_octant(
        &self,
        ray: &RayBoxTest,
        t_max: f32,
        test: impl FnMut(u32, u32, f32) -> Option<f32>,
        stack: &mut [Entry; STACK_SMALL],
    ) -> f32 {
        by_octant!(ray, OCT => self.closest_with::<STACK_SMALL, OCT>(ray, t_max, test, stack))
    }

    #[inline(always)]
    fn closest_with<const N: usize, const OCT: usize>(
        &self,
        ray: &RayBoxTest,
        mut t_max: f32,
        mut test: impl FnMut(u32, u32, f32) -> Option<f32>,
        stack: &mut [Entry; N],
    ) -> f32 {
        let nodes = &self.nodes[..];
        let near_planes = near_of::<OCT>(ray);
        let mut sp = 0usize;
        let (mut index, mut count) = (0u32, 0u32);
        loop {
            if count == 0 {
                let node = &nodes[index as usize];
                let (mask, near) = ray.entries_with(node, t_max, near_planes);
                match mask.count_ones() {
                    0 => {}
                    1 => {
                        let c = (mask.trailing_zeros() & LANE_BITS) as usize;
                        (index, count) = (node.index[c], node.count[c]);
                        continue;
                    }
                    2 => {
                        let a = (mask.trailing_zeros() & LANE_BITS) as usize;
                        let b = ((31 - mask.leading_zeros()) & LANE_BITS) as usize;
                        let (ta, tb) = (lane_t(&near, a), lane_t(&near, b));
                        let (c, f, tf) = if ta <= tb { (a, b, tb) } else { (b, a, ta) };
                        stack[sp] = Entry {
                            index: node.index[f],
                            count: node.count[f],
                            t: tf,
                        };
                        touch(nodes, node.index[f], node.count[f]);
                        sp += 1;
                        (index, count) = (node.index[c], node.count[c]);
                        continue;
                    }
                    _ => {
                        // Insertion sort of the entered children's keys, nearest first.
                        let mut k = [u32::MAX; WIDTH];
                        let mut n = 0usize;
                        let mut m = mask;
                        while m != 0 {
                            let c = m.trailing_zeros() & LANE_BITS;
                            m &= m - 1;
                            let kc = key(lane_t(&near, c as usize), c);
                            let mut j = n & (WIDTH - 1);
                            while j > 0 && k[j - 1] > kc {
                                k[j] = k[j - 1];
                                j -= 1;
                            }
                            k[j] = kc;
                            n += 1;
                        }
                        for &kk in k[1..n.min(WIDTH)].iter().rev() {
                            let c = (kk & LANE_BITS) as usize;
                            stack[sp] = Entry {
                                index: node.index[c],
                                count: node.count[c],
                                t: key_t(kk),
                            };
                            touch(nodes, node.index[c], node.count[c]);
                            sp += 1;
                        }
                        let c = (k[0] & LANE_BITS) as usize;
                        (index, count) = (node.index[c], node.count[c]);
                        continue;
                    }
                }
            } else if let Some(t) = test(index, count, t_max) {
                t_max = t;
            }
            loop {
                if sp == 0 {
                    return t_max;
                }
                sp -= 1;
                let e = stack[sp];
                if e.t <= t_max {
                    (index, count) = (e.index, e.count);
                    break;
                }
            }
        }
    }

    /// True as soon as `test(first, count, t_max)` reports a hit among the primitives in slots
    /// `first .. first + count` of a leaf the ray reaches before `t_max`.
    #[inline]
    pub fn any(
        &self,
        ray: &RayBoxTest,
        t_max: f32,
        test: impl FnMut(u32, u32, f32) -> bool,
    ) -> bool {
        if self.nodes.is_empty() {
            return false;
        }
        if self.stack_need > STACK_SMALL {
            let stack = &mut [(0, 0); STACK_MAX];
            return self.any_with::<STACK_MAX, 8>(ray, t_max, test, stack);
        }
        on_thread_stack!(test, any, |test, stack| self
            .any_octant(ray, t_max, test, stack))
    }

    /// [`Bvh::any`] with one copy of the loop per ray octant.
    #[inline(always)]
    fn any_octant(
        &self,
        ray: &RayBoxTest,
        t_max: f32,
        test: impl FnMut(u32, u32, f32) -> bool,
        stack: &mut [(u32, u32); STACK_SMALL],
    ) -> bool {
        by_octant!(ray, OCT => self.any_with::<STACK_SMALL, OCT>(ray, t_max, test, stack))
    }

    #[inline(always)]
    fn any_with<const N: usize, const OCT: usize>(
        &self,
        ray: &RayBoxTest,
        t_max: f32,
        mut test: impl FnMut(u32, u32, f32) -> bool,
        stack: &mut [(u32, u32); N],
    ) -> bool {
        let nodes = &self.nodes[..];
        let near_planes = near_of::<OCT>(ray);
        let mut sp = 0usize;
        let (mut index, mut count) = (0u32, 0u32);
        loop {
            if count == 0 {
                let node = &nodes[index as usize];
                let (mut mask, _) = ray.entries_with(node, t_max, near_planes);
                if mask != 0 {
                    let c = (mask.trailing_zeros() & LANE_BITS) as usize;
                    mask &= mask - 1;
                    while mask != 0 {
                        let f = ((31 - mask.leading_zeros()) & LANE_BITS) as usize;
                        stack[sp] = (node.index[f], node.count[f]);
                        touch(nodes, node.index[f], node.count[f]);
                        sp += 1;
                        mask &= !(1 << f);
                    }
                    (index, count) = (node.index[c], node.count[c]);
                    continue;
                }
            } else if test(index, count, t_max) {
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
    use super::*;
    use crate::accel::BvhNode;
    use crate::geometry::Aabb;

    /// A node whose first child is `b` (padded like the builder does) and whose others are absent.
    fn node_of(b: Aabb) -> Node8 {
        let (min, max) = crate::accel::build::padded(b);
        let n = BvhNode {
            min,
            index: 0,
            max,
            count: 1,
        };
        let mut node = Node8::EMPTY;
        node.set_child(0, n.min, n.max, n.index, n.count);
        node
    }

    fn entry(b: Aabb, o: Vec3, d: Vec3, t_max: f32) -> Option<f32> {
        let (mask, near) = RayBoxTest::new(o, d).entries(&node_of(b), t_max);
        assert_eq!(mask & !1, 0, "absent child must never be entered");
        (mask & 1 != 0).then_some(near[0])
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

    /// `Bvh::closest` with a per-slot test, in slot order (as a leaf callback would run it).
    fn closest_slots(
        bvh: &Bvh,
        r: &RayBoxTest,
        t_max: f32,
        mut test: impl FnMut(u32, f32) -> Option<f32>,
    ) -> f32 {
        bvh.closest(r, t_max, |first, count, mut t_max| {
            assert_eq!(first as usize % crate::accel::bvh::LEAF_BLOCK, 0);
            let mut found = None;
            for slot in first..first + count {
                if let Some(t) = test(slot, t_max) {
                    t_max = t;
                    found = Some(t);
                }
            }
            found
        })
    }

    /// `Bvh::any` with a per-slot test.
    fn any_slots(
        bvh: &Bvh,
        r: &RayBoxTest,
        t_max: f32,
        mut test: impl FnMut(u32, f32) -> bool,
    ) -> bool {
        bvh.any(r, t_max, |first, count, t_max| {
            (first..first + count).any(|slot| test(slot, t_max))
        })
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
                let t = closest_slots(&bvh, &r, f32::INFINITY, |slot, tmax| {
                    let b = boxes[bvh.order[slot as usize] as usize];
                    entry(b, o, d, tmax)
                });
                let found = (t != f32::INFINITY).then_some(t);
                if found != brute_first(&boxes, o, d) {
                    mismatches += 1;
                }
                let any = any_slots(&bvh, &r, f32::INFINITY, |slot, tmax| {
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
            let t = closest_slots(&bvh, &r, f32::INFINITY, |slot, tmax| {
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
        assert_eq!(bvh.order.len() % crate::accel::bvh::LEAF_BLOCK, 0);
        let mut seen: Vec<u32> = bvh
            .order
            .iter()
            .copied()
            .filter(|&o| o != crate::accel::bvh::PAD)
            .collect();
        seen.sort_unstable();
        assert_eq!(seen, (0..100_000).collect::<Vec<u32>>());
    }

    #[test]
    fn empty_and_single_primitive_trees() {
        let r = RayBoxTest::new(Vec3::new(0.5, 0.5, -1.0), Vec3::Z);
        let bvh = Bvh::build(&[]);
        assert_eq!(closest_slots(&bvh, &r, 5.0, |_, _| Some(1.0)), 5.0);
        assert!(!any_slots(&bvh, &r, 5.0, |_, _| true));
        let one = Bvh::build(&[Aabb {
            min: Vec3::ZERO,
            max: Vec3::ONE,
        }]);
        assert_eq!(closest_slots(&one, &r, 5.0, |_, _| Some(1.0)), 1.0);
        assert!(any_slots(&one, &r, 5.0, |_, _| true));
        let miss = RayBoxTest::new(Vec3::new(5.0, 5.0, -1.0), Vec3::Z);
        assert!(!any_slots(&one, &miss, 5.0, |_, _| true));
    }

    #[test]
    fn far_reciprocal_is_widened_by_at_least_pbrt_factor() {
        // |scale_up(inv)| >= |inv| (1 + 2γ₃), checked exactly in f64, over many magnitudes.
        let factor = 1.0 + 2.0 * f64::from(gamma(3));
        let mut rng = crate::sampling::Rng::new(1, 2);
        for _ in 0..100_000 {
            let e = (rng.next_u32() % 200) as i32 - 100;
            let inv = (1.0 + rng.next_f32()) * 2f32.powi(e);
            for v in [inv, -inv] {
                let w = f64::from(scale_up(v));
                assert!(w.abs() >= f64::from(v).abs() * factor, "{v}");
                assert_eq!(w.signum(), f64::from(v).signum());
            }
        }
        assert_eq!(scale_up(f32::INFINITY), f32::INFINITY);
        assert_eq!(scale_up(f32::NEG_INFINITY), f32::NEG_INFINITY);
    }
}

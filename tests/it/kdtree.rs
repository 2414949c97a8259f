//! The photon map's kd-tree against brute force: k-nearest and fixed-radius queries must return
//! exactly the brute-force set (same slots, bit-identical squared distances, ties to the lower
//! slot) on random, clustered, coincident, planar and lattice point sets, for every leaf size and
//! split rule; plus the hard cases of issue 13 (empty maps, k larger than the map, NaN).

use caustic::sampling::Rng;
use caustic::spatial::{
    BuildOptions, KdTree, KdTreeError, KnnHeap, Neighbor, Photon, SplitAxis, distance2,
};
use glam::Vec3;
use proptest::prelude::*;

/// Brute force over the tree's own item order: every item with `d² ≤ r2`, ordered by
/// `(d², slot)`, the first `k`.
fn brute_nearest(items: &[[f32; 3]], q: [f32; 3], r2: f32, k: usize) -> Vec<Neighbor> {
    let mut all: Vec<Neighbor> = items
        .iter()
        .enumerate()
        .map(|(i, &p)| Neighbor {
            index: i as u32,
            dist2: distance2(q, p),
        })
        .filter(|n| n.dist2 <= r2)
        .collect();
    all.sort_by(|a, b| a.dist2.total_cmp(&b.dist2).then(a.index.cmp(&b.index)));
    all.truncate(k);
    all
}

fn sorted_bits(v: &[[f32; 3]]) -> Vec<[u32; 3]> {
    let mut b: Vec<[u32; 3]> = v.iter().map(|p| p.map(f32::to_bits)).collect();
    b.sort_unstable();
    b
}

/// Checks one tree against brute force at every query, radius and k.
fn check_tree(tree: &KdTree<[f32; 3]>, queries: &[[f32; 3]], radii2: &[f32], ks: &[usize]) {
    let items = tree.items();
    let mut heap = KnnHeap::new(1);
    let mut found = Vec::new();
    for &q in queries {
        for &r2 in radii2 {
            for &k in ks {
                heap.set_k(k);
                let n = tree.nearest(q, r2, &mut heap);
                heap.sort();
                let got: Vec<Neighbor> = heap.iter().collect();
                let want = brute_nearest(items, q, r2, k);
                assert_eq!(n, want.len());
                assert_eq!(got, want, "k-nearest q {q:?} r² {r2} k {k}");
                assert_eq!(heap.max_dist2(), want.last().map(|w| w.dist2));
            }
            tree.within_into(q, r2, &mut found);
            found.sort_by_key(|n| n.index);
            let mut want = brute_nearest(items, q, r2, usize::MAX);
            want.sort_by_key(|n| n.index);
            assert_eq!(found, want, "radius q {q:?} r² {r2}");
        }
    }
}

/// Point sets: uniform, clustered (tight blobs at several scales), coincident, on an axis plane,
/// on an oblique plane, on a small integer lattice (many exact ties), and a mix.
fn point_set(kind: u8, n: usize, seed: u64) -> Vec<[f32; 3]> {
    let mut r = Rng::new(seed, 77);
    let mut u = move || r.next_f32();
    match kind % 7 {
        0 => (0..n)
            .map(|_| [u() * 20.0 - 10.0, u() * 20.0 - 10.0, u() * 20.0 - 10.0])
            .collect(),
        1 => {
            let centres: Vec<[f32; 3]> =
                (0..4).map(|_| [u() * 8.0, u() * 8.0, u() * 8.0]).collect();
            (0..n)
                .map(|i| {
                    let c = centres[i % 4];
                    let s = [1e-4f32, 1e-2, 1.0][i % 3];
                    [c[0] + s * u(), c[1] + s * u(), c[2] + s * u()]
                })
                .collect()
        }
        2 => vec![[1.5, -2.0, 0.25]; n],
        3 => (0..n).map(|_| [u() * 4.0, 3.0, u() * 4.0]).collect(),
        4 => (0..n)
            .map(|_| {
                let (a, b) = (u() * 4.0, u() * 4.0);
                [a, b, 0.3 * a - 0.7 * b + 1.0]
            })
            .collect(),
        5 => (0..n)
            .map(|_| {
                [
                    (u() * 4.0).floor(),
                    (u() * 4.0).floor(),
                    (u() * 2.0).floor(),
                ]
            })
            .collect(),
        _ => (0..n)
            .map(|i| match i % 3 {
                0 => [u(), u(), u()],
                1 => [0.5, 0.5, 0.5],
                _ => [u(), 0.0, u()],
            })
            .collect(),
    }
}

/// Queries: on items (exact coincidence), near them, between lattice points, and far outside.
fn queries(points: &[[f32; 3]], seed: u64) -> Vec<[f32; 3]> {
    let mut r = Rng::new(seed, 78);
    let mut q: Vec<[f32; 3]> = (0..6)
        .map(|_| {
            [
                r.next_f32() * 12.0 - 2.0,
                r.next_f32() * 12.0 - 2.0,
                r.next_f32() * 12.0 - 2.0,
            ]
        })
        .collect();
    q.extend([[0.5, 0.5, 0.5], [1e6, -1e6, 3.0], [1.5, 1.5, 0.5]]);
    for i in 0..4.min(points.len()) {
        let p = points[(i * 7919) % points.len()];
        q.push(p);
        q.push([p[0] + 1e-3, p[1], p[2] - 2e-3]);
    }
    q
}

fn options(leaf: usize, round_robin: bool) -> BuildOptions {
    BuildOptions {
        leaf_size: leaf,
        split_axis: if round_robin {
            SplitAxis::RoundRobin
        } else {
            SplitAxis::Widest
        },
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 160, failure_persistence: None, ..ProptestConfig::default() })]

    #[test]
    fn queries_agree_exactly_with_brute_force(
        kind in 0u8..7,
        n in 0usize..700,
        seed in any::<u64>(),
        leaf in prop::sample::select(vec![1usize, 2, 3, 8, 16, 64]),
        round_robin in any::<bool>(),
    ) {
        let points = point_set(kind, n, seed);
        let tree = KdTree::build_with(points.clone(), options(leaf, round_robin)).unwrap();
        // The tree holds exactly the input, reordered.
        prop_assert_eq!(sorted_bits(tree.items()), sorted_bits(&points));
        let qs = queries(&points, seed);
        check_tree(&tree, &qs, &[f32::INFINITY, 2.0, 0.01, 0.0], &[0, 1, 7, 50, n + 3]);
    }

    /// Arbitrary coordinates from a small value set: exact ties everywhere, shrinkable.
    #[test]
    fn queries_agree_on_shrinkable_tie_heavy_sets(
        points in prop::collection::vec(prop::array::uniform3(prop::sample::select(vec![-1.0f32, 0.0, 0.5, 1.0, 2.0])), 0..300),
        q in prop::array::uniform3(-1.5f32..2.5),
        leaf in 1usize..10,
    ) {
        let tree = KdTree::build_with(points, options(leaf, false)).unwrap();
        check_tree(&tree, &[q, [0.0, 0.0, 0.0], [0.5, 1.0, -1.0]], &[f32::INFINITY, 1.0, 0.25], &[1, 3, 10, 40]);
    }
}

#[test]
fn distance2_is_the_euclidean_distance() {
    // The definition the brute force shares with the tree, against f64.
    let mut r = Rng::new(1, 1);
    for _ in 0..10_000 {
        let a = [r.next_f32(), r.next_f32(), r.next_f32()].map(|x| x * 10.0 - 5.0);
        let b = [r.next_f32(), r.next_f32(), r.next_f32()].map(|x| x * 10.0 - 5.0);
        let exact: f64 = (0..3)
            .map(|i| (f64::from(a[i]) - f64::from(b[i])).powi(2))
            .sum();
        let d = f64::from(distance2(a, b));
        assert!((d - exact).abs() <= 1e-6 * exact.max(1e-30), "{a:?} {b:?}");
    }
}

#[test]
fn empty_map_finds_nothing() {
    let tree = KdTree::<[f32; 3]>::build(Vec::new()).unwrap();
    assert!(tree.is_empty() && tree.bounds().is_none());
    let mut heap = KnnHeap::new(10);
    assert_eq!(tree.nearest([0.0; 3], f32::INFINITY, &mut heap), 0);
    assert!(heap.is_empty() && heap.max_dist2().is_none());
    let mut out = vec![Neighbor {
        index: 9,
        dist2: 9.0,
    }];
    tree.within_into([0.0; 3], f32::INFINITY, &mut out);
    assert!(out.is_empty());
}

#[test]
fn k_larger_than_the_map_returns_the_whole_map_in_order() {
    let points: Vec<[f32; 3]> = (0..5).map(|i| [i as f32, 0.0, 0.0]).collect();
    let tree = KdTree::build(points).unwrap();
    let mut heap = KnnHeap::new(1000);
    assert_eq!(tree.nearest([-1.0, 0.0, 0.0], f32::INFINITY, &mut heap), 5);
    heap.sort();
    let d: Vec<f32> = heap.iter().map(|n| n.dist2).collect();
    assert_eq!(d, [1.0, 4.0, 9.0, 16.0, 25.0]);
    // The radius still applies: only x ∈ {0, 1} lie within 2 of x = −1.
    assert_eq!(tree.nearest([-1.0, 0.0, 0.0], 4.0, &mut heap), 2);
}

#[test]
fn coincident_photons_tie_to_the_lowest_slots_without_scanning_the_map() {
    // 200k identical positions: every distance ties, so the k nearest are slots 0..k. Pruning on
    // (distance, slot) keys makes this a short walk down the left spine; a search that pruned on
    // distance alone would visit all 200k photons per query (checked by timing against a scan).
    let n = 200_000;
    let photons: Vec<Photon> = (0..n)
        .map(|i| {
            Photon::new(
                Vec3::new(0.25, 0.5, 0.75),
                -Vec3::Y,
                Vec3::Y,
                Vec3::splat(i as f32),
            )
        })
        .collect();
    let tree = KdTree::build(photons).unwrap();
    let mut heap = KnnHeap::new(50);
    // Fastest of ten batches, so a preemption on a loaded machine cannot fail the test.
    let per_query = (0..10)
        .map(|_| {
            let t0 = std::time::Instant::now();
            for _ in 0..100 {
                assert_eq!(tree.nearest([0.25, 0.5, 0.8], 1.0, &mut heap), 50);
            }
            t0.elapsed().as_secs_f64() / 100.0
        })
        .fold(f64::INFINITY, f64::min);
    heap.sort();
    let slots: Vec<u32> = heap.iter().map(|n| n.index).collect();
    assert_eq!(slots, (0..50).collect::<Vec<u32>>());
    let t0 = std::time::Instant::now();
    let scan: f32 = tree
        .items()
        .iter()
        .map(|p| distance2([0.25, 0.5, 0.8], caustic::spatial::HasPosition::position(p)))
        .sum();
    let scan_time = t0.elapsed().as_secs_f64();
    assert!(scan > 0.0);
    assert!(
        per_query * 20.0 < scan_time,
        "query {per_query:.2e} s vs scan {scan_time:.2e} s"
    );
    // Radius query: all of them.
    let mut count = 0;
    tree.within([0.25, 0.5, 0.75], 0.0, |_| count += 1);
    assert_eq!(count, n);
}

#[test]
fn non_finite_input_is_rejected_or_finds_nothing() {
    let e = KdTree::build(vec![[0.0, 0.0, 0.0], [0.0, 0.0, f32::NAN]]).unwrap_err();
    assert!(
        matches!(e, KdTreeError::NonFinitePosition { index: 1, position } if position[2].is_nan())
    );
    assert!(e.to_string().contains("item 1") && e.to_string().contains("finite"));
    let tree = KdTree::build(vec![[0.0f32, 0.0, 0.0]; 10]).unwrap();
    let mut heap = KnnHeap::new(3);
    for (q, r2) in [
        ([f32::NAN, 0.0, 0.0], f32::INFINITY),
        ([f32::INFINITY, 0.0, 0.0], f32::INFINITY),
        ([0.0, 0.0, 0.0], f32::NAN),
        ([0.0, 0.0, 0.0], -1.0),
    ] {
        assert_eq!(tree.nearest(q, r2, &mut heap), 0, "{q:?} {r2}");
        let mut c = 0;
        tree.within(q, r2, |_| c += 1);
        assert_eq!(c, 0);
    }
    // −0 is a radius of zero, not a huge bit pattern.
    assert_eq!(tree.nearest([0.0; 3], -0.0, &mut heap), 3);
}

#[test]
fn build_is_the_same_for_any_thread_count() {
    let points = point_set(1, 150_000, 4);
    let build = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| KdTree::build(points.clone()).unwrap())
    };
    let (a, b) = (build(1), build(2));
    assert_eq!(
        a.items()
            .iter()
            .map(|p| p.map(f32::to_bits))
            .collect::<Vec<_>>(),
        b.items()
            .iter()
            .map(|p| p.map(f32::to_bits))
            .collect::<Vec<_>>()
    );
    let mut ha = KnnHeap::new(20);
    let mut hb = KnnHeap::new(20);
    for q in queries(&points, 4) {
        a.nearest(q, f32::INFINITY, &mut ha);
        b.nearest(q, f32::INFINITY, &mut hb);
        assert_eq!(ha.iter().collect::<Vec<_>>(), hb.iter().collect::<Vec<_>>());
    }
}

#[test]
fn large_random_map_agrees_with_brute_force() {
    // Deeper trees than the property test reaches (100k items: depth 13 with leaves of ≤ 16).
    for kind in [0u8, 1, 3] {
        let points = point_set(kind, 100_000, 11);
        let tree = KdTree::build(points.clone()).unwrap();
        let qs: Vec<[f32; 3]> = queries(&points, 12).into_iter().take(8).collect();
        check_tree(&tree, &qs, &[f32::INFINITY, 0.05], &[1, 50, 200]);
    }
}

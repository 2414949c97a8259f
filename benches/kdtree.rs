//! The photon map's kd-tree against the `kiddo` crate (6.3, `ImmutableKdTree<f32, 3>`, its
//! recommended tree for build-once-query-often) on the same points and queries: build time for
//! 1M points, k-nearest queries per second at k = 50 and 200 (within a maximum radius, results
//! unordered, as a density estimate uses them), and fixed-radius queries per second.
//!
//! Two point sets of 1M: `surfaces`, photons as a photon map holds them (on the floor, ceiling
//! and three walls of a unit box, a third of them in a tight caustic on the floor; queries are
//! uniform over the same surfaces, as camera hits are), and `cube`, uniform in the unit cube
//! (kiddo's own benchmark distribution; queries uniform in the cube). Ours is timed twice: over
//! bare `[f32; 3]` points (12 bytes, like kiddo's points plus a 4-byte index) and over packed
//! 24-byte `Photon`s, the photon map's real item.
//!
//! Queries run on one thread; figures are medians of `REPS` runs of `QUERIES` queries, as
//! queries per CPU-second of the timing thread (Linux schedstat, steadier on a shared machine;
//! wall-clock figures are printed to stderr). Each query kind's results are checked to agree
//! between the trees (count and summed distance), so the speeds compare equal work.
//!
//! Run: `cargo bench --bench kdtree --features bench-kiddo` (both sets) or `cargo bench --bench kdtree --features bench-kiddo -- surfaces`.
//! With `KDTREE_SWEEP=1` it instead times our tree alone for several leaf sizes (the figures
//! behind the default of 16).

use std::hint::black_box;
use std::num::NonZeroUsize;
use std::time::Instant;

use caustic::sampling::Rng;
use caustic::spatial::{BuildOptions, KdTree, KnnHeap, Photon, SplitAxis};
use glam::Vec3;
use kiddo::ImmutableKdTree;
use kiddo::dist::SquaredEuclidean;

const N: usize = 1_000_000;
const QUERIES: usize = 100_000;
const REPS: usize = 5;

type Kiddo = ImmutableKdTree<f32, 3>;

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// CPU seconds this thread has run (Linux schedstat; 0 where unavailable).
fn thread_cpu_secs() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .map_or(0.0, |ns| ns as f64 * 1e-9)
}

/// Runs `f` `REPS` times; returns (median CPU seconds, median wall seconds, last result).
fn time<R>(mut f: impl FnMut() -> R) -> (f64, f64, R) {
    let (mut cpu, mut wall) = (Vec::new(), Vec::new());
    let mut last = None;
    for _ in 0..REPS {
        let (c0, w0) = (thread_cpu_secs(), Instant::now());
        let r = f();
        wall.push(w0.elapsed().as_secs_f64());
        cpu.push(thread_cpu_secs() - c0);
        last = Some(r);
    }
    let cpu = median(cpu);
    let wall = median(wall);
    let Some(r) = last else {
        unreachable!("REPS > 0")
    };
    // Without schedstat, fall back to the wall clock.
    (if cpu > 0.0 { cpu } else { wall }, wall, r)
}

/// A point uniformly on the floor, ceiling or one of three walls of the unit box.
fn surface_point(r: &mut Rng) -> [f32; 3] {
    let (u, v) = r.next_2d();
    match (r.next_f32() * 5.0) as u32 {
        0 => [u, 0.0, v],
        1 => [u, 1.0, v],
        2 => [0.0, u, v],
        3 => [1.0, u, v],
        _ => [u, v, 1.0],
    }
}

fn point_set(name: &str) -> (Vec<[f32; 3]>, Vec<[f32; 3]>) {
    let mut r = Rng::new(2024, 13);
    match name {
        "surfaces" => {
            let points = (0..N)
                .map(|i| {
                    if i % 3 == 0 {
                        // The caustic: a disc of radius 0.05 on the floor, denser at its centre.
                        let (a, b) = r.next_2d();
                        let rad = 0.05 * a;
                        let phi = std::f32::consts::TAU * b;
                        [0.5 + rad * phi.cos(), 0.0, 0.5 + rad * phi.sin()]
                    } else {
                        surface_point(&mut r)
                    }
                })
                .collect();
            let queries = (0..QUERIES).map(|_| surface_point(&mut r)).collect();
            (points, queries)
        }
        _ => {
            let mut p = || [r.next_f32(), r.next_f32(), r.next_f32()];
            let points = (0..N).map(|_| p()).collect();
            let queries = (0..QUERIES).map(|_| p()).collect();
            (points, queries)
        }
    }
}

fn photons(points: &[[f32; 3]]) -> Vec<Photon> {
    points
        .iter()
        .map(|&p| Photon::new(Vec3::from(p), -Vec3::Y, Vec3::Y, Vec3::splat(1e-6)))
        .collect()
}

/// Sum of (count, Σ dist²) over all queries for our k-nearest.
fn ours_knn<T: caustic::spatial::HasPosition>(
    t: &KdTree<T>,
    qs: &[[f32; 3]],
    k: usize,
    r2: f32,
) -> (usize, f64) {
    let mut heap = KnnHeap::new(k);
    let (mut n, mut s) = (0, 0f64);
    for q in qs {
        n += t.nearest(black_box(*q), r2, &mut heap);
        s += heap.iter().map(|x| f64::from(x.dist2)).sum::<f64>();
    }
    (n, s)
}

fn ours_within<T: caustic::spatial::HasPosition>(
    t: &KdTree<T>,
    qs: &[[f32; 3]],
    r2: f32,
) -> (usize, f64) {
    let (mut n, mut s) = (0, 0f64);
    for q in qs {
        t.within(black_box(*q), r2, |x| {
            n += 1;
            s += f64::from(x.dist2);
        });
    }
    (n, s)
}

fn kiddo_knn(t: &Kiddo, qs: &[[f32; 3]], k: usize, r2: f32) -> (usize, f64) {
    let k = NonZeroUsize::new(k).unwrap_or(NonZeroUsize::MIN);
    let (mut n, mut s) = (0, 0f64);
    for q in qs {
        let res = t
            .query(black_box(q))
            .nearest_n::<SquaredEuclidean<f32>>(k)
            .within(r2)
            .unsorted()
            .execute();
        n += res.len();
        s += res.iter().map(|x| f64::from(x.distance)).sum::<f64>();
    }
    (n, s)
}

fn kiddo_within(t: &Kiddo, qs: &[[f32; 3]], r2: f32) -> (usize, f64) {
    let (mut n, mut s) = (0, 0f64);
    for q in qs {
        t.query(black_box(q))
            .within::<SquaredEuclidean<f32>>(r2)
            .unsorted()
            .visit(|x| {
                n += 1;
                s += f64::from(x.distance);
            });
    }
    (n, s)
}

/// Checks two (count, Σd²) results agree: counts exactly, sums to f64 rounding.
fn agree(what: &str, a: (usize, f64), b: (usize, f64)) {
    let ok = a.0 == b.0 && (a.1 - b.1).abs() <= 1e-9 * a.1.abs().max(1.0);
    eprintln!(
        "  {what}: ours {} found (Σd² {:.6}), kiddo {} (Σd² {:.6}){}",
        a.0,
        a.1,
        b.0,
        b.1,
        if ok { "" } else { "  ** DISAGREE **" }
    );
}

/// Our tree alone, for each leaf size: build (wall, current pool) and the three query kinds.
fn sweep(name: &str, points: &[[f32; 3]], queries: &[[f32; 3]], knn_r2: f32, fixed_r2: f32) {
    println!("| set | leaf size | build s | k=50 kq/s | k=200 kq/s | radius kq/s |");
    println!("|---|---|---|---|---|---|");
    let qps = |secs: f64| QUERIES as f64 / secs / 1e3;
    for leaf_size in [4usize, 8, 16, 32, 64] {
        let opts = BuildOptions {
            leaf_size,
            split_axis: SplitAxis::Widest,
        };
        let (_, build, tree) = time(|| KdTree::build_with(points.to_vec(), opts).expect("finite"));
        let k50 = time(|| ours_knn(&tree, queries, 50, knn_r2)).0;
        let k200 = time(|| ours_knn(&tree, queries, 200, knn_r2)).0;
        let rad = time(|| ours_within(&tree, queries, fixed_r2)).0;
        println!(
            "| {name} | {leaf_size} | {build:.3} | {:.0} | {:.0} | {:.0} |",
            qps(k50),
            qps(k200),
            qps(rad)
        );
    }
}

fn main() {
    let filter: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    println!(
        "| set | tree | build s (2 thr) | build s (1 thr) | k=50 kq/s | k=200 kq/s | radius kq/s (mean found) |"
    );
    println!("|---|---|---|---|---|---|---|");
    let one = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .expect("a one-thread pool");
    for name in ["surfaces", "cube"] {
        if !filter.is_empty() && !filter.iter().any(|f| name.contains(f.as_str())) {
            continue;
        }
        let (points, queries) = point_set(name);
        // Radii: the k-nearest cap is wide (rarely binding); the fixed radius holds ~50
        // photons at the surfaces' mean density (N over an area of 5) or the cube's (N per unit³).
        let (knn_r2, fixed_r2) = if name == "surfaces" {
            (
                0.05f32 * 0.05,
                50.0 * 5.0 / (std::f32::consts::PI * N as f32),
            )
        } else {
            (
                0.1f32 * 0.1,
                (50.0 * 3.0 / (4.0 * std::f32::consts::PI * N as f32)).powf(2.0 / 3.0),
            )
        };
        eprintln!(
            "{name}: {N} points, {QUERIES} queries, kNN max radius² {knn_r2}, fixed radius² {fixed_r2:.3e}"
        );
        if std::env::var_os("KDTREE_SWEEP").is_some() {
            sweep(name, &points, &queries, knn_r2, fixed_r2);
            continue;
        }

        // Builds: wall clock (the two-thread build's CPU time is not one thread's).
        let wall_build = |f: &mut dyn FnMut()| {
            median(
                (0..REPS)
                    .map(|_| {
                        let t0 = Instant::now();
                        f();
                        t0.elapsed().as_secs_f64()
                    })
                    .collect(),
            )
        };
        let opts = BuildOptions::default();
        let ours_b2 = wall_build(&mut || {
            black_box(KdTree::build_with(points.clone(), opts).expect("finite"));
        });
        let ours_b1 = one.install(|| {
            wall_build(&mut || {
                black_box(KdTree::build_with(points.clone(), opts).expect("finite"));
            })
        });
        let ph = photons(&points);
        let ph_b2 = wall_build(&mut || {
            black_box(KdTree::build(ph.clone()).expect("finite"));
        });
        let rr = BuildOptions {
            split_axis: SplitAxis::RoundRobin,
            ..opts
        };
        let rr_b2 = wall_build(&mut || {
            black_box(KdTree::build_with(points.clone(), rr).expect("finite"));
        });
        let kiddo_b2 = wall_build(&mut || {
            black_box(Kiddo::new_from_slice(&points).expect("kiddo build"));
        });
        let kiddo_b1 = one.install(|| {
            wall_build(&mut || {
                black_box(Kiddo::new_from_slice(&points).expect("kiddo build"));
            })
        });
        // (The clone of the input is inside our timing — our build takes ownership; kiddo's
        // borrows. It is ~1 ms for 12 MB.)

        let ours = KdTree::build_with(points.clone(), opts).expect("finite");
        let ours_rr = KdTree::build_with(points.clone(), rr).expect("finite");
        let ours_ph = KdTree::build(ph).expect("finite");
        let kd = Kiddo::new_from_slice(&points).expect("kiddo build");
        eprintln!(
            "  ours: depth {}, {:.1} bytes/point ([f32;3]), {:.1} bytes/photon (Photon)",
            ours.depth(),
            ours.memory_bytes() as f64 / N as f64,
            ours_ph.memory_bytes() as f64 / N as f64
        );

        let qps = |secs: f64| QUERIES as f64 / secs / 1e3;
        let mut rows: Vec<(String, f64, f64, [f64; 3], f64)> = Vec::new();
        let mut results = Vec::new();
        for (label, b2, b1) in [
            ("ours [f32;3]", ours_b2, ours_b1),
            ("ours [f32;3] round-robin", rr_b2, f64::NAN),
            ("ours Photon (24 B)", ph_b2, f64::NAN),
            ("kiddo ImmutableKdTree", kiddo_b2, kiddo_b1),
        ] {
            let mut speeds = [0.0; 3];
            let mut found = 0.0;
            let mut res = Vec::new();
            for (i, k) in [50usize, 200, 0].into_iter().enumerate() {
                let (cpu, wall, r) = match (label, k) {
                    ("ours [f32;3]", 0) => time(|| ours_within(&ours, &queries, fixed_r2)),
                    ("ours [f32;3]", k) => time(|| ours_knn(&ours, &queries, k, knn_r2)),
                    ("ours [f32;3] round-robin", 0) => {
                        time(|| ours_within(&ours_rr, &queries, fixed_r2))
                    }
                    ("ours [f32;3] round-robin", k) => {
                        time(|| ours_knn(&ours_rr, &queries, k, knn_r2))
                    }
                    ("ours Photon (24 B)", 0) => time(|| ours_within(&ours_ph, &queries, fixed_r2)),
                    ("ours Photon (24 B)", k) => time(|| ours_knn(&ours_ph, &queries, k, knn_r2)),
                    (_, 0) => time(|| kiddo_within(&kd, &queries, fixed_r2)),
                    (_, k) => time(|| kiddo_knn(&kd, &queries, k, knn_r2)),
                };
                eprintln!(
                    "  {label} {}: wall {:.1} kq/s",
                    if k == 0 {
                        "radius".into()
                    } else {
                        format!("k={k}")
                    },
                    qps(wall)
                );
                speeds[i] = qps(cpu);
                if k == 0 {
                    found = r.0 as f64 / QUERIES as f64;
                }
                res.push(r);
            }
            results.push(res);
            rows.push((label.to_string(), b2, b1, speeds, found));
        }
        for (i, what) in ["k=50", "k=200", "radius"].iter().enumerate() {
            agree(what, results[0][i], results[3][i]);
            agree(&format!("{what} (Photon)"), results[2][i], results[3][i]);
        }
        let f = |x: f64| {
            if x.is_nan() {
                "—".to_string()
            } else {
                format!("{x:.3}")
            }
        };
        for (label, b2, b1, s, found) in &rows {
            println!(
                "| {name} | {label} | {} | {} | {:.0} | {:.0} | {:.0} ({found:.1}) |",
                f(*b2),
                f(*b1),
                s[0],
                s[1],
                s[2]
            );
        }
        let (o, k) = (&rows[0], &rows[3]);
        println!(
            "| {name} | **ours / kiddo** | {:.2}× time | {:.2}× time | {:.2}× speed | {:.2}× speed | {:.2}× speed |",
            o.1 / k.1,
            o.2 / k.2,
            o.3[0] / k.3[0],
            o.3[1] / k.3[1],
            o.3[2] / k.3[2]
        );
    }
}

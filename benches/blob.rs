//! Ray-casting benchmark on the "bumpy blob" workload (docs/performance.md, "The blob workload"), timed
//! as that text prescribes (chunks of 4096 rays from an atomic counter, medians of 5), so the
//! figures compare with Embree 3.13's `rtcIntersect1` / `rtcOccluded1` on the same machine kind.
//!
//! Run: `cargo bench --bench blob` (both meshes) or `cargo bench --bench blob -- blob100k`.
//! Options: `--threads=1,2` (default both), `--reps=5` (default 5; 1 for a quick run, e.g. under
//! `valgrind --tool=callgrind`, where instruction counts compare variants deterministically).

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use caustic::accel::RayBoxTest;
use caustic::accel::bvh::LEAF_BLOCK;
use caustic::bench::blob::{BlobMesh, WorkloadRay, blob_mesh, primary_rays, secondary_rays};
use caustic::geometry::Ray;
use caustic::geometry::triangle::{TriRay, intersect_pack_k};
use caustic::render_scene::geometry::{Geometry, GeometryBuilder, TriAttrs};
use glam::{Vec2, Vec3};

const DEFAULT_REPS: usize = 5;
const CHUNK: usize = 4096;

/// Embree 3.13 on a 2-vCPU Zen 3 (blob-workload.md): (mesh, threads) → primary, secondary closest,
/// secondary any-hit (Mrays/s), build (s).
const EMBREE: [(&str, usize, f64, f64, f64, f64); 4] = [
    ("blob100k", 1, 9.02, 6.12, 6.54, 0.184),
    ("blob100k", 2, 17.61, 12.04, 12.95, 0.093),
    ("blob1m", 1, 7.32, 4.84, 5.10, 1.484),
    ("blob1m", 2, 13.27, 9.17, 9.72, 0.730),
];

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

fn builder(mesh: &BlobMesh) -> GeometryBuilder {
    let mut b = GeometryBuilder::default();
    for t in &mesh.triangles {
        b.triangles
            .push(t.map(|i| Vec3::from(mesh.positions[i as usize])));
        b.tri_attrs.push(TriAttrs {
            object: 0,
            normals: None,
            uvs: [Vec2::ZERO; 3],
        });
    }
    b
}

fn ray_of(r: &WorkloadRay) -> Ray {
    Ray::new(Vec3::from(r.origin), Vec3::from(r.dir))
}

/// CPU time this thread has run, in seconds (Linux `schedstat`; 0 where unavailable). Unlike the
/// wall clock it does not count time the thread waited for the CPU, so A/B comparisons on a
/// shared machine are steadier.
fn thread_cpu_secs() -> f64 {
    std::fs::read_to_string("/proc/thread-self/schedstat")
        .ok()
        .and_then(|s| s.split_whitespace().next()?.parse::<u64>().ok())
        .map_or(0.0, |ns| ns as f64 * 1e-9)
}

/// Total CPU seconds of the worker threads of the last timed pass (see [`thread_cpu_secs`]).
static CPU_NS: AtomicUsize = AtomicUsize::new(0);

/// Runs `f(i)` for every ray index on `threads` OS threads taking chunks from a shared counter
/// (one thread: the calling thread, so a profiler attributes the work to the caller);
/// returns the elapsed seconds.
fn timed<F: Fn(usize) + Sync>(n: usize, threads: usize, f: F) -> f64 {
    let next = AtomicUsize::new(0);
    CPU_NS.store(0, Ordering::Relaxed);
    let work = || {
        let _cpu = CpuTimer(thread_cpu_secs());
        loop {
            let begin = next.fetch_add(CHUNK, Ordering::Relaxed);
            if begin >= n {
                break;
            }
            for i in begin..(begin + CHUNK).min(n) {
                f(i);
            }
        }
    };
    let start = Instant::now();
    if threads <= 1 {
        work();
    } else {
        std::thread::scope(|s| {
            for _ in 0..threads {
                s.spawn(work);
            }
        });
    }
    start.elapsed().as_secs_f64()
}

/// Adds the thread's CPU time since construction to [`CPU_NS`] when dropped.
struct CpuTimer(f64);

impl Drop for CpuTimer {
    fn drop(&mut self) {
        let ns = ((thread_cpu_secs() - self.0) * 1e9) as usize;
        CPU_NS.fetch_add(ns, Ordering::Relaxed);
    }
}

fn cpu_secs() -> f64 {
    CPU_NS.load(Ordering::Relaxed) as f64 * 1e-9
}

/// Primary rays, closest hit (a separate function so that a profiler reports each ray kind; the
/// `black_box` keeps the linker from merging it with [`trace_secondary`]).
#[inline(never)]
fn trace_primary(
    g: &Geometry,
    rays: &[WorkloadRay],
    threads: usize,
) -> (f64, Vec<Option<(f32, u32)>>) {
    std::hint::black_box(1);
    closest(g, rays, threads)
}

/// Secondary rays, closest hit.
#[inline(never)]
fn trace_secondary(
    g: &Geometry,
    rays: &[WorkloadRay],
    threads: usize,
) -> (f64, Vec<Option<(f32, u32)>>) {
    std::hint::black_box(2);
    closest(g, rays, threads)
}

fn closest(g: &Geometry, rays: &[WorkloadRay], threads: usize) -> (f64, Vec<Option<(f32, u32)>>) {
    let results: Vec<std::sync::atomic::AtomicU64> = (0..rays.len())
        .map(|_| std::sync::atomic::AtomicU64::new(u64::MAX))
        .collect();
    let secs = timed(rays.len(), threads, |i| {
        if let Some(h) = g.intersect(&ray_of(&rays[i])) {
            let packed = (u64::from(h.t.to_bits()) << 32) | h.prim.index() as u64;
            results[i].store(packed, Ordering::Relaxed);
        }
    });
    let hits = results
        .iter()
        .map(|a| {
            let v = a.load(Ordering::Relaxed);
            (v != u64::MAX).then(|| (f32::from_bits((v >> 32) as u32), (v & 0xFFFF_FFFF) as u32))
        })
        .collect();
    (secs, hits)
}

#[inline(never)]
fn any_hit(g: &Geometry, rays: &[WorkloadRay], threads: usize) -> (f64, usize) {
    let count = AtomicUsize::new(0);
    let secs = timed(rays.len(), threads, |i| {
        if g.occluded(&ray_of(&rays[i])) {
            count.fetch_add(1, Ordering::Relaxed);
        }
    });
    (secs, count.into_inner())
}

/// The value of `--name=value` among the arguments, if given.
fn option(name: &str) -> Option<String> {
    let prefix = format!("--{name}=");
    std::env::args().find_map(|a| a.strip_prefix(&prefix).map(str::to_owned))
}

/// Mean leaves visited and triangle packs tested per ray by closest-hit queries (for `--stats`).
fn leaf_visits(g: &Geometry, rays: &[WorkloadRay]) -> (f64, f64) {
    let (mut leaves, mut packs) = (0usize, 0usize);
    for r in rays {
        let ray = ray_of(r);
        let tri = TriRay::new(&ray);
        let boxes = RayBoxTest::new(ray.origin, ray.dir);
        g.bvh.closest(&boxes, ray.t_max, |first, count, t_max| {
            leaves += 1;
            let mut best: Option<f32> = None;
            for p in
                first as usize / LEAF_BLOCK..(first + count).div_ceil(LEAF_BLOCK as u32) as usize
            {
                packs += 1;
                let pack = &g.tri_packs[p];
                let t = best.unwrap_or(t_max);
                let h = match tri.dominant_axis() {
                    0 => intersect_pack_k::<0>(&tri, pack, t),
                    1 => intersect_pack_k::<1>(&tri, pack, t),
                    _ => intersect_pack_k::<2>(&tri, pack, t),
                };
                let Some(h) = h else { continue };
                for lane in 0..LEAF_BLOCK {
                    if h.mask & (1 << lane) != 0 && best.is_none_or(|b| h.t[lane] < b) {
                        best = Some(h.t[lane]);
                    }
                }
            }
            best
        });
    }
    let n = rays.len().max(1) as f64;
    (leaves as f64 / n, packs as f64 / n)
}

fn main() {
    let filter: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| !a.starts_with("--"))
        .collect();
    let reps = option("reps")
        .and_then(|r| r.parse().ok())
        .unwrap_or(DEFAULT_REPS)
        .max(1);
    let thread_counts: Vec<usize> = option("threads").map_or(vec![1, 2], |t| {
        t.split(',').filter_map(|n| n.parse().ok()).collect()
    });
    println!(
        "| mesh | threads | build s | primary Mrays/s | secondary closest | secondary any-hit | vs Embree (prim / sec / any / build) |"
    );
    println!("|---|---|---|---|---|---|---|");
    for (name, k) in [("blob100k", 71u32), ("blob1m", 224)] {
        if !filter.is_empty() && !filter.iter().any(|f| name.contains(f.as_str())) {
            continue;
        }
        let mesh = blob_mesh(k);
        let mut build_times = Vec::new();
        let mut geometry = None;
        for _ in 0..reps {
            let b = builder(&mesh);
            let t0 = Instant::now();
            let g = b.build();
            build_times.push(t0.elapsed().as_secs_f64());
            geometry = Some(g);
        }
        let Some(g) = geometry else { return };
        let build = median(build_times);
        // The triangles in leaf order, as a mesh, so secondary rays use the hit triangle's vertices.
        let leaf_mesh = BlobMesh {
            positions: g
                .triangles
                .iter()
                .flat_map(|t| t.map(|p| p.to_array()))
                .collect(),
            normals: Vec::new(),
            triangles: (0..g.triangles.len() as u32)
                .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
                .collect(),
        };
        let primary = primary_rays();
        let (_, hits) = trace_primary(&g, &primary, 1);
        let hit_count = hits.iter().flatten().count();
        let t_sum: f64 = hits.iter().flatten().map(|h| f64::from(h.0)).sum();
        let secondary = secondary_rays(&leaf_mesh, &primary, &hits);
        let (_, sec_hits) = trace_secondary(&g, &secondary, 1);
        let sec_count = sec_hits.iter().flatten().count();
        let sec_sum: f64 = sec_hits.iter().flatten().map(|h| f64::from(h.0)).sum();
        let (_, occluded) = any_hit(&g, &secondary, 1);
        if std::env::args().any(|a| a == "--stats") {
            let (pl, pp) = leaf_visits(&g, &primary);
            let (sl, sp) = leaf_visits(&g, &secondary);
            eprintln!(
                "{name}: per ray, leaves visited / packs tested: primary {pl:.2} / {pp:.2}, secondary {sl:.2} / {sp:.2}"
            );
        }
        let bs = g.bvh.stats();
        eprintln!(
            "{name}: bvh {} nodes, {} leaves (mean {:.2} prims), depth {}, SAH {:.1}, stack {}",
            bs.nodes,
            bs.leaves,
            g.triangles.len() as f64 / bs.leaves as f64,
            bs.max_depth,
            bs.sah_cost,
            g.bvh.stack_need()
        );
        eprintln!(
            "{name}: {} triangles; primary hits {hit_count} (sum t {t_sum:.2}); secondary {} rays, hits {sec_count} (sum t {sec_sum:.2}), occluded {occluded}",
            g.triangles.len(),
            secondary.len()
        );
        for &threads in &thread_counts {
            let mut cpu = [Vec::new(), Vec::new(), Vec::new()];
            let prim = median(
                (0..reps)
                    .map(|_| {
                        let s = trace_primary(&g, &primary, threads).0;
                        cpu[0].push(cpu_secs());
                        s
                    })
                    .collect(),
            );
            let sec = median(
                (0..reps)
                    .map(|_| {
                        let s = trace_secondary(&g, &secondary, threads).0;
                        cpu[1].push(cpu_secs());
                        s
                    })
                    .collect(),
            );
            let any = median(
                (0..reps)
                    .map(|_| {
                        let s = any_hit(&g, &secondary, threads).0;
                        cpu[2].push(cpu_secs());
                        s
                    })
                    .collect(),
            );
            let [c0, c1, c2] = cpu.map(median);
            if threads == 1 && c0 > 0.0 {
                eprintln!(
                    "{name}: 1 thread, rays per CPU second (Mrays/s): primary {:.3}, secondary closest {:.3}, any-hit {:.3}",
                    primary.len() as f64 / c0 / 1e6,
                    secondary.len() as f64 / c1 / 1e6,
                    secondary.len() as f64 / c2 / 1e6
                );
            }
            let mr = |n: usize, s: f64| n as f64 / s / 1e6;
            let (p, s, a) = (
                mr(primary.len(), prim),
                mr(secondary.len(), sec),
                mr(secondary.len(), any),
            );
            let e = EMBREE.iter().find(|e| e.0 == name && e.1 == threads);
            let ratio = e.map_or(String::new(), |e| {
                format!(
                    "{:.0}% / {:.0}% / {:.0}% / {:.2}×",
                    100.0 * p / e.2,
                    100.0 * s / e.3,
                    100.0 * a / e.4,
                    build / e.5
                )
            });
            let b = if threads == 1 {
                format!("{build:.3}")
            } else {
                "—".into()
            };
            println!("| {name} | {threads} | {b} | {p:.2} | {s:.2} | {a:.2} | {ratio} |");
        }
    }
}

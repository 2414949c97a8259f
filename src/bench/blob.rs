//! The "bumpy blob" ray-casting workload (docs/performance.md, "The blob workload"): mesh and rays, bit-exact to its definition.
//!
//! Choices the text leaves open:
//! - Icosahedron: the 12 vertices `(±1, ±φ, 0)`, `(0, ±1, ±φ)`, `(±φ, 0, ±1)` normalised, with the vertex and face
//!   order of A. Kahler's "Creating an icosphere mesh in code" (first vertex `(-1, φ, 0)`, first face `0 11 5`).
//! - Grid point with integer barycentric weights `(a, b, c)` (sum `k`) on face `(A, B, C)`:
//!   `((A*a + B*b) + C*c) / k` per component, then divided by its length. A point on an icosahedron edge is
//!   always computed from the edge's two corners in increasing corner index, `(P*(k-m) + Q*m) / k`, so both faces
//!   share it. Vertex order: the 12 corners, then per face the edges not yet seen, then the face's interior points.
//! - OBJ text: [`blob_mesh`] formats each displaced f64 coordinate with Rust's `{}` (shortest string that round-trips
//!   the f64) and parses that string with `str::parse::<f32>`. [`write_obj`] writes the stored f32 with `{}`
//!   (shortest string that round-trips the f32), which parses back to the identical f32.
//! - Normals: sum of `cross(v1 - v0, v2 - v0)` of the adjacent triangles (f32 positions in f64), normalised.
//!
//! Check against the text's figures with a simple BVH and an f64 Möller–Trumbore test (two-sided): blob100k gives
//! 616,180 primary hits, sum t 1732141.82 (text: .81), and 46,699 secondary hits, sum t 8714.66 (text: .67); blob1m
//! gives 616,412 primary hits (sum t 1732795.36, text .28) and 46,749 secondary hits (text 46,753), the gap being
//! the edge-grazing rays on which intersectors differ.

use std::collections::HashMap;
use std::f64::consts::PI;
use std::fmt::Write as _;
use std::io::Write;

/// A triangle mesh of the blob: positions as read back from its OBJ text (f32), faces 0-based.
pub struct BlobMesh {
    /// Vertex positions, as parsed back from the OBJ text.
    pub positions: Vec<[f32; 3]>,
    /// Area-weighted unit vertex normals (written as `vn`, unused by the benchmark).
    pub normals: Vec<[f32; 3]>,
    /// Triangles as 0-based vertex indices; `cross(v1 - v0, v2 - v0)` points outward.
    pub triangles: Vec<[u32; 3]>,
}

/// One ray of the workload: origin and direction (f32), tnear = 0, tfar = +inf implied.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct WorkloadRay {
    /// Ray origin.
    pub origin: [f32; 3],
    /// Ray direction (unit length up to f32 rounding).
    pub dir: [f32; 3],
}

/// Image width and height of the primary ray grid.
const SIZE: u32 = 1024;
/// The camera position of the primary rays.
const EYE: [f64; 3] = [0.0, 0.0, 3.5];
const SEED: u64 = 0x0123_4567_89AB_CDEF;
const GAMMA: u64 = 0x9E37_79B9_7F4A_7C15;

#[rustfmt::skip]
const ICO_FACES: [[usize; 3]; 20] = [
    [0, 11, 5], [0, 5, 1], [0, 1, 7], [0, 7, 10], [0, 10, 11],
    [1, 5, 9], [5, 11, 4], [11, 10, 2], [10, 7, 6], [7, 1, 8],
    [3, 9, 4], [3, 4, 2], [3, 2, 6], [3, 6, 8], [3, 8, 9],
    [4, 9, 5], [2, 4, 11], [6, 2, 10], [8, 6, 7], [9, 8, 1],
];

fn normalize(p: [f64; 3]) -> [f64; 3] {
    let len = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
    [p[0] / len, p[1] / len, p[2] / len]
}

fn icosahedron() -> [[f64; 3]; 12] {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    #[rustfmt::skip]
    let v = [
        [-1.0, t, 0.0], [1.0, t, 0.0], [-1.0, -t, 0.0], [1.0, -t, 0.0],
        [0.0, -1.0, t], [0.0, 1.0, t], [0.0, -1.0, -t], [0.0, 1.0, -t],
        [t, 0.0, -1.0], [t, 0.0, 1.0], [-t, 0.0, -1.0], [-t, 0.0, 1.0],
    ];
    v.map(normalize)
}

/// Accumulates vertices: displaces a unit-sphere point, round-trips it through its OBJ text, stores the f32.
struct Builder {
    positions: Vec<[f32; 3]>,
    text: String,
}

impl Builder {
    fn push(&mut self, u: [f64; 3]) -> u32 {
        let f = 1.0 + 0.15 * (7.0 * u[0]).sin() * (9.0 * u[1]).sin() * (11.0 * u[2]).sin();
        let p = u.map(|c| {
            self.text.clear();
            write!(self.text, "{}", c * f).expect("formatting into a String cannot fail");
            self.text
                .parse::<f32>()
                .expect("Display output of an f64 parses")
        });
        self.positions.push(p);
        (self.positions.len() - 1) as u32
    }
}

/// Builds the blob with `k` subdivisions per icosahedron edge (224 → blob1m, 71 → blob100k).
pub fn blob_mesh(k: u32) -> BlobMesh {
    assert!(k >= 1, "k must be at least 1");
    let corners = icosahedron();
    let kf = f64::from(k);
    let n = k as usize;
    let mut b = Builder {
        positions: Vec::with_capacity(10 * n * n + 2),
        text: String::new(),
    };
    for c in corners {
        b.push(c);
    }
    // Edge (p, q) with p < q: index of the point with weight m on q (1..k) is base + m - 1.
    let mut edges: HashMap<(usize, usize), u32> = HashMap::new();
    let mut triangles = Vec::with_capacity(20 * n * n);
    let mut grid = vec![0u32; (n + 1) * (n + 2) / 2];
    for face in ICO_FACES {
        let [pa, pb, pc] = face.map(|i| corners[i]);
        let mut edge_vertex = |x: usize, y: usize, wy: u32, b: &mut Builder| -> u32 {
            let (p, q, m) = if x < y { (x, y, wy) } else { (y, x, k - wy) };
            let base = *edges.entry((p, q)).or_insert_with(|| {
                let (cp, cq) = (corners[p], corners[q]);
                let first = b.positions.len() as u32;
                for m in 1..k {
                    let (wp, wq) = (f64::from(k - m), f64::from(m));
                    b.push(normalize(std::array::from_fn(|c| {
                        (cp[c] * wp + cq[c] * wq) / kf
                    })));
                }
                first
            });
            base + m - 1
        };
        // Row r (0..=k) goes from A towards BC; column s (0..=r) from the AB edge towards the AC edge.
        for r in 0..=k {
            for s in 0..=r {
                let (wa, wb, wc) = (k - r, r - s, s);
                let id = match (wa, wb, wc) {
                    _ if wa == k => face[0] as u32,
                    _ if wb == k => face[1] as u32,
                    _ if wc == k => face[2] as u32,
                    (_, _, 0) => edge_vertex(face[0], face[1], wb, &mut b),
                    (0, _, _) => edge_vertex(face[1], face[2], wc, &mut b),
                    (_, 0, _) => edge_vertex(face[2], face[0], wa, &mut b),
                    _ => {
                        let (fa, fb, fc) = (f64::from(wa), f64::from(wb), f64::from(wc));
                        b.push(normalize(std::array::from_fn(|c| {
                            (pa[c] * fa + pb[c] * fb + pc[c] * fc) / kf
                        })))
                    }
                };
                grid[(r * (r + 1) / 2 + s) as usize] = id;
            }
        }
        let at = |r: u32, s: u32| grid[(r * (r + 1) / 2 + s) as usize];
        for r in 0..k {
            for s in 0..=r {
                triangles.push([at(r, s), at(r + 1, s), at(r + 1, s + 1)]);
                if s < r {
                    triangles.push([at(r, s), at(r + 1, s + 1), at(r, s + 1)]);
                }
            }
        }
    }
    let normals = vertex_normals(&b.positions, &triangles);
    BlobMesh {
        positions: b.positions,
        normals,
        triangles,
    }
}

fn f64s(p: [f32; 3]) -> [f64; 3] {
    p.map(f64::from)
}

fn cross(e1: [f64; 3], e2: [f64; 3]) -> [f64; 3] {
    [
        e1[1] * e2[2] - e1[2] * e2[1],
        e1[2] * e2[0] - e1[0] * e2[2],
        e1[0] * e2[1] - e1[1] * e2[0],
    ]
}

/// Unnormalised geometric normal `cross(v1 - v0, v2 - v0)` of a triangle, from its f32 vertices promoted to f64.
fn face_normal(positions: &[[f32; 3]], tri: [u32; 3]) -> [f64; 3] {
    let [v0, v1, v2] = tri.map(|i| f64s(positions[i as usize]));
    cross(
        std::array::from_fn(|c| v1[c] - v0[c]),
        std::array::from_fn(|c| v2[c] - v0[c]),
    )
}

fn vertex_normals(positions: &[[f32; 3]], triangles: &[[u32; 3]]) -> Vec<[f32; 3]> {
    let mut acc = vec![[0.0f64; 3]; positions.len()];
    for &tri in triangles {
        let n = face_normal(positions, tri);
        for i in tri {
            let a = &mut acc[i as usize];
            *a = std::array::from_fn(|c| a[c] + n[c]);
        }
    }
    acc.into_iter()
        .map(|a| normalize(a).map(|c| c as f32))
        .collect()
}

/// Writes the mesh as OBJ text (`v`, `vn`, `f a//a b//b c//c`, 1-based) exactly as the workload says.
///
/// Coordinates are written with `{}` (the shortest text that parses back to the identical f32).
pub fn write_obj(mesh: &BlobMesh, out: &mut impl Write) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(out);
    writeln!(w, "# bumpy blob (shared/bench/blob-workload.md)")?;
    for [x, y, z] in &mesh.positions {
        writeln!(w, "v {x} {y} {z}")?;
    }
    for [x, y, z] in &mesh.normals {
        writeln!(w, "vn {x} {y} {z}")?;
    }
    for t in &mesh.triangles {
        let [a, b, c] = t.map(|i| i + 1);
        writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
    }
    w.flush()
}

/// The 1024×1024 primary rays in pixel order (index = y*1024 + x).
pub fn primary_rays() -> Vec<WorkloadRay> {
    let th = (((40.0 * PI) / 180.0) / 2.0).tan();
    let size = f64::from(SIZE);
    let origin = EYE.map(|c| c as f32);
    let mut rays = Vec::with_capacity((SIZE * SIZE) as usize);
    for y in 0..SIZE {
        let v = (1.0 - (2.0 * (f64::from(y) + 0.5)) / size) * th;
        for x in 0..SIZE {
            let u = ((2.0 * (f64::from(x) + 0.5)) / size - 1.0) * th * 1.0;
            let inv = 1.0 / (u * u + v * v + 1.0).sqrt();
            let dir = [(u * inv) as f32, (v * inv) as f32, (-inv) as f32];
            rays.push(WorkloadRay { origin, dir });
        }
    }
    rays
}

/// Secondary rays, one per primary hit in increasing pixel order. `hits[i]` is the closest hit of primary ray i as
/// (t, triangle index) or None. Uses the mesh's f32 positions promoted to f64, as the text says.
pub fn secondary_rays(
    mesh: &BlobMesh,
    primaries: &[WorkloadRay],
    hits: &[Option<(f32, u32)>],
) -> Vec<WorkloadRay> {
    assert_eq!(primaries.len(), hits.len(), "one hit slot per primary ray");
    let mut rays = Vec::new();
    for (i, (ray, hit)) in primaries.iter().zip(hits).enumerate() {
        let Some((t, prim)) = *hit else { continue };
        let (org, d) = (f64s(ray.origin), f64s(ray.dir));
        let n = face_normal(&mesh.positions, mesh.triangles[prim as usize]);
        let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
        let sgn = if n[0] * d[0] + n[1] * d[1] + n[2] * d[2] > 0.0 {
            -1.0
        } else {
            1.0
        };
        let scale = sgn / len;
        let n = n.map(|c| c * scale);
        let t = f64::from(t);
        let o: [f64; 3] = std::array::from_fn(|c| (org[c] + t * d[c]) + 1e-4 * n[c]);

        let (u1, u2) = (uniform_at(2 * i as u64 + 1), uniform_at(2 * i as u64 + 2));
        let r = u1.sqrt();
        let phi = (2.0 * PI) * u2;
        let (lx, ly, lz) = (r * phi.cos(), r * phi.sin(), 0f64.max(1.0 - u1).sqrt());

        let s = 1f64.copysign(n[2]);
        let a = -1.0 / (s + n[2]);
        let b = n[0] * n[1] * a;
        let t1 = [1.0 + s * n[0] * n[0] * a, s * b, -s * n[0]];
        let t2 = [b, s + n[1] * n[1] * a, -n[1]];
        let dir: [f64; 3] = std::array::from_fn(|c| (lx * t1[c] + ly * t2[c]) + lz * n[c]);
        rays.push(WorkloadRay {
            origin: o.map(|c| c as f32),
            dir: dir.map(|c| c as f32),
        });
    }
    rays
}

/// splitmix64's output function (wrapping u64 arithmetic).
fn mix(mut z: u64) -> u64 {
    z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
    z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
    z ^ (z >> 31)
}

/// The splitmix64 draw for counter value k (the text's `mix(0x0123456789ABCDEF + k*0x9E3779B97F4A7C15)`), as f64 in [0,1).
pub fn uniform_at(k: u64) -> f64 {
    let bits = mix(SEED.wrapping_add(k.wrapping_mul(GAMMA))) >> 11;
    bits as f64 * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }

    fn counts(k: u32) -> [usize; 3] {
        let m = blob_mesh(k);
        [m.positions.len(), m.normals.len(), m.triangles.len()]
    }

    #[test]
    fn counts_blob100k() {
        assert_eq!(counts(71), [50_412, 50_412, 100_820]);
    }

    #[test] // about 1.5 s in an unoptimised debug build, so not #[ignore]d
    fn counts_blob1m() {
        assert_eq!(counts(224), [501_762, 501_762, 1_003_520]);
    }

    #[test]
    fn outward_watertight_and_consistent() {
        for k in [1, 2, 5, 71] {
            let m = blob_mesh(k);
            // Each directed edge once and its reverse present: every undirected edge is used by exactly 2
            // triangles, with opposite directions (consistent orientation).
            let mut edges = std::collections::HashSet::new();
            for &tri in &m.triangles {
                let c = std::array::from_fn(|i| {
                    tri.iter()
                        .map(|&v| f64::from(m.positions[v as usize][i]))
                        .sum()
                });
                assert!(
                    dot(face_normal(&m.positions, tri), c) > 0.0,
                    "k={k}: {tri:?} faces inward"
                );
                for e in [(tri[0], tri[1]), (tri[1], tri[2]), (tri[2], tri[0])] {
                    assert!(edges.insert(e), "k={k}: directed edge {e:?} twice");
                }
            }
            assert!(
                edges.iter().all(|&(a, b)| edges.contains(&(b, a))),
                "k={k}: open edge"
            );
            for p in &m.positions {
                let r = dot(f64s(*p), f64s(*p)).sqrt();
                assert!((0.84..1.16).contains(&r), "k={k}: radius {r}");
            }
        }
    }

    #[test]
    fn primary_rays_hand_evaluated() {
        let th = (((40.0 * PI) / 180.0) / 2.0).tan();
        assert_eq!(th, 0.363_970_234_266_202_34);
        let rays = primary_rays();
        assert_eq!(rays.len(), 1 << 20);
        assert!(rays.iter().all(|r| r.origin == [0.0, 0.0, 3.5]));
        // f32 bit patterns of the text's formulas, evaluated independently in Python (f64, libm tan).
        let expect = [
            ((0, 0), [0xbea5_902f, 0x3ea5_902f, 0xbf63_a9b6]),
            ((512, 512), [0x39ba_5a4d, 0xb9ba_5a4d, 0xbf7f_fffe]),
            ((1023, 1023), [0x3ea5_902f, 0xbea5_902f, 0xbf63_a9b6]),
        ];
        for ((x, y), bits) in expect {
            let got = rays[y * 1024 + x].dir.map(f32::to_bits);
            assert_eq!(got, bits, "pixel ({x}, {y})");
        }
    }

    #[test]
    fn splitmix64_reference() {
        // splitmix64 seeded with 0 (Vigna's splitmix64.c): its first three outputs.
        let seq: Vec<u64> = (1..=3).map(|k: u64| mix(k.wrapping_mul(GAMMA))).collect();
        let reference = [
            0xe220_a839_7b1d_cdaf,
            0x6e78_9e6a_a1b9_65f4,
            0x06c4_5d18_8009_454f,
        ];
        assert_eq!(seq, reference);
        // The text's stateful generator, written out by hand: pixel i draws u1, u2 = counters 2i+1, 2i+2.
        let mut s = SEED;
        let mut next = || {
            s = s.wrapping_add(0x9E3779B97F4A7C15);
            let mut z = s;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58476D1CE4E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D049BB133111EB);
            ((z ^ (z >> 31)) >> 11) as f64 * 2f64.powi(-53)
        };
        for i in 0..1000u64 {
            let pair = (uniform_at(2 * i + 1), uniform_at(2 * i + 2));
            assert_eq!((next(), next()), pair);
        }
        assert_eq!(uniform_at(1), 0.083_896_161_905_214_43);
        assert_eq!(uniform_at(2), 0.833_790_934_459_677_4);
    }

    #[test]
    fn secondary_rays_for_hand_built_hits() {
        let one = |p: [[f32; 3]; 3]| BlobMesh {
            positions: p.to_vec(),
            normals: vec![],
            triangles: vec![[0, 1, 2]],
        };
        let prim = primary_rays();
        let i = 300 * 1024 + 700;
        let mut hits = vec![None; prim.len()];
        hits[i] = Some((3.25f32, 0));
        let d = f64s(prim[i].dir);
        let hit: [f64; 3] = std::array::from_fn(|c| EYE[c] + 3.25 * d[c]);
        let (u1, u2) = (uniform_at(2 * i as u64 + 1), uniform_at(2 * i as u64 + 2));

        // Plane z = 0, |n| = 256 (exact), facing the ray or away from it: n = +z after the turn, the basis is
        // t1 = x, t2 = y, and the direction is (lx, ly, lz) exactly.
        let (r, phi) = (u1.sqrt(), 2.0 * PI * u2);
        let want = [r * phi.cos(), r * phi.sin(), (1.0 - u1).sqrt()].map(|c| c as f32);
        let (a, b, c) = ([-8.0, -8.0, 0.0], [8.0, -8.0, 0.0], [-8.0, 8.0, 0.0]);
        for mesh in [one([a, b, c]), one([a, c, b])] {
            let rays = secondary_rays(&mesh, &prim, &hits);
            assert_eq!(rays.len(), 1);
            assert_eq!(rays[0].dir, want);
            let origin = [hit[0], hit[1], hit[2] + 1e-4].map(|c| c as f32);
            assert_eq!(rays[0].origin, origin);
        }

        // A tilted triangle: unit direction in the hemisphere of the (turned) normal, origin offset 1e-4 along it.
        let tilted = one([[0.3, -0.2, 0.9], [-0.1, 0.5, 1.4], [0.6, 0.4, 0.7]]);
        let n = face_normal(&tilted.positions, [0, 1, 2]);
        let n = n.map(|c| c * -dot(n, d).signum() / dot(n, n).sqrt());
        let ray = secondary_rays(&tilted, &prim, &hits)[0];
        let dir = f64s(ray.dir);
        assert!((dot(dir, dir).sqrt() - 1.0).abs() < 1e-6);
        assert!(dot(dir, n) >= 0.0);
        for c in 0..3 {
            assert!((f64::from(ray.origin[c]) - hit[c] - 1e-4 * n[c]).abs() < 1e-6);
        }

        // Misses drop their pair of draws: one secondary ray per hit.
        let mesh = blob_mesh(2);
        let hits: Vec<_> = (0..prim.len())
            .map(|i| (i % 3 == 0).then_some((2.5, 7)))
            .collect();
        let rays = secondary_rays(&mesh, &prim, &hits);
        assert_eq!(rays.len(), prim.len().div_ceil(3));
    }

    #[test]
    fn obj_round_trip() {
        let mesh = blob_mesh(16);
        let mut text = Vec::new();
        write_obj(&mesh, &mut text).unwrap();
        let (mut v, mut vn, mut f) = (vec![], vec![], vec![]);
        for line in String::from_utf8(text).unwrap().lines() {
            let (tag, rest) = line.split_once(' ').unwrap();
            let words = rest.split(' ');
            match tag {
                "v" => v.extend(words.map(|w| w.parse::<f32>().unwrap().to_bits())),
                "vn" => vn.extend(words.map(|w| w.parse::<f32>().unwrap())),
                "f" => f.extend(words.map(|w| {
                    let (a, b) = w.split_once("//").unwrap();
                    assert_eq!(a, b);
                    a.parse::<u32>().unwrap() - 1
                })),
                _ => assert_eq!(tag, "#"),
            }
        }
        let positions: Vec<u32> = mesh
            .positions
            .iter()
            .flatten()
            .map(|c| c.to_bits())
            .collect();
        assert_eq!(v, positions);
        assert_eq!(vn, mesh.normals.concat());
        assert_eq!(f, mesh.triangles.concat());
    }
}

//! Meshing implicit surfaces into checked, closed OBJ parts.
//!
//! A part is the zero set of a signed distance function (negative inside), sampled on a regular
//! grid and meshed by Naive Surface Nets (Gibson, "Constrained Elastic Surface Nets", 1998) via
//! the `fast-surface-nets` crate. Each vertex is then pulled onto the exact zero set by a few
//! Newton steps, given the field's normalised gradient as its normal and an octahedral uv
//! (Meyer et al., "On Floating-Point Normal Vectors", 2010) of its direction from the part's
//! centre. Everything is plain f64 arithmetic and `sqrt` (no `sin`, `exp`, `atan2`), so the
//! written text is the same on every platform.
//!
//! [`check`] refuses a mesh with a degenerate or inverted triangle, an edge not shared by exactly
//! two oppositely wound triangles, a vertex whose triangles do not form one disk, or a part
//! enclosing negative volume (wound inwards).

use std::collections::HashMap;
use std::fmt::Write as _;

use fast_surface_nets::ndshape::{RuntimeShape, Shape};
use fast_surface_nets::{SurfaceNetsBuffer, surface_nets};
use glam::DVec3;

/// A signed distance function: negative inside, zero on the surface.
pub type Sdf<'a> = &'a dyn Fn(DVec3) -> f64;

/// How to mesh one part.
pub struct PartSpec<'a> {
    /// OBJ group name.
    pub name: &'static str,
    /// The surface.
    pub sdf: Sdf<'a>,
    /// Lower and upper corner of a box containing the whole surface.
    pub bounds: (DVec3, DVec3),
    /// Grid spacing, in model units.
    pub cell: f64,
    /// Centre for the octahedral uv mapping (inside the part).
    pub centre: DVec3,
}

/// A meshed part: positions, unit normals and uvs per vertex, counter-clockwise triangles
/// seen from outside. Values are already rounded to what the OBJ text holds.
pub struct Part {
    /// OBJ group name.
    pub name: &'static str,
    /// Vertex positions.
    pub positions: Vec<DVec3>,
    /// Unit vertex normals (outward).
    pub normals: Vec<DVec3>,
    /// Texture coordinates in [0, 1]².
    pub uvs: Vec<[f64; 2]>,
    /// Triangles, indices into the vertex arrays.
    pub triangles: Vec<[u32; 3]>,
}

/// Decimal places written for positions, normals and uvs.
const POSITION_DIGITS: usize = 5;
const NORMAL_DIGITS: usize = 4;
const UV_DIGITS: usize = 4;

/// Meshes `spec` into a part (not yet checked).
pub fn mesh_part(spec: &PartSpec) -> Part {
    let (lo, hi) = spec.bounds;
    let h = spec.cell;
    // Two cells of padding on each side so the surface never touches the grid's border (surface
    // nets leaves a surface that leaves the grid open), and the grid shifted off round numbers
    // so flat faces at round heights do not pass exactly through its samples.
    let origin = lo - DVec3::new(2.0 - 0.29, 2.0 - 0.23, 2.0 - 0.17) * h;
    let n = ((hi - lo) / h).ceil().as_uvec3() + glam::UVec3::splat(5);
    let shape = RuntimeShape::<u32, 3>::new([n.x, n.y, n.z]);
    let mut grid = vec![1.0f32; shape.usize()];
    for (i, g) in grid.iter_mut().enumerate() {
        let [x, y, z] = shape.delinearize(i as u32);
        let p = origin + DVec3::new(f64::from(x), f64::from(y), f64::from(z)) * h;
        *g = (spec.sdf)(p) as f32;
    }
    let mut buf = SurfaceNetsBuffer::default();
    surface_nets(&grid, &shape, [0; 3], [n.x - 1, n.y - 1, n.z - 1], &mut buf);
    let positions: Vec<DVec3> = buf
        .positions
        .iter()
        .map(|p| {
            let q = origin + DVec3::new(f64::from(p[0]), f64::from(p[1]), f64::from(p[2])) * h;
            project(spec.sdf, q, 0.5 * h)
        })
        .map(|p| p.to_array().map(|c| round(c, POSITION_DIGITS)).into())
        .collect();
    let normals = positions
        .iter()
        .map(|&p| {
            let g = gradient(spec.sdf, p).normalize_or_zero();
            g.to_array().map(|c| round(c, NORMAL_DIGITS)).into()
        })
        .collect();
    let uvs = positions
        .iter()
        .map(|&p| octahedral(p - spec.centre).map(|c| round(c, UV_DIGITS)))
        .collect();
    let mut triangles: Vec<[u32; 3]> = buf
        .indices
        .chunks_exact(3)
        .map(|t| [t[0], t[1], t[2]])
        .collect();
    let mut part = Part {
        name: spec.name,
        positions,
        normals,
        uvs,
        triangles: Vec::new(),
    };
    // Surface nets winds its quads one way for the whole grid: make it counter-clockwise from
    // outside (positive enclosed volume). `check` verifies every triangle agrees.
    if signed_volume(&part.positions, &triangles) < 0.0 {
        for t in &mut triangles {
            t.swap(1, 2);
        }
    }
    part.triangles = triangles;
    part
}

/// Rounds to `digits` decimals the way the OBJ text will show it (and turns −0 into 0).
fn round(v: f64, digits: usize) -> f64 {
    let s = format!("{v:.digits$}");
    let r: f64 = s.parse().unwrap_or(v);
    if r == 0.0 { 0.0 } else { r }
}

/// Central-difference gradient of `f` at `p`.
pub fn gradient(f: Sdf, p: DVec3) -> DVec3 {
    let e = 1e-6;
    DVec3::new(
        f(p + DVec3::X * e) - f(p - DVec3::X * e),
        f(p + DVec3::Y * e) - f(p - DVec3::Y * e),
        f(p + DVec3::Z * e) - f(p - DVec3::Z * e),
    ) / (2.0 * e)
}

/// Newton steps from `p` towards the zero set of `f`, moving at most `limit` in all (so a
/// vertex of a thin part never jumps to the far side).
fn project(f: Sdf, p: DVec3, limit: f64) -> DVec3 {
    let mut q = p;
    for _ in 0..4 {
        let g = gradient(f, q);
        let g2 = g.length_squared();
        if g2 < 1e-12 {
            break;
        }
        let next = q - g * (f(q) / g2);
        if (next - p).length() > limit {
            break;
        }
        q = next;
    }
    q
}

/// Octahedral map of a direction to [0, 1]²: continuous over the whole sphere.
fn octahedral(d: DVec3) -> [f64; 2] {
    let l1 = d.x.abs() + d.y.abs() + d.z.abs();
    if l1 == 0.0 {
        return [0.5, 0.5];
    }
    let p = d / l1;
    let (mut u, mut v) = (p.x, p.z);
    if p.y < 0.0 {
        let (ou, ov) = (u, v);
        u = (1.0 - ov.abs()) * if ou >= 0.0 { 1.0 } else { -1.0 };
        v = (1.0 - ou.abs()) * if ov >= 0.0 { 1.0 } else { -1.0 };
    }
    [0.5 * (u + 1.0), 0.5 * (v + 1.0)]
}

/// Six times the signed volume enclosed by the triangles (positive when wound outwards).
pub fn signed_volume(p: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| p[i as usize]);
            a.dot(b.cross(c))
        })
        .sum()
}

/// Checks a part: every index in range; no degenerate triangle (area below 1e-12 of the
/// part's size squared, or a repeated vertex); no inverted triangle (its geometric normal
/// against the mean of its vertex normals); every edge shared by exactly two triangles wound
/// oppositely (closed and consistently oriented); each vertex's triangles form one disk (a
/// manifold); positive enclosed volume (outward). Returns every problem found, as sentences.
pub fn check(part: &Part) -> Result<(), Vec<String>> {
    let mut problems = Vec::new();
    let name = part.name;
    let nv = part.positions.len();
    if part.normals.len() != nv || part.uvs.len() != nv {
        problems.push(format!("{name}: attribute counts differ"));
    }
    if part.triangles.is_empty() {
        problems.push(format!("{name}: no triangles"));
    }
    let (lo, hi) = part.positions.iter().fold(
        (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    let size2 = (hi - lo).length_squared();
    let mut directed: HashMap<(u32, u32), u32> = HashMap::new();
    for (i, t) in part.triangles.iter().enumerate() {
        if t.iter().any(|&k| k as usize >= nv) {
            problems.push(format!("{name}: triangle {i} has an index out of range"));
            continue;
        }
        if t[0] == t[1] || t[1] == t[2] || t[0] == t[2] {
            problems.push(format!("{name}: triangle {i} repeats a vertex {t:?}"));
            continue;
        }
        let [a, b, c] = t.map(|k| part.positions[k as usize]);
        let g = (b - a).cross(c - a);
        if g.length_squared() <= 1e-24 * size2 * size2 {
            problems.push(format!(
                "{name}: triangle {i} is degenerate (area {:e})",
                0.5 * g.length()
            ));
        }
        let n: DVec3 = t.iter().map(|&k| part.normals[k as usize]).sum();
        if g.dot(n) <= 0.0 {
            problems.push(format!(
                "{name}: triangle {i} is inverted (its winding faces against its vertex normals)"
            ));
        }
        for e in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            *directed.entry(e).or_default() += 1;
        }
    }
    for (&(a, b), &count) in &directed {
        let back = directed.get(&(b, a)).copied().unwrap_or(0);
        if count != 1 || back != 1 {
            problems.push(format!(
                "{name}: edge {a}-{b} is used {count} times this way and {back} times the other (want 1 and 1: closed and consistently wound)"
            ));
        }
    }
    // One disk per vertex: the edges opposite a vertex, b→c for each of its triangles, chain
    // into a single cycle.
    let mut link: HashMap<u32, Vec<(u32, u32)>> = HashMap::new();
    for t in &part.triangles {
        for k in 0..3 {
            link.entry(t[k])
                .or_default()
                .push((t[(k + 1) % 3], t[(k + 2) % 3]));
        }
    }
    for (&v, edges) in &link {
        let next: HashMap<u32, u32> = edges.iter().copied().collect();
        let start = edges[0].0;
        let (mut at, mut steps) = (start, 0);
        while let Some(&n) = next.get(&at) {
            steps += 1;
            at = n;
            if at == start || steps > edges.len() {
                break;
            }
        }
        if next.len() != edges.len() || at != start || steps != edges.len() {
            problems.push(format!(
                "{name}: vertex {v} is not manifold (its triangles do not form one disk)"
            ));
        }
    }
    if link.len() != nv {
        problems.push(format!(
            "{name}: {} vertices belong to no triangle",
            nv - link.len()
        ));
    }
    if signed_volume(&part.positions, &part.triangles) <= 0.0 {
        problems.push(format!(
            "{name}: encloses no positive volume (wound inwards)"
        ));
    }
    if problems.is_empty() {
        Ok(())
    } else {
        Err(problems)
    }
}

/// The parts as OBJ text: a header comment, then per part a `g` line, its vertices, normals,
/// uvs and faces (`f v/vt/vn`, 1-based, shared index per corner).
pub fn write_obj(header: &str, parts: &[Part]) -> String {
    let mut s = String::new();
    for line in header.lines() {
        let _ = writeln!(s, "# {line}");
    }
    let mut base = 1usize;
    for part in parts {
        let _ = writeln!(
            s,
            "g {}\n# {} vertices, {} triangles",
            part.name,
            part.positions.len(),
            part.triangles.len()
        );
        for p in &part.positions {
            let _ = writeln!(s, "v {:.5} {:.5} {:.5}", p.x, p.y, p.z);
        }
        for n in &part.normals {
            let _ = writeln!(s, "vn {:.4} {:.4} {:.4}", n.x, n.y, n.z);
        }
        for t in &part.uvs {
            let _ = writeln!(s, "vt {:.4} {:.4}", t[0], t[1]);
        }
        for t in &part.triangles {
            let [a, b, c] = t.map(|k| k as usize + base);
            let _ = writeln!(s, "f {a}/{a}/{a} {b}/{b}/{b} {c}/{c}/{c}");
        }
        base += part.positions.len();
    }
    s
}

//! Triangulating a polygon by its shape: ear clipping (Meisters, "Polygons have ears", 1975) of
//! the polygon projected onto its best-fit plane, whose normal is Newell's (Sutherland, Sproull
//! and Schumacker 1974): exact for planar polygons, convex or not, and the least-squares plane's
//! orientation for slightly warped ones.

use glam::{DVec2, DVec3, Vec3};

/// A polygon's triangles and what was wrong with its shape.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Triangulation {
    /// Corner indices into the polygon, each triangle wound like the polygon.
    pub triangles: Vec<[usize; 3]>,
    /// For a polygon that is not planar: the largest distance of a corner from the best-fit
    /// plane, as a fraction of the polygon's size (the diagonal of its bounding box).
    pub non_planar: Option<f64>,
    /// The polygon's projection crosses itself (two edges that do not share a corner meet), so
    /// it has no inside to fill: the triangles cover it as well as ear clipping can.
    pub self_intersecting: bool,
}

/// Distance from the best-fit plane, as a fraction of the polygon's size, above which a polygon
/// is reported as not planar (f32 positions alone are exact to about 1e-7).
pub const PLANARITY_TOLERANCE: f64 = 1e-3;

/// Triangulates the polygon with corners `p` (in order, either winding, at least 3).
///
/// A convex polygon gets the fan from its first corner, like any OBJ loader; otherwise ears are
/// clipped from the first corner on, which leaves every notch empty. A polygon whose corners all
/// lie on a line gets the fan (its triangles are degenerate and dropped later).
#[must_use]
pub fn triangulate(p: &[Vec3]) -> Triangulation {
    let n = p.len();
    let mut out = Triangulation::default();
    if n < 3 {
        return out;
    }
    let fan = |out: &mut Triangulation| {
        out.triangles = (1..n - 1).map(|i| [0, i, i + 1]).collect();
    };
    let pd: Vec<DVec3> = p.iter().map(|v| v.as_dvec3()).collect();
    // A polygon of zero vector area (a bow tie) still has a plane: its widest corner triangle's.
    let normal = newell_normal(&pd).try_normalize().or_else(|| {
        (2..n)
            .map(|k| (pd[1] - pd[0]).cross(pd[k] - pd[0]))
            .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))
            .and_then(DVec3::try_normalize)
    });
    let Some(normal) = normal else {
        fan(&mut out);
        return out;
    };
    // Planarity, against the plane through the centroid.
    let centroid = pd.iter().sum::<DVec3>() / n as f64;
    let (lo, hi) = pd
        .iter()
        .fold((pd[0], pd[0]), |(lo, hi), q| (lo.min(*q), hi.max(*q)));
    let size = (hi - lo).length();
    let off = pd
        .iter()
        .map(|q| (*q - centroid).dot(normal).abs())
        .fold(0.0, f64::max);
    if off > PLANARITY_TOLERANCE * size {
        out.non_planar = Some(off / size);
    }
    // Projection onto the plane, made counter-clockwise (Newell's normal already follows the
    // winding; the fallback normal may not).
    let (u, mut v) = plane_basis(normal);
    let project = |v: DVec3| -> Vec<DVec2> {
        pd.iter()
            .map(|x| DVec2::new((*x - centroid).dot(u), (*x - centroid).dot(v)))
            .collect()
    };
    let mut q = project(v);
    if signed_area(&q) < 0.0 {
        v = -v;
        q = project(v);
    }
    out.self_intersecting = crosses_itself(&q);
    if n == 3 || (!out.self_intersecting && is_convex(&q)) {
        fan(&mut out);
        return out;
    }
    out.triangles = clip_ears(&q);
    out
}

/// Newell's normal: twice the polygon's vector area, pointing to the side from which the corners
/// run counter-clockwise.
fn newell_normal(p: &[DVec3]) -> DVec3 {
    let n = p.len();
    (0..n).fold(DVec3::ZERO, |acc, i| {
        let (a, b) = (p[i], p[(i + 1) % n]);
        acc + DVec3::new(
            (a.y - b.y) * (a.z + b.z),
            (a.z - b.z) * (a.x + b.x),
            (a.x - b.x) * (a.y + b.y),
        )
    })
}

/// Two unit vectors spanning the plane of unit normal `n`, with `u × v = n`.
fn plane_basis(n: DVec3) -> (DVec3, DVec3) {
    let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let u = helper.cross(n).normalize();
    (u, n.cross(u))
}

/// Twice the signed area of a 2D polygon (positive when counter-clockwise).
fn signed_area(q: &[DVec2]) -> f64 {
    (0..q.len())
        .map(|i| cross(q[i], q[(i + 1) % q.len()]))
        .sum()
}

fn cross(a: DVec2, b: DVec2) -> f64 {
    a.perp_dot(b)
}

/// True when every corner turns left (a counter-clockwise convex polygon); collinear corners
/// are allowed.
fn is_convex(q: &[DVec2]) -> bool {
    let n = q.len();
    (0..n).all(|i| {
        let (a, b, c) = (q[(i + n - 1) % n], q[i], q[(i + 1) % n]);
        cross(b - a, c - b) >= 0.0
    })
}

/// True when two edges that share no corner intersect (touching counts).
fn crosses_itself(q: &[DVec2]) -> bool {
    let n = q.len();
    for i in 0..n {
        let (a, b) = (q[i], q[(i + 1) % n]);
        for j in i + 2..n {
            if (j + 1) % n == i {
                continue;
            }
            let (c, d) = (q[j], q[(j + 1) % n]);
            if segments_meet(a, b, c, d) {
                return true;
            }
        }
    }
    false
}

/// Whether segments `ab` and `cd` have a point in common.
fn segments_meet(a: DVec2, b: DVec2, c: DVec2, d: DVec2) -> bool {
    let o = |p: DVec2, q: DVec2, r: DVec2| cross(q - p, r - p);
    let on = |p: DVec2, q: DVec2, r: DVec2| {
        r.x >= p.x.min(q.x) && r.x <= p.x.max(q.x) && r.y >= p.y.min(q.y) && r.y <= p.y.max(q.y)
    };
    let (d1, d2, d3, d4) = (o(c, d, a), o(c, d, b), o(a, b, c), o(a, b, d));
    if ((d1 > 0.0 && d2 < 0.0) || (d1 < 0.0 && d2 > 0.0))
        && ((d3 > 0.0 && d4 < 0.0) || (d3 < 0.0 && d4 > 0.0))
    {
        return true;
    }
    (d1 == 0.0 && on(c, d, a))
        || (d2 == 0.0 && on(c, d, b))
        || (d3 == 0.0 && on(a, b, c))
        || (d4 == 0.0 && on(a, b, d))
}

/// Whether `p` lies inside or on the counter-clockwise triangle `abc`.
fn in_triangle(p: DVec2, a: DVec2, b: DVec2, c: DVec2) -> bool {
    cross(b - a, p - a) >= 0.0 && cross(c - b, p - b) >= 0.0 && cross(a - c, p - c) >= 0.0
}

/// Ear clipping of a counter-clockwise polygon: repeatedly cut off a convex corner whose
/// triangle holds no other remaining corner, trying the corners from the first one on. When no
/// corner is an ear (a self-intersecting polygon) the first convex corner, or failing that the
/// first corner, is cut anyway, so the polygon is always fully triangulated.
fn clip_ears(q: &[DVec2]) -> Vec<[usize; 3]> {
    let mut idx: Vec<usize> = (0..q.len()).collect();
    let mut tris = Vec::with_capacity(q.len() - 2);
    while idx.len() > 3 {
        let m = idx.len();
        let corner = |k: usize| (idx[(k + m - 1) % m], idx[k], idx[(k + 1) % m]);
        let convex = |k: usize| {
            let (a, b, c) = corner(k);
            cross(q[b] - q[a], q[c] - q[b]) > 0.0
        };
        let ear = |k: usize| {
            let (a, b, c) = corner(k);
            convex(k)
                && idx.iter().all(|&i| {
                    i == a
                        || i == b
                        || i == c
                        || q[i] == q[a]
                        || q[i] == q[b]
                        || q[i] == q[c]
                        || !in_triangle(q[i], q[a], q[b], q[c])
                })
        };
        // Start at corner 1 so a convex run is cut as the fan from corner 0.
        let order = (1..m).chain(std::iter::once(0));
        let k = order
            .clone()
            .find(|&k| ear(k))
            .or_else(|| order.clone().find(|&k| convex(k)))
            .unwrap_or(1);
        let (a, b, c) = corner(k);
        tris.push([a, b, c]);
        idx.remove(k);
    }
    tris.push([idx[0], idx[1], idx[2]]);
    tris
}

#[cfg(test)]
mod tests {
    use super::*;

    fn area(p: &[Vec3], t: &[usize; 3]) -> f64 {
        let [a, b, c] = t.map(|i| p[i].as_dvec3());
        0.5 * (b - a).cross(c - a).length()
    }

    #[test]
    fn a_convex_polygon_gets_the_fan_from_its_first_corner() {
        let hex: Vec<Vec3> = (0..6)
            .map(|i| {
                let a = f32::from(i as u8) * std::f32::consts::PI / 3.0;
                Vec3::new(a.cos(), a.sin(), 0.0)
            })
            .collect();
        let t = triangulate(&hex);
        assert_eq!(
            t.triangles,
            vec![[0, 1, 2], [0, 2, 3], [0, 3, 4], [0, 4, 5]]
        );
        assert_eq!((t.non_planar, t.self_intersecting), (None, false));
    }

    #[test]
    fn a_concave_polygon_starting_at_a_notch_keeps_its_notch_empty() {
        // The reported "C": a 3×3 square with the 2×1 notch x ∈ [1, 3], y ∈ [1, 2] cut out of
        // its right side, written from the notch corner (3, 1). Area 9 − 2 = 7 (shoelace by hand).
        let c: Vec<Vec3> = [
            (3, 1),
            (1, 1),
            (1, 2),
            (3, 2),
            (3, 3),
            (0, 3),
            (0, 0),
            (3, 0),
        ]
        .iter()
        .map(|&(x, y)| Vec3::new(x as f32, y as f32, 0.0))
        .collect();
        let t = triangulate(&c);
        assert_eq!(t.triangles.len(), 6);
        let total: f64 = t.triangles.iter().map(|tri| area(&c, tri)).sum();
        assert!((total - 7.0).abs() < 1e-12, "{total}");
        // No triangle reaches into the notch: each triangle's centroid is outside it, and the
        // triangles' winding matches the polygon's (shoelace +7: counter-clockwise in xy).
        for tri in &t.triangles {
            let g = tri.iter().map(|&i| c[i]).sum::<Vec3>() / 3.0;
            assert!(!(g.x > 1.0 && g.y > 1.0 && g.y < 2.0), "{tri:?}");
            let [a, b, d] = tri.map(|i| c[i]);
            assert!((b - a).cross(d - a).z > 0.0, "{tri:?} winding");
        }
        assert_eq!((t.non_planar, t.self_intersecting), (None, false));
    }

    #[test]
    fn warped_and_self_intersecting_polygons_are_reported() {
        // A square with one corner lifted by 0.2 (side 1, diagonal 1.0198): non-planar.
        let warped = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.2),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let t = triangulate(&warped);
        // By hand: Newell normal (−0.2, −0.2, 2) ∝ (−0.1, −0.1, 1); centroid (0.5, 0.5, 0.05);
        // every corner is 0.05/√1.02 from that plane; the bounding box diagonal is √2.04.
        let f = t.non_planar.expect("non-planar");
        let expected = 0.05 / (1.02f64 * 2.04).sqrt();
        assert!((f - expected).abs() < 1e-6, "{f} vs {expected}");
        assert_eq!(t.triangles.len(), 2);
        // A bow tie: edges 0–1 and 2–3 cross.
        let bow = [
            Vec3::new(0.0, 0.0, 0.0),
            Vec3::new(1.0, 1.0, 0.0),
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
        ];
        let t = triangulate(&bow);
        assert!(t.self_intersecting);
        assert_eq!(t.triangles.len(), 2);
        // A collinear "polygon" has no plane: the fan, nothing reported.
        let line = [Vec3::ZERO, Vec3::X, Vec3::X * 2.0, Vec3::X * 3.0];
        let t = triangulate(&line);
        assert_eq!(t.triangles.len(), 2);
        assert_eq!((t.non_planar, t.self_intersecting), (None, false));
    }
}

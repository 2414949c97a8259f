//! Expanding a hit into the surface record shading needs (position with error bound, normals,
//! texture coordinates).

use glam::{DVec3, Vec2, Vec3};

use super::geometry::{Geometry, Hit, PrimKind};
use crate::geometry::Ray;
use crate::geometry::float::gamma;
use crate::geometry::sphere::reproject_to_sphere;
use crate::geometry::triangle::hit_point_error;

/// Everything shading needs about a hit point.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfacePoint {
    /// Position.
    pub p: Vec3,
    /// Absolute error bound of `p`, per component, for robust ray spawning.
    pub p_error: Vec3,
    /// Unit geometric normal, outward (by winding for triangles).
    pub ng: Vec3,
    /// Unit shading normal, on the same side as `ng`.
    pub ns: Vec3,
    /// Where rays leaving to the outside of a smooth-shaded triangle should start: `p` moved onto
    /// the curved surface the vertex normals describe (Hanika, "Hacking the shadow terminator",
    /// Ray Tracing Gems II ch. 4), so coarse smooth meshes do not shadow themselves in facets.
    /// Equal to `p` for everything else.
    pub p_outside: Vec3,
    /// Texture coordinates.
    pub uv: Vec2,
    /// Owning object.
    pub object: u32,
}

impl Geometry {
    /// Expands a hit of `ray` into a full surface record.
    #[must_use]
    pub fn surface(&self, ray: &Ray, hit: &Hit) -> SurfacePoint {
        match hit.prim.kind() {
            PrimKind::Triangle => {
                let [p0, p1, p2] = self.triangles[hit.prim.index()];
                let a = &self.tri_attrs[hit.prim.index()];
                let b0 = 1.0 - hit.b1 - hit.b2;
                let p = p0 * b0 + p1 * hit.b1 + p2 * hit.b2;
                let th = crate::geometry::triangle::TriHit {
                    t: hit.t,
                    b0,
                    b1: hit.b1,
                    b2: hit.b2,
                };
                let ng = (p1 - p0).cross(p2 - p0).normalize();
                let ns = match a.normals {
                    Some([n0, n1, n2]) => {
                        let n = (n0 * b0 + n1 * hit.b1 + n2 * hit.b2).normalize_or_zero();
                        if n == Vec3::ZERO {
                            ng
                        } else if n.dot(ng) < 0.0 {
                            -n
                        } else {
                            n
                        }
                    }
                    None => ng,
                };
                let uv = a.uvs[0] * b0 + a.uvs[1] * hit.b1 + a.uvs[2] * hit.b2;
                let p_outside = a.normals.map_or(p, |n| {
                    terminator_point(p, [p0, p1, p2], n, [b0, hit.b1, hit.b2])
                });
                SurfacePoint {
                    p,
                    p_outside,
                    p_error: hit_point_error(&th, p0, p1, p2),
                    ng,
                    ns,
                    uv,
                    object: a.object,
                }
            }
            PrimKind::Sphere => {
                let s = &self.spheres[hit.prim.index()];
                let c = s.center.as_dvec3();
                let raw = ray.origin.as_dvec3() + ray.dir.as_dvec3() * f64::from(hit.t);
                let pd = reproject_to_sphere(c, f64::from(s.radius), raw);
                let n = ((pd - c) / f64::from(s.radius)).as_vec3().normalize();
                let p = pd.as_vec3();
                let uv = sphere_uv(n);
                SurfacePoint {
                    p,
                    p_outside: p,
                    p_error: p.abs() * gamma(2),
                    ng: n,
                    ns: n,
                    uv,
                    object: s.object,
                }
            }
            PrimKind::Ellipsoid => {
                let e = &self.ellipsoids[hit.prim.index()];
                let o = e.object_from_world.transform_point3(ray.origin.as_dvec3());
                let d = e.object_from_world.transform_vector3(ray.dir.as_dvec3());
                let po = reproject_to_sphere(DVec3::ZERO, 1.0, o + d * f64::from(hit.t));
                let pd = e.world_from_object.transform_point3(po);
                let n = (e.normal_to_world * po).as_vec3().normalize();
                let p = pd.as_vec3();
                let uv = sphere_uv(po.as_vec3());
                SurfacePoint {
                    p,
                    p_outside: p,
                    p_error: p.abs() * gamma(3),
                    ng: n,
                    ns: n,
                    uv,
                    object: e.object,
                }
            }
        }
    }
}

/// `p` moved off a flat triangle onto the smooth surface its vertex normals describe: the
/// barycentric mean of `p` projected onto each vertex's tangent plane, where that lies outside.
fn terminator_point(p: Vec3, v: [Vec3; 3], n: [Vec3; 3], b: [f32; 3]) -> Vec3 {
    let mut q = p;
    for i in 0..3 {
        let d = (p - v[i]).dot(n[i]).min(0.0);
        q -= n[i] * (d * b[i]);
    }
    if q.is_finite() { q } else { p }
}

/// Longitude/latitude coordinates of a unit direction: u from the azimuth about +y, v from the pole.
#[inline]
fn sphere_uv(n: Vec3) -> Vec2 {
    let u = 0.5 + n.z.atan2(n.x) / std::f32::consts::TAU;
    let v = n.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
    Vec2::new(u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn terminator_point_lifts_a_flat_facet_towards_the_smooth_sphere() {
        let v = [
            Vec3::new(1.0, 0.0, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 0.0, 1.0),
        ];
        let b = [1.0 / 3.0; 3];
        let p = (v[0] + v[1] + v[2]) / 3.0;
        let q = terminator_point(p, v, v, b);
        assert!(p.length() < 0.6);
        assert!(
            q.length() > p.length() && q.length() < 1.01,
            "{} -> {}",
            p.length(),
            q.length()
        );
        // Vertices stay where they are.
        assert!(terminator_point(v[0], v, v, [1.0, 0.0, 0.0]).distance(v[0]) < 1e-6);
    }
}

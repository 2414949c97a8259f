//! Expanding a hit into the surface record shading needs (position with error bound, normals,
//! texture coordinates).

use glam::{DVec3, Vec2, Vec3};

use super::geometry::{Geometry, Hit, PrimKind};
use crate::geometry::Ray;
use crate::geometry::float::gamma;
use crate::geometry::sphere::{reproject_to_sphere, unit_quadric_t};
use crate::geometry::triangle::hit_point_error;

/// Everything shading needs about a hit point, except its surface parameterisation
/// ([`SurfaceParams`], which only textures read and [`Geometry::surface_params`] computes).
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
    /// Owning object.
    pub object: u32,
    /// Where on its primitive the point lies, for [`Geometry::surface_params`]: the primitive,
    /// and the barycentric weights of the second and third vertex (triangles) or the point on
    /// the unit sphere (spheres: the normal; ellipsoids: the object-space point).
    local: Local,
}

impl SurfacePoint {
    /// The point `p` at infinity (beyond the scene) that an escaping ray meets on an
    /// environment light, with unit normal `n` facing the ray and owning object `object`
    /// (see `render_scene::light::escape`). It has no primitive: nothing shades it.
    #[must_use]
    pub fn at_infinity(p: Vec3, n: Vec3, object: u32) -> Self {
        Self {
            p,
            p_error: Vec3::ZERO,
            ng: n,
            ns: n,
            p_outside: p,
            object,
            local: Local {
                prim: super::geometry::PrimRef::new(PrimKind::Triangle, 0),
                b1: 0.0,
                b2: 0.0,
                unit: n,
            },
        }
    }
}

/// A hit's position on its primitive (see [`SurfacePoint`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct Local {
    prim: super::geometry::PrimRef,
    b1: f32,
    b2: f32,
    unit: Vec3,
}

/// A surface's parameterisation at a point: what texture lookups and bump mapping need.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SurfaceParams {
    /// Texture coordinates.
    pub uv: Vec2,
    /// ∂p/∂u: how the position changes with `u` (a tangent; never zero — a surface without a
    /// usable parameterisation gets an orthonormal tangent frame instead).
    pub dpdu: Vec3,
    /// ∂p/∂v.
    pub dpdv: Vec3,
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
                let p_outside = a.normals.map_or(p, |n| {
                    terminator_point(p, [p0, p1, p2], n, [b0, hit.b1, hit.b2])
                });
                SurfacePoint {
                    p,
                    p_outside,
                    p_error: hit_point_error(&th, p0, p1, p2),
                    ng,
                    ns,
                    object: a.object,
                    local: Local {
                        prim: hit.prim,
                        b1: hit.b1,
                        b2: hit.b2,
                        unit: Vec3::ZERO,
                    },
                }
            }
            PrimKind::Sphere => {
                let s = &self.spheres[hit.prim.index()];
                let c = s.center.as_dvec3();
                let raw = ray.origin.as_dvec3() + ray.dir.as_dvec3() * f64::from(hit.t);
                let pd = reproject_to_sphere(c, f64::from(s.radius), raw);
                let n = ((pd - c) / f64::from(s.radius)).as_vec3().normalize();
                let p = pd.as_vec3();
                SurfacePoint {
                    p,
                    p_outside: p,
                    p_error: p.abs() * gamma(2),
                    ng: n,
                    ns: n,
                    object: s.object,
                    local: Local {
                        prim: hit.prim,
                        b1: 0.0,
                        b2: 0.0,
                        unit: n,
                    },
                }
            }
            PrimKind::Ellipsoid => {
                let e = &self.ellipsoids[hit.prim.index()];
                let o = e.object_from_world.transform_point3(ray.origin.as_dvec3());
                let d = e.object_from_world.transform_vector3(ray.dir.as_dvec3());
                // The f32 `t` can be off by more than a thin ellipsoid's thickness: re-solve in f64.
                let t = unit_quadric_t(o, d, 1.0).unwrap_or(f64::from(hit.t));
                let po = reproject_to_sphere(DVec3::ZERO, 1.0, o + d * t);
                let pd = e.world_from_object.transform_point3(po);
                let n = (e.normal_to_world * po).as_vec3().normalize();
                let p = pd.as_vec3();
                SurfacePoint {
                    p,
                    p_outside: p,
                    p_error: p.abs() * gamma(3),
                    ng: n,
                    ns: n,
                    object: e.object,
                    local: Local {
                        prim: hit.prim,
                        b1: 0.0,
                        b2: 0.0,
                        unit: po.as_vec3(),
                    },
                }
            }
            PrimKind::Quadric => self.quadric_surface(ray, hit),
        }
    }

    /// [`Geometry::surface`] of a disc or cylinder hit: out of line, so that the common kinds'
    /// surface records stay as cheap as before the kind existed.
    #[inline(never)]
    fn quadric_surface(&self, ray: &Ray, hit: &Hit) -> SurfacePoint {
        let q = &self.quadrics[hit.prim.index()];
        let o = q.object_from_world.transform_point3(ray.origin.as_dvec3());
        let d = q.object_from_world.transform_vector3(ray.dir.as_dvec3());
        // Re-solved in f64 (as for ellipsoids), then moved exactly onto the surface.
        let t = q.shape.hit_t(o, d).unwrap_or(f64::from(hit.t));
        let po = q.shape.reproject(o + d * t);
        let p = q.world_from_object.transform_point3(po).as_vec3();
        let n = (q.normal_to_world * q.shape.normal(po))
            .as_vec3()
            .normalize();
        SurfacePoint {
            p,
            p_outside: p,
            p_error: p.abs() * gamma(3),
            ng: n,
            ns: n,
            object: q.object,
            local: Local {
                prim: hit.prim,
                b1: 0.0,
                b2: 0.0,
                unit: po.as_vec3(),
            },
        }
    }

    /// The parameterisation (uv and its derivatives) at a point [`Geometry::surface`] returned:
    /// interpolated vertex uvs for triangles, longitude/latitude for spheres and ellipsoids
    /// (pbrt's). Computed only for materials with textures.
    #[must_use]
    pub fn surface_params(&self, sp: &SurfacePoint) -> SurfaceParams {
        let Local { prim, b1, b2, unit } = sp.local;
        match prim.kind() {
            PrimKind::Triangle => {
                let a = &self.tri_attrs[prim.index()];
                let b0 = 1.0 - b1 - b2;
                let uv = a.uvs[0] * b0 + a.uvs[1] * b1 + a.uvs[2] * b2;
                let (dpdu, dpdv) = triangle_derivatives(self.triangles[prim.index()], a.uvs, sp.ng);
                SurfaceParams { uv, dpdu, dpdv }
            }
            PrimKind::Sphere => {
                let (dpdu, dpdv) = sphere_derivatives(unit, self.spheres[prim.index()].radius);
                SurfaceParams {
                    uv: sphere_uv(unit),
                    dpdu,
                    dpdv,
                }
            }
            PrimKind::Ellipsoid => {
                let (du, dv) = sphere_derivatives(unit, 1.0);
                let l = self.ellipsoids[prim.index()].world_from_object.matrix3;
                SurfaceParams {
                    uv: sphere_uv(unit),
                    dpdu: (l * du.as_dvec3()).as_vec3(),
                    dpdv: (l * dv.as_dvec3()).as_vec3(),
                }
            }
            PrimKind::Quadric => {
                let q = &self.quadrics[prim.index()];
                let (uv, du, dv) = q.shape.uv(unit.as_dvec3());
                let l = q.world_from_object.matrix3;
                SurfaceParams {
                    uv: uv.as_vec2(),
                    dpdu: (l * du).as_vec3(),
                    dpdv: (l * dv).as_vec3(),
                }
            }
        }
    }
}

impl Geometry {
    /// How strongly the surface curves at a hit, in 1/length (0 for flat faces): 1/r for a
    /// sphere, longest / shortest² semi-axis (its largest) for an ellipsoid, and for a smooth-shaded triangle the
    /// largest change of vertex normal per unit length along its edges. Used to widen texture
    /// footprints seen in curved mirrors and lenses.
    #[must_use]
    pub fn curvature(&self, hit: &Hit) -> f32 {
        let k = match hit.prim.kind() {
            PrimKind::Sphere => 1.0 / self.spheres[hit.prim.index()].radius,
            PrimKind::Ellipsoid => {
                // The largest curvature of an ellipsoid, at the ends of its longest axis:
                // longest / shortest².
                let m = self.ellipsoids[hit.prim.index()].world_from_object.matrix3;
                let axes = [m.x_axis.length(), m.y_axis.length(), m.z_axis.length()];
                let shortest = axes.iter().copied().fold(f64::INFINITY, f64::min);
                let longest = axes.iter().copied().fold(0.0, f64::max);
                (longest / (shortest * shortest)) as f32
            }
            PrimKind::Quadric => {
                let q = &self.quadrics[hit.prim.index()];
                q.shape.curvature(q.world_from_object.matrix3) as f32
            }
            PrimKind::Triangle => {
                let i = hit.prim.index();
                match self.tri_attrs[i].normals {
                    Some(n) => {
                        let p = self.triangles[i];
                        (0..3)
                            .map(|a| {
                                let b = (a + 1) % 3;
                                (n[a] - n[b]).length() / (p[a] - p[b]).length()
                            })
                            .fold(0.0, f32::max)
                    }
                    None => 0.0,
                }
            }
        };
        if k.is_finite() { k } else { 0.0 }
    }
}

/// ∂p/∂u and ∂p/∂v of a triangle from its vertex uvs; an orthonormal tangent frame around `ng`
/// when the uvs are degenerate (e.g. a mesh without texture coordinates).
fn triangle_derivatives(p: [Vec3; 3], uv: [Vec2; 3], ng: Vec3) -> (Vec3, Vec3) {
    let (duv02, duv12) = (uv[0] - uv[2], uv[1] - uv[2]);
    let (dp02, dp12) = (p[0] - p[2], p[1] - p[2]);
    let det = duv02.x * duv12.y - duv02.y * duv12.x;
    if det.abs() > 1e-12 {
        let inv = 1.0 / det;
        let dpdu = (dp02 * duv12.y - dp12 * duv02.y) * inv;
        let dpdv = (dp12 * duv02.x - dp02 * duv12.x) * inv;
        if dpdu.cross(dpdv).length_squared() > 0.0 && dpdu.is_finite() && dpdv.is_finite() {
            return (dpdu, dpdv);
        }
    }
    let f = crate::geometry::Frame::from_normal(ng);
    (f.s, f.t)
}

/// ∂p/∂u and ∂p/∂v of the longitude/latitude parameterisation of a sphere of radius `r` at unit
/// direction `n` (relative to the centre); at the poles, where ∂p/∂u vanishes, a tangent frame.
fn sphere_derivatives(n: Vec3, r: f32) -> (Vec3, Vec3) {
    use std::f32::consts::{PI, TAU};
    let rho = (n.x * n.x + n.z * n.z).sqrt();
    if rho < 1e-6 {
        let f = crate::geometry::Frame::from_normal(n);
        return (f.s * (TAU * r), f.t * (PI * r));
    }
    // u = 0.5 + atan2(−z, x)/2π, v = acos(y)/π: p = (sin θ cos φ, cos θ, −sin θ sin φ).
    let dpdu = Vec3::new(n.z, 0.0, -n.x) * (TAU * r);
    let (cos_phi, sin_phi) = (n.x / rho, -n.z / rho);
    let dpdv = Vec3::new(n.y * cos_phi, -rho, -n.y * sin_phi) * (PI * r);
    (dpdu, dpdv)
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

/// Longitude/latitude coordinates of a unit direction: v from the north (+y) pole down, u
/// increasing eastwards (clockwise seen from above), so an image wrapped around the sphere reads
/// left to right and upright from outside; its seam (u = 0) faces −x.
#[inline]
fn sphere_uv(n: Vec3) -> Vec2 {
    let u = 0.5 + (-n.z).atan2(n.x) / std::f32::consts::TAU;
    let v = n.y.clamp(-1.0, 1.0).acos() / std::f32::consts::PI;
    Vec2::new(u, v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_derivatives_match_finite_differences_of_the_parameterisation() {
        // p(u, v) for the parameterisation u = 0.5 + atan2(−z, x)/2π, v = acos(y)/π.
        let p = |u: f32, v: f32| {
            let (phi, theta) = ((u - 0.5) * std::f32::consts::TAU, v * std::f32::consts::PI);
            Vec3::new(
                theta.sin() * phi.cos(),
                theta.cos(),
                -theta.sin() * phi.sin(),
            ) * 2.0
        };
        for (u, v) in [(0.3f32, 0.4f32), (0.8, 0.7), (0.55, 0.1)] {
            let n = p(u, v) / 2.0;
            assert!(sphere_uv(n).distance(Vec2::new(u, v)) < 1e-5);
            let (du, dv) = sphere_derivatives(n, 2.0);
            let h = 1e-3;
            let fu = (p(u + h, v) - p(u - h, v)) / (2.0 * h);
            let fv = (p(u, v + h) - p(u, v - h)) / (2.0 * h);
            assert!(du.distance(fu) < 1e-2 * fu.length(), "{du} vs {fu}");
            assert!(dv.distance(fv) < 1e-2 * fv.length(), "{dv} vs {fv}");
        }
        // Poles: finite, tangent, non-zero.
        let (du, dv) = sphere_derivatives(Vec3::Y, 1.0);
        assert!(
            du.length() > 0.0
                && dv.length() > 0.0
                && du.dot(Vec3::Y).abs() < 1e-6
                && dv.dot(Vec3::Y).abs() < 1e-6
        );
    }

    #[test]
    fn triangle_derivatives_follow_the_uvs_or_fall_back_to_a_frame() {
        let p = [
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 3.0, 0.0),
        ];
        let uv = [Vec2::ZERO, Vec2::X, Vec2::Y];
        let (du, dv) = triangle_derivatives(p, uv, Vec3::Z);
        assert!(
            du.distance(Vec3::new(2.0, 0.0, 0.0)) < 1e-6
                && dv.distance(Vec3::new(0.0, 3.0, 0.0)) < 1e-6
        );
        let (du, dv) = triangle_derivatives(p, [Vec2::ZERO; 3], Vec3::Z);
        assert!(
            (du.length() - 1.0).abs() < 1e-6
                && du.dot(dv).abs() < 1e-6
                && du.dot(Vec3::Z).abs() < 1e-6
        );
    }

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

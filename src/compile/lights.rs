//! Lights as the renderer samples them: a sphere light too small to sample in single precision
//! is compiled as the point light it converges to.
//!
//! A sphere light of power Φ and radius r has radiance Φ/(4π²r²) and is sampled over the cone it
//! subtends, of solid angle ≈ πr²/d² at distance d (see `render_scene::light`). In f32 both
//! break for a small enough r: the radiance overflows to infinity, or r²/d² leaves the normal
//! range and loses its precision, then reaches 0 (infinite radiance times a zero solid angle is a
//! NaN sample). The irradiance the sphere casts, Φ cos θ/(4πd²) for a point it fully lights, is
//! exactly a point light's of the same power, and the difference for a finite sphere is of order
//! r²/d²; so below the radius f32 can sample, the point light *is* the sphere light, to every
//! digit f32 holds. It is kept rather than refused (a radius swept towards 0 keeps rendering the
//! same image) with a warning, because the point light has no surface a camera ray can hit.

//!
//! The lights of issue #25 are made here too: spot, distant and environment lights from the
//! `lights` list ([`spec_light`]), and area lights from the shapes that carry `emission`
//! ([`node_light`]): a quad becomes a [`RectLight`], a sphere a sphere light, a cube or mesh a
//! [`MeshLight`] over its triangles.

use std::path::Path;
use std::sync::Arc;

use glam::Vec3;

use crate::render_scene::geometry::{GeometryBuilder, SpherePrim};
use crate::render_scene::light::escape::InfinityRef;
use crate::render_scene::light::{
    DistantLight, EnvironmentLight, MeshLight, QuadricLight, RectLight, SceneSphere, SkyLight,
    SpotLight, sky,
};
use crate::render_scene::{Light, ObjectInfo};
use crate::scene::Diagnostic;
use crate::scene::schema::{EmissionSpec, LightSpec, SkySun};

/// Largest radiance, in W/(m²·sr), a sphere light may have: f32 reaches 3.4e38, and this leaves
/// eight orders of magnitude for the sums of samples and the exposure.
pub const MAX_SPHERE_RADIANCE: f64 = 1e30;

/// The smallest radius, in scene units, at which a sphere light of `power` (W per channel) can be
/// sampled in f32 from every point up to `reach` away: its radiance at most
/// [`MAX_SPHERE_RADIANCE`], and the squared sine of its cone's half-angle, r²/d², a normal f32
/// (at least `f32::MIN_POSITIVE`, about 1.2e-38) out to distance `reach`.
#[must_use]
pub fn min_sphere_light_radius(power: Vec3, reach: f64) -> f64 {
    let phi = f64::from(power.max_element().max(0.0));
    let by_radiance = (phi / (4.0 * std::f64::consts::PI.powi(2) * MAX_SPHERE_RADIANCE)).sqrt();
    let by_cone = f64::from(f32::MIN_POSITIVE).sqrt() * reach.max(1.0);
    by_radiance.max(by_cone)
}

/// The warning for `lights[index]`, a sphere light of `radius` below
/// [`min_sphere_light_radius`] for `power` and `reach`, compiled as a point light: which limit
/// it is below, and what to write instead.
#[must_use]
pub(super) fn point_fallback_warning(
    index: usize,
    radius: f32,
    power: Vec3,
    reach: f64,
) -> Diagnostic {
    let min = min_sphere_light_radius(power, reach);
    let r = f64::from(radius);
    let radiance = f64::from(power.max_element()) / (4.0 * std::f64::consts::PI.powi(2) * r * r);
    let why = if radiance > MAX_SPHERE_RADIANCE {
        format!(
            "its radiance Φ/(4π²r²) would be {radiance:.2e} W/(m²·sr), above the limit of {MAX_SPHERE_RADIANCE:e}"
        )
    } else {
        format!(
            "the cone it subtends from {reach:.3} units away is too narrow for f32 (r²/d² below {:e})",
            f32::MIN_POSITIVE
        )
    };
    Diagnostic::warning(
        format!("lights[{index}].radius"),
        format!(
            "a sphere light of radius {radius:e} is too small to sample in single precision: {why}; it is rendered as a point light of the same power, the limit it tends to (a point light is not seen by camera rays)"
        ),
    )
    .with_help(format!(
        "use a `Point` light, or a radius of at least {min:.3e}"
    ))
}

/// The farthest any point of the scene (every primitive built so far, and the camera `eye`) is
/// from `center`, in scene units: the longest distance a shaded point can be from a light there.
#[must_use]
pub(super) fn reach(builder: &GeometryBuilder, center: Vec3, eye: Vec3) -> f64 {
    let c = center.as_dvec3();
    let far = |p: Vec3| (p.as_dvec3() - c).length();
    let tris = builder.triangles.iter().flatten().map(|p| far(*p));
    let spheres = builder
        .spheres
        .iter()
        .map(|s| far(s.center) + f64::from(s.radius));
    let ellipsoids = builder.ellipsoids.iter().map(|e| {
        let m = e.world_from_object.matrix3;
        (e.world_from_object.translation - c).length()
            + m.x_axis.length()
            + m.y_axis.length()
            + m.z_axis.length()
    });
    let quadrics = builder.quadrics.iter().flat_map(|q| {
        (q.shape.corners().into_iter())
            .map(|p| (q.world_from_object.transform_point3(p) - c).length())
    });
    tris.chain(spheres)
        .chain(ellipsoids)
        .chain(quadrics)
        .fold(far(eye), f64::max)
}

/// How many primitives of each kind the builder holds: a node's primitives are those between
/// the counts before and after it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) struct PrimCounts {
    triangles: usize,
    spheres: usize,
    ellipsoids: usize,
    quadrics: usize,
}

impl PrimCounts {
    pub(super) fn of(b: &GeometryBuilder) -> Self {
        Self {
            triangles: b.triangles.len(),
            spheres: b.spheres.len(),
            ellipsoids: b.ellipsoids.len(),
            quadrics: b.quadrics.len(),
        }
    }
}

/// A shape with `emission`, as the flattener found it: its object and its primitives.
#[derive(Debug, Clone)]
pub(super) struct NodeEmitter {
    /// The node's field path (for diagnostics).
    pub path: String,
    /// Its object (which gets the light).
    pub object: u32,
    /// A `Quad` node (two triangles forming a parallelogram).
    pub is_quad: bool,
    /// What it emits.
    pub emission: EmissionSpec,
    /// Primitive counts before the node.
    pub first: PrimCounts,
    /// Primitive counts after it.
    pub end: PrimCounts,
}

/// The area light of an emissive shape: a rectangle for a quad (its corner and edges
/// recovered from its two triangles, the edges ordered so their cross product is the
/// triangles' winding normal), a sphere light for a sphere, a mesh light over the triangles
/// otherwise. An error for a sphere under non-uniform scale (an ellipsoid is not a light
/// shape) and for a shape with no area left.
#[allow(
    clippy::result_large_err,
    reason = "a Diagnostic is built once per bad light on a cold path and joins the compile's list of diagnostics by value"
)]
pub(super) fn node_light(b: &GeometryBuilder, e: &NodeEmitter) -> Result<Light, Diagnostic> {
    let radiance = Vec3::from(e.emission.radiance);
    let two_sided = e.emission.two_sided;
    if e.end.ellipsoids > e.first.ellipsoids {
        return Err(Diagnostic::error(
            format!("{}.transform", e.path),
            "an emissive sphere must keep its shape: its transforms scale it unevenly (an ellipsoid cannot be a light)",
        )
        .with_help("scale it by the same factor along every axis"));
    }
    if e.end.quadrics > e.first.quadrics {
        let q = b.quadrics[e.first.quadrics];
        return QuadricLight::new(q.shape, q.world_from_object, radiance, two_sided)
            .map(|q| Light::Quadric(Box::new(q)))
            .ok_or_else(|| {
                Diagnostic::error(
                    format!("{}.transform", e.path),
                    "an emissive cylinder must stay round: its transforms scale it unevenly across its axis or shear it (its area light is sampled by a uniform area element)",
                )
                .with_help("scale it by the same factor along x and y, or make it a mesh")
            });
    }
    if e.end.spheres > e.first.spheres {
        let s = b.spheres[e.first.spheres];
        return Ok(Light::Sphere {
            center: s.center,
            radius: s.radius,
            radiance,
        });
    }
    let tris = &b.triangles[e.first.triangles..e.end.triangles];
    if e.is_quad
        && let [t0, t1] = tris
        && let Some(r) = quad_rect(t0, t1, radiance, two_sided)
    {
        return Ok(Light::Rect(r));
    }
    let positions: Vec<Vec3> = tris.iter().flatten().copied().collect();
    let triangles: Vec<[u32; 3]> = (0..tris.len() as u32)
        .map(|i| [3 * i, 3 * i + 1, 3 * i + 2])
        .collect();
    MeshLight::new(positions, triangles, radiance, two_sided)
        .map(|m| Light::Mesh(Arc::new(m)))
        .ok_or_else(|| {
            Diagnostic::error(
                e.path.clone(),
                "an emissive shape needs some area, but every triangle of it is degenerate",
            )
        })
}

/// The parallelogram of a quad's two triangles `[p0, b, c]` and `[p0, c', d]` sharing `p0`
/// and the diagonal's far corner.
fn quad_rect(t0: &[Vec3; 3], t1: &[Vec3; 3], radiance: Vec3, two_sided: bool) -> Option<RectLight> {
    let p0 = t0[0];
    let winding = (t0[1] - t0[0]).cross(t0[2] - t0[0]);
    let shared = |v: Vec3| t1.contains(&v);
    let (diag, q) = if shared(t0[2]) {
        (t0[2], t0[1])
    } else {
        (t0[1], t0[2])
    };
    let r = *t1.iter().find(|v| **v != p0 && **v != diag)?;
    let (mut eu, mut ev) = (q - p0, r - p0);
    if eu.cross(ev).dot(winding) < 0.0 {
        std::mem::swap(&mut eu, &mut ev);
    }
    RectLight::new(p0, eu, ev, radiance, two_sided)
}

/// The sphere bounding every primitive built so far and the extra spheres `more` (centre,
/// radius): what lights at infinity cover with their photons.
pub(super) fn scene_sphere(b: &GeometryBuilder, more: &[(Vec3, f32)]) -> SceneSphere {
    let mut lo = Vec3::splat(f32::INFINITY);
    let mut hi = Vec3::splat(f32::NEG_INFINITY);
    for p in b.triangles.iter().flatten() {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let spheres = b.spheres.iter().map(|s| (s.center, s.radius));
    for (c, r) in spheres.chain(more.iter().copied()) {
        lo = lo.min(c - Vec3::splat(r));
        hi = hi.max(c + Vec3::splat(r));
    }
    for e in &b.ellipsoids {
        let m = e.world_from_object.matrix3.transpose();
        let c = e.world_from_object.translation.as_vec3();
        let half = Vec3::new(
            m.x_axis.length() as f32,
            m.y_axis.length() as f32,
            m.z_axis.length() as f32,
        );
        lo = lo.min(c - half);
        hi = hi.max(c + half);
    }
    for q in &b.quadrics {
        for c in q.shape.corners() {
            let p = q.world_from_object.transform_point3(c).as_vec3();
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    if !(lo.cmple(hi).all()) {
        return SceneSphere::new(Vec3::ZERO, 1.0);
    }
    SceneSphere::new((lo + hi) * 0.5, 0.5 * (hi - lo).length())
}

/// The light `lights[index]` compiles to, with the scene's bounding sphere for lights at
/// infinity. A sphere light smaller than [`min_sphere_light_radius`] allows (from every point of
/// `builder`'s primitives and the camera at `eye`) becomes a point light of the same power, with
/// a warning. Errors: a spot or distant light out of range, an environment map that cannot be
/// read or holds a negative or non-finite texel, named by file.
#[allow(
    clippy::result_large_err,
    reason = "a Diagnostic is built once per bad light on a cold path and joins the compile's list of diagnostics by value"
)]
fn spec_light(
    index: usize,
    l: &LightSpec,
    list: &[LightSpec],
    scene: SceneSphere,
    base_dir: &Path,
    builder: &GeometryBuilder,
    eye: Vec3,
) -> Result<SpecLight, Diagnostic> {
    let bad = |what: &str| {
        Diagnostic::error(
            format!("lights[{index}]"),
            format!("cannot build this light: {what}"),
        )
    };
    Ok(SpecLight::Light(match l {
        LightSpec::Point {
            position, power, ..
        } => Light::point((*position).into(), (*power).into()),
        LightSpec::Sphere {
            center,
            radius,
            power,
            ..
        } => {
            let (center, power): (Vec3, Vec3) = ((*center).into(), (*power).into());
            let reach = reach(builder, center, eye);
            let min = min_sphere_light_radius(power, reach);
            if f64::from(*radius) < min {
                return Ok(SpecLight::Point {
                    light: Light::point(center, power),
                    warning: point_fallback_warning(index, *radius, power, reach),
                });
            }
            return Ok(SpecLight::Sphere(
                Light::sphere(center, *radius, power),
                SpherePrim {
                    center,
                    radius: *radius,
                    object: u32::MAX,
                },
            ));
        }
        LightSpec::Spot {
            position,
            direction,
            intensity,
            inner_angle,
            outer_angle,
            ..
        } => Light::Spot(
            SpotLight::new(
                Vec3::from(*position),
                Vec3::from(*direction),
                Vec3::from(*intensity),
                inner_angle.to_radians(),
                outer_angle.to_radians(),
            )
            .ok_or_else(|| bad("its direction or cone angles are out of range"))?,
        ),
        LightSpec::Distant {
            direction,
            irradiance,
            angular_radius,
            ..
        } => Light::Distant(
            DistantLight::new(
                Vec3::from(*direction),
                Vec3::from(*irradiance),
                angular_radius.to_radians(),
                scene,
            )
            .ok_or_else(|| {
                bad("its direction is zero or its angular radius too small for single precision")
            })?,
        ),
        LightSpec::Environment {
            radiance,
            file,
            rotation,
            ..
        } => {
            let scale = Vec3::from(*radiance);
            let env = match file {
                None => EnvironmentLight::constant(scale, scene),
                Some(f) => load_environment(
                    index,
                    &base_dir.join(f),
                    scale,
                    rotation.to_radians(),
                    scene,
                )?,
            };
            Light::Environment(Arc::new(env))
        }
        LightSpec::Sky {
            sun,
            turbidity,
            ground_albedo,
            scale,
            ..
        } => {
            let sun = match *sun {
                SkySun::Direction(d) => sky::SkySun::Direction(d.into()),
                SkySun::Light(i) => match list.get(i) {
                    Some(LightSpec::Distant {
                        direction,
                        irradiance,
                        ..
                    }) => sky::SkySun::Light {
                        direction: (*direction).into(),
                        irradiance: (*irradiance).into(),
                    },
                    _ => return Err(bad(&format!("lights[{i}] is not a `Distant` light"))),
                },
            };
            let sky = SkyLight::new(sun, *turbidity, (*ground_albedo).into(), *scale, scene)
                .map_err(|e| bad(&e.to_string()))?;
            Light::Sky(Arc::new(sky))
        }
    }))
}

/// What [`compile_lights`] writes besides the light list: the primitives of sphere lights, the
/// objects of emitters and of the light filling the sky, and the diagnostics.
pub(super) struct Targets<'a> {
    /// Sphere lights add their sphere here.
    pub builder: &'a mut GeometryBuilder,
    /// Emitting objects (sphere lights, the light filling the sky) are added here.
    pub objects: &'a mut Vec<ObjectInfo>,
    /// Lights that cannot be built.
    pub errors: &'a mut Vec<Diagnostic>,
    /// Sphere lights compiled as point lights.
    pub warnings: &'a mut Vec<Diagnostic>,
}

/// The compiled lights of a scene.
#[derive(Debug)]
pub(super) struct Compiled {
    /// The `lights` list's lights in order (those that compiled), then the emissive shapes'.
    pub lights: Vec<Light>,
    /// Indices of the lights at infinity, in order (what escaping rays loop over).
    pub infinite_lights: Vec<u32>,
    /// The first light that fills the sky and its object (ray trees name escapes after it).
    pub infinity: Option<InfinityRef>,
}

/// Compiles the `lights` list (in order, so a light's index stays its place in the list when
/// every light before it compiled) and then the emissive shapes `emitters` collected while
/// flattening the nodes, after every primitive is built (lights at infinity cover them all with
/// the scene's bounding sphere). `eye` is the camera's position (how far a sphere light must be
/// sampled from).
pub(super) fn compile_lights(
    list: &[LightSpec],
    emitters: &[NodeEmitter],
    t: Targets<'_>,
    eye: Vec3,
    base_dir: &Path,
) -> Compiled {
    let Targets {
        builder,
        objects,
        errors,
        warnings,
    } = t;
    // The sphere lights of the list are geometry too: the bounding sphere covers them.
    let light_spheres: Vec<(Vec3, f32)> = list.iter().filter_map(light_sphere).collect();
    let scene_sphere = scene_sphere(builder, &light_spheres);
    let mut out = Compiled {
        lights: Vec::with_capacity(list.len()),
        infinite_lights: Vec::new(),
        infinity: None,
    };
    for (i, l) in list.iter().enumerate() {
        let light = match spec_light(i, l, list, scene_sphere, base_dir, builder, eye) {
            Ok(SpecLight::Light(light)) => light,
            Ok(SpecLight::Point { light, warning }) => {
                warnings.push(warning);
                light
            }
            Ok(SpecLight::Sphere(light, prim)) => {
                let index = out.lights.len() as u32;
                out.lights.push(light);
                let object = objects.len() as u32;
                objects.push(ObjectInfo {
                    name: format!("lights[{i}]"),
                    material: None,
                    light: Some(index),
                    body: None,
                });
                builder.spheres.push(SpherePrim { object, ..prim });
                continue;
            }
            Err(d) => {
                errors.push(d);
                continue;
            }
        };
        let index = out.lights.len() as u32;
        if light.is_infinite() {
            out.infinite_lights.push(index);
        }
        if light.fills_sky() && out.infinity.is_none() {
            let object = objects.len() as u32;
            objects.push(ObjectInfo {
                name: format!("lights[{i}]"),
                material: None,
                light: Some(index),
                body: None,
            });
            out.infinity = Some(InfinityRef {
                light: index,
                object,
            });
        }
        out.lights.push(light);
    }
    // Shapes with `emission` come after the list's lights (whose indices stay the list's).
    for e in emitters {
        match node_light(builder, e) {
            Ok(light) => {
                objects[e.object as usize].light = Some(out.lights.len() as u32);
                out.lights.push(light);
            }
            Err(d) => errors.push(d),
        }
    }
    out
}

/// The sphere a light of the list puts into the scene (a sphere light's centre and radius),
/// which the scene's bounding sphere covers.
fn light_sphere(l: &LightSpec) -> Option<(Vec3, f32)> {
    match *l {
        LightSpec::Sphere { center, radius, .. } => Some((center.into(), radius)),
        LightSpec::Point { .. }
        | LightSpec::Spot { .. }
        | LightSpec::Distant { .. }
        | LightSpec::Environment { .. }
        | LightSpec::Sky { .. } => None,
    }
}

/// A light of the `lights` list as [`spec_light`] compiles it.
enum SpecLight {
    /// A light without geometry.
    Light(Light),
    /// A sphere light too small to sample, compiled as the point light it tends to.
    Point {
        /// The point light.
        light: Light,
        /// Why.
        warning: Diagnostic,
    },
    /// A sphere light and its sphere (whose object the caller sets).
    Sphere(Light, SpherePrim),
}

/// Reads an equirectangular OpenEXR map (linear RGB) and makes the environment light of its
/// texels times `scale`.
#[allow(
    clippy::result_large_err,
    reason = "a Diagnostic is built once per bad light on a cold path and joins the compile's list of diagnostics by value"
)]
fn load_environment(
    index: usize,
    file: &Path,
    scale: Vec3,
    rotation: f32,
    scene: SceneSphere,
) -> Result<EnvironmentLight, Diagnostic> {
    let at = format!("lights[{index}].file");
    let img = image::open(file).map_err(|e| {
        Diagnostic::error(&at, format!("cannot read the environment map `{}`: {e}", file.display()))
            .with_help("give a linear equirectangular OpenEXR image, relative to the scene file (e.g. `assets/sky.exr`)")
    })?;
    let rgb = img.to_rgb32f();
    let (w, h) = (rgb.width() as usize, rgb.height() as usize);
    let texels: Vec<Vec3> = rgb.pixels().map(|p| Vec3::from(p.0) * scale).collect();
    EnvironmentLight::image(w, h, texels, rotation, scene).map_err(|e| {
        Diagnostic::error(&at, format!("`{}`: {e}", file.display()))
            .with_help("every texel of an environment map must be a finite, non-negative radiance")
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_limit_keeps_radiance_and_cone_inside_f32() {
        // A faint light (1 µW): the cone decides, r = 1.0842e-19 × reach.
        let power = Vec3::new(1e-6, 5e-7, 0.0);
        let reach = 10.0;
        let r = min_sphere_light_radius(power, reach);
        assert!((r / 1.084_202_2e-18 - 1.0).abs() < 1e-6, "{r:e}");
        // At the limit the radiance is finite and the cone's sin² at `reach` is a normal f32.
        let r32 = r as f32 * (1.0 + 1e-6);
        let radiance = 1e-6 / (4.0 * std::f32::consts::PI.powi(2) * r32 * r32);
        assert!(radiance.is_finite() && f64::from(radiance) <= MAX_SPHERE_RADIANCE);
        let sin2 = (r32 * r32) / (reach as f32 * reach as f32);
        assert!(sin2.is_normal(), "{sin2:e}");
        // A huge power makes the radiance decide: Φ/(4π²r²) = 1e30 at the limit.
        let r = min_sphere_light_radius(Vec3::splat(1e20), reach);
        let l = f64::from(1e20f32) / (4.0 * std::f64::consts::PI.powi(2) * r * r);
        assert!((l / MAX_SPHERE_RADIANCE - 1.0).abs() < 1e-9, "{l:e}");
    }
}

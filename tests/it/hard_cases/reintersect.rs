//! Re-intersection (issue #7; pbrt-v4 `shapes_test.cpp`, TestReintersectConvex): rays spawned
//! from a hit point with `offset_ray_origin` must never hit the surface they leave at the point
//! they leave it, for every primitive type under random transforms (scale 10^U(−4, 4), distance
//! from the origin 10^U(−4, 5)), with both closest-hit and any-hit queries.
//!
//! For each transform a ray from a random outside point hits the object; from the hit's
//! [`SurfacePoint`] rays leave in uniformly random directions:
//! - into the outside hemisphere of the convex objects (sphere, ellipsoid, cube) and to either
//!   side of the quad: they must hit nothing at all;
//! - into the inside hemisphere of the closed convex objects: the closest hit must be the far
//!   side, at the distance the exact (f64) shape gives, and an any-hit query up to half that
//!   distance must find nothing. This needs an object that f32 can resolve: one whose hit point's
//!   error bound is tiny next to its size (objects 10⁻⁴ across, 10⁵ from the origin are a few
//!   ulps wide and have no meaningful inside). Other transforms only run the outside checks;
//! - from the (non-convex) blob mesh in either hemisphere: the closest hit must not be the
//!   triangle left, any other hit must be confirmed by an f64 recomputation (a real crossing of
//!   another triangle, e.g. across a concave edge, at the same distance), and an any-hit query
//!   must find nothing before the closest hit.

use caustic::geometry::Ray;
use caustic::geometry::offset::offset_ray_origin;
use caustic::render_scene::{Hit, RenderScene, SurfacePoint};
use caustic::sampling::Rng;
use glam::{DAffine3, DVec3, Vec3};

use super::support::scene;

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Shape {
    Sphere,
    Ellipsoid,
    Quad,
    Cube,
    Mesh,
}

impl Shape {
    fn closed(self) -> bool {
        self != Shape::Quad
    }

    fn convex(self) -> bool {
        self != Shape::Mesh
    }

    /// Radius of a ball around the object-space origin containing the shape.
    fn object_radius(self) -> f64 {
        match self {
            Shape::Sphere | Shape::Ellipsoid => 1.0,
            Shape::Quad => 0.75,
            Shape::Cube => 0.9,
            Shape::Mesh => 1.9,
        }
    }
}

/// One random placement of a shape: its scene, object-to-world map and smallest half-extent.
struct Placement {
    scene: RenderScene,
    world_from_object: DAffine3,
    size: f64,
    text: String,
}

fn uniform(rng: &mut Rng, lo: f64, hi: f64) -> f64 {
    lo + (hi - lo) * f64::from(rng.next_f32())
}

fn sphere_dir(rng: &mut Rng) -> Vec3 {
    let z = 1.0 - 2.0 * rng.next_f32();
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f32::consts::TAU * rng.next_f32();
    Vec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A random f32 power of ten in `[10^lo, 10^hi]`.
fn p_exp(rng: &mut Rng, lo: f64, hi: f64) -> f32 {
    10f64.powf(uniform(rng, lo, hi)) as f32
}

fn place(shape: Shape, rng: &mut Rng) -> Placement {
    let s = p_exp(rng, -4.0, 4.0);
    // Non-uniform per-axis scale (anisotropy up to 10:1) for everything but the sphere.
    let axes: [f32; 3] = match shape {
        Shape::Sphere => [s; 3],
        _ => std::array::from_fn(|_| s * p_exp(rng, -0.5, 0.5)),
    };
    let rot: [f32; 3] = std::array::from_fn(|_| 360.0 * rng.next_f32());
    let t = sphere_dir(rng) * p_exp(rng, -4.0, 5.0);
    // The same composition the compiler uses: steps applied first to last, in f64.
    let world_from_object = DAffine3::from_translation(t.as_dvec3())
        * DAffine3::from_rotation_z(f64::from(rot[2]).to_radians())
        * DAffine3::from_rotation_y(f64::from(rot[1]).to_radians())
        * DAffine3::from_rotation_x(f64::from(rot[0]).to_radians())
        * DAffine3::from_scale(DVec3::from(axes.map(f64::from)));
    let scale = match shape {
        Shape::Sphere => format!("Scale({s:e})"),
        _ => format!("Scale(({:e}, {:e}, {:e}))", axes[0], axes[1], axes[2]),
    };
    let transform = format!(
        "[{scale}, RotateX({:e}), RotateY({:e}), RotateZ({:e}), Translate({:e}, {:e}, {:e})]",
        rot[0], rot[1], rot[2], t.x, t.y, t.z
    );
    let node = match shape {
        Shape::Sphere | Shape::Ellipsoid => {
            format!("Sphere(material: \"m\", center: (0, 0, 0), radius: 1, transform: {transform})")
        }
        Shape::Quad => format!("Quad(material: \"m\", size: (1, 1), transform: {transform})"),
        Shape::Cube => format!("Cube(material: \"m\", size: 1, transform: {transform})"),
        Shape::Mesh => format!(
            "Mesh(material: \"m\", file: \"{}/assets/blob.obj\", transform: {transform})",
            env!("CARGO_MANIFEST_DIR")
        ),
    };
    let text = format!(
        "Scene(render: (width: 8, height: 8),
          camera: Pinhole(eye: (0, 0, 10), look_at: (0, 0, 0), fov_y: 40),
          materials: {{ \"m\": (color: (0.5, 0.5, 0.5)) }},
          nodes: [{node}])"
    );
    let min_axis = f64::from(axes.iter().fold(f32::MAX, |a, &b| a.min(b)));
    let size = match shape {
        Shape::Sphere | Shape::Ellipsoid => min_axis,
        Shape::Quad | Shape::Cube => 0.5 * min_axis,
        Shape::Mesh => 0.85 * min_axis,
    };
    Placement {
        scene: scene(&text),
        world_from_object,
        size,
        text,
    }
}

/// A random object-space point the primary ray aims at (inside or on the shape, mostly).
fn aim(shape: Shape, rng: &mut Rng) -> DVec3 {
    let mut u = || uniform(rng, -0.5, 0.5);
    match shape {
        Shape::Quad => DVec3::new(u(), u(), 0.0),
        Shape::Cube => DVec3::new(u(), u(), u()),
        Shape::Sphere | Shape::Ellipsoid | Shape::Mesh => 1.6 * DVec3::new(u(), u(), u()),
    }
}

/// Far-side distance along `w` from `o`, which lies inside the exact (f64) closed convex shape:
/// the larger root against the unit sphere, or the exit from the unit cube, in object space.
fn far_side(shape: Shape, object_from_world: &DAffine3, o: Vec3, w: Vec3) -> f64 {
    let o = object_from_world.transform_point3(o.as_dvec3());
    let d = object_from_world.transform_vector3(w.as_dvec3());
    if shape == Shape::Cube {
        (0..3)
            .filter(|&k| d[k] != 0.0)
            .map(|k| (0.5f64.copysign(d[k]) - o[k]) / d[k])
            .fold(f64::INFINITY, f64::min)
    } else {
        let (a, b, c) = (d.length_squared(), d.dot(o), o.length_squared() - 1.0);
        (-b + (b * b - a * c).max(0.0).sqrt()) / a
    }
}

/// True if the ray `o + t·w` really meets `tri` at `t` (within `tol`), by Möller–Trumbore in
/// f64 on the stored f32 vertices, with a little slack at the edges.
fn confirmed(tri: [Vec3; 3], o: Vec3, w: Vec3, t: f32, tol: f32) -> bool {
    let [p0, p1, p2] = tri.map(Vec3::as_dvec3);
    let (o, d) = (o.as_dvec3(), w.as_dvec3());
    let (e1, e2) = (p1 - p0, p2 - p0);
    let q = d.cross(e2);
    let det = e1.dot(q);
    if det == 0.0 {
        return false;
    }
    let s = o - p0;
    let b1 = s.dot(q) / det;
    let r = s.cross(e1);
    let b2 = d.dot(r) / det;
    let t64 = e2.dot(r) / det;
    let slack = 1e-6;
    b1 >= -slack
        && b2 >= -slack
        && b1 + b2 <= 1.0 + slack
        && t64 > 0.0
        && (t64 - f64::from(t)).abs() <= 1e-4 * t64 + f64::from(tol)
}

#[derive(Debug, Default)]
struct Tally {
    placements: usize,
    primary_misses: usize,
    /// Rays checked into the outside hemisphere (either side for the quad).
    outside_rays: usize,
    /// Rays checked into the inside hemisphere.
    inside_rays: usize,
    /// Mesh rays that (really) hit another triangle, e.g. across a concave edge.
    other_triangle: usize,
    /// Inside rays not checked because f32 cannot resolve the object.
    inside_skipped: usize,
    /// Transforms where f32 cannot resolve the object (inside checks skipped).
    unresolved: usize,
    /// Inside rays whose exact far side is within a few error bounds (too close to tell), or
    /// that start beyond a cube's adjacent face.
    grazing: usize,
    closest_failures: usize,
    any_failures: usize,
    examples: Vec<String>,
}

impl Tally {
    fn fail(&mut self, any_hit: bool, what: String) {
        if any_hit {
            self.any_failures += 1;
        } else {
            self.closest_failures += 1;
        }
        if self.examples.len() < 5 {
            self.examples.push(what);
        }
    }
}

/// Runs `placements` random transforms of `shape` with `per_side` spawned rays per hemisphere.
fn run(shape: Shape, seed: u64, placements: usize, per_side: usize) -> Tally {
    let mut rng = Rng::new(seed, shape as u64);
    let mut tally = Tally::default();
    while tally.placements < placements {
        let pl = place(shape, &mut rng);
        let g = &pl.scene.geometry;
        let m = pl.world_from_object;
        let object_from_world = m.inverse();
        // A primary ray from a random point outside the object's bounding ball.
        let reach = shape.object_radius()
            * m.matrix3
                .to_cols_array()
                .iter()
                .map(|v| v.abs())
                .sum::<f64>();
        let centre = m.translation;
        let origin = (centre
            + sphere_dir(&mut rng).as_dvec3() * reach * 10f64.powf(uniform(&mut rng, 0.1, 3.0)))
        .as_vec3();
        let target = m.transform_point3(aim(shape, &mut rng)).as_vec3();
        let mut dir = target - origin;
        if rng.next_f32() < 0.5 {
            dir = dir.normalize();
        }
        let ray = Ray::new(origin, dir);
        let Some(hit) = g.intersect(&ray) else {
            tally.primary_misses += 1;
            continue;
        };
        tally.placements += 1;
        let sp: SurfacePoint = g.surface(&ray, &hit);
        let err = sp.p_error.max_element();
        // Inside checks need an object much larger than the hit point's error bound.
        let resolved = 1e3 * f64::from(err) < pl.size;
        if !resolved {
            tally.unresolved += 1;
        }
        let near = 16.0 * sp.p_error.length();
        let describe = |w: Vec3, po: Vec3, h: Option<Hit>| {
            format!(
                "{shape:?}: {}\n  primary {ray:?} hit {hit:?}\n  p {:?} p_error {:?} ng {:?}\n  spawned from {po:?} along {w:?}: {h:?}",
                pl.text, sp.p, sp.p_error, sp.ng
            )
        };
        for j in 0..2 * per_side {
            let mut w = sphere_dir(&mut rng);
            let inside_wanted = shape.closed() && j % 2 == 1;
            if (w.dot(sp.ng) < 0.0) != inside_wanted {
                w = -w;
            }
            if w.dot(sp.ng) == 0.0 {
                continue;
            }
            let n = if w.dot(sp.ng) > 0.0 { sp.ng } else { -sp.ng };
            let po = offset_ray_origin(sp.p, sp.p_error, n, w);
            let spawned = Ray::new(po, w);
            let closest = g.intersect(&spawned);
            let outward = w.dot(sp.ng) > 0.0 || !shape.closed();
            if outward {
                tally.outside_rays += 1;
            } else if !shape.convex() {
                tally.inside_rays += 1;
            }
            if shape.convex() && outward {
                if closest.is_some() {
                    tally.fail(false, describe(w, po, closest));
                }
                if g.occluded(&spawned) {
                    tally.fail(true, describe(w, po, None));
                }
            } else if shape.convex() {
                if !resolved {
                    tally.inside_skipped += 1;
                    continue;
                }
                // The spawned origin must lie inside the exact shape — except next to a cube's
                // edge, where moving off one face along its normal may cross the adjacent face
                // (it must still be inside the face it left).
                let start = object_from_world.transform_point3(po.as_dvec3());
                let (inside, edge) = if shape == Shape::Cube {
                    let face = object_from_world
                        .transform_point3(sp.p.as_dvec3())
                        .abs()
                        .max_position();
                    (start[face].abs() < 0.5, start.abs().max_element() >= 0.5)
                } else {
                    (start.length_squared() < 1.0, false)
                };
                if !inside {
                    tally.fail(
                        false,
                        format!("{} (starts outside at {start})", describe(w, po, closest)),
                    );
                    continue;
                }
                if edge {
                    tally.grazing += 1;
                    continue;
                }
                let expected = far_side(shape, &object_from_world, po, w);
                if expected < 4.0 * f64::from(near) {
                    tally.grazing += 1;
                    continue;
                }
                tally.inside_rays += 1;
                // The far side at the exact distance (to f32 accuracy plus the error bounds).
                let ok = closest.is_some_and(|h| {
                    let same_face = shape == Shape::Cube && {
                        let s = g.surface(&spawned, &h);
                        s.ng.dot(sp.ng) > 0.999
                    };
                    !same_face
                        && (f64::from(h.t) - expected).abs() <= 1e-4 * expected + f64::from(near)
                });
                if !ok {
                    tally.fail(
                        false,
                        format!("{} (expected t {expected:e})", describe(w, po, closest)),
                    );
                }
                let half = Ray {
                    t_max: (0.5 * expected) as f32,
                    ..spawned
                };
                if g.occluded(&half) {
                    tally.fail(
                        true,
                        format!("{} (expected t {expected:e})", describe(w, po, None)),
                    );
                }
            } else {
                // The mesh: never the triangle left (a plane cannot be crossed twice), and any
                // other hit must be real: the same hit, recomputed in f64 from the stored
                // vertices, at the same distance (to within the error bounds).
                let real = closest.filter(|h| {
                    h.prim != hit.prim && confirmed(g.triangles[h.prim.index()], po, w, h.t, near)
                });
                if closest.is_some() && real.is_none() {
                    tally.fail(false, describe(w, po, closest));
                }
                if real.is_some() {
                    tally.other_triangle += 1;
                }
                // Any-hit: nothing before the real hit (or at all, if there is none).
                let limit = real.map_or(f32::INFINITY, |h| 0.999 * h.t);
                if g.occluded(&Ray {
                    t_max: limit,
                    ..spawned
                }) {
                    tally.fail(true, describe(w, po, closest));
                }
            }
        }
    }
    tally
}

#[test]
fn spawned_rays_never_rehit_their_own_surface_point() {
    let t0 = std::time::Instant::now();
    let mut report = Vec::new();
    let mut failed = false;
    for (shape, placements, per_side) in [
        (Shape::Sphere, 1000, 64),
        (Shape::Ellipsoid, 1000, 64),
        (Shape::Quad, 1000, 32),
        (Shape::Cube, 1000, 64),
        (Shape::Mesh, 100, 512),
    ] {
        let t = std::time::Instant::now();
        let tally = run(shape, 7, placements, per_side);
        assert!(tally.outside_rays >= 10_000, "{shape:?}: {tally:?}");
        if shape.closed() {
            assert!(tally.inside_rays >= 10_000, "{shape:?}: {tally:?}");
        }
        failed |= tally.closest_failures + tally.any_failures > 0;
        report.push(format!(
            "{shape:?}: {} placements ({} primary misses, {} unresolved in f32), {} outside + {} inside rays ({} unresolved, {} grazing), {} confirmed hits on other triangles, failures: {} closest-hit, {} any-hit, {:?}\n{}",
            tally.placements,
            tally.primary_misses,
            tally.unresolved,
            tally.outside_rays,
            tally.inside_rays,
            tally.inside_skipped,
            tally.grazing,
            tally.other_triangle,
            tally.closest_failures,
            tally.any_failures,
            t.elapsed(),
            tally.examples.join("\n"),
        ));
    }
    eprintln!(
        "re-intersection in {:?}:\n{}",
        t0.elapsed(),
        report.join("\n")
    );
    assert!(!failed, "{}", report.join("\n"));
}

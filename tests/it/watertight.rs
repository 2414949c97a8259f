//! Closed meshes never leak: rays from inside a watertight mesh always hit it, including rays
//! aimed exactly at vertices and shared edges, near and far from the origin (Embree's
//! WatertightTest, with its 2e-5 bound tightened to zero).

use caustic::bench::blob::blob_mesh;
use caustic::geometry::Ray;
use caustic::render_scene::geometry::{Geometry, GeometryBuilder, TriAttrs};
use caustic::sampling::Rng;
use glam::{Vec2, Vec3};

fn closed_mesh(k: u32, scale: f32, offset: Vec3) -> (Geometry, Vec<Vec3>) {
    let mesh = blob_mesh(k);
    let verts: Vec<Vec3> = mesh
        .positions
        .iter()
        .map(|p| Vec3::from(*p) * scale + offset)
        .collect();
    let mut b = GeometryBuilder::default();
    for t in &mesh.triangles {
        b.triangles.push(t.map(|i| verts[i as usize]));
        b.tri_attrs.push(TriAttrs {
            object: 0,
            normals: None,
            uvs: [Vec2::ZERO; 3],
        });
    }
    (b.build(), verts)
}

fn random_dir(rng: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

fn leaks(offset: Vec3, rays: usize) -> (usize, usize) {
    // The blob's radius is in [0.85, 1.15]; scaled by 2, interior points within 1.5 of the centre are inside.
    let (g, verts) = closed_mesh(40, 2.0, offset);
    let mut rng = Rng::new(11, 0);
    let mut random_misses = 0;
    for _ in 0..rays {
        let o = offset + random_dir(&mut rng) * 1.5 * rng.next_f32();
        if g.intersect(&Ray::new(o, random_dir(&mut rng))).is_none() {
            random_misses += 1;
        }
    }
    let mut vertex_misses = 0;
    for v in verts.iter().step_by(3) {
        let o = offset + random_dir(&mut rng) * 0.5;
        if g.intersect(&Ray::new(o, *v - o)).is_none() {
            vertex_misses += 1;
        }
    }
    (random_misses, vertex_misses)
}

#[test]
fn no_ray_escapes_a_closed_mesh_at_the_origin() {
    assert_eq!(leaks(Vec3::ZERO, 200_000), (0, 0));
}

#[test]
fn no_ray_escapes_a_closed_mesh_far_from_the_origin() {
    assert_eq!(
        leaks(Vec3::new(148_376.0, 1234.0, -223_423.0), 200_000),
        (0, 0)
    );
}

#[test]
fn rays_along_shared_edges_hit_one_of_the_two_triangles() {
    // Aim at midpoints of edges of the mesh from inside: the hit must exist (either side).
    let (g, verts) = closed_mesh(12, 1.0, Vec3::ZERO);
    let mesh = blob_mesh(12);
    let mut misses = 0;
    for t in &mesh.triangles {
        for (a, b) in [(t[0], t[1]), (t[1], t[2]), (t[2], t[0])] {
            let target = (verts[a as usize] + verts[b as usize]) * 0.5;
            for o in [Vec3::ZERO, Vec3::new(0.1, -0.2, 0.05)] {
                if g.intersect(&Ray::new(o, target - o)).is_none() {
                    misses += 1;
                }
            }
        }
    }
    assert_eq!(misses, 0);
}

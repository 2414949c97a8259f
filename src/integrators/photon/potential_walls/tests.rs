//! Tests of the potential-wall criterion (super) against full lists and hand counts.

use glam::Vec3;

use crate::integrators::photon::wall_grid::{Listing, WallGrid, WallKind, estimate_reach};
use crate::integrators::photon::wall_list::Crossing;
use crate::integrators::photon::wall_list::tests::quad;
use crate::integrators::photon::walls::{Walls, segment, separated, tolerance};
use crate::render_scene::Geometry;
use crate::render_scene::geometry::{GeometryBuilder, SpherePrim};
use crate::sampling::Rng;

/// The six faces of the box `lo`–`hi` (object `object`), each as a quad; with `open`, no
/// face at `z = hi.z` (a Cornell box's open front).
fn cuboid(b: &mut GeometryBuilder, lo: Vec3, hi: Vec3, object: u32, open: bool) {
    let c = |x: f32, y: f32, z: f32| Vec3::new(x, y, z);
    let (l, h) = (lo, hi);
    let mut faces = vec![
        [
            c(l.x, l.y, l.z),
            c(h.x, l.y, l.z),
            c(h.x, l.y, h.z),
            c(l.x, l.y, h.z),
        ],
        [
            c(l.x, h.y, l.z),
            c(h.x, h.y, l.z),
            c(h.x, h.y, h.z),
            c(l.x, h.y, h.z),
        ],
        [
            c(l.x, l.y, l.z),
            c(l.x, h.y, l.z),
            c(l.x, h.y, h.z),
            c(l.x, l.y, h.z),
        ],
        [
            c(h.x, l.y, l.z),
            c(h.x, h.y, l.z),
            c(h.x, h.y, h.z),
            c(h.x, l.y, h.z),
        ],
        [
            c(l.x, l.y, l.z),
            c(h.x, l.y, l.z),
            c(h.x, h.y, l.z),
            c(l.x, h.y, l.z),
        ],
    ];
    if !open {
        faces.push([
            c(l.x, l.y, h.z),
            c(h.x, l.y, h.z),
            c(h.x, h.y, h.z),
            c(l.x, h.y, h.z),
        ]);
    }
    for f in faces {
        quad(b, f, object);
    }
}

/// The candidates of a grid of reach `reach` over `g`'s surfaces: (triangles per object,
/// bounds-only candidates).
fn listed(g: &Geometry, reach: f32, listing: Listing) -> (Vec<usize>, usize) {
    let grid = WallGrid::build_listing(&Walls::every_surface(g), reach, listing).expect("a grid");
    let mut per_object = vec![0usize; 8];
    let mut solids = 0;
    for w in &grid.walls {
        match w.kind {
            WallKind::Triangle => per_object[w.body as usize] += 1,
            WallKind::Bounds => solids += 1,
        }
    }
    (per_object, solids)
}

#[test]
fn a_cornell_box_s_walls_are_no_walls_and_its_ball_on_the_floor_is() {
    // Hand geometry: the five faces of [-1, 1]³ open at z = 1 (object 0), a ball of radius
    // 0.3 resting on the floor (object 1) and one alone in the air (object 2, 0.5 m from
    // everything at reach 0.1: G = 1.4 · 0.1 + 37 s ≈ 0.14 m). Every surface lies on the
    // room's side of each wall, so no wall is listed; the resting ball meets the floor. The
    // resting ball's points not parallel to the floor lie at least 0.3 (1 − 0.901) = 0.030 m
    // above it, more than their largest lift 0.901 H = 0.018 m (H = 0.2 · 0.1 + 12 s); at
    // reach 0.5 (0.901 H = 0.090 m) they could be lifted below it, and the floor is listed.
    let mut b = GeometryBuilder::default();
    cuboid(&mut b, Vec3::splat(-1.0), Vec3::splat(1.0), 0, true);
    b.spheres.push(SpherePrim {
        center: Vec3::new(-0.4, -0.7, 0.0),
        radius: 0.3,
        object: 1,
    });
    b.spheres.push(SpherePrim {
        center: Vec3::new(0.4, 0.0, 0.0),
        radius: 0.1,
        object: 2,
    });
    let g = b.build();
    assert_eq!(
        listed(&g, 0.1, Listing::Every),
        (vec![10, 0, 0, 0, 0, 0, 0, 0], 2)
    );
    assert_eq!(listed(&g, 0.1, Listing::PotentialWalls), (vec![0; 8], 1));
    // Reach 0.5 (G ≈ 0.7 m): the floating ball is within G of the walls and stays.
    assert_eq!(
        listed(&g, 0.5, Listing::PotentialWalls),
        (vec![2, 0, 0, 0, 0, 0, 0, 0], 2)
    );
}

#[test]
fn a_wall_is_kept_exactly_when_a_surface_lies_beyond_it_within_reach() {
    // A wall x = 0 (y ∈ [0, 1], z ∈ [-1, 1], object 0) with a floor before it (x ∈ [-1, 0],
    // object 1, meeting it at its foot: not beyond) and a strip of floor beyond it at
    // x ∈ [gap, gap + 0.1] (object 2). Reach 0.2: G = 1.4 · 0.2 + 37 s. The wall is listed
    // when the strip starts within G of it, not when it starts beyond; the floor never (its
    // surfaces lie above it, nothing non-parallel below); the strip never.
    let reach = 0.2f32;
    let slack = tolerance(Vec3::splat(1.0 + 1.4 * reach + 0.1));
    for (gap, kept) in [
        (0.0, false),
        (0.99 * (1.4 * reach), true),
        (1.01 * (1.4 * reach + 37.0 * slack), false),
    ] {
        let c = Vec3::new;
        let mut b = GeometryBuilder::default();
        quad(
            &mut b,
            [
                c(0.0, 0.0, -1.0),
                c(0.0, 1.0, -1.0),
                c(0.0, 1.0, 1.0),
                c(0.0, 0.0, 1.0),
            ],
            0,
        );
        quad(
            &mut b,
            [
                c(-1.0, 0.0, -1.0),
                c(0.0, 0.0, -1.0),
                c(0.0, 0.0, 1.0),
                c(-1.0, 0.0, 1.0),
            ],
            1,
        );
        if gap > 0.0 {
            let (x0, x1) = (gap, gap + 0.1);
            quad(
                &mut b,
                [
                    c(x0, 0.0, -1.0),
                    c(x1, 0.0, -1.0),
                    c(x1, 0.0, 1.0),
                    c(x0, 0.0, 1.0),
                ],
                2,
            );
        }
        let g = b.build();
        let (per_object, _) = listed(&g, reach, Listing::PotentialWalls);
        assert_eq!(per_object[0], if kept { 2 } else { 0 }, "gap {gap}");
        assert_eq!(per_object[1] + per_object[2], 0, "gap {gap}");
    }
}

/// A closed room [-1, 1] × [0, 1] × [-1, 1] (object 0) with a divider at x = 0.3 from the
/// wall z = -1 to z = 0.2 (object 1), a 0.2 m cube on the floor (object 2) and a ball of
/// radius 0.15 resting on the floor (object 3).
fn furnished() -> Geometry {
    let c = Vec3::new;
    let mut b = GeometryBuilder::default();
    cuboid(&mut b, c(-1.0, 0.0, -1.0), c(1.0, 1.0, 1.0), 0, false);
    quad(
        &mut b,
        [
            c(0.3, 0.0, -1.0),
            c(0.3, 1.0, -1.0),
            c(0.3, 1.0, 0.2),
            c(0.3, 0.0, 0.2),
        ],
        1,
    );
    cuboid(&mut b, c(-0.6, 0.0, -0.6), c(-0.4, 0.2, -0.4), 2, false);
    b.spheres.push(SpherePrim {
        center: c(-0.4, 0.15, 0.5),
        radius: 0.15,
        object: 3,
    });
    b.build()
}

#[test]
fn a_furnished_room_lists_its_divider_cube_and_ball_and_not_its_walls() {
    // Hand count at reach 0.375 (G ≈ 0.53 m, H ≈ 0.075 m): of the room's 12 triangles only
    // the floor's 2 have something beyond them (the ball's points 26° from its lowest lie
    // 0.15 · 0.099 = 0.015 m above the floor, and may be lifted 0.901 H = 0.068 m: below it;
    // the divider meets the walls and the floor at seams, not beyond); the divider has floor
    // on both sides; the cube's sides and top have its other faces beyond their planes,
    // its bottom (on the floor) has nothing beyond; the ball rests on the floor.
    let g = furnished();
    let (per_object, solids) = listed(&g, 0.375, Listing::PotentialWalls);
    assert_eq!(&per_object[..4], &[2, 2, 10, 0]);
    assert_eq!(solids, 1);
}

/// A random point on one of `g`'s surfaces (`furnished`): position, unit normal on its
/// room side, object.
fn surface_point(g: &Geometry, rng: &mut Rng) -> (Vec3, Vec3, u32) {
    let (u, v) = rng.next_2d();
    let (w, _) = rng.next_2d();
    let pick = (w * (g.triangles.len() + 4) as f32) as usize;
    if let Some(t) = g.triangles.get(pick) {
        let (su, sv) = if u + v > 1.0 {
            (1.0 - u, 1.0 - v)
        } else {
            (u, v)
        };
        let p = t[0] + su * (t[1] - t[0]) + sv * (t[2] - t[0]);
        let mut n = (t[1] - t[0]).cross(t[2] - t[0]).normalize();
        // Towards the room's centre, or either side for the divider and the cube.
        if n.dot(Vec3::new(0.0, 0.5, 0.0) - p) < 0.0 {
            n = -n;
        }
        (p, n, g.tri_attrs[pick].object)
    } else {
        let s = g.spheres[0];
        let z = 1.0 - 2.0 * u;
        let phi = std::f32::consts::TAU * v;
        let r = (1.0 - z * z).max(0.0).sqrt();
        let n = Vec3::new(r * phi.cos(), r * phi.sin(), z);
        (s.center + s.radius * n, n, s.object)
    }
}

#[test]
fn the_potential_walls_decide_every_segment_as_every_surface_does() {
    // Reference: the lists of every opaque surface (as before this module) and, where a
    // list cannot decide, walls::separated's ray. segments between random surface
    // points of the furnished room within the radius 0.3 of each other: the same decision
    // from the lists of potential walls, which are shorter. 3 000 segments, of which ~2 %
    // cross the divider or the cube.
    let g = furnished();
    let walls = Walls::every_surface(&g);
    let radius = 0.3f32;
    let reach = estimate_reach(Vec3::splat(1.0), radius);
    let every = WallGrid::build_listing(&walls, reach, Listing::Every).expect("grid");
    let potential = WallGrid::build_listing(&walls, reach, Listing::PotentialWalls).expect("grid");
    assert!(potential.walls.len() < every.walls.len());
    let mut rng = Rng::new(11, 3);
    let (mut tested, mut hidden, mut tries) = (0, 0, 0);
    while tested < 3000 {
        tries += 1;
        assert!(tries < 200_000, "too few pairs");
        let (q, nq, oq) = surface_point(&g, &mut rng);
        let (p, np, _) = surface_point(&g, &mut rng);
        if q.distance(p) > radius {
            continue;
        }
        let Some((a, b)) = segment(q, nq, p, np) else {
            continue;
        };
        let r = estimate_reach(q, q.distance(p));
        let decide = |grid: &WallGrid| match grid
            .near(q, r)
            .map(|l| l.crosses(a, b, nq, np, Some(oq)))
        {
            Some(Crossing::Wall) => true,
            Some(Crossing::Clear) => false,
            Some(Crossing::Unknown) | None => separated(&Walls::every_surface(&g), q, nq, p, np),
        };
        let full = decide(&every);
        assert_eq!(decide(&potential), full, "{q} {nq} -> {p} {np}");
        tested += 1;
        hidden += usize::from(full);
    }
    assert!(hidden > 25, "{hidden} of 3000 hidden");
}

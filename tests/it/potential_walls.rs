//! Issue 47, the cost of the wall test: only the opaque surfaces that can separate a query
//! point from a photon are listed in the wall grid (`integrators::photon::potential_walls`).
//! On the scenes: a Cornell box's five walls are no potential walls (everything lies on the
//! room's side of each), the reported two rooms' divider is.

use caustic::integrators::photon::wall_grid::{Listing, WallGrid, estimate_reach};
use caustic::integrators::photon::walls::Walls;
use caustic::render_scene::RenderScene;

use crate::common::root;

/// The scene file at `path` (relative to the repository), compiled.
fn scene(path: &str) -> RenderScene {
    let path = root().join(path);
    let file = caustic::scene::load::load(&path).expect("loads").scene;
    let dir = path.parent().expect("a folder");
    caustic::compile::compile(&file, dir).expect("compiles").0
}

/// The grid of `scene`'s walls for estimates of radius `radius` (the maps' reach, as
/// `PhotonMap::mark_walls` builds it), listing `listing`.
fn grid(scene: &RenderScene, radius: f32, listing: Listing) -> WallGrid {
    let bounds = scene.geometry.bvh.bounds;
    let far = bounds.min.abs().max(bounds.max.abs());
    WallGrid::build_listing(
        &Walls::of(scene, None),
        estimate_reach(far, radius),
        listing,
    )
    .expect("a grid")
}

#[test]
fn a_cornell_box_lists_no_wall_and_the_two_rooms_list_their_divider() {
    // Hand counts. scenes/cornell.ron: 10 wall triangles and 2 balls; at radius 0.05 nothing
    // lies beyond any wall, and the balls' points not parallel to the floor lie higher above
    // it than their lift: no triangle is a potential wall. The two rooms (a closed box
    // x ∈ [-2, 2], y ∈ [0, 2], z ∈ [-1, 1] of 12 triangles and the divider's 2 at x = 0,
    // overlapping the box by 0.2 m): the divider has floor on both sides, and the floor,
    // ceiling, front and back walls have the divider's overlap beyond them (10 triangles);
    // the end walls at x = ±2 have nothing beyond them within reach, nor has the light.
    let cornell = scene("scenes/cornell.ron");
    let every = grid(&cornell, 0.05, Listing::Every);
    let potential = grid(&cornell, 0.05, Listing::PotentialWalls);
    assert_eq!(every.candidate_counts().0, 10);
    assert_eq!(potential.candidate_counts().0, 0);
    assert!(potential.clear_cells() > every.clear_cells());
    let rooms = scene("tests/reported/thin-wall-photon-leak/two_rooms.ron");
    for r in [0.05, 0.2] {
        assert_eq!(grid(&rooms, r, Listing::Every).candidate_counts(), (14, 1));
        assert_eq!(
            grid(&rooms, r, Listing::PotentialWalls).candidate_counts(),
            (10, 0)
        );
    }
}

/// The counts docs/photon_map.md quotes (printed with `--nocapture`).
#[test]
fn potential_wall_counts() {
    // Every count is at most the full listing's; the bath keeps fewer than half its triangles.
    for (path, radius) in [
        ("scenes/cornell.ron", 0.05f32),
        ("scenes/bath.ron", 0.1),
        ("tests/reported/thin-wall-photon-leak/two_rooms.ron", 0.05),
    ] {
        let s = scene(path);
        for r in [radius, 2.0 * radius, 4.0 * radius] {
            let every = grid(&s, r, Listing::Every);
            let potential = grid(&s, r, Listing::PotentialWalls);
            assert!(potential.candidate_counts().0 <= every.candidate_counts().0);
            eprintln!(
                "{path} r {r}: every {:?} potential {:?} clear cells {} of {} (every: {})",
                every.candidate_counts(),
                potential.candidate_counts(),
                potential.clear_cells(),
                potential.cell_count(),
                every.clear_cells()
            );
        }
    }
}

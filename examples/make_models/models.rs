//! The bath scene's models as implicit surfaces: a rubber duck, a toy sailing boat and a
//! wall-mounted tub faucet.
//!
//! The toys face +x with +y up, in model units (the duck is about 1.2 long), with the origin on
//! the waterline they float at: translate them to the water's height and they sit partly
//! submerged. The faucet is in decimetres, its back on the wall plane z = 0, reaching out along
//! +z. Each OBJ group is its own closed surface; parts touching each other
//! (the beak in the head, the deck in the hull) overlap rather than share edges.

use glam::{DVec2, DVec3};

use super::mesher::{self, Part, PartSpec};
use super::sdf::{
    capsule, cylinder_y, cylinder_z, ellipsoid, rotate_z, round_box, smooth_intersection,
    smooth_union, sphere, triangle_2d,
};

fn v(x: f64, y: f64, z: f64) -> DVec3 {
    DVec3::new(x, y, z)
}

/// Centre and radius of the duck's head.
const HEAD: (DVec3, f64) = (DVec3::new(0.24, 0.56, 0.0), 0.215);

/// The duck's body and head, one smooth surface: an egg-shaped body with a flattened bottom, a
/// chest, a tail raised at the back, and a round head on a thick neck.
fn duck_body(p: DVec3) -> f64 {
    let body = ellipsoid(p, v(-0.02, 0.08, 0.0), v(0.5, 0.3, 0.37));
    let chest = ellipsoid(p, v(0.16, 0.1, 0.0), v(0.32, 0.27, 0.31));
    // The tail: a flattened ellipsoid at the back, tilted up by 45 degrees.
    let tail_at = v(-0.44, 0.31, 0.0);
    let tail = ellipsoid(rotate_z(p, tail_at, -45.0), tail_at, v(0.2, 0.085, 0.16));
    let (hc, hr) = HEAD;
    let head = ellipsoid(p, hc, v(hr, hr * 0.97, hr * 0.93));
    let torso = smooth_union(smooth_union(body, chest, 0.1), tail, 0.14);
    let duck = smooth_union(torso, head, 0.16);
    // A flat-ish bottom, so it sits in the water like the toy.
    smooth_intersection(duck, -(p.y + 0.17), 0.08)
}

/// The beak: a wide, flat bill tilted slightly down, its root inside the head.
fn duck_beak(p: DVec3) -> f64 {
    let at = v(0.44, 0.52, 0.0);
    ellipsoid(rotate_z(p, at, -6.0), at, v(0.17, 0.045, 0.12))
}

/// Unit direction from the head's centre to the eye on the `side` (+1 or −1) of the duck.
fn eye_direction(side: f64) -> DVec3 {
    v(0.62, 0.42, 0.66 * side).normalize()
}

/// Both eyes: small spheres half sunk into the head.
fn duck_eyes(p: DVec3) -> f64 {
    let (hc, hr) = HEAD;
    let r = 0.042;
    [1.0, -1.0]
        .map(|s| sphere(p, hc + eye_direction(s) * (hr * 0.93), r))
        .into_iter()
        .fold(f64::MAX, f64::min)
}

/// The rubber duck's parts, meshed and checked: `body`, `beak`, `eyes`.
pub fn duck() -> Result<Vec<Part>, Vec<String>> {
    let (hc, hr) = HEAD;
    let specs = [
        PartSpec {
            name: "body",
            sdf: &duck_body,
            bounds: (v(-0.62, -0.25, -0.4), v(0.52, 0.8, 0.4)),
            cell: 0.022,
            centre: v(0.0, 0.2, 0.0),
        },
        PartSpec {
            name: "beak",
            sdf: &duck_beak,
            bounds: (v(0.25, 0.43, -0.14), v(0.64, 0.63, 0.14)),
            cell: 0.012,
            centre: v(0.44, 0.52, 0.0),
        },
        PartSpec {
            name: "eyes",
            sdf: &duck_eyes,
            bounds: (hc - DVec3::splat(hr + 0.05), hc + DVec3::splat(hr + 0.05)),
            cell: 0.01,
            centre: hc,
        },
    ];
    mesh_all(&specs)
}

/// Half-width of the hull's deck outline at `(x, z)`: a pointed bow at +x and a flat transom
/// at the stern, from two intersecting circles (a vesica) cut by a plane; `inset` shrinks it.
fn hull_plan(x: f64, z: f64, inset: f64) -> f64 {
    let (r, d) = (1.105, 0.855);
    let left = DVec2::new(x + 0.1, z - d).length() - r;
    let right = DVec2::new(x + 0.1, z + d).length() - r;
    let stern = -x - 0.52;
    left.max(right).max(stern) + inset
}

/// The hull: the outline extruded, rounded underneath into a keel, flat on top.
fn boat_hull(p: DVec3) -> f64 {
    let plan = hull_plan(p.x, p.z, 0.0);
    let belly = ellipsoid(p, v(0.0, 0.14, 0.0), v(0.78, 0.34, 0.3));
    smooth_intersection(smooth_intersection(plan, belly, 0.06), p.y - 0.12, 0.03)
}

/// The deck: a plank platform on the hull, inset from its edge, its underside buried in it.
fn boat_deck(p: DVec3) -> f64 {
    let plan = hull_plan(p.x, p.z, 0.03);
    let slab = (p.y - 0.12).abs() - 0.028;
    smooth_intersection(plan, slab, 0.02)
}

/// The cabin: a rounded box towards the stern with a slightly wider flat roof.
fn boat_cabin(p: DVec3) -> f64 {
    let walls = round_box(p, v(-0.26, 0.24, 0.0), v(0.15, 0.1, 0.12), 0.02);
    let roof = round_box(p, v(-0.26, 0.355, 0.0), v(0.18, 0.015, 0.15), 0.012);
    smooth_union(walls, roof, 0.02)
}

/// The mast: a thin round pole standing on the deck ahead of the cabin.
fn boat_mast(p: DVec3) -> f64 {
    cylinder_y(p, 0.02, 0.0, 0.02, 0.1, 0.96, 0.008)
}

/// The sail: a thin triangle from the mast towards the bow, edges rounded.
fn boat_sail(p: DVec3) -> f64 {
    let tri = triangle_2d(
        DVec2::new(p.x, p.y),
        DVec2::new(0.055, 0.32),
        DVec2::new(0.055, 0.9),
        DVec2::new(0.48, 0.32),
    );
    let d = DVec2::new(tri, p.z.abs() - 0.014);
    d.max(DVec2::ZERO).length() + d.max_element().min(0.0) - 0.006
}

/// How far the boat's shapes (modelled with the hull's top at y = 0.12) are raised so that the
/// origin is on the waterline: a toy boat floats high, about a third of its hull under water.
const BOAT_LIFT: DVec3 = DVec3::new(0.0, 0.07, 0.0);

/// The toy boat's parts, meshed and checked: `hull`, `deck`, `cabin`, `mast`, `sail`.
pub fn boat() -> Result<Vec<Part>, Vec<String>> {
    let up = |p: DVec3| p + BOAT_LIFT;
    let hull = |p: DVec3| boat_hull(p - BOAT_LIFT);
    let deck = |p: DVec3| boat_deck(p - BOAT_LIFT);
    let cabin = |p: DVec3| boat_cabin(p - BOAT_LIFT);
    let mast = |p: DVec3| boat_mast(p - BOAT_LIFT);
    let sail = |p: DVec3| boat_sail(p - BOAT_LIFT);
    let specs = [
        PartSpec {
            name: "hull",
            sdf: &hull,
            bounds: (up(v(-0.56, -0.2, -0.3)), up(v(0.64, 0.14, 0.3))),
            cell: 0.02,
            centre: up(v(0.0, 0.05, 0.0)),
        },
        PartSpec {
            name: "deck",
            sdf: &deck,
            bounds: (up(v(-0.56, 0.07, -0.3)), up(v(0.64, 0.17, 0.3))),
            cell: 0.02,
            centre: up(v(0.0, 0.12, 0.0)),
        },
        PartSpec {
            name: "cabin",
            sdf: &cabin,
            bounds: (up(v(-0.47, 0.1, -0.2)), up(v(-0.05, 0.39, 0.2))),
            cell: 0.02,
            centre: up(v(-0.26, 0.24, 0.0)),
        },
        PartSpec {
            name: "mast",
            sdf: &mast,
            bounds: (up(v(-0.02, 0.08, -0.04)), up(v(0.06, 0.98, 0.04))),
            cell: 0.01,
            centre: up(v(0.02, 0.5, 0.0)),
        },
        PartSpec {
            name: "sail",
            sdf: &sail,
            bounds: (up(v(0.03, 0.29, -0.03)), up(v(0.52, 0.93, 0.03))),
            cell: 0.011,
            centre: up(v(0.2, 0.48, 0.0)),
        },
    ];
    mesh_all(&specs)
}

/// x of the two handles' axes, either side of the spout (decimetres).
const HANDLE_X: f64 = 1.6;

/// The faucet's wall plates: a round escutcheon behind the spout and a smaller rosette behind
/// each handle, thin discs with rounded edges, backs on the wall.
fn faucet_escutcheon(p: DVec3) -> f64 {
    let centre = cylinder_z(p, 0.0, 0.0, 0.55, 0.0, 0.12, 0.04);
    let rosettes = [-HANDLE_X, HANDLE_X].map(|x| cylinder_z(p, x, 0.0, 0.38, 0.0, 0.1, 0.035));
    centre.min(rosettes[0]).min(rosettes[1])
}

/// The spout: a neck out of the escutcheon, a round tube reaching 1.5 dm from the wall, turning
/// down into a short vertical nozzle with a flat mouth.
fn faucet_spout(p: DVec3) -> f64 {
    let neck = cylinder_z(p, 0.0, 0.0, 0.28, 0.05, 0.45, 0.05);
    let tube = capsule(p, v(0.0, 0.0, 0.3), v(0.0, 0.0, 1.42), 0.2);
    let bend = capsule(p, v(0.0, 0.0, 1.42), v(0.0, -0.3, 1.6), 0.18);
    let nozzle = cylinder_y(p, 0.0, 1.6, 0.19, -0.55, -0.25, 0.04);
    smooth_union(
        smooth_union(smooth_union(neck, tube, 0.08), bend, 0.08),
        nozzle,
        0.06,
    )
}

/// One lever handle on the axis `x`: a stem out of its rosette, a hub, and a lever rising from
/// the hub with a ball at its tip.
fn faucet_handle(p: DVec3, x: f64) -> f64 {
    let stem = cylinder_z(p, x, 0.0, 0.14, 0.05, 0.5, 0.03);
    let hub = cylinder_z(p, x, 0.0, 0.23, 0.38, 0.62, 0.07);
    let lever = capsule(p, v(x, 0.0, 0.52), v(x, 0.72, 0.62), 0.08);
    let tip = sphere(p, v(x, 0.76, 0.62), 0.11);
    smooth_union(
        smooth_union(smooth_union(stem, hub, 0.05), lever, 0.06),
        tip,
        0.05,
    )
}

/// Both handles, either side of the spout.
fn faucet_handles(p: DVec3) -> f64 {
    faucet_handle(p, -HANDLE_X).min(faucet_handle(p, HANDLE_X))
}

/// The faucet's parts, meshed and checked: `escutcheon`, `spout`, `handles`.
pub fn faucet() -> Result<Vec<Part>, Vec<String>> {
    let specs = [
        PartSpec {
            name: "escutcheon",
            sdf: &faucet_escutcheon,
            bounds: (v(-2.0, -0.58, -0.02), v(2.0, 0.58, 0.14)),
            cell: 0.03,
            centre: v(0.0, 0.0, 0.06),
        },
        PartSpec {
            name: "spout",
            sdf: &faucet_spout,
            bounds: (v(-0.32, -0.58, 0.02), v(0.32, 0.32, 1.82)),
            cell: 0.03,
            centre: v(0.0, 0.0, 0.9),
        },
        PartSpec {
            name: "handles",
            sdf: &faucet_handles,
            bounds: (v(-1.86, -0.26, 0.02), v(1.86, 0.9, 0.76)),
            cell: 0.025,
            centre: v(0.0, 0.2, 0.4),
        },
    ];
    mesh_all(&specs)
}

/// Meshes and checks every part; all problems of all parts if any.
fn mesh_all(specs: &[PartSpec]) -> Result<Vec<Part>, Vec<String>> {
    let mut parts = Vec::new();
    let mut problems = Vec::new();
    for spec in specs {
        let part = mesher::mesh_part(spec);
        if let Err(p) = mesher::check(&part) {
            problems.extend(p);
        }
        parts.push(part);
    }
    if problems.is_empty() {
        Ok(parts)
    } else {
        Err(problems)
    }
}

/// The duck as OBJ text.
pub fn duck_obj() -> Result<String, Vec<String>> {
    Ok(mesher::write_obj(
        "A rubber duck (groups body, beak, eyes), facing +x, y up, origin on its waterline.\n\
         Generated by `scripts/make_models.sh` (examples/make_models): do not edit.",
        &duck()?,
    ))
}

/// The boat as OBJ text.
pub fn boat_obj() -> Result<String, Vec<String>> {
    Ok(mesher::write_obj(
        "A toy sailing boat (groups hull, deck, cabin, mast, sail), bow towards +x, y up,\n\
         origin on its waterline. Generated by `scripts/make_models.sh` (examples/make_models): do not edit.",
        &boat()?,
    ))
}

/// The faucet as OBJ text.
pub fn faucet_obj() -> Result<String, Vec<String>> {
    Ok(mesher::write_obj(
        "A wall-mounted tub faucet (groups escutcheon, spout, handles), in decimetres: back on\n\
         the wall plane z = 0, spout along +z, y up. Generated by `scripts/make_models.sh` (examples/make_models): do not edit.",
        &faucet()?,
    ))
}

"""Mitsuba 3 renders of the issue #25 comparison scenes, one per light (and the thin lens).

Use:  /root/.cache/mitsuba3-venv/bin/python scripts/mitsuba/lights.py SCENE [--spp N] [-o out.exr]
      SCENE ∈ quad, mesh, spot, sun, env_constant, env_image, thin_lens, disc_cylinder (or `all`).

Every scene: 96×72 pixels, a floor y = 0 (Lambert 0.5), a grey sphere (Lambert 0.7, radius 0.5
at (0, 0.5, 0)), camera at (0, 2, 5) looking at (0, 0.5, 0), fov_y 40°, path tracing with
max_depth 6 (caustic: 5 bounces). Caustic's twins are `scripts/mitsuba/scenes/lights_*.ron`;
`scripts/mitsuba/lights_compare.py` renders both and compares them.

Convention differences and how each scene neutralises them:
  quad         Mitsuba's `rectangle` + `area` emitter is one-sided along its +z normal, radiance
               L; caustic's one-sided quad emits along edge_u × edge_v with the same L. The
               mapping is common.rect_to_world (no difference left).
  mesh         A triangle fan (32 triangles, a disc of radius 0.4 at y = 2.2 facing down),
               scripts/mitsuba/scenes/fan.obj (both renderers read it), loaded with face
               normals; one-sided by winding in both.
  spot         Mitsuba's `spot` falls off LINEARLY IN ANGLE from beam_width to cutoff_angle;
               caustic (pbrt-v4) uses smoothstep in COSINE between the outer and inner cones.
               The two agree inside the inner cone and outside the outer one, so the scene uses
               inner 25°, outer 25.5° (a 0.5° band, < 1 % of the lit floor's area: its
               remaining difference is far below the 1 % mean tolerance) — or compare only
               the pixels inside the inner cone. Mitsuba's `intensity` is caustic's I (W/sr).
  sun          Mitsuba's `directional` has no angular radius, so the sun of angular radius α is
               an `area`-emitting sphere of radius r = D sin α at distance D = 1e5 in the sun's
               direction, radiance L = E / (π sin²α) (caustic's relation E = π L sin²α). For
               α = 0 use `directional` with `irradiance` = E (same meaning as caustic's).
               The sphere is sampled by Mitsuba as a sphere emitter, not as a cone; only noise
               differs.
  env_constant Mitsuba's `constant` emitter, radiance L: identical meaning.
  env_image    Mitsuba's `envmap`: same equirectangular convention (u = atan2(x, −z)/2π,
               v = acos(y)/π, +y up, row 0 at the zenith); a rotation about +y is
               to_world = rotate([0, 1, 0], degrees), the same direction as caustic's rotation.
               Texel positions differ in v (measured with a one-hot map): caustic's texel
               (i, j) is centred at ((i + ½)/w, (j + ½)/h), Mitsuba's at ((i + ½)/w, j/(h − 1))
               (rows from pole to pole). mitsuba_sky() resamples assets/sky.exr so that
               Mitsuba's lookup is caustic's map. Mitsuba's envmap `scale` = 1.
  thin_lens    Mitsuba's `thinlens` takes aperture_radius and focus_distance (distance along
               the view axis to the plane of focus) with the same meaning as caustic's lens
               radius and focus distance; the lens is a disc in both (sampling patterns differ:
               Mitsuba warps square_to_uniform_disk_concentric too). Lit by the quad light.
"""
import math
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
W, H = 96, 72
EYE, LOOK, FOV = [0, 2, 5], [0, 0.5, 0], 40.0


def base(mi, spp, seed, lens=None):
    return {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": 6},
        "sensor": common.sensor(mi, EYE, LOOK, FOV, W, H, spp, seed, lens),
        "floor": common.floor(mi),
        "ball": {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "bsdf": common.diffuse([0.7, 0.7, 0.7])},
    }


def quad_light(mi):
    # 1 × 0.6 panel at y = 2.5 facing down, L = 8: caustic corner (-0.5, 2.5, -0.3),
    # edge_u (1, 0, 0), edge_v (0, 0, 0.6) (normal (1,0,0) × (0,0,0.6) = −y).
    return {"type": "rectangle", "bsdf": common.black(),
            "to_world": common.rect_to_world(mi, [-0.5, 2.5, -0.3], [1, 0, 0], [0, 0, 0.6]),
            "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [8, 8, 8]}}}


def scene_quad(mi, spp, seed):
    """A one-sided quad area light over the floor and sphere."""
    d = base(mi, spp, seed)
    d["panel"] = quad_light(mi)
    return d


def scene_mesh(mi, spp, seed):
    """An emissive triangle fan (a disc of radius 0.4 at y = 2.2, facing down, L = 10)."""
    # scenes/fan.obj, shared with caustic's twin: 32 triangles (centre, v_k, v_k+1) with
    # v_k = (r cos 2πk/n, h, r sin 2πk/n), winding normal −y.
    obj = Path(__file__).resolve().parent / "scenes" / "fan.obj"
    d = base(mi, spp, seed)
    d["fan"] = {"type": "obj", "filename": str(obj), "face_normals": True, "bsdf": common.black(),
                "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [10, 10, 10]}}}
    return d


def scene_spot(mi, spp, seed):
    """A spot at (0, 3, 1) aimed at (0, 0, 0), I = 20 W/sr, cone 25° (fall-off band 0.5°)."""
    d = base(mi, spp, seed)
    d["spot"] = {"type": "spot", "intensity": {"type": "rgb", "value": [20, 20, 20]},
                 "cutoff_angle": 25.5, "beam_width": 25.0,
                 "to_world": mi.ScalarTransform4f().look_at(origin=[0, 3, 1], target=[0, 0, 0], up=[0, 1, 0])}
    return d


SUN_DIR = [0.4, 0.8, 0.3]   # towards the sun (normalised below)
SUN_E = 5.0                 # W/m² on a surface facing it
SUN_ALPHA = math.radians(0.2665)
SUN_WIDE_ALPHA = math.radians(3.0)  # `sun_wide`: Mitsuba samples the far sphere's cone in f32,
                            # where 1 − cos α = 1.1e-5 for the real sun carries a ~0.3 % error;
                            # at 3° it is 1.4e-3 and the error ~5e-5
SUN_DISTANCE = 1e5          # the far sphere's distance: the ±4 m scene shifts its direction by
                            # 4e-5 rad (0.9 % of α) and its irradiance by 1e-4


def scene_sun(mi, spp, seed, alpha=SUN_ALPHA):
    """A sun of irradiance 5 W/m² and angular radius 0.2665° (a far emitting sphere)."""
    d = base(mi, spp, seed)
    s = [c / math.sqrt(sum(x * x for x in SUN_DIR)) for c in SUN_DIR]
    if alpha == 0:
        d["sun"] = {"type": "directional", "direction": [-c for c in s],
                    "irradiance": {"type": "rgb", "value": [SUN_E] * 3}}
        return d
    dist = SUN_DISTANCE
    radiance = SUN_E / (math.pi * math.sin(alpha) ** 2)
    d["sun"] = {"type": "sphere", "center": [c * dist for c in s], "radius": dist * math.sin(alpha),
                "bsdf": common.black(),
                "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [radiance] * 3}}}
    return d


def scene_env_constant(mi, spp, seed):
    """A constant environment of radiance 1 (a white furnace for the sphere's top)."""
    d = base(mi, spp, seed)
    d["sky"] = {"type": "constant", "radiance": {"type": "rgb", "value": [1, 1, 1]}}
    return d


def mitsuba_sky(mi, oversample=8):
    """assets/sky.exr resampled for Mitsuba's `envmap`, whose rows sit at v = j/(h − 1) (row 0
    exactly at the zenith, the last row at the nadir; measured with a one-hot map), where
    caustic's sit at texel centres v = (j + ½)/h and clamp beyond the first and last centre
    (columns agree: u = (i + ½)/w in both). Row k of the result, at v_k = k/(h' − 1) with
    h' = oversample·h + 1, holds caustic's interpolant at v_k, so Mitsuba's bilinear lookup
    reproduces caustic's map up to the knots' offsets inside one fine row. Written under the
    temp folder; returns its path."""
    import tempfile
    import numpy as np
    src = np.array(mi.Bitmap(str(ROOT / "assets" / "sky.exr")), dtype=np.float64)[..., :3]
    h = src.shape[0]
    rows = oversample * h + 1
    t = np.clip(np.arange(rows) / (rows - 1) * h - 0.5, 0.0, h - 1.0)
    j0 = np.minimum(np.floor(t).astype(int), h - 2)
    f = (t - j0)[:, None, None]
    out = (1.0 - f) * src[j0] + f * src[j0 + 1]
    path = Path(tempfile.gettempdir()) / "caustic_mitsuba_sky.exr"
    mi.Bitmap(out.astype(np.float32)).write(str(path))
    return path


def scene_env_image(mi, spp, seed, rotation_deg=30.0):
    """assets/sky.exr as an environment, rotated 30° about +y."""
    d = base(mi, spp, seed)
    d["sky"] = {"type": "envmap", "filename": str(mitsuba_sky(mi)),
                "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], rotation_deg)}
    return d


def scene_thin_lens(mi, spp, seed):
    """The quad-light scene through a thin lens (radius 0.1, focused on the sphere's front)."""
    focus = math.dist(EYE, [0, 0.5, 0.5])
    d = base(mi, spp, seed, lens=(0.1, focus))
    d["panel"] = quad_light(mi)
    return d


def scene_disc_cylinder(mi, spp, seed):
    """Issue 41: a disc area light (radius 0.4 at y = 2.2 facing down, L = 10: Mitsuba's `disk`
    with an `area` emitter, one-sided along its +z normal turned to −y, as caustic's `Disc`) over
    the floor, the sphere and an open cylinder (Mitsuba's `cylinder` has no caps; caustic's
    `Cylinder` without `caps`): radius 0.3 from (1.2, 0, 0) to (1.2, 0.8, 0), Lambert 0.7
    two-sided, its inside seen from above."""
    d = base(mi, spp, seed)
    d["disc"] = {"type": "disk", "bsdf": common.black(),
                 "to_world": mi.ScalarTransform4f().translate([0, 2.2, 0]).rotate([1, 0, 0], 90).scale(0.4),
                 "emitter": {"type": "area", "radiance": {"type": "rgb", "value": [10, 10, 10]}}}
    d["column"] = {"type": "cylinder", "p0": [1.2, 0, 0], "p1": [1.2, 0.8, 0], "radius": 0.3,
                   "bsdf": common.diffuse([0.7, 0.7, 0.7])}
    return d


SCENES = {
    "quad": scene_quad, "mesh": scene_mesh, "spot": scene_spot, "sun": scene_sun,
    "sun_wide": lambda mi, spp, seed: scene_sun(mi, spp, seed, alpha=SUN_WIDE_ALPHA),
    "env_constant": scene_env_constant, "env_image": scene_env_image, "thin_lens": scene_thin_lens,
    "disc_cylinder": scene_disc_cylinder,
}


if __name__ == "__main__":
    if len(sys.argv) < 2 or sys.argv[1] not in list(SCENES) + ["all"]:
        sys.exit(f"usage: {sys.argv[0]} {{{','.join(SCENES)},all}} [--spp N] [--seed S] [--threads T] [-o out.exr]")
    which = sys.argv.pop(1)
    names = list(SCENES) if which == "all" else [which]
    import argparse
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("-o", "--out", default=None, help="EXR path (default /tmp/mitsuba_<scene>.exr)")
    a = ap.parse_args()
    for name in names:
        out = a.out if (a.out and len(names) == 1) else f"/tmp/mitsuba_{name}.exr"
        common.render(lambda mi, f=SCENES[name]: f(mi, a.spp, a.seed), a.spp, out, a.threads, a.seed)

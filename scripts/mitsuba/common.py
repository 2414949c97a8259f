"""Shared set-up for the issue #25 Mitsuba 3 comparison scenes (lights and the thin lens).

Mitsuba is the independent renderer the new lights are checked against (phase 2 renders the
same scenes with caustic's `path` and default integrators and compares image means and 8×8-block
z-tests). The set-up follows /work/shared/bench/mitsuba/render.py: the llvm_ad_rgb variant, a
perspective sensor with the fov on y, a one-pixel box filter and a float32 RGB film, two threads.

Interpreter: /root/.cache/mitsuba3-venv/bin/python (see shared/bench/mitsuba/setup.sh).
Outputs go wherever --out says; keep the EXRs out of git (under /tmp or target/).

Conventions shared by every scene (caustic's, chosen so no remapping is needed):
  - metres, +y up, right-handed; the floor is the plane y = 0, a two-sided Lambert of albedo
    0.5 (Mitsuba: twosided diffuse);
  - max_depth: caustic's bounce count n is Mitsuba's max_depth n + 1 (Mitsuba counts segments);
  - one-sided emitters: Mitsuba's area emitter is one-sided, along the shape's normal, like
    caustic's one-sided quads and meshes.
"""
import glob
import os
import re
import time


def find_libllvm():
    """Newest libLLVM for Dr.Jit's LLVM backend (as in shared/bench/mitsuba/render.py)."""
    if os.environ.get("DRJIT_LIBLLVM_PATH"):
        return os.environ["DRJIT_LIBLLVM_PATH"]
    found = []
    for pat in ("/usr/lib/*/libLLVM*.so*", "/usr/lib/llvm-*/lib/libLLVM*.so*", "/usr/lib/libLLVM*.so*"):
        found += [p for p in glob.glob(pat) if os.path.isfile(p)]

    def major(p):
        m = re.search(r"libLLVM(?:-|\.so\.)(\d+)", os.path.basename(p)) or re.search(r"llvm-(\d+)/", p)
        return int(m.group(1)) if m else 0

    return max(found, key=major) if found else None


def mitsuba(threads=2):
    """Imports Mitsuba with the RGB LLVM variant and `threads` worker threads."""
    lib = find_libllvm()
    if lib:
        os.environ["DRJIT_LIBLLVM_PATH"] = lib
    import drjit as dr
    import mitsuba as mi
    mi.set_variant("llvm_ad_rgb")
    dr.set_thread_count(threads)
    return mi, dr


def diffuse(albedo):
    """caustic's Lambert material: two-sided diffuse."""
    return {"type": "twosided", "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": albedo}}}


def black():
    """The surface of an emitter: reflects nothing."""
    return {"type": "diffuse", "reflectance": {"type": "rgb", "value": [0, 0, 0]}}


def rect_to_world(mi, corner, edge_u, edge_v):
    """Mitsuba's `rectangle` spans [-1, 1]² in z = 0 with normal +z; this maps it onto
    caustic's quad `corner + s·edge_u + t·edge_v`, whose normal is edge_u × edge_v."""
    import numpy as np
    c, eu, ev = (np.array(v, float) for v in (corner, edge_u, edge_v))
    n = np.cross(eu, ev)
    n /= np.linalg.norm(n)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2] = eu / 2, ev / 2, n
    m[:3, 3] = c + eu / 2 + ev / 2
    return mi.ScalarTransform4f(m.tolist())


def floor(mi, half=4.0, albedo=(0.5, 0.5, 0.5)):
    """The floor y = 0, a (2·half)² square facing +y."""
    return {"type": "rectangle", "bsdf": diffuse(list(albedo)),
            "to_world": rect_to_world(mi, [-half, 0, half], [2 * half, 0, 0], [0, 0, -2 * half])}


def sensor(mi, eye, look_at, fov_y, width, height, spp, seed=0, lens=None):
    """A perspective sensor (fov on y) or, with lens=(aperture_radius, focus_distance), a thin
    lens (`thinlens`: aperture_radius and focus_distance, the same meaning as caustic's)."""
    d = {
        "type": "perspective", "fov": fov_y, "fov_axis": "y",
        "near_clip": 1e-3, "far_clip": 1e4,
        "to_world": mi.ScalarTransform4f().look_at(origin=eye, target=look_at, up=[0, 1, 0]),
        "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
        "film": {"type": "hdrfilm", "width": width, "height": height, "pixel_format": "rgb",
                 "component_format": "float32", "rfilter": {"type": "box"}},
    }
    if lens is not None:
        d["type"] = "thinlens"
        d["aperture_radius"], d["focus_distance"] = lens
    return d


def render(scene_dict, spp, out, threads=2, seed=0):
    """Renders and writes `out` (EXR); prints one line with the image mean."""
    mi, dr = mitsuba(threads)
    t0 = time.time()
    scene = mi.load_dict(scene_dict(mi))
    img = mi.render(scene, spp=spp, seed=seed)
    dr.eval(img)
    mi.Bitmap(img).write(out)
    import numpy as np
    a = np.array(img)
    print(f"mitsuba {mi.__version__} spp={spp} out={out} mean_rgb={a.reshape(-1, 3).mean(0).round(6).tolist()} "
          f"seconds={time.time() - t0:.1f}")


"""Mitsuba 3 `volpath` render of benches/scenes/foggy_box.ron (issue 44): a box of five
two-sided Lambert quads filled with homogeneous fog (the camera's medium, and every shape's
exterior), a diffuse ball, a sphere light, no refractive boundaries.

Use:  /root/.cache/mitsuba3-venv/bin/python scripts/mitsuba/foggy_box.py [--spp N] [-o out.exr]
          [--width W --height H] [--seed S] [--pass-spp P] [--threads T]
Then: caustic render benches/scenes/foggy_box.ron --integrator path --spp N -o caustic.exr
      caustic compare caustic.exr out.exr           (mean, bias per channel)

Mapping (caustic → Mitsuba):
  fog        sigma_a, sigma_s per channel → `homogeneous` with sigma_t = σa + σs and
             albedo = σs/σt per channel, phase `hg` with the same g (the same convention: g > 0
             forward).
  light      caustic's Sphere light of power Φ emits radiance L = Φ / (4π² r²) from its surface
             (Φ = π L · 4π r²): an `area` emitter on a sphere, with a black BSDF. It sits in
             the fog (exterior medium).
  max_depth  caustic counts bounces (64), Mitsuba segments: 65. Mitsuba counts medium
             interactions in max_depth as caustic does.
  camera     the sensor's medium is the fog, as caustic's scene-wide `medium`.
"""
import argparse
import math
import os
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

SIGMA_A = [0.02, 0.02, 0.02]
SIGMA_S = [0.25, 0.27, 0.3]
G = 0.3
LIGHT_POWER = [60.0, 55.0, 45.0]
LIGHT_CENTER, LIGHT_RADIUS = [0.3, 1.6, -0.2], 0.1


def scene(mi, spp, width=320, height=320, seed=0):
    sigma_t = [a + s for a, s in zip(SIGMA_A, SIGMA_S)]
    albedo = [s / t for s, t in zip(SIGMA_S, sigma_t)]
    fog = {"type": "ref", "id": "fog"}

    def quad(corner, eu, ev, albedo):
        return {"type": "rectangle", "bsdf": common.diffuse(albedo),
                "to_world": common.rect_to_world(mi, corner, eu, ev), "exterior": fog}

    white, red, green = [0.7] * 3, [0.6, 0.1, 0.08], [0.12, 0.5, 0.15]
    radiance = [p / (4 * math.pi ** 2 * LIGHT_RADIUS ** 2) for p in LIGHT_POWER]
    sensor = common.sensor(mi, [0, 1, 3.4], [0, 1, 0], 40, width, height, spp, seed=seed)
    sensor["medium"] = fog
    return {
        "type": "scene",
        "integrator": {"type": "volpath", "max_depth": 65},
        "fog": {"type": "homogeneous", "sigma_t": {"type": "rgb", "value": sigma_t},
                "albedo": {"type": "rgb", "value": albedo}, "scale": 1.0,
                "phase": {"type": "hg", "g": G}},
        "sensor": sensor,
        "floor": quad([-1, 0, 1], [2, 0, 0], [0, 0, -2], white),
        "ceiling": quad([-1, 2, -1], [2, 0, 0], [0, 0, 2], white),
        "back": quad([-1, 0, -1], [2, 0, 0], [0, 2, 0], white),
        "left": quad([-1, 0, 1], [0, 0, -2], [0, 2, 0], red),
        "right": quad([1, 0, -1], [0, 0, 2], [0, 2, 0], green),
        "ball": {"type": "sphere", "center": [-0.35, 0.35, 0.1], "radius": 0.35,
                 "bsdf": common.diffuse([0.8, 0.75, 0.5]), "exterior": fog},
        "light": {"type": "sphere", "center": LIGHT_CENTER, "radius": LIGHT_RADIUS,
                  "bsdf": common.black(), "exterior": fog,
                  "emitter": {"type": "area", "radiance": {"type": "rgb", "value": radiance}}},
    }


def render_passes(a):
    """Renders `a.spp` samples per pixel in passes of at most `a.pass_spp` (Mitsuba's LLVM
    variant holds a whole pass's samples as one wavefront, so long references go in passes),
    each pass with its own seed (`a.seed` · 1000 + pass), averaged. Prints the image mean and
    the CPU seconds (user + sys of this process, `resource.getrusage`) of the render calls
    alone — scene loading and the module import are not counted, the JIT compilation of the
    kernels is."""
    import resource

    import numpy as np
    mi, dr = common.mitsuba(a.threads)
    t0 = time.time()
    spp_pass = max(1, min(a.spp, a.pass_spp))
    passes = []
    left = a.spp
    while left > 0:
        passes.append(min(spp_pass, left))
        left -= passes[-1]
    sc = mi.load_dict(scene(mi, spp_pass, a.width, a.height, a.seed))

    def cpu():
        r = resource.getrusage(resource.RUSAGE_SELF)
        return r.ru_utime + r.ru_stime

    c0 = cpu()
    acc = None
    for i, n in enumerate(passes):
        img = mi.render(sc, spp=n, seed=a.seed * 1000 + i)
        dr.eval(img)
        x = np.array(img, dtype=np.float64) * n
        acc = x if acc is None else acc + x
    cpu_s = cpu() - c0
    acc /= a.spp
    mi.Bitmap(acc.astype(np.float32)).write(a.out)
    print(f"mitsuba {mi.__version__} spp={a.spp} passes={len(passes)} out={a.out} "
          f"mean_rgb={acc.reshape(-1, 3).mean(0).round(6).tolist()} cpu_s={cpu_s:.2f} "
          f"seconds={time.time() - t0:.1f}")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("-o", "--out", default="/tmp/foggy_box.mitsuba.exr")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--width", type=int, default=320)
    ap.add_argument("--height", type=int, default=320)
    ap.add_argument("--seed", type=int, default=0)
    ap.add_argument("--pass-spp", type=int, default=256)
    render_passes(ap.parse_args())


if __name__ == "__main__":
    main()

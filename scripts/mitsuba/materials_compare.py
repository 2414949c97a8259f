"""Issue #26's agreement table: rough chrome, rough gold, frosted glass (roughness 0.1 and 0.5)
and absorbing water, each rendered by Mitsuba 3 and by caustic's path tracer, compared by image
mean and by an 8×8-block z-test.

Use (from the repository root):
    /root/.cache/mitsuba3-venv/bin/python scripts/mitsuba/materials_compare.py \
        [--spp 256] [--seeds 4] [--caustic target/release/caustic] [--out /tmp/materials_compare] [SCENE…]

Each scene of scripts/mitsuba/materials.py is rendered `--seeds` times by Mitsuba (seeds
0…K−1) and `--seeds` times by caustic's twin scripts/mitsuba/scenes/materials_<scene>.ron with
`--integrator path` (seeds 1…K), each at `--spp` samples per pixel; the figures are those of
scripts/mitsuba/lights_compare.py (same functions): the image-mean ratio − 1 with its standard
error, and the 8×8-block z-test's χ²/dof (≈ 1 when the images differ by noise only; its own sd
is sqrt(2/dof)), the largest |z|, and the deterministic blocks (only emitter or environment
seen) by their largest relative difference. Also printed per scene: the mean over the sphere's
blocks only (the 8×8 blocks whose centre pixel sees the ball), where the material is, and over
its rim (view cosine < 0.4), where the Smith masking conventions differ; and, as the z-test's
noise-only baseline, its χ²/dof between the two halves of each renderer's own seeds.
`--reuse` recomputes the table from the renders an earlier run saved in --out.
Prints a Markdown table (the one in docs/material_agreement.md). Correctness only: no timings.
"""
import argparse
import os
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402
import lights_compare as lc  # noqa: E402
import materials  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
RIM_COS = 0.4


def mitsuba_runs(mi, dr, name, spp, seeds):
    """K Mitsuba renders of `name`, as an array (K, H, W, 3)."""
    scene = mi.load_dict(materials.SCENES[name](mi, spp, 0))
    out = []
    for s in range(seeds):
        img = mi.render(scene, spp=spp, seed=s)
        dr.eval(img)
        out.append(np.array(img, dtype=np.float64)[..., :3])
    return np.stack(out)


def caustic_runs(mi, binary, name, spp, seeds, out_dir):
    """K caustic `path` renders of the twin scene."""
    import subprocess
    twin = name.removesuffix("_hc")   # the `_hc` scenes change Mitsuba's side only
    scene = ROOT / "scripts" / "mitsuba" / "scenes" / f"materials_{twin}.ron"
    imgs = []
    for s in range(seeds):
        out = out_dir / f"caustic_{name}_{s}.exr"
        cmd = [binary, "render", str(scene), "-o", str(out), "--spp", str(spp), "--seed", str(s + 1),
               "--quiet", "--integrator", "path"]
        subprocess.run(cmd, check=True, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        imgs.append(lc.read_exr(mi, out))
    return np.stack(imgs)


def ball_cosines():
    """Per pixel centre, the cosine between the camera ray and the ball's normal where the ray
    meets the ball (analytic ray–sphere test), NaN where it misses."""
    import math
    w, h = 96, 72
    eye, look = np.array(materials.lights.EYE, float), np.array(materials.lights.LOOK, float)
    fwd = (look - eye) / np.linalg.norm(look - eye)
    right = np.cross(fwd, [0, 1, 0])
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    t = math.tan(math.radians(materials.FOV) / 2)
    cos = np.full((h, w), np.nan)
    c, r = np.array([0, 0.5, 0.0]), 0.5
    for j in range(h):
        for i in range(w):
            x = (2 * (i + 0.5) / w - 1) * t * w / h
            y = (1 - 2 * (j + 0.5) / h) * t
            d = fwd + x * right + y * up
            d /= np.linalg.norm(d)
            oc = eye - c
            b = oc @ d
            disc = b * b - (oc @ oc - r * r)
            if disc > 0:
                p = eye + (-b - math.sqrt(disc)) * d
                cos[j, i] = -((p - c) / r) @ d
    return cos


def ball_mean(c_runs, m_runs, mask):
    """caustic/Mitsuba − 1 of the mean over the pixels of `mask`, with its standard error."""
    cm, cv = lc.mean_and_var(c_runs)
    mm, mv = lc.mean_and_var(m_runs)
    n = mask.sum()
    rel = cm[mask].mean() / mm[mask].mean() - 1.0
    se = np.sqrt(cv[mask].sum() / n**2 + mv[mask].sum() / n**2) / mm[mask].mean()
    return rel, se


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="*", default=list(materials.SCENES),
                    help="default: all, the `_hc` scenes (Mitsuba with height-correlated masking) included")
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--caustic", default=os.environ.get("CAUSTIC_BIN", str(ROOT / "target" / "release" / "caustic")))
    ap.add_argument("--out", default="/tmp/materials_compare")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--reuse", action="store_true",
                    help="read the renders saved in --out by an earlier run instead of rendering")
    a = ap.parse_args()
    out_dir = Path(a.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    mi, dr = common.mitsuba(a.threads)
    cos = ball_cosines()
    mask = ~np.isnan(cos)
    # The rim: the ball seen at grazing angles (view cosine below 0.4), where the microfacet
    # masking conventions differ most (docs/material_agreement.md).
    rim = mask & (np.nan_to_num(cos, nan=1.0) < RIM_COS)
    print(f"Mitsuba {mi.__version__}, {a.seeds} × {a.spp} spp per side, 96×72, 8×8 blocks; "
          f"ball: {mask.sum()} pixels, of which {rim.sum()} are its rim (view cosine < {RIM_COS})")
    print()
    print("| scene | image mean (Mitsuba) | caustic/Mitsuba − 1 (± se) | ball pixels: caustic/Mitsuba − 1 (± se) "
          "| rim: caustic/Mitsuba − 1 (± se) | z8 χ²/dof (dof) | z8 between halves: caustic, Mitsuba "
          "| max \\|z\\| | deterministic blocks: count, max rel. diff |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name in a.scenes:
        if a.reuse:
            m_runs = np.load(out_dir / f"mitsuba_{name}.npy")
            c_runs = np.load(out_dir / f"caustic_{name}.npy")
        else:
            m_runs = mitsuba_runs(mi, dr, name, a.spp, a.seeds)
            c_runs = caustic_runs(mi, a.caustic, name, a.spp, a.seeds, out_dir)
            np.save(out_dir / f"mitsuba_{name}.npy", m_runs)
            np.save(out_dir / f"caustic_{name}.npy", c_runs)
        r = lc.compare(c_runs, m_runs)
        # The statistic's own baseline: the same z-test between the two halves of one renderer's
        # seeds (noise only by construction). Heavy-tailed pixels (light through a caustic) make
        # the estimated variances noisy, which lifts χ²/dof above 1 even without any bias.
        k = len(c_runs) // 2
        self_c = lc.compare(c_runs[:k], c_runs[k:2 * k])["chi2_dof"]
        self_m = lc.compare(m_runs[:k], m_runs[k:2 * k])["chi2_dof"]
        b, bse = ball_mean(c_runs, m_runs, mask)
        q, qse = ball_mean(c_runs, m_runs, rim)
        print(f"| {name} | {r['mean_c']:.5f} ({r['mean_m']:.5f}) | "
              f"{100 * r['rel']:+.2f}% (± {100 * r['rel_se']:.2f}%) | {100 * b:+.2f}% (± {100 * bse:.2f}%) | "
              f"{100 * q:+.2f}% (± {100 * qse:.2f}%) | "
              f"{r['chi2_dof']:.2f} ({r['dof']}) | {self_c:.2f}, {self_m:.2f} | {r['max_z']:.1f} | "
              f"{r['det']}, {r['det_diff']:.1e} |", flush=True)


if __name__ == "__main__":
    main()

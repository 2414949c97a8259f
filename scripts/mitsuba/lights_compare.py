"""Issue #25's agreement table: each light (and the thin lens) rendered by Mitsuba 3 and by
caustic, compared by image mean and by an 8×8-block z-test.

Use (from the repository root):
    /root/.cache/mitsuba3-venv/bin/python scripts/mitsuba/lights_compare.py \
        [--spp 256] [--seeds 4] [--caustic target/release/caustic] [--out /tmp/lights_compare] [SCENE…]

Each scene of scripts/mitsuba/lights.py is rendered `--seeds` times by Mitsuba (seeds 0…K−1) and
`--seeds` times by caustic's twin scripts/mitsuba/scenes/lights_<scene>.ron, once with
`--integrator path` and once with the scene's default estimator (seeds 1…K), each at `--spp`
samples per pixel. Per pixel, the mean over the K renders and the variance of that mean (the
sample variance across renders / K) are taken for each side.

Figures (on the average of the three channels):
  - mean: caustic's image mean / Mitsuba's − 1, with its standard error (from the per-pixel
    variances, pixels independent);
  - z8: for each 8×8 block b, z_b = (c_b − m_b) / sqrt(var c_b + var m_b), var of a block mean =
    Σ pixel variances / 64²; χ²/dof = Σ z_b² / blocks, ≈ 1 when the two images differ by noise
    only (its own sd is sqrt(2/dof)); max |z| is given too. Blocks whose standard error is below
    1e-4 of their mean (deterministic in both: they see only an emitter or the environment) are
    left out of χ² and reported by their largest relative difference.
Prints a Markdown table (the one in docs/lights.md). Correctness only: no timings.
"""
import argparse
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402
import lights  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
BLOCK = 8
# A block whose standard error is below this fraction of its mean is deterministic in both
# renderers (pixels that see an emitter or the environment directly, the same value every
# sample): a z-test there measures rounding, so such blocks are compared by their relative
# difference instead and left out of χ².
DETERMINISTIC = 1e-4


def read_exr(mi, path):
    return np.array(mi.Bitmap(str(path)), dtype=np.float64)[..., :3]


def mitsuba_runs(mi, dr, name, spp, seeds):
    """K Mitsuba renders of `name`, as an array (K, H, W, 3)."""
    scene = mi.load_dict(lights.SCENES[name](mi, spp, 0))
    out = []
    for s in range(seeds):
        img = mi.render(scene, spp=spp, seed=s)
        dr.eval(img)
        out.append(np.array(img, dtype=np.float64)[..., :3])
    return np.stack(out)


def caustic_runs(mi, binary, name, integrator, spp, seeds, out_dir):
    """K caustic renders of the twin scene, `integrator` None for the scene's default."""
    scene = ROOT / "scripts" / "mitsuba" / "scenes" / f"lights_{name}.ron"
    imgs = []
    for s in range(seeds):
        out = out_dir / f"caustic_{name}_{integrator or 'default'}_{s}.exr"
        cmd = [binary, "render", str(scene), "-o", str(out), "--spp", str(spp), "--seed", str(s + 1), "--quiet"]
        if integrator:
            cmd += ["--integrator", integrator]
        subprocess.run(cmd, check=True, cwd=ROOT, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        imgs.append(read_exr(mi, out))
    return np.stack(imgs)


def mean_and_var(runs):
    """Per-pixel mean over renders (channel average) and the variance of that mean."""
    y = runs.mean(axis=-1)
    k = y.shape[0]
    return y.mean(0), y.var(0, ddof=1) / k


def compare(c_runs, m_runs):
    cm, cv = mean_and_var(c_runs)
    mm, mv = mean_and_var(m_runs)
    n = cm.size
    rel = cm.mean() / mm.mean() - 1.0
    rel_se = np.sqrt(cv.sum() / n**2 + mv.sum() / n**2) / mm.mean()
    h, w = cm.shape
    hb, wb = h // BLOCK, w // BLOCK

    def blocks(a):
        return a[: hb * BLOCK, : wb * BLOCK].reshape(hb, BLOCK, wb, BLOCK).sum(axis=(1, 3))

    bc, bm = blocks(cm) / BLOCK**2, blocks(mm) / BLOCK**2
    var = (blocks(cv) + blocks(mv)) / BLOCK**4
    se = np.sqrt(var)
    scale = np.maximum(np.abs(bm), 1e-12)
    det = se < DETERMINISTIC * scale
    z = (bc - bm)[~det] / se[~det]
    det_diff = float((np.abs(bc - bm) / scale)[det].max()) if det.any() else 0.0
    return {
        "mean_c": cm.mean(), "mean_m": mm.mean(), "rel": rel, "rel_se": rel_se,
        "chi2_dof": float((z**2).mean()), "dof": z.size, "max_z": float(np.abs(z).max()),
        "det": int(det.sum()), "det_diff": det_diff,
    }


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("scenes", nargs="*", default=list(lights.SCENES))
    ap.add_argument("--spp", type=int, default=256)
    ap.add_argument("--seeds", type=int, default=4)
    ap.add_argument("--caustic", default=os.environ.get("CAUSTIC_BIN", str(ROOT / "target" / "release" / "caustic")))
    ap.add_argument("--out", default="/tmp/lights_compare")
    ap.add_argument("--threads", type=int, default=2)
    a = ap.parse_args()
    out_dir = Path(a.out)
    out_dir.mkdir(parents=True, exist_ok=True)
    mi, dr = common.mitsuba(a.threads)
    print(f"Mitsuba {mi.__version__}, {a.seeds} × {a.spp} spp per side, 96×72, 8×8 blocks")
    print()
    print("| scene | caustic | image mean (Mitsuba) | caustic/Mitsuba − 1 (± se) | z8 χ²/dof (dof) | max \\|z\\| | deterministic blocks: count, max rel. diff |")
    print("|---|---|---|---|---|---|---|")
    floor_checks = []
    for name in a.scenes:
        m_runs = mitsuba_runs(mi, dr, name, a.spp, a.seeds)
        for integrator in ["path", None]:
            c_runs = caustic_runs(mi, a.caustic, name, integrator, a.spp, a.seeds, out_dir)
            r = compare(c_runs, m_runs)
            if name.startswith("sun") and integrator:
                floor_checks.append((name, c_runs, m_runs))
            print(f"| {name} | {integrator or 'default'} | {r['mean_c']:.5f} ({r['mean_m']:.5f}) | "
                  f"{100 * r['rel']:+.2f}% (± {100 * r['rel_se']:.2f}%) | {r['chi2_dof']:.2f} ({r['dof']}) | "
                  f"{r['max_z']:.1f} | {r['det']}, {r['det_diff']:.1e} |", flush=True)

    # The sun's closed form on bare floor: the 8×8 block at rows 32–39, columns 0–7 sees floor
    # far from the ball (its light there is ρE cos θ/π plus the ball's faint bounce).
    for name, c_runs, m_runs in floor_checks:
        s = [v / np.linalg.norm(lights.SUN_DIR) for v in lights.SUN_DIR]
        closed = 0.5 * lights.SUN_E * s[1] / np.pi
        c = c_runs.mean(axis=(0, -1))[32:40, 0:8].mean()
        m = m_runs.mean(axis=(0, -1))[32:40, 0:8].mean()
        print(f"\n{name}: bare-floor block (rows 32–39, columns 0–7): caustic {c:.5f}, Mitsuba {m:.5f}, "
              f"ρE cos θ/π = {closed:.5f}")


if __name__ == "__main__":
    main()

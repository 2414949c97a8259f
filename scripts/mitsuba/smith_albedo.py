"""The directional albedo of a white (F = 1) GGX conductor under the two Smith masking-shadowing
conventions of docs/material_agreement.md: caustic's height-correlated G2 = 1/(1 + Λo + Λi)
(Heitz, JCGT 3(2) 2014, eq. 99) and Mitsuba 3's separable G1(ωo)·G1(ωi) (Heitz 2014, eq. 98).
G2/(G1·G1) = 1 + Λo·Λi/(1 + Λo + Λi) ≥ 1, so caustic reflects more, and only where both Λ are
large: at grazing angles.

    E(θo) = ∫ D(h) max(0, ωo·h) G(ωo, ωi) / cos θo dωh,  ωi = reflect(ωo, h), 0 below the surface

by a midpoint rule over (θh, φh) (1500 × 3000 cells), written from the formulas, independently of
the Rust code. Prints E under each convention and their ratio − 1 for the α of the comparison's
rough chrome (0.09) and rough gold (0.16).

With --mitsuba it also prints the same albedo (α = 0.16) estimated from 2²⁰ samples of Mitsuba's
`roughconductor` (material "none": F = 1) and of that BSDF wrapped in `height_correlated`
(materials.py): the wrapped one must reproduce the height-correlated column, the plain one the
separable column.

Use: /root/.cache/mitsuba3-venv/bin/python scripts/mitsuba/smith_albedo.py [--mitsuba]
"""
import sys
from pathlib import Path

import numpy as np


def smith_lambda(alpha, w):
    """GGX Smith Λ of direction w (isotropic α), w = (x, y, z) arrays with z > 0."""
    return (np.sqrt(1.0 + alpha * alpha * (w[0] ** 2 + w[1] ** 2) / w[2] ** 2) - 1.0) / 2.0


def albedo(alpha, theta_o, separable, n=1500):
    wo = np.array([np.sin(theta_o), 0.0, np.cos(theta_o)])
    th = (np.arange(n) + 0.5) / n * (np.pi / 2)
    ph = (np.arange(2 * n) + 0.5) / (2 * n) * (2 * np.pi)
    t, p = np.meshgrid(th, ph, indexing="ij")
    h = np.stack([np.sin(t) * np.cos(p), np.sin(t) * np.sin(p), np.cos(t)])
    tan2 = np.tan(t) ** 2
    d = 1.0 / (np.pi * alpha * alpha * np.cos(t) ** 4 * (1.0 + tan2 / (alpha * alpha)) ** 2)
    c = np.einsum("i,ijk->jk", wo, h)
    wi = 2.0 * c * h - wo[:, None, None]
    ok = (c > 0) & (wi[2] > 0)
    lo = smith_lambda(alpha, wo)
    li = smith_lambda(alpha, np.where(ok, wi, np.array([0.0, 0.0, 1.0])[:, None, None]))
    g = 1.0 / ((1.0 + lo) * (1.0 + li)) if separable else 1.0 / (1.0 + lo + li)
    f = np.where(ok, d * c * g / wo[2], 0.0) * np.sin(t)
    return float(f.sum() * (np.pi / 2 / n) * (2 * np.pi / (2 * n)))


def main():
    print("| α | θo | E, height-correlated (caustic) | E, separable (Mitsuba) | ratio − 1 |")
    print("|---|---|---|---|---|")
    for alpha in (0.09, 0.16):
        for deg in (0, 30, 60, 70, 80, 85):
            th = np.radians(deg)
            hc, sep = albedo(alpha, th, False), albedo(alpha, th, True)
            print(f"| {alpha} | {deg}° | {hc:.4f} | {sep:.4f} | {100 * (hc / sep - 1):+.2f} % |")


def mitsuba_check(alpha=0.16, n=1 << 20):
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    import common
    import materials
    mi, dr = common.mitsuba(2)
    plain = {"type": "roughconductor", "distribution": "ggx", "alpha": alpha, "sample_visible": True}
    bsdfs = {"separable (Mitsuba)": mi.load_dict(plain),
             "height_correlated wrapper": mi.load_dict(materials.height_correlated(mi, dict(plain)))}
    print(f"\nMitsuba {mi.__version__}, white roughconductor α = {alpha}, mean sample weight of {n} samples:")
    for name, bsdf in bsdfs.items():
        row = []
        for deg in (0, 60, 80, 85):
            th = np.radians(deg)
            si = dr.zeros(mi.SurfaceInteraction3f)
            si.wi = mi.Vector3f(float(np.sin(th)), 0.0, float(np.cos(th)))
            sampler = mi.load_dict({"type": "independent"})
            sampler.seed(1, n)
            _, w = bsdf.sample(mi.BSDFContext(), si, sampler.next_1d(), sampler.next_2d(), True)
            row.append(f"{deg}°: {float(dr.mean(w[0])[0]):.4f}")
        print(f"  {name}: " + ", ".join(row))


if __name__ == "__main__":
    main()
    if "--mitsuba" in sys.argv:
        mitsuba_check()

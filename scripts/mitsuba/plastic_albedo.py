"""Directional albedo of Mitsuba 3's `plastic` (nonlinear = false, specular_reflectance = 1), the
reference for caustic's coated lobe (src/shading/coated.rs, test
`directional_albedo_agrees_with_mitsuba_plastic`).

For each coat index, base albedo and incidence angle θ it prints
    ior  rho  theta_deg  albedo  coat  base
where coat = F(θ) is read from Mitsuba's own delta sample (weight × pdf of the sample chosen with
sample1 = 0, which picks the specular lobe), base = ∫ f cos θᵢ dωᵢ by a midpoint rule over
μ = cos θᵢ with 20 000 steps of Mitsuba's `eval` (isotropic, so one azimuth), and albedo their
sum. Deterministic (no random numbers).

Usage: /root/.cache/mitsuba3-venv/bin/python scripts/mitsuba/plastic_albedo.py \
           > tests/data/mitsuba_plastic_albedo.txt
"""
import math
import os
import sys

sys.path.insert(0, os.path.dirname(__file__))
from common import mitsuba  # noqa: E402

mi, dr = mitsuba()

IORS = [1.33, 1.5, 2.0]
RHOS = [0.2, 0.5, 0.8, 1.0]
THETAS = [0.0, 30.0, 60.0, 80.0]
STEPS = 20_000


def albedo(ior, rho, theta):
    bsdf = mi.load_dict({
        "type": "plastic",
        "int_ior": ior,
        "ext_ior": 1.0,
        "nonlinear": False,
        "diffuse_reflectance": {"type": "rgb", "value": [rho, rho, rho]},
        "specular_reflectance": {"type": "rgb", "value": [1.0, 1.0, 1.0]},
    })
    t = math.radians(theta)
    wo = mi.Vector3f(math.sin(t), 0.0, math.cos(t))
    ctx = mi.BSDFContext()
    # The coat: the delta sample, chosen with sample1 = 0.
    si = dr.zeros(mi.SurfaceInteraction3f)
    si.wi = wo
    bs, w = bsdf.sample(ctx, si, mi.Float(0.0), mi.Point2f(0.5, 0.5))
    coat = (w * bs.pdf)[0][0]
    # The base: ∫ eval (which includes cos θᵢ) dω = 2π ∫₀¹ eval(μ) dμ (no azimuth dependence).
    n = STEPS
    mu = (dr.arange(mi.Float, n) + 0.5) / n
    s = dr.safe_sqrt(1.0 - mu * mu)
    si = dr.zeros(mi.SurfaceInteraction3f, n)
    si.wi = mi.Vector3f(math.sin(t), 0.0, math.cos(t))
    wi = mi.Vector3f(s * 0.6, s * 0.8, mu)
    v = bsdf.eval(ctx, si, wi)
    base = dr.sum(v.x)[0] * 2.0 * math.pi / n
    return coat, base


def main():
    print("# Mitsuba", mi.__version__, "plastic (nonlinear = false, specular_reflectance = 1):"
          " directional albedo F(θ) + ∫ f cos θi dωi; scripts/mitsuba/plastic_albedo.py")
    print("# ior rho theta_deg albedo coat base")
    for ior in IORS:
        for rho in RHOS:
            for theta in THETAS:
                coat, base = albedo(ior, rho, theta)
                print(f"{ior} {rho} {theta} {coat + base:.6f} {coat:.6f} {base:.6f}")


if __name__ == "__main__":
    main()

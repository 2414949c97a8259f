"""Mitsuba 3 renders of the issue #26 comparison scenes, one per material.

Use:  /root/.cache/mitsuba3-venv/bin/python scripts/mitsuba/materials.py SCENE [--spp N] [-o out.exr]
      SCENE ∈ rough_chrome, rough_gold, frosted_01, frosted_05, water, glazed, and the rough
      ones with Mitsuba made height-correlated: rough_chrome_hc, rough_gold_hc, frosted_01_hc,
      frosted_05_hc (or `all`).

Every scene: 96×72 pixels, the floor y = 0 (Lambert 0.5), a sphere of the material (radius 0.5
at (0, 0.5, 0)), the 1 × 0.6 quad light of lights.py (y = 2.5, facing down, L = 8) and a
constant environment of radiance 0.3 (something for the metals to reflect); camera at
(0, 2, 5) looking at (0, 0.5, 0), fov_y 18° (the ball fills most of the frame); path tracing with max_depth 17 (caustic: 16
bounces), `volpath` for the absorbing water. Caustic's twins are
`scripts/mitsuba/scenes/materials_*.ron`; `scripts/mitsuba/materials_compare.py` renders both
and compares them.

Convention differences and how each scene neutralises them:
  roughness    caustic's `roughness` r is perceptual: the GGX width is α = r² (docs/material.md);
               Mitsuba's `alpha` is α. So Mitsuba gets alpha = r² (GGX, visible-normal
               sampling), r = 0.3 for chrome, 0.4 for gold, 0.1 and 0.5 for the frosted glass.
  conductors   caustic's presets are complex indices η + ik at 650/550/450 nm (the table in
               src/shading/conductor.rs); Mitsuba's named materials ("Cr", "Au") are spectral
               tables converted to RGB its own way. The scenes give Mitsuba caustic's η and k
               per RGB channel explicitly (`eta`, `k` as rgb), so both evaluate the same exact
               conductor Fresnel.
  masking      caustic's rough lobes use Heitz's height-correlated G2 = 1/(1 + Λ(ωo) + Λ(ωi))
               (src/shading/microfacet.rs); Mitsuba 3's microfacet distribution uses the
               separable G1(ωo)·G1(ωi) (MicrofacetDistribution::G in
               include/mitsuba/render/microfacet.h). G2 ≥ G1·G1, equal when either Λ is 0; the
               difference grows with α and at grazing angles (scripts/mitsuba/smith_albedo.py).
               The plain scenes keep Mitsuba's own convention; the `*_hc` scenes neutralise it:
               Mitsuba's own rough BSDF wrapped in `height_correlated` (below), which multiplies
               its value and its sample weight by G2/(G1·G1) = 1 + Λo Λi/(1 + Λo + Λi) (the
               same for reflection and transmission: Λ depends on cos² only) and leaves its
               sampling and pdf alone. Their caustic twins are the plain scenes' files.
  dielectric   Mitsuba's `roughdielectric`/`dielectric` with int_ior 1.5 (1.33), ext_ior 1:
               caustic's `ior` is the inside index relative to the outside (air).
  absorption   caustic's `absorption` σ (per metre) inside a closed dielectric; Mitsuba: the
               sphere's `interior` is a `homogeneous` medium with sigma_t = σ and albedo 0 (no
               scattering), rendered by `volpath` (Mitsuba's `path` ignores media).
  coat         caustic's `coat: (ior: 1.5)` over a diffuse `color` is Mitsuba's `plastic` with
               nonlinear = false, specular_reflectance 1, int_ior 1.5, the same diffuse
               reflectance. One difference is left (it cannot be set from the scene): Mitsuba
               takes the coat's internal diffuse reflectance F_dr,int from a fitted polynomial,
               caustic integrates it (0.59635 at η = 1.5, Mitsuba 0.59681), so Mitsuba's base
               would be brighter by (1 − F_dr,int,caustic)/(1 − F_dr,int,Mitsuba) − 1 = 0.115 %.
               With nonlinear = false the base is linear in its reflectance, so the scene
               neutralises this by giving Mitsuba the base colour times
               (1 − F_dr,int,Mitsuba)/(1 − F_dr,int,caustic) (`plastic_base_scale`; F_dr,int of
               caustic recomputed here by a midpoint rule, independently of the Rust code).
  emitters     one-sided quad as in lights.py; `constant` emitter = caustic's constant
               Environment (same meaning).
"""
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import common  # noqa: E402
import lights  # noqa: E402

# caustic's presets (src/shading/conductor.rs, ConductorPreset::complex_index), (η, k) per RGB.
CHROME = ([3.1071, 3.1812, 2.3230], [3.3314, 3.3291, 3.1350])
GOLD = ([0.1556, 0.4241, 1.3831], [3.6024, 2.4721, 1.9155])
WATER_SIGMA = [2.0, 0.4, 0.2]   # per metre: blue-green, strong enough to see through 1 m
ENV = 0.3
FOV = 18.0


def base(mi, spp, seed, integrator="path"):
    return {
        "type": "scene",
        "integrator": {"type": integrator, "max_depth": 17},
        "sensor": common.sensor(mi, lights.EYE, lights.LOOK, FOV, lights.W, lights.H, spp, seed),
        "floor": common.floor(mi),
        "panel": lights.quad_light(mi),
        "sky": {"type": "constant", "radiance": {"type": "rgb", "value": [ENV] * 3}},
    }


def ball(bsdf, **more):
    return {"type": "sphere", "center": [0, 0.5, 0], "radius": 0.5, "bsdf": bsdf, **more}


def rough_conductor(index, r):
    eta, k = index
    return {"type": "roughconductor", "distribution": "ggx", "alpha": r * r, "sample_visible": True,
            "eta": {"type": "rgb", "value": eta}, "k": {"type": "rgb", "value": k}}


def smith_lambda(dr, alpha, w):
    """GGX Smith Λ of a local direction (either hemisphere), isotropic α (Heitz 2014)."""
    z2 = dr.maximum(w.z * w.z, 1e-20)
    return (dr.sqrt(1.0 + alpha * alpha * (w.x * w.x + w.y * w.y) / z2) - 1.0) * 0.5


def register_height_correlated(mi, dr):
    """Registers the BSDF plugin `height_correlated` (once): {"type": "height_correlated",
    "alpha": α, "inner": a Mitsuba roughconductor/roughdielectric of that α}. It is the inner
    BSDF with its separable G1(ωi)G1(ωo) replaced by the height-correlated 1/(1 + Λi + Λo): value
    and sample weight times 1 + Λi Λo/(1 + Λi + Λo); sampling and pdf unchanged."""
    if getattr(register_height_correlated, "done", False):
        return

    class HeightCorrelated(mi.BSDF):
        def __init__(self, props):
            mi.BSDF.__init__(self, props)
            self.inner = props["inner"]
            self.alpha = props["alpha"]
            self.m_flags = self.inner.m_flags
            self.m_components = [self.inner.flags(i) for i in range(self.inner.component_count())]

        def ratio(self, si, wo):
            li, lo = smith_lambda(dr, self.alpha, si.wi), smith_lambda(dr, self.alpha, wo)
            return 1.0 + li * lo / (1.0 + li + lo)

        def sample(self, ctx, si, sample1, sample2, active=True):
            bs, w = self.inner.sample(ctx, si, sample1, sample2, active)
            return bs, w * self.ratio(si, bs.wo)

        def eval(self, ctx, si, wo, active=True):
            return self.inner.eval(ctx, si, wo, active) * self.ratio(si, wo)

        def pdf(self, ctx, si, wo, active=True):
            return self.inner.pdf(ctx, si, wo, active)

        def eval_pdf(self, ctx, si, wo, active=True):
            v, p = self.inner.eval_pdf(ctx, si, wo, active)
            return v * self.ratio(si, wo), p

        def traverse(self, callback):
            pass

        def to_string(self):
            return f"HeightCorrelated[alpha={self.alpha}, inner={self.inner}]"

    mi.register_bsdf("height_correlated", lambda props: HeightCorrelated(props))
    register_height_correlated.done = True


def height_correlated(mi, inner):
    """`inner` (a rough BSDF dict with `alpha`) with height-correlated masking-shadowing."""
    import drjit as dr
    register_height_correlated(mi, dr)
    return {"type": "height_correlated", "alpha": inner["alpha"], "inner": inner}


def rough_dielectric(r):
    return {"type": "roughdielectric", "distribution": "ggx", "alpha": r * r, "sample_visible": True,
            "int_ior": 1.5, "ext_ior": 1.0}


def scene_rough_chrome(mi, spp, seed):
    """A rough chrome ball (r = 0.3, α = 0.09)."""
    d = base(mi, spp, seed)
    d["ball"] = ball(rough_conductor(CHROME, 0.3))
    return d


def scene_rough_gold(mi, spp, seed):
    """A rough gold ball (r = 0.4, α = 0.16)."""
    d = base(mi, spp, seed)
    d["ball"] = ball(rough_conductor(GOLD, 0.4))
    return d


def scene_frosted(mi, spp, seed, r):
    """A frosted glass ball (η = 1.5, roughness r, α = r²)."""
    d = base(mi, spp, seed)
    d["ball"] = ball(rough_dielectric(r))
    return d


def scene_water(mi, spp, seed):
    """A ball of absorbing water: smooth dielectric η = 1.33 around a purely absorbing medium."""
    d = base(mi, spp, seed, integrator="volpath")
    # Mitsuba reads an RGB sigma_t as a reflectance (each channel in [0, 1]): it is given
    # divided by its largest channel, with `scale` = that channel.
    top = max(WATER_SIGMA)
    d["water"] = {"type": "homogeneous", "scale": top,
                  "sigma_t": {"type": "rgb", "value": [s / top for s in WATER_SIGMA]},
                  "albedo": {"type": "rgb", "value": [0.0, 0.0, 0.0]}}
    d["ball"] = ball({"type": "dielectric", "int_ior": 1.33, "ext_ior": 1.0},
                     interior={"type": "ref", "id": "water"})
    return d


GLAZE = [0.8, 0.45, 0.15]   # the glazed ball's base colour (an orange glaze)


def fresnel_dielectric(c, eta):
    """Unpolarised Fresnel reflectance at cosine c, light arriving from index 1 into index eta."""
    import numpy as np
    s2 = (1.0 - c * c) / (eta * eta)
    ct = np.sqrt(np.maximum(0.0, 1.0 - s2))
    rs = (c - eta * ct) / (c + eta * ct)
    rp = (eta * c - ct) / (eta * c + ct)
    return np.where(s2 >= 1.0, 1.0, 0.5 * (rs * rs + rp * rp))


def plastic_base_scale(mi, eta):
    """(1 − F_dr,int of Mitsuba's fit)/(1 − F_dr,int integrated): the factor that makes Mitsuba's
    linear `plastic` base equal to caustic's coated base. caustic's F_dr,int = 1 − (1 − F_dr,ext)/η²
    with F_dr,ext = ∫ F(μ) 2μ dμ by a 2·10⁶-step midpoint rule."""
    import numpy as np
    n = 2_000_000
    mu = (np.arange(n) + 0.5) / n
    fdr_ext = float(np.mean(fresnel_dielectric(mu, eta) * 2.0 * mu))
    fdr_int = 1.0 - (1.0 - fdr_ext) / (eta * eta)
    fit = np.asarray(mi.fresnel_diffuse_reflectance(mi.Float(1.0 / eta))).ravel()[0]
    return (1.0 - float(fit)) / (1.0 - fdr_int)


def scene_glazed(mi, spp, seed):
    """A glazed ball: a diffuse base under a smooth clear coat of index 1.5 (`plastic`), its base
    colour scaled by `plastic_base_scale` (0.99885) to neutralise the fitted F_dr,int."""
    d = base(mi, spp, seed)
    k = plastic_base_scale(mi, 1.5)
    d["ball"] = ball({"type": "plastic", "int_ior": 1.5, "ext_ior": 1.0, "nonlinear": False,
                      "diffuse_reflectance": {"type": "rgb", "value": [k * c for c in GLAZE]},
                      "specular_reflectance": {"type": "rgb", "value": [1.0, 1.0, 1.0]}})
    return d


def with_height_correlated(scene):
    """The scene function `scene` with its ball's rough BSDF made height-correlated."""
    def make(mi, spp, seed):
        d = scene(mi, spp, seed)
        d["ball"]["bsdf"] = height_correlated(mi, d["ball"]["bsdf"])
        return d
    return make


SCENES = {
    "rough_chrome": scene_rough_chrome,
    "rough_gold": scene_rough_gold,
    "frosted_01": lambda mi, spp, seed: scene_frosted(mi, spp, seed, 0.1),
    "frosted_05": lambda mi, spp, seed: scene_frosted(mi, spp, seed, 0.5),
    "water": scene_water,
    "glazed": scene_glazed,
}
# The rough scenes again with Mitsuba's masking made height-correlated, as caustic's (twins: the
# plain scenes' files).
for _name in ("rough_chrome", "rough_gold", "frosted_01", "frosted_05"):
    SCENES[_name + "_hc"] = with_height_correlated(SCENES[_name])


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

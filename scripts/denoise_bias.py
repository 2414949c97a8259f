#!/usr/bin/env python3
"""Bias and variance of the denoiser's inputs and outputs over seeds (docs/denoise.md, "Bias and
variance"; run by scripts/denoise_bias.sh).

For each kind of image (the noisy low-spp render, caustic's `--denoise` of it, OIDN on the same
noisy image + albedo + normal, the same two with 4x the caustic photons per pass when rendered,
and the noisy 16x-spp render), over N seeds: the mean image M and the per-pixel variance V over
the seeds (ddof 1). With relMSE's weights w = 1 / (ref^2 + 0.01) (as `caustic compare`):

    expected relMSE of one image = mean w [(M - ref)^2 + V (N-1)/N]     (= the seeds' average)
    bias^2                       = mean w [(M - ref)^2 - V / N]          (unbiased for E[X]'s)
    variance                     = mean w V

so bias^2 + variance is the seeds' average relMSE. bias^2 is what a perfect variance-only
denoiser of that image would leave (it would output E[X]). It includes the reference's own
noise (relMSE of the reference against the truth), which no image can go below: for a
reference rendered by the same estimator at R times the 16x render's samples it is about that
render's variance / R (printed when --ref-spp-ratio is given).

Regions: the whole image; the caustic region (scripts/denoise_bench.py's: the first seed's 16x
render's caustic layer, 7x7 average, at least --caustic-share of its whole light, 7x7
average); the rest. Each region's figures are means over its own pixels.
"""

import argparse
import json
import os
import sys

import numpy as np
import pyoidn

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import denoise_bench as bench  # noqa: E402  (read, box: one copy of the EXR and window helpers)

read, box = bench.read, bench.box


def rgb(ch, prefix="", names="RGB"):
    """`denoise_bench.rgb` in float64: sums over 16 seeds and squared errors."""
    return bench.rgb(ch, prefix, names).astype(np.float64)


def oidn(ch):
    noisy = np.ascontiguousarray(rgb(ch, "noisy").astype(np.float32))
    albedo = np.ascontiguousarray(rgb(ch, "albedo").astype(np.float32))
    normal = np.ascontiguousarray(rgb(ch, "normal", "XYZ").astype(np.float32))
    out = pyoidn.denoise(noisy, albedo, normal, hdr=True, quality="high")
    return np.asarray(out, dtype=np.float64)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--dir", required=True, help="low.<seed>.exr, p4.<seed>.exr, high.<seed>.exr")
    ap.add_argument("--reference", required=True)
    ap.add_argument("--seeds", nargs=2, type=int, required=True, metavar=("FIRST", "COUNT"))
    ap.add_argument("--caustic-share", type=float, default=0.5)
    ap.add_argument("--ref-spp-ratio", type=float,
                    help="the reference is the 16x render's estimator at this many times its samples")
    ap.add_argument("--json")
    a = ap.parse_args()

    ref = rgb(read(a.reference))
    wgt = 1.0 / (ref * ref + 0.01)
    seeds = range(a.seeds[0], a.seeds[0] + a.seeds[1])
    kinds = {}

    def add(name, img):
        kinds.setdefault(name, []).append(img)

    for s in seeds:
        low = read(os.path.join(a.dir, f"low.{s}.exr"))
        add("noisy", rgb(low, "noisy"))
        add("denoised", rgb(low))
        add("oidn", oidn(low))
        p4_path = os.path.join(a.dir, f"p4.{s}.exr")
        if os.path.exists(p4_path):
            p4 = read(p4_path)
            add("noisy, 4x caustic photons", rgb(p4, "noisy"))
            add("denoised, 4x caustic photons", rgb(p4))
            add("oidn, 4x caustic photons", oidn(p4))
        high = read(os.path.join(a.dir, f"high.{s}.exr"))
        add("noisy 16x spp", rgb(high))
        if s == a.seeds[0]:
            first_high = high
    caustic = box(rgb(first_high, "caustic").mean(-1), 3)
    region = caustic > a.caustic_share * box(rgb(first_high).mean(-1), 3)
    regions = {"whole": np.ones_like(region), "caustic": region, "rest": ~region}
    print(f"seeds {a.seeds[0]}..{a.seeds[0] + a.seeds[1] - 1}; caustic region {int(region.sum())} pixels")
    print(f"{'image':30} " + " ".join(f"{r + ' ' + q:>16}" for r in regions for q in ("relMSE", "bias2", "var"))
          + f" {'region mean/ref':>16}")
    figures = {"caustic_region_pixels": int(region.sum()), "seeds": list(a.seeds)}
    n = len(seeds)
    ref_region = ref[region].mean()
    for name, imgs in kinds.items():
        stack = np.stack(imgs)
        m = stack.mean(0)
        v = stack.var(0, ddof=1)
        d2 = (m - ref) ** 2
        row = {}
        for rname, mask in regions.items():
            ww = wgt[mask]
            bias2 = float(np.mean(ww * (d2[mask] - v[mask] / n)))
            var = float(np.mean(ww * v[mask]))
            rel = float(np.mean(ww * (d2[mask] + v[mask] * (n - 1) / n)))
            row[rname] = {"rel_mse": rel, "bias2": bias2, "variance": var}
        row["region_mean_over_ref"] = float(m[region].mean() / ref_region)
        figures[name] = row
        cells = " ".join(f"{row[r][q]:16.6f}" for r in regions for q in ("rel_mse", "bias2", "variance"))
        print(f"{name:30} {cells} {row['region_mean_over_ref']:16.4f}")
    if a.ref_spp_ratio:
        v = np.stack(kinds["noisy 16x spp"]).var(0, ddof=1) / a.ref_spp_ratio
        figures["reference_noise"] = {r: float(np.mean(wgt[mk] * v[mk])) for r, mk in regions.items()}
        print("reference's own noise (relMSE, estimated): "
              + ", ".join(f"{r} {x:.6f}" for r, x in figures["reference_noise"].items()))
    if a.json:
        with open(a.json, "w") as f:
            json.dump(figures, f, indent=2)


if __name__ == "__main__":
    sys.exit(main())

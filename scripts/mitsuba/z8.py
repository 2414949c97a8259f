"""Error figures of two renders (two seeds) of one estimator against an independent reference.

Usage: python z8.py A1.exr A2.exr REFERENCE.exr [--light 39] [--block 8] [--ref2 REF2.exr]
                   [--glint] [--noise]

Prints one line of `key=value` pairs for the mean image M = (A1 + A2) / 2:
  rmse, relmse (mean of (m - r)^2 / (r^2 + 0.01), as `caustic compare`), mean_ratio (image
  mean of M over the reference's), and z8: the chi-square per degree of freedom of an 8x8-block
  z-test of M against the reference,
      z_b,c = (mean_b(M) - mean_b(R)) / sqrt(sum_{p in b} (A1_p - A2_p)^2 / 2 / 64^2 / 2),
  i.e. each pixel's variance from its two seeds ((A1 - A2)^2 / 2 is an unbiased estimate of one
  render's pixel variance), the block mean's variance assuming independent pixels, halved for
  the mean of two renders; z8 = mean of z^2 over blocks and channels (1: agreement within noise;
  larger: bias, or noise shared between pixels). Blocks holding a pixel whose reference reads
  at least --light (the emitter seen directly) are excluded. The reference's own noise (RMSE
  about 0.005 for ../shared/bench/mitsuba/cbox_caustic.ref.exr) is not in the denominator, so
  z8 is slightly high for very converged inputs.

Options:
  --ref2 REF2.exr  the reference is given as two independent halves REFERENCE and REF2 (e.g.
      two shards of a long render): it is their mean, and its own per-pixel variance,
      (R1 - R2)^2 / 4, is added to the denominator (for comparing two long renders, neither of
      them negligibly noisy).
  --glint  also prints the brightest pixel (largest channel) of A1 and of A2 and of the
      reference, over the pixels that do not see the light (reference below --light, and not
      next to such a pixel): glint1, glint2, glint_ref and glint_ratio = max(glint1, glint2) /
      glint_ref (issue #24's glint figure: at most 1.5 at every seed).
  --noise  also prints noise_rmse = sqrt(mean (A1 - A2)^2 / 4) and noise_relmse = mean
      ((A1 - A2)^2 / 4 / (r^2 + 0.01)): the RMSE and relMSE that M's own noise contributes
      (for a reference given as two halves, its residual), and mean_ratio_sigma: the standard
      deviation of mean_ratio from the noise of M (and of the reference, with --ref2), pixels
      independent, a pixel's three channels not.
Reads EXR with Mitsuba's Bitmap (the venv of ../shared/bench/mitsuba/setup.sh).
"""
import argparse

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def load(path):
    bitmap = mi.Bitmap(path)
    if bitmap.pixel_format() == mi.Bitmap.PixelFormat.MultiChannel:
        # caustic's EXR with layers (e.g. `--denoise`: R, G, B denoised and `noisy.R/G/B`):
        # the image is the root layer.
        bitmap = dict(bitmap.split())["<root>"]
    a = np.array(bitmap.convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))
    return a.astype(np.float64)[..., :3]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("a1")
    ap.add_argument("a2")
    ap.add_argument("ref")
    ap.add_argument("--light", type=float, default=39.0)
    ap.add_argument("--block", type=int, default=8)
    ap.add_argument("--ref2")
    ap.add_argument("--glint", action="store_true")
    ap.add_argument("--noise", action="store_true")
    args = ap.parse_args()
    a1, a2, r = load(args.a1), load(args.a2), load(args.ref)
    var_ref = np.zeros_like(r)
    if args.ref2:
        r2 = load(args.ref2)
        var_ref = (r - r2) ** 2 / 4
        r = (r + r2) / 2
    m = (a1 + a2) / 2
    rmse = np.sqrt(np.mean((m - r) ** 2))
    relmse = np.mean((m - r) ** 2 / (r**2 + 0.01))
    ratio = m.mean() / r.mean()
    b = args.block
    h, w = (r.shape[0] // b) * b, (r.shape[1] // b) * b

    def blocks(x):
        return x[:h, :w].reshape(h // b, b, w // b, b, 3)

    var_pix = (a1 - a2) ** 2 / 2
    mean_m = blocks(m).mean(axis=(1, 3))
    mean_r = blocks(r).mean(axis=(1, 3))
    var_mean = blocks(var_pix).sum(axis=(1, 3)) / (b * b) ** 2 / 2 + blocks(var_ref).sum(axis=(1, 3)) / (b * b) ** 2
    light = (blocks(r).max(axis=(1, 3, 4)) >= args.light)[..., None].repeat(3, axis=2)
    ok = ~light & (var_mean > 0)
    z2 = (mean_m - mean_r) ** 2 / np.where(ok, var_mean, 1.0)
    z8 = z2[ok].mean()
    line = f"rmse={rmse:.5f} relmse={relmse:.5f} mean_ratio={ratio:.5f} z8={z8:.3f} blocks={ok.sum() // 3}"
    if args.noise:
        d2 = (a1 - a2) ** 2 / 4
        # The image mean's standard deviation (pixels independent, a pixel's channels not):
        # var(mean M) = sum_p (sum_c (A1 - A2)_pc)^2 / 4 / (3 N)^2, plus the reference's.
        n = r.shape[0] * r.shape[1] * 3
        var_m = (((a1 - a2).sum(axis=2)) ** 2).sum() / 4 / n**2
        if args.ref2:
            var_m += (((r2 - load(args.ref)).sum(axis=2)) ** 2).sum() / 4 / n**2
        line += (f" noise_rmse={np.sqrt(d2.mean()):.5f} noise_relmse={(d2 / (r**2 + 0.01)).mean():.6f}"
                 f" mean_ratio_sigma={np.sqrt(var_m) / r.mean():.5f}")
    if args.glint:
        sees = r.max(axis=2) >= args.light
        pad = np.pad(sees, 1)
        hh, ww = sees.shape
        near = np.zeros_like(sees)
        for dy in (0, 1, 2):
            for dx in (0, 1, 2):
                near |= pad[dy:dy + hh, dx:dx + ww]
        g1, g2, gr = (x.max(axis=2)[~near].max() for x in (a1, a2, r))
        line += f" glint1={g1:.3f} glint2={g2:.3f} glint_ref={gr:.3f} glint_ratio={max(g1, g2) / gr:.3f}"
    print(line)


if __name__ == "__main__":
    main()

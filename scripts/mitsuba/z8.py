"""Error figures of two renders (two seeds) of one estimator against an independent reference.

Usage: python z8.py A1.exr A2.exr REFERENCE.exr [--light 39]

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
Reads EXR with Mitsuba's Bitmap (the venv of ../shared/bench/mitsuba/setup.sh).
"""
import argparse

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def load(path):
    a = np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))
    return a.astype(np.float64)[..., :3]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("a1")
    ap.add_argument("a2")
    ap.add_argument("ref")
    ap.add_argument("--light", type=float, default=39.0)
    ap.add_argument("--block", type=int, default=8)
    args = ap.parse_args()
    a1, a2, r = load(args.a1), load(args.a2), load(args.ref)
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
    var_mean = blocks(var_pix).sum(axis=(1, 3)) / (b * b) ** 2 / 2
    light = (blocks(r).max(axis=(1, 3, 4)) >= args.light)[..., None].repeat(3, axis=2)
    ok = ~light & (var_mean > 0)
    z2 = (mean_m - mean_r) ** 2 / np.where(ok, var_mean, 1.0)
    z8 = z2[ok].mean()
    print(f"rmse={rmse:.5f} relmse={relmse:.5f} mean_ratio={ratio:.5f} z8={z8:.3f} blocks={ok.sum() // 3}")


if __name__ == "__main__":
    main()

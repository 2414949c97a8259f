"""Mean of several EXR images of the same size (e.g. Mitsuba renders of equal sample counts and
different seeds, for a render with more samples than one `mi.render` call holds in memory).

Usage: python mean_exr.py OUT.exr IN1.exr [IN2.exr ...]
Writes linear RGB float32 (Mitsuba's Bitmap; the venv of ../shared/bench/mitsuba/setup.sh).
"""
import sys

import mitsuba as mi
import numpy as np

mi.set_variant("scalar_rgb")


def load(path):
    a = np.array(mi.Bitmap(path).convert(mi.Bitmap.PixelFormat.RGB, mi.Struct.Type.Float32, False))
    return a.astype(np.float64)[..., :3]


def main():
    out, ins = sys.argv[1], sys.argv[2:]
    acc = sum(load(p) for p in ins) / len(ins)
    mi.Bitmap(acc.astype(np.float32), mi.Bitmap.PixelFormat.RGB).write(out)


if __name__ == "__main__":
    main()

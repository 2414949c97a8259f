#!/usr/bin/env python3
"""Denoiser yardstick (issue 46, docs/denoise.md): errors of caustic's `--denoise`, of Intel Open
Image Denoise (the `pyoidn` wheel, a yardstick only, never a dependency of caustic) on the very
same noisy render, albedo and normal, and of a noisy render with more samples, all against an
independent reference (Mitsuba 3's for the caustic Cornell box).

Reads EXR files written by `caustic render --denoise --layers albedo,normal,caustic`:
channels R,G,B (denoised), noisy.R/G/B, albedo.R/G/B, normal.X/Y/Z, caustic.R/G/B.

Figures (relMSE as `caustic compare` computes it: mean of d^2 / (ref^2 + 0.01) over pixels and
channels):
  - relMSE of the noisy low-spp image, caustic's denoised one, OIDN's, and the noisy high-spp one;
  - the caustic region (pixels where the high-spp render's caustic layer, box-averaged over 7x7,
    is above --caustic-threshold, or with --caustic-share S above S times that render's whole
    light box-averaged the same way: where caustic light makes that share of the pixel): each
    image's mean there over the reference's, and the correlation (Pearson, of the pixels'
    channel means) of each image with the reference there: whether the caustic's structure is
    kept;
  - the hot spot (5x5 around the reference's brightest box-averaged pixel in the region): each
    image's mean there over the reference's (1 = kept; 0.95 = peak lowered by 5 %).
"""

import argparse
import json
import sys

import numpy as np
import OpenEXR
import pyoidn


def read(path):
    with OpenEXR.File(str(path), separate_channels=True) as f:
        return {k: np.array(v.pixels, dtype=np.float32) for k, v in f.channels().items()}


def rgb(ch, prefix="", names="RGB"):
    p = prefix + "." if prefix else ""
    return np.stack([ch[p + c] for c in names], -1).astype(np.float32)


def write(path, image):
    channels = {c: image[..., i].copy() for i, c in enumerate("RGB")}
    header = {"compression": OpenEXR.ZIP_COMPRESSION, "type": OpenEXR.scanlineimage}
    with OpenEXR.File(header, channels) as f:
        f.write(str(path))


def slug(name):
    return {"noisy (low spp)": "noisy", "caustic --denoise": "denoised", "OIDN (same inputs)": "oidn",
            "noisy (high spp)": "noisy_high", "reference": "reference"}[name]


def save_png(path, img, exposure, tonemap):
    """Linear RGB times `exposure`, through `tonemap` (linear or aces: Narkowicz's fit, as
    caustic's), to an 8-bit sRGB PNG, as `caustic render` writes PNGs."""
    import struct
    import zlib
    v = np.maximum(img.astype(np.float64) * exposure, 0.0)
    if tonemap == "aces":
        v = np.minimum(v, 1e6)
        v = v * (2.51 * v + 0.03) / (v * (2.43 * v + 0.59) + 0.14)
    v = np.clip(v, 0.0, 1.0)
    srgb = np.where(v <= 0.0031308, 12.92 * v, 1.055 * np.power(v, 1 / 2.4) - 0.055)
    rows = (srgb * 255 + 0.5).astype(np.uint8)
    h, w = rows.shape[:2]
    raw = b"".join(b"\x00" + rows[y].tobytes() for y in range(h))

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data
                + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF))

    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, 8, 2, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def rel_mse(img, ref):
    d = img.astype(np.float64) - ref
    return float(np.mean(d * d / (ref.astype(np.float64) ** 2 + 0.01)))


def box(a, r):
    p = np.pad(a, r, mode="edge")
    w = 2 * r + 1
    return np.lib.stride_tricks.sliding_window_view(p, (w, w)).mean(axis=(-1, -2))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--low", required=True, help="EXR of the low-spp render with --denoise and layers")
    ap.add_argument("--high", required=True, help="EXR of the high-spp noisy render with the caustic layer")
    ap.add_argument("--reference", required=True, help="the reference EXR")
    ap.add_argument("--oidn-out", help="write OIDN's output here (EXR)")
    ap.add_argument("--caustic-threshold", type=float, default=0.05)
    ap.add_argument("--caustic-share", type=float,
                    help="region: caustic layer above this share of the whole light (instead of the threshold)")
    ap.add_argument("--crop", help="write X,Y,W,H crops of every image (PNG, sRGB, --exposure) with this prefix")
    ap.add_argument("--crop-box", help="the crop, as X,Y,W,H (default: 48x48 around the hot spot)")
    ap.add_argument("--crop-scale", type=int, default=4, help="crops enlarged this many times (nearest)")
    ap.add_argument("--exposure", type=float, default=1.0, help="exposure of the crops and pictures")
    ap.add_argument("--tonemap", choices=["linear", "aces"], default="linear",
                    help="tone curve of the crops and pictures (the scene's render.tonemap)")
    ap.add_argument("--pictures", help="write the whole images (PNG, sRGB, --exposure) with this prefix")
    ap.add_argument("--json", help="write the figures here")
    a = ap.parse_args()

    low, high, ref_ch = read(a.low), read(a.high), read(a.reference)
    ref = rgb(ref_ch)
    noisy, ours = rgb(low, "noisy"), rgb(low)
    albedo, normal = rgb(low, "albedo"), rgb(low, "normal", "XYZ")
    oidn = pyoidn.denoise(np.ascontiguousarray(noisy), np.ascontiguousarray(albedo),
                          np.ascontiguousarray(normal), hdr=True, quality="high")
    oidn = np.asarray(oidn, dtype=np.float32)
    if a.oidn_out:
        write(a.oidn_out, oidn)
    high_img = rgb(high)
    caustic = box(rgb(high, "caustic").mean(-1), 3)
    if a.caustic_share is not None:
        region = caustic > a.caustic_share * box(high_img.mean(-1), 3)
    else:
        region = caustic > a.caustic_threshold
    if not region.any():
        sys.exit(f"no caustic region: no pixel of the high-spp caustic layer is above {a.caustic_threshold}")
    lum = box(ref.mean(-1), 1)
    masked = np.where(region, lum, -np.inf)
    y, x = np.unravel_index(np.argmax(masked), masked.shape)
    spot = (slice(max(y - 2, 0), y + 3), slice(max(x - 2, 0), x + 3))
    ref_region, ref_spot = ref[region].mean(), ref[spot].mean()
    figures = {"caustic_region_pixels": int(region.sum()), "hot_spot": [int(x), int(y)]}
    rows = [("noisy (low spp)", noisy), ("caustic --denoise", ours), ("OIDN (same inputs)", oidn),
            ("noisy (high spp)", high_img)]
    print(f"caustic region: {region.sum()} pixels; hot spot at ({x}, {y})")
    print(f"{'image':22} {'relMSE':>10} {'region mean/ref':>16} {'hot spot/ref':>13} {'corr in region':>15}")
    ref_lum = ref.mean(-1)[region].astype(np.float64)
    for name, img in rows:
        e = rel_mse(img, ref)
        m = float(img[region].mean() / ref_region)
        s = float(img[spot].mean() / ref_spot)
        c = float(np.corrcoef(img.mean(-1)[region].astype(np.float64), ref_lum)[0, 1])
        figures[name] = {"rel_mse": e, "region_mean_over_ref": m, "hot_spot_over_ref": s,
                         "region_correlation": c}
        print(f"{name:22} {e:10.6f} {m:16.4f} {s:13.4f} {c:15.4f}")
    pictures = rows + [("reference", ref)]
    if a.pictures:
        for name, img in pictures:
            save_png(f"{a.pictures}{slug(name)}.png", img, a.exposure, a.tonemap)
    if a.crop:
        if a.crop_box:
            cx, cy, cw, ch = (int(v) for v in a.crop_box.split(","))
        else:
            cw = ch = min(48, ref.shape[1], ref.shape[0])
            cx = min(max(int(x) - cw // 2, 0), ref.shape[1] - cw)
            cy = min(max(int(y) - ch // 2, 0), ref.shape[0] - ch)
        figures["crop"] = [cx, cy, cw, ch]
        for name, img in pictures:
            crop = img[cy:cy + ch, cx:cx + cw].repeat(a.crop_scale, 0).repeat(a.crop_scale, 1)
            save_png(f"{a.crop}{slug(name)}.png", crop, a.exposure, a.tonemap)
    ratio = figures["caustic --denoise"]["rel_mse"] / figures["OIDN (same inputs)"]["rel_mse"]
    figures["ours_over_oidn"] = ratio
    print(f"caustic --denoise relMSE / OIDN relMSE: {ratio:.3f}")
    if a.json:
        with open(a.json, "w") as f:
            json.dump(figures, f, indent=2)


if __name__ == "__main__":
    main()

"""RMSE against time, log-log, for curves from CSV files (any renderer), with fitted slopes.

Usage: python3 loglog_plot.py OUT.svg --title TITLE [--ref-noise SIGMA] [--json OUT.json]
                              LABEL=FILE.csv [LABEL=FILE.csv ...]

Each CSV has a header row naming at least the columns `seconds` and `rmse` (more columns are
ignored): one point per row. For each curve it prints, and writes into the SVG's legend, the
least-squares slope of ln RMSE against ln seconds over all its points (what `caustic converge`
fits). With --ref-noise SIGMA (the RMSE of the reference's own noise, independent of the
curves'), it also gives the slope of sqrt(RMSE^2 - SIGMA^2), the error against the exact image:
a reference's noise adds SIGMA^2 to every point's expected MSE and flattens the curve's far end.
The SVG has the style of `caustic converge`'s plot: both axes logarithmic, one curve per file,
a grey guide of slope -1/2. Standard library only (no numpy, no matplotlib).
"""
import argparse
import csv
import json
import math


def slope(points):
    v = [(math.log(x), math.log(y)) for x, y in points if x > 0 and y > 0 and math.isfinite(y)]
    if len(v) < 2:
        return None
    n = len(v)
    mx = sum(p[0] for p in v) / n
    my = sum(p[1] for p in v) / n
    sxx = sum((p[0] - mx) ** 2 for p in v)
    sxy = sum((p[0] - mx) * (p[1] - my) for p in v)
    return sxy / sxx if sxx > 0 else None


def read(path):
    with open(path, newline="") as f:
        rows = list(csv.DictReader(f))
    return [(float(r["seconds"]), float(r["rmse"])) for r in rows]


def fmt(s):
    return "n/a" if s is None else f"{s:.3f}"


COLOURS = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd", "#ff7f0e", "#8c564b"]


def svg(path, title, curves):
    W, H = 720, 480
    L, R, T, B = 80, 20, 40, 60
    xs = [x for _, pts, _ in curves for x, _ in pts]
    ys = [y for _, pts, _ in curves for _, y in pts]
    x0, x1 = 10 ** math.floor(math.log10(min(xs))), 10 ** math.ceil(math.log10(max(xs)))
    y0, y1 = 10 ** math.floor(math.log10(min(ys))), 10 ** math.ceil(math.log10(max(ys)))

    def px(x):
        return L + (math.log10(x) - math.log10(x0)) / (math.log10(x1) - math.log10(x0)) * (W - L - R)

    def py(y):
        return H - B - (math.log10(y) - math.log10(y0)) / (math.log10(y1) - math.log10(y0)) * (H - T - B)

    o = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" '
         f'font-family="sans-serif" font-size="12">',
         f'<rect width="{W}" height="{H}" fill="white"/>',
         f'<text x="{W / 2}" y="22" text-anchor="middle" font-size="14">{title}</text>']
    for d in range(round(math.log10(x0)), round(math.log10(x1)) + 1):
        for m in range(1, 10):
            x = m * 10.0 ** d
            if x0 <= x <= x1:
                o.append(f'<line x1="{px(x):.1f}" y1="{T}" x2="{px(x):.1f}" y2="{H - B}" '
                         f'stroke="{"#ccc" if m == 1 else "#eee"}"/>')
                if m == 1:
                    o.append(f'<text x="{px(x):.1f}" y="{H - B + 16}" text-anchor="middle">{x:g}</text>')
    for d in range(round(math.log10(y0)), round(math.log10(y1)) + 1):
        for m in range(1, 10):
            y = m * 10.0 ** d
            if y0 <= y <= y1:
                o.append(f'<line x1="{L}" y1="{py(y):.1f}" x2="{W - R}" y2="{py(y):.1f}" '
                         f'stroke="{"#ccc" if m == 1 else "#eee"}"/>')
                if m == 1:
                    o.append(f'<text x="{L - 6}" y="{py(y) + 4:.1f}" text-anchor="end">{y:g}</text>')
    o.append(f'<rect x="{L}" y="{T}" width="{W - L - R}" height="{H - T - B}" fill="none" stroke="black"/>')
    o.append(f'<text x="{(L + W - R) / 2}" y="{H - 20}" text-anchor="middle">render time (s)</text>')
    o.append(f'<text x="18" y="{(T + H - B) / 2}" text-anchor="middle" '
             f'transform="rotate(-90 18 {(T + H - B) / 2})">RMSE</text>')
    # Guide of slope -1/2 through the first curve's first point.
    gx, gy = curves[0][1][0]
    a, b = x0, x1
    ya, yb = gy * (a / gx) ** -0.5, gy * (b / gx) ** -0.5
    o.append(f'<line x1="{px(a):.1f}" y1="{py(ya):.1f}" x2="{px(b):.1f}" y2="{py(yb):.1f}" '
             f'stroke="#999" stroke-dasharray="6 4"/>')
    o.append(f'<clipPath id="c"><rect x="{L}" y="{T}" width="{W - L - R}" height="{H - T - B}"/></clipPath>')
    o[-2] = o[-2].replace("/>", ' clip-path="url(#c)"/>')
    for i, (label, pts, _) in enumerate(curves):
        c = COLOURS[i % len(COLOURS)]
        p = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y in pts)
        o.append(f'<polyline points="{p}" fill="none" stroke="{c}" stroke-width="2"/>')
        for x, y in pts:
            o.append(f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="3" fill="{c}"/>')
    # Legend in the lower left corner (the curves fall from the upper left to the lower right).
    entries = curves + [("guide", None, "slope -1/2")]
    lx, ly = L + 12, H - B - 12 - 18 * (len(entries) - 1)
    for i, (label, _, text) in enumerate(entries):
        c = "#999" if label == "guide" else COLOURS[i % len(COLOURS)]
        dash = ' stroke-dasharray="6 4"' if label == "guide" else ""
        o.append(f'<line x1="{lx}" y1="{ly + 18 * i - 4}" x2="{lx + 20}" y2="{ly + 18 * i - 4}" '
                 f'stroke="{c}" stroke-width="2"{dash}/>')
        o.append(f'<text x="{lx + 26}" y="{ly + 18 * i}">{text}</text>')
    o.append("</svg>")
    with open(path, "w") as f:
        f.write("\n".join(o) + "\n")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("out")
    ap.add_argument("curves", nargs="+", metavar="LABEL=FILE.csv")
    ap.add_argument("--title", default="RMSE against render time")
    ap.add_argument("--ref-noise", type=float, default=0.0)
    ap.add_argument("--json")
    a = ap.parse_args()
    curves, doc = [], []
    for spec in a.curves:
        label, path = spec.split("=", 1)
        pts = sorted(read(path))
        s = slope(pts)
        sc = None
        if a.ref_noise > 0:
            sc = slope([(x, math.sqrt(y * y - a.ref_noise ** 2)) for x, y in pts if y > a.ref_noise])
        text = f"{label} (slope {fmt(s)}" + (f"; {fmt(sc)} net of the reference's noise" if a.ref_noise > 0 else "") + ")"
        curves.append((label, pts, text))
        print(f"{label}: {len(pts)} points, {pts[0][0]:.2f}–{pts[-1][0]:.2f} s, RMSE {pts[0][1]:.5f} → "
              f"{pts[-1][1]:.5f}; slope {fmt(s)}"
              + (f", {fmt(sc)} with the reference's noise ({a.ref_noise:.5f}) taken out" if a.ref_noise > 0 else ""))
        doc.append({"label": label, "csv": path, "points": pts, "slope": s,
                    "ref_noise": a.ref_noise or None, "slope_without_ref_noise": sc})
    svg(a.out, a.title, curves)
    if a.json:
        with open(a.json, "w") as f:
            json.dump({"title": a.title, "curves": doc}, f, indent=1)
    print(f"wrote {a.out}")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes assets/glass_cup.obj (a drinking glass: a closed lathe of its wall and thick base) and
assets/glass_water.obj (the water in it: a closed cylinder reaching 0.8 mm into the glass wall
and base, so that with a lower `priority` than the glass it touches the glass with no air gap,
docs/media.md). Metres; +y up, the base on y = 0. Per-vertex normals (radial on the walls, flat
on the rims), counter-clockwise faces seen from outside. Deterministic.
Usage: python3 scripts/make_glass_cup.py"""
import math
import os

SEGMENTS = 96
R, H, WALL, BASE = 0.04, 0.11, 0.003, 0.008
OVERLAP, LEVEL = 0.0008, 0.075


def lathe(profile, name, path):
    """Revolves the closed counter-clockwise (r, y) polyline `profile` about +y."""
    verts, normals, faces = [], [], []
    for (r0, y0), (r1, y1) in zip(profile, profile[1:] + profile[:1]):
        if r0 == 0 and r1 == 0:
            continue
        dr, dy = r1 - r0, y1 - y0
        ln = math.hypot(dr, dy)
        nr, ny = dy / ln, -dr / ln
        base = len(verts)
        for k in range(SEGMENTS):
            phi = 2 * math.pi * k / SEGMENTS
            c, s = math.cos(phi), math.sin(phi)
            verts += [(r0 * c, y0, r0 * s), (r1 * c, y1, r1 * s)]
            normals += [(nr * c, ny, nr * s)] * 2
        for k in range(SEGMENTS):
            a, b = base + 2 * k, base + 2 * k + 1
            d, c = base + 2 * ((k + 1) % SEGMENTS), base + 2 * ((k + 1) % SEGMENTS) + 1
            # (b − a) × (d − a) points along the outward normal (nr, ny).
            if r1 != 0:
                faces.append((a, b, c))
            if r0 != 0:
                faces.append((a, c, d))
    with open(path, "w") as f:
        f.write(f"# {name}: written by scripts/make_glass_cup.py\no {name}\n")
        for v in verts:
            f.write("v %.6f %.6f %.6f\n" % v)
        for n in normals:
            f.write("vn %.6f %.6f %.6f\n" % n)
        for t in faces:
            f.write("f " + " ".join(f"{i + 1}//{i + 1}" for i in t) + "\n")


root = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "assets")
# Counter-clockwise in (r, y): base underside, outer wall, rim, inner wall, inner floor.
lathe([(0, 0), (R, 0), (R, H), (R - WALL, H), (R - WALL, BASE), (0, BASE)], "glass",
      os.path.join(root, "glass_cup.obj"))
rw = R - WALL + OVERLAP
lathe([(0, BASE - OVERLAP), (rw, BASE - OVERLAP), (rw, LEVEL), (0, LEVEL)], "water",
      os.path.join(root, "glass_water.obj"))

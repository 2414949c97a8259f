#!/usr/bin/env python3
"""Writes deep_nesting.ron, deep_nesting.toml (inline tables) and deep_nesting_tables.toml (table
headers): groups nested DEPTH levels deep around one sphere.

The validator accepts at most 64 levels of group nesting (MAX_NESTING in src/scene/validate.rs);
these files nest 70. The RON file must be refused with a message naming the 65th level; the TOML
files stop earlier, at the TOML reader's own limit of 80 nested arrays/tables or 80-part headers.
Line 2 of each is the machine-checked `expect:` header (see tests/it/bad_scenes.rs).
Run from this directory: `python3 gen_deep_nesting.py`.
"""

DEPTH = 70

ron = [
    "// 70 nested groups (limit 64): message must name the first too-deep node "
    "nodes[0].children[0]...(64 times) and say nested more than 64 levels, not a parser recursion error.",
    "// expect: 73:265 | nodes[0].children[0].children[0] | children[0]: groups are nested more than 64 levels",
    "Scene(",
    "    render: (width: 64, height: 48, samples_per_pixel: 1),",
    "    camera: Pinhole(eye: (0, 1, 4), look_at: (0, 1, 0), fov_y: 40),",
    '    materials: { "white": (color: (0.8, 0.8, 0.8)) },',
    "    lights: [Point(position: (0, 3, 2), power: (50, 50, 50))],",
    "    nodes: [",
]
for d in range(DEPTH):
    ron.append("    " * (d + 2) + f'Group(name: "g{d + 1}", children: [')
ron.append("    " * (DEPTH + 2) + 'Sphere(material: "white", radius: 0.5),')
for d in reversed(range(DEPTH)):
    ron.append("    " * (d + 2) + "]),")
ron += ["    ],", ")"]

inner = '{ Sphere = { material = "white", radius = 0.5 } }'
for d in reversed(range(1, DEPTH)):
    inner = f'{{ Group = {{ name = "g{d + 1}", children = [{inner}] }} }}'
toml = [
    "# 70 groups nested inline: the TOML reader stops at 80 nested arrays/inline tables (about 26 "
    "groups); message must say so (not a bare recursion error), locate the first value past the "
    "limit, and point to RON for deeper scenes.",
    "# expect: 22:1003 | nested more than 80 deep | the TOML reader's limit | about 26 groups | "
    "64 levels | RON",
    "[render]",
    "width = 64",
    "height = 48",
    "samples_per_pixel = 1",
    "",
    "[camera.Pinhole]",
    "eye = [0, 1, 4]",
    "look_at = [0, 1, 0]",
    "fov_y = 40",
    "",
    "[materials]",
    "white = { color = [0.8, 0.8, 0.8] }",
    "",
    "[[lights]]",
    "Point = { position = [0, 3, 2], power = [50, 50, 50] }",
    "",
    "[[nodes]]",
    "[nodes.Group]",
    'name = "g1"',
    f"children = [{inner}]",
]

# The same depth written with [[...children]] table headers, which need no parser recursion.
tables = [
    "# 70 groups nested as table headers: the TOML reader stops at headers of more than 80 dotted "
    "parts (about 39 groups); message must say so, locate that header, and point to RON for "
    "deeper scenes.",
    "# expect: 139:1 | more than 80 dotted parts | the TOML reader's limit | about 39 groups | "
    "64 levels | RON",
] + toml[2:18]
prefix = "nodes"
tables += ["[[nodes]]"]
for d in range(DEPTH):
    tables += [f"[{prefix}.Group]", f'name = "g{d + 1}"', f"[[{prefix}.Group.children]]"]
    prefix += ".Group.children"
tables += [f"[{prefix}.Sphere]", 'material = "white"', "radius = 0.5"]

with open("deep_nesting_tables.toml", "w") as f:
    f.write("\n".join(tables) + "\n")
with open("deep_nesting.ron", "w") as f:
    f.write("\n".join(ron) + "\n")
with open("deep_nesting.toml", "w") as f:
    f.write("\n".join(toml) + "\n")

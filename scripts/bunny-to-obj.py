#!/usr/bin/env python3
"""Turns the npm package `bunny` (the Stanford bunny as JSON `positions` and `cells`) into
the OBJ file scenes/bunny.obj, with area-weighted vertex normals for smooth shading.

    scripts/bunny-to-obj.py [path/to/bunny/index.js] [-o scenes/bunny.obj]

Without a path the package is fetched with `npm pack bunny` into a temporary directory.
The model is the Stanford Bunny of the Stanford 3D Scanning Repository
(http://graphics.stanford.edu/data/3Dscanrep/); the package is in the public domain.
Faces are wound counter-clockwise seen from outside (checked by the sign of the volume).
"""

import argparse
import json
import math
import os
import re
import subprocess
import sys
import tarfile
import tempfile


def fetch_index_js():
    with tempfile.TemporaryDirectory() as tmp:
        out = subprocess.run(["npm", "pack", "bunny", "--silent"], cwd=tmp, check=True,
                             capture_output=True, text=True).stdout.split()[-1]
        with tarfile.open(os.path.join(tmp, out)) as tar:
            return tar.extractfile("package/index.js").read().decode()


def array(source, name):
    m = re.search(r"exports\.%s\s*=\s*(\[.*?\]\])" % name, source, re.S)
    if not m:
        sys.exit(f"no `exports.{name}` array found")
    return json.loads(m.group(1))


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("index_js", nargs="?")
    ap.add_argument("-o", "--output", default="scenes/bunny.obj")
    args = ap.parse_args()
    source = open(args.index_js).read() if args.index_js else fetch_index_js()
    positions, cells = array(source, "positions"), array(source, "cells")

    sub = lambda a, b: (a[0] - b[0], a[1] - b[1], a[2] - b[2])
    cross = lambda a, b: (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                          a[0] * b[1] - a[1] * b[0])
    # Six times the signed volume: positive when the faces wind counter-clockwise outside.
    volume = sum(sum(p * q for p, q in zip(positions[a], cross(positions[b], positions[c])))
                 for a, b, c in cells)
    if volume < 0:
        cells = [(a, c, b) for a, b, c in cells]
    normals = [[0.0, 0.0, 0.0] for _ in positions]
    for a, b, c in cells:
        # Unnormalised: each face counts in proportion to its area.
        n = cross(sub(positions[b], positions[a]), sub(positions[c], positions[a]))
        for v in (a, b, c):
            for k in range(3):
                normals[v][k] += n[k]

    def unit(n):
        length = math.sqrt(sum(x * x for x in n)) or 1.0
        return [x / length for x in n]

    with open(args.output, "w") as out:
        out.write("# The Stanford Bunny, from the Stanford 3D Scanning Repository\n"
                  "# (http://graphics.stanford.edu/data/3Dscanrep/), via the public-domain npm\n"
                  "# package `bunny`; converted by scripts/bunny-to-obj.py.\n")
        out.write(f"# {len(positions)} vertices, {len(cells)} triangles\n")
        out.write("".join("v %g %g %g\n" % tuple(p) for p in positions))
        out.write("".join("vn %.4f %.4f %.4f\n" % tuple(unit(n)) for n in normals))
        out.write("".join(f"f {a + 1}//{a + 1} {b + 1}//{b + 1} {c + 1}//{c + 1}\n"
                          for a, b, c in cells))
    print(f"{args.output}: {len(positions)} vertices, {len(cells)} triangles"
          f"{' (winding flipped)' if volume < 0 else ''}", file=sys.stderr)


if __name__ == "__main__":
    main()

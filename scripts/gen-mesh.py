#!/usr/bin/env python3
"""Writes a procedural OBJ mesh for testing and measuring `define shape obj`.

    scripts/gen-mesh.py torus  --triangles 1000000 [--normals] -o torus.obj
    scripts/gen-mesh.py sphere --triangles 20000 -o sphere.obj
    scripts/gen-mesh.py terrain --triangles 200000 -o terrain.obj

The torus (major radius 1, minor 0.35, around the y axis) and the sphere (radius 1, a
latitude/longitude grid with triangle fans at the poles) are closed; the terrain is a
height field over [-1, 1]² in x and z. Faces are triangles wound counter-clockwise seen from
outside (above, for the terrain); `--normals` adds one exact normal per vertex (`vn`) and
writes faces as `v//vn`. The triangle count is the smallest grid at least as large as asked.
Standard library only, deterministic output.
"""

import argparse
import math
import sys


def grid_size(triangles, aspect):
    """Columns u and rows v with 2·u·v >= triangles and u ≈ aspect·v."""
    v = max(3, math.ceil(math.sqrt(triangles / (2.0 * aspect))))
    u = max(3, math.ceil(triangles / (2.0 * v)))
    return u, v


def torus(triangles):
    nu, nv = grid_size(triangles, 2.0)
    big, small = 1.0, 0.35
    verts, norms = [], []
    for i in range(nu):
        a = 2 * math.pi * i / nu
        for j in range(nv):
            b = 2 * math.pi * j / nv
            n = (math.cos(a) * math.cos(b), math.sin(b), math.sin(a) * math.cos(b))
            verts.append(((big + small * math.cos(b)) * math.cos(a), small * math.sin(b),
                          (big + small * math.cos(b)) * math.sin(a)))
            norms.append(n)
    faces = []
    for i in range(nu):
        for j in range(nv):
            p = i * nv + j
            q = ((i + 1) % nu) * nv + j
            r = ((i + 1) % nu) * nv + (j + 1) % nv
            s = i * nv + (j + 1) % nv
            faces.append((p, s, r))
            faces.append((p, r, q))
    return verts, norms, faces


def sphere(triangles):
    nu, nv = grid_size(triangles, 2.0)
    nv += 1  # 2·nu·(nv − 1) triangles: the pole rows are fans
    verts, norms = [(0.0, 1.0, 0.0)], [(0.0, 1.0, 0.0)]
    for j in range(1, nv):
        theta = math.pi * j / nv
        for i in range(nu):
            phi = 2 * math.pi * i / nu
            n = (math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi))
            verts.append(n)
            norms.append(n)
    verts.append((0.0, -1.0, 0.0))
    norms.append((0.0, -1.0, 0.0))
    south = len(verts) - 1
    ring = lambda j, i: 1 + (j - 1) * nu + i % nu
    faces = [(0, ring(1, i), ring(1, i + 1)) for i in range(nu)]
    for j in range(1, nv - 1):
        for i in range(nu):
            a, b = ring(j, i), ring(j, i + 1)
            c, d = ring(j + 1, i), ring(j + 1, i + 1)
            faces.append((a, c, d))
            faces.append((a, d, b))
    faces += [(south, ring(nv - 1, i + 1), ring(nv - 1, i)) for i in range(nu)]
    return verts, norms, faces


def terrain(triangles):
    n, _ = grid_size(triangles, 1.0)
    h = lambda x, z: 0.15 * math.sin(3 * x) * math.cos(4 * z) + 0.05 * math.sin(11 * x + 7 * z)
    verts, norms = [], []
    for j in range(n + 1):
        z = -1 + 2 * j / n
        for i in range(n + 1):
            x = -1 + 2 * i / n
            dx = 0.45 * math.cos(3 * x) * math.cos(4 * z) + 0.55 * math.cos(11 * x + 7 * z)
            dz = -0.6 * math.sin(3 * x) * math.sin(4 * z) + 0.35 * math.cos(11 * x + 7 * z)
            length = math.sqrt(dx * dx + 1 + dz * dz)
            verts.append((x, h(x, z), z))
            norms.append((-dx / length, 1 / length, -dz / length))
    faces = []
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            b, c, d = a + 1, a + n + 1, a + n + 2
            faces.append((a, c, d))
            faces.append((a, d, b))
    return verts, norms, faces


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("shape", choices=["torus", "sphere", "terrain"])
    ap.add_argument("--triangles", type=int, default=1_000_000)
    ap.add_argument("--normals", action="store_true", help="write vertex normals (smooth shading)")
    ap.add_argument("-o", "--output", default="-")
    args = ap.parse_args()
    verts, norms, faces = {"torus": torus, "sphere": sphere, "terrain": terrain}[args.shape](
        args.triangles)
    out = sys.stdout if args.output == "-" else open(args.output, "w")
    w = out.write
    w(f"# {args.shape}: {len(verts)} vertices, {len(faces)} triangles (scripts/gen-mesh.py)\n")
    w("".join(f"v {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in verts))
    if args.normals:
        w("".join(f"vn {x:.6f} {y:.6f} {z:.6f}\n" for x, y, z in norms))
        w("".join(f"f {a + 1}//{a + 1} {b + 1}//{b + 1} {c + 1}//{c + 1}\n" for a, b, c in faces))
    else:
        w("".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in faces))
    if out is not sys.stdout:
        out.close()
    print(f"{args.shape}: {len(verts)} vertices, {len(faces)} triangles", file=sys.stderr)


if __name__ == "__main__":
    main()

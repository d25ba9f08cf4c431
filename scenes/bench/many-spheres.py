#!/usr/bin/env python3
"""Writes many-spheres.sdf: 3000 spheres on a golden-angle (phyllotaxis) spiral over a
floor plane, a BVH-bound scene for `anim bench`. Deterministic: no random numbers.

    python3 scenes/bench/many-spheres.py > scenes/bench/many-spheres.sdf
"""
import math

N = 3000
GOLDEN = math.pi * (3 - math.sqrt(5))
MATERIALS = [
    # name ka kd ks m [reflectivity opacity ior]
    ("red", "0.1 0.02 0.02 0.8 0.15 0.1 0.5 0.5 0.5 40"),
    ("green", "0.02 0.1 0.02 0.15 0.7 0.2 0.5 0.5 0.5 40"),
    ("blue", "0.02 0.03 0.12 0.1 0.25 0.85 0.5 0.5 0.5 40"),
    ("gold", "0.1 0.08 0.02 0.7 0.5 0.1 0.9 0.8 0.4 80 0.3 1 1"),
    ("white", "0.1 0.1 0.1 0.8 0.8 0.8 0.3 0.3 0.3 20"),
    ("chrome", "0 0 0 0.05 0.05 0.05 0.8 0.8 0.8 300 0.8 1 1"),
]

print("# Many spheres: %d on a golden-angle spiral over a floor plane (written by" % N)
print("# many-spheres.py; regenerate rather than edit). Tests the BVH, shadows and edges.")
for name, values in MATERIALS:
    print("define material %s %s" % (name, values))
print("define material floor 0.12 0.12 0.1 0.5 0.45 0.35 0.1 0.1 0.1 5 0.1 1 1")
print("define shape plane ground 0 0 0 0 1 0 floor")
names = ["ground"]
for i in range(N):
    r = 0.35 * math.sqrt(i + 0.5)
    a = i * GOLDEN
    radius = 0.12 + 0.1 * ((i * 7) % 11) / 10.0
    x, z = r * math.cos(a), r * math.sin(a) - 8
    mat = MATERIALS[(i * 5) % len(MATERIALS)][0]
    name = "s%d" % i
    print("define shape sphere %s %.4f %.4f %.4f %.3f %s" % (name, x, radius, z, radius, mat))
    names.append(name)
print("define shape composite root " + " ".join(names))
print("define light key 8 14 4 1 0.95 0.9 0.9")
print("define light fill -10 8 0 0.6 0.7 1 0.4")
print("ambient 0.2 0.2 0.2")
print("background 0.08 0.1 0.16")
print("define camera eye 60 0 6 6 0 -0.55 -1 0 1 0")
print("render eye many-spheres.png 640 360")

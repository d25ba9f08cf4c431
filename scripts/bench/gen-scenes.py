#!/usr/bin/env python3
"""Writes the generated scenes of scripts/bench/pov.sh and scripts/bench/instructions.sh into
DIR (deterministic: fixed seeds). Used by those two scripts; run it alone for the same scenes.

    python3 scripts/bench/gen-scenes.py DIR

- grid10k.sdf: 10,000 spheres in a deep grid (20 x 10 x 50, receding from the camera), 1280x720;
- random1k.sdf, random100k.sdf, random1m.sdf: 10^3, 10^5 and 10^6 spheres at random in the
  same box of space (seed 1), radii scaled so that the spheres fill about the same share of
  the box whatever their number, 640x360.

One in five spheres is a partial mirror, so reflected rays cross the hierarchy too. Every file
ends with a render line without a sample count: the script passes --spp.
"""
import os
import random
import sys

HEAD = """define material matte 0.2 0.3 0.6 0.5 0.6 0.9 0.3 0.3 0.3 20
define material mirror 0.3 0.2 0.1 0.8 0.5 0.3 0.5 0.5 0.5 60 0.4
define light key 40 60 40 1 1 1 1
define light fill -50 20 10 0.5 0.5 0.6 1
ambient 0.1 0.1 0.1
"""


def grid(path):
    with open(path, "w") as f:
        f.write("# 10,000 spheres in a 20 x 10 x 50 grid receding along -z (scripts/bench/gen-scenes.py)\n")
        f.write(HEAD)
        n = 0
        for x in range(20):
            for y in range(10):
                for z in range(50):
                    mat = "mirror" if (x + y + z) % 5 == 0 else "matte"
                    f.write("define shape sphere s%d %g %g %g 0.25 %s\n"
                            % (n, x - 9.5, y - 4.5, -3 - 2 * z, mat))
                    n += 1
        f.write("define camera eye 60 0 0 8 0 0 -1 0 1 0\nrender eye grid10k.ppm 1280 720\n")


def scattered(path, count):
    rng = random.Random(1)
    # Radius 0.1-0.5 at 10^5 spheres; the same covered share at other counts.
    k = (100_000 / count) ** (1.0 / 3.0)
    name = path.rsplit("/", 1)[-1].replace(".sdf", "")
    with open(path, "w") as f:
        f.write("# %d spheres at random, seed 1 (scripts/bench/gen-scenes.py)\n" % count)
        f.write(HEAD)
        for n in range(count):
            x, y, z = rng.uniform(-60, 60), rng.uniform(-35, 35), rng.uniform(-160, -40)
            r = rng.uniform(0.1, 0.5) * k
            mat = "mirror" if n % 5 == 0 else "matte"
            f.write("define shape sphere s%d %.3f %.3f %.3f %.4f %s\n" % (n, x, y, z, r, mat))
        f.write("define camera eye 60\nrender eye %s.ppm 640 360\n" % name)


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: gen-scenes.py DIR")
    out = sys.argv[1].rstrip("/")
    os.makedirs(out, exist_ok=True)
    grid(out + "/grid10k.sdf")
    scattered(out + "/random1k.sdf", 1_000)
    scattered(out + "/random100k.sdf", 100_000)
    scattered(out + "/random1m.sdf", 1_000_000)


if __name__ == "__main__":
    main()

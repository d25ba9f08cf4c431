#!/usr/bin/env python3
"""Scores stopping rules of adaptive sampling offline, from the per-pixel data of dump.sh.

For each scene of OUT (NAME.dump, NAME.ppm, NAME.ref.ppm, NAME.log), every rule below picks,
for each refined pixel, how many samples of its own pattern it keeps (a power of two from 4 to
128; the dump holds its mean, error estimate and rays at each). The image is then the default
render with those pixels replaced, rounded to 8 bits as the renderer writes them, and scored:
RMSE against the converged render, and rays (the first pass's, from the render summary, plus
the refined pixels' at their chosen counts), relative to the rule the renderer has.

    python3 scripts/bench/stopping-rules/score.py OUT

Needs numpy. Prints one line per rule and scene; see docs/benchmarks-history.md §4.9.
"""
import itertools
import re
import sys
from pathlib import Path

import numpy as np

COUNTS = [2, 4, 8, 16, 32, 64, 128]
NET_DECAY = 2 ** -0.75  # the renderer's pattern::NET_DECAY
MIN_SAMPLES = 4  # pattern::MIN_SAMPLES
EDGE_ERROR_SHARE = 0.2  # pattern::EDGE_ERROR_SHARE
DEFAULT = dict(error=2.0, max_spp=32, share=EDGE_ERROR_SHARE, expo=4 / 3)


def read_ppm(path):
    data = Path(path).read_bytes()
    magic, w, h, maxval, pixels = data.split(maxsplit=4)
    assert magic == b"P6" and maxval == b"255", path
    w, h = int(w), int(h)
    return np.frombuffer(pixels[: w * h * 3], dtype=np.uint8).reshape(h, w, 3).astype(float)


class Scene:
    def __init__(self, out, name):
        self.name = name
        self.ref = read_ppm(out / f"{name}.ref.ppm")
        img = read_ppm(out / f"{name}.ppm")
        rows = np.loadtxt(out / f"{name}.dump", ndmin=2)
        self.x, self.y = rows[:, 0].astype(int), rows[:, 1].astype(int)
        self.contrast, self.centre, self.prims = rows[:, 2], rows[:, 5:8], rows[:, 8]
        self.range, self.mean, self.est, self.rays = {}, {}, {}, {}
        k = 9
        for n in COUNTS:
            assert (rows[:, k + 1] == n).all(), f"{name}: dump columns"
            self.range[n] = rows[:, k]
            self.mean[n], self.est[n], self.rays[n] = rows[:, k + 2 : k + 5], rows[:, k + 5], rows[:, k + 6]
            k += 7
        self.refined_ref = self.ref[self.y, self.x]
        kept = np.ones(self.ref.shape[:2], bool)
        kept[self.y, self.x] = False
        self.kept_sse = ((img - self.ref)[kept] ** 2).sum()
        self.values = self.ref.size
        summary = (out / f"{name}.log").read_text()
        total = sum(int(v) for v in re.findall(r"(?:primary|shadow|reflected|refracted) (\d+)", summary))
        # The first pass: everything the default render traced but its refined pixels.
        self.first_pass = total - self.refined_rays(rule(self, **DEFAULT))

    def refined_rays(self, choice):
        return sum(self.rays[n][choice == n].sum() for n in COUNTS)

    def score(self, choice):
        """RMSE of the image with `choice` samples in each refined pixel, and its rays."""
        values = np.zeros_like(self.centre)
        for n in COUNTS:
            values[choice == n] = self.mean[n][choice == n]
        sse = self.kept_sse + ((np.round(values) - self.refined_ref) ** 2).sum()
        return (sse / self.values) ** 0.5, self.first_pass + self.refined_rays(choice)


def min_samples(contrast, error, share, max_spp, expo):
    """pattern::min_samples, with the share and exponent as parameters."""
    n = np.floor(np.minimum((share * contrast / error) ** expo, 65536))
    n = 2 ** np.ceil(np.log2(np.maximum(n, MIN_SAMPLES)))
    return np.minimum(n, max_spp)


def rule(s, error, max_spp, share, expo, estimate=None):
    """The renderer's rule: stop at the first power of two n ≥ min_samples whose estimate is
    at most `error`, else at max_spp; `estimate(s, n)` replaces the renderer's estimate."""
    at_least = min_samples(s.contrast, error, share, max_spp, expo)
    choice = np.full(len(s.x), max_spp)
    done = np.zeros(len(s.x), bool)
    for n in COUNTS:
        if n < MIN_SAMPLES or n > max_spp:
            continue
        est = s.est[n] if estimate is None else estimate(s, n)
        stop = ~done & (n >= at_least) & (est <= error)
        choice[stop], done = n, done | stop
    return choice


def tone_of_mean(s, n):
    """The estimate from the change of the written value (the tone of the mean) between n/2
    and n samples, instead of the mean of the samples' tones (n ≥ 8; at 4 the renderer's)."""
    if n < 8:
        return s.est[n]
    now = np.abs(s.mean[n] - s.mean[n // 2]).max(axis=1)
    before = np.abs(s.mean[n // 2] - s.mean[n // 4]).max(axis=1)
    return NET_DECAY * np.maximum(now, NET_DECAY * before)


def per_ray_cost(s, lam, prior, p, max_spp):
    """Stop where the expected squared error left, max(estimate, prior·contrast·(4/n)^p)², is
    at most lam·√(rays so far): refine by the gain per ray."""
    choice = np.full(len(s.x), max_spp)
    done = np.zeros(len(s.x), bool)
    for n in COUNTS:
        if n < MIN_SAMPLES or n > max_spp:
            continue
        err = np.maximum(s.est[n], prior * s.contrast * (MIN_SAMPLES / n) ** p)
        stop = ~done & (err**2 <= lam * np.sqrt(s.rays[n]))
        choice[stop], done = n, done | stop
    return choice


def main():
    out = Path(sys.argv[1] if len(sys.argv) > 1 else sys.exit(__doc__))
    names = sorted(p.stem for p in out.glob("*.dump"))
    scenes = [Scene(out, n) for n in names]
    base = {s.name: s.score(rule(s, **DEFAULT)) for s in scenes}

    def show(label, choose):
        cells = []
        for s in scenes:
            rmse, rays = s.score(choose(s))
            cells.append(f"{s.name} {rmse:.3f} {rays / base[s.name][1]:.2f}x")
        print(f"{label:<44} " + "  ".join(cells), flush=True)

    print("rule".ljust(44), "  ".join(f"{s.name} RMSE rays" for s in scenes))
    for error in [1, 1.5, 2, 2.5, 3, 4]:
        show(f"renderer's rule, error {error}", lambda s: rule(s, **{**DEFAULT, "error": error}))
    for error, max_spp, share, expo in itertools.product(
        [1, 2, 3], [32, 64, 128], [0.2, 0.5, 1.2], [4 / 3, 1.0]
    ):
        label = f"error {error} max {max_spp} share {share} exp {expo:.2f}"
        show(label, lambda s: rule(s, error, max_spp, share, expo))
    for error in [2, 2.5, 3]:
        show(f"tone-of-mean estimate, error {error}", lambda s: rule(s, **{**DEFAULT, "error": error}, estimate=tone_of_mean))
    for lam, prior, p, max_spp in itertools.product([0.02, 0.05, 0.2], [0.05, 0.1], [0.75, 1.5], [64, 128]):
        show(f"per-ray lam {lam} prior {prior} p {p} max {max_spp}", lambda s: per_ray_cost(s, lam, prior, p, max_spp))


if __name__ == "__main__":
    main()

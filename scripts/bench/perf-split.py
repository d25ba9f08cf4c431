#!/usr/bin/env python3
"""Where the CPU of an `anim render DIR` run goes, from perf's samples with their stacks.

    perf record -F 199 --call-graph dwarf,8192 -o run.data anim render DIR --quiet
    perf script -i run.data -F tid,ip,sym > run.txt
    python3 scripts/bench/perf-split.py run.txt

Each sample goes to the first of these that its stack shows (BENCHMARKS.md, "Frames from the
frame before", where a shot's CPU goes): the shots' plan loading every frame beforehand
(`shots::job_of`), the plan comparing frames, the records hashing each frame's inputs, loading
the frame to render, preparing it (the hierarchy), watching (a sample in a watched query whose
own function is not the hierarchy's or the shading's), tracing, writing images; then, for stacks
cut short, by the sample's own function; the rest.
"""
import re
import sys
from collections import Counter

TRAVERSAL = re.compile(r"geometry::|accel::wide|__powf|Integrator::(local|shade)")
RULES = [
    ("plan: loading every frame beforehand", lambda s, leaf: "shots::job_of" in s),
    ("plan: comparing frames", lambda s, leaf: "shots::plan_shots" in s),
    ("records: hashing each frame's inputs", lambda s, leaf: "cache::frame_hash" in s),
    ("loading the frame to render", lambda s, leaf: "load::load_file" in s or "sdf::read" in s),
    ("preparing: the hierarchy",
     lambda s, leaf: "Aggregate::build" in s or "Prepared::new" in s or "accel::binary" in s),
    ("watching: the footprint tests",
     lambda s, leaf: ("_watched" in s or "watch_" in s) and not TRAVERSAL.search(leaf)),
    ("tracing", lambda s, leaf: re.search(r"render::(sampler|integrator|geometry|compile|shading)", s)),
    ("writing images", lambda s, leaf: re.search(r"png::|deflate|crc32|encode", s)),
    ("loading (stack cut short)", lambda s, leaf: re.search(r"sdf::|scene::builder|IncludeCache", leaf)),
    ("preparing (stack cut short)", lambda s, leaf: "accel::" in leaf),
    ("tracing (stack cut short)", lambda s, leaf: re.search(r"geometry::|integrator|sampler", leaf)),
]


def samples(path):
    """The stacks of perf script's output, innermost function first."""
    stack = None
    for line in open(path):
        if not line.strip():
            continue
        if not line[0].isspace():
            if stack is not None:
                yield stack
            stack = []
            continue
        parts = line.split(None, 1)
        stack.append(parts[1].strip() if len(parts) > 1 else "?")
    if stack is not None:
        yield stack


def main():
    if len(sys.argv) != 2:
        sys.exit("usage: perf-split.py PERF_SCRIPT_OUTPUT")
    counts = Counter()
    for stack in samples(sys.argv[1]):
        text, leaf = "\n".join(stack), stack[0] if stack else "?"
        counts[next((name for name, rule in RULES if rule(text, leaf)), "rest")] += 1
    total = sum(counts.values())
    for name, n in counts.most_common():
        print("%-40s %6d %5.1f %%" % (name, n, 100.0 * n / total))
    print("%-40s %6d" % ("samples", total))


if __name__ == "__main__":
    main()

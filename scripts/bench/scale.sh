#!/usr/bin/env bash
# Scale (BENCHMARKS.md, "Scale"): flat files of 10^3..10^6 random spheres (written by this
# script, seed 8), loaded (`anim check`) and rendered (`anim render --spp 1`, 640×360), whole
# process, /usr/bin/time. Prints CPU seconds (user + system), peak RSS (%M), bytes of peak RSS
# per sphere and lines read per CPU-second (by `anim check`, whose time is the reader, the
# scene builder and the blank-image probe).
#
#   scripts/bench/scale.sh [ANIM_BINARY] [COUNTS...]
#   ANIM=/path/to/anim scripts/bench/scale.sh 1000 100000
#
# Default binary: ANIM, else `cargo build --release`, then target/release/anim; default
# counts: 1000 10000 100000 1000000. A first argument that is a number is a count.
# Environment: ANIM, READER. With READER=1, first the reader alone (the source tree's
# `parse_source`, no scene building) and then the whole loader (`load_file`: reading the file,
# parsing and building the scene) on a million-sphere file, in lines per CPU-second of the
# reading thread: two ignored tests of tests/hostile/scale.rs, run with `cargo test --release` (so
# READER=1 always builds from the source tree, whatever ANIM says).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)

bin=
if [ $# -gt 0 ] && ! [[ $1 =~ ^[0-9]+$ ]]; then
    bin=$1
    shift
fi
counts=("$@")
if [ ${#counts[@]} -eq 0 ]; then
    counts=(1000 10000 100000 1000000)
fi
if [ -z "$bin" ]; then
    if [ -n "${ANIM:-}" ]; then
        bin=$ANIM
    else
        cargo build --release --quiet --manifest-path "$root/Cargo.toml"
        bin=$root/target/release/anim
    fi
fi
if [ "${READER:-0}" = 1 ]; then
    cargo test --release --manifest-path "$root/Cargo.toml" --test hostile -- --ignored --nocapture \
        --test-threads 1 scale::the_ 2>&1 | grep -E "^(reader|loader):|panicked|FAILED" || true
fi
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

gen() { # count file
    python3 - "$1" "$2" <<'PY'
import random, sys
n, path = int(sys.argv[1]), sys.argv[2]
rng = random.Random(8)
# Spheres spread over a cube whose side grows with the count, so the view stays as full.
side = max(10.0, n ** (1 / 3) * 2.0)
with open(path, "w") as f:
    f.write("define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20\n")
    f.write("define material blue 0 0 0.2 0.1 0.1 0.8 0.5 0.5 0.5 20\n")
    f.write("define light sun %g %g %g 1 1 1 1\n" % (side, side * 2, side * 2))
    f.write("ambient 0.2 0.2 0.2\n")
    f.write("define camera eye 60 0 0 %g 0 0 -1 0 1 0\n" % (side * 1.2))
    f.write("render eye out.png 640 360\n")
    for i in range(n):
        x, y, z = (rng.uniform(-side / 2, side / 2) for _ in range(3))
        f.write("define shape sphere s%d %.4f %.4f %.4f %.4f %s\n"
                % (i, x, y, z, rng.uniform(0.2, 0.6), "red" if i % 2 else "blue"))
PY
}

measure() { # label count command...
    local label=$1 n=$2
    shift 2
    /usr/bin/time -f '%U %S %M' -o "$dir/time" "$@" >/dev/null 2>"$dir/err" || {
        echo "$label failed:" >&2
        tail -5 "$dir/err" >&2
        return 1
    }
    read -r user sys kb <"$dir/time"
    awk -v l="$label" -v n="$n" -v u="$user" -v s="$sys" -v kb="$kb" -v lines="$((n + 6))" \
        'BEGIN { cpu = u + s; rate = "";
                 if (l == "check") rate = cpu >= 0.01 ? sprintf("  %5.2f M lines/s", lines / cpu / 1e6) : "  (too fast to time)";
                 printf "%-7s %9d spheres  %7.2f CPU s  %8.1f MiB peak  %6.0f B/sphere%s\n",
                 l, n, cpu, kb / 1024, kb * 1024 / n, rate }'
}

for n in "${counts[@]}"; do
    f="$dir/spheres-$n.sdf"
    gen "$n" "$f"
    measure check "$n" "$bin" check -q "$f"
    measure render "$n" "$bin" render -q --spp 1 --out "$dir" "$f"
done

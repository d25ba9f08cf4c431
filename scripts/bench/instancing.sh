#!/usr/bin/env bash
# Instancing (BENCHMARKS.md, "Instancing"): whole-process CPU seconds (user + system) and peak
# RSS, both from /usr/bin/time, of `anim check` and `anim render` on three generated scenes,
# for each binary given, in turns (ROUNDS rounds, default 2):
#   chain20: a chain of composites 250 deep over one sphere that doubles at 20 levels
#            (2^20 spheres flattened), 64×48 at 1 spp;
#   chain16: the same with 16 doublings, 120 deep (65 536 spheres), 160×120, adaptive;
#            run again with `--max-memory 1G`, which makes it worth instancing;
#   blob:    1000 uses of a composite of 1000 spheres (10^6 flattened), 320×240, adaptive.
# Images of the same scene are compared byte for byte between binaries (md5 at the end).
#
#   scripts/bench/instancing.sh BINARY...     # e.g. an old build, then a new one
#   ANIM=/path/to/anim scripts/bench/instancing.sh
#
# Environment: ANIM (the binary when none is given as an argument; default: `cargo build
# --release`, then target/release/anim), ROUNDS (default 2). Scenes and images live in a
# temporary folder.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
if [ $# -eq 0 ]; then
    if [ -n "${ANIM:-}" ]; then
        set -- "$ANIM"
    else
        cargo build --release --quiet --manifest-path "$root/Cargo.toml"
        set -- "$root/target/release/anim"
    fi
fi

dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

chain() { # doublings depth width height
    python3 - "$@" <<'PY'
import sys
D, depth, w, h = int(sys.argv[1]), int(sys.argv[2]), sys.argv[3], sys.argv[4]
out = ["define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20",
       "define light sun 0 50 500 1 1 1 1", "ambient 0.2 0.2 0.2",
       "define camera eye 60 0 0 0 0 0 -1 0 1 0",
       f"transform eye translate {2.5*2**(D//2)/2} {2.5*2**((D+1)//2)/2} {2.5*2**(D//2)*1.3}",
       f"render eye image.ppm {w} {h}",
       "define shape sphere s 0 0 0 1 red", "define shape composite c0 s"]
passes = depth - 1 - 2 * D
prev, n = "c0", 0
for k in range(1, D + 1):
    for j in range(passes // D + (1 if k - 1 < passes % D else 0)):
        n += 1
        out += [f"define shape composite p{n} {prev}",
                f"transform p{n} translate 0 0 {0.001 if n % 2 else -0.001}"]
        prev = f"p{n}"
    shift = 2.5 * 2 ** ((k - 1) // 2)
    out += [f"define shape composite a{k} {prev}", f"define shape composite b{k} {prev}",
            f"transform b{k} translate {shift if k % 2 else 0} {0 if k % 2 else shift} 0",
            f"define shape composite c{k} a{k} b{k}"]
    prev = f"c{k}"
out.append(f"define shape composite root {prev}")
print("\n".join(out))
PY
}

blob() {
    python3 - <<'PY'
out = ["define material red 0.2 0 0 0.8 0.1 0.1 0.5 0.5 0.5 20",
       "define light sun 0 500 500 1 1 1 1", "ambient 0.2 0.2 0.2",
       "define camera eye 60 0 0 0 0 0 -1 0 1 0", "transform eye translate 50 50 260",
       "render eye image.ppm 320 240"]
cell = lambda i: (i % 10, i // 10 % 10, i // 100)
for i in range(1000):
    x, y, z = cell(i)
    out.append(f"define shape sphere s{i} {x*0.9} {y*0.9} {z*0.9} 0.4 red")
out.append("define shape composite blob " + " ".join(f"s{i}" for i in range(1000)))
for i in range(1000):
    x, y, z = cell(i)
    out += [f"define shape composite w{i} blob", f"transform w{i} translate {x*10} {y*10} {-z*10}"]
out.append("define shape composite root " + " ".join(f"w{i}" for i in range(1000)))
print("\n".join(out))
PY
}

chain 20 250 64 48 >"$dir/chain20.sdf"
chain 16 120 160 120 >"$dir/chain16.sdf"
blob >"$dir/blob.sdf"

run() { # label binary args...
    local label=$1 bin=$2
    shift 2
    local rc=0
    (cd "$dir" && /usr/bin/time -o "$dir/time" -f '%U %S %M' "$bin" "$@" >/dev/null 2>&1) || rc=$?
    read -r user sys rss < <(tail -n 1 "$dir/time")
    printf '%-44s %-28s exit %d  CPU %6.2f s  RSS %8d KB\n' "$label" "$tag" "$rc" \
        "$(awk -v u="$user" -v s="$sys" 'BEGIN { print u + s }')" "$rss"
}

for ((round = 1; round <= ${ROUNDS:-2}; round++)); do
    echo "round $round"
    i=0
    for bin in "$@"; do
        bin=$(realpath "$bin")
        # The binary's place in the list, so that two binaries named alike keep their images apart.
        i=$((i + 1))
        tag=$i-$(basename "$bin")
        run "check chain20" "$bin" check -q chain20.sdf
        run "render chain20 --spp 1" "$bin" render -q --spp 1 chain20.sdf
        run "render chain16" "$bin" render -q chain16.sdf
        cp "$dir/image.ppm" "$dir/chain16-$tag.ppm" 2>/dev/null || true
        run "render chain16 --max-memory 1G" "$bin" render -q --max-memory 1G chain16.sdf
        cp "$dir/image.ppm" "$dir/chain16-1G-$tag.ppm" 2>/dev/null || true
        run "check blob" "$bin" check -q blob.sdf
        run "render blob" "$bin" render -q blob.sdf
        cp "$dir/image.ppm" "$dir/blob-$tag.ppm" 2>/dev/null || true
    done
done
(cd "$dir" && md5sum chain16-*.ppm blob-*.ppm)

#!/usr/bin/env bash
# Two builds of anim on two BVH-bound scenes, in turns (old, new, old, new, ...): 10k spheres
# in a deep grid at 1280×720, and 100k random spheres at 640×360, both `--spp 1` (scenes
# written by this script; history: docs/benchmarks-history.md §6 and §9). Reports
# whole-process CPU seconds (user + system, from /usr/bin/time, so parsing and the BVH build
# count too), the best of RUNS (default 3) per build, the new/old ratio, rays per CPU-second
# from the render summary's ray counts, and the same for a 2×2 image (the setup alone). Warns
# when the two builds' ray counts or images differ.
#
#   scripts/bench/bvh.sh                             # base: merge-base of HEAD and main
#   BASE=<rev> RUNS=5 scripts/bench/bvh.sh
#   ANIM=/path/new/anim BASE_ANIM=/path/old/anim scripts/bench/bvh.sh   # nothing built
#
# Environment: ANIM (the new binary; default: `cargo build --release`, then
# target/release/anim), BASE_ANIM (the old binary; default: BASE built as below), BASE (the
# revision to build when BASE_ANIM is unset; default the merge-base of HEAD and main), RUNS
# (default 3), WORK (scenes, images and logs, default target/bvh-bench).
#
# Without BASE_ANIM the base is exported with `git archive` into target/bvh-base-src (a fixed
# place, so a second run does not rebuild it) and built with CARGO_TARGET_DIR=target-base.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
runs=${RUNS:-3}
# Scenes and images stay in WORK for a closer look.
work=${WORK:-$root/target/bvh-bench}
mkdir -p "$work"

if [ -n "${BASE_ANIM:-}" ]; then
  old=$BASE_ANIM
  base_name=$old
else
  base=${BASE:-$(git -C "$root" merge-base HEAD main)}
  base_name=$(git -C "$root" rev-parse --short "$base")
  src=$root/target/bvh-base-src
  rm -rf "$src" && mkdir -p "$src"
  git -C "$root" archive "$base" | tar -x -C "$src"
  CARGO_TARGET_DIR=$root/target-base cargo build --release --quiet --manifest-path "$src/Cargo.toml"
  old=$root/target-base/release/anim
fi
if [ -n "${ANIM:-}" ]; then
  new=$ANIM
else
  cargo build --release --quiet --manifest-path "$root/Cargo.toml"
  new=$root/target/release/anim
fi

python3 - "$work" <<'PY'
import random, sys
work = sys.argv[1]
head = """define material matte 0.2 0.3 0.6 0.5 0.6 0.9 0.3 0.3 0.3 20
define material mirror 0.3 0.2 0.1 0.8 0.5 0.3 0.5 0.5 0.5 60 0.4
define light key 40 60 40 1 1 1 1
define light fill -50 20 10 0.5 0.5 0.6 1
ambient 0.1 0.1 0.1
"""
# 20 x 10 x 50 spheres receding from the camera along -z: most rays cross many boxes.
with open(f"{work}/grid.sdf", "w") as f:
    f.write(head)
    n = 0
    for x in range(20):
        for y in range(10):
            for z in range(50):
                mat = "mirror" if (x + y + z) % 5 == 0 else "matte"
                f.write(f"define shape sphere s{n} {x - 9.5} {y - 4.5} {-3 - 2 * z} 0.25 {mat}\n")
                n += 1
    f.write("define camera eye 60 0 0 8\nrender eye grid.ppm 1280 720\n")
rng = random.Random(1)
with open(f"{work}/random.sdf", "w") as f:
    f.write(head)
    for n in range(100_000):
        x, y, z = (rng.uniform(-60, 60), rng.uniform(-35, 35), rng.uniform(-160, -40))
        mat = "mirror" if n % 5 == 0 else "matte"
        f.write(f"define shape sphere s{n} {x:.3f} {y:.3f} {z:.3f} {rng.uniform(0.1, 0.5):.3f} {mat}\n")
    f.write("define camera eye 60\nrender eye random.ppm 640 360\n")
PY

# One render into $work/out-TAG; prints "cpu_seconds rays". Extra arguments go to `anim render`.
run() {
  local bin=$1 tag=$2 scene=$3
  shift 3
  /usr/bin/time -f 'cpu %U %S' -o "$work/time" "$bin" render "$work/$scene.sdf" --spp 1 --force "$@" \
    --out "$work/out-$tag" 2>"$work/log"
  local rays
  rays=$(sed -n 's/.*(primary \([0-9]*\), shadow \([0-9]*\), reflected \([0-9]*\), refracted \([0-9]*\)).*/\1 \2 \3 \4/p' "$work/log" |
    awk '{ print $1 + $2 + $3 + $4 }')
  awk -v rays="$rays" '/^cpu/ { print $2 + $3, rays }' "$work/time"
}

min() { printf '%s\n' "$@" | sort -g | head -n 1; }

printf 'base %s, %d runs each, alternating; best CPU seconds (user+sys)\n' "$base_name" "$runs"
for scene in grid random; do
  old_t=(); new_t=(); old_s=(); new_s=(); rays_old=; rays_new=
  for ((r = 0; r < runs; r++)); do
    read -r t rays_old < <(run "$old" old "$scene"); old_t+=("$t")
    read -r t rays_new < <(run "$new" new "$scene"); new_t+=("$t")
    # The fixed cost (parse, compile, BVH build) of a 2×2 image, to see the tracing alone.
    read -r t _ < <(run "$old" old-setup "$scene" --width 2 --height 2); old_s+=("$t")
    read -r t _ < <(run "$new" new-setup "$scene" --width 2 --height 2); new_s+=("$t")
  done
  o=$(min "${old_t[@]}"); n=$(min "${new_t[@]}"); os=$(min "${old_s[@]}"); ns=$(min "${new_s[@]}")
  [ "$rays_old" = "$rays_new" ] || echo "warning: ray counts differ ($rays_old vs $rays_new)"
  if ! cmp -s "$work/out-old/$scene.ppm" "$work/out-new/$scene.ppm"; then
    echo "warning: $scene images differ"
  fi
  awk -v s="$scene" -v o="$o" -v n="$n" -v os="$os" -v ns="$ns" -v r="$rays_new" 'BEGIN {
    printf "%-7s rays %d: old %.2f CPU-s (%.2f Mrays/CPU-s), new %.2f CPU-s (%.2f Mrays/CPU-s), new/old %.3f\n",
      s, r, o, r / o / 1e6, n, r / n / 1e6, n / o
    printf "%-7s setup (2x2 image): old %.2f, new %.2f CPU-s; tracing alone: old %.2f, new %.2f CPU-s (%.2f vs %.2f Mrays/CPU-s), new/old %.3f\n",
      s, os, ns, o - os, n - ns, r / (o - os) / 1e6, r / (n - ns) / 1e6, (n - ns) / (o - os) }'
done

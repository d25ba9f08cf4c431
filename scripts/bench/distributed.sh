#!/usr/bin/env bash
# Time against error of soft shadows and depth of field (BENCHMARKS.md, "Soft shadows, spots
# and depth of field"): `anim bench` over two scenes written here, anim against POV-Ray's
# adaptive area light and focal blur, each renderer against its own converged image, one
# thread, both timed as whole processes.
#
#   scripts/bench/distributed.sh [extra anim bench options, e.g. --turns 5 or --no-pov]
#
# - soft-room: a matte room (floor, back wall, two balls, a box) under a spherical light of
#   radius 1.5 (ks = 0); POV-Ray: a `circular orient jitter` area light of its diameter, the
#   ladder SOFT_LADDER below (grid, adaptive level, anti-aliasing);
# - dof: balls from 4 to 40 units deep along a floor, a lens of aperture 0.25 focused at 10;
#   POV-Ray: focal_blur, the ladder DOF_LADDER (blur_samples, confidence, variance).
# anim runs the bench preset's settings (uniform 1…64 spp, error targets 8…0.5, 2 the default).
# Each scene is its own `anim bench` run, so that each takes only its own POV-Ray ladder; the
# reports go to OUT/report/soft-room and OUT/report/dof.
# Environment: ANIM (binary; default: `cargo build --release`, then target/release/anim),
# OUT (work folder with the scenes and the reports; default a temporary one, kept),
# WIDTH and HEIGHT (default 320 × 180), SHARED (folder holding tools/sdf2pov.py; default
# ../shared beside the repository), CACHE (converged images; default target/anim-bench-cache).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
if [ -n "${ANIM:-}" ]; then
  anim=$ANIM
else
  cargo build --release --quiet --manifest-path "$root/Cargo.toml"
  anim=$root/target/release/anim
fi
out=${OUT:-$(mktemp -d)}
mkdir -p "$out/scenes"
cat > "$out/scenes/soft-room.sdf" <<'SDF'
define material floor 0.2 0.2 0.2 0.7 0.7 0.7 0 0 0 1
define material wall 0.2 0.2 0.2 0.6 0.6 0.5 0 0 0 1
define material red 0.2 0.05 0.05 0.8 0.2 0.2 0 0 0 1
define material blue 0.05 0.05 0.2 0.2 0.3 0.8 0 0 0 1
define shape box ground -20 -1 -30 20 0 5 floor
define shape box back -20 0 -31 20 15 -30 wall
define shape sphere ball -2 1.5 -12 1.5 red
define shape sphere small 2.5 0.8 -9 0.8 blue
define shape box crate 4 0 -16 7 3 -13 wall
define light key -3 9 -6 1 1 1 1.2 radius 1.5
ambient 0.3 0.3 0.3
define camera eye 60 0 5 4 0 -0.35 -1 0 1 0
render eye soft-room.png 320 180
SDF
cat > "$out/scenes/dof.sdf" <<'SDF'
define material floor 0.2 0.2 0.2 0.6 0.6 0.6 0 0 0 1
define material a 0.2 0.1 0.05 0.8 0.4 0.2 0 0 0 1
define material b 0.05 0.1 0.2 0.2 0.4 0.8 0 0 0 1
define shape box ground -30 -1 -60 30 0 5 floor
define shape sphere s1 -1.5 0.5 -4 0.5 a
define shape sphere s2 1 0.7 -7 0.7 b
define shape sphere s3 -1 1 -10 1 a
define shape sphere s4 2.5 1 -15 1 b
define shape sphere s5 -3 1.5 -24 1.5 a
define shape sphere s6 4 2 -40 2 b
define light key 5 10 5 1 1 1 1
ambient 0.3 0.3 0.3
background 0.3 0.4 0.6
define camera eye 50 0 2 2 0 -0.1 -1 0 1 0
lens eye 0.25 10
render eye dof.png 320 180
SDF
# POV-Ray's ladders: one --pov-setting each (flags, then `anim bench --help`'s sampling words).
SOFT_LADDER=(
  "-A area=5 adaptive=1" "-A area=9 adaptive=1" "-A area=17 adaptive=2"
  "+A0.3 area=5 adaptive=1" "+A0.3 area=9 adaptive=1" "+A0.3 area=17 adaptive=2"
  "+A0.1 area=9 adaptive=1" "+A0.1 area=17 adaptive=2" "+A0.1 area=17 adaptive=3"
  "+A0.1 area=4" "+A0.1 area=8"
  "+A0.1 +AM2 +R3 area=9 adaptive=1" "+A0.05 +AM2 +R3 area=17 adaptive=2"
)
DOF_LADDER=(
  "-A blur=8" "-A blur=16" "-A blur=32" "-A blur=64" "-A blur=128"
  "-A blur=16 confidence=0.99 variance=0.0001" "-A blur=32 confidence=0.99 variance=0.0001"
  "-A blur=64 confidence=0.99 variance=0.0001" "-A blur=128 confidence=0.99 variance=0.0001"
  "+A0.3 blur=16" "+A0.3 blur=32"
)
bench() { # SCENE LADDER...
  local scene=$1 args=()
  shift
  for s in "$@"; do args+=(--pov-setting "$s"); done
  "$anim" bench --scenes "$out/scenes" --scene "$scene" --threads 1 --whole-process \
    --width "${WIDTH:-320}" --height "${HEIGHT:-180}" \
    --pov-tools "${SHARED:-$root/../shared}/tools" \
    --cache "${CACHE:-$root/target/anim-bench-cache}" \
    --out "$out/report/$scene" "${args[@]}" "${EXTRA[@]}"
}
EXTRA=("$@")
bench soft-room "${SOFT_LADDER[@]}"
bench dof "${DOF_LADDER[@]}"
echo "reports: $out/report/soft-room, $out/report/dof"

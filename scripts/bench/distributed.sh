#!/usr/bin/env bash
# Time against error of soft shadows and depth of field (BENCHMARKS.md, "Soft shadows and
# depth of field"): `anim bench` over two scenes written here, each against its own converged
# image (--spp 1024), one thread. anim alone: the bench's POV-Ray conversion (sdf2pov.py) knows
# neither spherical lights nor lenses, so POV-Ray's area light and focal blur are not on it.
#
#   scripts/bench/distributed.sh [extra anim bench options, e.g. --turns 5]
#
# - soft-room: a matte room (floor, back wall, two balls, a box) under a spherical light of
#   radius 1.5 (ks = 0);
# - dof: balls from 4 to 40 units deep along a floor, a lens of aperture 0.25 focused at 10.
# Environment: ANIM (binary; default: `cargo build --release`, then target/release/anim),
# OUT (work folder with the scenes and the report; default a temporary one, kept),
# WIDTH and HEIGHT (default 320 × 180).
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
"$anim" bench --scenes "$out/scenes" --threads 1 --no-pov \
  --width "${WIDTH:-320}" --height "${HEIGHT:-180}" --out "$out/report" "$@"
echo "report: $out/report"

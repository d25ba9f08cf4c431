#!/usr/bin/env bash
# The README's motion blur strip (not a timing): three frames of animations/blur.ron with the
# shutter at 0 and at 0.5 (as the spec has it), at 240×135, side by side, into docs/blur/
# (shutter-0.png and shutter-0.5.png). ffmpeg puts the frames side by side.
#
#   scripts/bench/blur-strip.sh [FRAME FRAME FRAME]     # default: 8 44 76
#   OUT=/tmp/strip ANIM=/path/to/anim scripts/bench/blur-strip.sh
#
# Frames 8 and 44: the ball shoots right, then back left, the pinwheel spins, the camera and
# everything else are still; frame 76: the camera dollies. Environment: ANIM (binary;
# default: `cargo build --release`, then target/release/anim), OUT (folder for the two
# strips, default docs/blur of the repository).
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
frames=("$@")
[ ${#frames[@]} -gt 0 ] || frames=(8 44 76)
if [ -n "${ANIM:-}" ]; then
  anim=$ANIM
else
  cargo build --release --quiet --manifest-path "$root/Cargo.toml"
  anim=$root/target/release/anim
fi
out=${OUT:-$root/docs/blur}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cp "$root/animations/blur.sdf" "$work/"
grep -v '^ *shutter:' "$root/animations/blur.ron" >"$work/still.ron"
"$anim" generate "$root/animations/blur.ron" -o "$work/blurred" --quiet
"$anim" generate "$work/still.ron" -o "$work/still" --quiet
mkdir -p "$out"
for kind in still blurred; do
  inputs=()
  for f in "${frames[@]}"; do
    file=$(printf '%s/%s/frame_%04d.sdf' "$work" "$kind" "$f")
    "$anim" render "$file" --width 240 --height 135 --quiet
    inputs+=(-i "${file%.sdf}.png")
  done
  name=$([ "$kind" = still ] && echo shutter-0 || echo shutter-0.5)
  ffmpeg -v error -y "${inputs[@]}" -filter_complex "hstack=inputs=${#frames[@]}" \
    "$out/$name.png"
  echo "wrote $out/$name.png ($(stat -c %s "$out/$name.png") bytes)"
done

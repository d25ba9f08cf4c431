#!/usr/bin/env bash
# Per-pixel data for studying adaptive sampling's stopping rule offline (BENCHMARKS.md, "Time
# against error"; docs/benchmarks-history.md §4.9). ANIM must be a build with dump.patch
# applied, which makes every refined pixel also take 128 samples of its own pattern and print,
# at each power of two, its mean, its error estimate and the rays spent (the image itself is
# the normal one). For the bench scenes (the held-out room among them), at 640×360 on one
# thread:
#   OUT/NAME.dump  the refined pixels' lines      OUT/NAME.ppm  the default render
#   OUT/NAME.log   its render summary (rays)      OUT/NAME.ref.ppm  a converged render
#
#   git apply scripts/bench/stopping-rules/dump.patch && cargo build --release &&
#     cp target/release/anim /tmp/anim-dump && git checkout crates/anim-core
#   ANIM=/tmp/anim-dump scripts/bench/stopping-rules/dump.sh OUT
#   python3 scripts/bench/stopping-rules/score.py OUT      # needs numpy
#
# Environment: ANIM (required), REF_SPP (samples of the converged renders, default 1024;
# they are kept and reused when OUT already holds them), SIZE (default "640 360").
set -euo pipefail
root=$(cd "$(dirname "$0")/../../.." && pwd)
: "${ANIM:?set ANIM to a build with dump.patch applied}"
out=${1:?usage: dump.sh OUT}
mkdir -p "$out"
read -r W H <<<"${SIZE:-640 360}"
for scene in "$root"/scenes/bench/*.sdf; do
  name=$(basename "$scene" .sdf)
  work=$(mktemp -d)
  # A copy whose render line writes image.ppm, which score.py reads without an image library.
  sed -E 's/^(render[[:space:]]+[^[:space:]]+[[:space:]]+)[^[:space:]]+/\1image.ppm/' "$scene" >"$work/scene.sdf"
  if [ ! -f "$out/$name.ref.ppm" ]; then
    "$ANIM" render "$work/scene.sdf" --width "$W" --height "$H" --spp "${REF_SPP:-1024}" \
      --out "$work/ref" -q
    mv "$work/ref/image.ppm" "$out/$name.ref.ppm"
  fi
  ANIM_DUMP_REFINED=1 "$ANIM" render "$work/scene.sdf" --width "$W" --height "$H" --threads 1 \
    --out "$work/img" 2>"$work/err"
  grep '^DUMP ' "$work/err" | cut -c6- >"$out/$name.dump"
  grep -v '^DUMP ' "$work/err" >"$out/$name.log"
  mv "$work/img/image.ppm" "$out/$name.ppm"
  rm -rf "$work"
  echo "$name: $(wc -l <"$out/$name.dump") refined pixels"
done

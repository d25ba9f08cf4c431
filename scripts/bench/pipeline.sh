#!/usr/bin/env bash
# The frame pipeline (BENCHMARKS.md, "The frame pipeline"): the benchmark animation
# (animations/assignment-orbit.ron: 120 frames of the assignment's example scene, 640×360,
# 1 sample per pixel) through anim generate + anim render + scripts/encode.sh, each stage and
# in total, in wall-clock seconds (`date +%s.%N` around each stage: the pipeline is what a
# user waits for), best of RUNS (default 3). With POV-Ray 3.7 and SHARED/tools present, also
# renders the same orbit with POV-Ray (two threads, no anti-aliasing; wall seconds, best of
# RUNS) for comparison in the same run. Needs ffmpeg (scripts/encode.sh) and bc.
#
#   scripts/bench/pipeline.sh
#   RUNS=1 ANIM=/path/to/anim scripts/bench/pipeline.sh
#
# Environment: ANIM (binary; default: `cargo build --release`, then target/release/anim), RUNS
# (default 3), SHARED (the folder holding tools/sdf2pov.py, default ../shared beside the
# repository; without it, or without povray, anim alone). Frames and video live in a
# temporary folder.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
runs=${RUNS:-3}
if [ -n "${ANIM:-}" ]; then
  anim=$(realpath "$ANIM")
else
  cargo build --release --quiet --manifest-path "$root/Cargo.toml"
  anim=$root/target/release/anim
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

now() { date +%s.%N; }
best() { printf '%s\n' "$@" | sort -g | head -n 1; }

gen=(); ren=(); enc=(); tot=()
for ((r = 0; r < runs; r++)); do
  rm -rf "$work/frames"
  t0=$(now)
  "$anim" generate "$root/animations/assignment-orbit.ron" -o "$work/frames" -q
  t1=$(now)
  "$anim" render "$work/frames" -q
  t2=$(now)
  "$root/scripts/encode.sh" "$work/frames" "$work/animation.mp4" >/dev/null
  t3=$(now)
  gen+=("$(echo "$t1 - $t0" | bc)"); ren+=("$(echo "$t2 - $t1" | bc)")
  enc+=("$(echo "$t3 - $t2" | bc)"); tot+=("$(echo "$t3 - $t0" | bc)")
done
printf 'anim, best of %d: generate %.2f s, render %.2f s, encode %.2f s, total %.2f s\n' \
  "$runs" "$(best "${gen[@]}")" "$(best "${ren[@]}")" "$(best "${enc[@]}")" "$(best "${tot[@]}")"

tools=${SHARED:-$root/../shared}/tools
if command -v povray >/dev/null && [ -f "$tools/sdf2pov.py" ]; then
  cd "$work"
  python3 "$tools/sdf2pov.py" "$root/scenes/assignment.sdf" --orbit 0 0 -150 450 150 \
    --width 640 --height 360 -o orbit.pov
  povt=()
  for ((r = 0; r < runs; r++)); do
    t0=$(now)
    povray -D +WT2 -A File_Gamma=1.0 +W640 +H360 +FN +KFI1 +KFF120 +KC +Opov_ orbit.pov 2>/dev/null
    t1=$(now)
    povt+=("$(echo "$t1 - $t0" | bc)")
  done
  printf 'POV-Ray 3.7, same 120 frames, best of %d: %.2f s\n' "$runs" "$(best "${povt[@]}")"
else
  echo "note: povray or $tools/sdf2pov.py not found (set SHARED to the folder holding tools/): anim only" >&2
fi

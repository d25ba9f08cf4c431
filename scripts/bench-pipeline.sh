#!/usr/bin/env bash
# Times the whole pipeline on the benchmark animation (animations/assignment-orbit.ron:
# 120 frames of the assignment's example scene, 640×360, 1 sample per pixel):
# anim generate + anim render + scripts/encode.sh, each stage and in total, best of RUNS
# (default 3). With POV-Ray 3.7 and ../shared/tools present, also renders the same orbit with
# POV-Ray (two threads, no anti-aliasing) for comparison in the same run.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
runs=${RUNS:-3}
cargo build --release --quiet --manifest-path "$root/Cargo.toml"
anim=$root/target/release/anim
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

tools=$root/../shared/tools
if command -v povray >/dev/null && [ -d "$tools" ]; then
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
fi

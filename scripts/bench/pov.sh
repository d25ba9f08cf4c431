#!/usr/bin/env bash
# Speed against POV-Ray 3.7 (BENCHMARKS.md, "Speed against POV-Ray"): anim and `povray`
# render the same scenes in turns (anim, POV, anim, POV, ... RUNS times each, default 3), and
# a table gives whole-process CPU seconds (user + system from /usr/bin/time, the median of the
# runs), their ratio, anim's rays per CPU-second (from the ray counts its render summary
# prints) and anim's peak RSS (/usr/bin/time's %M).
#
#   scripts/bench/pov.sh                 # RUNS=3; tools from ../shared beside the repository
#   RUNS=5 SHARED=/path/to/shared scripts/bench/pov.sh
#   ANIM=/path/to/other/anim scripts/bench/pov.sh   # another build of anim (not rebuilt)
#
# Environment: ANIM (binary; default: `cargo build --release`, then target/release/anim), RUNS
# (default 3), SHARED (the folder holding tools/sdf2pov.py, default ../shared beside the
# repository; without it, or without povray, anim alone), WORK (scenes, images and logs,
# default target/pov-bench).
#
# Scenes: the assignment example at 1920×1080, 1 spp; 10k spheres in a deep grid at 1280×720,
# 1 spp; 1k and 100k random spheres at 640×360, 1 spp; the mirror and glass room at 1280×720,
# 9 spp; 10⁶ random spheres (anim only: POV-Ray's parser alone takes minutes there). The
# generated ones come from scripts/bench/gen-scenes.py (fixed seeds) into $WORK, where images
# and logs stay for a closer look.
#
# POV-Ray gets the scene from SHARED/tools/sdf2pov.py (same geometry, camera, lights and
# Phong terms), two threads (+WT2, anim uses one per core on the 2-core machine) and no
# display (-D). 1 spp is `-A` (one ray through each pixel). For 9 spp the equivalent chosen is
# `+A0.0 +AM1 +R3`: method 1 with threshold 0 supersamples every pixel that differs at all
# from its neighbours with a 3×3 grid, i.e. 9 rays per pixel like anim's `--spp 9` 3×3
# stratified grid (plus the one corner ray per pixel POV traces first to decide, and minus the
# pixels exactly equal to all their neighbours, which it leaves at one ray). Adaptive method 2
# would spend a different number of rays per pixel and so measure a different thing.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
runs=${RUNS:-3}
shared=${SHARED:-$root/../shared}
work=${WORK:-$root/target/pov-bench}
mkdir -p "$work/scenes" "$work/anim" "$work/pov"

pov=yes
if [ ! -f "$shared/tools/sdf2pov.py" ]; then
  echo "note: $shared/tools/sdf2pov.py not found (set SHARED to the folder holding tools/): anim only" >&2
  pov=no
elif ! command -v povray >/dev/null; then
  echo "note: povray is not installed: anim only" >&2
  pov=no
fi

if [ -n "${ANIM:-}" ]; then
  anim=$ANIM
else
  cargo build --release --quiet --manifest-path "$root/Cargo.toml"
  anim=$root/target/release/anim
fi
python3 "$root/scripts/bench/gen-scenes.py" "$work/scenes"

# name file width height spp pov(yes/no)
scenes=(
  "assignment $root/scenes/assignment.sdf 1920 1080 1 yes"
  "grid10k $work/scenes/grid10k.sdf 1280 720 1 yes"
  "random1k $work/scenes/random1k.sdf 640 360 1 yes"
  "random100k $work/scenes/random100k.sdf 640 360 1 yes"
  "mirror-glass $root/scenes/bench/mirror-glass.sdf 1280 720 9 yes"
  "random1m $work/scenes/random1m.sdf 640 360 1 no"
)

median() { printf '%s\n' "$@" | sort -g | awk '{ v[NR] = $1 } END { print v[int((NR + 1) / 2)] }'; }

# One anim render; prints "cpu_seconds rays peak_rss_kb", or "refused" (and the reason on
# stderr) when anim exits non-zero.
run_anim() {
  local name=$1 file=$2 w=$3 h=$4 spp=$5
  if ! /usr/bin/time -f 'cpu %U %S %M' -o "$work/anim/$name.time" "$anim" render "$file" \
    --spp "$spp" --width "$w" --height "$h" --force --out "$work/anim" 2>"$work/anim/$name.log"; then
    grep -m1 'error' "$work/anim/$name.log" | sed "s|^|$name refused: |" >&2 || true
    echo refused
    return
  fi
  local rays
  rays=$(sed -n 's/.*(primary \([0-9]*\), shadow \([0-9]*\), reflected \([0-9]*\), refracted \([0-9]*\)).*/\1 \2 \3 \4/p' \
    "$work/anim/$name.log" | awk '{ print $1 + $2 + $3 + $4 }')
  awk -v rays="$rays" '/^cpu/ { print $2 + $3, rays, $4 }' "$work/anim/$name.time"
}

# One POV-Ray render of the converted scene; prints its CPU seconds.
run_pov() {
  local name=$1 w=$2 h=$3 spp=$4
  local aa=(-A)
  [ "$spp" = 9 ] && aa=(+A0.0 +AM1 +R3)
  (cd "$work/pov" && /usr/bin/time -f 'cpu %U %S' -o "$name.time" povray -D +WT2 "${aa[@]}" \
    File_Gamma=1.0 "+W$w" "+H$h" +FN "+O$name.png" "$name.pov" >"$name.log" 2>&1)
  awk '/^cpu/ { print $2 + $3 }' "$work/pov/$name.time"
}

printf '%d runs each, in turns; CPU seconds = user + system of the whole process, median\n\n' "$runs"
printf '| scene | size, spp | anim CPU s | POV CPU s | anim/POV | anim M rays per CPU s | anim peak RSS MB |\n'
printf '|---|---|---:|---:|---:|---:|---:|\n'
declare -A anim_cpu
for entry in "${scenes[@]}"; do
  read -r name file w h spp with_pov <<<"$entry"
  [ "$pov" = yes ] && [ "$with_pov" = yes ] &&
    python3 "$shared/tools/sdf2pov.py" "$file" --width "$w" --height "$h" -o "$work/pov/$name.pov"
  a=(); p=(); rss=(); rays=; refused=no
  for ((r = 0; r < runs; r++)); do
    out=$(run_anim "$name" "$file" "$w" "$h" "$spp")
    if [ "$out" = refused ]; then refused=yes; break; fi
    read -r t rays m <<<"$out"
    a+=("$t"); rss+=("$m")
    if [ "$pov" = yes ] && [ "$with_pov" = yes ]; then p+=("$(run_pov "$name" "$w" "$h" "$spp")"); fi
  done
  if [ "$refused" = yes ]; then
    printf '| %s | %s×%s, %s | refused | – | – | – | – |\n' "$name" "$w" "$h" "$spp"
    continue
  fi
  at=$(median "${a[@]}"); am=$(median "${rss[@]}")
  anim_cpu[$name]=$at
  if [ ${#p[@]} -gt 0 ]; then
    pt=$(median "${p[@]}")
    ratio=$(awk -v a="$at" -v p="$pt" 'BEGIN { printf "%.2f", a / p }')
  else
    pt=–; ratio=–
  fi
  awk -v n="$name" -v w="$w" -v h="$h" -v s="$spp" -v a="$at" -v p="$pt" -v q="$ratio" \
    -v rays="$rays" -v m="$am" 'BEGIN {
      printf "| %s | %s×%s, %s | %.2f | %s | %s | %.2f | %.0f |\n", n, w, h, s, a, p, q, rays / a / 1e6, m / 1024 }'
done
if [ -n "${anim_cpu[random1k]:-}" ] && [ -n "${anim_cpu[random100k]:-}" ]; then
  awk -v a="${anim_cpu[random1k]}" -v b="${anim_cpu[random100k]}" 'BEGIN {
    printf "\nanim CPU, 100k random spheres / 1k random spheres: %.2f (100× the spheres)\n", b / a }'
fi

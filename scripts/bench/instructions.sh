#!/usr/bin/env bash
# Instructions per render, for one build of anim or two side by side: the measurement that a
# refactoring of the render core is held to (BENCHMARKS.md, "The render core"). Instruction
# counts (valgrind --tool=callgrind, one worker thread) are the same from run to run whatever
# else the machine does, so a change of 1 % shows, where whole-process CPU seconds on a shared
# machine do not resolve it. Every image is compared byte for byte between the two builds.
#
#   scripts/bench/instructions.sh NEW [BASE]     # binaries; BASE adds a ratio column
#
# Environment: OUT (work folder, default target/bench-instructions), CASES (space-separated
# names to run a subset), SET (which cases, default `core`):
# - `core`: each kind of scene the render core treats apart: a handful of shapes (flat), a
#   room of mirrors and glass (flat, deep trees), the showcase (transformed shapes and glass
#   under a hierarchy), random spheres from a thousand to a hundred thousand (image tiles), a
#   deep grid (camera packets), a mesh, instanced composites and a motion-blurred frame; at
#   one sample per pixel and at the default adaptive settings;
# - `pov`: the scenes and settings of scripts/bench/pov.sh (speed against POV-Ray);
# - `adaptive`: the default and `--spp 1` runs of BENCHMARKS.md's "Time against error"
#   (`anim bench --whole-process`) on its three scenes at 640×360.
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
new=${1:?usage: scripts/bench/instructions.sh NEW [BASE]}
base=${2:-}
out=${OUT:-$root/target/bench-instructions}
mkdir -p "$out/scenes"
command -v valgrind >/dev/null || { echo "needs valgrind (apt-get install valgrind)" >&2; exit 1; }

python3 "$root/scripts/bench/gen-scenes.py" "$out/scenes"
# Frame 72 of the motion-blur animation: every kind of motion is in the shutter there.
if [ ! -f "$out/scenes/blur/frame_0072.sdf" ]; then
  sed "s|scene: File(\"blur.sdf\")|scene: File(\"$root/animations/blur.sdf\")|" \
    "$root/animations/blur.ron" >"$out/scenes/blur.ron"
  "$new" generate "$out/scenes/blur.ron" --out "$out/scenes/blur" -q
fi
# Instanced composites: 64 uses of a composite of 64 spheres, each use turned (kept as
# prototypes under a 64M memory budget).
python3 - "$out/scenes/instances.sdf" <<'PY'
import sys
lines = ["define material m 0.1 0.1 0.1 0.6 0.5 0.4 0.4 0.4 0.4 30",
         "define light key 20 30 20 1 1 1 1", "ambient 0.1 0.1 0.1",
         "define camera eye 50 0 0 30 0 0 -1 0 1 0", "render eye instances.png 640 360"]
balls = []
for i in range(64):
    x, y, z = i % 4, (i // 4) % 4, i // 16
    lines.append(f"define shape sphere s{i} {x} {y} {z} 0.4 m")
    balls.append(f"s{i}")
lines.append("define shape composite blob " + " ".join(balls))
uses = []
for k in range(64):
    lines.append(f"define shape composite u{k} blob")
    lines.append(f"transform u{k} rotate {k * 37 % 360} 1 1 0")
    lines.append(f"transform u{k} translate {(k % 8 - 4) * 6} {(k // 8 - 4) * 6} {-(k % 3) * 6}")
    uses.append(f"u{k}")
lines.append("define shape composite root " + " ".join(uses))
open(sys.argv[1], "w").write("\n".join(lines) + "\n")
PY

mg=$root/scenes/bench/mirror-glass.sdf

# name | scene | options
case ${SET:-core} in
pov) cases=(
  "assignment|$root/scenes/assignment.sdf|--spp 1 --width 1920 --height 1080"
  "grid10k|$out/scenes/grid10k.sdf|--spp 1 --width 1280 --height 720"
  "random1k|$out/scenes/random1k.sdf|--spp 1 --width 640 --height 360"
  "random100k|$out/scenes/random100k.sdf|--spp 1 --width 640 --height 360"
  "mirror-glass|$mg|--spp 9 --width 1280 --height 720"
  "random1m|$out/scenes/random1m.sdf|--spp 1 --width 640 --height 360"
) ;;
adaptive) cases=(
  "mirror-glass|$mg|--width 640 --height 360"
  "mirror-glass-1|$mg|--spp 1 --width 640 --height 360"
  "moved|$root/scenes/bench/mirror-glass-moved.sdf|--width 640 --height 360"
  "moved-1|$root/scenes/bench/mirror-glass-moved.sdf|--spp 1 --width 640 --height 360"
  "showcase|$root/scenes/showcase.sdf|--width 640 --height 360"
  "showcase-1|$root/scenes/showcase.sdf|--spp 1 --width 640 --height 360"
) ;;
*) cases=(
  "assignment|$root/scenes/assignment.sdf|--spp 1 --width 640 --height 360"
  "mirror-glass-1|$root/scenes/bench/mirror-glass.sdf|--spp 1 --width 640 --height 360"
  "mirror-glass|$root/scenes/bench/mirror-glass.sdf|--width 640 --height 360"
  "mirror-glass-9|$root/scenes/bench/mirror-glass.sdf|--spp 9 --width 320 --height 180"
  "showcase-1|$root/scenes/showcase.sdf|--spp 1 --width 640 --height 360"
  "showcase|$root/scenes/showcase.sdf|--width 640 --height 360"
  "random1k|$out/scenes/random1k.sdf|--spp 1 --width 640 --height 360"
  "random100k|$out/scenes/random100k.sdf|--spp 1 --width 640 --height 360"
  "grid10k|$out/scenes/grid10k.sdf|--spp 1 --width 640 --height 360"
  "bunny|$root/scenes/bunny.sdf|--width 320 --height 180"
  "instanced|$out/scenes/instances.sdf|--width 160 --height 90 --max-memory 64M"
  "blur72|$out/scenes/blur/frame_0072.sdf|--width 320 --height 180"
) ;;
esac

# count BINARY NAME SCENE OPTIONS...: instructions of one render into $out/NAME.<tag>.
count() {
  local bin=$1 tag=$2 name=$3 scene=$4
  shift 4
  rm -rf "$out/$name.$tag" && mkdir -p "$out/$name.$tag"
  # shellcheck disable=SC2068
  valgrind --tool=callgrind --callgrind-out-file=/dev/null "$bin" render "$scene" \
    --threads 1 --force -q --out "$out/$name.$tag" $@ 2>"$out/$name.$tag.log" >/dev/null
  sed -n 's/.*Collected : \([0-9]*\).*/\1/p' "$out/$name.$tag.log"
}

if [ -n "$base" ]; then
  printf '| case | options | base instructions (M) | new (M) | new / base | images |\n'
  printf '|---|---|---:|---:|---:|---|\n'
else
  printf '| case | options | instructions (M) |\n|---|---|---:|\n'
fi
for entry in "${cases[@]}"; do
  IFS='|' read -r name scene opts <<<"$entry"
  if [ -n "${CASES:-}" ] && [[ " $CASES " != *" $name "* ]]; then continue; fi
  n=$(count "$new" new "$name" "$scene" $opts)
  if [ -z "$base" ]; then
    awk -v c="$name" -v o="$opts" -v n="$n" 'BEGIN { printf "| %s | %s | %.1f |\n", c, o, n / 1e6 }'
    continue
  fi
  b=$(count "$base" base "$name" "$scene" $opts)
  same=identical
  for f in "$out/$name.base"/*; do
    cmp -s "$f" "$out/$name.new/$(basename "$f")" || same=DIFFERENT
  done
  awk -v c="$name" -v o="$opts" -v n="$n" -v b="$b" -v s="$same" \
    'BEGIN { printf "| %s | %s | %.1f | %.1f | %.4f | %s |\n", c, o, b / 1e6, n / 1e6, n / b, s }'
done

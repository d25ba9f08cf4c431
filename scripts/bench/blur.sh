#!/usr/bin/env bash
# What motion blur costs, and how close it is to brute force (BENCHMARKS.md, "Motion blur").
#
#   scripts/bench/blur.sh [FRAME ...]        # default: frames 10 and 72 of animations/blur.ron
#   ROUNDS=1 ANIM=/path/to/anim scripts/bench/blur.sh 10
#
# For each frame of animations/blur.ron (640×360, default adaptive settings), in turns
# (A B C A B C ..., ROUNDS rounds, default 3), the whole-process CPU seconds (user + system,
# /usr/bin/time) of:
#   A  the blurred frame (the spec as written, shutter 0.5);
#   B  the same frame unblurred (the spec without its shutter line);
#   C  brute force: 16 instants of the frame's exposure, rendered with the shutter at 0 in one
#      `anim render` run. They are the midpoints of the exposure's 16 equal parts, taken from
#      a copy of the spec at 32× the fps whose keys are all 1/64 of a frame later (so its
#      frame 32i+k+1 shows the original at t_i + (k+½)/16 of the exposure).
# Then the rays each traced (deterministic, so a ratio of work free of the machine's noise),
# and the RMSE, in 8-bit levels, of the blurred frame against the mean of the 16 instants'
# radiance (`--hdr`), both tone-mapped with the renderer's rule round(255·c/(c+1)).
#
# Environment: ANIM (binary; default: `cargo build --release`, then target/release/anim),
# ROUNDS (default 3), OUT (work folder, kept; default a temporary one, also kept), ANIM_ARGS
# (extra render options for all three, e.g. --threads 1 or --spp 16).
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
spec=$root/animations/blur.ron
rounds=${ROUNDS:-3}
frames=("$@")
[ ${#frames[@]} -gt 0 ] || frames=(10 72)

if [ -n "${ANIM:-}" ]; then
  anim=$ANIM
else
  cargo build --release --quiet --manifest-path "$root/Cargo.toml"
  anim=$root/target/release/anim
fi
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
echo "anim: $anim ($("$anim" --version)); work folder: $out"

# The unblurred spec, and the brute-force one (see above).
cp "$root/animations/blur.sdf" "$out/"
grep -v '^ *shutter:' "$spec" >"$out/still.ron"
python3 - "$spec" "$out/brute.ron" <<'EOF'
import re, sys
text = open(sys.argv[1]).read()
fps = int(re.search(r"^\s*fps:\s*(\d+)", text, re.M).group(1))
seconds = float(re.search(r"length:\s*Seconds\(([\d.]+)\)", text).group(1))
shift = 1.0 / (fps * 64)
text = re.sub(r"^\s*shutter:.*\n", "", text, flags=re.M)
text = re.sub(r"^(\s*fps:\s*)\d+", lambda m: m.group(1) + str(fps * 32), text, flags=re.M)
# One more frame than the original length, so the shifted last key stays inside.
text = re.sub(r"length:\s*Seconds\([\d.]+\)", "length: Frames(%d)" % (round(seconds * fps * 32) + 1), text)
text = re.sub(r"\bat:\s*([\d.]+)", lambda m: "at: %r" % (float(m.group(1)) + shift), text)
open(sys.argv[2], "w").write(text)
EOF
"$anim" generate "$spec" -o "$out/blurred" --quiet
"$anim" generate "$out/still.ron" -o "$out/still" --quiet
"$anim" generate "$out/brute.ron" -o "$out/brute" --quiet

name() { printf '%s/frame_%04d.sdf' "$1" "$2"; }

# CPU seconds (user + system) of one anim render run.
cpu() {
  /usr/bin/time -f '%U %S' -o "$out/time" "$anim" render "$@" --hdr --quiet ${ANIM_ARGS:-}
  awk '{ printf "%.2f", $1 + $2 }' "$out/time"
}

# Rays traced (primary + shadow + reflected + refracted) by one anim render run: the same
# every run, so a ratio of work free of the machine's noise.
rays() {
  "$anim" render "$@" ${ANIM_ARGS:-} 2>&1 >/dev/null |
    sed -n 's/.*(primary \([0-9]*\), shadow \([0-9]*\), reflected \([0-9]*\), refracted \([0-9]*\)).*/\1 \2 \3 \4/p' |
    awk '{ n += $1 + $2 + $3 + $4 } END { print n }'
}

rmse() {
  python3 - "$@" <<'EOF'
import math, struct, sys

def pfm(path):
    data = open(path, "rb").read()
    magic, size, scale, rest = data.split(b"\n", 3)
    assert magic == b"PF" and float(scale) < 0, path
    w, h = map(int, size.split())
    return w, h, struct.unpack("<%df" % (w * h * 3), rest[: w * h * 12])

def tone(c):
    return 0 if c <= 0 else math.floor(255.0 * c / (c + 1.0) + 0.5)

w, h, blurred = pfm(sys.argv[1])
instants = [pfm(p)[2] for p in sys.argv[2:]]
n = len(instants)
total = 0.0
for i, b in enumerate(blurred):
    m = sum(img[i] for img in instants) / n
    total += (tone(b) - tone(m)) ** 2
print("%.3f" % math.sqrt(total / len(blurred)))
EOF
}

notes=()
printf '\n| frame | round | blurred CPU s | unblurred CPU s | 16 instants CPU s | blurred/unblurred | 16 instants/unblurred |\n'
printf '|---|---|---|---|---|---|---|\n'
for f in "${frames[@]}"; do
  brute=()
  for k in $(seq 0 15); do brute+=("$(name "$out/brute" $((32 * f + k + 1)))"); done
  for r in $(seq 1 "$rounds"); do
    a=$(cpu "$(name "$out/blurred" "$f")")
    b=$(cpu "$(name "$out/still" "$f")")
    c=$(cpu "${brute[@]}")
    printf '| %d | %d | %s | %s | %s | %s | %s |\n' "$f" "$r" "$a" "$b" "$c" \
      "$(awk -v a="$a" -v b="$b" 'BEGIN { printf "%.2f", a / b }')" \
      "$(awk -v c="$c" -v b="$b" 'BEGIN { printf "%.1f", c / b }')"
  done
  ra=$(rays "$(name "$out/blurred" "$f")")
  rb=$(rays "$(name "$out/still" "$f")")
  rc=$(rays "${brute[@]}")
  notes+=("frame $f: rays traced: blurred $ra, unblurred $rb, 16 instants $rc ($(awk -v a="$ra" -v b="$rb" -v c="$rc" 'BEGIN { printf "%.2f and %.1f times the unblurred frame", a / b, c / b }'))")
  pfms=()
  for p in "${brute[@]}"; do pfms+=("${p%.sdf}.pfm"); done
  notes+=("frame $f: RMSE against the mean of the 16 instants: blurred $(rmse "$out/blurred/$(printf 'frame_%04d.pfm' "$f")" "${pfms[@]}") levels, unblurred $(rmse "$out/still/$(printf 'frame_%04d.pfm' "$f")" "${pfms[@]}") levels")
done
echo
printf '%s\n' "${notes[@]}"

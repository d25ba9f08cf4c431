#!/usr/bin/env bash
# Time against error (BENCHMARKS.md, "Time against error"): adaptive anti-aliasing against
# uniform sampling and POV-Ray's adaptive method 2, CPU seconds (user + system, whole
# process, /usr/bin/time; the median of TURNS turns) and RMSE in 8-bit levels against each
# scene's own 256-spp uniform render, all in one run on the same machine. POV-Ray's RMSE is
# not given (its reflection and refraction model differs, so its image is another one); only
# its time, and one third of it, the target for the default.
#
#   scripts/bench/adaptive.sh [extra anim flags for the adaptive run, e.g. --error 0.4]
#   REUSE_REF=1 TURNS=3 LADDER="--spp 1" ANIM=/path/to/anim scripts/bench/adaptive.sh
#
# Environment: ANIM (binary; default: `cargo build --release`, then target/release/anim),
# TOOLS (the POV-Ray converters and imgio.py, default SHARED/tools, SHARED defaulting to
# ../shared beside the checkout), OUT (work directory, default /tmp/adaptive-measure),
# REUSE_REF=1 to keep reference renders from an earlier run, SIZE (default "640 360"),
# QUICK=1 for the adaptive run alone, SCENES (default: the mirror-glass bench, its moved
# variant and the showcase; relative paths are from the repository's root), TURNS (default 3:
# every run, the default, the LADDER runs and uniform 4 and 16 spp, alternates with the others
# and with POV-Ray this many times; the median CPU time of each is printed), LADDER
# (';'-separated anim flag sets measured in the same turns, to trace the time/RMSE curve
# around the default; default "--error 2.5;--error 3;--error 4;--error 64;--spp 1"; empty for
# none).
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
if [ -n "${ANIM:-}" ]; then
  ANIM=$(realpath "$ANIM")
else
  cargo build --release --quiet --manifest-path "$root/Cargo.toml"
  ANIM=$root/target/release/anim
fi
TOOLS=${TOOLS:-${SHARED:-$root/../shared}/tools}
TOOLS=$(realpath -m "$TOOLS")
[ -f "$TOOLS/imgio.py" ] || { echo "needs $TOOLS/imgio.py (set SHARED or TOOLS to the comparison tools)" >&2; exit 1; }
OUT=${OUT:-/tmp/adaptive-measure}
OUT=$(realpath -m "$OUT")
cd "$root"
TURNS=${TURNS:-3}
read -r W H <<<"${SIZE:-640 360}"
IFS=';' read -r -a LADDER <<<"${LADDER---error 2.5;--error 3;--error 4;--error 64;--spp 1}"
mkdir -p "$OUT"

# The mirror-and-glass room, its held-out stand-in (see the file's header) and the showcase.
read -r -a SCENES <<<"${SCENES:-scenes/bench/mirror-glass.sdf scenes/bench/mirror-glass-moved.sdf scenes/showcase.sdf}"

# cpu_of LOG: user + sys seconds from a /usr/bin/time -f '%U %S' line (the last line).
cpu_of() { tail -n 1 "$1" | awk '{printf "%.2f", $1 + $2}'; }

# median of the numbers given as arguments.
median() { printf '%s\n' "$@" | sort -g | awk '{v[NR] = $1} END {print v[int((NR + 1) / 2)]}'; }

# render NAME SCENE FLAGS...: renders into $OUT/NAME, prints CPU seconds.
render() {
  local name=$1 scene=$2
  shift 2
  mkdir -p "$OUT/$name"
  /usr/bin/time -f '%U %S' -o "$OUT/$name/time" \
    "$ANIM" render "$scene" --width "$W" --height "$H" --out "$OUT/$name" "$@" \
    >"$OUT/$name/log" 2>&1
  cpu_of "$OUT/$name/time"
}

rmse() {
  python3 - "$1" "$2" "$TOOLS" <<'PY'
import sys
sys.path.insert(0, sys.argv[3])
import imgio
def load(p):
    w, h, n, rows = imgio.read_png(p)
    return w, h, [v for r in rows for i, v in enumerate(r) if n < 4 or i % 4 != 3]
wa, ha, a = load(sys.argv[1])
wb, hb, b = load(sys.argv[2])
assert (wa, ha) == (wb, hb), "sizes differ"
print("%.3f" % ((sum((x - y) ** 2 for x, y in zip(a, b)) / len(a)) ** 0.5))
PY
}

mean_spp() { grep -o 'primary [0-9]*' "$1" | awk -v px=$((W * H)) '{s += $2} END {printf "%.2f", s / px}'; }

printf '%-18s %-28s %8s %8s %8s\n' scene method cpu_s rmse mean_spp
for scene in "${SCENES[@]}"; do
  base=$(basename "$scene" .sdf)
  png=$(awk '$1 == "render" {print $3; exit}' "$scene")
  if [[ ${REUSE_REF:-0} != 1 || ! -f $OUT/$base-ref/$png ]]; then
    render "$base-ref" "$scene" --spp 256 >/dev/null
  fi
  ref=$OUT/$base-ref/$png
  # Every run takes turns with the others and POV-Ray, the default first.
  turned=("default:$*")
  ladder_runs=0
  if [[ ${QUICK:-0} != 1 ]]; then
    for flags in "${LADDER[@]}"; do
      [[ -n $flags ]] || continue
      turned+=("${flags//[- ]/}:$flags")
      ladder_runs=$((ladder_runs + 1))
    done
    turned+=("uniform 4:--spp 4" "uniform 16:--spp 16")
  fi
  pov=$OUT/$base-pov
  with_pov=0
  if [[ ${QUICK:-0} != 1 ]] && command -v povray >/dev/null; then
    with_pov=1
    mkdir -p "$pov"
    python3 "$TOOLS/sdf2pov.py" "$scene" -o "$pov/scene.pov"
  fi
  # cpus[i] holds run i's CPU seconds, one word per turn; every run and POV-Ray alternate, so
  # that all of them see the same machine load.
  cpus=()
  pov_cpu=()
  for ((turn = 0; turn < TURNS; turn++)); do
    for i in "${!turned[@]}"; do
      run=${turned[$i]}
      label=${run%%:*}
      # shellcheck disable=SC2086  # the flags are words on purpose
      cpus[i]+=" $(render "$base-${label// /-}" "$scene" ${run#*:})"
    done
    if [[ $with_pov == 1 ]]; then
      /usr/bin/time -f '%U %S' -o "$pov/time" povray -D +WT2 File_Gamma=1.0 +W"$W" +H"$H" \
        +A0.1 +AM2 +R3 +FN +O"$pov/pov.png" "$pov/scene.pov" >"$pov/log" 2>&1
      pov_cpu+=("$(cpu_of "$pov/time")")
    fi
  done
  for i in "${!turned[@]}"; do
    run=${turned[$i]}
    label=${run%%:*}
    flags=${run#*:}
    dir="$base-${label// /-}"
    if ((i > 0 && i <= ladder_runs)); then
      label=$flags
    else
      label="$label${flags:+ ($flags)}"
    fi
    # shellcheck disable=SC2086  # one word per turn
    printf '%-18s %-28s %8s %8s %8s\n' "$base" "anim $label" \
      "$(median ${cpus[$i]})" "$(rmse "$OUT/$dir/$png" "$ref")" "$(mean_spp "$OUT/$dir/log")"
  done
  if [[ $with_pov == 1 ]]; then
    # No RMSE: POV-Ray reflects and refracts by its own model (no Fresnel), so its image
    # is a different one, and only its time is comparable.
    pov_median=$(median "${pov_cpu[@]}")
    printf '%-18s %-28s %8s %8s %8s\n' "$base" "povray +A0.1 +AM2 +R3" "$pov_median" "-" "-"
    printf '%-18s %-28s %8s %8s %8s\n' "$base" "(one third of povray)" \
      "$(awk -v t="$pov_median" 'BEGIN {printf "%.2f", t / 3}')" "-" "-"
  fi
done

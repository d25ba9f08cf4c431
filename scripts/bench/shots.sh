#!/usr/bin/env bash
# Shots of a still camera (issue 41: `anim render DIR` tracing again only what changed) against
# their frames rendered alone, for one binary (BENCHMARKS.md, "Frames from the frame before"):
#
#   scripts/bench/shots.sh [BINARY]        # default: target/release/anim
#   ROUNDS=2 CASES="mover100k-plain hidden100k" scripts/bench/shots.sh /work/bin/anim-main
#
# For each animation of gen-animations.sh named in CASES (default mover100k-plain):
# - every frame generated whole (`--standalone`) and rendered alone, all in one process as
#   tests/pipeline/incremental.rs does: the share of the pixels that differ between
#   consecutive frames (mean, smallest and largest, pixdiff.py);
# - in turns, ROUNDS rounds (default 1): the whole-process CPU seconds (user + system,
#   /usr/bin/time) and peak RSS of the first generated frame rendered alone (with the static
#   part it includes), of `anim render DIR` (shots) and of `anim render DIR --no-incremental`,
#   each from a clean directory; the pixels traced again per frame by the frames traced from
#   the frame before (their records: mean and largest share, how many frames); and whether
#   every image of both runs is, byte for byte, the image of its `--standalone` frame rendered
#   alone (the script fails if one is not).
# The table goes to standard output, in Markdown. OUT: work folder (kept; default a temporary
# one, kept too).
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
rounds=${ROUNDS:-1}
bin=${1:-}
if [ -z "$bin" ]; then
    (cd "$root" && cargo build --release --quiet -p anim)
    bin="$root/target/release/anim"
fi
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
cd "$out"
echo "work folder: $out" >&2
"$root/scripts/bench/gen-animations.sh" .

cpu() { # file: "user sys rss" -> "cpu rss_mb"
    awk '{printf "%.2f %.0f", $1 + $2, $3 / 1024}' "$1"
}
retraced() { # as in animation.sh
    cat "$1"/.anim-cache/*.hash 2>/dev/null | awk '$1 == "incremental" { f = $2 / $3; s += f; n++; if (f > m) m = f }
        END { if (n) printf "%.2f %%, %.2f %% (%d)", 100 * s / n, 100 * m, n; else printf "–" }'
}
same() { # dir: "yes" when every image of the --standalone frames alone is there, the same
    local png
    for png in alone/*.png; do
        if ! cmp -s "$png" "$1/$(basename "$png")"; then
            echo "$1/$(basename "$png") differs from $png" >&2
            return 1
        fi
    done
    echo yes
}

echo "| animation | frames | pixels that differ between frames: mean, min, max | one frame: CPU s, peak MB | shots: CPU s, peak MB | --no-incremental: CPU s, peak MB | shots / one | full / one | traced again per frame: mean, max (frames) | every image as alone |"
echo "|---|---:|---:|---:|---:|---:|---:|---:|---:|---|"
read -r -a cases <<<"${CASES:-mover100k-plain}"
for c in "${cases[@]}"; do
    rm -rf frames standalone alone
    "$bin" generate "$c.ron" -o frames --quiet
    "$bin" generate "$c.ron" -o standalone --standalone --quiet
    "$bin" render standalone/*.sdf --out alone --quiet
    # shellcheck disable=SC2046 # the frames' names have no spaces
    differ=$(python3 "$root/scripts/bench/pixdiff.py" $(ls alone/*.png | sort) |
        awk '{ s += $3; n++; if (n == 1 || $3 < lo) lo = $3; if ($3 > hi) hi = $3 }
            END { printf "%.2f %%, %.2f %%, %.2f %%", s / n, lo, hi }')
    n=$(ls frames/*.sdf | wc -l)
    first=$(ls frames/*.sdf | sort | sed -n 1p)
    for round in $(seq "$rounds"); do
        rm -rf one && mkdir one && cp "$first" one/
        if [ -f frames/static.sdfi ]; then cp frames/static.sdfi one/; fi
        /usr/bin/time -f '%U %S %M' -o one.time "$bin" render "one/$(basename "$first")" --quiet
        rm -rf frames/*.png frames/.anim-cache
        /usr/bin/time -f '%U %S %M' -o shots.time "$bin" render frames --quiet
        shots_same=$(same frames)
        shots_traced=$(retraced frames)
        rm -rf frames/*.png frames/.anim-cache
        /usr/bin/time -f '%U %S %M' -o full.time "$bin" render frames --no-incremental --quiet
        full_same=$(same frames)
        read -r one_cpu one_mb <<<"$(cpu one.time)"
        read -r shots_cpu shots_mb <<<"$(cpu shots.time)"
        read -r full_cpu full_mb <<<"$(cpu full.time)"
        ratio() { awk -v a="$1" -v o="$one_cpu" 'BEGIN { printf "%.1f", a / o }'; }
        echo "| $c | $n | $differ | $one_cpu, $one_mb | $shots_cpu, $shots_mb | $full_cpu, $full_mb | $(ratio "$shots_cpu")× | $(ratio "$full_cpu")× | $shots_traced | $shots_same, $full_same |"
    done
done

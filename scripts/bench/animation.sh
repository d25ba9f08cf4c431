#!/usr/bin/env bash
# What a whole animation costs against one of its frames (BENCHMARKS.md, "Animations").
#
#   scripts/bench/animation.sh [BINARY ...]     # default: target/release/anim
#   ROUNDS=2 scripts/bench/animation.sh /tmp/anim-before target/release/anim
#
# Four animations at 320×180 (default adaptive settings), generated once by the first binary:
#   orbit100k  the camera circles 100,000 random spheres (gen-scenes.py's random100k), 48 frames;
#   orbitmesh  the camera circles a 1,000,000-triangle torus (gen-mesh.py) over a plane, 48 frames;
#   mover100k  one sphere slides among the 100,000 still ones, the camera still, 48 frames;
#   hold100k   nothing moves for 24 frames.
# For each animation and each binary, in turns (binary A B A B ..., ROUNDS rounds, default 1):
# the whole-process CPU seconds (user + system, /usr/bin/time) and peak RSS of one frame
# rendered alone (`anim render FRAME.sdf`) and of every frame (`anim render DIR` from a clean
# directory: no images, no records). Then the size of the frame directory's scene files and of
# the base scene file. The table goes to standard output, in Markdown.
#
# Environment: ROUNDS (default 1), OUT (work folder, kept; default a temporary one, kept too).
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
rounds=${ROUNDS:-1}
bins=("$@")
if [ ${#bins[@]} -eq 0 ]; then
    (cd "$root" && cargo build --release --quiet)
    bins=("$root/target/release/anim")
fi
out=${OUT:-$(mktemp -d)}
mkdir -p "$out"
cd "$out"
echo "work folder: $out" >&2

python3 "$root/scripts/bench/gen-scenes.py" . >/dev/null
# The generated file ends with its own camera and render line; the specs give both.
grep -v '^define camera\|^render' random100k.sdf > base100k.sdf
echo 'define camera eye 60 0 10 60 0 -0.15 -1 0 1 0' >> base100k.sdf
echo 'define shape sphere mover -20 0 -40 3 mirror' >> base100k.sdf
[ -f torus.obj ] || python3 "$root/scripts/gen-mesh.py" torus --triangles 1000000 -o torus.obj >/dev/null
cat > torus.sdf <<'EOF'
define material gold 0.2 0.15 0.05 0.8 0.6 0.2 0.6 0.6 0.5 40 0.2
define material floor 0.1 0.1 0.1 0.6 0.6 0.6 0.2 0.2 0.2 10
define light key 5 8 6 1 1 1 1
ambient 0.15 0.15 0.15
define shape obj torus torus.obj gold
define shape plane ground 0 -1.2 0 0 1 0 floor
transform torus rotate 30 1 0 0
define camera cam 45 0 0 3 0 0 -1 0 1 0
EOF
spec() { # name scene camera frames extra
    printf '(\n    scene: File("%s"),\n    camera: "%s",\n    fps: 24,\n    length: Frames(%s),\n    resolution: (320, 180),\n    output: "frame_{frame}.png",\n%s\n)\n' \
        "$2" "$3" "$4" "$5" > "$1.ron"
}
spec orbit100k base100k.sdf eye 48 '    orbit: (center: (0, 0, -100), radius: 160, height: 10, turns: 1, look_at: (0, 0, -100)),'
spec orbitmesh torus.sdf cam 48 '    orbit: (center: (0, 0, 0), radius: 3.5, height: 1.5, turns: 1, look_at: (0, 0, 0)),'
spec mover100k base100k.sdf eye 48 '    tracks: [(target: "mover", translate: [(at: 0, value: (0, 0, 0)), (at: 2, value: (40, 0, 0))])],'
spec hold100k base100k.sdf eye 24 ''

cases=(orbit100k orbitmesh mover100k hold100k)
for c in "${cases[@]}"; do
    rm -rf "frames-$c"
    "${bins[0]}" generate "$c.ron" -o "frames-$c" --quiet
done

cpu() { # file: "user sys rss" -> "cpu rss_mb"
    awk '{printf "%.2f %.0f", $1 + $2, $3 / 1024}' "$1"
}
echo "| animation | binary | frames | one frame: CPU s, peak MB | all frames: CPU s, peak MB | all / one | frame files | base scene |"
echo "|---|---|---:|---:|---:|---:|---:|---:|"
for c in "${cases[@]}"; do
    dir="frames-$c"
    n=$(ls "$dir"/*.sdf | wc -l)
    first=$(ls "$dir"/*.sdf | sort | head -1)
    base=$(grep -o 'File("[^"]*")' "$c.ron" | sed 's/File("\(.*\)")/\1/')
    for round in $(seq "$rounds"); do
        for bin in "${bins[@]}"; do
            rm -rf "$dir"/*.png "$dir/.anim-cache" alone && mkdir alone && cp "$first" alone/
            /usr/bin/time -f '%U %S %M' -o one.time "$bin" render "alone/$(basename "$first")" --quiet
            /usr/bin/time -f '%U %S %M' -o all.time "$bin" render "$dir" --quiet
            read -r one_cpu one_mb <<<"$(cpu one.time)"
            read -r all_cpu all_mb <<<"$(cpu all.time)"
            ratio=$(awk -v a="$all_cpu" -v o="$one_cpu" 'BEGIN { printf "%.1f", a / o }')
            files=$(du -sb --exclude='*.png' --exclude='.anim-cache' "$dir" | awk '{printf "%.1f MB", $1 / 1e6}')
            basesize=$(du -b "$base" | awk '{printf "%.1f MB", $1 / 1e6}')
            echo "| $c | $(basename "$bin") | $n | $one_cpu, $one_mb | $all_cpu, $all_mb | ${ratio}× | $files | $basesize |"
        done
    done
done

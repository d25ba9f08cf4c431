#!/usr/bin/env bash
# Writes the scenes and keyframe specs of scripts/bench/animation.sh and scripts/bench/shots.sh
# into DIR (deterministic: gen-scenes.py's fixed seeds, gen-mesh.py's torus):
#
#   scripts/bench/gen-animations.sh DIR
#
# Specs (320×180, 24 fps): orbit100k, orbitmesh, mover100k, mover100k-plain, hidden100k,
# bounce and hold100k; animation.sh says what each shows.
set -euo pipefail

root=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$1"
cd "$1"
python3 "$root/scripts/bench/gen-scenes.py" . >/dev/null
# The generated file ends with its own camera and render line; the specs give both.
grep -v '^define camera\|^render' random100k.sdf > base100k.sdf
echo 'define camera eye 60 0 10 60 0 -0.15 -1 0 1 0' >> base100k.sdf
# The hidden mover slides behind the front spheres; the plain one in front of them all, its
# shadow (the key light is above, right and in front) falling on those behind it.
{ cat base100k.sdf; echo 'define shape sphere mover -20 0 -40 3 mirror'; } > hidden100k.sdf
{ cat base100k.sdf; echo 'define shape sphere mover -20 -4 -36 4.5 mirror'; } > plain100k.sdf
# Issue 41's own mover: the same sphere among matte spheres only (no mirror shows it), matte
# itself, so that what changes is the sphere and its shadow.
sed 's/ mirror$/ matte/' base100k.sdf > matte100k.sdf
{ cat matte100k.sdf; echo 'define shape sphere mover -20 -4 -36 4.5 matte'; } > plainmatte100k.sdf
cp "$root/tests/pipeline/bounce/bounce.sdf" .
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
slide='    tracks: [(target: "mover", translate: [(at: 0, value: (0, 0, 0)), (at: 2, value: (40, 0, 0))])],'
spec mover100k plain100k.sdf eye 48 "$slide"
# A quarter of the speed: what changes from one frame to the next is the sphere's whole disk
# (its shading follows the light's direction) and the edges of its shadow, about the share
# the issue gives (scripts/bench/shots.sh measures it).
spec mover100k-plain plainmatte100k.sdf eye 48 \
    '    tracks: [(target: "mover", translate: [(at: 0, value: (0, 0, 0)), (at: 2, value: (10, 0, 0))])],'
spec hidden100k hidden100k.sdf eye 48 "$slide"
cp "$root/tests/pipeline/bounce/bounce.ron" .
spec hold100k base100k.sdf eye 24 ''

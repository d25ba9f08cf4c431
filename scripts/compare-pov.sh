#!/usr/bin/env bash
# Compares anim with POV-Ray 3.7 on the example scenes using the shared tools
# (../shared/tools): shading of the two assignment-style scenes to 1 LSB (three linear HDR
# channel passes, tone-mapped with c/(c+1)), and the showcase's geometry as object-ID masks
# (exact), and a soft shadow under a spherical light against POV-Ray's area light (RMSE).
# The POV tools know neither `plane` nor `background`, so the copies compared here
# replace the plane with a large slab and drop the background line.
# Needs povray and python3; without them it says "skipped" and exits 0, except under CI
# (CI set), where a missing tool is a failure: CI installs them.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
tools=${POV_TOOLS:-$root/../shared/tools}
anim=${ANIM:-$root/target/release/anim}
if ! command -v povray >/dev/null || ! command -v python3 >/dev/null || [ ! -d "$tools" ]; then
  if [ -n "${CI:-}" ]; then
    echo "compare-pov: povray, python3 or $tools missing, and CI is set: failing" >&2
    exit 1
  fi
  echo "compare-pov: skipped: povray, python3 or $tools missing"
  exit 0
fi
[ -x "$anim" ] || cargo build --release --quiet --manifest-path "$root/Cargo.toml"
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
cd "$work"

# pov_compatible SRC NAME W H: copy SRC as NAME.sdf rendering NAME.ppm at W×H. Planes
# (horizontal ones, as in the example scenes) become a 400-unit slab with the same top.
pov_compatible() {
  awk -v out="$2.ppm" -v w="$3" -v h="$4" '
    $1 == "define" && $2 == "shape" && $3 == "plane" {
      printf "define shape box %s -200 %s -200 200 %s 200 %s\n", $4, $6 - 1, $6, $11; next }
    $1 == "background" { next }
    $1 == "render" { printf "render %s %s %s %s\n", $2, out, w, h; next }
    { print }' "$1" > "$2.sdf"
}

shading() { # NAME W H
  for c in r g b; do
    python3 "$tools/sdf2pov.py" "$1.sdf" --channel $c -o "$1_$c.pov"
    povray -D +WT2 -A File_Gamma=1.0 +W$2 +H$3 +FH +O"$1_$c.hdr" "$1_$c.pov" 2>/dev/null
  done
  python3 "$tools/povtonemap.py" "$1_r.hdr" "$1_g.hdr" "$1_b.hdr" -o "$1_pov.png"
  # The converter composes transforms in the standard order (M <- T*M); anim is told the
  # same, as by default it would read a file that shows nothing that way the other way.
  "$anim" render "$1.sdf" --spp 1 --transform-order world --out out -q
  echo "shading $1:"
  python3 "$tools/imgcmp.py" "$1_pov.png" "out/$1.ppm" --tol 1
}

geometry() { # NAME W H
  python3 "$tools/sdf2pov.py" "$1.sdf" --shading id --ids ids.json -o "$1_id.pov"
  povray -D +WT2 -A File_Gamma=1.0 +W$2 +H$3 +FN +O"$1_povid.png" "$1_id.pov" 2>/dev/null
  python3 "$tools/sdf2id.py" "$1.sdf" -o "$1_id.sdf"
  "$anim" render "$1_id.sdf" --spp 1 --transform-order world --out out -q
  echo "geometry $1:"
  python3 "$tools/imgcmp.py" "out/$1.ppm" "$1_povid.png" --ids ids.json > ids.txt
  head -2 ids.txt
  grep -q "pixels differ by > 0 (0.0000%)" ids.txt
}

# soft_shadow W H: a ball over a matte floor under a spherical light of radius 1.5 (ks = 0:
# POV-Ray takes an area light's highlights from its centre only) against POV-Ray's 33×33
# jittered circular area light turned to face each point (`orient`), the disc anim's light
# shows; each converged (anim --spp 1024, POV-Ray anti-aliased), RMSE at most 2 levels.
soft_shadow() {
  cat > soft.sdf <<SDF
define material matte 0.2 0.2 0.2 0.8 0.8 0.8 0 0 0 1
define shape box ground -60 -1 -60 60 0 60 matte
define shape sphere ball 0 3 -10 1 matte
define light key -6 10 -10 1 1 1 1 radius 1.5
ambient 0.3 0.3 0.3
define camera eye 60 2 25 -10 0 -1 0 0 0 -1
render eye soft.ppm $1 $2
SDF
  # The converter writes the point light; the area light spans the disc's diameter.
  sed 's/ radius 1.5$//' soft.sdf > soft_point.sdf
  python3 "$tools/sdf2pov.py" soft_point.sdf --channel r -o soft_point.pov
  sed 's|^\(light_source { <-6, 10, -10> color rgb <1, 1, 1>\) }|\1 area_light <3, 0, 0>, <0, 0, 3>, 33, 33 circular orient jitter }|' \
    soft_point.pov > soft_pov.pov
  grep -q "area_light" soft_pov.pov
  # The scene is grey: one channel pass serves all three.
  povray -D +WT1 +A0.02 +AM2 +R3 File_Gamma=1.0 +W$1 +H$2 +FH +Osoft.hdr soft_pov.pov 2>/dev/null
  python3 "$tools/povtonemap.py" soft.hdr soft.hdr soft.hdr -o soft_pov.png
  "$anim" render soft.sdf --spp 1024 --out out -q
  echo "soft shadow:"
  python3 - "$tools" soft_pov.png out/soft.ppm <<'PY'
import math, sys
sys.path.insert(0, sys.argv[1])
import imgio
_, _, n, a = imgio.read_png(sys.argv[2])
_, _, b = imgio.read_ppm(sys.argv[3])
d = [x - y for ra, rb in zip(a, b) for x, y in zip([v for i, v in enumerate(ra) if i % n < 3], rb)]
rmse = math.sqrt(sum(v * v for v in d) / len(d))
print(f"  RMSE {rmse:.3f} levels against POV-Ray (at most 2), largest difference {max(map(abs, d))}")
sys.exit(0 if rmse <= 2.0 else 1)
PY
}

soft_shadow 160 120
pov_compatible "$root/scenes/assignment-extended.sdf" extended 480 320
shading extended 480 320
pov_compatible "$root/scenes/transforms.sdf" transforms 480 270
shading transforms 480 270
pov_compatible "$root/scenes/showcase.sdf" showcase 480 270
geometry showcase 480 270
echo "compare-pov: anim agrees with POV-Ray"

#!/usr/bin/env bash
# Writes the held-out stand-in for the mirror-and-glass room to FILE, so that tuning is not to
# one file: the same room with the spheres, box and cylinder moved, a second (flat) mirror on
# the right wall, the key light moved and another camera. Written, not shipped as a scene.
#
#   scripts/bench/mirror-glass-moved.sh FILE
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
sed -e 's/^define shape sphere ball .*/define shape sphere ball 1.6 1.2 -9 1.2 mirror/' \
  -e 's/^define shape sphere lens .*/define shape sphere lens -1.2 1.3 -6 1.3 glass/' \
  -e 's/^define shape box crate .*/define shape box crate -4.5 0 -12 -2.5 1.6 -10 green/' \
  -e 's/^define shape cylinder post .*/define shape cylinder post 3.8 0 -12 3.8 3.6 -12 0.5 gold/' \
  -e 's/^define light key .*/define light key -1 5.6 -4 1 0.95 0.9 0.9\
define shape box mirror2 5.9 0.5 -13 5.95 4.5 -7 mirror/' \
  -e 's/^define camera eye .*/define camera eye 55 -1.5 3.2 2.8 0.15 -0.2 -1 0 1 0/' \
  -e 's/^render eye mirror-glass.png .*/render eye mirror-glass-moved.png 1280 720/' \
  "$root/scenes/bench/mirror-glass.sdf" >"${1:?usage: scripts/bench/mirror-glass-moved.sh FILE}"

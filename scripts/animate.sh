#!/usr/bin/env bash
# The whole job in one command: build anim (release), generate the frames of a keyframe
# spec, render them in parallel and encode the MP4.
#
#   scripts/animate.sh animations/orbit.ron [OUT.mp4]
#
# OUT defaults to animation.mp4. Frames go where `anim generate` puts them: the spec's
# `frames_dir`, else frames/<spec name>/ beside the spec (override with FRAMES_DIR); extra
# `anim render` options can be passed in ANIM_RENDER_ARGS, e.g.
#   ANIM_RENDER_ARGS="--spp 16" scripts/animate.sh animations/orbit.ron
# ANIM=/path/to/anim uses that build instead of building one (cargo is then not needed).
# Re-running is cheap: unchanged frames are not rendered again.
set -euo pipefail

if [ $# -lt 1 ] || [ $# -gt 2 ]; then
  echo "usage: $0 SPEC.ron [OUT.mp4]" >&2
  exit 2
fi
spec=$1
out=${2:-animation.mp4}
root=$(cd "$(dirname "$0")/.." && pwd)

if [ ! -f "$spec" ]; then
  echo "error: $spec does not exist" >&2
  exit 1
fi
# Fail before the long part if a tool is missing.
if [ -z "${ANIM:-}" ] && ! command -v cargo >/dev/null 2>&1; then
  echo "error: cargo is not installed; install Rust from https://rustup.rs, or set ANIM to a built anim" >&2
  exit 127
fi
if ! command -v ffmpeg >/dev/null 2>&1; then
  echo "error: ffmpeg is not installed (Debian/Ubuntu: sudo apt-get install -y ffmpeg; macOS: brew install ffmpeg)" >&2
  exit 127
fi

if [ -n "${ANIM:-}" ]; then
  # A given build (the test suite passes its own), used as it is.
  anim=$ANIM
else
  echo "==> building anim (release)"
  cargo build --release --quiet --manifest-path "$root/Cargo.toml"
  # The binary lives in cargo's target directory, wherever CARGO_TARGET_DIR or a config puts it.
  target_dir=$(cargo metadata --format-version 1 --no-deps --manifest-path "$root/Cargo.toml" |
    sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')
  anim="${target_dir:-$root/target}/release/anim"
fi
if [ ! -x "$anim" ]; then
  echo "error: built anim not found at $anim" >&2
  exit 1
fi

echo "==> generating $spec"
# anim prints the frame directory it used: FRAMES_DIR, else the spec's own choice.
if [ -n "${FRAMES_DIR:-}" ]; then
  frames=$("$anim" generate "$spec" -o "$FRAMES_DIR" --print-dir)
else
  frames=$("$anim" generate "$spec" --print-dir)
fi

echo "==> rendering $frames"
# shellcheck disable=SC2086  # ANIM_RENDER_ARGS is a list of options, split on purpose.
"$anim" render "$frames" ${ANIM_RENDER_ARGS:-}

echo "==> encoding $out"
# The frame rate, as the generator wrote it in the first frame's header ("... at 24 fps", or
# the exact ratio of a fractional rate, "... at 24000/1001 fps").
# `sed -n 1p` reads to the end: `head` would leave early, and sort, still writing a long
# list, would die of SIGPIPE, which pipefail makes the script's failure.
first_frame=$(find "$frames" -maxdepth 1 -name '*.sdf' | sort | sed -n 1p)
fps=$(sed -n '1s/.* at \([0-9][0-9]*\(\/[0-9][0-9]*\)\{0,1\}\) fps.*/\1/p' "$first_frame")
"$root/scripts/encode.sh" "$frames" "$out" "${fps:-24}"

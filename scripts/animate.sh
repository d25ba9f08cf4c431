#!/usr/bin/env bash
# The whole job in one command: build anim (release), generate the frames of a keyframe
# spec, render them in parallel and encode the video.
#
#   scripts/animate.sh animations/orbit.ron [OUT] [--codec h264|h265|prores|webm|ffv1|gif]
#
# OUT defaults to animation.mp4 (or the codec's own container, see scripts/encode.sh). The
# frame rate and the images' names are the spec's: encode.sh reads them from the frames
# `anim generate` writes. Frames go where `anim generate` puts them: the spec's `frames_dir`,
# else frames/<spec name>/ beside the spec (override with FRAMES_DIR); extra `anim render`
# options can be passed in ANIM_RENDER_ARGS, e.g.
#   ANIM_RENDER_ARGS="--spp 16 --alpha" scripts/animate.sh animations/orbit.ron out.mov --codec prores
# ANIM=/path/to/anim uses that build instead of building one (cargo is then not needed).
# Re-running is cheap: unchanged frames are not rendered again.
set -euo pipefail

usage() {
  echo "usage: $0 SPEC.ron [OUT] [--codec h264|h265|prores|webm|ffv1|gif]" >&2
  exit 2
}
positional=()
encode_args=()
while [ $# -gt 0 ]; do
  case $1 in
    --codec) [ $# -ge 2 ] || usage; encode_args+=(--codec "$2"); shift 2 ;;
    --codec=*) encode_args+=("$1"); shift ;;
    -h | --help) usage ;;
    --) shift; positional+=("$@"); break ;;
    -?*) echo "error: unknown option $1" >&2; usage ;;
    *) positional+=("$1"); shift ;;
  esac
done
if [ ${#positional[@]} -lt 1 ] || [ ${#positional[@]} -gt 2 ]; then usage; fi
spec=${positional[0]}
out=${positional[1]:-}
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
# The encoder's own checks (ffmpeg and its encoder, the codec, the output's folder and
# extension) before anything is built, generated or rendered.
"$root/scripts/encode.sh" --check "$spec" ${out:+"$out"} "${encode_args[@]}"

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

echo "==> encoding ${out:-the video}"
"$root/scripts/encode.sh" "$frames" ${out:+"$out"} "${encode_args[@]}"

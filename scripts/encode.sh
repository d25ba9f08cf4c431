#!/usr/bin/env bash
# Assembles rendered frames into an MP4: H.264 (libx264), yuv420p, +faststart.
#
#   scripts/encode.sh FRAMES_DIR [OUTPUT.mp4] [FPS]
#
# FRAMES_DIR holds frame_0000.png, frame_0001.png, ... (as `anim generate` names them and
# `anim render` writes them). OUTPUT defaults to animation.mp4, FPS to 24. The frames must
# be complete and numbered consecutively from 0; odd image sizes are padded by one pixel
# (yuv420p needs even sizes). The MP4 is written to a temporary file and moved into place,
# so OUTPUT is never a half-written video; it gets the permissions the umask gives a new
# file. X264_PRESET (default veryfast) trades encoding time for file size.
#
# Each PNG is checked for completeness (its IEND chunk) and size, not for corrupted bytes in
# between: `anim render DIR` verifies every image against the hash of the bytes it wrote and
# renders a corrupted one again, so run it before encoding frames you did not just render.
set -euo pipefail

usage() {
  echo "usage: $0 FRAMES_DIR [OUTPUT.mp4] [FPS]" >&2
  exit 2
}

if [ $# -lt 1 ] || [ $# -gt 3 ]; then usage; fi
frames=$1
output=${2:-animation.mp4}
fps=${3:-24}

if ! command -v ffmpeg >/dev/null 2>&1 || ! command -v ffprobe >/dev/null 2>&1; then
  # printf is a shell builtin: this message must print even on a bare PATH.
  printf '%s\n' \
    "error: ffmpeg (with ffprobe) is not installed. Install it with" \
    "  Debian/Ubuntu:  sudo apt-get install -y ffmpeg" \
    "  Fedora:         sudo dnf install -y ffmpeg      (from RPM Fusion)" \
    "  macOS:          brew install ffmpeg" \
    "  Windows:        winget install ffmpeg" >&2
  exit 127
fi
# Captured first: `grep -q` stopping early would kill ffmpeg with SIGPIPE under pipefail.
encoders=$(ffmpeg -hide_banner -encoders 2>/dev/null || true)
if ! grep -q libx264 <<<"$encoders"; then
  echo "error: this ffmpeg has no libx264 encoder; install a build with H.264 support" >&2
  exit 1
fi
if ! [[ $fps =~ ^[0-9]+(/[0-9]+)?$ ]] || [[ $fps =~ ^0+(/|$) ]]; then
  echo "error: FPS must be a positive whole number (or a ratio like 30000/1001), not '$fps'" >&2
  exit 2
fi
if [ ! -d "$frames" ]; then
  echo "error: $frames is not a directory" >&2
  exit 1
fi
# Refused before anything is written: a name ffmpeg would read as an option, and a directory
# (the video would otherwise end up hidden inside it).
case $(basename -- "$output") in
  -*)
    echo "error: the output name '$output' starts with '-'; write ./$output" >&2
    exit 2
    ;;
esac
if [ -d "$output" ]; then
  echo "error: $output is a directory; give the video's file name, e.g. $output/animation.mp4" >&2
  exit 2
fi

# The frames: frame_<digits>.png. Their digit count comes from frame 0.
first=$(find "$frames" -maxdepth 1 -name 'frame_*.png' -printf '%f\n' | grep -E '^frame_0+\.png$' | head -n 1 || true)
if [ -z "$first" ]; then
  echo "error: no frame_0000.png in $frames (frames are numbered from 0)" >&2
  exit 1
fi
zeros=${first#frame_}
zeros=${zeros%.png}
width=${#zeros}
count=$(find "$frames" -maxdepth 1 -name 'frame_*.png' -printf '%f\n' | grep -cE "^frame_[0-9]{$width}\.png$" || true)

files=()
for ((i = 0; i < count; i++)); do
  printf -v f '%s/frame_%0*d.png' "$frames" "$width" "$i"
  if [ ! -f "$f" ]; then
    echo "error: $f is missing: frames must be consecutive from 0 (found $count frame files)" >&2
    exit 1
  fi
  files+=("$f")
done
# A PNG is complete when it ends with the IEND chunk: its last 8 bytes are
# 'I' 'E' 'N' 'D' ae 42 60 82. Its size sits in the IHDR chunk (bytes 16-23). One tail, one
# head and one od read every frame at once (a process per frame costs more than ffmpeg).
mapfile -t sizes < <(stat -c %s -- "${files[@]}")
for ((i = 0; i < count; i++)); do
  if [ "${sizes[$i]}" -lt 57 ]; then
    echo "error: ${files[$i]} is incomplete or not a PNG (${sizes[$i]} bytes); render it again" >&2
    exit 1
  fi
done
mapfile -t tails < <(tail -q -c 8 -- "${files[@]}" | od -An -v -tx1 -w8 | tr -d ' ')
mapfile -t heads < <(head -q -c 24 -- "${files[@]}" | od -An -v -tx1 -w24 | tr -d ' ')
expected_size=${heads[0]:32:16}
for ((i = 0; i < count; i++)); do
  if [ "${tails[$i]}" != "49454e44ae426082" ]; then
    echo "error: ${files[$i]} is incomplete or not a PNG (no IEND chunk at its end); render it again" >&2
    exit 1
  fi
  if [ "${heads[$i]:32:16}" != "$expected_size" ]; then
    echo "error: ${files[$i]} has a different image size from frame 0; render all frames at one size" >&2
    exit 1
  fi
done
# A frame whose scene file exists but whose image does not would silently shorten the video.
sdf_count=$(find "$frames" -maxdepth 1 -name 'frame_*.sdf' | wc -l)
if [ "$sdf_count" -gt "$count" ]; then
  echo "error: $frames has $sdf_count frame_*.sdf files but only $count rendered frames; run anim render $frames first" >&2
  exit 1
fi

out_dir=$(dirname -- "$output")
mkdir -p -- "$out_dir"
tmp=$(mktemp "$out_dir/.$(basename -- "$output").XXXXXX")
trap 'rm -f -- "$tmp"' EXIT

# ffmpeg reads the input name as a pattern in which '%' is special: the folder's own '%'
# characters are doubled so they stand for themselves.
pattern_dir=${frames//%/%%}

# pad: round width and height up to even numbers (yuv420p subsamples chroma 2x2).
ffmpeg -hide_banner -loglevel error -nostdin -y \
  -framerate "$fps" -start_number 0 -i "$pattern_dir/frame_%0${width}d.png" \
  -frames:v "$count" \
  -vf "pad=ceil(iw/2)*2:ceil(ih/2)*2" \
  -c:v libx264 -preset "${X264_PRESET:-veryfast}" -pix_fmt yuv420p -r "$fps" -movflags +faststart \
  -f mp4 "$tmp"
# mktemp makes the file private (0600); a video is a new file like any other.
chmod "$(printf '%o' $((0666 & ~$(umask))))" "$tmp"
mv -f -- "$tmp" "$output"
trap - EXIT

# One probe for both figures: packets counted (not the container's claim) and the duration.
{ read -r frames_out; read -r duration; } < <(ffprobe -v error -select_streams v:0 -count_packets \
  -show_entries stream=nb_read_packets:format=duration -of default=nw=1:nk=1 "$output")
echo "wrote $output: $frames_out frames, ${duration} s at $fps fps"

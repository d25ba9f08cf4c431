#!/usr/bin/env bash
# Encodes the rendered frames of a frame directory into a video.
#
#   scripts/encode.sh FRAMES_DIR [OUTPUT] [FPS] [--codec CODEC] [--fps FPS] [--images DIR] [--check]
#
# The frames are FRAMES_DIR's .sdf files in natural order (as `anim render DIR` takes them);
# each one's image is the file its first `render` line names, in whatever pattern and format
# anim wrote it (PNG, 16-bit PNG, JPEG, BMP, TGA, PPM, OpenEXR), looked for in FRAMES_DIR or
# in --images DIR (where `anim render --out DIR` put them). FPS defaults to the frame rate
# in the first frame's header (`# Frame 0 of N (t = 0 s at F fps), generated from ...`: a
# whole number or a ratio like 24000/1001), else 24.
#
# CODEC (default h264, or what OUTPUT's extension says: .webm webm, .gif gif):
#   h264    H.264 (libx264), yuv420p, in .mp4/.mov/.mkv    (default output animation.mp4)
#   h265    H.265 (libx265), yuv420p, in .mp4/.mov/.mkv    (animation.mp4)
#   prores  ProRes 422 HQ, or 4444 with alpha for frames with an alpha channel, .mov/.mkv
#   webm    VP9 (libvpx-vp9), with alpha for frames with one, .webm/.mkv
#   ffv1    FFV1, lossless (RGB, alpha and 16 bits kept), .mkv
#   gif     GIF with a palette made for the animation, .gif
# Frames with alpha going into a codec without it are composited over black. Colour: 8-bit
# and 16-bit tone-mapped images are encoded as they are; OpenEXR (linear radiance) and
# 16-bit PNGs marked linear (gAMA 1.0, `--linear`) get anim's own tone map c/(c+1) per
# channel first, so the video looks like anim's 8-bit images (a linear PNG was clipped at 1
# when written: OpenEXR keeps the highlights). OpenEXR's premultiplied alpha is divided out
# before the tone map, as a straight PNG's colour is.
#
# Everything is checked before ffmpeg starts: ffmpeg and ffprobe installed and built with the
# encoder, the codec and the output's extension, the output's folder (it must exist), every
# frame's image there (a PNG complete and of frame 0's size); --check stops after the
# checks that need no frames (the tools, codec, output), before anything renders. Odd sizes are padded by one
# pixel where the codec's chroma needs even sides. The video is written to a temporary file
# beside OUTPUT and moved into place, so OUTPUT is never half-written; it gets the
# permissions the umask gives a new file. X264_PRESET / X265_PRESET (default veryfast /
# fast) trade encoding time for file size.
set -euo pipefail

usage() {
  echo "usage: $0 FRAMES_DIR [OUTPUT] [FPS] [--codec h264|h265|prores|webm|ffv1|gif] [--fps FPS] [--images DIR] [--check]" >&2
  exit 2
}

positional=()
codec=
fps=
images=
check=0
while [ $# -gt 0 ]; do
  case $1 in
    --codec) [ $# -ge 2 ] || usage; codec=$2; shift 2 ;;
    --codec=*) codec=${1#--codec=}; shift ;;
    --fps) [ $# -ge 2 ] || usage; fps=$2; shift 2 ;;
    --fps=*) fps=${1#--fps=}; shift ;;
    --images) [ $# -ge 2 ] || usage; images=$2; shift 2 ;;
    --images=*) images=${1#--images=}; shift ;;
    --check) check=1; shift ;;
    -h | --help) usage ;;
    --) shift; positional+=("$@"); break ;;
    -?*) echo "error: unknown option $1" >&2; usage ;;
    *) positional+=("$1"); shift ;;
  esac
done
if [ ${#positional[@]} -lt 1 ] || [ ${#positional[@]} -gt 3 ]; then usage; fi
frames=${positional[0]}
output=${positional[1]:-}
if [ ${#positional[@]} -eq 3 ]; then
  if [ -n "$fps" ] && [ "$fps" != "${positional[2]}" ]; then
    echo "error: two frame rates given: $fps and ${positional[2]}" >&2
    exit 2
  fi
  fps=${positional[2]}
fi
images=${images:-$frames}

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

# The codec: given, else what the output's extension says, else H.264.
out_ext=
case $(basename -- "${output:-x}") in *.*) out_ext=${output##*.}; out_ext=${out_ext,,} ;; esac
if [ -z "$codec" ]; then
  case $out_ext in webm) codec=webm ;; gif) codec=gif ;; *) codec=h264 ;; esac
fi
case $codec in
  h264) encoder=libx264; containers="mp4 mov mkv" ;;
  h265 | hevc) codec=h265; encoder=libx265; containers="mp4 mov mkv" ;;
  prores) encoder=prores_ks; containers="mov mkv" ;;
  webm | vp9) codec=webm; encoder=libvpx-vp9; containers="webm mkv" ;;
  ffv1) encoder=ffv1; containers="mkv" ;;
  gif) encoder=gif; containers="gif" ;;
  *)
    echo "error: unknown codec '$codec'; choose one of h264, h265, prores, webm, ffv1, gif" >&2
    exit 2
    ;;
esac
if [ -z "$output" ]; then
  output=animation.${containers%% *}
  out_ext=${containers%% *}
fi
if [[ " $containers " != *" $out_ext "* ]]; then
  echo "error: $codec video goes in a file ending .${containers// /, .}, not '$(basename -- "$output")'" >&2
  exit 2
fi
# Captured first: `grep -q` stopping early would kill ffmpeg with SIGPIPE under pipefail.
encoders=$(ffmpeg -hide_banner -encoders 2>/dev/null || true)
if ! grep -qE "^ V\S* $encoder( |$)" <<<"$encoders"; then
  echo "error: this ffmpeg has no $encoder encoder (for --codec $codec); install a build with it" >&2
  exit 1
fi
# Refused before anything is written: a name ffmpeg would read as an option, a directory
# (the video would otherwise end up hidden inside it), a folder that does not exist.
case $(basename -- "$output") in
  -*)
    echo "error: the output name '$output' starts with '-'; write ./$output" >&2
    exit 2
    ;;
esac
if [ -d "$output" ]; then
  echo "error: $output is a directory; give the video's file name, e.g. $output/animation.${containers%% *}" >&2
  exit 2
fi
out_dir=$(dirname -- "$output")
if [ ! -d "$out_dir" ]; then
  echo "error: the output folder $out_dir does not exist" >&2
  exit 1
fi
# --check: the frames are not there yet (animate.sh asks before it renders them).
if [ "$check" = 1 ]; then exit 0; fi
if [ ! -d "$frames" ]; then
  echo "error: $frames is not a directory" >&2
  exit 1
fi
if [ ! -d "$images" ]; then
  echo "error: the images folder $images is not a directory" >&2
  exit 1
fi

# The frames, in natural order, and each one's image from its first render line: the first
# word after `render` that ends in an image extension (whatever the render line's form).
mapfile -t sdfs < <(find "$frames" -maxdepth 1 -type f -name '*.sdf' ! -name '.*' -printf '%f\n' | LC_ALL=C sort -V)
count=${#sdfs[@]}
if [ "$count" -eq 0 ]; then
  echo "error: no frame files (.sdf) in $frames; the images are found from their render lines" >&2
  exit 1
fi
# Each name goes to awk as ./NAME: neither an option nor a `var=value` assignment then.
mapfile -t named < <(cd "$frames" && awk '
  FNR == 1 { found = 0 }
  !found && $1 == "render" {
    for (i = 2; i <= NF; i++) {
      if (tolower($i) ~ /\.(png|ppm|pgm|pnm|pbm|pam|bmp|jpg|jpeg|tga|exr)$/) {
        print substr(FILENAME, 3) "\t" $i; found = 1; break
      }
    }
  }' "${sdfs[@]/#/./}")
declare -A image_of=()
for line in "${named[@]}"; do image_of[${line%%$'\t'*}]=${line#*$'\t'}; done

if [ -z "$fps" ]; then
  # The generator's header: "... at 24 fps), generated from" (or "at 24000/1001 fps").
  fps=$(sed -n '1s/^# Frame .* at \([0-9][0-9]*\(\/[0-9][0-9]*\)\{0,1\}\) fps).*/\1/p' "$frames/${sdfs[0]}")
  if [ -z "$fps" ]; then
    fps=24
    echo "note: ${sdfs[0]} has no anim header with a frame rate; encoding at 24 fps (give FPS to choose)" >&2
  fi
fi
if ! [[ $fps =~ ^[0-9]+(/[0-9]+)?$ ]] || [[ $fps =~ ^0+(/|$) ]] || [[ $fps =~ /0+$ ]]; then
  echo "error: FPS must be a positive whole number (or a ratio like 30000/1001), not '$fps'" >&2
  exit 2
fi

files=()
ext=
for sdf in "${sdfs[@]}"; do
  name=${image_of[$sdf]:-}
  if [ -z "$name" ]; then
    echo "error: $frames/$sdf has no render line naming an image" >&2
    exit 1
  fi
  # anim writes a name that leaves the folder (absolute, or climbing out) into the folder.
  case $name in /* | ../*) name=$(basename -- "$name") ;; esac
  this_ext=${name##*.}
  this_ext=${this_ext,,}
  if [ -z "$ext" ]; then ext=$this_ext; fi
  if [ "$this_ext" != "$ext" ]; then
    echo "error: $sdf writes a .$this_ext image but ${sdfs[0]} a .$ext one; a video takes one format" >&2
    exit 1
  fi
  f=$images/$name
  if [ ! -f "$f" ] || [ ! -s "$f" ]; then
    echo "error: $f (the image of $sdf) is missing or empty; run anim render $frames first" >&2
    exit 1
  fi
  files+=("$f")
done

if [ "$ext" = png ]; then
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
fi

# What the first frame holds: alpha, and linear values (OpenEXR; a PNG with gAMA 1.0 right
# after its header, as anim writes --linear).
pix_fmt=$(ffprobe -v error -select_streams v:0 -show_entries stream=pix_fmt -of default=nw=1:nk=1 -- "${files[0]}" || true)
if [ -z "$pix_fmt" ]; then
  echo "error: ${files[0]} cannot be read as an image" >&2
  exit 1
fi
alpha=0
case $pix_fmt in rgba* | bgra* | argb | abgr | gbrap* | ya* | yuva* | pal8) alpha=1 ;; esac
linear=0
if [ "$ext" = exr ]; then
  linear=1
elif [ "$ext" = png ] && [ "$(head -c 45 -- "${files[0]}" | tail -c 12 | od -An -v -tx1 | tr -d ' \n')" = 0000000467414d41000186a0 ]; then
  linear=1
fi

# The filters: anim's tone map for linear frames (alpha divided out of premultiplied
# OpenEXR first; geq reads each pixel as it is, as its bilinear default blends the last
# column and row with their neighbours); black under the frames where the codec has no alpha; even sides where
# its chroma needs them.
filters=()
if [ "$linear" = 1 ]; then
  if [ "$ext" = exr ] && [ "$alpha" = 1 ]; then
    tone="if(gt(alpha(X,Y),0),st(0,C(X,Y)/alpha(X,Y))/(ld(0)+1),0)"
    filters+=("format=gbrapf32le,geq=r='${tone//C/r}':g='${tone//C/g}':b='${tone//C/b}':a='alpha(X,Y)':interpolation=n")
  elif [ "$ext" = exr ]; then
    tone="C(X,Y)/(C(X,Y)+1)"
    filters+=("format=gbrpf32le,geq=r='${tone//C/r}':g='${tone//C/g}':b='${tone//C/b}':interpolation=n")
  else
    # 16-bit levels v: c = v/65535, stored again as 65535·c/(c+1).
    filters+=("lutrgb=r='65535*val/(val+65535)':g='65535*val/(val+65535)':b='65535*val/(val+65535)'")
  fi
fi
keeps_alpha=0
if [ "$alpha" = 1 ]; then
  case $codec in
    prores | webm | ffv1) keeps_alpha=1 ;;
    *) filters+=("premultiply=inplace=1,format=rgb24") ;;
  esac
fi
codec_args=()
case $codec in
  h264)
    filters+=("pad=ceil(iw/2)*2:ceil(ih/2)*2")
    codec_args=(-c:v libx264 -preset "${X264_PRESET:-veryfast}" -pix_fmt yuv420p)
    ;;
  h265)
    filters+=("pad=ceil(iw/2)*2:ceil(ih/2)*2")
    codec_args=(-c:v libx265 -preset "${X265_PRESET:-fast}" -pix_fmt yuv420p -tag:v hvc1 -x265-params log-level=error)
    ;;
  prores)
    if [ "$keeps_alpha" = 1 ]; then
      codec_args=(-c:v prores_ks -profile:v 4444 -pix_fmt yuva444p10le -alpha_bits 16)
    else
      filters+=("pad=ceil(iw/2)*2:ih")
      codec_args=(-c:v prores_ks -profile:v hq -pix_fmt yuv422p10le)
    fi
    ;;
  webm)
    if [ "$keeps_alpha" = 1 ]; then pix=yuva420p; else pix=yuv420p; fi
    codec_args=(-c:v libvpx-vp9 -pix_fmt "$pix" -crf 30 -b:v 0 -row-mt 1 -deadline good -cpu-used 4 -auto-alt-ref 0)
    ;;
  ffv1)
    codec_args=(-c:v ffv1 -level 3 -g 1)
    ;;
  gif)
    filters+=("split[a][b];[a]palettegen=stats_mode=diff[p];[b][p]paletteuse=dither=sierra2_4a")
    ;;
esac
case $out_ext in mp4 | mov) codec_args+=(-movflags +faststart) ;; esac

# The images as ffmpeg counts them: their own names where those are one numbered pattern
# from 0 (as anim's `{frame}` names them), else links under numbers in a temporary folder (a
# process per link: only for names that need it).
tmp=
links=
trap 'if [ -n "$links" ]; then rm -rf -- "$links"; fi; if [ -n "$tmp" ]; then rm -f -- "$tmp"; fi' EXIT
pattern=
if [[ ${files[0]} =~ ^(.*[^0-9])?(0+)(\.[^./]*)$ ]]; then
  # printf's pattern: the name with its % doubled, the zeros as %0Nd.
  pre=${BASH_REMATCH[1]}
  post=${BASH_REMATCH[3]}
  pattern="${pre//%/%%}%0${#BASH_REMATCH[2]}d${post//%/%%}"
  for ((i = 0; i < count; i++)); do
    printf -v expected "$pattern" "$i"
    if [ "$expected" != "${files[$i]}" ]; then
      pattern=
      break
    fi
  done
fi
if [ -z "$pattern" ]; then
  links=$(mktemp -d)
  for ((i = 0; i < count; i++)); do
    f=${files[$i]}
    case $f in /*) ;; *) f=$PWD/$f ;; esac
    printf -v link '%s/%06d.%s' "$links" "$i" "$ext"
    ln -s -- "$f" "$link"
  done
  pattern=$links/%06d.$ext
fi

tmp=$(mktemp "$out_dir/.$(basename -- "$output").XXXXXX")
filter_args=()
if [ ${#filters[@]} -gt 0 ]; then
  chain=$(IFS=,; echo "${filters[*]}")
  filter_args=(-filter_complex "$chain")
fi
ffmpeg -hide_banner -loglevel error -nostdin -y \
  -framerate "$fps" -start_number 0 -i "$pattern" \
  -frames:v "$count" "${filter_args[@]}" "${codec_args[@]}" -r "$fps" \
  -f "$(case $out_ext in mkv) echo matroska ;; *) echo "$out_ext" ;; esac)" "$tmp"
# mktemp makes the file private (0600); a video is a new file like any other.
chmod "$(printf '%o' $((0666 & ~$(umask))))" "$tmp"
mv -f -- "$tmp" "$output"
tmp=

# One probe for both figures: packets counted (not the container's claim) and the duration.
{ read -r frames_out; read -r duration; } < <(ffprobe -v error -select_streams v:0 -count_packets \
  -show_entries stream=nb_read_packets:format=duration -of default=nw=1:nk=1 "$output")
echo "wrote $output: $frames_out frames, ${duration} s at $fps fps ($codec)"

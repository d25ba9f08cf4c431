#!/usr/bin/env python3
"""Render every scene file under the given folders at thumbnail size into one contact sheet.

    python3 scripts/contact-sheet.py [--anim BINARY] [--out sheet.png] DIR [DIR ...]

Each `.sdf` and `.txt` file (MANIFEST.tsv aside) is rendered with `anim render --width 96
--height 72 --spp 1` into a temporary folder; its first image goes into a grid, labelled with
the file's path below the folder given and how anim judged it: a red label for a file anim
refused, orange for an image anim calls blank or nearly one colour, so a person sees at a glance which
files look wrong. Needs Pillow (`pip install pillow`). The sheet is an output: keep it out of
git.
"""

import argparse
import os
import subprocess
import sys
import tempfile

try:
    from PIL import Image, ImageDraw, ImageFont
except ImportError:
    sys.exit("contact-sheet.py needs Pillow: pip install pillow")

THUMB = (96, 72)
LABEL_HEIGHT = 24
COLUMNS = 10


def scene_files(folder):
    for root, dirs, names in os.walk(folder):
        dirs.sort()
        for name in sorted(names):
            if name.endswith((".sdf", ".txt")) and name != "MANIFEST.tsv":
                yield os.path.join(root, name)


def render(anim, scene, out):
    """(image path or None, 'ok' | 'blank' | 'refused')."""
    run = subprocess.run(
        [anim, "render", scene, "--out", out, "--spp", "1",
         "--width", str(THUMB[0]), "--height", str(THUMB[1])],
        capture_output=True, text=True)
    images = sorted(
        os.path.join(out, f) for f in os.listdir(out)
        if f.lower().endswith((".png", ".ppm", ".jpg", ".jpeg", ".bmp", ".tga"))
    ) if os.path.isdir(out) else []
    if run.returncode != 0 or not images:
        return None, "refused"
    blank = "would be blank" in run.stderr or "is one colour over" in run.stderr
    return images[0], "blank" if blank else "ok"


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dirs", nargs="+")
    parser.add_argument("--anim", default=os.environ.get("ANIM", "target/release/anim"))
    parser.add_argument("--out", default="contact-sheet.png")
    args = parser.parse_args()

    cells = []
    with tempfile.TemporaryDirectory() as tmp:
        for folder in args.dirs:
            for scene in scene_files(folder):
                out = os.path.join(tmp, f"{len(cells)}")
                image, verdict = render(args.anim, scene, out)
                thumb = Image.new("RGB", THUMB, (40, 40, 40))
                if image:
                    with Image.open(image) as im:
                        im = im.convert("RGB")
                        im.thumbnail(THUMB)
                        thumb.paste(im, (0, 0))
                cells.append((os.path.relpath(scene, folder), verdict, thumb))
                print(f"{verdict:8} {scene}", file=sys.stderr)
    rows = (len(cells) + COLUMNS - 1) // COLUMNS
    cell_w, cell_h = THUMB[0] + 4, THUMB[1] + LABEL_HEIGHT
    sheet = Image.new("RGB", (COLUMNS * cell_w, max(rows, 1) * cell_h), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    font = ImageFont.load_default()
    colour = {"ok": (0, 0, 0), "blank": (200, 110, 0), "refused": (200, 0, 0)}
    for i, (name, verdict, thumb) in enumerate(cells):
        x, y = (i % COLUMNS) * cell_w, (i // COLUMNS) * cell_h
        sheet.paste(thumb, (x + 2, y))
        label = name if len(name) <= 34 else "…" + name[-33:]
        # Two short lines under the thumbnail: the folder, then the file.
        head, _, tail = label.rpartition("/")
        draw.text((x + 2, y + THUMB[1] + 1), head[-17:], fill=colour[verdict], font=font)
        draw.text((x + 2, y + THUMB[1] + 12), tail[:17], fill=colour[verdict], font=font)
    sheet.save(args.out)
    counts = {v: sum(1 for c in cells if c[1] == v) for v in colour}
    print(f"{args.out}: {len(cells)} files, {counts['ok']} drawn, {counts['blank']} blank, "
          f"{counts['refused']} refused", file=sys.stderr)


if __name__ == "__main__":
    main()

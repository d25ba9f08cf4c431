#!/usr/bin/env python3
"""Drives the page of a running `anim preview` in headless Chromium (Playwright), as an
animator would: waits for the frames, reads the pixels on screen, scrubs, edits the spec on
disk, breaks it, fixes it, edits a file the base scene includes. tests/preview/browser.rs
runs it and compares the pixels with `anim render`'s.

    preview-browser.py --url http://127.0.0.1:PORT/ --spec SPEC --edited FILE --broken FILE
                       --frames N --out DIR [--chromium /usr/bin/chromium]
                       [--included FILE --included-edited FILE]

Writes into DIR: first.ppm, last.ppm (frames 0 and N-1 at full quality), edited.ppm (frame
0 after the edit), included.ppm (frame 0 after the included file was replaced by
--included-edited, once it shows within 5 s), export.mp4 (what Export gave once the included
file was put back: frame 0 after the edit, as it was), screenshot.png,
and result.json (what was seen, with timings; key_steps: each arrow key pressed with the
timeline, a button or nothing focused, with the frame before and after).

    preview-browser.py --url URL --frames N --screenshot OUT.png [--at FRAME]

only waits until every frame is drawn small, scrubs to FRAME and takes the page's picture
(the README's, of `anim preview` on a keyed copy of animations/orbit.ron).
"""

import argparse
import json
import pathlib
import sys
import time

from playwright.sync_api import sync_playwright

READ_PIXELS = """(img) => {
  const c = document.createElement('canvas');
  c.width = img.naturalWidth; c.height = img.naturalHeight;
  const g = c.getContext('2d');
  g.drawImage(img, 0, 0);
  const d = g.getImageData(0, 0, c.width, c.height).data;
  return {w: c.width, h: c.height, rgba: Array.from(d)};
}"""


def write_ppm(path, shot):
    rgb = bytearray()
    rgba = shot["rgba"]
    for i in range(0, len(rgba), 4):
        rgb += bytes(rgba[i:i + 3])
    path.write_bytes(b"P6\n%d %d\n255\n" % (shot["w"], shot["h"]) + bytes(rgb))


def shown(page, frame, quality=None, version_not=None, timeout=30000):
    """Waits until the image on screen is frame `frame` (at `quality`), returns its dataset."""
    cond = f"img.dataset.frame === '{frame}'"
    if quality:
        cond += f" && img.dataset.quality === '{quality}'"
    if version_not is not None:
        cond += f" && img.dataset.version !== '{version_not}'"
    page.wait_for_function(
        f"() => {{ const img = document.getElementById('frame'); return img.complete && {cond}; }}",
        timeout=timeout,
    )
    return page.eval_on_selector("#frame", "img => ({...img.dataset})")


def scrub(page, frame):
    page.locator("#scrub").fill(str(frame))


def screenshot(a):
    with sync_playwright() as p:
        browser = p.chromium.launch(executable_path=a.chromium, headless=True,
                                    args=["--no-sandbox"])
        page = browser.new_page(viewport={"width": 1000, "height": 760})
        page.goto(a.url)
        page.wait_for_function(f"() => Number(document.body.dataset.small) === {a.frames}",
                               timeout=30000)
        scrub(page, a.at)
        shown(page, a.at, "full", timeout=60000)
        page.screenshot(path=a.screenshot)
        browser.close()
    return 0


def key_steps(page):
    """Presses the arrow keys with the timeline (clicked, as a user does), a button and the
    page focused; each press must step one frame. Returns [(focus, before, after, key)]."""
    value = lambda: page.eval_on_selector("#scrub", "s => Number(s.value)")
    steps = []
    for target, key in [("#scrub", "ArrowRight"), ("#scrub", "ArrowLeft"), ("#play", "ArrowRight"),
                        ("#next", "ArrowLeft"), ("body", "ArrowRight")]:
        if target == "#scrub":
            page.click(target)
        else:
            scrub(page, 2)
            page.focus(target) if target != "body" else page.eval_on_selector(
                "body", "b => document.activeElement.blur()")
        before = value()
        page.keyboard.press(key)
        page.wait_for_timeout(100)
        steps.append([target, before, value(), key])
    return steps


def edit_included(page, a, result):
    """Replaces the included file and waits (5 s at most) for frame 0 to change on screen."""
    scrub(page, 0)
    before = shown(page, 0, "full")
    edited_at = time.monotonic()
    a.included.write_text(a.included_edited.read_text())
    shown(page, 0, version_not=before["version"], timeout=5000)
    result["included_edit_to_screen_s"] = time.monotonic() - edited_at
    shown(page, 0, "full")
    write_ppm(a.out / "included.ppm", page.eval_on_selector("#frame", READ_PIXELS))


def export(page, a, result, original):
    """Puts the included file back as it was (`original`: every frame is redrawn, small
    first), presses Export as soon as frame 0 shows the change, notes what the page says
    meanwhile, and saves the video as export.mp4."""
    if original is not None:
        scrub(page, 0)
        before = shown(page, 0)
        a.included.write_text(original)
        shown(page, 0, version_not=before["version"], timeout=5000)
    page.click("#export")
    result["export_progress"] = page.inner_text("#export-status")
    page.wait_for_function("() => document.getElementById('export-status').dataset.done === '1'",
                           timeout=60000)
    link = page.query_selector("#export-status a")
    if link:
        video = page.request.get(a.url + link.get_attribute("href").lstrip("/"))
        (a.out / "export.mp4").write_bytes(video.body())
        result["export"] = {"status": video.status, "bytes": len(video.body()),
                            "mp4": video.body()[4:8] == b"ftyp",
                            "said": page.inner_text("#export-status")}
    else:
        result["export"] = {"message": page.inner_text("#export-status")}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--url", required=True)
    ap.add_argument("--spec", type=pathlib.Path)
    ap.add_argument("--edited", type=pathlib.Path)
    ap.add_argument("--broken", type=pathlib.Path)
    ap.add_argument("--included", type=pathlib.Path)
    ap.add_argument("--included-edited", type=pathlib.Path)
    ap.add_argument("--frames", required=True, type=int)
    ap.add_argument("--out", type=pathlib.Path)
    ap.add_argument("--chromium", default="/usr/bin/chromium")
    ap.add_argument("--screenshot")
    ap.add_argument("--at", type=int, default=0)
    a = ap.parse_args()
    if a.screenshot:
        return screenshot(a)
    if not (a.spec and a.edited and a.broken and a.out):
        ap.error("--spec, --edited, --broken and --out are needed without --screenshot")
    result = {}
    last = a.frames - 1
    with sync_playwright() as p:
        # Root in a container has no user namespaces for Chromium's sandbox.
        browser = p.chromium.launch(executable_path=a.chromium, headless=True,
                                    args=["--no-sandbox"])
        page = browser.new_page(viewport={"width": 1000, "height": 760})
        page.goto(a.url)
        page.wait_for_function(f"() => document.body.dataset.full === '{a.frames}'",
                               timeout=30000)
        shown(page, 0, "full")
        write_ppm(a.out / "first.ppm", page.eval_on_selector("#frame", READ_PIXELS))
        scrub(page, last)
        shown(page, last, "full")
        write_ppm(a.out / "last.ppm", page.eval_on_selector("#frame", READ_PIXELS))
        scrub(page, 2)
        shown(page, 2, "full")
        result["position"] = page.inner_text("#position")
        result["key_marks"] = page.locator("#keys span").count()
        page.click("#play")
        page.wait_for_function("() => document.getElementById('frame').dataset.frame !== '2'",
                               timeout=5000)
        page.click("#play")
        result["played"] = True
        page.click("#next")
        after_step = page.eval_on_selector("#scrub", "s => Number(s.value)")
        page.click("#prev")
        result["stepped"] = page.eval_on_selector("#scrub", "s => Number(s.value)") == after_step - 1 \
            or after_step == 0
        result["key_steps"] = key_steps(page)
        scrub(page, 2)
        shown(page, 2, "full")
        page.screenshot(path=str(a.out / "screenshot.png"))

        scrub(page, 0)
        before = shown(page, 0, "full")
        edited_at = time.monotonic()
        a.spec.write_text(a.edited.read_text())
        shown(page, 0, version_not=before["version"], timeout=10000)
        result["edit_to_screen_s"] = time.monotonic() - edited_at
        shown(page, 0, "full")
        write_ppm(a.out / "edited.ppm", page.eval_on_selector("#frame", READ_PIXELS))

        a.spec.write_text(a.broken.read_text())
        page.wait_for_selector("#diagnostics:not([hidden])", timeout=10000)
        result["diagnostic"] = page.inner_text("#diag-text")
        result["frame_kept"] = page.eval_on_selector("#frame", "img => img.complete && img.naturalWidth > 0")
        a.spec.write_text(a.edited.read_text())
        page.wait_for_selector("#diagnostics", state="hidden", timeout=10000)
        result["fixed"] = True

        original = a.included.read_text() if a.included else None
        if a.included:
            edit_included(page, a, result)

        export(page, a, result, original)

        refused = {}
        for path in ["../../../etc/passwd", "%2e%2e/%2e%2e/etc/passwd", "frame/..%2f..%2fsmall.ron",
                     "small.ron"]:
            refused[path] = page.request.get(a.url + path).status
        result["refused"] = refused
        result["all_refused"] = all(400 <= s < 500 for s in refused.values())
        browser.close()
    text = json.dumps(result, indent=2, ensure_ascii=False)
    (a.out / "result.json").write_text(text, encoding="utf-8")
    print(text)
    return 0


if __name__ == "__main__":
    sys.exit(main())

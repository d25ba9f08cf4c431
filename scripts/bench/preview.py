#!/usr/bin/env python3
"""How fast `anim preview` puts the animation on screen, against `anim render`.

    ANIM=path/to/anim ROUNDS=2 python3 scripts/bench/preview.py   # builds release without ANIM

1. `anim generate` + `anim render DIR` of animations/orbit.ron (120 frames, 640x360), wall s.
2. `anim preview animations/orbit.ron`: seconds from launch until every frame can be shown
   small (state small or full in /api/state, what the page reads), and until every frame is
   at full quality; the full-quality time over anim render's (generate + render).
3. The same orbit with one keyed track (the mirror ball rises from 0 s to 1 s and is back at
   2 s): once every frame is small, the key at 1 s is edited on disk; seconds until every
   changed frame is on screen again (small or full, none stale), and, once all are full, how
   many times each frame was rendered: unchanged frames exactly twice (small, full).
"""

import json
import resource
import os
import pathlib
import shutil
import subprocess
import sys
import tempfile
import time
import urllib.request

ROOT = pathlib.Path(__file__).resolve().parents[2]
FRAMES = 120
TRACK = """    tracks: [
        (target: "ball", translate: [
            (at: 0, value: (0, 0, 0)), (at: 1, value: (0, KEY, 0)), (at: 2, value: (0, 0, 0)),
        ]),
    ],
)
"""


def anim_binary():
    if os.environ.get("ANIM"):
        return os.environ["ANIM"]
    subprocess.run(["cargo", "build", "--release", "-q"], cwd=ROOT, check=True)
    target = pathlib.Path(os.environ.get("CARGO_TARGET_DIR", ROOT / "target"))
    return str(target / "release" / "anim")


def spec_with_track(key):
    text = (ROOT / "animations/orbit.ron").read_text()
    body = text[: text.rstrip().rfind(")")]
    return body + TRACK.replace("KEY", key)


def state(port):
    with urllib.request.urlopen(f"http://127.0.0.1:{port}/api/state") as r:
        return json.loads(r.read())


def start(anim, spec, cwd):
    t0 = time.monotonic()
    p = subprocess.Popen([anim, "preview", spec, "--port", "0"], cwd=cwd,
                         stderr=subprocess.PIPE, stdout=subprocess.DEVNULL, text=True)
    line = p.stderr.readline()
    port = int(line.rsplit(":", 1)[1].strip().rstrip("/"))
    return p, port, t0


def wait(port, done, limit=300):
    start_t = time.monotonic()
    while True:
        try:
            s = state(port)
            if done(s):
                return time.monotonic(), s
        except OSError:
            pass
        if time.monotonic() - start_t > limit:
            raise SystemExit("gave up waiting")
        time.sleep(0.02)


def shown(s):
    return len(s["frames"]) == FRAMES and all(f["state"] in ("small", "full") for f in s["frames"])


def full(s):
    return len(s["frames"]) == FRAMES and all(f["state"] == "full" for f in s["frames"])


def stop(p):
    p.send_signal(2)
    p.wait(timeout=30)


def cpu():
    """CPU seconds (user + system) of the children waited for so far."""
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def orbit_round(anim, work):
    shutil.rmtree(work / "base", ignore_errors=True)
    c = cpu()
    t = time.monotonic()
    subprocess.run([anim, "generate", "orbit.ron", "-o", "base", "-q"], cwd=work, check=True)
    t_gen = time.monotonic() - t
    t = time.monotonic()
    subprocess.run([anim, "render", "base", "--quiet", "--force"], cwd=work, check=True)
    t_render = time.monotonic() - t
    c_base = cpu() - c
    print(f"  anim generate: {t_gen:.2f} s, anim render DIR: {t_render:.2f} s "
          f"(together {t_gen + t_render:.2f} s, {c_base:.2f} CPU s)")

    c = cpu()
    p, port, t0 = start(anim, "orbit.ron", work)
    t_small, _ = wait(port, shown)
    t_full, s = wait(port, full)
    stop(p)
    c_preview = cpu() - c
    renders = sorted({f["renders"] for f in s["frames"]})
    print(f"  anim preview orbit.ron: every frame small after {t_small - t0:.2f} s, "
          f"every frame full after {t_full - t0:.2f} s "
          f"= {(t_full - t0) / (t_gen + t_render):.2f} x generate + render "
          f"({(t_full - t0) / t_render:.2f} x render alone); renders per frame {renders}; "
          f"{c_preview:.2f} CPU s until stopped = {c_preview / c_base:.2f} x")


def main():
    anim = anim_binary()
    work = pathlib.Path(tempfile.mkdtemp(prefix="preview-bench-"))
    shutil.copy(ROOT / "animations/orbit.ron", work / "orbit.ron")
    shutil.copy(ROOT / "animations/showcase.sdf", work / "showcase.sdf")

    # In turns, so that load from elsewhere on the machine falls on both alike.
    for round_ in range(int(os.environ.get("ROUNDS", "1"))):
        print(f"round {round_ + 1}")
        orbit_round(anim, work)

    (work / "keyed.ron").write_text(spec_with_track("0.8"))
    p, port, t0 = start(anim, "keyed.ron", work)
    _, before = wait(port, shown)
    edited = time.monotonic()
    (work / "keyed.ron").write_text(spec_with_track("1.6"))
    t_seen, after = wait(port, lambda s: s["builds"] >= 2 and shown(s))
    _, done = wait(port, lambda s: s["builds"] >= 2 and full(s))
    stop(p)
    counts = [f["renders"] for f in done["frames"]]
    again = [i for i, c in enumerate(counts) if c > 2]
    print(f"edit of the key at 1 s: changed frames on screen (small or full) after "
          f"{t_seen - edited:.2f} s; frames rendered more than twice: {len(again)} "
          f"({again[0] if again else '-'}..{again[-1] if again else '-'}), "
          f"frames rendered exactly twice: {counts.count(2)} of {FRAMES}")
    shutil.rmtree(work)
    return 0


if __name__ == "__main__":
    sys.exit(main())

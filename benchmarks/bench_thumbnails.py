"""What the presets' thumbnails cost the editor's frames: the time of Thumbnails.step per frame
(the editor's own loop, 1280x720) until all are made, with an empty thumbnail cache (each
rendered) and then with the cache the first run left (each read). Run under a display:

    xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/python benchmarks/bench_thumbnails.py
"""

import os
import statistics
import tempfile
import time

os.environ["ALIGHT_CACHE_DIR"] = tempfile.mkdtemp()   # an empty cache: the first run renders
os.environ.setdefault("ALIGHT_DATA_DIR", tempfile.mkdtemp())

from alight.frontends.editor.state import EditorState  # noqa: E402
from alight.frontends.editor.window import EditorWindow  # noqa: E402


def run(label: str) -> None:
    state = EditorState()
    state.load_mesh("sphere")
    state.load_env("studio")
    win = EditorWindow(state, (1280, 720))
    win.finish_bake()
    steps, frames = [], []
    step = win.thumbnails.step

    def timed(*a, **k):
        before = set(win.thumbnails._wanted.values())
        t = time.perf_counter()
        step(*a, **k)
        steps.append(time.perf_counter() - t)
        if steps[-1] > 0.5:   # which thumbnails a slow step made (a shader variant compiled first)
            done = before - set(win.thumbnails._wanted.values())
            print(f"  slow step {steps[-1] * 1000:.0f} ms: {', '.join(m.name for m, _ in done) or 'the studio bake'}")

    win.thumbnails.step = timed
    for _ in range(400):
        t = time.perf_counter()
        win.frame()
        frames.append(time.perf_counter() - t)
        if len(steps) > 3 and not win.thumbnails.pending():
            break
    made = win.thumbnails.rendered + win.thumbnails.loaded
    busy = [s * 1000 for s in steps if s > 1e-4]
    print(f"{label}: {made} thumbnails ({win.thumbnails.rendered} rendered, {win.thumbnails.loaded} read) "
          f"over {len(steps)} frames; step per busy frame median {statistics.median(busy):.1f} ms, "
          f"max {max(busy):.1f} ms; whole frame median {statistics.median(frames) * 1000:.1f} ms, "
          f"max {max(frames) * 1000:.1f} ms")
    win.close()


run("empty cache")
run("warm cache")

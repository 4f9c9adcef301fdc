"""Frames while the editor opens a mesh file: the panel's 'open mesh' on DamagedHelmet, the
editor's window under X (its own EditorWindow, frames drawn back to back as while an artist
orbits), counting the frames drawn from the request until the helmet is on screen and the
longest gap between two of them (swap to swap).

Two code trees compared, alternated A B A B (the machine is shared: its load drifts); each is a
folder put on PYTHONPATH holding ``alight`` (e.g. one made from an older commit with ``git archive
COMMIT app shaders presets | tar -x -C DIR`` and DIR/py/alight -> DIR/app). In both the request
is the panel's own ``_open_mesh`` with the field holding the path, as the button calls it: the
older tree reads the file in the frame that asks, the newer one on a worker thread.

    python benchmarks/bench_editor_open_mesh.py --a /tmp/old_py --b /tmp/new_py [--rounds 2]

Needs a display (DISPLAY, e.g. Xvfb :63 -screen 0 1600x1000x24). Prints one line a run and a
Markdown table (for benchmarks/results/editor_open_mesh.md).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
HELMET = REPO.parent / "shared" / "data" / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"

DRIVER = r"""
import json, sys, time
sys.path.insert(0, sys.argv[2])
from x_events import open_editor, settle
win = open_editor((1280, 720))
try:
    settle(win)
    for _ in range(5):
        win.frame()
    s = win.state
    last = t0 = time.perf_counter()   # the last frame's end: gaps run from frame end to frame end
    win.panel.mesh_path = sys.argv[1]
    win.panel._open_mesh(s)          # what 'open mesh' calls
    gaps, shown_at, uploading = [], None, []
    jobs = win.panel.file_jobs
    for n in range(100000):
        uploading.append(getattr(jobs, "staged", None) is not None)   # (a tree with the staged upload)
        win.frame()
        now = time.perf_counter()
        gaps.append(now - last)
        last = now
        if shown_at is None and s.mesh_spec == sys.argv[1]:
            shown_at = n
        if shown_at is not None and n >= shown_at + 1:   # the frame after: the helmet drawn
            break
    # Split at the frame that took the mesh (it uploads it): the gaps while the file was read,
    # and that frame's and the next (the upload and the first draw, on the GL thread in both trees).
    before = list(zip(gaps[:shown_at], uploading[:shown_at]))
    print(json.dumps({"frames": len(gaps), "max_gap_ms": 1000 * max(gaps), "total_s": last - t0,
                      "max_gap_reading_ms": 1000 * max([g for g, u in before if not u] or [0.0]),
                      "max_gap_uploading_ms": 1000 * max([g for g, u in before if u] or [0.0]),
                      "uploading_frames": sum(u for _, u in before),
                      "taking_frames_ms": [round(1000 * g) for g in gaps[shown_at:]], "error": s.error}))
finally:
    win.close()
"""


def one_run(pythonpath: str, home: Path) -> dict:
    home.mkdir(parents=True, exist_ok=True)
    env = dict(os.environ, PYTHONPATH=pythonpath, ALIGHT_CONFIG_DIR=str(home / "config"),
               ALIGHT_CACHE_DIR=str(home / "cache"), ALIGHT_DATA_DIR=str(home / "data"))
    out = subprocess.run([sys.executable, "-c", DRIVER, str(HELMET), str(REPO / "tests")], cwd=home, env=env,
                         capture_output=True, text=True, timeout=900)
    if out.returncode != 0:
        raise SystemExit(out.stdout[-2000:] + out.stderr[-2000:])
    return json.loads(out.stdout.strip().splitlines()[-1])


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--a", required=True, help="PYTHONPATH of the tree before")
    parser.add_argument("--b", required=True, help="PYTHONPATH of the tree after")
    parser.add_argument("--rounds", type=int, default=2)
    args = parser.parse_args()
    runs = {"a": [], "b": []}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(args.rounds):
            for name in ("a", "b"):
                result = one_run(getattr(args, name), Path(tmp) / f"{name}{r}")
                runs[name].append(result)
                print(f"{name} round {r}: {result['frames']} frames, longest gap {result['max_gap_ms']:.0f} ms "
                      f"(while reading {result['max_gap_reading_ms']:.0f} ms; while uploading "
                      f"{result['max_gap_uploading_ms']:.0f} ms over {result['uploading_frames']} frames; "
                      f"the frames taking and first "
                      f"drawing it {result['taking_frames_ms']} ms), {result['total_s']:.2f} s to the helmet drawn "
                      f"{result['error']}", flush=True)
    print("\n| tree | runs | frames from the request to the helmet drawn | longest gap (ms) | "
          "longest gap while the file is read (ms) | longest gap while its textures are written (ms) | "
          "the frames taking and first drawing it (ms) | request to helmet drawn (s) |")
    print("|---|---|---|---|---|---|---|---|")
    for name in ("a", "b"):
        rs = runs[name]
        frames = ", ".join(str(x["frames"]) for x in rs)
        gaps = ", ".join(f"{x['max_gap_ms']:.0f}" for x in rs)
        median = statistics.median(x["max_gap_ms"] for x in rs)
        totals = ", ".join(f"{x['total_s']:.2f}" for x in rs)
        reading = ", ".join(f"{x['max_gap_reading_ms']:.0f}" for x in rs)
        uploading = ", ".join(f"{x['max_gap_uploading_ms']:.0f} ({x['uploading_frames']} frames)" for x in rs)
        taking = "; ".join(", ".join(str(t) for t in x["taking_frames_ms"]) for x in rs)
        print(f"| {name} ({getattr(args, name)}) | {len(rs)} | {frames} | {gaps} (median {median:.0f}) | {reading} | "
              f"{uploading} | {taking} | {totals} |")


if __name__ == "__main__":
    main()

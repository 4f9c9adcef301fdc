"""The editor's first seconds after a first start (empty thumbnail and bake caches): the orbit's
frame times while the presets' thumbnails still render in their child process, this checkout
against another one, alternated (before, after, before, after ...), each run a fresh process.
Not a test.

    git archive main | tar -x -C /tmp/base_src && mkdir /tmp/base && ln -s /tmp/base_src/app /tmp/base/alight
    xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/python benchmarks/bench_editor_first_start.py --base /tmp/base

``--base``: a folder whose ``alight`` is the other checkout's app/ (first on PYTHONPATH for the
"before" runs). Each run is ``alight edit --benchmark --frames N`` (1280x720, the material ball,
studio IBL, 3 lights, the panel) in a config and cache folder of its own, with
``EditorWindow.wait_for_thumbnails`` made a no-op: the phases are timed right after the warm-up
frames and the bake, as the artist's first orbit is. Prints each run's phases and, a side, the
median and range of the full-resolution orbit's median over the runs, and the thumbnails made
by the end of the run.
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile

CHILD = """
import sys, time
from alight.frontends.editor.window import EditorWindow
EditorWindow.wait_for_thumbnails = lambda self, timeout_s: 0.0
_frame = EditorWindow.frame
def frame(self):
    _frame(self)
    EditorWindow.last = self
EditorWindow.frame = frame
from alight.frontends.cli import main
code = main(sys.argv[1:])
t = EditorWindow.last.thumbnails
print(f"thumbnails at the end: {t.rendered} rendered, {t.pending()} pending")
sys.exit(code)
"""
FULL = re.compile(r"^orbiting, full resolution: .*median ([\d.]+) ms, p95 ([\d.]+) ms")
THUMBS = re.compile(r"^thumbnails at the end: (\d+) rendered, (\d+) pending")


def run(side: str, args) -> dict:
    env = dict(os.environ)
    if side == "before":
        env["PYTHONPATH"] = args.base + os.pathsep + env.get("PYTHONPATH", "")
    with tempfile.TemporaryDirectory(prefix="alight-bench-first-") as tmp:
        env["ALIGHT_CONFIG_DIR"] = env["ALIGHT_CACHE_DIR"] = tmp
        p = subprocess.run([sys.executable, "-c", CHILD, "edit", "--benchmark", "--frames", str(args.frames)],
                           env=env, capture_output=True, text=True, timeout=1800, cwd=tmp)
    if p.returncode != 0:
        raise SystemExit(f"{side}: {p.stderr[-2000:]}")
    out = {}
    for line in p.stdout.splitlines():
        if m := FULL.match(line):
            out["full_ms"], out["full_p95_ms"] = float(m.group(1)), float(m.group(2))
        if m := THUMBS.match(line):
            out["rendered"], out["pending"] = int(m.group(1)), int(m.group(2))
    return out


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", required=True, help="a folder whose 'alight' is the other checkout's app/")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--frames", type=int, default=40)
    args = ap.parse_args()
    results = {"before": [], "after": []}
    with open("/proc/loadavg") as f:
        load_before = f.read().split()[:3]
    for r in range(args.rounds):
        for side in ("before", "after"):
            res = run(side, args)
            results[side].append(res)
            print(f"round {r + 1} {side}: " + ", ".join(f"{k} {v}" for k, v in res.items()), flush=True)
    with open("/proc/loadavg") as f:
        load_after = f.read().split()[:3]
    print(f"{os.cpu_count()} cores, load average {'/'.join(load_before)} before, {'/'.join(load_after)} after; "
          f"{args.rounds} alternated rounds of {args.frames} frames")
    for side, runs in results.items():
        for field in ("full_ms", "full_p95_ms"):
            xs = [x[field] for x in runs]
            print(f"{side} {field}: median {statistics.median(xs):.1f} (range {min(xs):.1f}-{max(xs):.1f})")


if __name__ == "__main__":
    main()

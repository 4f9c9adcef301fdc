"""The editor's frame times against another build of alight, alternated in one run. Not a test.

    git worktree add --detach /tmp/alight-old aacb61c && (cd /tmp/alight-old && python3 -m venv .venv \
        && .venv/bin/pip install -q -e .)
    .venv/bin/python benchmarks/bench_editor_vs.py /tmp/alight-old/.venv/bin/alight --rounds 4

Each round runs ``alight edit --benchmark`` (1280x720, the material ball, studio IBL, 3 lights,
the panel) under ``xvfb-run -a -s "-screen 0 1920x1080x24"`` once with this checkout's
``alight`` and once with the other (A B A B ...), so load from other work falls on both alike.
Each run prints the median frame time of each phase; this prints, per phase, the median and the
range of those medians over the rounds and the ratio other / this (above 1: this is faster).
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

PHASES = {
    "full": re.compile(r"^orbiting, full resolution: .*median ([\d.]+) ms"),
    "adaptive": re.compile(r"^orbiting, adaptive scale .*: \d+ frames, median ([\d.]+) ms"),
    "still": re.compile(r"^still view .*median ([\d.]+) ms"),
}
STAGES = re.compile(r"^full resolution, per stage .*: (.*)$")
# The adaptive phase holds 30 FPS by moving the resolution: its frame time alone says little, the
# scale it settled at says how sharp the moving view stayed.
SCALE = re.compile(r"^orbiting, adaptive scale \(target 30 FPS; scale median ([\d.]+)")


def run(alight: str, frames: int) -> tuple[dict[str, float], str]:
    with tempfile.TemporaryDirectory(prefix="alight-editor-bench-") as tmp:
        # Each run gets its own config and cache folders: neither sees the other's session or bakes.
        env = {**os.environ, "ALIGHT_CONFIG_DIR": tmp, "ALIGHT_CACHE_DIR": tmp}
        p = subprocess.run(["xvfb-run", "-a", "-s", "-screen 0 1920x1080x24", alight, "edit", "--benchmark",
                            "--frames", str(frames)], env=env, capture_output=True, text=True, timeout=1800)
    if p.returncode != 0:
        raise SystemExit(f"{alight} failed:\n{p.stderr[-2000:]}")
    found, stages = {}, ""
    for line in p.stdout.splitlines():
        for name, pattern in PHASES.items():
            m = pattern.match(line)
            if m:
                found[name] = float(m.group(1))
        m = STAGES.match(line)
        if m:
            stages = m.group(1)
        m = SCALE.match(line)
        if m:
            found["adaptive scale"] = float(m.group(1))
    return found, stages


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("other", help="the other build's alight executable (e.g. an old checkout's .venv/bin/alight)")
    parser.add_argument("--rounds", type=int, default=4)
    parser.add_argument("--frames", type=int, default=60, help="frames per phase and run (default: 60)")
    args = parser.parse_args()
    this = str(Path(sys.executable).with_name("alight"))
    results: dict[str, dict[str, list[float]]] = {"this": {}, "other": {}}
    with open("/proc/loadavg") as f:
        load_before = f.read().split()[:3]
    for i in range(args.rounds):
        for label, exe in (("this", this), ("other", args.other)):
            found, stages = run(exe, args.frames)
            for k, v in found.items():
                results[label].setdefault(k, []).append(v)
            print(f"round {i + 1} {label}: " + ", ".join(f"{k} {v:.2f}" if k == "adaptive scale" else f"{k} {v:.1f} ms"
                                                         for k, v in found.items())
                  + f"; stages: {stages}", flush=True)
    with open("/proc/loadavg") as f:
        load_after = f.read().split()[:3]
    print(f"\n{os.cpu_count()} cores, load average {'/'.join(load_before)} before, {'/'.join(load_after)} after; "
          f"{args.rounds} alternated rounds of {args.frames} frames per phase")
    a, b = results["this"].get("adaptive scale"), results["other"].get("adaptive scale")
    if a and b:
        print(f"the adaptive phase's scale: this {statistics.median(a):.2f} ({min(a):.2f}-{max(a):.2f}), "
              f"other {statistics.median(b):.2f} ({min(b):.2f}-{max(b):.2f}) (1: full resolution)")
    for phase in PHASES:
        a, b = results["this"].get(phase), results["other"].get(phase)
        if not a or not b:
            continue
        print(f"{phase:9s} this {statistics.median(a):7.1f} ms ({min(a):.1f}-{max(a):.1f})   "
              f"other {statistics.median(b):7.1f} ms ({min(b):.1f}-{max(b):.1f})   "
              f"other/this {statistics.median(b) / statistics.median(a):.2f}x")
    return 0


if __name__ == "__main__":
    sys.exit(main())

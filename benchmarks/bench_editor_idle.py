"""An idle editor's CPU: ``alight edit --new`` started as a user starts it (its interactive loop),
left alone with the pointer outside its window, and the editor process's CPU seconds
(/proc/PID/stat utime + stime, its children not counted) over a wait, after it settled.

Two code trees compared, alternated A B A B (the machine is shared: its load drifts): each is
the folder put on PYTHONPATH (a folder holding ``alight``, e.g. one made from an older commit
with ``git archive COMMIT app shaders presets | tar -x -C DIR`` and DIR/py/alight -> DIR/app).

    python benchmarks/bench_editor_idle.py --a /tmp/old_py --b /tmp/new_py [--seconds 20] [--rounds 2]

Needs a display (DISPLAY, e.g. Xvfb :63 -screen 0 1600x1000x24). Prints one line a run and a
Markdown table (for benchmarks/results/editor_idle.md).
"""

from __future__ import annotations

import argparse
import os
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "tests"))


def cpu_seconds(pid: int) -> float:
    fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def children_cpu(pid: int) -> float:
    total = 0.0
    for line in subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True, text=True).stdout.split():
        try:
            total += cpu_seconds(int(line))
        except (OSError, ValueError):
            pass
    return total


def one_run(pythonpath: str, seconds: float, settle_s: float, home: Path) -> tuple[float, float]:
    """(the editor's CPU fraction of one core over ``seconds``, its children's)."""
    from x_events import XTest

    env = dict(os.environ, PYTHONPATH=pythonpath, ALIGHT_CONFIG_DIR=str(home / "config"),
               ALIGHT_CACHE_DIR=str(home / "cache"), ALIGHT_DATA_DIR=str(home / "data"))
    proc = subprocess.Popen([sys.executable, "-m", "alight", "edit", "--new", "--size", "1280x720"], cwd=home,
                            env=env, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        pointer = XTest()
        pointer.move(1590, 990)   # outside the window (at the screen's corner without a WM)
        pointer.sync()
        time.sleep(settle_s)      # start-up: the bake, the warm-up children, the thumbnails
        c0, k0, t0 = cpu_seconds(proc.pid), children_cpu(proc.pid), time.monotonic()
        time.sleep(seconds)
        c1, k1, t1 = cpu_seconds(proc.pid), children_cpu(proc.pid), time.monotonic()
        if proc.poll() is not None:
            raise SystemExit(f"the editor ({pythonpath}) exited with {proc.returncode} during the run")
        return (c1 - c0) / (t1 - t0), (k1 - k0) / (t1 - t0)
    finally:
        proc.send_signal(signal.SIGTERM)
        try:
            proc.wait(timeout=30)
        except subprocess.TimeoutExpired:
            proc.kill()


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--a", required=True, help="PYTHONPATH of A (the baseline)")
    p.add_argument("--b", required=True, help="PYTHONPATH of B")
    p.add_argument("--seconds", type=float, default=20.0)
    p.add_argument("--settle", type=float, default=30.0, help="seconds after start before measuring")
    p.add_argument("--rounds", type=int, default=2)
    args = p.parse_args()
    results: dict[str, list[tuple[float, float]]] = {"A": [], "B": []}
    with tempfile.TemporaryDirectory(prefix="alight-idle-") as tmp:
        for r in range(args.rounds):
            for label, path in (("A", args.a), ("B", args.b)):
                home = Path(tmp) / f"{label}{r}"
                home.mkdir()
                load = os.getloadavg()[0]
                editor, children = one_run(path, args.seconds, args.settle, home)
                results[label].append((editor, children))
                print(f"round {r + 1} {label}: editor {100 * editor:.1f}% of a core, its children "
                      f"{100 * children:.1f}% (load average {load:.1f})", flush=True)
    print("\n| run | editor process CPU (% of a core) | its children |\n|---|---|---|")
    for label, path in (("A", args.a), ("B", args.b)):
        cells = ", ".join(f"{100 * e:.1f}" for e, _ in results[label])
        kids = ", ".join(f"{100 * k:.1f}" for _, k in results[label])
        print(f"| {label} ({path}) | {cells} | {kids} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())

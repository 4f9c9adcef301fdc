"""The editor's compare split against the plain view, alternated in one process. Not a test.

    xvfb-run -a -s "-screen 0 1920x1080x24" .venv/bin/python benchmarks/bench_editor_compare.py --rounds 5

An EditorWindow (own loop, the material ball, studio IBL, 3 lights, the panel) at 960x540; each
round times ``frames`` frames while the camera orbits (every frame redraws the view) with compare
off, then as many with compare on (A a snapshot of gold, B the live copper), so load from other
work falls on both alike. Prints the median frame time of each round and, over the rounds, the
median and range of each and of the ratio on / off. The reference half is not timed here: its
sum is reported by the panel (``CompareView.reference_seconds``).
"""

from __future__ import annotations

import argparse
import statistics
import time

from alight.exchange.presets import load_preset
from alight.frontends.editor.compare import CompareState
from alight.frontends.editor.state import EditorState
from alight.frontends.editor.window import EditorWindow


def orbit_frames(win: EditorWindow, frames: int) -> float:
    times = []
    for _ in range(frames):
        win.orbit.yaw_deg += 2.0
        t0 = time.perf_counter()
        win.frame()
        win.ctx.finish()
        times.append(time.perf_counter() - t0)
    return statistics.median(times) * 1000.0


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--frames", type=int, default=20)
    args = ap.parse_args()
    state = EditorState()
    state.material = state.saved_material = load_preset("copper")
    state.load_mesh("sphere")
    state.load_env("studio")
    win = EditorWindow(state, (960, 540))
    compare = CompareState(mode="material", a_material=load_preset("gold"), a_label="preset gold")
    try:
        win.finish_bake()
        for _ in range(5):
            win.frame()
        off, on = [], []
        for r in range(args.rounds):
            state.compare = CompareState()
            off.append(orbit_frames(win, args.frames))
            state.compare = compare
            on.append(orbit_frames(win, args.frames))
            print(f"round {r + 1}: off {off[-1]:.1f} ms, on {on[-1]:.1f} ms")
        ratios = [b / a for a, b in zip(off, on)]
        for name, xs in (("off", off), ("on", on), ("on / off", ratios)):
            unit = "" if name == "on / off" else " ms"
            print(f"{name}: median {statistics.median(xs):.2f}{unit} (range {min(xs):.2f}-{max(xs):.2f})")
    finally:
        win.close()


if __name__ == "__main__":
    main()

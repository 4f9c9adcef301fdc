"""One frame of the material ball without layers, counted in CPU instructions by callgrind, in
this checkout and in another checkout (its own virtualenv): "a material without layers costs what
it costs on main", with everything that differs between the two (Python side, passes,
shaders) included. Prints the counts; not a test.

    git worktree add /tmp/alight_main main
    (cd /tmp/alight_main && python3 -m venv .venv && .venv/bin/pip install -e .)
    .venv/bin/python benchmarks/bench_frame_vs_checkout.py --other /tmp/alight_main/.venv/bin/python

Each process draws the ball (the built-in sphere, a red dielectric at roughness 0.45, 3 point
lights, royal_esplanade_1k baked at `low`, no AA) once uncounted (compiles and allocates), then
``--frames`` frames with callgrind's instrumentation switched on (``callgrind_control -i on``;
the process starts with it off, which also makes the uncounted start faster). llvmpipe runs on
one thread; each side gets its own warmed Mesa shader cache and LUT cache. The sides alternate
(this, other, this, other, ...).
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import tempfile
from pathlib import Path

ENV = Path(__file__).resolve().parents[2] / "shared" / "data" / "env" / "royal_esplanade_1k.hdr"


def child(frames: int, width: int, height: int, counted: bool) -> None:
    from alight.core.material import Material
    from alight.core.mesh import sphere
    from alight.core.scene import Light, Scene
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    r = ForwardRenderer()
    maps = r.bake(load_environment(str(ENV)), "low")
    lights = [Light(vector=(2.0, 3.0, 4.0)), Light(vector=(-3.0, 1.0, 2.0), color=(0.6, 0.7, 1.0)),
              Light(vector=(0.0, -2.0, 3.0), intensity=4.0)]
    scene = Scene(mesh=sphere(), material=Material(base_color=(0.55, 0.12, 0.08), roughness=0.45), lights=lights)

    def frame():
        r.render(scene, maps, width, height, aa="none", read_linear=False, read_srgb=False)
        r.ctx.finish()

    frame()
    if counted:
        subprocess.run(["callgrind_control", "-i", "on", str(os.getpid())], check=True, capture_output=True)
    for _ in range(frames):
        frame()
    if counted:
        subprocess.run(["callgrind_control", "-i", "off", str(os.getpid())], check=True, capture_output=True)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--other", required=True, help="the other checkout's Python (its virtualenv's bin/python)")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--frames", type=int, default=2)
    ap.add_argument("--size", default="640x360")
    ap.add_argument("--child", action="store_true", help=argparse.SUPPRESS)
    ap.add_argument("--counted", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    width, height = (int(x) for x in args.size.split("x"))
    if args.child:
        child(args.frames, width, height, args.counted)
        return 0
    sides = {"this checkout": sys.executable, "other": args.other}
    counts = {side: [] for side in sides}
    with tempfile.TemporaryDirectory() as tmp:
        envs = {}
        for k, (side, python) in enumerate(sides.items()):
            envs[side] = dict(os.environ, ALIGHT_CACHE_DIR=f"{tmp}/cache{k}", MESA_SHADER_CACHE_DIR=f"{tmp}/mesa{k}",
                              LP_NUM_THREADS="1", PYTHONHASHSEED="0")
            # warm both caches, uncounted
            subprocess.run([python, __file__, "--other", "-", "--child", "--frames", "1", "--size", args.size],
                           env=envs[side], check=True)
        for _ in range(args.rounds):
            for side, python in sides.items():
                run = subprocess.run(["valgrind", "--tool=callgrind", "--instr-atstart=no", "--callgrind-out-file=/dev/null",
                                      python, __file__, "--other", "-", "--child", "--counted",
                                      "--frames", str(args.frames), "--size", args.size],
                                     env=envs[side], capture_output=True, text=True)
                found = re.search(r"Collected\s*:\s*(\d+)", run.stderr)
                if run.returncode != 0 or not found:
                    raise SystemExit(f"{side}: callgrind run failed:\n{run.stderr[-1500:]}")
                counts[side].append(int(found.group(1)) / args.frames)
                print(f"  {side:14s} {counts[side][-1] / 1e6:9.2f} M instructions per frame", flush=True)
    a, b = (min(c) for c in counts.values())
    print(f"\nmaterial ball without layers, {args.size}, {args.frames} counted frames per process; "
          f"this checkout / other: {a / b:.4f} (least count of each side)")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

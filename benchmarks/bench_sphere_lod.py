"""The built-in ball at the tessellation its size needs (alight.core.sphere_lod) against the ball
drawn at its full 128 x 64 as before, alternated in one run. Not a test.

    .venv/bin/python benchmarks/bench_sphere_lod.py                  # CPU time per frame, alternated
    .venv/bin/python benchmarks/bench_sphere_lod.py --instructions   # callgrind: load-independent

Scenes: gold r = 0.3 on royal_esplanade_1k (low bake), 3 point lights, the default camera:
- ``editor``: the editor's scene view at full resolution (860 x 720, no anti-aliasing, sRGB
  only: the fused display path ``alight edit`` draws);
- ``steady``: the peer benchmark's frame (1920 x 1080, 4x MSAA, sRGB read back).

"before" draws the same Mesh with ``lod_sphere`` cleared: its own 128 x 64 facets, normals
interpolated over them (the renderer before the levels). CPU time is that of the process with
all its threads (llvmpipe's), ``ctx.finish()`` inside the timed span, so waiting for a core on a
loaded machine does not count; callgrind counts instructions with llvmpipe on one thread and
Mesa's shader cache off (1 and 1 + N frames in fresh processes; the difference over N).
"""

from __future__ import annotations

import argparse
import os
import re
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ENV = REPO.parent / "shared" / "data" / "env" / "royal_esplanade_1k.hdr"
SCENES = {"editor": (860, 720, "none", False), "steady": (1920, 1080, "msaa", True)}


def _setup(level: str):
    from dataclasses import replace

    from alight.core.mesh import sphere
    from alight.core.scene import Light, Scene
    from alight.exchange.presets import load_preset
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    r = ForwardRenderer()   # the bake from the disk cache: callgrind would spend minutes re-baking
    r.sphere_impostor = False   # the levels themselves (the impostor: bench_impostor.py)
    maps = r.bake(load_environment(str(ENV)), "low")
    mesh = sphere()
    if level == "before":
        mesh.lod_sphere = None
    scene = Scene(mesh=mesh, material=replace(load_preset("gold"), roughness=0.3),
                  lights=[Light(vector=(2.0, 3.0, 4.0)), Light(vector=(-3.0, 1.0, 2.0), color=(0.6, 0.7, 1.0)),
                          Light(vector=(0.0, -2.0, 3.0), intensity=4.0)])
    return r, maps, scene


def _frame(r, maps, scene, name: str) -> None:
    w, h, aa, _ = SCENES[name]
    r.render(scene, maps, w, h, aa=aa, read_linear=False, read_srgb=True)
    r.ctx.finish()


def child(level: str, name: str, frames: int) -> None:
    r, maps, scene = _setup(level)
    for _ in range(frames):
        _frame(r, maps, scene, name)


def instructions(names: list[str], frames: int) -> None:
    env = dict(os.environ, LP_NUM_THREADS="0", MESA_SHADER_CACHE_DISABLE="true")
    for name in names:
        per_frame = {}
        for level in ("before", "levels"):
            counts = []
            for n in (1, 1 + frames):
                run = subprocess.run(["valgrind", "--tool=callgrind", "--callgrind-out-file=/dev/null", sys.executable,
                                      __file__, "--child", level, name, "--frames", str(n)],
                                     capture_output=True, text=True, env=env, cwd=REPO)
                found = re.search(r"Collected\s*:\s*(\d+)", run.stderr)
                if run.returncode != 0 or not found:
                    raise SystemExit(f"callgrind run failed ({level}, {name}): {run.stderr[-500:]}")
                counts.append(int(found.group(1)))
            per_frame[level] = (counts[1] - counts[0]) / frames
        print(f"{name:7s} before {per_frame['before'] / 1e6:8.1f} M  levels {per_frame['levels'] / 1e6:8.1f} M "
              f"instructions per frame  levels/before {per_frame['levels'] / per_frame['before']:.3f}", flush=True)


def timing(names: list[str], rounds: int, frames: int) -> None:
    with open("/proc/loadavg") as f:
        load_before = f.read().split()[:3]
    setups = {level: _setup(level) for level in ("before", "levels")}
    for name in names:
        cpu = {"before": [], "levels": []}
        segments = None
        for level, (r, maps, scene) in setups.items():
            r.ctx.__enter__()
            _frame(r, maps, scene, name)    # compile and allocate outside the timing
            if level == "levels":
                segments = r.last_sphere_segments
        for _ in range(rounds):
            for level, (r, maps, scene) in setups.items():    # A B A B ...
                r.ctx.__enter__()
                c = time.process_time()
                for _ in range(frames):
                    _frame(r, maps, scene, name)
                cpu[level].append((time.process_time() - c) / frames)
        m = {k: statistics.median(v) for k, v in cpu.items()}
        w, h, aa, _ = SCENES[name]
        print(f"{name} ({w}x{h}, aa={aa}; levels drew {segments} segments): "
              + "   ".join(f"{k} {m[k] * 1000:.1f} ms CPU ({min(v) * 1000:.1f}-{max(v) * 1000:.1f})" for k, v in cpu.items())
              + f"   levels/before {m['levels'] / m['before']:.2f}", flush=True)
    with open("/proc/loadavg") as f:
        load_after = f.read().split()[:3]
    print(f"{os.cpu_count()} cores, load average {'/'.join(load_before)} before, {'/'.join(load_after)} after; "
          f"{rounds} alternated rounds of {frames} frames")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default="editor,steady")
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--frames", type=int, default=3)
    parser.add_argument("--instructions", action="store_true", help="callgrind instruction counts instead of time")
    parser.add_argument("--child", nargs=2, metavar=("LEVEL", "SCENE"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child:
        child(args.child[0], args.child[1], args.frames)
        return 0
    names = args.scenes.split(",")
    # A cache folder of its own, shared by the callgrind children (they load the bake its first
    # process made instead of baking under valgrind); the user's cache is never touched.
    with tempfile.TemporaryDirectory(prefix="alight-bench-lod-") as cache:
        os.environ["ALIGHT_CACHE_DIR"] = cache
        if args.instructions:
            _setup("levels")    # bake once, outside valgrind
            instructions(names, max(1, args.frames - 1))
        else:
            timing(names, args.rounds, args.frames)
    return 0


if __name__ == "__main__":
    sys.exit(main())

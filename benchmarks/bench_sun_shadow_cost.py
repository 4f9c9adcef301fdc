"""DamagedHelmet "with everything on" against its plain frame, and the same frames drawn with
another checkout's shaders (main's, say) side by side; not a test.

    git archive f147a40 shaders | tar -x -C /tmp/main_tree      # the other side's shaders/
    .venv/bin/python benchmarks/bench_sun_shadow_cost.py --other main=/tmp/main_tree/shaders
        [--size 512] [--rounds 7] [--env quarry_01_1k.hdr] [--save /tmp/frames]

DamagedHelmet in its own maps, the view of bench_occlusion.py, under quarry_01_1k at `medium`
(alight takes its sun out of the map and shadows it: PCSS), 4x MSAA, read back as sRGB (what a PNG needs; also waits for the frame). Conditions:

- ``plain``: occlusion off, shadows off;
- ``on``: occlusion on (the per-vertex bake) and shadows on (the sun's PCSS), the maps drawn once
  and reused;

each with the forward pass and with the visibility buffer (``mesh_shading``), for each shader
folder (this checkout's, then each ``--other NAME=DIR``: a renderer of its own on the same GL
context, whose ShaderLibrary reads that folder; the Python side is this checkout's, so this
compares shaders only). Every run of every side is alternated in one process, one frame each,
round after round (A B C ... A B C ...); CPU time of the process (llvmpipe's threads included:
on a shared machine wall time swings with other jobs far more than the work itself), medians
and [min-max]. Ratios are of medians: on / plain of the same side and pass (and on with the
visibility buffer / plain forward), and each other side's median / this checkout's.

``--save DIR`` writes each side's linear frames (.npy) after timing, for picture comparisons.
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

CONDITIONS = {"plain": ("off", "off"), "on": ("on", "on")}     # name: (occlusion, shadows)
PASSES = ("forward", "vbuffer")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--rounds", type=int, default=7)
    ap.add_argument("--env", default="quarry_01_1k.hdr")
    ap.add_argument("--other", action="append", default=[], metavar="NAME=DIR",
                    help="another shaders/ folder to draw the same frames with (repeatable)")
    ap.add_argument("--save", default=None, help="write each side's linear frames here (.npy)")
    args = ap.parse_args(argv)
    os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))

    import numpy as np
    from bench_occlusion import ENV_DIR, VIEWS, camera_for, load_scene_mesh

    from alight.core.gpu import ShaderLibrary
    from alight.core.scene import Scene
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    size = args.size
    mesh = load_scene_mesh("helmet", Path(tempfile.mkdtemp()))
    env = load_environment(str(ENV_DIR / args.env))
    first = ForwardRenderer(bake_cache=None)
    sides = {"this": first}
    for item in args.other:
        name, _, folder = item.partition("=")
        sides[name] = ForwardRenderer(ctx=first.ctx, shaders=ShaderLibrary(first.ctx, Path(folder)), bake_cache=None)
    maps = {name: r.bake(env, "medium") for name, r in sides.items()}
    camera = camera_for(mesh, (size, size), VIEWS["helmet"])
    scenes = {name: Scene(mesh=mesh, camera=camera, occlusion=occ, shadows=sh) for name, (occ, sh) in CONDITIONS.items()}
    runs = [(side, mode, cond) for side in sides for mode in PASSES for cond in CONDITIONS]

    def frame(run):
        side, mode, cond = run
        r = sides[side]
        r.mesh_shading = mode
        out = r.render(scenes[cond], maps[side], size, size, read_linear=args.save is not None, read_srgb=True)
        r.ctx.finish()
        return out

    for run in runs:                     # programs, bakes, shadow maps: out of the timing
        for _ in range(2):
            frame(run)
    cpu = {run: [] for run in runs}
    for k in range(args.rounds):
        for run in runs:
            c0 = time.process_time()
            frame(run)
            cpu[run].append((time.process_time() - c0) * 1e3)
        print(f"round {k + 1}: " + ", ".join(f"{'/'.join(run)} {cpu[run][-1]:.0f}" for run in runs), flush=True)

    med = {run: statistics.median(v) for run, v in cpu.items()}
    print(f"\nDamagedHelmet, {size} px, {args.env} (its sun: PCSS), 4x MSAA, {args.rounds} rounds, every run "
          "alternated in one process; CPU ms per frame, median [min-max]\n")
    print("| shaders | pass | plain | on (occlusion + sun shadows) | on / plain | on / plain forward |")
    print("|---|---|---|---|---|---|")
    for side in sides:
        for mode in PASSES:
            p, o = cpu[(side, mode, "plain")], cpu[(side, mode, "on")]
            print(f"| {side} | {mode} | {med[(side, mode, 'plain')]:.1f} [{min(p):.1f}-{max(p):.1f}] | "
                  f"{med[(side, mode, 'on')]:.1f} [{min(o):.1f}-{max(o):.1f}] | "
                  f"{med[(side, mode, 'on')] / med[(side, mode, 'plain')]:.2f} | "
                  f"{med[(side, mode, 'on')] / med[(side, 'forward', 'plain')]:.2f} |")
    for side in list(sides)[1:]:
        for mode in PASSES:
            for cond in CONDITIONS:
                # per round, so the ratio's range shows the noise
                ratios = [a / b for a, b in zip(cpu[(side, mode, cond)], cpu[("this", mode, cond)])]
                print(f"{side} / this, {mode}, {cond}: {med[(side, mode, cond)] / med[('this', mode, cond)]:.2f} "
                      f"(per round {min(ratios):.2f}-{max(ratios):.2f})")
    if args.save:
        out = Path(args.save)
        out.mkdir(parents=True, exist_ok=True)
        for run in runs:
            np.save(out / f"{'_'.join(run)}.npy", frame(run).linear)
    for r in reversed(list(sides.values())):
        r.release()
    return 0


if __name__ == "__main__":
    sys.exit(main())

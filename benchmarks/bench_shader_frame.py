"""A steady frame with this tree's shaders against another ref's shaders, the same Python: two
renderers in one process (each its own context), their frames interleaved in batches, so the
load of a shared machine falls on both alike. For shader-only changes, such as a define made a
uniform (the renderer binds what both trees' shaders read; a uniform one of them lacks is
skipped). Asserts nothing.

    .venv/bin/python benchmarks/bench_shader_frame.py --ref REF [--batches 12] [--frames 5]

Per scene (the material ball, DamagedHelmet): ``draw_display`` (the editor's path: no
anti-aliasing) at 1280x720 plus ``finish()``, studio IBL, three lights as benchmarks/bench_gltf.py;
each batch times ``--frames`` frames of one renderer then of the other (the order alternating),
after warm-up frames. Prints each batch's median frame and the ratio this / ref.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
HELMET = REPO.parent / "shared" / "data" / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"


def median_display_frame(r, scene, maps, targets, frames: int) -> float:
    """Median seconds of ``frames`` of the editor's view pass (``draw_display`` then
    ``ctx.finish()``), the renderer current (bench_mesh_flags.py times with it too)."""
    times = []
    for _ in range(frames):
        t = time.perf_counter()
        r.draw_display(scene, maps, targets)
        r.ctx.finish()
        times.append(time.perf_counter() - t)
    return statistics.median(times)


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--ref", required=True)
    ap.add_argument("--batches", type=int, default=12)
    ap.add_argument("--frames", type=int, default=5)
    args = ap.parse_args()
    from alight.core.gpu import ShaderLibrary
    from alight.core.scene import Display, Light, Scene
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    with tempfile.TemporaryDirectory(prefix="alight-shaders-") as tmp:
        archive = subprocess.run(["git", "-C", str(REPO), "archive", args.ref, "shaders"], check=True,
                                 capture_output=True).stdout
        subprocess.run(["tar", "-x", "-C", tmp], input=archive, check=True)
        mine = ForwardRenderer()
        ref = ForwardRenderer()
        ref.use_shaders(ShaderLibrary(ref.ctx, root=Path(tmp) / "shaders"))
        renderers = {"this tree": mine, args.ref: ref}
        env = load_environment("studio")
        lights = [Light("point", (2.0, 3.0, 4.0), intensity=30.0), Light("directional", (-1.0, -1.0, -1.0), intensity=2.0),
                  Light("point", (-3.0, 1.0, 2.0), intensity=10.0)]
        for name, mesh in (("ball", load_mesh("sphere")), ("helmet", load_mesh(str(HELMET)))):
            scene = Scene(mesh=mesh, lights=lights, display=Display())
            state = {}
            for label, r in renderers.items():
                r.make_current()   # (each renderer draws in its own context)
                maps = r.bake(env, "medium")
                targets = r._targets_for(1280, 720, "none", 0)
                for _ in range(3):
                    r.draw_display(scene, maps, targets)
                r.ctx.finish()
                state[label] = (r, maps, targets)
            times: dict[str, list[float]] = {label: [] for label in renderers}
            ratios = []
            for b in range(args.batches):
                order = list(renderers) if b % 2 == 0 else list(reversed(renderers))
                batch = {}
                for label in order:
                    r, maps, targets = state[label]
                    r.make_current()
                    batch[label] = median_display_frame(r, scene, maps, targets, args.frames)
                    times[label].append(batch[label])
                ratios.append(batch["this tree"] / batch[args.ref])
                print(f"{name} batch {b + 1}: this tree {batch['this tree'] * 1000:.1f} ms, "
                      f"{args.ref} {batch[args.ref] * 1000:.1f} ms, ratio {ratios[-1]:.3f}", flush=True)
            line = ", ".join(f"{label} {statistics.median(v) * 1000:.1f} ms ({min(v) * 1000:.1f}-{max(v) * 1000:.1f})"
                             for label, v in times.items())
            print(f"{name}: {line}; this / {args.ref} {statistics.median(ratios):.3f} "
                  f"({min(ratios):.3f}-{max(ratios):.3f})", flush=True)
    print(f"load average at the end: {' '.join(f'{x:.1f}' for x in os.getloadavg())}")


if __name__ == "__main__":
    sys.exit(main())

"""The steady-frame cost of HAS_UV1 / HAS_TEXTURE_TRANSFORM being the mesh's (every textured part
of a mesh where some map reads TEXCOORD_1 or has a transform compiles them in;
gpu_mesh.mark_mesh_uv_features) against each part's own (only the parts whose maps use them),
in one process: the flags are toggled on the uploaded parts between interleaved batches (both
programs kept in the library). Asserts nothing.

    .venv/bin/python benchmarks/bench_mesh_flags.py [FILE] [--batches 12] [--frames 5]

FILE: default the multi scene of benchmarks/bench_compile.py (``multi_scene``), written to a
temporary folder. ``draw_display`` at 1280x720, no AA, studio IBL, medium bake.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))


from bench_shader_frame import median_display_frame  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("file", nargs="?", default=None)
    ap.add_argument("--batches", type=int, default=12)
    ap.add_argument("--frames", type=int, default=5)
    args = ap.parse_args()
    from alight.core.scene import Display, Scene
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    with tempfile.TemporaryDirectory(prefix="alight-flags-") as tmp:
        path = args.file
        if path is None:
            from bench_compile import multi_scene
            path = str(multi_scene(Path(tmp) / "multi.glb"))
        mesh = load_mesh(path)
    r = ForwardRenderer()
    maps = r.bake(load_environment("studio"), "medium")
    scene = Scene(mesh=mesh, display=Display())
    targets = r._targets_for(1280, 720, "none", 0)
    parts = r.meshes.parts(mesh)
    marks = {id(gp): (gp.mesh_reads_uv1, gp.mesh_transforms) for gp in parts}
    own = {id(gp): (gp.has_uv1 and any(i.tex_coord == 1 for i in gp.infos.values()),
                    any(i.transform is not None for i in gp.infos.values())) for gp in parts}

    def use(flags: dict) -> None:
        for gp in parts:
            gp.mesh_reads_uv1, gp.mesh_transforms = flags[id(gp)]

    modes = {"mesh": marks, "part": own}
    for flags in modes.values():
        use(flags)
        for _ in range(3):
            r.draw_display(scene, maps, targets)
    times = {name: [] for name in modes}
    ratios = []
    for b in range(args.batches):
        batch = {}
        for name in (list(modes) if b % 2 == 0 else list(reversed(modes))):
            use(modes[name])
            batch[name] = median_display_frame(r, scene, maps, targets, args.frames)
            times[name].append(batch[name])
        ratios.append(batch["mesh"] / batch["part"])
        print(f"batch {b + 1}: per mesh {batch['mesh'] * 1000:.1f} ms, per part {batch['part'] * 1000:.1f} ms, "
              f"ratio {ratios[-1]:.3f}", flush=True)
    print(", ".join(f"per {n} {statistics.median(v) * 1000:.1f} ms ({min(v) * 1000:.1f}-{max(v) * 1000:.1f})"
                    for n, v in times.items()) +
          f"; per mesh / per part {statistics.median(ratios):.3f} ({min(ratios):.3f}-{max(ratios):.3f})")


if __name__ == "__main__":
    main()

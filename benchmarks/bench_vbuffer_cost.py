"""Where the visibility buffer pays as the pixel gets heavier: DamagedHelmet's frame, forward
against vbuffer, at several sizes (so several estimated pixels per triangle), with the plain
shading, with occlusion, and with occlusion and a sun's soft shadows (quarry_01: PCSS); in its
own five maps or in a grey untextured material. All conditions of one size are alternated in
one process (A B C ...), this process's CPU time (llvmpipe's threads included), medians and
ranges; the ratio is vbuffer / forward of the same condition. It calibrates
alight.render.vbuffer.auto_threshold.

    .venv/bin/python benchmarks/bench_vbuffer_cost.py [--sizes 384 512 768 1024] [--rounds 5]
        [--material file|grey] [--env quarry_01_1k.hdr]
"""

from __future__ import annotations

import argparse
import dataclasses
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))

CONDITIONS = {            # name: (occlusion, shadows)
    "plain": ("off", "off"),
    "occlusion": ("on", "off"),
    "occlusion + sun shadows": ("on", "on"),
}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--sizes", type=int, nargs="+", default=[384, 512, 768, 1024])
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--material", choices=("file", "grey"), default="file")
    ap.add_argument("--env", default="quarry_01_1k.hdr")
    args = ap.parse_args(argv)
    os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))

    from bench_occlusion import ENV_DIR, GREY, VIEWS, camera_for, load_scene_mesh

    from alight.core.material import Material
    from alight.core.scene import Scene
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer
    from alight.render.vbuffer import auto_threshold, pixels_per_triangle

    mesh = load_scene_mesh("helmet", Path(tempfile.mkdtemp()))
    r = ForwardRenderer(bake_cache=None)
    maps = r.bake(load_environment(str(ENV_DIR / args.env)), "medium")
    print(f"DamagedHelmet, material {args.material}, {args.env}, {args.rounds} rounds alternated; "
          f"CPU ms medians [ranges]; ratio vbuffer / forward")
    print("| size | est. pixels/triangle | condition | forward | vbuffer | ratio | auto's threshold | auto picks |")
    print("|---|---|---|---|---|---|---|---|")
    for size in args.sizes:
        scenes = {}
        for name, (occlusion, shadows) in CONDITIONS.items():
            scene = Scene(mesh=mesh, camera=camera_for(mesh, (size, size), VIEWS["helmet"]), occlusion=occlusion,
                          shadows=shadows, use_file_materials=args.material == "file")
            if args.material == "grey":
                scene = dataclasses.replace(scene, material=Material(**GREY))
            scenes[name] = scene
        runs = [(name, mode) for name in scenes for mode in ("forward", "vbuffer")]
        for name, mode in runs:            # bakes, programs, shadow maps: out of the timing
            r.mesh_shading = mode
            for _ in range(2):
                r.render(scenes[name], maps, size, size)
        cpu = {run: [] for run in runs}
        for _ in range(args.rounds):
            for run in runs:
                r.mesh_shading = run[1]
                c0 = time.process_time()
                r.render(scenes[run[0]], maps, size, size)
                cpu[run].append(time.process_time() - c0)
        density = pixels_per_triangle(r, scenes["plain"], scenes["plain"].camera.view_projection(1.0), (size, size))
        for name, scene in scenes.items():
            f, v = np.array(cpu[(name, "forward")]) * 1e3, np.array(cpu[(name, "vbuffer")]) * 1e3
            threshold, _ = auto_threshold(r, scene, maps)
            print(f"| {size} | {density:.1f} | {name} | {np.median(f):.1f} [{f.min():.1f}-{f.max():.1f}] | "
                  f"{np.median(v):.1f} [{v.min():.1f}-{v.max():.1f}] | {np.median(v) / np.median(f):.2f} | "
                  f"{threshold:g} | {'vbuffer' if density < threshold else 'forward'} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

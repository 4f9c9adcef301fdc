"""Render time of glTF files against their twins: textures tiled x1000 (large UV derivatives)
against x1, and compressed files (Draco, meshopt, KTX2) against their uncompressed sources.
Prints medians of repeats, after one warm-up each; not a test.

    python benchmarks/bench_gltf_sampling.py [--size 512] [--repeats 5] [--aa msaa]

The bake and the shader compilation are outside the timed part: the figure is the frame
(renderer.render), the part that large UV derivatives made 37x slower under MSAA.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
CASES = REPO.parent / "shared" / "data" / "cases" / "with_controls"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--repeats", type=int, default=5)
    ap.add_argument("--aa", default="msaa")
    ap.add_argument("files", nargs="*", help="pairs FILE TWIN (default: uv_tiling_x1000 against x1)")
    args = ap.parse_args()
    from alight.core.scene import Camera, Display, Light, Scene
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    files = args.files or [str(CASES / "uv_tiling_x1000.glb"), str(CASES / "uv_tiling_x1.glb")]
    r = ForwardRenderer()
    maps = r.bake(load_environment("studio"), "low")
    camera = Camera(position=(0.0, 0.0, 4.0), target=(0.0, 0.0, 0.0), fov_y_deg=40.0, near=0.1, far=20.0)
    lights = [Light(kind="directional", vector=(-0.4, -0.5, -1.0), intensity=2.0)]
    scenes, runs, loads = {}, {}, {}
    for path in files:
        t = time.perf_counter()
        mesh = load_mesh(path)
        loads[path] = time.perf_counter() - t
        scenes[path] = Scene(mesh=mesh, camera=camera, lights=lights, display=Display())
        r.render(scenes[path], maps, args.size, args.size, aa=args.aa)   # warm-up: compile, upload
        runs[path] = []
    for _ in range(args.repeats):   # interleaved, so the shared machine's load falls on both alike
        for path in files:
            t = time.perf_counter()
            r.render(scenes[path], maps, args.size, args.size, aa=args.aa)
            runs[path].append(time.perf_counter() - t)
    times = {path: statistics.median(runs[path]) for path in files}
    for path in files:
        print(f"{Path(path).name}: load {loads[path]:.3f} s, frame {times[path]:.3f} s "
              f"(min {min(runs[path]):.3f}, max {max(runs[path]):.3f}; {args.size}px, aa {args.aa})")
    for a, b in zip(files[::2], files[1::2]):
        print(f"{Path(a).name} / {Path(b).name}: {times[a] / times[b]:.2f}x")


if __name__ == "__main__":
    main()

"""A normal map's upload with its spread in A: the numpy twin's levels written (the upload before
the spread moved to the GPU) against the GPU pass (gpu_mesh.upload_normal_map), per 2048x2048 map,
and DamagedHelmet's cold render with each. Prints the figures; asserts nothing
(results/normal_spread.md).

    PYTHONPATH=... .venv/bin/python benchmarks/bench_normal_spread.py [--rounds 7] [--renders 5] [--size 512]

Per map (DamagedHelmet's 2048x2048 normal map, scale 1): ``cpu`` = normal_map_levels (numpy) then
each level written (level_texture, write_rgba8); ``gpu`` = upload_normal_map (level 0 with A = 0,
GL's generate_mipmap, alight.render.normal_spread_pass); ``plain`` = upload_image (GL's mips, no
spread: the floor). Each timed to ctx.finish(), the three alternated in every round; wall time
and the process's CPU time (every thread: llvmpipe's too). Then ``alight render`` of the helmet in
a fresh process per run, the cold frame, with the upload as before (``cpu``, patched in) and as
now, alternated, after one unmeasured run of each (shader and bake caches warm in a temporary
ALIGHT_CACHE_DIR); wall and the child's CPU time. The last two pictures are compared.
"""

from __future__ import annotations

import argparse
import os
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent.parent.parent / "shared" / "data"
HELMET = DATA / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
HERE = Path(__file__).resolve().parent


def cpu_upload(ctx, shaders, image, scale: float, mipmaps: bool = True):
    """The upload before the GPU pass: the numpy twin's levels, each written (``shaders``:
    upload_normal_map's, unused: no pass runs)."""
    from alight.core.gpu import write_rgba8
    from alight.render.gpu_mesh import level_texture, upload_image
    from alight.render.normal_spread import normal_map_levels, without_spread

    levels = normal_map_levels(image, scale, mipmaps)
    if levels is None:
        return upload_image(ctx, without_spread(image), False, mipmaps)
    h, w = levels[0].shape[:2]
    tex = level_texture(ctx, (w, h), len(levels), False)
    for n, level in enumerate(levels):
        write_rgba8(ctx, tex, n, 0, level)
    return tex


# `alight` with the upload before the GPU pass patched in.
CPU_ALIGHT = (f"import sys; sys.path.insert(0, {str(HERE)!r}); import bench_normal_spread as b; "
              "import alight.render.gpu_mesh as g; g.upload_normal_map = b.cpu_upload; "
              "from alight.frontends.cli import main; sys.exit(main())")


def spread(values: list[float]) -> str:
    return f"{statistics.median(values):7.1f} ({min(values):.1f}-{max(values):.1f})"


def per_map(rounds: int) -> None:
    from alight.core.gpu import ShaderLibrary, create_headless_context
    from alight.exchange.meshes import load_mesh
    from alight.render.gpu_mesh import upload_image, upload_normal_map

    ctx = create_headless_context()
    shaders = ShaderLibrary(ctx)
    image = load_mesh(str(HELMET)).parts[0].material.textures()["normal"].image
    ways = {"cpu": lambda: cpu_upload(ctx, shaders, image, 1.0),
            "gpu": lambda: upload_normal_map(ctx, shaders, image, 1.0),
            "plain": lambda: upload_image(ctx, image, False)}
    for way in ways.values():   # the pass compiled, the driver's first uses behind us
        way().release()
        ctx.finish()
    wall = {k: [] for k in ways}
    cpu = {k: [] for k in ways}
    for _ in range(rounds):
        for name, way in ways.items():
            w0, c0 = time.perf_counter(), time.process_time()
            tex = way()
            ctx.finish()
            wall[name].append(1e3 * (time.perf_counter() - w0))
            cpu[name].append(1e3 * (time.process_time() - c0))
            tex.release()
    print(f"per {image.shape[1]}x{image.shape[0]} map, {rounds} rounds alternated: median (min-max) ms")
    print(f"{'way':6} {'wall':>20} {'CPU (all threads)':>22}")
    for name in ways:
        print(f"{name:6} {spread(wall[name]):>20} {spread(cpu[name]):>22}")
    ratio_wall = [g / c for g, c in zip(wall["gpu"], wall["cpu"])]
    ratio_cpu = [g / c for g, c in zip(cpu["gpu"], cpu["cpu"])]
    print(f"gpu / cpu per round: wall {statistics.median(ratio_wall):.2f} ({min(ratio_wall):.2f}-{max(ratio_wall):.2f}), "
          f"CPU {statistics.median(ratio_cpu):.2f} ({min(ratio_cpu):.2f}-{max(ratio_cpu):.2f})")
    shaders.reload()
    ctx.release()


def cold_renders(runs: int, size: int) -> None:
    folder = Path(tempfile.mkdtemp(prefix="bench_normal_spread_"))
    env = dict(os.environ, ALIGHT_CACHE_DIR=str(folder / "cache"))
    ways = {"before (cpu)": ["-c", CPU_ALIGHT], "now (gpu)": ["-m", "alight"]}
    wall = {k: [] for k in ways}
    cpu = {k: [] for k in ways}
    outs = {}
    for n in range(runs + 1):
        for name, alight in ways.items():
            out = folder / f"{name.split()[0]}.png"
            c0 = resource.getrusage(resource.RUSAGE_CHILDREN)
            w0 = time.perf_counter()
            subprocess.run([sys.executable, *alight, "render", "--mesh", str(HELMET), "--size", str(size),
                            "--out", str(out)], check=True, stdout=subprocess.DEVNULL, env=env)
            w1 = time.perf_counter()
            c1 = resource.getrusage(resource.RUSAGE_CHILDREN)
            outs[name] = out
            if n:   # the first run of each fills the caches
                wall[name].append(w1 - w0)
                cpu[name].append(c1.ru_utime + c1.ru_stime - c0.ru_utime - c0.ru_stime)
    print(f"\nDamagedHelmet cold render (alight render --size {size}, a process each), {runs} runs alternated: "
          "median (min-max) s")
    for name in ways:
        print(f"{name:13} wall {statistics.median(wall[name]):.2f} ({min(wall[name]):.2f}-{max(wall[name]):.2f})  "
              f"CPU {statistics.median(cpu[name]):.2f} ({min(cpu[name]):.2f}-{max(cpu[name]):.2f})")
    ratio = [b / a for a, b in zip(wall["before (cpu)"], wall["now (gpu)"])]
    print(f"now / before per round: wall {statistics.median(ratio):.2f} ({min(ratio):.2f}-{max(ratio):.2f})")
    import imageio.v3 as iio

    a, b = (iio.imread(outs[k]).astype(int) for k in ways)
    print(f"pictures: max |before - now| {np.abs(a - b).max()} of 255, pixels differing {(a != b).any(axis=-1).sum()}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=7, help="per-map rounds (each times all three ways)")
    parser.add_argument("--renders", type=int, default=5, help="cold renders of each way (after one unmeasured)")
    parser.add_argument("--size", type=int, default=512, help="the cold render's size")
    args = parser.parse_args()
    per_map(args.rounds)
    if args.renders:
        cold_renders(args.renders, args.size)


if __name__ == "__main__":
    main()

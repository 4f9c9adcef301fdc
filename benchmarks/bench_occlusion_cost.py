"""What --occlusion costs a frame: DamagedHelmet (the grey material of bench_occlusion.py), 256x256,
quarry_01 (a map with a sun: its shadow map and the bake's sun pass both at work), the medium
bake; frames alternated in one run: occlusion off, on without the visible sky weight
(OcclusionParts.sky_weight off: the render before it, app/core/sky_weight.py), and on as now
(sun pass and sky weight). Wall time and
this process's CPU time (llvmpipe's threads included: steadier than the wall clock on a shared
machine), medians and ranges; the refined meshes' sizes; the sun pass's and the sky weight's own
times (its rays, and the weight from them).

    .venv/bin/python benchmarks/bench_occlusion_cost.py [--rounds 9] [--size 256] [--env NAME]
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


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--rounds", type=int, default=9)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--env", default="quarry_01_1k.hdr")
    args = ap.parse_args(argv)
    os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))

    import alight.core.visibility as vis
    from bench_occlusion import ENV_DIR, load_scene_mesh, scene_for

    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    mesh = load_scene_mesh("helmet", Path(tempfile.mkdtemp()))
    env = load_environment(str(ENV_DIR / args.env))
    size = args.size
    # One renderer (a second GL context in the process slowed the first one's frames 100-fold);
    # each condition its own copy of the mesh, so the renderer keeps a bake per condition.
    r = ForwardRenderer(bake_cache=None)
    r.visibility_parts.cache = None
    maps = r.bake(env, "medium")
    conditions = {}
    for name, weight in (("off", True), ("on, no sky weight", False), ("on (now)", True)):
        copy = dataclasses.replace(mesh, parts=[dataclasses.replace(p) for p in mesh.parts])
        scene = scene_for(copy, "helmet", size, "off" if name == "off" else "on")
        r.visibility_parts.sky_weight = weight
        r.render(scene, maps, size, size)          # the bake (if any), programs compiled
        r.render(scene, maps, size, size)
        conditions[name] = (copy, scene, weight)
    from alight.render.bindings import sun_world_directions

    baked_now = r.visibility_parts._parts[id(conditions["on (now)"][0])][3]
    directions = sun_world_directions(conditions["on (now)"][1], maps)
    sun_seconds = []
    for _ in range(2):
        t0 = time.perf_counter()
        vis.bake_sun_bounce(baked_now.parts, directions)
        sun_seconds.append(time.perf_counter() - t0)
    from alight.core import sky_weight as sw
    from alight.render.visibility_parts import environment_texels

    texels, _ = environment_texels(r.shaders, maps)
    ray_seconds, weight_seconds = [], []
    for _ in range(2):
        t0 = time.perf_counter()
        rays = sw.sky_rays(baked_now.parts, vis.DEFAULT_RAYS)
        ray_seconds.append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        for (free, angle), p in zip(rays, baked_now.parts):
            sw.sky_weight(free, angle, p.normals, p.indices.reshape(-1, 3), texels, 0.0)
        weight_seconds.append(time.perf_counter() - t0)
    baked = {name: _refined_triangles(r, copy) for name, (copy, _, _) in conditions.items()}
    wall = {n: [] for n in conditions}
    cpu = {n: [] for n in conditions}
    for _ in range(args.rounds):
        for name, (_, scene, weight) in conditions.items():
            r.visibility_parts.sky_weight = weight
            t0, c0 = time.perf_counter(), time.process_time()
            r.render(scene, maps, size, size)
            wall[name].append(time.perf_counter() - t0)
            cpu[name].append(time.process_time() - c0)
    print(f"DamagedHelmet, {size}x{size}, {args.env}, {args.rounds} rounds alternated (A B C), medians [ranges] in ms; "
          f"ratio: median / median of off")
    print("| condition | triangles drawn | wall | wall ratio | CPU | CPU ratio |")
    print("|---|---|---|---|---|---|")
    for name in conditions:
        w, c = np.array(wall[name]) * 1e3, np.array(cpu[name]) * 1e3
        print(f"| {name} | {baked[name]} | {np.median(w):.1f} [{w.min():.1f}-{w.max():.1f}] | "
              f"{np.median(w) / np.median(np.array(wall['off']) * 1e3):.2f} | {np.median(c):.1f} [{c.min():.1f}-{c.max():.1f}] | "
              f"{np.median(c) / np.median(np.array(cpu['off']) * 1e3):.2f} |")
    print(f"the sun pass ({len(directions)} sun, {sum(len(p.positions) for p in baked_now.parts)} vertices): "
          f"{sun_seconds[0]:.2f} s, {sun_seconds[1]:.2f} s")
    print(f"the sky weight: its rays ({vis.DEFAULT_RAYS} a vertex) {ray_seconds[0]:.2f} s, {ray_seconds[1]:.2f} s; "
          f"the weight from them {weight_seconds[0]:.2f} s, {weight_seconds[1]:.2f} s")
    return 0


def _refined_triangles(r, mesh) -> int:
    entry = r.visibility_parts._parts.get(id(mesh))
    if entry is None:
        return sum(len(np.asarray(p.indices).reshape(-1, 3)) for p in mesh.parts)
    return sum(g.ibo.size // 12 for g in entry[1])      # uint32 indices, three a triangle


if __name__ == "__main__":
    sys.exit(main())

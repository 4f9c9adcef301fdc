"""Mesh shading from the visibility buffer (ForwardRenderer.mesh_shading = "vbuffer",
alight.render.vbuffer) against the forward pass: steady frames alternated in one process
(A B A B ...), the first frame of a fresh process (shader compiles, Mesa's cache off), and how far
the pictures differ (relMAE of the linear radiance, as an EXR holds it). Asserts nothing.

    .venv/bin/python benchmarks/bench_vbuffer.py [--size 1024[,512...]] [--rounds 5] [--triangles 8000,1000000]
        [--first 3] [--pictures 512]

Per scene and size it also prints the triangle density that mesh_shading "auto" chooses by
(alight.render.vbuffer.pixels_per_triangle, the estimate, next to the covered pixels counted in
the forward frame, alpha > 0, per triangle of the mesh) and what "auto" chose, then a table of all.

Scenes: DamagedHelmet (its materials) and bumpy spheres of each --triangles count
(bench_assets.bumpy_sphere, untextured), the royal_esplanade environment, 4x MSAA, read back as sRGB.
--pictures: the helmet (also with its per-vertex occlusion, Scene.occlusion 'auto') and every
Khronos model in ../shared/data/models/khronos at that size.
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

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared" / "data"
HELMET = SHARED / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
ENV = SHARED / "env" / "royal_esplanade_1k.hdr"
MODES = ("forward", "vbuffer")

FIRST_FRAME = """
import sys, time
from alight.core.scene import Scene
from alight.exchange.meshes import load_mesh
from alight.ibl.environment import load_environment
from alight.render.renderer import ForwardRenderer
r = ForwardRenderer()
maps = r.bake(load_environment(sys.argv[1]), "medium")
scene = Scene(mesh=load_mesh(sys.argv[2]))
r.mesh_shading = sys.argv[3]
t = time.perf_counter()
r.render(scene, maps, int(sys.argv[4]), int(sys.argv[4]), read_linear=False)
print(time.perf_counter() - t)
"""


def summary(values) -> str:
    return f"{statistics.median(values):.3f} s ({min(values):.3f}-{max(values):.3f})"


def ratio_summary(a, b) -> str:
    ratios = [y / x for x, y in zip(a, b)]
    return f"{statistics.median(ratios):.2f}x ({min(ratios):.2f}-{max(ratios):.2f})"


def sphere_file(folder: Path, triangles: int) -> Path:
    import trimesh

    sys.path.insert(0, str(REPO / "benchmarks"))
    from bench_assets import bumpy_sphere

    p, f, uv, n = bumpy_sphere(triangles)
    m = trimesh.Trimesh(p, f, vertex_normals=n, process=False)
    m.visual = trimesh.visual.TextureVisuals(uv=uv)
    path = folder / f"sphere_{len(f)}.glb"
    m.export(path, include_normals=True)
    return path


def steady(r, scene, maps, size: int, rounds: int) -> tuple[dict[str, list[float]], dict[str, list[float]]]:
    """Round medians of 3 frames per mode, wall and CPU time (the process's, llvmpipe's threads
    included: less moved by other jobs on the machine), the modes alternated round by round."""
    for mode in MODES:     # compiles both first
        r.mesh_shading = mode
        r.render(scene, maps, size, size, read_linear=False)
    times: dict[str, list[float]] = {m: [] for m in MODES}
    cpu: dict[str, list[float]] = {m: [] for m in MODES}
    for i in range(rounds):
        for mode in (MODES if i % 2 == 0 else MODES[::-1]):
            r.mesh_shading = mode
            runs, cpus = [], []
            for _ in range(3):
                t, c = time.perf_counter(), time.process_time()
                r.render(scene, maps, size, size, read_linear=False)
                runs.append(time.perf_counter() - t)
                cpus.append(time.process_time() - c)
            times[mode].append(statistics.median(runs))
            cpu[mode].append(statistics.median(cpus))
    return times, cpu


def density(r, scene, maps, size: int) -> tuple[int, float, float | None, bool]:
    """(triangles, covered pixels per triangle counted in the forward frame, the estimate "auto"
    chooses by, whether "auto" took the visibility buffer)."""
    from alight.render.vbuffer import pixels_per_triangle

    r.mesh_shading = "forward"
    covered = int((r.render(scene, maps, size, size, read_srgb=False).linear[..., 3] > 0).sum())
    triangles = sum(len(part.indices) for part in scene.mesh.parts)
    view_projection = r.camera_for(scene, 1.0).view_projection(1.0)
    estimate = pixels_per_triangle(r, scene, view_projection, (size, size))
    r.mesh_shading = "auto"
    r.render(scene, maps, size, size, read_linear=False)
    return triangles, covered / triangles, estimate, r.last_vbuffer


def rel_mae(r, scene, maps, size: int) -> tuple[float, float, float, bool]:
    """relMAE of the linear RGB (vbuffer against forward), the share of pixels whose sRGB differs
    by more than 4/255, the largest sRGB difference (of 255), and whether the visibility buffer
    was used (alight.render.vbuffer.wanted: not with blended or transmissive parts)."""
    frames = {}
    for mode in MODES:
        r.mesh_shading = mode
        frames[mode] = r.render(scene, maps, size, size)
    used = r.last_vbuffer
    a, b = frames["forward"], frames["vbuffer"]
    rel = float(np.abs(a.linear[..., :3] - b.linear[..., :3]).sum() / max(np.abs(a.linear[..., :3]).sum(), 1e-12))
    d = np.abs(a.srgb.astype(int) - b.srgb.astype(int)).max(axis=2)
    return rel, float((d > 4).mean()), float(d.max()), used


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", default="1024", help="image sizes, comma-separated")
    ap.add_argument("--rounds", type=int, default=5)
    ap.add_argument("--triangles", default="8000,1000000", help="the spheres' triangle counts, comma-separated")
    ap.add_argument("--first", type=int, default=3, help="fresh processes per mode for the first frame (0: skip)")
    ap.add_argument("--pictures", type=int, default=512, help="size of the picture comparison (0: skip)")
    args = ap.parse_args()

    from alight.core.scene import Scene
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    r = ForwardRenderer()
    maps = r.bake(load_environment(str(ENV)), "medium")
    with tempfile.TemporaryDirectory() as tmp:
        scenes = {"DamagedHelmet": HELMET}
        for count in args.triangles.split(","):
            sphere = sphere_file(Path(tmp), int(count))
            scenes[sphere.stem] = sphere
        sizes = [int(x) for x in args.size.split(",")]
        print(f"{args.size} square, 4x MSAA, sRGB read back, {ENV.name}; {args.rounds} rounds of 3 frames, "
              "modes alternated; round medians: median (range)")
        rows = []
        for name, path in scenes.items():
            scene = Scene(mesh=load_mesh(str(path)))
            for size in sizes:
                times, cpu = steady(r, scene, maps, size, args.rounds)
                triangles, counted, estimate, auto = density(r, scene, maps, size)
                wall, proc = (ratio_summary(times["forward"], times["vbuffer"]),
                              ratio_summary(cpu["forward"], cpu["vbuffer"]))
                guess = "-" if estimate is None else f"{estimate:.2f}"
                chosen = "vbuffer" if auto else "forward"
                print(f"  {name} {size}: wall: forward {summary(times['forward'])}, "
                      f"vbuffer {summary(times['vbuffer'])}, vbuffer/forward {wall}")
                print(f"  {name} {size}: CPU:  forward {summary(cpu['forward'])}, "
                      f"vbuffer {summary(cpu['vbuffer'])}, vbuffer/forward {proc}")
                print(f"  {name} {size}: {triangles} triangles, covered pixels per triangle {counted:.2f} "
                      f"(estimate {guess}), auto: {chosen}")
                rows.append((name, size, triangles, counted, guess, wall, proc, chosen))
        print("| scene | size | triangles | covered px / triangle | estimate | vbuffer/forward wall | CPU | auto |")
        print("| --- | --- | --- | --- | --- | --- | --- | --- |")
        for name, size, triangles, counted, guess, wall, proc, chosen in rows:
            print(f"| {name} | {size} | {triangles:,} | {counted:.2f} | {guess} | {wall} | {proc} | {chosen} |")
        sys.stdout.flush()
        if args.first:
            env = {**os.environ, "MESA_SHADER_CACHE_DISABLE": "true"}
            for name, path in scenes.items():
                first: dict[str, list[float]] = {m: [] for m in MODES}
                for i in range(args.first):
                    for mode in (MODES if i % 2 == 0 else MODES[::-1]):
                        out = subprocess.run([sys.executable, "-c", FIRST_FRAME, str(ENV), str(path), mode,
                                              str(sizes[0])], capture_output=True, text=True, env=env, check=True)
                        first[mode].append(float(out.stdout.split()[-1]))
                print(f"  {name} first frame of a fresh process (Mesa cache off, bake cached), {args.first} each: "
                      f"forward {summary(first['forward'])}, vbuffer {summary(first['vbuffer'])}, "
                      f"vbuffer/forward {ratio_summary(first['forward'], first['vbuffer'])}")
    if args.pictures:
        print(f"pictures at {args.pictures}x{args.pictures}: relMAE of linear RGB, share of pixels > 4/255 in sRGB, "
              "largest sRGB difference")
        rel, share, worst, used = rel_mae(r, Scene(mesh=load_mesh(str(HELMET)), occlusion="auto"), maps, args.pictures)
        print(f"  DamagedHelmet, occlusion auto: {rel:.2e}, {share:.4%}, {worst:.0f}/255"
              + ("" if used else " (forward both: the scene keeps the forward pass)"))
        models = [HELMET] + sorted(p for p in (SHARED / "models" / "khronos").glob("*/glTF-Binary/*.glb"))
        for path in models:
            scene = Scene(mesh=load_mesh(str(path)))
            rel, share, worst, used = rel_mae(r, scene, maps, args.pictures)
            print(f"  {path.stem}: {rel:.2e}, {share:.4%}, {worst:.0f}/255"
                  + ("" if used else " (forward both: the scene keeps the forward pass)"))
    r.release()


if __name__ == "__main__":
    main()

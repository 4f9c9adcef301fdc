"""The visibility bake (app/core/visibility.py) against the path tracer (app/accuracy/path_trace.py):
the corner, the bowl, the product (a capsule on a ground plane that is part of the mesh;
app/accuracy/scenes.py) and DamagedHelmet's geometry under the maps of ../shared/data/env, alight
with --occlusion off, on without the visible sky weight (alight.core.sky_weight;
OcclusionParts.sky_weight off: the render before it existed) and on, binned 4x4 linear relMAE
(app/accuracy/binned.py, as `alight compare --bin 4`); and the cost: the bake's and the sky
weight's passes (its rays, then the weight from them), frame time off / on without the weight /
on alternated A B C A B C. Prints a table and writes benchmarks/results/occlusion-sky-weight.md
(--out); asserts nothing. (benchmarks/results/occlusion.md holds the earlier table, with the sun
pass's before.)

    .venv/bin/python benchmarks/bench_occlusion.py --references DIR [--maps a,b] [--scenes corner,bowl]

References are traced into DIR on first use (64x64 px, 128 samples a pixel, seed 0, 8 bounces)
and read from there afterwards. The material is a grey dielectric (0.7, roughness 0.5) on every
part (the helmet's own textures off in both: the path tracer applies factors only).
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
DATA = HERE.parent.parent / "shared" / "data"
ENV_DIR = DATA / "env"
HELMET = DATA / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
SCENES = ("corner", "bowl", "product", "helmet")
VIEWS = {"corner": (30.0, 25.0), "bowl": (0.0, 45.0), "product": (20.0, 20.0), "helmet": (30.0, 10.0)}   # (orbit, elevation)
GREY = dict(base_color=(0.7, 0.7, 0.7), metallic=0.0, roughness=0.5)


def all_maps() -> list[str]:
    return sorted(p.name for p in ENV_DIR.iterdir() if p.suffix in (".hdr", ".exr"))


def load_scene_mesh(name: str, folder: Path):
    from alight.accuracy.scenes import write_scene
    from alight.exchange.meshes import load_mesh

    if name == "helmet":
        return load_mesh(str(HELMET))
    obj = folder / f"{name}.obj"
    if not obj.exists():
        write_scene(name, folder)
    return load_mesh(str(obj))


def camera_for(mesh, size, view):
    from alight.core.scene import orbit_camera

    centre, radius = mesh.bounding_sphere()
    return orbit_camera(centre, radius, size[0] / size[1], view[0], view[1], None, 35.0, None, corners=mesh.corners())


def scene_for(mesh, name, size, occlusion="off"):
    from alight.core.material import Material
    from alight.core.scene import Scene

    return Scene(mesh=mesh, material=Material(**GREY), use_file_materials=False,
                 camera=camera_for(mesh, (size, size), VIEWS[name]), occlusion=occlusion)


def reference(folder: Path, name: str, mesh, env_name: str, env, size: int, samples: int) -> np.ndarray:
    from alight.accuracy.path_trace import TraceSettings, trace

    out = folder / f"{name}__{env_name}__{size}px_{samples}spp.npy"
    if out.exists():
        return np.load(out)
    start = time.perf_counter()
    ref = trace(scene_for(mesh, name, size), env.radiance, size, size, TraceSettings(samples=samples, seed=0)).linear
    np.save(out, ref)
    print(f"  traced {name} {env_name} in {time.perf_counter() - start:.1f} s", flush=True)
    return ref


def measure(folder: Path, size: int, samples: int, repeats: int, maps: list[str], scenes: list[str],
            out_name: str = "occlusion-sky-weight.md") -> None:
    from alight.accuracy.binned import binned_relative_mae
    from alight.core import sky_weight as sw
    from alight.core.visibility import bake_sun_bounce, bake_visibility, occlusion_statistic
    from alight.render.visibility_parts import environment_texels
    from alight.ibl.environment import load_environment
    from alight.render.bindings import sun_world_directions
    from alight.render.renderer import ForwardRenderer

    folder.mkdir(parents=True, exist_ok=True)
    renderer = ForwardRenderer(bake_cache=None)
    meshes = {name: load_scene_mesh(name, folder) for name in scenes}
    rows = []
    from alight.errors import AlightError

    for env_name in maps:
        try:
            env = load_environment(str(ENV_DIR / env_name))
        except AlightError as exc:      # memorial.exr is not an equirect map
            print(f"skipped: {exc}", flush=True)
            continue
        maps_ = renderer.bake(env, "medium")
        for name in scenes:
            ref = reference(folder, name, meshes[name], env_name, env, size, samples)
            errors = {}
            for label, mode, weight in (("off", "off", True), ("no sky weight", "on", False), ("on", "on", True)):
                renderer.visibility_parts.sky_weight = weight
                img = renderer.render(scene_for(meshes[name], name, size, mode), maps_, size, size,
                                      read_linear=True, read_srgb=False).linear
                errors[label] = 100.0 * binned_relative_mae(img, ref, 4)
            renderer.visibility_parts.sky_weight = True
            rows.append((name, env_name, errors["off"], errors["no sky weight"], errors["on"]))
            print(f"{name:8s} {env_name:28s} off {errors['off']:5.1f}%  on without the sky weight "
                  f"{errors['no sky weight']:5.1f}%  on {errors['on']:5.1f}%", flush=True)
    stats = {name: occlusion_statistic(meshes[name].parts) for name in scenes}
    # Cost: the bake (no disk cache), the sky weight's passes, and frames alternated, per scene.
    env = load_environment(str(ENV_DIR / maps[0]))
    maps_ = renderer.bake(env, "medium")
    texels, _ = environment_texels(renderer.shaders, maps_)
    frame = 256
    cost = []
    labels = ("off", "on, no sky weight", "on")
    for name in scenes:
        baked = bake_visibility(meshes[name])
        bake_s = baked.seconds
        pair = {m: scene_for(meshes[name], name, frame, m) for m in ("off", "on")}
        directions = sun_world_directions(pair["on"], maps_)
        start = time.perf_counter()
        bake_sun_bounce(baked.parts, directions)
        sun_s = time.perf_counter() - start
        rays_s, weight_s = [], []
        for _ in range(2):
            start = time.perf_counter()
            rays = sw.sky_rays(baked.parts, 192)
            rays_s.append(time.perf_counter() - start)
            start = time.perf_counter()
            for (free, angle), p in zip(rays, baked.parts):
                sw.sky_weight(free, angle, p.normals, p.indices.reshape(-1, 3), texels, 0.0)
            weight_s.append(time.perf_counter() - start)
        vertices = sum(len(p.positions) for p in baked.parts)
        setting = {"off": ("off", True), "on, no sky weight": ("on", False), "on": ("on", True)}

        def draw(label):
            mode, weight = setting[label]
            renderer.visibility_parts.sky_weight = weight
            renderer.render(pair[mode], maps_, frame, frame)

        for m in labels:   # warm: programs compiled, bake and weight done
            draw(m)
        times = {m: [] for m in labels}
        cpu = {m: [] for m in labels}
        for _ in range(repeats):
            for m in labels:
                start, start_cpu = time.perf_counter(), time.process_time()
                draw(m)
                times[m].append(time.perf_counter() - start)
                cpu[m].append(time.process_time() - start_cpu)
        renderer.visibility_parts.sky_weight = True
        med = {m: float(np.median(v)) for m, v in times.items()}
        med_cpu = {m: float(np.median(v)) for m, v in cpu.items()}
        ranges = "; ".join(f"{m} {min(times[m]) * 1e3:.0f}-{max(times[m]) * 1e3:.0f} ms" for m in labels)
        cost.append(f"- {name} ({vertices} refined vertices): bake {bake_s:.2f} s; the sun pass ({len(directions)} "
                    f"sun) {sun_s:.2f} s; the sky weight: its rays {rays_s[0]:.2f} s, {rays_s[1]:.2f} s, the weight "
                    f"from them {weight_s[0]:.2f} s, {weight_s[1]:.2f} s; frame {frame}x{frame} ({maps[0]}), "
                    f"alternated A B C x{repeats}, median wall off {med['off'] * 1e3:.1f} ms, on without the weight "
                    f"{med['on, no sky weight'] * 1e3:.1f} ms, on {med['on'] * 1e3:.1f} ms (on / off "
                    f"{med['on'] / med['off']:.2f}, on / on without {med['on'] / med['on, no sky weight']:.2f}; CPU "
                    f"on / off {med_cpu['on'] / med_cpu['off']:.2f}; ranges {ranges})")
        print(cost[-1], flush=True)
    lines = ["# The visibility bake with and without the visible sky weight, against the path tracer", "",
             f"{size}x{size} px; references: app/accuracy/path_trace.py, {samples} samples a pixel, seed 0, "
             "8 bounces; binned 4x4 linear relMAE; alight: medium bake, default IBL model, MSAA; grey dielectric "
             "(0.7, roughness 0.5) on every part.", "",
             "| scene | environment | occlusion off % | on, no sky weight (before) % | occlusion on % |",
             "|---|---|---|---|---|"]
    lines += [f"| {a} | {b} | {c:.1f} | {d:.1f} | {e:.1f} |" for a, b, c, d, e in rows]
    lines += ["", "occlusion statistic (auto bakes above 0.03): "
              + ", ".join(f"{n} {v:.3f}" for n, v in stats.items()), "", "Cost:", *cost]
    print("\n".join(lines))
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / out_name).write_text("\n".join(lines) + "\n")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--references", type=Path, required=True, metavar="DIR",
                   help="where the path-traced references are kept (traced there on first use)")
    p.add_argument("--maps", default="", help="comma-separated file names in ../shared/data/env (default: all)")
    p.add_argument("--scenes", default=",".join(SCENES), help=f"comma-separated, of {', '.join(SCENES)}")
    p.add_argument("--size", type=int, default=64)
    p.add_argument("--samples", type=int, default=128)
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--out", default="occlusion-sky-weight.md", help="file name in benchmarks/results")
    args = p.parse_args()
    os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))
    maps = [m for m in args.maps.split(",") if m] or all_maps()
    measure(args.references, args.size, args.samples, args.repeats, maps, [s for s in args.scenes.split(",") if s],
            args.out)


if __name__ == "__main__":
    sys.exit(main())

"""The visibility bake (app/core/visibility.py) against the path tracer (app/accuracy/path_trace.py):
the corner, the bowl, the product (a capsule on a ground plane that is part of the mesh;
app/accuracy/scenes.py) and DamagedHelmet's geometry under the maps of ../shared/data/env, alight
with --occlusion off, on without the suns' light on the occluders (the bake's sun pass off:
alight.render.visibility_parts.OcclusionParts.sun_bounce, the render before it existed) and on,
binned 4x4 linear relMAE
(app/accuracy/binned.py, as `alight compare --bin 4`); and the cost: bake time, frame time off/on
alternated A B A B. Prints a table and writes benchmarks/results/occlusion.md; asserts nothing.

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


def measure(folder: Path, size: int, samples: int, repeats: int, maps: list[str], scenes: list[str]) -> None:
    from alight.accuracy.binned import binned_relative_mae
    from alight.core.visibility import bake_sun_bounce, bake_visibility, occlusion_statistic
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
            for label, mode, sun_bounce in (("off", "off", True), ("no sun bounce", "on", False), ("on", "on", True)):
                renderer.visibility_parts.sun_bounce = sun_bounce
                img = renderer.render(scene_for(meshes[name], name, size, mode), maps_, size, size,
                                      read_linear=True, read_srgb=False).linear
                errors[label] = 100.0 * binned_relative_mae(img, ref, 4)
            renderer.visibility_parts.sun_bounce = True
            rows.append((name, env_name, errors["off"], errors["no sun bounce"], errors["on"]))
            print(f"{name:8s} {env_name:28s} off {errors['off']:5.1f}%  on without the suns' bounce "
                  f"{errors['no sun bounce']:5.1f}%  on {errors['on']:5.1f}%", flush=True)
    stats = {name: occlusion_statistic(meshes[name].parts) for name in scenes}
    # Cost: the bake (no disk cache) and frames alternated off/on, per scene.
    env = load_environment(str(ENV_DIR / maps[0]))
    maps_ = renderer.bake(env, "medium")
    frame = 256
    cost = []
    for name in scenes:
        bake_s = [bake_visibility(meshes[name]).seconds for _ in range(2)]
        pair = {m: scene_for(meshes[name], name, frame, m) for m in ("off", "on")}
        directions = sun_world_directions(pair["on"], maps_)
        baked = bake_visibility(meshes[name])
        sun_s = []
        for _ in range(2):
            start = time.perf_counter()
            bake_sun_bounce(baked.parts, directions)
            sun_s.append(time.perf_counter() - start)
        for m in ("off", "on"):   # warm: programs compiled, bake done
            renderer.render(pair[m], maps_, frame, frame)
        times = {"off": [], "on": []}
        for _ in range(repeats):
            for m in ("off", "on"):
                start = time.perf_counter()
                renderer.render(pair[m], maps_, frame, frame)
                times[m].append(time.perf_counter() - start)
        med = {m: float(np.median(v)) for m, v in times.items()}
        cost.append(f"- {name}: bake {bake_s[0]:.2f} s, {bake_s[1]:.2f} s; the sun pass ({len(directions)} "
                    f"sun) {sun_s[0]:.2f} s, {sun_s[1]:.2f} s; frame {frame}x{frame} ({maps[0]}), "
                    f"alternated A B x{repeats}, median off {med['off'] * 1e3:.1f} ms, on {med['on'] * 1e3:.1f} ms "
                    f"(ratio {med['on'] / med['off']:.2f}; off {min(times['off']) * 1e3:.1f}-"
                    f"{max(times['off']) * 1e3:.1f} ms, on {min(times['on']) * 1e3:.1f}-{max(times['on']) * 1e3:.1f} ms)")
        print(cost[-1], flush=True)
    lines = ["# The visibility bake against the path tracer", "",
             f"{size}x{size} px; references: app/accuracy/path_trace.py, {samples} samples a pixel, seed 0, "
             "8 bounces; binned 4x4 linear relMAE; alight: medium bake, default IBL model, MSAA; grey dielectric "
             "(0.7, roughness 0.5) on every part.", "",
             "| scene | environment | occlusion off % | on, no sun bounce (before) % | occlusion on % |",
             "|---|---|---|---|---|"]
    lines += [f"| {a} | {b} | {c:.1f} | {d:.1f} | {e:.1f} |" for a, b, c, d, e in rows]
    lines += ["", "occlusion statistic (auto bakes above 0.03): "
              + ", ".join(f"{n} {v:.3f}" for n, v in stats.items()), "", "Cost:", *cost]
    print("\n".join(lines))
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / "occlusion.md").write_text("\n".join(lines) + "\n")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--references", type=Path, required=True, metavar="DIR",
                   help="where the path-traced references are kept (traced there on first use)")
    p.add_argument("--maps", default="", help="comma-separated file names in ../shared/data/env (default: all)")
    p.add_argument("--scenes", default=",".join(SCENES), help=f"comma-separated, of {', '.join(SCENES)}")
    p.add_argument("--size", type=int, default=64)
    p.add_argument("--samples", type=int, default=128)
    p.add_argument("--repeats", type=int, default=5)
    args = p.parse_args()
    os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))
    maps = [m for m in args.maps.split(",") if m] or all_maps()
    measure(args.references, args.size, args.samples, args.repeats, maps, [s for s in args.scenes.split(",") if s])


if __name__ == "__main__":
    sys.exit(main())

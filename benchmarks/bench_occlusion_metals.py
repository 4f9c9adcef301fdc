"""The visibility bake on metals reflecting each other: the bowl (app/accuracy/scenes.py) in gold
and iron at roughness 0.3, 0.6 and 0.9, and the grey dielectric (0.7, roughness 0.5) for
comparison, under newport_loft and royal_esplanade, alight with --occlusion off and on against the
path tracer (app/accuracy/path_trace.py), binned 4x4 linear relMAE (app/accuracy/binned.py, as
`alight compare --bin 4`), and each image's mean against the reference's (signed). Prints a
table, and with --out writes it to benchmarks/results/<--out> (results/occlusion-metals.md was
put together from its runs by hand: before and after, and the variants tried); asserts nothing.

    .venv/bin/python benchmarks/bench_occlusion_metals.py --references DIR [--maps a,b] [--materials gold-0.6,grey]

References are traced into DIR on first use (64x64 px, 128 samples a pixel, seed 0, 8 bounces;
the grey ones under the same names as bench_occlusion.py's, so one folder serves both) and read
from there afterwards. --label names the "on" column (the method being measured).
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
sys.path.insert(0, str(HERE))
from bench_occlusion import ENV_DIR, VIEWS, camera_for, load_scene_mesh  # noqa: E402

MAPS = ("newport_loft.hdr", "royal_esplanade_1k.hdr")
COLOURS = {"gold": (1.0, 0.71, 0.29), "iron": (0.56, 0.57, 0.58)}
MATERIALS = ("grey", "gold-0.3", "gold-0.6", "gold-0.9", "iron-0.6")


def material(key: str):
    from alight.core.material import Material

    if key == "grey":
        return Material(base_color=(0.7, 0.7, 0.7), metallic=0.0, roughness=0.5)
    name, roughness = key.split("-")
    return Material(base_color=COLOURS[name], metallic=1.0, roughness=float(roughness))


def scene_for(mesh, name, key, size, occlusion="off"):
    from alight.core.scene import Scene

    return Scene(mesh=mesh, material=material(key), use_file_materials=False,
                 camera=camera_for(mesh, (size, size), VIEWS[name]), occlusion=occlusion)


def reference(folder: Path, name: str, key: str, mesh, env_name: str, env, size: int, samples: int) -> np.ndarray:
    from alight.accuracy.path_trace import TraceSettings, trace

    tag = "" if key == "grey" else f"__{key}"
    out = folder / f"{name}__{env_name}{tag}__{size}px_{samples}spp.npy"
    if out.exists():
        return np.load(out)
    start = time.perf_counter()
    ref = trace(scene_for(mesh, name, key, size), env.radiance, size, size,
                TraceSettings(samples=samples, seed=0)).linear
    np.save(out, ref)
    print(f"  traced {name} {key} {env_name} in {time.perf_counter() - start:.1f} s", flush=True)
    return ref


def measure(folder: Path, size: int, samples: int, maps: list[str], keys: list[str], scene: str,
            label: str, out_name: str, trace_only: bool) -> list[tuple]:
    from alight.accuracy.binned import binned_relative_mae
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    folder.mkdir(parents=True, exist_ok=True)
    mesh = load_scene_mesh(scene, folder)
    renderer = None if trace_only else ForwardRenderer(bake_cache=None)
    rows = []
    for env_name in maps:
        env = load_environment(str(ENV_DIR / env_name))
        maps_ = None if trace_only else renderer.bake(env, "medium")
        for key in keys:
            ref = reference(folder, scene, key, mesh, env_name, env, size, samples)
            if trace_only:
                continue
            errors = {}
            for mode in ("off", "on"):
                img = renderer.render(scene_for(mesh, scene, key, size, mode), maps_, size, size,
                                      read_linear=True, read_srgb=False).linear
                errors[mode] = 100.0 * binned_relative_mae(img, ref, 4)
                errors[mode + " bias"] = 100.0 * (float(img[..., :3].mean()) / max(float(ref[..., :3].mean()), 1e-9) - 1.0)
            rows.append((scene, env_name, key, errors["off"], errors["on"]))
            print(f"{scene} {env_name:24s} {key:9s} off {errors['off']:5.1f}%  {label} {errors['on']:5.1f}% "
                  f"(mean {errors['off bias']:+.0f}% / {errors['on bias']:+.0f}%)", flush=True)
    if trace_only:
        return rows
    lines = [f"# The bowl's metals against the path tracer ({label})", "",
             f"{size}x{size} px; references: app/accuracy/path_trace.py, {samples} samples a pixel, seed 0, "
             "8 bounces; binned 4x4 linear relMAE; alight: medium bake, default IBL model, MSAA.", "",
             f"| scene | environment | material | occlusion off % | {label} % |", "|---|---|---|---|---|"]
    lines += [f"| {a} | {b} | {c} | {d:.1f} | {e:.1f} |" for a, b, c, d, e in rows]
    print("\n".join(lines))
    if out_name:
        (HERE / "results").mkdir(exist_ok=True)
        (HERE / "results" / out_name).write_text("\n".join(lines) + "\n")
    return rows


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--references", type=Path, required=True, metavar="DIR")
    p.add_argument("--maps", default=",".join(MAPS), help="comma-separated file names in ../shared/data/env")
    p.add_argument("--materials", default=",".join(MATERIALS), help="grey, or gold-R / iron-R (R the roughness)")
    p.add_argument("--scene", default="bowl")
    p.add_argument("--size", type=int, default=64)
    p.add_argument("--samples", type=int, default=128)
    p.add_argument("--label", default="occlusion on")
    p.add_argument("--out", default="", help="file name in benchmarks/results (default: print only)")
    p.add_argument("--trace-only", action="store_true", help="trace the missing references and stop")
    args = p.parse_args()
    os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))
    measure(args.references, args.size, args.samples, [m for m in args.maps.split(",") if m],
            [k for k in args.materials.split(",") if k], args.scene, args.label, args.out, args.trace_only)


if __name__ == "__main__":
    sys.exit(main())

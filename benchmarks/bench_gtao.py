"""Screen-space GTAO (--occlusion gtao, app/render/screen_ao.py) against the path tracer and the
visibility bake, and its cost.

Error: the corner and the bowl (app/accuracy/scenes.py) under the maps given, alight with
--occlusion off, on (the bake), gtao (the occluders' radiance), gtao with the paper's multi-bounce
fit instead, and gtao with V alone, binned 4x4 linear
relMAE against app/accuracy/path_trace.py (bench_occlusion.py's scenes, cameras, grey material
and reference cache). Cost: frames alternated off / on / gtao (A B C, several rounds; process CPU
time and wall, medians and ranges) on DamagedHelmet and, off / gtao only, on a large mesh
(MetalRoughSpheresNoTextures, 1M triangles: its bake is the 97 s that AUTO_MAX_VERTICES avoids).
The gtao column's 4x4 bins are also counted by their ratio to the path tracer (luminance; the
bins where gtao differs from off, i.e. where the pass darkens or lights anything): above 1.2x and
1.1x, below 0.8x and 0.9x, the counts benchmarks/results/gtao.md quotes for the corner's glow and
band. Writes benchmarks/results/gtao.md (--out) and the renders as PNG beside the references;
asserts nothing.

    .venv/bin/python benchmarks/bench_gtao.py --references DIR [--maps a,b] [--size 96] [--samples 64] [--skip-cost]
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_occlusion import DATA, ENV_DIR, load_scene_mesh, reference, scene_for  # noqa: E402

HERE = Path(__file__).resolve().parent
BIG = DATA / "models" / "khronos" / "MetalRoughSpheresNoTextures" / "glTF-Binary" / "MetalRoughSpheresNoTextures.glb"
MODES = ("off", "on", "gtao", "gtao, multi-bounce fit", "gtao, V alone")
OCCLUDED = {"gtao": "occluders", "gtao, multi-bounce fit": "multi_bounce", "gtao, V alone": "black"}


def srgb_png(path: Path, linear: np.ndarray) -> None:
    from PIL import Image

    x = np.clip(linear[..., :3], 0.0, None)
    x = x / (1.0 + x)       # a plain Reinhard for looking, the same for every image
    x = np.where(x <= 0.0031308, 12.92 * x, 1.055 * np.power(x, 1 / 2.4) - 0.055)
    Image.fromarray((np.clip(x, 0, 1) * 255 + 0.5).astype(np.uint8)).save(path)


BIN_LIMITS = (("> 1.2x", 1.2, 1), ("> 1.1x", 1.1, 1), ("< 0.8x", 0.8, -1), ("< 0.9x", 0.9, -1))


def bin_counts(img: np.ndarray, off: np.ndarray, ref: np.ndarray, k: int = 4) -> tuple[int, ...]:
    """The k x k bins where ``img`` differs from ``off``, and how many of them lie beyond each of
    BIN_LIMITS as a ratio of their mean luminance (RGB mean) to the reference's."""
    def binned(x):
        y = x[..., :3].mean(-1)
        h, w = (y.shape[0] // k) * k, (y.shape[1] // k) * k
        return y[:h, :w].reshape(h // k, k, w // k, k).mean((1, 3))

    b, o, r = binned(img), binned(off), binned(ref)
    moved = b != o
    q = b[moved] / np.maximum(r[moved], 1e-6)
    return (int(moved.sum()), *[int((side * (q - limit) > 0).sum()) for _, limit, side in BIN_LIMITS])


def errors(folder: Path, size: int, samples: int, maps: list[str], renderer) -> list[tuple]:
    from alight.accuracy.binned import binned_relative_mae
    from alight.ibl.environment import load_environment

    rows = []
    for env_name in maps:
        env = load_environment(str(ENV_DIR / env_name))
        baked = renderer.bake(env, "medium")
        for name in ("corner", "bowl"):
            mesh = load_scene_mesh(name, folder)
            ref = reference(folder, name, mesh, env_name, env, size, samples)
            srgb_png(folder / f"{name}__{env_name}__reference.png", ref)
            errs, images = {}, {}
            for label in MODES:
                # The multi-bounce switch reaches the pass through ScreenAO (made on the first gtao frame).
                if label.startswith("gtao") and renderer.screen_ao is None:
                    renderer.render(scene_for(mesh, name, size, "gtao"), baked, size, size)
                if renderer.screen_ao is not None:
                    renderer.screen_ao.occluded = OCCLUDED.get(label, "occluders")
                mode = "gtao" if label.startswith("gtao") else label
                img = renderer.render(scene_for(mesh, name, size, mode), baked, size, size, read_linear=True,
                                      read_srgb=False).linear
                if renderer.screen_ao is not None:
                    renderer.screen_ao.occluded = "occluders"
                errs[label] = 100.0 * binned_relative_mae(img, ref, 4)
                images[label] = img
                srgb_png(folder / f"{name}__{env_name}__{label.replace(', ', '_').replace(' ', '-')}.png", img)
            counts = bin_counts(images["gtao"], images["off"], ref)
            rows.append((name, env_name, *[errs[m] for m in MODES], counts))
            print(f"{name:7s} {env_name:28s} " + "  ".join(f"{m} {errs[m]:5.1f}%" for m in MODES)
                  + f"  gtao bins {counts}", flush=True)
    return rows


def cost(renderer, maps_, mesh, name, frame: int, rounds: int, labels) -> str:
    from alight.core.material import Material
    from alight.core.scene import Scene

    scenes = {m: Scene(mesh=mesh, material=Material(base_color=(0.7, 0.7, 0.7), roughness=0.5), use_file_materials=True,
                       occlusion=m) for m in labels}
    start = time.perf_counter()
    for m in labels:    # warm: programs compiled, the bake made (or read)
        renderer.render(scenes[m], maps_, frame, frame, read_linear=False, read_srgb=True)
    warm = time.perf_counter() - start
    wall = {m: [] for m in labels}
    cpu = {m: [] for m in labels}
    for _ in range(rounds):
        for m in labels:
            w0, c0 = time.perf_counter(), time.process_time()
            renderer.render(scenes[m], maps_, frame, frame, read_linear=False, read_srgb=True)
            wall[m].append(time.perf_counter() - w0)
            cpu[m].append(time.process_time() - c0)
    med = {m: float(np.median(cpu[m])) for m in labels}
    medw = {m: float(np.median(wall[m])) for m in labels}
    parts = ", ".join(f"{m} CPU {med[m] * 1e3:.0f} ms ({min(cpu[m]) * 1e3:.0f}-{max(cpu[m]) * 1e3:.0f}), wall "
                      f"{medw[m] * 1e3:.0f} ms" for m in labels)
    ratios = ", ".join(f"{m} / off CPU {med[m] / med['off']:.2f}x, wall {medw[m] / medw['off']:.2f}x"
                       for m in labels if m != "off")
    vertices = sum(len(p.positions) for p in mesh.parts)
    return (f"| {name} ({vertices} vertices) | {frame}x{frame} | {rounds} | {parts} | {ratios} | "
            f"first frames (compile, bake) {warm:.1f} s |")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--references", type=Path, required=True, metavar="DIR")
    p.add_argument("--maps", default="royal_esplanade_1k.hdr,newport_loft.hdr")
    p.add_argument("--size", type=int, default=96)
    p.add_argument("--samples", type=int, default=64)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--frame", type=int, default=256)
    p.add_argument("--skip-big", action="store_true")
    p.add_argument("--skip-cost", action="store_true", help="the error half only")
    p.add_argument("--out", default="gtao.md")
    args = p.parse_args()
    os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    args.references.mkdir(parents=True, exist_ok=True)
    renderer = ForwardRenderer()
    maps = [m for m in args.maps.split(",") if m]
    rows = errors(args.references, args.size, args.samples, maps, renderer)
    lines_cost = []
    if not args.skip_cost:
        env = load_environment(str(ENV_DIR / maps[0]))
        baked = renderer.bake(env, "medium")
        lines_cost.append(cost(renderer, baked, load_mesh(str(DATA / "models" / "DamagedHelmet" / "DamagedHelmet.gltf")),
                               "DamagedHelmet", args.frame, args.rounds, ("off", "on", "gtao")))
        print(lines_cost[-1], flush=True)
    if not args.skip_cost and not args.skip_big:
        lines_cost.append(cost(renderer, baked, load_mesh(str(BIG)), "MetalRoughSpheresNoTextures", args.frame,
                               args.rounds, ("off", "gtao")))
        print(lines_cost[-1], flush=True)
    lines = ["# Screen-space GTAO against the path tracer and the bake", "",
             f"`benchmarks/bench_gtao.py --references DIR --maps {','.join(maps)} --size {args.size} "
             f"--samples {args.samples} --rounds {args.rounds} --frame {args.frame}`", "",
             f"Error: {args.size}x{args.size} px; references app/accuracy/path_trace.py, {args.samples} samples a "
             "pixel, seed 0, 8 bounces; binned 4x4 linear relMAE; alight: medium bake, default IBL model, MSAA; "
             "grey dielectric (0.7, roughness 0.5); bench_occlusion.py's cameras.", "",
             "| scene | environment | " + " % | ".join(MODES) + " % |", "|---|---|" + "---|" * len(MODES)]
    lines += ["| " + " | ".join([a, b] + [f"{x:.1f}" for x in rest]) + " |" for a, b, *rest, _ in rows]
    lines += ["", "gtao's 4x4 bins (luminance) where it differs from off, by their ratio to the path tracer:", "",
              "| scene | environment | bins | " + " | ".join(label for label, _, _ in BIN_LIMITS) + " |",
              "|---|---|---|" + "---|" * len(BIN_LIMITS)]
    lines += ["| " + " | ".join([a, b] + [str(x) for x in counts]) + " |" for a, b, *_, counts in rows]
    if lines_cost:
        lines += ["", f"Cost per frame (`render`, sRGB read back, MSAA, {maps[0]}): alternated A B C, medians of process "
                  "CPU time (ranges) and wall; 2-core shared machine, llvmpipe.", "",
                  "| mesh | frame | rounds | per mode | ratios | warm-up |", "|---|---|---|---|---|---|", *lines_cost]
    text = "\n".join(lines) + "\n"
    print(text)
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / args.out).write_text(text)


if __name__ == "__main__":
    sys.exit(main())

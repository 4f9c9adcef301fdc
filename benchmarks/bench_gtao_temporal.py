"""GTAO's passes (alight.core.gtao.rotation_offset): error and cost against the number of turns
of the 4x4 pattern averaged (app/render/screen_ao.py).

Error, per scene (bench_occlusion.py's corner and bowl, its cameras and grey material) and map:
- against the path tracer: binned 4x4 linear relMAE at --size (the references of
  bench_gtao.py / bench_occlusion.py, --references DIR; traced there where missing);
- the pattern's noise: unbinned relMAE of the image at --noise-size against the same render with
  64 passes (the converged GTAO), which is what the 4x4 pattern's stripes are.
Cost: the still frame (`alight render`'s path: all passes in one frame) with 1, 2, 4 and 8 passes,
alternated A B C D over --rounds rounds, process CPU time, medians and ranges; and the editor's
path (draw_hdr with screen_ao_temporal: one pass a frame, then none): the frame while refining
and once converged, against --occlusion off.
Prints a Markdown report (and writes it with --out); asserts nothing.

    .venv/bin/python benchmarks/bench_gtao_temporal.py --references DIR [--maps a,b] [--cost-only] [--out FILE]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_occlusion import DATA, ENV_DIR, VIEWS, load_scene_mesh, reference, scene_for  # noqa: E402

# The 1M-triangle spheres: 'auto' draws a mesh this big with GTAO (no bake).
BIG = DATA / "models" / "khronos" / "MetalRoughSpheresNoTextures" / "glTF-Binary" / "MetalRoughSpheresNoTextures.glb"

PASSES = (1, 2, 4, 8, 16)
COST_PASSES = (1, 2, 4, 8)


def render(renderer, scene, maps, size: int, passes: int) -> np.ndarray:
    from alight.core import gtao

    saved = gtao.STILL_FRAMES
    gtao.STILL_FRAMES = passes
    try:
        return renderer.render(scene, maps, size, size, read_linear=True, read_srgb=False).linear
    finally:
        gtao.STILL_FRAMES = saved


def errors(renderer, folder: Path, maps: list[str], size: int, samples: int, noise_size: int) -> list[str]:
    from alight.accuracy.binned import binned_relative_mae
    from alight.ibl.environment import load_environment

    lines = ["| scene | map | " + " | ".join(f"{k} pass{'es' if k > 1 else ''}" for k in PASSES) + " |",
             "| --- | --- |" + " --- |" * len(PASSES)]
    noise_lines = list(lines)
    for env_name in maps:
        env = load_environment(str(ENV_DIR / env_name))
        baked = renderer.bake(env, "medium")
        for name in ("corner", "bowl"):
            mesh = load_scene_mesh(name, folder)
            ref = reference(folder, name, mesh, env_name, env, size, samples)
            traced = [100.0 * binned_relative_mae(render(renderer, scene_for(mesh, name, size, "gtao"), baked, size, k),
                                                  ref, 4) for k in PASSES]
            scene = scene_for(mesh, name, noise_size, "gtao")
            converged = render(renderer, scene, baked, noise_size, 64)[..., :3]
            noise = []
            for k in PASSES:
                img = render(renderer, scene, baked, noise_size, k)[..., :3]
                noise.append(100.0 * float(np.abs(img - converged).mean() / max(np.abs(converged).mean(), 1e-12)))
            lines.append(f"| {name} | {env_name} | " + " | ".join(f"{e:.1f}%" for e in traced) + " |")
            noise_lines.append(f"| {name} | {env_name} | " + " | ".join(f"{e:.2f}%" for e in noise) + " |")
            print(lines[-1], noise_lines[-1], sep="\n", flush=True)
    return (["Binned 4x4 relMAE against the path tracer, " f"{size} px, {samples} spp:", ""] + lines
            + ["", f"Unbinned relMAE against 64 passes (the pattern's noise), {noise_size} px:", ""] + noise_lines)


def timed(fn, rounds: int, labels) -> dict:
    """Process CPU time of ``fn(label)``, alternated; where ``fn`` returns a time, that one."""
    cpu = {k: [] for k in labels}
    for _ in range(rounds):
        for k in labels:
            c0 = time.process_time()
            inner = fn(k)
            cpu[k].append(inner if inner is not None else time.process_time() - c0)
    return cpu


def summary(cpu: dict, base) -> str:
    med = {k: float(np.median(v)) for k, v in cpu.items()}
    return ", ".join(f"{k}: {med[k] * 1e3:.0f} ms ({min(v) * 1e3:.0f}-{max(v) * 1e3:.0f}), {med[k] / med[base]:.2f}x"
                     for k, v in cpu.items())


def cost(renderer, folder: Path, env_name: str, size: int, rounds: int) -> list[str]:
    from alight.core import gtao
    from alight.ibl.environment import load_environment
    from alight.render.targets import Targets

    env = load_environment(str(ENV_DIR / env_name))
    baked = renderer.bake(env, "medium")
    lines = []
    for name in ("corner", "helmet", "spheres"):
        if name == "spheres":
            from alight.exchange.meshes import load_mesh

            mesh = load_mesh(str(BIG))
            VIEWS.setdefault(name, (0.0, 0.0))
        else:
            mesh = load_scene_mesh(name, folder)
        scenes = {"off": scene_for(mesh, name, size, "off"), **{k: scene_for(mesh, name, size, "gtao")
                                                                for k in COST_PASSES}}

        def still(k):
            if k == "off":
                renderer.render(scenes["off"], baked, size, size, read_linear=False, read_srgb=True)
            else:
                render(renderer, scenes[k], baked, size, k)

        for k in scenes:
            still(k)      # compiled
        cpu = timed(still, rounds, list(scenes))
        lines.append(f"- {name}, still {size}x{size} (`render`, read back; {sum(len(p.positions) for p in mesh.parts)} vertices), CPU per frame: {summary(cpu, 'off')}")

        # The editor's path: draw_hdr into kept targets, the view unchanged from frame to frame.
        targets = Targets(renderer.ctx, size, size, "msaa", 4)
        renderer.screen_ao_temporal = True

        def frame(label):
            scene = scenes["off"] if label == "off" else scenes[1]
            # (untimed: the state each label stands for; "refining": a pass into a kept mean)
            if label == "refining":
                renderer.screen_ao.passes = 1
            elif label == "converged":
                while renderer.screen_ao.passes < gtao.TEMPORAL_FRAMES:
                    renderer.draw_hdr(scene, baked, targets)
            renderer.ctx.finish()
            c0 = time.process_time()
            renderer.draw_hdr(scene, baked, targets)
            renderer.ctx.finish()
            return time.process_time() - c0

        for _ in range(3):
            frame("converged")
        cpu = timed(frame, rounds, ["off", "refining", "converged"])
        renderer.screen_ao_temporal = False
        targets.release()
        lines.append(f"- {name}, the editor's frame {size}x{size} (draw_hdr, no read-back), CPU: {summary(cpu, 'off')}")
        print(lines[-2], lines[-1], sep="\n", flush=True)
    return lines


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--references", type=Path, required=True, metavar="DIR")
    p.add_argument("--maps", default="royal_esplanade_1k.hdr,newport_loft.hdr")
    p.add_argument("--size", type=int, default=128)
    p.add_argument("--samples", type=int, default=256)
    p.add_argument("--noise-size", type=int, default=384)
    p.add_argument("--frame", type=int, default=384)
    p.add_argument("--rounds", type=int, default=5)
    p.add_argument("--cost-only", action="store_true", help="skip the error tables")
    p.add_argument("--out", type=Path)
    a = p.parse_args()
    from alight.render.renderer import ForwardRenderer

    a.references.mkdir(parents=True, exist_ok=True)
    renderer = ForwardRenderer()
    maps = a.maps.split(",")
    report = ["# GTAO's passes: error and cost (benchmarks/bench_gtao_temporal.py)", "",
              f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, `{' '.join(sys.argv)}`", ""]
    if not a.cost_only:
        report += errors(renderer, a.references, maps, a.size, a.samples, a.noise_size)
    report += ["", f"Cost under {maps[0]}, {a.rounds} rounds alternated:", ""]
    report += cost(renderer, a.references, maps[0], a.frame, a.rounds)
    text = "\n".join(report) + "\n"
    print(text)
    if a.out:
        a.out.write_text(text)


if __name__ == "__main__":
    main()

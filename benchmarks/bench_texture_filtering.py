"""A textured mesh's steady frame with the anisotropic filtering level chosen per view
(alight.core.texture_footprint) against 8x on every texture (alight's former fixed level), in one
process, alternated frame set by frame set (A B A B ...); and how far the two pictures differ.
Asserts nothing.

    .venv/bin/python benchmarks/bench_texture_filtering.py [--model PATH] [--size 512] [--rounds 5]

Default model: DamagedHelmet (../shared/data/models/), studio light, 4x MSAA, read back as sRGB.
"""

from __future__ import annotations

import argparse
import statistics
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
HELMET = REPO.parent / "shared" / "data" / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", type=Path, default=HELMET)
    ap.add_argument("--size", type=int, default=512)
    ap.add_argument("--rounds", type=int, default=5)
    args = ap.parse_args()

    import alight.render.gpu_mesh as gpu_mesh_module
    import alight.render.renderer as renderer_module
    from alight.core.scene import Scene
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment

    chosen_rule = gpu_mesh_module.anisotropy_for_view
    mesh = load_mesh(str(args.model))
    r = renderer_module.ForwardRenderer()
    maps = r.bake(load_environment("studio"), "medium")
    scene = Scene(mesh=mesh)

    def frame(rule) -> tuple[float, np.ndarray]:
        gpu_mesh_module.anisotropy_for_view = rule
        for part in r._gpu_mesh(mesh):
            part._anisotropy_key = None        # choose again under this rule
        t = time.perf_counter()
        image = r.render(scene, maps, args.size, args.size, aa="msaa").srgb
        return time.perf_counter() - t, image

    rules = {"chosen per view": chosen_rule, "8x everywhere": lambda *a, **k: 8.0}
    images = {name: frame(rule)[1] for name, rule in rules.items()}     # compiles both variants first
    levels = {}
    times: dict[str, list[float]] = {name: [] for name in rules}
    for _ in range(args.rounds):
        for name, rule in rules.items():
            runs = [frame(rule)[0] for _ in range(3)]
            times[name].append(statistics.median(runs))
            levels[name] = dict(r.last_anisotropy)
    print(f"{args.model.name}, {args.size}x{args.size} 4x MSAA, {args.rounds} rounds of 3 frames, alternated")
    for name in rules:
        t = times[name]
        print(f"  {name:16s} levels {levels[name]}  frame median {statistics.median(t):.3f} s "
              f"({min(t):.3f}-{max(t):.3f})")
    ratios = [a / b for a, b in zip(times["chosen per view"], times["8x everywhere"])]
    print(f"  chosen / 8x: {statistics.median(ratios):.2f}x ({min(ratios):.2f}-{max(ratios):.2f})")
    d = np.abs(images["chosen per view"][..., :3].astype(int) - images["8x everywhere"][..., :3].astype(int)).max(axis=2)
    print(f"  picture difference: mean {d.mean():.3f}/255, p99 {np.percentile(d, 99):.0f}/255, "
          f"{(d > 4).mean() * 100:.2f}% of pixels over 4/255")


if __name__ == "__main__":
    main()

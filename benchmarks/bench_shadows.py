"""Frame cost of shadow maps (alight.render.shadows); not a test. Prints the figures and writes
results/shadows.md.

    .venv/bin/python benchmarks/bench_shadows.py [--rounds 7] [--size 640x480]

Scenes: the built-in sphere and DamagedHelmet (../shared/data/models/DamagedHelmet), each under
royal_esplanade (its sun is taken out of the map and shadowed) at `medium` and one directional
light, 4x MSAA, read back as sRGB (what `alight render` writes to a PNG). Settings, alternated
in one process (A B C A B C ...), render + read back, medians and ranges:

- ``off``: --shadows off;
- ``auto``: the default (for the sphere: no shadow code, no depth pass);
- ``on``: shadows forced on, the maps drawn once and reused (a still scene, or the camera moving);
- ``on, maps redrawn``: the maps drawn again every frame (the cost of a frame where a light or
  the mesh changed).

Then the per-vertex occlusion bake of DamagedHelmet on its own (3 runs).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))

RESULTS = REPO / "benchmarks" / "results"
SHARED = REPO.parent / "shared" / "data"


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--rounds", type=int, default=7)
    parser.add_argument("--size", default="640x480")
    args = parser.parse_args()
    width, height = (int(x) for x in args.size.split("x"))

    from alight.core.mesh import sphere
    from alight.core.scene import Light, Scene
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    r = ForwardRenderer()
    env = load_environment(str(SHARED / "env" / "royal_esplanade_1k.hdr"))
    maps = r.bake(env, "medium")
    light = Light(kind="directional", vector=(-0.6, -0.5, -0.6), intensity=3.0)
    meshes = {"sphere": sphere(), "DamagedHelmet": load_mesh(str(SHARED / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"))}
    settings = {"off": ("off", False), "auto": ("auto", False), "on": ("on", False), "on, maps redrawn": ("on", True)}
    lines = [f"# Shadow maps: frame cost ({width}x{height}, 4x MSAA, royal_esplanade medium with its sun + 1 "
             f"directional light, {args.rounds} alternated rounds, ms: median [min-max])", "",
             "| scene | " + " | ".join(settings) + " | on / off | redrawn / off |", "|---" * (len(settings) + 3) + "|"]
    for name, mesh in meshes.items():
        times = {k: [] for k in settings}
        for _ in range(args.rounds + 1):      # the first round warms programs and maps up
            for key, (mode, redraw) in settings.items():
                scene = Scene(mesh=mesh, lights=[light], shadows=mode, occlusion="off")
                if redraw:
                    r.shadow_maps._key = None
                t = time.perf_counter()
                r.render(scene, maps, width, height, read_linear=False, read_srgb=True)
                times[key].append(time.perf_counter() - t)
        med = {k: statistics.median(v[1:]) * 1000 for k, v in times.items()}
        cells = [f"{med[k]:.1f} [{min(v[1:]) * 1000:.1f}-{max(v[1:]) * 1000:.1f}]" for k, v in times.items()]
        lines.append(f"| {name} | " + " | ".join(cells) + f" | {med['on'] / med['off']:.2f} | "
                     f"{med['on, maps redrawn'] / med['off']:.2f} |")
        print(lines[-1], flush=True)
    text = "\n".join(lines) + "\n"
    RESULTS.mkdir(exist_ok=True)
    (RESULTS / "shadows.md").write_text(text)
    print(text)
    r.release()


if __name__ == "__main__":
    main()

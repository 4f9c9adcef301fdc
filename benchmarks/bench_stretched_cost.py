"""The default IBL model's frame cost: `stretched` against `alight` (one fetch) on the built-in
sphere and DamagedHelmet, alternated in one process. Prints ratios; asserts nothing.

    .venv/bin/python benchmarks/bench_stretched_cost.py [PAIRS] [ROUGHNESS]   # defaults: 10, 0.7

Each pair renders the same scene with `alight` then `stretched` (1024x1024, royal_esplanade,
medium bake, MSAA, read back), after two warm-up pairs; the ratio of each pair's times is
printed as a median and a range. At ROUGHNESS <= 0.3 the sphere's pass compiles `stretched`'s
single fetch only, at >= 0.5 its two fetches only, between them both (STRETCHED_SPAN); the
helmet's roughness map keeps both. Results: benchmarks/results/stretched_cost.md.
"""

from __future__ import annotations

import os
import statistics
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))

from bench_scene_reference import camera_for  # noqa: E402

from alight.core.scene import Scene  # noqa: E402
from alight.exchange.meshes import load_mesh  # noqa: E402
from alight.exchange.presets import load_preset  # noqa: E402
from alight.ibl.bake import quality_named  # noqa: E402
from alight.ibl.environment import load_environment  # noqa: E402
from alight.render.renderer import ForwardRenderer  # noqa: E402

SHARED = HERE.parents[1] / "shared" / "data"
SIZE = 1024


def main() -> int:
    pairs = int(sys.argv[1]) if len(sys.argv) > 1 else 10
    roughness = float(sys.argv[2]) if len(sys.argv) > 2 else 0.7
    r = ForwardRenderer()
    maps = r.bake(load_environment(str(SHARED / "env" / "royal_esplanade_1k.hdr")), quality_named("medium"))
    gold = replace(load_preset("gold"), roughness=roughness)

    def frame(scene) -> float:
        t = time.perf_counter()
        r.render(scene, maps, SIZE, SIZE)
        return time.perf_counter() - t

    for name in ("sphere", str(SHARED / "models" / "DamagedHelmet" / "DamagedHelmet.gltf")):
        mesh = load_mesh(name)
        scene = Scene(mesh=mesh, material=gold, camera=camera_for(mesh, (SIZE, SIZE), 30.0, 20.0), view="camera")
        a, b = replace(scene, ibl_model="alight"), replace(scene, ibl_model="stretched")
        for _ in range(2):
            frame(a), frame(b)
        ratios, base = [], []
        for _ in range(pairs):
            ta, tb = frame(a), frame(b)
            ratios.append(tb / ta)
            base.append(ta)
        print(f"{Path(name).stem} r {roughness:g}: stretched/alight frame median {statistics.median(ratios):.3f}, "
              f"range {min(ratios):.3f}-{max(ratios):.3f} ({pairs} alternated pairs; alight's median "
              f"{1000 * statistics.median(base):.0f} ms on this machine)", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

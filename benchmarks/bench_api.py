"""The Python API rendering many materials under one environment (figures, not a test).

    .venv/bin/python benchmarks/bench_api.py [--materials 100] [--size 256]

Prints the open time, the first render (with the bake), and the mean time per further
material; the bake count shows the cache at work.
"""

from __future__ import annotations

import argparse
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

from alight import Material, Renderer

ENV = REPO.parent / "shared" / "data" / "env" / "venice_sunset_1k.hdr"


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--materials", type=int, default=100)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--quality", default="medium")
    args = ap.parse_args()
    t0 = time.perf_counter()
    with Renderer(args.size, quality=args.quality) as r:
        r.open().set_environment(str(ENV))
        t1 = time.perf_counter()
        r.render()
        t2 = time.perf_counter()
        for i in range(args.materials - 1):
            r.set_material(Material(base_color=(i / args.materials, 0.5, 0.3), roughness=(i % 10) / 9,
                                    metallic=float(i % 2)))
            r.render()
        t3 = time.perf_counter()
        print(f"open + load env {t1 - t0:.2f}s; first render incl. bake ({args.quality}) {t2 - t1:.2f}s; "
              f"{args.materials - 1} more materials {1000 * (t3 - t2) / (args.materials - 1):.1f} ms each "
              f"at {args.size}px; bakes run: {r.bakes_done}")


if __name__ == "__main__":
    main()

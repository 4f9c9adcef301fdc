"""Where a mesh's steady frame goes: the same view drawn with one feature at a time turned off,
alternated in one process (every configuration once per round), CPU time of the process per
frame (llvmpipe's threads included: on a shared machine the wall time swings with other jobs far
more than the work itself). Prints each configuration's median and its ratio to the default
frame, per round. Asserts nothing.

    .venv/bin/python benchmarks/bench_frame_parts.py [--mesh FILE] [--env MAP] [--size 1024] [--rounds 4]

Configurations (alight.Renderer's scene fields): the default (stretched IBL model, shadows and
occlusion 'auto'); the lecture's split sum (no compact sources taken out of the map, so no sun
shadow either); Karis' split sum (likewise); alight's single-fetch model; occlusion off;
shadows off; everything off with the single fetch; the base-colour debug view (shading almost
nothing: what rasterising, 4x MSAA, resolving and reading back cost).
"""

from __future__ import annotations

import argparse
import dataclasses
import statistics
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data"

CONFIGURATIONS = {
    "default": {},
    "lecture": {"ibl_model": "lecture"},
    "karis": {"ibl_model": "karis"},
    "alight (one fetch)": {"ibl_model": "alight"},
    "occlusion off": {"occlusion": "off"},
    "shadows off": {"shadows": "off"},
    "all off, one fetch": {"shadows": "off", "occlusion": "off", "ibl_model": "alight"},
    "base colour view": {"debug_view": 1},
}


def main() -> None:
    from alight.frontends.api import Renderer

    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--mesh", default=str(DATA / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"))
    ap.add_argument("--env", default=str(DATA / "env" / "royal_esplanade_1k.hdr"))
    ap.add_argument("--size", type=int, default=1024)
    ap.add_argument("--rounds", type=int, default=4)
    ap.add_argument("--frames", type=int, default=4, help="frames per configuration and round (default 4)")
    args = ap.parse_args()

    r = Renderer(args.size)
    r.set_mesh(args.mesh).set_environment(args.env)
    base = r.scene

    def frames(name: str, count: int, orbit0: float) -> float:
        r.scene = dataclasses.replace(base, **CONFIGURATIONS[name])
        times = []
        for i in range(count + 1):   # the first frame after a switch re-binds: not counted
            r.set_camera(orbit_deg=orbit0 + i)
            t = time.process_time()
            r.render()
            times.append(time.process_time() - t)
        return statistics.median(times[1:])

    for name in CONFIGURATIONS:   # compiles every variant before anything is timed
        frames(name, 1, 0.0)
    results: dict[str, list[float]] = {name: [] for name in CONFIGURATIONS}
    for round_ in range(args.rounds):
        for name in CONFIGURATIONS:
            results[name].append(frames(name, args.frames, 10.0 * round_))
        print(f"round {round_ + 1}: " + ", ".join(f"{n} {v[-1] * 1000:.0f} ms" for n, v in results.items()),
              flush=True)
    default = results["default"]
    for name, values in results.items():
        ratios = [v / d for v, d in zip(values, default)]
        print(f"{name:22s} CPU {statistics.median(values) * 1000:6.0f} ms a frame, / default "
              f"{statistics.median(ratios):.2f} ({min(ratios):.2f}-{max(ratios):.2f})")


if __name__ == "__main__":
    main()

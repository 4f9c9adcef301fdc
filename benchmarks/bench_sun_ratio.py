"""Issue 21's ratio: a cold ``alight render`` of a ~1M-triangle bumpy sphere against a ~10k one
(bake cached), under the built-in studio (no sun) and under royal_esplanade_1k (a sun: ``--shadows
auto`` runs the self-shadowing test and draws a shadow map), for two trees alternated.

Every figure is one fresh process (wall time, CPU time and peak RSS from GNU time). Each
round runs tree A then tree B (B then A on odd rounds), each tree every environment and mesh in
turn, so load on the shared machine falls on both trees alike. One untimed render per tree and
environment first fills the bake cache (shared, ``ALIGHT_CACHE_DIR``). Asserts nothing.

    .venv/bin/python benchmarks/bench_sun_ratio.py --meshes DIR --tree before=/tmp/base_py \\
        --tree after=/tmp/this_py --rounds 3

``--tree NAME=PYTHONPATH``: a folder whose ``alight`` is the tree to run (a symlink to its app/).
``--meshes DIR`` holds sphere_<N>.glb (bench_assets.bumpy_sphere, exported as bench_assets does);
the first of ``--sizes`` is the ratios' base.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_assets import SHARED  # noqa: E402


def cold(args: list[str], pythonpath: str, cache: str) -> tuple[float, float, float]:
    """(wall seconds, CPU seconds (user + system), peak RSS MiB) of one ``python -m alight
    render`` process, from GNU time around it (bench_assets.cold, plus the CPU time: on this
    shared machine other jobs stretch the wall time far more than the process's own CPU time)."""
    env = dict(os.environ, ALIGHT_CACHE_DIR=cache, PYTHONPATH=pythonpath)
    start = time.perf_counter()
    done = subprocess.run(["/usr/bin/time", "-f", "timed %U %S %M", sys.executable, "-m", "alight", "render", *args],
                          env=env, cwd=tempfile.gettempdir(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"alight render {' '.join(args)} failed: {done.stderr[-400:]}")
    _, user, system, peak = [line for line in done.stderr.splitlines() if line.startswith("timed ")][-1].split()
    return wall, float(user) + float(system), int(peak) / 1024.0


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--meshes", required=True)
    ap.add_argument("--tree", action="append", required=True, metavar="NAME=PYTHONPATH")
    ap.add_argument("--sizes", default="10000,1000000")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--envs", default="studio,royal_esplanade_1k")
    args = ap.parse_args()
    trees = dict(t.split("=", 1) for t in args.tree)
    sizes = [int(s) for s in args.sizes.split(",")]
    envs = {e: ("studio" if e == "studio" else str(SHARED / "env" / f"{e}.hdr")) for e in args.envs.split(",")}
    cache = tempfile.mkdtemp(prefix="alight-sun-ratio-cache-")
    out = str(Path(tempfile.gettempdir()) / "alight-sun-ratio.png")

    def render(tree: str, env: str, size: int):
        return cold(["--mesh", str(Path(args.meshes) / f"sphere_{size}.glb"), "--env", envs[env], "--out", out],
                    trees[tree], cache)

    for tree in trees:
        for env in envs:
            render(tree, env, sizes[0])
    walls: dict = {}
    cpus: dict = {}
    peaks: dict = {}
    names = list(trees)
    for r in range(args.rounds):
        for tree in (names if r % 2 == 0 else names[::-1]):
            for env in envs:
                line = []
                for size in sizes:
                    wall, cpu, peak = render(tree, env, size)
                    walls.setdefault((tree, env, size), []).append(wall)
                    cpus.setdefault((tree, env, size), []).append(cpu)
                    peaks.setdefault((tree, env, size), []).append(peak)
                    line.append(f"{size}: {wall:.2f} s (CPU {cpu:.2f} s) {peak:.0f} MiB")
                ratio = walls[(tree, env, sizes[-1])][-1] / walls[(tree, env, sizes[0])][-1]
                cpu_ratio = cpus[(tree, env, sizes[-1])][-1] / cpus[(tree, env, sizes[0])][-1]
                print(f"round {r + 1} {tree:>8} {env:>20}: " + ", ".join(line)
                      + f"; {sizes[-1]}/{sizes[0]} {ratio:.2f}x (CPU {cpu_ratio:.2f}x)", flush=True)
    print()
    for env in envs:
        for tree in names:
            ratios = [b / a for a, b in zip(walls[(tree, env, sizes[0])], walls[(tree, env, sizes[-1])])]
            cpu_ratios = [b / a for a, b in zip(cpus[(tree, env, sizes[0])], cpus[(tree, env, sizes[-1])])]
            cells = ", ".join(f"{s}: {statistics.median(walls[(tree, env, s)]):.2f} s "
                              f"({min(walls[(tree, env, s)]):.2f}-{max(walls[(tree, env, s)]):.2f}), "
                              f"peak {max(peaks[(tree, env, s)]):.0f} MiB" for s in sizes)
            print(f"{env:>20} {tree:>8}: {cells}; ratio median {statistics.median(ratios):.2f}x "
                  f"({min(ratios):.2f}-{max(ratios):.2f}), CPU-time ratio {statistics.median(cpu_ratios):.2f}x "
                  f"({min(cpu_ratios):.2f}-{max(cpu_ratios):.2f})")


if __name__ == "__main__":
    main()

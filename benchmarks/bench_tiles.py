"""Large output sizes: peak memory of `alight render` at each size, and what
drawing in tiles costs against one pass. Prints what it measured; asserts nothing.

    .venv/bin/python benchmarks/bench_tiles.py                 # 1024 .. 16384 (minutes: 16384 is 268 Mpixel)
    .venv/bin/python benchmarks/bench_tiles.py --sizes 1024 8192 --formats png

1. Peak RSS: `alight render --size N --quality low --out x.png|x.exr` in a subprocess per run
   (os.wait4's ru_maxrss of that child alone), with its wall time and the tile plan it used.
2. Tile overhead: the material ball at 2048x2048 (one pass on llvmpipe) against the same image
   forced into 1024x1024 and 512x512 tiles, in one process, alternated A B C A B C ..., medians
   and ranges of the wall time of ForwardRenderer.render.
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

REPO = Path(__file__).resolve().parents[1]


def peak_rss(size: int, fmt: str, folder: Path) -> tuple[float, float, int]:
    """(peak RSS in MiB, wall seconds, exit status) of one `alight render` child process."""
    out = folder / f"big.{fmt}"
    cmd = [sys.executable, "-m", "alight", "render", "--size", str(size), "--quality", "low", "--out", str(out)]
    start = time.perf_counter()
    proc = subprocess.Popen(cmd, cwd=REPO, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - start
    err = proc.stderr.read().decode()
    proc.stderr.close()
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode:
        print(f"  exit {proc.returncode}: {err.strip().splitlines()[-1] if err.strip() else ''}")
    out.unlink(missing_ok=True)
    return usage.ru_maxrss / 1024.0, wall, proc.returncode


def plan_line(size: int) -> str:
    from alight.render.tiles import framebuffer_bytes, plan_tiles

    plan = plan_tiles(size, size, 16384, framebuffer_bytes("msaa", 4))
    if plan.single:
        return "one pass"
    strips = plan.strips()
    return f"{len(strips)} strips x {len(strips[0])} tiles of {plan.tile_width}x{plan.tile_height}"


def tile_overhead(repeats: int) -> None:
    from alight.core.mesh import sphere
    from alight.core.scene import Scene
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    r = ForwardRenderer()
    maps = r.bake(load_environment(str(REPO.parent / "shared" / "data" / "env" / "royal_esplanade_1k.hdr")), "low")
    scene = Scene(mesh=sphere())
    variants = {"one pass": None, "1024x1024 tiles": (1024, 1024), "512x512 tiles": (512, 512)}
    times = {name: [] for name in variants}
    for name, tile in variants.items():       # warm up: compile, allocate
        r.render(scene, maps, 2048, 2048, tile=tile)
    for _ in range(repeats):
        for name, tile in variants.items():
            t = time.perf_counter()
            r.render(scene, maps, 2048, 2048, tile=tile)
            times[name].append(time.perf_counter() - t)
    base = statistics.median(times["one pass"])
    for name, ts in times.items():
        med = statistics.median(ts)
        print(f"  {name:16s} median {med:.2f} s  (range {min(ts):.2f}-{max(ts):.2f} s)  {med / base:.2f}x one pass")
    r.release()


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", type=int, nargs="+", default=[1024, 4096, 8192, 16384])
    ap.add_argument("--formats", nargs="+", default=["png", "exr"], choices=["png", "exr"])
    ap.add_argument("--repeats", type=int, default=5, help="tile overhead: runs of each variant (default 5)")
    ap.add_argument("--skip-overhead", action="store_true")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        os.environ["ALIGHT_CACHE_DIR"] = str(Path(tmp) / "cache")
        print(f"peak RSS of 'alight render --size N --quality low' (machine: {os.cpu_count()} cores, shared)")
        for size in args.sizes:
            for fmt in args.formats:
                rss, wall, status = peak_rss(size, fmt, Path(tmp))
                print(f"  {size:5d}^2 .{fmt}: peak RSS {rss:7.0f} MiB  wall {wall:6.1f} s  exit {status}  "
                      f"({plan_line(size)})", flush=True)
        if not args.skip_overhead:
            print(f"tile overhead: the material ball at 2048x2048, MSAA, {args.repeats} alternated runs each")
            tile_overhead(args.repeats)


if __name__ == "__main__":
    main()

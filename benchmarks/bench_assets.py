"""Scaling of a cold ``alight render`` with its inputs: triangles, texture size, environment size
and output size. Every figure is one fresh process (``python -m alight render ... --out x.png``),
its wall time and its peak resident memory; rounds run the
whole set in turn (A B A B ...), so load on the shared machine falls on every column alike, and
the tables give medians, ranges and each row's ratio to the table's first row. Asserts nothing.

    .venv/bin/python benchmarks/bench_assets.py                   # quick: about 10 min on 2 loaded cores
    .venv/bin/python benchmarks/bench_assets.py --full            # adds 4M triangles, 8k textures, 4k maps, 4096² output
    .venv/bin/python benchmarks/bench_assets.py --against main    # the triangle table for another git ref too
    .venv/bin/python benchmarks/bench_assets.py --triangles-only 10000,1000000,4000000 --against main
                                                                  # only those meshes: results/assets_triangles.md

The inputs are generated into a temporary folder: a closed, bumpy UV sphere of N triangles with
normals and uvs (.glb and .ply: the .ply without normals, so alight computes them), a 2 x 2
quad whose base colour is a noise texture of S x S texels, and royal_esplanade_1k.hdr repeated
up to W x W/2 (the bake runs: an empty ``ALIGHT_CACHE_DIR`` per process, Mesa's shader cache
left as the machine has it). Results: ``results/assets.md`` (``assets_quick.md`` without --full).
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

import numpy as np

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
from bench_gltf import export  # noqa: E402  (the other ref exported with git archive)

SHARED = REPO.parent / "shared" / "data"


def bumpy_sphere(triangles: int):
    """(positions, faces, uvs, normals) of a closed UV sphere with about ``triangles`` faces."""
    rings = max(4, int(round((triangles / 4) ** 0.5)))
    seg = 2 * rings
    i, j = np.meshgrid(np.arange(rings + 1), np.arange(seg + 1), indexing="ij")
    theta, phi = np.pi * i / rings, 2 * np.pi * j / seg
    n = np.stack([-np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], -1).reshape(-1, 3)
    p = n * (1 + 0.03 * np.sin(13 * n[:, 0]) * np.sin(11 * n[:, 1]) * np.sin(7 * n[:, 2]))[:, None]
    a = (i[:-1, :-1] * (seg + 1) + j[:-1, :-1]).ravel()
    row = np.repeat(np.arange(rings), seg)
    b, c = a + 1, a + seg + 1
    f = np.concatenate([np.stack([a, c, c + 1], -1)[row != rings - 1], np.stack([a, c + 1, b], -1)[row != 0]])
    uv = np.stack([(j / seg).ravel(), (1 - i / rings).ravel()], -1)
    return p, f, uv, n


def make_inputs(folder: Path, triangles, textures, environments) -> dict:
    import trimesh
    from PIL import Image

    out = {"mesh": {}, "texture": {}, "env": {}}
    for t in triangles:
        p, f, uv, n = bumpy_sphere(t)
        m = trimesh.Trimesh(p, f, vertex_normals=n, process=False)
        m.visual = trimesh.visual.TextureVisuals(uv=uv)
        m.export(folder / f"sphere_{t}.glb", include_normals=True)
        trimesh.Trimesh(p, f, process=False).export(folder / f"sphere_{t}.ply")
        out["mesh"][t] = len(f)
    rng = np.random.default_rng(1)
    for s in textures:
        image = Image.fromarray(rng.integers(0, 256, (s, s, 3), dtype=np.uint8))
        quad = trimesh.Trimesh([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], [[0, 1, 2], [0, 2, 3]], process=False)
        quad.visual = trimesh.visual.TextureVisuals(uv=[[0, 0], [1, 0], [1, 1], [0, 1]], image=image)
        quad.export(folder / f"quad_{s}.glb")
    import OpenImageIO as oiio

    base = oiio.ImageBuf(str(SHARED / "env" / "royal_esplanade_1k.hdr")).get_pixels(oiio.FLOAT)[..., :3]
    for w in environments:
        k = max(1, w // base.shape[1])
        rad = np.ascontiguousarray(np.repeat(np.repeat(base, k, 0), k, 1), np.float32)
        path = folder / f"env_{w}.hdr"
        o = oiio.ImageOutput.create(str(path))
        o.open(str(path), oiio.ImageSpec(rad.shape[1], rad.shape[0], 3, oiio.FLOAT))
        o.write_image(rad)
        o.close()
    return out


def cold(args: list[str], pythonpath: str | None, cache: str) -> tuple[float, float]:
    """(wall seconds, peak RSS MiB) of one ``python -m alight render`` process. The peak comes
    from GNU time's %M around it: ``os.wait4``'s ru_maxrss of a child forked from this process
    never reads below this process's own size (hundreds of MiB once the inputs are made)."""
    env = dict(os.environ, ALIGHT_CACHE_DIR=cache)
    if pythonpath:
        env["PYTHONPATH"] = pythonpath
    else:
        env.pop("PYTHONPATH", None)
    start = time.perf_counter()
    done = subprocess.run(["/usr/bin/time", "-f", "peak_kib %M", sys.executable, "-m", "alight", "render", *args],
                          env=env, cwd=tempfile.gettempdir(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                          text=True)
    wall = time.perf_counter() - start
    if done.returncode != 0:
        raise SystemExit(f"alight render {' '.join(args)} failed: {done.stderr[-400:]}")
    peak = [line for line in done.stderr.splitlines() if line.startswith("peak_kib ")][-1]
    return wall, int(peak.split()[1]) / 1024.0


def table(title: str, rows: dict, unit: str) -> list[str]:
    lines = [f"### {title}", "", f"| {unit} | wall median (range) | × first row (range over rounds) | peak RSS |",
             "| --- | --- | --- | --- |"]
    first = next(iter(rows.values()))
    for name, runs in rows.items():
        walls = [w for w, _ in runs]
        ratios = [w / f for (w, _), (f, _) in zip(runs, first)]
        rss = max(r for _, r in runs)
        lines.append(f"| {name} | {statistics.median(walls):.2f} s ({min(walls):.2f}-{max(walls):.2f}) | "
                     f"{statistics.median(ratios):.2f}x ({min(ratios):.2f}-{max(ratios):.2f}) | {rss:.0f} MiB |")
    return lines + [""]


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true")
    ap.add_argument("--rounds", type=int, default=2)
    ap.add_argument("--against", default=None, help="a git ref whose triangle table runs alternated with this tree's")
    ap.add_argument("--only", default="triangles,textures,environments,outputs")
    ap.add_argument("--triangles-only", default=None, metavar="N,N,...",
                    help="only the triangle table, for these triangle counts (the first is the ratios' base)")
    args = ap.parse_args()
    only = set(args.only.split(","))
    triangles = [10_000, 1_000_000] + ([4_000_000] if args.full else [])
    if args.triangles_only:
        only = {"triangles"}
        triangles = [int(t) for t in args.triangles_only.split(",")]
    textures = [1024, 2048, 4096] + ([8192] if args.full else [])
    environments = [1024, 2048] + ([4096] if args.full else [])
    outputs = [512, 1024, 2048] + ([4096] if args.full else [])
    with tempfile.TemporaryDirectory(prefix="alight-assets-") as tmp:
        folder = Path(tmp)
        print("generating inputs ...", flush=True)
        made = make_inputs(folder, triangles if "triangles" in only else [],
                           textures if "textures" in only else [],
                           environments if "environments" in only else [])
        trees = {"this tree": None}
        if args.against:
            trees[args.against] = str(export(args.against, folder / "other"))
        cache = str(folder / "cache")   # the studio's bake, shared: only the environments table bakes
        results: dict[str, dict] = {}

        def add(key: str, row: str, run_args: list[str], pythonpath=None, own_cache=False):
            c = str(folder / f"cache_{time.monotonic_ns()}") if own_cache else cache
            wall, rss = cold(run_args, pythonpath, c)
            results.setdefault(key, {}).setdefault(row, []).append((wall, rss))
            print(f"  {key:36s} {row:28s} {wall:7.2f} s {rss:6.0f} MiB", flush=True)

        out = str(folder / "out.png")
        cold(["--out", out, "--size", "64"], None, cache)   # fills the BRDF LUT and the studio bake once
        for r in range(args.rounds):
            print(f"round {r + 1}/{args.rounds}", flush=True)
            if "triangles" in only:
                for tree, path in trees.items():
                    for t in triangles:
                        for ext in ("glb", "ply"):
                            add(f"triangles .{ext}, {tree}", f"{made['mesh'][t]:,} triangles",
                                ["--mesh", str(folder / f"sphere_{t}.{ext}"), "--out", out], path)
            if "textures" in only:
                for s in textures:
                    add("texture size", f"{s}x{s}", ["--mesh", str(folder / f"quad_{s}.glb"), "--out", out])
            if "environments" in only:
                for w in environments:
                    add("environment size (empty bake cache)", f"{w}x{w // 2}",
                        ["--env", str(folder / f"env_{w}.hdr"), "--out", out], own_cache=True)
            if "outputs" in only:
                for s in outputs:
                    add("output size (built-in ball)", f"{s}x{s}", ["--out", out, "--size", str(s)])
    lines = ["# Cold `alight render` against its inputs (benchmarks/bench_assets.py)", "",
             f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, {args.rounds} rounds alternated, "
             f"{'--triangles-only ' + args.triangles_only if args.triangles_only else '--full' if args.full else 'quick'}"
             f"{', against ' + args.against if args.against else ''}; one fresh process per figure (imports, GL context, load, "
             "bake or bake-cache load, first frame with its shader compiles, PNG write). 1024x1024 4x MSAA "
             "unless the table varies the output size.", ""]
    for key, rows in results.items():
        lines += table(key, rows, "input")
    name = "assets_triangles.md" if args.triangles_only else "assets.md" if args.full else "assets_quick.md"
    (REPO / "benchmarks" / "results" / name).write_text("\n".join(lines))
    print("\n".join(lines))


if __name__ == "__main__":
    main()

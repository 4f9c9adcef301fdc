"""The visibility bake (app/core/visibility.py) against the path-traced scene reference: the corner
(a floor, two walls and a box) under maps of ../shared/data/env, alight with --occlusion off and on,
binned 4x4 linear relMAE; and the cost: bake time, frame time off/on alternated A B A B.
Prints a table and writes benchmarks/results/occlusion.md; asserts nothing.

The path tracer lives on its own branch (app/accuracy/path_trace.py, app/accuracy/scenes.py of
`ptrace`); this script takes its references as files, made by that branch's Python:

    PYTHONPATH=/work/wt-ptrace /work/wt-ptrace/.venv/bin/python benchmarks/bench_occlusion.py --make-references DIR
    .venv/bin/python benchmarks/bench_occlusion.py --references DIR
"""

from __future__ import annotations

import argparse
import os
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ENV_DIR = HERE.parent.parent / "shared" / "data" / "env"
MAPS = ("royal_esplanade_1k", "venice_sunset_1k", "moonless_golf_1k")
MATERIALS = {"grey dielectric r0.5": dict(base_color=(0.7, 0.7, 0.7), metallic=0.0, roughness=0.5),
             "gold r0.7": dict(base_color=(1.0, 0.766, 0.336), metallic=1.0, roughness=0.7)}
VIEW = (30.0, 25.0)   # the corner's (orbit, elevation), as the path tracer's bench_scene_reference


def binned_relative_mae(test, ref, factor=4):
    """sum |T_b - R_b| / sum R_b over factor x factor blocks covered (alpha 1) in both: the
    measure of app/accuracy/binned.py on the path tracer's branch (repeated here to stay off it)."""
    def sums(img):
        h, w = img.shape[0] // factor * factor, img.shape[1] // factor * factor
        return img[:h, :w].reshape(h // factor, factor, w // factor, factor, -1).sum(axis=(1, 3))
    full = ((test[..., 3] >= 1.0) & (ref[..., 3] >= 1.0)).astype(np.float64)[..., None]
    keep = sums(full)[..., 0] >= factor * factor - 0.5
    t, r = sums(np.asarray(test, np.float64)[..., :3]), sums(np.asarray(ref, np.float64)[..., :3])
    return float(np.abs(t[keep] - r[keep]).sum() / max(r[keep].sum(), 1e-30))


def camera_for(mesh, size):
    from alight.core.scene import orbit_camera

    centre, radius = mesh.bounding_sphere()
    return orbit_camera(centre, radius, size[0] / size[1], VIEW[0], VIEW[1], None, 35.0, None, corners=mesh.corners())


def make_references(folder: Path, size: int, samples: int) -> None:
    from alight.accuracy.path_trace import TraceSettings, trace
    from alight.accuracy.scenes import write_scene
    from alight.core.material import Material
    from alight.core.scene import Scene
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment

    folder.mkdir(parents=True, exist_ok=True)
    obj = write_scene("corner", folder)
    mesh = load_mesh(str(obj))
    for name in MAPS:
        env = load_environment(str(ENV_DIR / f"{name}.hdr"))
        for label, fields in MATERIALS.items():
            out = folder / f"{name}__{label.replace(' ', '_')}.npy"
            if out.exists():
                continue
            scene = Scene(mesh=mesh, material=Material(**fields), camera=camera_for(mesh, (size, size)))
            start = time.perf_counter()
            ref = trace(scene, env.radiance, size, size, TraceSettings(samples=samples, seed=0)).linear
            np.save(out, ref)
            print(f"{name} {label}: traced in {time.perf_counter() - start:.1f} s", flush=True)


def measure(folder: Path, size: int, repeats: int) -> None:
    from alight.core.material import Material
    from alight.core.scene import Scene
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    mesh = load_mesh(str(folder / "corner.obj"))
    renderer = ForwardRenderer(bake_cache=None)
    rows = []
    camera = camera_for(mesh, (size, size))
    for name in MAPS:
        env = load_environment(str(ENV_DIR / f"{name}.hdr"))
        maps = renderer.bake(env, "medium")
        for label, fields in MATERIALS.items():
            ref = np.load(folder / f"{name}__{label.replace(' ', '_')}.npy")
            errors = {}
            for mode in ("off", "on"):
                scene = Scene(mesh=mesh, material=Material(**fields), camera=camera, occlusion=mode)
                img = renderer.render(scene, maps, size, size, read_linear=True, read_srgb=False).linear
                errors[mode] = 100.0 * binned_relative_mae(img, ref)
            rows.append((name, label, errors["off"], errors["on"]))
            print(f"{name:22s} {label:22s} off {errors['off']:5.1f}%  on {errors['on']:5.1f}%", flush=True)
    # Cost: the bake (fresh renderer state, no disk cache) and frames alternated off/on.
    from alight.core.visibility import bake_visibility

    bake_s = []
    for _ in range(2):
        bake_s.append(bake_visibility(mesh).seconds)
    env = load_environment(str(ENV_DIR / f"{MAPS[0]}.hdr"))
    maps = renderer.bake(env, "medium")
    times = {"off": [], "on": []}
    frame = 256
    scenes = {m: Scene(mesh=mesh, material=Material(**MATERIALS["grey dielectric r0.5"]), camera=camera_for(mesh, (frame, frame)),
                       occlusion=m) for m in ("off", "on")}
    for m in ("off", "on"):   # warm: programs compiled, bake done
        renderer.render(scenes[m], maps, frame, frame)
    for _ in range(repeats):
        for m in ("off", "on"):
            start = time.perf_counter()
            renderer.render(scenes[m], maps, frame, frame)
            times[m].append(time.perf_counter() - start)
    med = {m: float(np.median(v)) for m, v in times.items()}
    lines = ["# The visibility bake against the path-traced corner", "",
             f"{size}x{size} px; references from the path tracer's branch (its --samples, seed 0), "
             "binned 4x4 linear relMAE; alight: medium bake, default IBL model, MSAA.", "",
             "| environment | material | occlusion off % | occlusion on % |", "|---|---|---|---|"]
    lines += [f"| {a} | {b} | {c:.1f} | {d:.1f} |" for a, b, c, d in rows]
    lines += ["", f"bake (corner, default settings, twice): "
              + ", ".join(f"{s:.2f} s" for s in bake_s),
              f"frame {frame}x{frame}, alternated A B x{repeats}, median: off {med['off'] * 1e3:.1f} ms, "
              f"on {med['on'] * 1e3:.1f} ms (ratio {med['on'] / med['off']:.2f}; off runs "
              f"{min(times['off']) * 1e3:.1f}-{max(times['off']) * 1e3:.1f} ms, on runs "
              f"{min(times['on']) * 1e3:.1f}-{max(times['on']) * 1e3:.1f} ms)"]
    print("\n".join(lines[-2:]))
    (HERE / "results").mkdir(exist_ok=True)
    (HERE / "results" / "occlusion.md").write_text("\n".join(lines) + "\n")


def main() -> None:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--make-references", type=Path, metavar="DIR")
    p.add_argument("--references", type=Path, metavar="DIR")
    p.add_argument("--size", type=int, default=64)
    p.add_argument("--samples", type=int, default=128)
    p.add_argument("--repeats", type=int, default=5)
    args = p.parse_args()
    os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))
    if args.make_references:
        make_references(args.make_references, args.size, args.samples)
    if args.references:
        measure(args.references, args.size, args.repeats)
    if not (args.make_references or args.references):
        p.error("give --make-references DIR (with the path tracer's branch) or --references DIR")


if __name__ == "__main__":
    sys.exit(main())

"""alight's render against the whole-scene ground truth (app/accuracy/path_trace.py), and every
IBL model on flat faces and oblique views against the exact reference. Prints and writes tables;
asserts nothing.

    .venv/bin/python benchmarks/bench_scene_reference.py                 # both parts, every map (~25 min on 2 cores)
    .venv/bin/python benchmarks/bench_scene_reference.py --part scenes   # the test scenes and the sphere
    .venv/bin/python benchmarks/bench_scene_reference.py --part oblique  # the IBL models, plane and sphere, 0/30/60 deg
    .venv/bin/python benchmarks/bench_scene_reference.py --part agreement  # the path tracer vs the exact sum, sphere
    .venv/bin/python benchmarks/bench_scene_reference.py --quick         # royal_esplanade only

Part "scenes": the corner, bowl and product of app/accuracy/scenes.py and the built-in sphere,
each under every 2:1 map of ../shared/data/env, rendered by alight (default settings: medium
quality, the default IBL model, MSAA) and path-traced (256 samples, seed 0); linear relMAE after
4x4 binning over the blocks covered in both. Also the exact texel sum (alight reference
--integrator exact, no occlusion) against both, which splits the gap into alight's own IBL error
(render vs exact) and what visibility adds (exact vs path). Noise: the path tracer against
itself with seed 1 (binned), on royal_esplanade.

Part "oblique": each IBL model (alight render --ibl) on the built-in plane and the sphere seen
from 0, 30 and 60 degrees of elevation (the plane from 10 instead of 0: at 0 it is edge-on),
against the exact texel sum (noise-free, so per-pixel relMAE over the pixels covered in both).

Results: benchmarks/results/scene_reference.md/.csv and oblique_ibl.md/.csv; with --pictures DIR
also the corner beside its reference as a PNG.
"""

from __future__ import annotations

import argparse
import csv
import os
import sys
import tempfile
import time
from dataclasses import replace
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
RESULTS = HERE / "results"
os.environ.setdefault("ALIGHT_CACHE_DIR", tempfile.mkdtemp(prefix="alight-bench-cache-"))

from alight.accuracy.binned import binned_relative_mae  # noqa: E402
from alight.accuracy.chart import default_env_dir, equirect_envs  # noqa: E402
from alight.accuracy.path_trace import TraceSettings, trace  # noqa: E402
from alight.accuracy.reference import ReferenceRenderer  # noqa: E402
from alight.accuracy.scenes import SCENE_VIEWS, SCENES, write_scene  # noqa: E402
from alight.core.ibl_models import DEFAULT_IBL_MODEL, IBL_MODELS  # noqa: E402
from alight.core.material import Material  # noqa: E402
from alight.core.scene import Scene, orbit_camera  # noqa: E402
from alight.exchange.meshes import load_mesh  # noqa: E402
from alight.exchange.presets import load_preset  # noqa: E402
from alight.ibl.bake import quality_named  # noqa: E402
from alight.ibl.environment import load_environment  # noqa: E402
from alight.render.renderer import ForwardRenderer  # noqa: E402


EXACT_ON = ("royal_esplanade", "venice_sunset")


def materials():
    gold = load_preset("gold")
    return {
        "gold r0.3": replace(gold, roughness=0.3),
        "gold r0.4": replace(gold, roughness=0.4),
        "gold r0.5": replace(gold, roughness=0.5),
        "gold r0.7": replace(gold, roughness=0.7),
        "red dielectric r0.5": Material(base_color=(0.8, 0.1, 0.1), metallic=0.0, roughness=0.5),
        "grey dielectric r0.5": Material(base_color=(0.7, 0.7, 0.7), metallic=0.0, roughness=0.5),
    }


def camera_for(mesh, size, orbit, elevation):
    centre, radius = mesh.bounding_sphere()
    return orbit_camera(centre, radius, size[0] / size[1], orbit, elevation, None, 35.0, None, corners=mesh.corners())


def write_md(path: Path, title: str, header: list[str], rows: list[list], notes: list[str]) -> None:
    lines = [f"# {title}", "", *notes, "", "| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    lines += ["| " + " | ".join(str(c) for c in r) + " |" for r in rows]
    path.write_text("\n".join(lines) + "\n")


def write_csv(path: Path, header, rows) -> None:
    with open(path, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(header)
        w.writerows(rows)


def part_scenes(envs, renderer, exact, size, samples, pictures: Path | None, suffix: str) -> None:
    mats = materials()
    folder = Path(tempfile.mkdtemp(prefix="alight-scenes-"))
    cases = [(name, str(write_scene(name, folder)), SCENE_VIEWS[name], ["grey dielectric r0.5", "gold r0.7"])
             for name in SCENES]
    cases.append(("sphere", "sphere", (0.0, 0.0), ["gold r0.3", "gold r0.7", "red dielectric r0.5"]))
    notes = [f"{size[0]}x{size[1]} px, path tracer {samples} samples a pixel (seed 0), max 8 bounces; relMAE "
             "(linear RGB) after 4x4 binning over the blocks covered in both images. render: `alight render` "
             "defaults (medium, the default IBL model, MSAA); exact: `alight reference --integrator exact` (no "
             "occlusion; on royal_esplanade and venice_sunset only, for time); path: `alight reference "
             "--integrator path`. path noise: seed 1 against seed 0, "
             "divided by sqrt(2). Views (orbit, elevation): " +
             ", ".join(f"{k} {v}" for k, v in SCENE_VIEWS.items()) + ", sphere (0, 0)."]
    header = ["scene", "environment", "material", "render vs path %", "render vs exact %", "exact vs path %",
              "path noise %", "trace s", "exact s"]
    rows = []
    for env_path in envs:
        env = load_environment(env_path)
        env_name = Path(env_path).stem
        maps = renderer.bake(env, quality_named("medium"))
        for scene_name, mesh_spec, (orbit, elevation), mat_names in cases:
            mesh = load_mesh(mesh_spec)
            camera = camera_for(mesh, size, orbit, elevation)
            for mat_name in mat_names:
                scene = Scene(mesh=mesh, material=mats[mat_name], camera=camera, view="camera",
                              ibl_model=DEFAULT_IBL_MODEL)
                render = renderer.render(scene, maps, size[0], size[1], read_linear=True, read_srgb=False).linear
                t0 = time.perf_counter()
                ref = trace(scene, env.radiance, size[0], size[1], TraceSettings(samples=samples, seed=0)).linear
                t1 = time.perf_counter()
                # the exact sum costs pixels x texels: on the two maps of the split only (2 cores)
                split = any(k in env_name for k in EXACT_ON)
                ex = exact.render(scene, env.radiance, size[0], size[1]).linear if split else None
                t2 = time.perf_counter()
                noise = ""
                if "royal_esplanade" in env_name:
                    other = trace(scene, env.radiance, size[0], size[1], TraceSettings(samples=samples, seed=1)).linear
                    # the difference of two independent estimates has sqrt(2) times one's noise
                    noise = f"{100 * binned_relative_mae(other, ref, 4) / np.sqrt(2):.2f}"
                    if pictures is not None and scene_name == "corner" and mat_name.startswith("grey"):
                        save_pictures(pictures, render, ref, ex)
                row = [scene_name, env_name, mat_name, f"{100 * binned_relative_mae(render, ref, 4):.1f}",
                       f"{100 * binned_relative_mae(render, ex, 4):.1f}" if split else "",
                       f"{100 * binned_relative_mae(ex, ref, 4):.1f}" if split else "",
                       noise, f"{t1 - t0:.1f}", f"{t2 - t1:.1f}" if split else ""]
                rows.append(row)
                print(" | ".join(row), flush=True)
                write_md(RESULTS / f"scene_reference{suffix}.md", "alight render against the path-traced scene "
                         "reference", header, rows, notes)
                write_csv(RESULTS / f"scene_reference{suffix}.csv", header, rows)
    write_md(RESULTS / f"scene_reference{suffix}.md", "alight render against the path-traced scene reference",
             header, rows, notes)
    write_csv(RESULTS / f"scene_reference{suffix}.csv", header, rows)


def save_pictures(folder: Path, render, ref, exact) -> None:
    from PIL import Image

    from alight.accuracy.metrics import tonemapped_srgb

    folder.mkdir(parents=True, exist_ok=True)
    tiles = []
    for img in (render, exact, ref):
        t = tonemapped_srgb(img)
        if t.dtype != np.uint8:
            t = (np.clip(t, 0.0, 1.0) * 255.0 + 0.5).astype(np.uint8)
        tiles.append(t[..., :3])
    gap = np.full((tiles[0].shape[0], 4, 3), 255, np.uint8)
    row = np.concatenate([tiles[0], gap, tiles[1], gap, tiles[2]], axis=1)
    Image.fromarray(row).save(folder / "ptrace_corner.png", optimize=True)
    print(folder / "ptrace_corner.png")


def part_oblique(envs, renderer, exact, size, suffix: str) -> None:
    mats = materials()
    notes = [f"{size[0]}x{size[1]} px, no anti-aliasing (the exact reference samples pixel centres); relMAE % "
             "(linear RGB) per pixel over the pixels covered in both, against `alight reference --integrator exact` "
             "from the same camera (orbit 0, the elevation given). Medium quality bake. The plane is the built-in "
             "XZ plane facing +Y (at elevation 0 it is edge-on, so 10 degrees there)."]
    header = ["mesh", "elevation", "environment", "material", *IBL_MODELS, f"{DEFAULT_IBL_MODEL}/lecture"]
    rows = []
    views = [("plane", (10.0, 30.0, 60.0)), ("sphere", (0.0, 30.0, 60.0))]
    for env_path in envs:
        env = load_environment(env_path)
        env_name = Path(env_path).stem
        maps = renderer.bake(env, quality_named("medium"))
        for mesh_name, elevations in views:
            mesh = load_mesh(mesh_name)
            for elevation in elevations:
                camera = camera_for(mesh, size, 0.0, elevation)
                for mat_name in ("gold r0.3", "gold r0.4", "gold r0.5", "gold r0.7", "red dielectric r0.5"):
                    scene = Scene(mesh=mesh, material=mats[mat_name], camera=camera, view="camera")
                    ex = exact.render(scene, env.radiance, size[0], size[1]).linear
                    errors = {}
                    for model in IBL_MODELS:
                        s = replace(scene, ibl_model=model)
                        img = renderer.render(s, maps, size[0], size[1], aa="none", read_linear=True,
                                              read_srgb=False).linear
                        errors[model] = binned_relative_mae(img, ex, 1)
                    ratio = errors[DEFAULT_IBL_MODEL] / max(errors["lecture"], 1e-12)
                    row = [mesh_name, f"{elevation:g}", env_name, mat_name,
                           *[f"{100 * errors[m]:.1f}" for m in IBL_MODELS], f"{ratio:.2f}"]
                    rows.append(row)
                    print(" | ".join(row), flush=True)
                    write_md(RESULTS / f"oblique_ibl{suffix}.md", "Every IBL model on flat faces and oblique views",
                             header, rows, notes)
                    write_csv(RESULTS / f"oblique_ibl{suffix}.csv", header, rows)
    write_md(RESULTS / f"oblique_ibl{suffix}.md", "Every IBL model on flat faces and oblique views", header, rows,
             notes)
    write_csv(RESULTS / f"oblique_ibl{suffix}.csv", header, rows)


def part_agreement(envs, exact, size, samples, suffix: str) -> None:
    """The engine check: the path tracer on the built-in sphere (nothing to occlude) against
    the exact texel sum, pixel centres in both (no jitter), every map, three materials."""
    mats = materials()
    mesh = load_mesh("sphere")
    # The renderer draws the built-in sphere with fewer segments where the image is small (16 at
    # 32 px: alight.core.sphere_lod), the G-buffer of the exact sum too; the path tracer takes
    # the mesh as given. Same geometry in both: the sphere as a plain mesh.
    mesh.lod_sphere = None
    header = ["environment", "material", "binned relMAE %", "mean ratio path/exact", "trace s", "exact s"]
    notes = [f"{size[0]}x{size[1]} px, {samples} samples a pixel (seed 0), pixel centres; relMAE (linear RGB) after "
             "4x4 binning, and the ratio of the summed radiance over the pixels covered in both. The sphere is the "
             "built-in 128-segment mesh in both (no level of detail)."]
    rows = []
    for env_path in envs:
        env = load_environment(env_path)
        for mat_name in ("gold r0.3", "gold r0.7", "red dielectric r0.5"):
            scene = Scene(mesh=mesh, material=mats[mat_name], view="camera")
            t0 = time.perf_counter()
            ref = trace(scene, env.radiance, size[0], size[1], TraceSettings(samples=samples, jitter=False)).linear
            t1 = time.perf_counter()
            ex = exact.render(scene, env.radiance, size[0], size[1]).linear
            t2 = time.perf_counter()
            both = (ref[..., 3] == 1.0) & (ex[..., 3] == 1.0)
            ratio = ref[both, :3].sum() / ex[both, :3].sum()
            row = [Path(env_path).stem, mat_name, f"{100 * binned_relative_mae(ref, ex, 4):.2f}", f"{ratio:.4f}",
                   f"{t1 - t0:.1f}", f"{t2 - t1:.1f}"]
            rows.append(row)
            print(" | ".join(row), flush=True)
            write_md(RESULTS / f"path_vs_exact_sphere{suffix}.md", "The path tracer against the exact reference "
                     "on the sphere", header, rows, notes)
            write_csv(RESULTS / f"path_vs_exact_sphere{suffix}.csv", header, rows)


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--part", choices=("scenes", "oblique", "agreement", "all"), default="all")
    ap.add_argument("--quick", action="store_true", help="royal_esplanade only")
    ap.add_argument("--size", type=int, default=80)
    ap.add_argument("--samples", type=int, default=256)
    ap.add_argument("--oblique-size", type=int, default=48)
    ap.add_argument("--pictures", type=Path, help="write the corner beside its reference into this folder")
    ap.add_argument("--only", metavar="A,B", help="only the maps whose names contain one of these (comma-separated)")
    ap.add_argument("--suffix", default="", help="appended to the result files' names (a run split over processes)")
    args = ap.parse_args()
    env_dir = default_env_dir()
    if env_dir is None:
        print("no ../shared/data/env", file=sys.stderr)
        return 1
    envs, skipped = equirect_envs(env_dir)
    for line in skipped:
        print(f"skipped {line}", file=sys.stderr)
    if args.quick:
        envs = [e for e in envs if "royal_esplanade" in e]
    if args.only:
        envs = [e for e in envs if any(k in Path(e).name for k in args.only.split(","))]
    suffix = ("_quick" if args.quick else "") + args.suffix
    RESULTS.mkdir(exist_ok=True)
    renderer = ForwardRenderer()
    exact = ReferenceRenderer(renderer)
    size = (args.size, args.size)
    start = time.perf_counter()
    if args.part in ("scenes", "all"):
        part_scenes(envs, renderer, exact, size, args.samples, args.pictures, suffix)
    if args.part in ("agreement", "all"):
        part_agreement(envs, exact, (32, 32), 512, suffix)
    if args.part in ("oblique", "all"):
        part_oblique(envs, renderer, exact, (args.oblique_size, args.oblique_size), suffix)
    print(f"done in {time.perf_counter() - start:.0f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

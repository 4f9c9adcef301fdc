"""A glass slab over a floor: does light pass through transmissive parts in alight's shadows and
occlusion bake as in the path tracer? (alight.render.visibility_parts.light_through, the shadow
casters of alight.render.shadows, the bake's see-through parts in alight.core.visibility.)

Scene: a 4 x 4 grey floor (0.7, roughness 0.5) and a 1.2 x 0.2 x 1.2 slab 0.4 above it, white,
roughness 0.2, KHR_materials_transmission --transmission (default 0.9); the camera 35 degrees
up. Reference: app/accuracy/path_trace.py (transmission as a thin wall: the share t goes straight
on), 128x128 px (--size), --samples a pixel, seed 0. alight: --occlusion on, shadows auto, the medium bake;
"opaque": every part taken as opaque (light_through None: what alight did before), "through":
as it does now. Metric: binned 4x4 linear relMAE on the floor's pixels only (the glass itself is
shaded by alight's transmission layer, which the tracer does not model).

    .venv/bin/python benchmarks/bench_transmissive_occlusion.py [--maps quarry_01_1k.hdr,...]
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
ENV_DIR = HERE.parent.parent / "shared" / "data" / "env"


def _box(lo, hi, name, material):
    from alight.core.mesh import MeshPart

    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    faces = [[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1], [2, 3, 7], [2, 7, 6],
             [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]]
    return _flat(corners, faces, name, material, MeshPart)


def _flat(corners, faces, name, material, MeshPart):
    tri = np.asarray(corners, np.float32)[np.asarray(faces)]
    n = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    n /= np.linalg.norm(n, axis=1, keepdims=True)
    v = tri.reshape(-1, 3)
    count = len(v)
    return MeshPart(name, v, np.repeat(n, 3, axis=0).astype(np.float32), np.zeros((count, 2), np.float32),
                    np.tile(np.float32([1, 0, 0, 1]), (count, 1)), np.arange(count, dtype=np.uint32).reshape(-1, 3),
                    material)


def glass_over_floor(transmission: float):
    from alight.core.mesh import FileMaterial, Mesh, MeshPart

    floor = FileMaterial(base_color=(0.7, 0.7, 0.7), metallic=0.0, roughness=0.5, name="floor")
    glass = FileMaterial(base_color=(1.0, 1.0, 1.0), metallic=0.0, roughness=0.2, name="glass",
                         layers={"transmission": transmission}, double_sided=True)
    h = 2.0
    plane = _flat([[-h, 0, -h], [h, 0, -h], [h, 0, h], [-h, 0, h]], [[0, 2, 1], [0, 3, 2]], "floor", floor, MeshPart)
    return Mesh([plane, _box((-0.6, 0.4, -0.6), (0.6, 0.6, 0.6), "glass", glass)], "glass_over_floor")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--maps", default="quarry_01_1k.hdr,pedestrian_overpass_1k.hdr")
    ap.add_argument("--transmission", type=float, default=0.9)
    ap.add_argument("--samples", type=int, default=128)
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--out", default="", help="a folder for the PNGs (reference, opaque, through), tone-mapped alike")
    args = ap.parse_args(argv)

    import alight.render.passes as passes
    import alight.render.visibility_parts as vp
    from alight.accuracy.binned import binned_relative_mae
    from alight.accuracy.path_trace import TraceSettings, _camera_rays, _Rays, scene_geometry, trace
    from alight.core.scene import Scene, orbit_camera
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    mesh = glass_over_floor(args.transmission)
    centre, radius = mesh.bounding_sphere()
    size = args.size
    camera = orbit_camera(centre, radius, 1.0, 20.0, 35.0, None, 35.0, None, corners=mesh.corners())
    r = ForwardRenderer()
    r.bake_cache = None
    r.visibility_parts.cache = None
    geom, _ = scene_geometry(Scene(mesh=mesh, camera=camera))
    origin, direction = _camera_rays(camera, 1.0, size, size, np.arange(size * size), None, False)
    prim, _, _, _ = _Rays(geom).hit(origin, direction)
    floor_px = ((prim >= 0) & (geom.material[np.maximum(prim, 0)] == 0)).reshape(size, size)
    floor = floor_px.reshape(size // 4, 4, size // 4, 4).all(axis=(1, 3))     # blocks wholly floor
    real = vp.light_through
    print(f"glass (transmission {args.transmission:g}) over a floor, {size}x{size} px, path tracer {args.samples} "
          f"spp; floor blocks {int(floor.sum())}; binned 4x4 relMAE on the floor")
    print("| map | opaque casters % | light through % |")
    print("|---|---|---|")
    for name in args.maps.split(","):
        env = load_environment(str(ENV_DIR / name))
        scene = Scene(mesh=mesh, camera=camera, occlusion="on")
        t = time.perf_counter()
        ref = trace(scene, env.radiance, size, size, TraceSettings(samples=args.samples, seed=0)).linear
        traced = time.perf_counter() - t
        maps = r.bake(env, "medium")
        row = []
        for opaque in (True, False):
            fake = (lambda scene: None) if opaque else real
            vp.light_through = passes.light_through = fake
            try:
                img = r.render(Scene(mesh=mesh, camera=camera, occlusion="on"), maps, size, size).linear
            finally:
                vp.light_through = passes.light_through = real
            row.append(100.0 * binned_relative_mae(img, ref, 4, mask=floor))
            if args.out:
                _png(img, Path(args.out) / f"{name}_{'opaque' if opaque else 'through'}.png")
        if args.out:
            _png(ref, Path(args.out) / f"{name}_reference.png")
        print(f"| {name} | {row[0]:.1f} | {row[1]:.1f} |   (traced in {traced:.0f} s)", flush=True)
    return 0


def _png(image, path: Path) -> None:
    from PIL import Image

    path.parent.mkdir(parents=True, exist_ok=True)
    rgb = np.clip(np.asarray(image, np.float64)[..., :3] / (1.0 + np.asarray(image, np.float64)[..., :3]), 0, 1)
    Image.fromarray((255.0 * rgb ** (1 / 2.2)).astype(np.uint8)).save(path)


if __name__ == "__main__":
    sys.exit(main())

"""The path tracer (app/accuracy/path_trace.py) against Mitsuba 3 where both compute the same
thing: the corner scene (app/accuracy/scenes.py) in a constant environment of radiance 1, with
shadows and inter-reflection, a near-Lambertian material. Prints; asserts nothing.

    .venv/bin/python -m pip install mitsuba      # or: pip install 'alight[crosscheck]'
    .venv/bin/python benchmarks/bench_mitsuba_crosscheck.py [--samples 256] [--size 64]

Mitsuba: scalar_rgb, its path integrator (max_depth 9), a two-sided stock `diffuse` BSDF of
reflectance 0.7, a box pixel filter, the same camera (vertical fov, look-at). alight: base 0.7,
metallic 0, specular_f0 0, roughness 1 (docs/conventions.md's BRDF is then Lambert but for the
Fresnel-Schlick term (1 - v.h)^5, which moves the albedo by well under 1% at these angles),
max 9 vertices. A constant environment needs no agreement on the equirect mapping. Reported:
binned 4x4 relMAE between the two, the same between two seeds of alight's (the noise floor),
and the ratio of the summed radiance.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time

import numpy as np

from alight.accuracy.binned import binned_relative_mae
from alight.accuracy.path_trace import TraceSettings, trace
from alight.accuracy.scenes import write_scene
from alight.core.material import Material
from alight.core.scene import Scene, orbit_camera
from alight.exchange.meshes import load_mesh


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--samples", type=int, default=256)
    ap.add_argument("--size", type=int, default=64)
    args = ap.parse_args()
    try:
        import mitsuba as mi
    except ImportError:
        print("needs mitsuba: .venv/bin/python -m pip install mitsuba", file=sys.stderr)
        return 1
    mi.set_variant("scalar_rgb")
    size, spp = args.size, args.samples
    path = write_scene("corner", tempfile.mkdtemp(prefix="alight-xcheck-"))
    mesh = load_mesh(str(path))
    centre, radius = mesh.bounding_sphere()
    cam = orbit_camera(centre, radius, 1.0, 30.0, 25.0, None, 35.0, None, corners=mesh.corners())
    scene = Scene(mesh=mesh, material=Material(base_color=(0.7,) * 3, metallic=0.0, roughness=1.0,
                                               specular_f0=(0.0,) * 3), camera=cam, view="camera")
    env = np.ones((64, 128, 3), np.float32)
    t0 = time.perf_counter()
    ours = [trace(scene, env, size, size, TraceSettings(samples=spp, seed=s, max_bounces=9)).linear for s in (0, 1)]
    t1 = time.perf_counter()
    mscene = mi.load_dict({
        "type": "scene", "integrator": {"type": "path", "max_depth": 9},
        "sensor": {"type": "perspective", "fov": cam.fov_y_deg, "fov_axis": "y", "near_clip": 0.01,
                   "to_world": mi.ScalarTransform4f().look_at(origin=[float(x) for x in cam.position],
                                                             target=[float(x) for x in cam.target],
                                                             up=[float(x) for x in cam.up]),
                   "film": {"type": "hdrfilm", "width": size, "height": size, "rfilter": {"type": "box"}},
                   "sampler": {"type": "independent", "sample_count": spp, "seed": 0}},
        "env": {"type": "constant", "radiance": {"type": "rgb", "value": 1.0}},
        "mesh": {"type": "obj", "filename": str(path), "face_normals": True,
                 "bsdf": {"type": "twosided",
                          "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.7}}}},
    })
    theirs = np.array(mi.render(mscene))[..., :3]
    t2 = time.perf_counter()
    theirs = np.concatenate([theirs, ours[0][..., 3:]], axis=2)   # Mitsuba's RGB film has no alpha: ours
    covered = ours[0][..., 3] == 1.0
    print(f"corner, constant environment 1, {size}x{size}, {spp} samples a pixel")
    print(f"alight vs Mitsuba, binned 4x4 relMAE: {100 * binned_relative_mae(ours[0], theirs, 4):.2f}%")
    print(f"alight seed 0 vs seed 1 (noise floor): {100 * binned_relative_mae(ours[0], ours[1], 4):.2f}%")
    print(f"summed radiance alight/Mitsuba: {ours[0][covered, :3].sum() / theirs[covered, :3].sum():.4f}")
    print(f"time: alight {(t1 - t0) / 2:.1f} s an image, Mitsuba scalar_rgb {t2 - t1:.1f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())

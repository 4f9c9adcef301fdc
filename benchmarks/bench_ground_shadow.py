"""The ground's sun shadow against ray-traced visibility: a model on --ground under a map with a
compact sun (default DamagedHelmet under quarry_01, whose sun holds 48% of the power, 10 degrees
above the horizon), seen from straight above with an orthographic camera.

Reference: at each pixel's point on the ground plane, the share of the sun's disk the model hides,
by Embree shadow rays (app/accuracy/path_trace.py's _Rays) toward N stratified points on the
disk of radius spread * sqrt(2) (alight.render.shadows.SPREAD_TO_RADIUS, the radius the PCSS
uses). alight: the ground's alpha over a transparent background, 1 - E_shadowed / E, divided by
the sun's share of E (E_sun / E, the same on the whole flat ground) to give the hidden share too.

Prints the mean absolute error of the hidden share over the ground near the model (inside the
fade's start, off the model), the error in the penumbra (reference strictly between 0.02 and
0.98), and the largest error of the "stripes" (the high-pass residual of alight's share along
the ground, compared with the reference's); writes PNGs of both and of a crop into --out.

    .venv/bin/python benchmarks/bench_ground_shadow.py --out /tmp/ground_shadow [--mesh M --env E]
"""

from __future__ import annotations

import argparse
import math
import os
import sys
import time

import numpy as np


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--mesh", default="../shared/data/models/DamagedHelmet/DamagedHelmet.gltf")
    ap.add_argument("--env", default="../shared/data/env/quarry_01_1k.hdr")
    ap.add_argument("--size", type=int, default=384)
    ap.add_argument("--disk-samples", type=int, default=64)
    ap.add_argument("--out", default="/tmp/ground_shadow")
    ap.add_argument("--tag", default="", help="suffix of the PNG names (before/after)")
    ap.add_argument("--view", choices=("top", "camera"), default="top",
                    help="top: orthographic from straight above; camera: alight render's default camera")
    args = ap.parse_args(argv)

    from PIL import Image

    from alight.accuracy.path_trace import _camera_rays, _Rays, scene_geometry
    from alight.core.ground import ground_under
    from alight.core.scene import Camera, Display, Scene
    from alight.core.shading import rotate_world_to_map
    from alight.exchange.meshes import load_mesh
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer
    from alight.render.shadows import SPREAD_TO_RADIUS

    os.makedirs(args.out, exist_ok=True)
    mesh = load_mesh(args.mesh)
    lo, hi = mesh.bounds()
    centre, radius = mesh.bounding_sphere()
    ground = ground_under(lo, hi, centre, radius)
    half = ground.fade * 0.75
    gc = ground.centre
    camera = Camera(position=(gc[0], hi[1] + 10.0 * radius, gc[2]), target=(gc[0], gc[1], gc[2]), up=(0.0, 0.0, -1.0),
                    ortho_half_height=half, near=0.1 * radius, far=30.0 * radius)
    if args.view == "camera":
        from alight.core.scene import default_camera
        camera = default_camera(mesh, 1.0)
    env = load_environment(args.env)
    r = ForwardRenderer()
    maps = r.bake(env, "medium")
    if not maps.suns:
        print(f"{args.env}: no compact source, nothing to compare", file=sys.stderr)
        return 1
    sun = maps.suns[0]
    scene = Scene(mesh=mesh, ground=True, camera=camera, display=Display(background="transparent"), occlusion="off")
    t = time.perf_counter()
    frame = r.render(scene, maps, args.size, args.size)
    render_s = time.perf_counter() - t
    alpha = np.asarray(frame.linear)[..., 3].astype(np.float64)

    geom, _ = scene_geometry(scene)
    rays = _Rays(geom)
    # Each pixel's point on the ground plane, along the camera ray through its centre.
    origin, direction = _camera_rays(camera, 1.0, args.size, args.size, np.arange(args.size * args.size),
                                     None, False)
    t_plane = (gc[1] - origin[:, 1]) / np.where(np.abs(direction[:, 1]) > 1e-9, direction[:, 1], -1e-9)
    on_plane = t_plane > 0.0
    pts = origin + direction * np.where(on_plane, t_plane, 0.0)[:, None]
    x, z = (pts[:, i].reshape(args.size, args.size) for i in (0, 2))
    toward = np.asarray(rotate_world_to_map(np.asarray(sun.direction, np.float64), -scene.env_rotation_deg))
    toward /= np.linalg.norm(toward)
    disk_radius = math.tan(float(sun.spread) * SPREAD_TO_RADIUS)
    a = np.cross(toward, [0.0, 1.0, 0.0] if abs(toward[1]) < 0.9 else [1.0, 0.0, 0.0])
    a /= np.linalg.norm(a)
    b = np.cross(toward, a)
    n = args.disk_samples
    k = np.arange(n)
    rho, phi = np.sqrt((k + 0.5) / n), k * math.pi * (3.0 - math.sqrt(5.0))
    hidden = np.zeros(len(pts))
    up = np.array([0.0, 1.0, 0.0])
    # the model's top view covers the ground under it: a ray from the ground starting inside the
    # model's footprint still counts (the ground there is hidden by the model anyway: masked below)
    for rr, pp in zip(rho, phi):
        d = toward + disk_radius * rr * (math.cos(pp) * a + math.sin(pp) * b)
        d /= np.linalg.norm(d)
        origins = pts + up * 1e-4 * radius
        hidden += rays.blocked(origins, np.broadcast_to(d, pts.shape), np.full(len(pts), np.inf))
    hidden = (hidden / n).reshape(args.size, args.size)
    # The model in front of the ground (or the sky above the horizon): not ground.
    prim, dist, _, _ = rays.hit(origin, direction)
    model = (((prim >= 0) & (dist < t_plane - 1e-3 * radius)) | ~on_plane).reshape(args.size, args.size)
    near = np.hypot(x - gc[0], z - gc[2]) < 0.6 * ground.fade
    ring = near & ~_dilate(model, 3)
    umbra = ring & (hidden > 0.999)
    share_sun = float(np.median(alpha[umbra])) if umbra.any() else float(alpha[ring].max())
    est = alpha / max(share_sun, 1e-6)
    err = np.abs(est - hidden)
    pen = ring & (hidden > 0.02) & (hidden < 0.98)
    stripes = _high_pass(est) - _high_pass(hidden)
    print(f"{os.path.basename(args.mesh)} on --ground, {os.path.basename(args.env)}: sun {math.degrees(math.asin(toward[1])):.1f} deg "
          f"above the horizon, angular radius {math.degrees(sun.spread * SPREAD_TO_RADIUS):.2f} deg, "
          f"its share of the ground's irradiance {share_sun:.3f}; {args.size}^2 px, {n} disk rays a pixel; "
          f"render {render_s * 1e3:.0f} ms")
    print(f"hidden share, |alight - rays|: mean {err[ring].mean():.4f} on the ground near the model, "
          f"{err[pen].mean():.4f} in the penumbra ({int(pen.sum())} px); shadowed area alight "
          f"{float((est[ring] > 0.5).mean()):.4f} rays {float((hidden[ring] > 0.5).mean()):.4f}")
    print(f"stripes (high-pass residual, alight - rays) on the ground near the model: rms {np.sqrt((stripes[ring] ** 2).mean()):.4f}, "
          f"99th percentile |.| {np.percentile(np.abs(stripes[ring]), 99):.4f}")
    tag = f"_{args.tag}" if args.tag else ""
    grey = lambda v: Image.fromarray((255.0 * (1.0 - np.clip(v, 0.0, 1.0))).astype(np.uint8))
    grey(np.where(model, 1.0, est)).save(os.path.join(args.out, f"alight{tag}.png"))
    grey(np.where(model, 1.0, hidden)).save(os.path.join(args.out, f"rays{tag}.png"))
    s = args.size
    both = np.concatenate([np.where(model, 1.0, est), np.ones((s, 4)), np.where(model, 1.0, hidden)], axis=1)
    grey(both).save(os.path.join(args.out, f"side_by_side{tag}.png"))
    return 0


def _dilate(mask: np.ndarray, n: int) -> np.ndarray:
    out = mask.copy()
    for _ in range(n):
        grown = out.copy()
        grown[1:] |= out[:-1]
        grown[:-1] |= out[1:]
        grown[:, 1:] |= out[:, :-1]
        grown[:, :-1] |= out[:, 1:]
        out = grown
    return out


def _high_pass(img: np.ndarray, k: int = 4) -> np.ndarray:
    """img minus its (2k+1)^2 box blur: what varies over a few pixels."""
    pad = np.pad(img, k, mode="edge")
    c = np.cumsum(np.cumsum(pad, 0), 1)
    c = np.pad(c, ((1, 0), (1, 0)))
    w = 2 * k + 1
    box = (c[w:, w:] - c[:-w, w:] - c[w:, :-w] + c[:-w, :-w]) / (w * w)
    return img - box


if __name__ == "__main__":
    sys.exit(main())

"""alight against a peer renderer, pyvista/VTK, on the same scene; prints ratios. Not a test.

    .venv/bin/pip install -e '.[peers]'            # pyvista and VTK (an optional extra)
    .venv/bin/python benchmarks/bench_peers.py      # about 20 minutes on 2 heavily loaded cores
    .venv/bin/python benchmarks/bench_peers.py --rounds 2 --frames 5   # shorter

The scene: a UV sphere (128 x 64), royal_esplanade_1k.hdr as image-based light and background,
gold (alight's preset: base colour (1.0, 0.782, 0.344), metallic 1) at roughness 0.3, no other
light (pyvista's default light kit off), alight's camera (from +Z, 35 degrees vertical field, the
sphere framed), 4x MSAA in both (pyvista's default is 8x: set to 4 so that both resolve the same
number of samples).

- **cold process at 1024x1024**: process start to PNG written. alight: ``alight render`` twice per
  round, the first with an empty bake cache (it bakes and keeps the bake), the second with that
  cache (it loads it); VTK: a script that builds the same scene and writes a screenshot (VTK
  bakes its own IBL maps on the GPU in every process).
- **steady frame at 1920x1080**: one process per renderer and round; after two warm-up frames,
  each frame orbits the camera by 1 degree (so neither can reuse the last image) and reads the
  8-bit image back into numpy (``alight.Renderer.render()``; pyvista's ``screenshot``). alight
  runs twice: with its built-in sphere (drawn as an impostor: ForwardRenderer._sphere_impostor)
  and with the same 128 x 64 UV sphere read from an OBJ file (drawn as a mesh, as any asset is).

Every measurement alternates alight and VTK within a round (A B A B ...), so load from other
work on a shared machine falls on both alike. Each is taken as wall time and as CPU time of the
process with all its threads (waiting for a core on a loaded machine does not count there);
medians and ranges are printed, then the ratios alight / VTK (below 1: alight is faster).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
ENV = REPO.parent / "shared" / "data" / "env" / "royal_esplanade_1k.hdr"
GOLD = (1.0, 0.782, 0.344)
ROUGHNESS = 0.3

# The VTK side, run as `python -c VTK_SCRIPT MODE W H FRAMES OUT`: the same scene through pyvista.
VTK_SCRIPT = r'''
import sys, time, json
t0 = time.perf_counter()
import numpy as np
import pyvista as pv
mode, w, h, frames, out, env = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), int(sys.argv[4]), sys.argv[5], sys.argv[6]
gold, roughness = json.loads(sys.argv[7]), float(sys.argv[8])
pl = pv.Plotter(off_screen=True, window_size=(w, h), lighting="none")   # IBL only, as alight's scene
pl.enable_anti_aliasing("msaa", multi_samples=4)
texture = pv.read_texture(env)
pl.set_environment_texture(texture, is_srgb=False)
pl.add_actor(texture.to_skybox())
pl.add_mesh(pv.Sphere(radius=1.0, theta_resolution=128, phi_resolution=64), pbr=True, metallic=1.0,
            roughness=roughness, color=gold, smooth_shading=True)
# alight's framing of the unit sphere (core.scene.frame_camera): from +Z, 35 degrees vertical field.
pl.camera.position, pl.camera.focal_point, pl.camera.up = (0.0, 0.0, 4.323162), (0.0, 0.0, 0.0), (0.0, 1.0, 0.0)
pl.camera.view_angle = 35.0
pl.renderer.ResetCameraClippingRange()
if mode == "cold":
    pl.screenshot(out)
    print(json.dumps({"seconds_in_process": time.perf_counter() - t0}))
else:
    times = []
    cpu = []
    pl.screenshot(return_img=True)   # the first render (pyvista sets up its window here)
    previous = None
    for i in range(frames + 2):
        pl.camera.azimuth += 1.0
        t, c = time.perf_counter(), time.process_time()
        pl.render_window.Render()     # screenshot() alone may hand back the last image unrendered
        image = np.array(pl.image)    # glReadPixels into numpy
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
        assert previous is None or not np.array_equal(image, previous), "VTK did not render a new frame"
        previous = image
    assert image.shape[:2] == (h, w)
    print(json.dumps({"frames": times[2:], "cpu": cpu[2:]}))
'''

ALIGHT_STEADY = r'''
import sys, time, json
import alight
w, h, frames, env, roughness = int(sys.argv[1]), int(sys.argv[2]), int(sys.argv[3]), sys.argv[4], float(sys.argv[5])
mesh = sys.argv[6]
with alight.Renderer(w, h, aa="msaa") as r:
    r.set_mesh(mesh).set_environment(env).set_material("gold", roughness=roughness)
    times, cpu = [], []
    for i in range(frames + 2):
        r.set_camera(orbit_deg=float(i))
        t, c = time.perf_counter(), time.process_time()
        image = r.render()
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
    assert image.shape[:2] == (h, w)
print(json.dumps({"frames": times[2:], "cpu": cpu[2:]}))
'''


def run(args, env=None) -> tuple[float, float, str]:
    """(wall seconds, CPU seconds of the child and all its threads, stdout). CPU time is the
    steadier measure on a loaded machine: waiting for a core does not count."""
    with tempfile.TemporaryFile() as err:
        start = time.perf_counter()
        p = subprocess.Popen(args, cwd=REPO, env=env or dict(os.environ), stdout=subprocess.PIPE, stderr=err)
        out = p.stdout.read().decode()
        _, status, usage = os.wait4(p.pid, 0)
        seconds = time.perf_counter() - start
        if os.waitstatus_to_exitcode(status) != 0:
            err.seek(0)
            raise SystemExit(f"failed: {' '.join(map(str, args))}\n{err.read().decode()[-2000:]}")
    return seconds, usage.ru_utime + usage.ru_stime, out


def summary(values) -> str:
    return f"median {statistics.median(values) * 1000:7.0f} ms  (range {min(values) * 1000:.0f}-{max(values) * 1000:.0f}, n={len(values)})"


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--rounds", type=int, default=4, help="alternated rounds (default: 4)")
    parser.add_argument("--frames", type=int, default=10, help="steady frames per process (default: 10)")
    parser.add_argument("--parts", default="cold,steady", help="which measurements: cold, steady or both (default)")
    args = parser.parse_args()
    try:
        import pyvista  # noqa: F401
    except ImportError:
        print("pyvista is not installed: pip install -e '.[peers]'", file=sys.stderr)
        return 2
    py = sys.executable
    with open("/proc/loadavg") as f:
        load_before = f.read().split()[:3]
    cold = {"alight first": [], "alight second": [], "vtk": []}
    cold_cpu = {k: [] for k in cold}
    steady = {"alight": [], "alight mesh file": [], "vtk": []}
    steady_cpu = {k: [] for k in steady}
    with tempfile.TemporaryDirectory(prefix="alight-peers-") as tmp:
        tmp = Path(tmp)
        cache = tmp / "cache"
        env = {**os.environ, "ALIGHT_CACHE_DIR": str(cache)}
        render = [py, "-m", "alight", "render", "--env", str(ENV), "--preset", "gold", "--roughness", str(ROUGHNESS),
                  "--size", "1024", "--out", str(tmp / "alight.png")]
        vtk_cold = [py, "-c", VTK_SCRIPT, "cold", "1024", "1024", "0", str(tmp / "vtk.png"), str(ENV),
                    json.dumps(GOLD), str(ROUGHNESS)]
        parts = set(args.parts.split(","))
        sphere_file = tmp / "uv_sphere.obj"
        if "steady" in parts:
            import trimesh
            from alight.core.mesh import sphere
            part = sphere().parts[0]
            trimesh.Trimesh(part.positions, part.indices, vertex_normals=part.normals, process=False,
                            visual=trimesh.visual.TextureVisuals(uv=part.uvs)).export(sphere_file)
        for i in range(args.rounds if "cold" in parts else 0):
            # The BRDF LUT stays cached (it does not depend on the environment); the bake does not.
            shutil.rmtree(cache / "bakes", ignore_errors=True)
            for key, command, child_env in (("alight first", render, env), ("vtk", vtk_cold, None),
                                            ("alight second", render, env)):
                wall, cpu, _ = run(command, child_env)
                cold[key].append(wall)
                cold_cpu[key].append(cpu)
            print(f"round {i + 1}/{args.rounds}: cold alight {cold['alight first'][-1]:.2f} s, "
                  f"vtk {cold['vtk'][-1]:.2f} s, alight again {cold['alight second'][-1]:.2f} s", file=sys.stderr)
        for i in range(args.rounds if "steady" in parts else 0):
            for key, mesh in (("alight", "sphere"), ("alight mesh file", str(sphere_file))):
                out = run([py, "-c", ALIGHT_STEADY, "1920", "1080", str(args.frames), str(ENV), str(ROUGHNESS), mesh],
                          env)[2]
                steady[key] += json.loads(out)["frames"]
                steady_cpu[key] += json.loads(out)["cpu"]
            out = run([py, "-c", VTK_SCRIPT, "steady", "1920", "1080", str(args.frames), "-", str(ENV),
                       json.dumps(GOLD), str(ROUGHNESS)])[2]
            steady["vtk"] += json.loads(out)["frames"]
            steady_cpu["vtk"] += json.loads(out)["cpu"]
            print(f"round {i + 1}/{args.rounds}: steady alight {statistics.median(steady['alight']) * 1000:.0f} ms, "
                  f"alight mesh file {statistics.median(steady['alight mesh file']) * 1000:.0f} ms, "
                  f"vtk {statistics.median(steady['vtk']) * 1000:.0f} ms", file=sys.stderr)
        for name in ("alight.png", "vtk.png") if "cold" in parts else ():
            shutil.copy(tmp / name, Path(tempfile.gettempdir()) / f"bench_peers_{name}")
    with open("/proc/loadavg") as f:
        load_after = f.read().split()[:3]

    print(f"machine: {os.cpu_count()} cores, load average {'/'.join(load_before)} before, "
          f"{'/'.join(load_after)} after; {args.rounds} alternated rounds")
    if "cold" not in parts:
        cold = cold_cpu = {}
    if "steady" not in parts:
        steady = steady_cpu = {}
    print("cold process, 1024x1024, to PNG (wall; CPU of the process and its threads):")
    for k in cold:
        print(f"  {k:14s} wall {summary(cold[k])}\n  {'':14s} CPU  {summary(cold_cpu[k])}")
    print("steady frame, 1920x1080, with read-back (wall; CPU of the process and its threads):")
    for k in steady:
        print(f"  {k:14s} wall {summary(steady[k])}\n  {'':14s} CPU  {summary(steady_cpu[k])}")
    m = statistics.median
    print("ratios of medians, wall (CPU); below 1: alight faster:")
    for label, a, b in (("cold, empty bake cache / VTK", "alight first", "vtk"),
                        ("cold, bake cached / VTK", "alight second", "vtk"),
                        ("cold, bake cached / empty cache", "alight second", "alight first")) if cold else ():
        print(f"  {label:34s} {m(cold[a]) / m(cold[b]):.2f} ({m(cold_cpu[a]) / m(cold_cpu[b]):.2f})")
    if steady:
        for label, key in (("steady 1920x1080 frame / VTK", "alight"),
                           ("  the sphere from a mesh file / VTK", "alight mesh file")):
            print(f"  {label:34s} {m(steady[key]) / m(steady['vtk']):.2f} "
                  f"({m(steady_cpu[key]) / m(steady_cpu['vtk']):.2f})")
    if "cold" in parts:
        print(f"images: {tempfile.gettempdir()}/bench_peers_alight.png, {tempfile.gettempdir()}/bench_peers_vtk.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())

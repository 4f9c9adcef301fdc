"""alight against three peer renderers (pyvista/VTK, pygfx, pyrender) on real assets; prints ratios. Not a test.

    python3 -m venv /tmp/peers-venv       # the peers in a venv of their own (or pip install -e '.[peers]')
    /tmp/peers-venv/bin/pip install pyvista pygfx gltflib OpenImageIO pyrender trimesh
    apt-get install mesa-vulkan-drivers    # pygfx draws through wgpu: Vulkan, lavapipe on a CPU-only machine
    .venv/bin/python benchmarks/bench_peers_assets.py --peers-python /tmp/peers-venv/bin/python --rounds 3 --frames 5

The scenes (``--scenes``):
- **helmet**: DamagedHelmet.gltf with its own glTF materials (base colour, metal/roughness,
  normal, occlusion and emissive maps), royal_esplanade_1k.hdr as image-based light and
  background where the peer has image-based light, no other light.
- **mesh1m**: a 1.31M-triangle icosphere (trimesh, 8 subdivisions) written to a .ply in a
  temporary folder, gold at roughness 0.3, the same environment; alight with shadows off (no
  peer draws them, and the 'auto' self-shadow test is quadratic on a convex mesh: see below).

alight's camera for every scene and frame (``alight.Renderer.set_camera(orbit_deg=i)``: the
mesh framed from +Z, 35 degrees vertical field, then orbiting 1 degree per frame) is computed
here and handed to every peer as eye, target and up, so all draw the same view. 1024x1024.
Anti-aliasing: alight 4x MSAA; pyvista 4x MSAA (``enable_anti_aliasing("msaa", 4)``); pyrender
its fixed 4x MSAA; pygfx has no MSAA (its render target's sample count is fixed at 1): it renders
at ``pixel_scale=2`` (2x2 supersampling, 4 shaded samples a pixel) and filters down.

Image-based light per peer:
- pyvista: ``set_environment_texture`` (VTK bakes its own irradiance and prefiltered maps on
  the GPU in every process) with the glTF's PBR materials (``import_gltf``), the map as skybox;
- pygfx: a cube map made from the .hdr (read with OpenImageIO, resampled to 6 x 256² in numpy in
  the peer's process, mipmapped by pygfx) as ``env_map`` of every MeshStandardMaterial, and as
  the skybox background; pygfx has no equirectangular environment. pygfx decodes material
  colours, environment maps and skyboxes as sRGB, so the map and the sphere's colour are handed
  to it sRGB-encoded;
- pyrender: no image-based light at all. It gets a directional light from the camera and an
  ambient term instead, so its picture is lit differently (a reference for speed only).

Measured per scene, alternating alight and each peer within every round (A B A B ...), so the
load of other work on a shared machine falls on all alike:
- **cold process to PNG**: process start to PNG file written (``alight render`` twice: first with
  an empty bake cache, then with the bake cached; each peer's script writes its screenshot).
- **steady frame**: one process per renderer and round; two warm-up frames, then ``--frames``
  frames, each with the camera orbited 1 degree and the 8-bit image read back into numpy.
Both as wall time and as CPU time of the process and all its threads.

``--alight-features default,off`` runs alight's steady frame both ways before each peer's process:
``default`` is alight's defaults (its sun's soft shadow and the occlusion bake ``auto``, on for the
helmet under royal_esplanade_1k), ``off`` sets ``set_shadows("off")`` and ``set_occlusion("off")``,
the features no peer here draws: the feature-matched comparison. Its rows are labelled
"alight, shadows+occlusion off"; the default rows stay "alight". The cold part always runs the
defaults. Medians, ranges, and the
ratios alight / peer (below 1: alight takes less). The cold PNGs are copied to ``--images``.
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
DATA = REPO.parent / "shared" / "data"
ENV = DATA / "env" / "royal_esplanade_1k.hdr"
HELMET = DATA / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
GOLD = (1.0, 0.782, 0.344)   # alight's gold preset
ROUGHNESS = 0.3
PEERS = ("pyvista", "pygfx", "pyrender")

# What every peer script starts with: its arguments as one JSON object, the camera helpers.
PEER_HEAD = r'''
import sys, time, json, math
t0 = time.perf_counter()
import numpy as np
a = json.loads(sys.argv[1])
mode, w, h, frames, out, scene, env, cams = a["mode"], a["w"], a["h"], a["frames"], a["out"], a["scene"], a["env"], a["cameras"]
def steady(draw, move):
    """Two warm-ups and `frames` frames; each moves the camera (alight's orbit, 1 degree a frame)."""
    times, cpu, previous = [], [], None
    for i in range(frames + 2):
        move(cams[i])
        t, c = time.perf_counter(), time.process_time()
        image = draw()
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
        assert image.shape[:2] == (h, w), image.shape
        assert previous is None or not np.array_equal(image, previous), "the same image twice"
        previous = image
    print(json.dumps({"frames": times[2:], "cpu": cpu[2:]}))
'''

PYVISTA_SCRIPT = PEER_HEAD + r'''
import pyvista as pv
pl = pv.Plotter(off_screen=True, window_size=(w, h), lighting="none")   # image-based light only
pl.enable_anti_aliasing("msaa", multi_samples=4)
if scene["kind"] == "gltf":
    pl.import_gltf(scene["path"])            # vtkGLTFImporter: the file's PBR materials and maps
    pl.remove_all_lights()
else:
    mesh = pv.read(scene["path"])
    pl.add_mesh(mesh, pbr=True, metallic=1.0, roughness=scene["roughness"], color=scene["color"],
                smooth_shading=True)
texture = pv.read_texture(env)
pl.set_environment_texture(texture, is_srgb=False)
# VTK reads an equirect map turned against alight's (docs/conventions.md: the map's centre is -Z, u = 0.75
# is +X): with the environment's right vector on -Z its skybox and reflections face as alight's do.
pl.renderer.SetEnvironmentUp(0.0, 1.0, 0.0)
pl.renderer.SetEnvironmentRight(*a.get("env_right", (0.0, 0.0, -1.0)))
pl.add_actor(texture.to_skybox())
def move(c):
    pl.camera.position, pl.camera.focal_point, pl.camera.up = c["position"], c["target"], c["up"]
    pl.camera.view_angle = c["fov_y_deg"]
    pl.camera.clipping_range = (c["near"], c["far"])
move(cams[0])
if mode == "cold":
    pl.screenshot(out)
else:
    pl.screenshot(return_img=True)           # the first render (pyvista sets up its window here)
    def draw():
        pl.render_window.Render()            # screenshot() alone may hand back the last image
        return np.array(pl.image)            # glReadPixels into numpy
    steady(draw, move)
'''

PYGFX_SCRIPT = PEER_HEAD + r'''
import pygfx as gfx
from rendercanvas.offscreen import RenderCanvas
import OpenImageIO as oiio

def cube_from_equirect(path, size=256):
    """The .hdr as a cube map (+X -X +Y -Y +Z -Z, wgpu's layer order, GL's face orientation), nearest
    texel, in numpy."""
    eq = oiio.ImageBuf(path).get_pixels(oiio.FLOAT)[:, :, :3]
    H, W = eq.shape[:2]
    s = (np.arange(size) + 0.5) / size * 2 - 1
    u, v = np.meshgrid(s, -s)                 # v: +1 at the top row
    one = np.ones_like(u)
    faces = [(one, v, -u), (-one, v, u), (u, one, -v), (u, -one, v), (u, v, one), (-u, v, -one)]
    out = np.empty((6, size, size, 4), np.float32)
    for i, (x, y, z) in enumerate(faces):
        x = -x                                # pygfx samples its cube maps at (-x, y, z) of the world direction
        n = np.sqrt(x * x + y * y + z * z)
        lon = np.arctan2(x, -z)               # alight's equirect: the centre column looks along -Z
        lat = np.arcsin(y / n)
        col = ((lon / (2 * np.pi) + 0.5) * W).astype(int) % W
        row = np.clip(((0.5 - lat / np.pi) * H).astype(int), 0, H - 1)
        out[i, :, :, :3] = eq[row, col]
        out[i, :, :, 3] = 1
    return out

def srgb_encoded(linear):
    """pygfx linearises colours, environment maps and skyboxes as sRGB (srgb2physical in its shaders):
    hand it alight's linear values sRGB-encoded (the curve continued above 1) so that it lights with them."""
    c = np.maximum(np.asarray(linear, np.float32), 0.0)
    return np.where(c > 0.0031308, 1.055 * np.power(c, 1 / 2.4) - 0.055, 12.92 * c).astype(np.float32)

canvas = RenderCanvas(size=(w, h), pixel_ratio=1)
renderer = gfx.renderers.WgpuRenderer(canvas, pixel_scale=2)   # no MSAA in pygfx: 2x2 supersampling
cube = cube_from_equirect(env)
cube[..., :3] = srgb_encoded(cube[..., :3])
env_tex = gfx.Texture(cube, dim=2, size=(cube.shape[2], cube.shape[1], 6), generate_mipmaps=True)
world = gfx.Scene()
sky_tex = gfx.Texture(cube, dim=2, size=(cube.shape[2], cube.shape[1], 6))   # the skybox without mips
world.add(gfx.Background(None, gfx.BackgroundSkyboxMaterial(map=sky_tex)))
if scene["kind"] == "gltf":
    world.add(gfx.load_gltf(scene["path"], quiet=True).scene)
else:
    import trimesh
    m = trimesh.load(scene["path"], process=False)
    geometry = gfx.Geometry(positions=np.asarray(m.vertices, np.float32), indices=np.asarray(m.faces, np.int32),
                            normals=np.asarray(m.vertex_normals, np.float32))
    world.add(gfx.Mesh(geometry, gfx.MeshStandardMaterial(color=tuple(srgb_encoded(scene["color"])), metalness=1.0,
                                                          roughness=scene["roughness"])))
for obj in world.iter():
    if isinstance(getattr(obj, "material", None), gfx.MeshStandardMaterial):
        obj.material.env_map = env_tex
# pygfx's own near and far planes: with alight's (depth_range) its skybox looked the opposite way.
camera = gfx.PerspectiveCamera(cams[0]["fov_y_deg"], 1.0)
def move(c):
    camera.local.position = c["position"]
    camera.world.reference_up = c["up"]
    camera.look_at(c["target"])
move(cams[0])
canvas.request_draw(lambda: renderer.render(world, camera))
if mode == "cold":
    image = np.asarray(canvas.draw())
    import imageio.v3 as iio
    iio.imwrite(out, image[:, :, :3])
else:
    canvas.draw()
    steady(lambda: np.asarray(canvas.draw()), move)
'''

PYRENDER_SCRIPT = PEER_HEAD + r'''
import os
os.environ.setdefault("PYOPENGL_PLATFORM", "egl")
import pyrender, trimesh
if scene["kind"] == "gltf":
    world = pyrender.Scene.from_trimesh_scene(trimesh.load(scene["path"]), bg_color=(0.5, 0.5, 0.5, 1.0),
                                              ambient_light=(0.3, 0.3, 0.3))
else:
    m = trimesh.load(scene["path"], process=False)
    material = pyrender.MetallicRoughnessMaterial(baseColorFactor=list(scene["color"]) + [1.0], metallicFactor=1.0,
                                                  roughnessFactor=scene["roughness"])
    world = pyrender.Scene(bg_color=(0.5, 0.5, 0.5, 1.0), ambient_light=(0.3, 0.3, 0.3))
    world.add(pyrender.Mesh.from_trimesh(m, material=material, smooth=True))
def pose(c):
    eye, target, up = (np.asarray(c[k], np.float64) for k in ("position", "target", "up"))
    z = eye - target
    z /= np.linalg.norm(z)
    x = np.cross(up, z)
    x /= np.linalg.norm(x)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = x, np.cross(z, x), z, eye
    return m
c0 = cams[0]
camera = world.add(pyrender.PerspectiveCamera(yfov=math.radians(c0["fov_y_deg"]), aspectRatio=w / h,
                                              znear=c0["near"], zfar=c0["far"]), pose=pose(c0))
light = world.add(pyrender.DirectionalLight(intensity=3.0), pose=pose(c0))   # no IBL in pyrender: a headlight
def move(c):
    world.set_pose(camera, pose(c))
    world.set_pose(light, pose(c))
r = pyrender.OffscreenRenderer(w, h)         # 4x MSAA, fixed in pyrender
if mode == "cold":
    color, _ = r.render(world)
    import imageio.v3 as iio
    iio.imwrite(out, color)
else:
    r.render(world)
    steady(lambda: r.render(world)[0], move)
'''

SCRIPTS = {"pyvista": PYVISTA_SCRIPT, "pygfx": PYGFX_SCRIPT, "pyrender": PYRENDER_SCRIPT}

ALIGHT_STEADY = r'''
import sys, time, json
import numpy as np
import alight
a = json.loads(sys.argv[1])
w, h, frames, scene = a["w"], a["h"], a["frames"], a["scene"]
with alight.Renderer(w, h, aa="msaa") as r:
    r.set_mesh(scene["path"]).set_environment(a["env"])
    if scene["kind"] != "gltf":
        r.set_material("gold", roughness=scene["roughness"])
    if "shadows" in scene:
        r.set_shadows(scene["shadows"])
    if a.get("features") == "off":          # --alight-features off: what no peer draws, off
        r.set_shadows("off").set_occlusion("off")
    times, cpu, previous = [], [], None
    for i in range(frames + 2):
        r.set_camera(orbit_deg=float(i))
        t, c = time.perf_counter(), time.process_time()
        image = r.render()
        times.append(time.perf_counter() - t)
        cpu.append(time.process_time() - c)
        assert image.shape[:2] == (h, w)
        assert previous is None or not np.array_equal(image, previous), "the same image twice"
        previous = image
print(json.dumps({"frames": times[2:], "cpu": cpu[2:]}))
'''


def cameras(path: str, kind: str, size: int, count: int) -> list[dict]:
    """alight's cameras for orbit 0, 1, ... count-1 degrees (Renderer.set_camera(orbit_deg=i))."""
    import alight

    r = alight.Renderer(size, size, aa="msaa")
    r.set_mesh(path)
    out = []
    for i in range(count):
        r.set_camera(orbit_deg=float(i))
        c = r.scene.camera
        out.append({"position": [float(x) for x in c.position], "target": [float(x) for x in c.target],
                    "up": [float(x) for x in c.up], "fov_y_deg": float(c.fov_y_deg), "near": float(c.near),
                    "far": float(c.far)})
    return out


def run(args, env=None) -> tuple[float, float, str]:
    """(wall seconds, CPU seconds of the child and all its threads, stdout)."""
    with tempfile.TemporaryFile() as err:
        start = time.perf_counter()
        p = subprocess.Popen(args, cwd=REPO, env=env or dict(os.environ), stdout=subprocess.PIPE, stderr=err)
        out = p.stdout.read().decode()
        _, status, usage = os.wait4(p.pid, 0)
        seconds = time.perf_counter() - start
        if os.waitstatus_to_exitcode(status) != 0:
            err.seek(0)
            raise RuntimeError(f"failed: {' '.join(map(str, args))[:300]}\n{err.read().decode()[-2000:]}")
    return seconds, usage.ru_utime + usage.ru_stime, out


def summary(values) -> str:
    return (f"median {statistics.median(values) * 1000:7.0f} ms  "
            f"(range {min(values) * 1000:.0f}-{max(values) * 1000:.0f}, n={len(values)})")


def make_mesh1m(folder: Path) -> Path:
    import trimesh

    path = folder / "icosphere_1m.ply"
    trimesh.creation.icosphere(subdivisions=8).export(path)
    return path


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--peers-python", default=sys.executable,
                        help="the Python that has the peers (pyvista, pygfx, pyrender) (default: this one)")
    parser.add_argument("--peers", default=",".join(PEERS), help="which peers (default: all three)")
    parser.add_argument("--scenes", default="helmet", help="helmet, mesh1m or both (default: helmet)")
    parser.add_argument("--rounds", type=int, default=3, help="alternated rounds (default: 3)")
    parser.add_argument("--frames", type=int, default=5, help="steady frames per process (default: 5)")
    parser.add_argument("--size", type=int, default=1024, help="square image size (default: 1024)")
    parser.add_argument("--parts", default="cold,steady", help="cold, steady or both (default)")
    parser.add_argument("--alight-features", default="default",
                        help="alight's steady frame: default (its defaults), off (shadows and occlusion off, "
                             "as no peer draws them) or default,off (both, alternated; default: default)")
    parser.add_argument("--images", default=str(Path(tempfile.gettempdir()) / "bench_peers_assets"),
                        help="where the cold PNGs are copied (default: $TMPDIR/bench_peers_assets)")
    args = parser.parse_args()
    peers = [p for p in args.peers.split(",") if p]
    features = [f for f in args.alight_features.split(",") if f]
    if not features or set(features) - {"default", "off"}:
        raise SystemExit(f"--alight-features: default, off or both, not {args.alight_features!r}")
    label = {"default": "alight", "off": "alight, shadows+occlusion off"}
    parts = set(args.parts.split(","))
    images = Path(args.images)
    images.mkdir(parents=True, exist_ok=True)
    py, size = sys.executable, args.size
    with open("/proc/loadavg") as f:
        load_before = f.read().split()[:3]
    results = {}   # (scene, part, who) -> (walls, cpus)
    failures = {}  # (scene, peer) -> message
    per_round = {}  # (scene, part, peer, features) -> [(alight / peer wall, alight / peer CPU) of each round]
    own = []        # alight's frame with shadows and occlusion off / with its defaults, per pair of processes

    def add(key, wall, cpu):
        walls, cpus = results.setdefault(key, ([], []))
        walls += wall if isinstance(wall, list) else [wall]
        cpus += cpu if isinstance(cpu, list) else [cpu]

    with tempfile.TemporaryDirectory(prefix="alight-peers-assets-") as tmp:
        tmp = Path(tmp)
        cache = tmp / "cache"
        alight_env = {**os.environ, "ALIGHT_CACHE_DIR": str(cache)}
        peer_env = {**os.environ, "PYOPENGL_PLATFORM": "egl"}
        scenes = {}
        for name in args.scenes.split(","):
            if name == "helmet":
                scenes[name] = {"kind": "gltf", "path": str(HELMET)}
            elif name == "mesh1m":
                # alight --shadows off: no peer draws shadows, and alight's 'auto' test of whether a
                # mesh can shadow itself (alight.core.shadow_fit.can_shadow_itself) tests every face's
                # plane against every vertex when the mesh is convex: over 4 minutes on this sphere.
                scenes[name] = {"kind": "mesh", "path": str(make_mesh1m(tmp)), "color": GOLD, "roughness": ROUGHNESS,
                                "shadows": "off"}
            else:
                raise SystemExit(f"unknown scene {name!r}")
        for name, scene in scenes.items():
            cams = cameras(scene["path"], scene["kind"], size, args.frames + 2)

            def peer_args(peer, mode, out="-"):
                blob = {"mode": mode, "w": size, "h": size, "frames": args.frames, "out": out, "scene": scene,
                        "env": str(ENV), "cameras": cams}
                return [args.peers_python, "-c", SCRIPTS[peer], json.dumps(blob)]

            render = [str(REPO / ".venv" / "bin" / "alight"), "render", "--mesh", scene["path"], "--env", str(ENV),
                      "--size", str(size), "--aa", "msaa", "--out", str(tmp / f"{name}_alight.png")]
            if scene["kind"] != "gltf":
                render += ["--preset", "gold", "--roughness", str(ROUGHNESS)]
            if "shadows" in scene:
                render += ["--shadows", scene["shadows"]]
            for i in range(args.rounds if "cold" in parts else 0):
                # The BRDF LUT stays cached (it does not depend on the scene); the bakes do not.
                for sub in cache.iterdir() if cache.exists() else ():
                    if sub.name != "lut" and sub.is_dir():
                        shutil.rmtree(sub, ignore_errors=True)
                wall, cpu, _ = run(render, alight_env)
                add((name, "cold", "alight first"), wall, cpu)
                line = [f"alight {wall:.2f}"]
                for peer in peers:
                    if (name, peer) in failures:
                        continue
                    try:
                        wall, cpu, _ = run(peer_args(peer, "cold", str(tmp / f"{name}_{peer}.png")), peer_env)
                    except RuntimeError as e:
                        failures[(name, peer)] = str(e)
                        print(f"{peer} failed on {name}:\n{e}", file=sys.stderr)
                        continue
                    add((name, "cold", peer), wall, cpu)
                    line.append(f"{peer} {wall:.2f}")
                    peer_wall, peer_cpu = wall, cpu
                    wall, cpu, _ = run(render, alight_env)   # alternated: alight (bake cached) after each peer
                    per_round.setdefault((name, "cold", peer, "default"), []).append((wall / peer_wall, cpu / peer_cpu))
                    add((name, "cold", "alight"), wall, cpu)
                    add((name, "cold", f"alight/{peer}"), wall, cpu)
                    line.append(f"alight {wall:.2f}")
                print(f"{name} cold round {i + 1}/{args.rounds}: " + ", ".join(line) + " s", file=sys.stderr)
            for i in range(args.rounds if "steady" in parts else 0):
                line = []
                for peer in peers:
                    if (name, peer) in failures:
                        continue
                    mine = {}
                    for feature in features:
                        blob = json.dumps({"w": size, "h": size, "frames": args.frames, "scene": scene,
                                           "env": str(ENV), "features": feature})
                        mine[feature] = json.loads(run([py, "-c", ALIGHT_STEADY, blob], alight_env)[2])
                        add((name, "steady", f"{label[feature]}/{peer}"), mine[feature]["frames"], mine[feature]["cpu"])
                        add((name, "steady", label[feature]), mine[feature]["frames"], mine[feature]["cpu"])
                    try:
                        out = json.loads(run(peer_args(peer, "steady"), peer_env)[2])
                    except RuntimeError as e:
                        failures[(name, peer)] = str(e)
                        print(f"{peer} failed on {name}:\n{e}", file=sys.stderr)
                        continue
                    add((name, "steady", peer), out["frames"], out["cpu"])
                    m = statistics.median
                    if len(features) > 1:   # alight's own frame, off / default, side by side in this round
                        own.append((m(mine["off"]["frames"]) / m(mine["default"]["frames"]),
                                    m(mine["off"]["cpu"]) / m(mine["default"]["cpu"])))
                    for feature in features:
                        per_round.setdefault((name, "steady", peer, feature), []).append(
                            (m(mine[feature]["frames"]) / m(out["frames"]), m(mine[feature]["cpu"]) / m(out["cpu"])))
                    line.append(", ".join(f"{label[f]} {m(mine[f]['frames']) * 1000:.0f}" for f in features)
                                + f" / {peer} {m(out['frames']) * 1000:.0f}")
                print(f"{name} steady round {i + 1}/{args.rounds} (ms): " + ", ".join(line), file=sys.stderr)
            for who in ["alight"] + peers if "cold" in parts else ():
                if (tmp / f"{name}_{who}.png").exists():
                    shutil.copy(tmp / f"{name}_{who}.png", images / f"{name}_{who}.png")
    with open("/proc/loadavg") as f:
        load_after = f.read().split()[:3]

    m = statistics.median
    print(f"command: {' '.join(sys.argv)}")
    print(f"machine: {os.cpu_count()} cores, load average {'/'.join(load_before)} before, "
          f"{'/'.join(load_after)} after; {args.rounds} alternated rounds, {size}x{size}")
    for (name, peer), message in failures.items():
        print(f"{peer} did not run on {name}: {message.splitlines()[-1] if message else '?'}")
    for name in scenes:
        for part in ("cold", "steady"):
            rows = [(k[2], v) for k, v in results.items() if k[:2] == (name, part)]
            if not rows:
                continue
            print(f"{name}, {part} ({'process start to PNG written' if part == 'cold' else 'frame with read-back'}):")
            for who, (walls, cpus) in rows:
                if who.startswith("alight") and "/" in who:
                    continue
                print(f"  {who:30s} wall {summary(walls)}\n  {'':30s} CPU  {summary(cpus)}")
            print("  ratios of medians alight / peer, wall (CPU), then the range of the rounds' ratios; "
                  "below 1: alight takes less:")
            for feature in features if part == "steady" else ["default"]:
                if part == "steady" and len(features) > 1:
                    print(f"   {label[feature]}:")
                for peer in peers:
                    if (name, part, peer) not in results:
                        continue
                    pw, pc = results[(name, part, peer)]
                    a = results[(name, part, f"{label[feature]}/{peer}")]   # the alight runs next to this peer's
                    rounds = per_round[(name, part, peer, feature)]
                    print(f"    {peer:10s} {m(a[0]) / m(pw):.2f} ({m(a[1]) / m(pc):.2f})   rounds "
                          f"{min(r[0] for r in rounds):.2f}-{max(r[0] for r in rounds):.2f} "
                          f"({min(r[1] for r in rounds):.2f}-{max(r[1] for r in rounds):.2f})", end="")
                    if part == "cold":
                        first = results[(name, part, "alight first")]
                        print(f"   empty bake cache: {m(first[0]) / m(pw):.2f} ({m(first[1]) / m(pc):.2f})", end="")
                    print()
    if own:
        print(f"alight's own frame, shadows+occlusion off / defaults (median of {len(own)} process pairs, range): "
              f"wall {m(r[0] for r in own):.2f} ({min(r[0] for r in own):.2f}-{max(r[0] for r in own):.2f}), "
              f"CPU {m(r[1] for r in own):.2f} ({min(r[1] for r in own):.2f}-{max(r[1] for r in own):.2f})")
    if "cold" in parts:
        print(f"images: {images}/")
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""A trial, not a feature: every file part of a mesh compiled with the union of the mesh's maps
(MATERIAL_MAPS_MASK), so that parts differing only in which maps they have share one program,
against each part its own maps (alight's choice). Patches ``variants.part_defines`` as seen by
the forward pass. Asserts nothing.

    UNION=0|1 .venv/bin/python benchmarks/bench_map_union.py FILE first    # one process: first and second render
    .venv/bin/python benchmarks/bench_map_union.py FILE steady             # interleaved steady frames, off / on

``first``: 512x512 4x MSAA, prints the process and first-frame time and the programs compiled,
saves the linear frame to /tmp/alight_union_{0,1}.npy (for comparing); run it under
``MESA_SHADER_CACHE_DISABLE=true`` or a warmed ``MESA_SHADER_CACHE_DIR``. ``steady``: 12
batches of 5 ``draw_display`` frames at 1280x720, no AA, union off and on alternating.
FILE: e.g. the multi scene of benchmarks/bench_compile.py (``multi_scene``).
"""
import json, os, sys, time, statistics
t0 = time.perf_counter()
from alight.core.shader_names import MATERIAL_MAPS, map_mask
from alight.render import passes, variants
UNION = {"on": os.environ.get("UNION") == "1"}
orig = variants.part_defines
def part_defines(scene, gpu_part, part, user_maps):
    d = orig(scene, gpu_part, part, user_maps)
    if UNION["on"] and scene.mesh is not None and part.material is not None and scene.use_file_materials:
        u = 0
        for gp, p in zip(_r.meshes.parts(scene.mesh), scene.mesh.parts):
            if p.material is not None:
                u |= map_mask(set(gp.textures) & set(MATERIAL_MAPS))
        d["MATERIAL_MAPS_MASK"] = u
    return d
passes.part_defines = part_defines
from alight.core import gpu
n = [0]
o2 = gpu.ShaderLibrary.program
def program(self, v, f, defines=None):
    key = ("program", v, f, tuple(sorted((defines or {}).items())))
    if key not in self._programs: n[0] += 1
    return o2(self, v, f, defines)
gpu.ShaderLibrary.program = program
from alight.exchange.meshes import load_mesh
from alight.core.scene import Scene
from alight.render.renderer import ForwardRenderer
from alight.ibl.environment import load_environment
mesh = load_mesh(sys.argv[1])
_r = r = ForwardRenderer()
maps = r.bake(load_environment("studio"), "medium")
scene = Scene(mesh=mesh)
if sys.argv[2] == "first":
    t = time.perf_counter(); r.render(scene, maps, 512, 512, aa="msaa"); first = time.perf_counter() - t
    img = r.render(scene, maps, 512, 512, aa="msaa").linear
    import numpy as np; np.save(f"/tmp/alight_union_{int(UNION['on'])}.npy", img)
    print(json.dumps({"process": time.perf_counter() - t0, "first": first, "programs": n[0]}))
else:   # steady: interleave union off/on batches at 1280x720 no AA (draw_display)
    from alight.core.scene import Display
    scene = Scene(mesh=mesh, display=Display())
    targets = r._targets_for(1280, 720, "none", 0)
    for on in (False, True):
        UNION["on"] = on
        for _ in range(3): r.draw_display(scene, maps, targets)
    res = {False: [], True: []}; ratios = []
    for b in range(12):
        order = (False, True) if b % 2 == 0 else (True, False)
        bt = {}
        for on in order:
            UNION["on"] = on; fr = []
            for _ in range(5):
                t = time.perf_counter(); r.draw_display(scene, maps, targets); r.ctx.finish(); fr.append(time.perf_counter() - t)
            bt[on] = statistics.median(fr); res[on].append(bt[on])
        ratios.append(bt[True] / bt[False])
    print("off", [round(x*1000,1) for x in res[False]]); print("on", [round(x*1000,1) for x in res[True]])
    print(f"union/own median {statistics.median(ratios):.3f} ({min(ratios):.3f}-{max(ratios):.3f}); off {statistics.median(res[False])*1000:.1f} ms on {statistics.median(res[True])*1000:.1f} ms")

"""A glTF file's first render with Mesa's shader cache empty against warm, and where the first
frame's time goes: compiling and linking the GL programs (``ShaderLibrary.program``) or the
draws themselves (llvmpipe compiles each shader variant with LLVM at its first draw). Rounds
alternate empty and warm (A B A B ...) in fresh processes; asserts nothing.

    .venv/bin/python benchmarks/bench_compile.py [--model PATH | --scene multi] [--rounds 3] [--against REF]

"empty": ``MESA_SHADER_CACHE_DISABLE=true``; "warm": Mesa's cache in a private folder
(``MESA_SHADER_CACHE_DIR``) filled by one run first, so the user's own cache is never touched.
``--fresh`` adds "fresh" to every round: the cache on, in a new empty folder each run (a user's
first render, which also writes the cache; what another process could fill ahead of a draw).
alight's bake cache is warm in both (a shared temporary ``ALIGHT_CACHE_DIR``). The default model
is the Khronos TextureTransformTest (``../shared/data/models/khronos/``), 512x512, 4x MSAA.
``--scene multi`` writes a file like Khronos' TextureTransformMultiTest (not in the shared data)
and renders it: nine materials in a 3x3 grid of quads, each reading one map (baseColorTexture,
emissiveTexture, normalTexture, metallicRoughnessTexture, occlusionTexture) with
KHR_texture_transform on TEXCOORD_0 or TEXCOORD_1, or untransformed ("Sample"), as that file's
rows and columns do; its textures are made in numpy (``multi_scene``).
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO / "benchmarks"))
sys.path.insert(0, str(REPO))
from bench_gltf import export, this_tree  # noqa: E402

MODEL = REPO.parent / "shared" / "data" / "models" / "khronos" / "TextureTransformTest" / "glTF" / "TextureTransformTest.gltf"

PROBE = r"""
import json, sys, time
t0 = time.perf_counter()
from alight.core import gpu
compile_seconds = [0.0, 0]
mesh_variants = set()   # the mesh pass's programs (render/pbr.frag), one per distinct define set
original = gpu.ShaderLibrary.program
def program(self, vertex, fragment, defines=None):
    key = ("program", vertex, fragment, tuple(sorted((defines or {}).items())))
    new = key not in self._programs
    t = time.perf_counter()
    out = original(self, vertex, fragment, defines)
    if new and "pbr.frag" in fragment:
        mesh_variants.add(key)
    if new:
        compile_seconds[0] += time.perf_counter() - t
        compile_seconds[1] += 1
    return out
gpu.ShaderLibrary.program = program
from alight.exchange.meshes import load_mesh
from alight.core.scene import Scene
from alight.render.renderer import ForwardRenderer
from alight.ibl.environment import load_environment
mesh = load_mesh(sys.argv[1])
r = ForwardRenderer()
maps = r.bake(load_environment("studio"), "medium")
scene = Scene(mesh=mesh)
t = time.perf_counter()
r.render(scene, maps, 512, 512, aa="msaa")
first = time.perf_counter() - t
t = time.perf_counter()
r.render(scene, maps, 512, 512, aa="msaa")
second = time.perf_counter() - t
print(json.dumps({"process": time.perf_counter() - t0, "first": first, "second": second,
                  "compile": compile_seconds[0], "programs": compile_seconds[1],
                  "mesh_variants": len(mesh_variants)}))
"""


# The Khronos file's transform (every transformed map there has it): a quarter turn, scale 0.35
TRANSFORM = {"offset": [0.705, 0.285], "rotation": 1.5707963705062866, "scale": [0.35, 0.35]}
# (name, textureInfo's place, texCoord, transformed), one material each, as TextureTransformMultiTest's
# "UV 0", "UV 1" and "Sample" columns on its base colour, emission, normal, metal-rough and occlusion rows.
MULTI_MATERIALS = (
    ("BaseColorUV0", "baseColorTexture", 0, True),
    ("BaseColorUV1", "baseColorTexture", 1, True),
    ("BaseColorSample", "baseColorTexture", 0, False),
    ("EmissionUV0", "emissiveTexture", 0, True),
    ("EmissionUV1", "emissiveTexture", 1, True),
    ("NormalUV0", "normalTexture", 0, True),
    ("NormalUV1", "normalTexture", 1, True),
    ("MetalRoughUV0", "metallicRoughnessTexture", 0, True),
    ("OcclusionUV1", "occlusionTexture", 1, True),
)


def multi_scene(path: Path) -> Path:
    """A .glb like TextureTransformMultiTest: MULTI_MATERIALS on nine quads; a "Sample" quad has
    TEXCOORD_0 only (as that column's meshes), the others both sets."""
    import numpy as np
    from tests.gltf_builder import USHORT, Gltf, grid_plane

    g = Gltf()
    positions, normals, uvs, idx = grid_plane(2, size=0.9)
    y, x = np.mgrid[0:128, 0:128] / 128.0
    ring = np.abs(np.hypot(x - 0.5, y - 0.5) - 0.3) < 0.06
    mark = ring | ((np.abs(x - y) < 0.05) & (np.abs(x - 0.5) < 0.3))
    images = {   # a mark in each map's own terms (sRGB colour, tangent-space normal, G/B, R)
        "baseColorTexture": np.where(mark[..., None], [220, 40, 30], [235, 235, 235]),
        "emissiveTexture": np.where(mark[..., None], [255, 200, 40], [0, 0, 0]),
        "normalTexture": np.where(mark[..., None], [200, 128, 220], [128, 128, 255]),
        "metallicRoughnessTexture": np.where(mark[..., None], [0, 40, 255], [0, 230, 0]),
        "occlusionTexture": np.where(mark[..., None], [40, 40, 40], [255, 255, 255]),
    }
    g.use("KHR_texture_transform")
    for k, (name, slot, tex_coord, transformed) in enumerate(MULTI_MATERIALS):
        info = {"index": g.image(images[slot].astype(np.uint8)), "texCoord": tex_coord}
        if transformed:
            info["extensions"] = {"KHR_texture_transform": dict(TRANSFORM)}
        pbr = {"metallicFactor": 0.0, "roughnessFactor": 0.5}
        fields = {"name": name}
        if slot in ("baseColorTexture", "metallicRoughnessTexture"):
            pbr[slot] = info
            if slot == "metallicRoughnessTexture":
                pbr["metallicFactor"] = 1.0
        else:
            fields[slot] = info
            if slot == "emissiveTexture":
                fields["emissiveFactor"] = [1.0, 1.0, 1.0]
        mat = g.material(pbrMetallicRoughness=pbr, **fields)
        offset = np.array([(k % 3 - 1) * 1.0, (1 - k // 3) * 1.0, 0.0])
        attributes = {"POSITION": g.accessor(positions + offset, bounds=True), "NORMAL": g.accessor(normals),
                      "TEXCOORD_0": g.accessor(uvs)}
        if transformed:   # the second set: the first turned a half (what a UV 1 quad reads)
            attributes["TEXCOORD_1"] = g.accessor(1.0 - uvs)
        g.mesh([{"attributes": attributes, "indices": g.accessor(idx.ravel(), USHORT), "material": mat}], name=name)
    return g.save(path)


def run(model: Path, env_extra: dict, pythonpath: str, cache: str) -> dict:
    env = dict(os.environ, ALIGHT_CACHE_DIR=cache, PYTHONPATH=pythonpath, **env_extra)
    done = subprocess.run([sys.executable, "-c", PROBE, str(model)], env=env, capture_output=True, text=True,
                          cwd=tempfile.gettempdir())
    if done.returncode != 0:
        raise SystemExit(done.stderr[-600:])
    return json.loads(done.stdout.strip().splitlines()[-1])


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", type=Path, default=MODEL)
    ap.add_argument("--scene", choices=("model", "multi"), default="model",
                    help="multi: the nine-material TextureTransformMultiTest-like file (multi_scene)")
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--against", default=None, help="another git ref, alternated with this tree")
    ap.add_argument("--fresh", action="store_true",
                    help="also a run with Mesa's cache on in a new empty folder, every round")
    args = ap.parse_args()
    with tempfile.TemporaryDirectory(prefix="alight-compile-") as tmp:
        folder = Path(tmp)
        cache = str(folder / "alight-cache")
        if args.scene == "multi":
            args.model = multi_scene(folder / "TextureTransformMultiLike.glb")
        trees = {"this tree": str(this_tree(folder / "this"))}
        if args.against:
            trees[args.against] = str(export(args.against, folder / "other"))
        modes = {}
        for tree, path in trees.items():
            mesa = str(folder / f"mesa-{len(modes)}")
            run(args.model, {"MESA_SHADER_CACHE_DIR": mesa}, path, cache)   # fills the bake and Mesa's cache
            modes[f"{tree}, empty"] = ({"MESA_SHADER_CACHE_DISABLE": "true"}, path)
            if args.fresh:
                modes[f"{tree}, fresh"] = ({"MESA_SHADER_CACHE_DIR": None}, path)   # a new folder per run
            modes[f"{tree}, warm"] = ({"MESA_SHADER_CACHE_DIR": mesa}, path)
        results: dict[str, list[dict]] = {name: [] for name in modes}
        for r in range(args.rounds):
            for name, (extra, path) in modes.items():
                if extra.get("MESA_SHADER_CACHE_DIR", "") is None:
                    extra = {"MESA_SHADER_CACHE_DIR": str(folder / f"fresh-{r}-{list(modes).index(name)}")}
                out = run(args.model, extra, path, cache)
                results[name].append(out)
                print(f"round {r + 1} {name:22s} process {out['process']:.2f} s first frame {out['first']:.2f} s "
                      f"(compile+link {out['compile']:.2f} s, {out['programs']} programs, "
                      f"{out['mesh_variants']} of pbr.frag) second {out['second']:.2f} s",
                      flush=True)

    def med(name, key):
        values = [o[key] for o in results[name]]
        return f"{statistics.median(values):.2f} s ({min(values):.2f}-{max(values):.2f})"

    print(f"\n{args.model.name}, 512x512 4x MSAA, {args.rounds} rounds alternated")
    print("| run | process | first frame | of which compile+link | second frame |")
    print("| --- | --- | --- | --- | --- |")
    for name in modes:
        print(f"| {name} | {med(name, 'process')} | {med(name, 'first')} | {med(name, 'compile')} | {med(name, 'second')} |")
    for tree in trees:
        for cold in ("empty", "fresh") if args.fresh else ("empty",):
            pairs = list(zip(results[f"{tree}, {cold}"], results[f"{tree}, warm"]))
            ratios = [e["process"] / w["process"] for e, w in pairs]
            first = [e["first"] / w["first"] for e, w in pairs]
            print(f"{tree}: {cold} / warm, process {statistics.median(ratios):.2f}x ({min(ratios):.2f}-{max(ratios):.2f}), "
                  f"first frame {statistics.median(first):.2f}x ({min(first):.2f}-{max(first):.2f})")


if __name__ == "__main__":
    main()

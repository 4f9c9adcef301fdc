"""Cold `alight render` of each file that uses a feature against its twin that does not: the
compressed, quantized, tiled, far, odd-sized or LDR files of ../shared/data/cases/with_controls
against their controls, and DamagedHelmet as the optimisers write it (gltf-transform draco and
meshopt, gltfpack -c and -cc, its textures as KTX2 through alktx2) against the original.
Issue 20's bar: no valid file takes more than 3x its twin. Prints what it measured; asserts nothing.

    .venv/bin/python benchmarks/bench_twins.py [--rounds 3] [--size 256] [--only NAME]

One fresh process per render (imports, GL context, load, bake-cache load, first frame with its
shader compiles, PNG write), feature and control alternated (A B A B ...) so the shared machine's
load falls on both alike. The bake cache and Mesa's shader cache are warmed once for every file
first, so the figure is the file's own cost. Wall time and the child's CPU time (user + system,
which waiting for a core does not inflate) are both given; the ratio is of medians.
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared" / "data"
CASES = SHARED / "cases" / "with_controls"
HELMET = SHARED / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
NODE_BIN = REPO / "tools" / "node" / "node_modules" / ".bin"
ALIGHT = [sys.executable, "-m", "alight"]

MESH_PAIRS = [
    ("gltf_transform_draco_vcol.glb", "src_vertex_colour_sphere.glb"),
    ("gltf_transform_quantize_draco.glb", "gltf_transform_quantized_ctrl.glb"),
    ("far_1e6.glb", "far_ctrl_origin.glb"),
    ("morph_mesh_weights_1.glb", "morph_ctrl_baked.glb"),
    ("skin_mesh_node_transform.glb", "skin_ctrl_unskinned.glb"),
    ("texture_9000x4.glb", "texture_ctrl_4500x4.glb"),
    ("uv_tiling_x1000.glb", "uv_tiling_x1.glb"),
    ("obj_concave_hexagon.obj", "obj_concave_ctrl_triangles.obj"),
    ("obj_cube_s_off_no_vn.obj", "obj_cube_ctrl_flat_vn.obj"),
    ("stl_ascii_two_solids_crlf.stl", "stl_ctrl_binary.stl"),
]
ENV_PAIRS = [
    ("awkward_8198x4099.exr", "awkward_ctrl_4096x2048.exr"),
    ("ldr_srgb.png", "ldr_ctrl_decoded.exr"),
]


def helmet_twins(folder: Path) -> list[tuple[str, Path]]:
    """DamagedHelmet as the optimisers write it: (label, file) for each tool that is here."""
    out = []
    glb = folder / "helmet.glb"
    tool = NODE_BIN / "gltf-transform"
    if tool.exists():
        subprocess.run([str(tool), "copy", str(HELMET), str(glb)], check=True, capture_output=True)
        for command in ("draco", "meshopt"):
            path = folder / f"helmet_{command}.glb"
            subprocess.run([str(tool), command, str(glb), str(path)], check=True, capture_output=True)
            out.append((f"gltf-transform {command}", path))
    pack = NODE_BIN / "gltfpack"
    if pack.exists():
        for flag in ("-c", "-cc"):
            path = folder / f"helmet_gltfpack{flag}.glb"
            subprocess.run([str(pack), "-i", str(HELMET), "-o", str(path), flag], check=True, capture_output=True)
            out.append((f"gltfpack {flag}", path))
    ktx2 = helmet_ktx2(folder)
    if ktx2 is not None:
        out.append(("textures as KTX2 (UASTC, alktx2)", ktx2))
    return out


def helmet_ktx2(folder: Path) -> Path | None:
    """DamagedHelmet.gltf with every image encoded to KTX2 (UASTC) and KHR_texture_basisu
    required: no PNG or JPEG left for the reader to fall back on."""
    try:
        import alktx2
        import numpy as np
        from PIL import Image
    except ImportError:
        return None
    doc = json.loads(HELMET.read_text())
    for i, image in enumerate(doc["images"]):
        rgba = np.asarray(Image.open(HELMET.parent / image["uri"]).convert("RGBA"))
        data = alktx2.encode_raw_rgba_to_ktx2(rgba.tobytes(), rgba.shape[1], rgba.shape[0], False, codec="uastc")
        name = f"image{i}.ktx2"
        (folder / name).write_bytes(data)
        doc["images"][i] = {"uri": name, "mimeType": "image/ktx2"}
    for texture in doc["textures"]:
        texture["extensions"] = {"KHR_texture_basisu": {"source": texture.pop("source")}}
    for key in ("extensionsUsed", "extensionsRequired"):
        doc[key] = sorted(set(doc.get(key, [])) | {"KHR_texture_basisu"})
    for buffer in doc["buffers"]:
        shutil.copy(HELMET.parent / buffer["uri"], folder / buffer["uri"])
    path = folder / "helmet_ktx2.gltf"
    path.write_text(json.dumps(doc))
    return path


def render(args: list[str], out: Path, env: dict) -> tuple[float, float]:
    """(wall s, CPU s) of one `alight render` process."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t = time.perf_counter()
    proc = subprocess.run([*ALIGHT, "render", *args, "--out", str(out)], env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise SystemExit(f"alight render {' '.join(args)} failed: {proc.stderr.strip()}")
    return wall, (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--only", help="only pairs whose feature file's label contains this")
    opts = ap.parse_args()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        env = dict(os.environ, ALIGHT_CACHE_DIR=str(tmp / "cache"), MESA_SHADER_CACHE_DIR=str(tmp / "mesa"))
        size = ["--size", str(opts.size)]
        pairs = [(f, ["--mesh", str(CASES / f), *size], ["--mesh", str(CASES / c), *size]) for f, c in MESH_PAIRS]
        env_look = ["--preset", "silver", "--roughness", "0.05", "--env-rotation", "180", *size]
        pairs += [(f, ["--env", str(CASES / f), *env_look], ["--env", str(CASES / c), *env_look]) for f, c in ENV_PAIRS]
        pairs += [(f"DamagedHelmet, {label}", ["--mesh", str(path), *size], ["--mesh", str(HELMET), *size])
                  for label, path in helmet_twins(tmp)]
        if opts.only:
            pairs = [p for p in pairs if opts.only in p[0]]
        print(f"{time.strftime('%Y-%m-%d %H:%M UTC', time.gmtime())}, load average "
              f"{os.getloadavg()[0]:.1f}, {opts.rounds} rounds alternated, {opts.size}px, defaults otherwise")
        print("| feature file | its twin | wall median (range) | twin wall | x twin (wall) | x twin (CPU) |")
        print("| --- | --- | --- | --- | --- | --- |")
        worst = 0.0
        for label, feature, control in pairs:
            for args in (feature, control):   # warm the bake cache and Mesa's shader cache
                render(args, tmp / "warm.png", env)
            runs = {"feature": [], "control": []}
            for _ in range(opts.rounds):
                runs["feature"].append(render(feature, tmp / "f.png", env))
                runs["control"].append(render(control, tmp / "c.png", env))
            fw = [w for w, _ in runs["feature"]]
            cw = [w for w, _ in runs["control"]]
            fc = [c for _, c in runs["feature"]]
            cc = [c for _, c in runs["control"]]
            ratio_wall = statistics.median(fw) / statistics.median(cw)
            ratio_cpu = statistics.median(fc) / statistics.median(cc)
            worst = max(worst, ratio_cpu)
            twin = Path(control[1]).name
            print(f"| {label} | {twin} | {statistics.median(fw):.2f} s ({min(fw):.2f}-{max(fw):.2f}) | "
                  f"{statistics.median(cw):.2f} s ({min(cw):.2f}-{max(cw):.2f}) | {ratio_wall:.2f}x | {ratio_cpu:.2f}x |",
                  flush=True)
        print(f"worst CPU ratio: {worst:.2f}x")


if __name__ == "__main__":
    main()

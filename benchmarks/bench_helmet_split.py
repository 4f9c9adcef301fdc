"""Where DamagedHelmet's gap to the textured path tracer comes from: the split sum, the texture
filtering or the visibility. Prints one table; asserts nothing (results/helmet_split.md).

    PYTHONPATH=... .venv/bin/python benchmarks/bench_helmet_split.py [--size 128] [--samples 64] [--no-normal-map]
        [--toksvig] [--no-toksvig] [--lod-bias LOG2] [--keep DIR]

Six images of the same view (`--orbit 30 --elevation 10`, royal_esplanade_1k, the file's own
materials), all linear:

- render: `alight render --occlusion off` (MSAA); rendernoaa: the same with `--aa none`;
- full: the path tracer (app/accuracy/path_trace.py, seed 0, 8 bounces, jittered samples);
- nogbuf: the unoccluded environment integral (the texel sum, by one environment sample and one
  GGX sample a pass, power heuristic, no shadow rays) at alight's own G-buffer (the reference's
  rasterised inputs: mip-filtered maps at the pixel centre, as the renderer reads them);
- nocentre / nojit: the same integral at the path tracer's camera hits (its maps: bilinear, no
  mips), at the pixel centres / jittered over the pixel (the footprint's box average).

So rendernoaa vs nogbuf is alight's image-based lighting alone (same inputs), nogbuf vs nojit the
filtering of the maps (inputs averaged before shading against shading averaged over the pixel),
nojit vs full what visibility and inter-reflection add. Each pair: binned relMAE (4x4 at 128 px,
the same footprint, 8x8, at 256 px) over the blocks covered in both, split into the glossy blocks
(mean G-buffer roughness below 0.1) above the chin, the other blocks above it, and the chin (the
lowest 30% of the helmet's rows): each region's share of the whole error, its own relMAE and its
sum against the second image's. --toksvig adds the integral shaded once at the footprint's mean
inputs (an ideal mip filter) with the roughness widened by Toksvig's variance of the mean normal
(x0, x1, x2), against nojit. --no-normal-map drops normalTexture from a copy of the .gltf (in a
temporary folder) for every image. --no-toksvig renders alight's images (render, rendernoaa and
the G-buffer of nogbuf) without the normal map's widening (NORMAL_MAP_TOKSVIG off: the shading
before it); --lod-bias sets their normal maps' level-of-detail bias (NORMAL_MAP_LOD_BIAS, 0: the
plain fetch). The regions always come from the G-buffer without either. --keep DIR saves the traced
images (which alight's shading does not change) and reuses them, with alight's three beside.
"""

from __future__ import annotations

import argparse
import json
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

DATA = Path(__file__).resolve().parent.parent.parent / "shared" / "data"   # as bench_occlusion.py
HELMET = DATA / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
ENV = DATA / "env" / "royal_esplanade_1k.hdr"
VIEW = ["--orbit", "30", "--elevation", "10"]


def helmet_copy(folder: Path, normal_map: bool) -> Path:
    """The .gltf with absolute uris (and without normalTexture unless ``normal_map``)."""
    doc = json.loads(HELMET.read_text())
    for item in doc.get("buffers", []) + doc.get("images", []):
        item["uri"] = str(HELMET.parent / item["uri"])
    if not normal_map:
        for m in doc["materials"]:
            m.pop("normalTexture", None)
    out = folder / "helmet.gltf"
    out.write_text(json.dumps(doc))
    return out


def scene_setup(mesh: Path, size: int):
    from alight.frontends.cli import build_parser
    from alight.frontends.options import build_look
    from alight.frontends.scene_setup import scene_from_flags

    args = build_parser().parse_args(["reference", "--mesh", str(mesh), "--env", str(ENV), *VIEW,
                                      "--size", str(size), "--out", "unused.exr"])
    return scene_from_flags(args, args.size, build_look(args), lambda line: None)


# The normal maps' level-of-detail bias alight's images are made with (--lod-bias; None: the
# renderer's own, alight.render.normal_spread.NORMAL_MAP_LOD_BIAS).
LOD_BIAS: list[float | None] = [None]


def alight_command(toksvig: bool) -> list[str]:
    """`alight`, with NORMAL_MAP_TOKSVIG off unless ``toksvig`` (the shading before it) and the
    --lod-bias given (alight.render.normal_spread)."""
    if toksvig and LOD_BIAS[0] is None:
        return ["-m", "alight"]
    return ["-c", "import sys; import alight.render.normal_spread as s; "
            + ("" if toksvig else "s.NORMAL_MAP_TOKSVIG = False; ")
            + ("" if LOD_BIAS[0] is None else f"s.NORMAL_MAP_LOD_BIAS = {LOD_BIAS[0]!r}; ")
            + "from alight.frontends.cli import main; sys.exit(main())"]


def render(mesh: Path, size: int, folder: Path, extra: list[str], toksvig: bool = True) -> np.ndarray:
    from alight.accuracy.metrics import read_linear

    out = folder / f"render{'_'.join(extra)}.exr"
    alight = alight_command(toksvig)

    subprocess.run([sys.executable, *alight, "render", "--mesh", str(mesh), "--env", str(ENV), *VIEW,
                    "--size", str(size), "--occlusion", "off", "--out", str(out), *extra],
                   check=True, stdout=subprocess.DEVNULL)
    return read_linear(str(out))


def gbuffer(setup, toksvig: bool = True, lod_bias: float | None = None) -> dict[str, np.ndarray]:
    from alight.accuracy.reference import GBUFFER, ReferenceRenderer
    from alight.render import normal_spread

    was = normal_spread.NORMAL_MAP_TOKSVIG, normal_spread.NORMAL_MAP_LOD_BIAS
    normal_spread.NORMAL_MAP_TOKSVIG = toksvig
    if lod_bias is not None:
        normal_spread.NORMAL_MAP_LOD_BIAS = lod_bias
    try:
        texs = ReferenceRenderer().mesh_gbuffer(setup.scene, setup.width, setup.height)
    finally:
        normal_spread.NORMAL_MAP_TOKSVIG, normal_spread.NORMAL_MAP_LOD_BIAS = was
    return {n: np.frombuffer(t.read(), np.float32).reshape(setup.height, setup.width, 4)[::-1].astype(np.float64)
            for n, t in zip(GBUFFER, texs)}


def kept(folder: str | None, name: str, make) -> np.ndarray:
    """``make()``, or its result saved in ``folder`` by an earlier run with the same arguments
    (--keep: the traced images do not depend on alight's shading)."""
    if folder is None:
        return make()
    path = Path(folder) / f"{name}.npy"
    if path.is_file():
        return np.load(path)
    image = make()
    Path(folder).mkdir(parents=True, exist_ok=True)
    np.save(path, image)
    return image


def integrate(n, v, base, metal, rough, f0, env, rng) -> np.ndarray:
    """One pass of the unoccluded environment integral: an environment sample and a GGX sample,
    power heuristic (path_trace.py's strategies without the shadow rays)."""
    from alight.accuracy import path_trace as pt

    rough = np.maximum(rough, pt.MIN_TRACE_ROUGHNESS)
    p_spec = pt._specular_probability(pt._dot(n, v), base, metal, f0)
    l, radiance, pe = env.sample(rng.random((len(n), 3)))
    f = pt.brdf_cos(n, v, l, base, metal, rough, f0)
    pb = pt.brdf_pdf(n, v, l, rough, p_spec)
    out = np.where((pt._dot(n, l) > 0)[:, None], f * radiance * (pe / np.maximum(pe * pe + pb * pb, 1e-300))[:, None], 0.0)
    l = pt.sample_brdf(n, v, rough, p_spec, rng.random((len(n), 3)))
    pb = pt.brdf_pdf(n, v, l, rough, p_spec)
    f = pt.brdf_cos(n, v, l, base, metal, rough, f0)
    pe = env.pdf(l)
    ok = (pt._dot(n, l) > 0) & (pb > 0)
    return out + np.where(ok[:, None], f * env.lookup(l) * (pb / np.maximum(pb * pb + pe * pe, 1e-300))[:, None], 0.0)


def sampler(setup):
    from alight.accuracy.path_trace import EnvironmentSampler

    return EnvironmentSampler(setup.environment.radiance, setup.scene.env_rotation_deg, setup.scene.env_intensity)


def unoccluded_gbuffer(setup, g, samples: int) -> np.ndarray:
    from alight.accuracy.path_trace import _normalize

    h, w = g["position"].shape[:2]
    idx = np.flatnonzero(g["position"][..., 3].ravel() > 0.5)
    col = lambda name, c: g[name][..., c].reshape(h * w, -1)[idx]   # noqa: E731
    # float32 normals are unit to 1e-7, which is alpha^2 at roughness 0.01: D's peak explodes
    n, v = _normalize(col("normal", slice(0, 3))), _normalize(col("view", slice(0, 3)))
    rough, metal = col("normal", 3)[:, 0], col("view", 3)[:, 0]
    base = col("base_color", slice(0, 3))
    f0 = col("specular_f0", slice(0, 3)) * (1 - metal)[:, None] + base * metal[:, None]
    env, rng = sampler(setup), np.random.Generator(np.random.PCG64(0))
    acc = sum(integrate(n, v, base, metal, rough, f0, env, rng) for _ in range(samples))
    out = np.zeros((h * w, 4))
    out[idx, :3] = col("emissive", slice(0, 3)) + acc / samples
    out[idx, 3] = 1.0
    return out.reshape(h, w, 4)


def unoccluded_hits(setup, samples: int, jitter: bool) -> np.ndarray:
    from alight.accuracy import path_trace as pt
    from alight.core.scene import default_camera

    scene, w, h = setup.scene, setup.width, setup.height
    geom, _ = pt.scene_geometry(scene)
    rays = pt._Rays(geom)
    camera = scene.camera if scene.camera is not None else default_camera(scene.mesh, w / h)
    env, rng, tb = sampler(setup), np.random.Generator(np.random.PCG64(0)), geom.table
    acc, cover = np.zeros((w * h, 3)), np.zeros(w * h)
    for _ in range(samples):
        pix = np.arange(w * h)
        origin, direction = pt._camera_rays(camera, w / h, w, h, pix, rng, jitter)
        prim, _dist, bu, bv = rays.hit(origin, direction, camera=True)
        hit = prim >= 0
        acc[pix[~hit]] += env.lookup(direction[~hit])
        pix, prim, bu, bv, direction = pix[hit], prim[hit], bu[hit], bv[hit], direction[hit]
        cover[pix] += 1
        nv = geom.normals[prim]
        n = pt._normalize((1 - bu - bv)[:, None] * nv[:, 0] + bu[:, None] * nv[:, 1] + bv[:, None] * nv[:, 2])
        v = -direction
        n = np.where((pt._dot(geom.ng[prim], v) < 0)[:, None], -n, n)
        m = geom.material[prim]
        base, metal, rough, emissive, _, _, n = geom.maps.shade(
            prim, bu, bv, m, n, tb["base"][m], tb["metallic"][m], tb["roughness"][m], tb["emissive"][m], None, None,
            pt.MIN_TRACE_ROUGHNESS)
        f0 = tb["specular_f0"][m] * (1 - metal)[:, None] + base * metal[:, None]
        acc[pix] += emissive + integrate(n, v, base, metal, rough, f0, env, rng)
    out = np.zeros((h * w, 4))
    out[:, :3], out[:, 3] = acc / samples, cover / samples
    return out.reshape(h, w, 4)


def footprint_mean_inputs(setup, samples: int, widen: float) -> np.ndarray:
    """The integral once at the footprint's mean inputs (the tracer's maps averaged over
    ``samples`` jittered hits a pixel: an ideal mip filter), the roughness widened by Toksvig's
    variance of the mean normal (alpha^2 + widen (1 - |n|) / |n|; widen 0: none). Pixels only
    partly covered are left out (alpha 0)."""
    from alight.accuracy import path_trace as pt
    from alight.core.scene import default_camera

    scene, w, h = setup.scene, setup.width, setup.height
    geom, _ = pt.scene_geometry(scene)
    rays = pt._Rays(geom)
    camera = scene.camera if scene.camera is not None else default_camera(scene.mesh, w / h)
    rng, tb = np.random.Generator(np.random.PCG64(5)), geom.table
    sums = {k: np.zeros((w * h, 3)) for k in ("n", "v", "base", "em")} | {k: np.zeros(w * h) for k in ("r", "m", "c")}
    for _ in range(samples):
        pix = np.arange(w * h)
        origin, direction = pt._camera_rays(camera, w / h, w, h, pix, rng, True)
        prim, _dist, bu, bv = rays.hit(origin, direction, camera=True)
        hit = prim >= 0
        pix, prim, bu, bv, direction = pix[hit], prim[hit], bu[hit], bv[hit], direction[hit]
        nv = geom.normals[prim]
        n = pt._normalize((1 - bu - bv)[:, None] * nv[:, 0] + bu[:, None] * nv[:, 1] + bv[:, None] * nv[:, 2])
        n = np.where((pt._dot(geom.ng[prim], -direction) < 0)[:, None], -n, n)
        m = geom.material[prim]
        base, metal, rough, emissive, _, _, n = geom.maps.shade(
            prim, bu, bv, m, n, tb["base"][m], tb["metallic"][m], tb["roughness"][m], tb["emissive"][m], None, None, 0.0)
        for key, value in (("n", n), ("v", -direction), ("base", base), ("em", emissive), ("r", rough), ("m", metal),
                           ("c", np.ones(len(pix)))):
            np.add.at(sums[key], pix, value)
    idx = np.flatnonzero(sums["c"] == samples)
    mean = {k: a[idx] / samples for k, a in sums.items()}
    length = np.linalg.norm(mean["n"], axis=1)
    alpha2 = np.minimum(mean["r"] ** 4 + widen * np.maximum(1 - length, 0) / np.maximum(length, 1e-6), 1.0)
    n, v, base, metal = pt._normalize(mean["n"]), pt._normalize(mean["v"]), mean["base"], mean["m"]
    f0 = 0.04 * (1 - metal)[:, None] + base * metal[:, None]
    env, rng = sampler(setup), np.random.Generator(np.random.PCG64(0))
    acc = sum(integrate(n, v, base, metal, alpha2 ** 0.25, f0, env, rng) for _ in range(samples))
    out = np.zeros((h * w, 4))
    out[idx, :3] = mean["em"] + acc / samples
    out[idx, 3] = 1.0
    return out.reshape(h, w, 4)


def table(images: dict[str, np.ndarray], g: dict[str, np.ndarray], factor: int) -> list[str]:
    from alight.accuracy.binned import binned_sums, covered_blocks

    rough = binned_sums(g["normal"][..., 3:4], factor)[..., 0] / factor ** 2
    keep = covered_blocks(images["render"], images["full"], factor)
    rows = np.nonzero(keep.any(axis=1))[0]
    row_of = np.arange(keep.shape[0])[:, None] * np.ones((1, keep.shape[1]))
    chin = row_of >= rows.min() + 0.7 * (rows.max() - rows.min() + 1)
    regions = (("glossy r<0.1", (rough < 0.1) & ~chin), ("r>=0.1", (rough >= 0.1) & ~chin), ("chin", chin))
    sums = {k: binned_sums(np.asarray(a, np.float64)[..., :3], factor) for k, a in images.items()}
    light = sums["full"][keep].sum()
    lines = [f"blocks {factor}x{factor}: " + "; ".join(
        f"{name} {int((keep & m).sum())} ({sums['full'][keep & m].sum() / light * 100:.0f}% of the light)"
        for name, m in regions),
        "| pair | binned % | " + " | ".join(f"{name}: share, own %, sum ratio" for name, _ in regions) + " |",
        "|---|---|" + "---|" * len(regions)]
    for a, b in (("render", "full"), ("rendernoaa", "nogbuf"), ("nogbuf", "nocentre"), ("nocentre", "nojit"),
                 ("nogbuf", "nojit"), ("nojit", "full"), ("render", "rendernoaa"),
                 *((k, "nojit") for k in images if k.startswith("mean inputs"))):
        t, r = sums[a], sums[b]
        k = covered_blocks(images[a], images[b], factor)
        err = np.abs(t - r)
        total = r[k].sum()
        cells = [f"{err[k & m].sum() / total * 100:.1f}, {err[k & m].sum() / r[k & m].sum() * 100:.1f}, "
                 f"{t[k & m].sum() / r[k & m].sum():.3f}" for _, m in regions]
        lines.append(f"| {a} vs {b} | {err[k].sum() / total * 100:.1f} | " + " | ".join(cells) + " |")
    return lines


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--size", type=int, default=128)
    parser.add_argument("--samples", type=int, default=64)
    parser.add_argument("--no-normal-map", action="store_true")
    parser.add_argument("--toksvig", action="store_true",
                        help="also shade once at the footprint's mean inputs, without and with Toksvig's widening")
    parser.add_argument("--no-toksvig", action="store_true",
                        help="alight's render and G-buffer without the normal map's widening (NORMAL_MAP_TOKSVIG off)")
    parser.add_argument("--lod-bias", type=float, metavar="LOG2",
                        help="alight's normal maps fetched with this level-of-detail bias (NORMAL_MAP_LOD_BIAS; "
                             "0: none; default: the renderer's)")
    parser.add_argument("--keep", metavar="DIR",
                        help="keep the traced images (full, nocentre, nojit, mean inputs) in DIR and reuse them")
    args = parser.parse_args()
    from alight.accuracy.path_trace import TraceSettings, trace

    on = not args.no_toksvig
    LOD_BIAS[0] = args.lod_bias
    from alight.render.normal_spread import NORMAL_MAP_LOD_BIAS

    bias = NORMAL_MAP_LOD_BIAS if args.lod_bias is None else args.lod_bias
    tag = f"{args.size}_{args.samples}_{'off' if args.no_normal_map else 'on'}"
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        mesh = helmet_copy(folder, not args.no_normal_map)
        setup = scene_setup(mesh, args.size)
        # the regions by the roughness the maps give, unwidened (the same blocks either way)
        g = gbuffer(setup, toksvig=False, lod_bias=0.0)
        images = {"render": render(mesh, args.size, folder, [], on),
                  "rendernoaa": render(mesh, args.size, folder, ["--aa", "none"], on),
                  "full": kept(args.keep, f"full_{tag}", lambda: trace(
                      setup.scene, setup.environment.radiance, setup.width, setup.height,
                      TraceSettings(samples=args.samples, seed=0)).linear),
                  "nogbuf": unoccluded_gbuffer(setup, gbuffer(setup, on, LOD_BIAS[0]), args.samples),
                  "nocentre": kept(args.keep, f"nocentre_{tag}", lambda: unoccluded_hits(setup, args.samples, False)),
                  "nojit": kept(args.keep, f"nojit_{tag}", lambda: unoccluded_hits(setup, args.samples, True))}
        if args.toksvig:
            for widen in (0.0, 1.0, 2.0):
                images[f"mean inputs, toksvig x{widen:g}"] = kept(
                    args.keep, f"mean{widen:g}_{tag}", lambda: footprint_mean_inputs(setup, args.samples, widen))
        if args.keep:
            for name in ("render", "rendernoaa", "nogbuf"):
                np.save(Path(args.keep) / f"{name}_{tag}_{'toksvig' if on else 'old'}_bias{bias:g}.npy", images[name])
    print(f"DamagedHelmet {args.size} px, {args.samples} samples, normal map {'off' if args.no_normal_map else 'on'}, "
          f"NORMAL_MAP_TOKSVIG {'on' if on else 'off'}, NORMAL_MAP_LOD_BIAS {bias:g}")
    print("\n".join(table(images, g, max(4, args.size // 32))))
    return 0


if __name__ == "__main__":
    sys.exit(main())

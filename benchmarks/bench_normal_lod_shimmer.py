"""The shimmer the normal maps' level-of-detail bias may add (NORMAL_MAP_LOD_BIAS,
alight.render.normal_spread): DamagedHelmet orbiting in small steps, each bias's temporal flicker
against a supersampled truth's. Prints one table; asserts nothing (results/normal_lod_shimmer.md).

    PYTHONPATH=... .venv/bin/python benchmarks/bench_normal_lod_shimmer.py [--size 128] [--frames 42]
        [--start 30] [--step 0.2] [--biases 0,-0.5,-1] [--supersample 4]
        [--strip DIR]

DamagedHelmet with its own materials under royal_esplanade_1k, through ``alight.Renderer``
(4x MSAA, quality medium, background transparent so alpha is the coverage; occlusion and shadows
off, so nothing but the shading at the pixels changes between the runs), the camera orbiting from
``--start`` degrees (30) by ``--step`` degrees a frame at elevation 10. For each bias a Renderer
of its own, the module constant set before its first render and kept while it renders
(variants.py reads it when the parts' programs are chosen; 0 compiles no define). The truth:
bias 0 rendered at 4x the size (``--supersample``) and box-averaged 4x4 in linear radiance (the
pixel's footprint supersampled: the filtered answer's own temporal behaviour, what a moving image
should do; at 4x it still flickers, so the ratios to it are lower bounds: results page).

Flicker, per consecutive triple of frames, is the second difference |I_t - 2 I_{t+1} + I_{t+2}|
(smooth motion at a constant speed cancels; a highlight that pops in and out of a pixel does not),
averaged over the helmet's interior pixels (alpha 1 in all three frames of every image compared)
and over the triples: in linear luminance (relative to the truth's mean luminance on the same
pixels) and in display sRGB (ACES, the sRGB curve: metrics.tonemapped_srgb, 0-255), with the share
of pixel-triples whose sRGB second difference exceeds 4/255 (a step one sees). Regions: the whole
helmet, and the glossy pixels (G-buffer roughness below 0.1 at the middle frame, bias 0, 1x: the
visor and the polished metal) and the rest. Each figure is also given as a ratio to the truth's.

``--strip DIR`` writes DIR/shimmer_visor_<size>_<start>.png: a crop around the visor over 8
consecutive frames (columns), bias 0, the lowest bias and the truth (rows), sRGB, enlarged 4x; and
DIR/shimmer_map_<size>_<start>.png: each image's mean sRGB second difference per pixel, side by side.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data"
HELMET = DATA / "models" / "DamagedHelmet" / "DamagedHelmet.gltf"
ENV = DATA / "env" / "royal_esplanade_1k.hdr"
START_DEG, ELEVATION_DEG = 30.0, 10.0
SUPERSAMPLE = 4
GLOSSY = 0.1          # G-buffer roughness below this: the glossy region (as bench_helmet_split.py)
VISIBLE = 4.0         # an sRGB second difference above this (of 255) counts as a visible step


def frames(bias: float, size: int, count: int, start: float, step: float, render_size: int,
           gbuffer: bool = False):
    """(count, render_size, render_size, 4) linear frames with NORMAL_MAP_LOD_BIAS = ``bias``, and
    with ``gbuffer`` the (count, size, size) roughness of the G-buffer at ``size``."""
    import alight
    from alight.accuracy.reference import ReferenceRenderer
    from alight.render import normal_spread

    was = normal_spread.NORMAL_MAP_LOD_BIAS
    normal_spread.NORMAL_MAP_LOD_BIAS = bias
    out, rough = [], []
    try:
        r = alight.Renderer(size, size, aa="msaa", background="transparent")
        r.set_mesh(str(HELMET)).set_environment(str(ENV))
        r.set_occlusion("off").set_shadows("off")
        with r:
            for i in range(count):
                r.set_camera(orbit_deg=start + i * step, elevation_deg=ELEVATION_DEG)
                out.append(r.render(render_size, render_size, linear=True).astype(np.float32))
                if gbuffer:
                    with r._renderer.ctx:
                        texs = ReferenceRenderer(r._renderer).mesh_gbuffer(r.scene, size, size)
                        normal = np.frombuffer(texs[1].read(), np.float32).reshape(size, size, 4)[::-1]
                        for t in texs:
                            t.release()
                    rough.append(normal[..., 3].copy())
    finally:
        normal_spread.NORMAL_MAP_LOD_BIAS = was
    return np.stack(out), (np.stack(rough) if gbuffer else None)


def box(images: np.ndarray, k: int) -> np.ndarray:
    n, h, w, c = images.shape
    return images.reshape(n, h // k, k, w // k, k, c).mean(axis=(2, 4))


def luminance(rgb: np.ndarray) -> np.ndarray:
    return rgb[..., 0] * 0.2126 + rgb[..., 1] * 0.7152 + rgb[..., 2] * 0.0722


def flicker(seq: dict[str, np.ndarray], region: np.ndarray) -> dict[str, tuple[float, float, float]]:
    """Per image: (mean |second difference| of linear luminance over the region's pixel-triples,
    relative to the truth's mean luminance there; the same of display sRGB (0-255, mean of RGB);
    the share of pixel-triples whose sRGB second difference exceeds VISIBLE)."""
    from alight.accuracy.metrics import tonemapped_srgb

    out = {}
    truth_lum = luminance(seq["truth"][1:-1, ..., :3])[region].mean()
    for name, s in seq.items():
        lum = luminance(s[..., :3])
        d_lin = np.abs(lum[:-2] - 2 * lum[1:-1] + lum[2:])[region].mean() / truth_lum
        srgb = np.stack([tonemapped_srgb(f) for f in s]) * 255.0
        d2 = np.abs(srgb[:-2] - 2 * srgb[1:-1] + srgb[2:]).mean(axis=-1)
        out[name] = (float(d_lin), float(d2[region].mean()), float((d2[region] > VISIBLE).mean()))
    return out


def strip(seq: dict[str, np.ndarray], glossy: np.ndarray, path: Path, columns: int = 8, zoom: int = 4) -> None:
    """A crop around the glossy region's largest part over ``columns`` consecutive frames."""
    from alight.accuracy.metrics import tonemapped_srgb
    from alight.exchange.output import write_image

    ys, xs = np.nonzero(glossy)
    cy, cx = int(np.median(ys)), int(np.median(xs))
    size = glossy.shape[0]
    half = max(12, size // 6)
    y0, x0 = np.clip(cy - half, 0, size - 2 * half), np.clip(cx - half, 0, size - 2 * half)
    rows, columns = [], min(columns, len(next(iter(seq.values()))))
    for name, s in seq.items():
        tiles = [tonemapped_srgb(s[i, y0:y0 + 2 * half, x0:x0 + 2 * half]) for i in range(columns)]
        row = np.concatenate([np.pad(t, ((1, 1), (1, 1), (0, 0)), constant_values=1.0) for t in tiles], axis=1)
        rows.append(row)
    image = np.concatenate(rows, axis=0)
    image = np.repeat(np.repeat(image, zoom, axis=0), zoom, axis=1)
    write_image(path, (np.clip(image, 0, 1) * 255 + 0.5).astype(np.uint8), linear=False)
    print(f"wrote {path} (rows: {', '.join(seq)}; frames 0-{columns - 1}; crop x {x0}-{x0 + 2 * half}, "
          f"y {y0}-{y0 + 2 * half} of {size} px)")


def flicker_map(seq: dict[str, np.ndarray], interior: np.ndarray, path: Path, zoom: int = 2) -> None:
    """Each image's mean sRGB second difference per pixel over the triples (white: 16/255 and
    above), side by side, the helmet's interior only."""
    from alight.accuracy.metrics import tonemapped_srgb
    from alight.exchange.output import write_image

    inside = interior.all(axis=0)
    tiles = []
    for s in seq.values():
        srgb = np.stack([tonemapped_srgb(f) for f in s]) * 255.0
        d2 = np.abs(srgb[:-2] - 2 * srgb[1:-1] + srgb[2:]).mean(axis=(0, -1))
        tiles.append(np.pad(np.where(inside, np.clip(d2 / 16.0, 0, 1), 0.15), 2, constant_values=1.0))
    image = np.repeat(np.repeat(np.concatenate(tiles, axis=1), zoom, axis=0), zoom, axis=1)
    write_image(path, np.repeat((image * 255 + 0.5).astype(np.uint8)[..., None], 3, axis=2), linear=False)
    print(f"wrote {path} (left to right: {', '.join(seq)}; mean sRGB second difference, white >= 16/255)")


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--size", type=int, default=128)
    ap.add_argument("--frames", type=int, default=42, help="frames rendered (frames - 2 triples)")
    ap.add_argument("--start", type=float, default=START_DEG, help="the orbit's first angle, degrees")
    ap.add_argument("--step", type=float, default=0.2, help="degrees of orbit a frame")
    ap.add_argument("--biases", default="0,-0.5,-1", help="comma-separated NORMAL_MAP_LOD_BIAS values")
    ap.add_argument("--supersample", type=int, default=SUPERSAMPLE, help="the truth's size factor (box-averaged)")
    ap.add_argument("--strip", metavar="DIR", help="write a PNG strip of visor crops over consecutive frames")
    args = ap.parse_args(argv)
    biases = [float(b) for b in args.biases.split(",")]

    seq: dict[str, np.ndarray] = {}
    t0 = time.perf_counter()
    rough = None
    for b in biases:
        seq[f"bias {b:g}"], g = frames(b, args.size, args.frames, args.start, args.step, args.size,
                                       gbuffer=rough is None and b == 0)
        rough = g if g is not None else rough
        print(f"bias {b:g}: {time.perf_counter() - t0:.0f} s", flush=True)
    truth, _ = frames(0.0, args.size, args.frames, args.start, args.step, args.size * args.supersample)
    seq["truth"] = box(truth, args.supersample)
    print(f"truth: {time.perf_counter() - t0:.0f} s", flush=True)
    if rough is None:
        _, rough = frames(0.0, args.size, args.frames, args.start, args.step, args.size, gbuffer=True)

    names = list(seq)
    base = names[0]
    for name in names[1:]:
        if name != "truth":
            print(f"{name} vs {base}: mean |linear difference| at frame 0 "
                  f"{np.abs(seq[name][0, ..., :3] - seq[base][0, ..., :3]).mean():.5f}")
    covered = np.ones(seq["truth"].shape[:3], bool)
    for s in seq.values():
        covered &= s[..., 3] > 0.999
    interior = covered[:-2] & covered[1:-1] & covered[2:]
    glossy = interior & (rough[1:-1] < GLOSSY)
    regions = {"helmet": interior, f"glossy r<{GLOSSY:g}": glossy, f"r>={GLOSSY:g}": interior & ~glossy}
    print(f"\nDamagedHelmet {args.size} px, royal_esplanade_1k, 4x MSAA, occlusion and shadows off; "
          f"orbit {args.start:g} + {args.step:g} deg a frame, elevation {ELEVATION_DEG:g}, {args.frames} frames "
          f"({args.frames - 2} triples); truth: bias 0 at {args.supersample}x, box-averaged")
    print(f"pixels a triple: helmet {interior.sum() / len(interior):.0f}, glossy {glossy.sum() / len(glossy):.0f}")
    print("| region | image | flicker, linear lum. (% of mean) | / truth | flicker, sRGB (of 255) | / truth | "
          f"share > {VISIBLE:g}/255 | / truth |")
    print("|---|---|---|---|---|---|---|---|")
    for rname, region in regions.items():
        f = flicker(seq, region)
        t = f["truth"]
        for name in names:
            v = f[name]
            print(f"| {rname} | {name} | {v[0] * 100:.2f} | {v[0] / t[0]:.2f} | {v[1]:.2f} | {v[1] / t[1]:.2f} | "
                  f"{v[2] * 100:.1f}% | {v[2] / max(t[2], 1e-9):.2f} |")
    if args.strip:
        Path(args.strip).mkdir(parents=True, exist_ok=True)
        keep = [n for n in names if n in (base, "truth") or n == f"bias {min(biases):g}"]
        strip({n: seq[n] for n in keep}, glossy[0], Path(args.strip) / f"shimmer_visor_{args.size}_{args.start:g}.png")
        flicker_map(seq, interior, Path(args.strip) / f"shimmer_map_{args.size}_{args.start:g}.png")
    return 0


if __name__ == "__main__":
    sys.exit(main())

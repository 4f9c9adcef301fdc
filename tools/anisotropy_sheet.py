"""docs/anisotropy_compare.png: KHR_materials_anisotropy looked at.

Top row: brushed_aluminium in the probe view (docs/conventions.md) under royal_esplanade: the exact
answer (docs/layer_anisotropy.md, summed in numpy over the map reduced by 4), alight's stretched
lookup, the round lookup and the Khronos sample viewer's bent normal (the last two through
anisotropy.glsl's ANISOTROPY_LOOKUP, as benchmarks/bench_anisotropy.py selects them). Below:
the Khronos CompareAnisotropy model (left: without the layer, right: with it; the right cap
has the spiral anisotropyTexture) under two environments. Labels are drawn with Pillow.

    .venv/bin/python tools/anisotropy_sheet.py            # writes docs/anisotropy_compare.png
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

REPO = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(REPO))
ENV = REPO.parent / "shared" / "data" / "env"
MODEL = REPO.parent / "shared" / "data" / "models" / "khronos" / "CompareAnisotropy" / "glTF-Binary" / "CompareAnisotropy.glb"


def _srgb(linear: np.ndarray, exposure: float = 0.0) -> np.ndarray:
    from alight.core.shading import linear_to_srgb, tonemap_aces_fitted

    return (linear_to_srgb(tonemap_aces_fitted(linear[..., :3] * 2.0 ** exposure)) * 255.0 + 0.5).astype(np.uint8)


def _label(tile: np.ndarray, text: str) -> np.ndarray:
    img = Image.fromarray(tile)
    draw = ImageDraw.Draw(img)
    draw.rectangle((0, 0, 8 + 6 * len(text), 14), fill=(0, 0, 0))
    draw.text((4, 2), text, fill=(255, 255, 255))
    return np.asarray(img)


def probe_row(size: int = 192) -> np.ndarray:
    from alight.accuracy.converged import downsample_equirect
    from alight.accuracy.ground_truth import anisotropic_ground_truth_terms, probe_points
    from alight.core.scene import Scene
    from alight.exchange.presets import load_preset
    from alight.ibl.environment import load_environment
    from benchmarks.bench_anisotropy import renderers

    env = load_environment(str(ENV / "royal_esplanade_1k.hdr"))
    m = load_preset("brushed_aluminium")
    pts, inside = probe_points(size)
    terms = anisotropic_ground_truth_terms(downsample_equirect(env.radiance, 4), pts, (0.0, 0.0, 1.0), None,
                                           [(m.roughness, m.anisotropy_strength, m.anisotropy_rotation)])[0]
    truth = np.zeros((size, size, 3))
    truth[inside] = terms.combine(m.base_color, m.metallic, m.specular_f0)
    tiles = [_label(_srgb(truth), "exact answer")]
    rs, tmp = renderers()
    maps = rs["stretched"].bake(env, "medium")
    for name, label in (("stretched", "alight (stretched)"), ("round", "round lookup"), ("bent", "bent normal")):
        got = rs[name].render(Scene(material=m, view="probe"), maps, size, size, read_srgb=False).linear
        err = np.abs(got[..., :3] - truth)[inside].sum() / np.abs(truth)[inside].sum()
        tiles.append(_label(_srgb(got), f"{label} {100 * err:.1f}%"))
    tmp.cleanup()
    return np.concatenate(tiles, axis=1)


def compare_rows(width: int) -> list[np.ndarray]:
    import alight

    rows = []
    with alight.Renderer(512, quality="medium") as r:
        r.set_mesh(str(MODEL))
        for env in ("royal_esplanade_1k.hdr", "venice_sunset_1k.hdr"):
            r.set_environment(str(ENV / env))
            img = r.render(1600, 900)[..., :3]
            h, w = img.shape[:2]
            crop = img[int(h * 0.25):int(h * 0.75), int(w * 0.27):int(w * 0.73)]
            scale = width / crop.shape[1]
            crop = np.asarray(Image.fromarray(crop).resize((width, int(crop.shape[0] * scale)), Image.LANCZOS))
            rows.append(_label(crop, f"CompareAnisotropy, {env.split('_1k')[0]}: left without, right with the layer"))
    return rows


def main() -> int:
    top = probe_row()
    rows = [top] + compare_rows(top.shape[1])
    sheet = np.concatenate(rows, axis=0)
    out = REPO / "docs" / "anisotropy_compare.png"
    Image.fromarray(sheet).save(out)
    print(out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

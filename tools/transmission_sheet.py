"""Renders docs/transmission.png: the transmission layer's contact sheet.

Row 1-2: the transmissive presets (water, plastic_glass_low, glass_high_ruby, diamond) and a
thin-walled glass beside plastic_high (opaque, for contrast), in the built-in studio and under
venice_sunset_1k. Row 3: the Khronos Compare* pairs (each: without the feature on the left, with
it on the right; the glTF-Alpha sphere of CompareTransmission is alpha BLEND) under
royal_esplanade_1k, with a closer camera than alight's framing of the whole file.

    .venv/bin/python tools/transmission_sheet.py [--size 320]
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared" / "data"
PRESETS = ["plastic_high", "water", "plastic_glass_low", "glass_high_ruby", "diamond", "thin glass"]
COMPARE = ["CompareTransmission", "CompareVolume", "CompareIor"]


def label(tile: np.ndarray, text: str) -> np.ndarray:
    from PIL import Image, ImageDraw

    im = Image.fromarray(tile)
    draw = ImageDraw.Draw(im)
    draw.rectangle((0, 0, im.width, 16), fill=(0, 0, 0))
    draw.text((4, 2), text, fill=(255, 255, 255))
    return np.asarray(im)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=320)
    ap.add_argument("--out", default=str(REPO / "docs" / "transmission.png"))
    args = ap.parse_args(argv)

    from alight.core.material import Material
    from alight.core.mesh import sphere
    from alight.core.scene import Camera, Scene
    from alight.exchange.meshes import load_mesh
    from alight.exchange.output import write_image
    from alight.exchange.presets import load_preset
    from alight.ibl.environment import load_environment, studio_environment
    from alight.render.renderer import ForwardRenderer

    size = args.size
    materials = {name: load_preset(name) for name in PRESETS if name != "thin glass"}
    materials["thin glass"] = Material(base_color=(1.0, 1.0, 1.0), roughness=0.05, transmission=1.0, ior=1.5,
                                       name="thin glass")
    rows = []
    with ForwardRenderer() as r:
        ball = sphere()
        for env_label, env in (("studio", studio_environment()),
                               ("venice_sunset", load_environment(str(SHARED / "env" / "venice_sunset_1k.hdr")))):
            maps = r.bake(env, "medium")
            rows.append([label(r.render(Scene(mesh=ball, material=m), maps, size, size, read_linear=False).srgb[..., :3],
                               f"{name}, {env_label}") for name, m in materials.items()])
        maps = r.bake(load_environment(str(SHARED / "env" / "royal_esplanade_1k.hdr")), "medium")
        row = []
        for name in COMPARE:
            mesh = load_mesh(str(SHARED / "models" / "khronos" / name / "glTF-Binary" / f"{name}.glb"))
            camera = Camera(position=(0.0, 0.0, 3.2), target=(0.0, 0.0, 0.0), fov_y_deg=35.0)
            image = r.render(Scene(mesh=mesh, camera=camera), maps, 2 * size, size, read_linear=False).srgb[..., :3]
            row.append(label(image, f"{name}, royal_esplanade"))
        rows.append(row)
    width = max(sum(t.shape[1] for t in row) for row in rows)
    sheet = np.concatenate([np.pad(np.concatenate(row, axis=1), ((0, 0), (0, width - sum(t.shape[1] for t in row)), (0, 0)))
                            for row in rows], axis=0)
    write_image(args.out, sheet, linear=False)
    print(args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

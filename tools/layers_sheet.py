"""Renders docs/layers_clearcoat_sheen.png: the clearcoat and sheen presets beside the same
material without the layer, ClearCoatTest beside its reference screenshot, and CompareSheen.

    .venv/bin/python tools/layers_sheet.py

Needs ../shared/data beside the checkout. Everything is rendered by alight's ForwardRenderer at
`medium` (the Khronos models at `low`) under royal_esplanade_1k; the reference screenshot is
Khronos' own (another viewer, camera and environment: compare which highlights appear where,
not the pixels).
"""

from __future__ import annotations

import dataclasses
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data"
BALL = 256


def label(image: Image.Image, text: str) -> Image.Image:
    out = Image.new("RGB", (image.width, image.height + 22), (24, 24, 24))
    out.paste(image, (0, 22))
    ImageDraw.Draw(out).text((6, 5), text, fill=(235, 235, 235))
    return out


def row(images: list[Image.Image]) -> Image.Image:
    out = Image.new("RGB", (sum(i.width for i in images) + 6 * (len(images) - 1), max(i.height for i in images)),
                    (24, 24, 24))
    x = 0
    for i in images:
        out.paste(i, (x, 0))
        x += i.width + 6
    return out


def main() -> None:
    from alight.core.scene import Scene
    from alight.exchange.meshes import load_mesh
    from alight.exchange.presets import load_preset
    from alight.ibl.environment import load_environment
    from alight.render.renderer import ForwardRenderer

    r = ForwardRenderer()
    env = load_environment(str(DATA / "env" / "royal_esplanade_1k.hdr"))
    maps = r.bake(env, "medium")
    sphere = load_mesh("sphere")

    def ball(material, text):
        frame = r.render(Scene(mesh=sphere, material=material), maps, BALL, BALL)
        return label(Image.fromarray(frame.srgb[..., :3]), text)

    car, velvet = load_preset("car_paint"), load_preset("velvet")
    presets = row([ball(car, "car_paint"), ball(dataclasses.replace(car, clearcoat=0.0), "car_paint, no coat"),
                   ball(velvet, "velvet"), ball(dataclasses.replace(velvet, sheen_color=(0.0, 0.0, 0.0)),
                                                "velvet, no sheen")])

    low = r.bake(env, "low")
    cct = load_mesh(str(DATA / "models" / "khronos" / "ClearCoatTest" / "glTF-Binary" / "ClearCoatTest.glb"))
    frame = r.render(Scene(mesh=cct, material=car, use_file_materials=True), low, 1280, 1440)
    full = Image.fromarray(frame.srgb[..., :3])
    w, h = full.size
    ours = full.crop((int(w * 0.44), int(h * 0.24), int(w * 0.80), int(h * 0.76)))
    height = 560
    ours = ours.resize((ours.width * height // ours.height, height))
    ref = Image.open(DATA / "models" / "khronos" / "ClearCoatTest" / "screenshot" / "screenshot_large.jpg").convert("RGB")
    ref = ref.resize((ref.width * height // ref.height, height))
    cct_row = row([label(ref, "ClearCoatTest: Khronos' screenshot"), label(ours, "ClearCoatTest: alight")])

    sheen = load_mesh(str(DATA / "models" / "khronos" / "CompareSheen" / "glTF-Binary" / "CompareSheen.glb"))
    frame = r.render(Scene(mesh=sheen, material=velvet, use_file_materials=True), low, 1440, 720)
    pair = Image.fromarray(frame.srgb[..., :3]).crop((400, 200, 1040, 520))
    sheen_row = label(pair, "CompareSheen: alight (right: the same with sheen colour red, roughness 0.3)")

    rows = [presets, cct_row, sheen_row]
    sheet = Image.new("RGB", (max(x.width for x in rows), sum(x.height for x in rows) + 12 * len(rows)), (24, 24, 24))
    y = 0
    for x in rows:
        sheet.paste(x, (0, y))
        y += x.height + 12
    out = REPO / "docs" / "layers_clearcoat_sheen.png"
    sheet.save(out)
    print(out)
    r.release()


if __name__ == "__main__":
    main()

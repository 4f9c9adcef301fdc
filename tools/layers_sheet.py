"""Renders docs/layers.jpg, the material layers' contact sheet: every preset on the
material ball, ClearCoatTest beside Khronos' reference screenshot, and the Khronos Compare*
models of the material extensions (each pair: without the feature on the left, with it on the
right), all under royal_esplanade_1k.

    .venv/bin/python tools/layers_sheet.py [--out docs/layers.jpg] [--keep DIR]

Needs ../shared/data beside the checkout. Everything is drawn by alight's public Renderer at
`medium` with the files' own materials; what alight printed as a warning (an extension it does
not render) is written in red under the model's name. The reference screenshot is Khronos' own
(another viewer, camera and environment): compare which highlights appear where, as the
model's README asks, not the pixels. The Compare* models have no screenshot here.
"""

from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from khronos_sheet import save_sheet   # tools/ is on sys.path when this runs as a script

REPO = Path(__file__).resolve().parents[1]
DATA = REPO.parent / "shared" / "data"
KHRONOS = DATA / "models" / "khronos"
ENV = DATA / "env" / "royal_esplanade_1k.hdr"
# The Compare* models of material extensions (the others, base colour to normal, are core glTF:
# docs/khronos.jpg shows them).
COMPARE = ["CompareAnisotropy", "CompareSheen", "CompareTransmission", "CompareVolume", "CompareIor",
           "CompareSpecular", "CompareIridescence", "CompareDispersion"]
BG = (24, 24, 24)


def label(image: Image.Image, text: str, notes: list[str] = ()) -> Image.Image:
    """``image`` under a caption; ``notes`` (alight's warnings) in red below it."""
    lines = [line for n in notes for line in textwrap.wrap(n, max(20, image.width // 6))][:2]
    top = 20 + 12 * len(lines)
    out = Image.new("RGB", (image.width, image.height + top), BG)
    out.paste(image, (0, top))
    draw = ImageDraw.Draw(out)
    draw.text((6, 4), text, fill=(235, 235, 235))
    for k, line in enumerate(lines):
        draw.text((6, 18 + 12 * k), line, fill=(255, 110, 110))
    return out


def stack(images: list[Image.Image], across: bool, gap: int = 6) -> Image.Image:
    if across:
        size = (sum(i.width for i in images) + gap * (len(images) - 1), max(i.height for i in images))
    else:
        size = (max(i.width for i in images), sum(i.height for i in images) + gap * (len(images) - 1))
    out = Image.new("RGB", size, BG)
    at = 0
    for i in images:
        out.paste(i, (at, 0) if across else (0, at))
        at += (i.width if across else i.height) + gap
    return out


def heading(text: str, width: int) -> Image.Image:
    out = Image.new("RGB", (width, 24), (48, 48, 48))
    ImageDraw.Draw(out).text((6, 6), text, fill=(255, 255, 255))
    return out


def model_file(name: str) -> Path:
    return next((KHRONOS / name / "glTF-Binary").glob("*.glb"))


def front_camera(mesh, aspect: float, fov_deg: float = 30.0, margin: float = 1.08):
    """A Camera on +Z (the test models face +Z) whose view the mesh's bounding box fills at
    ``aspect`` (width / height); alight's own framing fits the bounding sphere, which leaves the
    flat test boards small."""
    import math

    from alight.core.scene import Camera

    lo, hi = mesh.bounds()
    centre, half = (lo + hi) / 2.0, (hi - lo) / 2.0
    t = math.tan(math.radians(fov_deg) / 2.0)
    distance = margin * max(half[1] / t, half[0] / (t * aspect)) + half[2]
    return Camera(position=(float(centre[0]), float(centre[1]), float(centre[2] + distance)),
                  target=tuple(float(c) for c in centre), fov_y_deg=fov_deg)


def warnings_of(mesh) -> list[str]:
    return [w.split(": ", 1)[1].replace("extensionsUsed: ", "").replace(
        " is not supported; rendered without it", " not rendered") for w in mesh.warnings]


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(REPO / "docs" / "layers.jpg"))
    ap.add_argument("--ball", type=int, default=200, help="size of a preset's tile (default 200)")
    ap.add_argument("--keep", metavar="DIR", help="also write each render as DIR/NAME.png")
    args = ap.parse_args(argv)

    import alight
    from alight.exchange.presets import list_presets

    keep = Path(args.keep) if args.keep else None
    if keep:
        keep.mkdir(parents=True, exist_ok=True)

    def shot(r, name: str, width: int, height: int) -> Image.Image:
        image = Image.fromarray(np.ascontiguousarray(r.render(width, height)[:, :, :3]))
        if keep:
            image.save(keep / f"{name}.png")
        return image

    with alight.Renderer(args.ball, quality="medium") as r:
        r.set_environment(str(ENV))
        balls = []
        for name in list_presets():
            r.set_material(name)
            balls.append(label(shot(r, name, args.ball, args.ball), name))
            print(name, file=sys.stderr)
        half = (len(balls) + 1) // 2
        presets = stack([stack(balls[:half], True), stack(balls[half:], True)], False)

        r.set_mesh(str(model_file("ClearCoatTest")))
        r.set_material(use_file_materials=True)
        r.set_camera(front_camera(r.mesh, 720 / 810))
        ours = shot(r, "ClearCoatTest", 720, 810)
        ref = Image.open(KHRONOS / "ClearCoatTest" / "screenshot" / "screenshot_large.jpg").convert("RGB")
        ref = ref.resize((ref.width * ours.height // ref.height, ours.height), Image.LANCZOS)
        cct = stack([label(ref, "ClearCoatTest: Khronos' screenshot (columns: base, coated, coat only)"),
                     label(ours, "ClearCoatTest: alight", warnings_of(r.mesh))], True)
        print("ClearCoatTest", "; ".join(r.mesh.warnings) or "ok", file=sys.stderr)

        pairs = []
        for name in COMPARE:
            r.set_mesh(str(model_file(name)))
            r.set_material(use_file_materials=True)
            r.set_camera(front_camera(r.mesh, 480 / 270))
            pairs.append(label(shot(r, name, 480, 270), f"{name}: without | with", warnings_of(r.mesh)))
            print(name, "; ".join(r.mesh.warnings) or "ok", file=sys.stderr)
        compare = stack([stack(pairs[i:i + 4], True) for i in range(0, len(pairs), 4)], False)

    width = max(presets.width, cct.width, compare.width)
    sheet = stack([heading("Presets, royal_esplanade_1k, medium bake (alight render)", width), presets,
                   heading("KHR_materials_clearcoat: ClearCoatTest", width), cct,
                   heading("Khronos Compare* models of the material extensions (no reference screenshots)", width),
                   compare], False, gap=8)
    save_sheet(sheet, args.out)
    print(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())

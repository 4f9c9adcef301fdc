"""docs/khronos.jpg: alight's render of every Khronos sample test model in
../shared/data/models/khronos/ beside the model's reference screenshot, one row per model.

    .venv/bin/python tools/khronos_sheet.py [--out docs/khronos.jpg] [--size 256] [--only NAME ...]

Each model is rendered with the glTF file's own materials under royal_esplanade (a map with a
clear horizon, as NormalTangentTest asks), framed from +Z (the test models face +Z), or from
the view in VIEWS where the screenshot was taken from elsewhere. Models whose feature is a
material extension alight does not render yet are marked so under their name (the warning
alight printed). Renders are also written as PNGs beside the sheet (--keep).
"""

from __future__ import annotations

import argparse
import sys
import textwrap
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

REPO = Path(__file__).resolve().parents[1]
KHRONOS = REPO.parent / "shared" / "data" / "models" / "khronos"
ENV = REPO.parent / "shared" / "data" / "env" / "royal_esplanade_1k.hdr"
# Camera per model where the reference screenshot looks from elsewhere than +Z: Renderer.set_camera keywords.
VIEWS = {
    "OrientationTest": dict(orbit_deg=30.0, elevation_deg=25.0),
    "EmissiveStrengthTest": dict(orbit_deg=-25.0, elevation_deg=20.0),
}


def model_file(folder: Path) -> Path | None:
    for sub in ("glTF-Binary", "glTF"):
        files = sorted((folder / sub).glob("*.gl*")) if (folder / sub).is_dir() else []
        if files:
            return files[0]
    return None


def screenshot(folder: Path) -> Path | None:
    shots = folder / "screenshot"
    for name in ("screenshot.png", "screenshot.jpg"):
        if (shots / name).is_file():
            return shots / name
    return None


def front_view(mesh, fov_deg: float = 35.0) -> dict:
    """set_camera keywords that fill the frame with the mesh's bounding box seen from +Z (the
    bounding sphere leaves flat test boards small)."""
    import math

    lo, hi = mesh.bounds()
    centre, half = (lo + hi) / 2.0, (hi - lo) / 2.0
    distance = 1.08 * max(half[0], half[1]) / math.tan(math.radians(fov_deg) / 2.0) + half[2]
    return dict(orbit_deg=0.0, elevation_deg=0.0, distance=float(distance), fov_deg=fov_deg, target=tuple(centre))


def save_sheet(sheet: Image.Image, out) -> None:
    """A contact sheet as JPEG at quality 92 without chroma subsampling: the renders' gradients
    stay smooth (a 256-colour PNG banded them) and the sheet stays under the repository's 1 MiB a
    file (a PNG was 1.3-1.7 MB)."""
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    sheet.convert("RGB").save(out, quality=92, optimize=True, subsampling=0)


def fit(image: Image.Image, size: int) -> Image.Image:
    image = image.convert("RGB")
    image.thumbnail((size, size))
    tile = Image.new("RGB", (size, size), (40, 40, 40))
    tile.paste(image, ((size - image.width) // 2, (size - image.height) // 2))
    return tile


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", default=str(REPO / "docs" / "khronos.jpg"))
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--only", nargs="*", help="model folders to render (default: all)")
    ap.add_argument("--keep", metavar="DIR", help="also write each render as DIR/NAME.png")
    args = ap.parse_args(argv)

    import alight

    folders = sorted(p for p in KHRONOS.iterdir() if p.is_dir())
    if args.only:
        folders = [f for f in folders if f.name in args.only]
    size = args.size
    label_h = 44
    rows = []
    with alight.Renderer(size, quality="medium") as r:
        r.set_environment(str(ENV) if ENV.is_file() else "studio", rotation_deg=90)
        r.set_display(background="color")   # the screenshots' plain backdrop
        for folder in folders:
            path = model_file(folder)
            if path is None:
                continue
            r.set_mesh(str(path))
            r.set_material(use_file_materials=True)
            r.set_lights(list(r.mesh.lights))
            r.set_camera(**VIEWS.get(folder.name, front_view(r.mesh)))
            pixels = r.render()
            render = Image.fromarray(np.ascontiguousarray(pixels[:, :, :3]))
            if args.keep:
                Path(args.keep).mkdir(parents=True, exist_ok=True)
                render.save(Path(args.keep) / f"{folder.name}.png")
            shot = screenshot(folder)
            notes = [w.split(": ", 1)[1] for w in r.mesh.warnings]
            rows.append((folder.name, render, fit(Image.open(shot), size) if shot else None, notes))
            print(folder.name, "; ".join(notes) or "ok", file=sys.stderr)

    pair_w = 2 * size + 8
    sheet_cols = 3
    n_rows = (len(rows) + sheet_cols - 1) // sheet_cols
    sheet = Image.new("RGB", (sheet_cols * (pair_w + 16), n_rows * (size + label_h + 8)), "white")
    draw = ImageDraw.Draw(sheet)
    for i, (name, render, shot, notes) in enumerate(rows):
        x = (i % sheet_cols) * (pair_w + 16) + 8
        y = (i // sheet_cols) * (size + label_h + 8) + 4
        draw.text((x, y), f"{name}: alight | reference", fill="black")
        note = "; ".join(n.replace("extensionsUsed: ", "").replace(" is not supported; rendered without it", " not rendered")
                         for n in notes)
        for k, line in enumerate(textwrap.wrap(note, 2 * size // 6)[:2]):
            draw.text((x, y + 12 + 11 * k), line, fill=(170, 0, 0))
        sheet.paste(render, (x, y + label_h))
        if shot is not None:
            sheet.paste(shot, (x + size + 8, y + label_h))
        else:
            draw.rectangle([x + size + 8, y + label_h, x + 2 * size + 8, y + label_h + size], outline="grey")
            draw.text((x + size + 16, y + label_h + size // 2), "no reference screenshot", fill="grey")
    save_sheet(sheet, args.out)
    print(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())

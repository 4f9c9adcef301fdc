"""Renders docs/iridescence.png (KHR_materials_iridescence's sheet) and prints its errors.

Row 1: the Khronos CompareIridescence pair (the same material without the film on the left,
with it on the right, its iridescenceTexture masking the glTF logo) in the built-in studio and
under royal_esplanade_1k. Row 2: the oil_film preset on the probe at `medium` beside
`alight reference` (docs/conventions.md's ground truth at the environment level it chooses), and
a thickness sweep of the same film. Prints the probe's relMAE against the reference.

    .venv/bin/python tools/iridescence_sheet.py [--size 256]
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared" / "data"
THICKNESS_NM = (150.0, 250.0, 500.0, 700.0)


def label(tile: np.ndarray, text: str) -> np.ndarray:
    from PIL import Image, ImageDraw

    im = Image.fromarray(np.ascontiguousarray(tile))
    draw = ImageDraw.Draw(im)
    draw.rectangle((0, 0, im.width, 16), fill=(0, 0, 0))
    draw.text((4, 2), text, fill=(255, 255, 255))
    return np.asarray(im)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--size", type=int, default=256)
    ap.add_argument("--env-level", type=int, default=None,
                    help="the reference's environment level (default: the one alight reference chooses)")
    ap.add_argument("--out", default=str(REPO / "docs" / "iridescence.png"))
    args = ap.parse_args(argv)

    from alight.accuracy.ground_truth import probe_points, relative_error
    from alight.accuracy.reference import ReferenceRenderer
    from alight.core.scene import Camera, Scene
    from alight.core.shading import linear_to_srgb
    from alight.exchange.meshes import load_mesh
    from alight.exchange.output import write_image
    from alight.exchange.presets import load_preset
    from alight.ibl.environment import load_environment, studio_environment
    from alight.render.renderer import ForwardRenderer

    size = args.size
    royal = load_environment(str(SHARED / "env" / "royal_esplanade_1k.hdr"))
    mesh = load_mesh(str(SHARED / "models" / "khronos" / "CompareIridescence" / "glTF-Binary" / "CompareIridescence.glb"))
    oil = load_preset("oil_film")
    rows = []
    with ForwardRenderer() as r:
        camera = Camera(position=(0.0, 0.0, 3.2), target=(0.0, 0.0, 0.0), fov_y_deg=35.0)
        row = []
        for env_label, env in (("studio", studio_environment()), ("royal_esplanade", royal)):
            image = r.render(Scene(mesh=mesh, camera=camera), r.bake(env, "medium"), 2 * size, size,
                             read_linear=False).srgb[..., :3]
            row.append(label(image, f"CompareIridescence, {env_label}"))
        rows.append(row)
        maps = r.bake(royal, "medium")
        _, inside = probe_points(size)
        row = []
        for m in (oil,):
            forward = r.render(Scene(material=m, view="probe"), maps, size, size).linear
            truth = ReferenceRenderer(r).render(Scene(material=m, view="probe"), royal.radiance, size, size,
                                                     env_level=args.env_level).linear
            err = relative_error(forward[..., :3], truth[..., :3], inside)
            print(f"{m.name}: probe at medium vs alight reference (royal_esplanade): relMAE {100 * err:.2f}%", flush=True)
            if m is oil:
                for name, img in (("oil_film, medium", forward), (f"reference ({100 * err:.1f}% relMAE)", truth)):
                    srgb = (np.clip(linear_to_srgb(np.clip(img[..., :3], 0.0, 1.0)), 0.0, 1.0) * 255 + 0.5).astype(np.uint8)
                    row.append(label(srgb, name))
        for d in THICKNESS_NM:
            m = dataclasses.replace(oil, iridescence_thickness_maximum=d)
            row.append(label(r.render(Scene(material=m, view="probe"), maps, size, size, read_linear=False).srgb[..., :3],
                             f"oil_film, {d:g} nm"))
        rows.append(row)
    width = max(sum(t.shape[1] for t in row) for row in rows)
    sheet = np.concatenate([np.pad(np.concatenate(row, axis=1), ((0, 0), (0, width - sum(t.shape[1] for t in row)), (0, 0)))
                            for row in rows], axis=0)
    write_image(args.out, sheet, linear=False)
    print(args.out)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

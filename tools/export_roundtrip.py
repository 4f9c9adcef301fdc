"""Each mesh file exported with its own materials (`alight export --mesh FILE`), rendered beside
the original (`alight render --mesh`, 128x96, occlusion and shadows off) and compared: one line a
file with the max and mean difference (of 255), the share of pixels off by more than 8, the
distinct materials alight loads from each, the sizes of the original and the export, and the export's stderr (what it left out).

    .venv/bin/python tools/export_roundtrip.py --out /tmp/roundtrip [FILE ...]

Without FILEs: every .glb under ../shared/data/models/khronos, DamagedHelmet and the Duck. Every
file is written under --out (never beside the models). docs/guides/gltf-export.md quotes a run.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image

REPO = Path(__file__).resolve().parents[1]
MODELS = REPO.parent / "shared" / "data" / "models"


def _alight(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "alight", *args], capture_output=True, text=True)


def _size(path: Path) -> int:
    """The bytes of a model (a .gltf with everything in its folder)."""
    return sum(p.stat().st_size for p in path.parent.iterdir()) if path.suffix == ".gltf" else path.stat().st_size


def _materials(path: Path) -> int:
    """How many distinct materials the file's parts are drawn with, as alight loads it."""
    from alight.exchange.meshes import load_mesh

    return len({id(p.material) for p in load_mesh(str(path)).parts if p.material is not None})


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--out", required=True, type=Path)
    ap.add_argument("files", nargs="*", type=Path)
    args = ap.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    files = args.files or [*sorted((MODELS / "khronos").glob("*/glTF-Binary/*.glb")),
                           MODELS / "DamagedHelmet" / "DamagedHelmet.gltf", MODELS / "Duck.glb"]
    for model in files:
        out = args.out / f"{model.stem}_out.glb"
        r = _alight("export", "--mesh", str(model), "--out", str(out))
        if r.returncode:
            print(f"{model.stem}: export failed: {r.stderr.strip()}", flush=True)
            continue
        pictures = []
        for source, tag in ((model, "original"), (out, "exported")):
            png = args.out / f"{model.stem}_{tag}.png"
            q = _alight("render", "--mesh", str(source), "--size", "128x96", "--occlusion", "off", "--shadows", "off",
                        "--out", str(png))
            if q.returncode:
                print(f"{model.stem}: render of the {tag} failed: {q.stderr.strip()}", flush=True)
                break
            pictures.append(np.asarray(Image.open(png).convert("RGB"), np.float64))
        if len(pictures) == 2:
            d = np.abs(pictures[0] - pictures[1])
            print(f"{model.stem}: max {d.max():.0f} mean {d.mean():.3f} off>8 {(d.max(-1) > 8).mean():.4f} "
                  f"| materials {_materials(model)} -> {_materials(out)} "
                  f"| {_size(model)} -> {out.stat().st_size} bytes | {r.stderr.strip()}", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())

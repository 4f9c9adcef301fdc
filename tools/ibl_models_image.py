"""docs/ibl_models.png: the lecture's split sum, the ground truth and alight's default model side
by side on the probe view, with each model's relative error against the truth in its title.

    .venv/bin/python tools/ibl_models_image.py     # needs matplotlib (pip install matplotlib)

The truth is `alight reference` on the GPU (docs/conventions.md's texel sum over the map reduced by 2,
--env-level 1); the models are `alight render --ibl ...` at the medium bake. Every figure in the
titles is measured by this script when it runs.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]

import numpy as np

ENV_DIR = REPO.parent / "shared" / "data" / "env"
CASES = [("quarry_01_1k.hdr", "gold", 0.5), ("venice_sunset_1k.hdr", "water", 0.5),
         ("royal_esplanade_1k.hdr", "copper", 0.7)]
SIZE = 128


def run(*args):
    subprocess.run([sys.executable, "-m", "alight", *args], check=True, cwd=REPO)


def read_exr(path):
    import OpenImageIO as oiio

    return oiio.ImageBuf(str(path)).get_pixels(oiio.FLOAT)[..., :3]


def main():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from alight.core.shading import linear_to_srgb, tonemap_aces_fitted

    fig, axes = plt.subplots(len(CASES), 3, figsize=(7.5, 2.6 * len(CASES)))
    with tempfile.TemporaryDirectory() as tmp:
        for row, (env, preset, rough) in enumerate(CASES):
            common = ["--view", "probe", "--env", str(ENV_DIR / env), "--preset", preset,
                      "--roughness", str(rough), "--size", str(SIZE)]
            truth_path = Path(tmp) / "truth.exr"
            run("reference", *common, "--env-level", "1", "--out", str(truth_path))
            truth = read_exr(truth_path)
            images = {}
            for model in ("lecture", "alight"):
                path = Path(tmp) / f"{model}.exr"
                run("render", *common, "--ibl", model, "--out", str(path))
                images[model] = read_exr(path)
            inside = truth.sum(axis=2) > 0
            for col, (name, img) in enumerate((("lecture", images["lecture"]), ("ground truth", truth),
                                               ("alight (default)", images["alight"]))):
                ax = axes[row, col]
                ax.imshow(np.clip(linear_to_srgb(tonemap_aces_fitted(img)), 0.0, 1.0))
                ax.set_xticks([])
                ax.set_yticks([])
                title = name
                if img is not truth:
                    err = np.abs(img - truth)[inside].sum() / np.abs(truth)[inside].sum()
                    title += f": {100 * err:.1f}% off"
                ax.set_title(title, fontsize=9)
            axes[row, 0].set_ylabel(f"{env.split('_1k')[0]}\n{preset}, r = {rough:g}", fontsize=9)
    fig.tight_layout()
    out = REPO / "docs" / "ibl_models.png"
    fig.savefig(out, dpi=100)
    print(out)


if __name__ == "__main__":
    main()

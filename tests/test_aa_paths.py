"""Each anti-aliasing mode draws the same picture, whatever path the frame takes. ``--aa none``
to a PNG draws the scene tone mapped in one pass (passes.frame_strips, Renderer.draw_display: the
editor's default view), ``msaa`` resolves radiance then tone maps: a feature that one path
forgets shows here (blended parts came out opaque with ``--aa none``, in the editor's view and
its screenshots, while MSAA drew them see-through). Edges differ between the modes, so the
images are compared in 8x8 blocks (binned relative MAE) and their alpha pixel by pixel."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from alight.accuracy.binned import binned_relative_mae

REPO = Path(__file__).resolve().parents[1]
SHARED = REPO.parent / "shared" / "data"
BLEND = str(SHARED / "cases" / "gltf_alpha_blend.glb")
CASES = {
    "alpha blend": ["--mesh", BLEND],
    "alpha blend on the ground": ["--mesh", BLEND, "--ground"],
    "alpha blend, transparent background": ["--mesh", BLEND, "--background", "transparent"],
    "alpha mask": ["--mesh", str(SHARED / "cases" / "gltf_alpha_mask.glb")],
    "AlphaBlendModeTest": ["--mesh", str(SHARED / "models" / "khronos" / "AlphaBlendModeTest" / "glTF-Binary"
                                         / "AlphaBlendModeTest.glb")],
    "transmission": ["--preset", "flint_glass"],
    "probe": ["--view", "probe", "--preset", "gold"],
}


def _render(out: Path, aa: str, args: list[str]) -> np.ndarray:
    proc = subprocess.run([sys.executable, "-m", "alight", "render", "--size", "96", "--aa", aa, *args, "--out", str(out)],
                          capture_output=True, text=True, cwd=REPO, env=dict(os.environ), timeout=300)
    assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
    rgba = np.asarray(Image.open(out).convert("RGBA")).astype(np.float64) / 255.0
    rgb = rgba[:, :, :3]
    rgba[:, :, :3] = np.where(rgb <= 0.04045, rgb / 12.92, ((rgb + 0.055) / 1.055) ** 2.4)
    return rgba


@pytest.mark.parametrize("name", list(CASES))
def test_no_anti_aliasing_draws_what_msaa_draws(tmp_path, name):
    none = _render(tmp_path / "none.png", "none", CASES[name])
    msaa = _render(tmp_path / "msaa.png", "msaa", CASES[name])
    error = binned_relative_mae(none[:, :, :3], msaa[:, :, :3], 8)
    assert error < 0.03, f"{name}: --aa none is {error:.3f} off --aa msaa in 8x8 blocks"
    assert np.abs(none[:, :, 3] - msaa[:, :, 3]).mean() < 0.02, name

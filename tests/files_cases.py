"""Helpers for the tests of what users' files hold: render through the real command to linear
EXR and compare a feature file's picture with its control's (../shared/data/cases/README.md:
within 1% relMAE over covered pixels)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np

REPO = Path(__file__).resolve().parents[1]
CASES = REPO.parent / "shared" / "data" / "cases"
CONTROLS = CASES / "with_controls"


def run(*args, timeout: float = 300) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "alight", *map(str, args)], cwd=REPO, env=dict(os.environ),
                          capture_output=True, text=True, timeout=timeout)


def render_exr(out: Path, *args, size: int = 96) -> tuple[np.ndarray, list[str]]:
    """``alight render ARGS --size SIZE --quality low --tonemap none --out OUT.exr``: the linear
    RGBA pixels and the warning lines; asserts success."""
    proc = run("render", "--size", size, "--quality", "low", "--tonemap", "none", *args, "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert "Traceback" not in proc.stderr
    return read_exr(out), [ln for ln in proc.stderr.splitlines() if ln.startswith("alight: warning:")]


def read_exr(path: Path) -> np.ndarray:
    import OpenImageIO as oiio

    buf = oiio.ImageBuf(str(path))
    assert not buf.has_error, buf.geterror()
    return np.asarray(buf.get_pixels(oiio.FLOAT))


def rel_mae(test: np.ndarray, ref: np.ndarray) -> float:
    """sum |test - ref| / sum |ref| over RGB of the pixels covered in either (alpha > 0): a
    surface missing from one image counts in full."""
    mask = (test[..., 3] > 0) | (ref[..., 3] > 0)
    assert mask.any(), "nothing covered"
    t, r = test[..., :3][mask], ref[..., :3][mask]
    return float(np.abs(t - r).sum() / np.abs(r).sum())

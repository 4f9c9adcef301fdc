"""The built-in preview meshes (sphere, cube, plane, shader ball, rounded cube, drape): each has
uvs and tangents a texture set can use, is closed or open as meant, and `alight render --mesh
NAME` shows it filling a good part of the frame from its 3/4 view (never a flat mesh edge-on)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from alight.core.mesh import BUILTIN_MESHES, is_closed
from alight.exchange.meshes import load_mesh
from test_gltf_material import validate  # noqa: F401  (the Khronos validator fixture)

REPO = Path(__file__).resolve().parents[1]
CLOSED = {"sphere": True, "cube": True, "plane": False, "shader_ball": True, "rounded_cube": True, "drape": False}


def test_the_list_has_the_three_new_meshes():
    assert set(BUILTIN_MESHES) == set(CLOSED)


@pytest.mark.parametrize("name", BUILTIN_MESHES)
def test_uvs_tangents_and_closedness(name):
    mesh = load_mesh(name)
    assert mesh.source == name and len(mesh.parts) == 1
    part = mesh.parts[0]
    p, n, uv, t = (a.astype(np.float64) for a in (part.positions, part.normals, part.uvs, part.tangents))
    assert uv.shape == (len(p), 2) and t.shape == (len(p), 4)
    assert uv.min() >= 0.0 and uv.max() <= 1.0 and np.ptp(uv, axis=0).min() > 0.99   # the whole square used
    np.testing.assert_allclose(np.linalg.norm(n, axis=1), 1.0, atol=1e-5)
    np.testing.assert_allclose(np.linalg.norm(t[:, :3], axis=1), 1.0, atol=1e-5)
    assert np.abs((t[:, :3] * n).sum(axis=1)).max() < 1e-4                 # tangent in the surface
    assert np.all(np.abs(t[:, 3]) == 1.0)
    # The tangent follows +u: along each triangle, dP and du agree in sign where u changes.
    f = part.indices.astype(np.int64)
    dp, du = p[f[:, 1]] - p[f[:, 0]], uv[f[:, 1], 0] - uv[f[:, 0], 0]
    moving = np.abs(du) > 1e-6
    along = ((dp * t[f[:, 0], :3]).sum(axis=1) * du)[moving]
    assert np.mean(along > 0) > 0.95
    # Faces wound counter-clockwise from outside: the face normal agrees with the vertex normals.
    fn = np.cross(p[f[:, 1]] - p[f[:, 0]], p[f[:, 2]] - p[f[:, 0]])
    keep = np.linalg.norm(fn, axis=1) > 1e-12
    assert np.all((fn[keep] * n[f[keep]].sum(axis=1)).sum(axis=1) > 0)
    assert is_closed(part.positions, part.indices) == CLOSED[name]


def test_the_shader_ball_has_a_groove():
    """Concave light needs a concave place: round the equator the surface goes in (0.70) from the
    ball (0.85), and there are normals facing up and down there (the groove's floor and ceiling)."""
    part = load_mesh("shader_ball").parts[0]
    p, n = part.positions.astype(np.float64), part.normals.astype(np.float64)
    r = np.hypot(p[:, 0], p[:, 2])
    band = np.abs(p[:, 1]) < 0.075
    assert r[band].max() < 0.72 and r[(np.abs(p[:, 1]) > 0.1) & (np.abs(p[:, 1]) < 0.3)].min() > 0.78
    rim = np.abs(np.abs(p[:, 1]) - 0.08) < 1e-6
    assert (n[rim, 1] > 0.99).any() and (n[rim, 1] < -0.99).any()


@pytest.mark.parametrize("name", BUILTIN_MESHES)
def test_render_fills_the_frame_from_three_quarters(name, tmp_path):
    out = tmp_path / f"{name}.png"
    proc = subprocess.run([sys.executable, "-m", "alight", "render", "--mesh", name, "--size", "96",
                           "--quality", "low", "--background", "transparent", "--out", str(out)],
                          cwd=REPO, env=dict(os.environ), capture_output=True, text=True, timeout=180)
    assert proc.returncode == 0, proc.stderr
    assert "edge-on" not in proc.stderr
    alpha = np.asarray(Image.open(out).convert("RGBA"))[..., 3] > 128
    assert alpha.mean() > 0.15, f"{name}: covers {alpha.mean():.3f} of the frame"
    rows, cols = np.nonzero(alpha)
    # Seen at an angle, not dead-on: a cube's or plane's outline is no axis-aligned rectangle.
    if name in ("cube", "plane", "rounded_cube", "drape"):
        box = (np.ptp(rows) + 1) * (np.ptp(cols) + 1)
        assert alpha.sum() < 0.92 * box, f"{name}: its outline fills its bounding box (seen square on)"
    # And taller than a sliver: a flat mesh seen edge-on would be a line.
    assert np.ptp(rows) > 0.3 * alpha.shape[0]


def test_explicit_orbit_and_elevation_still_give_the_front_view(tmp_path):
    """`--orbit 0 --elevation 0` is the view from +Z as before: the cube square on, its outline
    filling its bounding box, where the default (its 3/4 view) does not."""
    out = tmp_path / "front.png"
    proc = subprocess.run([sys.executable, "-m", "alight", "render", "--mesh", "cube", "--orbit", "0", "--elevation",
                           "0", "--size", "96", "--quality", "low", "--background", "transparent", "--out", str(out)],
                          cwd=REPO, env=dict(os.environ), capture_output=True, text=True, timeout=180)
    assert proc.returncode == 0, proc.stderr
    alpha = np.asarray(Image.open(out).convert("RGBA"))[..., 3] > 128
    rows, cols = np.nonzero(alpha)
    assert alpha.sum() > 0.97 * (np.ptp(rows) + 1) * (np.ptp(cols) + 1)


@pytest.mark.parametrize("name", ["shader_ball", "rounded_cube", "drape"])
def test_the_new_meshes_export_validator_clean(name, tmp_path, validate):
    """`alight export --mesh NAME` writes a .glb with their uvs and tangents that the Khronos
    validator passes with no error and no warning."""
    out = tmp_path / f"{name}.glb"
    proc = subprocess.run([sys.executable, "-m", "alight", "export", "--preset", "gold", "--mesh", name,
                           "--out", str(out)], cwd=REPO, env=dict(os.environ), capture_output=True, text=True,
                          timeout=180)
    assert proc.returncode == 0, proc.stderr
    (report,) = validate(out)
    assert (report["errors"], report["warnings"]) == (0, 0), report

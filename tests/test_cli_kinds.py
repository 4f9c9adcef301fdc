"""The command line's mistakes fixed as kinds, each through the real command (subprocess):
negative vectors as values, a closed pipe, light specs missing what places them, options that do
nothing for the chosen output, --quality auto's wording, and --camera gltf's aspect ratio."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.gltf_builder import FLOAT, UINT, Gltf, grid_plane

REPO = Path(__file__).resolve().parents[1]


def run(*args, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "alight", *map(str, args)], cwd=REPO, env=dict(os.environ),
                          capture_output=True, text=True, timeout=timeout)


def assert_refused(proc, names, folder: Path) -> None:
    assert proc.returncode == 2, proc.stderr
    assert "Traceback" not in proc.stdout + proc.stderr
    lines = proc.stderr.splitlines()
    assert len(lines) == 1 and lines[0].startswith("alight: error: "), lines
    for name in names:
        assert name in lines[0], (name, lines[0])
    assert sorted(p.name for p in folder.iterdir()) == []


@pytest.fixture
def out_dir(tmp_path):
    d = tmp_path / "out"
    d.mkdir()
    return d


# --- negative numbers wherever an option takes a vector or number ---------------------------

@pytest.mark.parametrize("args", [
    ["--target", "-0.18,0,0"],
    ["--target", "-1e-1,-0,-.5"],
    ["--orbit", "-30", "--elevation", "-1.5e1"],
    ["--env-rotation", "-90"],
], ids=["target", "target-exp", "orbit-elevation", "env-rotation"])
def test_negative_values_are_values(out_dir, args):
    out = out_dir / "n.png"
    proc = run("render", "--size", "16", "--quality", "low", "--aa", "none", *args, "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert out.is_file()


def test_a_negative_colour_is_refused_for_its_value_not_as_a_missing_argument(out_dir):
    proc = run("render", "--size", "16", "--base-color", "-1,0,0", "--out", out_dir / "x.png")
    assert_refused(proc, ["--base-color"], out_dir)
    assert "expected one argument" not in proc.stderr


# --- a closed pipe ends quietly ------------------------------------------------------------

@pytest.mark.parametrize("args", [["presets"], ["--help"], ["render", "--help"], ["cache", "show"]],
                         ids=["presets", "help", "render-help", "cache"])
def test_closed_pipe_is_quiet(tmp_path, args):
    """`alight ARGS | head -0`: the reader is gone before anything is written."""
    env = dict(os.environ, ALIGHT_CACHE_DIR=str(tmp_path / "cache"))
    r, w = os.pipe()
    os.close(r)                    # nobody will read
    proc = subprocess.run([sys.executable, "-m", "alight", *args], cwd=REPO, env=env, stdout=w,
                          stderr=subprocess.PIPE, text=True, timeout=60)
    os.close(w)
    assert "Traceback" not in proc.stderr and "BrokenPipe" not in proc.stderr, proc.stderr
    assert proc.stderr == ""
    assert proc.returncode in (0, 141)   # argparse itself swallows the error of printing --help


def test_render_into_a_closed_pipe_still_writes_its_image(tmp_path):
    out = tmp_path / "p.png"
    r, w = os.pipe()
    os.close(r)
    proc = subprocess.run([sys.executable, "-m", "alight", "render", "--size", "16", "--quality", "low",
                           "--aa", "none", "--out", str(out)], cwd=REPO, stdout=w, stderr=subprocess.PIPE,
                          text=True, timeout=120)
    os.close(w)
    assert "Traceback" not in proc.stderr and proc.stderr == "", proc.stderr
    assert out.is_file()


def test_presets_through_head():
    proc = subprocess.run(f"'{sys.executable}' -m alight presets | head -n 2", shell=True, cwd=REPO,
                          capture_output=True, text=True, timeout=60)
    assert len(proc.stdout.splitlines()) == 2 and proc.stderr == "", proc.stderr


# --- light specs missing what places them ---------------------------------------------------

@pytest.mark.parametrize("spec, missing", [
    ("spot:pos=0,2,0", "dir="), ("point:intensity=30", "pos="), ("spot:dir=0,-1,0", "pos="),
    ("directional:intensity=3", "dir="),
])
def test_light_missing_a_required_field_is_refused(out_dir, spec, missing):
    proc = run("render", "--size", "16", "--no-ibl", "--light", spec, "--out", out_dir / "x.png")
    assert_refused(proc, ["--light", spec, missing], out_dir)


def test_complete_lights_still_render(out_dir):
    out = out_dir / "l.png"
    proc = run("render", "--size", "16", "--no-ibl", "--aa", "none", "--light", "spot:pos=0,2,2:dir=0,-1,-1",
               "--light", "point:pos=-1,1,2:intensity=30", "--light", "directional:dir=-1,-1,-1", "--out", out)
    assert proc.returncode == 0, proc.stderr


# --- options that do nothing for the chosen output -------------------------------------------

@pytest.mark.parametrize("args, names", [
    (["--tonemap", "aces"], ["--tonemap", "x.exr"]),
    (["--tonemap", "neutral"], ["--tonemap", "x.exr"]),
    (["--exposure", "1"], ["--exposure", "x.exr"]),
    (["--exposure", "-1"], ["--exposure", "x.exr"]),
])
def test_png_only_options_are_refused_with_exr(out_dir, args, names):
    assert_refused(run("render", "--size", "16", *args, "--out", out_dir / "x.exr"), names, out_dir)


def test_background_colour_without_colour_background_is_refused(out_dir):
    proc = run("render", "--size", "16", "--background-color", "1,0,0", "--out", out_dir / "x.png")
    assert_refused(proc, ["--background-color", "--background color"], out_dir)


def test_tonemap_none_with_exr_is_fine(out_dir):
    out = out_dir / "x.exr"
    proc = run("render", "--size", "16", "--quality", "low", "--aa", "none", "--tonemap", "none", "--out", out)
    assert proc.returncode == 0 and out.is_file(), proc.stderr


def test_environment_options_with_no_ibl_are_warned(out_dir):
    out = out_dir / "x.png"
    proc = run("render", "--size", "16", "--aa", "none", "--no-ibl", "--env-rotation", "90",
               "--light", "directional:dir=0,0,-1", "--out", out)
    assert proc.returncode == 0, proc.stderr
    warnings = [ln for ln in proc.stderr.splitlines() if ln.startswith("alight: warning:")]
    assert len(warnings) == 1 and "--env-rotation" in warnings[0] and "--no-ibl" in warnings[0]


# --- --quality auto does not claim to have measured a file nobody gave -------------------------

def test_quality_auto_says_where_its_figures_come_from(out_dir):
    out = out_dir / "q.png"
    proc = run("render", "--size", "16", "--aa", "none", "--quality", "auto", "--out", out)
    assert proc.returncode == 0, proc.stderr
    line = next(ln for ln in proc.stderr.splitlines() if "quality auto" in ln)
    assert "measured on piz" not in line          # the old wording, read as "measured on your file"
    assert "predicted from the table's runs" in line and "not measured on this one" in line


# --- --camera gltf and the camera's aspect ratio ----------------------------------------------

def _camera_file(path: Path, aspect: float | None, name: str | None = "Shot") -> Path:
    """A 4x2 plane filling a 2:1 camera exactly (yfov 2 atan(1/4), at z = 4): its corners touch
    the frame's corners. ``aspect`` None: the camera gives no aspectRatio (it is optional)."""
    g = Gltf()
    pos, nor, uv, idx = grid_plane(4, 2.0)
    pos = pos * np.array([2.0, 1.0, 1.0])
    g.mesh([{"attributes": {"POSITION": g.accessor(pos, FLOAT, bounds=True), "NORMAL": g.accessor(nor)},
             "indices": g.accessor(idx.reshape(-1), UINT)}])
    perspective = {"yfov": 2 * float(np.arctan(0.25)), "znear": 0.1}
    if aspect is not None:
        perspective["aspectRatio"] = aspect
    g.doc["cameras"] = [{"type": "perspective", "perspective": perspective, **({"name": name} if name else {})}]
    g.node(camera=0, translation=[0.0, 0.0, 4.0])
    return g.save(path)


def _size_of(png: Path) -> tuple[int, int]:
    from PIL import Image

    with Image.open(png) as im:
        return im.size


def _warnings(proc) -> list[str]:
    assert "Traceback" not in proc.stderr, proc.stderr
    return [ln for ln in proc.stderr.splitlines() if ln.startswith("alight: warning:")]


def _render_through_camera(mesh: Path, out: Path, *size) -> subprocess.CompletedProcess:
    return run("render", "--mesh", mesh, "--camera", "gltf", *size, "--quality", "low", "--aa", "none",
               "--out", out)


def test_gltf_camera_takes_its_aspect_from_one_side_and_says_so(tmp_path, out_dir):
    """--size 64 asks for 64x64 by the help's first words; the camera's 1.5 makes it 64x43, which
    one line says, naming the file, the camera and the size (a new user's trial found it silent)."""
    mesh = _camera_file(tmp_path / "cam.gltf", 1.5)
    out = out_dir / "c.png"
    proc = _render_through_camera(mesh, out, "--size", "64")
    assert proc.returncode == 0, proc.stderr
    assert _size_of(out) == (64, 43)
    warnings = _warnings(proc)
    assert warnings == [f"alight: warning: --camera gltf: {mesh}'s camera 'Shot' has aspect ratio 1.5, so the image "
                        f"is 64x43 (give --size WxH to choose both)"], warnings


def test_gltf_camera_without_a_name_is_called_by_its_number(tmp_path, out_dir):
    mesh = _camera_file(tmp_path / "cam.glb", 2.0, name=None)
    out = out_dir / "c.png"
    proc = _render_through_camera(mesh, out, "--size", "64")
    assert proc.returncode == 0, proc.stderr
    assert _size_of(out) == (64, 32)
    warnings = _warnings(proc)
    assert len(warnings) == 1 and f"{mesh}'s camera 0 has aspect ratio 2, so the image is 64x32" in warnings[0]


def test_gltf_camera_warns_when_the_size_crops(tmp_path, out_dir):
    mesh = _camera_file(tmp_path / "cam.glb", 2.0)
    out = out_dir / "c.png"
    proc = _render_through_camera(mesh, out, "--size", "64x64")
    assert proc.returncode == 0, proc.stderr
    warnings = _warnings(proc)
    assert len(warnings) == 1, warnings
    assert "camera 'Shot' has aspect ratio 2 but --size 64x64 is 1" in warnings[0], warnings
    assert "keeps the camera's vertical field of view, so its sides are cut off" in warnings[0], warnings
    assert _size_of(out) == (64, 64)


def test_gltf_camera_warns_when_the_size_widens(tmp_path, out_dir):
    mesh = _camera_file(tmp_path / "cam.glb", 1.5)
    out = out_dir / "c.png"
    proc = _render_through_camera(mesh, out, "--size", "64x32")
    assert proc.returncode == 0, proc.stderr
    warnings = _warnings(proc)
    assert len(warnings) == 1 and "so its sides are widened beyond the camera's frame" in warnings[0], warnings
    assert _size_of(out) == (64, 32)


@pytest.mark.parametrize("aspect, size, expected", [
    (1.5, ["--size", "60x40"], (60, 40)),        # WxH that is the camera's ratio
    (1.5, ["--size", "64x43"], (64, 43)),        # ... to the nearest pixel
    (None, ["--size", "32"], (32, 32)),          # no aspectRatio: the square --size promises
    (1.0, ["--size", "32"], (32, 32)),           # a square camera: the square --size promises
], ids=["wxh-matches", "wxh-rounded", "no-aspect", "square-camera"])
def test_gltf_camera_says_nothing_when_the_size_is_what_was_asked(tmp_path, out_dir, aspect, size, expected):
    mesh = _camera_file(tmp_path / "cam.glb", aspect)
    out = out_dir / "c.png"
    proc = _render_through_camera(mesh, out, *size)
    assert proc.returncode == 0, proc.stderr
    assert "warning" not in proc.stderr, proc.stderr
    assert _size_of(out) == expected


@pytest.mark.parametrize("command, args, names", [
    ("reference", ["--view", "probe", "--camera", "gltf"], ["--camera gltf: not with --view probe"]),
    ("reference", ["--view", "probe", "--mesh", "cube"], ["--mesh cube: not with --view probe"]),
    ("reference", ["--mesh", "cube", "--camera", "gltf:1"],
     ["--camera gltf:1: the built-in mesh 'cube' has no glTF camera"]),
    ("render", ["--view", "probe", "--fov", "40"], ["--fov: not with --view probe"]),
], ids=["reference-probe-gltf", "reference-probe-mesh", "reference-builtin-gltf", "render-probe-fov"])
def test_probe_and_builtin_camera_conflicts_are_one_line(out_dir, command, args, names):
    """alight reference reads the scene and camera flags as alight render does: the same refusals."""
    assert_refused(run(command, "--size", "16", *args, "--out", out_dir / "x.exr"), names, out_dir)

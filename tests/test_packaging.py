"""What ``pip install .`` gives a user: a package named alight (nothing named app), cheap to
import, carrying its shaders, presets and measured table, usable beside a project that has its
own ``app`` package.

The wheel is built from this checkout and installed into a fresh virtual environment; its
dependencies come from this interpreter's site-packages through a path entry that is searched
after the new environment's own, so the alight under test is the one in the wheel."""

from __future__ import annotations

import os
import shutil
import site
import subprocess
import sys
import sysconfig
import textwrap
import zipfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
GL_MODULES = ("moderngl", "glfw", "OpenGL", "imgui_bundle", "trimesh", "OpenImageIO")


def run(python, code_or_args, cwd, **kw):
    args = ["-c", code_or_args] if isinstance(code_or_args, str) else code_or_args
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    return subprocess.run([str(python), *args], cwd=cwd, env=env, capture_output=True, text=True, timeout=300, **kw)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    # Built from a copy: setuptools builds inside the source tree (build/), which must stay clean.
    src, out = tmp_path_factory.mktemp("src"), tmp_path_factory.mktemp("wheel")
    for name in ("app", "shaders", "presets"):
        shutil.copytree(REPO / name, src / name, ignore=shutil.ignore_patterns("__pycache__"))
    for name in ("pyproject.toml", "README.md"):
        shutil.copy2(REPO / name, src / name)
    built = subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(src)],
                           capture_output=True, text=True, timeout=600)
    assert built.returncode == 0, built.stderr[-3000:]
    (whl,) = out.glob("alight-*.whl")
    return whl


@pytest.fixture(scope="module")
def fresh_venv(wheel, tmp_path_factory) -> Path:
    """A new virtual environment with the wheel installed (no deps) and this one's deps behind it."""
    root = tmp_path_factory.mktemp("venv")
    made = subprocess.run([sys.executable, "-m", "venv", "--without-pip", str(root)], capture_output=True, text=True)
    assert made.returncode == 0, made.stderr
    python = root / "bin" / "python"
    purelib = Path(run(python, "import sysconfig; print(sysconfig.get_paths()['purelib'])", root).stdout.strip())
    with zipfile.ZipFile(wheel) as z:   # a wheel is a zip laid out as site-packages: installing it is unpacking it
        z.extractall(purelib)
    ours = [p for p in (sysconfig.get_paths()["purelib"], *site.getsitepackages()) if Path(p).is_dir()]
    (purelib / "zz_alight_test_deps.pth").write_text("\n".join(dict.fromkeys(ours)) + "\n")
    return python


def test_wheel_holds_alight_and_nothing_named_app(wheel):
    names = zipfile.ZipFile(wheel).namelist()
    tops = {n.split("/")[0] for n in names}
    assert {t for t in tops if not t.endswith(".dist-info")} == {"alight"}
    shipped = {n.removeprefix("alight/shaders/") for n in names if n.startswith("alight/shaders/")}
    in_repo = {p.relative_to(REPO / "shaders").as_posix() for p in (REPO / "shaders").rglob("*") if p.is_file()}
    assert in_repo and in_repo <= shipped, f"shaders missing from the wheel: {sorted(in_repo - shipped)}"
    presets = {n.removeprefix("alight/presets/") for n in names if n.startswith("alight/presets/") and n.endswith(".json")}
    assert presets == {p.name for p in (REPO / "presets").glob("*.json")} and len(presets) >= 10
    assert "alight/accuracy/auto_quality_table.json" in names
    entry_points = zipfile.ZipFile(wheel).read(next(n for n in names if n.endswith("entry_points.txt"))).decode()
    assert "alight = alight.frontends.cli:main" in entry_points
    assert "alight = alight.frontends.pytest_plugin" in entry_points


def test_import_alight_loads_no_gl_module(fresh_venv, tmp_path):
    code = (f"import sys, alight; print(alight.__file__); "
            f"print([m for m in {GL_MODULES!r} if m in sys.modules]); "
            f"import importlib.util; print(importlib.util.find_spec('app'))")
    out = run(fresh_venv, code, tmp_path)
    assert out.returncode == 0, out.stderr
    where, loaded, app_spec = out.stdout.split("\n")[:3]
    assert Path(where).is_relative_to(fresh_venv.parents[1]), where    # the wheel's copy, not the checkout
    assert loaded == "[]"
    assert app_spec == "None"                                           # nothing named app is installed


def test_python_m_alight_help(fresh_venv, tmp_path):
    out = run(fresh_venv, ["-m", "alight", "--help"], tmp_path)
    assert out.returncode == 0, out.stderr
    assert out.stdout.startswith("usage: alight") and " render " in out.stdout


def test_nothing_named_app_in_site_packages(fresh_venv, tmp_path):
    purelib = Path(run(fresh_venv, "import sysconfig; print(sysconfig.get_paths()['purelib'])", tmp_path).stdout.strip())
    assert not [p.name for p in purelib.iterdir() if p.name.split(".")[0] == "app"]
    assert (purelib / "alight" / "shaders" / "common" / "brdf.glsl").is_file()


def test_a_project_with_its_own_app_package_uses_alight(fresh_venv, tmp_path):
    """The usual name for a user's application is ``app``: both import and work in one process."""
    (tmp_path / "app").mkdir()
    (tmp_path / "app" / "__init__.py").write_text("NAME = 'the user app'\n")
    (tmp_path / "app" / "views.py").write_text("def title():\n    return 'gold preview'\n")
    (tmp_path / "main.py").write_text(textwrap.dedent("""
        import app
        from app.views import title
        import alight

        with alight.Renderer(32, quality="low") as r:
            pixels = r.set_material("gold").render()
        print(app.NAME, '|', title(), '|', pixels.shape, pixels[16, 16, :3].tolist(), '|', alight.__file__)
    """))
    out = run(fresh_venv, ["main.py"], tmp_path)
    assert out.returncode == 0, out.stderr[-2000:]
    name, title, shape, where = [s.strip() for s in out.stdout.strip().split("|")]
    assert name == "the user app" and title == "gold preview"
    assert shape.startswith("(32, 32, 4)") and "[0, 0, 0]" not in shape       # gold is lit, not black
    assert Path(where).is_relative_to(fresh_venv.parents[1])


def test_console_script_renders(tmp_path):
    """The ``alight`` command of this interpreter's install (make setup) renders from any folder."""
    script = Path(sys.executable).parent / "alight"
    assert script.exists(), "no alight console script beside this interpreter (make setup installs it)"
    out = subprocess.run([str(script), "render", "--size", "32", "--quality", "low", "--out", "x.png"],
                         cwd=tmp_path, capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert (tmp_path / "x.png").stat().st_size > 0

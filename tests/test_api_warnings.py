"""What alight says it drew without, through each front end: the Python API and the pytest
plugin issue an ``alight.AlightWarning`` (a Python warning, so pytest's capture, ``pytest.warns``
and ``-W error::alight.AlightWarning`` see it in every test), the CLI prints its one
``alight: warning:`` line, once (app/errors.py warn)."""

from __future__ import annotations

import os
import subprocess
import sys
import warnings
from pathlib import Path

import alight
from tests.warned import alight_warnings

REPO = Path(__file__).resolve().parents[1]
DUCK = REPO.parent / "shared" / "data" / "models" / "Duck.glb"
SAMPLER = ("textures[0]: sampler minFilter NEAREST_MIPMAP_LINEAR is drawn as minFilter LINEAR_MIPMAP_LINEAR "
           "(a material's maps are drawn repeat, trilinear; the file loaded as the mesh draws its samplers as given)")

INNER = f'''
import pytest
import alight

DUCK = {str(DUCK)!r}

def test_first(alight_renderer):
    with pytest.warns(alight.AlightWarning, match="NEAREST_MIPMAP_LINEAR"):
        alight_renderer.set_material(DUCK)

def test_second_sees_it_too(alight_renderer):
    with pytest.warns(alight.AlightWarning, match="NEAREST_MIPMAP_LINEAR"):
        alight_renderer.set_material(DUCK)

def test_uncaught(alight_renderer):
    alight_renderer.set_material(DUCK)
'''


def test_warnings_are_python_warnings_in_every_pytest_test(pytester):
    """A new user's suite saw a file's warning in its first test only (stderr, once a process):
    now each test's pytest.warns sees it, pytest's summary lists it under the test that met it,
    and -W error::alight.AlightWarning fails that test."""
    pytester.makepyfile(test_inner=INNER)
    plugin = [] if _plugin_installed() else ["-p", "alight.frontends.pytest_plugin"]
    run = pytester.runpytest_subprocess(*plugin, "-p", "no:cacheprovider")
    run.assert_outcomes(passed=3, warnings=1)
    run.stdout.fnmatch_lines(["*test_uncaught*", "*AlightWarning: *Duck.glb: textures[[]0[]]: sampler minFilter*"])
    strict = pytester.runpytest_subprocess(*plugin, "-p", "no:cacheprovider", "-W", "error::alight.AlightWarning")
    strict.assert_outcomes(passed=2, failed=1)
    strict.stdout.fnmatch_lines(["*FAILED*test_uncaught*AlightWarning*"])


def _plugin_installed() -> bool:
    from importlib.metadata import entry_points

    return any(ep.name == "alight" for ep in entry_points(group="pytest11"))


def test_the_api_warns_per_call_site_and_names_the_sampler():
    """catch_warnings sees each call's warning (no once-a-process memory); the sampler's enums
    are named as the glTF spec names them (it showed {'minFilter': 9986, ...})."""
    r = alight.Renderer(16)
    for _ in range(2):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            r.set_material(DUCK)
        said = [w for w in caught if issubclass(w.category, alight.AlightWarning)]
        assert [str(w.message) for w in said] == [f"{DUCK}: {SAMPLER}"], [str(w.message) for w in caught]
        assert said[0].filename == __file__   # the user's line, not alight's
    assert issubclass(alight.AlightWarning, UserWarning)


def test_the_mesh_draws_its_samplers_so_loading_it_says_nothing():
    """set_mesh(Duck.glb) draws the file's own sampler (alight.render.gpu_mesh), so only
    set_material, whose maps are drawn repeat/trilinear, warns about it."""
    with alight_warnings() as said:
        alight.Renderer(16).set_mesh(DUCK)
    assert not [x for x in said if "sampler" in x], said


def test_the_cli_says_it_once_on_stderr(tmp_path):
    """The CLI keeps its one 'alight: warning:' line (not a second, Python-formatted one)."""
    p = subprocess.run([sys.executable, "-m", "alight", "render", "--preset", str(DUCK), "--size", "16",
                        "--quality", "low", "--out", str(tmp_path / "duck.png")],
                       cwd=REPO, env=dict(os.environ), capture_output=True, text=True, timeout=120)
    assert p.returncode == 0, p.stderr
    assert [x for x in p.stderr.splitlines() if "sampler" in x] == [f"alight: warning: {DUCK}: {SAMPLER}"], p.stderr
    assert "AlightWarning" not in p.stderr


def test_api_warnings_name_the_api_not_the_command_line(tmp_path):
    """Through the API a warning names Renderer.set_mesh (or a value that fits both front ends),
    not a CLI flag: a new user was told '--occlusion on bakes it' and 'render the file with
    --mesh' from Python."""
    import numpy as np

    from alight.exchange.gltf_material import import_material
    from tests.gltf_builder import Gltf

    g = Gltf()
    t = g.image(np.full((4, 4, 3), 128, np.uint8))
    g.use("KHR_materials_clearcoat")
    g.material(pbrMetallicRoughness={"baseColorTexture": {"index": t, "texCoord": 1}},
               extensions={"KHR_materials_clearcoat": {"clearcoatFactor": 1.0, "clearcoatTexture": {"index": t}}})
    path = g.save(tmp_path / "layered.gltf")
    with alight_warnings() as said:
        alight.Renderer(16).set_material(path)
    assert len(said) == 2 and "texCoord 1" in said[0] and "clearcoat" in said[1], said
    assert all("Renderer.set_mesh" in x and "--" not in x for x in said), said
    with alight_warnings() as said:
        import_material(path)   # (a library function: both ways named)
    assert len(said) == 1 and "Renderer.set_mesh" in said[0], said

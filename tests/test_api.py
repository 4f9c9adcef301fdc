"""The Python API (app/frontends/api.py): lazy import, rendering to arrays and files, the bake cache, release."""

from __future__ import annotations

import re
import subprocess
import sys

import numpy as np
import pytest

import alight.render.renderer
from alight import Renderer
from alight.core.material import Material
from alight.errors import AlightError
from alight.exchange.presets import list_presets
from tests.warned import alight_warnings


def test_import_alight_is_cheap():
    code = ("import sys, alight; assert 'moderngl' not in sys.modules and 'trimesh' not in sys.modules; "
            "from alight import Renderer; assert 'moderngl' not in sys.modules; print('ok')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "ok"


def test_unknown_attribute_is_an_attribute_error():
    import alight

    with pytest.raises(AttributeError):
        alight.no_such_thing  # noqa: B018


def test_hundred_materials_under_one_environment_bake_once(monkeypatch, tmp_path):
    monkeypatch.setenv("ALIGHT_CACHE_DIR", str(tmp_path))   # an empty bake cache: the first render bakes
    calls = []
    real = alight.render.renderer.bake_steps   # (ForwardRenderer.bake runs its steps to their end)

    def counting(*args, **kwargs):
        calls.append(args[2].content_hash)
        return real(*args, **kwargs)

    monkeypatch.setattr(alight.render.renderer, "bake_steps", counting)
    with Renderer(16, quality="low") as r:
        r.set_environment("studio")
        centres = set()
        for i in range(100):
            r.set_material(Material(base_color=(i / 99, 0.5, 0.2), roughness=(i % 10) / 9, name=f"m{i}"))
            centres.add(tuple(r.render()[8, 8, :3]))
        assert len(calls) == 1 and r.bakes_done == 1
        assert len(centres) > 50  # the materials really differ in the images
        # Another quality of the same environment is another bake; coming back to low is not.
        r.quality = "medium"
        r.render()
        r.quality = "low"
        r.render()
        assert len(calls) == 2


def test_render_linear_and_srgb_and_presets_differ():
    with Renderer(32, quality="low") as r:
        r.set_material("gold")
        srgb = r.render()
        lin = r.render(linear=True)
        assert srgb.dtype == np.uint8 and srgb.shape == (32, 32, 4)
        assert lin.dtype == np.float32 and lin.shape == (32, 32, 4)
        assert lin[16, 16, 3] == 1.0 and lin[0, 0, 3] == 0.0  # the ball is hit in the middle only
        gold = lin[16, 16, :3]
        assert gold[0] > gold[2] * 1.5  # gold is yellow
        r.set_material("silver")
        silver = r.render(linear=True)[16, 16, :3]
        assert abs(silver[0] - silver[2]) < 0.2 * silver.max()


def test_field_overrides_and_probe_view():
    with Renderer(32, quality="low") as r:
        r.set_material("gold", roughness=1.0)
        assert r.material.roughness == 1.0 and r.material.name == "gold"
        r.set_view("probe")
        probe = r.render(linear=True)
        assert probe[0, 0, 3] == 0.0 and probe[16, 16, 3] == 1.0
        with pytest.raises(AlightError):
            r.render(32, 16)


def test_save_png_and_exr(tmp_path):
    import OpenImageIO as oiio

    with Renderer(24, 16, quality="low") as r:
        r.set_mesh("cube").set_camera(orbit_deg=30, elevation_deg=20)
        png = r.save(tmp_path / "a.png")
        exr = r.save(tmp_path / "a.exr")
    assert oiio.ImageInput.open(str(png)).spec().width == 24
    spec = oiio.ImageInput.open(str(exr)).spec()
    assert (spec.width, spec.height, spec.nchannels) == (24, 16, 4)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.exr", "a.png"]


def test_lights_without_environment():
    with Renderer(32, quality="low") as r:
        r.set_environment(None).set_material(Material(base_color=(0.8, 0.8, 0.8)))
        dark = r.render(linear=True)[16, 16, :3].sum()
        r.add_light("point:pos=0,0,5:intensity=50")
        lit = r.render(linear=True)[16, 16, :3].sum()
        assert dark < 1e-6 < lit
        assert r.bakes_done == 0


def test_close_releases_and_reopens():
    r = Renderer(16, quality="low")
    assert not r.is_open
    with r:
        r.render()
        assert r.is_open
    assert not r.is_open
    r.close()  # idempotent
    with pytest.raises(AlightError, match="closed"):   # no context opened behind the user's back
        r.render()
    assert r.open().render().shape == (16, 16, 4)  # opened again, explicitly
    r.close()


@pytest.mark.parametrize("call", [
    lambda r: r.set_mesh("nosuch.obj"),
    lambda r: r.set_material("no-such-preset"),
    lambda r: r.set_material("gold", roughness=2.0),
    lambda r: r.set_display(tonemap="filmic"),
    lambda r: r.save("out.jpg"),
    lambda r: r.render(0),
])
def test_bad_input_is_one_alight_error(call):
    r = Renderer(8, quality="low")
    with pytest.raises(AlightError) as exc:
        call(r)
    assert "\n" not in str(exc.value)
    r.close()


@pytest.mark.parametrize("call, said", [
    (lambda r: r.set_material(roughnes=0.3), r"^set_material: unknown field 'roughnes' \(did you mean 'roughness'\?"),
    (lambda r: r.add_light("foo"), r"^add_light: 'foo': the kind must be"),
    (lambda r: r.add_light("point:pos=1,2"), r"^add_light: pos '1,2' is not 3"),
    (lambda r: r.set_lights(["spot:pos=0,1,0"]), r"^set_lights: 'spot:pos=0,1,0': a spot light needs dir="),
])
def test_bad_input_names_the_call(call, said):
    """A script's mistake is named by the call it made (not the CLI's flag: add_light said
    '--light:') and a misspelt field gets the near name, as the CLI's presets do."""
    r = Renderer(8, quality="low")
    with pytest.raises(AlightError, match=said):
        call(r)
    r.close()


def test_every_preset_loads_by_name():
    r = Renderer(8, quality="low")
    for name in list_presets():
        assert r.set_material(name).material.name == name


def test_other_renderers_in_the_process_are_not_disturbed():
    """Opening and closing an Renderer must leave another renderer's context current."""
    from alight.core.scene import Scene
    from alight.ibl.environment import constant_environment
    from tests.gpu import renderer

    shared = renderer()
    maps = shared.bake(constant_environment(1.0, 64), "low")
    scene = Scene(material=Material(base_color=(0.5, 0.5, 0.5), roughness=1.0), view="probe")
    before = shared.render(scene, maps, 16, 16).linear
    with Renderer(16, quality="low") as r:
        r.render()
        between = shared.render(scene, maps, 16, 16).linear
    after = shared.render(scene, maps, 16, 16).linear
    assert before[8, 8, 3] == 1.0 and before[8, 8, :3].min() > 0.1
    np.testing.assert_array_equal(before, between)
    np.testing.assert_array_equal(before, after)


def test_ibl_model_is_chosen_by_name_and_changes_the_image(shared_data, monkeypatch, tmp_path):
    monkeypatch.setenv("ALIGHT_CACHE_DIR", str(tmp_path))   # an empty bake cache: the first render bakes
    with Renderer(48, quality="low") as r:
        r.set_environment(str(shared_data / "env" / "quarry_01_1k.hdr")).set_material("gold").set_view("probe")
        default = r.render(linear=True)
        lecture = r.set_ibl_model("lecture").render(linear=True)
        assert r.bakes_done == 1                       # a model is a shader choice, not a bake
        assert np.abs(default - lecture).max() > 0.05
        with pytest.raises(AlightError, match="ibl model"):
            r.set_ibl_model("nonsense")


def test_file_warnings_reach_the_api_user_once(tmp_path):
    """What a mesh file is drawn without is said through the API too, as an AlightWarning (a
    Python warning: the default filter shows it once per calling line, as for a loop here)."""
    import alight

    (tmp_path / "tri2.obj").write_text("mtllib nowhere.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    r = alight.Renderer(16)
    with alight_warnings() as said:
        for _ in range(2):
            r.set_mesh(tmp_path / "tri2.obj")
    assert said == [f"{tmp_path / 'tri2.obj'}: mtllib 'nowhere.mtl' not found; the parts using its materials "
                    "are drawn with the current material (the default unless one is set)"]
    r.close()


def test_the_probe_view_refuses_what_it_would_ignore(tmp_path):
    """set_view('probe') with a ground, shadows 'on' or occlusion 'on'/'gtao': one AlightError
    naming the setter at render (the probe draws the material on its unit sphere; these were
    silently ignored), as `alight render --view probe` refuses the flags; and nothing written."""
    with Renderer(16, quality="low") as r:
        r.set_view("probe")
        for setup, setter in ((lambda: r.set_shadows(ground=True), "set_shadows(ground=True)"),
                              (lambda: r.set_shadows("on"), "set_shadows('on')"),
                              (lambda: r.set_occlusion("gtao"), "set_occlusion('gtao')")):
            setup()
            with pytest.raises(AlightError, match=r"^" + re.escape(setter) + r": not with set_view\('probe'\)"):
                r.save(tmp_path / "probe.png")
            r.set_shadows("auto", ground=False, occlusion="auto")
        assert not (tmp_path / "probe.png").exists()
        assert r.render().shape == (16, 16, 4)     # the defaults draw


def test_a_ground_with_nothing_to_catch_says_so_in_the_setters_words(shared_data):
    """set_shadows(ground=True) in the built-in studio with no light draws nothing: one warning
    in the API's words (it said --ground and --light, the command line's); with a directional
    light, none."""
    with Renderer(32, quality="low") as r:
        r.set_mesh(str(shared_data / "models" / "Duck.glb")).set_shadows(ground=True)
        with alight_warnings() as said:
            r.render()
        lines = [x for x in said if "ground" in x]
        assert lines == ["set_shadows(ground=True): nothing casts a shadow on it, so it changes "
                         "nothing: no light, and no sun in the map that the IBL model shades exactly "
                         "(add_light(...), or use a map with a sun)"], lines
        r.add_light("directional:dir=-0.5,-1,-0.3")
        with alight_warnings() as said:
            r.render()
        assert not [x for x in said if "ground" in x], said

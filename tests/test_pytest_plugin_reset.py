"""The plugin's alight_renderer fixture (app/frontends/pytest_plugin.py) resets the session's
renderer before each test, in an inner test file run through pytester in its own process."""

from __future__ import annotations

INNER = '''
import os

import alight

STATE = {}


def test_a_sets_a_scene(alight_renderer):
    r = alight_renderer
    r.set_mesh("sphere").set_material("gold").set_camera(orbit_deg=90).add_light("point:pos=0,2,3")
    r.set_display(background="transparent", exposure=1.0)
    STATE["image"] = r.render(24, 24)
    STATE["bakes"] = r.bakes_done
    STATE["renderer"] = r


def test_b_gets_the_constructors_scene(alight_renderer):
    r = alight_renderer
    assert r is STATE["renderer"]                        # one renderer for the session ...
    assert r.material == alight.Material() and r.scene.use_file_materials   # ... reset for this test
    assert r.scene.camera is None and r.scene.lights == []
    assert (r.scene.display.background, r.scene.display.exposure) == ("env", 0.0)
    assert r.set_mesh(os.environ["DUCK"]).scene.use_file_materials   # the duck's own materials
    r.set_mesh("sphere").render(24, 24)
    assert r.bakes_done == STATE["bakes"]                # the studio is not baked again


def test_c_closing_it_leaves_the_next_test_a_usable_renderer(alight_renderer):
    alight_renderer.close()


def test_d_renders(alight_renderer):
    assert alight_renderer.render(8, 8).shape == (8, 8, 4)
'''


def test_each_test_gets_a_reset_session_renderer(pytester, monkeypatch, shared_data):
    pytester.makepyfile(test_inner=INNER)
    monkeypatch.setenv("DUCK", str(shared_data / "models" / "Duck.glb"))
    result = pytester.runpytest_subprocess("-p", "no:cacheprovider", "-p", "no:randomly")
    result.assert_outcomes(passed=4)

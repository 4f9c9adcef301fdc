"""alight.Renderer's scene state (app/frontends/api.py): reset to the constructor's scene, the
orbit camera framed at render, fields on a file's own materials, a Camera's clip planes fitted
to the mesh, a closed renderer, sizes and names checked as given, and the docstrings."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

import alight
from alight import Renderer
from alight.core.material import Material
from alight.errors import AlightError
from tests.warned import alight_warnings

REPO = Path(__file__).resolve().parents[1]
ALPHA_BLEND = "models/khronos/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb"
TINY = "models/khronos/MetalRoughSpheresNoTextures/glTF-Binary/MetalRoughSpheresNoTextures.glb"


def test_reset_goes_back_to_the_constructors_scene_without_a_bake(shared_data):
    """A scene set by one user of a shared renderer (the plugin's fixture) never reaches the
    next after reset(): the image is the constructor's again, and the studio is not baked again."""
    with Renderer(32, quality="low", tonemap="agx", background="transparent") as r:
        first = r.render()
        bakes = r.bakes_done
        r.set_mesh(str(shared_data / "models" / "Duck.glb")).set_material("gold", roughness=0.5).set_camera(orbit_deg=90)
        r.set_environment(None).add_light("point:pos=2,3,4:intensity=30").set_shadows("on", ground=True)
        r.set_display(tonemap="none", exposure=2.0, background="env").set_ibl_model("lecture")
        r.width, r.aa, r.quality = 48, "none", "medium"
        assert r.reset() is r
        assert (r.width, r.height, r.aa, r.quality) == (32, 32, "msaa", "low")
        assert r.material == Material() and r.texture_maps is None and r.scene.use_file_materials
        assert r.scene.camera is None and r.scene.lights == [] and r.scene.material_overrides == {}
        assert (r.scene.display.tonemap, r.scene.display.exposure, r.scene.display.background) == \
            ("agx", 0.0, "transparent")
        np.testing.assert_array_equal(r.render(), first)
        assert r.bakes_done == bakes     # the same studio: its bake is reused, not made again
        # set_mesh on a glTF after reset draws the file's own materials, not the last test's gold.
        r.set_mesh(str(shared_data / "models" / "Duck.glb"))
        assert r.scene.use_file_materials


def test_a_material_set_before_or_after_set_mesh_replaces_the_files_own(shared_data):
    """As `alight render --mesh Duck.glb --preset gold` (a gold duck), whatever the order."""
    with Renderer(32, quality="low") as r:
        duck = str(shared_data / "models" / "Duck.glb")
        before = r.set_material("gold").set_mesh(duck).render()
        after = r.reset().set_mesh(duck).set_material("gold").render()
        own = r.reset().set_mesh(duck).render()
        np.testing.assert_array_equal(before, after)
        assert np.abs(own.astype(int) - after.astype(int)).max() > 50


def test_orbit_camera_is_framed_for_the_renders_own_size(shared_data):
    """set_camera(orbit_deg=...) on a square renderer, then a tall render: framed for the tall
    image (it was framed for the constructor's square and cropped the model at the sides)."""
    with Renderer(64, quality="low", background="transparent") as r:
        r.set_mesh(str(shared_data / ALPHA_BLEND)).set_camera(orbit_deg=0)
        alpha = r.render(32, 64)[:, :, 3]
        assert alpha.max() == 255
        assert alpha[:, 0].max() == 0 and alpha[:, -1].max() == 0, "the model is cut at the image's sides"
        # ... and for the mesh of the render, not the one set before the camera.
        r.set_mesh("sphere").set_camera(orbit_deg=0).set_mesh(str(shared_data / ALPHA_BLEND))
        np.testing.assert_array_equal(r.render(32, 64)[:, :, 3], alpha)


def test_fields_without_a_material_apply_to_a_files_own_materials(shared_data):
    """set_material(base_color=...) on a glTF drawn with its own materials changes the picture
    (it was a silent no-op), as `alight render --mesh Duck.glb --base-color ...` does; the file's
    own materials stay on (the duck keeps its texture); a new material ends the overrides."""
    with Renderer(32, quality="low") as r:
        r.set_mesh(str(shared_data / "models" / "Duck.glb"))
        own = r.render().astype(int)
        blue = r.set_material(base_color=(0.1, 0.1, 0.9), roughness=0.2).render().astype(int)
        assert r.scene.use_file_materials and r.material.base_color == (0.1, 0.1, 0.9)
        assert r.scene.material_overrides == {"base_color": (0.1, 0.1, 0.9), "roughness": 0.2}
        assert np.abs(own - blue).max() > 50
        mean_before, mean_after = own[..., :3].reshape(-1, 3).mean(0), blue[..., :3].reshape(-1, 3).mean(0)
        assert mean_after[2] - mean_after[0] > mean_before[2] - mean_before[0]   # bluer
        r.set_material("gold")
        assert r.scene.material_overrides == {} and not r.scene.use_file_materials


def test_a_camera_without_clip_planes_fits_them_to_a_tiny_model(shared_data):
    """A 5 mm model seen from 1.6 cm: a Camera with near/far unset fits them and draws it; a
    fixed 0.05..100 range misses all of it, and says so in one warning."""
    with Renderer(32, quality="low", background="transparent") as r:
        r.set_mesh(str(shared_data / TINY))
        centre, radius = r.mesh.bounding_sphere()
        eye = tuple(float(x) for x in np.asarray(centre) + (0.0, 0.0, 3.0 * radius))
        with alight_warnings() as said:
            fitted = r.set_camera(alight.Camera(position=eye, target=tuple(centre))).render()
        assert (fitted[:, :, 3] > 0).mean() > 0.2
        assert not [x for x in said if "clip range" in x], said
        with alight_warnings() as said:
            fixed = r.set_camera(alight.Camera(position=eye, target=tuple(centre), near=0.05, far=100.0)).render()
        assert fixed[:, :, 3].max() == 0
        lines = [x for x in said if "clip range" in x]
        assert len(lines) == 1 and lines[0].startswith("set_camera: the mesh lies outside "
                                                       "the camera's clip range (near 0.05, far 100;"), lines


def test_rendering_after_the_with_block_is_an_error(tmp_path):
    """Leaving `with` released the context; a render then opened a new one that nothing
    released. Now one alight.Error, nothing written; open() (or `with r:`) opens it again."""
    with Renderer(16, quality="low") as r:
        r.render()
    with pytest.raises(AlightError, match=r"^render: this Renderer is closed") as exc:
        r.render()
    assert "\n" not in str(exc.value)
    with pytest.raises(AlightError, match="closed"):
        r.save(tmp_path / "x.png")
    assert not (tmp_path / "x.png").exists() and not r.is_open
    with r:
        assert r.render().shape == (16, 16, 4)
    assert not r.is_open


@pytest.mark.parametrize("size, said", [((0, 0), "size: 0x0 "), ((7, 0), "size: 7x0 "), ((0, 7), "size: 0x7 ")])
def test_render_size_is_checked_as_given(size, said):
    r = Renderer(16, quality="low")
    with pytest.raises(AlightError, match="^" + said + "must have sides 1..16384$"):
        r.render(*size)


def test_a_misspelt_environment_gets_the_suggestion_batch_gives():
    r = Renderer(16, quality="low")
    with pytest.raises(AlightError, match=r"^stuido: no such file; did you mean studio\?$"):
        r.set_environment("stuido")


def test_the_setters_and_camera_have_docstrings_and_the_guide_shows_the_options():
    for thing, words in ((Renderer.add_light, ("point:pos=", "directional", "AlightError")),
                         (Renderer.set_view, ("probe", "square", "AlightError")),
                         (Renderer.set_display, ("exposure", "transparent", "AlightError")),
                         (Renderer.reset, ("constructor",)),
                         (alight.Camera, ("near", "far", "fov_y_deg", "degrees", "+Y up", "ortho_half_height"))):
        doc = thing.__doc__ or ""
        assert all(w in doc for w in words), (thing, doc)
    guide = (REPO / "docs" / "guides" / "python-api.md").read_text()
    for words in ('background="transparent"', "tonemap=", 'aa="', "exposure=", "reset()"):
        assert words in guide, words

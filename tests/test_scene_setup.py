"""'alight render' and 'alight reference' read their shared flags into one scene
(app/frontends/scene_setup.py): the same flags give the same scene, image size and warnings.
The Python API says the same framing warning."""

from __future__ import annotations

import dataclasses
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from tests.gltf_builder import FLOAT, UINT, Gltf, grid_plane

REPO = Path(__file__).resolve().parents[1]
FLAT = REPO.parent / "shared" / "data" / "bad" / "singlevn.obj"   # a y = 0 plane whose mtllib is missing
# The Scene fields only 'alight render' has flags for; the reference keeps their defaults.
RENDER_ONLY = ("display", "ibl_model", "multiple_scattering", "shadows", "ground", "occlusion")


def run(*args) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "alight", *map(str, args)], cwd=REPO, env=dict(os.environ),
                          capture_output=True, text=True, timeout=300)


def camera_file(path: Path) -> Path:
    """A 4x2 plane and a 2:1 perspective camera on +Z looking at it."""
    g = Gltf()
    pos, nor, uv, idx = grid_plane(4, 2.0)
    g.mesh([{"attributes": {"POSITION": g.accessor(pos * np.array([2.0, 1.0, 1.0]), FLOAT, bounds=True),
                            "NORMAL": g.accessor(nor)}, "indices": g.accessor(idx.reshape(-1), UINT)}])
    g.doc["cameras"] = [{"type": "perspective",
                         "perspective": {"yfov": 2 * float(np.arctan(0.25)), "aspectRatio": 2.0, "znear": 0.1}}]
    g.node(camera=0, translation=[0.0, 0.0, 4.0])
    return g.save(path)


def warnings(stderr: str) -> list[str]:
    return [line for line in stderr.splitlines() if line.startswith("alight: warning:")]


def setups(flags: list[str]):
    """(render's, reference's) SceneSetup and warning lines for the same scene flags, through
    each command's own parser and scene function."""
    from alight.frontends import cli
    from alight.frontends.cli import reference, render
    from alight.frontends.options import build_look

    parser = cli.build_parser()
    flags = flags if "--size" in flags else [*flags, "--size", "64"]   # the defaults differ (1024, 256)
    result = []
    for module, command, out in ((render, "render", "x.png"), (reference, "reference", "x.exr")):
        args = parser.parse_args([command, *flags, "--out", out])
        said: list[str] = []
        module._warn_line, keep = said.append, module._warn_line   # what the command would print
        try:
            result.append((module._scene(args, build_look(args)), said))
        finally:
            module._warn_line = keep
    return result


def comparable(scene):
    """The scene without its mesh's arrays (compared apart) and render's own fields."""
    defaults = {f.name: (f.default_factory() if f.default is dataclasses.MISSING else f.default)
                for f in dataclasses.fields(scene) if f.name in RENDER_ONLY}
    return dataclasses.replace(scene, mesh=None, **defaults)


@pytest.mark.parametrize("flags", [
    [],
    ["--mesh", str(FLAT)],
    ["--mesh", str(FLAT), "--elevation", "30", "--light", "point:pos=1,2,3:intensity=5", "--preset", "gold",
     "--roughness", "0.4", "--env-rotation", "40", "--env-intensity", "0.5"],
    ["--mesh", "cube", "--no-ibl", "--fov", "50", "--target", "0,0.1,0"],
    ["--view", "probe", "--preset", "copper"],
    ["--mesh", "CAMERA", "--camera", "gltf", "--size", "64"],
    ["--mesh", "CAMERA", "--camera", "gltf", "--size", "64x64"],
], ids=["defaults", "flat", "flat-lit-gold", "cube-no-ibl", "probe", "gltf-camera", "gltf-camera-cropped"])
def test_render_and_reference_build_the_same_scene(flags, tmp_path):
    flags = [str(camera_file(tmp_path / "cam.glb")) if f == "CAMERA" else f for f in flags]
    (r, r_said), (f, f_said) = setups(flags)
    assert r_said == f_said
    assert (r.width, r.height) == (f.width, f.height)
    assert comparable(r.scene) == comparable(f.scene)
    assert (r.environment is None) == (f.environment is None)
    if r.environment is not None:
        assert r.environment.content_hash == f.environment.content_hash
    if r.scene.mesh is None:
        assert f.scene.mesh is None
    else:
        assert r.scene.mesh.source == f.scene.mesh.source and len(r.scene.mesh.parts) == len(f.scene.mesh.parts)
        for a, b in zip(r.scene.mesh.parts, f.scene.mesh.parts):
            assert np.array_equal(a.positions, b.positions) and np.array_equal(a.indices, b.indices)
    if "--camera" in flags:
        assert (r.width, r.height) == ((64, 32) if flags[-1] == "64" else (64, 64))
        # Both differ from the size asked for (the one side is not square, 64x64 is cropped): one line each.
        assert len(r_said) == 1 and ("so the image is 64x32" if flags[-1] == "64" else "cut off") in r_said[0]


def test_the_scene_check_can_fail():
    """Different flags give different scenes and warnings (the comparison above is not vacuous)."""
    (r, r_said), _ = setups(["--mesh", str(FLAT)])
    (_, e_said), (f, _) = setups(["--mesh", str(FLAT), "--elevation", "30"])
    assert comparable(r.scene) != comparable(f.scene)
    assert r_said != e_said


def test_render_and_reference_print_the_same_warnings(tmp_path):
    """Through the commands: a flat mesh file with a missing mtllib gives both warnings in both."""
    common = ["--mesh", FLAT, "--size", "16", "--no-ibl"]
    rendered = run("render", *common, "--quality", "low", "--aa", "none", "--out", tmp_path / "r.png")
    referenced = run("reference", *common, "--integrator", "exact", "--out", tmp_path / "f.exr")
    assert rendered.returncode == 0 and referenced.returncode == 0, rendered.stderr + referenced.stderr
    said = warnings(rendered.stderr)
    assert len(said) == 2 and "surface.mtl" in said[0] and "edge-on" in said[1], said
    assert warnings(referenced.stderr) == said


def test_reference_takes_the_gltf_cameras_aspect_as_render_does(tmp_path):
    """--size W with --camera gltf: both images are W x W / aspect (the reference used to be square),
    and both say so in the same one line."""
    import OpenImageIO as oiio

    from PIL import Image

    mesh = camera_file(tmp_path / "cam.glb")
    common = ["--mesh", mesh, "--camera", "gltf", "--size", "32", "--no-ibl", "--light", "directional:dir=0,0,-1"]
    rendered = run("render", *common, "--quality", "low", "--aa", "none", "--out", tmp_path / "r.png")
    referenced = run("reference", *common, "--integrator", "exact", "--out", tmp_path / "f.exr")
    assert rendered.returncode == 0 and referenced.returncode == 0, rendered.stderr + referenced.stderr
    said = warnings(rendered.stderr)
    assert len(said) == 1 and "has aspect ratio 2, so the image is 32x16" in said[0], said
    assert warnings(referenced.stderr) == said
    with Image.open(tmp_path / "r.png") as im:
        assert im.size == (32, 16)
    spec = oiio.ImageInput.open(str(tmp_path / "f.exr")).spec()
    assert (spec.width, spec.height) == (32, 16)


def test_the_api_says_a_flat_mesh_is_seen_edge_on():
    """alight.Renderer frames a mesh from +Z by default too, and says so for a flat one, with the
    API's way out; a built-in plane has its own view and is not warned about."""
    import alight

    from tests.warned import alight_warnings

    with alight.Renderer(16, quality="low") as r:
        r.set_environment(None)
        with alight_warnings() as said:
            r.set_mesh("plane").render()
        assert not [line for line in said if "edge-on" in line], said
        with alight_warnings() as said:
            r.set_mesh(FLAT).render()
        edge_on = [line for line in said if "edge-on" in line]
        assert edge_on == [f"{FLAT}: the mesh is flat and the default camera (on +Z) sees it "
                           "edge-on, so it may not show; set_camera(orbit_deg=0, elevation_deg=30) looks at it "
                           "from another side"]


def test_light_spec_is_parse_lights_inverse():
    """The editor's 'copy camera as flags' writes each light with light_spec: --light reads it
    back as the same light, for every kind and the optional fields."""
    from alight.core.scene import Light, light_spec, parse_light

    for light in (Light("point", (2.0, 3.0, 4.0), (1.0, 0.95, 0.9), 10.0),
                  Light("directional", (-0.3, -1.0, -0.5), (1.0, 1.0, 1.0), 1.0),
                  Light("spot", (1.0, 2.0, 3.0), (0.5, 0.5, 0.5), 30.0, range=12.5, direction=(0.0, -1.0, 0.0),
                        inner_cone_deg=10.0, outer_cone_deg=35.0)):
        assert parse_light(light_spec(light)) == light, light_spec(light)


def test_the_editors_flags_are_read_back_as_its_scene():
    """'copy camera as flags' (EditorState.render_flags) leaves out each setting that is at
    'alight render''s default: parsed by the command's own parser and set up by its own code, the
    flags give the editor's scene back, field by field, for the editor's defaults and for every
    setting moved off them. (render_flags writes the command's defaults down itself: a default
    changed in the parser and not there fails here.)"""
    from alight.core.scene import Display, Light
    from alight.frontends.cli import build_parser
    from alight.frontends.cli.render import _scene
    from alight.frontends.editor.camera import OrbitCamera
    from alight.frontends.editor.state import EditorState
    from alight.frontends.options import build_look

    moved = [{}, {"lights": []}, {"lights": [Light("directional", (0.0, -1.0, 0.0), (1.0, 1.0, 1.0), 2.0)]},
             {"env_rotation_deg": 90.0}, {"env_intensity": 0.5}, {"ibl_enabled": False}, {"ibl_model": "lecture"},
             {"multiple_scattering": True}, {"quality": "high"}, {"occlusion": "off"}, {"occlusion": "gtao"},
             {"shadows": "off"}, {"ground": True}, {"aa": "none"},
             {"display": Display(tonemap="none", exposure=1.5, background="color", background_color=(0.5, 0.25, 0.125))},
             {"display": Display(background="blur")}]
    for fields in moved:
        state = EditorState(**fields)
        state.load_mesh("sphere")
        state.load_env("studio")
        camera = OrbitCamera()
        flags = [*camera.render_flags((64, 48)), *state.render_flags()]
        args = build_parser().parse_args(["render", "--out", "x.png", *flags])
        got = _scene(args, build_look(args)).scene
        want = state.scene(camera)
        for name in ("lights", "env_rotation_deg", "env_intensity", "ibl_enabled", "ibl_model",
                     "multiple_scattering", "occlusion", "shadows", "ground"):
            assert getattr(got, name) == getattr(want, name), (fields, name, flags)
        assert dataclasses.replace(got.display, blur_roughness=0) == dataclasses.replace(want.display, blur_roughness=0), \
            (fields, flags)
        assert (args.quality, args.aa) == (state.quality, state.aa), (fields, flags)


@pytest.mark.parametrize("kind", ["point", "spot", "directional"])
@pytest.mark.parametrize("centre, radius", [((0.0, 0.0, 0.0), 1.0), ((40.0, -3.0, 7.0), 10.0), ((0.01, 0.0, 0.0), 0.005)])
def test_an_added_light_gives_the_mesh_the_irradiance_asked_for(kind, centre, radius):
    """alight.core.scene.added_light (the editor's 'add point/spot/directional'): the light faces
    the mesh's centre from a distance in proportion to its radius, and its irradiance there is the
    one asked for, whatever the mesh's size and place."""
    from alight.core.scene import added_light

    light = added_light(kind, centre, radius, 3.5)
    if kind == "directional":
        assert light.intensity == pytest.approx(3.5)
        return
    to_centre = np.asarray(centre) - np.asarray(light.vector)
    d = float(np.linalg.norm(to_centre))
    assert 2.0 * radius < d < 6.0 * radius, (d, radius)
    assert light.intensity / d ** 2 == pytest.approx(3.5)
    if kind == "spot":   # its axis on the centre
        np.testing.assert_allclose(light.direction, to_centre / d, atol=1e-9)


def test_the_mean_irradiance_of_a_constant_map_is_pi_times_its_radiance():
    from alight.ibl.environment import mean_irradiance

    assert mean_irradiance(np.full((64, 128, 3), 0.7, np.float32)) == pytest.approx(np.pi * 0.7, rel=1e-6)

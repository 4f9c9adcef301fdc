"""The frame's pass structure (app/render/renderer.py): the fused MSAA resolve, the fused display
path and the IBL lookup compiled without its below-grid fade give the pixels of the passes they
replace. Each test builds the reference from the separate passes (background pass over every
sample, the blit resolve, the tone map pass) in the same renderer, so the check can fail."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from alight.core.material import Material
from alight.core.mesh import sphere
from alight.core.scene import Display, Light, Scene
from alight.core.stretched_lobe import lobe_table
from alight.exchange.presets import load_preset
from alight.ibl.bake import grid_roughness
from alight.ibl.environment import load_environment
from tests.gpu import renderer

W, H = 120, 90


@pytest.fixture(autouse=True)
def tessellated_ball():
    """The separate passes draw into the multisampled target, which the built-in sphere's impostor
    never does (its own equivalence is tests/test_sphere_lod.py's): compare like with like."""
    r = renderer()
    r.sphere_impostor = False
    yield
    r.sphere_impostor = True


def _read(fbo, components, dtype, np_dtype):
    return np.frombuffer(fbo.read(components=components, dtype=dtype), np_dtype).reshape(H, W, 4)[::-1]


def _separate_passes(r, scene, maps, aa):
    """The frame as the separate passes make it: surfaces, the background pass over every
    sample, the resolve (a blit), the tone map pass."""
    targets = r._targets_for(W, H, aa, 4)
    r.draw_hdr(scene, maps, targets)
    r.tonemap(targets.radiance, scene.display, targets.display_fbo,
              opaque=scene.display.background != "transparent")
    return (_read(targets.radiance_fbo, 4, "f4", np.float32).copy(),
            _read(targets.display_fbo, 4, "f1", np.uint8).astype(int))


@pytest.mark.parametrize("background", ["env", "blur", "color", "transparent"])
def test_the_fused_msaa_resolve_equals_the_separate_passes(shared_data, background):
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "quarry_01_1k.hdr")), "low")
    scene = Scene(mesh=sphere(), material=load_preset("gold"), lights=[Light("point", (2.0, 3.0, 4.0))],
                  display=Display(background=background, exposure=0.5))
    linear, srgb = _separate_passes(r, scene, maps, "msaa")
    both = r.render(scene, maps, W, H, aa="msaa", read_linear=True, read_srgb=True)
    only_linear = r.render(scene, maps, W, H, aa="msaa", read_linear=True, read_srgb=False).linear
    only_srgb = r.render(scene, maps, W, H, aa="msaa", read_linear=False, read_srgb=True).srgb
    assert srgb[:, :, :3].std() > 5.0                        # a real picture
    edge = (linear[:, :, 3] > 0.0) & (linear[:, :, 3] < 1.0)
    assert edge.sum() > 50                                   # anti-aliased silhouette pixels are compared too
    for got in (both.linear, only_linear):
        np.testing.assert_array_equal(got[:, :, 3], linear[:, :, 3])    # coverage
        rel = np.abs(got[:, :, :3] - linear[:, :, :3]).sum() / np.abs(linear[:, :, :3]).sum()
        assert rel < 1e-5, rel                               # float summation order only
    for got in (both.srgb, only_srgb):
        assert np.abs(got.astype(int) - srgb).max() <= 1


def test_the_display_path_for_srgb_only_frames_equals_the_separate_passes():
    r = renderer()
    maps = r.bake(load_environment("studio"), "low")
    scene = Scene(mesh=sphere(), material=load_preset("copper"), lights=[Light("point", (2.0, 3.0, 4.0))])
    _, srgb = _separate_passes(r, scene, maps, "none")
    fused = r.render(scene, maps, W, H, aa="none", read_linear=False, read_srgb=True).srgb
    assert np.abs(fused.astype(int)[:, :, :3] - srgb[:, :, :3]).max() <= 1
    assert (fused[:, :, 3] == 255).all()


@pytest.mark.parametrize("view", ["camera", "probe"])
def test_the_lookup_without_its_below_grid_fade_is_chosen_only_where_it_changes_nothing(shared_data, view):
    """Where every fetch reads at or above grid A's first step (r0 = 0.25 at medium) the fade is
    compiled out and the image equals the one with it compiled in; below r0 it is kept (the image
    differs from the grid-only lookup). The default model's fitted pair (from r 0.2) fetches at
    r sqrt(beta), down to 0.47 r, so its safe roughness is r0 / sqrt(min beta)."""
    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "medium")
    r0 = grid_roughness(0, maps.quality.prefiltered_levels)
    size = 64

    def frame(roughness, force_fade: bool):
        scene = Scene(mesh=None if view == "probe" else sphere(), view=view,
                      material=Material(base_color=(0.9, 0.6, 0.3), metallic=1.0, roughness=roughness))
        real = r._below_grid_defines
        if force_fade:
            r._below_grid_defines = lambda *a, **k: {}
        try:
            chosen = real(scene, maps, [scene.material])
            image = r.render(scene, maps, size, size, aa="none", read_srgb=False).linear
        finally:
            r._below_grid_defines = real
        return chosen, image

    safe = max(r0 + 0.05, r0 / math.sqrt(float(lobe_table()[..., 3].min())) + 0.02)
    chosen, without = frame(safe, False)
    _, with_fade = frame(safe, True)
    assert chosen == {"IBL_BELOW_GRID": 0}
    chosen, _ = frame(r0 + 0.05, False)
    assert chosen == {}                                     # the pair's narrowest fetch reads below r0
    np.testing.assert_array_equal(without, with_fade)
    chosen, _ = frame(r0 * 0.5, False)
    assert chosen == {}                                     # a roughness below the grid keeps the fade
    # A layer's roughness counts too when the layer is on (clearcoat > 0); a layer that is off
    # (glTF's default clearcoat_roughness 0, clearcoat 0) does not. So does a roughness map.
    coated = Material(roughness=0.8, clearcoat=1.0, clearcoat_roughness=0.05)
    scene = Scene(mesh=sphere(), material=coated)
    assert r._below_grid_defines(scene, maps, [coated]) == {}
    assert r._below_grid_defines(scene, maps, [Material(roughness=0.8, clearcoat_roughness=0.05)]) == {"IBL_BELOW_GRID": 0}
    # Layers that fetch at a roughness of their own keep the fade (the transmission LUT's
    # refracted lobe is narrower than the material's: 2% -> 10% error at r = 0.3 without it).
    for layered in (load_preset("water"), load_preset("velvet"), load_preset("brushed_aluminium")):
        assert r._below_grid_defines(scene, maps, [replace(layered, roughness=0.8)]) == {}
    assert r._below_grid_defines(scene, maps, [Material(roughness=0.8)], map_mask=2) == {}   # metallic-roughness map
    assert r._below_grid_defines(scene, maps, [Material(roughness=0.8)], map_mask=1) == {"IBL_BELOW_GRID": 0}


def test_a_frame_with_blended_parts_keeps_the_background_pass_and_equals_it():
    """A glTF BLEND part is drawn over the background (glTF 2.0 3.9.4), so an MSAA frame with one
    takes the separate passes (background, blended parts, blit resolve), not the fused resolve:
    the same pixels, and the background shows through the half-transparent ball."""
    from dataclasses import replace

    from alight.core.mesh import FileMaterial, Mesh

    r = renderer()
    maps = r.bake(load_environment("studio"), "low")
    ball = sphere()
    glass = FileMaterial(base_color=(0.9, 0.2, 0.1), metallic=0.0, roughness=0.4, alpha=0.5, alpha_mode="BLEND")
    mesh = Mesh(parts=[replace(part, material=glass) for part in ball.parts], source="blend test")
    scene = Scene(mesh=mesh, use_file_materials=True, lights=[Light("point", (2.0, 3.0, 4.0))])
    assert r._has_blending_parts(scene)
    linear, srgb = _separate_passes(r, scene, maps, "msaa")
    frame = r.render(scene, maps, W, H, aa="msaa", read_linear=True, read_srgb=True)
    np.testing.assert_array_equal(frame.linear, linear)
    assert np.abs(frame.srgb.astype(int) - srgb).max() == 0
    centre = linear[H // 2, W // 2]
    assert 0.4 < centre[3] < 0.6        # half covered: the ball blends over the background


def test_srgb_only_msaa_frames_in_half_floats_keep_the_pixels_and_clamp_what_half_cannot_hold():
    """An sRGB-only MSAA frame draws into half floats (renderer.HALF_FLOAT_MIN_EXPOSURE): the
    same 8-bit pixels as the float frame within 1 LSB, also where the radiance passes half's
    largest value (a light of 1e9: its highlight clamps to 65504 and still saturates, never inf
    or NaN); an exposure below the limit keeps the float target. (llvmpipe's conversion to half
    saturates by itself, so here the shader's clamp, HALF_FLOAT_OUTPUT, is not what is tested:
    it is there for a GL that rounds to +inf.)"""
    from alight.render.renderer import HALF_FLOAT_MAX, HALF_FLOAT_MIN_EXPOSURE

    r = renderer()
    maps = r.bake(load_environment("studio"), "low")
    scene = Scene(mesh=sphere(), material=Material(base_color=(0.9, 0.9, 0.9), metallic=1.0, roughness=0.2),
                  lights=[Light("point", (2.0, 3.0, 4.0), intensity=1e9)], display=Display(exposure=-5.0))
    full = r.render(scene, maps, W, H, aa="msaa", read_linear=True, read_srgb=True)
    assert not r._targets.half
    assert full.linear[:, :, :3].max() > 10 * HALF_FLOAT_MAX        # the highlight is out of half's range
    half = r.render(scene, maps, W, H, aa="msaa", read_linear=False, read_srgb=True).srgb
    assert r._targets.half
    assert np.abs(half.astype(int) - full.srgb).max() <= 1
    assert (half[full.srgb[:, :, :3].max(axis=2) == 255].max(axis=1) == 255).all()   # saturated stays saturated
    scene.display.exposure = HALF_FLOAT_MIN_EXPOSURE - 1.0
    r.render(scene, maps, W, H, aa="msaa", read_linear=False, read_srgb=True)
    assert not r._targets.half


def test_a_mirror_like_ball_has_no_sparkles_on_its_rim_with_msaa(shared_data):
    """MSAA shades an edge pixel once, at its centre, which may lie off the triangle: the normal
    there is extrapolated past the silhouette and a mirror-like metal flashes. The normal is then
    read at the covered samples' centroid (mesh_material.glsl): the MSAA image matches the SSAA one
    but for ordinary anti-aliasing differences (without the fix: 11 pixels off by > 60 of 255)."""
    from alight.ibl.environment import load_environment

    r = renderer()
    maps = r.bake(load_environment(str(shared_data / "cases" / "hdr_minusY_rle.hdr")), "low")
    scene = Scene(mesh=sphere(), material=replace(load_preset("silver"), roughness=0.05))
    msaa = r.render(scene, maps, 256, 256, aa="msaa").srgb.astype(int)
    ssaa = r.render(scene, maps, 256, 256, aa="ssaa").srgb.astype(int)
    assert (np.abs(msaa - ssaa).max(axis=2) > 60).sum() == 0


@pytest.mark.parametrize("view", ["camera", "probe"])
def test_the_suns_loop_is_compiled_out_only_for_an_environment_without_a_sun(shared_data, view, monkeypatch):
    """IBL_SUNS 0 (common/suns.glsl) where the maps hold no compact source: the same pixels as the
    loop compiled in with a count of 0. One renderer switching between a map with a sun and one
    without, both ways (as the editor's environment switch and a batch over environments do):
    the map with a sun always draws with the loop (the image with it compiled out differs), and
    each map's image is the one it gets alone, before any switch."""
    from alight.render import passes
    from alight.render.variants import sun_defines

    r = renderer()
    sunny = r.bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")
    plain = r.bake(load_environment("studio"), "low")
    assert sunny.suns and not plain.suns
    assert sun_defines(plain) == {"IBL_SUNS": 0} and sun_defines(None) == {"IBL_SUNS": 0}
    assert sun_defines(sunny) == {}
    # car paint: the suns through the clear coat's layering (sun_layered); the camera view adds
    # the ground and its sun shadow (ground.frag's loop) and a point light
    scene = Scene(mesh=None if view == "probe" else sphere(), view=view, material=load_preset("car_paint"),
                  lights=[] if view == "probe" else [Light("point", (2.0, 3.0, 4.0))],
                  shadows="off" if view == "probe" else "on", ground=view == "camera")
    size = 64
    real = passes.sun_defines

    def frame(maps, defines=None):
        monkeypatch.setattr(passes, "sun_defines", real if defines is None else (lambda _maps: defines))
        return r.render(scene, maps, size, size, aa="none", read_srgb=False).linear

    sunny_alone = frame(sunny)
    plain_out = frame(plain)
    sunny_after = frame(sunny)
    plain_after = frame(plain)
    plain_loop = frame(plain, {})                     # the loop compiled in, its count a uniform 0
    sunny_out = frame(sunny, {"IBL_SUNS": 0})         # what a sun drawn without its loop would give
    keys = {k for k in r.shaders.compiled_keys() if k[2] == f"render/{'probe' if view == 'probe' else 'pbr'}.frag"}
    assert any(("IBL_SUNS", 0) in k[3] for k in keys) and any(("IBL_SUNS", 0) not in k[3] for k in keys)
    np.testing.assert_array_equal(plain_out, plain_loop)
    np.testing.assert_array_equal(plain_after, plain_loop)
    np.testing.assert_array_equal(sunny_after, sunny_alone)
    assert np.abs(sunny_out[..., :3] - sunny_alone[..., :3]).max() > 0.05   # the sun shows on the ball

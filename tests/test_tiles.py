"""Output sizes one framebuffer cannot hold: tiles with the same pixels.

The plan (alight.render.tiles) is checked as arithmetic at every size the CLI accepts; the GL
side by equivalence: an image drawn in small forced tiles against the same image in one pass,
linear radiance and the tone-mapped display both, for the probe view, the mesh view with each
anti-aliasing mode, and each background.
"""

from __future__ import annotations

import itertools
import subprocess
import sys

import moderngl
import numpy as np
import OpenImageIO as oiio
import pytest

from alight.core.material import Material
from alight.core.mesh import cube, sphere
from alight.core.scene import Camera, Display, Light, Scene
from alight.errors import AlightError
from alight.exchange.meshes import load_mesh
from alight.ibl.environment import load_environment
from alight.render import renderer as renderer_module
from alight.render.tiles import (
    READBACK_BYTES,
    STRIP_BYTES,
    TILE_BYTES,
    Tile,
    TilePlan,
    framebuffer_bytes,
    plan_tiles,
    side_limit,
    tile_matrix,
)
from tests.conftest import REPO, SHARED_DATA
from tests.gpu import renderer

CASES = SHARED_DATA / "cases"
LLVMPIPE = {"GL_MAX_TEXTURE_SIZE": 16384, "GL_MAX_RENDERBUFFER_SIZE": 16384, "GL_MAX_VIEWPORT_DIMS": (16384, 16384),
            "GL_MAX_FRAMEBUFFER_WIDTH": 16384, "GL_MAX_FRAMEBUFFER_HEIGHT": 16384}


# --- the plan -------------------------------------------------------------------------------

def _covers_once(plan: TilePlan) -> None:
    seen = np.zeros((plan.height, plan.width), np.int8)
    y = 0
    for strip in plan.strips():
        assert strip[0].y == y and len({t.height for t in strip}) == 1   # strips are whole rows, in order
        x = 0
        for t in strip:
            assert t.x == x and t.y == y
            assert 1 <= t.width <= plan.tile_width and 1 <= t.height <= plan.tile_height
            seen[t.y:t.y + t.height, t.x:t.x + t.width] += 1
            x += t.width
        assert x == plan.width
        y += strip[0].height
    assert y == plan.height and np.all(seen == 1)


@pytest.mark.parametrize("aa, samples", [("none", 0), ("msaa", 4), ("ssaa", 0)])
@pytest.mark.parametrize("width, height", [(1, 1), (256, 256), (1024, 1024), (2048, 2048), (1920, 1080),
                                           (4096, 4096), (8192, 8192), (16384, 16384), (16384, 1), (1, 16384),
                                           (16384, 9), (12345, 6789)])
def test_every_cli_size_has_a_plan_within_the_limits(width, height, aa, samples):
    side = side_limit(LLVMPIPE, aa)
    bpp = framebuffer_bytes(aa, samples)
    plan = plan_tiles(width, height, side, bpp)
    _covers_once(plan)
    assert plan.tile_width <= side and plan.tile_height <= side
    assert plan.tile_width * plan.tile_height * bpp <= TILE_BYTES
    if not plan.single:
        assert plan.tile_height * width * READBACK_BYTES <= STRIP_BYTES
    if width * height * bpp <= TILE_BYTES and max(width, height) <= side:
        assert plan.single      # what fits is drawn in one pass, as before


def test_sizes_that_fit_stay_one_pass():
    # the default 1024 and 2048x2048 with 4x MSAA (400 MiB of framebuffers) are not tiled
    for size in (1024, 2048):
        assert plan_tiles(size, size, 16384, framebuffer_bytes("msaa", 4)).single
    assert side_limit(LLVMPIPE, "ssaa") == 8192 and side_limit(LLVMPIPE, "msaa") == 16384
    # SSAA draws 2x: 9000 wide does not fit one 16384 framebuffer
    assert not plan_tiles(9000, 10, 8192, framebuffer_bytes("ssaa", 0)).single


def test_forced_tiles_are_evened_out():
    plan = plan_tiles(100, 70, 16384, 24, tile=(32, 32))
    assert (plan.tile_width, plan.tile_height) == (25, 24)
    _covers_once(plan)


def test_tile_matrix_puts_each_tile_on_its_framebuffer():
    """A full-image pixel centre, projected with the tile's matrix, lands on that pixel's place in
    the tile's framebuffer (clip coordinates with w != 1 too)."""
    rng = np.random.default_rng(2)
    plan = plan_tiles(97, 61, 16384, 24, tile=(20, 13))
    for strip in plan.strips():
        for t in strip:
            m = tile_matrix(plan, t)
            px = rng.uniform(t.x, t.x + t.width, 20)
            row = rng.uniform(t.y, t.y + t.height, 20)          # rows from the top
            gl_y = plan.height - row
            w = rng.uniform(0.5, 3.0, 20)
            clip = np.column_stack([(2 * px / plan.width - 1) * w, (2 * gl_y / plan.height - 1) * w,
                                    rng.uniform(-1, 1, 20) * w, w])
            tile_clip = clip @ m
            fx = (tile_clip[:, 0] / tile_clip[:, 3] + 1) / 2 * plan.tile_width
            fy = (tile_clip[:, 1] / tile_clip[:, 3] + 1) / 2 * plan.tile_height
            np.testing.assert_allclose(fx, px - t.x, atol=1e-9)
            np.testing.assert_allclose(fy, gl_y - (plan.height - t.y - t.height), atol=1e-9)
            np.testing.assert_allclose(tile_clip[:, 2:], clip[:, 2:])
    one = plan_tiles(50, 40, 16384, 24)
    np.testing.assert_array_equal(tile_matrix(one, Tile(0, 0, 50, 40)), np.eye(4))


# --- the GL: tiles against one pass ---------------------------------------------------------

@pytest.fixture(scope="module")
def maps(shared_data):
    return renderer().bake(load_environment(str(shared_data / "env" / "royal_esplanade_1k.hdr")), "low")


GOLD = Material(base_color=(1.0, 0.78, 0.34), metallic=1.0, roughness=0.35)
LIGHTS = [Light(kind="point", vector=(2.0, 3.0, 4.0), intensity=30.0)]


def _compare(one: np.ndarray, tiled: np.ndarray, edge_fraction: float) -> tuple[float, float]:
    """(relative mean absolute difference, fraction of pixels that differ by more than 1e-4 of
    the image's mean); asserts both small: differences are float rounding, and at MSAA
    silhouettes a sample whose coverage the rounding flips."""
    one, tiled = one.astype(np.float64), tiled.astype(np.float64)
    scale = max(np.abs(one).mean(), 1e-12)
    diff = np.abs(tiled - one)
    rel = float(diff.sum() / max(np.abs(one).sum(), 1e-12))
    differing = float(np.mean(diff.max(axis=2) > 1e-4 * scale))
    assert rel < 1e-3, rel
    assert differing <= edge_fraction, differing
    return rel, differing


SCENES = {   # name: (scene, anti-aliasing, size)
    "probe aces": (lambda: Scene(view="probe", material=GOLD), "msaa", (72, 72)),
    "probe none transparent": (
        lambda: Scene(view="probe", material=GOLD, display=Display(tonemap="none", background="transparent")),
        "none", (72, 72)),
    "ball msaa": (lambda: Scene(mesh=sphere(), material=GOLD, lights=LIGHTS), "msaa", (96, 64)),
    "ball ssaa neutral": (
        lambda: Scene(mesh=sphere(), material=GOLD, display=Display(tonemap="neutral")), "ssaa", (96, 64)),
    "ball none exposure": (lambda: Scene(mesh=sphere(), display=Display(exposure=1.5)), "none", (64, 96)),
    "cube blur": (lambda: Scene(mesh=cube(), display=Display(background="blur")), "msaa", (90, 70)),
    "cube colour": (
        lambda: Scene(mesh=cube(), camera=Camera(position=(2.5, 2.0, 3.0)),
                      display=Display(background="color", background_color=(0.2, 0.3, 0.4))),
        "msaa", (90, 70)),
    "ball transparent": (lambda: Scene(mesh=sphere(), display=Display(background="transparent")), "msaa", (80, 80)),
    # glTF alphaMode BLEND (drawn after the background, back to front) and MASK, over nothing
    "blend file transparent": (
        lambda: Scene(mesh=load_mesh(str(CASES / "gltf_alpha_blend.glb")), display=Display(background="transparent")),
        "msaa", (80, 60)),
    "mask file": (lambda: Scene(mesh=load_mesh(str(CASES / "gltf_alpha_mask.glb"))), "ssaa", (80, 60)),
}


@pytest.mark.parametrize("name", list(SCENES))
def test_tiles_give_the_one_pass_image(maps, name):
    make, aa, (w, h) = SCENES[name]
    r = renderer()
    one = r.render(make(), maps, w, h, aa=aa)
    for tile in [(20, 13), (w - 1, h // 2 + 1)]:
        tiled = r.render(make(), maps, w, h, aa=aa, tile=tile)
        # Silhouettes: a sample (MSAA), sub-pixel (SSAA) or pixel centre on an edge may fall
        # the other way in one of them; measured at most 0.2% of the pixels.
        edges = 0.0 if scene_is_probe(name) else 0.005
        _compare(one.linear, tiled.linear, edges)
        # the display: the same 8-bit values, but where such a sample flipped
        srgb_diff = np.abs(one.srgb.astype(int) - tiled.srgb.astype(int)).max(axis=2)
        assert np.mean(srgb_diff > 1) <= edges


def scene_is_probe(name: str) -> bool:
    return name.startswith("probe")


def test_strips_come_in_order_with_bounded_rows(maps):
    r = renderer()
    scene = Scene(view="probe", material=GOLD)
    one = r.render(scene, maps, 50, 50)
    rows = []
    for strip in r.render_strips(scene, maps, 50, 50, tile=(50, 7)):
        assert strip.y0 == sum(rows) and strip.frame.linear.shape[1:] == (50, 4)
        assert len(strip.frame.linear) <= 7
        np.testing.assert_allclose(strip.frame.linear, one.linear[strip.y0:strip.y0 + len(strip.frame.linear)],
                                   rtol=1e-5, atol=1e-6)
        rows.append(len(strip.frame.linear))
    assert sum(rows) == 50 and len(rows) == 8


def test_framebuffers_the_gl_refuses_give_smaller_tiles(maps, monkeypatch):
    """Where the GL cannot make the framebuffers (memory, an incomplete framebuffer: the
    traceback of 'alight render --size 8192'), tiles a quarter the size are tried."""
    r = renderer()
    scene = Scene(mesh=sphere(), material=GOLD)
    one = r.render(scene, maps, 96, 64)
    real = renderer_module.ForwardRenderer._targets_for
    asked = []

    def refuse_big(self, width, height, aa, samples, half=False):
        asked.append((width, height))
        if width * height > 1000:
            raise moderngl.Error("the framebuffer is not complete")
        return real(self, width, height, aa, samples, half)

    monkeypatch.setattr(renderer_module.ForwardRenderer, "_targets_for", refuse_big)
    tiled = r.render(scene, maps, 96, 64)
    assert asked[0] == (96, 64) and asked[-1][0] * asked[-1][1] <= 1000
    _compare(one.linear, tiled.linear, 0.01)

    def refuse_all(self, width, height, aa, samples, half=False):
        raise moderngl.Error("GL_OUT_OF_MEMORY\ntoo big")

    monkeypatch.setattr(renderer_module.ForwardRenderer, "_targets_for", refuse_all)
    with pytest.raises(AlightError) as ei:
        r.render(scene, maps, 96, 64)
    msg = str(ei.value)
    assert "\n" not in msg and msg.startswith("OpenGL: cannot make a") and "96x64 image" in msg
    monkeypatch.undo()
    r._targets = None


def test_cli_writes_tiled_images_strip_by_strip(tmp_path):
    """alight render through the tiled path (tile_bytes made tiny, in a process of its own) writes
    the same PNG and EXR as one pass, band by band."""
    assert len(plan_tiles(96, 64, 16384, framebuffer_bytes("msaa", 4), 30 * 1024).strips()) > 2
    outs = {}
    for tiled, ext in itertools.product((False, True), ("png", "exr")):
        out = tmp_path / f"{'tiled' if tiled else 'one'}.{ext}"
        code = ("import sys, alight.render.renderer as r\n"
                + ("r.ForwardRenderer.tile_bytes = 30 * 1024\n" if tiled else "")
                + "from alight.frontends.cli import main\n"
                + f"sys.exit(main(['render', '--size', '96x64', '--quality', 'low', '--out', {str(out)!r}]))")
        proc = subprocess.run([sys.executable, "-c", code], cwd=REPO, capture_output=True, text=True,
                              timeout=300, check=False)
        assert proc.returncode == 0 and "Traceback" not in proc.stderr, proc.stderr
        outs[(tiled, ext)] = oiio.ImageBuf(str(out)).get_pixels(oiio.FLOAT)
    _compare(outs[(False, "exr")], outs[(True, "exr")], 0.005)
    diff = np.abs(outs[(False, "png")] - outs[(True, "png")]).max(axis=2)
    assert np.mean(diff > 1.5 / 255) <= 0.005
    assert outs[(True, "png")].shape == (64, 96, 3)


@pytest.mark.parametrize("size", [(8000, 6000), (4002, 4002), (7000, 5000)])
def test_even_image_gets_even_tiles(size):
    """An even image's automatic tiles are even (8000x6000 was cut into 2667-wide tiles): a pass
    of an odd size cannot use the visibility buffer (alight.render.vbuffer.ineligible_reason)."""
    plan = plan_tiles(*size, 16384, framebuffer_bytes("msaa", 4))
    assert not plan.single and plan.tile_width % 2 == 0 and plan.tile_height % 2 == 0, plan
    assert sum(t.width for t in plan.strips()[0]) == size[0]
    assert sum(s[0].height for s in plan.strips()) == size[1]

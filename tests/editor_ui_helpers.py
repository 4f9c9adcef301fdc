"""What the editor's UI check files (tests/editor_ui_checks*.py) share: where the ball is in the
view, waiting on frames, and the window or a screenshot as a user would get it. Each check file
is loaded by path by ``alight edit --ui-test`` (not as a package), so it puts this folder on
``sys.path`` before importing this module. Not collected by pytest."""

from __future__ import annotations

import os
import time

import numpy as np

from alight.frontends.editor.ui_test import editor, view

OUT = os.environ.get("ALIGHT_UI_TEST_OUT", ".")   # the run's folder (the editor's cwd too)


def ball(image: np.ndarray) -> np.ndarray:
    """Pixels well inside the ball (it fills the middle of the view): float64 (n, channels)."""
    h, w = image.shape[:2]
    y, x = np.mgrid[0:h, 0:w]
    return image[(x - w / 2) ** 2 + (y - h / 2) ** 2 < (0.2 * h) ** 2].astype(np.float64)


def contrast(image: np.ndarray) -> float:
    """Mean horizontal luminance step inside the ball: high for a mirror, low for a rough ball."""
    lum = image.astype(np.float64).mean(axis=2)
    step = np.zeros_like(lum)
    step[:, 1:] = np.abs(np.diff(lum, axis=1))
    return float(ball(step[:, :, None]).mean())


def changed(ctx, before: np.ndarray, what: str) -> np.ndarray:
    """The view now, asserting the ball differs from ``before`` (a widget's edit showed): float64."""
    after = view(ctx).astype(np.float64)
    assert np.abs(ball(after) - ball(before)).mean() > 0.3, what
    return after


def until(ctx, done, frames: int = 6000) -> None:
    """Frames until ``done()``; AssertionError after ``frames``."""
    for _ in range(frames):
        ctx.yield_()
        if done():
            return
    raise AssertionError("timed out")


def until_seconds(ctx, done, limit_s: float) -> float:
    """Frames until ``done()``: the seconds it took; AssertionError after ``limit_s``."""
    start = time.monotonic()
    while not done():
        assert time.monotonic() - start < limit_s, f"not done after {limit_s} s"
        ctx.yield_()
    return time.monotonic() - start


def capture(ctx, name: str) -> np.ndarray:
    """The whole window as the engine captures it (panel and view, as shown), written to OUT/name:
    uint8 (h, w, 4)."""
    import OpenImageIO as oiio
    from imgui_bundle.immapp.testing import capture as engine_capture

    path = os.path.join(OUT, name)
    engine_capture(ctx, path)
    return oiio.ImageBuf(path).get_pixels(oiio.UINT8)


def screenshot(ctx) -> np.ndarray:
    """Click 'screenshot (F12)' and read the file it writes into the editor's cwd: uint8 (h, w, c)."""
    import OpenImageIO as oiio

    names = set(os.listdir("."))
    ctx.set_ref("alight")
    ctx.item_click("**/screenshot (F12)")
    new = []
    until(ctx, lambda: editor().screenshot_job is None and
          bool(new.extend(n for n in set(os.listdir(".")) - names if n.startswith("alight-screenshot-")) or new))
    return oiio.ImageBuf(new[0]).get_pixels(oiio.UINT8)


def checker_levels(corner: np.ndarray) -> tuple[float, float]:
    """The fractions of a corner's pixels (uint8 (h, w, 3)) at the transparent background's
    checkerboard light and dark grey (204, 153)."""
    v = corner.astype(np.int32)
    grey = (v.max(axis=2) - v.min(axis=2)) <= 2
    light = (grey & (np.abs(v[:, :, 0] - 204) <= 2)).mean()
    dark = (grey & (np.abs(v[:, :, 0] - 153) <= 2)).mean()
    return float(light), float(dark)


def type_path(ctx, ref: str, text: str) -> None:
    """Type ``text`` into the field ``ref`` without Enter (the engine's item_input_value ends
    with Enter, which in the env, mesh, map and texture-set fields applies the field: a check of
    the button beside the field types with this, then clicks the button)."""
    ctx.item_click(ref)
    ctx.key_chars_replace(text)

"""The view saved as a PNG (F12, the panel's button): at the view's size or a chosen one up to
MAX_SIDE a side, RGBA with the coverage as alpha when the background is transparent.

The renderer's offline path draws it (``ForwardRenderer.render_strips``: an image too big for
one framebuffer is drawn in tiles, ``alight.render.tiles``), and the file is written a strip at
a time (``alight.exchange.output.image_rows_writer``: atomic, the file appears only whole), a
few strips a frame, so a big picture keeps the window drawing and the panel shows its progress.
"""

from __future__ import annotations

import os
import sys
import time
from dataclasses import dataclass

from alight.frontends.editor.widgets import tooltip

MAX_SIDE = 16384          # the renderer's limit (GL_MAX_TEXTURE_SIZE guaranteed by OpenGL 4.1)
STEP_BUDGET_S = 0.05      # time a frame gives the screenshot being written, beyond one strip


@dataclass
class ScreenshotSize:
    """The panel's choice: the view's own size, or ``width`` x ``height`` pixels."""

    at_view_size: bool = True
    width: int = 3840
    height: int = 2160

    def size(self, view_area: tuple[int, int]) -> tuple[int, int]:
        if self.at_view_size:
            return view_area
        return clamp_side(self.width), clamp_side(self.height)


def clamp_side(n: int) -> int:
    return max(1, min(MAX_SIDE, int(n)))


class ScreenshotJob:
    """One PNG being drawn and written strip by strip (``step``); the scene is the one at the
    start. Errors: AlightError of one line naming the file; nothing is left half written."""

    def __init__(self, renderer, scene, maps, size: tuple[int, int], aa: str, path: str):
        from alight.exchange.output import check_output_path, image_rows_writer

        self.path = str(check_output_path(path, (".png",)).resolve())
        self.width, self.height = size
        self.channels = 4 if scene.display.background == "transparent" else 3
        self._writer = image_rows_writer(self.path, self.width, self.height, self.channels, linear=False)
        self._put = self._writer.__enter__()
        self._strips = renderer.render_strips(scene, maps, self.width, self.height, aa=aa,
                                              read_linear=False, read_srgb=True)
        self.rows = 0

    def step(self, budget_s: float = STEP_BUDGET_S) -> bool:
        """Draw and write strips for about ``budget_s`` (at least one); True once the file is whole."""
        start = time.perf_counter()
        try:
            while True:
                strip = next(self._strips, None)
                if strip is None:
                    self._writer.__exit__(None, None, None)
                    return True
                self._put(strip.frame.srgb[:, :, :self.channels])
                self.rows += len(strip.frame.srgb)
                if self.rows >= self.height:   # the last strip: the file is whole now
                    self._strips.close()
                    self._writer.__exit__(None, None, None)
                    return True
                if time.perf_counter() - start >= budget_s:
                    return False
        except BaseException:
            self._strips.close()
            if not self._writer.__exit__(*sys.exc_info()):   # the temporary file removed; AlightError raised
                raise
            return True

    def cancel(self) -> None:
        self._strips.close()
        try:
            self._writer.__exit__(RuntimeError, RuntimeError("cancelled"), None)
        except Exception:
            pass

    def progress(self) -> str:
        return f"writing {os.path.basename(self.path)}: {self.rows} of {self.height} rows"


class WholeScreenshotJob:
    """A PNG drawn whole in one step (the compare split, whose halves are put together on the
    whole image: compare_view.compose_frame), with ScreenshotJob's interface. ``pixels()``
    returns (H, W, C) uint8 sRGB, top row first."""

    def __init__(self, pixels, size: tuple[int, int], path: str):
        from alight.exchange.output import check_output_path

        self.path = str(check_output_path(path, (".png",)).resolve())
        self.width, self.height = size
        self._pixels = pixels
        self.rows = 0

    def step(self, budget_s: float = STEP_BUDGET_S) -> bool:
        from alight.exchange.output import write_image

        write_image(self.path, self._pixels(), linear=False)   # atomic: whole or not at all
        self.rows = self.height
        return True

    def cancel(self) -> None:
        pass

    def progress(self) -> str:
        return f"writing {os.path.basename(self.path)}"


def draw_controls(win) -> None:
    """The panel's screenshot row: size (the view's or chosen), the button, the job's progress."""
    from imgui_bundle import imgui

    choice = win.screenshot_size
    w, h = win.view_area()
    _, choice.at_view_size = imgui.checkbox(f"screenshot at the view's size ({w}x{h})###shot_view_size",
                                            choice.at_view_size)
    if not choice.at_view_size:
        changed, v = imgui.input_int2("screenshot size", [choice.width, choice.height])
        if changed:
            choice.width, choice.height = clamp_side(v[0]), clamp_side(v[1])
        if imgui.is_item_hovered():
            tooltip(f"pixels, up to {MAX_SIDE} a side; a big one is drawn in tiles and "
                              "written a strip a frame")
    if imgui.button("screenshot (F12)"):
        win.screenshot_request = win.next_screenshot_name()   # the window writes it after the frame
    job = getattr(win, "screenshot_job", None)
    if job is not None:
        imgui.same_line()
        imgui.text_disabled(job.progress())

"""The framebuffers of a frame (one output size and anti-aliasing mode), kept between frames,
and how an image too big for one framebuffer picks its tile size (alight.render.tiles)."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass

import moderngl
import numpy as np

from alight.core.gpu import release_objects
from alight.errors import AlightError
from alight.render.tiles import TILE_BYTES, Tile, TilePlan, framebuffer_bytes, plan_tiles, side_limit

# A multisampled frame read as sRGB only is drawn into half floats (half the bytes written,
# cleared and resolved) where the tone map saturates before the clamp to half's largest value
# could show: 65504 / 4 (one sample of four) at 2^-6 is 256, white in every tone map.
HALF_FLOAT_MAX = 65504.0
HALF_FLOAT_MIN_EXPOSURE = -6.0


@dataclass(frozen=True)
class View:
    """The part of the image a pass draws: the whole image's size, and for a tile its
    off-centre matrix (alight.render.tiles) and its bottom-left pixel in the image."""

    width: int
    height: int
    matrix: np.ndarray | None = None
    origin: tuple[int, int] = (0, 0)


class Targets:
    """Framebuffers for one output size and anti-aliasing mode, kept between frames."""

    def __init__(self, ctx: moderngl.Context, width: int, height: int, aa: str, samples: int, half: bool = False):
        self.ctx = ctx
        self.width, self.height, self.aa, self.samples = width, height, aa, samples
        self.half = half and aa == "msaa"     # the MSAA colour in half floats (HALF_FLOAT_MIN_EXPOSURE)
        self._display_draw = None
        self._behind: tuple[moderngl.Texture, moderngl.Framebuffer] | None = None
        self.draw = self.depth = self.radiance_fbo = self.radiance = self.display_fbo = self.display = None
        self._both_fbo = None
        self._single: tuple[moderngl.Texture, moderngl.Framebuffer] | None = None
        self._visibility: tuple[moderngl.Texture, moderngl.Framebuffer] | None = None
        self.color = None
        try:
            self._allocate()
        except Exception:
            self.release()
            raise

    def _allocate(self) -> None:
        ctx, width, height, aa, samples = self.ctx, self.width, self.height, self.aa, self.samples
        # Linear radiance at the output size: drawn into directly without anti-aliasing, else the
        # MSAA resolve or the SSAA reduction lands here.
        self.radiance = ctx.texture((width, height), 4, dtype="f4")
        self.radiance.filter = (moderngl.NEAREST, moderngl.NEAREST)
        self.radiance_fbo = ctx.framebuffer([self.radiance])
        scale = 2 if aa == "ssaa" else 1
        self.draw_size = (width * scale, height * scale)
        ms = samples if aa == "msaa" else 0
        if aa == "msaa":
            # A texture, not a renderbuffer: render/resolve.frag reads its samples.
            self.color = ctx.texture(self.draw_size, 4, samples=ms, dtype="f2" if self.half else "f4")
        elif aa == "ssaa":
            self.color = ctx.texture(self.draw_size, 4, dtype="f4")
        else:
            self.color = self.radiance
        self.depth = ctx.depth_renderbuffer(self.draw_size, samples=ms)
        self.draw = ctx.framebuffer([self.color], self.depth)
        self.display = ctx.texture((width, height), 4, dtype="f1")
        self.display_fbo = ctx.framebuffer([self.display])

    def behind(self) -> tuple[moderngl.Texture, moderngl.Framebuffer]:
        """What transmissive parts see behind them: the opaque parts' radiance with alpha =
        coverage (premultiplied: uncovered pixels are 0), at the draw size, mipmapped so that a
        rough surface reads it blurred (common/transmission.glsl: scene_behind). Half floats:
        a blurred view through glass needs no more than 11 bits."""
        if self._behind is None:
            tex = self.ctx.texture(self.draw_size, 4, dtype="f2")
            tex.build_mipmaps()
            tex.filter = (moderngl.LINEAR_MIPMAP_LINEAR, moderngl.LINEAR)
            tex.repeat_x = tex.repeat_y = False
            self._behind = (tex, self.ctx.framebuffer([tex]))
        return self._behind

    def single(self) -> tuple[moderngl.Texture, moderngl.Framebuffer]:
        """A single-sample colour target at the draw size, in the multisampled one's format, where
        the built-in sphere's impostor writes its coverage-weighted radiance for the fused resolve
        (alight.render.sphere_impostor). No depth: the proxy is one flat polygon facing the eye."""
        if self._single is None:
            tex = self.ctx.texture(self.draw_size, 4, dtype="f2" if self.half else "f4")
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self._single = (tex, self.ctx.framebuffer([tex]))
        return self._single

    def visibility(self) -> tuple[moderngl.Texture, moderngl.Framebuffer]:
        """The visibility buffer (alight.render.vbuffer): per sample (triangle + 1, part + 1) as
        unsigned integers, 0 where no surface, multisampled as the colour target, with its depth."""
        if self._visibility is None:
            tex = self.ctx.texture(self.draw_size, 2, samples=self.samples, dtype="u4")
            self._visibility = (tex, self.ctx.framebuffer([tex], self.depth))
        return self._visibility

    def display_draw(self) -> moderngl.Framebuffer:
        """The display image with the depth buffer, for ForwardRenderer.draw_display (no AA only)."""
        if self._display_draw is None:
            self._display_draw = self.ctx.framebuffer([self.display], self.depth)
        return self._display_draw

    def resolve_fbo(self, radiance: bool, display: bool) -> moderngl.Framebuffer:
        """Where render/resolve.frag writes: the radiance, the display image, or both (in that
        order: its RADIANCE_OUTPUT at location 0, DISPLAY_OUTPUT at 1)."""
        if radiance and display:
            if self._both_fbo is None:
                self._both_fbo = self.ctx.framebuffer([self.radiance, self.display])
            return self._both_fbo
        return self.radiance_fbo if radiance else self.display_fbo

    def release(self) -> None:
        owned = [self._both_fbo, self._display_draw, self.draw, self.depth, self.radiance_fbo,
                 self.radiance, self.display_fbo, self.display]
        if self.color is not self.radiance:
            owned.append(self.color)
        if self._behind is not None:
            owned.extend(self._behind[::-1])
        if self._single is not None:
            owned.extend(self._single[::-1])
        if self._visibility is not None:
            owned.extend(self._visibility[::-1])
        release_objects(self.ctx, *owned)


_GL_LIMITS = ("GL_MAX_TEXTURE_SIZE", "GL_MAX_RENDERBUFFER_SIZE", "GL_MAX_VIEWPORT_DIMS",
              "GL_MAX_FRAMEBUFFER_WIDTH", "GL_MAX_FRAMEBUFFER_HEIGHT")


def tiled_targets(ctx: moderngl.Context, width: int, height: int, aa: str, samples: int,
                  tile: tuple[int, int] | None, make: Callable[[int, int], Targets],
                  forget: Callable[[], None], budget: int = TILE_BYTES) -> tuple[TilePlan, Targets]:
    """The tile plan for this size and the framebuffers of one tile (``make(tile_width,
    tile_height)``). Where the GL refuses them (out of memory, an incomplete framebuffer), tiles
    a quarter the size are tried (``forget`` drops what the refused attempt left); at 16x16 an
    AlightError says so in one line. ``budget``: the bytes one tile's framebuffers may take."""
    limits = {key: ctx.info.get(key) for key in _GL_LIMITS}
    while True:
        plan = plan_tiles(width, height, side_limit(limits, aa), framebuffer_bytes(aa, samples), budget, tile=tile)
        try:
            return plan, make(plan.tile_width, plan.tile_height)
        except moderngl.Error as exc:
            forget()
            if plan.tile_width * plan.tile_height <= 16 * 16:
                reason = " ".join(str(exc).split()) or type(exc).__name__
                raise AlightError(f"OpenGL: cannot make a {plan.tile_width}x{plan.tile_height} framebuffer "
                                  f"({aa}) for a {width}x{height} image ({reason})") from None
            budget = min(budget, plan.tile_width * plan.tile_height * framebuffer_bytes(aa, samples)) // 4
            tile = None


def read_tile(fbo: moderngl.Framebuffer, tile: Tile, dtype: str, np_dtype) -> np.ndarray:
    """The tile's pixels from the bottom-left of ``fbo``, rows top first (a view, not a copy)."""
    data = fbo.read(viewport=(0, 0, tile.width, tile.height), components=4, dtype=dtype)
    return np.frombuffer(data, np_dtype).reshape(tile.height, tile.width, 4)[::-1]

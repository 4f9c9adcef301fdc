"""Images larger than one framebuffer holds, drawn in tiles that put together are one pass.

A tile is a rectangle of the output image drawn into a framebuffer of its own with an
off-centre projection: the whole image's view-projection followed by the NDC scale and offset
that carry the tile's pixels onto the framebuffer's (the "tiled rendering" of the OpenGL
Programming Guide's appendix on large images). Pixel centres, MSAA sample positions and SSAA's
sub-pixels fall where they fall in one pass over the whole image, so the pixels are that pass's,
up to float rounding of the vertex positions.

Tiles come in strips (rows of tiles, top first), so a caller can write each strip and drop it:
the memory a render holds is one tile's framebuffers and one strip's pixels, whatever the size.
Pure functions; the renderer (``alight.render.renderer``) does the GL.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

# The choices, in one place.
# Framebuffer memory one tile may take (llvmpipe keeps it in system memory). An image whose
# framebuffers fit is drawn in one pass as before: 2048x2048 with 4x MSAA takes 400 MiB.
TILE_BYTES = 512 * 1024 * 1024
# Memory for one strip of read-back pixels (float RGBA radiance and 8-bit sRGB: 20 bytes a pixel).
STRIP_BYTES = 256 * 1024 * 1024
READBACK_BYTES = 16 + 4


def framebuffer_bytes(aa: str, samples: int) -> int:
    """Bytes of framebuffer memory per output pixel: float RGBA radiance (16) and 8-bit display
    (4), plus what is drawn into: a 24-bit depth buffer (4) per sample, and float RGBA colour per
    MSAA sample or per SSAA sub-pixel (2x2)."""
    if aa == "msaa":
        return 16 + 4 + samples * (16 + 4)
    if aa == "ssaa":
        return 16 + 4 + 4 * (16 + 4)
    return 16 + 4 + 4


@dataclass(frozen=True)
class Tile:
    """A rectangle of the image, in output pixels, row 0 at the top."""

    x: int
    y: int
    width: int
    height: int


@dataclass(frozen=True)
class TilePlan:
    """How an image is cut: every tile is drawn into framebuffers of tile_width x tile_height
    output pixels (those of the last row and column use a part of them)."""

    width: int
    height: int
    tile_width: int
    tile_height: int

    @property
    def single(self) -> bool:
        return self.tile_width == self.width and self.tile_height == self.height

    def strips(self) -> list[list[Tile]]:
        """The tiles, a list per strip, strips top to bottom, tiles left to right."""
        return [[Tile(x, y, min(self.tile_width, self.width - x), min(self.tile_height, self.height - y))
                 for x in range(0, self.width, self.tile_width)]
                for y in range(0, self.height, self.tile_height)]


def plan_tiles(width: int, height: int, max_side: int, bytes_per_pixel: int, tile_bytes: int = TILE_BYTES,
               strip_bytes: int = STRIP_BYTES, tile: tuple[int, int] | None = None) -> TilePlan:
    """One tile when the whole image fits (its sides within ``max_side``, the GL limit on a
    framebuffer's side, and its framebuffers within ``tile_bytes``); else strips no taller than
    ``strip_bytes`` of read-back pixels allow, cut into tiles that fit. ``tile`` forces at most
    that size (the tests' small tiles). Tiles are evened out so the last ones are not slivers."""
    if width < 1 or height < 1 or max_side < 1:
        raise ValueError(f"cannot tile a {width}x{height} image into sides of at most {max_side}")
    if tile is None and width <= max_side and height <= max_side and width * height * bytes_per_pixel <= tile_bytes:
        return TilePlan(width, height, width, height)
    if tile is not None:
        tw, th = max(1, min(tile[0], max_side, width)), max(1, min(tile[1], max_side, height))
    else:
        # Strips as tall as the read-back budget allows, but no taller than a square tile.
        square = math.isqrt(max(1, tile_bytes // bytes_per_pixel))
        th = max(1, min(height, max_side, strip_bytes // (width * READBACK_BYTES), square))
        tw = max(1, min(width, max_side, tile_bytes // (th * bytes_per_pixel)))
    nx, ny = -(-width // tw), -(-height // th)
    tw, th = -(-width // nx), -(-height // ny)
    if tile is None:
        # Even sides where the image's are: a pass with an odd width or height cannot shade its
        # mesh from the visibility buffer (alight.render.vbuffer.ineligible_reason), so an even
        # image cut into odd tiles would lose it in every tile. One more column or row than the
        # budget (or one fewer at the GL limit).
        tw = _even(tw, width, max_side)
        th = _even(th, height, max_side)
    return TilePlan(width, height, tw, th)


def _even(side: int, whole: int, max_side: int) -> int:
    """``side`` made even where ``whole`` is even and ``side`` cuts it."""
    if side % 2 == 0 or whole % 2 or side >= whole:
        return side
    return side + 1 if side + 1 <= max_side else side - 1


def tile_matrix(plan: TilePlan, tile: Tile) -> np.ndarray:
    """The NDC scale and offset that put ``tile`` of the image onto the bottom-left corner of a
    tile_width x tile_height framebuffer: clip-space x' = sx x + ox w (and y alike). 4x4 float64
    in pyrr's row-vector layout (``Camera.view_projection``'s): multiply it on the right."""
    gx, gy = tile.x, plan.height - tile.y - tile.height     # the tile's bottom-left, GL pixels
    sx, sy = plan.width / plan.tile_width, plan.height / plan.tile_height
    ox = (plan.width - 2.0 * gx) / plan.tile_width - 1.0
    oy = (plan.height - 2.0 * gy) / plan.tile_height - 1.0
    m = np.eye(4)
    m[0, 0], m[1, 1], m[3, 0], m[3, 1] = sx, sy, ox, oy
    return m


def tile_origin(plan: TilePlan, tile: Tile) -> tuple[int, int]:
    """The tile's bottom-left pixel in the image's GL window coordinates (origin bottom-left)."""
    return tile.x, plan.height - tile.y - tile.height


def side_limit(limits: dict, aa: str) -> int:
    """The longest framebuffer side the GL allows (GL_MAX_TEXTURE_SIZE, _RENDERBUFFER_SIZE,
    _VIEWPORT_DIMS, _FRAMEBUFFER_WIDTH/HEIGHT, where reported), in output pixels: SSAA draws 2x."""
    sides = []
    for key in ("GL_MAX_TEXTURE_SIZE", "GL_MAX_RENDERBUFFER_SIZE", "GL_MAX_VIEWPORT_DIMS",
                "GL_MAX_FRAMEBUFFER_WIDTH", "GL_MAX_FRAMEBUFFER_HEIGHT"):
        value = limits.get(key)
        if value:
            sides.extend(int(v) for v in (value if isinstance(value, (tuple, list)) else (value,)))
    side = min(sides) if sides else 4096
    return max(1, side // (2 if aa == "ssaa" else 1))

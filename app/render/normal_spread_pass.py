"""A normal map's spread written into its levels' A on the GPU (shaders/render/normal_spread.comp),
where alight.render.normal_spread is its numpy twin.

The texture arrives with every level's RGB in place (GL's generate_mipmap, or mip_levels' levels
written by the editor's staged upload) and A = 0; the pass writes A of each level from 1 on, RGB
kept. On llvmpipe, where the GPU is the same CPU cores, the upload of a 2048x2048 map takes about
half the time it took with the numpy twin's levels (benchmarks/results/normal_spread.md); on a GPU
the pass is a few short dispatches. Nothing is read back, and no 2048^2 float array is made on
the CPU.

Every call here is GL work: it runs on the thread that owns the context (the frame's upload,
or the editor's ``Renderer.upload_step``). ``SpreadWriter.write`` does one band of one level, so
a caller that must keep drawing frames splits the work (alight.render.mesh_upload).

The pass is compiled by the renderer's ShaderLibrary, as every other program: the editor's shader
reload (a new library, ``ForwardRenderer.use_shaders``) recompiles it from the saved file.
"""

from __future__ import annotations

import moderngl
import numpy as np

from alight.core.gpu import GL_RGBA8, GL_RGBA32F, ShaderLibrary, rgba32f_texture
from alight.render import normal_spread

SHADER = "render/normal_spread.comp"
GROUP = 8   # the shader's local size, in texels each way

# What one band covers at most, in texels of the level written (level 1 of a 2048^2 map is 1M):
# a quarter of it per band keeps one band near 10 ms on llvmpipe (four level-0 texels decoded each).
BAND_TEXELS = 1 << 18


def spread_defines() -> dict[str, str]:
    """The twin's constants as the shader's defines (shader_names.SHADER_OPTIONS declares them):
    one source for both languages."""
    return {"NORMAL_SPREAD_MAX": repr(float(normal_spread.MAX_SPREAD)),
            "NORMAL_SPREAD_FLOOR": repr(float(normal_spread.SPREAD_FLOOR)),
            "NORMAL_FLAT_LENGTH": repr(float(normal_spread.FLAT_LENGTH))}


def level_size(size: tuple[int, int], level: int) -> tuple[int, int]:
    """(w, h) of ``level`` of a (w, h) texture (GL's rule: halved, at least 1)."""
    return max(1, size[0] >> level), max(1, size[1] >> level)


def level_count(size: tuple[int, int]) -> int:
    """The levels of a full mip chain of a (w, h) texture (down to 1x1)."""
    return max(size).bit_length()


def spread_bands(size: tuple[int, int], levels: int, band_texels: int = BAND_TEXELS) -> list[tuple[int, int, int]]:
    """The pieces of a map's spread pass, in the order they must run (a level reads the one above's
    means): (level, first row, end row) of the level written, each at most about ``band_texels``
    texels (whole groups of rows). Level 0 (w, h) = ``size``; no GL (any thread)."""
    bands = []
    for level in range(1, levels):
        w, h = level_size(size, level)
        rows = max(GROUP, band_texels // w // GROUP * GROUP)
        bands += [(level, y, min(h, y + rows)) for y in range(0, h, rows)]
    return bands


class SpreadWriter:
    """The spread of one normal map texture's ``levels`` levels (level 0 (w, h) = ``size``, an
    RGBA8 texture with every level allocated and RGB written), measured at normalTexture.scale
    ``scale``, by the pass that ``shaders`` (the renderer's library, on ``ctx``) compiles.
    ``bands``: ``spread_bands``; ``write(i)`` runs band i, in order. The means (an RGBA32F texture
    of the levels from 1 on: 5.3 MiB for a 2048^2 map) are made by the first band and freed by
    ``release()``; ``write_all`` releases them itself. ``write`` raises ShaderCompileError where
    the pass's source does not compile."""

    def __init__(self, ctx: moderngl.Context, shaders: ShaderLibrary, tex: moderngl.Texture, size: tuple[int, int],
                 levels: int, scale: float, band_texels: int = BAND_TEXELS):
        self.ctx, self.shaders, self.tex, self.size, self.levels = ctx, shaders, tex, size, levels
        self.scale = float(scale)
        self.bands = spread_bands(size, levels, band_texels)
        self._means = None

    def allocate(self) -> None:
        """Make the means texture (``write`` does it if not done): 30-70 ms on llvmpipe for a 2048^2
        map (its 21 MiB touched), which a caller keeping frames short runs as a step of its own."""
        if self._means is None:
            self._means = rgba32f_texture(self.ctx, level_size(self.size, 1), self.levels - 1)

    def write(self, band: int) -> None:
        """Band ``band`` of ``bands``: its texels' means into the means texture, their A into the map."""
        level, y0, y1 = self.bands[band]
        # looked up per band, not kept: a library reloaded meanwhile released what it compiled
        prog = self.shaders.compute(SHADER, spread_defines())
        self.allocate()
        first = level == 1
        # the source: level 0's texels for level 1, else the level above's means
        self.tex.bind_to_image(0, read=True, write=False, level=0, format=GL_RGBA8)
        self._means.bind_to_image(1, read=True, write=False, level=0 if first else level - 2, format=GL_RGBA32F)
        self._means.bind_to_image(2, read=False, write=True, level=level - 1, format=GL_RGBA32F)
        self.tex.bind_to_image(3, read=True, write=True, level=level, format=GL_RGBA8)
        w, h = level_size(self.size, level)
        prog["u_size"].value = (w, h)
        prog["u_finer_size"].value = level_size(self.size, level - 1)
        prog["u_from_level0"].value = int(first)
        prog["u_scale"].value = self.scale
        prog["u_decode"].value = float(np.float32(2.0 / 255.0))
        prog["u_origin"].value = (0, y0)
        prog.run(-(-w // GROUP), -(-(y1 - y0) // GROUP), 1)
        # the next band may read these means, and a draw samples the map
        self.ctx.memory_barrier()

    def write_all(self) -> None:
        """Every band, then the means released."""
        for band in range(len(self.bands)):
            self.write(band)
        self.release()

    def release(self) -> None:
        if self._means is not None:
            self._means.release()
            self._means = None

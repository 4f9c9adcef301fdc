"""Equirectangular environment files (.hdr, .exr and whatever else OpenImageIO reads).

Files are read in strips of scanlines (or rows of tiles), repaired strip by strip (NaN/Inf/
negative texels set to 0) and, when wider than ``max_width``, box-reduced strip by strip, so a
huge map never sits in memory at full resolution. Every problem with a file becomes one
:class:`AlightError` line naming the file first; every repair becomes one warning line.
"""

from __future__ import annotations

import math
import os

import numpy as np

from alight.core.equirect import _box_factor, _reduce_columns, _reduce_rows
from alight.errors import AlightError

# Bytes of float32 RGB read per strip (before reduction); bounds the loader's memory.
_STRIP_BYTES = 8 * 1024 * 1024



def _one_line(msg: str) -> str:
    """Condense a (possibly multi-line) OIIO error message to one line."""
    msg = " ".join(str(msg).split())
    return msg if msg else "unknown read error"


def read_equirect(path: str, max_width: int) -> tuple[np.ndarray, list[str]]:
    """The file's radiance as an (H, W, 3) float32 array (row 0 = +Y) and the repair warnings."""
    import OpenImageIO as oiio

    if not os.path.exists(path):
        raise AlightError(f"{path}: no such file")
    if os.path.isdir(path):
        raise AlightError(f"{path}: is a directory, not an image")
    if os.path.getsize(path) == 0:
        raise AlightError(f"{path}: empty file")

    inp = oiio.ImageInput.open(path)
    if inp is None:
        raise AlightError(f"{path}: cannot read environment map ({_one_line(oiio.geterror())})")
    try:
        ispec = inp.spec()
        width, height, nch = int(ispec.width), int(ispec.height), int(ispec.nchannels)
        if width <= 0 or height <= 0 or nch <= 0:
            raise AlightError(f"{path}: empty image ({width}x{height}, {nch} channels)")
        if width != 2 * height:
            raise AlightError(f"{path}: not a 2:1 equirectangular map ({width}x{height})")
        if nch == 2:
            raise AlightError(f"{path}: 2-channel image (need 1 = grey, 3 = RGB or 4+ = RGBA)")
        nread = 1 if nch == 1 else 3

        factor = _box_factor(width, height, max_width) if width > max_width else 1
        tile_h = int(ispec.tile_height) if int(ispec.tile_width) > 0 else 0
        # Strip height: a multiple of the box factor (and of the tile height for tiled files).
        unit = factor if not tile_h else factor * tile_h // math.gcd(factor, tile_h)
        rows = max(1, _STRIP_BYTES // (width * 3 * 4) // unit) * unit

        out = np.empty((height // factor, width // factor, 3), dtype=np.float32)
        bad = 0
        for y0 in range(0, height, rows):
            y1 = min(height, y0 + rows)
            if tile_h:
                strip = inp.read_tiles(ispec.x, ispec.x + width, ispec.y + y0, ispec.y + y1,
                                       ispec.z, ispec.z + max(1, int(ispec.depth)), 0, nread, oiio.FLOAT)
            else:
                strip = inp.read_scanlines(ispec.y + y0, ispec.y + y1, ispec.z, 0, nread, oiio.FLOAT)
            err = inp.geterror()
            if strip is None or isinstance(strip, bool) or err:
                why = _one_line(err or oiio.geterror() or f"read error in rows {y0}..{y1 - 1}")
                raise AlightError(f"{path}: corrupt or truncated file ({why})")
            strip = np.asarray(strip, dtype=np.float32).reshape(y1 - y0, width, nread)
            if nread == 1:
                strip = np.repeat(strip, 3, axis=2)
            elif not strip.flags.writeable:
                strip = strip.copy()
            broken = ~np.all(np.isfinite(strip) & (strip >= 0.0), axis=2)
            n = int(np.count_nonzero(broken))
            if n:
                bad += n
                strip[broken] = 0.0
            if factor > 1:
                out[y0 // factor:y1 // factor] = _reduce_rows(_reduce_columns(strip, factor), factor, y0, height)
            else:
                out[y0:y1] = strip
    finally:
        try:
            inp.close()
        except Exception:
            pass

    warnings = []
    if bad:
        warnings.append(f"{path}: {bad} NaN/Inf/negative texels set to 0")
    if factor > 1:
        warnings.append(f"{path}: {width}x{height} is wider than {max_width}; box-reduced by {factor} "
                        f"to {width // factor}x{height // factor}")
    return np.ascontiguousarray(out, dtype=np.float32), warnings

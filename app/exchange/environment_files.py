"""Equirectangular environment files (.hdr, .exr and whatever else OpenImageIO reads).

What the file says is the picture is what is loaded:
- **orientation:** the file's stored order is turned into the picture's (OpenImageIO reports it
  as ``Orientation``, EXIF's 1-8). Radiance's eight resolution strings are defined by
  ``pix2loc`` in Radiance's ``resolu.c``; OpenImageIO 3.2 reports ``+X +Y`` as 6 and ``-X -Y``
  as 8, where that definition makes them 8 and 6, so for .hdr those two are swapped back;
- **windows:** the display window is the picture; texels outside the data window are 0, data
  outside the display window is dropped (OpenEXR);
- **parts and channels:** channels are chosen by name: R, G, B (else a layer's ``name.R/G/B``),
  or Y (grey, alpha ignored). A multi-part file gives its first part that has them, and one
  warning says which; a file with none is refused, naming its parts and channels.

Files are read in strips of scanlines (or rows of tiles), repaired strip by strip (NaN/Inf/
negative texels set to 0, texels above ``RADIANCE_MAX`` clamped to it) and, when wider than
``max_width``, box-reduced strip by strip, so a huge map never sits in memory at full
resolution. Every problem with a file becomes one ``AlightError`` line naming the file
first; every repair becomes one warning line.
"""

from __future__ import annotations

import math
import os
from dataclasses import dataclass

import numpy as np

from alight.core.equirect import _reduce_columns, _reduce_rows, area_resample
from alight.errors import AlightError

# Bytes of float32 read per strip (before reduction); bounds the loader's memory.
_STRIP_BYTES = 8 * 1024 * 1024

# The largest radiance kept: above every map in ../shared/data/env (the brightest,
# pedestrian_overpass_1k, peaks at 118,272) and above the sun's luminance in cd/m2 (1.6e9), so
# no real capture is changed; 28 orders of magnitude below float32's limit, so the bake's sums,
# the shading's products (x --env-intensity, x 2^exposure) and the tone map stay finite. A
# texel of 1e30 (a broken file) used to make the PNG black.
RADIANCE_MAX = 1.0e10

# EXIF orientation -> (transpose, flip rows, flip columns) of the stored image, in that order,
# to get the picture (TIFF 6.0's Orientation tag).
_ORIENTATIONS = {
    1: (False, False, False), 2: (False, False, True), 3: (False, True, True), 4: (False, True, False),
    5: (True, False, False), 6: (True, False, True), 7: (True, True, True), 8: (True, True, False),
}
# Radiance's pix2loc: "+X +Y" stores columns left to right, each bottom to top (EXIF 8);
# "-X -Y" columns right to left, each top to bottom (EXIF 6). OpenImageIO 3.2 reports 6 and 8.
_RADIANCE_FIX = {6: 8, 8: 6}


def _one_line(msg: str) -> str:
    """Condense a (possibly multi-line) OIIO error message to one line."""
    msg = " ".join(str(msg).split())
    return msg if msg else "unknown read error"


@dataclass(frozen=True)
class _Part:
    """The subimage to read and which of its channels: 3 (R, G, B) or 1 (Y)."""

    index: int
    channels: tuple[int, ...]
    describe: str          # e.g. "part 1 'beauty' (R, G, B)"


def _part_label(index: int, spec) -> str:
    name = spec.getattribute("name") or spec.getattribute("oiio:subimagename")
    return f"part {index}" + (f" '{name}'" if name else "")


def _rgb_or_grey(names: list[str]) -> tuple[tuple[int, ...], str] | None:
    """Indices of R, G, B (plain, else the first layer that has all three) or of Y; and their names."""
    if all(c in names for c in "RGB"):
        return tuple(names.index(c) for c in "RGB"), "R, G, B"
    for name in names:
        layer, dot, last = name.rpartition(".")
        if dot and last == "R" and all(f"{layer}.{c}" in names for c in "GB"):
            chosen = [f"{layer}.{c}" for c in "RGB"]
            return tuple(names.index(c) for c in chosen), ", ".join(chosen)
    if "Y" in names:
        return (names.index("Y"),), "Y"
    return None


def _choose_part(inp, path: str) -> tuple[_Part, list[str]]:
    """The first part with R, G, B; else the first with Y; else AlightError naming every part."""
    parts = []
    index = 0
    while inp.seek_subimage(index, 0):
        spec = inp.spec()
        parts.append((index, spec, list(spec.channelnames)))
        index += 1
    inp.geterror()      # seeking past the last part left an error behind: clear it
    if not parts:
        raise AlightError(f"{path}: no image in the file")
    found = None
    for want_rgb in (True, False):
        for index, spec, names in parts:
            pick = _rgb_or_grey(names)
            if pick is not None and (len(pick[0]) == 3) == want_rgb:
                found = (index, spec, pick)
                break
        if found:
            break
    if found is None:
        listing = "; ".join(f"{_part_label(i, s)}: {', '.join(n) or 'no channels'}" for i, s, n in parts)
        if len(parts) == 1:
            raise AlightError(f"{path}: channels {', '.join(parts[0][2]) or 'none'}: "
                              "need R, G and B, or Y (grey)")
        raise AlightError(f"{path}: no part has R, G and B, or Y (grey) channels ({listing})")
    index, spec, (channels, chosen) = found
    part = _Part(index, channels, f"{_part_label(index, spec)} ({chosen})")
    warnings = []
    if len(parts) > 1:
        others = "; ".join(f"{_part_label(i, s)} ({', '.join(n)})" for i, s, n in parts if i != index)
        warnings.append(f"{path}: {len(parts)}-part file: took {part.describe}, left out {others}")
    elif chosen not in ("R, G, B", "Y"):
        warnings.append(f"{path}: no plain R, G, B channels: took the layer {chosen}")
    if len(channels) == 1 and any(c in spec.channelnames for c in ("RY", "BY")):
        warnings.append(f"{path}: luminance/chroma (Y, RY, BY) file: loaded as grey from Y")
    return part, warnings


@dataclass(frozen=True)
class _Layout:
    """Where the picture lies in the stored image (OpenImageIO's coordinates)."""

    data: tuple[int, int, int, int]      # data window x, y, width, height
    display: tuple[int, int, int, int]   # display window x, y, width, height (the picture, before orienting)
    transpose: bool
    flip_rows: bool
    flip_cols: bool

    @property
    def size(self) -> tuple[int, int]:
        """The picture's (width, height) after orienting."""
        w, h = self.display[2], self.display[3]
        return (h, w) if self.transpose else (w, h)


def _layout(inp, spec) -> _Layout:
    data = (int(spec.x), int(spec.y), int(spec.width), int(spec.height))
    display = (int(spec.full_x), int(spec.full_y), int(spec.full_width), int(spec.full_height))
    if display[2] <= 0 or display[3] <= 0:   # a format without a display window
        display = data
    orientation = int(spec.get_int_attribute("Orientation", 1))
    if inp.format_name() == "hdr":
        orientation = _RADIANCE_FIX.get(orientation, orientation)
    transpose, flip_rows, flip_cols = _ORIENTATIONS.get(orientation, _ORIENTATIONS[1])
    return _Layout(data, display, transpose, flip_rows, flip_cols)


def _read_rows(inp, path: str, part: _Part, spec, layout: _Layout, r0: int, r1: int) -> np.ndarray:
    """Rows r0..r1-1 of the display window (stored order) as (r1 - r0, display width, nch) float32:
    0 where the data window does not reach."""
    dx, dy, dw, dh = layout.data
    fx, fy, fw, _ = layout.display
    ch0, ch1 = min(part.channels), max(part.channels) + 1
    a0, a1 = max(fy + r0, dy), min(fy + r1, dy + dh)        # stored rows with data
    c0, c1 = max(fx, dx), min(fx + fw, dx + dw)              # stored columns with data and shown
    if a0 >= a1 or c0 >= c1:
        return np.zeros((r1 - r0, fw, len(part.channels)), np.float32)
    tile_w, tile_h = int(spec.tile_width), int(spec.tile_height)
    if tile_w > 0:
        # Tiles are read whole: widen the rows to tile boundaries (counted from the data window).
        t0 = dy + (a0 - dy) // tile_h * tile_h
        t1 = min(dy + dh, dy + -(-(a1 - dy) // tile_h) * tile_h)
        block = inp.read_tiles(part.index, 0, dx, dx + dw, t0, t1, int(spec.z),
                               int(spec.z) + max(1, int(spec.depth)), ch0, ch1, _float())
        shape = (t1 - t0, dw, ch1 - ch0)
    else:
        t0 = a0
        block = inp.read_scanlines(part.index, 0, a0, a1, int(spec.z), ch0, ch1, _float())
        shape = (a1 - a0, dw, ch1 - ch0)
    err = inp.geterror()
    if block is None or isinstance(block, bool) or err:
        import OpenImageIO as oiio

        why = _one_line(err or oiio.geterror() or f"read error in rows {a0}..{a1 - 1}")
        raise AlightError(f"{path}: corrupt or truncated file ({why})")
    block = np.asarray(block, dtype=np.float32).reshape(shape)
    picked = [c - ch0 for c in part.channels]
    if (a0, a1, t0, c0, c1) == (fy + r0, fy + r1, a0, dx, dx + dw) and picked == list(range(len(picked))):
        return block        # the usual file: rows and channels as read, nothing to place
    out = np.zeros((r1 - r0, fw, len(part.channels)), np.float32)
    out[a0 - fy - r0:a1 - fy - r0, c0 - fx:c1 - fx] = block[a0 - t0:a1 - t0, c0 - dx:c1 - dx][..., picked]
    return out


def _float():
    import OpenImageIO as oiio

    return oiio.FLOAT


@dataclass
class Repairs:
    broken: int = 0        # NaN/Inf/negative texels set to 0
    clamped: int = 0       # finite texels above RADIANCE_MAX
    peak: float = 0.0      # the largest finite value seen among the clamped ones

    def lines(self, name: str) -> list[str]:
        out = []
        if self.broken:
            out.append(f"{name}: {self.broken} NaN/Inf/negative texels set to 0")
        if self.clamped:
            out.append(f"{name}: {self.clamped} texel{'s' if self.clamped > 1 else ''} above {RADIANCE_MAX:g} "
                       f"clamped to {RADIANCE_MAX:g} (the brightest was {self.peak:.3g})")
        return out


def repair_radiance(rgb: np.ndarray, repairs: Repairs) -> np.ndarray:
    """Set NaN/Inf/negative texels of an (..., 3) float32 array to 0 and clamp the rest to
    RADIANCE_MAX, in place where the array is writable; counts go to ``repairs``."""
    lo, hi = rgb.min(initial=0.0), rgb.max(initial=0.0)     # NaN makes both NaN: not taken below
    if lo >= 0.0 and hi <= RADIANCE_MAX:
        return rgb          # the usual strip: two fast reductions, nothing to repair
    broken = ~np.all(np.isfinite(rgb) & (rgb >= 0.0), axis=-1)
    hot = np.any(rgb > RADIANCE_MAX, axis=-1) & ~broken     # NaN compares False; Inf is broken
    n_broken, n_hot = int(np.count_nonzero(broken)), int(np.count_nonzero(hot))
    if not (n_broken or n_hot):
        return rgb
    if not rgb.flags.writeable:
        rgb = rgb.copy()
    if n_hot:
        repairs.clamped += n_hot
        repairs.peak = max(repairs.peak, float(rgb[hot].max()))
        rgb[hot] = np.minimum(rgb[hot], RADIANCE_MAX)
    if n_broken:
        repairs.broken += n_broken
        rgb[broken] = 0.0
    return rgb


def may_be_equirect(path: str) -> bool:
    """Whether a file browser should offer ``path`` as an environment: an 8-bit picture
    (.png, .jpg, ...) only where its header says 2:1, as ``read_equirect`` requires (a user's
    1280x720 screenshots were listed beside the skies, each refused when picked); .hdr, .exr and
    the rest are offered (their headers are left to the reader)."""
    from alight.exchange.images import IMAGE_SUFFIXES

    suffix = os.path.splitext(str(path))[1].lower()
    if suffix not in IMAGE_SUFFIXES or suffix in (".hdr", ".exr"):
        return True
    try:
        from PIL import Image

        with Image.open(path) as image:   # (the header only: no pixels decoded)
            width, height = image.size
    except Exception:   # unreadable by PIL: the reader may still take it (OpenImageIO)
        return True
    return width == 2 * height


def read_equirect(path: str, max_width: int) -> tuple[np.ndarray, list[str]]:
    """The file's radiance as an (H, W, 3) float32 array (row 0 = +Y) and the warnings (repairs,
    the part chosen). See the module docstring for what is read and how."""
    import OpenImageIO as oiio

    if not os.path.exists(path):
        raise AlightError(f"{path}: no such file")
    if os.path.isdir(path):
        raise AlightError(f"{path}: is a directory, not an image")
    if os.path.getsize(path) == 0:
        raise AlightError(f"{path}: empty file")

    inp = oiio.ImageInput.open(path)
    if inp is None:
        error = _one_line(oiio.geterror())
        if "format reader" in error:     # (OpenImageIO's words for a kind of file it has no reader for)
            raise AlightError(f"{path}: not an image alight reads as an environment (use an equirectangular "
                              ".hdr or .exr; .png, .jpg and other images OpenImageIO reads are taken as "
                              "display-referred)")
        raise AlightError(f"{path}: cannot read environment map ({error})")
    try:
        part, warnings = _choose_part(inp, path)
        inp.seek_subimage(part.index, 0)
        spec = inp.spec()
        layout = _layout(inp, spec)
        width, height = layout.size
        if width <= 0 or height <= 0:
            raise AlightError(f"{path}: empty image ({width}x{height})")
        if width != 2 * height:
            raise AlightError(f"{path}: not a 2:1 equirectangular map ({width}x{height})")

        factor, out_w = _reduction(width, height, max_width)
        out_h = out_w // 2
        stored_w, stored_h = layout.display[2], layout.display[3]
        tile_h = int(spec.tile_height) if int(spec.tile_width) > 0 else 0
        # Strip height: a multiple of the box factor (and of the tile height for tiled files).
        step = max(factor, 1)    # a resampled map (factor 0) takes strips of any height
        unit = step if not tile_h else step * tile_h // math.gcd(step, tile_h)
        nread = max(part.channels) - min(part.channels) + 1
        rows = max(1, _STRIP_BYTES // (max(stored_w, layout.data[2]) * nread * 4) // unit) * unit

        # A resampled map is summed into (each output texel gets parts of several strips).
        out = (np.empty if factor else np.zeros)((out_h, out_w, 3), dtype=np.float32)
        repairs = Repairs()
        decode = _display_referred(inp, spec)
        for r0 in range(0, stored_h, rows):
            r1 = min(stored_h, r0 + rows)
            strip = _read_rows(inp, path, part, spec, layout, r0, r1)
            if strip.shape[2] == 1:
                strip = np.repeat(strip, 3, axis=2)
            if decode:
                strip = _srgb_decode(strip)
            strip = repair_radiance(strip, repairs)
            _place(out, strip, r0, r1, layout, factor, height, width)
    finally:
        try:
            inp.close()
        except Exception:
            pass

    if decode:
        article = "an" if decode.startswith("8") else "a"
        warnings.insert(0, f"{path}: {article} {decode} is display-referred (sRGB, clipped at 1): decoded from "
                           f"sRGB to linear, but its bright sources are clipped, so the lighting is dimmer "
                           f"and flatter than the scene's; an .hdr or .exr keeps the radiance")
    warnings += repairs.lines(path)
    if factor > 1:
        warnings.append(f"{path}: {width}x{height} is wider than {max_width}; box-reduced by {factor} "
                        f"to {width // factor}x{height // factor}")
    elif factor == 0:
        warnings.append(f"{path}: {width}x{height} is wider than {max_width}; area-resampled to {out_w}x{out_h}")
    return np.ascontiguousarray(out, dtype=np.float32), warnings


def _reduction(width: int, height: int, max_width: int) -> tuple[int, int]:
    """(box factor, output width) for a map ``width`` wide: factor 1 when it fits; the whole
    factor ceil(width / max_width) when it divides the height (an exact box); else factor 0:
    area-resampled to ``max_width`` (an awkward height, e.g. a prime 4099, has no whole factor
    near the ratio, and the smallest one that divides could be the height itself)."""
    if width <= max_width:
        return 1, width
    factor = -(-width // max_width)
    if height % factor == 0:
        return factor, width // factor
    return 0, max_width // 2 * 2


# OpenImageIO's names of the formats whose pixels are display-referred 8/16-bit sRGB.
_DISPLAY_FORMATS = {"png": "PNG", "jpeg": "JPEG", "bmp": "BMP", "targa": "TGA", "gif": "GIF", "webp": "WebP"}


def _display_referred(inp, spec) -> str:
    """The format's name when the file holds display-referred integer sRGB (PNG, JPEG, ...: what
    a photo or a screenshot is), to be decoded; '' for scene-referred files (.hdr, .exr, float
    TIFF) and for integer files that say they are linear."""
    import OpenImageIO as oiio

    name = inp.format_name()
    space = str(spec.getattribute("oiio:ColorSpace") or "").lower()
    # OpenImageIO 3 names an 8-bit PNG's space "srgb_rec709_scene" and linear ones "lin_..." or
    # "linear"; only a file that says it is linear is taken as it is.
    if space.startswith("lin") or "linear" in space:
        return ""
    if name in _DISPLAY_FORMATS:
        bits = 16 if spec.format in (oiio.UINT16, oiio.INT16) else 8
        return f"{bits}-bit {_DISPLAY_FORMATS[name]}"
    return ""


def _srgb_decode(strip: np.ndarray) -> np.ndarray:
    """IEC 61966-2-1's sRGB decode of values read as 0..1 (OpenImageIO scales 8- and 16-bit
    integers to 0..1 and leaves the transfer function to us)."""
    from alight.core.shading import srgb_to_linear

    return np.asarray(srgb_to_linear(np.clip(strip, 0.0, 1.0)), dtype=np.float32)


def _place(out: np.ndarray, strip: np.ndarray, r0: int, r1: int, layout: _Layout, factor: int,
           height: int, width: int) -> None:
    """Put stored rows r0..r1-1 where the picture has them (rows, or columns if transposed),
    box-reduced by ``factor``, or (factor 0) area-resampled to ``out``'s size and added in."""
    if factor == 0:
        _resample_into(out, strip, r0, r1, layout, height, width)
        return
    if layout.transpose:
        block = strip.transpose(1, 0, 2)                  # stored rows become picture columns
        if layout.flip_rows:
            block = block[::-1]
        c0, c1 = (width - r1, width - r0) if layout.flip_cols else (r0, r1)
        if layout.flip_cols:
            block = block[:, ::-1]
        if factor > 1:
            block = _reduce_rows(_reduce_columns(block, factor), factor, 0, height)
        out[:, c0 // factor:c1 // factor] = block
        return
    block = strip[::-1] if layout.flip_rows else strip
    if layout.flip_cols:
        block = block[:, ::-1]
    y0, y1 = (height - r1, height - r0) if layout.flip_rows else (r0, r1)
    if factor > 1:
        block = _reduce_rows(_reduce_columns(block, factor), factor, y0, height)
    out[y0 // factor:y1 // factor] = block


def _resample_into(out: np.ndarray, strip: np.ndarray, r0: int, r1: int, layout: _Layout,
                   height: int, width: int) -> None:
    """Stored rows r0..r1-1, oriented, area-resampled (alight.core.equirect.area_resample) and
    added to ``out`` (out_h, out_w, 3): the axis the strip holds whole is resampled in full, the
    other gives the strip's share of the output texels it overlaps."""
    out_h, out_w = out.shape[:2]
    if layout.transpose:
        block = strip.transpose(1, 0, 2)                  # all picture rows, columns c0..c1-1
        if layout.flip_rows:
            block = block[::-1]
        c0 = width - r1 if layout.flip_cols else r0
        if layout.flip_cols:
            block = block[:, ::-1]
        _, rows = area_resample(block, 0, height, out_h, 0, True)
        o0, share = area_resample(rows, c0, width, out_w, 1, False)
        out[:, o0:o0 + share.shape[1]] += share.astype(np.float32)
        return
    block = strip[::-1] if layout.flip_rows else strip
    if layout.flip_cols:
        block = block[:, ::-1]
    y0 = height - r1 if layout.flip_rows else r0
    _, cols = area_resample(block, 0, width, out_w, 1, False)
    o0, share = area_resample(cols, y0, height, out_h, 0, True)
    out[o0:o0 + share.shape[0]] += share.astype(np.float32)

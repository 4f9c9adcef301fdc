"""Image files for texture maps, read with OpenImageIO into 8-bit RGBA arrays.

Decoded images are cached by (path, modification time, size), so reloading an unchanged file is
free. Every failure is one ``AlightError`` line naming the file.
"""

from __future__ import annotations

import collections
import os

import numpy as np

from alight.errors import AlightError

# What a dropped file with one of these suffixes is (.hdr and .exr stay environments).
IMAGE_SUFFIXES = (".png", ".jpg", ".jpeg", ".tga", ".tif", ".tiff", ".bmp", ".webp")
# The largest texture side: OpenGL 4.1 and later guarantee GL_MAX_TEXTURE_SIZE >= 16384 (llvmpipe
# and current GPUs give 16384 or more), so every image up to it uploads; a valid 9000x4 strip was
# refused at 8192.
MAX_MAP_SIZE = 16384


# Decoded images by (absolute path, modification time, size): reloading an unchanged file is free.
_CACHE: collections.OrderedDict[tuple, np.ndarray] = collections.OrderedDict()
_CACHE_ENTRIES = 16


def load_map_image(path: str) -> np.ndarray:
    """An image file as (H, W, 4) uint8, row 0 = top (as alight.core.mesh gives file textures): grey is
    spread to RGB, a missing alpha is 255, 16-bit and float files are rescaled to 8 bits.
    Any failure is an AlightError of one line naming the file."""
    if not os.path.exists(path):
        raise AlightError(f"{path}: no such file")
    if os.path.isdir(path):
        raise AlightError(f"{path}: is a directory, not an image")
    stat = os.stat(path)
    if stat.st_size == 0:
        raise AlightError(f"{path}: empty file")
    key = (os.path.abspath(path), stat.st_mtime_ns, stat.st_size)
    if key in _CACHE:
        _CACHE.move_to_end(key)
        return _CACHE[key]
    try:
        image = _read(path)
    except AlightError:
        raise
    except MemoryError:
        raise AlightError(f"{path}: not enough memory to read the texture map") from None
    except Exception as exc:   # anything OIIO or numpy throws: one line, no traceback
        raise AlightError(f"{path}: cannot read texture map ({_one_line(exc)})") from None
    image.setflags(write=False)
    _CACHE[key] = image
    while len(_CACHE) > _CACHE_ENTRIES:
        _CACHE.popitem(last=False)
    return image


def _read(path: str) -> np.ndarray:
    import OpenImageIO as oiio

    # The stored values, alpha straight as PNG keeps it (PNG specification 12.8): OpenImageIO
    # would otherwise premultiply colour by alpha as it reads.
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    inp = oiio.ImageInput.open(path, config)
    if inp is None:
        raise AlightError(f"{path}: cannot read texture map ({_one_line(oiio.geterror()) or 'unknown format'})")
    try:
        spec = inp.spec()
        w, h, c = int(spec.width), int(spec.height), int(spec.nchannels)
        if w <= 0 or h <= 0 or c <= 0:
            raise AlightError(f"{path}: empty image ({w}x{h}, {c} channels)")
        if max(w, h) > MAX_MAP_SIZE:
            raise AlightError(f"{path}: {w}x{h} is larger than {MAX_MAP_SIZE} pixels a side")
        pixels = inp.read_image(0, 0, 0, min(c, 4), oiio.UINT8)
        err = inp.geterror()
        if pixels is None or isinstance(pixels, bool) or err:
            raise AlightError(f"{path}: corrupt or truncated image ({_one_line(err or oiio.geterror()) or 'read failed'})")
    finally:
        inp.close()
    pixels = np.asarray(pixels, dtype=np.uint8).reshape(h, w, min(c, 4))
    if pixels.shape[2] in (1, 2):     # grey (and alpha)
        grey = np.repeat(pixels[:, :, :1], 3, axis=2)
        alpha = pixels[:, :, 1:2] if pixels.shape[2] == 2 else np.full((h, w, 1), 255, np.uint8)
        pixels = np.concatenate([grey, alpha], axis=2)
    elif pixels.shape[2] == 3:
        pixels = np.concatenate([pixels, np.full((h, w, 1), 255, np.uint8)], axis=2)
    return np.ascontiguousarray(pixels)


def _one_line(text) -> str:
    return " ".join(str(text or "").split())


def decode_texture(data: bytes, where: str) -> np.ndarray:
    """Encoded image bytes (PNG, JPEG, WebP, ...; a glTF image) as (H, W, 4) uint8 RGBA, row 0 =
    top, decoded with Pillow (which reads from memory, as GLB and data: images need).

    The stored values are kept: PNG gAMA and iCCP chunks and JPEG ICC profiles are ignored, as
    glTF 2.0 (section 3.8.2) requires; 16-bit channels are rounded to 8 bits (Pillow reduces
    16-bit colour PNGs itself and keeps 16-bit grey, which is rescaled here); grey is spread to
    RGB; a missing alpha is 255. ``where`` names the file and element in a failure's one line.
    """
    import io

    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(io.BytesIO(data)) as img:
            img.load()
            w, h = img.size
            if max(w, h) > MAX_MAP_SIZE:
                raise AlightError(f"{where}: {w}x{h} is larger than {MAX_MAP_SIZE} pixels a side")
            if img.mode in ("I;16", "I;16B", "I;16L", "I"):
                wide = np.asarray(img, dtype=np.uint32 if img.mode == "I" else np.uint16).astype(np.float64)
                peak = 65535.0
                grey = np.clip(np.rint(wide * (255.0 / peak)), 0, 255).astype(np.uint8)
                return np.ascontiguousarray(np.dstack([grey, grey, grey, np.full_like(grey, 255)]))
            if img.mode == "F":
                grey = np.clip(np.rint(np.asarray(img, np.float64) * 255.0), 0, 255).astype(np.uint8)
                return np.ascontiguousarray(np.dstack([grey, grey, grey, np.full_like(grey, 255)]))
            rgba = img if img.mode == "RGBA" else img.convert("RGBA")
            return np.ascontiguousarray(np.asarray(rgba, dtype=np.uint8))
    except AlightError:
        raise
    except (UnidentifiedImageError, OSError, ValueError, SyntaxError) as exc:
        raise AlightError(f"{where}: cannot decode the image ({_one_line(exc) or type(exc).__name__})") from None
    except MemoryError:
        raise AlightError(f"{where}: not enough memory to decode the image") from None

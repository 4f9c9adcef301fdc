"""GL's generate_mipmap of an RGBA8 texture, on the CPU and bit for bit as llvmpipe makes it:
the levels alight.render.mesh_upload writes in steps (the editor), and a normal map's RGB
beside its spread (alight.render.normal_spread)."""

from __future__ import annotations

import numpy as np


def _srgb_to_linear_table() -> np.ndarray:
    c = np.arange(256, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4).astype(np.float32)


SRGB_TO_LINEAR = _srgb_to_linear_table()


def _encode_srgb(linear: np.ndarray) -> np.ndarray:
    x = np.clip(linear, 0.0, 1.0)
    return np.rint(np.where(x <= 0.0031308, x * 12.92, 1.055 * np.power(x, 1.0 / 2.4) - 0.055) * 255.0)


def _halve_unorm(level: np.ndarray) -> np.ndarray:
    """A 2x2 box of uint8 values as llvmpipe's generate_mipmap gives it (checked bit for bit on
    random images): rounded half-sums, (a + b + 1) >> 1, along each row first, then of the rows."""
    v = level.astype(np.uint16)
    across = (v[:, 0::2] + v[:, 1::2] + 1) >> 1
    return ((across[0::2] + across[1::2] + 1) >> 1).astype(np.uint8)


def _halve_srgb(level: np.ndarray) -> np.ndarray:
    """The colour averaged as linear light (GL's rule for sRGB textures), alpha as unorm.
    llvmpipe's own sRGB encoding is an approximation: this lands within 1 of it per level."""
    out = _halve_unorm(level)
    linear = SRGB_TO_LINEAR[level[..., :3]]
    mean = 0.25 * (linear[0::2, 0::2] + linear[0::2, 1::2] + linear[1::2, 0::2] + linear[1::2, 1::2])
    out[..., :3] = _encode_srgb(mean).astype(np.uint8)
    return out


def mip_levels(image: np.ndarray, srgb: bool, mipmaps: bool = True) -> list[np.ndarray] | None:
    """``image`` (rows top first, RGB or RGBA uint8) as the texture's levels, level 0 first, each
    (h, w, 4) uint8 bottom row first, as ``upload_image`` writes it. Each level from the one
    before, as GL does. None where a side is not a power of two (GL's halving of an odd side is
    not a 2x2 box: such a texture is uploaded by ``upload_image`` instead)."""
    image = np.asarray(image, dtype=np.uint8)
    if image.shape[2] == 3:
        image = np.concatenate([image, np.full(image.shape[:2] + (1,), 255, np.uint8)], axis=2)
    level = np.ascontiguousarray(image[::-1, :, :4])
    h, w = level.shape[:2]
    if not mipmaps:
        return [level]
    if h & (h - 1) or w & (w - 1):
        return None
    levels = [level]
    halve = _halve_srgb if srgb else _halve_unorm
    while level.shape[0] > 1 or level.shape[1] > 1:
        if level.shape[0] == 1:   # one row left: pairs along it (the row repeated as its pair)
            level = np.concatenate([level, level], axis=0)
        if level.shape[1] == 1:
            level = np.concatenate([level, level], axis=1)
        level = np.ascontiguousarray(halve(level))
        levels.append(level)
    return levels

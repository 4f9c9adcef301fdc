"""A normal map's mip levels with the spread of its normals in A (mesh_material.glsl's
NORMAL_MAP_TOKSVIG).

A mip texel of a normal map is the average of the level-0 normals under it; the renderer shades
at that average, renormalised, and so loses how much the normals under the pixel disagreed. Where
they disagree the texel's mean unit normal is shorter than 1: Toksvig (2005, "Mipmapping Normal
Maps") reads a spread from its length |Na|, sigma^2 = (1 - |Na|) / |Na|, which the shader adds to
GGX's alpha^2 (``shading.normal_map_roughness``, its twin).

The length is measured when the map is uploaded, not from the filtered texel in the shader: a texel
of an 8-bit map decoded as 2c - 1 is not of length 1 (up to about 0.004 off), and that alone
would give alpha^2 = 0.004 (roughness 0.25) to a perfect mirror. So each level's |Na| is the mean
of the level-0 normals *renormalised* (after glTF's normalTexture.scale, which scales x and y
before normalising) over the texel's footprint: exactly 1 at level 0 and wherever the normals
under a texel agree. The result goes in the level's A channel, which glTF's normal texture does
not use, as the widening's own perceptual roughness, A = (sigma^2)^(1/4) (its alpha is A^2):
8 bits of a roughness keep the small spreads of near-mirrors (the least kept, A = 8/255, is
sigma^2 = 1e-6; 8 bits of sigma^2 itself would start at roughness 0.25). RGB are the levels as GL's
generate_mipmap makes them (alight.render.mip_levels, bit for bit), so the filtered
normal is the one the renderer read before. Trilinear and anisotropic filtering then blend A
between texels and levels like any channel (an estimate: the spread *between* the blended
texels is not in it).

The uploads make A on the GPU (alight.render.normal_spread_pass, render/normal_spread.comp: no
2048^2 float array on the CPU, nothing read back); the functions here are its numpy twin, each
step the same float32 operation in the same order, which the tests compare level by level.
"""

from __future__ import annotations

import numpy as np

from alight.render.mip_levels import mip_levels

# The largest sigma^2 kept (|Na| = 0.5): A = 1.
MAX_SPREAD = 1.0
# sigma^2 below this reads as 0: float32's rounding of a unit normal (6e-8 off its length) would
# otherwise give agreeing normals A = 4 (alpha^2 6e-8: nothing to see, but not exactly a mirror).
# Above it A >= 8 (roughness 0.03).
SPREAD_FLOOR = 1e-6
# A decoded normal this short reads as the unperturbed (0, 0, 1), and |Na| is clipped to it (a mean
# of opposite normals: sigma^2 at its MAX_SPREAD, never a division by 0).
FLAT_LENGTH = 1e-6
# The quality choice, as Filament names its own: False uploads normal maps as before (GL's mips,
# the file's A) and compiles NORMAL_MAP_TOKSVIG nowhere: the old shading, for measurements
# (bench_helmet_split.py --no-toksvig, the tests). Set it before a mesh is uploaded.
NORMAL_MAP_TOKSVIG = True
# The normal maps' level-of-detail bias (log2; mesh_material.glsl normal_from_map, compiled in
# as NORMAL_MAP_LOD_BIAS where a part has one; 0: none): one level finer, so the fetch's
# trilinear kernel spans about the pixel's box rather than twice it. DamagedHelmet against the
# path tracer (results/helmet_split.md): -1 took 20.2% to 17.7% binned at 128 px, 15.3% to 14.3%
# at 256 px, and the per-pixel error 32.6% to 30.2%; -0.75 to -1.5 read within a point of it.
# Under a moving camera (results/normal_lod_shimmer.md) it adds no flicker on the visor and a
# few percent of displayed flicker on the rest, against bias 0's own (about 2x a supersampled truth's).
NORMAL_MAP_LOD_BIAS = -1.0
# The maps whose spread widens a roughness: the base normal map (the base, anisotropy and
# transmission lobes) and the coat's own.
SPREAD_MAPS = ("normal", "clearcoat_normal")


def spread_scale(name: str, file_material) -> float | None:
    """The normalTexture.scale a map's spread is measured at (``file_material``: the part's
    FileMaterial, None for the user's maps: scale 1), or None where the map carries none (not a
    normal map, or NORMAL_MAP_TOKSVIG off)."""
    if not NORMAL_MAP_TOKSVIG or name not in SPREAD_MAPS:
        return None
    if file_material is None:
        return 1.0
    return float(file_material.normal_scale if name == "normal" else file_material.clearcoat_normal_scale)


def unit_normals(level0: np.ndarray, scale: float) -> np.ndarray:
    """(h, w, 3) float32 unit tangent-space normals of an (h, w, >=3) uint8 normal map, decoded as
    mesh_material.glsl's normal_from_map does (2c - 1, x and y times ``scale``, normalised; a zero
    vector reads as the unperturbed normal (0, 0, 1))."""
    m = level0[..., :3].astype(np.float32) * np.float32(2.0 / 255.0) - np.float32(1.0)
    m[..., :2] *= np.float32(scale)
    length = np.sqrt(np.einsum("ijk,ijk->ij", m, m))
    flat = length <= FLAT_LENGTH
    m /= np.where(flat, 1.0, length)[..., None]
    m[flat] = (0.0, 0.0, 1.0)
    return m


def spread_to_alpha_channel(mean_length: np.ndarray) -> np.ndarray:
    """A as uint8 from |Na|: round(255 * min((1 - |Na|) / |Na|, MAX_SPREAD)^(1/4)); 0 at |Na| = 1
    (and where sigma^2 < SPREAD_FLOOR)."""
    length = np.clip(mean_length, FLAT_LENGTH, 1.0)
    spread = np.minimum((1.0 - length) / length, MAX_SPREAD)
    spread[spread < SPREAD_FLOOR] = 0.0
    return np.rint(255.0 * np.sqrt(np.sqrt(spread))).astype(np.uint8)


def _halve_mean(m: np.ndarray) -> np.ndarray:
    """A 2x2 box of mean vectors (a side of 1 is paired with itself, as mip_levels pairs it)."""
    if m.shape[0] == 1:
        m = np.concatenate([m, m], axis=0)
    if m.shape[1] == 1:
        m = np.concatenate([m, m], axis=1)
    return np.float32(0.25) * (m[0::2, 0::2] + m[0::2, 1::2] + m[1::2, 0::2] + m[1::2, 1::2])


def normal_map_levels(image: np.ndarray, scale: float, mipmaps: bool = True) -> list[np.ndarray] | None:
    """``image`` (a normal map, rows top first, RGB or RGBA uint8) as its texture's levels, level 0
    first, each (h, w, 4) uint8 bottom row first (as mip_levels gives them) with A the
    encoded spread: 0 on level 0. None where a side is not a power of two (mip_levels' rule)."""
    levels = mip_levels(image, False, mipmaps)
    if levels is None:
        return None
    levels[0][..., 3] = 0
    if len(levels) == 1:
        return levels
    # level 1's means from level 0 in bands of rows: float32 vectors of one band at a time
    # (BAND_ROWS x 2048 x 12 bytes, not 48 MiB for a 2048^2 map)
    level0 = levels[0]
    if level0.shape[0] == 1:
        level0 = np.concatenate([level0, level0], axis=0)
    mean = np.concatenate([_halve_mean(unit_normals(level0[y:y + BAND_ROWS], scale))
                           for y in range(0, len(level0), BAND_ROWS)])
    for n, level in enumerate(levels[1:]):
        if n:
            mean = _halve_mean(mean)
        level[..., 3] = spread_to_alpha_channel(np.sqrt(np.einsum("ijk,ijk->ij", mean, mean)))
    return levels


BAND_ROWS = 128   # even


def without_spread(image: np.ndarray) -> np.ndarray:
    """``image`` as RGBA with A = 0 (no widening at any level: GL's mips of a constant A keep it),
    for a normal map uploaded by generate_mipmap (a side not a power of two)."""
    image = np.asarray(image, dtype=np.uint8)
    out = np.zeros(image.shape[:2] + (4,), np.uint8)
    out[..., :3] = image[..., :3]
    return out

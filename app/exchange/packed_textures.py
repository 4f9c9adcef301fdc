"""KHR_materials_diffuse_transmission's two textures as the one texture alight samples.

The extension reads the strength from ``diffuseTransmissionTexture``'s A (linear) and the colour
from ``diffuseTransmissionColorTexture``'s RGB (sRGB). alight samples both from one texture, RGB
the colour and A the strength (uploaded as GL_SRGB8_ALPHA8, which decodes RGB and leaves A
linear), so the layer costs one sampler unit: with every layer and map compiled in, the forward
shader otherwise needs 33 of the 32 a fragment shader may have on llvmpipe.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np

from alight.core.mesh import TextureInfo


def _resized(image: np.ndarray, size: tuple[int, int]) -> np.ndarray:
    """(H, W, 4) uint8 resampled to ``size`` (W, H), bilinear (Pillow), each channel on its own
    (Pillow's RGBA resize premultiplies by A, which here is another map); unchanged if already so."""
    if (image.shape[1], image.shape[0]) == size:
        return image
    from PIL import Image

    return np.stack([np.asarray(Image.fromarray(np.ascontiguousarray(image[..., c], np.uint8), "L")
                                .resize(size, Image.BILINEAR)) for c in range(4)], axis=-1)


def pack_diffuse_transmission(strength: TextureInfo | None,
                              color: TextureInfo | None) -> tuple[TextureInfo | None, str]:
    """(the packed TextureInfo: RGB = ``color``'s RGB, A = ``strength``'s A, white and 1 where one
    is absent; a note, '' or why the pair could not be kept exactly).

    The packed texture reads with the colour texture's texCoord, transform and sampler (the
    strength's when there is no colour texture). Where the two differ in those, the strength is
    read with the colour's (the note says so); where only their sizes differ, both are resampled
    to the larger (bilinear). One image used for both is kept as it is."""
    if strength is None and color is None:
        return None, ""
    if color is None:
        image = np.array(strength.image, np.uint8, copy=True)
        image[..., :3] = 255
        return replace(strength, image=image), ""
    if strength is None:
        image = np.array(color.image, np.uint8, copy=True)
        image[..., 3] = 255
        return replace(color, image=image), ""
    note = ""
    if (strength.tex_coord, strength.transform, strength.sampler) != (color.tex_coord, color.transform, color.sampler):
        note = "differs from diffuseTransmissionColorTexture in texCoord, KHR_texture_transform or sampler: " \
               "read with the colour texture's (alight samples the two as one texture)"
    if strength.image is color.image:
        return color, note
    size = (max(strength.image.shape[1], color.image.shape[1]), max(strength.image.shape[0], color.image.shape[0]))
    image = np.array(_resized(color.image, size), np.uint8, copy=True)
    image[..., 3] = _resized(strength.image, size)[..., 3]
    return replace(color, image=image), note

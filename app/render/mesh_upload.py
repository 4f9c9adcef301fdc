"""A mesh put on the GPU in steps, for a front end that must keep drawing frames while a new
mesh arrives (the editor; issue 21: no frame over 100 ms).

``render()`` uploads a mesh the first time it draws it, all in that frame: each texture and its
mip levels (GL's generate_mipmap, which llvmpipe computes on the CPU: 0.65 s for DamagedHelmet's
five 2048x2048 maps) and, for shadows, the self-shadowing test (0.22 s). Here the CPU work is split
from the GL work:

* ``prepare_upload(mesh)`` touches no GL and may run on any thread: every texture's levels as
  the GL upload wants them (flipped, RGBA, ``mip_levels``) and shadow_fit.can_shadow_itself.
* ``Renderer.upload_step(upload)`` on the GL thread writes up to STEP_BYTES of those levels per
  call (a band of a big level, or several small levels), then, in a call of its own, the parts'
  buffers; it returns True once the mesh is whole. The renderer then
  draws it with those textures (the same keys, filters and wrap as its own upload) and the
  remembered self-shadowing answer.

The CLI, the API and batch never call these: their upload (``upload_image``) is unchanged.
"""

from __future__ import annotations

import numpy as np

from alight.render.gpu_mesh import SRGB_MAPS


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


# What one ``step`` writes at most (a piece is never split further than a band of rows): a
# 2048x2048 level 0 is 16 MiB, 50-100 ms to write on llvmpipe under load, too long for one frame.
STEP_BYTES = 4 << 20


class MeshUpload:
    """What ``prepare_upload`` made for one mesh, and how far the steps got."""

    def __init__(self, mesh, textures: list[tuple], self_shadowing: bool):
        self.mesh = mesh
        # (key, info, srgb, levels or None): one per distinct (image, colour space, sampler), keyed
        # as MeshTextures keys them; None: not a power of two, uploaded whole by upload_image.
        self.textures = textures
        self.self_shadowing = self_shadowing
        # The pieces to write, in order: (texture index, level, first row, end row).
        self.pieces = []
        for t, (_, _, _, levels) in enumerate(textures):
            for n, level in enumerate(levels or [None]):
                rows = len(level) if level is not None else 1
                band = max(1, STEP_BYTES // max(1, level[0].nbytes)) if level is not None else 1
                self.pieces += [(t, n, y, min(rows, y + band)) for y in range(0, rows, band)]
        self.next = 0                    # the next piece
        self.made: dict[int, object] = {}   # texture index -> the GL texture (released if dropped)
        self.steps = 0
        self.done = False

    def step(self, ctx, meshes, shadow_maps) -> bool:
        """Write pieces up to STEP_BYTES (at least one); once all are written, make the parts'
        buffers and hand everything to ``meshes`` (GpuMeshes) and ``shadow_maps``. True when whole."""
        from alight.core.gpu import write_rgba8
        from alight.render.gpu_mesh import MeshTextures, level_texture, upload_image

        if self.done:
            return True
        self.steps += 1
        written = 0
        while self.next < len(self.pieces) and written < STEP_BYTES:
            t, n, y0, y1 = self.pieces[self.next]
            key, info, srgb, levels = self.textures[t]
            if levels is None:
                self.made[t] = MeshTextures.sampled(upload_image(ctx, info.image, srgb, info.sampler.mipmaps),
                                                    info.sampler)
                written += info.image.nbytes
            else:
                if t not in self.made:
                    h, w = levels[0].shape[:2]
                    self.made[t] = MeshTextures.sampled(level_texture(ctx, (w, h), len(levels), srgb), info.sampler)
                band = levels[n][y0:y1]
                write_rgba8(ctx, self.made[t], n, y0, band)
                written += band.nbytes
            self.next += 1
        if self.next < len(self.pieces) or written:
            return False   # the parts' buffers in a frame of their own
        textures = MeshTextures(ctx)
        for t, tex in self.made.items():
            textures.adopt(self.textures[t][0], tex)
        meshes.adopt(self.mesh, textures)
        shadow_maps.know_self_shadowing(self.mesh, self.self_shadowing)
        self.made, self.done = {}, True
        return True

    def drop(self) -> None:
        """Release the textures made so far (another mesh was chosen before this one was whole)."""
        for tex in self.made.values():
            tex.release()
        self.made = {}


def prepare_upload(mesh) -> MeshUpload:
    """The CPU side of ``mesh``'s upload (no GL: any thread)."""
    from alight.core.shadow_fit import can_shadow_itself

    seen, textures = set(), []
    for part in mesh.parts:
        if part.material is None:
            continue
        for name, info in part.material.textures().items():
            srgb = name in SRGB_MAPS
            key = (id(info.image), srgb, info.sampler)
            if key in seen:
                continue
            seen.add(key)
            textures.append((key, info, srgb, mip_levels(info.image, srgb, info.sampler.mipmaps)))
    shadowing = bool(mesh.parts) and can_shadow_itself([(p.positions, p.indices) for p in mesh.parts])
    return MeshUpload(mesh, textures, shadowing)

"""A mesh put on the GPU in steps, for a front end that must keep drawing frames while a new
mesh arrives (the editor; issue 21: no frame over 100 ms).

``render()`` uploads a mesh the first time it draws it, all in that frame: each texture and its
mip levels (GL's generate_mipmap, which llvmpipe computes on the CPU: 0.65 s for DamagedHelmet's
five 2048x2048 maps) and, for shadows, the self-shadowing test (0.22 s). Here the CPU work is split
from the GL work:

* ``prepare_upload(mesh)`` touches no GL and may run on any thread: every texture's levels as
  the GL upload wants them (flipped, RGBA, ``mip_levels``; a normal map's with A = 0) and
  shadow_fit.can_shadow_itself.
* ``Renderer.upload_step(upload)`` on the GL thread writes up to STEP_BYTES of those levels per
  call (a band of a big level, or several small levels), then for a normal map the spread of its
  normals into A, a band of a level at a time (alight.render.normal_spread_pass: a compute pass,
  GL work, so here and not in ``prepare_upload``), then, in a call of its own, the parts'
  buffers; it returns True once the mesh is whole. The renderer then
  draws it with those textures (the same keys, filters and wrap as its own upload) and the
  remembered self-shadowing answer.

The CLI, the API and batch never call these: they upload in the frame (``upload_image``, and
``upload_normal_map`` for a normal map with its spread).
"""

from __future__ import annotations

from alight.render.gpu_mesh import SRGB_MAPS, spread_of
from alight.render.mip_levels import mip_levels
from alight.render.normal_spread_pass import BAND_TEXELS, spread_bands


# What one ``step`` writes at most (a piece is never split further than a band of rows): a
# 2048x2048 level 0 is 16 MiB, 50-100 ms to write on llvmpipe under load, too long for one frame.
STEP_BYTES = 4 << 20
# A piece's level for a band of a normal map's spread pass (its row fields: the band's index).
SPREAD = -1


class MeshUpload:
    """What ``prepare_upload`` made for one mesh, and how far the steps got."""

    def __init__(self, mesh, textures: list[tuple], self_shadowing: bool):
        self.mesh = mesh
        # (key, info, srgb, levels or None): one per distinct (image, colour space, sampler), keyed
        # as MeshTextures keys them; None: not a power of two, uploaded whole by upload_image.
        self.textures = textures
        self.self_shadowing = self_shadowing
        # The pieces to write, in order: (texture index, level, first row, end row), or for a
        # band of a normal map's spread pass (texture index, SPREAD, band or -1 for its means
        # texture made, the band's texels).
        self.pieces = []
        for t, (key, _, _, levels) in enumerate(textures):
            for n, level in enumerate(levels or [None]):
                rows = len(level) if level is not None else 1
                band = max(1, STEP_BYTES // max(1, level[0].nbytes)) if level is not None else 1
                self.pieces += [(t, n, y, min(rows, y + band)) for y in range(0, rows, band)]
            if levels is not None and len(levels) > 1 and spread_of(key) is not None:
                h, w = levels[0].shape[:2]
                # first the pass's means texture made (band -1), then its bands
                self.pieces += [(t, SPREAD, -1, BAND_TEXELS)]
                self.pieces += [(t, SPREAD, i, (y1 - y0) * (w >> level or 1))
                                for i, (level, y0, y1) in enumerate(spread_bands((w, h), len(levels)))]
        self.next = 0                    # the next piece
        self.made: dict[int, object] = {}   # texture index -> the GL texture (released if dropped)
        self.spreads: dict[int, object] = {}   # texture index -> its SpreadWriter (while it runs)
        self.steps = 0
        self.done = False

    def step(self, ctx, shaders, meshes, shadow_maps) -> bool:
        """Write pieces up to STEP_BYTES (at least one; a normal map's spread by the pass that
        ``shaders``, the renderer's library, compiles); once all are written, make the parts'
        buffers and hand everything to ``meshes`` (GpuMeshes) and ``shadow_maps``. True when whole."""
        from alight.core.gpu import write_rgba8
        from alight.render.gpu_mesh import MeshTextures, level_texture, upload_image
        from alight.render.normal_spread import without_spread
        from alight.render.normal_spread_pass import SpreadWriter

        if self.done:
            return True
        self.steps += 1
        written = 0
        while self.next < len(self.pieces) and written < STEP_BYTES:
            t, n, y0, y1 = self.pieces[self.next]
            key, info, srgb, levels = self.textures[t]
            if n == SPREAD:
                # the band's level reads the levels written before it (all of them, RGB and A)
                if t not in self.spreads:
                    h, w = levels[0].shape[:2]
                    self.spreads[t] = SpreadWriter(ctx, shaders, self.made[t], (w, h), len(levels), spread_of(key))
                writer = self.spreads[t]
                if y0 < 0:
                    writer.allocate()
                else:
                    writer.write(y0)
                    if y0 == len(writer.bands) - 1:
                        self.spreads.pop(t).release()
                # a band of BAND_TEXELS costs about as much as writing STEP_BYTES (llvmpipe)
                written += max(1, STEP_BYTES * y1 // BAND_TEXELS)
            elif levels is None:
                # (a normal map with its spread, texture_key's "spread": A = 0, no widening)
                image = without_spread(info.image) if spread_of(key) is not None else info.image
                self.made[t] = MeshTextures.sampled(upload_image(ctx, image, srgb, info.sampler.mipmaps),
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
        textures = MeshTextures(ctx, shaders)
        for t, tex in self.made.items():
            textures.adopt(self.textures[t][0], tex)
        meshes.adopt(self.mesh, textures)
        shadow_maps.know_self_shadowing(self.mesh, self.self_shadowing)
        self.made, self.done = {}, True
        return True

    def drop(self) -> None:
        """Release the textures made so far (another mesh was chosen before this one was whole)."""
        for writer in self.spreads.values():
            writer.release()
        for tex in self.made.values():
            tex.release()
        self.made, self.spreads = {}, {}


def prepare_upload(mesh) -> MeshUpload:
    """The CPU side of ``mesh``'s upload (no GL: any thread)."""
    from alight.core.shadow_fit import can_shadow_itself
    from alight.render.gpu_mesh import texture_key
    from alight.render.normal_spread import spread_scale, without_spread

    seen, textures = set(), []
    for part in mesh.parts:
        if part.material is None:
            continue
        for name, info in part.material.textures().items():
            srgb = name in SRGB_MAPS
            spread = spread_scale(name, part.material)
            key = texture_key(info, srgb, spread)
            if key in seen:
                continue
            seen.add(key)
            # a normal map's RGB levels here with A = 0: its spread is written on the GPU by the steps
            levels = mip_levels(info.image if spread is None else without_spread(info.image), srgb,
                                info.sampler.mipmaps)
            textures.append((key, info, srgb, levels))
    shadowing = bool(mesh.parts) and can_shadow_itself([(p.positions, p.indices) for p in mesh.parts])
    return MeshUpload(mesh, textures, shadowing)

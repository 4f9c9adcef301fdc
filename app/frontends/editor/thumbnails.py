"""Thumbnails of materials (the F0 table's presets, the library's entries) for the panel.

Each is the material on the built-in sphere under the built-in studio (its own 'low' bake,
whatever the view shows, so a thumbnail depends on the material alone), rendered once by the
editor's ForwardRenderer and kept as a PNG in the user's cache folder under the material's
content key (``library.content_key``): the next start only reads the files. The panel asks
for a texture id each frame (``texture_id``: no GL, None until ready); the window renders what
was asked for in ``step`` after the view, one thumbnail a frame at most and none in the first
frames, so a long list never stalls the editor (the studio's bake for them runs in slices too).
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from alight.errors import AlightError
from alight.frontends.editor.library import content_key

THUMB_SIZE = 64          # pixels a side, rendered and cached (drawn smaller in the list)
START_AFTER_FRAMES = 2   # the editor's first frames draw the view alone
FRAME_BUDGET_S = 0.015   # what step() spends a frame at most, beyond one render or bake slice
THUMB_VERSION = "1"      # part of the cache key: a change to how thumbnails look renders them anew


def thumbnail_dir() -> Path:
    from alight.paths import cache_dir

    return cache_dir() / "thumbnails"


class Thumbnails:
    def __init__(self, ctx, renderer):
        self.ctx, self.renderer = ctx, renderer
        self._keys: dict = {}          # (material, maps) -> content key (hashing map files once)
        self._textures: dict = {}      # content key -> moderngl.Texture
        self._wanted: dict = {}        # content key -> (material, maps), in the order asked
        self._failed: dict = {}        # content key -> the error line (not retried)
        self._frames = 0
        self._env = self._ibl = self._mesh = None
        self._bake = None              # the studio's bake in progress (a generator)
        self.rendered = 0              # thumbnails rendered (not read from the cache) so far
        self.loaded = 0                # thumbnails read from the cache so far

    def key(self, material, maps) -> str:
        k = (material, maps)
        if k not in self._keys:
            self._keys[k] = content_key(material, maps, f"thumbnail {THUMB_VERSION} {THUMB_SIZE}")
        return self._keys[k]

    def forget(self, material, maps) -> None:
        """Hash the maps' files again next time (a map changed on disk)."""
        self._keys.pop((material, maps), None)

    def texture_id(self, material, maps) -> int | None:
        """The GL name of the thumbnail's texture, or None until it is ready (then it is queued)."""
        key = self.key(material, maps)
        texture = self._textures.get(key)
        if texture is not None:
            return texture.glo
        if key not in self._failed:
            self._wanted.setdefault(key, (material, maps))
        return None

    def pending(self) -> int:
        return len(self._wanted)

    def step(self, budget_s: float = FRAME_BUDGET_S) -> None:
        """Make the thumbnails asked for (GL context current): read cached ones while the budget
        lasts, render at most one. Leaves the window's framebuffer bound."""
        self._frames += 1
        if self._frames <= START_AFTER_FRAMES or not self._wanted:
            return
        start = time.perf_counter()
        try:
            while self._wanted and time.perf_counter() - start < budget_s:
                key, (material, maps) = next(iter(self._wanted.items()))
                file = thumbnail_dir() / f"{key}.png"
                pixels = _read(file)
                if pixels is None:
                    if not self._studio_ready():
                        return
                    try:
                        pixels = self._render(material, maps)
                    except AlightError as exc:
                        self._failed[key] = " ".join(str(exc).split())
                        del self._wanted[key]
                        continue
                    self._write(file, pixels)
                    self.rendered += 1
                else:
                    self.loaded += 1
                self._textures[key] = self.ctx.texture((THUMB_SIZE, THUMB_SIZE), 4, np.ascontiguousarray(pixels).tobytes())
                del self._wanted[key]
        finally:
            self.ctx.screen.use()
            self.ctx.viewport = (0, 0) + tuple(self.ctx.screen.size)

    def _studio_ready(self) -> bool:
        """The built-in studio's 'low' bake, a slice a call: True once it is done."""
        if self._ibl is not None:
            return True
        if self._bake is None:
            from alight.exchange.meshes import load_mesh
            from alight.ibl.environment import load_environment

            self._env, self._mesh = load_environment("studio"), load_mesh("sphere")
            self._bake = self.renderer.bake_steps(self._env, "low")
        try:
            next(self._bake)
            return False
        except StopIteration as done:
            self._ibl, self._bake = done.value, None
            return True

    def _render(self, material, maps):
        """uint8 (THUMB_SIZE, THUMB_SIZE, 4) sRGB, top row first: the material on the sphere."""
        from alight.core.scene import Scene
        from alight.exchange.texture_sets import load_map_images
        from alight.frontends.editor.state import default_lights

        scene = Scene(mesh=self._mesh, material=material, use_file_materials=False, lights=default_lights(),
                      texture_maps=maps, texture_images=load_map_images(maps) if maps.paths() else {},
                      shadows="off")
        frame = self.renderer.render(scene, self._ibl, THUMB_SIZE, THUMB_SIZE, aa="none",
                                     read_linear=False, read_srgb=True)
        return frame.srgb

    @staticmethod
    def _write(file: Path, pixels) -> None:
        """Into the cache; a cache that cannot be written only costs a render next time."""
        from alight.exchange.output import write_image

        try:
            file.parent.mkdir(parents=True, exist_ok=True)
            write_image(file, pixels, linear=False)
        except (AlightError, OSError):
            pass

    def release(self) -> None:
        for texture in self._textures.values():
            texture.release()
        self._textures.clear()
        if self._bake is not None:
            self._bake.close()


def _read(file: Path):
    """A cached thumbnail's RGBA pixels, or None (absent, unreadable or another size)."""
    if not file.is_file():
        return None
    try:
        import OpenImageIO as oiio

        buf = oiio.ImageBuf(str(file))
        pixels = buf.get_pixels(oiio.UINT8)
    except Exception:   # a damaged cache file: rendered again
        return None
    if pixels is None or pixels.shape != (THUMB_SIZE, THUMB_SIZE, 4):
        return None
    return pixels

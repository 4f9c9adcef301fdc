"""Thumbnails of materials (the F0 table's presets, the library's entries) for the panel.

Each is the material on the built-in sphere under the built-in studio (its own 'low' bake,
whatever the view shows, so a thumbnail depends on the material alone), kept as a PNG in the
user's cache folder under the material's content key (``library.content_key``): the next start
only reads the files.

They are rendered by one child process (thumbnail_worker.py, on worker_process.py as the
reference's and the warm-up's children, niced below the editor), one job at a time, sent and
answered from ``step``: a layered material (transmission, sheen, anisotropy ...) needs its own
shader variant, and compiling one took 12-19 s on this 2-core llvmpipe machine under load, a
freeze of the editor had its own GL context done it; at the editor's priority the child took the
first frames' CPU (a first start's orbit 45.6 ms against 15.1 ms). The panel asks for a texture
id each frame (``texture_id``: no GL, None until ready); the window's ``step`` (after the view)
uploads the PNGs that are ready, none in the first frames and a few milliseconds' worth a frame.
"""

from __future__ import annotations

import time
from pathlib import Path

import numpy as np

from alight.frontends.editor.library import content_key

THUMB_SIZE = 64          # pixels a side, rendered and cached (drawn smaller in the list)
START_AFTER_FRAMES = 2   # the editor's first frames draw the view alone
FRAME_BUDGET_S = 0.01    # what step() spends a frame reading and uploading ready thumbnails
THUMB_VERSION = "2"      # part of the cache key: a change to how thumbnails look renders them anew


def thumbnail_dir() -> Path:
    from alight.paths import cache_dir

    return cache_dir() / "thumbnails"


class Thumbnails:
    def __init__(self, ctx, renderer=None):
        self.ctx = ctx
        self._keys: dict = {}          # (material, maps) -> content key (hashing map files once)
        self._textures: dict = {}      # content key -> moderngl.Texture
        self._wanted: dict = {}        # content key -> (material, maps), in the order asked
        self._failed: dict = {}        # content key -> the error line (not retried)
        self._frames = 0
        self._queue: list = []         # (key, material, maps) for the child, in order
        self._queued: set = set()      # keys sent or to send (their PNG is not looked for again until answered)
        self._worker = None            # worker_process.WorkerProcess, started with the first job
        self._job = None               # (job id, key) of the job the child has
        self.rendered = 0              # thumbnails rendered (not read from the cache) so far
        self.loaded = 0                # thumbnails read from the cache so far

    def key(self, material, maps) -> str:
        k = (material, maps)
        if k not in self._keys:
            self._keys[k] = content_key(material, maps, f"thumbnail {THUMB_VERSION} {THUMB_SIZE}")
        return self._keys[k]

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

    def failures(self) -> list[str]:
        return list(self._failed.values())

    def step(self, budget_s: float = FRAME_BUDGET_S) -> None:
        """Take the child's answer, upload the thumbnails asked for whose PNG is in the cache (GL
        context current) while the budget lasts, queue the others and send the next job. Binds
        nothing else."""
        self._frames += 1
        self._settle()
        if self._frames <= START_AFTER_FRAMES or not self._wanted:
            return
        start = time.perf_counter()
        for key, (material, maps) in list(self._wanted.items()):
            if time.perf_counter() - start >= budget_s:
                break
            if key in self._failed:
                del self._wanted[key]
                continue
            if key in self._queued:   # the child has it or will: no file to look for yet
                continue
            pixels = _read(thumbnail_dir() / f"{key}.png")
            if pixels is None:
                self._queued.add(key)
                self._queue.append((key, material, maps))
                continue
            self.loaded += 1
            self._upload(key, pixels)
        self._send()

    def _upload(self, key, pixels) -> None:
        self._textures[key] = self.ctx.texture((THUMB_SIZE, THUMB_SIZE), 4, np.ascontiguousarray(pixels).tobytes())
        self._wanted.pop(key, None)

    def _send(self) -> None:
        if self._job is not None or not self._queue:
            return
        from alight.frontends.editor.thumbnail_worker import ThumbnailJob
        from alight.frontends.editor.worker_process import WorkerProcess

        key, material, maps = self._queue.pop(0)
        if self._worker is None:
            self._worker = WorkerProcess("alight.frontends.editor.thumbnail_worker")
        out = thumbnail_dir() / f"{key}.png"
        try:
            out.parent.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            self._fail(key, material, f"cannot make {out.parent} ({exc})")
            return
        self._job = (self._worker.submit(ThumbnailJob(material=material, maps=maps, out=str(out), size=THUMB_SIZE)), key, material)

    def _settle(self) -> None:
        """The child's answer to the job it has: the PNG uploaded, or the error kept."""
        if self._job is None:
            return
        job_id, key, material = self._job
        for answered, word, text in self._worker.answers():
            if answered != job_id or word == "progress":
                continue
            self._job = None
            pixels = _read(thumbnail_dir() / f"{key}.png") if word == "done" else None
            if pixels is not None:
                self.rendered += 1
                self._upload(key, pixels)
            else:
                self._fail(key, material, text if word == "error" else f"the render process answered {word}")
            return

    def _fail(self, key, material, text: str) -> None:
        self._failed[key] = " ".join(f"thumbnail of '{material.name}': {text or 'the render process ended'}".split())
        self._wanted.pop(key, None)

    def release(self) -> None:
        if self._worker is not None:
            self._worker.close()
            self._worker = None
        for texture in self._textures.values():
            texture.release()
        self._textures.clear()


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
    if pixels is None or pixels.shape[:2] != (THUMB_SIZE, THUMB_SIZE) or pixels.shape[2] not in (3, 4):
        return None
    if pixels.shape[2] == 3:   # alight render's opaque PNG: RGB
        pixels = np.concatenate([pixels, np.full(pixels.shape[:2] + (1,), 255, np.uint8)], axis=2)
    return pixels

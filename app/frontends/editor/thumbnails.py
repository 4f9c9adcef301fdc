"""Thumbnails of materials (the F0 table's presets, the library's entries) for the panel.

Each is the material on the built-in sphere under the built-in studio (its own 'low' bake,
whatever the view shows, so a thumbnail depends on the material alone), kept as a PNG in the
user's cache folder under the material's content key (``library.content_key``): the next start
only reads the files.

They are rendered by one child process (thumbnail_worker.py), a job at a time, driven by a
thread of their own: a layered material (transmission, sheen, anisotropy ...) needs its own shader
variant, and compiling one took 12-19 s on this 2-core llvmpipe machine under load, a freeze
of the editor had its own GL context done it. The panel asks for a texture id each frame
(``texture_id``: no GL, None until ready); the window's ``step`` (after the view) uploads the
PNGs that are ready, none in the first frames and a few milliseconds' worth a frame.
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

import numpy as np

from alight.errors import AlightError
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
        self._lock = threading.Lock()
        self._queue: list = []         # (key, material, maps) for the worker, in order
        self._queued: set = set()
        self._worker = None
        self._stop = threading.Event()
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
        """Upload the thumbnails asked for whose PNG is in the cache (GL context current), while
        the budget lasts; hand the others to the worker thread. Binds nothing else."""
        self._frames += 1
        if self._frames <= START_AFTER_FRAMES or not self._wanted:
            return
        start = time.perf_counter()
        for key, (material, maps) in list(self._wanted.items()):
            if time.perf_counter() - start >= budget_s:
                return
            with self._lock:
                failed = self._failed.get(key)
            if failed is not None:
                del self._wanted[key]
                continue
            pixels = _read(thumbnail_dir() / f"{key}.png")
            if pixels is None:
                self._ask(key, material, maps)
                continue
            self.loaded += key not in self._queued
            self._textures[key] = self.ctx.texture((THUMB_SIZE, THUMB_SIZE), 4, np.ascontiguousarray(pixels).tobytes())
            del self._wanted[key]

    def _ask(self, key, material, maps) -> None:
        with self._lock:
            if key in self._queued:
                return
            self._queued.add(key)
            self._queue.append((key, material, maps))
        if self._worker is None:
            self._worker = threading.Thread(target=self._work, name="alight-thumbnails", daemon=True)
            self._worker.start()

    def _work(self) -> None:
        """The worker thread: jobs to the render process (thumbnail_worker.py), one at a time."""
        process = None
        try:
            while not self._stop.is_set():
                with self._lock:
                    job = self._queue.pop(0) if self._queue else None
                if job is None:
                    self._stop.wait(0.1)
                    continue
                key, material, maps = job
                try:
                    if process is None or process.poll() is not None:
                        process = _start_worker()
                    render_thumbnail(process, material, maps, thumbnail_dir() / f"{key}.png")
                    self.rendered += 1
                except AlightError as exc:
                    with self._lock:
                        self._failed[key] = " ".join(str(exc).split())
        finally:
            if process is not None and process.poll() is None:
                process.stdin.close()
                try:
                    process.wait(timeout=5)
                except subprocess.TimeoutExpired:
                    process.kill()

    def release(self) -> None:
        self._stop.set()
        for texture in self._textures.values():
            texture.release()
        self._textures.clear()


def _start_worker():
    return subprocess.Popen([sys.executable, "-m", "alight.frontends.editor.thumbnail_worker"],
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                            text=True, bufsize=1)


def render_thumbnail(process, material, maps, out: Path) -> None:
    """The material (written to a scratch file: .json, or .glb with its maps) rendered by the
    worker process into ``out``. Errors: AlightError with the worker's line."""
    from alight.exchange.material_files import save_material_file

    out.parent.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory(prefix="alight-thumb-") as scratch:
        source = Path(scratch) / ("material.glb" if maps.paths() else "material.json")
        save_material_file(material, source, maps)
        try:
            process.stdin.write(f"{source}\t{out}\n")
            process.stdin.flush()
            answer = process.stdout.readline().strip()
        except (OSError, ValueError):
            answer = ""
    if answer != "ok":
        raise AlightError(f"thumbnail of '{material.name}': {answer or 'the render process ended'}")


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

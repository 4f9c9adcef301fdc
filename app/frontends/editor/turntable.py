"""Turntables from the editor: N frames of the view with the camera orbiting once about the
vertical axis through its target, as numbered PNGs, one animated WebP or one MP4.

Why the camera orbits (and the environment and lights stay put): the mesh is seen from every
side with the lighting the artist set up, as the orbit (left drag) shows it, and frame 0 is the
view itself. Turning the environment instead shows a sphere's reflections moving but never the
mesh's back; the artist gets that one by dragging with Shift.

Drawn off the frame loop as the screenshots are (screenshot.py): a few frames each editor
frame, so the window keeps drawing and the panel shows the progress. Each frame is the
screenshot of that camera (the renderer's offline path at the view's size). The files are
encoded and written by a worker thread (the frames are numpy arrays; Pillow's encoders release
the GIL), so the window keeps drawing while they are written: the WebP's encoding took one frame
of 3.5 s, 20-34 s under load, before. The files appear only whole: the PNGs are written under
temporary names and renamed once all are drawn, the WebP (lossless, through imageio's Pillow
plugin) is written to a temporary file and renamed. The MP4's frames go to imageio-ffmpeg's
bundled ffmpeg as they are drawn (it encodes in its own process, beside the editor's frames)
into a temporary file, which the worker thread closes (ffmpeg writes its last frames and index)
and renames.

The MP4 is H.264 in yuv420p (what browsers and players read) at CRF 18: lossy, within a few
levels of the PNG on the editor's ball (tests/editor_ui_checks_turntable_video.py bounds it). 4:2:0 needs
even sides: a view of odd width or height is padded by repeating its last column or row.
"""

from __future__ import annotations

import concurrent.futures
import contextlib
import dataclasses
import os
import time
from dataclasses import dataclass
from pathlib import Path

from alight.errors import AlightError
from alight.frontends.editor.widgets import tooltip

SUFFIXES = (".png", ".webp", ".mp4")
MAX_FRAMES = 720
STEP_BUDGET_S = 0.05   # time a frame gives the turntable, beyond one of its frames
FRAME_MS = 40          # the WebP's and MP4's frame time (25 frames a second)
MP4_CRF = 18           # x264's constant rate factor: 18 is about visually lossless, 23 its default


@dataclass
class TurntableSettings:
    """The panel's choice: how many frames, and where (``NAME.png``: NAME_000.png ...;
    ``NAME.webp``, ``NAME.mp4``: one animated file)."""

    frames: int = 36
    path: str = "turntable.webp"   # DEFAULT_PATH: relative, so the working folder of the moment


DEFAULT_PATH = TurntableSettings.path


def frame_paths(path: str, frames: int) -> list[Path]:
    """The files a turntable writes: ``path`` itself for .webp and .mp4, else NAME_000.png, NAME_001.png, ..."""
    p = Path(path)
    if p.suffix.lower() in (".webp", ".mp4"):
        return [p]
    digits = max(3, len(str(frames - 1)))
    return [p.with_name(f"{p.stem}_{i:0{digits}d}{p.suffix}") for i in range(frames)]


def orbit_cameras(orbit, frames: int) -> list:
    """``frames`` cameras one turn about the vertical axis through ``orbit``'s target, the first
    the orbit's own (alight.core.scene.Camera)."""
    return [dataclasses.replace(orbit, yaw_deg=orbit.yaw_deg + 360.0 * i / frames).camera()
            for i in range(frames)]


class TurntableJob:
    """A turntable being drawn a frame or a few at a time (``step``), with ScreenshotJob's
    interface. ``scene_for(camera)`` gives the scene for a camera (the editor's, at the start).
    Errors: AlightError of one line naming the file (bad path, frame count, a write that
    failed); nothing is left under the final names."""

    def __init__(self, renderer, scene_for, cameras, maps, size: tuple[int, int], aa: str, path: str,
                 channels: int = 3):
        from alight.exchange.output import check_output_path

        if not 2 <= len(cameras) <= MAX_FRAMES:
            raise AlightError(f"{path}: a turntable has 2 to {MAX_FRAMES} frames, not {len(cameras)}")
        out = check_output_path(path, SUFFIXES).resolve()
        self.path = str(out)
        self.webp = out.suffix.lower() == ".webp"
        self.mp4 = out.suffix.lower() == ".mp4"
        self._video = None              # the MP4's (writer, temporary path) once its first frame is drawn
        self.finals = frame_paths(self.path, len(cameras))
        self.width, self.height = size
        self._render = lambda camera: renderer.render(scene_for(camera), maps, size[0], size[1], aa=aa,
                                                      read_linear=False, read_srgb=True).srgb
        self._cameras = cameras
        self._temps: list[Path] = []    # the PNGs drawn so far, under temporary names
        self._frames: list = []         # the WebP's frames drawn so far
        self.done = 0
        # One thread that writes the files (never GL): the PNGs as they are drawn, the WebP at the end.
        self._writer = concurrent.futures.ThreadPoolExecutor(1, thread_name_prefix="turntable")
        self._writes: list[concurrent.futures.Future] = []
        self._final_write: concurrent.futures.Future | None = None   # the WebP's encoding, the MP4's close
        self.whole = False         # the files are written, under their final names
        self.channels = channels   # 4 (RGBA, coverage as alpha) where the background is transparent

    @property
    def rows(self) -> int:   # (the window's "is it whole" check reads a screenshot job's rows)
        return self.height if self.whole else 0

    @property
    def writing(self) -> bool:
        """Every frame drawn, the files still being written by the worker thread."""
        return self.done == len(self._cameras)

    def step(self, budget_s: float = STEP_BUDGET_S) -> bool:
        """Draw frames for about ``budget_s`` (at least one); True once the files are whole."""
        start = time.perf_counter()
        try:
            while self.done < len(self._cameras):
                pixels = self._render(self._cameras[self.done])
                self._keep(pixels[:, :, :self.channels])
                self.done += 1
                if self.done < len(self._cameras) and time.perf_counter() - start >= budget_s:
                    return False
            if self._final_write is None:
                if self.webp and self._frames:
                    self._final_write = self._writer.submit(self._write_webp, self._frames)
                    self._frames = []
                elif self.mp4 and self._video is not None:
                    self._final_write = self._writer.submit(self._close_mp4, self._video)
            pending = self._writes + ([self._final_write] if self._final_write is not None else [])
            if not all(f.done() for f in pending):
                return False   # the window draws on meanwhile; the panel says "writing ..."
            for f in pending:
                f.result()     # a write that failed raises its AlightError here
            self._writes, self._final_write, self._video = [], None, None
            self._finish()
            self.whole = True
            return True
        except BaseException:
            self.cancel()
            raise

    def _keep(self, pixels) -> None:
        if self.mp4:
            self._append_video(pixels[:, :, :3])
            return
        if self.webp:
            self._frames.append(pixels.copy())
            return
        from alight.exchange.output import write_image

        final = self.finals[self.done]
        temp = final.with_name(f".{final.stem}.tmp{os.getpid()}{final.suffix}")
        self._temps.append(temp)
        self._writes.append(self._writer.submit(write_image, temp, pixels.copy(), linear=False))

    def _write_webp(self, frames) -> None:
        """On the worker thread: the frames into one animated WebP, atomically."""
        import imageio.v3 as iio

        from alight.exchange.output import atomic_path

        try:
            with atomic_path(self.path) as temp:
                iio.imwrite(temp, frames, plugin="pillow", extension=".webp", lossless=True,
                            duration=FRAME_MS, loop=0)
        except (OSError, ValueError) as exc:
            raise AlightError(f"{self.path}: cannot write the turntable ({' '.join(str(exc).split())})") from None

    def _append_video(self, pixels) -> None:
        import numpy as np

        h, w = pixels.shape[:2]
        pixels = np.pad(pixels, ((0, h % 2), (0, w % 2), (0, 0)), mode="edge")
        try:
            if self._video is None:
                self._video = _open_mp4(self.path)
            self._video[0].append_data(np.ascontiguousarray(pixels))
        except (OSError, ValueError, RuntimeError) as exc:
            raise AlightError(f"{self.path}: cannot write the turntable ({' '.join(str(exc).split())})") from None

    def _close_mp4(self, video) -> None:
        """On the worker thread: ffmpeg's last frames and index, then the file under its name."""
        writer, temp = video
        try:
            writer.close()
            os.chmod(temp, _default_mode(self.path))
            os.replace(temp, self.path)
        except (OSError, ValueError, RuntimeError) as exc:
            raise AlightError(f"{self.path}: cannot write the turntable ({' '.join(str(exc).split())})") from None

    def _finish(self) -> None:
        self._writer.shutdown(wait=False)
        if self.webp or self.mp4:
            return
        for temp, final in zip(self._temps, self.finals):
            os.replace(temp, final)
        self._temps = []

    def cancel(self) -> None:
        """Nothing under the final names but a WebP already being written (it is whole when it
        lands: temp file and rename); the PNGs' temporary files go."""
        for f in self._writes:
            f.cancel()
        self._writer.shutdown(wait=True)   # a PNG being written finishes before its file goes
        self._writes = []
        if self._video is not None and self._final_write is None:   # an MP4 not closed yet: it goes
            writer, temp = self._video
            with contextlib.suppress(Exception):
                writer.close()
            with contextlib.suppress(FileNotFoundError):
                temp.unlink()
        self._video = None
        for temp in self._temps:
            with contextlib.suppress(FileNotFoundError):
                temp.unlink()
        self._temps, self._frames = [], []

    def progress(self) -> str:
        if self.writing:
            return f"writing {os.path.basename(self.path)}..."   # (ASCII: the default font has no U+2026)
        return f"turntable {os.path.basename(self.path)}: frame {self.done} of {len(self._cameras)}"


def _open_mp4(path: str):
    """imageio-ffmpeg's writer into a temporary .mp4 beside ``path``: (writer, temporary path)."""
    import tempfile

    import imageio.v2 as iio

    final = Path(path)
    fd, temp = tempfile.mkstemp(prefix=f".{final.stem}.", suffix=".tmp.mp4", dir=final.parent)
    os.close(fd)
    try:
        writer = iio.get_writer(temp, format="FFMPEG", mode="I", fps=1000.0 / FRAME_MS, codec="libx264",
                                pixelformat="yuv420p", quality=None, macro_block_size=1, ffmpeg_log_level="error",
                                output_params=["-crf", str(MP4_CRF), "-movflags", "+faststart"])
    except BaseException:
        os.unlink(temp)
        raise
    return writer, Path(temp)


def _default_mode(path: str) -> int:
    """The mode an ordinary write of ``path`` would give it (mkstemp's file is private)."""
    try:
        return os.stat(path).st_mode & 0o7777
    except FileNotFoundError:
        umask = os.umask(0)
        os.umask(umask)
        return 0o666 & ~umask


def draw_controls(win) -> None:
    """The panel's turntable row: frames, the file, the button, the job's progress."""
    from imgui_bundle import imgui

    t = win.turntable
    changed, n = imgui.input_int("turntable frames", t.frames)
    if changed:
        t.frames = max(2, min(MAX_FRAMES, n))
    _, t.path = imgui.input_text("turntable file", t.path)
    if imgui.is_item_hovered():
        tooltip("NAME.webp: one animated WebP (lossless); NAME.mp4: one H.264 video (lossy, CRF 18); NAME.png: NAME_000.png, NAME_001.png, ...; "
                          "the camera orbits once about the vertical axis, at the view's size")
    if imgui.button("turntable (T)"):
        win.turntable_request = True   # the window starts it after the frame
    job = getattr(win, "turntable_job", None)
    if job is not None:
        imgui.same_line()
        imgui.text_disabled(job.progress())

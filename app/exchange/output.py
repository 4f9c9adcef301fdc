"""Atomic file writing: a reader never sees a half-written file."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path beside ``path`` (same suffix, so writers pick the format by it);
    rename it over ``path`` only when the block finishes without an exception. The temporary
    file, ``.NAME.XXXXXXXX.tmp.SUFFIX``, is removed on any exception, KeyboardInterrupt included
    (the CLI raises one on SIGTERM: app/frontends/cli/termination.py); only a process killed
    without unwinding (SIGKILL, or SIGTERM where no handler is set, as under the Python API)
    leaves it behind."""
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}", dir=directory)
    try:   # from the file's creation on: a Ctrl-C at any point after it leaves no temporary file
        os.close(fd)
        yield Path(tmp)
        # mkstemp makes the file private (0600); give it the mode an ordinary write would have:
        # the replaced file's own, else the default under the user's umask.
        try:
            mode = path.stat().st_mode & 0o7777
        except FileNotFoundError:
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(tmp, mode)
        os.replace(tmp, path)
    except BaseException:
        with contextlib.suppress(FileNotFoundError):
            os.unlink(tmp)
        raise


def write_text_atomic(path: str | os.PathLike, text: str) -> None:
    with atomic_path(path) as tmp:
        tmp.write_text(text, encoding="utf-8")


IMAGE_SUFFIXES = (".png", ".exr")


def check_output_path(path: str | os.PathLike, suffixes=IMAGE_SUFFIXES) -> Path:
    """Refuse a bad output path before any work is done: unknown suffix, missing folder."""
    from alight.errors import AlightError

    if not str(path).strip():
        raise AlightError(f"output: the path is empty (use a {' or '.join(suffixes)} file)")
    p = Path(path)
    if p.suffix.lower() not in suffixes:
        raise AlightError(f"{p}: unsupported output format '{p.suffix}' (use {' or '.join(suffixes)})")
    parent = p.parent if str(p.parent) else Path(".")
    if not parent.is_dir():
        raise AlightError(f"{p}: the folder {parent} does not exist")
    if p.is_dir():
        raise AlightError(f"{p}: is a folder, not a file")
    return p


def write_image(path: str | os.PathLike, pixels, linear: bool) -> None:
    """Write an image atomically through OpenImageIO.

    ``linear``: float32 RGBA radiance for .exr (docs/conventions.md). Otherwise uint8 sRGB for .png.
    Rows are top first.
    """
    import numpy as np

    pixels = np.asarray(pixels)
    h, w, c = pixels.shape
    with image_rows_writer(path, w, h, c, linear) as put:
        put(pixels)


@contextlib.contextmanager
def image_rows_writer(path: str | os.PathLike, width: int, height: int, channels: int, linear: bool):
    """Write an image band by band, top first, so a huge one never sits in memory whole:
    ``with image_rows_writer(...) as put: put(rows)`` for bands of (n, width, channels) pixels
    that together make ``height`` rows. Atomic: the file appears, whole, only when the block ends
    without an exception (a temporary file beside it, renamed; OpenImageIO's scanline writes).
    ``linear``: float32 for .exr (zip-compressed); else uint8 for .png. Any write failure is an
    AlightError of one line naming the file."""
    import numpy as np
    import OpenImageIO as oiio

    from alight.errors import AlightError

    p = Path(path)
    fmt = oiio.FLOAT if linear else oiio.UINT8
    spec = oiio.ImageSpec(width, height, channels, fmt)
    if linear:
        spec.attribute("compression", "zip")
    else:
        # The display image's alpha is straight (render/tonemap.frag): written as given.
        # OpenImageIO takes pixels as premultiplied by default and divides them by alpha for PNG.
        spec.attribute("oiio:UnassociatedAlpha", 1)
    try:
        with atomic_path(p) as tmp:
            out = oiio.ImageOutput.create(str(tmp))
            if out is None or not out.open(str(tmp), spec):
                raise OSError(" ".join((oiio.geterror() or "cannot open for writing").split()))
            written = 0

            def put(rows) -> None:
                nonlocal written
                rows = np.ascontiguousarray(rows, dtype=np.float32 if linear else np.uint8)
                if rows.shape[1:] != (width, channels) or written + len(rows) > height:
                    raise ValueError(f"rows of shape {rows.shape} do not continue a {width}x{height}x{channels} "
                                     f"image at row {written}")
                if not out.write_scanlines(written, written + len(rows), 0, rows):
                    raise OSError(" ".join(out.geterror().split()) or "write failed")
                written += len(rows)

            try:
                yield put
                if written != height:
                    raise ValueError(f"{written} of {height} rows were written")
            finally:
                out.close()
    except OSError as exc:
        raise AlightError(f"{p}: cannot write ({exc.strerror or exc})") from None

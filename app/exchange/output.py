"""Atomic file writing: a reader never sees a half-written file."""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path


@contextlib.contextmanager
def atomic_path(path: str | os.PathLike):
    """Yield a temporary path beside ``path`` (same suffix, so writers pick the format by it);
    rename it over ``path`` only when the block finishes without an exception."""
    path = Path(path)
    directory = path.parent if str(path.parent) else Path(".")
    fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}", dir=directory)
    os.close(fd)
    try:
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

    ``linear``: float32 RGBA radiance for .exr (CONVENTIONS.md). Otherwise uint8 sRGB for .png.
    Rows are top first.
    """
    import numpy as np
    import OpenImageIO as oiio

    from alight.errors import AlightError

    p = Path(path)
    pixels = np.ascontiguousarray(pixels)
    h, w, c = pixels.shape
    fmt = oiio.FLOAT if linear else oiio.UINT8
    spec = oiio.ImageSpec(w, h, c, fmt)
    if linear:
        spec.attribute("compression", "zip")
    try:
        with atomic_path(p) as tmp:
            out = oiio.ImageOutput.create(str(tmp))
            if out is None or not out.open(str(tmp), spec):
                raise OSError(" ".join((oiio.geterror() or "cannot open for writing").split()))
            ok = out.write_image(pixels)
            error = out.geterror()
            out.close()
            if not ok:
                raise OSError(" ".join(error.split()) or "write failed")
    except OSError as exc:
        raise AlightError(f"{p}: cannot write ({exc.strerror or exc})") from None

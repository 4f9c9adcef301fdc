"""Atomic writes: a new file gets the ordinary mode, a replaced file keeps its own, and a failed
write leaves the old file whole and no temporary file behind."""

import os
import stat

import numpy as np
import pytest

from alight.errors import AlightError
from alight.exchange.output import atomic_path, write_image, write_text_atomic


def mode(path):
    return stat.S_IMODE(os.stat(path).st_mode)


def test_new_file_has_the_umask_default_mode(tmp_path):
    old = os.umask(0o022)
    try:
        write_image(tmp_path / "x.png", np.zeros((4, 4, 3), np.uint8), linear=False)
        write_text_atomic(tmp_path / "x.json", "{}")
    finally:
        os.umask(old)
    assert mode(tmp_path / "x.png") == 0o644 and mode(tmp_path / "x.json") == 0o644


def test_replaced_file_keeps_its_mode(tmp_path):
    target = tmp_path / "x.json"
    target.write_text("old")
    os.chmod(target, 0o640)
    write_text_atomic(target, "new")
    assert target.read_text() == "new" and mode(target) == 0o640


def test_failure_leaves_the_old_file_and_no_temporary(tmp_path):
    target = tmp_path / "x.exr"
    target.write_bytes(b"old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_bytes(b"half")
            raise RuntimeError("interrupted")
    assert target.read_bytes() == b"old"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["x.exr"]


def test_unwritable_folder_is_a_one_line_error(tmp_path):
    with pytest.raises(AlightError) as info:
        write_image(tmp_path / "missing" / "x.png", np.zeros((2, 2, 3), np.uint8), linear=False)
    assert "\n" not in str(info.value) and "x.png" in str(info.value)


def test_png_keeps_straight_alpha_as_given(tmp_path):
    """The display image's alpha is straight (PNG specification 12.8): the file holds the bytes
    given, not colour divided by alpha (OpenImageIO's default for PNG), and reading a texture map
    back gives them unpremultiplied."""
    import OpenImageIO as oiio

    from alight.exchange.images import load_map_image

    px = np.zeros((2, 3, 4), np.uint8)
    px[..., :3] = (200, 120, 40)
    px[..., 3] = [[0, 64, 128], [191, 255, 1]]
    path = tmp_path / "straight.png"
    write_image(path, px, linear=False)
    config = oiio.ImageSpec()
    config.attribute("oiio:UnassociatedAlpha", 1)
    inp = oiio.ImageInput.open(str(path), config)
    stored = np.asarray(inp.read_image(0, 0, 0, 4, oiio.UINT8)).reshape(2, 3, 4)
    inp.close()
    np.testing.assert_array_equal(stored, px)
    np.testing.assert_array_equal(load_map_image(str(path)), px)

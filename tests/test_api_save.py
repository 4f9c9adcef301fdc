"""Renderer.save (app/frontends/api.py) writes through alight.exchange.output.atomic_path: an
interrupted save leaves neither the image nor its hidden temporary file."""

from __future__ import annotations

import pytest

import alight


def test_an_interrupted_save_leaves_no_temporary_file(tmp_path, monkeypatch):
    """Ctrl-C (KeyboardInterrupt) while Renderer.save writes: the hidden .NAME.*.tmp.png beside
    the output is removed (alight.exchange.output.atomic_path), and no image appears."""
    import OpenImageIO as oiio

    real_create = oiio.ImageOutput.create

    class Interrupted:   # the real writer, interrupted at its first rows
        def __init__(self, out):
            self.out = out

        def __getattr__(self, name):
            return getattr(self.out, name)

        def write_scanlines(self, *args):
            assert list(tmp_path.glob(".big.*.tmp.png")), "no temporary file was being written"
            raise KeyboardInterrupt

    monkeypatch.setattr(oiio.ImageOutput, "create", staticmethod(lambda path: Interrupted(real_create(path))))
    with alight.Renderer(32, quality="low") as r, pytest.raises(KeyboardInterrupt):
        r.save(tmp_path / "big.png")
    assert list(tmp_path.iterdir()) == []
